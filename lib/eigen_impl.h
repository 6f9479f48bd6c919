/* eigen_impl.h: what eigen.c shares with response.c (internal): the
 * structured solver of (A - s I) x = b for A = [[0, I, 0], [K, C, E],
 * [F, G, H]] (doc/linear.md): nq coordinates, their nq rates and nc
 * controller states.
 *
 * With x = (x1, x2, x3) and b = (b1, b2, b3): x2 = b1 + s x1,
 * x3 = (H - sI)^-1 (b3 - F x1 - G x2), and
 * P(s) x1 = b2 - (C - sI) b1 - E (H - sI)^-1 (b3 - G b1) with
 * P(s) = K + s C - s^2 I - E (H - sI)^-1 (F + s G). P is factored once
 * (LU, O(nq^3 + nq^2 nc)); each solve then costs one matrix-vector
 * product with C and two triangular solves, O(nq^2). Without controller
 * states (nc = 0) this is K + s C - s^2 I. Where H - s I itself is
 * singular the whole A - s I is factored instead (O(n^3)). */
#ifndef TOWSTAB_EIGEN_IMPL_H
#define TOWSTAB_EIGEN_IMPL_H

#include <complex.h>

#include "lapack.h"
#include "towstab/error.h"
#include "towstab/linearize.h"

/* A factored P(s) of a linear model. */
typedef struct tsi_shift {
    const ts_linear *lin;
    int nq, n, nc;         /* nc = n - 2 nq controller states */
    double complex *hlu;   /* [nc * nc] LU of H - s I (zgetrf), nc > 0 */
    int *hpiv;             /* [nc] */
    double complex *wc;    /* [2 nc] work */
    double complex *full;  /* [n * n] LU of the whole A - s I (zgetrf),
                              used instead when H - s I is singular (s an
                              eigenvalue of the controller block alone: an
                              integrator at s = 0) */
    int *fpiv;             /* [n] */
    int is_complex;        /* s has a nonzero imaginary part, or there are
                              controller states (complex arithmetic) */
    double complex s;
    double *lu;            /* [nq * nq] real LU (dgetrf), when real */
    double complex *zlu;   /* [nq * nq] complex LU (zgetrf), when complex */
    int *ipiv;             /* [nq] */
    double complex *w;     /* [nq] work */
    double *wr;            /* [2 nq] work */
} tsi_shift;

/* Factor P(s) for lin (real arithmetic when Im s == 0). Returns TS_OK,
 * TS_ESINGULAR (s is an eigenvalue to working precision: P singular) or
 * TS_ENOMEM. Free with tsi_shift_free. */
int tsi_shift_factor(tsi_shift *sh, const ts_linear *lin, double complex s,
                     ts_err *err);
void tsi_shift_free(tsi_shift *sh);

/* x[n] = (A - s I)^-1 b[n], real s only. x may not alias b. */
void tsi_shift_solve_real(tsi_shift *sh, const double *b, double *x);

/* x[n] = (A - s I)^-1 b[n] in complex arithmetic (any s). x may not alias
 * b. */
void tsi_shift_solve(tsi_shift *sh, const double complex *b,
                     double complex *x);

#endif
