/* report_converge.c: JSON (jansson) and CSV of convergence studies and of
 * health verdicts (towstab/report_converge.h). Files go through
 * tsi_outfile (lib/outfile.h), so a failed run leaves no file that
 * looks finished. */
#include "towstab/report_converge.h"

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

/* A setting: whole links as an integer. */
static json_t *setting_json(const ts_convergence *c, double s)
{
    if (!isfinite(s))
        return json_null();
    return c->param == TS_CONV_LINKS ? json_integer((json_int_t)s)
                                     : json_real(s);
}

int ts_report_modes_health_json(json_t *modes, const ts_eigen *e,
                                const ts_mode_health mh[], const ts_trust *t)
{
    json_t *tj = ts_report_trust_json(t);
    if (!tj)
        return TS_ENOMEM;
    json_object_update(modes, tj);
    json_decref(tj);
    double ratio = e->max_real_error > 0
                       ? fabs(e->max_real) / e->max_real_error
                       : INFINITY;
    json_object_set_new(modes, "margin_ratio", num(ratio));
    json_t *list = json_object_get(modes, "modes");
    for (int m = 0; m < e->nmodes && mh; m++) {
        json_t *md = json_array_get(list, (size_t)m);
        if (!md)
            break;
        const ts_mode_health *h = &mh[m];
        json_object_set_new(md, "trustworthy", json_boolean(h->trustworthy));
        json_object_set_new(md, "shape_trustworthy",
                            json_boolean(h->shape_resolved));
        json_object_set_new(md, "freq_error_hz", num(h->freq_error_hz));
        json_object_set_new(md, "damping_error", num(h->damping_error));
        json_object_set_new(md, "vector_error", num(h->vector_error));
        json_object_set_new(md, "vector_condition",
                            num(e->modes[m].vector_condition));
        json_object_set_new(md, "nearest_mode",
                            h->nearest >= 0 ? json_integer(h->nearest + 1)
                                            : json_null());
    }
    return TS_OK;
}

/* {NAME: a[v]} over the values. */
static json_t *by_name(const ts_convergence *c, const double *a)
{
    json_t *o = json_object();
    for (int v = 0; o && v < c->nvalues; v++)
        json_object_set_new(o, c->values[v].name, num(a[v]));
    return o;
}

json_t *ts_report_convergence_json(const ts_convergence *c)
{
    json_t *o = json_object(), *vals = json_array(), *order = json_object();
    json_t *rows = json_array(), *wp = json_array();
    int *idx = malloc((size_t)(c->nrows > 0 ? c->nrows : 1) * sizeof(int));
    if (!o || !vals || !order || !rows || !wp || !idx) {
        json_decref(o);
        json_decref(vals);
        json_decref(order);
        json_decref(rows);
        json_decref(wp);
        free(idx);
        return NULL;
    }
    json_object_set_new(o, "analysis", json_string(c->analysis));
    json_object_set_new(o, "parameter",
                        json_string(ts_conv_param_name(c->param)));
    json_object_set_new(o, "target", num(c->target));
    for (int v = 0; v < c->nvalues; v++) {
        const ts_conv_value *V = &c->values[v];
        json_array_append_new(
            vals, json_pack("{s:s,s:s,s:o,s:o,s:o,s:o,s:s}", "name", V->name,
                            "unit", V->unit, "scale", num(V->rel_scale),
                            "order", num(V->order), "reference",
                            num(V->reference), "reference_error",
                            num(V->reference_error), "reference_kind",
                            ts_conv_ref_name(V->ref_kind)));
        json_object_set_new(order, V->name, num(V->order));
    }
    json_object_set_new(o, "values", vals);
    json_object_set_new(o, "order", order);
    ts_convergence_sorted_rows(c, idx);
    for (int i = 0; i < c->nrows; i++) {
        const ts_conv_row *r = &c->rows[idx[i]];
        json_t *row = json_object();
        if (!row)
            continue;
        json_object_set_new(row, "series",
                            json_string(c->series[r->series].name));
        json_object_set_new(row, "setting", setting_json(c, r->setting));
        json_object_set_new(row, "h", num(r->h));
        json_object_set_new(row, "status",
                            json_string(r->status == TS_OK ? "ok"
                                                           : "failed"));
        if (r->status != TS_OK)
            json_object_set_new(row, "message", json_string(r->message));
        json_object_set_new(row, "wall_s", num(r->wall_s));
        json_object_set_new(row, "timed_runs", json_integer(r->timed_runs));
        json_object_set_new(row, "evaluations",
                            json_integer((json_int_t)r->evaluations));
        json_object_set_new(row, "values", by_name(c, r->values));
        json_object_set_new(row, "errors", by_name(c, r->errors));
        json_object_set_new(row, "relative_errors",
                            by_name(c, r->rel_errors));
        json_object_set_new(row, "orders", by_name(c, r->order));
        json_object_set_new(row, "max_relative_error",
                            num(r->max_rel_error));
        json_object_set_new(row, "meets_target",
                            json_boolean(r->meets_target));
        json_t *tj = ts_report_trust_json(&r->trust);
        if (tj) {
            json_object_update(row, tj);
            json_decref(tj);
        }
        json_array_append_new(rows, row);
    }
    json_object_set_new(o, "rows", rows);
    const ts_conv_row *rec = c->recommended >= 0 ? &c->rows[c->recommended]
                                                 : NULL;
    json_object_set_new(o, "recommended",
                        rec ? setting_json(c, rec->setting) : json_null());
    json_object_set_new(o, "recommended_series",
                        rec ? json_string(c->series[rec->series].name)
                            : json_null());
    json_object_set_new(o, "limiting_value",
                        c->limiting_value >= 0
                            ? json_string(c->values[c->limiting_value].name)
                            : json_null());
    json_object_set_new(
        o, "prediction",
        isfinite(c->predicted_setting)
            ? json_pack("{s:o,s:o}", "setting",
                        setting_json(c, c->predicted_setting), "wall_s",
                        num(c->predicted_wall_s))
            : json_null());
    int k = 0;
    for (int s = 0; s < c->nseries; s++) {
        json_t *ser = json_object(), *sr = json_array();
        if (!ser || !sr) {
            json_decref(ser);
            json_decref(sr);
            continue;
        }
        for (; k < c->nrows && c->rows[idx[k]].series == s; k++) {
            const ts_conv_row *r = &c->rows[idx[k]];
            json_array_append_new(
                sr, json_pack("{s:o,s:o,s:o,s:I}", "setting",
                              setting_json(c, r->setting),
                              "max_relative_error", num(r->max_rel_error),
                              "wall_s", num(r->wall_s), "evaluations",
                              (json_int_t)r->evaluations));
        }
        int sr_rec = c->series[s].recommended;
        json_object_set_new(ser, "series", json_string(c->series[s].name));
        json_object_set_new(ser, "recommended",
                            sr_rec >= 0
                                ? setting_json(c, c->rows[sr_rec].setting)
                                : json_null());
        json_object_set_new(ser, "rows", sr);
        json_array_append_new(wp, ser);
    }
    json_object_set_new(o, "work_precision", wp);
    free(idx);
    return o;
}

int ts_report_convergence_csv(const ts_convergence *c, const char *path,
                              ts_err *err)
{
    return ts_report_convergence_csv_display(c, NULL, path, err);
}

int ts_report_convergence_csv_display(const ts_convergence *c,
                                      const ts_display *d, const char *path,
                                      ts_err *err)
{
    d = ts_display_or_si(d);
    size_t nv = (size_t)(c->nvalues > 0 ? c->nvalues : 1);
    int *idx = malloc((size_t)(c->nrows > 0 ? c->nrows : 1) * sizeof(int));
    double *k = malloc(nv * sizeof *k);
    if (!idx || !k) {
        free(idx);
        free(k);
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
    }
    tsi_outfile out;
    int orc = tsi_outfile_open(&out, path, err);
    if (orc != TS_OK) {
        free(idx);
        free(k);
        return orc;
    }
    FILE *f = out.f;
    fprintf(f, "series,setting,h,status,wall_s,evaluations,trustworthy,"
               "max_relative_error");
    for (int v = 0; v < c->nvalues; v++) {
        char u[64], t[64] = "";
        k[v] = ts_display_convert(d, c->values[v].unit, 1.0, u, sizeof u);
        if (strcmp(u, c->values[v].unit)) {
            t[0] = '_';
            ts_display_unit_token(u, t + 1, sizeof t - 1);
        }
        fprintf(f, ",%s%s,%s%s_error", c->values[v].name, t,
                c->values[v].name, t);
    }
    fprintf(f, "\n");
    ts_convergence_sorted_rows(c, idx);
    for (int i = 0; i < c->nrows; i++) {
        const ts_conv_row *r = &c->rows[idx[i]];
        fprintf(f, "%s", c->series[r->series].name);
        tsi_csv_number(f, r->setting);
        tsi_csv_number(f, r->h);
        fprintf(f, ",%s", r->status == TS_OK ? "ok" : "failed");
        tsi_csv_number(f, r->wall_s);
        fprintf(f, ",%ld,%d", r->evaluations, r->trust.trustworthy);
        tsi_csv_number(f, r->max_rel_error);
        for (int v = 0; v < c->nvalues; v++) {
            tsi_csv_number(f, k[v] * r->values[v]);
            tsi_csv_number(f, k[v] * r->errors[v]);
        }
        fprintf(f, "\n");
    }
    free(idx);
    free(k);
    return tsi_outfile_commit(&out, err);
}
