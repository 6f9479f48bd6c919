/* test_lazylib.c: the numerical libraries opened when used (lib/lazylib.h).
 *
 * This program is built from lib/lazylib.c itself with two sonames
 * replaced (test/meson.build): ARPACK's by a file that does not exist, and
 * KLU's by the C maths library, which exists but has no klu_defaults. Both
 * must fail as an installation fault (TS_EIO) whose message names the
 * file, the reason and the repair, and leave the table empty. LAPACK and
 * NLopt keep their own sonames and must work through their tables: a 3 x
 * 3 solve (dgesv_) and a product (dgemm_, a BLAS routine found through
 * LAPACK's dependencies) against values worked by hand, and an NLopt
 * minimisation of a quadratic whose minimum is known. Opening a library
 * twice gives the same functions (it stays loaded). Opening ahead
 * (tsi_preload_start): LAPACK, not loaded before, is loaded once the
 * thread is joined; the missing ARPACK and the wrong KLU are passed over
 * in silence there, and still reported where they are opened. */
#define _GNU_SOURCE /* RTLD_NOLOAD */
#include "lazylib.h"

#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"

/* 1 when every byte of the object is zero. */
static int all_zero(const void *p, size_t size)
{
    const unsigned char *c = p;
    for (size_t i = 0; i < size; i++)
        if (c[i])
            return 0;
    return 1;
}

static void check_lapack(void)
{
    tsi_lapack la, again;
    ts_err err = {0};
    int rc = tsi_lapack_open(&la, &err);
    CHECK(rc == TS_OK, "LAPACK (%s) opens: %s", TSI_LAPACK_SONAME,
          rc == TS_OK ? "ok" : err.msg);
    if (rc != TS_OK)
        return;
    CHECK(tsi_lapack_open(&again, &err) == TS_OK &&
              again.dgetrf_ == la.dgetrf_ && again.dgemm_ == la.dgemm_,
          "LAPACK opened again gives the same functions");
    /* A x = b with x = (1.5, -2.25, 0.75) and the symmetric A below
     * (column-major); b = A x, exact in binary: 4(1.5) + 2(2.25) + 0.75 =
     * 11.25, -3 - 9 - 1.5 = -13.5, 1.5 + 4.5 + 3 = 9. */
    double a[9] = {4, -2, 1, -2, 4, -2, 1, -2, 4};
    double b[3] = {11.25, -13.5, 9.0}, x[3] = {1.5, -2.25, 0.75};
    int n = 3, one = 1, ipiv[3], info = -1;
    la.dgesv_(&n, &one, a, &n, ipiv, b, &n, &info);
    CHECK(info == 0, "dgesv_ through the table: info %d", info);
    /* Rounding: a well-conditioned 3 x 3 (condition about 6) solves to a
     * few ulps of values of order 1. */
    for (int i = 0; i < 3; i++)
        CHECK_NEAR(b[i], x[i], 1e-14, "dgesv_ solution component");
    /* C = A B with A = [[1, 2], [3, 4]], B = [[0.5, -1], [2, 0.25]]
     * (row-major here, column-major in the arrays): C = [[4.5, -0.5],
     * [9.5, -2]]. */
    double A[4] = {1, 3, 2, 4}, B[4] = {0.5, 2, -1, 0.25}, C[4] = {0};
    double want[4] = {4.5, 9.5, -0.5, -2.0}, pone = 1.0, zero = 0.0;
    int two = 2;
    la.dgemm_("N", "N", &two, &two, &two, &pone, A, &two, B, &two, &zero, C,
              &two, 1, 1);
    for (int i = 0; i < 4; i++)
        CHECK(C[i] == want[i], "dgemm_ (BLAS, through LAPACK's table) "
              "entry %d: %g, want %g (exact in binary)", i, C[i], want[i]);
}

/* f(x, y) = (x - 1.25)^2 + 2 (y + 0.5)^2 + 3, least 3 at (1.25, -0.5). */
static double quadratic(unsigned n, const double *x, double *grad,
                        void *data)
{
    (void)n;
    (void)data;
    double dx = x[0] - 1.25, dy = x[1] + 0.5;
    if (grad) {
        grad[0] = 2 * dx;
        grad[1] = 4 * dy;
    }
    return dx * dx + 2 * dy * dy + 3;
}

static void check_nlopt(void)
{
    tsi_nlopt nl;
    ts_err err = {0};
    int rc = tsi_nlopt_open(&nl, &err);
    CHECK(rc == TS_OK, "NLopt (%s) opens: %s", TSI_NLOPT_SONAME,
          rc == TS_OK ? "ok" : err.msg);
    if (rc != TS_OK)
        return;
    nlopt_opt opt = nl.nlopt_create(NLOPT_LN_BOBYQA, 2);
    CHECK(opt != NULL, "nlopt_create through the table");
    if (!opt)
        return;
    double lo[2] = {-4, -4}, hi[2] = {4, 4}, x[2] = {0.3, 0.7}, f = 0;
    nl.nlopt_set_lower_bounds(opt, lo);
    nl.nlopt_set_upper_bounds(opt, hi);
    nl.nlopt_set_min_objective(opt, quadratic, NULL);
    nl.nlopt_set_xtol_abs1(opt, 1e-10);
    nl.nlopt_set_maxeval(opt, 2000);
    int nrc = nl.nlopt_optimize(opt, x, &f);
    nl.nlopt_destroy(opt);
    CHECK(nrc > 0, "nlopt_optimize succeeds: code %d", nrc);
    /* BOBYQA's quadratic model is exact for a quadratic: the minimum to
     * well inside the step tolerance's square root. */
    CHECK_NEAR(x[0], 1.25, 1e-6, "NLopt minimum x");
    CHECK_NEAR(x[1], -0.5, 1e-6, "NLopt minimum y");
    CHECK_NEAR(f, 3.0, 1e-10, "NLopt least value");
}

/* A library that is not there, and one without the function. */
static void check_faults(void)
{
    tsi_arpack ar;
    memset(&ar, 0xff, sizeof ar);
    ts_err err = {0};
    int rc = tsi_arpack_open(&ar, &err);
    CHECK(rc == TS_EIO && err.code == TS_EIO,
          "a missing ARPACK is TS_EIO: %d", rc);
    CHECK(strstr(err.msg, TSI_ARPACK_SONAME) != NULL &&
              strstr(err.msg, "ARPACK") && strstr(err.msg, "reinstall") &&
              strstr(err.msg, "libarpack2"),
          "its message names the library, the file and the repair: %s",
          err.msg);
    CHECK(all_zero(&ar, sizeof ar), "the table is left empty");

    tsi_klu klu;
    memset(&klu, 0xff, sizeof klu);
    ts_err kerr = {0};
    rc = tsi_klu_open(&klu, &kerr);
    CHECK(rc == TS_EIO, "a library without KLU's functions is TS_EIO: %d",
          rc);
    CHECK(strstr(kerr.msg, TSI_KLU_SONAME) != NULL &&
              strstr(kerr.msg, "lacks klu_defaults") &&
              strstr(kerr.msg, "reinstall") && strstr(kerr.msg, "libklu1"),
          "its message names the file, the function and the repair: %s",
          kerr.msg);
    CHECK(all_zero(&klu, sizeof klu), "the table is left empty");
    CHECK(tsi_arpack_open(&ar, NULL) == TS_EIO,
          "a NULL error record is allowed");
}

/* Before anything else opens LAPACK. */
static void check_preload(void)
{
    void *h = dlopen(TSI_LAPACK_SONAME, RTLD_NOW | RTLD_NOLOAD);
    CHECK(h == NULL, "LAPACK (%s) is not loaded before it is opened",
          TSI_LAPACK_SONAME);
    tsi_preload none = {0};
    tsi_preload_start(&none, 0);
    CHECK(!none.started, "nothing asked: no thread");
    tsi_preload_join(&none);
    tsi_preload p = {0};
    tsi_preload_start(&p, TSI_PRELOAD_LAPACK | TSI_PRELOAD_ARPACK |
                              TSI_PRELOAD_KLU);
    tsi_preload_join(&p);
    CHECK(!p.started, "joined");
    h = dlopen(TSI_LAPACK_SONAME, RTLD_NOW | RTLD_NOLOAD);
    CHECK(h != NULL, "LAPACK is loaded once the thread that opens it ahead "
          "is joined (the missing ARPACK and the wrong KLU beside it)");
    if (h)
        dlclose(h);
}

int main(void)
{
    check_preload();
    check_lapack();
    check_nlopt();
    check_faults();
    return tc_done();
}
