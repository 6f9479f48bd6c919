/* converge.c: resolution sweeps, error estimates, observed orders and the
 * recommendation (towstab/converge.h; doc/converge.md).
 *
 * A value computed at resolution h is modelled as f(h) = f* + C h^p. Three
 * consecutive rows of a series (h0 > h1 > h2) give the observed order p as
 * the root of
 *   R(p) = (h0^p - h1^p) / (h1^p - h2^p) = (f0 - f1) / (f1 - f2),
 * which for refinement ratios r1 = h0/h1, r2 = h1/h2 is
 * R(p) = r2^p (r1^p - 1) / (r2^p - 1), increasing in p from ln r1 / ln r2
 * (GSL's Brent solver on [TS_CONV_ORDER_MIN, TS_CONV_ORDER_MAX]; Roache,
 * Verification and Validation in Computational Science and Engineering,
 * 1998, ch. 5; Celik et al., J. Fluids Eng. 130, 2008, for the
 * non-constant ratio). Richardson extrapolation of the two finest rows at
 * that order gives the reference f* (Richardson 1911). The reference is
 * trusted as asymptotic when the order of the finest triple agrees within
 * ORDER_AGREE with that of the triple before (or when only three rows
 * exist); its uncertainty is its distance from the extrapolation of the
 * triple before (or, with three rows, the size of the correction itself).
 * Otherwise the finest row is the reference, with the geometric tail of
 * the last two differences as its uncertainty; differences within the
 * runs' noise (solver tolerance, rounding) mean the value has converged;
 * differences that do not shrink mean it has not.
 *
 * Each row's error is |f - f*| plus the reference's uncertainty, at least
 * the row's own noise. The recommendation in a series is its coarsest row
 * from which on every row meets the target (status OK, trustworthy, every
 * relative error <= target): in a sweep of one parameter the cost grows
 * with resolution, and requiring the finer rows too keeps a lucky
 * cancellation at a coarse setting from being recommended. Across series
 * the recommendation with the least wall time wins.
 *
 * The built-in analyses rebuild the system with N links per cable
 * (ts_conv_system_with_links) or change a tolerance or step, and report
 * values that keep their meaning across resolutions: bodies and free ends
 * (not node indices), the top tension, the k-th lowest oscillatory mode,
 * and for a simulation the amplitude ratio, mean offset and phase of a
 * named output under a periodic excitation, fitted by least squares at
 * the excitation frequency over the window after the transient
 * (ts_compare_fit_sinusoid; Kamman & Nguyen 1990, example 4).
 */
#include "towstab/converge.h"

#include <float.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "towstab/compare.h"
#include "towstab/response.h"

/* The finest two observed orders agree (asymptotic range) when they
 * differ by at most this fraction of the finer one. */
#define ORDER_AGREE 0.2
/* Differences below the two rows' noise plus this many ulps of the values
 * are not resolved. */
#define ROUND_ULPS 8.0
/* Noise of an equilibrium value: this many times its relative residual
 * (at least 16 eps) times the length or force scale. */
#define EQ_NOISE_FACTOR 10.0
#define EQ_NOISE_MIN_REL (16.0 * DBL_EPSILON)
/* Noise of a mode value in a step sweep, relative. */
#define STEP_NOISE_REL (64.0 * DBL_EPSILON)
/* Brent iterations for the observed order. */
#define ORDER_MAXIT 200

/* ---- names and checks -------------------------------------------------- */

const char *ts_conv_param_name(ts_conv_param p)
{
    switch (p) {
    case TS_CONV_LINKS: return "links";
    case TS_CONV_TOLERANCE: return "tolerance";
    case TS_CONV_STEP: return "step";
    }
    return "?";
}

const char *ts_conv_ref_name(ts_conv_ref k)
{
    switch (k) {
    case TS_CONV_REF_RICHARDSON: return "richardson";
    case TS_CONV_REF_FINEST: return "finest";
    case TS_CONV_REF_CONVERGED: return "converged";
    case TS_CONV_REF_DIVERGING: return "diverging";
    default: return "none";
    }
}

double ts_conv_resolution(ts_conv_param p, double setting)
{
    return p == TS_CONV_LINKS ? 1.0 / setting : setting;
}

static int check_setting(ts_conv_param p, double v, const char *what,
                         ts_err *err)
{
    switch (p) {
    case TS_CONV_LINKS:
        if (!(v >= 1 && v <= TS_CONV_MAX_LINKS) || v != floor(v))
            return ts_fail(err, TS_EINVAL,
                           "%s: links must be whole numbers in [1, %d], "
                           "got %g",
                           what, TS_CONV_MAX_LINKS, v);
        break;
    case TS_CONV_TOLERANCE:
        if (!(v > 0 && v < 1))
            return ts_fail(err, TS_EINVAL,
                           "%s: tolerances must be in (0, 1), got %g", what,
                           v);
        break;
    case TS_CONV_STEP:
        if (!(v > 0 && v <= 0.1))
            return ts_fail(err, TS_EINVAL,
                           "%s: relative steps must be in (0, 0.1], got %g",
                           what, v);
        break;
    default:
        return ts_fail(err, TS_EINVAL, "%s: unknown parameter %d", what,
                       (int)p);
    }
    return TS_OK;
}

int ts_conv_check_settings(ts_conv_param p, const double settings[], int n,
                           const char *what, ts_err *err)
{
    if (n < 1 || n > TS_CONV_MAX_SETTINGS)
        return ts_fail(err, TS_EINVAL,
                       "%s: expected 1 to %d settings, got %d", what,
                       TS_CONV_MAX_SETTINGS, n);
    for (int i = 0; i < n; i++) {
        int rc = check_setting(p, settings[i], what, err);
        if (rc)
            return rc;
        for (int j = 0; j < i; j++)
            if (settings[j] == settings[i])
                return ts_fail(err, TS_EINVAL,
                               "%s: %g is given twice", what, settings[i]);
    }
    return TS_OK;
}

/* ---- order and extrapolation ------------------------------------------- */

typedef struct order_eq {
    double r1, r2, ratio;
} order_eq;

/* R(p) - ratio, with R(p) = r2^p (r1^p - 1) / (r2^p - 1) written with
 * expm1 so that it stays accurate for small p. */
static double order_f(double p, void *params)
{
    const order_eq *q = params;
    double a = expm1(p * log(q->r1)), b = expm1(p * log(q->r2));
    return exp(p * log(q->r2)) * a / b - q->ratio;
}

int ts_conv_observed_order(const double h[3], const double f[3], double *p)
{
    *p = NAN;
    if (!(h[0] > h[1] && h[1] > h[2] && h[2] > 0))
        return TS_EINVAL;
    double d1 = f[0] - f[1], d2 = f[1] - f[2];
    if (!(d1 != 0 && d2 != 0) || (d1 > 0) != (d2 > 0) || !isfinite(d1) ||
        !isfinite(d2))
        return TS_EDOMAIN;
    order_eq q = {h[0] / h[1], h[1] / h[2], d1 / d2};
    double lo = TS_CONV_ORDER_MIN, hi = TS_CONV_ORDER_MAX;
    double flo = order_f(lo, &q), fhi = order_f(hi, &q);
    if (!(flo < 0 && fhi > 0))
        return TS_EDOMAIN;
    gsl_set_error_handler_off();
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!s)
        return TS_ENOMEM;
    gsl_function F = {order_f, &q};
    gsl_root_fsolver_set(s, &F, lo, hi);
    int status = GSL_CONTINUE;
    for (int it = 0; status == GSL_CONTINUE && it < ORDER_MAXIT; it++) {
        if (gsl_root_fsolver_iterate(s))
            break;
        status = gsl_root_test_interval(gsl_root_fsolver_x_lower(s),
                                        gsl_root_fsolver_x_upper(s), 0.0,
                                        1e-13);
    }
    double root = gsl_root_fsolver_root(s);
    gsl_root_fsolver_free(s);
    if (status != GSL_SUCCESS)
        return TS_EDOMAIN;
    *p = root;
    return TS_OK;
}

double ts_conv_extrapolate(double h1, double f1, double h2, double f2,
                           double p)
{
    return f2 + (f2 - f1) / expm1(p * log(h1 / h2));
}

/* ---- the table --------------------------------------------------------- */

static void row_free(ts_conv_row *r)
{
    free(r->values);
    free(r->noise);
    free(r->errors);
    free(r->rel_errors);
    free(r->order);
}

static void series_free(ts_conv_series *s)
{
    free(s->order);
    free(s->reference);
    free(s->reference_error);
    free(s->ref_kind);
}

void ts_convergence_free(ts_convergence *c)
{
    if (!c)
        return;
    for (int i = 0; i < c->nrows; i++)
        row_free(&c->rows[i]);
    for (int s = 0; s < c->nseries; s++)
        series_free(&c->series[s]);
    free(c->rows);
    free(c->series);
    free(c->values);
    free(c);
}

ts_convergence *ts_convergence_alloc(const char *analysis,
                                     ts_conv_param param, int nvalues,
                                     const ts_conv_value values[],
                                     int capacity, ts_err *err)
{
    if (nvalues < 1 || capacity < 1) {
        ts_fail(err, TS_EINVAL,
                "convergence: need at least one value and one row, got %d "
                "and %d",
                nvalues, capacity);
        return NULL;
    }
    for (int i = 0; i < nvalues; i++) {
        if (!values[i].name[0] || !(values[i].scale >= 0)) {
            ts_fail(err, TS_EINVAL,
                    "convergence: value %d needs a name and a scale >= 0", i);
            return NULL;
        }
        for (int j = 0; j < i; j++)
            if (strcmp(values[i].name, values[j].name) == 0) {
                ts_fail(err, TS_EINVAL,
                        "convergence: value '%s' is named twice",
                        values[i].name);
                return NULL;
            }
    }
    ts_convergence *c = calloc(1, sizeof *c);
    if (c) {
        c->values = calloc((size_t)nvalues, sizeof *c->values);
        c->rows = calloc((size_t)capacity, sizeof *c->rows);
    }
    if (!c || !c->values || !c->rows) {
        ts_convergence_free(c);
        ts_fail(err, TS_ENOMEM, "convergence: out of memory");
        return NULL;
    }
    snprintf(c->analysis, sizeof c->analysis, "%s", analysis ? analysis : "");
    c->param = param;
    c->nvalues = nvalues;
    c->capacity = capacity;
    c->recommended = -1;
    c->limiting_value = -1;
    c->predicted_setting = c->predicted_wall_s = NAN;
    for (int i = 0; i < nvalues; i++) {
        ts_conv_value *v = &c->values[i];
        memcpy(v->name, values[i].name, sizeof v->name);
        v->name[sizeof v->name - 1] = '\0';
        memcpy(v->unit, values[i].unit, sizeof v->unit);
        v->unit[sizeof v->unit - 1] = '\0';
        v->scale = values[i].scale;
        v->order = v->reference = v->reference_error = NAN;
        v->ref_kind = TS_CONV_REF_NONE;
        v->rel_scale = NAN;
    }
    return c;
}

int ts_convergence_add_series(ts_convergence *c, const char *name,
                              ts_err *err)
{
    ts_conv_series *ns =
        realloc(c->series, (size_t)(c->nseries + 1) * sizeof *ns);
    if (!ns)
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    c->series = ns;
    ts_conv_series *s = &ns[c->nseries];
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name ? name : "");
    s->recommended = -1;
    size_t nv = (size_t)c->nvalues;
    s->order = malloc(nv * sizeof(double));
    s->reference = malloc(nv * sizeof(double));
    s->reference_error = malloc(nv * sizeof(double));
    s->ref_kind = calloc(nv, sizeof(ts_conv_ref));
    if (!s->order || !s->reference || !s->reference_error || !s->ref_kind) {
        series_free(s);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    for (size_t i = 0; i < nv; i++)
        s->order[i] = s->reference[i] = s->reference_error[i] = NAN;
    return c->nseries++;
}

int ts_convergence_add_row(ts_convergence *c, int series, double setting,
                           int status, const char *message, double wall_s,
                           long evaluations, const ts_trust *trust,
                           const double values[], const double noise[],
                           ts_err *err)
{
    if (series < 0 || series >= c->nseries)
        return ts_fail(err, TS_EINVAL, "convergence: no series %d", series);
    int rc = check_setting(c->param, setting, "convergence", err);
    if (rc)
        return rc;
    for (int i = 0; i < c->nrows; i++)
        if (c->rows[i].series == series && c->rows[i].setting == setting)
            return ts_fail(err, TS_EINVAL,
                           "convergence: %s %g is already in series '%s'",
                           ts_conv_param_name(c->param), setting,
                           c->series[series].name);
    if (c->nrows >= c->capacity)
        return ts_fail(err, TS_ENOMEM,
                       "convergence: the table holds %d rows", c->capacity);
    ts_conv_row *r = &c->rows[c->nrows];
    memset(r, 0, sizeof *r);
    size_t nv = (size_t)c->nvalues;
    r->values = malloc(nv * sizeof(double));
    r->noise = malloc(nv * sizeof(double));
    r->errors = malloc(nv * sizeof(double));
    r->rel_errors = malloc(nv * sizeof(double));
    r->order = malloc(nv * sizeof(double));
    if (!r->values || !r->noise || !r->errors || !r->rel_errors ||
        !r->order) {
        row_free(r);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    r->series = series;
    r->setting = setting;
    r->h = ts_conv_resolution(c->param, setting);
    r->status = status;
    snprintf(r->message, sizeof r->message, "%s", message ? message : "");
    r->wall_s = wall_s;
    r->evaluations = evaluations;
    if (trust)
        r->trust = *trust;
    else
        ts_trust_init(&r->trust);
    /* A failed run is not trustworthy, whatever its statistics say. */
    if (status != TS_OK)
        ts_trust_fail(&r->trust, "the run failed: %s",
                      message && message[0] ? message : ts_strerror(status));
    for (size_t i = 0; i < nv; i++) {
        r->values[i] = status == TS_OK && values ? values[i] : NAN;
        r->noise[i] = noise && noise[i] >= 0 ? noise[i] : 0.0;
        r->errors[i] = r->rel_errors[i] = r->order[i] = NAN;
    }
    r->max_rel_error = NAN;
    c->nrows++;
    c->estimated = 0;
    return TS_OK;
}

/* ---- estimation -------------------------------------------------------- */

/* Rows of series s with status OK and a finite value v, by h descending
 * (coarse to fine). Returns their number. */
static int usable_rows(const ts_convergence *c, int s, int v, int *idx)
{
    int m = 0;
    for (int i = 0; i < c->nrows; i++) {
        const ts_conv_row *r = &c->rows[i];
        if (r->series == s && r->status == TS_OK && isfinite(r->values[v]))
            idx[m++] = i;
    }
    for (int i = 1; i < m; i++) /* insertion sort: m is small */
        for (int j = i; j > 0 && c->rows[idx[j - 1]].h < c->rows[idx[j]].h;
             j--) {
            int t = idx[j];
            idx[j] = idx[j - 1];
            idx[j - 1] = t;
        }
    return m;
}

/* Reference of value v in series s; local orders into the rows. */
static void estimate_value(ts_convergence *c, int s, int v, int *idx,
                           double *d, int *resolved, double *p)
{
    ts_conv_series *S = &c->series[s];
    int m = usable_rows(c, s, v, idx);
    S->order[v] = S->reference[v] = S->reference_error[v] = NAN;
    S->ref_kind[v] = TS_CONV_REF_NONE;
    if (m == 0)
        return;
#define F(i) (c->rows[idx[i]].values[v])
#define H(i) (c->rows[idx[i]].h)
#define N(i) (c->rows[idx[i]].noise[v])
    for (int i = 0; i + 1 < m; i++) {
        d[i] = F(i + 1) - F(i);
        double floor = N(i) + N(i + 1) +
                       ROUND_ULPS * DBL_EPSILON * (fabs(F(i)) + fabs(F(i + 1)));
        resolved[i] = fabs(d[i]) > floor;
    }
    for (int i = 0; i + 2 < m; i++) {
        p[i] = NAN;
        if (resolved[i] && resolved[i + 1]) {
            double hh[3] = {H(i), H(i + 1), H(i + 2)};
            double ff[3] = {F(i), F(i + 1), F(i + 2)};
            ts_conv_observed_order(hh, ff, &p[i]);
        }
        c->rows[idx[i + 2]].order[v] = p[i];
    }
    double fn = F(m - 1), nn = N(m - 1);
    if (m == 1) {
        S->reference[v] = fn;
        return; /* one row: no estimate */
    }
    int L = m - 2; /* last difference */
    if (m >= 3)
        S->order[v] = p[m - 3];
    if (!resolved[L]) {
        S->ref_kind[v] = TS_CONV_REF_CONVERGED;
        S->reference[v] = fn;
        S->reference_error[v] = fabs(d[L]) + nn;
    } else if (m >= 3 && isfinite(p[m - 3]) &&
               (m == 3 ||
                (isfinite(p[m - 4]) &&
                 fabs(p[m - 3] - p[m - 4]) <= ORDER_AGREE * p[m - 3]))) {
        double ref = ts_conv_extrapolate(H(m - 2), F(m - 2), H(m - 1), fn,
                                         p[m - 3]);
        double unc;
        if (m >= 4) {
            double prev = ts_conv_extrapolate(H(m - 3), F(m - 3), H(m - 2),
                                              F(m - 2), p[m - 4]);
            unc = fabs(ref - prev);
        } else {
            unc = fabs(ref - fn);
        }
        S->ref_kind[v] = TS_CONV_REF_RICHARDSON;
        S->reference[v] = ref;
        S->reference_error[v] = unc + nn;
    } else if (L >= 1 && resolved[L - 1]) {
        double rho = fabs(d[L]) / fabs(d[L - 1]);
        S->reference[v] = fn;
        if (rho < 1) {
            S->ref_kind[v] = TS_CONV_REF_FINEST;
            S->reference_error[v] = fabs(d[L]) * rho / (1.0 - rho) + nn;
        } else {
            S->ref_kind[v] = TS_CONV_REF_DIVERGING;
            S->reference_error[v] = fabs(d[L]) + nn;
        }
    } else {
        /* Two rows, or a resolved difference after an unresolved one: the
         * last difference itself, which bounds the error of the finer row
         * when each step at least halves it. */
        S->ref_kind[v] = TS_CONV_REF_FINEST;
        S->reference[v] = fn;
        S->reference_error[v] = fabs(d[L]) + nn;
    }
#undef F
#undef H
#undef N
}

/* Relative scale of value v: its own scale, else |reference|, else the
 * largest |value| of any row, else 1. */
static double rel_scale(const ts_convergence *c, int v, double ref)
{
    if (c->values[v].scale > 0)
        return c->values[v].scale;
    if (isfinite(ref) && ref != 0)
        return fabs(ref);
    double big = 0;
    for (int i = 0; i < c->nrows; i++)
        if (isfinite(c->rows[i].values[v]))
            big = fmax(big, fabs(c->rows[i].values[v]));
    return big > 0 ? big : 1.0;
}

/* Rows of series s with status OK, by h descending. */
static int series_rows(const ts_convergence *c, int s, int ok_only, int *idx)
{
    int m = 0;
    for (int i = 0; i < c->nrows; i++)
        if (c->rows[i].series == s &&
            (!ok_only || c->rows[i].status == TS_OK))
            idx[m++] = i;
    for (int i = 1; i < m; i++)
        for (int j = i; j > 0 && c->rows[idx[j - 1]].h < c->rows[idx[j]].h;
             j--) {
            int t = idx[j];
            idx[j] = idx[j - 1];
            idx[j - 1] = t;
        }
    return m;
}

void ts_convergence_sorted_rows(const ts_convergence *c, int idx[])
{
    int m = 0;
    for (int s = 0; s < c->nseries; s++)
        m += series_rows(c, s, 0, idx + m);
}

int ts_convergence_estimate(ts_convergence *c, double target, ts_err *err)
{
    if (!(target > 0) || !isfinite(target))
        return ts_fail(err, TS_EINVAL,
                       "convergence: the target relative error must be > 0, "
                       "got %g",
                       target);
    if (c->nrows == 0 || c->nseries == 0)
        return ts_fail(err, TS_EINVAL, "convergence: no runs to estimate");
    int n = c->nrows, nv = c->nvalues;
    int *idx = malloc((size_t)n * sizeof(int));
    int *resolved = malloc((size_t)n * sizeof(int));
    double *d = malloc((size_t)n * sizeof(double));
    double *p = malloc((size_t)n * sizeof(double));
    if (!idx || !resolved || !d || !p) {
        free(idx);
        free(resolved);
        free(d);
        free(p);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    c->target = target;
    for (int s = 0; s < c->nseries; s++)
        for (int v = 0; v < nv; v++)
            estimate_value(c, s, v, idx, d, resolved, p);

    /* The reference series: the most accurate reference (largest relative
     * uncertainty over the values, smallest over the series); a series
     * with a value it cannot estimate only if no other can. */
    int best = 0;
    double best_q = INFINITY;
    int best_bad = 1;
    for (int s = 0; s < c->nseries; s++) {
        const ts_conv_series *S = &c->series[s];
        double q = 0;
        int bad = 0;
        for (int v = 0; v < nv; v++) {
            bad |= S->ref_kind[v] == TS_CONV_REF_NONE ||
                   S->ref_kind[v] == TS_CONV_REF_DIVERGING;
            double r = S->reference_error[v] /
                       rel_scale(c, v, S->reference[v]);
            q = fmax(q, isfinite(r) ? r : INFINITY);
        }
        if ((bad < best_bad) || (bad == best_bad && q < best_q)) {
            best = s;
            best_q = q;
            best_bad = bad;
        }
    }
    c->reference_series = best;
    const ts_conv_series *R = &c->series[best];
    for (int v = 0; v < nv; v++) {
        ts_conv_value *V = &c->values[v];
        V->order = R->order[v];
        V->reference = R->reference[v];
        V->reference_error = R->reference_error[v];
        V->ref_kind = R->ref_kind[v];
        V->rel_scale = rel_scale(c, v, V->reference);
    }
    int ref_ok = !best_bad;

    /* Every row against the common reference. */
    for (int i = 0; i < n; i++) {
        ts_conv_row *r = &c->rows[i];
        r->max_rel_error = 0;
        for (int v = 0; v < nv; v++) {
            const ts_conv_value *V = &c->values[v];
            double e = NAN;
            if (r->status == TS_OK && isfinite(r->values[v]) &&
                V->ref_kind != TS_CONV_REF_NONE)
                e = fmax(fabs(r->values[v] - V->reference) +
                             V->reference_error,
                         r->noise[v]);
            r->errors[v] = e;
            r->rel_errors[v] = e / V->rel_scale;
        }
        /* One unknown error makes the row's maximum unknown. */
        for (int v = 0; v < nv && isfinite(r->max_rel_error); v++)
            r->max_rel_error = isfinite(r->rel_errors[v])
                                   ? fmax(r->max_rel_error, r->rel_errors[v])
                                   : NAN;
        r->meets_target = ref_ok && r->status == TS_OK &&
                          r->trust.trustworthy &&
                          r->max_rel_error <= target;
    }

    /* Recommendations. */
    c->recommended = -1;
    for (int s = 0; s < c->nseries; s++) {
        ts_conv_series *S = &c->series[s];
        int m = series_rows(c, s, 0, idx);
        S->recommended = -1;
        for (int i = m - 1; i >= 0 && c->rows[idx[i]].meets_target; i--)
            S->recommended = idx[i];
        if (S->recommended >= 0 &&
            (c->recommended < 0 ||
             c->rows[S->recommended].wall_s < c->rows[c->recommended].wall_s))
            c->recommended = S->recommended;
    }

    /* The limiting value (largest error at the reference series' finest
     * row) and, with no recommendation, the predicted setting. */
    c->limiting_value = -1;
    c->predicted_setting = c->predicted_wall_s = NAN;
    int m = series_rows(c, best, 1, idx);
    if (m > 0) {
        const ts_conv_row *fin = &c->rows[idx[m - 1]];
        double worst = -1;
        for (int v = 0; v < nv; v++)
            if (isfinite(fin->rel_errors[v]) && fin->rel_errors[v] > worst) {
                worst = fin->rel_errors[v];
                c->limiting_value = v;
            }
        int lv = c->limiting_value;
        if (c->recommended < 0 && lv >= 0 && worst > target &&
            c->values[lv].ref_kind == TS_CONV_REF_RICHARDSON &&
            c->values[lv].order > 0) {
            double pp = c->values[lv].order;
            double h = fin->h * pow(target / worst, 1.0 / pp);
            c->predicted_setting =
                c->param == TS_CONV_LINKS ? ceil(1.0 / h) : h;
            double hp = ts_conv_resolution(c->param, c->predicted_setting);
            if (m >= 2) {
                const ts_conv_row *prev = &c->rows[idx[m - 2]];
                double q = 0;
                if (prev->wall_s > 0 && fin->wall_s > 0)
                    q = log(fin->wall_s / prev->wall_s) /
                        log(prev->h / fin->h);
                if (!(q > 0))
                    q = 0;
                c->predicted_wall_s = fin->wall_s * pow(fin->h / hp, q);
            }
        }
    }
    c->estimated = 1;
    free(idx);
    free(resolved);
    free(d);
    free(p);
    return TS_OK;
}

/* ---- the sweep ------------------------------------------------------- */

static double wall_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void ts_conv_analysis_free(ts_conv_analysis *an)
{
    if (!an)
        return;
    if (an->free_ctx && an->ctx)
        an->free_ctx(an->ctx);
    free(an->values);
    an->values = NULL;
    an->ctx = NULL;
    an->nvalues = 0;
}

int ts_convergence_sweep(ts_convergence *c, int series,
                         const ts_conv_analysis *an, const double settings[],
                         int n, ts_err *err)
{
    if (an->nvalues != c->nvalues)
        return ts_fail(err, TS_EINVAL,
                       "convergence: the analysis reports %d values, the "
                       "table holds %d",
                       an->nvalues, c->nvalues);
    for (int v = 0; v < c->nvalues; v++)
        if (strcmp(an->values[v].name, c->values[v].name) != 0)
            return ts_fail(err, TS_EINVAL,
                           "convergence: value %d is '%s' in the analysis "
                           "and '%s' in the table",
                           v, an->values[v].name, c->values[v].name);
    int rc = ts_conv_check_settings(c->param, settings, n,
                                    ts_conv_param_name(c->param), err);
    if (rc)
        return rc;
    double *val = malloc((size_t)c->nvalues * sizeof(double));
    double *noise = malloc((size_t)c->nvalues * sizeof(double));
    if (!val || !noise) {
        free(val);
        free(noise);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    for (int i = 0; i < n && rc == TS_OK; i++) {
        ts_progress p = {"sweep", i, n, "runs"};
        if (c->progress && c->progress(&p, c->progress_data)) {
            rc = ts_fail(err, TS_ECANCEL, "convergence: stopped on request "
                         "after %d of %d runs", i, n);
            break;
        }
        for (int v = 0; v < c->nvalues; v++) {
            val[v] = NAN;
            noise[v] = 0.0;
        }
        ts_trust trust;
        ts_trust_init(&trust);
        long evals = 0;
        ts_err rerr = {0};
        double t0 = wall_now();
        int st = an->run(an->ctx, c->param, settings[i], val, noise, &evals,
                         &trust, &rerr);
        double wall = wall_now() - t0;
        if (st == TS_ENOMEM) {
            if (err)
                *err = rerr;
            rc = st;
            break;
        }
        if (st != TS_OK && !rerr.msg[0])
            snprintf(rerr.msg, sizeof rerr.msg, "%s", ts_strerror(st));
        rc = ts_convergence_add_row(c, series, settings[i], st,
                                    st == TS_OK ? NULL : rerr.msg, wall,
                                    evals, &trust, val, noise, err);
        if (rc == TS_OK && st == TS_ECANCEL) {
            if (err)
                *err = rerr;
            rc = st;
        }
    }
    free(val);
    free(noise);
    return rc;
}

/* ---- systems --------------------------------------------------------- */

ts_system *ts_conv_system_with_links(const ts_system *sys, int links,
                                     ts_err *err)
{
    if (links < 1 || links > TS_CONV_MAX_LINKS) {
        ts_fail(err, TS_EINVAL, "links: expected 1 to %d per cable, got %d",
                TS_CONV_MAX_LINKS, links);
        return NULL;
    }
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].link_fraction) {
            ts_fail(err, TS_EINVAL,
                    "links: cables[%d] '%s' has link_lengths; a link sweep "
                    "needs equal links (remove link_lengths)",
                    c, sys->cables[c].name);
            return NULL;
        }
    ts_system *s = ts_system_copy(sys, err);
    if (!s)
        return NULL;
    for (int c = 0; c < s->ncables; c++)
        s->cables[c].nlinks = links;
    if (ts_system_build(s, err) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

static double total_length(const ts_system *sys)
{
    double L = 0;
    for (int c = 0; c < sys->ncables; c++)
        L += sys->cables[c].length;
    return L;
}

/* Node of reported point i: body i, or the free end of the i-th cable
 * without a body at its end. */
static int point_node(const ts_system *sys, int use_bodies, int i)
{
    if (use_bodies)
        return ts_system_body_node(sys, i);
    int k = 0;
    for (int c = 0; c < sys->ncables; c++) {
        if (sys->cables[c].to_body >= 0)
            continue;
        if (k++ != i)
            continue;
        for (int l = 0; l < sys->nlinks; l++)
            if (sys->links[l].cable == c && sys->links[l].next < 0)
                return sys->links[l].lower;
    }
    return -1;
}

/* The system of one run: a copy with N links, or the analysis' own. */
static ts_system *run_system(const ts_system *base, ts_conv_param p,
                             double setting, ts_err *err)
{
    if (p == TS_CONV_LINKS)
        return ts_conv_system_with_links(base, (int)setting, err);
    return (ts_system *)base;
}

/* ---- equilibrium ----------------------------------------------------- */

typedef struct eq_ctx {
    ts_system *sys;
    ts_equilibrium_opts eo;
    int use_bodies, npoints;
    double length;
} eq_ctx;

static void eq_ctx_free(void *p)
{
    eq_ctx *x = p;
    ts_system_free(x->sys);
    free(x);
}

static int eq_run(void *ctx, ts_conv_param p, double setting,
                  double values[], double noise[], long *evaluations,
                  ts_trust *trust, ts_err *err)
{
    eq_ctx *x = ctx;
    if (p == TS_CONV_STEP)
        return ts_fail(err, TS_EINVAL,
                       "equilibrium: there is no linearization step to "
                       "sweep; sweep links or tolerance");
    ts_equilibrium_opts o = x->eo;
    if (p == TS_CONV_TOLERANCE)
        o.tol = setting;
    ts_system *sys = run_system(x->sys, p, setting, err);
    if (!sys)
        return err && err->code ? err->code : TS_EINVAL;
    ts_kernel *k = ts_kernel_alloc(sys, err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, err) : NULL;
    int rc = eq ? ts_equilibrium_solve(k, &o, eq, err) : TS_ENOMEM;
    if (eq) {
        *evaluations += eq->evaluations;
        ts_health_equilibrium(sys, eq, trust);
    }
    if (rc == TS_OK) {
        double rel = fmax(eq->residual, EQ_NOISE_MIN_REL);
        for (int i = 0; i < x->npoints; i++) {
            int node = point_node(sys, x->use_bodies, i);
            for (int j = 0; j < 3; j++) {
                values[3 * i + j] = eq->positions[3 * node + j];
                noise[3 * i + j] = EQ_NOISE_FACTOR * rel * x->length;
            }
        }
        values[3 * x->npoints] = eq->top_tension;
        noise[3 * x->npoints] = EQ_NOISE_FACTOR * rel * eq->force_scale;
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    if (sys != x->sys)
        ts_system_free(sys);
    return rc;
}

/* Names of the reported points (bodies, or free ends) into an's values.
 * Returns the number of points, or -1 out of memory. */
static int point_values(const ts_system *sys, ts_conv_analysis *an,
                        int extra, int *use_bodies)
{
    *use_bodies = sys->nbodies > 0;
    int np = 0;
    if (*use_bodies)
        np = sys->nbodies;
    else
        for (int c = 0; c < sys->ncables; c++)
            np += sys->cables[c].to_body < 0;
    an->nvalues = 3 * np + extra;
    an->values = calloc((size_t)an->nvalues, sizeof *an->values);
    if (!an->values)
        return -1;
    double L = total_length(sys);
    static const char axis[3] = {'x', 'y', 'z'};
    int i = 0;
    for (int c = 0; !*use_bodies && c < sys->ncables; c++) {
        if (sys->cables[c].to_body >= 0)
            continue;
        for (int j = 0; j < 3; j++) {
            ts_conv_value *v = &an->values[3 * i + j];
            snprintf(v->name, sizeof v->name, "%.60s.end.%c",
                     sys->cables[c].name, axis[j]);
            snprintf(v->unit, sizeof v->unit, "m");
            v->scale = L;
        }
        i++;
    }
    for (int b = 0; *use_bodies && b < sys->nbodies; b++)
        for (int j = 0; j < 3; j++) {
            ts_conv_value *v = &an->values[3 * b + j];
            snprintf(v->name, sizeof v->name, "%.63s.%c", sys->bodies[b].name,
                     axis[j]);
            snprintf(v->unit, sizeof v->unit, "m");
            v->scale = L;
        }
    return np;
}

int ts_conv_equilibrium_analysis(const ts_system *sys,
                                 const ts_equilibrium_opts *eo,
                                 ts_conv_analysis *an, ts_err *err)
{
    memset(an, 0, sizeof *an);
    eq_ctx *x = calloc(1, sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    x->sys = ts_system_copy(sys, err);
    if (!x->sys) {
        free(x);
        return err && err->code ? err->code : TS_ENOMEM;
    }
    if (eo)
        x->eo = *eo;
    else
        ts_equilibrium_opts_default(&x->eo);
    x->length = total_length(sys);
    snprintf(an->name, sizeof an->name, "equilibrium");
    an->ctx = x;
    an->free_ctx = eq_ctx_free;
    an->run = eq_run;
    x->npoints = point_values(sys, an, 1, &x->use_bodies);
    if (x->npoints < 0) {
        ts_conv_analysis_free(an);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    ts_conv_value *t = &an->values[3 * x->npoints];
    snprintf(t->name, sizeof t->name, "top_tension");
    snprintf(t->unit, sizeof t->unit, "N");
    t->scale = 0.0;
    return TS_OK;
}

/* ---- modes ----------------------------------------------------------- */

typedef struct modes_ctx {
    ts_system *sys;
    ts_equilibrium_opts eo;
    ts_linearize_opts lo;
    ts_eigen_opts eig;
    int have_eig;
    int nmodes;
} modes_ctx;

static void modes_ctx_free(void *p)
{
    modes_ctx *x = p;
    ts_system_free(x->sys);
    free(x);
}

/* States from which the default uses ARPACK (ts_eigen_opts default). */
#define MODES_ARPACK_STATES 1200

static int modes_run(void *ctx, ts_conv_param p, double setting,
                     double values[], double noise[], long *evaluations,
                     ts_trust *trust, ts_err *err)
{
    modes_ctx *x = ctx;
    ts_equilibrium_opts o = x->eo;
    ts_linearize_opts lo = x->lo;
    if (p == TS_CONV_TOLERANCE)
        o.tol = setting;
    if (p == TS_CONV_STEP)
        lo.rel_step = setting;
    ts_system *sys = run_system(x->sys, p, setting, err);
    if (!sys)
        return err && err->code ? err->code : TS_EINVAL;
    ts_kernel *k = ts_kernel_alloc(sys, err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, err) : NULL;
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    ts_mode_health *mh = NULL;
    int rc = eq ? ts_equilibrium_solve(k, &o, eq, err) : TS_ENOMEM;
    if (eq) {
        *evaluations += eq->evaluations;
        ts_health_equilibrium(sys, eq, trust);
    }
    if (rc == TS_OK) {
        lin = ts_linear_alloc(k, err);
        rc = lin ? ts_linearize_equilibrium(k, eq, &lo, lin, err) : TS_ENOMEM;
    }
    if (rc == TS_OK) {
        *evaluations += lin->evaluations;
        ts_eigen_opts eg;
        if (x->have_eig) {
            eg = x->eig;
        } else {
            ts_eigen_opts_default(&eg);
            eg.count = lin->nstate >= MODES_ARPACK_STATES ? 2 * x->nmodes + 10
                                                          : 0;
            eg.vectors = 1;
        }
        rc = ts_eigen_solve(lin, &eg, &e, err);
    }
    if (rc == TS_OK) {
        mh = malloc((size_t)(e->nmodes > 0 ? e->nmodes : 1) * sizeof *mh);
        ts_trust all;
        ts_trust_init(&all);
        rc = mh ? ts_health_modes(sys, lin, e, mh, &all, err)
                : ts_fail(err, TS_ENOMEM, "convergence: out of memory");
        if (rc == TS_OK) {
            /* The row's health: the surface kink and the reported modes
             * (a stiff axial mode far above them does not make their
             * frequencies untrustworthy); the notes of the whole
             * analysis. */
            if (lin->kinks > lin->kink_tow)
                ts_trust_fail(trust, "%s", all.reasons[0]);
            for (int i = 0; i < all.nnotes; i++)
                ts_trust_note(trust, "%s", all.notes[i]);
            int k2 = 0;
            for (int m = 0; m < e->nmodes && k2 < x->nmodes; m++) {
                const ts_mode *md = &e->modes[m];
                if (!(md->im > 0) ||
                    !(md->damping_ratio < TS_CONV_MODE_DAMPING_MAX))
                    continue;
                double mag = hypot(md->re, md->im);
                values[2 * k2] = md->freq_hz;
                values[2 * k2 + 1] = md->damping_ratio;
                if (p == TS_CONV_STEP) {
                    noise[2 * k2] = STEP_NOISE_REL * fabs(md->freq_hz);
                    noise[2 * k2 + 1] =
                        STEP_NOISE_REL * fmax(fabs(md->damping_ratio), 1.0);
                } else {
                    noise[2 * k2] = md->error_bound / (2.0 * M_PI);
                    noise[2 * k2 + 1] = md->error_bound / mag;
                }
                if (!mh[m].trustworthy)
                    ts_trust_fail(trust, "mode%d (%.6g Hz): damping ratio "
                                         "%.3g +- %.2g is not resolved",
                                  k2 + 1, md->freq_hz, md->damping_ratio,
                                  mh[m].damping_error);
                k2++;
            }
        }
    }
    free(mh);
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    if (sys != x->sys)
        ts_system_free(sys);
    return rc;
}

int ts_conv_modes_analysis(const ts_system *sys,
                           const ts_equilibrium_opts *eo,
                           const ts_linearize_opts *lo,
                           const ts_eigen_opts *eig, int nmodes,
                           ts_conv_analysis *an, ts_err *err)
{
    memset(an, 0, sizeof *an);
    if (nmodes < 1 || nmodes > 1000)
        return ts_fail(err, TS_EINVAL,
                       "modes: expected 1 to 1000 modes to follow, got %d",
                       nmodes);
    modes_ctx *x = calloc(1, sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    x->sys = ts_system_copy(sys, err);
    if (!x->sys) {
        free(x);
        return err && err->code ? err->code : TS_ENOMEM;
    }
    if (eo)
        x->eo = *eo;
    else
        ts_equilibrium_opts_default(&x->eo);
    if (lo)
        x->lo = *lo;
    else
        ts_linearize_opts_default(&x->lo);
    x->lo.estimate_error = 1; /* the error bounds are the modes' noise */
    if (eig) {
        x->eig = *eig;
        x->eig.vectors = 1;
        x->have_eig = 1;
    }
    x->nmodes = nmodes;
    snprintf(an->name, sizeof an->name, "modes");
    an->ctx = x;
    an->free_ctx = modes_ctx_free;
    an->run = modes_run;
    an->nvalues = 2 * nmodes;
    an->values = calloc((size_t)an->nvalues, sizeof *an->values);
    if (!an->values) {
        ts_conv_analysis_free(an);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    for (int m = 0; m < nmodes; m++) {
        ts_conv_value *f = &an->values[2 * m], *z = f + 1;
        snprintf(f->name, sizeof f->name, "mode%d.freq_hz", m + 1);
        snprintf(f->unit, sizeof f->unit, "Hz");
        f->scale = 0.0;
        snprintf(z->name, sizeof z->name, "mode%d.damping_ratio", m + 1);
        snprintf(z->unit, sizeof z->unit, "1");
        z->scale = 1.0;
    }
    return TS_OK;
}

/* ---- simulate ---------------------------------------------------------- */

/* Rounding noise of a simulated value: this many eps per sqrt(step). */
#define SIM_ROUND_EPS 16.0
/* Integrator noise of a simulated value in a links sweep: this many
 * times rel_tol of the value's scale. */
#define SIM_TOL_NOISE 10.0

typedef struct sim_ctx {
    ts_system *sys;
    ts_equilibrium_opts eo;
    ts_sim_opts so;
    const ts_excitation *ex;
    char output[2 * TS_NAME_MAX + 16];
    double transient;
    int exc_index;
    double length;
} sim_ctx;

static void sim_ctx_free(void *p)
{
    sim_ctx *x = p;
    ts_system_free(x->sys);
    free(x);
}

static double wrap_deg(double d)
{
    d = fmod(d, 360.0);
    if (d > 180.0)
        d -= 360.0;
    if (d <= -180.0)
        d += 360.0;
    return d;
}

/* Fit the output and the excitation over the window of history h. */
static int sim_fit(const sim_ctx *x, const ts_history *h,
                   const ts_output *out, double eq_value, double values[],
                   ts_err *err)
{
    const ts_signal *sg = ts_excitation_signal(x->ex, x->exc_index);
    int first = 0;
    while (first < h->nsamples && h->t[first] < x->transient - 1e-12)
        first++;
    int n = h->nsamples - first;
    if (n < 3)
        return ts_fail(err, TS_EINVAL,
                       "simulate: %d samples after the transient (%g s)", n,
                       x->transient);
    double *buf = malloc(3 * (size_t)n * sizeof(double));
    if (!buf)
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    double *t = buf, *xo = buf + n, *xe = buf + 2 * n;
    size_t stride = 3 * (size_t)h->nnodes;
    for (int i = 0; i < n; i++) {
        size_t s = (size_t)(first + i);
        t[i] = h->t[s];
        xo[i] = h->positions[stride * s + 3 * (size_t)out->node + out->comp];
        xe[i] = h->input[TS_NINPUT * s + sg->axis];
    }
    double c, a, ph, ce, ae, phe;
    int rc = ts_compare_fit_sinusoid(t, xe, n, sg->frequency, &ce, &ae, &phe,
                                     err);
    if (rc == TS_OK)
        rc = ts_compare_fit_sinusoid(t, xo, n, sg->frequency, &c, &a, &ph,
                                     err);
    if (rc == TS_OK) {
        values[0] = a / ae;
        values[1] = c - eq_value;
        values[2] = wrap_deg((ph - phe) * 180.0 / M_PI);
    }
    free(buf);
    return rc;
}

static int sim_run(void *ctx, ts_conv_param p, double setting,
                   double values[], double noise[], long *evaluations,
                   ts_trust *trust, ts_err *err)
{
    sim_ctx *x = ctx;
    if (p == TS_CONV_STEP)
        return ts_fail(err, TS_EINVAL,
                       "simulate: there is no linearization step to sweep; "
                       "sweep tolerances or links");
    ts_sim_opts o = x->so;
    if (p == TS_CONV_TOLERANCE) {
        o.abs_tol = x->so.abs_tol * (setting / x->so.rel_tol);
        o.rel_tol = setting;
    }
    ts_system *sys = run_system(x->sys, p, setting, err);
    if (!sys)
        return err && err->code ? err->code : TS_EINVAL;
    ts_output out;
    ts_kernel *k = NULL;
    ts_equilibrium *eq = NULL;
    ts_history *h = NULL;
    ts_sim_stats st;
    memset(&st, 0, sizeof st);
    int rc = ts_response_output_find(sys, x->output, &out, err);
    if (rc == TS_OK) {
        k = ts_kernel_alloc(sys, err);
        eq = k ? ts_equilibrium_alloc(sys, err) : NULL;
        rc = eq ? ts_equilibrium_solve(k, &x->eo, eq, err) : TS_ENOMEM;
        if (eq) {
            *evaluations += eq->evaluations;
            ts_trust eqt;
            ts_trust_init(&eqt);
            ts_health_equilibrium(sys, eq, &eqt);
            ts_trust_merge(trust, "equilibrium: ", &eqt);
        }
        if (rc != TS_OK)
            ts_err_prefix(err, "simulate: the initial equilibrium: ");
    }
    if (rc == TS_OK) {
        h = ts_history_alloc(sys, ts_sim_nsamples(&o), err);
        rc = h ? ts_simulate(k, x->ex, eq->y, &o, h, &st, NULL, err)
               : TS_ENOMEM;
        *evaluations += st.evaluations;
        ts_health_simulation(&o, &st, trust);
    }
    if (rc == TS_OK)
        rc = sim_fit(x, h, &out, eq->positions[3 * out.node + out.comp],
                     values, err);
    if (rc == TS_OK) {
        double eq_noise = EQ_NOISE_FACTOR *
                          fmax(eq->residual, EQ_NOISE_MIN_REL) * x->length;
        double scale[3] = {fabs(values[0]), x->length, 360.0};
        double round = SIM_ROUND_EPS * DBL_EPSILON *
                       sqrt((double)(st.steps + st.rejected + 1));
        for (int v = 0; v < 3; v++) {
            noise[v] = round * scale[v];
            if (p == TS_CONV_LINKS)
                noise[v] += SIM_TOL_NOISE * o.rel_tol * scale[v];
        }
        noise[1] += eq_noise;
    }
    ts_history_free(h);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    if (sys != x->sys)
        ts_system_free(sys);
    return rc;
}

int ts_conv_simulate_analysis(const ts_system *sys,
                              const ts_equilibrium_opts *eo,
                              const ts_sim_opts *so, const ts_excitation *ex,
                              const char *output, double transient,
                              ts_conv_analysis *an, ts_err *err)
{
    memset(an, 0, sizeof *an);
    int idx;
    if (!ex || !ts_excitation_periodic(ex, &idx))
        return ts_fail(err, TS_EINVAL,
                       "simulate: the convergence of an amplitude ratio "
                       "needs a single periodic tow-point excitation (one "
                       "sine or crank on tow.surge, tow.sway or tow.heave)");
    ts_sim_opts o;
    if (so)
        o = *so;
    else
        ts_sim_opts_default(&o);
    int rc = ts_sim_opts_check(&o, err);
    if (rc)
        return rc;
    ts_output out;
    if (!output ||
        (rc = ts_response_output_find(sys, output, &out, err)) != TS_OK)
        return rc ? rc
                  : ts_fail(err, TS_EINVAL, "simulate: no output named");
    if (out.kind != TS_OUT_POSITION)
        return ts_fail(err, TS_EINVAL,
                       "simulate: output '%s' is a tension; the amplitude "
                       "ratio is of a position <node>.x|y|z",
                       output);
    const ts_signal *sg = ts_excitation_signal(ex, idx);
    double period = 1.0 / sg->frequency;
    if (!(transient >= 0) || !(transient < o.t_end))
        return ts_fail(err, TS_EINVAL,
                       "simulate: the transient must be in [0, %g) s (the "
                       "run), got %g s",
                       o.t_end, transient);
    if (o.t_end - transient < period * (1.0 - 1e-9))
        return ts_fail(err, TS_EINVAL,
                       "simulate: %g s are left after the transient, less "
                       "than one period (%g s) of the %g Hz excitation",
                       o.t_end - transient, period, sg->frequency);
    if (o.dt_sample >
        period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD * (1.0 + 1e-9))
        return ts_fail(err, TS_EINVAL,
                       "simulate: the sample interval %g s is too coarse "
                       "for %g Hz; at most %g s (%d samples per period)",
                       o.dt_sample, sg->frequency,
                       period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD,
                       TS_COMPARE_MIN_SAMPLES_PER_PERIOD);
    if ((rc = ts_excitation_check_span(ex, o.t_end, err)))
        return rc;
    sim_ctx *x = calloc(1, sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    x->sys = ts_system_copy(sys, err);
    if (!x->sys) {
        free(x);
        return err && err->code ? err->code : TS_ENOMEM;
    }
    if (eo)
        x->eo = *eo;
    else
        ts_equilibrium_opts_default(&x->eo);
    x->so = o;
    x->ex = ex;
    snprintf(x->output, sizeof x->output, "%s", out.name);
    x->transient = transient;
    x->exc_index = idx;
    x->length = total_length(sys);
    snprintf(an->name, sizeof an->name, "simulate");
    an->ctx = x;
    an->free_ctx = sim_ctx_free;
    an->run = sim_run;
    an->nvalues = 3;
    an->values = calloc(3, sizeof *an->values);
    if (!an->values) {
        ts_conv_analysis_free(an);
        return ts_fail(err, TS_ENOMEM, "convergence: out of memory");
    }
    static const char *const suffix[3] = {"amplitude_ratio", "mean_offset",
                                          "phase_deg"};
    static const char *const unit[3] = {"1", "m", "deg"};
    double scale[3] = {0.0, sg->amplitude, 360.0};
    for (int v = 0; v < 3; v++) {
        ts_conv_value *V = &an->values[v];
        snprintf(V->name, sizeof V->name, "%.70s.%s", out.name, suffix[v]);
        snprintf(V->unit, sizeof V->unit, "%s", unit[v]);
        V->scale = scale[v];
    }
    return TS_OK;
}
