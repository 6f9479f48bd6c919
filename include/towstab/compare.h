/* towstab/compare.h: linear against nonlinear time histories, to show
 * where the linear model can be trusted (doc/simulate.md, "Comparison";
 * Kamman & Nguyen 1990, example 4).
 *
 * Over a window [t_discard, t_end] (the transient discarded) the chosen
 * output (a node coordinate, e.g. sphere.z) of both runs is fitted by least
 * squares at the excitation frequency f,
 *   x(t) ~ c + a sin(2 pi f t) + b cos(2 pi f t),
 * and so is the tow-point displacement along the excitation axis. The
 * amplitude ratio is |(a, b)| of the output over that of the excitation
 * (its fundamental: exactly the sine amplitude, or the crank radius, as
 * the rod term of a slider crank has even harmonics only); the phase is
 * the difference of the two phases (output leads when > 0); the mean
 * offset is c less the output's equilibrium value. Differences are
 * relative to the nonlinear run, taken as the truth:
 *   amplitude_difference_pct = 100 (ratio_lin - ratio_nl) / ratio_nl,
 *   mean_difference_pct = 100 (offset_lin - offset_nl) / |offset_nl|,
 * and the RMS of x_lin - x_nl over the window (m). The linear
 * frequency-response prediction at f comes from ts_response_at
 * (towstab/response.h). The periodic excitation is a sine or crank on a
 * tow axis (ts_excitation_periodic) or a lone sine on a vehicle's input
 * (ts_compare_periodic); the excitation is then that input's value (m,
 * rad, N, ...) and a ratio is the output's unit per the input's
 * (ratio_unit: "m/m", "m/rad", "N/m"). Without a single periodic
 * excitation the means are plain window averages and the amplitude
 * fields are NaN: an amplitude and a phase belong to a sinusoid.
 *
 * A step instead: when the excitation is a single step or ramp (on any
 * axis, a manoeuvre's or a vehicle's input included) that has reached its
 * final value by the end of the run, the final-value gain of each run,
 *   final_gain = (x(t_end) - x_eq) / du,
 * du the input's change (input_unit), estimates the steady-state gain; the
 * linear model's static gain H(0) (ts_response.static_gain) is its
 * prediction, NaN where a towing vehicle's neutral modes leave it
 * undefined (static_note says why). The linear run's final gain reaches
 * H(0) as the run settles: their difference says how far it is from
 * settled. Otherwise final_gain and static_gain are NaN.
 */
#ifndef TOWSTAB_COMPARE_H
#define TOWSTAB_COMPARE_H

#include "towstab/error.h"
#include "towstab/excitation.h"
#include "towstab/linearize.h"
#include "towstab/response.h"
#include "towstab/simulate.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Fewest samples per period the least-squares fit accepts. */
#define TS_COMPARE_MIN_SAMPLES_PER_PERIOD 8

typedef struct ts_compare_run {
    double amplitude;        /* fitted output amplitude, m or N */
    double amplitude_ratio;  /* amplitude / excitation amplitude
                                (ratio_unit) */
    double phase_deg;        /* output phase less the excitation's, deg */
    double mean_offset;      /* mean (fitted constant) less equilibrium,
                                m or N */
    double half_range;       /* (max - min) / 2 over the window, m or N */
    double final_gain;       /* a step's (x(t_end) - equilibrium) / its
                                change (ratio_unit); NaN otherwise */
} ts_compare_run;

typedef struct ts_compare {
    ts_output output;        /* what is compared */
    int periodic;            /* 1: a single periodic excitation
                                (ts_compare_periodic) */
    int step;                /* 1: a single step or ramp, finished by
                                t_to (final_gain, static_gain) */
    ts_axis exc_axis;        /* its axis */
    ts_signal_type exc_type;
    char input[TS_IO_NAME];  /* the input it drives: "tow.heave",
                                "tow.pitch", "aurora.wing", "tow.speed"
                                ("" when neither periodic nor a step) */
    char input_unit[16];     /* that input's SI unit: "m", "rad", "N" */
    char ratio_unit[48];     /* the output's SI unit per the input's:
                                "m/m", "N/m", "m/rad" (ts_response's) */
    double exc_amplitude;    /* its nominal amplitude (crank radius);
                                a step's change du; input_unit */
    double exc_frequency_hz; /* Hz */
    double exc_fit_amplitude;/* fitted fundamental of the input,
                                input_unit */
    double t_from, t_to;     /* window, s */
    int nsamples;            /* samples in the window */
    double equilibrium;      /* output's equilibrium value, m or N */
    ts_compare_run linear, nonlinear;
    double pred_ratio;       /* |H(i w)| of the linear model */
    double pred_phase_deg;   /* arg H(i w), deg */
    double static_gain;      /* a step's H(0) (ratio_unit), NaN when
                                undefined or not a step */
    char static_note[256];   /* why static_gain is NaN for a step, else
                                "" (ts_response.static_note) */
    double amplitude_difference_pct;
    double mean_difference_pct;
    double rms_difference;   /* m or N */
    double rms_difference_ratio; /* rms / excitation amplitude
                                    (ratio_unit) */
} ts_compare;

/* The single periodic excitation a comparison fits: ts_excitation_periodic's
 * (one sine or crank, on a tow axis), or else exactly one sine of all
 * the signals, on a vehicle's input (TS_AXIS_INPUT). Returns 1 and its
 * index, else 0. */
TS_API int ts_compare_periodic(const ts_excitation *ex, int *index);

/* Least-squares fit x[i] ~ c + a sin(w t[i]) + b cos(w t[i]) over n
 * samples (w = 2 pi freq_hz, > 0): mean c, amplitude |(a, b)| and phase
 * atan2(b, a) (rad). TS_EINVAL when n < 3 or the normal equations are
 * singular (the samples do not resolve the frequency). */
TS_API int ts_compare_fit_sinusoid(const double t[], const double x[],
                                   int n, double freq_hz, double *mean,
                                   double *amplitude, double *phase,
                                   ts_err *err);

/* A phase difference in degrees wrapped into (-180, 180]. */
TS_API double ts_compare_wrap_deg(double deg);

/* Compare the output `out` of the nonlinear history nl and the linear
 * history li (same sample times) over t >= t_discard: a node position,
 * or a link tension when lin has the tension Jacobians (the linear run
 * then records tensions). lin is the linear model (its r0 and t0 give the
 * equilibrium value and it yields the frequency response), ex the
 * excitation of both runs. Amplitudes, offsets and ranges are in the
 * output's unit (m or N). Returns TS_OK or TS_EINVAL (different sample
 * times, a window with fewer than 3 samples or shorter than one period,
 * fewer than TS_COMPARE_MIN_SAMPLES_PER_PERIOD samples per period,
 * another kind of output, a value that is not finite, t_discard outside
 * [0, t_end)). */
TS_API int ts_compare_histories(const ts_system *sys, const ts_linear *lin,
                                const ts_excitation *ex,
                                const ts_history *nl, const ts_history *li,
                                const ts_output *out, double t_discard,
                                ts_compare *c, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
