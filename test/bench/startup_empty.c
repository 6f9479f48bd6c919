/* startup_empty.c: a program that does nothing but is linked to LAPACK
 * and BLAS (and, built with -DWITH_ARPACK, to ARPACK; with
 * -DWITH_UDUNITS, to udunits2, whose XML database it reads when given the
 * argument "read"): what loading them costs a process, measured by
 * startup_pairs (test/bench/startup_cost.sh, doc/performance.md,
 * "Start-up"). Each library is kept by an address taken from it, so that
 * the link cannot drop it. */
#include <stdio.h>
#include <string.h>
#ifdef WITH_UDUNITS
#include <udunits2.h>
#endif

void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv,
             int *info);
double ddot_(const int *n, const double *x, const int *incx, const double *y,
             const int *incy);
#ifdef WITH_ARPACK
void dnaupd_(void);
#endif

int main(int argc, char **argv)
{
    /* The addresses, read through volatile so that none is dropped. */
    void (*volatile keep_lapack)(const int *, const int *, double *,
                                 const int *, int *, int *) = dgetrf_;
    double (*volatile keep_blas)(const int *, const double *, const int *,
                                 const double *, const int *) = ddot_;
    int linked = keep_lapack != NULL && keep_blas != NULL;
#ifdef WITH_ARPACK
    void (*volatile keep_arpack)(void) = dnaupd_;
    linked = linked && keep_arpack != NULL;
#endif
#ifdef WITH_UDUNITS
    if (argc > 1 && !strcmp(argv[1], "read")) {
        ut_set_error_message_handler(ut_ignore);
        ut_system *sys = ut_read_xml(NULL);
        if (!sys) {
            fprintf(stderr, "startup_empty: cannot read the udunits2 "
                            "database\n");
            return 1;
        }
        ut_free_system(sys);
    }
#else
    (void)argv;
    (void)argc;
#endif
    return linked ? 0 : 1;
}
