/* towstab/cost.h: what an analysis will cost, before it runs
 * (doc/manual.md, "Long runs"; issue: say the cost of a long run before
 * it starts, and how to reduce it).
 *
 * The estimates are lower bounds built from what is known before a run:
 * the kernel's cost per evaluation (measured on this machine: a few
 * evaluations of the system at rest), the number of steps an integrator
 * cannot do without, and the size of dense matrices.
 *
 * Steps of a simulation, at least the largest of
 *  - the output samples (steps stop at every output time, esdirk excepted),
 *  - TS_COST_STEPS_PER_PERIOD per period of the fastest periodic
 *    tow-point excitation over the run (no integrator follows a sinusoid
 *    with fewer),
 *  - for the explicit integrators, t_end omega_max / TS_COST_STABILITY:
 *    omega_max bounds the fastest mode of the discretised system, the
 *    highest transverse mode of a beaded string 2 sqrt(T / (m l)) with T
 *    the largest tension the loads allow (ts_system_check_loads' sum), m
 *    the lightest node (half a link, added mass included) and l the
 *    shortest link, and for elastic links the highest axial mode
 *    2 sqrt(EA / (m l)) (doc/elastic.md). An explicit method's steps are
 *    bounded by omega h of order one on the true fastest mode; omega_max
 *    overestimates it (the real tension is below T, most nodes carry a
 *    whole link), so the constant is measured: rk8pd took steps with
 *    omega_max h = 18 to 19 on Kamman's example 1 at rest (20 links:
 *    4.3 steps per simulated s, omega_max 84 rad/s) and on the drop test
 *    with 100000 links (1.0e4 steps per s, omega_max 1.9e5 rad/s);
 *    TS_COST_STABILITY = 25 keeps the count a lower bound.
 * Evaluations per step: the stages of the method (rk8pd 13, rkf45 6, the
 * implicit ones at least their stages); an implicit method forms at least
 * one Jacobian (2 (n + 9) evaluations) and factors it (n^3 / 3 flops),
 * except esdirk without a vehicle, whose Newton matrix comes from the
 * sparse model (TS_COST_SPARSE_EVALUATIONS, O(links) factorisations).
 * Dense linear algebra is costed at TS_COST_FLOPS flop/s, a fast
 * machine's rate, so that the bound stays a bound. Nothing is allocated
 * but the kernel whose evaluations are timed; nothing prints.
 */
#ifndef TOWSTAB_COST_H
#define TOWSTAB_COST_H

#include "towstab/eigen.h"
#include "towstab/error.h"
#include "towstab/excitation.h"
#include "towstab/simulate.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Steps per period of an excitation no integrator does with fewer. */
#define TS_COST_STEPS_PER_PERIOD 4.0
/* omega_max h of an explicit method's steps, at most (measured, above). */
#define TS_COST_STABILITY 25.0
/* Dense linear algebra rate assumed, flop/s (an optimistic one). */
#define TS_COST_FLOPS 5e10

typedef struct ts_cost {
    double seconds;      /* the run takes at least this long here, s */
    double steps;        /* integrator steps, at least (simulations) */
    double evaluations;  /* kernel evaluations, at least */
    double flops;        /* dense linear algebra, at least */
    double bytes;        /* memory of the largest arrays (history, dense
                            matrices), bytes */
    double eval_s;       /* one kernel evaluation, measured, s */
    double omega_max;    /* fastest mode bound, rad/s (simulations) */
    char what[320];      /* what sets the cost, in a sentence */
    char reduce[160];    /* what reduces it (scene keys: links, t_end,
                            sample, integrator, method) */
} ts_cost;

/* The fastest mode of sys's discretisation under motion mb (rad/s): the
 * beaded-string bound above, and the axial one of elastic links. */
TS_API double ts_cost_fastest_mode(const ts_system *sys,
                                       const ts_motion_bound *mb);

/* The cost of a nonlinear simulation of sys with options o under ex (may
 * be NULL) from the frame of sys's tow. TS_OK, TS_ENOMEM. */
TS_API int ts_cost_simulate(const ts_system *sys, const ts_excitation *ex,
                                const ts_sim_opts *o, ts_cost *e,
                                ts_err *err);

/* Kernel evaluations the sparse linearization costs at least: 18
 * perturbation groups, each 2 residual evaluations (without the error
 * estimate), a residual evaluation costing at least half a kernel
 * evaluation (it skips the elimination). */
#define TS_COST_SPARSE_EVALUATIONS 18.0

/* The cost of the eigen analysis of an n-state linearization by method m
 * (TS_EIG_LAPACK: a dense nonsymmetric eigenproblem with vectors, about
 * 30 n^3 flops and 6 n^2 doubles; ARPACK on the dense A, when it is
 * formed: its LU, 2/3 n^3 flops; ARPACK on the sparse model: O(links),
 * counted as 0), plus the linearization: the dense model's 2 (n + 9)
 * evaluations of sys's kernel (below the linearizer's dense_max_states,
 * with LAPACK, or with a towing vehicle at the root) or the sparse model's
 * TS_COST_SPARSE_EVALUATIONS. */
TS_API int ts_cost_modes(const ts_system *sys, int n, ts_eig_method m,
                             ts_cost *e, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
