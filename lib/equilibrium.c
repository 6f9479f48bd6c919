/* equilibrium.c: steady configurations (towstab/equilibrium.h,
 * doc/equilibrium.md; doc/model.md section 5).
 *
 * The fast path marches from the free ends and shoots on their positions
 * (march.c); with vehicles, that march sits inside a small root problem in
 * the vehicles' attitudes and controller states. The general path is Newton on q''(q) = 0 over all angles:
 * central-difference Jacobian through the kernel, LU solve (LAPACK dgetrf/
 * dgetrs), backtracking line search on |q''|, re-charting of links that
 * approach cos(theta2) = 0. Turns are reached by continuation in turn rate
 * from the straight tow, with the step refined when a step fails. Whatever
 * the path, the answer is accepted only from the kernel's own verdict: the
 * largest unbalanced nodal force relative to the largest force.
 *
 * One module although long: the march, Newton, the continuations and the
 * vehicles' trim share one workspace, one acceptance test and one report
 * (ts_equilibrium); split, each would need the others' private state.
 */
#include "towstab/equilibrium.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multiroots.h>
#include <stdlib.h>
#include <string.h>

#include "kernel_impl.h"
#include "lazylib.h"
#include "march.h"
#include "vec3.h"
#include "vehicle.h"

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
 * units of max_iter (the examples take at most 29 with max_iter 100: 3
 * leaves a factor of 10, and a path that cannot be followed fails in
 * seconds rather than a minute). */
#define CONTINUATION_MAX_ITER 3
/* Bending with more links than this (ts_equilibrium_opts.coarse_above's
 * default): Newton starts from the equilibrium of a coarser copy (each
 * cable's links halved, down to this size, where the continuation in
 * bending runs) interpolated onto the links (coarse_start). The shipped
 * two-part tows (35 links) solve directly; at 105 links (35 a cable) the
 * continuation took 175 Newton iterations, and at 399 it did not reach
 * the end of its path (doc/equilibrium.md). */
#define BENDING_DIRECT_LINKS 64
/* A vehicle's attitude alone on its joint in the straight tow (the
 * Newton start): moment residual relative to its weight and flow forces
 * times its lever, and the hybrid solver's iterations. */
#define TRIM_RTOL 1e-12
#define TRIM_MAXIT 200
/* Shooting with vehicles: the outer iterations go on below the tolerance
 * to this fraction of it while they improve (as Newton's last step lands
 * far below it), so that the trim is not a hair's breadth from the
 * tolerance; they stop at the march's rounding, a residual of about
 * 1e-14. */
#define VSHOOT_POLISH 1e-6
/* Shooting with a towing vehicle: a central difference whose two values
 * agree to this fraction of their size (about 64 machine epsilons) is
 * rounding of an even function (a balance along the track against the
 * roll, yaw or turn rate of a symmetric tow), and its entry is zero. */
#define VSHOOT_EVEN_RTOL 1.5e-14
/* Characters of where a failed shooting with vehicles stood (its worst
 * outer equation, the surfaces at their limits), with the zero: with
 * Newton's message after it, a failure's message stays within
 * TS_ERR_MSG_MAX. */
#define VSHOOT_WHERE_MAX 384
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
    o->coarse_above = BENDING_DIRECT_LINKS;
    o->progress = NULL;
    o->progress_data = NULL;
}

/* The towing vehicle's position coordinates in q: x, y, z of its tow
 * point, or x, y for a surface ship (its depth is held). */
static int root_npos(const ts_kernel *k)
{
    return ts_kernel_root_dof(k) == 3 ? 2 : 3;
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
    int ro = ts_kernel_root_offset(k);
    if (ro >= 0) {
        /* The towing vehicle: its position, and the steady motion solved
         * with it becomes the kernel's frame. */
        memcpy(y + ro, eq->y + ro, (size_t)root_npos(k) * sizeof(double));
        ts_frame f;
        ts_kernel_get_frame(k, &f);
        f.speed = eq->speed;
        f.turn_rate = eq->turn_rate;
        ts_kernel_set_frame(k, &f);
        ts_kernel_set_thrust_bias(k, eq->thrust_bias);
        ts_kernel_set_turn_deflection(k, eq->turn_deflection);
    }
    return TS_OK;
}

int ts_equilibrium_state(ts_kernel *k, const ts_equilibrium *eq, double y[],
                         ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int n = ts_kernel_nstate(k), nl = sys->nlinks;
    double *strain = calloc((size_t)(nl > 0 ? nl : 1), sizeof(double));
    if (!strain)
        return ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
    /* Strains do not depend on the charts: take them from eq->y. */
    for (int l = 0; l < nl; l++)
        if (sys->links[l].elastic)
            strain[l] = eq->y[ts_kernel_link_offset(k, l) + 2];
    memset(y, 0, (size_t)n * sizeof(double));
    ts_kernel_set_shape(k, eq->directions, strain, NULL, NULL,
                        TS_CHART_RECHART, y);
    free(strain);
    return ts_equilibrium_set_bodies(k, eq, y, err);
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
    eq->motion_step[0] = eq->motion_step[1] = NAN;
    size_t nl = (size_t)sys->nlinks, nn = (size_t)sys->nnodes;
    /* Controller states: at most an integrator per loop and an actuator
     * per surface. */
    size_t maxc = 0;
    for (int b = 0; b < sys->nbodies; b++)
        if (sys->bodies[b].vehicle)
            maxc += (size_t)(sys->bodies[b].vehicle->nloops +
                             sys->bodies[b].vehicle->ncomponents);
    eq->nvehicles = sys->nvehicles;
    /* up to 3 coordinates a link, 3 a vehicle (6 the towing vehicle),
     * and their rates */
    eq->y = calloc(6 * nl + 6 * (size_t)sys->nvehicles +
                       (sys->tow.vehicle >= 0 ? 6 : 0) + maxc,
                   sizeof(double));
    eq->directions = calloc(3 * nl + 1, sizeof(double));
    eq->positions = calloc(3 * nn, sizeof(double));
    eq->tensions = calloc(nl + 1, sizeof(double));
    eq->attitudes = calloc(9 * (size_t)sys->nvehicles + 1, sizeof(double));
    eq->controls = calloc(maxc + 1, sizeof(double));
    eq->vehicles = calloc((size_t)sys->nvehicles + 1,
                          sizeof(ts_vehicle_result));
    if (!eq->y || !eq->directions || !eq->positions || !eq->tensions ||
        !eq->attitudes || !eq->controls || !eq->vehicles)
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
    free(eq->vehicles);
    free(eq);
}

/* The cables' length (1 m for a towing vehicle without cables: a scale
 * of positions). */
static double total_length(const ts_system *sys)
{
    double L = 0;
    for (int l = 0; l < sys->nlinks; l++)
        L += sys->links[l].length;
    return sys->nlinks > 0 ? L : 1.0;
}

/* Weight of controller state i's rate in the verdict: a loop's error over
 * its scale (the cable length for depth, 1 rad for angles), an
 * actuator's rate times its time constant. */
static double control_weight(const ts_kernel *k, int i)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_control_state cs;
    ts_kernel_control_state(k, i, &cs);
    const ts_vehicle *d =
        sys->bodies[ts_kernel_vehicle_body(k, cs.vehicle)].vehicle;
    if (cs.actuator == TS_CONTROL_SPEED)
        return 1.0 / d->propulsion.speed;
    if (cs.actuator)
        return d->component[cs.index].time_constant;
    return d->loop[cs.index].measure == TS_MEASURE_DEPTH
               ? 1.0 / total_length(sys)
               : 1.0;
}

/* Size of controller state i, the step of its unknown: 1 rad for an
 * actuator, 1 rad / |ki| for a loop's integrator, the vehicle's weight
 * (at least 1 N) / ki for a speed integrator. */
static double control_scale(const ts_kernel *k, int i)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_control_state cs;
    ts_kernel_control_state(k, i, &cs);
    const ts_body *b = &sys->bodies[ts_kernel_vehicle_body(k, cs.vehicle)];
    if (cs.actuator == TS_CONTROL_SPEED)
        return fmax(b->mass * sys->env.gravity, 1.0) /
               b->vehicle->propulsion.ki;
    return cs.actuator ? 1.0 : 1.0 / fabs(b->vehicle->loop[cs.index].ki);
}

/* The largest weighted |c'| of f = f(y); 0 without controllers. */
static double control_residual_of(const ts_kernel *k, const double *f)
{
    int nq = ts_kernel_nq(k), nc = ts_kernel_ncontrol(k);
    double worst = 0.0;
    for (int i = 0; i < nc; i++) {
        double r = fabs(f[2 * nq + i]) * control_weight(k, i);
        if (!(r <= worst))
            worst = r;
    }
    return worst;
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
    ts_frame fr;
    ts_kernel_get_frame(k, &fr);
    eq->speed = fr.speed;
    eq->turn_rate = fr.turn_rate;
    eq->thrust_bias = ts_kernel_thrust_bias(k);
    eq->turn_deflection = ts_kernel_turn_deflection(k);
    double scale;
    double worst = ts_kernel_unbalanced(k, &scale);
    eq->force_scale = scale;
    eq->residual = scale > 0 ? worst / scale : worst;
    eq->min_tension = INFINITY;
    for (int l = 0; l < nl; l++)
        if (eq->tensions[l] < eq->min_tension)
            eq->min_tension = eq->tensions[l];
    for (int v = 0; v < eq->nvehicles; v++)
        ts_kernel_vehicle_result(k, v, &eq->vehicles[v]);
    eq->control_residual = control_residual_of(k, dydt);
    return TS_OK;
}

/* Work arrays of the general Newton. Its unknowns are the coordinates q
 * and the controller states c (nu = nq + nc), its residual the rows of f
 * that must vanish at rest, (q'', c') = f[nq..n). */
typedef struct newton_ws {
    int nq, nc, nu, n;
    double *J, *R, *dq, *yt, *f1, *f2;
    double *work;   /* [2 nu] and iwork [nu]: LAPACK dlacn2 */
    int *iwork;
    double *rowsum; /* [nu] the last Jacobian's row sums sum_j |J_ij| */
    int have_lu;    /* J holds the LU of the last Jacobian */
    double rcond;   /* its reciprocal Skeel condition (skeel_condition) */
    double *scale;  /* [nu] size of each unknown: 1 rad for angles,
                       1e-3 for an elastic link's strain, 1 rad for an
                       actuator, 1 rad / |ki| for an integrator */
    double *dirs;   /* [3 nlinks] link directions of the last good state */
    double *strains;/* [nlinks] its strains */
    double *att;    /* [9 nvehicles] its attitudes */
    double *ctl;    /* [nc] its controller states */
    int *ipiv;
    tsi_lapack la;  /* LAPACK, opened with the first Jacobian */
    /* A towing vehicle: the unknowns at its x and y positions (held at the
     * tow point) are the parameters of its steady motion instead
     * (doc/towing-vehicle.md, section 3): the speed, or the speed
     * controller's thrust bias, and the turn rate. -1 without one. */
    int ux, uy;
    int x_is_bias;  /* 1: ux is the thrust bias, 0: the speed */
    int y_is_turn;  /* 1: uy is the turn surface's deflection (the turn
                       rate given), 0: the turn rate */
    double rootpos[3]; /* the saved shape's root position */
    ts_progress_fn progress; /* the caller's (ts_equilibrium_opts), or
                                NULL */
    void *progress_data;
} newton_ws;

/* Index in y of unknown i. */
static inline int unknown(const newton_ws *w, int i)
{
    return i < w->nq ? i : w->nq + i;
}

static inline int is_param(const newton_ws *w, int i)
{
    return w->ux >= 0 && (i == w->ux || i == w->uy);
}

/* Value of unknown i: y's, or the kernel's parameter. */
static double uget(const ts_kernel *k, const newton_ws *w, const double *y,
                   int i)
{
    if (!is_param(w, i))
        return y[unknown(w, i)];
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    if (i == w->uy)
        return w->y_is_turn ? ts_kernel_turn_deflection(k) : f.turn_rate;
    return w->x_is_bias ? ts_kernel_thrust_bias(k) : f.speed;
}

static void uset(ts_kernel *k, const newton_ws *w, double *y, int i,
                 double v)
{
    if (!is_param(w, i)) {
        y[unknown(w, i)] = v;
        return;
    }
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    if (i == w->uy && w->y_is_turn)
        ts_kernel_set_turn_deflection(k, v);
    else if (i == w->uy)
        f.turn_rate = v;
    else if (w->x_is_bias)
        ts_kernel_set_thrust_bias(k, v);
    else
        f.speed = v;
    ts_kernel_set_frame(k, &f);
}

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
    free(w->rowsum);
    free(w->dirs);
    free(w->strains);
    free(w->att);
    free(w->ctl);
    free(w->scale);
    free(w->ipiv);
}

static int newton_ws_alloc(newton_ws *w, const ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k), nc = ts_kernel_ncontrol(k);
    w->nq = nq;
    w->nc = nc;
    w->nu = nq + nc;
    w->n = 2 * nq + nc;
    size_t nu = (size_t)w->nu, n = (size_t)w->n;
    w->scale = malloc(nu * sizeof(double));
    if (w->scale) {
        for (int i = 0; i < nq; i++)
            w->scale[i] = 1.0; /* link and vehicle angles */
        for (int l = 0; l < sys->nlinks; l++)
            /* A strain's step: small against any strain a cable carries,
             * large against rounding. */
            if (sys->links[l].elastic)
                w->scale[ts_kernel_link_offset(k, l) + 2] = 1e-3;
        for (int i = 0; i < nc; i++)
            w->scale[nq + i] = control_scale(k, i);
    }
    w->ux = w->uy = -1;
    int ro = ts_kernel_root_offset(k);
    if (ro >= 0) {
        const ts_body *bd = &sys->bodies[sys->tow.vehicle];
        w->ux = ro;
        w->uy = ro + 1;
        /* A PI speed controller's integrator carries the thrust: the
         * speed is the unknown (its integrator holds it at the set
         * speed), as with a thrust or a power. */
        w->x_is_bias = bd->vehicle->propulsion.type == TS_PROP_SPEED &&
                       !(bd->vehicle->propulsion.ki > 0);
        w->y_is_turn = sys->tow.turn_surface >= 0;
        if (w->scale) {
            /* Steps of the speed, a thrust, the turn rate. */
            w->scale[ro] = w->x_is_bias
                               ? fmax(bd->mass * sys->env.gravity, 1.0)
                               : fmax(fabs(sys->tow.speed), 1.0);
            w->scale[ro + 1] = 0.1; /* rad/s, or rad */
        }
    }
    w->J = malloc(nu * nu * sizeof(double));
    w->R = malloc(n * sizeof(double));
    w->dq = malloc(nu * sizeof(double));
    w->yt = calloc(n, sizeof(double));
    w->f1 = malloc(n * sizeof(double));
    w->f2 = malloc(n * sizeof(double));
    w->work = malloc(2 * nu * sizeof(double));
    w->iwork = malloc(nu * sizeof(int));
    w->rowsum = malloc(nu * sizeof(double));
    w->dirs = malloc(3 * (size_t)sys->nlinks * sizeof(double));
    w->strains = malloc((size_t)sys->nlinks * sizeof(double));
    w->att = malloc((9 * (size_t)sys->nvehicles + 1) * sizeof(double));
    w->ctl = malloc((nc > 0 ? (size_t)nc : 1) * sizeof(double));
    w->ipiv = malloc(nu * sizeof(int));
    return w->J && w->R && w->dq && w->yt && w->f1 && w->f2 && w->work &&
           w->iwork && w->rowsum && w->dirs && w->strains && w->att && w->ctl &&
           w->scale && w->ipiv;
}

static double norm2(const double *v, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
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
    int nu = w->nu, nq = w->nq, one = 1, info = 0;
    for (int i = 0; i < nu; i++)
        w->dq[i] = w->R[nq + i];
    w->la.dgetrs_("N", &nu, &one, w->J, &nu, w->ipiv, w->dq, &nu, &info, 1);
    if (info != 0)
        return;
    double big = 0.0;
    for (int i = 0; i < nq; i++)
        big = fmax(big, fabs(w->dq[i]) / w->scale[i]);
    eq->condition = w->rcond > 0 ? 1.0 / w->rcond : INFINITY;
    eq->shape_error = big * total_length(ts_kernel_system(k));
    /* The steady motion's unknowns (a towing vehicle): their own parts
     * of the same step. */
    if (w->ux >= 0) {
        eq->motion_step[0] = fabs(w->dq[w->ux]);
        eq->motion_step[1] = fabs(w->dq[w->uy]);
        /* A PI speed controller: the thrust's step is its integral
         * term's. */
        int zs = ts_kernel_speed_integrator(k);
        if (zs >= 0) {
            const ts_system *sys = ts_kernel_system(k);
            eq->motion_step[0] =
                sys->bodies[sys->tow.vehicle].vehicle->propulsion.ki *
                fabs(w->dq[nq + zs]);
        }
    }
}

/* Where the kernel's last evaluation has its largest load or tension
 * (the first one that is not finite, if any), as a scene key path: a
 * vehicle "bodies[b] 'name'", a body at a node, or "cables[c] 'name' link
 * i"; and that magnitude (N) in *big. */
static void largest_load(const ts_kernel *k, char *buf, size_t size,
                         double *big)
{
    const ts_system *sys = ts_kernel_system(k);
    const double *Q = ts_kernel_loads(k), *t = ts_kernel_tensions(k);
    int where = -1, veh = -1;
    *big = 0.0;
    /* "+ 0.0 * x" keeps a NaN, which fmax would drop. */
    for (int i = 1; i < sys->nnodes && isfinite(*big); i++) {
        double m = fabs(t[i - 1]);
        for (int j = 0; j < 3; j++)
            m = fmax(m, fabs(Q[3 * i + j])) + 0.0 * Q[3 * i + j];
        if (!(m <= *big)) {
            *big = m;
            where = i;
        }
    }
    for (int v = 0; v < ts_kernel_nvehicles(k) && isfinite(*big); v++) {
        ts_vehicle_result r;
        ts_kernel_vehicle_result(k, v, &r);
        double m = 0;
        for (int j = 0; j < 3; j++)
            m = fmax(m, fabs(r.hydro_force[j])) + 0.0 * r.hydro_force[j];
        if (!(m <= *big)) {
            *big = m;
            veh = r.body;
        }
    }
    if (veh >= 0) {
        snprintf(buf, size, "bodies[%d] '%s'", veh, sys->bodies[veh].name);
    } else if (where > 0 && sys->nodes[where].body >= 0) {
        int b = sys->nodes[where].body;
        snprintf(buf, size, "bodies[%d] '%s'", b, sys->bodies[b].name);
    } else if (where > 0) {
        const ts_link *L = &sys->links[sys->nodes[where].link];
        snprintf(buf, size, "cables[%d] '%s' link %d", L->cable,
                 sys->cables[L->cable].name, L->index);
    } else {
        buf[0] = '\0';
    }
}

/* The part of the system state y[i] (a coordinate or a controller
 * state) belongs to, as a scene key path. */
static void singular_place(const ts_kernel *k, int i, char *buf, size_t size)
{
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k);
    if (i >= 2 * nq) {
        ts_control_state cs;
        ts_kernel_control_state(k, i - 2 * nq, &cs);
        int b = ts_kernel_vehicle_body(k, cs.vehicle);
        const ts_vehicle *v = sys->bodies[b].vehicle;
        if (cs.actuator == TS_CONTROL_SPEED)
            snprintf(buf, size, "bodies[%d] '%s' speed controller", b,
                     sys->bodies[b].name);
        else
            snprintf(buf, size, "bodies[%d] '%s' %s '%s'", b,
                     sys->bodies[b].name,
                     cs.actuator ? "control surface" : "controller",
                     cs.actuator ? v->component[cs.index].name
                                 : v->loop[cs.index].name);
        return;
    }
    if (ts_kernel_root(k) >= 0 && i >= ts_kernel_root_offset(k) &&
        i < ts_kernel_root_offset(k) + root_npos(k)) {
        int b = sys->tow.vehicle;
        snprintf(buf, size, "bodies[%d] '%s' (its steady motion: speed, "
                 "turn rate%s)", b, sys->bodies[b].name,
                 root_npos(k) == 3 ? ", depth" : "");
        return;
    }
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        int o = ts_kernel_vehicle_offset(k, v);
        int na = v == ts_kernel_root(k) && root_npos(k) == 2 ? 1 : 3;
        if (i >= o && i < o + na) {
            int b = ts_kernel_vehicle_body(k, v);
            snprintf(buf, size, "bodies[%d] '%s' (its attitude)", b,
                     sys->bodies[b].name);
            return;
        }
    }
    int l = 0;
    while (l + 1 < sys->nlinks && ts_kernel_link_offset(k, l + 1) <= i)
        l++;
    const ts_link *L = &sys->links[l];
    snprintf(buf, size, "cables[%d] '%s' link %d", L->cable,
             sys->cables[L->cable].name, L->index);
}

/* Report `done` Jacobian columns of nu to the caller's progress callback:
 * TS_OK to go on, TS_ECANCEL (message set) when it asks to stop. */
static int poll_progress(const newton_ws *w, int done, const ts_equilibrium *eq,
                         ts_err *err)
{
    if (!w->progress)
        return TS_OK;
    ts_progress p = {"equilibrium", done, w->nu, "Jacobian columns"};
    if (!w->progress(&p, w->progress_data))
        return TS_OK;
    return ts_fail(err, TS_ECANCEL, "equilibrium: stopped on request in "
                                    "Newton iteration %d (%d of %d Jacobian "
                                    "columns formed)",
                   eq->iterations, done, w->nu);
}

/* The Skeel condition number || |J^-1| |J| ||_inf of the last Jacobian
 * (w->J holding its LU, w->rowsum its row sums), i.e. the inf-norm
 * condition of J with its rows scaled to unit sums, D J with D^-1 =
 * diag(rowsum): || |J^-1| |J| e ||_inf = || J^-1 D^-1 ||_inf, estimated
 * as the 1-norm of its transpose D^-1 J^-T by LAPACK's dlacn2 (Hager and
 * Higham's estimator, as dgecon uses) with solves by the LU. Unlike the
 * plain condition it does not change with the scaling of the rows: they
 * are accelerations of links whose masses and inertias differ by orders
 * (a 3 mm link beside a 14 cm one), and the Newton step's accuracy does
 * not depend on that scaling. A few O(nu^2) solves. */
static double skeel_condition(newton_ws *w)
{
    int nu = w->nu, kase = 0, isave[3] = {0, 0, 0}, one = 1, info = 0;
    double est = 0.0, *v = w->work, *x = w->work + nu;
    do {
        w->la.dlacn2_(&nu, v, x, w->iwork, &est, &kase, isave);
        if (kase == 1) { /* x := D^-1 J^-T x */
            w->la.dgetrs_("T", &nu, &one, w->J, &nu, w->ipiv, x, &nu, &info,
                          1);
            for (int i = 0; i < nu; i++)
                x[i] *= w->rowsum[i];
        } else if (kase == 2) { /* x := J^-1 D^-1 x */
            for (int i = 0; i < nu; i++)
                x[i] *= w->rowsum[i];
            w->la.dgetrs_("N", &nu, &one, w->J, &nu, w->ipiv, x, &nu, &info,
                          1);
        }
    } while (kase != 0 && info == 0);
    return info == 0 ? est : NAN;
}

/* The Jacobian of (q'', c') at y by central differences, column by
 * column, and its LU and condition in w (w->R holds f(y)). TS_OK,
 * TS_ECANCEL, TS_ECONV (a column left the chart), TS_EIO (LAPACK cannot
 * be opened), or -info of a singular dgetrf. */

static int jacobian(ts_kernel *k, double *y, newton_ws *w, ts_equilibrium *eq,
                    ts_err *err)
{
    int nq = w->nq, nu = w->nu;
    for (int j = 0; j < nu; j++) {
        int prc = poll_progress(w, j, eq, err);
        if (prc != TS_OK)
            return prc;
        double h = NEWTON_FD_STEP * w->scale[j], y0 = uget(k, w, y, j);
        uset(k, w, y, j, y0 + h);
        int r1 = ts_kernel_eval(k, y, NULL, w->f1);
        uset(k, w, y, j, y0 - h);
        int r2 = ts_kernel_eval(k, y, NULL, w->f2);
        uset(k, w, y, j, y0);
        eq->evaluations += 2;
        if (r1 != TS_OK || r2 != TS_OK)
            return ts_fail(err, TS_ECONV,
                           "equilibrium: Newton Jacobian column %d left "
                           "the model's chart",
                           j);
        double *col = w->J + (size_t)j * nu;
        for (int i = 0; i < nu; i++)
            col[i] = (w->f1[nq + i] - w->f2[nq + i]) / (2 * h);
    }
    int prc = poll_progress(w, nu, eq, err);
    if (prc != TS_OK)
        return prc;
    int info = 0;
    if (!w->la.dgetrf_ && tsi_lapack_open(&w->la, err) != TS_OK)
        return TS_EIO;
    for (int i = 0; i < nu; i++)
        w->rowsum[i] = 0.0;
    for (int j = 0; j < nu; j++) {
        const double *col = w->J + (size_t)j * nu;
        for (int i = 0; i < nu; i++)
            w->rowsum[i] += fabs(col[i]);
    }
    w->la.dgetrf_(&nu, &nu, w->J, &nu, w->ipiv, &info);
    w->have_lu = info == 0;
    if (info == 0)
        w->rcond = 1.0 / skeel_condition(w);
    return info == 0 ? TS_OK : -info;
}

/* Newton on (q'', c')(q, c) = 0 from y (rates must be zero; y[n]). */
static int newton(ts_kernel *k, double *y, double tol, int max_iter,
                  newton_ws *w, ts_equilibrium *eq, ts_err *err)
{
    int nq = w->nq, nu = w->nu, n = w->n, rc;
    double rel = INFINITY, crel = 0.0;
    for (int it = 0;; it++) {
        rc = ts_kernel_eval(k, y, NULL, w->R);
        eq->evaluations++;
        if (rc != TS_OK)
            return ts_fail(err, rc, "equilibrium: Newton start is outside "
                                    "the model (%s)", ts_strerror(rc));
        double scale, worst = ts_kernel_unbalanced(k, &scale);
        rel = scale > 0 ? worst / scale : worst;
        crel = control_residual_of(k, w->R);
        if (rel <= tol && crel <= tol) {
            /* A start that is already the answer (a straight tow with
             * vehicles) still gets the Jacobian its health needs. */
            int jrc = w->have_lu ? TS_OK : jacobian(k, y, w, eq, err);
            if (jrc == TS_ECANCEL || jrc == TS_EIO)
                return jrc; /* TS_EIO: LAPACK missing, err says so */
            if (jrc == TS_ECONV)
                ts_err_clear(err);
            newton_health(k, y, w, eq);
            return TS_OK;
        }
        if (!isfinite(rel) || !isfinite(crel)) {
            char place[2 * TS_NAME_MAX + 32], size[64];
            double big;
            largest_load(k, place, sizeof place, &big);
            if (isfinite(big))
                snprintf(size, sizeof size, "largest %.3g N", big);
            else
                snprintf(size, sizeof size, "a load is not finite");
            return ts_fail(err, TS_EDOMAIN,
                           "equilibrium: %s%sthe forces overflow (%s) after "
                           "%d Newton iterations: an input beyond the "
                           "model's range (a speed, length or coefficient "
                           "too large?)",
                           place, place[0] ? ": " : "", size, it);
        }
        if (it >= max_iter)
            break;
        eq->iterations++;
        rc = jacobian(k, y, w, eq, err);
        if (rc == TS_ECANCEL)
            return ts_fail(err, TS_ECANCEL, "equilibrium: stopped on "
                                            "request in Newton iteration %d "
                                            "at relative residual %.3g "
                                            "(tolerance %.3g)",
                           eq->iterations, rel, tol);
        if (rc == TS_ECONV || rc == TS_EIO)
            return rc;
        int one = 1, info = -rc;
        for (int i = 0; i < nu; i++)
            w->dq[i] = -w->R[nq + i];
        if (info == 0)
            w->la.dgetrs_("N", &nu, &one, w->J, &nu, w->ipiv, w->dq, &nu, &info,
                          1);
        if (info != 0) {
            char place[2 * TS_NAME_MAX + 64];
            singular_place(k, unknown(w, info - 1), place, sizeof place);
            return ts_fail(err, TS_ESINGULAR,
                           "equilibrium: singular Newton Jacobian at "
                           "relative residual %.3g: nothing restores %s "
                           "(LAPACK dgetrf info %d), as with neutral "
                           "buoyancy and no flow past it",
                           rel, place, info);
        }
        double big = 0.0;
        for (int i = 0; i < nu; i++)
            big = fmax(big, fabs(w->dq[i]) / w->scale[i]);
        if (big > NEWTON_MAX_STEP)
            for (int i = 0; i < nu; i++)
                w->dq[i] *= NEWTON_MAX_STEP / big;
        /* Backtracking line search on |(q'', c')|. */
        double phi0 = norm2(w->R + nq, nu), alpha = 1.0;
        int accepted = 0;
        double p0[2] = {0, 0};
        if (w->ux >= 0) {
            p0[0] = uget(k, w, y, w->ux);
            p0[1] = uget(k, w, y, w->uy);
        }
        memcpy(w->yt, y, (size_t)n * sizeof(double));
        while (alpha >= NEWTON_ALPHA_MIN) {
            for (int i = 0; i < nu; i++)
                uset(k, w, w->yt, i,
                     (is_param(w, i) ? p0[i == w->uy] : y[unknown(w, i)]) +
                         alpha * w->dq[i]);
            rc = ts_kernel_eval(k, w->yt, NULL, w->f1);
            eq->evaluations++;
            if (rc == TS_OK && norm2(w->f1 + nq, nu) <=
                                   (1.0 - 1e-4 * alpha) * phi0) {
                accepted = 1;
                break;
            }
            alpha *= 0.5;
        }
        if (!accepted) {
            /* |q''| can stop falling at its rounding before the forces
             * balance to the tolerance (many short links with bending:
             * the two-part tow at 300 links). Then the full step is
             * taken if it lowers the force residual, the acceptance
             * test's measure, by the same margin. */
            for (int i = 0; i < nu; i++)
                uset(k, w, w->yt, i,
                     (is_param(w, i) ? p0[i == w->uy] : y[unknown(w, i)]) +
                         w->dq[i]);
            rc = ts_kernel_eval(k, w->yt, NULL, w->f1);
            eq->evaluations++;
            double fscale, fworst = ts_kernel_unbalanced(k, &fscale);
            double frel = fscale > 0 ? fworst / fscale : fworst;
            accepted = rc == TS_OK && frel <= (1.0 - 1e-4) * rel;
        }
        if (!accepted) {
            if (w->ux >= 0) {
                uset(k, w, y, w->ux, p0[0]);
                uset(k, w, y, w->uy, p0[1]);
            }
            break;
        }
        memcpy(y, w->yt, (size_t)n * sizeof(double));
        ts_kernel_rechart(k, y, TS_CHART_RECHART);
    }
    if (crel > tol && rel <= tol)
        return ts_fail(err, TS_ECONV,
                       "equilibrium: Newton stopped after %d iterations with "
                       "the forces balanced but the controllers unsettled "
                       "(controller residual %.3g, target %.3g): a set "
                       "point out of reach of the surfaces' limits?",
                       eq->iterations, crel, tol);
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
    const double *sp0, *sp1; /* set points at the start and the end,
                                vehicle by vehicle, loop by loop */
} path_ctx;
typedef void (*path_fn)(const path_ctx *pc, double t);

/* Turn rate from 0 to the target. */
static void turn_path(const path_ctx *pc, double t)
{
    ts_frame f = pc->frame;
    f.turn_rate *= t;
    ts_kernel_set_frame(pc->k, &f);
}

/* Every loop's set point from sp0 to sp1 (a heading by the shorter way:
 * sp1 is within pi of sp0), the frame straight. */
static void setpoint_path(const path_ctx *pc, double t)
{
    const ts_system *sys = ts_kernel_system(pc->k);
    ts_frame f = pc->frame;
    f.turn_rate = 0.0; /* the turn comes after, along turn_path */
    ts_kernel_set_frame(pc->k, &f);
    for (int v = 0, i = 0; v < ts_kernel_nvehicles(pc->k); v++) {
        const ts_vehicle *d =
            sys->bodies[ts_kernel_vehicle_body(pc->k, v)].vehicle;
        for (int l = 0; l < d->nloops; l++, i++)
            ts_kernel_set_setpoint(pc->k, v, l,
                                   pc->sp0[i] + t * (pc->sp1[i] - pc->sp0[i]));
    }
}

/* Controllers: start every loop at the set point the state y already
 * has (its measurement), with integrators at zero and actuators at their
 * open-loop deflections, so that y (a trim with the loops idle) solves the
 * closed loop at t = 0; sp0[nloops] receives those set points and sp1
 * the targets (the kernel's set points on entry). Returns the number of
 * loops. */
static int controls_start(ts_kernel *k, double *y, double *sp0, double *sp1,
                          double *dydt)
{
    const ts_system *sys = ts_kernel_system(k);
    int i = 0, nout = ts_kernel_noutput(k), j = 0;
    double *out = malloc((size_t)(nout > 0 ? nout : 1) * sizeof(double));
    if (!out)
        return -1;
    ts_kernel_eval(k, y, NULL, dydt);
    ts_kernel_outputs(k, out);
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        double xi[TS_VEHICLE_MAX_LOOPS] = {0}, act[TS_VEHICLE_MAX_COMPONENTS];
        static const int measure_out[4] = {0, 1, 2, 3}; /* depth pitch roll
                                                           yaw */
        for (int l = 0; l < d->nloops; l++, i++) {
            double m = out[j + measure_out[d->loop[l].measure]];
            sp1[i] = ts_kernel_setpoint(k, v, l);
            sp0[i] = m;
            if (d->loop[l].measure == TS_MEASURE_HEADING) {
                /* go the shorter way round */
                double dh = remainder(sp1[i] - m, 2 * M_PI);
                sp1[i] = m + dh;
            }
        }
        int nsurf = 0;
        for (int c = 0; c < d->ncomponents; c++) {
            const ts_component *cp = &d->component[c];
            act[c] = fmax(-cp->limit, fmin(cp->limit, cp->deflection));
            nsurf += cp->control != 0;
        }
        ts_kernel_set_controls(k, v, xi, act, y);
        /* Its outputs: 4 measures, the loops, the surfaces' deflections
         * (ts_kernel_outputs). */
        j += 4 + d->nloops + nsurf;
    }
    free(out);
    return i;
}

/* Bending stiffness from b0 times its value to its value, geometrically. */
static void bending_path(const path_ctx *pc, double t)
{
    ts_kernel_set_bending_scale(pc->k, pow(pc->b0, 1.0 - t));
}

/* Remember the shape of state y (directions, strains, attitudes:
 * chart-free) and its controller states. */
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
    for (int v = 0; v < sys->nvehicles; v++)
        ts_kernel_get_vehicle(k, v, y, w->att + 9 * v, NULL);
    memcpy(w->ctl, y + 2 * w->nq, (size_t)w->nc * sizeof(double));
    if (w->ux >= 0)
        memcpy(w->rootpos, y + w->ux, sizeof w->rootpos);
}

/* Go back to the saved shape, at rest. */
static void restore_shape(ts_kernel *k, double *y, newton_ws *w)
{
    const ts_system *sys = ts_kernel_system(k);
    memset(y, 0, (size_t)w->n * sizeof(double));
    ts_kernel_set_shape(k, w->dirs, w->strains, NULL, NULL, TS_CHART_RECHART,
                        y);
    for (int v = 0; v < sys->nvehicles; v++)
        ts_kernel_set_vehicle(k, v, w->att + 9 * v, NULL, TS_CHART_RECHART, y);
    memcpy(y + 2 * w->nq, w->ctl, (size_t)w->nc * sizeof(double));
    if (w->ux >= 0)
        memcpy(y + w->ux, w->rootpos, sizeof w->rootpos);
}

/* A path step that keeps the towing vehicle's steady motion (speed, turn
 * rate, thrust bias: unknowns, not the path's). */
static void path_at(ts_kernel *k, const newton_ws *w, path_fn path,
                    const path_ctx *pc, double t)
{
    ts_frame f;
    double bias = ts_kernel_thrust_bias(k);
    double turn = ts_kernel_turn_deflection(k);
    ts_kernel_get_frame(k, &f);
    path(pc, t);
    if (w->ux < 0)
        return;
    /* A towing vehicle's speed and turn rate are Newton's unknowns: the
     * path leaves them; with turn_by the turn rate is the scene's, a
     * parameter the path moves, and the rudder the unknown. */
    ts_frame g;
    ts_kernel_get_frame(k, &g);
    g.speed = f.speed;
    if (!w->y_is_turn)
        g.turn_rate = f.turn_rate;
    ts_kernel_set_frame(k, &g);
    ts_kernel_set_thrust_bias(k, bias);
    ts_kernel_set_turn_deflection(k, turn);
}

/* Appends to buf (holding len characters) the lifting surfaces in or
 * past their stall at the kernel's last evaluation, |alpha| beyond stall
 * - stall_width, where the lift curve bends over (a solve asking more
 * lift than a surface gives stops at its maximum, inside that band):
 * ", with <vehicle>.<surface> (angle of attack A deg, its stall S +- W
 * deg) stalling", the first two named. A surface with tabulated curves
 * has no stall angle and is not judged. Returns the new length.
 * O(vehicles' components). */
static size_t stalled(const ts_kernel *k, char *buf, size_t len, size_t size)
{
    const ts_system *sys = ts_kernel_system(k);
    int n = 0;
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        ts_vehicle_result r;
        ts_kernel_vehicle_result(k, v, &r);
        const ts_body *b = &sys->bodies[r.body];
        for (int c = 0; c < b->vehicle->ncomponents; c++) {
            const ts_component *cp = &b->vehicle->component[c];
            if (cp->type != TS_COMP_SURFACE || cp->curve == TS_CURVE_TABLE ||
                !(fabs(r.load[c].alpha) > cp->stall - cp->stall_width))
                continue;
            if (n++ < 2 && len < size)
                len += (size_t)snprintf(
                    buf + len, size - len, "%s%s.%s (angle of attack %.3g "
                    "deg, its stall %.3g +- %.3g deg)",
                    n > 1 ? ", " : ", with ", b->name, cp->name,
                    r.load[c].alpha * 180 / M_PI, cp->stall * 180 / M_PI,
                    cp->stall_width * 180 / M_PI);
        }
    }
    if (n > 2 && len < size)
        len += (size_t)snprintf(buf + len, size - len, " and %d more", n - 2);
    if (n > 0 && len < size)
        len += (size_t)snprintf(buf + len, size - len, " stalling: more "
                                "lift asked than %s gives?",
                                n > 1 ? "they" : "it");
    return len < size ? len : size - 1;
}

/* ", with <vehicle>.<surface> at its limit" for the first control
 * surface at its deflection limit in state y, else "", then the surfaces
 * past their stall (stalled). */
static void saturated(ts_kernel *k, const double *y, char *buf, size_t size)
{
    const ts_system *sys = ts_kernel_system(k);
    double *f = malloc((size_t)ts_kernel_nstate(k) * sizeof(double));
    buf[0] = '\0';
    if (!f || ts_kernel_eval(k, y, NULL, f) != TS_OK) {
        free(f);
        return;
    }
    free(f);
    for (int v = 0; v < ts_kernel_nvehicles(k) && !buf[0]; v++) {
        ts_vehicle_result r;
        ts_kernel_vehicle_result(k, v, &r);
        const ts_body *b = &sys->bodies[r.body];
        for (int c = 0; c < b->vehicle->ncomponents; c++) {
            const ts_component *cp = &b->vehicle->component[c];
            if (cp->control && isfinite(cp->limit) &&
                fabs(r.delta[c]) >= cp->limit * (1 - 1e-9)) {
                snprintf(buf, size, ", with %s.%s at its limit %.4g deg: a "
                         "set point out of the surfaces' reach?", b->name,
                         cp->name, cp->limit * 180 / M_PI);
                break;
            }
            if (cp->type == TS_COMP_BALLAST &&
                (r.delta[c] <= 1e-9 * cp->capacity ||
                 r.delta[c] >= cp->capacity * (1 - 1e-9))) {
                snprintf(buf, size, ", with the ballast tank %s.%s %s: a "
                         "set point out of its reach?", b->name, cp->name,
                         r.delta[c] > 0.5 * cp->capacity ? "full" : "empty");
                break;
            }
        }
    }
    stalled(k, buf, strlen(buf), size);
}

/* Newton along a parameter path t in [0, 1] from y, a state near the
 * solution at t = 0: solve there, then step towards 1, doubling the step
 * after a success and halving it after a failure (restarting from the last
 * solution), down to CONTINUATION_MIN_STEP. */
static int continuation(ts_kernel *k, double *y, newton_ws *w, path_fn path,
                        const path_ctx *pc, const ts_equilibrium_opts *o,
                        ts_equilibrium *eq, ts_err *err)
{
    path_at(k, w, path, pc, 0.0);
    int rc = newton(k, y, o->tol, o->max_iter, w, eq, err);
    eq->continuation_steps++;
    double t = 0.0, dt = 1.0;
    while (rc == TS_OK && t < 1.0) {
        if (t + dt > 1.0)
            dt = 1.0 - t;
        save_shape(k, y, w);
        path_at(k, w, path, pc, t + dt);
        rc = newton(k, y, o->tol, o->max_iter, w, eq, err);
        eq->continuation_steps++;
        if (rc == TS_OK) {
            t += dt;
            dt *= 2.0;
            continue;
        }
        if (rc == TS_ENOMEM || rc == TS_ECANCEL || rc == TS_EIO ||
            dt <= CONTINUATION_MIN_STEP)
            break;
        /* A path that keeps failing can halve its step ten times, each
         * try up to max_iter Newton iterations: bound the whole. */
        if (eq->iterations > CONTINUATION_MAX_ITER * o->max_iter) {
            /* Keep the last try's message: it gives the residual. */
            ts_err_prefix(err, "%d Newton iterations without reaching the "
                               "end of the path, more than the %d (%d times "
                               "max_iter) a solve may take; the last try: ",
                          eq->iterations, CONTINUATION_MAX_ITER * o->max_iter,
                          CONTINUATION_MAX_ITER);
            break;
        }
        dt *= 0.5;
        restore_shape(k, y, w);
        path_at(k, w, path, pc, t);
        rc = TS_OK;
    }
    /* Name the continuation only where there was one: a straight tow has
     * no turn-rate path (its first Newton solve is the whole of it). */
    if (rc != TS_OK && rc != TS_ENOMEM && rc != TS_ECANCEL && rc != TS_EIO) {
        ts_frame f;
        ts_kernel_get_frame(k, &f);
        if (path == bending_path)
            ts_err_prefix(err, "continuation in bending stiffness (EI "
                               "scaled up from %g of its value) stopped "
                               "%.4g of the way: ", pc->b0, t);
        else if (path == setpoint_path) {
            char sat[2 * TS_NAME_MAX + 96];
            saturated(k, y, sat, sizeof sat);
            ts_err_prefix(err, "continuation in the controllers' set points "
                               "(from where the loops idle to their "
                               "targets) stopped %.4g of the way%s: ", t,
                          sat);
        }
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
    /* (The state holds the vehicles' angles and controllers too.) */
    size_t ns = kr ? (size_t)ts_kernel_nstate(kr) : 0;
    double *y = kr ? calloc(ns, sizeof(double)) : NULL;
    double *dydt = kr ? malloc(ns * sizeof(double)) : NULL;
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

/* The fraction of its cable's length that link l of sys takes. */
static double link_share(const ts_system *sys, int l)
{
    const ts_cable *cb = &sys->cables[sys->links[l].cable];
    return cb->link_fraction ? cb->link_fraction[sys->links[l].index - 1]
                             : 1.0 / cb->nlinks;
}

/* A walk along a cable of the coarse system cs (directions cd[3
 * cs->nlinks]) for the unit tangent at increasing fractions s of its
 * length: linear in s between the directions at the midpoints of its
 * links, the end links' own beyond theirs (extrapolating from the last
 * two instead started the two-part tow farther from its equilibrium: the
 * shape bends hardest at its ends). O(its links) for the whole walk. */
typedef struct tangent_walk {
    const ts_system *cs;
    const double *cd;
    int a, b;         /* the coarse links around s (a -1 before the first
                         midpoint) */
    double ma, mb;    /* their midpoints' fractions */
    double end;       /* where b ends */
} tangent_walk;

static void walk_start(tangent_walk *t, const ts_system *cs,
                       const double *cd, int first)
{
    t->cs = cs;
    t->cd = cd;
    t->a = -1;
    t->b = first;
    t->ma = 0.0;
    t->end = link_share(cs, first);
    t->mb = 0.5 * t->end;
}

static void walk_tangent(tangent_walk *t, double s, double out[3])
{
    const ts_system *cs = t->cs;
    while (s > t->mb && cs->links[t->b].next >= 0) {
        t->a = t->b;
        t->ma = t->mb;
        t->b = cs->links[t->b].next;
        double f = link_share(cs, t->b);
        t->mb = t->end + 0.5 * f;
        t->end += f;
    }
    const double *db = t->cd + 3 * t->b;
    if (t->a < 0 || s >= t->mb) {
        memcpy(out, db, 3 * sizeof(double));
        return;
    }
    const double *da = t->cd + 3 * t->a;
    double w = (s - t->ma) / (t->mb - t->ma);
    for (int i = 0; i < 3; i++)
        out[i] = (1 - w) * da[i] + w * db[i];
    double nt = v3_norm(out);
    for (int i = 0; i < 3; i++)
        out[i] /= nt;
}

/* Whether every controller loop of k's vehicles is closed (a coarse
 * start copies only closed loops' states). */
static int loops_closed(const ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        for (int l = 0; l < d->nloops; l++)
            if (ts_kernel_loop_mode(k, v, l) != TS_LOOP_CLOSED)
                return 0;
    }
    return 1;
}

/* Newton's start with bending and many links (opts.coarse_above): the
 * equilibrium of a coarser copy of the system (ts_system_level, each
 * cable's links halved), solved by ts_equilibrium_solve, so recursively
 * down to the direct size, at k's frame, set points, thrust bias and
 * turn deflection; its link directions interpolated along each cable
 * onto k's links (walk_tangent: a smooth shape's to second order in
 * the link length), its vehicles' attitudes, controller states and a
 * towing vehicle's steady motion as they are (ts_equilibrium_set_bodies).
 * Sets the directions into dvec[3 nlinks], strains from a rigid copy
 * (rigid_strains) into strain[nlinks], and y at rest. Adds the coarse
 * solve's iterations, evaluations and steps to eq's. TS_OK; TS_ENOMEM;
 * TS_ECANCEL (the caller asked to stop); else the coarse solve's failure,
 * err saying why, for the caller to start otherwise. Only with every
 * loop closed (loops_closed: an open loop's frozen output is not copied).
 * Time and memory: the coarse levels', about an eighth of this level's
 * dense Newton and less. */
static int coarse_start(ts_kernel *k, const ts_equilibrium_opts *o,
                        const ts_frame *frame, double *y, double *dvec,
                        double *strain, ts_equilibrium *eq, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int nv = ts_kernel_nvehicles(k);
    double ratio;
    ts_system *cs = ts_system_level(sys, 1, &ratio, err);
    ts_kernel *kc = cs ? ts_kernel_alloc(cs, err) : NULL;
    ts_equilibrium *ec = kc ? ts_equilibrium_alloc(cs, err) : NULL;
    int *first = cs ? malloc((size_t)cs->ncables * sizeof *first) : NULL;
    int rc;
    if (!ec || !first) {
        rc = ts_fail(err, TS_ENOMEM, "equilibrium: out of memory for a "
                     "coarser copy of %d links", sys->nlinks);
        goto out;
    }
    ts_kernel_set_frame(kc, frame);
    ts_kernel_set_thrust_bias(kc, ts_kernel_thrust_bias(k));
    ts_kernel_set_turn_deflection(kc, ts_kernel_turn_deflection(k));
    for (int v = 0; v < nv; v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        for (int l = 0; l < d->nloops; l++)
            ts_kernel_set_setpoint(kc, v, l, ts_kernel_setpoint(k, v, l));
    }
    ts_equilibrium_opts oc = *o;
    oc.guess = NULL;
    rc = ts_equilibrium_solve(kc, &oc, ec, err);
    eq->iterations += ec->iterations;
    eq->evaluations += ec->evaluations;
    eq->continuation_steps += ec->continuation_steps;
    if (rc != TS_OK)
        goto out;
    for (int l = 0; l < cs->nlinks; l++)
        if (cs->links[l].index == 1)
            first[cs->links[l].cable] = l;
    for (int l0 = 0; l0 < sys->nlinks; l0++) {
        if (sys->links[l0].index != 1)
            continue;
        tangent_walk tw;
        walk_start(&tw, cs, ec->directions, first[sys->links[l0].cable]);
        double at = 0.0; /* where link l starts along its cable */
        for (int l = l0; l >= 0; l = sys->links[l].next) {
            double f = link_share(sys, l);
            walk_tangent(&tw, at + 0.5 * f, dvec + 3 * l);
            at += f;
        }
    }
    memset(y, 0, (size_t)ts_kernel_nstate(k) * sizeof(double));
    memset(strain, 0, (size_t)sys->nlinks * sizeof(double));
    if (sys->has_elastic &&
        (rc = rigid_strains(k, dvec, strain, err)) != TS_OK)
        goto out;
    ts_kernel_set_shape(k, dvec, sys->has_elastic ? strain : NULL, NULL,
                        NULL, TS_CHART_RECHART, y);
    rc = ts_equilibrium_set_bodies(k, ec, y, err);
out:
    free(first);
    ts_equilibrium_free(ec);
    ts_kernel_free(kc);
    ts_system_free(cs);
    return rc;
}


/* ------------------------------------------------------------------ */
/* Vehicles: the Newton start                                           */

/* A vehicle alone on its joint at depth zA, towed straight through the
 * water at `flow` (its velocity relative to the water, M): in a straight
 * steady tow its moment about the joint does not depend on the cable, so
 * its attitude can be solved first. Actuators are taken as settled and
 * integrators as zero (the full Newton finds them). */
typedef struct trim_par {
    ts_vehicle d;            /* the description, actuators made ideal */
    tsi_vehicle_ws *ws;
    double mass, rho, g, zA;
    ts_frame frame;          /* straight tow */
    int nfree;               /* angles solved: 3, or 2 (yaw held at 0) */
    double mscale;           /* moment scale, N m */
    double G[6];
} trim_par;

static void trim_loads(trim_par *p, const double th[3], tsi_vehicle_state *st)
{
    static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const double zero[3] = {0, 0, 0};
    double rA[3] = {0, 0, p->zA}, val[4], rate[4];
    double out[TS_VEHICLE_MAX_LOOPS], delta[TS_VEHICLE_MAX_COMPONENTS];
    tsi_vehicle_kinematics(&p->d, I3, th, zero, 0.0, rA, zero, st);
    tsi_vehicle_flow(&p->frame, &p->d, st);
    tsi_vehicle_measure(st, val, rate);
    /* The loops contribute nothing here: the set-point continuation
     * starts from the errors this trim leaves (solve_controlled). */
    int open[TS_VEHICLE_MAX_LOOPS];
    for (int l = 0; l < TS_VEHICLE_MAX_LOOPS; l++)
        open[l] = TS_LOOP_OPEN;
    tsi_control_in in = {val, rate, NULL, NULL, NULL, NULL, NULL, open, NULL,
                         1};
    tsi_vehicle_control(&p->d, &in, out, delta, NULL, NULL);
    tsi_vehicle_loads(&p->d, p->ws, p->mass, p->rho, p->g, st, delta, p->G,
                      NULL);
}

static int trim_f(const gsl_vector *x, void *par, gsl_vector *f)
{
    trim_par *p = par;
    double th[3] = {gsl_vector_get(x, 0), gsl_vector_get(x, 1),
                    p->nfree == 3 ? gsl_vector_get(x, 2) : 0.0};
    tsi_vehicle_state st;
    trim_loads(p, th, &st);
    for (int j = 0; j < p->nfree; j++)
        gsl_vector_set(f, (size_t)j, p->G[3 + j] / p->mscale);
    return isfinite(p->G[3]) ? GSL_SUCCESS : GSL_EDOM;
}

/* The attitude R[9] of vehicle body b alone in the straight tow at depth
 * zA, and the force it then pulls its node with, F[3] (M). Falls back to
 * pitch and roll only (yaw 0: a body without yaw stiffness), then to a
 * level attitude. */
static void vehicle_trim(const ts_system *sys, int b, const ts_frame *fr,
                         double zA, double R[9], double F[3])
{
    const ts_body *bd = &sys->bodies[b];
    trim_par *p = calloc(1, sizeof *p);
    double th[3] = {0, 0, 0};
    if (!p)
        goto level;
    p->d = *bd->vehicle;
    for (int c = 0; c < p->d.ncomponents; c++) {
        p->d.component[c].time_constant = 0.0;
        p->d.component[c].rate_limit = INFINITY;
    }
    p->ws = tsi_vehicle_ws_alloc(&p->d, NULL);
    if (!p->ws)
        goto level;
    p->mass = bd->mass;
    p->rho = sys->env.water_density;
    p->g = sys->env.gravity;
    p->zA = zA;
    p->frame = *fr;
    p->frame.turn_rate = 0.0;
    tsi_vehicle_state st;
    p->nfree = 3;
    trim_loads(p, th, &st);
    p->mscale = (p->mass * p->g + v3_norm(p->G)) *
                fmax(tsi_vehicle_lever(&p->d), 1e-3);
    for (p->nfree = 3; p->nfree >= 2; p->nfree--) {
        gsl_multiroot_fsolver *s =
            gsl_multiroot_fsolver_alloc(gsl_multiroot_fsolver_hybrids,
                                        (size_t)p->nfree);
        gsl_vector *x = gsl_vector_calloc((size_t)p->nfree);
        gsl_multiroot_function fn = {trim_f, (size_t)p->nfree, p};
        int ok = 0;
        if (s && x && gsl_multiroot_fsolver_set(s, &fn, x) == GSL_SUCCESS)
            for (int it = 0; it < TRIM_MAXIT; it++) {
                if (gsl_multiroot_fsolver_iterate(s) != GSL_SUCCESS)
                    break;
                if (gsl_multiroot_test_residual(s->f, TRIM_RTOL) ==
                    GSL_SUCCESS) {
                    ok = 1;
                    break;
                }
            }
        if (ok)
            for (int j = 0; j < p->nfree; j++)
                th[j] = gsl_vector_get(s->x, (size_t)j);
        gsl_vector_free(x);
        if (s)
            gsl_multiroot_fsolver_free(s);
        if (ok)
            break;
        th[0] = th[1] = th[2] = 0.0;
    }
    trim_loads(p, th, &st);
    memcpy(R, st.R, sizeof st.R);
    mat3_mul(st.R, p->G, F); /* the body pulls its node with G's force */
    tsi_vehicle_ws_free(p->ws);
    free(p);
    return;
level:
    free(p);
    memset(R, 0, 9 * sizeof(double));
    R[0] = R[4] = R[8] = 1.0;
    v3_set(F, 0, 0, bd->mass * sys->env.gravity);
}

/* The straight-tow march with every vehicle trimmed alone and pulling its
 * node (twice: the second time at the depths the first march found), into
 * directions dvec, strains and attitudes att[9 nvehicles]. Returns the
 * march's code. */
static int vehicle_start(const ts_system *sys, tsi_march *m,
                         const ts_frame *straight, double tol, int max_iter,
                         double *dvec, double *strain, double *att,
                         ts_equilibrium *eq)
{
    int nn = sys->nnodes, rc = TS_OK;
    double *F = calloc(3 * (size_t)nn, sizeof(double));
    double *x = malloc((size_t)tsi_march_nunknown(m) * sizeof(double) + 1);
    if (!F || !x) {
        free(F);
        free(x);
        return TS_ENOMEM;
    }
    double L = total_length(sys);
    for (int pass = 0; pass < 2; pass++) {
        for (int b = 0, v = 0; b < sys->nbodies; b++) {
            if (sys->bodies[b].type != TS_BODY_VEHICLE)
                continue;
            if (b == sys->tow.vehicle) {
                /* The towing vehicle starts level at the tow point. */
                static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
                memcpy(att + 9 * v, I3, sizeof I3);
                v++;
                continue;
            }
            int node = ts_system_body_node(sys, b);
            /* First pass: deep enough to be submerged; then the march's. */
            double zA = pass == 0 ? L : tsi_march_positions(m)[3 * node + 2];
            vehicle_trim(sys, b, straight, zA, att + 9 * v, F + 3 * node);
            v++;
        }
        tsi_march_set_loads(m, F);
        ts_err merr = {0};
        int it = 0;
        long ev = 0;
        rc = tsi_march_solve(m, straight, x, 1, tol, max_iter, &it, &ev,
                             &merr);
        eq->evaluations += ev;
        if (rc != TS_OK)
            break;
    }
    if (rc == TS_OK) {
        tsi_march_strains(m, strain);
        memcpy(dvec, tsi_march_directions(m),
               3 * (size_t)sys->nlinks * sizeof(double));
    }
    tsi_march_set_loads(m, NULL);
    free(F);
    free(x);
    return rc;
}

/* Shooting with continuation in turn rate: from the guess's shape at the
 * full turn rate when there is one, else (or when that fails) schedules
 * of 1, 4, 16 steps from hanging. */
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
    if (o->guess) {
        tsi_march_warm(m, o->guess, x);
        rc = tsi_march_solve(m, frame, x, 0, pos_tol, o->max_iter,
                             &eq->iterations, &eq->evaluations, err);
        eq->continuation_steps++;
        if (rc == TS_OK) {
            free(x);
            return rc;
        }
    }
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

/* ------------------------------------------------------------------ */
/* Vehicles: shooting                                                    */

/* Shooting with vehicles. A small outer root problem has for unknowns
 * every vehicle's three attitude angles and every controller state; for
 * each value of them, the march (whose unknowns are the free ends'
 * positions, as without vehicles) balances every cable with each vehicle
 * pulling its node as tsi_kernel_vehicle_pull gives at the node's marched
 * position, and its child cables starting at their points on it. The
 * outer residual is what the kernel then finds unbalanced: the vehicles'
 * angular accelerations (the moments about their joints) and the
 * controllers' rates. Each residual is one march solve, O(links); the
 * outer Jacobian has 3 per vehicle plus one per controller state
 * columns. */
typedef struct vshoot {
    ts_kernel *k;
    tsi_march *m;
    ts_frame frame;       /* the frame of the current solve */
    double *y, *f;        /* [n] the state and its f(y) */
    double *x;            /* [march nunknown] free-end positions */
    double *off;          /* [3 nlinks] starts of links on vehicles */
    double *strain;       /* [nlinks] */
    int *node_veh;        /* [nnodes] vehicle at the node, or -1 */
    int nz, *zy;          /* outer unknown i is y[zy[i]] / zscale[i], its
                             residual the row of f of y[zy[i]]'s rate */
    double *zscale, *zw;  /* and its residual's weight */
    /* A towing vehicle at the root: the outer unknowns at its x and y
     * (held at the tow point) are its steady motion's parameters, as in
     * Newton (newton_ws): zsp the speed or the speed controller's bias,
     * ztr the turn rate or the turn surface's deflection; -1 without
     * one. */
    int zsp, ztr, x_is_bias, y_is_turn;
    int nx;               /* the march's unknowns */
    double *xsave, *nsave;/* [nx], [3 nlinks]: with a towing vehicle, the
                             march's free ends and directions the outer
                             Jacobian is entered with, every difference's
                             start */
    double pos_tol;
    int max_iter;
    ts_equilibrium *eq;
    ts_err merr;          /* the last march failure */
    double *out;          /* [ts_kernel_noutput] the vehicles' outputs */
    double where_merit;   /* the outer solve's least merit above tol */
    char where[VSHOOT_WHERE_MAX]; /* where it stood then (vshoot_where) */
} vshoot;

static int vshoot_pull(void *ctx, int node, const double r[3], double F[3])
{
    vshoot *s = ctx;
    return tsi_kernel_vehicle_pull(s->k, s->node_veh[node], s->y, r, F);
}

/* The value of the towing vehicle's steady-motion parameter that outer
 * unknown i stands for (zsp or ztr), and setting it. */
static double vshoot_param(const vshoot *s, int i)
{
    ts_frame f;
    ts_kernel_get_frame(s->k, &f);
    if (i == s->ztr)
        return s->y_is_turn ? ts_kernel_turn_deflection(s->k) : f.turn_rate;
    return s->x_is_bias ? ts_kernel_thrust_bias(s->k) : f.speed;
}

static void vshoot_set_param(vshoot *s, int i, double v)
{
    ts_frame f;
    ts_kernel_get_frame(s->k, &f);
    if (i == s->ztr && s->y_is_turn)
        ts_kernel_set_turn_deflection(s->k, v);
    else if (i == s->ztr)
        f.turn_rate = v;
    else if (s->x_is_bias)
        ts_kernel_set_thrust_bias(s->k, v);
    else
        f.speed = v;
    ts_kernel_set_frame(s->k, &f);
}

/* The outer residual res[nz] at the unknowns z[nz]; the state in s->y,
 * its f(y) in s->f. With a towing vehicle the march runs in the frame of
 * its steady motion, and its cables end at its tow point where its depth
 * places it, each at its own point on the body as the attitude turns it
 * (tsi_kernel_vehicle_lever, as for a towed vehicle's child cables). */
static int vshoot_eval(vshoot *s, const double *z, double *res)
{
    ts_kernel *k = s->k;
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k);
    for (int i = 0; i < s->nz; i++) {
        if (i == s->zsp || i == s->ztr)
            vshoot_set_param(s, i, z[i] * s->zscale[i]);
        else
            s->y[s->zy[i]] = z[i] * s->zscale[i];
    }
    if (s->zsp >= 0) {
        double r0[3];
        ts_kernel_get_frame(k, &s->frame);
        ts_kernel_root_position(k, s->y, r0);
        tsi_march_set_root(s->m, r0);
    }
    for (int l = 0; l < sys->nlinks; l++)
        if (sys->links[l].up_body >= 0)
            tsi_kernel_vehicle_lever(k, s->node_veh[sys->links[l].upper],
                                     s->y, l, s->off + 3 * l);
    int it = 0;
    long ev = 0;
    ts_err_clear(&s->merr);
    int rc = tsi_march_solve(s->m, &s->frame, s->x, 0, s->pos_tol,
                             s->max_iter, &it, &ev, &s->merr);
    s->eq->evaluations += ev;
    if (rc != TS_OK)
        return rc;
    tsi_march_strains(s->m, s->strain);
    ts_kernel_set_shape(k, tsi_march_directions(s->m), s->strain, NULL, NULL,
                        TS_CHART_RECHART, s->y);
    rc = ts_kernel_eval(k, s->y, NULL, s->f);
    s->eq->evaluations++;
    if (rc != TS_OK)
        return rc;
    for (int i = 0; i < s->nz; i++) {
        int j = s->zy[i] < nq ? nq + s->zy[i] : s->zy[i];
        res[i] = s->f[j] * s->zw[i];
    }
    return TS_OK;
}

static int vshoot_f(const gsl_vector *z, void *par, gsl_vector *r)
{
    return vshoot_eval(par, z->data, r->data) == TS_OK ? GSL_SUCCESS
                                                        : GSL_EDOM;
}

/* With a towing vehicle (restore nonzero), the march restarted from the
 * state the Jacobian was entered with, so that each difference does not
 * depend on the one before (a march ends within its tolerance of where
 * it started from, and a symmetric tow would keep a lateral trace of the
 * last lateral step). */
static void vshoot_restart(vshoot *s, int restore)
{
    if (!restore)
        return;
    tsi_march_warm(s->m, s->nsave, s->x);
    memcpy(s->x, s->xsave, (size_t)s->nx * sizeof(double));
}

/* Forward differences, step NEWTON_FD_STEP of each unknown's size; with
 * a towing vehicle central ones, as Newton's: a residual even in an
 * unknown (the balances along the track in the sideslip, roll and turn
 * rate of a symmetric tow) then has an exactly zero column there, where a
 * forward difference leaves one of the step's order, which couples the
 * lateral unknowns to the residuals along the track and, where the
 * lateral problem is nearly neutral (a vehicle of little directional
 * stability), moves the solve off the straight tow to a slight turn. */
static int vshoot_fdf(const gsl_vector *z, void *par, gsl_vector *r,
                      gsl_matrix *J)
{
    vshoot *s = par;
    int nz = s->nz, central = s->zsp >= 0;
    double *zt = malloc(3 * (size_t)nz * sizeof(double)), *rt = zt + nz;
    double *rm = rt + nz;
    if (!zt)
        return GSL_ENOMEM;
    int status = GSL_SUCCESS;
    memcpy(zt, z->data, (size_t)nz * sizeof(double));
    if (central) {
        memcpy(s->xsave, s->x, (size_t)s->nx * sizeof(double));
        memcpy(s->nsave, tsi_march_directions(s->m),
               3 * (size_t)ts_kernel_system(s->k)->nlinks * sizeof(double));
    }
    for (int j = 0; j < nz && status == GSL_SUCCESS; j++) {
        zt[j] = z->data[j] + NEWTON_FD_STEP;
        vshoot_restart(s, central);
        if (vshoot_eval(s, zt, rt) != TS_OK)
            status = GSL_EDOM;
        zt[j] = z->data[j] - NEWTON_FD_STEP;
        vshoot_restart(s, central);
        if (central && status == GSL_SUCCESS &&
            vshoot_eval(s, zt, rm) != TS_OK)
            status = GSL_EDOM;
        zt[j] = z->data[j];
        for (int i = 0; i < nz && status == GSL_SUCCESS; i++) {
            double d = rt[i] - rm[i];
            if (central &&
                fabs(d) <= VSHOOT_EVEN_RTOL * fmax(fabs(rt[i]), fabs(rm[i])))
                d = 0.0; /* even in z[j] to rounding */
            gsl_matrix_set(J, (size_t)i, (size_t)j,
                           central ? d / (2 * NEWTON_FD_STEP) : rt[i]);
        }
    }
    /* Last, so that s->y and s->f are those of z. */
    vshoot_restart(s, central);
    if (status == GSL_SUCCESS && vshoot_eval(s, z->data, r->data) != TS_OK)
        status = GSL_EDOM;
    for (int j = 0; j < nz && status == GSL_SUCCESS && !central; j++)
        for (int i = 0; i < nz; i++)
            gsl_matrix_set(J, (size_t)i, (size_t)j,
                           (gsl_matrix_get(J, (size_t)i, (size_t)j) -
                            r->data[i]) / NEWTON_FD_STEP);
    free(zt);
    return status;
}

static int vshoot_df(const gsl_vector *z, void *par, gsl_matrix *J)
{
    vshoot *s = par;
    double *r = malloc((size_t)s->nz * sizeof(double));
    if (!r)
        return GSL_ENOMEM;
    gsl_vector_view rv = gsl_vector_view_array(r, (size_t)s->nz);
    int status = vshoot_fdf(z, par, &rv.vector, J);
    free(r);
    return status;
}

/* Where the outer solve stands, for the message of a failure, into
 * s->where: its merit (the kernel's relative force and weighted
 * controller residuals, as vshoot_solve judges them), the outer equation
 * whose weighted residual res[nz] is the largest, named with its value
 * in its own unit (a loop's error, a vehicle's angular acceleration, a
 * towing vehicle's force balance), and the control surfaces whose
 * command sits at its deflection limit (the usual reason a set point is
 * out of reach). Reads the kernel's last evaluation (s->y, s->f, its
 * outputs) and changes nothing: O(outer unknowns + components). */
static void vshoot_where(vshoot *s, const double *res, double merit)
{
    ts_kernel *k = s->k;
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k), nc = ts_kernel_ncontrol(k);
    int nv = ts_kernel_nvehicles(k), iw = -1;
    for (int i = 0; i < s->nz; i++)
        if (isfinite(res[i]) && (iw < 0 || fabs(res[i]) > fabs(res[iw])))
            iw = i;
    ts_kernel_outputs(k, s->out);
    char worst[224] = "";
    int zy = iw >= 0 ? s->zy[iw] : -1, fin = 1;
    if (zy >= 2 * nq) {
        /* A controller state: its rate is what is unbalanced. */
        int c = zy - 2 * nq;
        ts_control_state cs;
        ts_kernel_control_state(k, c, &cs);
        const ts_body *b = &sys->bodies[ts_kernel_vehicle_body(k, cs.vehicle)];
        const ts_vehicle *d = b->vehicle;
        double rate = s->f[zy];
        fin = isfinite(rate);
        if (cs.actuator == TS_CONTROL_SPEED) {
            snprintf(worst, sizeof worst, "the speed controller of towing "
                     "vehicle '%s', its speed error %.3g m/s", b->name,
                     rate);
        } else if (cs.actuator) {
            const ts_component *cp = &d->component[cs.index];
            snprintf(worst, sizeof worst, "the actuator of surface '%s' of "
                     "vehicle '%s', %.3g deg from its command", cp->name,
                     b->name, rate * cp->time_constant * 180 / M_PI);
        } else {
            /* A loop's integrator: its rate is the loop's error. */
            const ts_loop *lp = &d->loop[cs.index];
            int o = 0;
            for (int v = 0; v < cs.vehicle; v++) {
                const ts_vehicle *dv =
                    sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
                o += 4 + dv->nloops;
                for (int j = 0; j < dv->ncomponents; j++)
                    o += dv->component[j].control != 0;
            }
            static const char *const measure[4] = {"depth", "pitch", "roll",
                                                   "heading"};
            int m = (int)lp->measure, depth = m == TS_MEASURE_DEPTH;
            double f = depth ? 1.0 : 180 / M_PI;
            double sp = ts_kernel_setpoint(k, cs.vehicle, cs.index);
            const char *u = depth ? "m" : "deg";
            double meas = s->out[o + (m >= 0 && m < 4 ? m : 0)];
            fin = fin && isfinite(meas) && isfinite(sp);
            char target[64] = "";
            if (sp != lp->setpoint) /* on the path to the scene's */
                snprintf(target, sizeof target, " on the way to %.4g %s",
                         lp->setpoint * f, u);
            snprintf(worst, sizeof worst, "loop '%s' of vehicle '%s', its "
                     "error %.4g %s (%s %.4g %s against the set point "
                     "%.4g %s in force%s)", lp->name, b->name, rate * f, u,
                     m >= 0 && m < 4 ? measure[m] : "measure", meas * f, u,
                     sp * f, u, target);
        }
    } else if (zy >= 0) {
        int v = 0;
        while (v + 1 < nv && zy >= ts_kernel_vehicle_offset(k, v + 1))
            v++;
        int ro = ts_kernel_root_offset(k);
        double a = s->f[nq + zy];
        fin = isfinite(a);
        if (ro >= 0 && zy >= ro && zy < ro + root_npos(k)) {
            static const char *const axis[3] = {"along the track",
                                                "across the track",
                                                "vertically"};
            snprintf(worst, sizeof worst, "the force balance of towing "
                     "vehicle '%s' %s (acceleration %.3g m/s^2)",
                     sys->bodies[sys->tow.vehicle].name, axis[zy - ro], a);
        } else {
            snprintf(worst, sizeof worst, "the moment balance of vehicle "
                     "'%s' (angular acceleration %.3g rad/s^2)",
                     sys->bodies[ts_kernel_vehicle_body(k, v)].name, a);
        }
    }
    if (!fin) /* no number that is not finite is shown */
        worst[0] = '\0';
    /* The surfaces whose command (limited: an actuator's state plus its
     * lag times its rate) is at the limit. */
    char lim[160] = "";
    size_t len = 0;
    int nlim = 0, o = 0;
    for (int v = 0; v < nv; v++) {
        const ts_body *b = &sys->bodies[ts_kernel_vehicle_body(k, v)];
        const ts_vehicle *d = b->vehicle;
        int js = o + 4 + d->nloops;
        for (int j = 0; j < d->ncomponents; j++) {
            const ts_component *cp = &d->component[j];
            if (!cp->control)
                continue;
            double dl = s->out[js++];
            for (int c = 0; c < nc && cp->time_constant > 0; c++) {
                ts_control_state cs;
                ts_kernel_control_state(k, c, &cs);
                if (cs.vehicle == v && cs.actuator == 1 && cs.index == j)
                    dl = s->y[2 * nq + c] +
                         cp->time_constant * s->f[2 * nq + c];
            }
            if (cp->type == TS_COMP_BALLAST || !isfinite(cp->limit) ||
                !(fabs(dl) >= cp->limit * (1 - 1e-9)))
                continue;
            if (nlim++ < 2 && len < sizeof lim)
                len += (size_t)snprintf(lim + len, sizeof lim - len,
                                        "%s%s.%s (%.4g deg)",
                                        nlim > 1 ? ", " : "", b->name,
                                        cp->name, cp->limit * 180 / M_PI);
        }
        o = js;
    }
    if (nlim > 2 && len < sizeof lim)
        snprintf(lim + len, sizeof lim - len, " and %d more", nlim - 2);
    s->where_merit = merit;
    int w = snprintf(s->where, sizeof s->where, "%s%s%s%s%s",
             worst[0] ? ", worst in " : "", worst, nlim ? ", with " : "",
             lim,
             nlim ? (nlim > 1 ? " at their deflection limits: a set point "
                                "out of the surfaces' reach?"
                              : " at its deflection limit: a set point out "
                                "of the surfaces' reach?")
                  : "");
    if (w >= 0 && (size_t)w < sizeof s->where)
        stalled(k, s->where, (size_t)w, sizeof s->where);
}

/* The outer solve from z[nz] at the kernel's frame and set points, until
 * the kernel's verdict (force and controller residuals) is at most
 * VSHOOT_POLISH tol, or at most tol where the iterations stop improving
 * it. On success s->y is the equilibrium and z its unknowns. */
static int vshoot_solve(vshoot *s, double *z, double tol, int max_iter)
{
    ts_kernel *k = s->k;
    gsl_multiroot_function_fdf fn = {vshoot_f, vshoot_df, vshoot_fdf,
                                     (size_t)s->nz, s};
    gsl_multiroot_fdfsolver *solver = gsl_multiroot_fdfsolver_alloc(
        gsl_multiroot_fdfsolver_hybridsj, (size_t)s->nz);
    double *r = malloc(2 * (size_t)s->nz * sizeof(double)), *best = r + s->nz;
    double best_merit = INFINITY;
    int rc = TS_ECONV;
    s->where[0] = '\0';
    if (!solver || !r) {
        rc = TS_ENOMEM;
        goto out;
    }
    gsl_vector_view zv = gsl_vector_view_array(z, (size_t)s->nz);
    for (int it = 0;; it++) {
        rc = vshoot_eval(s, z, r);
        if (rc != TS_OK)
            break;
        double scale, worst = ts_kernel_unbalanced(k, &scale);
        double merit = fmax(scale > 0 ? worst / scale : worst,
                            control_residual_of(k, s->f));
        rc = TS_ECONV;
        if (!isfinite(merit))
            break;
        if (merit < best_merit) {
            best_merit = merit;
            memcpy(best, z, (size_t)s->nz * sizeof(double));
            if (merit > tol)
                vshoot_where(s, r, merit);
        } else if (best_merit <= tol) {
            break; /* no better than the best, which will do */
        }
        if (merit <= VSHOOT_POLISH * tol || it >= max_iter)
            break;
        if (it == 0 &&
            gsl_multiroot_fdfsolver_set(solver, &fn, &zv.vector) !=
                GSL_SUCCESS)
            break;
        s->eq->iterations++;
        if (gsl_multiroot_fdfsolver_iterate(solver) != GSL_SUCCESS)
            break;
        memcpy(z, solver->x->data, (size_t)s->nz * sizeof(double));
    }
    if (rc != TS_ENOMEM && best_merit <= tol) {
        memcpy(z, best, (size_t)s->nz * sizeof(double));
        rc = vshoot_eval(s, z, r);
    }
out:
    free(r);
    if (solver)
        gsl_multiroot_fdfsolver_free(solver);
    return rc;
}

/* The outer unknowns of shooting with vehicles into s (zy, zscale, zw,
 * zsp, ztr; zy and zscale hold 3 nvehicles + 3 + ncontrol): every
 * vehicle's angles (a surface ship's yaw alone), a towing vehicle's
 * position coordinates (its depth, and at its held x and y the speed or
 * bias and the turn rate or deflection, sized as Newton's), the
 * controller states. Returns their number. */
static int vshoot_layout(vshoot *s, const ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k), nc = ts_kernel_ncontrol(k), i = 0;
    s->zsp = s->ztr = -1;
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        int na = v == ts_kernel_root(k) && root_npos(k) == 2 ? 1 : 3;
        for (int j = 0; j < na; j++, i++) {
            s->zy[i] = ts_kernel_vehicle_offset(k, v) + j;
            s->zscale[i] = 1.0;
            s->zw[i] = 1.0;
        }
    }
    int ro = ts_kernel_root_offset(k);
    if (ro >= 0) {
        const ts_body *bd = &sys->bodies[sys->tow.vehicle];
        s->x_is_bias = bd->vehicle->propulsion.type == TS_PROP_SPEED &&
                       !(bd->vehicle->propulsion.ki > 0);
        s->y_is_turn = sys->tow.turn_surface >= 0;
        s->zsp = i;
        s->ztr = i + 1;
        for (int j = 0; j < root_npos(k); j++, i++) {
            s->zy[i] = ro + j;
            s->zscale[i] = 1.0; /* a depth, m */
            s->zw[i] = 1.0;
        }
        s->zscale[s->zsp] = s->x_is_bias
                                ? fmax(bd->mass * sys->env.gravity, 1.0)
                                : fmax(fabs(sys->tow.speed), 1.0);
        s->zscale[s->ztr] = 0.1; /* rad/s, or rad */
    }
    for (int c = 0; c < nc; c++, i++) {
        s->zy[i] = 2 * nq + c;
        s->zscale[i] = control_scale(k, c);
        s->zw[i] = control_weight(k, c);
    }
    return i;
}

/* How far to trust the solution z of the outer problem, with the vehicles
 * still attached to the march (doc/equilibrium.md, "How far to trust
 * it"). One outer Jacobian J at z (nz or 2 nz marches) and its LU give:
 *  - with a towing vehicle, the next outer Newton step of its steady
 *    motion's two unknowns (a PI speed controller's: its integral
 *    term's) into eq->motion_step: their solver error to first order, as
 *    Newton's newton_health gives it;
 *  - eq->condition: J's 1-norm condition (exact: J is small) times the
 *    march's (tsi_march_condition, its extra marches run with the
 *    vehicles attached), the condition of the two problems nested;
 *  - eq->shape_error: how far the next outer Newton step moves the
 *    nodes (one march at z - J^-1 r, the largest node displacement) plus
 *    the march's own shape error.
 * Leaves s->y, s->f and the march at z. Each part stays NaN when it
 * cannot be formed. */
static void vshoot_health(vshoot *s, double *z)
{
    size_t nz = (size_t)s->nz;
    const ts_system *sys = ts_kernel_system(s->k);
    size_t np = 3 * (size_t)sys->nnodes, nl = (size_t)sys->nlinks;
    gsl_matrix *J = gsl_matrix_alloc(nz, nz), *Ji = gsl_matrix_alloc(nz, nz);
    gsl_permutation *p = gsl_permutation_alloc(nz);
    gsl_vector *r = gsl_vector_alloc(nz), *dz = gsl_vector_alloc(nz);
    double *pos = malloc((np + 2 * nz) * sizeof(double));
    gsl_vector_view zv = gsl_vector_view_array(z, nz);
    int sign = 0, ok = J && Ji && p && r && dz && pos &&
                       vshoot_fdf(&zv.vector, s, r, J) == GSL_SUCCESS;
    double outer_cond = NAN, step = NAN;
    if (ok) {
        /* The march at z: every further march starts from it. */
        memcpy(s->xsave, s->x, (size_t)s->nx * sizeof(double));
        memcpy(s->nsave, tsi_march_directions(s->m), 3 * nl * sizeof(double));
        memcpy(pos, ts_kernel_positions(s->k), np * sizeof(double));
        double anorm = tsi_norm1(J->data, s->nz);
        ok = gsl_linalg_LU_decomp(J, p, &sign) == GSL_SUCCESS &&
             gsl_linalg_LU_solve(J, p, r, dz) == GSL_SUCCESS;
        if (ok && gsl_linalg_LU_invert(J, p, Ji) == GSL_SUCCESS)
            outer_cond = anorm * tsi_norm1(Ji->data, s->nz);
    }
    if (ok && s->zsp >= 0) {
        int zs = ts_kernel_speed_integrator(s->k), nq = ts_kernel_nq(s->k);
        s->eq->motion_step[0] =
            fabs(gsl_vector_get(dz, (size_t)s->zsp)) * s->zscale[s->zsp];
        s->eq->motion_step[1] =
            fabs(gsl_vector_get(dz, (size_t)s->ztr)) * s->zscale[s->ztr];
        for (int i = 0; zs >= 0 && i < s->nz; i++)
            if (s->zy[i] == 2 * nq + zs)
                s->eq->motion_step[0] =
                    sys->bodies[sys->tow.vehicle].vehicle->propulsion.ki *
                    fabs(gsl_vector_get(dz, (size_t)i)) * s->zscale[i];
    }
    if (ok) {
        /* The nodes after the next outer Newton step, then back to z
         * (from the march at z, so that z's state is as solved). */
        double *zt = pos + np, *rt = zt + nz;
        for (size_t i = 0; i < nz; i++)
            zt[i] = z[i] - gsl_vector_get(dz, i);
        vshoot_restart(s, 1);
        if (vshoot_eval(s, zt, rt) == TS_OK) {
            const double *q = ts_kernel_positions(s->k);
            step = 0.0;
            for (size_t i = 0; i < np; i++)
                step = fmax(step, fabs(q[i] - pos[i]));
        }
        vshoot_restart(s, 1);
        ok = vshoot_eval(s, z, rt) == TS_OK;
    }
    double mc = NAN, mshape = NAN;
    if (ok && tsi_march_condition(s->m, &mc, &mshape,
                                  &s->eq->evaluations) == TS_OK) {
        s->eq->condition = outer_cond * mc;
        s->eq->shape_error = step + mshape;
    }
    gsl_matrix_free(J);
    gsl_matrix_free(Ji);
    gsl_permutation_free(p);
    gsl_vector_free(r);
    gsl_vector_free(dz);
    free(pos);
}

/* A speed controller without integral gain holds its set speed through
 * the bias, which is solved: the kernel's frame then moves at that
 * speed, the tow point (M's origin) through the water at the set speed,
 * V less the current (turns have no horizontal current). */
static void hold_set_speed(ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    double sp = sys->bodies[sys->tow.vehicle].vehicle->propulsion.speed;
    double c2 = sp * sp - f.current[1] * f.current[1] -
                f.current[2] * f.current[2];
    f.speed = f.current[0] + sqrt(fmax(c2, 0.0));
    ts_kernel_set_frame(k, &f);
}

/* The equilibrium of a system with vehicles by shooting (no bending):
 * from the straight-tow march with each vehicle trimmed alone, with the
 * controllers idle at the set points that start gives (controls_start),
 * the outer solve at the frame and set points of the kernel; where that
 * fails, continuation from that start to them (turn rate and set points
 * together) in 4, then 16 steps. A towing vehicle at the root starts
 * level at the scene's tow point, at the scene's speed (or the set speed
 * its controller holds) and turn rate; its speed, or bias, and turn rate,
 * or turn deflection, are outer unknowns that no path moves (with
 * turn_by, the path moves the turn rate the deflection is solved for).
 * On TS_OK, y[n] is the equilibrium; the kernel's frame and set points
 * are then the targets again, with a towing vehicle's steady motion in
 * the frame, its bias and deflection as solved; on failure they are as
 * on entry. */
static int solve_vehicle_shooting(ts_kernel *k, tsi_march *m,
                                  const ts_frame *frame,
                                  const ts_equilibrium_opts *o,
                                  ts_equilibrium *eq, double *y, double *dydt,
                                  double *dvec, double *att, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int nc = ts_kernel_ncontrol(k), ro = ts_kernel_root_offset(k);
    int n = ts_kernel_nstate(k), nv = sys->nvehicles, nl = sys->nlinks;
    int nx = tsi_march_nunknown(m), nloops = 0;
    for (int v = 0; v < nv; v++)
        nloops += sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle->nloops;
    double bias0 = ts_kernel_thrust_bias(k);
    double turn0 = ts_kernel_turn_deflection(k);
    vshoot s = {0};
    s.k = k;
    s.m = m;
    s.eq = eq;
    s.pos_tol = SHOOT_POS_RTOL * total_length(sys);
    s.max_iter = o->max_iter;
    s.y = y;
    s.f = dydt;
    size_t maxz = 3 * (size_t)nv + 3 + (size_t)nc;
    s.x = malloc(2 * ((size_t)nx + 1) * sizeof(double));
    s.nx = nx;
    s.xsave = malloc(((size_t)nx + 1) * sizeof(double));
    s.nsave = malloc((3 * (size_t)nl + 1) * sizeof(double));
    s.off = calloc(3 * (size_t)nl, sizeof(double));
    s.strain = calloc((size_t)nl, sizeof(double));
    s.node_veh = malloc((size_t)sys->nnodes * sizeof(int));
    s.zy = malloc(maxz * sizeof(int));
    s.zscale = malloc(3 * maxz * sizeof(double));
    s.out = malloc(((size_t)ts_kernel_noutput(k) + 1) * sizeof(double));
    double *y0 = malloc((size_t)n * sizeof(double));
    double *sp = calloc(2 * (size_t)nloops + 1, sizeof(double));
    int rc = TS_ENOMEM;
    if (!s.x || !s.xsave || !s.nsave || !s.off || !s.strain ||
        !s.node_veh || !s.zy || !s.zscale || !s.out || !y0 || !sp)
        goto out;
    s.zw = s.zscale + maxz;
    double *z = s.zscale + 2 * maxz, *x0 = s.x + nx + 1;
    for (int i = 0; i < sys->nnodes; i++)
        s.node_veh[i] = -1;
    for (int v = 0; v < nv; v++)
        s.node_veh[ts_system_body_node(sys, ts_kernel_vehicle_body(k, v))] =
            v;
    s.nz = vshoot_layout(&s, k);

    /* The start, straight, the loops idle where it leaves them. */
    ts_frame f = *frame;
    f.turn_rate = 0.0;
    ts_kernel_set_frame(k, &f);
    if (s.zsp >= 0 && s.x_is_bias) {
        hold_set_speed(k);
        ts_kernel_get_frame(k, &f);
    }
    tsi_march_set_root(m, sys->tow.point);
    rc = vehicle_start(sys, m, &f, s.pos_tol, o->max_iter, dvec, s.strain,
                       att, eq);
    if (rc != TS_OK)
        goto out;
    memset(y, 0, (size_t)n * sizeof(double));
    if (ro >= 0)
        memcpy(y + ro, sys->tow.point,
               (size_t)root_npos(k) * sizeof(double));
    ts_kernel_set_shape(k, dvec, s.strain, NULL, NULL, TS_CHART_RECHART, y);
    for (int v = 0; v < nv; v++)
        ts_kernel_set_vehicle(k, v, att + 9 * v, NULL, TS_CHART_RECHART, y);
    if (nc > 0 && controls_start(k, y, sp, sp + nloops, dydt) < 0) {
        rc = TS_ENOMEM;
        goto out;
    }
    tsi_march_warm(m, dvec, x0);
    memcpy(y0, y, (size_t)n * sizeof(double));
    tsi_march_set_vehicles(m, vshoot_pull, &s, s.off);
    /* The towing vehicle's steady motion starts at the scene's turn rate
     * (an unknown), or straight (turn_by: the path's). */
    double p0[2] = {0, 0};
    if (s.zsp >= 0) {
        if (!s.y_is_turn) {
            f.turn_rate = frame->turn_rate;
            ts_kernel_set_frame(k, &f);
        }
        p0[0] = vshoot_param(&s, s.zsp);
        p0[1] = vshoot_param(&s, s.ztr);
    }

    static const int schedule[] = {1, 4, 16};
    int nsched = frame->turn_rate != 0 || nloops > 0 ? 3 : 1;
    int steps = 1, jfail = 0; /* the last path tried, its failed step */
    rc = TS_ECONV;
    for (int sc = 0; sc < nsched && rc != TS_OK; sc++) {
        steps = schedule[sc];
        memcpy(y, y0, (size_t)n * sizeof(double));
        memcpy(s.x, x0, (size_t)nx * sizeof(double));
        if (s.zsp >= 0) {
            vshoot_set_param(&s, s.zsp, p0[0]);
            vshoot_set_param(&s, s.ztr, p0[1]);
        }
        rc = TS_OK;
        for (int j = 1; j <= steps && rc == TS_OK; j++) {
            double t = (double)j / steps;
            ts_frame g;
            ts_kernel_get_frame(k, &g);
            s.frame = *frame;
            s.frame.turn_rate = frame->turn_rate * t;
            if (s.zsp >= 0) {
                /* The steady motion's unknowns stay where they are. */
                s.frame.speed = g.speed;
                if (!s.y_is_turn)
                    s.frame.turn_rate = g.turn_rate;
            }
            ts_kernel_set_frame(k, &s.frame);
            for (int v = 0, i = 0; v < nv; v++) {
                const ts_vehicle *d =
                    sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
                for (int l = 0; l < d->nloops; l++, i++)
                    ts_kernel_set_setpoint(
                        k, v, l, sp[i] + t * (sp[nloops + i] - sp[i]));
            }
            for (int i = 0; i < s.nz; i++)
                z[i] = (i == s.zsp || i == s.ztr ? vshoot_param(&s, i)
                                                  : y[s.zy[i]]) /
                       s.zscale[i];
            rc = vshoot_solve(&s, z, o->tol, o->max_iter);
            eq->continuation_steps++;
            jfail = j;
        }
    }
    if (rc == TS_OK)
        vshoot_health(&s, z);
    if (rc != TS_OK && rc != TS_ENOMEM) {
        /* Where the last path stopped: how far it got, and where its
         * failed solve stood at best (or why its march failed). */
        char path[160] = "";
        if (steps > 1)
            snprintf(path, sizeof path, ": it got %.4g of the way from "
                     "where the loops idle to their set points%s, and the "
                     "next step's solve", (double)(jfail - 1) / steps,
                     frame->turn_rate != 0 ? " and the turn rate" : "");
        else
            snprintf(path, sizeof path, ": its solve");
        char where[VSHOOT_WHERE_MAX + 96] = "";
        if (s.where[0])
            snprintf(where, sizeof where, "%s got no closer than outer "
                     "mismatch %.3g (tolerance %.3g)%s", path, s.where_merit,
                     o->tol, s.where);
        rc = ts_fail(err, TS_ECONV, "equilibrium: shooting with vehicles "
                     "did not converge (%d outer iterations)%s%s%.256s",
                     eq->iterations, where,
                     s.merr.msg[0] ? "; its last march: " : "", s.merr.msg);
    }
out:
    if (rc == TS_ENOMEM)
        ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
    tsi_march_set_vehicles(m, NULL, NULL, NULL);
    if (rc == TS_OK && ro >= 0) {
        /* The towing vehicle's steady motion as solved. */
        ts_frame g;
        ts_kernel_get_frame(k, &g);
        f = *frame;
        f.speed = g.speed;
        f.turn_rate = g.turn_rate;
        ts_kernel_set_frame(k, &f);
    } else {
        ts_kernel_set_frame(k, frame);
        if (ro >= 0) {
            ts_kernel_set_thrust_bias(k, bias0);
            ts_kernel_set_turn_deflection(k, turn0);
        }
    }
    free(s.x);
    free(s.xsave);
    free(s.nsave);
    free(s.off);
    free(s.strain);
    free(s.node_veh);
    free(s.zy);
    free(s.zscale);
    free(s.out);
    free(y0);
    free(sp);
    return rc;
}

/* Record the shooting result in y (*rc: record's code) and accept it
 * when the kernel's force and controller residuals meet tol: then eq is
 * shooting's, with the march's condition (m non-NULL; with vehicles
 * vshoot_health has set it), and the return 1. */
static int shooting_accept(ts_kernel *k, tsi_march *m, const double *y,
                           ts_equilibrium *eq, double *dydt, double tol,
                           int *rc)
{
    if ((*rc = record(k, y, eq, dydt)) != TS_OK || eq->residual > tol ||
        eq->control_residual > tol)
        return 0;
    eq->method = TS_EQ_SHOOTING;
    eq->converged = 1;
    if (m)
        tsi_march_condition(m, &eq->condition, &eq->shape_error,
                            &eq->evaluations);
    return 1;
}

/* The error of a shooting run that is the answer (method shooting, or a
 * failure Newton cannot mend): its own message serr, or, when it
 * converged, the kernel's residual against tol. */
static int shooting_refuse(int rc, const ts_err *serr,
                           const ts_equilibrium *eq, double tol, ts_err *err)
{
    if (err)
        *err = *serr;
    if (rc == TS_OK)
        rc = ts_fail(err, TS_ECONV,
                     "equilibrium: shooting converged but the kernel "
                     "residual is %.3g (target %.3g)",
                     eq->residual, tol);
    return rc;
}

/* The message of a vehicle scene whose shooting (serr) and Newton, its
 * fallback (err), both failed: both reasons, shooting's first, in err.
 * Shooting's takes at most half the message (VSHOOT_WHERE_MAX keeps it
 * shorter); Newton's is cut to what is left, marked "...". */
static void both_failed(const ts_err *serr, ts_err *err)
{
    if (!err)
        return;
    char newton[TS_ERR_MSG_MAX];
    memcpy(newton, err->msg, sizeof newton);
    newton[sizeof newton - 1] = '\0';
    size_t size = sizeof err->msg;
    int n = snprintf(err->msg, size, "%.*s; then Newton, the fallback, "
                     "failed too: ", (int)(size / 2), serr->msg);
    if (n < 0 || (size_t)n >= size - 4)
        return;
    size_t room = size - 1 - (size_t)n, len = strlen(newton);
    if (len > room)
        snprintf(err->msg + n, size - (size_t)n, "%.*s...",
                 (int)(room - 3), newton);
    else
        memcpy(err->msg + n, newton, len + 1);
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
    eq->motion_step[0] = eq->motion_step[1] = NAN;
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
    ts_motion_bound mb = {fabs(frame.speed), fabs(frame.turn_rate), 0, 0,
                          0, 0};
    int lrc = ts_system_check_loads(sys, &mb, err);
    if (lrc != TS_OK) {
        ts_err_prefix(err, "equilibrium: ");
        return lrc;
    }

    int nl = sys->nlinks, nq = ts_kernel_nq(k), rc;
    int n = ts_kernel_nstate(k), nv = sys->nvehicles, nloops = 0;
    for (int b = 0; b < sys->nbodies; b++)
        if (sys->bodies[b].vehicle)
            nloops += sys->bodies[b].vehicle->nloops;
    /* The set points in force on entry are the targets; the kernel's
     * steady flag is restored on exit. */
    double *sp0 = calloc((size_t)nloops + 1, sizeof(double));
    double *sp1 = calloc((size_t)nloops + 1, sizeof(double));
    double *sp_entry = calloc((size_t)nloops + 1, sizeof(double));
    for (int v = 0, i = 0; sp_entry && v < nv; v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        for (int l = 0; l < d->nloops; l++, i++)
            sp_entry[i] = ts_kernel_setpoint(k, v, l);
    }
    double *y = calloc((size_t)n, sizeof(double));
    double *dydt = malloc((size_t)n * sizeof(double));
    double *dvec = malloc((3 * (size_t)nl + 1) * sizeof(double));
    double *strain = calloc((size_t)nl + 1, sizeof(double));
    double *att = malloc((9 * (size_t)nv + 1) * sizeof(double));
    /* (No march for a towing vehicle alone.) */
    tsi_march *m = nl > 0 ? tsi_march_alloc(sys, err) : NULL;
    newton_ws w = {0};
    int ro = ts_kernel_root_offset(k);
    if (y && ro >= 0)
        memcpy(y + ro, sys->tow.point, (size_t)root_npos(k) * sizeof(double));
    if (!m && nl > 0) {
        rc = err ? err->code : TS_ENOMEM; /* the march named its size */
        goto out;
    }
    if (!y || !dydt || !dvec || !strain || !att || !sp0 || !sp1 ||
        !sp_entry) {
        rc = ts_fail_nomem(err, 8.0 * (4.0 * nq + 4.0 * nl), "fewer links",
                           "equilibrium: out of memory for the state of %d "
                           "links", nl);
        goto out;
    }

    /* Fast path. */
    int have_guess = 0, vshoot_failed = 0;
    ts_err serr = {0}; /* shooting's failure */
    if (!sys->has_bending && nv == 0 && o.method != TS_EQ_NEWTON) {
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
            if (shooting_accept(k, m, y, eq, dydt, o.tol, &rc))
                goto out;
        }
        if (o.method == TS_EQ_SHOOTING || rc == TS_ESINGULAR) {
            rc = shooting_refuse(rc, &serr, eq, o.tol, err);
            goto out;
        }
    }

    /* Vehicles without bending: shooting, the vehicles' attitudes, a
     * towing vehicle's depth and steady motion and the controllers as
     * outer unknowns; else (or when it fails, or a towing vehicle without
     * cables) Newton. */
    if (!sys->has_bending && nv > 0 && m && o.method != TS_EQ_NEWTON) {
        ts_kernel_set_steady(k, 1);
        rc = solve_vehicle_shooting(k, m, &frame, &o, eq, y, dydt, dvec, att,
                                    &serr);
        if (rc == TS_OK &&
            shooting_accept(k, NULL, y, eq, dydt, o.tol, &rc))
            goto out;
        if (o.method == TS_EQ_SHOOTING || rc == TS_ENOMEM) {
            rc = shooting_refuse(rc, &serr, eq, o.tol, err);
            goto out;
        }
        /* Why shooting failed, for the message should Newton fail too. */
        shooting_refuse(rc, &serr, eq, o.tol, &serr);
        vshoot_failed = 1;
        /* Newton starts afresh, at the targets. */
        ts_kernel_set_frame(k, &frame);
        for (int v = 0, i = 0; v < nv; v++) {
            const ts_vehicle *d =
                sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
            for (int l = 0; l < d->nloops; l++, i++)
                ts_kernel_set_setpoint(k, v, l, sp_entry[i]);
        }
        memset(y, 0, (size_t)n * sizeof(double));
        if (ro >= 0)
            memcpy(y + ro, sys->tow.point,
                   (size_t)root_npos(k) * sizeof(double));
    }

    /* General Newton, from the straight-tow march (no bending) or from the
     * shooting result, with continuation in turn rate. */
    eq->method = TS_EQ_NEWTON;
    if (!newton_ws_alloc(&w, k)) {
        int nj = nq + ts_kernel_ncontrol(k);
        rc = ts_fail_nomem(err, 8.0 * nj * (double)nj, "fewer links "
                           "(Newton is used for bending stiffness, and "
                           "where shooting fails)", "equilibrium: out of "
                           "memory for a %d x %d Newton Jacobian", nj, nj);
        goto out;
    }
    w.progress = o.progress;
    w.progress_data = o.progress_data;
    if (ro >= 0 && w.x_is_bias)
        hold_set_speed(k); /* the bias is solved */
    rc = TS_ECONV;
    /* Actuators settle smoothly: no rate limit in a steady state. */
    ts_kernel_set_steady(k, 1);
    if (!o.guess && !have_guess && sys->has_bending &&
        o.coarse_above > 0 && nl > o.coarse_above &&
        ts_system_can_coarsen(sys) && loops_closed(k)) {
        /* Many links with bending: from a coarser copy's equilibrium;
         * should that fail, the continuation below. */
        rc = coarse_start(k, &o, &frame, y, dvec, strain, eq, err);
        if (rc == TS_ENOMEM || rc == TS_ECANCEL || rc == TS_EIO)
            goto out;
        if (rc == TS_OK) {
            rc = newton(k, y, o.tol, o.max_iter, &w, eq, err);
            eq->continuation_steps++;
        }
    }
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
    if (rc != TS_OK && rc != TS_ENOMEM && rc != TS_ECANCEL &&
        rc != TS_EIO) {
        /* From the straight-tow march (bending ignored), or hanging. */
        ts_frame straight = frame;
        straight.turn_rate = 0;
        ts_err merr = {0};
        int it = 0;
        long ev = 0;
        double *x = m ? malloc((size_t)tsi_march_nunknown(m) *
                               sizeof(double))
                      : NULL;
        int mrc = TS_ECONV;
        if (nv > 0 && m)
            mrc = vehicle_start(sys, m, &straight,
                                SHOOT_POS_RTOL * total_length(sys),
                                o.max_iter, dvec, strain, att, eq);
        else if (x)
            mrc = tsi_march_solve(m, &straight, x, 1,
                                  SHOOT_POS_RTOL * total_length(sys),
                                  o.max_iter, &it, &ev, &merr);
        if (mrc == TS_OK && nv == 0) {
            tsi_march_strains(m, strain);
            memcpy(dvec, tsi_march_directions(m),
                   3 * (size_t)nl * sizeof(double));
        } else if (mrc != TS_OK) {
            for (int l = 0; l < nl; l++) {
                dvec[3 * l] = dvec[3 * l + 1] = 0.0;
                dvec[3 * l + 2] = 1.0;
                strain[l] = 0.0;
            }
            for (int v = 0; v < nv; v++) {
                double *R = att + 9 * v;
                memset(R, 0, 9 * sizeof(double));
                R[0] = R[4] = R[8] = 1.0;
            }
        }
        free(x);
        eq->evaluations += ev;
        ts_kernel_set_shape(k, dvec, strain, NULL, NULL, TS_CHART_RECHART, y);
        for (int v = 0; v < nv; v++)
            ts_kernel_set_vehicle(k, v, att + 9 * v, NULL, TS_CHART_RECHART,
                                  y);
        memset(y + nq, 0, (size_t)nq * sizeof(double));
        /* Turn rate from 0 with bending nearly off, then bending up;
         * with controllers, first their set points from where the loops
         * are idle to their targets, straight (doc/equilibrium.md). */
        double b0 = sys->has_bending ? BENDING_START : 1.0;
        path_ctx pc = {k, frame, b0, NULL, NULL};
        ts_kernel_set_bending_scale(k, b0);
        rc = TS_OK;
        if (ts_kernel_ncontrol(k) > 0 &&
            controls_start(k, y, sp0, sp1, dydt) < 0)
            rc = ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
        if (rc == TS_OK && nloops > 0) {
            pc.sp0 = sp0;
            pc.sp1 = sp1;
            rc = continuation(k, y, &w, setpoint_path, &pc, &o, eq, err);
        }
        /* (A towing vehicle's turn rate is an unknown, which the path
         * leaves alone: path_at.) */
        if (rc == TS_OK)
            rc = continuation(k, y, &w, turn_path, &pc, &o, eq, err);
        if (rc == TS_OK && sys->has_bending)
            rc = continuation(k, y, &w, bending_path, &pc, &o, eq, err);
        ts_kernel_set_bending_scale(k, 1.0);
        if (ro < 0)
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
        eq->converged = eq->residual <= o.tol &&
                        eq->control_residual <= o.tol;
    else if (vshoot_failed && rc != TS_ENOMEM && rc != TS_ECANCEL &&
             rc != TS_EIO)
        both_failed(&serr, err);

out:
    ts_kernel_set_frame(k, &frame);
    if (ro >= 0 && rc == TS_OK) {
        /* The kernel is left at the towing vehicle's steady motion. */
        ts_frame f = frame;
        f.speed = eq->speed;
        f.turn_rate = eq->turn_rate;
        ts_kernel_set_frame(k, &f);
        ts_kernel_set_thrust_bias(k, eq->thrust_bias);
        ts_kernel_set_turn_deflection(k, eq->turn_deflection);
    }
    newton_ws_free(&w);
    tsi_march_free(m);
    free(y);
    free(dydt);
    free(dvec);
    free(strain);
    free(att);
    ts_kernel_set_steady(k, 0);
    for (int v = 0, i = 0; sp_entry && v < nv; v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        for (int l = 0; l < d->nloops; l++, i++)
            ts_kernel_set_setpoint(k, v, l, sp_entry[i]);
    }
    free(sp0);
    free(sp1);
    free(sp_entry);
    if (rc == TS_OK && !eq->converged)
        rc = ts_fail(err, TS_ECONV,
                     "equilibrium: not converged, relative residual %.3g "
                     "(target %.3g)",
                     eq->residual, o.tol);
    if (rc == TS_OK)
        ts_err_clear(err); /* a failed first attempt leaves no message */
    return rc;
}

double ts_equilibrium_strain(const ts_system *sys, const ts_equilibrium *eq,
                             int link)
{
    const ts_link *L = &sys->links[link];
    return L->elastic && L->ea > 0 ? eq->tensions[link] / L->ea : 0.0;
}

double ts_equilibrium_cable_length(const ts_system *sys,
                                   const ts_equilibrium *eq, int c)
{
    double len = 0;
    for (int l = 0; l < sys->nlinks; l++)
        if (sys->links[l].cable == c)
            len += sys->links[l].length *
                   (1.0 + ts_equilibrium_strain(sys, eq, l));
    return len;
}
