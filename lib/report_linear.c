/* report_linear.c: JSON (jansson) and CSV output of linearizations, modes
 * and frequency responses (towstab/report_linear.h). Every file goes
 * through tsi_outfile (lib/outfile.h), so a failed run leaves no file
 * that looks finished. */
#include "towstab/report_linear.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "outfile.h"
#include "towstab/report.h"

/* A JSON number, or null for a value that is not finite. */
static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

/* Rows of a column-major m x n matrix as a JSON array of arrays. */
static json_t *matrix_rows(const double *a, int m, int n, int ld)
{
    json_t *rows = json_array();
    for (int i = 0; rows && i < m; i++) {
        json_t *row = json_array();
        if (!row) {
            json_decref(rows);
            return NULL;
        }
        for (int j = 0; j < n; j++)
            json_array_append_new(row, num(a[i + (size_t)j * ld]));
        json_array_append_new(rows, row);
    }
    return rows;
}

json_t *ts_report_linear_json(const ts_linear *lin, int matrices)
{
    json_t *o = json_object(), *inputs = json_array();
    if (!o || !inputs) {
        json_decref(o);
        json_decref(inputs);
        return NULL;
    }
    for (int j = 0; j < lin->ninput; j++)
        json_array_append_new(inputs, json_string(lin->input_name[j]));
    json_object_set_new(o, "nstate", json_integer(lin->nstate));
    json_object_set_new(o, "nq", json_integer(lin->nq));
    json_object_set_new(o, "ninput", json_integer(lin->ninput));
    json_object_set_new(o, "inputs", inputs);
    json_object_set_new(o, "trunc_err", num(lin->trunc_err));
    json_object_set_new(o, "trunc_norm", num(lin->trunc_norm));
    json_object_set_new(o, "round_norm", num(lin->round_norm));
    json_object_set_new(o, "b_trunc_err", num(lin->b_trunc_err));
    json_object_set_new(o, "a_scale", num(lin->a_scale));
    json_object_set_new(o, "kinks", json_integer(lin->kinks));
    json_object_set_new(o, "kink_tow", json_boolean(lin->kink_tow));
    json_object_set_new(o, "evaluations", json_integer(lin->evaluations));
    json_object_set_new(o, "threads", json_integer(lin->threads));
    json_object_set_new(o, "model", json_string(lin->A ? (lin->desc ? "dense "
                                                      "and sparse" : "dense")
                                                : "sparse"));
    json_object_set_new(o, "groups", json_integer(lin->groups));
    json_object_set_new(o, "residual_evaluations",
                        json_integer(lin->residual_evaluations));
    json_object_set_new(o, "sparse_error", num(lin->desc_err));
    json_object_set_new(o, "sparse_rounding", num(lin->desc_round));
    if (matrices && lin->A && lin->B) {
        json_t *A = matrix_rows(lin->A, lin->nstate, lin->nstate,
                                lin->nstate);
        json_t *B = matrix_rows(lin->B, lin->nstate, lin->ninput,
                                lin->nstate);
        if (!A || !B) {
            json_decref(A);
            json_decref(B);
            json_decref(o);
            return NULL;
        }
        json_object_set_new(o, "A", A);
        json_object_set_new(o, "B", B);
    }
    return o;
}

static json_t *shape_json(const ts_system *sys, const ts_linear *lin,
                          const ts_eigen *e, int m, double *amp,
                          double *phase)
{
    if (ts_eigen_mode_shape(sys, lin, e, m, amp, phase, NULL) != TS_OK)
        return json_null();
    json_t *arr = json_array();
    char name[2 * TS_NAME_MAX];
    for (int i = 0; arr && i < sys->nnodes; i++) {
        const double *a = amp + 3 * i, *p = phase + 3 * i;
        ts_system_node_name(sys, i, name, sizeof name);
        json_array_append_new(
            arr, json_pack("{s:s,s:o,s:o,s:o,s:o,s:o,s:o}", "node", name,
                           "x_amp", num(a[0]), "x_phase_deg",
                           num(p[0] * 180 / M_PI), "y_amp", num(a[1]),
                           "y_phase_deg", num(p[1] * 180 / M_PI), "z_amp",
                           num(a[2]), "z_phase_deg", num(p[2] * 180 / M_PI)));
    }
    return arr ? arr : json_null();
}

json_t *ts_report_modes_json(const ts_system *sys, const ts_linear *lin,
                             const ts_eigen *e, int shapes)
{
    json_t *o = json_object(), *modes = json_array();
    double *amp = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    double *phase = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    if (!o || !modes || !amp || !phase) {
        json_decref(o);
        json_decref(modes);
        free(amp);
        free(phase);
        return NULL;
    }
    json_object_set_new(o, "stable", json_boolean(e->verdict == TS_STABLE));
    json_object_set_new(o, "verdict", json_string(ts_verdict_name(e->verdict)));
    json_object_set_new(o, "max_real", num(e->max_real));
    json_object_set_new(o, "max_real_error", num(e->max_real_error));
    json_object_set_new(o, "undecided_real", num(e->undecided_real));
    json_object_set_new(o, "undecided_error", num(e->undecided_error));
    json_object_set_new(o, "complete", json_boolean(e->complete));
    json_object_set_new(o, "neutral_modes", json_integer(e->nneutral));
    const ts_mode *r = &e->rightmost;
    json_object_set_new(o, "rightmost",
                        json_pack("{s:o,s:o,s:o,s:o,s:o,s:o,s:o}", "re",
                                  num(r->re), "im", num(r->im), "freq_hz",
                                  num(r->freq_hz), "damping_ratio",
                                  num(r->damping_ratio), "error_bound",
                                  num(r->error_bound), "residual",
                                  num(r->residual), "ritz_error",
                                  num(r->ritz_error)));
    if (e->sweep_shifts > 0)
        json_object_set_new(o, "search",
                            json_pack("{s:i,s:i,s:i,s:i,s:o}", "shifts",
                                      e->sweep_shifts, "failed",
                                      e->sweep_failed, "rejected",
                                      e->sweep_rejected, "found",
                                      e->sweep_found, "top_hz",
                                      num(e->top_hz)));
    json_object_set_new(o, "method", json_string(ts_eig_method_name(e->method)));
    json_object_set_new(o, "target_hz", num(e->target_hz));
    json_object_set_new(o, "nstate", json_integer(e->nstate));
    json_object_set_new(o, "nmodes", json_integer(e->nmodes));
    json_object_set_new(o, "kinks", json_integer(lin->kinks));
    json_object_set_new(o, "linearization_error", num(lin->trunc_norm));
    char desc[256];
    for (int m = 0; m < e->nmodes; m++) {
        const ts_mode *md = &e->modes[m];
        ts_eigen_describe(sys, lin, e, m, desc, sizeof desc);
        json_t *j = json_pack(
            "{s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:s}", "re",
            num(md->re), "im", num(md->im), "freq_hz", num(md->freq_hz),
            "period_s", num(md->period_s), "damping_ratio",
            num(md->damping_ratio), "time_constant_s",
            num(md->time_constant_s), "condition", num(md->condition),
            "error_bound", num(md->error_bound), "residual",
            num(md->residual), "ritz_error", num(md->ritz_error),
            "description", desc);
        if (j && md->neutral >= 0 && md->neutral < lin->nneutral)
            json_object_set_new(j, "neutral",
                                json_string(lin->neutral[md->neutral].name));
        if (j && shapes && e->vec_re)
            json_object_set_new(j, "shape",
                                shape_json(sys, lin, e, m, amp, phase));
        json_array_append_new(modes, j);
    }
    json_object_set_new(o, "modes", modes);
    free(amp);
    free(phase);
    return o;
}

int ts_report_modes_csv(const ts_system *sys, const ts_linear *lin,
                        const ts_eigen *e, const char *path, ts_err *err)
{
    return ts_report_modes_csv_display(sys, lin, e, NULL, path, err);
}

/* A column's unit as CSV names it: the SI name `si` when the display unit
 * of q is SI, else the display unit as a token. */
static void column_unit(const ts_display *d, ts_quantity q, const char *si,
                        char *buf, size_t size)
{
    const char *u = ts_display_unit(d, q);
    if (!strcmp(u, ts_quantity_si(q)))
        snprintf(buf, size, "%s", si);
    else
        ts_display_unit_token(u, buf, size);
}

int ts_report_modes_csv_display(const ts_system *sys, const ts_linear *lin,
                                const ts_eigen *e, const ts_display *d,
                                const char *path, ts_err *err)
{
    d = ts_display_or_si(d);
    char iu[64], fu[64], tu[64];
    column_unit(d, TS_QTY_ANGULAR_RATE, "rad_per_s", iu, sizeof iu);
    column_unit(d, TS_QTY_FREQUENCY, "hz", fu, sizeof fu);
    column_unit(d, TS_QTY_TIME, "s", tu, sizeof tu);
    double ki = ts_display_value(d, TS_QTY_ANGULAR_RATE, 1.0);
    double kf = ts_display_value(d, TS_QTY_FREQUENCY, 1.0);
    double kt = ts_display_value(d, TS_QTY_TIME, 1.0);
    tsi_outfile out;
    char desc[256];
    int orc = tsi_outfile_open(&out, path, err);
    if (orc != TS_OK)
        return orc;
    FILE *f = out.f;
    fprintf(f, "mode,re_per_s,im_%s,freq_%s,period_%s,damping_ratio,"
               "time_constant_%s,condition,error_bound,description\n",
            iu, fu, tu, tu);
    for (int m = 0; m < e->nmodes; m++) {
        const ts_mode *md = &e->modes[m];
        ts_eigen_describe(sys, lin, e, m, desc, sizeof desc);
        fprintf(f, "%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.6g,%.6g,\"%s\"\n",
                m + 1, md->re, ki * md->im, kf * md->freq_hz,
                kt * md->period_s, md->damping_ratio,
                kt * md->time_constant_s, md->condition, md->error_bound,
                desc);
    }
    return tsi_outfile_commit(&out, err);
}

int ts_report_shapes_csv(const ts_system *sys, const ts_linear *lin,
                         const ts_eigen *e, const char *path, ts_err *err)
{
    return ts_report_shapes_csv_display(sys, lin, e, NULL, path, err);
}

int ts_report_shapes_csv_display(const ts_system *sys, const ts_linear *lin,
                                 const ts_eigen *e, const ts_display *d,
                                 const char *path, ts_err *err)
{
    if (!e->vec_re)
        return ts_fail(err, TS_EINVAL,
                       "%s: no eigenvectors were kept, so no mode shapes",
                       path);
    d = ts_display_or_si(d);
    char fu[64], pu[64];
    column_unit(d, TS_QTY_FREQUENCY, "hz", fu, sizeof fu);
    /* Angles are shown in deg by default (their SI unit is rad). */
    const char *pa = ts_display_unit(d, TS_QTY_ANGLE);
    if (!strcmp(pa, "deg"))
        snprintf(pu, sizeof pu, "deg");
    else
        ts_display_unit_token(pa, pu, sizeof pu);
    double kf = ts_display_value(d, TS_QTY_FREQUENCY, 1.0);
    double *amp = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    double *phase = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    if (!amp || !phase) {
        free(amp);
        free(phase);
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
    }
    tsi_outfile out;
    char name[2 * TS_NAME_MAX];
    int orc = tsi_outfile_open(&out, path, err);
    if (orc != TS_OK) {
        free(amp);
        free(phase);
        return orc;
    }
    FILE *f = out.f;
    fprintf(f, "mode,freq_%s,node,x_amp,x_phase_%s,y_amp,y_phase_%s,z_amp,"
               "z_phase_%s\n", fu, pu, pu, pu);
    int rc = TS_OK;
    for (int m = 0; m < e->nmodes && rc == TS_OK; m++) {
        rc = ts_eigen_mode_shape(sys, lin, e, m, amp, phase, err);
        for (int i = 0; rc == TS_OK && i < sys->nnodes; i++) {
            const double *a = amp + 3 * i, *p = phase + 3 * i;
            ts_system_node_name(sys, i, name, sizeof name);
            fprintf(f, "%d,%.17g,%s,%.10g,%.6f,%.10g,%.6f,%.10g,%.6f\n", m + 1,
                    kf * e->modes[m].freq_hz, name, a[0],
                    ts_display_value(d, TS_QTY_ANGLE, p[0]), a[1],
                    ts_display_value(d, TS_QTY_ANGLE, p[1]), a[2],
                    ts_display_value(d, TS_QTY_ANGLE, p[2]));
        }
    }
    free(amp);
    free(phase);
    if (rc != TS_OK) {
        tsi_outfile_abandon(&out);
        return rc;
    }
    return tsi_outfile_commit(&out, err);
}

json_t *ts_report_response_json(const ts_response *r)
{
    json_t *o = json_object(), *pts = json_array();
    if (!o || !pts) {
        json_decref(o);
        json_decref(pts);
        return NULL;
    }
    json_object_set_new(o, "input", json_string(r->input_name));
    json_object_set_new(o, "output", json_string(r->output.name));
    json_object_set_new(o, "unit", json_string(r->unit));
    json_object_set_new(o, "static_gain", num(r->static_gain));
    if (r->static_note[0])
        json_object_set_new(o, "static_gain_note",
                            json_string(r->static_note));
    for (int i = 0; i < r->npoints; i++)
        json_array_append_new(
            pts, json_pack("{s:o,s:o,s:o,s:o,s:o}", "freq_hz",
                           num(r->freq_hz[i]), "magnitude",
                           num(r->magnitude[i]), "phase_deg",
                           num(r->phase_deg[i]), "re", num(r->re[i]), "im",
                           num(r->im[i])));
    json_object_set_new(o, "points", pts);
    return o;
}

int ts_report_response_csv(const ts_response *r, const char *path,
                           ts_err *err)
{
    return ts_report_response_csv_display(r, NULL, path, err);
}

int ts_report_response_csv_display(const ts_response *r, const ts_display *d,
                                   const char *path, ts_err *err)
{
    d = ts_display_or_si(d);
    char fu[64], gu[64], ft[64], gt[64];
    double fk = ts_display_convert(d, "Hz", 1.0, fu, sizeof fu);
    double gk = ts_display_convert(d, r->output.unit, 1.0, gu, sizeof gu);
    ts_display_unit_token(fu, ft, sizeof ft);
    ts_display_unit_token(gu, gt, sizeof gt);
    /* The SI names, unless the unit shown is another. */
    int gs = !strcmp(gu, r->output.unit);
    tsi_outfile out;
    int orc = tsi_outfile_open(&out, path, err);
    if (orc != TS_OK)
        return orc;
    FILE *f = out.f;
    fprintf(f, "freq_%s,magnitude%s%s,phase_deg,re%s%s,im%s%s\n",
            strcmp(fu, "Hz") ? ft : "hz", gs ? "" : "_", gs ? "" : gt,
            gs ? "" : "_", gs ? "" : gt, gs ? "" : "_", gs ? "" : gt);
    for (int i = 0; i < r->npoints; i++)
        fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g\n", fk * r->freq_hz[i],
                gk * r->magnitude[i], r->phase_deg[i], gk * r->re[i],
                gk * r->im[i]);
    return tsi_outfile_commit(&out, err);
}
