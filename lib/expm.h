/* expm.h: the matrix exponential (internal; lib/expm.c). */
#ifndef TOWSTAB_EXPM_H
#define TOWSTAB_EXPM_H

#include "towstab/error.h"

/* E[n*n] = exp(A[n*n]), both column-major (E may not alias A), by Pade
 * approximants with scaling and squaring (Higham 2005, algorithm 2.3):
 * backward error below the unit roundoff for any ||A||_1. Cost: up to 6
 * matrix products plus one per squaring and one LU solve, O(n^3).
 * *squarings, when not NULL, receives the number of squarings s.
 * Returns TS_OK, TS_EINVAL (n < 1 or A not finite), TS_ENOMEM or
 * TS_ELAPACK (the Pade denominator is singular, which the theory rules
 * out for finite A: reported, never hidden). */
int tsi_expm(int n, const double *A, double *E, int *squarings, ts_err *err);

#endif
