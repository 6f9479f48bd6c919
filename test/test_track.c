/* test_track.c: the earth-frame tracks (lib/track.c) against closed
 * forms and invariants.
 *
 *  1. A steady turn from t = 0: M's origin on the circle
 *     (V/Omega sin Omega t, V/Omega (1 - cos Omega t)), heading Omega t.
 *  2. A speed step (quintic over its rise): the distance run is
 *     V0 t + A (t - start - rise / 2) after the step (the quintic's mean
 *     over its rise is 1/2), with no sideways motion.
 *  3. A ramped turn rate (no closed form): after the ramp, the origin
 *     runs on a circle of radius V / Omega_1 whose centre, found from
 *     the pose at each later time, stays put.
 *  4. A point of M to E: a rotation by the heading plus the origin.
 *  5. A simulation of Kamman's steady turn (example 3) from its
 *     equilibrium: the sphere at rest in M runs on a circle about the turn
 *     centre (0, V/Omega) of E, its earth channels from ts_history_value;
 *     the earth channels are refused outside a simulation; the full
 *     state's JSON carries the poses. The tracks are computed only when
 *     asked (the pictures, an earth channel, the full state): the frame
 *     stays NaN otherwise, and is the same however it was asked.
 *  6. A straight-line speed change of a towing vehicle (a thrust step):
 *     the steady speed over the ground from its earth track against the
 *     Newton trim at the stepped thrust.
 *  7. The constant-power law in the time domain: T U = P at every sample
 *     of a towing vehicle slowed by a force step.
 *  8. Bad times refused.
 * Tolerances are stated at each check with their reason. */
#include "towstab/track.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/analysis.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/simulate.h"
#include "towstab/vehicle.h"
#include "towstab/output.h"
#include "towstab/report_time.h"

/* The quadrature's relative tolerance TS_TRACK_RTOL times distances of
 * tens of m, summed over up to 100 stretches, with margin. */
#define TOL_TRACK 1e-8

static void test_steady_turn(void)
{
    ts_frame base = {0};
    base.speed = 2.385;
    base.turn_rate = 0.1375;
    double t[50], pose[150];
    for (int i = 0; i < 50; i++)
        t[i] = 0.9 * i;
    int rc = ts_track_poses(NULL, &base, 50, t, pose, NULL);
    double R = base.speed / base.turn_rate, worst = 0, worst_psi = 0;
    for (int i = 0; i < 50; i++) {
        double w = base.turn_rate * t[i];
        worst = fmax(worst, hypot(pose[3 * i] - R * sin(w),
                                  pose[3 * i + 1] - R * (1 - cos(w))));
        worst_psi = fmax(worst_psi, fabs(pose[3 * i + 2] - w));
    }
    CHECK(rc == TS_OK && worst < TOL_TRACK,
          "steady turn: origin on the circle of radius V/Omega = %.4f m to "
          "%.2g m (tolerance %.0e m)", R, worst, TOL_TRACK);
    CHECK(worst_psi < 1e-14, "steady turn: heading Omega t to %.2g rad",
          worst_psi);
}

static void test_speed_step(const ts_units *u)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_excitation_parse(ex, "speed:step,by=0.75,start=2.5,rise=1.5", u,
                        "test", &err);
    ts_frame base = {0};
    base.speed = 1.25;
    double t[4] = {1.0, 2.5, 5.25, 11.0}, pose[12];
    int rc = ts_track_poses(ex, &base, 4, t, pose, &err);
    CHECK(rc == TS_OK, "speed step: integrated (%s)", err.msg);
    CHECK_NEAR(pose[0], 1.25, TOL_TRACK, "before the step: V0 t");
    CHECK_NEAR(pose[3], 1.25 * 2.5, TOL_TRACK, "at its start: V0 t");
    CHECK_NEAR(pose[6], 1.25 * 5.25 + 0.75 * (5.25 - 2.5 - 0.75), TOL_TRACK,
               "after it: V0 t + A (t - start - rise/2)");
    CHECK_NEAR(pose[9], 1.25 * 11.0 + 0.75 * (11.0 - 2.5 - 0.75), TOL_TRACK,
               "long after it");
    CHECK(pose[10] == 0 && pose[11] == 0,
          "no sideways motion, no heading change");
    ts_excitation_free(ex);
}

static void test_ramped_turn(const ts_units *u)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_excitation_parse(ex, "turn_rate:ramp,to=0.2rad/s,start=1,duration=4",
                        u, "test", &err);
    ts_frame base = {0};
    base.speed = 3.125;
    enum { N = 40 };
    double t[N], pose[3 * N];
    for (int i = 0; i < N; i++)
        t[i] = 6.0 + 1.7 * i; /* after the ramp (ends at 5.1 s) */
    int rc = ts_track_poses(ex, &base, N, t, pose, &err);
    double R = base.speed / 0.2, cx[N], cy[N], spread = 0;
    for (int i = 0; i < N; i++) {
        /* The centre is R to starboard of the heading. */
        double psi = pose[3 * i + 2];
        cx[i] = pose[3 * i] - R * sin(psi);
        cy[i] = pose[3 * i + 1] + R * cos(psi);
        spread = fmax(spread, hypot(cx[i] - cx[0], cy[i] - cy[0]));
    }
    CHECK(rc == TS_OK && spread < TOL_TRACK,
          "ramped turn: the turning circle's centre (%.6f, %.6f) m stays "
          "put to %.2g m over %.0f s (%s)", cx[0], cy[0], spread,
          t[N - 1] - t[0], err.msg);
    /* Before the turn the origin runs straight along x. */
    double t0[1] = {0.75}, p0[3];
    ts_track_poses(ex, &base, 1, t0, p0, NULL);
    CHECK_NEAR(p0[0], 3.125 * 0.75, TOL_TRACK, "before the ramp: straight");
    ts_excitation_free(ex);
}

static void test_to_earth(void)
{
    double pose[3] = {10.5, -4.25, 2.0}, r[3] = {-1.5, 0.75, 12.0}, e[3];
    ts_track_to_earth(pose, r, e);
    double c = cos(2.0), s = sin(2.0);
    CHECK_NEAR(e[0], 10.5 + c * -1.5 - s * 0.75, 1e-14, "to earth: x");
    CHECK_NEAR(e[1], -4.25 + s * -1.5 + c * 0.75, 1e-14, "to earth: y");
    CHECK_NEAR(e[2], 12.0, 0, "to earth: depth unchanged");
}

/* Kamman's steady turn at 8 links over 15 s with the channels `outputs`,
 * asking for the tracks when `tracks`; NULL on failure. */
static ts_result *turn_run(const ts_scene *sc, const char *outputs,
                           int tracks)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.setup.links = 8;
    rq.simulate.sim.t_end = 15;
    rq.simulate.sim.dt_sample = 0.5;
    rq.simulate.tracks = tracks;
    snprintf(rq.simulate.outputs, sizeof rq.simulate.outputs, "%s",
             outputs);
    ts_err err = {0};
    ts_result *r = NULL;
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    ts_request_clear(&rq);
    if (!CHECK(rc == TS_OK && r && r->nonlinear, "turn simulated with %s "
               "(tracks %d): %s", outputs, tracks, err.msg)) {
        ts_result_free(r);
        return NULL;
    }
    return r;
}

/* The tracks cost a few per cent of a run: computed only when asked (the
 * pictures: ts_simulate_opts.tracks; an earth channel; the full state). */
static void test_tracks_on_request(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/kamman_ex3_turn.yaml");
    if (!sc)
        return;
    ts_result *plain = turn_run(sc, "sphere.x", 0);
    ts_result *asked = turn_run(sc, "sphere.x", 1);
    ts_result *earth = turn_run(sc, "sphere.earth_x", 0);
    ts_result *all = turn_run(sc, "all", 0);
    if (plain && asked && earth && all) {
        const ts_history *hp = plain->nonlinear, *ha = asked->nonlinear,
                         *he = earth->nonlinear, *hl = all->nonlinear;
        int none = 1, same = ha->nsamples == he->nsamples &&
                             hl->nsamples == he->nsamples;
        for (int i = 0; i < 3 * hp->nsamples; i++)
            none &= isnan(hp->frame[i]);
        for (int i = 0; same && i < 3 * he->nsamples; i++)
            same &= isfinite(he->frame[i]) &&
                    ha->frame[i] == he->frame[i] &&
                    hl->frame[i] == he->frame[i];
        CHECK(none, "without earth channels or the pictures the tracks are "
                    "not computed (the frame stays NaN)");
        CHECK(same, "asked for (the pictures), by an earth channel or by "
                    "the full state, the same tracks, at all %d samples",
              he->nsamples);
    }
    ts_result_free(plain);
    ts_result_free(asked);
    ts_result_free(earth);
    ts_result_free(all);
    ts_scene_free(sc);
}

static void test_simulated_turn(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/kamman_ex3_turn.yaml");
    if (!sc)
        return;
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.setup.links = 8;
    rq.simulate.sim.t_end = 15;
    rq.simulate.sim.dt_sample = 0.5;
    snprintf(rq.simulate.outputs, sizeof rq.simulate.outputs,
             "sphere.earth_x,sphere.earth_y,sphere.x,sphere.y,tow.earth_y");
    ts_err err = {0};
    ts_result *r = NULL;
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (CHECK(rc == TS_OK && r && r->nonlinear && r->noutputs == 5,
              "Kamman's steady turn simulated with earth channels (%s)",
              err.msg)) {
        const ts_history *h = r->nonlinear;
        const ts_system *sys = r->sys;
        double V = sys->tow.speed, W = sys->tow.turn_rate, R = V / W;
        /* The sphere's distance from the turn centre (0, R) of E, and the
         * same in M, where it is at rest. */
        double rM = hypot(ts_history_value(sys, h, &r->outputs[2], 0),
                          ts_history_value(sys, h, &r->outputs[3], 0) - R);
        double worst = 0, tow = 0;
        for (int i = 0; i < h->nsamples; i++) {
            double x = ts_history_value(sys, h, &r->outputs[0], i);
            double y = ts_history_value(sys, h, &r->outputs[1], i);
            worst = fmax(worst, fabs(hypot(x, y - R) - rM));
            /* The tow point, at M's origin, on the circle of M's origin. */
            double ty = ts_history_value(sys, h, &r->outputs[4], i);
            tow = fmax(tow, fabs(ty - R * (1 - cos(W * h->t[i]))));
        }
        /* The sphere stays at its equilibrium to the integrator's
         * tolerance (rtol 1e-6 of a 1.8 m cable). */
        CHECK(worst < 1e-5,
              "the sphere runs on a circle of radius %.6f m about the turn "
              "centre (0, %.4f) m of E to %.2g m", rM, R, worst);
        CHECK(tow < TOL_TRACK,
              "the tow point's earth y is V/Omega (1 - cos Omega t) to %.2g m",
              tow);
        /* The full state's JSON carries the poses. */
        json_t *o = json_object();
        int jrc = ts_report_history_full(o, sys, h);
        json_t *hd = json_object_get(json_object_get(o, "frame"), "heading");
        int i = h->nsamples - 1;
        CHECK(jrc == TS_OK && json_array_size(hd) == (size_t)h->nsamples &&
                  json_real_value(json_array_get(hd, (size_t)i)) ==
                      h->frame[3 * i + 2],
              "the full state's JSON has the frame's heading, %g rad at "
              "%g s", h->frame[3 * i + 2], h->t[i]);
        json_decref(o);
    }
    ts_result_free(r);

    ts_output out;
    rc = ts_output_find(sc->system, "sphere.earth_x", TS_OUT_ALL, &out, &err);
    CHECK(rc == TS_EINVAL &&
              strstr(err.msg, "an earth-frame position (a simulation's) is "
                              "not an output of this analysis"),
          "earth channels outside a simulation refused: %.90s", err.msg);
    rc = ts_output_find(sc->system, "sphere.earth_z",
                        TS_OUT_ALL | TS_OUT_BIT(TS_OUT_EARTH), &out, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "earth_x or earth_y"),
          "earth_z refused: %.90s", err.msg);
    ts_request_clear(&rq);
    ts_scene_free(sc);
}

/* A towing vehicle (test/scenes/towing_sphere.yaml, 1500 N of thrust)
 * given a thrust step of +500 N: its steady speed over the ground, from
 * the earth track of its tow point over the last 20 s of a 150 s run,
 * against the Newton trim of the same scene at 2000 N (the equilibrium's
 * solved speed). */
static void test_speed_change(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "test/scenes/towing_sphere.yaml");
    if (!sc)
        return;
    /* The trim at 2000 N: the same text with the thrust replaced. */
    const char *at = strstr(sc->text, "thrust: 1500 N");
    ts_scene *s2 = NULL;
    if (CHECK(at != NULL, "the scene gives 1500 N of thrust")) {
        size_t n = strlen(sc->text), k = (size_t)(at - sc->text);
        char *t2 = malloc(n + 1);
        if (!t2)
            return;
        memcpy(t2, sc->text, n + 1);
        memcpy(t2 + k, "thrust: 2000 N", 14);
        s2 = tscene_parse(u, t2);
        free(t2);
    }
    ts_err err = {0};
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_EQUILIBRIUM);
    ts_result *eq = NULL;
    int rc = s2 ? ts_analysis_run(s2->system, &rq, &eq, &err) : TS_EINVAL;
    double U2 = rc == TS_OK && eq && eq->eq ? eq->eq->speed : NAN;
    CHECK(rc == TS_OK && isfinite(U2), "Newton trim at 2000 N: %.9f m/s "
          "(%s)", U2, err.msg);
    ts_result_free(eq);
    ts_request_clear(&rq);

    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.simulate.sim.t_end = 150;
    rq.simulate.sim.dt_sample = 1;
    snprintf(rq.simulate.outputs, sizeof rq.simulate.outputs,
             "tow.earth_x,tow.earth_y");
    rq.simulate.excitation = ts_excitation_alloc(&err);
    ts_excitation_parse(rq.simulate.excitation,
                        "tug.thrust:step,amplitude=500,rise=1", u, "test",
                        &err);
    ts_result *r = NULL;
    rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (CHECK(rc == TS_OK && r && r->nonlinear,
              "thrust step of the towing vehicle simulated (%s)", err.msg)) {
        const ts_history *h = r->nonlinear;
        int i1 = h->nsamples - 1, i0 = i1 - 20;
        double dx = ts_history_value(r->sys, h, &r->outputs[0], i1) -
                    ts_history_value(r->sys, h, &r->outputs[0], i0);
        double dy = ts_history_value(r->sys, h, &r->outputs[1], i1) -
                    ts_history_value(r->sys, h, &r->outputs[1], i0);
        double U = hypot(dx, dy) / (h->t[i1] - h->t[i0]);
        /* The surge settles in a few tens of seconds; what is left of
         * the transient at 150 s (the sphere's slower depth change) is
         * 2e-5 relative: tolerance 1e-4. */
        CHECK(fabs(U - U2) <= 1e-4 * U2,
              "steady speed reached by simulation %.6f m/s, Newton's %.6f "
              "m/s (rel. diff %.2g)", U, U2, fabs(U - U2) / U2);
    }
    ts_result_free(r);
    ts_request_clear(&rq);
    ts_scene_free(s2);
    ts_scene_free(sc);
}

/* The constant-power law in the time domain: the towing vehicle of
 * test/scenes/towing_sphere.yaml driven at a power P = 4800 W (in place of
 * its thrust), slowed by a step of -800 N along its axis (the input
 * tug.force.x): at every sample of the 60 s run its thrust times its
 * surge speed through the water is P, while the thrust changes. */
static void test_constant_power(const ts_units *u)
{
    const char *path = "test/scenes/towing_sphere.yaml";
    ts_scene *sc = tscene_load(u, path);
    if (!sc)
        return;
    const char *at = strstr(sc->text, "    thrust: 1500 N\n");
    ts_scene *sp = NULL;
    if (at) {
        const char *law = "    power: 4800 W\n    max_thrust: 5000 N\n";
        size_t n = strlen(sc->text), k = (size_t)(at - sc->text);
        size_t old = strlen("    thrust: 1500 N\n"), nl = strlen(law);
        char *t = malloc(n - old + nl + 1);
        if (t) {
            memcpy(t, sc->text, k);
            memcpy(t + k, law, nl);
            memcpy(t + k + nl, at + old, n - k - old + 1);
            sp = tscene_parse(u, t);
            free(t);
        }
    }
    ts_scene_free(sc);
    if (!CHECK(sp != NULL, "the scene at constant power"))
        return;
    ts_err err = {0};
    const ts_system *sys = sp->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_history *h = ts_history_alloc(sys, 61, &err);
    double *y0 = k ? malloc((size_t)ts_kernel_nstate(k) * sizeof *y0) : NULL;
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    int rc = k && eq && ex && h && y0 ? ts_equilibrium_solve(k, &eo, eq, &err)
                                      : TS_ENOMEM;
    if (rc == TS_OK)
        rc = ts_equilibrium_state(k, eq, y0, &err);
    if (rc == TS_OK)
        rc = ts_excitation_parse(ex, "tug.force.x:step,amplitude=-800,rise=2",
                                 u, "test", &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    ts_sim *sim = rc == TS_OK ? ts_sim_alloc(k, ex, &o, &err) : NULL;
    if (CHECK(sim && ts_sim_set_state(sim, 0, y0, &err) == TS_OK,
              "constant power: trimmed at %.6f m/s and started (%s)",
              eq ? eq->speed : NAN, err.msg)) {
        int root = ts_kernel_root(k);
        double worst = 0, tmin = INFINITY, tmax = 0;
        for (int i = 0; i <= 60 && rc == TS_OK; i++) {
            if (i > 0)
                rc = ts_sim_advance(sim, i, &err);
            if (rc == TS_OK)
                rc = ts_sim_record(sim, h, &err);
            ts_vehicle_result vr;
            ts_kernel_vehicle_result(k, root, &vr);
            worst = fmax(worst, fabs(vr.power - 4800.0));
            tmin = fmin(tmin, vr.thrust);
            tmax = fmax(tmax, vr.thrust);
        }
        CHECK(rc == TS_OK, "60 s simulated (%s)", err.msg);
        /* T = P / U exactly, so T U = P to rounding (1e-12 relative). */
        CHECK(worst <= 1e-12 * 4800.0,
              "T U = P = 4800 W at every sample to %.2g W while the thrust "
              "went from %.1f to %.1f N", worst, tmin, tmax);
        CHECK(tmax - tmin > 0.05 * tmax,
              "the speed changed: the thrust by %.1f %%",
              100 * (tmax - tmin) / tmax);
    }
    ts_sim_free(sim);
    free(y0);
    ts_history_free(h);
    ts_excitation_free(ex);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sp);
}

static void test_bad(void)
{
    ts_frame base = {0};
    base.speed = 1;
    double t[3] = {0.0, 2.0, 1.0}, pose[9];
    ts_err err = {0};
    CHECK(ts_track_poses(NULL, &base, 3, t, pose, &err) == TS_EINVAL &&
              strstr(err.msg, "non-decreasing, got t[2] = 1 s"),
          "times out of order: %s", err.msg);
    t[0] = -1;
    CHECK(ts_track_poses(NULL, &base, 1, t, pose, &err) == TS_EINVAL,
          "negative time refused: %s", err.msg);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    test_steady_turn();
    test_speed_step(u);
    test_ramped_turn(u);
    test_to_earth();
    test_simulated_turn(u);
    test_tracks_on_request(u);
    test_speed_change(u);
    test_constant_power(u);
    test_bad();
    ts_units_free(u);
    return tc_done();
}
