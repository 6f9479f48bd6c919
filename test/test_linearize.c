/* test_linearize.c: the linearizer (towstab/linearize.h) against
 * references that do not use lib/linearize.c.
 *
 *  1. Structure: rows 0..nq-1 of A are exactly [0 I] and of B exactly 0.
 *  2. Threads: A, B and the tension Jacobians from 2 threads equal the
 *     serial ones bit for bit (each column is the same arithmetic).
 *  3. A second method: the directional derivative (f(y + e v) - f(y - e v))
 *     / 2e along a random direction v, Richardson-extrapolated, equals A v;
 *     the actual error of A is below a small multiple of the reported
 *     truncation estimate.
 *  4. Exact input derivatives: for a chain hanging at rest in vacuum, a
 *     tow-point acceleration a_z lowers every tension by a_z times the mass
 *     below the link (dT_k/da_z = -sum of node masses below), tow
 *     displacement and velocity change nothing (dT/dx = dT/dv = 0, B_x =
 *     B_v = 0), and a horizontal tow acceleration a_x gives the angle
 *     accelerations of the pendulum chain: q1'' = -a_x / l for the top link
 *     and 0 for the others (the chain below moves rigidly at first order).
 *  5. Node displacement map: ts_linear_node_displacements against central
 *     differences of the kernel's node positions.
 *  6. Kinks: a tow point at the waterline is reported (kink_tow), a node
 *     exactly at z = 0 is counted (kink_node), a fully submerged system and
 *     any system in vacuum have none.
 *  7. Refusals: an unconverged equilibrium, a bad step, a size mismatch;
 *     input names.
 *  8. The rounding noise (fnoise, round_norm): at a step of 1e-9 the
 *     difference of A to a tight reference is that noise, its size
 *     within a factor 3 of the prediction.
 */
#include "towstab/linearize.h"

#include <gsl/gsl_rng.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"

static ts_units *units;

/* A towed cable with a sphere, in water, straight tow, tow point 0.7 m
 * below the surface (so no node is near the waterline). */
static const char *towed_yaml =
    "name: towed\n"
    "tow: {speed: 2.385, point: [0, 0, 0.7]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: 31.7, diameter: 0.021,\n"
    "     mass_per_length: 0.83, links: 9, normal_drag: 1.2,\n"
    "     tangential_drag: 0.01, added_mass: 1.0}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: 0.3, mass: 41.0, drag: 0.5,\n"
    "     added_mass: 0.5}\n";

static ts_equilibrium *solve(ts_kernel *k, const ts_system *sys)
{
    ts_err err = {0};
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    int rc = ts_equilibrium_solve(k, NULL, eq, &err);
    if (rc)
        printf("equilibrium: %s\n", err.msg);
    return eq;
}

static void test_structure_threads_and_second_method(void)
{
    ts_scene *sc = tscene_parse(units, towed_yaml);
    const ts_system *sys = sc->system;
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = solve(k, sys);
    CHECK(eq->converged, "towed: equilibrium converged");
    ts_linear *l1 = ts_linear_alloc(k, &err), *l2 = ts_linear_alloc(k, &err);
    ts_linearize_opts o;
    ts_linearize_opts_default(&o);
    o.tensions = 1;
    o.threads = 1;
    int rc1 = ts_linearize_equilibrium(k, eq, &o, l1, &err);
    o.threads = 2;
    int rc2 = ts_linearize_equilibrium(k, eq, &o, l2, &err);
    CHECK(rc1 == TS_OK && rc2 == TS_OK, "towed: linearized serially and with "
                                        "2 threads (%s)", err.msg);
    int n = l1->nstate, nq = l1->nq, nl = l1->nlinks;

    /* 1. Exact structure. */
    int exact = 1;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < nq; i++)
            exact &= l1->A[i + (size_t)j * n] == (j == i + nq ? 1.0 : 0.0);
    for (int j = 0; j < TS_NINPUT; j++)
        for (int i = 0; i < nq; i++)
            exact &= l1->B[i + (size_t)j * n] == 0.0;
    CHECK(exact, "upper nq rows: A = [0 I] and B = 0 exactly");

    /* 2. Threads: identical bits. */
    int same = memcmp(l1->A, l2->A, (size_t)n * n * sizeof(double)) == 0 &&
               memcmp(l1->B, l2->B, (size_t)n * TS_NINPUT * sizeof(double)) ==
                   0 &&
               memcmp(l1->Ty, l2->Ty, (size_t)nl * n * sizeof(double)) == 0 &&
               memcmp(l1->Tu, l2->Tu, (size_t)nl * TS_NINPUT * sizeof(double)) ==
                   0;
    CHECK(same, "A, B, dT/dy, dT/du identical with 1 and %d threads",
          l2->threads);
    CHECK(l1->evaluations == 1 + 4L * (n + l1->ninput) + 8 + 1,
          "evaluations: 4 per column, base, 8 for the rounding noise, "
          "restore (%ld)", l1->evaluations);

    /* 3. Second method: Richardson-extrapolated directional derivative.
     * Its error is O(e^4) ~ 1e-12 relative, far below A's own. */
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 2385);
    double *v = malloc((size_t)n * sizeof(double));
    double *y = malloc((size_t)n * sizeof(double));
    double *fp = malloc((size_t)n * sizeof(double));
    double *fm = malloc((size_t)n * sizeof(double));
    double *d1 = malloc((size_t)n * sizeof(double));
    double *d2 = malloc((size_t)n * sizeof(double));
    for (int i = 0; i < n; i++)
        v[i] = gsl_rng_uniform(rng) - 0.5;
    double e = 1e-3;
    for (int pass = 0; pass < 2; pass++) {
        double h = pass ? e / 2 : e;
        double *d = pass ? d2 : d1;
        for (int i = 0; i < n; i++)
            y[i] = l1->y0[i] + h * v[i];
        ts_kernel_eval(k, y, NULL, fp);
        for (int i = 0; i < n; i++)
            y[i] = l1->y0[i] - h * v[i];
        ts_kernel_eval(k, y, NULL, fm);
        for (int i = 0; i < n; i++)
            d[i] = (fp[i] - fm[i]) / (2 * h);
    }
    double worst = 0, scale = 0;
    for (int i = nq; i < n; i++) {
        double ref = (4 * d2[i] - d1[i]) / 3, Av = 0;
        for (int j = 0; j < n; j++)
            Av += l1->A[i + (size_t)j * n] * v[j];
        worst = fmax(worst, fabs(Av - ref));
        scale = fmax(scale, fabs(ref));
    }
    /* |A v - ref| <= ||dA||_F |v|_2 with dA the error of A, estimated by
     * trunc_norm: allow 10x that plus a rounding floor of 1e-9 |A v|. */
    double v2 = 0;
    for (int i = 0; i < n; i++)
        v2 += v[i] * v[i];
    double allow = 10 * l1->trunc_norm * sqrt(v2) + 1e-9 * scale;
    CHECK(worst <= allow, "A v against Richardson directional derivative: "
                          "max diff %.3g <= %.3g (trunc_err %.3g, |Av| %.3g)",
          worst, allow, l1->trunc_err, scale);
    CHECK(l1->trunc_err > 0 && l1->trunc_err < 1e-7 * l1->a_scale,
          "truncation estimate %.3g is positive and below 1e-7 of max |A| "
          "%.3g (h ~ eps^(1/3): error ~ eps^(2/3) relative)",
          l1->trunc_err, l1->a_scale);
    CHECK(l1->kinks == 0 && l1->kink_tow == 0 && l1->kink_node == -1,
          "submerged tow: no kinks");

    /* 5. Node displacements against kernel positions. */
    double *dr = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    double *rp = malloc(3 * (size_t)sys->nnodes * sizeof(double));
    ts_linear_node_displacements(sys, l1, v, dr);
    double hq = 1e-5, dworst = 0;
    for (int i = 0; i < n; i++)
        y[i] = l1->y0[i] + (i < nq ? hq * v[i] : 0);
    ts_kernel_eval(k, y, NULL, fp);
    memcpy(rp, ts_kernel_positions(k), 3 * (size_t)sys->nnodes * sizeof(double));
    for (int i = 0; i < n; i++)
        y[i] = l1->y0[i] - (i < nq ? hq * v[i] : 0);
    ts_kernel_eval(k, y, NULL, fp);
    const double *rm = ts_kernel_positions(k);
    for (int i = 0; i < 3 * sys->nnodes; i++)
        dworst = fmax(dworst, fabs((rp[i] - rm[i]) / (2 * hq) - dr[i]));
    /* Central difference error ~ h^2 L / 6 ~ 5e-10 m per unit dq. */
    CHECK(dworst < 1e-8, "node displacement map vs kernel positions: max "
                         "diff %.3g m < 1e-8", dworst);
    CHECK(dr[0] == 0 && dr[1] == 0 && dr[2] == 0, "tow point does not move");

    free(v);
    free(y);
    free(fp);
    free(fm);
    free(d1);
    free(d2);
    free(dr);
    free(rp);
    gsl_rng_free(rng);
    ts_linear_free(l1);
    ts_linear_free(l2);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

static void test_exact_inputs(void)
{
    ts_scene *sc = tscene_parse(units, 
        "name: chain\n"
        "environment: {water_density: 0, gravity: 9.79}\n"
        "tow: {speed: 0}\n"
        "cables:\n"
        "  - {name: chain, from: tow, length: 7.3, diameter: 0.01,\n"
        "     mass_per_length: 2.385, links: 6}\n");
    const ts_system *sys = sc->system;
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = solve(k, sys);
    ts_linear *lin = ts_linear_alloc(k, &err);
    ts_linearize_opts o;
    ts_linearize_opts_default(&o);
    o.tensions = 1;
    int rc = ts_linearize_equilibrium(k, eq, &o, lin, &err);
    CHECK(rc == TS_OK, "chain: linearized (%s)", err.msg);
    int n = lin->nstate, nq = lin->nq, nl = lin->nlinks;
    /* dT_k/da_z = -(mass of the nodes below link k). Rounding only:
     * tensions ~ 170 N, steps ~ 6e-5 m/s^2: 1e-9 relative. */
    double worst = 0, below = 0;
    for (int l = nl - 1; l >= 0; l--) {
        below += sys->nodes[sys->links[l].lower].mass;
        double got = lin->Tu[l + (size_t)(TS_IN_ACC + 2) * nl];
        worst = fmax(worst, fabs(got + below) / below);
    }
    CHECK(worst < 1e-8, "dT/da_z = -mass below each link: rel err %.3g < "
                        "1e-8", worst);
    double bx = 0, tx = 0;
    for (int c = TS_IN_DISP; c < TS_IN_ACC; c++) {
        for (int i = 0; i < n; i++)
            bx = fmax(bx, fabs(lin->B[i + (size_t)c * n]));
        for (int l = 0; l < nl; l++)
            tx = fmax(tx, fabs(lin->Tu[l + (size_t)c * nl]));
    }
    /* At rest in vacuum nothing depends on where the tow point is or how
     * fast it moves: zero up to rounding of f ~ 1e-9. */
    CHECK(bx < 1e-7 && tx < 1e-6, "B_x = B_v = 0 and dT/dx = dT/dv = 0 "
                                  "(max %.3g, %.3g)", bx, tx);
    /* a_x moves the chain's top link only: theta1 of link 1 is the angle
     * from -x towards +z; a horizontal tow acceleration a swings link 1 by
     * l q1'' cos(...) = ... at the vertical theta1 = pi/2, dn/dt1 = (1,0,0),
     * so the node's relative acceleration -a_x must come from l1 q1'':
     * q1'' = -a_x / l1, others 0. */
    double l1 = sys->links[0].length, qworst = 0;
    for (int i = 0; i < nq; i++) {
        double want = i == 0 ? -1.0 / l1 : 0.0;
        qworst = fmax(qworst, fabs(lin->B[nq + i + (size_t)TS_IN_ACC * n] -
                                   want));
    }
    CHECK(qworst < 1e-8, "dq''/da_x: -1/l on link 1, 0 elsewhere (max diff "
                         "%.3g)", qworst);
    CHECK(lin->kinks == 0, "vacuum: no kinks even with the tow point at z = 0");
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

static void test_kinks(void)
{
    ts_err err = {0};
    /* Tow point at the waterline, straight tow. */
    ts_scene *sc = tscene_parse(units, 
        "name: surface\n"
        "tow: {speed: 1.7}\n"
        "cables:\n"
        "  - {name: c, from: tow, length: 12.3, diameter: 0.02,\n"
        "     mass_per_length: 0.9, links: 5}\n");
    ts_kernel *k = ts_kernel_alloc(sc->system, &err);
    ts_equilibrium *eq = solve(k, sc->system);
    ts_linear *lin = ts_linear_alloc(k, &err);
    int rc = ts_linearize_equilibrium(k, eq, NULL, lin, &err);
    CHECK(rc == TS_OK && lin->kink_tow == 1 && lin->kinks == 1 &&
              lin->kink_node == -1,
          "tow point at z = 0: kink_tow 1, kinks 1, no other node (%d %d %d)",
          lin->kink_tow, lin->kinks, lin->kink_node);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);

    /* A chain hanging at rest from 2 links' length above the water: node 2
     * sits exactly at z = 0. */
    sc = tscene_parse(units, "name: dip\n"
                    "tow: {speed: 0, point: [0, 0, -2.4]}\n"
                    "cables:\n"
                    "  - {name: c, from: tow, length: 6.0, diameter: 0.02,\n"
                    "     mass_per_length: 1.1, links: 5}\n");
    k = ts_kernel_alloc(sc->system, &err);
    eq = solve(k, sc->system);
    lin = ts_linear_alloc(k, &err);
    rc = ts_linearize_equilibrium(k, eq, NULL, lin, &err);
    CHECK(rc == TS_OK && lin->kinks == 1 && lin->kink_node == 2 &&
              !lin->kink_tow,
          "node at the waterline counted: kinks %d, node %d", lin->kinks,
          lin->kink_node);

    /* 7. Refusals. */
    eq->converged = 0;
    eq->residual = 3.5e-4;
    ts_err_clear(&err);
    rc = ts_linearize_equilibrium(k, eq, NULL, lin, &err);
    CHECK(rc == TS_ECONV && strstr(err.msg, "did not converge") &&
              strstr(err.msg, "0.00035"),
          "unconverged equilibrium refused: %s", err.msg);
    ts_linearize_opts o;
    ts_linearize_opts_default(&o);
    o.rel_step = -1;
    ts_err_clear(&err);
    rc = ts_linearize(k, lin->y0, NULL, &o, lin, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "rel_step"),
          "bad rel_step refused: %s", err.msg);
    ts_scene *sc2 = tscene_parse(units, towed_yaml);
    ts_kernel *k2 = ts_kernel_alloc(sc2->system, &err);
    ts_err_clear(&err);
    rc = ts_linearize(k2, lin->y0, NULL, NULL, lin, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "sized"),
          "size mismatch refused: %s", err.msg);
    ts_kernel_free(k2);
    ts_scene_free(sc2);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);

    CHECK(strcmp(ts_input_name(2), "tow.heave") == 0 &&
              strcmp(ts_input_name(0), "tow.surge") == 0 &&
              strcmp(ts_input_name(8), "tow.heave_acceleration") == 0 &&
              strcmp(ts_input_name(TS_IN_ROT + 1), "tow.pitch") == 0 &&
              strcmp(ts_input_name(TS_IN_ROT_VEL + 1),
                     "tow.pitch_velocity") == 0 &&
              strcmp(ts_input_name(TS_IN_ROT_ACC + 2),
                     "tow.yaw_acceleration") == 0 &&
              ts_input_name(TS_NINPUT) == NULL && ts_input_name(-1) == NULL,
          "input names");
}

/* 8. The rounding noise: with a step of 1e-9, where rounding dominates
 * (eps / h against h^2), the lower block of A differs from a tight
 * reference (Richardson-extrapolated central differences at step 1e-3,
 * fourth order, rounding a million times smaller) by noise whose root
 * mean square over the entries is the one predicted from fnoise,
 * sqrt(sum_ij fnoise_i^2 / (2 h_j^2)) (round_norm), within a factor 3
 * (the rms of 2 x 80 x 80 independent draws). */
static void test_rounding_noise(void)
{
    ts_scene *sc = tscene_parse(units, towed_yaml);
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sc->system, &err);
    ts_equilibrium *eq = solve(k, sc->system);
    ts_linear *a = ts_linear_alloc(k, &err), *b = ts_linear_alloc(k, &err);
    ts_linearize_opts o;
    ts_linearize_opts_default(&o);
    o.rel_step = 1e-9;
    int rc = ts_linearize_equilibrium(k, eq, &o, a, &err);
    o.rel_step = 1e-3;
    if (rc == TS_OK)
        rc = ts_linearize_equilibrium(k, eq, &o, b, &err);
    if (!CHECK(rc == TS_OK && a->fnoise && isfinite(a->round_norm),
               "rounding noise estimated (%s)", err.msg)) {
        ts_linear_free(a);
        ts_linear_free(b);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        ts_scene_free(sc);
        return;
    }
    int n = a->nstate, nq = a->nq, nlow = n - nq;
    double d2 = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < nlow; i++) {
            double ref = b->A[nq + i + (size_t)j * n] -
                         b->Aerr[i + (size_t)j * nlow];
            double d = a->A[nq + i + (size_t)j * n] - ref;
            d2 += d * d;
        }
    double ratio = sqrt(d2) / a->round_norm;
    int positive = 1;
    for (int i = 0; i < nlow; i++)
        positive &= a->fnoise[i] > 0;
    CHECK(positive && ratio > 1.0 / 3 && ratio < 3,
          "step 1e-9: ||A - A_tight||_F = %.3g against the predicted "
          "rounding noise %.3g (ratio %.2f, in [1/3, 3]); the truncation "
          "estimate says %.3g", sqrt(d2), a->round_norm, ratio,
          a->trunc_norm);
    ts_linear_free(a);
    ts_linear_free(b);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

int main(void)
{
    units = tscene_units();
    if (!units)
        return 1;
    test_structure_threads_and_second_method();
    test_exact_inputs();
    test_kinks();
    test_rounding_noise();
    ts_units_free(units);
    return tc_done();
}
