/* towstab/health.h: is a result trustworthy, and how close is it to the
 * limits of its method? (doc/converge.md, "Numerical health").
 *
 * Every analysis can end in a number that looks fine and is not: a mode
 * whose damping is smaller than the linearization's error, two modes so
 * close that their shapes mix, an equilibrium whose residual was met but
 * whose links are in compression. The checks here read what the solvers
 * already report (residuals, error bounds, eigenvector conditioning) and
 * return a ts_trust record: trustworthy or not, with the reasons in
 * sentences ("what, how big, against what limit"), plus notes for results
 * that are trustworthy but near a limit. The command line prints the
 * reasons next to the result and writes them to JSON as
 * "trustworthy": false, "reasons": [...], "notes": [...].
 *
 * Nothing here computes anything expensive: O(nmodes^2) for the modes,
 * O(1) for an equilibrium.
 */
#ifndef TOWSTAB_HEALTH_H
#define TOWSTAB_HEALTH_H

#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/linearize.h"
#include "towstab/simulate.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_TRUST_MAX 8      /* reasons (and notes) kept; more are counted */
#define TS_TRUST_TEXT 320   /* characters of one reason or note */

/* A mode's damping ratio is resolved when its error allowance
 * (error_bound / |lambda|) is at most TS_HEALTH_DAMPING_RTOL of |zeta|, or
 * at most TS_HEALTH_DAMPING_ATOL absolute (an undamped mode, zeta = 0 to
 * within 1e-6, is a resolved result). */
#define TS_HEALTH_DAMPING_RTOL 0.1
#define TS_HEALTH_DAMPING_ATOL 1e-6
/* A mode shape is resolved when its eigenvector's error allowance
 * (ts_mode.vector_error, an angle) is at most this, in rad. */
#define TS_HEALTH_VECTOR_ERROR 0.1
/* The stability margin is "near its limit" (a note) when it is less than
 * this many times its error bound. */
#define TS_HEALTH_MARGIN_NOTE 10.0
/* The linearization is "near its limit" (a note) when its truncation
 * error estimate exceeds this fraction of max |A|. */
#define TS_HEALTH_LINEAR_NOTE 1e-6
/* An equilibrium residual within this factor of its target is a note. */
#define TS_HEALTH_RESIDUAL_NOTE 0.1
/* The equilibrium solver's Jacobian: a condition number above FAIL
 * (1 / (10 eps): its solves keep less than one significant digit, so the
 * shape error estimate, computed with them, is not determined either)
 * makes the shape untrustworthy, above NOTE is a note. Below FAIL the
 * shape error estimate (|J^-1 q''| or |J^-1| |mismatch|, to cond eps of
 * itself) decides: above SHAPE_RTOL of the total cable length the shape
 * is untrustworthy. (FAIL was 1 / (1e3 eps) = 4.5e12, the solves' three
 * digits; the two-part tow at 798 links, condition 6.2e12, reaches the
 * same shape within 2.2e-10 m from a start moved by 1e-7 rad a link, its
 * shape error estimate 3.8e-10 m: test_bending.) */
#define TS_HEALTH_CONDITION_FAIL 4.5e14
#define TS_HEALTH_CONDITION_NOTE 1e8
#define TS_HEALTH_SHAPE_RTOL 1e-6

/* The verdict on one result. */
typedef struct ts_trust {
    int trustworthy;   /* 1 unless a reason was added */
    int nreasons;      /* reasons[0..nreasons): why it is not trustworthy */
    char reasons[TS_TRUST_MAX][TS_TRUST_TEXT];
    int nnotes;        /* notes[0..nnotes): trustworthy, but near a limit */
    char notes[TS_TRUST_MAX][TS_TRUST_TEXT];
    int dropped;       /* reasons and notes beyond TS_TRUST_MAX (counted,
                          not kept; a dropped reason still clears
                          trustworthy) */
} ts_trust;

/* A fresh record: trustworthy, no reasons, no notes. */
TS_API void ts_trust_init(ts_trust *t);

/* Add a reason (the result is not trustworthy) or a note, printf-style.
 * Texts longer than TS_TRUST_TEXT - 1 are cut, ending in "...". */
TS_API void ts_trust_fail(ts_trust *t, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;
TS_API void ts_trust_note(ts_trust *t, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Append src's reasons and notes to dst, each prefixed with `prefix`
 * ("equilibrium: "; may be NULL), and clear dst->trustworthy when src is
 * not trustworthy. */
TS_API void ts_trust_merge(ts_trust *dst, const char *prefix,
                           const ts_trust *src);

/* Health of an equilibrium (O(nlinks)). Not trustworthy when it did not
 * converge (residual above its target), when a link is in compression
 * (the rigid-link model allows it; a real cable would be slack there),
 * when the solver's Jacobian is nearly singular or the shape error it
 * implies exceeds TS_HEALTH_SHAPE_RTOL of the cable length. Notes: a
 * residual within TS_HEALTH_RESIDUAL_NOTE of its target, an
 * ill-conditioned Jacobian. Writes into t, which the caller
 * initialised. */
TS_API void ts_health_equilibrium(const ts_system *sys,
                                  const ts_equilibrium *eq, ts_trust *t);

/* A time integration: more than TS_HEALTH_SIM_REJECT_NOTE rejected trial
 * steps per accepted step is a note (the tolerance is near what the method
 * delivers, or the scene is stiff for it), and so is any re-chart; a mean
 * accepted step below TS_HEALTH_SIM_STEP_FAIL of the run makes it
 * untrustworthy (rounding of the time, not the tolerance, sets the
 * error). */
#define TS_HEALTH_SIM_REJECT_NOTE 1.0
#define TS_HEALTH_SIM_STEP_FAIL 1e-10

/* Health of a simulation run from its options and statistics (O(1)).
 * Writes into t, which the caller initialised. */
TS_API void ts_health_simulation(const ts_sim_opts *o,
                                 const ts_sim_stats *st, ts_trust *t);

/* Per-mode health. */
typedef struct ts_mode_health {
    double freq_error_hz;   /* error allowance of the frequency:
                               error_bound / (2 pi), Hz */
    double damping_error;   /* of the damping ratio: error_bound / |lambda|
                               (INFINITY at lambda = 0) */
    int damping_resolved;   /* see TS_HEALTH_DAMPING_RTOL / _ATOL */
    int nearest;            /* index of the nearest other computed mode
                               (|lambda - lambda_k|, conjugates included),
                               -1 when there is none */
    double gap;             /* that distance, 1/s */
    double vector_error;    /* ts_mode.vector_error, rad */
    int shape_resolved;     /* vector_error <= TS_HEALTH_VECTOR_ERROR */
    int trustworthy;        /* the eigenvalue and its damping are resolved
                               (the shape is judged apart: a degenerate
                               pair has exact eigenvalues and mixed
                               shapes) */
} ts_mode_health;

/* Health of a mode analysis of system sys (used to name a node at the
 * water surface; may be NULL). mh[e->nmodes] (may be NULL) receives each
 * mode's health; t (initialised by the caller) the overall verdict.
 * Not trustworthy when: a node other than the tow point sits within a
 * linearization step of the water surface (A is then the mean of
 * one-sided derivatives); some mode's damping ratio is not resolved by its
 * error bound; an ARPACK Ritz vector's residual exceeds 1e-8 of ||A||.
 * Notes: the stability margin below TS_HEALTH_MARGIN_NOTE times its error
 * (stated with the ratio: the linearization error against the smallest
 * damping); close modes whose shapes are not resolved (the pair's motion
 * is determined, each shape is not); a linearization error estimate above
 * TS_HEALTH_LINEAR_NOTE of max |A|; modes not covered (ARPACK subset).
 * Returns TS_OK or TS_ENOMEM. */
TS_API int ts_health_modes(const ts_system *sys, const ts_linear *lin,
                           const ts_eigen *e, ts_mode_health mh[],
                           ts_trust *t, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
