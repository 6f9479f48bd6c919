/* test_guidance.c: the waypoint guidance (lib/guidance.c) on analytic
 * cases.
 *
 *  1. Wrapping into (-pi, pi]: the ends, multiples of 2 pi, both signs.
 *  2. Bearing and heading error: a 3-4-5 triangle; an error across the
 *     +-pi cut takes the short way round.
 *  3. Switching: strictly inside the radius only; several close
 *     waypoints passed in one call; the index kept past the last one.
 *  4. After the last waypoint the law holds the last leg's heading (from
 *     the start with a single waypoint).
 *  5. The rudder: bias plus gain times error, limited.
 *  6. Closed loop with a kinematic vehicle (speed U, yaw rate -c delta):
 *     toward a far waypoint the error decays as e0 exp(-c kp t); on a
 *     square course every waypoint is reached in order and the vehicle
 *     leaves on the last leg's heading.
 *  7. Bad descriptions refused, naming the key.
 * Tolerances are stated at each check with their reason. */
#include "towstab/guidance.h"

#include <math.h>
#include <string.h>

#include "tcheck.h"

/* Round-off of a few operations on angles of order pi. */
#define TOL_ANGLE 1e-14

static void test_wrap(void)
{
    CHECK_NEAR(ts_wrap_pi(M_PI), M_PI, 0, "wrap(pi) = pi");
    CHECK_NEAR(ts_wrap_pi(-M_PI), M_PI, TOL_ANGLE, "wrap(-pi) = pi");
    CHECK_NEAR(ts_wrap_pi(1.5 * M_PI), -0.5 * M_PI, TOL_ANGLE,
               "wrap(3 pi/2) = -pi/2");
    CHECK_NEAR(ts_wrap_pi(-2.385), -2.385, 0, "wrap of an angle inside");
    CHECK_NEAR(ts_wrap_pi(2.385 + 6 * M_PI), 2.385, 1e-13,
               "wrap(2.385 + 6 pi)");
    CHECK_NEAR(ts_wrap_pi(-2.385 - 4 * M_PI), -2.385, 1e-13,
               "wrap(-2.385 - 4 pi)");
    CHECK_NEAR(ts_wrap_pi(-3 * M_PI), M_PI, 1e-13, "wrap(-3 pi) = pi");
}

static ts_guidance course(void)
{
    ts_guidance g;
    ts_guidance_defaults(&g);
    g.start[0] = 1.5;
    g.start[1] = -2.25;
    g.nwaypoints = 3;
    g.waypoint[0][0] = 4.5;   /* 3, 4 from the start */
    g.waypoint[0][1] = 1.75;
    g.waypoint[1][0] = 4.5;
    g.waypoint[1][1] = 31.75;
    g.waypoint[2][0] = -25.5;
    g.waypoint[2][1] = 31.75;
    return g;
}

static void test_bearing(void)
{
    ts_guidance g = course();
    CHECK_NEAR(ts_guidance_bearing(&g, 0, 1.5, -2.25), atan2(4.0, 3.0),
               TOL_ANGLE, "bearing of a 3-4-5 leg");
    CHECK_NEAR(ts_guidance_distance(&g, 0, 1.5, -2.25), 5.0, 1e-14,
               "distance of a 3-4-5 leg");
    /* Waypoint 2 dead astern of (4.5, 31.75) on -0.0 gives atan2 = pi. */
    CHECK_NEAR(ts_guidance_bearing(&g, 2, 10.0, 31.75), M_PI, 0,
               "bearing of a target on -x: pi, not -pi");
    /* Heading 3.0 rad against a bearing of -3.0 rad: the short way, an
     * error of 6 - 2 pi (to port of the bearing across the cut). */
    double x = 0, y = 0;
    ts_guidance h;
    ts_guidance_defaults(&h);
    h.nwaypoints = 1;
    h.start[0] = 5;
    h.waypoint[0][0] = 100 * cos(-3.0);
    h.waypoint[0][1] = 100 * sin(-3.0);
    CHECK_NEAR(ts_guidance_error(&h, 0, x, y, 3.0), 6.0 - 2 * M_PI, 1e-13,
               "error across the cut: 6 - 2 pi");
    CHECK_NEAR(ts_guidance_error(&h, 0, x, y, -3.0 + 0.25), 0.25, 1e-13,
               "error of a heading 0.25 rad to starboard");
}

static void test_switching(void)
{
    ts_guidance g = course();
    CHECK(ts_guidance_advance(&g, 0, 1.5, -2.25) == 0,
          "5 m away: the target stays");
    /* 1.999 m from waypoint 0: reached (radius 2 m). */
    CHECK(ts_guidance_advance(&g, 0, 4.5 - 1.999, 1.75) == 1,
          "within 2 m: next waypoint");
    CHECK(ts_guidance_advance(&g, 0, 4.5 - 2.0, 1.75) == 0,
          "exactly at the radius: not yet");
    CHECK(ts_guidance_advance(&g, -3, 4.5, 1.75) == 1,
          "a negative index is taken as 0");
    g.radius = 35.0;
    CHECK(ts_guidance_advance(&g, 0, 4.5, 1.75) == 2,
          "radius 35 m: waypoints 0 and 1 passed in one call");
    g.radius = 100.0;
    CHECK(ts_guidance_advance(&g, 0, 4.5, 1.75) == 3,
          "all reached: index = nwaypoints");
    CHECK(ts_guidance_advance(&g, 3, 500, 500) == 3,
          "past the last: the index stays");
}

static void test_after_last(void)
{
    ts_guidance g = course();
    /* Last leg from (4.5, 31.75) to (-25.5, 31.75): heading pi. */
    CHECK_NEAR(ts_guidance_bearing(&g, 3, -40.0, 12.0), M_PI, TOL_ANGLE,
               "after the last: the last leg's heading, wherever it is");
    CHECK_NEAR(ts_guidance_error(&g, 3, -40.0, 12.0, -M_PI + 0.125), 0.125,
               1e-13, "and its error");
    ts_guidance h;
    ts_guidance_defaults(&h);
    h.nwaypoints = 1;
    h.start[0] = 1.5;
    h.start[1] = -2.25;
    h.waypoint[0][0] = 4.5;
    h.waypoint[0][1] = 1.75;
    CHECK_NEAR(ts_guidance_bearing(&h, 1, 100.0, -7.0), atan2(4.0, 3.0),
               TOL_ANGLE, "a single waypoint: the heading from the start");
}

static void test_rudder(void)
{
    ts_guidance g;
    ts_guidance_defaults(&g);
    g.kp = -1.75;
    g.delta0 = 0.0125;
    g.limit = 0.4;
    CHECK_NEAR(ts_guidance_rudder(&g, 0.1), 0.0125 - 0.175, 1e-15,
               "rudder inside the limit: delta0 + kp e");
    CHECK_NEAR(ts_guidance_rudder(&g, 1.0), -0.4, 0, "rudder at -limit");
    CHECK_NEAR(ts_guidance_rudder(&g, -2.0), 0.4, 0, "rudder at +limit");
    g.limit = INFINITY;
    CHECK_NEAR(ts_guidance_rudder(&g, -2.0), 0.0125 + 3.5, 1e-15,
               "no limit");
}

/* A kinematic vehicle: x' = U cos psi, y' = U sin psi, psi' = -c delta
 * (a positive rudder turns it to port), the rudder from the law. Classic
 * RK4 with the target switched between steps, as a simulator does. */
typedef struct {
    double U, c;
    const ts_guidance *g;
    int index;
} boat;

static void boat_rhs(const boat *b, const double s[3], double d[3])
{
    double e = ts_guidance_error(b->g, b->index, s[0], s[1], s[2]);
    d[0] = b->U * cos(s[2]);
    d[1] = b->U * sin(s[2]);
    d[2] = -b->c * ts_guidance_rudder(b->g, e);
}

static void boat_step(const boat *b, double s[3], double h)
{
    double k1[3], k2[3], k3[3], k4[3], t[3];
    boat_rhs(b, s, k1);
    for (int i = 0; i < 3; i++) t[i] = s[i] + 0.5 * h * k1[i];
    boat_rhs(b, t, k2);
    for (int i = 0; i < 3; i++) t[i] = s[i] + 0.5 * h * k2[i];
    boat_rhs(b, t, k3);
    for (int i = 0; i < 3; i++) t[i] = s[i] + h * k3[i];
    boat_rhs(b, t, k4);
    for (int i = 0; i < 3; i++)
        s[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}

static void test_closed_loop(void)
{
    /* Far waypoint (10 km): the bearing moves by at most U t e0 / L
     * ~ 2.5e-4 rad over the 5 s run, so e(t) = e0 exp(-c kp t) to that. */
    ts_guidance g;
    ts_guidance_defaults(&g);
    g.nwaypoints = 1;
    g.start[0] = -1.0;
    g.waypoint[0][0] = 1e4;
    g.waypoint[0][1] = 0.0;
    g.kp = 0.8;
    boat b = {2.5, 0.6, &g, 0};
    double s[3] = {0, 0, 0.35};
    double h = 0.01;
    for (int i = 0; i < 500; i++)
        boat_step(&b, s, h);
    double e = ts_guidance_error(&g, 0, s[0], s[1], s[2]);
    CHECK_NEAR(e, 0.35 * exp(-0.6 * 0.8 * 5.0), 3e-4,
               "far waypoint: error decays as e0 exp(-c kp t) (to the "
               "bearing's drift U t e0 / L)");

    /* A square course of 60 m sides at 2.5 m/s, rudder limited. */
    ts_guidance q;
    ts_guidance_defaults(&q);
    q.nwaypoints = 4;
    double wp[4][2] = {{60, 0}, {60, 60}, {0, 60}, {0, 0}};
    memcpy(q.waypoint, wp, sizeof wp);
    q.kp = 1.5;
    q.limit = 0.5;
    CHECK(ts_guidance_check(&q, "waypoints", NULL) == TS_OK,
          "square course is valid");
    boat sq = {2.5, 0.6, &q, 0};
    double z[3] = {0, 0, 0};
    double closest[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    int order_ok = 1;
    for (int i = 0; i < 20000 && sq.index < 4; i++) {
        boat_step(&sq, z, h);
        for (int k = 0; k < 4; k++)
            closest[k] = fmin(closest[k],
                              ts_guidance_distance(&q, k, z[0], z[1]));
        int next = ts_guidance_advance(&q, sq.index, z[0], z[1]);
        if (next > sq.index + 1)
            order_ok = 0;
        sq.index = next;
    }
    CHECK(sq.index == 4, "square: every waypoint reached (index %d)",
          sq.index);
    CHECK(order_ok, "square: one waypoint at a time");
    for (int k = 0; k < 4; k++)
        CHECK(closest[k] < q.radius,
              "square: came within %.3f m < 2 m of waypoint %d", closest[k],
              k);
    /* Then 40 s on: the heading settles on the last leg's, -pi/2. */
    for (int i = 0; i < 4000; i++)
        boat_step(&sq, z, h);
    CHECK_NEAR(ts_wrap_pi(z[2] + M_PI / 2), 0.0, 1e-6,
               "after the last: heading of the last leg (decays as "
               "exp(-0.9 t), 1e-6 after 40 s)");
}

static void test_bad(void)
{
    ts_err err;
    ts_guidance g = course();
    ts_err_clear(&err);
    g.nwaypoints = 0;
    CHECK(ts_guidance_check(&g, "waypoints (line 7)", &err) == TS_EINVAL &&
          strstr(err.msg, "waypoints (line 7): needs 1 to 64 waypoints"),
          "no waypoint: %s", err.msg);
    g = course();
    g.radius = -2;
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_EINVAL &&
          strstr(err.msg, "waypoints.radius: must be > 0 m"),
          "negative radius: %s", err.msg);
    g = course();
    g.waypoint[1][1] = NAN;
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_EINVAL &&
          strstr(err.msg, "waypoints.points[1]: must be finite"),
          "NaN waypoint: %s", err.msg);
    g = course();
    g.waypoint[2][0] = 4.5;
    g.waypoint[2][1] = 33.0;
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_EINVAL &&
          strstr(err.msg, "waypoints.points[2]: must be farther than the "
                          "radius 2 m from points[1], got 1.25 m"),
          "waypoints too close: %s", err.msg);
    g = course();
    g.start[0] = 4.0;
    g.start[1] = 1.0;
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_EINVAL &&
          strstr(err.msg, "from start"), "first waypoint at the start: %s",
          err.msg);
    g = course();
    g.limit = 0;
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_EINVAL &&
          strstr(err.msg, "waypoints.limit: must be > 0 rad"),
          "zero limit: %s", err.msg);
    g = course();
    g.kp = INFINITY;
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_EINVAL &&
          strstr(err.msg, "waypoints.gain: must be finite"),
          "infinite gain: %s", err.msg);
    g = course();
    CHECK(ts_guidance_check(&g, "waypoints", &err) == TS_OK,
          "the course itself is valid");
}

int main(void)
{
    test_wrap();
    test_bearing();
    test_switching();
    test_after_last();
    test_rudder();
    test_closed_loop();
    test_bad();
    return tc_done();
}
