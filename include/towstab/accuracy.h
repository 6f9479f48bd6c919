/* towstab/accuracy.h: is a result accurate to the target? The
 * discretisation error of every key value from the same analysis on
 * coarser discretisations (Richardson), the modes that the discretisation
 * does not resolve, and whether a simulation's analysed window has
 * settled and is periodic (doc/accuracy.md).
 *
 * The lumped model of a cable of N links is a discretisation of the
 * continuous cable: a value f computed with N links behaves as
 * f(h) = f* + C h^p + ..., h = 1/N, with p = 2 (the lumped loads are a
 * midpoint/trapezoid quadrature of the distributed ones, doc/model.md
 * section 3) or p = 1 when a cylinder sits at a cable's end (its axis is
 * the direction of the last link, whose chord differs from the cable's
 * end tangent by O(h)). The same analysis on a coarser discretisation
 * (every cable's links halved, rounded up: ratio r = N / N_c) gives the
 * Richardson estimate of the run's own error
 *     E = |f_N - f_Nc| / (r^p - 1);
 * a third level (N/4) gives the observed order, which replaces p when it
 * is smaller, down to half of p (a pre-asymptotic range converges more
 * slowly than the theory says, and a smaller p gives a larger, safe
 * estimate). A system
 * in which some cable has a single link is refined instead (2N links):
 * E = |f_N - f_2N| / (1 - 2^-p).
 *
 * Nothing here runs an analysis: the pipelines (towstab/analysis.h) run
 * the coarser levels and call these functions on what they computed.
 * Nothing prints.
 */
#ifndef TOWSTAB_ACCURACY_H
#define TOWSTAB_ACCURACY_H

#include "towstab/converge.h"
#include "towstab/eigen.h"
#include "towstab/error.h"
#include "towstab/health.h"
#include "towstab/linearize.h"
#include "towstab/response.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The default relative accuracy of a result's key values (the scene key
 * and option `accuracy`). */
#define TS_ACCURACY_DEFAULT 1e-3
/* Observed orders below this fraction of the theoretical order are not
 * used; the fraction of the theory is used instead. A small observed
 * order says the coarser levels are not yet in the asymptotic range; the
 * coarsest of three (a quarter of the links) may be far outside it while
 * the run and the next are near it, and its order would then inflate the
 * estimate many times (doc/accuracy.md, "When it fails"). */
#define TS_ACCURACY_ORDER_FLOOR 0.5
/* A mode whose shape has half-waves of at most this many links along the
 * cable that moves most varies on the scale of the discretisation: it is
 * an artefact of the links, not a mode of the cable. */
#define TS_ACCURACY_GRID_HALF_WAVE 2.0
/* Coarser levels compared, at most (the run itself is level 0). */
#define TS_ACCURACY_LEVELS 3

/* ---- discretisation levels --------------------------------------------- */

/* The theoretical order in 1/links of sys's discretisation: 2, or 1 when a
 * cylinder body ends a cable (see above). Tension extremes of a time
 * history and tension outputs are of order 1 whatever the system (a
 * link's tension is the tension near its midpoint, half a link from the
 * end where the extreme lies), and so is a frequency response whose
 * linear model has a node at the water surface (doc/model.md section 6:
 * its derivatives there are means of one-sided ones that differ by the
 * order of one link's load); the pipelines apply these. */
TS_API double ts_accuracy_order(const ts_system *sys);


/* The node of `other` (another discretisation of the same description)
 * at the place of node `node` of `sys`: the tow point, a body's node, a
 * free end, or a cable node at the same fraction of its cable's length;
 * -1 when `other` has no node there. */
TS_API int ts_accuracy_node_map(const ts_system *sys, const ts_system *other,
                                int node);

/* The largest number of links of any cable of sys. */
TS_API int ts_accuracy_max_links(const ts_system *sys);

/* One value at up to TS_ACCURACY_LEVELS levels. */
typedef struct ts_accuracy_series {
    int nlevels;        /* 1 (nothing to compare), 2 or 3 */
    double f[TS_ACCURACY_LEVELS];   /* f[0] the run's value */
    double ratio[TS_ACCURACY_LEVELS - 1]; /* h_{k+1} / h_k: > 1 coarser,
                                             < 1 finer */
    double noise;       /* solver error of the values, >= 0 (the
                           differences below it are not resolved) */
    double order;       /* theoretical order p */
} ts_accuracy_series;

/* What the estimate found. */
typedef struct ts_accuracy_estimate {
    double error;       /* estimated |f_0 - f*|, in f's unit; NaN when
                           fewer than 2 levels have finite values */
    double order;       /* order used */
    double observed;    /* observed order from 3 levels; NaN */
} ts_accuracy_estimate;

/* The Richardson estimate of a real value (order: the observed one from 3
 * coarser levels when it is finite and below the theoretical order, at
 * least TS_ACCURACY_ORDER_FLOOR of it, and that floor when the
 * differences hardly shrink; the theoretical one otherwise, from the
 * larger difference when the two differ in sign). A difference within
 * the noise counts as the noise. */
TS_API ts_accuracy_estimate ts_accuracy_richardson(const ts_accuracy_series
                                                       *s);

/* The same for a complex value (an eigenvalue, a complex gain) given as
 * re[] and im[] over the levels: the error is |lambda_0 - lambda*|; the
 * observed order comes from the sizes of the two differences when they
 * point within 90 degrees of each other. */
TS_API ts_accuracy_estimate ts_accuracy_richardson_complex(
    const ts_accuracy_series *re, const ts_accuracy_series *im);

/* The factor by which every cable's links must grow for a relative error
 * `rel` (> accuracy) at order p to fall to `accuracy`: (rel / accuracy)^(1
 * / p); 1 when rel <= accuracy; NaN when unknown. */
TS_API double ts_accuracy_links_factor(double rel, double accuracy,
                                       double order);

/* ---- modes ------------------------------------------------------------- */

/* What the discretisation says of one mode. */
typedef struct ts_mode_accuracy {
    int matched[TS_ACCURACY_LEVELS - 1]; /* the mode of each other level
                                           nearest to this one, -1 */
    double error;           /* estimated |lambda - lambda*|, 1/s; NaN */
    double re_error;        /* of Re lambda, 1/s */
    double freq_error_hz;   /* of the frequency, Hz */
    double damping_error;   /* of the damping ratio */
    double order;           /* order used; NaN */
    double half_wave_links; /* links per half-wave of the shape along the
                               cable that moves most (INFINITY: no sign
                               change; NaN without vectors) */
    int grid_scale;         /* half_wave_links <= TS_ACCURACY_GRID_HALF_WAVE */
    int resolved;           /* not grid-scale, and error <= accuracy
                               |lambda| (when estimated) */
} ts_mode_accuracy;

/* Links per half-wave of mode m's shape: along every cable with at least
 * 3 links, the relative displacements of consecutive links (their
 * rotations, and stretch for elastic links) d_k give R^2 = sum |d_{k+1} -
 * d_k|^2 / sum (|d_k|^2 + |d_{k+1}|^2) / 2; a shape varying as
 * cos(pi k / w) along the links has R = 2 sin(pi / (2 w)), so w = pi / (2
 * asin(R / 2)), taken on the cable with the largest motion. INFINITY for a
 * shape that does not vary along the links, NaN without vectors. */
TS_API double ts_accuracy_half_wave(const ts_system *sys,
                                    const ts_linear *lin, const ts_eigen *e,
                                    int m);

/* For every mode of `e` (level 0, system sys0) the nearest mode of each
 * other level (levels[k] for level k + 1, NULL when absent; their
 * ratios in s->ratio, the theoretical order in s->order) and the
 * Richardson estimates; the shape scale of every mode; resolved against
 * `accuracy`. ma[e->nmodes] receives the result. */
TS_API void ts_accuracy_modes(const ts_system *sys0, const ts_linear *lin0,
                              const ts_eigen *e, int nlevels,
                              const ts_eigen *const levels[],
                              const double ratio[], double order,
                              double accuracy, ts_mode_accuracy ma[]);

/* The stability verdict, resolved modes apart from unresolved ones. */
typedef struct ts_stability {
    int estimated;       /* 1: the modes' resolution is known (a coarser
                            level was compared); 0: only the shape test */
    int nresolved, nunresolved;
    int nneutral;        /* modes left out: a towing vehicle's neutral
                            modes by symmetry (ts_mode.neutral) */
    int verdict;         /* of the resolved modes: TS_STABLE, TS_UNSTABLE,
                            TS_MARGINAL; -1 when none is resolved */
    int mode;            /* the resolved mode with the largest real part,
                            -1 */
    double max_real;     /* its real part, 1/s; NaN */
    double solver_error; /* its error bound, 1/s */
    double discretisation_error; /* its re_error, 1/s; NaN */
    int unresolved_verdict; /* of the unresolved modes, -1 when none */
    int unresolved_mode;
    double unresolved_max_real, unresolved_error; /* 1/s: its real part
                            and error bound */
} ts_stability;

/* The verdicts of the resolved and of the unresolved modes of e (ma as
 * ts_accuracy_modes made it). A resolved mode is stable when re +
 * error_bound + re_error < 0 and unstable when re - error_bound -
 * re_error > 0; an unresolved one is judged as computed, with its
 * error_bound only (it is a mode of the discrete model, not of the
 * cable). */
TS_API void ts_accuracy_stability(const ts_eigen *e,
                                  const ts_mode_accuracy ma[],
                                  int estimated, ts_stability *st);

/* ---- simulations --------------------------------------------------------- */

/* A run's analysed window: has the start transient decayed, and is the
 * signal periodic? */
typedef struct ts_window {
    int checked;          /* 1: the checks ran (a periodic excitation, a
                             fit over a window) */
    double period;        /* s, of the excitation */
    double transient;     /* s discarded */
    double t_end;         /* s */
    double slowest_tau;   /* s, the slowest time constant -1 / Re lambda of
                             the linearized system (NaN: not known) */
    double slowest_freq_hz; /* its mode's frequency */
    int modes_complete;   /* 1: every mode was searched */
    double drift;         /* difference of the fits over the last two
                             periods, relative to `scale` (NaN when the
                             run is shorter than two periods) */
    double scale;         /* m: the output's amplitude (at least a
                             thousandth of the excitation's) */
    double remaining;     /* the start transient that may remain at the
                             window's start, relative to scale: drift /
                             (1 - exp(-period / slowest_tau)), what
                             remained two periods before the end, scaled
                             back to the window's start; NaN */
    int settled;          /* transient >= 5 slowest_tau, or remaining <=
                             accuracy; -1 unknown */
    int periodic;         /* drift <= accuracy; -1 unknown */
    double transient_needed; /* s that would do (>= transient) */
    double t_end_needed;     /* s that would do (>= t_end) */
} ts_window;

/* Time constants needed for a start transient to decay. */
#define TS_ACCURACY_SETTLE_TAU 5.0
/* The output's amplitude used as the scale of the drift is at least this
 * fraction of the excitation's (an output that hardly moves). */
#define TS_ACCURACY_SCALE_FLOOR 1e-3

/* The checks on a sampled output x[n] at equal steps t[n] (the whole
 * run, t[0] = 0), under a periodic excitation of `period` s and amplitude
 * `amplitude` (m), analysed over t >= transient, with the slowest time
 * constant `tau` (s, NaN when unknown) of the linear model. The drift is
 * the largest difference between the last period and the one before:
 * sample against sample when a period holds a whole number of samples,
 * else between least-squares fits of a mean and 3 harmonics over each
 * (GSL), compared at 64 phases. Its scale is the output's half range over
 * the last period. Fills w. */
TS_API void ts_accuracy_window(const double t[], const double x[], int n,
                               double period, double amplitude,
                               double transient, double tau,
                               double accuracy, ts_window *w);

#ifdef __cplusplus
}
#endif
#endif
