/* sea.c: wave spectra and the sea's heading (towstab/sea.h;
 * doc/seastate.md, section 1; DNV-RP-C205 (2010) 3.5.5).
 *
 * Pierson-Moskowitz in Hs and Tp: with x = w / wp,
 *   S_PM(w) = 5/16 Hs^2 / wp * x^-5 exp(-5/4 x^-4),
 * and int_0^inf x^-5 exp(-5/4 x^-4) dx = 1/5 (substitute u = 5/4 x^-4), so
 * m0 = Hs^2 / 16 exactly. JONSWAP multiplies by gamma^r(x); its integral is
 * Hs^2/16 (1 + 5 J), J = int x^-5 exp(-5/4 x^-4) (gamma^r - 1) dx, which
 * vanishes outside a few sigma of the peak: J is integrated by GSL's QAG
 * (Gauss-Kronrod 61) on [1 - 12 sigma_a, 1] and [1, 1 + 12 sigma_b] (beyond
 * 12 sigma, gamma^r - 1 < ln(10) e^-72) and C = 1 / (1 + 5 J). Moments of
 * a parametric spectrum: QAG on [lo, wp] and [wp, hi] (QAGIU for an
 * infinite hi), or closed form where the shape is PM's. A table is
 * piecewise linear, integrated exactly segment by segment.
 */
#include "towstab/sea.h"

#include <ctype.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "csvtab.h"

/* JONSWAP spectral width parameters (DNV-RP-C205 3.5.5.4). */
#define SIGMA_BELOW 0.07
#define SIGMA_ABOVE 0.09
/* Half-width of the peak enhancement integrated, in sigmas. */
#define PEAK_SIGMAS 12.0
/* Relative accuracy of the quadratures. */
#define QUAD_RTOL 1e-12
/* GSL workspace intervals. */
#define QUAD_LIMIT 200
/* Longest sea description accepted. */
#define SPEC_MAX 1024

struct ts_sea {
    ts_sea_info in;   /* kind, hs, tp, gamma, norm, heading, m0 */
    double wp;        /* peak frequency 2 pi / tp, rad/s */
    int n;
    double *omega, *density; /* [n] table */
    char source[512];
};

static double pm_shape(double x) /* x^-5 exp(-5/4 x^-4), x > 0 */
{
    double x4 = x * x * x * x;
    return exp(-1.25 / x4) / (x4 * x);
}

static double peak_exponent(double x)
{
    double s = x <= 1.0 ? SIGMA_BELOW : SIGMA_ABOVE;
    double d = (x - 1.0) / s;
    return exp(-0.5 * d * d);
}

static double excess(double x, void *p) /* x^-5 e^(..) (gamma^r - 1) */
{
    double lg = *(const double *)p;
    return pm_shape(x) * expm1(lg * peak_exponent(x));
}

static double parametric(const ts_sea *s, double w)
{
    if (!(w > 0))
        return 0.0;
    double x = w / s->wp;
    double v = 5.0 / 16.0 * s->in.hs * s->in.hs / s->wp * pm_shape(x);
    if (s->in.kind == TS_SEA_JONSWAP && s->in.gamma != 1.0)
        v *= s->in.norm * pow(s->in.gamma, peak_exponent(x));
    return v;
}

double ts_sea_density(const ts_sea *s, double w)
{
    if (s->in.kind != TS_SEA_TABLE)
        return parametric(s, w);
    if (!(w >= s->omega[0]) || !(w <= s->omega[s->n - 1]))
        return 0.0;
    int lo = 0, hi = s->n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (s->omega[mid] <= w)
            lo = mid;
        else
            hi = mid;
    }
    double h = s->omega[hi] - s->omega[lo];
    double a = (w - s->omega[lo]) / h;
    return s->density[lo] + a * (s->density[hi] - s->density[lo]);
}

/* QAG of f over [a, b] (b may be INFINITY), to QUAD_RTOL. */
static int quad(gsl_function *f, double a, double b, double *v)
{
    gsl_integration_workspace *w =
        gsl_integration_workspace_alloc(QUAD_LIMIT);
    if (!w)
        return GSL_ENOMEM;
    double abserr;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int st = isinf(b) ? gsl_integration_qagiu(f, a, 0.0, QUAD_RTOL,
                                              QUAD_LIMIT, w, v, &abserr)
                      : gsl_integration_qag(f, a, b, 0.0, QUAD_RTOL,
                                            QUAD_LIMIT, GSL_INTEG_GAUSS61, w,
                                            v, &abserr);
    gsl_set_error_handler(old);
    gsl_integration_workspace_free(w);
    return st;
}

static int jonswap_norm(double gamma, double *norm, ts_err *err)
{
    if (gamma == 1.0) {
        *norm = 1.0;
        return TS_OK;
    }
    double lg = log(gamma), j1 = 0, j2 = 0;
    gsl_function f = {excess, &lg};
    int st = quad(&f, 1.0 - PEAK_SIGMAS * SIGMA_BELOW, 1.0, &j1);
    if (!st)
        st = quad(&f, 1.0, 1.0 + PEAK_SIGMAS * SIGMA_ABOVE, &j2);
    if (st)
        return ts_fail(err, TS_EDOMAIN, "JONSWAP normalisation: the "
                       "quadrature failed for gamma %g (%s)", gamma,
                       gsl_strerror(st));
    *norm = 1.0 / (1.0 + 5.0 * (j1 + j2));
    return TS_OK;
}

static int check_heading(double heading, ts_err *err)
{
    if (!isfinite(heading))
        return ts_fail(err, TS_EINVAL, "sea: heading must be finite, got "
                       "%g rad", heading);
    return TS_OK;
}

ts_sea *ts_sea_jonswap(double hs, double tp, double gamma, double heading,
                       ts_err *err)
{
    if (!(hs > 0) || !(hs <= TS_SEA_HS_MAX)) {
        ts_fail(err, TS_EINVAL, "sea: Hs must be a height > 0 m and at most "
                "%g m (five times the largest measured), got %g m",
                TS_SEA_HS_MAX, hs);
        return NULL;
    }
    if (!(tp >= TS_SEA_TP_MIN) || !(tp <= TS_SEA_TP_MAX)) {
        ts_fail(err, TS_EINVAL, "sea: Tp must be a period from %g s (shorter "
                "waves are capillary ripples) to %g s, got %g s",
                TS_SEA_TP_MIN, TS_SEA_TP_MAX, tp);
        return NULL;
    }
    if (!(gamma >= 1.0) || !(gamma <= TS_SEA_GAMMA_MAX)) {
        ts_fail(err, TS_EINVAL, "sea: gamma must be in [1, %g] (1 is "
                "Pierson-Moskowitz; DNV-RP-C205 gives 1 to 7), got %g",
                TS_SEA_GAMMA_MAX, gamma);
        return NULL;
    }
    if (check_heading(heading, err))
        return NULL;
    ts_sea *s = calloc(1, sizeof *s);
    if (!s) {
        ts_fail(err, TS_ENOMEM, "sea: out of memory");
        return NULL;
    }
    s->in.source = s->source;
    s->in.kind = gamma == 1.0 ? TS_SEA_PM : TS_SEA_JONSWAP;
    s->in.hs = hs;
    s->in.tp = tp;
    s->in.gamma = gamma;
    s->wp = 2.0 * M_PI / tp;
    s->in.heading = heading;
    s->in.m0 = hs * hs / 16.0;
    if (jonswap_norm(gamma, &s->in.norm, err)) {
        free(s);
        return NULL;
    }
    return s;
}

ts_sea *ts_sea_table(int n, const double omega[], const double density[],
                     double heading, ts_err *err)
{
    if (n < 2) {
        ts_fail(err, TS_EINVAL, "sea table: at least 2 samples are needed, "
                "got %d", n);
        return NULL;
    }
    double m0 = 0, smax = -1;
    int imax = 0;
    for (int i = 0; i < n; i++) {
        if (!isfinite(omega[i]) || !(omega[i] >= 0) ||
            !isfinite(density[i]) || !(density[i] >= 0)) {
            ts_fail(err, TS_EINVAL, "sea table: sample %d must have a "
                    "frequency >= 0 rad/s and a density >= 0 m^2 s/rad, got "
                    "%g rad/s, %g m^2 s/rad", i + 1, omega[i], density[i]);
            return NULL;
        }
        if (i > 0 && !(omega[i] > omega[i - 1])) {
            ts_fail(err, TS_EINVAL, "sea table: frequencies must increase; "
                    "sample %d has %g rad/s after %g rad/s", i + 1, omega[i],
                    omega[i - 1]);
            return NULL;
        }
        if (i > 0)
            m0 += 0.5 * (density[i] + density[i - 1]) *
                  (omega[i] - omega[i - 1]);
        if (density[i] > smax) {
            smax = density[i];
            imax = i;
        }
    }
    if (!(m0 > 0)) {
        ts_fail(err, TS_EINVAL, "sea table: the density is zero everywhere");
        return NULL;
    }
    if (!(4.0 * sqrt(m0) <= TS_SEA_HS_MAX)) {
        ts_fail(err, TS_EINVAL, "sea table: its Hs = 4 sqrt(m0) = %g m is "
                "beyond %g m (five times the largest measured)",
                4.0 * sqrt(m0), TS_SEA_HS_MAX);
        return NULL;
    }
    if (check_heading(heading, err))
        return NULL;
    ts_sea *s = calloc(1, sizeof *s);
    if (s) {
        s->omega = malloc((size_t)n * sizeof(double));
        s->density = malloc((size_t)n * sizeof(double));
    }
    if (!s || !s->omega || !s->density) {
        ts_sea_free(s);
        ts_fail(err, TS_ENOMEM, "sea: out of memory");
        return NULL;
    }
    s->in.source = s->source;
    memcpy(s->omega, omega, (size_t)n * sizeof(double));
    memcpy(s->density, density, (size_t)n * sizeof(double));
    s->in.kind = TS_SEA_TABLE;
    s->n = s->in.npoints = n;
    s->in.m0 = m0;
    s->in.hs = 4.0 * sqrt(m0);
    s->in.gamma = NAN;
    s->in.norm = NAN;
    s->wp = omega[imax];
    s->in.tp = omega[imax] > 0 ? 2.0 * M_PI / omega[imax] : INFINITY;
    s->in.heading = heading;
    return s;
}

void ts_sea_free(ts_sea *s)
{
    if (!s)
        return;
    free(s->omega);
    free(s->density);
    free(s);
}

ts_sea *ts_sea_read_csv(const char *path, const ts_units *units,
                        double heading, ts_err *err)
{
    tsi_csv t;
    int rc = tsi_csv_read(path, &t, err);
    if (rc)
        return NULL;
    ts_sea *s = NULL;
    double *w = NULL, *d = NULL;
    if (t.nprops > 0) {
        ts_fail(err, TS_EINVAL, "%s line %d: a spectrum table has no "
                "properties ('%s: ...'); expected the header, e.g. 'omega "
                "[rad/s], S [m^2 s/rad]'", path, t.props[0].line,
                t.props[0].key);
        goto done;
    }
    if (t.ncols != 2) {
        ts_fail(err, TS_EINVAL, "%s line %d: expected two columns, the "
                "frequency and the density (e.g. 'omega [rad/s], S [m^2 "
                "s/rad]' or 'frequency [Hz], S [m^2/Hz]'), got %d", path,
                t.header_line, t.ncols);
        goto done;
    }
    int angular;
    if (!strcmp(t.name[0], "omega") || !strcmp(t.name[0], "w"))
        angular = 1;
    else if (!strcmp(t.name[0], "frequency") || !strcmp(t.name[0], "f"))
        angular = 0;
    else {
        ts_fail(err, TS_EINVAL, "%s line %d, column 1: '%s' is not a "
                "frequency column; expected 'omega [rad/s]' (angular) or "
                "'frequency [Hz]' (cyclic)", path, t.header_line, t.name[0]);
        goto done;
    }
    double fs, ds;
    if (tsi_csv_unit_scale(units, &t, 0, angular ? "rad/s" : "Hz",
                     angular ? "omega [rad/s]" : "frequency [Hz]", &fs, err))
        goto done;
    if (tsi_csv_unit_scale(units, &t, 1, angular ? "m^2*s/rad" : "m^2/Hz",
                     angular ? "S [m^2 s/rad]" : "S [m^2/Hz]", &ds, err)) {
        ts_err_prefix(err, "the density must be per unit of the frequency "
                      "column (%s): ", angular ? "per rad/s" : "per Hz");
        goto done;
    }
    if (!angular) {
        fs *= 2.0 * M_PI;
        ds /= 2.0 * M_PI;
    }
    w = malloc((size_t)t.nrows * sizeof *w);
    d = malloc((size_t)t.nrows * sizeof *d);
    if (!w || !d) {
        ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    for (int i = 0; i < t.nrows; i++) {
        w[i] = fs * t.data[2 * i];
        d[i] = ds * t.data[2 * i + 1];
    }
    s = ts_sea_table(t.nrows, w, d, heading, err);
    if (!s) {
        /* Name the line of a bad sample. */
        int bad = -1;
        for (int i = 0; i < t.nrows && bad < 0; i++)
            if (!(w[i] >= 0) || !(d[i] >= 0) || (i > 0 && !(w[i] > w[i - 1])))
                bad = i;
        ts_err_prefix(err, bad >= 0 ? "%s line %d: " : "%s: ", path,
                      bad >= 0 ? t.line[bad] : 0);
    } else {
        snprintf(s->source, sizeof s->source, "%s", path);
    }
done:
    free(w);
    free(d);
    tsi_csv_free(&t);
    return s;
}

double ts_sea_default_gamma(double hs, double tp)
{
    double r = tp / sqrt(hs);
    if (r <= 3.6)
        return 5.0;
    if (r >= 5.0)
        return 1.0;
    return exp(5.75 - 1.15 * r);
}

ts_sea *ts_sea_parse(const char *spec, const ts_units *units,
                     const char *where, ts_err *err)
{
    enum { K_TYPE, K_HS, K_TP, K_GAMMA, K_HEADING, K_FILE, K_N };
    static const char *const keys[K_N] = {"type", "hs", "tp", "gamma",
                                          "heading", "file"};
    if (!where)
        where = "sea";
    if (!spec || !*spec || strlen(spec) >= SPEC_MAX) {
        ts_fail(err, TS_EINVAL, "%s: expected Hs=..,Tp=..[,gamma=..]"
                "[,heading=..], type=pm,Hs=..,Tp=.. or file=PATH (at most %d "
                "characters)", where, SPEC_MAX - 1);
        return NULL;
    }
    char buf[SPEC_MAX];
    snprintf(buf, sizeof buf, "%s", spec);
    char *val[K_N] = {0};
    char *save = NULL;
    for (char *item = strtok_r(buf, ",", &save); item;
         item = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(item, '=');
        if (!eq) {
            ts_fail(err, TS_EINVAL, "%s: '%.60s' is not key=value; expected "
                    "keys Hs, Tp, gamma, heading, type, file", where,
                   tsi_csv_trim(item));
            return NULL;
        }
        *eq = '\0';
        char *k = tsi_csv_trim(item), *v = tsi_csv_trim(eq + 1);
        int j = 0;
        while (j < K_N && strcasecmp(k, keys[j]))
            j++;
        if (j == K_N) {
            ts_fail(err, TS_EINVAL, "%s: unknown key '%.40s'; expected Hs, "
                    "Tp, gamma, heading, type or file", where, k);
            return NULL;
        }
        if (val[j]) {
            ts_fail(err, TS_EINVAL, "%s: '%s' given twice", where, keys[j]);
            return NULL;
        }
        if (!*v) {
            ts_fail(err, TS_EINVAL, "%s: '%s' has no value", where, k);
            return NULL;
        }
        val[j] = v;
    }
    int rc = TS_OK;
    double heading = TS_SEA_HEADING_DEFAULT;
    char w[160];
    if (val[K_HEADING]) {
        snprintf(w, sizeof w, "%s: heading", where);
        rc = ts_units_parse(units, val[K_HEADING], "rad", w, &heading, err);
        if (rc)
            return NULL;
    }
    int pm = 0;
    if (val[K_TYPE]) {
        if (!strcasecmp(val[K_TYPE], "pm") ||
            !strcasecmp(val[K_TYPE], "pierson-moskowitz"))
            pm = 1;
        else if (strcasecmp(val[K_TYPE], "jonswap")) {
            ts_fail(err, TS_EINVAL, "%s: unknown type '%.40s'; expected "
                    "jonswap or pm (a table is file=PATH)", where,
                    val[K_TYPE]);
            return NULL;
        }
    }
    if (val[K_FILE]) {
        if (val[K_TYPE] || val[K_HS] || val[K_TP] || val[K_GAMMA]) {
            ts_fail(err, TS_EINVAL, "%s: file= gives the whole spectrum; "
                    "leave out type, Hs, Tp and gamma", where);
            return NULL;
        }
        ts_sea *s = ts_sea_read_csv(val[K_FILE], units, heading, err);
        if (!s)
            ts_err_prefix(err, "%s: ", where);
        return s;
    }
    if (!val[K_HS] || !val[K_TP]) {
        ts_fail(err, TS_EINVAL, "%s: a parametric sea needs Hs and Tp, e.g. "
                "Hs=4m,Tp=10s", where);
        return NULL;
    }
    if (pm && val[K_GAMMA]) {
        ts_fail(err, TS_EINVAL, "%s: type pm has no gamma (it is JONSWAP "
                "with gamma = 1)", where);
        return NULL;
    }
    double hs, tp, gamma = NAN;
    snprintf(w, sizeof w, "%s: Hs", where);
    rc = ts_units_parse(units, val[K_HS], "m", w, &hs, err);
    if (!rc) {
        snprintf(w, sizeof w, "%s: Tp", where);
        rc = ts_units_parse(units, val[K_TP], "s", w, &tp, err);
    }
    if (!rc && val[K_GAMMA]) {
        snprintf(w, sizeof w, "%s: gamma", where);
        rc = ts_units_parse(units, val[K_GAMMA], "1", w, &gamma, err);
    }
    if (rc)
        return NULL;
    if (pm)
        gamma = 1.0;
    else if (!val[K_GAMMA] && hs > 0 && tp > 0)
        gamma = ts_sea_default_gamma(hs, tp);
    ts_sea *s = ts_sea_jonswap(hs, tp, gamma, heading, err);
    if (!s) {
        /* "WHERE: Tp must be ...", not "WHERE: sea: Tp ...". */
        if (err && !strncmp(err->msg, "sea: ", 5))
            memmove(err->msg, err->msg + 5, strlen(err->msg + 5) + 1);
        ts_err_prefix(err, "%s: ", where);
    }
    return s;
}

void ts_sea_get_info(const ts_sea *s, ts_sea_info *info)
{
    *info = s->in;
}

typedef struct moment_ctx {
    const ts_sea *s;
    int k;
} moment_ctx;

static double moment_integrand(double w, void *p)
{
    const moment_ctx *c = p;
    double v = parametric(c->s, w);
    return c->k == 0 ? v : c->k == 1 ? w * v : w * w * v;
}

/* int_a^b w^k (alpha + beta w) dw */
static double poly_moment(int k, double alpha, double beta, double a,
                          double b)
{
    double k1 = k + 1.0, k2 = k + 2.0;
    return alpha * (pow(b, k1) - pow(a, k1)) / k1 +
           beta * (pow(b, k2) - pow(a, k2)) / k2;
}

int ts_sea_moment(const ts_sea *s, int k, double lo, double hi,
                  double *value, ts_err *err)
{
    *value = NAN;
    if (k < 0 || k > 2)
        return ts_fail(err, TS_EINVAL, "sea moment: order must be 0, 1 or "
                       "2, got %d", k);
    if (!(lo >= 0) || !(hi > lo) || isnan(hi) || isinf(lo))
        return ts_fail(err, TS_EINVAL, "sea moment: need 0 <= lo < hi, got "
                       "[%g, %g] rad/s", lo, hi);
    if (s->in.kind == TS_SEA_TABLE) {
        double sum = 0;
        for (int i = 0; i + 1 < s->n; i++) {
            double w0 = s->omega[i], w1 = s->omega[i + 1];
            double a = fmax(w0, lo), b = fmin(w1, hi);
            if (!(b > a))
                continue;
            double beta = (s->density[i + 1] - s->density[i]) / (w1 - w0);
            double alpha = s->density[i] - beta * w0;
            sum += poly_moment(k, alpha, beta, a, b);
        }
        *value = sum;
        return TS_OK;
    }
    /* Below 0.05 wp the density is below e^-(5/4 20^4) of its peak. */
    double a = fmax(lo, 0.05 * s->wp);
    if (!(hi > a)) {
        *value = 0.0;
        return TS_OK;
    }
    moment_ctx c = {s, k};
    gsl_function f = {moment_integrand, &c};
    double v1 = 0, v2 = 0;
    int st = 0;
    if (a < s->wp)
        st = quad(&f, a, fmin(hi, s->wp), &v1);
    if (!st && hi > s->wp)
        st = quad(&f, fmax(a, s->wp), hi, &v2);
    if (st)
        return ts_fail(err, TS_EDOMAIN, "sea moment %d on [%g, %g] rad/s: "
                       "the quadrature failed (%s)", k, lo, hi,
                       gsl_strerror(st));
    *value = v1 + v2;
    return TS_OK;
}

void ts_sea_band(const ts_sea *s, double tail, double *lo, double *hi)
{
    if (s->in.kind == TS_SEA_TABLE) {
        /* A band starts above 0 (analyses work in ln w): the first
         * segment of a table that starts at 0 is left outside. */
        *lo = s->omega[0] > 0 ? s->omega[0] : s->omega[1];
        *hi = s->omega[s->n - 1];
        return;
    }
    /* Fraction of m0 below w: C exp(-5/4 (wp/w)^4) (PM's distribution,
     * scaled); above: C (1 - exp(-5/4 (wp/w)^4)). Half the tail each. */
    double c = s->in.kind == TS_SEA_JONSWAP ? s->in.norm : 1.0;
    double q = 0.5 * tail / c;
    *lo = s->wp * pow(1.25 / -log(q), 0.25);
    *hi = s->wp * pow(1.25 / -log1p(-q), 0.25);
}

double ts_sea_encounter(double omega, double speed, double heading,
                        double gravity)
{
    return omega - omega * omega * speed * cos(heading) / gravity;
}

void ts_sea_describe(const ts_sea *s, char *buf, size_t size)
{
    double hd = s->in.heading * 180.0 / M_PI;
    switch (s->in.kind) {
    case TS_SEA_PM:
        snprintf(buf, size, "Pierson-Moskowitz Hs %.6g m, Tp %.6g s, "
                 "heading %.6g deg", s->in.hs, s->in.tp, hd);
        return;
    case TS_SEA_JONSWAP:
        snprintf(buf, size, "JONSWAP Hs %.6g m, Tp %.6g s, gamma %.6g "
                 "(normalisation %.6g), heading %.6g deg", s->in.hs, s->in.tp,
                 s->in.gamma, s->in.norm, hd);
        return;
    case TS_SEA_TABLE:
        snprintf(buf, size, "table %s (%d samples, %.6g to %.6g rad/s): Hs "
                 "%.6g m, peak at %.6g s, heading %.6g deg",
                 s->source[0] ? s->source : "(given)", s->n, s->omega[0],
                 s->omega[s->n - 1], s->in.hs, s->in.tp, hd);
        return;
    }
}
