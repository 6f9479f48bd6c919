/* test_eigen.c: modes (towstab/eigen.h) against independent references.
 *
 *  1. Hanging chain in vacuum (rho = 0, V = 0), 12 links: the small
 *     oscillations of the discrete chain solve K phi = w^2 M phi with, for
 *     link angles phi_k from the vertical, M_jk = l^2 sum_{i >= max(j,k)} m_i
 *     and K = diag(g l sum_{i >= k} m_i) (m_i the node masses). Solved here
 *     with GSL's generalized symmetric eigensolver, independently of the
 *     kernel and LAPACK. The eigenvalues of A must be purely imaginary,
 *     each frequency twice (in-plane and out-of-plane), equal to the
 *     discrete frequencies to 1e-6 (relative; the linearization error is
 *     ~1e-9).
 *  2. Continuum limit: f_n = (j_0n / 2) sqrt(g/L) / (2 pi), j_0n the zeros
 *     of J0 (GSL gsl_sf_bessel_zero_J0): the error of the 3 lowest
 *     frequencies falls as the links go 10 -> 20 -> 40 and is below 1 % at
 *     40 links for the lowest.
 *  3. ARPACK and LAPACK agree (1e-8 relative) on the modes they share, for
 *     a real shift (lowest modes) and a complex one (nearest 1.3 Hz), on a
 *     towed cable with drag. The Ritz value's own error (ritz_error, the
 *     pencil's Newton correction) equals the true error of Ritz values
 *     left by runs at tolerances 1e-3 and 1e-1 (against a run at machine
 *     precision on the same model) within a factor 2.
 *  4. Every straight-tow example with drag (every scene in examples/, turn rate set
 *     to 0) is stable, with every damping ratio > 0 (a towing vehicle's
 *     neutral modes by symmetry apart).
 *  5. Mode shapes of the chain: the k-th in-plane mode has k - 1 nodes,
 *     shape amplitude 1 at its largest component; the verdict of an
 *     undamped chain is marginal.
 *  6. Refusals: negative count, negative target, arpack without a count,
 *     too many modes for arpack.
 *  7. The error bound covers rounding: Kamman ex. 3 in the turn, ex. 1
 *     above the water and ex. 4 at 10 links, linearized with the default
 *     step and with steps 1e-7 and 1e-8 (where the rounding noise of the
 *     differences, eps / h, dominates the truncation, h^2): every
 *     eigenvalue is within its error bound of the eigenvalues of an
 *     independent, tighter linearization (central differences at steps
 *     5e-4 and 1e-3 extrapolated twice, sixth order, rounding 1e4 times
 *     smaller) up to that reference's own uncertainty (its distance to
 *     the fourth-order value at 5e-4); at step 1e-8 at least a third of
 *     the modes have errors 10 times that uncertainty, so the check is
 *     not the reference's. The same with ARPACK for the 8 modes nearest
 *     0 through the sparse model (its entry-wise truncation and rounding,
 *     left and right vectors of the pencil) at the three steps, and on
 *     the dense A alone at 1e-8 (no left vectors: the rounding term with
 *     every |u_i| 1).
 */
#include "towstab/eigen.h"

#include <complex.h>
#include <glob.h>
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_sf_bessel.h>
#include <gsl/gsl_sort_vector.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/analysis.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"

static ts_units *units;

/* Solve, linearize; NULL on failure (reported). */
static ts_linear *linearize(const ts_system *sys)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_linear *lin = NULL;
    if (ts_equilibrium_solve(k, NULL, eq, &err) == TS_OK) {
        lin = ts_linear_alloc(k, &err);
        if (ts_linearize_equilibrium(k, eq, NULL, lin, &err) != TS_OK) {
            ts_linear_free(lin);
            lin = NULL;
        }
    }
    if (!lin)
        printf("linearize %s: %s\n", sys->name, err.msg);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return lin;
}

static char *chain_yaml(int links, double length)
{
    static char buf[512];
    snprintf(buf, sizeof buf,
             "name: chain\n"
             "environment: {water_density: 0, gravity: 9.80665}\n"
             "tow: {speed: 0}\n"
             "cables:\n"
             "  - {name: chain, from: tow, length: %.17g, diameter: 0.01,\n"
             "     mass_per_length: 1.37, links: %d}\n",
             length, links);
    return buf;
}

/* The discrete chain's angular frequencies, ascending, into w[N]. */
static void chain_exact(const ts_system *sys, double *w)
{
    int N = sys->nlinks;
    double g = sys->env.gravity;
    gsl_matrix *M = gsl_matrix_alloc(N, N), *K = gsl_matrix_calloc(N, N);
    double *below = calloc((size_t)N, sizeof(double));
    for (int k = N - 1; k >= 0; k--)
        below[k] = sys->nodes[sys->links[k].lower].mass +
                   (k + 1 < N ? below[k + 1] : 0.0);
    for (int j = 0; j < N; j++) {
        double lj = sys->links[j].length;
        gsl_matrix_set(K, j, j, g * lj * below[j]);
        for (int k = 0; k < N; k++)
            gsl_matrix_set(M, j, k,
                           lj * sys->links[k].length * below[j > k ? j : k]);
    }
    gsl_vector *eval = gsl_vector_alloc(N);
    gsl_eigen_gensymm_workspace *ws = gsl_eigen_gensymm_alloc(N);
    gsl_eigen_gensymm(K, M, eval, ws);
    gsl_sort_vector(eval);
    for (int i = 0; i < N; i++)
        w[i] = sqrt(gsl_vector_get(eval, i));
    gsl_eigen_gensymm_free(ws);
    gsl_vector_free(eval);
    gsl_matrix_free(M);
    gsl_matrix_free(K);
    free(below);
}

static void test_chain(void)
{
    ts_scene *sc = tscene_parse(units, chain_yaml(12, 8.25));
    const ts_system *sys = sc->system;
    ts_linear *lin = linearize(sys);
    ts_eigen *e = NULL;
    ts_err err = {0};
    int rc = ts_eigen_solve(lin, NULL, &e, &err);
    CHECK(rc == TS_OK, "chain: lapack eigen (%s)", err.msg);
    int N = sys->nlinks;
    CHECK(e->nmodes == 2 * N && e->complete && e->neig == 4 * N,
          "chain: %d modes cover all %d eigenvalues", e->nmodes, e->neig);
    double w[64];
    chain_exact(sys, w);
    double re_worst = 0, f_worst = 0;
    for (int m = 0; m < e->nmodes; m++) {
        re_worst = fmax(re_worst, fabs(e->modes[m].re) / e->modes[m].im);
        /* Sorted by frequency: modes 2i and 2i+1 are the pair of w[i]. */
        f_worst = fmax(f_worst, fabs(e->modes[m].im - w[m / 2]) / w[m / 2]);
    }
    CHECK(re_worst < 1e-8, "chain: purely imaginary, max |Re|/Im %.3g < 1e-8",
          re_worst);
    CHECK(f_worst < 1e-6, "chain: every frequency twice and equal to the "
                          "discrete chain's, max rel err %.3g < 1e-6",
          f_worst);
    CHECK(e->verdict == TS_MARGINAL,
          "chain: undamped, verdict marginal (got %s)",
          ts_verdict_name(e->verdict));

    /* 5. Mode shapes: the lowest in-plane and out-of-plane pair. */
    int nin = 0;
    for (int m = 0; m < 6; m++) {
        char d[256];
        ts_eigen_describe(sys, lin, e, m, d, sizeof d);
        int order = m / 2 + 1;
        char want[32];
        snprintf(want, sizeof want, "order %d (", order);
        CHECK(strstr(d, want) != NULL, "chain mode %d: '%s' has %s", m + 1, d,
              want);
        nin += strstr(d, "in-plane") != NULL;
    }
    CHECK(nin == 3, "chain: one in-plane mode in each of the 3 lowest "
                    "pairs (%d)",
          nin);
    double amp[3 * 13], ph[3 * 13];
    rc = ts_eigen_mode_shape(sys, lin, e, 0, amp, ph, &err);
    double big = 0, zbig = 0;
    for (int i = 0; i < 3 * sys->nnodes; i++) {
        big = fmax(big, amp[i]);
        if (i % 3 == 2)
            zbig = fmax(zbig, amp[i]);
    }
    CHECK(rc == TS_OK && fabs(big - 1) < 1e-12 && zbig < 1e-6,
          "chain mode 1 shape: max amplitude 1 (%.15g), vertical motion "
          "%.3g < 1e-6 (second order only)",
          big, zbig);
    ts_err_clear(&err);
    rc = ts_eigen_mode_shape(sys, lin, e, e->nmodes, amp, ph, &err);
    CHECK(rc == TS_EINVAL, "mode shape: out of range refused (%s)", err.msg);
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_scene_free(sc);
}

static void test_continuum(void)
{
    static const int links[3] = {10, 20, 40};
    double L = 9.3, err_prev[3] = {INFINITY, INFINITY, INFINITY};
    int falling = 1;
    double last1 = 0;
    for (int t = 0; t < 3; t++) {
        ts_scene *sc = tscene_parse(units, chain_yaml(links[t], L));
        ts_linear *lin = linearize(sc->system);
        ts_eigen *e = NULL;
        ts_eigen_opts o;
        ts_eigen_opts_default(&o);
        o.count = 6;
        ts_eigen_solve(lin, &o, &e, NULL);
        double g = sc->system->env.gravity;
        for (int j = 0; j < 3; j++) {
            double fc = 0.5 * gsl_sf_bessel_zero_J0(j + 1) * sqrt(g / L) /
                        (2 * M_PI);
            double f = e->modes[2 * j].freq_hz;
            double rel = fabs(f - fc) / fc;
            printf("  %d links: f%d = %.9f Hz, continuum %.9f, rel err %.3g\n",
                   links[t], j + 1, f, fc, rel);
            falling &= rel < err_prev[j];
            err_prev[j] = rel;
            if (j == 0)
                last1 = rel;
        }
        ts_eigen_free(e);
        ts_linear_free(lin);
        ts_scene_free(sc);
    }
    CHECK(falling, "chain: errors against the continuum fall with links");
    CHECK(last1 < 0.01, "chain, 40 links: f1 within 1%% of the continuum "
                        "(%.3g)",
          last1);
}

static const char *towed_yaml =
    "name: towed\n"
    "tow: {speed: 2.1, point: [0, 0, 0.5]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: fish, length: 40.3, diameter: 0.018,\n"
    "     mass_per_length: 0.71, links: 40, normal_drag: 1.2,\n"
    "     tangential_drag: 0.01, added_mass: 1.0}\n"
    "bodies:\n"
    "  - {name: fish, type: sphere, diameter: 0.4, mass: 63.0, drag: 0.5,\n"
    "     added_mass: 0.5}\n";

/* Nearest LAPACK mode to lambda: relative distance. */
static double nearest(const ts_eigen *all, double re, double im)
{
    double best = INFINITY;
    for (int m = 0; m < all->nmodes; m++)
        best = fmin(best, hypot(all->modes[m].re - re, all->modes[m].im - im));
    return best / hypot(re, im);
}

static void test_arpack_small(void)
{
    ts_scene *sc = tscene_parse(units, towed_yaml);
    ts_linear *lin = linearize(sc->system);
    ts_eigen *all = NULL, *ar = NULL, *lp = NULL;
    ts_err err = {0};
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    int rc = ts_eigen_solve(lin, &o, &all, &err);
    CHECK(rc == TS_OK, "towed: lapack all (%s)", err.msg);
    for (int pass = 0; pass < 2; pass++) {
        o.count = 8;
        o.target_hz = pass ? 1.3 : 0.0;
        o.method = TS_EIG_ARPACK;
        rc = ts_eigen_solve(lin, &o, &ar, &err);
        CHECK(rc == TS_OK && ar->method == TS_EIG_ARPACK && ar->nmodes == 8,
              "towed: arpack %s shift, %d modes (%s)",
              pass ? "complex" : "real", ar ? ar->nmodes : 0, err.msg);
        o.method = TS_EIG_LAPACK;
        rc = ts_eigen_solve(lin, &o, &lp, &err);
        /* The two methods use two linearizations (LAPACK the dense A of
         * column differences, ARPACK the sparse model of the node
         * residual): each mode agrees within the sum of its two error
         * bounds. */
        double worst = 0, resid = 0;
        for (int m = 0; rc == TS_OK && ar && m < ar->nmodes; m++) {
            const ts_mode *a = &ar->modes[m], *b = &lp->modes[m];
            double diff = hypot(a->re - b->re, a->im - b->im);
            double allow = a->error_bound + b->error_bound;
            worst = fmax(worst, diff / allow);
            worst = fmax(worst, nearest(all, a->re, a->im) *
                                    hypot(a->re, a->im) / allow);
            resid = fmax(resid, a->residual);
            if (m < 3)
                printf("  mode %d: arpack %.12g%+.12gi +- %.2g, lapack "
                       "%.12g%+.12gi +- %.2g\n",
                       m, a->re, a->im, a->error_bound, b->re, b->im,
                       b->error_bound);
        }
        CHECK(rc == TS_OK && worst <= 1.0,
              "towed, %s shift: arpack and lapack agree on the 8 modes "
              "nearest the target within their error bounds (largest "
              "difference %.3g of the allowance)",
              pass ? "complex" : "real", worst);
        CHECK(resid < 1e-6, "towed, %s shift: arpack residuals %.3g < 1e-6 "
              "of |lambda| (rounding relative to ||A||)",
              pass ? "complex" : "real", resid);
        ts_eigen_free(ar);
        ts_eigen_free(lp);
        ar = lp = NULL;
    }
    /* The Ritz value's own error (ritz_error, the pencil's Newton
     * correction with the left null vector, doc/linear.md section 3):
     * runs at a loose tolerance leave errors well above rounding, measured
     * against a run at machine precision on the same sparse model (so the
     * two differ by the Ritz values' errors only). Where an error stands
     * above rounding (1e-12 of |lambda|), the correction is first-order
     * exact: it must equal the error within a factor 2 (seen: 1.00). */
    int seen = 0;
    double lo = INFINITY, hi = 0;
    for (int pass = 0; pass < 4; pass++) {
        ts_eigen *tight = NULL, *loose = NULL;
        o.count = 8;
        o.target_hz = pass % 2 ? 1.3 : 0.0;
        o.method = TS_EIG_ARPACK;
        o.rightmost = 0;
        o.arpack_tol = 0.0;
        rc = ts_eigen_solve(lin, &o, &tight, &err);
        o.arpack_tol = pass < 2 ? 1e-3 : 1e-1;
        if (rc == TS_OK)
            rc = ts_eigen_solve(lin, &o, &loose, &err);
        CHECK(rc == TS_OK, "towed, %s shift: arpack at tolerances 0 and %g "
              "(%s)", pass % 2 ? "complex" : "real", o.arpack_tol, err.msg);
        for (int m = 0; rc == TS_OK && m < loose->nmodes; m++) {
            const ts_mode *a = &loose->modes[m];
            double best = INFINITY;
            for (int k = 0; k < tight->nmodes; k++)
                best = fmin(best, hypot(a->re - tight->modes[k].re,
                                        a->im - tight->modes[k].im));
            if (!(best > 1e-12 * hypot(a->re, a->im)))
                continue;
            seen++;
            lo = fmin(lo, a->ritz_error / best);
            hi = fmax(hi, a->ritz_error / best);
        }
        ts_eigen_free(tight);
        ts_eigen_free(loose);
    }
    CHECK(seen > 0 && lo >= 0.5 && hi <= 2.0,
          "towed: ritz_error equals the error of Ritz values at tolerances "
          "1e-3 and 1e-1 within a factor 2 (%d with errors above rounding, "
          "ratios %.4g to %.4g)", seen, lo, hi);
    ts_eigen_opts_default(&o);
    /* Auto picks arpack only above the size threshold. */
    o.method = TS_EIG_AUTO;
    o.count = 4;
    o.target_hz = 0;
    o.arpack_min_states = lin->nstate;
    rc = ts_eigen_solve(lin, &o, &ar, &err);
    CHECK(rc == TS_OK && ar->method == TS_EIG_ARPACK,
          "auto: arpack at the threshold size");
    ts_eigen_free(ar);
    o.arpack_min_states = lin->nstate + 1;
    rc = ts_eigen_solve(lin, &o, &ar, &err);
    CHECK(rc == TS_OK && ar->method == TS_EIG_LAPACK,
          "auto: lapack below it");
    ts_eigen_free(ar);

    /* 6. Refusals. */
    ts_eigen_opts_default(&o);
    o.count = -1;
    rc = ts_eigen_solve(lin, &o, &ar, &err);
    CHECK(rc == TS_EINVAL && ar == NULL, "count -1 refused: %s", err.msg);
    ts_eigen_opts_default(&o);
    o.target_hz = -0.5;
    rc = ts_eigen_solve(lin, &o, &ar, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "target"),
          "negative target refused: %s", err.msg);
    ts_eigen_opts_default(&o);
    o.method = TS_EIG_ARPACK;
    rc = ts_eigen_solve(lin, &o, &ar, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "count"),
          "arpack without count refused: %s", err.msg);
    o.count = lin->nstate / 2;
    rc = ts_eigen_solve(lin, &o, &ar, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "lapack"),
          "arpack with too many modes refused: %s", err.msg);
    /* The same checks without a linearization, naming the states. */
    int n = lin->nstate, most = (n - 3) / 2;
    o.count = most;
    CHECK(ts_eigen_check(n, &o, &err) == TS_OK,
          "ts_eigen_check: arpack with %d modes of %d states", most, n);
    o.count = most + 1;
    char want[64];
    snprintf(want, sizeof want, "the %d states allow (at most %d modes)", n,
             most);
    CHECK(ts_eigen_check(n, &o, &err) == TS_EINVAL && strstr(err.msg, want),
          "ts_eigen_check: %d modes refused: %s", most + 1, err.msg);
    o.method = TS_EIG_LAPACK;
    o.count = n + 1;
    snprintf(want, sizeof want, "the system has %d states", n);
    CHECK(ts_eigen_check(n, &o, &err) == TS_EINVAL && strstr(err.msg, want),
          "ts_eigen_check: a count above the states refused: %s", err.msg);
    /* arpack_tol: >= 0, or the default TS_ARPACK_TOL_AUTO (the
     * tolerance chosen by the model), nothing else. */
    ts_eigen_opts_default(&o);
    CHECK(o.arpack_tol == TS_ARPACK_TOL_AUTO &&
              ts_eigen_check(n, &o, &err) == TS_OK,
          "ts_eigen_check: the default arpack_tol (automatic) accepted");
    o.arpack_tol = -0.5;
    CHECK(ts_eigen_check(n, &o, &err) == TS_EINVAL &&
              strstr(err.msg, "arpack_tol"),
          "ts_eigen_check: arpack_tol -0.5 refused: %s", err.msg);
    ts_eigen_free(all);
    ts_linear_free(lin);
    ts_scene_free(sc);
}

static void test_examples_stable(void)
{
    glob_t g;
    int found = glob("examples/*.yaml", 0, NULL, &g) == 0 ? (int)g.gl_pathc
                                                          : 0;
    CHECK(found >= 1, "examples found: %d", found);
    for (int i = 0; i < found; i++) {
        ts_err err = {0};
        ts_scene *sc = ts_scene_load(g.gl_pathv[i], units, &err);
        if (!sc) {
            CHECK(0, "%s: %s", g.gl_pathv[i], err.msg);
            continue;
        }
        ts_system *sys = sc->system;
        int has_drag = sys->env.water_density > 0;
        if (!has_drag) {
            ts_scene_free(sc);
            continue;
        }
        sys->tow.turn_rate = 0;
        ts_linear *lin = linearize(sys);
        ts_eigen *e = NULL;
        int rc = lin ? ts_eigen_solve(lin, NULL, &e, &err) : TS_ECONV;
        /* A towing vehicle's neutral modes by symmetry (undamped by
         * nature, doc/linear.md section 3a) apart. */
        double zmin = INFINITY;
        for (int m = 0; rc == TS_OK && m < e->nmodes; m++)
            if (e->modes[m].neutral < 0)
                zmin = fmin(zmin, e->modes[m].damping_ratio);
        if (sys->tow.speed > 0)
            CHECK(rc == TS_OK && e->verdict == TS_STABLE && zmin > 0,
                  "%s, straight tow: %s, max Re %.4g 1/s, smallest damping "
                  "ratio %.4g > 0%s",
                  g.gl_pathv[i], e ? ts_verdict_name(e->verdict) : err.msg,
                  e ? e->max_real : NAN, zmin,
                  e && e->nneutral ? " (the neutral modes by symmetry apart)"
                                   : "");
        else
            /* Hanging without flow (a drop test's rest shape): quadratic
             * drag has no first-order term at zero velocity, so the linear
             * model is undamped and the verdict must be marginal, not a
             * false "stable". */
            CHECK(rc == TS_OK && e->verdict == TS_MARGINAL,
                  "%s, no flow: %s (quadratic drag gives no linear damping), "
                  "max Re %.4g 1/s within its error %.3g",
                  g.gl_pathv[i], e ? ts_verdict_name(e->verdict) : err.msg,
                  e ? e->max_real : NAN, e ? e->max_real_error : NAN);
        ts_eigen_free(e);
        ts_linear_free(lin);
        ts_scene_free(sc);
    }
    globfree(&g);
}

/* ---- 7. the error bound covers rounding ------------------------------- */

/* Linearize sys about its equilibrium with relative step `step` (model
 * `model`); with `tight`, replace A by the Richardson value A(h) - Aerr,
 * fourth order in h (doc/linear.md, section 2). NULL on failure. */
static ts_linear *linearize_at(const ts_system *sys, double step, int tight,
                               ts_lin_model model)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_linear *lin = NULL;
    ts_linearize_opts o;
    ts_linearize_opts_default(&o);
    o.rel_step = step;
    o.model = model;
    if (ts_equilibrium_solve(k, NULL, eq, &err) == TS_OK) {
        lin = ts_linear_alloc(k, &err);
        if (ts_linearize_equilibrium(k, eq, &o, lin, &err) != TS_OK) {
            ts_linear_free(lin);
            lin = NULL;
        }
    }
    if (lin && tight) {
        int n = lin->nstate, nq = lin->nq, nlow = n - nq;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < nlow; i++)
                lin->A[nq + i + (size_t)j * n] -=
                    lin->Aerr[i + (size_t)j * nlow];
    }
    if (!lin)
        printf("linearize %s: %s\n", sys->name, err.msg);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return lin;
}

/* The mode of e nearest to lambda: its distance. */
static double nearest_dist(const ts_eigen *e, double re, double im)
{
    double best = INFINITY;
    for (int j = 0; j < e->nmodes; j++)
        best = fmin(best, hypot(re - e->modes[j].re, im - e->modes[j].im));
    return best;
}

/* Every mode of the linearization at `step` (method m, count) against the
 * nearest of the tight one (sixth order: Richardson of the fourth-order
 * values at steps 5e-4 and 1e-3), whose own uncertainty is its distance
 * to the fourth-order one at 5e-4:
 * |lambda - lambda_tight| <= error_bound + that uncertainty. Counts the
 * modes and those whose error is at least 10 times the reference's
 * uncertainty (the ones the check is about); returns the largest ratio of
 * error to bound + uncertainty. */
static double bound_ratio(const ts_system *sys, double step, ts_eig_method m,
                          ts_lin_model model, int count, int *n, int *clear,
                          double *worst_err, double *worst_bound)
{
    ts_linear *a = linearize_at(sys, step, 0, model);
    ts_linear *b = linearize_at(sys, 5e-4, 1, TS_LIN_DENSE);
    ts_linear *c = linearize_at(sys, 1e-3, 1, TS_LIN_DENSE);
    /* b becomes the sixth-order (16 b - c) / 15; b's fourth-order value,
     * c, is then a bound on its error (15 times b's own, and more). */
    if (b && c) {
        int nn = b->nstate;
        for (size_t i = 0; i < (size_t)nn * nn; i++) {
            double x = b->A[i];
            b->A[i] = (16 * x - c->A[i]) / 15;
            c->A[i] = x;
        }
    }
    ts_eigen *ea = NULL, *eb = NULL, *ec = NULL;
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    o.method = m;
    o.count = count;
    double worst = NAN;
    *n = *clear = 0;
    if (a && b && c && ts_eigen_solve(a, &o, &ea, NULL) == TS_OK &&
        ts_eigen_solve(b, NULL, &eb, NULL) == TS_OK &&
        ts_eigen_solve(c, NULL, &ec, NULL) == TS_OK) {
        worst = 0;
        for (int k = 0; k < ea->nmodes; k++) {
            const ts_mode *md = &ea->modes[k];
            double e = nearest_dist(eb, md->re, md->im);
            int j = 0;
            for (int i = 1; i < eb->nmodes; i++)
                if (hypot(md->re - eb->modes[i].re,
                          md->im - eb->modes[i].im) <
                    hypot(md->re - eb->modes[j].re,
                          md->im - eb->modes[j].im))
                    j = i;
            double u = nearest_dist(ec, eb->modes[j].re, eb->modes[j].im);
            double r = e / (md->error_bound + u);
            *clear += e >= 10 * u;
            if (r > worst) {
                worst = r;
                *worst_err = e;
                *worst_bound = md->error_bound;
            }
            (*n)++;
        }
    }
    ts_eigen_free(ea);
    ts_eigen_free(eb);
    ts_eigen_free(ec);
    ts_linear_free(a);
    ts_linear_free(b);
    ts_linear_free(c);
    return worst;
}

static void test_rounding(void)
{
    static const char *const scenes[3] = {"examples/kamman_ex3_turn.yaml",
                                          "examples/kamman_ex1_above.yaml",
                                          "examples/kamman_ex4.yaml"};
    /* The default step (truncation and rounding about equal), then steps
     * where rounding dominates (eps / h against h^2). */
    static const double steps[3] = {6.055454452393343e-06, 1e-7, 1e-8};
    for (int s = 0; s < 3; s++) {
        ts_err err = {0};
        ts_scene *sc = ts_scene_load(scenes[s], units, &err);
        if (!sc) {
            CHECK(0, "%s: %s", scenes[s], err.msg);
            continue;
        }
        ts_system *sys = ts_system_copy(sc->system, &err);
        ts_system_set_links(sys, 10, &err);
        for (int k = 0; k < 3; k++) {
            int n, clear;
            double e = NAN, bd = NAN;
            double w = bound_ratio(sys, steps[k], TS_EIG_LAPACK,
                                   TS_LIN_AUTO, 0, &n,
                                   &clear, &e, &bd);
            CHECK(w <= 1 && (k < 2 || clear >= n / 3),
                  "%s, 10 links, step %.3g: every eigenvalue (%d; %d with "
                  "errors 10 times the reference's uncertainty) within its "
                  "error bound of the tight one (closest %.2f: error %.3g, "
                  "bound %.3g)", sc->system->name, steps[k], n, clear, w, e,
                  bd);
        }
        /* ARPACK through the sparse model (its entry-wise truncation and
         * rounding with the pencil's left and right vectors) at the three
         * steps; on the dense A alone (the rounding term without left
         * vectors) at 1e-8. */
        for (int k = 0; k < 4; k++) {
            int dense = k == 3, n, clear;
            double step = dense ? 1e-8 : steps[k], e = NAN, bd = NAN;
            if (dense && s != 0)
                continue;
            double w = bound_ratio(sys, step, TS_EIG_ARPACK,
                                   dense ? TS_LIN_DENSE : TS_LIN_AUTO, 8, &n,
                                   &clear, &e, &bd);
            CHECK(w <= 1 && (step > 1e-8 || clear >= 2),
                  "%s, ARPACK (%s model), step %.3g: the 8 modes nearest 0 "
                  "within their error bounds (%d clear; closest %.2f: error "
                  "%.3g, bound %.3g)",
                  sc->system->name, dense ? "dense" : "sparse", step, clear,
                  w, e, bd);
        }
        ts_system_free(sys);
        ts_scene_free(sc);
    }
}

/* ---- 8. entries below their error do not spoil the balancing -------- */

/* The towing vehicle's linear model has entries of 1e-23 and less where
 * central differences round an exact zero (the positions along and
 * across the track move nothing). The eigen analysis zeroes entries below
 * their own error estimate before dgeevx balances: with the cyclic cut
 * switched off (nneutral = 0), which would otherwise hide them, the
 * eigenvectors must still be accurate, ||A v - lambda v|| at rounding
 * level of ||A|| |v| (left in, those entries made the balancing scale by
 * ~1e30 and this residual 7e-9), and the eigenvalues those of the cut
 * model within their error bounds. */
static void test_balancing(void)
{
    ts_err err = {0};
    ts_scene *sc = ts_scene_load("test/scenes/towing_sphere.yaml", units,
                                 &err);
    if (!CHECK(sc != NULL, "towing_sphere: %s", err.msg))
        return;
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_MODES);
    rq.setup.discretisation_error = 0;
    rq.modes.margins = 0;
    ts_result *r = NULL;
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (!CHECK(rc == TS_OK && r && r->lin && r->lin->A && r->lin->Aerr,
               "towing_sphere: modes with the dense A and its error (%s)",
               err.msg)) {
        ts_result_free(r);
        ts_request_clear(&rq);
        ts_scene_free(sc);
        return;
    }
    const ts_linear *lin = r->lin;
    int n = lin->nstate;
    ts_linear raw = *lin;
    raw.nneutral = 0;
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    o.method = TS_EIG_LAPACK;
    ts_eigen *er = NULL, *ec = NULL;
    rc = ts_eigen_solve(&raw, &o, &er, &err);
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, &o, &ec, &err);
    double anorm = 0, tiny = INFINITY;
    for (size_t i = 0; i < (size_t)n * n; i++) {
        anorm += lin->A[i] * lin->A[i];
        if (lin->A[i] != 0)
            tiny = fmin(tiny, fabs(lin->A[i]));
    }
    anorm = sqrt(anorm);
    double worst = 0, off = 0;
    for (int m = 0; rc == TS_OK && m < er->nmodes; m++) {
        const double *vr = er->vec_re + (size_t)n * m;
        const double *vi = er->vec_im + (size_t)n * m;
        double complex lam = er->modes[m].re + I * er->modes[m].im;
        double r2 = 0, v2 = 0;
        for (int i = 0; i < n; i++) {
            double complex av = 0;
            for (int j = 0; j < n; j++)
                av += lin->A[i + (size_t)j * n] * (vr[j] + I * vi[j]);
            double complex v = vr[i] + I * vi[i];
            r2 += pow(cabs(av - lam * v), 2);
            v2 += pow(cabs(v), 2);
        }
        worst = fmax(worst, sqrt(r2 / v2) / anorm);
    }
    for (int m = 0; rc == TS_OK && m < ec->nmodes; m++) {
        double complex lam = ec->modes[m].re + I * ec->modes[m].im;
        double best = INFINITY;
        for (int k = 0; k < er->nmodes; k++)
            best = fmin(best, cabs(er->modes[k].re + I * er->modes[k].im -
                                   lam));
        off = fmax(off, best / ec->modes[m].error_bound);
    }
    /* 1e-13: a hundred times the backward error of a stable QR on
     * ||A||_F (the examples give 1e-15 to 1e-16). */
    CHECK(rc == TS_OK && worst < 1e-13 && off <= 1,
          "towing_sphere without the cyclic cut (smallest entry %.2g of "
          "max %.3g): every eigenvector's residual %.2g of ||A|| |v| "
          "(< 1e-13), every eigenvalue the cut model's within %.2g of its "
          "bound (%s)", tiny, lin->a_scale, worst, off,
          rc == TS_OK ? "ok" : err.msg);
    ts_eigen_free(er);
    ts_eigen_free(ec);
    ts_result_free(r);
    ts_request_clear(&rq);
    ts_scene_free(sc);
}

int main(void)
{
    units = tscene_units();
    if (!units)
        return 1;
    test_chain();
    test_continuum();
    test_arpack_small();
    test_examples_stable();
    test_rounding();
    test_balancing();
    ts_units_free(units);
    return tc_done();
}
