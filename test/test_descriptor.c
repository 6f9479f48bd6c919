/* test_descriptor.c: the sparse linear model (lib/descriptor.h,
 * lib/shift.h) against the dense one of lib/linearize.c, which
 * differentiates the eliminated kernel f(y, u) column by column: two
 * linearizations that share only the kernel's load assembly.
 *
 *  1. The residual is the kernel: at a moving, non-equilibrium state of a
 *     scene with every kind of link and body (rigid and elastic links,
 *     bending, a junction, a sphere and a towfish, a turn with a current,
 *     tow-point motion), the node residual at the kernel's positions,
 *     velocities, accelerations and tensions is zero to rounding (1e-12 of
 *     the largest force).
 *  2. E^-1 F = A on every shipped example (about its equilibrium, at the
 *     scene's link count and at 40 links): every column of the dense A
 *     formed from the sparse model (S_inf solves) equals the column of
 *     the dense linearization within ten times the sum of the two error
 *     estimates (each (D(2h) - D(h)) / 3; the factor covers the estimate's
 *     own uncertainty, as for eigenvalue bounds) plus 1e-8 of the column's
 *     size (rounding, see ROUNDING); the same for the nine columns of B
 *     (the heave columns excepted when the tow point is at the waterline,
 *     a kink both report). The vehicle examples alike: their angles,
 *     rates and controller states are columns of A, their inputs columns
 *     of B.
 *  3. The shifted solve: (A - s I)^-1 b by the sparse model equals the
 *     dense solve (LAPACK) at real and complex s, to 1e-7 relative (the
 *     two A differ by ~1e-9 relative; (A - s I)^-1 amplifies by the
 *     distance of s to the spectrum).
 *  4. The maps between the kernel's coordinates and node displacements
 *     invert each other (1e-12).
 *  5. The number of residual evaluations does not grow with the links:
 *     the same groups at 20 and 2000 links.
 *  6. A towing vehicle at the root (DOLPHIN with 6 degrees of freedom, a
 *     surface ship with 3): section 2 with each column of B against its
 *     own estimate, the sparse LU's fill, and the frequency response by
 *     the sparse model against the dense one at four frequencies.
 */
#include <complex.h>
#include <float.h>
#include <glob.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <klu.h>

#include "descriptor.h"
#include "kernel_impl.h"
#include "shift.h"
#include "lapack.h"
#include "tcheck.h"
#include "tscene.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/response.h"
#include "towstab/scene.h"

static ts_units *units;

/* Every kind of link and body, in a turn with a current. */
static const char *mixed_yaml =
    "name: mixed\n"
    "environment: {current: [0.21, -0.13, 0]}\n"
    "tow: {speed: 2.1, turn_rate: 0.037, point: [0, 0, -1.3]}\n"
    "cables:\n"
    "  - {name: main, from: tow, to: knot, length: 14.3, diameter: 0.02,\n"
    "     mass_per_length: 0.9, links: 7, normal_drag: 1.2, added_mass: 1.0,\n"
    "     EI: 35}\n"
    "  - {name: a, from: knot, to: fish, length: 7.1, diameter: 0.012,\n"
    "     mass_per_length: 0.4, links: 5, normal_drag: 1.1, EA: 3.3e6,\n"
    "     damping: 900, EI: 6, added_mass: 0.8}\n"
    "  - {name: b, from: knot, to: ball, length: 5.3, diameter: 0.01,\n"
    "     mass_per_length: 0.3, links: 4, normal_drag: 1.3}\n"
    "bodies:\n"
    "  - {name: knot, type: junction, mass: 3.0}\n"
    "  - {name: fish, type: cylinder, diameter: 0.2, length: 1.1, mass: 30,\n"
    "     drag: 0.3, cross_drag: 1.0, added_mass: 0.1, cross_added_mass: "
    "1.0}\n"
    "  - {name: ball, type: sphere, diameter: 0.25, mass: 9.0, drag: 0.5,\n"
    "     added_mass: 0.5}\n";

static void test_residual_is_kernel(void)
{
    ts_scene *sc = tscene_parse(units, mixed_yaml);
    const ts_system *sys = sc->system;
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    int n = ts_kernel_nstate(k), nq = n / 2, nn = sys->nnodes;
    double *y = malloc((size_t)n * sizeof(double));
    double *f = malloc((size_t)n * sizeof(double));
    double *R = malloc(3 * (size_t)nn * sizeof(double));
    double *r = malloc(3 * (size_t)nn * sizeof(double));
    double *v = malloc(3 * (size_t)nn * sizeof(double));
    double *a = malloc(3 * (size_t)nn * sizeof(double));
    double *t = malloc((size_t)sys->nlinks * sizeof(double));
    /* A sagging, twisted, moving shape; elastic links stretched 1e-4. */
    for (int l = 0; l < sys->nlinks; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o] = 0.35 + 0.07 * l;
        y[o + 1] = 0.2 * sin(0.9 * l);
        y[nq + o] = 0.03 * cos(0.5 * l);
        y[nq + o + 1] = -0.02 + 0.004 * l;
        if (sys->links[l].elastic) {
            y[o + 2] = 1e-4 * (1 + 0.1 * l);
            y[nq + o + 2] = 2e-5 * sin(l);
        }
    }
    double u[TS_NINPUT] = {0.03, -0.02, 0.05, 0.2, 0.1, -0.3, 0.4, -0.7, 1.1};
    ts_frame fr;
    ts_kernel_get_frame(k, &fr);
    fr.speed_rate = 0.13;
    fr.turn_accel = -0.004;
    ts_kernel_set_frame(k, &fr);
    int rc = ts_kernel_eval(k, y, u, f);
    CHECK(rc == TS_OK, "mixed: kernel evaluated at a moving state");
    memcpy(r, ts_kernel_positions(k), 3 * (size_t)nn * sizeof(double));
    memcpy(v, ts_kernel_velocities(k), 3 * (size_t)nn * sizeof(double));
    memcpy(a, ts_kernel_rel_accelerations(k), 3 * (size_t)nn * sizeof(double));
    memcpy(t, ts_kernel_tensions(k), (size_t)sys->nlinks * sizeof(double));
    double scale;
    ts_kernel_unbalanced(k, &scale);
    rc = tsi_kernel_residual(k, r, v, a, t, NULL, NULL, u, R);
    double worst = 0;
    for (int i = 3; i < 3 * nn; i++)
        worst = fmax(worst, fabs(R[i]));
    CHECK(rc == TS_OK && worst <= 1e-12 * scale,
          "mixed: the node residual at the kernel's solution is %.3g N, "
          "<= 1e-12 of the largest force %.4g N",
          worst, scale);
    /* And it is not trivially zero: a wrong tension shows. */
    t[3] += 1.0;
    tsi_kernel_residual(k, r, v, a, t, NULL, NULL, u, R);
    worst = 0;
    for (int i = 1; i < nn; i++)
        worst = fmax(worst, sqrt(R[3 * i] * R[3 * i] + R[3 * i + 1] *
                                 R[3 * i + 1] + R[3 * i + 2] * R[3 * i + 2]));
    CHECK(fabs(worst - 1.0) < 1e-9,
          "mixed: 1 N more tension in one link leaves 1 N unbalanced "
          "(%.12g)",
          worst);
    free(y);
    free(f);
    free(R);
    free(r);
    free(v);
    free(a);
    free(t);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* Linearize about the equilibrium with both models; NULL when there is no
 * equilibrium. */
static ts_linear *both(const ts_system *sys, ts_kernel **kout, int *conv)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_linear *lin = NULL;
    *conv = ts_equilibrium_solve(k, NULL, eq, &err) == TS_OK;
    if (*conv) {
        ts_linearize_opts o;
        ts_linearize_opts_default(&o);
        o.model = TS_LIN_BOTH;
        lin = ts_linear_alloc(k, &err);
        if (ts_linearize_equilibrium(k, eq, &o, lin, &err) != TS_OK) {
            printf("  linearize: %s\n", err.msg);
            ts_linear_free(lin);
            lin = NULL;
        }
    }
    ts_equilibrium_free(eq);
    *kout = k;
    return lin;
}

/* Rounding allowance relative to a column's largest entry: each finite
 * difference rounds to ~eps^(2/3) = 4e-11 of the largest term of f, which
 * in the stiff columns (strain rates of elastic links) is about 100 times
 * the column's entries. */
#define ROUNDING 1e-8

static double col_max(const double *x, int n)
{
    double m = 0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(x[i]));
    return m;
}

/* The largest difference between the columns of B from the sparse model
 * (S_inf solves, acc) and the dense B, over the kernel's inputs (the tow
 * heave columns left out at a kinked tow point), as a fraction of its
 * allowance: ten times the two truncation estimates (the sparse column's,
 * and the dense model's largest, b_trunc_err, or with own its column's
 * Berr) plus ROUNDING of the column. The worst column into *wj (may be
 * NULL). */
static double b_worst(const ts_linear *lin, tsi_shift *acc, int own,
                      int *wj)
{
    int n = lin->nstate, nlow = n - lin->nq;
    double *col = malloc((size_t)n * sizeof(double));
    double *ecol = malloc((size_t)n * sizeof(double));
    double wb = 0;
    for (int j = 0; j < lin->frame_input; j++) {
        if (lin->kink_tow && j < TS_NINPUT && j % 3 == 2)
            continue;
        tsi_shift_apply_input(acc, j, col, 0);
        tsi_shift_apply_input(acc, j, ecol, 1);
        const double *Bd = lin->B + (size_t)j * n;
        double diff = 0;
        for (int i = 0; i < n; i++)
            diff = fmax(diff, fabs(col[i] - Bd[i]));
        double dense = own ? col_max(lin->Berr + (size_t)j * nlow, nlow)
                           : lin->b_trunc_err;
        double allow = 10.0 * (dense + col_max(ecol, n)) +
                       ROUNDING * col_max(Bd, n);
        if (diff / allow > wb) {
            wb = diff / allow;
            if (wj)
                *wj = j;
        }
    }
    free(col);
    free(ecol);
    return wb;
}

/* Section 2: A and B from the sparse model against the dense ones. */
static void compare_dense(const char *name, const ts_system *sys)
{
    ts_kernel *k;
    int conv;
    ts_linear *lin = both(sys, &k, &conv);
    if (!conv) {
        printf("  %s: no equilibrium (a released or dropped scene): no "
               "linear model to compare\n",
               name);
        ts_kernel_free(k);
        return;
    }
    if (!lin) {
        CHECK(0, "%s: linearized with both models", name);
        ts_kernel_free(k);
        return;
    }
    if (sys->tow.vehicle >= 0 && !lin->desc) {
        /* A towing vehicle at the root keeps the dense model alone. */
        CHECK(lin->A != NULL, "%s (%d links): a towing vehicle: the dense "
              "model only", name, sys->nlinks);
        ts_linear_free(lin);
        ts_kernel_free(k);
        return;
    }
    CHECK(lin->desc && lin->A, "%s (%d links): both models formed", name,
          sys->nlinks);
    if (!lin->desc) {
        ts_linear_free(lin);
        ts_kernel_free(k);
        return;
    }
    int n = lin->nstate, nq = lin->nq;
    ts_err err = {0};
    tsi_shift acc;
    int rc = tsi_shift_factor_inf(&acc, lin, &err);
    double *x = calloc((size_t)n, sizeof(double));
    double *col = malloc((size_t)n * sizeof(double));
    double *ecol = malloc((size_t)n * sizeof(double));
    double worst = 0, wb = 0;
    int wj = -1;
    for (int j = 0; rc == TS_OK && j < n; j++) {
        x[j] = 1.0;
        tsi_shift_apply(&acc, x, col, 0);
        tsi_shift_apply(&acc, x, ecol, 1);
        x[j] = 0.0;
        const double *Ad = lin->A + (size_t)j * n;
        double diff = 0;
        for (int i = 0; i < n; i++)
            diff = fmax(diff, fabs(col[i] - Ad[i]));
        double allow = 10.0 * (col_max(ecol + nq, n - nq) +
                               col_max(lin->Aerr + (size_t)j * (n - nq),
                                       n - nq)) +
                       ROUNDING * col_max(Ad, n);
        if (diff / allow > worst) {
            worst = diff / allow;
            wj = j;
        }
    }
    CHECK(rc == TS_OK && worst <= 1.0,
          "%s (%d links): E^-1 F = A within the error estimates, every "
          "column (largest difference %.3g of the allowance, column %d)",
          name, sys->nlinks, worst, wj);
    /* The kernel's inputs; the frame inputs after them are columns of
     * the dense B only (doc/linear.md, section 1). */
    if (rc == TS_OK)
        wb = b_worst(lin, &acc, 0, NULL);
    CHECK(rc == TS_OK && wb <= 1.0,
          "%s (%d links): the columns of B agree within their error "
          "estimates (largest difference %.3g of the allowance)",
          name, sys->nlinks, wb);
    if (rc == TS_OK)
        tsi_shift_free(&acc);
    free(x);
    free(col);
    free(ecol);
    ts_linear_free(lin);
    ts_kernel_free(k);
}

static void test_examples(void)
{
    glob_t g;
    int grc = glob("examples/*.yaml", 0, NULL, &g);
    CHECK(grc == 0 && g.gl_pathc >= 9, "examples found: %zu",
          grc == 0 ? g.gl_pathc : 0);
    for (size_t i = 0; grc == 0 && i < g.gl_pathc; i++) {
        ts_err err = {0};
        ts_scene *sc = ts_scene_load(g.gl_pathv[i], units, &err);
        if (!sc) {
            CHECK(0, "%s: %s", g.gl_pathv[i], err.msg);
            continue;
        }
        ts_system *sys = sc->system;
        compare_dense(g.gl_pathv[i], sys);
        for (int c = 0; c < sys->ncables; c++) {
            sys->cables[c].nlinks = 40 / sys->ncables + 1;
            free(sys->cables[c].link_fraction);
            sys->cables[c].link_fraction = NULL;
        }
        if (ts_system_build(sys, &err) == TS_OK)
            compare_dense(g.gl_pathv[i], sys);
        ts_scene_free(sc);
    }
    if (grc == 0)
        globfree(&g);
}

/* Section 3: (A - s I)^-1 b, sparse against dense. */
/* The mixed scene without turn and current (an equilibrium), its
 * kernel and both models (both). */
static ts_linear *mixed_straight(ts_scene **sc, ts_kernel **k, int *conv)
{
    *sc = tscene_parse(units, mixed_yaml);
    ts_system *sys = (*sc)->system;
    sys->tow.turn_rate = 0;
    sys->env.current[0] = sys->env.current[1] = 0;
    return both(sys, k, conv);
}

static void test_shifted_solve(void)
{
    ts_scene *sc;
    ts_kernel *k;
    int conv;
    ts_linear *lin = mixed_straight(&sc, &k, &conv);
    ts_system *sys = sc->system;
    CHECK(conv && lin, "mixed, straight: equilibrium and both models");
    if (!lin) {
        ts_kernel_free(k);
        ts_scene_free(sc);
        return;
    }
    int n = lin->nstate, one = 1, info;
    double complex *M = malloc((size_t)n * n * sizeof *M);
    double complex *b = malloc((size_t)n * sizeof *b);
    double complex *xd = malloc((size_t)n * sizeof *xd);
    double complex *xs = malloc((size_t)n * sizeof *xs);
    double *br = malloc((size_t)n * sizeof *br);
    double *xr = malloc((size_t)n * sizeof *xr);
    int *piv = malloc((size_t)n * sizeof *piv);
    static const double complex shifts[] = {0.0, -0.37, 2.3 * I,
                                            -0.8 + 11.7 * I, 240.0 * I};
    for (int si = 0; si < 5; si++) {
        double complex s = shifts[si];
        for (int i = 0; i < n; i++) {
            b[i] = sin(1.7 * i + 0.3) + I * (cimag(s) != 0 ? cos(0.9 * i) : 0);
            br[i] = creal(b[i]);
        }
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++)
                M[i + (size_t)j * n] = lin->A[i + (size_t)j * n] -
                                       (i == j ? s : 0);
        memcpy(xd, b, (size_t)n * sizeof *b);
        double mnorm = 0, rcond = 0;
        for (int j = 0; j < n; j++) {
            double c = 0;
            for (int i = 0; i < n; i++)
                c += cabs(M[i + (size_t)j * n]);
            mnorm = fmax(mnorm, c);
        }
        zgesv_(&n, &one, M, &n, piv, xd, &n, &info);
        if (info == 0) {
            double complex *wk = malloc(2 * (size_t)n * sizeof *wk);
            double *rw = malloc(2 * (size_t)n * sizeof *rw);
            int cinfo;
            zgecon_("1", &n, M, &n, &mnorm, &rcond, wk, rw, &cinfo, 1);
            free(wk);
            free(rw);
        }
        /* Near an eigenvalue (s = -0.37 is one: cond_1 ~ 4e10) either
         * solve's own forward error is of order cond_1 eps (the rounding
         * of the LU, which differs between BLAS kernels), so the
         * allowance is the larger of that and the models' 1e-7. */
        double tol = fmax(1e-7, DBL_EPSILON / fmax(rcond, 1e-300));
        tsi_shift sh;
        ts_err err = {0};
        int rc = tsi_shift_factor(&sh, lin, s, &err);
        double diff = 0, big = 0, diffr = 0;
        if (rc == TS_OK) {
            tsi_shift_solve(&sh, b, xs);
            if (cimag(s) == 0)
                tsi_shift_solve_real(&sh, br, xr);
            for (int i = 0; i < n; i++) {
                diff = fmax(diff, cabs(xs[i] - xd[i]));
                big = fmax(big, cabs(xd[i]));
                if (cimag(s) == 0)
                    diffr = fmax(diffr, fabs(xr[i] - creal(xd[i])));
            }
            tsi_shift_free(&sh);
        }
        CHECK(rc == TS_OK && info == 0 && diff <= tol * big &&
                  diffr <= tol * big,
              "mixed: (A - s I)^-1 b at s = %g%+gi, sparse vs dense: "
              "%.3g (real solve %.3g) of %.3g, <= %.2g relative "
              "(max(1e-7, cond_1 %.3g x eps)) (%s)",
              creal(s), cimag(s), diff, diffr, big, tol, 1 / rcond,
              err.msg);
    }
    /* Section 4: the maps. */
    double *dq = malloc((size_t)lin->nq * sizeof(double));
    double *dq2 = malloc((size_t)lin->nq * sizeof(double));
    double *dr = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    for (int i = 0; i < lin->nq; i++)
        dq[i] = 1e-3 * sin(2.3 * i + 1);
    ts_linear_node_displacements(sys, lin, dq, dr);
    tsi_desc_from_nodes(sys, lin, dr, dq2);
    double md = 0;
    for (int i = 0; i < lin->nq; i++)
        md = fmax(md, fabs(dq2[i] - dq[i]));
    CHECK(md <= 1e-15, "mixed: node displacements map back to the "
                       "coordinates (%.3g rad)",
          md);
    free(dq);
    free(dq2);
    free(dr);
    free(M);
    free(b);
    free(xd);
    free(xs);
    free(br);
    free(xr);
    free(piv);
    ts_linear_free(lin);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* The eigenvalue error estimates (tsi_shift_eig_error) in one sequence,
 * each S(lambda) refactored with the previous eigenvalue's pivots and
 * judged by its first solve's backward error (SHIFT_NEAR_BACKWARD), equal
 * those of a fresh factorisation per eigenvalue: the first-order change
 * within 1e-6 of itself, the Ritz value's own error within 1e-9 |lambda|
 * (what the left vector's backward error of 1e-10 may move it by, and
 * far below the bounds it enters). On the mixed scene's 12 lowest modes
 * (LAPACK's, real and complex, so the sequence also crosses between real
 * and complex arithmetic). */
static void test_eig_error_refactored(void)
{
    ts_scene *sc;
    ts_kernel *k;
    int conv;
    ts_linear *lin = mixed_straight(&sc, &k, &conv);
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    o.method = TS_EIG_LAPACK;
    o.count = 12;
    ts_eigen *e = NULL;
    ts_err err = {0};
    int rc = lin ? ts_eigen_solve(lin, &o, &e, &err) : TS_EINVAL;
    CHECK(conv && rc == TS_OK && e->nmodes == 12 && e->vec_re,
          "mixed: 12 modes with their vectors (%s)", err.msg);
    int n = lin ? lin->nstate : 0, nreal = 0, checked = 0;
    double dworst = 0, rworst = 0;
    double complex *v = malloc(((size_t)n + 1) * sizeof *v);
    tsi_shift seq = {0};
    for (int m = 0; rc == TS_OK && m < e->nmodes; m++) {
        double complex lam = e->modes[m].re + I * e->modes[m].im;
        for (int i = 0; i < n; i++)
            v[i] = e->vec_re[(size_t)m * n + i] +
                   I * e->vec_im[(size_t)m * n + i];
        nreal += cimag(lam) == 0;
        tsi_shift fresh = {0};
        double d1, r1, d2, r2;
        rc = tsi_shift_eig_error(&seq, lin, lam, v, &d1, &r1, &err);
        if (rc == TS_OK)
            rc = tsi_shift_eig_error(&fresh, lin, lam, v, &d2, &r2, &err);
        tsi_shift_free(&fresh);
        if (rc != TS_OK || !isfinite(d1) || !isfinite(d2))
            break;
        checked++;
        dworst = fmax(dworst, fabs(d1 - d2) / d2);
        rworst = fmax(rworst, fabs(r1 - r2) / cabs(lam));
    }
    tsi_shift_free(&seq);
    /* (Some refactorisation served: fresh factorisations alone would
     * give the same estimates bit for bit.) */
    CHECK(rc == TS_OK && checked == 12 && nreal > 0 && nreal < 12 &&
              dworst <= 1e-6 && rworst <= 1e-9 && dworst + rworst > 0,
          "mixed: error estimates of 12 modes (%d real) in one sequence of "
          "refactorisations = fresh ones: first-order change within %.3g "
          "of itself (<= 1e-6, > 0: refactored), Ritz error within %.3g "
          "|lambda| (<= 1e-9) (%s)", nreal, dworst, rworst, err.msg);
    free(v);
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* tsi_shift_refactor_judged over the rightmost search's kind of sequence,
 * imaginary shifts a factor 4 apart (the band top down the grid, then
 * back up): each solve equals a fresh factorisation's within 1e-9 of the
 * solution (the backward error of 1e-10 the refactorisation must keep,
 * times the modest condition away from the eigenvalues), and the old
 * pivots served at least once (else the test would compare fresh
 * factorisations with themselves). On the mixed scene. */
static void test_refactor_judged(void)
{
    ts_scene *sc;
    ts_kernel *k;
    int conv;
    ts_linear *lin = mixed_straight(&sc, &k, &conv);
    int n = lin ? lin->nstate : 0, served = 0, done = 0;
    double worst = 0;
    double complex *b = malloc(((size_t)n + 1) * sizeof *b);
    double complex *x1 = malloc(((size_t)n + 1) * sizeof *x1);
    double complex *x2 = malloc(((size_t)n + 1) * sizeof *x2);
    static const double w[] = {970.0, 242.5, 60.6, 15.2, 3.79, 60.6, 970.0};
    tsi_shift seq = {0};
    ts_err err = {0};
    int rc = lin ? TS_OK : TS_EINVAL;
    for (int i = 0; i < n; i++)
        b[i] = sin(1.3 * i + 0.2) + I * cos(0.7 * i);
    for (int si = 0; rc == TS_OK && si < 7; si++) {
        int fresh = -1;
        rc = tsi_shift_refactor_judged(&seq, lin, I * w[si], &fresh, &err);
        tsi_shift one = {0};
        if (rc == TS_OK)
            rc = tsi_shift_factor(&one, lin, I * w[si], &err);
        if (rc != TS_OK)
            break;
        served += fresh == 0;
        tsi_shift_solve(&seq, b, x1);
        tsi_shift_solve(&one, b, x2);
        tsi_shift_free(&one);
        double diff = 0, big = 0;
        for (int i = 0; i < n; i++) {
            diff = fmax(diff, cabs(x1[i] - x2[i]));
            big = fmax(big, cabs(x2[i]));
        }
        worst = fmax(worst, diff / big);
        done++;
    }
    tsi_shift_free(&seq);
    CHECK(conv && rc == TS_OK && done == 7 && served > 0 && worst <= 1e-9,
          "mixed: 7 shifts a factor 4 apart refactored with the old pivots "
          "while a solve's backward error stays within 1e-10 (%d of 6 "
          "served, > 0): solves within %.3g of a fresh factorisation's "
          "(<= 1e-9) (%s)", served, worst, err.msg);
    free(b);
    free(x1);
    free(x2);
    ts_linear_free(lin);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* Section 5: evaluations independent of the number of links. */
static void test_groups(void)
{
    int groups[4] = {0, 0, 0, 0};
    long evals[4] = {0, 0, 0, 0};
    /* Without bending at 20 and 2000 links, with bending at 20 and 200. */
    static const int links[4] = {20, 2000, 20, 200};
    for (int p = 0; p < 4; p++) {
        char yaml[512];
        snprintf(yaml, sizeof yaml,
                 "name: towed\n"
                 "tow: {speed: 2.385, point: [0, 0, 0.7]}\n"
                 "cables:\n"
                 "  - {name: cable, from: tow, to: sphere, length: 31.7,\n"
                 "     diameter: 0.021, mass_per_length: 0.83, links: %d,\n"
                 "     normal_drag: 1.2, added_mass: 1.0, EI: %g}\n"
                 "bodies:\n"
                 "  - {name: sphere, type: sphere, diameter: 0.3, mass: "
                 "41.0}\n",
                 links[p], p < 2 ? 0.0 : 2.0);
        ts_scene *sc = tscene_parse(units, yaml);
        ts_err err = {0};
        ts_kernel *k = ts_kernel_alloc(sc->system, &err);
        ts_equilibrium *eq = ts_equilibrium_alloc(sc->system, &err);
        ts_equilibrium_solve(k, NULL, eq, &err);
        ts_linear *lin = ts_linear_alloc(k, &err);
        ts_linearize_opts o;
        ts_linearize_opts_default(&o);
        o.model = TS_LIN_SPARSE;
        int rc = ts_linearize_equilibrium(k, eq, &o, lin, &err);
        if (rc == TS_OK) {
            groups[p] = lin->groups;
            evals[p] = lin->residual_evaluations;
        }
        CHECK(rc == TS_OK && !lin->A,
              "%d links: sparse model only (no dense A), %d groups, %ld "
              "residual evaluations (%s)",
              links[p], lin->groups, lin->residual_evaluations, err.msg);
        ts_linear_free(lin);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        ts_scene_free(sc);
    }
    /* Positions 3 colours (rows reach 1 link), 5 with bending (2 links);
     * velocities 3; times x, y, z (the frame inputs' 4 only when asked
     * for: test_response). */
    CHECK(groups[0] == 18 && groups[1] == 18 && evals[0] == evals[1],
          "groups at 20 and 2000 links: %d and %d (18), evaluations %ld and "
          "%ld",
          groups[0], groups[1], evals[0], evals[1]);
    CHECK(groups[2] == 24 && groups[3] == 24 && evals[2] == evals[3],
          "with bending, groups at 20 and 200 links: %d and %d (24), "
          "evaluations %ld and %ld",
          groups[2], groups[3], evals[2], evals[3]);
}

/* A scene's linear model about its equilibrium with the model asked for
 * (tensions for the dense tension Jacobians); NULL when it fails. */
static ts_linear *linear_of(const ts_system *sys, ts_lin_model model,
                            ts_kernel **kout)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_linear *lin = NULL;
    if (k && eq && ts_equilibrium_solve(k, NULL, eq, &err) == TS_OK) {
        ts_linearize_opts o;
        ts_linearize_opts_default(&o);
        o.model = model;
        o.tensions = 1;
        lin = ts_linear_alloc(k, &err);
        if (lin && ts_linearize_equilibrium(k, eq, &o, lin, &err) != TS_OK) {
            printf("  linearize: %s\n", err.msg);
            ts_linear_free(lin);
            lin = NULL;
        }
    } else {
        printf("  equilibrium: %s\n", err.msg);
    }
    ts_equilibrium_free(eq);
    *kout = k;
    return lin;
}

/* The most entries of the sparse LU per entry of S(s): a cable's band
 * fills about 2 times; AMD's ordering with node 0 free gave 6.9 times on
 * dolphin_aurora at 30 links and 24 at 100 (the dense LU's). */
#define FILL_MAX 4.0

/* 6. A towing vehicle at the root (6 degrees of freedom, and a surface
 * ship of 3): E^-1 F = A and E^-1 G = B (section 2's allowance: ten times
 * the two models' truncation estimates plus ROUNDING of the column),
 * here with each column of B judged against its own estimate (Berr) and
 * the tow inputs' columns named; then the frequency response by the
 * sparse model (one sparse complex solve per frequency) against the
 * dense one's at four frequencies, for a position, a tension, a tow
 * translation, a tow rotation (each cable's start point moved by its own
 * theta x r) and a vehicle input: the difference within the sum of the two
 * gains' error allowances (each ten times its model's error estimate,
 * lib/response.c). */
static void towing_case(const char *path, const char *pos_name,
                        const char *out2, const char *tow_input,
                        const char *rot_input, const char *input_name)
{
    ts_err err = {0};
    ts_scene *sc = ts_scene_load(path, units, &err);
    if (!CHECK(sc != NULL, "%s: %s", path, err.msg))
        return;
    const ts_system *sys = sc->system;
    ts_kernel *k, *kd;
    ts_linear *lin = linear_of(sys, TS_LIN_BOTH, &k);
    ts_linear *lsp = linear_of(sys, TS_LIN_SPARSE, &kd);
    CHECK(lin && lin->desc && lin->A && lsp && lsp->desc && !lsp->A,
          "%s: a towing vehicle at the root: the sparse model formed (alone "
          "when asked)", path);
    if (!lin || !lin->desc || !lsp) {
        ts_linear_free(lin);
        ts_linear_free(lsp);
        ts_kernel_free(k);
        ts_kernel_free(kd);
        ts_scene_free(sc);
        return;
    }
    tsi_shift acc;
    int rc = tsi_shift_factor_inf(&acc, lin, &err);
    int wj = -1;
    double wb = rc == TS_OK ? b_worst(lin, &acc, 1, &wj) : INFINITY;
    CHECK(rc == TS_OK && wb <= 1.0,
          "%s: every column of B (%d inputs: the tow inputs, the vehicles') "
          "within its own error estimates: largest %.3g of the allowance "
          "(%s)", path, lin->frame_input, wb,
          wj >= 0 ? lin->input_name[wj] : "-");
    if (rc == TS_OK)
        tsi_shift_free(&acc);

    /* The factors stay sparse: L + U within FILL_MAX times S's entries
     * at a frequency of the response. */
    tsi_shift sh = {0};
    rc = tsi_shift_factor(&sh, lin, I * 2.0 * M_PI * 0.33, &err);
    if (rc == TS_OK) {
        const klu_numeric *num = sh.numeric;
        double fill = (double)(num->lnz + num->unz) / lin->desc->nnz;
        CHECK(fill <= FILL_MAX, "%s: the sparse LU at 0.33 Hz holds %.2f "
              "times the entries of S(s) (%d unknowns), <= %g", path, fill,
              lin->desc->nx, FILL_MAX);
        tsi_shift_free(&sh);
    } else {
        CHECK(0, "%s: factored at 0.33 Hz: %s", path, err.msg);
    }

    /* The response, sparse against dense. */
    ts_kernel *kdd;
    ts_linear *ld = linear_of(sys, TS_LIN_DENSE, &kdd);
    static const double freq[4] = {0.0137, 0.071, 0.33, 1.9};
    const char *outs[3] = {pos_name, out2, NULL};
    int inputs[3] = {-1, -1, -1};
    if (ts_response_input_lookup(k, tow_input, &inputs[0], &err) != TS_OK ||
        ts_response_input_lookup(k, rot_input, &inputs[1], &err) != TS_OK ||
        ts_response_input_lookup(k, input_name, &inputs[2], &err) != TS_OK)
        CHECK(0, "%s: %s", path, err.msg);
    double worst = 0, rel = 0, sworst = 0, srel = 0;
    int nchecks = 0, nstatic = 0, nundef = 0, smismatch = 0;
    char snote[256] = "";
    for (int oi = 0; ld && oi < 2; oi++) {
        ts_output out;
        if (ts_response_output_lookup(k, outs[oi], &out, &err) != TS_OK) {
            CHECK(0, "%s: %s", path, err.msg);
            continue;
        }
        for (int ii = 0; ii < 3; ii++) {
            if (inputs[ii] < 0)
                continue;
            ts_response *rs = NULL, *rd = NULL;
            int r1 = ts_response_compute(sys, lsp, inputs[ii], &out, freq, 4,
                                         &rs, &err);
            int r2 = r1 == TS_OK ? ts_response_compute(sys, ld, inputs[ii],
                                                       &out, freq, 4, &rd,
                                                       &err)
                                 : r1;
            if (!CHECK(r1 == TS_OK && r2 == TS_OK, "%s: response of %s: %s",
                       path, out.name, err.msg)) {
                ts_response_free(rs);
                ts_response_free(rd);
                continue;
            }
            for (int i = 0; i < 4; i++) {
                double d = hypot(rs->re[i] - rd->re[i], rs->im[i] - rd->im[i]);
                double allow = rs->error[i] + rd->error[i];
                worst = fmax(worst, d / allow);
                rel = fmax(rel, allow / rd->magnitude[i]);
                nchecks++;
            }
            /* The static gain: the sparse model's limit by extrapolation
             * against the dense model's bordered solve, or both
             * undefined. */
            if (isnan(rs->static_gain) && isnan(rd->static_gain)) {
                nundef++;
                snprintf(snote, sizeof snote, "%s", rs->static_note);
            } else {
                double d = fabs(rs->static_gain - rd->static_gain);
                double allow = rs->static_error + rd->static_error;
                if (!(d <= allow))
                    smismatch++;
                if (d / allow > sworst || isnan(d / allow))
                    sworst = d / allow;
                srel = fmax(srel, allow / fabs(rd->static_gain));
                nstatic++;
            }
            ts_response_free(rs);
            ts_response_free(rd);
        }
    }
    /* With the sparse model alone: every mode (LAPACK) refused, naming
     * the dense A; a number of modes from ARPACK on the sparse model, the
     * neutral modes found there and recognised (doc/linear.md section
     * 3a). */
    ts_eigen *eg = NULL;
    ts_err_clear(&err);
    int erc = ts_eigen_solve(lsp, NULL, &eg, &err);
    CHECK(erc == TS_EINVAL && !eg && strstr(err.msg, "dense A"),
          "%s: every mode with the sparse model alone refused: %s", path,
          err.msg);
    ts_eigen_free(eg);
    eg = NULL;
    ts_err_clear(&err);
    ts_eigen_opts eo;
    ts_eigen_opts_default(&eo);
    eo.count = 10;
    erc = ts_eigen_solve(lsp, &eo, &eg, &err);
    CHECK(erc == TS_OK && eg->method == TS_EIG_ARPACK &&
              lsp->nneutral > 0 && eg->nneutral == lsp->nneutral &&
              eg->sweep_shifts > 0,
          "%s: 10 modes with the sparse model alone: ARPACK with the "
          "rightmost search (%d shifts), %d of its %d neutral modes "
          "recognised, verdict %s (%s)", path, eg ? eg->sweep_shifts : 0,
          eg ? eg->nneutral : 0, lsp->nneutral,
          eg ? ts_verdict_name(eg->verdict) : "-", err.msg);
    ts_eigen_free(eg);
    CHECK(ld && nchecks == 24 && worst <= 1.0,
          "%s: the sparse response equals the dense one at 4 frequencies "
          "(%s and %s to %s, %s and %s, %d gains): largest difference "
          "%.3g of the two error allowances (themselves at most %.2g of "
          "the gain)", path, pos_name, out2, tow_input, rot_input,
          input_name, nchecks, worst, rel);
    CHECK(ld && nstatic + nundef == 6 && smismatch == 0,
          "%s: the static gains with the sparse model alone (extrapolated "
          "to 0 Hz) equal the dense model's (bordered solve): %d defined "
          "on both, largest difference %.3g of the two allowances (at most "
          "%.2g of the gain); %d undefined on both%s%s", path, nstatic,
          sworst, srel, nundef, nundef ? ", e.g.: " : "", snote);
    ts_linear_free(ld);
    ts_linear_free(lin);
    ts_linear_free(lsp);
    ts_kernel_free(k);
    ts_kernel_free(kd);
    ts_kernel_free(kdd);
    ts_scene_free(sc);
}

/* towing_sphere's tug with a PI speed controller (its integrator the
 * first controller state, then its depth loop's). */
static const char *pi_yaml =
    "name: pi\n"
    "tow: {speed: 2.5 m/s, point: [0, 0, 20 m]}\n"
    "towing_vehicle:\n"
    "  name: tug\n"
    "  mass: 4126.1375 kg\n"
    "  volume: 4.0255 m^3\n"
    "  inertia: [330 kg*m^2, 22000 kg*m^2, 22000 kg*m^2]\n"
    "  mass_centre: [0, 0, 0.05 m]\n"
    "  tow_point: [-4 m, 0, 0]\n"
    "  added_mass: spheroid\n"
    "  components:\n"
    "    - {name: hull, type: hull, length: 8 m, diameter: 0.8 m}\n"
    "    - {name: foreplane, type: surface, position: [0.5 m, 0, 0],\n"
    "       area: 0.4 m^2, span: 1.2 m, control: true, time_constant: 0.1 s}\n"
    "    - {name: tailplane, type: surface, position: [-3.6 m, 0, 0],\n"
    "       area: 0.6 m^2, span: 1.2 m}\n"
    "    - {name: rudder, type: surface, position: [-3.6 m, 0, 0],\n"
    "       area: 0.6 m^2, span: 1.2 m, roll: 90 deg, control: true}\n"
    "  controllers:\n"
    "    - {name: depth, measure: depth, setpoint: 20 m, kp: 0.05 rad/m,\n"
    "       ki: 0.005 rad/(m*s), kd: 0.2 rad*s/m, surfaces: {foreplane: 1}}\n"
    "  propulsion: {speed: 3 m/s, gain: 2000 N*s/m, integral_gain: 300 N/m,\n"
    "               max_thrust: 1600 N}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: 50 m, diameter: 0.02 m,\n"
    "     weight: 5 N/m, links: 8}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: 0.5 m, wet_weight: 500 N}\n";

static void test_towing(void)
{
    /* A PI speed controller: its integrator in the tug's local block
     * (the speed set point among its inputs). */
    ts_scene *pi = tscene_parse(units, pi_yaml);
    if (CHECK(pi != NULL, "PI speed controller scene parsed")) {
        ts_err err = {0};
        ts_kernel *k = ts_kernel_alloc(pi->system, &err);
        CHECK(k && ts_kernel_speed_integrator(k) == 0 &&
                  ts_kernel_ncontrol(k) == 3,
              "PI speed controller: its integrator the first of 3 "
              "controller states (%d of %d)",
              k ? ts_kernel_speed_integrator(k) : -1,
              k ? ts_kernel_ncontrol(k) : -1);
        ts_kernel_free(k);
        compare_dense("PI speed controller", pi->system);
    }
    ts_scene_free(pi);

    towing_case("examples/dolphin_aurora.yaml", "aurora.z",
                "armoured.1.tension", "tow.heave", "tow.pitch",
                "dolphin.thrust");
    /* A straight tow is symmetric: the lateral outputs to the lateral
     * inputs. */
    towing_case("test/scenes/survey_ship.yaml", "depressor.y", "ship.yaw",
                "tow.sway", "tow.roll", "ship.rudder");
    /* DOLPHIN with a PI speed controller: its integrator is the first
     * controller state, and DOLPHIN is the last vehicle; its own loops'
     * states follow the integrator (lib/kernel.c, layout_controls), so
     * that they are one block, AURORA's after them. Section 2 on it. */
    ts_err err = {0};
    ts_scene *sc = ts_scene_load("examples/dolphin_aurora.yaml", units, &err);
    if (CHECK(sc != NULL, "dolphin_aurora: %s", err.msg)) {
        ts_system *sys = sc->system;
        ts_propulsion *pr = &sys->bodies[sys->tow.vehicle].vehicle->propulsion;
        pr->type = TS_PROP_SPEED;
        pr->speed = 5.0;
        pr->gain = 2000.0;
        pr->ki = 300.0;
        pr->max_thrust = INFINITY;
        ts_kernel *k = ts_kernel_alloc(sys, &err);
        if (CHECK(k != NULL, "dolphin_aurora with a PI speed controller: %s",
                  err.msg)) {
            int root = ts_kernel_root(k), nv = ts_kernel_nvehicles(k);
            tsi_vehicle_layout lr, lo;
            tsi_kernel_vehicle_layout(k, root, &lr);
            tsi_kernel_vehicle_layout(k, root == 0 ? 1 : 0, &lo);
            CHECK(nv == 2 && root == nv - 1 &&
                      ts_kernel_speed_integrator(k) == 0 && lr.c0 == 0 &&
                      lr.nc >= 2 && lo.c0 == lr.nc,
                  "dolphin_aurora with a PI speed controller: DOLPHIN (the "
                  "last of %d vehicles) holds controller states 0..%d, its "
                  "integrator first, AURORA's from %d", nv, lr.nc - 1,
                  lo.c0);
        }
        ts_kernel_free(k);
        compare_dense("dolphin_aurora with a PI speed controller", sys);
        ts_scene_free(sc);
    }
    /* Section 2 on the test scenes with a towing vehicle. */
    const char *scenes[2] = {"test/scenes/survey_ship.yaml",
                             "test/scenes/towing_sphere.yaml"};
    for (int i = 0; i < 2; i++) {
        ts_err_clear(&err);
        sc = ts_scene_load(scenes[i], units, &err);
        if (!CHECK(sc != NULL, "%s: %s", scenes[i], err.msg))
            continue;
        compare_dense(scenes[i], sc->system);
        ts_scene_free(sc);
    }
}

int main(void)
{
    units = tscene_units();
    if (!units)
        return 1;
    test_residual_is_kernel();
    test_examples();
    test_shifted_solve();
    test_eig_error_refactored();
    test_refactor_judged();
    test_groups();
    test_towing();
    ts_units_free(units);
    return tc_done();
}
