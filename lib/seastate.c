/* seastate.c: spectral and time-domain response to the ship's motion in an
 * irregular sea (towstab/seastate.h; doc/seastate.md, sections 3 and 4).
 *
 * Spectral: on a uniform grid of wave frequencies, the sea's density, the
 * tow point's transfer T_j (ts_rao_tow_point) and the linear model's gains
 * H_j at the encounter frequencies (ts_response_compute, one call per
 * driven input) give G = sum_j H_j T_j and S_out = |G|^2 S. The moments are
 * Simpson sums on the grid and on its every second and fourth point. The
 * integrands are smooth but for a few jumps in their second derivative
 * (the RAO table's rows, the JONSWAP peak), and their peaks meet the grid
 * differently at each level, so the convergence is irregular: the error
 * is the full difference of the two finest sums, unless the three show a
 * steady order in [2, 8] (ts_conv_observed_order), when it is the
 * Richardson error at that order (capped at Simpson's 4). The band error is the wave moment outside the band times the
 * edge values of |G|^2 (and w_e^2).
 *
 * Realisation: GSL's MT19937 seeded with the seed draws, for each bin k in
 * order, first the frequency's place in the bin and then the phase; the
 * components go to ts_excitation_add_sum.
 *
 * Record statistics: the biased autocovariance R_k = (1/n) sum d_i d_(i+k)
 * by GSL's radix-2 FFT of the record padded with zeros to a power of two
 * >= 2n (no wrap-around), then Sokal's automatic window on the running
 * correlation time of R^2.
 */
#include "towstab/seastate.h"

#include <complex.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "response_impl.h"
#include "towstab/converge.h"

/* Observed orders of the three grids trusted for a Richardson error, and
 * the cap on it (Simpson's order: a higher observed order would make the
 * estimate optimistic). Outside, the error is the full difference of the
 * two finest grids. */
#define ORDER_TRUST_MIN 2.0
#define ORDER_TRUST_MAX 8.0
#define SIMPSON_ORDER 4.0
/* Most intervals of the fine grid. */
#define INTERVALS_MAX (1 << 20)
/* Wave energy outside the band (relative to Hs^2/16) above which a note
 * says so. */
#define BAND_NOTE 1e-3
/* Fewer cycles than this in the duration: the Rayleigh maximum is a note. */
#define CYCLES_NOTE 10.0

int ts_seaway_init(ts_seaway *w, const ts_system *sys, const ts_sea *sea,
                   const ts_rao *rao, const double reference[3], ts_err *err)
{
    memset(w, 0, sizeof *w);
    if (sys->tow.turn_rate != 0.0)
        return ts_fail(err, TS_EDOMAIN, "sea state: the tow turns (%g "
                       "rad/s): its heading to the waves changes all the "
                       "time, so the response is not stationary; analyse a "
                       "straight tow", sys->tow.turn_rate);
    if (!(sys->env.gravity > 0))
        return ts_fail(err, TS_EDOMAIN, "sea state: gravity is %g m/s^2: "
                       "there are no surface waves without it",
                       sys->env.gravity);
    ts_sea_info si;
    ts_sea_get_info(sea, &si);
    if (rao) {
        int rc = ts_rao_check_heading(rao, si.heading, err);
        if (rc)
            return rc;
    }
    w->rotations = sys->tow.vehicle >= 0;
    const double *attach =
        w->rotations ? sys->bodies[sys->tow.vehicle].vehicle->attach : NULL;
    for (int c = 0; c < 3; c++) {
        double r = reference ? reference[c] : 0.0;
        if (!isfinite(r))
            return ts_fail(err, TS_EINVAL, "sea state: the RAO reference "
                           "point must be finite");
        w->lever[c] = sys->tow.point[c] - r;
        w->reference[c] = r;
        w->origin[c] = sys->tow.point[c] - (attach ? attach[c] : 0.0);
    }
    w->sea = sea;
    w->rao = rao;
    w->speed = sys->tow.speed;
    w->gravity = sys->env.gravity;
    return TS_OK;
}

int ts_seaway_tow(const ts_seaway *w, double omega,
                  double re[TS_SUM_AXES], double im[TS_SUM_AXES],
                  ts_err *err)
{
    for (int j = 0; j < TS_SUM_AXES; j++)
        re[j] = im[j] = 0.0;
    if (!w->rao) {
        re[2] = -1.0; /* z is down: the surface rises by eta */
        return TS_OK;
    }
    ts_sea_info si;
    ts_sea_get_info(w->sea, &si);
    if (!w->rotations)
        return ts_rao_tow_point(w->rao, si.heading, omega, w->lever, re, im,
                                err);
    /* The origin O's translation; the rotation about O moves each start
     * point r from O by theta x r in the kernel. */
    double lever[3], xr[TS_NDOF], xi[TS_NDOF];
    for (int c = 0; c < 3; c++)
        lever[c] = w->origin[c] - w->reference[c];
    int rc = ts_rao_tow_point(w->rao, si.heading, omega, lever, re, im, err);
    if (!rc)
        rc = ts_rao_eval(w->rao, si.heading, omega, xr, xi, err);
    for (int j = 3; j < 6 && !rc; j++) {
        re[j] = xr[TS_DOF_ROLL + j - 3];
        im[j] = xi[TS_DOF_ROLL + j - 3];
    }
    return rc;
}

void ts_seaway_set_trim(ts_seaway *w, const ts_kernel *k, const double y[])
{
    int v = ts_kernel_root(k);
    if (v < 0)
        return;
    const ts_system *sys = ts_kernel_system(k);
    const double *attach = sys->bodies[sys->tow.vehicle].vehicle->attach;
    double R[9], rA[3];
    ts_kernel_get_vehicle(k, v, y, R, NULL);
    ts_kernel_root_position(k, y, rA);
    for (int c = 0; c < 3; c++)
        w->origin[c] = rA[c] - (R[3 * c] * attach[0] +
                                R[3 * c + 1] * attach[1] +
                                R[3 * c + 2] * attach[2]);
}

int ts_seaway_band(const ts_seaway *w, double tail, double *lo, double *hi,
                   ts_err *err)
{
    if (!(tail > 0 && tail < 0.5))
        return ts_fail(err, TS_EINVAL, "sea state: the tail must be in (0, "
                       "0.5), got %g", tail);
    ts_sea_band(w->sea, tail, lo, hi);
    if (w->rao) {
        double a, b;
        ts_rao_range(w->rao, &a, &b);
        if (!(a < *hi && b > *lo))
            return ts_fail(err, TS_EDOMAIN, "sea state: the RAO table (%g to "
                           "%g rad/s) and the sea's band (%g to %g rad/s) do "
                           "not overlap", a, b, *lo, *hi);
        *lo = fmax(*lo, a);
        *hi = fmin(*hi, b);
    }
    return TS_OK;
}

void ts_seastate_opts_default(ts_seastate_opts *o)
{
    memset(o, 0, sizeof *o);
    o->intervals = TS_SEASTATE_INTERVALS;
    o->tail = TS_SEASTATE_TAIL;
    o->duration = TS_SEASTATE_DURATION;
}

void ts_seastate_free(ts_seastate *s)
{
    if (!s)
        return;
    free(s->omega);
    free(s->omega_e);
    free(s->wave);
    free(s->input_re);
    free(s->input_im);
    free(s->gain_re);
    free(s->gain_im);
    free(s->density);
    free(s);
}

/* Simpson's rule over f[0..n] (n even) taken every `stride` points, step
 * h between the points used. */
static double simpson(const double *f, int n, int stride, double h)
{
    int m = n / stride;
    double s = f[0] + f[(size_t)m * stride];
    for (int i = 1; i < m; i++)
        s += (i % 2 ? 4.0 : 2.0) * f[(size_t)i * stride];
    return s * h * stride / 3.0;
}

/* The fine-grid integral of f and its grid error from the grids of a
 * half and a quarter as many intervals. */
static double integrate(const double *f, int n, double h, double *error,
                        double *order)
{
    double q[3] = {simpson(f, n, 4, h), simpson(f, n, 2, h),
                   simpson(f, n, 1, h)};
    double hh[3] = {4 * h, 2 * h, h}, p;
    *order = NAN;
    double d = fabs(q[2] - q[1]);
    *error = d;
    if (ts_conv_observed_order(hh, q, &p) == TS_OK) {
        *order = p;
        if (p >= ORDER_TRUST_MIN && p <= ORDER_TRUST_MAX)
            *error = d / (pow(2.0, fmin(p, SIMPSON_ORDER)) - 1.0);
    }
    return q[2];
}

static int check_opts(const ts_seastate_opts *o, ts_err *err)
{
    if (o->intervals < 16 || o->intervals > INTERVALS_MAX ||
        o->intervals % 8)
        return ts_fail(err, TS_EINVAL, "sea state: intervals must be a "
                       "multiple of 8 in [16, %d] (the grid is halved "
                       "twice for the error estimate), got %d", INTERVALS_MAX,
                       o->intervals);
    if (!(o->duration > 0) || !isfinite(o->duration))
        return ts_fail(err, TS_EINVAL, "sea state: the duration must be > 0 "
                       "s, got %g s", o->duration);
    if ((o->omega_lo != 0 || o->omega_hi != 0) &&
        !(o->omega_lo > 0 && o->omega_hi > o->omega_lo &&
          isfinite(o->omega_hi)))
        return ts_fail(err, TS_EINVAL, "sea state: the band must have 0 < "
                       "lo < hi, got [%g, %g] rad/s", o->omega_lo,
                       o->omega_hi);
    return TS_OK;
}

/* The grid's band: given, or the seaway's; a given band must lie in the
 * RAO table. */
static int grid_band(const ts_seaway *w, double lo_opt, double hi_opt,
                     double tail, double *lo, double *hi, ts_err *err)
{
    if (lo_opt == 0 && hi_opt == 0)
        return ts_seaway_band(w, tail, lo, hi, err);
    *lo = lo_opt;
    *hi = hi_opt;
    if (w->rao) {
        double a, b;
        ts_rao_range(w->rao, &a, &b);
        if (*lo < a * (1 - 1e-12) || *hi > b * (1 + 1e-12))
            return ts_fail(err, TS_EDOMAIN, "sea state: the band %g to %g "
                           "rad/s leaves the RAO table (%g to %g rad/s)",
                           *lo, *hi, a, b);
    }
    return TS_OK;
}

static int alloc_result(ts_seastate *s, int np, int nin)
{
    size_t n = (size_t)np;
    s->omega = malloc(n * sizeof(double));
    s->omega_e = malloc(n * sizeof(double));
    s->wave = malloc(n * sizeof(double));
    s->input_re = calloc(n * (size_t)nin, sizeof(double));
    s->input_im = calloc(n * (size_t)nin, sizeof(double));
    s->gain_re = calloc(n, sizeof(double));
    s->gain_im = calloc(n, sizeof(double));
    s->density = malloc(n * sizeof(double));
    return s->omega && s->omega_e && s->wave && s->input_re &&
           s->input_im && s->gain_re && s->gain_im && s->density;
}

/* The errors of sigma, 2 sigma, Tz and the most probable maximum caused
 * by errors e0 of m0 and e2 of m2 (first order). */
static void stat_errors(const ts_seastate *s, double e0, double e2,
                        double out[4])
{
    double m0 = s->m0.value, m2 = s->m2.value, sigma = sqrt(m0);
    double es = sigma > 0 ? e0 / (2 * sigma) : sqrt(e0);
    double rel_tz = 0.5 * (e0 / m0 + e2 / m2);
    out[0] = es;
    out[1] = 2 * es;
    out[2] = s->tz.value * rel_tz;
    if (s->cycles > 1) {
        double q = sqrt(2 * log(s->cycles));
        out[3] = es * q + sigma / q * rel_tz;
    } else {
        out[3] = NAN;
    }
}

static void stat_total(ts_stat *t)
{
    t->error = t->grid + t->band + t->discretisation;
}

/* Statistics from m0, m2 and their errors' parts. */
static void statistics(ts_seastate *s)
{
    double m0 = s->m0.value, m2 = s->m2.value;
    double sigma = sqrt(m0);
    s->sigma.value = sigma;
    s->significant.value = 2 * sigma;
    s->tz.value = m2 > 0 ? 2 * M_PI * sqrt(m0 / m2) : NAN;
    s->cycles = s->duration / s->tz.value;
    s->mpm.value = s->cycles > 1 ? sigma * sqrt(2 * log(s->cycles)) : NAN;
    double g[4], b[4];
    stat_errors(s, s->m0_grid_error, s->m2_grid_error, g);
    stat_errors(s, s->m0_band_error, s->m2_band_error, b);
    ts_stat *st[4] = {&s->sigma, &s->significant, &s->tz, &s->mpm};
    for (int i = 0; i < 4; i++) {
        st[i]->grid = g[i];
        st[i]->band = b[i];
        stat_total(st[i]);
    }
    s->m0.grid = s->m0_grid_error;
    s->m0.band = s->m0_band_error;
    s->m2.grid = s->m2_grid_error;
    s->m2.band = s->m2_band_error;
    stat_total(&s->m0);
    stat_total(&s->m2);
}

/* The caller's progress over the driven axes (ts_seastate_opts.progress):
 * one axis' frequencies, counted after the axes done before it. */
typedef struct axis_progress {
    const ts_seastate_opts *o;
    double before, total;
} axis_progress;

static int on_axis_progress(const ts_progress *p, void *data)
{
    const axis_progress *a = data;
    ts_progress q = {"sea state", a->before + p->done, a->total,
                     "frequencies"};
    return a->o->progress(&q, a->o->progress_data);
}

/* The towing vehicle's origin O at the linearization's trim: from a
 * cable starting on it, O = r_A + R (p - A) - R p (ts_linear.up_map's
 * lever and tow_lever of its lower node). */
static void linear_origin(const ts_system *sys, const ts_linear *lin,
                          double origin[3])
{
    for (int l = 0; lin->up_map && l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        if (L->upper != 0 || L->up_body < 0)
            continue;
        const double *lev = lin->up_map + 12 * l + 9;
        const double *r = lin->tow_lever + 3 * L->lower;
        for (int c = 0; c < 3; c++)
            origin[c] = lin->r0[c] + lev[c] - r[c];
        return;
    }
}

int ts_seastate_compute(const ts_system *sys, const ts_linear *lin,
                        const ts_seaway *way, const ts_output *out,
                        const ts_seastate_opts *opts, ts_seastate **res,
                        ts_err *err)
{
    *res = NULL;
    /* With a towing vehicle, its origin at this linearization's trim. */
    ts_seaway wl = *way;
    const ts_seaway *w = &wl;
    if (wl.rotations)
        linear_origin(sys, lin, wl.origin);
    ts_seastate_opts o;
    if (opts)
        o = *opts;
    else
        ts_seastate_opts_default(&o);
    int rc = check_opts(&o, err);
    double lo, hi;
    if (!rc)
        rc = grid_band(w, o.omega_lo, o.omega_hi, o.tail, &lo, &hi, err);
    if (rc)
        return rc;
    int n = o.intervals, np = n + 1, nin = w->rotations ? 6 : 3;
    ts_seastate *s = calloc(1, sizeof *s);
    double *freq = malloc((size_t)np * sizeof *freq);
    double *f2 = malloc((size_t)np * sizeof *f2);
    if (!s || !freq || !f2 || !alloc_result(s, np, nin)) {
        ts_seastate_free(s);
        free(freq);
        free(f2);
        return ts_fail(err, TS_ENOMEM, "sea state: out of memory");
    }
    ts_sea_info si;
    ts_sea_get_info(w->sea, &si);
    s->output = *out;
    s->unit = out->si_unit;
    s->mean = ts_output_value(sys, out, lin->r0, lin->t0, NULL);
    s->npoints = np;
    s->ninputs = nin;
    s->duration = o.duration;
    s->band_lo = lo;
    s->band_hi = hi;
    s->wave_hs = si.hs;
    ts_trust_init(&s->trust);
    /* Uniform in u = ln w: the integrands are f(w) w du. */
    double h = log(hi / lo) / n;
    double tmax[TS_SUM_AXES] = {0};
    for (int i = 0; i < np && !rc; i++) {
        double wv = i == 0 ? lo : i == n ? hi : lo * exp(i * h);
        s->omega[i] = wv;
        s->omega_e[i] = ts_sea_encounter(wv, w->speed, si.heading,
                                         w->gravity);
        s->wave[i] = ts_sea_density(w->sea, wv);
        double tr[TS_SUM_AXES], ti[TS_SUM_AXES];
        rc = ts_seaway_tow(w, wv, tr, ti, err);
        for (int j = 0; j < nin && !rc; j++) {
            s->input_re[(size_t)j * np + i] = tr[j];
            s->input_im[(size_t)j * np + i] = ti[j];
            tmax[j] = fmax(tmax[j], hypot(tr[j], ti[j]));
        }
        freq[i] = fabs(s->omega_e[i]) / (2 * M_PI);
    }
    /* Gains of the driven inputs, summed coherently. */
    int driven = 0;
    for (int j = 0; j < nin; j++)
        driven += tmax[j] != 0;
    axis_progress ap = {&o, 0, (double)driven * np};
    for (int j = 0; j < nin && !rc; j++) {
        int ch = j < 3 ? TS_IN_DISP + j : TS_IN_ROT + j - 3;
        s->channel[j] = ch;
        if (tmax[j] == 0)
            continue;
        ts_response *r = NULL;
        rc = tsi_response_compute(sys, lin, ch, out, freq, np,
                                  o.progress ? on_axis_progress : NULL, &ap,
                                  &r, err);
        ap.before += np;
        if (rc) {
            ts_err_prefix(err, "sea state, input %s: ", ts_input_name(ch));
            break;
        }
        s->responses += np;
        for (int i = 0; i < np; i++) {
            double complex H = r->re[i] + I * r->im[i];
            if (s->omega_e[i] < 0)
                H = conj(H);
            double complex T = s->input_re[(size_t)j * np + i] +
                               I * s->input_im[(size_t)j * np + i];
            double complex g = H * T;
            s->gain_re[i] += creal(g);
            s->gain_im[i] += cimag(g);
        }
        ts_response_free(r);
    }
    if (rc) {
        ts_seastate_free(s);
        free(freq);
        free(f2);
        return rc;
    }
    for (int i = 0; i < np; i++) {
        double g2 = s->gain_re[i] * s->gain_re[i] +
                    s->gain_im[i] * s->gain_im[i];
        s->density[i] = g2 * s->wave[i];
        freq[i] = s->omega[i] * s->density[i];
        f2[i] = s->omega_e[i] * s->omega_e[i] * freq[i];
    }
    s->m0.value = integrate(freq, n, h, &s->m0_grid_error, &s->order_m0);
    s->m2.value = integrate(f2, n, h, &s->m2_grid_error, &s->order_m2);
    /* The band: wave energy outside it, and the output it would add with
     * the transfer held at its edge values. */
    double below = 0, above = 0, inside = 0;
    rc = ts_sea_moment(w->sea, 0, 0.0, lo, &below, err);
    if (!rc)
        rc = ts_sea_moment(w->sea, 0, hi, INFINITY, &above, err);
    if (!rc)
        rc = ts_sea_moment(w->sea, 0, lo, hi, &inside, err);
    if (rc) {
        ts_seastate_free(s);
        free(freq);
        free(f2);
        return rc;
    }
    double g0 = s->gain_re[0] * s->gain_re[0] + s->gain_im[0] * s->gain_im[0];
    double gn = s->gain_re[n] * s->gain_re[n] + s->gain_im[n] * s->gain_im[n];
    double we0 = s->omega_e[0], wen = s->omega_e[n];
    s->m0_band_error = g0 * below + gn * above;
    s->m2_band_error = g0 * we0 * we0 * below + gn * wen * wen * above;
    s->wave_m0_band = inside;
    s->wave_m0_out = below + above;
    s->disc_order = NAN;
    s->disc_links_needed = NAN;
    statistics(s);

    /* Verdict. */
    double rel = s->sigma.value > 0 ? s->sigma.error / s->sigma.value : 0;
    if (!(rel <= TS_SEASTATE_RTOL)) {
        int grid = s->m0_grid_error >= s->m0_band_error;
        ts_trust_fail(&s->trust, "sigma's estimated error is %.2g %% "
                      "(target %.2g %%), mostly from the %s: %s",
                      100 * rel, 100 * TS_SEASTATE_RTOL,
                      grid ? "frequency grid" : "band",
                      grid ? "use more intervals"
                           : "widen the band (the RAO table's frequencies "
                             "limit it)");
    }
    if (s->wave_m0_out > BAND_NOTE * si.m0)
        ts_trust_note(&s->trust, "%.3g %% of the wave variance lies outside "
                      "the band %.4g to %.4g rad/s (its estimated share of "
                      "the output variance is in the band error)",
                      100 * s->wave_m0_out / si.m0, lo, hi);
    if (!(s->m0.value > 0))
        ts_trust_note(&s->trust, "%s does not respond to this sea (sigma "
                      "= 0): Tz and the most probable maximum are not "
                      "defined", s->output.name);
    else if (s->cycles < CYCLES_NOTE)
        ts_trust_note(&s->trust, "only %.3g response cycles in %g s: the "
                      "most probable maximum sigma sqrt(2 ln N) assumes many",
                      s->cycles, s->duration);
    if (si.kind != TS_SEA_TABLE) {
        double steep = 2 * M_PI * si.hs / (w->gravity * si.tp * si.tp);
        if (steep > 1.0 / 15.0)
            ts_trust_note(&s->trust, "the sea's steepness 2 pi Hs / (g Tp^2) "
                          "= %.3g exceeds 1/15, the limit DNV-RP-C205 gives "
                          "for observed seas", steep);
    }
    free(freq);
    free(f2);
    *res = s;
    return TS_OK;
}

/* --- Time domain ----------------------------------------------------- */

void ts_sea_realisation_default(const ts_seaway *w, ts_sea_realisation *r)
{
    memset(r, 0, sizeof *r);
    r->components = TS_SEA_COMPONENTS;
    r->seed = 1;
    ts_sea_info si;
    ts_sea_get_info(w->sea, &si);
    r->rise = isfinite(si.tp) ? 2.0 * si.tp : 0.0;
}

int ts_seaway_excitation(const ts_seaway *w, const ts_sea_realisation *r,
                         ts_excitation *ex, double *band_m0, ts_err *err)
{
    if (r->components < 1)
        return ts_fail(err, TS_EINVAL, "sea realisation: components must be "
                       ">= 1, got %d", r->components);
    if (!(r->rise >= 0) || !isfinite(r->rise))
        return ts_fail(err, TS_EINVAL, "sea realisation: the fade-in must "
                       "be >= 0 s, got %g s", r->rise);
    double lo, hi;
    int rc = grid_band(w, r->omega_lo, r->omega_hi, TS_SEA_REALISATION_TAIL,
                       &lo, &hi, err);
    if (rc)
        return rc;
    int n = r->components;
    double *we = malloc((size_t)n * sizeof *we);
    double *cre = malloc(TS_SUM_AXES * (size_t)n * sizeof *cre);
    double *cim = malloc(TS_SUM_AXES * (size_t)n * sizeof *cim);
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!we || !cre || !cim || !rng) {
        rc = ts_fail(err, TS_ENOMEM, "sea realisation: out of memory");
        goto done;
    }
    gsl_rng_set(rng, r->seed);
    ts_sea_info si;
    ts_sea_get_info(w->sea, &si);
    /* Bins of equal width du in u = ln w: a component at w_k stands for
     * S(w_k) w_k du, whose mean over the bin is the bin's integral. */
    double du = log(hi / lo) / n;
    for (int k = 0; k < n && !rc; k++) {
        double wk = lo * exp((k + gsl_rng_uniform(rng)) * du);
        double phi = 2.0 * M_PI * gsl_rng_uniform(rng);
        double a = sqrt(2.0 * ts_sea_density(w->sea, wk) * wk * du);
        double tr[TS_SUM_AXES], ti[TS_SUM_AXES];
        rc = ts_seaway_tow(w, wk, tr, ti, err);
        double complex e = a * cexp(I * phi);
        for (int j = 0; j < TS_SUM_AXES && !rc; j++) {
            double complex c = (tr[j] + I * ti[j]) * e;
            cre[TS_SUM_AXES * k + j] = creal(c);
            cim[TS_SUM_AXES * k + j] = cimag(c);
        }
        we[k] = ts_sea_encounter(wk, w->speed, si.heading, w->gravity);
    }
    if (!rc)
        rc = ts_excitation_add_sum(ex, n, we, cre, cim, r->rise, err);
    if (!rc && band_m0)
        rc = ts_sea_moment(w->sea, 0, lo, hi, band_m0, err);
done:
    gsl_rng_free(rng);
    free(we);
    free(cre);
    free(cim);
    return rc;
}

int ts_record_stats_compute(const double x[], int n, double dt,
                            ts_record_stats *st, ts_err *err)
{
    memset(st, 0, sizeof *st);
    if (n < 16)
        return ts_fail(err, TS_EINVAL, "record statistics: at least 16 "
                       "samples are needed, got %d", n);
    if (!(dt > 0) || !isfinite(dt))
        return ts_fail(err, TS_EINVAL, "record statistics: the sample "
                       "interval must be > 0 s, got %g s", dt);
    double mean = 0, xmax = -INFINITY, xmin = INFINITY;
    for (int i = 0; i < n; i++) {
        if (!isfinite(x[i]))
            return ts_fail(err, TS_EINVAL, "record statistics: sample %d is "
                           "not finite", i);
        mean += x[i];
        xmax = fmax(xmax, x[i]);
        xmin = fmin(xmin, x[i]);
    }
    mean /= n;
    size_t m = 1;
    while (m < 2 * (size_t)n)
        m <<= 1;
    double *a = calloc(m, sizeof *a);
    if (!a)
        return ts_fail(err, TS_ENOMEM, "record statistics: out of memory");
    for (int i = 0; i < n; i++)
        a[i] = x[i] - mean;
    int ups = 0;
    double first = NAN, last = NAN;
    for (int i = 0; i + 1 < n; i++)
        if (a[i] < 0 && a[i + 1] >= 0) {
            /* Linear interpolation of the crossing. */
            double tc = dt * (i + a[i] / (a[i] - a[i + 1]));
            if (ups == 0)
                first = tc;
            last = tc;
            ups++;
        }
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int s1 = gsl_fft_real_radix2_transform(a, 1, m);
    if (!s1) {
        /* Half-complex: a[0] and a[m/2] real, a[k] + i a[m-k]. */
        a[0] = a[0] * a[0];
        a[m / 2] = a[m / 2] * a[m / 2];
        for (size_t k = 1; k < m / 2; k++) {
            double re = a[k], im = a[m - k];
            a[k] = re * re + im * im;
            a[m - k] = 0.0;
        }
        s1 = gsl_fft_halfcomplex_radix2_inverse(a, 1, m);
    }
    gsl_set_error_handler(old);
    if (s1) {
        free(a);
        return ts_fail(err, TS_EDOMAIN, "record statistics: FFT failed "
                       "(%s)", gsl_strerror(s1));
    }
    double r0 = a[0] / n;
    st->nsamples = n;
    st->duration = (n - 1) * dt;
    st->mean = mean;
    st->maximum = xmax;
    st->minimum = xmin;
    st->sigma.value = sqrt(r0);
    st->tz = ups > 1 ? (last - first) / (ups - 1) : NAN;
    if (!(r0 > 0)) {
        free(a);
        st->corr_time = 0;
        st->independent = INFINITY;
        return TS_OK;
    }
    /* Sokal's window on tau2(M) = dt (1 + 2 sum_1^M rho_k^2). */
    double sum = 1.0, sum1 = 1.0;
    int M = n / 2, k;
    for (k = 1; k < n / 2; k++) {
        double rho = a[k] / n / r0;
        sum += 2.0 * rho * rho;
        sum1 += 2.0 * rho;
        if (k >= TS_SEA_SOKAL * sum) {
            M = k;
            break;
        }
    }
    free(a);
    st->window_lags = M;
    st->corr_time = dt * sum;
    st->mean_error = st->sigma.value * sqrt(dt * fmax(sum1, 1.0) /
                                            st->duration);
    st->independent = st->duration / st->corr_time;
    st->sigma.error = st->sigma.value * sqrt(st->corr_time /
                                             (2.0 * st->duration));
    return TS_OK;
}

int ts_record_from_history(const ts_history *h, const ts_output *out,
                           double t_from, double x[], int *n, double *dt,
                           ts_err *err)
{
    *n = 0;
    *dt = NAN;
    int ns = h->nsamples;
    if (ns < 3)
        return ts_fail(err, TS_EINVAL, "record: the history has %d samples",
                       ns);
    double step = h->t[1] - h->t[0];
    int last = ns - 1;
    if (fabs((h->t[last] - h->t[last - 1]) - step) > 1e-9 * step)
        last--;
    int first = 0;
    while (first <= last && h->t[first] < t_from - 1e-9 * step)
        first++;
    if (out->kind == TS_OUT_POSITION &&
        (out->node < 0 || out->node >= h->nnodes))
        return ts_fail(err, TS_EINVAL, "record: output node %d out of range",
                       out->node);
    if (out->kind == TS_OUT_TENSION &&
        (out->link < 0 || out->link >= h->nlinks))
        return ts_fail(err, TS_EINVAL, "record: output link %d out of range",
                       out->link);
    for (int i = first; i <= last; i++) {
        double v = ts_history_value(NULL, h, out, i);
        if (!isfinite(v))
            return ts_fail(err, TS_EINVAL, "record: %s is not available at "
                           "t = %g s (a linear run has tensions when "
                           "linearized with their Jacobians; the tow force "
                           "comes from nonlinear runs only)", out->name,
                           h->t[i]);
        x[(*n)++] = v;
    }
    *dt = step;
    return TS_OK;
}

/* --- Discretisation -------------------------------------------------- */

typedef struct conv_ctx {
    ts_system *sys;
    ts_equilibrium_opts eo;
    const ts_sea *sea;
    const ts_rao *rao;
    double reference[3];
    char output[2 * TS_NAME_MAX + 16];
    ts_seastate_opts o;
} conv_ctx;

static void conv_ctx_free(void *p)
{
    conv_ctx *x = p;
    ts_system_free(x->sys);
    free(x);
}

static int conv_run(void *ctx, ts_conv_param p, double setting,
                    double values[], double noise[], long *evaluations,
                    ts_trust *trust, ts_err *err)
{
    conv_ctx *x = ctx;
    ts_equilibrium_opts eo = x->eo;
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    if (p == TS_CONV_TOLERANCE)
        eo.tol = setting;
    if (p == TS_CONV_STEP)
        lo.rel_step = setting;
    ts_system *sys = p == TS_CONV_LINKS
                         ? ts_conv_system_with_links(x->sys, (int)setting, err)
                         : x->sys;
    if (!sys)
        return err && err->code ? err->code : TS_EINVAL;
    ts_output out;
    int rc = ts_response_output_find(sys, x->output, &out, err);
    lo.tensions = out.kind == TS_OUT_TENSION;
    ts_kernel *k = rc ? NULL : ts_kernel_alloc(sys, err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, err) : NULL;
    ts_linear *lin = NULL;
    ts_seastate *r = NULL;
    if (!rc)
        rc = eq ? ts_equilibrium_solve(k, &eo, eq, err) : TS_ENOMEM;
    if (eq) {
        *evaluations += eq->evaluations;
        ts_health_equilibrium(sys, eq, trust);
    }
    if (!rc) {
        lin = ts_linear_alloc(k, err);
        rc = lin ? ts_linearize_equilibrium(k, eq, &lo, lin, err) : TS_ENOMEM;
        if (lin)
            *evaluations += lin->evaluations;
    }
    ts_seaway w;
    if (!rc)
        rc = ts_seaway_init(&w, sys, x->sea, x->rao, x->reference, err);
    if (!rc)
        rc = ts_seastate_compute(sys, lin, &w, &out, &x->o, &r, err);
    if (!rc) {
        const ts_stat *st[3] = {&r->sigma, &r->tz, &r->mpm};
        for (int i = 0; i < 3; i++) {
            values[i] = st[i]->value;
            noise[i] = st[i]->grid + st[i]->band;
        }
        ts_trust_merge(trust, "", &r->trust);
    }
    ts_seastate_free(r);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    if (sys != x->sys)
        ts_system_free(sys);
    return rc;
}

int ts_seastate_conv_analysis(const ts_system *sys,
                              const ts_equilibrium_opts *eo,
                              const ts_sea *sea, const ts_rao *rao,
                              const double reference[3], const char *output,
                              const ts_seastate_opts *o, ts_conv_analysis *an,
                              ts_err *err)
{
    memset(an, 0, sizeof *an);
    ts_output out;
    int rc = ts_response_output_find(sys, output, &out, err);
    if (rc)
        return rc;
    conv_ctx *x = calloc(1, sizeof *x);
    an->values = calloc(3, sizeof *an->values);
    if (x)
        x->sys = ts_system_copy(sys, err);
    if (!x || !x->sys || !an->values) {
        if (x)
            ts_system_free(x->sys);
        free(x);
        free(an->values);
        an->values = NULL;
        return ts_fail(err, TS_ENOMEM, "sea state: out of memory");
    }
    if (eo)
        x->eo = *eo;
    else
        ts_equilibrium_opts_default(&x->eo);
    if (o)
        x->o = *o;
    else
        ts_seastate_opts_default(&x->o);
    x->sea = sea;
    x->rao = rao;
    for (int c = 0; c < 3; c++)
        x->reference[c] = reference ? reference[c] : 0.0;
    snprintf(x->output, sizeof x->output, "%s", out.name);
    snprintf(an->name, sizeof an->name, "seastate");
    an->nvalues = 3;
    static const char *const what[3] = {"sigma", "tz", "mpm"};
    const char *unit = out.kind == TS_OUT_TENSION ? "N" : "m";
    for (int i = 0; i < 3; i++) {
        snprintf(an->values[i].name, sizeof an->values[i].name, "%.80s.%s",
                 out.name, what[i]);
        snprintf(an->values[i].unit, sizeof an->values[i].unit, "%s",
                 i == 1 ? "s" : unit);
        an->values[i].scale = 0.0;
    }
    an->ctx = x;
    an->free_ctx = conv_ctx_free;
    an->run = conv_run;
    return TS_OK;
}

int ts_seastate_discretisation(const ts_system *sys,
                               const ts_equilibrium_opts *eo,
                               const ts_seaway *w, const ts_seastate_opts *o,
                               ts_seastate *r, ts_err *err)
{
    int N = sys->ncables > 0 ? sys->cables[0].nlinks : 0;
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].nlinks != N || sys->cables[c].link_fraction)
            return ts_fail(err, TS_EDOMAIN, "sea state: the discretisation "
                           "error needs every cable at the same number of "
                           "equal links (cable '%s' has %d%s)",
                           sys->cables[c].name, sys->cables[c].nlinks,
                           sys->cables[c].link_fraction ? ", unequal" : "");
    if (N < TS_SEASTATE_DISC_LINKS_MIN)
        return ts_fail(err, TS_EDOMAIN, "sea state: the discretisation error "
                       "needs at least %d links per cable (halved twice: the "
                       "coarsest run must keep 2), got %d",
                       TS_SEASTATE_DISC_LINKS_MIN, N);
    double reference[3];
    for (int c = 0; c < 3; c++)
        reference[c] = sys->tow.point[c] - w->lever[c];
    ts_conv_analysis an;
    int rc = ts_seastate_conv_analysis(sys, eo, w->sea, w->rao, reference,
                                       r->output.name, o, &an, err);
    if (rc)
        return rc;
    ts_convergence *cv = ts_convergence_alloc("seastate", TS_CONV_LINKS, 3,
                                              an.values, 3, err);
    if (!cv) {
        ts_conv_analysis_free(&an);
        return err && err->code ? err->code : TS_ENOMEM;
    }
    double settings[2] = {(N + 3) / 4, (N + 1) / 2};
    const ts_stat *st[3] = {&r->sigma, &r->tz, &r->mpm};
    double values[3], noise[3];
    for (int i = 0; i < 3; i++) {
        values[i] = st[i]->value;
        noise[i] = st[i]->grid + st[i]->band;
    }
    rc = ts_convergence_add_series(cv, "", err);
    if (rc >= 0)
        rc = ts_convergence_sweep(cv, 0, &an, settings, 2, err);
    for (int i = 0; rc == TS_OK && i < cv->nrows; i++)
        if (cv->rows[i].status != TS_OK)
            rc = ts_fail(err, cv->rows[i].status, "sea state, %g links per "
                         "cable: %s", cv->rows[i].setting,
                         cv->rows[i].message);
    if (rc == TS_OK)
        rc = ts_convergence_add_row(cv, 0, N, TS_OK, NULL, 0.0, 0,
                                    &r->trust, values, noise, err);
    if (rc == TS_OK)
        rc = ts_convergence_estimate(cv, TS_SEASTATE_RTOL, err);
    if (rc == TS_OK) {
        int fine = -1;
        double wall = 0;
        for (int i = 0; i < cv->nrows; i++) {
            if (cv->rows[i].setting == N)
                fine = i;
            else
                wall += cv->rows[i].wall_s;
        }
        const ts_conv_row *row = &cv->rows[fine];
        double e[3];
        for (int i = 0; i < 3; i++)
            e[i] = isfinite(row->errors[i]) ? row->errors[i] : 0.0;
        r->sigma.discretisation = e[0];
        r->significant.discretisation = 2 * e[0];
        r->tz.discretisation = e[1];
        r->mpm.discretisation = isfinite(r->mpm.value) ? e[2] : NAN;
        stat_total(&r->sigma);
        stat_total(&r->significant);
        stat_total(&r->tz);
        stat_total(&r->mpm);
        r->disc_estimated = 1;
        r->disc_links[0] = (int)settings[0];
        r->disc_links[1] = (int)settings[1];
        r->disc_links[2] = N;
        r->disc_order = cv->series[0].order[0];
        r->disc_wall_s = wall;
        double rel = r->sigma.value > 0 ? e[0] / r->sigma.value : 0;
        if (!isfinite(row->errors[0]))
            ts_trust_note(&r->trust, "the discretisation error of sigma "
                          "could not be estimated from %d, %d and %d links "
                          "(%s)", r->disc_links[0], r->disc_links[1], N,
                          ts_conv_ref_name(cv->series[0].ref_kind[0]));
        else if (rel > TS_SEASTATE_RTOL) {
            r->disc_links_needed = cv->predicted_setting;
            if (isfinite(cv->predicted_setting))
                ts_trust_fail(&r->trust, "sigma's discretisation error is "
                              "%.2g %% with %d links per cable (target %.2g "
                              "%%); the observed order %.2g says about %.0f "
                              "links would meet it", 100 * rel, N,
                              100 * TS_SEASTATE_RTOL, r->disc_order,
                              ceil(cv->predicted_setting));
            else
                ts_trust_fail(&r->trust, "sigma's discretisation error is "
                              "%.2g %% with %d links per cable (target %.2g "
                              "%%): use more links", 100 * rel, N,
                              100 * TS_SEASTATE_RTOL);
        }
    }
    ts_convergence_free(cv);
    ts_conv_analysis_free(&an);
    return rc;
}
