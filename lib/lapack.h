/* lapack.h: prototypes of every LAPACK and BLAS (Fortran) routine towstab
 * and its tests call (internal; ARPACK's are in arpack.h). Integers are
 * Fortran INTEGER (int with Debian's LP64 build); a CHARACTER argument
 * carries gfortran's hidden length, passed last; COMPLEX*16 is double
 * complex. */
#ifndef TOWSTAB_LAPACK_H
#define TOWSTAB_LAPACK_H

#include <complex.h>
#include <stddef.h>

void dgesv_(const int *n, const int *nrhs, double *a, const int *lda,
            int *ipiv, double *b, const int *ldb, int *info);
void dgecon_(const char *norm, const int *n, const double *a, const int *lda,
             const double *anorm, double *rcond, double *work, int *iwork,
             int *info, size_t norm_len);
double dlange_(const char *norm, const int *m, const int *n, const double *a,
               const int *lda, double *work, size_t norm_len);
void dlacn2_(const int *n, double *v, double *x, int *isgn, double *est,
             int *kase, int *isave);
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv,
             int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a,
             const int *lda, const int *ipiv, double *b, const int *ldb,
             int *info, size_t trans_len);
void dgeev_(const char *jobvl, const char *jobvr, const int *n, double *a,
            const int *lda, double *wr, double *wi, double *vl,
            const int *ldvl, double *vr, const int *ldvr, double *work,
            const int *lwork, int *info, size_t jobvl_len, size_t jobvr_len);
void dgeevx_(const char *balanc, const char *jobvl, const char *jobvr,
             const char *sense, const int *n, double *a, const int *lda,
             double *wr, double *wi, double *vl, const int *ldvl, double *vr,
             const int *ldvr, int *ilo, int *ihi, double *scale,
             double *abnrm, double *rconde, double *rcondv, double *work,
             const int *lwork, int *iwork, int *info, size_t balanc_len,
             size_t jobvl_len, size_t jobvr_len, size_t sense_len);
void zgeev_(const char *jobvl, const char *jobvr, const int *n,
            double complex *a, const int *lda, double complex *w,
            double complex *vl, const int *ldvl, double complex *vr,
            const int *ldvr, double complex *work, const int *lwork,
            double *rwork, int *info, size_t jobvl_len, size_t jobvr_len);
void zgesv_(const int *n, const int *nrhs, double complex *a, const int *lda,
            int *ipiv, double complex *b, const int *ldb, int *info);
void zgecon_(const char *norm, const int *n, const double complex *a,
             const int *lda, const double *anorm, double *rcond,
             double complex *work, double *rwork, int *info, size_t norm_len);
void zgetrf_(const int *m, const int *n, double complex *a, const int *lda,
             int *ipiv, int *info);
void zgetrs_(const char *trans, const int *n, const int *nrhs,
             const double complex *a, const int *lda, const int *ipiv,
             double complex *b, const int *ldb, int *info, size_t trans_len);

/* BLAS. */
void dgemv_(const char *trans, const int *m, const int *n,
            const double *alpha, const double *a, const int *lda,
            const double *x, const int *incx, const double *beta, double *y,
            const int *incy, size_t trans_len);
void dgemm_(const char *transa, const char *transb, const int *m,
            const int *n, const int *k, const double *alpha, const double *a,
            const int *lda, const double *b, const int *ldb,
            const double *beta, double *c, const int *ldc, size_t transa_len,
            size_t transb_len);
void zgemm_(const char *transa, const char *transb, const int *m,
            const int *n, const int *k, const double complex *alpha,
            const double complex *a, const int *lda, const double complex *b,
            const int *ldb, const double complex *beta, double complex *c,
            const int *ldc, size_t transa_len, size_t transb_len);

#endif
