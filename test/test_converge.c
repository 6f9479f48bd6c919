/* test_converge.c: resolution sweeps, error estimates, observed orders and
 * recommendations (towstab/converge.h, report_converge.h).
 *
 *  1. The observed-order formula on sequences f = f* + C h^p with known p
 *     and refinement ratios that are not constant (7, 10, 23, 41 links):
 *     p recovered to 1e-9 (Brent tolerance 1e-13; rounding in the
 *     differences of values ~1 is ~1e-16 relative, amplified by the
 *     ratio of differences ~1e2); refusals (sign change, zero
 *     difference, unordered h).
 *  2. A synthetic study f = 3.25 + 0.7 h^2 exactly: order 2 to 1e-9,
 *     Richardson reference 3.25 to 1e-13 relative, each row's estimated
 *     error 0.7 h^2 to 1e-9 relative; the recommendation is the coarsest
 *     row whose error (and every finer row's) is below the target, and
 *     none with an untrustworthy or failed finer row; the predicted
 *     setting for a target no row meets follows from h (target / e)^(1/p).
 *  3. A sequence with a higher-order term, f* + h^2 + 5 h^3: the estimate
 *     of the finest row's error is at least the true error and at most 3
 *     times it (Richardson removes the h^2 term; what is left is O(h^3)).
 *  4. Noise, divergence and oscillation: values equal within their noise
 *     are "converged"; differences that grow are "diverging" (no
 *     recommendation); alternating shrinking differences are "finest"
 *     with the geometric tail as uncertainty.
 *  5. Two series (a work-precision comparison): the reference comes from
 *     the more accurate series, and the recommendation is the cheaper of
 *     the two series' recommendations.
 *  6. Settings and table refusals (duplicate, non-integer links,
 *     tolerance >= 1, step > 0.1, unknown series, full table).
 *  7. The equilibrium sweep on Kamman ex. 1 (submerged): the observed
 *     order at the finest triple of 40, 80, 160, 320 links is 2 within
 *     0.03 for the sphere's x, z and the top tension (measured 1.984,
 *     1.997, 1.998). Why 2: the lumped model puts half of each link's
 *     weight and drag at its ends and evaluates the drag at the link
 *     midpoint, a midpoint/trapezoid quadrature of the continuous cable's
 *     loads, whose error is O(l^2) = O(1/N^2). The orders are lower on
 *     coarse grids (sphere.x: 0.77 at 5-10-20 links, 1.38, 1.78, 1.94 at
 *     40-80-160: pre-asymptotic; the drag on the steep upper links
 *     changes most). Against an independent 2560-link solution (whose own
 *     error is 1/64 of the 320-link one): the Richardson reference is at
 *     least 20 times closer than the 320-link value, and the 320-link
 *     error estimate is within a factor 2 of the truth. For a target no
 *     run meets (2e-6), the predicted link count, solved, meets it.
 *  8. The modes sweep on Kamman ex. 4 (10, 20, 40, 80 links): the two
 *     lowest oscillatory modes converge at order 2 (within 0.1) in
 *     frequency and damping ratio; the third mode's orders (0.93 at
 *     10-20-40, 2.0 at 20-40-80) disagree, so its reference is the finest
 *     run and no link count is predicted: 10 links is not yet
 *     asymptotic for it.
 *  9. JSON and CSV of a study: the required keys, one CSV line per run.
 * 11. A sweep stopped by its progress callback before the third run keeps
 *     the two rows so far (TS_ECANCEL), which still estimate.
 * 10. The simulate analysis on Kamman ex. 4 (tow point heaved 0.1 ft at
 *     1 Hz, 8 s, fitted over 4..8 s), rk8pd at tolerances 1e-3 .. 1e-6:
 *     the true error of the amplitude ratio and of the phase (against an
 *     independent run: rkf45 at rtol 1e-11, fitted here) shrinks with
 *     the tolerance at every step, and the finest run agrees with the
 *     independent one within 1e-6 relative (its tolerance is 1e-6, and
 *     the integrator's global error for this damped system stays at the
 *     level of the local tolerance; measured 1.9e-10 and 3.4e-10); the
 *     finest estimated error is at least the true error less 1e-9
 *     relative (measured: the ratio's estimate 3.1e-11 covers its true
 *     2.6e-11; the phase's 5.8e-10 deg is below its true 5.1e-9 deg, a
 *     3e-10 relative miss that the allowance admits: near rounding the
 *     estimate is optimistic) and the estimates shrink with the
 *     tolerance; a links sweep re-resolves sphere.z at every link count; refusals (no periodic excitation, a
 *     tension output, a window shorter than a period).
 */
#include "towstab/converge.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcheck.h"
#include "towstab/analysis.h"
#include "towstab/compare.h"
#include "towstab/report_converge.h"
#include "towstab/scene.h"

/* ---- helpers ------------------------------------------------------------ */

/* A study of one value "f" (scale 0: relative to the reference) over the
 * given settings, f from fn(h). */
static ts_convergence *synthetic(ts_conv_param p, const double *settings,
                                 int n, double (*fn)(double h), double noise,
                                 double scale)
{
    ts_conv_value v = {0};
    snprintf(v.name, sizeof v.name, "f");
    snprintf(v.unit, sizeof v.unit, "1");
    v.scale = scale;
    ts_err err = {0};
    ts_convergence *c = ts_convergence_alloc("synthetic", p, 1, &v, 16, &err);
    if (!c || ts_convergence_add_series(c, "", &err) != 0) {
        printf("     alloc: %s\n", err.msg);
        ts_convergence_free(c);
        return NULL;
    }
    for (int i = 0; i < n; i++) {
        double h = ts_conv_resolution(p, settings[i]);
        double f = fn(h);
        ts_convergence_add_row(c, 0, settings[i], TS_OK, NULL,
                               1e-3 * (i + 1), 10 * (i + 1), NULL, &f,
                               &noise, &err);
    }
    return c;
}

static double f_quadratic(double h) { return 3.25 + 0.7 * h * h; }
static double f_cubic(double h) { return 1.0 + h * h + 5 * h * h * h; }
static double f_growing(double h) { return 1.0 / h; }
static double f_alternating(double h)
{
    /* 1 + (-1)^k 2^-k for h = 2^-k: differences alternate and halve. */
    double k = -log2(h);
    return 1.0 + (fmod(k, 2.0) == 0 ? 1 : -1) * h;
}
static double f_flat(double h) { return 2.0 + 1e-14 * h; }

/* Row of setting s in series 0. */
static const ts_conv_row *row_at(const ts_convergence *c, double s)
{
    for (int i = 0; i < c->nrows; i++)
        if (c->rows[i].setting == s)
            return &c->rows[i];
    return NULL;
}

/* ---- 1. observed order ---------------------------------------------------- */

static void test_order(void)
{
    static const double N[4] = {7, 10, 23, 41};
    static const double P[3] = {1.0, 1.5, 2.0};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i + 2 < 4; i++) {
            double h[3], f[3], p;
            for (int j = 0; j < 3; j++) {
                h[j] = 1.0 / N[i + j];
                f[j] = 1.5 - 2.2 * pow(h[j], P[k]);
            }
            int rc = ts_conv_observed_order(h, f, &p);
            CHECK(rc == TS_OK && fabs(p - P[k]) <= 1e-9,
                  "order %.1f from links %g, %g, %g: got %.12g", P[k],
                  N[i], N[i + 1], N[i + 2], p);
        }
    }
    double h[3] = {0.1, 0.05, 0.025}, p;
    double fs[3] = {1.0, 1.1, 1.05};
    CHECK(ts_conv_observed_order(h, fs, &p) == TS_EDOMAIN && isnan(p),
          "order: differences of opposite sign are refused (EDOMAIN, NaN)");
    double fz[3] = {1.0, 1.0, 1.0};
    CHECK(ts_conv_observed_order(h, fz, &p) == TS_EDOMAIN,
          "order: zero differences are refused");
    double fg[3] = {1.0, 1.1, 1.3};
    CHECK(ts_conv_observed_order(h, fg, &p) == TS_EDOMAIN,
          "order: growing differences are refused");
    double hu[3] = {0.05, 0.1, 0.025};
    double fq[3] = {1.0, 1.1, 1.15};
    CHECK(ts_conv_observed_order(hu, fq, &p) == TS_EINVAL,
          "order: unordered resolutions are refused");
    CHECK_NEAR(ts_conv_extrapolate(0.2, 1.04, 0.1, 1.01, 2.0), 1.0, 1e-15,
               "extrapolate 1 + h^2 from h = 0.2, 0.1 at order 2");
}

/* ---- 2. a synthetic study -------------------------------------------- */

static void test_synthetic(void)
{
    static const double N[5] = {5, 10, 20, 40, 80};
    ts_convergence *c =
        synthetic(TS_CONV_LINKS, N, 5, f_quadratic, 0.0, 0.0);
    ts_err err = {0};
    if (!CHECK(c && ts_convergence_estimate(c, 1e-3, &err) == TS_OK,
               "synthetic study estimates (%s)", err.msg)) {
        ts_convergence_free(c);
        return;
    }
    const ts_conv_value *V = &c->values[0];
    CHECK(V->ref_kind == TS_CONV_REF_RICHARDSON, "reference is Richardson");
    CHECK_NEAR(V->order, 2.0, 1e-9, "observed order of 3.25 + 0.7 h^2");
    CHECK_REL(V->reference, 3.25, 1e-13, "Richardson reference");
    double worst = 0;
    for (int i = 0; i < 5; i++) {
        const ts_conv_row *r = row_at(c, N[i]);
        double want = 0.7 / (N[i] * N[i]);
        worst = fmax(worst, fabs(r->errors[0] - want) / want);
    }
    CHECK(worst <= 1e-9, "every row's estimated error is 0.7 h^2 (worst "
                         "relative deviation %.3g <= 1e-9)",
          worst);
    /* Relative to 3.25: errors 8.6e-3, 2.2e-3, 5.4e-4, ... */
    CHECK(c->recommended >= 0 && c->rows[c->recommended].setting == 20,
          "target 1e-3: recommended 20 links (error 5.4e-4), got %g",
          c->recommended >= 0 ? c->rows[c->recommended].setting : -1.0);
    CHECK(isnan(c->predicted_setting), "no prediction when a row qualifies");

    /* A target no row meets: e(h) = 0.7 h^2 / 3.25 = 1e-7 at
     * N = sqrt(0.7 / 3.25e-7) = 1467.6 -> 1468. */
    ts_convergence_estimate(c, 1e-7, &err);
    CHECK(c->recommended < 0 && c->predicted_setting == 1468,
          "target 1e-7: none qualifies, 1468 links predicted (got %g)",
          c->predicted_setting);
    CHECK(isfinite(c->predicted_wall_s) && c->predicted_wall_s > 5e-3,
          "the predicted run time is extrapolated beyond the finest run's "
          "(%.3g s)",
          c->predicted_wall_s);
    ts_convergence_free(c);

    /* An untrustworthy finest row: nothing coarser may be recommended. */
    c = synthetic(TS_CONV_LINKS, N, 4, f_quadratic, 0.0, 0.0);
    ts_trust bad;
    ts_trust_init(&bad);
    ts_trust_fail(&bad, "test: a link in compression");
    double f80 = f_quadratic(1.0 / 80);
    ts_convergence_add_row(c, 0, 80, TS_OK, NULL, 0.01, 50, &bad, &f80, NULL,
                           &err);
    ts_convergence_estimate(c, 1e-3, &err);
    CHECK(c->recommended < 0 && !row_at(c, 80)->meets_target,
          "an untrustworthy finer row blocks the recommendation");
    ts_convergence_free(c);

    /* A failed coarse row does not matter; a failed finer row does. */
    c = synthetic(TS_CONV_LINKS, N + 1, 4, f_quadratic, 0.0, 0.0);
    ts_convergence_add_row(c, 0, 5, TS_ECONV, "did not converge", 0.001, 9,
                           NULL, NULL, NULL, &err);
    ts_convergence_estimate(c, 1e-3, &err);
    CHECK(c->recommended >= 0 && c->rows[c->recommended].setting == 20 &&
              row_at(c, 5)->status == TS_ECONV &&
              isnan(row_at(c, 5)->errors[0]),
          "a failed coarse row keeps its status and has no error; 20 links "
          "still recommended");
    ts_convergence_free(c);
}

/* ---- 3. higher-order terms ------------------------------------------ */

static void test_cubic(void)
{
    static const double N[5] = {4, 8, 16, 32, 64};
    ts_convergence *c = synthetic(TS_CONV_LINKS, N, 5, f_cubic, 0.0, 1.0);
    ts_err err = {0};
    ts_convergence_estimate(c, 1e-3, &err);
    const ts_conv_row *fin = row_at(c, 64);
    double truth = f_cubic(1.0 / 64) - 1.0;
    CHECK(fin->errors[0] >= truth && fin->errors[0] <= 3 * truth,
          "f* + h^2 + 5 h^3: finest error estimate %.4g within [1, 3] x the "
          "true error %.4g",
          fin->errors[0], truth);
    CHECK(fabs(c->values[0].order - 2.0) < 0.3,
          "f* + h^2 + 5 h^3: order near 2 at 16, 32, 64 links (%.4f)",
          c->values[0].order);
    ts_convergence_free(c);
}

/* ---- 4. noise, divergence, oscillation -------------------------------- */

static void test_kinds(void)
{
    static const double N[4] = {10, 20, 40, 80};
    ts_err err = {0};
    ts_convergence *c = synthetic(TS_CONV_LINKS, N, 4, f_flat, 1e-12, 0.0);
    ts_convergence_estimate(c, 1e-6, &err);
    CHECK(c->values[0].ref_kind == TS_CONV_REF_CONVERGED &&
              c->recommended >= 0 && c->rows[c->recommended].setting == 10,
          "values equal within their noise: converged, the coarsest is "
          "recommended");
    ts_convergence_free(c);

    c = synthetic(TS_CONV_LINKS, N, 4, f_growing, 0.0, 0.0);
    ts_convergence_estimate(c, 0.5, &err);
    CHECK(c->values[0].ref_kind == TS_CONV_REF_DIVERGING &&
              c->recommended < 0,
          "growing differences: diverging, nothing recommended (kind %s)",
          ts_conv_ref_name(c->values[0].ref_kind));
    ts_convergence_free(c);

    static const double T[4] = {0.25, 0.125, 0.0625, 0.03125};
    c = synthetic(TS_CONV_TOLERANCE, T, 4, f_alternating, 0.0, 1.0);
    ts_convergence_estimate(c, 1e-3, &err);
    /* Differences -0.375, 0.1875, -0.09375: rho = 1/2, tail = |d|. */
    CHECK(c->values[0].ref_kind == TS_CONV_REF_FINEST &&
              fabs(c->values[0].reference_error - 0.09375) < 1e-15,
          "alternating differences: finest reference with the geometric "
          "tail |d| rho / (1 - rho) = 0.09375 (got %s, %.6g)",
          ts_conv_ref_name(c->values[0].ref_kind),
          c->values[0].reference_error);
    ts_convergence_free(c);
}

/* ---- 5. two series ---------------------------------------------------- */

static void test_series(void)
{
    ts_conv_value v = {0};
    snprintf(v.name, sizeof v.name, "amplitude_ratio");
    v.scale = 0.0;
    ts_err err = {0};
    ts_convergence *c =
        ts_convergence_alloc("synthetic", TS_CONV_TOLERANCE, 1, &v, 16, &err);
    int a = ts_convergence_add_series(c, "slow", &err);
    int b = ts_convergence_add_series(c, "fast", &err);
    static const double T[4] = {1e-3, 1e-5, 1e-7, 1e-9};
    for (int i = 0; i < 4; i++) {
        /* "slow": error 10 tol, run time 1 ms / tol^0.2;
         * "fast": error 0.1 tol^0.5, cheaper. */
        double fa = 0.2 + 10 * T[i], fb = 0.2 + 0.1 * sqrt(T[i]);
        ts_convergence_add_row(c, a, T[i], TS_OK, NULL,
                               1e-3 * pow(T[i], -0.2), 100, NULL, &fa, NULL,
                               &err);
        ts_convergence_add_row(c, b, T[i], TS_OK, NULL,
                               1e-4 * pow(T[i], -0.2), 10, NULL, &fb, NULL,
                               &err);
    }
    ts_convergence_estimate(c, 1e-3, &err);
    CHECK(c->reference_series == a, "the reference comes from the series "
                                    "whose reference is most accurate "
                                    "(slow: %d, fast: %d, got %d)",
          a, b, c->reference_series);
    CHECK(fabs(c->values[0].reference - 0.2) <= 1e-9,
          "common reference 0.2 (got %.12g)", c->values[0].reference);
    /* slow meets 1e-3 (relative to 0.2: 2e-4) from tol 1e-5 on; fast
     * (0.1 sqrt(tol) / 0.2) from 1e-7 on; fast is ten times cheaper. */
    const ts_conv_row *rec =
        c->recommended >= 0 ? &c->rows[c->recommended] : NULL;
    CHECK(rec && rec->series == b && rec->setting == 1e-7,
          "work-precision: the cheapest qualifying run is fast at 1e-7 "
          "(got %s %g)",
          rec ? c->series[rec->series].name : "none",
          rec ? rec->setting : 0.0);
    CHECK(c->series[a].recommended >= 0 &&
              c->rows[c->series[a].recommended].setting == 1e-5,
          "each series keeps its own recommendation (slow: 1e-5)");
    ts_convergence_free(c);
}

/* ---- 6. refusals ------------------------------------------------------- */

static void test_refusals(void)
{
    ts_err err = {0};
    double dup[3] = {5, 10, 5}, frac[2] = {5, 7.5}, tol[2] = {1e-3, 1.0};
    double step[1] = {0.2}, many[65];
    for (int i = 0; i < 65; i++)
        many[i] = i + 1;
    CHECK(ts_conv_check_settings(TS_CONV_LINKS, dup, 3, "--links", &err) ==
                  TS_EINVAL &&
              strstr(err.msg, "--links") && strstr(err.msg, "twice"),
          "duplicate setting refused: %s", err.msg);
    CHECK(ts_conv_check_settings(TS_CONV_LINKS, frac, 2, "--links", &err) ==
              TS_EINVAL,
          "non-integer links refused: %s", err.msg);
    CHECK(ts_conv_check_settings(TS_CONV_TOLERANCE, tol, 2, "--tolerances",
                                 &err) == TS_EINVAL,
          "tolerance 1 refused: %s", err.msg);
    CHECK(ts_conv_check_settings(TS_CONV_STEP, step, 1, "--steps", &err) ==
              TS_EINVAL,
          "step 0.2 refused: %s", err.msg);
    CHECK(ts_conv_check_settings(TS_CONV_LINKS, many, 65, "--links", &err) ==
              TS_EINVAL,
          "65 settings refused: %s", err.msg);
    ts_conv_value v[2];
    memset(v, 0, sizeof v);
    snprintf(v[0].name, sizeof v[0].name, "a");
    snprintf(v[1].name, sizeof v[1].name, "a");
    CHECK(!ts_convergence_alloc("x", TS_CONV_LINKS, 2, v, 4, &err) &&
              err.code == TS_EINVAL,
          "duplicate value names refused: %s", err.msg);
    ts_convergence *c = ts_convergence_alloc("x", TS_CONV_LINKS, 1, v, 1,
                                             &err);
    double f = 1;
    CHECK(ts_convergence_add_row(c, 0, 5, TS_OK, NULL, 0, 0, NULL, &f, NULL,
                                 &err) == TS_EINVAL,
          "a row in a series that does not exist is refused");
    ts_convergence_add_series(c, "", &err);
    ts_convergence_add_row(c, 0, 5, TS_OK, NULL, 0, 0, NULL, &f, NULL, &err);
    CHECK(ts_convergence_add_row(c, 0, 10, TS_OK, NULL, 0, 0, NULL, &f, NULL,
                                 &err) == TS_ENOMEM,
          "a full table is refused: %s", err.msg);
    CHECK(ts_convergence_estimate(c, 0.0, &err) == TS_EINVAL,
          "target 0 refused");
    ts_convergence_free(c);
}

/* ---- 7. equilibrium sweep on Kamman ex. 1 ---------------------------- */

static ts_scene *load(const char *path, ts_units **u)
{
    ts_err err = {0};
    *u = ts_units_alloc(&err);
    ts_scene *s = *u ? ts_scene_load(path, *u, &err) : NULL;
    if (!s)
        printf("     %s: %s\n", path, err.msg);
    return s;
}

/* A sweep of the pipeline of `analysis` (towstab/analysis.h) with the
 * request's defaults; extra settings from *rq when given. */
static int pipeline_sweep(const ts_system *sys, ts_analysis_kind analysis,
                          ts_request *rq, ts_conv_analysis *an, ts_err *err)
{
    ts_request own;
    if (!rq) {
        ts_request_init(&own, TS_ANALYSIS_CONVERGE);
        rq = &own;
    }
    rq->converge.analysis = analysis;
    return ts_analysis_sweep(sys, rq, 0, an, err);
}

/* The equilibrium analysis of sys (into *an) and a links table of 8 rows
 * for it; NULL on failure (an is then safe to free). */
static ts_convergence *equilibrium_links_table(const ts_system *sys,
                                               ts_conv_analysis *an,
                                               ts_err *err)
{
    memset(an, 0, sizeof *an);
    if (pipeline_sweep(sys, TS_ANALYSIS_EQUILIBRIUM, NULL, an, err) != TS_OK)
        return NULL;
    return ts_convergence_alloc(an->name, TS_CONV_LINKS, an->nvalues,
                                an->values, 8, err);
}

/* Sphere x, z and top tension of a system with N links per cable. */
static int solve_ex(const ts_system *base, int links, double out[3])
{
    ts_err err = {0};
    ts_system *s = ts_conv_system_with_links(base, links, &err);
    ts_kernel *k = s ? ts_kernel_alloc(s, &err) : NULL;
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(s, &err) : NULL;
    int rc = eq ? ts_equilibrium_solve(k, NULL, eq, &err) : TS_ENOMEM;
    if (rc == TS_OK) {
        int node = ts_system_body_node(s, 0);
        out[0] = eq->positions[3 * node];
        out[1] = eq->positions[3 * node + 2];
        out[2] = eq->top_tension;
    } else {
        printf("     %d links: %s\n", links, err.msg);
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
    return rc;
}

static int value_index(const ts_convergence *c, const char *name)
{
    for (int v = 0; v < c->nvalues; v++)
        if (strcmp(c->values[v].name, name) == 0)
            return v;
    return -1;
}


static void test_equilibrium_sweep(void)
{
    ts_units *u;
    ts_scene *sc = load("examples/kamman_ex1_submerged.yaml", &u);
    if (!CHECK(sc, "load Kamman ex. 1")) {
        ts_units_free(u);
        return;
    }
    ts_err err = {0};
    ts_conv_analysis an;
    ts_convergence *c = equilibrium_links_table(sc->system, &an, &err);
    static const double N[4] = {40, 80, 160, 320};
    int rc = c ? ts_convergence_add_series(c, "", &err) : TS_ENOMEM;
    if (rc == 0)
        rc = ts_convergence_sweep(c, 0, &an, N, 4, &err);
    if (rc == TS_OK)
        rc = ts_convergence_estimate(c, 1e-3, &err);
    if (!CHECK(rc == TS_OK, "ex. 1 sweep over 40..320 links (%s)", err.msg)) {
        ts_conv_analysis_free(&an);
        ts_convergence_free(c);
        ts_scene_free(sc);
        ts_units_free(u);
        return;
    }
    static const char *const names[3] = {"sphere.x", "sphere.z",
                                         "top_tension"};
    for (int i = 0; i < 3; i++) {
        int v = value_index(c, names[i]);
        CHECK(v >= 0 && fabs(c->values[v].order - 2.0) <= 0.03 &&
                  c->values[v].ref_kind == TS_CONV_REF_RICHARDSON,
              "ex. 1 %s: observed order %.4f = 2 +- 0.03 (lumped loads: a "
              "midpoint quadrature), Richardson reference",
              names[i], v >= 0 ? c->values[v].order : NAN);
    }
    int vy = value_index(c, "sphere.y");
    CHECK(vy >= 0 && c->values[vy].ref_kind == TS_CONV_REF_CONVERGED &&
              c->values[vy].reference == 0.0,
          "ex. 1 sphere.y is 0 at every resolution (straight tow): "
          "converged");
    CHECK(c->recommended >= 0 && c->rows[c->recommended].setting == 40,
          "ex. 1 target 1e-3: 40 links recommended (top tension error "
          "3.3e-4 at 40), got %g",
          c->recommended >= 0 ? c->rows[c->recommended].setting : -1.0);
    /* Timing: a run timed once took at least TS_CONV_TIMING_MIN; a
     * shorter one was repeated, at most TS_CONV_TIMING_REPEATS times. */
    int timing_ok = 1, repeated = 0;
    for (int i = 0; i < c->nrows; i++) {
        const ts_conv_row *r = &c->rows[i];
        if (r->timed_runs < 1 || r->timed_runs > TS_CONV_TIMING_REPEATS ||
            !(r->wall_s > 0) ||
            (r->timed_runs == 1 && r->wall_s < TS_CONV_TIMING_MIN))
            timing_ok = 0;
        repeated += r->timed_runs > 1;
    }
    CHECK(timing_ok, "every run's time is one run of at least %g s or the "
          "median of repeats (%d rows repeated)", TS_CONV_TIMING_MIN,
          repeated);
    /* Independent: the 2560-link solution. */
    double fine[3];
    if (CHECK(solve_ex(sc->system, 2560, fine) == TS_OK,
              "ex. 1 at 2560 links")) {
        const ts_conv_row *r320 = row_at(c, 320);
        for (int i = 0; i < 3; i++) {
            int v = value_index(c, names[i]);
            double eref = fabs(c->values[v].reference - fine[i]);
            double e320 = fabs(r320->values[v] - fine[i]);
            CHECK(eref * 20 <= e320,
                  "ex. 1 %s: the Richardson reference is within %.3g of "
                  "the 2560-link value, the 320-link value within %.3g "
                  "(>= 20 times closer)",
                  names[i], eref, e320);
            CHECK(r320->errors[v] >= 0.5 * e320 &&
                      r320->errors[v] <= 2 * e320,
                  "ex. 1 %s: the 320-link error estimate %.3g is within a "
                  "factor 2 of its distance %.3g from the 2560-link value",
                  names[i], r320->errors[v], e320);
        }
        /* A target no run meets: the predicted link count meets it. */
        ts_convergence_estimate(c, 2e-6, &err);
        double np = c->predicted_setting, at[3];
        int lv = c->limiting_value;
        if (CHECK(c->recommended < 0 && np > 320 && np < 2560 && lv >= 0,
                  "ex. 1 target 2e-6: none of 40..320 meets it, %g links "
                  "predicted (limited by %s)",
                  np, lv >= 0 ? c->values[lv].name : "?") &&
            solve_ex(sc->system, (int)np, at) == TS_OK) {
            double worst = 0;
            for (int i = 0; i < 3; i++) {
                int v = value_index(c, names[i]);
                worst = fmax(worst,
                             fabs(at[i] - fine[i]) / c->values[v].rel_scale);
            }
            CHECK(worst <= 2e-6,
                  "ex. 1: solved at the predicted %g links, the largest "
                  "relative error against 2560 links is %.3g <= 2e-6",
                  np, worst);
        }
    }

    /* JSON and CSV (at the 1e-3 target, which 40 links meets). */
    ts_convergence_estimate(c, 1e-3, &err);
    json_t *j = ts_report_convergence_json(c);
    json_t *rows = j ? json_object_get(j, "rows") : NULL;
    json_t *r0 = rows ? json_array_get(rows, 0) : NULL;
    CHECK(j && json_is_string(json_object_get(j, "analysis")) &&
              json_is_object(json_object_get(j, "order")) &&
              json_array_size(rows) == 4 && r0 &&
              json_is_integer(json_object_get(r0, "setting")) &&
              json_is_object(json_object_get(r0, "values")) &&
              json_is_object(json_object_get(r0, "errors")) &&
              json_is_real(json_object_get(r0, "wall_s")) &&
              json_is_integer(json_object_get(r0, "evaluations")) &&
              json_is_integer(json_object_get(j, "recommended")) &&
              json_is_array(json_object_get(j, "work_precision")),
          "JSON: analysis, order, 4 rows with setting, values, errors, "
          "wall_s, evaluations; recommended; work_precision");
    json_decref(j);
    char path[64];
    snprintf(path, sizeof path, "/tmp/test_converge_%ld.csv", (long)getpid());
    int lines = 0;
    if (ts_report_convergence_csv(c, path, &err) == TS_OK) {
        FILE *f = fopen(path, "r");
        for (int ch; f && (ch = fgetc(f)) != EOF;)
            lines += ch == '\n';
        if (f)
            fclose(f);
        remove(path);
    }
    CHECK(lines == 5, "CSV: a header and one line per run (%d lines)", lines);
    ts_conv_analysis_free(&an);
    ts_convergence_free(c);

    /* A tolerance sweep: positions stop changing once the residual is
     * below what moves them. */
    rc = pipeline_sweep(sc->system, TS_ANALYSIS_EQUILIBRIUM, NULL, &an, &err);
    c = ts_convergence_alloc(an.name, TS_CONV_TOLERANCE, an.nvalues,
                             an.values, 4, &err);
    static const double T[3] = {1e-6, 1e-9, 1e-12};
    ts_convergence_add_series(c, "", &err);
    rc = ts_convergence_sweep(c, 0, &an, T, 3, &err);
    ts_convergence_estimate(c, 1e-9, &err);
    int ok = rc == TS_OK;
    for (int i = 0; i < c->nrows; i++)
        ok &= c->rows[i].status == TS_OK && c->rows[i].trust.trustworthy;
    CHECK(ok && c->recommended >= 0,
          "ex. 1 tolerance sweep 1e-6..1e-12: every run converges and one "
          "meets 1e-9 (shooting closes a straight tow exactly)");
    ts_conv_analysis_free(&an);
    ts_convergence_free(c);
    ts_scene_free(sc);
    ts_units_free(u);
}

/* ---- 8. modes sweep on Kamman ex. 4 ---------------------------------- */

static void test_modes_sweep(void)
{
    ts_units *u;
    ts_scene *sc = load("examples/kamman_ex4.yaml", &u);
    if (!CHECK(sc, "load Kamman ex. 4")) {
        ts_units_free(u);
        return;
    }
    ts_err err = {0};
    ts_conv_analysis an;
    int rc = pipeline_sweep(sc->system, TS_ANALYSIS_MODES, NULL, &an, &err);
    ts_convergence *c =
        rc ? NULL
           : ts_convergence_alloc(an.name, TS_CONV_LINKS, an.nvalues,
                                  an.values, 8, &err);
    static const double N[4] = {10, 20, 40, 80};
    rc = c ? ts_convergence_add_series(c, "", &err) : TS_ENOMEM;
    if (rc == 0)
        rc = ts_convergence_sweep(c, 0, &an, N, 4, &err);
    if (rc == TS_OK)
        rc = ts_convergence_estimate(c, 1e-3, &err);
    if (CHECK(rc == TS_OK && c->nvalues == 6, "ex. 4 modes sweep (%s)",
              err.msg)) {
        for (int v = 0; v < 4; v++)
            CHECK(fabs(c->values[v].order - 2.0) <= 0.1 &&
                      c->values[v].ref_kind == TS_CONV_REF_RICHARDSON,
                  "ex. 4 %s: order %.4f = 2 +- 0.1 at 20, 40, 80 links, "
                  "Richardson reference",
                  c->values[v].name, c->values[v].order);
        int ok = 1;
        for (int i = 0; i < c->nrows; i++)
            ok &= c->rows[i].status == TS_OK &&
                  c->rows[i].evaluations > 0;
        CHECK(ok, "ex. 4: every run succeeded and counted its evaluations");
        int lv = c->limiting_value;
        CHECK(c->recommended < 0 && lv == 4 &&
                  c->values[4].ref_kind == TS_CONV_REF_FINEST &&
                  isnan(c->predicted_setting),
              "ex. 4 target 1e-3: no run meets it, limited by mode3.freq_hz "
              "(got %s) whose reference is the finest run (orders %.3g and "
              "%.3g disagree): no prediction",
              lv >= 0 ? c->values[lv].name : "none",
              row_at(c, 40)->order[4], row_at(c, 80)->order[4]);
    }
    ts_conv_analysis_free(&an);
    ts_convergence_free(c);
    ts_scene_free(sc);
    ts_units_free(u);
}

/* Amplitude ratio and phase (deg) of sphere.z over t >= t0, by a run
 * made here: rkf45 (another method than the sweep's) at a tight
 * tolerance, fitted directly. */
static int sim_reference(const ts_system *sys, const ts_excitation *ex,
                         const ts_sim_opts *o, double t0, double out[2])
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, &err) : NULL;
    ts_history *h = eq ? ts_history_alloc(sys, ts_sim_nsamples(o), &err)
                       : NULL;
    ts_sim_stats st;
    int rc = h ? ts_equilibrium_solve(k, NULL, eq, &err) : TS_ENOMEM;
    if (rc == TS_OK)
        rc = ts_simulate(k, ex, eq->y, o, h, &st, NULL, &err);
    int node = ts_system_body_node(sys, 0), n = 0;
    double t[400], x[400], u[400];
    for (int i = 0; rc == TS_OK && i < h->nsamples && n < 400; i++)
        if (h->t[i] >= t0 - 1e-12) {
            t[n] = h->t[i];
            x[n] = h->positions[3 * (size_t)h->nnodes * i + 3 * node + 2];
            u[n++] = h->input[TS_NINPUT * (size_t)i + 2];
        }
    double c, a, ph, ce, ae, phe;
    if (rc == TS_OK)
        rc = ts_compare_fit_sinusoid(t, x, n, 1.0, &c, &a, &ph, &err);
    if (rc == TS_OK)
        rc = ts_compare_fit_sinusoid(t, u, n, 1.0, &ce, &ae, &phe, &err);
    if (rc == TS_OK) {
        out[0] = a / ae;
        out[1] = (ph - phe) * 180.0 / M_PI;
        out[1] -= 360.0 * round(out[1] / 360.0);
    } else {
        printf("     reference run: %s\n", err.msg);
    }
    ts_history_free(h);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return rc;
}

static void test_simulate_sweep(void)
{
    ts_units *u;
    ts_scene *sc = load("examples/kamman_ex4.yaml", &u);
    if (!CHECK(sc, "load Kamman ex. 4")) {
        ts_units_free(u);
        return;
    }
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    /* An impulsive start (ramp=0): its transient keeps each tolerance's
     * error above the reference's floor (~2e-8 deg of phase) down to rtol
     * 1e-6; started smoothly, the two finest runs both reach that floor. */
    int rc = ex ? ts_excitation_parse(ex, "tow.heave:amplitude=0.1ft,"
                                          "frequency=1Hz,ramp=0",
                                      u, "test", &err)
                : TS_ENOMEM;
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 8.0;
    o.dt_sample = 0.05;
    ts_conv_analysis an;
    memset(&an, 0, sizeof an);
    /* The request borrows ex: it is not cleared. */
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_CONVERGE);
    rq.simulate.sim = o;
    rq.simulate.excitation = ex;
    rq.simulate.transient = 4.0;
    snprintf(rq.simulate.output, sizeof rq.simulate.output, "sphere.z");
    if (rc == TS_OK)
        rc = pipeline_sweep(sc->system, TS_ANALYSIS_SIMULATE, &rq, &an, &err);
    static const double tol[4] = {1e-3, 1e-4, 1e-5, 1e-6};
    ts_convergence *c =
        rc ? NULL
           : ts_convergence_alloc(an.name, TS_CONV_TOLERANCE, an.nvalues,
                                  an.values, 8, &err);
    rc = c ? ts_convergence_add_series(c, "rk8pd", &err) : TS_ENOMEM;
    if (rc == 0)
        rc = ts_convergence_sweep(c, 0, &an, tol, 4, &err);
    if (rc == TS_OK)
        rc = ts_convergence_estimate(c, 1e-3, &err);
    ts_sim_opts ro = o;
    ro.integrator = TS_INT_RKF45;
    ro.rel_tol = 1e-11;
    ro.abs_tol = 1e-14;
    double ref[2] = {NAN, NAN};
    if (CHECK(rc == TS_OK && c->nvalues == 9 &&
                  strcmp(c->values[0].name,
                         "sphere.z.amplitude_ratio") == 0 &&
                  strcmp(c->values[2].name, "sphere.z.phase_deg") == 0 &&
                  strcmp(c->values[3].name, "tension.max") == 0 &&
                  strcmp(c->values[5].name, "tow.force.max") == 0 &&
                  strcmp(c->values[8].name,
                         "tow.force.amplification") == 0,
              "ex. 4 simulate tolerance sweep: the fitted values and the "
              "tow force's extremes (%s)", err.msg) &&
        CHECK(sim_reference(sc->system, ex, &ro, 4.0, ref) == TS_OK,
              "independent rkf45 run at rtol 1e-11")) {
        int vi[2] = {0, 2};
        for (int j = 0; j < 2; j++) {
            int v = vi[j];
            double e[4], est[4];
            int shrink = 1, est_ok = 1;
            for (int i = 0; i < 4; i++) {
                const ts_conv_row *r = row_at(c, tol[i]);
                e[i] = fabs(r->values[v] - ref[j]);
                est[i] = r->errors[v];
                if (i > 0 && !(e[i] < e[i - 1]))
                    shrink = 0;
                if (i > 0 && !(est[i] < est[i - 1]))
                    est_ok = 0;
            }
            CHECK(shrink, "%s: true error shrinks with the tolerance: "
                          "%.2e %.2e %.2e %.2e",
                  c->values[v].name, e[0], e[1], e[2], e[3]);
            CHECK(est_ok, "%s: estimated error shrinks with the "
                          "tolerance: %.2e %.2e %.2e %.2e",
                  c->values[v].name, est[0], est[1], est[2], est[3]);
            double scale = fabs(ref[j]);
            CHECK(e[3] <= 1e-6 * scale,
                  "%s: finest run (rtol 1e-6) %.12g agrees with the "
                  "independent run %.12g within 1e-6 relative (%.2e)",
                  c->values[v].name, row_at(c, 1e-6)->values[v], ref[j],
                  e[3] / scale);
            CHECK(est[3] >= e[3] - 1e-9 * scale,
                  "%s: finest estimated error %.2e covers the true error "
                  "%.2e",
                  c->values[v].name, est[3], e[3]);
        }
        int ok = 1;
        for (int i = 0; i < c->nrows; i++)
            ok &= c->rows[i].status == TS_OK && c->rows[i].evaluations > 0 &&
                  c->rows[i].trust.trustworthy;
        CHECK(ok, "every simulate run succeeded, trustworthy, with its "
                  "evaluations");
    }
    ts_convergence_free(c);
    c = NULL;
    /* Links: sphere.z found again at every link count. */
    static const double N[2] = {10, 20};
    c = rc ? NULL
           : ts_convergence_alloc(an.name, TS_CONV_LINKS, an.nvalues,
                                  an.values, 2, &err);
    rc = c ? ts_convergence_add_series(c, "", &err) : TS_ENOMEM;
    if (rc == 0)
        rc = ts_convergence_sweep(c, 0, &an, N, 2, &err);
    CHECK(rc == TS_OK && c->rows[0].status == TS_OK &&
              c->rows[1].status == TS_OK &&
              fabs(c->rows[0].values[0] - c->rows[1].values[0]) <
                  0.05 * c->rows[1].values[0],
          "links 10, 20: both runs find sphere.z; amplitude ratios %.6g "
          "and %.6g within 5 %% (%s)",
          c ? c->rows[0].values[0] : NAN, c ? c->rows[1].values[0] : NAN,
          err.msg);
    ts_convergence_free(c);
    ts_conv_analysis_free(&an);
    /* Refusals. */
    ts_excitation *none = ts_excitation_alloc(&err);
    rq.simulate.excitation = none;
    CHECK(pipeline_sweep(sc->system, TS_ANALYSIS_SIMULATE, &rq, &an,
                         &err) == TS_EINVAL &&
              strstr(err.msg, "periodic"),
          "no periodic excitation refused: %s", err.msg);
    rq.simulate.excitation = ex;
    snprintf(rq.simulate.output, sizeof rq.simulate.output, "tow.z");
    CHECK(pipeline_sweep(sc->system, TS_ANALYSIS_SIMULATE, &rq, &an,
                         &err) == TS_EINVAL && strstr(err.msg, "tow.force"),
          "the tow point's position refused, naming tow.force: %s", err.msg);
    snprintf(rq.simulate.output, sizeof rq.simulate.output, "sphere.z");
    rq.simulate.transient = 7.5;
    CHECK(pipeline_sweep(sc->system, TS_ANALYSIS_SIMULATE, &rq, &an,
                         &err) == TS_EINVAL &&
              strstr(err.msg, "period"),
          "a window shorter than a period refused: %s", err.msg);
    ts_excitation_free(none);
    ts_excitation_free(ex);
    ts_scene_free(sc);
    ts_units_free(u);
}

/* A progress callback that stops the sweep before run `stop_before`. */
static int stop_sweep(const ts_progress *p, void *data)
{
    int *calls = data;
    (*calls)++;
    return p->done >= 2 && !strcmp(p->unit, "runs");
}

/* 10. Stopping a sweep: the callback is called before each run with the
 * runs done; its nonzero return stops the sweep with TS_ECANCEL and the
 * rows so far, which still estimate. */
static void test_stop(void)
{
    ts_units *u;
    ts_scene *sc = load("examples/kamman_ex1_submerged.yaml", &u);
    if (!CHECK(sc, "load Kamman ex. 1")) {
        ts_units_free(u);
        return;
    }
    ts_err err = {0};
    ts_conv_analysis an;
    ts_convergence *c = equilibrium_links_table(sc->system, &an, &err);
    static const double N[5] = {5, 10, 20, 40, 80};
    int calls = 0;
    if (c) {
        c->progress = stop_sweep;
        c->progress_data = &calls;
    }
    int rc = c ? ts_convergence_add_series(c, "", &err) : TS_ENOMEM;
    if (rc == 0)
        rc = ts_convergence_sweep(c, 0, &an, N, 5, &err);
    CHECK(rc == TS_ECANCEL && c->nrows == 2 && calls == 3 &&
              strstr(err.msg, "after 2 of 5 runs"),
          "a sweep stopped before its third run keeps 2 rows (%d calls): %s",
          calls, err.msg);
    CHECK(c && c->nrows == 2 &&
              ts_convergence_estimate(c, 1e-3, &err) == TS_OK,
          "the rows so far still estimate");
    ts_conv_analysis_free(&an);
    ts_convergence_free(c);
    ts_scene_free(sc);
    ts_units_free(u);
}

int main(void)
{
    test_order();
    test_synthetic();
    test_cubic();
    test_kinds();
    test_series();
    test_refusals();
    test_equilibrium_sweep();
    test_modes_sweep();
    test_simulate_sweep();
    test_stop();
    return tc_done();
}
