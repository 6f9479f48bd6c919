/* towstab/track.h: earth-frame tracks of a simulation (doc/simulate.md,
 * "Tracks in the earth frame"; doc/model.md sections 1 and 10).
 *
 * The earth frame E is the inertial frame R of doc/model.md section 1: x
 * and y horizontal, z down, coinciding with the mean ship frame M at
 * t = 0. M's origin moves at its speed V(t) along its own x axis and M
 * turns at Omega(t) about z, so its pose in E (origin x, y and heading
 * psi) is
 *
 *   psi(t) = integral_0^t Omega dt        (closed form, the excitation's)
 *   x(t)   = integral_0^t V cos psi dt,   y(t) = integral_0^t V sin psi dt,
 *
 * integrated here by GSL's CQUAD between consecutive sample times, split at
 * the excitation's breakpoints (where V or Omega is not smooth), to a
 * relative TS_TRACK_RTOL of the distance run. A point r of M is at
 * (x, y, 0) + Rz(psi) r in E: depth is the same in both frames.
 *
 * Positions m, heading rad (not wrapped: it counts whole turns).
 */
#ifndef TOWSTAB_TRACK_H
#define TOWSTAB_TRACK_H

#include "towstab/error.h"
#include "towstab/excitation.h"
#include "towstab/kernel.h"
#include "towstab/simulate.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Relative error of each integrated stretch of the origin's track. */
#define TS_TRACK_RTOL 1e-11

/* The pose of M in E at the n times t[n] (s, non-decreasing, t[0] >= 0):
 * pose[3 i] x, pose[3 i + 1] y (m), pose[3 i + 2] heading (rad), under the
 * manoeuvres of ex (NULL: none) from the frame `base` of t = 0 (its speed
 * and turn rate; rates ignored). TS_EINVAL for times out of order or
 * negative, TS_ENOMEM, TS_ECONV when the quadrature fails. */
TS_API int ts_track_poses(const ts_excitation *ex, const ts_frame *base,
                          int n, const double t[], double pose[],
                          ts_err *err);

/* The point r_M (M frame, m) in E for the pose[3] of M: (x, y, 0) +
 * Rz(heading) r_M. r_E may alias r_M. */
TS_API void ts_track_to_earth(const double pose[3], const double r_M[3],
                              double r_E[3]);

/* Fill h->frame (the poses of M at the times of h's samples) for a run
 * under ex (NULL: none; a linear run has no frame inputs: NULL) from the
 * frame `base`. Codes of ts_track_poses. */
TS_API int ts_track_history(ts_history *h, const ts_excitation *ex,
                            const ts_frame *base, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
