/* lib/esdirk.h (internal): an L-stable implicit Runge-Kutta stepper for
 * stiff, lightly damped systems, y' = f(t, y), one step at a time.
 *
 * SUNDIALS ARKODE (ARKStep, fully implicit) with the ESDIRK 5(4) table
 * ARK548L2SA (Kennedy & Carpenter 2019: 8 stages, order 5, embedded
 * order 4, L-stable and stiffly accurate), modified Newton on each stage
 * with the user's dense Jacobian, and the iteration matrix I - gamma h J
 * factored by LAPACK (dgetrf/dgetrs; all stages share gamma, so one LU
 * serves a step and usually many). ARKODE re-evaluates the Jacobian and
 * refactors only when the Newton iteration slows or gamma h drifts.
 *
 * Why this method (doc/simulate.md, "Stiff integrators"): the stiffness of
 * an elastic cable is its axial modes, kHz and nearly undamped. BDF of
 * order 3-5 is unstable near the imaginary axis and must resolve them;
 * an A-stable but not L-stable method (Gauss, rk4imp) carries them
 * undamped; an L-stable method steps over them, damping what the
 * tolerance does not ask it to resolve.
 *
 * Callbacks: f returns 0, > 0 for a state it refuses (the step is retried
 * shorter) or < 0 for a fatal failure; jac writes df/dy column-major into
 * J[n * n] with the same return convention. Costs per step: 7 implicit
 * stages of a few Newton iterations, each one f and one O(n^2) LU solve;
 * an O(n^3) LU and a Jacobian now and then. With a structured solver
 * (tsi_ode_lsys) the solves and factorisations cost what it costs: O(n)
 * for the sparse model of lib/shift.h. */
#ifndef TOWSTAB_LIB_ESDIRK_H
#define TOWSTAB_LIB_ESDIRK_H

#include "towstab/error.h"

typedef int (*tsi_ode_fn)(double t, const double y[], double dydt[],
                          void *params);
typedef int (*tsi_ode_jac)(double t, const double y[], double J[],
                           void *params);

/* A structured Newton solver instead of a dense Jacobian: setup prepares
 * to solve (I - gamma J) x = b with J = df/dy at (t, y), re-evaluating J
 * unless jok (then the last J is reused; *jcur = 1 when J was
 * re-evaluated), and factors; solve writes x[n] for b[n]. Return codes as
 * f. */
typedef struct tsi_ode_lsys {
    int (*setup)(double t, const double y[], double gamma, int jok,
                 int *jcur, void *params);
    int (*solve)(double x[], const double b[], void *params);
    int linear;  /* 1: f is linear in y with a constant J (f = J y + g(t)),
                    and setup makes the exact I - gamma J: the ESDIRK
                    takes one Newton iteration per stage, without a
                    convergence test (ARKStepSetLinear; bdf ignores it);
                    0 (a brace initializer's default): Newton as usual */
} tsi_ode_lsys;

typedef struct tsi_esdirk tsi_esdirk;

typedef struct tsi_esdirk_stats {
    long steps;       /* accepted steps */
    long rejected;    /* error-test and Newton-convergence failures */
    long setups;      /* LU factorisations */
    double h_last;    /* s: last step taken */
    double h_next;    /* s: step planned next */
} tsi_esdirk_stats;

/* A stepper for n equations, relative and absolute tolerances rtol and
 * atol (ARKODE's weighted RMS norm), first step h_init (> 0). NULL with
 * err set on failure. Call tsi_esdirk_reset before the first step. */
tsi_esdirk *tsi_esdirk_alloc(int n, tsi_ode_fn f, tsi_ode_jac jac,
                             void *params, double rtol, double atol,
                             double h_init, ts_err *err);

/* The same with a structured Newton solver (lsys, copied): no n x n
 * matrix is formed; ARKODE's rules for when to re-evaluate J (lsys's jok)
 * and when to refactor are unchanged. */
tsi_esdirk *tsi_esdirk_alloc_lsys(int n, tsi_ode_fn f,
                                  const tsi_ode_lsys *lsys, void *params,
                                  double rtol, double atol, double h_init,
                                  ts_err *err);
/* Either of the above (jac or lsys non-NULL) with bdf = 1: SUNDIALS
 * CVODE's variable-step BDF of order 1 to 2 instead of the ESDIRK (one
 * Newton solve per step; A- and L-stable); bdf = 0 is the ESDIRK. */
tsi_esdirk *tsi_esdirk_alloc_method(int n, tsi_ode_fn f, tsi_ode_jac jac,
                                    const tsi_ode_lsys *lsys, void *params,
                                    double rtol, double atol, double h_init,
                                    int bdf, ts_err *err);
void tsi_esdirk_free(tsi_esdirk *s);

/* Start again from (t, y): step-size history, Jacobian and factorisation
 * are dropped; the statistics keep counting. */
int tsi_esdirk_reset(tsi_esdirk *s, double t, const double y[], ts_err *err);

/* One step from *t towards tstop (> *t), never past it: *t and y[n] are
 * advanced. TS_EINTEGRATOR with ARKODE's reason in err on failure (*t and
 * y unchanged). */
int tsi_esdirk_step(tsi_esdirk *s, double tstop, double *t, double y[],
                    ts_err *err);

/* The solution at t inside the last step (ARKODE's Hermite interpolant,
 * degree 4 for this order-5 method) into y[n]. */
int tsi_esdirk_interpolate(tsi_esdirk *s, double t, double y[], ts_err *err);

void tsi_esdirk_get_stats(const tsi_esdirk *s, tsi_esdirk_stats *st);

#endif
