/* test_excitation.c: tow-point excitations and manoeuvres
 * (towstab/excitation.h) against references written out here.
 *
 *  1. Every shape's velocity and acceleration against central differences
 *     of its displacement and velocity (they must be exact derivatives, or
 *     the rigid-link kinematics would be inconsistent).
 *  2. Closed-form values: sine, the slider crank of doc/model.md section 8,
 *     the end values and midpoint of steps and ramps, the ramp's plateau
 *     rate and its linear part x = A/T (t - start - rise/2).
 *  3. Series: a sampled sinusoid through the cubic spline, its
 *     derivatives within the spline's error; CSV reading (header, comments)
 *     and every CSV error.
 *  4. Manoeuvres: turn rate and speed with to= and by=, their rates by
 *     differences, the heading against a Simpson integral of the turn rate,
 *     the current rotated into the turning frame (a current along +x at
 *     t = 0, seen from the ship after a quarter turn to starboard, flows
 *     to port, along -y).
 *  5. Breakpoints, time scales, the periodic signal.
 *  6. The spec parser: units, defaults, and every refusal with its message.
 *  7. Signals on a vehicle's inputs: by name, in m or rad, evaluated alone.
 *  7. Sums (an irregular sea's tow-point motion): the closed-form value
 *     at full amplitude, the derivatives by differences during and after
 *     the fade-in (whose end is a breakpoint), one signal per driven axis
 *     sharing the components, the rms and the time scale, refusals.
 *  8. The smooth start of a sine or crank: the signal times S(t / ramp),
 *     written out here, exact derivatives across the ramp's end (a
 *     breakpoint), no jump at t = 0 (ts_excitation_start_jump), the
 *     parser's default of two periods, ramp=0 for an impulsive start.
 * Tolerances are stated at each check. */
#include "towstab/compare.h"
#include "towstab/excitation.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcheck.h"

/* Largest |v - dx/dt| and |a - dv/dt| over n points in [t0, t1], each
 * relative to `vscale` and `ascale`; central differences with step h
 * (error h^2/6 |x'''| + eps |x| / h). */
static void fd_check(const ts_excitation *ex, int axis, double t0, double t1,
                     int n, double h, double *ev, double *ea)
{
    *ev = *ea = 0.0;
    for (int i = 0; i < n; i++) {
        double t = t0 + (t1 - t0) * (i + 0.37) / n;
        double u[TS_NINPUT], up[TS_NINPUT], um[TS_NINPUT];
        ts_excitation_input(ex, t, u);
        ts_excitation_input(ex, t + h, up);
        ts_excitation_input(ex, t - h, um);
        double dv = fabs(u[3 + axis] - (up[axis] - um[axis]) / (2 * h));
        double da = fabs(u[6 + axis] - (up[3 + axis] - um[3 + axis]) / (2 * h));
        if (dv > *ev)
            *ev = dv;
        if (da > *ea)
            *ea = da;
    }
}

static ts_excitation *one(const ts_signal *s)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    if (ts_excitation_add(ex, s, &err))
        printf("note: add failed: %s\n", err.msg);
    return ex;
}

static void test_shapes(void)
{
    /* FD step 1e-5 s: for these signals (|x'''| <= ~A w^3 ~ 10) the
     * truncation error is below 2e-9 and rounding below 1e-10. */
    const double h = 1e-5;
    double ev, ea;

    ts_signal s = {0};
    s.type = TS_SIGNAL_SINE;
    s.axis = TS_AXIS_HEAVE;
    s.amplitude = 0.03048;
    s.frequency = 0.8375;
    s.phase = 0.4;
    ts_excitation *ex = one(&s);
    double u[TS_NINPUT], w = 2 * M_PI * s.frequency, t = 2.385;
    ts_excitation_input(ex, t, u);
    CHECK_NEAR(u[2], s.amplitude * sin(w * t + 0.4), 1e-16, "sine x");
    CHECK_NEAR(u[5], s.amplitude * w * cos(w * t + 0.4), 1e-15, "sine v");
    CHECK_NEAR(u[8], -s.amplitude * w * w * sin(w * t + 0.4), 1e-14,
               "sine a");
    CHECK(u[0] == 0 && u[1] == 0 && u[3] == 0 && u[7] == 0,
          "sine drives its own axis only");
    fd_check(ex, 2, 0.0, 7.0, 50, h, &ev, &ea);
    CHECK(ev < 1e-8 && ea < 1e-8, "sine v, a are the derivatives (max err "
          "%.2g, %.2g m/s, m/s^2 < 1e-8)", ev, ea);
    ts_excitation_free(ex);

    /* Slider crank, doc/model.md section 8: z = r cos th + l (1 - sqrt(1 -
     * (r/l)^2 sin^2 th)), with awkward r/l so that the rod term matters. */
    s.type = TS_SIGNAL_CRANK;
    s.axis = TS_AXIS_SURGE;
    s.amplitude = 0.1;
    s.rod = 0.35;
    s.frequency = 1.0 / 1.6;
    s.phase = -0.3;
    ex = one(&s);
    double maxd = 0;
    for (int i = 0; i < 40; i++) {
        double tt = 0.123 + 0.1 * i, th = 2 * M_PI * tt / 1.6 - 0.3;
        double r = 0.1, l = 0.35, sn = sin(th);
        double z = r * cos(th) + l * (1 - sqrt(1 - (r / l) * (r / l) * sn * sn));
        ts_excitation_input(ex, tt, u);
        maxd = fmax(maxd, fabs(u[0] - z));
    }
    CHECK(maxd < 1e-15, "crank displacement is doc/model.md section 8's (max err "
          "%.2g m < 1e-15)", maxd);
    fd_check(ex, 0, 0.0, 3.2, 60, h, &ev, &ea);
    CHECK(ev < 1e-8 && ea < 1e-7, "crank v, a are the derivatives (max err "
          "%.2g m/s < 1e-8, %.2g m/s^2 < 1e-7)", ev, ea);
    ts_excitation_free(ex);

    /* Step: 0 before, A after, A/2 at mid-rise (S5 is odd about 1/2),
     * continuous derivatives at both ends. */
    s = (ts_signal){0};
    s.type = TS_SIGNAL_STEP;
    s.axis = TS_AXIS_SWAY;
    s.amplitude = -0.2385;
    s.start = 1.25;
    s.rise = 0.4;
    ex = one(&s);
    ts_excitation_input(ex, 1.25 - 1e-9, u);
    CHECK(u[1] == 0 && u[4] == 0 && u[7] == 0, "step: zero before start");
    ts_excitation_input(ex, 1.45, u);
    CHECK_NEAR(u[1], -0.2385 / 2, 1e-15, "step: half way at mid-rise");
    ts_excitation_input(ex, 1.65 + 1e-12, u);
    CHECK(u[1] == -0.2385 && u[4] == 0 && u[7] == 0,
          "step: exactly A, at rest, after start + rise");
    ts_excitation_input(ex, 1.65 - 1e-6, u);
    CHECK(fabs(u[7]) < 1e-3, "step: acceleration continuous at the end "
          "(%.2g m/s^2 1 us before; peak ~%.2g)", u[7],
          0.2385 * 5.77 / (0.4 * 0.4));
    fd_check(ex, 1, 1.25, 1.65, 40, 1e-6, &ev, &ea);
    CHECK(ev < 1e-7 && ea < 1e-5, "step v, a are the derivatives (max err "
          "%.2g m/s < 1e-7, %.2g m/s^2 < 1e-5; step 1e-6 s)", ev, ea);
    ts_excitation_free(ex);

    /* Ramp with rise < duration: plateau rate A/T and x = A/T (t - start -
     * rise/2) in the linear part; final value exactly A. */
    s = (ts_signal){0};
    s.type = TS_SIGNAL_RAMP;
    s.axis = TS_AXIS_HEAVE;
    s.amplitude = 0.75;
    s.start = 0.5;
    s.duration = 3.0;
    s.rise = 0.6;
    ex = one(&s);
    ts_excitation_input(ex, 2.2, u);
    CHECK_NEAR(u[5], 0.75 / 3.0, 1e-15, "ramp: plateau rate A/T");
    CHECK_NEAR(u[2], 0.75 / 3.0 * (2.2 - 0.5 - 0.3), 1e-15,
               "ramp: linear part A/T (t - start - rise/2)");
    CHECK(u[8] == 0, "ramp: no acceleration on the plateau");
    ts_excitation_input(ex, 0.5 + 3.0 + 0.6, u);
    CHECK_NEAR(u[2], 0.75, 1e-15, "ramp: final value A at start + T + rise");
    CHECK(u[5] == 0 && u[8] == 0, "ramp: at rest after the ramp");
    fd_check(ex, 2, 0.3, 4.4, 80, 1e-6, &ev, &ea);
    CHECK(ev < 1e-8 && ea < 1e-6, "ramp v, a are the derivatives (max err "
          "%.2g m/s < 1e-8, %.2g m/s^2 < 1e-6)", ev, ea);
    ts_excitation_free(ex);

    /* Ramp with rise > duration still ends at exactly A. */
    s.duration = 0.2;
    s.rise = 0.7;
    ex = one(&s);
    ts_excitation_input(ex, 0.5 + 0.2 + 0.7 + 1e-12, u);
    CHECK_NEAR(u[2], 0.75, 1e-14, "ramp with rise > duration ends at A");
    fd_check(ex, 2, 0.4, 1.5, 60, 1e-6, &ev, &ea);
    CHECK(ev < 1e-8 && ea < 1e-5, "short ramp v, a are the derivatives "
          "(%.2g, %.2g)", ev, ea);
    ts_excitation_free(ex);

    /* Sums: two signals on one axis add. */
    ts_err err = {0};
    ex = ts_excitation_alloc(&err);
    ts_signal a = {0}, b = {0};
    a.type = b.type = TS_SIGNAL_SINE;
    a.axis = b.axis = TS_AXIS_HEAVE;
    a.amplitude = 0.1;
    a.frequency = 0.3;
    b.amplitude = 0.05;
    b.frequency = 1.1;
    ts_excitation_add(ex, &a, &err);
    ts_excitation_add(ex, &b, &err);
    ts_excitation_input(ex, 1.7, u);
    CHECK_NEAR(u[2], 0.1 * sin(2 * M_PI * 0.3 * 1.7) +
                         0.05 * sin(2 * M_PI * 1.1 * 1.7), 1e-16,
               "two sines on one axis add");
    int idx = -1;
    CHECK(!ts_excitation_periodic(ex, &idx), "two periodic signals: no "
          "single excitation frequency");
    ts_excitation_free(ex);
}

static void test_series(void)
{
    ts_err err = {0};
    /* sin(w t) sampled every 0.01 s on [0, 10]; natural end conditions
     * hold exactly (x'' = 0 at t = 0 and at w t = 6 pi). Spline errors for
     * spacing d: x ~ d^4 w^4 / 384, x' ~ d^3 w^4 / 24, x'' ~ d^2 w^4 / 12:
     * with w = 1.885, d = 0.01: 3e-11, 5e-7, 1.1e-4 (relative). */
    int n = 1001;
    double w = 2 * M_PI * 0.3, A = 0.4;
    double *t = malloc(n * sizeof *t), *x = malloc(n * sizeof *x);
    for (int i = 0; i < n; i++) {
        t[i] = 0.01 * i;
        x[i] = A * sin(w * t[i]);
    }
    ts_excitation *ex = ts_excitation_alloc(&err);
    CHECK(ts_excitation_add_series(ex, TS_AXIS_SURGE, n, t, x, &err) == TS_OK,
          "series accepted");
    double ex_, ev = 0, ea = 0;
    ex_ = 0;
    for (int i = 0; i < 97; i++) {
        double tt = 0.3 + 9.4 * i / 96.0, u[TS_NINPUT];
        ts_excitation_input(ex, tt, u);
        ex_ = fmax(ex_, fabs(u[0] - A * sin(w * tt)));
        ev = fmax(ev, fabs(u[3] - A * w * cos(w * tt)));
        ea = fmax(ea, fabs(u[6] + A * w * w * sin(w * tt)));
    }
    CHECK(ex_ < 1e-9 * A && ev < 1e-6 * A * w && ea < 2e-4 * A * w * w,
          "series spline x, v, a within the spline error (%.2g, %.2g, %.2g "
          "relative)", ex_ / A, ev / (A * w), ea / (A * w * w));
    CHECK(ts_excitation_check_span(ex, 10.0, &err) == TS_OK,
          "series covers [0, 10] s");
    CHECK(ts_excitation_check_span(ex, 10.5, &err) == TS_EINVAL &&
              strstr(err.msg, "ends at 10 s"),
          "a run beyond the series is refused: %s", err.msg);
    CHECK(ts_excitation_time_scale(ex) == 0.01 * 1 ||
              fabs(ts_excitation_time_scale(ex) - 0.01) < 1e-15,
          "series time scale is its spacing");
    ts_excitation_free(ex);

    /* CSV round trip with a header and a comment. */
    char path[] = "/tmp/towstab_test_excitation_XXXXXX";
    int fd = mkstemp(path);
    FILE *f = fdopen(fd, "w");
    fprintf(f, "# tow heave record\ntime_s,heave_m\n");
    for (int i = 0; i < 201; i++)
        fprintf(f, "%.17g, %.17g\n", t[i], x[i]);
    fclose(f);
    ex = ts_excitation_alloc(&err);
    int rc = ts_excitation_read_series(ex, TS_AXIS_HEAVE, path, &err);
    CHECK(rc == TS_OK, "CSV with header and comment read");
    double u[TS_NINPUT];
    ts_excitation_input(ex, 1.005, u);
    CHECK_NEAR(u[2], A * sin(w * 1.005), 1e-9, "CSV series value");
    ts_excitation_free(ex);

    struct { const char *text; const char *want; } bad[] = {
        {"t,x\n0,1\n0.1,2\n", "at least 3 samples"},
        {"0,1\n0.2,2\n0.1,3\n", "times must increase"},
        {"0,1\n0.1,2\n0.2,abc\n", "line 3"},
        {"0.5,1\n0.6,2\n0.7,3\n", "start at t <= 0"},
        {"0,1\n0.1,inf\n0.2,3\n", "line 2"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        f = fopen(path, "w");
        fputs(bad[i].text, f);
        fclose(f);
        ex = ts_excitation_alloc(&err);
        ts_err_clear(&err);
        rc = ts_excitation_read_series(ex, TS_AXIS_HEAVE, path, &err);
        CHECK(rc == TS_EINVAL && strstr(err.msg, bad[i].want),
              "bad CSV %zu refused: %s", i, err.msg);
        ts_excitation_free(ex);
    }
    unlink(path);
    ex = ts_excitation_alloc(&err);
    rc = ts_excitation_read_series(ex, TS_AXIS_HEAVE,
                                   "/nonexistent/heave.csv", &err);
    CHECK(rc == TS_EIO && strstr(err.msg, "cannot read"),
          "missing CSV: %s", err.msg);
    rc = ts_excitation_add_series(ex, TS_AXIS_SPEED, 3, t, x, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tow-point axis"),
          "series on a manoeuvre axis refused: %s", err.msg);
    ts_excitation_free(ex);
    free(t);
    free(x);
}

static void test_manoeuvres(void)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal s = {0};
    s.type = TS_SIGNAL_RAMP;
    s.axis = TS_AXIS_TURN_RATE;
    s.amplitude = 0.5;
    s.absolute = 1;
    s.start = 0.7;
    s.duration = 2.0;
    s.rise = 0.5;
    CHECK(ts_excitation_add(ex, &s, &err) == TS_OK, "turn ramp accepted");
    ts_signal v = {0};
    v.type = TS_SIGNAL_STEP;
    v.axis = TS_AXIS_SPEED;
    v.amplitude = -0.3;
    v.start = 1.1;
    v.rise = 0.9;
    CHECK(ts_excitation_add(ex, &v, &err) == TS_OK, "speed step accepted");
    CHECK(ts_excitation_has_manoeuvre(ex), "has a manoeuvre");

    ts_frame base = {0.762, 0.1, 0.0, 0.0, {0.2, -0.1, 0.05}}, f, fp, fm;
    ts_excitation_frame(ex, &base, 10.0, &f);
    CHECK_NEAR(f.turn_rate, 0.5, 1e-15, "turn rate reaches to= 0.5 rad/s "
               "(from a base of 0.1)");
    CHECK_NEAR(f.speed, 0.762 - 0.3, 1e-15, "speed changes by by= -0.3 m/s");
    CHECK(f.turn_accel == 0 && f.speed_rate == 0, "rates zero after both");
    double maxr = 0;
    for (int i = 0; i < 50; i++) {
        double t = 0.5 + 3.0 * i / 49.0, h = 1e-6;
        ts_excitation_frame(ex, &base, t, &f);
        ts_excitation_frame(ex, &base, t + h, &fp);
        ts_excitation_frame(ex, &base, t - h, &fm);
        maxr = fmax(maxr, fabs(f.turn_accel - (fp.turn_rate - fm.turn_rate) /
                                                  (2 * h)));
        maxr = fmax(maxr, fabs(f.speed_rate - (fp.speed - fm.speed) / (2 * h)));
    }
    CHECK(maxr < 1e-8, "turn_accel and speed_rate are the derivatives (max "
          "err %.2g < 1e-8)", maxr);

    /* Heading: Simpson's rule on Omega(t) over [0, 4.2] with 4200
     * intervals (error ~ h^4 |Omega''''| << 1e-12 on the smooth pieces;
     * the breakpoints fall on nodes). */
    int m = 4200;
    double T = 4.2, hs = T / m, sum = 0;
    for (int i = 0; i <= m; i++) {
        ts_excitation_frame(ex, &base, hs * i, &f);
        double wgt = (i == 0 || i == m) ? 1 : (i % 2 ? 4 : 2);
        sum += wgt * f.turn_rate;
    }
    double psi_ref = sum * hs / 3;
    CHECK_NEAR(ts_excitation_heading(ex, &base, T), psi_ref, 1e-10,
               "heading = integral of the turn rate");
    ts_excitation_frame(ex, &base, T, &f);
    double psi = psi_ref, c = cos(psi), sn = sin(psi);
    CHECK(fabs(f.current[0] - (c * 0.2 + sn * -0.1)) < 1e-10 &&
              fabs(f.current[1] - (-sn * 0.2 + c * -0.1)) < 1e-10 &&
              f.current[2] == 0.05,
          "current rotated by -psi into M (%.6f, %.6f, %.6f)", f.current[0],
          f.current[1], f.current[2]);
    ts_excitation_free(ex);

    /* A current from ahead seen after a quarter turn to starboard, with a
     * steady base turn and no signal: it flows to port. */
    ex = ts_excitation_alloc(&err);
    ts_frame b2 = {1.0, 0.25, 0, 0, {1.0, 0.0, 0.0}};
    ts_excitation_frame(ex, &b2, M_PI / 2 / 0.25, &f);
    CHECK(fabs(f.current[0]) < 1e-15 && fabs(f.current[1] + 1.0) < 1e-15,
          "after a 90 deg starboard turn a current along +x is along -y "
          "(%.3g, %.3g)", f.current[0], f.current[1]);
    ts_excitation_free(ex);
}

static void test_meta(void)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal s = {0};
    s.type = TS_SIGNAL_RAMP;
    s.axis = TS_AXIS_HEAVE;
    s.amplitude = 0.1;
    s.start = 1.0;
    s.duration = 2.0;
    s.rise = 0.5;
    ts_excitation_add(ex, &s, &err);
    s.type = TS_SIGNAL_STEP;
    s.start = 3.0; /* its start coincides with the ramp's plateau end */
    s.rise = 0.25;
    ts_excitation_add(ex, &s, &err);
    double bp[8];
    int nb = ts_excitation_breakpoints(ex, 10.0, bp, 8);
    CHECK(nb == 5 && bp[0] == 1.0 && bp[1] == 1.5 && bp[2] == 3.0 &&
              bp[3] == 3.25 && bp[4] == 3.5,
          "breakpoints sorted, deduplicated (%d: %g %g %g %g %g)", nb, bp[0],
          bp[1], bp[2], bp[3], bp[4]);
    CHECK(ts_excitation_breakpoints(ex, 3.2, bp, 8) == 3,
          "breakpoints limited to (0, t_end)");
    CHECK(ts_excitation_time_scale(ex) == 0.25, "time scale: shortest rise");
    int idx;
    CHECK(!ts_excitation_periodic(ex, &idx), "no periodic signal");
    s.type = TS_SIGNAL_CRANK;
    s.amplitude = 0.1;
    s.rod = 0.35;
    s.frequency = 0.625;
    s.phase = 0;
    ts_excitation_add(ex, &s, &err);
    CHECK(ts_excitation_periodic(ex, &idx) && idx == 2,
          "the single crank is the periodic signal");
    CHECK_NEAR(ts_excitation_time_scale(ex), 1 / (4 * M_PI * 0.625), 1e-17,
               "time scale: the crank's 1/(4 pi f) = 0.127 s (second "
               "harmonic) undercuts the step's 0.25 s");
    char d[256];
    ts_excitation_describe(ex, 2, d, sizeof d);
    CHECK(strstr(d, "tow.heave slider crank radius 0.1 m, rod 0.35 m") != NULL,
          "describe: %s", d);
    ts_excitation_free(ex);
}

static void test_parse(void)
{
    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    int rc = ts_excitation_parse(ex, "tow.heave:amplitude=0.1ft,"
                                 "frequency=0.25Hz", units, "--excite", &err);
    const ts_signal *s = ts_excitation_signal(ex, 0);
    CHECK(rc == TS_OK && s->type == TS_SIGNAL_SINE &&
              s->axis == TS_AXIS_HEAVE && s->amplitude == 0.1 * 0.3048 &&
              s->frequency == 0.25 && s->phase == 0,
          "documented example parsed: sine, heave, 0.03048 m, 0.25 Hz (%s)",
          err.msg);
    rc = ts_excitation_parse(ex, " tow.x : type = crank , amplitude = 10 cm,"
                             " rod=0.35, period=1.6 s, phase=90deg", units,
                             "--excite", &err);
    s = ts_excitation_signal(ex, 1);
    CHECK(rc == TS_OK && s->type == TS_SIGNAL_CRANK &&
              s->axis == TS_AXIS_SURGE && fabs(s->amplitude - 0.1) < 1e-16 &&
              s->rod == 0.35 && fabs(s->frequency - 0.625) < 1e-15 &&
              fabs(s->phase - M_PI / 2) < 1e-15,
          "crank with blanks, period and degrees (%s)", err.msg);
    {
        /* The two-part tow's command: a bare type word and r for radius. */
        ts_excitation *ex2 = ts_excitation_alloc(&err);
        int rc2 = ex2 ? ts_excitation_parse(ex2, "tow.heave:slider_crank,"
                                            "r=0.1m,rod=0.35m,period=1.6s",
                                            units, "--excite", &err)
                      : TS_ENOMEM;
        const ts_signal *c = rc2 == TS_OK ? ts_excitation_signal(ex2, 0) : NULL;
        CHECK(c && c->type == TS_SIGNAL_CRANK && c->axis == TS_AXIS_HEAVE &&
                  fabs(c->amplitude - 0.1) < 1e-16 && c->rod == 0.35 &&
                  fabs(c->frequency - 0.625) < 1e-15,
              "slider_crank,r=0.1m,rod=0.35m,period=1.6s parsed as a crank "
              "(%s)",
              err.msg);
        ts_excitation_free(ex2);
    }
    rc = ts_excitation_parse(ex, "turn_rate:to=0.5rad/s,duration=2s", units,
                             "--manoeuvre", &err);
    s = ts_excitation_signal(ex, 2);
    CHECK(rc == TS_OK && s->type == TS_SIGNAL_RAMP && s->absolute &&
              s->amplitude == 0.5 && s->duration == 2 &&
              s->rise == TS_SIGNAL_RISE && s->start == 0,
          "manoeuvre defaults: ramp, start 0, rise %g s (%s)",
          TS_SIGNAL_RISE, err.msg);
    rc = ts_excitation_parse(ex, "speed:type=step,by=-1knot,start=3", units,
                             "--manoeuvre", &err);
    s = ts_excitation_signal(ex, 3);
    CHECK(rc == TS_OK && s->type == TS_SIGNAL_STEP && !s->absolute &&
              fabs(s->amplitude + 1852.0 / 3600) < 1e-15 && s->start == 3,
          "speed step by -1 knot");
    rc = ts_excitation_parse(ex, "tow.sway:type=ramp,amplitude=1,"
                             "duration=0.05", units, "x", &err);
    s = ts_excitation_signal(ex, 4);
    CHECK(rc == TS_OK && s->rise == 0.05,
          "a ramp shorter than the default rise gets rise = duration");

    struct { const char *spec; int code; const char *want; } bad[] = {
        {"tow.spin:amplitude=1,frequency=1", TS_EINVAL, "unknown axis 'tow.spin'"},
        {"tow.pitch:crank,amplitude=0.1,frequency=1,rod=1", TS_EINVAL, "a rotation takes a sine"},
        {"tow.pitch:amplitude=0.1,frequency=1,ramp=0", TS_EINVAL, "a rotation starts smoothly"},
        {"tow.pitch:amplitude=1m,frequency=1", TS_EUNIT, "tow.pitch"},
        {"tow.heave:amplitud=1,frequency=1", TS_EINVAL, "unknown parameter 'amplitud'"},
        {"tow.heave:amplitude=1,frequency=1,rod=2", TS_EINVAL, "'rod' does not apply to type sine"},
        {"tow.heave:amplitude=1,frequency=-1Hz", TS_EINVAL, "frequency must be > 0 Hz, got -1"},
        {"tow.heave:amplitude=1,period=-2", TS_EINVAL, "period must be > 0 s"},
        {"tow.heave:type=step,amplitude=1,start=-1", TS_EINVAL, "start must be >= 0 s, got -1"},
        {"tow.heave:type=step,amplitude=1,rise=0", TS_EINVAL, "rise must be > 0 s"},
        {"tow.heave:type=ramp,amplitude=1,duration=-3", TS_EINVAL, "duration must be > 0 s"},
        {"tow.heave:type=ramp,amplitude=1", TS_EINVAL, "needs duration="},
        {"tow.heave:frequency=1", TS_EINVAL, "needs amplitude="},
        {"tow.heave:amplitude=1,frequency=1,period=1", TS_EINVAL, "exactly one of frequency= and period="},
        {"tow.heave:amplitude=1", TS_EINVAL, "exactly one of frequency= and period="},
        {"tow.heave:type=crank,amplitude=1,frequency=1", TS_EINVAL, "needs rod="},
        {"tow.heave:type=crank,amplitude=1,frequency=1,rod=0.5", TS_EINVAL, "rod must be longer"},
        {"tow.heave:type=square,amplitude=1", TS_EINVAL, "unknown type 'square'"},
        {"tow.heave:amplitude=1 s,frequency=1", TS_EUNIT, "amplitude"},
        /* A bare first word is the type ("tow.heave:crank,..."). */
        {"tow.heave:amplitude,frequency=1", TS_EINVAL, "unknown type 'amplitude'"},
        {"tow.heave:amplitude=1,frequency,phase=0", TS_EINVAL, "is not key=value"},
        {"tow.heave:amplitude=1,,frequency=1", TS_EINVAL, "empty item"},
        {"tow.heave:amplitude=1,amplitude=2,frequency=1", TS_EINVAL, "given twice"},
        {"tow.heave:amplitude=,frequency=1", TS_EINVAL, "has no value"},
        {"turn_rate:type=sine,amplitude=1,frequency=1", TS_EINVAL, "a manoeuvre is a step or a ramp"},
        {"turn_rate:duration=2", TS_EINVAL, "exactly one of to="},
        {"turn_rate:to=1,by=1,duration=2", TS_EINVAL, "exactly one of to="},
        {"turn_rate:to=0.1rad/s,duration=2", TS_EINVAL, "two signals set its final value"},
        {"speed:amplitude=1,duration=1", TS_EINVAL, "'amplitude' does not apply"},
        {"tow.heave:type=csv", TS_EINVAL, "needs file=PATH"},
        {"tow.heave:type=csv,file=/nonexistent.csv", TS_EIO, "cannot read"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ts_err_clear(&err);
        rc = ts_excitation_parse(ex, bad[i].spec, units, "--excite", &err);
        CHECK(rc == bad[i].code && strstr(err.msg, bad[i].want) &&
                  strncmp(err.msg, "--excite", 8) == 0,
              "refused '%s': %s", bad[i].spec, err.msg);
    }
    CHECK(ts_excitation_nsignals(ex) == 5, "refused specs added nothing "
          "(%d signals)", ts_excitation_nsignals(ex));
    ts_excitation_free(ex);
    ts_units_free(units);
}

static void test_sum(void)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    /* Three components; sway is not driven. */
    const double w[3] = {0.43, -0.91, 1.7};
    /* TS_SUM_AXES = 6 per component: surge, sway, heave, then the
     * rotations (none here). */
    const double re[18] = {0.3, 0, -0.2, 0, 0, 0, 0.1, 0, 0.05, 0, 0, 0,
                           -0.02, 0, 0.07, 0, 0, 0};
    const double im[18] = {0.1, 0, 0.4, 0, 0, 0, -0.2, 0, 0.01, 0, 0, 0,
                           0.03, 0, -0.06, 0, 0, 0};
    int rc = ts_excitation_add_sum(ex, 3, w, re, im, 5.0, &err);
    CHECK(rc == TS_OK && ts_excitation_nsignals(ex) == 2,
          "sum: one signal per driven axis (%d): %s",
          ts_excitation_nsignals(ex), err.msg);
    const ts_signal *s0 = ts_excitation_signal(ex, 0);
    const ts_signal *s1 = ts_excitation_signal(ex, 1);
    CHECK(s0->type == TS_SIGNAL_SUM && s0->axis == TS_AXIS_SURGE &&
              s1->axis == TS_AXIS_HEAVE &&
              ts_excitation_sum_components(ex, 1) == 3,
          "sum signals on surge and heave, 3 components");
    CHECK_NEAR(s1->amplitude,
               sqrt(0.5 * (0.2 * 0.2 + 0.4 * 0.4 + 0.05 * 0.05 +
                           0.01 * 0.01 + 0.07 * 0.07 + 0.06 * 0.06)),
               1e-15, "sum: heave rms sqrt(sum |c|^2 / 2)");
    /* Full amplitude after the fade-in: x = sum Re(c e^(i w t)). */
    double t = 11.3, u[TS_NINPUT];
    ts_excitation_input(ex, t, u);
    double x0 = 0, x2 = 0;
    for (int k = 0; k < 3; k++) {
        x0 += re[6 * k] * cos(w[k] * t) - im[6 * k] * sin(w[k] * t);
        x2 += re[6 * k + 2] * cos(w[k] * t) - im[6 * k + 2] * sin(w[k] * t);
    }
    CHECK(fabs(u[0] - x0) < 1e-15 && fabs(u[2] - x2) < 1e-15 &&
              u[1] == 0 && u[4] == 0 && u[7] == 0,
          "sum after the fade-in: the closed form; sway untouched");
    ts_excitation_input(ex, 0.0, u);
    CHECK(u[0] == 0 && u[3] == 0 && u[6] == 0 && u[2] == 0,
          "sum at t = 0: faded in from rest");
    /* Derivatives by central differences (step 1e-5 s: |x'''| < 1, so
     * truncation below 1e-10), in and after the fade-in. */
    double ev, ea, worst = 0;
    for (int ax = 0; ax < 3; ax += 2) {
        fd_check(ex, ax, 0.01, 4.99, 40, 1e-5, &ev, &ea);
        worst = fmax(worst, fmax(ev, ea));
        fd_check(ex, ax, 5.01, 30, 40, 1e-5, &ev, &ea);
        worst = fmax(worst, fmax(ev, ea));
    }
    CHECK(worst < 1e-8, "sum: velocity and acceleration are the "
          "derivatives (max diff %.2g)", worst);
    double bp[4];
    CHECK(ts_excitation_breakpoints(ex, 20, bp, 4) == 1 && bp[0] == 5.0,
          "sum: the end of the fade-in is a breakpoint");
    CHECK_NEAR(ts_excitation_time_scale(ex), 1 / 1.7, 1e-15,
               "sum: time scale 1 / max |w|");
    int idx;
    CHECK(!ts_excitation_periodic(ex, &idx), "a sum is not periodic");
    char d[256];
    ts_excitation_describe(ex, 1, d, sizeof d);
    CHECK(strstr(d, "tow.heave sum of 3 sinusoids") != NULL, "describe: %s",
          d);
    ts_excitation_free(ex);
    /* Refusals add nothing. */
    ex = ts_excitation_alloc(&err);
    const double zero[18] = {0};
    const double bad_w[1] = {NAN};
    ts_err e = {0};
    CHECK(ts_excitation_add_sum(ex, 3, w, zero, zero, 0, &e) == TS_EINVAL,
          "sum of zeros refused: %s", e.msg);
    CHECK(ts_excitation_add_sum(ex, 1, bad_w, re, im, 0, &e) == TS_EINVAL,
          "non-finite frequency refused: %s", e.msg);
    CHECK(ts_excitation_add_sum(ex, 3, w, re, im, -1, &e) == TS_EINVAL,
          "negative fade-in refused: %s", e.msg);
    CHECK(ts_excitation_add_sum(ex, 0, w, re, im, 0, &e) == TS_EINVAL,
          "no component refused");
    CHECK(ts_excitation_nsignals(ex) == 0, "refused sums added nothing");
    /* Many signals before: the sum's signals still fit. */
    ts_signal sg = {0};
    sg.type = TS_SIGNAL_SINE;
    sg.axis = TS_AXIS_SWAY;
    sg.amplitude = 0.1;
    sg.frequency = 0.2;
    for (int i = 0; i < 4; i++)
        ts_excitation_add(ex, &sg, &e);
    CHECK(ts_excitation_add_sum(ex, 3, w, re, im, 0, &e) == TS_OK &&
              ts_excitation_nsignals(ex) == 6,
          "a sum after four signals (table full): %s", e.msg);
    ts_excitation_input(ex, 2.0, u);
    CHECK(fabs(u[1] - 4 * 0.1 * sin(2 * M_PI * 0.2 * 2.0)) < 1e-15,
          "the sines still add up beside the sum");
    /* A copy: the same inputs and frames, and independent of the
     * original. Add a series and a manoeuvre first. */
    const double ts[4] = {-1, 0.7, 1.9, 3.4}, xs[4] = {0, 0.02, -0.01, 0.03};
    ts_signal man = {0};
    man.type = TS_SIGNAL_RAMP;
    man.axis = TS_AXIS_TURN_RATE;
    man.amplitude = 0.1;
    man.duration = 1.0;
    man.rise = 0.1;
    man.absolute = 1;
    int rc2 = ts_excitation_add_series(ex, TS_AXIS_HEAVE, 4, ts, xs, &e);
    if (rc2 == TS_OK)
        rc2 = ts_excitation_add(ex, &man, &e);
    CHECK(rc2 == TS_OK && ts_excitation_nsignals(ex) == 8,
          "a series and a manoeuvre beside the sum: %s", e.msg);
    ts_excitation *cp = ts_excitation_copy(ex, &e);
    int same = cp && ts_excitation_nsignals(cp) == ts_excitation_nsignals(ex);
    ts_frame base = {0}, fa, fb;
    base.speed = 2;
    for (int i = 0; same && i < 30; i++) {
        double ua[TS_NINPUT], ub[TS_NINPUT], t = 0.11 * i;
        ts_excitation_input(ex, t, ua);
        ts_excitation_input(cp, t, ub);
        ts_excitation_frame(ex, &base, t, &fa);
        ts_excitation_frame(cp, &base, t, &fb);
        same = !memcmp(ua, ub, sizeof ua) && fa.turn_rate == fb.turn_rate &&
               fa.turn_accel == fb.turn_accel;
    }
    ts_excitation_free(ex);
    double uc[TS_NINPUT];
    if (cp)
        ts_excitation_input(cp, 1.3, uc);
    CHECK(same && cp && isfinite(uc[2]), "a copy gives the same inputs and "
          "frames, and outlives the original (%d signals)",
          cp ? ts_excitation_nsignals(cp) : 0);
    ts_excitation_free(cp);
}

/* 7. Signals on a vehicle's inputs: parsed by name, the amplitude a
 * length or an angle, evaluated alone, neither a manoeuvre nor a periodic
 * tow excitation; the tow input untouched. */
static void test_vehicle_inputs(void)
{
    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    int rc = ts_excitation_parse(ex, "fish.wing:sine,amplitude=2deg,"
                                 "period=10s,ramp=0", units, "--excite",
                                 &err);
    rc = rc ? rc : ts_excitation_parse(ex, "fish.depth.setpoint:amplitude=5m,"
                                       "start=1s,rise=2s", units, "--excite",
                                       &err);
    const ts_signal *a = ts_excitation_signal(ex, 0),
                    *b = ts_excitation_signal(ex, 1);
    CHECK(rc == TS_OK && a->axis == TS_AXIS_INPUT &&
              !strcmp(a->input, "fish.wing") && !strcmp(a->input_unit, "rad") &&
              fabs(a->amplitude - 2 * M_PI / 180) < 1e-16 &&
              b->type == TS_SIGNAL_STEP && !strcmp(b->input_unit, "m") &&
              b->amplitude == 5.0,
          "fish.wing sine in rad, fish.depth.setpoint a step (the default) "
          "in m (%s)", err.msg);
    double u[TS_NINPUT];
    ts_excitation_input(ex, 2.0, u);
    int zero = 1;
    for (int j = 0; j < TS_NINPUT; j++)
        zero &= u[j] == 0.0;
    int idx;
    /* At 2.5 s the sine is at 2 deg sin(pi/2); the step at mid-rise is
     * half its amplitude (S(1/2) = 1/2). */
    CHECK(zero && !ts_excitation_has_manoeuvre(ex) &&
              !ts_excitation_periodic(ex, &idx) &&
              fabs(ts_excitation_value(ex, 0, 2.5) - 2 * M_PI / 180) < 1e-16 &&
              fabs(ts_excitation_value(ex, 1, 2.0) - 2.5) < 1e-15,
          "values alone, tow input zero, no manoeuvre, not periodic");
    /* The comparison fits the lone sine on the fin (the step beside it
     * does not count); with a tow sine as well there are two, and none
     * is fitted. */
    idx = -1;
    CHECK(ts_compare_periodic(ex, &idx) && idx == 0,
          "compare: the fin's sine, signal 0, is the periodic excitation");
    ts_excitation *two = ts_excitation_copy(ex, &err);
    rc = two ? ts_excitation_parse(two, "tow.heave:amplitude=0.1m,"
                                   "period=10s", units, "--excite", &err)
             : TS_ENOMEM;
    CHECK(rc == TS_OK && !ts_compare_periodic(two, &idx) &&
              !ts_excitation_periodic(two, &idx),
          "compare: a fin sine and a tow sine, none periodic (%s)", err.msg);
    ts_excitation_free(two);
    const char *badspec[] = {"fish.wing:amplitude=1kg", "fish.wing:crank,"
                             "amplitude=1deg,frequency=1Hz,rod=1m",
                             "fish.wing:amplitude=1deg,to=2deg", "wing:step"};
    for (int i = 0; i < 4; i++) {
        ts_err e = {0};
        rc = ts_excitation_parse(ex, badspec[i], units, "--excite", &e);
        CHECK(rc != TS_OK && strstr(e.msg, "--excite"), "%s refused: %s",
              badspec[i], e.msg);
    }
    ts_excitation_free(ex);
    ts_units_free(units);
}

/* Section 8: the smooth start. */
static void test_smooth_start(void)
{
    ts_signal s = {0};
    s.type = TS_SIGNAL_SINE;
    s.axis = TS_AXIS_HEAVE;
    s.amplitude = 0.03048;
    s.frequency = 0.8375;
    s.phase = 0.4;
    s.ramp = 2.3;
    ts_excitation *ex = one(&s);
    double u[TS_NINPUT], w = 2 * M_PI * s.frequency, maxd = 0;
    for (int i = 0; i < 30; i++) {
        double t = 0.1 * i + 0.013, xi = t / 2.3;
        double R = xi >= 1 ? 1 : xi * xi * xi * (10 - 15 * xi + 6 * xi * xi);
        ts_excitation_input(ex, t, u);
        maxd = fmax(maxd, fabs(u[2] - R * s.amplitude * sin(w * t + 0.4)));
    }
    CHECK(maxd < 1e-16, "smooth sine: A sin(w t + phase) S(t / ramp) (max "
          "err %.2g m < 1e-16)", maxd);
    double ev, ea;
    /* FD step 1e-5 s as in section 1; across the ramp's end S is C2. */
    fd_check(ex, 2, 0.0, 5.0, 80, 1e-5, &ev, &ea);
    CHECK(ev < 1e-8 && ea < 1e-7, "smooth sine: v, a are the derivatives "
          "through the start (max err %.2g m/s, %.2g m/s^2)", ev, ea);
    double du[TS_NINPUT];
    ts_excitation_input(ex, 0.0, u);
    CHECK(!ts_excitation_start_jump(ex, du) && u[2] == 0 && u[5] == 0 &&
              u[8] == 0,
          "smooth sine: at rest at t = 0, no jump");
    double bp[4];
    int nb = ts_excitation_breakpoints(ex, 10.0, bp, 4);
    CHECK(nb == 1 && bp[0] == 2.3, "smooth sine: the ramp's end is a "
          "breakpoint (%d: %g s)", nb, nb ? bp[0] : NAN);
    ts_excitation_free(ex);
    s.ramp = 0;
    ex = one(&s);
    int jump = ts_excitation_start_jump(ex, du);
    CHECK(jump && fabs(du[2] - s.amplitude * sin(0.4)) < 1e-17 &&
              fabs(du[5] - s.amplitude * w * cos(0.4)) < 1e-16 && du[0] == 0,
          "impulsive sine: jumps by A sin(phase), A w cos(phase) at t = 0");
    ts_excitation_free(ex);
    /* The crank's displacement jumps without a ramp. */
    s = (ts_signal){0};
    s.type = TS_SIGNAL_CRANK;
    s.axis = TS_AXIS_SURGE;
    s.amplitude = 0.1;
    s.rod = 0.35;
    s.frequency = 0.625;
    ex = one(&s);
    jump = ts_excitation_start_jump(ex, du);
    CHECK(jump && fabs(du[0] - 0.1) < 1e-16 && du[3] == 0,
          "impulsive crank: jumps by its radius at phase 0");
    ts_excitation_free(ex);

    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ex = ts_excitation_alloc(&err);
    int rc = ts_excitation_parse(ex, "tow.heave:amplitude=0.1ft,"
                                 "frequency=0.25Hz", units, "--excite", &err);
    char buf[256];
    ts_excitation_describe(ex, 0, buf, sizeof buf);
    CHECK(rc == TS_OK && ts_excitation_signal(ex, 0)->ramp == 8.0 &&
              strstr(buf, "smooth start over 8 s (2 periods)"),
          "parser: a smooth start over two periods by default: %s", buf);
    rc = ts_excitation_parse(ex, "tow.heave:type=crank,amplitude=0.1ft,"
                             "rod=0.35ft,period=4s,ramp=0", units, "--excite",
                             &err);
    ts_excitation_describe(ex, 1, buf, sizeof buf);
    CHECK(rc == TS_OK && ts_excitation_signal(ex, 1)->ramp == 0 &&
              strstr(buf, "impulsive start"),
          "parser: ramp=0 starts impulsively: %s", buf);
    rc = ts_excitation_parse(ex, "tow.heave:amplitude=1,frequency=1,ramp=-1",
                             units, "--excite", &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "ramp"),
          "a negative ramp refused: %s", err.msg);
    rc = ts_excitation_parse(ex, "tow.heave:type=step,amplitude=1,ramp=2",
                             units, "--excite", &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "ramp"),
          "ramp does not apply to a step: %s", err.msg);
    ts_excitation_free(ex);
    ts_units_free(units);
}

/* A rotation of the ship (tow.pitch) as a parsed sine: its angle,
 * rate and acceleration land in u[TS_TOW_ROT + 1], + 3, + 6, the
 * translations untouched; it starts smoothly by default (two periods),
 * its derivatives are the angle's (central differences); a sum drives
 * the rotation axes from its last three coefficients; the bound counts
 * it as a rotation. */
static void test_rotation(void)
{
    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ts_excitation *ex = ts_excitation_alloc(&err);
    int rc = ts_excitation_parse(ex, "tow.pitch:amplitude=2.385deg,"
                                 "frequency=0.15Hz", units, "--excite", &err);
    const ts_signal *s = ts_excitation_signal(ex, 0);
    CHECK(rc == TS_OK && s->axis == TS_AXIS_PITCH &&
              fabs(s->amplitude - 2.385 * M_PI / 180) < 1e-15 &&
              fabs(s->ramp - 2 / 0.15) < 1e-12,
          "tow.pitch parsed in rad with the default smooth start (%s)",
          err.msg);
    double u[TS_NINPUT], w = 2 * M_PI * 0.15, A = s->amplitude;
    ts_excitation_input(ex, 0.0, u);
    int zero = 1;
    for (int j = 0; j < TS_NINPUT; j++)
        zero &= u[j] == 0;
    CHECK(zero, "tow.pitch at t = 0: at rest (faded in)");
    ts_excitation_input(ex, 5.0, u);
    double full = A * sin(w * 5.0);
    CHECK(fabs(u[TS_TOW_ROT + 1]) < fabs(full) && u[TS_TOW_ROT + 1] != 0,
          "tow.pitch during the smooth start: less than the sine (%.4g of "
          "%.4g rad)", u[TS_TOW_ROT + 1], full);
    double t = 20.0;
    ts_excitation_input(ex, t, u);
    int others = 1;
    for (int j = 0; j < TS_NINPUT; j++)
        if (j % 3 != 1 || j < TS_TOW_ROT)
            others &= u[j] == 0;
    CHECK(fabs(u[TS_TOW_ROT + 1] - A * sin(w * t)) < 1e-15 &&
              fabs(u[TS_TOW_ROT + 4] - A * w * cos(w * t)) < 1e-15 &&
              fabs(u[TS_TOW_ROT + 7] + A * w * w * sin(w * t)) < 1e-15 &&
              others,
          "tow.pitch after the start: angle, rate and acceleration of the "
          "sine at u[10], u[13], u[16], nothing else");
    double ev, ea;
    fd_check(ex, TS_TOW_ROT + 1, 0.01, 30, 60, 1e-5, &ev, &ea);
    CHECK(ev < 1e-8 && ea < 1e-8, "tow.pitch: rate and acceleration are "
          "the derivatives, in the start too (%.2g, %.2g)", ev, ea);
    int idx;
    CHECK(ts_excitation_periodic(ex, &idx) && idx == 0,
          "a rotation sine is the periodic excitation (amplitude ratios)");
    ts_frame f0 = {0};
    ts_motion_bound mb;
    ts_excitation_bound(ex, &f0, &mb);
    CHECK(mb.tow_speed == 0 && fabs(mb.rot_rate - A * w) < 1e-15 &&
              fabs(mb.rot_accel - A * w * w) < 1e-15,
          "bound: a rotation's rate and acceleration, not the tow point's");
    ts_excitation_free(ex);
    /* A sum on yaw alone. */
    ex = ts_excitation_alloc(&err);
    const double om[1] = {0.7}, re[6] = {0, 0, 0, 0, 0, 0.01},
                 im[6] = {0, 0, 0, 0, 0, -0.02};
    rc = ts_excitation_add_sum(ex, 1, om, re, im, 0, &err);
    ts_excitation_input(ex, 3.0, u);
    CHECK(rc == TS_OK && ts_excitation_nsignals(ex) == 1 &&
              ts_excitation_signal(ex, 0)->axis == TS_AXIS_YAW &&
              fabs(u[TS_TOW_ROT + 2] - (0.01 * cos(2.1) + 0.02 * sin(2.1))) <
                  1e-15 &&
              u[2] == 0,
          "a sum's sixth coefficient drives tow.yaw");
    ts_excitation_free(ex);
    ts_units_free(units);
}

int main(void)
{
    test_rotation();
    test_vehicle_inputs();
    test_sum();
    test_shapes();
    test_smooth_start();
    test_series();
    test_manoeuvres();
    test_meta();
    test_parse();
    return tc_done();
}
