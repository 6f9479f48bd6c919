/* towstab/report_converge.h: convergence tables and the health of modes as JSON
 * (jansson) and CSV (doc/converge.md). SI units (the unit of each value is
 * named with it); numbers that are not finite are JSON null and "nan" in
 * CSV. Files are written as towstab/report.h describes
 * (atomically, devices in place).
 */
#ifndef TOWSTAB_REPORT_CONVERGE_H
#define TOWSTAB_REPORT_CONVERGE_H

#include <jansson.h>

#include "towstab/converge.h"
#include "towstab/eigen.h"
#include "towstab/error.h"
#include "towstab/health.h"
#include "towstab/report.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Add the health of a mode analysis to its JSON (ts_report_modes_json):
 * top level "trustworthy", "reasons", "notes", "margin_ratio" (|max Re| /
 * its error bound: the smallest damping against the linearization error);
 * in each of "modes"[m]: "trustworthy", "shape_trustworthy",
 * "freq_error_hz", "damping_error", "vector_error", "vector_condition",
 * "nearest_mode" (1-based, null for its own conjugate). Returns TS_OK or
 * TS_ENOMEM. */
TS_API int ts_report_modes_health_json(json_t *modes, const ts_eigen *e,
                                       const ts_mode_health mh[],
                                       const ts_trust *t);

/* A convergence study (after ts_convergence_estimate) as a new object:
 * {"analysis", "parameter", "target",
 *  "values": [{"name", "unit", "scale", "order", "reference",
 *              "reference_error", "reference_kind"}],
 *  "order": {NAME: observed order},
 *  "rows": [{"series", "setting", "h", "status", "message", "wall_s",
 *            "evaluations", "values": {NAME: v}, "errors": {NAME: e},
 *            "relative_errors": {NAME: e / scale}, "orders": {NAME: p},
 *            "max_relative_error", "meets_target", "trustworthy",
 *            "reasons", "notes"}],
 *  "recommended": setting or null, "recommended_series",
 *  "limiting_value", "prediction": {"setting", "wall_s"} or null,
 *  "work_precision": [{"series", "recommended", "rows": [{"setting",
 *                      "max_relative_error", "wall_s", "evaluations"}]}]}.
 * Rows are grouped by series, coarse to fine; a links setting is an
 * integer. NULL on allocation failure. */
TS_API json_t *ts_report_convergence_json(const ts_convergence *c);

/* The rows as CSV: series,setting,h,status,wall_s,evaluations,
 * trustworthy,max_relative_error, then <name>,<name>_error for every
 * value; same order as the JSON. */
TS_API int ts_report_convergence_csv(const ts_convergence *c,
                                     const char *path, ts_err *err);

/* The same in the display units d (towstab/units.h; NULL: SI): a value
 * shown in another unit than its own names its columns with it
 * ("sphere.z_ft", "sphere.z_ft_error"). */
TS_API int ts_report_convergence_csv_display(const ts_convergence *c,
                                             const ts_display *d,
                                             const char *path, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
