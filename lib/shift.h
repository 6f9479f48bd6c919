/* shift.h (internal): solves with the sparse linear model at a shift s,
 * shared by the eigen analysis, the frequency response and the stiff
 * integrator (doc/linear.md, sections 2-4).
 *
 * The kernel's state y = (q, q') maps to node displacements dr = J q and
 * velocities dr' = J q' (J local: one link at a time, lib/descriptor.h).
 * With y' = A y, solving (s I - A) y = w for y is solving, for the node
 * displacements and the link tensions,
 *
 *     (s^2 M + s C + K) dr + N dt = M (s J w_q + J w_q') + C J w_q
 *     rigid link:   n . (dr_k - dr_p) = 0
 *     elastic link: (EA/l + s Cv) n.dd + ... - dt = Cv n.(J w_q)_k - ...
 *
 * (the matrix S(s) of lib/descriptor.h), then q = J^-1 dr and q' = s q -
 * w_q. The factorisation is KLU's (SuiteSparse: block triangular form,
 * AMD ordering, left-looking LU with partial pivoting), real or complex,
 * over KLU's ordering of the pattern computed once per system. Both the
 * factorisation and each solve are O(nlinks). A itself is applied with
 * S_inf = [[M, N], [acceleration constraints]], likewise O(nlinks).
 *
 * The maps are exact about a state at rest relative to M (an equilibrium);
 * about a moving state they omit the terms of J' (first order in the link
 * rates), which the stiff integrator's Newton iteration absorbs.
 *
 * Towed vehicles are in the sparse model (their angles among the points,
 * their controller states among the unknowns, lib/descriptor.h): y =
 * (q, q', c), the controller rows' right-hand side wc - Hv J wq, S_inf's
 * controller rows the identity (c' = Hr p + Hv p' + Hc c).
 *
 * Towing vehicles' cyclic states cut for the eigen analysis (ts_descriptor
 * cut, the eigen analysis's copy of the model: doc/linear.md section 3a):
 * the shifted solves take the cut states' entries of b as zero and set
 * theirs to -b_j / s (their columns of A are zero, their rows cut to
 * -s x_j = b_j), A's action zeroes them in its input and output, and
 * tsi_shift_eig_error takes the whole model's eigenvector (v_j = v_(nq+j)
 * / lam).
 *
 * Without the sparse model (ts_linear.desc NULL: TS_LIN_DENSE)
 * the same solves use the dense A = [[0, I, 0], [K, C, E], [F, G, H]]
 * (nc controller states last): with x = (x1, x2, x3), x2 = b1 + s x1,
 * x3 = (H - sI)^-1 (b3 - F x1 - G x2) and P(s) x1 = b2 - (C - sI) b1 -
 * E (H - sI)^-1 (b3 - G b1), P(s) = K + s C - s^2 I - E (H - sI)^-1 (F +
 * s G): one LAPACK LU of P, O(nq^3 + nq^2 nc), then O(nq^2) per solve.
 * Only tsi_shift_solve_real and tsi_shift_solve work then. */
#ifndef TOWSTAB_SHIFT_H
#define TOWSTAB_SHIFT_H

#include <complex.h>

#include "descriptor.h"
#include "lazylib.h"
#include "towstab/error.h"
#include "towstab/linearize.h"

typedef struct tsi_shift {
    tsi_lapack la;         /* the dense backend's LAPACK */
    tsi_klu klu;           /* the sparse backend's KLU */
    const ts_linear *lin;
    const ts_descriptor *d;
    const ts_system *sys;
    double complex s;
    int is_complex;        /* s has a nonzero imaginary part */
    int inf;               /* S_inf: A's action, not a shift */
    /* Dense backend (no sparse model): A = [[0, I, 0], [K, C, E],
     * [F, G, H]] with nc controller states; P(s) = K + s C - s^2 I -
     * E (H - sI)^-1 (F + s G), the Schur complement of the controller
     * block (complex whenever nc > 0); where H - s I is singular (an
     * integrator at s = 0) the whole A - s I is factored instead. */
    int nq, n, nc;
    double complex *hlu;   /* [nc * nc] LU of H - s I (zgetrf), nc > 0 */
    int *hpiv;             /* [nc] */
    double complex *wc;    /* [2 nc] work */
    double complex *full;  /* [n * n] LU of A - s I, the fallback */
    int *fpiv;             /* [n] */
    double *lu;            /* [nq * nq] real LU (dgetrf), when real */
    double complex *zlu;   /* [nq * nq] complex LU (zgetrf), when complex */
    int *ipiv;             /* [nq] */
    double complex *zw;    /* [nq] work */
    double *wr;            /* [2 nq] work */
    /* Sparse backend. */
    void *common;          /* KLU parameters and status (own copy) */
    void *numeric;         /* KLU factors */
    double rcond;          /* KLU's rcond estimate of the last full
                              factorisation */
    double rcond_raw;      /* the same of its factors without KLU's row
                              scaling: the reference of a refactorisation,
                              which skips the scaling */
    double *Sx;            /* [nnz] real or [2 nnz] complex values */
    double *Sk, *Sc, *Sm;  /* [nnz] S(s) = Sk + s Sc + s^2 Sm, kept for
                              refactorisations (tsi_desc_fill_parts) */
    double *rhs;           /* [2 nx] */
    double *cols;          /* [2 nx] */
    double *u1, *u2;       /* [3 nnodes] node displacement work */
    double *w;             /* [2 nq] */
    double *ework;         /* the eigenvalue error estimates' work
                              (tsi_shift_eig_error), kept across calls */
} tsi_shift;

/* Factor S(s) (real arithmetic when Im s == 0) of lin's sparse model, or
 * P(s) of its dense A without one. Returns TS_OK, TS_EINVAL (no model),
 * TS_ESINGULAR (s is an eigenvalue to working precision) or TS_ENOMEM.
 * Free with tsi_shift_free. */
int tsi_shift_factor(tsi_shift *sh, const ts_linear *lin, double complex s,
                     ts_err *err);

/* Factor at a new shift s, reusing sh's factorisation (of the same lin)
 * when it has one of the same kind (real or complex): KLU's refactor with
 * the old pivot order and without KLU's row scaling (with the pivots
 * fixed, scaling the rows scales the factors' rows alike and leaves their
 * accuracy), no allocation, unless the new factors' rcond estimate falls
 * below SHIFT_REFACTOR_RCOND times the last full factorisation's (taken
 * without its scaling too), when it factors afresh (with pivoting and
 * scaling) in the arrays it holds; so too when s has crossed to the other
 * kind. A sequence of nearby shifts (a frequency sweep) then pays for
 * pivoting now and then. Without a factorisation of lin's sparse model in
 * sh, as tsi_shift_factor (sh freed first). Same codes. */
#define SHIFT_REFACTOR_RCOND 1e-2
int tsi_shift_refactor(tsi_shift *sh, const ts_linear *lin, double complex s,
                       ts_err *err);

/* tsi_shift_eig_error's test of the old pivots at a new eigenvalue: the
 * componentwise backward error of its first solve. At 1e-10 the left
 * vector is the exact one of a pencil within 1e-10 of S(lambda) entry by
 * entry, which moves the estimates (first-order, themselves 1e-9 to 1e-6
 * of |lambda|) by far less than their own size (doc/linear.md section
 * 3). */
#define SHIFT_NEAR_BACKWARD 1e-10

/* Factor at a new shift s as tsi_shift_refactor, with the old pivots
 * judged as tsi_shift_eig_error judges them: by the componentwise
 * backward error of the first step of its left vector's inverse
 * iteration (a transposed solve of a fixed right-hand side, Oettli and
 * Prager), which must stay within SHIFT_NEAR_BACKWARD; else S(s) is
 * factored afresh. For a sequence of shifts far apart (the rightmost
 * search's, a factor 4 apart), where the rcond estimates of the two
 * factorisations differ with S(s) itself. One extra solve and an O(nnz)
 * pass; sh then holds the estimates' work too. *fresh (may be NULL) is
 * set when it factored afresh. Same codes. */
int tsi_shift_refactor_judged(tsi_shift *sh, const ts_linear *lin,
                              double complex s, int *fresh, ts_err *err);

/* Factor S_inf, for tsi_shift_apply. Same codes. */
int tsi_shift_factor_inf(tsi_shift *sh, const ts_linear *lin, ts_err *err);

void tsi_shift_free(tsi_shift *sh);

/* x[n] = (A - s I)^-1 b[n], real s only. x may not alias b. */
void tsi_shift_solve_real(tsi_shift *sh, const double *b, double *x);

/* x[n] = (A - s I)^-1 b[n] in complex arithmetic (any s). x may not alias
 * b. */
void tsi_shift_solve(tsi_shift *sh, const double complex *b,
                     double complex *x);

/* With S_inf: y[n] = A x[n]; with err, the linearization's error estimate
 * applied instead (dA x, from the blocks' (D(2h) - D(h)) / 3; zero without
 * the estimate). */
void tsi_shift_apply(tsi_shift *sh, const double *x, double *y, int err);

/* With S_inf: column j of B (y-space, TS_NINPUT columns: tow
 * displacement, velocity, acceleration along x, y, z, then the same of a
 * rotation about them, which moves the tow point by e x tow.point; the
 * vehicles' inputs; without a towing vehicle the frame inputs from
 * ts_linear.frame_input on, the descriptor's Gf), each input alone
 * with the coordinates fixed, into col[n]; with err, its error estimate
 * (from the blocks' (D(2h) - D(h)) / 3; a frame input's with the
 * estimate only). */
void tsi_shift_apply_input(tsi_shift *sh, int j, double *col, int err);

/* The response to a unit harmonic tow-point displacement along input
 * (0 x, 1 y, 2 z; or a rotation about x, y, z, TS_TOW_ROT + 0..2, which
 * moves it by d = e x tow.point, else d = e_input) at the factored s: the
 * tow point moves by d, with velocity s d and acceleration s^2 d; or to a
 * unit
 * harmonic vehicle input (input >= TS_NINPUT: a control surface, a loop,
 * a set point), the tow point at rest (dr_0 = 0); or to a unit harmonic
 * change of the mean frame's speed or turn rate (input
 * ts_linear.frame_input + TS_FRAME_SPEED or TS_FRAME_TURN_RATE, with its
 * rate s times it; the descriptor's Gf: without a towing vehicle), the
 * tow point at rest in M. Writes the
 * absolute point displacements dr[3 np] (dr_0 = d; m per m; then
 * the vehicles' angles, rad per m) followed by the controller states
 * (dr[3 np + j]), and the link tensions dt[nlinks] (N per m), complex. */
void tsi_shift_input(tsi_shift *sh, int input, double complex *dr,
                     double complex *dt);

/* The transposed solve S(s)^T w = b with the factors of sh (sparse
 * backend; plain transpose, no conjugate): w[nx] complex, b in, w out. */
void tsi_shift_tsolve(tsi_shift *sh, double complex *w);

/* First-order error of an eigenvalue lam of lin's sparse model from the
 * model's own error (doc/linear.md, section 3): with the right
 * eigenvector v[n] (kernel coordinates, mapped to node displacements x)
 * and the left null vector w of the pencil, S(lam)^T w = 0 (two steps of
 * inverse iteration with S(lam), factored at lam; a shift that is
 * singular to working precision is moved by 1e-10 |lam|),
 *
 *     dlam = (|w^T dS x| + rms of w^T N x) / |w^T S'(lam) x|,
 *
 * dS = dK + lam dC and N the rounding noise (tsi_desc_error_terms),
 * S'(lam) = [[2 lam M + C, 0], [Cv n^T rows of taut elastic links, 0]].
 * Into *dlam (1/s; NaN without the estimate). Into *ritz (1/s; NaN
 * without the estimate) the Ritz value's own error, the pencil's Newton
 * correction |w^T S(lam) [x; 0]| / |w^T S'(lam) x| (the tensions' columns
 * left out: w^T S(lam) vanishes on them to second order in the error of
 * lam, S' and S'' having none), a product with S and no solve, so free of
 * the rounding of a solve with S_inf that the residual ||A v - lam v||
 * carries (its floor grows like the cube of the links). sh: the caller's (zeroed
 * before the first call, freed with tsi_shift_free after the last), whose
 * factors are refactored at each lam (tsi_shift_refactor). Cost: one KLU
 * (re)factorisation and two transposed solves, O(nlinks). Returns TS_OK,
 * TS_EINVAL (no sparse model), TS_ESINGULAR or TS_ENOMEM. */
int tsi_shift_eig_error(tsi_shift *sh, const ts_linear *lin,
                        double complex lam, const double complex v[],
                        double *dlam, double *ritz, ts_err *err);

/* dq[nq] of node displacements, the inverse of
 * ts_linear_node_displacements (for displacements that keep the rigid
 * links' lengths). */
void tsi_shift_nodes_to_q(const tsi_shift *sh, const double *dr, double *dq);

/* The link tension changes dt[nlinks] (N) of the last tsi_shift_apply or
 * tsi_shift_apply_input with S_inf: the tension unknowns of its solve, so
 * that with x = (z, 0) they are the linear model's dT/dy z and with
 * column j of B its dT/du_j. O(nlinks). */
void tsi_shift_tensions(const tsi_shift *sh, double *dt);

/* The vehicles' output changes out[noutput] (m, rad) of the sparse model
 * at state z[n] and input deviations v[m] (the first m inputs, m at most
 * the frame inputs' index: the sparse model has no frame inputs): the
 * output rows Ov (lib/descriptor.h) on each vehicle's node displacement
 * and velocity (the tow inputs' displacement and velocity channels move
 * the node with the coordinates held, ts_linear_tow_shift), its angles
 * and their rates, its controller states and its inputs; the linear
 * model's Vy z + Vu v. Any factorisation of lin in sh (its work arrays).
 * O(nlinks). */
void tsi_shift_outputs(tsi_shift *sh, const double *z, const double *v,
                       int m, double *out);

#endif
