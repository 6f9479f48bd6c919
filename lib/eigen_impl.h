/* eigen_impl.h: what eigen.c shares with response.c (internal): the
 * structured solver of (A - s I) x = b for A = [[0, I], [K, C]]
 * (doc/linear.md).
 *
 * With x = (x1, x2) and b = (b1, b2) (nq each): x2 = b1 + s x1 and
 * P(s) x1 = b2 - C b1 + s b1 with P(s) = K + s C - s^2 I. P is factored
 * once (LU, O(nq^3)); each solve then costs one matrix-vector product with
 * C and two triangular solves, O(nq^2). The same factors solve with
 * (A - s I)^T, whose reduced matrix is P^T. */
#ifndef TOWSTAB_EIGEN_IMPL_H
#define TOWSTAB_EIGEN_IMPL_H

#include <complex.h>

#include "lapack.h"
#include "towstab/error.h"
#include "towstab/linearize.h"

/* A factored P(s) of a linear model. */
typedef struct tsi_shift {
    const ts_linear *lin;
    int nq, n;
    int is_complex;        /* s has a nonzero imaginary part */
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
