/* towstab/report_seastate.h: the sea-state results as JSON (jansson) and
 * CSV (doc/seastate.md). SI units (m, N, s, rad/s); angles in degrees
 * with the unit in the key; a statistic is {"value", "error"} in the
 * output's unit. Files are written as towstab/report.h describes
 * (atomically, devices in place). Numbers that are not finite are JSON
 * null.
 */
#ifndef TOWSTAB_REPORT_SEASTATE_H
#define TOWSTAB_REPORT_SEASTATE_H

#include <jansson.h>

#include "towstab/error.h"
#include "towstab/seastate.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sea as JSON: {"spectrum": "pierson-moskowitz" | "jonswap" |
 * "table", "hs", "tp", "gamma", "normalisation", "heading_deg", "m0",
 * "source"}. NULL on allocation failure. */
TS_API json_t *ts_report_sea_json(const ts_sea *s);

/* A spectral result: {"output", "unit", "mean", "speed", "lever",
 * "band": {"from_rad_s", "to_rad_s", "wave_m0_band", "wave_m0_outside"},
 * "grid": {"intervals", "order_m0", "order_m2", "responses"},
 * "statistics": {"sigma", "significant_amplitude",
 * "significant_double_amplitude", "tz_s", "most_probable_maximum",
 * "most_probable_largest", "most_probable_smallest", "m0", "m2" (each
 * {"value", "error", "error_parts": {"grid", "band", "discretisation"}},
 * discretisation null when not estimated), "duration_s", "cycles"},
 * "discretisation": {"estimated", "links" [3], "order", "wall_s",
 * "links_needed"}, "trustworthy", "reasons", "notes"} and, with
 * `spectrum`, "points": [{"omega_rad_s", "omega_e_rad_s", "wave",
 * "gain_re", "gain_im", "density"}]. The largest and smallest are the mean
 * plus and minus the most probable maximum. NULL on allocation failure. */
TS_API json_t *ts_report_seastate_json(const ts_seastate *r, const ts_seaway *w,
                                       int spectrum);

/* The spectra as CSV, one row per grid point: omega_rad_s,
 * omega_e_rad_s, wave_m2_s_rad, then the real and imaginary part of each
 * input per metre of wave amplitude (tow.surge_re, tow.surge_im, ...),
 * gain_re, gain_im, gain_abs (output per m) and density_<unit>2_s_rad. */
TS_API int ts_report_seastate_csv(const ts_seastate *r, const char *path,
                                  ts_err *err);

/* The same in the display units d (towstab/units.h; NULL: SI): the wave
 * spectrum in length^2 s/rad, the gains in the output's unit per length,
 * the output's spectrum in its unit^2 s/rad, the columns named with the
 * units shown ("wave_ft2_s_rad", "gain_re_lbf_per_ft",
 * "density_lbf2_s_rad"); the wave frequencies stay in rad/s and the tow
 * point's RAOs (m/m) as they are. */
TS_API int ts_report_seastate_csv_display(const ts_seastate *r,
                                          const ts_display *d,
                                          const char *path, ts_err *err);

/* A record's statistics: {"samples", "duration_s", "mean", "mean_error",
 * "sigma":
 * {"value", "error"}, "corr_time_s", "independent_samples", "tz_s",
 * "maximum", "minimum", "window_lags"}. */
TS_API json_t *ts_report_record_json(const ts_record_stats *st);

#ifdef __cplusplus
}
#endif
#endif
