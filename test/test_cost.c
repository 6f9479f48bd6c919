/* test_cost.c: what a run will cost before it runs (towstab/cost.h), the
 * refusals of runs a simulation cannot resolve or hold (lib/analysis.c),
 * and the out-of-memory message (ts_fail_nomem, towstab/error.h).
 *
 *  1. The fastest-mode bound of a bare chain hanging in vacuum equals the
 *     beaded-string formula 2 sqrt(T / (m l)) with T the chain's weight,
 *     m half a link's mass and l a link's length (1e-12 relative), and
 *     that of an elastic chain the axial 2 sqrt(EA / (m l)) when larger.
 *  2. The estimate is a lower bound of the work: on Kamman's example 1
 *     (20 links, rk8pd, 20 s, at rest in its equilibrium) and example 4
 *     under its 1 Hz heave (3 s), the estimated steps and evaluations are
 *     at most those the run took, and more than 1/50 of them (a bound
 *     worth saying). Times are not compared (they depend on the load).
 *     Modes: 30 n^3 flops and 6 n^2 doubles for LAPACK, none for ARPACK.
 *     With a towing vehicle the bound is taken at its solved speed, not
 *     the scene's (DOLPHIN-AURORA: 4.49 against 5 m/s).
 *  3. A simulation request whose default sample interval (16 per period)
 *     would take more than TS_SIMULATE_AUTO_SAMPLES_MAX samples is
 *     refused naming the excitation; a sample interval given longer than
 *     half a period is refused naming the sample; a history larger than
 *     the machine's memory is refused as out of memory, with its size.
 *  4. ts_fail_nomem: the size in the unit that keeps it below 1000, and
 *     the hint after a semicolon.
 */
#include "towstab/cost.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "towstab/analysis.h"
#include "towstab/equilibrium.h"
#include "tscene.h"

#define G 9.80665

/* A bare chain of n links, total length L (m), mass per length mu
 * (kg/m), in vacuum at rest; EA 0 for rigid links. */
static ts_system *chain(int n, double L, double mu, double ea)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(1, 0, &err);
    s->env.gravity = G;
    s->env.water_density = 0.0;
    ts_cable *c = &s->cables[0];
    snprintf(c->name, sizeof c->name, "chain");
    c->from_body = c->to_body = -1;
    c->length = L;
    c->diameter = 0.01;
    c->mass_per_length = mu;
    c->nlinks = n;
    c->ea = ea;
    if (ea > 0)
        c->damping = 1.0;
    ts_system_build(s, &err);
    return s;
}

static void test_fastest_mode(void)
{
    ts_motion_bound rest = {0, 0, 0, 0, 0, 0};
    ts_system *s = chain(8, 3.7, 0.45, 0);
    double l = 3.7 / 8, m = 0.5 * 0.45 * l, T = 0.45 * 3.7 * G;
    double want = 2 * sqrt(T / (m * l)), got = ts_cost_fastest_mode(s, &rest);
    CHECK_REL(got, want, 1e-12, "bare chain: omega_max = 2 sqrt(T / (m l))");
    ts_system_free(s);
    s = chain(8, 3.7, 0.45, 2.5e6);
    want = 2 * sqrt(2.5e6 / (m * l));
    got = ts_cost_fastest_mode(s, &rest);
    CHECK_REL(got, want, 1e-12, "elastic chain: omega_max = 2 sqrt(EA / "
              "(m l)), the axial mode");
    ts_system_free(s);
}

/* Run example `path` as rq (simulate) and compare with its estimate. */
static void bound_check(const ts_units *u, const char *path,
                        const char *excite, double t_end)
{
    ts_scene *sc = tscene_load(u, path);
    if (!sc)
        return;
    ts_err err = {0};
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.simulate.sim.t_end = t_end;
    if (excite) {
        rq.simulate.excitation = ts_excitation_alloc(&err);
        ts_excitation_parse(rq.simulate.excitation, excite, u, "test", &err);
    }
    ts_cost c;
    int rc = ts_analysis_cost(sc->system, &rq, &c, &err);
    ts_result *r = NULL;
    int rr = ts_analysis_run(sc->system, &rq, &r, &err);
    if (CHECK(rc == TS_OK && rr == TS_OK && r && r->nonlinear,
              "%s: estimated and run (%s)", path, err.msg)) {
        const ts_sim_stats *st = &r->nonlinear_stats;
        double accepted = (double)(st->steps - st->rejected);
        /* Counts only: times depend on the machine's load (the estimate
         * times the kernel; benchmarks, not tests, compare times). */
        CHECK(c.steps <= accepted && c.steps > accepted / 50 &&
                  c.evaluations <= (double)st->evaluations &&
                  c.seconds > 0 && c.eval_s > 0,
              "%s: estimate %.4g steps, %.4g evaluations <= the run's %.4g "
              "accepted steps, %ld evaluations", path, c.steps,
              c.evaluations, accepted, st->evaluations);
    }
    ts_result_free(r);
    ts_request_clear(&rq);
    ts_scene_free(sc);
}

static void test_bounds(const ts_units *u)
{
    bound_check(u, "examples/kamman_ex1_submerged.yaml", NULL, 20.0);
    bound_check(u, "examples/kamman_ex4.yaml",
                "tow.heave:amplitude=0.1ft,frequency=1Hz", 3.0);
    ts_err err = {0};
    ts_system *s = chain(10, 5, 0.3, 0);
    ts_cost c;
    int rc = ts_cost_modes(s, 1000, TS_EIG_LAPACK, &c, &err);
    CHECK(rc == TS_OK && c.flops == 30.0 * 1e9 && c.bytes == 6 * 8.0 * 1e6 &&
              strstr(c.what, "LAPACK"),
          "modes: LAPACK on 1000 states, 3e10 flops, 48 MB: %s", c.what);
    rc = ts_cost_modes(s, 1000, TS_EIG_ARPACK, &c, &err);
    CHECK(rc == TS_OK && fabs(c.flops - 2e9 / 3) <= 1e-12 * c.flops &&
              c.evaluations == 2.0 * 1009,
          "modes: ARPACK below 1200 states: the dense linearization and "
          "LU (%g evaluations, %g flops)", c.evaluations, c.flops);
    rc = ts_cost_modes(s, 40000, TS_EIG_ARPACK, &c, &err);
    CHECK(rc == TS_OK && c.flops == 0 && c.bytes == 0 &&
              c.evaluations == TS_COST_SPARSE_EVALUATIONS &&
              strstr(c.what, "sparse"),
          "modes: ARPACK on 40000 states: the sparse linearization only "
          "(%g evaluations): %s", c.evaluations, c.what);
    ts_system_free(s);
}

/* With a towing vehicle the steady speed is solved: DOLPHIN-AURORA at
 * 4500 N of thrust runs at about 4.49 m/s, not the scene's 5 m/s. The
 * estimate's fastest-mode bound is the one at the solved speed (the
 * equilibrium run's, put into the system by hand: the same number), not
 * the one at the scene's speed, and its sentence says which speed; the
 * estimated steps stay at most the run's. */
static void test_towing_speed(const ts_units *u)
{
    const char *path = "examples/dolphin_aurora.yaml";
    ts_scene *sc = tscene_load(u, path);
    if (!sc)
        return;
    ts_err err = {0};
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.simulate.sim.t_end = 2.0;
    rq.setup.discretisation_error = 0;
    ts_cost c;
    int rc = ts_analysis_cost(sc->system, &rq, &c, &err);
    ts_request req;
    ts_request_init(&req, TS_ANALYSIS_EQUILIBRIUM);
    ts_result *eq = NULL;
    int re = ts_analysis_run(sc->system, &req, &eq, &err);
    ts_system *at = ts_system_copy(sc->system, &err);
    ts_cost c_solved, c_scene;
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 2.0;
    int ok = rc == TS_OK && re == TS_OK && at && eq->eq->converged;
    if (ok) {
        at->tow.speed = eq->eq->speed;
        at->tow.turn_rate = eq->eq->turn_rate;
        ok = ts_system_build(at, &err) == TS_OK &&
             ts_cost_simulate(at, NULL, &o, &c_solved, &err) == TS_OK &&
             ts_cost_simulate(sc->system, NULL, &o, &c_scene, &err) == TS_OK;
    }
    char want[64] = "";
    if (ok)
        snprintf(want, sizeof want, "solved speed %.4g m/s", eq->eq->speed);
    CHECK(ok && fabs(eq->eq->speed - 5.0) > 0.1 &&
              c.omega_max == c_solved.omega_max &&
              c.omega_max != c_scene.omega_max && strstr(c.what, want),
          "towing vehicle: the bound at the solved speed %.6g m/s (%.6g "
          "rad/s; at the scene's 5 m/s %.6g rad/s), estimated %.6g: %s",
          ok ? eq->eq->speed : NAN, ok ? c_solved.omega_max : NAN,
          ok ? c_scene.omega_max : NAN, c.omega_max, ok ? c.what : err.msg);
    ts_result *r = NULL;
    int rr = ts_analysis_run(sc->system, &rq, &r, &err);
    if (CHECK(rr == TS_OK && r && r->nonlinear, "%s: run (%s)", path,
              err.msg)) {
        const ts_sim_stats *st = &r->nonlinear_stats;
        double accepted = (double)(st->steps - st->rejected);
        CHECK(c.steps <= accepted && c.evaluations <= (double)st->evaluations,
              "%s: estimate %.4g steps, %.4g evaluations <= the run's %.4g "
              "accepted steps, %ld evaluations", path, c.steps,
              c.evaluations, accepted, st->evaluations);
    }
    ts_result_free(r);
    ts_result_free(eq);
    ts_system_free(at);
    ts_request_clear(&rq);
    ts_request_clear(&req);
    ts_scene_free(sc);
}

/* ---- 3. refusals ------------------------------------------------------- */

static int check_simulate(const ts_units *u, const ts_system *sys,
                          const char *excite, double t_end, double sample,
                          ts_err *err)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.simulate.sim.t_end = t_end;
    rq.simulate.sim.dt_sample = sample;
    if (excite) {
        rq.simulate.excitation = ts_excitation_alloc(err);
        ts_excitation_parse(rq.simulate.excitation, excite, u, "test", err);
    }
    int rc = ts_analysis_check(sys, &rq, err);
    ts_request_clear(&rq);
    return rc;
}

static void test_refusals(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    if (!sc)
        return;
    ts_err err = {0};
    int rc = check_simulate(u, sc->system,
                            "tow.heave:amplitude=0.1m,frequency=1e6Hz", 1.0,
                            0, &err);
    CHECK(rc == TS_EINVAL && !strncmp(err.msg, "excite: ", 8) &&
              strstr(err.msg, "1.6e+07 samples") &&
              strstr(err.msg, "more than the 1e+06"),
          "a 1 MHz excitation without a sample interval: %s", err.msg);
    rc = check_simulate(u, sc->system,
                        "tow.heave:amplitude=0.1m,frequency=5e4Hz", 1.0, 0,
                        &err);
    CHECK(rc == TS_OK, "50 kHz for 1 s (8e5 samples) is allowed (%s)",
          rc ? err.msg : "ok");
    rc = check_simulate(u, sc->system,
                        "tow.heave:amplitude=0.1m,frequency=3Hz", 10.0, 0.2,
                        &err);
    CHECK(rc == TS_EINVAL && !strncmp(err.msg, "sample: ", 8) &&
              strstr(err.msg, "at most 0.166667 s, 2 samples per period"),
          "a sample interval above half the period: %s", err.msg);
    rc = check_simulate(u, sc->system,
                        "tow.heave:amplitude=0.1m,frequency=2.5Hz", 10.0, 0.2,
                        &err);
    CHECK(rc == TS_OK, "2 samples per period are enough to resolve (%s)",
          rc ? err.msg : "ok");
    ts_scene_free(sc);
    /* 1e8 samples of 100000 links: 3e17 bytes, beyond any machine. */
    ts_system *s = chain(100000, 100, 1, 0);
    rc = check_simulate(u, s, NULL, 1e8, 1.0, &err);
    CHECK(rc == TS_ENOMEM && strstr(err.msg, "out of memory for the history "
                                             "of 1e+08 samples") &&
              strstr(err.msg, "coarser sample"),
          "a history beyond memory: %s", err.msg);
    ts_system_free(s);
}

static void test_nomem(void)
{
    ts_err err = {0};
    int rc = ts_fail_nomem(&err, 2.9e10, "fewer links", "x: out of memory "
                           "for %d links", 7);
    CHECK(rc == TS_ENOMEM && err.code == TS_ENOMEM &&
              !strcmp(err.msg, "x: out of memory for 7 links (29 GB); fewer "
                               "links"),
          "ts_fail_nomem: '%s'", err.msg);
    ts_fail_nomem(&err, 512, NULL, "y");
    CHECK(!strcmp(err.msg, "y (512 bytes)"), "without a hint: '%s'",
          err.msg);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    test_fastest_mode();
    test_bounds(u);
    test_towing_speed(u);
    test_refusals(u);
    test_nomem();
    ts_units_free(u);
    return tc_done();
}
