/* towstab/excitation.h: prescribed motions as functions of time, for the
 * simulator (doc/simulate.md; doc/model.md sections 1 and 8).
 *
 * An excitation is a list of signals. A signal drives one axis:
 *  - a tow-point axis (surge x, sway y, heave z of the mean ship frame M):
 *    the signal is the tow point's displacement from its nominal position
 *    (m); or a rotation axis (roll, pitch, yaw: a small rotation of the
 *    ship about x, y, z of M, rad, which moves a cable start point r by
 *    theta x r, towstab/kernel.h); the kernel's tow inputs u[TS_NINPUT]
 *    (displacement, velocity, acceleration, each x, y, z, then the same
 *    of the rotation) are the sum of the signals on each axis with their
 *    analytic first and second time derivatives;
 *  - a manoeuvre axis (the speed V of M, or its turn rate Omega): the
 *    signal is the change of V (m/s) or Omega (rad/s) from the base frame,
 *    and the frame of time t carries the matching speed_rate / turn_accel
 *    (doc/model.md sections 1 and 10). The current, fixed in inertial
 *    space, rotates in M by the heading change psi(t) = integral of Omega;
 *  - a vehicle's input (TS_AXIS_INPUT, named by ts_signal.input: a control
 *    surface "<vehicle>.<surface>", a loop's output "<vehicle>.<loop>" or
 *    its set point "<vehicle>.<loop>.setpoint", ts_kernel_input_name): the
 *    signal is added to that kernel input (rad, or m for a depth set
 *    point); a sine, a step or a ramp (ts_excitation_value). The name is
 *    checked against the kernel by the simulator.
 *
 * Signal shapes (t in s; A the amplitude; w = 2 pi f):
 *  - sine:   A sin(w t + phase), for all t >= 0;
 *  - crank:  slider crank of radius A and rod l (doc/model.md section 8),
 *            A cos(th) + l (1 - sqrt(1 - (A/l)^2 sin^2 th)), th = w t + phase;
 *            a sine or crank starts smoothly: times S(t / ramp) (S below),
 *            full from t = ramp on (default two periods; ramp = 0 starts
 *            at full amplitude, a jump at t = 0);
 *  - step:   0 before `start`, A after `start + rise`, in between the quintic
 *            A S(xi), S(xi) = 10 xi^3 - 15 xi^4 + 6 xi^5, xi = (t-start)/rise:
 *            displacement, velocity and acceleration are continuous;
 *  - ramp:   0 before `start`, A after `start + duration + rise`, rising
 *            linearly at A/duration in between, the two corners rounded
 *            over `rise` (the rate itself follows S), so that the velocity
 *            and acceleration are continuous and the final value is exactly A;
 *  - series: a natural cubic spline through samples (t_i, x_i) (tow axes
 *            only), defined on [t_0, t_last] with t_0 <= 0;
 *  - sum:    a sum of sinusoids shared by the tow axes, the tow point's
 *            motion in an irregular sea (towstab/seastate.h):
 *            x_j = r(t) sum_k Re(c_jk e^(i w_k t)), faded in by
 *            r = S(t / rise) (r = 1 without a rise); one signal per axis
 *            driven, the components evaluated once for all of them.
 * A rigid-link cable cannot follow a tow point whose velocity jumps (it
 * would need an impulsive tension), hence the rounded steps and ramps:
 * `rise` must be > 0 (default TS_SIGNAL_RISE).
 *
 * Manoeuvre signals are steps or ramps only (their heading integral is
 * closed-form). Their amplitude is the change of V or Omega, or, with
 * `absolute` set, the final value (the change is then that value less the
 * base frame's).
 */
#ifndef TOWSTAB_EXCITATION_H
#define TOWSTAB_EXCITATION_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/kernel.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_SIGNAL_RISE 0.1   /* default rise / corner time of steps, ramps, s */
#define TS_SIGNAL_RAMP_PERIODS 2.0 /* default smooth start of a sine or crank,
                                      periods */

typedef enum {
    TS_SIGNAL_SINE = 0,
    TS_SIGNAL_CRANK = 1,
    TS_SIGNAL_STEP = 2,
    TS_SIGNAL_RAMP = 3,
    TS_SIGNAL_SERIES = 4,
    TS_SIGNAL_SUM = 5
} ts_signal_type;

typedef enum {
    TS_AXIS_SURGE = 0,     /* tow point, x of M (forward) */
    TS_AXIS_SWAY = 1,      /* tow point, y of M (starboard) */
    TS_AXIS_HEAVE = 2,     /* tow point, z of M (down) */
    TS_AXIS_SPEED = 3,     /* speed V of M */
    TS_AXIS_TURN_RATE = 4, /* turn rate Omega of M */
    TS_AXIS_INPUT = 5,     /* a vehicle's input, named by ts_signal.input */
    /* A small rotation of the ship about x, y, z of M (rad; towstab/
     * kernel.h): each value is the index of its kernel input, as the
     * translations' are (its rate 3 after, its acceleration 6 after). */
    TS_AXIS_ROLL = 9,
    TS_AXIS_PITCH = 10,
    TS_AXIS_YAW = 11
} ts_axis;

/* Axes of a sum of sinusoids (ts_excitation_add_sum): surge, sway,
 * heave, roll, pitch, yaw. */
#define TS_SUM_AXES 6

/* Longest name of a vehicle input (TS_IO_NAME of towstab/linearize.h). */
#define TS_SIGNAL_INPUT_MAX (2 * TS_NAME_MAX + 16)

/* One signal. Fields a type does not use are ignored. */
typedef struct ts_signal {
    ts_signal_type type;
    ts_axis axis;
    double amplitude;  /* m on tow axes, m/s on speed, rad/s on turn rate;
                          the crank radius for a crank; a sum's rms
                          (sqrt(sum_k |c_jk|^2 / 2), before the fade-in) */
    double frequency;  /* Hz, > 0 (sine, crank); a sum's highest |w_k| /
                          2 pi */
    double phase;      /* rad (sine, crank) */
    double rod;        /* m, > amplitude (crank) */
    double start;      /* s, >= 0 (step, ramp) */
    double duration;   /* s, > 0 (ramp) */
    double rise;       /* s, > 0 (step, ramp); >= 0 fade-in (sum) */
    double ramp;       /* s, >= 0 (sine, crank): the signal starts
                          smoothly, times S(t / ramp) (the quintic of the
                          steps), reaching full amplitude at t = ramp; 0
                          (a zeroed struct) starts at full amplitude, a
                          jump in velocity (sine) or displacement (crank)
                          at t = 0. The parser's default is two periods
                          (TS_SIGNAL_RAMP_PERIODS) */
    int absolute;      /* manoeuvres: amplitude is the final value */
    char input[TS_SIGNAL_INPUT_MAX]; /* TS_AXIS_INPUT: the input's name */
    char input_unit[4];/* TS_AXIS_INPUT: "m", "rad", "N" or "N*m" when the amplitude
                          was given with a unit of that kind, "" for a
                          plain (SI) number */
} ts_signal;

typedef struct ts_excitation ts_excitation;

/* An empty excitation (no signal: u = 0, the frame unchanged). */
TS_API ts_excitation *ts_excitation_alloc(ts_err *err);
TS_API void ts_excitation_free(ts_excitation *ex);

/* A deep copy of ex (NULL: an empty excitation), to add signals to
 * without changing ex. NULL on failure (TS_ENOMEM). */
TS_API ts_excitation *ts_excitation_copy(const ts_excitation *ex,
                                         ts_err *err);

/* Add a copy of signal s after checking it (TS_EINVAL naming the field:
 * frequency <= 0, negative start, rise <= 0, a crank rod not longer than
 * its radius, a series or sine on a manoeuvre axis, a second absolute
 * signal on one manoeuvre axis, non-finite values). */
TS_API int ts_excitation_add(ts_excitation *ex, const ts_signal *s,
                             ts_err *err);

/* Add a series on tow axis `axis` through n >= 3 samples t[n] (s, strictly
 * increasing, t[0] <= 0) and x[n] (m). The arrays are copied. */
TS_API int ts_excitation_add_series(ts_excitation *ex, ts_axis axis, int n,
                                    const double t[], const double x[],
                                    ts_err *err);

/* Add a sum of n >= 1 sinusoids driving the tow axes, with shared
 * components: axis j (0 surge, 1 sway, 2 heave, m; 3 roll, 4 pitch, 5
 * yaw, rad; TS_SUM_AXES) moves by
 *   x_j(t) = r(t) sum_k (re[6 k + j] cos(w_k t) - im[6 k + j] sin(w_k t)),
 * w_k = omega[k] (rad/s, finite, any sign), r the quintic fade-in over
 * [0, rise] (rise >= 0 s; 0: none, the motion starts at full amplitude).
 * Adds one TS_SIGNAL_SUM signal for each axis with a nonzero coefficient
 * (TS_EINVAL when there is none, or for a non-finite value); the
 * components are copied and evaluated once per time for all the axes
 * (n sines and cosines). */
TS_API int ts_excitation_add_sum(ts_excitation *ex, int n,
                                 const double omega[], const double re[],
                                 const double im[], double rise,
                                 ts_err *err);

/* Read a series from a CSV file: two columns, time (s) and displacement
 * (m); lines starting with '#' and a first line that is not numeric (a
 * header) are skipped; further columns are ignored. TS_EIO when the file
 * cannot be read, TS_EINVAL (with the line) for a bad number. */
TS_API int ts_excitation_read_series(ts_excitation *ex, ts_axis axis,
                                     const char *path, ts_err *err);

/* Parse a signal description and add it:
 *   AXIS[:key=value,key=value,...]
 * AXIS is tow.surge (tow.x), tow.sway (tow.y), tow.heave (tow.z), tow.roll,
 * tow.pitch, tow.yaw (amplitude in rad or deg; no crank), speed,
 * turn_rate, or a vehicle's input (any other name with a '.', e.g.
 * fish.depth.setpoint: a step by default, its amplitude in m or rad). Keys: type (sine, crank, step, ramp, csv; default sine on tow
 * axes, ramp on manoeuvres), amplitude, frequency or period, phase, rod,
 * start, duration, rise, to (final value, manoeuvres), by (change,
 * manoeuvres), file (csv), ramp (sine and crank: the smooth start, s;
 * default two periods; 0 for an impulsive start). Values may carry units ("0.1ft", "0.25 Hz",
 * "30deg", "0.5rad/s"); plain numbers are SI. `where` names the origin in
 * messages ("--excite"). Unknown axes, types and keys, missing or
 * conflicting keys and out-of-range values give TS_EINVAL or TS_EUNIT. */
TS_API int ts_excitation_parse(ts_excitation *ex, const char *spec,
                               const ts_units *units, const char *where,
                               ts_err *err);

TS_API int ts_excitation_nsignals(const ts_excitation *ex);
/* Signal i, 0 <= i < nsignals (a series reports type TS_SIGNAL_SERIES). */
TS_API const ts_signal *ts_excitation_signal(const ts_excitation *ex, int i);

/* The value at t of signal i (a step, ramp or sine; for a vehicle input,
 * in the input's unit). */
TS_API double ts_excitation_value(const ts_excitation *ex, int i, double t);

/* The jump of the tow inputs' displacements and velocities at t = 0
 * (u(0+) less the rest state before, zero): nonzero only for a sine or
 * crank started impulsively (ramp 0). du[TS_NINPUT] in the kernel's
 * layout (du[0..3) displacement, m, du[3..6) velocity, m/s, the
 * accelerations zero, then the rotations' alike). Returns 1 when there
 * is a jump. */
TS_API int ts_excitation_start_jump(const ts_excitation *ex,
                                    double du[TS_NINPUT]);

/* 1 when any signal drives the speed or the turn rate. */
TS_API int ts_excitation_has_manoeuvre(const ts_excitation *ex);

/* The tow-point input at time t: u[0..3) displacement (m), u[3..6)
 * velocity (m/s), u[6..9) acceleration (m/s^2), in M; u[9..18) the
 * rotation's (rad, rad/s, rad/s^2). */
TS_API void ts_excitation_input(const ts_excitation *ex, double t,
                                double u[TS_NINPUT]);

/* The frame at time t, from the frame `base` of t = 0 (its speed, turn
 * rate and current; its rates are ignored): speed, turn rate and their
 * rates from the manoeuvre signals, current rotated by the heading change.
 * f may alias base. */
TS_API void ts_excitation_frame(const ts_excitation *ex, const ts_frame *base,
                                double t, ts_frame *f);

/* Heading change psi(t) = integral_0^t Omega dt (rad, about +z of M). */
TS_API double ts_excitation_heading(const ts_excitation *ex,
                                    const ts_frame *base, double t);

/* Times in (0, t_end) where a signal is not smooth (ends of steps, ramp
 * corners, the end of a smooth start or of a sum's fade-in), sorted,
 * without duplicates; writes at most `max` of them to out and returns how
 * many there are. */
TS_API int ts_excitation_breakpoints(const ts_excitation *ex, double t_end,
                                     double out[], int max);

/* The shortest time scale of the signals (s): 1/(2 pi f) for a sine,
 * 1/(4 pi f) for a crank (its second harmonic), the rise of steps and
 * ramps (manoeuvres included), the smallest sample spacing of a series,
 * 1/max |w_k| for a sum (and its fade-in time, if shorter); INFINITY
 * without signals. The linear simulator sizes its steps on it. */
TS_API double ts_excitation_time_scale(const ts_excitation *ex);

/* Bounds of the motion under ex from the frame `base` (ex may be NULL:
 * none): |speed| and |turn rate| at most their base values plus every
 * manoeuvre's change; the tow point's velocity and acceleration at most
 * the sum over its signals of each one's largest (a sine: A w and A w^2; a
 * crank: those times 1 + A / sqrt(l^2 - A^2) and its square; a step:
 * 1.875 A / rise and 5.78 A / rise^2, the quintic's largest slopes; a
 * ramp: A / duration and 1.875 A / (duration rise); a series: its largest
 * sample differences; a sum of sinusoids: the sums of |c_k| w_k and
 * |c_k| w_k^2, with its fade-in's slopes). For ts_system_check_loads. */
TS_API void ts_excitation_bound(const ts_excitation *ex, const ts_frame *base,
                                ts_motion_bound *m);

/* Check that every series covers [0, t_end] (TS_EINVAL otherwise). */
TS_API int ts_excitation_check_span(const ts_excitation *ex, double t_end,
                                    ts_err *err);

/* The single periodic tow excitation, for amplitude ratios: when exactly
 * one signal is a sine or a crank, on a tow axis, returns 1 and its index;
 * else 0 (also when a sine drives a vehicle's input). */
TS_API int ts_excitation_periodic(const ts_excitation *ex, int *index);

/* Number of components of sum signal i (0 for other signals). */
TS_API int ts_excitation_sum_components(const ts_excitation *ex, int i);

/* Names: "tow.surge", "tow.sway", "tow.heave", "speed", "turn_rate",
 * "input", "tow.roll", "tow.pitch", "tow.yaw";
 * "sine", "crank", "step", "ramp", "csv", "sum". */
TS_API const char *ts_axis_name(ts_axis a);
TS_API const char *ts_signal_type_name(ts_signal_type t);
/* A signal's axis in messages: ts_axis_name, or its input's name on
 * TS_AXIS_INPUT. */
TS_API const char *ts_signal_axis_label(const ts_signal *s);

/* One-line description of signal i with SI values, e.g.
 * "tow.heave sine amplitude 0.03048 m, frequency 0.25 Hz, phase 0 deg". */
TS_API void ts_excitation_describe(const ts_excitation *ex, int i, char *buf,
                                   size_t size);
/* The same in the display units d (towstab/units.h; NULL: SI): the
 * amplitude in the unit of its axis' quantity (length, speed, turn rate;
 * a vehicle input's "m" or "rad" as length or angle), times, frequencies
 * and phases in theirs. */
TS_API void ts_excitation_describe_display(const ts_excitation *ex, int i,
                                           const ts_display *d, char *buf,
                                           size_t size);

#ifdef __cplusplus
}
#endif
#endif
