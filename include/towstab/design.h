/* towstab/design.h: design by optimisation (doc/design.md).
 *
 * A design study changes 1 to TS_DESIGN_MAX_FREE scene values by path
 * (towstab/param.h: cables.main.length, bodies.depressor.mass, tow.speed),
 * each within its bounds, to meet a goal, subject to inequality
 * constraints on the result of one analysis (equilibrium or modes):
 *
 *   target    a value equal to a number ("fish.z = 300 m"): the misfit
 *             ((v - t) / s)^2 is minimised, s = |t| (1 when t = 0); the
 *             target is reached when |v - t| <= target_rtol s;
 *   minimise, maximise   a value (v / s, s its magnitude at the start);
 *   none      constraints alone: a point that meets them.
 *
 * Constraints: value <= bound or value >= bound, as (v - b) / s <= 0
 * with s = |b| (1 when b = 0). A value is named as ts_design_value()
 * finds it.
 *
 * The optimiser is NLopt's (nlopt.h): COBYLA (derivative-free, bounds and
 * nonlinear inequality constraints; the default), BOBYQA (derivative-
 * free, bounds only) or SLSQP (a gradient method, bounds and inequality
 * constraints; the gradients by central differences of the analysis,
 * TS_DESIGN_GRAD_STEP), on the free values scaled to [0, 1] over their
 * bounds. Every evaluation is the analysis at those values (ts_setup_set),
 * without the discretisation estimate, its equilibrium started from the
 * previous evaluation's (continuation). The optimum is then run again as
 * the single command would at those settings: from a cold start, with the
 * discretisation estimate, so that the values reported are the single
 * run's, with their error estimates and trust verdict.
 *
 * Nothing here prints or writes files; ts_design_json gives the study as
 * JSON (with the final run's result, towstab/report_result.h).
 */
#ifndef TOWSTAB_DESIGN_H
#define TOWSTAB_DESIGN_H

#include <jansson.h>

#include "towstab/analysis.h"
#include "towstab/error.h"
#include "towstab/param.h"
#include "towstab/progress.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_DESIGN_MAX_FREE 8
#define TS_DESIGN_MAX_CONSTRAINTS 8
/* Evaluations by default, at most. */
#define TS_DESIGN_MAX_EVALS 200
/* A target is reached within this fraction of it, by default. */
#define TS_DESIGN_TARGET_RTOL 1e-6
/* The optimiser stops when a step changes the scaled free values by less
 * than this, by default. */
#define TS_DESIGN_XTOL 1e-7

typedef enum ts_design_goal_kind {
    TS_DESIGN_NONE = 0,
    TS_DESIGN_TARGET = 1,
    TS_DESIGN_MINIMISE = 2,
    TS_DESIGN_MAXIMISE = 3
} ts_design_goal_kind;

typedef enum ts_design_method {
    TS_DESIGN_COBYLA = 0,
    TS_DESIGN_BOBYQA = 1,
    TS_DESIGN_SLSQP = 2
} ts_design_method;

/* SLSQP's gradients: central differences of this step in the scaled free
 * values (a fraction of each one's range; one-sided at a bound). */
#define TS_DESIGN_GRAD_STEP 1e-4

/* A free value. */
typedef struct ts_design_var {
    char path[TS_PARAM_PATH_MAX]; /* canonical after ts_design_run */
    double lower, upper;          /* SI bounds, lower < upper */
    double start;                 /* SI; NAN: the system's value (clipped
                                     into the bounds) */
} ts_design_var;

typedef struct ts_design_goal {
    ts_design_goal_kind kind;
    char name[TS_VALUE_NAME_MAX]; /* the value (not for NONE) */
    double target;                /* SI (TARGET) */
} ts_design_goal;

typedef struct ts_design_constraint {
    char name[TS_VALUE_NAME_MAX];
    int upper;                    /* 1: value <= bound; 0: value >= bound */
    double bound;                 /* SI */
} ts_design_constraint;

typedef struct ts_design_spec {
    ts_request rq;                /* equilibrium or modes; its settings at
                                     every evaluation */
    int nfree;
    ts_design_var free[TS_DESIGN_MAX_FREE];
    ts_design_goal goal;
    int nconstraints;
    ts_design_constraint constraints[TS_DESIGN_MAX_CONSTRAINTS];
    ts_design_method method;
    int max_evals;                /* 0: TS_DESIGN_MAX_EVALS */
    double target_rtol;           /* 0: TS_DESIGN_TARGET_RTOL */
    double xtol;                  /* 0: TS_DESIGN_XTOL */
    double fin_step;              /* m: fin_use adds, on every limited
                                     control surface and ballast tank,
                                     |the jump of its
                                     command| when the depth loops' set
                                     points step by this: sum over depth
                                     loops of kp gain fin_step; 0: the
                                     steady deflections alone */
    ts_progress_fn progress;      /* after each evaluation ("design",
                                     evaluations of max_evals); nonzero
                                     stops the study */
    void *progress_data;
} ts_design_spec;

/* One evaluation of the history. */
typedef struct ts_design_eval {
    double x[TS_DESIGN_MAX_FREE]; /* SI */
    int status;                   /* of the analysis */
    double goal;                  /* the goal's value (NAN: failed) */
    double violation;             /* largest scaled constraint violation,
                                     0 when met */
    long evaluations;             /* kernel evaluations */
    double wall_s;
} ts_design_eval;

typedef struct ts_design {
    ts_design_spec spec;          /* as run (paths canonical, defaults
                                     filled) */
    char unit[TS_DESIGN_MAX_FREE][TS_PARAM_UNIT_MAX]; /* of the free */
    int neval;
    ts_design_eval *history;      /* [neval] */
    int gradients;                /* SLSQP: gradients computed (2 nfree
                                     runs each, in neval) */
    int nlopt_code;               /* NLopt's result */
    const char *nlopt_reason;     /* its meaning, static */
    double x[TS_DESIGN_MAX_FREE]; /* the optimum, SI */
    int at_bound[TS_DESIGN_MAX_FREE]; /* -1 lower, 1 upper, 0 inside */
    ts_result *result;            /* the single run at the optimum (with
                                     the discretisation estimate), NULL
                                     when none ran */
    int status;                   /* that run's status */
    ts_value goal_value;          /* the goal's value there, estimates */
    double goal_misfit;           /* TARGET: |v - t| */
    int reached;                  /* TARGET: within target_rtol; else 1 */
    ts_value constraint_value[TS_DESIGN_MAX_CONSTRAINTS];
    int constraint_met[TS_DESIGN_MAX_CONSTRAINTS]; /* value within the
                                     bound (to its target_rtol) */
    int feasible;                 /* every constraint met */
    int success;                  /* reached and feasible, trust aside */
    long evaluations;             /* kernel evaluations of the study and
                                     of the final run */
    double wall_s;                /* of the study and the final run */
    double final_wall_s;          /* of the final run */
} ts_design;

/* The value `name` of result r into *out: a key value of the result
 * (ts_result_value), an equilibrium value ("fish.z", "top_tension"), or
 *   layback        horizontal distance from the tow point to the last
 *                  body (or free end), m;
 *   max_real       the stability margin (ts_result_margin), 1/s;
 *   min_damping    the smallest damping ratio of the oscillatory modes
 *                  computed that are resolved (not grid-scale, and within
 *                  the accuracy when the estimate ran), 1;
 *   control_damping  the same over the modes that move a vehicle most
 *                  (the largest node displacement of the shape is at a
 *                  vehicle: the modes its controllers act on), 1;
 *   fin_use        the largest |steady deflection| / limit over the
 *                  vehicles' control surfaces with a limit, and |fill -
 *                  capacity / 2| / (capacity / 2) over their ballast
 *                  tanks (1: at a limit, a tank empty or full), 1 (a
 *                  study adds the jump of a depth set-point step,
 *                  fin_step);
 *   a free value's path (its value in the run's system).
 * Returns 1, or 0 when r has no such value (or it is NaN). */
TS_API int ts_design_value(const ts_result *r, const char *name,
                           ts_value *out);

/* The SI unit of value `name` of a run of rq on sys (as ts_design_value
 * finds it) into unit[size]: TS_OK, or TS_EINVAL naming `what` ("goal",
 * "constraint") and listing the values a run has. */
TS_API int ts_design_unit(const ts_system *sys, const ts_request *rq,
                          const char *what, const char *name, char *unit,
                          size_t size, ts_err *err);

/* Check a spec against sys without running: the analysis, the paths and
 * bounds, the goal and constraint names (against a run's value names).
 * TS_OK or TS_EINVAL naming what is wrong. */
TS_API int ts_design_check(const ts_system *sys, const ts_design_spec *sp,
                           ts_err *err);

/* Run the study. *out receives it (free with ts_design_free), also when
 * the optimum misses its target or constraints (d->success 0: not an
 * error); NULL only after a check's failure or out of memory. Returns
 * TS_OK, TS_EINVAL (ts_design_check), TS_ECANCEL (progress stopped it:
 * the best point so far is run and reported), or the final run's code. */
TS_API int ts_design_run(const ts_system *sys, const ts_design_spec *sp,
                         ts_design **out, ts_err *err);

TS_API void ts_design_free(ts_design *d);

/* Names. */
TS_API const char *ts_design_goal_name(ts_design_goal_kind k);
TS_API const char *ts_design_method_name(ts_design_method m);

/* The study as JSON: settings, optimum, goal and constraints with their
 * estimates, history, the final run's result (towstab/report_result.h).
 * NULL when out of memory. */
TS_API json_t *ts_design_json(const ts_design *d);

#ifdef __cplusplus
}
#endif
#endif
