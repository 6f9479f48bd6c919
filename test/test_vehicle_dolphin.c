/* test_vehicle_dolphin.c: the data of the DOLPHIN-like towing vehicle
 * (doc/dolphin.md, test/scenes/dolphin.yaml) checked through the vehicle
 * model (lib/vehicle.c), so that the scene, the page and the physics
 * agree.
 *
 *  1. Mass equals buoyancy at the running depth: m = rho V (the page's
 *     sums, to their rounding).
 *  2. Level trim at rest: weight and buoyancy give no pitch or roll
 *     moment about the body origin.
 *  3. Roll stability: heeled by 10 deg, the righting moment about the
 *     mass centre is rho g V BG sin(10 deg) (BG 0.1464 m): 5.68 kN m/rad.
 *  4. Straight running at 5 m/s: the components' drag is the page's
 *     table (hull 1630, mast 389, keel 123, bulb 181, planes 308, wave
 *     375 N: 3006 N), with no side or vertical force.
 *  5. Static stability in pitch and yaw at 5 m/s: the moment about the
 *     mass centre (hydrodynamics and the Munk moment) falls with the angle
 *     of attack and rises with the sideslip, turning the nose back into
 *     the flow; and the pitch moment of the drag at zero angle, which the
 *     tailplanes must trim.
 * Tolerances are stated at each check with their reason. */
#include "vehicle.h"

#include <math.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/system.h"

#define RHO 1025.0

/* A level state: chart C, angles th, rates thd, attach point at rA moving
 * at rdA (M, relative to M), fully submerged, no flow. */
static void state_at(const ts_vehicle *v, const double C[9],
                     const double th[3], const double thd[3],
                     const double rA[3], const double rdA[3],
                     tsi_vehicle_state *st)
{
    memset(st, 0, sizeof *st);
    tsi_vehicle_kinematics(v, C, th, thd, 0.0, rA, rdA, st);
    st->frac = 1.0;
}

/* The moment about the mass centre of the generalised force G6 about the
 * attach point: M_G = M_A - (r_G - r_A) x F (body axes). */
static void about_g(const ts_vehicle *v, const double G6[6], double M[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = v->mass_centre[i] - v->attach[i];
    M[0] = G6[3] - (r[1] * G6[2] - r[2] * G6[1]);
    M[1] = G6[4] - (r[2] * G6[0] - r[0] * G6[2]);
    M[2] = G6[5] - (r[0] * G6[1] - r[1] * G6[0]);
}

static void test_dolphin(const ts_scene *sc)
{
    const ts_system *sys = sc->system;
    int b = ts_system_find_body(sys, "dolphin");
    if (!CHECK(b >= 0 && sys->bodies[b].type == TS_BODY_VEHICLE,
               "the dolphin is a vehicle"))
        return;
    const ts_body *B = &sys->bodies[b];
    const ts_vehicle *v = B->vehicle;
    double g = sys->env.gravity;
    /* The mast (a surface-piercing component): 2.025 m of it under water
     * at the running depth, its foot 0.45 m above O. */
    const ts_component *mast = NULL;
    for (int c = 0; c < v->ncomponents; c++)
        if (v->component[c].type == TS_COMP_MAST)
            mast = &v->component[c];
    if (!CHECK(mast != NULL, "the dolphin has a mast"))
        return;
    double zrun = 2.475, s_run = zrun + mast->position[2];
    double Vm = mast->area * s_run, Vt = v->volume + Vm;
    CHECK_NEAR(s_run / mast->length, 0.70, 0.0005,
               "the mast is 70 % submerged at the running depth");
    /* 1. The page rounds volumes to 0.1 l and masses to 0.1 kg. */
    CHECK_NEAR(B->mass, RHO * Vt, 0.2,
               "mass = rho V at the running depth, the mast's part "
               "included (kg)");

    ts_err err = {0};
    tsi_vehicle_ws *w = tsi_vehicle_ws_alloc(v, &err);
    if (!CHECK(w != NULL, "workspace (%s)", err.msg))
        return;
    /* Control deflections 0, ballast tanks at their trim fills. */
    double delta[TS_VEHICLE_MAX_COMPONENTS] = {0};
    for (int c = 0; c < v->ncomponents; c++)
        if (v->component[c].type == TS_COMP_BALLAST)
            delta[c] = v->component[c].deflection;

    /* 2. At rest, level. The generalised force is about the attach
     * point A; moments here are about the mass centre G (about_g), where
     * weight has none: what is left is buoyancy's, zero in pitch when the
     * buoyancy centre is over G (x_B = x_G, to the page's 0.1 mm). */
    tsi_vehicle_state st;
    double C[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, th[3] = {0, 0, 0},
           thd[3] = {0, 0, 0}, rA[3] = {0, 0, zrun + v->attach[2]},
           rdA[3] = {0, 0, 0};
    double Gf[6], Mg[3];
    state_at(v, C, th, thd, rA, rdA, &st);
    tsi_vehicle_loads(v, w, B->mass, RHO, g, &st, delta, Gf, NULL);
    about_g(v, Gf, Mg);
    double W = RHO * g * Vt;
    CHECK(fabs(Mg[1]) < 1e-4 * W && fabs(Mg[0]) < 1e-9,
          "level at rest: pitch moment %.3g N m (buoyancy %.0f N times "
          "1e-4 m), roll %.3g N m", Mg[1], W, Mg[0]);
    CHECK(fabs(Gf[2]) < 0.2 * g,
          "at rest weight and buoyancy balance: net %.3g N", Gf[2]);

    /* 3. Heeled by +-phi about x through O (O held at the running
     * depth): the righting moment about G per radian, by central
     * differences, is the metacentric rho g (V BG + J), V BG the whole
     * volume's (hull and the mast's submerged part) and J the mast's
     * waterplane moment about x, A t^2 / 16: to 1e-6 (truncation phi^2
     * = 1e-8, rounding 1e-12 N m / phi against 5.7 kN m). */
    double phi = 1e-4, slope = 0;
    for (int sgn = -1; sgn <= 1; sgn += 2) {
        th[0] = sgn * phi;
        double R[9], rO[3] = {0, 0, zrun};
        tsi_rot123(th, R);
        for (int i = 0; i < 3; i++)
            rA[i] = rO[i] + R[3 * i] * v->attach[0] +
                    R[3 * i + 1] * v->attach[1] + R[3 * i + 2] * v->attach[2];
        state_at(v, C, th, thd, rA, rdA, &st);
        tsi_vehicle_loads(v, w, B->mass, RHO, g, &st, delta, Gf, NULL);
        about_g(v, Gf, Mg);
        slope += sgn * Mg[0] / (2 * phi);
    }
    th[0] = 0;
    rA[0] = rA[1] = 0;
    rA[2] = zrun + v->attach[2];
    double zB = (v->volume * v->buoyancy_centre[2] +
                 Vm * (mast->position[2] - 0.5 * s_run)) / Vt;
    double BG = v->mass_centre[2] - zB;
    double J = mast->area * mast->thickness * mast->thickness / 16;
    CHECK_REL(slope, -RHO * g * (Vt * BG + J), 1e-6,
              "heeled: righting moment per radian about G, -rho g (V BG + "
              "J) (N m/rad)");
    CHECK_NEAR(-slope / 1000, 5.68, 0.01,
               "righting moment per radian, kN m (the page's 5.68)");
    CHECK_NEAR(RHO * g * J, 0.67, 0.01,
               "of which the mast's waterplane, N m/rad (the page's 0.67)");

    /* 4. Straight at 5 m/s: each component's drag, from the page's
     * table (rounded to 1 N). */
    double U = 5.0, wO[3] = {U, 0, 0}, om[3] = {0, 0, 0}, F[3], Mo[3];
    ts_component_load each[TS_VEHICLE_MAX_COMPONENTS];
    tsi_vehicle_hydro(v, w, RHO, 1.0, wO, om, delta, F, Mo, each);
    static const struct { const char *name; double drag; } table[] = {
        {"hull", 1630}, {"mast_drag", 389}, {"keel", 123}, {"bulb", 181},
        {"mast_wave", 375}};
    double planes = 0;
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        int listed = 0;
        for (size_t k = 0; k < sizeof table / sizeof table[0]; k++)
            if (!strcmp(cp->name, table[k].name)) {
                CHECK_NEAR(-each[c].force[0], table[k].drag, 0.5,
                           cp->name);
                listed = 1;
            }
        if (!listed)
            planes += -each[c].force[0];
    }
    CHECK_NEAR(planes, 308, 0.5, "the six planes' drag (N)");
    CHECK_NEAR(-F[0], 3006, 1.0, "total drag at 5 m/s (N), the table's");
    CHECK(fabs(F[1]) < 1e-9 && fabs(F[2]) < 1e-9,
          "no side or vertical force in straight running: %.3g, %.3g N",
          F[1], F[2]);

    /* 5. Static stability: the moment about the mass centre (the
     * generalised force is about A: move it) at a small angle of attack
     * alpha (flow from below, w_z > 0) must be nose down (M_y < 0), at a
     * small sideslip (w_y > 0) nose to starboard (M_z > 0), Munk moment
     * included (tsi_vehicle_loads with the flow: the kernel's wO_b). */
    /* 5. The derivatives by central differences over +-2 deg (the
     * moments are smooth there: below every surface's stall). At zero
     * angle the drag of the parts above and below G already gives a
     * nose-up moment (mast and wave drag high, keel and bulb low), which
     * the tailplanes trim; stability is the slope. */
    double a = 2.0 * M_PI / 180, m0 = 0;
    th[0] = 0;
    for (int axis = 0; axis < 3; axis++) {
        double slope = 0;
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            double ang = axis == 2 ? 0.0 : sgn * a;
            state_at(v, C, th, thd, rA, rdA, &st);
            st.wO_b[0] = U * cos(ang);
            st.wO_b[1] = axis == 1 ? U * sin(ang) : 0;
            st.wO_b[2] = axis == 0 ? U * sin(ang) : 0;
            double Ga[6], Ma[3];
            tsi_vehicle_loads(v, w, B->mass, RHO, g, &st, delta, Ga, NULL);
            about_g(v, Ga, Ma);
            slope += sgn * Ma[axis == 0 ? 1 : 2] / (2 * a);
            if (axis == 2)
                m0 = Ma[1];
        }
        if (axis == 0)
            CHECK(slope < 0, "pitch: dM/dalpha about G at 5 m/s %.0f N m/rad "
                  "< 0 (the tailplanes beat the Munk moment and the "
                  "foreplanes)", slope);
        else if (axis == 1)
            CHECK(slope > 0, "yaw: dN/dbeta about G at 5 m/s %.0f N m/rad "
                  "> 0 (the vertical tailplanes beat the Munk moment)",
                  slope);
    }
    /* Against the sum of each component's drag (section 4) times its
     * height above G: every force is along -x at zero angle. */
    double sum = 0;
    for (int c = 0; c < v->ncomponents; c++)
        sum += -each[c].force[0] *
               (v->mass_centre[2] - v->component[c].position[2]);
    /* Less the moment at rest (buoyancy's, 1 N m: the page's centres
     * are rounded to 0.1 mm). */
    {
        double G0[6], M0[3];
        state_at(v, C, th, thd, rA, rdA, &st);
        tsi_vehicle_loads(v, w, B->mass, RHO, g, &st, delta, G0, NULL);
        about_g(v, G0, M0);
        m0 -= M0[1];
    }
    CHECK_NEAR(m0, sum, 1e-9 * fabs(sum), "straight at 5 m/s: the pitch "
               "moment about G is the sum of drag times height above G (N m)");
    CHECK_NEAR(m0 / 1000, 1.62, 0.005, "and the page's 1.62 kN m nose up");
    tsi_vehicle_ws_free(w);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = tscene_load(u, "test/scenes/dolphin.yaml");
    if (sc)
        test_dolphin(sc);
    ts_scene_free(sc);
    ts_units_free(u);
    return tc_done();
}
