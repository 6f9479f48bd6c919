/* towstab/report_time.h: time histories, run statistics and the
 * linear-against-nonlinear comparison as JSON (jansson) and CSV
 * (doc/simulate.md, "Output"). SI throughout (m, N, s, J); phases in
 * degrees with the unit in the key. Files are written as
 * towstab/report.h describes (atomically, devices in place).
 */
#ifndef TOWSTAB_REPORT_TIME_H
#define TOWSTAB_REPORT_TIME_H

#include <jansson.h>

#include "towstab/compare.h"
#include "towstab/error.h"
#include "towstab/excitation.h"
#include "towstab/extremes.h"
#include "towstab/output.h"
#include "towstab/simulate.h"
#include "towstab/system.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Statistics of a run as a new JSON object: {method, steps, rejected,
 * evaluations, jacobians, recharts, restarts, t_reached, h_last, wall_s,
 * simulated_per_wall}. `method` names the integrator ("rk8pd", "expm").
 * NULL on allocation failure. */
TS_API json_t *ts_report_sim_stats_json(const ts_sim_stats *st,
                                        const char *method);

/* A history as a new JSON object: {"t": [...], "nodes": [{"name", "x":
 * [...], "y": [...], "z": [...]}], and for nonlinear runs (finite
 * tensions) "tensions": [{"cable", "index", "tension": [...]}] and
 * "energy": {"kinetic": [...], "potential": [...]}}. With node >= 0 only
 * that node is listed and tensions and energy are left out. NULL on
 * allocation failure. */
TS_API json_t *ts_report_history_json(const ts_system *sys,
                                       const ts_history *h, int node);

/* The channels outs[n] of history h as a new JSON object {"t": [...],
 * "outputs": {NAME: [...], ...}}: one array per channel the run gives
 * (a channel that is not finite at any sample, e.g. the tow force of a
 * linear run, is left out). NULL on allocation failure. */
TS_API json_t *ts_report_channels_json(const ts_system *sys,
                                       const ts_history *h, int n,
                                       const ts_output outs[]);

/* The full state of h added to the object o: "nodes" (every node's x, y,
 * z), "frame" {"x", "y", "heading"} (M's pose in the earth frame, m and
 * rad, towstab/track.h; once h->frame is filled), and for a nonlinear run
 * "tensions", "tow_force" {"x", "y", "z"} and "energy" (as
 * ts_report_history_json). TS_OK or TS_ENOMEM. */
TS_API int ts_report_history_full(json_t *o, const ts_system *sys,
                                  const ts_history *h);

/* Extremes (towstab/extremes.h) as a new JSON object {"max", "t_max",
 * "max_error", "min", "t_min", "min_error", "mean", "static",
 * "amplification", "from_s" (the first time considered: the window's
 * start)}; NaN values are null. */
TS_API json_t *ts_report_extremes_json(const ts_extremes *e);

/* The comparison summary as a new JSON object:
 * {"output", "excitation": {"axis", "type", "amplitude", "frequency_hz"},
 *  "window": {"from_s", "to_s", "samples"}, "equilibrium",
 *  "linear": {"amplitude_ratio", "phase_deg", "mean_offset", "half_range"},
 *  "nonlinear": {...}, "response_prediction": {"amplitude_ratio",
 *  "phase_deg"}, "amplitude_difference_pct", "mean_difference_pct",
 *  "rms_difference", "rms_difference_ratio"}; NaN values are null. */
TS_API json_t *ts_report_compare_json(const ts_compare *c);

/* The excitation as a JSON array of {"axis", "type", ...parameters}. */
TS_API json_t *ts_report_excitation_json(const ts_excitation *ex);

/* Write histories as CSV to `path` ("-": stdout), atomically: a header
 * "t_s,<node>.x_m,<node>.y_m,<node>.z_m,...,<cable>.<k>.tension_N,...",
 * one row per sample. Either history may be NULL; when both are given the
 * columns of each carry the prefix "nonlinear." or "linear." and the rows
 * run to the shorter one. Tensions are written for nonlinear runs only. */
TS_API int ts_report_history_csv(const ts_system *sys, const ts_history *nl,
                                 const ts_history *li, const char *path,
                                 ts_err *err);

/* The same in the display units d (towstab/units.h; NULL: SI), columns
 * named with them ("t_s", "sphere.x_ft", "cable.1.tension_lbf"). */
TS_API int ts_report_history_csv_display(const ts_system *sys,
                                         const ts_history *nl,
                                         const ts_history *li,
                                         const ts_display *d,
                                         const char *path, ts_err *err);

/* Write the channels outs[n] of the histories as CSV to `path` ("-":
 * stdout), atomically, in the display units d (NULL: SI): a header
 * "t_s,NAME_UNIT,..." (UNIT the channel's unit shown, m or N in SI; none
 * for a strain), one row per sample. Either history may be NULL; with
 * both, each column carries the prefix "nonlinear." or "linear." and the
 * rows run to the shorter one. Channels a run does not give (not finite
 * at any sample) are left out of its columns. */
TS_API int ts_report_channels_csv(const ts_system *sys, const ts_history *nl,
                                  const ts_history *li, int n,
                                  const ts_output outs[], const ts_display *d,
                                  const char *path, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
