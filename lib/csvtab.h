/* csvtab.h: private reader of the numeric CSV tables with a unit-carrying
 * header that sea.c and rao.c read (wave spectra, ship RAOs).
 *
 * A table file is, in order:
 *   - comment lines starting with '#', and blank lines, anywhere;
 *   - optional property lines "key: value" (before the header only);
 *   - the header: comma-separated cells "name [unit]" (the unit may be
 *     absent: unit is then "");
 *   - data rows: exactly as many comma-separated numbers as header cells.
 * Names are trimmed and lower-cased; units are kept as written. Every
 * message names the file and line (and the column where it applies).
 */
#ifndef TOWSTAB_CSVTAB_H
#define TOWSTAB_CSVTAB_H

#include "towstab/error.h"
#include "towstab/units.h"

/* Longest header cell name, unit, property key and value. */
#define TSI_CSV_NAME_MAX 64
#define TSI_CSV_VALUE_MAX 256
/* Most columns and properties in one table. */
#define TSI_CSV_MAX_COLS 32
#define TSI_CSV_MAX_PROPS 8

typedef struct tsi_csv_prop {
    char key[TSI_CSV_NAME_MAX];     /* lower-cased */
    char value[TSI_CSV_VALUE_MAX];  /* trimmed */
    int line;
} tsi_csv_prop;

typedef struct tsi_csv {
    char path[512];
    int nprops;
    tsi_csv_prop props[TSI_CSV_MAX_PROPS];
    int header_line;
    int ncols;
    char name[TSI_CSV_MAX_COLS][TSI_CSV_NAME_MAX]; /* lower-cased */
    char unit[TSI_CSV_MAX_COLS][TSI_CSV_NAME_MAX]; /* "" when absent */
    int nrows;
    double *data;   /* [nrows * ncols], row-major */
    int *line;      /* [nrows] file line of each row */
} tsi_csv;

/* Read `path` into *t (fields zeroed first). TS_EIO when the file cannot be
 * read; TS_EINVAL for a malformed line (named), no header or no rows;
 * TS_ENOMEM. On failure *t holds nothing to free. */
int tsi_csv_read(const char *path, tsi_csv *t, ts_err *err);

/* Release the rows. Safe on a zeroed table. */
void tsi_csv_free(tsi_csv *t);

/* Column whose name is `name`, or -1. */
int tsi_csv_column(const tsi_csv *t, const char *name);

/* The property `key`, or NULL. */
const tsi_csv_prop *tsi_csv_property(const tsi_csv *t, const char *key);

/* The value of property `key` as the index of one of `n` words (-1 when
 * the property is absent); TS_EINVAL naming the file, line and the words
 * (`what` explains them) for another value. */
int tsi_csv_choice(const tsi_csv *t, const char *key,
                   const char *const words[], int n, const char *what,
                   int *choice, ts_err *err);

/* The factor from column j's unit to `si` (the value of "1 <unit>" in
 * si); TS_EUNIT naming the column, with `example` (e.g. "omega [rad/s]"),
 * when the column has no unit or one of another dimension. */
int tsi_csv_unit_scale(const ts_units *units, const tsi_csv *t, int j,
                       const char *si, const char *example, double *scale,
                       ts_err *err);

/* Blanks trimmed at both ends, in place. */
char *tsi_csv_trim(char *s);

#endif
