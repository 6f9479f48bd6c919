/* test_waypoints.c: the waypoint autopilot of simulate (a scene's
 * `waypoints` entry steering the towing vehicle's rudder; lib/scene.c,
 * lib/simulate.c; doc/guidance.md, "The autopilot in simulate").
 *
 *  1. The DOLPHIN-like towing vehicle of test/scenes/dolphin_waypoints.yaml
 *     (a sphere on 60 m of cable) on a course of three waypoints (a turn
 *     of 39 degrees to starboard, then one of 51 degrees more): every
 *     waypoint reached, in order, within the 2 m radius, at autopilot
 *     updates (multiples of the 0.5 s interval). Independently of the
 *     autopilot's own pose (a closed form of M's motion), the tow point's
 *     earth track (lib/track.c's quadrature, ts_history_value) at each
 *     reaching time lies within the radius plus the tow point's
 *     lever from the vehicle's origin (1.209 m) of the waypoint. After the last waypoint the law holds the last leg's
 *     heading (due +y): the track's direction over the last 10 s is
 *     pi/2 to 0.01 rad. The towfish's depth range and the tension
 *     extremes through the turn are reported and physical (the fish
 *     rises and falls, the tension drops in the turn).
 *  2. Refusals naming the key and line: waypoints without a towing
 *     vehicle, a rudder that is not a control surface, two waypoints
 *     closer than the radius, the linear model. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/analysis.h"
#include "towstab/output.h"
#include "towstab/simulate.h"

static const char *const SCENE = "test/scenes/dolphin_waypoints.yaml";

static void test_course(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, SCENE);
    if (!CHECK(sc != NULL, "scene %s loaded", SCENE))
        return;
    const ts_system *sys = sc->system;
    const ts_autopilot *ap = &sys->tow.autopilot;
    CHECK(ap->on && ap->g.nwaypoints == 3 && ap->nrudders == 2 &&
              ap->g.radius == 2.0 && ap->interval == 0.5,
          "waypoints read: %d points, %d rudders, radius %g m, every %g s",
          ap->g.nwaypoints, ap->nrudders, ap->g.radius, ap->interval);
    ts_err err = {0};
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.simulate.sim.t_end = 70;
    rq.simulate.sim.dt_sample = 0.5;
    snprintf(rq.simulate.outputs, sizeof rq.simulate.outputs,
             "tow.earth_x,tow.earth_y,fish.z");
    ts_result *r = NULL;
    int rc = ts_analysis_run(sys, &rq, &r, &err);
    if (!CHECK(rc == TS_OK && r && r->nonlinear, "course simulated (%s)",
               err.msg)) {
        ts_result_free(r);
        ts_request_clear(&rq);
        ts_scene_free(sc);
        return;
    }
    const ts_history *h = r->nonlinear;
    CHECK(h->nreached == 3, "all three waypoints reached: %d", h->nreached);
    for (int i = 0; i < h->nreached; i++) {
        const double *w = ap->g.waypoint[i];
        double t = h->reached_t[i];
        CHECK(h->reached_d[i] < ap->g.radius, "waypoint %d reached at t = "
              "%g s within the radius: %.4f m", i + 1, t, h->reached_d[i]);
        CHECK(i == 0 || t > h->reached_t[i - 1], "waypoint %d after the "
              "one before", i + 1);
        /* Updates every 0.5 s from t = 0: t / 0.5 whole to rounding. */
        CHECK(fabs(t / 0.5 - round(t / 0.5)) < 1e-9, "reached at an "
              "update: t = %.12g s", t);
        /* The sample at t (samples every 0.5 s from 0 as the updates). */
        int k = (int)lround(t / 0.5);
        double x = ts_history_value(r->sys, h, &r->outputs[0], k);
        double y = ts_history_value(r->sys, h, &r->outputs[1], k);
        double d = hypot(x - w[0], y - w[1]);
        /* The tow point is at (-0.6, 0, 1.05) m from the origin the
         * guidance steers, in body axes: heeled in the turn, its
         * horizontal offset is at most the lever's length 1.209 m, so
         * |d - reached_d| <= 1.209 m (the track's quadrature is good to
         * 1e-11 relative, TS_TRACK_RTOL: 1e-6 m of margin). */
        double lever = hypot(0.6, 1.05);
        CHECK(fabs(h->t[k] - t) < 1e-9 &&
                  fabs(d - h->reached_d[i]) <= lever + 1e-6,
              "tow point's earth track at t = %g s: %.4f m from waypoint "
              "%d (origin %.4f m)", h->t[k], d, i + 1, h->reached_d[i]);
    }
    /* The last leg is (110, 40) -> (110, 100): due +y. */
    int i1 = h->nsamples - 1, i0 = i1 - 20;
    double dx = ts_history_value(r->sys, h, &r->outputs[0], i1) -
                ts_history_value(r->sys, h, &r->outputs[0], i0);
    double dy = ts_history_value(r->sys, h, &r->outputs[1], i1) -
                ts_history_value(r->sys, h, &r->outputs[1], i0);
    CHECK(fabs(atan2(dy, dx) - M_PI / 2) < 0.01, "the last leg's heading "
          "held: track direction %.5f rad over the last 10 s",
          atan2(dy, dx));
    /* The fish (node 6) sinks as the vehicle slows in the turns and the
     * cable's pull drops; it starts at its equilibrium depth. */
    ts_depth_range dr[2];
    int nd = ts_history_depth_ranges(sys, h, -INFINITY, dr, 2);
    double lo = dr[0].min, hi = dr[0].max, thi = dr[0].t_max;
    CHECK(nd == 1 && !strcmp(sys->bodies[dr[0].body].name, "fish"),
          "one towed body's depth range: %d", nd);
    CHECK(fabs(lo - h->positions[3 * (sys->nnodes - 1) + 2]) < 1e-6 &&
              hi - lo > 0.5 && thi > h->reached_t[0],
          "fish depth %.4f m to %.4f m (at %g s, after the first turn "
          "began)", lo, hi, thi);
    CHECK(r->tensions && r->tow_force.min < 0.9 * r->tow_force.max,
          "tow force through the turns %.1f N to %.1f N", r->tow_force.min,
          r->tow_force.max);
    ts_result_free(r);

    /* The linear model has no autopilot: refused. */
    rq.simulate.linear = 1;
    r = NULL;
    rc = ts_analysis_run(sys, &rq, &r, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "linear: the waypoints (line"),
          "linear run refused: %.100s", err.msg);
    ts_result_free(r);
    ts_request_clear(&rq);
    ts_scene_free(sc);
}

/* The scene's text with `from` replaced by `to` (once), parsed; the
 * parse's error in *err. */
static int parse_edit(const ts_units *u, const char *text, const char *from,
                      const char *to, ts_err *err)
{
    const char *at = strstr(text, from);
    if (!CHECK(at != NULL, "the scene has \"%.40s\"", from))
        return TS_EINVAL;
    size_t n = strlen(text), k = (size_t)(at - text), lf = strlen(from),
           lt = strlen(to);
    char *t = malloc(n - lf + lt + 1);
    if (!t)
        return TS_ENOMEM;
    memcpy(t, text, k);
    memcpy(t + k, to, lt);
    memcpy(t + k + lt, at + lf, n - k - lf + 1);
    ts_scene *sc = ts_scene_parse(t, strlen(t), "edited", u, err);
    int rc = sc ? TS_OK : err->code;
    ts_scene_free(sc);
    free(t);
    return rc;
}

static void test_refused(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, SCENE);
    if (!sc)
        return;
    ts_err err = {0};
    /* Without a towing vehicle: the same waypoints on a prescribed tow. */
    const char *wp = strstr(sc->text, "waypoints:");
    const char *end = wp ? strstr(wp, "cables:") : NULL;
    if (CHECK(end != NULL, "the scene has a waypoints entry")) {
        char *t = malloc(strlen(wp) + 400);
        if (t) {
            snprintf(t, strlen(wp) + 400, "name: no_vehicle\ntow:\n  speed: "
                     "2 m/s\n%.*scables:\n  - name: c\n    from: tow\n    "
                     "length: 10 m\n    diameter: 0.01 m\n    weight: 1 "
                     "N/m\n", (int)(end - wp), wp);
            ts_scene *s2 = ts_scene_parse(t, strlen(t), "no_vehicle", u,
                                          &err);
            CHECK(!s2 && strstr(err.msg, "waypoints (line 4)") &&
                      strstr(err.msg, "no towing_vehicle"),
                  "waypoints without a towing vehicle refused: %.120s",
                  err.msg);
            ts_scene_free(s2);
            free(t);
        }
    }
    int rc = parse_edit(u, sc->text, "rudders: [rudder_upper, rudder_lower]",
                        "rudders: [rudder_upper, keel]", &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "waypoints.rudders[1] (line") &&
              strstr(err.msg, "'keel' is not a control surface"),
          "a fixed fin as rudder refused: %.120s", err.msg);
    rc = parse_edit(u, sc->text, "[\"110 m\", \"100 m\"]",
                    "[\"110 m\", \"41 m\"]", &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "waypoints.points[2]"),
          "waypoints closer than the radius refused: %.120s", err.msg);
    rc = parse_edit(u, sc->text, "interval: \"0.5 s\"", "interval: 0",
                    &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "waypoints.interval (line"),
          "a zero interval refused: %.120s", err.msg);
    ts_scene_free(sc);
}

int main(void)
{
    ts_units *u = tscene_units();
    test_course(u);
    test_refused(u);
    ts_units_free(u);
    return tc_done();
}
