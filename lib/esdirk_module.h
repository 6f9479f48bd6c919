/* esdirk_module.h (internal): the table of functions the SUNDIALS module
 * (lib/esdirk_sundials.c, towstab-sundials.so) exports under the name
 * TSI_ESDIRK_MODULE_SYMBOL, and the library's stepper (lib/esdirk.c)
 * calls through once it has opened the module (lib/dlmodule.h). Each
 * entry does what the function of lib/esdirk.h of the same name does, on
 * the module's own stepper (tsi_esdirk_impl, opaque here). */
#ifndef TOWSTAB_LIB_ESDIRK_MODULE_H
#define TOWSTAB_LIB_ESDIRK_MODULE_H

#include "dlmodule.h"
#include "esdirk.h"

#define TSI_ESDIRK_MODULE_SYMBOL "towstab_sundials_module"
#define TSI_ESDIRK_MODULE_VERSION 2
#define TSI_ESDIRK_MODULE_FILE "towstab-sundials.so"

typedef struct tsi_esdirk_impl tsi_esdirk_impl;

typedef struct tsi_esdirk_module {
    tsi_module_head head; /* TSI_ESDIRK_MODULE_VERSION */
    tsi_esdirk_impl *(*alloc_method)(int n, tsi_ode_fn f, tsi_ode_jac jac,
                                     const tsi_ode_lsys *lsys, void *params,
                                     double rtol, double atol, double h_init,
                                     int bdf, ts_err *err);
    void (*free)(tsi_esdirk_impl *s);
    int (*reset)(tsi_esdirk_impl *s, double t, const double y[],
                 ts_err *err);
    int (*step)(tsi_esdirk_impl *s, double tstop, double *t, double y[],
                ts_err *err);
    int (*interpolate)(tsi_esdirk_impl *s, double t, double y[],
                       ts_err *err);
    void (*get_stats)(const tsi_esdirk_impl *s, tsi_esdirk_stats *st);
} tsi_esdirk_module;

#endif
