/* job.c: one analysis of a scene as one handle (towstab/job.h): an option
 * set over the scene's entry, the request it makes, the result, and the
 * result's JSON text. */
#include "towstab/job.h"

#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "report_impl.h"
#include "towstab/eigen.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"
#include "towstab/options.h"
#include "towstab/report_result.h"

struct ts_job {
    const ts_scene *scene;
    const ts_units *units;
    int entry;          /* the scene's entry given, -1 its first */
    ts_optset *opts;
    int ran;            /* ts_job_run was called */
    ts_request rq;      /* valid when ran and checked */
    int have_rq;
    ts_result *result;
    char notes[TS_OPTSET_NOTES_MAX];
    char *json;         /* the last text of ts_job_json */
    /* The caller's progress callback and its throttle (ts_job_progress). */
    ts_progress_fn progress;
    void *progress_data;
    double interval;    /* s of wall time between reports passed on */
    const char *what;   /* the run of the last report passed on */
    double last;        /* its wall time */
    double done;        /* the progress of the last report seen */
};

ts_job *ts_job_alloc(const ts_scene *scene, const ts_units *units,
                     const char *kind, int entry, ts_err *err)
{
    int k = kind ? ts_analysis_find(kind) : -1;
    if (!scene || k < 0) {
        ts_fail(err, TS_EINVAL, "analysis: expected equilibrium, modes, "
                "response, simulate or converge, got '%s'",
                kind ? kind : "(none)");
        return NULL;
    }
    if (entry < -1 || entry >= scene->nanalyses ||
        (entry >= 0 && strcmp(scene->analyses[entry].type, kind) != 0)) {
        ts_fail(err, TS_EINVAL, "analyses[%d]: %s", entry,
                entry >= 0 && entry < scene->nanalyses
                    ? "not an entry of this analysis"
                    : "the scene has no such entry");
        return NULL;
    }
    ts_job *j = calloc(1, sizeof *j);
    if (!j) {
        ts_fail(err, TS_ENOMEM, "%s: out of memory", kind);
        return NULL;
    }
    j->scene = scene;
    j->units = units;
    j->entry = entry;
    j->opts = ts_optset_alloc(k, err);
    if (!j->opts) {
        free(j);
        return NULL;
    }
    return j;
}

void ts_job_free(ts_job *j)
{
    if (!j)
        return;
    ts_result_free(j->result);
    if (j->have_rq)
        ts_request_clear(&j->rq);
    ts_optset_free(j->opts);
    free(j->json);
    free(j);
}

int ts_job_give(ts_job *j, const char *name, const char *text, ts_err *err)
{
    if (j->ran)
        return ts_fail(err, TS_EINVAL, "%s: the job has run already",
                       name ? name : "option");
    if (!name || !text)
        return ts_fail(err, TS_EINVAL, "option: expected a name and a text");
    return ts_optset_give(j->opts, name, text, TS_OPTSET_COMMAND, name, err);
}

int ts_job_progress(ts_job *j, ts_progress_fn fn, void *data,
                    double interval, ts_err *err)
{
    if (j->ran)
        return ts_fail(err, TS_EINVAL, "progress: the job has run already");
    if (!(interval >= 0))
        return ts_fail(err, TS_EINVAL, "progress: the interval must be "
                       ">= 0 s, got %g s", interval);
    j->progress = fn;
    j->progress_data = data;
    j->interval = interval;
    return TS_OK;
}

/* The request's progress callback: passes the first report of a run (a
 * new `what`, or progress going back: the next run of a sweep or of the
 * discretisation estimate) and then one every j->interval s to the
 * caller's; between them, goes on. */
static int job_progress(const ts_progress *p, void *data)
{
    ts_job *j = data;
    double now = tsi_wall_now();
    int first = !j->what || strcmp(j->what, p->what) != 0 ||
                p->done < j->done;
    j->done = p->done;
    if (!first && now - j->last < j->interval)
        return 0;
    j->what = p->what;
    j->last = now;
    return j->progress(p, j->progress_data);
}

int ts_job_run(ts_job *j, ts_err *err)
{
    if (j->ran)
        return ts_fail(err, TS_EINVAL, "the job has run already");
    j->ran = 1;
    /* The scene's options are given last: a study's related entry
     * depends on the analysis the options given name. */
    int rc = ts_optset_give_scene(j->opts, j->scene, j->entry, err);
    if (rc == TS_OK)
        rc = ts_optset_request(j->opts, j->scene->system, j->units, &j->rq,
                               j->notes, sizeof j->notes, err);
    if (rc != TS_OK)
        return rc;
    j->have_rq = 1;
    if (j->progress) {
        j->rq.progress = job_progress;
        j->rq.progress_data = j;
    }
    rc = ts_analysis_run(j->scene->system, &j->rq, &j->result, err);
    if (!j->result)
        return rc ? rc : ts_fail(err, TS_ENOMEM, "out of memory");
    if (rc != TS_OK) {
        /* As the command line: the message names where the option that
         * failed was given. */
        ts_optset_locate(j->opts, err);
        snprintf(j->result->error, sizeof j->result->error, "%s", err->msg);
    }
    return rc;
}

const char *ts_job_notes(const ts_job *j)
{
    return j->notes;
}

const ts_result *ts_job_result(const ts_job *j)
{
    return j->result;
}

const char *ts_job_json(ts_job *j, int flags, ts_err *err)
{
    if (!j->result) {
        ts_fail(err, TS_EINVAL, "the job has no result (it did not run)");
        return NULL;
    }
    /* Written as the command line writes a file (the large arrays as
     * they are made, never a whole tree), in jansson's one-line form,
     * into memory. */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f) {
        ts_fail(err, TS_ENOMEM, "the result's JSON: out of memory");
        return NULL;
    }
    int rc = tsi_report_result_dump(j->result, flags, NULL, f,
                                    TSI_JSON_SPACED, "the result's JSON",
                                    err);
    if (fclose(f) != 0 && rc == TS_OK)
        rc = ts_fail(err, TS_ENOMEM, "the result's JSON: out of memory");
    if (rc != TS_OK) {
        free(text);
        return NULL;
    }
    free(j->json);
    j->json = text;
    return text;
}

const double *ts_job_array(const ts_job *j, const char *name, int *rows,
                           int *cols)
{
    *rows = *cols = 0;
    const ts_result *r = j->result;
    if (!r || !name)
        return NULL;
    const ts_history *h = NULL;
    size_t run = strcspn(name, ".");
    if (!strncmp(name, "nonlinear", run) && run == strlen("nonlinear"))
        h = r->nonlinear;
    else if (!strncmp(name, "linear", run) && run == strlen("linear"))
        h = r->linear;
    if (!h || name[run] != '.' || h->nsamples <= 0)
        return NULL;
    const char *part = name + run + 1;
    const struct {
        const char *name;
        const double *data;
        int cols;
    } parts[] = {
        {"t", h->t, 1},
        {"positions", h->positions, 3 * h->nnodes},
        {"tensions", h->tensions, h->nlinks},
        {"tow_force", h->tow_force, 3},
        {"energy", h->energy, 2},
        {"input", h->input, TS_NINPUT},
    };
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++)
        if (!strcmp(part, parts[i].name) && parts[i].data &&
            parts[i].cols > 0) {
            *rows = h->nsamples;
            *cols = parts[i].cols;
            return parts[i].data;
        }
    return NULL;
}

const double *ts_job_matrix(const ts_job *j, const char *name, int *rows,
                            int *cols)
{
    *rows = *cols = 0;
    const ts_result *r = j->result;
    if (!r || !name)
        return NULL;
    const ts_linear *lin = r->lin;
    const ts_eigen *e = r->eigen;
    const struct {
        const char *name;
        const double *data;
        int rows, cols;
    } parts[] = {
        {"A", lin ? lin->A : NULL, lin ? lin->nstate : 0,
         lin ? lin->nstate : 0},
        {"B", lin ? lin->B : NULL, lin ? lin->nstate : 0,
         lin ? lin->ninput : 0},
        {"vectors_re", e ? e->vec_re : NULL, e ? e->nstate : 0,
         e ? e->nmodes : 0},
        {"vectors_im", e ? e->vec_im : NULL, e ? e->nstate : 0,
         e ? e->nmodes : 0},
    };
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++)
        if (!strcmp(name, parts[i].name) && parts[i].data &&
            parts[i].rows > 0 && parts[i].cols > 0) {
            *rows = parts[i].rows;
            *cols = parts[i].cols;
            return parts[i].data;
        }
    return NULL;
}
