/* control.c: the open-loop plant and the loop margins of the vehicles'
 * controllers (towstab/control.h; doc/vehicle.md section 5).
 *
 * Open loop: every loop is set TS_LOOP_OPEN with its output frozen at the
 * closed-loop trim's value, so the surfaces keep their deflections and the
 * state drops the integrators; the plant is linearized about the same
 * physical state.
 *
 * Margins, one loop at a time: the loop is set TS_LOOP_BROKEN (its
 * surfaces see the loop's input instead of its output; the other loops
 * stay closed; its integrator stays, being part of the controller between
 * the error and the output), the input set to the trim's output, and the
 * model linearized there. G(s) = (output row) (sI - A)^-1 (input column)
 * + D is the transfer from the break's input back to the loop's output
 * (ts_response_at); closing the loop feeds the output back positively, so
 * in the usual negative-feedback convention the loop transfer is L = -G.
 * Crossings of |L| = 1 (gain crossover: phase margin 180 + arg L) and of
 * arg L = -180 deg (Im L = 0 with Re L < 0, phase crossover: gain margin
 * 1 / |L|) are found on a log-spaced scan and refined by Brent's method
 * (GSL) in log frequency; the smallest margin of each kind is reported.
 */
#include "towstab/control.h"

#include <complex.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "response_impl.h"
#include "towstab/response.h"

/* Crossing refinement: relative accuracy in frequency, iterations. */
#define CROSS_RTOL 1e-9
#define CROSS_MAXIT 100

int ts_control_nloops(const ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    int n = 0;
    for (int v = 0; v < ts_kernel_nvehicles(k); v++)
        n += sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle->nloops;
    return n;
}

/* The closed-loop trim's state in y[nstate] (k's charts) and the loop
 * outputs there, out[nloops in all]. */
static int trim_state(ts_kernel *k, const ts_equilibrium *eq, double *y,
                      double *out, ts_err *err)
{
    int rc = ts_equilibrium_state(k, eq, y, err);
    if (rc != TS_OK)
        return rc;
    double *f = malloc((size_t)ts_kernel_nstate(k) * sizeof(double));
    if (!f)
        return ts_fail(err, TS_ENOMEM, "control: out of memory");
    rc = ts_kernel_eval(k, y, NULL, f);
    free(f);
    if (rc != TS_OK)
        return ts_fail(err, rc, "control: the kernel refuses the trim (%s)",
                       ts_strerror(rc));
    for (int v = 0, i = 0; v < ts_kernel_nvehicles(k); v++) {
        ts_vehicle_result r;
        ts_kernel_vehicle_result(k, v, &r);
        for (int l = 0; l < r.nloops; l++)
            out[i++] = r.loop_output[l];
    }
    return TS_OK;
}

void ts_control_close(ts_kernel *k)
{
    const ts_system *sys = ts_kernel_system(k);
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        for (int l = 0; l < d->nloops; l++)
            ts_kernel_set_loop_mode(k, v, l, TS_LOOP_CLOSED, 0.0, NULL);
    }
}

/* Room for one vehicle's integrators and actuators. */
#define CTL_STRIDE (TS_VEHICLE_MAX_LOOPS + TS_VEHICLE_MAX_COMPONENTS)

int ts_control_open(ts_kernel *k, const ts_equilibrium *eq, double y[],
                    ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int n0 = ts_kernel_nstate(k), nq = ts_kernel_nq(k);
    int nl = ts_control_nloops(k), nv = ts_kernel_nvehicles(k);
    double *y0 = calloc((size_t)n0, sizeof(double));
    double *vout = calloc((size_t)nl + 1, sizeof(double));
    double *ctl = calloc((size_t)nv * CTL_STRIDE + 1, sizeof(double));
    int rc = y0 && vout && ctl ? TS_OK
                               : ts_fail(err, TS_ENOMEM,
                                         "open loop: out of memory");
    if (rc == TS_OK)
        rc = trim_state(k, eq, y0, vout, err);
    /* The actuators' states, by vehicle, before the layout changes. */
    for (int v = 0; rc == TS_OK && v < nv; v++) {
        double *xi = ctl + (size_t)v * CTL_STRIDE;
        ts_kernel_get_controls(k, v, y0, xi, xi + TS_VEHICLE_MAX_LOOPS);
    }
    for (int v = 0, i = 0; rc == TS_OK && v < nv; v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        for (int l = 0; rc == TS_OK && l < d->nloops; l++, i++)
            rc = ts_kernel_set_loop_mode(k, v, l, TS_LOOP_OPEN, vout[i], err);
    }
    if (rc == TS_OK) {
        memset(y, 0, (size_t)ts_kernel_nstate(k) * sizeof(double));
        memcpy(y, y0, 2 * (size_t)nq * sizeof(double));
        /* A speed integrator is the first controller state in every
         * layout. */
        int zs = ts_kernel_speed_integrator(k);
        if (zs >= 0)
            y[2 * nq + zs] = y0[2 * nq + zs];
        for (int v = 0; v < nv; v++) {
            double *xi = ctl + (size_t)v * CTL_STRIDE;
            ts_kernel_set_controls(k, v, xi, xi + TS_VEHICLE_MAX_LOOPS, y);
        }
    } else {
        ts_control_close(k);
    }
    free(y0);
    free(vout);
    free(ctl);
    return rc;
}

int ts_linearize_open_loop(ts_kernel *k, const ts_equilibrium *eq,
                           const ts_linearize_opts *opts, ts_linear **out,
                           ts_err *err)
{
    *out = NULL;
    double *y = calloc((size_t)ts_kernel_nstate(k), sizeof(double));
    if (!y)
        return ts_fail(err, TS_ENOMEM, "open loop: out of memory");
    int rc = ts_control_open(k, eq, y, err);
    ts_linear *lin = NULL;
    if (rc == TS_OK) {
        lin = ts_linear_alloc(k, err);
        rc = lin ? ts_linearize(k, y, NULL, opts, lin, err) : err->code;
    }
    ts_control_close(k);
    free(y);
    if (rc != TS_OK) {
        ts_linear_free(lin);
        return rc;
    }
    *out = lin;
    return TS_OK;
}

/* L(i w) = -G(i w) of a broken loop. */
typedef struct loop_tf {
    const ts_system *sys;
    const ts_linear *lin;
    int input;
    ts_output out;
    tsi_gain *g;     /* its gain, one factorisation refactored along */
    int failed;
} loop_tf;

static double complex loop_at(loop_tf *t, double w)
{
    double complex v = NAN;
    if (tsi_gain_at(t->g, w, &v, NULL) != TS_OK) {
        t->failed = 1;
        v = NAN;
    }
    return -v;
}

static double cross_gain(double x, void *p)
{
    return cabs(loop_at(p, exp(x))) - 1.0;
}

static double cross_phase(double x, void *p)
{
    return cimag(loop_at(p, exp(x)));
}

/* The root of f in log frequency between x0 and x1 (a sign change). */
static double refine(double (*f)(double, void *), loop_tf *t, double x0,
                     double x1)
{
    gsl_function F = {f, t};
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    double x = 0.5 * (x0 + x1);
    if (s && gsl_root_fsolver_set(s, &F, x0, x1) == GSL_SUCCESS) {
        for (int it = 0; it < CROSS_MAXIT; it++) {
            if (gsl_root_fsolver_iterate(s) != GSL_SUCCESS)
                break;
            x = gsl_root_fsolver_root(s);
            double lo = gsl_root_fsolver_x_lower(s);
            double hi = gsl_root_fsolver_x_upper(s);
            if (gsl_root_test_interval(lo, hi, 0.0, CROSS_RTOL) ==
                GSL_SUCCESS)
                break;
        }
    }
    if (s)
        gsl_root_fsolver_free(s);
    return x;
}

/* Scan and refine one broken loop's L. */
static void margins_of(loop_tf *t, double from, double to, int points,
                       ts_loop_margin *m)
{
    m->gain_margin = INFINITY;
    m->phase_crossover_hz = NAN;
    m->phase_margin_deg = NAN;
    m->gain_crossover_hz = NAN;
    double x0 = log(2 * M_PI * from), x1 = log(2 * M_PI * to);
    double xp = x0;
    double complex Lp = loop_at(t, exp(x0));
    for (int i = 1; i < points && !t->failed; i++) {
        double x = x0 + (x1 - x0) * i / (points - 1);
        double complex L = loop_at(t, exp(x));
        if ((cabs(Lp) - 1.0) * (cabs(L) - 1.0) < 0) {
            double xc = refine(cross_gain, t, xp, x);
            double complex Lc = loop_at(t, exp(xc));
            double pm = 180.0 + carg(Lc) * 180.0 / M_PI;
            if (pm > 180.0)
                pm -= 360.0;
            if (isnan(m->phase_margin_deg) || pm < m->phase_margin_deg) {
                m->phase_margin_deg = pm;
                m->gain_crossover_hz = exp(xc) / (2 * M_PI);
            }
        }
        if (cimag(Lp) * cimag(L) < 0 && creal(Lp) + creal(L) < 0) {
            double xc = refine(cross_phase, t, xp, x);
            double complex Lc = loop_at(t, exp(xc));
            if (creal(Lc) < 0) {
                double gm = 1.0 / cabs(Lc);
                if (gm < m->gain_margin) {
                    m->gain_margin = gm;
                    m->phase_crossover_hz = exp(xc) / (2 * M_PI);
                }
            }
        }
        xp = x;
        Lp = L;
    }
}

int ts_loop_margins(ts_kernel *k, const ts_equilibrium *eq, double from_hz,
                    double to_hz, int points, ts_loop_margin m[], ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    if (!(from_hz > 0 && to_hz > from_hz && isfinite(to_hz)) || points < 2)
        return ts_fail(err, TS_EINVAL, "margins: needs 0 < from < to (Hz) "
                       "and points >= 2, got %g .. %g Hz, %d points",
                       from_hz, to_hz, points);
    gsl_set_error_handler_off();
    int n = ts_kernel_nstate(k), nl = ts_control_nloops(k), rc = TS_OK;
    double *y = calloc((size_t)n, sizeof(double));
    double *vout = calloc((size_t)nl + 1, sizeof(double));
    double *u0 = calloc((size_t)ts_kernel_ninput(k), sizeof(double));
    ts_linear *lin = ts_linear_alloc(k, err);
    if (!y || !vout || !u0 || !lin)
        rc = lin ? ts_fail(err, TS_ENOMEM, "margins: out of memory")
                 : err->code;
    if (rc == TS_OK)
        rc = trim_state(k, eq, y, vout, err);
    char name[TS_IO_NAME];
    for (int v = 0, i = 0; rc == TS_OK && v < ts_kernel_nvehicles(k); v++) {
        const ts_body *bd = &sys->bodies[ts_kernel_vehicle_body(k, v)];
        for (int l = 0; rc == TS_OK && l < bd->vehicle->nloops; l++, i++) {
            ts_loop_margin *mi = &m[i];
            memset(mi, 0, sizeof *mi);
            mi->vehicle = v;
            mi->loop = l;
            snprintf(mi->name, sizeof mi->name, "%s.%s", bd->name,
                     bd->vehicle->loop[l].name);
            /* Broken at its output: the same layout (the integrator
             * stays), its input set to the trim's output. */
            rc = ts_kernel_set_loop_mode(k, v, l, TS_LOOP_BROKEN, 0.0, err);
            loop_tf t = {sys, lin, ts_kernel_input_find(k, mi->name),
                         {0}, NULL, 0};
            snprintf(name, sizeof name, "%s.output", mi->name);
            if (rc == TS_OK)
                rc = ts_response_output_lookup(k, name, &t.out, err);
            if (rc == TS_OK) {
                memset(u0, 0, (size_t)ts_kernel_ninput(k) * sizeof(double));
                u0[t.input] = vout[i];
                rc = ts_linearize(k, y, u0, NULL, lin, err);
            }
            if (rc == TS_OK && !(t.g = tsi_gain_alloc(sys, lin, t.input,
                                                      &t.out, err)))
                rc = err && err->code ? err->code : TS_ENOMEM;
            if (rc == TS_OK) {
                margins_of(&t, from_hz, to_hz, points, mi);
                if (t.failed)
                    rc = ts_fail(err, TS_ESINGULAR, "margins: loop %s: the "
                                 "loop transfer has a pole on the scanned "
                                 "imaginary axis", mi->name);
            }
            tsi_gain_free(t.g);
            ts_kernel_set_loop_mode(k, v, l, TS_LOOP_CLOSED, 0.0, NULL);
        }
    }
    ts_linear_free(lin);
    free(y);
    free(vout);
    free(u0);
    return rc;
}
