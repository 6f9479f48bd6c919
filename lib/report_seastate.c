/* report_seastate.c: JSON (jansson) and CSV of sea-state results
 * (towstab/report_seastate.h). Files go through lib/outfile.h: a failed
 * write leaves no file that looks finished. */
#include "towstab/report_seastate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "outfile.h"
#include "towstab/linearize.h"
#include "towstab/report.h"

/* A JSON number, or null for a value that is not finite. */
static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

/* {"value", "error", "error_parts": {"grid", "band", "discretisation"}};
 * the discretisation part is null when it was not estimated. */
static json_t *stat(ts_stat s, int disc)
{
    return json_pack("{s:o,s:o,s:{s:o,s:o,s:o}}", "value", num(s.value),
                     "error", num(s.error), "error_parts", "grid",
                     num(s.grid), "band", num(s.band), "discretisation",
                     disc ? num(s.discretisation) : json_null());
}

/* s times k, and shifted by `shift`. */
static ts_stat scaled(ts_stat s, double k, double shift)
{
    ts_stat t = {shift + k * s.value, k * s.error, k * s.grid, k * s.band,
                 k * s.discretisation};
    return t;
}

json_t *ts_report_sea_json(const ts_sea *s)
{
    ts_sea_info in;
    ts_sea_get_info(s, &in);
    static const char *const kinds[3] = {"pierson-moskowitz", "jonswap",
                                         "table"};
    return json_pack("{s:s,s:o,s:o,s:o,s:o,s:o,s:o,s:s}", "spectrum",
                     kinds[in.kind], "hs", num(in.hs), "tp", num(in.tp),
                     "gamma", num(in.gamma), "normalisation", num(in.norm),
                     "heading_deg", num(in.heading * 180 / M_PI), "m0",
                     num(in.m0), "source", in.source ? in.source : "");
}

json_t *ts_report_seastate_json(const ts_seastate *r, const ts_seaway *w,
                                int spectrum)
{
    int d = r->disc_estimated;
    /* The lever the RAO translation is taken at: the tow point's, or with
     * a towing vehicle its origin O's (towstab/seastate.h). */
    double lever[3];
    for (int c = 0; c < 3; c++)
        lever[c] = w->rotations ? w->origin[c] - w->reference[c]
                                : w->lever[c];
    json_t *stats = json_pack(
        "{s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o}", "sigma",
        stat(r->sigma, d), "significant_amplitude", stat(r->significant, d),
        "significant_double_amplitude", stat(scaled(r->significant, 2, 0), d),
        "tz_s", stat(r->tz, d), "most_probable_maximum", stat(r->mpm, d),
        "most_probable_largest", stat(scaled(r->mpm, 1, r->mean), d),
        "most_probable_smallest", stat(scaled(r->mpm, -1, r->mean), d),
        "m0", stat(r->m0, 0), "m2", stat(r->m2, 0), "duration_s",
        num(r->duration), "cycles", num(r->cycles));
    json_t *o = json_pack(
        "{s:s,s:s,s:o,s:o,s:[o,o,o],s:{s:o,s:o,s:o,s:o},s:{s:i,s:o,s:o,s:I},"
        "s:o}",
        "output", r->output.name, "unit", r->unit, "mean", num(r->mean),
        "speed", num(w->speed), "lever", num(lever[0]),
        num(lever[1]), num(lever[2]), "band", "from_rad_s",
        num(r->band_lo), "to_rad_s", num(r->band_hi), "wave_m0_band",
        num(r->wave_m0_band), "wave_m0_outside", num(r->wave_m0_out),
        "grid", "intervals", r->npoints - 1, "order_m0", num(r->order_m0),
        "order_m2", num(r->order_m2), "responses", (json_int_t)r->responses,
        "statistics", stats ? stats : json_null());
    if (!o)
        return NULL;
    json_t *sea = ts_report_sea_json(w->sea);
    if (sea)
        json_object_set_new(o, "sea", sea);
    json_t *disc = d ? json_pack("{s:b,s:[i,i,i],s:o,s:o,s:o}", "estimated",
                                 1, "links", r->disc_links[0],
                                 r->disc_links[1], r->disc_links[2], "order",
                                 num(r->disc_order), "wall_s",
                                 num(r->disc_wall_s), "links_needed",
                                 num(r->disc_links_needed))
                     : json_pack("{s:b}", "estimated", 0);
    if (disc)
        json_object_set_new(o, "discretisation", disc);
    json_t *tj = ts_report_trust_json(&r->trust);
    if (tj) {
        json_object_update(o, tj);
        json_decref(tj);
    }
    if (spectrum) {
        json_t *pts = json_array();
        for (int i = 0; pts && i < r->npoints; i++)
            json_array_append_new(
                pts, json_pack("{s:o,s:o,s:o,s:o,s:o,s:o}", "omega_rad_s",
                               num(r->omega[i]), "omega_e_rad_s",
                               num(r->omega_e[i]), "wave", num(r->wave[i]),
                               "gain_re", num(r->gain_re[i]), "gain_im",
                               num(r->gain_im[i]), "density",
                               num(r->density[i])));
        if (!pts) {
            json_decref(o);
            return NULL;
        }
        json_object_set_new(o, "points", pts);
    }
    return o;
}

int ts_report_seastate_csv(const ts_seastate *r, const char *path,
                           ts_err *err)
{
    return ts_report_seastate_csv_display(r, NULL, path, err);
}

int ts_report_seastate_csv_display(const ts_seastate *r, const ts_display *d,
                                   const char *path, ts_err *err)
{
    d = ts_display_or_si(d);
    char lu[64], ou[64], gu[160], ot[64], gt[160];
    ts_display_unit_token(ts_display_unit(d, TS_QTY_LENGTH), lu, sizeof lu);
    double kl = ts_display_value(d, TS_QTY_LENGTH, 1.0);
    double ko = ts_display_convert(d, r->unit, 1.0, ou, sizeof ou);
    ts_display_unit_token(ou, ot, sizeof ot);
    /* The gain is the output per length of wave amplitude. */
    snprintf(gu, sizeof gu, "%s/%s", ou, ts_display_unit(d, TS_QTY_LENGTH));
    ts_display_unit_token(gu, gt, sizeof gt);
    int si = kl == 1.0 && ko == 1.0;
    tsi_outfile out;
    int orc = tsi_outfile_open(&out, path, err);
    if (orc != TS_OK)
        return orc;
    FILE *f = out.f;
    fprintf(f, "omega_rad_s,omega_e_rad_s,wave_%s2_s_rad", lu);
    for (int j = 0; j < r->ninputs; j++) {
        const char *nm = ts_input_name(r->channel[j]);
        fprintf(f, ",%s_re,%s_im", nm, nm);
    }
    if (si)
        fprintf(f, ",gain_re,gain_im,gain_abs,density_%s2_s_rad\n", r->unit);
    else
        fprintf(f, ",gain_re_%s,gain_im_%s,gain_abs_%s,density_%s2_s_rad\n",
                gt, gt, gt, ot);
    double kg = ko / kl;
    size_t np = (size_t)r->npoints;
    for (size_t i = 0; i < np; i++) {
        fprintf(f, "%.17g,%.17g,%.17g", r->omega[i], r->omega_e[i],
                kl * kl * r->wave[i]);
        for (int j = 0; j < r->ninputs; j++)
            fprintf(f, ",%.17g,%.17g", r->input_re[(size_t)j * np + i],
                    r->input_im[(size_t)j * np + i]);
        fprintf(f, ",%.17g,%.17g,%.17g,%.17g\n", kg * r->gain_re[i],
                kg * r->gain_im[i], kg * hypot(r->gain_re[i], r->gain_im[i]),
                ko * ko * r->density[i]);
    }
    return tsi_outfile_commit(&out, err);
}

json_t *ts_report_record_json(const ts_record_stats *st)
{
    return json_pack("{s:i,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:i}",
                     "samples", st->nsamples, "duration_s",
                     num(st->duration), "mean", num(st->mean), "mean_error",
                     num(st->mean_error), "sigma",
                     json_pack("{s:o,s:o}", "value", num(st->sigma.value),
                               "error", num(st->sigma.error)),
                     "corr_time_s",
                     num(st->corr_time), "independent_samples",
                     num(st->independent), "tz_s", num(st->tz), "maximum",
                     num(st->maximum), "minimum", num(st->minimum),
                     "window_lags", st->window_lags);
}
