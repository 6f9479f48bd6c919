/* test_sweep.c: sweeps over scene values (towstab/sweep.h) and their
 * records (towstab/report_sweep.h).
 *
 *  1. A point is the single run: every point of a sweep of cold starts
 *     (chain 1), and the first point of every chain of a continued sweep,
 *     equals ts_analysis_run of the request with that point's values set,
 *     bit for bit (values, estimates, evaluations). A continued point
 *     agrees with its single run within the sum of their solver error
 *     estimates (both meet the same force residual) and starts from its
 *     neighbour.
 *  2. Threads: the table on 1 and on 3 threads is the same, bit for bit;
 *     so is a sweep of modes with ARPACK and its rightmost search on 1
 *     and 2 threads (ARPACK's runs take turns, each from a start vector
 *     of its own size alone: lib/eigen.c).
 *  3. Records: every chain written as a record and restored into a fresh
 *     sweep gives the same table bit for bit; a sweep stopped after some
 *     chains and resumed from their records equals one run in one go.
 *  4. The stability boundary of Kamman's example 1 with the tow point
 *     above the water (the sphere starts to skim the surface, an in-plane
 *     flutter near 0.41 Hz, between 8 and 9 m/s): the crossing's bracket
 *     is below 1e-3 of the grid step, and single runs of `modes` just
 *     outside it, independent of the bisection, are not unstable below
 *     and unstable above.
 *  5. Refusals name the axis or option: an unknown path, a value the key
 *     does not allow, an axis given twice or also set, a boundary without
 *     modes.
 */
#include "towstab/sweep.h"

#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/report_sweep.h"

static ts_sweep *make(const ts_system *sys, ts_analysis_kind kind,
                      const char *p0, const double *v0, int n0,
                      const char *p1, const double *v1, int n1, int chain,
                      int threads)
{
    ts_sweep_spec sp;
    memset(&sp, 0, sizeof sp);
    ts_request_init(&sp.rq, kind);
    sp.naxes = p1 ? 2 : 1;
    snprintf(sp.axes[0].path, sizeof sp.axes[0].path, "%s", p0);
    sp.axes[0].n = n0;
    sp.axes[0].values = (double *)v0;
    if (p1) {
        snprintf(sp.axes[1].path, sizeof sp.axes[1].path, "%s", p1);
        sp.axes[1].n = n1;
        sp.axes[1].values = (double *)v1;
    }
    sp.chain = chain;
    sp.threads = threads;
    sp.boundary = kind == TS_ANALYSIS_MODES;
    ts_err err = {0};
    ts_sweep *s = ts_sweep_alloc(sys, &sp, &err);
    if (!s)
        printf("     sweep: %s\n", err.msg);
    return s;
}

static int run_all(ts_sweep *s)
{
    ts_err err = {0};
    int rc = ts_sweep_run(s, 0, 1, &err);
    if (!rc)
        rc = ts_sweep_crossings_find(s, &err);
    if (!rc)
        rc = ts_sweep_run_crossings(s, 0, 1, &err);
    ts_sweep_finish(s);
    if (rc)
        printf("     run: %s\n", err.msg);
    return rc;
}

/* Two sweeps' tables are the same bit for bit. */
static int same_table(const ts_sweep *a, const ts_sweep *b)
{
    if (a->npoints != b->npoints || a->ncolumns != b->ncolumns ||
        a->ncrossings != b->ncrossings)
        return 0;
    size_t n = (size_t)a->npoints * (size_t)a->ncolumns;
    for (size_t i = 0; i < n; i++)
        if (memcmp(&a->values[i], &b->values[i], sizeof(double)) ||
            memcmp(&a->errors[i], &b->errors[i], sizeof(ts_estimate)))
            return 0;
    for (int p = 0; p < a->npoints; p++) {
        const ts_sweep_point *x = &a->points[p], *y = &b->points[p];
        if (x->state != y->state || x->status != y->status ||
            x->verdict != y->verdict || x->warm != y->warm ||
            x->evaluations != y->evaluations ||
            x->trust.trustworthy != y->trust.trustworthy ||
            x->trust.nreasons != y->trust.nreasons ||
            x->trust.nnotes != y->trust.nnotes || strcmp(x->error, y->error))
            return 0;
    }
    for (int i = 0; i < a->ncrossings; i++) {
        const ts_sweep_crossing *x = &a->crossings[i], *y = &b->crossings[i];
        if (x->stable != y->stable || x->unstable != y->unstable ||
            x->runs != y->runs || x->evaluations != y->evaluations ||
            x->done != y->done)
            return 0;
    }
    return 1;
}

static int has_value(const ts_result *r, const char *name)
{
    for (int i = 0; i < r->nvalues; i++)
        if (!strcmp(r->values[i].name, name))
            return 1;
    return 0;
}

/* Point p of s against the single run of its request. exact: bit for
 * bit; else within the solver estimates. Returns 1 when it holds. */
static int against_single(const ts_sweep *s, int p, int exact,
                          double *worst)
{
    int idx[TS_SWEEP_MAX_AXES];
    ts_sweep_point_index(s, p, idx);
    ts_request rq = s->spec.rq;
    for (int a = 0; a < s->spec.naxes; a++)
        ts_setup_set(&rq.setup, s->spec.axes[a].path,
                     s->spec.axes[a].values[idx[a]], NULL);
    ts_result *r = NULL;
    ts_err err = {0};
    int rc = ts_analysis_run(s->sys, &rq, &r, &err);
    ts_value *eqv = NULL;
    int neq = 0;
    ts_result_equilibrium_values(r, &eqv, &neq, NULL);
    int ok = rc == s->points[p].status;
    if (exact)
        ok = ok && r->evaluations == s->points[p].evaluations;
    for (int i = 0; ok && i < neq + r->nvalues; i++) {
        const ts_value *v = i < neq ? &eqv[i] : &r->values[i - neq];
        /* A name among the result's own values is recorded with their
         * estimates (the equilibrium's list has no discretisation). */
        if (i < neq && has_value(r, v->name))
            continue;
        int c = ts_sweep_column_find(s, v->name);
        if (c < 0)
            return 0;
        size_t k = (size_t)p * (size_t)s->ncolumns + (size_t)c;
        double d = fabs(v->value - s->values[k]);
        if (exact) {
            ok = !memcmp(&v->value, &s->values[k], sizeof(double)) &&
                 !memcmp(&v->error, &s->errors[k], sizeof(ts_estimate));
        } else {
            double tol = v->error.solver + s->errors[k].solver;
            ok = d <= tol;
            if (tol > 0 && d / tol > *worst)
                *worst = d / tol;
        }
    }
    free(eqv);
    ts_result_free(r);
    return ok;
}

static void test_points(const ts_system *ex1, const ts_system *ex3)
{
    /* Equilibria over speed x cable length, cold starts. */
    double v[4] = {1.5, 2.385, 3.2, 4.75}, len[3] = {20.5, 30.48, 41.0};
    ts_sweep *s = make(ex1, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.length",
                       len, 3, "speed", v, 4, 1, 1);
    if (s && !run_all(s)) {
        int ok = 1;
        double w = 0;
        for (int p = 0; p < s->npoints; p++)
            ok &= against_single(s, p, 1, &w);
        CHECK(ok && s->completed, "chain 1: each of the %d points equals "
              "the single run at its settings bit for bit", s->npoints);
    }
    ts_sweep_free(s);
    /* Over the link count: the discretisation estimate's coarser levels
     * are those of the point's own links, as in the single run. */
    double nl[2] = {10, 20};
    s = make(ex1, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.links", nl, 2, NULL,
             NULL, 0, 0, 1);
    if (s && !run_all(s)) {
        int ok = 1;
        double w = 0;
        for (int p = 0; p < s->npoints; p++)
            ok &= against_single(s, p, 1, &w);
        int z = ts_sweep_column_find(s, "sphere.z");
        double e10 = z >= 0 ? s->errors[z].discretisation : NAN;
        double e20 = z >= 0 ? s->errors[s->ncolumns + z].discretisation : NAN;
        CHECK(ok && e20 > 0 && e20 < e10,
              "over cables.cable.links 10, 20: each point equals its single "
              "run bit for bit, the depth's discretisation error falls "
              "(%.3g m, %.3g m)", e10, e20);
    }
    ts_sweep_free(s);
    /* Modes in a turn, continued: chain starts exact, the rest within
     * their estimates. */
    double w8[9];
    for (int i = 0; i < 9; i++)
        w8[i] = 0.9 + 0.05 * i;
    s = make(ex3, TS_ANALYSIS_MODES, "tow.turn_rate", w8, 9, NULL, NULL, 0,
             0, 1);
    if (s && !run_all(s)) {
        int exact = 1, near = 1, warm = 0;
        double worst = 0;
        for (int p = 0; p < s->npoints; p++) {
            int first, n;
            ts_sweep_chain_points(s, ts_sweep_chain_of(s, p), &first, &n);
            if (p == first)
                exact &= against_single(s, p, 1, &worst) &&
                         !s->points[p].warm;
            else
                near &= against_single(s, p, 0, &worst);
            warm += s->points[p].warm;
        }
        CHECK(exact && s->nchains == 2, "continued sweep: the first point "
              "of each of its %d chains equals its single run bit for bit",
              s->nchains);
        CHECK(near && warm == s->npoints - s->nchains,
              "the %d continued points agree with their single runs within "
              "their solver estimates (largest ratio %.3g)", warm, worst);
    }
    ts_sweep_free(s);
}

static void test_threads_and_records(const ts_system *ex3)
{
    double w[7] = {0.0, 0.3, 0.6, 0.9, 1.2, 1.5, 1.8};
    double len[2] = {1.6, 1.9};
    ts_sweep *a = make(ex3, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.length",
                       len, 2, "turn_rate", w, 7, 3, 1);
    ts_sweep *b = make(ex3, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.length",
                       len, 2, "turn_rate", w, 7, 3, 3);
    if (a && b && !run_all(a) && !run_all(b))
        CHECK(same_table(a, b) && a->nchains == 6,
              "1 and 3 threads: the same table bit for bit (%d points, %d "
              "chains)", a->npoints, a->nchains);
    /* Every record restored into a fresh sweep. */
    ts_sweep *c = make(ex3, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.length",
                       len, 2, "turn_rate", w, 7, 3, 1);
    int rc = TS_OK;
    for (int t = 0; a && c && t < a->nchains && !rc; t++) {
        char *rec = ts_report_sweep_record(a, t);
        ts_err err = {0};
        rc = rec ? ts_report_sweep_restore(c, rec, &err) : TS_ENOMEM;
        if (rc)
            printf("     restore: %s\n", err.msg);
        free(rec);
    }
    if (c)
        ts_sweep_finish(c);
    CHECK(a && c && !rc && c->completed && same_table(a, c),
          "a sweep restored from its records is the same table bit for bit");
    ts_sweep_free(c);
    /* Stopped after two chains, resumed from their records. */
    c = make(ex3, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.length", len, 2,
             "turn_rate", w, 7, 3, 1);
    ts_sweep *d = make(ex3, TS_ANALYSIS_EQUILIBRIUM, "cables.cable.length",
                       len, 2, "turn_rate", w, 7, 3, 1);
    if (a && c && d) {
        ts_err err = {0};
        for (int t = 0; t < 2; t++) {
            ts_sweep_run_chain(c, t, &err);
            char *rec = ts_report_sweep_record(c, t);
            if (rec)
                ts_report_sweep_restore(d, rec, &err);
            free(rec);
        }
        int done = 0;
        for (int p = 0; p < d->npoints; p++)
            done += d->points[p].state == TS_SWEEP_DONE;
        int rc2 = run_all(d);
        CHECK(done > 0 && done < d->npoints && !rc2 && same_table(a, d),
              "stopped with %d of %d points, resumed from the records: the "
              "same table as one run", done, d->npoints);
        char rec[] = "{\"chain\": 99, \"points\": []}";
        int rrc = ts_report_sweep_restore(d, rec, &err);
        CHECK(rrc == TS_EINVAL && strstr(err.msg, "the sweep has 6 chains"),
              "a record of another sweep refused: %s", err.msg);
    }
    ts_sweep_free(a);
    ts_sweep_free(b);
    ts_sweep_free(c);
    ts_sweep_free(d);
}

/* Progress that stops the sweep once a chain of points is done (the
 * callback is also called inside each point's run: its equilibrium's
 * stages). */
static int stop_soon(const ts_progress *p, void *data)
{
    int *calls = data;
    ++*calls;
    return p->done >= 1;
}

/* Modes with ARPACK (the sparse model, the rightmost search) at 300
 * links on 1 and 2 threads: ARPACK keeps a run's state in SAVE variables,
 * so two runs at once corrupt each other (a crash, heap corruption), and
 * its own random start vector depends on the runs before it. */
static void test_threads_arpack(const ts_system *ex1)
{
    ts_err err = {0};
    ts_system *sys = ts_system_copy(ex1, &err);
    if (!CHECK(sys && ts_system_set_links(sys, 300, &err) == TS_OK,
               "300 links (%s)", err.msg)) {
        ts_system_free(sys);
        return;
    }
    double v[4] = {2.0, 2.5, 3.0, 3.5};
    ts_sweep *s[2] = {NULL, NULL};
    for (int t = 0; t < 2; t++) {
        ts_sweep_spec sp;
        memset(&sp, 0, sizeof sp);
        ts_request_init(&sp.rq, TS_ANALYSIS_MODES);
        sp.rq.modes.eigen.method = TS_EIG_ARPACK;
        sp.rq.modes.count = 6;
        sp.rq.setup.discretisation_error = 0;
        sp.naxes = 1;
        snprintf(sp.axes[0].path, sizeof sp.axes[0].path, "speed");
        sp.axes[0].n = 4;
        sp.axes[0].values = v;
        sp.chain = 1;
        sp.threads = t + 1;
        s[t] = ts_sweep_alloc(sys, &sp, &err);
        if (!s[t])
            printf("     sweep: %s\n", err.msg);
    }
    int ok = s[0] && s[1] && !run_all(s[0]) && !run_all(s[1]);
    CHECK(ok && same_table(s[0], s[1]),
          "modes with ARPACK and the rightmost search, 300 links, 4 points "
          "on 1 and 2 threads: the same table bit for bit");
    ts_sweep_free(s[0]);
    ts_sweep_free(s[1]);
    ts_system_free(sys);
}

static void test_stop(const ts_system *ex3)
{
    double w[7] = {0.0, 0.3, 0.6, 0.9, 1.2, 1.5, 1.8};
    ts_sweep_spec sp;
    memset(&sp, 0, sizeof sp);
    ts_request_init(&sp.rq, TS_ANALYSIS_EQUILIBRIUM);
    sp.naxes = 1;
    snprintf(sp.axes[0].path, sizeof sp.axes[0].path, "turn_rate");
    sp.axes[0].n = 7;
    sp.axes[0].values = w;
    sp.chain = 2;
    sp.threads = 1;
    int calls = 0;
    sp.progress = stop_soon;
    sp.progress_data = &calls;
    ts_err err = {0};
    ts_sweep *s = ts_sweep_alloc(ex3, &sp, &err);
    int rc = s ? ts_sweep_run(s, 0, 1, &err) : TS_ENOMEM;
    int done = 0;
    for (int p = 0; s && p < s->npoints; p++)
        done += s->points[p].state == TS_SWEEP_DONE;
    CHECK(rc == TS_ECANCEL && done > 0 && done < 7,
          "stopped by its progress callback: TS_ECANCEL with %d of 7 points "
          "kept (%s)", done, err.msg);
    ts_sweep_free(s);
}

static void test_boundary(const ts_system *above)
{
    double v[9];
    for (int i = 0; i < 9; i++)
        v[i] = 2.0 + i;
    ts_sweep *s = make(above, TS_ANALYSIS_MODES, "speed", v, 9, NULL, NULL,
                       0, 0, 2);
    if (!s || run_all(s)) {
        ts_sweep_free(s);
        return;
    }
    CHECK(s->ncrossings == 1, "one crossing of the stability boundary "
          "between 2 and 10 m/s (%d)", s->ncrossings);
    if (s->ncrossings == 1) {
        const ts_sweep_crossing *x = &s->crossings[0];
        CHECK(x->status == TS_OK && x->stable >= 8 && x->unstable <= 9 &&
                  fabs(x->unstable - x->stable) <= 1e-3 * 1.0,
              "bisected to [%.7g, %.7g] m/s in %d runs (step 1 m/s), the "
              "unstable mode at %.4g Hz", x->stable, x->unstable, x->runs,
              x->freq_hz);
        /* Independent single runs just outside the bracket. */
        double at[2] = {x->stable - 2e-4, x->unstable + 2e-4};
        int verdict[2] = {-1, -1};
        for (int k = 0; k < 2; k++) {
            ts_request rq;
            ts_request_init(&rq, TS_ANALYSIS_MODES);
            rq.setup.speed = at[k];
            ts_result *r = NULL;
            if (ts_analysis_run(above, &rq, &r, NULL) == TS_OK)
                verdict[k] = r->stability.verdict >= 0
                                 ? r->stability.verdict
                                 : r->stability.unresolved_verdict;
            ts_result_free(r);
        }
        CHECK(verdict[0] != TS_UNSTABLE && verdict[1] == TS_UNSTABLE,
              "single runs: %s at %.7g m/s, %s at %.7g m/s",
              verdict[0] >= 0 ? ts_verdict_name(verdict[0]) : "failed",
              at[0], verdict[1] >= 0 ? ts_verdict_name(verdict[1])
                                     : "failed",
              at[1]);
    }
    ts_sweep_free(s);
}

static void test_refusals(const ts_system *ex1)
{
    double v[2] = {1.0, 2.0}, bad[2] = {10.0, -1.0};
    const struct {
        const char *p0, *p1;
        const double *v0;
        ts_analysis_kind kind;
        int boundary;
        const char *says;
    } cases[] = {
        {"cables.rope.length", NULL, v, TS_ANALYSIS_EQUILIBRIUM, 0,
         "vary: cables.rope.length: no cable of that name"},
        {"cables.cable.length", NULL, bad, TS_ANALYSIS_EQUILIBRIUM, 0,
         "vary: value 2 of cables.cable.length: cables.cable.length: must "
         "be > 0 m"},
        {"speed", "tow.speed", v, TS_ANALYSIS_EQUILIBRIUM, 0,
         "vary: tow.speed is varied twice"},
        {"speed", NULL, v, TS_ANALYSIS_EQUILIBRIUM, 1,
         "boundary: the stability boundary needs the modes analysis"},
        {"speed", NULL, v, TS_ANALYSIS_CONVERGE, 0,
         "analysis: a sweep runs equilibrium, modes, response or simulate"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        ts_sweep_spec sp;
        memset(&sp, 0, sizeof sp);
        ts_request_init(&sp.rq, cases[i].kind);
        sp.naxes = cases[i].p1 ? 2 : 1;
        snprintf(sp.axes[0].path, TS_PARAM_PATH_MAX, "%s", cases[i].p0);
        sp.axes[0].n = 2;
        sp.axes[0].values = (double *)cases[i].v0;
        if (cases[i].p1) {
            snprintf(sp.axes[1].path, TS_PARAM_PATH_MAX, "%s", cases[i].p1);
            sp.axes[1].n = 2;
            sp.axes[1].values = v;
        }
        sp.boundary = cases[i].boundary;
        ts_err err = {0};
        ts_sweep *s = ts_sweep_alloc(ex1, &sp, &err);
        CHECK(!s && strstr(err.msg, cases[i].says), "refused: %s", err.msg);
        ts_sweep_free(s);
    }
    /* The same key also set in the request. */
    ts_sweep_spec sp;
    memset(&sp, 0, sizeof sp);
    ts_request_init(&sp.rq, TS_ANALYSIS_EQUILIBRIUM);
    ts_setup_set(&sp.rq.setup, "tow.speed", 3, NULL);
    sp.naxes = 1;
    snprintf(sp.axes[0].path, TS_PARAM_PATH_MAX, "speed");
    sp.axes[0].n = 2;
    sp.axes[0].values = v;
    ts_err err = {0};
    ts_sweep *s = ts_sweep_alloc(ex1, &sp, &err);
    CHECK(!s && strstr(err.msg, "vary: tow.speed is also set"),
          "refused: %s", err.msg);
    ts_sweep_free(s);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *ex1 = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    ts_scene *above = tscene_load(u, "examples/kamman_ex1_above.yaml");
    ts_scene *ex3 = tscene_load(u, "examples/kamman_ex3_turn.yaml");
    if (ex1 && above && ex3) {
        test_points(ex1->system, ex3->system);
        test_threads_and_records(ex3->system);
        test_threads_arpack(ex1->system);
        test_stop(ex3->system);
        test_boundary(above->system);
        test_refusals(ex1->system);
    }
    ts_scene_free(ex1);
    ts_scene_free(above);
    ts_scene_free(ex3);
    ts_units_free(u);
    return tc_done();
}
