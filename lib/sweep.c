/* sweep.c: one analysis over a grid of scene values (towstab/sweep.h,
 * doc/sweep.md).
 *
 * Layout: points are numbered with the last axis fastest; each line along
 * the last axis is cut into ceil(n / chain) chains of near-equal length,
 * chain k of a line holding points [floor(k n / m), floor((k + 1) n / m))
 * of it (m chains). A chain runs its points in order: the first from a
 * cold start, each next one from the previous one's link directions
 * (continuation; towstab/equilibrium.h opts.guess). Every point is the
 * pipeline of towstab/analysis.h on the request with the point's values
 * set by path (ts_setup_set), so it is what the single command computes.
 *
 * Determinism: a chain's results depend only on the chain (its points and
 * their order), not on which thread or process runs it, so the table is
 * the same for any number of threads or processes. Two things are fixed
 * for that: the linearization inside a point runs on one thread (its
 * error norms are sums whose order would follow the thread count), and
 * no point sees another chain's state.
 *
 * Parallelism: OpenMP over chains (dynamic schedule, one chain at a
 * time); the callbacks (progress, on_chain) are called inside one
 * critical section. A process's share of the chains (part modulo nparts)
 * is how several processes (MPI, in tools/) split a sweep.
 *
 * The stability boundary: crossings between neighbouring grid points, one
 * unstable (ts_eigen verdict TS_UNSTABLE: max Re(lambda) above its error
 * bound) and one completed and not unstable, are bisected along their
 * axis on the verdict of a modes run at the middle of the bracket, each
 * run continuing from the previous one's equilibrium; a crossing is
 * itself a chain.
 */
#include "towstab/sweep.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "clock.h"
#include "towstab/param.h"

void ts_sweep_free(ts_sweep *s)
{
    if (!s)
        return;
    for (int a = 0; a < s->spec.naxes; a++)
        free(s->spec.axes[a].values);
    free(s->columns);
    free(s->points);
    free(s->values);
    free(s->errors);
    free(s->crossings);
    free(s);
}

/* ---- layout ------------------------------------------------------------- */

void ts_sweep_point_index(const ts_sweep *s, int p, int idx[])
{
    for (int a = s->spec.naxes - 1; a >= 0; a--) {
        int n = s->spec.axes[a].n;
        idx[a] = p % n;
        p /= n;
    }
}

/* Chains per line. */
static int chains_per_line(const ts_sweep *s)
{
    int n = s->spec.axes[s->spec.naxes - 1].n;
    return (n + s->chain_len - 1) / s->chain_len;
}

void ts_sweep_chain_points(const ts_sweep *s, int c, int *first, int *n)
{
    int nl = s->spec.axes[s->spec.naxes - 1].n, m = chains_per_line(s);
    int line = c / m, k = c % m;
    int lo = (int)((long)k * nl / m), hi = (int)((long)(k + 1) * nl / m);
    *first = line * nl + lo;
    *n = hi - lo;
}

int ts_sweep_chain_of(const ts_sweep *s, int p)
{
    int nl = s->spec.axes[s->spec.naxes - 1].n, m = chains_per_line(s);
    int line = p / nl, j = p % nl;
    /* The k with floor(k nl / m) <= j < floor((k + 1) nl / m). */
    int k = (int)(((long)j * m) / nl);
    while (k > 0 && (long)k * nl / m > j)
        k--;
    while ((long)(k + 1) * nl / m <= j)
        k++;
    return line * m + k;
}

int ts_sweep_column_find(const ts_sweep *s, const char *name)
{
    for (int c = 0; c < s->ncolumns; c++)
        if (!strcmp(s->columns[c].name, name))
            return c;
    return -1;
}

/* Add a column unless one of that name exists. */
static void add_column(ts_sweep *s, const char *name, const char *unit)
{
    if (ts_sweep_column_find(s, name) >= 0)
        return;
    ts_sweep_column *c = &s->columns[s->ncolumns++];
    snprintf(c->name, sizeof c->name, "%s", name);
    snprintf(c->unit, sizeof c->unit, "%s", unit);
}

/* The request of the point with grid coordinates idx (value `at` along
 * axis `axis` instead, when axis >= 0: a bisection run). */
static int point_request(const ts_sweep *s, const int *idx, int axis,
                         double at, ts_request *rq, ts_err *err)
{
    *rq = s->spec.rq;
    rq->progress = NULL;
    rq->progress_data = NULL;
    rq->setup.equilibrium.guess = NULL;
    /* One thread inside a point: see "Determinism" above. */
    rq->modes.linearize.threads = 1;
    for (int a = 0; a < s->spec.naxes; a++) {
        const ts_sweep_axis *ax = &s->spec.axes[a];
        double v = a == axis ? at : ax->values[idx[a]];
        int rc = ts_setup_set(&rq->setup, ax->path, v, err);
        if (rc)
            return rc;
    }
    return TS_OK;
}

/* tow.speed and tow.turn_rate of a scene with a towing vehicle are only
 * the start values of its equilibrium's V and Omega, which it solves
 * (doc/towing-vehicle.md section 1): the speed from its propulsion, the
 * turn rate at its deflections unless `turn_by` names the surface
 * deflected to turn at tow.turn_rate. Varying one would give the same
 * point at every value: refused, naming the key that sets it. */
static int solved_by_towing(const ts_system *sys, const char *canon,
                            ts_err *err)
{
    if (sys->tow.vehicle < 0)
        return TS_OK;
    const ts_body *b = &sys->bodies[sys->tow.vehicle];
    if (!strcmp(canon, "tow.speed")) {
        ts_propulsion_type t = b->vehicle->propulsion.type;
        const char *key = t == TS_PROP_POWER   ? "power"
                          : t == TS_PROP_SPEED ? "speed"
                                               : "thrust";
        const char *what =
            t == TS_PROP_POWER   ? "its power: the speed is solved at it"
            : t == TS_PROP_SPEED ? "its speed controller's set speed, which "
                                   "the steady speed equals"
                                 : "its thrust: the speed is solved at it";
        return ts_fail(err, TS_EINVAL, "vary: tow.speed: the towing "
                       "vehicle '%s' solves its speed from its propulsion, "
                       "and tow.speed is only the solve's start value "
                       "(every point would be the same); vary "
                       "towing_vehicle.propulsion.%s (%s)", b->name, key,
                       what);
    }
    if (!strcmp(canon, "tow.turn_rate") && sys->tow.turn_surface < 0)
        return ts_fail(err, TS_EINVAL, "vary: tow.turn_rate: the towing "
                       "vehicle '%s' solves its turn rate at its control "
                       "deflections, and tow.turn_rate is only the solve's "
                       "start value (every point would be the same); give "
                       "it `turn_by: <rudder>` in the scene (the rudder's "
                       "deflection is then solved at each turn rate), or "
                       "vary towing_vehicle.components.<rudder>.deflection",
                       b->name);
    return TS_OK;
}

/* Path ends in ".links". */
static int is_links(const char *path)
{
    size_t n = strlen(path);
    return n > 6 && !strcmp(path + n - 6, ".links");
}

static int check_spec(const ts_system *sys, const ts_sweep_spec *sp,
                      ts_err *err)
{
    ts_analysis_kind k = sp->rq.kind;
    if (k != TS_ANALYSIS_EQUILIBRIUM && k != TS_ANALYSIS_MODES &&
        k != TS_ANALYSIS_RESPONSE && k != TS_ANALYSIS_SIMULATE)
        return ts_fail(err, TS_EINVAL, "analysis: a sweep runs equilibrium, "
                       "modes, response or simulate, not %s",
                       ts_analysis_name(k));
    if (sp->naxes < 1 || sp->naxes > TS_SWEEP_MAX_AXES)
        return ts_fail(err, TS_EINVAL, "vary: expected 1 to %d values to "
                       "vary, got %d", TS_SWEEP_MAX_AXES, sp->naxes);
    if (sp->chain < 0)
        return ts_fail(err, TS_EINVAL, "chain: expected a whole number >= 1 "
                       "(0: %d), got %d", TS_SWEEP_CHAIN, sp->chain);
    if (sp->threads < 0)
        return ts_fail(err, TS_EINVAL, "jobs: expected a whole number >= 1 "
                       "(0: every core), got %d", sp->threads);
    if (!(sp->boundary_rtol >= 0 && sp->boundary_rtol < 1))
        return ts_fail(err, TS_EINVAL, "boundary_tol: expected a fraction of "
                       "the grid step in (0, 1), got %g", sp->boundary_rtol);
    if (sp->boundary && k != TS_ANALYSIS_MODES)
        return ts_fail(err, TS_EINVAL, "boundary: the stability boundary "
                       "needs the modes analysis, not %s",
                       ts_analysis_name(k));
    long np = 1;
    for (int a = 0; a < sp->naxes; a++) {
        const ts_sweep_axis *ax = &sp->axes[a];
        char canon[TS_PARAM_PATH_MAX], unit[TS_PARAM_UNIT_MAX];
        int rc = ts_param_canonical(ax->path, canon, sizeof canon, err);
        if (!rc)
            rc = ts_param_unit(sys, canon, unit, sizeof unit, err);
        if (rc) {
            ts_err_prefix(err, "vary: ");
            return rc;
        }
        if (ax->n < 1 || !ax->values)
            return ts_fail(err, TS_EINVAL, "vary: %s: expected at least one "
                           "value", canon);
        np *= ax->n;
        if (np > TS_SWEEP_MAX_POINTS)
            return ts_fail(err, TS_EINVAL, "vary: more than %d points",
                           TS_SWEEP_MAX_POINTS);
        for (int b = 0; b < a; b++) {
            char other[TS_PARAM_PATH_MAX];
            ts_param_canonical(sp->axes[b].path, other, sizeof other, NULL);
            if (!strcmp(other, canon))
                return ts_fail(err, TS_EINVAL, "vary: %s is varied twice",
                               canon);
        }
        const ts_setup *su = &sp->rq.setup;
        for (int i = 0; i < su->nsets; i++) {
            char other[TS_PARAM_PATH_MAX];
            if (ts_param_canonical(su->sets[i].path, other, sizeof other,
                                   NULL) == TS_OK &&
                !strcmp(other, canon))
                return ts_fail(err, TS_EINVAL, "vary: %s is also set (set); "
                               "give it once", canon);
        }
        if ((!strcmp(canon, "tow.speed") && !isnan(su->speed)) ||
            (!strcmp(canon, "tow.turn_rate") && !isnan(su->turn_rate)))
            return ts_fail(err, TS_EINVAL, "vary: %s is also given as %s; "
                           "give it once", canon, canon + 4);
        if ((rc = solved_by_towing(sys, canon, err)))
            return rc;
        if (is_links(canon) && su->links > 0)
            return ts_fail(err, TS_EINVAL, "vary: %s and links (every cable) "
                           "both set links; give one", canon);
        /* Every value against the key's limits and the whole system. */
        for (int i = 0; i < ax->n; i++) {
            ts_system *c = ts_system_copy(sys, err);
            if (!c)
                return err && err->code ? err->code : TS_ENOMEM;
            rc = ts_param_set(c, canon, ax->values[i], err);
            if (!rc)
                rc = ts_system_build(c, err);
            ts_system_free(c);
            if (rc) {
                ts_err_prefix(err, "vary: value %d of %s: ", i + 1, canon);
                return rc;
            }
        }
    }
    return TS_OK;
}

/* "<output>.peak_gain", "<output>.peak_hz": the largest gain of a
 * response and its frequency. */
static void peak_name(char *buf, size_t size, const ts_request *rq,
                      const char *what)
{
    snprintf(buf, size, "%.70s.peak_%s", rq->response.output, what);
}

/* The columns: the equilibrium's key values, the analysis' own, and the
 * stability margin (modes) or the response's peak. */
static int lay_out_columns(ts_sweep *s, const ts_request *rq0, ts_err *err)
{
    ts_request eqr = *rq0;
    eqr.kind = TS_ANALYSIS_EQUILIBRIUM;
    ts_value *eqv = NULL, *own = NULL;
    int neq = 0, nown = 0;
    int rc = ts_analysis_value_names(s->sys, &eqr, &eqv, &neq, err);
    if (!rc && s->kind != TS_ANALYSIS_EQUILIBRIUM)
        rc = ts_analysis_value_names(s->sys, rq0, &own, &nown, err);
    if (!rc) {
        s->columns = calloc((size_t)(neq + nown + 2), sizeof *s->columns);
        if (!s->columns)
            rc = ts_fail(err, TS_ENOMEM, "sweep: out of memory");
    }
    for (int i = 0; !rc && i < neq; i++)
        add_column(s, eqv[i].name, eqv[i].unit);
    for (int i = 0; !rc && i < nown; i++)
        add_column(s, own[i].name, own[i].unit);
    if (!rc && s->kind == TS_ANALYSIS_MODES) {
        add_column(s, TS_SWEEP_MAX_REAL, "1/s");
        add_column(s, TS_SWEEP_MAX_REAL_FREQ, "Hz");
    }
    if (!rc && s->kind == TS_ANALYSIS_RESPONSE) {
        char name[TS_VALUE_NAME_MAX];
        peak_name(name, sizeof name, rq0, "gain");
        add_column(s, name, "");
        peak_name(name, sizeof name, rq0, "hz");
        add_column(s, name, "Hz");
    }
    free(eqv);
    free(own);
    return rc;
}

ts_sweep *ts_sweep_alloc(const ts_system *sys, const ts_sweep_spec *spec,
                         ts_err *err)
{
    if (check_spec(sys, spec, err))
        return NULL;
    ts_sweep *s = calloc(1, sizeof *s);
    if (!s) {
        ts_fail(err, TS_ENOMEM, "sweep: out of memory");
        return NULL;
    }
    s->spec = *spec;
    s->sys = sys;
    s->kind = spec->rq.kind;
    s->npoints = 1;
    int rc = TS_OK;
    for (int a = 0; a < spec->naxes; a++) {
        ts_sweep_axis *ax = &s->spec.axes[a];
        ax->values = NULL;
    }
    for (int a = 0; a < spec->naxes && !rc; a++) {
        ts_sweep_axis *ax = &s->spec.axes[a];
        ax->values = malloc((size_t)ax->n * sizeof(double));
        if (!ax->values) {
            rc = ts_fail(err, TS_ENOMEM, "sweep: out of memory");
            break;
        }
        memcpy(ax->values, spec->axes[a].values,
               (size_t)ax->n * sizeof(double));
        ts_param_canonical(spec->axes[a].path, ax->path, sizeof ax->path,
                           NULL);
        ts_param_unit(sys, ax->path, ax->unit, sizeof ax->unit, NULL);
        s->npoints *= ax->n;
    }
    s->chain_len = spec->chain > 0 ? spec->chain : TS_SWEEP_CHAIN;
    if (!rc)
        s->nchains = s->npoints / s->spec.axes[spec->naxes - 1].n *
                     chains_per_line(s);
    /* The request at the first point, checked as the command checks it. */
    ts_request rq0;
    int idx0[TS_SWEEP_MAX_AXES] = {0};
    if (!rc)
        rc = point_request(s, idx0, -1, 0, &rq0, err);
    if (!rc)
        rc = ts_analysis_check(sys, &rq0, err);
    if (!rc)
        rc = lay_out_columns(s, &rq0, err);
    if (!rc) {
        size_t n = (size_t)s->npoints;
        s->points = calloc(n, sizeof *s->points);
        s->values = malloc(n * (size_t)s->ncolumns * sizeof *s->values);
        s->errors = malloc(n * (size_t)s->ncolumns * sizeof *s->errors);
        if (!s->points || !s->values || !s->errors)
            rc = ts_fail(err, TS_ENOMEM, "sweep: out of memory for %d points",
                         s->npoints);
    }
    if (rc) {
        ts_sweep_free(s);
        return NULL;
    }
    for (size_t i = 0; i < (size_t)s->npoints * (size_t)s->ncolumns; i++) {
        s->values[i] = NAN;
        s->errors[i].discretisation = NAN;
        s->errors[i].solver = NAN;
    }
    for (int p = 0; p < s->npoints; p++)
        s->points[p].verdict = -1;
    return s;
}

/* The stop flag, shared by the threads of a run. */
static int get_stop(const ts_sweep *s)
{
    int v;
#ifdef _OPENMP
#pragma omp atomic read
#endif
    v = s->stop;
    return v;
}

static void set_stop(ts_sweep *s)
{
#ifdef _OPENMP
#pragma omp atomic write
#endif
    s->stop = 1;
}

/* ---- one point ------------------------------------------------------------ */

/* Set column `name` of point p (when the sweep has it). */
static void put(ts_sweep *s, int p, const char *name, double value,
                double disc, double solver)
{
    int c = ts_sweep_column_find(s, name);
    if (c < 0)
        return;
    size_t i = (size_t)p * (size_t)s->ncolumns + (size_t)c;
    s->values[i] = value;
    s->errors[i].discretisation = disc;
    s->errors[i].solver = solver;
}

/* Record result r (status rc) as point p's. */
static int record(ts_sweep *s, int p, const ts_result *r, int rc, int warm,
                  ts_err *err)
{
    ts_sweep_point *pt = &s->points[p];
    pt->status = rc;
    snprintf(pt->error, sizeof pt->error, "%s", r->error);
    pt->trust = r->trust;
    pt->warm = warm;
    pt->evaluations = r->evaluations;
    pt->iterations = r->eq ? r->eq->iterations : 0;
    pt->wall_s = r->wall_s;
    ts_margin mg;
    int has_margin = ts_result_margin(r, &mg) && rc == TS_OK;
    pt->verdict = has_margin ? mg.verdict : -1;
    for (size_t c = 0; c < (size_t)s->ncolumns; c++) {
        size_t i = (size_t)p * (size_t)s->ncolumns + c;
        s->values[i] = NAN;
        s->errors[i].discretisation = s->errors[i].solver = NAN;
    }
    ts_value *eqv = NULL;
    int neq = 0;
    int vrc = ts_result_equilibrium_values(r, &eqv, &neq, err);
    if (vrc)
        return vrc;
    for (int i = 0; i < neq; i++)
        put(s, p, eqv[i].name, eqv[i].value, eqv[i].error.discretisation,
            eqv[i].error.solver);
    free(eqv);
    /* The result's own key values last: for an equilibrium they are the
     * same names, with whatever estimates the pipeline made of them. */
    for (int i = 0; i < r->nvalues; i++)
        put(s, p, r->values[i].name, r->values[i].value,
            r->values[i].error.discretisation, r->values[i].error.solver);
    if (has_margin) {
        put(s, p, TS_SWEEP_MAX_REAL, mg.max_real, mg.error.discretisation,
            mg.error.solver);
        put(s, p, TS_SWEEP_MAX_REAL_FREQ, mg.freq_hz, NAN, NAN);
    }
    if (r->response && rc == TS_OK) {
        const ts_response *res = r->response;
        int k = 0;
        for (int j = 1; j < res->npoints; j++)
            if (res->magnitude[j] > res->magnitude[k])
                k = j;
        char name[TS_VALUE_NAME_MAX];
        peak_name(name, sizeof name, &s->spec.rq, "gain");
        put(s, p, name, res->magnitude[k], NAN, NAN);
        peak_name(name, sizeof name, &s->spec.rq, "hz");
        put(s, p, name, res->freq_hz[k], NAN, NAN);
    }
    pt->state = TS_SWEEP_DONE;
    return TS_OK;
}

/* The progress callback with the chains done; inside the critical
 * section ts_sweep_callbacks. */
static void call_progress(ts_sweep *s)
{
    if (get_stop(s) || !s->spec.progress)
        return;
    ts_progress sp = {"sweep", (double)s->chains_done,
                      (double)(s->nchains + s->ncrossings), "chains"};
    if (s->spec.progress(&sp, s->spec.progress_data) != 0)
        set_stop(s);
}

/* Polled by long runs inside a point: the sweep's stop flag, set by its
 * progress callback (called here too, so that a signal reaches a long
 * simulation). */
static int poll_stop(const ts_progress *pr, void *data)
{
    (void)pr;
    ts_sweep *s = data;
    int stop;
#ifdef _OPENMP
#pragma omp critical(ts_sweep_callbacks)
#endif
    call_progress(s);
    stop = get_stop(s);
    return stop;
}

/* Run request rq (a point of chain, or a bisection run) with the guess
 * `dir` (NULL: cold; its nlinks must match), keeping the equilibrium's
 * directions in *next (reallocated) for the next run. */
static int run_point(ts_sweep *s, ts_request *rq, double **dir, int *ndir,
                     int warm, ts_result **out, ts_err *err)
{
    rq->setup.equilibrium.guess = warm && *dir ? *dir : NULL;
    if (s->spec.progress) {
        rq->progress = poll_stop;
        rq->progress_data = s;
    }
    int rc = ts_analysis_run(s->sys, rq, out, err);
    const ts_result *r = *out;
    if (!r)
        return rc;
    /* A guess must fit the next system (equal links). */
    if (r->eq && r->eq->converged) {
        int n = 3 * r->eq->nlinks;
        if (n != *ndir) {
            double *d = realloc(*dir, (size_t)n * sizeof **dir);
            if (!d)
                return ts_fail(err, TS_ENOMEM, "sweep: out of memory");
            *dir = d;
            *ndir = n;
        }
        memcpy(*dir, r->eq->directions, (size_t)n * sizeof **dir);
    } else {
        free(*dir);
        *dir = NULL;
        *ndir = 0;
    }
    return rc;
}

/* Continuation is possible: not a cold-start sweep, no varied link
 * count. */
static int can_continue(const ts_sweep *s)
{
    if (s->chain_len <= 1)
        return 0;
    for (int a = 0; a < s->spec.naxes; a++)
        if (is_links(s->spec.axes[a].path))
            return 0;
    return 1;
}

int ts_sweep_run_chain(ts_sweep *s, int c, ts_err *err)
{
    if (c < 0 || c >= s->nchains)
        return ts_fail(err, TS_EINVAL, "sweep: no chain %d (0 to %d)", c,
                       s->nchains - 1);
    int first, n;
    ts_sweep_chain_points(s, c, &first, &n);
    double *dir = NULL;
    int ndir = 0, rc = TS_OK, cont = can_continue(s);
    for (int p = first; p < first + n && rc == TS_OK; p++) {
        int idx[TS_SWEEP_MAX_AXES];
        ts_sweep_point_index(s, p, idx);
        ts_request rq;
        ts_err perr = {0};
        rc = point_request(s, idx, -1, 0, &rq, err);
        if (rc)
            break;
        int warm = cont && p > first && dir != NULL;
        ts_result *r = NULL;
        int prc = run_point(s, &rq, &dir, &ndir, warm, &r, &perr);
        if (!r) {
            rc = ts_fail(err, prc, "%s", perr.msg);
            break;
        }
        if (prc == TS_ECANCEL || get_stop(s)) {
            rc = ts_fail(err, TS_ECANCEL, "sweep: stopped on request");
        } else if (prc == TS_ENOMEM) {
            rc = ts_fail(err, prc, "%s", perr.msg);
        } else {
            rc = record(s, p, r, prc, warm, err);
        }
        ts_result_free(r);
    }
    free(dir);
    if (rc != TS_OK)
        for (int p = first; p < first + n; p++)
            s->points[p].state = TS_SWEEP_PENDING;
    return rc;
}

/* Callbacks after a finished chain (or crossing), one thread at a time. */
static void chain_done(ts_sweep *s, int c)
{
#ifdef _OPENMP
#pragma omp critical(ts_sweep_callbacks)
#endif
    {
        s->chains_done++;
        if (s->spec.on_chain &&
            s->spec.on_chain(s, c, s->spec.on_chain_data) != 0)
            set_stop(s);
        call_progress(s);
    }
}

static int chain_pending(const ts_sweep *s, int c)
{
    int first, n;
    ts_sweep_chain_points(s, c, &first, &n);
    for (int p = first; p < first + n; p++)
        if (s->points[p].state != TS_SWEEP_DONE)
            return 1;
    return 0;
}

static int threads_of(const ts_sweep *s)
{
    int nt = 1;
#ifdef _OPENMP
    nt = s->spec.threads > 0 ? s->spec.threads : omp_get_max_threads();
#else
    (void)s;
#endif
    return nt < 1 ? 1 : nt;
}

/* Run tasks todo[n] (chains, or crossings when `crossings`) over the
 * sweep's threads. */
static int run_tasks(ts_sweep *s, const int *todo, int n, int crossings,
                     ts_err *err);

/* Run this process's share (part modulo nparts) of the tasks not done:
 * the chains, or the crossings. */
static int run_share(ts_sweep *s, int crossings, int part, int nparts,
                     ts_err *err)
{
    if (nparts < 1 || part < 0 || part >= nparts)
        return ts_fail(err, TS_EINVAL, "sweep: part %d of %d", part, nparts);
    int ntasks = crossings ? s->ncrossings : s->nchains;
    int *todo = malloc((size_t)(ntasks > 0 ? ntasks : 1) * sizeof *todo);
    if (!todo)
        return ts_fail(err, TS_ENOMEM, "sweep: out of memory");
    int n = 0;
    s->chains_done = crossings ? s->nchains : 0;
    for (int i = 0; i < ntasks; i++) {
        int done = crossings ? s->crossings[i].done : !chain_pending(s, i);
        if (done)
            s->chains_done++;
        else if (i % nparts == part)
            todo[n++] = i;
    }
    int rc = run_tasks(s, todo, n, crossings, err);
    free(todo);
    return rc;
}

int ts_sweep_run(ts_sweep *s, int part, int nparts, ts_err *err)
{
    return run_share(s, 0, part, nparts, err);
}

/* ---- the stability boundary ------------------------------------------ */

/* The point one step from p along axis a (dir +-1), or -1. */
static int neighbour(const ts_sweep *s, int p, int a, int dir)
{
    int idx[TS_SWEEP_MAX_AXES];
    ts_sweep_point_index(s, p, idx);
    int j = idx[a] + dir;
    if (j < 0 || j >= s->spec.axes[a].n)
        return -1;
    int stride = 1;
    for (int b = s->spec.naxes - 1; b > a; b--)
        stride *= s->spec.axes[b].n;
    return p + dir * stride;
}

static int usable(const ts_sweep_point *pt)
{
    return pt->state == TS_SWEEP_DONE && pt->status == TS_OK &&
           pt->verdict >= 0;
}

int ts_sweep_crossings_find(ts_sweep *s, ts_err *err)
{
    free(s->crossings);
    s->crossings = NULL;
    s->ncrossings = 0;
    if (!s->spec.boundary)
        return TS_OK;
    for (int p = 0; p < s->npoints; p++)
        if (s->points[p].state != TS_SWEEP_DONE)
            return ts_fail(err, TS_EINVAL, "boundary: point %d of the grid "
                           "is not done", p);
    int cap = 16;
    s->crossings = calloc((size_t)cap, sizeof *s->crossings);
    if (!s->crossings)
        return ts_fail(err, TS_ENOMEM, "sweep: out of memory");
    int mr = ts_sweep_column_find(s, TS_SWEEP_MAX_REAL);
    int mf = ts_sweep_column_find(s, TS_SWEEP_MAX_REAL_FREQ);
    for (int p = 0; p < s->npoints; p++) {
        const ts_sweep_point *pt = &s->points[p];
        if (!usable(pt) || pt->verdict != TS_UNSTABLE)
            continue;
        for (int a = 0; a < s->spec.naxes; a++)
            for (int dir = -1; dir <= 1; dir += 2) {
                int q = neighbour(s, p, a, dir);
                if (q < 0 || !usable(&s->points[q]) ||
                    s->points[q].verdict == TS_UNSTABLE)
                    continue;
                if (s->ncrossings == cap) {
                    ts_sweep_crossing *x = realloc(
                        s->crossings, 2 * (size_t)cap * sizeof *x);
                    if (!x)
                        return ts_fail(err, TS_ENOMEM, "sweep: out of "
                                       "memory");
                    s->crossings = x;
                    cap *= 2;
                }
                ts_sweep_crossing *x = &s->crossings[s->ncrossings++];
                memset(x, 0, sizeof *x);
                int iq[TS_SWEEP_MAX_AXES], ip[TS_SWEEP_MAX_AXES];
                ts_sweep_point_index(s, q, iq);
                ts_sweep_point_index(s, p, ip);
                x->axis = a;
                x->from = q;
                x->to = p;
                x->stable = s->spec.axes[a].values[iq[a]];
                x->unstable = s->spec.axes[a].values[ip[a]];
                x->value = 0.5 * (x->stable + x->unstable);
                x->max_real_stable =
                    s->values[(size_t)q * (size_t)s->ncolumns + (size_t)mr];
                x->max_real_unstable =
                    s->values[(size_t)p * (size_t)s->ncolumns + (size_t)mr];
                x->freq_hz = s->values[(size_t)p * (size_t)s->ncolumns +
                                       (size_t)mf];
            }
    }
    return TS_OK;
}

/* Bisect crossing i. */
static int run_crossing(ts_sweep *s, int i, ts_err *err)
{
    ts_sweep_crossing *x = &s->crossings[i];
    double rtol = s->spec.boundary_rtol > 0 ? s->spec.boundary_rtol
                                            : TS_SWEEP_BOUNDARY_RTOL;
    double step = fabs(x->unstable - x->stable);
    int idx[TS_SWEEP_MAX_AXES];
    ts_sweep_point_index(s, x->from, idx);
    double *dir = NULL, t0 = tsi_wall_now();
    int ndir = 0, rc = TS_OK, cont = can_continue(s);
    x->status = TS_OK;
    x->error[0] = '\0';
    while (fabs(x->unstable - x->stable) > rtol * step &&
           x->runs < TS_SWEEP_BOUNDARY_MAX_RUNS) {
        double mid = 0.5 * (x->stable + x->unstable);
        ts_request rq;
        rc = point_request(s, idx, x->axis, mid, &rq, err);
        if (rc)
            break;
        ts_result *r = NULL;
        ts_err perr = {0};
        int prc = run_point(s, &rq, &dir, &ndir, cont && x->runs > 0, &r,
                            &perr);
        if (!r) {
            rc = ts_fail(err, prc, "%s", perr.msg);
            break;
        }
        x->runs++;
        x->evaluations += r->evaluations;
        if (prc == TS_ECANCEL || get_stop(s)) {
            ts_result_free(r);
            rc = ts_fail(err, TS_ECANCEL, "sweep: stopped on request");
            break;
        }
        ts_margin mg;
        if (!ts_result_margin(r, &mg) || prc != TS_OK) {
            x->status = prc != TS_OK ? prc : TS_ECONV;
            snprintf(x->error, sizeof x->error, "at %.150s = %.10g: %.800s",
                     s->spec.axes[x->axis].path, mid,
                     r->error[0] ? r->error : "no resolved mode");
            ts_result_free(r);
            break;
        }
        if (mg.verdict == TS_UNSTABLE) {
            x->unstable = mid;
            x->max_real_unstable = mg.max_real;
            x->freq_hz = mg.freq_hz;
        } else {
            x->stable = mid;
            x->max_real_stable = mg.max_real;
        }
        ts_result_free(r);
    }
    free(dir);
    x->value = 0.5 * (x->stable + x->unstable);
    x->wall_s = tsi_wall_now() - t0;
    if (rc == TS_OK)
        x->done = 1;
    return rc;
}

int ts_sweep_run_crossings(ts_sweep *s, int part, int nparts, ts_err *err)
{
    return run_share(s, 1, part, nparts, err);
}

/* ---- the driver -------------------------------------------------------- */

static int run_tasks(ts_sweep *s, const int *todo, int n, int crossings,
                     ts_err *err)
{
    int nt = threads_of(s);
    if (nt > n)
        nt = n > 0 ? n : 1;
    int rc = TS_OK;
    double t0 = tsi_wall_now();
    s->stop = 0;
#ifdef _OPENMP
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
#endif
    for (int i = 0; i < n; i++) {
        if (get_stop(s))
            continue;
        ts_err e = {0};
        int trc = crossings ? run_crossing(s, todo[i], &e)
                            : ts_sweep_run_chain(s, todo[i], &e);
        if (trc == TS_OK) {
            chain_done(s, crossings ? s->nchains + todo[i] : todo[i]);
            continue;
        }
#ifdef _OPENMP
#pragma omp critical(ts_sweep_callbacks)
#endif
        {
            set_stop(s);
            if (rc == TS_OK || (rc == TS_ECANCEL && trc != TS_ECANCEL)) {
                rc = trc;
                if (err)
                    *err = e;
            }
        }
    }
    s->wall_s += tsi_wall_now() - t0;
    if (rc == TS_OK && get_stop(s))
        rc = ts_fail(err, TS_ECANCEL, "sweep: stopped on request");
    return rc;
}

void ts_sweep_finish(ts_sweep *s)
{
    int done = 1;
    s->evaluations = 0;
    for (int p = 0; p < s->npoints; p++) {
        done &= s->points[p].state == TS_SWEEP_DONE;
        s->evaluations += s->points[p].evaluations;
    }
    for (int i = 0; i < s->ncrossings; i++) {
        done &= s->crossings[i].done;
        s->evaluations += s->crossings[i].evaluations;
    }
    s->completed = done;
}
