/* extremes.c: extremes of output channels over a history and the links
 * whose tension leaves a cable's range (towstab/extremes.h).
 *
 * One pass over the samples per channel (those of the window, t >=
 * t_from, when one is given): the largest and smallest finite sample,
 * the trapezoidal integral for the mean, and the parabola through each
 * extreme's neighbours for its sampling error. The links are
 * scanned sample by sample (rows of h->tensions are contiguous), keeping
 * per link the first and last time out of range.
 */
#include "towstab/extremes.h"

#include <math.h>
#include <stdlib.h>

/* The sampling error of the extreme at sample i of h (sign +1 for a
 * maximum, -1 for a minimum), over the samples first..n-1: how far the
 * parabola through three samples around it (shifted inward at the
 * window's ends) goes beyond it, when its vertex lies within a sample of
 * i and inside the window; else 0 (the extreme is the window's own end
 * value). */
static double peak_error(const ts_system *sys, const ts_history *h,
                         const ts_output *out, int first, int i,
                         double sign)
{
    int n = h->nsamples;
    if (n - first < 3)
        return 0.0;
    int c = i < first + 1 ? first + 1 : i > n - 2 ? n - 2 : i;
    double t0 = h->t[c - 1], t1 = h->t[c], t2 = h->t[c + 1];
    double a = ts_history_value(sys, h, out, c - 1);
    double b = ts_history_value(sys, h, out, c);
    double d = ts_history_value(sys, h, out, c + 1);
    double x = ts_history_value(sys, h, out, i);
    /* Newton's form p(t) = a + d1 (t - t0) + q (t - t0)(t - t1). */
    double d1 = (b - a) / (t1 - t0), d2 = (d - b) / (t2 - t1);
    double q = (d2 - d1) / (t2 - t0);
    if (!(sign * q < 0) || !isfinite(q + x))
        return 0.0;
    double ts = 0.5 * (t0 + t1) - d1 / (2 * q);
    double lo = h->t[i > first ? i - 1 : first];
    double hi = h->t[i < n - 1 ? i + 1 : n - 1];
    if (!(ts >= lo && ts <= hi))
        return 0.0;
    double p = a + d1 * (ts - t0) + q * (ts - t0) * (ts - t1);
    return fmax(0.0, sign * (p - x));
}

void ts_extremes_compute(const ts_system *sys, const ts_history *h,
                         const ts_output *out, double reference,
                         ts_extremes *e)
{
    ts_extremes_window(sys, h, out, reference, -INFINITY, e);
}

void ts_extremes_window(const ts_system *sys, const ts_history *h,
                        const ts_output *out, double reference,
                        double t_from, ts_extremes *e)
{
    e->max = e->t_max = e->min = e->t_min = NAN;
    e->max_error = e->min_error = e->mean = e->amplification = NAN;
    e->reference = reference;
    e->samples = 0;
    int first = ts_history_first(h, t_from);
    e->t_from = first < h->nsamples ? h->t[first] : NAN;
    int imax = -1, imin = -1, prev = -1;
    double integral = 0, span = 0, xmax = 0, xmin = 0, xprev = 0;
    for (int i = first; i < h->nsamples; i++) {
        double x = ts_history_value(sys, h, out, i);
        if (!isfinite(x))
            continue;
        e->samples++;
        if (imax < 0 || x > xmax) {
            imax = i;
            xmax = x;
        }
        if (imin < 0 || x < xmin) {
            imin = i;
            xmin = x;
        }
        if (prev >= 0) {
            double dt = h->t[i] - h->t[prev];
            integral += 0.5 * (x + xprev) * dt;
            span += dt;
        }
        prev = i;
        xprev = x;
    }
    if (imax < 0)
        return;
    e->max = xmax;
    e->t_max = h->t[imax];
    e->min = xmin;
    e->t_min = h->t[imin];
    e->max_error = peak_error(sys, h, out, first, imax, 1.0);
    e->min_error = peak_error(sys, h, out, first, imin, -1.0);
    e->mean = span > 0 ? integral / span : xmax;
    if (isfinite(reference) && reference != 0)
        e->amplification = e->max / reference;
}

/* Order of events: first time, then link. */
static int by_time(const void *pa, const void *pb)
{
    const ts_slack *a = pa, *b = pb;
    if (a->t_first != b->t_first)
        return a->t_first < b->t_first ? -1 : 1;
    return (a->link > b->link) - (a->link < b->link);
}

int ts_slack_find(const ts_system *sys, const ts_history *h,
                  ts_slack **events, int *n, ts_err *err)
{
    *events = NULL;
    *n = 0;
    int nl = h->nlinks, ns = h->nsamples;
    if (nl == 0 || ns == 0)
        return TS_OK;
    double peak = 0;
    for (size_t k = 0; k < (size_t)nl * (size_t)ns; k++)
        if (isfinite(h->tensions[k]))
            peak = fmax(peak, fabs(h->tensions[k]));
    double floor = -TS_SLACK_RTOL * peak;
    ts_slack *ev = calloc((size_t)nl, sizeof *ev);
    if (!ev)
        return ts_fail(err, TS_ENOMEM, "tensions: out of memory for %d "
                       "links", nl);
    for (int l = 0; l < nl; l++) {
        ev[l].link = l;
        ev[l].elastic = sys->links[l].elastic;
        ev[l].min = INFINITY;
    }
    for (int i = 0; i < ns; i++) {
        const double *T = h->tensions + (size_t)nl * (size_t)i;
        for (int l = 0; l < nl; l++) {
            int out = ev[l].elastic ? T[l] <= 0 : T[l] < floor;
            if (!out)
                continue;
            if (ev[l].samples++ == 0)
                ev[l].t_first = h->t[i];
            ev[l].t_last = h->t[i];
            ev[l].min = fmin(ev[l].min, T[l]);
        }
    }
    int m = 0;
    for (int l = 0; l < nl; l++)
        if (ev[l].samples > 0)
            ev[m++] = ev[l];
    if (m == 0) {
        free(ev);
        return TS_OK;
    }
    qsort(ev, (size_t)m, sizeof *ev, by_time);
    *events = ev;
    *n = m;
    return TS_OK;
}
