/* test_job.c: one analysis of a scene as one handle (towstab/job.h).
 *
 *  1. Refusals: an unknown analysis, an entry of another kind or out of
 *     range, an option the analysis does not have (named), a value out of
 *     range (named, nothing runs, no result), a second run, an option
 *     after the run; ts_job_json without a result.
 *  2. Options by name over the scene's entry: the scene's t_end is taken,
 *     an option given overrides it (the histories end there), and both
 *     the scene key and the command-line spelling are accepted.
 *  3. The JSON text parses and its top tension is the result's key value
 *     to the last digit (17 significant digits, read back exactly); the
 *     text, written as it is made, is byte for byte jansson's dump of
 *     the result's tree (ts_report_result_json), the full state of both
 *     runs and the links' force extremes included.
 *  4. Arrays without a copy: the nonlinear run's t, positions, tensions,
 *     tow force, energy and input are the history's own memory, with its
 *     shape; the linear run's tensions are finite and start at the
 *     nonlinear run's (both from the equilibrium), its tow force NaN;
 *     unknown names give NULL and 0 x 0.
 *  5. A simulation that fails (h_min above the step it needs) returns its
 *     code and keeps the partial history, its error in the JSON.
 *  6. Progress: with interval 0 every report reaches the callback (the
 *     simulated time rises to t_end of total t_end, unit "s"); a callback
 *     that asks to stop at its third report stops the run there with
 *     TS_ECANCEL, the history kept up to that time, "completed" false
 *     and the error saying where; with a long interval only the first
 *     report of each run (nonlinear, linear) passes; stopped at the first
 *     report of the discretisation estimate's run, the estimate is not
 *     made and says so; refusals after the
 *     run and of a
 *     negative interval.
 *  7. A document of several results (ts_report_results, `towstab run`)
 *     written as they come is byte for byte jansson's dump of the whole
 *     tree, to a file and to a stream, and nothing reaches either before
 *     the close; abandoned it leaves nothing; /dev/full fails naming it.
 */
#include "towstab/job.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tfiles.h"
#include "towstab/kernel.h"
#include "towstab/report_result.h"

/* A progress callback's record: reports seen, the last, when to stop. */
typedef struct {
    int calls, stop_at, ordered;
    double done, total;
    const char *what, *unit;
} seen;

static int on_progress(const ts_progress *p, void *data)
{
    seen *s = data;
    if (s->calls > 0 && !strcmp(p->what, s->what) && p->done < s->done)
        s->ordered = 0;
    s->calls++;
    s->done = p->done;
    s->total = p->total;
    s->what = p->what;
    s->unit = p->unit;
    return s->stop_at > 0 && s->calls >= s->stop_at;
}

static const char scene_text[] =
    "name: job\n"
    "tow: {speed: 2}\n"
    "cables:\n"
    "  - {name: c, from: tow, to: ball, length: 20, diameter: 0.01,\n"
    "     mass_per_length: 0.2, links: 8}\n"
    "bodies:\n"
    "  - {name: ball, type: sphere, diameter: 0.3, mass: 30}\n"
    "analyses:\n"
    "  - equilibrium\n"
    "  - {type: simulate, t_end: 1 s,\n"
    "     excite: \"tow.heave:amplitude=0.1,frequency=1Hz\"}\n";

/* The whole text of a file (malloc'd), NULL when it cannot be read. */
static char *read_all(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *text = NULL;
    size_t n = 0;
    FILE *m = f ? open_memstream(&text, &n) : NULL;
    int c;
    while (m && (c = getc(f)) != EOF)
        putc(c, m);
    if (m)
        fclose(m);
    if (f)
        fclose(f);
    return text;
}

/* 7. A document of several results written as they come: byte for byte
 * jansson's dump of the whole tree, to a file and to a stream; nothing
 * reaches the target before the close; abandoned, nothing is left; a
 * device that refuses the bytes fails at the close naming it. */
static void test_results(const ts_scene *sc, const ts_units *u)
{
    ts_err err = {0};
    ts_job *job[2] = {ts_job_alloc(sc, u, "equilibrium", -1, &err),
                      ts_job_alloc(sc, u, "simulate", 1, &err)};
    ts_job_give(job[1], "outputs", "all", &err);
    ts_job_give(job[1], "t_end", "3 s", &err);
    ts_job_give(job[1], "compare", "true", &err);
    ts_job_give(job[1], "discretisation_error", "false", &err);
    const ts_result *r[2];
    json_t *tree = json_pack("{s:s,s:[]}", "scene", "job", "analyses");
    json_t *tail = json_pack("{s:b,s:s}", "completed", 0, "error", "a\"b");
    for (int k = 0; k < 2; k++) {
        ts_job_run(job[k], &err);
        r[k] = ts_job_result(job[k]);
        if (r[k])
            json_array_append_new(json_object_get(tree, "analyses"),
                                  ts_report_result_json(r[k], 0));
    }
    json_object_update(tree, tail);
    char *ref = json_dumps(tree, JSON_INDENT(2) | JSON_REAL_PRECISION(17));
    size_t nref = ref ? strlen(ref) : 0;

    char path[600];
    snprintf(path, sizeof path, "%s/run.json", tf_dir);
    ts_report_results *d = ts_report_results_open(path, NULL, "job", &err);
    int rc = d && r[0] && r[1] ? TS_OK : TS_ENOMEM;
    for (int k = 0; k < 2 && rc == TS_OK; k++)
        rc = ts_report_results_add(d, r[k], 0, NULL, &err);
    int early = tf_exists(path);
    if (rc == TS_OK)
        rc = ts_report_results_close(d, tail, &err);
    else
        ts_report_results_abandon(d);
    char *text = read_all(path);
    CHECK(rc == TS_OK && !early && ref && text && strlen(text) == nref + 1 &&
              !strncmp(text, ref, nref) && text[nref] == '\n',
          "results: the file appears at the close, jansson's dump of the "
          "tree and a newline (%zu bytes): %s", nref, err.msg);
    free(text);
    unlink(path);

    char *mem = NULL;
    size_t nmem = 0;
    FILE *mf = open_memstream(&mem, &nmem);
    d = mf ? ts_report_results_open("memory", mf, "job", &err) : NULL;
    rc = d && r[0] && r[1] ? TS_OK : TS_ENOMEM;
    for (int k = 0; k < 2 && rc == TS_OK; k++)
        rc = ts_report_results_add(d, r[k], 0, NULL, &err);
    if (mf)
        fflush(mf);
    size_t before = nmem;
    if (rc == TS_OK)
        rc = ts_report_results_close(d, tail, &err);
    else
        ts_report_results_abandon(d);
    if (mf)
        fclose(mf);
    CHECK(rc == TS_OK && before == 0 && mem && ref &&
              strlen(mem) == nref + 1 && !strncmp(mem, ref, nref),
          "results: a stream gets nothing before the close, then the "
          "same bytes (%zu before)", before);
    free(mem);

    d = ts_report_results_open(path, NULL, "job", &err);
    if (d && r[0])
        ts_report_results_add(d, r[0], 0, NULL, &err);
    ts_report_results_abandon(d);
    CHECK(d && !tf_exists(path) && tf_count("") == 2,
          "results: abandoned, nothing is left");
    ts_report_results_abandon(NULL);

    if (tf_exists("/dev/full")) {
        ts_err_clear(&err);
        d = ts_report_results_open("/dev/full", NULL, "job", &err);
        rc = d && r[0] ? ts_report_results_add(d, r[0], 0, NULL, &err)
                       : TS_ENOMEM;
        rc = d ? ts_report_results_close(d, tail, &err) : rc;
        CHECK(rc == TS_EIO && strstr(err.msg, "/dev/full"),
              "results: /dev/full: TS_EIO at the close (%s)", err.msg);
    }
    free(ref);
    json_decref(tree);
    json_decref(tail);
    ts_job_free(job[0]);
    ts_job_free(job[1]);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = u ? ts_scene_parse(scene_text, strlen(scene_text),
                                      "job.yaml", u, &err)
                     : NULL;
    if (!CHECK(sc != NULL, "the scene reads: %s", err.msg))
        return tc_done();

    /* 1. Refusals. */
    ts_err_clear(&err);
    CHECK(!ts_job_alloc(sc, u, "bode", -1, &err) && err.code == TS_EINVAL &&
              strstr(err.msg, "'bode'"),
          "an unknown analysis is refused by name: %s", err.msg);
    ts_err_clear(&err);
    CHECK(!ts_job_alloc(sc, u, "modes", 1, &err) && err.code == TS_EINVAL &&
              strstr(err.msg, "analyses[1]"),
          "an entry of another kind is refused: %s", err.msg);
    ts_err_clear(&err);
    CHECK(!ts_job_alloc(sc, u, "modes", 7, &err) &&
              strstr(err.msg, "no such entry"),
          "an entry out of range is refused: %s", err.msg);
    ts_job *j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_err_clear(&err);
    CHECK(j && ts_job_give(j, "t_edn", "2", &err) == TS_EINVAL &&
              strstr(err.msg, "t_edn"),
          "an unknown option is refused by name: %s", err.msg);
    ts_err_clear(&err);
    CHECK(ts_job_json(j, 0, &err) == NULL && err.code == TS_EINVAL,
          "no JSON before the run: %s", err.msg);
    ts_job_give(j, "t_end", "-1", &err);
    ts_err_clear(&err);
    int rc = ts_job_run(j, &err);
    CHECK(rc == TS_EINVAL && !strncmp(err.msg, "t_end: ", 7) &&
              ts_job_result(j) == NULL,
          "a value out of range: nothing runs, the option named: %s",
          err.msg);
    ts_err_clear(&err);
    CHECK(ts_job_run(j, &err) == TS_EINVAL &&
              ts_job_give(j, "t_end", "1", &err) == TS_EINVAL,
          "a job runs once, and takes no option after");
    ts_job_free(j);

    /* 2.-4. Options over the scene's entry; JSON; arrays. */
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    rc = ts_job_run(j, &err);
    const ts_result *r = ts_job_result(j);
    CHECK(rc == TS_OK && r && r->nonlinear &&
              fabs(r->nonlinear->t[r->nonlinear->nsamples - 1] - 1.0) < 1e-12,
          "the scene's entry (t_end 1 s) is taken: %s", err.msg);
    ts_job_free(j);
    j = ts_job_alloc(sc, u, "simulate", 1, &err);
    ts_err_clear(&err);
    CHECK(ts_job_give(j, "t-end", "3 s", &err) == TS_OK &&
              ts_job_give(j, "compare", "true", &err) == TS_OK &&
              ts_job_give(j, "outputs", "all", &err) == TS_OK,
          "the command-line spelling and the scene key are taken");
    rc = ts_job_run(j, &err);
    r = ts_job_result(j);
    const ts_history *h = r ? r->nonlinear : NULL;
    CHECK(rc == TS_OK && h && fabs(h->t[h->nsamples - 1] - 3.0) < 1e-12 &&
              r->linear,
          "an option given overrides the scene's (t_end 3 s): %s",
          err.msg);
    CHECK(ts_job_notes(j) && ts_job_notes(j)[0] == '\0', "no notes");

    const char *text = ts_job_json(j, 0, &err);
    json_t *doc = text ? json_loads(text, 0, NULL) : NULL;
    const ts_value *v = r ? ts_result_value(r, "tension.max") : NULL;
    double jv = NAN;
    size_t i;
    json_t *kv;
    json_array_foreach(json_object_get(doc, "key_values"), i, kv)
    {
        if (!strcmp(json_string_value(json_object_get(kv, "name")),
                    "tension.max"))
            jv = json_number_value(json_object_get(kv, "value"));
    }
    CHECK(doc && v && jv == v->value,
          "the JSON's tension.max is the result's to the last digit (%.17g)",
          jv);
    json_decref(doc);
    /* The text is streamed (histories and forces.links never a tree):
     * byte for byte jansson's one-line dump of the result's tree. */
    json_t *tree = r ? ts_report_result_json(r, 0) : NULL;
    char *ref = tree ? json_dumps(tree, JSON_REAL_PRECISION(17)) : NULL;
    CHECK(text && ref && !strcmp(text, ref) &&
              strstr(text, "\"tensions\": [{\"cable\": ") &&
              strstr(text, "\"links\": [{\"max\": "),
          "ts_job_json is jansson's dump of the tree, full state and "
          "forces.links included (%zu bytes)", ref ? strlen(ref) : 0);
    free(ref);
    json_decref(tree);

    if (h) {
        int rows, cols;
        const double *a = ts_job_array(j, "nonlinear.t", &rows, &cols);
        CHECK(a == h->t && rows == h->nsamples && cols == 1,
              "nonlinear.t is the history's own, %d x %d", rows, cols);
        a = ts_job_array(j, "nonlinear.positions", &rows, &cols);
        CHECK(a == h->positions && rows == h->nsamples &&
                  cols == 3 * h->nnodes,
              "nonlinear.positions: %d x %d (3 x %d nodes)", rows, cols,
              h->nnodes);
        a = ts_job_array(j, "nonlinear.tensions", &rows, &cols);
        CHECK(a == h->tensions && cols == h->nlinks && cols == 8 &&
                  a[0] > 0,
              "nonlinear.tensions: %d links, %.6g N at t = 0", cols, a[0]);
        a = ts_job_array(j, "nonlinear.energy", &rows, &cols);
        CHECK(a == h->energy && cols == 2, "nonlinear.energy: 2 columns");
        a = ts_job_array(j, "nonlinear.input", &rows, &cols);
        CHECK(a == h->input && cols == TS_NINPUT, "nonlinear.input: %d",
              cols);
        const double *tn = h->tensions;
        a = ts_job_array(j, "linear.tensions", &rows, &cols);
        int finite = a && rows == r->linear->nsamples && cols == 8;
        for (int k = 0; finite && k < rows * cols; k++)
            finite = isfinite(a[k]);
        CHECK(finite && fabs(a[0] - tn[0]) <= 1e-9 * tn[0],
              "linear.tensions: finite (the tension Jacobians), the first "
              "link's at t = 0 the nonlinear run's (%.12g, %.12g N)",
              a ? a[0] : NAN, tn[0]);
        a = ts_job_array(j, "nonlinear.tow_force", &rows, &cols);
        CHECK(a == h->tow_force && cols == 3 && a[0] < 0,
              "nonlinear.tow_force: 3 columns, drag aft (%.6g N)", a[0]);
        a = ts_job_array(j, "linear.tow_force", &rows, &cols);
        CHECK(a && cols == 3 && isnan(a[0]), "linear.tow_force: NaN");
        const char *bad[] = {"nonlinear.speed", "lin.t", "nonlinear",
                             "nonlinear.", "t"};
        int none = 1;
        for (int k = 0; k < 5; k++)
            none &= !ts_job_array(j, bad[k], &rows, &cols) && rows == 0 &&
                    cols == 0;
        CHECK(none, "unknown array names: NULL, 0 x 0");
    }
    ts_job_free(j);

    /* Matrices without a copy: A, B and the eigenvectors of modes. */
    j = ts_job_alloc(sc, u, "modes", -1, &err);
    rc = j ? ts_job_run(j, &err) : -1;
    r = j ? ts_job_result(j) : NULL;
    if (CHECK(rc == TS_OK && r && r->lin && r->eigen, "modes run: %s",
              err.msg)) {
        int rows, cols, n = r->lin->nstate;
        const double *a = ts_job_matrix(j, "A", &rows, &cols);
        CHECK(a == r->lin->A && rows == n && cols == n, "A: %d x %d", rows,
              cols);
        a = ts_job_matrix(j, "B", &rows, &cols);
        CHECK(a == r->lin->B && rows == n && cols == r->lin->ninput,
              "B: %d x %d", rows, cols);
        a = ts_job_matrix(j, "vectors_im", &rows, &cols);
        CHECK(a == r->eigen->vec_im && rows == n &&
                  cols == r->eigen->nmodes,
              "vectors_im: %d x %d", rows, cols);
        CHECK(!ts_job_matrix(j, "C", &rows, &cols) && rows == 0 &&
                  !ts_job_array(j, "A", &rows, &cols),
              "unknown matrices: NULL");
    }
    ts_job_free(j);

    /* 5. A failing run keeps what it computed. */
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_job_give(j, "h_min", "0.5 s", &err);
    ts_job_give(j, "initial", "released", &err);
    ts_err_clear(&err);
    rc = ts_job_run(j, &err);
    r = ts_job_result(j);
    text = ts_job_json(j, 0, NULL);
    CHECK(rc == TS_EINTEGRATOR && r && !r->completed && r->nonlinear &&
              r->nonlinear->nsamples > 0 && text &&
              strstr(text, "\"completed\": false") && strstr(text, "h_min"),
          "a failed run: code %d, its history and error kept: %s", rc,
          err.msg);
    ts_job_free(j);
    ts_job_free(NULL);

    /* 6. Progress and stopping. */
    seen all = {.ordered = 1};
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_err_clear(&err);
    CHECK(ts_job_progress(j, on_progress, &all, -1, &err) == TS_EINVAL &&
              strstr(err.msg, "interval"),
          "a negative interval is refused: %s", err.msg);
    ts_job_progress(j, on_progress, &all, 0, &err);
    rc = ts_job_run(j, &err);
    CHECK(rc == TS_OK && all.calls > 10 && all.ordered &&
              fabs(all.done - 1.0) < 1e-12 && all.total == 1.0 &&
              !strcmp(all.unit, "s"),
          "every report: rc %d, %d calls, last %g of %g %s", rc, all.calls,
          all.done, all.total, all.unit ? all.unit : "?");
    ts_err_clear(&err);
    CHECK(ts_job_progress(j, NULL, NULL, 0, &err) == TS_EINVAL,
          "progress after the run is refused: %s", err.msg);
    ts_job_free(j);

    seen stop = {.stop_at = 3, .ordered = 1};
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_job_progress(j, on_progress, &stop, 0, &err);
    ts_err_clear(&err);
    rc = ts_job_run(j, &err);
    r = ts_job_result(j);
    text = ts_job_json(j, 0, NULL);
    h = r ? r->nonlinear : NULL;
    CHECK(rc == TS_ECANCEL && stop.calls == 3 && h && h->nsamples > 0 &&
              h->t[h->nsamples - 1] <= stop.done && stop.done < 1.0 &&
              !r->completed && text &&
              strstr(text, "\"completed\": false") &&
              strstr(text, "stopped on request"),
          "stopped at the third report: rc %d, %d calls, t = %g, %s", rc,
          stop.calls, stop.done, err.msg);
    ts_job_free(j);

    /* Stopped in the discretisation estimate (a run at fewer links
     * starts again from t = 0: its first report passes): the estimate
     * is not made, and says at how many links it stopped. */
    seen est = {.ordered = 1};
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_job_give(j, "discretisation_error", "false", &err);
    ts_job_progress(j, on_progress, &est, 0, &err);
    ts_err_clear(&err);
    rc = ts_job_run(j, &err);
    int reports = est.calls;
    ts_job_free(j);
    est = (seen){.stop_at = reports + 1, .ordered = 1};
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_job_give(j, "discretisation_error", "true", &err);
    ts_job_progress(j, on_progress, &est, 0, &err);
    rc = ts_job_run(j, &err);
    r = ts_job_result(j);
    CHECK(reports > 0 && rc == TS_ECANCEL && r && !r->completed &&
              est.done < 1e-2 && !r->accuracy.estimated &&
              strstr(r->accuracy.not_estimated, "links stopped"),
          "stopped in the estimate: rc %d after %d + 1 reports: %s", rc,
          reports, r ? r->accuracy.not_estimated : "(no result)");
    ts_job_free(j);

    seen sparse = {.ordered = 1};
    j = ts_job_alloc(sc, u, "simulate", -1, &err);
    ts_job_give(j, "compare", "true", &err);
    ts_job_give(j, "t_end", "3 s", &err);
    ts_job_give(j, "discretisation_error", "false", &err);
    ts_job_progress(j, on_progress, &sparse, 3600, &err);
    rc = ts_job_run(j, &err);
    /* The initial equilibrium's, the nonlinear run's, the linear run's. */
    CHECK(rc == TS_OK && sparse.calls == 3,
          "an hour's interval: the first report of each run only (%d; "
          "rc %d %s)", sparse.calls, rc, err.msg);
    ts_job_free(j);

    if (CHECK(tf_begin("job") == 0, "a folder under %s", tf_dir)) {
        test_results(sc, u);
        CHECK(tf_end(), "nothing left in the test folder");
    }
    ts_scene_free(sc);
    ts_units_free(u);
    return tc_done();
}
