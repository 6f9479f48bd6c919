/* test_esdirk.c: the L-stable ESDIRK 5(4) stepper (lib/esdirk.h) against
 * the exact solution of a linear, stiff, lightly damped test system.
 *
 * The system (n = 4), two uncoupled damped oscillators, the slow one
 * driven:
 *   x1'' + 2 zs ws x1' + ws^2 x1 = F cos(W t)   ws = 1 rad/s, zs = 0.05
 *   x2'' + 2 zf wf x2' + wf^2 x2 = 0            wf = 1e4 rad/s, zf = 1e-3
 * with y = (x1, x1', x2, x2'), F = 0.7385 m/s^2, W = 2.385 rad/s. Its exact
 * solution is the steady sinusoid plus the free decaying oscillation
 * (exact_state below). The fast mode decays at zf wf = 10 1/s, so over
 * 10 s by exp(-100), and it completes wf 10 / (2 pi) = 15915 periods:
 * this is the cable's axial mode in miniature, kHz and nearly undamped.
 *
 *  1. Accuracy: at rtol 1e-9 the slow mode at t = 10 s equals the exact
 *     solution; the error at rtol 1e-6 is larger, and both are below a
 *     bound proportional to rtol.
 *  2. L-stability: the fast mode excited at the start (1 mm) is followed
 *     accurately while the exact solution keeps it above the tolerance;
 *     once it has decayed, the steps (rtol 1e-6) are far fewer than its
 *     periods, it is damped far beyond the physical rate, and the slow
 *     mode stays accurate.
 *  3. Interpolation inside the last step equals the exact solution;
 *     outside it fails with TS_EINTEGRATOR and a message.
 *  4. tstop: steps end exactly at tstop = 0.37 s, never past it, and the
 *     run continues accurately from there.
 *  5. Refusals: an f that refuses (> 0) trial steps too long, or trial
 *     states too far from the last accepted one, makes the stepper retry
 *     shorter steps, and the run stays accurate; a Jacobian refusing once
 *     is retried too; an f failing (< 0) fails the step with
 *     TS_EINTEGRATOR and a message, leaving t and y as they were.
 *  6. reset: a restart from a new state and time continues the counters
 *     and follows the exact solution from that state.
 * Tolerances are stated at each check with their reason. */
#include "esdirk.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "tcheck.h"

#define NSTATE 4

/* The test system's constants (header comment). */
static const double omega_slow = 1.0, zeta_slow = 0.05;
static const double omega_fast = 1e4, zeta_fast = 1e-3;
static const double force_amp = 0.7385, force_freq = 2.385;

typedef struct osc {
    long nf, njac;          /* calls of f and of the Jacobian */
    /* Refusals (> 0) of trial states: those whose slow part lies farther
     * than reach from ybase, or whose time is more than ahead (s) after
     * tbase, (ybase, tbase) being the last accepted step's end; 0: never. */
    double reach, ahead;
    double ybase[NSTATE], tbase;
    long refused;
    int fatal;              /* f returns -1 when set */
    int jac_refuse;         /* Jacobian calls still to refuse (> 0) */
    long jac_refused;
} osc;

static int osc_f(double t, const double y[], double dydt[], void *params)
{
    osc *o = params;
    o->nf++;
    if (o->fatal)
        return -1;
    if ((o->reach > 0 && (fabs(y[0] - o->ybase[0]) > o->reach ||
                          fabs(y[1] - o->ybase[1]) > o->reach)) ||
        (o->ahead > 0 && t - o->tbase > o->ahead)) {
        o->refused++;
        return 1;
    }
    dydt[0] = y[1];
    dydt[1] = -omega_slow * omega_slow * y[0] -
              2 * zeta_slow * omega_slow * y[1] +
              force_amp * cos(force_freq * t);
    dydt[2] = y[3];
    dydt[3] = -omega_fast * omega_fast * y[2] -
              2 * zeta_fast * omega_fast * y[3];
    return 0;
}

/* df/dy, column-major: J[i + j n] = d f_i / d y_j. */
static int osc_jac(double t, const double y[], double J[], void *params)
{
    (void)t;
    (void)y;
    osc *o = params;
    o->njac++;
    if (o->jac_refuse > 0) {
        o->jac_refuse--;
        o->jac_refused++;
        return 1;
    }
    memset(J, 0, NSTATE * NSTATE * sizeof *J);
    J[0 + 1 * NSTATE] = 1;
    J[1 + 0 * NSTATE] = -omega_slow * omega_slow;
    J[1 + 1 * NSTATE] = -2 * zeta_slow * omega_slow;
    J[2 + 3 * NSTATE] = 1;
    J[3 + 2 * NSTATE] = -omega_fast * omega_fast;
    J[3 + 3 * NSTATE] = -2 * zeta_fast * omega_fast;
    return 0;
}

/* Free oscillation x'' + 2 zeta w x' + w^2 x = 0 from (x0, v0) after time
 * tau: x = e^{-a tau} (x0 cos wd tau + (v0 + a x0)/wd sin wd tau),
 * v = e^{-a tau} (v0 cos wd tau - (w^2 x0 + a v0)/wd sin wd tau), with
 * a = zeta w and wd = w sqrt(1 - zeta^2). */
static void free_osc(double w, double zeta, double x0, double v0, double tau,
                     double *x, double *v)
{
    double a = zeta * w, wd = w * sqrt(1 - zeta * zeta);
    double e = exp(-a * tau), c = cos(wd * tau), s = sin(wd * tau);
    *x = e * (x0 * c + (v0 + a * x0) / wd * s);
    *v = e * (v0 * c - (w * w * x0 + a * v0) / wd * s);
}

/* The steady response to F cos(W t): x_p = P cos W t + Q sin W t with
 * D = (ws^2 - W^2)^2 + (2 zs ws W)^2, P = F (ws^2 - W^2)/D,
 * Q = F 2 zs ws W / D (substitute and match cos and sin). */
static void forced(double t, double *x, double *v)
{
    double w2 = omega_slow * omega_slow, W = force_freq;
    double c = 2 * zeta_slow * omega_slow * W;
    double D = (w2 - W * W) * (w2 - W * W) + c * c;
    double P = force_amp * (w2 - W * W) / D, Q = force_amp * c / D;
    *x = P * cos(W * t) + Q * sin(W * t);
    *v = W * (-P * sin(W * t) + Q * cos(W * t));
}

/* The exact state at t of the solution through (t0, y0). */
static void exact_state(double t0, const double y0[], double t, double y[])
{
    double xp0, vp0, xp, vp, xh, vh;
    forced(t0, &xp0, &vp0);
    forced(t, &xp, &vp);
    free_osc(omega_slow, zeta_slow, y0[0] - xp0, y0[1] - vp0, t - t0, &xh,
             &vh);
    y[0] = xp + xh;
    y[1] = vp + vh;
    free_osc(omega_fast, zeta_fast, y0[2], y0[3], t - t0, &y[2], &y[3]);
}

/* max(|x1 - x1e|, |v1 - v1e|): the slow mode's error. */
static double slow_error(const double y[], const double ye[])
{
    return fmax(fabs(y[0] - ye[0]), fabs(y[1] - ye[1]));
}

/* Step from *t to t1 (tsi_esdirk_step with tstop t1). *past counts steps
 * that ended beyond t1 (there must be none). */
static int run_to(tsi_esdirk *s, osc *o, double t1, double *t, double y[],
                  long *past, ts_err *err)
{
    while (*t < t1) {
        int rc = tsi_esdirk_step(s, t1, t, y, err);
        if (rc)
            return rc;
        if (*t > t1)
            ++*past;
        memcpy(o->ybase, y, sizeof o->ybase);
        o->tbase = *t;
    }
    return TS_OK;
}

/* The slow mode's initial state of every run (m, m/s): awkward values. */
static const double x1_start = 0.8125, v1_start = -0.3172;

/* Integrate the system from t = 0 with the fast mode at (xf, vf) to t1 at
 * tolerance rtol (atol = 1e-3 rtol: the slow mode is of order 1). The
 * stepper is returned (caller frees) with the final state in y. */
static tsi_esdirk *run(osc *o, double rtol, double xf, double vf, double t1,
                       double y[NSTATE], double *t, ts_err *err)
{
    double y0[NSTATE] = {x1_start, v1_start, xf, vf};
    tsi_esdirk *s = tsi_esdirk_alloc(NSTATE, osc_f, osc_jac, o, rtol,
                                     1e-3 * rtol, 1e-4, err);
    if (!s)
        return NULL;
    memcpy(y, y0, sizeof y0);
    memcpy(o->ybase, y0, sizeof y0);
    o->tbase = 0;
    *t = 0;
    long past = 0;
    if (tsi_esdirk_reset(s, 0, y, err) ||
        run_to(s, o, t1, t, y, &past, err)) {
        tsi_esdirk_free(s);
        return NULL;
    }
    return s;
}

/* ---- 1. Accuracy ------------------------------------------------------ */

static void test_accuracy(void)
{
    static const double y0[NSTATE] = {x1_start, v1_start, 0, 0};
    const double rtols[2] = {1e-6, 1e-9};
    double errs[2] = {0, 0};
    long steps[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        osc o = {0};
        ts_err err = {0};
        double y[NSTATE], ye[NSTATE], t = 0;
        tsi_esdirk *s = run(&o, rtols[k], 0, 0, 10, y, &t, &err);
        if (!CHECK(s, "accuracy: rtol %g: run to 10 s (%s)", rtols[k],
                   err.msg))
            continue;
        tsi_esdirk_stats st;
        tsi_esdirk_get_stats(s, &st);
        steps[k] = st.steps;
        exact_state(0, y0, t, ye);
        errs[k] = slow_error(y, ye);
        /* The method bounds the local error per step to about rtol |y|
         * (|y| < 1 here); the global error after 10 s is that sum damped
         * and propagated over 1.6 slow periods: 50 rtol leaves a margin of
         * several over the measured figure and still fails a method
         * of lower order or a broken error estimate. */
        CHECK(errs[k] < 50 * rtols[k],
              "accuracy: rtol %g: slow mode at t = 10 s off by %.3g < 50 "
              "rtol = %.3g (%ld steps)", rtols[k], errs[k], 50 * rtols[k],
              st.steps);
        /* The fast mode starts at rest and is never forced: it stays at
         * zero (to rounding: its equations are homogeneous). */
        CHECK(fabs(y[2]) < 1e-15 && fabs(y[3]) < 1e-12,
              "accuracy: rtol %g: the unexcited fast mode stays at 0 "
              "(%.3g m, %.3g m/s)", rtols[k], y[2], y[3]);
        CHECK(t == 10, "accuracy: rtol %g: the run ends at exactly 10 s "
              "(%.17g)", rtols[k], t);
        tsi_esdirk_free(s);
    }
    /* A thousand-fold tighter tolerance must cut the error by at least
     * ten (an order-5 method with a working controller gives about a
     * thousand). */
    CHECK(errs[0] > 10 * errs[1],
          "accuracy: error at rtol 1e-6 (%.3g) > 10 x error at 1e-9 (%.3g)",
          errs[0], errs[1]);
    CHECK(steps[1] > steps[0], "accuracy: more steps at rtol 1e-9 (%ld) "
          "than at 1e-6 (%ld)", steps[1], steps[0]);
}

/* ---- 2. L-stability --------------------------------------------------- */

/* The fast mode's amplitude sqrt(x2^2 + (x2'/wf)^2), m: it decays as
 * exp(-zf wf t) (to within zf = 1e-3 over a period). */
static double fast_amp(const double y[])
{
    return hypot(y[2], y[3] / omega_fast);
}

/* The fast mode excited at the start: 1 mm and 5 m/s, amplitude 1.1 mm.
 * The exact solution carries it above the absolute tolerance (1e-9 m) for
 * 1.4 s (1.1e-3 exp(-10 t) > 1e-9), some 2200 of its periods: there an
 * accurate stepper must follow it, L-stable or not, and does (2.1). What
 * L-stability buys is the rest of the run: once the mode has decayed
 * below the tolerance, steps far longer than its period (2.2), and
 * numerical damping of what is left far beyond the physical one (2.3):
 * |R(z)| -> 0 as |z| -> infinity, where an A-stable method such as the
 * trapezoidal rule keeps |R(z)| -> 1 and carries the residue along. */
static void test_l_stability(void)
{
    static const double xf0 = 1e-3, vf0 = 5.0;
    static const double y0[NSTATE] = {x1_start, v1_start, xf0, vf0};
    osc o = {0};
    ts_err err = {0};
    double y[NSTATE], ye[NSTATE], t = 0;
    tsi_esdirk *s = run(&o, 1e-6, xf0, vf0, 0.1, y, &t, &err);
    if (!CHECK(s, "L-stability: run to 0.1 s (%s)", err.msg))
        return;
    /* 2.1 At 0.1 s, 159 fast periods in, the fast mode (0.4 mm) is the
     * exact one. Each accepted step's local error is within the weights
     * (WRMS norm <= 1 over 4 components: each component below 2 weights),
     * atol + rtol |y| <= 1e-9 + 1e-6 x 1.1e-3 m for x2 and the same in
     * x2'/wf; the mode is neutrally stable over 0.1 s, so the global error
     * is at most the sum over the steps taken. A stepper damping or
     * dephasing the mode is off by the amplitude itself. */
    tsi_esdirk_stats st;
    tsi_esdirk_get_stats(s, &st);
    exact_state(0, y0, t, ye);
    double ef = fmax(fabs(y[2] - ye[2]), fabs(y[3] - ye[3]) / omega_fast);
    double ef_max = 2.0 * (double)st.steps * (1e-9 + 1e-6 * fast_amp(y0));
    CHECK(ef < ef_max, "L-stability: the fast mode while above the "
          "tolerance: at 0.1 s off by %.3g m < %ld steps x 2 weights = "
          "%.3g m (amplitude %.3g m)", ef, st.steps, ef_max, fast_amp(ye));

    long past = 0;
    tsi_esdirk_stats st5, st10;
    int rc = run_to(s, &o, 5, &t, y, &past, &err);
    tsi_esdirk_get_stats(s, &st5);
    if (rc == TS_OK)
        rc = run_to(s, &o, 10, &t, y, &past, &err);
    tsi_esdirk_get_stats(s, &st10);
    if (!CHECK(rc == TS_OK && t == 10 && past == 0, "L-stability: run to "
               "10 s (%s)", err.msg)) {
        tsi_esdirk_free(s);
        return;
    }
    /* 2.2 From 5 s on the exact fast mode is below 1.1e-3 exp(-50) =
     * 2e-25 m: the tolerance no longer asks for it, and the steps are what
     * the slow mode asks (tens over 5 s), where following the fast mode
     * would take several per period (> 7958). A twentieth of the period
     * count is far from both. */
    double periods = omega_fast * 5 / (2 * M_PI);
    long late = st10.steps - st5.steps;
    CHECK(late < periods / 20, "L-stability: %ld steps from 5 s to 10 s < "
          "%.0f fast periods / 20 (%ld steps in all, %ld rejected)", late,
          periods, st10.steps, st10.rejected);
    /* 2.3 The exact fast amplitude at 10 s is 1.1e-3 exp(-100) = 4e-47 m;
     * the stepper's is what its damping left of the residue it had when
     * it began stepping over the mode (~atol): an L-stable method leaves
     * almost nothing, an A-stable one with |R(inf)| = 1 far more than the
     * exact value. Below a thousandth of the exact value. */
    exact_state(0, y0, t, ye);
    CHECK(fast_amp(y) < 1e-3 * fast_amp(ye),
          "L-stability: fast mode at 10 s damped beyond physics: amplitude "
          "%.3g m < 1e-3 x exact %.3g m", fast_amp(y), fast_amp(ye));
    /* Same bound as the accuracy test: the fast transient must not spoil
     * the slow mode. */
    double e = slow_error(y, ye);
    CHECK(e < 50e-6, "L-stability: slow mode at 10 s off by %.3g < 50 rtol "
          "= 5e-05", e);
    tsi_esdirk_free(s);
}

/* ---- 3. Interpolation ------------------------------------------------- */

static void test_interpolate(void)
{
    static const double y0[NSTATE] = {x1_start, v1_start, 0, 0};
    osc o = {0};
    ts_err err = {0};
    double y[NSTATE], ye[NSTATE], yi[NSTATE], t = 0;
    /* 3.1 s: a time no step is aimed at, well into the run. */
    tsi_esdirk *s = run(&o, 1e-9, 0, 0, 3.1, y, &t, &err);
    if (!CHECK(s, "interpolate: run to 3.1 s (%s)", err.msg))
        return;
    /* One more free step (tstop far away), then ask inside it. */
    double t_prev = t;
    int rc = tsi_esdirk_step(s, 100, &t, y, &err);
    CHECK(rc == TS_OK && t > t_prev, "interpolate: a step from %.6g s to "
          "%.6g s", t_prev, t);
    tsi_esdirk_stats st;
    tsi_esdirk_get_stats(s, &st);
    CHECK_NEAR(st.h_last, t - t_prev, 1e-14, "interpolate: h_last is the "
               "step just taken (s)");
    double worst = 0;
    const double fractions[3] = {0.2174, 0.5, 0.8391};
    for (int i = 0; i < 3; i++) {
        double ti = t_prev + fractions[i] * (t - t_prev);
        rc = tsi_esdirk_interpolate(s, ti, yi, &err);
        if (!CHECK(rc == TS_OK, "interpolate: at %.6g s (%s)", ti, err.msg))
            continue;
        exact_state(0, y0, ti, ye);
        worst = fmax(worst, slow_error(yi, ye));
    }
    /* The interpolant is the degree-4 Hermite of ARKODE's step ends and
     * derivatives, error O(h^5) of the step the controller chose for
     * rtol 1e-9; 100 rtol allows its interpolation error on top of the
     * end points' global error (< 50 rtol, test 1). */
    CHECK(worst < 1e-7, "interpolate: inside the last step the slow mode is "
          "off by %.3g < 100 rtol = 1e-07", worst);
    /* At the step's end the interpolant is the step's result. */
    rc = tsi_esdirk_interpolate(s, t, yi, &err);
    CHECK(rc == TS_OK && slow_error(yi, y) < 1e-12,
          "interpolate: at the step end equals the step's state (%.3g)",
          slow_error(yi, y));

    /* Outside the last step: a time ahead and one well behind. */
    const double outside[2] = {t + 0.5, t_prev - 1.0};
    for (int i = 0; i < 2; i++) {
        ts_err e2 = {0};
        rc = tsi_esdirk_interpolate(s, outside[i], yi, &e2);
        CHECK(rc == TS_EINTEGRATOR && e2.code == TS_EINTEGRATOR &&
              strlen(e2.msg) > 0, "interpolate: at %.6g s, outside [%.6g, "
              "%.6g] s, refused: \"%s\"", outside[i], t_prev, t, e2.msg);
    }
    tsi_esdirk_free(s);
}

/* ---- 4. tstop --------------------------------------------------------- */

static void test_tstop(void)
{
    static const double y0[NSTATE] = {x1_start, v1_start, 0, 0};
    osc o = {0};
    ts_err err = {0};
    double y[NSTATE], ye[NSTATE], t = 0;
    /* Loose tolerance: the controller wants steps longer than 0.37 s, so
     * the stop must cut one. */
    tsi_esdirk *s = tsi_esdirk_alloc(NSTATE, osc_f, osc_jac, &o, 1e-5,
                                     1e-8, 0.1, &err);
    if (!CHECK(s, "tstop: alloc (%s)", err.msg))
        return;
    memcpy(y, y0, sizeof y);
    CHECK(tsi_esdirk_reset(s, 0, y, &err) == TS_OK, "tstop: reset");
    long past = 0, nstep = 0;
    while (t < 0.37) {
        int rc = tsi_esdirk_step(s, 0.37, &t, y, &err);
        if (!CHECK(rc == TS_OK, "tstop: step (%s)", err.msg))
            break;
        nstep++;
        if (t > 0.37)
            past++;
    }
    CHECK(past == 0 && t == 0.37, "tstop: %ld steps, none past 0.37 s, "
          "ending at exactly %.17g s", nstep, t);
    exact_state(0, y0, t, ye);
    /* Local accuracy over a third of a second at rtol 1e-5: 50 rtol. */
    CHECK(slow_error(y, ye) < 5e-4, "tstop: state at 0.37 s off by %.3g "
          "< 5e-4", slow_error(y, ye));
    /* And on from there to 2.9 s (the stop must not upset the step). */
    long p2 = 0;
    int rc = run_to(s, &o, 2.9, &t, y, &p2, &err);
    exact_state(0, y0, t, ye);
    CHECK(rc == TS_OK && p2 == 0 && t == 2.9 &&
          slow_error(y, ye) < 5e-4, "tstop: on to %.17g s (never past), "
          "off by %.3g < 50 rtol", t, slow_error(y, ye));
    tsi_esdirk_free(s);
}

/* ---- 5. Refusals ------------------------------------------------------ */

static void test_refusals(void)
{
    static const double y0[NSTATE] = {x1_start, v1_start, 0, 0};
    double y[NSTATE], ye[NSTATE], t = 0;

    /* 5.1 f refuses trial states, (a) at times more than 0.05 s after
     * the last accepted step (a trial step too long for the model), (b)
     * whose slow part moved more than 0.02 from the last accepted state
     * (a chart boundary in miniature, as the kernel's TS_CHART). The slow
     * velocity and acceleration are below ~1.5, so steps of 0.01 s never
     * meet (b); the controller, at rtol 1e-6, wants ~0.2 s. Either way the
     * stepper must retry shorter steps and stay accurate. */
    for (int k = 0; k < 2; k++) {
        osc o = {0};
        if (k == 0)
            o.ahead = 0.05;
        else
            o.reach = 0.02;
        const char *what = k == 0 ? "trial times > 0.05 s ahead"
                                  : "trial states > 0.02 away";
        ts_err err = {0};
        tsi_esdirk *s = tsi_esdirk_alloc(NSTATE, osc_f, osc_jac, &o, 1e-6,
                                         1e-9, 0.5, &err);
        if (!CHECK(s != NULL, "refusal: alloc (%s)", err.msg))
            continue;
        memcpy(y, y0, sizeof y);
        memcpy(o.ybase, y0, sizeof y0);
        t = 0;
        long past = 0;
        int rc = tsi_esdirk_reset(s, 0, y, &err);
        if (rc == TS_OK)
            rc = run_to(s, &o, 10, &t, y, &past, &err);
        tsi_esdirk_stats st;
        tsi_esdirk_get_stats(s, &st);
        CHECK(rc == TS_OK && t == 10, "refusal: f refusing (> 0) %s: run "
              "to 10 s succeeds (%s)", what, err.msg);
        CHECK(o.refused > 0 && st.rejected > 0,
              "refusal: f refused %ld trial states, %ld steps retried "
              "(%ld accepted)", o.refused, st.rejected, st.steps);
        if (rc == TS_OK) {
            exact_state(0, y0, t, ye);
            /* As test 1: shorter steps only make it more accurate. */
            CHECK(slow_error(y, ye) < 50e-6, "refusal: %s: slow mode at "
                  "10 s off by %.3g < 50 rtol", what, slow_error(y, ye));
        }
        tsi_esdirk_free(s);
    }

    /* 5.2 The Jacobian refuses its first evaluation (> 0): ARKODE
     * retries the step, and the run is as accurate as without. */
    {
        osc o = {.jac_refuse = 1};
        ts_err err = {0};
        tsi_esdirk *s = run(&o, 1e-6, 0, 0, 10, y, &t, &err);
        CHECK(s != NULL && t == 10, "refusal: Jacobian refusing once: run "
              "to 10 s succeeds (%s)", err.msg);
        if (s) {
            CHECK(o.jac_refused == 1 && o.njac > 1, "refusal: the Jacobian "
                  "refused once and was evaluated again (%ld calls)",
                  o.njac);
            exact_state(0, y0, t, ye);
            CHECK(slow_error(y, ye) < 50e-6, "refusal: slow mode at 10 s "
                  "off by %.3g < 50 rtol", slow_error(y, ye));
            tsi_esdirk_free(s);
        }
    }

    /* 5.3 f fails (< 0) mid-run: the step fails with TS_EINTEGRATOR and
     * a message; t and y are those of the last accepted step. */
    {
        osc o = {0};
        ts_err err = {0};
        tsi_esdirk *s = run(&o, 1e-6, 0, 0, 1.7, y, &t, &err);
        CHECK(s != NULL, "fatal: run to 1.7 s (%s)", err.msg);
        if (s) {
            double ykeep[NSTATE], tkeep = t;
            memcpy(ykeep, y, sizeof y);
            o.fatal = 1;
            int rc = tsi_esdirk_step(s, 10, &t, y, &err);
            CHECK(rc == TS_EINTEGRATOR && err.code == TS_EINTEGRATOR &&
                  strlen(err.msg) > 0, "fatal: f returning < 0 fails the "
                  "step with TS_EINTEGRATOR: \"%s\"", err.msg);
            CHECK(t == tkeep && memcmp(y, ykeep, sizeof y) == 0,
                  "fatal: t (%.17g s) and y unchanged", t);
            tsi_esdirk_free(s);
        }
    }
}

/* ---- 6. reset --------------------------------------------------------- */

static void test_reset(void)
{
    static const double y0[NSTATE] = {x1_start, v1_start, 0, 0};
    osc o = {0};
    ts_err err = {0};
    double y[NSTATE], ye[NSTATE], t = 0;
    tsi_esdirk *s = run(&o, 1e-8, 0, 0, 4.2, y, &t, &err);
    if (!CHECK(s, "reset: first run to 4.2 s (%s)", err.msg))
        return;
    tsi_esdirk_stats st1, st2;
    tsi_esdirk_get_stats(s, &st1);
    exact_state(0, y0, t, ye);
    CHECK(slow_error(y, ye) < 50e-8, "reset: first run off by %.3g < 50 "
          "rtol", slow_error(y, ye));

    /* A new state at a new time, with the fast mode excited too. */
    const double t1 = 7.25;
    const double y1[NSTATE] = {-0.4416, 1.0931, 2.5e-4, -1.75};
    memcpy(y, y1, sizeof y);
    t = t1;
    memcpy(o.ybase, y1, sizeof y1);
    o.tbase = t1;
    int rc = tsi_esdirk_reset(s, t1, y, &err);
    CHECK(rc == TS_OK, "reset: restart at %.6g s (%s)", t1, err.msg);
    /* The step-size history is dropped: the first step after the
     * restart is at most the configured first step, 1e-4 s (shorter if
     * the error test rejects it), not the ~0.1 s the run had reached. */
    rc = tsi_esdirk_step(s, t1 + 10, &t, y, &err);
    tsi_esdirk_get_stats(s, &st2);
    CHECK(rc == TS_OK && st2.h_last <= 1e-4 * (1 + 1e-12) &&
          st1.h_last > 1e-2, "reset: the first step after the restart, "
          "%.3g s, <= h_init 1e-4 s (before it: %.3g s)", st2.h_last,
          st1.h_last);
    long past = 0;
    rc = run_to(s, &o, t1 + 5, &t, y, &past, &err);
    tsi_esdirk_get_stats(s, &st2);
    CHECK(rc == TS_OK && t == t1 + 5, "reset: second run to %.6g s (%s)",
          t1 + 5, err.msg);
    /* The counters keep counting across the restart. */
    CHECK(st2.steps > st1.steps && st2.setups > st1.setups,
          "reset: steps %ld -> %ld, LU setups %ld -> %ld, still counting",
          st1.steps, st2.steps, st1.setups, st2.setups);
    exact_state(t1, y1, t, ye);
    CHECK(slow_error(y, ye) < 50e-8, "reset: slow mode 5 s after the "
          "restart off by %.3g < 50 rtol", slow_error(y, ye));
    /* The fast mode (excited at the restart) is damped: see test 2. */
    CHECK(fabs(y[2]) < 1e-8 && fabs(y[3]) < 1e-4, "reset: fast mode damped "
          "(%.3g m, %.3g m/s)", y[2], y[3]);
    tsi_esdirk_free(s);
}

int main(void)
{
    test_accuracy();
    test_l_stability();
    test_interpolate();
    test_tstop();
    test_refusals();
    test_reset();
    return tc_done();
}
