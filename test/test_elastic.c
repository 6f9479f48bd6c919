/* test_elastic.c: elastic cables (doc/model.md section 7; doc/elastic.md)
 * against the rigid model, invariants and limits that do not come from the
 * elastic code itself.
 *
 *  1. The same physics: an elastic kernel whose strains are set so that its
 *     tensions equal those of the rigid kernel at the same shape, in a turn
 *     with a current, partly above water, with added mass and bending,
 *     gives the rigid kernel's nodal loads and node accelerations, and no
 *     strain acceleration (the rigid constraint holds).
 *  2. Rigid limit of the equilibrium (Kamman example 1, examples/
 *     kamman_ex1_elastic.yaml and kamman_ex1_submerged.yaml): straight at
 *     20 and 100 links, in a turn, and with the tow point 35 ft above the
 *     water. The elastic shape differs from the rigid one by O(1/EA): at
 *     EA = 1e9 N by ~2e-7 of the cable length (1e-4 is required),
 *     and the log-log slope over EA = 1e6..1e10 is -1. Every elastic link
 *     obeys Hooke, |r_k - r_p| = l (1 + T / EA). Newton started from the
 *     rigid solution's directions agrees with the march.
 *  3. Rigid limit of the modes: the rigid model's lowest modes are found in
 *     the elastic model with relative differences falling like 1/EA; the
 *     elastic model has one more oscillatory (axial) mode per link, the
 *     highest at (1/pi) sqrt(EA / (l m)) cos(pi / (2N + 1)) (the
 *     fixed-free spring-mass chain), so it grows like sqrt(EA).
 *  4. Slack: compressed links carry exactly zero tension and the kernel
 *     stays finite (a wholly slack chain falls freely at g); the clamp
 *     max(0, EA e + Cv l e') holds on random states; a link of zero length
 *     is refused; a neutrally buoyant elastic cable without flow has no
 *     steady state and the solver says so; an elastic link that goes slack
 *     in a march does not stop the solver from finding a steady state that
 *     exists (a soft cable in a tight turn).
 *  5. Rigid and elastic cables in one tree: equilibria converge (march and
 *     Newton, straight and turning), the junction balances the tensions,
 *     its load and its mass (written out here) times the frame
 *     acceleration, elastic links obey Hooke and rigid ones keep their
 *     length.
 *  6. The two-part tow (examples/two_part_tow.yaml): Newton with
 *     continuation in bending stiffness converges, the modes are stable,
 *     the low modes match those of the same tow with rigid cables, and
 *     the axial modes lie at the spring-mass estimate.
 *  7. Bad values of EA, EI, damping and a towfish without volume are
 *     refused by ts_system_build naming the key.
 * Run from the project root (it reads examples/). Tolerances are stated at
 * each check with their reason. */
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"
#include "towstab/scene.h"
#include "towstab/units.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"

#define FT 0.3048

/* ---- helpers ------------------------------------------------------------ */

static double norm3(const double a[3])
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

static int all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* Equilibrium of a built system by method m (guess: link directions for
 * Newton, or NULL). Returns the result (converged or not) and the code. */
static ts_equilibrium *solve(const ts_system *s, ts_eq_method m,
                             const double *guess, int *rc, ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(s, err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, err);
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = m;
    o.guess = guess;
    *rc = k && eq ? ts_equilibrium_solve(k, &o, eq, err) : TS_ENOMEM;
    ts_kernel_free(k);
    return eq;
}

/* Largest node position difference, m. */
static double max_diff(const ts_equilibrium *a, const ts_equilibrium *b)
{
    double d = 0;
    for (int i = 0; i < 3 * a->nnodes; i++)
        d = fmax(d, fabs(a->positions[i] - b->positions[i]));
    return d;
}

static double total_length(const ts_system *s)
{
    double L = 0;
    for (int c = 0; c < s->ncables; c++)
        L += s->cables[c].length;
    return L;
}

/* Least-squares slope of log y against log x. */
static double loglog_slope(const double *x, const double *y, int n)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < n; i++) {
        double a = log(x[i]), b = log(y[i]);
        sx += a;
        sy += b;
        sxx += a * a;
        sxy += a * b;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/* Largest deviation from Hooke's law over the elastic links of an
 * equilibrium, as a strain: | |r_k - r_p| / l - 1 - T / EA |; and the
 * largest relative length error of the rigid links. */
static void hooke(const ts_system *s, const ts_equilibrium *eq,
                  double *elastic_err, double *rigid_err)
{
    *elastic_err = 0;
    *rigid_err = 0;
    for (int l = 0; l < s->nlinks; l++) {
        const ts_link *L = &s->links[l];
        double d[3];
        for (int j = 0; j < 3; j++)
            d[j] = eq->positions[3 * L->lower + j] -
                   eq->positions[3 * L->upper + j];
        double stretch = norm3(d) / L->length - 1.0;
        if (L->elastic)
            *elastic_err = fmax(*elastic_err,
                                fabs(stretch - eq->tensions[l] / L->ea));
        else
            *rigid_err = fmax(*rigid_err, fabs(stretch));
    }
}

/* ---- 1. the same physics as the rigid model ---------------------------- */

static void test_same_physics(const ts_units *u)
{
    ts_scene *sr = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    ts_scene *se = tscene_load(u, "examples/kamman_ex1_elastic.yaml");
    if (!sr || !se) {
        ts_scene_free(sr);
        ts_scene_free(se);
        return;
    }
    ts_system *r = sr->system, *e = se->system;
    /* Tow point 3 m above the water (links cross the surface), a starboard
     * turn, bending on both; the elastic one very stiff so that its
     * stretch (T / EA ~ 3e-11) leaves the shape the rigid one's. */
    const double ea = 1e13;
    ts_system *sys[2] = {r, e};
    for (int i = 0; i < 2; i++) {
        sys[i]->tow.point[2] = -3.0;
        sys[i]->tow.turn_rate = 0.021;
        sys[i]->cables[0].nlinks = 12;
        sys[i]->cables[0].ei = 31.7;
        ts_system_build(sys[i], NULL);
    }
    e->cables[0].ea = ea;
    ts_system_build(e, NULL);
    int nl = r->nlinks, nn = r->nnodes;
    ts_kernel *kr = ts_kernel_alloc(r, NULL), *ke = ts_kernel_alloc(e, NULL);
    ts_equilibrium *eq = ts_equilibrium_alloc(r, NULL);
    ts_err err = {0};
    int rc = ts_equilibrium_solve(kr, NULL, eq, &err);
    CHECK(rc == TS_OK, "same physics: rigid turn above water solves (%s)",
          err.msg);
    /* Moving state: the equilibrium with every angle moved and turning,
     * in a current along x (a turn with a current is not steady, but the
     * kernel's f(y) is defined anywhere). */
    ts_frame f;
    ts_kernel_get_frame(kr, &f);
    f.current[0] = 0.31;
    f.current[1] = -0.12;
    ts_kernel_set_frame(kr, &f);
    ts_kernel_set_frame(ke, &f);
    int nqr = ts_kernel_nq(kr), nqe = ts_kernel_nq(ke);
    double *yr = calloc(2 * (size_t)nqr, sizeof(double));
    double *ye = calloc(2 * (size_t)nqe, sizeof(double));
    double *dr = calloc(2 * (size_t)nqr, sizeof(double));
    double *de = calloc(2 * (size_t)nqe, sizeof(double));
    double *n = calloc(3 * (size_t)nl, sizeof(double));
    double *nd = calloc(3 * (size_t)nl, sizeof(double));
    double *strain = calloc((size_t)nl, sizeof(double));
    memcpy(yr, eq->y, (size_t)nqr * sizeof(double));
    for (int l = 0; l < nl; l++) {
        yr[2 * l] += 0.04 * sin(1.3 * l);
        yr[2 * l + 1] += 0.03 * cos(0.7 * l);
        yr[nqr + 2 * l] = 0.05 * cos(2.1 * l);
        yr[nqr + 2 * l + 1] = -0.04 * sin(1.1 * l);
    }
    const double uin[TS_NINPUT] = {0.1, -0.05, 0.02, 0.3, 0.1, -0.2,
                                   0.4, -0.3, 0.25};
    int rr = ts_kernel_eval(kr, yr, uin, dr);
    const double *tr = ts_kernel_tensions(kr);
    double tmin = INFINITY;
    for (int l = 0; l < nl; l++)
        tmin = fmin(tmin, tr[l]);
    CHECK(rr == TS_OK && tmin > 0, "same physics: rigid state with every "
                                   "tension > 0 (min %.4g N)", tmin);
    /* The elastic state of the same shape and motion, strains T / EA. */
    const double *rd = ts_kernel_velocities(kr);
    memcpy(n, ts_kernel_directions(kr), 3 * (size_t)nl * sizeof(double));
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &r->links[l];
        for (int j = 0; j < 3; j++)
            nd[3 * l + j] = (rd[3 * L->lower + j] - rd[3 * L->upper + j]) /
                            L->length;
        strain[l] = tr[l] / ea;
    }
    ts_kernel_set_shape(ke, n, strain, nd, NULL, TS_CHART_RECHART, ye);
    int re = ts_kernel_eval(ke, ye, uin, de);
    CHECK(re == TS_OK, "same physics: elastic kernel evaluates");
    const double *Qr = ts_kernel_loads(kr), *Qe = ts_kernel_loads(ke);
    const double *ar = ts_kernel_rel_accelerations(kr);
    const double *ae = ts_kernel_rel_accelerations(ke);
    const double *te = ts_kernel_tensions(ke);
    double dq = 0, qs = 0, da = 0, as = 9.81, dt = 0, ts = 0;
    for (int i = 0; i < 3 * nn; i++) {
        dq = fmax(dq, fabs(Qr[i] - Qe[i]));
        qs = fmax(qs, fabs(Qr[i]));
        da = fmax(da, fabs(ar[i] - ae[i]));
        as = fmax(as, fabs(ar[i]));
    }
    for (int l = 0; l < nl; l++) {
        dt = fmax(dt, fabs(tr[l] - te[l]));
        ts = fmax(ts, tr[l]);
    }
    /* The shapes differ by the stretch, 3e-11 of a link: loads (drag,
     * buoyancy, submerged fraction, bending) and accelerations agree to
     * that order; 1e-8 allows the rounding of the elastic strain path. */
    CHECK(dt <= 1e-12 * ts, "same physics: tensions equal (%.2g of %.4g N)",
          dt, ts);
    CHECK(dq <= 1e-8 * qs, "same physics: nodal loads equal (drag, "
                           "buoyancy, partial submersion, bending): %.2g of "
                           "%.4g N", dq, qs);
    CHECK(da <= 1e-8 * as, "same physics: node accelerations equal (mass "
                           "matrices with added mass): %.2g of %.4g m/s^2",
          da, as);
    /* The rigid kernel's accelerations satisfy the length constraint; with
     * the same tensions the elastic strain does not accelerate:
     * e'' ~ a / l ~ 1 1/s^2 scale, rounding ~1e-8 of it. */
    double edd = 0;
    for (int l = 0; l < nl; l++)
        edd = fmax(edd, fabs(de[nqe + ts_kernel_link_offset(ke, l) + 2]));
    CHECK(edd <= 1e-8 * as / e->links[0].length,
          "same physics: strain accelerations vanish (%.2g 1/s^2)", edd);
    free(yr);
    free(ye);
    free(dr);
    free(de);
    free(n);
    free(nd);
    free(strain);
    ts_equilibrium_free(eq);
    ts_kernel_free(kr);
    ts_kernel_free(ke);
    ts_scene_free(sr);
    ts_scene_free(se);
}

/* ---- 2. rigid limit of the equilibrium --------------------------------- */

typedef struct eq_case {
    const char *name;
    int nlinks;
    double turn_rate;  /* rad/s */
    double tow_z;      /* m */
    int tension_moves; /* the top tension depends on the stretch */
} eq_case;

static void set_case(ts_system *s, const eq_case *c, double ea)
{
    s->cables[0].nlinks = c->nlinks;
    s->tow.turn_rate = c->turn_rate;
    s->tow.point[2] = c->tow_z;
    s->cables[0].ea = ea;
    ts_system_build(s, NULL);
}

static void test_rigid_limit(const ts_units *u)
{
    ts_scene *sr = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    ts_scene *se = tscene_load(u, "examples/kamman_ex1_elastic.yaml");
    if (!sr || !se) {
        ts_scene_free(sr);
        ts_scene_free(se);
        return;
    }
    ts_system *r = sr->system, *e = se->system;
    CHECK(e->cables[0].ea == 1e9 && e->cables[0].damping == 4000 &&
          e->links[0].elastic && !r->links[0].elastic,
          "examples: kamman_ex1_elastic has EA 1e9 N and Cv 4000 N s/m");
    double L = r->cables[0].length, V = r->tow.speed;
    const eq_case cases[] = {
        /* Straight and fully submerged, no load depends on the stretch:
         * the elastic shape is the rigid one stretched, same tensions. */
        {"straight, 20 links", 20, 0.0, 0.0, 0},
        {"straight, 100 links", 100, 0.0, 0.0, 0},
        /* A turn of radius 2 L: frame accelerations depend on position. */
        {"turn radius 2 L", 20, V / (2 * L), 0.0, 1},
        /* Tow point 35 ft above the water: the submerged fraction of the
         * links crossing the surface depends on the stretch. */
        {"tow point 35 ft above water", 20, 0.0, -35 * FT, 1},
    };
    static const double eas[] = {1e6, 1e7, 1e8, 1e9, 1e10};
    enum { NEA = 5 };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        const eq_case *cs = &cases[c];
        set_case(r, cs, 0.0);
        int rc;
        ts_err err = {0};
        ts_equilibrium *eqr = solve(r, TS_EQ_AUTO, NULL, &rc, &err);
        CHECK(rc == TS_OK, "%s: rigid equilibrium (%s)", cs->name, err.msg);
        double dpos[NEA], dten[NEA], hooke_worst = 0, rigid_len = 0;
        int ok = rc == TS_OK;
        for (int i = 0; i < NEA; i++) {
            set_case(e, cs, eas[i]);
            ts_equilibrium *eqe = solve(e, TS_EQ_AUTO, NULL, &rc, &err);
            ok &= rc == TS_OK && eqe->converged;
            dpos[i] = max_diff(eqe, eqr) / L;
            dten[i] = fabs(eqe->top_tension - eqr->top_tension) /
                      eqr->top_tension;
            double he, hr;
            hooke(e, eqe, &he, &hr);
            hooke_worst = fmax(hooke_worst, he);
            rigid_len = fmax(rigid_len, hr);
            printf("     %s, EA %.0e N: max |r_el - r_rig| / L = %.4e, top "
                   "tension %.4e relative (%s)\n", cs->name, eas[i], dpos[i],
                   dten[i], ts_eq_method_name(eqe->method));
            if (eas[i] == 1e9) {
                /* The requirement: 1e-4 relative. The stretch is
                 * T / EA ~ 3e-7 at the top, so ~2e-7 is expected. */
                CHECK(dpos[i] < 1e-4 && dpos[i] < 1e-6,
                      "%s: EA 1e9 N within %.3g of the cable length of the "
                      "rigid shape (< 1e-4, and < 1e-6 as the strain "
                      "predicts)", cs->name, dpos[i]);
                /* Newton from the rigid solution's directions (the
                 * solver starts the strains at the rigid tensions over
                 * EA). */
                {
                    ts_equilibrium *eqn = solve(e, TS_EQ_NEWTON,
                                                eqr->directions, &rc, &err);
                    CHECK(rc == TS_OK && eqn->converged &&
                              eqn->continuation_steps == 1,
                          "%s: Newton from the rigid directions converges "
                          "directly (%d iterations, %d continuation steps)",
                          cs->name, eqn->iterations,
                          eqn->continuation_steps);
                    /* Both converged to 1e-10 of the largest force; the
                     * shape follows to that order times the cable's
                     * compliance: 1e-9 of its length is ample. */
                    CHECK(max_diff(eqn, eqe) <= 1e-9 * L,
                          "%s: Newton and the march agree to %.2g m",
                          cs->name, max_diff(eqn, eqe));
                    ts_equilibrium_free(eqn);
                }
            }
            ts_equilibrium_free(eqe);
        }
        CHECK(ok, "%s: every elastic equilibrium converged", cs->name);
        /* The difference is analytic in 1/EA, a/EA + b/EA^2: the second
         * term is the strain (3e-4 at 1e6 N) times the first, so the slope
         * is -1 to ~1e-3; allow 0.02. */
        double sp = loglog_slope(eas, dpos, NEA);
        CHECK(fabs(sp + 1) < 0.02, "%s: shape difference ~ EA^%.4f over "
                                   "1e6..1e10 N (slope -1 +- 0.02)",
              cs->name, sp);
        if (cs->tension_moves) {
            double st = loglog_slope(eas, dten, NEA);
            CHECK(fabs(st + 1) < 0.02, "%s: top tension difference ~ "
                                       "EA^%.4f (slope -1 +- 0.02)",
                  cs->name, st);
        } else {
            /* Straight and submerged: loads do not depend on the stretch,
             * so the tensions are the rigid ones to rounding. */
            double worst = 0;
            for (int i = 0; i < NEA; i++)
                worst = fmax(worst, dten[i]);
            CHECK(worst < 1e-12, "%s: top tension equal to the rigid one "
                                 "(%.2g relative)", cs->name, worst);
        }
        /* Lengths from positions lose ~1e-16 / 1e-3 of a strain of 1e-3:
         * 1e-12 absolute is far above that and far below any strain. */
        CHECK(hooke_worst < 1e-12, "%s: elastic links obey Hooke, "
                                   "|d|/l - 1 = T/EA to %.2g", cs->name,
              hooke_worst);
        ts_equilibrium_free(eqr);
    }
    ts_scene_free(sr);
    ts_scene_free(se);
}

/* ---- 3. rigid limit of the modes --------------------------------------- */

/* Modes of the equilibrium of s (LAPACK, all of them). */
static ts_eigen *all_modes(const ts_system *s, ts_equilibrium **eq_out)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    int rc = ts_equilibrium_solve(k, NULL, eq, &err);
    if (rc == TS_OK)
        lin = ts_linear_alloc(k, &err);
    if (lin) {
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        rc = ts_linearize_equilibrium(k, eq, &lo, lin, &err);
    }
    if (lin && rc == TS_OK) {
        ts_eigen_opts eo;
        ts_eigen_opts_default(&eo);
        eo.method = TS_EIG_LAPACK;
        rc = ts_eigen_solve(lin, &eo, &e, &err);
    }
    if (!e)
        printf("     modes failed: %s\n", err.msg);
    ts_linear_free(lin);
    ts_kernel_free(k);
    if (eq_out)
        *eq_out = eq;
    else
        ts_equilibrium_free(eq);
    return e;
}

/* Largest relative distance from each of the first m modes of `ref` to
 * the nearest eigenvalue of `e`. */
static double match_modes(const ts_eigen *ref, const ts_eigen *e, int m)
{
    double worst = 0;
    for (int i = 0; i < m && i < ref->nmodes; i++) {
        double best = INFINITY;
        for (int j = 0; j < e->nmodes; j++)
            best = fmin(best, hypot(e->modes[j].re - ref->modes[i].re,
                                    e->modes[j].im - ref->modes[i].im));
        worst = fmax(worst, best / hypot(ref->modes[i].re, ref->modes[i].im));
    }
    return worst;
}

static double highest_freq(const ts_eigen *e)
{
    double f = 0;
    for (int j = 0; j < e->nmodes; j++)
        f = fmax(f, e->modes[j].freq_hz);
    return f;
}

static int oscillatory(const ts_eigen *e)
{
    int n = 0;
    for (int j = 0; j < e->nmodes; j++)
        n += e->modes[j].im > 0;
    return n;
}

static void test_modes(const ts_units *u)
{
    ts_scene *sr = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    ts_scene *se = tscene_load(u, "examples/kamman_ex1_elastic.yaml");
    if (!sr || !se) {
        ts_scene_free(sr);
        ts_scene_free(se);
        return;
    }
    ts_system *r = sr->system, *e = se->system;
    /* The rigid model at the elastic example's links, so that the low
     * modes are those of the same discretisation. */
    ts_system_set_links(r, e->cables[0].nlinks, NULL);
    ts_eigen *er = all_modes(r, NULL);
    if (!CHECK(er != NULL, "modes: rigid example 1")) {
        ts_scene_free(sr);
        ts_scene_free(se);
        return;
    }
    /* Without internal damping: with the example's Cv the axial modes are
     * overdamped below EA ~ 1e7 N (Cv > sqrt(EA m / l)), and their
     * frequencies would not show the sqrt(EA) law. */
    e->cables[0].damping = 0;
    static const double eas[] = {1e5, 1e6, 1e7, 1e8, 1e9, 1e10};
    enum { NEA = 6, NLOW = 10 };
    double diff[NEA], fhi[NEA];
    int ok = 1, extra_ok = 1, stable = 1;
    const int N = e->cables[0].nlinks;
    const double l = e->links[0].length, m = e->links[0].mass;
    for (int i = 0; i < NEA; i++) {
        e->cables[0].ea = eas[i];
        ts_system_build(e, NULL);
        ts_eigen *ee = all_modes(e, NULL);
        if (!ee) {
            ok = 0;
            continue;
        }
        diff[i] = match_modes(er, ee, NLOW);
        fhi[i] = highest_freq(ee);
        /* The fixed-free chain of N equal masses m and springs EA / l:
         * omega_max = 2 sqrt(EA / (l m)) cos(pi / (2N + 1)). */
        double chain = sqrt(eas[i] / (l * m)) * cos(M_PI / (2 * N + 1)) /
                       M_PI;
        printf("     EA %.0e N: %d modes (%d oscillatory; rigid %d, %d); "
               "lowest %d within %.3e; highest %.6g Hz, chain estimate "
               "%.6g Hz\n", eas[i], ee->nmodes, oscillatory(ee),
               er->nmodes, oscillatory(er), NLOW, diff[i], fhi[i], chain);
        /* Every link adds one oscillatory axial mode. */
        extra_ok &= oscillatory(ee) == oscillatory(er) + N;
        stable &= ee->verdict == TS_STABLE;
        /* The end node (half a link and the sphere) and the coupling to
         * the angles move the top of the spectrum by 2e-4: allow 1e-3. */
        CHECK(fabs(fhi[i] / chain - 1) < 1e-3,
              "modes EA %.0e N: highest frequency %.6g Hz within 0.1 %% of "
              "the spring-mass chain's %.6g Hz", eas[i], fhi[i], chain);
        ts_eigen_free(ee);
    }
    CHECK(ok, "modes: every elastic case linearized and solved");
    CHECK(extra_ok, "modes: each of the %d links adds one oscillatory "
                    "(axial) mode", N);
    CHECK(stable, "modes: every elastic case is stable");
    /* The expected order of magnitude at 1e9 N: ~1e-6 (1/EA from 1.4e-3 at
     * 1e6 N). The linearization's own error (~1e-8 relative here) is far
     * below. */
    CHECK(diff[4] < 1e-5, "modes: at EA 1e9 N the %d lowest rigid modes are "
                          "matched to %.3g (< 1e-5)", NLOW, diff[4]);
    double sp = loglog_slope(eas + 1, diff + 1, NEA - 1);
    CHECK(fabs(sp + 1) < 0.03, "modes: low-mode difference ~ EA^%.4f over "
                               "1e6..1e10 N (slope -1 +- 0.03: the "
                               "linearization error enters at 1e10)", sp);
    double sf = loglog_slope(eas, fhi, NEA);
    CHECK(fabs(sf - 0.5) < 1e-3, "modes: highest frequency ~ EA^%.5f (0.5 "
                                 "+- 1e-3: the axial chain alone)", sf);
    ts_eigen_free(er);
    ts_scene_free(sr);
    ts_scene_free(se);
}

/* ---- 4. slack ------------------------------------------------------------ */

/* A chain in vacuum: 5 elastic links (EA 3e4 N, Cv 120 N s/m) to a sphere,
 * no flow. */
static ts_system *vacuum_chain(void)
{
    ts_system *s = ts_system_alloc(1, 1, NULL);
    if (!s)
        return NULL;
    s->env.water_density = 0.0;
    s->env.gravity = 9.80665;
    s->tow.point[2] = 1.7;
    ts_cable *c = &s->cables[0];
    snprintf(c->name, sizeof c->name, "chain");
    c->from_body = -1;
    c->to_body = 0;
    c->length = 3.1;
    c->diameter = 0.012;
    c->mass_per_length = 0.7;
    c->nlinks = 5;
    c->cdn = 1.2;
    c->ea = 3e4;
    c->damping = 120;
    ts_body *b = &s->bodies[0];
    snprintf(b->name, sizeof b->name, "ball");
    b->type = TS_BODY_SPHERE;
    b->diameter = 0.1;
    b->mass = 1.3;
    if (ts_system_build(s, NULL) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

static void test_slack(const ts_units *u)
{
    ts_system *s = vacuum_chain();
    if (!CHECK(s != NULL, "slack: vacuum chain builds"))
        return;
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    int nl = s->nlinks, nn = s->nnodes, nq = ts_kernel_nq(k), ns = 2 * nq;
    double *y = calloc((size_t)ns, sizeof(double));
    double *d = calloc((size_t)ns, sizeof(double));
    const double g = s->env.gravity;

    /* (a) Every link shorter than its rest length and shortening: the
     * chain is a set of free particles, each falling at g. */
    for (int l = 0; l < nl; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o] = 0.4 + 0.5 * l;
        y[o + 1] = 0.3 * sin(1.7 * l);
        y[o + 2] = -0.02 - 0.03 * l;
        y[nq + o] = 0.8 * cos(l);
        y[nq + o + 1] = -0.6 * sin(2.0 * l);
        y[nq + o + 2] = -0.1 * l;
    }
    int rc = ts_kernel_eval(k, y, NULL, d);
    const double *t = ts_kernel_tensions(k);
    const double *a = ts_kernel_rel_accelerations(k);
    double tmax = 0, afall = 0;
    for (int l = 0; l < nl; l++)
        tmax = fmax(tmax, fabs(t[l]));
    for (int i = 1; i < nn; i++)
        afall = fmax(afall, fabs(a[3 * i]) + fabs(a[3 * i + 1]) +
                                fabs(a[3 * i + 2] - g));
    CHECK(rc == TS_OK && all_finite(d, ns), "slack: a wholly compressed "
                                            "chain evaluates, finite");
    CHECK(tmax == 0, "slack: every compressed link carries exactly 0 N");
    /* Free fall: the nodes' accelerations are g e_z to rounding. */
    CHECK(afall <= 1e-12 * g, "slack: every node falls freely at g (off by "
                              "%.2g m/s^2)", afall);

    /* (b) The upper two links compressed (the tow point moved toward the
     * ball), the lower three stretched and at rest in length: zero and
     * EA e. */
    for (int l = 0; l < nl; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o + 2] = l < 2 ? -0.2 : 0.004 + 0.001 * l;
        y[nq + o + 2] = 0.0;
    }
    rc = ts_kernel_eval(k, y, NULL, d);
    t = ts_kernel_tensions(k);
    double terr = 0;
    for (int l = 0; l < nl; l++) {
        double want = l < 2 ? 0.0 : 3e4 * (0.004 + 0.001 * l);
        terr = fmax(terr, fabs(t[l] - want));
    }
    CHECK(rc == TS_OK && all_finite(d, ns) && terr <= 1e-12,
          "slack: upper links slack (0 N), lower ones EA e (error %.2g N), "
          "finite", terr);

    /* (c) The clamp on random states: T = max(0, EA e + Cv l e'), never
     * negative; with damping a link just short of its rest length that is
     * being stretched fast already pulls (the price of a tension that is
     * continuous in the state). */
    unsigned seed = 12345u;
    double clamp_err = 0, tmin = INFINITY;
    int pulled_short = 0;
    for (int trial = 0; trial < 200; trial++) {
        for (int i = 0; i < ns; i++) {
            seed = seed * 1103515245u + 12345u;
            double r01 = (seed >> 8) / 16777216.0;
            y[i] = i < nq ? 2.0 * r01 - 0.5 : 4.0 * r01 - 2.0;
        }
        for (int l = 0; l < nl; l++) {
            int o = ts_kernel_link_offset(k, l);
            y[o + 2] = 0.04 * (y[o + 2] - 0.75);       /* -0.05 .. 0.03 */
            y[nq + o + 2] *= 0.2;                        /* -0.4 .. 0.4 1/s */
        }
        if (ts_kernel_eval(k, y, NULL, d) != TS_OK || !all_finite(d, ns)) {
            clamp_err = INFINITY;
            break;
        }
        t = ts_kernel_tensions(k);
        for (int l = 0; l < nl; l++) {
            int o = ts_kernel_link_offset(k, l);
            double e = y[o + 2], ed = y[nq + o + 2];
            double want = fmax(0.0, 3e4 * e + 120 * s->links[l].length * ed);
            clamp_err = fmax(clamp_err, fabs(t[l] - want));
            tmin = fmin(tmin, t[l]);
            pulled_short += e < 0 && t[l] > 0;
        }
    }
    CHECK(clamp_err <= 1e-12 && tmin >= 0,
          "slack: 200 random states: T = max(0, EA e + Cv l e') to %.2g N, "
          "never negative (min %.3g N), finite; %d short links pulled by "
          "damping", clamp_err, tmin, pulled_short);

    /* (d) A link of zero length has no direction: refused, NaN out. */
    y[ts_kernel_link_offset(k, 2) + 2] = -1.0;
    rc = ts_kernel_eval(k, y, NULL, d);
    CHECK(rc == TS_ESINGULAR && isnan(d[0]), "slack: a link of zero length "
                                             "(e = -1) gives TS_ESINGULAR "
                                             "and NaN");
    free(y);
    free(d);
    ts_kernel_free(k);

    /* (e) Towed in water: the equilibrium of the elastic example with
     * every link vector 0.7 of its rest length (the tow point moved 30 %
     * of the way toward the sphere). */
    ts_scene *se = tscene_load(u, "examples/kamman_ex1_elastic.yaml");
    if (se) {
        ts_system *e = se->system;
        ts_kernel *ke = ts_kernel_alloc(e, NULL);
        ts_equilibrium *eq = ts_equilibrium_alloc(e, NULL);
        ts_equilibrium_solve(ke, NULL, eq, NULL);
        int nqe = ts_kernel_nq(ke);
        double *ye = calloc(2 * (size_t)nqe, sizeof(double));
        double *de = calloc(2 * (size_t)nqe, sizeof(double));
        double *strain = calloc((size_t)e->nlinks, sizeof(double));
        for (int l = 0; l < e->nlinks; l++)
            strain[l] = -0.3;
        ts_kernel_set_shape(ke, eq->directions, strain, NULL, NULL,
                            TS_CHART_RECHART, ye);
        rc = ts_kernel_eval(ke, ye, NULL, de);
        double tm = 0;
        for (int l = 0; l < e->nlinks; l++)
            tm = fmax(tm, fabs(ts_kernel_tensions(ke)[l]));
        double scale, unb = ts_kernel_unbalanced(ke, &scale);
        CHECK(rc == TS_OK && all_finite(de, 2 * nqe) && tm == 0 &&
                  isfinite(unb),
              "slack: towed example 1 with its links at 0.7 of their "
              "length: finite, every tension 0 N, unbalanced %.4g N", unb);
        free(ye);
        free(de);
        free(strain);
        ts_equilibrium_free(eq);
        ts_kernel_free(ke);
        ts_scene_free(se);
    }

    /* (f) No steady state: a neutrally buoyant elastic cable without flow
     * has no load to align with; the solver says so, naming the cable. */
    ts_err err = {0};
    double rho = 1025.0, dc = s->cables[0].diameter, db = s->bodies[0].diameter;
    s->env.water_density = rho;
    s->cables[0].mass_per_length = rho * M_PI * 0.25 * dc * dc;
    s->bodies[0].mass = rho * M_PI * db * db * db / 6.0;
    s->tow.speed = 0.0;
    CHECK(ts_system_build(s, &err) == TS_OK, "slack: neutral chain builds");
    ts_equilibrium *eqn = solve(s, TS_EQ_AUTO, NULL, &rc, &err);
    CHECK(rc == TS_ESINGULAR && !eqn->converged &&
              strstr(err.msg, "cables[0] 'chain'") &&
              strstr(err.msg, "no steady shape"),
          "slack: weightless cable without flow: TS_ESINGULAR, '%s'",
          err.msg);
    ts_equilibrium_free(eqn);
    ts_system_free(s);

    /* (g) A soft cable (EA 1000 N: 40 % stretch) in a tight turn: marching
     * the turn in one step makes an elastic link go slack on the way (the
     * local root's other branch), which must not end the solve: a steady
     * state exists (Newton finds it directly) and auto must find it too. */
    ts_scene *sr = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    if (sr) {
        ts_system *r = sr->system;
        r->cables[0].nlinks = 10;
        r->cables[0].ea = 1000;
        r->tow.speed = 0.5;
        r->tow.turn_rate = 0.5;
        ts_system_build(r, NULL);
        ts_err e1 = {0}, e2 = {0};
        int rc1, rc2;
        ts_equilibrium *a1 = solve(r, TS_EQ_AUTO, NULL, &rc1, &e1);
        ts_equilibrium *a2 = solve(r, TS_EQ_NEWTON, NULL, &rc2, &e2);
        CHECK(rc2 == TS_OK && a2->converged,
              "slack: soft cable in a turn, Newton converges (top tension "
              "%.6g N) %s", a2->top_tension, e2.msg);
        CHECK(rc1 == TS_OK && a1->converged,
              "slack: soft cable in a turn, auto converges too (%s) %s",
              ts_eq_method_name(a1->method), e1.msg);
        if (rc1 == TS_OK && rc2 == TS_OK)
            CHECK(max_diff(a1, a2) <= 1e-9 * total_length(r) *
                                          (1 + a2->top_tension / 1000),
                  "slack: auto and Newton agree (%.2g m)", max_diff(a1, a2));
        ts_equilibrium_free(a1);
        ts_equilibrium_free(a2);
        ts_scene_free(sr);
    }
}

/* ---- 5. rigid and elastic cables in one tree -------------------------- */

/* Lead cable elastic (EA 3.1e5 N, Cv 50) to a junction with mass; an
 * upper branch rigid to a sphere; a lower branch elastic (EA 8.7e4 N) to a
 * sphere. In water, towed at 1.37 m/s. */
static ts_system *mixed_tree(double turn)
{
    ts_system *s = ts_system_alloc(3, 3, NULL);
    if (!s)
        return NULL;
    s->env.water_density = 1025.0;
    s->env.gravity = 9.80665;
    s->tow.speed = 1.37;
    s->tow.turn_rate = turn;
    s->tow.point[2] = 0.4;
    static const struct {
        const char *name;
        int from, to, n;
        double length, d, mpl, ea, cv;
    } cd[3] = {{"lead", -1, 0, 6, 7.3, 0.017, 0.61, 3.1e5, 50},
               {"upper", 0, 1, 4, 2.9, 0.011, 0.29, 0, 0},
               {"lower", 0, 2, 5, 3.7, 0.013, 0.38, 8.7e4, 0}};
    for (int i = 0; i < 3; i++) {
        ts_cable *c = &s->cables[i];
        snprintf(c->name, sizeof c->name, "%s", cd[i].name);
        c->from_body = cd[i].from;
        c->to_body = cd[i].to;
        c->length = cd[i].length;
        c->diameter = cd[i].d;
        c->mass_per_length = cd[i].mpl;
        c->nlinks = cd[i].n;
        c->cdn = 1.3;
        c->cdt = 0.012;
        c->can = 0.9;
        c->ea = cd[i].ea;
        c->damping = cd[i].cv;
    }
    static const struct {
        const char *name;
        ts_body_type type;
        double D, m;
    } bd[3] = {{"junction", TS_BODY_JUNCTION, 0, 1.9},
               {"float", TS_BODY_SPHERE, 0.14, 3.1},
               {"weight", TS_BODY_SPHERE, 0.12, 6.3}};
    for (int b = 0; b < 3; b++) {
        ts_body *o = &s->bodies[b];
        snprintf(o->name, sizeof o->name, "%s", bd[b].name);
        o->type = bd[b].type;
        o->diameter = bd[b].D;
        o->mass = bd[b].m;
        o->cd = 0.5;
        o->ca = 0.5;
    }
    if (ts_system_build(s, NULL) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* Force balance at node j of an equilibrium: the link above pulls -t n,
 * each child +t n, plus the node's external load (kernel loads at the
 * equilibrium state), equal to M_j times the frame acceleration of a point
 * at rest in the turning frame, afr = (-W^2 x, W V - W^2 y, 0), with M_j
 * written out here: the junction's mass, half of each adjacent link's, and
 * half of each adjacent link's normal added mass Can rho (pi d^2/4) l
 * (I - n n^T) (every link submerged). Returns |sum - M_j afr| and the
 * largest term. */
static double junction_balance(const ts_system *s, const ts_equilibrium *eq,
                               int j, double *scale)
{
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    double *d = calloc((size_t)eq->nstate, sizeof(double));
    /* eq->y is in the charts of the solver's kernel: rebuild the state in
     * this kernel's from the directions and the strains T / EA. */
    double *strain = calloc((size_t)s->nlinks, sizeof(double));
    double *y = calloc((size_t)eq->nstate, sizeof(double));
    for (int l = 0; l < s->nlinks; l++)
        strain[l] = s->links[l].elastic ? eq->tensions[l] / s->links[l].ea
                                        : 0.0;
    ts_kernel_set_shape(k, eq->directions, strain, NULL, NULL,
                        TS_CHART_RECHART, y);
    ts_kernel_eval(k, y, NULL, d);
    const double *Q = ts_kernel_loads(k);
    double F[3] = {Q[3 * j], Q[3 * j + 1], Q[3 * j + 2]};
    double big = norm3(F);
    const ts_node *nd = &s->nodes[j];
    const double *r = eq->positions + 3 * j, W = s->tow.turn_rate;
    const double afr[3] = {-W * W * r[0], W * s->tow.speed - W * W * r[1],
                           0.0};
    double Ma[3], mass = s->bodies[nd->body].mass;
    int adj[8], na = 0;
    adj[na++] = nd->link;
    for (int i = nd->child_begin; i < nd->child_end && na < 8; i++)
        adj[na++] = s->child_links[i];
    for (int i = 0; i < na; i++)
        mass += 0.5 * s->links[adj[i]].mass;
    for (int c = 0; c < 3; c++)
        Ma[c] = mass * afr[c];
    for (int i = 0; i < na; i++) {
        const ts_link *L = &s->links[adj[i]];
        const double *n = eq->directions + 3 * adj[i];
        double A = 0.5 * L->can * s->env.water_density * M_PI * 0.25 *
                   L->diameter * L->diameter * L->length;
        double an = n[0] * afr[0] + n[1] * afr[1] + n[2] * afr[2];
        for (int c = 0; c < 3; c++)
            Ma[c] += A * (afr[c] - an * n[c]);
    }
    int up = nd->link;
    for (int c = 0; c < 3; c++)
        F[c] -= eq->tensions[up] * eq->directions[3 * up + c] + Ma[c];
    big = fmax(big, fabs(eq->tensions[up]));
    for (int i = nd->child_begin; i < nd->child_end; i++) {
        int l = s->child_links[i];
        for (int c = 0; c < 3; c++)
            F[c] += eq->tensions[l] * eq->directions[3 * l + c];
        big = fmax(big, fabs(eq->tensions[l]));
    }
    free(d);
    free(y);
    free(strain);
    ts_kernel_free(k);
    *scale = big;
    return norm3(F);
}

static void test_mixed(void)
{
    for (int turning = 0; turning < 2; turning++) {
        ts_system *s = mixed_tree(turning ? 0.047 : 0.0);
        if (!CHECK(s && s->has_elastic && !s->links[6].elastic,
                   "mixed: tree of elastic and rigid cables builds"))
            continue;
        const char *what = turning ? "turn 0.047 rad/s" : "straight";
        int rc1, rc2;
        ts_err e1 = {0}, e2 = {0};
        ts_equilibrium *a = solve(s, TS_EQ_AUTO, NULL, &rc1, &e1);
        ts_equilibrium *b = solve(s, TS_EQ_NEWTON, NULL, &rc2, &e2);
        CHECK(rc1 == TS_OK && a->converged, "mixed %s: auto (%s) converges, "
                                            "residual %.2g %s", what,
              ts_eq_method_name(a->method), a->residual, e1.msg);
        CHECK(rc2 == TS_OK && b->converged, "mixed %s: Newton converges, "
                                            "residual %.2g %s", what,
              b->residual, e2.msg);
        /* Both to 1e-10 of the largest force; the softest cable (EA 8.7e4
         * N) turns that into ~1e-10 of its length: 1e-8 m is ample. */
        CHECK(max_diff(a, b) < 1e-8, "mixed %s: march and Newton agree to "
                                     "%.2g m", what, max_diff(a, b));
        double he, hr;
        hooke(s, a, &he, &hr);
        CHECK(he < 1e-12 && hr < 1e-13,
              "mixed %s: elastic links obey Hooke (%.2g), rigid ones keep "
              "their length (%.2g)", what, he, hr);
        {
            /* The junction: the three tensions and its load balance its
             * mass times the frame acceleration (zero when straight). The
             * equilibrium's residual is 1e-10 of the largest force. */
            int j = ts_system_body_node(s, 0), m;
            double scale, res = junction_balance(s, a, j, &scale);
            m = s->nodes[j].child_end - s->nodes[j].child_begin;
            CHECK(m == 2 && res <= 1e-9 * scale,
                  "mixed %s: the junction balances its tensions, load and "
                  "inertia to %.2g N of %.4g N", what, res, scale);
        }
        ts_equilibrium_free(a);
        ts_equilibrium_free(b);
        ts_system_free(s);
    }
}

/* ---- 6. the two-part tow ----------------------------------------------- */

static void test_two_part(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/two_part_tow.yaml");
    if (!sc)
        return;
    ts_system *s = sc->system;
    CHECK(s->has_bending && s->has_elastic,
          "two-part: elastic cables with bending");
    ts_equilibrium *eq;
    ts_eigen *e = all_modes(s, &eq);
    CHECK(eq->converged && eq->method == TS_EQ_NEWTON &&
              eq->residual <= 1e-10 && eq->continuation_steps > 2,
          "two-part: Newton with continuation converges (residual %.2g, %d "
          "continuation steps)", eq->residual, eq->continuation_steps);
    /* The same tow with rigid cables (bending kept). */
    ts_system *r = ts_system_copy(s, NULL);
    for (int c = 0; c < r->ncables; c++) {
        r->cables[c].ea = 0;
        r->cables[c].damping = 0;
    }
    ts_system_build(r, NULL);
    ts_equilibrium *eqr;
    ts_eigen *er = all_modes(r, &eqr);
    if (e && er) {
        CHECK(e->verdict == TS_STABLE && e->max_real < 0,
              "two-part: stable (max Re lambda %.4g 1/s, error %.2g)",
              e->max_real, e->max_real_error);
        /* The strains are ~1e-5: shapes agree to that times the length. */
        double dp = max_diff(eq, eqr);
        CHECK(dp < 1e-4, "two-part: the elastic shape is the rigid one to "
                         "%.3g m (strain ~1e-5 of 4.6 m of cable)", dp);
        /* Low modes: differences ~1e-5 times eigenvalue sensitivities; the
         * worst (a real mode at -19.5 1/s) is 1.4e-3, and falls like 1/EA
         * (1.4e-4 with EA ten times larger). */
        double dm = match_modes(er, e, 12);
        CHECK(dm < 5e-3, "two-part: the 12 lowest rigid modes are in the "
                         "elastic spectrum to %.3g relative (< 5e-3)", dm);
        CHECK(oscillatory(e) == oscillatory(er) + s->nlinks,
              "two-part: %d oscillatory modes = rigid %d + one axial per "
              "link (%d)", oscillatory(e), oscillatory(er), s->nlinks);
        /* Axial: the shortest and lightest links (depressor cable, 0.1 m,
         * 0.063 kg/m) are the fastest chain, (1/pi) sqrt(EA / (l m)) at
         * most (26.9 kHz); damping (9 % of critical there) and the heavy
         * ends lower it (observed 0.87 of it). */
        double fmax_est = 0;
        for (int c = 0; c < s->ncables; c++) {
            const ts_cable *cb = &s->cables[c];
            double l = cb->length / cb->nlinks;
            fmax_est = fmax(fmax_est, sqrt(cb->ea / (l * l *
                                                     cb->mass_per_length)) /
                                          M_PI);
        }
        double fh = highest_freq(e);
        CHECK(fh > 0.7 * fmax_est && fh < fmax_est,
              "two-part: highest (axial) frequency %.5g Hz within [0.7, 1] "
              "of the fastest link chain's %.5g Hz", fh, fmax_est);
    }
    ts_eigen_free(e);
    ts_eigen_free(er);
    ts_equilibrium_free(eq);
    ts_equilibrium_free(eqr);
    ts_system_free(r);
    ts_scene_free(sc);
}

/* ---- 7. bad values ------------------------------------------------------ */

static void bad_value(const char *what, void (*spoil)(ts_system *),
                      const char *key)
{
    ts_system *s = vacuum_chain();
    if (!s)
        return;
    spoil(s);
    ts_err err = {0};
    int rc = ts_system_build(s, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, key),
          "bad value: %s refused naming '%s': %s", what, key, err.msg);
    ts_system_free(s);
}

static void neg_ea(ts_system *s) { s->cables[0].ea = -4.5e6; }
static void neg_ei(ts_system *s) { s->cables[0].ei = -9.1; }
static void neg_cv(ts_system *s) { s->cables[0].damping = -50; }
static void nan_ea(ts_system *s) { s->cables[0].ea = NAN; }
static void rigid_cv(ts_system *s)
{
    s->cables[0].ea = 0;
    s->cables[0].damping = 50;
}
static void no_volume(ts_system *s)
{
    s->bodies[0].type = TS_BODY_CYLINDER;
    s->bodies[0].diameter = 0.11;
    s->bodies[0].length = 0.0;
}

static void test_bad_values(void)
{
    bad_value("EA < 0", neg_ea, "cables[0].EA");
    bad_value("EA NaN", nan_ea, "cables[0].EA");
    bad_value("EI < 0", neg_ei, "cables[0].EI");
    bad_value("damping < 0", neg_cv, "cables[0].damping");
    bad_value("damping without EA", rigid_cv, "cables[0].damping");
    bad_value("towfish without volume", no_volume, "bodies[0]");
}

int main(void)
{
    ts_units *u = ts_units_alloc(NULL);
    if (!CHECK(u != NULL, "units"))
        return tc_done();
    test_same_physics(u);
    test_rigid_limit(u);
    test_modes(u);
    test_slack(u);
    test_mixed();
    test_two_part(u);
    test_bad_values();
    ts_units_free(u);
    return tc_done();
}
