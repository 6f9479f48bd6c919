/* towstab/report_sweep.h: a sweep (towstab/sweep.h) as JSON and CSV, and
 * its chains as records that restore them (doc/manual.md, "towstab
 * sweep"; doc/sweep.md).
 *
 * The table: one row per point with its grid values, outcome and every
 * column with its error estimate; JSON also has the axes, the columns
 * with their units, each point's verdict with its reasons and notes and
 * run time, the crossings of the stability boundary and the totals. SI
 * units. The CSV leaves out run times, so that two runs of one sweep give
 * the same file whatever threads or processes ran it.
 *
 * A record is one line of JSON holding everything a chain (or a
 * crossing) computed, numbers written with 17 significant digits (they
 * read back to the same bits): a sweep interrupted and resumed from its
 * records, or assembled from records made by other processes, has the
 * table of a sweep run in one go.
 */
#ifndef TOWSTAB_REPORT_SWEEP_H
#define TOWSTAB_REPORT_SWEEP_H

#include <jansson.h>

#include "towstab/error.h"
#include "towstab/sweep.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sweep as a new JSON object (done points; pending ones are listed
 * with "status": "pending"); NULL on allocation failure. */
TS_API json_t *ts_report_sweep_json(const ts_sweep *s);

/* The table as CSV, written as towstab/report.h writes files:
 * index, the axes' paths, status, trustworthy, verdict, warm,
 * evaluations, iterations, then each column and its discretisation and
 * solver errors (<name>, <name>_discretisation, <name>_solver). */
TS_API int ts_report_sweep_csv(const ts_sweep *s, const char *path,
                               ts_err *err);

/* Record of task t: chain t (0 <= t < nchains) or crossing t - nchains,
 * as one line of JSON (no newline; caller frees). NULL when out of
 * memory or t is not a task. */
TS_API char *ts_report_sweep_record(const ts_sweep *s, int t);

/* Restore a record into s (its points, or its crossing, marked done).
 * TS_OK, or TS_EINVAL when the text is not a record of this sweep (not
 * JSON, a chain that does not exist, points or columns that do not
 * match): the message says which. A crossing record needs the crossings
 * laid out (ts_sweep_crossings_find). */
TS_API int ts_report_sweep_restore(ts_sweep *s, const char *text,
                                   ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
