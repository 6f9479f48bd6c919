/* towstab/report_linear.h: the linear-stability results as JSON (jansson)
 * and CSV (doc/linear.md). SI units throughout (1/s, Hz, s, m, N); phases
 * in degrees with the unit in the key. Files are written as
 * towstab/report.h describes (atomically, devices in place). Numbers that are not finite
 * are written as JSON null and as "nan"/"inf" in CSV.
 */
#ifndef TOWSTAB_REPORT_LINEAR_H
#define TOWSTAB_REPORT_LINEAR_H

#include <jansson.h>

#include "towstab/eigen.h"
#include "towstab/error.h"
#include "towstab/linearize.h"
#include "towstab/response.h"
#include "towstab/system.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The linearization as JSON: nstate, nq, ninput, inputs (names),
 * trunc_err, trunc_norm, b_trunc_err, a_scale, kinks, kink_tow,
 * evaluations, threads; with `matrices`, also "A" [n][n] and "B" [n][9]
 * as arrays of rows. NULL on allocation failure. */
TS_API json_t *ts_report_linear_json(const ts_linear *lin, int matrices);

/* The mode report: {"stable", "verdict", "max_real", "max_real_error",
 * "complete", "method", "target_hz", "nstate", "nmodes", "kinks",
 * "modes": [{"re", "im", "freq_hz", "period_s", "damping_ratio",
 * "time_constant_s", "condition", "error_bound", "residual",
 * "description"}]}; with `shapes` (needs vectors) each mode also has
 * "shape": [{"node", "x_amp", "x_phase_deg", "y_amp", ..., "z_phase_deg"}].
 * NULL on allocation failure. */
TS_API json_t *ts_report_modes_json(const ts_system *sys,
                                    const ts_linear *lin, const ts_eigen *e,
                                    int shapes);

/* The mode table as CSV: mode,re_per_s,im_rad_per_s,freq_hz,period_s,
 * damping_ratio,time_constant_s,condition,error_bound,description. */
TS_API int ts_report_modes_csv(const ts_system *sys, const ts_linear *lin,
                               const ts_eigen *e, const char *path,
                               ts_err *err);

/* Mode shapes as CSV, one row per mode and node: mode,freq_hz,node,
 * x_amp,x_phase_deg,y_amp,y_phase_deg,z_amp,z_phase_deg (amplitudes
 * normalised to 1 at the largest component of each mode). */
TS_API int ts_report_shapes_csv(const ts_system *sys, const ts_linear *lin,
                                const ts_eigen *e, const char *path,
                                ts_err *err);

/* The mode table and the mode shapes in the display units d
 * (towstab/units.h; NULL: SI, as above): Im as a turn rate, frequencies,
 * periods, time constants and phases in theirs, a column in another unit
 * than SI named with it ("freq_mHz", "period_min", "x_phase_rad"). */
TS_API int ts_report_modes_csv_display(const ts_system *sys,
                                       const ts_linear *lin,
                                       const ts_eigen *e,
                                       const ts_display *d, const char *path,
                                       ts_err *err);
TS_API int ts_report_shapes_csv_display(const ts_system *sys,
                                        const ts_linear *lin,
                                        const ts_eigen *e,
                                        const ts_display *d,
                                        const char *path, ts_err *err);

/* The frequency response: {"input", "output", "unit", "static_gain",
 * "points": [{"freq_hz", "magnitude", "phase_deg", "re", "im"}]}. */
TS_API json_t *ts_report_response_json(const ts_response *r);

/* The same as CSV: freq_hz,magnitude,phase_deg,re,im. */
TS_API int ts_report_response_csv(const ts_response *r, const char *path,
                                  ts_err *err);

/* The same in the display units d (towstab/units.h; NULL: SI): a
 * frequency or gain shown in another unit names its columns with it
 * ("freq_Hz", "magnitude_lbf_per_ft", "re_lbf_per_ft", ...). */
TS_API int ts_report_response_csv_display(const ts_response *r,
                                          const ts_display *d,
                                          const char *path, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
