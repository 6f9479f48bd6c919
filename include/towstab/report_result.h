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
 * The per-node and per-link arrays are written as they are made, never
 * held in memory whole. TS_OK, TS_ENOMEM, or TS_EIO naming path. */
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

#ifdef __cplusplus
}
#endif
#endif
