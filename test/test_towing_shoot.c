/* test_towing_shoot.c: the equilibrium of a towing vehicle at the root by
 * shooting (lib/equilibrium.c, solve_vehicle_shooting; doc/equilibrium.md,
 * doc/towing-vehicle.md section 3) against Newton with the dense Jacobian
 * on every coordinate, the method it replaces: two solvers that share the
 * kernel's verdict only (shooting marches the cables, Newton moves every
 * link angle).
 *
 * On every towing-vehicle scene shipped (examples/dolphin_aurora.yaml at
 * its 30 links and at 100, test/scenes/towing_sphere.yaml,
 * dolphin_waypoints.yaml, survey_ship.yaml: a surface ship of 3 degrees
 * of freedom at a given power) and on variants that reach each unknown
 * of the steady motion (towing_sphere with 3 deg of rudder: a steady
 * turn, the turn rate solved; turn_by rudder at that turn rate: the
 * deflection solved, which must give back the 3 deg; a proportional speed
 * controller: its bias solved at the set speed; a PI one: its integrator),
 * method auto must answer by shooting, and give Newton's equilibrium:
 * every node's position, every tension, each vehicle's attitude and
 * origin, the speed, turn rate, thrust bias and turn deflection, and every
 * controller state.
 *
 * Tolerance. Both solves stop at a relative force residual of 1e-12
 * here (tighter than the default 1e-10, so that the comparison says
 * something about the method rather than about where each stopped). Two
 * states whose residuals are both below r differ by up to about cond * r
 * relative, cond the condition of the balance equations: Newton's
 * Jacobian's estimate (printed) is up to about 1e7 on these scenes, a
 * bound near 1e-5. The tolerance is 1e-7 of each quantity's scale (the
 * cables' length for positions, the largest tension for tensions, the
 * speed for the speed and V / L for the turn rate, 1 rad for angles and
 * deflections, the vehicle's weight for a bias, a controller state's own
 * size, at least 1, for those): a hundred times under that bound, so
 * that another state balanced as well (a slight steady turn instead of
 * the straight tow, which a nearly neutral lateral problem allows: a
 * forward-difference outer Jacobian led there, 5.6e-6 rad of yaw) fails,
 * and a thousand times above the largest difference seen (about 1e-10
 * of the scale, survey_ship's positions and tensions).
 *
 * Error bars. On every scene with vehicles that shooting answers (the
 * four above, examples/aurora_towfish.yaml, kamman_ex1_vehicle.yaml and
 * test/scenes/dolphin.yaml: towed vehicles), shooting at a residual of
 * LOOSE_TOL and Newton at LOOSE_TOL and at SOLVE_TOL must differ, at
 * every node and in the top tension, by at most the sum of their reported
 * solver errors (ts_result_equilibrium_values): neither solution is
 * exact, so the sum is what bounds their difference. The loose tolerance
 * makes Newton's error measurable (2.2e-7 m on dolphin_waypoints);
 * shooting polishes past it. And shooting's condition (the outer
 * problem's times the march's) must be within CONDITION_FACTOR of
 * Newton's: the two are conditions of different Jacobians in differently
 * scaled unknowns (on a plain cable, kamman_ex1_submerged, Newton's
 * Skeel condition is 3.9e3 where the march's is exactly right at 1), so
 * only their order can agree; the largest ratio seen is 78
 * (aurora_towfish; 2.7e4, survey_ship's, with Newton's 1-norm condition
 * before), and the march's condition alone (1) fails the check on two
 * scenes (dolphin_aurora, aurora_towfish).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/analysis.h"
#include "towstab/system.h"

/* The comparison's tolerance, relative to each quantity's scale (see
 * above). */
#define AGREE_RTOL 1e-7
#define SOLVE_TOL 1e-12
#define LOOSE_TOL 1e-8
#define CONDITION_FACTOR 1e5

typedef struct solved {
    ts_kernel *k;
    ts_equilibrium *eq;
    int rc;
} solved;

static solved solve_at(const ts_system *sys, ts_eq_method method,
                       double tol)
{
    solved s = {0};
    ts_err err = {0};
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = method;
    o.tol = tol;
    s.k = ts_kernel_alloc(sys, &err);
    s.eq = s.k ? ts_equilibrium_alloc(sys, &err) : NULL;
    s.rc = s.eq ? ts_equilibrium_solve(s.k, &o, s.eq, &err) : TS_ENOMEM;
    if (s.rc != TS_OK)
        printf("  %s: %s\n", ts_eq_method_name(method), err.msg);
    return s;
}

static solved solve(const ts_system *sys, ts_eq_method method)
{
    return solve_at(sys, method, SOLVE_TOL);
}

static void solved_free(solved *s)
{
    ts_equilibrium_free(s->eq);
    ts_kernel_free(s->k);
}

static double largest_diff(const double *a, const double *b, int n)
{
    double d = 0;
    for (int i = 0; i < n; i++)
        d = fmax(d, fabs(a[i] - b[i])) + 0.0 * (a[i] - b[i]);
    return d;
}

/* Shooting (method auto) against Newton on sys; *turn receives the
 * turn rate solved (NULL: not wanted). */
static void compare(const char *name, const ts_system *sys, double *turn)
{
    solved a = solve(sys, TS_EQ_AUTO), b = solve(sys, TS_EQ_NEWTON);
    if (!CHECK(a.rc == TS_OK && b.rc == TS_OK && a.eq->converged &&
                   b.eq->converged,
               "%s (%d links): auto and newton converge", name,
               sys->nlinks)) {
        solved_free(&a);
        solved_free(&b);
        return;
    }
    const ts_equilibrium *s = a.eq, *n = b.eq;
    CHECK(s->method == TS_EQ_SHOOTING && n->method == TS_EQ_NEWTON,
          "%s: auto answers by %s (shooting), newton by %s", name,
          ts_eq_method_name(s->method), ts_eq_method_name(n->method));
    double L = 0, T = 0;
    for (int l = 0; l < sys->nlinks; l++) {
        L += sys->links[l].length;
        T = fmax(T, fabs(n->tensions[l]));
    }
    double dr = largest_diff(s->positions, n->positions, 3 * sys->nnodes);
    double dt = largest_diff(s->tensions, n->tensions, sys->nlinks);
    double V = fabs(n->speed);
    double dv = fabs(s->speed - n->speed);
    double dw = fabs(s->turn_rate - n->turn_rate);
    double root_weight = 1.0;
    for (int b2 = 0; b2 < sys->nbodies; b2++)
        if (b2 == sys->tow.vehicle)
            root_weight = fmax(sys->bodies[b2].mass * sys->env.gravity, 1.0);
    double db = fabs(s->thrust_bias - n->thrust_bias);
    double dd = fabs(s->turn_deflection - n->turn_deflection);
    double da = 0, dor = 0;
    for (int v = 0; v < n->nvehicles; v++) {
        const ts_vehicle_result *p = &s->vehicles[v], *q = &n->vehicles[v];
        da = fmax(da, fmax(fabs(p->roll - q->roll),
                           fmax(fabs(p->pitch - q->pitch),
                                fabs(remainder(p->yaw - q->yaw, 2 * M_PI)))));
        dor = fmax(dor, largest_diff(p->origin, q->origin, 3));
    }
    /* Controller states relative to their own size (at least the
     * Newton step scale: 1 rad, or 1 rad / |ki| for an integrator). */
    double dc = 0;
    for (int i = 0; i < n->ncontrol; i++)
        dc = fmax(dc, fabs(s->controls[i] - n->controls[i]) /
                          fmax(fabs(n->controls[i]), 1.0));
    double tol_r = AGREE_RTOL * L, tol_t = AGREE_RTOL * T;
    double tol_w = AGREE_RTOL * V / L;
    int ok = dr <= tol_r && dor <= tol_r && dt <= tol_t &&
             dv <= AGREE_RTOL * V && dw <= tol_w &&
             db <= AGREE_RTOL * root_weight && dd <= AGREE_RTOL &&
             da <= AGREE_RTOL && dc <= AGREE_RTOL;
    CHECK(ok,
          "%s: shooting = Newton: positions %.3g m, origins %.3g m (<= "
          "%.3g), tensions %.3g N (<= %.3g), speed %.3g m/s of %.6g, turn "
          "rate %.3g rad/s (<= %.3g), bias %.3g N, deflection %.3g rad, "
          "attitudes %.3g rad, controller states %.3g (relative); Newton's "
          "condition %.3g",
          name, dr, dor, tol_r, dt, tol_t, dv, V, dw, tol_w, db, dd, da, dc, n->condition);
    if (turn)
        *turn = n->turn_rate;
    solved_free(&a);
    solved_free(&b);
}

/* The reported solver error of the points' positions and of the top
 * tension of eq (ts_result_equilibrium_values: every point carries the
 * same position error), into e[2]. */
static void solver_errors(const ts_system *sys, ts_equilibrium *eq,
                          double e[2])
{
    ts_result r;
    memset(&r, 0, sizeof r);
    r.sys = (ts_system *)sys;
    r.eq = eq;
    ts_value *v = NULL;
    int n = 0;
    ts_err err = {0};
    e[0] = e[1] = NAN;
    if (ts_result_equilibrium_values(&r, &v, &n, &err) == TS_OK && n >= 4) {
        e[0] = v[0].error.solver;
        for (int i = 0; i < n; i++)
            if (!strcmp(v[i].name, "top_tension"))
                e[1] = v[i].error.solver;
    }
    free(v);
}

/* Error bars (see the header): shooting at LOOSE_TOL against Newton at
 * LOOSE_TOL and at SOLVE_TOL; every node's position and the top tension
 * must differ by at most the sum of the two reported solver errors, and
 * shooting's condition must be within CONDITION_FACTOR of Newton's at
 * SOLVE_TOL. */
static void error_bars(const char *name, const ts_system *sys)
{
    solved a = solve_at(sys, TS_EQ_AUTO, LOOSE_TOL);
    solved b[2] = {solve_at(sys, TS_EQ_NEWTON, LOOSE_TOL),
                   solve_at(sys, TS_EQ_NEWTON, SOLVE_TOL)};
    if (CHECK(a.rc == TS_OK && b[0].rc == TS_OK && b[1].rc == TS_OK &&
                  a.eq->converged && b[0].eq->converged &&
                  b[1].eq->converged && a.eq->method == TS_EQ_SHOOTING,
              "%s (%d links): shooting at %.0e, newton at %.0e and %.0e "
              "converge",
              name, sys->nlinks, LOOSE_TOL, LOOSE_TOL, SOLVE_TOL)) {
        double es[2];
        solver_errors(sys, a.eq, es);
        for (int t = 0; t < 2; t++) {
            const ts_equilibrium *n = b[t].eq;
            double en[2];
            solver_errors(sys, b[t].eq, en);
            double dr = largest_diff(a.eq->positions, n->positions,
                                     3 * sys->nnodes);
            double dt = fabs(a.eq->top_tension - n->top_tension);
            CHECK(dr <= es[0] + en[0] && dt <= es[1] + en[1],
                  "%s: shooting's and Newton's (at %.0e) solver errors "
                  "bound their difference: positions %.3g m <= %.3g + "
                  "%.3g, top tension %.3g N <= %.3g + %.3g",
                  name, n->tolerance, dr, es[0], en[0], dt, es[1], en[1]);
        }
        double cs = a.eq->condition, cn = b[1].eq->condition;
        CHECK(cs >= cn / CONDITION_FACTOR && cs <= cn * CONDITION_FACTOR,
              "%s: shooting's condition %.3g within %.0e of Newton's %.3g "
              "(ratio %.3g)",
              name, cs, CONDITION_FACTOR, cn, cn / cs);
    }
    solved_free(&a);
    solved_free(&b[0]);
    solved_free(&b[1]);
}

static ts_scene *variant(const ts_units *u, const ts_scene *base, int n,
                         const char *const *keys, const char *const *vals)
{
    ts_err err = {0};
    ts_scene *s = ts_scene_set(base, n, keys, vals, u, &err);
    CHECK(s != NULL, "%s set (%s)", keys[0], s ? "ok" : err.msg);
    return s;
}

int main(void)
{
    ts_units *u = tscene_units();
    if (!u)
        return 1;
    /* Every scene with vehicles that shooting answers; the first four
     * have a towing vehicle. */
    const char *files[] = {"examples/dolphin_aurora.yaml",
                           "test/scenes/towing_sphere.yaml",
                           "test/scenes/dolphin_waypoints.yaml",
                           "test/scenes/survey_ship.yaml",
                           "examples/aurora_towfish.yaml",
                           "examples/kamman_ex1_vehicle.yaml",
                           "test/scenes/dolphin.yaml"};
    for (int f = 0; f < 7; f++) {
        ts_scene *sc = tscene_load(u, files[f]);
        if (sc && f < 4)
            compare(files[f], sc->system, NULL);
        if (sc)
            error_bars(files[f], sc->system);
        ts_scene_free(sc);
    }

    /* DOLPHIN-AURORA at 100 links. */
    ts_scene *da = tscene_load(u, "examples/dolphin_aurora.yaml");
    ts_err err = {0};
    if (da && CHECK(ts_system_set_links(da->system, 100, &err) == TS_OK,
                    "dolphin_aurora at 100 links (%s)",
                    err.msg[0] ? err.msg : "ok"))
        compare("dolphin_aurora", da->system, NULL);
    ts_scene_free(da);

    /* The unknowns of the steady motion, one by one, on TOWING-SPHERE. */
    ts_scene *ts = tscene_load(u, "test/scenes/towing_sphere.yaml");
    if (ts) {
        const char *rk[] = {"towing_vehicle.components[rudder].deflection"};
        const char *rv[] = {"3 deg"};
        ts_scene *turn = variant(u, ts, 1, rk, rv);
        double w = NAN;
        if (turn)
            compare("towing_sphere, rudder 3 deg (turn rate solved)",
                    turn->system, &w);
        ts_scene_free(turn);
        CHECK(fabs(w) > 1e-3, "the 3 deg rudder turns (%.6g rad/s)", w);
        if (isfinite(w)) {
            char rate[64];
            snprintf(rate, sizeof rate, "%.17g rad/s", w);
            const char *bk[] = {"tow.turn_rate", "towing_vehicle.turn_by"};
            const char *bv[] = {rate, "rudder"};
            ts_scene *by = variant(u, ts, 2, bk, bv);
            if (by) {
                compare("towing_sphere, turn_by rudder (deflection solved)",
                        by->system, NULL);
                solved s = solve(by->system, TS_EQ_AUTO);
                CHECK(s.rc == TS_OK &&
                          fabs(s.eq->turn_deflection - 3 * M_PI / 180) <
                              1e-9,
                      "shooting's turn_by deflection is the 3 deg the turn "
                      "came from: %.12g deg",
                      s.rc == TS_OK ? s.eq->turn_deflection * 180 / M_PI
                                    : NAN);
                solved_free(&s);
            }
            ts_scene_free(by);
        }
        /* Speed controllers: the bias (proportional) and the integrator
         * (PI) solved. */
        for (int pi = 0; pi < 2; pi++) {
            const char *zv[] = {"0 deg"};
            ts_scene *c = variant(u, ts, 1, rk, zv);
            if (!c)
                continue;
            ts_system *sys = c->system;
            ts_vehicle *d = sys->bodies[sys->tow.vehicle].vehicle;
            d->propulsion.type = TS_PROP_SPEED;
            d->propulsion.speed = 2.85;
            d->propulsion.gain = 2000.0;
            d->propulsion.ki = pi ? 300.0 : 0.0;
            d->propulsion.max_thrust = INFINITY;
            compare(pi ? "towing_sphere, PI speed controller (integrator "
                         "solved)"
                       : "towing_sphere, speed controller (bias solved)",
                    sys, NULL);
            ts_scene_free(c);
        }
    }
    ts_scene_free(ts);
    ts_units_free(u);
    return tc_done();
}
