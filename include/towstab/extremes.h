/* towstab/extremes.h: what breaks cables, from a time history: the
 * largest, smallest and mean value of a force (or any output channel)
 * with its dynamic amplification over the static value, and the links
 * whose tension leaves the range a cable can carry (doc/simulate.md,
 * "Tensions").
 *
 * Extremes are taken over the samples of the history; the largest value
 * between two samples can exceed the largest sample. The parabola
 * through the extreme sample and its two neighbours (the three nearest
 * inside the run at its ends) estimates by how much (the sampling error,
 * a discretisation error): how far its vertex goes beyond the sample
 * when the vertex lies within a sample of it and inside the run (for
 * equal spacing and samples a, b, c around an interior extreme b,
 * (a - c)^2 / (8 |a - 2 b + c|)); zero when the extreme is the run's own
 * end value. The estimate errs by O(h^4) of the channel's fourth
 * derivative. The mean is the trapezoidal time average over the run.
 * A window (ts_extremes_window: the samples at t >= t_from, the analysed
 * window of a run after its start transient) is treated as the run: its
 * first sample is an end.
 *
 * A rigid link carries compression as a rod would; a cable cannot, so a
 * rigid link whose tension falls below -TS_SLACK_RTOL of the run's
 * largest link tension is outside the model (the elastic model lets the
 * cable go slack). An elastic link is slack when its tension is zero
 * (the kernel's elastic tension is never compressive): its next pull is
 * a snap load. Cost: O(nsamples) per channel, O(nsamples nlinks) for the
 * links.
 */
#ifndef TOWSTAB_EXTREMES_H
#define TOWSTAB_EXTREMES_H

#include "towstab/error.h"
#include "towstab/output.h"
#include "towstab/simulate.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Negative tension below this fraction of the largest tension of a run
 * is compression (rounding noise of a tension near zero is not). */
#define TS_SLACK_RTOL 1e-9

/* Extremes of one channel over a run, in its unit (N for a force). */
typedef struct ts_extremes {
    double max, t_max;   /* the largest sample and its time (s) */
    double min, t_min;   /* the smallest and its time */
    double max_error;    /* the sampling error of max (above) */
    double min_error;    /* that of min */
    double mean;         /* trapezoidal time average */
    double reference;    /* the static value (the initial equilibrium's);
                            NAN: none */
    double amplification;/* max / reference: the dynamic amplification;
                            NAN without a reference */
    int samples;         /* finite samples used (0: every field NAN but
                            reference) */
    double t_from;       /* s: the time of the first sample considered
                            (the window's start; the run's first sample
                            without a window); NAN without samples */
} ts_extremes;

/* Extremes of output `out` over the samples of h, with `reference` the
 * static value (NAN: none). Samples where the output is not finite are
 * skipped. */
TS_API void ts_extremes_compute(const ts_system *sys, const ts_history *h,
                                const ts_output *out, double reference,
                                ts_extremes *e);

/* The same over the samples of h at t >= t_from (s; -INFINITY: all). */
TS_API void ts_extremes_window(const ts_system *sys, const ts_history *h,
                               const ts_output *out, double reference,
                               double t_from, ts_extremes *e);

/* A link whose tension left the range of a cable. */
typedef struct ts_slack {
    int link;            /* index into sys->links */
    int elastic;         /* 1: slack (an elastic link at zero tension);
                            0: compression (a rigid link) */
    double t_first;      /* s: the first sample out of range */
    double t_last;       /* s: the last */
    int samples;         /* samples out of range */
    double min;          /* N: the lowest tension */
} ts_slack;

/* The links of h (a run with tensions) whose tension left the range,
 * ordered by t_first (then by link). *events receives a new array (NULL
 * when there is none; caller frees) and *n their number. Returns TS_OK or
 * TS_ENOMEM. */
TS_API int ts_slack_find(const ts_system *sys, const ts_history *h,
                         ts_slack **events, int *n, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
