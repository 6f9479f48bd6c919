/* cmd_response.c: `towstab response SCENE` and the `response` analysis of
 * a scene: how tow-point motion passes down to a node, a body or a link
 * tension, over a log-spaced frequency list (doc/linear.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"

/* The plot quantities of a response's unit "OUT/IN" (m, N or rad). */
static ts_plot_quantity unit_quantity(const char *u, size_t len)
{
    if (len == 1 && u[0] == 'N')
        return TS_PLOT_FORCE;
    if (len == 3 && strncmp(u, "rad", 3) == 0)
        return TS_PLOT_ANGLE;
    return TS_PLOT_LENGTH;
}

static void unit_quantities(const char *unit, ts_plot_quantity *out_q,
                            ts_plot_quantity *in_q)
{
    const char *slash = strchr(unit, '/');
    size_t lo = slash ? (size_t)(slash - unit) : strlen(unit);
    *out_q = unit_quantity(unit, lo);
    *in_q = slash ? unit_quantity(slash + 1, strlen(slash + 1))
                  : TS_PLOT_LENGTH;
}

static void print_response(const ts_result *res, int quiet,
                           const ts_display *d)
{
    const ts_response *r = res->response;
    char e[160] = "", gu[64], fu[64];
    double k = ts_display_convert(d, r->unit, 1.0, gu, sizeof gu);
    double kf = ts_display_convert(d, "Hz", 1.0, fu, sizeof fu);
    if (res->nvalues > 0)
        cli_value_error(&res->values[0], d, e, sizeof e);
    if (isfinite(r->static_gain))
        printf("response of %s to %s (%s): static gain %.9g %s\n",
               r->output.name, r->input_name, gu, k * r->static_gain, e);
    else
        printf("response of %s to %s (%s): static gain %s\n",
               r->output.name, r->input_name, gu,
               r->static_note[0] ? r->static_note : "undefined");
    int ib = 0;
    for (int i = 1; i < r->npoints; i++)
        if (r->magnitude[i] > r->magnitude[ib])
            ib = i;
    if (res->nvalues > 1)
        cli_value_error(&res->values[1], d, e, sizeof e);
    printf("largest magnitude %.6g %s at %.6g %s (phase %.3f deg)\n",
           k * r->magnitude[ib], e, kf * r->freq_hz[ib], fu,
           r->phase_deg[ib]);
    if (res->magnitude_error)
        printf("the magnitude meets the accuracy %.3g (of the largest) up to "
               "%s%.6g %s%s\n",
               res->accuracy.accuracy,
               isfinite(res->accurate_to_hz) ? "" : "(no point) ",
               kf * (isfinite(res->accurate_to_hz) ? res->accurate_to_hz
                                                   : r->freq_hz[0]),
               fu,
               isfinite(res->accurate_to_hz) &&
                       res->accurate_to_hz >= r->freq_hz[r->npoints - 1]
                   ? ", the whole range"
                   : "");
    if (quiet)
        return;
    char h[2][80];
    snprintf(h[0], sizeof h[0], "freq [%s]", fu);
    snprintf(h[1], sizeof h[1], "magnitude [%s]", gu);
    printf("\n%14s %20s %10s %12s %10s\n", h[0], h[1], "+- disc.",
           "phase [deg]", "+- disc.");
    for (int i = 0; i < r->npoints; i++) {
        printf("%14.6g %20.9g", kf * r->freq_hz[i], k * r->magnitude[i]);
        if (res->magnitude_error)
            printf(" %10.2g", k * res->magnitude_error[i]);
        else
            printf(" %10s", "-");
        printf(" %12.4f", r->phase_deg[i]);
        if (res->phase_error_deg)
            printf(" %10.2g\n", res->phase_error_deg[i]);
        else
            printf(" %10s\n", "-");
    }
}


/* Rows of the spectrum table printed (every k-th grid point). */
#define SEA_TABLE_ROWS 32

static void print_stat(const char *what, const ts_stat *s, double k,
                       const char *unit, int disc)
{
    if (!isfinite(s->value)) {
        printf("  %-36s %12s (not defined here)\n", what, "none");
        return;
    }
    char dt[48] = "discretisation not estimated";
    if (disc && isfinite(s->discretisation))
        snprintf(dt, sizeof dt, "discretisation %.2g", k * s->discretisation);
    printf("  %-36s %12.6g %s +- %.2g (grid %.2g, band %.2g, %s)\n", what,
           k * s->value, unit, k * s->error, k * s->grid, k * s->band, dt);
}

/* The statistics of a spectral result (towstab/seastate.h), each with its
 * error, in the display units d (the output's unit, lengths, speeds and
 * times; the wave frequencies stay in rad/s); with !quiet, the spectra on
 * a coarse grid. */
void cli_print_seastate(const ts_result *r, int quiet, const ts_display *d)
{
    const ts_seastate *s = r->seastate;
    const ts_seaway *w = &r->seaway;
    d = ts_display_or_si(d);
    const char *lu = ts_display_unit(d, TS_QTY_LENGTH);
    const char *su = ts_display_unit(d, TS_QTY_SPEED);
    const char *tu = ts_display_unit(d, TS_QTY_TIME);
    char desc[512];
    ts_sea_describe(w->sea, desc, sizeof desc);
    printf("sea: %s\n", desc);
    if (r->rao_file[0])
        printf("ship RAOs: %s; lever arm (tow point less reference point) "
               "%g, %g, %g %s; speed %.6g %s\n", r->rao_file,
               ts_display_value(d, TS_QTY_LENGTH, w->lever[0]),
               ts_display_value(d, TS_QTY_LENGTH, w->lever[1]),
               ts_display_value(d, TS_QTY_LENGTH, w->lever[2]), lu,
               ts_display_value(d, TS_QTY_SPEED, w->speed), su);
    else
        printf("ship RAOs: none: the tow point follows the water surface; "
               "speed %.6g %s\n", ts_display_value(d, TS_QTY_SPEED, w->speed),
               su);
    if (!s)
        return;
    printf("band %.4g to %.4g rad/s (%.3g %% of the wave variance outside), "
           "%d intervals in ln w, %ld gains\n", s->band_lo, s->band_hi,
           100 * s->wave_m0_out / (s->wave_m0_band + s->wave_m0_out),
           s->npoints - 1, s->responses);
    int disc = s->disc_estimated;
    char ou[64];
    double k = ts_display_convert(d, s->unit, 1.0, ou, sizeof ou);
    double kt = ts_display_value(d, TS_QTY_TIME, 1.0);
    printf("%s about its equilibrium value %.6g %s:\n", s->output.name,
           k * s->mean, ou);
    print_stat("standard deviation sigma", &s->sigma, k, ou, disc);
    print_stat("significant amplitude 2 sigma", &s->significant, k, ou,
               disc);
    print_stat("zero up-crossing period Tz", &s->tz, kt, tu, disc);
    char mp[96];
    snprintf(mp, sizeof mp, "most probable maximum in %.6g %s",
             kt * s->duration, tu);
    print_stat(mp, &s->mpm, k, ou, disc);
    if (isfinite(s->mpm.value))
        printf("  (%.4g cycles: most probable largest %.6g %s, smallest %.6g "
               "%s)\n", s->cycles, k * (s->mean + s->mpm.value), ou,
               k * (s->mean - s->mpm.value), ou);
    if (disc) {
        char order[48] = "no steady observed order";
        if (isfinite(s->disc_order))
            snprintf(order, sizeof order, "observed order %.3g",
                     s->disc_order);
        printf("discretisation error from %d, %d and %d links per cable "
               "(%s), %.3f s\n", s->disc_links[0], s->disc_links[1],
               s->disc_links[2], order, s->disc_wall_s);
    }
    if (quiet)
        return;
    /* The wave's elevation spectrum in length^2 s/rad, the gain in the
     * output's unit per length, the output's spectrum in its unit^2
     * s/rad. */
    double kl = ts_display_value(d, TS_QTY_LENGTH, 1.0);
    char hs[64], hg[80], ho[80];
    snprintf(hs, sizeof hs, "S [%s^2 s/rad]", lu);
    snprintf(hg, sizeof hg, "|G| [%s/%s]", ou, lu);
    snprintf(ho, sizeof ho, "S_out [%s^2 s/rad]", ou);
    printf("\n%12s %12s %16s %16s %20s\n", "w [rad/s]", "w_e [rad/s]", hs, hg,
           ho);
    int step = (s->npoints - 1) / SEA_TABLE_ROWS;
    if (step < 1)
        step = 1;
    for (int i = 0; i < s->npoints; i += step)
        printf("%12.5g %12.5g %16.6g %16.6g %20.6g\n", s->omega[i],
               s->omega_e[i], kl * kl * s->wave[i],
               k / kl * hypot(s->gain_re[i], s->gain_im[i]),
               k * k * s->density[i]);
}

static void response_print(const cli_run *c, const ts_result *r)
{
    cli_print_equilibrium(r, 1, &c->display);
    cli_print_linearization(r);
    if (r->has_sea) {
        cli_print_seastate(r, c->quiet, &c->display);
        if (r->seastate)
            cli_print_trust(&r->trust);
        return;
    }
    if (!r->response)
        return;
    if (r->lin->kink_tow && r->response->input == 2)
        printf("warning: the tow point is at the water surface: the "
               "heave response uses the mean of the one-sided "
               "derivatives, and a real heave also shifts the mean "
               "depth at first order (doc/model.md section 6)\n");
    print_response(r, c->quiet, &c->display);
    cli_print_accuracy(r);
    cli_print_trust(&r->trust);
}

static int response_prepare(cli_run *c)
{
    if (c->plot.dir && c->rq.response.sea.sea && c->plot_optional)
        c->plot.dir = NULL; /* there is no picture of it */
    if (c->plot.dir && c->rq.response.sea.sea) {
        fprintf(stderr, "towstab: error: response: --plot draws a Bode plot, "
                        "which a sea-state response has not; write its "
                        "spectra with --csv (or --json) instead\n");
        return EXIT_BADINPUT;
    }
    if (c->nextra[0] && !c->plot.dir) {
        fprintf(stderr, "towstab: error: response: --db sets the Bode "
                        "plot's magnitude axis; add --plot DIR\n");
        return EXIT_BADINPUT;
    }
    /* The Bode plot marks the natural frequencies. */
    c->rq.response.natural = c->plot.dir != NULL;
    return 0;
}

/* The Bode plot with the natural frequencies marked. */
static int response_draw(cli_run *c, const ts_result *r)
{
    if (!c->plot.dir || r->status != TS_OK || !r->response)
        return 0;
    const ts_response *res = r->response;
    const cli_plot *plot = &c->plot;
    int status = 0;
    {
        /* Phase unwrapped for drawing, in radians. */
        double *ph = malloc((size_t)res->npoints * sizeof(double));
        if (!ph) {
            fprintf(stderr, "towstab: error: response: --plot: out of "
                            "memory\n");
            status = EXIT_FAILED;
        } else {
            double shift = 0.0;
            for (int i = 0; i < res->npoints; i++) {
                double p = res->phase_deg[i] * M_PI / 180.0;
                if (i > 0) {
                    double prev = ph[i - 1] - shift;
                    if (p - prev > M_PI)
                        shift -= 2 * M_PI;
                    else if (p - prev < -M_PI)
                        shift += 2 * M_PI;
                }
                ph[i] = p + shift;
            }
            char title[256], mag_label[2 * TS_IO_NAME + 8];
            snprintf(title, sizeof title, "%s: frequency response",
                     r->sys->name);
            snprintf(mag_label, sizeof mag_label, "%s / %s",
                     res->output.name, res->input_name);
            ts_plot_bode_curve bc = {res->npoints, res->freq_hz,
                                     res->magnitude, ph, mag_label,
                                     TS_PLOT_SOLID, 0};
            ts_plot_quantity out_q, in_q;
            unit_quantities(res->unit, &out_q, &in_q);
            ts_err perr = {0};
            ts_plot_opts po = plot->opts;
            po.bode_db = c->nextra[0] > 0; /* --db */
            if (ts_plot_bode(plot->dir, "bode", title, mag_label, out_q,
                             in_q, 1, &bc, r->nnatural, r->natural_hz, &po,
                             &perr) != TS_OK)
                status = cli_report(&perr, perr.code);
            else
                cli_plot_wrote(plot, "bode");
            free(ph);
        }
    }
    return status;
}

static const char *const response_pictures[] = {"bode", NULL};

static const cli_extra response_extras[] = {
    {"db", 0, 0, NULL,
     "the Bode plot's magnitude in dB (20 log10 |H|) with --plot"},
    {NULL, 0, 0, NULL, NULL}};

const cli_command cli_cmd_response = {
    "response", "frequency response to tow-point motion or a vehicle's input",
    TS_ANALYSIS_RESPONSE, NULL, response_prepare, response_print,
    response_draw, NULL, response_pictures, response_extras, NULL};
