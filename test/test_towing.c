/* test_towing.c: the towing vehicle as the dynamic root of the tree
 * (doc/towing-vehicle.md; lib/kernel.c, lib/equilibrium.c).
 *
 *  1. Energy: a towing vehicle pulling a cable and a sphere in vacuum, no
 *     thrust, in a turning frame: nothing prescribed does work, so the
 *     kinetic plus potential energy is conserved; RK4's drift falls like
 *     h^4.
 *  2. The cable sees only the tow point's steady motion: a towing vehicle
 *     whose speed controller holds 3 m/s and whose depth loop holds its
 *     tow point at 20 m gives the prescribed-tow equilibrium at 3 m/s from
 *     (0, 0, 20 m): the same tensions and shape, and its thrust equals
 *     the cable's pull plus its own drag.
 *  3. Thrust = drag(U), analytic: a symmetric neutral vehicle pulling a
 *     neutral cable that streams straight behind it. At zero attitude the
 *     drag is 1/2 rho U^2 (Cd_axial pi D^2 / 4 + sum S Cd0 + Cdt pi d L),
 *     so at a given thrust U = sqrt(T / that), at a given power
 *     U = (P / that)^(1/3).
 */
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"
#include "towstab/units.h"
#include "../lib/vec3.h"
#include "../lib/vehicle.h"

/* The towing vehicle of test/scenes/towing_sphere.yaml, with `prop` its
 * propulsion and `extra` more top-level text. */
static const char *vehicle_text =
    "towing_vehicle:\n"
    "  name: tug\n"
    "  mass: 4126.1375 kg\n"
    "  volume: 4.0255 m^3\n"
    "  inertia: [330 kg*m^2, 22000 kg*m^2, 22000 kg*m^2]\n"
    "  mass_centre: [0, 0, 0.05 m]\n"
    "  tow_point: [-4 m, 0, 0]\n"
    "  added_mass: spheroid\n"
    "  components:\n"
    "    - {name: hull, type: hull, position: [0, 0, 0], length: 8 m, "
    "diameter: 0.8 m}\n"
    "    - {name: foreplane, type: surface, position: [0.5 m, 0, 0], "
    "area: 0.4 m^2, span: 1.2 m, roll: 0 deg, control: true}\n"
    "    - {name: tailplane, type: surface, position: [-3.6 m, 0, 0], "
    "area: 0.6 m^2, span: 1.2 m, roll: 0 deg}\n"
    "    - {name: rudder, type: surface, position: [-3.6 m, 0, 0], "
    "area: 0.6 m^2, span: 1.2 m, roll: 90 deg, control: true}\n"
    "  controllers:\n"
    "    - {name: depth, measure: depth, setpoint: 20 m, kp: 0.05 rad/m, "
    "ki: 0.005 rad/(m*s), kd: 0.2 rad*s/m, surfaces: {foreplane: 1}}\n";

static ts_scene *scene(const char *fmt, ...)
{
    char text[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *s = ts_scene_parse(text, strlen(text), "test", u, &err);
    if (!s)
        printf("scene: %s\n", err.msg);
    ts_units_free(u);
    return s;
}

/* ---- 1. energy in vacuum ------------------------------------------- */

static int rk4_step(ts_kernel *k, double *y, double h, int n, double *w)
{
    double *k1 = w, *k2 = w + n, *k3 = w + 2 * n, *k4 = w + 3 * n,
           *yt = w + 4 * n;
    int rc = ts_kernel_eval(k, y, NULL, k1);
    for (int i = 0; i < n; i++)
        yt[i] = y[i] + 0.5 * h * k1[i];
    rc |= ts_kernel_eval(k, yt, NULL, k2);
    for (int i = 0; i < n; i++)
        yt[i] = y[i] + 0.5 * h * k2[i];
    rc |= ts_kernel_eval(k, yt, NULL, k3);
    for (int i = 0; i < n; i++)
        yt[i] = y[i] + h * k3[i];
    rc |= ts_kernel_eval(k, yt, NULL, k4);
    for (int i = 0; i < n; i++)
        y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    return rc;
}

static double energy(ts_kernel *k, const double *y, double *f)
{
    ts_kernel_eval(k, y, NULL, f);
    return ts_kernel_kinetic_energy(k) + ts_kernel_potential_energy(k);
}

static double drift(const ts_system *s, double h, double T, double *E0)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    int n = ts_kernel_nstate(k), nq = ts_kernel_nq(k), nl = s->nlinks;
    double *y = calloc((size_t)n, sizeof(double));
    double *w = malloc(5 * (size_t)n * sizeof(double));
    double *f = malloc((size_t)n * sizeof(double));
    /* A 3-D state: each link's angles and rates in its chart. */
    for (int l = 0; l < nl; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o] = 0.5 + 0.3 * sin(1.7 * l);
        y[o + 1] = 0.4 * cos(2.3 * l + 1);
        y[nq + o] = 0.5 * cos(l + 0.2);
        y[nq + o + 1] = -0.4 * sin(3.1 * l);
    }
    double om[3] = {0.2, -0.15, 0.3}, R[9], th[3] = {0.11, -0.08, 0.2};
    tsi_rot123(th, R);
    ts_kernel_set_vehicle(k, ts_kernel_root(k), R, om, TS_CHART_RECHART, y);
    int ro = ts_kernel_root_offset(k);
    double pos[3] = {1.0, -0.5, 20.0}, vel[3] = {0.3, -0.2, 0.1};
    for (int j = 0; j < 3; j++) {
        y[ro + j] = pos[j];
        y[nq + ro + j] = vel[j];
    }
    double e0 = energy(k, y, f), worst = 0;
    int steps = (int)lround(T / h);
    for (int i = 0; i < steps; i++) {
        if (rk4_step(k, y, h, n, w) != TS_OK) {
            worst = INFINITY;
            break;
        }
        worst = fmax(worst, fabs(energy(k, y, f) - e0));
    }
    *E0 = e0;
    free(y);
    free(w);
    free(f);
    ts_kernel_free(k);
    return worst;
}

static void test_energy(void)
{
    ts_scene *sc = scene(
        "name: vacuum\n"
        "environment: {water_density: 0, gravity: 9.81}\n"
        "tow: {speed: 2 m/s, turn_rate: 0.05 rad/s, point: [0, 0, 20 m]}\n"
        "%s"
        "  propulsion: {thrust: 0 N}\n"
        "cables:\n"
        "  - {name: c, from: tow, to: ball, length: 6 m, diameter: 0.02 m, "
        "mass_per_length: 2 kg/m, links: 3}\n"
        "bodies:\n"
        "  - {name: ball, type: sphere, diameter: 0.3 m, mass: 40 kg}\n",
        vehicle_text);
    CHECK(sc != NULL, "vacuum scene with a towing vehicle parses");
    if (!sc)
        return;
    const ts_system *s = sc->system;
    double E0, E;
    /* The vehicle (4 t) swings the 52 kg below it: 2 s, steps of 8, 4 and
     * 2 ms. */
    double d1 = drift(s, 8e-3, 2.0, &E0), d2 = drift(s, 4e-3, 2.0, &E),
           d3 = drift(s, 2e-3, 2.0, &E);
    /* Scale: the sphere's weight over 1 m (393 N m). RK4: ratios near 16
     * per halving. */
    CHECK(d3 < 1e-6 * 40 * 9.81 && d1 / d2 > 10 && d1 / d2 < 40 &&
              d2 / d3 > 10 && d2 / d3 < 40,
          "vacuum, turning frame: energy drift %.3g, %.3g, %.3g J at h 8, "
          "4, 2 ms (ratios %.1f, %.1f), E0 %.6g J",
          d1, d2, d3, d1 / d2, d2 / d3, E0);
    ts_scene_free(sc);
}

/* ---- 2. the cable sees the tow point's steady motion --------------- */

static const char *cable_text =
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: 50 m, "
    "diameter: 0.02 m, weight: 5 N/m, links: 10}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: 0.5 m, wet_weight: 500 N}\n";

static ts_equilibrium *solve(const ts_system *s, ts_kernel **kout)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    int rc = ts_equilibrium_solve(k, NULL, eq, &err);
    if (rc != TS_OK)
        printf("equilibrium: %s\n", err.msg);
    if (kout)
        *kout = k;
    else
        ts_kernel_free(k);
    return eq;
}

static void test_prescribed(void)
{
    ts_scene *tow = scene("name: prescribed\n"
                          "tow: {speed: 3 m/s, point: [0, 0, 20 m]}\n%s",
                          cable_text);
    ts_scene *veh = scene("name: towing\n"
                          "tow: {speed: 2.5 m/s, point: [0, 0, 20 m]}\n%s"
                          "  propulsion: {speed: 3 m/s, gain: 800 N*s/m}\n%s",
                          vehicle_text, cable_text);
    CHECK(tow && veh, "prescribed and towing-vehicle scenes parse");
    if (!tow || !veh)
        return;
    const ts_system *st = tow->system, *sv = veh->system;
    ts_kernel *kv;
    ts_equilibrium *et = solve(st, NULL), *ev = solve(sv, &kv);
    CHECK(et->converged && ev->converged, "both equilibria converge "
          "(residuals %.3g, %.3g)", et->residual, ev->residual);
    double worst = 0, big = 0;
    for (int l = 0; l < st->nlinks; l++) {
        worst = fmax(worst, fabs(et->tensions[l] - ev->tensions[l]));
        big = fmax(big, fabs(et->tensions[l]));
    }
    /* The vehicle's depth loop holds its origin at 20 m, so its tow
     * point sits where its pitch puts it: compare relative to it. */
    double dpos = 0;
    for (int i = 0; i < 3 * st->nnodes; i++)
        dpos = fmax(dpos, fabs(et->positions[i] - et->positions[i % 3] -
                               (ev->positions[i] - ev->positions[i % 3])));
    /* Both solved to 1e-10 of the largest force: the tensions agree to
     * that, the positions to its shape error (1e-8 m). */
    CHECK(worst <= 1e-8 * big && dpos <= 1e-7,
          "towing vehicle at 3 m/s: tensions as prescribed to %.3g N of "
          "%.4g N, node positions relative to the tow point to %.3g m",
          worst, big, dpos);
    CHECK_NEAR(ev->speed, 3.0, 1e-12, "steady speed is the controller's");
    CHECK_NEAR(ev->turn_rate, 0.0, 1e-12, "steady turn rate, symmetric");
    const ts_vehicle_result *r = &ev->vehicles[ts_kernel_root(kv)];
    CHECK(r->towing, "the towing vehicle's result is marked");
    /* Its own balance along its axis: thrust = -(hydro force x) - the
     * cable's pull along body x (the pull is in M). */
    double pull_b[3];
    mat3_tmul(r->R, r->joint_force, pull_b);
    double gx = 0;
    {
        /* weight and buoyancy along body x */
        double ez_b[3] = {r->R[6], r->R[7], r->R[8]};
        const ts_body *b = &sv->bodies[sv->tow.vehicle];
        gx = (b->mass * sv->env.gravity -
              sv->env.water_density * sv->env.gravity *
                  b->vehicle->volume * r->submerged) * ez_b[0];
    }
    CHECK_REL(r->thrust, -(r->hydro_force[0] + pull_b[0] + gx), 1e-8,
              "thrust balances drag, pull and weight along the axis");
    CHECK_REL(r->thrust, ev->thrust_bias, 1e-9,
              "at the set speed the thrust is the trimmed bias");
    CHECK_REL(r->power, r->thrust * 3.0 * cos(r->alpha) * cos(r->beta),
              1e-9, "power is thrust times surge speed");
    ts_equilibrium_free(et);
    ts_equilibrium_free(ev);
    ts_kernel_free(kv);
    ts_scene_free(tow);
    ts_scene_free(veh);
}

/* ---- 3. thrust = drag(U) ---------------------------------------------- */

static void test_thrust_drag(void)
{
    const double rho = 1025, D = 0.8, S = 0.4, S2 = 0.6, cd0 = 0.01,
                 cdt = 0.01, d = 0.02, L = 50, cda = 0.2;
    /* A neutral cable: mass per length rho pi d^2 / 4. */
    double mpl = rho * M_PI * d * d / 4;
    double K = 0.5 * rho * (cda * M_PI * D * D / 4 + (S + S2 + S2) * cd0 +
                            cdt * M_PI * d * L);
    const char *laws[2] = {"thrust: 1500 N", "power: 6 kW, max_thrust: 5 kN"};
    double want[2] = {sqrt(1500 / K), cbrt(6000 / K)};
    for (int c = 0; c < 2; c++) {
        ts_scene *sc = scene(
            "name: drag\n"
            "tow: {speed: 2 m/s, point: [0, 0, 20 m]}\n%s"
            "  propulsion: {%s}\n"
            "cables:\n"
            "  - {name: cable, from: tow, length: %g m, diameter: %g m, "
            "mass_per_length: %.17g kg/m, tangential_drag: %g, links: 10}\n",
            vehicle_text, laws[c], L, d, mpl, cdt);
        CHECK(sc != NULL, "scene with %s parses", laws[c]);
        if (!sc)
            continue;
        ts_kernel *k;
        ts_equilibrium *eq = solve(sc->system, &k);
        const ts_vehicle_result *r = &eq->vehicles[ts_kernel_root(k)];
        /* Solved to 1e-10 of the largest force: U to about 1e-10. */
        CHECK(eq->converged, "%s: converged (residual %.3g)", laws[c],
              eq->residual);
        CHECK_REL(eq->speed, want[c], 1e-9, laws[c]);
        CHECK(fabs(r->pitch) < 1e-9 && fabs(r->yaw) < 1e-9,
              "%s: level (pitch %.3g, yaw %.3g rad), foreplane %.3g rad",
              laws[c], r->pitch, r->yaw, r->delta[1]);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        ts_scene_free(sc);
    }
}

int main(void)
{
    test_energy();
    test_prescribed();
    test_thrust_drag();
    return tc_done();
}
