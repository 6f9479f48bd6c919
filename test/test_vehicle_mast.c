/* test_vehicle_mast.c: a surface-piercing mast's buoyancy (doc/vehicle.md
 * section 4, doc/model.md section 8) against independent references.
 *
 *  1. A vertical circular cylinder: the buoyancy change is rho g A dz
 *     exactly while the waterline is on the mast; the force is rho g A h
 *     fully under water and zero above it.
 *  2. Tilted at finite angles, with the waterline cutting the side, the
 *     top or the foot: the force and the moment about the body origin
 *     against a brute-force quadrature of the submerged volume, each
 *     generator's submerged length found from the rotated body points'
 *     depths (not from the closed-form moments).
 *  3. Small heel about the foot: the restoring moment approaches the
 *     metacentric rho g (A s^2 / 2 + J) phi (KB = s/2, BM = J / V), the
 *     error falling like phi^2.
 *  4. A floating spar (hull deep, a mast through the surface): under an
 *     added weight dm g it sinks by dm / (rho A), the static sinkage of
 *     the waterplane, found by root-finding on tsi_vehicle_loads.
 *  5. Its drag on the submerged part's frontal area, at that part's
 *     centroid, against a hand computation upright at two depths and
 *     pitched and heeled.
 * Tolerances are stated at each check with their reason. */
#include "vehicle.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <string.h>

#include "tcheck.h"

#define RHO 1025.0
#define G 9.80665

static ts_component mast(double d_chord, double d_thick, double h,
                         const double foot[3])
{
    ts_component c;
    ts_component_defaults(&c, TS_COMP_MAST);
    snprintf(c.name, sizeof c.name, "mast");
    c.chord = d_chord;
    c.thickness = d_thick;
    c.area = M_PI * d_chord * d_thick / 4;
    c.length = h;
    memcpy(c.position, foot, sizeof c.position);
    return c;
}

/* The body components of M's e_z for the 1-2-3 angles th. */
static void ez_body(const double th[3], double ez_b[3])
{
    double R[9];
    tsi_rot123(th, R);
    for (int j = 0; j < 3; j++)
        ez_b[j] = R[6 + j];
}

/* Brute force: the submerged volume's force and moment about O by
 * Gauss-Legendre in the section's radius and the trapezoid rule in its
 * angle (spectral for a periodic integrand), each generator's submerged
 * length from the depths of its points in M, with O at depth zO. */
static void brute(const ts_component *c, const double th[3], double zO,
                  double F[3], double Mo[3])
{
    double R[9];
    tsi_rot123(th, R);
    gsl_integration_glfixed_table *t = gsl_integration_glfixed_table_alloc(
        200);
    const int nang = 400;
    double vol = 0, S[3] = {0, 0, 0};
    for (int i = 0; i < 200; i++) {
        double r, wr;
        gsl_integration_glfixed_point(0, 1, (size_t)i, &r, &wr, t);
        for (int k = 0; k < nang; k++) {
            double ph = 2 * M_PI * k / nang;
            double xi = 0.5 * c->chord * r * cos(ph),
                   eta = 0.5 * c->thickness * r * sin(ph);
            /* dA = (chord/2)(thickness/2) r dr dph */
            double dA = 0.25 * c->chord * c->thickness * r * wr *
                        (2 * M_PI / nang);
            /* Depth of the generator's point at s: linear in s. */
            double p0[3] = {c->position[0] + xi, c->position[1] + eta,
                            c->position[2]};
            double z0 = zO, dz = 0;
            for (int j = 0; j < 3; j++)
                z0 += R[6 + j] * p0[j];
            dz = -R[8]; /* d depth / ds along (0, 0, -1) */
            /* Submerged part of s in [0, h]: z0 + s dz > 0. */
            double lo = 0, hi = c->length;
            if (dz > 0)
                lo = fmax(lo, -z0 / dz);
            else if (dz < 0)
                hi = fmin(hi, -z0 / dz);
            else if (z0 <= 0)
                hi = lo;
            if (hi <= lo)
                continue;
            double len = hi - lo, mid = 0.5 * (lo + hi);
            vol += len * dA;
            S[0] += len * dA * p0[0];
            S[1] += len * dA * p0[1];
            S[2] += len * dA * (p0[2] - mid);
        }
    }
    gsl_integration_glfixed_table_free(t);
    double ez[3] = {R[6], R[7], R[8]};
    for (int j = 0; j < 3; j++)
        F[j] = -RHO * G * vol * ez[j];
    Mo[0] = -RHO * G * (S[1] * ez[2] - S[2] * ez[1]);
    Mo[1] = -RHO * G * (S[2] * ez[0] - S[0] * ez[2]);
    Mo[2] = -RHO * G * (S[0] * ez[1] - S[1] * ez[0]);
}

static void test_vertical_cylinder(void)
{
    double foot[3] = {0.3, -0.1, -0.45}, d = 0.2, h = 3.0;
    ts_component c = mast(d, d, h, foot);
    double A = c.area, ez[3] = {0, 0, 1}, F0[3], M0[3], F[3], M[3], s;
    double z0 = 2.0; /* foot at 1.55 m: 1.55 m submerged */
    tsi_mast_buoyancy(&c, RHO, G, z0, ez, F0, M0, &s, NULL);
    CHECK_REL(s, z0 + foot[2], 1e-15, "upright: submerged length = the "
              "foot's depth (m)");
    CHECK_REL(F0[2], -RHO * G * A * (z0 + foot[2]), 1e-14,
              "upright: buoyancy rho g A s (N)");
    /* The centre of buoyancy is on the axis at half the draft: moment
     * about O = r_B x F, with r_B = foot + (0, 0, -s/2). */
    CHECK(fabs(M0[0] - foot[1] * F0[2]) < 1e-12 * fabs(F0[2]) &&
              fabs(M0[1] + foot[0] * F0[2]) < 1e-12 * fabs(F0[2]) &&
              M0[2] == 0,
          "upright: moment (%.6g, %.6g, %.6g) N m = foot x F", M0[0], M0[1],
          M0[2]);
    static const double dzs[] = {1e-3, 0.1, -0.5, 1.2};
    double worst = 0;
    for (size_t i = 0; i < sizeof dzs / sizeof dzs[0]; i++) {
        tsi_mast_buoyancy(&c, RHO, G, z0 + dzs[i], ez, F, M, NULL, NULL);
        double want = -RHO * G * A * dzs[i];
        worst = fmax(worst, fabs(F[2] - F0[2] - want) / fabs(F0[2]));
    }
    /* Rounding of a few operations on F0 ~ 500 N. */
    CHECK(worst < 1e-14, "upright: buoyancy change = -rho g A dz exactly "
          "for dz = 1 mm .. 1.2 m (worst %.2g of the buoyancy)", worst);
    tsi_mast_buoyancy(&c, RHO, G, 10.0, ez, F, M, &s, NULL);
    CHECK(s == h && fabs(F[2] + RHO * G * A * h) <= 1e-14 * RHO * G * A * h,
          "deep: the whole mast, %.6g m, %.8g N", s, F[2]);
    tsi_mast_buoyancy(&c, RHO, G, 0.4, ez, F, M, &s, NULL);
    CHECK(s == 0 && F[2] == 0, "above the water (foot 5 cm up): none");
}

static void test_tilted(void)
{
    double foot[3] = {0.3, 0.05, -0.45};
    ts_component c = mast(0.45, 0.15, 2.9, foot);
    static const struct {
        double th[3], zO;
        const char *what;
    } cases[] = {
        {{0.15, 0.0, 0.0}, 2.475, "heeled 8.6 deg, waterline on the side"},
        {{0.0, -0.2, 0.3}, 2.475, "pitched 11 deg, yawed"},
        {{0.1, 0.12, 0.0}, 0.5, "heeled and pitched, waterline near the foot"},
        {{0.25, 0.3, 0.0}, 0.47, "waterline cutting the foot"},
        {{0.25, -0.3, 0.0}, 3.3, "waterline cutting the top"},
        {{0.1, 0.1, 0.0}, 3.5, "all under water"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double ez[3], F[3], M[3], Fb[3], Mb[3];
        ez_body(cases[i].th, ez);
        tsi_mast_buoyancy(&c, RHO, G, cases[i].zO, ez, F, M, NULL, NULL);
        brute(&c, cases[i].th, cases[i].zO, Fb, Mb);
        double fs = RHO * G * c.area * c.length, e = 0;
        for (int j = 0; j < 3; j++)
            e = fmax(e, fmax(fabs(F[j] - Fb[j]) / fs,
                             fabs(M[j] - Mb[j]) / (fs * c.length)));
        /* The quadrature (200 x 400 points) of a generator length with
         * kinks (the clamps at the foot and the top) converges slowly:
         * 1e-8 of the full buoyancy (and of it times the length for
         * moments; observed 2e-9 where the waterline cuts the foot,
         * 1e-10 elsewhere). */
        CHECK(e < 1e-8, "%s: force and moment against the quadrature, "
              "worst %.2g of rho g A h (force %.6g N)", cases[i].what, e,
              -F[2]);
    }
}

static void test_metacentre(void)
{
    double foot[3] = {0, 0, 0};
    ts_component c = mast(0.45, 0.15, 4.0, foot);
    double zO = 2.0, A = c.area;
    double Jx = A * c.chord * c.chord / 16, Jy = A * c.thickness *
                                                  c.thickness / 16;
    double err_prev[2] = {0, 0}, ratio[2] = {0, 0};
    for (int k = 0; k < 3; k++) {
        double phi = 0.04 / (1 << k);
        for (int axis = 0; axis < 2; axis++) {
            double th[3] = {0, 0, 0}, ez[3], F[3], M[3];
            th[axis] = phi;
            ez_body(th, ez);
            tsi_mast_buoyancy(&c, RHO, G, zO, ez, F, M, NULL, NULL);
            /* Heel about x (roll): the waterplane's moment about x is
             * the thickness's, J_y; pitch about y: the chord's, J_x. */
            double J = axis == 0 ? Jy : Jx;
            double want = -RHO * G * (A * zO * zO / 2 + J) * phi;
            double e = fabs(M[axis] - want) / fabs(want);
            if (k > 0)
                ratio[axis] = err_prev[axis] / e;
            err_prev[axis] = e;
            if (k == 2)
                CHECK(e < 1e-3 && M[axis] * phi < 0,
                      "%s %.4f rad about the foot: restoring moment %.8g "
                      "N m, metacentric rho g (A s^2/2 + J) phi %.8g "
                      "(rel %.2g)", axis ? "pitched" : "heeled", phi,
                      M[axis], want, e);
        }
    }
    /* Second order: halving phi divides the error by 4. */
    CHECK(ratio[0] > 3.9 && ratio[0] < 4.1 && ratio[1] > 3.9 &&
              ratio[1] < 4.1,
          "the difference from the metacentric moment falls like phi^2: "
          "ratios %.3f (roll), %.3f (pitch)", ratio[0], ratio[1]);
}

/* A floating spar: its net vertical force at depth zO, upright. */
typedef struct {
    const ts_vehicle *v;
    double mass;
    tsi_vehicle_ws *ws;
} spar;

static double net_heave(double zO, void *par)
{
    const spar *s = par;
    tsi_vehicle_state st;
    memset(&st, 0, sizeof st);
    double C[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, th[3] = {0, 0, 0},
           z3[3] = {0, 0, 0};
    double rA[3] = {0, 0, zO + s->v->attach[2]};
    tsi_vehicle_kinematics(s->v, C, th, z3, 0.0, rA, z3, &st);
    st.frac = 1.0;
    double Gf[6], delta[TS_VEHICLE_MAX_COMPONENTS] = {0};
    tsi_vehicle_loads(s->v, s->ws, s->mass, RHO, G, &st, delta, Gf, NULL);
    return Gf[2];
}

static double float_depth(spar *s)
{
    gsl_root_fsolver *r = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    gsl_function f = {net_heave, s};
    gsl_root_fsolver_set(r, &f, 0.5, 5.0);
    double z = NAN;
    for (int it = 0; it < 200; it++) {
        gsl_root_fsolver_iterate(r);
        z = gsl_root_fsolver_root(r);
        double lo = gsl_root_fsolver_x_lower(r),
               hi = gsl_root_fsolver_x_upper(r);
        if (gsl_root_test_interval(lo, hi, 1e-14, 0) == GSL_SUCCESS)
            break;
    }
    gsl_root_fsolver_free(r);
    return z;
}

static void test_sinkage(void)
{
    static ts_vehicle v;
    memset(&v, 0, sizeof v);
    v.volume = 3.0;
    v.inertia[0] = v.inertia[1] = v.inertia[2] = 1000;
    v.mass_centre[2] = 0.2;
    double foot[3] = {0, 0, -0.45};
    v.ncomponents = 1;
    v.component[0] = mast(0.45, 0.15, 3.0, foot);
    ts_err err = {0};
    tsi_vehicle_ws *ws = tsi_vehicle_ws_alloc(&v, &err);
    if (!CHECK(ws != NULL, "workspace (%s)", err.msg))
        return;
    double A = v.component[0].area;
    /* Floating with 2 m of mast submerged: m = rho (V + 2 A). */
    double m = RHO * (v.volume + 2.0 * A);
    spar s = {&v, m, ws};
    double z0 = float_depth(&s);
    CHECK_NEAR(z0, 2.45, 1e-12, "floats with 2 m of the mast under water "
               "(depth of O, m; the root's tolerance)");
    static const double dm[] = {5.0, 20.0, -30.0};
    for (size_t i = 0; i < 3; i++) {
        s.mass = m + dm[i];
        double z = float_depth(&s);
        CHECK_NEAR(z - z0, dm[i] / (RHO * A), 1e-11,
                   dm[i] > 0 ? "an added weight sinks it by dm / (rho A) (m)"
                             : "a lighter one rises by dm / (rho A) (m)");
    }
    tsi_vehicle_ws_free(ws);
}

/* 5. The mast's drag (tsi_mast_drag through tsi_vehicle_statics) against
 * a hand computation. With the waterline across the mast's sides, the
 * submerged length of the generator at section offset q is f(q) = s_c +
 * k.q (s_c = z_foot / cz, k = (ez_x, ez_y) / cz), so over the elliptic
 * section (semi-axes a0 = chord/2, a1 = thickness/2, second moments a0^2
 * / 4 and a1^2 / 4 of the area) its mean is s_c and the submerged
 * part's centroid is the foot plus (a0^2 k_x / (4 s_c), a1^2 k_y / (4
 * s_c), -(s_c^2 + (k_x^2 a0^2 + k_y^2 a1^2) / 4) / (2 s_c)): upright,
 * the middle of the submerged length. The drag there is -1/2 rho Cd
 * thickness s_c |w_perp| w_perp, w the centroid's velocity through the
 * water (wO + om x centroid) and w_perp its part across the mast (body x,
 * y). Upright at two depths (0.55 and 1.55 m of the mast under water)
 * and pitched 0.1 rad and heeled 0.05 rad at the second: the statics
 * less the drag-free mast's (its buoyancy, the same to the last bit) are
 * the hand's force and moment about O to 1e-12 relative (rounding). */
static void test_drag(void)
{
    static ts_vehicle v, v0;
    memset(&v, 0, sizeof v);
    v.volume = 3.0;
    v.inertia[0] = v.inertia[1] = v.inertia[2] = 1000;
    double foot[3] = {0.3, -0.1, -0.45};
    v.ncomponents = 1;
    v.component[0] = mast(0.45, 0.15, 3.0, foot);
    v0 = v;
    CHECK(v0.component[0].drag == 0.0, "a mast's drag is 0 by default");
    ts_component *c = &v.component[0];
    c->drag = 1.17;
    static const struct {
        double zO, th[3];
    } cases[] = {{1.0, {0, 0, 0}}, {2.0, {0, 0, 0}}, {2.0, {0.05, 0.1, 0}}};
    const double wO[3] = {2.3, 0.4, 0.35}, om[3] = {0.03, -0.08, 0.05};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        tsi_vehicle_state st;
        memset(&st, 0, sizeof st);
        double C[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, z3[3] = {0, 0, 0};
        double rA[3] = {0, 0, cases[i].zO};
        tsi_vehicle_kinematics(&v, C, cases[i].th, z3, 0.0, rA, z3, &st);
        memcpy(st.wO_b, wO, sizeof st.wO_b);
        memcpy(st.om_b, om, sizeof st.om_b);
        st.frac = 1.0;
        double F[3], M[3], F0[3], M0[3];
        tsi_vehicle_statics(&v, RHO, G, &st, NULL, F, M, NULL);
        tsi_vehicle_statics(&v0, RHO, G, &st, NULL, F0, M0, NULL);
        /* The hand's geometry. */
        double ez[3];
        ez_body(cases[i].th, ez);
        double zp = cases[i].zO + ez[0] * foot[0] + ez[1] * foot[1] +
                    ez[2] * foot[2];
        double sc = zp / ez[2], kx = ez[0] / ez[2], ky = ez[1] / ez[2];
        double a0 = 0.5 * c->chord, a1 = 0.5 * c->thickness;
        double m2 = kx * kx * a0 * a0 + ky * ky * a1 * a1;
        double cen[3] = {foot[0] + a0 * a0 * kx / (4 * sc),
                         foot[1] + a1 * a1 * ky / (4 * sc),
                         foot[2] - (sc * sc + m2 / 4) / (2 * sc)};
        double w[3] = {wO[0] + om[1] * cen[2] - om[2] * cen[1],
                       wO[1] + om[2] * cen[0] - om[0] * cen[2], 0};
        double k = -0.5 * RHO * c->drag * c->thickness * sc *
                   hypot(w[0], w[1]);
        double Fh[3] = {k * w[0], k * w[1], 0};
        double Mh[3] = {cen[1] * Fh[2] - cen[2] * Fh[1],
                        cen[2] * Fh[0] - cen[0] * Fh[2],
                        cen[0] * Fh[1] - cen[1] * Fh[0]};
        double ef = 0, em = 0, nf = hypot(Fh[0], Fh[1]), nm = 0;
        for (int j = 0; j < 3; j++) {
            ef = fmax(ef, fabs(F[j] - F0[j] - Fh[j]));
            em = fmax(em, fabs(M[j] - M0[j] - Mh[j]));
            nm = fmax(nm, fabs(Mh[j]));
        }
        CHECK(sc - sqrt(m2) > 0 && sc + sqrt(m2) < c->length &&
                  ef <= 1e-12 * nf && em <= 1e-12 * nm,
              "mast drag, O at %.2f m, pitch %.2f, roll %.2f rad: %.4f m "
              "submerged, centroid (%.4f, %.4f, %.4f) m; force %.6f, %.6f "
              "N, moment %.6f, %.6f, %.6f N m by hand; statics less the "
              "buoyancy off by %.2g N, %.2g N m",
              cases[i].zO, cases[i].th[1], cases[i].th[0], sc, cen[0],
              cen[1], cen[2], Fh[0], Fh[1], Mh[0], Mh[1], Mh[2], ef, em);
    }
}

int main(void)
{
    gsl_set_error_handler_off();
    test_vertical_cylinder();
    test_tilted();
    test_metacentre();
    test_sinkage();
    test_drag();
    return tc_done();
}
