/* towstab/simulate.h: time-domain simulation, nonlinear y' = f(y, u(t))
 * through the one kernel and linear z' = A z + B v about an equilibrium
 * (doc/simulate.md; Kamman & Nguyen 1990, examples 3 to 5).
 *
 * Nonlinear: GSL odeiv2 (evolve/control/step under a driver) on the
 * kernel's state y[2 nq] (link angles and rates, doc/model.md section 2), with
 * the tow-point input u(t) and the frame motion of an excitation
 * (towstab/excitation.h). Explicit adaptive Runge-Kutta (rk8pd, rkf45) or
 * implicit methods for stiff scenes (GSL's rk4imp, bsimp, msbdf, and
 * esdirk: SUNDIALS ARKODE's L-stable ESDIRK 5(4), the one for elastic
 * cables; bdf: SUNDIALS CVODE's BDF of order 1-2 with the same Newton
 * matrix) whose Jacobian df/dy comes from the linearizer
 * (towstab/linearize.h): GSL's the dense A, O(nlinks^2) per Jacobian and
 * O(nlinks^3) per LU; esdirk's and bdf's the sparse model, O(nlinks) per
 * Jacobian, factorisation and solve. A run starts from ts_sim_start_state of its
 * initial state (an impulsive start absorbed by the top links). Steps never
 * straddle an output time or a breakpoint of the excitation. After every
 * accepted step, links with |cos theta2| below the re-chart threshold are
 * moved to a chart centred on their direction (ts_kernel_rechart) and the
 * integrator restarts from the rewritten state: positions and velocities
 * are continuous, the numbers in y are not.
 *
 * Linear: z = y - y0 and v = u - u0 about the linearization point of a
 * ts_linear; either exact discretisation (matrix exponential of the
 * Van Loan block matrix, the input interpolated by a cubic on each step,
 * lib/expm.c) or the same GSL integrators on z' = A z + B v. Node positions
 * are reconstructed as the equilibrium positions plus the first-order
 * displacement of the angles plus the tow displacement (kinematics
 * "linear"), or by the kernel's exact geometry at y0 + z (kinematics
 * "nonlinear", the way DYNTOCABS-style codes draw a linear run).
 *
 * Outputs are sampled at t_i = i dt (i = 0..N-1) and t_end into a
 * ts_history. Units SI throughout; angles in rad.
 */
#ifndef TOWSTAB_SIMULATE_H
#define TOWSTAB_SIMULATE_H

#include "towstab/error.h"
#include "towstab/guidance.h"
#include "towstab/excitation.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"
#include "towstab/output.h"
#include "towstab/progress.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_INT_RK8PD = 0,   /* explicit Runge-Kutta Prince-Dormand 8(9) */
    TS_INT_RKF45 = 1,   /* explicit Runge-Kutta-Fehlberg 4(5) */
    TS_INT_RK4IMP = 2,  /* implicit Gauss 4th order (Jacobian) */
    TS_INT_BSIMP = 3,   /* implicit Bulirsch-Stoer, Bader-Deuflhard (Jacobian) */
    TS_INT_MSBDF = 4,   /* variable-order BDF, stiff (Jacobian) */
    TS_INT_ESDIRK = 5,  /* L-stable ESDIRK 5(4), SUNDIALS ARKODE, stiff and
                           lightly damped: elastic cables (Jacobian) */
    TS_INT_BDF = 6      /* BDF of order 1-2 (A- and L-stable), SUNDIALS
                           CVODE, with esdirk's Newton matrix: elastic
                           cables at loose tolerances (Jacobian) */
} ts_integrator;

typedef enum {
    TS_LINSIM_EXPM = 0, /* exact discretisation with cubic input hold
                           (the dense model) */
    TS_LINSIM_ODE = 1,  /* the integrator of ts_sim_opts.integrator (the
                           dense model) */
    TS_LINSIM_SPARSE = 2 /* esdirk (bdf when ts_sim_opts.integrator is
                           bdf) on the sparse model: O(nlinks) per step;
                           what any method runs without the dense model */
} ts_linsim_method;

typedef enum {
    TS_KIN_LINEAR = 0,    /* positions r0 + dr(z) + tow displacement */
    TS_KIN_NONLINEAR = 1  /* positions of the state y0 + z (kernel) */
} ts_kinematics;

/* Smallest relative tolerance accepted: below ~100 eps the error
 * estimates are rounding noise and steps can shrink without end. */
#define TS_SIM_RTOL_MIN 1e-14

typedef struct ts_sim_opts {
    ts_integrator integrator; /* default TS_INT_RK8PD */
    double t_end;       /* s, > 0; default 10 */
    double dt_sample;   /* s, in (0, t_end]; default 0.1 */
    double rel_tol;     /* relative local error per step, >=
                           TS_SIM_RTOL_MIN; default 1e-6 */
    double abs_tol;     /* absolute, rad and rad/s; default 1e-9 */
    double h_init;      /* first step, s (at least h_min); default 1e-3 */
    double h_min;       /* s; an accepted step below it (other than one cut
                           short to land on an output time) fails the run;
                           default 0: only GSL's machine-precision limit */
    long max_steps;     /* accepted steps per run; 0 (default): no limit */
    double rechart;     /* |cos theta2| re-chart threshold, default
                           TS_CHART_RECHART */
    ts_linsim_method linear_method;  /* default TS_LINSIM_EXPM */
    ts_kinematics kinematics;        /* default TS_KIN_LINEAR */
    int jacobian_threads; /* threads of the Jacobian (ts_linearize_opts);
                           default 1 */
    ts_progress_fn progress; /* called after every accepted step (linear
                           expm: every output sample) with the simulated
                           time of t_end, "nonlinear" or "linear"; nonzero
                           stops the run with TS_ECANCEL at that state
                           (towstab/progress.h). Default NULL: none */
    void *progress_data;  /* passed to progress */
} ts_sim_opts;

TS_API void ts_sim_opts_default(ts_sim_opts *o);

/* Check the options (TS_EINVAL naming the field: t_end <= 0, a sample
 * interval <= 0 or longer than the run, tolerances <= 0, ...). */
TS_API int ts_sim_opts_check(const ts_sim_opts *o, ts_err *err);

/* Number of output samples: N + 1 with N = ceil(t_end / dt_sample), the
 * last one at t_end (within 1e-9 of a multiple, t_end itself). */
TS_API int ts_sim_nsamples(const ts_sim_opts *o);

/* Time of sample i (0 <= i < ts_sim_nsamples). */
TS_API double ts_sim_sample_time(const ts_sim_opts *o, int i);

TS_API const char *ts_integrator_name(ts_integrator m);
/* Parse "rk8pd", "rkf45", "rk4imp", "bsimp", "msbdf", "esdirk", "bdf": 0
 * or -1. */
TS_API int ts_integrator_parse(const char *name, ts_integrator *m);

/* The Newton matrix of an implicit method: none (an explicit method or
 * a linear run), the dense Jacobian and its LU (GSL's implicit steppers,
 * O(links^2) and O(n^3)), or the sparse model and its KLU factorisation
 * (esdirk and bdf where it covers the system, O(links)). */
typedef enum {
    TS_NEWTON_NONE = 0,
    TS_NEWTON_DENSE,
    TS_NEWTON_SPARSE
} ts_newton_matrix;

/* Work statistics of a run. */
typedef struct ts_sim_stats {
    long steps;         /* accepted steps (linear expm: discrete steps) */
    long rejected;      /* rejected trial steps */
    long evaluations;   /* f evaluations by the integrator (linear: input
                           evaluations and matrix-vector products) */
    long jacobians;     /* Jacobian evaluations (implicit methods) */
    ts_newton_matrix newton; /* which Newton matrix they made */
    long recharts;      /* links moved to a new chart */
    long restarts;      /* integrator restarts after re-charting */
    double t_reached;   /* s: the time the run got to */
    double h_last;      /* s: last step size */
    double wall_s;      /* wall-clock seconds of the run */
} ts_sim_stats;

/* Sampled results. */
typedef struct ts_history {
    int nnodes, nlinks;
    int capacity;        /* samples allocated (doubled as a run fills
                            them: ts_sim_record) */
    int nsamples;        /* samples filled */
    double *t;           /* [capacity] s */
    double *positions;   /* [capacity][3 nnodes] m, M frame, node 0 = tow */
    double *tensions;    /* [capacity][nlinks] N (linear runs: from the
                            tension Jacobians or the sparse model, NaN
                            without either) */
    double *tow_force;   /* [capacity][3] N, the force on the tow point
                            (ts_kernel_tow_force; NaN in linear runs) */
    double *energy;      /* [capacity][2] kinetic, potential, J (NaN in
                            linear runs; ts_kernel_kinetic_energy) */
    double *input;       /* [capacity][TS_NINPUT] u(t) */
    double *frame;       /* [capacity][3] the pose of M in the earth frame
                            E: its origin's x, y (m) and its heading (rad)
                            (towstab/track.h, ts_track_history); NaN until
                            filled */
    int noutput;         /* the vehicles' outputs (ts_kernel_noutput), set
                            by the first sample recorded */
    double *outputs;     /* [capacity][noutput] their values (depth, pitch,
                            roll, yaw, loop outputs, deflections; the
                            linear run's v0 + Vy z + Vu du); NULL without
                            vehicles */
    char (*output_name)[2 * TS_NAME_MAX + 16]; /* [noutput]
                            ts_kernel_output_name */
    const char **output_unit; /* [noutput] "m" or "rad" */
    int nreached;        /* waypoints reached (a scene with waypoints,
                            towstab/guidance.h; ts_simulate), in order */
    double reached_t[TS_GUIDANCE_MAX_WAYPOINTS];  /* s: the autopilot
                            update at which each was found within the
                            radius */
    double reached_d[TS_GUIDANCE_MAX_WAYPOINTS];  /* m: the vehicle's
                            distance from it then */
} ts_history;

/* A history of `capacity` samples for system sys, to begin with: the
 * runs that record into it double it when it is full, so a history holds
 * what a run reached, not what it may reach (a run of t_end 1e9 s is
 * stopped long before its 1e7 samples); NULL on failure. */
TS_API ts_history *ts_history_alloc(const ts_system *sys, int capacity,
                                    ts_err *err);
TS_API void ts_history_free(ts_history *h);

/* The value of output channel `out` (towstab/output.h) at sample i of h
 * (0 <= i < h->nsamples), NaN when the run does not give it (the tow
 * force of a linear run; an earth-frame position before h->frame is
 * filled). */
TS_API double ts_history_value(const ts_system *sys, const ts_history *h,
                               const ts_output *out, int i);

/* The depth range of a towed body over a run: its least and greatest
 * depth (z, m; the same in M and E) and their times (the depth excursion
 * of a towfish through a manoeuvre). */
/* Depth ranges reported at most (the reports list the first ones). */
#define TS_MAX_DEPTH_RANGES 32

typedef struct ts_depth_range {
    int body;                 /* index into sys->bodies */
    double min, t_min, max, t_max;   /* m, s (NaN without samples) */
} ts_depth_range;

/* Samples a run's history starts with (ts_history_alloc; it grows as
 * the run fills it). */
#define TS_HISTORY_INITIAL 1024

/* Samples within this (s) of a window's start belong to the window. */
#define TS_HISTORY_TIME_EPS 1e-12

/* The index of h's first sample at t >= t_from (within
 * TS_HISTORY_TIME_EPS); h->nsamples when there is none. */
TS_API int ts_history_first(const ts_history *h, double t_from);

/* The depth ranges over h's samples at t >= t_from (s; -INFINITY: the
 * whole run) of every body but the towing vehicle, in node order, at most
 * `max` into out; returns how many were written. */
TS_API int ts_history_depth_ranges(const ts_system *sys, const ts_history *h,
                                   double t_from, ts_depth_range *out,
                                   int max);

/* --- Nonlinear simulation: set / advance / read, and a driver. --- */

typedef struct ts_sim ts_sim;

/* A simulator on kernel k (which it uses, not owns, and must outlive it)
 * with excitation ex (may be NULL: none; used, not owned). The kernel's
 * frame at this call is the frame of t = 0; it is restored by
 * ts_sim_free. NULL on failure (bad options, no memory). */
TS_API ts_sim *ts_sim_alloc(ts_kernel *k, const ts_excitation *ex,
                            const ts_sim_opts *o, ts_err *err);
TS_API void ts_sim_free(ts_sim *s);

/* Set time t (s) and state y[2 nq] in the kernel's current charts;
 * re-charts links near the singularity (y is copied, then rewritten in
 * the simulator). Resets the integrator. */
TS_API int ts_sim_set_state(ts_sim *s, double t, const double y[],
                            ts_err *err);

/* Integrate to t1 (> current time). Returns TS_OK; TS_EINTEGRATOR when
 * the step size underflows (below h_min or machine precision), the step
 * limit is reached or the state stops being finite; TS_ESINGULAR when the
 * kernel fails fatally; TS_ECANCEL when the progress callback asked to
 * stop. On failure the simulator holds the last accepted state and time
 * (ts_sim_time). */
TS_API int ts_sim_advance(ts_sim *s, double t1, ts_err *err);

TS_API double ts_sim_time(const ts_sim *s);
/* The current state [2 nq] in the kernel's current charts. */
TS_API const double *ts_sim_state(const ts_sim *s);
TS_API void ts_sim_get_stats(const ts_sim *s, ts_sim_stats *st);

/* Evaluate the kernel at the current time and state (so that its
 * accessors hold positions, tensions, energies) and append a sample to h
 * (doubling h when it is full: TS_ENOMEM when that fails, the samples so
 * far kept). */
TS_API int ts_sim_record(ts_sim *s, ts_history *h, ts_err *err);

/* Driver: simulate from y0 (kernel charts; the system before the tow
 * point moves: the run starts from ts_sim_start_state(k, ex, y0)) over
 * [0, o->t_end], recording every output sample (h needs ts_sim_nsamples(o)
 * samples). y_end[2 nq]
 * (may be NULL) receives the final state in the kernel's charts, which
 * may have changed. On failure the history holds the samples reached and
 * *st the statistics so far. */
TS_API int ts_simulate(ts_kernel *k, const ts_excitation *ex,
                       const double y0[], const ts_sim_opts *o,
                       ts_history *h, ts_sim_stats *st, double y_end[],
                       ts_err *err);

/* Check the signals of ex on vehicles' inputs against kernel k: each
 * names one of its inputs (ts_kernel_input_name) with an amplitude of its
 * kind (m or rad). TS_OK, TS_EINVAL listing the valid names, TS_EUNIT.
 * ts_sim_alloc and ts_simulate_linear check the same. */
TS_API int ts_sim_check_inputs(const ts_kernel *k, const ts_excitation *ex,
                               ts_err *err);

/* --- Linear simulation. --- */

/* Check that the linear model can follow the manoeuvres of ex (a step or
 * ramp of the frame's speed or turn rate, the frame inputs of
 * towstab/linearize.h): refused (TS_EINVAL) with a towing vehicle, whose
 * own steady motion is the frame, and a turn-rate change in a horizontal
 * current, which turns the current in the frame by the heading change
 * (no state of the linear model). TS_OK without manoeuvres. */
TS_API int ts_sim_check_linear_manoeuvre(const ts_kernel *k,
                                         const ts_excitation *ex,
                                         ts_err *err);

/* Simulate z' = A z + B (u(t) - u0) from z(0) = z0 (NULL: 0) over
 * [0, o->t_end], recording positions into h, and the link tensions
 * T0 + dT/dy z + dT/du (u - u0) when lin has the tension Jacobians
 * (ts_linearize_opts.tensions; else NaN) or runs on the sparse model;
 * energies and the tow force are NaN.
 * The dense A and B with linear_method expm or ode; the sparse model
 * (lin->desc) with linear_method sparse, or with any method when lin has
 * no dense A: esdirk (bdf when o->integrator is bdf) at o's tolerances,
 * A's action and the Newton solves by lib/shift.h, the tensions and the
 * vehicles' outputs from the same model; a manoeuvre (the frame inputs)
 * needs the dense model.
 * `k` must be the kernel lin was computed with, in the same charts (its
 * frame too, the base of the manoeuvres); it is used for the nonlinear
 * kinematics only. A manoeuvre drives the frame inputs with the frame's
 * change from k's frame (ts_excitation_frame): the state z stays the
 * deviation from the initial equilibrium in the mean frame so moved, as
 * the nonlinear run's (doc/simulate.md); refused as
 * ts_sim_check_linear_manoeuvre says. Cost per output interval: expm
 * O(n^2) per step plus one O((n + 4 m)^3) exponential per distinct step
 * size (m inputs driven); ode: O(n^2) per evaluation; sparse: O(nlinks)
 * per evaluation and per Newton solve, and O(nlinks m) memory. */
TS_API int ts_simulate_linear(ts_kernel *k, const ts_linear *lin,
                              const ts_excitation *ex, const double z0[],
                              const ts_sim_opts *o, ts_history *h,
                              ts_sim_stats *st, ts_err *err);

/* The name of the method a linear run used, from its statistics: "expm",
 * or the integrator's name (esdirk or bdf on the sparse model,
 * st->newton TS_NEWTON_SPARSE). */
TS_API const char *ts_linear_method_name(const ts_sim_opts *o,
                                         const ts_sim_stats *st);

/* --- Initial states. --- */

/* The state at t = 0+ of a run started from y0[2 nq] (the system before
 * the tow point moves) under ex: y0 itself unless a tow signal starts
 * impulsively (a sine or crank with ramp 0: ts_excitation_start_jump),
 * which sets the tow point moving at once. Its coordinates being relative
 * to the tow point, y0 would then move every node with it; instead the
 * jump in velocity is absorbed where the cable can: a link leaving a node
 * that jumps takes the jump whole when elastic (its lower node keeps its
 * velocity: a rate of stretch, the start of an axial wave), and only the
 * part normal to itself when rigid (the part along it moves its lower
 * node, and so on down). A displacement the signal has at t = 0 (a crank
 * at phase 0) is where the tow point rested before: the cable starts
 * there with it. Writes y[2 nq] (may alias y0) in k's charts. ts_simulate
 * starts from this state; doc/simulate.md. Returns TS_OK or TS_ESINGULAR
 * (the kernel refuses y0). */
TS_API int ts_sim_start_state(ts_kernel *k, const ts_excitation *ex,
                              const double y0[], double y[], ts_err *err);

/* A released shape: every link along the unit direction of angles
 * (theta1, theta2) (rad; n = (-c1 c2, -s2, s1 c2): 0, 0 is straight aft,
 * horizontal), at rest relative to M. Writes y[2 nq] in k's charts,
 * re-charting links as needed. TS_EINVAL for non-finite angles. */
TS_API int ts_sim_released_state(ts_kernel *k, double theta1, double theta2,
                                 double y[], ts_err *err);

/* A shape from node positions pos[3 nnodes] (m; node 0 the tow point,
 * which only fixes the origin), at rest: link directions are the
 * normalised node differences. Refuses (TS_EINVAL, naming the link) a
 * link whose length differs from the system's by more than `rtol`
 * relative. Writes y[2 nq] in k's charts (re-charting as needed). */
TS_API int ts_sim_shape_state(ts_kernel *k, const double pos[], double rtol,
                              double y[], ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
