/* lazylib.c: the numerical libraries opened when used (lazylib.h). */
#define _GNU_SOURCE /* RTLD_NODELETE */
#include "lazylib.h"

#include <dlfcn.h>
#include <string.h>

/* What a library that cannot be used asks for. */
#define REPAIR "reinstall it (Debian: the package %s), or rebuild towstab " \
               "against the one installed"

/* Open the library `file` (what: its name in messages, package: Debian's
 * package of it). NULL with err set when it cannot be opened. */
static void *open_lib(const char *what, const char *file,
                      const char *package, ts_err *err)
{
    void *h = dlopen(file, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!h) {
        const char *why = dlerror();
        ts_fail(err, TS_EIO, "cannot load %s (%s): %s: " REPAIR, what, file,
                why ? why : "no reason given", package);
    }
    return h;
}

/* dlsym's answer for a function, into a function pointer (POSIX allows
 * the conversion; the copy avoids the cast ISO C leaves undefined). */
static int lookup(void *h, const char *name, void *slot, const char *what,
                  const char *file, const char *package, ts_err *err)
{
    void *p = dlsym(h, name);
    if (!p) {
        const char *why = dlerror();
        return ts_fail(err, TS_EIO, "%s (%s) lacks %s: %s: " REPAIR, what,
                       file, name, why ? why : "no reason given", package);
    }
    memcpy(slot, &p, sizeof p);
    return TS_OK;
}

/* The body of each tsi_<lib>_open. The handle is not closed: the library
 * stays loaded (RTLD_NODELETE) and a closed handle would only drop the
 * count dlopen raised. */
#define LOOKUP(f)                                                           \
    if (lookup(h, #f, &t->f, what, file, package, err) != TS_OK) {         \
        memset(t, 0, sizeof *t);                                            \
        return TS_EIO;                                                      \
    }
#define OPEN_TABLE(FUNCS)                                                   \
    do {                                                                    \
        void *h = open_lib(what, file, package, err);                       \
        if (!h) {                                                           \
            memset(t, 0, sizeof *t);                                        \
            return TS_EIO;                                                  \
        }                                                                   \
        FUNCS(LOOKUP)                                                       \
        dlclose(h);                                                         \
        return TS_OK;                                                       \
    } while (0)

int tsi_lapack_open(tsi_lapack *t, ts_err *err)
{
    const char *what = "LAPACK", *file = TSI_LAPACK_SONAME,
               *package = "liblapack3 or libopenblas0";
    OPEN_TABLE(TSI_LAPACK_FUNCS);
}

int tsi_arpack_open(tsi_arpack *t, ts_err *err)
{
    const char *what = "ARPACK", *file = TSI_ARPACK_SONAME,
               *package = "libarpack2";
    OPEN_TABLE(TSI_ARPACK_FUNCS);
}

int tsi_klu_open(tsi_klu *t, ts_err *err)
{
    const char *what = "KLU", *file = TSI_KLU_SONAME, *package = "libklu1";
    OPEN_TABLE(TSI_KLU_FUNCS);
}

int tsi_nlopt_open(tsi_nlopt *t, ts_err *err)
{
    const char *what = "NLopt", *file = TSI_NLOPT_SONAME,
               *package = "libnlopt0";
    OPEN_TABLE(TSI_NLOPT_FUNCS);
}

static void *preload_main(void *arg)
{
    const tsi_preload *p = arg;
    ts_err err = {0};
    if (p->what & TSI_PRELOAD_LAPACK) {
        tsi_lapack t;
        tsi_lapack_open(&t, &err);
    }
    if (p->what & TSI_PRELOAD_ARPACK) {
        tsi_arpack t;
        tsi_arpack_open(&t, &err);
    }
    if (p->what & TSI_PRELOAD_KLU) {
        tsi_klu t;
        tsi_klu_open(&t, &err);
    }
    return NULL;
}

void tsi_preload_start(tsi_preload *p, int what)
{
    p->what = what;
    p->started = what != 0 &&
                 pthread_create(&p->thread, NULL, preload_main, p) == 0;
}

void tsi_preload_join(tsi_preload *p)
{
    if (p->started)
        pthread_join(p->thread, NULL);
    p->started = 0;
}
