/* test_surface.c: the towing vehicle as a surface ship of 3 degrees of
 * freedom (doc/towing-vehicle.md section 7; lib/kernel.c, towing_vehicle
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
 *  6. Wave-induced motion of the tow point (the tow-point inputs with a
 *     towing vehicle, doc/towing-vehicle.md section 8): with the ship's
 *     mass and inertias 1e3 and 1e4 times, the depressor's response to
 *     tow.heave, tow.surge and tow.sway is the prescribed tow's at the
 *     ship's speed, the distance falling like 1 / mass.
 *  7. Linear against nonlinear for a heaving tow point: the kernel (RK4)
 *     and x' = A x + B u under a sine heave of 0.4 and 0.2 m at 0.02 Hz
 *     (one period, 50 s, from the trim) differ by the square of the
 *     amplitude.
 *  8. The ship's rotations (tow.roll, tow.pitch, tow.yaw): a small
 *     rotation theta about e moves the cable's start point r (from the
 *     ship's origin) by theta e x r, so each of the rotations' columns of
 *     B (displacement, rate, acceleration) is the combination (e x r) of
 *     the translations' columns, to the differencing error; the
 *     depressor's pitch gain is r_z surge - r_x heave; roll and yaw of a
 *     ship whose tow point is on its centreline move it sideways only:
 *     the vertical plane does not respond (symmetry), and the sideways
 *     response is -r_z and r_x times the sway's.
 *  9. Linear against nonlinear for a pitching ship with two cables, one
 *     from its tow point and one from a point 4 m forward of it, 2 m to
 *     starboard, 1.5 m below the waterline (below it so that no node of
 *     its light cable sits on the waterline, where the submerged fraction
 *     is kinked and the difference would be first order): a pitch sine of
 *     0.02 and 0.01 rad at 0.05 Hz, the second sphere's depth, second
 *     order in the amplitude.
 * 10. A sea with a pure-pitch RAO on that two-cable ship, referred to the
 *     ship's origin: the spectral gain of the second sphere's depth is
 *     the tow.pitch input's gain times the RAO at every grid point (the
 *     RAO's rotation turns each cable's start about the origin), unlike
 *     one translation of the tow point; a realisation drives tow.pitch.
 * 11. A prescribed tow point p: a rotation about M's origin is the
 *     translation theta x p, in the dense and the sparse model.
 */
#include <complex.h>
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
#include "towstab/response.h"
#include "towstab/seastate.h"

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

/* The ship on 6 links (a check that fails when it does not parse). */
static ts_scene *ship_six_links(void)
{
    static const char *const few[] = {"    links: 6", NULL};
    ts_scene *s = ship_variant(few);
    CHECK(s != NULL, "the ship on 6 links parses");
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
    ts_scene *s3 = ship_six_links();
    if (!s3)
        return;
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

/* ---- 6. heavy ship: the motion input is the prescribed tow's ---------- */

/* The gains of `out` to tow.surge, tow.sway, tow.heave at freq[nf] Hz
 * (g[3][nf][2]) of system s about the equilibrium of system se (the same
 * state and inputs: s itself, or a heavier copy). */
static int gains(const ts_system *se, const ts_system *s, const char *out,
                 const double *freq, int nf, double g[3][4][2],
                 double *speed)
{
    ts_kernel *ke, *k;
    ts_equilibrium *eq = solve(se, &ke);
    ts_err err = {0};
    k = ts_kernel_alloc(s, &err);
    ts_linear *lin = k ? ts_linear_alloc(k, &err) : NULL;
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = TS_LIN_DENSE;
    ts_output o;
    int rc = eq && eq->converged ? ts_linearize_equilibrium(k, eq, &lo, lin,
                                                            &err)
                                 : TS_ECONV;
    if (rc == TS_OK)
        rc = ts_response_output_lookup(k, out, &o, &err);
    for (int c = 0; c < 3 && rc == TS_OK; c++)
        for (int i = 0; i < nf && rc == TS_OK; i++)
            rc = ts_response_at(s, lin, c, &o, 2 * M_PI * freq[i], &g[c][i][0],
                                &g[c][i][1], &err);
    if (rc != TS_OK)
        printf("gains: %s\n", err.msg);
    *speed = eq ? eq->speed : NAN;
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_kernel_free(ke);
    return rc;
}

static void test_heavy_motion(void)
{
    const double freq[4] = {0.01, 0.05, 0.2, 0.8};
    double d[2] = {NAN, NAN}, speed = NAN, gs[3][4][2], gp[3][4][2];
    const ts_system *s0 = NULL;
    ts_scene *base = tscene_load(units, SHIP);
    if (!base)
        return;
    s0 = base->system;
    const ts_body *b = &s0->bodies[s0->tow.vehicle];
    for (int h = 0; h < 2; h++) {
        double heavy = h ? 1e4 : 1e3;
        char mass[96], inertia[160];
        snprintf(mass, sizeof mass, "  mass: %.17g kg", b->mass * heavy);
        snprintf(inertia, sizeof inertia, "  inertia: [%.17g kg*m^2, %.17g "
                 "kg*m^2, %.17g kg*m^2]", b->vehicle->inertia[0] * heavy,
                 b->vehicle->inertia[1] * heavy,
                 b->vehicle->inertia[2] * heavy);
        /* Its straight trim is the ship's (the weight goes into the
         * hull's reaction): linearized there, as its Newton solve would
         * balance forces 1e4 times smaller than its weight. */
        const char *lines[] = {"    links: 8", mass, inertia, NULL};
        const char *same[] = {"    links: 8", NULL};
        ts_scene *sc = ship_variant(lines), *s1 = ship_variant(same);
        if (!sc || !s1 ||
            gains(s1->system, sc->system, "depressor.z", freq, 4, gs,
                  &speed)) {
            CHECK(0, "heavy ship x %g: gains", heavy);
            ts_scene_free(sc);
            ts_scene_free(s1);
            continue;
        }
        /* The same cable and depressor from a prescribed tow point at
         * the ship's tow point, at its speed. */
        char pt[160];
        snprintf(pt, sizeof pt, "name: prescribed\n"
                 "tow: {speed: %.17g m/s, point: [0, 0, -3 m]}\n", speed);
        char *text = strstr(ship_text, "cables:");
        size_t n = strlen(pt) + strlen(text) + 1;
        char *yaml = malloc(n);
        snprintf(yaml, n, "%s%s", pt, text);
        char *lk = strstr(yaml, "links: 20");
        if (lk)
            memcpy(lk, "links: 8 ", 9);
        ts_scene *sp = tscene_parse(units, yaml);
        free(yaml);
        double sp_speed;
        if (!sp || gains(sp->system, sp->system, "depressor.z", freq, 4, gp,
                         &sp_speed)) {
            CHECK(0, "prescribed tow: gains");
        } else {
            d[h] = 0;
            double big = 0;
            for (int c = 0; c < 3; c++)
                for (int i = 0; i < 4; i++) {
                    d[h] = fmax(d[h], hypot(gs[c][i][0] - gp[c][i][0],
                                            gs[c][i][1] - gp[c][i][1]));
                    big = fmax(big, hypot(gp[c][i][0], gp[c][i][1]));
                }
            d[h] /= big;
            printf("ship x %g: depressor.z per m of tow.surge, sway, heave "
                   "at %g .. %g Hz: largest distance from the prescribed "
                   "tow's %.3g of the largest gain %.3g (heave at 0.2 Hz: "
                   "%.6f%+.6fi against %.6f%+.6fi)\n", heavy, freq[0],
                   freq[3], d[h], big, gs[2][2][0], gs[2][2][1],
                   gp[2][2][0], gp[2][2][1]);
        }
        ts_scene_free(sp);
        ts_scene_free(sc);
        ts_scene_free(s1);
    }
    /* A 1e3 times heavier ship still yields to the cable's pull: its
     * surge and sway responses, and so the difference, fall like 1 /
     * mass (ratio 10). */
    CHECK(d[0] / d[1] > 8 && d[0] / d[1] < 12 && d[1] < 1e-3,
          "heavy ship: the tow-point motion input is the prescribed tow's "
          "(relative distance %.3g, %.3g; ratio %.3g)", d[0], d[1],
          d[0] / d[1]);
    ts_scene_free(base);
}

/* ---- 7. linear against nonlinear: a slow heave --------------------------- */

/* The kernel (lin NULL) or the linear model x' = A x + B u under a sine
 * of amplitude a at om rad/s on tow input `axis` (its displacement's
 * index: 2 heave, TS_IN_ROT + 1 pitch); u[ninput] holds the input of the
 * last evaluation. */
typedef struct heave_run {
    ts_kernel *k;
    const ts_linear *lin;
    double a, om;
    double *u;
    int axis;
} heave_run;

static void heave_rhs(heave_run *h, double t, const double *x, double *out)
{
    double *u = h->u, a = h->a, om = h->om;
    u[h->axis] = a * sin(om * t);
    u[h->axis + 3] = a * om * cos(om * t);
    u[h->axis + 6] = -a * om * om * sin(om * t);
    if (!h->lin) {
        ts_kernel_eval(h->k, x, u, out);
        return;
    }
    int n = h->lin->nstate;
    for (int r = 0; r < n; r++) {
        double v = 0;
        for (int j = 0; j < n; j++)
            v += h->lin->A[r + (size_t)j * n] * x[j];
        for (int j = 0; j < TS_NINPUT; j++)
            v += h->lin->B[r + (size_t)j * n] * u[j];
        out[r] = v;
    }
}

/* One RK4 step of length dt from t, x[n] in place; w[5 n] scratch. */
static void heave_step(heave_run *h, double t, double dt, double *x,
                       double *w)
{
    int n = ts_kernel_nstate(h->k);
    double *st[4] = {w, w + n, w + 2 * n, w + 3 * n}, *xt = w + 4 * n;
    static const double cs[4] = {0, 0.5, 0.5, 1};
    for (int s = 0; s < 4; s++) {
        for (int j = 0; j < n; j++)
            xt[j] = x[j] + (s ? cs[s] * dt * st[s - 1][j] : 0);
        heave_rhs(h, t + cs[s] * dt, xt, st[s]);
    }
    for (int j = 0; j < n; j++)
        x[j] += dt / 6 * (st[0][j] + 2 * st[1][j] + 2 * st[2][j] + st[3][j]);
}

static void test_heave_linear(void)
{
    ts_scene *sc = ship_six_links();
    if (!sc)
        return;
    ts_kernel *k;
    ts_equilibrium *eq = solve(sc->system, &k);
    ts_err err = {0};
    ts_linear *lin = ts_linear_alloc(k, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = TS_LIN_DENSE;
    int rc = ts_linearize_equilibrium(k, eq, &lo, lin, &err);
    CHECK(rc == TS_OK, "linearized (%s)", rc ? err.msg : "ok");
    int n = ts_kernel_nstate(k), nin = ts_kernel_ninput(k);
    int nl = sc->system->nlinks;
    double *y0 = calloc((size_t)n, sizeof(double)), *y = calloc((size_t)n,
                                                              sizeof(double));
    double *x = calloc((size_t)n, sizeof(double)), *u = calloc((size_t)nin,
                                                             sizeof(double));
    double *w = malloc(5 * (size_t)n * sizeof(double)), *f = malloc(
        (size_t)n * sizeof(double));
    double diff[2] = {0, 0}, resp[2] = {0, 0}, dt = 0.02, om = 2 * M_PI * 0.02;
    const double *z0 = NULL;
    double *dr = malloc(3 * ((size_t)nl + 1) * sizeof(double));
    for (int c = 0; rc == TS_OK && c < 2; c++) {
        double a = c ? 0.2 : 0.4;
        ts_equilibrium_state(k, eq, y0, NULL);
        memcpy(y, y0, (size_t)n * sizeof(double));
        memset(x, 0, (size_t)n * sizeof(double));
        /* 50 s: one period of the heave; the depressor's depth. */
        heave_run hn = {k, NULL, a, om, u, 2}, hl = {k, lin, a, om, u, 2};
        for (int i = 0; i < 2500; i++) {
            double t = i * dt;
            heave_step(&hn, t, dt, y, w);
            heave_step(&hl, t, dt, x, w);
            /* The depressor's depth: nonlinear from the kernel, linear
             * from the node displacements of x. */
            ts_kernel_eval(k, y, u, f);
            z0 = ts_kernel_positions(k);
            ts_linear_node_displacements(sc->system, lin, x, dr);
            /* The linear depth: the links' part and the tow point's own
             * displacement, which every node below it shares. */
            double zl = dr[3 * nl + 2] + u[2];
            double zn = z0[3 * nl + 2] - eq->positions[3 * nl + 2];
            diff[c] = fmax(diff[c], fabs(zn - zl));
            resp[c] = fmax(resp[c], fabs(zl));
        }
    }
    printf("tow.heave 0.4 and 0.2 m at 0.02 Hz: depressor depth linear "
           "less nonlinear %.3g and %.3g m of responses %.3g and %.3g m\n",
           diff[0], diff[1], resp[0], resp[1]);
    /* Second order in the amplitude (ratio 4), and small against the
     * response. */
    CHECK(rc == TS_OK && diff[0] / diff[1] > 3.5 && diff[0] / diff[1] < 4.5 &&
              diff[0] < 0.02 * resp[0],
          "slow heave: linear and nonlinear agree to second order in the "
          "amplitude (ratio %.3g)", diff[0] / diff[1]);
    free(dr);
    free(y0);
    free(y);
    free(x);
    free(u);
    free(w);
    free(f);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* ---- 8. the rotations' columns and gains --------------------------------- */

/* A scene's trim, linearized (dense), and the start point r (M axes,
 * from the ship's origin) of its first cable: R times the ship's attach
 * point. */
typedef struct trim {
    ts_scene *sc;
    ts_kernel *k;
    ts_equilibrium *eq;
    ts_linear *lin;
    double r[3];
} trim;

static void trim_free(trim *c)
{
    ts_linear_free(c->lin);
    ts_equilibrium_free(c->eq);
    ts_kernel_free(c->k);
    ts_scene_free(c->sc);
}

/* Solve and linearize sc (owned by c from here); 0 with a check that
 * failed (c freed). */
static int trim_open(trim *c, ts_scene *sc, const char *what)
{
    memset(c, 0, sizeof *c);
    c->sc = sc;
    if (!sc)
        return 0;
    c->eq = solve(sc->system, &c->k);
    ts_err err = {0};
    const ts_system *s = sc->system;
    if (c->eq && c->eq->converged) {
        double *y = calloc((size_t)ts_kernel_nstate(c->k), sizeof(double));
        double R[9];
        ts_equilibrium_state(c->k, c->eq, y, NULL);
        ts_kernel_get_vehicle(c->k, ts_kernel_root(c->k), y, R, NULL);
        const double *p = s->bodies[s->tow.vehicle].vehicle->attach;
        for (int i = 0; i < 3; i++)
            c->r[i] = R[3 * i] * p[0] + R[3 * i + 1] * p[1] +
                      R[3 * i + 2] * p[2];
        free(y);
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        lo.model = TS_LIN_DENSE;
        c->lin = ts_linear_alloc(c->k, &err);
        if (c->lin &&
            ts_linearize_equilibrium(c->k, c->eq, &lo, c->lin, &err)) {
            printf("linearize: %s\n", err.msg);
            ts_linear_free(c->lin);
            c->lin = NULL;
        }
    }
    CHECK(c->lin != NULL, "%s linearized", what);
    if (!c->lin)
        trim_free(c);
    return c->lin != NULL;
}

static void test_rotation_columns(void)
{
    trim c;
    if (!trim_open(&c, ship_six_links(), "the ship"))
        return;
    ts_kernel *k = c.k;
    const ts_linear *lin = c.lin;
    const ts_scene *sc = c.sc;
    const double *r = c.r;
    int n = lin->nstate, nq = lin->nq, nr = n - nq;
    /* Column j of B's lower part, its error estimate. */
#define BCOL(j) (lin->B + (size_t)(j) * n + nq)
#define BERR(j) (lin->Berr + (size_t)(j) * nr)
    /* Each rotation column against (e_a x r) . the translation columns
     * of the same order: the difference within ten times the error
     * estimates of the columns combined (central differences: their
     * truncation estimates, and the rounding noise of f over each
     * column's step, fnoise / (sqrt 2 h): doc/linear.md). */
    double worst = 0, big = 0;
    for (int a = 0; a < 3; a++) {
        double e[3] = {0, 0, 0}, c[3];
        e[a] = 1;
        c[0] = e[1] * r[2] - e[2] * r[1];
        c[1] = e[2] * r[0] - e[0] * r[2];
        c[2] = e[0] * r[1] - e[1] * r[0];
        for (int q = 0; q < 3; q++) {
            int jr = TS_IN_ROT + 3 * q + a, jt = 3 * q;
            for (int i = 0; i < nr; i++) {
                double nz = lin->fnoise ? lin->fnoise[i] / sqrt(2.0) : 0;
                double comb = 0, allow = fabs(BERR(jr)[i]) +
                                         nz / lin->h[n + jr];
                for (int m = 0; m < 3; m++) {
                    comb += c[m] * BCOL(jt + m)[i];
                    allow += fabs(c[m]) * (fabs(BERR(jt + m)[i]) +
                                           nz / lin->h[n + jt + m]);
                }
                double d = fabs(BCOL(jr)[i] - comb);
                big = fmax(big, fabs(comb));
                allow *= 10;
                if (d > 0)
                    worst = fmax(worst, d / allow);
            }
        }
    }
    printf("rotations' columns of B against (e x r) . translations' (r = "
           "%.3f, %.3f, %.3f m): largest difference %.3g of the allowance "
           "(largest entry %.3g)\n", r[0], r[1], r[2], worst, big);
    CHECK(worst <= 1 && big > 0, "B: every rotation column is (e x r) . "
          "the translation columns within the differencing error (%.3g of "
          "the allowance)", worst);
#undef BCOL
#undef BERR

    /* Gains: pitch = r_z surge - r_x heave; roll = -r_z sway and yaw =
     * r_x sway (r_y = 0: on the centreline); roll and yaw leave the
     * vertical plane at rest. */
    const double freq[3] = {0.01, 0.1, 0.4};
    const char *outs[2] = {"depressor.z", "depressor.y"};
    double dp = 0, dry = 0, plane = 0, scale = 0;
    ts_err err = {0};
    for (int o = 0; o < 2; o++) {
        ts_output out;
        if (ts_response_output_lookup(k, outs[o], &out, &err)) {
            CHECK(0, "output %s: %s", outs[o], err.msg);
            continue;
        }
        for (int i = 0; i < 3; i++) {
            double w = 2 * M_PI * freq[i], g[6][2];
            for (int a = 0; a < 6; a++)
                ts_response_at(sc->system, lin,
                               a < 3 ? a : TS_IN_ROT + a - 3, &out, w,
                               &g[a][0], &g[a][1], &err);
            for (int c = 0; c < 2; c++) {
                scale = fmax(scale, fabs(g[o ? 1 : 2][c]));
                if (o == 0) {
                    dp = fmax(dp, fabs(g[4][c] - (r[2] * g[0][c] -
                                                  r[0] * g[2][c])));
                    plane = fmax(plane, fmax(fabs(g[3][c]), fabs(g[5][c])));
                } else {
                    dry = fmax(dry, fmax(fabs(g[3][c] + r[2] * g[1][c]),
                                         fabs(g[5][c] - r[0] * g[1][c])));
                }
            }
        }
    }
    printf("gains at 0.01, 0.1, 0.4 Hz: pitch less r_z surge - r_x heave "
           "%.3g; roll, yaw less -r_z, r_x sway %.3g; roll and yaw in the "
           "vertical plane %.3g (largest translation gain %.3g)\n", dp, dry,
           plane, scale);
    /* The gains of a column combination are the combination of the
     * gains to the columns' error (checked above): 1e-6 of the largest
     * gain; the vertical plane's to the rounding of a symmetric trim. */
    CHECK(dp <= 1e-6 * scale && dry <= 1e-6 * scale,
          "pitch gain = r_z surge - r_x heave, roll = -r_z sway, yaw = "
          "r_x sway (%.3g, %.3g of %.3g)", dp, dry, scale);
    CHECK(plane <= 1e-9 * scale, "roll and yaw do not move the depressor "
          "up or down (symmetry: %.3g)", plane);
    trim_free(&c);
}

/* ---- 9. two cables: linear against nonlinear under pitch ------------------ */

/* The ship on 6 links with a second cable from a point forward of the
 * tow point, to starboard and below the waterline, and a second sphere. */
static ts_scene *ship_two_cables(void)
{
    static const char *const two[] = {
        "    links: 6",
        "bodies:>  - name: cable2\n"
        "    from: ship\n"
        "    at: [-8 m, 2 m, 1.5 m]\n"
        "    to: fish\n"
        "    length: 60 m\n"
        "    diameter: 0.0173 m\n"
        "    weight: 9.6 N/m\n"
        "    links: 6\n"
        "bodies:\n"
        "  - name: fish\n"
        "    type: sphere\n"
        "    diameter: 0.5 m\n"
        "    wet_weight: 3000 N",
        NULL};
    ts_scene *s = ship_variant(two);
    CHECK(s != NULL, "the ship with two cables parses");
    return s;
}

static void test_pitch_linear(void)
{
    trim c;
    if (!trim_open(&c, ship_two_cables(), "the two-cable ship"))
        return;
    ts_kernel *k = c.k;
    const ts_linear *lin = c.lin;
    const ts_equilibrium *eq = c.eq;
    const ts_system *s = c.sc->system;
    int fish = -1;
    for (int i = 0; i < s->nnodes; i++)
        if (s->nodes[i].body >= 0 &&
            !strcmp(s->bodies[s->nodes[i].body].name, "fish"))
            fish = i;
    int n = ts_kernel_nstate(k), nin = ts_kernel_ninput(k);
    double *y = calloc((size_t)n, sizeof(double));
    double *x = calloc((size_t)n, sizeof(double));
    double *u = calloc((size_t)nin, sizeof(double));
    double *w = malloc(5 * (size_t)n * sizeof(double));
    double *f = malloc((size_t)n * sizeof(double));
    double *dr = malloc(3 * (size_t)s->nnodes * sizeof(double));
    double diff[2] = {0, 0}, resp[2] = {0, 0}, dt = 0.02;
    double om = 2 * M_PI * 0.05, shift[3];
    int pitch = TS_IN_ROT + 1;
    for (int c = 0; lin && fish > 0 && c < 2; c++) {
        double a = c ? 0.01 : 0.02;
        ts_equilibrium_state(k, eq, y, NULL);
        memset(x, 0, (size_t)n * sizeof(double));
        heave_run hn = {k, NULL, a, om, u, pitch}, hl = {k, lin, a, om, u,
                                                        pitch};
        /* 20 s: one period of the pitch. */
        for (int i = 0; i < 1000; i++) {
            double t = i * dt;
            heave_step(&hn, t, dt, y, w);
            heave_step(&hl, t, dt, x, w);
            ts_kernel_eval(k, y, u, f);
            const double *z = ts_kernel_positions(k);
            ts_linear_node_displacements(s, lin, x, dr);
            ts_linear_tow_shift(lin, fish, pitch, shift);
            double zl = dr[3 * fish + 2] + shift[2] * u[pitch];
            double zn = z[3 * fish + 2] - eq->positions[3 * fish + 2];
            diff[c] = fmax(diff[c], fabs(zn - zl));
            resp[c] = fmax(resp[c], fabs(zl));
        }
    }
    printf("tow.pitch 0.02 and 0.01 rad at 0.05 Hz, two cables: the second "
           "sphere's depth linear less nonlinear %.3g and %.3g m of "
           "responses %.3g and %.3g m\n", diff[0], diff[1], resp[0],
           resp[1]);
    CHECK(fish > 0 && diff[0] / diff[1] > 3.5 && diff[0] / diff[1] < 4.5 &&
              diff[0] < 0.02 * resp[0],
          "pitch: linear and nonlinear agree to second order in the "
          "amplitude (ratio %.3g)", diff[0] / diff[1]);
    free(y);
    free(x);
    free(u);
    free(w);
    free(f);
    free(dr);
    trim_free(&c);
}

/* ---- 10. a ship's RAOs feed its rotations -------------------------------- */

static void test_rao_rotation(void)
{
    trim c;
    if (!trim_open(&c, ship_two_cables(), "the two-cable ship (sea)"))
        return;
    const ts_system *s = c.sc->system;
    ts_err err = {0};
    /* A pure-pitch RAO, one heading (head seas): the wave slope with a
     * lead, in long waves. */
    enum { NF = 24 };
    double w[NF], hd[1] = {M_PI};
    for (int k = 0; k < NF; k++)
        w[k] = 0.3 + k * (2.0 - 0.3) / (NF - 1);
    ts_rao *rao = ts_rao_alloc(1, hd, NF, w, &err);
    for (int k = 0; rao && k < NF; k++)
        ts_rao_set(rao, TS_DOF_PITCH, 0, k,
                   w[k] * w[k] / 9.80665 / (1 + w[k] * w[k]), 1.1 + 0.3 * w[k],
                   &err);
    if (rao)
        ts_rao_finish(rao, &err);
    ts_sea *sea = ts_sea_jonswap(1.5, 7.0, 3.3, M_PI, &err);
    /* The reference point: the ship's origin at its trim, from the
     * kernel (r_A less R times the attach point), so that the RAOs'
     * translation there is zero and the rotation is all. */
    double *y = calloc((size_t)ts_kernel_nstate(c.k), sizeof(double));
    double R[9], ref[3];
    ts_equilibrium_state(c.k, c.eq, y, NULL);
    ts_kernel_get_vehicle(c.k, ts_kernel_root(c.k), y, R, NULL);
    const double *p = s->bodies[s->tow.vehicle].vehicle->attach;
    for (int i = 0; i < 3; i++)
        ref[i] = c.eq->positions[i] - (R[3 * i] * p[0] + R[3 * i + 1] * p[1] +
                                       R[3 * i + 2] * p[2]);
    ts_seaway way;
    ts_seastate_opts so;
    ts_seastate_opts_default(&so);
    so.intervals = 32;
    ts_output out;
    ts_seastate *st = NULL;
    int rc = rao && sea ? ts_seaway_init(&way, s, sea, rao, ref, &err)
                        : TS_ENOMEM;
    if (rc == TS_OK)
        rc = ts_response_output_lookup(c.k, "fish.z", &out, &err);
    if (rc == TS_OK)
        rc = ts_seastate_compute(s, c.lin, &way, &out, &so, &st, &err);
    CHECK(rc == TS_OK && way.rotations && st->ninputs == 6,
          "a towing ship's sea drives its translations and rotations (%s)",
          rc ? err.msg : "ok");
    /* Against the pitch input's gain times the RAO at every grid point,
     * and against one translation of the tow point (the start of the
     * first cable, theta x r_A), which the second cable does not see. */
    double dmax = 0, gmax = 0, dold = 0;
    for (int i = 0; rc == TS_OK && i < st->npoints; i++) {
        double xr[TS_NDOF], xi[TS_NDOF], h[2], t[3][2];
        ts_rao_eval(rao, M_PI, st->omega[i], xr, xi, &err);
        double complex th = xr[TS_DOF_PITCH] + I * xi[TS_DOF_PITCH];
        double we = st->omega_e[i];
        ts_response_at(s, c.lin, TS_IN_ROT + 1, &out, we, &h[0], &h[1], &err);
        for (int a = 0; a < 3; a++)
            ts_response_at(s, c.lin, a, &out, we, &t[a][0], &t[a][1], &err);
        double complex g = st->gain_re[i] + I * st->gain_im[i];
        double complex want = (h[0] + I * h[1]) * th;
        /* theta_y e_y x r = (r_z, 0, -r_x) theta_y */
        double complex old = ((t[0][0] + I * t[0][1]) * c.r[2] -
                              (t[2][0] + I * t[2][1]) * c.r[0]) * th;
        dmax = fmax(dmax, cabs(g - want));
        dold = fmax(dold, cabs(g - old));
        gmax = fmax(gmax, cabs(want));
    }
    printf("pure-pitch RAO, two cables: the second sphere's gain per m of "
           "wave less the pitch input's gain times the RAO %.3g of %.3g; "
           "less one translation of the tow point %.3g\n", dmax, gmax, dold);
    /* The same gains, summed in another order: rounding (1e-12), and the
     * origin's translation, theta x (the origin from the linearization
     * less the kernel's), rounding too. */
    CHECK(rc == TS_OK && dmax <= 1e-10 * gmax && gmax > 0,
          "sea: the rotation RAO is the pitch input (%.3g of %.3g)", dmax,
          gmax);
    CHECK(rc == TS_OK && dold > 0.05 * gmax,
          "sea: not one translation of the tow point (that would differ by "
          "%.3g of %.3g)", dold, gmax);
    /* A realisation drives tow.pitch. */
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_sea_realisation real;
    ts_seaway_set_trim(&way, c.k, y);
    ts_sea_realisation_default(&way, &real);
    real.components = 16;
    int pitch = 0;
    if (ex && ts_seaway_excitation(&way, &real, ex, NULL, &err) == TS_OK)
        for (int i = 0; i < ts_excitation_nsignals(ex); i++)
            pitch |= ts_excitation_signal(ex, i)->axis == TS_AXIS_PITCH;
    CHECK(pitch, "a realisation of that sea drives tow.pitch");
    ts_excitation_free(ex);
    free(y);
    ts_seastate_free(st);
    ts_sea_free(sea);
    ts_rao_free(rao);
    trim_free(&c);
}

/* ---- 11. a prescribed tow point's rotations --------------------------- */

/* The ship's rotation about M's origin moves a prescribed tow point p by
 * theta x p: on examples/survey_tow_sea.yaml (p = (0, 0, -5) m) the
 * fish's depth per rad of tow.pitch is -5 times its gain per m of
 * tow.surge, per rad of tow.roll 5 times that per m of tow.sway, in the
 * dense model (the columns differenced at their own steps: 1e-6) and the
 * sparse one (the tow point's displacement e x p itself: rounding). */
static void test_prescribed_rotation(void)
{
    ts_scene *sc = tscene_load(units, "examples/survey_tow_sea.yaml");
    if (!sc)
        return;
    const ts_system *s = sc->system;
    ts_err err = {0};
    ts_kernel *k;
    ts_equilibrium *eq = solve(s, &k);
    const double *p = s->tow.point;
    for (int m = 0; m < 2; m++) {
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        lo.model = m ? TS_LIN_SPARSE : TS_LIN_DENSE;
        ts_linear *lin = ts_linear_alloc(k, &err);
        ts_output out;
        int rc = lin && eq && eq->converged
                     ? ts_linearize_equilibrium(k, eq, &lo, lin, &err)
                     : TS_ECONV;
        if (!rc)
            rc = ts_response_output_lookup(k, "fish.z", &out, &err);
        double d = 0, big = 0;
        for (int i = 0; !rc && i < 3; i++) {
            double w = 2 * M_PI * (0.02 + 0.1 * i), g[4][2];
            const int in[4] = {TS_IN_DISP, TS_IN_DISP + 1, TS_IN_ROT + 1,
                               TS_IN_ROT};
            for (int j = 0; !rc && j < 4; j++)
                rc = ts_response_at(s, lin, in[j], &out, w, &g[j][0],
                                    &g[j][1], &err);
            for (int c = 0; !rc && c < 2; c++) {
                /* e_y x p = (p_z, 0, -p_x), e_x x p = (0, -p_z, p_y) */
                d = fmax(d, fabs(g[2][c] - p[2] * g[0][c]));
                d = fmax(d, fabs(g[3][c] + p[2] * g[1][c]));
                big = fmax(big, fabs(p[2] * g[0][c]));
            }
        }
        printf("prescribed tow point (%s): fish.z per rad of tow.pitch less "
               "p_z tow.surge's, of tow.roll less -p_z tow.sway's: %.3g of "
               "%.3g\n", m ? "sparse" : "dense", d, big);
        CHECK(rc == TS_OK && big > 0 && d <= (m ? 1e-12 : 1e-6) * big,
              "prescribed tow point, %s model: a rotation is the translation "
              "theta x p (%.3g of %.3g) %s", m ? "sparse" : "dense", d, big,
              rc ? err.msg : "");
        ts_linear_free(lin);
    }
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
    test_heavy_motion();
    test_heave_linear();
    test_rotation_columns();
    test_pitch_linear();
    test_rao_rotation();
    test_prescribed_rotation();
    free(ship_text);
    ts_units_free(units);
    return tc_done();
}
