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

#include "towstab/accuracy.h"
#include "towstab/compare.h"
#include "towstab/control.h"
#include "towstab/converge.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/cost.h"
#include "towstab/excitation.h"
#include "towstab/extremes.h"
#include "towstab/health.h"
#include "towstab/linearize.h"
#include "towstab/param.h"
#include "towstab/progress.h"
#include "towstab/response.h"
#include "towstab/seastate.h"
#include "towstab/simulate.h"
#include "towstab/system.h"
#include "towstab/towing.h"

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

/* Scene values a request sets by path, at most. */
#define TS_SETUP_MAX_SETS 16

/* Characters of a setting's value as given (for messages), with the
 * zero; a longer text is cut. */
#define TS_SETTING_GIVEN_MAX 48

/* One scene value set by path (towstab/param.h). */
typedef struct ts_setting {
    char path[TS_PARAM_PATH_MAX]; /* "cables.main.length", "tow.speed" */
    double value;                 /* SI, in ts_param_unit's unit, or in
                                     `unit` when it is given */
    char unit[TS_PARAM_UNIT_MAX]; /* "" (the key's unit), or the SI unit
                                     value is in when the key's depends on
                                     the system (a loop's key given with a
                                     unit, ts_param_parse): checked against
                                     the loop when the request is */
    char given[TS_SETTING_GIVEN_MAX]; /* the text given with `unit` ("400
                                     m"), for messages; "" otherwise */
} ts_setting;

/* What every analysis shares. */
typedef struct ts_setup {
    double speed;          /* tow speed V, m/s, >= 0; NAN: the system's */
    double turn_rate;      /* Omega, rad/s; NAN: the system's */
    int links;             /* equal links on every cable, 1..TS_MAX_LINKS;
                              0 (default): the system's */
    ts_equilibrium_opts equilibrium; /* method and tol (its defaults); a
                              guess must fit the system analysed (3
                              directions per link) */
    int open_loop;         /* 1: the vehicles' controller loops open in
                              the linear model and the simulation, about
                              the closed-loop trim: each loop's output
                              held at its trim value (the surfaces keep
                              their trim deflections), its integrator out
                              of the state (towstab/control.h); 0
                              (default): closed */
    double accuracy;       /* relative accuracy wanted of the key values,
                              in (0, 1); default TS_ACCURACY_DEFAULT */
    int discretisation_error; /* 1: estimate the discretisation error of
                              the key values from the same analysis at
                              coarser discretisations (towstab/accuracy.h;
                              default for equilibrium, modes and response,
                              which it costs less than the run itself);
                              0: not (default for simulate, where it costs
                              a second simulation) */
    int refine;            /* 1: when the accuracy is missed, rerun with
                              the links the error model says meet it, at
                              most TS_REFINE_ROUNDS times (needs the
                              estimate; equal links on every cable) */
    int nsets;             /* scene values set by path, applied in order
                              to the copy of the system before speed,
                              turn_rate and links (which must not name
                              the same keys); default none */
    ts_setting sets[TS_SETUP_MAX_SETS];
} ts_setup;

/* --refine: reruns at most, each with at most TS_REFINE_GROWTH times the
 * links of the run before. */
#define TS_REFINE_ROUNDS 3
#define TS_REFINE_GROWTH 8

/* Set `path` to `value` (SI) in the setup: replaces an earlier setting of
 * the same key (`speed` and `tow.speed` are one), else appends. TS_OK, or
 * TS_EINVAL for a path of no known form or more than TS_SETUP_MAX_SETS
 * settings. The value is checked when the request is (ts_analysis_check,
 * against the system). */
TS_API int ts_setup_set(ts_setup *s, const char *path, double value,
                        ts_err *err);

/* As ts_setup_set, with the value in the SI unit `unit` that
 * ts_param_parse named without the system (a loop's gain or setpoint
 * given with a unit: the unit of a depth loop or of an angle loop; NULL
 * or "": the key's own) and the text it was given as (for messages; may
 * be NULL). A value whose unit does not fit the loop the path names
 * (a length for a pitch loop's setpoint) is refused when the request is
 * checked (ts_analysis_check, TS_EUNIT naming the path, what the loop
 * measures and the unit expected: ts_param_fits). */
TS_API int ts_setup_set_in(ts_setup *s, const char *path, double value,
                           const char *unit, const char *given,
                           ts_err *err);

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
    int margins;           /* 1 (default): with controller loops closed,
                              each loop's gain and phase margins
                              (ts_loop_margins over TS_MARGINS_FROM_HZ to
                              TS_MARGINS_TO_HZ) */
    int free_vehicle;      /* 1: with a towing vehicle, its modes alone
                              against the coupled ones
                              (ts_free_vehicle_compare); default 0 */
    int oscillatory;       /* 1: list the oscillatory modes only (the
                              `count` lowest when count is given; the
                              table always lists them first); the verdict
                              still covers every mode computed */
} ts_modes_opts;

/* The band and scan of the loop margins of a modes result: log-spaced,
 * TS_MARGINS_PER_DECADE points a decade, each crossing refined. */
#define TS_MARGINS_FROM_HZ 1e-5
#define TS_MARGINS_TO_HZ 100.0
#define TS_MARGINS_PER_DECADE 40

/* Frequency response defaults. */
#define TS_RESPONSE_FROM_HZ 0.01
#define TS_RESPONSE_TO_HZ 10.0
#define TS_RESPONSE_POINTS 100
#define TS_RESPONSE_MAX_POINTS 1000000
/* Natural frequencies a response result carries, at most. */
#define TS_RESPONSE_NATURAL 12

/* The sea state of a response or a simulation (towstab/seastate.h,
 * doc/seastate.md). */
typedef struct ts_sea_opts {
    ts_sea *sea;           /* owned by the request; NULL: no sea */
    ts_rao *rao;           /* owned; NULL: the tow point follows the water
                              surface (heave only) */
    char rao_file[TS_REQUEST_PATH_MAX]; /* the RAO file read, "" without */
    double reference[3];   /* the RAOs' reference point in M, m (default
                              M's origin): the lever arm is the tow point
                              less it */
} ts_sea_opts;

typedef struct ts_response_opts {
    char input[TS_REQUEST_NAME_MAX];  /* tow.surge, tow.sway, tow.heave
                                         (default), or a vehicle's input
                                         (ts_response_input_lookup) */
    char output[TS_REQUEST_NAME_MAX]; /* required: <node>.x|y|z,
                                         <cable>.<k>.tension or a
                                         vehicle's output
                                         (ts_response_output_lookup) */
    double from_hz, to_hz;            /* > 0, from < to; defaults above */
    int points;                       /* 2..TS_RESPONSE_MAX_POINTS */
    int natural;                      /* 1: also the natural frequencies
                                         (modes nearest 0 Hz), e.g. to
                                         mark them on a Bode plot */
    /* With a sea (sea.sea set) the response is the spectral response to
     * the sea (ts_seastate_compute): every tow axis is an input, so
     * input, from, to and points do not apply (giving one is refused). */
    ts_sea_opts sea;
    int frequency_given;              /* input, from, to or points given */
    int intervals;                    /* the spectral grid (default
                                         TS_SEASTATE_INTERVALS) */
    double duration;                  /* s, for the most probable maximum
                                         (default TS_SEASTATE_DURATION) */
} ts_response_opts;

/* Simulation defaults: run length (s), sample interval (s) and the samples
 * per period it guarantees for a periodic excitation. */
#define TS_SIMULATE_T_END 10.0
#define TS_SIMULATE_SAMPLE 0.05
#define TS_SIMULATE_SAMPLES_PER_PERIOD 16
/* A run without a sample interval takes at most this many samples: an
 * excitation so fast that its 16 samples per period would exceed it is
 * refused, so that a default never makes a huge run (give the sample
 * interval to ask for one). */
#define TS_SIMULATE_AUTO_SAMPLES_MAX 1e6
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
    /* With a sea (sea.sea set), one realisation of it
     * (ts_seaway_excitation) drives the tow point besides `excitation`;
     * the output's statistics over t >= transient are the key values, and
     * the spectral prediction of the same band is computed beside them. */
    ts_sea_opts sea;
    long seed;             /* the realisation's seed, >= 0 (default 1) */
    int components;        /* its sinusoids (default TS_SEA_COMPONENTS) */
    double fade_in;        /* s, >= 0; NAN (default): 2 Tp */
    int tracks;            /* 1: compute the earth-frame tracks (the
                              history's frame: the tracks and plan_earth
                              pictures); 0 (default): only when the
                              outputs include an earth-frame position or
                              the full state ("all"), or the scene steers
                              by waypoints */
    int check_window;      /* 1 (default): check that the analysed window
                              has settled and is periodic
                              (ts_accuracy_window); 0: not (the runs of a
                              convergence study) */
    int nwaypoints;        /* > 0: these waypoints replace the points of
                              the scene's `waypoints` entry (its rudders,
                              gain, radius and interval kept; the scene
                              must have one); 0 (default): the scene's */
    double waypoints[TS_GUIDANCE_MAX_WAYPOINTS][2]; /* m, earth frame x, y
                              (towstab/guidance.h) */
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
    double order;                 /* the order in 1/links the
                                     discretisation estimate used; NaN */
} ts_value;

/* How accurate a result is against the continuous cable (towstab/
 * accuracy.h; doc/accuracy.md). */
typedef struct ts_result_accuracy {
    double accuracy;        /* the relative accuracy wanted */
    int estimated;          /* 1: the discretisation error was estimated */
    char not_estimated[TS_TRUST_TEXT]; /* why not, "" when estimated */
    int nlevels;            /* discretisations compared, the run's
                               included (2 or 3) */
    int links[TS_ACCURACY_LEVELS]; /* links of the longest cable at each */
    double ratio[TS_ACCURACY_LEVELS - 1]; /* resolution ratios between
                               consecutive levels (> 1 coarser, < 1 finer) */
    double order;           /* theoretical order in 1/links */
    double wall_s;          /* s, the runs of the other levels: the cost
                               of the estimate */
    long evaluations;       /* their kernel evaluations */
    double max_rel_error;   /* largest relative discretisation error of
                               what the accuracy is judged on (key values,
                               stability margin, response points); NaN */
    char limiting[TS_VALUE_NAME_MAX]; /* the quantity it belongs to */
    double limiting_order;  /* the order its estimate used */
    double limiting_theory; /* its theoretical order, which predicts the
                               links needed */
    int met;                /* 1 met, 0 missed, -1 not known */
    double links_factor;    /* the growth of every cable's links that the
                               error model says meets the accuracy; NaN */
    int links_needed;       /* --links that would meet it (the longest
                               cable's links times links_factor, rounded
                               up); 0 when met or not known */
    int refined_from;       /* --refine: the longest cable's links of the
                               first run; 0 when not refined */
    int refinements;        /* reruns --refine made */
    int eigen_method[TS_ACCURACY_LEVELS]; /* modes: the eigensolver of each
                               level (ts_eig_method), the run's first; 0
                               for the other analyses */
} ts_result_accuracy;

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
    ts_result_accuracy accuracy; /* against the continuum (every kind but
                                   converge) */

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
    int open_loop;              /* the linear model and the simulation
                                   have the vehicles' loops open */
    /* modes */
    ts_eigen *eigen;
    ts_mode_health *mode_health; /* [eigen->nmodes] */
    ts_trust modes_trust;       /* the modes' own verdict (part of
                                   `trust`) */
    ts_mode_accuracy *mode_accuracy; /* [eigen->nmodes]: discretisation
                                   errors, shape scale, resolved */
    ts_stability stability;     /* the verdict of the resolved modes and,
                                   apart, of the unresolved ones, over
                                   every mode computed (also those a
                                   --near or --oscillatory table leaves
                                   out) */
    int nmodes_computed;        /* modes the eigen analysis kept, before
                                   --near or --oscillatory chose those
                                   listed (eigen->nmodes) */
    double eigen_wall_s;
    ts_free_vehicle *free_vehicle; /* modes --free-vehicle, else NULL */
    int nmargins;               /* modes with closed loops: one per loop */
    ts_loop_margin *margins;    /* [nmargins] */
    double margins_wall_s;
    /* response */
    ts_response *response;
    /* response or simulate with a sea: the seaway (its sea and RAOs are
     * the request's) and the spectral result (of simulate: over the
     * realisation's band) */
    int has_sea;
    ts_seaway seaway;
    char rao_file[TS_REQUEST_PATH_MAX]; /* the request's, "" without */
    ts_seastate *seastate;
    ts_sea_realisation realisation; /* simulate: the one run */
    /* simulate with a sea: the realisation with the request's signals
     * (owned; `excitation` points to it) and the records' statistics */
    ts_excitation *sea_excitation;
    int has_records;            /* bit 0: nonlinear, bit 1: linear */
    ts_record_stats record_nonlinear, record_linear;
    int nnatural;
    double natural_hz[TS_RESPONSE_NATURAL]; /* lowest natural frequencies,
                                               Hz */
    double *magnitude_error;    /* [response->npoints] discretisation error
                                   of the magnitude (output unit per m);
                                   NULL unless estimated */
    double *phase_error_deg;    /* [npoints] of the phase, deg */
    double accurate_to_hz;      /* the highest frequency up to which every
                                   point meets the accuracy (relative to
                                   the largest magnitude); NaN */
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
     * fields when the run gives it none), over the analysed window
     * (forces_from); the links in compression or slack over the whole
     * run. The references are the initial equilibrium's values (NAN
     * when the run did not start from it). */
    ts_extremes tow_force;
    ts_extremes *tensions;      /* [sys->nlinks], NULL without a
                                   nonlinear run */
    int peak_link;              /* the link of the largest tension, -1 */
    int low_link;               /* the link of the smallest, -1 */
    ts_extremes output_extremes;
    double forces_from;         /* s: the extremes above (and the bodies'
                                   depth ranges) are over t >= forces_from:
                                   the transient when the run analyses a
                                   window after it (a periodic excitation,
                                   a sea, or a transient given), else 0
                                   (the whole run) */
    int nslack;
    ts_slack *slack;            /* [nslack] ordered by first time */
    ts_window window;           /* the analysed window of the nonlinear run
                                   (the linear run's without one): settled,
                                   periodic (checked: 0 when not) */
    /* converge */
    ts_convergence *convergence;
} ts_result;

/* Check everything that can be checked without running (settings against
 * the system, names of inputs and outputs, excitations against the run,
 * the initial state's file): TS_OK, or a code with a message that names
 * the option by its scene key ("t_end: ...", "output: ..."). */
TS_API int ts_analysis_check(const ts_system *sys, const ts_request *rq,
                             ts_err *err);

/* What the analysis of rq will cost at least (towstab/cost.h):
 * simulations (nonlinear, else the linear model's: nothing), modes (the
 * eigen solve), with the discretisation estimate's runs when asked for;
 * zero for the others. With a towing vehicle a simulation's estimate is
 * at the steady speed and turn rate it solves first (the run's
 * equilibrium), not the scene's starting values. Meant to be said before
 * a long run starts (the command line does above a minute). TS_OK or
 * TS_ENOMEM. */
TS_API int ts_analysis_cost(const ts_system *sys, const ts_request *rq,
                            ts_cost *e, ts_err *err);

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

/* The stability margin of a modes result. */
typedef struct ts_margin {
    double max_real;       /* max Re(lambda), 1/s */
    ts_estimate error;     /* its estimates (discretisation NaN for
                              unresolved modes) */
    double freq_hz;        /* the frequency of that mode (0: real) */
    int verdict;           /* TS_STABLE, TS_UNSTABLE, TS_MARGINAL; -1 */
    int resolved;          /* 1: of the resolved modes */
} ts_margin;

/* The stability margin of r: that of its resolved modes (r->stability;
 * the unresolved ones are modes of the discretisation, not of the cable)
 * or, when none is resolved, that of the modes computed (resolved 0: the
 * result's verdict then says the accuracy is missed). Returns 1, or 0
 * (verdict -1, NaN values) for a result without modes. */
TS_API int ts_result_margin(const ts_result *r, ts_margin *m);

/* The key values a result of rq on sys will carry (names, units, scales;
 * values and estimates NAN), without running: *values[*n] (caller frees;
 * NULL when none, e.g. a response). rq of any kind but converge. TS_OK or
 * a code of ts_analysis_check's (the settings, the simulation's). */
TS_API int ts_analysis_value_names(const ts_system *sys, const ts_request *rq,
                                   ts_value **values, int *n, ts_err *err);

/* The key values of an equilibrium (the points' x, y, z and the top
 * tension, with their estimates) for any result with a system: those of
 * r->eq when it converged, else named with NAN values. *values[*n]
 * (caller frees). TS_OK, TS_EINVAL (no system) or TS_ENOMEM. */
TS_API int ts_result_equilibrium_values(const ts_result *r,
                                        ts_value **values, int *n,
                                        ts_err *err);

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
