/* towstab/equilibrium.h: steady configurations, straight tow and steady turn
 * (doc/model.md section 5; Kamman & Nguyen eq. 55).
 *
 * An equilibrium is a state with q' = 0 and q''(q) = 0 for the kernel's
 * frame (speed V, turn rate Omega). Convergence is judged on forces: the
 * largest unbalanced nodal force max_k |M_k r''_k| must be below `tol`
 * times the largest force in the system (largest link tension or nodal
 * load); both are reported.
 *
 * Methods (doc/equilibrium.md):
 *  - shooting: marching from the free ends, with Powell-hybrid shooting on
 *    the free-end positions (3 unknowns per free end) and continuation in
 *    turn rate when needed. O(nlinks) per march. Not for bending (EI > 0).
 *  - newton: Newton on q''(q) = 0 over all angles with a central-difference
 *    Jacobian (LAPACK dgesv), a backtracking line search and continuation in
 *    turn rate, started from the straight-tow march. O(nlinks^2) per
 *    Jacobian and O(nlinks^3) per solve: the general fallback.
 *  - auto: shooting when it applies and converges, else newton.
 */
#ifndef TOWSTAB_EQUILIBRIUM_H
#define TOWSTAB_EQUILIBRIUM_H

#include "towstab/error.h"
#include "towstab/kernel.h"
#include "towstab/progress.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_EQ_AUTO = 0,
    TS_EQ_SHOOTING = 1,
    TS_EQ_NEWTON = 2
} ts_eq_method;

typedef struct ts_equilibrium_opts {
    double tol;           /* relative force residual, default 1e-10 */
    int max_iter;         /* per continuation step, default 100 */
    ts_eq_method method;  /* default TS_EQ_AUTO */
    const double *guess;  /* [3 nlinks] link unit directions to start
                             from, e.g. a neighbouring equilibrium's
                             (continuation in a sweep), or NULL; default
                             NULL. Shooting starts from the free-end
                             positions they give (at the full turn rate,
                             falling back to its own schedule from
                             hanging); Newton from the shape itself
                             (elastic links at the strain of the tension
                             a rigid copy carries there) instead of the
                             straight-tow march */
    int coarse_above;     /* with bending stiffness and no guess, more
                             links than this: Newton starts from the
                             equilibrium of a copy with each cable's
                             links halved (solved the same way, so down
                             to this many), its shape interpolated, at
                             the full bending; should that fail, from
                             the continuation in bending. 0: always
                             the continuation. Default 64
                             (doc/equilibrium.md) */
    ts_progress_fn progress; /* towstab/progress.h: called as the Newton
                             solver goes (what "equilibrium", done: the
                             columns of its Jacobian formed, of the
                             unknowns); a nonzero return stops it with
                             TS_ECANCEL, the state reached so far and its
                             residual recorded (converged 0). Shooting
                             (O(nlinks), fast) is not polled. Default
                             NULL */
    void *progress_data;
} ts_equilibrium_opts;

typedef struct ts_equilibrium {
    int nlinks, nnodes;
    int converged;        /* 1 only when residual <= tolerance */
    int iterations;       /* solver iterations over all continuation steps */
    long evaluations;     /* kernel evaluations plus marches */
    int continuation_steps;
    double residual;      /* max unbalanced nodal force / force_scale */
    double force_scale;   /* largest force in the system, N */
    double tolerance;     /* the target residual */
    ts_eq_method method;  /* the method that produced the result */
    int nstate;           /* length of y: 2 ts_kernel_nq() */
    double *y;            /* [nstate] state in the kernel's charts */
    double *directions;   /* [3 nlinks] link unit vectors */
    double *positions;    /* [3 nnodes] node positions, m (M frame) */
    double *tensions;     /* [nlinks] N */
    double tow_force[3];  /* force of the cables on the tow point, N */
    double top_tension;   /* |tow_force|, N */
    double min_tension;   /* smallest link tension, N (< 0: compression) */
    double condition;     /* condition number of the solver's last
                             Jacobian (shooting: the 1-norm condition of
                             d mismatch / d free-end positions, with
                             vehicles times that of the outer problem's;
                             Newton: the Skeel condition
                             || |J^-1| |J| ||_inf of J = d q'' / d q,
                             which the rows' scaling does not change);
                             NaN if none */
    double shape_error;   /* node position error it implies, m: Newton
                             |J^-1 q''| times the cable length, shooting
                             |J^-1| |mismatch|, with vehicles plus the
                             nodes' move over the next outer Newton step
                             (doc/equilibrium.md); NaN if none */
    int nvehicles;
    double *attitudes;    /* [9 nvehicles] each vehicle's attitude, body to
                             M, row-major (ts_kernel_vehicle_body order) */
    int ncontrol;         /* controller states of the kernel solved with */
    double *controls;     /* [ncontrol] their values */
    double control_residual; /* the controllers' settling: the largest
                             |integrator rate| (a loop's error) over its
                             scale (the cable length for depth, 1 rad for
                             angles) and |actuator rate| times its time
                             constant (rad); converged needs it <= tol
                             too; 0 without controllers */
    ts_vehicle_result *vehicles; /* [nvehicles] attitude, flow angles,
                             loads and deflections of each vehicle */
    /* The steady motion of the mean frame M: the kernel's speed and turn
     * rate, or, with a towing vehicle (doc/towing-vehicle.md), the ones
     * solved with its trim, and its speed controller's thrust bias (N;
     * 0 without one). */
    double speed, turn_rate, thrust_bias;
    double turn_deflection; /* the deflection added to the towing
                             vehicle's turn surface to turn at the given
                             rate (ts_tow.turn_surface), rad; 0 */
    double motion_step[2]; /* with a towing vehicle, Newton's next step
                             (from the last Jacobian) of the two unknowns
                             of the steady motion: [0] the speed (m/s) or
                             the speed controller's bias (N), [1] the turn
                             rate (rad/s) or turn_deflection (rad), as
                             solved; their solver error to first order
                             (doc/towing-vehicle.md, section 3). NaN
                             without a towing vehicle or a Jacobian */
} ts_equilibrium;

TS_API void ts_equilibrium_opts_default(ts_equilibrium_opts *o);

/* Allocate a result for a built system; NULL on failure. */
TS_API ts_equilibrium *ts_equilibrium_alloc(const ts_system *sys,
                                            ts_err *err);
TS_API void ts_equilibrium_free(ts_equilibrium *eq);

/* Solve for the equilibrium of kernel k's system at k's frame (speed and
 * turn rate; the frame's rates must be zero, and a turn cannot be steady in
 * a current). On success returns TS_OK with eq->converged = 1, and leaves
 * the kernel's charts consistent with eq->y. On failure returns TS_ECONV
 * (message: how far it got), TS_ESINGULAR or TS_EDOMAIN, with
 * eq->converged = 0; eq then holds the best iterate, for diagnosis only. */
TS_API int ts_equilibrium_solve(ts_kernel *k, const ts_equilibrium_opts *opts,
                                ts_equilibrium *eq, ts_err *err);

/* Set the vehicles' attitudes (at rest in M) and the controller states of
 * equilibrium eq in state y[nstate] of kernel k (any kernel of eq's system
 * whose controller layout matches). TS_OK, or TS_EINVAL when the layouts
 * differ. */
TS_API int ts_equilibrium_set_bodies(ts_kernel *k, const ts_equilibrium *eq,
                                     double y[], ts_err *err);

/* The whole state y[nstate] of equilibrium eq in kernel k's charts (any
 * kernel of eq's system with the same controller layout): the links'
 * directions and strains (re-charted with TS_CHART_RECHART), the
 * vehicles' attitudes and the controller states, at rest. TS_OK,
 * TS_EINVAL (layouts differ) or TS_ENOMEM. */
TS_API int ts_equilibrium_state(ts_kernel *k, const ts_equilibrium *eq,
                                double y[], ts_err *err);

/* Name of a method ("auto", "shooting", "newton"). */
TS_API const char *ts_eq_method_name(ts_eq_method m);

/* An elastic link's strain at the equilibrium, e = T / EA (exact: at
 * rest the tension is EA e; a slack link, T = 0, gives 0); 0 for a rigid
 * link. */
TS_API double ts_equilibrium_strain(const ts_system *sys,
                                    const ts_equilibrium *eq, int link);

/* Cable c's stretched length at the equilibrium, sum of l (1 + e) over
 * its links (m); its length for a rigid cable. */
TS_API double ts_equilibrium_cable_length(const ts_system *sys,
                                          const ts_equilibrium *eq, int c);

#ifdef __cplusplus
}
#endif
#endif
