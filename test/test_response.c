/* test_response.c: frequency response (towstab/response.h) against
 * independent references.
 *
 *  1. Static gain, heave: Kamman's example 1 with the tow point 35 ft above
 *     the water (the cable pierces the surface, so heaving the tow point
 *     changes the wetted length and the shape: the gain is not 1). The
 *     zero-frequency limit and the response at 1e-6 Hz must equal the
 *     static gain from re-solving the equilibrium with the tow point
 *     displaced by +-1 mm (central difference, error ~1e-8) to 1e-5, for
 *     the sphere's depth and the top link's tension. No node is within
 *     0.1 m of the waterline (checked), far from the kink.
 *  2. Static gain, surge in a turn (Kamman ex. 3, 0.5 rad/s): moving the
 *     tow point forward changes its radius, so the sphere moves sideways;
 *     the same comparison for sphere.y. The frame inputs tow.speed and
 *     tow.turn_rate, straight and in the turn: their static gains against
 *     the equilibrium re-solved at V +- dV, Omega +- dOmega (1e-5).
 *  3. Resonance: for a chain hanging in vacuum, tow.surge -> bottom node x
 *     has a local maximum of |G| on a fine grid next to each of its three
 *     lowest in-plane natural frequencies (from the eigen solver), none
 *     elsewhere, and |G| > 1e3 at 1e-6 off each of them.
 *  4. Names and ranges: inputs, outputs (aliases, tow refused, valid names
 *     listed), log spacing refused for empty or negative ranges, tension
 *     outputs need the tension Jacobians.
 *  5. The gain's error allowance (ts_response.error, static_error)
 *     covers the linearization's rounding: Kamman ex. 3 in the turn at 10
 *     links, surge and sway, three outputs (one a tension), the static gain
 *     and 5 frequencies, at the default step and at steps 1e-7 and 1e-8
 *     where rounding dominates: every gain within its allowance of that
 *     of a tight, fourth-order linearization, for the dense model and
 *     the sparse one (test_rounding).
 *  6. The same with a vehicle, dense and sparse: controller states, the
 *     vehicle's own inputs and outputs, a tension output
 *     (test_vehicle_allowance).
 */
#include "towstab/response.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lapack.h"
#include "response_impl.h"
#include "tcheck.h"
#include "tscene.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"

static ts_units *units;

static const char *above_yaml =
    "name: ex1_above\n"
    "environment: {water_density: \"1.9905 slug/ft^3\", gravity: \"32.174 "
    "ft/s^2\"}\n"
    "tow: {speed: \"8.345 ft/s\", point: [0, 0, \"-35 ft\"]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: \"100 ft\",\n"
    "     diameter: \"1 in\", weight: \"1 lbf/ft\", links: 20,\n"
    "     normal_drag: 1.2, tangential_drag: 0.01, added_mass: 1.0}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: \"10 in\", weight: \"50 lbf\",\n"
    "     drag: 0.5, added_mass: 0.5}\n";

static const char *turn_yaml =
    "name: ex3_turn\n"
    "environment: {water_density: \"1.9905 slug/ft^3\", gravity: \"32.174 "
    "ft/s^2\"}\n"
    "tow: {speed: \"2.5 ft/s\", turn_rate: \"0.5 rad/s\"}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: \"6 ft\",\n"
    "     diameter: \"0.163 in\", weight: \"0.008979 lbf/ft\", links: 20}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: \"2 in\", weight: \"0.246 "
    "lbf\"}\n";

/* Equilibrium output value with the scene value *value (of sys) changed
 * by d, then restored. */
static double resolved_with(ts_system *sys, double *value, double d,
                            const ts_output *out, int *ok)
{
    ts_err err = {0};
    double p0 = *value;
    *value = p0 + d;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.tol = 1e-12;
    int rc = ts_equilibrium_solve(k, &o, eq, &err);
    if (rc != TS_OK) {
        printf("  re-solved equilibrium: %s\n", err.msg);
        *ok = 0;
    }
    double v = out->kind == TS_OUT_POSITION
                   ? eq->positions[3 * out->node + out->comp]
                   : eq->tensions[out->link];
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    *value = p0;
    return v;
}


static ts_linear *linearize_at(const ts_system *sys, ts_lin_model model,
                               double step, int frame, double *zmin);

static ts_linear *linearize(const ts_system *sys, ts_lin_model model,
                            double *zmin)
{
    return linearize_at(sys, model, 0.0, 1, zmin);
}

/* Linearized with relative step `step` (0: the default), the sparse
 * model's frame columns when `frame`. */
static ts_linear *linearize_at(const ts_system *sys, ts_lin_model model,
                               double step, int frame, double *zmin)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_linear *lin = NULL;
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    eo.tol = 1e-12;
    if (ts_equilibrium_solve(k, &eo, eq, &err) == TS_OK) {
        ts_linearize_opts o;
        ts_linearize_opts_default(&o);
        o.tensions = 1;
        o.model = model;
        o.frame_inputs = frame;
        if (step > 0)
            o.rel_step = step;
        lin = ts_linear_alloc(k, &err);
        if (ts_linearize_equilibrium(k, eq, &o, lin, &err) != TS_OK) {
            ts_linear_free(lin);
            lin = NULL;
        }
    }
    if (!lin)
        printf("linearize: %s\n", err.msg);
    if (zmin) {
        *zmin = INFINITY;
        for (int i = 0; i < sys->nnodes; i++)
            *zmin = fmin(*zmin, fabs(eq->positions[3 * i + 2]));
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return lin;
}

/* The static gain of input `in` to out at w = 0 and at 1e-6 Hz against
 * the central difference of the equilibria re-solved with the scene value
 * *value changed by +-d; returns that difference. */
static double static_check(ts_system *sys, ts_linear *lin, int in,
                           const ts_output *out, double *value, double d,
                           const char *in_name, const char *out_name)
{
    ts_err err = {0};
    int ok = 1;
    double ref = (resolved_with(sys, value, d, out, &ok) -
                  resolved_with(sys, value, -d, out, &ok)) / (2 * d);
    double g0r = NAN, g0i = NAN, glr = NAN, gli = NAN;
    int rc = ts_response_at(sys, lin, in, out, 0.0, &g0r, &g0i, &err);
    rc |= ts_response_at(sys, lin, in, out, 2 * M_PI * 1e-6, &glr, &gli,
                         &err);
    printf("  %s -> %s: re-solved %.10g, w = 0 %.10g, 1e-6 Hz %.10g%+.3gi\n",
           in_name, out_name, ref, g0r, glr, gli);
    CHECK(ok && rc == TS_OK, "%s -> %s: responses and re-solved equilibria "
          "computed (%s)", in_name, out_name, err.msg);
    /* 1e-5 relative: the central difference of the re-solved equilibria
     * is good to ~1e-7 ((d / scale)^2), their residuals to 1e-12, the
     * linearization to ~1e-9. */
    CHECK(fabs(g0r - ref) <= 1e-5 * fabs(ref), "%s -> %s: static gain at "
          "w = 0 vs re-solved (%.3g relative <= 1e-5)", in_name, out_name,
          fabs(g0r - ref) / fabs(ref));
    CHECK(fabs(hypot(glr, gli) - fabs(ref)) <= 1e-5 * fabs(ref), "%s -> %s: "
          "|gain| at 1e-6 Hz vs re-solved", in_name, out_name);
    CHECK(g0i == 0.0, "%s -> %s: gain at w = 0 is real", in_name, out_name);
    return ref;
}

static void static_case(ts_system *sys, ts_linear *lin, const char *in_name,
                        const char *out_name, double not_trivial)
{
    ts_err err = {0};
    int in;
    ts_output out;
    int rc = ts_response_input_find(in_name, &in, &err);
    rc |= ts_response_output_find(sys, out_name, &out, &err);
    CHECK(rc == TS_OK, "%s -> %s: names found (%s)", in_name, out_name,
          err.msg);
    double ref = static_check(sys, lin, in, &out, &sys->tow.point[in], 1e-3,
                              in_name, out_name);
    CHECK(fabs(ref - round(ref)) > not_trivial,
          "%s -> %s: the gain %.6g is not trivially an integer", in_name,
          out_name, ref);
}

/* The zero-frequency response to the frame inputs tow.speed and
 * tow.turn_rate (dense B columns) against the static sensitivity from
 * re-solving the equilibrium at V +- dV, Omega +- dOmega. */
static void frame_static_case(ts_system *sys, ts_linear *lin,
                              const char *in_name, const char *out_name,
                              double d)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    int in = -1, c = strcmp(in_name, "tow.speed") ? 1 : 0;
    ts_output out;
    int rc = ts_response_input_lookup(k, in_name, &in, &err);
    rc |= ts_response_output_find(sys, out_name, &out, &err);
    ts_kernel_free(k);
    CHECK(rc == TS_OK && in == lin->frame_input + c, "%s -> %s: names "
          "found, input column %d (%s)", in_name, out_name, in, err.msg);
    double ref = static_check(sys, lin, in, &out,
                              c == 0 ? &sys->tow.speed : &sys->tow.turn_rate,
                              d, in_name, out_name);
    CHECK(fabs(ref) > 1e-3, "%s -> %s: the gain %.6g is not nil", in_name,
          out_name, ref);
}

static void test_static_gain(void)
{
    ts_scene *sc = tscene_parse(units, above_yaml);
    double zmin;
    ts_linear *lin = linearize(sc->system, TS_LIN_BOTH, &zmin);
    CHECK(lin && zmin > 0.1, "above-water tow: every node %.3g m > 0.1 m "
                             "from the waterline",
          zmin);
    CHECK(lin->kinks == 0, "above-water tow: no kinks");
    static_case(sc->system, lin, "tow.heave", "sphere.z", 0.01);
    static_case(sc->system, lin, "tow.heave", "cable.1.tension", 0.01);
    static_case(sc->system, lin, "tow.heave", "cable.12.x", 0.001);
    ts_linear_free(lin);
    ts_scene_free(sc);

    sc = tscene_parse(units, turn_yaml);
    lin = linearize(sc->system, TS_LIN_BOTH, NULL);
    static_case(sc->system, lin, "tow.surge", "sphere.y", 0.01);
    ts_linear_free(lin);
    ts_scene_free(sc);

    /* The frame inputs, in straight tow and in the turn: the dense
     * model's B columns, and the sparse model's (its Gf, the residual's
     * change at fixed points). */
    for (int m = 0; m < 2; m++) {
        ts_lin_model model = m ? TS_LIN_SPARSE : TS_LIN_DENSE;
        printf("  the frame inputs, %s model:\n", m ? "sparse" : "dense");
        sc = tscene_parse(units, above_yaml);
        lin = linearize(sc->system, model, NULL);
        frame_static_case(sc->system, lin, "tow.speed", "sphere.z", 1e-3);
        frame_static_case(sc->system, lin, "tow.speed", "cable.1.tension",
                          1e-3);
        frame_static_case(sc->system, lin, "tow.turn_rate", "sphere.y",
                          1e-4);
        ts_linear_free(lin);
        ts_scene_free(sc);
        sc = tscene_parse(units, turn_yaml);
        lin = linearize(sc->system, model, NULL);
        frame_static_case(sc->system, lin, "tow.speed", "sphere.y", 1e-4);
        frame_static_case(sc->system, lin, "tow.turn_rate", "sphere.x",
                          1e-4);
        frame_static_case(sc->system, lin, "tow.turn_rate",
                          "cable.20.tension", 1e-4);
        ts_linear_free(lin);
        ts_scene_free(sc);
    }
}

/* The frame inputs' response, the sparse model's (its Gf columns) against
 * the dense model's (B's), at 4 frequencies in straight tow and in the
 * turn: within the sum of the two gains' error allowances. */
static void test_frame_sparse(void)
{
    static const double freq[4] = {0.0137, 0.071, 0.33, 1.9};
    static const char *const ins[2] = {"tow.speed", "tow.turn_rate"};
    static const char *const outs[3] = {"sphere.z", "sphere.y",
                                        "cable.1.tension"};
    const char *yamls[2] = {above_yaml, turn_yaml};
    for (int sidx = 0; sidx < 2; sidx++) {
        ts_scene *sc = tscene_parse(units, yamls[sidx]);
        if (!sc)
            continue;
        ts_system *sys = sc->system;
        ts_linear *ld = linearize(sys, TS_LIN_DENSE, NULL);
        ts_linear *ls = linearize(sys, TS_LIN_SPARSE, NULL);
        ts_err err = {0};
        ts_kernel *k = ts_kernel_alloc(sys, &err);
        double worst = 0, rel = 0;
        int n = 0, bad = 0;
        for (int ii = 0; k && ld && ls && ii < 2; ii++)
            for (int oi = 0; oi < 3; oi++) {
                int in = -1;
                ts_output out;
                ts_response *rs = NULL, *rd = NULL;
                if (ts_response_input_lookup(k, ins[ii], &in, &err) !=
                        TS_OK ||
                    ts_response_output_find(sys, outs[oi], &out, &err) !=
                        TS_OK ||
                    ts_response_compute(sys, ls, in, &out, freq, 4, &rs,
                                        &err) != TS_OK ||
                    ts_response_compute(sys, ld, in, &out, freq, 4, &rd,
                                        &err) != TS_OK) {
                    printf("  %s -> %s: %s\n", ins[ii], outs[oi], err.msg);
                    bad++;
                } else {
                    for (int i = 0; i < 4; i++) {
                        double d = hypot(rs->re[i] - rd->re[i],
                                         rs->im[i] - rd->im[i]);
                        double allow = rs->error[i] + rd->error[i];
                        if (!(d <= allow))
                            bad++;
                        worst = fmax(worst, d / allow);
                        /* (Zero by symmetry: tow.speed to sphere.y in
                         * the straight tow.) */
                        if (rd->magnitude[i] > allow)
                            rel = fmax(rel, allow / rd->magnitude[i]);
                        n++;
                    }
                }
                ts_response_free(rs);
                ts_response_free(rd);
            }
        CHECK(ls && ls->desc && !ls->A && n == 24 &&
                  bad == 0,
              "%s: the frame inputs (tow.speed, tow.turn_rate to sphere.z, "
              "sphere.y, cable.1.tension) on the sparse model alone = the "
              "dense model at 4 frequencies (0.0137 to 1.9 Hz, %d gains): "
              "largest difference %.3g of the two allowances (themselves "
              "at most %.2g of the gains not zero by symmetry)", sidx ? "in the turn" :
              "straight", n, worst, rel);
        /* Without the frame columns (ts_linearize_opts.frame_inputs 0,
         * the default): 4 groups fewer, and tow.speed refused. */
        ts_linear *ln = linearize_at(sys, TS_LIN_SPARSE, 0.0, 0, NULL);
        int in = -1;
        ts_output out;
        double re, im;
        ts_err_clear(&err);
        int rc = k && ln && ls &&
                         ts_response_input_lookup(k, "tow.speed", &in,
                                                  &err) == TS_OK &&
                         ts_response_output_find(sys, "sphere.z", &out,
                                                 &err) == TS_OK
                     ? ts_response_at(sys, ln, in, &out, 0.1, &re, &im, &err)
                     : TS_OK;
        CHECK(ln && ls && ln->groups == ls->groups - 4 && rc == TS_EINVAL &&
                  strstr(err.msg, "tow.speed needs the sparse model's "
                                  "frame columns"),
              "%s: without the frame columns %d groups (%d with), tow.speed "
              "refused: %s", sidx ? "in the turn" : "straight",
              ln ? ln->groups : 0, ls ? ls->groups : 0, err.msg);
        ts_linear_free(ln);
        ts_kernel_free(k);
        ts_linear_free(ld);
        ts_linear_free(ls);
        ts_scene_free(sc);
    }
}

static void test_resonance(void)
{
    ts_scene *sc = tscene_parse(units, 
        "name: chain\n"
        "environment: {water_density: 0, gravity: 9.80665}\n"
        "tow: {speed: 0}\n"
        "cables:\n"
        "  - {name: chain, from: tow, length: 5.17, diameter: 0.01,\n"
        "     mass_per_length: 1.9, links: 10}\n");
    const ts_system *sys = sc->system;
    ts_linear *lin = linearize(sys, TS_LIN_AUTO, NULL);
    ts_eigen *e = NULL;
    ts_err err = {0};
    ts_eigen_solve(lin, NULL, &e, &err);
    double fn[3];
    for (int j = 0; j < 3; j++)
        fn[j] = e->modes[2 * j].freq_hz;
    int in;
    ts_output out;
    ts_response_input_find("tow.surge", &in, &err);
    int rc = ts_response_output_find(sys, "chain.10.x", &out, &err);
    CHECK(rc == TS_OK, "chain.10.x found (%s)", err.msg);
    int np = 600;
    double *f = malloc((size_t)np * sizeof(double));
    ts_response_logspace(0.6 * fn[0], 1.15 * fn[2], np, f, &err);
    ts_response *r = NULL;
    rc = ts_response_compute(sys, lin, in, &out, f, np, &r, &err);
    CHECK(rc == TS_OK, "chain: response on %d points (%s)", np, err.msg);
    double ratio = pow(1.15 * fn[2] / (0.6 * fn[0]), 1.0 / (np - 1));
    int matched[3] = {0, 0, 0}, stray = 0;
    for (int i = 1; rc == TS_OK && i + 1 < np; i++) {
        if (!(r->magnitude[i] > r->magnitude[i - 1] &&
              r->magnitude[i] > r->magnitude[i + 1]))
            continue;
        int hit = 0;
        for (int j = 0; j < 3; j++)
            if (r->freq_hz[i] / fn[j] < ratio && fn[j] / r->freq_hz[i] < ratio) {
                matched[j]++;
                hit = 1;
            }
        stray += !hit;
    }
    CHECK(matched[0] == 1 && matched[1] == 1 && matched[2] == 1 && stray == 0,
          "chain: one peak next to each of f1, f2, f3 (%.5g, %.5g, %.5g Hz; "
          "%d %d %d) and %d elsewhere",
          fn[0], fn[1], fn[2], matched[0], matched[1], matched[2], stray);
    for (int j = 0; j < 3; j++) {
        double re, im;
        ts_response_at(sys, lin, in, &out, 2 * M_PI * fn[j] * (1 + 1e-6), &re,
                       &im, &err);
        CHECK(hypot(re, im) > 1e3, "chain: |G| at f%d (1 + 1e-6) = %.3g > 1e3",
              j + 1, hypot(re, im));
    }
    ts_response_free(r);
    free(f);
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_scene_free(sc);
}

/* The response the old way, from the dense A, B and tension Jacobians of
 * the column-difference linearization (an independent reference for the
 * sparse solve): Z = (i w I - A)^-1 (B_x + i w B_v - w^2 B_a), then the
 * node displacement of Z's coordinates plus the tow displacement, or
 * dT/dy Z + dT/du (1, i w, -w^2). One dense complex LU (LAPACK zgesv). */
static double complex dense_gain(const ts_system *sys, const ts_linear *lin,
                                 int input, const ts_output *out, double w)
{
    int n = lin->nstate, nq = lin->nq, nl = lin->nlinks, one = 1, info = 0;
    double complex s = I * w;
    double complex *M = malloc((size_t)n * n * sizeof *M);
    double complex *z = malloc((size_t)n * sizeof *z);
    int *piv = malloc((size_t)n * sizeof *piv);
    double *dq = malloc((size_t)nq * sizeof *dq);
    double *dr = malloc(3 * (size_t)sys->nnodes * sizeof *dr);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            M[i + (size_t)j * n] = (i == j ? s : 0) - lin->A[i + (size_t)j * n];
    const double *Bx = lin->B + (size_t)(TS_IN_DISP + input) * n;
    const double *Bv = lin->B + (size_t)(TS_IN_VEL + input) * n;
    const double *Ba = lin->B + (size_t)(TS_IN_ACC + input) * n;
    for (int i = 0; i < n; i++)
        z[i] = Bx[i] + s * Bv[i] + s * s * Ba[i];
    zgesv_(&n, &one, M, &n, piv, z, &n, &info);
    double complex g = 0;
    if (out->kind == TS_OUT_POSITION) {
        int idx = 3 * out->node + out->comp;
        for (int i = 0; i < nq; i++)
            dq[i] = creal(z[i]);
        ts_linear_node_displacements(sys, lin, dq, dr);
        g = dr[idx];
        for (int i = 0; i < nq; i++)
            dq[i] = cimag(z[i]);
        ts_linear_node_displacements(sys, lin, dq, dr);
        g += I * dr[idx] + (out->comp == input ? 1.0 : 0.0);
    } else {
        int l = out->link;
        for (int j = 0; j < n; j++)
            g += lin->Ty[l + (size_t)j * nl] * z[j];
        g += lin->Tu[l + (size_t)(TS_IN_DISP + input) * nl] +
             s * lin->Tu[l + (size_t)(TS_IN_VEL + input) * nl] +
             s * s * lin->Tu[l + (size_t)(TS_IN_ACC + input) * nl];
    }
    free(M);
    free(z);
    free(piv);
    free(dq);
    free(dr);
    return info == 0 ? g : NAN;
}

/* The sparse response against the dense one on scenes of every kind:
 * above water (the cable pierces the surface), a turn, an elastic cable
 * with internal damping, a branched tree with bending. */
static void test_dense_reference(void)
{
    const char *const scenes[] = {above_yaml, turn_yaml,
        "name: elastic\n"
        "tow: {speed: 2.385, point: [0, 0, 0.7]}\n"
        "cables:\n"
        "  - {name: cable, from: tow, to: sphere, length: 31.7, diameter: "
        "0.021,\n"
        "     mass_per_length: 0.83, links: 12, normal_drag: 1.2,\n"
        "     tangential_drag: 0.01, added_mass: 1.0, EA: 2.1e7, damping: "
        "3000}\n"
        "bodies:\n"
        "  - {name: sphere, type: sphere, diameter: 0.3, mass: 41.0, drag: "
        "0.5,\n"
        "     added_mass: 0.5}\n",
        "name: tree\n"
        "tow: {speed: 1.9, point: [0, 0, 0.5]}\n"
        "cables:\n"
        "  - {name: main, from: tow, to: knot, length: 12.3, diameter: "
        "0.02,\n"
        "     mass_per_length: 0.9, links: 6, normal_drag: 1.2, added_mass: "
        "1.0,\n"
        "     EI: 35}\n"
        "  - {name: a, from: knot, to: fish, length: 7.1, diameter: 0.012,\n"
        "     mass_per_length: 0.4, links: 5, normal_drag: 1.1, EI: 6}\n"
        "  - {name: b, from: knot, length: 5.3, diameter: 0.01,\n"
        "     mass_per_length: 0.3, links: 4, normal_drag: 1.3}\n"
        "bodies:\n"
        "  - {name: knot, type: junction, mass: 3.0}\n"
        "  - {name: fish, type: cylinder, diameter: 0.2, length: 1.1, mass: "
        "30,\n"
        "     drag: 0.3, cross_drag: 1.0, added_mass: 0.1, cross_added_mass: "
        "1.0}\n"};
    static const char *const outs[][3] = {
        {"sphere.z", "cable.1.tension", "cable.9.y"},
        {"sphere.y", "cable.20.tension", "cable.3.x"},
        {"sphere.z", "cable.1.tension", "cable.7.tension"},
        {"fish.z", "a.2.tension", "b.4.y"}};
    for (int sc_i = 0; sc_i < 4; sc_i++) {
        ts_scene *sc = tscene_parse(units, scenes[sc_i]);
        if (!sc)
            continue;
        const ts_system *sys = sc->system;
        ts_linear *lin = linearize(sys, TS_LIN_BOTH, NULL);
        ts_err err = {0};
        double worst = 0, sweep = 0;
        int bad = 0;
        for (int o = 0; lin && o < 3; o++) {
            ts_output out;
            if (ts_response_output_find(sys, outs[sc_i][o], &out, &err)) {
                printf("  %s\n", err.msg);
                bad++;
                continue;
            }
            /* A tow point at the waterline makes heave's derivatives the
             * mean of one-sided ones, different for the two
             * linearizations' steps (both report the kink). */
            for (int input = 0; input < 3; input++)
                for (int i = 0; i <= 24 && !(input == 2 && lin->kink_tow);
                     i++) {
                    double w = i == 0 ? 0.0 : 2 * M_PI * 0.003 *
                                                   pow(10.0, i / 6.0);
                    double re, im;
                    if (ts_response_at(sys, lin, input, &out, w, &re, &im,
                                       &err)) {
                        printf("  %s\n", err.msg);
                        bad++;
                        continue;
                    }
                    double complex gd = dense_gain(sys, lin, input, &out, w);
                    /* Relative to the gain, or to 1 m/m or 1 N/m for
                     * gains near zero. */
                    double rel = cabs(re + I * im - gd) / fmax(cabs(gd), 1.0);
                    if (rel > worst && getenv("TS_DEBUG"))
                        printf("  %s in %d w %.4g: sparse %.10g%+.10gi dense "
                               "%.10g%+.10gi\n", outs[sc_i][o], input, w,
                               re, im, creal(gd), cimag(gd));
                    worst = fmax(worst, rel);
                }
            /* A sweep (ts_response_compute refactors with the pivots of
             * an earlier frequency) against each point factored afresh
             * (ts_response_at). */
            double f[24];
            for (int i = 0; i < 24; i++)
                f[i] = 0.003 * pow(10.0, (i + 1) / 6.0);
            ts_response *r = NULL;
            int in = lin->kink_tow ? 0 : 2;
            if (ts_response_compute(sys, lin, in, &out, f, 24, &r, &err)) {
                printf("  %s\n", err.msg);
                bad++;
                continue;
            }
            for (int i = 0; i < 24; i++) {
                double re, im;
                if (ts_response_at(sys, lin, in, &out, 2 * M_PI * f[i], &re,
                                   &im, &err) == TS_OK)
                    sweep = fmax(sweep, hypot(r->re[i] - re, r->im[i] - im) /
                                            fmax(hypot(re, im), 1.0));
                else
                    bad++;
            }
            ts_response_free(r);
        }
        /* 1e-6: each linearization's relative truncation error is below
         * 1e-8 (desc_err, trunc_err / a_scale), amplified at most 100
         * times by the lightest damping of these scenes near their
         * resonances. */
        CHECK(lin && !bad && worst < 1e-6,
              "%s: sparse response = dense (i w I - A)^-1 B at 25 "
              "frequencies, %d inputs, 3 outputs: largest relative "
              "difference %.3g < 1e-6 (linearization errors: sparse %.2g, "
              "dense %.2g)",
              sys->name, lin && lin->kink_tow ? 2 : 3, worst,
              lin ? lin->desc_err : NAN,
              lin ? lin->trunc_err / lin->a_scale : NAN);
        /* 1e-9: the same equations solved with other pivots differ by
         * rounding, amplified by the condition of S(i w) (KLU's rcond is
         * kept within 100 times a fresh factorisation's). */
        CHECK(lin && !bad && sweep < 1e-9,
              "%s: a sweep of 24 frequencies with refactored pivots = each "
              "factored afresh to %.2g (< 1e-9)", sys->name, sweep);
        ts_linear_free(lin);
        ts_scene_free(sc);
    }
}

static void test_names(void)
{
    ts_scene *sc = tscene_parse(units, above_yaml);
    const ts_system *sys = sc->system;
    ts_err err = {0};
    ts_output out;
    int in, rc;
    rc = ts_response_output_find(sys, "sphere.z", &out, &err);
    CHECK(rc == TS_OK && out.kind == TS_OUT_POSITION && out.node == 20 &&
              out.comp == 2 && strcmp(out.name, "sphere.z") == 0,
          "sphere.z: node 20 z");
    rc = ts_response_output_find(sys, "cable.20.z", &out, &err);
    CHECK(rc == TS_OK && out.node == 20 && strcmp(out.name, "sphere.z") == 0,
          "cable.20.z is the sphere (canonical %s)", out.name);
    rc = ts_response_output_find(sys, "cable.3.x", &out, &err);
    CHECK(rc == TS_OK && out.node == 3 && out.comp == 0, "cable.3.x");
    rc = ts_response_output_find(sys, "cable.3.tension", &out, &err);
    CHECK(rc == TS_OK && out.kind == TS_OUT_TENSION && out.link == 2,
          "cable.3.tension: link index 2");
    rc = ts_response_output_find(sys, "sphere.tension", &out, &err);
    CHECK(rc == TS_OK && out.link == 19 &&
              strcmp(out.name, "cable.20.tension") == 0,
          "sphere.tension is cable.20.tension");
    static const char *bad[] = {"nosuch.z", "cable.21.x", "cable.0.x",
                                "sphere.w", "cable", "cable.x.y", ".z"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ts_err_clear(&err);
        rc = ts_response_output_find(sys, bad[i], &out, &err);
        CHECK(rc == TS_EINVAL && strstr(err.msg, bad[i]) &&
                  strstr(err.msg, "cable.1 .. cable.19, sphere") &&
                  strstr(err.msg, "cable.1.tension .. cable.20.tension"),
              "bad output '%s' refused, valid names listed: %s", bad[i],
              err.msg);
    }
    ts_err_clear(&err);
    rc = ts_response_output_find(sys, "tow.z", &out, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tow is the input"),
          "tow.z refused: %s", err.msg);
    rc = ts_response_input_find("tow.heave", &in, &err);
    CHECK(rc == TS_OK && in == 2, "tow.heave is channel 2");
    rc = ts_response_input_find("sphere.z", &in, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tow.surge, tow.sway, "
                                             "tow.heave") &&
              strstr(err.msg, "tow.roll, tow.pitch, tow.yaw"),
          "bad input refused: %s", err.msg);
    rc = ts_response_input_find("tow.pitch", &in, &err);
    CHECK(rc == TS_OK && in == TS_IN_ROT + 1, "tow.pitch is channel %d",
          TS_IN_ROT + 1);

    double f[4];
    rc = ts_response_logspace(0.01, 10, 4, f, &err);
    CHECK(rc == TS_OK && f[0] == 0.01 && f[3] == 10 &&
              fabs(f[1] - 0.1) < 1e-15 && fabs(f[2] - 1) < 1e-14,
          "logspace 0.01..10 in 4: %g %g %g %g", f[0], f[1], f[2], f[3]);
    static const double bad_range[][2] = {{0, 10}, {-1, 10}, {5, 5},
                                          {10, 1}, {1, INFINITY}};
    for (int i = 0; i < 5; i++) {
        rc = ts_response_logspace(bad_range[i][0], bad_range[i][1], 10, f,
                                  &err);
        CHECK(rc == TS_EINVAL, "range %g..%g refused: %s", bad_range[i][0],
              bad_range[i][1], err.msg);
    }
    rc = ts_response_logspace(1, 2, 1, f, &err);
    CHECK(rc == TS_EINVAL, "1 point refused: %s", err.msg);

    /* The dense model alone (a system with a vehicle) answers the same,
     * a tension only with the tension Jacobians. */
    ts_linear *lin = linearize(sys, TS_LIN_DENSE, NULL);
    ts_linear *sp = linearize(sys, TS_LIN_SPARSE, NULL);
    ts_response_output_find(sys, "cable.3.tension", &out, &err);
    double re, im, sre = NAN, sim = NAN;
    rc = ts_response_at(sys, lin, 2, &out, 1.0, &re, &im, &err);
    if (rc == TS_OK && sp)
        rc = ts_response_at(sys, sp, 2, &out, 1.0, &sre, &sim, &err);
    CHECK(rc == TS_OK && hypot(re - sre, im - sim) <= 1e-6 * hypot(sre, sim),
          "tension response from the dense model alone = the sparse one "
          "(%.9g%+.9gi, %.9g%+.9gi N/m): %s", re, im, sre, sim, err.msg);
    ts_linear_free(sp);
    free(lin->Ty);
    lin->Ty = NULL;
    rc = ts_response_at(sys, lin, 2, &out, 1.0, &re, &im, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tensions"),
          "tension response from the dense model without its tension "
          "Jacobians refused: %s", err.msg);
    ts_linear_free(lin);
    lin = linearize(sys, TS_LIN_AUTO, NULL);
    ts_response_output_find(sys, "sphere.z", &out, &err);
    rc = ts_response_at(sys, lin, 3, &out, 1.0, &re, &im, &err);
    CHECK(rc == TS_EINVAL, "channel 3 refused: %s", err.msg);
    rc = ts_response_at(sys, lin, 2, &out, -1.0, &re, &im, &err);
    CHECK(rc == TS_EINVAL, "negative frequency refused: %s", err.msg);
    ts_linear_free(lin);

    /* The frame inputs by name: their rates come with them; a turn in a
     * horizontal current has no linear model. */
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    rc = ts_response_input_lookup(k, "tow.speed_rate", &in, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "give tow.speed"),
          "tow.speed_rate refused: %s", err.msg);
    rc = ts_response_input_lookup(k, "nosuch", &in, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tow.speed, tow.turn_rate"),
          "a bad input's message lists the frame inputs: %s", err.msg);
    ts_kernel_free(k);
    sc->system->env.current[1] = 0.3;
    k = ts_kernel_alloc(sys, &err);
    rc = ts_response_input_lookup(k, "tow.turn_rate", &in, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "heading change"),
          "tow.turn_rate in a horizontal current refused: %s", err.msg);
    rc = ts_response_input_lookup(k, "tow.speed", &in, &err);
    CHECK(rc == TS_OK, "tow.speed in a current is an input");
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* ---- 5. the gain's error allowance covers rounding -------------------- */

/* x = (4 x - y) / 3 over n entries: a's A, B, dT/dy, dT/du become the
 * Richardson value of steps h (a) and 2h (b), fourth order. */
static void richardson(ts_linear *a, const ts_linear *b)
{
    size_t n = (size_t)a->nstate, nl = (size_t)a->nlinks;
    size_t ni = (size_t)a->ninput, no = (size_t)a->noutput;
    struct {
        double *x;
        const double *y;
        size_t len;
    } m[6] = {{a->A, b->A, n * n},
              {a->B, b->B, n * ni},
              {a->Ty, b->Ty, nl * n},
              {a->Tu, b->Tu, nl * ni},
              {a->Vy, b->Vy, no * n},
              {a->Vu, b->Vu, no * ni}};
    for (int k = 0; k < 6; k++)
        for (size_t i = 0; m[k].x && i < m[k].len; i++)
            m[k].x[i] = (4 * m[k].x[i] - m[k].y[i]) / 3;
}

/* The Richardson linearization of steps h and 2h (NULL on failure). */
static ts_linear *tight(const ts_system *sys, double h)
{
    ts_linear *a = linearize_at(sys, TS_LIN_DENSE, h, 1, NULL);
    ts_linear *b = linearize_at(sys, TS_LIN_DENSE, 2 * h, 1, NULL);
    if (a && b)
        richardson(a, b);
    ts_linear_free(b);
    if (!b) {
        ts_linear_free(a);
        a = NULL;
    }
    return a;
}

/* Tally of gains against a tight reference: how many, how many with
 * errors 10 times the reference's uncertainty, the largest ratio of error
 * to allowance + uncertainty (with that error and allowance), and whether
 * every allowance is finite. */
typedef struct tally {
    int n, clear, finite;
    double worst, we, wb;
} tally;

/* The gains of input `in` to `out` at 0 and freq[nf] from lin against
 * those of ref (the tight linearization) and ref2 (the same from twice
 * the steps, its uncertainty), into t. Returns 0 when a response fails
 * (err set). */
static int tally_gains(const ts_system *sys, const ts_linear *lin,
                       const ts_linear *ref, const ts_linear *ref2, int in,
                       const ts_output *out, const double *freq, int nf,
                       tally *t, ts_err *err)
{
    ts_response *r = NULL, *g = NULL, *g2 = NULL;
    int ok = ts_response_compute(sys, lin, in, out, freq, nf, &r, err) ==
                 TS_OK &&
             ts_response_compute(sys, ref, in, out, freq, nf, &g, err) ==
                 TS_OK &&
             ts_response_compute(sys, ref2, in, out, freq, nf, &g2, err) ==
                 TS_OK;
    for (int i = -1; i < nf && ok; i++) {
        double e = i < 0 ? fabs(r->static_gain - g->static_gain)
                         : hypot(r->re[i] - g->re[i], r->im[i] - g->im[i]);
        double u = i < 0 ? fabs(g2->static_gain - g->static_gain)
                         : hypot(g2->re[i] - g->re[i], g2->im[i] - g->im[i]);
        double bd = i < 0 ? r->static_error : r->error[i];
        double q = e / (bd + u);
        t->finite = t->finite && isfinite(bd);
        t->n++;
        t->clear += e >= 10 * u;
        if (!(q <= t->worst)) {
            t->worst = q;
            t->we = e;
            t->wb = bd;
        }
    }
    ts_response_free(r);
    ts_response_free(g);
    ts_response_free(g2);
    return ok;
}

/* Kamman ex. 3 in the turn at 10 links, tow.surge and tow.sway (heave
 * is left out: the tow point is at the waterline, a kink) to the
 * sphere's y and z and the top link's tension, at 0 (the static gain)
 * and 5 frequencies from 0.05 to 5 Hz, linearized at the default step
 * and at 1e-7 and 1e-8 (rounding, eps / h, dominating the truncation,
 * h^2): every gain lies within its error allowance of the gain of a
 * tight linearization (A, B, dT/dy, dT/du Richardson-extrapolated from
 * steps 5e-4 and 1e-3, fourth order, rounding 1e4 times smaller), up to
 * that reference's own uncertainty (its distance to the same from steps
 * 1e-3 and 2e-3). At 1e-8 at least a third of the gains have errors 10
 * times that uncertainty, so the check is about the allowance. The same
 * for the dense model (A's error estimate and noise) and the sparse one
 * (the node residual's entry-wise truncation and rounding, with tension
 * outputs from its own unknowns). */
static void test_rounding(void)
{
    ts_scene *sc = tscene_parse(units, turn_yaml);
    ts_err err = {0};
    ts_system *sys = ts_system_copy(sc->system, &err);
    ts_system_set_links(sys, 10, &err);
    ts_linear *ref = tight(sys, 5e-4), *ref2 = tight(sys, 1e-3);
    static const double steps[3] = {0.0, 1e-7, 1e-8};
    static const char *const ins[2] = {"tow.surge", "tow.sway"};
    static const char *const outs[3] = {"sphere.y", "sphere.z",
                                        "cable.1.tension"};
    double freq[5];
    ts_response_logspace(0.05, 5, 5, freq, &err);
    for (int kk = 0; kk < 6 && ref && ref2; kk++) {
        int k = kk % 3, sparse = kk >= 3;
        ts_linear *lin = linearize_at(sys, sparse ? TS_LIN_SPARSE
                                                  : TS_LIN_DENSE,
                                      steps[k], 1, NULL);
        tally t = {0, 0, 1, 0.0, NAN, NAN};
        int ok = lin != NULL;
        for (int a = 0; a < 2 && ok; a++)
            for (int b = 0; b < 3 && ok; b++) {
                int in;
                ts_output out;
                ok = ts_response_input_find(ins[a], &in, &err) == TS_OK &&
                     ts_response_output_find(sys, outs[b], &out, &err) ==
                         TS_OK &&
                     tally_gains(sys, lin, ref, ref2, in, &out, freq, 5, &t,
                                 &err);
            }
        /* At 1e-8 the allowance is not vacuous: some gain's error is at
         * least a hundredth of it (10 times the estimate by design; the
         * rms estimate counts noise in every entry, while far from a
         * perturbed coordinate the kernel rounds identically). */
        CHECK(ok && t.finite && t.worst <= 1 &&
                  (k < 2 || (t.clear >= t.n / 3 && t.worst >= 0.01)),
              "ex. 3 turn, 10 links, %s model, step %.3g: every gain (%d; "
              "%d with errors 10 times the reference's uncertainty) within "
              "its error allowance of the tight one (closest %.2f: error "
              "%.3g, allowance %.3g) (%s)",
              sparse ? "sparse" : "dense", steps[k], t.n, t.clear, t.worst,
              t.we, t.wb, ok ? "" : err.msg);
        ts_linear_free(lin);
    }
    CHECK(ref && ref2, "tight linearizations");
    ts_linear_free(ref);
    ts_linear_free(ref2);
    ts_system_free(sys);
    ts_scene_free(sc);
}

/* ---- 6. the allowance with a vehicle ------------------------------------ */

/* The AURORA-like towfish (examples/aurora_towfish.yaml: a PID depth loop
 * with an integrator, lagged surfaces, so controller states) at 10 links:
 * the tow surge and two of the vehicle's own inputs (the wing, the depth
 * set point) to its depth and pitch (its own outputs, rows of Vy, Vu)
 * and the top tension (Ty, Tu), at 0 and 5 frequencies from 0.01 to 1
 * Hz, at the default step and at 1e-7 and 1e-8: every gain within its
 * allowance of a tight linearization's (A, B, Ty, Tu, Vy, Vu
 * Richardson-extrapolated from steps 5e-4 and 1e-3), up to that
 * reference's own uncertainty (its distance to the same from 1e-3 and
 * 2e-3). Both models: the dense A (Vy, Vu, Ty, Tu and their errors)
 * and the sparse one (the vehicle's rows, its inputs' columns and its
 * outputs' rows, each with its entry-wise truncation and rounding). */
static void test_vehicle_allowance(void)
{
    ts_err err = {0};
    ts_scene *sc = ts_scene_load("examples/aurora_towfish.yaml", units, &err);
    if (!CHECK(sc != NULL, "aurora_towfish: %s", err.msg))
        return;
    ts_system *sys = ts_system_copy(sc->system, &err);
    ts_system_set_links(sys, 10, &err);
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_linear *ref = tight(sys, 5e-4), *ref2 = tight(sys, 1e-3);
    static const double steps[3] = {0.0, 1e-7, 1e-8};
    static const char *const ins[3] = {"tow.surge", "aurora.wing",
                                       "aurora.depth.setpoint"};
    static const char *const outs[3] = {"aurora.depth", "aurora.pitch",
                                        "armoured.1.tension"};
    double freq[5];
    ts_response_logspace(0.01, 1, 5, freq, &err);
    CHECK(k && ref && ref2 && ts_kernel_ncontrol(k) > 0,
          "aurora, 10 links: tight linearizations, %d controller states",
          k ? ts_kernel_ncontrol(k) : 0);
    for (int s = 0; s < 6 && k && ref && ref2; s++) {
        int sparse = s >= 3;
        ts_linear *lin = linearize_at(sys, sparse ? TS_LIN_SPARSE
                                                  : TS_LIN_DENSE,
                                      steps[s % 3], 1, NULL);
        tally t = {0, 0, 1, 0.0, NAN, NAN};
        int ok = lin != NULL;
        for (int a = 0; a < 3 && ok; a++)
            for (int b = 0; b < 3 && ok; b++) {
                int in;
                ts_output out;
                ok = ts_response_input_lookup(k, ins[a], &in, &err) ==
                         TS_OK &&
                     ts_response_output_lookup(k, outs[b], &out, &err) ==
                         TS_OK &&
                     tally_gains(sys, lin, ref, ref2, in, &out, freq, 5, &t,
                                 &err);
            }
        CHECK(ok && t.finite && t.worst <= 1 &&
                  (s % 3 < 2 || t.clear >= t.n / 3),
              "aurora, 10 links, %s model, step %.3g: every gain (%d; %d "
              "with errors 10 times the reference's uncertainty) has a "
              "finite allowance and lies within it of the tight one "
              "(closest %.2f: error %.3g, allowance %.3g) (%s)",
              sparse ? "sparse" : "dense", steps[s % 3], t.n, t.clear,
              t.worst, t.we, t.wb, ok ? "" : err.msg);
        ts_linear_free(lin);
    }
    ts_linear_free(ref);
    ts_linear_free(ref2);
    ts_kernel_free(k);
    ts_system_free(sys);
    ts_scene_free(sc);
}

/* A long sweep runs in chunks on the linearization's threads (lib/
 * response.c, resp_chunks): from 200 links on. The result must not depend
 * on the threads, bit for bit, and each gain must equal the one factored
 * afresh at its own frequency (ts_response_at) within the gain's error
 * allowance (the chunks differ from a single pass only in where the
 * factors are fresh, a rounding difference). A stop asked for through the
 * progress callback ends the sweep with TS_ECANCEL. */
static int stop_after(const ts_progress *p, void *data)
{
    return p->done >= *(const int *)data;
}

static void test_chunked_sweep(void)
{
    ts_err err = {0};
    ts_scene *sc = tscene_load(units, "examples/kamman_ex1_submerged.yaml");
    ts_system *sys = sc ? ts_system_copy(sc->system, &err) : NULL;
    if (!CHECK(sys && ts_system_set_links(sys, 240, &err) == TS_OK,
               "chunked sweep: scene at 240 links (%s)", err.msg)) {
        ts_system_free(sys);
        ts_scene_free(sc);
        return;
    }
    ts_linear *lin = linearize(sys, TS_LIN_SPARSE, NULL);
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_output out;
    int in = -1, np = 37;
    double freq[37];
    ts_response_logspace(0.01, 3, np, freq, &err);
    int ok = lin && k &&
             ts_response_output_lookup(k, "sphere.z", &out, &err) == TS_OK &&
             ts_response_input_lookup(k, "tow.heave", &in, &err) == TS_OK;
    ts_response *r1 = NULL, *r2 = NULL;
    if (ok) {
        lin->threads = 1;
        ok = ts_response_compute(sys, lin, in, &out, freq, np, &r1, &err) ==
             TS_OK;
        lin->threads = 2;
        ok = ok && ts_response_compute(sys, lin, in, &out, freq, np, &r2,
                                       &err) == TS_OK;
    }
    int same = ok, within = ok;
    double worst = 0;
    for (int i = 0; ok && i < np; i++) {
        same &= r1->re[i] == r2->re[i] && r1->im[i] == r2->im[i] &&
                r1->error[i] == r2->error[i];
        double re, im;
        if (ts_response_at(sys, lin, in, &out, 2 * M_PI * freq[i], &re, &im,
                           &err) != TS_OK) {
            ok = 0;
            break;
        }
        double d = cabs((r1->re[i] - re) + I * (r1->im[i] - im));
        within &= d <= r1->error[i];
        worst = fmax(worst, d / r1->error[i]);
    }
    CHECK(ok && same, "240 links, %d frequencies in chunks: one thread and "
          "two give the same gains and allowances, bit for bit (%s)", np,
          ok ? "" : err.msg);
    CHECK(ok && within, "240 links: every gain equals the one factored "
          "afresh at its frequency within its allowance (largest %.3g of "
          "it)", worst);
    int stop = 5;
    ts_response *r3 = NULL;
    int rc = ok ? tsi_response_compute(sys, lin, in, &out, freq, np,
                                       stop_after, &stop, &r3, &err)
                : TS_EINVAL;
    CHECK(rc == TS_ECANCEL && r3 == NULL && strstr(err.msg, "stopped"),
          "240 links, chunked: a stop after %d frequencies ends the sweep "
          "with TS_ECANCEL and no result (%s)", stop, err.msg);
    /* One gain evaluator along the scan and back (the loop margins' scan
     * and Brent's jumps), refactoring as it goes: each gain within its
     * allowance of the one factored afresh (ts_response_at; r1's errors
     * are those allowances, here 1e-9 relative and less). */
    tsi_gain *g = ok ? tsi_gain_alloc(sys, lin, in, &out, &err) : NULL;
    int gok = g != NULL, gin = gok;
    double gworst = 0;
    for (int j = 0; gok && j < 2 * np; j++) {
        int i = j < np ? j : 2 * np - 1 - j; /* up, then down */
        if (j % 3 == 2)
            i = (i * 7) % np;                /* and jumps */
        double complex v;
        double re, im;
        gok = tsi_gain_at(g, 2 * M_PI * freq[i], &v, &err) == TS_OK &&
              ts_response_at(sys, lin, in, &out, 2 * M_PI * freq[i], &re,
                             &im, &err) == TS_OK;
        double d = cabs(v - (re + I * im));
        gin &= d <= r1->error[i];
        gworst = fmax(gworst, d / r1->error[i]);
    }
    tsi_gain_free(g);
    CHECK(gok && gin, "240 links: one evaluator refactored along %d "
          "frequencies up, down and jumping gives each gain within its "
          "allowance of a fresh factorisation (largest %.3g of it; %s)",
          2 * np, gworst, gok ? "" : err.msg);
    ts_response_free(r1);
    ts_response_free(r2);
    ts_linear_free(lin);
    ts_kernel_free(k);
    ts_system_free(sys);
    ts_scene_free(sc);
}

int main(void)
{
    units = tscene_units();
    if (!units)
        return 1;
    test_static_gain();
    test_frame_sparse();
    test_resonance();
    test_dense_reference();
    test_names();
    test_rounding();
    test_vehicle_allowance();
    test_chunked_sweep();
    ts_units_free(units);
    return tc_done();
}
