/* test_kernel.c: the dynamics kernel f(y, u) (towstab/kernel.h) against
 * references written out here, independently of lib/kernel.c.
 *
 *  1. Loads (doc/model.md section 3): the nodal loads of one link and a
 *     sphere, partly submerged, moving in a turning, accelerating frame with a
 *     current, for both drag laws, recomputed from the formulas.
 *  2. Hanging at rest (V = 0): q'' = 0 and every link's tension is the wet
 *     weight below its midpoint in the lumped model.
 *  3. Planar multiple pendulum in vacuum (N = 3..6 links, unequal lengths
 *     and masses, a prescribed tow-point acceleration): the kernel's angle
 *     accelerations against Lagrange's equations M(q) q'' = -C(q, q') -
 *     dV/dq, derived and solved (GSL LU) here.
 *  4. Newton's law at every node and the rigidity of every link for an
 *     arbitrary 3-D state of a branched tree with added mass, partial
 *     submersion, a turning and accelerating frame, a current and tow-point
 *     motion; the force on the tow point.
 *  5. Energy: kinetic + potential energy of a branched 3-D tree with bending
 *     joints in vacuum is conserved by fixed-step RK4, the drift falling at
 *     fourth order as the step halves.
 *  6. Charts: re-charting every link leaves positions, velocities and node
 *     accelerations unchanged (also when mapped back from dydt through the
 *     chart formulas written here); |cos theta2| < TS_CHART_MIN gives
 *     TS_CHART with NaN output; clone, set_directions and reset_charts.
 * Tolerances are stated at each check with their reason. */
#include "towstab/kernel.h"

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tmodel.h"

/* ---- building systems ------------------------------------------------ */

typedef struct cable_def {
    const char *name;
    int from, to;           /* body indices, -1: tow point / free end */
    double length, diameter, mpl;
    int nlinks;
    const double *frac;     /* NULL: equal links */
    double cdn, cdt, can, ei;
    ts_drag_law law;
} cable_def;

typedef struct body_def {
    const char *name;
    ts_body_type type;
    double diameter, mass, cd, ca;
} body_def;

typedef struct env_def {
    double rho, g, speed, turn, point[3], current[3];
} env_def;

static ts_system *build(int nc, const cable_def *cd, int nb,
                        const body_def *bd, const env_def *e)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(nc, nb, &err);
    if (!s)
        return NULL;
    snprintf(s->name, sizeof s->name, "test");
    s->env.water_density = e->rho;
    s->env.gravity = e->g;
    for (int j = 0; j < 3; j++) {
        s->env.current[j] = e->current[j];
        s->tow.point[j] = e->point[j];
    }
    s->tow.speed = e->speed;
    s->tow.turn_rate = e->turn;
    for (int i = 0; i < nc; i++) {
        ts_cable *c = &s->cables[i];
        snprintf(c->name, sizeof c->name, "%s", cd[i].name);
        c->from_body = cd[i].from;
        c->to_body = cd[i].to;
        c->length = cd[i].length;
        c->diameter = cd[i].diameter;
        c->mass_per_length = cd[i].mpl;
        c->nlinks = cd[i].nlinks;
        c->cdn = cd[i].cdn;
        c->cdt = cd[i].cdt;
        c->can = cd[i].can;
        c->ei = cd[i].ei;
        c->drag_law = cd[i].law;
        if (cd[i].frac) {
            c->link_fraction = malloc((size_t)c->nlinks * sizeof(double));
            memcpy(c->link_fraction, cd[i].frac,
                   (size_t)c->nlinks * sizeof(double));
        }
    }
    for (int b = 0; b < nb; b++) {
        ts_body *o = &s->bodies[b];
        snprintf(o->name, sizeof o->name, "%s", bd[b].name);
        o->type = bd[b].type;
        o->diameter = bd[b].diameter;
        o->mass = bd[b].mass;
        o->cd = bd[b].cd;
        o->ca = bd[b].ca;
    }
    if (ts_system_build(s, &err) != TS_OK) {
        printf("build failed: %s\n", err.msg);
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* ---- small helpers --------------------------------------------------- */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double a[3]) { return sqrt(dot3(a, a)); }

static double uniform(gsl_rng *r, double a, double b)
{
    return a + (b - a) * gsl_rng_uniform(r);
}

/* The chart rotation R of link l, recovered from ts_kernel_direction():
 * the standard directions (-1,0,0), (0,1,0), (0,0,1) are reached at
 * (t1,t2) = (0,0), (0,-pi/2), (pi/2,0); R maps them to R's columns
 * -c0, c1, c2 (up to cos(pi/2) ~ 6e-17). R is column-stored here. */
static void chart_of(const ts_kernel *k, int l, double R[3][3])
{
    double n[3];
    ts_kernel_direction(k, l, 0, 0, n);
    for (int j = 0; j < 3; j++)
        R[0][j] = -n[j];
    ts_kernel_direction(k, l, 0, -M_PI / 2, n);
    for (int j = 0; j < 3; j++)
        R[1][j] = n[j];
    ts_kernel_direction(k, l, M_PI / 2, 0, n);
    for (int j = 0; j < 3; j++)
        R[2][j] = n[j];
}

/* Direction, its rate and its second rate for link angles a = t1, b = t2
 * with rates and accelerations, in the chart R (doc/model.md section 2:
 * n = (-c1 c2, -s2, s1 c2) before rotation), differentiated here. */
static void dir_derivs(const double R[3][3], double a, double b, double ad,
                       double bd, double add, double bdd, double n[3],
                       double nd[3], double ndd[3])
{
    double c1 = cos(a), s1 = sin(a), c2 = cos(b), s2 = sin(b);
    double h[3] = {-c1 * c2, -s2, s1 * c2};
    double na[3] = {s1 * c2, 0, c1 * c2};
    double nb[3] = {c1 * s2, -c2, -s1 * s2};
    double naa[3] = {c1 * c2, 0, -s1 * c2};
    double nab[3] = {-s1 * s2, 0, -c1 * s2};
    double nbb[3] = {c1 * c2, s2, -s1 * c2};
    double hd[3], hdd[3];
    for (int j = 0; j < 3; j++) {
        hd[j] = na[j] * ad + nb[j] * bd;
        hdd[j] = na[j] * add + nb[j] * bdd + naa[j] * ad * ad +
                 2 * nab[j] * ad * bd + nbb[j] * bd * bd;
    }
    for (int i = 0; i < 3; i++) {
        n[i] = nd[i] = ndd[i] = 0;
        for (int j = 0; j < 3; j++) {
            n[i] += R[j][i] * h[j];
            nd[i] += R[j][i] * hd[j];
            ndd[i] += R[j][i] * hdd[j];
        }
    }
}

/* Node positions, velocities and accelerations relative to M from the
 * state y and its derivative dydt, by the chart formulas above: the
 * kinematics of doc/model.md section 4 run forward. r, rd, rdd [3 nnodes]. */
static void nodes_from_state(const ts_kernel *k, const double y[],
                             const double dydt[], const double u[],
                             double r[], double rd[], double rdd[])
{
    const ts_system *s = ts_kernel_system(k);
    int nq = 2 * s->nlinks;
    for (int j = 0; j < 3; j++) {
        r[j] = s->tow.point[j] + (u ? u[j] : 0);
        rd[j] = u ? u[3 + j] : 0;
        rdd[j] = u ? u[6 + j] : 0;
    }
    for (int l = 0; l < s->nlinks; l++) {
        const ts_link *L = &s->links[l];
        double R[3][3], n[3], nd[3], ndd[3];
        chart_of(k, l, R);
        dir_derivs(R, y[2 * l], y[2 * l + 1], y[nq + 2 * l],
                   y[nq + 2 * l + 1], dydt ? dydt[nq + 2 * l] : 0,
                   dydt ? dydt[nq + 2 * l + 1] : 0, n, nd, ndd);
        for (int j = 0; j < 3; j++) {
            r[3 * L->lower + j] = r[3 * L->upper + j] + L->length * n[j];
            rd[3 * L->lower + j] = rd[3 * L->upper + j] + L->length * nd[j];
            rdd[3 * L->lower + j] = rdd[3 * L->upper + j] + L->length * ndd[j];
        }
    }
}

/* Largest |a_i - b_i| over n numbers. */
static double maxdiff(const double *a, const double *b, int n)
{
    double m = 0;
    for (int i = 0; i < n; i++)
        if (!(fabs(a[i] - b[i]) <= m))
            m = fabs(a[i] - b[i]);
    return m;
}

static double maxabs(const double *a, int n)
{
    double m = 0;
    for (int i = 0; i < n; i++)
        if (fabs(a[i]) > m)
            m = fabs(a[i]);
    return m;
}

/* ---- 1. loads -------------------------------------------------------- */

static void test_loads(ts_drag_law law)
{
    const char *lname = law == TS_DRAG_STANDARD ? "standard" : "loading";
    cable_def c = {"c", -1, 0, 2.385, 0.0317, 1.713, 1, NULL,
                   1.37, 0.023, 0.9, 0, law};
    body_def b = {"s", TS_BODY_SPHERE, 0.31, 7.9, 0.61, 0.5};
    env_def e = {1021.7, 9.79, 1.73, 0.137, {0.41, -0.23, -0.62},
                 {0.21, -0.13, 0.07}};
    ts_system *s = build(1, &c, 1, &b, &e);
    if (!CHECK(s != NULL, "loads (%s): system builds", lname))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    f.speed_rate = 0.31;
    f.turn_accel = -0.047;
    ts_kernel_set_frame(k, &f);
    /* Tow point 0.62 m above water, link 55 deg down and 20 deg to port:
     * the link crosses the surface; the sphere sits in it (cap). */
    double y[4] = {17 * M_PI / 180, 20 * M_PI / 180, 0.37, -0.29};
    double u[TS_NINPUT] = {0.013, -0.021, 0.017, 0.11, -0.07, 0.05, 0, 0, 0};
    double dydt[4];
    int rc = ts_kernel_eval(k, y, u, dydt);
    CHECK(rc == TS_OK, "loads (%s): eval ok", lname);

    double r[6], rd[6], rdd[6];
    nodes_from_state(k, y, NULL, u, r, rd, rdd);
    double n[3] = {(r[3] - r[0]) / c.length, (r[4] - r[1]) / c.length,
                   (r[5] - r[2]) / c.length};
    CHECK(r[2] < 0 && r[5] > 0 && r[5] < b.diameter / 2,
          "loads (%s): link crosses the surface, sphere partly wet "
          "(z %.3f, %.3f)", lname, r[2], r[5]);
    /* Inertial velocities of the nodes relative to the water. */
    double v[2][3];
    for (int i = 0; i < 2; i++) {
        v[i][0] = e.speed - e.turn * r[3 * i + 1] + rd[3 * i] - e.current[0];
        v[i][1] = e.turn * r[3 * i] + rd[3 * i + 1] - e.current[1];
        v[i][2] = rd[3 * i + 2] - e.current[2];
    }
    double w[3], wn[3], wt[3];
    for (int j = 0; j < 3; j++)
        w[j] = 0.5 * (v[0][j] + v[1][j]);
    double wdn = dot3(w, n);
    for (int j = 0; j < 3; j++) {
        wt[j] = wdn * n[j];
        wn[j] = w[j] - wt[j];
    }
    double sfrac = link_sub(r[2], r[5]);
    double l = c.length, d = c.diameter, rho = e.rho, g = e.g;
    double Fl[3] = {0, 0, (c.mpl - sfrac * rho * M_PI * d * d / 4) * l * g};
    if (law == TS_DRAG_STANDARD) {
        for (int j = 0; j < 3; j++)
            Fl[j] += -0.5 * rho * c.cdn * d * l * sfrac * norm3(wn) * wn[j] -
                     0.5 * rho * c.cdt * M_PI * d * l * sfrac * fabs(wdn) *
                         wt[j];
    } else {
        double hh = acos(fabs(wdn) / norm3(w)); /* angle link-flow */
        double fp = 0.5 - 0.1 * cos(hh) + 0.1 * sin(hh) - 0.4 * cos(2 * hh) +
                    0.11 * sin(2 * hh);
        double fq = 0.01 * (2.008 - 0.3858 * hh + 1.9159 * hh * hh -
                            4.1615 * pow(hh, 3) + 3.5064 * pow(hh, 4) -
                            1.1873 * pow(hh, 5));
        double q = 0.5 * rho * c.cdn * d * l * sfrac * dot3(w, w);
        for (int j = 0; j < 3; j++)
            Fl[j] += -q * fp * wn[j] / norm3(wn) -
                     q * fq * (wdn > 0 ? 1 : -1) * n[j];
    }
    double D = b.diameter, fr = sphere_sub(r[5], D);
    double Fs[3] = {0, 0, b.mass * g - fr * rho * g * M_PI * D * D * D / 6};
    double vs = norm3(v[1]);
    for (int j = 0; j < 3; j++)
        Fs[j] -= 0.5 * rho * b.cd * M_PI * D * D / 4 * fr * vs * v[1][j];
    const double *Q = ts_kernel_loads(k);
    double want[6], scale = fmax(norm3(Fl), norm3(Fs));
    for (int j = 0; j < 3; j++) {
        want[j] = 0.5 * Fl[j];
        want[3 + j] = 0.5 * Fl[j] + Fs[j];
    }
    /* Both sides are a few dozen floating-point operations on O(1..100) N:
     * agreement to 1e-13 of the largest load is rounding. */
    double dq = maxdiff(Q, want, 6);
    CHECK(dq <= 1e-13 * scale,
          "loads (%s): nodal loads = half link + sphere (weight, buoyancy "
          "of the wet %.3f of the link and %.3f of the sphere, drag): "
          "max diff %.3g N <= 1e-13 x %.4g N",
          lname, sfrac, fr, dq, scale);
    /* The kernel's positions and velocities: the chart kinematics. */
    CHECK(maxdiff(ts_kernel_positions(k), r, 6) <= 1e-14 * 3 &&
              maxdiff(ts_kernel_velocities(k), rd, 6) <= 1e-14 * 3,
          "loads (%s): positions and velocities from the angles", lname);
    ts_kernel_free(k);
    ts_system_free(s);
}

/* ---- 2. hanging at rest --------------------------------------------- */

static void test_hanging_kernel(void)
{
    static const double fr[4] = {0.31, 0.17, 0.29, 0.23};
    cable_def c[2] = {{"a", -1, 0, 3.71, 0.021, 0.913, 4, fr, 1.2, 0.01,
                       1.0, 0, TS_DRAG_STANDARD},
                      {"b", 0, 1, 1.93, 0.013, 0.377, 3, NULL, 1.2, 0.01,
                       1.0, 0, TS_DRAG_STANDARD}};
    body_def b[2] = {{"j", TS_BODY_JUNCTION, 0, 0.271, 0, 0},
                     {"s", TS_BODY_SPHERE, 0.17, 3.37, 0.5, 0.5}};
    env_def e = {1025.3, 9.80665, 0, 0, {0.3, -0.2, 1.1}, {0, 0, 0}};
    ts_system *s = build(2, c, 2, b, &e);
    if (!CHECK(s != NULL, "hanging: system builds"))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    int nl = s->nlinks, nq = 2 * nl;
    double *y = calloc(2 * (size_t)nq, sizeof(double));
    double *dydt = calloc(2 * (size_t)nq, sizeof(double));
    for (int l = 0; l < nl; l++)
        y[2 * l] = M_PI / 2;
    CHECK(ts_kernel_eval(k, y, NULL, dydt) == TS_OK, "hanging: eval ok");
    /* Wet weight of each link and body, from the definitions. */
    double g = e.g, rho = e.rho;
    double below = 0, worst = 0, Wtot = 0;
    const double *t = ts_kernel_tensions(k);
    for (int l = nl - 1; l >= 0; l--) {
        const ts_link *L = &s->links[l];
        const cable_def *cd = &c[L->cable];
        double len = cd->length * (cd->frac ? cd->frac[L->index - 1]
                                            : 1.0 / cd->nlinks);
        double wl = (cd->mpl - rho * M_PI * cd->diameter * cd->diameter / 4) *
                    g * len;
        if (cd->to >= 0 && L->next < 0) {
            const body_def *bb = &b[cd->to];
            below += bb->mass * g;
            if (bb->type == TS_BODY_SPHERE)
                below -= rho * g * M_PI * pow(bb->diameter, 3) / 6;
        }
        double want = below + 0.5 * wl;
        below += wl;
        double rel = fabs(t[l] - want) / want;
        if (rel > worst)
            worst = rel;
    }
    Wtot = below;
    /* Sums of a handful of terms: rounding, 1e-12 relative. */
    CHECK(worst <= 1e-12, "hanging: link tension = wet weight below its "
                          "midpoint, worst rel diff %.3g <= 1e-12", worst);
    double F[3];
    double top = ts_kernel_tow_force(k, F);
    CHECK_REL(top, Wtot, 1e-12, "hanging: force on the tow point = the "
                                "whole wet weight");
    CHECK(maxabs(dydt + nq, nq) <= 1e-12 * g / 0.5,
          "hanging: q'' = 0 (max %.3g rad/s^2)", maxabs(dydt + nq, nq));
    free(y);
    free(dydt);
    ts_kernel_free(k);
    ts_system_free(s);
}

/* ---- 3. planar pendulum against Lagrange ------------------------------ */

static void test_lagrange(gsl_rng *rng, int N)
{
    /* Cable a: 2 unequal links; a junction with its own mass; cable b:
     * N - 2 unequal links to a sphere. In vacuum. */
    double fb[4];
    double sum = 0;
    for (int i = 0; i < N - 2; i++)
        sum += fb[i] = 1.0 + 0.37 * i * i;
    for (int i = 0; i < N - 2; i++)
        fb[i] /= sum;
    static const double fa[2] = {0.37, 0.63};
    cable_def c[2] = {{"a", -1, 0, 1.913, 0.01, 0.731, 2, fa, 1.2, 0.01,
                       1.0, 0, TS_DRAG_STANDARD},
                      {"b", 0, 1, 2.385, 0.01, 0.268, N - 2, fb, 1.2, 0.01,
                       1.0, 0, TS_DRAG_STANDARD}};
    body_def b[2] = {{"j", TS_BODY_JUNCTION, 0, 0.417, 0, 0},
                     {"s", TS_BODY_SPHERE, 0.2, 1.237, 0.5, 0.5}};
    env_def e = {0.0, 9.80665, 0, 0, {0.7, 0.3, -1.9}, {0, 0, 0}};
    ts_system *s = build(2, c, 2, b, &e);
    if (!CHECK(s != NULL && s->nlinks == N, "pendulum N=%d: builds", N))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    int nq = 2 * N;
    /* Link lengths and joint masses, from the definitions (not sys). */
    double len[6], mass[6], mlink[6];
    for (int i = 0; i < N; i++) {
        const cable_def *cd = i < 2 ? &c[0] : &c[1];
        len[i] = cd->length * cd->frac[i < 2 ? i : i - 2];
        mlink[i] = cd->mpl * len[i];
    }
    for (int i = 0; i < N; i++)
        mass[i] = 0.5 * mlink[i] + (i + 1 < N ? 0.5 * mlink[i + 1] : 0) +
                  (i == 1 ? b[0].mass : 0) + (i == N - 1 ? b[1].mass : 0);

    for (int trial = 0; trial < 4; trial++) {
        double y[24] = {0}, dydt[24], q[6], qd[6];
        for (int i = 0; i < N; i++) {
            q[i] = uniform(rng, -M_PI, M_PI);
            qd[i] = uniform(rng, -2.5, 2.5);
            y[2 * i] = q[i];
            y[nq + 2 * i] = qd[i];
        }
        /* Tow-point acceleration (x, z): an extra uniform field. */
        double u[TS_NINPUT] = {0};
        u[6] = trial ? uniform(rng, -3, 3) : 0;
        u[8] = trial ? uniform(rng, -3, 3) : 0;
        double Gx = -u[6], Gz = e.g - u[8];
        int rc = ts_kernel_eval(k, y, u, dydt);
        CHECK(rc == TS_OK, "pendulum N=%d trial %d: eval ok", N, trial);
        /* Lagrange: with r_i = sum_{j<=i} l_j (-cos q_j, 0, sin q_j) and
         * Mbar_jk = sum of the joint masses at or below max(j, k),
         *   T = 1/2 sum_jk Mbar_jk l_j l_k cos(q_j - q_k) q_j' q_k',
         *   V = -sum_i m_i G.r_i,
         * d/dt dT/dq_j' - dT/dq_j + dV/dq_j = 0 gives
         *   sum_k Mbar_jk l_j l_k [cos(q_j - q_k) q_k'' + sin(q_j - q_k)
         *   q_k'^2] = Mbar_jj l_j (G_x sin q_j + G_z cos q_j). */
        double Mbar[6], A[36], rhs[6];
        for (int j = 0; j < N; j++) {
            Mbar[j] = 0;
            for (int i = j; i < N; i++)
                Mbar[j] += mass[i];
        }
        for (int j = 0; j < N; j++) {
            rhs[j] = Mbar[j] * len[j] * (Gx * sin(q[j]) + Gz * cos(q[j]));
            for (int kk = 0; kk < N; kk++) {
                double m = Mbar[j > kk ? j : kk] * len[j] * len[kk];
                A[j * N + kk] = m * cos(q[j] - q[kk]);
                rhs[j] -= m * sin(q[j] - q[kk]) * qd[kk] * qd[kk];
            }
        }
        gsl_matrix_view Am = gsl_matrix_view_array(A, (size_t)N, (size_t)N);
        gsl_vector_view bv = gsl_vector_view_array(rhs, (size_t)N);
        gsl_vector *x = gsl_vector_alloc((size_t)N);
        gsl_permutation *p = gsl_permutation_alloc((size_t)N);
        int sg;
        gsl_linalg_LU_decomp(&Am.matrix, p, &sg);
        gsl_linalg_LU_solve(&Am.matrix, p, &bv.vector, x);
        double scale = 0, d1 = 0, d2 = 0;
        for (int i = 0; i < N; i++) {
            double want = gsl_vector_get(x, (size_t)i);
            scale = fmax(scale, fabs(want));
            d1 = fmax(d1, fabs(dydt[nq + 2 * i] - want));
            d2 = fmax(d2, fabs(dydt[nq + 2 * i + 1]));
        }
        gsl_vector_free(x);
        gsl_permutation_free(p);
        /* Both are O(N) solves of well-conditioned systems (the mass
         * matrix of point masses): 1e-10 of the largest q'' is far above
         * their rounding and far below any modelling difference. */
        CHECK(d1 <= 1e-10 * scale && d2 <= 1e-10 * scale,
              "pendulum N=%d trial %d: theta1'' = Lagrange (max diff %.3g "
              "of %.4g rad/s^2), theta2'' = 0 (%.3g) to 1e-10", N, trial,
              d1, scale, d2);
    }
    ts_kernel_free(k);
    ts_system_free(s);
}

/* ---- 4. Newton's law at every node ----------------------------------- */

/* A branched tree used by several tests: lead cable to a junction with
 * mass, an upper branch to a sphere and a lower branch to a sphere. */
static ts_system *branched(double rho, double ei, const env_def *e)
{
    static const double fl[3] = {0.29, 0.38, 0.33};
    cable_def c[3] = {{"lead", -1, 0, 2.13, 0.019, 0.83, 3, fl, 1.31, 0.013,
                       0.93, ei, TS_DRAG_STANDARD},
                      {"up", 0, 1, 1.47, 0.011, 0.42, 2, NULL, 1.17, 0.021,
                       1.07, 0, TS_DRAG_LOADING},
                      {"lo", 0, 2, 1.12, 0.014, 0.55, 3, NULL, 1.42, 0.008,
                       0.81, 0.5 * ei, TS_DRAG_STANDARD}};
    body_def b[3] = {{"j", TS_BODY_JUNCTION, 0, 0.31, 0, 0},
                     {"s1", TS_BODY_SPHERE, 0.1, 0.9, 0.55, 0.5},
                     {"s2", TS_BODY_SPHERE, 0.12, 1.4, 0.47, 0.45}};
    env_def ee = *e;
    ee.rho = rho;
    return build(3, c, 3, b, &ee);
}

static void random_state(gsl_rng *rng, int nl, double *y, double t2max,
                         double rate)
{
    int nq = 2 * nl;
    for (int l = 0; l < nl; l++) {
        y[2 * l] = uniform(rng, 0.2, 2.9);
        y[2 * l + 1] = uniform(rng, -t2max, t2max);
        y[nq + 2 * l] = uniform(rng, -rate, rate);
        y[nq + 2 * l + 1] = uniform(rng, -rate, rate);
    }
}

static void test_newton_nodes(gsl_rng *rng)
{
    env_def e = {0, 9.80665, 1.37, 0.23, {0.11, 0.07, -0.45},
                 {0.17, -0.09, 0.04}};
    ts_system *s = branched(1024.1, 0.0, &e);
    if (!CHECK(s != NULL, "newton nodes: system builds"))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    f.speed_rate = -0.27;
    f.turn_accel = 0.061;
    ts_kernel_set_frame(k, &f);
    int nl = s->nlinks, nn = s->nnodes, nq = 2 * nl;
    double rho = s->env.water_density;
    double *y = calloc(2 * (size_t)nq, sizeof(double));
    double *dydt = calloc(2 * (size_t)nq, sizeof(double));
    double *r = calloc(3 * (size_t)nn, sizeof(double));
    double *rd = calloc(3 * (size_t)nn, sizeof(double));
    double *rdd = calloc(3 * (size_t)nn, sizeof(double));
    int wet_links = 0, dry_links = 0, cut_links = 0;
    for (int trial = 0; trial < 20; trial++) {
        random_state(rng, nl, y, 1.0, 1.5);
        double u[TS_NINPUT] = {0};
        for (int j = 0; j < 9; j++)
            u[j] = uniform(rng, -0.3, 0.3);
        if (ts_kernel_eval(k, y, u, dydt) != TS_OK) {
            CHECK(0, "newton nodes trial %d: eval ok", trial);
            continue;
        }
        nodes_from_state(k, y, dydt, u, r, rd, rdd);
        const double *Q = ts_kernel_loads(k), *t = ts_kernel_tensions(k);
        const double *kr = ts_kernel_positions(k);
        const double *krdd = ts_kernel_rel_accelerations(k);
        /* Frame part of each node's acceleration (doc/model.md section 1). */
        double worst = 0, scale = 0, rig = 0, rscale = 0;
        for (int l = 0; l < nl; l++)
            scale = fmax(scale, fabs(t[l]));
        for (int i = 0; i < nn; i++)
            scale = fmax(scale, norm3(Q + 3 * i));
        for (int i = 1; i < nn; i++) {
            const double *ri = r + 3 * i, *vi = rd + 3 * i;
            double W = f.turn_rate, Wd = f.turn_accel;
            double afr[3] = {f.speed_rate - Wd * ri[1] - W * W * ri[0] -
                                 2 * W * vi[1],
                             W * f.speed + Wd * ri[0] - W * W * ri[1] +
                                 2 * W * vi[0],
                             0};
            double a[3], Mm[3][3] = {{0}};
            for (int j = 0; j < 3; j++)
                a[j] = rdd[3 * i + j] + afr[j];
            /* Node mass matrix (doc/model.md section 4). */
            double m = s->nodes[i].mass;
            int bi = s->nodes[i].body;
            if (bi >= 0 && s->bodies[bi].type == TS_BODY_SPHERE) {
                double D = s->bodies[bi].diameter;
                m += sphere_sub(ri[2], D) * s->bodies[bi].ca * rho * M_PI *
                     D * D * D / 6;
            }
            for (int j = 0; j < 3; j++)
                Mm[j][j] = m;
            double F[3];
            for (int j = 0; j < 3; j++)
                F[j] = Q[3 * i + j];
            for (int l = 0; l < nl; l++) {
                const ts_link *L = &s->links[l];
                if (L->upper != i && L->lower != i)
                    continue;
                double n[3];
                for (int j = 0; j < 3; j++)
                    n[j] = (r[3 * L->lower + j] - r[3 * L->upper + j]) /
                           L->length;
                double sub = link_sub(r[3 * L->upper + 2],
                                      r[3 * L->lower + 2]);
                double A = L->can * rho * M_PI * L->diameter * L->diameter /
                           4 * L->length * sub;
                for (int p = 0; p < 3; p++)
                    for (int q2 = 0; q2 < 3; q2++)
                        Mm[p][q2] += 0.5 * A * ((p == q2) - n[p] * n[q2]);
                /* Tension pulls the lower node up the link and the upper
                 * node down it. */
                double sgn = L->lower == i ? -1.0 : 1.0;
                for (int j = 0; j < 3; j++)
                    F[j] += sgn * t[l] * n[j];
                if (L->lower == i) {
                    if (sub == 1)
                        wet_links++;
                    else if (sub == 0)
                        dry_links++;
                    else
                        cut_links++;
                }
            }
            for (int j = 0; j < 3; j++) {
                double Ma = Mm[j][0] * a[0] + Mm[j][1] * a[1] +
                            Mm[j][2] * a[2];
                worst = fmax(worst, fabs(Ma - F[j]));
            }
        }
        for (int l = 0; l < nl; l++) {
            const ts_link *L = &s->links[l];
            double n[3], dv[3], da[3];
            for (int j = 0; j < 3; j++) {
                n[j] = (r[3 * L->lower + j] - r[3 * L->upper + j]) / L->length;
                dv[j] = (rd[3 * L->lower + j] - rd[3 * L->upper + j]) /
                        L->length;
                da[j] = rdd[3 * L->lower + j] - rdd[3 * L->upper + j];
            }
            /* d2/dt2 |r_k - r_p|^2 = 0: n.(r''_k - r''_p) = -l |n'|^2. */
            double want = -L->length * dot3(dv, dv);
            rig = fmax(rig, fabs(dot3(n, da) - want));
            rscale = fmax(rscale, fmax(norm3(da), fabs(want)));
        }
        /* The kernel eliminates 3x3 blocks along the tree: its residual is
         * rounding on the largest force, far below 1e-10 of it. */
        CHECK(worst <= 1e-10 * scale,
              "newton nodes trial %2d: M_k a_k = Q_k - t_k n_k + sum t_c n_c "
              "at every node, max %.3g N <= 1e-10 x %.4g N", trial, worst,
              scale);
        CHECK(rig <= 1e-10 * rscale,
              "newton nodes trial %2d: rigidity n.(r''_k - r''_p) = -l|n'|^2, "
              "max %.3g <= 1e-10 x %.4g m/s^2", trial, rig, rscale);
        double dpos = maxdiff(kr, r, 3 * nn);
        double dacc = maxdiff(krdd, rdd, 3 * nn);
        CHECK(dpos <= 1e-13 && dacc <= 1e-10 * maxabs(rdd, 3 * nn),
              "newton nodes trial %2d: kernel positions and r'' = those "
              "mapped from y and dydt (%.3g m, %.3g m/s^2)", trial, dpos,
              dacc);
        /* The force on the tow point: the top link's tension, the loads
         * lumped at node 0, less node 0's inertia (its mass is half the
         * top link's plus its added mass). */
        double F0[3], Fw[3];
        ts_kernel_tow_force(k, F0);
        const ts_link *L0 = &s->links[0];
        double n0[3];
        for (int j = 0; j < 3; j++)
            n0[j] = (r[3 + j] - r[j]) / L0->length;
        double W = f.turn_rate, Wd = f.turn_accel;
        double a0[3] = {f.speed_rate - Wd * r[1] - W * W * r[0] - 2 * W * rd[1]
                            + u[6],
                        W * f.speed + Wd * r[0] - W * W * r[1] + 2 * W * rd[0]
                            + u[7],
                        u[8]};
        double sub0 = link_sub(r[2], r[5]);
        double A0 = L0->can * rho * M_PI * L0->diameter * L0->diameter / 4 *
                    L0->length * sub0;
        double na0 = dot3(n0, a0);
        for (int j = 0; j < 3; j++)
            Fw[j] = t[0] * n0[j] + Q[j] - s->nodes[0].mass * a0[j] -
                    0.5 * A0 * (a0[j] - na0 * n0[j]);
        CHECK(maxdiff(F0, Fw, 3) <= 1e-12 * scale,
              "newton nodes trial %2d: tow force = t n + Q_0 - M_0 a_0 "
              "(diff %.3g N)", trial, maxdiff(F0, Fw, 3));
    }
    CHECK(wet_links > 0 && dry_links > 0 && cut_links > 0,
          "newton nodes: states covered wet (%d), dry (%d) and cut (%d) "
          "links", wet_links, dry_links, cut_links);
    free(y);
    free(dydt);
    free(r);
    free(rd);
    free(rdd);
    ts_kernel_free(k);
    ts_system_free(s);
}

/* ---- 5. energy in vacuum, RK4 ---------------------------------------- */

static double energy(ts_kernel *k, const double *y, double *dydt)
{
    if (ts_kernel_eval(k, y, NULL, dydt) != TS_OK)
        return NAN;
    return ts_kernel_kinetic_energy(k) + ts_kernel_potential_energy(k);
}

static void test_energy(gsl_rng *rng)
{
    env_def e = {0, 9.80665, 0, 0, {0.2, -0.1, 0.3}, {0, 0, 0}};
    ts_system *s = branched(0.0, 0.37, &e);
    if (!CHECK(s != NULL && s->has_bending, "energy: system with bending"))
        return;
    int nl = s->nlinks, ns = 4 * nl;
    double *y0 = calloc((size_t)ns, sizeof(double));
    double *y = calloc((size_t)ns, sizeof(double));
    double *w = calloc(5 * (size_t)ns, sizeof(double));
    random_state(rng, nl, y0, 0.6, 1.2);
    const double T = 1.0;
    double drift[3], Escale = 0;
    int recharts = 0;
    for (int run = 0; run < 3; run++) {
        int steps = 200 << run;
        double h = T / steps;
        ts_kernel *k = ts_kernel_alloc(s, NULL);
        memcpy(y, y0, (size_t)ns * sizeof(double));
        double E0 = energy(k, y, w);
        Escale = ts_kernel_kinetic_energy(k) +
                 fabs(ts_kernel_potential_energy(k));
        double worst = 0;
        int rc = TS_OK;
        for (int n = 0; n < steps && rc == TS_OK; n++) {
            rc = rk4_step(k, y, h, ns, w);
            recharts += ts_kernel_rechart(k, y, TS_CHART_RECHART);
            worst = fmax(worst, fabs(energy(k, y, w) - E0));
        }
        CHECK(rc == TS_OK, "energy: RK4 with h = %.4g s ran", h);
        drift[run] = worst / Escale;
        ts_kernel_free(k);
    }
    printf("     energy drift over %.1f s: %.3g, %.3g, %.3g (h = %g, %g, "
           "%g s); %d re-charts\n", T, drift[0], drift[1], drift[2], T / 200,
           T / 400, T / 800, recharts);
    /* RK4's global error is O(h^4): halving h divides the drift by 16.
     * Allow 11..23 (the leading term dominates only asymptotically); the
     * finest drift must also be small, so this is not rounding. */
    double r1 = drift[0] / drift[1], r2 = drift[1] / drift[2];
    CHECK(r1 > 11 && r1 < 23 && r2 > 11 && r2 < 23,
          "energy: T + U drift falls at 4th order (ratios %.2f, %.2f in "
          "[11, 23])", r1, r2);
    CHECK(drift[2] < 1e-5 && drift[2] > 1e-14,
          "energy: finest drift %.3g relative, 1e-14 < drift < 1e-5",
          drift[2]);
    free(y0);
    free(y);
    free(w);
    ts_system_free(s);
}

/* ---- 6. charts -------------------------------------------------------- */

static void test_charts(gsl_rng *rng)
{
    env_def e = {0, 9.80665, 1.61, -0.19, {0.1, 0.2, 0.35},
                 {0.05, 0.11, 0}};
    ts_system *s = branched(1025.0, 0.0, &e);
    if (!CHECK(s != NULL, "charts: system builds"))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    int nl = s->nlinks, nn = s->nnodes, nq = 2 * nl, ns = 2 * nq;
    double *y = calloc((size_t)ns, sizeof(double));
    double *y2 = calloc((size_t)ns, sizeof(double));
    double *d1 = calloc((size_t)ns, sizeof(double));
    double *d2 = calloc((size_t)ns, sizeof(double));
    double *r1 = calloc(9 * (size_t)nn, sizeof(double));
    double *r2 = calloc(9 * (size_t)nn, sizeof(double));
    double *m1 = calloc(9 * (size_t)nn, sizeof(double));
    double *m2 = calloc(9 * (size_t)nn, sizeof(double));
    double u[TS_NINPUT] = {0.01, 0.02, -0.03, 0.1, 0.05, -0.2, 0.3, -0.1, 0.2};

    for (int trial = 0; trial < 5; trial++) {
        ts_kernel *kc = ts_kernel_alloc(s, NULL);
        random_state(rng, nl, y, 1.2, 1.0);
        memcpy(y2, y, (size_t)ns * sizeof(double));
        int rc1 = ts_kernel_eval(kc, y, u, d1);
        memcpy(r1, ts_kernel_positions(kc), 3 * (size_t)nn * sizeof(double));
        memcpy(r1 + 3 * nn, ts_kernel_velocities(kc),
               3 * (size_t)nn * sizeof(double));
        memcpy(r1 + 6 * nn, ts_kernel_rel_accelerations(kc),
               3 * (size_t)nn * sizeof(double));
        nodes_from_state(kc, y, d1, u, m1, m1 + 3 * nn, m1 + 6 * nn);
        /* A threshold above 1 moves every link to a chart centred on its
         * direction (|cos theta2| <= 1 < 1.5). */
        int moved = ts_kernel_rechart(kc, y2, 1.5);
        double cmin = 1;
        for (int l = 0; l < nl; l++)
            cmin = fmin(cmin, fabs(cos(y2[2 * l + 1])));
        int rc2 = ts_kernel_eval(kc, y2, u, d2);
        memcpy(r2, ts_kernel_positions(kc), 3 * (size_t)nn * sizeof(double));
        memcpy(r2 + 3 * nn, ts_kernel_velocities(kc),
               3 * (size_t)nn * sizeof(double));
        memcpy(r2 + 6 * nn, ts_kernel_rel_accelerations(kc),
               3 * (size_t)nn * sizeof(double));
        nodes_from_state(kc, y2, d2, u, m2, m2 + 3 * nn, m2 + 6 * nn);
        CHECK(rc1 == TS_OK && rc2 == TS_OK && moved == nl &&
                  cmin > 1 - 1e-12,
              "charts trial %d: all %d links re-charted to their centre "
              "(min |cos theta2| %.15f)", trial, moved, cmin);
        /* Positions, velocities and accelerations of the same physical
         * state: the chart change is an exact rotation, so they agree to
         * rounding, 1e-12 of their size. */
        double sp = maxabs(r1, 3 * nn), sv = maxabs(r1 + 3 * nn, 3 * nn),
               sa = maxabs(r1 + 6 * nn, 3 * nn);
        double dp = maxdiff(r1, r2, 3 * nn),
               dv = maxdiff(r1 + 3 * nn, r2 + 3 * nn, 3 * nn),
               da = maxdiff(r1 + 6 * nn, r2 + 6 * nn, 3 * nn);
        CHECK(dp <= 1e-12 * sp && dv <= 1e-12 * sv && da <= 1e-12 * sa,
              "charts trial %d: kernel r, r', r'' unchanged by re-charting "
              "(%.2g, %.2g, %.2g relative <= 1e-12)", trial, dp / sp,
              dv / sv, da / sa);
        double dm = maxdiff(m1 + 6 * nn, m2 + 6 * nn, 3 * nn),
               dk = maxdiff(m2 + 6 * nn, r2 + 6 * nn, 3 * nn);
        CHECK(dm <= 1e-12 * sa && dk <= 1e-12 * sa,
              "charts trial %d: dydt mapped to r'' is the same in both "
              "charts (%.2g) and equals the kernel's r'' (%.2g), relative "
              "<= 1e-12", trial, dm / sa, dk / sa);
        double dpm = maxdiff(m2, r2, 6 * nn);
        CHECK(dpm <= 1e-12 * fmax(sp, sv),
              "charts trial %d: positions and velocities from the new "
              "angles (%.2g)", trial, dpm);
        /* A clone keeps the charts: the same numbers, bit for bit. */
        ts_kernel *cl = ts_kernel_clone(kc, NULL);
        double *d3 = calloc((size_t)ns, sizeof(double));
        ts_kernel_eval(cl, y2, u, d3);
        CHECK(memcmp(d2, d3, (size_t)ns * sizeof(double)) == 0,
              "charts trial %d: clone evaluates identically", trial);
        free(d3);
        ts_kernel_free(cl);
        /* Back to the standard chart: the original angles and rates
         * (theta1 up to 2 pi). */
        int left = ts_kernel_reset_charts(kc, y2, 0.25);
        double da2 = 0;
        for (int i = 0; i < ns; i++) {
            double dd = y2[i] - y[i];
            if (i < nq && (i % 2) == 0)
                dd = remainder(dd, 2 * M_PI);
            da2 = fmax(da2, fabs(dd));
        }
        CHECK(left == 0 && da2 <= 1e-12,
              "charts trial %d: reset_charts restores the standard angles "
              "and rates (%.2g)", trial, da2);
        ts_kernel_free(kc);
    }

    /* set_directions: directions and rates -> the same state. */
    random_state(rng, nl, y, 1.2, 1.0);
    ts_kernel_eval(k, y, NULL, d1);
    double *n = calloc(3 * (size_t)nl, sizeof(double));
    double *nd = calloc(3 * (size_t)nl, sizeof(double));
    for (int l = 0; l < nl; l++) {
        double R[3][3], ndd[3];
        chart_of(k, l, R);
        dir_derivs(R, y[2 * l], y[2 * l + 1], y[nq + 2 * l],
                   y[nq + 2 * l + 1], 0, 0, n + 3 * l, nd + 3 * l, ndd);
    }
    int moved = ts_kernel_set_directions(k, n, nd, 0.25, y2);
    double dd = 0;
    for (int i = 0; i < ns; i++)
        dd = fmax(dd, fabs(i < nq && i % 2 == 0
                               ? remainder(y2[i] - y[i], 2 * M_PI)
                               : y2[i] - y[i]));
    CHECK(moved == 0 && dd <= 1e-12,
          "set_directions: recovers angles and rates (%.2g)", dd);

    /* The chart singularity: link 3 pointing (nearly) sideways. */
    random_state(rng, nl, y, 0.5, 1.0);
    static const double bad[] = {M_PI / 2, -M_PI / 2, M_PI / 2 - 5e-7,
                                 -M_PI / 2 + 9e-7, 3 * M_PI / 2};
    for (int i = 0; i < 5; i++) {
        y[2 * 3 + 1] = bad[i];
        for (int j = 0; j < ns; j++)
            d1[j] = 0;
        int rc = ts_kernel_eval(k, y, NULL, d1);
        int allnan = 1;
        for (int j = 0; j < ns; j++)
            allnan &= isnan(d1[j]);
        CHECK(rc == TS_CHART && allnan,
              "chart: theta2 = %.9f (|cos| %.2g < %g) gives TS_CHART and "
              "NaN in all %d outputs", bad[i], fabs(cos(bad[i])),
              TS_CHART_MIN, ns);
    }
    /* Just inside the chart: finite and right, though 1/cos theta2 ~ 5e5
     * amplifies rounding in theta1'', which the mapping back through
     * cos theta2 cancels: r'' agrees to 1e-10. */
    y[2 * 3 + 1] = M_PI / 2 - 2e-6;
    int rc = ts_kernel_eval(k, y, NULL, d1);
    int finite = 1;
    for (int j = 0; j < ns; j++)
        finite &= isfinite(d1[j]);
    nodes_from_state(k, y, d1, NULL, m1, m1 + 3 * nn, m1 + 6 * nn);
    double sa = maxabs(ts_kernel_rel_accelerations(k), 3 * nn);
    double dk = maxdiff(m1 + 6 * nn, ts_kernel_rel_accelerations(k), 3 * nn);
    CHECK(rc == TS_OK && finite && dk <= 1e-10 * sa,
          "chart: |cos theta2| = 2e-6 evaluates, finite, r'' consistent "
          "(%.2g relative <= 1e-10)", dk / sa);
    memcpy(r1, ts_kernel_rel_accelerations(k), 3 * (size_t)nn * sizeof(double));
    /* Re-charting with the default threshold moves that link only. */
    memcpy(y2, y, (size_t)ns * sizeof(double));
    moved = ts_kernel_rechart(k, y2, TS_CHART_RECHART);
    rc = ts_kernel_eval(k, y2, NULL, d2);
    dk = maxdiff(r1, ts_kernel_rel_accelerations(k), 3 * nn);
    CHECK(moved == 1 && rc == TS_OK && fabs(cos(y2[7])) > 1 - 1e-9 &&
              dk <= 1e-10 * sa,
          "chart: rechart moves the one link near the singularity (%d), same "
          "r'' (%.2g)", moved, dk / sa);
    free(n);
    free(nd);
    free(y);
    free(y2);
    free(d1);
    free(d2);
    free(r1);
    free(r2);
    free(m1);
    free(m2);
    ts_kernel_free(k);
    ts_system_free(s);
}

/* ---- errors ------------------------------------------------------------ */

static void test_errors(void)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(1, 0, NULL);
    ts_kernel *k = ts_kernel_alloc(s, &err);
    CHECK(k == NULL && err.code == TS_EINVAL && strstr(err.msg, "built"),
          "kernel of an unbuilt system: TS_EINVAL (%s)", err.msg);
    ts_system_free(s);
    ts_kernel_free(NULL);
}

int main(void)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 20261122);
    test_loads(TS_DRAG_STANDARD);
    test_loads(TS_DRAG_LOADING);
    test_hanging_kernel();
    for (int N = 3; N <= 6; N++)
        test_lagrange(rng, N);
    test_newton_nodes(rng);
    test_energy(rng);
    test_charts(rng);
    test_errors();
    gsl_rng_free(rng);
    return tc_done();
}
