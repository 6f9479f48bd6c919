/* towstab/guidance.h: waypoint guidance of a towing vehicle, the
 * proportional heading law toward the next waypoint (doc/guidance.md;
 * doc/model.md section 10; Buckham et al. 2003, section 4.1 and Fig. 5).
 *
 * Earth frame E: the inertial frame of doc/model.md section 1 (x and y
 * horizontal, z down), its origin and axes those of the mean ship frame M
 * at t = 0. A heading psi is the angle of the vehicle's x axis from E's x
 * axis, positive toward +y (to starboard, about +z down). Positions in m,
 * angles in rad.
 *
 * The law: the target is waypoint `index`; its bearing from the vehicle at
 * (x, y) is chi = atan2(y_w - y, x_w - x); the heading error is
 * e = wrap(psi - chi), wrapped into (-pi, pi] (measured less wanted, the
 * convention of the vehicle's loops, towstab/vehicle.h); the rudder command
 * is delta = delta0 + kp e, limited to +-limit. A vehicle within `radius`
 * of its target has reached it and the next waypoint becomes the target
 * (Buckham's 2 m). After the last waypoint the law holds the heading of
 * the last leg: the bearing from the waypoint before it (or, with a single
 * waypoint, from `start`) to the last one.
 *
 * Everything here is a pure function of its arguments: the only state of
 * the guidance is the target's index, which the caller keeps (a simulator
 * advances it between steps, ts_guidance_advance). No globals, no
 * allocation.
 */
#ifndef TOWSTAB_GUIDANCE_H
#define TOWSTAB_GUIDANCE_H

#include "towstab/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_GUIDANCE_MAX_WAYPOINTS 64
#define TS_GUIDANCE_RADIUS 2.0   /* default switching radius, m (Buckham) */

typedef struct ts_guidance {
    int nwaypoints;                 /* 1..TS_GUIDANCE_MAX_WAYPOINTS */
    double waypoint[TS_GUIDANCE_MAX_WAYPOINTS][2]; /* x, y in E, m */
    double start[2];  /* where the vehicle starts (E, m): the leg before
                         the first waypoint */
    double radius;    /* switching radius, m, > 0 (TS_GUIDANCE_RADIUS) */
    double kp;        /* rudder per heading error, rad/rad (its sign is
                         the rudder's: the law turns the vehicle toward
                         the target when kp times the rudder's yaw
                         moment per rad is negative) */
    double delta0;    /* rudder bias, rad */
    double limit;     /* largest |rudder|, rad, > 0 (INFINITY: none) */
    int line;         /* scene line, 0 if none */
} ts_guidance;

#define TS_AUTOPILOT_MAX_RUDDERS 4
#define TS_AUTOPILOT_INTERVAL 0.5  /* default update interval, s */
#define TS_AUTOPILOT_NAME_MAX 64

/* A scene's waypoint autopilot (the `waypoints` entry, doc/guidance.md,
 * "The autopilot in simulate"): the guidance (its start is the towing
 * vehicle's position at the start of a run, set by the simulator), the
 * towing vehicle's control surfaces that take the rudder command (each the
 * whole command), and the update interval: the command is computed from
 * the vehicle's earth-frame position and heading every `interval` seconds
 * and held in between. */
typedef struct ts_autopilot {
    int on;                         /* 1: the scene gives waypoints */
    ts_guidance g;
    int nrudders;                   /* 1..TS_AUTOPILOT_MAX_RUDDERS */
    char rudder[TS_AUTOPILOT_MAX_RUDDERS][TS_AUTOPILOT_NAME_MAX];
    double interval;                /* s, > 0 */
} ts_autopilot;

/* Defaults: no waypoint, start at the origin, radius TS_GUIDANCE_RADIUS,
 * kp 1, delta0 0, no limit. */
TS_API void ts_guidance_defaults(ts_guidance *g);

/* Validate: 1..TS_GUIDANCE_MAX_WAYPOINTS finite waypoints, radius > 0,
 * finite kp and delta0, limit > 0, and no two consecutive points of the
 * path (start, waypoints) closer than the radius (the leg's heading would
 * be undefined). `where` names it in messages ("waypoints (line 12)").
 * TS_OK or TS_EINVAL naming the key. */
TS_API int ts_guidance_check(const ts_guidance *g, const char *where,
                             ts_err *err);

/* An angle wrapped into (-pi, pi] (rad). */
TS_API double ts_wrap_pi(double a);

/* The target after reaching every waypoint within the radius of (x, y):
 * from `index`, advance while the target is within g->radius (so a
 * vehicle may pass several close waypoints in one call). Returns the new
 * index, g->nwaypoints when the last one has been reached. index < 0 is
 * taken as 0. */
TS_API int ts_guidance_advance(const ts_guidance *g, int index, double x,
                               double y);

/* The heading wanted at (x, y) with target `index` (rad, in (-pi, pi]):
 * the bearing of the target, or after the last waypoint (index >=
 * nwaypoints) the heading of the last leg. */
TS_API double ts_guidance_bearing(const ts_guidance *g, int index, double x,
                                  double y);

/* The heading error wrap(psi - ts_guidance_bearing), rad in (-pi, pi]. */
TS_API double ts_guidance_error(const ts_guidance *g, int index, double x,
                                double y, double psi);

/* The rudder command of heading error e: delta0 + kp e limited to
 * +-limit (rad). */
TS_API double ts_guidance_rudder(const ts_guidance *g, double e);

/* Distance from (x, y) to the point of index `index` (m): a waypoint, or
 * with index >= nwaypoints the last one. */
TS_API double ts_guidance_distance(const ts_guidance *g, int index, double x,
                                   double y);

#ifdef __cplusplus
}
#endif
#endif
