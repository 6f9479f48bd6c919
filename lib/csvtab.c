/* csvtab.c: numeric CSV tables with a unit-carrying header (csvtab.h).
 *
 * One pass over the lines: comments and blanks skipped, "key: value"
 * properties until the header, the header split into "name [unit]" cells,
 * then rows of numbers parsed with strtod (finite only, nothing after a
 * number but blanks and the separating comma). */
#include "csvtab.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Longest line accepted. */
#define LINE_MAX_TAB 4096

char *tsi_csv_trim(char *s)
{
    while (*s == ' ' || *s == '\t' || *s == '\r')
        s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r'))
        s[--n] = '\0';
    return s;
}

static void lower(char *s)
{
    for (; *s; s++)
        *s = (char)tolower((unsigned char)*s);
}

/* A property line is "key: value" with a key of letters, digits, '_' or
 * '-' and no comma before the colon. */
static int is_property(const char *s)
{
    const char *c = strchr(s, ':');
    if (!c || c == s)
        return 0;
    for (const char *p = s; p < c; p++)
        if (!(isalnum((unsigned char)*p) || *p == '_' || *p == '-' ||
              *p == ' '))
            return 0;
    return 1;
}

static int parse_header(tsi_csv *t, char *s, int lineno, ts_err *err)
{
    t->header_line = lineno;
    t->ncols = 0;
    char *save = NULL;
    char *copy = s;
    for (char *cell = strtok_r(copy, ",", &save); cell;
         cell = strtok_r(NULL, ",", &save)) {
        if (t->ncols == TSI_CSV_MAX_COLS)
            return ts_fail(err, TS_EINVAL, "%s line %d: more than %d "
                           "columns", t->path, lineno, TSI_CSV_MAX_COLS);
        char *c = tsi_csv_trim(cell);
        char *br = strchr(c, '[');
        char unit[TSI_CSV_NAME_MAX] = "";
        if (br) {
            char *close = strchr(br, ']');
            if (!close || *tsi_csv_trim(close + 1))
                return ts_fail(err, TS_EINVAL, "%s line %d, column %d: "
                               "expected 'name [unit]', got '%.60s'",
                               t->path, lineno, t->ncols + 1, c);
            *close = '\0';
            *br = '\0';
            char *u = tsi_csv_trim(br + 1);
            if (strlen(u) >= sizeof unit || !*u)
                return ts_fail(err, TS_EINVAL, "%s line %d, column %d: the "
                               "unit in brackets is empty or longer than "
                               "%d characters", t->path, lineno,
                               t->ncols + 1, TSI_CSV_NAME_MAX - 1);
            snprintf(unit, sizeof unit, "%s", u);
        }
        c = tsi_csv_trim(c);
        if (!*c || strlen(c) >= TSI_CSV_NAME_MAX)
            return ts_fail(err, TS_EINVAL, "%s line %d, column %d: a column "
                           "name of 1 to %d characters is needed", t->path,
                           lineno, t->ncols + 1, TSI_CSV_NAME_MAX - 1);
        snprintf(t->name[t->ncols], TSI_CSV_NAME_MAX, "%s", c);
        lower(t->name[t->ncols]);
        for (int j = 0; j < t->ncols; j++)
            if (!strcmp(t->name[j], t->name[t->ncols]))
                return ts_fail(err, TS_EINVAL, "%s line %d: column '%s' "
                               "appears twice", t->path, lineno, c);
        snprintf(t->unit[t->ncols], TSI_CSV_NAME_MAX, "%s", unit);
        t->ncols++;
    }
    if (t->ncols == 0)
        return ts_fail(err, TS_EINVAL, "%s line %d: empty header", t->path,
                       lineno);
    return TS_OK;
}

static int parse_row(tsi_csv *t, const char *s, int lineno, double *row,
                     ts_err *err)
{
    const char *p = s;
    for (int j = 0; j < t->ncols; j++) {
        while (*p == ' ' || *p == '\t')
            p++;
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno == ERANGE || !isfinite(v))
            return ts_fail(err, TS_EINVAL, "%s line %d, column %d (%s): "
                           "expected a finite number, got '%.30s'", t->path,
                           lineno, j + 1, t->name[j], p);
        p = end;
        while (*p == ' ' || *p == '\t' || *p == '\r')
            p++;
        if (j < t->ncols - 1) {
            if (*p != ',')
                return ts_fail(err, TS_EINVAL, "%s line %d: expected %d "
                               "numbers (one per header column), found %d",
                               t->path, lineno, t->ncols, j + 1);
            p++;
        }
        row[j] = v;
    }
    if (*p != '\0')
        return ts_fail(err, TS_EINVAL, "%s line %d: expected %d numbers (one "
                       "per header column), found more or trailing text "
                       "'%.30s'", t->path, lineno, t->ncols, p);
    return TS_OK;
}

int tsi_csv_read(const char *path, tsi_csv *t, ts_err *err)
{
    memset(t, 0, sizeof *t);
    if (!path || strlen(path) >= sizeof t->path)
        return ts_fail(err, TS_EINVAL, "table file: a path of at most %zu "
                       "characters is needed", sizeof t->path - 1);
    snprintf(t->path, sizeof t->path, "%s", path);
    FILE *f = fopen(path, "r");
    if (!f)
        return ts_fail(err, TS_EIO, "cannot read '%s': %s", path,
                       strerror(errno));
    char line[LINE_MAX_TAB];
    int lineno = 0, cap = 0, rc = TS_OK;
    while (rc == TS_OK && fgets(line, sizeof line, f)) {
        lineno++;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n') {
            rc = ts_fail(err, TS_EINVAL, "%s line %d: longer than %d "
                         "characters", path, lineno, LINE_MAX_TAB - 2);
            break;
        }
        while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r'))
            line[--len] = '\0';
        char *s = tsi_csv_trim(line);
        if (*s == '#' || *s == '\0')
            continue;
        if (t->ncols == 0 && is_property(s)) {
            if (t->nprops == TSI_CSV_MAX_PROPS) {
                rc = ts_fail(err, TS_EINVAL, "%s line %d: more than %d "
                             "property lines", path, lineno,
                             TSI_CSV_MAX_PROPS);
                break;
            }
            char *colon = strchr(s, ':');
            *colon = '\0';
            tsi_csv_prop *pr = &t->props[t->nprops];
            char *k = tsi_csv_trim(s), *v = tsi_csv_trim(colon + 1);
            if (strlen(k) >= sizeof pr->key || strlen(v) >= sizeof pr->value) {
                rc = ts_fail(err, TS_EINVAL, "%s line %d: property too long",
                             path, lineno);
                break;
            }
            snprintf(pr->key, sizeof pr->key, "%s", k);
            lower(pr->key);
            for (int i = 0; i < t->nprops; i++)
                if (!strcmp(t->props[i].key, pr->key))
                    rc = ts_fail(err, TS_EINVAL, "%s line %d: property '%s' "
                                 "given twice (also line %d)", path, lineno,
                                 pr->key, t->props[i].line);
            snprintf(pr->value, sizeof pr->value, "%s", v);
            pr->line = lineno;
            t->nprops++;
            continue;
        }
        if (t->ncols == 0) {
            rc = parse_header(t, s, lineno, err);
            continue;
        }
        if (t->nrows == cap) {
            cap = cap ? 2 * cap : 64;
            double *d = realloc(t->data, (size_t)cap * (size_t)t->ncols *
                                             sizeof *d);
            if (d)
                t->data = d;
            int *l = realloc(t->line, (size_t)cap * sizeof *l);
            if (l)
                t->line = l;
            if (!d || !l) {
                rc = ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
                break;
            }
        }
        rc = parse_row(t, s, lineno, t->data + (size_t)t->nrows * t->ncols,
                       err);
        t->line[t->nrows] = lineno;
        if (rc == TS_OK)
            t->nrows++;
    }
    if (rc == TS_OK && ferror(f))
        rc = ts_fail(err, TS_EIO, "%s: read error", path);
    fclose(f);
    if (rc == TS_OK && t->ncols == 0)
        rc = ts_fail(err, TS_EINVAL, "%s: no header line (column names with "
                     "units in brackets)", path);
    else if (rc == TS_OK && t->nrows == 0)
        rc = ts_fail(err, TS_EINVAL, "%s: no data rows after the header "
                     "(line %d)", path, t->header_line);
    if (rc != TS_OK)
        tsi_csv_free(t);
    return rc;
}

void tsi_csv_free(tsi_csv *t)
{
    free(t->data);
    free(t->line);
    t->data = NULL;
    t->line = NULL;
    t->nrows = 0;
}

int tsi_csv_column(const tsi_csv *t, const char *name)
{
    for (int j = 0; j < t->ncols; j++)
        if (!strcmp(t->name[j], name))
            return j;
    return -1;
}

const tsi_csv_prop *tsi_csv_property(const tsi_csv *t, const char *key)
{
    for (int i = 0; i < t->nprops; i++)
        if (!strcmp(t->props[i].key, key))
            return &t->props[i];
    return NULL;
}

int tsi_csv_choice(const tsi_csv *t, const char *key,
                   const char *const words[], int n, const char *what,
                   int *choice, ts_err *err)
{
    *choice = -1;
    const tsi_csv_prop *p = tsi_csv_property(t, key);
    if (!p)
        return TS_OK;
    for (int i = 0; i < n; i++)
        if (!strcmp(p->value, words[i])) {
            *choice = i;
            return TS_OK;
        }
    char list[256] = "";
    for (int i = 0; i < n; i++) {
        strncat(list, words[i], sizeof list - strlen(list) - 1);
        if (i + 1 < n)
            strncat(list, i + 2 < n ? ", " : " or ",
                    sizeof list - strlen(list) - 1);
    }
    return ts_fail(err, TS_EINVAL, "%s line %d: %s: expected %s (%s), got "
                   "'%.40s'", t->path, p->line, key, list, what, p->value);
}

int tsi_csv_unit_scale(const ts_units *units, const tsi_csv *t, int j,
                       const char *si, const char *example, double *scale,
                       ts_err *err)
{
    if (!t->unit[j][0])
        return ts_fail(err, TS_EUNIT, "%s line %d, column %d (%s): give its "
                       "unit in brackets, e.g. '%s'", t->path, t->header_line,
                       j + 1, t->name[j], example);
    char text[TSI_CSV_NAME_MAX + 4];
    snprintf(text, sizeof text, "1 %s", t->unit[j]);
    char where[640];
    snprintf(where, sizeof where, "%s line %d, column %d (%s)", t->path,
             t->header_line, j + 1, t->name[j]);
    return ts_units_parse(units, text, si, where, scale, err);
}
