/* towstab/units.h: quantities with units at the edges (scene files, reports).
 *
 * Built on udunits2. A quantity is a plain number, taken as SI, or a string
 * "<number> <unit>" ("100 ft", "8.345 ft/s", "1 lbf/ft", "0.5 rad/s",
 * "5 knot"). It is converted to the SI unit the caller expects; a quantity
 * of another dimension is refused with a message naming both dimensions
 * (a mass given where a weight is expected says so and suggests lbf).
 * The unit systems are made when a quantity first needs one (a bare number
 * needs none; the common units are built in memory; any other unit reads
 * udunits2's XML database), once per ts_units. udunits2 keeps
 * process-wide parser state and a process-wide message handler (towstab
 * silences it), and the systems are made on first use: do not call these
 * functions from several threads at once, even on separate ts_units
 * objects.
 */
#ifndef TOWSTAB_UNITS_H
#define TOWSTAB_UNITS_H

#include <stddef.h>

#include "towstab/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ts_units ts_units;

/* A unit converter; its unit systems are made on first use, and a
 * database that cannot be read is reported by the conversion that needed
 * it. NULL on failure (out of memory; message in err). */
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

/* ---- display units ------------------------------------------------------
 * What tables, CSV files and pictures show numbers in: one unit per kind
 * of quantity. Numbers stay SI inside and in JSON; a display converts at
 * the edge. A display is a plain struct (copied by value). */

typedef enum {
    TS_QTY_LENGTH = 0,       /* m */
    TS_QTY_FORCE = 1,        /* N */
    TS_QTY_SPEED = 2,        /* m/s */
    TS_QTY_ANGULAR_RATE = 3, /* rad/s (turn rates) */
    TS_QTY_TIME = 4,         /* s */
    TS_QTY_FREQUENCY = 5,    /* Hz */
    TS_QTY_ANGLE = 6,        /* rad inside; shown in deg by default */
    TS_QTY_MASS = 7          /* kg */
} ts_quantity;
#define TS_QTY_COUNT 8
#define TS_DISPLAY_UNIT_MAX 24

typedef struct ts_display {
    char unit[TS_QTY_COUNT][TS_DISPLAY_UNIT_MAX]; /* "m", "ft", "knot" */
    double factor[TS_QTY_COUNT]; /* shown = SI value * factor */
} ts_display;

/* The name of a quantity in a specification ("length", "force", "speed",
 * "turn_rate", "time", "frequency", "angle", "mass"), and its SI unit. */
TS_API const char *ts_quantity_name(ts_quantity q);
TS_API const char *ts_quantity_si(ts_quantity q);

/* SI: m, N, m/s, rad/s, s, Hz, deg, kg (angles in degrees, as the
 * tables and the `_deg` keys show them). */
TS_API void ts_display_si(ts_display *d);

/* d, or when d is NULL a read-only SI display. */
TS_API const ts_display *ts_display_or_si(const ts_display *d);

/* Parse a display specification into d: comma-separated items, each
 * "si", "imperial" (ft, lbf, knot, lb; the rest as SI) or
 * "QUANTITY=UNIT" ("speed=knot", "force=kN", "turn_rate=deg/s"), applied
 * in order from SI ("imperial,force=kN"). A unit must be a multiple of
 * the quantity's SI unit (udunits2). `where` names the option in
 * messages ("--units"). TS_OK, TS_EINVAL (malformed, unknown quantity)
 * or TS_EUNIT (wrong or unknown unit); d is SI after a failure. */
TS_API int ts_display_parse(const ts_units *u, const char *spec,
                            const char *where, ts_display *d, ts_err *err);

/* An SI value of quantity q as shown, and the unit it is shown in. */
TS_API double ts_display_value(const ts_display *d, ts_quantity q,
                               double si);
TS_API const char *ts_display_unit(const ts_display *d, ts_quantity q);

/* A value given in the SI unit `si_unit` as shown: a quantity's SI unit
 * ("m", "N", "m/s", "rad/s", "s", "Hz", "kg", "rad"; "deg" for an angle
 * already in degrees) or a ratio of two ("N/m", "1/m"); a ratio of one
 * quantity to itself ("m/m") and anything else ("1", "1/s") stay as
 * they are. The unit shown is written to unit[size]. */
TS_API double ts_display_convert(const ts_display *d, const char *si_unit,
                                 double v, char *unit, size_t size);

/* The display unit as a name suffix: '/' becomes "_per_", '^' and blanks
 * are dropped ("lbf_per_ft", "m_per_s2"): for CSV column names. */
TS_API void ts_display_unit_token(const char *unit, char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif
