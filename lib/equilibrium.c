/* equilibrium.c: steady configurations (towstab/equilibrium.h,
 * doc/equilibrium.md; doc/model.md section 5).
 *
 * The fast path marches from the free ends and shoots on their positions
 * (march.c). The general path is Newton on q''(q) = 0 over all angles:
 * central-difference Jacobian through the kernel, LU solve (LAPACK dgetrf/
 * dgetrs), backtracking line search on |q''|, re-charting of links that
 * approach cos(theta2) = 0. Turns are reached by continuation in turn rate
 * from the straight tow, with the step refined when a step fails. Whatever
 * the path, the answer is accepted only from the kernel's own verdict: the
 * largest unbalanced nodal force relative to the largest force.
 */
#include "towstab/equilibrium.h"

#include <gsl/gsl_errno.h>
#include <stdlib.h>
#include <string.h>

#include "lapack.h"
#include "march.h"
#include "vec3.h"

/* Shooting mismatch target, relative to the total cable length: far below
 * what moves a force by 1e-10 of the largest one. */
#define SHOOT_POS_RTOL 1e-13
/* A shooting run stopped with a larger mismatch than that, but below this
 * one, is handed to the kernel's force check rather than discarded. */
#define SHOOT_ACCEPT_RTOL 1e-9
/* Central-difference step for the Newton Jacobian, relative to each
 * coordinate's size (1 rad for angles, 1e-3 for strains): truncation ~h^2 and rounding ~eps/h balance near 1e-5 to
 * 1e-6. */
#define NEWTON_FD_STEP 1e-6
#define NEWTON_ALPHA_MIN 1e-6
/* Largest Newton step of any coordinate, in units of its size: the angle
 * accelerations come from the dynamic tension solve, whose conditioning
 * degrades with the number of links, so a full step from a poor start can
 * jump to a different branch (a zigzag on 20 hanging links was underrated
 * tenfold and the step went 0.9 rad). */
#define NEWTON_MAX_STEP 0.3
/* Continuation: the bending scale it starts from (bending nearly off), and
 * the smallest step, as a fraction of the path, before it gives up. */
#define BENDING_START 1e-4
#define CONTINUATION_MIN_STEP (1.0 / 1024)
/* Newton iterations one solve may take along a continuation path, in
 * units of max_iter (the examples take at most 29 with max_iter 100). */
#define CONTINUATION_MAX_ITER 10
/* A relative force residual this small is rounding in the sums of the
 * nodal balances (about 1000 machine epsilons): Newton stalling there has
 * converged as far as double precision goes. */
#define ROUNDING_RESIDUAL 2e-13

void ts_equilibrium_opts_default(ts_equilibrium_opts *o)
{
    o->tol = 1e-10;
    o->max_iter = 100;
    o->method = TS_EQ_AUTO;
    o->guess = NULL;
}

int ts_equilibrium_set_bodies(ts_kernel *k, const ts_equilibrium *eq,
                              double y[], ts_err *err)
{
    int nv = ts_kernel_nvehicles(k), nc = ts_kernel_ncontrol(k);
    int nq = ts_kernel_nq(k);
    if (nv != eq->nvehicles || nc != eq->ncontrol)
        return ts_fail(err, TS_EINVAL,
                       "equilibrium: solved with %d vehicles and %d "
                       "controller states, the kernel has %d and %d",
                       eq->nvehicles, eq->ncontrol, nv, nc);
    for (int v = 0; v < nv; v++)
        ts_kernel_set_vehicle(k, v, eq->attitudes + 9 * v, NULL,
                              TS_CHART_RECHART, y);
    memcpy(y + 2 * nq, eq->controls, (size_t)nc * sizeof(double));
    return TS_OK;
}

const char *ts_eq_method_name(ts_eq_method m)
{
    switch (m) {
    case TS_EQ_SHOOTING: return "shooting";
    case TS_EQ_NEWTON: return "newton";
    default: return "auto";
    }
}

ts_equilibrium *ts_equilibrium_alloc(const ts_system *sys, ts_err *err)
{
    ts_equilibrium *eq = calloc(1, sizeof *eq);
    if (!eq)
        goto nomem;
    eq->nlinks = sys->nlinks;
    eq->nnodes = sys->nnodes;
    size_t nl = (size_t)sys->nlinks, nn = (size_t)sys->nnodes;
    /* Controller states: at most an integrator per loop and an actuator
     * per surface. */
    size_t maxc = 0;
    for (int b = 0; b < sys->nbodies; b++)
        if (sys->bodies[b].vehicle)
            maxc += (size_t)(sys->bodies[b].vehicle->nloops +
                             sys->bodies[b].vehicle->ncomponents);
    eq->nvehicles = sys->nvehicles;
    /* up to 3 coordinates a link, 3 a vehicle, and their rates */
    eq->y = calloc(6 * nl + 6 * (size_t)sys->nvehicles + maxc,
                   sizeof(double));
    eq->directions = calloc(3 * nl, sizeof(double));
    eq->positions = calloc(3 * nn, sizeof(double));
    eq->tensions = calloc(nl, sizeof(double));
    eq->attitudes = calloc(9 * (size_t)sys->nvehicles + 1, sizeof(double));
    eq->controls = calloc(maxc + 1, sizeof(double));
    if (!eq->y || !eq->directions || !eq->positions || !eq->tensions ||
        !eq->attitudes || !eq->controls)
        goto nomem;
    return eq;
nomem:
    ts_equilibrium_free(eq);
    ts_fail_nomem(err, 8.0 * (10.0 * sys->nlinks + 3.0 * sys->nnodes),
                  "fewer links", "equilibrium: out of memory for the result "
                  "of %d links", sys->nlinks);
    return NULL;
}

void ts_equilibrium_free(ts_equilibrium *eq)
{
    if (!eq)
        return;
    free(eq->y);
    free(eq->directions);
    free(eq->positions);
    free(eq->tensions);
    free(eq->attitudes);
    free(eq->controls);
    free(eq);
}

/* Evaluate the kernel at y (rates zero) and record the result in eq. */
static int record(ts_kernel *k, const double *y, ts_equilibrium *eq,
                  double *dydt)
{
    const ts_system *sys = ts_kernel_system(k);
    int nl = sys->nlinks, nq = ts_kernel_nq(k), nc = ts_kernel_ncontrol(k);
    eq->nstate = 2 * nq + nc;
    memcpy(eq->y, y, (size_t)nq * sizeof(double));
    memset(eq->y + nq, 0, (size_t)nq * sizeof(double));
    memcpy(eq->y + 2 * nq, y + 2 * nq, (size_t)nc * sizeof(double));
    eq->ncontrol = nc;
    memcpy(eq->controls, y + 2 * nq, (size_t)nc * sizeof(double));
    for (int v = 0; v < eq->nvehicles; v++)
        ts_kernel_get_vehicle(k, v, eq->y, eq->attitudes + 9 * v, NULL);
    int rc = ts_kernel_eval(k, eq->y, NULL, dydt);
    eq->evaluations++;
    if (rc != TS_OK)
        return rc;
    memcpy(eq->directions, ts_kernel_directions(k),
           3 * (size_t)nl * sizeof(double));
    memcpy(eq->positions, ts_kernel_positions(k),
           3 * (size_t)sys->nnodes * sizeof(double));
    memcpy(eq->tensions, ts_kernel_tensions(k), (size_t)nl * sizeof(double));
    eq->top_tension = ts_kernel_tow_force(k, eq->tow_force);
    double scale;
    double worst = ts_kernel_unbalanced(k, &scale);
    eq->force_scale = scale;
    eq->residual = scale > 0 ? worst / scale : worst;
    eq->min_tension = INFINITY;
    for (int l = 0; l < nl; l++)
        if (eq->tensions[l] < eq->min_tension)
            eq->min_tension = eq->tensions[l];
    return TS_OK;
}

/* Work arrays of the general Newton. */
typedef struct newton_ws {
    int nq;
    double *J, *R, *dq, *yt, *f1, *f2;
    double *work;   /* [4 nq] and iwork [nq]: LAPACK dgecon */
    int *iwork;
    int have_lu;    /* J holds the LU of the last Jacobian */
    double rcond;   /* its reciprocal 1-norm condition, anorm its norm */
    double anorm;
    double *scale;  /* [nq] size of each coordinate: 1 rad for angles,
                       1e-3 for an elastic link's strain */
    double *dirs;   /* [3 nlinks] link directions of the last good state */
    double *strains;/* [nlinks] its strains */
    int *ipiv;
} newton_ws;

static void newton_ws_free(newton_ws *w)
{
    free(w->J);
    free(w->R);
    free(w->dq);
    free(w->yt);
    free(w->f1);
    free(w->f2);
    free(w->work);
    free(w->iwork);
    free(w->dirs);
    free(w->strains);
    free(w->scale);
    free(w->ipiv);
}

static int newton_ws_alloc(newton_ws *w, const ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k);
    size_t n = (size_t)nq;
    w->nq = nq;
    w->scale = malloc(n * sizeof(double));
    if (w->scale)
        for (int l = 0; l < sys->nlinks; l++) {
            int o = ts_kernel_link_offset(k, l);
            int e = sys->links[l].elastic;
            w->scale[o] = w->scale[o + 1] = 1.0;
            /* A strain's step: small against any strain a cable carries,
             * large against rounding. */
            if (e)
                w->scale[o + 2] = 1e-3;
        }
    w->J = malloc(n * n * sizeof(double));
    w->R = malloc(2 * n * sizeof(double));
    w->dq = malloc(n * sizeof(double));
    w->yt = calloc(2 * n, sizeof(double));
    w->f1 = malloc(2 * n * sizeof(double));
    w->f2 = malloc(2 * n * sizeof(double));
    w->work = malloc(4 * n * sizeof(double));
    w->iwork = malloc(n * sizeof(int));
    w->dirs = malloc(3 * (size_t)sys->nlinks * sizeof(double));
    w->strains = malloc((size_t)sys->nlinks * sizeof(double));
    w->ipiv = malloc(n * sizeof(int));
    return w->J && w->R && w->dq && w->yt && w->f1 && w->f2 && w->work &&
           w->iwork &&
           w->dirs && w->strains && w->scale && w->ipiv;
}

static double norm2(const double *v, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
}

static double total_length(const ts_system *sys)
{
    double L = 0;
    for (int l = 0; l < sys->nlinks; l++)
        L += sys->links[l].length;
    return L;
}

/* At convergence: the condition of the last Jacobian, and the shape error
 * the next Newton step implies, |J^-1 q''| times the cable length (from
 * the last LU: its Jacobian is a step old, which is what the estimate
 * needs). NaN when Newton converged without forming a Jacobian. */
static void newton_health(ts_kernel *k, const double *y, newton_ws *w,
                          ts_equilibrium *eq)
{
    (void)y;
    eq->condition = NAN;
    eq->shape_error = NAN;
    if (!w->have_lu)
        return;
    int nq = w->nq, one = 1, info = 0;
    for (int i = 0; i < nq; i++)
        w->dq[i] = w->R[nq + i];
    dgetrs_("N", &nq, &one, w->J, &nq, w->ipiv, w->dq, &nq, &info, 1);
    if (info != 0)
        return;
    double big = 0.0;
    for (int i = 0; i < nq; i++)
        big = fmax(big, fabs(w->dq[i]) / w->scale[i]);
    eq->condition = w->rcond > 0 ? 1.0 / w->rcond : INFINITY;
    eq->shape_error = big * total_length(ts_kernel_system(k));
}

/* Newton on q''(q) = 0 from y (rates must be zero; y[2 nq]). */
static int newton(ts_kernel *k, double *y, double tol, int max_iter,
                  newton_ws *w, ts_equilibrium *eq, ts_err *err)
{
    int nq = w->nq, rc;
    double rel = INFINITY;
    for (int it = 0;; it++) {
        rc = ts_kernel_eval(k, y, NULL, w->R);
        eq->evaluations++;
        if (rc != TS_OK)
            return ts_fail(err, rc, "equilibrium: Newton start is outside "
                                    "the model (%s)", ts_strerror(rc));
        double scale, worst = ts_kernel_unbalanced(k, &scale);
        rel = scale > 0 ? worst / scale : worst;
        if (!isfinite(rel))
            return ts_fail(err, TS_ECONV, "equilibrium: the forces overflowed "
                           "(are not finite) at Newton iteration %d: an "
                           "extreme value of the scene (a stiffness, mass or "
                           "drag coefficient) drove a tension or strain out "
                           "of range", eq->iterations);
        if (rel <= tol) {
            newton_health(k, y, w, eq);
            return TS_OK;
        }
        if (it >= max_iter)
            break;
        eq->iterations++;
        /* Jacobian of q'' by central differences, column by column. */
        for (int j = 0; j < nq; j++) {
            double h = NEWTON_FD_STEP * w->scale[j], y0 = y[j];
            y[j] = y0 + h;
            int r1 = ts_kernel_eval(k, y, NULL, w->f1);
            y[j] = y0 - h;
            int r2 = ts_kernel_eval(k, y, NULL, w->f2);
            y[j] = y0;
            eq->evaluations += 2;
            if (r1 != TS_OK || r2 != TS_OK)
                return ts_fail(err, TS_ECONV,
                               "equilibrium: Newton Jacobian column %d left "
                               "the model's chart",
                               j);
            double *col = w->J + (size_t)j * nq;
            for (int i = 0; i < nq; i++)
                col[i] = (w->f1[nq + i] - w->f2[nq + i]) / (2 * h);
        }
        for (int i = 0; i < nq; i++)
            w->dq[i] = -w->R[nq + i];
        int one = 1, info = 0;
        w->anorm = dlange_("1", &nq, &nq, w->J, &nq, w->work, 1);
        dgetrf_(&nq, &nq, w->J, &nq, w->ipiv, &info);
        w->have_lu = info == 0;
        if (info == 0) {
            int cinfo = 0;
            dgecon_("1", &nq, w->J, &nq, &w->anorm, &w->rcond, w->work,
                    w->iwork, &cinfo, 1);
            if (cinfo != 0)
                w->rcond = NAN;
            dgetrs_("N", &nq, &one, w->J, &nq, w->ipiv, w->dq, &nq, &info, 1);
        }
        if (info != 0) {
            /* Name the link of the coordinate that nothing restores. */
            const ts_system *sys = ts_kernel_system(k);
            int l = 0;
            while (l + 1 < sys->nlinks &&
                   ts_kernel_link_offset(k, l + 1) <= info - 1)
                l++;
            const ts_link *L = &sys->links[l];
            return ts_fail(err, TS_ESINGULAR,
                           "equilibrium: singular Newton Jacobian at "
                           "relative residual %.3g: nothing restores "
                           "cables[%d] '%s' link %d (LAPACK dgetrf info %d), "
                           "as with neutral buoyancy and no flow past it",
                           rel, L->cable, sys->cables[L->cable].name,
                           L->index, info);
        }
        double big = 0.0;
        for (int i = 0; i < nq; i++)
            big = fmax(big, fabs(w->dq[i]) / w->scale[i]);
        if (big > NEWTON_MAX_STEP)
            for (int i = 0; i < nq; i++)
                w->dq[i] *= NEWTON_MAX_STEP / big;
        /* Backtracking line search on |q''|. */
        double phi0 = norm2(w->R + nq, nq), alpha = 1.0;
        int accepted = 0;
        while (alpha >= NEWTON_ALPHA_MIN) {
            for (int i = 0; i < nq; i++)
                w->yt[i] = y[i] + alpha * w->dq[i];
            rc = ts_kernel_eval(k, w->yt, NULL, w->f1);
            eq->evaluations++;
            if (rc == TS_OK && norm2(w->f1 + nq, nq) <=
                                   (1.0 - 1e-4 * alpha) * phi0) {
                accepted = 1;
                break;
            }
            alpha *= 0.5;
        }
        if (!accepted)
            break;
        memcpy(y, w->yt, (size_t)nq * sizeof(double));
        ts_kernel_rechart(k, y, TS_CHART_RECHART);
    }
    if (rel <= ROUNDING_RESIDUAL)
        return ts_fail(err, TS_ECONV,
                       "equilibrium: Newton stopped after %d iterations at "
                       "relative residual %.3g, which is rounding: the "
                       "tolerance %.3g is below what double precision "
                       "reaches (about %g)",
                       eq->iterations, rel, tol, ROUNDING_RESIDUAL);
    return ts_fail(err, TS_ECONV,
                   "equilibrium: Newton stopped after %d iterations at "
                   "relative residual %.3g (tolerance %.3g)",
                   eq->iterations, rel, tol);
}

/* A continuation path: sets the kernel's parameters for t in [0, 1]. */
typedef struct path_ctx {
    ts_kernel *k;
    ts_frame frame;  /* the target frame */
    double b0;       /* bending scale at the start */
} path_ctx;
typedef void (*path_fn)(const path_ctx *pc, double t);

/* Turn rate from 0 to the target. */
static void turn_path(const path_ctx *pc, double t)
{
    ts_frame f = pc->frame;
    f.turn_rate *= t;
    ts_kernel_set_frame(pc->k, &f);
}

/* Bending stiffness from b0 times its value to its value, geometrically. */
static void bending_path(const path_ctx *pc, double t)
{
    ts_kernel_set_bending_scale(pc->k, pow(pc->b0, 1.0 - t));
}

/* Remember the shape of state y (directions and strains: chart-free). */
static void save_shape(ts_kernel *k, const double *y, newton_ws *w)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_kernel_eval(k, y, NULL, w->f1);
    memcpy(w->dirs, ts_kernel_directions(k),
           3 * (size_t)sys->nlinks * sizeof(double));
    for (int l = 0; l < sys->nlinks; l++)
        w->strains[l] = sys->links[l].elastic
                            ? y[ts_kernel_link_offset(k, l) + 2]
                            : 0.0;
}

/* Newton along a parameter path t in [0, 1] from y, a state near the
 * solution at t = 0: solve there, then step towards 1, doubling the step
 * after a success and halving it after a failure (restarting from the last
 * solution), down to CONTINUATION_MIN_STEP. */
static int continuation(ts_kernel *k, double *y, newton_ws *w, path_fn path,
                        const path_ctx *pc, const ts_equilibrium_opts *o,
                        ts_equilibrium *eq, ts_err *err)
{
    int nq = w->nq;
    path(pc, 0.0);
    int rc = newton(k, y, o->tol, o->max_iter, w, eq, err);
    eq->continuation_steps++;
    double t = 0.0, dt = 1.0;
    while (rc == TS_OK && t < 1.0) {
        if (t + dt > 1.0)
            dt = 1.0 - t;
        save_shape(k, y, w);
        path(pc, t + dt);
        rc = newton(k, y, o->tol, o->max_iter, w, eq, err);
        eq->continuation_steps++;
        if (rc == TS_OK) {
            t += dt;
            dt *= 2.0;
            continue;
        }
        if (rc == TS_ENOMEM || dt <= CONTINUATION_MIN_STEP)
            break;
        /* A path that keeps failing can halve its step ten times, each
         * try up to max_iter Newton iterations: bound the whole. */
        if (eq->iterations > CONTINUATION_MAX_ITER * o->max_iter) {
            rc = ts_fail(err, TS_ECONV, "equilibrium: %d Newton iterations "
                         "without reaching the end of the path, more than "
                         "the %d (%d times max_iter) a solve may take",
                         eq->iterations, CONTINUATION_MAX_ITER * o->max_iter,
                         CONTINUATION_MAX_ITER);
            break;
        }
        dt *= 0.5;
        ts_kernel_set_shape(k, w->dirs, w->strains, NULL, NULL,
                            TS_CHART_RECHART, y);
        memset(y + nq, 0, (size_t)nq * sizeof(double));
        path(pc, t);
        rc = TS_OK;
    }
    /* Name the continuation only where there was one: a straight tow has
     * no turn-rate path (its first Newton solve is the whole of it). */
    if (rc != TS_OK && rc != TS_ENOMEM) {
        ts_frame f;
        ts_kernel_get_frame(k, &f);
        if (path == bending_path)
            ts_err_prefix(err, "continuation in bending stiffness (EI "
                               "scaled up from %g of its value) stopped "
                               "%.4g of the way: ", pc->b0, t);
        else if (pc->frame.turn_rate != 0)
            ts_err_prefix(err, "continuation in turn rate towards %.6g "
                               "rad/s stopped %.4g of the way, at %.6g "
                               "rad/s: ", pc->frame.turn_rate, t,
                          f.turn_rate);
    }
    return rc;
}

/* Starting strains for Newton from link directions n[3 nlinks] alone
 * (opts.guess): the tensions a rigid copy of the system carries in that
 * shape at rest, over EA, into strain[nlinks] (0 for rigid links, and for
 * a link the rigid model compresses). Starting at zero strain instead puts
 * every elastic link at the slack kink, T = max(0, EA e): with no tension
 * a link in air has no load that depends on its angles and the Jacobian is
 * singular. One rigid kernel evaluation, O(nlinks). */
static int rigid_strains(const ts_kernel *k, const double *n, double *strain,
                         ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_system *r = ts_system_copy(sys, err);
    if (!r)
        return TS_ENOMEM;
    for (int c = 0; c < r->ncables; c++) {
        r->cables[c].ea = 0.0;
        r->cables[c].damping = 0.0;
    }
    int rc = ts_system_build(r, err);
    ts_kernel *kr = rc == TS_OK ? ts_kernel_alloc(r, err) : NULL;
    double *y = kr ? calloc(4 * (size_t)sys->nlinks, sizeof(double)) : NULL;
    double *dydt = kr ? malloc(4 * (size_t)sys->nlinks * sizeof(double))
                      : NULL;
    if (!y || !dydt) {
        rc = rc == TS_OK ? ts_fail(err, TS_ENOMEM, "equilibrium: out of "
                                                   "memory")
                         : rc;
    } else {
        ts_frame f;
        ts_kernel_get_frame(k, &f);
        ts_kernel_set_frame(kr, &f);
        ts_kernel_set_directions(kr, n, NULL, TS_CHART_RECHART, y);
        rc = ts_kernel_eval(kr, y, NULL, dydt);
        const double *t = ts_kernel_tensions(kr);
        for (int l = 0; l < sys->nlinks; l++) {
            const ts_link *L = &sys->links[l];
            strain[l] = rc == TS_OK && L->elastic && t[l] > 0
                            ? t[l] / L->ea
                            : 0.0;
        }
        rc = TS_OK; /* a failed evaluation leaves zero strains: a start */
    }
    free(y);
    free(dydt);
    ts_kernel_free(kr);
    ts_system_free(r);
    return rc;
}


/* Shooting with continuation in turn rate: schedules of 1, 4, 16 steps. */
static int solve_shooting(ts_kernel *k, tsi_march *m, const ts_frame *frame,
                          const ts_equilibrium_opts *o, ts_equilibrium *eq,
                          ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int nu = tsi_march_nunknown(m), rc = TS_ECONV;
    double *x = malloc((size_t)nu * sizeof(double));
    if (!x)
        return ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
    double pos_tol = SHOOT_POS_RTOL * total_length(sys);
    static const int schedule[] = {1, 4, 16};
    int nsched = frame->turn_rate != 0 ? 3 : 1;
    for (int s = 0; s < nsched; s++) {
        int steps = schedule[s];
        ts_frame f = *frame;
        rc = TS_OK;
        for (int j = (steps > 1 ? 0 : steps); j <= steps && rc == TS_OK; j++) {
            f.turn_rate = frame->turn_rate * j / steps;
            rc = tsi_march_solve(m, &f, x, j == 0 || steps == 1, pos_tol,
                                 o->max_iter, &eq->iterations,
                                 &eq->evaluations, err);
            eq->continuation_steps++;
        }
        if (rc == TS_OK || rc == TS_ESINGULAR)
            break;
    }
    free(x);
    return rc;
}

int ts_equilibrium_solve(ts_kernel *k, const ts_equilibrium_opts *opts,
                         ts_equilibrium *eq, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_equilibrium_opts o;
    if (opts)
        o = *opts;
    else
        ts_equilibrium_opts_default(&o);
    if (!(o.tol > 0) || o.max_iter < 1)
        return ts_fail(err, TS_EINVAL, "equilibrium: tolerance must be > 0 "
                                       "and max_iter >= 1");
    /* towstab checks every GSL status itself; GSL's default handler would
     * abort the process (a process-wide GSL setting). */
    gsl_set_error_handler_off();

    ts_frame frame;
    ts_kernel_get_frame(k, &frame);
    eq->converged = 0;
    eq->iterations = 0;
    eq->evaluations = 0;
    eq->continuation_steps = 0;
    eq->tolerance = o.tol;
    eq->condition = NAN;
    eq->shape_error = NAN;
    if (frame.speed_rate != 0 || frame.turn_accel != 0)
        return ts_fail(err, TS_EDOMAIN, "equilibrium: the frame is "
                                        "accelerating; set speed_rate and "
                                        "turn_accel to 0");
    if (frame.turn_rate != 0 &&
        (frame.current[0] != 0 || frame.current[1] != 0))
        return ts_fail(err, TS_EDOMAIN,
                       "equilibrium: a turn (turn_rate %g rad/s) in a "
                       "horizontal current has no steady state: the current "
                       "rotates in the ship frame",
                       frame.turn_rate);
    if (o.method == TS_EQ_SHOOTING && sys->has_bending)
        return ts_fail(err, TS_EDOMAIN,
                       "equilibrium: method shooting does not apply to "
                       "cables with bending stiffness (EI > 0); use newton "
                       "or auto");
    /* Loads that overflow are the input's fault: say which input. */
    ts_motion_bound mb = {fabs(frame.speed), fabs(frame.turn_rate), 0, 0};
    int lrc = ts_system_check_loads(sys, &mb, err);
    if (lrc != TS_OK) {
        ts_err_prefix(err, "equilibrium: ");
        return lrc;
    }

    int nl = sys->nlinks, nq = ts_kernel_nq(k), rc;
    double *y = calloc(2 * (size_t)nq, sizeof(double));
    double *dydt = malloc(2 * (size_t)nq * sizeof(double));
    double *dvec = malloc(3 * (size_t)nl * sizeof(double));
    double *strain = calloc((size_t)nl, sizeof(double));
    tsi_march *m = tsi_march_alloc(sys, err);
    newton_ws w = {0};
    if (!m) {
        rc = err ? err->code : TS_ENOMEM; /* the march named its size */
        goto out;
    }
    if (!y || !dydt || !dvec || !strain) {
        rc = ts_fail_nomem(err, 8.0 * (4.0 * nq + 4.0 * nl), "fewer links",
                           "equilibrium: out of memory for the state of %d "
                           "links", nl);
        goto out;
    }

    /* Fast path. */
    int have_guess = 0;
    if (!sys->has_bending && o.method != TS_EQ_NEWTON) {
        ts_err serr = {0};
        rc = solve_shooting(k, m, &frame, &o, eq, &serr);
        /* The verdict is the kernel's: a shooting run that stalled just
         * short of its mismatch target (rounding in the local solves of a
         * cable awash, say) may already balance the forces. */
        if (rc == TS_ECONV &&
            tsi_march_mismatch(m) <= SHOOT_ACCEPT_RTOL * total_length(sys))
            rc = TS_OK;
        if (rc == TS_OK) {
            tsi_march_strains(m, strain);
            ts_kernel_set_shape(k, tsi_march_directions(m), strain, NULL,
                                NULL, TS_CHART_RECHART, y);
            have_guess = 1;
            if ((rc = record(k, y, eq, dydt)) == TS_OK && eq->residual <= o.tol) {
                eq->method = TS_EQ_SHOOTING;
                eq->converged = 1;
                tsi_march_condition(m, &eq->condition, &eq->shape_error,
                                    &eq->evaluations);
                goto out;
            }
        }
        if (o.method == TS_EQ_SHOOTING || rc == TS_ESINGULAR) {
            if (err)
                *err = serr;
            if (rc == TS_OK)
                rc = ts_fail(err, TS_ECONV,
                             "equilibrium: shooting converged but the kernel "
                             "residual is %.3g (target %.3g)",
                             eq->residual, o.tol);
            goto out;
        }
    }

    /* General Newton, from the straight-tow march (no bending) or from the
     * shooting result, with continuation in turn rate. */
    eq->method = TS_EQ_NEWTON;
    if (!newton_ws_alloc(&w, k)) {
        rc = ts_fail_nomem(err, 8.0 * nq * (double)nq, "fewer links "
                           "(Newton is used for bending stiffness, and "
                           "where shooting fails)", "equilibrium: out of "
                           "memory for a %d x %d Newton Jacobian", nq, nq);
        goto out;
    }
    rc = TS_ECONV;
    if (o.guess || have_guess) {
        /* Straight from the guess at the full turn rate and bending. */
        if (o.guess) {
            if (sys->has_elastic &&
                (rc = rigid_strains(k, o.guess, strain, err)) != TS_OK)
                goto out;
            ts_kernel_set_shape(k, o.guess, sys->has_elastic ? strain : NULL,
                                NULL, NULL, TS_CHART_RECHART, y);
        }
        memset(y + nq, 0, (size_t)nq * sizeof(double));
        rc = newton(k, y, o.tol, o.max_iter, &w, eq, err);
        eq->continuation_steps++;
    }
    if (rc != TS_OK && rc != TS_ENOMEM) {
        /* From the straight-tow march (bending ignored), or hanging. */
        ts_frame straight = frame;
        straight.turn_rate = 0;
        ts_err merr = {0};
        int it = 0;
        long ev = 0;
        double *x = malloc((size_t)tsi_march_nunknown(m) * sizeof(double));
        if (x && tsi_march_solve(m, &straight, x, 1,
                                 SHOOT_POS_RTOL * total_length(sys),
                                 o.max_iter, &it, &ev, &merr) == TS_OK) {
            tsi_march_strains(m, strain);
            memcpy(dvec, tsi_march_directions(m),
                   3 * (size_t)nl * sizeof(double));
        } else {
            for (int l = 0; l < nl; l++) {
                dvec[3 * l] = dvec[3 * l + 1] = 0.0;
                dvec[3 * l + 2] = 1.0;
                strain[l] = 0.0;
            }
        }
        free(x);
        eq->evaluations += ev;
        ts_kernel_set_shape(k, dvec, strain, NULL, NULL, TS_CHART_RECHART, y);
        memset(y + nq, 0, (size_t)nq * sizeof(double));
        /* Turn rate from 0 with bending nearly off, then bending up. */
        double b0 = sys->has_bending ? BENDING_START : 1.0;
        path_ctx pc = {k, frame, b0};
        ts_kernel_set_bending_scale(k, b0);
        rc = continuation(k, y, &w, turn_path, &pc, &o, eq, err);
        if (rc == TS_OK && sys->has_bending)
            rc = continuation(k, y, &w, bending_path, &pc, &o, eq, err);
        ts_kernel_set_bending_scale(k, 1.0);
        ts_kernel_set_frame(k, &frame);
    }
    {
        int rrc = record(k, y, eq, dydt);
        if (rc == TS_OK && rrc != TS_OK)
            rc = ts_fail(err, rrc, "equilibrium: final state is outside "
                                   "the model (%s)",
                         ts_strerror(rrc));
    }
    if (rc == TS_OK)
        eq->converged = eq->residual <= o.tol;

out:
    ts_kernel_set_frame(k, &frame);
    newton_ws_free(&w);
    tsi_march_free(m);
    free(y);
    free(dydt);
    free(dvec);
    free(strain);
    if (rc == TS_OK && !eq->converged)
        rc = ts_fail(err, TS_ECONV,
                     "equilibrium: not converged, relative residual %.3g "
                     "(target %.3g)",
                     eq->residual, o.tol);
    if (rc == TS_OK)
        ts_err_clear(err); /* a failed first attempt leaves no message */
    return rc;
}
