/* towstab/converge.h: how accurate is a result and what does it cost?
 * Resolution sweeps with error estimates, observed orders of convergence
 * and a recommendation (doc/converge.md).
 *
 * An analysis is rerun at several settings of one resolution parameter:
 * links per cable, a solver's or integrator's tolerance, or the
 * linearization step. Each run (a row) gives named values (body
 * positions, top tension, mode frequencies, ...), its wall time, its
 * kernel evaluations and its health (towstab/health.h). With
 * h the resolution measure of a setting (1/links, the tolerance, the
 * step), a value is assumed to behave as f(h) = f* + C h^p for small h.
 * From three consecutive rows the observed order p solves
 *   (f1 - f2) / (f2 - f3) = (h1^p - h2^p) / (h2^p - h3^p)
 * (GSL Brent root; any ratios h1/h2, h2/h3), and Richardson extrapolation
 * of the two finest rows at that order gives a reference f*; every row's
 * error is then estimated as |f - f*| plus the reference's own
 * uncertainty. When the finest two orders disagree, or the differences
 * are not monotone, the finest row is the reference; when they are at the
 * level of the runs' own noise (solver tolerance, rounding), the value has
 * converged. The recommendation is the cheapest setting whose estimated
 * relative error, and that of every finer setting of the same series, is
 * below the target for every value, among trustworthy runs; when none
 * qualifies the observed order predicts the setting that would, and the
 * wall time it would take.
 *
 * Several series (e.g. one per integrator: a work-precision comparison)
 * share one reference: that of the series whose reference is the most
 * accurate. Nothing here prints; report_converge.h writes JSON and CSV.
 *
 * Analyses plug in through ts_conv_analysis (a run callback with its value
 * names). The pipelines of towstab/analysis.h provide it for the
 * equilibrium, the modes and a time-domain simulation under a periodic
 * excitation (ts_analysis_sweep); others provide the same callback.
 */
#ifndef TOWSTAB_CONVERGE_H
#define TOWSTAB_CONVERGE_H

#include "towstab/error.h"
#include "towstab/health.h"
#include "towstab/progress.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_CONV_NAME_MAX 96
#define TS_CONV_UNIT_MAX 16
#define TS_CONV_MSG_MAX 512
/* Settings in one sweep. */
#define TS_CONV_MAX_SETTINGS 64

/* The parameter swept. */
typedef enum {
    TS_CONV_LINKS = 0,     /* links per cable N (every cable); h = 1/N */
    TS_CONV_TOLERANCE = 1, /* relative tolerance of the solver or
                              integrator, in (0, 1); h = tolerance */
    TS_CONV_STEP = 2       /* relative step of the linearization, in
                              (0, 0.1]; h = step */
} ts_conv_param;

/* What a value's reference is. */
typedef enum {
    TS_CONV_REF_NONE = 0,       /* fewer than two usable rows */
    TS_CONV_REF_RICHARDSON = 1, /* extrapolated at the observed order */
    TS_CONV_REF_FINEST = 2,     /* the finest row; the last differences
                                   shrink but give no steady order */
    TS_CONV_REF_CONVERGED = 3,  /* the finest rows agree within their
                                   noise */
    TS_CONV_REF_DIVERGING = 4   /* the last differences do not shrink:
                                   no error estimate to trust */
} ts_conv_ref;

/* A value an analysis reports, and what the sweep found about it. */
typedef struct ts_conv_value {
    char name[TS_CONV_NAME_MAX];  /* "sphere.z", "top_tension", ... */
    char unit[TS_CONV_UNIT_MAX];  /* "m", "N", "Hz", "1" */
    double scale;      /* > 0: relative errors are errors / scale (e.g. the
                          cable length for positions, 1 for a damping
                          ratio); 0: relative to |reference| */
    /* Filled by ts_convergence_estimate (reference series): */
    double order;      /* observed order at the finest triple; NaN */
    double reference;  /* f*, in unit */
    double reference_error; /* its own uncertainty, >= 0 */
    ts_conv_ref ref_kind;
    double rel_scale;  /* the scale relative errors use, > 0 */
} ts_conv_value;

/* One run. */
/* A run shorter than this (s) is repeated, up to TS_CONV_TIMING_REPEATS
 * runs in all or until the repeats take this long, and its wall time is
 * the median (ts_convergence_sweep): sub-millisecond timer and scheduler
 * noise would otherwise zig-zag the work-precision curve. */
#define TS_CONV_TIMING_MIN 0.05
#define TS_CONV_TIMING_REPEATS 15

typedef struct ts_conv_row {
    int series;         /* index into ts_convergence.series */
    double setting;     /* links (whole), tolerance or step */
    double h;           /* resolution measure, > 0 */
    int status;         /* TS_OK, or the run's failure code */
    char message[TS_CONV_MSG_MAX]; /* the failure's message, "" if none */
    double wall_s;      /* s: one run's; for a run shorter than
                           TS_CONV_TIMING_MIN, the median of timed_runs
                           repeats (timer noise) */
    int timed_runs;     /* the runs timed, >= 1 */
    long evaluations;   /* kernel (or right-hand side) evaluations */
    ts_trust trust;     /* health of the run's result */
    double *values;     /* [nvalues]; NaN where the run gave none */
    double *noise;      /* [nvalues] uncertainty that does not shrink with
                           h (solver residual, rounding), >= 0 */
    /* Filled by ts_convergence_estimate: */
    double *errors;     /* [nvalues] estimated absolute error; NaN */
    double *rel_errors; /* [nvalues] errors / rel_scale */
    double *order;      /* [nvalues] observed order of the triple ending at
                           this row in its series; NaN */
    double max_rel_error; /* over the values; NaN if any is NaN */
    int meets_target;   /* max_rel_error <= target, status OK, trustworthy */
} ts_conv_row;

/* A series of rows (one per integrator, say). */
typedef struct ts_conv_series {
    char name[TS_CONV_NAME_MAX]; /* "" for a sweep of one series */
    int recommended;    /* its cheapest qualifying row, -1 */
    double *order;      /* [nvalues] observed order at its finest triple */
    double *reference;  /* [nvalues] its own reference */
    double *reference_error; /* [nvalues] */
    ts_conv_ref *ref_kind;   /* [nvalues] */
} ts_conv_series;

typedef struct ts_convergence {
    char analysis[TS_CONV_NAME_MAX]; /* "equilibrium", "modes", ... */
    ts_conv_param param;
    int nvalues;
    ts_conv_value *values;   /* [nvalues] */
    int nseries;
    ts_conv_series *series;  /* [nseries] */
    int nrows, capacity;
    ts_conv_row *rows;       /* [capacity], in the order added */
    /* Filled by ts_convergence_estimate: */
    int estimated;
    double target;           /* relative error wanted */
    int reference_series;    /* series whose reference all rows use */
    int recommended;         /* cheapest qualifying row overall, -1 */
    double predicted_setting;/* when none qualifies: the setting the
                                observed order says reaches the target in
                                the reference series; NaN if unknown */
    double predicted_wall_s; /* its wall time, extrapolated from the two
                                finest rows (wall ~ h^-q); NaN */
    int limiting_value;      /* value with the largest finest-row error of
                                the reference series, -1 */
    /* Set by the caller (ts_convergence_alloc leaves them NULL): called by
     * ts_convergence_sweep before each run with the runs done of the
     * sweep's ("sweep", unit "runs"); nonzero stops the sweep
     * (towstab/progress.h). */
    ts_progress_fn progress;
    void *progress_data;
} ts_convergence;

/* A table for `nvalues` values (names, units and scales copied from
 * values[]; the estimate fields are ignored) and up to `capacity` rows.
 * NULL on failure (TS_EINVAL: nvalues < 1, capacity < 1, an empty or
 * duplicate name; TS_ENOMEM). */
TS_API ts_convergence *ts_convergence_alloc(const char *analysis,
                                            ts_conv_param param, int nvalues,
                                            const ts_conv_value values[],
                                            int capacity, ts_err *err);
TS_API void ts_convergence_free(ts_convergence *c);

/* Add a series; returns its index (>= 0) or a negative code. */
TS_API int ts_convergence_add_series(ts_convergence *c, const char *name,
                                     ts_err *err);

/* Add a row to series `series`: the run at `setting` ended with `status`
 * (message: its error text or NULL) after wall_s seconds and
 * `evaluations` evaluations; values[nvalues] and noise[nvalues] (NULL:
 * zero) as the run gave them, trust its health (NULL: trustworthy; a
 * failed run is made untrustworthy with its message as the reason).
 * TS_EINVAL for a setting outside the parameter's range or already in the
 * series, TS_ENOMEM when the table is full or memory runs out. */
TS_API int ts_convergence_add_row(ts_convergence *c, int series,
                                  double setting, int status,
                                  const char *message, double wall_s,
                                  long evaluations, const ts_trust *trust,
                                  const double values[],
                                  const double noise[], ts_err *err);

/* An analysis to sweep. run() computes the values at one setting of
 * parameter p: values[nvalues] (NaN where there is none) and noise[nvalues]
 * (>= 0, the part of their error that h does not control), adds its
 * kernel evaluations to *evaluations and its health to *trust (both set by
 * the caller: 0 and ts_trust_init). It returns TS_OK or a failure code
 * with the message in err; a failed run becomes a row with that status
 * and the sweep goes on, except after TS_ENOMEM. */
typedef struct ts_conv_analysis {
    char name[TS_CONV_NAME_MAX];
    int nvalues;
    ts_conv_value *values;        /* [nvalues] names, units, scales; owned */
    int (*run)(void *ctx, ts_conv_param p, double setting, double values[],
               double noise[], long *evaluations, ts_trust *trust,
               ts_err *err);
    void *ctx;                    /* owned when free_ctx is set */
    void (*free_ctx)(void *ctx);
} ts_conv_analysis;

/* Release what an analysis owns (values, ctx); the struct itself is the
 * caller's. Safe on a zeroed struct. */
TS_API void ts_conv_analysis_free(ts_conv_analysis *an);

/* Run `an` at settings[n] (any order; each checked first with
 * ts_conv_check_settings) into series `series` of c, timing each run
 * (CLOCK_MONOTONIC). c must have been allocated with an's values. Returns
 * TS_OK when every run was recorded (failed runs included), TS_EINVAL
 * (bad settings, mismatched values) or TS_ENOMEM; TS_ECANCEL when
 * c->progress asked to stop before a run, or a run returned TS_ECANCEL
 * (its own progress callback asked: that run is recorded with the
 * status), the rows so far kept. */
TS_API int ts_convergence_sweep(ts_convergence *c, int series,
                                const ts_conv_analysis *an,
                                const double settings[], int n, ts_err *err);

/* Estimate errors, orders, references and the recommendation for a
 * relative error `target` (> 0). May be called again with another target.
 * Returns TS_OK or TS_EINVAL (target not > 0, no rows). */
TS_API int ts_convergence_estimate(ts_convergence *c, double target,
                                   ts_err *err);

/* Row indices grouped by series (in series order), each series coarse to
 * fine (h descending), into idx[c->nrows]. */
TS_API void ts_convergence_sorted_rows(const ts_convergence *c, int idx[]);

/* Check settings[n] for parameter p: 1 <= n <= TS_CONV_MAX_SETTINGS,
 * finite, distinct; links whole numbers in [1, TS_MAX_LINKS];
 * tolerances in (0, 1); steps in (0, 0.1]. `what` names the option in
 * the message ("--links"). */
TS_API int ts_conv_check_settings(ts_conv_param p, const double settings[],
                                  int n, const char *what, ts_err *err);

/* Resolution measure h of a setting (1/links, tolerance, step). */
TS_API double ts_conv_resolution(ts_conv_param p, double setting);

/* Observed order p of three values at resolutions h[0] > h[1] > h[2] > 0:
 * the root of (f0 - f1)/(f1 - f2) = (h0^p - h1^p)/(h1^p - h2^p) in
 * [TS_CONV_ORDER_MIN, TS_CONV_ORDER_MAX]. Returns TS_OK, or TS_EDOMAIN
 * (*p = NaN) when the differences are zero, change sign or do not shrink
 * fast enough for an order in that range; TS_EINVAL for unordered h. */
#define TS_CONV_ORDER_MIN 0.05
#define TS_CONV_ORDER_MAX 20.0
TS_API int ts_conv_observed_order(const double h[3], const double f[3],
                                  double *p);

/* Richardson extrapolation of f1 at h1 and f2 at h2 < h1 at order p:
 * f2 + (f2 - f1) / ((h1/h2)^p - 1). */
TS_API double ts_conv_extrapolate(double h1, double f1, double h2, double f2,
                                  double p);

/* Names: "links", "tolerance", "step"; "richardson", "finest",
 * "converged", "diverging", "none". */
TS_API const char *ts_conv_param_name(ts_conv_param p);
TS_API const char *ts_conv_ref_name(ts_conv_ref k);

/* Modes a modes sweep follows are oscillatory with a damping ratio below
 * this: a pair near critical damping is two real modes about to meet, and
 * its frequency (the square root of a small discriminant) is not a value
 * that converges; such pairs come and go as the resolution changes. */
#define TS_CONV_MODE_DAMPING_MAX 0.95

/* A copy of sys with every cable cut into `links` equal links, built.
 * TS_EINVAL for a cable with link_lengths or links outside
 * [1, TS_MAX_LINKS]. NULL on failure. */
TS_API ts_system *ts_conv_system_with_links(const ts_system *sys, int links,
                                            ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
