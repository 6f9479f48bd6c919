/* rao.c: ship motion RAOs, their interpolation and the tow point's motion
 * (towstab/rao.h; doc/seastate.md, section 2).
 *
 * Storage: amplitude and phase of each degree of freedom at each heading
 * and frequency, amp[(dof nh + ih) nf + k], in M's axes with phases as
 * leads; the phases are unwrapped along frequency once (ts_rao_finish), so
 * that linear interpolation of the phase follows the shortest way between
 * neighbouring rows. Evaluation: amplitude and phase interpolated in
 * frequency by Steffen's monotone cubic (GSL gsl_interp_steffen: C1, no
 * overshoot between rows, so an amplitude stays >= 0 and the spectral
 * integrands are smooth enough for Simpson's rule to converge at third
 * order; linear for a two-row table) at the two headings around the one
 * asked for, then linear in heading (phase difference wrapped into
 * (-pi, pi]). Interpolators are evaluated without an accelerator, so the
 * table is read-only after ts_rao_finish. The tow point's translation is
 * T = xi + theta x r, complex.
 */
#include "towstab/rao.h"

#include <ctype.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_interp.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csvtab.h"

struct ts_rao {
    int nh, nf;
    double *heading;   /* [nh] rad, increasing; a single NaN: any */
    double *omega;     /* [nf] rad/s, increasing */
    double *amp;       /* [TS_NDOF nh nf] */
    double *phase;     /* [TS_NDOF nh nf] rad, lead; unwrapped along k */
    int given[TS_NDOF];
    gsl_interp **interp; /* [2 TS_NDOF nh]: amplitude, phase of (dof, ih)
                            (ts_rao_finish); NULL before */
};

static const char *const dof_names[TS_NDOF] = {"surge", "sway", "heave",
                                               "roll", "pitch", "yaw"};

const char *ts_rao_dof_name(int dof)
{
    return dof >= 0 && dof < TS_NDOF ? dof_names[dof] : "?";
}

static size_t idx(const ts_rao *r, int dof, int ih, int k)
{
    return ((size_t)dof * (size_t)r->nh + (size_t)ih) * (size_t)r->nf +
           (size_t)k;
}

ts_rao *ts_rao_alloc(int nheading, const double heading[], int nfreq,
                     const double omega[], ts_err *err)
{
    if (nheading < 1 || nfreq < 2) {
        ts_fail(err, TS_EINVAL, "RAO table: at least 1 heading and 2 "
                "frequencies are needed, got %d and %d", nheading, nfreq);
        return NULL;
    }
    int any = nheading == 1 && isnan(heading[0]);
    for (int i = 0; i < nheading && !any; i++) {
        if (!isfinite(heading[i]) || (i > 0 && !(heading[i] > heading[i - 1]))) {
            ts_fail(err, TS_EINVAL, "RAO table: headings must be finite and "
                    "increase; heading %d is %g deg", i + 1,
                    heading[i] * 180 / M_PI);
            return NULL;
        }
    }
    if (!any && !(heading[nheading - 1] - heading[0] < 2 * M_PI)) {
        ts_fail(err, TS_EINVAL, "RAO table: headings must lie within one "
                "turn, got %g to %g deg", heading[0] * 180 / M_PI,
                heading[nheading - 1] * 180 / M_PI);
        return NULL;
    }
    for (int k = 0; k < nfreq; k++)
        if (!isfinite(omega[k]) || !(omega[k] > 0) ||
            (k > 0 && !(omega[k] > omega[k - 1]))) {
            ts_fail(err, TS_EINVAL, "RAO table: wave frequencies must be > 0 "
                    "and increase; frequency %d is %g rad/s", k + 1,
                    omega[k]);
            return NULL;
        }
    ts_rao *r = calloc(1, sizeof *r);
    size_t n = (size_t)TS_NDOF * (size_t)nheading * (size_t)nfreq;
    if (r) {
        r->nh = nheading;
        r->nf = nfreq;
        r->heading = malloc((size_t)nheading * sizeof(double));
        r->omega = malloc((size_t)nfreq * sizeof(double));
        r->amp = calloc(n, sizeof(double));
        r->phase = calloc(n, sizeof(double));
    }
    if (!r || !r->heading || !r->omega || !r->amp || !r->phase) {
        ts_rao_free(r);
        ts_fail(err, TS_ENOMEM, "RAO table: out of memory");
        return NULL;
    }
    memcpy(r->heading, heading, (size_t)nheading * sizeof(double));
    memcpy(r->omega, omega, (size_t)nfreq * sizeof(double));
    return r;
}

static void free_interp(ts_rao *r)
{
    if (!r->interp)
        return;
    for (int i = 0; i < 2 * TS_NDOF * r->nh; i++)
        gsl_interp_free(r->interp[i]);
    free(r->interp);
    r->interp = NULL;
}

void ts_rao_free(ts_rao *r)
{
    if (!r)
        return;
    free_interp(r);
    free(r->heading);
    free(r->omega);
    free(r->amp);
    free(r->phase);
    free(r);
}

int ts_rao_set(ts_rao *r, int dof, int ih, int k, double amplitude,
               double phase, ts_err *err)
{
    if (dof < 0 || dof >= TS_NDOF || ih < 0 || ih >= r->nh || k < 0 ||
        k >= r->nf)
        return ts_fail(err, TS_EINVAL, "RAO table: index out of range (dof "
                       "%d, heading %d, frequency %d)", dof, ih, k);
    if (!(amplitude >= 0) || !isfinite(amplitude) || !isfinite(phase))
        return ts_fail(err, TS_EINVAL, "RAO %s at %g rad/s: amplitude must "
                       "be finite and >= 0 and phase finite, got %g, %g rad",
                       dof_names[dof], r->omega[k], amplitude, phase);
    r->amp[idx(r, dof, ih, k)] = amplitude;
    r->phase[idx(r, dof, ih, k)] = phase;
    r->given[dof] = 1;
    free_interp(r); /* stale until ts_rao_finish */
    return TS_OK;
}

/* x wrapped into (-pi, pi]. */
static double wrap(double x)
{
    double y = remainder(x, 2 * M_PI);
    return y <= -M_PI ? y + 2 * M_PI : y;
}

int ts_rao_finish(ts_rao *r, ts_err *err)
{
    for (int d = 0; d < TS_NDOF; d++)
        for (int ih = 0; ih < r->nh; ih++) {
            double *p = r->phase + idx(r, d, ih, 0);
            p[0] = wrap(p[0]);
            for (int k = 1; k < r->nf; k++)
                p[k] = p[k - 1] + wrap(p[k] - p[k - 1]);
        }
    free_interp(r);
    int n = 2 * TS_NDOF * r->nh, rc = TS_OK;
    r->interp = calloc((size_t)n, sizeof *r->interp);
    if (!r->interp)
        return ts_fail(err, TS_ENOMEM, "RAO table: out of memory");
    const gsl_interp_type *type =
        r->nf >= 3 ? gsl_interp_steffen : gsl_interp_linear;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    for (int d = 0; d < TS_NDOF && !rc; d++)
        for (int ih = 0; ih < r->nh && !rc; ih++)
            for (int q = 0; q < 2 && !rc; q++) {
                gsl_interp *it = gsl_interp_alloc(type, (size_t)r->nf);
                const double *y = (q ? r->phase : r->amp) + idx(r, d, ih, 0);
                int st = it ? gsl_interp_init(it, r->omega, y, (size_t)r->nf)
                            : GSL_ENOMEM;
                r->interp[(d * r->nh + ih) * 2 + q] = it;
                if (st)
                    rc = ts_fail(err, st == GSL_ENOMEM ? TS_ENOMEM
                                                       : TS_EINVAL,
                                 "RAO table: interpolation failed (%s)",
                                 gsl_strerror(st));
            }
    gsl_set_error_handler(old);
    if (rc)
        free_interp(r);
    return rc;
}

void ts_rao_range(const ts_rao *r, double *lo, double *hi)
{
    *lo = r->omega[0];
    *hi = r->omega[r->nf - 1];
}

int ts_rao_headings(const ts_rao *r, double *heading, int max)
{
    for (int i = 0; heading && i < r->nh && i < max; i++)
        heading[i] = r->heading[i];
    return r->nh;
}

int ts_rao_has_dof(const ts_rao *r, int dof)
{
    return dof >= 0 && dof < TS_NDOF && r->given[dof];
}

/* Heading bracket: ih and weight a (result = (1-a) [ih] + a [ih+1]);
 * TS_EDOMAIN outside. */
static int heading_bracket(const ts_rao *r, double heading, int *ih,
                           double *a, ts_err *err)
{
    *ih = 0;
    *a = 0.0;
    if (r->nh == 1 && isnan(r->heading[0]))
        return TS_OK;
    if (!isfinite(heading))
        return ts_fail(err, TS_EINVAL, "RAO: heading must be finite");
    double h0 = r->heading[0], h1 = r->heading[r->nh - 1];
    /* The turn of `heading` nearest above h0 - tol. */
    double h = heading - 2 * M_PI * floor((heading - h0 + TS_RAO_HEADING_TOL) /
                                          (2 * M_PI));
    if (h <= h1 + TS_RAO_HEADING_TOL) {
        for (int i = 0; i < r->nh; i++)
            if (fabs(h - r->heading[i]) <= TS_RAO_HEADING_TOL) {
                *ih = i;
                return TS_OK;
            }
        int i = 0;
        while (i + 2 < r->nh && r->heading[i + 1] <= h)
            i++;
        *ih = i;
        *a = (h - r->heading[i]) / (r->heading[i + 1] - r->heading[i]);
        return TS_OK;
    }
    char list[256] = "";
    for (int i = 0; i < r->nh; i++) {
        size_t n = strlen(list);
        if (n + 24 >= sizeof list) {
            strncat(list, ", ...", sizeof list - n - 1);
            break;
        }
        snprintf(list + n, sizeof list - n, "%s%g", i ? ", " : "",
                 r->heading[i] * 180 / M_PI);
    }
    return ts_fail(err, TS_EDOMAIN, "heading %g deg is not covered by the "
                   "RAO table (headings %s deg); RAOs are not extrapolated: "
                   "tabulate it (a ship symmetric about its centreline has "
                   "at 360 - beta the RAOs of beta with sway, roll and yaw "
                   "reversed)", heading * 180 / M_PI, list);
}

int ts_rao_check_heading(const ts_rao *r, double heading, ts_err *err)
{
    int ih;
    double a;
    return heading_bracket(r, heading, &ih, &a, err);
}

int ts_rao_eval(const ts_rao *r, double heading, double omega,
                double re[TS_NDOF], double im[TS_NDOF], ts_err *err)
{
    int ih;
    double ah;
    if (!r->interp)
        return ts_fail(err, TS_EINVAL, "RAO table: call ts_rao_finish "
                       "after setting it");
    int rc = heading_bracket(r, heading, &ih, &ah, err);
    if (rc)
        return rc;
    double lo = r->omega[0], hi = r->omega[r->nf - 1];
    if (!(omega >= lo * (1 - 1e-12)) || !(omega <= hi * (1 + 1e-12)))
        return ts_fail(err, TS_EDOMAIN, "wave frequency %g rad/s is outside "
                       "the RAO table (%g to %g rad/s); RAOs are not "
                       "extrapolated", omega, lo, hi);
    double w = fmin(fmax(omega, lo), hi);
    int nh = ah > 0 ? 2 : 1;
    for (int d = 0; d < TS_NDOF; d++) {
        double amp[2], ph[2];
        for (int j = 0; j < nh; j++) {
            gsl_interp *const *it =
                r->interp + (d * r->nh + ih + j) * 2;
            const double *a = r->amp + idx(r, d, ih + j, 0);
            const double *p = r->phase + idx(r, d, ih + j, 0);
            amp[j] = gsl_interp_eval(it[0], r->omega, a, w, NULL);
            ph[j] = gsl_interp_eval(it[1], r->omega, p, w, NULL);
        }
        double A = amp[0], P = ph[0];
        if (nh == 2) {
            A = (1 - ah) * amp[0] + ah * amp[1];
            P = ph[0] + ah * wrap(ph[1] - ph[0]);
        }
        re[d] = A * cos(P);
        im[d] = A * sin(P);
    }
    return TS_OK;
}

int ts_rao_tow_point(const ts_rao *r, double heading, double omega,
                     const double lever[3], double re[3], double im[3],
                     ts_err *err)
{
    double xr[TS_NDOF], xi[TS_NDOF];
    int rc = ts_rao_eval(r, heading, omega, xr, xi, err);
    if (rc)
        return rc;
    const double *p = lever;
    /* T = xi + theta x r for the real and the imaginary parts. */
    const double *v[2] = {xr, xi};
    double *out[2] = {re, im};
    for (int c = 0; c < 2; c++) {
        const double *x = v[c];
        out[c][0] = x[0] + x[4] * p[2] - x[5] * p[1];
        out[c][1] = x[1] + x[5] * p[0] - x[3] * p[2];
        out[c][2] = x[2] + x[3] * p[1] - x[4] * p[0];
    }
    return TS_OK;
}

/* ------------------------------------------------------------------ */
/* CSV                                                                  */

/* "heave_amp", "Heave  amplitude" -> "heave amp"; returns the dof and
 * whether it is the phase (*phase), or -1. */
static int dof_column(const char *name, int *phase)
{
    char buf[TSI_CSV_NAME_MAX];
    size_t n = 0;
    for (const char *p = name; *p && n + 1 < sizeof buf; p++) {
        char c = *p == '_' ? ' ' : *p;
        if (c == ' ' && (n == 0 || buf[n - 1] == ' '))
            continue;
        buf[n++] = c;
    }
    buf[n] = '\0';
    char *sp = strchr(buf, ' ');
    if (!sp)
        return -1;
    *sp = '\0';
    const char *what = sp + 1;
    for (int d = 0; d < TS_NDOF; d++)
        if (!strcmp(buf, dof_names[d])) {
            if (!strcmp(what, "amp") || !strcmp(what, "amplitude")) {
                *phase = 0;
                return d;
            }
            if (!strcmp(what, "phase")) {
                *phase = 1;
                return d;
            }
        }
    return -1;
}

typedef struct row_key {
    double heading, omega;
    int row;
} row_key;

static int cmp_key(const void *a, const void *b)
{
    const row_key *x = a, *y = b;
    if (x->heading != y->heading)
        return x->heading < y->heading ? -1 : 1;
    return (x->omega > y->omega) - (x->omega < y->omega);
}

ts_rao *ts_rao_read_csv(const char *path, const ts_units *units, ts_err *err)
{
    tsi_csv t;
    if (tsi_csv_read(path, &t, err))
        return NULL;
    ts_rao *r = NULL;
    row_key *keys = NULL;
    double *hs = NULL, *ws = NULL;
    /* Properties: both needed, no others. */
    static const char *const axes_words[2] = {"z-down", "z-up"};
    static const char *const phase_words[2] = {"lead", "lag"};
    int zup, lag;
    for (int i = 0; i < t.nprops; i++)
        if (strcmp(t.props[i].key, "axes") && strcmp(t.props[i].key, "phase")) {
            ts_fail(err, TS_EINVAL, "%s line %d: unknown property '%s'; "
                    "expected axes and phase", path, t.props[i].line,
                    t.props[i].key);
            goto done;
        }
    if (tsi_csv_choice(&t, "axes", axes_words, 2, "z-down: x forward, y "
                       "starboard, z down; z-up: x forward, y port, z up",
                       &zup, err) ||
        tsi_csv_choice(&t, "phase", phase_words, 2, "of the motion over the "
                       "wave crest at the reference point", &lag, err))
        goto done;
    if (zup < 0 || lag < 0) {
        ts_fail(err, TS_EINVAL, "%s: the lines 'axes: z-down|z-up' and "
                "'phase: lead|lag' must come before the header: RAO tables "
                "differ in both, and a guess would reverse motions", path);
        goto done;
    }
    /* Columns. */
    int cf = -1, ch = -1, fkind = 0; /* 0 Hz, 1 rad/s, 2 period */
    int camp[TS_NDOF], cph[TS_NDOF];
    for (int d = 0; d < TS_NDOF; d++)
        camp[d] = cph[d] = -1;
    for (int j = 0; j < t.ncols; j++) {
        const char *nm = t.name[j];
        int ph, d;
        if (!strcmp(nm, "frequency") || !strcmp(nm, "omega") ||
            !strcmp(nm, "period")) {
            if (cf >= 0) {
                ts_fail(err, TS_EINVAL, "%s line %d: give one of frequency, "
                        "omega and period", path, t.header_line);
                goto done;
            }
            cf = j;
            fkind = nm[0] == 'f' ? 0 : nm[0] == 'o' ? 1 : 2;
        } else if (!strcmp(nm, "heading")) {
            ch = j;
        } else if ((d = dof_column(nm, &ph)) >= 0) {
            if (ph)
                cph[d] = j;
            else
                camp[d] = j;
        } else {
            ts_fail(err, TS_EINVAL, "%s line %d, column %d: unknown column "
                    "'%s'; expected frequency, omega or period, heading, and "
                    "'<dof> amp', '<dof> phase' for dof surge, sway, heave, "
                    "roll, pitch, yaw", path, t.header_line, j + 1, nm);
            goto done;
        }
    }
    if (cf < 0) {
        ts_fail(err, TS_EINVAL, "%s line %d: no frequency column (frequency "
                "[Hz], omega [rad/s] or period [s])", path, t.header_line);
        goto done;
    }
    int ndof = 0;
    for (int d = 0; d < TS_NDOF; d++) {
        if ((camp[d] < 0) != (cph[d] < 0)) {
            ts_fail(err, TS_EINVAL, "%s line %d: %s has an %s column but no "
                    "%s column", path, t.header_line, dof_names[d],
                    camp[d] >= 0 ? "amp" : "phase",
                    camp[d] >= 0 ? "phase" : "amp");
            goto done;
        }
        ndof += camp[d] >= 0;
    }
    if (ndof == 0) {
        ts_fail(err, TS_EINVAL, "%s line %d: no RAO columns ('<dof> amp "
                "[unit]', '<dof> phase [unit]')", path, t.header_line);
        goto done;
    }
    /* Units. */
    double fscale, hscale = 1, ascale[TS_NDOF], pscale[TS_NDOF];
    static const char *const fsi[3] = {"Hz", "rad/s", "s"};
    static const char *const fex[3] = {"frequency [Hz]", "omega [rad/s]",
                                       "period [s]"};
    if (tsi_csv_unit_scale(units, &t, cf, fsi[fkind], fex[fkind], &fscale, err))
        goto done;
    if (ch >= 0 &&
        tsi_csv_unit_scale(units, &t, ch, "rad", "heading [deg]", &hscale, err))
        goto done;
    for (int d = 0; d < TS_NDOF; d++) {
        if (camp[d] < 0)
            continue;
        char ex[64];
        snprintf(ex, sizeof ex, "%s amp [%s]", dof_names[d],
                 d < 3 ? "m/m" : "deg/m");
        if (tsi_csv_unit_scale(units, &t, camp[d], d < 3 ? "1" : "rad/m", ex,
                       &ascale[d], err))
            goto done;
        snprintf(ex, sizeof ex, "%s phase [deg]", dof_names[d]);
        if (tsi_csv_unit_scale(units, &t, cph[d], "rad", ex, &pscale[d], err))
            goto done;
    }
    /* Rows, sorted by heading and frequency. */
    keys = malloc((size_t)t.nrows * sizeof *keys);
    hs = malloc((size_t)t.nrows * sizeof *hs);
    ws = malloc((size_t)t.nrows * sizeof *ws);
    if (!keys || !hs || !ws) {
        ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    for (int i = 0; i < t.nrows; i++) {
        const double *row = t.data + (size_t)i * t.ncols;
        double f = row[cf] * fscale;
        double w = fkind == 0 ? 2 * M_PI * f : fkind == 1 ? f : 2 * M_PI / f;
        if (!(f > 0) || !isfinite(w)) {
            ts_fail(err, TS_EINVAL, "%s line %d: the %s must be > 0, got %g",
                    path, t.line[i], t.name[cf], row[cf]);
            goto done;
        }
        keys[i].omega = w;
        keys[i].heading = ch >= 0 ? row[ch] * hscale : 0.0;
        keys[i].row = i;
    }
    qsort(keys, (size_t)t.nrows, sizeof *keys, cmp_key);
    int nh = 1;
    for (int i = 1; i < t.nrows; i++)
        nh += keys[i].heading != keys[i - 1].heading;
    int nf = t.nrows / nh;
    for (int i = 0, h = 0; i < t.nrows; h++) {
        int j = i;
        while (j < t.nrows && keys[j].heading == keys[i].heading)
            j++;
        if (j - i != nf || nf * nh != t.nrows) {
            ts_fail(err, TS_EINVAL, "%s: heading %g deg has %d rows, heading "
                    "%g deg has %d: every heading must list the same "
                    "frequencies", path, keys[0].heading * 180 / M_PI,
                    t.nrows / nh, keys[i].heading * 180 / M_PI, j - i);
            goto done;
        }
        hs[h] = keys[i].heading;
        for (int k = 0; k < nf; k++) {
            const row_key *q = &keys[i + k];
            if (h == 0)
                ws[k] = q->omega;
            else if (fabs(q->omega - ws[k]) > 1e-9 * ws[k]) {
                ts_fail(err, TS_EINVAL, "%s line %d: heading %g deg lists "
                        "%g rad/s where the first heading lists %g rad/s: "
                        "every heading must list the same frequencies",
                        path, t.line[q->row], q->heading * 180 / M_PI,
                        q->omega, ws[k]);
                goto done;
            }
            if (k > 0 && !(q->omega > keys[i + k - 1].omega)) {
                char at[64] = "";
                if (ch >= 0)
                    snprintf(at, sizeof at, " at heading %g deg",
                             q->heading * 180 / M_PI);
                ts_fail(err, TS_EINVAL, "%s line %d: frequency %g rad/s "
                        "appears twice%s", path, t.line[q->row], q->omega,
                        at);
                goto done;
            }
        }
        i = j;
    }
    if (nf < 2) {
        ts_fail(err, TS_EINVAL, "%s: at least 2 frequencies per heading are "
                "needed, got %d", path, nf);
        goto done;
    }
    if (ch < 0)
        hs[0] = NAN;
    r = ts_rao_alloc(nh, hs, nf, ws, err);
    if (!r) {
        ts_err_prefix(err, "%s: ", path);
        goto done;
    }
    /* z-up (x forward, y port, z up) to M is a half turn about x: sway,
     * heave, pitch and yaw change sign. */
    static const int reversed[TS_NDOF] = {0, 1, 1, 0, 1, 1};
    for (int i = 0; i < t.nrows; i++) {
        const double *row = t.data + (size_t)keys[i].row * t.ncols;
        int ih = i / nf, k = i % nf;
        for (int d = 0; d < TS_NDOF; d++) {
            if (camp[d] < 0)
                continue;
            double a = row[camp[d]] * ascale[d], p = row[cph[d]] * pscale[d];
            if (!(a >= 0)) {
                ts_fail(err, TS_EINVAL, "%s line %d, column %d (%s): an "
                        "amplitude must be >= 0 (a negative one is a phase "
                        "of 180 deg), got %g", path, t.line[keys[i].row],
                        camp[d] + 1, t.name[camp[d]], row[camp[d]]);
                ts_rao_free(r);
                r = NULL;
                goto done;
            }
            if (lag)
                p = -p;
            if (zup && reversed[d])
                p += M_PI;
            if (ts_rao_set(r, d, ih, k, a, p, err)) {
                ts_err_prefix(err, "%s line %d: ", path,
                              t.line[keys[i].row]);
                ts_rao_free(r);
                r = NULL;
                goto done;
            }
        }
    }
    if (ts_rao_finish(r, err)) {
        ts_rao_free(r);
        r = NULL;
    }
done:
    free(keys);
    free(hs);
    free(ws);
    tsi_csv_free(&t);
    return r;
}
