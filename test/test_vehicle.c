/* test_vehicle.c: the vehicle's physics (lib/vehicle.c) against references
 * written out here.
 *
 *  1. Added mass of a spheroid: Lamb's coefficients k1, k2, k' against
 *     their defining integrals (Newman 1977, 4.13) computed by GSL
 *     quadrature; the sphere (0.5, 0.5, 0) and slender (0, 1, 1) limits;
 *     the series and closed forms meet at e = 0.1.
 *  2. Moving an added-mass matrix to another point keeps the kinetic
 *     energy 1/2 nu^T A nu of every motion.
 *  3. Lift and drag curves: Helmbold's limits; exactly linear below the
 *     stall blend and a flat plate above it; continuous with continuous
 *     slope through the blend; tables reproduce their rows and hold the
 *     end values.
 *  4. Surface and hull loads: lift normal and drag parallel to the flow
 *     with the curve's coefficients at the effective angle (incidence and
 *     deflection added); an X tail's symmetry; a hull's cross-flow drag
 *     against its integral written out; the Munk moment of a spheroid,
 *     (a33 - a11) U^2 sin a cos a.
 *  5. Kinematics: the 1-2-3 rotation against R1 R2 R3; E and kappa against
 *     central differences of R and of E theta'; the inverse of E; yaw,
 *     pitch, roll and their rates against the rotation and differences.
 *  6. The spatial inertia's kinetic energy against 1/2 m |v_G|^2 +
 *     1/2 om.I_G om.
 *  7. Controllers: the PID law, its integrator, deflection and rate
 *     limits, frozen and broken loops, heading wrap.
 *  8. Bad descriptions refused, naming the key.
 * Tolerances are stated at each check with their reason. */
#include "vehicle.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "vec3.h"

/* ---- 1. spheroid ----------------------------------------------------- */

typedef struct { double a, b, p; } quad_par;

/* alpha0: a b^2 / ((a^2 + l)^3/2 (b^2 + l)); beta0: a b^2 / ((a^2 + l)^1/2
 * (b^2 + l)^2), integrated over l in [0, inf) (Lamb 1932, art. 114). */
static double f_alpha(double l, void *p)
{
    quad_par *q = p;
    return q->a * q->b * q->b /
           (pow(q->a * q->a + l, 1.5) * (q->b * q->b + l));
}

static double f_beta(double l, void *p)
{
    quad_par *q = p;
    return q->a * q->b * q->b /
           (sqrt(q->a * q->a + l) * (q->b * q->b + l) * (q->b * q->b + l));
}

static double integrate(double (*f)(double, void *), quad_par *q)
{
    gsl_integration_workspace *w = gsl_integration_workspace_alloc(1000);
    gsl_function F = {f, q};
    double r = NAN, e;
    gsl_integration_qagiu(&F, 0.0, 0.0, 1e-13, 1000, w, &r, &e);
    gsl_integration_workspace_free(w);
    return r;
}

static void test_spheroid(void)
{
    ts_err err = {0};
    double A[36], k[3];
    CHECK(ts_added_mass_spheroid(1025, 1.0, 1.0, A, k, &err) == TS_OK,
          "sphere accepted");
    CHECK_NEAR(k[0], 0.5, 1e-14, "sphere k1");
    CHECK_NEAR(k[1], 0.5, 1e-14, "sphere k2");
    CHECK_NEAR(k[2], 0.0, 1e-14, "sphere k'");
    CHECK_REL(A[0], 0.5 * 1025 * M_PI / 6, 1e-14,
              "sphere A11 = rho V / 2");
    static const double ratio[] = {1.0001, 1.004, 1.0482, 1.0484, 1.2, 2.0,
                                   5.0, 10.0, 100.0};
    for (size_t i = 0; i < sizeof ratio / sizeof *ratio; i++) {
        double L = 2.0 * ratio[i], D = 2.0;
        ts_added_mass_spheroid(998.2, L, D, A, k, &err);
        quad_par q = {0.5 * L, 0.5 * D, 0};
        double a0 = integrate(f_alpha, &q), b0 = integrate(f_beta, &q);
        double e2 = 1 - (D / L) * (D / L);
        double k1 = a0 / (2 - a0), k2 = b0 / (2 - b0);
        /* k' from the integrals: e^4 (b0 - a0) / ((2 - e^2) (2 e^2 -
         * (2 - e^2)(b0 - a0))). */
        double kp = e2 * e2 * (b0 - a0) /
                    ((2 - e2) * (2 * e2 - (2 - e2) * (b0 - a0)));
        char nm[64];
        snprintf(nm, sizeof nm, "L/D %g: k1 vs quadrature", ratio[i]);
        CHECK_NEAR(k[0], k1, 1e-10, nm);
        snprintf(nm, sizeof nm, "L/D %g: k2 vs quadrature", ratio[i]);
        CHECK_NEAR(k[1], k2, 1e-10, nm);
        snprintf(nm, sizeof nm, "L/D %g: k' vs quadrature", ratio[i]);
        CHECK_NEAR(k[2], kp, 1e-10, nm);
        double mf = 998.2 * M_PI * L * D * D / 6;
        snprintf(nm, sizeof nm, "L/D %g: A33 = k2 m_f, A66 = k' I_f",
                 ratio[i]);
        CHECK(fabs(A[14] - k[1] * mf) <= 1e-12 * mf &&
                  fabs(A[35] - k[2] * mf * (L * L + D * D) / 20) <=
                      1e-12 * mf * L * L,
              "%s", nm);
    }
    /* Slender limit: k1 -> 0, k2 -> 1, k' -> 1 (strip theory). */
    ts_added_mass_spheroid(1000, 1e4, 1.0, A, k, &err);
    CHECK(k[0] < 1e-6 && fabs(k[1] - 1) < 1e-6 && fabs(k[2] - 1) < 1e-6,
          "slender limit L/D 1e4: k1 %.3g, k2 %.9f, k' %.9f", k[0], k[1],
          k[2]);
    /* The two branches meet at e = 0.3 (L/D = 1/sqrt(0.91)); the closed
     * form's rounding there is ~eps / e^2 ~ 3e-15. */
    double kl[3], kh[3], Ld = 1.0 / sqrt(0.91);
    /* Lengths a few ulps apart, on either side of the switch: the
     * coefficients' own change is ~1e-16. */
    double Ll = Ld * (1 - 4e-16), Lh = Ld * (1 + 4e-16);
    ts_added_mass_spheroid(1000, Ll, 1.0, A, kl, &err);
    ts_added_mass_spheroid(1000, Lh, 1.0, A, kh, &err);
    CHECK(sqrt(1 - 1 / (Ll * Ll)) < 0.3 && sqrt(1 - 1 / (Lh * Lh)) >= 0.3,
          "the two lengths straddle e = 0.3");
    CHECK(fabs(kl[0] - kh[0]) < 1e-13 && fabs(kl[1] - kh[1]) < 1e-13 &&
              fabs(kl[2] - kh[2]) < 1e-13,
          "series and closed form agree at e = 0.3: %.3g %.3g %.3g",
          kl[0] - kh[0], kl[1] - kh[1], kl[2] - kh[2]);
    CHECK(ts_added_mass_spheroid(1000, 0.5, 1.0, A, k, &err) == TS_EINVAL &&
              strstr(err.msg, "length >= diameter"),
          "oblate refused: %s", err.msg);
}

/* ---- 2. added mass shift --------------------------------------------- */

static double quad6(const double A[36], const double x[6])
{
    double s = 0;
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            s += x[i] * A[6 * i + j] * x[j];
    return s;
}

static void test_shift(void)
{
    double A[36], B[36];
    /* A symmetric positive matrix with couplings. */
    for (int i = 0; i < 6; i++)
        for (int j = 0; j <= i; j++) {
            double v = i == j ? 3.0 + i : 0.37 * sin(1.7 * i + 2.3 * j);
            A[6 * i + j] = A[6 * j + i] = v;
        }
    double r[3] = {0.83, -0.41, 0.29};
    ts_added_mass_shift(A, r, B);
    double worst = 0;
    for (int trial = 0; trial < 5; trial++) {
        double nuO[6], nuP[6];
        for (int i = 0; i < 6; i++)
            nuO[i] = cos(1.3 * trial + 0.7 * i);
        /* v_P = v_O + om x r */
        double om[3] = {nuO[3], nuO[4], nuO[5]}, x[3];
        x[0] = om[1] * r[2] - om[2] * r[1];
        x[1] = om[2] * r[0] - om[0] * r[2];
        x[2] = om[0] * r[1] - om[1] * r[0];
        for (int i = 0; i < 3; i++) {
            nuP[i] = nuO[i] + x[i];
            nuP[3 + i] = om[i];
        }
        worst = fmax(worst, fabs(quad6(B, nuO) - quad6(A, nuP)));
    }
    CHECK(worst < 1e-12, "shifted added mass keeps the kinetic energy: %.3g",
          worst);
    double sym = 0;
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            sym = fmax(sym, fabs(B[6 * i + j] - B[6 * j + i]));
    CHECK(sym < 1e-14, "shifted added mass symmetric: %.3g", sym);
}

/* ---- 3. curves -------------------------------------------------------- */

static ts_vehicle *one_surface(double area, double span)
{
    ts_vehicle *v = calloc(1, sizeof *v);
    v->ncomponents = 1;
    ts_component_defaults(&v->component[0], TS_COMP_SURFACE);
    snprintf(v->component[0].name, sizeof v->component[0].name, "wing");
    v->component[0].area = area;
    v->component[0].span = span;
    return v;
}

static void test_curves(void)
{
    CHECK_REL(ts_lift_slope_helmbold(1e8), 2 * M_PI, 1e-7,
              "Helmbold, large aspect ratio -> 2 pi");
    CHECK_REL(ts_lift_slope_helmbold(1e-6) / 1e-6, M_PI / 2, 1e-6,
              "Helmbold, small aspect ratio -> pi ar / 2");
    CHECK_REL(ts_lift_slope_helmbold(4.0), 2 * M_PI * 4 / (2 + sqrt(20.0)),
              1e-15, "Helmbold at ar 4");

    ts_err err = {0};
    ts_vehicle *v = one_surface(0.3, 0.9); /* ar 2.7 */
    ts_component *c = &v->component[0];
    tsi_vehicle_ws *w = tsi_vehicle_ws_alloc(v, &err);
    double ar = 0.81 / 0.3, a = ts_lift_slope_helmbold(ar);
    double cl, cd;
    double lin_end = c->stall - c->stall_width;
    for (double al = -lin_end; al <= lin_end; al += lin_end / 7) {
        tsi_surface_coefficients(v, w, 0, al, &cl, &cd);
        double cdw = c->cd0 + a * a * al * al / (M_PI * c->efficiency * ar);
        if (!(fabs(cl - a * al) < 1e-15 && fabs(cd - cdw) < 1e-15)) {
            CHECK(0, "linear range at %g deg: cl %g cd %g", al * 180 / M_PI,
                  cl, cd);
            break;
        }
    }
    CHECK(1, "exactly linear lift and parabolic drag below the blend");
    double fp_start = c->stall + c->stall_width, worst = 0;
    for (double al = fp_start; al < 3.1; al += 0.1) {
        tsi_surface_coefficients(v, w, 0, -al, &cl, &cd);
        worst = fmax(worst, fabs(cl + c->cn90 * sin(al) * cos(al)));
        worst = fmax(worst, fabs(cd - c->cd0 - c->cn90 * sin(al) * sin(al)));
    }
    CHECK(worst < 1e-15, "flat plate past the blend: %.3g", worst);
    /* Continuity and continuous slope through the blend: a central
     * difference of step h across the blend changes by O(h) only. */
    double h = 1e-6, jump = 0, sjump = 0, prev_s = NAN;
    for (double al = lin_end - 0.01; al < fp_start + 0.01; al += h * 97) {
        double c1, d1, c2, d2;
        tsi_surface_coefficients(v, w, 0, al - h, &c1, &d1);
        tsi_surface_coefficients(v, w, 0, al + h, &c2, &d2);
        jump = fmax(jump, fabs(c2 - c1));
        double s = (c2 - c1) / (2 * h);
        if (isfinite(prev_s))
            sjump = fmax(sjump, fabs(s - prev_s));
        prev_s = s;
    }
    CHECK(jump < 2 * h * 10 && sjump < 0.05,
          "curve continuous (largest step over 2h %.3g) with a continuous "
          "slope (largest change between samples %.3g 1/rad)",
          jump, sjump);
    /* Wrapping: alpha and alpha + 2 pi agree. */
    double cl2, cd2;
    tsi_surface_coefficients(v, w, 0, 0.1, &cl, &cd);
    tsi_surface_coefficients(v, w, 0, 0.1 + 2 * M_PI, &cl2, &cd2);
    CHECK(fabs(cl - cl2) < 1e-12 && fabs(cd - cd2) < 1e-12,
          "angles wrap into (-pi, pi]");
    tsi_vehicle_ws_free(w);

    /* A table: rows reproduced, ends held. */
    c->curve = TS_CURVE_TABLE;
    c->npoints = 5;
    double ta[5] = {-0.5, -0.2, 0.0, 0.25, 0.6};
    double tl[5] = {-0.7, -0.55, 0.0, 0.6, 0.8};
    double td[5] = {0.4, 0.05, 0.012, 0.07, 0.5};
    memcpy(c->alpha, ta, sizeof ta);
    memcpy(c->cl, tl, sizeof tl);
    memcpy(c->cd, td, sizeof td);
    w = tsi_vehicle_ws_alloc(v, &err);
    CHECK(w != NULL, "table interpolator built");
    worst = 0;
    for (int i = 0; i < 5; i++) {
        tsi_surface_coefficients(v, w, 0, ta[i], &cl, &cd);
        worst = fmax(worst, fabs(cl - tl[i]) + fabs(cd - td[i]));
    }
    CHECK(worst < 1e-14, "table rows reproduced: %.3g", worst);
    tsi_surface_coefficients(v, w, 0, 1.2, &cl, &cd);
    tsi_surface_coefficients(v, w, 0, -3.0, &cl2, &cd2);
    CHECK(cl == 0.8 && cd == 0.5 && cl2 == -0.7 && cd2 == 0.4,
          "outside the table the end rows hold");
    /* Steffen's interpolant stays within the neighbouring rows. */
    int mono = 1;
    for (double al = -0.2; al <= 0.0; al += 0.01) {
        tsi_surface_coefficients(v, w, 0, al, &cl, &cd);
        mono = mono && cl >= -0.55 - 1e-15 && cl <= 1e-15;
    }
    CHECK(mono, "table interpolation monotone between rows");
    tsi_vehicle_ws_free(w);
    free(v);
}

/* ---- 4. loads --------------------------------------------------------- */

static void test_loads(void)
{
    ts_err err = {0};
    ts_vehicle *v = one_surface(0.25, 0.6);
    ts_component *c = &v->component[0];
    c->position[0] = 0.4;
    c->position[2] = 0.1;
    c->control = 1;
    c->incidence = 0.03;
    tsi_vehicle_ws *w = tsi_vehicle_ws_alloc(v, &err);
    double rho = 1025, om[3] = {0, 0, 0};
    double F[3], Mo[3];
    ts_component_load ld;
    int ok = 1;
    for (int t = 0; t < 12; t++) {
        double al = -0.6 + 0.1 * t, U = 2.3, delta[1] = {0.05 - 0.01 * t};
        double wO[3] = {U * cos(al), 0.4, U * sin(al)};
        tsi_vehicle_hydro(v, w, rho, 1.0, wO, om, delta, F, Mo, &ld);
        /* Flow in the chord-normal plane (normal +z at roll 0). */
        double sp = hypot(wO[0], wO[2]);
        double lift_dir[3] = {wO[2] / sp, 0, -wO[0] / sp};
        double drag_dir[3] = {-wO[0] / sp, 0, -wO[2] / sp};
        double cl, cd;
        tsi_surface_coefficients(v, w, 0, al + c->incidence + delta[0], &cl,
                                 &cd);
        double q = 0.5 * rho * sp * sp * c->area;
        double L = F[0] * lift_dir[0] + F[2] * lift_dir[2];
        double D = F[0] * drag_dir[0] + F[2] * drag_dir[2];
        double r[3] = {0.4, 0, 0.1};
        double m_want = r[2] * F[0] - r[0] * F[2]; /* (r x F)_y */
        ok = ok && fabs(L - q * cl) < 1e-12 * q && fabs(D - q * cd) < 1e-12 * q &&
             F[1] == 0 && fabs(Mo[1] - m_want) < 1e-12 * q;
    }
    CHECK(ok, "surface: lift normal, drag along the flow, C_L and C_D at "
              "alpha + incidence + deflection, moment r x F (1e-12: rounding)");
    tsi_vehicle_ws_free(w);

    /* X tail: four equal surfaces at roll 45, 135, -135, -45 deg, no
     * deflection. In a flow with sideslip only, the heave force vanishes
     * by symmetry and the side force opposes the sideslip. */
    ts_vehicle *x = calloc(1, sizeof *x);
    x->ncomponents = 4;
    static const double rolls[4] = {M_PI / 4, 3 * M_PI / 4, -3 * M_PI / 4,
                                    -M_PI / 4};
    for (int i = 0; i < 4; i++) {
        ts_component *s = &x->component[i];
        ts_component_defaults(s, TS_COMP_SURFACE);
        snprintf(s->name, sizeof s->name, "tail%d", i + 1);
        s->area = 0.02;
        s->span = 0.15;
        s->roll = rolls[i];
        s->position[0] = -0.6; /* all four on the body axis */
    }
    w = tsi_vehicle_ws_alloc(x, &err);
    double wO[3] = {2.0, 0.15, 0.0};
    tsi_vehicle_hydro(x, w, rho, 1.0, wO, om, NULL, F, Mo, NULL);
    CHECK(fabs(F[2]) < 1e-13 && F[1] < 0 && fabs(Mo[0]) < 1e-13,
          "X tail in sideslip: heave force %.3g (0 by symmetry), side force "
          "%.4g N opposing, roll moment %.3g",
          F[2], F[1], Mo[0]);
    double wz[3] = {2.0, 0.0, 0.15};
    double F2[3], M2[3];
    tsi_vehicle_hydro(x, w, rho, 1.0, wz, om, NULL, F2, M2, NULL);
    CHECK(fabs(F2[2] - F[1]) < 1e-13 && fabs(F2[1]) < 1e-13,
          "X tail: the same angle in pitch gives the same force in heave");
    tsi_vehicle_ws_free(w);
    free(x);

    /* Hull: cross-flow drag integrated along the length. With cross flow
     * w_y + s om_z > 0 all along, the force is -k int (w_y + s om_z)^2 ds
     * = -k (L w_y^2 + om_z^2 L^3 / 12), k = 1/2 rho Cd D, and the yaw
     * moment about the centre -k int s (w_y + s om_z)^2 ds = -k w_y om_z
     * L^3 / 6: Gauss-Legendre is exact for these cubics. */
    ts_vehicle *h = calloc(1, sizeof *h);
    h->ncomponents = 1;
    ts_component *hu = &h->component[0];
    ts_component_defaults(hu, TS_COMP_HULL);
    snprintf(hu->name, sizeof hu->name, "hull");
    hu->length = 1.9;
    hu->diameter = 0.21;
    hu->position[0] = 0.13;
    w = tsi_vehicle_ws_alloc(h, &err);
    double Lh = 1.9, Dh = 0.21, wy = 0.7, omz = 0.3;
    double om2[3] = {0, 0, omz};
    /* velocity at the hull centre = wO + om x position */
    double wOh[3] = {1.5, wy - omz * 0.13, 0};
    tsi_vehicle_hydro(h, w, rho, 1.0, wOh, om2, NULL, F, Mo, &ld);
    double k = 0.5 * rho * hu->cd_cross * Dh;
    double Fy = -k * (Lh * wy * wy + omz * omz * Lh * Lh * Lh / 12);
    double Mz = -k * wy * omz * Lh * Lh * Lh / 6;
    double Fx = -0.5 * rho * hu->cd_axial * M_PI * Dh * Dh / 4 * 1.5 * 1.5;
    CHECK_REL(F[1], Fy, 1e-13, "hull cross-flow force");
    CHECK_REL(ld.moment[2] - 0.13 * F[1], Mz, 1e-12,
              "hull yaw moment about its centre");
    CHECK_REL(F[0], Fx, 1e-14, "hull axial drag");
    tsi_vehicle_ws_free(w);
    free(h);

    /* Munk moment of a spheroid at angle of attack a: (a33 - a11) U^2
     * sin a cos a, nose up for a > 0 (destabilising). Steady, no
     * rotation, attach at O, vacuum apart from added mass. */
    ts_vehicle *m = calloc(1, sizeof *m);
    ts_added_mass_spheroid(rho, 2.0, 0.3, m->added_mass, NULL, &err);
    m->inertia[0] = m->inertia[1] = m->inertia[2] = 1;
    w = tsi_vehicle_ws_alloc(m, &err);
    tsi_vehicle_state st;
    memset(&st, 0, sizeof st);
    st.R[0] = st.R[4] = st.R[8] = 1;
    st.frac = 1;
    double a = 0.21, U = 1.7, G[6], munk[3];
    v3_set(st.wO_b, U * cos(a), 0, U * sin(a));
    tsi_vehicle_loads(m, w, 10.0, rho, 0.0, &st, NULL, G, munk);
    double want = (m->added_mass[14] - m->added_mass[0]) * U * U * sin(a) *
                  cos(a);
    CHECK_REL(munk[1], want, 1e-14, "Munk moment (a33 - a11) U^2 sin cos");
    CHECK(want > 0 && fabs(G[4] - want) < 1e-12 * want && fabs(G[2]) < 1e-12,
          "steady translation: the Munk moment is the only load");
    tsi_vehicle_ws_free(w);
    free(m);
    free(v);
}

/* ---- 5. kinematics ---------------------------------------------------- */

static void mat_mul(const double A[9], const double B[9], double C[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            C[3 * i + j] = 0;
            for (int k = 0; k < 3; k++)
                C[3 * i + j] += A[3 * i + k] * B[3 * k + j];
        }
}

static void test_kinematics(void)
{
    double th[3] = {0.31, -0.52, 1.13}, thd[3] = {0.7, -0.4, 0.9};
    double R[9], R1[9] = {0}, R2[9] = {0}, R3[9] = {0}, T[9], P[9];
    tsi_rot123(th, R);
    double c1 = cos(th[0]), s1 = sin(th[0]), c2 = cos(th[1]),
           s2 = sin(th[1]), c3 = cos(th[2]), s3 = sin(th[2]);
    R1[0] = 1, R1[4] = c1, R1[5] = -s1, R1[7] = s1, R1[8] = c1;
    R2[0] = c2, R2[2] = s2, R2[4] = 1, R2[6] = -s2, R2[8] = c2;
    R3[0] = c3, R3[1] = -s3, R3[3] = s3, R3[4] = c3, R3[8] = 1;
    mat_mul(R1, R2, T);
    mat_mul(T, R3, P);
    double d = 0;
    for (int i = 0; i < 9; i++)
        d = fmax(d, fabs(P[i] - R[i]));
    CHECK(d < 1e-15, "1-2-3 rotation = R1 R2 R3: %.3g", d);

    /* omega_b from R^T dR/dt by central differences along theta(t) =
     * theta + t theta'. h = 1e-5: truncation ~h^2 = 1e-10, rounding
     * 1e-16 / 1e-5. */
    double h = 1e-5, tp[3], tm[3], Rp[9], Rm[9], E[9], om[3];
    for (int j = 0; j < 3; j++) {
        tp[j] = th[j] + h * thd[j];
        tm[j] = th[j] - h * thd[j];
    }
    tsi_rot123(tp, Rp);
    tsi_rot123(tm, Rm);
    double W[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            W[3 * i + j] = 0;
            for (int k = 0; k < 3; k++)
                W[3 * i + j] += R[3 * k + i] * (Rp[3 * k + j] - Rm[3 * k + j]) /
                                (2 * h);
        }
    tsi_rate_matrix(th, E);
    for (int i = 0; i < 3; i++)
        om[i] = E[3 * i] * thd[0] + E[3 * i + 1] * thd[1] + E[3 * i + 2] * thd[2];
    /* W = [om]x: W[7] = om_x, W[2] = om_y, W[3] = om_z */
    CHECK(fabs(W[7] - om[0]) < 1e-9 && fabs(W[2] - om[1]) < 1e-9 &&
              fabs(W[3] - om[2]) < 1e-9 && fabs(W[0]) < 1e-9,
          "omega_b = E theta' against R^T dR/dt");
    /* kappa = d/dt (E theta') at theta'' = 0. */
    double Ep[9], Em[9], kap[3];
    tsi_rate_matrix(tp, Ep);
    tsi_rate_matrix(tm, Em);
    tsi_rate_kappa(th, thd, kap);
    double kd = 0;
    for (int i = 0; i < 3; i++) {
        double fd = 0;
        for (int j = 0; j < 3; j++)
            fd += (Ep[3 * i + j] - Em[3 * i + j]) * thd[j] / (2 * h);
        kd = fmax(kd, fabs(fd - kap[i]));
    }
    CHECK(kd < 1e-9, "kappa against d(E theta')/dt: %.3g", kd);
    double back[3];
    tsi_rates_from_omega(th, om, back);
    CHECK(fabs(back[0] - thd[0]) < 1e-14 && fabs(back[1] - thd[1]) < 1e-14 &&
              fabs(back[2] - thd[2]) < 1e-14,
          "E inverse");

    /* Yaw-pitch-roll: R = Rz(y) Ry(p) Rx(r). */
    double ypr[3];
    tsi_ypr_from_rot(R, ypr);
    double cy = cos(ypr[0]), sy = sin(ypr[0]), cp = cos(ypr[1]),
           sp = sin(ypr[1]), cr = cos(ypr[2]), sr = sin(ypr[2]);
    double Z[9] = {cy, -sy, 0, sy, cy, 0, 0, 0, 1};
    double Y[9] = {cp, 0, sp, 0, 1, 0, -sp, 0, cp};
    double X[9] = {1, 0, 0, 0, cr, -sr, 0, sr, cr};
    mat_mul(Z, Y, T);
    mat_mul(T, X, P);
    d = 0;
    for (int i = 0; i < 9; i++)
        d = fmax(d, fabs(P[i] - R[i]));
    CHECK(d < 1e-15, "yaw-pitch-roll reproduce the rotation: %.3g", d);
    double yp[3], ym[3], yd[3];
    tsi_ypr_from_rot(Rp, yp);
    tsi_ypr_from_rot(Rm, ym);
    tsi_ypr_rates(ypr, om, yd);
    d = 0;
    for (int j = 0; j < 3; j++)
        d = fmax(d, fabs((yp[j] - ym[j]) / (2 * h) - yd[j]));
    CHECK(d < 1e-9, "yaw-pitch-roll rates against differences: %.3g", d);
    /* Kamman's sense: a positive theta2 alone pitches the nose up. */
    double th2[3] = {0, 0.2, 0};
    tsi_rot123(th2, R);
    tsi_ypr_from_rot(R, ypr);
    CHECK(R[6] < 0 && fabs(ypr[1] - 0.2) < 1e-15,
          "theta2 > 0 raises the nose (z of the nose %.3g < 0)", R[6]);
}

/* ---- 6. inertia ------------------------------------------------------- */

static void test_mass6(void)
{
    ts_vehicle v;
    memset(&v, 0, sizeof v);
    double I[6] = {2.1, 7.3, 6.9, -0.2, 0.35, 0.1};
    memcpy(v.inertia, I, sizeof I);
    v3_set(v.mass_centre, 0.12, -0.03, 0.07);
    v3_set(v.attach, 0.55, 0.02, -0.11);
    tsi_vehicle_state st;
    memset(&st, 0, sizeof st);
    double M6[36], m = 47.3;
    tsi_vehicle_mass6(&v, m, &st, M6);
    double nu[6] = {0.3, -1.1, 0.6, 0.8, -0.25, 0.45};
    double rho[3], vG[3], x[3], om[3] = {nu[3], nu[4], nu[5]}, Iom[3];
    for (int j = 0; j < 3; j++)
        rho[j] = v.mass_centre[j] - v.attach[j];
    v3_cross(om, rho, x);
    for (int j = 0; j < 3; j++)
        vG[j] = nu[j] + x[j];
    sym3_mul(I, om, Iom);
    double T = 0.5 * m * v3_dot(vG, vG) + 0.5 * v3_dot(om, Iom);
    CHECK_REL(0.5 * quad6(M6, nu), T, 1e-14,
              "spatial inertia about A: kinetic energy");
}

/* ---- 7. controllers --------------------------------------------------- */

static void test_control(void)
{
    ts_vehicle *v = calloc(1, sizeof *v);
    v->ncomponents = 3;
    for (int i = 0; i < 3; i++) {
        ts_component *c = &v->component[i];
        ts_component_defaults(c, TS_COMP_SURFACE);
        snprintf(c->name, sizeof c->name, "s%d", i);
        c->area = 0.1;
        c->span = 0.5;
        c->control = i < 2;
    }
    v->component[0].deflection = 0.02;
    v->component[0].limit = 0.3;
    v->component[1].time_constant = 0.05;
    v->component[1].rate_limit = 0.5;
    v->nloops = 2;
    ts_loop *d = &v->loop[0], *p = &v->loop[1];
    snprintf(d->name, sizeof d->name, "depth");
    d->measure = TS_MEASURE_DEPTH;
    d->setpoint = 10.0;
    d->kp = 0.2;
    d->ki = 0.03;
    d->kd = 0.5;
    d->nsurfaces = 1;
    d->surface[0] = 0;
    d->gain[0] = 1.0;
    snprintf(p->name, sizeof p->name, "heading");
    p->measure = TS_MEASURE_HEADING;
    p->setpoint = 3.0;
    p->kp = 1.5;
    p->nsurfaces = 2;
    p->surface[0] = 0;
    p->gain[0] = -0.5;
    p->surface[1] = 1;
    p->gain[1] = 1.0;
    ts_err err = {0};
    CHECK(ts_vehicle_check(v, 10.0, "bodies[0]", 0, &err) == TS_EINVAL,
          "inertia zero refused: %s", err.msg);
    v->inertia[0] = v->inertia[1] = v->inertia[2] = 1;
    CHECK(ts_vehicle_check(v, 10.0, "bodies[0]", 0, &err) == TS_OK,
          "controller description accepted");

    double val[4] = {10.4, 0.05, -0.02, -3.0}, rate[4] = {-0.1, 0, 0, 0};
    double xi[2] = {0.7, 99.0}, act[3] = {0, 0.1, 0}, us[3] = {0.01, 0, 0};
    double ul[2] = {0, 0}, out[2], delta[3], xd[2], ad[3];
    tsi_control_in in = {val, rate, xi, act, us, ul, NULL, NULL, NULL, 0};
    tsi_vehicle_control(v, &in, out, delta, xd, ad);
    double e_d = 0.4, v_d = 0.2 * 0.4 + 0.03 * 0.7 + 0.5 * -0.1;
    /* heading error -3 - 3 = -6 rad wraps to -6 + 2 pi */
    double e_h = -6.0 + 2 * M_PI, v_h = 1.5 * e_h;
    CHECK_NEAR(out[0], v_d, 1e-15, "PID output kp e + ki x + kd e'");
    CHECK_NEAR(xd[0], e_d, 1e-15, "integrator x' = e");
    CHECK_NEAR(out[1], v_h, 1e-14, "heading error wrapped into (-pi, pi]");
    double cmd0 = 0.02 + 0.01 + v_d - 0.5 * v_h;
    CHECK_NEAR(delta[0], fmax(-0.3, fmin(0.3, cmd0)), 1e-15,
               "surface 0: delta0 + input + mixed loops, within its limit");
    CHECK_NEAR(delta[1], 0.1, 0, "surface 1 deflects as its actuator state");
    double r = (v_h - 0.1) / 0.05;
    CHECK_NEAR(ad[1], fmax(-0.5, fmin(0.5, r)), 1e-15,
               "actuator rate (cmd - delta) / tau, saturated at 0.5 rad/s");
    CHECK(delta[2] == 0 && ad[2] == 0, "a fixed surface does not deflect");
    /* Saturation of the deflection. */
    us[0] = 1.0;
    tsi_vehicle_control(v, &in, out, delta, xd, ad);
    CHECK(delta[0] == 0.3, "deflection limited to 0.3 rad");
    in.steady = 1;
    tsi_vehicle_control(v, &in, out, delta, xd, ad);
    CHECK_NEAR(ad[1], (v_h - 0.1) / 0.05, 1e-12,
               "steady: the actuator's rate is not limited");
    in.steady = 0;
    double sp[2] = {10.25, 3.0};
    in.setpoint = sp;
    tsi_vehicle_control(v, &in, out, delta, xd, ad);
    CHECK_NEAR(xd[0], 0.15, 1e-15, "a set point in force other than the "
                                   "scene's: e = 10.4 - 10.25");
    in.setpoint = NULL;
    us[0] = 0.0;
    /* Frozen (open) and broken loops. */
    int mode[2] = {TS_LOOP_OPEN, TS_LOOP_BROKEN};
    double frozen[2] = {0.011, 0.0};
    ul[1] = 0.07;
    in.mode = mode;
    in.frozen = frozen;
    tsi_vehicle_control(v, &in, out, delta, xd, ad);
    CHECK_NEAR(delta[0], 0.02 + 0.011 - 0.5 * 0.07, 1e-15,
               "frozen loop holds its trim output, a broken loop passes its "
               "input");
    CHECK_NEAR(out[0], 0.2 * 0.4 + 0.5 * -0.1, 1e-15,
               "a frozen loop's output has no integrator");
    CHECK_NEAR(out[1], v_h, 1e-14, "a broken loop still reports its law");
    free(v);
}

/* ---- 8. bad descriptions ---------------------------------------------- */

static void test_bad(void)
{
    ts_vehicle *v = one_surface(0.1, 0.3);
    v->inertia[0] = v->inertia[1] = v->inertia[2] = 1;
    ts_component *c = &v->component[0];
    ts_err err = {0};
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_OK, "good fin");
    c->area = -1;
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "bodies[1].components[0].area"),
          "negative area: %s", err.msg);
    c->area = 0.1;
    c->stall = 0.02;
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, ".stall:"),
          "stall below its width: %s", err.msg);
    c->stall = 0.3;
    c->rate_limit = 1.0;
    c->control = 1;
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "time_constant"),
          "rate limit without an actuator: %s", err.msg);
    c->rate_limit = INFINITY;
    c->control = 0;
    c->limit = 0.2;
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "control surfaces"),
          "limit on a fixed surface: %s", err.msg);
    c->limit = INFINITY;
    v->added_mass[1] = 3.0;
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "symmetric"),
          "asymmetric added mass: %s", err.msg);
    v->added_mass[1] = 0;
    CHECK(ts_vehicle_check(v, 0, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "bodies[1].mass"),
          "massless vehicle: %s", err.msg);
    v->nloops = 1;
    v->loop[0].nsurfaces = 1;
    v->loop[0].surface[0] = 0;
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "not a control surface"),
          "loop driving a fixed surface: %s", err.msg);
    c->control = 1;
    snprintf(v->loop[0].name, sizeof v->loop[0].name, "wing");
    CHECK(ts_vehicle_check(v, 5, "bodies[1]", 0, &err) == TS_EINVAL &&
              strstr(err.msg, "also a component's name"),
          "loop named as a surface: %s", err.msg);
    free(v);
}

/* Drawing: ts_vehicle_rotation inverts tsi_ypr_from_rot; a hull's
 * outline spans its length along the body axis, turned by the attitude. */
static void test_outline(void)
{
    double R[9], ypr[3];
    ts_vehicle_rotation(0.3, -0.2, 0.1, R);
    tsi_ypr_from_rot(R, ypr);
    CHECK(fabs(ypr[0] - 0.3) < 1e-15 && fabs(ypr[1] + 0.2) < 1e-15 &&
              fabs(ypr[2] - 0.1) < 1e-15,
          "yaw, pitch, roll -> R -> yaw, pitch, roll (%.17g %.17g %.17g)",
          ypr[0], ypr[1], ypr[2]);
    ts_vehicle v = {0};
    v.ncomponents = 2;
    ts_component_defaults(&v.component[0], TS_COMP_HULL);
    v.component[0].length = 2.0;
    v.component[0].diameter = 0.2;
    ts_component_defaults(&v.component[1], TS_COMP_SURFACE);
    v.component[1].position[0] = -1.0;
    v.component[1].area = 0.1;
    v.component[1].span = 0.5;
    double O[3] = {1, 2, 3}, pts[3 * 100];
    ts_vehicle_rotation(0, 0.5, 0, R); /* nose up 0.5 rad */
    int n = ts_vehicle_outline(&v, R, O, NULL, pts, 100);
    /* 2 hull ellipses, 2 separators, a 5-point planform. */
    int want = 2 * TS_OUTLINE_HULL_POINTS + 2 + 5;
    double zmin = INFINITY, zmax = -INFINITY, xmin = INFINITY;
    for (int k = 0; k < TS_OUTLINE_HULL_POINTS; k++) {
        zmin = fmin(zmin, pts[3 * k + 2]);
        zmax = fmax(zmax, pts[3 * k + 2]);
        xmin = fmin(xmin, pts[3 * k]);
    }
    /* The nose (body x = 1) at z = 3 - sin 0.5 (up), the tail at
     * 3 + sin 0.5: the outline's depth range is 2 sin 0.5 plus the
     * diameter's share; the hull outline starts at the nose. */
    CHECK(n == want && isnan(pts[3 * TS_OUTLINE_HULL_POINTS]) &&
              fabs(pts[0] - (1 + cos(0.5))) < 1e-15 &&
              fabs(pts[2] - (3 - sin(0.5))) < 1e-15 && zmin < 3 - 0.47 &&
              zmax > 3 + 0.47 && xmin > 1 - cos(0.5) - 0.1,
          "outline: %d points (want %d), nose at x %.6f z %.6f", n, want,
          pts[0], pts[2]);
}

int main(void)
{
    gsl_set_error_handler_off();
    test_outline();
    test_spheroid();
    test_shift();
    test_curves();
    test_loads();
    test_kinematics();
    test_mass6();
    test_control();
    test_bad();
    return tc_done();
}
