/* towstab/analysis.h: one library pipeline per analysis (doc/architecture.md,
 * "Pipelines").
 *
 * An analysis is run from a system (as a scene describes it) plus a
 * request: the settings every analysis shares (ts_setup: speed, turn rate,
 * links, the equilibrium's method and tolerance) and those of its kind.
 * ts_analysis_run() copies the system with the settings applied, runs the
 * whole chain (equilibrium -> linearization -> eigen analysis or frequency
 * response; equilibrium or released shape -> time integration, linear
 * model, comparison; or a resolution sweep of any of these), judges the
 * result once (towstab/health.h) and returns one ts_result: what was
 * computed, its verdict, its key values with their error estimates, the
 * run time and kernel evaluations, and, when it failed, why. The command
 * line, `towstab run`, the convergence sweeps and a binding all call the
 * same pipeline, so their defaults cannot drift apart. Nothing here
 * prints; towstab/report.h serialises a result.
 *
 * Requests and results are plain structs (fixed-size text, counted
 * arrays) so that other languages can read them (e.g. Python's ctypes).
 * Units are SI throughout.
 */
#ifndef TOWSTAB_ANALYSIS_H
#define TOWSTAB_ANALYSIS_H

#include "towstab/compare.h"
#include "towstab/converge.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/excitation.h"
#include "towstab/extremes.h"
#include "towstab/health.h"
#include "towstab/linearize.h"
#include "towstab/progress.h"
#include "towstab/response.h"
#include "towstab/simulate.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The analyses, in the order of towstab's commands. */
typedef enum {
    TS_ANALYSIS_EQUILIBRIUM = 0,
    TS_ANALYSIS_MODES = 1,
    TS_ANALYSIS_RESPONSE = 2,
    TS_ANALYSIS_SIMULATE = 3,
    TS_ANALYSIS_CONVERGE = 4
} ts_analysis_kind;
#define TS_ANALYSIS_COUNT 5

/* "equilibrium", "modes", "response", "simulate", "converge". */
TS_API const char *ts_analysis_name(ts_analysis_kind kind);
/* The kind named `name`, or -1. */
TS_API int ts_analysis_find(const char *name);

/* ---- requests ---------------------------------------------------------- */

/* Text fields of a request. */
#define TS_REQUEST_NAME_MAX 160
#define TS_REQUEST_PATH_MAX 1024

/* What every analysis shares. */
typedef struct ts_setup {
    double speed;          /* tow speed V, m/s, >= 0; NAN: the system's */
    double turn_rate;      /* Omega, rad/s; NAN: the system's */
    int links;             /* equal links on every cable, 1..TS_MAX_LINKS;
                              0 (default): the system's */
    ts_equilibrium_opts equilibrium; /* method and tol (its defaults) */
} ts_setup;

/* Modes reported by default when the system has at least
 * ts_eigen_opts.arpack_min_states states (ARPACK finds a subset), and
 * around a target frequency. */
#define TS_MODES_LARGE_COUNT 20
#define TS_MODES_NEAR_COUNT 10
/* Lowest oscillatory modes whose frequency and damping ratio are the key
 * values of a modes result (what a convergence study follows). */
#define TS_MODES_FOLLOW 3

typedef struct ts_modes_opts {
    ts_eigen_opts eigen;   /* method, target_hz (its defaults); count is
                              set from `count` below */
    int count;             /* modes wanted; 0 (default): all of them below
                              eigen.arpack_min_states states, else
                              max(TS_MODES_LARGE_COUNT, 2 follow + 10), or
                              TS_MODES_NEAR_COUNT when `near` */
    int near;              /* 1: eigen.target_hz was asked for */
    int follow;            /* key values: the `follow` lowest oscillatory
                              modes with damping below
                              TS_CONV_MODE_DAMPING_MAX (default
                              TS_MODES_FOLLOW, 1..100) */
    ts_linearize_opts linearize; /* its defaults */
} ts_modes_opts;

/* Frequency response defaults. */
#define TS_RESPONSE_FROM_HZ 0.01
#define TS_RESPONSE_TO_HZ 10.0
#define TS_RESPONSE_POINTS 100
#define TS_RESPONSE_MAX_POINTS 1000000
/* Natural frequencies a response result carries, at most. */
#define TS_RESPONSE_NATURAL 12

typedef struct ts_response_opts {
    char input[TS_REQUEST_NAME_MAX];  /* tow.surge, tow.sway, tow.heave
                                         (default) */
    char output[TS_REQUEST_NAME_MAX]; /* required: <node>.x|y|z or
                                         <cable>.<k>.tension */
    double from_hz, to_hz;            /* > 0, from < to; defaults above */
    int points;                       /* 2..TS_RESPONSE_MAX_POINTS */
    int natural;                      /* 1: also the natural frequencies
                                         (modes nearest 0 Hz), e.g. to
                                         mark them on a Bode plot */
} ts_response_opts;

/* Simulation defaults: run length (s), sample interval (s) and the samples
 * per period it guarantees for a periodic excitation. */
#define TS_SIMULATE_T_END 10.0
#define TS_SIMULATE_SAMPLE 0.05
#define TS_SIMULATE_SAMPLES_PER_PERIOD 16
/* Link lengths of a shape file must match the system's to this. */
#define TS_SIMULATE_SHAPE_RTOL 1e-6

typedef enum {
    TS_INITIAL_EQUILIBRIUM = 0, /* the steady state (default) */
    TS_INITIAL_RELEASED = 1,    /* every link straight along theta1,
                                   theta2, at rest */
    TS_INITIAL_SHAPE = 2        /* node positions from a CSV file, at rest */
} ts_initial;

typedef struct ts_simulate_opts {
    ts_sim_opts sim;       /* integrator, t_end (TS_SIMULATE_T_END),
                              tolerances, h_min, max_steps, linear_method,
                              kinematics; dt_sample 0 (default): the
                              smaller of TS_SIMULATE_SAMPLE and 1/16 of a
                              periodic excitation's period, at most t_end */
    double transient;      /* s discarded before comparing or fitting, in
                              [0, t_end); NAN (default): t_end / 2 */
    int compare;           /* 1: the nonlinear and the linear model, and
                              their comparison */
    int linear;            /* 1: the linear model only */
    ts_initial initial;
    double theta1, theta2; /* rad, TS_INITIAL_RELEASED */
    char shape_file[TS_REQUEST_PATH_MAX]; /* TS_INITIAL_SHAPE: CSV
                              node,x_m,y_m,z_m as towstab equilibrium
                              --csv writes it */
    char output[TS_REQUEST_NAME_MAX]; /* the channel compared and fitted
                              (towstab/output.h: a position, tension,
                              strain, length or the tow force; the linear
                              model gives positions and tensions); ""
                              (default): the last sphere's .z, else the
                              last node's */
    char outputs[TS_REQUEST_PATH_MAX]; /* the channels reported (written
                              and printed), comma-separated; "all": the
                              full state (every node, link tension, the
                              tow force, the energies); "" (default): the
                              output (a position: its node's x, y, z) and
                              tow.force */
    ts_excitation *excitation; /* tow-point excitations and manoeuvres
                              (owned by the request; NULL: none) */
    int need_values;       /* 1: the key values (fit over the window) are
                              required: a run whose fit fails fails */
} ts_simulate_opts;

/* Integrators of one convergence study, at most (one series each). */
#define TS_CONVERGE_MAX_SERIES 5
#define TS_CONVERGE_TARGET 1e-3

typedef struct ts_converge_opts {
    ts_analysis_kind analysis;  /* equilibrium (default), modes or
                                   simulate: swept with the request's own
                                   settings for it */
    ts_conv_param param;        /* what is swept */
    double settings[TS_CONV_MAX_SETTINGS];
    int nsettings;              /* 0 (default): links 5..320 (equilibrium),
                                   10..80 (modes), tolerances 1e-3..1e-9
                                   (simulate) */
    double target;              /* relative error wanted, (0, 1); default
                                   TS_CONVERGE_TARGET */
    ts_integrator integrators[TS_CONVERGE_MAX_SERIES];
    int nintegrators;           /* simulate: one series per integrator; 0:
                                   the simulation's own */
} ts_converge_opts;

/* A request: the kind and its settings. Sections other than the kind's
 * are ignored, except that a convergence study of modes or simulate uses
 * those sections. */
typedef struct ts_request {
    ts_analysis_kind kind;
    ts_setup setup;
    ts_modes_opts modes;
    ts_response_opts response;
    ts_simulate_opts simulate;
    ts_converge_opts converge;
    /* Called by the long runs (every integrator step of a simulation,
     * every run of a sweep; towstab/progress.h); nonzero stops the
     * analysis with TS_ECANCEL, keeping what it has. NULL (default):
     * none. A simulation's own sim.progress, when set, wins. */
    ts_progress_fn progress;
    void *progress_data;
} ts_request;

/* Every default (as documented above). Release with ts_request_clear. */
TS_API void ts_request_init(ts_request *rq, ts_analysis_kind kind);
/* Free what the request owns (the excitation) and reset it to the
 * defaults of its kind. */
TS_API void ts_request_clear(ts_request *rq);

/* The default sweep of a convergence study of `analysis` as text
 * ("5,10,20,40,80,160,320"), and its parameter. */
TS_API const char *ts_converge_default_sweep(ts_analysis_kind analysis,
                                             ts_conv_param *param);

/* ---- results ----------------------------------------------------------- */

/* An error estimate of a reported number, in its unit: from the
 * discretisation (links, linearization step, sample interval) and from
 * the solver (residual, tolerance, rounding). NAN: not estimated. */
typedef struct ts_estimate {
    double discretisation;
    double solver;
} ts_estimate;

#define TS_VALUE_NAME_MAX 96
#define TS_VALUE_UNIT_MAX 16

/* A key value of a result: what a study follows across resolutions. */
typedef struct ts_value {
    char name[TS_VALUE_NAME_MAX]; /* "sphere.z", "top_tension",
                                     "mode1.freq_hz", ... */
    char unit[TS_VALUE_UNIT_MAX]; /* "m", "N", "Hz", "1", "deg" */
    double value;                 /* NAN when the run gave none */
    double scale;                 /* > 0: relative errors are errors /
                                     scale; 0: relative to |value| */
    ts_estimate error;
} ts_value;

/* What an analysis computed. The parts it does not compute, or did not
 * reach, are NULL (counts 0). */
typedef struct ts_result {
    ts_analysis_kind kind;
    int status;                 /* TS_OK, or the code of the failure */
    char error[TS_ERR_MSG_MAX]; /* its message, "" when none */
    int completed;              /* ran to its end (status TS_OK) */
    ts_trust trust;             /* the verdict on the whole result; a
                                   failed run is never trustworthy */
    double wall_s;              /* s, the whole analysis */
    long evaluations;           /* kernel evaluations (and marches) */
    int nvalues;
    ts_value *values;           /* [nvalues] key values */

    ts_system *sys;             /* the system analysed: the request's
                                   settings applied (owned) */
    /* The equilibrium (every kind but converge; simulate from it). */
    int eq_attempted;           /* the solver ran (its summary exists) */
    ts_equilibrium *eq;
    double eq_wall_s;
    ts_trust eq_trust;          /* the equilibrium's own verdict (part of
                                   `trust`, which names it) */
    /* The linearization (modes, response, simulate --linear/--compare). */
    ts_linear *lin;
    double lin_wall_s;
    /* modes */
    ts_eigen *eigen;
    ts_mode_health *mode_health; /* [eigen->nmodes] */
    ts_trust modes_trust;       /* the modes' own verdict (part of
                                   `trust`) */
    double eigen_wall_s;
    /* response */
    ts_response *response;
    int nnatural;
    double natural_hz[TS_RESPONSE_NATURAL]; /* lowest natural frequencies,
                                               Hz */
    /* simulate */
    const ts_excitation *excitation; /* the request's (not owned: the
                                        request must outlive the result) */
    ts_sim_opts sim;            /* the options run, defaults resolved
                                   (dt_sample) */
    double transient;           /* s, resolved */
    ts_output output;           /* the node coordinate compared, fitted */
    char initial[256];          /* how the run started, in words */
    ts_history *nonlinear, *linear;
    ts_sim_stats nonlinear_stats, linear_stats;
    int compared;
    ts_compare compare;
    /* The channels reported (rq->simulate.outputs resolved): noutputs
     * names; all_outputs 1 when the full state was asked for. */
    int noutputs;
    ts_output *outputs;
    int all_outputs;
    /* Forces of the nonlinear run (towstab/extremes.h), also of a run
     * that stopped early (its samples so far): the size of the force on
     * the tow point, every link's tension, the output's extremes (NAN
     * fields when the run gives it none), the links in compression or
     * slack. The references are the initial equilibrium's values (NAN
     * when the run did not start from it). */
    ts_extremes tow_force;
    ts_extremes *tensions;      /* [sys->nlinks], NULL without a
                                   nonlinear run */
    int peak_link;              /* the link of the largest tension, -1 */
    int low_link;               /* the link of the smallest, -1 */
    ts_extremes output_extremes;
    int nslack;
    ts_slack *slack;            /* [nslack] ordered by first time */
    /* converge */
    ts_convergence *convergence;
} ts_result;

/* Check everything that can be checked without running (settings against
 * the system, names of inputs and outputs, excitations against the run,
 * the initial state's file): TS_OK, or a code with a message that names
 * the option by its scene key ("t_end: ...", "output: ..."). */
TS_API int ts_analysis_check(const ts_system *sys, const ts_request *rq,
                             ts_err *err);

/* Run the analysis of `rq` on a copy of `sys`. *out receives the result
 * (caller frees with ts_result_free), also after a failure, with what was
 * computed so far; NULL only when memory ran out. Returns the result's
 * status: TS_OK, a code from ts_analysis_check (nothing ran), the failure
 * of a solver (result->error holds the message, also copied to err), or
 * TS_ECANCEL when rq->progress asked to stop (a simulation keeps its
 * history so far, a study its runs so far, estimated). */
TS_API int ts_analysis_run(const ts_system *sys, const ts_request *rq,
                           ts_result **out, ts_err *err);

TS_API void ts_result_free(ts_result *r);

/* The key value called `name`, or NULL. */
TS_API const ts_value *ts_result_value(const ts_result *r, const char *name);

/* An analysis of a convergence study (towstab/converge.h) that runs the
 * pipeline of rq->converge.analysis with rq's settings at each setting of
 * the sweep (links: setup.links; tolerance: the equilibrium's tol, or the
 * integrator's rel_tol with abs_tol scaled alike; step: the
 * linearization's rel_step), in series `series` (simulate: that
 * integrator, 0 for the request's own). Its values are the pipeline's key
 * values; their noise the solver error estimates (plus, in a links sweep
 * of a simulation, 10 rel_tol of each value's scale; in a step sweep, 64
 * eps of each mode value). The request must outlive it. Returns TS_OK or
 * a code (nothing runs). */
TS_API int ts_analysis_sweep(const ts_system *sys, const ts_request *rq,
                             int series, ts_conv_analysis *an, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
