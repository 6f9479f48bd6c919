/* analysis.c: one pipeline per analysis (towstab/analysis.h;
 * doc/architecture.md, "Pipelines").
 *
 * Every pipeline starts from a copy of the system with the request's
 * settings applied (ts_setup), checks what can be checked before anything
 * runs, and fills one ts_result: the parts it computed (equilibrium,
 * linearization, modes, response, histories, comparison, sweep), the
 * verdict on them (towstab/health.h, judged here and nowhere else), the
 * key values with their solver error estimates, the run time and the
 * kernel evaluations. A failure ends the pipeline with its code and
 * message in the result, which keeps what was computed before it and is
 * never trustworthy.
 *
 * The chains (doc/linear.md, doc/simulate.md, doc/converge.md):
 *   equilibrium  solve (doc/equilibrium.md);
 *   modes        equilibrium -> linearize about it with a fresh kernel
 *                re-charted from its directions -> eigen (LAPACK, or
 *                ARPACK for a subset) -> health of the modes;
 *   response     the same linearization (with tension Jacobians for a
 *                tension output) -> frequency response at log-spaced
 *                frequencies (and optionally the lowest natural ones);
 *                with a sea, the spectral response to it instead
 *                (towstab/seastate.h) and its discretisation error;
 *   simulate     initial state (equilibrium, released or a shape file)
 *                -> the linear model about the equilibrium (linearized
 *                with the equilibrium's own kernel, whose charts both runs
 *                then start from) and/or the nonlinear integration ->
 *                comparison and the fit of the output's amplitude ratio,
 *                mean offset and phase against a periodic excitation;
 *                with a sea, a realisation of it added to the
 *                excitation, the records' statistics and the spectral
 *                prediction over the realisation's band;
 *   converge     one of the above rerun at every setting of a resolution
 *                sweep (towstab/converge.h estimates errors and orders),
 *                one series per integrator for a simulation.
 * The convergence study calls the same pipelines through
 * ts_analysis_sweep, so a sweep's runs are exactly what the commands run.
 *
 * One module: the pipelines share the system set-up, the equilibrium and
 * linearization stages, the result and its key values, and converge runs
 * the others; split, each file would need the others' internals.
 */
#include "towstab/analysis.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "clock.h"
#include "csvtab.h"
#include "lazylib.h"
#include "response_impl.h"
#include "towstab/kernel.h"
#include "towstab/track.h"

/* Noise of an equilibrium value: this many times its relative residual
 * (at least EQ_NOISE_MIN_REL) times the length or force scale. */
#define EQ_NOISE_FACTOR 10.0
#define EQ_NOISE_MIN_REL (16.0 * DBL_EPSILON)
/* A towing vehicle's solved rudder deflection is judged relative to
 * itself, or to this (rad: a degree) when smaller. */
#define DEFLECTION_SCALE (M_PI / 180.0)
/* Noise of a mode value in a step sweep, relative. */
#define STEP_NOISE_REL (64.0 * DBL_EPSILON)
/* Rounding noise of a simulated value: this many eps per sqrt(step). */
#define SIM_ROUND_EPS 16.0
/* Integrator noise of a simulated value in a links sweep: this many times
 * rel_tol of the value's scale. */
#define SIM_TOL_NOISE 10.0
/* Key values of a simulation under a periodic excitation: amplitude
 * ratio, mean offset, phase (SIM_FIT values), then the extreme link
 * tensions over the window; the extremes of the forces (over the window
 * too, sim_forces) follow (sim_values). */
#define SIM_FIT 3
#define SIM_TMAX 3
#define SIM_TMIN 4

static const char *const kind_names[TS_ANALYSIS_COUNT] = {
    "equilibrium", "modes", "response", "simulate", "converge"};

const char *ts_analysis_name(ts_analysis_kind kind)
{
    return (int)kind >= 0 && kind < TS_ANALYSIS_COUNT ? kind_names[kind]
                                                      : "?";
}

int ts_analysis_find(const char *name)
{
    for (int k = 0; name && k < TS_ANALYSIS_COUNT; k++)
        if (strcmp(name, kind_names[k]) == 0)
            return k;
    return -1;
}

/* ---- requests ---------------------------------------------------------- */

void ts_request_init(ts_request *rq, ts_analysis_kind kind)
{
    memset(rq, 0, sizeof *rq);
    rq->kind = kind;
    rq->setup.speed = NAN;
    rq->setup.turn_rate = NAN;
    ts_equilibrium_opts_default(&rq->setup.equilibrium);
    rq->setup.accuracy = TS_ACCURACY_DEFAULT;
    rq->setup.discretisation_error = kind != TS_ANALYSIS_SIMULATE &&
                                     kind != TS_ANALYSIS_CONVERGE;
    ts_eigen_opts_default(&rq->modes.eigen);
    rq->modes.follow = TS_MODES_FOLLOW;
    rq->modes.margins = 1;
    ts_linearize_opts_default(&rq->modes.linearize);
    snprintf(rq->response.input, sizeof rq->response.input, "tow.heave");
    rq->response.from_hz = TS_RESPONSE_FROM_HZ;
    rq->response.to_hz = TS_RESPONSE_TO_HZ;
    rq->response.points = TS_RESPONSE_POINTS;
    rq->response.intervals = TS_SEASTATE_INTERVALS;
    rq->response.duration = TS_SEASTATE_DURATION;
    rq->simulate.seed = 1;
    rq->simulate.components = TS_SEA_COMPONENTS;
    rq->simulate.fade_in = NAN;
    ts_sim_opts_default(&rq->simulate.sim);
    rq->simulate.sim.t_end = TS_SIMULATE_T_END;
    rq->simulate.sim.dt_sample = 0;
    rq->simulate.transient = NAN;
    rq->simulate.check_window = 1;
    rq->converge.analysis = TS_ANALYSIS_EQUILIBRIUM;
    rq->converge.param = TS_CONV_LINKS;
    rq->converge.target = TS_CONVERGE_TARGET;
}

void ts_request_clear(ts_request *rq)
{
    ts_excitation_free(rq->simulate.excitation);
    ts_sea_free(rq->response.sea.sea);
    ts_rao_free(rq->response.sea.rao);
    ts_sea_free(rq->simulate.sea.sea);
    ts_rao_free(rq->simulate.sea.rao);
    ts_request_init(rq, rq->kind);
}

const char *ts_converge_default_sweep(ts_analysis_kind analysis,
                                      ts_conv_param *param)
{
    *param = analysis == TS_ANALYSIS_SIMULATE ? TS_CONV_TOLERANCE
                                              : TS_CONV_LINKS;
    switch (analysis) {
    case TS_ANALYSIS_MODES: return "10,20,40,80";
    case TS_ANALYSIS_SIMULATE: return "1e-3,1e-5,1e-7,1e-9";
    default: return "5,10,20,40,80,160,320";
    }
}

/* The default sweep as numbers. */
static int default_settings(ts_analysis_kind analysis, ts_conv_param *param,
                            double *settings)
{
    const char *text = ts_converge_default_sweep(analysis, param);
    int n = 0;
    for (const char *p = text; *p && n < TS_CONV_MAX_SETTINGS;) {
        char *end;
        settings[n++] = strtod(p, &end);
        p = *end == ',' ? end + 1 : end;
    }
    return n;
}

/* ---- the system -------------------------------------------------------- */

int ts_setup_set(ts_setup *s, const char *path, double value, ts_err *err)
{
    return ts_setup_set_in(s, path, value, NULL, NULL, err);
}

int ts_setup_set_in(ts_setup *s, const char *path, double value,
                    const char *unit, const char *given, ts_err *err)
{
    char canon[TS_PARAM_PATH_MAX], other[TS_PARAM_PATH_MAX];
    int rc = ts_param_canonical(path, canon, sizeof canon, err);
    if (rc)
        return rc;
    int i = 0;
    for (; i < s->nsets; i++)
        if (ts_param_canonical(s->sets[i].path, other, sizeof other,
                               NULL) == TS_OK &&
            !strcmp(other, canon))
            break;
    if (i == TS_SETUP_MAX_SETS)
        return ts_fail(err, TS_EINVAL, "set: at most %d scene values",
                       TS_SETUP_MAX_SETS);
    if (unit && strlen(unit) >= sizeof s->sets[i].unit)
        return ts_fail(err, TS_EINVAL, "set: %s: unit '%s' longer than %zu "
                       "characters", canon, unit, sizeof s->sets[i].unit - 1);
    snprintf(s->sets[i].path, sizeof s->sets[i].path, "%s", canon);
    s->sets[i].value = value;
    snprintf(s->sets[i].unit, sizeof s->sets[i].unit, "%s",
             unit ? unit : "");
    snprintf(s->sets[i].given, sizeof s->sets[i].given, "%s",
             unit && unit[0] && given ? given : "");
    if (i == s->nsets)
        s->nsets++;
    return TS_OK;
}

/* The setup's own checks (those a scene makes of tow.speed and
 * tow.turn_rate, and the link limit). */
static int check_setup(const ts_setup *s, ts_err *err)
{
    if (s->nsets < 0 || s->nsets > TS_SETUP_MAX_SETS)
        return ts_fail(err, TS_EINVAL, "set: expected 0 to %d scene values, "
                       "got %d", TS_SETUP_MAX_SETS, s->nsets);
    for (int i = 0; i < s->nsets; i++) {
        char canon[TS_PARAM_PATH_MAX];
        int rc = ts_param_canonical(s->sets[i].path, canon, sizeof canon,
                                    err);
        if (rc) {
            ts_err_prefix(err, "set: ");
            return rc;
        }
        static const char *const own[2] = {"speed", "turn_rate"};
        double given[2] = {s->speed, s->turn_rate};
        for (int k = 0; k < 2; k++)
            if (!isnan(given[k]) && !strcmp(canon + 4, own[k]) &&
                !strncmp(canon, "tow.", 4))
                return ts_fail(err, TS_EINVAL, "set: %s is also given as "
                               "%s; give it once", canon, own[k]);
        if (s->links > 0 && strlen(canon) > 6 &&
            !strcmp(canon + strlen(canon) - 6, ".links"))
            return ts_fail(err, TS_EINVAL, "set: %s and links (every cable) "
                           "both set links; give one", canon);
    }
    if (!isnan(s->speed) && !(s->speed >= 0 && isfinite(s->speed)))
        return ts_fail(err, TS_EINVAL, "speed: must be >= 0 m/s, got %g m/s",
                       s->speed);
    if (!isnan(s->turn_rate) && !isfinite(s->turn_rate))
        return ts_fail(err, TS_EINVAL,
                       "turn_rate: must be finite, got %g rad/s",
                       s->turn_rate);
    if (s->links != 0 && (s->links < 1 || s->links > TS_MAX_LINKS))
        return ts_fail(err, TS_EINVAL,
                       "links: expected 1 to %d per cable, got %d",
                       TS_MAX_LINKS, s->links);
    const ts_equilibrium_opts *e = &s->equilibrium;
    if (!(e->tol > 0 && e->tol < 1))
        return ts_fail(err, TS_EINVAL,
                       "tolerance: expected a number in (0, 1), got %g",
                       e->tol);
    if (!(s->accuracy > 0 && s->accuracy < 1))
        return ts_fail(err, TS_EINVAL,
                       "accuracy: expected a relative error in (0, 1), got "
                       "%g", s->accuracy);
    return TS_OK;
}

/* A simulation's waypoints (simulate.waypoints) in place of the points of
 * the scene's waypoints entry. */
static int set_waypoints(ts_system *c, const ts_simulate_opts *s,
                         ts_err *err)
{
    ts_autopilot *ap = &c->tow.autopilot;
    if (!ap->on)
        return ts_fail(err, TS_EINVAL, "waypoints: they replace the points "
                       "of the scene's waypoints entry, which gives the "
                       "rudders and the heading law's gain; the scene has "
                       "none%s", c->tow.vehicle < 0 ? " (and no "
                       "towing_vehicle to steer)" : "");
    ts_guidance g = ap->g;
    g.nwaypoints = s->nwaypoints;
    memcpy(g.waypoint, s->waypoints,
           (size_t)s->nwaypoints * sizeof g.waypoint[0]);
    int rc = ts_guidance_check(&g, "waypoints", err);
    if (rc == TS_OK)
        ap->g = g;
    else
        ts_err_prefix(err, "waypoints: ");
    return rc;
}

/* A copy of sys with the request's setup (and a simulation's waypoints)
 * applied, built; NULL on failure. */
static ts_system *setup_system(const ts_system *sys, const ts_request *rq,
                               ts_err *err)
{
    const ts_setup *s = &rq->setup;
    if (check_setup(s, err) != TS_OK)
        return NULL;
    /* A towing vehicle solves its speed and turn rate: the options
     * would only move the solve's start (given by tow.speed in the
     * scene, or --set). */
    static const char *const own[2] = {"speed", "turn_rate"};
    static const char *const why[2] = {
        "the run would not be at the speed given",
        "the run would not turn at the rate given"};
    double given[2] = {s->speed, s->turn_rate};
    for (int k = 0; k < 2; k++)
        if (!isnan(given[k]) &&
            ts_param_solved(sys, k ? "tow.turn_rate" : "tow.speed", why[k],
                            "set", err) != TS_OK) {
            ts_err_prefix(err, "%s: ", own[k]);
            return NULL;
        }
    ts_system *c = ts_system_copy(sys, err);
    if (!c)
        return NULL;
    if (rq->kind == TS_ANALYSIS_SIMULATE && rq->simulate.nwaypoints > 0 &&
        set_waypoints(c, &rq->simulate, err) != TS_OK) {
        ts_system_free(c);
        return NULL;
    }
    /* A loop's key given with a unit: the unit must be the loop's (a
     * length for depth, an angle else: towstab/param.h). */
    for (int i = 0; i < s->nsets; i++)
        if (ts_param_fits(c, s->sets[i].path, s->sets[i].unit,
                          s->sets[i].given, err) != TS_OK ||
            ts_param_set(c, s->sets[i].path, s->sets[i].value, err) !=
            TS_OK) {
            ts_err_prefix(err, "set: ");
            ts_system_free(c);
            return NULL;
        }
    if (!isnan(s->speed))
        c->tow.speed = s->speed;
    if (!isnan(s->turn_rate))
        c->tow.turn_rate = s->turn_rate;
    int rc = s->links > 0 ? ts_system_set_links(c, s->links, err)
                          : ts_system_build(c, err);
    if (rc != TS_OK) {
        ts_system_free(c);
        return NULL;
    }
    return c;
}

static double total_length(const ts_system *sys)
{
    double L = 0;
    for (int c = 0; c < sys->ncables; c++)
        L += sys->cables[c].length;
    return L;
}

/* ---- results ----------------------------------------------------------- */

static ts_result *result_alloc(ts_analysis_kind kind, ts_err *err)
{
    ts_result *r = calloc(1, sizeof *r);
    if (!r) {
        ts_fail(err, TS_ENOMEM, "%s: out of memory", ts_analysis_name(kind));
        return NULL;
    }
    r->kind = kind;
    ts_trust_init(&r->trust);
    ts_trust_init(&r->eq_trust);
    ts_trust_init(&r->modes_trust);
    r->transient = NAN;
    r->peak_link = r->low_link = -1;
    r->accurate_to_hz = NAN;
    ts_result_accuracy *a = &r->accuracy;
    a->accuracy = NAN;
    a->order = a->wall_s = a->max_rel_error = NAN;
    a->limiting_order = a->limiting_theory = a->links_factor = NAN;
    a->met = -1;
    r->stability.verdict = r->stability.unresolved_verdict = -1;
    r->stability.mode = r->stability.unresolved_mode = -1;
    r->stability.max_real = r->stability.unresolved_max_real = NAN;
    r->stability.discretisation_error = r->stability.solver_error = NAN;
    r->stability.unresolved_error = NAN;
    return r;
}

void ts_result_free(ts_result *r)
{
    if (!r)
        return;
    free(r->values);
    ts_system_free(r->sys);
    ts_equilibrium_free(r->eq);
    ts_linear_free(r->lin);
    ts_eigen_free(r->eigen);
    free(r->mode_health);
    free(r->margins);
    ts_free_vehicle_free(r->free_vehicle);
    free(r->mode_accuracy);
    ts_response_free(r->response);
    ts_seastate_free(r->seastate);
    ts_excitation_free(r->sea_excitation);
    free(r->magnitude_error);
    free(r->phase_error_deg);
    ts_history_free(r->nonlinear);
    ts_history_free(r->linear);
    free(r->outputs);
    free(r->tensions);
    free(r->slack);
    ts_convergence_free(r->convergence);
    free(r);
}

const ts_value *ts_result_value(const ts_result *r, const char *name)
{
    for (int i = 0; r && name && i < r->nvalues; i++)
        if (strcmp(r->values[i].name, name) == 0)
            return &r->values[i];
    return NULL;
}

int ts_result_margin(const ts_result *r, ts_margin *m)
{
    const ts_stability *st = r ? &r->stability : NULL;
    m->max_real = m->freq_hz = NAN;
    m->error.discretisation = m->error.solver = NAN;
    m->verdict = -1;
    m->resolved = 0;
    if (!r || !r->eigen)
        return 0;
    if (st->mode >= 0 && st->verdict >= 0) {
        m->max_real = st->max_real;
        m->error.solver = st->solver_error;
        m->error.discretisation = st->discretisation_error;
        m->freq_hz = r->eigen->modes[st->mode].freq_hz;
        m->verdict = st->verdict;
        m->resolved = 1;
    } else if (st->unresolved_mode >= 0 && st->unresolved_verdict >= 0) {
        m->max_real = st->unresolved_max_real;
        m->error.solver = st->unresolved_error;
        m->freq_hz = r->eigen->modes[st->unresolved_mode].freq_hz;
        m->verdict = st->unresolved_verdict;
    }
    return m->verdict >= 0;
}

/* Room for n key values, named later; NAN values and estimates. */
static int values_alloc(ts_result *r, int n, ts_err *err)
{
    r->values = calloc((size_t)(n > 0 ? n : 1), sizeof *r->values);
    if (!r->values)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory",
                       ts_analysis_name(r->kind));
    r->nvalues = n;
    for (int i = 0; i < n; i++) {
        r->values[i].value = NAN;
        r->values[i].error.discretisation = NAN;
        r->values[i].error.solver = NAN;
        r->values[i].order = NAN;
    }
    return TS_OK;
}

static void value_name(ts_value *v, const char *unit, double scale,
                       const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static void value_name(ts_value *v, const char *unit, double scale,
                       const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->name, sizeof v->name, fmt, ap);
    va_end(ap);
    snprintf(v->unit, sizeof v->unit, "%s", unit);
    v->scale = scale;
}

/* End a pipeline: record the outcome; a failure is never trustworthy. */
static int finish(ts_result *r, int rc, const ts_err *e, ts_err *err,
                  double t0)
{
    r->wall_s = tsi_wall_now() - t0;
    r->status = rc;
    r->completed = rc == TS_OK;
    if (rc != TS_OK) {
        const char *msg = e && e->msg[0] ? e->msg : ts_strerror(rc);
        snprintf(r->error, sizeof r->error, "%s", msg);
        ts_trust_fail(&r->trust, "the run failed: %s", msg);
        if (err && err != e)
            ts_fail(err, rc, "%s", msg);
    }
    return rc;
}

/* ---- equilibrium ------------------------------------------------------- */

/* Reported points: the bodies, or without bodies the free cable ends. */
static int npoints(const ts_system *sys)
{
    if (sys->nbodies > 0)
        return sys->nbodies;
    int n = 0;
    for (int c = 0; c < sys->ncables; c++)
        n += sys->cables[c].to_body < 0;
    return n;
}

/* Node of reported point i. */
static int point_node(const ts_system *sys, int i)
{
    if (sys->nbodies > 0)
        return ts_system_body_node(sys, i);
    int k = 0;
    for (int c = 0; c < sys->ncables; c++) {
        if (sys->cables[c].to_body >= 0 || k++ != i)
            continue;
        for (int l = 0; l < sys->nlinks; l++)
            if (sys->links[l].cable == c && sys->links[l].next < 0)
                return sys->links[l].lower;
    }
    return -1;
}

/* Key values of an equilibrium: x, y, z of the points ("<body>.x", or
 * "<cable>.end.x"; scale the cable length) and the top tension (relative
 * to itself), into v[3 npoints + 1] (allocated by values_alloc: NAN
 * values and estimates). Solver error: EQ_NOISE_FACTOR times the
 * relative residual (at least EQ_NOISE_MIN_REL) of the length or the
 * largest force, for the points at least the solver's shape error
 * (doc/equilibrium.md, "How far to trust it"). eq may be NULL or not
 * converged: names only. */
static void eq_values_into(const ts_system *sys, const ts_equilibrium *eq,
                           ts_value *v0)
{
    int np = npoints(sys);
    double L = total_length(sys);
    static const char axis[3] = {'x', 'y', 'z'};
    for (int i = 0, c = 0; i < np; i++) {
        for (int j = 0; j < 3; j++) {
            ts_value *v = &v0[3 * i + j];
            if (sys->nbodies > 0) {
                value_name(v, "m", L, "%.63s.%c", sys->bodies[i].name,
                           axis[j]);
            } else {
                while (sys->cables[c].to_body >= 0)
                    c++;
                value_name(v, "m", L, "%.60s.end.%c", sys->cables[c].name,
                           axis[j]);
            }
        }
        if (sys->nbodies == 0)
            c++;
    }
    value_name(&v0[3 * np], "N", 0.0, "top_tension");
    if (!eq || !eq->converged)
        return;
    double rel = fmax(eq->residual, EQ_NOISE_MIN_REL);
    /* A small residual is not a small error when the problem is
     * ill-conditioned: the solver's first-order estimate of how far the
     * nodes are from the solution (shape_error) bounds it from below. */
    double pos_err = EQ_NOISE_FACTOR * rel * L;
    if (eq->shape_error > pos_err)
        pos_err = eq->shape_error;
    for (int i = 0; i < np; i++) {
        int node = point_node(sys, i);
        for (int j = 0; j < 3; j++) {
            v0[3 * i + j].value = eq->positions[3 * node + j];
            v0[3 * i + j].error.solver = pos_err;
        }
    }
    v0[3 * np].value = eq->top_tension;
    v0[3 * np].error.solver = EQ_NOISE_FACTOR * rel * eq->force_scale;
}

/* The solved steady motion of a towing vehicle (doc/towing-vehicle.md,
 * section 3) as key values after the top tension: what the equilibrium
 * solved for, not what the scene gave. Along the track, the speed and the
 * power at a given thrust, the speed and the thrust at a given power, the
 * thrust and the power of a speed controller; across it, the turn rate at
 * the given deflections, or with turn_by the turn surface's deflection.
 * Returns their number (0 without a towing vehicle); with v0 non-NULL
 * names them into v0[] and, when eq has converged, fills them. */
static int tow_values(const ts_system *sys, const ts_equilibrium *eq,
                      ts_value *v0)
{
    if (sys->tow.vehicle < 0)
        return 0;
    const ts_body *b = &sys->bodies[sys->tow.vehicle];
    const char *nm = b->name;
    int bias = b->vehicle->propulsion.type == TS_PROP_SPEED;
    int turn_by = sys->tow.turn_surface >= 0;
    if (!v0)
        return 3;
    /* Along the track: the unknown solved, then what follows from it. */
    if (bias) {
        value_name(&v0[0], "N", 0.0, "%.63s.thrust", nm);
        value_name(&v0[1], "W", 0.0, "%.63s.power", nm);
    } else {
        value_name(&v0[0], "m/s", 0.0, "%.63s.speed", nm);
        value_name(&v0[1], b->vehicle->propulsion.type == TS_PROP_POWER
                               ? "N" : "W", 0.0,
                   b->vehicle->propulsion.type == TS_PROP_POWER
                       ? "%.63s.thrust" : "%.63s.power", nm);
    }
    if (turn_by)
        value_name(&v0[2], "rad", 0.0, "%.63s.%.63s.deflection", nm,
                   b->vehicle->component[sys->tow.turn_surface].name);
    else
        value_name(&v0[2], "rad/s", 0.0, "%.63s.turn_rate", nm);
    if (!eq || !eq->converged)
        return 3;
    const ts_vehicle_result *vr = NULL;
    for (int v = 0; v < eq->nvehicles; v++)
        if (eq->vehicles[v].towing)
            vr = &eq->vehicles[v];
    if (!vr)
        return 3;
    double rel = EQ_NOISE_FACTOR * fmax(eq->residual, EQ_NOISE_MIN_REL);
    /* The unknown along the track carries Newton's next step; thrust,
     * power and speed vary together along it (T = P / u, P = T u), so
     * what follows from it has the same relative error. */
    double x = bias ? vr->thrust : eq->speed;
    double ex = fmax(EQ_NOISE_FACTOR * eq->motion_step[0],
                     rel * (bias ? eq->force_scale : fabs(x)));
    double follows = bias ? vr->power
                     : b->vehicle->propulsion.type == TS_PROP_POWER
                         ? vr->thrust : vr->power;
    v0[0].value = bias ? vr->thrust : eq->speed;
    v0[0].error.solver = ex;
    v0[1].value = follows;
    v0[1].error.solver = fabs(x) > 0 ? fabs(follows) * ex / fabs(x) : NAN;
    /* Across it: a turn rate relative to itself or, near zero, to V / L
     * (the turn whose radius is the cables' length); a deflection
     * relative to itself or to DEFLECTION_SCALE. */
    double y = turn_by ? vr->delta[sys->tow.turn_surface] : eq->turn_rate;
    double yscale = turn_by ? DEFLECTION_SCALE
                            : fabs(eq->speed) / total_length(sys);
    v0[2].value = y;
    v0[2].scale = fmax(fabs(y), yscale);
    v0[2].error.solver = fmax(EQ_NOISE_FACTOR * eq->motion_step[1],
                              rel * v0[2].scale);
    return 3;
}

static int eq_nvalues(const ts_system *sys)
{
    return 3 * npoints(sys) + 1 + tow_values(sys, NULL, NULL);
}

static int eq_values(ts_result *r, ts_err *err)
{
    int rc = values_alloc(r, eq_nvalues(r->sys), err);
    if (rc == TS_OK) {
        eq_values_into(r->sys, r->eq, r->values);
        tow_values(r->sys, r->eq, r->values + 3 * npoints(r->sys) + 1);
    }
    return rc;
}

int ts_result_equilibrium_values(const ts_result *r, ts_value **values,
                                 int *n, ts_err *err)
{
    *values = NULL;
    *n = 0;
    if (!r || !r->sys)
        return ts_fail(err, TS_EINVAL, "equilibrium values: the result has "
                       "no system");
    ts_result tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.kind = TS_ANALYSIS_EQUILIBRIUM;
    int rc = values_alloc(&tmp, eq_nvalues(r->sys), err);
    if (rc)
        return rc;
    eq_values_into(r->sys, r->eq, tmp.values);
    tow_values(r->sys, r->eq, tmp.values + 3 * npoints(r->sys) + 1);
    *values = tmp.values;
    *n = tmp.nvalues;
    return TS_OK;
}

/* Solve the equilibrium of r->sys with kernel k (re-charted by the
 * solver), with the request's equilibrium options and its progress
 * callback (unless the options have their own). Its own verdict goes to
 * r->eq_trust. */
static int run_equilibrium(ts_result *r, ts_kernel *k, const ts_request *rq,
                           ts_err *err)
{
    /* A stop asked for before (during the setup, or a stage that cannot
     * poll: a shooting solve, a linearization) is taken here. */
    ts_progress p = {"equilibrium", 0, 1, "solves"};
    if (rq->progress && rq->progress(&p, rq->progress_data))
        return ts_fail(err, TS_ECANCEL, "equilibrium: stopped on request "
                                        "before it started");
    r->eq = ts_equilibrium_alloc(r->sys, err);
    if (!r->eq)
        return err && err->code ? err->code : TS_ENOMEM;
    ts_equilibrium_opts eo = rq->setup.equilibrium;
    if (!eo.progress) {
        eo.progress = rq->progress;
        eo.progress_data = rq->progress_data;
    }
    double t0 = tsi_wall_now();
    int rc = ts_equilibrium_solve(k, &eo, r->eq, err);
    r->eq_wall_s = tsi_wall_now() - t0;
    /* A stop asked for in the part of the solve that does not poll (a
     * shooting solve, the last LU factorisation) is taken here; the
     * equilibrium is kept as solved. */
    p.done = 1;
    if (rc == TS_OK && rq->progress && rq->progress(&p, rq->progress_data))
        rc = ts_fail(err, TS_ECANCEL, "equilibrium: stopped on request "
                                      "after it converged");
    r->eq_attempted = rc != TS_EINVAL && rc != TS_EDOMAIN;
    r->evaluations += r->eq->evaluations;
    if (rc == TS_OK)
        ts_health_equilibrium(r->sys, r->eq, &r->eq_trust);
    return rc;
}

/* Linearize about r->eq with a fresh kernel re-charted from its
 * directions; with open_loop, the vehicles' loops open at the trim
 * (towstab/control.h). An equilibrium that did not converge is not
 * linearized. */
static int run_linearize(ts_result *r, const ts_linearize_opts *lo,
                         int open_loop, ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(r->sys, err);
    if (!k)
        return err && err->code ? err->code : TS_ENOMEM;
    int rc = TS_OK;
    double t0 = tsi_wall_now();
    if (open_loop && ts_control_nloops(k) > 0) {
        r->open_loop = 1;
        rc = ts_linearize_open_loop(k, r->eq, lo, &r->lin, err);
    } else {
        r->lin = ts_linear_alloc(k, err);
        rc = r->lin ? ts_linearize_equilibrium(k, r->eq, lo, r->lin, err)
                    : (err && err->code ? err->code : TS_ENOMEM);
    }
    r->lin_wall_s = tsi_wall_now() - t0;
    if (r->lin)
        r->evaluations += r->lin->evaluations;
    ts_kernel_free(k);
    if (rc != TS_OK) {
        ts_linear_free(r->lin);
        r->lin = NULL;
    }
    return rc;
}

static ts_eigen_opts modes_eigen_opts(const ts_modes_opts *m, int n);

/* The libraries the modes of a linear model of n states will open
 * (lib/lazylib.h): LAPACK always (the dense eigen analysis, or the Ritz
 * vectors of ARPACK's runs), ARPACK when the method at n is ARPACK, KLU
 * with the sparse model (any model but the dense one alone). */
static int modes_libraries(const ts_modes_opts *m,
                           const ts_linearize_opts *lo, int n)
{
    ts_eigen_opts o = modes_eigen_opts(m, n);
    return TSI_PRELOAD_LAPACK |
           (ts_eigen_method(n, &o) == TS_EIG_ARPACK ? TSI_PRELOAD_ARPACK
                                                    : 0) |
           (lo->model != TS_LIN_DENSE ? TSI_PRELOAD_KLU : 0);
}

/* The equilibrium stage of modes and response: solve, then linearize
 * (the linear model lo). With `modes` (the modes pipeline) the libraries
 * the modes will need are opened ahead, beside the two
 * (modes_libraries). */
static int equilibrium_then_linear(ts_result *r, const ts_request *rq,
                                   const ts_linearize_opts *lo, int modes,
                                   ts_err *err)
{
    tsi_preload pre = {0};
    ts_kernel *k = ts_kernel_alloc(r->sys, err);
    if (k && modes)
        tsi_preload_start(&pre, modes_libraries(&rq->modes, lo,
                                                ts_kernel_nstate(k)));
    int rc = k ? run_equilibrium(r, k, rq, err)
               : (err && err->code ? err->code : TS_ENOMEM);
    ts_kernel_free(k);
    if (rc != TS_OK) {
        if (r->eq && !r->eq->converged)
            ts_err_prefix(err, "the equilibrium did not converge, so it is "
                               "not linearized: ");
    } else {
        ts_trust_merge(&r->trust, "equilibrium: ", &r->eq_trust);
        rc = run_linearize(r, lo, rq->setup.open_loop, err);
    }
    tsi_preload_join(&pre);
    return rc;
}

static int pipeline_equilibrium(ts_result *r, const ts_request *rq,
                                ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(r->sys, err);
    int rc = k ? run_equilibrium(r, k, rq, err)
               : (err && err->code ? err->code : TS_ENOMEM);
    ts_kernel_free(k);
    if (rc == TS_OK)
        ts_trust_merge(&r->trust, NULL, &r->eq_trust);
    int vrc = r->eq ? eq_values(r, err) : TS_OK;
    return rc ? rc : vrc;
}

/* ---- modes ------------------------------------------------------------- */

/* The eigen options of a request for a linear model of n states. With
 * `near` the modes nearest the target are chosen among the oscillatory
 * ones (select_modes): every mode is computed below arpack_min_states,
 * and ARPACK is asked for more than are listed (real modes near 0 Hz
 * compete with them). */
static ts_eigen_opts modes_eigen_opts(const ts_modes_opts *m, int n)
{
    ts_eigen_opts o = m->eigen;
    o.count = m->count;
    int arpack = o.method == TS_EIG_ARPACK ||
                 (o.method == TS_EIG_AUTO && n >= o.arpack_min_states);
    if (m->near || (m->oscillatory && m->count > 0)) {
        int want = m->count > 0 ? m->count : TS_MODES_NEAR_COUNT;
        o.count = arpack ? 2 * want + 10 : 0;
    } else if (o.count == 0) {
        int large = 2 * m->follow + 10;
        if (large < TS_MODES_LARGE_COUNT)
            large = TS_MODES_LARGE_COUNT;
        if (arpack)
            o.count = large;
    }
    /* More than exist: all of them. ARPACK finds a few near a target and
     * says how many it can (ts_eigen_check). */
    if (o.count > n / 2 + 1 && o.method != TS_EIG_ARPACK)
        o.count = 0;
    return o;
}

/* Oscillatory modes first (by frequency), then real ones (by |lambda|);
 * among the first `nsel` places those chosen (sel[m] = 1). */
typedef struct mode_key {
    int index;
    int group;     /* 0 chosen oscillatory, 1 chosen real, 2 not chosen */
    double freq, mag;
} mode_key;

static int cmp_mode_key(const void *a, const void *b)
{
    const mode_key *x = a, *y = b;
    if (x->group != y->group)
        return x->group < y->group ? -1 : 1;
    double kx = x->group == 1 ? x->mag : x->freq;
    double ky = y->group == 1 ? y->mag : y->freq;
    if (kx != ky)
        return kx < ky ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

/* Reorder e's modes (and vectors) as perm says: new mode i is old perm[i]. */
static int permute_modes(ts_eigen *e, const int *perm, ts_err *err)
{
    int n = e->nmodes, ns = e->nstate;
    ts_mode *md = malloc((size_t)(n > 0 ? n : 1) * sizeof *md);
    double *vr = e->vec_re ? malloc((size_t)ns * (size_t)n * sizeof *vr)
                           : NULL;
    double *vi = e->vec_im ? malloc((size_t)ns * (size_t)n * sizeof *vi)
                           : NULL;
    if (!md || (e->vec_re && !vr) || (e->vec_im && !vi)) {
        free(md);
        free(vr);
        free(vi);
        return ts_fail(err, TS_ENOMEM, "modes: out of memory");
    }
    for (int i = 0; i < n; i++) {
        md[i] = e->modes[perm[i]];
        if (vr)
            memcpy(vr + (size_t)i * ns, e->vec_re + (size_t)perm[i] * ns,
                   (size_t)ns * sizeof *vr);
        if (vi)
            memcpy(vi + (size_t)i * ns, e->vec_im + (size_t)perm[i] * ns,
                   (size_t)ns * sizeof *vi);
    }
    free(e->modes);
    e->modes = md;
    if (vr) {
        free(e->vec_re);
        e->vec_re = vr;
    }
    if (vi) {
        free(e->vec_im);
        e->vec_im = vi;
    }
    return TS_OK;
}

/* The modes listed: oscillatory first by frequency, then the real ones;
 * with `near` the `count` (TS_MODES_NEAR_COUNT) oscillatory modes nearest
 * the target frequency; with `oscillatory` the oscillatory ones only (the
 * `count` lowest, when given). The
 * listed modes come first in e, e->nmodes becomes their number and
 * r->nmodes_computed keeps the number computed (the rest stay behind
 * them, for the verdict). */
static int select_modes(ts_result *r, const ts_modes_opts *m, ts_err *err)
{
    ts_eigen *e = r->eigen;
    int n = e->nmodes;
    r->nmodes_computed = n;
    mode_key *key = malloc((size_t)(n > 0 ? n : 1) * sizeof *key);
    int *perm = malloc((size_t)(n > 0 ? n : 1) * sizeof *perm);
    if (!key || !perm) {
        free(key);
        free(perm);
        return ts_fail(err, TS_ENOMEM, "modes: out of memory");
    }
    for (int i = 0; i < n; i++) {
        key[i].index = i;
        key[i].freq = e->modes[i].freq_hz;
        key[i].mag = hypot(e->modes[i].re, e->modes[i].im);
        key[i].group = e->modes[i].im > 0 ? 0 : 1;
    }
    if (m->near) {
        /* Rank the oscillatory modes by distance to the target. */
        int want = m->count > 0 ? m->count : TS_MODES_NEAR_COUNT;
        for (int i = 0; i < n; i++)
            key[i].freq = key[i].group == 0
                              ? fabs(key[i].freq - m->eigen.target_hz)
                              : INFINITY;
        qsort(key, (size_t)n, sizeof *key, cmp_mode_key);
        for (int i = 0; i < n; i++) {
            int chosen = key[i].group == 0 && i < want;
            key[i].freq = e->modes[key[i].index].freq_hz;
            key[i].group = chosen ? 0 : 2;
        }
    } else if (m->oscillatory) {
        /* The `count` (all) lowest oscillatory ones. */
        qsort(key, (size_t)n, sizeof *key, cmp_mode_key);
        for (int i = 0; i < n; i++)
            if (key[i].group == 1 || (m->count > 0 && i >= m->count))
                key[i].group = 2;
    }
    qsort(key, (size_t)n, sizeof *key, cmp_mode_key);
    int listed = 0;
    for (int i = 0; i < n; i++) {
        perm[i] = key[i].index;
        listed += key[i].group < 2;
    }
    int rc = permute_modes(e, perm, err);
    free(key);
    free(perm);
    if (rc == TS_OK)
        e->nmodes = listed;
    return rc;
}

/* The mode that is the k-th key mode (0-based) of e's first n modes: the
 * k-th lowest oscillatory one with damping below
 * TS_CONV_MODE_DAMPING_MAX; -1. */
static int key_mode(const ts_eigen *e, int n, int k)
{
    /* Lowest by frequency, whatever the listing order. */
    int prev = -1;
    for (int j = 0; j <= k; j++) {
        int best = -1;
        for (int m = 0; m < n; m++) {
            const ts_mode *md = &e->modes[m];
            if (!(md->im > 0) ||
                !(md->damping_ratio < TS_CONV_MODE_DAMPING_MAX))
                continue;
            if (prev >= 0 &&
                (md->freq_hz < e->modes[prev].freq_hz ||
                 (md->freq_hz == e->modes[prev].freq_hz && m <= prev)))
                continue;
            if (best < 0 || md->freq_hz < e->modes[best].freq_hz)
                best = m;
        }
        if (best < 0)
            return -1;
        prev = best;
    }
    return prev;
}

/* Key values: frequency (Hz, relative to itself) and damping ratio (scale
 * 1) of the `follow` lowest oscillatory modes with damping below
 * TS_CONV_MODE_DAMPING_MAX among every mode computed; solver error: each
 * mode's error bound as a frequency and as a damping ratio. */
static int modes_values(ts_result *r, int follow, ts_err *err)
{
    int rc = values_alloc(r, 2 * follow, err);
    if (rc)
        return rc;
    for (int m = 0; m < follow; m++) {
        value_name(&r->values[2 * m], "Hz", 0.0, "mode%d.freq_hz", m + 1);
        value_name(&r->values[2 * m + 1], "1", 1.0, "mode%d.damping_ratio",
                   m + 1);
    }
    const ts_eigen *e = r->eigen;
    for (int k = 0; e && k < follow; k++) {
        int m = key_mode(e, r->nmodes_computed, k);
        if (m < 0)
            break;
        const ts_mode *md = &e->modes[m];
        double mag = hypot(md->re, md->im);
        r->values[2 * k].value = md->freq_hz;
        r->values[2 * k].error.solver = md->error_bound / (2.0 * M_PI);
        r->values[2 * k + 1].value = md->damping_ratio;
        r->values[2 * k + 1].error.solver = md->error_bound / mag;
    }
    return TS_OK;
}

/* The gain and phase margins of every loop (none without loops). */
static int modes_margins(ts_result *r, ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(r->sys, err);
    if (!k)
        return err && err->code ? err->code : TS_ENOMEM;
    int nl = ts_control_nloops(k), rc = TS_OK;
    if (nl > 0) {
        r->margins = calloc((size_t)nl, sizeof *r->margins);
        if (!r->margins)
            rc = ts_fail(err, TS_ENOMEM, "margins: out of memory");
        double decades = log10(TS_MARGINS_TO_HZ / TS_MARGINS_FROM_HZ);
        int points = (int)ceil(decades * TS_MARGINS_PER_DECADE) + 1;
        double t0 = tsi_wall_now();
        if (rc == TS_OK)
            rc = ts_loop_margins(k, r->eq, TS_MARGINS_FROM_HZ,
                                 TS_MARGINS_TO_HZ, points, r->margins, err);
        r->margins_wall_s = tsi_wall_now() - t0;
        if (rc == TS_OK)
            r->nmargins = nl;
    }
    ts_kernel_free(k);
    return rc;
}

static int pipeline_modes(ts_result *r, const ts_request *rq, ts_err *err)
{
    const ts_modes_opts *m = &rq->modes;
    if (m->free_vehicle && r->sys->tow.vehicle < 0)
        return ts_fail(err, TS_EINVAL, "free_vehicle: the scene has no "
                       "towing_vehicle to compare");
    if (m->free_vehicle && rq->setup.open_loop)
        return ts_fail(err, TS_EINVAL, "free_vehicle: compares the closed "
                       "loops; leave out open_loop");
    if (m->free_vehicle && m->eigen.method == TS_EIG_ARPACK)
        return ts_fail(err, TS_EINVAL, "free_vehicle: needs every coupled "
                       "mode with its shape: eigen_method lapack or auto");
    /* LAPACK needs the dense A at any size. */
    ts_linearize_opts lo = m->linearize;
    if (m->eigen.method == TS_EIG_LAPACK && lo.model == TS_LIN_AUTO)
        lo.model = TS_LIN_BOTH;
    int rc = equilibrium_then_linear(r, rq, &lo, 1, err);
    if (rc != TS_OK)
        return rc;
    ts_eigen_opts o = modes_eigen_opts(m, r->lin->nstate);
    o.progress = rq->progress;
    o.progress_data = rq->progress_data;
    /* LAPACK's one call cannot be polled: a stop asked for during the
     * equilibrium or the linearization is taken here, before it. */
    ts_progress p = {"eigensolve", 0, NAN, "operator applications"};
    if (rq->progress && rq->progress(&p, rq->progress_data))
        return ts_fail(err, TS_ECANCEL, "modes: stopped on request after "
                                        "the equilibrium and the "
                                        "linearization, before the "
                                        "eigensolve");
    double t0 = tsi_wall_now();
    rc = ts_eigen_solve(r->lin, &o, &r->eigen, err);
    r->eigen_wall_s = tsi_wall_now() - t0;
    /* A stop asked for during LAPACK's call is taken after it. */
    p.done = r->eigen ? r->eigen->arpack_ops : 0;
    if (rc == TS_OK && rq->progress && rq->progress(&p, rq->progress_data))
        return ts_fail(err, TS_ECANCEL, "modes: stopped on request after "
                                        "the eigensolve (%s), before the "
                                        "modes' checks",
                       ts_eig_method_name(r->eigen->method));
    if (rc == TS_OK)
        rc = select_modes(r, m, err);
    if (rc != TS_OK)
        return rc;
    int nm = r->nmodes_computed;
    r->mode_health = malloc((size_t)(nm > 0 ? nm : 1) *
                            sizeof *r->mode_health);
    if (!r->mode_health)
        return ts_fail(err, TS_ENOMEM, "modes: out of memory for the health "
                                       "of %d modes", nm);
    rc = ts_health_modes(r->sys, r->lin, r->eigen, r->mode_health,
                         &r->modes_trust, err);
    if (rc != TS_OK)
        return rc;
    if (m->near && r->eigen->nmodes < (m->count > 0 ? m->count
                                                    : TS_MODES_NEAR_COUNT))
        ts_trust_note(&r->modes_trust, "only %d oscillatory mode%s among "
                      "the %d computed near %.4g Hz", r->eigen->nmodes,
                      r->eigen->nmodes == 1 ? "" : "s", nm,
                      m->eigen.target_hz);
    ts_trust_merge(&r->trust, NULL, &r->modes_trust);
    if (m->margins && !rq->setup.open_loop && (rc = modes_margins(r, err)))
        return rc;
    if (m->free_vehicle &&
        (rc = ts_free_vehicle_compare(r->sys, r->eq, r->lin, r->eigen,
                                      &r->free_vehicle, err)))
        return rc;
    return modes_values(r, m->follow, err);
}

/* ---- response ---------------------------------------------------------- */

/* A sea's seaway on sys: the message names the option at fault. */
static int sea_seaway(const ts_system *sys, const ts_sea_opts *so,
                      ts_seaway *w, ts_err *err)
{
    int rc = ts_seaway_init(w, sys, so->sea, so->rao, so->reference, err);
    if (rc)
        ts_err_prefix(err, "sea: ");
    return rc;
}

static int check_response_sea(const ts_system *sys, const ts_response_opts *o,
                              ts_output *out, ts_err *err)
{
    if (o->frequency_given)
        return ts_fail(err, TS_EINVAL, "sea: the sea drives every tow-point "
                       "axis over its own frequencies: input, from, to and "
                       "points do not apply (leave them out)");
    if (!o->output[0]) {
        char list[768];
        ts_response_output_names(sys, list, sizeof list);
        return ts_fail(err, TS_EINVAL, "output: required; valid outputs: %s",
                       list);
    }
    int rc = ts_response_output_find(sys, o->output, out, err);
    if (rc != TS_OK) {
        ts_err_prefix(err, "output: ");
        return rc;
    }
    if (o->intervals < 16 || o->intervals % 8)
        return ts_fail(err, TS_EINVAL, "intervals: expected a multiple of 8 "
                       "from 16 on (the grid is halved twice for its error "
                       "estimate), got %d", o->intervals);
    ts_seaway w;
    return sea_seaway(sys, &o->sea, &w, err);
}

/* The input and output of a response: a tow axis or a vehicle's input
 * (a surface, a loop, a set point: none with the loops open), a node
 * coordinate, a tension or a vehicle's output. */
static int response_channels(const ts_system *sys, const ts_response_opts *o,
                             int open_loop, int *input, ts_output *out,
                             ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(sys, err);
    if (!k)
        return err && err->code ? err->code : TS_ENOMEM;
    int rc = ts_response_input_lookup(k, o->input, input, err);
    if (rc != TS_OK)
        ts_err_prefix(err, "input: ");
    if (rc == TS_OK && open_loop && ts_control_nloops(k) > 0 &&
        ts_kernel_input_is_setpoint(k, *input))
        rc = ts_fail(err, TS_EINVAL, "input: %s does nothing with the loops "
                     "open (open_loop): the loop's output is held at its "
                     "trim value", o->input);
    if (rc == TS_OK && !o->output[0]) {
        char list[768];
        ts_response_output_names(sys, list, sizeof list);
        rc = ts_fail(err, TS_EINVAL, "output: required; valid outputs: %s%s",
                     list, ts_kernel_noutput(k) > 0
                               ? " or a vehicle's (depth, pitch, roll, yaw, "
                                 "<loop>.output, <surface>.deflection)"
                               : "");
    } else if (rc == TS_OK) {
        rc = ts_response_output_lookup(k, o->output, out, err);
        if (rc != TS_OK)
            ts_err_prefix(err, "output: ");
    }
    ts_kernel_free(k);
    return rc;
}

static int check_response(const ts_system *sys, const ts_response_opts *o,
                          int open_loop, int *input, ts_output *out,
                          ts_err *err)
{
    if (o->sea.sea)
        return check_response_sea(sys, o, out, err);
    int rc = response_channels(sys, o, open_loop, input, out, err);
    if (rc != TS_OK)
        return rc;
    if (!(o->points >= 2 && o->points <= TS_RESPONSE_MAX_POINTS))
        return ts_fail(err, TS_EINVAL,
                       "points: expected a whole number in [2, %d], got %d",
                       TS_RESPONSE_MAX_POINTS, o->points);
    double f[2];
    rc = ts_response_logspace(o->from_hz, o->to_hz, 2, f, err);
    if (rc != TS_OK)
        ts_err_prefix(err, "to: ");
    return rc;
}

/* Key values of a spectral result: <output>.sigma, .tz, .mpm with the
 * discretisation error (NAN when not estimated) and the grid and band
 * errors as the solver's. */
static int sea_values(ts_result *r, const ts_seastate *s, ts_err *err)
{
    int rc = values_alloc(r, 3, err);
    if (rc)
        return rc;
    static const char *const suffix[3] = {"sigma", "tz", "mpm"};
    const ts_stat *st[3] = {&s->sigma, &s->tz, &s->mpm};
    for (int v = 0; v < 3; v++) {
        value_name(&r->values[v], v == 1 ? "s" : s->unit, 0.0, "%.70s.%s",
                   s->output.name, suffix[v]);
        r->values[v].value = st[v]->value;
        r->values[v].error.solver = st[v]->grid + st[v]->band;
        r->values[v].error.discretisation =
            s->disc_estimated ? st[v]->discretisation : NAN;
    }
    return TS_OK;
}

static int pipeline_response_sea(ts_result *r, const ts_request *rq,
                                 ts_err *err)
{
    const ts_response_opts *o = &rq->response;
    ts_output out;
    int rc = check_response_sea(r->sys, o, &out, err);
    if (rc == TS_OK)
        rc = sea_seaway(r->sys, &o->sea, &r->seaway, err);
    if (rc != TS_OK)
        return rc;
    r->has_sea = 1;
    snprintf(r->rao_file, sizeof r->rao_file, "%s", o->sea.rao_file);
    ts_linearize_opts lo = rq->modes.linearize;
    lo.tensions = out.kind == TS_OUT_TENSION;
    rc = equilibrium_then_linear(r, rq, &lo, 0, err);
    /* A towing vehicle's speed is solved: the waves meet it at that one
     * (the encounter frequency), not at the scene's starting value. */
    if (rc == TS_OK && r->sys->tow.vehicle >= 0)
        r->seaway.speed = r->eq->speed;
    ts_seastate_opts so;
    ts_seastate_opts_default(&so);
    so.intervals = o->intervals;
    so.duration = o->duration;
    so.progress = rq->progress;
    so.progress_data = rq->progress_data;
    if (rc == TS_OK)
        rc = ts_seastate_compute(r->sys, r->lin, &r->seaway, &out, &so,
                                 &r->seastate, err);
    if (rc != TS_OK)
        return rc;
    ts_seastate *s = r->seastate;
    /* With a sea, the spectral analysis estimates its own discretisation
     * error (the same levels, ts_seastate_discretisation); the accuracy
     * stage judges it. */
    if (rq->setup.discretisation_error || rq->setup.refine) {
        ts_err de = {0};
        int drc = ts_seastate_discretisation(r->sys, &rq->setup.equilibrium,
                                             &r->seaway, &so, s, &de);
        if (drc == TS_EDOMAIN)
            ts_trust_note(&s->trust, "the discretisation error was not "
                          "estimated (%s); towstab converge can sweep "
                          "the links", de.msg);
        else if (drc != TS_OK)
            return ts_fail(err, drc, "sea: the discretisation estimate: %s",
                           de.msg);
    }
    ts_trust_merge(&r->trust, NULL, &s->trust);
    const ts_linear *lin = r->lin;
    if (lin->kink_tow && s->sigma.value > 0)
        ts_trust_note(&r->trust, "the tow point is at the water surface: a "
                                 "real heave also shifts the mean depth at "
                                 "first order, which the linear model "
                                 "cannot show");
    return sea_values(r, s, err);
}

/* The frequency point of the largest magnitude. */
static int response_peak(const ts_response *res)
{
    int ip = 0;
    for (int i = 1; i < res->npoints; i++)
        if (res->magnitude[i] > res->magnitude[ip])
            ip = i;
    return ip;
}

/* Key values of a response: the static gain and the largest magnitude
 * over the frequencies (the output's unit per m), both relative to the
 * largest magnitude; the solver's part of their error is the
 * linearization's error allowance (towstab/response.h). */
static int response_values(ts_result *r, ts_err *err)
{
    const ts_response *res = r->response;
    int rc = values_alloc(r, 2, err);
    if (rc)
        return rc;
    double peak = res->magnitude[response_peak(res)];
    value_name(&r->values[0], res->unit, peak, "%.80s.static_gain",
               res->output.name);
    value_name(&r->values[1], res->unit, peak,
               "%.80s.peak_magnitude", res->output.name);
    r->values[0].value = res->static_gain;
    r->values[1].value = peak;
    r->values[0].error.solver = res->error ? res->static_error : NAN;
    r->values[1].error.solver = res->error ? res->error[response_peak(res)]
                                           : NAN;
    if (!(peak > 0))
        r->values[0].scale = r->values[1].scale = 0.0;
    return TS_OK;
}

static int pipeline_response(ts_result *r, const ts_request *rq, ts_err *err)
{
    const ts_response_opts *o = &rq->response;
    if (o->sea.sea)
        return pipeline_response_sea(r, rq, err);
    int input;
    ts_output out;
    int rc = check_response(r->sys, o, rq->setup.open_loop, &input, &out,
                            err);
    double *freq = rc ? NULL : malloc((size_t)o->points * sizeof(double));
    if (rc == TS_OK && !freq)
        rc = ts_fail(err, TS_ENOMEM, "response: out of memory for %d "
                                     "frequencies", o->points);
    if (rc == TS_OK)
        rc = ts_response_logspace(o->from_hz, o->to_hz, o->points, freq, err);
    if (rc != TS_OK) {
        free(freq);
        return rc;
    }
    ts_linearize_opts lo = rq->modes.linearize;
    lo.tensions = out.kind == TS_OUT_TENSION;
    /* A frame input: the sparse model's frame columns (its Gf,
     * doc/linear.md section 2b), or with a towing vehicle the dense B's
     * (the sparse model has none then). */
    int frame = input >= TS_NINPUT && (!strcmp(o->input, "tow.speed") ||
                                       !strcmp(o->input, "tow.turn_rate"));
    lo.frame_inputs = frame;
    if (frame && r->sys->tow.vehicle >= 0 && lo.model != TS_LIN_DENSE)
        lo.model = TS_LIN_DENSE;
    rc = equilibrium_then_linear(r, rq, &lo, 0, err);
    if (rc == TS_OK)
        rc = tsi_response_compute(r->sys, r->lin, input, &out, freq,
                                  o->points, rq->progress, rq->progress_data,
                                  &r->response, err);
    free(freq);
    if (rc != TS_OK)
        return rc;
    rc = response_values(r, err);
    if (rc != TS_OK)
        return rc;
    if (o->natural) {
        /* The lowest natural frequencies; a failure leaves none. */
        ts_eigen_opts eo;
        ts_eigen_opts_default(&eo);
        eo.count = TS_RESPONSE_NATURAL;
        eo.rightmost = 0; /* the lowest modes only, no verdict */
        if (eo.count > r->lin->nstate / 2)
            eo.count = 0;
        ts_eigen *e = NULL;
        if (ts_eigen_solve(r->lin, &eo, &e, NULL) == TS_OK)
            for (int m = 0; m < e->nmodes && r->nnatural < TS_RESPONSE_NATURAL;
                 m++)
                if (e->modes[m].im > 0)
                    r->natural_hz[r->nnatural++] = e->modes[m].freq_hz;
        ts_eigen_free(e);
    }
    /* A rigid cable passes the tow point's acceleration down at once: its
     * tension grows as the frequency squared without bound. */
    const ts_response *re = r->response;
    if (out.kind == TS_OUT_TENSION &&
        !r->sys->links[out.link].elastic && re->npoints > 0)
        ts_trust_note(&r->trust, "inextensible links overstate the tension "
                      "at high frequency: a rigid cable moves everything "
                      "below with the tow point at once, so |H| grows as "
                      "the frequency squared (%.4g %s at %.4g Hz, %.3g times "
                      "the static gain); an elastic cable (cables[].ea, "
                      "doc/elastic.md) has axial resonances and bounds it",
                      re->magnitude[re->npoints - 1], out.unit,
                      re->freq_hz[re->npoints - 1],
                      re->static_gain != 0
                          ? re->magnitude[re->npoints - 1] /
                                fabs(re->static_gain)
                          : INFINITY);
    /* The waterline kink for a heave input (towstab/health.h). */
    const ts_linear *lin = r->lin;
    if (lin->kink_tow && input == 2)
        ts_trust_note(&r->trust, "the tow point is at the water surface: a "
                                 "real heave also shifts the mean depth at "
                                 "first order, which a frequency response "
                                 "cannot show");
    if (lin->kinks && !(lin->kink_tow && lin->kinks == 1))
        ts_trust_note(&r->trust, "%d node%s within a linearization step of "
                                 "the water surface: f is not smooth there",
                      lin->kinks, lin->kinks == 1 ? "" : "s");
    return TS_OK;
}

/* ---- simulate ---------------------------------------------------------- */

/* Read "node,x_m,y_m,z_m[,...]" rows (a header first) into pos[3 nnodes],
 * matching node names; the tow point's row may be left out. */
static int read_shape(const ts_system *sys, const char *path, double *pos,
                      ts_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return ts_fail(err, TS_EINVAL, "initial: cannot read '%s': %s", path,
                       strerror(errno));
    char *seen = calloc((size_t)sys->nnodes, 1);
    if (!seen) {
        fclose(f);
        return ts_fail(err, TS_ENOMEM, "initial: out of memory");
    }
    char line[1024], name[2 * TS_NAME_MAX];
    int lineno = 0, rc = TS_OK;
    while (!rc && fgets(line, sizeof line, f)) {
        lineno++;
        line[strcspn(line, "\r\n")] = '\0';
        if (line[0] == '#' || line[0] == '\0')
            continue;
        if (lineno == 1 && !strncmp(line, "node,", 5)) {
            /* Positions in metres only (a CSV written with --units
             * imperial says x_ft). */
            if (strncmp(line, "node,x_m,y_m,z_m", 16) != 0) {
                rc = ts_fail(err, TS_EINVAL, "initial: %s line 1: expected "
                             "the header node,x_m,y_m,z_m (positions in m; "
                             "write the file with --units si), got '%.60s'",
                             path, line);
                break;
            }
            continue;
        }
        char *c1 = strchr(line, ',');
        if (!c1) {
            rc = ts_fail(err, TS_EINVAL, "initial: %s line %d: expected "
                         "node,x_m,y_m,z_m", path, lineno);
            break;
        }
        *c1 = '\0';
        double v[3];
        char *p = c1 + 1, *end;
        for (int j = 0; j < 3 && !rc; j++) {
            v[j] = strtod(p, &end);
            if (end == p || !isfinite(v[j]) || (*end != ',' && *end != '\0'))
                rc = ts_fail(err, TS_EINVAL, "initial: %s line %d: "
                             "coordinate %d is not a number", path, lineno,
                             j + 1);
            p = *end ? end + 1 : end;
        }
        int k = 0;
        for (; !rc && k < sys->nnodes; k++) {
            ts_system_node_name(sys, k, name, sizeof name);
            if (!strcmp(name, line))
                break;
        }
        if (!rc && k == sys->nnodes)
            rc = ts_fail(err, TS_EINVAL, "initial: %s line %d: '%.60s' is "
                         "not a node of the scene", path, lineno, line);
        if (!rc) {
            memcpy(pos + 3 * k, v, sizeof v);
            seen[k] = 1;
        }
    }
    fclose(f);
    for (int k = 1; !rc && k < sys->nnodes; k++)
        if (!seen[k]) {
            ts_system_node_name(sys, k, name, sizeof name);
            rc = ts_fail(err, TS_EINVAL, "initial: %s has no row for node "
                         "'%s'", path, name);
        }
    if (!rc && !seen[0])
        memcpy(pos, sys->tow.point, 3 * sizeof(double));
    free(seen);
    return rc;
}

/* The resolved options of a simulation: the sample interval and the
 * transient of their defaults. */
static void sim_resolve(const ts_simulate_opts *s, ts_sim_opts *o,
                        double *transient)
{
    *o = s->sim;
    if (!(o->dt_sample > 0)) {
        double dt = TS_SIMULATE_SAMPLE;
        int idx;
        if (s->excitation && ts_excitation_periodic(s->excitation, &idx)) {
            double f = ts_excitation_signal(s->excitation, idx)->frequency;
            dt = fmin(dt, 1.0 / (TS_SIMULATE_SAMPLES_PER_PERIOD * f));
        }
        o->dt_sample = fmin(dt, o->t_end);
    }
    *transient = isnan(s->transient) ? o->t_end / 2 : s->transient;
}

/* The excitation's signals on vehicles' inputs against the system's
 * vehicles; with the loops open, none on a loop's output or set point
 * (they are held at the trim). */
static int check_sim_inputs(const ts_system *sys, const ts_excitation *ex,
                            int open_loop, ts_err *err)
{
    int ns = ex ? ts_excitation_nsignals(ex) : 0, any = 0;
    for (int i = 0; i < ns; i++)
        any |= ts_excitation_signal(ex, i)->axis == TS_AXIS_INPUT;
    if (!any)
        return TS_OK;
    ts_kernel *k = ts_kernel_alloc(sys, err);
    if (!k)
        return err && err->code ? err->code : TS_ENOMEM;
    int rc = ts_sim_check_inputs(k, ex, err);
    for (int i = 0; i < ns && rc == TS_OK && open_loop; i++) {
        const ts_signal *sg = ts_excitation_signal(ex, i);
        int j = sg->axis == TS_AXIS_INPUT ? ts_kernel_input_find(k, sg->input)
                                          : -1;
        /* Only a set point does nothing with the loops open: a loop's
         * input adds to its frozen output, and a towing vehicle's
         * thrust, forces, moments and commanded speed act on the plant
         * (its speed controller stays closed), as in response. */
        if (ts_control_nloops(k) > 0 && ts_kernel_input_is_setpoint(k, j))
            rc = ts_fail(err, TS_EINVAL, "excite: %s does nothing with the "
                         "loops open (open_loop): the loop's output is held "
                         "at its trim value", sg->input);
    }
    ts_kernel_free(k);
    if (rc != TS_OK && strncmp(err->msg, "excite", 6))
        ts_err_prefix(err, "excite: ");
    return rc;
}

/* A channel of a simulation: ts_output_find's, or a vehicle's output
 * (ts_kernel_output_name: <vehicle>.depth|pitch|roll|yaw, its loops'
 * outputs, <vehicle>.<surface>.deflection), whose names the message of a
 * bad one then lists too. */
static int sim_channel(const ts_system *sys, const char *name, int kinds,
                       ts_output *out, ts_err *err)
{
    int rc = ts_output_find(sys, name, kinds, out, err);
    if (rc == TS_OK || sys->nvehicles == 0)
        return rc;
    ts_kernel *k = ts_kernel_alloc(sys, NULL);
    if (!k)
        return rc;
    if (ts_kernel_output_find(k, name) >= 0) {
        ts_err_clear(err);
        rc = ts_response_output_lookup(k, name, out, err);
    } else {
        tsi_response_list_vehicle_outputs(k, err);
    }
    ts_kernel_free(k);
    return rc;
}

/* The output of a simulation: the named one, or the last sphere's .z
 * (else the last node's). */
static int sim_output(const ts_system *sys, const char *name, ts_output *out,
                      ts_err *err)
{
    char def[2 * TS_NAME_MAX + 4];
    if (!name || !name[0]) {
        int node = sys->nnodes - 1;
        for (int b = sys->nbodies - 1; b >= 0; b--)
            if (sys->bodies[b].type == TS_BODY_SPHERE) {
                node = ts_system_body_node(sys, b);
                break;
            }
        ts_system_node_name(sys, node, def, sizeof def - 2);
        strcat(def, ".z");
        name = def;
    }
    int rc = sim_channel(sys, name, TS_OUT_ALL, out, err);
    if (rc)
        ts_err_prefix(err, "output: ");
    return rc;
}

/* The channels a simulation reports (s->outputs): the list, each name
 * once, or the default (the output, for a position its node's x, y, z;
 * and tow.force). *sel (caller frees) receives them, *all 1 for "all"
 * (with the default list). */
static int sim_selection(const ts_system *sys, const ts_simulate_opts *s,
                         const ts_output *out, ts_output **sel, int *n,
                         int *all, ts_err *err)
{
    *sel = NULL;
    *n = 0;
    *all = 0;
    char text[TS_REQUEST_PATH_MAX];
    snprintf(text, sizeof text, "%s", s->outputs);
    char *p = tsi_csv_trim(text);
    if (strcmp(p, "all") == 0) {
        *all = 1;
        p[0] = '\0';
    }
    /* At most one channel per two characters of the text, plus the
     * default's four. */
    size_t cap = strlen(p) / 2 + 5;
    ts_output *o = calloc(cap, sizeof *o);
    if (!o)
        return ts_fail(err, TS_ENOMEM, "outputs: out of memory");
    int m = 0, rc = TS_OK;
    if (!p[0]) {
        char name[TS_OUTPUT_NAME_MAX + 4], node[TS_OUTPUT_NAME_MAX];
        if (out->kind == TS_OUT_POSITION) {
            ts_system_node_name(sys, out->node, node, sizeof node);
            for (int c = 0; c < 3 && !rc; c++) {
                snprintf(name, sizeof name, "%s.%c", node, "xyz"[c]);
                rc = ts_output_find(sys, name, TS_OUT_ALL, &o[m++], err);
            }
        } else {
            o[m++] = *out;
        }
        if (!rc && !(out->kind == TS_OUT_TOW_FORCE &&
                     out->comp == TS_OUT_MAGNITUDE))
            rc = ts_output_find(sys, "tow.force", TS_OUT_ALL, &o[m++], err);
    }
    for (char *tok = p[0] ? p : NULL; tok && !rc;) {
        char *comma = strchr(tok, ',');
        if (comma)
            *comma = '\0';
        char *b = tsi_csv_trim(tok);
        if (!b[0])
            rc = ts_fail(err, TS_EINVAL, "outputs: an empty name in '%s' "
                         "(names are separated by commas)", s->outputs);
        else if (strcmp(b, "all") == 0)
            rc = ts_fail(err, TS_EINVAL, "outputs: 'all' (the full state) "
                         "stands alone, not in a list");
        else if ((size_t)m >= cap)
            rc = ts_fail(err, TS_EINVAL, "outputs: too many names");
        else if ((rc = sim_channel(sys, b,
                                   TS_OUT_ALL | TS_OUT_BIT(TS_OUT_EARTH),
                                   &o[m], err)))
            ts_err_prefix(err, "outputs: ");
        for (int k = 0; !rc && k < m; k++)
            if (!strcmp(o[k].name, o[m].name))
                rc = ts_fail(err, TS_EINVAL, "outputs: '%s' is listed twice",
                             o[m].name);
        if (!rc)
            m++;
        tok = comma ? comma + 1 : NULL;
    }
    if (rc) {
        free(o);
        return rc;
    }
    *sel = o;
    *n = m;
    return TS_OK;
}

/* Everything a simulation needs that can be checked without running. */
/* Physical memory of the machine, bytes (0: unknown). */
static double memory_bytes(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : 0.0;
}

/* An excitation faster than the run can resolve, and a history larger
 * than memory, are refused before anything runs: a sample interval given
 * must sample every periodic tow signal at least twice a period; without
 * one, the 16 samples per period of the default must stay within
 * TS_SIMULATE_AUTO_SAMPLES_MAX. */
static int check_resolution(const ts_system *sys, const ts_simulate_opts *s,
                            const ts_sim_opts *o, ts_err *err)
{
    const ts_excitation *ex = s->excitation;
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        const ts_signal *sg = ts_excitation_signal(ex, i);
        /* The fundamental (a crank's harmonics are small corrections). */
        double f = sg->type == TS_SIGNAL_CRANK ||
                           sg->type == TS_SIGNAL_SINE ||
                           sg->type == TS_SIGNAL_SUM
                       ? sg->frequency
                       : 0.0;
        if (!(f > 0))
            continue;
        double period = 1.0 / f;
        if (s->sim.dt_sample > 0 && o->dt_sample > period / 2)
            return ts_fail(err, TS_EINVAL, "sample: %g s cannot resolve the "
                           "%g Hz excitation %s (period %g s): at most %g s, "
                           "2 samples per period", o->dt_sample, f,
                           ts_signal_axis_label(sg), period, period / 2);
        double n = o->t_end * f * TS_SIMULATE_SAMPLES_PER_PERIOD;
        if (!(s->sim.dt_sample > 0) && n > TS_SIMULATE_AUTO_SAMPLES_MAX)
            return ts_fail(err, TS_EINVAL, "excite: the %g Hz excitation %s "
                           "needs %.3g samples over the %g s run (%d per "
                           "period), more than the %g a run takes without a "
                           "sample interval given: shorten t_end, lower the "
                           "frequency, or give the sample interval", f,
                           ts_signal_axis_label(sg), n, o->t_end,
                           TS_SIMULATE_SAMPLES_PER_PERIOD,
                           TS_SIMULATE_AUTO_SAMPLES_MAX);
    }
    double samples = ceil(o->t_end / o->dt_sample) + 1;
    double bytes = 8.0 * samples *
                   (4.0 + 3.0 * sys->nnodes + sys->nlinks + TS_NINPUT);
    double mem = memory_bytes();
    if (mem > 0 && bytes > mem)
        return ts_fail(err, TS_ENOMEM, "sample: out of memory for the "
                       "history of %.3g samples of %d nodes and %d links "
                       "(%.3g GB, the machine has %.3g GB): a coarser sample "
                       "interval, a shorter t_end or fewer links",
                       samples, sys->nnodes, sys->nlinks, bytes / 1e9,
                       mem / 1e9);
    return TS_OK;
}

static int check_simulate(const ts_system *sys, const ts_simulate_opts *s,
                          int open_loop, ts_sim_opts *o, double *transient,
                          ts_output *out, ts_err *err)
{
    sim_resolve(s, o, transient);
    if (!(o->t_end > 0) || !isfinite(o->t_end))
        return ts_fail(err, TS_EINVAL, "t_end: the run length must be > 0 "
                       "s, got %g s", o->t_end);
    if (o->dt_sample > o->t_end)
        return ts_fail(err, TS_EINVAL, "sample: the sample interval %g s is "
                       "longer than the run (%g s)", o->dt_sample, o->t_end);
    if (s->compare && s->linear)
        return ts_fail(err, TS_EINVAL, "linear: linear runs the linear model "
                       "alone; compare runs both: give one");
    if (sys->tow.autopilot.on && (s->linear || s->compare))
        return ts_fail(err, TS_EINVAL, "%s: the waypoints (line %d) steer "
                       "the towing vehicle in the nonlinear run only; the "
                       "linear model has no autopilot: run without it",
                       s->linear ? "linear" : "compare",
                       sys->tow.autopilot.g.line);
    if (!(*transient >= 0) || !(*transient < o->t_end))
        return ts_fail(err, TS_EINVAL, "transient: must be in [0, %g) s (the "
                       "run length), got %g s", o->t_end, *transient);
    int rc = ts_sim_opts_check(o, err);
    if (rc)
        return rc;
    if (s->initial == TS_INITIAL_SHAPE && !s->shape_file[0])
        return ts_fail(err, TS_EINVAL, "initial: shape: needs a file name");
    const ts_excitation *ex = s->excitation;
    if (ex && (rc = ts_excitation_check_span(ex, o->t_end, err))) {
        ts_err_prefix(err, "excite: ");
        return rc;
    }
    if ((rc = sim_output(sys, s->output, out, err)))
        return rc;
    if ((rc = check_resolution(sys, s, o, err)))
        return rc;
    /* Loads an excitation or a manoeuvre makes overflow: refused here,
     * naming the option that brought them (the simulator refuses them
     * too, naming only the input). */
    {
        ts_frame f0 = {sys->tow.speed, sys->tow.turn_rate, 0, 0,
                       {sys->env.current[0], sys->env.current[1],
                        sys->env.current[2]}};
        ts_motion_bound mb, st;
        ts_excitation_bound(ex, &f0, &mb);
        if ((rc = ts_system_check_loads(sys, &mb, err))) {
            ts_motion_bound_steady(sys, &st);
            mb.tow_speed = mb.tow_accel = mb.rot_rate = mb.rot_accel = 0.0;
            if (ts_system_check_loads(sys, &st, NULL))
                ts_err_prefix(err, "simulate: ");
            else if (ts_system_check_loads(sys, &mb, NULL))
                ts_err_prefix(err, "manoeuvre: ");
            else
                ts_err_prefix(err, "excite: ");
            return rc;
        }
    }
    int use_linear = s->compare || s->linear;
    const char *lw = s->compare ? "compare" : "linear";
    if (use_linear && out->kind != TS_OUT_POSITION &&
        out->kind != TS_OUT_TENSION && out->kind != TS_OUT_VEHICLE)
        return ts_fail(err, TS_EINVAL, "output: '%s': the linear model "
                       "gives node positions, link tensions and the "
                       "vehicles' outputs, so %s needs one of those (the "
                       "nonlinear run alone gives the others)", out->name,
                       lw);
    if (use_linear && o->linear_method == TS_LINSIM_SPARSE && ex &&
        ts_excitation_has_manoeuvre(ex) && sys->tow.vehicle >= 0)
        return ts_fail(err, TS_EINVAL, "linear_method: sparse: a manoeuvre "
                       "drives the frame's speed or turn rate, which with a "
                       "towing vehicle are inputs of the dense linear model "
                       "only: use expm or ode (the dense model is then "
                       "formed at any size)");
    if (use_linear && s->initial != TS_INITIAL_EQUILIBRIUM)
        return ts_fail(err, TS_EINVAL, "initial: the linear model starts at "
                       "the equilibrium, so %s needs the initial state "
                       "'equilibrium'", lw);
    if (use_linear && ex && ts_excitation_has_manoeuvre(ex)) {
        ts_kernel *k = ts_kernel_alloc(sys, err);
        if (!k)
            return err && err->code ? err->code : TS_ENOMEM;
        rc = ts_sim_check_linear_manoeuvre(k, ex, err);
        ts_kernel_free(k);
        if (rc)
            return rc;
    }
    if ((rc = check_sim_inputs(sys, ex, open_loop, err)))
        return rc;
    /* What the comparison will need. */
    int idx;
    if (s->compare && ex && ts_compare_periodic(ex, &idx)) {
        double f = ts_excitation_signal(ex, idx)->frequency;
        double period = 1.0 / f;
        if (o->dt_sample > period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD)
            return ts_fail(err, TS_EINVAL, "sample: the sample interval %g s "
                           "is too coarse to compare at %g Hz; at most %g s "
                           "(%d samples per period)", o->dt_sample, f,
                           period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD,
                           TS_COMPARE_MIN_SAMPLES_PER_PERIOD);
        if (o->t_end - *transient < period)
            return ts_fail(err, TS_EINVAL, "transient: %g s are left after "
                           "the transient, less than one period (%g s) of "
                           "the %g Hz excitation", o->t_end - *transient,
                           period, f);
    }
    if (s->sea.sea) {
        ts_seaway w;
        if ((rc = sea_seaway(sys, &s->sea, &w, err)))
            return rc;
        if (s->initial != TS_INITIAL_EQUILIBRIUM)
            return ts_fail(err, TS_EINVAL, "initial: a sea state starts from "
                           "the equilibrium (its statistics and spectral "
                           "prediction are about it)");
        if (s->components < 1)
            return ts_fail(err, TS_EINVAL, "components: expected a whole "
                           "number >= 1, got %d", s->components);
        if (!isnan(s->fade_in) && !(s->fade_in >= 0 && isfinite(s->fade_in)))
            return ts_fail(err, TS_EINVAL, "fade_in: expected a time >= 0 "
                           "s, got %g s", s->fade_in);
    }
    if (s->need_values && !s->sea.sea) {
        if (!ex || !ts_excitation_periodic(ex, &idx))
            return ts_fail(err, TS_EINVAL, "excite: the amplitude ratio, "
                           "mean offset and phase need a single periodic "
                           "tow-point excitation (one sine or crank on "
                           "tow.surge, tow.sway or tow.heave)");
        double f = ts_excitation_signal(ex, idx)->frequency;
        double period = 1.0 / f;
        if (o->t_end - *transient < period * (1.0 - 1e-9))
            return ts_fail(err, TS_EINVAL, "transient: %g s are left after "
                           "the transient, less than one period (%g s) of "
                           "the %g Hz excitation", o->t_end - *transient,
                           period, f);
        if (o->dt_sample >
            period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD * (1.0 + 1e-9))
            return ts_fail(err, TS_EINVAL, "sample: the sample interval %g s "
                           "is too coarse for %g Hz; at most %g s (%d samples "
                           "per period)", o->dt_sample, f,
                           period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD,
                           TS_COMPARE_MIN_SAMPLES_PER_PERIOD);
    }
    ts_output *sel;
    int nsel, all;
    if ((rc = sim_selection(sys, s, out, &sel, &nsel, &all, err)))
        return rc;
    free(sel);
    if (s->initial == TS_INITIAL_SHAPE) {
        double *pos = malloc(3 * (size_t)sys->nnodes * sizeof *pos);
        if (!pos)
            return ts_fail(err, TS_ENOMEM, "initial: out of memory");
        rc = read_shape(sys, s->shape_file, pos, err);
        free(pos);
    }
    return rc;
}

/* The force key values of one channel: NAME.max, .min, .mean and
 * .amplification (N, N, N, 1) from its extremes e. Relative errors are
 * relative to the largest |value| (the channel's force scale). Errors:
 * discretisation, the sampling error of an extreme; solver, rounding
 * (`round` of each value's size) and, for the amplification, the
 * reference's residual `res` (relative). */
static void force_values(ts_value *v, const char *name, const ts_extremes *e,
                         double round, double res)
{
    static const char *const suffix[4] = {"max", "min", "mean",
                                          "amplification"};
    double scale = fmax(fabs(e->max), fabs(e->min));
    for (int k = 0; k < 4; k++)
        value_name(&v[k], k < 3 ? "N" : "1", k < 3 && scale > 0 ? scale : 0,
                   "%.80s.%s", name, suffix[k]);
    if (e->samples == 0)
        return;
    double val[4] = {e->max, e->min, e->mean, e->amplification};
    double disc[4] = {e->max_error, e->min_error, NAN,
                      e->max_error / fabs(e->reference)};
    for (int k = 0; k < 4; k++) {
        v[k].value = val[k];
        v[k].error.discretisation = isfinite(val[k]) ? disc[k] : NAN;
        v[k].error.solver = round * fabs(val[k]);
    }
    v[3].error.solver += res * fabs(val[3]);
}

/* The number of fitted key values of a simulation (SIM_FIT under a
 * single periodic excitation, else 0); the values from index SIM_FIT on
 * are extremes of the time history. */
static int sim_nfit(const ts_result *r)
{
    int idx;
    return r->excitation && ts_excitation_periodic(r->excitation, &idx)
               ? SIM_FIT
               : 0;
}

/* Key values of a simulation:
 *  - under a single periodic excitation, the output's amplitude ratio
 *    (relative to itself), mean offset from the equilibrium (m, scale
 *    the excitation amplitude; N, scale the static tension) and phase
 *    (deg, scale 360), fitted with the tow motion over t >= transient of
 *    the nonlinear run, and the largest and smallest link tension over
 *    that window (tension.max, tension.min: N, relative to themselves);
 *    solver error: rounding, SIM_ROUND_EPS eps sqrt(steps) of each
 *    value's scale (of the largest tension for both tensions), and the
 *    equilibrium's residual for the mean offset; a fit that cannot be
 *    made leaves NAN values (an error only when required);
 *  - with a nonlinear run, the extremes of the force on the tow point
 *    (tow.force.max, ...) and of a tension output (force_values) over
 *    r->forces_from on (sim_forces).
 * `linear_only`: the request runs the linear model alone; `ran`: the
 * runs succeeded (else only the names, NAN values). */
static int sim_values(ts_result *r, int linear_only, int ran, int required,
                      ts_err *err)
{
    const ts_excitation *ex = r->excitation;
    int idx = 0;
    int nfit = sim_nfit(r);
    if (nfit)
        ts_excitation_periodic(ex, &idx);
    int tension = r->output.kind == TS_OUT_TENSION;
    int nforce = linear_only ? 0 : tension ? 2 : 1;
    if (nfit + nforce == 0)
        return TS_OK;
    int ntens = nfit ? SIM_TMIN + 1 - SIM_FIT : 0; /* tension.max, .min */
    int rc = values_alloc(r, nfit + ntens + 4 * nforce, err);
    if (rc)
        return rc;
    const ts_history *h = r->nonlinear;
    const ts_sim_stats *st = &r->nonlinear_stats;
    double round = SIM_ROUND_EPS * DBL_EPSILON *
                   sqrt((double)(st->steps + st->rejected + 1));
    double res = r->eq ? EQ_NOISE_FACTOR *
                             fmax(r->eq->residual, EQ_NOISE_MIN_REL)
                       : 0;
    ts_extremes none;
    memset(&none, 0, sizeof none); /* samples 0: names only */
    int have = ran && h && r->tensions;
    if (nforce > 0) {
        force_values(r->values + nfit + ntens, "tow.force",
                     have ? &r->tow_force : &none, round, res);
        if (tension)
            force_values(r->values + nfit + ntens + 4, r->output.name,
                         have ? &r->output_extremes : &none, round, res);
    }
    if (nfit == 0)
        return TS_OK;
    const ts_signal *sg = ts_excitation_signal(ex, idx);
    static const char *const suffix[3] = {"amplitude_ratio", "mean_offset",
                                          "phase_deg"};
    /* A position's ratio is m/m ("1"), a tension's N/m; per rad for a
     * rotation of the ship (tow.roll, tow.pitch, tow.yaw). */
    const char *ou = r->output.si_unit;
    int rot = sg->axis == TS_AXIS_ROLL || sg->axis == TS_AXIS_PITCH ||
              sg->axis == TS_AXIS_YAW;
    int position = !strcmp(ou, "m") && !rot;
    char ratio_unit[TS_VALUE_UNIT_MAX];
    if (rot)
        snprintf(ratio_unit, sizeof ratio_unit, "%s/rad", ou);
    else
        snprintf(ratio_unit, sizeof ratio_unit, "%s",
                 position ? "1" : r->output.unit);
    const char *unit[3] = {ratio_unit, ou, "deg"};
    double scale[3] = {0.0, position ? sg->amplitude : 0.0, 360.0};
    for (int v = 0; v < 3; v++)
        value_name(&r->values[v], unit[v], scale[v], "%.70s.%s",
                   r->output.name, suffix[v]);
    value_name(&r->values[SIM_TMAX], "N", 0.0, "tension.max");
    value_name(&r->values[SIM_TMIN], "N", 0.0, "tension.min");
    if (!h || !r->eq || !ran)
        return TS_OK;
    int first = ts_history_first(h, r->transient);
    int n = h->nsamples - first;
    /* The extreme link tensions over the window. */
    double tmax = -INFINITY, tmin = INFINITY;
    for (int i = first; h->tensions && i < h->nsamples; i++)
        for (int l = 0; l < h->nlinks; l++) {
            double tl = h->tensions[(size_t)h->nlinks * i + l];
            tmax = fmax(tmax, tl);
            tmin = fmin(tmin, tl);
        }
    ts_err fe = {0};
    if (n < 3) {
        ts_fail(&fe, TS_EINVAL, "simulate: %d samples after the transient "
                                "(%g s)", n, r->transient);
        return required ? ts_fail(err, fe.code, "%s", fe.msg) : TS_OK;
    }
    double *buf = malloc(3 * (size_t)n * sizeof(double));
    if (!buf)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    double *t = buf, *xo = buf + n, *xe = buf + 2 * n;
    const ts_output *out = &r->output;
    for (int i = 0; i < n; i++) {
        size_t s = (size_t)(first + i);
        t[i] = h->t[s];
        xo[i] = ts_history_value(r->sys, h, out, first + i);
        xe[i] = h->input[TS_NINPUT * s + sg->axis];
    }
    double c, a, ph, ce, ae, phe;
    rc = ts_compare_fit_sinusoid(t, xe, n, sg->frequency, &ce, &ae, &phe,
                                 &fe);
    if (rc == TS_OK)
        rc = ts_compare_fit_sinusoid(t, xo, n, sg->frequency, &c, &a, &ph,
                                     &fe);
    free(buf);
    if (rc != TS_OK)
        return required ? ts_fail(err, rc, "%s", fe.msg) : TS_OK;
    double eqv = ts_output_value(r->sys, out, r->eq->positions,
                                 r->eq->tensions, r->eq->tow_force);
    double vals[3] = {a / ae, c - eqv,
                      ts_compare_wrap_deg((ph - phe) * 180.0 / M_PI)};
    /* Noise is relative to the cable's length for a position, to the
     * static value for a force or strain. */
    double L = position ? total_length(r->sys) : fabs(eqv);
    if (!position)
        r->values[1].scale = fabs(eqv);
    double noise_scale[3] = {fabs(vals[0]), L, 360.0};
    for (int v = 0; v < 3; v++) {
        r->values[v].value = vals[v];
        r->values[v].error.solver = round * noise_scale[v];
    }
    if (tmax >= tmin) {
        r->values[SIM_TMAX].value = tmax;
        r->values[SIM_TMIN].value = tmin;
        r->values[SIM_TMAX].error.solver = round * fabs(tmax);
        r->values[SIM_TMIN].error.solver = round * fabs(tmax);
    }
    r->values[1].error.solver += res * L;
    return TS_OK;
}

/* Whether a simulation computes its earth-frame tracks (h->frame): when
 * the request asks (s->tracks: the pictures), the channels reported
 * include an earth-frame position or the full state, or the scene steers
 * by waypoints. */
static int sim_needs_tracks(const ts_result *r, const ts_simulate_opts *s)
{
    if (s->tracks || r->all_outputs || r->sys->tow.autopilot.on)
        return 1;
    for (int k = 0; k < r->noutputs; k++)
        if (r->outputs[k].kind == TS_OUT_EARTH)
            return 1;
    return 0;
}

/* The samples a run's history starts with: those of the run, at most
 * TS_HISTORY_INITIAL (it grows as the run fills it). */
static int history_start(int nsamples)
{
    return nsamples < TS_HISTORY_INITIAL ? nsamples : TS_HISTORY_INITIAL;
}

/* The start of the window the forces' extremes are taken over
 * (ts_result.forces_from): the transient when the run analyses a window
 * after it (a periodic excitation's fit, a sea's statistics, or a
 * transient given), else 0, the whole run (a manoeuvre's loads are in its
 * transient). */
static double forces_window(const ts_result *r, const ts_simulate_opts *s)
{
    int idx;
    int windowed = r->has_sea || !isnan(s->transient) ||
                   (r->excitation &&
                    ts_excitation_periodic(r->excitation, &idx));
    return windowed ? r->transient : 0.0;
}

/* The forces of the nonlinear run (ts_result: tow_force, tensions,
 * output_extremes over the window from forces_from on; slack over the
 * whole run) and their verdict: a rigid link in compression is a reason
 * (a cable cannot push), an elastic link going slack a note (a snap load
 * follows). References: the initial equilibrium's values. */
static int sim_forces(ts_result *r, const ts_simulate_opts *s, ts_err *err)
{
    const ts_system *sys = r->sys;
    const ts_history *h = r->nonlinear;
    const ts_equilibrium *eq =
        s->initial == TS_INITIAL_EQUILIBRIUM && r->eq && r->eq->converged
            ? r->eq
            : NULL;
    const ts_history *ho = h ? h : r->linear;
    double from = r->forces_from = forces_window(r, s);
    if (ho)
        ts_extremes_window(sys, ho, &r->output,
                           eq ? ts_output_value(sys, &r->output,
                                                eq->positions, eq->tensions,
                                                eq->tow_force)
                              : NAN,
                           from, &r->output_extremes);
    if (!h || h->nsamples == 0)
        return TS_OK;
    ts_output o;
    ts_output_find(sys, "tow.force", TS_OUT_ALL, &o, NULL);
    ts_extremes_window(sys, h, &o, eq ? eq->top_tension : NAN, from,
                       &r->tow_force);
    r->tensions = calloc((size_t)sys->nlinks, sizeof *r->tensions);
    if (!r->tensions)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    memset(&o, 0, sizeof o);
    o.kind = TS_OUT_TENSION;
    for (int l = 0; l < sys->nlinks; l++) {
        o.link = l;
        ts_extremes *e = &r->tensions[l];
        ts_extremes_window(sys, h, &o, eq ? eq->tensions[l] : NAN, from,
                           e);
        if (e->samples == 0)
            continue;
        if (r->peak_link < 0 || e->max > r->tensions[r->peak_link].max)
            r->peak_link = l;
        if (r->low_link < 0 || e->min < r->tensions[r->low_link].min)
            r->low_link = l;
    }
    int rc = ts_slack_find(sys, h, &r->slack, &r->nslack, err);
    if (rc)
        return rc;
    /* The first link of each kind names the event; the others are
     * counted. */
    for (int elastic = 0; elastic < 2; elastic++) {
        int count = 0, first = -1;
        for (int k = 0; k < r->nslack; k++)
            if (r->slack[k].elastic == elastic && count++ == 0)
                first = k;
        if (first < 0)
            continue;
        const ts_slack *e = &r->slack[first];
        const ts_link *L = &sys->links[e->link];
        char others[64] = "";
        if (count > 1)
            snprintf(others, sizeof others, "; %d links in all", count);
        if (elastic)
            ts_trust_note(&r->trust, "elastic link %s.%d goes slack at t = "
                          "%.6g s (%d samples to t = %.6g s%s): a snap load "
                          "follows when it pulls again",
                          sys->cables[L->cable].name, L->index, e->t_first,
                          e->samples, e->t_last, others);
        else
            ts_trust_fail(&r->trust, "rigid link %s.%d is in compression "
                          "at t = %.6g s (%d samples to t = %.6g s, lowest "
                          "%.6g N%s): a cable cannot push; the elastic "
                          "model (cables[].ea) lets it go slack",
                          sys->cables[L->cable].name, L->index, e->t_first,
                          e->samples, e->t_last, e->min, others);
    }
    return TS_OK;
}

/* The realisation of a simulation's sea, added to a copy of the request's
 * excitation (r->sea_excitation, which r->excitation then points to). */
/* The excitation of s with its sea's realisation added, into *out (a new
 * excitation, NULL on failure), with the seaway and the realisation's
 * settings; the ship's speed through the waves is `speed` (m/s; NaN: the
 * scene's); a towing vehicle's trim y on kernel k (NULL: none), which
 * places the origin its rotations turn about. */
static int sea_excitation(const ts_system *sys, const ts_simulate_opts *s,
                          double speed, const ts_kernel *k,
                          const double *y, ts_seaway *w,
                          ts_sea_realisation *real, ts_excitation **out,
                          ts_err *err)
{
    *out = NULL;
    int rc = sea_seaway(sys, &s->sea, w, err);
    if (rc)
        return rc;
    if (isfinite(speed))
        w->speed = speed;
    if (k && y)
        ts_seaway_set_trim(w, k, y);
    *out = ts_excitation_copy(s->excitation, err);
    if (!*out)
        return err && err->code ? err->code : TS_ENOMEM;
    ts_sea_realisation_default(w, real);
    real->seed = s->seed;
    real->components = s->components;
    if (!isnan(s->fade_in))
        real->rise = s->fade_in;
    rc = ts_seaway_excitation(w, real, *out, NULL, err);
    if (rc)
        ts_err_prefix(err, "sea: ");
    return rc;
}

static int sea_realise(ts_result *r, const ts_simulate_opts *s,
                       double speed, const ts_kernel *k, const double *y,
                       ts_err *err)
{
    int rc = sea_excitation(r->sys, s, speed, k, y, &r->seaway,
                            &r->realisation, &r->sea_excitation, err);
    if (!r->sea_excitation)
        return rc;
    r->has_sea = 1;
    snprintf(r->rao_file, sizeof r->rao_file, "%s", s->sea.rao_file);
    r->excitation = r->sea_excitation;
    return rc;
}

/* After a simulation with a sea: the records' statistics over t >=
 * transient, their key values (<output>.sigma and .mean_offset, with the
 * statistical error as the solver's), and the spectral prediction over
 * the realisation's band. */
static int sea_records(ts_result *r, ts_err *err)
{
    const ts_history *h[2] = {r->nonlinear, r->linear};
    ts_record_stats *st[2] = {&r->record_nonlinear, &r->record_linear};
    int n = r->nonlinear ? r->nonlinear->nsamples : r->linear->nsamples;
    double *x = malloc((size_t)(n > 0 ? n : 1) * sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    int rc = TS_OK;
    for (int i = 0; i < 2 && rc == TS_OK; i++) {
        if (!h[i])
            continue;
        int m;
        double dt;
        rc = ts_record_from_history(h[i], &r->output, r->transient, x, &m,
                                    &dt, err);
        if (rc == TS_OK)
            rc = ts_record_stats_compute(x, m, dt, st[i], err);
        if (rc == TS_OK)
            r->has_records |= 1 << i;
        else
            ts_err_prefix(err, "transient: the record after %g s: ",
                          r->transient);
    }
    free(x);
    if (rc == TS_OK && r->lin) {
        double lo, hi;
        ts_seastate_opts so;
        ts_seastate_opts_default(&so);
        rc = ts_seaway_band(&r->seaway, TS_SEA_REALISATION_TAIL, &lo, &hi,
                            err);
        so.omega_lo = lo;
        so.omega_hi = hi;
        so.duration = r->sim.t_end - r->transient;
        if (rc == TS_OK)
            rc = ts_seastate_compute(r->sys, r->lin, &r->seaway, &r->output,
                                     &so, &r->seastate, err);
        if (rc == TS_OK)
            ts_trust_merge(&r->trust, "spectral prediction: ",
                           &r->seastate->trust);
    }
    if (rc != TS_OK)
        return rc;
    const ts_record_stats *use =
        r->has_records & 1 ? &r->record_nonlinear : &r->record_linear;
    rc = values_alloc(r, 2, err);
    if (rc)
        return rc;
    value_name(&r->values[0], "m", 0.0, "%.70s.sigma", r->output.name);
    value_name(&r->values[1], "m", total_length(r->sys), "%.70s.mean_offset",
               r->output.name);
    r->values[0].value = use->sigma.value;
    r->values[0].error.solver = use->sigma.error;
    double eqv = r->eq ? r->eq->positions[3 * r->output.node +
                                          r->output.comp]
                       : NAN;
    r->values[1].value = use->mean - eqv;
    r->values[1].error.solver = use->mean_error;
    double window = r->sim.t_end - r->transient;
    if (use->corr_time > 0 && window < 20 * use->corr_time)
        ts_trust_note(&r->trust, "the record after the transient is %g s, "
                      "%.3g correlation times: sigma's statistical error is "
                      "%.2g %%", window, window / use->corr_time,
                      100 * use->sigma.error / use->sigma.value);
    return TS_OK;
}

static int pipeline_simulate(ts_result *r, const ts_request *rq, ts_err *err)
{
    const ts_simulate_opts *s = &rq->simulate;
    const ts_system *sys = r->sys;
    r->excitation = s->excitation;
    int rc = check_simulate(sys, s, rq->setup.open_loop, &r->sim,
                            &r->transient, &r->output, err);
    /* A towing vehicle's speed, which the waves' encounter frequency
     * needs, is known after its equilibrium: its sea is realised there. */
    int sea_later = s->sea.sea && sys->tow.vehicle >= 0;
    if (rc == TS_OK && s->sea.sea && !sea_later)
        rc = sea_realise(r, s, NAN, NULL, NULL, err);
    if (rc != TS_OK)
        return rc;
    ts_sim_opts *o = &r->sim;
    if (!o->progress) {
        o->progress = rq->progress;
        o->progress_data = rq->progress_data;
    }
    ts_excitation *none = NULL;
    const ts_excitation *ex = r->excitation;
    if (!ex) {
        ex = none = ts_excitation_alloc(err);
        if (!ex)
            return err && err->code ? err->code : TS_ENOMEM;
    }
    ts_kernel *k = ts_kernel_alloc(sys, err), *knl = NULL;
    int n = k ? ts_kernel_nstate(k) : 0;
    double *y0 = k ? calloc((size_t)n, sizeof *y0) : NULL;
    double *pos = k ? calloc(3 * (size_t)sys->nnodes, sizeof *pos) : NULL;
    if (!k)
        rc = err && err->code ? err->code : TS_ENOMEM;
    else if (!y0 || !pos)
        rc = ts_fail(err, TS_ENOMEM, "simulate: out of memory for %d states",
                     n);
    /* Initial state. */
    if (rc == TS_OK && s->initial == TS_INITIAL_EQUILIBRIUM) {
        snprintf(r->initial, sizeof r->initial, "equilibrium");
        rc = run_equilibrium(r, k, rq, err);
        if (rc) {
            ts_err_prefix(err, "simulate: the initial equilibrium: ");
        } else {
            /* The state rebuilt from the equilibrium's shape, as the
             * linear model about it starts (ts_linearize_equilibrium):
             * with the loops open or closed the runs start from the same
             * bits (eq->y may differ from the rebuilt state by an ulp of
             * a link angle, and a rebuilt level heading is -0). */
            rc = ts_equilibrium_state(k, r->eq, y0, err);
            ts_trust_merge(&r->trust, "initial equilibrium: ", &r->eq_trust);
            if (rc == TS_OK && sea_later) {
                rc = sea_realise(r, s, r->eq->speed, k, y0, err);
                if (r->sea_excitation)
                    ex = r->excitation;
            }
            /* The loops open at the trim: the state loses their
             * integrators. */
            if (rc == TS_OK && rq->setup.open_loop &&
                ts_control_nloops(k) > 0) {
                r->open_loop = 1;
                rc = ts_control_open(k, r->eq, y0, err);
                n = ts_kernel_nstate(k);
            }
        }
    } else if (rc == TS_OK && s->initial == TS_INITIAL_RELEASED) {
        snprintf(r->initial, sizeof r->initial,
                 "released straight at rest, theta1 %.6g deg, theta2 %.6g "
                 "deg",
                 s->theta1 * 180 / M_PI, s->theta2 * 180 / M_PI);
        rc = ts_sim_released_state(k, s->theta1, s->theta2, y0, err);
    } else if (rc == TS_OK) {
        snprintf(r->initial, sizeof r->initial, "shape from %.200s",
                 s->shape_file);
        rc = read_shape(sys, s->shape_file, pos, err);
        if (!rc) {
            rc = ts_sim_shape_state(k, pos, TS_SIMULATE_SHAPE_RTOL, y0, err);
            if (rc)
                ts_err_prefix(err, "initial: %s: ", s->shape_file);
        }
    }
    int N = ts_sim_nsamples(o);
    if (rc == TS_OK && (s->compare || s->linear || r->has_sea)) {
        /* The linear model about the equilibrium, with its kernel: both
         * runs then start from the linearization's charts (a sea's
         * spectral prediction needs it too). */
        r->lin = ts_linear_alloc(k, err);
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        lo.tensions = 1; /* the linear run's tensions */
        /* The linear run: the dense A and B below the automatic size
         * (dense_max_states, as the modes and the response), the sparse
         * model alone above it (ts_simulate_linear integrates it in
         * O(links) per step), or alone when linear_method sparse asks for
         * it; with a towing vehicle at any size under a manoeuvre (its
         * frame inputs are the dense model's only; without one the sparse
         * model has them too, its Gf). */
        int manoeuvre = ex && ts_excitation_has_manoeuvre(ex);
        lo.frame_inputs = manoeuvre;
        if ((s->compare || s->linear) && manoeuvre &&
            r->sys->tow.vehicle >= 0)
            lo.model = TS_LIN_BOTH;
        else if ((s->compare || s->linear) &&
                 o->linear_method == TS_LINSIM_SPARSE)
            lo.model = TS_LIN_SPARSE;
        double t0 = tsi_wall_now();
        if (!r->lin)
            rc = err && err->code ? err->code : TS_ENOMEM;
        else if (rq->setup.open_loop && ts_control_nloops(k) > 0)
            rc = ts_linearize(k, y0, NULL, &lo, r->lin, err);
        else
            rc = ts_linearize_equilibrium(k, r->eq, &lo, r->lin, err);
        r->lin_wall_s = tsi_wall_now() - t0;
        if (r->lin)
            r->evaluations += r->lin->evaluations;
        if (rc == TS_OK && (s->compare || s->linear)) {
            r->linear = ts_history_alloc(sys, history_start(N), err);
            rc = r->linear ? ts_simulate_linear(k, r->lin, ex, NULL, o,
                                                r->linear, &r->linear_stats,
                                                err)
                           : (err && err->code ? err->code : TS_ENOMEM);
            r->evaluations += r->linear_stats.evaluations;
        }
        if (rc == TS_OK)
            memcpy(y0, r->lin->y0, (size_t)n * sizeof *y0);
    }
    if (rc == TS_OK && !s->linear) {
        knl = ts_kernel_clone(k, err);
        r->nonlinear = knl ? ts_history_alloc(sys, history_start(N), err)
                           : NULL;
        rc = r->nonlinear ? ts_simulate(knl, ex, y0, o, r->nonlinear,
                                        &r->nonlinear_stats, NULL, err)
                          : (err && err->code ? err->code : TS_ENOMEM);
        r->evaluations += r->nonlinear_stats.evaluations;
    }
    /* Health: the start, the linear model's kinks and the integrations'
     * statistics (towstab/health.h). */
    if (r->lin && r->lin->kink_tow && s->compare)
        ts_trust_note(&r->trust, "the tow point is at the water surface: a "
                                 "heave shifts the mean depth at first "
                                 "order, which the linear model cannot "
                                 "show");
    if (r->nonlinear)
        ts_health_simulation(o, &r->nonlinear_stats, &r->trust);
    /* The linear run's integration checked unless it was exact (expm on
     * the dense model). */
    if (r->linear && (o->linear_method != TS_LINSIM_EXPM ||
                      r->linear_stats.newton == TS_NEWTON_SPARSE))
        ts_health_simulation(o, &r->linear_stats, &r->trust);
    if (rc == TS_OK && s->compare) {
        rc = ts_compare_histories(sys, r->lin, ex, r->nonlinear, r->linear,
                                  &r->output, r->transient, &r->compare, err);
        if (rc)
            ts_err_prefix(err, "compare: ");
        else
            r->compared = 1;
    }
    /* The selection, and the forces of what was simulated (a failed
     * run's samples so far too). */
    int frc = sim_selection(sys, s, &r->output, &r->outputs, &r->noutputs,
                            &r->all_outputs, rc == TS_OK ? err : NULL);
    /* The earth-frame tracks (towstab/track.h), when asked for: the
     * frame's pose at each sample, also of a run that stopped early. */
    if (frc == TS_OK && k && sim_needs_tracks(r, s)) {
        ts_frame base;
        ts_kernel_get_frame(k, &base);
        base.speed_rate = base.turn_accel = 0.0;
        ts_history *runs[2] = {r->nonlinear, r->linear};
        for (int i = 0; i < 2; i++)
            if (runs[i]) {
                int trc = ts_track_history(runs[i], ex, &base,
                                           rc == TS_OK ? err : NULL);
                if (rc == TS_OK)
                    rc = trc;
            }
    }
    if (frc == TS_OK)
        frc = sim_forces(r, s, rc == TS_OK ? err : NULL);
    if (rc == TS_OK)
        rc = frc;
    if (rc == TS_OK && r->has_sea)
        rc = sea_records(r, err);
    else if (rc == TS_OK)
        rc = sim_values(r, s->linear, 1, s->need_values, err);
    else if (s->need_values)
        sim_values(r, s->linear, 0, 0, NULL); /* names, NAN values */
    free(y0);
    free(pos);
    ts_kernel_free(knl);
    ts_kernel_free(k);
    ts_excitation_free(none);
    if (none)
        r->excitation = NULL;
    return rc;
}

/* ---- accuracy ---------------------------------------------------------- */

/* A tow-point output of `sys` named again on another discretisation
 * `lev` (the same place): into name; 0, or -1 when lev has no node
 * there. */
static int map_output(const ts_system *sys, const ts_system *lev,
                      const ts_output *out, char *name, size_t size)
{
    int node = out->kind == TS_OUT_TENSION ? sys->links[out->link].lower
                                           : out->node;
    int k = ts_accuracy_node_map(sys, lev, node);
    if (k < 1)
        return -1;
    char nn[2 * TS_NAME_MAX];
    ts_system_node_name(lev, k, nn, sizeof nn);
    static const char axis[3] = {'x', 'y', 'z'};
    if (out->kind == TS_OUT_TENSION)
        snprintf(name, size, "%s.tension", nn);
    else
        snprintf(name, size, "%s.%c", nn, axis[out->comp]);
    return 0;
}

/* The request of another level: the same analysis on system `lev` (which
 * carries the speed and turn rate), without estimate, refinement or
 * window checks; its output named at the same place; modes: every mode
 * below ARPACK's size, else more than the run kept, around the same
 * target. Returns 0, or -1 (with why) when the output has no place. */
/* A coarser level of a modes run that took ARPACK takes ARPACK too from
 * this many states on (LAPACK below: 0.17 s at 400 states), and when it
 * has this many states per mode asked for (ARPACK's Arnoldi vectors,
 * about twice the modes, with room to spare). */
#define LEVEL_ARPACK_MIN_STATES 400
#define LEVEL_ARPACK_ROOM 8

static int level_request(const ts_result *r, const ts_request *rq,
                         const ts_system *lev, ts_request *sub, char *why,
                         size_t size)
{
    *sub = *rq; /* shallow: the excitation is borrowed */
    /* lev carries the settings (it is r->sys coarsened), and a starting
     * guess fits the run's links only. */
    sub->setup.nsets = 0;
    sub->setup.equilibrium.guess = NULL;
    sub->setup.links = 0;
    sub->setup.speed = NAN;
    sub->setup.turn_rate = NAN;
    sub->setup.discretisation_error = 0;
    sub->setup.refine = 0;
    sub->simulate.check_window = 0;
    sub->simulate.compare = 0;
    sub->simulate.linear = 0;
    sub->modes.near = 0;
    sub->modes.oscillatory = 0;
    sub->modes.margins = 0; /* the run's alone are reported */
    if (rq->kind == TS_ANALYSIS_MODES) {
        /* A level of a run that took ARPACK takes it too where it has
         * room (LEVEL_ARPACK_MIN_STATES), below arpack_min_states as
         * well: LAPACK's O(n^3) at the coarser level of a large run costs
         * more than the run (the 250-link level of a 1000-link run:
         * seconds, the run a tenth of one). */
        double nlev = r->lin->nstate / (double)r->sys->nlinks * lev->nlinks;
        int count = r->nmodes_computed + 10;
        int follow = rq->modes.eigen.method == TS_EIG_AUTO && r->eigen &&
                     r->eigen->method == TS_EIG_ARPACK &&
                     nlev >= LEVEL_ARPACK_MIN_STATES &&
                     nlev >= LEVEL_ARPACK_ROOM * count;
        int arpack = rq->modes.eigen.method == TS_EIG_ARPACK || follow ||
                     (rq->modes.eigen.method == TS_EIG_AUTO &&
                      nlev >= rq->modes.eigen.arpack_min_states);
        sub->modes.count = arpack ? count : 0;
        if (follow)
            sub->modes.eigen.method = TS_EIG_ARPACK;
    }
    const ts_output *out = rq->kind == TS_ANALYSIS_RESPONSE
                               ? &r->response->output
                               : &r->output;
    char *dst = rq->kind == TS_ANALYSIS_RESPONSE ? sub->response.output
                                                 : sub->simulate.output;
    size_t dsize = rq->kind == TS_ANALYSIS_RESPONSE
                       ? sizeof sub->response.output
                       : sizeof sub->simulate.output;
    if ((rq->kind == TS_ANALYSIS_RESPONSE ||
         rq->kind == TS_ANALYSIS_SIMULATE) &&
        map_output(r->sys, lev, out, dst, dsize) != 0) {
        snprintf(why, size, "the %d-link discretisation has no node at the "
                 "place of %s (a body, a free end or a node at a fraction "
                 "of its cable that both have)",
                 ts_accuracy_max_links(lev), out->name);
        return -1;
    }
    return 0;
}

/* The result of every level: r itself, then the runs at the other
 * discretisations. */
typedef struct levels {
    int n;                                  /* r included */
    const ts_result *res[TS_ACCURACY_LEVELS];
    ts_result *own[TS_ACCURACY_LEVELS];     /* the other levels (owned) */
    ts_system *sys[TS_ACCURACY_LEVELS];
} levels;

static void levels_free(levels *L)
{
    for (int k = 1; k < TS_ACCURACY_LEVELS; k++) {
        ts_result_free(L->own[k]);
        ts_system_free(L->sys[k]);
    }
}

/* Run the other levels: two coarser ones, or one finer when some cable
 * has a single link. A level that fails ends the series there; its
 * message goes to why. */
static int run_levels(ts_result *r, const ts_request *rq, levels *L,
                      char *why, size_t size)
{
    ts_result_accuracy *a = &r->accuracy;
    memset(L, 0, sizeof *L);
    L->n = 1;
    L->res[0] = r;
    if (r->eigen)
        a->eigen_method[0] = (int)r->eigen->method;
    int coarser = ts_system_can_coarsen(r->sys);
    int want = coarser ? 3 : 2;
    const ts_system *from = r->sys;
    for (int k = 1; k < want; k++) {
        if (k > 1 && !ts_system_can_coarsen(from))
            break;
        ts_err e = {0};
        double ratio;
        ts_system *lev = ts_system_level(from, coarser, &ratio, &e);
        if (!lev) {
            snprintf(why, size, "no %s discretisation: %.200s",
                     coarser ? "coarser" : "finer", e.msg);
            return e.code == TS_ENOMEM ? TS_ENOMEM : TS_OK;
        }
        ts_request sub;
        if (level_request(r, rq, lev, &sub, why, size) != 0) {
            ts_system_free(lev);
            return TS_OK;
        }
        ts_result *lr = NULL;
        int rc = ts_analysis_run(lev, &sub, &lr, &e);
        if (lr) {
            a->wall_s = (isnan(a->wall_s) ? 0.0 : a->wall_s) + lr->wall_s;
            a->evaluations += lr->evaluations;
        }
        if (rc == TS_ECANCEL || rc == TS_ENOMEM) {
            snprintf(why, size, "the run at %d links stopped: %.200s",
                     ts_accuracy_max_links(lev), e.msg);
            ts_result_free(lr);
            ts_system_free(lev);
            return rc;
        }
        if (rc != TS_OK) {
            if (k == 1)
                snprintf(why, size, "the run at %d links failed: %.200s",
                         ts_accuracy_max_links(lev), e.msg);
            ts_result_free(lr);
            ts_system_free(lev);
            break;
        }
        L->sys[k] = lev;
        L->own[k] = lr;
        L->res[k] = lr;
        if (lr->eigen)
            a->eigen_method[k] = (int)lr->eigen->method;
        a->ratio[k - 1] = ratio;
        a->links[k] = ts_accuracy_max_links(lev);
        L->n = k + 1;
        from = lev;
    }
    a->nlevels = L->n;
    return TS_OK;
}

/* The Richardson estimate of key value v from the levels (values matched
 * by index: every level names them alike). */
static void estimate_value(ts_result *r, const levels *L, int v,
                           double order)
{
    ts_accuracy_series s = {0};
    s.order = order;
    s.nlevels = L->n;
    for (int k = 0; k < L->n; k++) {
        const ts_value *x = v < L->res[k]->nvalues ? &L->res[k]->values[v]
                                                   : NULL;
        s.f[k] = x ? x->value : NAN;
        if (x && isfinite(x->error.solver))
            s.noise = fmax(s.noise, x->error.solver);
        if (k > 0)
            s.ratio[k - 1] = r->accuracy.ratio[k - 1];
    }
    ts_accuracy_estimate e = ts_accuracy_richardson(&s);
    r->values[v].error.discretisation = e.error;
    r->values[v].order = isfinite(e.error) ? e.order : NAN;
}

/* What the accuracy is judged on: one relative error, its order and its
 * name. */
static void judge(ts_result_accuracy *a, double rel, double order,
                  double theory, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* `order` is the order the estimate used, `theory` the theoretical one,
 * which predicts the links needed: the error falls as N^-p once N is in
 * the asymptotic range (an estimate made at a smaller, pre-asymptotic
 * order is already the larger). */
static void judge(ts_result_accuracy *a, double rel, double order,
                  double theory, const char *fmt, ...)
{
    if (!isfinite(rel))
        return;
    double f = ts_accuracy_links_factor(rel, a->accuracy, theory);
    if (isfinite(f) && !(f <= a->links_factor))
        a->links_factor = f;
    if (isfinite(a->max_rel_error) && !(rel > a->max_rel_error))
        return;
    a->max_rel_error = rel;
    a->limiting_order = order;
    a->limiting_theory = theory;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(a->limiting, sizeof a->limiting, fmt, ap);
    va_end(ap);
}

/* The relative scale of key value v. */
static double value_scale(const ts_value *v)
{
    return v->scale > 0 ? v->scale : fabs(v->value);
}

/* Modes: match every mode computed to the other levels; the key values'
 * errors from their modes; the verdicts of resolved and unresolved
 * modes. Without levels, only the shape test. */
static void estimate_modes(ts_result *r, const ts_request *rq,
                           const levels *L)
{
    ts_result_accuracy *a = &r->accuracy;
    ts_eigen all = *r->eigen;
    all.nmodes = r->nmodes_computed;
    const ts_eigen *lev[TS_ACCURACY_LEVELS - 1] = {NULL, NULL};
    for (int k = 1; k < L->n; k++)
        lev[k - 1] = L->res[k]->eigen;
    ts_accuracy_modes(r->sys, r->lin, &all, L->n, lev, a->ratio, a->order,
                      a->accuracy, r->mode_accuracy);
    ts_accuracy_stability(&all, r->mode_accuracy, L->n > 1, &r->stability);
    if (L->n < 2)
        return;
    for (int k = 0; k < rq->modes.follow && 2 * k + 1 < r->nvalues; k++) {
        int m = key_mode(&all, all.nmodes, k);
        if (m < 0)
            continue;
        const ts_mode_accuracy *ma = &r->mode_accuracy[m];
        r->values[2 * k].error.discretisation = ma->freq_error_hz;
        r->values[2 * k + 1].error.discretisation = ma->damping_error;
        r->values[2 * k].order = r->values[2 * k + 1].order = ma->order;
    }
    const ts_stability *st = &r->stability;
    if (st->mode >= 0) {
        const ts_mode *md = &all.modes[st->mode];
        double mag = hypot(md->re, md->im);
        if (mag > 0)
            judge(a, st->discretisation_error / mag,
                  r->mode_accuracy[st->mode].order, a->order,
                  "the stability margin (Re of mode %d, relative to "
                  "|lambda|)", st->mode + 1);
    }
}

/* Response: the errors of magnitude and phase at every frequency, of the
 * key values, and the highest frequency up to which the magnitude meets
 * the accuracy. */
static int estimate_response(ts_result *r, const levels *L, ts_err *err)
{
    ts_result_accuracy *a = &r->accuracy;
    const ts_response *res = r->response;
    int np = res->npoints;
    r->magnitude_error = malloc((size_t)np * sizeof(double));
    r->phase_error_deg = malloc((size_t)np * sizeof(double));
    if (!r->magnitude_error || !r->phase_error_deg)
        return ts_fail(err, TS_ENOMEM, "response: out of memory");
    double order = res->output.kind == TS_OUT_TENSION ? 1.0 : a->order;
    int ip = response_peak(res);
    double peak = res->magnitude[ip];
    r->accurate_to_hz = NAN;
    int all_met = 1;
    double worst = -1;
    int iw = -1;
    for (int i = 0; i < np; i++) {
        ts_accuracy_series mag = {0}, ph = {0};
        mag.order = ph.order = order;
        mag.nlevels = ph.nlevels = L->n;
        for (int k = 0; k < L->n; k++) {
            const ts_response *q = L->res[k]->response;
            mag.f[k] = q->magnitude[i];
            /* Phases unwrapped onto the run's. */
            ph.f[k] = res->phase_deg[i] +
                      ts_compare_wrap_deg(q->phase_deg[i] -
                                          res->phase_deg[i]);
            if (k > 0)
                mag.ratio[k - 1] = ph.ratio[k - 1] = a->ratio[k - 1];
        }
        mag.noise = 16 * DBL_EPSILON * peak;
        r->magnitude_error[i] = ts_accuracy_richardson(&mag).error;
        r->phase_error_deg[i] = ts_accuracy_richardson(&ph).error;
        double rel = peak > 0 ? r->magnitude_error[i] / peak : NAN;
        if (rel > worst) {
            worst = rel;
            iw = i;
        }
        if (all_met && rel <= a->accuracy)
            r->accurate_to_hz = res->freq_hz[i];
        else
            all_met = 0;
    }
    if (iw >= 0)
        judge(a, worst, order, order, "the magnitude at %.4g Hz (relative to the "
              "largest, %.4g %s)", res->freq_hz[iw], peak, res->unit);
    /* Key values: the static gain at each level, the magnitude at the
     * peak's frequency. */
    for (int v = 0; v < r->nvalues && v < 2; v++) {
        ts_accuracy_series s = {0};
        s.order = order;
        s.nlevels = L->n;
        for (int k = 0; k < L->n; k++) {
            const ts_response *q = L->res[k]->response;
            s.f[k] = v == 0 ? q->static_gain : q->magnitude[ip];
            if (k > 0)
                s.ratio[k - 1] = a->ratio[k - 1];
        }
        s.noise = 16 * DBL_EPSILON * peak;
        ts_accuracy_estimate e = ts_accuracy_richardson(&s);
        r->values[v].error.discretisation = e.error;
        r->values[v].order = e.order;
    }
    return TS_OK;
}

/* The analysed window of a simulation: settled and periodic. The slowest
 * time constant comes from the modes of the linear model about the
 * equilibrium (linearized here when the run did not need it). */
static int check_window(ts_result *r, const ts_request *rq, ts_err *err)
{
    const ts_excitation *ex = r->excitation;
    int idx;
    const ts_history *h = r->nonlinear ? r->nonlinear : r->linear;
    if (!rq->simulate.check_window || !ex ||
        !ts_excitation_periodic(ex, &idx) || !h || h->nsamples < 3 ||
        !r->eq || !r->eq->converged ||
        (!r->compared && !(r->nvalues > 0 && isfinite(r->values[0].value))))
        return TS_OK;
    const ts_signal *sg = ts_excitation_signal(ex, idx);
    double tau = NAN, fslow = NAN;
    int complete = 0;
    ts_linear *own = NULL;
    const ts_linear *lin = r->lin;
    if (!lin) {
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        lo.estimate_error = 0;
        ts_kernel *k = ts_kernel_alloc(r->sys, err);
        own = k ? ts_linear_alloc(k, err) : NULL;
        int rc = own ? ts_linearize_equilibrium(k, r->eq, &lo, own, err)
                     : (err && err->code ? err->code : TS_ENOMEM);
        ts_kernel_free(k);
        if (rc == TS_ENOMEM) {
            ts_linear_free(own);
            return rc;
        }
        if (rc == TS_OK) {
            lin = own;
            r->evaluations += own->evaluations;
        } else {
            ts_err_clear(err);
        }
    }
    if (lin) {
        ts_eigen_opts eo;
        ts_eigen_opts_default(&eo);
        if (lin->nstate >= eo.arpack_min_states)
            eo.count = TS_MODES_LARGE_COUNT;
        ts_eigen *e = NULL;
        if (ts_eigen_solve(lin, &eo, &e, NULL) == TS_OK) {
            complete = e->complete;
            /* Grid-scale modes are left out: artefacts of the links whose
             * time constants grow with their number (the top mode's is
             * 9 s at 20 links and 25 s at 80 in Kamman's ex. 4), which
             * the output hardly sees; the drift check sees them if it
             * does. */
            for (int m = 0; m < e->nmodes; m++)
                if (e->modes[m].re < 0 &&
                    !(-1.0 / e->modes[m].re <= tau) &&
                    !(ts_accuracy_half_wave(r->sys, lin, e, m) <=
                      TS_ACCURACY_GRID_HALF_WAVE)) {
                    tau = -1.0 / e->modes[m].re;
                    fslow = e->modes[m].freq_hz;
                }
        }
        ts_eigen_free(e);
    }
    ts_linear_free(own);
    /* The output of each run over the whole run. */
    const ts_history *runs[2] = {r->nonlinear, r->linear};
    size_t stride = 3 * (size_t)h->nnodes;
    size_t off = 3 * (size_t)r->output.node + (size_t)r->output.comp;
    double *x = malloc((size_t)h->nsamples * sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    for (int j = 0; j < 2; j++) {
        const ts_history *q = runs[j];
        if (!q || (j == 1 && !r->compared && r->nonlinear))
            continue;
        for (int i = 0; i < q->nsamples; i++)
            x[i] = q->positions[stride * i + off];
        ts_window w;
        ts_accuracy_window(q->t, x, q->nsamples, 1.0 / sg->frequency,
                           sg->amplitude, r->transient, tau,
                           rq->setup.accuracy, &w);
        w.slowest_freq_hz = fslow;
        w.modes_complete = complete;
        /* The window reported is the worse of the two runs'. */
        if (!r->window.checked || w.settled == 0 ||
            (w.periodic == 0 && r->window.settled != 0) ||
            (isfinite(w.drift) && w.drift > r->window.drift &&
             r->window.settled != 0 && r->window.periodic != 0))
            r->window = w;
    }
    free(x);
    const ts_window *w = &r->window;
    char slow[160] = "";
    if (isfinite(tau))
        snprintf(slow, sizeof slow, "the slowest mode%s (%s, %.4g s)",
                 complete ? "" : " among those nearest 0 Hz",
                 fslow > 0 ? "oscillatory" : "real", tau);
    if (w->settled == 0)
        ts_trust_fail(&r->trust, "not settled: the window starts at %.4g s, "
                      "before %.4g time constants (%.4g s) of %s; "
                      "--transient %.4g --t-end %.4g would do",
                      w->transient, TS_ACCURACY_SETTLE_TAU,
                      TS_ACCURACY_SETTLE_TAU * tau, slow,
                      w->transient_needed, w->t_end_needed);
    else if (w->settled == 1 && isfinite(tau) &&
             w->transient < TS_ACCURACY_SETTLE_TAU * tau)
        ts_trust_note(&r->trust, "the analysis window begins at %.4g s, "
                      "before %.4g time constants of the slowest mode "
                      "(%.4g s), but the last two periods agree to %.2g, so "
                      "at most %.2g of a decaying transient remains",
                      w->transient, TS_ACCURACY_SETTLE_TAU, tau, w->drift,
                      w->remaining);
    if (w->periodic == 0)
        ts_trust_fail(&r->trust, "not periodic: the output's last two "
                      "periods differ by %.2g of its half range, above the "
                      "accuracy %.3g; --transient %.4g --t-end %.4g would "
                      "do", w->drift, rq->setup.accuracy,
                      w->transient_needed, w->t_end_needed);
    else if (w->periodic < 0 && w->t_end < 2 * w->period)
        ts_trust_fail(&r->trust, "the run (%.4g s) is shorter than two "
                      "periods (%.4g s), so its periodicity cannot be "
                      "checked; --t-end %.4g would do", w->t_end,
                      2 * w->period, w->t_end_needed);
    return TS_OK;
}

/* The note on a turn whose radius is short for the cable: a turn rate
 * probably meant in other units. */
static void tow_notes(ts_result *r)
{
    const ts_tow *t = &r->sys->tow;
    if (t->turn_rate == 0.0)
        return;
    double R = t->speed / fabs(t->turn_rate), L = total_length(r->sys);
    if (R < 0.1 * L)
        ts_trust_note(&r->trust, "the turn radius V / Omega = %.4g m is "
                      "shorter than a tenth of the cable length (%.4g m): "
                      "the turn rate %.4g rad/s is %.4g deg/s; a rate meant "
                      "in deg/s is given as \"%.4g deg/s\"",
                      R, L, t->turn_rate, t->turn_rate * 180.0 / M_PI,
                      t->turn_rate);
}

/* The theoretical order of key value v: a link tension's (the extremes
 * of a time history, a tension output) is 1, else the result's. */
static double value_order(const ts_result *r, const ts_request *rq, int v)
{
    if (rq->kind == TS_ANALYSIS_SIMULATE && !r->has_sea && v >= sim_nfit(r))
        return 1.0;
    if (rq->kind == TS_ANALYSIS_RESPONSE && r->response &&
        r->response->output.kind == TS_OUT_TENSION)
        return 1.0;
    return r->accuracy.order;
}

/* The accuracy of a finished result: the window checks of a simulation,
 * the discretisation error of every key value from the other levels, the
 * modes' resolution, and the verdict against rq->setup.accuracy. */
static int accuracy_stage(ts_result *r, const ts_request *rq, ts_err *err)
{
    ts_result_accuracy *a = &r->accuracy;
    a->accuracy = rq->setup.accuracy;
    a->order = ts_accuracy_order(r->sys);
    /* A response through a kinked linear model converges at first order
     * (towstab/accuracy.h). */
    if (rq->kind == TS_ANALYSIS_RESPONSE && r->lin && r->lin->kinks > 0)
        a->order = 1.0;
    a->links[0] = ts_accuracy_max_links(r->sys);
    a->nlevels = 1;
    int rc = TS_OK;
    if (rq->kind == TS_ANALYSIS_SIMULATE)
        rc = check_window(r, rq, err);
    if (rc != TS_OK)
        return rc;
    if (rq->kind == TS_ANALYSIS_MODES) {
        int n = r->nmodes_computed;
        r->mode_accuracy = calloc((size_t)(n > 0 ? n : 1),
                                  sizeof *r->mode_accuracy);
        if (!r->mode_accuracy)
            return ts_fail(err, TS_ENOMEM, "modes: out of memory");
    }
    levels L = {1, {r}, {NULL}, {NULL}};
    int wanted = rq->setup.discretisation_error || rq->setup.refine;
    if (wanted && r->seastate && rq->kind == TS_ANALYSIS_RESPONSE) {
        /* A sea response estimated its own (ts_seastate_discretisation,
         * coarse to fine in disc_links): judge it. */
        const ts_seastate *ss = r->seastate;
        a->estimated = ss->disc_estimated;
        if (a->estimated) {
            a->nlevels = 3;
            for (int k = 0; k < 3; k++)
                a->links[k] = ss->disc_links[2 - k];
            for (int k = 0; k < 2; k++)
                a->ratio[k] = (double)a->links[k] / a->links[k + 1];
            a->wall_s = ss->disc_wall_s;
        } else {
            snprintf(a->not_estimated, sizeof a->not_estimated,
                     "the sea state's estimate needs every cable at the "
                     "same number (at least %d) of equal links",
                     TS_SEASTATE_DISC_LINKS_MIN);
        }
    } else if (!wanted)
        snprintf(a->not_estimated, sizeof a->not_estimated,
                 rq->kind == TS_ANALYSIS_SIMULATE
                     ? "off: it costs the simulation again at a half and "
                       "a quarter of the links (--discretisation-error)"
                     : "off (--no-discretisation-error)");
    else if (rq->kind == TS_ANALYSIS_SIMULATE && r->nvalues == 0)
        snprintf(a->not_estimated, sizeof a->not_estimated,
                 "the run has no key values to compare (they need a "
                 "single periodic excitation and a nonlinear run)");
    else
        rc = run_levels(r, rq, &L, a->not_estimated,
                        sizeof a->not_estimated);
    if (rc != TS_OK) {
        levels_free(&L);
        return rc;
    }
    if (!r->seastate || rq->kind != TS_ANALYSIS_RESPONSE)
        a->estimated = L.n > 1;
    if (a->estimated)
        a->not_estimated[0] = '\0';
    if (rq->kind == TS_ANALYSIS_MODES)
        estimate_modes(r, rq, &L);
    else if (rq->kind == TS_ANALYSIS_RESPONSE && a->estimated &&
             !r->seastate)
        rc = estimate_response(r, &L, err);
    else if (a->estimated && L.n > 1)
        for (int v = 0; v < r->nvalues; v++)
            estimate_value(r, &L, v, value_order(r, rq, v));
    levels_free(&L);
    if (rc != TS_OK)
        return rc;
    /* The verdict: every key value's relative error against the
     * accuracy. */
    for (int v = 0; a->estimated && v < r->nvalues; v++) {
        const ts_value *x = &r->values[v];
        double sc = value_scale(x);
        double theory = value_order(r, rq, v);
        if (sc > 0 && isfinite(x->error.discretisation))
            judge(a, x->error.discretisation / sc, x->order, theory, "%s",
                  x->name);
    }
    if (!a->estimated || !isfinite(a->max_rel_error))
        return TS_OK;
    a->met = a->max_rel_error <= a->accuracy;
    if (a->met)
        return TS_OK;
    double need = ceil(a->links[0] * a->links_factor);
    a->links_needed = need <= TS_MAX_LINKS ? (int)need : 0;
    char links[160];
    if (a->links_needed > 0)
        snprintf(links, sizeof links, "about %d links per cable would meet "
                 "it (--links %d, or --refine)", a->links_needed,
                 a->links_needed);
    else
        snprintf(links, sizeof links, "more than %d links per cable would "
                 "be needed", TS_MAX_LINKS);
    ts_trust_fail(&r->trust, "discretisation error: %s is %.2g (relative), "
                  "above the accuracy %.3g; the error model (Richardson "
                  "from %d and %d links, falling as links^-%.3g) says %s",
                  a->limiting, a->max_rel_error, a->accuracy, a->links[0],
                  a->links[1], a->limiting_theory, links);
    return TS_OK;
}

/* ---- converge ---------------------------------------------------------- */

/* A sweep's run: the pipeline of the study's analysis at one setting. */
typedef struct sweep_ctx {
    const ts_system *sys;
    ts_request rq;      /* a shallow copy: the excitation is borrowed */
    ts_conv_param param;
} sweep_ctx;

static void sweep_ctx_free(void *p) { free(p); }

/* The row verdict of a modes run: the equilibrium's, the surface kink,
 * the notes of the mode analysis, and the damping of the modes followed
 * (a stiff axial mode far above them does not make their frequencies
 * untrustworthy). */
static void modes_row_trust(const ts_result *r, int follow, ts_trust *t)
{
    ts_trust_merge(t, NULL, &r->eq_trust);
    if (!r->eigen)
        return;
    const ts_linear *lin = r->lin;
    if (lin->kinks > lin->kink_tow && r->modes_trust.nreasons > 0)
        ts_trust_fail(t, "%s", r->modes_trust.reasons[0]);
    for (int i = 0; i < r->modes_trust.nnotes; i++)
        ts_trust_note(t, "%s", r->modes_trust.notes[i]);
    const ts_eigen *e = r->eigen;
    for (int m = 0, k = 0; m < e->nmodes && k < follow; m++) {
        const ts_mode *md = &e->modes[m];
        if (!(md->im > 0) || !(md->damping_ratio < TS_CONV_MODE_DAMPING_MAX))
            continue;
        if (!r->mode_health[m].trustworthy)
            ts_trust_fail(t, "mode%d (%.6g Hz): damping ratio %.3g +- %.2g "
                             "is not resolved",
                          k + 1, md->freq_hz, md->damping_ratio,
                          r->mode_health[m].damping_error);
        k++;
    }
}

static int sweep_run(void *ctx, ts_conv_param p, double setting,
                     double values[], double noise[], long *evaluations,
                     ts_trust *trust, ts_err *err)
{
    sweep_ctx *x = ctx;
    ts_request rq = x->rq;
    ts_analysis_kind kind = rq.kind;
    /* The study estimates the errors itself: each run is plain. */
    rq.setup.discretisation_error = 0;
    rq.setup.refine = 0;
    rq.simulate.check_window = 0;
    if (p == TS_CONV_STEP && kind != TS_ANALYSIS_MODES)
        return ts_fail(err, TS_EINVAL, "%s: there is no linearization step "
                       "to sweep; sweep links or tolerances",
                       ts_analysis_name(kind));
    if (p == TS_CONV_LINKS)
        rq.setup.links = (int)setting;
    else if (p == TS_CONV_STEP)
        rq.modes.linearize.rel_step = setting;
    else if (kind == TS_ANALYSIS_SIMULATE) {
        ts_sim_opts *o = &rq.simulate.sim;
        o->abs_tol = o->abs_tol * (setting / o->rel_tol);
        o->rel_tol = setting;
    } else
        rq.setup.equilibrium.tol = setting;
    ts_result *r = NULL;
    int rc = ts_analysis_run(x->sys, &rq, &r, err);
    if (!r)
        return rc;
    *evaluations += r->evaluations;
    if (kind == TS_ANALYSIS_MODES)
        modes_row_trust(r, rq.modes.follow, trust);
    else {
        /* Its verdict without the failure, which the row records. */
        for (int i = 0; i < r->trust.nreasons; i++)
            if (strncmp(r->trust.reasons[i], "the run failed: ", 16) != 0)
                ts_trust_fail(trust, "%s", r->trust.reasons[i]);
        for (int i = 0; i < r->trust.nnotes; i++)
            ts_trust_note(trust, "%s", r->trust.notes[i]);
    }
    for (int v = 0; rc == TS_OK && v < r->nvalues; v++) {
        const ts_value *V = &r->values[v];
        values[v] = V->value;
        noise[v] = isfinite(V->error.solver) ? V->error.solver : 0.0;
        if (p == TS_CONV_STEP)
            noise[v] = STEP_NOISE_REL *
                       (V->scale > 0 ? fmax(fabs(V->value), V->scale)
                                     : fabs(V->value));
        if (p == TS_CONV_LINKS && kind == TS_ANALYSIS_SIMULATE) {
            double sc = V->scale > 0 ? V->scale : fabs(V->value);
            if (v == 1)
                sc = total_length(r->sys); /* the mean offset, m */
            noise[v] += SIM_TOL_NOISE * rq.simulate.sim.rel_tol * sc;
        }
    }
    ts_result_free(r);
    return rc;
}

/* A result of rq's kind with its key values named (values and estimates
 * NAN), without running: *out (also after a failure, may be NULL). */
static int named_result(const ts_system *sys, const ts_request *rq,
                        ts_result **out, ts_err *err)
{
    ts_analysis_kind kind = rq->kind;
    ts_result *r = *out = result_alloc(kind, err);
    int rc = r ? TS_OK : TS_ENOMEM;
    if (rc == TS_OK) {
        r->sys = setup_system(sys, rq, err);
        rc = r->sys ? TS_OK : (err && err->code ? err->code : TS_ENOMEM);
    }
    if (rc == TS_OK && kind == TS_ANALYSIS_EQUILIBRIUM)
        rc = eq_values(r, err);
    else if (rc == TS_OK && kind == TS_ANALYSIS_MODES)
        rc = modes_values(r, rq->modes.follow, err);
    else if (rc == TS_OK && kind == TS_ANALYSIS_SIMULATE) {
        rc = check_simulate(r->sys, &rq->simulate, rq->setup.open_loop,
                            &r->sim, &r->transient, &r->output, err);
        r->excitation = rq->simulate.excitation;
        if (rc == TS_OK)
            rc = sim_values(r, rq->simulate.linear, 0, 0, err);
    }
    return rc;
}

int ts_analysis_value_names(const ts_system *sys, const ts_request *rq,
                            ts_value **values, int *n, ts_err *err)
{
    *values = NULL;
    *n = 0;
    if (rq->kind == TS_ANALYSIS_CONVERGE)
        return ts_fail(err, TS_EINVAL, "analysis: a convergence study's "
                       "values are those of its analysis");
    ts_result *r = NULL;
    int rc = named_result(sys, rq, &r, err);
    if (rc == TS_OK) {
        *values = r->values;
        *n = r->nvalues;
        r->values = NULL;
        r->nvalues = 0;
    }
    ts_result_free(r);
    return rc;
}

int ts_analysis_sweep(const ts_system *sys, const ts_request *rq, int series,
                      ts_conv_analysis *an, ts_err *err)
{
    memset(an, 0, sizeof *an);
    ts_analysis_kind kind = rq->converge.analysis;
    if (kind != TS_ANALYSIS_EQUILIBRIUM && kind != TS_ANALYSIS_MODES &&
        kind != TS_ANALYSIS_SIMULATE)
        return ts_fail(err, TS_EINVAL, "analysis: '%s' is not an analysis to "
                       "converge; expected equilibrium, modes or simulate",
                       ts_analysis_name(kind));
    sweep_ctx *x = calloc(1, sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "converge: out of memory");
    x->sys = sys;
    x->rq = *rq;
    x->rq.kind = kind;
    x->param = rq->converge.param;
    ts_simulate_opts *s = &x->rq.simulate;
    if (kind == TS_ANALYSIS_SIMULATE) {
        s->need_values = 1;
        s->compare = 0;
        if (series < rq->converge.nintegrators)
            s->sim.integrator = rq->converge.integrators[series];
    }
    if (kind == TS_ANALYSIS_MODES && !(rq->modes.follow >= 1 &&
                                       rq->modes.follow <= 100)) {
        free(x);
        return ts_fail(err, TS_EINVAL, "modes: expected 1 to 100 modes to "
                       "follow, got %d", rq->modes.follow);
    }
    ts_result *r = NULL;
    int rc = named_result(sys, &x->rq, &r, err);
    if (rc == TS_OK) {
        an->values = calloc((size_t)r->nvalues, sizeof *an->values);
        if (!an->values)
            rc = ts_fail(err, TS_ENOMEM, "converge: out of memory");
    }
    if (rc != TS_OK) {
        ts_result_free(r);
        free(x);
        return rc;
    }
    an->nvalues = r->nvalues;
    for (int v = 0; v < r->nvalues; v++) {
        snprintf(an->values[v].name, sizeof an->values[v].name, "%s",
                 r->values[v].name);
        snprintf(an->values[v].unit, sizeof an->values[v].unit, "%s",
                 r->values[v].unit);
        an->values[v].scale = r->values[v].scale;
    }
    ts_result_free(r);
    snprintf(an->name, sizeof an->name, "%s", ts_analysis_name(kind));
    an->ctx = x;
    an->free_ctx = sweep_ctx_free;
    an->run = sweep_run;
    return TS_OK;
}

/* The sweep of a study: the request's, or the default one. */
static void converge_sweep(const ts_converge_opts *c, ts_conv_param *param,
                           double *settings, int *n)
{
    if (c->nsettings > 0) {
        *param = c->param;
        *n = c->nsettings;
        memcpy(settings, c->settings, (size_t)*n * sizeof *settings);
    } else {
        *n = default_settings(c->analysis, param, settings);
    }
}

/* Refuse a cable with link_lengths for option `key`, saying why. */
static int equal_links_only(const ts_system *sys, const char *key,
                            const char *why, ts_err *err)
{
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].link_fraction)
            return ts_fail(err, TS_EINVAL, "%s: cables[%d] '%s' has "
                           "link_lengths; %s", key, c, sys->cables[c].name,
                           why);
    return TS_OK;
}

static int check_converge(const ts_system *sys, const ts_request *rq,
                          ts_err *err)
{
    const ts_converge_opts *c = &rq->converge;
    ts_conv_param param;
    double settings[TS_CONV_MAX_SETTINGS];
    int n;
    converge_sweep(c, &param, settings, &n);
    static const char *const key[3] = {"links", "tolerances", "steps"};
    int rc = ts_conv_check_settings(param, settings, n, key[param], err);
    if (rc)
        return rc;
    if (param == TS_CONV_STEP && c->analysis != TS_ANALYSIS_MODES)
        return ts_fail(err, TS_EINVAL, "steps: the linearization step "
                       "applies to the modes analysis, not to %s",
                       ts_analysis_name(c->analysis));
    if (!(c->target > 0 && c->target < 1))
        return ts_fail(err, TS_EINVAL, "target: expected a relative error in "
                       "(0, 1), got %g", c->target);
    if (c->nintegrators > 0 && c->analysis != TS_ANALYSIS_SIMULATE)
        return ts_fail(err, TS_EINVAL, "integrators: applies to the simulate "
                       "analysis, not to %s", ts_analysis_name(c->analysis));
    if (param == TS_CONV_LINKS &&
        (rc = equal_links_only(sys, "links", "a link sweep needs equal links "
                               "(remove link_lengths, or sweep tolerances)",
                               err)))
        return rc;
    if (c->analysis == TS_ANALYSIS_SIMULATE) {
        const ts_simulate_opts *s = &rq->simulate;
        if (s->initial != TS_INITIAL_EQUILIBRIUM)
            return ts_fail(err, TS_EINVAL, "initial: the simulate study "
                           "starts from the equilibrium (its values are the "
                           "steady response to a periodic excitation)");
        if (s->linear)
            return ts_fail(err, TS_EINVAL, "linear: the simulate study sweeps "
                           "the nonlinear integrator; drop linear");
        int idx;
        if (!s->excitation || !ts_excitation_periodic(s->excitation, &idx))
            return ts_fail(err, TS_EINVAL, "excite: the simulate study needs "
                           "a single periodic tow-point excitation (one sine "
                           "or crank), e.g. --excite "
                           "tow.heave:amplitude=0.1ft,frequency=1Hz");
    }
    ts_conv_analysis an;
    rc = ts_analysis_sweep(sys, rq, 0, &an, err);
    ts_conv_analysis_free(&an);
    return rc;
}

static int pipeline_converge(ts_result *r, const ts_request *rq,
                             const ts_system *base, ts_err *err)
{
    const ts_converge_opts *c = &rq->converge;
    ts_conv_param param;
    double settings[TS_CONV_MAX_SETTINGS];
    int n;
    converge_sweep(c, &param, settings, &n);
    ts_request sub = *rq;
    sub.converge.param = param;
    int simulate = c->analysis == TS_ANALYSIS_SIMULATE;
    int nseries = simulate && c->nintegrators > 0 ? c->nintegrators : 1;
    if (simulate) {
        r->excitation = rq->simulate.excitation;
        sim_resolve(&rq->simulate, &r->sim, &r->transient);
        int rc = sim_output(r->sys, rq->simulate.output, &r->output, err);
        if (rc)
            return rc;
    }
    int rc = TS_OK;
    for (int k = 0; k < nseries && rc == TS_OK; k++) {
        ts_conv_analysis an;
        rc = ts_analysis_sweep(base, &sub, k, &an, err);
        if (rc)
            break;
        if (!r->convergence) {
            r->convergence = ts_convergence_alloc(an.name, param, an.nvalues,
                                                  an.values, n * nseries,
                                                  err);
            if (r->convergence) {
                r->convergence->progress = rq->progress;
                r->convergence->progress_data = rq->progress_data;
            }
        }
        if (!r->convergence) {
            ts_conv_analysis_free(&an);
            return err && err->code ? err->code : TS_ENOMEM;
        }
        char series[TS_CONV_NAME_MAX] = "";
        if (simulate)
            snprintf(series, sizeof series, "%s",
                     ts_integrator_name(k < c->nintegrators
                                            ? c->integrators[k]
                                            : rq->simulate.sim.integrator));
        int s = ts_convergence_add_series(r->convergence, series, err);
        rc = s < 0 ? s
                   : ts_convergence_sweep(r->convergence, s, &an, settings, n,
                                          err);
        ts_conv_analysis_free(&an);
    }
    /* Stopped on request: the runs so far, estimated as far as they go,
     * are the result, marked incomplete by the status. */
    ts_err stop = {0};
    if (rc == TS_ECANCEL && r->convergence && r->convergence->nrows > 0) {
        stop = *err;
        rc = TS_OK;
    }
    if (rc == TS_OK)
        rc = ts_convergence_estimate(r->convergence, c->target, err);
    if (rc != TS_OK)
        return rc;
    if (stop.code) {
        *err = stop;
        return stop.code;
    }
    const ts_convergence *cv = r->convergence;
    int nok = 0;
    for (int i = 0; i < cv->nrows; i++) {
        nok += cv->rows[i].status == TS_OK;
        r->evaluations += cv->rows[i].evaluations;
    }
    /* Every run failed: nothing was learnt. */
    if (nok == 0)
        return ts_fail(err, TS_ECONV, "converge: every run failed (first: "
                       "%s)", cv->rows[0].message);
    /* The verdict of the finest runs: their notes. */
    int *idx = malloc((size_t)cv->nrows * sizeof *idx);
    if (!idx)
        return ts_fail(err, TS_ENOMEM, "converge: out of memory");
    ts_convergence_sorted_rows(cv, idx);
    const ts_conv_row *fin = &cv->rows[idx[cv->nrows - 1]];
    for (int i = 0; i < fin->trust.nnotes; i++)
        ts_trust_note(&r->trust, "finest run: %s", fin->trust.notes[i]);
    free(idx);
    if (cv->recommended < 0)
        ts_trust_note(&r->trust, "no trustworthy setting meets the target "
                                 "%.3g", cv->target);
    return TS_OK;
}

/* ---- the entry points -------------------------------------------------- */

/* open_loop: loops to open, opened at the trim. */
static int check_open_loop(const ts_system *sys, const ts_request *rq,
                           ts_err *err)
{
    if (!rq->setup.open_loop)
        return TS_OK;
    int loops = 0;
    for (int b = 0; b < sys->nbodies; b++)
        if (sys->bodies[b].vehicle)
            loops += sys->bodies[b].vehicle->nloops;
    if (loops == 0)
        return ts_fail(err, TS_EINVAL, "open_loop: no vehicle of the scene "
                       "has a controller loop to open");
    if (rq->kind == TS_ANALYSIS_SIMULATE &&
        rq->simulate.initial != TS_INITIAL_EQUILIBRIUM)
        return ts_fail(err, TS_EINVAL, "open_loop: the loops open at the "
                       "trim's outputs, so it needs the initial state "
                       "'equilibrium'");
    return TS_OK;
}

static int check_kind(const ts_system *sys, const ts_request *rq,
                      ts_err *err)
{
    int rc = check_open_loop(sys, rq, err);
    if (rc != TS_OK)
        return rc;
    if (rq->setup.refine &&
        (rc = equal_links_only(sys, "refine", "refining sets equal links on "
                               "every cable (remove link_lengths, or give "
                               "--links)", err)))
        return rc;
    switch (rq->kind) {
    case TS_ANALYSIS_EQUILIBRIUM:
        return TS_OK;
    case TS_ANALYSIS_MODES:
        if (rq->modes.count < 0)
            return ts_fail(err, TS_EINVAL, "count: expected a whole number "
                           ">= 1, got %d", rq->modes.count);
        if (!(rq->modes.eigen.target_hz >= 0) ||
            !isfinite(rq->modes.eigen.target_hz))
            return ts_fail(err, TS_EINVAL, "near: expected a frequency >= 0 "
                           "Hz, got %g Hz", rq->modes.eigen.target_hz);
        {
            /* The count and method against the number of states, before
             * the equilibrium runs. */
            ts_kernel *k = ts_kernel_alloc(sys, err);
            if (!k)
                return err && err->code ? err->code : TS_ENOMEM;
            int n = ts_kernel_nstate(k);
            ts_kernel_free(k);
            ts_eigen_opts o = modes_eigen_opts(&rq->modes, n);
            int rc = ts_eigen_check(n, &o, err);
            if (rc != TS_OK)
                ts_err_prefix(err, "count: ");
            return rc;
        }
    case TS_ANALYSIS_RESPONSE: {
        int input;
        ts_output out;
        return check_response(sys, &rq->response, rq->setup.open_loop,
                              &input, &out, err);
    }
    case TS_ANALYSIS_SIMULATE: {
        ts_sim_opts o;
        double transient;
        ts_output out;
        return check_simulate(sys, &rq->simulate, rq->setup.open_loop, &o,
                              &transient, &out, err);
    }
    case TS_ANALYSIS_CONVERGE:
        return TS_OK; /* checked on the base system (check_converge) */
    }
    return ts_fail(err, TS_EINVAL, "analysis: unknown kind %d",
                   (int)rq->kind);
}

int ts_analysis_check(const ts_system *sys, const ts_request *rq,
                      ts_err *err)
{
    ts_system *s = setup_system(sys, rq, err);
    if (!s)
        return err && err->code ? err->code : TS_ENOMEM;
    int rc = check_kind(s, rq, err);
    ts_system_free(s);
    if (rc == TS_OK && rq->kind == TS_ANALYSIS_CONVERGE)
        rc = check_converge(sys, rq, err);
    return rc;
}

/* With a towing vehicle, the steady motion the run starts from is
 * solved, not the scene's tow.speed and tow.turn_rate (their starting
 * values): the estimate solves the same equilibrium (the request's
 * options, no progress) and puts its speed and turn rate into s. *speed
 * is the solved speed, NaN when there is no towing vehicle or its trim
 * did not converge (then the scene's stay). */
static void cost_trim(ts_system *s, const ts_request *rq, double *speed)
{
    *speed = NAN;
    if (s->tow.vehicle < 0)
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(s, NULL) : NULL;
    ts_equilibrium_opts eo = rq->setup.equilibrium;
    eo.progress = NULL;
    eo.progress_data = NULL;
    if (eq && ts_equilibrium_solve(k, &eo, eq, NULL) == TS_OK &&
        eq->converged && isfinite(eq->speed)) {
        *speed = s->tow.speed = eq->speed;
        s->tow.turn_rate = eq->turn_rate;
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
}

int ts_analysis_cost(const ts_system *sys, const ts_request *rq,
                     ts_cost *e, ts_err *err)
{
    memset(e, 0, sizeof *e);
    if (rq->kind != TS_ANALYSIS_SIMULATE && rq->kind != TS_ANALYSIS_MODES)
        return TS_OK;
    ts_system *s = setup_system(sys, rq, err);
    if (!s)
        return err && err->code ? err->code : TS_ENOMEM;
    int rc = TS_OK;
    if (rq->kind == TS_ANALYSIS_SIMULATE && !rq->simulate.linear) {
        ts_sim_opts o;
        double transient, trimmed;
        sim_resolve(&rq->simulate, &o, &transient);
        cost_trim(s, rq, &trimmed);
        /* With a sea, its realisation is part of the excitation (a
         * towing vehicle meets it at its solved speed, as in the run). */
        ts_excitation *ex = NULL;
        if (rq->simulate.sea.sea) {
            ts_seaway w;
            ts_sea_realisation real;
            rc = sea_excitation(s, &rq->simulate, trimmed, NULL, NULL, &w, &real, &ex,
                                err);
        }
        if (rc == TS_OK)
            rc = ts_cost_simulate(s, ex ? ex : rq->simulate.excitation, &o,
                                  e, err);
        ts_excitation_free(ex);
        size_t len = strlen(e->what);
        if (rc == TS_OK && s->tow.vehicle >= 0)
            snprintf(e->what + len, sizeof e->what - len, isfinite(trimmed)
                     ? "; at the towing vehicle's solved speed %.4g m/s"
                     : "; at the scene's speed %.4g m/s (the towing "
                       "vehicle's trim did not converge)", s->tow.speed);
    } else if (rq->kind == TS_ANALYSIS_MODES) {
        ts_kernel *k = ts_kernel_alloc(s, err);
        int n = k ? ts_kernel_nstate(k) : 0;
        ts_kernel_free(k);
        ts_eigen_opts o = modes_eigen_opts(&rq->modes, n);
        rc = k ? ts_cost_modes(s, n, ts_eigen_method(n, &o), e, err)
               : (err && err->code ? err->code : TS_ENOMEM);
    }
    ts_system_free(s);
    /* The discretisation estimate runs the analysis again at a half and
     * a quarter of the links (doc/accuracy.md): a dense eigen analysis
     * at least 1/8 + 1/64 more, a sparse one (no flops counted) 1/2 +
     * 1/4, an explicit simulation 1/4 + 1/16 (its steps and its
     * evaluations each halve with the links). */
    int estimate = rq->setup.discretisation_error || rq->setup.refine;
    if (rc == TS_OK && estimate && e->seconds > 0) {
        double f = rq->kind != TS_ANALYSIS_MODES ? 1.0 / 4 + 1.0 / 16
                   : e->flops > 0                ? 1.0 / 8 + 1.0 / 64
                                                 : 1.0 / 2 + 1.0 / 4;
        e->seconds *= 1 + f;
        e->evaluations *= 1 + f;
        e->flops *= 1 + f;
        size_t len = strlen(e->what);
        snprintf(e->what + len, sizeof e->what - len, "%s",
                 len + 60 < sizeof e->what
                     ? " (with the discretisation estimate's runs)"
                     : "");
    }
    return rc;
}

/* One run of the analysis at the request's settings, judged. */
static int run_once(const ts_system *sys, const ts_request *rq,
                    ts_result **out, ts_err *err)
{
    double t0 = tsi_wall_now();
    ts_err e = {0};
    *out = result_alloc(rq->kind, err);
    if (!*out)
        return TS_ENOMEM;
    ts_result *r = *out;
    r->sys = setup_system(sys, rq, &e);
    int rc = r->sys ? check_kind(r->sys, rq, &e) : (e.code ? e.code
                                                           : TS_ENOMEM);
    if (rc == TS_OK && rq->kind == TS_ANALYSIS_CONVERGE)
        rc = check_converge(sys, rq, &e);
    if (rc == TS_OK) {
        switch (rq->kind) {
        case TS_ANALYSIS_EQUILIBRIUM:
            rc = pipeline_equilibrium(r, rq, &e);
            break;
        case TS_ANALYSIS_MODES: rc = pipeline_modes(r, rq, &e); break;
        case TS_ANALYSIS_RESPONSE: rc = pipeline_response(r, rq, &e); break;
        case TS_ANALYSIS_SIMULATE: rc = pipeline_simulate(r, rq, &e); break;
        case TS_ANALYSIS_CONVERGE:
            rc = pipeline_converge(r, rq, sys, &e);
            break;
        }
    }
    if (r->sys && rq->kind != TS_ANALYSIS_CONVERGE)
        tow_notes(r);
    if (rc == TS_OK && rq->kind != TS_ANALYSIS_CONVERGE)
        rc = accuracy_stage(r, rq, &e);
    return finish(r, rc, &e, err, t0);
}

int ts_analysis_run(const ts_system *sys, const ts_request *rq,
                    ts_result **out, ts_err *err)
{
    double t0 = tsi_wall_now();
    int rc = run_once(sys, rq, out, err);
    ts_result *r = *out;
    /* --refine: rerun with the links the error model says meet the
     * accuracy. */
    int first = r ? r->accuracy.links[0] : 0;
    double wall = r && isfinite(r->accuracy.wall_s) ? r->accuracy.wall_s
                                                   : 0.0;
    long evals = r ? r->accuracy.evaluations : 0;
    for (int round = 0; rq->setup.refine && rc == TS_OK &&
                        round < TS_REFINE_ROUNDS && r->accuracy.met == 0;
         round++) {
        int now = r->accuracy.links[0];
        int next = r->accuracy.links_needed;
        if (next <= now)
            next = now + 1;
        if (next > TS_REFINE_GROWTH * now)
            next = TS_REFINE_GROWTH * now;
        if (next > TS_MAX_LINKS)
            next = TS_MAX_LINKS;
        if (next <= now)
            break;
        ts_request rq2 = *rq;
        rq2.setup.links = next;
        rq2.setup.equilibrium.guess = NULL; /* it fits the links before */
        ts_result *r2 = NULL;
        ts_err e2 = {0};
        int rc2 = run_once(sys, &rq2, &r2, &e2);
        if (!r2)
            break;
        /* The coarser result is kept as its cost. */
        wall += r->wall_s;
        evals += r->evaluations;
        if (rc2 != TS_OK) {
            ts_trust_note(&r->trust, "--refine: the run at %d links failed "
                          "(%s); the result is that at %d links", next,
                          e2.msg, now);
            ts_result_free(r2);
            break;
        }
        ts_result_free(r);
        *out = r = r2;
        r->accuracy.refinements = round + 1;
        r->accuracy.refined_from = first;
    }
    if (r && r->accuracy.refinements > 0) {
        r->accuracy.wall_s = (isfinite(r->accuracy.wall_s)
                                  ? r->accuracy.wall_s
                                  : 0.0) + wall;
        r->accuracy.evaluations += evals;
        r->wall_s = tsi_wall_now() - t0;
        if (r->accuracy.met == 0)
            ts_trust_note(&r->trust, "--refine: %d rerun%s from %d to %d "
                          "links did not meet the accuracy (at most %d "
                          "reruns, each at most %d times the links)",
                          r->accuracy.refinements,
                          r->accuracy.refinements == 1 ? "" : "s", first,
                          r->accuracy.links[0], TS_REFINE_ROUNDS,
                          TS_REFINE_GROWTH);
    }
    return rc;
}
