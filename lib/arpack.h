/* arpack.h: prototypes of the ARPACK (Fortran 77) routines towstab calls
 * (internal). Integers are Fortran INTEGER (int with Debian's LP64 build),
 * LOGICAL is int, complex numbers are pairs of doubles (double _Complex
 * has the same layout). gfortran passes the length of every CHARACTER
 * argument as a hidden trailing size_t, in the order of the arguments;
 * they are declared here so that the calls match the Fortran interface. */
#ifndef TOWSTAB_ARPACK_H
#define TOWSTAB_ARPACK_H

#include <complex.h>
#include <stddef.h>

/* Real nonsymmetric: reverse-communication Arnoldi and post-processing. */
void dnaupd_(int *ido, const char *bmat, const int *n, const char *which,
             const int *nev, const double *tol, double *resid, const int *ncv,
             double *v, const int *ldv, int *iparam, int *ipntr, double *workd,
             double *workl, const int *lworkl, int *info, size_t bmat_len,
             size_t which_len);
void dneupd_(const int *rvec, const char *howmny, int *select, double *dr,
             double *di, double *z, const int *ldz, const double *sigmar,
             const double *sigmai, double *workev, const char *bmat,
             const int *n, const char *which, const int *nev,
             const double *tol, double *resid, const int *ncv, double *v,
             const int *ldv, int *iparam, int *ipntr, double *workd,
             double *workl, const int *lworkl, int *info, size_t howmny_len,
             size_t bmat_len, size_t which_len);

/* Complex: the same for complex operators. */
void znaupd_(int *ido, const char *bmat, const int *n, const char *which,
             const int *nev, const double *tol, double complex *resid,
             const int *ncv, double complex *v, const int *ldv, int *iparam,
             int *ipntr, double complex *workd, double complex *workl,
             const int *lworkl, double *rwork, int *info, size_t bmat_len,
             size_t which_len);
void zneupd_(const int *rvec, const char *howmny, int *select,
             double complex *d, double complex *z, const int *ldz,
             const double complex *sigma, double complex *workev,
             const char *bmat, const int *n, const char *which, const int *nev,
             const double *tol, double complex *resid, const int *ncv,
             double complex *v, const int *ldv, int *iparam, int *ipntr,
             double complex *workd, double complex *workl, const int *lworkl,
             double *rwork, int *info, size_t howmny_len, size_t bmat_len,
             size_t which_len);

#endif
