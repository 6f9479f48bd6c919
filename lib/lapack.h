/* lapack.h: prototypes of the LAPACK (Fortran) routines towstab calls
 * (internal). Integers are Fortran INTEGER (int with Debian's LP64 build);
 * a CHARACTER argument carries gfortran's hidden length, passed last. */
#ifndef TOWSTAB_LAPACK_H
#define TOWSTAB_LAPACK_H

#include <stddef.h>

void dgesv_(const int *n, const int *nrhs, double *a, const int *lda,
            int *ipiv, double *b, const int *ldb, int *info);
void dgecon_(const char *norm, const int *n, const double *a, const int *lda,
             const double *anorm, double *rcond, double *work, int *iwork,
             int *info, size_t norm_len);
double dlange_(const char *norm, const int *m, const int *n, const double *a,
               const int *lda, double *work, size_t norm_len);
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv,
             int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a,
             const int *lda, const int *ipiv, double *b, const int *ldb,
             int *info, size_t trans_len);

#endif
