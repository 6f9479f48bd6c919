/* test_simulate.c: time-domain simulation (towstab/simulate.h), the
 * matrix exponential (lib/expm.h) and the comparison (towstab/compare.h),
 * against invariants, analytic limits and second methods.
 *
 *  1. expm: rotations (exact), a nilpotent matrix (finite series), small
 *     norms through every Pade degree against a long Taylor series, a
 *     diagonalisable matrix V e^D V^-1, exp(A) exp(-A) = I; refusals.
 *  2. Energy: a chain with a sphere in vacuum, swinging in 3-D through
 *     re-charts, conserves kinetic + potential energy (relative drift
 *     below 1e-6 of m g L over 20 s at tolerance 1e-11).
 *  3. A steady tow started at its equilibrium stays there (drift below
 *     1e-8 of the cable length over 20 s).
 *  4. Small amplitude (1e-4 of the cable length): the nonlinear amplitude
 *     ratio and phase equal the frequency response (1 %, 1 deg); the
 *     linear simulation equals it too (1e-4), by expm and by ODE (which
 *     agree to 1e-6 of the amplitude).
 *  5. Second order: halving the amplitude quarters the RMS difference
 *     between linear and nonlinear runs (the relative difference halves).
 *  6. Kamman example 3: straight tow into the 0.5 rad/s turn settles onto
 *     the steady-turn equilibrium (1e-6 of the cable length). Manoeuvres
 *     in the linear model (its frame inputs): steps in speed and turn
 *     rate, straight and in the turn, differ from the nonlinear runs at
 *     second order in the step (ratio 4 on halving), and the linear run
 *     ends on the equilibrium re-solved in the final frame to second
 *     order.
 *  7. Implicit integrators (rk4imp, bsimp, msbdf, esdirk; Jacobian from the
 *     linearizer) agree with rk8pd.
 *  8. Initial shapes, sample times, the sinusoid fit, reports, a history
 *     of 5 samples grown to hold a run of 21 (the same samples as one
 *     allocated whole), and every refusal: options, step-size underflow
 *     (history kept), h_min, the step limit (also when every step ends on an output
 *     time), a turn-rate manoeuvre in a current in a linear run.
 *  9. The progress callback: called after every accepted step with the
 *     simulated time (rk8pd, esdirk) or every sample (linear, expm); a
 *     nonzero return stops the run with TS_ECANCEL, keeping the history
 *     so far.
 * Tolerances are stated at each check with their reason. */
#include "towstab/simulate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "expm.h"
#include "tcheck.h"
#include "towstab/analysis.h"
#include "towstab/compare.h"
#include "towstab/equilibrium.h"
#include "towstab/report_time.h"
#include "towstab/response.h"
#include "towstab/scene.h"

static ts_units *units;

static ts_scene *scene(const char *text)
{
    ts_err err = {0};
    ts_scene *s = ts_scene_parse(text, strlen(text), "test", units, &err);
    if (!s) {
        printf("FAIL scene: %s\n", err.msg);
        exit(1);
    }
    return s;
}

/* ---- 1. expm ---------------------------------------------------------- */

static double max_abs_diff(int n, const double *a, const double *b)
{
    double m = 0;
    for (int i = 0; i < n * n; i++)
        m = fmax(m, fabs(a[i] - b[i]));
    return m;
}

static void matmul(int n, const double *a, const double *b, double *c)
{
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double s = 0;
            for (int k = 0; k < n; k++)
                s += a[i + k * n] * b[k + j * n];
            c[i + j * n] = s;
        }
}

/* exp(A) by 60 Taylor terms (for ||A|| < 1 the remainder is < 1e-80). */
static void taylor(int n, const double *A, double *E)
{
    double *T = calloc(n * n, sizeof *T), *T2 = calloc(n * n, sizeof *T2);
    for (int i = 0; i < n * n; i++)
        E[i] = T[i] = 0;
    for (int i = 0; i < n; i++)
        E[i + i * n] = T[i + i * n] = 1;
    for (int k = 1; k < 60; k++) {
        matmul(n, T, A, T2);
        for (int i = 0; i < n * n; i++) {
            T[i] = T2[i] / k;
            E[i] += T[i];
        }
    }
    free(T);
    free(T2);
}

static void test_expm(void)
{
    ts_err err = {0};
    int s;
    /* Rotation: exp([[0, -a], [a, 0]]) = [[c, -s], [s, c]]; a = 2.385 uses
     * degree 13 without scaling, a = 50 needs squarings (rounding grows
     * with the squarings: ~ 2^s eps). */
    double as[2] = {2.385, 50.0}, tol[2] = {4e-15, 2e-13};
    for (int i = 0; i < 2; i++) {
        double A[4] = {0, as[i], -as[i], 0}, E[4];
        int rc = tsi_expm(2, A, E, &s, &err);
        double R[4] = {cos(as[i]), sin(as[i]), -sin(as[i]), cos(as[i])};
        CHECK(rc == TS_OK && max_abs_diff(2, E, R) < tol[i],
              "expm of a rotation generator, angle %g (%d squarings): max "
              "err %.2g < %.0e", as[i], s, max_abs_diff(2, E, R), tol[i]);
    }
    /* Nilpotent: strictly upper triangular 4x4, exp = I + N + N^2/2 + N^3/6. */
    double N[16] = {0}, N2[16], N3[16], E[16], R[16];
    N[0 + 1 * 4] = 2.385;
    N[1 + 2 * 4] = -1.7;
    N[2 + 3 * 4] = 3.1;
    N[0 + 3 * 4] = 0.4;
    N[1 + 3 * 4] = 5.0;
    matmul(4, N, N, N2);
    matmul(4, N2, N, N3);
    for (int i = 0; i < 16; i++)
        R[i] = N[i] + N2[i] / 2 + N3[i] / 6 + (i % 5 == 0 ? 1 : 0);
    tsi_expm(4, N, E, &s, &err);
    CHECK(max_abs_diff(4, E, R) < 1e-13 * 30, "expm of a nilpotent matrix is "
          "its finite series (err %.2g; entries up to ~30)",
          max_abs_diff(4, E, R));
    /* Small norms: each Pade degree (3, 5, 7, 9) against Taylor. */
    double norms[4] = {0.01, 0.2, 0.9, 2.0};
    for (int k = 0; k < 4; k++) {
        int n = 5;
        double A[25], T[25], X[25];
        double sum = 0;
        for (int i = 0; i < 25; i++) {
            A[i] = sin(1.3 * i + 0.7);
            sum = fmax(sum, 0);
        }
        double nrm = 0;
        for (int j = 0; j < n; j++) {
            double c = 0;
            for (int i = 0; i < n; i++)
                c += fabs(A[i + j * n]);
            nrm = fmax(nrm, c);
        }
        for (int i = 0; i < 25; i++)
            A[i] *= norms[k] / nrm;
        if (norms[k] < 1)
            taylor(n, A, T);
        else {
            /* exp(A) = exp(A/4)^4 with the Taylor series of A/4. */
            double Q[25], Q2[25];
            for (int i = 0; i < 25; i++)
                Q[i] = A[i] / 4;
            taylor(n, Q, T);
            matmul(n, T, T, Q2);
            matmul(n, Q2, Q2, T);
        }
        tsi_expm(n, A, X, &s, &err);
        CHECK(max_abs_diff(n, X, T) < 1e-14 * exp(norms[k]),
              "expm ||A||_1 = %g (Pade degree for that norm) against Taylor: "
              "err %.2g", norms[k], max_abs_diff(n, X, T));
    }
    /* Diagonalisable: V diag(d) V^-1 with V = I + upper; V^-1 by hand. */
    {
        double d[3] = {-3.7, 0.25, 1.9};
        double V[9] = {1, 0, 0, 0.5, 1, 0, -2, 0.3, 1};
        /* V^-1 for unit upper triangular [[1, .5, -2], [0, 1, .3], [0,0,1]]. */
        double Vi[9] = {1, 0, 0, -0.5, 1, 0, 2 + 0.5 * 0.3, -0.3, 1};
        double D[9] = {0}, tmp[9], A[9], eD[9] = {0}, Ref[9], X[9];
        for (int i = 0; i < 3; i++) {
            D[i * 4] = d[i];
            eD[i * 4] = exp(d[i]);
        }
        matmul(3, V, D, tmp);
        matmul(3, tmp, Vi, A);
        matmul(3, V, eD, tmp);
        matmul(3, tmp, Vi, Ref);
        tsi_expm(3, A, X, &s, &err);
        CHECK(max_abs_diff(3, X, Ref) < 1e-13 * 30,
              "expm of V D V^-1 is V e^D V^-1 (err %.2g)",
              max_abs_diff(3, X, Ref));
    }
    /* exp(A) exp(-A) = I for a 30 x 30 matrix of norm ~ 8. */
    {
        int n = 30;
        double *A = malloc(n * n * sizeof *A), *M = malloc(n * n * sizeof *M);
        double *E1 = malloc(n * n * sizeof *E1), *E2 = malloc(n * n * sizeof *E2);
        double *P = malloc(n * n * sizeof *P), *I = calloc(n * n, sizeof *I);
        for (int i = 0; i < n * n; i++) {
            A[i] = 0.6 * sin(0.37 * i * i + 1.1 * i);
            M[i] = -A[i];
        }
        for (int i = 0; i < n; i++)
            I[i + i * n] = 1;
        tsi_expm(n, A, E1, &s, &err);
        tsi_expm(n, M, E2, NULL, &err);
        matmul(n, E1, E2, P);
        double e = max_abs_diff(n, P, I), big = 0;
        for (int i = 0; i < n * n; i++)
            big = fmax(big, fabs(E1[i]));
        CHECK(e < 1e-12 * big, "exp(A) exp(-A) = I, n = 30, %d squarings "
              "(err %.2g, max |exp A| %.2g)", s, e, big);
        free(A);
        free(M);
        free(E1);
        free(E2);
        free(P);
        free(I);
    }
    double bad[4] = {1, NAN, 0, 1}, out[4];
    CHECK(tsi_expm(2, bad, out, NULL, &err) == TS_EINVAL &&
              strstr(err.msg, "non-finite"),
          "expm refuses NaN: %s", err.msg);
    CHECK(tsi_expm(0, bad, out, NULL, &err) == TS_EINVAL, "expm refuses n 0");
}

/* ---- scenes ----------------------------------------------------------- */

/* Six unequal links and a sphere in vacuum, tow point fixed. */
static const char *vacuum_chain =
    "name: vacuum_chain\n"
    "environment: {water_density: 0, gravity: 9.80665}\n"
    "tow: {speed: 0}\n"
    "cables:\n"
    "  - {name: chain, from: tow, to: bob, length: 2.385, diameter: 0.01,\n"
    "     mass_per_length: 0.37, links: 6,\n"
    "     link_lengths: [0.3, 0.5, 0.285, 0.4, 0.6, 0.3]}\n"
    "bodies:\n"
    "  - {name: bob, type: sphere, diameter: 0.05, mass: 0.213}\n";

/* Kamman example 3's cable and sphere with the tow point 1 m deep, so
 * that nothing crosses the surface (f smooth). */
static const char *ex3_submerged =
    "name: ex3_submerged\n"
    "environment: {water_density: 1.9905 slug/ft^3, gravity: 32.174 ft/s^2}\n"
    "tow: {speed: 2.5 ft/s, point: [0, 0, 1]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: 6 ft,\n"
    "     diameter: 0.163 in, weight: 0.008979 lbf/ft, links: 8}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: 2 in, weight: 0.246 lbf}\n";

static const char *ex1_small =
    "name: ex1_small\n"
    "environment: {water_density: 1.9905 slug/ft^3, gravity: 32.174 ft/s^2}\n"
    "tow: {speed: 8.345 ft/s}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: 100 ft,\n"
    "     diameter: 1 in, weight: 1 lbf/ft, links: 10}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: 10 in, weight: 50 lbf}\n";

static double cable_length(const ts_system *sys)
{
    double L = 0;
    for (int c = 0; c < sys->ncables; c++)
        L += sys->cables[c].length;
    return L;
}

/* ---- 2. energy -------------------------------------------------------- */

static void test_energy(void)
{
    ts_err err = {0};
    ts_scene *sc = scene(vacuum_chain);
    ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    int n = ts_kernel_nstate(k), nq = n / 2;
    double *y = calloc(n, sizeof *y);
    /* Released 20 deg below horizontal, pointing mostly to starboard
     * (theta2 = -70 deg: |cos theta2| = 0.34, near the re-chart threshold),
     * with angle rates that swing the chain through sideways directions. */
    ts_sim_released_state(k, 20 * M_PI / 180, -70 * M_PI / 180, y, &err);
    for (int l = 0; l < nq / 2; l++) {
        y[nq + 2 * l] = 0.8 - 0.1 * l;
        y[nq + 2 * l + 1] = -0.5 + 0.15 * l;
    }
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 20.0;
    o.dt_sample = 0.05;
    o.rel_tol = 1e-11;
    o.abs_tol = 1e-12;
    ts_history *h = ts_history_alloc(sys, ts_sim_nsamples(&o), &err);
    ts_sim_stats st;
    int rc = ts_simulate(k, NULL, y, &o, h, &st, NULL, &err);
    CHECK(rc == TS_OK && h->nsamples == ts_sim_nsamples(&o),
          "vacuum chain simulated 20 s (%s)", err.msg);
    double m = 0.213;
    for (int i = 1; i < sys->nnodes; i++)
        m = fmax(m, 0); /* total mass below */
    m = 0.37 * 2.385 + 0.213;
    double scale = m * 9.80665 * 2.385, E0 = h->energy[0] + h->energy[1];
    double drift = 0;
    for (int i = 0; i < h->nsamples; i++)
        drift = fmax(drift, fabs(h->energy[2 * i] + h->energy[2 * i + 1] - E0));
    CHECK(drift / scale < 1e-6, "energy conserved in vacuum: max |E - E0| / "
          "(m g L) = %.2g < 1e-6 (%ld steps, %ld re-charts)", drift / scale,
          st.steps, st.recharts);
    CHECK(st.recharts > 0 && st.restarts > 0, "the swing went through "
          "re-charts (%ld links moved, %ld restarts)", st.recharts,
          st.restarts);
    /* Kinetic energy really changes: the test is not vacuous. */
    double tmin = 1e300, tmax = 0;
    for (int i = 0; i < h->nsamples; i++) {
        tmin = fmin(tmin, h->energy[2 * i]);
        tmax = fmax(tmax, h->energy[2 * i]);
    }
    CHECK((tmax - tmin) / scale > 0.1, "kinetic energy swings by %.2f m g L",
          (tmax - tmin) / scale);
    ts_history_free(h);
    free(y);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* ---- 3. steady tow ---------------------------------------------------- */

static void test_steady(void)
{
    ts_err err = {0};
    ts_scene *sc = scene(ex1_small);
    ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    int rc = ts_equilibrium_solve(k, &eo, eq, &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 20.0;
    o.dt_sample = 1.0;
    ts_history *h = ts_history_alloc(sys, ts_sim_nsamples(&o), &err);
    ts_sim_stats st;
    rc = ts_simulate(k, NULL, eq->y, &o, h, &st, NULL, &err);
    double L = cable_length(sys), drift = 0;
    for (int i = 0; i < h->nsamples; i++)
        for (int j = 0; j < 3 * sys->nnodes; j++)
            drift = fmax(drift, fabs(h->positions[3 * sys->nnodes * i + j] -
                                     eq->positions[j]));
    CHECK(rc == TS_OK && drift / L < 1e-8, "steady tow at its equilibrium "
          "stays: max |r - r_eq| / L = %.2g < 1e-8 over 20 s (eq residual "
          "%.2g)", drift / L, eq->residual);
    ts_history_free(h);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}


/* ---- 4, 5. linear against nonlinear ----------------------------------- */

typedef struct lin_case {
    ts_scene *sc;
    ts_system *sys;
    ts_kernel *k;
    ts_equilibrium *eq;
    ts_linear *lin;
    ts_output out;
} lin_case;

static void lin_case_open(lin_case *c, const char *text, const char *output)
{
    ts_err err = {0};
    c->sc = scene(text);
    c->sys = c->sc->system;
    c->k = ts_kernel_alloc(c->sys, &err);
    c->eq = ts_equilibrium_alloc(c->sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    int rc = ts_equilibrium_solve(c->k, &eo, c->eq, &err);
    c->lin = ts_linear_alloc(c->k, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.frame_inputs = 1; /* the manoeuvres' on the sparse model (6b) */
    if (!rc)
        rc = ts_linearize_equilibrium(c->k, c->eq, &lo, c->lin, &err);
    if (!rc)
        rc = ts_response_output_find(c->sys, output, &c->out, &err);
    if (rc) {
        printf("FAIL setting up %s: %s\n", c->sys->name, err.msg);
        exit(1);
    }
}

static void lin_case_close(lin_case *c)
{
    ts_linear_free(c->lin);
    ts_equilibrium_free(c->eq);
    ts_kernel_free(c->k);
    ts_scene_free(c->sc);
}

/* Run both models under a heave sine of amplitude A (m) and frequency f;
 * compare over the second half. Histories returned when wanted. */
static int run_pair(lin_case *c, double A, double f, double t_end,
                    const ts_sim_opts *base, ts_compare *cmp,
                    ts_history **hn_out, ts_history **hl_out)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal s = {0};
    s.type = TS_SIGNAL_SINE;
    s.axis = TS_AXIS_HEAVE;
    s.amplitude = A;
    s.frequency = f;
    ts_excitation_add(ex, &s, &err);
    ts_sim_opts o = *base;
    o.t_end = t_end;
    int N = ts_sim_nsamples(&o);
    ts_history *hn = ts_history_alloc(c->sys, N, &err);
    ts_history *hl = ts_history_alloc(c->sys, N, &err);
    ts_kernel *k2 = ts_kernel_clone(c->k, &err);
    ts_sim_stats st;
    int rc = ts_simulate(k2, ex, c->lin->y0, &o, hn, &st, NULL, &err);
    if (!rc)
        rc = ts_simulate_linear(c->k, c->lin, ex, NULL, &o, hl, &st, &err);
    if (!rc)
        rc = ts_compare_histories(c->sys, c->lin, ex, hn, hl, &c->out,
                                  t_end / 2, cmp, &err);
    if (rc)
        printf("note: run_pair: %s\n", err.msg);
    ts_kernel_free(k2);
    ts_excitation_free(ex);
    if (hn_out)
        *hn_out = hn;
    else
        ts_history_free(hn);
    if (hl_out)
        *hl_out = hl;
    else
        ts_history_free(hl);
    return rc;
}

static void test_small_amplitude(void)
{
    lin_case c;
    lin_case_open(&c, ex3_submerged, "sphere.z");
    double L = cable_length(c.sys), A = 1e-4 * L, f = 0.4;
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.dt_sample = 0.05;
    o.rel_tol = 1e-9;
    o.abs_tol = 1e-12;
    ts_compare cmp;
    ts_history *hl;
    int rc = run_pair(&c, A, f, 30.0, &o, &cmp, NULL, &hl);
    CHECK(rc == TS_OK, "small-amplitude runs");
    /* The nonlinear error is O(A) relative: 1e-4 of the cable length
     * leaves it near 1e-4, far inside 1 %. */
    CHECK_REL(cmp.nonlinear.amplitude_ratio, cmp.pred_ratio, 0.01,
              "nonlinear amplitude ratio = |H(i w)| at A = 1e-4 L");
    CHECK_NEAR(cmp.nonlinear.phase_deg, cmp.pred_phase_deg, 1.0,
               "nonlinear phase = arg H(i w) (deg)");
    /* The linear run differs from H only by the decayed transient
     * (15 s of it) and the cubic hold (rel_tol 1e-9). */
    CHECK_REL(cmp.linear.amplitude_ratio, cmp.pred_ratio, 1e-4,
              "linear (expm) amplitude ratio = |H(i w)|");
    CHECK_NEAR(cmp.linear.phase_deg, cmp.pred_phase_deg, 0.01,
               "linear (expm) phase = arg H(i w) (deg)");
    CHECK(fabs(cmp.linear.mean_offset) < 1e-4 * A, "linear mean offset is "
          "nil but for the decaying transient (%.2g m < 1e-4 A, A = %.3g m)",
          cmp.linear.mean_offset, A);

    /* Second method: the same linear model by the ODE integrator. */
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal s = {0};
    s.type = TS_SIGNAL_SINE;
    s.axis = TS_AXIS_HEAVE;
    s.amplitude = A;
    s.frequency = f;
    ts_excitation_add(ex, &s, &err);
    o.t_end = 30.0;
    o.linear_method = TS_LINSIM_ODE;
    ts_history *h2 = ts_history_alloc(c.sys, ts_sim_nsamples(&o), &err);
    ts_sim_stats st;
    rc = ts_simulate_linear(c.k, c.lin, ex, NULL, &o, h2, &st, &err);
    double d = 0;
    for (int i = 0; i < h2->nsamples * 3 * c.sys->nnodes; i++)
        d = fmax(d, fabs(h2->positions[i] - hl->positions[i]));
    CHECK(rc == TS_OK && d < 1e-6 * A, "linear runs by expm and by rk8pd "
          "agree: max |dr| = %.2g m < 1e-6 A (both at tolerance 1e-9)", d);
    /* Nonlinear kinematics of a linear run differ at second order only. */
    o.linear_method = TS_LINSIM_EXPM;
    o.kinematics = TS_KIN_NONLINEAR;
    h2->nsamples = 0;
    rc = ts_simulate_linear(c.k, c.lin, ex, NULL, &o, h2, &st, &err);
    d = 0;
    for (int i = 0; i < h2->nsamples * 3 * c.sys->nnodes; i++)
        d = fmax(d, fabs(h2->positions[i] - hl->positions[i]));
    CHECK(rc == TS_OK && d < 1e-3 * A, "nonlinear kinematics of the linear "
          "run: max |dr| = %.2g m, second order (< 1e-3 A)", d);
    ts_history_free(h2);
    ts_history_free(hl);
    ts_excitation_free(ex);
    lin_case_close(&c);
}

static void test_second_order(void)
{
    lin_case c;
    lin_case_open(&c, ex3_submerged, "sphere.z");
    double L = cable_length(c.sys), f = 0.6;
    double amps[2] = {0.02 * L, 0.01 * L};
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.dt_sample = 0.05;
    o.rel_tol = 1e-10;
    o.abs_tol = 1e-12;
    ts_compare cmp[2];
    for (int i = 0; i < 2; i++)
        run_pair(&c, amps[i], f, 20.0, &o, &cmp[i], NULL, NULL);
    double r = cmp[0].rms_difference / cmp[1].rms_difference;
    double rr = cmp[0].rms_difference_ratio / cmp[1].rms_difference_ratio;
    /* O(A^2) differences with an O(A^3) remainder of relative size ~A/L
     * (a few %): ratio 4 within 10 %. */
    CHECK(fabs(r - 4.0) < 0.4, "halving the amplitude quarters the RMS "
          "linear-nonlinear difference: ratio %.3f (4 +- 0.4; %.3g m, "
          "%.3g m)", r, cmp[0].rms_difference, cmp[1].rms_difference);
    CHECK(fabs(rr - 2.0) < 0.2, "... so the difference relative to the "
          "amplitude halves: ratio %.3f (2 +- 0.2)", rr);
    double mr = cmp[0].nonlinear.mean_offset / cmp[1].nonlinear.mean_offset;
    CHECK(fabs(mr - 4.0) < 0.4, "the nonlinear mean offset is second order "
          "(ratio %.3f, 4 +- 0.4)", mr);
    lin_case_close(&c);
}

/* ---- 6. into the turn ------------------------------------------------- */

static void test_turn(void)
{
    ts_err err = {0};
    ts_scene *sc = scene(ex3_submerged);
    ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq0 = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium *eq1 = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    int rc = ts_equilibrium_solve(k, &eo, eq0, &err);
    /* The steady turn, on its own kernel. */
    ts_kernel *kt = ts_kernel_alloc(sys, &err);
    ts_frame fr;
    ts_kernel_get_frame(kt, &fr);
    fr.turn_rate = 0.5;
    ts_kernel_set_frame(kt, &fr);
    rc |= ts_equilibrium_solve(kt, &eo, eq1, &err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    rc |= ts_excitation_parse(ex, "turn_rate:to=0.5rad/s,start=1,duration=2s",
                              units, "test", &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 45.0;
    o.dt_sample = 0.5;
    o.rel_tol = 1e-10;
    o.abs_tol = 1e-12;
    ts_history *h = ts_history_alloc(sys, ts_sim_nsamples(&o), &err);
    ts_sim_stats st;
    if (!rc)
        rc = ts_simulate(k, ex, eq0->y, &o, h, &st, NULL, &err);
    double L = cable_length(sys), d = 0, d0 = 0;
    const double *pl = h->positions + 3 * sys->nnodes * (h->nsamples - 1);
    for (int j = 0; j < 3 * sys->nnodes; j++) {
        d = fmax(d, fabs(pl[j] - eq1->positions[j]));
        d0 = fmax(d0, fabs(eq0->positions[j] - eq1->positions[j]));
    }
    CHECK(rc == TS_OK && d / L < 1e-6, "straight tow into the 0.5 rad/s turn "
          "settles onto the steady-turn equilibrium: max |r - r_turn| / L = "
          "%.2g < 1e-6 after %g s (the two equilibria differ by %.3f L)",
          d / L, o.t_end, d0 / L);
    ts_frame fend;
    ts_kernel_get_frame(k, &fend);
    CHECK(fend.turn_rate == 0.0, "the kernel's frame is restored after the "
          "run");
    ts_history_free(h);
    ts_excitation_free(ex);
    ts_equilibrium_free(eq0);
    ts_equilibrium_free(eq1);
    ts_kernel_free(k);
    ts_kernel_free(kt);
    ts_scene_free(sc);
}

/* ---- 6b. manoeuvres in the linear model ------------------------------ */

/* ex3_submerged in its steady 0.5 rad/s turn. */
static const char *ex3_turning =
    "name: ex3_turning\n"
    "environment: {water_density: 1.9905 slug/ft^3, gravity: 32.174 ft/s^2}\n"
    "tow: {speed: 2.5 ft/s, turn_rate: 0.5 rad/s, point: [0, 0, 1]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: sphere, length: 6 ft,\n"
    "     diameter: 0.163 in, weight: 0.008979 lbf/ft, links: 8}\n"
    "bodies:\n"
    "  - {name: sphere, type: sphere, diameter: 2 in, weight: 0.246 lbf}\n";

/* The manoeuvre `spec` (its change given by `by=`) run by both models
 * from the equilibrium of c: the largest difference of any node's
 * position between them over the run (*run), and of the linear run's
 * last positions from the equilibrium re-solved in the final frame
 * (*end; the manoeuvre over by then); the largest difference between the
 * linear runs on the dense and the sparse model (*sparse), and the
 * largest move of a node in the dense one (*moved). */
static void manoeuvre_pair(lin_case *c, const char *spec, double t_end,
                           double *run, double *end, double *sparse,
                           double *moved)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    int rc = ts_excitation_parse(ex, spec, units, "test", &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = t_end;
    o.dt_sample = 0.1;
    o.rel_tol = 1e-10;
    o.abs_tol = 1e-13;
    int N = ts_sim_nsamples(&o);
    ts_history *hn = ts_history_alloc(c->sys, N, &err);
    ts_history *hl = ts_history_alloc(c->sys, N, &err);
    ts_history *hs = ts_history_alloc(c->sys, N, &err);
    ts_kernel *k2 = ts_kernel_clone(c->k, &err);
    ts_sim_stats st;
    if (!rc)
        rc = ts_simulate(k2, ex, c->lin->y0, &o, hn, &st, NULL, &err);
    if (!rc)
        rc = ts_simulate_linear(c->k, c->lin, ex, NULL, &o, hl, &st, &err);
    /* The same linear run on the sparse model (its frame columns Gf). */
    ts_sim_opts os = o;
    os.linear_method = TS_LINSIM_SPARSE;
    if (!rc)
        rc = ts_simulate_linear(c->k, c->lin, ex, NULL, &os, hs, &st, &err);
    /* The final frame's equilibrium. */
    ts_frame f0, f1;
    ts_kernel_get_frame(c->k, &f0);
    ts_excitation_frame(ex, &f0, t_end, &f1);
    f1.speed_rate = f1.turn_accel = 0.0;
    ts_kernel_set_frame(k2, &f1);
    ts_equilibrium *eq = ts_equilibrium_alloc(c->sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    eo.tol = 1e-13;
    if (!rc)
        rc = ts_equilibrium_solve(k2, &eo, eq, &err);
    *run = *end = *sparse = *moved = NAN;
    if (!rc) {
        int nn3 = 3 * c->sys->nnodes;
        *run = *sparse = *moved = 0.0;
        for (int i = 0; i < hn->nsamples * nn3; i++) {
            *run = fmax(*run, fabs(hn->positions[i] - hl->positions[i]));
            *sparse = fmax(*sparse, fabs(hs->positions[i] -
                                         hl->positions[i]));
            *moved = fmax(*moved, fabs(hl->positions[i] -
                                       hl->positions[i % nn3]));
        }
        const double *last = hl->positions + (size_t)(hl->nsamples - 1) * nn3;
        *end = 0.0;
        for (int j = 0; j < nn3; j++)
            *end = fmax(*end, fabs(last[j] - eq->positions[j]));
    } else {
        printf("note: manoeuvre_pair %s: %s\n", spec, err.msg);
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k2);
    ts_history_free(hn);
    ts_history_free(hl);
    ts_history_free(hs);
    ts_excitation_free(ex);
}

static void test_manoeuvre_linear(void)
{
    /* Steps in speed and turn rate, in straight tow and in the turn. The
     * linear model takes them as its frame inputs; its state is the
     * deviation from the initial equilibrium in the commanded frame, the
     * nonlinear run's frame, so the two differ at second order in the
     * step: halving it quarters the difference (its O(step^3) remainder
     * is a few % here: ratio 4 within 10 %). */
    struct {
        const char *scene, *what, *fmt;
        double by;
    } cases[] = {
        {ex3_submerged, "speed step in straight tow",
         "speed:type=step,by=%g,start=1,rise=1.5", 0.08},
        {ex3_submerged, "turn-rate ramp from straight tow",
         "turn_rate:by=%g,start=1,duration=2,rise=0.5", 0.2},
        {ex3_turning, "speed step in the 0.5 rad/s turn",
         "speed:type=step,by=%g,start=1,rise=1.5", -0.08},
        {ex3_turning, "turn-rate step in the turn",
         "turn_rate:type=step,by=%g,start=1,rise=1.5", 0.1}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        lin_case c;
        lin_case_open(&c, cases[i].scene, "sphere.z");
        double run[2], end[2], sp[2], moved[2];
        char spec[128];
        for (int h = 0; h < 2; h++) {
            snprintf(spec, sizeof spec, cases[i].fmt, cases[i].by / (1 << h));
            manoeuvre_pair(&c, spec, 25.0, &run[h], &end[h], &sp[h],
                           &moved[h]);
        }
        /* The sparse model's run (its frame columns Gf) against the
         * dense one's: two linearizations of the same system (truncation
         * about 1e-9 of the model) integrated to 1e-10: within 1e-7 of
         * the motion. */
        CHECK(sp[0] <= 1e-7 * moved[0] && sp[1] <= 1e-7 * moved[1],
              "%s: the linear run on the sparse model = the dense one's: "
              "%.3g m apart on a motion of %.3g m (%.3g and %.3g at half "
              "the step; <= 1e-7 of it)", cases[i].what, sp[0], moved[0],
              sp[1], moved[1]);
        double r = run[0] / run[1], re = end[0] / end[1];
        CHECK(fabs(r - 4.0) < 0.4, "%s: linear against nonlinear, the "
              "largest position difference %.3g m at %g, %.3g m at half "
              "of it: ratio %.3f (4 +- 0.4)", cases[i].what, run[0],
              cases[i].by, run[1], r);
        /* At the end (22 s after the step, the slowest mode's time
         * constant is under 2 s) the linear run has settled on the
         * equilibrium of the final frame to first order. */
        CHECK(fabs(re - 4.0) < 0.4, "%s: the linear run's final shape "
              "against the equilibrium re-solved in the final frame: "
              "%.3g m, %.3g m at half the step, ratio %.3f (4 +- 0.4)",
              cases[i].what, end[0], end[1], re);
        lin_case_close(&c);
    }
}

/* ---- 7. implicit integrators ----------------------------------------- */

static void test_implicit(void)
{
    ts_err err = {0};
    ts_scene *sc = scene(ex3_submerged);
    ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    ts_equilibrium_solve(k, &eo, eq, &err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_excitation_parse(ex, "tow.heave:amplitude=0.05,frequency=0.7", units,
                        "test", &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 4.0;
    o.dt_sample = 0.5;
    o.rel_tol = 1e-9;
    o.abs_tol = 1e-11;
    int N = ts_sim_nsamples(&o);
    ts_history *ref = ts_history_alloc(sys, N, &err);
    ts_kernel *kr = ts_kernel_clone(k, &err);
    ts_sim_stats st;
    ts_simulate(kr, ex, eq->y, &o, ref, &st, NULL, &err);
    double L = cable_length(sys);
    ts_integrator m[4] = {TS_INT_RK4IMP, TS_INT_BSIMP, TS_INT_MSBDF,
                          TS_INT_ESDIRK};
    for (int i = 0; i < 4; i++) {
        ts_history *h = ts_history_alloc(sys, N, &err);
        ts_kernel *kc = ts_kernel_clone(k, &err);
        o.integrator = m[i];
        ts_err_clear(&err);
        int rc = ts_simulate(kc, ex, eq->y, &o, h, &st, NULL, &err);
        double d = 0;
        for (int j = 0; j < N * 3 * sys->nnodes && !rc; j++)
            d = fmax(d, fabs(h->positions[j] - ref->positions[j]));
        /* Both at tolerance 1e-9 per step; over ~1e3 steps the global
         * errors stay below ~1e-6 of the length. */
        CHECK(rc == TS_OK && d / L < 1e-6 && st.jacobians > 0,
              "%s (%ld Jacobians from the linearizer) agrees with rk8pd: "
              "max |dr| / L = %.2g < 1e-6 (%s)", ts_integrator_name(m[i]),
              st.jacobians, d / L, err.msg);
        ts_history_free(h);
        ts_kernel_free(kc);
    }
    ts_history_free(ref);
    ts_kernel_free(kr);
    ts_excitation_free(ex);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

/* ---- 8. shapes, samples, fit, reports, refusals ------------------------ */

static void test_misc(void)
{
    ts_err err = {0};
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 30;
    o.dt_sample = 3;
    CHECK(ts_sim_nsamples(&o) == 11 && ts_sim_sample_time(&o, 10) == 30,
          "30 s every 3 s: 11 samples ending at 30 s");
    o.t_end = 1.0;
    o.dt_sample = 0.3;
    CHECK(ts_sim_nsamples(&o) == 5 && ts_sim_sample_time(&o, 3) == 0.3 * 3 &&
              ts_sim_sample_time(&o, 4) == 1.0,
          "1 s every 0.3 s: 0, 0.3, 0.6, 0.9, 1");
    o.t_end = 60;
    o.dt_sample = 0.1;
    CHECK(ts_sim_nsamples(&o) == 601, "60 s every 0.1 s: 601 samples (%d)",
          ts_sim_nsamples(&o));

    struct { double t_end, dt, rtol; const char *want; } bad[] = {
        {-1, 0.1, 1e-6, "t_end must be > 0 s"},
        {10, 0, 1e-6, "sample interval must be > 0 s"},
        {10, 20, 1e-6, "longer than the run"},
        {10, 0.1, 0, "relative tolerance"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ts_sim_opts_default(&o);
        o.t_end = bad[i].t_end;
        o.dt_sample = bad[i].dt;
        o.rel_tol = bad[i].rtol;
        CHECK(ts_sim_opts_check(&o, &err) == TS_EINVAL &&
                  strstr(err.msg, bad[i].want),
              "options refused: %s", err.msg);
    }

    /* Fit: an exact sinusoid over 2.3 periods (not whole) is recovered. */
    double t[200], x[200];
    for (int i = 0; i < 200; i++) {
        t[i] = 3.0 + 0.0115 * i;
        x[i] = 0.125 + 0.0317 * sin(2 * M_PI * t[i] + 0.6);
    }
    double c, a, ph;
    int rc = ts_compare_fit_sinusoid(t, x, 200, 1.0, &c, &a, &ph, &err);
    CHECK(rc == TS_OK && fabs(c - 0.125) < 1e-15 && fabs(a - 0.0317) < 1e-15 &&
              fabs(ph - 0.6) < 1e-12,
          "sinusoid fit over 2.3 periods exact (c %.17g, a %.17g, phase "
          "%.17g)", c, a, ph);
    for (int i = 0; i < 200; i++)
        t[i] = 1.0 * i; /* sampled once per period: nothing to fit */
    rc = ts_compare_fit_sinusoid(t, x, 200, 1.0, &c, &a, &ph, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "do not resolve"),
          "fit refuses samples that do not resolve the frequency: %s",
          err.msg);

    /* Shapes: a released shape and the same shape from positions. */
    ts_scene *sc = scene(vacuum_chain);
    ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    int n = ts_kernel_nstate(k);
    double *y = calloc(n, sizeof *y), *y2 = calloc(n, sizeof *y2);
    double *dy = calloc(n, sizeof *dy);
    ts_sim_released_state(k, 0.3, 0.2, y, &err);
    ts_kernel_eval(k, y, NULL, dy);
    double *pos = malloc(3 * sys->nnodes * sizeof *pos);
    memcpy(pos, ts_kernel_positions(k), 3 * sys->nnodes * sizeof *pos);
    const double *last = pos + 3 * (sys->nnodes - 1);
    double nref[3] = {-cos(0.3) * cos(0.2), -sin(0.2), sin(0.3) * cos(0.2)};
    CHECK(fabs(last[0] - 2.385 * nref[0]) < 1e-14 &&
              fabs(last[1] - 2.385 * nref[1]) < 1e-14 &&
              fabs(last[2] - 2.385 * nref[2]) < 1e-14,
          "released shape: the free end at L n(theta1, theta2)");
    rc = ts_sim_shape_state(k, pos, 1e-9, y2, &err);
    ts_kernel_eval(k, y2, NULL, dy);
    double d = 0;
    for (int j = 0; j < 3 * sys->nnodes; j++)
        d = fmax(d, fabs(ts_kernel_positions(k)[j] - pos[j]));
    CHECK(rc == TS_OK && d < 1e-14, "shape from positions reproduces them "
          "(%.2g m)", d);
    pos[3 * 2 + 0] += 0.01;
    rc = ts_sim_shape_state(k, pos, 1e-6, y2, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "link 2 of cable 'chain'"),
          "a shape with a wrong link length is refused: %s", err.msg);

    /* A history that grows; refusals of a run: underflow keeps the history;
     * h_min; the step limit; a manoeuvre in a linear run. */
    ts_sim_opts_default(&o);
    o.t_end = 2.0;
    o.dt_sample = 0.1;
    ts_history *h = ts_history_alloc(sys, 5, &err);
    ts_sim_stats st;
    memset(&err, 0, sizeof err);
    /* Each run on its own clone: a run may re-chart its kernel. */
    ts_kernel *k1 = ts_kernel_clone(k, &err), *k2 = ts_kernel_clone(k, &err);
    rc = ts_simulate(k1, NULL, y, &o, h, &st, NULL, &err);
    ts_history *full = ts_history_alloc(sys, ts_sim_nsamples(&o), &err);
    int rc2 = ts_simulate(k2, NULL, y, &o, full, NULL, NULL, &err);
    ts_kernel_free(k1);
    ts_kernel_free(k2);
    int same = rc == TS_OK && rc2 == TS_OK && h->nsamples == full->nsamples;
    size_t nn = 3 * (size_t)sys->nnodes;
    for (size_t i = 0; same && i < (size_t)h->nsamples; i++)
        same = h->t[i] == full->t[i] &&
               !memcmp(h->positions + nn * i, full->positions + nn * i,
                       nn * sizeof(double)) &&
               isnan(h->frame[3 * i]);
    CHECK(same && h->capacity >= ts_sim_nsamples(&o) && h->capacity < 2 *
                                                            ts_sim_nsamples(&o),
          "a history of 5 samples grows to hold the run's %d (capacity %d), "
          "the same samples as one allocated whole (%s)",
          ts_sim_nsamples(&o), h->capacity, err.msg);
    ts_history_free(full);
    ts_history_free(h);
    h = ts_history_alloc(sys, ts_sim_nsamples(&o), &err);
    /* Underflow: at t = 1e15 s the spacing of doubles is 0.125 s, far
     * above any step this swinging chain can take at 1e-10. */
    o.rel_tol = 1e-10;
    ts_sim *sim = ts_sim_alloc(k, NULL, &o, &err);
    rc = ts_sim_set_state(sim, 1e15, y, &err);
    if (!rc)
        rc = ts_sim_advance(sim, 1e15 + 10.0, &err);
    CHECK(rc == TS_EINTEGRATOR && strstr(err.msg, "step size underflowed") &&
              ts_sim_time(sim) == 1e15,
          "step-size underflow reported, the state kept at the last time: "
          "%s", err.msg);
    ts_sim_free(sim);
    o.rel_tol = 1e-15;
    CHECK(ts_sim_opts_check(&o, &err) == TS_EINVAL &&
              strstr(err.msg, "[1e-14, 1)"),
          "a tolerance below 1e-14 is refused: %s", err.msg);
    ts_sim_opts_default(&o);
    o.t_end = 2.0;
    o.dt_sample = 0.1;
    o.h_min = 0.05;
    h->nsamples = 0;
    rc = ts_simulate(k, NULL, y, &o, h, &st, NULL, &err);
    CHECK(rc == TS_EINTEGRATOR && strstr(err.msg, "below h_min") &&
              h->nsamples >= 1,
          "h_min enforced, %d samples kept: %s", h->nsamples, err.msg);
    o.h_min = 0;
    o.max_steps = 20;
    h->nsamples = 0;
    rc = ts_simulate(k, NULL, y, &o, h, &st, NULL, &err);
    CHECK(rc == TS_EINTEGRATOR && strstr(err.msg, "step limit 20") &&
              h->nsamples >= 1 && h->nsamples < ts_sim_nsamples(&o),
          "step limit enforced after %d samples: %s", h->nsamples, err.msg);
    ts_history_free(h);
    /* A chain at rest in equilibrium takes one step per output interval:
     * every step ends on an output time, and the limit still counts. */
    {
        ts_scene *s3 = scene(ex1_small);
        ts_kernel *k3 = ts_kernel_alloc(s3->system, &err);
        ts_equilibrium *eq = ts_equilibrium_alloc(s3->system, &err);
        ts_equilibrium_solve(k3, NULL, eq, &err);
        ts_sim_opts_default(&o);
        o.t_end = 10.0;
        o.dt_sample = 0.5;
        o.max_steps = 7;
        ts_history *h3 = ts_history_alloc(s3->system, ts_sim_nsamples(&o),
                                          &err);
        rc = ts_simulate(k3, NULL, eq->y, &o, h3, &st, NULL, &err);
        CHECK(rc == TS_EINTEGRATOR && strstr(err.msg, "step limit 7") &&
                  st.steps == 7 && st.t_reached < o.t_end,
              "the step limit counts steps that end on output times: %ld "
              "steps to t = %g s: %s", st.steps, st.t_reached, err.msg);
        o.max_steps = 0;
        h3->nsamples = 0;
        rc = ts_simulate(k3, NULL, eq->y, &o, h3, &st, NULL, &err);
        long need = st.steps;
        o.max_steps = need;
        h3->nsamples = 0;
        rc |= ts_simulate(k3, NULL, eq->y, &o, h3, &st, NULL, &err);
        CHECK(rc == TS_OK && st.steps == need,
              "a limit of the %ld steps the run needs is enough (%s)", need,
              rc ? err.msg : "ok");
        ts_history_free(h3);
        ts_equilibrium_free(eq);
        ts_kernel_free(k3);
        ts_scene_free(s3);
    }
    free(y);
    free(y2);
    free(dy);
    free(pos);
    ts_kernel_free(k);
    ts_scene_free(sc);

    /* A steady turn in a current, no excitation: the current, fixed in
     * inertial space, rotates in M by -Omega t; the kernel's frame after
     * recording the sample at t = 2 s is that of t = 2 s. */
    {
        ts_scene *s2 = scene(ex3_submerged);
        ts_kernel *k2 = ts_kernel_alloc(s2->system, &err);
        int n2 = ts_kernel_nstate(k2);
        double *y3 = calloc(n2, sizeof *y3);
        ts_sim_released_state(k2, 0.6, 0.0, y3, &err);
        ts_frame fr;
        ts_kernel_get_frame(k2, &fr);
        fr.turn_rate = 0.3;
        fr.current[0] = 0.1;
        fr.current[1] = 0.0;
        ts_kernel_set_frame(k2, &fr);
        ts_sim_opts_default(&o);
        o.t_end = 2.0;
        o.dt_sample = 2.0;
        ts_history *h2 = ts_history_alloc(s2->system, 2, &err);
        ts_sim *sim = ts_sim_alloc(k2, NULL, &o, &err);
        rc = ts_sim_set_state(sim, 0.0, y3, &err);
        if (!rc)
            rc = ts_sim_advance(sim, 2.0, &err);
        if (!rc)
            rc = ts_sim_record(sim, h2, &err);
        ts_frame now;
        ts_kernel_get_frame(k2, &now);
        CHECK(rc == TS_OK && fabs(now.current[0] - 0.1 * cos(0.6)) < 1e-15 &&
                  fabs(now.current[1] + 0.1 * sin(0.6)) < 1e-15,
              "a steady turn without excitation rotates the current in M "
              "(%.6f, %.6f at 2 s; want %.6f, %.6f)", now.current[0],
              now.current[1], 0.1 * cos(0.6), -0.1 * sin(0.6));
        ts_sim_free(sim);
        ts_kernel_get_frame(k2, &now);
        CHECK(now.current[0] == 0.1 && now.current[1] == 0.0 &&
                  now.turn_rate == 0.3,
              "freeing the simulator restores the kernel's frame");
        ts_history_free(h2);
        free(y3);
        ts_kernel_free(k2);
        ts_scene_free(s2);
    }

    lin_case lc;
    lin_case_open(&lc, ex3_submerged, "sphere.z");
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_excitation_parse(ex, "turn_rate:by=0.1,duration=1", units, "test",
                        &err);
    ts_sim_opts_default(&o);
    o.t_end = 1;
    h = ts_history_alloc(lc.sys, ts_sim_nsamples(&o), &err);
    ts_frame fc;
    ts_kernel_get_frame(lc.k, &fc);
    fc.current[0] = 0.05;
    ts_kernel_set_frame(lc.k, &fc);
    rc = ts_simulate_linear(lc.k, lc.lin, ex, NULL, &o, h, &st, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "heading"),
          "a turn-rate manoeuvre in a horizontal current is refused in a "
          "linear run: %s", err.msg);
    fc.current[0] = 0.0;
    ts_kernel_set_frame(lc.k, &fc);

    /* Reports: the comparison JSON has the required keys; the CSV header. */
    ts_compare cmp;
    ts_history *hn, *hl;
    ts_sim_opts_default(&o);
    o.dt_sample = 0.05;
    run_pair(&lc, 0.01, 0.5, 8.0, &o, &cmp, &hn, &hl);
    json_t *j = ts_report_compare_json(&cmp);
    const char *keys[] = {"output", "excitation", "linear", "nonlinear",
                          "response_prediction", "amplitude_difference_pct",
                          "mean_difference_pct"};
    int ok = j != NULL;
    for (size_t i = 0; ok && i < sizeof keys / sizeof keys[0]; i++)
        ok = json_object_get(j, keys[i]) != NULL;
    ok = ok && json_is_real(json_object_get(json_object_get(j, "linear"),
                                            "amplitude_ratio")) &&
         json_is_real(json_object_get(json_object_get(j, "nonlinear"),
                                      "mean_offset")) &&
         json_is_real(json_object_get(json_object_get(j, "excitation"),
                                      "frequency_hz")) &&
         !strcmp(json_string_value(json_object_get(
                     json_object_get(j, "excitation"), "axis")), "tow.heave") &&
         json_is_real(json_object_get(json_object_get(j,
                                      "response_prediction"), "phase_deg"));
    CHECK(ok, "comparison JSON has output, excitation{axis,amplitude,"
          "frequency_hz}, linear/nonlinear{amplitude_ratio,mean_offset}, "
          "response_prediction{amplitude_ratio,phase_deg}, the differences");
    json_decref(j);
    char path[] = "/tmp/towstab_test_simulate_XXXXXX";
    int fd = mkstemp(path);
    close(fd);
    rc = ts_report_history_csv(lc.sys, hn, hl, path, &err);
    FILE *f = fopen(path, "r");
    static char line[65536];
    int rows = 0;
    line[0] = '\0';
    if (f) {
        if (!fgets(line, sizeof line, f))
            line[0] = '\0';
        static char buf[65536];
        while (fgets(buf, sizeof buf, f))
            rows++;
        fclose(f);
    }
    CHECK(rc == TS_OK && !strncmp(line, "t_s,nonlinear.tow.x_m,", 22) &&
              rows == hn->nsamples,
          "history CSV: header '%.40s...', %d rows", line, rows);
    unlink(path);
    j = ts_report_history_json(lc.sys, hn, -1);
    CHECK(j && json_array_size(json_object_get(j, "t")) ==
                   (size_t)hn->nsamples &&
              json_object_get(j, "tensions") && json_object_get(j, "energy"),
          "history JSON with times, nodes, tensions, energy");
    json_decref(j);
    ts_history_free(hn);
    ts_history_free(hl);
    ts_history_free(h);
    ts_excitation_free(ex);
    lin_case_close(&lc);
}

/* ---- 9. progress and stopping ---------------------------------------- */

/* Counts calls, checks that time only grows and stops once it passes
 * `stop_at` (s). */
typedef struct progress_log {
    long calls;
    double last, stop_at, total;
    int backwards;
    const char *what;
} progress_log;

static int log_progress(const ts_progress *p, void *data)
{
    progress_log *l = data;
    l->calls++;
    l->backwards |= p->done < l->last;
    l->last = p->done;
    l->total = p->total;
    l->what = p->what;
    return p->done >= l->stop_at;
}

static void test_progress(void)
{
    ts_err err = {0};
    ts_scene *sc = scene(vacuum_chain);
    ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    int n = ts_kernel_nstate(k);
    double *y = calloc(n, sizeof *y);
    ts_sim_released_state(k, 0.6, 0.2, y, &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 4.0;
    o.dt_sample = 0.25;
    int N = ts_sim_nsamples(&o);
    ts_history *h = ts_history_alloc(sys, N, &err);
    ts_sim_stats st;
    /* To the end: one call per accepted step, time growing to t_end. */
    progress_log l = {0, 0, INFINITY, 0, 0, NULL};
    o.progress = log_progress;
    o.progress_data = &l;
    int rc = ts_simulate(k, NULL, y, &o, h, &st, NULL, &err);
    /* GSL's step count includes the rejected trials. */
    CHECK(rc == TS_OK && l.calls == st.steps - st.rejected && !l.backwards &&
              l.last == o.t_end && l.total == o.t_end &&
              !strcmp(l.what, "nonlinear"),
          "rk8pd: the callback sees every accepted step (%ld calls, %ld "
          "steps, %ld rejected, %ld restarts), time growing to t_end",
          l.calls, st.steps, st.rejected, st.restarts);
    /* Stopped after 1.3 s: TS_ECANCEL, samples up to there kept, and the
     * last one is the state the run stopped at. */
    progress_log s = {0, 0, 1.3, 0, 0, NULL};
    o.progress_data = &s;
    h->nsamples = 0;
    rc = ts_simulate(k, NULL, y, &o, h, &st, NULL, &err);
    double tl = h->nsamples ? h->t[h->nsamples - 1] : -1;
    CHECK(rc == TS_ECANCEL && strstr(err.msg, "stopped on request") &&
              st.t_reached >= 1.3 && st.t_reached < 2.0 &&
              tl == st.t_reached && h->nsamples >= 6 && h->nsamples < N,
          "rk8pd: stopped at t = %g s, %d samples kept, the last at %g s: "
          "%s", st.t_reached, h->nsamples, tl, err.msg);
    /* esdirk stops the same way. */
    o.integrator = TS_INT_ESDIRK;
    progress_log e = {0, 0, 1.3, 0, 0, NULL};
    o.progress_data = &e;
    h->nsamples = 0;
    rc = ts_simulate(k, NULL, y, &o, h, &st, NULL, &err);
    CHECK(rc == TS_ECANCEL && e.calls == st.steps && st.t_reached < 2.5 &&
              h->nsamples >= 5 && h->nsamples < N,
          "esdirk: stopped at t = %g s after %ld calls, %d samples: %s",
          st.t_reached, e.calls, h->nsamples, err.msg);
    ts_history_free(h);
    free(y);
    ts_kernel_free(k);
    ts_scene_free(sc);

    /* Linear (expm): a call per sample; stopped after 1 s. */
    lin_case lc;
    lin_case_open(&lc, ex1_small, "sphere.z");
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_excitation_parse(ex, "tow.heave:amplitude=0.01m,frequency=0.5Hz",
                        units, "test", &err);
    ts_sim_opts_default(&o);
    o.t_end = 4.0;
    o.dt_sample = 0.25;
    progress_log li = {0, 0, 1.0, 0, 0, NULL};
    o.progress = log_progress;
    o.progress_data = &li;
    ts_history *hl = ts_history_alloc(lc.sys, ts_sim_nsamples(&o), &err);
    rc = ts_simulate_linear(lc.k, lc.lin, ex, NULL, &o, hl, &st, &err);
    CHECK(rc == TS_ECANCEL && !strcmp(li.what, "linear") &&
              hl->nsamples == 5 && hl->t[4] == 1.0 && li.calls == 4,
          "linear: stopped at the sample t = 1 s (%d samples, %ld calls): "
          "%s", hl->nsamples, li.calls, err.msg);
    ts_history_free(hl);
    ts_excitation_free(ex);
    lin_case_close(&lc);
}

/* ---- 10. the linear run on the sparse model -------------------------- */

/* The linear run of `path` at `links` under the excitation `spec`
 * through the analysis pipeline (as `towstab simulate --linear` runs
 * it), by linear_method `method`; NULL after printing a failure. */
static ts_result *sparse_run(const char *path, int links, const char *spec,
                             double t_end, ts_linsim_method method)
{
    ts_err err = {0};
    ts_scene *sc = ts_scene_load(path, units, &err);
    if (!sc) {
        CHECK(0, "load %s: %s", path, err.msg);
        return NULL;
    }
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.setup.links = links;
    rq.setup.discretisation_error = 0;
    rq.simulate.linear = 1;
    rq.simulate.compare = 0;
    rq.simulate.check_window = 0;
    rq.simulate.sim.t_end = t_end;
    rq.simulate.sim.dt_sample = 0.1;
    rq.simulate.sim.linear_method = method;
    rq.simulate.excitation = ts_excitation_alloc(&err);
    ts_result *r = NULL;
    int rc = rq.simulate.excitation
                 ? ts_excitation_parse(rq.simulate.excitation, spec, units,
                                       "test", &err)
                 : TS_ENOMEM;
    if (rc == TS_OK)
        rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (rc != TS_OK || !r || r->status != TS_OK || !r->linear) {
        CHECK(0, "linear run of %s at %d links (method %d): %s", path,
              links, (int)method, r && r->error[0] ? r->error : err.msg);
        ts_result_free(r);
        r = NULL;
    }
    ts_request_clear(&rq);
    ts_scene_free(sc);
    return r;
}

/* Max |a - b| of channel `name` over the samples of two linear runs, and
 * its range in a (max - min) into *range. */
static double channel_diff(const ts_result *a, const ts_result *b,
                           const char *name, double *range)
{
    ts_err err = {0};
    ts_output out;
    *range = NAN;
    ts_kernel *k = ts_kernel_alloc(a->sys, &err);
    int rc = k ? ts_response_output_lookup(k, name, &out, &err) : TS_ENOMEM;
    ts_kernel_free(k);
    if (rc != TS_OK || a->linear->nsamples != b->linear->nsamples) {
        CHECK(0, "channel %s of runs with %d and %d samples: %s", name,
              a->linear->nsamples, b->linear->nsamples, err.msg);
        return NAN;
    }
    double d = 0, lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < a->linear->nsamples; i++) {
        double va = ts_history_value(a->sys, a->linear, &out, i);
        double vb = ts_history_value(b->sys, b->linear, &out, i);
        d = isfinite(va) && isfinite(vb) ? fmax(d, fabs(va - vb)) : NAN;
        lo = fmin(lo, va);
        hi = fmax(hi, va);
        if (isnan(d))
            break;
    }
    *range = hi - lo;
    return d;
}

/* The sparse model's linear run (esdirk on lib/shift.h, O(links)) against
 * the dense model's exact discretisation (expm) under the same
 * excitation: both are the same linear system, the dense A and B by
 * central differences of the kernel, the sparse blocks by coloured ones,
 * so they differ by the integration's tolerance (rel_tol 1e-6 of the
 * state) and the linearization's error (relative ~1e-7, as the modes'
 * eigenvalues of the two models agree: doc/linear.md section 3), both
 * below 1e-5 of a channel's swing (measured: at most 2e-6, the heaved
 * AURORA's depth).
 * Then a run at 2000 links forms no dense matrix at all. */
static void test_sparse_linear(void)
{
    struct {
        const char *path, *spec, *ch[3];
        int links;
    } cases[4] = {
        {"examples/kamman_ex1_submerged.yaml",
         "tow.heave:amplitude=1ft,frequency=0.25Hz",
         {"sphere.z", "sphere.x", "cable.1.tension"}, 60},
        /* A towed vehicle: its depth loop's set point stepped (a vehicle
         * input), its depth and wing deflection (outputs) and a
         * tension. */
        {"examples/aurora_towfish.yaml",
         "aurora.depth.setpoint:amplitude=1m,start=1s,rise=2s",
         {"aurora.depth", "aurora.wing.deflection", "armoured.3.tension"},
         40},
        /* The same heaved: the tow input moves the vehicle's node in its
         * outputs (ts_linear_tow_shift). */
        {"examples/aurora_towfish.yaml",
         "tow.heave:amplitude=1m,frequency=0.2Hz",
         {"aurora.depth", "aurora.pitch", "armoured.1.tension"}, 40},
        /* A towing vehicle at the root, its own outputs. */
        {"test/scenes/towing_sphere.yaml",
         "tow.heave:amplitude=0.2m,frequency=0.2Hz",
         {"tug.depth", "tug.pitch", "cable.1.tension"}, 0},
    };
    for (int c = 0; c < 4; c++) {
        ts_result *rd = sparse_run(cases[c].path, cases[c].links,
                                   cases[c].spec, 10.0, TS_LINSIM_EXPM);
        ts_result *rs = sparse_run(cases[c].path, cases[c].links,
                                   cases[c].spec, 10.0, TS_LINSIM_SPARSE);
        if (rd && rs) {
            int nl = rd->sys->nlinks;
            CHECK(rd->lin->A && rd->linear_stats.newton == TS_NEWTON_NONE,
                  "%s at %d links: linear_method expm runs the dense model",
                  cases[c].path, nl);
            CHECK(!rs->lin->A && rs->linear_stats.newton == TS_NEWTON_SPARSE &&
                      !strcmp(ts_linear_method_name(&rs->sim,
                                                    &rs->linear_stats),
                              "esdirk"),
                  "%s at %d links: linear_method sparse forms no dense A "
                  "and runs esdirk with the sparse Newton matrix",
                  cases[c].path, nl);
            for (int k = 0; k < 3; k++) {
                double range, d = channel_diff(rd, rs, cases[c].ch[k], &range);
                CHECK(d <= 1e-5 * range && range > 0,
                      "%s at %d links: %s of the sparse linear run = the "
                      "dense (expm) one: max |difference| %.3g <= 1e-5 of "
                      "its swing %.4g",
                      cases[c].path, nl, cases[c].ch[k], d, range);
            }
        }
        ts_result_free(rd);
        ts_result_free(rs);
    }
    /* 2000 links, 8000 states: the default method (expm) finds no dense
     * model (above dense_max_states the pipeline forms the sparse one
     * alone) and runs on the sparse model. */
    ts_result *r = sparse_run("examples/kamman_ex1_submerged.yaml", 2000,
                              "tow.heave:amplitude=1ft,frequency=0.25Hz",
                              0.5, TS_LINSIM_EXPM);
    if (r) {
        /* The run against itself: 0 when every tension is finite. */
        double range, d = channel_diff(r, r, "cable.1.tension", &range);
        CHECK(!r->lin->A && !r->lin->Ty && r->lin->desc &&
                  r->linear_stats.newton == TS_NEWTON_SPARSE &&
                  r->linear->nsamples == 6 &&
                  fabs(r->linear_stats.t_reached - 0.5) < 1e-12 && d == 0,
              "2000 links: the linear run completes on the sparse model "
              "without a dense A (%d samples to %g s, %ld steps, %.3g s "
              "wall)",
              r->linear->nsamples, r->linear_stats.t_reached,
              r->linear_stats.steps, r->linear_stats.wall_s);
    }
    ts_result_free(r);
}

int main(void)
{
    ts_err err = {0};
    units = ts_units_alloc(&err);
    test_expm();
    test_energy();
    test_steady();
    test_small_amplitude();
    test_second_order();
    test_turn();
    test_manoeuvre_linear();
    test_implicit();
    test_misc();
    test_progress();
    test_sparse_linear();
    ts_units_free(units);
    return tc_done();
}
