/* towstab/job.h: one analysis of a scene as one handle, for programs and
 * bindings (the Python package, doc/python.md) that hold no C structs.
 *
 * A job takes its options as `towstab KIND SCENE --name value` does: texts
 * by name over the scene's entry of the analysis (towstab/options.h), then
 * builds the request, checks it against the scene's system, runs the
 * pipeline (towstab/analysis.h) and keeps the request and the result
 * together (a result may point into its request). The result is read as
 * the JSON text the command line writes (towstab/report_result.h) and,
 * without a copy, as the arrays of its time histories, its linear model
 * and its eigenvectors.
 *
 *     ts_job *j = ts_job_alloc(scene, units, "modes", -1, &err);
 *     ts_job_give(j, "count", "6", &err);
 *     int rc = ts_job_run(j, &err);        // TS_OK, or a failure
 *     const char *json = ts_job_json(j, 0, &err);
 *     ts_job_free(j);
 */
#ifndef TOWSTAB_JOB_H
#define TOWSTAB_JOB_H

#include "towstab/analysis.h"
#include "towstab/error.h"
#include "towstab/scene.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ts_job ts_job;

/* A job of analysis `kind` ("equilibrium", "modes", "response",
 * "simulate", "converge") on `scene`, taking the options of the scene's
 * entry analyses[entry], or with entry -1 of its first entry of that kind
 * when it has one (ts_optset_give_scene). The scene and units are used,
 * not copied: they must outlive the job. NULL on failure (TS_EINVAL for
 * an unknown kind or an entry of another kind, TS_ENOMEM). */
TS_API ts_job *ts_job_alloc(const ts_scene *scene, const ts_units *units,
                            const char *kind, int entry, ts_err *err);
TS_API void ts_job_free(ts_job *j);

/* Give option `name` (a scene key such as "t_end", or the command-line
 * spelling "t-end") the text `text` ("12 s", "true", "5,10,20"), above
 * the scene's entry, as the command line does; a repeatable option
 * (excite) takes each text given. Messages name the option. TS_EINVAL for
 * a name the analysis does not have, or after ts_job_run. */
TS_API int ts_job_give(ts_job *j, const char *name, const char *text,
                       ts_err *err);

/* Progress reports and stopping (towstab/progress.h): the job's run calls
 * `fn` with `data` as the long runs go (a simulation's steps, a
 * convergence sweep's runs): the first report of each run (a new `what`,
 * or `done` going back) and then at most one every `interval` s of wall
 * time (0: every report), so that a callback into an interpreter costs
 * the run little. A nonzero return stops the run with TS_ECANCEL, keeping
 * what it computed (the result's "completed" false, "error" how far it
 * got). fn NULL: none. Before ts_job_run; TS_EINVAL after it or for a
 * negative or NaN interval. The throttle's state is the job's. */
TS_API int ts_job_progress(ts_job *j, ts_progress_fn fn, void *data,
                           double interval, ts_err *err);

/* Check the request and run the analysis, once. Returns TS_OK, a check's
 * code (nothing ran: ts_job_result is NULL; the message names the option
 * and where it was given), or the run's status (the result holds what
 * was computed, its "error" the message). */
TS_API int ts_job_run(ts_job *j, ts_err *err);

/* The notes of the request: scene values that yielded to their defaults
 * because the options given contradict them, one a line; "" when none. */
TS_API const char *ts_job_notes(const ts_job *j);

/* The result after ts_job_run, NULL before or when nothing ran. */
TS_API const ts_result *ts_job_result(const ts_job *j);

/* The result as the command line's JSON (ts_report_result_json with
 * `flags`, numbers to 17 significant digits) on one line, as jansson's
 * json_dumps writes it, made without building the tree: text owned by
 * the job, valid until the next call or ts_job_free. NULL with TS_EINVAL
 * when there is no result, TS_ENOMEM (or TS_EIO, a failed write into
 * memory). */
TS_API const char *ts_job_json(ts_job *j, int flags, ts_err *err);

/* An array of the result, not copied (valid until ts_job_free), row-major
 * with *rows rows of *cols: "nonlinear.t" and "linear.t" ([samples] s,
 * one column), "<run>.positions" ([samples][3 nodes] m, node 0 the tow
 * point), "<run>.tensions" ([samples][links] N), "<run>.tow_force"
 * ([samples][3] N, the force on the tow point), "<run>.energy"
 * ([samples][2] kinetic and potential J), "<run>.input" ([samples]
 * [TS_NINPUT] u(t)); NaN where the run has none (towstab/simulate.h,
 * ts_history). NULL (rows and cols 0) for a name the result does
 * not hold. */
TS_API const double *ts_job_array(const ts_job *j, const char *name,
                                  int *rows, int *cols);

/* A matrix of the result, not copied (valid until ts_job_free), stored
 * column-major (LAPACK's order) with *rows rows of *cols: "A" ([n][n],
 * the linear model's state matrix) and "B" ([n][ninput]) of the dense
 * model (towstab/linearize.h; absent when only the sparse model was
 * formed), "vectors_re" and "vectors_im" ([n][modes], column m the right
 * eigenvector of mode m, unit 2-norm; towstab/eigen.h). NULL (rows and
 * cols 0) for a name the result does not hold. */
TS_API const double *ts_job_matrix(const ts_job *j, const char *name,
                                   int *rows, int *cols);

#ifdef __cplusplus
}
#endif
#endif
