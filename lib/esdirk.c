/* lib/esdirk.c: the stepper of lib/esdirk.h, through the SUNDIALS module.
 *
 * The stepper itself (ARKODE's ESDIRK 5(4), CVODE's BDF) is
 * lib/esdirk_sundials.c, built as a module of its own,
 * towstab-sundials.so, the only part of towstab linked to SUNDIALS. Each
 * stepper opens the module when it is made (lib/dlmodule.h; the
 * environment variable TOWSTAB_SUNDIALS_MODULE names it for the tests)
 * and closes it when freed, so that a run that does not step with esdirk
 * or bdf (every equilibrium, modes and response, a simulation with GSL's
 * integrators) does not load SUNDIALS (doc/performance.md, "Start-up").
 * The first stepper of a process maps the module; it stays loaded.
 */
#include "esdirk.h"

#include <stdlib.h>

#include "dlmodule.h"
#include "esdirk_module.h"

struct tsi_esdirk {
    tsi_module dl;
    const tsi_esdirk_module *t; /* dl's table */
    tsi_esdirk_impl *impl;      /* the module's stepper */
};

tsi_esdirk *tsi_esdirk_alloc_method(int n, tsi_ode_fn f, tsi_ode_jac jac,
                                    const tsi_ode_lsys *lsys, void *params,
                                    double rtol, double atol, double h_init,
                                    int bdf, ts_err *err)
{
    tsi_esdirk *s = calloc(1, sizeof *s);
    if (!s) {
        ts_fail(err, TS_ENOMEM, "esdirk: out of memory");
        return NULL;
    }
    if (tsi_module_open(&s->dl, "SUNDIALS module", TSI_ESDIRK_MODULE_FILE,
                        "TOWSTAB_SUNDIALS_MODULE", TSI_ESDIRK_MODULE_SYMBOL,
                        TSI_ESDIRK_MODULE_VERSION, err) != TS_OK) {
        free(s);
        return NULL;
    }
    s->t = s->dl.table;
    s->impl = s->t->alloc_method(n, f, jac, lsys, params, rtol, atol, h_init,
                                 bdf, err);
    if (!s->impl) {
        tsi_module_close(&s->dl);
        free(s);
        return NULL;
    }
    return s;
}

tsi_esdirk *tsi_esdirk_alloc(int n, tsi_ode_fn f, tsi_ode_jac jac,
                             void *params, double rtol, double atol,
                             double h_init, ts_err *err)
{
    return tsi_esdirk_alloc_method(n, f, jac, NULL, params, rtol, atol,
                                   h_init, 0, err);
}

tsi_esdirk *tsi_esdirk_alloc_lsys(int n, tsi_ode_fn f,
                                  const tsi_ode_lsys *lsys, void *params,
                                  double rtol, double atol, double h_init,
                                  ts_err *err)
{
    return tsi_esdirk_alloc_method(n, f, NULL, lsys, params, rtol, atol,
                                   h_init, 0, err);
}

void tsi_esdirk_free(tsi_esdirk *s)
{
    if (!s)
        return;
    s->t->free(s->impl);
    tsi_module_close(&s->dl);
    free(s);
}

int tsi_esdirk_reset(tsi_esdirk *s, double t, const double y[], ts_err *err)
{
    return s->t->reset(s->impl, t, y, err);
}

int tsi_esdirk_step(tsi_esdirk *s, double tstop, double *t, double y[],
                    ts_err *err)
{
    return s->t->step(s->impl, tstop, t, y, err);
}

int tsi_esdirk_interpolate(tsi_esdirk *s, double t, double y[], ts_err *err)
{
    return s->t->interpolate(s->impl, t, y, err);
}

void tsi_esdirk_get_stats(const tsi_esdirk *s, tsi_esdirk_stats *st)
{
    s->t->get_stats(s->impl, st);
}
