/* test_equilibrium.c: steady states (towstab/equilibrium.h) against
 * references that do not come from the solver itself.
 *
 *  1. No flow (V = 0): the cable hangs straight down and each link carries
 *     the wet weight below its midpoint (lumped model), also across the
 *     surface and through a branch point; the top tension is the whole wet
 *     weight.
 *  2. Critical angle: with Cdt = 0 and no end body every link lies at the
 *     angle phi with w cos(phi) = 1/2 rho Cdn d V^2 sin(phi)^2 (root found
 *     here with GSL); with a heavy end body the top link approaches phi
 *     monotonically as the cable gets longer.
 *  3. Newton from a perturbed shape (the march shape with both angles of
 *     every link moved by 0.1 rad; and the hanging shape) converges from
 *     that start, without falling back to the march, and agrees with
 *     marching/shooting for straight tows: submerged, tow point above
 *     water, branched, current along x.
 *  4. Omega -> -Omega mirrors y, for a single cable and the branched tree.
 *  5. Force balance at a massless junction (straight and turning).
 *  6. Continuity through the surface: tow-point depth swept across z = 0;
 *     node moves and shape changes per step halve with the step.
 *  7. Failures: no convergence (TS_ECONV with the residual reached) and the
 *     requests the model refuses (TS_EDOMAIN, TS_EINVAL, TS_ESINGULAR).
 *  8. Continuation: started from a neighbouring equilibrium (opts.guess),
 *     the same equilibrium as from a cold start, in fewer evaluations.
 * Each check states its tolerance and the reason for it. */
#include "towstab/equilibrium.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tmodel.h"

#define FT 0.3048
#define INCH 0.0254
#define LB 0.45359237

/* ---- building systems ------------------------------------------------ */

typedef struct cable_def {
    const char *name;
    int from, to;
    double length, diameter, mpl;
    int nlinks;
    double cdn, cdt, can, ei;
} cable_def;

typedef struct body_def {
    const char *name;
    ts_body_type type;
    double diameter, mass, cd, ca;
} body_def;

static ts_system *build(int nc, const cable_def *cd, int nb,
                        const body_def *bd, double rho, double speed,
                        double turn, double tow_z)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(nc, nb, &err);
    if (!s)
        return NULL;
    snprintf(s->name, sizeof s->name, "test");
    s->env.water_density = rho;
    s->env.gravity = 9.80665;
    s->tow.speed = speed;
    s->tow.turn_rate = turn;
    s->tow.point[0] = 0.13;
    s->tow.point[1] = -0.07;
    s->tow.point[2] = tow_z;
    for (int i = 0; i < nc; i++) {
        ts_cable *c = &s->cables[i];
        snprintf(c->name, sizeof c->name, "%s", cd[i].name);
        c->from_body = cd[i].from;
        c->to_body = cd[i].to;
        c->length = cd[i].length;
        c->diameter = cd[i].diameter;
        c->mass_per_length = cd[i].mpl;
        c->nlinks = cd[i].nlinks;
        c->cdn = cd[i].cdn;
        c->cdt = cd[i].cdt;
        c->can = cd[i].can;
        c->ei = cd[i].ei;
    }
    for (int b = 0; b < nb; b++) {
        ts_body *o = &s->bodies[b];
        snprintf(o->name, sizeof o->name, "%s", bd[b].name);
        o->type = bd[b].type;
        o->diameter = bd[b].diameter;
        o->mass = bd[b].mass;
        o->cd = bd[b].cd;
        o->ca = bd[b].ca;
    }
    if (ts_system_build(s, &err) != TS_OK) {
        printf("build failed: %s\n", err.msg);
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* Kamman example 1 (doc/model.md section 9) in SI, our coefficients. */
static ts_system *ex1(double tow_z, double speed)
{
    cable_def c = {"cable", -1, 0, 100 * FT, INCH, LB / FT, 20,
                   1.2, 0.01, 1.0, 0};
    body_def b = {"sphere", TS_BODY_SPHERE, 10 * INCH, 50 * LB, 0.5, 0.5};
    return build(1, &c, 1, &b, 1025.9, speed, 0, tow_z);
}

/* Kamman example 2: lead to a massless junction, two branches. */
static ts_system *ex2(double turn)
{
    double d = 0.163 * INCH, mpl = 0.008979 * LB / FT;
    cable_def c[3] = {{"lead", -1, 0, 3 * FT, d, mpl, 10, 1.2, 0.01, 1.0, 0},
                      {"upper", 0, 1, 3 * FT, d, mpl, 10, 1.2, 0.01, 1.0, 0},
                      {"lower", 0, 2, 1.8 * FT, d, mpl, 6, 1.2, 0.01, 1.0,
                       0}};
    body_def b[3] = {{"branch", TS_BODY_JUNCTION, 0, 0, 0, 0},
                     {"sphere_upper", TS_BODY_SPHERE, 2 * INCH, 0.246 * LB,
                      0.5, 0.5},
                     {"sphere_lower", TS_BODY_SPHERE, 2 * INCH, 0.492 * LB,
                      0.5, 0.5}};
    return build(3, c, 3, b, 1025.9, 2.5 * FT, turn, 0.0);
}

/* Kamman example 3: 6 ft of the example-2 cable and one sphere. */
static ts_system *ex3(double turn)
{
    cable_def c = {"cable", -1, 0, 6 * FT, 0.163 * INCH, 0.008979 * LB / FT,
                   20, 1.2, 0.01, 1.0, 0};
    body_def b = {"sphere", TS_BODY_SPHERE, 2 * INCH, 0.246 * LB, 0.5, 0.5};
    return build(1, &c, 1, &b, 1025.9, 2.5 * FT, turn, 0.0);
}

static double total_length(const ts_system *s)
{
    double L = 0;
    for (int l = 0; l < s->nlinks; l++)
        L += s->links[l].length;
    return L;
}

/* Solve with a method (and an optional Newton guess); prints the error. */
static ts_equilibrium *solve(const ts_system *s, ts_eq_method m,
                             const double *guess, int *rc_out)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = m;
    o.guess = guess;
    int rc = ts_equilibrium_solve(k, &o, eq, &err);
    if (rc != TS_OK)
        printf("     solve (%s): %s\n", ts_eq_method_name(m), err.msg);
    if (rc_out)
        *rc_out = rc;
    ts_kernel_free(k);
    return eq;
}

static double max_pos_diff(const ts_equilibrium *a, const ts_equilibrium *b,
                           int mirror)
{
    double m = 0;
    for (int i = 0; i < a->nnodes; i++)
        for (int j = 0; j < 3; j++) {
            double bj = b->positions[3 * i + j];
            if (mirror && j == 1)
                bj = -bj; /* mirrored about the plane y = 0 */
            double d = fabs(a->positions[3 * i + j] - bj);
            if (!(d <= m))
                m = d;
        }
    return m;
}

/* ---- 1. no flow ------------------------------------------------------ */

static void check_hanging(const char *what, const ts_system *s)
{
    int rc;
    ts_equilibrium *eq = solve(s, TS_EQ_AUTO, NULL, &rc);
    CHECK(rc == TS_OK && eq->converged, "hanging %s: converged", what);
    size_t nl = (size_t)s->nlinks, nn = (size_t)s->nnodes;
    double dmax = 0;
    for (size_t l = 0; l < nl; l++) {
        const double *n = eq->directions + 3 * l;
        dmax = fmax(dmax, fmax(fabs(n[0]), fmax(fabs(n[1]),
                                                fabs(n[2] - 1))));
    }
    /* One balance per link along an exactly vertical load: rounding. */
    CHECK(dmax <= 1e-12, "hanging %s: every link along (0,0,1), max "
                         "deviation %.3g <= 1e-12", what, dmax);
    /* Wet weight of each link and body at its (vertical) position. */
    double g = s->env.gravity, rho = s->env.water_density;
    double *below = calloc(nn, sizeof(double)); /* at each node */
    double *wl = calloc(nl, sizeof(double));
    double *zn = calloc(nn, sizeof(double));
    zn[0] = s->tow.point[2];
    for (size_t l = 0; l < nl; l++) {
        const ts_link *L = &s->links[l];
        zn[L->lower] = zn[L->upper] + L->length;
        double sfrac = link_sub(zn[L->upper], zn[L->lower]);
        wl[l] = (L->mass - sfrac * rho * M_PI * L->diameter * L->diameter /
                               4 * L->length) * g;
    }
    for (size_t i = 1; i < nn; i++) {
        int b = s->nodes[i].body;
        if (b < 0)
            continue;
        const ts_body *bd = &s->bodies[b];
        below[i] = bd->mass * g;
        if (bd->type == TS_BODY_SPHERE)
            below[i] -= sphere_sub(zn[i], bd->diameter) * rho * g * M_PI *
                        pow(bd->diameter, 3) / 6;
    }
    /* Links in reverse order: everything below a node is known when its
     * link is reached. */
    double worst = 0;
    for (int l = s->nlinks - 1; l >= 0; l--) {
        const ts_link *L = &s->links[l];
        double want = 0.5 * wl[l] + below[L->lower];
        worst = fmax(worst, fabs(eq->tensions[l] - want) / fabs(want));
        below[L->upper] += wl[l] + below[L->lower];
    }
    /* Sums of a few dozen terms: 1e-12 relative is rounding. */
    CHECK(worst <= 1e-12, "hanging %s: link tension = wet weight below its "
                          "midpoint, worst rel diff %.3g <= 1e-12", what,
          worst);
    CHECK_REL(eq->top_tension, below[0], 1e-12, "hanging: top tension = "
                                                "whole wet weight");
    double pmax = 0;
    for (size_t i = 0; i < nn; i++)
        pmax = fmax(pmax, fabs(eq->positions[3 * i + 2] - zn[i]));
    CHECK(pmax <= 1e-12 * total_length(s),
          "hanging %s: node depths = tow depth + length above (%.3g m)",
          what, pmax);
    free(below);
    free(wl);
    free(zn);
    ts_equilibrium_free(eq);
}

static void test_hanging(void)
{
    ts_system *s = ex1(0.37, 0);
    if (s)
        check_hanging("ex1, submerged", s);
    ts_system_free(s);
    /* Tow point 7.3 m above water: links in air, one cut by the surface. */
    s = ex1(-7.3, 0);
    if (s)
        check_hanging("ex1, across the surface", s);
    ts_system_free(s);
    /* A branched tree; its junction has a mass of its own. */
    s = ex2(0);
    if (s) {
        s->tow.speed = 0;
        s->bodies[0].mass = 0.0173;
        ts_system_build(s, NULL);
        check_hanging("ex2, branched", s);
    }
    ts_system_free(s);
}

/* ---- 2. critical angle ------------------------------------------------ */

typedef struct crit_params {
    double w, q; /* wet weight per length N/m, 1/2 rho Cdn d V^2 N/m */
} crit_params;

static double crit_f(double phi, void *p)
{
    const crit_params *c = p;
    return c->w * cos(phi) - c->q * sin(phi) * sin(phi);
}

/* The critical angle from the horizontal, by Brent's method on (0, pi/2),
 * where w cos(phi) falls and q sin^2(phi) rises: one root. */
static double critical_angle(double w, double q)
{
    crit_params c = {w, q};
    gsl_function F = {crit_f, &c};
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    gsl_root_fsolver_set(s, &F, 0.0, M_PI / 2);
    double phi = NAN;
    int status = GSL_CONTINUE;
    for (int it = 0; it < 200 && status == GSL_CONTINUE; it++) {
        gsl_root_fsolver_iterate(s);
        phi = gsl_root_fsolver_root(s);
        status = gsl_root_test_interval(gsl_root_fsolver_x_lower(s),
                                        gsl_root_fsolver_x_upper(s), 0,
                                        1e-15);
    }
    gsl_root_fsolver_free(s);
    return phi;
}

static void test_critical_angle(void)
{
    const double rho = 1025.3, d = 0.0213, mpl = 1.13, cdn = 1.37, V = 1.83;
    double w = (mpl - rho * M_PI * d * d / 4) * 9.80665;
    double phi = critical_angle(w, 0.5 * rho * cdn * d * V * V);
    printf("     critical angle %.12f deg\n", phi * 180 / M_PI);
    static const ts_eq_method methods[2] = {TS_EQ_SHOOTING, TS_EQ_NEWTON};
    for (int mi = 0; mi < 2; mi++) {
        cable_def c = {"bare", -1, -1, 97.3, d, mpl, 25, cdn, 0.0, 1.0, 0};
        ts_system *s = build(1, &c, 0, NULL, rho, V, 0, 0.5);
        if (!s)
            continue;
        int rc;
        ts_equilibrium *eq = solve(s, methods[mi], NULL, &rc);
        double worst = 0, side = 0;
        for (int l = 0; l < s->nlinks; l++) {
            const double *n = eq->directions + 3 * l;
            worst = fmax(worst, fabs(atan2(n[2], -n[0]) - phi));
            side = fmax(side, fabs(n[1]));
        }
        /* The lumped balance puts every link exactly at phi (each link's
         * load is along it there): the solver's force residual 1e-10
         * moves angles by about that much. */
        CHECK(rc == TS_OK && worst <= 1e-10 && side <= 1e-12,
              "critical angle (%s): all 25 links at phi, max |angle - phi| "
              "%.3g rad <= 1e-10, |n_y| %.2g", ts_eq_method_name(methods[mi]),
              worst, side);
        ts_equilibrium_free(eq);
        ts_system_free(s);
    }
    /* A heavy sphere at the end: links of 4.1 m, longer and longer cable. */
    double prev = INFINITY, first = 0;
    int monotone = 1;
    for (int i = 0; i < 6; i++) {
        int nlinks = 5 << i;
        cable_def c = {"bare", -1, 0, 4.1 * nlinks, d, mpl, nlinks, cdn, 0.0,
                       1.0, 0};
        body_def b = {"weight", TS_BODY_SPHERE, 0.3, 87.0, 0.6, 0.5};
        ts_system *s = build(1, &c, 1, &b, rho, V, 0, 0.5);
        if (!s)
            continue;
        int rc;
        ts_equilibrium *eq = solve(s, TS_EQ_AUTO, NULL, &rc);
        const double *n = eq->directions;
        double err = fabs(atan2(n[2], -n[0]) - phi);
        printf("     %4d links, %7.1f m: top link %.6f deg, |error| %.3g "
               "rad\n", nlinks, 4.1 * nlinks,
               atan2(n[2], -n[0]) * 180 / M_PI, err);
        CHECK(rc == TS_OK && eq->converged, "heavy end, %d links: converged",
              nlinks);
        if (i == 0)
            first = err;
        if (!(err < prev))
            monotone = 0;
        prev = err;
        ts_equilibrium_free(eq);
        ts_system_free(s);
    }
    CHECK(monotone && prev < 0.1 * first,
          "heavy end: the top link's error falls monotonically with length, "
          "to %.3g of its value at 20 m (< 0.1)", prev / first);
}

/* ---- 3. Newton against shooting --------------------------------------- */

static void compare_methods(const char *what, const ts_system *s)
{
    int rc1, rc2;
    ts_equilibrium *a = solve(s, TS_EQ_SHOOTING, NULL, &rc1);
    CHECK(rc1 == TS_OK && a->converged && a->method == TS_EQ_SHOOTING &&
              a->residual <= 1e-10,
          "%s: shooting converged (residual %.3g)", what, a->residual);
    int nl = s->nlinks;
    /* Newton starts from the march shape with both angles of every link
     * moved by 0.1 rad. */
    double *guess = malloc(3 * (size_t)nl * sizeof(double));
    for (int l = 0; l < nl; l++) {
        double t1, t2;
        ts_direction_angles(a->directions + 3 * l, &t1, &t2);
        t1 += 0.1;
        t2 += 0.1;
        guess[3 * l] = -cos(t1) * cos(t2);
        guess[3 * l + 1] = -sin(t2);
        guess[3 * l + 2] = sin(t1) * cos(t2);
    }
    ts_equilibrium *b = solve(s, TS_EQ_NEWTON, guess, &rc2);
    /* From the guess itself: one continuation step, no fall-back to the
     * march start. */
    CHECK(rc2 == TS_OK && b->converged && b->method == TS_EQ_NEWTON &&
              b->residual <= 1e-10 && b->continuation_steps == 1,
          "%s: Newton from the perturbed shape converged (%d iterations, "
          "%d continuation step(s), residual %.3g)", what, b->iterations,
          b->continuation_steps, b->residual);
    double L = total_length(s), d = max_pos_diff(a, b, 0);
    /* Both satisfy the forces to 1e-10 of the largest; positions, summed
     * over the links, agree to 1e-8 of the cable length. */
    CHECK(d <= 1e-8 * L, "%s: node positions agree, max %.3g m <= 1e-8 x "
                         "%.3f m", what, d, L);
    double dt = 0, tmax = 0;
    for (int l = 0; l < nl; l++) {
        dt = fmax(dt, fabs(a->tensions[l] - b->tensions[l]));
        tmax = fmax(tmax, fabs(a->tensions[l]));
    }
    CHECK(dt <= 1e-8 * tmax, "%s: tensions agree, max %.3g N <= 1e-8 x "
                             "%.4g N", what, dt, tmax);
    /* eq->y reproduces the reported shape in a fresh evaluation, once the
     * kernel's charts are those of the solve. */
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    ts_equilibrium *c = ts_equilibrium_alloc(s, NULL);
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = TS_EQ_NEWTON;
    o.guess = guess;
    ts_equilibrium_solve(k, &o, c, NULL);
    double *dydt = malloc(4 * (size_t)nl * sizeof(double));
    ts_kernel_eval(k, c->y, NULL, dydt);
    double dp = 0;
    for (int i = 0; i < 3 * s->nnodes; i++)
        dp = fmax(dp, fabs(ts_kernel_positions(k)[i] - c->positions[i]));
    CHECK(dp <= 1e-14 * L, "%s: eq->y re-evaluates to eq->positions (%.2g m)",
          what, dp);
    free(dydt);
    ts_equilibrium_free(c);
    ts_kernel_free(k);
    free(guess);
    ts_equilibrium_free(a);
    ts_equilibrium_free(b);
}

static void test_newton_vs_shooting(void)
{
    ts_system *s = ex1(0, 8.345 * FT);
    if (s)
        compare_methods("ex1 submerged", s);
    ts_system_free(s);
    s = ex1(-35 * FT, 8.345 * FT);
    if (s)
        compare_methods("ex1 tow point above water", s);
    ts_system_free(s);
    s = ex2(0);
    if (s)
        compare_methods("ex2 branched", s);
    ts_system_free(s);
    s = ex1(1.7, 1.9);
    if (s) {
        s->env.current[0] = 0.63; /* along x: 1.27 m/s through the water */
        s->env.current[2] = 0;
        compare_methods("ex1 with a current along x", s);
    }
    ts_system_free(s);

    /* Newton from the hanging shape, straight down. */
    s = ex1(0, 8.345 * FT);
    if (s) {
        double *guess = calloc(3 * (size_t)s->nlinks, sizeof(double));
        for (int l = 0; l < s->nlinks; l++)
            guess[3 * l + 2] = 1;
        int rc1, rc2;
        ts_equilibrium *a = solve(s, TS_EQ_SHOOTING, NULL, &rc1);
        ts_equilibrium *b = solve(s, TS_EQ_NEWTON, guess, &rc2);
        double d = max_pos_diff(a, b, 0), L = total_length(s);
        CHECK(rc1 == TS_OK && rc2 == TS_OK && d <= 1e-8 * L &&
                  b->continuation_steps == 1,
              "ex1 submerged: Newton from the hanging shape itself (%d "
              "iterations, %d continuation step(s): 1 = no fall-back) = "
              "shooting, max %.3g m <= 1e-8 x %.3f m", b->iterations,
              b->continuation_steps, d, L);
        ts_equilibrium_free(a);
        ts_equilibrium_free(b);
        free(guess);
    }
    ts_system_free(s);
}

/* ---- 4. mirror symmetry of turns --------------------------------------- */

static void check_mirror(const char *what, ts_system *s, double W)
{
    s->tow.point[1] = 0; /* the mirror is about the tow point's plane */
    s->tow.turn_rate = W;
    int rc1, rc2;
    ts_equilibrium *a = solve(s, TS_EQ_AUTO, NULL, &rc1);
    s->tow.turn_rate = -W;
    ts_equilibrium *b = solve(s, TS_EQ_AUTO, NULL, &rc2);
    double L = total_length(s), d = max_pos_diff(a, b, 1);
    double ymax = 0;
    for (int i = 0; i < s->nnodes; i++)
        ymax = fmax(ymax, fabs(a->positions[3 * i + 1]));
    /* Two independent solves to 1e-10 force residual each. */
    CHECK(rc1 == TS_OK && rc2 == TS_OK && d <= 1e-9 * L && ymax > 0.05 * L,
          "%s: Omega = %+g and %+g rad/s mirror each other, (x,-y,z) to "
          "%.3g m <= 1e-9 x %.3f m (largest |y| %.3f m)", what, W, -W, d, L,
          ymax);
    double dt = 0, tmax = 0;
    for (int l = 0; l < s->nlinks; l++) {
        dt = fmax(dt, fabs(a->tensions[l] - b->tensions[l]));
        tmax = fmax(tmax, a->tensions[l]);
    }
    CHECK(dt <= 1e-9 * tmax, "%s: same tensions (%.3g N)", what, dt);
    ts_equilibrium_free(a);
    ts_equilibrium_free(b);
}

static void test_mirror(void)
{
    ts_system *s = ex3(0.5);
    if (s)
        check_mirror("ex3 single cable", s, 0.5);
    ts_system_free(s);
    s = ex2(0.5);
    if (s)
        check_mirror("ex2 branched", s, 0.5);
    ts_system_free(s);
}

/* ---- 5. junction balance ------------------------------------------------ */

static void check_junction(double W)
{
    ts_system *s = ex2(W);
    if (!s)
        return;
    /* Solve, then evaluate the kernel at the solution for its loads. */
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, NULL);
    int rc = ts_equilibrium_solve(k, NULL, eq, NULL);
    double *dydt = malloc(4 * (size_t)s->nlinks * sizeof(double));
    ts_kernel_eval(k, eq->y, NULL, dydt);
    const double *Q = ts_kernel_loads(k);
    int J = ts_system_body_node(s, 0);
    const ts_node *nd = &s->nodes[J];
    int p = nd->link;
    const double *r = eq->positions + 3 * J;
    double rho = s->env.water_density, V = s->tow.speed;
    /* A node at rest in the turning frame accelerates at
     * (-W^2 x, W V - W^2 y, 0) (doc/model.md section 1). */
    double a[3] = {-W * W * r[0], W * V - W * W * r[1], 0};
    double lhs[3], rhs[3];
    for (int j = 0; j < 3; j++) {
        lhs[j] = eq->tensions[p] * eq->directions[3 * p + j];
        rhs[j] = Q[3 * J + j] - nd->mass * a[j];
    }
    int links[3] = {p, -1, -1}, m = 1;
    for (int c = nd->child_begin; c < nd->child_end; c++) {
        int l = s->child_links[c];
        links[m++] = l;
        for (int j = 0; j < 3; j++)
            rhs[j] += eq->tensions[l] * eq->directions[3 * l + j];
    }
    /* Normal added mass of the three links meeting there (all wet). */
    for (int i = 0; i < 3; i++) {
        const ts_link *L = &s->links[links[i]];
        const double *n = eq->directions + 3 * links[i];
        double A = L->can * rho * M_PI * L->diameter * L->diameter / 4 *
                   L->length;
        double an = a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
        for (int j = 0; j < 3; j++)
            rhs[j] -= 0.5 * A * (a[j] - an * n[j]);
    }
    double d = 0;
    for (int j = 0; j < 3; j++)
        d = fmax(d, fabs(lhs[j] - rhs[j]));
    /* The equilibrium's residual is below 1e-10 of the largest force. */
    CHECK(rc == TS_OK && m == 3 && d <= 1e-10 * eq->tensions[p],
          "junction, turn rate %g: t_parent n_parent = sum t_child n_child "
          "+ half-link loads%s, diff %.3g N <= 1e-10 x %.4g N", W,
          W != 0 ? " - inertia" : "", d, eq->tensions[p]);
    free(dydt);
    ts_kernel_free(k);
    ts_equilibrium_free(eq);
    ts_system_free(s);
}

/* ---- 6. through the surface --------------------------------------------- */

/* Largest node displacement between consecutive tow depths from +0.2 m to
 * -0.2 m in steps h: of the nodes (*moved) and of the shape relative to the
 * tow point (*shape), which leaves out the translation the tow point itself
 * imposes (exactly h per step) and so shows what the surface does. */
static void sweep(double h, int *ok, double *moved, double *shape)
{
    ts_system *s = ex1(0.2, 8.345 * FT);
    *moved = *shape = NAN;
    if (!s) {
        *ok = 0;
        return;
    }
    int n = (int)lround(0.4 / h), crossing = 0;
    double *prev = NULL;
    *moved = *shape = 0;
    for (int i = 0; i <= n; i++) {
        s->tow.point[2] = 0.2 - i * h;
        int rc;
        ts_equilibrium *eq = solve(s, TS_EQ_AUTO, NULL, &rc);
        if (rc != TS_OK || !eq->converged)
            *ok = 0;
        const double *r = eq->positions;
        if (r[2] < 0 && r[5] > 0)
            crossing++; /* the top link is cut by the surface */
        if (prev)
            for (int k = 0; k < s->nnodes; k++) {
                double d[3], e[3];
                for (int j = 0; j < 3; j++) {
                    d[j] = r[3 * k + j] - prev[3 * k + j];
                    e[j] = d[j] - (r[j] - prev[j]);
                }
                *moved = fmax(*moved, sqrt(d[0] * d[0] + d[1] * d[1] +
                                           d[2] * d[2]));
                *shape = fmax(*shape, sqrt(e[0] * e[0] + e[1] * e[1] +
                                           e[2] * e[2]));
            }
        free(prev);
        prev = malloc(3 * (size_t)s->nnodes * sizeof(double));
        memcpy(prev, r, 3 * (size_t)s->nnodes * sizeof(double));
        ts_equilibrium_free(eq);
    }
    if (crossing < n / 3)
        *ok = 0;
    free(prev);
    ts_system_free(s);
}

static void test_surface(void)
{
    int ok = 1;
    double h = 0.02, a, as, b, bs;
    sweep(h, &ok, &a, &as);
    sweep(h / 2, &ok, &b, &bs);
    CHECK(ok, "surface sweep: every equilibrium converged, the top link cut "
              "by the surface in the second half");
    /* The tow point itself moves by h; the shape shifts by about as much.
     * A jump would not shrink with the step. */
    CHECK(a <= 3 * h && b <= 3 * h / 2,
          "surface sweep: largest node move per step %.4g m (h = %g), "
          "%.4g m (h = %g), below 3 h", a, h, b, h / 2);
    CHECK(a / b > 1.7 && a / b < 2.3,
          "surface sweep: halving the step halves it (ratio %.3f in [1.7, "
          "2.3])", a / b);
    CHECK(as > 0 && as <= 3 * h && bs <= 3 * h / 2 && as / bs > 1.7 &&
              as / bs < 2.3,
          "surface sweep: shape relative to the tow point, largest change "
          "%.3g m (h = %g), %.3g m (h = %g), ratio %.3f in [1.7, 2.3]", as,
          h, bs, h / 2, as / bs);
}

/* ---- 7. failures ---------------------------------------------------------- */

static void test_failures(void)
{
    ts_system *s = ex2(0.5);
    if (!s)
        return;
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = TS_EQ_NEWTON;
    o.max_iter = 1;
    int rc = ts_equilibrium_solve(k, &o, eq, &err);
    const char *p = strstr(err.msg, "residual ");
    double reported = p ? strtod(p + 9, NULL) : NAN;
    CHECK(rc == TS_ECONV && err.code == TS_ECONV && !eq->converged,
          "turn, newton, max_iter 1: TS_ECONV, converged = 0 (%s)", err.msg);
    CHECK(p && isfinite(reported) && reported > o.tol &&
              eq->residual > o.tol,
          "turn, newton, max_iter 1: the message gives the residual reached "
          "(%.3g; eq->residual %.3g > tol)", reported, eq->residual);
    /* Requests the model refuses. */
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    f.turn_accel = 0.01;
    ts_kernel_set_frame(k, &f);
    ts_err_clear(&err);
    rc = ts_equilibrium_solve(k, NULL, eq, &err);
    CHECK(rc == TS_EDOMAIN && strstr(err.msg, "accelerating"),
          "accelerating frame: TS_EDOMAIN (%s)", err.msg);
    f.turn_accel = 0;
    f.current[1] = 0.1;
    ts_kernel_set_frame(k, &f);
    ts_err_clear(&err);
    rc = ts_equilibrium_solve(k, NULL, eq, &err);
    CHECK(rc == TS_EDOMAIN && strstr(err.msg, "current"),
          "turn in a current: TS_EDOMAIN (%s)", err.msg);
    f.current[1] = 0;
    ts_kernel_set_frame(k, &f);
    o.tol = 0;
    o.max_iter = 100;
    ts_err_clear(&err);
    rc = ts_equilibrium_solve(k, &o, eq, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tolerance"),
          "tolerance 0: TS_EINVAL (%s)", err.msg);
    ts_kernel_free(k);
    ts_equilibrium_free(eq);
    ts_system_free(s);

    /* Bending: shooting refuses, auto takes Newton. */
    cable_def c = {"stiff", -1, 0, 3.1, 0.012, 0.41, 8, 1.2, 0.01, 1.0,
                   0.023};
    body_def b = {"s", TS_BODY_SPHERE, 0.08, 0.7, 0.5, 0.5};
    s = build(1, &c, 1, &b, 1025, 1.1, 0, 0.2);
    if (s) {
        k = ts_kernel_alloc(s, NULL);
        eq = ts_equilibrium_alloc(s, NULL);
        ts_equilibrium_opts_default(&o);
        o.method = TS_EQ_SHOOTING;
        ts_err_clear(&err);
        rc = ts_equilibrium_solve(k, &o, eq, &err);
        CHECK(rc == TS_EDOMAIN && strstr(err.msg, "EI"),
              "bending with shooting: TS_EDOMAIN (%s)", err.msg);
        ts_err_clear(&err);
        rc = ts_equilibrium_solve(k, NULL, eq, &err);
        CHECK(rc == TS_OK && eq->converged && eq->method == TS_EQ_NEWTON &&
                  eq->residual <= 1e-10,
              "bending with auto: Newton converged (residual %.3g)",
              eq->residual);
        ts_kernel_free(k);
        ts_equilibrium_free(eq);
        ts_system_free(s);
    }

    /* A neutrally buoyant free end without flow has no steady shape. The
     * mass per length is written as the library forms the buoyancy, so
     * that the wet weight is exactly zero, not a rounding error. */
    double d = 0.02, rho = 1025;
    cable_def nb = {"neutral", -1, -1, 2.0, d, rho * (M_PI * 0.25 * d * d), 4,
                    1.2, 0.01, 1.0, 0};
    s = build(1, &nb, 0, NULL, rho, 0, 0, 1.0);
    if (s) {
        k = ts_kernel_alloc(s, NULL);
        eq = ts_equilibrium_alloc(s, NULL);
        ts_err_clear(&err);
        rc = ts_equilibrium_solve(k, NULL, eq, &err);
        CHECK(rc == TS_ESINGULAR && !eq->converged &&
                  strstr(err.msg, "neutral"),
              "neutrally buoyant, no flow: TS_ESINGULAR (%s)", err.msg);
        ts_kernel_free(k);
        ts_equilibrium_free(eq);
        ts_system_free(s);
    }
}

/* 8. Continuation from a neighbour: started from the equilibrium at a
 * nearby turn rate (opts.guess), the solver finds the same equilibrium as
 * from a cold start (positions within 1e-9 of the cable length: both meet
 * the force residual 1e-10, whose shape error is orders smaller), with
 * fewer kernel evaluations where the cold start needs its continuation
 * schedule or Newton. */
static void warm_case(const char *what, ts_system *near, ts_system *s)
{
    int rc0, rc1, rc2;
    ts_equilibrium *n = solve(near, TS_EQ_AUTO, NULL, &rc0);
    ts_equilibrium *cold = solve(s, TS_EQ_AUTO, NULL, &rc1);
    ts_equilibrium *warm = solve(s, TS_EQ_AUTO, n->directions, &rc2);
    double L = total_length(s);
    double d = rc0 == TS_OK && rc1 == TS_OK && rc2 == TS_OK
                   ? max_pos_diff(cold, warm, 0)
                   : INFINITY;
    CHECK(d <= 1e-9 * L && warm->evaluations < cold->evaluations,
          "%s: from the neighbour's shape, the cold start's equilibrium "
          "(max |dr| %.2g m <= 1e-9 L) in %ld evaluations (%s) against "
          "%ld (%s)",
          what, d, warm->evaluations, ts_eq_method_name(warm->method),
          cold->evaluations, ts_eq_method_name(cold->method));
    ts_equilibrium_free(n);
    ts_equilibrium_free(cold);
    ts_equilibrium_free(warm);
    ts_system_free(near);
    ts_system_free(s);
}

static void test_warm_start(void)
{
    warm_case("ex. 3, 0.95 -> 1 rad/s (shooting)", ex3(0.95), ex3(1.0));
    warm_case("ex. 3, 1.2 -> 1.25 rad/s", ex3(1.2), ex3(1.25));
    /* With bending: Newton, which starts cold from the straight-tow march
     * with continuation in turn rate and in bending. */
    ts_system *b0 = ex3(0.45), *b1 = ex3(0.5);
    b0->cables[0].ei = b1->cables[0].ei = 2e-4;
    ts_system_build(b0, NULL);
    ts_system_build(b1, NULL);
    warm_case("ex. 3 with EI 2e-4 N m^2, 0.45 -> 0.5 rad/s (newton)", b0, b1);
}

int main(void)
{
    gsl_set_error_handler_off();
    test_warm_start();
    test_hanging();
    test_critical_angle();
    test_newton_vs_shooting();
    test_mirror();
    check_junction(0);
    check_junction(0.5);
    test_surface();
    test_failures();
    return tc_done();
}
