/* test_surface.c: the towing vehicle as a surface ship of 3 degrees of
 * freedom (doc/towing-vehicle.md section 6; lib/kernel.c, towing_vehicle
 * dof: 3), on test/scenes/survey_ship.yaml and variants of it.
 *
 *  1. Energy: the ship (no thrust) pulling its cable and sphere in vacuum
 *     in a turning frame. Heave, roll and pitch are held by reactions
 *     that do no work (the tow point's depth is fixed, roll and pitch
 *     are 0), so kinetic plus potential energy is conserved; RK4's drift
 *     falls like h^4.
 *  2. The hydrostatic reaction is the 6-dof model's missing load: the
 *     same ship with 6 degrees of freedom, its weight changed by the
 *     reported vertical reaction and its mass centre moved so that its
 *     weight's moments about the tow point make up the reported roll and
 *     pitch moments, floats in the 3-dof trim: the same speed and cable,
 *     level, its tow point at the scene's depth.
 *  3. Slow modes: that 6-dof ship with heave, roll and pitch held by
 *     springs of stiffness k (closed through its own force and moment
 *     inputs in the linear model) has the 3-dof ship's modes in the limit
 *     k -> infinity: the distance falls like 1 / k.
 *  4. Thrust = drag(U), analytic: a ship (half submerged, f = 1/2)
 *     pulling a neutral cable that streams straight behind it at zero
 *     attitude: U = sqrt(T / K) at a thrust, (P / K)^(1/3) at a power,
 *     K = 1/2 rho (f (Cd_axial pi D^2 / 4 + sum S Cd0) + Cdt pi d L).
 *  5. The steady turn at a rudder is where a simulation settles: from the
 *     straight trim with the rudder over, RK4 on the kernel reaches
 *     Newton's steady turn (tensions, speed, yaw, turn rate); and turn_by
 *     rudder at that turn rate gives the rudder back.
 */
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tmodel.h"
#include "tfiles.h"
#include "tscene.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"

#define SHIP "test/scenes/survey_ship.yaml"

static ts_units *units;
static char *ship_text;

/* The survey ship's scene with each line that starts with the key of
 * one of `lines` (a NULL-terminated list of "key: value" lines with
 * their indent) replaced by that line; a line "old_key:>new line"
 * replaces the line of old_key by the new line, and "key:!" cuts the
 * scene at the line of key. */
static ts_scene *ship_variant(const char *const *lines)
{
    size_t cap = strlen(ship_text) + 4096;
    char *out = malloc(cap), *o = out;
    const char *p = ship_text;
    while (*p) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) + 1 : strlen(p);
        const char *with = NULL;
        for (int i = 0; lines && lines[i]; i++) {
            size_t kl = strcspn(lines[i], ":") + 1;
            if (len > kl && !strncmp(p, lines[i], kl))
                with = lines[i][kl] == '>' || lines[i][kl] == '!'
                           ? lines[i] + kl + (lines[i][kl] == '>')
                           : lines[i];
        }
        if (with && !strcmp(with, "!"))
            break;
        if (with)
            o += snprintf(o, cap - (size_t)(o - out), "%s\n", with);
        else {
            memcpy(o, p, len);
            o += len;
        }
        p += len;
    }
    *o = '\0';
    ts_scene *s = tscene_parse(units, out);
    free(out);
    return s;
}

static ts_equilibrium *solve(const ts_system *s, ts_kernel **kout)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(s, &err) : NULL;
    if (eq && ts_equilibrium_solve(k, NULL, eq, &err) != TS_OK)
        printf("equilibrium: %s\n", err.msg);
    *kout = k;
    return eq;
}

/* ---- 1. energy in vacuum --------------------------------------------- */

/* The largest energy drift of RK4 at step h over T s from a 3-D state. */
static double drift(const ts_system *s, double h, double T, double *E0)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    int n = ts_kernel_nstate(k), nq = ts_kernel_nq(k);
    int qo = ts_kernel_vehicle_offset(k, ts_kernel_root(k));
    double *y = calloc((size_t)n, sizeof(double));
    tm_link_state(k, s->nlinks, y);
    /* Yaw, its rate, and the tow point's velocity in M. */
    y[qo] = 0.2;
    y[nq + qo] = 0.03;
    y[nq + qo + 1] = 0.7;
    y[nq + qo + 2] = -0.4;
    double worst = tm_energy_drift(k, y, h, T, E0);
    free(y);
    ts_kernel_free(k);
    return worst;
}

static void test_energy(void)
{
    static const char *const vac[] = {
        "  water_density: 0", "  speed: 2 m/s", "    power:>    thrust: 0 N",
        "    max_thrust:>", "    links: 3", NULL};
    ts_scene *sc = ship_variant(vac);
    CHECK(sc != NULL, "vacuum ship scene parses");
    if (!sc)
        return;
    /* A turning frame, so that the frame's terms are exercised. */
    sc->system->tow.turn_rate = 0.05;
    double E0, d8 = drift(sc->system, 0.008, 2.0, &E0);
    double d4 = drift(sc->system, 0.004, 2.0, &E0);
    double d2 = drift(sc->system, 0.002, 2.0, &E0);
    printf("energy %.6g J, drift %.3g %.3g %.3g J (ratios %.3g %.3g)\n", E0,
           d8, d4, d2, d8 / d4, d4 / d2);
    /* RK4: the drift falls like h^4 (16 per halving); rounding (1e-16 of
     * E0 per step, 1000 steps: 1e-13 of E0) is far below. */
    CHECK(d8 / d4 > 12 && d4 / d2 > 10, "energy drift falls like h^4 "
          "(ratios %.3g, %.3g)", d8 / d4, d4 / d2);
    CHECK(d2 < 1e-8 * E0, "energy conserved to %.3g of %.6g J", d2, E0);
    ts_scene_free(sc);
}

/* ---- 2. the reaction is the 6-dof ship's missing load ----------------- */

/* The 6-dof ship whose weight and mass centre make up the 3-dof ship's
 * reaction r[3] (vertical force, roll and pitch moments about the tow
 * point, body axes) at zero attitude: W' = W + r_z; the weight's roll
 * moment y_G' W' = y_G W - ... about A (body z down: roll moment of a
 * weight at lever (x, y) from A is y W, pitch moment -x W). */
static ts_scene *six_dof(const ts_system *s3, const double r[3],
                         const char *extra)
{
    const ts_body *b = &s3->bodies[s3->tow.vehicle];
    const ts_vehicle *v = b->vehicle;
    double g = s3->env.gravity, W = b->mass * g, W1 = W + r[0];
    double xa = v->mass_centre[0] - v->attach[0];
    double ya = v->mass_centre[1] - v->attach[1];
    double x1 = (xa * W - r[2]) / W1, y1 = (ya * W + r[1]) / W1;
    char mass[128], mc[160];
    snprintf(mass, sizeof mass, "  mass: %.17g kg", W1 / g);
    snprintf(mc, sizeof mc, "  mass_centre: [%.17g m, %.17g m, %.17g m]",
             v->attach[0] + x1, v->attach[1] + y1, v->mass_centre[2]);
    const char *lines[] = {"  dof: 6", mass, mc, extra, NULL};
    return ship_variant(lines);
}

static void test_reaction(void)
{
    ts_scene *s3 = tscene_load(units, SHIP);
    if (!s3)
        return;
    ts_kernel *k3, *k6;
    ts_equilibrium *e3 = solve(s3->system, &k3);
    const ts_vehicle_result *r3 = &e3->vehicles[ts_kernel_root(k3)];
    CHECK(e3->converged && r3->dof == 3, "3-dof trim converged (residual "
          "%.3g), %.6g m/s", e3->residual, e3->speed);
    /* Straight: the cable's vertical pull is the vertical reaction
     * (weight and buoyancy balance), no roll moment. */
    CHECK_REL(r3->held[0], -r3->joint_force[2], 1e-9,
              "vertical reaction = the cable's vertical pull");
    CHECK(fabs(r3->held[1]) < 1e-9 * fabs(r3->held[2]),
          "no roll moment in a straight tow (%.3g N m)", r3->held[1]);
    ts_scene *s6 = six_dof(s3->system, r3->held, NULL);
    if (!s6) {
        CHECK(0, "6-dof scene parses");
        return;
    }
    ts_equilibrium *e6 = solve(s6->system, &k6);
    const ts_vehicle_result *r6 = &e6->vehicles[ts_kernel_root(k6)];
    CHECK(e6->converged && r6->dof == 6, "6-dof trim converged (residual "
          "%.3g)", e6->residual);
    /* Both solved to 1e-10 of the largest force (the ship's weight,
     * 1.9 MN): the tensions (6 kN) to about 1e-4 N, angles to 1e-10. */
    CHECK_REL(e6->speed, e3->speed, 1e-9, "6-dof speed = 3-dof speed");
    double dt = 0;
    for (int l = 0; l < s3->system->nlinks; l++)
        dt = fmax(dt, fabs(e6->tensions[l] - e3->tensions[l]));
    CHECK(dt < 1e-3, "tensions agree to %.3g N", dt);
    CHECK(fabs(r6->pitch) < 1e-9 && fabs(r6->roll) < 1e-9 &&
              fabs(r6->yaw) < 1e-9,
          "6-dof ship level: pitch %.3g, roll %.3g, yaw %.3g rad", r6->pitch,
          r6->roll, r6->yaw);
    CHECK_NEAR(e6->positions[2], s3->system->tow.point[2], 1e-8,
               "6-dof tow point at the scene's depth");
    ts_equilibrium_free(e6);
    ts_kernel_free(k6);
    ts_scene_free(s6);
    ts_equilibrium_free(e3);
    ts_kernel_free(k3);
    ts_scene_free(s3);
}

/* ---- 3. slow modes: stiff heave, roll and pitch ------------------------ */

static ts_eigen *modes_of(ts_kernel *k, const ts_equilibrium *eq,
                          ts_linear **lout, const double *spring)
{
    ts_err err = {0};
    ts_linear *lin = ts_linear_alloc(k, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = TS_LIN_DENSE;
    ts_eigen *e = NULL;
    if (ts_linearize_equilibrium(k, eq, &lo, lin, &err) != TS_OK) {
        printf("linearize: %s\n", err.msg);
        *lout = lin;
        return NULL;
    }
    if (spring) {
        /* Springs on heave, roll and pitch through the ship's force.z,
         * moment.x and moment.y inputs: u = -k_j q_j. */
        static const char *in[3] = {"ship.force.z", "ship.moment.x",
                                    "ship.moment.y"};
        int qo = ts_kernel_vehicle_offset(k, ts_kernel_root(k));
        int q[3] = {ts_kernel_root_offset(k) + 2, qo, qo + 1}, n = lin->nstate;
        for (int j = 0; j < 3; j++) {
            int c = ts_kernel_input_find(k, in[j]);
            for (int i = 0; i < n; i++)
                lin->A[i + (size_t)q[j] * n] -=
                    spring[j] * lin->B[i + (size_t)c * n];
        }
    }
    ts_eigen_opts eo;
    ts_eigen_opts_default(&eo);
    eo.method = TS_EIG_LAPACK;
    if (ts_eigen_solve(lin, &eo, &e, &err) != TS_OK)
        printf("eigen: %s\n", err.msg);
    *lout = lin;
    return e;
}

/* The largest distance from a mode of a to the nearest mode of b, each
 * over max(|lambda_a|, 0.01 1/s) (the neutral modes sit at 0). */
static double farthest(const ts_eigen *a, const ts_eigen *b)
{
    double worst = 0;
    for (int i = 0; i < a->nmodes; i++) {
        double best = INFINITY;
        for (int j = 0; j < b->nmodes; j++)
            best = fmin(best, hypot(a->modes[i].re - b->modes[j].re,
                                    a->modes[i].im - b->modes[j].im));
        worst = fmax(worst, best / fmax(hypot(a->modes[i].re,
                                              a->modes[i].im), 0.01));
    }
    return worst;
}

static void test_stiff_modes(void)
{
    /* 6 links: the cable's modes stay below the springs' frequencies. */
    static const char *const few[] = {"    links: 6", NULL};
    ts_scene *s3 = ship_variant(few);
    if (!s3) {
        CHECK(0, "6-link ship parses");
        return;
    }
    ts_kernel *k3, *kh, *k6;
    ts_equilibrium *e3 = solve(s3->system, &k3);
    ts_scene *t3 = six_dof(s3->system,
                           e3->vehicles[ts_kernel_root(k3)].held, NULL);
    /* The 3-dof ship with the 6-dof one's weight and mass centre: the
     * same body, held instead of sprung. */
    const ts_vehicle *v6 = t3->system->bodies[t3->system->tow.vehicle].vehicle;
    char mass[128], mc[160];
    snprintf(mass, sizeof mass, "  mass: %.17g kg",
             t3->system->bodies[t3->system->tow.vehicle].mass);
    snprintf(mc, sizeof mc, "  mass_centre: [%.17g m, %.17g m, %.17g m]",
             v6->mass_centre[0], v6->mass_centre[1], v6->mass_centre[2]);
    const char *held[] = {"    links: 6", mass, mc, NULL};
    ts_scene *h3 = ship_variant(held);
    const char *six[] = {"    links: 6", mass, mc, "  dof: 6", NULL};
    ts_scene *s6 = ship_variant(six);
    ts_equilibrium *eh = solve(h3->system, &kh);
    ts_equilibrium *e6 = solve(s6->system, &k6);
    ts_linear *lh, *l6[3];
    ts_eigen *mh = modes_of(kh, eh, &lh, NULL);
    /* Springs: heave, roll and pitch frequencies of s rad/s for the mass
     * and inertias (about the tow point, roughly). */
    const ts_body *b = &s6->system->bodies[s6->system->tow.vehicle];
    double m = b->mass, Ix = b->vehicle->inertia[0] + m * 9.0,
           Iy = b->vehicle->inertia[1] + m * 144.0;
    double d[3];
    ts_eigen *m6[3];
    for (int i = 0; i < 3; i++) {
        double s = 10.0 * pow(sqrt(10.0), i), k[3] = {m * s * s,
                                                      Ix * s * s, Iy * s * s};
        m6[i] = modes_of(k6, e6, &l6[i], k);
        d[i] = mh && m6[i] ? farthest(mh, m6[i]) : NAN;
    }
    printf("3-dof modes %d; 6-dof with springs of 10, 31.6, 100 rad/s: "
           "farthest relative distance %.3g, %.3g, %.3g\n",
           mh ? mh->nmodes : -1, d[0], d[1], d[2]);
    /* k ten times stiffer: the distance falls ten times (the held
     * coordinates follow the slow motion quasi-statically, their
     * deflection ~ 1/k). */
    CHECK(d[0] / d[1] > 7 && d[1] / d[2] > 7, "slow modes converge like 1/k "
          "(ratios %.3g, %.3g)", d[0] / d[1], d[1] / d[2]);
    CHECK(d[2] < 1e-3, "at 100 rad/s every 3-dof mode within %.3g", d[2]);
    for (int i = 0; i < 3; i++) {
        ts_eigen_free(m6[i]);
        ts_linear_free(l6[i]);
    }
    ts_eigen_free(mh);
    ts_linear_free(lh);
    ts_equilibrium_free(e6);
    ts_equilibrium_free(eh);
    ts_equilibrium_free(e3);
    ts_kernel_free(k6);
    ts_kernel_free(kh);
    ts_kernel_free(k3);
    ts_scene_free(s6);
    ts_scene_free(h3);
    ts_scene_free(t3);
    ts_scene_free(s3);
}

/* ---- 4. thrust = drag(U) ---------------------------------------------- */

static void test_thrust_drag(void)
{
    const ts_system *s0 = NULL;
    ts_scene *base = tscene_load(units, SHIP);
    if (!base)
        return;
    s0 = base->system;
    const ts_vehicle *v = s0->bodies[s0->tow.vehicle].vehicle;
    const double rho = s0->env.water_density, d = 0.0173, L = 200,
                 cdt = 0.01;
    /* The hull's axial drag and the fins' Cd0 on the double body, half
     * submerged; the neutral cable's skin friction. */
    double D = v->component[0].diameter, hull = v->component[0].cd_axial;
    double fins = v->component[1].area * v->component[1].cd0 +
                  v->component[2].area * v->component[2].cd0;
    double K = 0.5 * rho * (0.5 * (hull * M_PI * D * D / 4 + fins) +
                            cdt * M_PI * d * L);
    char mpl[96];
    snprintf(mpl, sizeof mpl, "    weight:>    mass_per_length: %.17g kg/m\n"
             "    tangential_drag: %g", rho * M_PI * d * d / 4, cdt);
    const char *thrust[] = {"  point: [0, 0, 1 m]",
                            "  tow_point: [-12 m, 0, 1 m]",
                            "    power:>    thrust: 15 kN",
                            "    max_thrust:>", "    to:>", mpl,
                            "bodies:!", NULL};
    const char *power[] = {"  point: [0, 0, 1 m]",
                           "  tow_point: [-12 m, 0, 1 m]", "    to:>", mpl,
                           "bodies:!", NULL};
    const char *const *sets[2] = {thrust, power};
    double want[2] = {sqrt(15e3 / K), cbrt(v->propulsion.power / K)};
    for (int c = 0; c < 2; c++) {
        ts_scene *sc = ship_variant(sets[c]);
        CHECK(sc != NULL, "%s scene parses", c ? "power" : "thrust");
        if (!sc)
            continue;
        ts_kernel *k;
        ts_equilibrium *eq = solve(sc->system, &k);
        const ts_vehicle_result *r = &eq->vehicles[ts_kernel_root(k)];
        /* Solved to 1e-10 of the largest force (the weight): U to about
         * 1e-10 relative. */
        CHECK(eq->converged, "converged (residual %.3g)", eq->residual);
        CHECK_REL(eq->speed, want[c], 1e-9,
                  c ? "U = (P / K)^(1/3) at 90 kW" : "U = sqrt(T / K) at 15 kN");
        CHECK(fabs(r->yaw) < 1e-12 && r->pitch == 0 && r->roll == 0,
              "straight and level (yaw %.3g rad)", r->yaw);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        ts_scene_free(sc);
    }
    ts_scene_free(base);
}

/* ---- 5. the steady turn at a rudder ------------------------------------- */

static void test_turn(void)
{
    static const char *const rudder[] = {
        "    links: 6", "      limit:>      limit: 35 deg\n"
        "      deflection: 4 deg", NULL};
    ts_scene *sc = ship_variant(rudder);
    if (!sc) {
        CHECK(0, "ship with 10 deg of rudder parses");
        return;
    }
    ts_kernel *k;
    ts_equilibrium *eq = solve(sc->system, &k);
    const ts_vehicle_result *re = &eq->vehicles[ts_kernel_root(k)];
    CHECK(eq->converged && fabs(eq->turn_rate) > 1e-3, "rudder 4 deg: "
          "Newton's steady turn %.6g rad/s at %.6g m/s, drift angle %.4g "
          "deg", eq->turn_rate, eq->speed, re->beta * 180 / M_PI);
    /* Released from that turn with its yaw 0.05 rad off and its tow point
     * moving 0.3 m/s sideways: RK4 for 1200 s (the slowest decay 0.016
     * 1/s leaves 5e-9 of the kick). The circle's centre may settle
     * elsewhere: the ship then circles in M at the same speed through the
     * water, drift angle, tensions, with no yaw rate relative to M. */
    int n = ts_kernel_nstate(k), nq = ts_kernel_nq(k), nl = sc->system->nlinks;
    int qo = ts_kernel_vehicle_offset(k, ts_kernel_root(k));
    double *y = calloc((size_t)n, sizeof(double));
    double *w = malloc(5 * (size_t)n * sizeof(double));
    ts_equilibrium_state(k, eq, y, NULL);
    y[qo] += 0.05;
    y[nq + qo + 2] += 0.3;
    int bad = 0;
    for (int i = 0; i < 24000 && !bad; i++)
        bad = rk4_step(k, y, 0.05, n, w);
    double *f = malloc((size_t)n * sizeof(double));
    ts_kernel_eval(k, y, NULL, f);
    ts_vehicle_result r;
    ts_kernel_vehicle_result(k, ts_kernel_root(k), &r);
    const double *t = ts_kernel_tensions(k);
    double dt = 0;
    for (int l = 0; l < nl; l++)
        dt = fmax(dt, fabs(t[l] - eq->tensions[l]));
    CHECK(!bad && dt < 1e-6 * eq->tensions[0] &&
              fabs(r.speed - re->speed) < 1e-8 &&
              fabs(r.beta - re->beta) < 1e-8 && fabs(y[nq + qo]) < 1e-9,
          "simulated 1200 s from a kicked turn: tensions to %.3g N, speed "
          "through the water %.3g m/s, drift angle %.3g rad, yaw rate "
          "relative to M %.3g rad/s",
          dt, fabs(r.speed - re->speed), fabs(r.beta - re->beta), y[nq + qo]);
    /* The inverse: turn_by rudder at that turn rate gives back 4 deg. */
    char turn[96], by[] = "  dof: 3\n  turn_by: rudder";
    snprintf(turn, sizeof turn, "  speed:>  speed: 4 m/s\n  turn_rate: "
             "%.17g rad/s", eq->turn_rate);
    const char *inv[] = {"    links: 6", "      limit:>      limit: 35 deg",
                         turn, by, NULL};
    ts_scene *si = ship_variant(inv);
    ts_kernel *ki = NULL;
    ts_equilibrium *ei = si ? solve(si->system, &ki) : NULL;
    CHECK(ei && ei->converged &&
              fabs(ei->turn_deflection - 4 * M_PI / 180) < 1e-9 &&
              fabs(ei->speed - eq->speed) < 1e-8,
          "turn_by rudder at that turn rate: the rudder %.12g deg (4), "
          "speed %.12g m/s (%.12g)",
          ei ? ei->turn_deflection * 180 / M_PI : NAN, ei ? ei->speed : NAN,
          eq->speed);
    ts_equilibrium_free(ei);
    ts_kernel_free(ki);
    ts_scene_free(si);
    free(y);
    free(w);
    free(f);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

int main(void)
{
    units = tscene_units();
    ship_text = tf_slurp(SHIP) ? strdup(tf_slurp(SHIP)) : NULL;
    CHECK(ship_text != NULL, "%s read", SHIP);
    if (!units || !ship_text)
        return 1;
    test_energy();
    test_reaction();
    test_stiff_modes();
    test_thrust_drag();
    test_turn();
    free(ship_text);
    ts_units_free(units);
    return tc_done();
}
