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
 * The analyses swept are the pipelines of towstab/analysis.h
 * (ts_analysis_sweep): they rerun an equilibrium, a mode analysis or a
 * simulation at each setting and report values that keep their meaning
 * across resolutions: bodies and free ends (not node indices), the top
 * tension, the k-th lowest oscillatory mode, and for a simulation the
 * amplitude ratio, mean offset and phase of a named output under a
 * periodic excitation (Kamman & Nguyen 1990, example 4).
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


/* The finest two observed orders agree (asymptotic range) when they
 * differ by at most this fraction of the finer one. */
#define ORDER_AGREE 0.2
/* Differences below the two rows' noise plus this many ulps of the values
 * are not resolved. */
#define ROUND_ULPS 8.0
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
        if (!(v >= 1 && v <= TS_MAX_LINKS) || v != floor(v))
            return ts_fail(err, TS_EINVAL,
                           "%s: links must be whole numbers in [1, %d], "
                           "got %g",
                           what, TS_MAX_LINKS, v);
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
    r->timed_runs = 1;
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

/* The median wall time of a short run: the first took `first` s; the
 * run is repeated (its results dropped) until TS_CONV_TIMING_REPEATS runs
 * or the repeats took TS_CONV_TIMING_MIN s; *timed is the count. A
 * repeat that fails or cannot get memory ends the repeats. */
static double repeat_timing(const ts_conv_analysis *an, ts_conv_param p,
                            double setting, int nvalues, double first,
                            int *timed)
{
    double t[TS_CONV_TIMING_REPEATS];
    int n = 0;
    t[n++] = first;
    double *scratch = malloc(2 * (size_t)(nvalues > 0 ? nvalues : 1) *
                             sizeof *scratch);
    double spent = 0;
    while (scratch && n < TS_CONV_TIMING_REPEATS &&
           spent < TS_CONV_TIMING_MIN) {
        ts_trust tr;
        ts_trust_init(&tr);
        ts_err e = {0};
        long ev = 0;
        double t0 = wall_now();
        int st = an->run(an->ctx, p, setting, scratch, scratch + nvalues,
                         &ev, &tr, &e);
        double w = wall_now() - t0;
        if (st != TS_OK)
            break;
        t[n++] = w;
        spent += w;
    }
    free(scratch);
    /* The median: insertion sort of at most TS_CONV_TIMING_REPEATS. */
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && t[j] < t[j - 1]; j--) {
            double x = t[j];
            t[j] = t[j - 1];
            t[j - 1] = x;
        }
    *timed = n;
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
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
        int timed = 1;
        if (st == TS_OK && wall < TS_CONV_TIMING_MIN)
            wall = repeat_timing(an, c->param, settings[i], c->nvalues,
                                 wall, &timed);
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
        if (rc == TS_OK)
            c->rows[c->nrows - 1].timed_runs = timed;
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
    ts_system *s = ts_system_copy(sys, err);
    if (s && ts_system_set_links(s, links, err) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}
