/* towstab/eigen.h: eigenvalues and mode shapes of a linear model
 * z' = A z (doc/model.md section 6; doc/linear.md).
 *
 * Two methods:
 *  - lapack: every eigenvalue and right eigenvector of the dense A (LAPACK
 *    dgeevx with balancing), plus left eigenvectors and the eigenvalue
 *    condition numbers. O(n^3) time,
 *    O(n^2) memory (n = nstate).
 *  - arpack: the eigenvalues nearest a shift sigma = i 2 pi target (target
 *    in Hz; 0 gives the lowest modes, smallest |lambda|) by implicitly
 *    restarted Arnoldi (ARPACK) in shift-invert mode, OP = (A - sigma I)^-1:
 *    dnaupd/dneupd for a real shift, znaupd/zneupd for a complex one. The
 *    operator is a solve with the sparse linear model (ts_linear.desc,
 *    doc/linear.md section 2b): one KLU factorisation of the shifted node
 *    equations, O(nlinks), then O(nlinks) per application.
 *  - auto: arpack when a number of modes is asked for and nstate >=
 *    arpack_min_states or the dense A was not formed, else lapack.
 * lapack needs the dense A, arpack the sparse model.
 *
 * Threads: solves on different linear models may run at once (a sweep's
 * threads); ARPACK's, which keeps Fortran state between calls, are taken
 * one at a time.
 *
 * A mode is one eigenvalue with Im >= 0: one of each complex-conjugate
 * pair, or a real (non-oscillatory) eigenvalue. Units: lambda in 1/s,
 * frequency in Hz, period and time constant in s.
 */
#ifndef TOWSTAB_EIGEN_H
#define TOWSTAB_EIGEN_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/linearize.h"
#include "towstab/progress.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_EIG_AUTO = 0,
    TS_EIG_LAPACK = 1,
    TS_EIG_ARPACK = 2
} ts_eig_method;

/* ts_eigen_opts.arpack_tol: the tolerance chosen by the model. */
#define TS_ARPACK_TOL_AUTO (-1.0)

typedef struct ts_eigen_opts {
    ts_eig_method method;  /* default TS_EIG_AUTO */
    int count;             /* modes wanted; 0 (default): all (lapack) */
    double target_hz;      /* modes nearest i 2 pi target_hz (Hz, >= 0);
                              default 0: the lowest modes */
    int arpack_min_states; /* auto uses arpack from this size on when
                              count > 0; default 1200 */
    double arpack_tol;     /* relative Ritz tolerance of the modes' runs
                              (0: machine precision); default
                              TS_ARPACK_TOL_AUTO: 1e-6 with the sparse
                              model's error estimate (each Ritz value's
                              own error is then measured, ritz_error),
                              1e-10 otherwise; the rightmost search uses
                              1e-6 or this when looser */
    int arpack_max_iter;   /* restarts; default 1000 */
    int vectors;           /* 1 (default): keep the right eigenvectors */
    int rightmost;         /* 1 (default): with arpack, also search the
                              whole spectrum for the eigenvalues with the
                              largest real parts (doc/linear.md, section
                              3); the verdict covers what it finds */
    ts_progress_fn progress; /* towstab/progress.h: called with arpack as
                              it goes, at every operator application
                              (what "eigensolve": done the applications,
                              total NAN, unknown; what "rightmost search":
                              done the shifts run, of at most total); a
                              nonzero return stops it with TS_ECANCEL
                              (nothing kept: no Ritz value is final before
                              its run ends). lapack (one LAPACK call) is
                              not polled. Default NULL */
    void *progress_data;
} ts_eigen_opts;

typedef struct ts_mode {
    double re, im;          /* eigenvalue, 1/s; im >= 0 */
    double freq_hz;         /* im / (2 pi); 0 for a real mode */
    double period_s;        /* 1 / freq_hz; INFINITY for a real mode */
    double damping_ratio;   /* -re / |lambda|: 1 for a decaying real mode,
                               -1 for a growing one, 0 undamped */
    double time_constant_s; /* -1 / re (< 0: growth time); INFINITY at 0 */
    double condition;       /* eigenvalue condition number kappa (>= 1) of
                               the balanced matrix (1 / RCONDE of LAPACK
                               dgeevx); NaN when not computed (arpack) */
    double error_bound;     /* error allowance of lambda (1/s): 10 times
                               the first-order change of lambda by the
                               linearization's error estimate E
                               (ts_linear.Aerr), |u^H E v| / |u^H v|
                               (lapack; ||E v|| / |v| with arpack, which
                               has no left vector u, E the sparse model's
                               error estimate), plus rounding
                               kappa eps ||A_bal|| (lapack: the balanced
                               matrix's 1-norm and condition number from
                               dgeevx) or ritz_error (arpack) */
    double residual;        /* ||A v - lambda v|| / (|lambda| |v|), A
                               applied through the sparse model's S_inf
                               when there is one (whose rounding floor,
                               growing like links^3, dominates it on long
                               cables: 3e-5 at 10 000 links); NaN when not
                               computed (lapack: backward stable) */
    double ritz_error;      /* the Ritz value's own error estimate, 1/s
                               (arpack): with the sparse model and its
                               error estimate the pencil's Newton
                               correction |w^T S(lambda) x| /
                               |w^T S'(lambda) x| (w the left null vector,
                               doc/linear.md section 3), otherwise the
                               residual ||A v - lambda v|| / |v|; NaN with
                               lapack */
    double vector_condition;/* conditioning of the right eigenvector: the
                               largest kappa_k ||A_bal||_1 / |lambda -
                               lambda_k| over the other eigenvalues k
                               (conjugates included; kappa_k their
                               condition numbers), the sensitivity of the
                               shape to relative changes of A from its
                               nearest neighbour (~ 1 / RCONDV of
                               dgeevx); NaN with arpack */
    double vector_error;    /* error allowance of the unit eigenvector (an
                               angle, rad): 10 times (as error_bound is
                               of the eigenvalue's) its first-order
                               perturbation estimate, sqrt(sum |c_k|^2)
                               over the 8
                               eigenvalues nearest (conjugates included),
                               c_k = |u_k^H E v| / (|lambda - lambda_k|
                               |u_k^H v_k|) with E the linearization's
                               error estimate, plus rounding (lapack);
                               (the first-order eigenvalue change + eps
                               ||A||_F) / distance to the nearest other
                               computed eigenvalue (arpack). The
                               estimate alone fell 3.4 times short on
                               the slowest real modes of a 500-link
                               cable (test_eigen_arpack). Large for
                               close modes, whose shapes can mix
                               (towstab/health.h); INFINITY for an
                               exactly double eigenvalue; for a neutral
                               mode, the sine of the computed vector's
                               angle to its symmetry's span */
    int neutral;            /* -1, or the towing vehicle's neutral mode by
                               symmetry this is (index in lin->neutral,
                               towstab/linearize.h): its eigenvalue and
                               shape are the symmetry's exact ones, the
                               computed eigenvalue lies within
                               error_bound of it, and the verdict leaves
                               it out (doc/linear.md section 3a) */
} ts_mode;

typedef struct ts_eigen {
    int nstate;
    int nmodes;             /* modes stored */
    int neig;               /* eigenvalues they stand for (2 per complex) */
    int complete;           /* 1 when every eigenvalue of A is covered */
    int nneutral;           /* modes recognised as neutral by symmetry
                               (ts_mode.neutral >= 0) */
    ts_eig_method method;   /* the method used */
    double target_hz;
    ts_mode *modes;         /* [nmodes] by frequency, then |lambda| */
    double *vec_re, *vec_im;/* [nstate * nmodes] right eigenvectors, column
                               m for mode m, unit 2-norm, largest entry
                               real; NULL unless opts.vectors */
    double max_real;        /* max Re lambda over the eigenvalues the
                               verdict covers (every one but the neutral
                               modes by symmetry), 1/s */
    double max_real_error;  /* error_bound of that eigenvalue, 1/s */
    double undecided_real;  /* TS_MARGINAL: the Re of the covered
                               eigenvalue whose bound reaches 0 furthest
                               (Re + bound largest), 1/s; it may not be the
                               rightmost; NaN otherwise */
    double undecided_error; /* its error bound, 1/s; NaN otherwise */
    ts_mode rightmost;      /* that eigenvalue (Im >= 0) as a mode: every
                               field but the shape's; with lapack the
                               rightmost of all */
    int verdict;            /* TS_STABLE, TS_UNSTABLE or TS_MARGINAL, over
                               every eigenvalue with lapack; with arpack
                               over the modes and the 4 rightmost
                               eigenvalues the search found */
    double top_hz;          /* the highest band top of the discretisation
                               the search estimated, Hz (NaN without it) */
    int sweep_shifts;       /* shifts of the rightmost search (0: none) */
    int sweep_failed;       /* of those, runs that did not converge */
    int sweep_rejected;     /* Ritz pairs of the search dropped for their
                               residual (not converged) */
    int sweep_found;        /* eigenvalues it found besides the modes (2
                               per complex pair) */
    int arpack_iterations;  /* restarts used (arpack, all runs) */
    int arpack_ops;         /* applications of OP (arpack, all runs) */
    int arpack_nconv;       /* Ritz values converged (arpack, all runs) */
} ts_eigen;

/* Verdicts: stable when every eigenvalue covered has re + error_bound < 0;
 * unstable when one has re - error_bound > 0; marginal otherwise (a margin
 * smaller than its error, e.g. an undamped system). */
enum { TS_STABLE = 0, TS_UNSTABLE = 1, TS_MARGINAL = 2 };

TS_API void ts_eigen_opts_default(ts_eigen_opts *o);

/* Check opts for a linearization of `nstate` states, as ts_eigen_solve
 * does before it computes anything, so that a caller can refuse bad
 * options before the equilibrium and the linearization: TS_OK or
 * TS_EINVAL naming the number of states and the limit broken. */
TS_API int ts_eigen_check(int nstate, const ts_eigen_opts *opts,
                          ts_err *err);

/* The method ts_eigen_solve uses for nstate states with opts (auto
 * resolved: ARPACK with a count at or above arpack_min_states). */
TS_API ts_eig_method ts_eigen_method(int nstate, const ts_eigen_opts *opts);

/* Modes of lin->A. On success *out is a new result (free with
 * ts_eigen_free). Returns TS_OK, TS_EINVAL (bad options: count < 0 or
 * above the number of modes possible, target < 0, arpack asked with
 * count 0), TS_ELAPACK (LAPACK or ARPACK info, named in the message),
 * TS_ESINGULAR (A - sigma I singular: move the target), TS_ECONV (ARPACK
 * did not converge within arpack_max_iter) or TS_ENOMEM. */
TS_API int ts_eigen_solve(const ts_linear *lin, const ts_eigen_opts *opts,
                          ts_eigen **out, ts_err *err);
TS_API void ts_eigen_free(ts_eigen *e);

/* Name of a method ("auto", "lapack", "arpack") and of a verdict
 * ("stable", "unstable", "marginal"). */
TS_API const char *ts_eig_method_name(ts_eig_method m);
TS_API const char *ts_verdict_name(int verdict);

/* 1 when e's verdict is marginal although its rightmost eigenvalue is
 * decided (max_real + max_real_error < 0): another eigenvalue's bound,
 * undecided_real +- undecided_error, reaches 0; else 0. */
TS_API int ts_eigen_other_undecided(const ts_eigen *e);

/* Node displacements of mode m: amp[3 nnodes] (m per unit of the
 * normalisation, >= 0) and phase[3 nnodes] (rad) for x, y, z of every
 * node, from the angle part of the eigenvector through the link geometry
 * (ts_linear_node_displacements). Normalised so that the largest
 * component has amplitude 1 and phase 0. Needs vectors. Returns TS_OK or
 * TS_EINVAL (no vectors, m out of range). */
TS_API int ts_eigen_mode_shape(const ts_system *sys, const ts_linear *lin,
                               const ts_eigen *e, int m, double amp[],
                               double phase[], ts_err *err);

/* One-line description of mode m's shape into buf: the motion's plane
 * relative to the equilibrium's vertical plane (in-plane, out-of-plane or
 * mixed with the out-of-plane share), the cable with the largest motion,
 * its number of interior nodes (zero crossings) and mode order, and the
 * node that moves most, e.g. "in-plane, cable 'cable' order 2 (1 node),
 * largest at sphere". Needs vectors; writes "" otherwise. */
TS_API void ts_eigen_describe(const ts_system *sys, const ts_linear *lin,
                              const ts_eigen *e, int m, char *buf,
                              size_t size);

#ifdef __cplusplus
}
#endif
#endif
