/* towstab/report_result.h: a result of towstab/analysis.h as one JSON
 * document and one CSV table (doc/manual.md, "JSON and CSV").
 *
 * Every kind writes what its command always wrote (towstab/report.h,
 * report_linear.h, report_time.h, report_converge.h), plus the keys every
 * result shares: "type" (the analysis), "completed", the verdict
 * "trustworthy", "reasons", "notes" (towstab/health.h), "error" when it
 * failed, and "key_values": [{"name", "unit", "value", "error":
 * {"discretisation", "solver"}}] (null where not estimated). SI units.
 * Files are written as towstab/report.h describes.
 */
#ifndef TOWSTAB_REPORT_RESULT_H
#define TOWSTAB_REPORT_RESULT_H

#include <jansson.h>
#include <stdio.h>

#include "towstab/analysis.h"
#include "towstab/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Flags of ts_report_result_json. */
#define TS_REPORT_MATRICES 1  /* modes: A and B */

/* The result as a new JSON object; NULL on allocation failure. */
TS_API json_t *ts_report_result_json(const ts_result *r, int flags);

/* Write the result's JSON to `path` ("-": standard output), indented,
 * as towstab/report.h describes: the document ts_report_result_json
 * makes, with the keys of the object `extra` (NULL: none) added last.
 * The per-node and per-link arrays and a simulation's histories are
 * written as they are made, never held in memory whole. TS_OK, TS_ENOMEM, or TS_EIO naming path. */
TS_API int ts_report_result_write_json(const ts_result *r, int flags,
                                       const json_t *extra,
                                       const char *path, ts_err *err);

/* The same to the open stream f (flushed by the caller, not closed);
 * `name` names f in messages. */
TS_API int ts_report_result_dumpf(const ts_result *r, int flags,
                                  const json_t *extra, FILE *f,
                                  const char *name, ts_err *err);

/* The result's table as CSV: an equilibrium's nodes (converged only),
 * the modes, the response, the histories (also of a failed run: the
 * samples reached) or the runs of a study. TS_EINVAL when the result has
 * no such table (nothing is written). */
TS_API int ts_report_result_csv(const ts_result *r, const char *path,
                                ts_err *err);

/* The same in the display units d (towstab/units.h; NULL: SI): the
 * tables of an equilibrium, a response, a simulation and a study show
 * their lengths, forces, times and frequencies in d's units and name
 * their columns with them; the mode tables stay SI. */
TS_API int ts_report_result_csv_display(const ts_result *r,
                                        const ts_display *d,
                                        const char *path, ts_err *err);

/* A document of several results, each written as it comes (`towstab
 * run`): {"scene": SCENE, "analyses": [result, ...], then the keys of the
 * object `tail` given at the end}, indented as ts_report_result_write_json
 * writes. Only the result being added is held as a tree (its large
 * arrays not even that); nothing reaches the target before
 * ts_report_results_close: a file is written under a temporary name and
 * renamed (towstab/report.h), and a stream or a target written in place
 * (a device, standard output) gets its bytes from a temporary file at
 * the close, so a document abandoned leaves nothing. */
typedef struct ts_report_results ts_report_results;

/* Begin the document for `path` ("-": standard output), or, when f is
 * not NULL, for the open stream f (flushed, not closed; `path` then only
 * names it in messages). NULL with TS_EIO or TS_ENOMEM naming path. */
TS_API ts_report_results *ts_report_results_open(const char *path, FILE *f,
                                                 const char *scene,
                                                 ts_err *err);

/* Add result r as ts_report_result_write_json writes it (with the keys
 * of extra added last; extra may be NULL). TS_OK, or TS_ENOMEM or TS_EIO
 * naming the target (the document can then only be abandoned). */
TS_API int ts_report_results_add(ts_report_results *d, const ts_result *r,
                                 int flags, const json_t *extra,
                                 ts_err *err);

/* Close the list, add the keys of `tail` (an object; NULL: none) and
 * write the document to its target. TS_OK, or TS_ENOMEM or TS_EIO naming
 * the target (nothing is left of it then). Releases d either way. */
TS_API int ts_report_results_close(ts_report_results *d, const json_t *tail,
                                   ts_err *err);

/* Give the document up: nothing is written. Releases d; NULL does
 * nothing. */
TS_API void ts_report_results_abandon(ts_report_results *d);

#ifdef __cplusplus
}
#endif
#endif
