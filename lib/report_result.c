/* report_result.c: a result of any analysis as JSON and CSV
 * (towstab/report_result.h). Each kind is serialised by the writers of
 * its parts (report.c, report_linear.c, report_time.c,
 * report_converge.c); the keys every result shares are added here, once. */
#include "towstab/report_result.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "outfile.h"
#include "report_impl.h"
#include "report_time_impl.h"

#include "towstab/report.h"
#include "towstab/report_converge.h"
#include "towstab/report_linear.h"
#include "towstab/report_seastate.h"
#include "towstab/report_time.h"

/* A JSON number, or null for a value that is not finite. */
static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

/* Set key of o to the trust of t (replacing what is there). */
static void set_trust(json_t *o, const ts_trust *t)
{
    json_t *tj = ts_report_trust_json(t);
    if (tj) {
        json_object_update(o, tj);
        json_decref(tj);
    }
}

/* The equilibrium part, with its own verdict; its nodes and links
 * listed in defer when it is not NULL (report_impl.h). */
static json_t *eq_json(const ts_result *r, const ts_trust *t,
                       tsi_json_defer *defer)
{
    return r->eq && r->eq_attempted
               ? tsi_report_equilibrium_tree(r->sys, r->eq, r->eq_wall_s, t,
                                             defer)
               : NULL;
}

/* The loops' margins: [{name, gain_margin, gain_margin_db,
 * phase_crossover_hz, phase_margin_deg, gain_crossover_hz}] (null where
 * there is no crossing in the band), with the band and run time. */
static json_t *margins_json(const ts_result *r)
{
    json_t *o = json_object(), *a = json_array();
    if (!o || !a) {
        json_decref(o);
        json_decref(a);
        return NULL;
    }
    for (int i = 0; i < r->nmargins; i++) {
        const ts_loop_margin *m = &r->margins[i];
        json_t *e = json_object();
        if (!e)
            break;
        json_object_set_new(e, "name", json_string(m->name));
        json_object_set_new(e, "gain_margin", num(m->gain_margin));
        json_object_set_new(e, "gain_margin_db",
                            num(20.0 * log10(m->gain_margin)));
        json_object_set_new(e, "phase_crossover_hz",
                            num(m->phase_crossover_hz));
        json_object_set_new(e, "phase_margin_deg", num(m->phase_margin_deg));
        json_object_set_new(e, "gain_crossover_hz",
                            num(m->gain_crossover_hz));
        json_array_append_new(a, e);
    }
    json_object_set_new(o, "loops", a);
    json_object_set_new(o, "from_hz", json_real(TS_MARGINS_FROM_HZ));
    json_object_set_new(o, "to_hz", json_real(TS_MARGINS_TO_HZ));
    json_object_set_new(o, "wall_s", json_real(r->margins_wall_s));
    return o;
}

/* modes --free-vehicle: {speed, turn_rate, thrust, nstate, modes: [{re,
 * im, freq_hz, damping_ratio, coupled (1-based mode number of the
 * coupled table, null if none), coupled_re, coupled_im, coupled_freq_hz,
 * coupled_damping_ratio, mac}]}. */
static json_t *free_vehicle_json(const ts_result *r)
{
    const ts_free_vehicle *f = r->free_vehicle;
    json_t *o = json_object(), *a = json_array();
    if (!o || !a) {
        json_decref(o);
        json_decref(a);
        return NULL;
    }
    for (int i = 0; i < f->nmodes; i++) {
        const ts_free_mode *m = &f->modes[i];
        json_t *e = json_pack(
            "{s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o}", "re", num(m->re),
            "im", num(m->im), "freq_hz", num(m->freq_hz), "damping_ratio",
            num(m->damping_ratio), "coupled",
            m->coupled >= 0 ? json_integer(m->coupled + 1) : json_null(),
            "coupled_re", num(m->coupled_re), "coupled_im",
            num(m->coupled_im), "coupled_freq_hz", num(m->coupled_freq_hz),
            "coupled_damping_ratio", num(m->coupled_damping_ratio), "mac",
            num(m->mac));
        if (e)
            json_object_set_new(e, "mac_span", json_integer(m->span));
        json_array_append_new(a, e);
    }
    json_object_set_new(o, "speed", num(f->speed));
    json_object_set_new(o, "turn_rate", num(f->turn_rate));
    json_object_set_new(o, "thrust", num(f->thrust));
    json_object_set_new(o, "nstate", json_integer(f->nstate));
    json_object_set_new(o, "modes", a);
    return o;
}

/* {"discretisation": d, "solver": s} */
static json_t *error_json(double disc, double solver)
{
    return json_pack("{s:o,s:o}", "discretisation", num(disc), "solver",
                     num(solver));
}

static json_t *verdict_json(int v)
{
    return v >= 0 ? json_string(ts_verdict_name(v)) : json_null();
}

/* The stability verdict of the resolved modes and, apart, of the
 * unresolved ones (mode numbers 1-based among the modes computed). */
static json_t *stability_json(const ts_result *r)
{
    const ts_stability *st = &r->stability;
    json_t *o = json_pack(
        "{s:b,s:i,s:i,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o}", "estimated",
        st->estimated, "resolved_modes", st->nresolved, "unresolved_modes",
        st->nunresolved, "verdict", verdict_json(st->verdict), "mode",
        st->mode >= 0 ? json_integer(st->mode + 1) : json_null(),
        "max_real", num(st->max_real), "max_real_error",
        error_json(st->discretisation_error, st->solver_error),
        "unresolved_verdict", verdict_json(st->unresolved_verdict),
        "unresolved_mode",
        st->unresolved_mode >= 0 ? json_integer(st->unresolved_mode + 1)
                                 : json_null(),
        "unresolved_max_real", num(st->unresolved_max_real),
        "unresolved_max_real_error", num(st->unresolved_error),
        "modes_computed", json_integer(r->nmodes_computed));
    return o;
}

/* Every listed mode's discretisation error, shape scale and resolution. */
static void modes_accuracy_json(json_t *j, const ts_result *r)
{
    json_t *modes = json_object_get(j, "modes");
    for (int m = 0; r->mode_accuracy && m < r->eigen->nmodes; m++) {
        json_t *o = json_array_get(modes, (size_t)m);
        const ts_mode_accuracy *a = &r->mode_accuracy[m];
        const ts_mode *md = &r->eigen->modes[m];
        if (!o)
            break;
        json_object_set_new(o, "resolved", json_boolean(a->resolved));
        json_object_set_new(o, "grid_scale", json_boolean(a->grid_scale));
        json_object_set_new(o, "half_wave_links", num(a->half_wave_links));
        json_object_set_new(o, "error",
                            error_json(a->error, md->error_bound));
        json_object_set_new(o, "freq_discretisation_error_hz",
                            num(a->freq_error_hz));
        json_object_set_new(o, "damping_discretisation_error",
                            num(a->damping_error));
        json_object_set_new(o, "order", num(a->order));
    }
    json_object_set_new(j, "stability", stability_json(r));
}

static json_t *modes_json(const ts_result *r, int flags)
{
    if (!r->eigen || !r->mode_health)
        return json_object();
    json_t *j = ts_report_modes_json(r->sys, r->lin, r->eigen, 0);
    if (j && ts_report_modes_health_json(j, r->eigen, r->mode_health,
                                         &r->trust) != TS_OK) {
        json_decref(j);
        return NULL;
    }
    if (j)
        modes_accuracy_json(j, r);
    if (j)
        json_object_set_new(j, "linearization",
                            ts_report_linear_json(r->lin,
                                                  flags & TS_REPORT_MATRICES));
    if (j && r->nmargins > 0)
        json_object_set_new(j, "margins", margins_json(r));
    if (j && r->free_vehicle)
        json_object_set_new(j, "free_vehicle", free_vehicle_json(r));
    return j;
}

/* A value emitted by fn(w, a, b): with defer, a placeholder listed in
 * it, to be written in its place (report_impl.h); else built now. */
static json_t *deferred(tsi_json_defer *defer, tsi_json_emit_fn fn,
                        const void *a, const void *b)
{
    if (!defer)
        return tsi_json_build(fn, a, b);
    json_t *at = json_object();
    if (at && tsi_json_defer_add(defer, at, fn, a, b) != 0) {
        json_decref(at);
        return NULL;
    }
    return at;
}

/* A run's history h of result r: the channels reported, and the full
 * state when it was asked for. */
static void emit_history(tsi_json *w, const void *rv, const void *h)
{
    const ts_result *r = rv;
    tsi_json_object_open(w);
    tsi_report_channels_keys(w, r->sys, h, r->noutputs, r->outputs);
    if (r->all_outputs)
        tsi_report_full_keys(w, r->sys, h);
    tsi_json_object_close(w);
}

/* forces.links: every link's tension extremes, with its cable and
 * index. */
static void emit_force_links(tsi_json *w, const void *rv, const void *unused)
{
    (void)unused;
    const ts_result *r = rv;
    const ts_system *sys = r->sys;
    tsi_json_array_open(w);
    for (int l = 0; l < sys->nlinks; l++) {
        tsi_json_object_open(w);
        tsi_report_extremes_keys(w, &r->tensions[l]);
        tsi_json_key(w, "cable");
        tsi_json_str(w, sys->cables[sys->links[l].cable].name);
        tsi_json_key(w, "index");
        tsi_json_int(w, sys->links[l].index);
        tsi_json_object_close(w);
    }
    tsi_json_array_close(w);
}

/* The forces of the nonlinear run: the tow force, every link, the peak
 * and lowest links, the output's extremes, the links out of range. */
static json_t *forces_json(const ts_result *r, tsi_json_defer *defer)
{
    const ts_system *sys = r->sys;
    json_t *f = json_object(), *slack = json_array();
    json_t *links = deferred(defer, emit_force_links, r, NULL);
    if (!f || !links || !slack) {
        json_decref(f);
        json_decref(links);
        json_decref(slack);
        return NULL;
    }
    json_object_set_new(f, "from_s", num(r->forces_from));
    json_object_set_new(f, "tow", ts_report_extremes_json(&r->tow_force));
    json_object_set_new(f, "links", links);
    int pick[2] = {r->peak_link, r->low_link};
    static const char *const key[2] = {"peak_link", "low_link"};
    for (int k = 0; k < 2; k++) {
        const ts_link *L = pick[k] >= 0 ? &sys->links[pick[k]] : NULL;
        json_object_set_new(f, key[k],
                            L ? json_pack("{s:s,s:i}", "cable",
                                          sys->cables[L->cable].name,
                                          "index", L->index)
                              : json_null());
    }
    for (int k = 0; k < r->nslack; k++) {
        const ts_slack *e = &r->slack[k];
        const ts_link *L = &sys->links[e->link];
        json_array_append_new(
            slack, json_pack("{s:s,s:i,s:s,s:o,s:o,s:i,s:o}", "cable",
                             sys->cables[L->cable].name, "index", L->index,
                             "kind", e->elastic ? "slack" : "compression",
                             "t_first", num(e->t_first), "t_last",
                             num(e->t_last), "samples", e->samples, "min",
                             num(e->min)));
    }
    json_object_set_new(f, "slack", slack);
    return f;
}

/* The sea state of a response or a simulation: the spectral result with
 * the RAO file (and, with `points`, the spectra). */
static json_t *sea_json(const ts_result *r, int points)
{
    json_t *j = r->seastate
                    ? ts_report_seastate_json(r->seastate, &r->seaway, points)
                    : json_object();
    if (j) {
        json_object_set_new(j, "rao_file", json_string(r->rao_file));
        if (!json_object_get(j, "sea"))
            json_object_set_new(j, "sea", ts_report_sea_json(r->seaway.sea));
    }
    return j;
}

/* A simulation's sea: the realisation, the records' statistics and the
 * spectral prediction over the realisation's band. */
static json_t *sim_sea_json(const ts_result *r)
{
    json_t *j = json_object(), *rec = json_object();
    if (!j || !rec) {
        json_decref(j);
        json_decref(rec);
        return NULL;
    }
    if (r->has_records & 1)
        json_object_set_new(rec, "nonlinear",
                            ts_report_record_json(&r->record_nonlinear));
    if (r->has_records & 2)
        json_object_set_new(rec, "linear",
                            ts_report_record_json(&r->record_linear));
    json_object_set_new(j, "seed", json_integer((json_int_t)r->realisation.seed));
    json_object_set_new(j, "components",
                        json_integer(r->realisation.components));
    json_object_set_new(j, "fade_in_s", num(r->realisation.rise));
    json_object_set_new(j, "transient_s", num(r->transient));
    json_object_set_new(j, "records", rec);
    json_object_set_new(j, "spectral", sea_json(r, 0));
    return j;
}

/* The waypoint course of a run (the scene's autopilot): the waypoints,
 * those reached and when, and the depth range of every body. */
static json_t *waypoints_json(const ts_result *r, const ts_history *h)
{
    const ts_system *sys = r->sys;
    const ts_guidance *g = &sys->tow.autopilot.g;
    json_t *j = json_object(), *pts = json_array(), *reached = json_array(),
           *depth = json_array();
    if (!j || !pts || !reached || !depth) {
        json_decref(j);
        json_decref(pts);
        json_decref(reached);
        json_decref(depth);
        return NULL;
    }
    for (int i = 0; i < g->nwaypoints; i++)
        json_array_append_new(pts, json_pack("[o,o]", num(g->waypoint[i][0]),
                                             num(g->waypoint[i][1])));
    for (int i = 0; i < h->nreached; i++)
        json_array_append_new(reached,
                              json_pack("{s:i,s:o,s:o}", "index", i + 1,
                                        "t_s", num(h->reached_t[i]),
                                        "distance_m", num(h->reached_d[i])));
    ts_depth_range dr[TS_MAX_DEPTH_RANGES];
    int nd = ts_history_depth_ranges(sys, h, r->forces_from, dr,
                                     TS_MAX_DEPTH_RANGES);
    for (int k = 0; k < nd; k++)
        json_array_append_new(
            depth, json_pack("{s:s,s:o,s:o,s:o,s:o,s:o}", "body",
                             sys->bodies[dr[k].body].name, "min_m",
                             num(dr[k].min), "t_min_s", num(dr[k].t_min),
                             "max_m", num(dr[k].max), "t_max_s",
                             num(dr[k].t_max), "excursion_m",
                             num(dr[k].max - dr[k].min)));
    json_object_set_new(j, "points", pts);
    json_object_set_new(j, "radius_m", num(g->radius));
    json_object_set_new(j, "interval_s",
                        num(sys->tow.autopilot.interval));
    json_object_set_new(j, "reached", reached);
    json_object_set_new(j, "all_reached",
                        json_boolean(h->nreached == g->nwaypoints));
    json_object_set_new(j, "depth", depth);
    return j;
}

static json_t *simulate_json(const ts_result *r, int flags,
                             tsi_json_defer *defer)
{
    (void)flags;
    const ts_system *sys = r->sys;
    json_t *j = json_object();
    if (!j || !sys)
        return j;
    json_object_set_new(j, "scene", json_string(sys->name));
    json_object_set_new(j, "nlinks", json_integer(sys->nlinks));
    json_object_set_new(j, "output", json_string(r->output.name));
    json_object_set_new(j, "t_end", json_real(r->sim.t_end));
    json_object_set_new(j, "sample", json_real(r->sim.dt_sample));
    json_object_set_new(j, "initial", json_string(r->initial));
    json_object_set_new(j, "excitation",
                        r->excitation ? ts_report_excitation_json(r->excitation)
                                      : json_array());
    if (r->nonlinear) {
        json_t *o = json_object();
        json_object_set_new(o, "stats",
                            ts_report_sim_stats_json(
                                &r->nonlinear_stats,
                                ts_integrator_name(r->sim.integrator)));
        json_object_set_new(o, "rel_tol", json_real(r->sim.rel_tol));
        json_object_set_new(o, "abs_tol", json_real(r->sim.abs_tol));
        json_object_set_new(o, "history",
                            deferred(defer, emit_history, r, r->nonlinear));
        json_object_set_new(j, "nonlinear", o);
    }
    if (r->linear) {
        json_t *o = json_object();
        json_object_set_new(
            o, "stats",
            ts_report_sim_stats_json(&r->linear_stats,
                                     ts_linear_method_name(&r->sim,
                                                           &r->linear_stats)));
        json_object_set_new(o, "kinematics",
                            json_string(r->sim.kinematics == TS_KIN_LINEAR
                                            ? "linear"
                                            : "nonlinear"));
        json_object_set_new(o, "history",
                            deferred(defer, emit_history, r, r->linear));
        json_object_set_new(j, "linear", o);
    }
    json_t *outs = json_array();
    for (int k = 0; outs && k < r->noutputs; k++)
        json_array_append_new(outs, json_string(r->outputs[k].name));
    json_object_set_new(j, "outputs", outs);
    json_object_set_new(j, "full_state", json_boolean(r->all_outputs));
    const ts_history *ho = r->nonlinear ? r->nonlinear : r->linear;
    if (ho) {
        json_t *oe = ts_report_extremes_json(&r->output_extremes);
        if (oe)
            json_object_set_new(oe, "unit",
                                json_string(r->output.si_unit));
        json_object_set_new(j, "output_extremes", oe);
    }
    if (r->tensions)
        json_object_set_new(j, "forces", forces_json(r, defer));
    if (r->nonlinear && sys->tow.autopilot.on)
        json_object_set_new(j, "waypoints", waypoints_json(r, r->nonlinear));
    if (r->compared)
        json_object_set_new(j, "compare", ts_report_compare_json(&r->compare));
    if (r->has_sea)
        json_object_set_new(j, "sea", sim_sea_json(r));
    if (r->window.checked) {
        const ts_window *w = &r->window;
        json_object_set_new(
            j, "window",
            json_pack("{s:o,s:o,s:o,s:o,s:o,s:b,s:o,s:o,s:o,s:o,s:o,s:o,"
                      "s:o}",
                      "period_s", num(w->period), "transient_s",
                      num(w->transient), "t_end_s", num(w->t_end),
                      "slowest_time_constant_s", num(w->slowest_tau),
                      "slowest_freq_hz", num(w->slowest_freq_hz),
                      "modes_complete", w->modes_complete, "drift",
                      num(w->drift), "remaining", num(w->remaining),
                      "settled",
                      w->settled < 0 ? json_null()
                                     : json_boolean(w->settled),
                      "periodic",
                      w->periodic < 0 ? json_null()
                                      : json_boolean(w->periodic),
                      "transient_needed_s", num(w->transient_needed),
                      "t_end_needed_s", num(w->t_end_needed), "scale_m",
                      num(w->scale)));
    }
    /* Final positions of the bodies (the nonlinear run when there is
     * one). */
    const ts_history *hf = r->nonlinear ? r->nonlinear : r->linear;
    if (hf && hf->nsamples > 0) {
        json_t *bodies = json_array();
        const double *p = hf->positions +
                          3 * (size_t)hf->nnodes * (size_t)(hf->nsamples - 1);
        for (int b = 0; b < sys->nbodies; b++) {
            const double *q = p + 3 * ts_system_body_node(sys, b);
            json_array_append_new(bodies,
                                  json_pack("{s:s,s:f,s:f,s:f}", "name",
                                            sys->bodies[b].name, "x", q[0],
                                            "y", q[1], "z", q[2]));
        }
        json_object_set_new(j, "final_t",
                            json_real(hf->t[hf->nsamples - 1]));
        json_object_set_new(j, "final_bodies", bodies);
    }
    return j;
}

static json_t *converge_json(const ts_result *r)
{
    if (!r->convergence)
        return json_object();
    json_t *j = ts_report_convergence_json(r->convergence);
    if (j && r->excitation) {
        json_t *o = json_pack("{s:s,s:f,s:f,s:f,s:f,s:f}", "output",
                              r->output.name, "t_end", r->sim.t_end,
                              "sample", r->sim.dt_sample, "transient",
                              r->transient, "rel_tol", r->sim.rel_tol,
                              "abs_tol", r->sim.abs_tol);
        json_t *ej = ts_report_excitation_json(r->excitation);
        if (o && ej)
            json_object_set_new(o, "excitation", ej);
        else
            json_decref(ej);
        if (!o || json_object_set_new(j, "simulation", o) != 0) {
            json_decref(j);
            return NULL;
        }
    }
    return j;
}

static json_t *key_values_json(const ts_result *r)
{
    json_t *a = json_array();
    for (int i = 0; a && i < r->nvalues; i++) {
        const ts_value *v = &r->values[i];
        json_array_append_new(
            a, json_pack("{s:s,s:s,s:o,s:o,s:o}", "name", v->name, "unit",
                         v->unit, "value", num(v->value), "error",
                         error_json(v->error.discretisation,
                                    v->error.solver),
                         "order", num(v->order)));
    }
    return a;
}

/* The accuracy of a result against the continuum. */
static json_t *accuracy_json(const ts_result *r)
{
    const ts_result_accuracy *a = &r->accuracy;
    json_t *links = json_array(), *ratios = json_array();
    for (int k = 0; links && k < a->nlevels; k++)
        json_array_append_new(links, json_integer(a->links[k]));
    for (int k = 0; ratios && k + 1 < a->nlevels; k++)
        json_array_append_new(ratios, num(a->ratio[k]));
    json_t *methods = json_null();
    if (a->eigen_method[0] != TS_EIG_AUTO) {
        methods = json_array();
        for (int k = 0; methods && k < a->nlevels; k++)
            json_array_append_new(
                methods,
                json_string(ts_eig_method_name(
                    (ts_eig_method)a->eigen_method[k])));
    }
    return json_pack(
        "{s:o,s:b,s:o,s:o,s:o,s:o,s:o,s:I,s:o,s:o,s:o,s:o,s:o,s:o,s:i,s:o}",
        "accuracy", num(a->accuracy), "estimated", a->estimated,
        "not_estimated",
        a->not_estimated[0] ? json_string(a->not_estimated) : json_null(),
        "levels", links, "ratios", ratios, "order", num(a->order),
        "wall_s", num(a->wall_s), "evaluations", (json_int_t)a->evaluations,
        "max_relative_error", num(a->max_rel_error), "limiting",
        a->limiting[0] ? json_string(a->limiting) : json_null(), "met",
        a->met < 0 ? json_null() : json_boolean(a->met), "links_factor",
        num(a->links_factor), "links_needed",
        a->links_needed > 0 ? json_integer(a->links_needed) : json_null(),
        "refined_from",
        a->refined_from > 0 ? json_integer(a->refined_from) : json_null(),
        "refinements", a->refinements, "eigen_methods", methods);
}

/* Every point's discretisation and linearization (solver) error, and
 * where the accuracy holds. */
static void response_accuracy_json(json_t *j, const ts_result *r)
{
    json_t *pts = json_object_get(j, "points");
    const ts_response *res = r->response;
    for (int i = 0; i < res->npoints; i++) {
        json_t *o = json_array_get(pts, (size_t)i);
        if (!o)
            break;
        double lin = res->error ? res->error[i] : NAN;
        json_object_set_new(
            o, "magnitude_error",
            error_json(r->magnitude_error ? r->magnitude_error[i] : NAN, lin));
        json_object_set_new(
            o, "phase_error_deg",
            error_json(r->phase_error_deg ? r->phase_error_deg[i] : NAN,
                       res->magnitude[i] > 0
                           ? lin / res->magnitude[i] * 180.0 / M_PI
                           : NAN));
    }
    json_object_set_new(j, "accurate_to_hz", num(r->accurate_to_hz));
}

/* The result's document; with defer, its large arrays left to be
 * streamed (report_impl.h). */
static json_t *result_tree(const ts_result *r, int flags,
                           tsi_json_defer *defer)
{
    json_t *j = NULL;
    switch (r->kind) {
    case TS_ANALYSIS_EQUILIBRIUM:
        j = eq_json(r, &r->trust, defer);
        if (!j)
            j = json_object();
        break;
    case TS_ANALYSIS_MODES: j = modes_json(r, flags); break;
    case TS_ANALYSIS_RESPONSE:
        j = r->has_sea    ? sea_json(r, 1)
            : r->response ? ts_report_response_json(r->response)
                          : json_object();
        if (j && r->response && !r->has_sea)
            response_accuracy_json(j, r);
        break;
    case TS_ANALYSIS_SIMULATE: j = simulate_json(r, flags, defer); break;
    case TS_ANALYSIS_CONVERGE: j = converge_json(r); break;
    }
    if (!j)
        return NULL;
    if (r->kind == TS_ANALYSIS_MODES || r->kind == TS_ANALYSIS_RESPONSE) {
        json_t *e = eq_json(r, &r->eq_trust, defer);
        if (e)
            json_object_set_new(j, "equilibrium", e);
    }
    if (r->open_loop)
        json_object_set_new(j, "open_loop", json_true());
    json_object_set_new(j, "type", json_string(ts_analysis_name(r->kind)));
    json_object_set_new(j, "completed", json_boolean(r->completed));
    if (r->status != TS_OK)
        json_object_set_new(j, "error", json_string(r->error));
    set_trust(j, &r->trust);
    json_object_set_new(j, "key_values", key_values_json(r));
    if (r->kind != TS_ANALYSIS_CONVERGE)
        json_object_set_new(j, "accuracy", accuracy_json(r));
    /* JSON stays SI whatever the display: the units, named. */
    const ts_display *si = ts_display_or_si(NULL);
    json_t *units = json_object();
    for (int q = 0; units && q < TS_QTY_COUNT; q++)
        json_object_set_new(units, ts_quantity_name((ts_quantity)q),
                            json_string(ts_display_unit(si, (ts_quantity)q)));
    json_object_set_new(j, "units", units);
    return j;
}

json_t *ts_report_result_json(const ts_result *r, int flags)
{
    return result_tree(r, flags, NULL);
}

/* The streamed document with the keys of extra added last. */
static json_t *stream_tree(const ts_result *r, int flags, const json_t *extra,
                           tsi_json_defer *defer)
{
    json_t *j = result_tree(r, flags, defer);
    if (j && extra && json_object_update(j, (json_t *)extra) != 0) {
        json_decref(j);
        return NULL;
    }
    return j;
}

int ts_report_result_write_json(const ts_result *r, int flags,
                                const json_t *extra, const char *path,
                                ts_err *err)
{
    tsi_json_defer defer = {0};
    json_t *j = stream_tree(r, flags, extra, &defer);
    if (!j)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory for the JSON",
                       path);
    int rc = tsi_report_write_tree(j, &defer, path, err);
    json_decref(j);
    return rc;
}

int tsi_report_result_dump(const ts_result *r, int flags, const json_t *extra,
                           FILE *f, int indent, const char *name,
                           ts_err *err)
{
    tsi_json_defer defer = {0};
    json_t *j = stream_tree(r, flags, extra, &defer);
    if (!j)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory for the JSON",
                       name);
    int bad = tsi_report_dump_tree(j, &defer, f, indent) != 0;
    int e = errno;
    json_decref(j);
    return bad ? ts_fail(err, e == ENOMEM ? TS_ENOMEM : TS_EIO,
                         "%s: write failed (%s)", name, strerror(e))
               : TS_OK;
}

int ts_report_result_dumpf(const ts_result *r, int flags, const json_t *extra,
                           FILE *f, const char *name, ts_err *err)
{
    return tsi_report_result_dump(r, flags, extra, f, 1, name, err);
}

struct ts_report_results {
    char *name;       /* the target as given, for messages */
    FILE *given;      /* the caller's stream, or NULL */
    tsi_outfile out;  /* a file's temporary name beside it (out.f) */
    FILE *spool;      /* where the document goes: out.f, or a temporary
                         file copied to a direct target at the close */
    tsi_json *w;
};

void ts_report_results_abandon(ts_report_results *d)
{
    if (!d)
        return;
    tsi_json_close(d->w);
    if (d->spool && d->spool != d->out.f)
        fclose(d->spool);
    tsi_outfile_abandon(&d->out);
    free(d->name);
    free(d);
}

/* Fail with code (TS_ENOMEM when e is ENOMEM, else TS_EIO) naming d's
 * target, after giving d up. */
static int results_fail(ts_report_results *d, int e, ts_err *err)
{
    int rc = ts_fail(err, e == ENOMEM ? TS_ENOMEM : TS_EIO,
                     "%s: write failed (%s)", d->name, strerror(e));
    ts_report_results_abandon(d);
    return rc;
}

ts_report_results *ts_report_results_open(const char *path, FILE *f,
                                          const char *scene, ts_err *err)
{
    ts_report_results *d = calloc(1, sizeof *d);
    if (!d || !(d->name = strdup(path))) {
        free(d);
        ts_fail(err, TS_ENOMEM, "%s: out of memory for the JSON", path);
        return NULL;
    }
    d->given = f;
    tsi_outfile_id id;
    if (!f && tsi_outfile_identify(path, &id, NULL) == TS_OK &&
        id.kind == 0) {
        /* A file: written under its temporary name from the start. */
        if (tsi_outfile_open(&d->out, path, err) != TS_OK) {
            ts_report_results_abandon(d);
            return NULL;
        }
        d->spool = d->out.f;
    } else {
        /* Written in place: nothing goes there before the close. A path
         * that does not resolve fails there, as a single result's. */
        d->spool = tmpfile();
    }
    d->w = d->spool ? tsi_json_open(d->spool, 1) : NULL;
    if (!d->w) {
        results_fail(d, d->spool ? ENOMEM : errno, err);
        return NULL;
    }
    tsi_json_object_open(d->w);
    tsi_json_key(d->w, "scene");
    tsi_json_str(d->w, scene);
    tsi_json_key(d->w, "analyses");
    tsi_json_array_open(d->w);
    return d;
}

int ts_report_results_add(ts_report_results *d, const ts_result *r,
                          int flags, const json_t *extra, ts_err *err)
{
    tsi_json_defer defer = {0};
    json_t *j = stream_tree(r, flags, extra, &defer);
    if (!j)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory for the JSON",
                       d->name);
    tsi_json_tree(d->w, j, &defer);
    json_decref(j);
    int e = tsi_json_status(d->w);
    return e ? ts_fail(err, e == ENOMEM ? TS_ENOMEM : TS_EIO,
                       "%s: write failed (%s)", d->name, strerror(e))
             : TS_OK;
}

/* Copy the spooled document to f: 0, or -1 with errno set. */
static int copy_spool(FILE *spool, FILE *f)
{
    char buf[TSI_JSON_BUFFER];
    size_t n;
    if (fflush(spool) != 0 || fseek(spool, 0, SEEK_SET) != 0)
        return -1;
    while ((n = fread(buf, 1, sizeof buf, spool)) > 0)
        if (fwrite(buf, 1, n, f) != n)
            return -1;
    return ferror(spool) ? (errno = EIO, -1) : 0;
}

int ts_report_results_close(ts_report_results *d, const json_t *tail,
                            ts_err *err)
{
    tsi_json_array_close(d->w);
    const char *key;
    json_t *v;
    json_object_foreach((json_t *)tail, key, v)
    {
        tsi_json_key(d->w, key);
        tsi_json_tree(d->w, v, NULL);
    }
    tsi_json_object_close(d->w);
    int bad = tsi_json_close(d->w) != 0;
    d->w = NULL;
    if (bad)
        return results_fail(d, errno, err);
    if (d->spool == d->out.f) {
        d->spool = NULL;
        int rc = tsi_outfile_commit(&d->out, err);
        ts_report_results_abandon(d);
        return rc;
    }
    int rc = TS_OK;
    if (d->given) {
        if (copy_spool(d->spool, d->given) != 0 || fflush(d->given) != 0)
            return results_fail(d, errno, err);
    } else {
        rc = tsi_outfile_open(&d->out, d->name, err);
        if (rc == TS_OK && copy_spool(d->spool, d->out.f) != 0)
            return results_fail(d, errno, err);
        if (rc == TS_OK)
            rc = tsi_outfile_commit(&d->out, err);
    }
    ts_report_results_abandon(d);
    return rc;
}

int ts_report_result_csv(const ts_result *r, const char *path, ts_err *err)
{
    return ts_report_result_csv_display(r, NULL, path, err);
}

int ts_report_result_csv_display(const ts_result *r, const ts_display *d,
                                 const char *path, ts_err *err)
{
    switch (r->kind) {
    case TS_ANALYSIS_EQUILIBRIUM:
        if (r->eq && r->eq->converged)
            return ts_report_equilibrium_csv_display(r->sys, r->eq, d, path,
                                                     err);
        break;
    case TS_ANALYSIS_MODES:
        if (r->eigen)
            return ts_report_modes_csv_display(r->sys, r->lin, r->eigen, d,
                                               path, err);
        break;
    case TS_ANALYSIS_RESPONSE:
        if (r->seastate)
            return ts_report_seastate_csv_display(r->seastate, d, path,
                                                  err);
        if (r->response)
            return ts_report_response_csv_display(r->response, d, path, err);
        break;
    case TS_ANALYSIS_SIMULATE:
        if ((r->nonlinear || r->linear) && r->all_outputs)
            return ts_report_history_csv_display(r->sys, r->nonlinear,
                                                 r->linear, d, path, err);
        if (r->nonlinear || r->linear)
            return ts_report_channels_csv(r->sys, r->nonlinear, r->linear,
                                          r->noutputs, r->outputs, d, path,
                                          err);
        break;
    case TS_ANALYSIS_CONVERGE:
        if (r->convergence)
            return ts_report_convergence_csv_display(r->convergence, d, path,
                                                     err);
        break;
    }
    return ts_fail(err, TS_EINVAL, "%s: the %s result has no table to write",
                   path, ts_analysis_name(r->kind));
}
