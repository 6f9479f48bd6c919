/* test_bending.c: bending stiffness (doc/model.md section 3;
 * doc/elastic.md) in the rigid and the elastic model, against references
 * that do not come from the code under test.
 *
 *  1. Joint forces: tsi_bending (lib/forces.h) against -dU/dr of
 *     tsi_bending_energy by central differences, at awkward angles from
 *     nearly straight (alpha 1e-9, below the series switch, and 1e-7, 1e-4)
 *     to nearly folded (pi - alpha = 1e-3), in 3-D.
 *  2. The kernel's assembly: on a branched tree of rigid and stretched
 *     elastic links the generalised bending force on every coordinate,
 *     sum_i F_i . dr_i/dq_j (F_i the change of the nodal loads when bending
 *     is switched on), equals -dU/dq_j of the kernel's bending energy. Both
 *     derivatives by central differences. This catches forces that are not
 *     the gradient of the energy reported (a stretched link's length).
 *  3. Energy in vacuum (rho = 0, V = 0, no damping) with elastic links and
 *     bending on a branched tree: kinetic + potential energy (gravity,
 *     strain 1/2 EA l e^2, bending) is conserved by fixed-step RK4 written
 *     here, and the drift falls at the method's order as the step halves.
 *  4. A static case with a known answer: a vertical, neutrally buoyant
 *     cable held taut (tension T) by a drag-free end weight, pinned at the
 *     tow point (a ball joint), under the small uniform lateral drag q of a
 *     slow tow. Its deflection obeys the beam-string equation
 *     EI x'''' - T x'' = q with x = x'' = 0 at the top and x'' = 0,
 *     T x' - EI x''' = 0 at the free tip, solved here in closed form. The
 *     towstab equilibrium (Newton with continuation in bending stiffness)
 *     approaches it as the links are refined, in the rigid and the elastic
 *     model, at second order; the bending term is a fifth of the answer, so
 *     the comparison sees it. At 80 links it starts from the equilibrium
 *     of a coarser copy (5).
 *  5. The start from a coarser copy (ts_equilibrium_opts.coarse_above)
 *     against the continuation in bending alone, on the two-part tows
 *     refined past its threshold (105 and 66 links): the same
 *     equilibrium, node by node and vehicle attitude, in fewer Newton
 *     iterations.
 *  6. Newton's condition number is the Skeel condition || |J^-1| |J| ||
 *     (inf-norm) of its Jacobian: against the one computed here from a
 *     central-difference Jacobian at the solution and its explicit
 *     inverse (GSL), on the two-part tow at 105 links (whose plain
 *     1-norm condition, 3.6e13, is 500 times larger: the rows, link
 *     accelerations, differ by orders in scale), at its own 35 and on a
 *     plain cable; the plain condition printed beside it.
 * Tolerances are stated at each check with their reason. */
#include "towstab/equilibrium.h"
#include "towstab/health.h"
#include "towstab/kernel.h"

#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "tcheck.h"
#include "tmodel.h"
#include "tscene.h"

/* ---- helpers ------------------------------------------------------------ */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double a[3]) { return sqrt(dot3(a, a)); }

static void unit3(double a[3])
{
    double n = norm3(a);
    for (int j = 0; j < 3; j++)
        a[j] /= n;
}

/* ---- 1. joint forces against the energy gradient ------------------------ */

/* Bending energy of a joint with the nodes at r[9] (i, j, k), EI and the
 * spring's mean length lbar fixed: tsi_bending_energy with la = lb = lbar. */
static double joint_energy(double ei, double lbar, const double r[9])
{
    double na[3], nb[3];
    for (int j = 0; j < 3; j++) {
        na[j] = r[3 + j] - r[j];
        nb[j] = r[6 + j] - r[3 + j];
    }
    unit3(na);
    unit3(nb);
    return tsi_bending_energy(ei, lbar, lbar, na, nb);
}

/* One joint: upper node at the origin, link a of length la along na,
 * link b of length lb at angle alpha from na, turned by phi about na. */
static void check_joint(double alpha, double phi, double h_rel,
                        const char *what)
{
    const double ei = 2.385, la = 0.37, lb = 0.61;
    double na[3] = {0.31, -0.52, 0.79}, p[3], q[3];
    unit3(na);
    /* p, q: an orthonormal pair normal to na. */
    double t[3] = {1, 0, 0};
    v3_cross(na, t, p);
    unit3(p);
    v3_cross(na, p, q);
    double nb[3];
    for (int j = 0; j < 3; j++)
        nb[j] = cos(alpha) * na[j] +
                sin(alpha) * (cos(phi) * p[j] + sin(phi) * q[j]);
    double r[9];
    for (int j = 0; j < 3; j++) {
        r[j] = 0.113 * (j + 1);
        r[3 + j] = r[j] + la * na[j];
        r[6 + j] = r[3 + j] + lb * nb[j];
    }
    /* The joint's forces at lengths la, lb; the energy holds its spring
     * constant EI / lbar fixed, so -dU/dr is exactly these forces. */
    double F[9];
    tsi_bending(ei, la, lb, na, nb, F, F + 3, F + 6);
    double lbar = 0.5 * (la + lb), worst = 0, big = 0;
    for (int i = 0; i < 9; i++) {
        /* Central differences with steps h and 2h, Richardson-combined:
         * D(h) - (D(2h) - D(h)) / 3 removes the h^2 error term. */
        double D[2], r0 = r[i];
        for (int m = 0; m < 2; m++) {
            double h = (m + 1) * h_rel * la;
            r[i] = r0 + h;
            double up = joint_energy(ei, lbar, r);
            r[i] = r0 - h;
            double um = joint_energy(ei, lbar, r);
            D[m] = -(up - um) / (2 * h);
        }
        r[i] = r0;
        double g = D[0] - (D[1] - D[0]) / 3.0;
        worst = fmax(worst, fabs(g - F[i]));
        big = fmax(big, fabs(F[i]));
    }
    double sum[3] = {F[0] + F[3] + F[6], F[1] + F[4] + F[7],
                     F[2] + F[5] + F[8]};
    /* Errors of the differences, relative to |F|: rounding of alpha
     * (~1e-16 absolute, from the node positions) gives 1e-16 l / h, and
     * near straight 1e-16 / alpha (U is then that of the perturbed angle,
     * ~h/l, and its difference is alpha l / h of it: 2e-8 at alpha 8e-9,
     * the reason the series branch, sin alpha < 1e-8, is checked there and
     * not at 1e-9); the
     * h^2 term, removed by the extrapolation, is (h/l)^2 / alpha near
     * straight (first- and second-order changes of the directions
     * multiply: 1e-3 at alpha = 1e-9 with h = 1e-6 l, without it) and
     * (h / (l (pi - alpha)))^2 near folded, where U has a cone; what is
     * left is their squares. With h = 1e-6 l everything is below 1e-9,
     * but near straight, so 1e-7 of the largest force is a failure of the
     * formula. */
    CHECK(worst <= 1e-7 * big,
          "joint %s (alpha %.3g rad): -dU/dr = F to %.2g of max |F| %.4g N "
          "(<= 1e-7)", what, alpha, worst / big, big);
    /* The forces of an internal spring add up to zero (to rounding). */
    CHECK(norm3(sum) <= 1e-14 * big, "joint %s: forces sum to %.2g N",
          what, norm3(sum));
    /* Near straight the force is k alpha / l: EI alpha / (lbar la), on the
     * upper node; checks the series branch's scale. */
    if (alpha < 1e-3)
        CHECK(fabs(norm3(F) - ei * alpha / (lbar * la)) <=
                  1e-6 * ei * alpha / (lbar * la),
              "joint %s: |F_i| = EI alpha / (lbar la) to 1e-6 (small-angle "
              "limit, error alpha^2)", what);
}

static void test_joints(void)
{
    /* Steps 1e-6 of the link; folded to 1e-5 rad, the cone at alpha = pi
     * needs the step well inside pi - alpha (1e-8 of the link, where
     * rounding, 1e-16 / 1e-8, is still small). */
    check_joint(8e-9, 0.7, 1e-6, "nearly straight, series branch");
    check_joint(1e-7, 2.1, 1e-6, "nearly straight");
    check_joint(1e-4, -1.3, 1e-6, "slightly bent");
    check_joint(0.4137, 0.37, 1e-6, "bent");
    check_joint(1.9021, 4.0, 1e-6, "bent past a right angle");
    check_joint(M_PI - 1e-3, 1.1, 1e-6, "nearly folded");
    check_joint(M_PI - 1e-5, -0.6, 1e-8, "folded to 1e-5 rad");
}

/* ---- building systems ------------------------------------------------- */

typedef struct cable_def {
    const char *name;
    int from, to;
    double length, diameter, mpl;
    int nlinks;
    double cdn, cdt, can, ei, ea;
} cable_def;

typedef struct body_def {
    const char *name;
    ts_body_type type;
    double diameter, mass, cd, ca;
} body_def;

static ts_system *build(int nc, const cable_def *cd, int nb,
                        const body_def *bd, double rho, double g,
                        double speed, const double point[3])
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(nc, nb, &err);
    if (!s)
        return NULL;
    snprintf(s->name, sizeof s->name, "test");
    s->env.water_density = rho;
    s->env.gravity = g;
    s->tow.speed = speed;
    for (int j = 0; j < 3; j++)
        s->tow.point[j] = point[j];
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
        c->ea = cd[i].ea;
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

/* A branched tree in vacuum: an elastic lead cable with bending to a
 * junction with mass, an elastic branch with bending and a rigid branch
 * with bending below it. Bending acts within each cable, never across the
 * junction (a free joint). */
static ts_system *mixed_tree(double g)
{
    const double origin[3] = {0.07, -0.03, 0.11};
    cable_def c[3] = {
        {"lead", -1, 0, 2.31, 0.012, 0.83, 4, 0, 0, 0, 0.37, 2.2e3},
        {"elastic_branch", 0, 1, 1.47, 0.011, 0.62, 3, 0, 0, 0, 0.21,
         1.6e3},
        {"rigid_branch", 0, -1, 1.12, 0.014, 0.55, 3, 0, 0, 0, 0.29, 0}};
    body_def b[2] = {{"junction", TS_BODY_JUNCTION, 0, 0.31, 0, 0},
                     {"ball", TS_BODY_SPHERE, 0.1, 0.9, 0.5, 0.5}};
    return build(3, c, 2, b, 0.0, g, 0.0, origin);
}

/* A 3-D state: angles theta1 = t1base + spread (t1base 0: trailing
 * backwards, pi/2: hanging), theta2 spread about 0, strains of the elastic
 * links (strain0[cable] times a spread), rates. */
static void tree_state(const ts_kernel *k, double t1base,
                       const double strain0[], double rate, double *y)
{
    const ts_system *s = ts_kernel_system(k);
    int nq = ts_kernel_nq(k);
    for (int l = 0; l < s->nlinks; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o] = t1base + 0.35 + 0.29 * (l % 4) + 0.05 * sin(3.1 * l);
        y[o + 1] = 0.23 * cos(1.7 * l) - 0.11;
        y[nq + o] = rate * sin(2.3 * l + 0.4);
        y[nq + o + 1] = rate * cos(1.9 * l + 0.2);
        if (s->links[l].elastic) {
            y[o + 2] = strain0[s->links[l].cable] *
                       (1.0 + 0.17 * sin(1.3 * l));
            y[nq + o + 2] = 0.0;
        }
    }
}

/* ---- 2. the kernel's generalised bending forces ------------------------ */

/* Bending energy of state y: the kernel's potential energy with bending
 * minus without (gravity and strain energy cancel). Leaves the kernel at
 * bending scale 1 with the positions of y. */
static double bend_energy(ts_kernel *k, const double *y, double *dydt)
{
    ts_kernel_set_bending_scale(k, 0.0);
    ts_kernel_eval(k, y, NULL, dydt);
    double u0 = ts_kernel_potential_energy(k);
    ts_kernel_set_bending_scale(k, 1.0);
    ts_kernel_eval(k, y, NULL, dydt);
    return ts_kernel_potential_energy(k) - u0;
}

static void test_kernel_gradient(void)
{
    /* g = 0: the potential energy is then bending and strain only, so the
     * rounding of the differences is that of energies of order 1 J. */
    ts_system *s = mixed_tree(0.0);
    if (!CHECK(s && s->has_bending && s->has_elastic,
               "gradient: mixed tree with bending builds"))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    int nq = ts_kernel_nq(k), ns = 2 * nq, nn = s->nnodes;
    double *y = calloc((size_t)ns, sizeof(double));
    double *dydt = calloc((size_t)ns, sizeof(double));
    double *F = calloc(3 * (size_t)nn, sizeof(double));
    double *rp = calloc(3 * (size_t)nn, sizeof(double));
    double *rm = calloc(3 * (size_t)nn, sizeof(double));
    /* Strains of a few percent: a force that divided by the unstretched
     * length would be off by that much. */
    const double strain[3] = {0.031, 0.027, 0.0};
    tree_state(k, 0.0, strain, 0.0, y);
    double U = bend_energy(k, y, dydt);
    memcpy(F, ts_kernel_loads(k), 3 * (size_t)nn * sizeof(double));
    ts_kernel_set_bending_scale(k, 0.0);
    ts_kernel_eval(k, y, NULL, dydt);
    for (int i = 0; i < 3 * nn; i++)
        F[i] -= ts_kernel_loads(k)[i];
    CHECK(U > 0.1, "gradient: bending energy %.4g J of a bent tree", U);
    double worst = 0, big = 0, strain_worst = 0;
    int worst_q = -1;
    for (int j = 0; j < nq; j++) {
        /* Central differences with h = 1e-6 (rad, or strain): truncation
         * ~h^2 = 1e-12, rounding ~eps U / h ~ 1e-10 of the forces. */
        const double h = 1e-6;
        double y0 = y[j];
        y[j] = y0 + h;
        double up = bend_energy(k, y, dydt);
        memcpy(rp, ts_kernel_positions(k), 3 * (size_t)nn * sizeof(double));
        y[j] = y0 - h;
        double um = bend_energy(k, y, dydt);
        memcpy(rm, ts_kernel_positions(k), 3 * (size_t)nn * sizeof(double));
        y[j] = y0;
        double dU = (up - um) / (2 * h), Q = 0;
        for (int i = 0; i < 3 * nn; i++)
            Q += F[i] * (rp[i] - rm[i]) / (2 * h);
        if (fabs(Q + dU) > worst) {
            worst = fabs(Q + dU);
            worst_q = j;
        }
        big = fmax(big, fabs(dU));
        /* A strain coordinate: bending forces are normal to the links and
         * the energy uses unstretched lengths, so both are zero. */
        for (int l = 0; l < s->nlinks; l++)
            if (s->links[l].elastic &&
                j == ts_kernel_link_offset(k, l) + 2)
                strain_worst = fmax(strain_worst, fmax(fabs(Q), fabs(dU)));
    }
    CHECK(worst <= 1e-7 * big,
          "gradient: generalised bending forces = -dU/dq on all %d "
          "coordinates to %.2g of max %.4g (<= 1e-7; worst q%d)",
          nq, worst / big, big, worst_q);
    CHECK(strain_worst <= 1e-7 * big,
          "gradient: bending does no work on strains (%.2g, <= 1e-7 of max)",
          strain_worst / big);
    free(y);
    free(dydt);
    free(F);
    free(rp);
    free(rm);
    ts_kernel_free(k);
    ts_system_free(s);
}

/* ---- 3. energy in vacuum ------------------------------------------------ */

static void test_energy(void)
{
    ts_system *s = mixed_tree(9.80665);
    if (!CHECK(s != NULL, "energy: mixed tree builds"))
        return;
    ts_kernel *k0 = ts_kernel_alloc(s, NULL);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, NULL);
    int nq = ts_kernel_nq(k0), ns = 2 * nq;
    double *y0 = calloc((size_t)ns, sizeof(double));
    double *y = calloc((size_t)ns, sizeof(double));
    double *w = calloc(5 * (size_t)ns, sizeof(double));
    /* Start from the hanging shape (strains 0.6 % to 2 %), every angle
     * moved by up to 0.05 rad and every link swinging at up to 0.4 rad/s.
     * A zigzag of lumped links releases large tension waves (from larger
     * angle changes some links go slack), so the disturbance is kept to
     * what leaves every link taut (checked below): the tension's kink at
     * e = 0 would cost RK4 its order. */
    int hang = ts_equilibrium_solve(k0, NULL, eq, NULL);
    CHECK(hang == TS_OK, "energy: hanging shape of the tree in vacuum");
    memcpy(y0, eq->y, (size_t)ns * sizeof(double));
    ts_equilibrium_free(eq);
    for (int l = 0; l < s->nlinks; l++) {
        int o = ts_kernel_link_offset(k0, l);
        y0[o] += 0.05 * sin(2.1 * l + 0.3);
        y0[o + 1] += 0.05 * cos(1.7 * l);
        y0[nq + o] = 0.4 * sin(2.3 * l + 0.4);
        y0[nq + o + 1] = 0.4 * cos(1.9 * l + 0.2);
    }
    ts_kernel_free(k0);
    /* The fastest axial mode: about 2 sqrt(EA / (l m)) ~ 300 rad/s for the
     * lead's links; h = 5 ms puts h omega at 1.5 (RK4 is stable to 2.8),
     * and 4 s cover about one swing of the tree (2 pi sqrt(L/g) ~ 3.8 s)
     * and two hundred axial periods. */
    const double T = 4.0;
    const int base = 800;
    double drift[3], Escale = 0, emin = INFINITY;
    int ok = 1, recharts = 0;
    for (int run = 0; run < 3; run++) {
        int steps = base << run;
        double h = T / steps;
        ts_kernel *k = ts_kernel_alloc(s, NULL);
        memcpy(y, y0, (size_t)ns * sizeof(double));
        ts_kernel_eval(k, y, NULL, w);
        double E0 = ts_kernel_kinetic_energy(k) +
                    ts_kernel_potential_energy(k);
        Escale = ts_kernel_kinetic_energy(k) +
                 fabs(ts_kernel_potential_energy(k));
        double worst = 0;
        int rc = TS_OK;
        for (int n = 0; n < steps && rc == TS_OK; n++) {
            rc = rk4_step(k, y, h, ns, w);
            recharts += ts_kernel_rechart(k, y, TS_CHART_RECHART);
            if (rc == TS_OK)
                rc = ts_kernel_eval(k, y, NULL, w);
            double E = ts_kernel_kinetic_energy(k) +
                       ts_kernel_potential_energy(k);
            worst = fmax(worst, fabs(E - E0));
            for (int l = 0; l < s->nlinks; l++)
                if (s->links[l].elastic)
                    emin = fmin(emin, y[ts_kernel_link_offset(k, l) + 2]);
        }
        ok &= rc == TS_OK;
        drift[run] = worst / Escale;
        ts_kernel_free(k);
    }
    printf("     energy drift over %.1f s: %.3g, %.3g, %.3g (h = %.3g, "
           "%.3g, %.3g s); smallest strain %.3g; %d re-charts\n",
           T, drift[0], drift[1], drift[2], T / base, T / (2 * base),
           T / (4 * base), emin, recharts);
    CHECK(ok, "energy: RK4 ran through all three step sizes");
    CHECK(emin > 0, "energy: no link went slack (smallest strain %.3g > 0)",
          emin);
    /* The required bound: conserved to 1e-6 relative over the run. */
    CHECK(drift[2] < 1e-6 && drift[2] > 1e-15,
          "energy: finest drift %.3g relative (1e-15 < drift < 1e-6)",
          drift[2]);
    /* RK4's global error is O(h^4) (ratio 16 per halving), but on a linear
     * oscillation its energy error is O(h^5): |R(i h w)|^2 = 1 -
     * (h w)^6 / 72 per step (ratio 32). The fast axial modes carry the
     * error here, so the ratio is near 32; allow 20..40 (below 16 would
     * be an error of lower order, e.g. a force that is not the gradient
     * of the energy, or a kink). */
    double r1 = drift[0] / drift[1], r2 = drift[1] / drift[2];
    CHECK(r1 > 20 && r1 < 40 && r2 > 20 && r2 < 40,
          "energy: drift falls at RK4's order on oscillations, 5 (ratios "
          "%.2f, %.2f in [20, 40])", r1, r2);
    free(y0);
    free(y);
    free(w);
    ts_system_free(s);
}

/* ---- 4. the beam-string cable ------------------------------------------ */

/* The tip deflection problem, SI. */
typedef struct beam_case {
    double L, d, rho, g, cdn, V, tension, ei;
} beam_case;

/* Lateral deflection (along x) at arc length z of the continuum cable:
 * EI x'''' - T x'' = q, q = -1/2 rho Cdn d V^2 (drag backwards),
 * x(0) = x''(0) = 0, x''(L) = 0, T x'(L) - EI x'''(L) = 0. With k^2 = T/EI,
 * u = x'' solves u'' - k^2 u = q/EI, u(0) = u(L) = 0:
 * u = (q/T)(cosh kz - tanh(kL/2) sinh kz - 1). Integrating the equation
 * once with the tip condition, EI x''' - T x' = q (z - L), so
 * x = (EI/T) u + (q/T)(L z - z^2/2) (x(0) = 0 since u(0) = 0). */
static double beam_string(const beam_case *b, double z, double ei)
{
    double q = -0.5 * b->rho * b->cdn * b->d * b->V * b->V, T = b->tension;
    double string = q / T * (b->L * z - 0.5 * z * z);
    if (!(ei > 0))
        return string;
    double k = sqrt(T / ei);
    double u = q / T * (cosh(k * z) - tanh(0.5 * k * b->L) * sinh(k * z) -
                        1.0);
    return ei / T * u + string;
}

/* The towstab model of the case with n links; EA 0 (rigid) or > 0. */
static ts_system *beam_system(const beam_case *b, int n, double ea)
{
    const double point[3] = {0.0, 0.0, 1.3};  /* below the surface */
    double area = M_PI * 0.25 * b->d * b->d;
    /* The end weight: a drag-free sphere whose wet weight is T. */
    double D = 0.3, vol = M_PI * D * D * D / 6;
    cable_def c = {"cable", -1, 0, b->L, b->d, b->rho * area, n, b->cdn, 0.0,
                   1.0, b->ei, ea};
    body_def w = {"weight", TS_BODY_SPHERE, D,
                  b->tension / b->g + b->rho * vol, 0.0, 0.0};
    return build(1, &c, 1, &w, b->rho, b->g, b->V, point);
}

/* Largest |x_node - x(z_node)| over the nodes, relative to the largest
 * continuum deflection; z_node is the node's arc length (depth below the
 * tow point equals it to (slope)^2 ~ 1e-6). */
static int beam_error(const beam_case *b, int n, double ea, double *err_out,
                      double *res_out, int *method, int *steps)
{
    *err_out = INFINITY;
    *res_out = INFINITY;
    *method = TS_EQ_AUTO;
    *steps = 0;
    ts_system *s = beam_system(b, n, ea);
    if (!s)
        return 0;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, NULL);
    ts_err err = {0};
    int rc = ts_equilibrium_solve(k, NULL, eq, &err);
    int ok = rc == TS_OK && eq->converged;
    if (!ok)
        printf("     equilibrium failed: %s\n", err.msg);
    double worst = 0, big = 0, x0 = eq->positions[0];
    for (int i = 0; i <= n; i++) {
        double z = b->L * i / n;
        double x = beam_string(b, z, b->ei);
        worst = fmax(worst, fabs(eq->positions[3 * i] - x0 - x));
        big = fmax(big, fabs(x));
    }
    *err_out = worst / big;
    *res_out = eq->residual;
    *method = eq->method;
    *steps = eq->continuation_steps;
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
    return ok;
}

static void test_beam_string(void)
{
    /* 12.7 m of 1 in neutrally buoyant cable under T = 842 N, towed at
     * 0.0731 m/s (q L / T = 1.3e-3: slopes of that order, so the linear
     * theory holds to ~1e-6); EI = T / k^2 with k L = 2.9. */
    beam_case b = {12.7, 0.0254, 1025.0, 9.80665, 1.2, 0.0731, 842.0, 0.0};
    double kL = 2.9;
    b.ei = b.tension * b.L * b.L / (kL * kL);
    /* The bending term's share: it vanishes at both ends (x'' = 0 there)
     * and is largest inside. */
    double share = 0, tip = beam_string(&b, b.L, b.ei);
    for (int i = 0; i <= 1000; i++) {
        double z = b.L * i / 1000;
        share = fmax(share, fabs(beam_string(&b, z, b.ei) -
                                 beam_string(&b, z, 0.0)));
    }
    share /= fabs(tip);
    printf("     beam-string: EI %.5g N m^2, tip deflection %.6g m; the "
           "bending term is up to %.1f %% of it\n", b.ei, tip, 100 * share);
    CHECK(share > 0.1, "beam-string: the bending term is %.1f %% of the "
                       "deflection (> 10 %%: the comparison sees it)",
          100 * share);
    static const int sizes[] = {10, 20, 40, 80};
    const double eas[2] = {0.0, 1e9};
    for (int m = 0; m < 2; m++) {
        double e[4];
        int ok = 1;
        for (int i = 0; i < 4; i++) {
            double res;
            int method, steps;
            ok &= beam_error(&b, sizes[i], eas[m], &e[i], &res, &method,
                             &steps);
            printf("     %s, %3d links: max |x - x_beam| / max |x_beam| = "
                   "%.3e (residual %.2g, %s, %d continuation steps)\n",
                   m ? "elastic EA 1e9 N" : "rigid", sizes[i], e[i], res,
                   ts_eq_method_name(method), steps);
        }
        const char *model = m ? "elastic" : "rigid";
        CHECK(ok, "beam-string %s: every equilibrium converged (Newton with "
                  "bending continuation)", model);
        /* Lumping the load and the bending energy at nodes is second-order
         * accurate: each doubling divides the error by about 4 (allow 3 to
         * 5.5). */
        double r1 = e[0] / e[1], r2 = e[1] / e[2], r3 = e[2] / e[3];
        CHECK(r1 > 3 && r1 < 5.5 && r2 > 3 && r2 < 5.5 && r3 > 3 && r3 < 5.5,
              "beam-string %s: error falls at 2nd order (ratios %.2f %.2f "
              "%.2f in [3, 5.5])", model, r1, r2, r3);
        /* At 80 links: 5e-4 at 10 links over 64 at second order is
         * 8e-6; the linear theory itself is good to ~(q L / T)^2 = 2e-6.
         * Against a bending term of 13 %, the model has the bending right
         * (a string would be off by that much). */
        CHECK(e[3] < 2e-5, "beam-string %s: 80 links within %.2g of the "
                           "continuum (< 2e-5)", model, e[3]);
    }
}

/* Scene `path` at `links` a cable (its own with 0), or NULL after a FAIL
 * line. */
static ts_scene *load_at(const ts_units *u, const char *path, int links)
{
    ts_scene *sc = tscene_load(u, path);
    ts_err err = {0};
    if (sc && (links <= 0 ||
               ts_system_set_links(sc->system, links, &err) == TS_OK))
        return sc;
    CHECK(0, "%s at %d links a cable (%s)", path, links, err.msg);
    ts_scene_free(sc);
    return NULL;
}

/* 5. Equilibrium of scene `path` at `links` a cable, from a coarser
 * copy (the default) and by the continuation alone (coarse_above 0). */
static void coarse_case(const ts_units *u, const char *path, int links)
{
    ts_scene *sc = load_at(u, path, links);
    if (!sc)
        return;
    ts_err err = {0};
    const ts_system *sys = sc->system;
    ts_kernel *k[2];
    ts_equilibrium *eq[2];
    int rc[2];
    for (int i = 0; i < 2; i++) {
        ts_equilibrium_opts o;
        ts_equilibrium_opts_default(&o);
        if (i == 1)
            o.coarse_above = 0;
        k[i] = ts_kernel_alloc(sys, &err);
        eq[i] = ts_equilibrium_alloc(sys, &err);
        rc[i] = ts_equilibrium_solve(k[i], &o, eq[i], &err);
        if (rc[i] != TS_OK)
            printf("     %s: %s\n", i ? "continuation" : "coarse start",
                   err.msg);
    }
    if (CHECK(rc[0] == TS_OK && rc[1] == TS_OK && eq[0]->converged &&
                  eq[1]->converged,
              "%s, %d links: both starts converge", path, sys->nlinks)) {
        /* The two are roots of the same equations to the tolerance 1e-10
         * of the largest force: their nodes agree to each one's shape
         * error estimate (|J^-1 q''| times the length, about 1e-10 m
         * here), with a factor of 100 for the estimate's first order and
         * 1e-9 m for rounding in the positions. */
        double dmax = 0, allow = 100 * (eq[0]->shape_error +
                                        eq[1]->shape_error) + 1e-9;
        for (int i = 0; i < 3 * sys->nnodes; i++)
            dmax = fmax(dmax, fabs(eq[0]->positions[i] -
                                   eq[1]->positions[i]));
        double amax = 0;
        for (int i = 0; i < 9 * eq[0]->nvehicles; i++)
            amax = fmax(amax, fabs(eq[0]->attitudes[i] -
                                   eq[1]->attitudes[i]));
        CHECK(dmax <= allow && amax <= 1e-7,
              "%s, %d links: the same equilibrium from both starts (nodes "
              "%.2g m apart, within %.2g; attitudes %.2g apart, within "
              "1e-7)", path, sys->nlinks, dmax, allow, amax);
        CHECK(eq[0]->iterations < eq[1]->iterations,
              "%s, %d links: the coarse start takes fewer Newton iterations "
              "(%d, its coarse levels' included) than the continuation "
              "(%d)", path, sys->nlinks, eq[0]->iterations,
              eq[1]->iterations);
    }
    for (int i = 0; i < 2; i++) {
        ts_equilibrium_free(eq[i]);
        ts_kernel_free(k[i]);
    }
    ts_scene_free(sc);
}


/* 6. The Skeel condition of d q'' / d q at eq (no controllers, no
 * towing vehicle: the unknowns are q), from central differences with
 * the solver's steps (1e-6 of 1 rad, of 1e-3 for a strain) and the
 * explicit inverse; NaN when it cannot be formed. O(nq^3). */
static double skeel_here(ts_kernel *k, const ts_equilibrium *eq,
                         double *plain)
{
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k), n = ts_kernel_nstate(k);
    double *y = malloc((size_t)n * sizeof(double));
    double *f1 = malloc((size_t)n * sizeof(double));
    double *f2 = malloc((size_t)n * sizeof(double));
    double *sc = malloc((size_t)nq * sizeof(double));
    gsl_matrix *J = gsl_matrix_alloc((size_t)nq, (size_t)nq);
    gsl_matrix *Ji = gsl_matrix_alloc((size_t)nq, (size_t)nq);
    gsl_permutation *p = gsl_permutation_alloc((size_t)nq);
    double cond = NAN;
    ts_err err = {0};
    if (!y || !f1 || !f2 || !sc || !J || !Ji || !p ||
        ts_equilibrium_state(k, eq, y, &err) != TS_OK)
        goto out;
    for (int i = 0; i < nq; i++)
        sc[i] = 1.0;
    for (int l = 0; l < sys->nlinks; l++)
        if (sys->links[l].elastic)
            sc[ts_kernel_link_offset(k, l) + 2] = 1e-3;
    for (int j = 0; j < nq; j++) {
        double h = 1e-6 * sc[j], y0 = y[j];
        y[j] = y0 + h;
        int r1 = ts_kernel_eval(k, y, NULL, f1);
        y[j] = y0 - h;
        int r2 = ts_kernel_eval(k, y, NULL, f2);
        y[j] = y0;
        if (r1 != TS_OK || r2 != TS_OK)
            goto out;
        for (int i = 0; i < nq; i++)
            gsl_matrix_set(J, (size_t)i, (size_t)j,
                           (f1[nq + i] - f2[nq + i]) / (2 * h));
    }
    /* |J| e, then || |J^-1| |J| e ||_inf; and the plain 1-norm
     * condition ||J||_1 ||J^-1||_1 (what Newton reported before), into
     * *plain. */
    double n1 = 0;
    for (int i = 0; i < nq; i++) {
        f1[i] = 0;
        double colsum = 0;
        for (int j = 0; j < nq; j++) {
            f1[i] += fabs(gsl_matrix_get(J, (size_t)i, (size_t)j));
            colsum += fabs(gsl_matrix_get(J, (size_t)j, (size_t)i));
        }
        n1 = fmax(n1, colsum);
    }
    int sg;
    if (gsl_linalg_LU_decomp(J, p, &sg) != 0 ||
        gsl_linalg_LU_invert(J, p, Ji) != 0)
        goto out;
    double ni1 = 0;
    for (int j = 0; j < nq; j++) {
        double colsum = 0;
        for (int i = 0; i < nq; i++)
            colsum += fabs(gsl_matrix_get(Ji, (size_t)i, (size_t)j));
        ni1 = fmax(ni1, colsum);
    }
    *plain = n1 * ni1;
    cond = 0;
    for (int i = 0; i < nq; i++) {
        double r = 0;
        for (int j = 0; j < nq; j++)
            r += fabs(gsl_matrix_get(Ji, (size_t)i, (size_t)j)) * f1[j];
        cond = fmax(cond, r);
    }
out:
    free(y);
    free(f1);
    free(f2);
    free(sc);
    if (J)
        gsl_matrix_free(J);
    if (Ji)
        gsl_matrix_free(Ji);
    if (p)
        gsl_permutation_free(p);
    return cond;
}

static void condition_case(const ts_units *u, const char *path, int links)
{
    ts_scene *sc = load_at(u, path, links);
    if (!sc)
        return;
    tscene_solved s;
    int rc = tscene_solve(sc->system, &s, TS_EQ_NEWTON);
    double plain = NAN;
    double here = rc == TS_OK ? skeel_here(s.k, s.eq, &plain) : NAN;
    printf("     %s, %d links: Skeel condition %.3g here, the plain 1-norm "
           "condition %.3g\n", path, sc->system->nlinks, here, plain);
    /* dlacn2 estimates from below and is usually exact; the solver's
     * Jacobian is the last iteration's, a step from the solution, and
     * rounding in either moves an ill-conditioned one's condition by a
     * few times its relative error: within a factor 3 either way. */
    CHECK(rc == TS_OK && here > 0 && s.eq->condition >= here / 3 &&
              s.eq->condition <= 3 * here,
          "%s, %d links: Newton's condition %.3g is the Skeel condition of "
          "its Jacobian, %.3g here (within a factor 3)", path,
          sc->system->nlinks, s.eq->condition, here);
    tscene_solved_free(&s);
    ts_scene_free(sc);
}

/* 7. Where Newton's Jacobian is ill-conditioned: scene `path` at
 * `links` a cable solved, then solved again from its own link
 * directions, each turned by up to 1e-7 rad (a fixed sequence): the two
 * shapes agree within ten times the sum of their shape error estimates
 * (|J^-1 q''| times the length, each an estimate of its distance from the
 * root), and the health check, which those estimates decide below a
 * condition of 1 / (10 eps), finds each shape trustworthy. */
static void restart_case(const ts_units *u, const char *path, int links)
{
    ts_scene *sc = load_at(u, path, links);
    if (!sc)
        return;
    ts_err err = {0};
    const ts_system *sys = sc->system;
    int nl = sys->nlinks, rc = TS_ENOMEM;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq[2] = {ts_equilibrium_alloc(sys, &err),
                             ts_equilibrium_alloc(sys, &err)};
    double *g = malloc(3 * (size_t)nl * sizeof(double));
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    if (k && eq[0] && eq[1] && g)
        rc = ts_equilibrium_solve(k, &o, eq[0], &err);
    if (rc == TS_OK) {
        unsigned long long r = 0x2545F4914F6CDD1DULL;
        for (int l = 0; l < nl; l++) {
            double d[3];
            for (int c = 0; c < 3; c++) {
                r = r * 6364136223846793005ULL + 1442695040888963407ULL;
                d[c] = eq[0]->directions[3 * l + c] +
                       ((double)(r >> 11) * 0x1.0p-53 - 0.5) * 2e-7;
            }
            unit3(d);
            memcpy(g + 3 * l, d, sizeof d);
        }
        o.guess = g;
        rc = ts_equilibrium_solve(k, &o, eq[1], &err);
    }
    if (CHECK(rc == TS_OK && eq[1]->converged,
              "%s, %d links: solved, and again from its shape turned by "
              "1e-7 rad (%d iterations; %s)",
              path, nl, rc == TS_OK ? eq[1]->iterations : 0, err.msg)) {
        double dmax = 0;
        for (int i = 0; i < 3 * sys->nnodes; i++)
            dmax = fmax(dmax, fabs(eq[0]->positions[i] -
                                   eq[1]->positions[i]));
        double allow = 10 * (eq[0]->shape_error + eq[1]->shape_error);
        CHECK(dmax <= allow,
              "%s, %d links: the two shapes %.2g m apart, within %.2g (ten "
              "times their shape error estimates, %.2g and %.2g m; Skeel "
              "condition %.3g)",
              path, nl, dmax, allow, eq[0]->shape_error, eq[1]->shape_error,
              eq[0]->condition);
        for (int i = 0; i < 2; i++) {
            ts_trust t;
            ts_trust_init(&t);
            ts_health_equilibrium(sys, eq[i], &t);
            CHECK(t.trustworthy, "%s, %d links: shape %d trustworthy (%s)",
                  path, nl, i + 1,
                  t.nnotes ? t.notes[0] : (t.nreasons ? t.reasons[0] : ""));
        }
    }
    free(g);
    ts_equilibrium_free(eq[0]);
    ts_equilibrium_free(eq[1]);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* 5, 6 and 7. */
static void test_scenes(void)
{
    ts_units *u = tscene_units();
    if (!u)
        return;
    coarse_case(u, "examples/two_part_tow.yaml", 35);
    coarse_case(u, "examples/two_part_tow_vehicle.yaml", 22);
    condition_case(u, "examples/two_part_tow.yaml", 35);
    condition_case(u, "examples/two_part_tow.yaml", 0);
    condition_case(u, "examples/kamman_ex1_submerged.yaml", 0);
    restart_case(u, "examples/two_part_tow.yaml", 35);
    ts_units_free(u);
}

/* With an argument N (suite huge): only case 7, the two-part tow at N
 * links a cable (266: 798 links, Skeel condition 6.2e12; about a minute). */
int main(int argc, char **argv)
{
    if (argc > 1) {
        ts_units *u = tscene_units();
        if (u)
            restart_case(u, "examples/two_part_tow.yaml", atoi(argv[1]));
        ts_units_free(u);
        return tc_done();
    }
    test_joints();
    test_kernel_gradient();
    test_energy();
    test_beam_string();
    test_scenes();
    return tc_done();
}
