/* excitation.c: tow-point excitations and manoeuvres as functions of time
 * (towstab/excitation.h; doc/simulate.md section "Excitations").
 *
 * Every signal is evaluated with its first and second time derivatives in
 * closed form, so the kernel's input u = (x, x', x'') is exactly consistent
 * (a finite-difference velocity would break the rigid links' kinematics).
 *  - sine: x = A sin th, th = w t + phase.
 *  - slider crank (doc/model.md section 8): with S = sqrt(l^2 - A^2 sin^2 th),
 *      x   = A cos th + l - S,
 *      x'  = w (-A sin th + A^2 sin th cos th / S),
 *      x'' = w^2 (-A cos th + A^2 cos 2th / S + (A^2 sin th cos th)^2 / S^3).
 *  - step: x = A S5(xi), xi = (t - start)/rise, with the quintic
 *    S5 = 10 xi^3 - 15 xi^4 + 6 xi^5 (clamped to [0, 1]); S5' and S5'' vanish
 *    at both ends, so x, x', x'' are continuous.
 *  - ramp: the rate is (A/T) [S5(xi1) - S5(xi2)], xi1 = (t - start)/rise,
 *    xi2 = xi1 - T/rise (T the duration): a plateau at A/T with rounded
 *    corners. Its integral uses I(xi) = int_0^xi S5 = 2.5 xi^4 - 3 xi^5 + xi^6
 *    on [0, 1] and xi - 1/2 beyond, x = (A rise/T) [I(xi1) - I(xi2)], which
 *    tends to exactly A.
 *  - series: GSL natural cubic spline (gsl_spline, cspline): C2, so x, x'
 *    and x'' are continuous; evaluated without an accelerator (binary
 *    search) so that evaluation does not write and the excitation can be
 *    shared read-only.
 *  - sum: x_j = r s_j with s_j = sum_k (a_jk cos w_k t - b_jk sin w_k t),
 *    s_j' = -sum_k w_k (a_jk sin + b_jk cos), s_j'' = -sum_k w_k^2 (a_jk cos
 *    - b_jk sin), and the fade-in r = S5(t / rise): x' = r' s + r s',
 *    x'' = r'' s + 2 r' s' + r s''. The axes of one sum share a group: one
 *    sin/cos pair per component and time serves all of them.
 * Manoeuvres: V(t) = V0 + sum dV(t), Omega(t) = Omega0 + sum dOmega(t), with
 * their rates from the same derivatives; the heading psi(t) = Omega0 t +
 * sum int dOmega uses J(xi) = int_0^xi I = xi^5/2 - xi^6/2 + xi^7/7 on [0,1]
 * and 1/7 + xi (xi - 1)/2 beyond. A current c fixed in inertial space has,
 * in M rotated by psi about +z, the components R_z(psi)^T c.
 *
 * One module, though long: the signal types share one evaluation of
 * displacement, velocity and acceleration, one spec parser and one
 * description; a signal is a few dozen lines of each.
 */
#include "towstab/excitation.h"

#include <ctype.h>
#include <errno.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Longest spec and key accepted by the parser (far beyond a real use). */
#define SPEC_MAX 1024
/* Longest CSV line. */
#define LINE_MAX_CSV 4096
/* A series may end this little before t_end (relative) and still cover. */
#define SPAN_RTOL 1e-12

/* The components of a sum, shared by the signals of its axes. */
typedef struct sum_group {
    int n;                 /* components */
    double *omega;         /* [n] rad/s */
    double *c;             /* [2 TS_SUM_AXES n]: re, im of each axis per
                              component */
    double rise;           /* fade-in, s (0: none) */
    int axes[TS_SUM_AXES]; /* 1: the group drives axis j */
} sum_group;

struct ts_excitation {
    int n, cap;
    ts_signal *sig;        /* [cap] */
    gsl_spline **spline;   /* [cap], non-NULL for series */
    double *series_dt;     /* [cap] smallest sample spacing of a series */
    sum_group **sum;       /* [cap], the group of a sum signal */
    char *sum_lead;        /* [cap] 1: the first signal of its group (which
                              owns and evaluates it) */
};

static void sum_group_free(sum_group *g)
{
    if (!g)
        return;
    free(g->omega);
    free(g->c);
    free(g);
}

ts_excitation *ts_excitation_alloc(ts_err *err)
{
    ts_excitation *ex = calloc(1, sizeof *ex);
    if (!ex)
        ts_fail(err, TS_ENOMEM, "ts_excitation_alloc: out of memory");
    return ex;
}

void ts_excitation_free(ts_excitation *ex)
{
    if (!ex)
        return;
    for (int i = 0; i < ex->n; i++) {
        if (ex->spline[i])
            gsl_spline_free(ex->spline[i]);
        if (ex->sum_lead[i])
            sum_group_free(ex->sum[i]);
    }
    free(ex->sig);
    free(ex->spline);
    free(ex->series_dt);
    free(ex->sum);
    free(ex->sum_lead);
    free(ex);
}

ts_excitation *ts_excitation_copy(const ts_excitation *ex, ts_err *err)
{
    ts_excitation *c = ts_excitation_alloc(err);
    if (!c || !ex)
        return c;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int rc = TS_OK;
    for (int i = 0; i < ex->n && rc == TS_OK; i++) {
        if (ex->sum[i] && !ex->sum_lead[i])
            continue; /* added with its group's lead */
        if (ex->sum[i]) {
            const sum_group *g = ex->sum[i];
            const size_t na = TS_SUM_AXES;
            double *re = malloc(na * (size_t)g->n * sizeof *re);
            double *im = malloc(na * (size_t)g->n * sizeof *im);
            if (!re || !im)
                rc = ts_fail(err, TS_ENOMEM, "excitation: out of memory");
            for (int k = 0; rc == TS_OK && k < g->n; k++)
                for (size_t j = 0; j < na; j++) {
                    const double *c = g->c + 2 * na * k + 2 * j;
                    re[na * k + j] = g->axes[j] ? c[0] : 0.0;
                    im[na * k + j] = g->axes[j] ? c[1] : 0.0;
                }
            if (rc == TS_OK)
                rc = ts_excitation_add_sum(c, g->n, g->omega, re, im, g->rise,
                                           err);
            free(re);
            free(im);
        } else if (ex->spline[i]) {
            const gsl_spline *sp = ex->spline[i];
            rc = ts_excitation_add_series(c, ex->sig[i].axis, (int)sp->size,
                                          sp->x, sp->y, err);
        } else {
            rc = ts_excitation_add(c, &ex->sig[i], err);
        }
    }
    gsl_set_error_handler(old);
    if (rc != TS_OK) {
        ts_excitation_free(c);
        return NULL;
    }
    return c;
}

const char *ts_axis_name(ts_axis a)
{
    switch (a) {
    case TS_AXIS_SURGE: return "tow.surge";
    case TS_AXIS_SWAY: return "tow.sway";
    case TS_AXIS_HEAVE: return "tow.heave";
    case TS_AXIS_SPEED: return "speed";
    case TS_AXIS_TURN_RATE: return "turn_rate";
    case TS_AXIS_INPUT: return "input";
    case TS_AXIS_ROLL: return "tow.roll";
    case TS_AXIS_PITCH: return "tow.pitch";
    case TS_AXIS_YAW: return "tow.yaw";
    }
    return "?";
}

const char *ts_signal_type_name(ts_signal_type t)
{
    switch (t) {
    case TS_SIGNAL_SINE: return "sine";
    case TS_SIGNAL_CRANK: return "crank";
    case TS_SIGNAL_STEP: return "step";
    case TS_SIGNAL_RAMP: return "ramp";
    case TS_SIGNAL_SERIES: return "csv";
    case TS_SIGNAL_SUM: return "sum";
    }
    return "?";
}

/* A rotation axis of the ship (tow.roll, tow.pitch, tow.yaw). */
static int is_rot_axis(int a)
{
    return a >= TS_AXIS_ROLL && a <= TS_AXIS_YAW;
}
/* An axis of the tow inputs: a translation or a rotation; its value is
 * the index of its displacement among the kernel's inputs. */
static int is_tow_axis(int a)
{
    return (a >= TS_AXIS_SURGE && a <= TS_AXIS_HEAVE) || is_rot_axis(a);
}
/* The axis of sum axis j (0..TS_SUM_AXES). */
static ts_axis sum_axis(int j)
{
    return j < 3 ? (ts_axis)j : (ts_axis)(TS_AXIS_ROLL + j - 3);
}
static int is_manoeuvre(int a)
{
    return a == TS_AXIS_SPEED || a == TS_AXIS_TURN_RATE;
}

const char *ts_signal_axis_label(const ts_signal *s)
{
    return s->axis == TS_AXIS_INPUT ? s->input : ts_axis_name(s->axis);
}

static int grow(ts_excitation *ex, ts_err *err)
{
    if (ex->n < ex->cap)
        return TS_OK;
    int cap = ex->cap ? 2 * ex->cap : 4;
    ts_signal *s = realloc(ex->sig, (size_t)cap * sizeof *s);
    if (s)
        ex->sig = s;
    gsl_spline **sp = realloc(ex->spline, (size_t)cap * sizeof *sp);
    if (sp)
        ex->spline = sp;
    double *dt = realloc(ex->series_dt, (size_t)cap * sizeof *dt);
    if (dt)
        ex->series_dt = dt;
    sum_group **sg = realloc(ex->sum, (size_t)cap * sizeof *sg);
    if (sg)
        ex->sum = sg;
    char *sl = realloc(ex->sum_lead, (size_t)cap);
    if (sl)
        ex->sum_lead = sl;
    if (!s || !sp || !dt || !sg || !sl)
        return ts_fail(err, TS_ENOMEM, "excitation: out of memory");
    ex->cap = cap;
    return TS_OK;
}

int ts_excitation_add(ts_excitation *ex, const ts_signal *s, ts_err *err)
{
    const char *an = ts_signal_axis_label(s), *tn = ts_signal_type_name(s->type);
    if (!((s->axis >= TS_AXIS_SURGE && s->axis <= TS_AXIS_INPUT) ||
          is_rot_axis(s->axis)))
        return ts_fail(err, TS_EINVAL, "excitation: axis %d is not one of "
                       "tow.surge, tow.sway, tow.heave, speed, turn_rate, "
                       "input, tow.roll, tow.pitch, tow.yaw", (int)s->axis);
    if (is_rot_axis(s->axis) && s->type == TS_SIGNAL_CRANK)
        return ts_fail(err, TS_EINVAL, "excitation %s: a rotation takes a "
                       "sine, a step or a ramp (a crank is a slider's "
                       "translation), got crank", an);
    if (s->axis == TS_AXIS_INPUT &&
        (!memchr(s->input, '\0', sizeof s->input) || !strchr(s->input, '.')))
        return ts_fail(err, TS_EINVAL, "excitation: a vehicle input's name "
                       "is <vehicle>.<surface>, <vehicle>.<loop> or "
                       "<vehicle>.<loop>.setpoint");
    if (s->axis == TS_AXIS_INPUT && s->type == TS_SIGNAL_CRANK)
        return ts_fail(err, TS_EINVAL, "excitation %s: a vehicle input "
                       "takes a sine, a step or a ramp, got crank", an);
    if (!(s->type >= TS_SIGNAL_SINE && s->type <= TS_SIGNAL_RAMP))
        return ts_fail(err, TS_EINVAL, "excitation %s: type %d is not sine, "
                       "crank, step or ramp (series: "
                       "ts_excitation_add_series)", an, (int)s->type);
    if (is_manoeuvre(s->axis) && s->type != TS_SIGNAL_STEP &&
        s->type != TS_SIGNAL_RAMP)
        return ts_fail(err, TS_EINVAL, "excitation %s: a manoeuvre is a step "
                       "or a ramp, got %s", an, tn);
    if (!isfinite(s->amplitude))
        return ts_fail(err, TS_EINVAL, "excitation %s: amplitude must be "
                       "finite, got %g", an, s->amplitude);
    if (s->type == TS_SIGNAL_SINE || s->type == TS_SIGNAL_CRANK) {
        if (!(s->amplitude > 0))
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): amplitude "
                           "must be > 0, got %g", an, tn, s->amplitude);
        if (!(s->frequency > 0) || !isfinite(s->frequency))
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): frequency "
                           "must be > 0 Hz, got %g Hz", an, tn, s->frequency);
        if (!isfinite(s->phase))
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): phase must "
                           "be finite, got %g rad", an, tn, s->phase);
        if (!(s->ramp >= 0) || !isfinite(s->ramp))
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): ramp (the "
                           "smooth start) must be >= 0 s, got %g s", an, tn,
                           s->ramp);
        /* An impulsive start jumps the tow point's velocity, which the
         * simulators pass down the cable as the same jump at every start
         * point (ts_sim_start_state); a rotation's differs from point to
         * point. */
        if (is_rot_axis(s->axis) && s->ramp == 0 && s->amplitude != 0)
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): a rotation "
                           "starts smoothly: ramp (the smooth start) must be "
                           "> 0 s, got 0 s", an, tn);
    }
    if (s->type == TS_SIGNAL_CRANK &&
        (!(s->rod > s->amplitude) || !isfinite(s->rod)))
        return ts_fail(err, TS_EINVAL, "excitation %s (crank): rod must be "
                       "longer than the crank radius %g m, got %g m", an,
                       s->amplitude, s->rod);
    if (s->type == TS_SIGNAL_STEP || s->type == TS_SIGNAL_RAMP) {
        if (!(s->start >= 0) || !isfinite(s->start))
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): start must "
                           "be >= 0 s, got %g s", an, tn, s->start);
        if (!(s->rise > 0) || !isfinite(s->rise))
            return ts_fail(err, TS_EINVAL, "excitation %s (%s): rise must "
                           "be > 0 s (a rigid cable cannot follow a jump in "
                           "velocity), got %g s", an, tn, s->rise);
    }
    if (s->type == TS_SIGNAL_RAMP &&
        (!(s->duration > 0) || !isfinite(s->duration)))
        return ts_fail(err, TS_EINVAL, "excitation %s (ramp): duration must "
                       "be > 0 s, got %g s", an, s->duration);
    if (s->absolute) {
        if (!is_manoeuvre(s->axis))
            return ts_fail(err, TS_EINVAL, "excitation %s: a final value "
                           "('to') applies to manoeuvres only", an);
        for (int i = 0; i < ex->n; i++)
            if (ex->sig[i].axis == s->axis && ex->sig[i].absolute)
                return ts_fail(err, TS_EINVAL, "excitation %s: two signals "
                               "set its final value ('to'); give one, or "
                               "changes ('by')", an);
    }
    int rc = grow(ex, err);
    if (rc)
        return rc;
    ex->sig[ex->n] = *s;
    ex->spline[ex->n] = NULL;
    ex->series_dt[ex->n] = INFINITY;
    ex->sum[ex->n] = NULL;
    ex->sum_lead[ex->n] = 0;
    ex->n++;
    return TS_OK;
}

int ts_excitation_add_series(ts_excitation *ex, ts_axis axis, int n,
                             const double t[], const double x[], ts_err *err)
{
    const char *an = ts_axis_name(axis);
    if (!is_tow_axis(axis))
        return ts_fail(err, TS_EINVAL, "excitation %s: a series drives a "
                       "tow-point axis (tow.surge, tow.sway, tow.heave) only",
                       an);
    if (n < 3)
        return ts_fail(err, TS_EINVAL, "excitation %s (csv): a series needs "
                       "at least 3 samples for a cubic spline, got %d", an, n);
    double dtmin = INFINITY;
    for (int i = 0; i < n; i++) {
        if (!isfinite(t[i]) || !isfinite(x[i]))
            return ts_fail(err, TS_EINVAL, "excitation %s (csv): sample %d "
                           "is not finite (t = %g s, x = %g m)", an, i + 1,
                           t[i], x[i]);
        if (i > 0) {
            if (!(t[i] > t[i - 1]))
                return ts_fail(err, TS_EINVAL, "excitation %s (csv): times "
                               "must increase, sample %d has t = %g s after "
                               "%g s", an, i + 1, t[i], t[i - 1]);
            if (t[i] - t[i - 1] < dtmin)
                dtmin = t[i] - t[i - 1];
        }
    }
    if (t[0] > 0)
        return ts_fail(err, TS_EINVAL, "excitation %s (csv): the series must "
                       "start at t <= 0 s (the run starts at 0), its first "
                       "time is %g s", an, t[0]);
    int rc = grow(ex, err);
    if (rc)
        return rc;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    gsl_spline *sp = gsl_spline_alloc(gsl_interp_cspline, (size_t)n);
    int st = sp ? gsl_spline_init(sp, t, x, (size_t)n) : GSL_ENOMEM;
    gsl_set_error_handler(old);
    if (st) {
        gsl_spline_free(sp);
        return ts_fail(err, st == GSL_ENOMEM ? TS_ENOMEM : TS_EINVAL,
                       "excitation %s (csv): the cubic spline failed (%s)",
                       an, gsl_strerror(st));
    }
    ts_signal s = {0};
    s.type = TS_SIGNAL_SERIES;
    s.axis = axis;
    s.start = t[0];
    s.duration = t[n - 1] - t[0];
    ex->sig[ex->n] = s;
    ex->spline[ex->n] = sp;
    ex->series_dt[ex->n] = dtmin;
    ex->sum[ex->n] = NULL;
    ex->sum_lead[ex->n] = 0;
    ex->n++;
    return TS_OK;
}

int ts_excitation_add_sum(ts_excitation *ex, int n, const double omega[],
                          const double re[], const double im[], double rise,
                          ts_err *err)
{
    if (n < 1)
        return ts_fail(err, TS_EINVAL, "excitation sum: at least one "
                       "component is needed, got %d", n);
    if (!(rise >= 0) || !isfinite(rise))
        return ts_fail(err, TS_EINVAL, "excitation sum: the fade-in time "
                       "must be >= 0 s, got %g s", rise);
    enum { NA = TS_SUM_AXES };
    double ms[NA] = {0}, wmax = 0;
    for (int k = 0; k < n; k++) {
        if (!isfinite(omega[k]))
            return ts_fail(err, TS_EINVAL, "excitation sum: component %d: "
                           "frequency must be finite, got %g rad/s", k,
                           omega[k]);
        wmax = fmax(wmax, fabs(omega[k]));
        for (int j = 0; j < NA; j++) {
            double a = re[NA * k + j], b = im[NA * k + j];
            if (!isfinite(a) || !isfinite(b))
                return ts_fail(err, TS_EINVAL, "excitation sum: component "
                               "%d, %s: the amplitude overflows (is not a "
                               "finite number): the wave heights or the "
                               "motions per metre of wave are too large",
                               k, ts_axis_name(sum_axis(j)));
            ms[j] += 0.5 * (a * a + b * b);
        }
    }
    int naxes = 0;
    for (int j = 0; j < NA; j++)
        naxes += ms[j] > 0;
    if (naxes == 0)
        return ts_fail(err, TS_EINVAL, "excitation sum: every coefficient "
                       "is zero: no axis is driven");
    sum_group *g = calloc(1, sizeof *g);
    if (g) {
        g->omega = malloc((size_t)n * sizeof(double));
        g->c = malloc(2 * NA * (size_t)n * sizeof(double));
    }
    if (!g || !g->omega || !g->c) {
        sum_group_free(g);
        return ts_fail(err, TS_ENOMEM, "excitation: out of memory");
    }
    g->n = n;
    g->rise = rise;
    memcpy(g->omega, omega, (size_t)n * sizeof(double));
    for (int k = 0; k < n; k++)
        for (int j = 0; j < NA; j++) {
            g->c[2 * NA * k + 2 * j] = re[NA * k + j];
            g->c[2 * NA * k + 2 * j + 1] = im[NA * k + j];
        }
    for (int j = 0; j < NA; j++)
        g->axes[j] = ms[j] > 0;
    /* Room for every axis first, so that a failure adds nothing (grow()
     * enlarges a full table). */
    while (ex->cap < ex->n + naxes) {
        int keep = ex->n;
        ex->n = ex->cap;
        int rc = grow(ex, err);
        ex->n = keep;
        if (rc) {
            sum_group_free(g);
            return rc;
        }
    }
    int lead = 1;
    for (int j = 0; j < NA; j++) {
        if (!g->axes[j])
            continue;
        ts_signal sg = {0};
        sg.type = TS_SIGNAL_SUM;
        sg.axis = sum_axis(j);
        sg.amplitude = sqrt(ms[j]);
        sg.frequency = wmax / (2.0 * M_PI);
        sg.rise = rise;
        ex->sig[ex->n] = sg;
        ex->spline[ex->n] = NULL;
        ex->series_dt[ex->n] = INFINITY;
        ex->sum[ex->n] = g;
        ex->sum_lead[ex->n] = (char)lead;
        lead = 0;
        ex->n++;
    }
    return TS_OK;
}

int ts_excitation_sum_components(const ts_excitation *ex, int i)
{
    return i >= 0 && i < ex->n && ex->sum[i] ? ex->sum[i]->n : 0;
}

/* Skip blanks. */
static const char *skip_ws(const char *s)
{
    while (*s == ' ' || *s == '\t' || *s == '\r')
        s++;
    return s;
}

/* Parse one CSV field as a number, advancing *s past it and a comma. */
static int csv_number(const char **s, double *v)
{
    const char *p = skip_ws(*s);
    char *end;
    errno = 0;
    *v = strtod(p, &end);
    if (end == p || errno == ERANGE || !isfinite(*v))
        return -1;
    p = skip_ws(end);
    if (*p == ',')
        p++;
    else if (*p != '\0' && *p != '\n')
        return -1;
    *s = p;
    return 0;
}

int ts_excitation_read_series(ts_excitation *ex, ts_axis axis,
                              const char *path, ts_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return ts_fail(err, TS_EIO, "excitation %s (csv): cannot read '%s': "
                       "%s", ts_axis_name(axis), path, strerror(errno));
    double *t = NULL, *x = NULL;
    int n = 0, cap = 0, lineno = 0, data_lines = 0, rc = TS_OK;
    char line[LINE_MAX_CSV];
    while (fgets(line, sizeof line, f)) {
        lineno++;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n') {
            rc = ts_fail(err, TS_EINVAL, "%s line %d: longer than %d "
                         "characters", path, lineno, LINE_MAX_CSV - 2);
            break;
        }
        while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r'))
            line[--len] = '\0';
        const char *s = skip_ws(line);
        if (*s == '#' || *s == '\0')
            continue;
        data_lines++;
        const char *p = s;
        double tv, xv;
        if (csv_number(&p, &tv) || csv_number(&p, &xv)) {
            if (data_lines == 1 && isalpha((unsigned char)*s))
                continue; /* a header */
            rc = ts_fail(err, TS_EINVAL, "%s line %d: expected two numbers "
                         "'time_s,displacement_m', got '%.40s'", path,
                         lineno, s);
            break;
        }
        if (n == cap) {
            cap = cap ? 2 * cap : 256;
            double *nt = realloc(t, (size_t)cap * sizeof *t);
            if (nt)
                t = nt;
            double *nx = realloc(x, (size_t)cap * sizeof *x);
            if (nx)
                x = nx;
            if (!nt || !nx) {
                rc = ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
                break;
            }
        }
        t[n] = tv;
        x[n] = xv;
        n++;
    }
    if (!rc && ferror(f))
        rc = ts_fail(err, TS_EIO, "%s: read error", path);
    fclose(f);
    if (!rc) {
        rc = ts_excitation_add_series(ex, axis, n, t, x, err);
        if (rc)
            ts_err_prefix(err, "%s: ", path);
    }
    free(t);
    free(x);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Parsing "AXIS:key=value,..."                                         */

enum {
    K_TYPE, K_AMPLITUDE, K_FREQUENCY, K_PERIOD, K_PHASE, K_ROD, K_START,
    K_DURATION, K_RISE, K_TO, K_BY, K_FILE, K_RAMP, K_N
};
static const char *const key_names[K_N] = {
    "type", "amplitude", "frequency", "period", "phase", "rod", "start",
    "duration", "rise", "to", "by", "file", "ramp"};

/* Keys each type accepts (besides `type`), as a bit set over K_*. */
static unsigned keys_for(ts_signal_type t, int tow)
{
#define B(k) (1u << (k))
    switch (t) {
    case TS_SIGNAL_SINE:
        return B(K_AMPLITUDE) | B(K_FREQUENCY) | B(K_PERIOD) | B(K_PHASE) |
               B(K_RAMP);
    case TS_SIGNAL_CRANK:
        return B(K_AMPLITUDE) | B(K_FREQUENCY) | B(K_PERIOD) | B(K_PHASE) |
               B(K_ROD) | B(K_RAMP);
    case TS_SIGNAL_STEP:
        return (tow ? B(K_AMPLITUDE) : B(K_TO) | B(K_BY)) | B(K_START) |
               B(K_RISE);
    case TS_SIGNAL_RAMP:
        return (tow ? B(K_AMPLITUDE) : B(K_TO) | B(K_BY)) | B(K_START) |
               B(K_DURATION) | B(K_RISE);
    case TS_SIGNAL_SERIES:
        return B(K_FILE);
    case TS_SIGNAL_SUM: /* built by ts_excitation_add_sum, not parsed */
        return 0;
    }
    return 0;
#undef B
}

static void key_list(unsigned set, char *buf, size_t size)
{
    buf[0] = '\0';
    for (int k = 0; k < K_N; k++)
        if (set & (1u << k)) {
            if (buf[0])
                strncat(buf, ", ", size - strlen(buf) - 1);
            strncat(buf, key_names[k], size - strlen(buf) - 1);
        }
}

static int parse_axis(const char *name, ts_axis *a)
{
    static const struct { const char *name; ts_axis axis; } tab[] = {
        {"tow.surge", TS_AXIS_SURGE}, {"tow.x", TS_AXIS_SURGE},
        {"tow.sway", TS_AXIS_SWAY},   {"tow.y", TS_AXIS_SWAY},
        {"tow.heave", TS_AXIS_HEAVE}, {"tow.z", TS_AXIS_HEAVE},
        {"speed", TS_AXIS_SPEED},     {"turn_rate", TS_AXIS_TURN_RATE},
        {"tow.roll", TS_AXIS_ROLL},   {"tow.pitch", TS_AXIS_PITCH},
        {"tow.yaw", TS_AXIS_YAW}};
    for (size_t i = 0; i < sizeof tab / sizeof tab[0]; i++)
        if (!strcmp(name, tab[i].name)) {
            *a = tab[i].axis;
            return 0;
        }
    return -1;
}

/* Trim blanks at both ends in place. */
static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
        s[--n] = '\0';
    return s;
}

/* The amplitude of a vehicle input's signal: a length (m), an angle
 * (rad), a force (N) or a moment (N*m), its kind kept in s->input_unit ("" for a plain number). */
static int input_amplitude(const ts_units *units, const char *text,
                           const char *where, ts_signal *s, ts_err *err)
{
    char *end;
    double v = strtod(text, &end);
    if (end != text && !*trim(end)) {
        s->amplitude = v;
        return TS_OK;
    }
    ts_err e = {0};
    if (ts_units_parse(units, text, "m", where, &s->amplitude, &e) == TS_OK) {
        snprintf(s->input_unit, sizeof s->input_unit, "m");
        return TS_OK;
    }
    if (ts_units_parse(units, text, "rad", where, &s->amplitude, &e) ==
        TS_OK) {
        snprintf(s->input_unit, sizeof s->input_unit, "rad");
        return TS_OK;
    }
    /* A towing vehicle's thrust or external force, moment, or its speed
     * controller's set speed. */
    static const char *const other[3] = {"N", "N*m", "m/s"};
    for (int i = 0; i < 3; i++)
        if (ts_units_parse(units, text, other[i], where, &s->amplitude, &e) ==
            TS_OK) {
            snprintf(s->input_unit, sizeof s->input_unit, "%s", other[i]);
            return TS_OK;
        }
    return ts_fail(err, TS_EUNIT, "%s: '%.40s' is neither a length (m, for "
                   "a depth set point), an angle (rad, deg), a force (N, a "
                   "towing vehicle's thrust or force), a moment (N*m) nor a "
                   "speed (m/s, a towing vehicle's speed_set)",
                   where, text);
}

int ts_excitation_parse(ts_excitation *ex, const char *spec,
                        const ts_units *units, const char *where,
                        ts_err *err)
{
    if (!where)
        where = "excitation";
    if (!spec || strlen(spec) >= SPEC_MAX)
        return ts_fail(err, TS_EINVAL, "%s: expected AXIS[:key=value,...] "
                       "of at most %d characters", where, SPEC_MAX - 1);
    char buf[SPEC_MAX];
    snprintf(buf, sizeof buf, "%s", spec);
    char *colon = strchr(buf, ':');
    if (colon)
        *colon = '\0';
    char *axis_name = trim(buf);
    ts_axis axis;
    if (parse_axis(axis_name, &axis)) {
        /* Any other dotted name is a vehicle's input, checked against the
         * kernel by the simulator. */
        if (!strchr(axis_name, '.') || !strncmp(axis_name, "tow.", 4) ||
            strlen(axis_name) >= TS_SIGNAL_INPUT_MAX)
            return ts_fail(err, TS_EINVAL, "%s: unknown axis '%.60s'; "
                           "expected tow.surge, tow.sway, tow.heave (or "
                           "tow.x, tow.y, tow.z), tow.roll, tow.pitch, "
                           "tow.yaw, speed, turn_rate or a vehicle's input (<vehicle>.<surface>, "
                           "<vehicle>.<loop>, <vehicle>.<loop>.setpoint)",
                           where, axis_name);
        axis = TS_AXIS_INPUT;
    }
    /* A vehicle input takes a tow axis' keys (amplitude, no to/by). */
    int input = axis == TS_AXIS_INPUT, tow = is_tow_axis(axis) || input;
    const char *an = input ? axis_name : ts_axis_name(axis);

    /* Collect key=value pairs. */
    char *val[K_N] = {0};
    char *rest = colon ? colon + 1 : NULL;
    for (int first = 1; rest && *trim(rest); first = 0) {
        char *comma = strchr(rest, ',');
        if (comma)
            *comma = '\0';
        char *item = trim(rest);
        rest = comma ? comma + 1 : NULL;
        if (!*item)
            return ts_fail(err, TS_EINVAL, "%s: %s: empty item; expected "
                           "key=value separated by commas", where, an);
        char *eq = strchr(item, '=');
        char *key, *value;
        if (!eq && first) {
            /* A bare first item is the type: "tow.heave:crank,...". */
            key = (char *)"type";
            value = item;
        } else if (!eq) {
            return ts_fail(err, TS_EINVAL, "%s: %s: '%.60s' is not "
                           "key=value", where, an, item);
        } else {
            *eq = '\0';
            key = trim(item);
            value = trim(eq + 1);
        }
        /* Aliases: r and radius for a crank's amplitude (its radius). */
        if (!strcmp(key, "r") || !strcmp(key, "radius"))
            key = (char *)"amplitude";
        int k = 0;
        while (k < K_N && strcmp(key, key_names[k]))
            k++;
        if (k == K_N) {
            char list[256];
            key_list((1u << K_N) - 1, list, sizeof list);
            return ts_fail(err, TS_EINVAL, "%s: %s: unknown parameter "
                           "'%.60s'; expected one of %s", where, an, key,
                           list);
        }
        if (val[k])
            return ts_fail(err, TS_EINVAL, "%s: %s: '%s' given twice", where,
                           an, key);
        if (!*value)
            return ts_fail(err, TS_EINVAL, "%s: %s: '%s' has no value", where,
                           an, key);
        val[k] = value;
    }

    ts_signal s = {0};
    s.axis = axis;
    s.type = input ? TS_SIGNAL_STEP : tow ? TS_SIGNAL_SINE : TS_SIGNAL_RAMP;
    if (input)
        snprintf(s.input, sizeof s.input, "%s", axis_name);
    if (val[K_TYPE]) {
        static const char *const types[] = {"sine", "crank", "step", "ramp",
                                            "csv"};
        int t = 0;
        while (t < 5 && strcmp(val[K_TYPE], types[t]))
            t++;
        if (!strcmp(val[K_TYPE], "slider_crank"))
            t = TS_SIGNAL_CRANK;
        if (t == 5)
            return ts_fail(err, TS_EINVAL, "%s: %s: unknown type '%.40s'; "
                           "expected %s", where, an, val[K_TYPE],
                           input ? "sine, step or ramp"
                           : tow ? "sine, crank, step, ramp or csv"
                                 : "step or ramp");
        s.type = (ts_signal_type)t;
    }
    if (input && (s.type == TS_SIGNAL_CRANK || s.type == TS_SIGNAL_SERIES))
        return ts_fail(err, TS_EINVAL, "%s: %s: a vehicle input takes a "
                       "sine, a step or a ramp, got type %s", where, an,
                       ts_signal_type_name(s.type));
    unsigned allowed = keys_for(s.type, tow);
    if (!tow && s.type != TS_SIGNAL_STEP && s.type != TS_SIGNAL_RAMP)
        return ts_fail(err, TS_EINVAL, "%s: %s: a manoeuvre is a step or a "
                       "ramp, got type %s", where, an,
                       ts_signal_type_name(s.type));
    for (int k = 1; k < K_N; k++)
        if (val[k] && !(allowed & (1u << k))) {
            char list[256];
            key_list(allowed, list, sizeof list);
            return ts_fail(err, TS_EINVAL, "%s: %s: parameter '%s' does not "
                           "apply to type %s; expected %s", where, an,
                           key_names[k], ts_signal_type_name(s.type), list);
        }

    if (s.type == TS_SIGNAL_SERIES) {
        if (!val[K_FILE])
            return ts_fail(err, TS_EINVAL, "%s: %s: type csv needs "
                           "file=PATH", where, an);
        int rc = ts_excitation_read_series(ex, axis, val[K_FILE], err);
        if (rc)
            ts_err_prefix(err, "%s: ", where);
        return rc;
    }

    /* Quantities, each with its SI unit. */
    const char *amp_unit = is_rot_axis(axis)     ? "rad"
                           : tow                 ? "m"
                           : axis == TS_AXIS_SPEED ? "m/s"
                                                   : "rad/s";
    double period = 0;
    const struct { int key; const char *unit; double *dst; } q[] = {
        {K_AMPLITUDE, amp_unit, &s.amplitude}, {K_TO, amp_unit, &s.amplitude},
        {K_BY, amp_unit, &s.amplitude},        {K_FREQUENCY, "Hz", &s.frequency},
        {K_PERIOD, "s", &period},              {K_PHASE, "rad", &s.phase},
        {K_ROD, "m", &s.rod},                  {K_START, "s", &s.start},
        {K_DURATION, "s", &s.duration},        {K_RISE, "s", &s.rise},
        {K_RAMP, "s", &s.ramp}};
    for (size_t i = 0; i < sizeof q / sizeof q[0]; i++) {
        if (!val[q[i].key])
            continue;
        char w[160];
        snprintf(w, sizeof w, "%.60s: %.60s: %s", where, an,
                 key_names[q[i].key]);
        if (input && q[i].key == K_AMPLITUDE) {
            /* m (a depth set point) or rad (the rest): which one the
             * input takes is checked against the kernel. */
            int rc = input_amplitude(units, val[K_AMPLITUDE], w, &s, err);
            if (rc)
                return rc;
            continue;
        }
        int rc = ts_units_parse(units, val[q[i].key], q[i].unit, w, q[i].dst,
                                err);
        if (rc)
            return rc;
    }
    int need_amp = !(s.type == TS_SIGNAL_STEP || s.type == TS_SIGNAL_RAMP) ||
                   tow;
    if (need_amp && !val[K_AMPLITUDE])
        return ts_fail(err, TS_EINVAL, "%s: %s: type %s needs amplitude=",
                       where, an, ts_signal_type_name(s.type));
    if (is_manoeuvre(axis)) {
        if (!!val[K_TO] + !!val[K_BY] != 1)
            return ts_fail(err, TS_EINVAL, "%s: %s: give exactly one of to= "
                           "(final value) and by= (change)", where, an);
        s.absolute = val[K_TO] != NULL;
    }
    if (s.type == TS_SIGNAL_SINE || s.type == TS_SIGNAL_CRANK) {
        if (!!val[K_FREQUENCY] + !!val[K_PERIOD] != 1)
            return ts_fail(err, TS_EINVAL, "%s: %s: give exactly one of "
                           "frequency= and period=", where, an);
        if (val[K_PERIOD]) {
            if (!(period > 0))
                return ts_fail(err, TS_EINVAL, "%s: %s: period must be > 0 "
                               "s, got %g s", where, an, period);
            s.frequency = 1.0 / period;
        }
        /* Smooth by default: a tow point that jumps into motion moves the
         * whole cable at once (its coordinates are relative to it). */
        if (!val[K_RAMP] && s.frequency > 0)
            s.ramp = TS_SIGNAL_RAMP_PERIODS / s.frequency;
    }
    if (s.type == TS_SIGNAL_CRANK && !val[K_ROD])
        return ts_fail(err, TS_EINVAL, "%s: %s: type crank needs rod= (the "
                       "connecting rod length)", where, an);
    if (s.type == TS_SIGNAL_RAMP && !val[K_DURATION])
        return ts_fail(err, TS_EINVAL, "%s: %s: type ramp needs duration=",
                       where, an);
    if ((s.type == TS_SIGNAL_STEP || s.type == TS_SIGNAL_RAMP) &&
        !val[K_RISE]) {
        s.rise = TS_SIGNAL_RISE;
        if (s.type == TS_SIGNAL_RAMP && s.duration > 0 &&
            s.duration < s.rise)
            s.rise = s.duration;
    }
    int rc = ts_excitation_add(ex, &s, err);
    if (rc)
        ts_err_prefix(err, "%s: ", where);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Evaluation                                                           */

/* Quintic smooth step and its derivatives, clamped outside [0, 1]. */
static double s5(double x)
{
    if (x <= 0)
        return 0.0;
    if (x >= 1)
        return 1.0;
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}
static double s5d(double x)
{
    if (x <= 0 || x >= 1)
        return 0.0;
    double y = x * (1.0 - x);
    return 30.0 * y * y;
}
static double s5dd(double x)
{
    if (x <= 0 || x >= 1)
        return 0.0;
    return 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x);
}
/* I(x) = int_0^x s5, J(x) = int_0^x I. */
static double s5i(double x)
{
    if (x <= 0)
        return 0.0;
    if (x >= 1)
        return x - 0.5;
    double x4 = x * x * x * x;
    return x4 * (2.5 + x * (-3.0 + x));
}
static double s5ii(double x)
{
    if (x <= 0)
        return 0.0;
    if (x >= 1)
        return 1.0 / 7.0 + 0.5 * x * (x - 1.0);
    double x5 = x * x * x * x * x;
    return x5 * (0.5 + x * (-0.5 + x / 7.0));
}

/* Value and first two derivatives of signal i at t, with the amplitude
 * `amp` (the signal's own, or a manoeuvre's change). */
static void signal_raw(const ts_excitation *ex, int i, double amp, double t,
                       double *x, double *v, double *a)
{
    const ts_signal *s = &ex->sig[i];
    switch (s->type) {
    case TS_SIGNAL_SINE: {
        double w = 2.0 * M_PI * s->frequency, th = w * t + s->phase;
        double sn = sin(th), cs = cos(th);
        *x = amp * sn;
        *v = amp * w * cs;
        *a = -amp * w * w * sn;
        return;
    }
    case TS_SIGNAL_CRANK: {
        double w = 2.0 * M_PI * s->frequency, th = w * t + s->phase;
        double r = amp, l = s->rod, sn = sin(th), cs = cos(th);
        double S = sqrt(l * l - r * r * sn * sn);
        double g = r * r * sn * cs;
        *x = r * cs + l - S;
        *v = w * (-r * sn + g / S);
        *a = w * w * (-r * cs + r * r * cos(2.0 * th) / S + g * g / (S * S * S));
        return;
    }
    case TS_SIGNAL_STEP: {
        double xi = (t - s->start) / s->rise;
        *x = amp * s5(xi);
        *v = amp * s5d(xi) / s->rise;
        *a = amp * s5dd(xi) / (s->rise * s->rise);
        return;
    }
    case TS_SIGNAL_RAMP: {
        double tau = s->rise, T = s->duration;
        double x1 = (t - s->start) / tau, x2 = x1 - T / tau;
        *x = amp * tau / T * (s5i(x1) - s5i(x2));
        *v = amp / T * (s5(x1) - s5(x2));
        *a = amp / (T * tau) * (s5d(x1) - s5d(x2));
        return;
    }
    case TS_SIGNAL_SUM: /* evaluated by group (sum_eval) */
        break;
    case TS_SIGNAL_SERIES: {
        const gsl_spline *sp = ex->spline[i];
        double lo = s->start, hi = s->start + s->duration;
        double tc = t < lo ? lo : (t > hi ? hi : t);
        /* Outside its span a series holds its end value. */
        *x = gsl_spline_eval(sp, tc, NULL);
        *v = tc == t ? gsl_spline_eval_deriv(sp, tc, NULL) : 0.0;
        *a = tc == t ? gsl_spline_eval_deriv2(sp, tc, NULL) : 0.0;
        return;
    }
    }
    *x = *v = *a = 0.0;
}

/* With a sine's or crank's smooth start: x R, (x R)', (x R)'' with the
 * envelope R = S(t / ramp). */
static void signal_eval(const ts_excitation *ex, int i, double amp, double t,
                        double *x, double *v, double *a)
{
    signal_raw(ex, i, amp, t, x, v, a);
    const ts_signal *s = &ex->sig[i];
    if (!(s->type == TS_SIGNAL_SINE || s->type == TS_SIGNAL_CRANK) ||
        !(s->ramp > 0) || t >= s->ramp)
        return;
    double xi = t / s->ramp, R = s5(xi), Rd = s5d(xi) / s->ramp,
           Rdd = s5dd(xi) / (s->ramp * s->ramp);
    double x0 = *x, v0 = *v, a0 = *a;
    *x = R * x0;
    *v = Rd * x0 + R * v0;
    *a = Rdd * x0 + 2.0 * Rd * v0 + R * a0;
}

int ts_excitation_start_jump(const ts_excitation *ex, double du[TS_NINPUT])
{
    int jump = 0;
    for (int j = 0; j < TS_NINPUT; j++)
        du[j] = 0.0;
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        if (!is_tow_axis(s->axis) || s->type == TS_SIGNAL_SERIES)
            continue;
        double x, v, a;
        signal_eval(ex, i, s->amplitude, 0.0, &x, &v, &a);
        du[s->axis] += x;
        du[3 + s->axis] += v;
        jump |= x != 0.0 || v != 0.0;
    }
    return jump;
}

/* Integral over [0, t] of a step or ramp manoeuvre of amplitude amp. */
static double signal_integral(const ts_signal *s, double amp, double t)
{
    if (s->type == TS_SIGNAL_STEP)
        return amp * s->rise * s5i((t - s->start) / s->rise);
    double tau = s->rise, T = s->duration;
    double x1 = (t - s->start) / tau, x2 = x1 - T / tau;
    return amp * tau * tau / T * (s5ii(x1) - s5ii(x2));
}

/* Add the displacement, velocity and acceleration of sum group g at t to
 * u (each driven axis). */
static void sum_eval(const sum_group *g, double t, double u[TS_NINPUT])
{
    enum { NA = TS_SUM_AXES };
    double x[NA] = {0}, v[NA] = {0}, a[NA] = {0};
    for (int k = 0; k < g->n; k++) {
        double w = g->omega[k], sn = sin(w * t), cs = cos(w * t);
        const double *c = g->c + 2 * NA * k;
        for (int j = 0; j < NA; j++) {
            double re = c[2 * j], im = c[2 * j + 1];
            double p = re * cs - im * sn, q = re * sn + im * cs;
            x[j] += p;
            v[j] -= w * q;
            a[j] -= w * w * p;
        }
    }
    double r = 1.0, r1 = 0.0, r2 = 0.0;
    if (g->rise > 0) {
        double xi = t / g->rise;
        r = s5(xi);
        r1 = s5d(xi) / g->rise;
        r2 = s5dd(xi) / (g->rise * g->rise);
    }
    for (int j = 0; j < NA; j++)
        if (g->axes[j]) {
            int d = (int)sum_axis(j);
            u[d] += r * x[j];
            u[3 + d] += r1 * x[j] + r * v[j];
            u[6 + d] += r2 * x[j] + 2.0 * r1 * v[j] + r * a[j];
        }
}

int ts_excitation_nsignals(const ts_excitation *ex) { return ex->n; }

const ts_signal *ts_excitation_signal(const ts_excitation *ex, int i)
{
    return i >= 0 && i < ex->n ? &ex->sig[i] : NULL;
}

int ts_excitation_has_manoeuvre(const ts_excitation *ex)
{
    for (int i = 0; i < ex->n; i++)
        if (is_manoeuvre(ex->sig[i].axis))
            return 1;
    return 0;
}

double ts_excitation_value(const ts_excitation *ex, int i, double t)
{
    double x, v, a;
    if (i < 0 || i >= ex->n || ex->sig[i].type == TS_SIGNAL_SUM)
        return 0.0;
    signal_eval(ex, i, ex->sig[i].amplitude, t, &x, &v, &a);
    return x;
}

void ts_excitation_input(const ts_excitation *ex, double t,
                         double u[TS_NINPUT])
{
    for (int j = 0; j < TS_NINPUT; j++)
        u[j] = 0.0;
    for (int i = 0; i < ex->n; i++) {
        int ax = ex->sig[i].axis;
        if (!is_tow_axis(ax))
            continue;
        if (ex->sig[i].type == TS_SIGNAL_SUM) {
            if (ex->sum_lead[i])
                sum_eval(ex->sum[i], t, u);
            continue;
        }
        double x, v, a;
        signal_eval(ex, i, ex->sig[i].amplitude, t, &x, &v, &a);
        u[ax] += x;
        u[3 + ax] += v;
        u[6 + ax] += a;
    }
}

/* The change a manoeuvre signal makes, given the base value. */
static double manoeuvre_amp(const ts_signal *s, double base)
{
    return s->absolute ? s->amplitude - base : s->amplitude;
}

double ts_excitation_heading(const ts_excitation *ex, const ts_frame *base,
                             double t)
{
    double psi = base->turn_rate * t;
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        if (s->axis == TS_AXIS_TURN_RATE)
            psi += signal_integral(s, manoeuvre_amp(s, base->turn_rate), t);
    }
    return psi;
}

void ts_excitation_frame(const ts_excitation *ex, const ts_frame *base,
                         double t, ts_frame *f)
{
    ts_frame b = *base;
    ts_frame out = b;
    out.speed_rate = 0.0;
    out.turn_accel = 0.0;
    double psi = b.turn_rate * t;
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        if (!is_manoeuvre(s->axis))
            continue;
        double b0 = s->axis == TS_AXIS_SPEED ? b.speed : b.turn_rate;
        double amp = manoeuvre_amp(s, b0), x, v, a;
        signal_eval(ex, i, amp, t, &x, &v, &a);
        if (s->axis == TS_AXIS_SPEED) {
            out.speed += x;
            out.speed_rate += v;
        } else {
            out.turn_rate += x;
            out.turn_accel += v;
            psi += signal_integral(s, amp, t);
        }
    }
    /* The current is fixed in inertial space: rotate it into M. */
    double c = cos(psi), sn = sin(psi);
    out.current[0] = c * b.current[0] + sn * b.current[1];
    out.current[1] = -sn * b.current[0] + c * b.current[1];
    out.current[2] = b.current[2];
    *f = out;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int ts_excitation_breakpoints(const ts_excitation *ex, double t_end,
                              double out[], int max)
{
    /* At most four per signal. */
    double *all = malloc((size_t)(4 * ex->n + 1) * sizeof *all);
    if (!all)
        return 0;
    int m = 0;
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        if (s->type == TS_SIGNAL_STEP) {
            all[m++] = s->start;
            all[m++] = s->start + s->rise;
        } else if (s->type == TS_SIGNAL_SUM && s->rise > 0) {
            all[m++] = s->rise;
        } else if (s->type == TS_SIGNAL_RAMP) {
            all[m++] = s->start;
            all[m++] = s->start + s->rise;
            all[m++] = s->start + s->duration;
            all[m++] = s->start + s->duration + s->rise;
        } else if ((s->type == TS_SIGNAL_SINE ||
                    s->type == TS_SIGNAL_CRANK) && s->ramp > 0) {
            all[m++] = s->ramp;
        }
    }
    qsort(all, (size_t)m, sizeof *all, cmp_double);
    int k = 0;
    for (int i = 0; i < m; i++) {
        if (!(all[i] > 0 && all[i] < t_end))
            continue;
        if (k > 0 && all[i] - all[k - 1] <= 1e-12 * (1.0 + all[i]))
            continue;
        all[k++] = all[i];
    }
    for (int i = 0; i < k && i < max; i++)
        out[i] = all[i];
    free(all);
    return k;
}

double ts_excitation_time_scale(const ts_excitation *ex)
{
    double ts = INFINITY;
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        double v = INFINITY;
        switch (s->type) {
        case TS_SIGNAL_SINE: v = 1.0 / (2.0 * M_PI * s->frequency); break;
        case TS_SIGNAL_CRANK: v = 1.0 / (4.0 * M_PI * s->frequency); break;
        case TS_SIGNAL_STEP:
        case TS_SIGNAL_RAMP: v = s->rise; break;
        case TS_SIGNAL_SERIES: v = ex->series_dt[i]; break;
        case TS_SIGNAL_SUM:
            v = s->frequency > 0 ? 1.0 / (2.0 * M_PI * s->frequency)
                                 : INFINITY;
            if (s->rise > 0 && s->rise < v)
                v = s->rise;
            break;
        }
        if (v < ts)
            ts = v;
    }
    return ts;
}

/* Largest slopes of the quintic S(xi) = 10 xi^3 - 15 xi^4 + 6 xi^5:
 * S' at xi = 1/2, S'' at xi = (3 - sqrt 3) / 6. */
#define QUINTIC_SLOPE 1.875
#define QUINTIC_CURVE 5.7735

void ts_excitation_bound(const ts_excitation *ex, const ts_frame *base,
                         ts_motion_bound *m)
{
    m->speed = fabs(base->speed);
    m->turn_rate = fabs(base->turn_rate);
    m->tow_speed = m->tow_accel = m->rot_rate = m->rot_accel = 0.0;
    for (int i = 0; ex && i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        double A = fabs(s->amplitude), w = 2.0 * M_PI * s->frequency;
        double v = 0.0, a = 0.0;
        switch (s->type) {
        case TS_SIGNAL_SINE:
            v = A * w;
            a = A * w * w;
            break;
        case TS_SIGNAL_CRANK: {
            double f = 1.0 + A / sqrt(s->rod * s->rod - A * A);
            v = A * w * f;
            a = A * w * w * f * f;
            break;
        }
        case TS_SIGNAL_STEP:
            v = QUINTIC_SLOPE * A / s->rise;
            a = QUINTIC_CURVE * A / (s->rise * s->rise);
            break;
        case TS_SIGNAL_RAMP:
            v = A / s->duration;
            a = QUINTIC_SLOPE * v / s->rise;
            break;
        case TS_SIGNAL_SUM: {
            /* Sum of |c_k| w_k (and w_k^2) on this axis, plus the fade-in's
             * slopes times the sum of |c_k|. */
            const sum_group *g = ex->sum[i];
            int j = is_rot_axis(s->axis) ? 3 + (int)s->axis - TS_AXIS_ROLL
                                         : (int)s->axis;
            double c = 0.0;
            for (int k = 0; k < g->n; k++) {
                const double *gc = g->c + 2 * TS_SUM_AXES * k + 2 * j;
                double ck = hypot(gc[0], gc[1]);
                double wk = fabs(g->omega[k]);
                c += ck;
                v += ck * wk;
                a += ck * wk * wk;
            }
            if (g->rise > 0) {
                a += 2.0 * QUINTIC_SLOPE / g->rise * v +
                     QUINTIC_CURVE / (g->rise * g->rise) * c;
                v += QUINTIC_SLOPE / g->rise * c;
            }
            break;
        }
        case TS_SIGNAL_SERIES: {
            const gsl_spline *sp = ex->spline[i];
            double vprev = 0.0;
            for (size_t k = 1; k < sp->size; k++) {
                double dt = sp->x[k] - sp->x[k - 1];
                double vk = (sp->y[k] - sp->y[k - 1]) / dt;
                v = fmax(v, fabs(vk));
                if (k > 1)
                    a = fmax(a, fabs(vk - vprev) / dt);
                vprev = vk;
            }
            break;
        }
        }
        if (s->axis == TS_AXIS_SPEED)
            m->speed += A;
        else if (s->axis == TS_AXIS_TURN_RATE)
            m->turn_rate += A;
        else if (is_rot_axis(s->axis)) {
            m->rot_rate += v;
            m->rot_accel += a;
        } else if (s->axis != TS_AXIS_INPUT) {
            m->tow_speed += v;
            m->tow_accel += a;
        }
    }
}

int ts_excitation_check_span(const ts_excitation *ex, double t_end,
                             ts_err *err)
{
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        if (s->type != TS_SIGNAL_SERIES)
            continue;
        double hi = s->start + s->duration;
        if (hi < t_end * (1.0 - SPAN_RTOL))
            return ts_fail(err, TS_EINVAL, "excitation %s (csv): the series "
                           "ends at %g s, before the end of the run (%g s); "
                           "extend it or shorten the run",
                           ts_signal_axis_label(s), hi, t_end);
    }
    return TS_OK;
}

int ts_excitation_periodic(const ts_excitation *ex, int *index)
{
    int found = -1;
    for (int i = 0; i < ex->n; i++) {
        const ts_signal *s = &ex->sig[i];
        if (s->type == TS_SIGNAL_SINE || s->type == TS_SIGNAL_CRANK) {
            if (found >= 0 || !is_tow_axis(s->axis))
                return 0;
            found = i;
        }
    }
    if (found < 0)
        return 0;
    *index = found;
    return 1;
}

void ts_excitation_describe(const ts_excitation *ex, int i, char *buf,
                            size_t size)
{
    ts_excitation_describe_display(ex, i, NULL, buf, size);
}

void ts_excitation_describe_display(const ts_excitation *ex, int i,
                                    const ts_display *d, char *buf,
                                    size_t size)
{
    const ts_signal *s = &ex->sig[i];
    d = ts_display_or_si(d);
    const char *an = ts_signal_axis_label(s);
    /* The amplitude's quantity; an input of no unit of its own stays as
     * given. */
    int q = is_rot_axis(s->axis)              ? TS_QTY_ANGLE
            : is_tow_axis(s->axis)            ? TS_QTY_LENGTH
            : s->axis == TS_AXIS_SPEED        ? TS_QTY_SPEED
            : s->axis == TS_AXIS_TURN_RATE    ? TS_QTY_ANGULAR_RATE
            : !strcmp(s->input_unit, "m")     ? TS_QTY_LENGTH
            : !strcmp(s->input_unit, "rad")   ? TS_QTY_ANGLE
                                              : -1;
    const char *u = q >= 0 ? ts_display_unit(d, (ts_quantity)q) : "(SI)";
    double ka = q >= 0 ? ts_display_value(d, (ts_quantity)q, 1.0) : 1.0;
    double kl = ts_display_value(d, TS_QTY_LENGTH, 1.0);
    double kt = ts_display_value(d, TS_QTY_TIME, 1.0);
    double kf = ts_display_value(d, TS_QTY_FREQUENCY, 1.0);
    const char *lu = ts_display_unit(d, TS_QTY_LENGTH);
    const char *tu = ts_display_unit(d, TS_QTY_TIME);
    const char *fu = ts_display_unit(d, TS_QTY_FREQUENCY);
    const char *pu = ts_display_unit(d, TS_QTY_ANGLE);
    double phase = ts_display_value(d, TS_QTY_ANGLE, s->phase);
    const char *what = s->absolute ? "to" : !is_manoeuvre(s->axis)
                                                ? "amplitude" : "by";
    switch (s->type) {
    case TS_SIGNAL_SINE:
    case TS_SIGNAL_CRANK: {
        char start[96];
        if (s->ramp > 0)
            snprintf(start, sizeof start, "smooth start over %.6g %s (%.3g "
                     "periods)", kt * s->ramp, tu, s->ramp * s->frequency);
        else
            snprintf(start, sizeof start, "impulsive start");
        if (s->type == TS_SIGNAL_SINE)
            snprintf(buf, size, "%s sine amplitude %.6g %s, frequency "
                     "%.6g %s, phase %.6g %s, %s", an, ka * s->amplitude, u,
                     kf * s->frequency, fu, phase, pu, start);
        else
            snprintf(buf, size, "%s slider crank radius %.6g %s, rod %.6g "
                     "%s, frequency %.6g %s, phase %.6g %s, %s", an,
                     kl * s->amplitude, lu, kl * s->rod, lu,
                     kf * s->frequency, fu, phase, pu, start);
        return;
    }
    case TS_SIGNAL_STEP:
        snprintf(buf, size, "%s step %s %.6g %s at %.6g %s, rise %.6g %s", an,
                 what, ka * s->amplitude, u, kt * s->start, tu, kt * s->rise,
                 tu);
        return;
    case TS_SIGNAL_RAMP:
        snprintf(buf, size, "%s ramp %s %.6g %s from %.6g %s over %.6g %s, "
                 "corners %.6g %s", an, what, ka * s->amplitude, u,
                 kt * s->start, tu, kt * s->duration, tu, kt * s->rise, tu);
        return;
    case TS_SIGNAL_SERIES:
        snprintf(buf, size, "%s series (cubic spline) on [%.6g, %.6g] %s, "
                 "spacing >= %.6g %s", an, kt * s->start,
                 kt * (s->start + s->duration), tu, kt * ex->series_dt[i],
                 tu);
        return;
    case TS_SIGNAL_SUM:
        snprintf(buf, size, "%s sum of %d sinusoids up to %.6g %s, rms %.6g "
                 "%s, fade-in %.6g %s", an, ex->sum[i]->n,
                 kf * s->frequency, fu, kl * s->amplitude, lu, kt * s->rise,
                 tu);
        return;
    }
    snprintf(buf, size, "%s ?", an);
}
