/* lazylib.h (internal): the numerical libraries the library opens only
 * when a run uses them. LAPACK and BLAS (OpenBLAS on Debian, with
 * gfortran's run-time), ARPACK, KLU (with AMD, COLAMD, BTF and
 * SuiteSparse's config) and NLopt are not linked to libtowstab: a run that
 * needs none of them (`--version`, `--help`, a refused scene, an
 * equilibrium whose shooting needs no dense algebra) does not load them.
 * doc/performance.md, "Start-up".
 *
 * Each library has a table of the functions the library calls, filled by
 * its tsi_<lib>_open with dlopen of the library's soname (below; the
 * dynamic loader's search path, as for a linked library) and dlsym. The
 * table is the caller's: an analysis keeps it in its workspace, or opens
 * it where it is used. Nothing is kept here: a library once opened stays
 * loaded (RTLD_NODELETE), and opening it again only finds it.
 *
 * A library that cannot be opened, or that lacks a function, is an
 * installation fault, not one of the run's input: TS_EIO, naming the
 * file, the dynamic loader's reason and the repair (exit status 1 at the
 * command line, as for towstab's own modules, dlmodule.h).
 *
 * The members have the names and the types of the functions they stand
 * for (lapack.h, arpack.h, klu.h, nlopt.h): `la.dgetrf_(...)` calls
 * LAPACK's dgetrf_. */
#ifndef TOWSTAB_LIB_LAZYLIB_H
#define TOWSTAB_LIB_LAZYLIB_H

#include "arpack.h"
#include "lapack.h"
#include "towstab/error.h"

#include <klu.h>
#include <nlopt.h>
#include <pthread.h>

/* The sonames, Debian's (the build may pass others). */
#ifndef TSI_LAPACK_SONAME
#define TSI_LAPACK_SONAME "liblapack.so.3"
#endif
#ifndef TSI_ARPACK_SONAME
#define TSI_ARPACK_SONAME "libarpack.so.2"
#endif
#ifndef TSI_KLU_SONAME
#define TSI_KLU_SONAME "libklu.so.1"
#endif
#ifndef TSI_NLOPT_SONAME
#define TSI_NLOPT_SONAME "libnlopt.so.0"
#endif

/* The functions of each table. LAPACK's table also holds the BLAS
 * routines: liblapack.so.3 depends on libblas.so.3 (or is OpenBLAS, which
 * is both), and dlsym looks in a library's dependencies too. */
#define TSI_LAPACK_FUNCS(X)                                                 \
    X(dgesv_) X(dgecon_) X(dlange_) X(dgetrf_) X(dgetrs_) X(dgeevx_)        \
    X(dgeev_) X(dlacn2_) X(zgetrf_) X(zgetrs_) X(dgemv_) X(dgemm_)         \
    X(zgeev_) X(zgemm_)
#define TSI_ARPACK_FUNCS(X) X(dnaupd_) X(dneupd_) X(znaupd_) X(zneupd_)
#define TSI_KLU_FUNCS(X)                                                    \
    X(klu_defaults) X(klu_analyze) X(klu_free_symbolic) X(klu_factor)       \
    X(klu_refactor) X(klu_free_numeric) X(klu_solve) X(klu_tsolve)          \
    X(klu_rcond) X(klu_z_factor) X(klu_z_refactor) X(klu_z_free_numeric)    \
    X(klu_z_solve) X(klu_z_tsolve) X(klu_z_rcond)
#define TSI_NLOPT_FUNCS(X)                                                  \
    X(nlopt_create) X(nlopt_destroy) X(nlopt_optimize) X(nlopt_force_stop)  \
    X(nlopt_set_lower_bounds) X(nlopt_set_upper_bounds)                     \
    X(nlopt_set_min_objective) X(nlopt_add_inequality_constraint)           \
    X(nlopt_set_xtol_abs1) X(nlopt_set_maxeval) X(nlopt_set_stopval)        \
    X(nlopt_set_initial_step)

#define TSI_LAZY_MEMBER(f) __typeof__(f) *f;
typedef struct tsi_lapack {
    TSI_LAPACK_FUNCS(TSI_LAZY_MEMBER)
} tsi_lapack;
typedef struct tsi_arpack {
    TSI_ARPACK_FUNCS(TSI_LAZY_MEMBER)
} tsi_arpack;
typedef struct tsi_klu {
    TSI_KLU_FUNCS(TSI_LAZY_MEMBER)
} tsi_klu;
typedef struct tsi_nlopt {
    TSI_NLOPT_FUNCS(TSI_LAZY_MEMBER)
} tsi_nlopt;

/* Fill t from the library (opening it on first use): TS_OK, or TS_EIO
 * with the file, the reason and the repair in err (t is then zeroed). */
int tsi_lapack_open(tsi_lapack *t, ts_err *err);
int tsi_arpack_open(tsi_arpack *t, ts_err *err);
int tsi_klu_open(tsi_klu *t, ts_err *err);
int tsi_nlopt_open(tsi_nlopt *t, ts_err *err);

/* Opening ahead: a run that knows which of the libraries it will need
 * opens them on a thread of its own while it computes what comes first
 * (the equilibrium and the linearization), so that loading them (LAPACK
 * with OpenBLAS some milliseconds: doc/performance.md, "Start-up") is not
 * on the path of the analysis that uses them. The thread only opens the
 * libraries, as each tsi_<lib>_open does, and keeps nothing: the analysis
 * opens them again where it uses them, which then only finds them, and
 * reports a library that cannot be opened as before. tsi_preload_join
 * waits for the thread; without one (pthread_create failed, or nothing
 * asked) it returns at once. */
enum {
    TSI_PRELOAD_LAPACK = 1,
    TSI_PRELOAD_ARPACK = 2,
    TSI_PRELOAD_KLU = 4
};
typedef struct tsi_preload {
    pthread_t thread;
    int what;    /* TSI_PRELOAD_ flags */
    int started; /* the thread runs, to be joined */
} tsi_preload;
void tsi_preload_start(tsi_preload *p, int what);
void tsi_preload_join(tsi_preload *p);

#endif
