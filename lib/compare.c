/* compare.c: linear against nonlinear histories (towstab/compare.h;
 * doc/simulate.md, "Comparison").
 *
 * Algorithm. The fit x ~ c + a sin wt + b cos wt is linear least squares
 * in (c, a, b): the 3 x 3 normal equations are formed with the time origin
 * and the data centred on the window (which keeps them well conditioned)
 * and solved by LAPACK dgesv. With at least TS_COMPARE_MIN_SAMPLES_PER_PERIOD
 * samples per period and a window of at least one period, harmonics 2..3 of
 * the response do not alias onto the fundamental, and a fit over a window
 * that is not a whole number of periods still returns the fundamental of
 * a pure sinusoid exactly (unlike a plain mean or a DFT bin). The linear
 * prediction is ts_response_compute (response.c), the same algebra as
 * (i w I - A)^-1 (B_x + i w B_v - w^2 B_a) plus the tow feedthrough, for
 * the column of B the excitation drives (lin_input), whose unit makes
 * the ratio's.
 */
#include "towstab/compare.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lazylib.h"

int ts_compare_fit_sinusoid(const double t[], const double x[], int n,
                            double freq_hz, double *mean, double *amplitude,
                            double *phase, ts_err *err)
{
    if (n < 3)
        return ts_fail(err, TS_EINVAL, "fit: at least 3 samples are needed, "
                       "got %d", n);
    if (!(freq_hz > 0) || !isfinite(freq_hz))
        return ts_fail(err, TS_EINVAL, "fit: frequency must be > 0 Hz, got "
                       "%g", freq_hz);
    double w = 2.0 * M_PI * freq_hz, xm = 0.0;
    for (int i = 0; i < n; i++)
        xm += x[i];
    xm /= n;
    /* Basis (1, sin wt, cos wt) with t absolute (the phase refers to
     * t = 0); the data are centred by xm, added back to c. */
    double N[9] = {0}, r[3] = {0};
    for (int i = 0; i < n; i++) {
        double ph[3] = {1.0, sin(w * t[i]), cos(w * t[i])}, d = x[i] - xm;
        for (int p = 0; p < 3; p++) {
            r[p] += ph[p] * d;
            for (int q = 0; q < 3; q++)
                N[p + 3 * q] += ph[p] * ph[q];
        }
    }
    tsi_lapack la;
    if (tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    int three = 3, one = 1, ipiv[3], info = 0;
    double Ncopy[9];
    memcpy(Ncopy, N, sizeof N);
    la.dgesv_(&three, &one, Ncopy, &three, ipiv, r, &three, &info);
    /* Reject a numerically singular system too: the normal matrix of a
     * resolved sinusoid has a condition number of order 1. */
    double diag_min = fmin(N[0], fmin(N[4], N[8]));
    if (info != 0 || !(diag_min > 1e-6 * n) || !isfinite(r[0] + r[1] + r[2]))
        return ts_fail(err, TS_EINVAL, "fit: the %d samples do not resolve "
                       "a %g Hz sinusoid", n, freq_hz);
    *mean = xm + r[0];
    *amplitude = hypot(r[1], r[2]);
    *phase = atan2(r[2], r[1]);
    return TS_OK;
}

double ts_compare_wrap_deg(double d)
{
    d = fmod(d, 360.0);
    if (d > 180.0)
        d -= 360.0;
    if (d <= -180.0)
        d += 360.0;
    return d;
}

int ts_compare_periodic(const ts_excitation *ex, int *index)
{
    if (ts_excitation_periodic(ex, index))
        return 1;
    int found = -1, n = ts_excitation_nsignals(ex);
    for (int i = 0; i < n; i++) {
        const ts_signal *s = ts_excitation_signal(ex, i);
        if (s->type == TS_SIGNAL_SINE || s->type == TS_SIGNAL_CRANK ||
            s->type == TS_SIGNAL_SUM) {
            if (found >= 0 || s->type != TS_SIGNAL_SINE ||
                s->axis != TS_AXIS_INPUT)
                return 0;
            found = i;
        }
    }
    if (found < 0)
        return 0;
    *index = found;
    return 1;
}

/* The column of lin's B that signal s drives: a tow axis' displacement or
 * rotation, a manoeuvre's frame input, a vehicle's input by its name; -1
 * when lin has none (a name it does not know). */
static int lin_input(const ts_linear *lin, const ts_signal *s)
{
    switch (s->axis) {
    case TS_AXIS_SURGE:
    case TS_AXIS_SWAY:
    case TS_AXIS_HEAVE:
        return TS_IN_DISP + (int)s->axis;
    case TS_AXIS_ROLL:
    case TS_AXIS_PITCH:
    case TS_AXIS_YAW:
        return TS_IN_ROT + (int)(s->axis - TS_AXIS_ROLL);
    case TS_AXIS_SPEED:
        return lin->frame_input + TS_FRAME_SPEED;
    case TS_AXIS_TURN_RATE:
        return lin->frame_input + TS_FRAME_TURN_RATE;
    case TS_AXIS_INPUT:
        for (int j = TS_NINPUT; lin->input_name && j < lin->frame_input; j++)
            if (!strcmp(lin->input_name[j], s->input))
                return j;
        return -1;
    }
    return -1;
}

/* The name and unit of lin's input col and the ratio's unit, output per
 * input, written as ts_response's ("m/rad", "N/(m/s)"). */
static void ratio_unit(ts_compare *c, const ts_linear *lin, int col)
{
    const char *iu = lin->input_unit[col];
    snprintf(c->input, sizeof c->input, "%s", lin->input_name[col]);
    snprintf(c->input_unit, sizeof c->input_unit, "%s", iu);
    snprintf(c->ratio_unit, sizeof c->ratio_unit,
             strchr(iu, '/') ? "%s/(%s)" : "%s/%s", c->output.si_unit, iu);
}

/* The change du of the single step or ramp of ex (its only signal) once
 * it has reached its final value at t (else NaN): its amplitude; a
 * manoeuvre given as its final value (`absolute`) changes the system's
 * speed or turn rate by that value less the base. */
static double step_change(const ts_system *sys, const ts_excitation *ex,
                          double t)
{
    if (ts_excitation_nsignals(ex) != 1)
        return NAN;
    const ts_signal *s = ts_excitation_signal(ex, 0);
    double end = s->type == TS_SIGNAL_STEP   ? s->start + s->rise
                 : s->type == TS_SIGNAL_RAMP ? s->start + s->duration + s->rise
                                             : INFINITY;
    if (!(t >= end))
        return NAN;
    double du = s->amplitude;
    if (s->absolute && s->axis == TS_AXIS_SPEED)
        du -= sys->tow.speed;
    else if (s->absolute && s->axis == TS_AXIS_TURN_RATE)
        du -= sys->tow.turn_rate;
    return du != 0 ? du : NAN;
}

static void run_stats(const double *t, const double *x, int n, double eq,
                      int periodic, double f, double exc_amp,
                      double exc_phase, ts_compare_run *r, ts_err *err,
                      int *rc)
{
    double lo = INFINITY, hi = -INFINITY, sum = 0.0;
    for (int i = 0; i < n; i++) {
        lo = fmin(lo, x[i]);
        hi = fmax(hi, x[i]);
        sum += x[i];
    }
    r->half_range = 0.5 * (hi - lo);
    r->amplitude = r->amplitude_ratio = r->phase_deg = NAN;
    r->final_gain = NAN;
    r->mean_offset = sum / n - eq;
    if (!periodic || *rc)
        return;
    double c, a, ph;
    *rc = ts_compare_fit_sinusoid(t, x, n, f, &c, &a, &ph, err);
    if (*rc)
        return;
    r->mean_offset = c - eq;
    r->amplitude = a;
    r->amplitude_ratio = a / exc_amp;
    r->phase_deg = ts_compare_wrap_deg((ph - exc_phase) * 180.0 / M_PI);
}

int ts_compare_histories(const ts_system *sys, const ts_linear *lin,
                         const ts_excitation *ex, const ts_history *nl,
                         const ts_history *li, const ts_output *out,
                         double t_discard, ts_compare *c, ts_err *err)
{
    memset(c, 0, sizeof *c);
    c->output = *out;
    if (out->kind != TS_OUT_POSITION &&
        !(out->kind == TS_OUT_TENSION && ((lin->Ty && lin->Tu) ||
                                           lin->desc)) &&
        !(out->kind == TS_OUT_VEHICLE && out->index < lin->noutput))
        return ts_fail(err, TS_EINVAL, "compare: output '%s': the linear "
                       "model gives node positions, the vehicles' outputs "
                       "and, with its tension Jacobians or its sparse "
                       "form, link tensions (choose <node>.x|y|z, "
                       "<vehicle>.depth ... or <cable>.<k>.tension)",
                       out->name);
    if (nl->nsamples != li->nsamples || nl->nsamples < 1)
        return ts_fail(err, TS_EINVAL, "compare: the runs have %d and %d "
                       "samples; they must share their sample times",
                       nl->nsamples, li->nsamples);
    for (int i = 0; i < nl->nsamples; i++)
        if (fabs(nl->t[i] - li->t[i]) > 1e-9 * (1.0 + fabs(nl->t[i])))
            return ts_fail(err, TS_EINVAL, "compare: sample %d is at %g s in "
                           "one run and %g s in the other", i, nl->t[i],
                           li->t[i]);
    double t_end = nl->t[nl->nsamples - 1];
    if (!(t_discard >= 0) || !(t_discard < t_end))
        return ts_fail(err, TS_EINVAL, "compare: the transient to discard "
                       "must be in [0, %g) s (the run's end), got %g s",
                       t_end, t_discard);
    int first = 0;
    while (first < nl->nsamples && nl->t[first] < t_discard - 1e-12)
        first++;
    int n = nl->nsamples - first;
    if (n < 3)
        return ts_fail(err, TS_EINVAL, "compare: only %d samples after the "
                       "discarded transient (%g s); need at least 3", n,
                       t_discard);
    c->t_from = nl->t[first];
    c->t_to = t_end;
    c->nsamples = n;
    c->equilibrium = out->kind == TS_OUT_VEHICLE
                         ? lin->v0[out->index]
                         : ts_output_value(sys, out, lin->r0, lin->t0, NULL);

    double *buf = malloc(4 * (size_t)n * sizeof(double));
    if (!buf)
        return ts_fail(err, TS_ENOMEM, "compare: out of memory");
    double *tt = buf, *xn = buf + n, *xl = buf + 2 * n, *xe = buf + 3 * n;
    for (int i = 0; i < n; i++) {
        tt[i] = nl->t[first + i];
        xn[i] = ts_history_value(sys, nl, out, first + i);
        xl[i] = ts_history_value(sys, li, out, first + i);
        if (!isfinite(xn[i]) || !isfinite(xl[i])) {
            free(buf);
            return ts_fail(err, TS_EINVAL, "compare: %s is not finite at t "
                           "= %g s in the %s run", out->name, tt[i],
                           isfinite(xn[i]) ? "linear" : "nonlinear");
        }
    }

    int idx = 0, rc = TS_OK;
    c->periodic = ex && ts_compare_periodic(ex, &idx);
    double f = 0, exc_amp = NAN, exc_phase = 0;
    c->pred_ratio = c->pred_phase_deg = c->static_gain = NAN;
    c->exc_amplitude = c->exc_frequency_hz = c->exc_fit_amplitude = NAN;
    if (c->periodic) {
        const ts_signal *s = ts_excitation_signal(ex, idx);
        c->exc_axis = s->axis;
        c->exc_type = s->type;
        c->exc_amplitude = s->amplitude;
        c->exc_frequency_hz = f = s->frequency;
        int col = lin_input(lin, s);
        double period = 1.0 / f, dt = (c->t_to - c->t_from) / (n - 1);
        if (col < 0)
            rc = ts_fail(err, TS_EINVAL, "compare: the linear model has no "
                         "input %s", s->input);
        else if (c->t_to - c->t_from < period * (1.0 - 1e-9))
            rc = ts_fail(err, TS_EINVAL, "compare: the window %g..%g s is "
                         "shorter than one period (%g s) of the %g Hz "
                         "excitation; run longer or discard less",
                         c->t_from, c->t_to, period, f);
        else if (dt > period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD * (1 + 1e-9))
            rc = ts_fail(err, TS_EINVAL, "compare: the sample interval %g s "
                         "is too coarse for %g Hz; at most %g s (%d samples "
                         "per period) are needed", dt, f,
                         period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD,
                         TS_COMPARE_MIN_SAMPLES_PER_PERIOD);
        /* A tow axis: the history's input, the sum of every signal on
         * it; a vehicle's input: its signal (the history keeps the tow
         * inputs only). */
        for (int i = 0; i < n && !rc; i++)
            xe[i] = s->axis == TS_AXIS_INPUT
                        ? ts_excitation_value(ex, idx, tt[i])
                        : nl->input[TS_NINPUT * (size_t)(first + i) +
                                    s->axis];
        double ce;
        if (!rc)
            rc = ts_compare_fit_sinusoid(tt, xe, n, f, &ce, &exc_amp,
                                         &exc_phase, err);
        c->exc_fit_amplitude = exc_amp;
        if (!rc) {
            double re, im;
            rc = ts_response_at(sys, lin, col, out, 2.0 * M_PI * f, &re, &im,
                                err);
            c->pred_ratio = hypot(re, im);
            c->pred_phase_deg = atan2(im, re) * 180.0 / M_PI;
            ratio_unit(c, lin, col);
        }
    } else if (ex && isfinite(step_change(sys, ex, c->t_to))) {
        const ts_signal *s = ts_excitation_signal(ex, 0);
        int col = lin_input(lin, s);
        ts_response *res = NULL;
        /* Any frequency above 0: the static gain comes with it. */
        double f1 = 1.0;
        if (col >= 0)
            rc = ts_response_compute(sys, lin, col, out, &f1, 1, &res, err);
        /* A model singular at 0 Hz (an undamped neutral mode), or one
         * whose response to this input is not formed (the frame inputs'
         * columns not asked for), has no static gain here, but the runs
         * still have their final values. */
        if (col >= 0 && (rc == TS_ESINGULAR || rc == TS_EINVAL)) {
            c->step = 1;
            snprintf(c->static_note, sizeof c->static_note, "%s: %.200s",
                     rc == TS_ESINGULAR ? "undefined" : "not available",
                     err ? err->msg : "");
            ts_err_clear(err);
            rc = TS_OK;
        } else if (!rc) {
            c->step = 1;
            c->static_gain = res->static_gain;
            snprintf(c->static_note, sizeof c->static_note, "%s",
                     res->static_note);
        }
        if (c->step) {
            c->exc_axis = s->axis;
            c->exc_type = s->type;
            c->exc_amplitude = step_change(sys, ex, c->t_to);
            ratio_unit(c, lin, col);
        }
        ts_response_free(res);
    }
    if (!rc) {
        run_stats(tt, xl, n, c->equilibrium, c->periodic, f, exc_amp,
                  exc_phase, &c->linear, err, &rc);
        run_stats(tt, xn, n, c->equilibrium, c->periodic, f, exc_amp,
                  exc_phase, &c->nonlinear, err, &rc);
    }
    if (!rc && c->step) {
        c->linear.final_gain = (xl[n - 1] - c->equilibrium) / c->exc_amplitude;
        c->nonlinear.final_gain =
            (xn[n - 1] - c->equilibrium) / c->exc_amplitude;
    }
    if (!rc) {
        double ss = 0.0;
        for (int i = 0; i < n; i++)
            ss += (xl[i] - xn[i]) * (xl[i] - xn[i]);
        c->rms_difference = sqrt(ss / n);
        c->rms_difference_ratio = c->periodic ? c->rms_difference / exc_amp
                                              : NAN;
        c->amplitude_difference_pct =
            c->periodic ? 100.0 * (c->linear.amplitude_ratio -
                                   c->nonlinear.amplitude_ratio) /
                              c->nonlinear.amplitude_ratio
                        : NAN;
        c->mean_difference_pct =
            c->nonlinear.mean_offset != 0
                ? 100.0 * (c->linear.mean_offset - c->nonlinear.mean_offset) /
                      fabs(c->nonlinear.mean_offset)
                : NAN;
    }
    free(buf);
    return rc;
}
