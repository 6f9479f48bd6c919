/* report_sweep.c: a sweep as JSON and CSV, and its chains as records
 * (towstab/report_sweep.h).
 *
 * Records are compact JSON written with 17 significant digits, which
 * strtod reads back to the same double; numbers that are not finite are
 * null and come back as NAN (a sweep's columns are NAN or finite). A
 * record holds a whole chain: a chain is restored entirely or not at
 * all, as the sweep computes it.
 */
#include "towstab/report_sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "outfile.h"
#include "towstab/report.h"

/* A JSON number, or null for a value that is not finite. */
static json_t *num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

/* A number of a record: null is NAN. */
static double get_num(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static const char *verdict_text(int v)
{
    return v >= 0 ? ts_verdict_name(v) : NULL;
}

static json_t *text_or_null(const char *t)
{
    return t ? json_string(t) : json_null();
}

/* The axes' values of point p: {"tow.speed": 2.5, ...}. */
static json_t *at_json(const ts_sweep *s, const int *idx, int axis,
                       double value)
{
    json_t *o = json_object();
    for (int a = 0; o && a < s->spec.naxes; a++)
        json_object_set_new(o, s->spec.axes[a].path,
                            num(a == axis ? value
                                          : s->spec.axes[a].values[idx[a]]));
    return o;
}

static json_t *value_json(double v, const ts_estimate *e)
{
    return json_pack("{s:o,s:{s:o,s:o}}", "value", num(v), "error",
                     "discretisation", num(e->discretisation), "solver",
                     num(e->solver));
}

static json_t *point_json(const ts_sweep *s, int p)
{
    const ts_sweep_point *pt = &s->points[p];
    int idx[TS_SWEEP_MAX_AXES];
    ts_sweep_point_index(s, p, idx);
    json_t *o = json_object();
    if (!o)
        return NULL;
    json_object_set_new(o, "index", json_integer(p));
    json_object_set_new(o, "at", at_json(s, idx, -1, 0));
    if (pt->state != TS_SWEEP_DONE) {
        json_object_set_new(o, "status", json_string("pending"));
        return o;
    }
    json_object_set_new(o, "status", json_string(pt->status == TS_OK
                                                     ? "ok"
                                                     : "failed"));
    if (pt->status != TS_OK)
        json_object_set_new(o, "error", json_string(pt->error));
    ts_report_trust_into(o, &pt->trust);
    json_object_set_new(o, "verdict", text_or_null(verdict_text(pt->verdict)));
    json_object_set_new(o, "warm", json_boolean(pt->warm));
    json_object_set_new(o, "evaluations", json_integer(pt->evaluations));
    json_object_set_new(o, "iterations", json_integer(pt->iterations));
    json_object_set_new(o, "wall_s", num(pt->wall_s));
    json_t *vals = json_object();
    for (int c = 0; vals && c < s->ncolumns; c++) {
        size_t i = (size_t)p * (size_t)s->ncolumns + (size_t)c;
        json_object_set_new(vals, s->columns[c].name,
                            value_json(s->values[i], &s->errors[i]));
    }
    json_object_set_new(o, "values", vals);
    return o;
}

static json_t *crossing_json(const ts_sweep *s, int i)
{
    const ts_sweep_crossing *x = &s->crossings[i];
    int idx[TS_SWEEP_MAX_AXES];
    ts_sweep_point_index(s, x->from, idx);
    json_t *o = json_object();
    if (!o)
        return NULL;
    json_object_set_new(o, "path", json_string(s->spec.axes[x->axis].path));
    json_object_set_new(o, "at", at_json(s, idx, x->axis, x->value));
    json_object_set_new(o, "value", num(x->value));
    json_object_set_new(o, "stable", num(x->stable));
    json_object_set_new(o, "unstable", num(x->unstable));
    json_object_set_new(o, "max_real_stable", num(x->max_real_stable));
    json_object_set_new(o, "max_real_unstable", num(x->max_real_unstable));
    json_object_set_new(o, "freq_hz", num(x->freq_hz));
    json_object_set_new(o, "from", json_integer(x->from));
    json_object_set_new(o, "to", json_integer(x->to));
    json_object_set_new(o, "runs", json_integer(x->runs));
    json_object_set_new(o, "evaluations", json_integer(x->evaluations));
    json_object_set_new(o, "wall_s", num(x->wall_s));
    json_object_set_new(o, "status", json_string(!x->done ? "pending"
                                                 : x->status == TS_OK
                                                     ? "ok"
                                                     : "failed"));
    if (x->done && x->status != TS_OK)
        json_object_set_new(o, "error", json_string(x->error));
    return o;
}

json_t *ts_report_sweep_json(const ts_sweep *s)
{
    json_t *o = json_object(), *axes = json_array(), *cols = json_array();
    json_t *pts = json_array(), *bnd = json_array();
    if (!o || !axes || !cols || !pts || !bnd) {
        json_decref(o);
        json_decref(axes);
        json_decref(cols);
        json_decref(pts);
        json_decref(bnd);
        return NULL;
    }
    json_object_set_new(o, "type", json_string("sweep"));
    json_object_set_new(o, "analysis", json_string(ts_analysis_name(s->kind)));
    json_object_set_new(o, "scene", json_string(s->sys->name));
    for (int a = 0; a < s->spec.naxes; a++) {
        const ts_sweep_axis *ax = &s->spec.axes[a];
        json_t *v = json_array();
        for (int i = 0; v && i < ax->n; i++)
            json_array_append_new(v, num(ax->values[i]));
        json_array_append_new(axes, json_pack("{s:s,s:s,s:o}", "path",
                                              ax->path, "unit", ax->unit,
                                              "values", v));
    }
    json_object_set_new(o, "axes", axes);
    for (int c = 0; c < s->ncolumns; c++)
        json_array_append_new(cols, json_pack("{s:s,s:s}", "name",
                                              s->columns[c].name, "unit",
                                              s->columns[c].unit));
    json_object_set_new(o, "columns", cols);
    json_object_set_new(o, "chain", json_integer(s->chain_len));
    json_object_set_new(o, "chains", json_integer(s->nchains));
    ts_trust all;
    ts_trust_init(&all);
    int failed = 0, untrusted = 0, warm = 0;
    for (int p = 0; p < s->npoints; p++) {
        json_array_append_new(pts, point_json(s, p));
        const ts_sweep_point *pt = &s->points[p];
        if (pt->state != TS_SWEEP_DONE)
            continue;
        failed += pt->status != TS_OK;
        untrusted += pt->status == TS_OK && !pt->trust.trustworthy;
        warm += pt->warm;
    }
    json_object_set_new(o, "points", pts);
    for (int i = 0; i < s->ncrossings; i++)
        json_array_append_new(bnd, crossing_json(s, i));
    json_object_set_new(o, "boundary", bnd);
    json_object_set_new(o, "points_failed", json_integer(failed));
    json_object_set_new(o, "points_untrustworthy", json_integer(untrusted));
    json_object_set_new(o, "points_continued", json_integer(warm));
    if (failed)
        ts_trust_fail(&all, "%d of %d points failed", failed, s->npoints);
    if (untrusted)
        ts_trust_fail(&all, "%d of %d points are not trustworthy (see their "
                      "reasons)", untrusted, s->npoints);
    if (!s->completed)
        ts_trust_fail(&all, "the sweep is incomplete");
    json_object_set_new(o, "completed", json_boolean(s->completed));
    ts_report_trust_into(o, &all);
    json_object_set_new(o, "wall_s", num(s->wall_s));
    json_object_set_new(o, "evaluations", json_integer(s->evaluations));
    return o;
}

int ts_report_sweep_csv(const ts_sweep *s, const char *path, ts_err *err)
{
    tsi_outfile out;
    int rc = tsi_outfile_open(&out, path, err);
    if (rc != TS_OK)
        return rc;
    FILE *f = out.f;
    fprintf(f, "index");
    for (int a = 0; a < s->spec.naxes; a++)
        fprintf(f, ",%s", s->spec.axes[a].path);
    fprintf(f, ",status,trustworthy,verdict,warm,evaluations,iterations");
    for (int c = 0; c < s->ncolumns; c++)
        fprintf(f, ",%s,%s_discretisation,%s_solver", s->columns[c].name,
                s->columns[c].name, s->columns[c].name);
    fprintf(f, "\n");
    for (int p = 0; p < s->npoints; p++) {
        const ts_sweep_point *pt = &s->points[p];
        int idx[TS_SWEEP_MAX_AXES];
        ts_sweep_point_index(s, p, idx);
        fprintf(f, "%d", p);
        for (int a = 0; a < s->spec.naxes; a++)
            tsi_csv_number(f, s->spec.axes[a].values[idx[a]]);
        const char *v = verdict_text(pt->verdict);
        fprintf(f, ",%s,%d,%s,%d,%ld,%d",
                pt->state != TS_SWEEP_DONE ? "pending"
                : pt->status == TS_OK      ? "ok"
                                           : "failed",
                pt->state == TS_SWEEP_DONE && pt->trust.trustworthy,
                v ? v : "", pt->warm, pt->evaluations, pt->iterations);
        for (int c = 0; c < s->ncolumns; c++) {
            size_t i = (size_t)p * (size_t)s->ncolumns + (size_t)c;
            tsi_csv_number(f, s->values[i]);
            tsi_csv_number(f, s->errors[i].discretisation);
            tsi_csv_number(f, s->errors[i].solver);
        }
        fprintf(f, "\n");
    }
    return tsi_outfile_commit(&out, err);
}

/* ---- records ----------------------------------------------------------- */

static json_t *num_array(const double *v, size_t n, size_t stride)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++)
        json_array_append_new(a, num(v[i * stride]));
    return a;
}

static json_t *point_record(const ts_sweep *s, int p)
{
    const ts_sweep_point *pt = &s->points[p];
    size_t nc = (size_t)s->ncolumns, at = (size_t)p * nc;
    double *d = malloc(2 * nc * sizeof *d + 1);
    if (!d)
        return NULL;
    for (size_t c = 0; c < nc; c++) {
        d[c] = s->errors[at + c].discretisation;
        d[nc + c] = s->errors[at + c].solver;
    }
    json_t *o = json_pack("{s:i,s:i,s:s,s:o,s:i,s:b,s:I,s:i,s:o,s:o,s:o,s:o}",
                          "index", p, "status", pt->status, "error",
                          pt->error, "trust", ts_report_trust_json(&pt->trust),
                          "verdict", pt->verdict, "warm", pt->warm,
                          "evaluations", (json_int_t)pt->evaluations,
                          "iterations", pt->iterations, "wall_s",
                          num(pt->wall_s), "v",
                          num_array(s->values + at, nc, 1), "d",
                          num_array(d, nc, 1), "s", num_array(d + nc, nc, 1));
    free(d);
    return o;
}

char *ts_report_sweep_record(const ts_sweep *s, int t)
{
    json_t *o = NULL;
    if (t >= 0 && t < s->nchains) {
        int first, n;
        ts_sweep_chain_points(s, t, &first, &n);
        json_t *pts = json_array();
        for (int p = first; pts && p < first + n; p++)
            json_array_append_new(pts, point_record(s, p));
        o = json_pack("{s:i,s:o}", "chain", t, "points", pts);
    } else if (t >= s->nchains && t < s->nchains + s->ncrossings) {
        int i = t - s->nchains;
        const ts_sweep_crossing *x = &s->crossings[i];
        o = json_pack("{s:i,s:i,s:i,s:i,s:i,s:s,s:o,s:o,s:o,s:o,s:o,s:i,"
                      "s:I,s:o}",
                      "crossing", i, "axis", x->axis, "from", x->from, "to",
                      x->to, "status", x->status, "error", x->error,
                      "stable", num(x->stable), "unstable", num(x->unstable),
                      "max_real_stable", num(x->max_real_stable),
                      "max_real_unstable", num(x->max_real_unstable),
                      "freq_hz", num(x->freq_hz), "runs", x->runs,
                      "evaluations", (json_int_t)x->evaluations, "wall_s",
                      num(x->wall_s));
    }
    if (!o)
        return NULL;
    char *text = json_dumps(o, JSON_COMPACT | JSON_REAL_PRECISION(17));
    json_decref(o);
    return text;
}

/* Read numbers a[n] (null: NAN) into out[i * stride]. */
static int read_nums(const json_t *a, size_t n, double *out, size_t stride)
{
    if (!json_is_array(a) || json_array_size(a) != n)
        return 0;
    for (size_t i = 0; i < n; i++) {
        const json_t *v = json_array_get(a, i);
        if (!json_is_number(v) && !json_is_null(v))
            return 0;
        out[i * stride] = json_is_number(v) ? json_number_value(v) : NAN;
    }
    return 1;
}

static int read_trust(const json_t *o, ts_trust *t)
{
    ts_trust_init(t);
    const json_t *r = json_object_get(o, "reasons");
    const json_t *n = json_object_get(o, "notes");
    if (!json_is_array(r) || !json_is_array(n))
        return 0;
    for (size_t i = 0; i < json_array_size(r); i++)
        ts_trust_fail(t, "%s", json_string_value(json_array_get(r, i))
                                   ? json_string_value(json_array_get(r, i))
                                   : "");
    for (size_t i = 0; i < json_array_size(n); i++)
        ts_trust_note(t, "%s", json_string_value(json_array_get(n, i))
                                   ? json_string_value(json_array_get(n, i))
                                   : "");
    t->trustworthy = json_is_true(json_object_get(o, "trustworthy"));
    t->dropped = (int)json_integer_value(json_object_get(o, "dropped"));
    return 1;
}

/* Restore point p from record o into a scratch point and arrays. */
static int read_point(const ts_sweep *s, const json_t *o, int p,
                      ts_sweep_point *pt, double *v, ts_estimate *e)
{
    size_t nc = (size_t)s->ncolumns;
    const json_t *err = json_object_get(o, "error");
    if (json_integer_value(json_object_get(o, "index")) != p ||
        !json_is_string(err) ||
        !read_trust(json_object_get(o, "trust"), &pt->trust))
        return 0;
    double *tmp = malloc(2 * nc * sizeof *tmp + 1);
    if (!tmp)
        return 0;
    int ok = read_nums(json_object_get(o, "v"), nc, v, 1) &&
             read_nums(json_object_get(o, "d"), nc, tmp, 1) &&
             read_nums(json_object_get(o, "s"), nc, tmp + nc, 1);
    for (size_t c = 0; ok && c < nc; c++) {
        e[c].discretisation = tmp[c];
        e[c].solver = tmp[nc + c];
    }
    free(tmp);
    if (!ok)
        return 0;
    pt->state = TS_SWEEP_DONE;
    pt->status = (int)json_integer_value(json_object_get(o, "status"));
    snprintf(pt->error, sizeof pt->error, "%s", json_string_value(err));
    pt->verdict = (int)json_integer_value(json_object_get(o, "verdict"));
    pt->warm = json_is_true(json_object_get(o, "warm"));
    pt->evaluations = (long)json_integer_value(json_object_get(o,
                                                               "evaluations"));
    pt->iterations = (int)json_integer_value(json_object_get(o,
                                                             "iterations"));
    pt->wall_s = get_num(o, "wall_s");
    return 1;
}

static int restore_chain(ts_sweep *s, const json_t *o, int c, ts_err *err)
{
    int first, n;
    ts_sweep_chain_points(s, c, &first, &n);
    const json_t *pts = json_object_get(o, "points");
    if (!json_is_array(pts) || (int)json_array_size(pts) != n)
        return ts_fail(err, TS_EINVAL, "record of chain %d: expected %d "
                       "points", c, n);
    size_t nc = (size_t)s->ncolumns;
    ts_sweep_point *pt = calloc((size_t)n, sizeof *pt);
    double *v = malloc((size_t)n * nc * sizeof *v + 1);
    ts_estimate *e = malloc((size_t)n * nc * sizeof *e + 1);
    int rc = pt && v && e ? TS_OK
                          : ts_fail(err, TS_ENOMEM, "sweep: out of memory");
    for (int i = 0; !rc && i < n; i++)
        if (!read_point(s, json_array_get(pts, (size_t)i), first + i, &pt[i],
                        v + (size_t)i * nc, e + (size_t)i * nc))
            rc = ts_fail(err, TS_EINVAL, "record of chain %d: point %d does "
                         "not fit this sweep's %d columns", c, first + i,
                         s->ncolumns);
    if (!rc) {
        memcpy(s->points + first, pt, (size_t)n * sizeof *pt);
        memcpy(s->values + (size_t)first * nc, v,
               (size_t)n * nc * sizeof *v);
        memcpy(s->errors + (size_t)first * nc, e,
               (size_t)n * nc * sizeof *e);
    }
    free(pt);
    free(v);
    free(e);
    return rc;
}

static int restore_crossing(ts_sweep *s, const json_t *o, int i, ts_err *err)
{
    if (i < 0 || i >= s->ncrossings)
        return ts_fail(err, TS_EINVAL, "record of crossing %d: the sweep has "
                       "%d crossings", i, s->ncrossings);
    ts_sweep_crossing *x = &s->crossings[i];
    const json_t *e = json_object_get(o, "error");
    if (json_integer_value(json_object_get(o, "axis")) != x->axis ||
        json_integer_value(json_object_get(o, "from")) != x->from ||
        json_integer_value(json_object_get(o, "to")) != x->to ||
        !json_is_string(e))
        return ts_fail(err, TS_EINVAL, "record of crossing %d: not this "
                       "sweep's crossing (axis %d, points %d to %d)", i,
                       x->axis, x->from, x->to);
    x->status = (int)json_integer_value(json_object_get(o, "status"));
    snprintf(x->error, sizeof x->error, "%s", json_string_value(e));
    x->stable = get_num(o, "stable");
    x->unstable = get_num(o, "unstable");
    x->value = 0.5 * (x->stable + x->unstable);
    x->max_real_stable = get_num(o, "max_real_stable");
    x->max_real_unstable = get_num(o, "max_real_unstable");
    x->freq_hz = get_num(o, "freq_hz");
    x->runs = (int)json_integer_value(json_object_get(o, "runs"));
    x->evaluations = (long)json_integer_value(json_object_get(o,
                                                              "evaluations"));
    x->wall_s = get_num(o, "wall_s");
    x->done = 1;
    return TS_OK;
}

int ts_report_sweep_restore(ts_sweep *s, const char *text, ts_err *err)
{
    json_error_t je;
    json_t *o = json_loads(text, 0, &je);
    if (!json_is_object(o)) {
        json_decref(o);
        return ts_fail(err, TS_EINVAL, "record: not a JSON object (%s)",
                       je.text);
    }
    const json_t *c = json_object_get(o, "chain");
    const json_t *x = json_object_get(o, "crossing");
    int rc;
    if (json_is_integer(c)) {
        json_int_t k = json_integer_value(c);
        rc = k >= 0 && k < s->nchains
                 ? restore_chain(s, o, (int)k, err)
                 : ts_fail(err, TS_EINVAL, "record of chain %lld: the sweep "
                           "has %d chains", (long long)k, s->nchains);
    } else if (json_is_integer(x)) {
        rc = restore_crossing(s, o, (int)json_integer_value(x), err);
    } else {
        rc = ts_fail(err, TS_EINVAL, "record: neither a chain nor a "
                     "crossing");
    }
    json_decref(o);
    return rc;
}
