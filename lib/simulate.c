/* simulate.c: nonlinear and linear time-domain simulation
 * (towstab/simulate.h; doc/simulate.md).
 *
 * Nonlinear. GSL odeiv2 integrates y' = f(t, y) = kernel(y, u(t)) with the
 * frame of time t (ts_excitation_frame: speed, turn rate, their rates, the
 * current rotated into M). A GSL driver owns the stepper, the standard
 * error control (|err_i| <= abs_tol + rel_tol |y_i|) and the evolve object;
 * we call gsl_odeiv2_evolve_apply ourselves, one accepted step at a time,
 * so that after each step we can
 *   - re-chart links whose |cos theta2| fell below the threshold
 *     (ts_kernel_rechart) and restart the stepper (gsl_odeiv2_driver_reset:
 *     multistep histories and FSAL derivatives refer to the old numbers);
 *   - stop exactly at output times and excitation breakpoints (the target
 *     of evolve_apply), so no step straddles a kink of u(t);
 *   - enforce h_min, the step limit and finiteness.
 * The right-hand side returns GSL_FAILURE when the kernel refuses a trial
 * state near the chart singularity (TS_CHART): evolve then retries with a
 * smaller step. A fatal kernel error returns GSL_EBADFUNC, which evolve
 * passes straight back. Implicit steppers get df/dy from ts_linearize
 * (central differences through the kernel, O(nlinks^2)); df/dt, used by
 * bsimp only, is a central difference of f in time.
 *
 * The integrator esdirk is not GSL's: SUNDIALS ARKODE's L-stable ESDIRK
 * 5(4) (lib/esdirk.h), with the same Jacobian, the kernel's refusals
 * passed on as recoverable failures, re-initialised after a re-chart. Its
 * steps stop at breakpoints but not at output times: cutting a step
 * changes gamma h and costs a new LU of I - gamma h J; an output inside a
 * step is
 * ARKODE's interpolant, and re-charting waits for the step's end, after
 * the outputs before it, so that every output is in the charts it was
 * computed in.
 *
 * Linear, exact discretisation (Van Loan 1978, "Computing integrals
 * involving the matrix exponential", IEEE TAC 23(3)). On a step of length
 * h the input v(t) = u(t) - u0 is replaced by the cubic through its values
 * at t + {0, 1/3, 2/3, 1} h, v(t + s) = p0 + p1 s + p2 s^2/2 + p3 s^3/6.
 * Then z(t + h) = Phi z(t) + sum_k G_k p_k exactly, where Phi and G_k are
 * the top blocks of exp(M h), M = [[A, B, 0, 0, 0], [0, 0, I, 0, 0],
 * [0, 0, 0, I, 0], [0, 0, 0, 0, I], [0, 0, 0, 0, 0]] (order n + 4 m, m = 9).
 * The only error is the input interpolation: for a harmonic of angular
 * frequency w it is below 5.1e-4 (w h)^4 of its amplitude (the
 * interpolation remainder w^4/4! max|prod (s - s_j)|, max 0.01227 h^4), so
 * h is chosen as tau (rel_tol / 5.1e-4)^(1/4), tau the excitation's
 * shortest time scale, and at most the output interval. Each distinct h
 * costs one exponential (two at most per run: the regular interval and a
 * shorter last one).
 *
 * One module, though long: the nonlinear and the linear runs share the
 * options, the sampling into a history, the step checks, the re-charting
 * and the statistics.
 */
#include "towstab/simulate.h"

#include <float.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "descriptor.h"
#include "esdirk.h"
#include "expm.h"
#include "kernel_impl.h"
#include "lazylib.h"
#include "shift.h"

/* Interpolation error constant of the cubic input hold (see above). */
#define CUBIC_HOLD_ERR 5.1e-4
/* Relative slack when deciding that t_end is a multiple of dt_sample. */
#define SAMPLE_RTOL 1e-9
/* Relative time step of the df/dt central difference (bsimp), times the
 * excitation's time scale (capped at 1 s). */
#define DFDT_REL_STEP 6e-6

void ts_sim_opts_default(ts_sim_opts *o)
{
    o->integrator = TS_INT_RK8PD;
    o->t_end = 10.0;
    o->dt_sample = 0.1;
    o->rel_tol = 1e-6;
    o->abs_tol = 1e-9;
    o->h_init = 1e-3;
    o->h_min = 0.0;
    o->max_steps = 0;
    o->rechart = TS_CHART_RECHART;
    o->linear_method = TS_LINSIM_EXPM;
    o->kinematics = TS_KIN_LINEAR;
    o->jacobian_threads = 1;
    o->progress = NULL;
    o->progress_data = NULL;
}

static const char *const integrator_names[] = {"rk8pd", "rkf45", "rk4imp",
                                               "bsimp", "msbdf", "esdirk",
                                               "bdf"};

/* The SUNDIALS steppers of lib/esdirk.h (ARKODE's ESDIRK, CVODE's BDF). */
static int sundials_method(ts_integrator m)
{
    return m == TS_INT_ESDIRK || m == TS_INT_BDF;
}

const char *ts_integrator_name(ts_integrator m)
{
    return m >= TS_INT_RK8PD && m <= TS_INT_BDF ? integrator_names[m] : "?";
}

int ts_integrator_parse(const char *name, ts_integrator *m)
{
    for (int i = 0; i <= TS_INT_BDF; i++)
        if (!strcmp(name, integrator_names[i])) {
            *m = (ts_integrator)i;
            return 0;
        }
    return -1;
}

int ts_sim_opts_check(const ts_sim_opts *o, ts_err *err)
{
    if (!(o->t_end > 0) || !isfinite(o->t_end))
        return ts_fail(err, TS_EINVAL, "simulate: t_end must be > 0 s, got "
                       "%g s", o->t_end);
    if (!(o->dt_sample > 0) || !isfinite(o->dt_sample))
        return ts_fail(err, TS_EINVAL, "simulate: the sample interval must "
                       "be > 0 s, got %g s", o->dt_sample);
    if (o->dt_sample > o->t_end * (1.0 + SAMPLE_RTOL))
        return ts_fail(err, TS_EINVAL, "simulate: the sample interval %g s "
                       "is longer than the run (t_end %g s)", o->dt_sample,
                       o->t_end);
    if (o->t_end / o->dt_sample > 1e8)
        return ts_fail(err, TS_EINVAL, "simulate: %g samples (t_end %g s / "
                       "interval %g s) is more than 1e8", o->t_end /
                       o->dt_sample, o->t_end, o->dt_sample);
    if (!(o->rel_tol >= TS_SIM_RTOL_MIN) || !(o->rel_tol < 1))
        return ts_fail(err, TS_EINVAL, "simulate: the relative tolerance "
                       "must be in [%g, 1), got %g", TS_SIM_RTOL_MIN,
                       o->rel_tol);
    if (!(o->abs_tol > 0) || !isfinite(o->abs_tol))
        return ts_fail(err, TS_EINVAL, "simulate: the absolute tolerance "
                       "must be > 0, got %g", o->abs_tol);
    if (!(o->h_init > 0) || !isfinite(o->h_init))
        return ts_fail(err, TS_EINVAL, "simulate: the first step must be > 0 "
                       "s, got %g s", o->h_init);
    if (!(o->h_min >= 0) || !isfinite(o->h_min))
        return ts_fail(err, TS_EINVAL, "simulate: h_min must be >= 0 s, got "
                       "%g s", o->h_min);
    if (o->max_steps < 0)
        return ts_fail(err, TS_EINVAL, "simulate: max_steps must be >= 0, "
                       "got %ld", o->max_steps);
    if (!(o->rechart > TS_CHART_MIN) || !(o->rechart < 1))
        return ts_fail(err, TS_EINVAL, "simulate: the re-chart threshold "
                       "must be in (%g, 1), got %g", TS_CHART_MIN, o->rechart);
    if (!(o->integrator >= TS_INT_RK8PD && o->integrator <= TS_INT_BDF))
        return ts_fail(err, TS_EINVAL, "simulate: unknown integrator %d",
                       (int)o->integrator);
    if (o->linear_method != TS_LINSIM_EXPM &&
        o->linear_method != TS_LINSIM_ODE &&
        o->linear_method != TS_LINSIM_SPARSE)
        return ts_fail(err, TS_EINVAL, "simulate: unknown linear method %d",
                       (int)o->linear_method);
    if (o->kinematics != TS_KIN_LINEAR && o->kinematics != TS_KIN_NONLINEAR)
        return ts_fail(err, TS_EINVAL, "simulate: unknown kinematics %d",
                       (int)o->kinematics);
    return TS_OK;
}

int ts_sim_nsamples(const ts_sim_opts *o)
{
    double r = o->t_end / o->dt_sample;
    return (int)ceil(r - SAMPLE_RTOL * r) + 1;
}

double ts_sim_sample_time(const ts_sim_opts *o, int i)
{
    int last = ts_sim_nsamples(o) - 1;
    if (i >= last)
        return o->t_end;
    return i * o->dt_sample;
}

/* ------------------------------------------------------------------ */
/* History                                                              */

ts_history *ts_history_alloc(const ts_system *sys, int capacity, ts_err *err)
{
    if (capacity < 1) {
        ts_fail(err, TS_EINVAL, "ts_history_alloc: capacity must be >= 1, "
                "got %d", capacity);
        return NULL;
    }
    ts_history *h = calloc(1, sizeof *h);
    if (!h)
        goto nomem;
    size_t c = (size_t)capacity;
    h->nnodes = sys->nnodes;
    h->nlinks = sys->nlinks;
    h->capacity = capacity;
    h->t = malloc(c * sizeof(double));
    h->positions = malloc(c * 3 * (size_t)sys->nnodes * sizeof(double));
    h->tensions = malloc(c * (size_t)sys->nlinks * sizeof(double));
    h->tow_force = malloc(c * 3 * sizeof(double));
    h->energy = malloc(c * 2 * sizeof(double));
    h->input = malloc(c * TS_NINPUT * sizeof(double));
    h->frame = malloc(c * 3 * sizeof(double));
    if (!h->t || !h->positions || !h->tensions || !h->tow_force ||
        !h->energy || !h->input || !h->frame)
        goto nomem;
    for (size_t i = 0; i < 3 * c; i++)
        h->frame[i] = NAN;
    return h;
nomem:
    ts_history_free(h);
    ts_fail_nomem(err, 8.0 * capacity * (3.0 + 3.0 * sys->nnodes +
                                         sys->nlinks + TS_NINPUT),
                  "a coarser sample interval, a shorter t_end or fewer links",
                  "simulate: out of memory for a history of %d samples of "
                  "%d nodes", capacity, sys->nnodes);
    return NULL;
}

/* One array of h grown from `old` to `c` samples of `width` values each
 * (the new part NaN when `nan`); 0, or -1 with *a unchanged. */
static int grow(double **a, size_t old, size_t c, size_t width, int nan)
{
    if (!*a)
        return 0;
    double *p = realloc(*a, c * width * sizeof(double));
    if (!p)
        return -1;
    for (size_t i = old * width; nan && i < c * width; i++)
        p[i] = NAN;
    *a = p;
    return 0;
}

/* Room in h for one more sample: the arrays are doubled when full, so
 * that a history holds what a run reached, not what it may reach. */
static int history_reserve(ts_history *h, ts_err *err)
{
    if (h->nsamples < h->capacity)
        return TS_OK;
    size_t old = (size_t)h->capacity;
    size_t c = old < (size_t)INT_MAX / 2 ? 2 * old : (size_t)INT_MAX;
    size_t nn = (size_t)h->nnodes, nl = (size_t)h->nlinks;
    if (c == old ||
        grow(&h->t, old, c, 1, 0) || grow(&h->positions, old, c, 3 * nn, 0) ||
        grow(&h->tensions, old, c, nl, 0) ||
        grow(&h->tow_force, old, c, 3, 0) || grow(&h->energy, old, c, 2, 0) ||
        grow(&h->input, old, c, TS_NINPUT, 0) ||
        grow(&h->frame, old, c, 3, 1) ||
        grow(&h->outputs, old, c, (size_t)h->noutput, 0)) {
        /* The arrays grown so far keep the old samples; the capacity
         * stays that of the smallest. */
        return ts_fail_nomem(err, 8.0 * (double)c * (9.0 + 3.0 * nn + nl +
                                                     TS_NINPUT + h->noutput),
                             "a coarser sample interval, a shorter t_end or "
                             "fewer links",
                             "simulate: out of memory for a history of %zu "
                             "samples of %d nodes", c, h->nnodes);
    }
    h->capacity = (int)c;
    return TS_OK;
}

void ts_history_free(ts_history *h)
{
    if (!h)
        return;
    free(h->t);
    free(h->positions);
    free(h->tensions);
    free(h->tow_force);
    free(h->energy);
    free(h->input);
    free(h->frame);
    free(h->outputs);
    free(h->output_name);
    free(h->output_unit);
    free(h);
}

/* The outputs of the sample being recorded, allocated with their names
 * and units (of kernel k) at the first sample. */
static double *history_outputs(ts_history *h, const ts_kernel *k,
                               ts_err *err)
{
    int no = ts_kernel_noutput(k);
    if (no <= 0)
        return NULL;
    if (!h->outputs) {
        size_t c = (size_t)h->capacity * (size_t)no;
        h->outputs = malloc(c * sizeof(double));
        h->output_name = calloc((size_t)no, sizeof *h->output_name);
        h->output_unit = calloc((size_t)no, sizeof *h->output_unit);
        if (!h->outputs || !h->output_name || !h->output_unit) {
            free(h->outputs);
            h->outputs = NULL;
            ts_fail(err, TS_ENOMEM, "simulate: out of memory for the "
                    "vehicles' outputs over %d samples", h->capacity);
            return NULL;
        }
        h->noutput = no;
        for (int j = 0; j < no; j++) {
            ts_kernel_output_name(k, j, h->output_name[j],
                                  sizeof h->output_name[j]);
            h->output_unit[j] = ts_kernel_output_unit(k, j);
        }
    }
    return h->outputs + (size_t)no * (size_t)h->nsamples;
}

/* What an input's unit measures, for messages. */
static const char *quantity_of(const char *unit)
{
    return !strcmp(unit, "m")     ? "a length (m)"
           : !strcmp(unit, "rad") ? "an angle (rad, deg)"
           : !strcmp(unit, "N")   ? "a force (N)"
           : !strcmp(unit, "N*m") ? "a moment (N*m)"
           : !strcmp(unit, "m/s") ? "a speed (m/s)"
                                  : unit;
}

/* Kernel input indices of the excitation's vehicle-input signals,
 * idx[nsignals] (-1 for the other signals); checks each name and unit
 * against the kernel. NULL (and *idx NULL) without such signals. */
static int bind_inputs(const ts_kernel *k, const ts_excitation *ex,
                       int **idx, ts_err *err)
{
    *idx = NULL;
    int ns = ex ? ts_excitation_nsignals(ex) : 0, any = 0;
    for (int i = 0; i < ns; i++) {
        int axis = ts_excitation_signal(ex, i)->axis;
        any |= axis == TS_AXIS_INPUT;
    }
    if (!any)
        return TS_OK;
    int *x = malloc((size_t)ns * sizeof *x);
    if (!x)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    for (int i = 0; i < ns; i++) {
        const ts_signal *sg = ts_excitation_signal(ex, i);
        x[i] = -1;
        if (sg->axis != TS_AXIS_INPUT)
            continue;
        int j = ts_kernel_input_find(k, sg->input);
        if (j < TS_NINPUT) {
            char list[1024] = "", buf[TS_IO_NAME];
            for (int c = TS_NINPUT; c < ts_kernel_ninput(k); c++) {
                size_t len = strlen(list);
                snprintf(list + len, sizeof list - len, "%s%s",
                         len ? ", " : "",
                         ts_kernel_input_name(k, c, buf, sizeof buf));
            }
            free(x);
            return ts_fail(err, TS_EINVAL, "excite: '%.80s' is not a "
                           "vehicle's input; expected %s", sg->input,
                           list[0] ? list : "(none: the scene has no "
                           "vehicle with control surfaces or loops)");
        }
        const char *unit = ts_kernel_input_unit(k, j);
        if (sg->input_unit[0] && strcmp(sg->input_unit, unit)) {
            free(x);
            return ts_fail(err, TS_EUNIT, "excite: %.80s: the amplitude is "
                           "%s, expected %s", sg->input,
                           quantity_of(sg->input_unit), quantity_of(unit));
        }
        x[i] = j;
    }
    *idx = x;
    return TS_OK;
}

int ts_sim_check_inputs(const ts_kernel *k, const ts_excitation *ex,
                        ts_err *err)
{
    int *idx;
    int rc = bind_inputs(k, ex, &idx, err);
    free(idx);
    return rc;
}

int ts_sim_check_linear_manoeuvre(const ts_kernel *k,
                                  const ts_excitation *ex, ts_err *err)
{
    if (!ex || !ts_excitation_has_manoeuvre(ex))
        return TS_OK;
    if (ts_kernel_root(k) >= 0)
        return ts_fail(err, TS_EINVAL, "manoeuvre: the mean frame is the "
                       "towing vehicle's own steady motion, which its "
                       "thrust, rudder and loops set; the linear model "
                       "takes no frame manoeuvre with a towing vehicle "
                       "(excite its inputs instead)");
    ts_frame f;
    ts_kernel_get_frame(k, &f);
    for (int i = 0; i < ts_excitation_nsignals(ex); i++)
        if (ts_excitation_signal(ex, i)->axis == TS_AXIS_TURN_RATE &&
            (f.current[0] != 0 || f.current[1] != 0))
            return ts_fail(err, TS_EINVAL, "manoeuvre: a turn-rate change "
                           "turns the horizontal current (%g, %g m/s) in "
                           "the mean frame by the heading change, without "
                           "bound; the linear model has no heading state "
                           "(simulate it nonlinearly)", f.current[0],
                           f.current[1]);
    return TS_OK;
}

/* Add the vehicle-input signals at t into u[ninput] (idx from
 * bind_inputs; nothing when NULL). */
static void add_inputs(const ts_excitation *ex, const int *idx, double t,
                       double *u)
{
    for (int i = 0; idx && i < ts_excitation_nsignals(ex); i++)
        if (idx[i] >= 0)
            u[idx[i]] += ts_excitation_value(ex, i, t);
}

double ts_history_value(const ts_system *sys, const ts_history *h,
                        const ts_output *out, int i)
{
    if (i < 0 || i >= h->nsamples)
        return NAN;
    size_t s = (size_t)i;
    if (out->kind == TS_OUT_EARTH) {
        /* (x, y, 0) + Rz(psi) r of the node's position r in M. */
        const double *r = h->positions + 3 * ((size_t)h->nnodes * s +
                                              (size_t)out->node);
        const double *f = h->frame + 3 * s;
        double c = cos(f[2]), sn = sin(f[2]);
        return out->comp == 0 ? f[0] + c * r[0] - sn * r[1]
                              : f[1] + sn * r[0] + c * r[1];
    }
    if (out->kind == TS_OUT_VEHICLE)
        return h->outputs && out->index >= 0 && out->index < h->noutput
                   ? h->outputs[(size_t)h->noutput * s + (size_t)out->index]
                   : NAN;
    return ts_output_value(sys, out, h->positions + 3 * (size_t)h->nnodes * s,
                           h->tensions + (size_t)h->nlinks * s,
                           h->tow_force + 3 * s);
}

/* ------------------------------------------------------------------ */
/* Nonlinear simulator                                                  */

struct ts_sim {
    ts_kernel *k;
    const ts_system *sys;
    const ts_excitation *ex;
    ts_sim_opts o;
    ts_frame orig;        /* the kernel's frame at alloc, restored at free */
    ts_frame base;        /* the same with zero rates: the frame of t = 0 */
    ts_excitation *own_ex;/* an empty excitation when the caller gave none */
    int frame_varies;     /* the frame changes with time */
    int n, nq, nl;
    double t, h;
    double *y;            /* [n] */
    double *work;         /* [3 n]: kernel output and df/dt differences */
    double *u;            /* [ninput] the kernel's input at the time of the
                             last prepare(): the tow channels and the
                             vehicles' inputs from the excitation */
    int ninput;
    int *in_idx;          /* [nsignals] bind_inputs; NULL: none */
    double *breaks;       /* [nbreaks] */
    int nbreaks;
    double dfdt_step;
    gsl_odeiv2_system gsys;
    gsl_odeiv2_driver *drv; /* GSL integrators */
    tsi_esdirk *sd;         /* esdirk (drv is NULL) */
    int ahead;              /* esdirk has stepped to t_int > t */
    double t_int;
    double *y_int;          /* [n] esdirk's state at t_int */
    ts_linear *lin;       /* Jacobian (implicit methods; sparse model for
                             esdirk) */
    tsi_shift sh;         /* esdirk: factored S(1 / gamma) */
    ts_newton_matrix newton; /* the Newton matrix the method makes */
    ts_linearize_opts lopts;
    /* Statistics: evolve's counters are added in at each reset. */
    long steps0, rejected0, nfev, njac, nrechart, nrestart;
    double wall;
    int fatal;            /* a kernel code < 0 met inside GSL */
    long chart_refusals;  /* TS_CHART from trial states */
    long collapse_refusals; /* trial states with an elastic link of zero
                             or negative length (strain <= -1) */
    double t_start;       /* time of the last ts_sim_set_state */
    long steps_start;     /* accepted steps before it */
    double *hold;         /* [ninput] held inputs added to the excitation's
                             (the waypoint autopilot's rudder), or NULL */
    double t_hold;        /* the next autopilot update: a stop of the
                             integrator (INFINITY: none) */
};

static int needs_jacobian(ts_integrator m);

/* Accepted steps since the last restart of the GSL driver, or in all
 * (esdirk keeps its own count across restarts). */
static long steps_now(const ts_sim *s)
{
    if (s->sd) {
        tsi_esdirk_stats st;
        tsi_esdirk_get_stats(s->sd, &st);
        return st.steps;
    }
    return s->steps0 + (long)s->drv->e->count;
}

/* 1 when state y has an elastic link of zero or negative length. */
static int collapsed(const ts_sim *s, const double y[])
{
    for (int l = 0; l < s->sys->nlinks; l++)
        if (s->sys->links[l].elastic &&
            !(y[ts_kernel_link_offset(s->k, l) + 2] > -1.0))
            return 1;
    return 0;
}

/* The shortest axial period of the elastic links, pi sqrt(l m / EA) (s;
 * the highest mode of a spring-mass chain of links of length l and mass m
 * is at most 2 sqrt(EA / (l m)) rad/s, doc/elastic.md), and the link that
 * sets it in *which; INFINITY without elastic links. */
static double axial_period(const ts_system *sys, int *which)
{
    double best = INFINITY;
    *which = -1;
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        if (!L->elastic || !(L->mass > 0))
            continue;
        double p = M_PI * sqrt(L->length * L->mass / L->ea);
        if (p < best) {
            best = p;
            *which = l;
        }
    }
    return best;
}

/* After a failed run of an explicit integrator on a scene with elastic
 * links: append to err's message the step the integrator needed (its
 * last step and its mean step) against the shortest axial period, and
 * name stiffness and the implicit integrator. */
static void stiffness_note(const ts_sim *s, ts_err *err)
{
    int l;
    double per = axial_period(s->sys, &l);
    if (!err || needs_jacobian(s->o.integrator) || l < 0)
        return;
    long steps = steps_now(s) - s->steps_start;
    double mean = steps > 0 ? (s->t - s->t_start) / (double)steps : NAN;
    size_t len = strlen(err->msg);
    snprintf(err->msg + len, sizeof err->msg - len, "; %s needed steps of "
             "%.2g s (last accepted %.2g s, mean %.2g s over %ld steps) "
             "against a shortest axial period of the elastic links of "
             "%.2g s (link %d of cable '%s'): the system is stiff, use "
             "--integrator esdirk", ts_integrator_name(s->o.integrator),
             fabs(s->h), s->drv->e->last_step, mean, steps, per,
             s->sys->links[l].index, s->sys->cables[s->sys->links[l].cable].name);
}

/* Frame and input of time t into the kernel; u[ninput] (s->u): the tow
 * channels and the vehicles' inputs. */
static void prepare(ts_sim *s, double t, double *u)
{
    ts_excitation_input(s->ex, t, u);
    if (s->in_idx || s->hold) {
        for (int j = TS_NINPUT; j < s->ninput; j++)
            u[j] = s->hold ? s->hold[j] : 0.0;
        if (s->in_idx)
            add_inputs(s->ex, s->in_idx, t, u);
    }
    if (s->frame_varies) {
        ts_frame f;
        ts_excitation_frame(s->ex, &s->base, t, &f);
        ts_kernel_set_frame(s->k, &f);
    }
}

static int rhs(double t, const double y[], double dydt[], void *params)
{
    ts_sim *s = params;
    double *u = s->u;
    s->nfev++;
    prepare(s, t, u);
    int rc = ts_kernel_eval(s->k, y, u, dydt);
    if (rc == TS_OK)
        return GSL_SUCCESS;
    if (rc > 0) {
        s->chart_refusals++;
        return GSL_FAILURE; /* evolve retries with a smaller step */
    }
    if (rc == TS_ESINGULAR && collapsed(s, y)) {
        /* A trial state of a step too long for a stiff elastic link: not
         * fatal, evolve retries with a smaller step. */
        s->collapse_refusals++;
        return GSL_FAILURE;
    }
    s->fatal = rc;
    return GSL_EBADFUNC;
}

/* df/dy at (t, y) into s->lin->A (column-major): GSL_SUCCESS,
 * GSL_FAILURE (a refused state) or GSL_EBADFUNC (fatal). */
static int linearize_at(ts_sim *s, double t, const double y[])
{
    double *u = s->u;
    s->njac++;
    prepare(s, t, u);
    int rc = ts_linearize(s->k, y, u, &s->lopts, s->lin, NULL);
    s->nfev += s->lin->evaluations + s->lin->residual_evaluations;
    if (rc > 0) {
        s->chart_refusals++;
        return GSL_FAILURE;
    }
    if (rc < 0) {
        s->fatal = rc;
        return GSL_EBADFUNC;
    }
    return GSL_SUCCESS;
}

static int jacobian(double t, const double y[], double *dfdy, double dfdt[],
                    void *params)
{
    ts_sim *s = params;
    int n = s->n, rc = linearize_at(s, t, y);
    if (rc != GSL_SUCCESS)
        return rc;
    const double *A = s->lin->A;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            dfdy[(size_t)i * n + j] = A[i + (size_t)j * n];
    if (s->o.integrator != TS_INT_BSIMP) {
        for (int i = 0; i < n; i++)
            dfdt[i] = 0.0; /* unused by rk4imp and msbdf */
        return GSL_SUCCESS;
    }
    double dt = s->dfdt_step, *fp = s->work + n, *fm = s->work + 2 * n;
    int r1 = rhs(t + dt, y, fp, s), r2 = rhs(t - dt, y, fm, s);
    if (r1 != GSL_SUCCESS)
        return r1;
    if (r2 != GSL_SUCCESS)
        return r2;
    for (int i = 0; i < n; i++)
        dfdt[i] = (fp[i] - fm[i]) / (2.0 * dt);
    return GSL_SUCCESS;
}

/* GSL's return codes as lib/esdirk.h's: 0, > 0 retry, < 0 fatal. */
static int esdirk_code(int gsl_rc)
{
    return gsl_rc == GSL_SUCCESS ? 0 : (gsl_rc == GSL_FAILURE ? 1 : -1);
}

static int rhs_esdirk(double t, const double y[], double dydt[], void *params)
{
    return esdirk_code(rhs(t, y, dydt, params));
}

/* esdirk's dense Jacobian, where the sparse model does not cover the
 * system (the descriptor could not be laid out). */
static int jacobian_esdirk(double t, const double y[], double J[],
                           void *params)
{
    ts_sim *s = params;
    int rc = linearize_at(s, t, y);
    if (rc == GSL_SUCCESS)
        memcpy(J, s->lin->A, (size_t)s->n * (size_t)s->n * sizeof(double));
    return esdirk_code(rc);
}

/* esdirk's Newton matrix I - gamma J from the sparse model (lib/shift.h):
 * J re-evaluated unless ARKODE says the last one will do, then S(1 /
 * gamma) factored, O(nlinks) each. */
static int lsys_setup_esdirk(double t, const double y[], double gamma,
                             int jok, int *jcur, void *params)
{
    ts_sim *s = params;
    if (!jok || !s->lin->desc) {
        int rc = linearize_at(s, t, y);
        if (rc != GSL_SUCCESS)
            return esdirk_code(rc);
        *jcur = 1;
    }
    if (s->sh.numeric)
        tsi_shift_free(&s->sh);
    int rc = tsi_shift_factor(&s->sh, s->lin, 1.0 / gamma, NULL);
    if (rc == TS_ESINGULAR)
        return 1; /* ARKODE retries with another step */
    return rc == TS_OK ? 0 : -1;
}

/* x[n] = (I - gamma J)^-1 b = s (s I - J)^-1 b with s = 1 / gamma, the
 * shift sh is factored at, and tsi_shift_solve_real gives (J - s I)^-1. */
static int newton_solve(tsi_shift *sh, int n, const double b[], double x[])
{
    double s = creal(sh->s);
    tsi_shift_solve_real(sh, b, x);
    for (int i = 0; i < n; i++)
        x[i] *= -s;
    return 0;
}

static int lsys_solve_esdirk(double x[], const double b[], void *params)
{
    ts_sim *s = params;
    return newton_solve(&s->sh, s->n, b, x);
}

static const gsl_odeiv2_step_type *step_type(ts_integrator m)
{
    switch (m) {
    case TS_INT_RKF45: return gsl_odeiv2_step_rkf45;
    case TS_INT_RK4IMP: return gsl_odeiv2_step_rk4imp;
    case TS_INT_BSIMP: return gsl_odeiv2_step_bsimp;
    case TS_INT_MSBDF: return gsl_odeiv2_step_msbdf;
    default: return gsl_odeiv2_step_rk8pd;
    }
}

static int needs_jacobian(ts_integrator m)
{
    return m == TS_INT_RK4IMP || m == TS_INT_BSIMP || m == TS_INT_MSBDF ||
           sundials_method(m);
}

void ts_sim_free(ts_sim *s)
{
    if (!s)
        return;
    if (s->k)
        ts_kernel_set_frame(s->k, &s->orig);
    ts_excitation_free(s->own_ex);
    if (s->drv)
        gsl_odeiv2_driver_free(s->drv);
    tsi_esdirk_free(s->sd);
    if (s->sh.numeric)
        tsi_shift_free(&s->sh);
    ts_linear_free(s->lin);
    free(s->y);
    free(s->y_int);
    free(s->work);
    free(s->u);
    free(s->hold);
    free(s->in_idx);
    free(s->breaks);
    free(s);
}

ts_sim *ts_sim_alloc(ts_kernel *k, const ts_excitation *ex,
                     const ts_sim_opts *o, ts_err *err)
{
    if (ts_sim_opts_check(o, err))
        return NULL;
    /* Loads that overflow under the excitation's motion are the input's
     * fault: refuse them before a single step, naming the input (a step
     * size would otherwise shrink towards zero chasing them). */
    ts_frame f0;
    ts_motion_bound mb;
    ts_kernel_get_frame(k, &f0);
    ts_excitation_bound(ex, &f0, &mb);
    if (ts_system_check_loads(ts_kernel_system(k), &mb, err) != TS_OK) {
        ts_err_prefix(err, "simulate: ");
        return NULL;
    }
    ts_sim *s = calloc(1, sizeof *s);
    if (!s) {
        ts_fail(err, TS_ENOMEM, "simulate: out of memory");
        return NULL;
    }
    s->k = k;
    s->sys = ts_kernel_system(k);
    s->o = *o;
    ts_kernel_get_frame(k, &s->orig);
    s->base = s->orig;
    s->base.speed_rate = 0.0;
    s->base.turn_accel = 0.0;
    if (!ex) {
        /* Without signals the frame may still vary: a current rotates in
         * M during a steady turn. */
        s->own_ex = ts_excitation_alloc(err);
        if (!s->own_ex) {
            free(s);
            return NULL;
        }
        ex = s->own_ex;
    }
    s->ex = ex;
    s->n = ts_kernel_nstate(k);
    s->nq = ts_kernel_nq(k);
    s->nl = ts_kernel_system(k)->nlinks;
    int cur = s->base.current[0] != 0 || s->base.current[1] != 0;
    s->frame_varies = ts_excitation_has_manoeuvre(ex) ||
                      (s->base.turn_rate != 0 && cur);
    s->h = o->h_init > o->h_min ? o->h_init : o->h_min;
    double tau = ts_excitation_time_scale(ex);
    s->dfdt_step = DFDT_REL_STEP * (tau < 1.0 ? tau : 1.0);
    size_t n = (size_t)s->n;
    s->y = calloc(n, sizeof(double));
    s->work = calloc(3 * n, sizeof(double));
    s->ninput = ts_kernel_ninput(k);
    s->u = calloc((size_t)s->ninput, sizeof(double));
    s->t_hold = INFINITY;
    int nb = ts_excitation_breakpoints(ex, o->t_end, NULL, 0);
    s->breaks = malloc((size_t)(nb + 1) * sizeof(double));
    if (!s->y || !s->work || !s->breaks || !s->u)
        goto nomem;
    s->nbreaks = ts_excitation_breakpoints(ex, o->t_end, s->breaks, nb);
    if (bind_inputs(k, ex, &s->in_idx, err)) {
        ts_sim_free(s);
        return NULL;
    }
    int sparse = 0;
    if (needs_jacobian(o->integrator)) {
        s->lin = ts_linear_alloc(k, err);
        if (!s->lin) {
            ts_sim_free(s);
            return NULL;
        }
        ts_linearize_opts_default(&s->lopts);
        s->lopts.estimate_error = 0;
        s->lopts.threads = o->jacobian_threads;
        /* GSL's implicit steppers take a dense Jacobian; esdirk and bdf
         * solve with the sparse model where it covers the system: towed
         * and towing vehicles and their controllers too. Its descriptor
         * is laid out here, once, for the linear model to keep; one that
         * cannot be (TS_EINVAL) leaves the dense model. */
        if (sundials_method(o->integrator)) {
            ts_err derr = {0};
            s->lin->desc = tsi_desc_alloc(k, &derr);
            sparse = s->lin->desc != NULL;
        }
        s->lopts.model = sparse ? TS_LIN_SPARSE : TS_LIN_DENSE;
        s->newton = sparse ? TS_NEWTON_SPARSE : TS_NEWTON_DENSE;
    }
    if (sundials_method(o->integrator)) {
        const tsi_ode_lsys lsys = {lsys_setup_esdirk, lsys_solve_esdirk,
                                   0};
        s->sd = tsi_esdirk_alloc_method(
            s->n, rhs_esdirk, sparse ? NULL : jacobian_esdirk,
            sparse ? &lsys : NULL, s, o->rel_tol, o->abs_tol, s->h,
            o->integrator == TS_INT_BDF, err);
        if (!s->sd) {
            ts_sim_free(s);
            return NULL;
        }
        if (!(s->y_int = calloc(n, sizeof(double))))
            goto nomem;
        return s;
    }
    s->gsys.function = rhs;
    s->gsys.jacobian = needs_jacobian(o->integrator) ? jacobian : NULL;
    s->gsys.dimension = n;
    s->gsys.params = s;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    s->drv = gsl_odeiv2_driver_alloc_y_new(&s->gsys, step_type(o->integrator),
                                           s->h, o->abs_tol, o->rel_tol);
    gsl_set_error_handler(old);
    if (!s->drv)
        goto nomem;
    return s;
nomem:
    ts_sim_free(s);
    ts_fail_nomem(err, 8.0 * (double)n * (needs_jacobian(o->integrator)
                                             ? (double)n + 10 : 10.0),
                  needs_jacobian(o->integrator)
                      ? "fewer links, or an explicit integrator (rk8pd)"
                      : "fewer links",
                  "simulate: out of memory for the integrator of %d states",
                  (int)n);
    return NULL;
}

/* Restart the integrator (after re-charting or a new state). */
static int restart(ts_sim *s, ts_err *err)
{
    s->ahead = 0;
    if (s->sd)
        return tsi_esdirk_reset(s->sd, s->t, s->y, err);
    s->steps0 += (long)s->drv->e->count;
    s->rejected0 += (long)s->drv->e->failed_steps;
    gsl_odeiv2_driver_reset(s->drv);
    return TS_OK;
}

/* Re-chart links near the singularity; 1 when any moved. */
static int maybe_rechart(ts_sim *s)
{
    int near = 0;
    for (int l = 0; l < s->sys->nlinks && !near; l++)
        near = fabs(cos(s->y[ts_kernel_link_offset(s->k, l) + 1])) <
               s->o.rechart;
    if (!near)
        return 0;
    int moved = ts_kernel_rechart(s->k, s->y, s->o.rechart);
    s->nrechart += moved;
    return moved > 0;
}

int ts_sim_set_state(ts_sim *s, double t, const double y[], ts_err *err)
{
    if (!isfinite(t))
        return ts_fail(err, TS_EINVAL, "simulate: the start time must be "
                       "finite, got %g s", t);
    for (int i = 0; i < s->n; i++)
        if (!isfinite(y[i]))
            return ts_fail(err, TS_EINVAL, "simulate: the initial state has "
                           "a non-finite entry y[%d] = %g", i, y[i]);
    memcpy(s->y, y, (size_t)s->n * sizeof(double));
    s->t = t;
    s->t_start = t;
    maybe_rechart(s);
    int rc = restart(s, err);
    s->steps_start = steps_now(s);
    return rc;
}

double ts_sim_time(const ts_sim *s) { return s->t; }
const double *ts_sim_state(const ts_sim *s) { return s->y; }

void ts_sim_get_stats(const ts_sim *s, ts_sim_stats *st)
{
    if (s->sd) {
        tsi_esdirk_stats sd;
        tsi_esdirk_get_stats(s->sd, &sd);
        st->steps = sd.steps;
        st->rejected = sd.rejected;
        st->h_last = sd.h_last;
    } else {
        st->steps = s->steps0 + (long)s->drv->e->count;
        st->rejected = s->rejected0 + (long)s->drv->e->failed_steps;
        st->h_last = s->drv->e->last_step;
    }
    st->evaluations = s->nfev;
    st->jacobians = s->njac;
    st->newton = s->newton;
    st->recharts = s->nrechart;
    st->restarts = s->nrestart;
    st->t_reached = s->t;
    st->wall_s = s->wall;
}

/* The first excitation breakpoint after the current time and before
 * limit, else limit: where the next step must stop. */
static double next_stop(const ts_sim *s, double limit)
{
    if (s->t_hold > s->t && s->t_hold < limit)
        limit = s->t_hold;
    for (int b = 0; b < s->nbreaks; b++)
        if (s->breaks[b] > s->t && s->breaks[b] < limit)
            return s->breaks[b];
    return limit;
}

static int finite_state(const double y[], int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(y[i]))
            return 0;
    return 1;
}

/* Report progress at simulated time t (run `what`) to the caller's
 * callback: TS_ECANCEL when it asks to stop, else TS_OK. */
static int report_progress(const ts_sim_opts *o, const char *what, double t,
                           ts_err *err)
{
    if (!o->progress)
        return TS_OK;
    ts_progress p = {what, t, o->t_end, "s"};
    if (!o->progress(&p, o->progress_data))
        return TS_OK;
    return ts_fail(err, TS_ECANCEL, "simulate (%s): stopped on request at "
                   "t = %.6g s of %.6g s", what, t, o->t_end);
}

/* A step that failed inside the kernel (fatal) or on the angle chart. */
static int fail_kernel(const ts_sim *s, ts_err *err)
{
    return ts_fail(err, s->fatal ? s->fatal : TS_ESINGULAR, "simulate: the "
                   "kernel failed at t = %.9g s (%s): a nodal mass matrix "
                   "is not positive definite", s->t, ts_strerror(s->fatal));
}

static int fail_chart(const ts_sim *s, ts_err *err)
{
    return ts_fail(err, TS_EINTEGRATOR, "simulate: %s cannot step past "
                   "t = %.9g s: every trial step leaves the angle chart (a "
                   "link turning sideways faster than the re-chart "
                   "threshold %g can follow)",
                   ts_integrator_name(s->o.integrator), s->t, s->o.rechart);
}

/* Checks of an accepted step from t_before to t (state y; step size h,
 * s; towards stop, on the way to the caller's t1; `steps` accepted so
 * far): the step changed t, the state is finite, h is not below h_min
 * unless the step was cut to land on stop, the step limit. TS_OK or
 * TS_EINTEGRATOR naming the integrator. */
static int check_step(const ts_sim *s, double t_before, double t,
                      const double y[], double h, double stop, double t1,
                      long steps, ts_err *err)
{
    const char *name = ts_integrator_name(s->o.integrator);
    if (t == t_before)
        /* t + h == t in floating point: GSL does not catch this one. */
        return ts_fail(err, TS_EINTEGRATOR, "simulate: %s failed at t = "
                       "%.9g s: the step size underflowed (%.3g s is below "
                       "the resolution of t)", name, t, h);
    if (!finite_state(y, s->n))
        return ts_fail(err, TS_EINTEGRATOR, "simulate: %s produced a "
                       "non-finite state at t = %.9g s", name, t);
    if (s->o.h_min > 0 && t < stop && h < s->o.h_min)
        return ts_fail(err, TS_EINTEGRATOR, "simulate: %s failed at t = "
                       "%.9g s: the step size %.3g s fell below h_min %.3g s",
                       name, t, h, s->o.h_min);
    /* The limit counts over the run: reached anywhere before its end (or
     * the caller's target beyond it) it fails, also at an output time. */
    if (s->o.max_steps > 0 && steps >= s->o.max_steps &&
        t < fmax(t1, s->o.t_end))
        return ts_fail(err, TS_EINTEGRATOR, "simulate: %s reached the step "
                       "limit %ld at t = %.9g s", name, s->o.max_steps, t);
    return TS_OK;
}

/* ts_sim_advance for esdirk (see the head of this file): step from the
 * integrator's time towards the next breakpoint or t_end, not t1; hand
 * out the interpolant at t1 when a step passes it. */
static int advance_esdirk(ts_sim *s, double t1, ts_err *err)
{
    const size_t bytes = (size_t)s->n * sizeof(double);
    while (s->t < t1) {
        if (s->ahead) {
            if (s->t_int > t1) {
                int rc = tsi_esdirk_interpolate(s->sd, t1, s->y, err);
                if (!rc)
                    s->t = t1;
                return rc;
            }
            /* Move to the step's end, then re-chart there if needed. */
            s->t = s->t_int;
            memcpy(s->y, s->y_int, bytes);
            s->ahead = 0;
            if (maybe_rechart(s)) {
                int rc = restart(s, err);
                if (rc)
                    return rc;
                s->nrestart++;
            }
            continue;
        }
        double stop = next_stop(s, s->o.t_end > t1 ? s->o.t_end : t1);
        long refusals = s->chart_refusals;
        double t = s->t;
        ts_err esd = {0};
        int failed = tsi_esdirk_step(s->sd, stop, &t, s->y_int, &esd);
        tsi_esdirk_stats sd;
        tsi_esdirk_get_stats(s->sd, &sd);
        s->h = sd.h_next;
        if (failed && s->fatal)
            return fail_kernel(s, err);
        if (failed && s->chart_refusals > refusals)
            return fail_chart(s, err);
        if (failed)
            return ts_fail(err, TS_EINTEGRATOR, "simulate: %s (relative "
                           "tolerance %g, absolute %g)", esd.msg,
                           s->o.rel_tol, s->o.abs_tol);
        int rc = check_step(s, s->t, t, s->y_int, sd.h_last, stop, t1,
                            sd.steps, err);
        if (rc)
            return rc;
        s->t_int = t;
        s->ahead = 1;
        /* Stopping here keeps s->t, the last state handed out. */
        if ((rc = report_progress(&s->o, "nonlinear", t, err)))
            return rc;
    }
    return TS_OK;
}

int ts_sim_advance(ts_sim *s, double t1, ts_err *err)
{
    if (!(t1 > s->t))
        return ts_fail(err, TS_EINVAL, "simulate: the target time %g s is "
                       "not after the current time %g s", t1, s->t);
    if (s->sd) {
        double w0 = tsi_wall_now();
        int rc = advance_esdirk(s, t1, err);
        s->wall += tsi_wall_now() - w0;
        return rc;
    }
    double w0 = tsi_wall_now();
    int rc = TS_OK, step_failed = 0;
    while (s->t < t1) {
        double target = next_stop(s, t1);
        long refusals = s->chart_refusals;
        double t_before = s->t;
        int st = gsl_odeiv2_evolve_apply(s->drv->e, s->drv->c, s->drv->s,
                                         &s->gsys, &s->t, target, &s->h,
                                         s->y);
        if (st == GSL_EBADFUNC) {
            rc = fail_kernel(s, err);
            break;
        }
        if (st != GSL_SUCCESS) {
            if (s->chart_refusals > refusals)
                rc = fail_chart(s, err);
            else
                rc = step_failed = ts_fail(err, TS_EINTEGRATOR, "simulate: "
                             "%s failed at t = %.9g s: the step size "
                             "underflowed (%.3g s) at relative tolerance %g, "
                             "absolute %g; the scene may be stiff (try "
                             "esdirk) or the tolerance too tight",
                             ts_integrator_name(s->o.integrator), s->t, s->h,
                             s->o.rel_tol, s->o.abs_tol);
            break;
        }
        if ((rc = step_failed = check_step(s, t_before, s->t, s->y,
                                           fabs(s->h), target, t1,
                                           steps_now(s), err))) {
            if (!finite_state(s->y, s->n))
                s->t = t_before;
            break;
        }
        if (maybe_rechart(s)) {
            if ((rc = restart(s, err)))
                break;
            s->nrestart++;
        }
        if ((rc = report_progress(&s->o, "nonlinear", s->t, err)))
            break;
    }
    if (step_failed)
        stiffness_note(s, err);
    s->wall += tsi_wall_now() - w0;
    return rc;
}

int ts_sim_record(ts_sim *s, ts_history *h, ts_err *err)
{
    if (h->nnodes != s->sys->nnodes || h->nlinks != s->sys->nlinks)
        return ts_fail(err, TS_EINVAL, "simulate: the history is sized for "
                       "%d links, the system has %d", h->nlinks,
                       s->sys->nlinks);
    int rc = history_reserve(h, err);
    if (rc)
        return rc;
    double *u = s->u;
    prepare(s, s->t, u);
    rc = ts_kernel_eval(s->k, s->y, u, s->work);
    if (rc)
        return ts_fail(err, rc < 0 ? rc : TS_EINTEGRATOR, "simulate: the "
                       "kernel refused the state at t = %.9g s (%s)", s->t,
                       ts_strerror(rc));
    size_t i = (size_t)h->nsamples, nn = (size_t)h->nnodes,
           nl = (size_t)h->nlinks;
    h->t[i] = s->t;
    memcpy(h->positions + 3 * nn * i, ts_kernel_positions(s->k),
           3 * nn * sizeof(double));
    memcpy(h->tensions + nl * i, ts_kernel_tensions(s->k), nl * sizeof(double));
    ts_kernel_tow_force(s->k, h->tow_force + 3 * i);
    h->energy[2 * i] = ts_kernel_kinetic_energy(s->k);
    h->energy[2 * i + 1] = ts_kernel_potential_energy(s->k);
    memcpy(h->input + TS_NINPUT * i, u, TS_NINPUT * sizeof(double));
    if (ts_kernel_noutput(s->k) > 0) {
        double *o = history_outputs(h, s->k, err);
        if (!o)
            return TS_ENOMEM;
        ts_kernel_outputs(s->k, o);
    }
    h->nsamples++;
    return TS_OK;
}

int ts_history_first(const ts_history *h, double t_from)
{
    int first = 0;
    while (first < h->nsamples &&
           h->t[first] < t_from - TS_HISTORY_TIME_EPS)
        first++;
    return first;
}

int ts_history_depth_ranges(const ts_system *sys, const ts_history *h,
                            double t_from, ts_depth_range *out, int max)
{
    int first = ts_history_first(h, t_from);
    int m = 0;
    for (int n = 0; n < sys->nnodes && m < max; n++) {
        int b = sys->nodes[n].body;
        if (b < 0 || b == sys->tow.vehicle)
            continue;
        ts_depth_range *d = &out[m++];
        d->body = b;
        d->min = d->t_min = d->max = d->t_max = NAN;
        for (int i = first; i < h->nsamples; i++) {
            double z = h->positions[(size_t)(3 * h->nnodes) * (size_t)i +
                                    3 * (size_t)n + 2];
            if (!(z >= d->min)) {
                d->min = z;
                d->t_min = h->t[i];
            }
            if (!(z <= d->max)) {
                d->max = z;
                d->t_max = h->t[i];
            }
        }
    }
    return m;
}

/* ------------------------------------------------------------------ */
/* The waypoint autopilot (towstab/guidance.h, doc/guidance.md)          */

typedef struct autopilot {
    const ts_autopilot *ap;
    ts_guidance g;       /* the scene's, its start the run's */
    int index;           /* the target waypoint: the autopilot's state */
    long updates;        /* updates so far: the next is at updates dt */
    int root;            /* the towing vehicle's index among the vehicles */
    const double *attach;/* its tow point in body axes, m */
    int in[TS_AUTOPILOT_MAX_RUDDERS]; /* the rudders' kernel inputs */
} autopilot;

/* The towing vehicle's origin (x, y in E, m) and heading (rad) at the
 * simulator's time and state. M moves at the base frame's speed V and
 * turn rate Omega (the autopilot refuses frame manoeuvres), so its pose is
 * closed: heading Omega t, origin (V sin(Omega t) / Omega,
 * V (1 - cos(Omega t)) / Omega) (towstab/track.h). */
static void ap_pose(const ts_sim *s, const autopilot *a, double xy[2],
                    double *psi)
{
    double R[9], r[2];
    ts_kernel_get_vehicle(s->k, a->root, s->y, R, NULL);
    const double *at = a->attach;
    int off = ts_kernel_root_offset(s->k);
    for (int i = 0; i < 2; i++)
        r[i] = s->y[off + i] -
               (R[3 * i] * at[0] + R[3 * i + 1] * at[1] + R[3 * i + 2] * at[2]);
    double V = s->base.speed, W = s->base.turn_rate, t = s->t, th = W * t;
    double ox = fabs(th) < 1e-6 ? V * t * (1 - th * th / 6)
                                : V * sin(th) / W;
    double oy = fabs(th) < 1e-6 ? V * t * th / 2 * (1 - th * th / 12)
                                : V * (1 - cos(th)) / W;
    double c = cos(th), sn = sin(th);
    xy[0] = ox + c * r[0] - sn * r[1];
    xy[1] = oy + sn * r[0] + c * r[1];
    *psi = th + atan2(R[3], R[0]);
}

/* Bind the scene's autopilot to the simulator: rudder inputs, the start
 * of the path (the vehicle's position at t = 0, checked against the
 * first waypoint), the held inputs. a->ap NULL when the scene has none. */
static int ap_bind(ts_sim *s, const ts_excitation *ex, autopilot *a,
                   ts_err *err)
{
    memset(a, 0, sizeof *a);
    const ts_autopilot *ap = &s->sys->tow.autopilot;
    if (!ap->on)
        return TS_OK;
    if (ts_kernel_root(s->k) < 0)
        return ts_fail(err, TS_EINVAL, "simulate: waypoints (line %d) steer "
                       "a towing vehicle; the scene has none", ap->g.line);
    if (ex && ts_excitation_has_manoeuvre(ex))
        return ts_fail(err, TS_EINVAL, "simulate: waypoints (line %d): a "
                       "speed or turn-rate manoeuvre of the frame cannot be "
                       "combined with the autopilot of a towing vehicle; "
                       "remove the manoeuvre", ap->g.line);
    a->ap = ap;
    a->g = ap->g;
    a->root = ts_kernel_root(s->k);
    a->attach = s->sys->bodies[ts_kernel_vehicle_body(s->k, a->root)]
                    .vehicle->attach;
    const char *veh = s->sys->bodies[s->sys->tow.vehicle].name;
    for (int i = 0; i < ap->nrudders; i++) {
        char name[2 * TS_NAME_MAX + 8];
        snprintf(name, sizeof name, "%s.%s", veh, ap->rudder[i]);
        a->in[i] = ts_kernel_input_find(s->k, name);
        if (a->in[i] < 0)
            return ts_fail(err, TS_EINVAL, "simulate: waypoints.rudders[%d]: "
                           "the kernel has no input '%s'", i, name);
    }
    if (!s->hold && !(s->hold = calloc((size_t)s->ninput, sizeof(double))))
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    double psi;
    ap_pose(s, a, a->g.start, &psi);
    return ts_guidance_check(&a->g, "waypoints", err);
}

/* An autopilot update at the simulator's time: advance the target past
 * the waypoints within the radius (recording them in h), set and hold
 * the rudder command, schedule the next update. */
static int ap_update(ts_sim *s, autopilot *a, ts_history *h, ts_err *err)
{
    double xy[2], psi;
    ap_pose(s, a, xy, &psi);
    int before = a->index;
    a->index = ts_guidance_advance(&a->g, a->index, xy[0], xy[1]);
    for (int i = before; i < a->index && h->nreached < a->g.nwaypoints; i++) {
        h->reached_t[h->nreached] = s->t;
        h->reached_d[h->nreached] = ts_guidance_distance(&a->g, i, xy[0],
                                                         xy[1]);
        h->nreached++;
    }
    double d = ts_guidance_rudder(&a->g, ts_guidance_error(&a->g, a->index,
                                                           xy[0], xy[1],
                                                           psi));
    a->updates++;
    s->t_hold = s->t_start + (double)a->updates * a->ap->interval;
    if (s->hold[a->in[0]] == d)
        return TS_OK;
    for (int i = 0; i < a->ap->nrudders; i++)
        s->hold[a->in[i]] = d;
    /* The command jumps: no step may reuse derivatives from before. */
    return restart(s, err);
}

/* Advance to t1 stopping at the autopilot's updates (a->ap NULL: none). */
static int ap_advance(ts_sim *s, autopilot *a, ts_history *h, double t1,
                      ts_err *err)
{
    int rc = TS_OK;
    while (!rc && a->ap && s->t_hold <= t1 * (1 + 1e-12)) {
        if (s->t_hold > s->t)
            rc = ts_sim_advance(s, s->t_hold, err);
        if (!rc)
            rc = ap_update(s, a, h, err);
    }
    if (!rc && s->t < t1)
        rc = ts_sim_advance(s, t1, err);
    return rc;
}

int ts_simulate(ts_kernel *k, const ts_excitation *ex, const double y0[],
                const ts_sim_opts *o, ts_history *h, ts_sim_stats *st,
                double y_end[], ts_err *err)
{
    if (st)
        memset(st, 0, sizeof *st);
    int rc = ts_sim_opts_check(o, err);
    if (rc)
        return rc;
    int N = ts_sim_nsamples(o);
    if (ex && (rc = ts_excitation_check_span(ex, o->t_end, err)))
        return rc;
    double *ys = malloc((size_t)ts_kernel_nstate(k) * sizeof(double));
    if (!ys)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    rc = ts_sim_start_state(k, ex, y0, ys, err);
    ts_sim *s = rc ? NULL : ts_sim_alloc(k, ex, o, err);
    if (!s) {
        free(ys);
        return rc ? rc : err ? err->code : TS_ENOMEM;
    }
    rc = ts_sim_set_state(s, 0.0, ys, err);
    free(ys);
    autopilot a;
    if (!rc)
        rc = ap_bind(s, ex, &a, err);
    if (!rc && a.ap)
        rc = ap_update(s, &a, h, err);
    if (!rc)
        rc = ts_sim_record(s, h, err);
    for (int i = 1; i < N && !rc; i++) {
        rc = ap_advance(s, &a, h, ts_sim_sample_time(o, i), err);
        int rr = ts_sim_record(s, h, rc ? NULL : err);
        if (!rc)
            rc = rr;
    }
    if (st)
        ts_sim_get_stats(s, st);
    if (y_end)
        memcpy(y_end, s->y, (size_t)s->n * sizeof(double));
    ts_sim_free(s);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Initial states                                                       */

int ts_sim_start_state(ts_kernel *k, const ts_excitation *ex,
                       const double y0[], double y[], ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int n = ts_kernel_nstate(k), nn = sys->nnodes;
    if (y != y0)
        memcpy(y, y0, (size_t)n * sizeof(double));
    double du[TS_NINPUT];
    if (!ex || !ts_excitation_start_jump(ex, du) ||
        (du[3] == 0 && du[4] == 0 && du[5] == 0))
        return TS_OK;
    double *f = malloc((size_t)n * sizeof(double));
    double *r = malloc(6 * (size_t)nn * sizeof(double));
    double *dp = calloc(6 * (size_t)nn, sizeof(double));
    if (!f || !r || !dp) {
        free(f);
        free(r);
        free(dp);
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    }
    double *v = r + 3 * nn, *dv = dp + 3 * nn;
    int rc = ts_kernel_eval(k, y0, NULL, f);
    if (rc == TS_OK) {
        memcpy(r, ts_kernel_positions(k), 3 * (size_t)nn * sizeof(double));
        memcpy(v, ts_kernel_velocities(k), 3 * (size_t)nn * sizeof(double));
        /* Only the velocity jumps: a displacement the signal has at t = 0
         * is where the tow point rests before, and the cable with it. */
        memcpy(dv, du + 3, 3 * sizeof(double));
    }
    /* Links in order, upper nodes first: each absorbs its upper node's
     * jump (dp, dv) whole (elastic) or in its normal part (rigid), and
     * passes the rest to its lower node. */
    for (int l = 0; rc == TS_OK && l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        int p = L->upper, q = L->lower;
        const double *pp = dp + 3 * p, *pv = dv + 3 * p;
        if (!pp[0] && !pp[1] && !pp[2] && !pv[0] && !pv[1] && !pv[2])
            continue;
        double d[3], dd[3];
        for (int j = 0; j < 3; j++) {
            d[j] = r[3 * q + j] - r[3 * p + j] - pp[j];
            dd[j] = v[3 * q + j] - v[3 * p + j] - pv[j];
        }
        if (!L->elastic) {
            double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            double along = 0.0;
            for (int j = 0; j < 3; j++)
                d[j] *= L->length / len;
            for (int j = 0; j < 3; j++)
                along += d[j] * dd[j] / (L->length * L->length);
            for (int j = 0; j < 3; j++) {
                dd[j] -= along * d[j];
                /* The lower node's jump: its new place less its old. */
                dp[3 * q + j] = r[3 * p + j] + pp[j] + d[j] - r[3 * q + j];
                dv[3 * q + j] = v[3 * p + j] + pv[j] + dd[j] - v[3 * q + j];
            }
        }
        tsi_kernel_set_link(k, l, d, dd, TS_CHART_RECHART, y);
    }
    free(f);
    free(r);
    free(dp);
    if (rc != TS_OK)
        return ts_fail(err, rc, "simulate: the kernel refuses the initial "
                       "state (%s)", ts_strerror(rc));
    return TS_OK;
}

int ts_sim_released_state(ts_kernel *k, double theta1, double theta2,
                          double y[], ts_err *err)
{
    if (!isfinite(theta1) || !isfinite(theta2))
        return ts_fail(err, TS_EINVAL, "released shape: angles must be "
                       "finite, got theta1 %g rad, theta2 %g rad", theta1,
                       theta2);
    int nl = ts_kernel_system(k)->nlinks;
    double n[3] = {-cos(theta1) * cos(theta2), -sin(theta2),
                   sin(theta1) * cos(theta2)};
    double *dirs = malloc(3 * (size_t)nl * sizeof(double));
    if (!dirs)
        return ts_fail(err, TS_ENOMEM, "released shape: out of memory");
    for (int l = 0; l < nl; l++)
        memcpy(dirs + 3 * l, n, sizeof n);
    ts_kernel_set_directions(k, dirs, NULL, TS_CHART_RECHART, y);
    free(dirs);
    return TS_OK;
}

int ts_sim_shape_state(ts_kernel *k, const double pos[], double rtol,
                       double y[], ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int nl = sys->nlinks;
    double *dirs = malloc(3 * (size_t)nl * sizeof(double));
    if (!dirs)
        return ts_fail(err, TS_ENOMEM, "simulate: out of memory");
    char name[2 * TS_NAME_MAX];
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &sys->links[l];
        const double *a = pos + 3 * L->upper, *b = pos + 3 * L->lower;
        double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(fabs(len - L->length) <= rtol * L->length)) {
            snprintf(name, sizeof name, "%s", sys->cables[L->cable].name);
            free(dirs);
            return ts_fail(err, TS_EINVAL, "initial shape: link %d of cable "
                           "'%s' spans %.9g m between its nodes, its length "
                           "is %.9g m (tolerance %g relative)", L->index, name,
                           len, L->length, rtol);
        }
        for (int j = 0; j < 3; j++)
            dirs[3 * l + j] = d[j] / len;
    }
    ts_kernel_set_directions(k, dirs, NULL, TS_CHART_RECHART, y);
    free(dirs);
    return TS_OK;
}

/* ------------------------------------------------------------------ */
/* Linear simulation                                                    */

typedef struct lin_hold {
    double h;          /* step the blocks were computed for, 0: none */
    double *Phi;       /* [n n] */
    double *G;         /* [n 4m] */
} lin_hold;

typedef struct lin_sim {
    const ts_linear *lin;
    const ts_excitation *ex;
    int n, m;          /* states; inputs driven: TS_NINPUT, or every input
                          when a signal drives a vehicle's input or the
                          frame (a manoeuvre) */
    const int *in_idx; /* bind_inputs; NULL: none */
    int manoeuvre;     /* 1: the frame inputs follow the excitation */
    ts_frame base;     /* the frame linearized in (t = 0) */
    double *tmp;       /* [n] */
    double *v;         /* [6 m]: four input samples, two for df/dt */
    double *p;         /* [4 m]: the cubic's coefficients */
    long nfev;
    tsi_lapack la;     /* BLAS's dgemv */
    /* The sparse model's run (lin_rhs_sparse): A's action by S_inf, the
     * Newton solves by S(1 / gamma), B's m driven columns and their
     * tension changes formed once, O(nlinks m). */
    int sparse;
    tsi_shift shi;     /* S_inf */
    tsi_shift shs;     /* S(1 / gamma) */
    double gamma;      /* of shs; 0: none yet */
    double *Bc;        /* [n m] */
    double *Tc;        /* [nlinks m] */
} lin_sim;

/* 1 when a signal of ex drives a tow rotation (tow.roll ...). */
static int drives_rotation(const ts_excitation *ex)
{
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        ts_axis a = ts_excitation_signal(ex, i)->axis;
        if (a == TS_AXIS_ROLL || a == TS_AXIS_PITCH || a == TS_AXIS_YAW)
            return 1;
    }
    return 0;
}

/* v[m] = u(t) - u0: the tow channels from the excitation, the vehicles'
 * inputs (when driven) the signals on them, the frame inputs (under a
 * manoeuvre) the frame's change from the base frame: speed, turn rate
 * and their rates (ts_excitation_frame). */
static void lin_input(const lin_sim *L, double t, double *v)
{
    double u[TS_NINPUT] = {0};
    if (L->ex)
        ts_excitation_input(L->ex, t, u);
    for (int j = 0; j < L->m; j++)
        v[j] = j < TS_NINPUT ? u[j] - L->lin->u0[j] : 0.0;
    if (L->in_idx)
        add_inputs(L->ex, L->in_idx, t, v);
    if (L->manoeuvre) {
        ts_frame f;
        ts_excitation_frame(L->ex, &L->base, t, &f);
        double *vf = v + L->lin->frame_input;
        vf[0] = f.speed - L->base.speed;
        vf[1] = f.turn_rate - L->base.turn_rate;
        vf[2] = f.speed_rate;
        vf[3] = f.turn_accel;
    }
}

/* Phi and G of step h: top blocks of exp(M h). */
static int hold_compute(const ts_linear *lin, int m, double h, lin_hold *H,
                        ts_err *err)
{
    int n = lin->nstate, N = n + 4 * m;
    size_t NN = (size_t)N * (size_t)N;
    double *M = calloc(NN, sizeof(double));
    double *E = malloc(NN * sizeof(double));
    if (!M || !E) {
        free(M);
        free(E);
        return ts_fail(err, TS_ENOMEM, "simulate (linear): out of memory "
                       "for the order-%d exponential", N);
    }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++)
            M[i + (size_t)j * N] = h * lin->A[i + (size_t)j * n];
    for (int j = 0; j < m; j++)
        for (int i = 0; i < n; i++)
            M[i + (size_t)(n + j) * N] = h * lin->B[i + (size_t)j * n];
    for (int b = 0; b < 3; b++)
        for (int j = 0; j < m; j++) {
            int row = n + b * m + j, col = n + (b + 1) * m + j;
            M[row + (size_t)col * N] = h;
        }
    int rc = tsi_expm(N, M, E, NULL, err);
    if (!rc) {
        for (int j = 0; j < n; j++)
            memcpy(H->Phi + (size_t)j * n, E + (size_t)j * N,
                   (size_t)n * sizeof(double));
        for (int j = 0; j < 4 * m; j++)
            memcpy(H->G + (size_t)j * n, E + (size_t)(n + j) * N,
                   (size_t)n * sizeof(double));
        H->h = h;
    }
    free(M);
    free(E);
    return rc;
}

/* One exact step of length h: z <- Phi z + G p, the cubic through
 * v0..v3 (values at 0, h/3, 2h/3, h; v[k m + j]), p[4 m] scratch. */
static void hold_step(const tsi_lapack *la, const lin_hold *H, int n,
                      int m, const double *v, double *p, double *z,
                      double *tmp)
{
    const int m4 = 4 * m, one = 1;
    double h = H->h;
    for (int j = 0; j < m; j++) {
        /* Newton forward differences on x = 3 s / h. */
        const double *v0 = v, *v1 = v + m, *v2 = v + 2 * m, *v3 = v + 3 * m;
        double f0 = v0[j], d1 = v1[j] - f0, d2 = v2[j] - 2 * v1[j] + f0,
               d3 = v3[j] - 3 * v2[j] + 3 * v1[j] - f0;
        double c1 = d1 - d2 / 2 + d3 / 3, c2 = d2 / 2 - d3 / 2, c3 = d3 / 6;
        p[j] = f0;
        p[m + j] = 3.0 * c1 / h;
        p[2 * m + j] = 2.0 * 9.0 * c2 / (h * h);
        p[3 * m + j] = 6.0 * 27.0 * c3 / (h * h * h);
    }
    const double a1 = 1.0, b0 = 0.0;
    la->dgemv_("N", &n, &n, &a1, H->Phi, &n, z, &one, &b0, tmp, &one, 1);
    la->dgemv_("N", &n, &m4, &a1, H->G, &n, p, &one, &a1, tmp, &one, 1);
    memcpy(z, tmp, (size_t)n * sizeof(double));
}

static int lin_rhs(double t, const double z[], double dz[], void *params)
{
    lin_sim *L = params;
    const int n = L->n, m = L->m, one = 1;
    const double a1 = 1.0, b0 = 0.0;
    double *v = L->v + 4 * m;
    L->nfev++;
    lin_input(L, t, v);
    L->la.dgemv_("N", &n, &n, &a1, L->lin->A, &n, z, &one, &b0, dz, &one, 1);
    L->la.dgemv_("N", &n, &m, &a1, L->lin->B, &n, v, &one, &a1, dz, &one, 1);
    return GSL_SUCCESS;
}

static int lin_jac(double t, const double z[], double *dfdy, double dfdt[],
                   void *params)
{
    lin_sim *L = params;
    const int n = L->n, m = L->m, one = 1;
    (void)z;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            dfdy[(size_t)i * n + j] = L->lin->A[i + (size_t)j * n];
    /* df/dt = B dv/dt by a central difference of the input. */
    double tau = L->ex ? ts_excitation_time_scale(L->ex) : INFINITY;
    double dt = DFDT_REL_STEP * (tau < 1.0 ? tau : 1.0);
    double *vp = L->v + 4 * m, *vm = L->v + 5 * m;
    lin_input(L, t + dt, vp);
    lin_input(L, t - dt, vm);
    for (int j = 0; j < m; j++)
        vp[j] = (vp[j] - vm[j]) / (2 * dt);
    const double a1 = 1.0, b0 = 0.0;
    L->la.dgemv_("N", &n, &m, &a1, L->lin->B, &n, vp, &one, &b0, dfdt, &one, 1);
    return GSL_SUCCESS;
}

static int lin_rhs_esdirk(double t, const double z[], double dz[],
                          void *params)
{
    return esdirk_code(lin_rhs(t, z, dz, params));
}

static int lin_jac_esdirk(double t, const double z[], double J[],
                          void *params)
{
    const lin_sim *L = params;
    (void)t;
    (void)z;
    memcpy(J, L->lin->A, (size_t)L->n * (size_t)L->n * sizeof(double));
    return 0;
}

/* z' = A z + B v(t) on the sparse model: O(nlinks) (m columns of B). */
static int lin_rhs_sparse(double t, const double z[], double dz[],
                          void *params)
{
    lin_sim *L = params;
    const size_t n = (size_t)L->n;
    double *v = L->v + 4 * L->m;
    L->nfev++;
    lin_input(L, t, v);
    tsi_shift_apply(&L->shi, z, dz, 0);
    for (int j = 0; j < L->m; j++)
        if (v[j] != 0) {
            const double *b = L->Bc + (size_t)j * n;
            for (size_t i = 0; i < n; i++)
                dz[i] += b[i] * v[j];
        }
    return 0;
}

/* esdirk's Newton matrix I - gamma A: S(1 / gamma) factored when gamma
 * changes (A is constant: nothing to evaluate), refactored on KLU's
 * pivot order (tsi_shift_refactor), O(nlinks). */
static int lin_lsys_setup(double t, const double y[], double gamma, int jok,
                          int *jcur, void *params)
{
    lin_sim *L = params;
    (void)t;
    (void)y;
    *jcur = !jok;
    if (L->gamma == gamma)
        return 0;
    L->gamma = 0.0;
    int rc = tsi_shift_refactor(&L->shs, L->lin, 1.0 / gamma, NULL);
    if (rc == TS_ESINGULAR)
        return 1; /* ARKODE retries with another step */
    if (rc != TS_OK)
        return -1;
    L->gamma = gamma;
    return 0;
}

/* x = (I - gamma A)^-1 b. */
static int lin_lsys_solve(double x[], const double b[], void *params)
{
    lin_sim *L = params;
    return newton_solve(&L->shs, L->n, b, x);
}

/* The sparse run's set-up: S_inf, and B's m columns with their tension
 * changes (tsi_shift_apply_input, tsi_shift_tensions). */
static int lin_sparse_setup(lin_sim *L, ts_err *err)
{
    const ts_linear *lin = L->lin;
    size_t n = (size_t)L->n, nl = (size_t)lin->nlinks;
    L->Bc = malloc(n * (size_t)L->m * sizeof(double));
    L->Tc = malloc(nl * (size_t)L->m * sizeof(double));
    if (!L->Bc || !L->Tc)
        return ts_fail(err, TS_ENOMEM, "simulate (linear): out of memory "
                       "for %d input columns of %d states", L->m, L->n);
    int rc = tsi_shift_factor_inf(&L->shi, lin, err);
    if (rc) {
        ts_err_prefix(err, "simulate (linear): ");
        return rc;
    }
    for (int j = 0; j < L->m; j++) {
        tsi_shift_apply_input(&L->shi, j, L->Bc + (size_t)j * n, 0);
        tsi_shift_tensions(&L->shi, L->Tc + (size_t)j * nl);
    }
    return TS_OK;
}

/* Append a linear sample: positions from z. */
static int lin_record(ts_kernel *k, const ts_linear *lin, lin_sim *L,
                      const ts_sim_opts *o, double t, const double *z,
                      ts_history *h, double *ywork, double *dr, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int rc = history_reserve(h, err);
    if (rc)
        return rc;
    size_t i = (size_t)h->nsamples, nn = (size_t)h->nnodes,
           nl = (size_t)h->nlinks;
    /* The input deviation (ywork's last part), then the tow channels. */
    int n = lin->nstate;
    double *dv = ywork + 2 * n + lin->ninput;
    lin_input(L, t, dv);
    double u[TS_NINPUT];
    for (int j = 0; j < TS_NINPUT; j++)
        u[j] = (j < L->m ? dv[j] : 0.0) + lin->u0[j];
    double *pos = h->positions + 3 * nn * i;
    if (o->kinematics == TS_KIN_LINEAR) {
        /* The tow inputs move every node with the coordinates held:
         * ts_linear_tow_shift (a rotation by theta x its cable's start). */
        ts_linear_node_displacements(sys, lin, z, dr);
        for (size_t a = 0; a < nn; a++) {
            for (int c = 0; c < 3; c++)
                pos[3 * a + c] = lin->r0[3 * a + c] + dr[3 * a + c];
            for (int j = 0; j < 6; j++) {
                int in = j < 3 ? TS_IN_DISP + j : TS_IN_ROT + j - 3;
                double d[3];
                if (in >= L->m || dv[in] == 0)
                    continue;
                ts_linear_tow_shift(lin, (int)a, in, d);
                for (int c = 0; c < 3; c++)
                    pos[3 * a + c] += d[c] * dv[in];
            }
        }
    } else {
        double *ufull = ywork + 2 * n;
        for (int j = 0; j < n; j++)
            ywork[j] = lin->y0[j] + z[j];
        for (int j = 0; j < lin->ninput; j++)
            ufull[j] = lin->u0[j] + (j < L->m ? dv[j] : 0.0);
        rc = ts_kernel_eval(k, ywork, ufull, ywork + n);
        if (rc)
            return ts_fail(err, rc < 0 ? rc : TS_EDOMAIN, "simulate "
                           "(linear): the state y0 + z at t = %.9g s is "
                           "outside the kernel's chart; use linear "
                           "kinematics", t);
        memcpy(pos, ts_kernel_positions(k), 3 * nn * sizeof(double));
    }
    h->t[i] = t;
    /* Tensions T0 + dT/dy z + dT/du v: O(nlinks n) per sample with the
     * dense tension Jacobians; on the sparse model the tension unknowns
     * of one solve with S_inf (A z) and B's columns', O(nlinks). */
    double *ten = h->tensions + nl * i;
    if (L->sparse) {
        tsi_shift_apply(&L->shi, z, L->tmp, 0);
        tsi_shift_tensions(&L->shi, ten);
        for (size_t l = 0; l < nl; l++)
            ten[l] += lin->t0[l];
        for (int j = 0; j < L->m; j++)
            if (dv[j] != 0)
                for (size_t l = 0; l < nl; l++)
                    ten[l] += L->Tc[l + nl * (size_t)j] * dv[j];
    } else {
        for (size_t l = 0; l < nl; l++)
            ten[l] = lin->Ty && lin->Tu ? lin->t0[l] : NAN;
    }
    if (!L->sparse && lin->Ty && lin->Tu) {
        int n = lin->nstate;
        for (int j = 0; j < n; j++)
            if (z[j] != 0)
                for (size_t l = 0; l < nl; l++)
                    ten[l] += lin->Ty[l + nl * (size_t)j] * z[j];
        for (int j = 0; j < L->m; j++)
            if (dv[j] != 0)
                for (size_t l = 0; l < nl; l++)
                    ten[l] += lin->Tu[l + nl * (size_t)j] * dv[j];
    }
    for (int c = 0; c < 3; c++)
        h->tow_force[3 * i + (size_t)c] = NAN;
    h->energy[2 * i] = h->energy[2 * i + 1] = NAN;
    memcpy(h->input + TS_NINPUT * i, u, sizeof u);
    if (lin->noutput > 0) {
        /* v0 + Vy z + Vu du */
        double *out = history_outputs(h, k, err);
        if (!out)
            return TS_ENOMEM;
        const int no = lin->noutput, m = L->m, one = 1;
        const double a1 = 1.0;
        if (L->sparse) {
            /* The output rows of the sparse model, O(nlinks). */
            tsi_shift_outputs(&L->shi, z, dv, L->m, out);
            for (int r = 0; r < no; r++)
                out[r] += lin->v0[r];
        } else {
            memcpy(out, lin->v0, (size_t)no * sizeof(double));
            L->la.dgemv_("N", &no, &n, &a1, lin->Vy, &no, z, &one, &a1, out,
                         &one, 1);
            L->la.dgemv_("N", &no, &m, &a1, lin->Vu, &no, dv, &one, &a1, out,
                         &one, 1);
        }
    }
    h->nsamples++;
    return TS_OK;
}

const char *ts_linear_method_name(const ts_sim_opts *o,
                                  const ts_sim_stats *st)
{
    if (st->newton == TS_NEWTON_SPARSE)
        return ts_integrator_name(o->integrator == TS_INT_BDF ? TS_INT_BDF
                                                              : TS_INT_ESDIRK);
    return o->linear_method == TS_LINSIM_EXPM
               ? "expm"
               : ts_integrator_name(o->integrator);
}

int ts_simulate_linear(ts_kernel *k, const ts_linear *lin,
                       const ts_excitation *ex, const double z0[],
                       const ts_sim_opts *o, ts_history *h, ts_sim_stats *st,
                       ts_err *err)
{
    ts_sim_stats stats = {0};
    if (st)
        *st = stats;
    int rc = ts_sim_opts_check(o, err);
    if (rc)
        return rc;
    int n = lin->nstate;
    if (n != ts_kernel_nstate(k) || h->nlinks != lin->nlinks)
        return ts_fail(err, TS_EINVAL, "simulate (linear): the model has %d "
                       "states, the kernel %d and the history %d links", n,
                       ts_kernel_nstate(k), h->nlinks);
    /* The sparse model when asked for, or when it is the only one. */
    int sparse = lin->desc && (o->linear_method == TS_LINSIM_SPARSE ||
                               !lin->A || !lin->B);
    int manoeuvre = ex && ts_excitation_has_manoeuvre(ex);
    if (!sparse && (!lin->A || !lin->B))
        return ts_fail(err, TS_EINVAL, "simulate (linear): the linear "
                       "simulation needs a linear model, sparse or dense "
                       "(linearize with model TS_LIN_AUTO, SPARSE, DENSE or "
                       "BOTH)");
    if (o->linear_method == TS_LINSIM_SPARSE && !lin->desc)
        return ts_fail(err, TS_EINVAL, "simulate (linear): linear_method "
                       "sparse needs the sparse model (linearize with model "
                       "TS_LIN_AUTO, SPARSE or BOTH)");
    if (sparse && manoeuvre && !lin->desc->frame)
        return ts_fail(err, TS_EINVAL, "simulate (linear): a manoeuvre "
                       "drives the frame inputs, which with a towing "
                       "vehicle only the dense model has (linearize with "
                       "model TS_LIN_DENSE or BOTH, and linear_method expm "
                       "or ode)");
    ts_frame base;
    ts_kernel_get_frame(k, &base);
    if ((rc = ts_sim_check_linear_manoeuvre(k, ex, err)))
        return rc;
    int N = ts_sim_nsamples(o);
    if (ex && (rc = ts_excitation_check_span(ex, o->t_end, err)))
        return rc;
    int *in_idx = NULL;
    if ((rc = bind_inputs(k, ex, &in_idx, err)))
        return rc;
    double w0 = tsi_wall_now();
    size_t sn = (size_t)n;
    /* Only the tow channels are driven unless a signal drives a vehicle's
     * input or the frame (the exponential's order is n + 4 m), and only
     * the translations' unless a signal drives a rotation. */
    int m = manoeuvre               ? lin->ninput
            : in_idx && sparse      ? lin->frame_input
            : in_idx                ? lin->ninput
            : drives_rotation(ex) ? TS_NINPUT
                                    : TS_TOW_ROT;
    /* The exponential's blocks: expm on the dense model only. */
    int hold = !sparse && o->linear_method == TS_LINSIM_EXPM;
    double *z = calloc(sn, sizeof(double));
    double *tmp = calloc(sn, sizeof(double));
    /* y0 + z, f there, the whole input, and its deviation. */
    double *ywork = calloc(2 * sn + 2 * (size_t)lin->ninput, sizeof(double));
    double *dr = calloc(3 * (size_t)lin->nnodes, sizeof(double));
    double *vbuf = calloc(10 * (size_t)m, sizeof(double));
    lin_hold H[2];
    for (int c = 0; c < 2; c++) {
        H[c].h = 0.0;
        H[c].Phi = hold ? malloc(sn * sn * sizeof(double)) : NULL;
        H[c].G = hold ? malloc(sn * 4 * (size_t)m * sizeof(double)) : NULL;
    }
    lin_sim L = {.lin = lin,   .ex = ex,         .n = n,
                 .m = m,       .in_idx = in_idx, .manoeuvre = manoeuvre,
                 .base = base, .tmp = tmp,       .v = vbuf,
                 .p = vbuf + 6 * m, .sparse = sparse};
    gsl_odeiv2_driver *drv = NULL;
    tsi_esdirk *sd = NULL;
    gsl_odeiv2_system gsys = {lin_rhs, lin_jac, sn, &L};
    if (!z || !tmp || !ywork || !dr || !vbuf ||
        (hold && (!H[0].Phi || !H[0].G || !H[1].Phi || !H[1].G))) {
        rc = ts_fail(err, TS_ENOMEM, "simulate (linear): out of memory for "
                     "%d states", n);
        goto done;
    }
    /* BLAS for the dense model's products only. */
    if (!sparse && (rc = tsi_lapack_open(&L.la, err)) != TS_OK)
        goto done;
    if (z0)
        memcpy(z, z0, sn * sizeof(double));
    /* An impulsive start (ts_sim_start_state) to first order: the tow
     * point's jump in velocity passes down the links, each elastic one
     * absorbing it whole and each rigid one its normal part; dr holds the
     * node velocities relative to the tow point that this makes (the jump
     * a node takes less the tow point's), and the rates follow
     * (tsi_desc_from_nodes). */
    double du[TS_NINPUT];
    if (ex && ts_excitation_start_jump(ex, du)) {
        const ts_system *sys = ts_kernel_system(k);
        for (int part = 1; part < 2; part++) {
            /* jump[] of every node in ywork (3 nnodes <= 2 n). */
            double *jump = ywork;
            memcpy(jump, du + 3 * part, 3 * sizeof(double));
            dr[0] = dr[1] = dr[2] = 0.0;
            for (int l = 0; l < sys->nlinks; l++) {
                const ts_link *L = &sys->links[l];
                const double *n = lin->n0 + 3 * l, *jp = jump + 3 * L->upper;
                double along = L->elastic ? 0.0
                                          : n[0] * jp[0] + n[1] * jp[1] +
                                                n[2] * jp[2];
                for (int c = 0; c < 3; c++) {
                    jump[3 * L->lower + c] = along * n[c];
                    dr[3 * L->lower + c] =
                        jump[3 * L->lower + c] - du[3 * part + c];
                }
            }
            tsi_desc_from_nodes(sys, lin, dr, tmp);
            for (int i = 0; i < lin->nq; i++)
                z[part * lin->nq + i] += tmp[i];
        }
    }
    if (sparse) {
        /* esdirk (bdf when chosen) with the sparse Newton solves, at the
         * run's tolerances. */
        const tsi_ode_lsys lsys = {lin_lsys_setup, lin_lsys_solve, 1};
        if ((rc = lin_sparse_setup(&L, err)))
            goto done;
        stats.newton = TS_NEWTON_SPARSE;
        sd = tsi_esdirk_alloc_method(n, lin_rhs_sparse, NULL, &lsys, &L,
                                     o->rel_tol, o->abs_tol, o->h_init,
                                     o->integrator == TS_INT_BDF, err);
        if (!sd || (rc = tsi_esdirk_reset(sd, 0.0, z, err))) {
            rc = rc ? rc : TS_ENOMEM;
            goto done;
        }
    } else if (o->linear_method == TS_LINSIM_ODE &&
               sundials_method(o->integrator)) {
        sd = tsi_esdirk_alloc_method(n, lin_rhs_esdirk, lin_jac_esdirk, NULL,
                                     &L, o->rel_tol, o->abs_tol, o->h_init,
                                     o->integrator == TS_INT_BDF, err);
        if (!sd || (rc = tsi_esdirk_reset(sd, 0.0, z, err))) {
            rc = rc ? rc : TS_ENOMEM;
            goto done;
        }
    } else if (o->linear_method == TS_LINSIM_ODE) {
        gsl_error_handler_t *old = gsl_set_error_handler_off();
        drv = gsl_odeiv2_driver_alloc_y_new(&gsys, step_type(o->integrator),
                                            o->h_init, o->abs_tol,
                                            o->rel_tol);
        gsl_set_error_handler(old);
        if (!drv) {
            rc = ts_fail(err, TS_ENOMEM, "simulate (linear): out of memory");
            goto done;
        }
    }
    double tau = ex ? ts_excitation_time_scale(ex) : INFINITY;
    double h_max = tau * pow(o->rel_tol / CUBIC_HOLD_ERR, 0.25);
    rc = lin_record(k, lin, &L, o, 0.0, z, h, ywork, dr, err);
    double t = 0.0, hode = o->h_init;
    for (int i = 1; i < N && !rc; i++) {
        double t1 = ts_sim_sample_time(o, i);
        if (sd) {
            while (t < t1 && !rc)
                if (tsi_esdirk_step(sd, t1, &t, z, err))
                    rc = TS_EINTEGRATOR;
            if (rc)
                break;
        } else if (!hold) {
            gsl_error_handler_t *old = gsl_set_error_handler_off();
            while (t < t1 && !rc) {
                int s = gsl_odeiv2_evolve_apply(drv->e, drv->c, drv->s, &gsys,
                                                &t, t1, &hode, z);
                if (s != GSL_SUCCESS)
                    rc = ts_fail(err, TS_EINTEGRATOR, "simulate (linear): "
                                 "%s failed at t = %.9g s (step %.3g s)",
                                 ts_integrator_name(o->integrator), t, hode);
            }
            gsl_set_error_handler(old);
            if (rc)
                break;
        } else {
            double dt = t1 - t;
            long steps = (long)ceil(dt / h_max - 1e-9);
            if (steps < 1)
                steps = 1;
            double hs = dt / (double)steps;
            lin_hold *Hc = NULL;
            for (int c = 0; c < 2 && !Hc; c++)
                if (H[c].h > 0 && fabs(H[c].h - hs) <= 1e-12 * hs)
                    Hc = &H[c];
            if (!Hc) {
                Hc = H[0].h == 0 ? &H[0] : &H[1];
                if ((rc = hold_compute(lin, m, hs, Hc, err)))
                    break;
            }
            double *v = L.v;
            lin_input(&L, t, v);
            for (long s = 0; s < steps; s++) {
                double ts = t + (double)s * hs;
                for (int j = 1; j <= 3; j++)
                    lin_input(&L, ts + j * hs / 3.0, v + j * m);
                hold_step(&L.la, Hc, n, m, v, L.p, z, tmp);
                memcpy(v, v + 3 * m, (size_t)m * sizeof(double));
                L.nfev += 3;
                stats.steps++;
                stats.h_last = hs;
            }
            t = t1;
        }
        int finite = 1;
        for (int j = 0; j < n && finite; j++)
            finite = isfinite(z[j]);
        if (!finite) {
            rc = ts_fail(err, TS_EINTEGRATOR, "simulate (linear): the state "
                         "is not finite at t = %.9g s", t1);
            break;
        }
        rc = lin_record(k, lin, &L, o, t1, z, h, ywork, dr, err);
        if (!rc)
            rc = report_progress(o, "linear", t1, err);
    }
done:
    if (drv) {
        stats.steps = (long)drv->e->count;
        stats.rejected = (long)drv->e->failed_steps;
        stats.h_last = drv->e->last_step;
        gsl_odeiv2_driver_free(drv);
    }
    if (sd) {
        tsi_esdirk_stats sds;
        tsi_esdirk_get_stats(sd, &sds);
        stats.steps = sds.steps;
        stats.rejected = sds.rejected;
        stats.h_last = sds.h_last;
        tsi_esdirk_free(sd);
    }
    stats.evaluations = L.nfev;
    stats.t_reached = h->nsamples > 0 ? h->t[h->nsamples - 1] : 0.0;
    stats.wall_s = tsi_wall_now() - w0;
    if (st)
        *st = stats;
    for (int c = 0; c < 2; c++) {
        free(H[c].Phi);
        free(H[c].G);
    }
    tsi_shift_free(&L.shi);
    tsi_shift_free(&L.shs);
    free(L.Bc);
    free(L.Tc);
    free(z);
    free(tmp);
    free(ywork);
    free(dr);
    free(vbuf);
    free(in_idx);
    return rc;
}
