/* towstab/report.h: results as JSON (jansson) and CSV, written safely.
 *
 * Every number is SI (m, N, s) except angles, which carry their unit in the
 * key (theta1_deg). A regular file (or a new one) is written to a
 * temporary name in the same folder and renamed when complete, so a failed
 * run never leaves a file that looks finished; a device or FIFO
 * (/dev/null, a named pipe) is written in place and never replaced; a
 * symbolic link is followed and kept; "-" means standard output. Every
 * write, the flush and the close are checked (TS_EIO naming the file).
 */
#ifndef TOWSTAB_REPORT_H
#define TOWSTAB_REPORT_H

#include <jansson.h>
#include <stddef.h>

#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/health.h"
#include "towstab/system.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* {"trustworthy": bool, "reasons": [text], "notes": [text]} plus
 * "dropped": n when reasons or notes were dropped. NULL on allocation
 * failure. */
TS_API json_t *ts_report_trust_json(const ts_trust *t);

/* Add the keys of ts_report_trust_json(t) to object o. TS_OK or
 * TS_ENOMEM. */
TS_API int ts_report_trust_into(json_t *o, const ts_trust *t);

/* The equilibrium as a new JSON object: converged, iterations, evaluations,
 * residual, force_scale, tolerance, method, speed, turn_rate, wall_s,
 * top_tension, min_tension, tow_force, condition, shape_error, with a
 * verdict `trust` (may be NULL: left out) trustworthy, reasons [text],
 * notes [text] (towstab/health.h), nodes [{name,x,y,z}] (tow point
 * first), links [{cable,index,tension,theta1_deg,theta2_deg}], bodies
 * [{name,x,y,z}], and with vehicles, vehicles [ts_report_vehicle_json]
 * and control_residual. NULL on allocation failure. */
TS_API json_t *ts_report_equilibrium_json(const ts_system *sys,
                                          const ts_equilibrium *eq,
                                          double wall_s,
                                          const ts_trust *trust);

/* A vehicle's state as a new JSON object: name, x, y, depth (its origin,
 * m, M frame), pitch_deg, roll_deg, yaw_deg (yaw-pitch-roll relative to
 * M), alpha_deg, beta_deg (the flow at its origin), speed, submerged,
 * joint_force (N, M), hydro_force, hydro_moment (all components; body
 * axes, N and N m about the origin), munk_moment, mass_centre (m, M),
 * components [{name, type, force, moment, alpha_deg, speed, and for a
 * control surface deflection_deg}] (body axes), controllers [{name,
 * error, output_deg}]. NULL on allocation failure. */
TS_API json_t *ts_report_vehicle_json(const ts_system *sys,
                                      const ts_vehicle_result *r);

/* Write a JSON value to `path` ("-": stdout), indented, as above. */
TS_API int ts_report_write_json(const json_t *value, const char *path,
                                ts_err *err);

/* Write `len` bytes of `text` (a page, any document made in memory) to
 * `path` ("-": stdout), as above. TS_OK, or TS_EIO naming the file. */
TS_API int ts_report_write_text(const char *text, size_t len,
                                const char *path, ts_err *err);

/* Write the node table "node,x_m,y_m,z_m,tension_above_N" as CSV. */
TS_API int ts_report_equilibrium_csv(const ts_system *sys,
                                     const ts_equilibrium *eq,
                                     const char *path, ts_err *err);

/* The same in the display units d (towstab/units.h; NULL: SI), the
 * columns named with them ("x_ft", "tension_above_lbf"). */
TS_API int ts_report_equilibrium_csv_display(const ts_system *sys,
                                             const ts_equilibrium *eq,
                                             const ts_display *d,
                                             const char *path, ts_err *err);

/* Refuse outputs that name the same file: paths[n] (NULL entries are
 * skipped) are compared by what they resolve to (device and inode, links
 * followed; for a file still to be made, its directory and name), so
 * "out.json" and "./out.json" are the same. what[i] names each in the
 * message ("--json"). Devices (/dev/null) may be shared; standard output
 * ("-", /dev/stdout) may not. Returns TS_OK or TS_EINVAL. */
TS_API int ts_report_check_targets(int n, const char *const what[],
                                   const char *const paths[], ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
