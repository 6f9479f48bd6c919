/* test_seastate.c: response to an irregular sea (towstab/seastate.h), by
 * spectral analysis and in the time domain, on a 5-link towfish scene.
 *
 *  1. Seaway: a turning tow, zero gravity and a heading outside the RAO
 *     table are refused; the band is cut to the RAO table.
 *  2. Spectral, against independent computations:
 *     - the gain G at every grid point equals the coherent sum written out
 *       here, sum_j H_j T_j, with H from ts_response_at (conjugated at a
 *       following sea's negative encounter frequencies) and T from the
 *       RAOs and the lever arm by this test's own cross product (1e-12);
 *     - m0 against GSL's adaptive quadrature (QAG, 1e-11) of the same
 *       integrand over the same band, for 32 to 512 intervals: the
 *       reported grid error bounds the true error, and is at most 100
 *       times it once the true error is above 1e-9 of m0 (the estimate is
 *       conservative: the convergence is irregular);
 *     - symmetry: heave and pitch alone (head seas) give no sway of the
 *       fish (sigma below 1e-12 of the heave's);
 *     - linearity: sigma doubles with Hs to 1e-12;
 *     - the statistics from m0 and m2 by their formulas;
 *     - the JSON and CSV reports carry the same numbers;
 *     - the discretisation error (ts_seastate_discretisation) at 8 and 16
 *       links per cable bounds the difference to 32 links (whose own
 *       error is below a tenth of 16 links': the sequence 8, 16, 32, 64
 *       converges to 1e-4), within a factor 30: the convergence in links
 *       is irregular (the top link crosses the waterline); refusals for
 *       too few and unequal links.
 *  3. Time domain:
 *     - a realisation is reproducible from its seed, and differs with it;
 *     - the record statistics of a sinusoid: sigma = A / sqrt 2, Tz its
 *       period;
 *     - the statistical error estimate against the spread of sigma over
 *       40 independent realisations of the tow point's heave (no
 *       simulation): within a factor 0.7 to 2 of it;
 *     - the cross-check: at Hs = 0.5 m the standard deviation of the fish's
 *       depth from a linear and from a nonlinear simulation (1200 s, 1000
 *       s analysed) agrees with the spectral one within 3 times the sum of
 *       their errors.
 */
#include "towstab/seastate.h"

#include <complex.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcheck.h"
#include "towstab/equilibrium.h"
#include "towstab/report_seastate.h"
#include "towstab/scene.h"

static ts_units *units;

static const char *fish_yaml =
    "name: fish5\n"
    "tow: {speed: 2.0, point: [0, 0, -4]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: fish, length: 150, diameter: 0.025,\n"
    "     mass_per_length: 1.5, links: 5}\n"
    "bodies:\n"
    "  - {name: fish, type: sphere, diameter: 0.7, mass: 400}\n";

typedef struct setup {
    ts_scene *scene;
    ts_kernel *k;
    ts_equilibrium *eq;
    ts_linear *lin;
} setup;

static int setup_open(setup *s, const char *yaml)
{
    ts_err err = {0};
    memset(s, 0, sizeof *s);
    s->scene = ts_scene_parse(yaml, strlen(yaml), "test", units, &err);
    if (!s->scene) {
        printf("scene: %s\n", err.msg);
        return 0;
    }
    const ts_system *sys = s->scene->system;
    s->k = ts_kernel_alloc(sys, &err);
    s->eq = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    eo.tol = 1e-12;
    if (ts_equilibrium_solve(s->k, &eo, s->eq, &err)) {
        printf("equilibrium: %s\n", err.msg);
        return 0;
    }
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.tensions = 1;
    s->lin = ts_linear_alloc(s->k, &err);
    if (ts_linearize_equilibrium(s->k, s->eq, &lo, s->lin, &err)) {
        printf("linearize: %s\n", err.msg);
        return 0;
    }
    return 1;
}

static void setup_close(setup *s)
{
    ts_linear_free(s->lin);
    ts_equilibrium_free(s->eq);
    ts_kernel_free(s->k);
    ts_scene_free(s->scene);
}

/* Heave and pitch RAOs of a 60 m ship in head and bow seas (M axes,
 * leads): heave 1 in long waves falling off near 1 rad/s, pitch the wave
 * slope k = w^2/g (rad/m) in long waves with a 90 deg lead, both with a
 * damped resonance's phase lag. */
static ts_rao *ship_rao(void)
{
    ts_err err = {0};
    const int nf = 40;
    double w[40], hd[2] = {150 * M_PI / 180, M_PI};
    for (int k = 0; k < nf; k++)
        w[k] = 0.2 + k * (2.5 - 0.2) / (nf - 1);
    ts_rao *r = ts_rao_alloc(2, hd, nf, w, &err);
    for (int h = 0; h < 2; h++)
        for (int k = 0; k < nf; k++) {
            double x = w[k] / 0.95, c = h ? 1.0 : 0.87;
            double dyn = 1 / sqrt(pow(1 - x * x, 2) + pow(0.5 * x, 2));
            double lag = atan2(0.5 * x, 1 - x * x);
            double fk = exp(-0.3 * x * x);
            ts_rao_set(r, TS_DOF_HEAVE, h, k, fk * dyn, M_PI - lag, &err);
            ts_rao_set(r, TS_DOF_PITCH, h, k,
                       c * w[k] * w[k] / 9.80665 * fk * dyn,
                       M_PI / 2 - lag, &err);
        }
    ts_rao_finish(r, &err);
    return r;
}

static const double reference_point[3] = {28.0, 0.0, 0.0};

/* A JONSWAP sea of Hs (m), Tp 7.5 s, gamma 3.3 in head seas on the ship
 * of ship_rao() (reference point 28 m ahead of the tow point) and output
 * `name`. */
typedef struct ship_case {
    ts_sea *sea;
    ts_rao *rao;
    ts_seaway w;
    ts_output out;
} ship_case;

static void ship_case_open(ship_case *c, const setup *s, double hs,
                           const char *name)
{
    ts_err err = {0};
    c->rao = ship_rao();
    c->sea = ts_sea_jonswap(hs, 7.5, 3.3, M_PI, &err);
    ts_seaway_init(&c->w, s->scene->system, c->sea, c->rao, reference_point,
                   &err);
    ts_response_output_find(s->scene->system, name, &c->out, &err);
}

static void ship_case_close(ship_case *c)
{
    ts_sea_free(c->sea);
    ts_rao_free(c->rao);
}

static void test_seaway(setup *s)
{
    ts_err err = {0};
    ts_sea *sea = ts_sea_jonswap(2.0, 8.0, 3.3, 100 * M_PI / 180, &err);
    ts_rao *rao = ship_rao();
    ts_seaway w;
    ts_err e = {0};
    CHECK(ts_seaway_init(&w, s->scene->system, sea, rao, NULL, &e) ==
                  TS_EDOMAIN &&
              strstr(e.msg, "heading 100 deg"),
          "heading outside the RAO table refused: %s", e.msg);
    ts_sea_free(sea);
    sea = ts_sea_jonswap(2.0, 8.0, 3.3, M_PI, &err);
    ts_system *sys = ts_system_copy(s->scene->system, &err);
    sys->tow.turn_rate = 0.01;
    CHECK(ts_seaway_init(&w, sys, sea, rao, NULL, &e) == TS_EDOMAIN &&
              strstr(e.msg, "turns"),
          "turning tow refused: %s", e.msg);
    sys->tow.turn_rate = 0;
    sys->env.gravity = 0;
    CHECK(ts_seaway_init(&w, sys, sea, rao, NULL, &e) == TS_EDOMAIN &&
              strstr(e.msg, "gravity"),
          "zero gravity refused: %s", e.msg);
    ts_system_free(sys);
    CHECK(ts_seaway_init(&w, s->scene->system, sea, rao, reference_point,
                         &err) == TS_OK,
          "seaway: %s", err.msg);
    CHECK(w.lever[0] == -28 && w.lever[2] == -4 && w.speed == 2.0,
          "lever arm = tow point - reference point; the tow's speed");
    double lo, hi;
    ts_seaway_band(&w, 1e-6, &lo, &hi, &err);
    CHECK(lo > 0.2 && hi == 2.5, "band cut to the RAO table: %g to %g", lo,
          hi);
    ts_seastate_opts o;
    ts_seastate_opts_default(&o);
    ts_output out;
    ts_response_output_find(s->scene->system, "fish.z", &out, &err);
    ts_seastate *r = NULL;
    static const struct {
        int intervals;
        double duration, lo, hi;
        const char *expect;
    } bad[] = {{100, 3600, 0, 0, "multiple of 8"},
               {8, 3600, 0, 0, "multiple of 8"},
               {512, 0, 0, 0, "duration"},
               {512, 3600, 1.0, 0.5, "0 < lo < hi"},
               {512, 3600, 0.1, 1.0, "leaves the RAO table"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        o.intervals = bad[i].intervals;
        o.duration = bad[i].duration;
        o.omega_lo = bad[i].lo;
        o.omega_hi = bad[i].hi;
        CHECK(ts_seastate_compute(s->scene->system, s->lin, &w, &out, &o, &r,
                                  &e) != TS_OK &&
                  !r && strstr(e.msg, bad[i].expect),
              "options refused (%s): %s", bad[i].expect, e.msg);
    }
    ts_rao_free(rao);
    ts_sea_free(sea);
}

/* QAG integrand: |sum_j H_j T_j|^2 S at wave frequency w. */
typedef struct qctx {
    const ts_system *sys;
    const ts_linear *lin;
    const ts_seaway *w;
    const ts_output *out;
    double heading;
    long calls;
} qctx;

static double complex gain_direct(qctx *q, double w)
{
    ts_err err = {0};
    double we = ts_sea_encounter(w, q->w->speed, q->heading, q->w->gravity);
    double complex t[3] = {0, 0, -1};
    if (q->w->rao) {
        double re[TS_NDOF], im[TS_NDOF];
        ts_rao_eval(q->w->rao, q->heading, w, re, im, &err);
        double complex x[TS_NDOF];
        for (int d = 0; d < TS_NDOF; d++)
            x[d] = re[d] + I * im[d];
        const double *r = q->w->lever;
        t[0] = x[0] + x[4] * r[2] - x[5] * r[1];
        t[1] = x[1] + x[5] * r[0] - x[3] * r[2];
        t[2] = x[2] + x[3] * r[1] - x[4] * r[0];
    }
    double complex g = 0;
    for (int j = 0; j < 3; j++) {
        if (t[j] == 0)
            continue;
        double hr, hi;
        ts_response_at(q->sys, q->lin, j, q->out, fabs(we), &hr, &hi, &err);
        double complex h = hr + I * (we < 0 ? -hi : hi);
        g += h * t[j];
    }
    q->calls++;
    return g;
}

static double qag_integrand(double w, void *p)
{
    qctx *q = p;
    double complex g = gain_direct(q, w);
    return creal(g * conj(g)) * ts_sea_density(q->w->sea, w);
}

static void test_report(const ts_seastate *r, const ts_seaway *w)
{
    ts_err err = {0};
    json_t *j = ts_report_seastate_json(r, w, 1);
    json_t *st = j ? json_object_get(j, "statistics") : NULL;
    json_t *sg = st ? json_object_get(st, "sigma") : NULL;
    json_t *mx = st ? json_object_get(st, "most_probable_largest") : NULL;
    json_t *pts = j ? json_object_get(j, "points") : NULL;
    CHECK(sg && json_real_value(json_object_get(sg, "value")) ==
                    r->sigma.value &&
              json_real_value(json_object_get(sg, "error")) ==
                  r->sigma.error &&
              json_real_value(json_object_get(mx, "value")) ==
                  r->mean + r->mpm.value &&
              json_array_size(pts) == (size_t)r->npoints &&
              !strcmp(json_string_value(json_object_get(j, "unit")), "m") &&
              json_is_true(json_object_get(j, "trustworthy")),
          "JSON: sigma, its error, the largest value, the points, the "
          "verdict");
    json_decref(j);
    char path[] = "/tmp/towstab_test_seastate_XXXXXX";
    int fd = mkstemp(path);
    if (fd >= 0)
        close(fd);
    int rc = ts_report_seastate_csv(r, path, &err);
    FILE *f = rc == TS_OK ? fopen(path, "r") : NULL;
    int lines = 0, commas = -1;
    char line[4096];
    while (f && fgets(line, sizeof line, f)) {
        int c = 0;
        for (char *p = line; *p; p++)
            c += *p == ',';
        if (lines == 0)
            commas = c;
        else if (c != commas)
            commas = -2;
        lines++;
    }
    if (f)
        fclose(f);
    unlink(path);
    CHECK(rc == TS_OK && lines == r->npoints + 1 &&
              commas == 3 + 2 * r->ninputs + 3,
          "CSV: header and one row per point, %d columns (%s)", commas + 1,
          err.msg);
}

static void test_spectral(setup *s)
{
    ts_err err = {0};
    const ts_system *sys = s->scene->system;
    ship_case c;
    ship_case_open(&c, s, 2.0, "fish.z");
    ts_seaway w = c.w;
    ts_output out = c.out;
    qctx q = {sys, s->lin, &w, &out, M_PI, 0};

    /* m0 by QAG over the band of the default grid. */
    ts_seastate_opts o;
    ts_seastate_opts_default(&o);
    ts_seastate *r = NULL;
    int rc = ts_seastate_compute(sys, s->lin, &w, &out, &o, &r, &err);
    if (!CHECK(rc == TS_OK, "spectral fish.z: %s", err.msg))
        return;
    double worst = 0;
    for (int i = 0; i < r->npoints; i += 7) {
        double complex g = gain_direct(&q, r->omega[i]);
        worst = fmax(worst, cabs(g - (r->gain_re[i] + I * r->gain_im[i])) /
                                (cabs(g) + 1e-300));
    }
    CHECK(worst <= 1e-12, "gain = sum_j H_j T_j written out (max rel diff "
          "%.2g)", worst);
    /* QAG piece by piece between the kinks of the integrand: the RAO
     * table's frequencies (linear interpolation) and the peak (where the
     * JONSWAP shape's second derivative jumps). */
    gsl_integration_workspace *ws = gsl_integration_workspace_alloc(2000);
    gsl_function f = {qag_integrand, &q};
    double ref = 0, abserr = 0, cuts[64];
    int ncut = 0, st = 0;
    cuts[ncut++] = r->band_lo;
    for (int k = 0; k < 40; k++) {
        double wk = 0.2 + k * (2.5 - 0.2) / 39;
        if (wk > r->band_lo && wk < r->band_hi)
            cuts[ncut++] = wk;
    }
    cuts[ncut++] = r->band_hi;
    double wp = 2 * M_PI / 7.5;
    gsl_set_error_handler_off();
    for (int c = 0; c + 1 < ncut; c++) {
        double a = cuts[c], b = cuts[c + 1], v, e;
        int pieces = wp > a && wp < b ? 2 : 1;
        for (int p = 0; p < pieces; p++) {
            double lo = pieces == 2 && p == 1 ? wp : a;
            double hi = pieces == 2 && p == 0 ? wp : b;
            st |= gsl_integration_qag(&f, lo, hi, 0, 1e-13, 2000,
                                      GSL_INTEG_GAUSS41, ws, &v, &e);
            ref += v;
            abserr += e;
        }
    }
    CHECK(st == 0 && abserr < 1e-11 * ref, "QAG reference m0 %.12g (+- "
          "%.2g, %ld gains)", ref, abserr, q.calls);
    printf("  spectral fish.z: sigma %.6g +- %.2g m, Tz %.4g s, %ld gains\n",
           r->sigma.value, r->sigma.error, r->tz.value, r->responses);
    ts_seastate_free(r);
    for (int n = 32; n <= 512; n *= 2) {
        o.intervals = n;
        rc = ts_seastate_compute(sys, s->lin, &w, &out, &o, &r, &err);
        if (rc) {
            CHECK(0, "intervals %d: %s", n, err.msg);
            continue;
        }
        double truth = fabs(r->m0.value - ref);
        double est = r->m0_grid_error;
        printf("  %4d intervals: m0 %.12g, true error %.3g, estimated %.3g "
               "(order %.3g)\n", n, r->m0.value, truth, est, r->order_m0);
        CHECK(truth <= est + 2 * abserr, "%d intervals: the grid error %.3g "
              "bounds the true error %.3g", n, est, truth);
        if (truth > 1e-9 * ref)
            CHECK(est <= 100 * truth, "%d intervals: the estimate is at "
                  "most 100 times the true error (%.3g)", n, est / truth);
        ts_seastate_free(r);
    }
    gsl_integration_workspace_free(ws);

    /* Statistics by their formulas. */
    ts_seastate_opts_default(&o);
    o.duration = 3600;
    ts_seastate_compute(sys, s->lin, &w, &out, &o, &r, &err);
    double m0 = r->m0.value, m2 = r->m2.value;
    CHECK_REL(r->sigma.value, sqrt(m0), 1e-15, "sigma = sqrt(m0)");
    CHECK_REL(r->significant.value, 2 * sqrt(m0), 1e-15,
              "significant = 2 sigma");
    CHECK_REL(r->tz.value, 2 * M_PI * sqrt(m0 / m2), 1e-15,
              "Tz = 2 pi sqrt(m0/m2)");
    CHECK_REL(r->mpm.value, sqrt(m0) * sqrt(2 * log(3600 / r->tz.value)),
              1e-14, "most probable maximum sigma sqrt(2 ln N)");
    CHECK_REL(r->sigma.error, r->m0.error / (2 * sqrt(m0)), 1e-14,
              "sigma's error from m0's");
    CHECK(r->trust.trustworthy, "default grid trustworthy");
    CHECK_REL(r->mean, s->eq->positions[3 * out.node + 2], 1e-12,
              "mean: the equilibrium depth");
    double sigma1 = r->sigma.value;
    test_report(r, &w);
    ts_seastate_free(r);

    /* Linearity. */
    ship_case c2;
    ship_case_open(&c2, s, 4.0, "fish.z");
    ts_seastate_compute(sys, s->lin, &c2.w, &out, &o, &r, &err);
    CHECK_REL(r->sigma.value, 2 * sigma1, 1e-12, "sigma doubles with Hs");
    ts_seastate_free(r);
    ship_case_close(&c2);

    /* Symmetry: head seas move the fish in its vertical plane only. */
    ts_output outy;
    ts_response_output_find(sys, "fish.y", &outy, &err);
    ts_seastate_compute(sys, s->lin, &w, &outy, &o, &r, &err);
    CHECK(r->sigma.value <= 1e-12 * sigma1, "no sway of the fish in head "
          "seas (sigma %.2g m)", r->sigma.value);
    ts_seastate_free(r);

    /* A tension output. */
    ts_output outt;
    ts_response_output_find(sys, "cable.1.tension", &outt, &err);
    rc = ts_seastate_compute(sys, s->lin, &w, &outt, &o, &r, &err);
    CHECK(rc == TS_OK && !strcmp(r->unit, "N") && r->sigma.value > 0 &&
              fabs(r->mean - s->eq->tensions[0]) < 1e-9 * r->mean,
          "top tension: sigma %.4g N about %.6g N", r ? r->sigma.value : 0,
          r ? r->mean : 0);
    ts_seastate_free(r);

    /* Following seas, the tow point on the surface: the encounter
     * frequency changes sign at w = g / U. */
    ts_sea *fol = ts_sea_jonswap(1.0, 3.0, 3.3, 0.0, &err);
    ts_seaway wf;
    ts_seaway_init(&wf, sys, fol, NULL, NULL, &err);
    ts_output outx;
    ts_response_output_find(sys, "fish.x", &outx, &err);
    ts_seastate_opts_default(&o);
    rc = ts_seastate_compute(sys, s->lin, &wf, &outx, &o, &r, &err);
    int neg = 0;
    for (int i = 0; rc == TS_OK && i < r->npoints; i++)
        neg += r->omega_e[i] < 0;
    qctx qf = {sys, s->lin, &wf, &outx, 0.0, 0};
    worst = 0;
    for (int i = 0; rc == TS_OK && i < r->npoints; i += 5) {
        double complex g = gain_direct(&qf, r->omega[i]);
        worst = fmax(worst, cabs(g - (r->gain_re[i] + I * r->gain_im[i])) /
                                (cabs(g) + 1e-300));
    }
    CHECK(rc == TS_OK && neg > 10 && worst <= 1e-12,
          "following seas: %d points with w_e < 0, gain conjugated there "
          "(max rel diff %.2g)", neg, worst);
    ts_seastate_free(r);
    ts_sea_free(fol);
    ship_case_close(&c);
}

static void test_discretisation(setup *s)
{
    ts_err err = {0};
    ts_rao *rao = ship_rao();
    ts_sea *sea = ts_sea_jonswap(2.0, 7.5, 3.3, M_PI, &err);
    ts_seastate_opts o;
    ts_seastate_opts_default(&o);
    o.intervals = 64;
    double sigma[3], est[2];
    static const int links[3] = {8, 16, 32};
    for (int i = 0; i < 3; i++) {
        ts_system *sys = ts_conv_system_with_links(s->scene->system,
                                                   links[i], &err);
        ts_kernel *k = ts_kernel_alloc(sys, &err);
        ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
        ts_equilibrium_opts eo;
        ts_equilibrium_opts_default(&eo);
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        ts_linear *lin = ts_linear_alloc(k, &err);
        ts_seaway w;
        ts_output out;
        ts_seastate *r = NULL;
        int rc = ts_equilibrium_solve(k, &eo, eq, &err);
        if (!rc)
            rc = ts_linearize_equilibrium(k, eq, &lo, lin, &err);
        if (!rc)
            rc = ts_seaway_init(&w, sys, sea, rao, reference_point, &err);
        if (!rc)
            rc = ts_response_output_find(sys, "fish.z", &out, &err);
        if (!rc)
            rc = ts_seastate_compute(sys, lin, &w, &out, &o, &r, &err);
        if (!rc && i < 2)
            rc = ts_seastate_discretisation(sys, &eo, &w, &o, r, &err);
        if (CHECK(rc == TS_OK, "%d links: %s", links[i], err.msg)) {
            sigma[i] = r->sigma.value;
            if (i < 2) {
                est[i] = r->sigma.discretisation;
                CHECK(r->disc_estimated && r->disc_links[0] == links[i] / 4 &&
                          r->disc_links[1] == links[i] / 2 &&
                          fabs(r->sigma.error - (r->sigma.grid +
                                                 r->sigma.band + est[i])) <=
                              1e-15 * r->sigma.error,
                      "%d links: discretisation from %d and %d links, in "
                      "the error", links[i], r->disc_links[0],
                      r->disc_links[1]);
            } else {
                ts_err e = {0};
                ts_system *odd = ts_system_copy(sys, &err);
                odd->cables[0].nlinks = 5;
                ts_system_build(odd, &err);
                CHECK(ts_seastate_discretisation(odd, &eo, &w, &o, r, &e) ==
                              TS_EDOMAIN &&
                          strstr(e.msg, "at least 8"),
                      "too few links refused: %s", e.msg);
                ts_system_free(odd);
            }
        }
        ts_seastate_free(r);
        ts_linear_free(lin);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        ts_system_free(sys);
    }
    for (int i = 0; i < 2; i++) {
        double truth = fabs(sigma[i] - sigma[2]);
        printf("  %d links: sigma %.6g m, discretisation error %.3g "
               "estimated, %.3g against 32 links\n", links[i], sigma[i],
               est[i], truth);
        CHECK(est[i] >= truth && est[i] <= 30 * truth, "%d links: the "
              "estimate bounds the error, within a factor 30 (%.3g)",
              links[i], est[i] / truth);
    }
    ts_sea_free(sea);
    ts_rao_free(rao);
}

static void test_record(void)
{
    ts_err err = {0};
    /* A sinusoid over whole periods. */
    const int n = 4000;
    const double dt = 0.05, T = 6.25, A = 1.7;
    double *x = malloc(n * sizeof *x);
    for (int i = 0; i < n; i++)
        x[i] = 3.0 + A * sin(2 * M_PI * i * dt / T + 0.3);
    ts_record_stats st;
    int rc = ts_record_stats_compute(x, n, dt, &st, &err);
    CHECK(rc == TS_OK && fabs(st.mean - 3.0) < 1e-3 &&
              fabs(st.sigma.value - A / sqrt(2)) < 1e-3 * A,
          "sinusoid: mean 3, sigma A/sqrt 2 (%.6g, %.6g)", st.mean,
          st.sigma.value);
    CHECK_REL(st.tz, T, 1e-6, "sinusoid: Tz its period");
    CHECK_NEAR(st.maximum, 3 + A, 1e-3, "maximum");
    ts_err e = {0};
    CHECK(ts_record_stats_compute(x, 10, dt, &st, &e) == TS_EINVAL,
          "short record refused");
    x[7] = NAN;
    CHECK(ts_record_stats_compute(x, n, dt, &st, &e) == TS_EINVAL &&
              strstr(e.msg, "sample 7"),
          "NaN refused: %s", e.msg);
    free(x);
}

static void test_realisation(setup *s)
{
    ts_err err = {0};
    const ts_system *sys = s->scene->system;
    ts_sea *sea = ts_sea_jonswap(1.0, 7.5, 3.3, M_PI, &err);
    ts_seaway w;
    ts_seaway_init(&w, sys, sea, NULL, NULL, &err);
    ts_sea_realisation r;
    ts_sea_realisation_default(&w, &r);
    CHECK(r.rise == 15.0 && r.components == TS_SEA_COMPONENTS,
          "defaults: fade-in 2 Tp");
    ts_excitation *a = ts_excitation_alloc(&err);
    ts_excitation *b = ts_excitation_alloc(&err);
    ts_excitation *c = ts_excitation_alloc(&err);
    double m0a;
    ts_seaway_excitation(&w, &r, a, &m0a, &err);
    ts_seaway_excitation(&w, &r, b, NULL, &err);
    r.seed = 2;
    ts_seaway_excitation(&w, &r, c, NULL, &err);
    int same = 1, differ = 0;
    for (int i = 0; i < 50; i++) {
        double ua[TS_NINPUT], ub[TS_NINPUT], uc[TS_NINPUT];
        ts_excitation_input(a, 20 + i * 1.3, ua);
        ts_excitation_input(b, 20 + i * 1.3, ub);
        ts_excitation_input(c, 20 + i * 1.3, uc);
        same &= !memcmp(ua, ub, sizeof ua);
        differ |= ua[2] != uc[2];
    }
    CHECK(same && differ, "a realisation is reproducible from its seed and "
          "differs with it");
    CHECK(ts_excitation_nsignals(a) == 1 &&
              ts_excitation_signal(a, 0)->axis == TS_AXIS_HEAVE,
          "surface follower: heave only");
    CHECK(m0a < 1.0 / 16 && m0a > (1 - 2e-3) / 16,
          "the realisation's band holds all but 1e-3 of m0 (%.6g)",
          m0a * 16);
    ts_excitation_free(a);
    ts_excitation_free(b);
    ts_excitation_free(c);

    /* The error estimate against the spread over 40 realisations. */
    const double dt = 0.25, T = 300;
    const int n = (int)(T / dt), R = 40;
    double *x = malloc(n * sizeof *x), s1 = 0, s2 = 0, e1 = 0;
    r.rise = 0;
    r.components = 512;
    for (int seed = 1; seed <= R; seed++) {
        r.seed = (unsigned long)seed;
        ts_excitation *ex = ts_excitation_alloc(&err);
        ts_seaway_excitation(&w, &r, ex, NULL, &err);
        for (int i = 0; i < n; i++) {
            double u[TS_NINPUT];
            ts_excitation_input(ex, i * dt, u);
            x[i] = u[2];
        }
        ts_record_stats st;
        ts_record_stats_compute(x, n, dt, &st, &err);
        s1 += st.sigma.value;
        s2 += st.sigma.value * st.sigma.value;
        e1 += st.sigma.error;
        ts_excitation_free(ex);
    }
    free(x);
    double mean = s1 / R, spread = sqrt((s2 - R * mean * mean) / (R - 1));
    double ratio = e1 / R / spread;
    printf("  40 records of %g s: sigma %.5g (band %.5g), spread %.3g, "
           "estimated error %.3g\n", T, mean, sqrt(m0a), spread, e1 / R);
    CHECK(ratio >= 0.7 && ratio <= 2.0, "statistical error estimate / "
          "spread over realisations = %.3g, in [0.7, 2]", ratio);
    ts_sea_free(sea);
}

static void test_cross_check(setup *s)
{
    ts_err err = {0};
    const ts_system *sys = s->scene->system;
    ship_case c;
    ship_case_open(&c, s, 0.5, "fish.z");
    ts_seaway w = c.w;
    ts_output out = c.out;
    ts_sea_realisation r;
    ts_sea_realisation_default(&w, &r);
    r.seed = 11;
    double lo, hi;
    ts_seaway_band(&w, TS_SEA_REALISATION_TAIL, &lo, &hi, &err);
    ts_seastate_opts o;
    ts_seastate_opts_default(&o);
    o.omega_lo = lo;
    o.omega_hi = hi;
    ts_seastate *sp = NULL;
    ts_seastate_compute(sys, s->lin, &w, &out, &o, &sp, &err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    int rc = ts_seaway_excitation(&w, &r, ex, NULL, &err);
    ts_sim_opts so;
    ts_sim_opts_default(&so);
    so.t_end = 1200;
    so.dt_sample = 0.25;
    const double transient = 200;
    int ns = ts_sim_nsamples(&so);
    ts_history *hl = ts_history_alloc(sys, ns, &err);
    ts_history *hn = ts_history_alloc(sys, ns, &err);
    double *x = malloc(ns * sizeof *x), dt;
    int n;
    ts_record_stats st;
    if (!rc)
        rc = ts_simulate_linear(s->k, s->lin, ex, NULL, &so, hl, NULL, &err);
    if (!rc)
        rc = ts_record_from_history(hl, &out, transient, x, &n, &dt, &err);
    if (!rc)
        rc = ts_record_stats_compute(x, n, dt, &st, &err);
    if (CHECK(rc == TS_OK, "linear run: %s", err.msg)) {
        double d = fabs(st.sigma.value - sp->sigma.value);
        double tol = 3 * (st.sigma.error + sp->sigma.error);
        CHECK(d <= tol, "linear time domain sigma %.5g +- %.2g m against "
              "spectral %.5g +- %.2g m: |diff| %.2g <= %.2g",
              st.sigma.value, st.sigma.error, sp->sigma.value,
              sp->sigma.error, d, tol);
    }
    ts_kernel *knl = ts_kernel_clone(s->k, &err);
    ts_sim_stats ss;
    rc = ts_simulate(knl, ex, s->eq->y, &so, hn, &ss, NULL, &err);
    if (!rc)
        rc = ts_record_from_history(hn, &out, transient, x, &n, &dt, &err);
    if (!rc)
        rc = ts_record_stats_compute(x, n, dt, &st, &err);
    if (CHECK(rc == TS_OK, "nonlinear run: %s", err.msg)) {
        double d = fabs(st.sigma.value - sp->sigma.value);
        double tol = 3 * (st.sigma.error + sp->sigma.error);
        CHECK(d <= tol, "nonlinear time domain sigma %.5g +- %.2g m against "
              "spectral %.5g +- %.2g m: |diff| %.2g <= %.2g (%ld steps)",
              st.sigma.value, st.sigma.error, sp->sigma.value,
              sp->sigma.error, d, tol, ss.steps);
        printf("  nonlinear mean depth %.5g m, equilibrium %.5g m\n",
               st.mean, sp->mean);
    }
    /* The linear run's tensions (dT/dy z + dT/du v, recorded sample by
     * sample) against the spectral statistics of the same tension (the
     * frequency response through the same Jacobians). */
    ts_output tens;
    ts_response_output_find(sys, "cable.1.tension", &tens, &err);
    ts_seastate *spt = NULL;
    rc = ts_seastate_compute(sys, s->lin, &w, &tens, &o, &spt, &err);
    if (!rc)
        rc = ts_record_from_history(hl, &tens, transient, x, &n, &dt, &err);
    if (!rc)
        rc = ts_record_stats_compute(x, n, dt, &st, &err);
    if (CHECK(rc == TS_OK, "linear run, tension: %s", err.msg)) {
        double d = fabs(st.sigma.value - spt->sigma.value);
        double tol = 3 * (st.sigma.error + spt->sigma.error);
        CHECK(d <= tol, "linear time domain tension sigma %.5g +- %.2g N "
              "against spectral %.5g +- %.2g N: |diff| %.2g <= %.2g",
              st.sigma.value, st.sigma.error, spt->sigma.value,
              spt->sigma.error, d, tol);
        CHECK(fabs(st.mean - spt->mean) <= tol,
              "linear time domain mean tension %.6g N against the "
              "equilibrium's %.6g N within %.2g N", st.mean, spt->mean, tol);
    }
    ts_seastate_free(spt);
    ts_output force;
    ts_output_find(sys, "tow.force", TS_OUT_ALL, &force, &err);
    ts_err e = {0};
    CHECK(ts_record_from_history(hl, &force, transient, x, &n, &dt, &e) ==
                  TS_EINVAL &&
              strstr(e.msg, "nonlinear runs only"),
          "the tow force from a linear history refused: %s", e.msg);
    free(x);
    ts_history_free(hl);
    ts_history_free(hn);
    ts_kernel_free(knl);
    ts_excitation_free(ex);
    ts_seastate_free(sp);
    ship_case_close(&c);
}

int main(void)
{
    ts_err err = {0};
    units = ts_units_alloc(&err);
    setup s;
    if (!units || !setup_open(&s, fish_yaml)) {
        printf("FAIL setup\n");
        return 1;
    }
    test_seaway(&s);
    test_spectral(&s);
    test_discretisation(&s);
    test_record();
    test_realisation(&s);
    test_cross_check(&s);
    setup_close(&s);
    ts_units_free(units);
    return tc_done();
}
