/* accuracy.c: discretisation error estimates, resolved modes and the
 * window checks of a simulation (towstab/accuracy.h; doc/accuracy.md).
 *
 * Richardson extrapolation (Richardson 1911; Roache 1998, ch. 5): with
 * f(h) = f* + C h^p, two levels at h0 and h1 = r h0 give the error of the
 * finer one, C h0^p = (f0 - f1) / (1 - r^p) (r > 1: a coarser second
 * level; r < 1: a finer one). Three levels give the observed order
 * (towstab/converge.h, ts_conv_observed_order). Modes are matched between
 * levels by the nearest eigenvalue; their shapes are measured by the
 * ratio of link-to-link change to link motion. The window checks fit the
 * output over each of the last two periods (towstab/compare.h).
 */
#include "towstab/accuracy.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>

/* Two fractions of a cable's length closer than this are one place. */
#define PLACE_RTOL 1e-9
/* Complex differences of three levels whose directions differ by more
 * than 90 degrees give no order (cos of that angle). */
#define ALIGN_MIN_COS 0.0

double ts_accuracy_order(const ts_system *sys)
{
    for (int c = 0; c < sys->ncables; c++) {
        int b = sys->cables[c].to_body;
        if (b >= 0 && sys->bodies[b].type == TS_BODY_CYLINDER)
            return 1.0;
    }
    return 2.0;
}

int ts_accuracy_max_links(const ts_system *sys)
{
    int n = 0;
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].nlinks > n)
            n = sys->cables[c].nlinks;
    return n;
}

/* Fraction of its cable's length at the lower end of link `l`. */
static double place_of(const ts_system *sys, int l)
{
    const ts_cable *c = &sys->cables[sys->links[l].cable];
    int k = sys->links[l].index;
    if (!c->link_fraction)
        return (double)k / c->nlinks;
    double f = 0;
    for (int i = 0; i < k; i++)
        f += c->link_fraction[i];
    return f;
}

int ts_accuracy_node_map(const ts_system *sys, const ts_system *other,
                         int node)
{
    if (node == 0)
        return 0;
    if (node < 0 || node >= sys->nnodes)
        return -1;
    const ts_node *nd = &sys->nodes[node];
    if (nd->body >= 0)
        return ts_system_body_node(other, nd->body);
    int l = nd->link, cable = sys->links[l].cable;
    double f = place_of(sys, l);
    for (int k = 0; k < other->nlinks; k++)
        if (other->links[k].cable == cable &&
            fabs(place_of(other, k) - f) <= PLACE_RTOL)
            return other->links[k].lower;
    return -1;
}

/* ---- Richardson ---------------------------------------------------------- */

/* Resolution of level k relative to level 0 (h_0 = 1). */
static double level_h(const ts_accuracy_series *s, int k)
{
    double h = 1.0;
    for (int i = 0; i < k; i++)
        h *= s->ratio[i];
    return h;
}

/* The smallest order used: TS_ACCURACY_ORDER_FLOOR of the theory. */
static double order_floor(double theory)
{
    return TS_ACCURACY_ORDER_FLOOR * theory;
}

/* The order to use: the observed one when it is below the theory, but
 * not below the floor. */
static double use_order(double theory, double observed)
{
    if (!isfinite(observed))
        return theory;
    if (observed > theory)
        return theory;
    return observed < order_floor(theory) ? order_floor(theory) : observed;
}

/* The error of level 0 from the difference d = f0 - f1 at ratio r and
 * order p. */
static double two_level(double d, double r, double p)
{
    return fabs(d) / fabs(pow(r, p) - 1.0);
}

/* Observed order from the sizes of two differences, d01 (levels 0, 1)
 * and d12 (levels 1, 2), of a series with coarser levels. */
static double observed_order(const ts_accuracy_series *s, double d01,
                             double d12)
{
    if (s->nlevels < 3 || !(s->ratio[0] > 1) || !(s->ratio[1] > 1))
        return NAN;
    /* Differences at the noise carry no order. */
    if (!(fabs(d01) > s->noise) || !(fabs(d12) > s->noise))
        return NAN;
    double h[3] = {level_h(s, 2), level_h(s, 1), 1.0};
    double f[3] = {0.0, fabs(d12), fabs(d12) + fabs(d01)};
    double p;
    return ts_conv_observed_order(h, f, &p) == TS_OK ? p : NAN;
}

/* The estimate from the differences d01 (levels 0, 1) and d12 (levels
 * 1, 2; NaN with two levels) of sizes a01, a12 whose directions agree
 * (`aligned`): at the observed order when there is one; at the smallest
 * order when they agree but do not shrink (a pre-asymptotic range, where
 * the theory's order would understate the error); at the theoretical
 * order from the larger of the two when they disagree (an oscillating
 * convergence). */
static ts_accuracy_estimate three_level(const ts_accuracy_series *s,
                                        double a01, double a12, int aligned,
                                        double noise)
{
    ts_accuracy_estimate e = {NAN, s->order, NAN};
    double d = a01;
    int resolved = s->nlevels >= 3 && isfinite(a12) && a01 > noise &&
                   a12 > noise && s->ratio[0] > 1 && s->ratio[1] > 1;
    if (resolved && aligned) {
        e.observed = observed_order(s, a01, a12);
        /* Without an order in [TS_CONV_ORDER_MIN, TS_CONV_ORDER_MAX] the
         * differences either hardly shrink or shrink faster than any
         * order there. */
        if (isfinite(e.observed))
            e.order = use_order(s->order, e.observed);
        else if (a12 < 1.5 * a01)
            e.order = order_floor(s->order);
    } else if (resolved) {
        d = fmax(a01, a12);
    }
    if (!(d > noise))
        d = noise;
    e.error = two_level(d, s->ratio[0], e.order);
    return e;
}

ts_accuracy_estimate ts_accuracy_richardson(const ts_accuracy_series *s)
{
    ts_accuracy_estimate e = {NAN, s->order, NAN};
    if (s->nlevels < 2 || !isfinite(s->f[0]) || !isfinite(s->f[1]))
        return e;
    double d01 = s->f[0] - s->f[1], d12 = NAN;
    if (s->nlevels >= 3 && isfinite(s->f[2]))
        d12 = s->f[1] - s->f[2];
    return three_level(s, fabs(d01), fabs(d12), d01 * d12 > 0, s->noise);
}

ts_accuracy_estimate ts_accuracy_richardson_complex(
    const ts_accuracy_series *re, const ts_accuracy_series *im)
{
    ts_accuracy_estimate e = {NAN, re->order, NAN};
    int n = re->nlevels < im->nlevels ? re->nlevels : im->nlevels;
    if (n < 2)
        return e;
    for (int k = 0; k < 2; k++)
        if (!isfinite(re->f[k]) || !isfinite(im->f[k]))
            return e;
    double complex l0 = re->f[0] + I * im->f[0];
    double complex l1 = re->f[1] + I * im->f[1];
    double complex d01 = l0 - l1, d12 = NAN;
    ts_accuracy_series s = *re;
    s.nlevels = n;
    s.noise = hypot(re->noise, im->noise);
    if (n >= 3 && isfinite(re->f[2]) && isfinite(im->f[2]))
        d12 = l1 - (re->f[2] + I * im->f[2]);
    double c = creal(d01 * conj(d12));
    return three_level(&s, cabs(d01), cabs(d12),
                       c > ALIGN_MIN_COS * cabs(d01) * cabs(d12), s.noise);
}

double ts_accuracy_links_factor(double rel, double accuracy, double order)
{
    if (!isfinite(rel) || !(accuracy > 0) || !(order > 0))
        return NAN;
    if (rel <= accuracy)
        return 1.0;
    return pow(rel / accuracy, 1.0 / order);
}

/* ---- modes --------------------------------------------------------------- */

double ts_accuracy_half_wave(const ts_system *sys, const ts_linear *lin,
                             const ts_eigen *e, int m)
{
    if (!e->vec_re || !e->vec_im || m < 0 || m >= e->nmodes)
        return NAN;
    int nn = sys->nnodes, nq = lin->nq, nl = sys->nlinks;
    double *dq = malloc((size_t)nq * sizeof *dq);
    double *dr = malloc(6 * (size_t)nn * sizeof *dr);
    double *num = calloc(2 * (size_t)sys->ncables, sizeof *num);
    if (!dq || !dr || !num) {
        free(dq);
        free(dr);
        free(num);
        return NAN;
    }
    double *di = dr + 3 * (size_t)nn, *den = num + sys->ncables;
    memcpy(dq, e->vec_re + (size_t)m * e->nstate, (size_t)nq * sizeof *dq);
    ts_linear_node_displacements(sys, lin, dq, dr);
    memcpy(dq, e->vec_im + (size_t)m * e->nstate, (size_t)nq * sizeof *dq);
    ts_linear_node_displacements(sys, lin, dq, di);
    /* The relative displacement of link l, d_l = dr_lower - dr_upper
     * (complex 3-vector), against that of the next link of its cable. */
    double move_best = -1;
    int best = -1;
    double *move = calloc((size_t)sys->ncables, sizeof *move);
    for (int l = 0; move && l < nl; l++) {
        const ts_link *L = &sys->links[l];
        int a = L->lower, b = L->upper;
        double d2 = 0;
        for (int c = 0; c < 3; c++) {
            double re = dr[3 * a + c] - dr[3 * b + c];
            double im = di[3 * a + c] - di[3 * b + c];
            d2 += re * re + im * im;
        }
        move[L->cable] += d2;
        if (L->next < 0)
            continue;
        const ts_link *M = &sys->links[L->next];
        double s2 = 0, m2 = 0;
        for (int c = 0; c < 3; c++) {
            double re1 = dr[3 * a + c] - dr[3 * b + c];
            double im1 = di[3 * a + c] - di[3 * b + c];
            double re2 = dr[3 * M->lower + c] - dr[3 * M->upper + c];
            double im2 = di[3 * M->lower + c] - di[3 * M->upper + c];
            /* Relative displacements per unit length: links of unequal
             * length turn alike in a smooth shape. */
            re1 /= L->length;
            im1 /= L->length;
            re2 /= M->length;
            im2 /= M->length;
            s2 += (re2 - re1) * (re2 - re1) + (im2 - im1) * (im2 - im1);
            m2 += 0.5 * (re1 * re1 + im1 * im1 + re2 * re2 + im2 * im2);
        }
        num[L->cable] += s2;
        den[L->cable] += m2;
    }
    for (int c = 0; move && c < sys->ncables; c++)
        if (sys->cables[c].nlinks >= 3 && move[c] > move_best) {
            move_best = move[c];
            best = c;
        }
    double w = INFINITY;
    if (!move)
        w = NAN;
    else if (best >= 0 && den[best] > 0) {
        double R = sqrt(num[best] / den[best]);
        w = R >= 2.0 ? 1.0 : (R > 0 ? M_PI / (2.0 * asin(0.5 * R))
                                    : INFINITY);
    }
    free(move);
    free(dq);
    free(dr);
    free(num);
    return w;
}

/* The mode of `other` nearest to lambda (conjugates of real modes are
 * themselves), -1 when it has none. */
static int nearest_mode(const ts_eigen *other, double complex lambda)
{
    int best = -1;
    double dbest = INFINITY;
    for (int k = 0; other && k < other->nmodes; k++) {
        double complex mu = other->modes[k].re + I * other->modes[k].im;
        double d = cabs(lambda - mu);
        if (d < dbest) {
            dbest = d;
            best = k;
        }
    }
    return best;
}

void ts_accuracy_modes(const ts_system *sys0, const ts_linear *lin0,
                       const ts_eigen *e, int nlevels,
                       const ts_eigen *const levels[], const double ratio[],
                       double order, double accuracy, ts_mode_accuracy ma[])
{
    for (int m = 0; m < e->nmodes; m++) {
        ts_mode_accuracy *a = &ma[m];
        const ts_mode *md = &e->modes[m];
        double complex lam = md->re + I * md->im;
        a->matched[0] = a->matched[1] = -1;
        a->error = a->re_error = a->freq_error_hz = a->damping_error = NAN;
        a->order = NAN;
        ts_accuracy_series re = {1, {md->re, NAN, NAN}, {NAN, NAN},
                                 md->error_bound, order};
        ts_accuracy_series im = re;
        im.f[0] = md->im;
        ts_accuracy_series zeta = re;
        zeta.f[0] = md->damping_ratio;
        double mag = cabs(lam);
        zeta.noise = mag > 0 ? md->error_bound / mag : 0.0;
        /* Follow the mode down the levels: each level's nearest to the
         * one above. */
        double complex cur = lam;
        for (int k = 0; k + 1 < nlevels && k < TS_ACCURACY_LEVELS - 1; k++) {
            int j = nearest_mode(levels[k], cur);
            a->matched[k] = j;
            if (j < 0)
                break;
            const ts_mode *mk = &levels[k]->modes[j];
            cur = mk->re + I * mk->im;
            re.f[k + 1] = mk->re;
            im.f[k + 1] = mk->im;
            zeta.f[k + 1] = mk->damping_ratio;
            re.ratio[k] = im.ratio[k] = zeta.ratio[k] = ratio[k];
            re.nlevels = im.nlevels = zeta.nlevels = k + 2;
        }
        if (re.nlevels >= 2) {
            ts_accuracy_estimate el = ts_accuracy_richardson_complex(&re,
                                                                     &im);
            a->error = el.error;
            a->order = el.order;
            /* Parts at the same order as the whole. */
            double p = el.order;
            a->re_error = two_level(re.f[0] - re.f[1], re.ratio[0], p);
            a->freq_error_hz = two_level(im.f[0] - im.f[1], im.ratio[0], p) /
                               (2.0 * M_PI);
            a->damping_error = two_level(zeta.f[0] - zeta.f[1],
                                         zeta.ratio[0], p);
        }
        a->half_wave_links = ts_accuracy_half_wave(sys0, lin0, e, m);
        a->grid_scale = a->half_wave_links <= TS_ACCURACY_GRID_HALF_WAVE;
        a->resolved = !a->grid_scale &&
                      !(isfinite(a->error) && a->error > accuracy * mag) &&
                      !(nlevels >= 2 && !isfinite(a->error));
        if (md->neutral >= 0) {
            /* A neutral mode by symmetry is exact at any number of links
             * (its eigenvalue is the symmetry's). */
            a->error = a->re_error = a->freq_error_hz = 0.0;
            a->damping_error = 0.0;
            a->grid_scale = 0;
            a->resolved = 1;
        }
    }
}

/* Verdict of a real part with an error allowance. */
static int verdict_of(double re, double err)
{
    if (re + err < 0)
        return TS_STABLE;
    if (re - err > 0)
        return TS_UNSTABLE;
    return TS_MARGINAL;
}

void ts_accuracy_stability(const ts_eigen *e, const ts_mode_accuracy ma[],
                           int estimated, ts_stability *st)
{
    memset(st, 0, sizeof *st);
    st->estimated = estimated;
    st->verdict = st->unresolved_verdict = -1;
    st->mode = st->unresolved_mode = -1;
    st->max_real = st->discretisation_error = st->solver_error = NAN;
    st->unresolved_max_real = st->unresolved_error = NAN;
    int rv = TS_STABLE, uv = TS_STABLE;
    for (int m = 0; m < e->nmodes; m++) {
        const ts_mode *md = &e->modes[m];
        if (md->neutral >= 0) {
            /* Neutral by symmetry: outside the verdict (eigen.h). */
            st->nneutral++;
            continue;
        }
        double dis = isfinite(ma[m].re_error) ? ma[m].re_error : 0.0;
        /* An unresolved mode is judged as computed: its discretisation
         * "error" measures how far it is from being a mode of the cable
         * at all. */
        double err = md->error_bound + (ma[m].resolved ? dis : 0.0);
        int v = verdict_of(md->re, err);
        if (ma[m].resolved) {
            st->nresolved++;
            if (st->mode < 0 || md->re > st->max_real) {
                st->mode = m;
                st->max_real = md->re;
                st->solver_error = md->error_bound;
                st->discretisation_error = ma[m].re_error;
            }
            if (v == TS_UNSTABLE || (v == TS_MARGINAL && rv == TS_STABLE))
                rv = v;
        } else {
            st->nunresolved++;
            if (st->unresolved_mode < 0 || md->re > st->unresolved_max_real) {
                st->unresolved_mode = m;
                st->unresolved_max_real = md->re;
                st->unresolved_error = err;
            }
            if (v == TS_UNSTABLE || (v == TS_MARGINAL && uv == TS_STABLE))
                uv = v;
        }
    }
    if (st->nresolved > 0)
        st->verdict = rv;
    if (st->nunresolved > 0)
        st->unresolved_verdict = uv;
}

/* ---- simulations ----------------------------------------------------------- */

/* Harmonics fitted over a period when the samples do not fall on the
 * same phases in both periods. */
#define FIT_HARMONICS 3
/* Phases at which two fitted periods are compared. */
#define FIT_PHASES 64
/* Samples per period: an integer to this relative tolerance means both
 * periods are sampled at the same phases. */
#define PHASE_RTOL 1e-6

/* Least squares fit of c + sum_k (a_k sin k w t + b_k cos k w t), k = 1
 * .. K, over samples [i0, i1) of (t, x) into coef[2K + 1] (GSL). */
static int fit_periodic(const double t[], const double x[], int i0, int i1,
                        double w, int K, double *coef)
{
    int n = i1 - i0, p = 2 * K + 1;
    if (n < p + 1)
        return -1;
    gsl_matrix *X = gsl_matrix_alloc((size_t)n, (size_t)p);
    gsl_matrix *cov = gsl_matrix_alloc((size_t)p, (size_t)p);
    gsl_vector *y = gsl_vector_alloc((size_t)n);
    gsl_vector *c = gsl_vector_alloc((size_t)p);
    gsl_multifit_linear_workspace *ws =
        gsl_multifit_linear_alloc((size_t)n, (size_t)p);
    int rc = -1;
    if (X && cov && y && c && ws) {
        for (int i = 0; i < n; i++) {
            gsl_matrix_set(X, (size_t)i, 0, 1.0);
            for (int k = 1; k <= K; k++) {
                gsl_matrix_set(X, (size_t)i, (size_t)(2 * k - 1),
                               sin(k * w * t[i0 + i]));
                gsl_matrix_set(X, (size_t)i, (size_t)(2 * k),
                               cos(k * w * t[i0 + i]));
            }
            gsl_vector_set(y, (size_t)i, x[i0 + i]);
        }
        double chisq;
        if (gsl_multifit_linear(X, y, c, cov, &chisq, ws) == GSL_SUCCESS) {
            for (int j = 0; j < p; j++)
                coef[j] = gsl_vector_get(c, (size_t)j);
            rc = 0;
        }
    }
    gsl_multifit_linear_free(ws);
    gsl_vector_free(c);
    gsl_vector_free(y);
    gsl_matrix_free(cov);
    gsl_matrix_free(X);
    return rc;
}

/* The largest difference between the last two periods of x, and the
 * output's half range over the last period: sample against sample when
 * a period holds a whole number of samples, else between fits with
 * harmonics. Returns 0, or -1 when the run is too short. */
static int period_drift(const double t[], const double x[], int n,
                        double period, double *drift, double *half_range)
{
    if (n < 3)
        return -1;
    double dt = (t[n - 1] - t[0]) / (n - 1);
    double spp = period / dt;
    int np = (int)lround(spp);
    if (fabs(spp - np) <= PHASE_RTOL * spp && np >= 2 && n >= 2 * np + 1) {
        double d = 0, lo = INFINITY, hi = -INFINITY;
        for (int i = n - np; i < n; i++) {
            d = fmax(d, fabs(x[i] - x[i - np]));
            lo = fmin(lo, x[i]);
            hi = fmax(hi, x[i]);
        }
        *drift = d;
        *half_range = 0.5 * (hi - lo);
        return 0;
    }
    double T = t[n - 1];
    int im = n, i0 = n;
    while (im > 0 && t[im - 1] >= T - period - 1e-9 * period)
        im--;
    while (i0 > 0 && t[i0 - 1] >= T - 2 * period - 1e-9 * period)
        i0--;
    if (T - t[0] < 2 * period * (1 - 1e-9))
        return -1;
    int K = FIT_HARMONICS;
    while (K > 1 && (im - i0 < 2 * K + 2 || n - im < 2 * K + 2))
        K--;
    double c1[2 * FIT_HARMONICS + 1], c2[2 * FIT_HARMONICS + 1];
    double w = 2.0 * M_PI / period;
    if (fit_periodic(t, x, i0, im, w, K, c1) != 0 ||
        fit_periodic(t, x, im, n, w, K, c2) != 0)
        return -1;
    double d = 0, lo = INFINITY, hi = -INFINITY;
    for (int j = 0; j < FIT_PHASES; j++) {
        double th = 2.0 * M_PI * j / FIT_PHASES, f1 = c1[0], f2 = c2[0];
        for (int k = 1; k <= K; k++) {
            f1 += c1[2 * k - 1] * sin(k * th) + c1[2 * k] * cos(k * th);
            f2 += c2[2 * k - 1] * sin(k * th) + c2[2 * k] * cos(k * th);
        }
        d = fmax(d, fabs(f2 - f1));
        lo = fmin(lo, f2);
        hi = fmax(hi, f2);
    }
    *drift = d;
    *half_range = 0.5 * (hi - lo);
    return 0;
}

void ts_accuracy_window(const double t[], const double x[], int n,
                        double period, double amplitude, double transient,
                        double tau, double accuracy, ts_window *w)
{
    memset(w, 0, sizeof *w);
    w->checked = 1;
    w->period = period;
    w->transient = transient;
    w->t_end = n > 0 ? t[n - 1] : 0.0;
    w->slowest_tau = tau;
    w->drift = w->remaining = NAN;
    w->settled = w->periodic = -1;
    w->transient_needed = transient;
    w->t_end_needed = w->t_end;
    double T = w->t_end, d, half;
    int ok = period_drift(t, x, n, period, &d, &half) == 0;
    w->scale = ok ? fmax(half, TS_ACCURACY_SCALE_FLOOR * amplitude) : NAN;
    if (ok && w->scale > 0) {
        w->drift = d / w->scale;
        w->periodic = w->drift <= accuracy;
    }
    /* The transient still present at the window's start: the largest
     * drift, between the starts of the last two periods, is
     * (1 - exp(-P / tau)) of what remained at T - 2P, and that was
     * exp((T - 2P - transient) / tau) times larger at the window's
     * start. */
    int known_tau = isfinite(tau) && tau > 0;
    if (known_tau && isfinite(w->drift)) {
        double per = -expm1(-period / tau);
        double back = (T - 2 * period - transient) / tau;
        w->remaining = back < 700 ? w->drift / per * exp(back) : INFINITY;
    }
    if (known_tau && transient >= TS_ACCURACY_SETTLE_TAU * tau)
        w->settled = 1;
    else if (isfinite(w->remaining))
        w->settled = w->remaining <= accuracy;
    else if (known_tau)
        w->settled = 0;
    /* What would do: 5 time constants of transient, the window kept (at
     * least two periods); or, without a time constant, a longer run. */
    double window = T - transient;
    if (window < 2 * period)
        window = 2 * period;
    if (w->settled == 0 && known_tau)
        w->transient_needed = fmax(transient,
                                   TS_ACCURACY_SETTLE_TAU * tau);
    if (w->periodic == 0 && known_tau && isfinite(w->drift) &&
        w->drift > 0) {
        /* The drift falls as exp(-t / tau): wait until it is below the
         * accuracy. */
        double more = tau * log(w->drift / accuracy);
        w->transient_needed = fmax(w->transient_needed,
                                   T - window + more);
    }
    if (w->periodic == 0 && !known_tau)
        w->transient_needed = fmax(transient, 2.0 * T);
    if (!ok && T < 2 * period)
        w->transient_needed = fmax(transient, 0.0);
    w->t_end_needed = fmax(T, w->transient_needed + window);
}
