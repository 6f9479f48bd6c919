/* report_time.c: JSON and CSV of time-domain results
 * (towstab/report_time.h). Numbers are written with 17 significant digits
 * (CSV %.17g; JSON through ts_report_write_json) so a history read back
 * reproduces the run bit for bit; non-finite values are JSON null and CSV
 * "nan". A history's keys and the extremes are emitted once, through
 * lib/jsonout.h: into a tree for the public functions here, or straight
 * to the file for a result's document (report_result.c), so that a
 * history is never held as a tree there. */
#include "towstab/report_time.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "outfile.h"
#include "report_impl.h"
#include "report_time_impl.h"
#include "towstab/report.h"

static json_t *num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

/* A JSON array of n values read with a stride. */
static void series(tsi_json *w, const double *base, int n, size_t stride)
{
    tsi_json_array_open(w);
    for (int i = 0; i < n; i++)
        tsi_json_num(w, base[stride * (size_t)i]);
    tsi_json_array_close(w);
}

/* key: series(...). */
static void key_series(tsi_json *w, const char *key, const double *base,
                       int n, size_t stride)
{
    tsi_json_key(w, key);
    series(w, base, n, stride);
}

json_t *ts_report_sim_stats_json(const ts_sim_stats *st, const char *method)
{
    double ratio = st->wall_s > 0 ? st->t_reached / st->wall_s : NAN;
    static const char *const newton[] = {NULL, "dense", "sparse"};
    return json_pack("{s:s,s:I,s:I,s:I,s:I,s:s?,s:I,s:I,s:o,s:o,s:o,s:o}",
                     "method", method, "steps", (json_int_t)st->steps,
                     "rejected", (json_int_t)st->rejected, "evaluations",
                     (json_int_t)st->evaluations, "jacobians",
                     (json_int_t)st->jacobians, "newton_matrix",
                     newton[st->newton], "recharts",
                     (json_int_t)st->recharts, "restarts",
                     (json_int_t)st->restarts, "t_reached",
                     num(st->t_reached), "h_last", num(st->h_last), "wall_s",
                     num(st->wall_s), "simulated_per_wall", num(ratio));
}

/* A run with tensions and a tow force (a nonlinear one). */
static int has_forces(const ts_history *h)
{
    return h->nsamples > 0 && isfinite(h->tow_force[0]);
}

/* Channel `out` gives a finite value at some sample of h. */
static int gives(const ts_system *sys, const ts_history *h,
                 const ts_output *out)
{
    for (int i = 0; i < h->nsamples; i++)
        if (isfinite(ts_history_value(sys, h, out, i)))
            return 1;
    return 0;
}

void tsi_report_channels_keys(tsi_json *w, const ts_system *sys,
                              const ts_history *h, int n,
                              const ts_output outs[])
{
    key_series(w, "t", h->t, h->nsamples, 1);
    tsi_json_key(w, "outputs");
    tsi_json_object_open(w);
    for (int k = 0; k < n; k++) {
        if (!gives(sys, h, &outs[k]))
            continue;
        tsi_json_key(w, outs[k].name);
        tsi_json_array_open(w);
        for (int i = 0; i < h->nsamples; i++)
            tsi_json_num(w, ts_history_value(sys, h, &outs[k], i));
        tsi_json_array_close(w);
    }
    tsi_json_object_close(w);
}

/* The arguments of ts_report_channels_json. */
typedef struct channels_args {
    const ts_system *sys;
    int n;
    const ts_output *outs;
} channels_args;

static void emit_channels(tsi_json *w, const void *a, const void *h)
{
    const channels_args *c = a;
    tsi_json_object_open(w);
    tsi_report_channels_keys(w, c->sys, h, c->n, c->outs);
    tsi_json_object_close(w);
}

json_t *ts_report_channels_json(const ts_system *sys, const ts_history *h,
                                int n, const ts_output outs[])
{
    return tsi_json_build(emit_channels, &(channels_args){sys, n, outs}, h);
}

/* Three interleaved series base[3 i + j] (j = 0, 1, 2) under key, as an
 * object of arrays named name[j]. */
static void triple(tsi_json *w, const char *key, const double *base, int n,
                   const char *const name[3])
{
    tsi_json_key(w, key);
    tsi_json_object_open(w);
    for (int j = 0; j < 3; j++)
        key_series(w, name[j], base + j, n, 3);
    tsi_json_object_close(w);
}

/* The keys of ts_report_history_json after "t": nodes (only `node` when
 * >= 0), and with every node, for a nonlinear run, tensions and energy;
 * the vehicles' outputs. */
static void history_keys(tsi_json *w, const ts_system *sys,
                         const ts_history *h, int node)
{
    int n = h->nsamples;
    size_t ps = 3 * (size_t)h->nnodes;
    char name[2 * TS_NAME_MAX];
    tsi_json_key(w, "nodes");
    tsi_json_array_open(w);
    for (int k = 0; k < h->nnodes; k++) {
        if (node >= 0 && k != node)
            continue;
        ts_system_node_name(sys, k, name, sizeof name);
        const double *p = h->positions + 3 * (size_t)k;
        tsi_json_object_open(w);
        tsi_json_key(w, "name");
        tsi_json_str(w, name);
        key_series(w, "x", p, n, ps);
        key_series(w, "y", p + 1, n, ps);
        key_series(w, "z", p + 2, n, ps);
        tsi_json_object_close(w);
    }
    tsi_json_array_close(w);
    int nonlinear = n > 0 && h->nlinks > 0 && isfinite(h->tensions[0]);
    if (node < 0 && nonlinear) {
        tsi_json_key(w, "tensions");
        tsi_json_array_open(w);
        for (int l = 0; l < h->nlinks; l++) {
            const ts_link *L = &sys->links[l];
            tsi_json_object_open(w);
            tsi_json_key(w, "cable");
            tsi_json_str(w, sys->cables[L->cable].name);
            tsi_json_key(w, "index");
            tsi_json_int(w, L->index);
            key_series(w, "tension", h->tensions + l, n, (size_t)h->nlinks);
            tsi_json_object_close(w);
        }
        tsi_json_array_close(w);
        tsi_json_key(w, "energy");
        tsi_json_object_open(w);
        key_series(w, "kinetic", h->energy, n, 2);
        key_series(w, "potential", h->energy + 1, n, 2);
        tsi_json_object_close(w);
    }
    if (h->noutput > 0 && h->outputs) {
        /* The vehicles' depth, attitude, loop outputs and deflections. */
        tsi_json_key(w, "vehicle_outputs");
        tsi_json_array_open(w);
        for (int j = 0; j < h->noutput; j++) {
            tsi_json_object_open(w);
            tsi_json_key(w, "name");
            tsi_json_str(w, h->output_name[j]);
            tsi_json_key(w, "unit");
            tsi_json_str(w, h->output_unit[j]);
            key_series(w, "value", h->outputs + j, n, (size_t)h->noutput);
            tsi_json_object_close(w);
        }
        tsi_json_array_close(w);
    }
}

void tsi_report_full_keys(tsi_json *w, const ts_system *sys,
                          const ts_history *h)
{
    history_keys(w, sys, h, -1);
    if (has_forces(h)) {
        static const char *const xyz[3] = {"x", "y", "z"};
        triple(w, "tow_force", h->tow_force, h->nsamples, xyz);
    }
    if (h->nsamples > 0 && isfinite(h->frame[0])) {
        /* The pose of M in the earth frame (towstab/track.h). */
        static const char *const pose[3] = {"x", "y", "heading"};
        triple(w, "frame", h->frame, h->nsamples, pose);
    }
}

static void emit_full(tsi_json *w, const void *sys, const void *h)
{
    tsi_json_object_open(w);
    tsi_report_full_keys(w, sys, h);
    tsi_json_object_close(w);
}

int ts_report_history_full(json_t *o, const ts_system *sys,
                           const ts_history *h)
{
    json_t *full = tsi_json_build(emit_full, sys, h);
    if (!full)
        return TS_ENOMEM;
    int rc = json_object_update(o, full) ? TS_ENOMEM : TS_OK;
    json_decref(full);
    return rc;
}

void tsi_report_extremes_keys(tsi_json *w, const ts_extremes *e)
{
    static const char *const key[10] = {
        "max", "t_max", "max_error", "min", "t_min", "min_error", "mean",
        "static", "amplification", "from_s"};
    const double v[10] = {e->max,  e->t_max,     e->max_error,
                          e->min,  e->t_min,     e->min_error,
                          e->mean, e->reference, e->amplification,
                          e->t_from};
    for (int k = 0; k < 10; k++) {
        tsi_json_key(w, key[k]);
        tsi_json_num(w, v[k]);
    }
}

static void emit_extremes(tsi_json *w, const void *e, const void *unused)
{
    (void)unused;
    tsi_json_object_open(w);
    tsi_report_extremes_keys(w, e);
    tsi_json_object_close(w);
}

json_t *ts_report_extremes_json(const ts_extremes *e)
{
    return tsi_json_build(emit_extremes, e, NULL);
}

/* The arguments of ts_report_history_json. */
typedef struct history_args {
    const ts_system *sys;
    int node;
} history_args;

static void emit_history(tsi_json *w, const void *a, const void *hv)
{
    const history_args *ha = a;
    const ts_history *h = hv;
    tsi_json_object_open(w);
    key_series(w, "t", h->t, h->nsamples, 1);
    history_keys(w, ha->sys, h, ha->node);
    tsi_json_object_close(w);
}

json_t *ts_report_history_json(const ts_system *sys, const ts_history *h,
                               int node)
{
    return tsi_json_build(emit_history, &(history_args){sys, node}, h);
}

json_t *ts_report_compare_json(const ts_compare *c)
{
    json_t *exc = c->periodic || c->step
        ? json_pack("{s:s,s:s,s:s,s:s,s:o,s:o,s:o}", "axis",
                    ts_axis_name(c->exc_axis), "input", c->input, "unit",
                    c->input_unit, "type", ts_signal_type_name(c->exc_type),
                    "amplitude", num(c->exc_amplitude), "frequency_hz",
                    num(c->exc_frequency_hz), "fitted_amplitude",
                    num(c->exc_fit_amplitude))
        : json_pack("{s:n,s:n,s:n,s:n,s:n,s:n}", "axis", "input", "unit",
                    "type", "amplitude", "frequency_hz");
    json_t *runs[2];
    const ts_compare_run *r[2] = {&c->linear, &c->nonlinear};
    for (int i = 0; i < 2; i++)
        runs[i] = json_pack("{s:o,s:o,s:o,s:o,s:o,s:o}", "amplitude_ratio",
                            num(r[i]->amplitude_ratio), "phase_deg",
                            num(r[i]->phase_deg), "mean_offset",
                            num(r[i]->mean_offset), "amplitude",
                            num(r[i]->amplitude), "half_range",
                            num(r[i]->half_range), "final_gain",
                            num(r[i]->final_gain));
    return json_pack(
        "{s:s,s:o,s:o,s:{s:o,s:o,s:i},s:o,s:o,s:o,s:{s:o,s:o,s:o,s:o},s:o,"
        "s:o,s:o,s:o}",
        "output", c->output.name, "ratio_unit",
        c->ratio_unit[0] ? json_string(c->ratio_unit) : json_null(),
        "excitation", exc, "window", "from_s",
        num(c->t_from), "to_s", num(c->t_to), "samples", c->nsamples,
        "equilibrium", num(c->equilibrium), "linear", runs[0], "nonlinear",
        runs[1], "response_prediction", "amplitude_ratio", num(c->pred_ratio),
        "phase_deg", num(c->pred_phase_deg), "static_gain",
        num(c->static_gain), "static_note",
        c->static_note[0] ? json_string(c->static_note) : json_null(),
        "amplitude_difference_pct",
        num(c->amplitude_difference_pct), "mean_difference_pct",
        num(c->mean_difference_pct), "rms_difference",
        num(c->rms_difference), "rms_difference_ratio",
        num(c->rms_difference_ratio));
}

json_t *ts_report_excitation_json(const ts_excitation *ex)
{
    json_t *a = json_array();
    int n = ex ? ts_excitation_nsignals(ex) : 0;
    for (int i = 0; a && i < n; i++) {
        const ts_signal *s = ts_excitation_signal(ex, i);
        json_t *o = json_pack("{s:s,s:s}", "axis", ts_axis_name(s->axis),
                              "type", ts_signal_type_name(s->type));
        if (o && s->axis == TS_AXIS_INPUT)
            json_object_set_new(o, "input", json_string(s->input));
        switch (s->type) {
        case TS_SIGNAL_CRANK:
            json_object_set_new(o, "rod", num(s->rod));
            /* fall through */
        case TS_SIGNAL_SINE:
            json_object_set_new(o, "amplitude", num(s->amplitude));
            json_object_set_new(o, "frequency_hz", num(s->frequency));
            json_object_set_new(o, "phase_deg", num(s->phase * 180 / M_PI));
            break;
        case TS_SIGNAL_RAMP:
            json_object_set_new(o, "duration", num(s->duration));
            /* fall through */
        case TS_SIGNAL_STEP:
            json_object_set_new(o, s->absolute ? "to" : "amplitude",
                                num(s->amplitude));
            json_object_set_new(o, "start", num(s->start));
            json_object_set_new(o, "rise", num(s->rise));
            break;
        case TS_SIGNAL_SERIES:
            json_object_set_new(o, "from_s", num(s->start));
            json_object_set_new(o, "to_s", num(s->start + s->duration));
            break;
        case TS_SIGNAL_SUM:
            json_object_set_new(o, "rms", num(s->amplitude));
            json_object_set_new(o, "components",
                                json_integer(ts_excitation_sum_components(ex, i)));
            json_object_set_new(o, "max_frequency_hz", num(s->frequency));
            json_object_set_new(o, "fade_in_s", num(s->rise));
            break;
        }
        json_array_append_new(a, o);
    }
    return a;
}

/* The columns of one run: its header cells (after "t_s", with a
 * prefix) and its cells of row i. `slot` 0 is the first run, 1 the
 * second. */
typedef struct csv_cols {
    void (*header)(struct csv_cols *c, FILE *f, const ts_history *h,
                   const char *prefix, int slot);
    void (*row)(struct csv_cols *c, FILE *f, const ts_history *h, int i,
                int slot);
    const ts_system *sys;
    int n;                   /* channels */
    const ts_output *outs;   /* [n] */
    char *use;               /* [2 n]: the channels each run gives */
    const ts_display *d;     /* the units shown */
    char t[TS_DISPLAY_UNIT_MAX * 2]; /* time's unit as a name */
} csv_cols;

/* Write "t_s" and the columns of nl and li (either may be NULL; with
 * both, prefixed and to the shorter run), atomically. */
static int write_runs(csv_cols *c, const ts_history *nl, const ts_history *li,
                      const char *path, ts_err *err)
{
    tsi_outfile out;
    int orc = tsi_outfile_open(&out, path, err);
    if (orc != TS_OK)
        return orc;
    FILE *f = out.f;
    int both = nl && li;
    const ts_history *first = nl ? nl : li;
    int rows = first->nsamples;
    if (both && li->nsamples < rows)
        rows = li->nsamples;
    fprintf(f, "t_%s", c->t);
    if (nl)
        c->header(c, f, nl, both ? "nonlinear." : "", 0);
    if (li)
        c->header(c, f, li, both ? "linear." : "", 1);
    fputc('\n', f);
    for (int i = 0; i < rows; i++) {
        fprintf(f, "%.17g", ts_display_value(c->d, TS_QTY_TIME, first->t[i]));
        if (nl)
            c->row(c, f, nl, i, 0);
        if (li)
            c->row(c, f, li, i, 1);
        fputc('\n', f);
    }
    return tsi_outfile_commit(&out, err);
}

/* Set up the units of c: d, or SI. */
static void cols_units(csv_cols *c, const ts_display *d)
{
    c->d = ts_display_or_si(d);
    ts_display_unit_token(ts_display_unit(c->d, TS_QTY_TIME), c->t,
                          sizeof c->t);
}

/* The vehicles' outputs of a run, SI (m, rad): their columns and their
 * cells of row i. */
static void vehicle_header(FILE *f, const ts_history *h, const char *prefix)
{
    for (int j = 0; h->outputs && j < h->noutput; j++)
        fprintf(f, ",%s%s_%s", prefix, h->output_name[j], h->output_unit[j]);
}

static void vehicle_row(FILE *f, const ts_history *h, int i)
{
    const double *o = h->outputs ? h->outputs + (size_t)h->noutput * i : NULL;
    for (int j = 0; o && j < h->noutput; j++)
        fprintf(f, ",%.17g", o[j]);
}

/* The full state: every node, every link's tension and the tow force
 * (nonlinear runs). */
static void full_header(csv_cols *c, FILE *f, const ts_history *h,
                        const char *prefix, int slot)
{
    (void)slot;
    const ts_system *sys = c->sys;
    char name[2 * TS_NAME_MAX], lu[TS_DISPLAY_UNIT_MAX * 2],
        fu[TS_DISPLAY_UNIT_MAX * 2];
    ts_display_unit_token(ts_display_unit(c->d, TS_QTY_LENGTH), lu,
                          sizeof lu);
    ts_display_unit_token(ts_display_unit(c->d, TS_QTY_FORCE), fu,
                          sizeof fu);
    for (int k = 0; k < h->nnodes; k++) {
        ts_system_node_name(sys, k, name, sizeof name);
        fprintf(f, ",%s%s.x_%s,%s%s.y_%s,%s%s.z_%s", prefix, name, lu, prefix,
                name, lu, prefix, name, lu);
    }
    if (h->nsamples > 0 && h->nlinks > 0 && isfinite(h->tensions[0]))
        for (int l = 0; l < h->nlinks; l++)
            fprintf(f, ",%s%s.%d.tension_%s", prefix,
                    sys->cables[sys->links[l].cable].name,
                    sys->links[l].index, fu);
    if (has_forces(h))
        fprintf(f, ",%stow.force.x_%s,%stow.force.y_%s,%stow.force.z_%s",
                prefix, fu, prefix, fu, prefix, fu);
    vehicle_header(f, h, prefix);
}

static void full_row(csv_cols *c, FILE *f, const ts_history *h, int i,
                     int slot)
{
    (void)slot;
    const double *p = h->positions + 3 * (size_t)h->nnodes * (size_t)i;
    for (int k = 0; k < 3 * h->nnodes; k++)
        fprintf(f, ",%.17g", ts_display_value(c->d, TS_QTY_LENGTH, p[k]));
    if (h->nsamples > 0 && h->nlinks > 0 && isfinite(h->tensions[0])) {
        const double *t = h->tensions + (size_t)h->nlinks * (size_t)i;
        for (int l = 0; l < h->nlinks; l++)
            fprintf(f, ",%.17g", ts_display_value(c->d, TS_QTY_FORCE, t[l]));
    }
    if (has_forces(h))
        for (int k = 0; k < 3; k++)
            fprintf(f, ",%.17g",
                    ts_display_value(c->d, TS_QTY_FORCE,
                                     h->tow_force[3 * (size_t)i + (size_t)k]));
    vehicle_row(f, h, i);
}

int ts_report_history_csv(const ts_system *sys, const ts_history *nl,
                          const ts_history *li, const char *path,
                          ts_err *err)
{
    return ts_report_history_csv_display(sys, nl, li, NULL, path, err);
}

int ts_report_history_csv_display(const ts_system *sys, const ts_history *nl,
                                  const ts_history *li, const ts_display *d,
                                  const char *path, ts_err *err)
{
    if (!nl && !li)
        return ts_fail(err, TS_EINVAL, "%s: no history to write", path);
    csv_cols c = {full_header, full_row, sys, 0, NULL, NULL, NULL, ""};
    cols_units(&c, d);
    return write_runs(&c, nl, li, path, err);
}

/* The channels a run gives, named with their unit (none for a strain). */
static void channels_header(csv_cols *c, FILE *f, const ts_history *h,
                            const char *prefix, int slot)
{
    char *use = c->use + (size_t)slot * (size_t)c->n;
    for (int k = 0; k < c->n; k++) {
        use[k] = (char)gives(c->sys, h, &c->outs[k]);
        if (!use[k])
            continue;
        char u[64], t[64];
        ts_display_convert(c->d, c->outs[k].si_unit, 1.0, u, sizeof u);
        ts_display_unit_token(u, t, sizeof t);
        int bare = !strcmp(u, "1");
        fprintf(f, ",%s%s%s%s", prefix, c->outs[k].name, bare ? "" : "_",
                bare ? "" : t);
    }
}

static void channels_row(csv_cols *c, FILE *f, const ts_history *h, int i,
                         int slot)
{
    const char *use = c->use + (size_t)slot * (size_t)c->n;
    char u[64];
    for (int k = 0; k < c->n; k++)
        if (use[k])
            fprintf(f, ",%.17g",
                    ts_display_convert(c->d, c->outs[k].si_unit,
                                       ts_history_value(c->sys, h,
                                                        &c->outs[k], i),
                                       u, sizeof u));
}

int ts_report_channels_csv(const ts_system *sys, const ts_history *nl,
                           const ts_history *li, int n,
                           const ts_output outs[], const ts_display *d,
                           const char *path, ts_err *err)
{
    if (!nl && !li)
        return ts_fail(err, TS_EINVAL, "%s: no history to write", path);
    csv_cols c = {channels_header, channels_row, sys, n, outs, NULL, NULL,
                  ""};
    cols_units(&c, d);
    c.use = calloc(2 * (size_t)(n > 0 ? n : 1), 1);
    if (!c.use)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
    int rc = write_runs(&c, nl, li, path, err);
    free(c.use);
    return rc;
}
