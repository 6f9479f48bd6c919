/* cost.c: lower bounds of what an analysis will cost (towstab/
 * cost.h, where the bounds are derived). */
#include "towstab/cost.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"

/* Kernel evaluations timed: at least this many, and at least this long. */
#define TIME_EVALS 3
#define TIME_MIN_S 2e-3
#define TIME_MAX_EVALS 200

/* Time one kernel evaluation of sys, at rest with every link straight aft
 * (y = 0: a state of every chart). */
static int time_kernel(const ts_system *sys, double *eval_s, int *nstate,
                       ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(sys, err);
    if (!k)
        return err && err->code ? err->code : TS_ENOMEM;
    int n = ts_kernel_nstate(k);
    double *y = calloc(2 * (size_t)n, sizeof *y);
    if (!y) {
        ts_kernel_free(k);
        return ts_fail(err, TS_ENOMEM, "estimate: out of memory for a state "
                       "of %d values (%.3g MB); fewer links", n,
                       16.0 * n / 1e6);
    }
    /* One evaluation first (caches, pages), then the fastest of three
     * batches: a lower bound of the cost, whatever else the machine does. */
    ts_kernel_eval(k, y, NULL, y + n);
    *eval_s = INFINITY;
    for (int b = 0; b < 3; b++) {
        int m = 0;
        double t0 = tsi_wall_now(), t = t0;
        while (m < TIME_MAX_EVALS && (m < TIME_EVALS || t - t0 < TIME_MIN_S)) {
            ts_kernel_eval(k, y, NULL, y + n);
            m++;
            t = tsi_wall_now();
        }
        *eval_s = fmin(*eval_s, (t - t0) / m);
    }
    *nstate = n;
    free(y);
    ts_kernel_free(k);
    return TS_OK;
}

double ts_cost_fastest_mode(const ts_system *sys,
                                const ts_motion_bound *mb)
{
    /* The largest tension: every load of the system at once, as
     * ts_system_check_loads sums them (weights, buoyancy, drag at the flow
     * bound, inertia), taken from the links' and bodies' sizes. */
    const double rho = sys->env.water_density, g = fabs(sys->env.gravity);
    double R = 0, T = 0;
    for (int c = 0; c < sys->ncables; c++)
        R += sys->cables[c].length;
    double flow = mb->speed + mb->turn_rate * R + mb->tow_speed +
                  mb->rot_rate * R;
    double acc = mb->turn_rate * mb->turn_rate * R +
                 mb->turn_rate * mb->speed + mb->tow_accel +
                 mb->rot_accel * R;
    double lmin = INFINITY, mmin = INFINITY, wmax = 0.0;
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        double vol = M_PI * 0.25 * L->diameter * L->diameter * L->length;
        double added = rho * L->can * vol;
        T += (L->mass + rho * vol) * g + (L->mass + added) * acc +
             0.5 * rho * flow * flow * L->diameter * L->length *
                 (L->cdn + M_PI * L->cdt);
        lmin = fmin(lmin, L->length);
        /* A node carries half of each link next to it. */
        mmin = fmin(mmin, 0.5 * (L->mass + added));
        if (L->elastic && L->mass > 0)
            wmax = fmax(wmax, 2.0 * sqrt(L->ea / (0.5 * L->mass * L->length)));
    }
    for (int b = 0; b < sys->nbodies; b++) {
        const ts_body *B = &sys->bodies[b];
        double vol = ts_body_volume(B), D = B->diameter;
        T += (B->mass + rho * vol) * g + B->mass * acc +
             0.5 * rho * flow * flow * B->cd * M_PI * 0.25 * D * D;
    }
    if (sys->nlinks > 0 && mmin > 0 && lmin > 0)
        wmax = fmax(wmax, 2.0 * sqrt(T / (mmin * lmin)));
    return wmax;
}

/* Stages (right-hand sides per step) of an integrator, at least. */
static double stages(ts_integrator m)
{
    switch (m) {
    case TS_INT_RK8PD: return 13;
    case TS_INT_RKF45: return 6;
    case TS_INT_RK4IMP: return 2;
    case TS_INT_BSIMP: return 4;
    case TS_INT_MSBDF: return 1;
    case TS_INT_ESDIRK: return 7;
    case TS_INT_BDF: return 1;
    }
    return 1;
}

static int explicit_method(ts_integrator m)
{
    return m == TS_INT_RK8PD || m == TS_INT_RKF45;
}

/* "3.2 min", "42 s", "5.1 h", "2.3 days". */
static void duration(double s, char *buf, size_t size)
{
    if (s < 120)
        snprintf(buf, size, "%.2g s", s);
    else if (s < 7200)
        snprintf(buf, size, "%.2g min", s / 60);
    else if (s < 172800)
        snprintf(buf, size, "%.2g h", s / 3600);
    else
        snprintf(buf, size, "%.2g days", s / 86400);
}

int ts_cost_simulate(const ts_system *sys, const ts_excitation *ex,
                         const ts_sim_opts *o, ts_cost *e, ts_err *err)
{
    memset(e, 0, sizeof *e);
    int n;
    int rc = time_kernel(sys, &e->eval_s, &n, err);
    if (rc)
        return rc;
    ts_frame f0 = {sys->tow.speed, sys->tow.turn_rate, 0, 0,
                   {sys->env.current[0], sys->env.current[1],
                    sys->env.current[2]}};
    ts_motion_bound mb;
    ts_excitation_bound(ex, &f0, &mb);
    e->omega_max = ts_cost_fastest_mode(sys, &mb);
    double samples = ceil(o->t_end / o->dt_sample);
    /* The fastest periodic excitation. */
    double fastest = 0.0;
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        const ts_signal *s = ts_excitation_signal(ex, i);
        double f = s->type == TS_SIGNAL_CRANK ? 2 * s->frequency
                   : s->type == TS_SIGNAL_SINE || s->type == TS_SIGNAL_SUM
                       ? s->frequency
                       : 0.0;
        fastest = fmax(fastest, f);
    }
    int sundials = o->integrator == TS_INT_ESDIRK || o->integrator == TS_INT_BDF;
    double by_samples = sundials ? 0.0 : samples;
    double by_exc = o->t_end * fastest * TS_COST_STEPS_PER_PERIOD;
    double by_stiff = explicit_method(o->integrator)
                          ? o->t_end * e->omega_max / TS_COST_STABILITY
                          : 0.0;
    e->steps = fmax(1.0, fmax(by_samples, fmax(by_exc, by_stiff)));
    e->evaluations = e->steps * stages(o->integrator);
    /* esdirk's Newton matrix comes from the sparse model (no vehicle):
     * O(links); GSL's implicit steppers take a dense Jacobian and LU. */
    int sparse = sundials && sys->nvehicles == 0;
    if (!explicit_method(o->integrator)) {
        e->evaluations += sparse ? TS_COST_SPARSE_EVALUATIONS : 2.0 * (n + 9);
        e->flops = sparse ? 0.0 : (double)n * n * n / 3.0;
    }
    e->seconds = e->evaluations * e->eval_s + e->flops / TS_COST_FLOPS;
    /* History: time, positions, tensions, energies and inputs per sample;
     * an implicit method's Jacobian and its factors. */
    e->bytes = 8.0 * (samples + 1) *
               (1 + 3.0 * sys->nnodes + sys->nlinks + 2 + TS_NINPUT);
    if (!explicit_method(o->integrator) && !sparse)
        e->bytes += 3 * 8.0 * n * n;
    char d[32];
    duration(e->seconds, d, sizeof d);
    const char *why = e->steps == by_stiff
                          ? "the explicit integrator's stability limit on "
                            "the fastest mode"
                      : e->steps == by_exc ? "the excitation's period"
                                           : "the output samples";
    snprintf(e->what, sizeof e->what,
             "at least %s: %.3g steps of %s (set by %s; fastest mode %.3g "
             "rad/s), %.3g kernel evaluations of %d links at %.3g s each",
             d, e->steps, ts_integrator_name(o->integrator), why,
             e->omega_max, e->evaluations, sys->nlinks, e->eval_s);
    snprintf(e->reduce, sizeof e->reduce, "%s",
             e->steps == by_stiff
                 ? "fewer links (longer ones are slower modes), a shorter "
                   "t_end, or an implicit integrator (esdirk)"
             : e->steps == by_exc ? "a shorter t_end or a slower excitation"
                                  : "a shorter t_end or a coarser sample");
    return TS_OK;
}

int ts_cost_modes(const ts_system *sys, int n, ts_eig_method m,
                      ts_cost *e, ts_err *err)
{
    memset(e, 0, sizeof *e);
    int nk;
    int rc = time_kernel(sys, &e->eval_s, &nk, err);
    if (rc)
        return rc;
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    int dense = m != TS_EIG_ARPACK || n < lo.dense_max_states;
    if (dense) {
        e->evaluations = 2.0 * (n + 9);
        e->bytes = 8.0 * n * (double)n;
    } else {
        e->evaluations = TS_COST_SPARSE_EVALUATIONS;
    }
    if (m != TS_EIG_ARPACK) {
        e->flops = 30.0 * n * (double)n * n;
        e->bytes = 6 * 8.0 * n * (double)n;
    } else if (dense) {
        e->flops = 2.0 / 3.0 * n * (double)n * n;
    }
    e->seconds = e->evaluations * e->eval_s + e->flops / TS_COST_FLOPS;
    char d[32];
    duration(e->seconds, d, sizeof d);
    if (e->flops > 0)
        snprintf(e->what, sizeof e->what,
                 "at least %s: %s of the %d-state %s linearization (%.3g "
                 "flops, %.3g GB) after %.3g kernel evaluations of %d links",
                 d, m == TS_EIG_ARPACK ? "ARPACK" : "a dense LAPACK eigensolve",
                 n, dense ? "dense" : "sparse", e->flops, e->bytes / 1e9,
                 e->evaluations, sys->nlinks);
    else
        snprintf(e->what, sizeof e->what,
                 "at least %s: %.3g kernel evaluations of %d links to "
                 "linearize, then ARPACK on the %d-state sparse system", d,
                 e->evaluations, sys->nlinks, n);
    snprintf(e->reduce, sizeof e->reduce, "%s", m == TS_EIG_ARPACK
             ? "fewer links"
             : "fewer links, or method arpack with a count (the modes near "
               "a target)");
    return TS_OK;
}
