/* tcheck.h: the checks every test program uses. One line per check,
 * "PASS ..." or "FAIL ...", and a closing "N passed, N failed" line; the
 * exit status is 0 only when nothing failed. State is per program. */
#ifndef TOWSTAB_TCHECK_H
#define TOWSTAB_TCHECK_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static int tc_npass, tc_nfail;

#ifdef __GNUC__
__attribute__((format(printf, 4, 5)))
#endif
static int tc_check(int ok, const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("%s ", ok ? "PASS" : "FAIL");
    vprintf(fmt, ap);
    if (!ok)
        printf("   [%s:%d]", file, line);
    printf("\n");
    va_end(ap);
    if (ok)
        tc_npass++;
    else
        tc_nfail++;
    fflush(stdout);
    return ok;
}

/* CHECK(condition, "what is checked %d", args...) */
#define CHECK(cond, ...) tc_check(!!(cond), __FILE__, __LINE__, __VA_ARGS__)

/* |got - want| <= tol (absolute); the values are printed. */
#define CHECK_NEAR(got, want, tol, name)                                      \
    do {                                                                      \
        double g_ = (got), w_ = (want), t_ = (tol);                           \
        tc_check(fabs(g_ - w_) <= t_, __FILE__, __LINE__,                     \
                 "%s: got %.12g, want %.12g, |diff| %.3g <= %.3g", (name),    \
                 g_, w_, fabs(g_ - w_), t_);                                  \
    } while (0)

/* |got - want| <= rtol |want| */
#define CHECK_REL(got, want, rtol, name)                                      \
    do {                                                                      \
        double g_ = (got), w_ = (want), t_ = (rtol);                          \
        double r_ = fabs(g_ - w_) / fmax(fabs(w_), 1e-300);                   \
        tc_check(r_ <= t_, __FILE__, __LINE__,                                \
                 "%s: got %.12g, want %.12g, rel diff %.3g <= %.3g", (name),  \
                 g_, w_, r_, t_);                                             \
    } while (0)

static int tc_done(void)
{
    printf("%d passed, %d failed\n", tc_npass, tc_nfail);
    return tc_nfail ? 1 : 0;
}

#endif
