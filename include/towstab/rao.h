/* towstab/rao.h: the ship's motion response amplitude operators (RAOs) and
 * the tow-point motion they give (doc/seastate.md, section 2).
 *
 * An RAO of degree of freedom j is the complex amplitude of the ship's
 * motion per metre of wave amplitude: for the wave elevation
 * eta(t) = a cos(w_e t) at the ship's reference point (w_e the encounter
 * frequency, towstab/sea.h), the motion is Re(RAO_j a e^(i w_e t)), so
 * arg RAO_j is the phase lead over the wave crest. Degrees of freedom, in
 * the mean ship frame M (x forward, y starboard, z down): surge, sway,
 * heave (m/m) and the small rotations roll, pitch, yaw about +x, +y, +z of
 * M (rad/m): roll lowers the starboard side, pitch raises the bow, yaw
 * turns the bow to starboard. RAOs are tabulated at wave frequencies w
 * (not encounter frequencies) and headings.
 *
 * Interpolation: in frequency, amplitude and the phase unwrapped along
 * the table (so that a phase turning through 180 deg between two rows does
 * not cancel the amplitude) by Steffen's monotone cubic (continuous slope,
 * no overshoot: an amplitude stays >= 0; linear for two rows); in
 * heading, linearly between the two tabulated headings around it (phase
 * difference taken in (-180, 180] deg). No extrapolation: a frequency or heading outside the
 * table is TS_EDOMAIN (a single-heading table serves only that heading).
 *
 * Tow point: at the lever arm r = (tow point) - (reference point), both in
 * M (m), the small rotation theta = (roll, pitch, yaw) moves it by
 * theta x r, so its translation per metre of wave amplitude is
 *   T = xi + theta x r:  T_x = xi_x + theta_y r_z - theta_z r_y,
 *                        T_y = xi_y + theta_z r_x - theta_x r_z,
 *                        T_z = xi_z + theta_x r_y - theta_y r_x,
 * complex, first order in the rotations (they are small: a few degrees).
 */
#ifndef TOWSTAB_RAO_H
#define TOWSTAB_RAO_H

#include "towstab/error.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    TS_DOF_SURGE = 0,
    TS_DOF_SWAY = 1,
    TS_DOF_HEAVE = 2,
    TS_DOF_ROLL = 3,
    TS_DOF_PITCH = 4,
    TS_DOF_YAW = 5,
    TS_NDOF = 6
};

/* Headings closer than this (rad) to a tabulated one use it as is. */
#define TS_RAO_HEADING_TOL 1e-9

typedef struct ts_rao ts_rao;

/* A table of nheading headings (rad, strictly increasing, within one
 * turn) by nfreq wave frequencies (rad/s, > 0, strictly increasing),
 * every RAO zero and no degree of freedom given. NULL on failure
 * (TS_EINVAL naming the value, TS_ENOMEM). */
TS_API ts_rao *ts_rao_alloc(int nheading, const double heading[], int nfreq,
                            const double omega[], ts_err *err);
TS_API void ts_rao_free(ts_rao *r);

/* Set RAO `dof` at heading index ih and frequency index k: amplitude
 * (>= 0; m/m for surge, sway, heave, rad/m for rotations) and phase (rad,
 * lead), in M's axes. Marks the degree of freedom as given. Call
 * ts_rao_finish after the last one (evaluation refuses a table changed
 * since). TS_EINVAL for bad indices or
 * values. */
TS_API int ts_rao_set(ts_rao *r, int dof, int ih, int k, double amplitude,
                      double phase, ts_err *err);

/* Unwrap the phases along frequency and build the interpolators: needed
 * after the last ts_rao_set and before evaluation (the CSV reader calls
 * it). TS_OK, TS_ENOMEM. */
TS_API int ts_rao_finish(ts_rao *r, ts_err *err);

/* Read a table from a CSV file (format in doc/seastate.md, section 2):
 * comment lines '#'; two property lines, "axes: z-down" (M: x forward,
 * y starboard, z down) or "axes: z-up" (x forward, y port, z up, the
 * usual seakeeping frame: its sway, heave, pitch and yaw are reversed on
 * reading) and "phase: lead" or "phase: lag" (lag phases are negated);
 * then the header, each column with its unit in brackets:
 *   frequency [Hz] | omega [rad/s] | period [s],  [heading [deg],]
 *   <dof> amp [unit], <dof> phase [unit], ...   for some of surge, sway,
 *   heave (unit of m/m), roll, pitch, yaw (of rad/m: deg/m, rad/m).
 * Without a heading column the table has one heading, NaN, which any
 * heading uses (ts_rao_headings says so). With one, every heading must
 * list the same frequencies. Degrees of freedom not in the file are zero.
 * TS_EIO, TS_EINVAL or TS_EUNIT naming the file, line and column. */
TS_API ts_rao *ts_rao_read_csv(const char *path, const ts_units *units,
                               ts_err *err);

/* Frequencies tabulated: lowest and highest (rad/s). */
TS_API void ts_rao_range(const ts_rao *r, double *omega_lo,
                         double *omega_hi);

/* Number of headings; heading[i] for i < n when `heading` is not NULL
 * (rad; a single NaN: the table has no heading column). */
TS_API int ts_rao_headings(const ts_rao *r, double *heading, int max);

/* 1 when degree of freedom `dof` was given. */
TS_API int ts_rao_has_dof(const ts_rao *r, int dof);

/* "surge", ..., "yaw". */
TS_API const char *ts_rao_dof_name(int dof);

/* TS_OK when `heading` (rad, any turn) is covered by the table, else
 * TS_EDOMAIN with a message listing the tabulated headings. */
TS_API int ts_rao_check_heading(const ts_rao *r, double heading,
                                ts_err *err);

/* The six RAOs at (heading, omega), interpolated: re[6], im[6] (M axes,
 * m/m and rad/m). TS_EDOMAIN outside the table. */
TS_API int ts_rao_eval(const ts_rao *r, double heading, double omega,
                       double re[TS_NDOF], double im[TS_NDOF], ts_err *err);

/* The tow point's translation per metre of wave amplitude, T = xi +
 * theta x lever (lever[3]: tow point less reference point, m, M axes):
 * re[3], im[3] (m/m, M axes). TS_EDOMAIN outside the table. */
TS_API int ts_rao_tow_point(const ts_rao *r, double heading, double omega,
                            const double lever[3], double re[3], double im[3],
                            ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
