/* units_impl.h (internal): what test_units needs to check the small unit
 * system against udunits2's whole database (lib/units.c). */
#ifndef TOWSTAB_LIB_UNITS_IMPL_H
#define TOWSTAB_LIB_UNITS_IMPL_H

#include <stddef.h>

#include "towstab/units.h"

/* The i-th word the small system reads (a name, plural, symbol, prefixed
 * word or alias), or NULL past the last. */
const char *tsi_units_small_word(size_t i);

/* Which systems `u` has made so far: *small and *full are 1 or 0. */
void tsi_units_made(const ts_units *u, int *small, int *full);

#endif
