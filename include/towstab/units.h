/* towstab/units.h: quantities with units at the edges (scene files, reports).
 *
 * Built on udunits2. A quantity is a plain number, taken as SI, or a string
 * "<number> <unit>" ("100 ft", "8.345 ft/s", "1 lbf/ft", "0.5 rad/s",
 * "5 knot"). It is converted to the SI unit the caller expects; a quantity
 * of another dimension is refused with a message naming both dimensions
 * (a mass given where a weight is expected says so and suggests lbf).
 * The unit system is read once by ts_units_alloc() and is read-only after.
 * udunits2 keeps process-wide parser state and a process-wide message
 * handler (towstab silences it): do not call these functions from several
 * threads at once, even on separate ts_units objects.
 */
#ifndef TOWSTAB_UNITS_H
#define TOWSTAB_UNITS_H

#include "towstab/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ts_units ts_units;

/* Load the unit database. NULL on failure (message in err). */
TS_API ts_units *ts_units_alloc(ts_err *err);

/* Release it. ts_units_free(NULL) does nothing. */
TS_API void ts_units_free(ts_units *u);

/* Convert `text` to the SI unit `si_unit` ("m", "kg", "N", "N/m", "kg/m",
 * "m/s", "rad/s", "kg/m^3", "m/s^2", "N*m^2", "s", "Hz", "rad", "1").
 * `where` names the quantity in messages ("cables[0].length (line 12)").
 * Text without a unit is taken as SI. NaN, infinities and trailing garbage
 * are refused. Returns TS_OK, TS_EUNIT (wrong or unknown unit) or TS_EINVAL
 * (not a number). */
TS_API int ts_units_parse(const ts_units *u, const char *text,
                          const char *si_unit, const char *where,
                          double *value, ts_err *err);

/* Convert an SI value to `unit` (for reports: "ft", "lbf", "knot").
 * Returns TS_OK or TS_EUNIT when the dimensions differ. */
TS_API int ts_units_from_si(const ts_units *u, double value_si,
                            const char *si_unit, const char *unit,
                            double *out, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
