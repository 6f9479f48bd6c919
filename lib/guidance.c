/* guidance.c: waypoint guidance, the proportional heading law of Buckham
 * et al. (2003, section 4.1, Fig. 5): the rudder is proportional to the
 * difference between the vehicle's heading and the bearing of the next
 * waypoint, which is switched when the vehicle comes within a radius of it
 * (2 m in Buckham's runs). doc/guidance.md gives the law, the sign
 * conventions and the choice after the last waypoint (hold the last leg's
 * heading).
 *
 * Pure functions: the target's index is the caller's state. */
#include "towstab/guidance.h"

#include <math.h>
#include <stdio.h>

void ts_guidance_defaults(ts_guidance *g)
{
    g->nwaypoints = 0;
    g->start[0] = g->start[1] = 0.0;
    g->radius = TS_GUIDANCE_RADIUS;
    g->kp = 1.0;
    g->delta0 = 0.0;
    g->limit = INFINITY;
    g->line = 0;
}

double ts_wrap_pi(double a)
{
    if (a > -M_PI && a <= M_PI)
        return a;
    a = fmod(a, 2 * M_PI);     /* in (-2 pi, 2 pi) */
    if (a > M_PI)
        a -= 2 * M_PI;
    else if (a <= -M_PI)
        a += 2 * M_PI;
    return a;
}

/* Point i of the path: -1 the start, 0..n-1 the waypoints. */
static const double *path_point(const ts_guidance *g, int i)
{
    return i < 0 ? g->start : g->waypoint[i];
}

int ts_guidance_check(const ts_guidance *g, const char *where, ts_err *err)
{
    if (g->nwaypoints < 1 || g->nwaypoints > TS_GUIDANCE_MAX_WAYPOINTS)
        return ts_fail(err, TS_EINVAL,
                       "%s: needs 1 to %d waypoints, got %d", where,
                       TS_GUIDANCE_MAX_WAYPOINTS, g->nwaypoints);
    for (int i = -1; i < g->nwaypoints; i++) {
        const double *p = path_point(g, i);
        if (!isfinite(p[0]) || !isfinite(p[1]))
            return i < 0 ? ts_fail(err, TS_EINVAL,
                                   "%s.start: must be finite m, got (%g, %g)",
                                   where, p[0], p[1])
                         : ts_fail(err, TS_EINVAL,
                                   "%s.points[%d]: must be finite m, got "
                                   "(%g, %g)", where, i, p[0], p[1]);
    }
    if (!(g->radius > 0.0) || !isfinite(g->radius))
        return ts_fail(err, TS_EINVAL,
                       "%s.radius: must be > 0 m and finite, got %g m", where,
                       g->radius);
    if (!isfinite(g->kp))
        return ts_fail(err, TS_EINVAL, "%s.gain: must be finite, got %g",
                       where, g->kp);
    if (!isfinite(g->delta0))
        return ts_fail(err, TS_EINVAL,
                       "%s.bias: must be finite rad, got %g rad", where,
                       g->delta0);
    if (!(g->limit > 0.0))
        return ts_fail(err, TS_EINVAL, "%s.limit: must be > 0 rad, got %g rad",
                       where, g->limit);
    for (int i = 0; i < g->nwaypoints; i++) {
        const double *a = path_point(g, i - 1), *b = path_point(g, i);
        double d = hypot(b[0] - a[0], b[1] - a[1]);
        if (!(d > g->radius)) {
            char prev[32];
            if (i == 0)
                snprintf(prev, sizeof prev, "start");
            else
                snprintf(prev, sizeof prev, "points[%d]", i - 1);
            return ts_fail(err, TS_EINVAL,
                           "%s.points[%d]: must be farther than the radius "
                           "%g m from %s, got %g m", where, i, g->radius,
                           prev, d);
        }
    }
    return TS_OK;
}

double ts_guidance_distance(const ts_guidance *g, int index, double x,
                            double y)
{
    int i = index < 0 ? 0 : index >= g->nwaypoints ? g->nwaypoints - 1 : index;
    return hypot(g->waypoint[i][0] - x, g->waypoint[i][1] - y);
}

int ts_guidance_advance(const ts_guidance *g, int index, double x, double y)
{
    if (index < 0)
        index = 0;
    while (index < g->nwaypoints &&
           ts_guidance_distance(g, index, x, y) < g->radius)
        index++;
    return index;
}

double ts_guidance_bearing(const ts_guidance *g, int index, double x,
                           double y)
{
    if (index < 0)
        index = 0;
    if (index >= g->nwaypoints) {
        /* Past the last waypoint: hold the last leg's heading. */
        const double *a = path_point(g, g->nwaypoints - 2);
        const double *b = path_point(g, g->nwaypoints - 1);
        return ts_wrap_pi(atan2(b[1] - a[1], b[0] - a[0]));
    }
    /* atan2 gives -pi for a target dead astern on -0.0: wrapped to pi. */
    return ts_wrap_pi(atan2(g->waypoint[index][1] - y,
                            g->waypoint[index][0] - x));
}

double ts_guidance_error(const ts_guidance *g, int index, double x, double y,
                         double psi)
{
    return ts_wrap_pi(psi - ts_guidance_bearing(g, index, x, y));
}

double ts_guidance_rudder(const ts_guidance *g, double e)
{
    double d = g->delta0 + g->kp * e;
    return d > g->limit ? g->limit : d < -g->limit ? -g->limit : d;
}
