/* test_extremes.c: extremes of a channel over a history and the links
 * out of a cable's range (towstab/extremes.h), on histories written by
 * hand, so that every number has a closed form.
 *
 *  1. A tension T(t) = 300 + 40 sin(2 pi 0.37 t + 0.4) N sampled every
 *     0.1 s over 0..10 s: the sampled maximum is below the true 340 N by
 *     less than its estimated sampling error plus the parabola's own
 *     error (O(h^4)), and the estimate is within 5 % of the real gap;
 *     likewise the minimum; the mean is the trapezoidal average, within
 *     the trapezoid's error of the closed form (the minimum lies between
 *     the last two samples: the estimate looks inside the run's end);
 *     times are those of the extreme samples; amplification = max /
 *     reference; no reference gives NAN; NAN samples are skipped (the
 *     sample count says so); a monotonic channel's extremes at the run's
 *     ends have no sampling error. Over a window t >= 5 s a start spike
 *     of 1000 N (the whole run's max) is left out, the extremes are
 *     within their sampling errors of the closed form's on [5, 10] s, the
 *     mean is the window's average; a window past the end is empty.
 *  2. Slack: a rigid link at -2.5 N from t = 0.3 to 0.5 s is in
 *     compression (3 samples, lowest -2.5 N); rounding noise of -1e-12 of
 *     the run's largest tension is not; an elastic link at exactly 0 from
 *     t = 0.1 s is slack; the events are ordered by their first time; a
 *     run without any gives none (NULL).
 */
#include "towstab/extremes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/scene.h"
#include "towstab/units.h"

static const char *yaml =
    "name: extremes\n"
    "tow: {speed: 1.5, point: [0, 0, 0]}\n"
    "cables:\n"
    "  - {name: rod, from: tow, length: 8, diameter: 0.01,\n"
    "     mass_per_length: 0.3, links: 2}\n"
    "  - {name: rope, from: tow, length: 5, diameter: 0.01,\n"
    "     mass_per_length: 0.3, links: 1, EA: 1e5}\n";

static double T_of(double t)
{
    return 300.0 + 40.0 * sin(2 * M_PI * 0.37 * t + 0.4);
}

static void test_extremes(const ts_system *sys)
{
    ts_err err = {0};
    int n = 101;
    double dt = 0.1;
    ts_history *h = ts_history_alloc(sys, n, &err);
    if (!CHECK(h != NULL, "history of %d samples (%s)", n, err.msg))
        return;
    size_t nl = (size_t)sys->nlinks;
    for (int i = 0; i < n; i++) {
        h->t[i] = i * dt;
        for (size_t l = 0; l < nl; l++)
            h->tensions[nl * i + l] = l == 0 ? T_of(h->t[i]) : 50.0;
        for (int c = 0; c < 3; c++)
            h->tow_force[3 * i + c] = c == 2 ? T_of(h->t[i]) : 0.0;
    }
    h->nsamples = n;
    ts_output o;
    ts_output_find(sys, "rod.1.tension", TS_OUT_ALL, &o, &err);
    ts_extremes e;
    ts_extremes_compute(sys, h, &o, 287.5, &e);
    double gap_max = 340.0 - e.max, gap_min = e.min - 260.0;
    CHECK(e.samples == n && gap_max >= 0 && gap_min >= 0,
          "%d samples; the sampled max %.9g <= 340 N and min %.9g >= 260 N",
          e.samples, e.max, e.min);
    /* The parabola's own error at the peak: O(w^4 h^4 A), ~1e-3 N here. */
    double w = 2 * M_PI * 0.37, para = 40.0 * pow(w * dt, 4);
    CHECK(fabs(gap_max - e.max_error) <= 0.05 * gap_max + para &&
              gap_max <= e.max_error + para,
          "max: sampling error estimate %.4g N against the real gap %.4g N "
          "(within 5 %% + %.2g N)", e.max_error, gap_max, para);
    /* The true minimum, at 9.963 s, lies between the last two samples. */
    CHECK(fabs(gap_min - e.min_error) <= 0.05 * gap_min + para &&
              gap_min <= e.min_error + para,
          "min at the run's last sample %.4g s: sampling error estimate "
          "%.4g N against the real gap %.4g N", e.t_min, e.min_error,
          gap_min);
    int imax = (int)lround(e.t_max / dt), imin = (int)lround(e.t_min / dt);
    CHECK(T_of(imax * dt) == e.max && T_of(imin * dt) == e.min &&
              T_of((imax + 1) * dt) < e.max && T_of((imax - 1) * dt) < e.max,
          "t_max %.4g s and t_min %.4g s are the extreme samples' times",
          e.t_max, e.t_min);
    /* Mean over 0..10 s: 300 + 40 (cos(0.4) - cos(10 w + 0.4)) / (10 w);
     * the trapezoid errs by ~ (dt^2 / 12) |T''| ~ 0.45 N at most. */
    double exact = 300.0 + 40.0 * (cos(0.4) - cos(10 * w + 0.4)) / (10 * w);
    CHECK_NEAR(e.mean, exact, dt * dt / 12 * 40 * w * w,
               "mean: the trapezoidal time average");
    CHECK_NEAR(e.amplification, e.max / 287.5, 0,
               "amplification = max / reference");
    ts_extremes_compute(sys, h, &o, NAN, &e);
    CHECK(isnan(e.amplification) && isnan(e.reference),
          "without a reference the amplification is NAN");
    /* The tow force channel reads its own array. */
    ts_output f;
    ts_output_find(sys, "tow.force", TS_OUT_ALL, &f, &err);
    ts_extremes ef;
    ts_extremes_compute(sys, h, &f, NAN, &ef);
    CHECK(ef.max == e.max && ef.min == e.min,
          "tow.force: the same extremes from its components");
    /* A window t >= 5 s (the analysed window after a transient): a start
     * spike of 1000 N at 1 s is left out; its extremes are those of T on
     * [5, 10] s (closed form: the sinusoid's crest and trough inside it,
     * or the window's ends), with their sampling errors, and its mean is
     * the window's trapezoidal average. */
    double spike = h->tensions[nl * 10];
    h->tensions[nl * 10] = 1000.0;
    ts_extremes_compute(sys, h, &o, 287.5, &e);
    ts_extremes ew;
    ts_extremes_window(sys, h, &o, 287.5, 5.0, &ew);
    double wmax = -INFINITY, wmin = INFINITY;
    for (int j = 0; j <= 50000; j++) {
        double x = T_of(5.0 + 5.0 * j / 50000);
        wmax = fmax(wmax, x);
        wmin = fmin(wmin, x);
    }
    double wmean = 300.0 + 40.0 * (cos(5 * w + 0.4) - cos(10 * w + 0.4)) /
                               (5 * w);
    CHECK(e.max == 1000.0 && e.t_max == 1.0 && e.t_from == 0.0,
          "the whole run's max is the start spike (%g N at %g s)", e.max,
          e.t_max);
    CHECK(ew.samples == 51 && ew.t_from == 5.0 && ew.t_max >= 5.0 &&
              ew.t_min >= 5.0 && ew.max <= wmax && ew.min >= wmin &&
              wmax - ew.max <= ew.max_error + para &&
              ew.min - wmin <= ew.min_error + para,
          "window t >= %g s (%d samples): max %.9g N at %g s, min %.9g N at "
          "%g s; true %.9g and %.9g N, within the sampling errors %.3g, "
          "%.3g N", ew.t_from, ew.samples, ew.max, ew.t_max, ew.min,
          ew.t_min, wmax, wmin, ew.max_error, ew.min_error);
    CHECK_NEAR(ew.mean, wmean, dt * dt / 12 * 40 * w * w,
               "window: the mean is the window's trapezoidal average");
    CHECK_NEAR(ew.amplification, ew.max / 287.5, 0,
               "window: amplification = the window's max / reference");
    ts_extremes_window(sys, h, &o, 287.5, 20.0, &ew);
    CHECK(ew.samples == 0 && isnan(ew.max) && isnan(ew.t_from),
          "a window after the run's end has no samples");
    h->tensions[nl * 10] = spike;
    /* NAN samples are skipped. */
    h->tensions[nl * imax] = NAN;
    ts_extremes_compute(sys, h, &o, NAN, &e);
    CHECK(e.samples == n - 1 && e.max < T_of(imax * dt),
          "a NAN sample is skipped: %d samples, max %.9g", e.samples, e.max);
    /* A rising channel peaks at the run's end: no sampling error. */
    for (int i = 0; i < n; i++)
        h->tensions[nl * i] = 10.0 + i * i;
    ts_extremes_compute(sys, h, &o, 10.0, &e);
    CHECK(e.max == 10.0 + (n - 1) * (n - 1) && e.max_error == 0 &&
              e.min_error == 0 && e.t_min == 0,
          "extremes at the ends carry no sampling error (max %g at %g s)",
          e.max, e.t_max);
    ts_history_free(h);
}

static void test_slack(const ts_system *sys)
{
    ts_err err = {0};
    int n = 12;
    ts_history *h = ts_history_alloc(sys, n, &err);
    if (!CHECK(h != NULL, "history (%s)", err.msg))
        return;
    size_t nl = (size_t)sys->nlinks;
    /* rod.1 (link 0) pulls; rod.2 (link 1) dips into compression and
     * shows rounding noise; rope.1 (link 2, elastic) goes slack. */
    for (int i = 0; i < n; i++) {
        double t = 0.1 * i;
        h->t[i] = t;
        double *T = h->tensions + nl * i;
        T[0] = 1000.0;
        T[1] = i >= 3 && i <= 5 ? -2.5 + 0.5 * (i - 3) : 20.0;
        if (i == 8)
            T[1] = -1e-12 * 1000.0;
        T[2] = i >= 1 && i <= 2 ? 0.0 : 30.0;
    }
    h->nsamples = n;
    ts_slack *ev = NULL;
    int m = -1;
    int rc = ts_slack_find(sys, h, &ev, &m, &err);
    CHECK(rc == TS_OK && m == 2, "two links out of range (%d; %s)", m,
          err.msg);
    if (m == 2) {
        CHECK(ev[0].link == 2 && ev[0].elastic && ev[0].samples == 2 &&
                  ev[0].t_first == h->t[1] && ev[0].t_last == h->t[2] &&
                  ev[0].min == 0,
              "first: the elastic link slack from t = %g s, %d samples",
              ev[0].t_first, ev[0].samples);
        CHECK(ev[1].link == 1 && !ev[1].elastic && ev[1].samples == 3 &&
                  ev[1].t_first == h->t[3] && ev[1].t_last == h->t[5] &&
                  ev[1].min == -2.5,
              "then: the rigid link in compression from t = %g to %g s, "
              "lowest %g N (not the -1e-9 N of rounding at t = 0.8 s)",
              ev[1].t_first, ev[1].t_last, ev[1].min);
    }
    free(ev);
    for (int i = 0; i < n; i++)
        for (size_t l = 0; l < nl; l++)
            h->tensions[nl * i + l] = 10.0;
    rc = ts_slack_find(sys, h, &ev, &m, &err);
    CHECK(rc == TS_OK && m == 0 && ev == NULL, "a taut run: none");
    ts_history_free(h);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *s = tscene_parse(u, yaml);
    if (s) {
        test_extremes(s->system);
        test_slack(s->system);
    }
    ts_scene_free(s);
    ts_units_free(u);
    return tc_done();
}
