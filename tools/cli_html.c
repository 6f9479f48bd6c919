/* cli_html.c: an HTML page made in memory, tables from a result's JSON,
 * pictures as data URIs (cli_html.h). */
#include "cli_html.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A list of numbers longer than this is summarised (count and range). */
#define LIST_INLINE 6
/* A table with more rows than this is folded under a <details>. */
#define ROWS_OPEN 12
/* Columns of a table made from a list of objects, at most, and in one
 * table on the page (more are split over several). */
#define MAX_COLUMNS 64
#define TABLE_COLUMNS 6
/* Largest picture read, bytes. */
#define SVG_MAX (64L * 1024 * 1024)
/* Deepest nesting of objects shown as tables of their own. */
#define MAX_LEVEL 6

int cli_page_open(cli_page *p, ts_err *err)
{
    memset(p, 0, sizeof *p);
    p->f = open_memstream(&p->buf, &p->len);
    return p->f ? TS_OK
                : ts_fail(err, TS_ENOMEM, "out of memory for the page");
}

int cli_page_close(cli_page *p, ts_err *err)
{
    int bad = ferror(p->f);
    bad |= fclose(p->f) != 0;
    p->f = NULL;
    return bad ? ts_fail(err, TS_ENOMEM, "out of memory for the page")
               : TS_OK;
}

void cli_page_free(cli_page *p)
{
    if (p->f)
        fclose(p->f);
    free(p->buf);
    memset(p, 0, sizeof *p);
}

void cli_html_textn(FILE *f, const char *s, size_t n)
{
    for (size_t i = 0; i < n && s[i]; i++) {
        switch (s[i]) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&#39;", f); break;
        default: fputc(s[i], f);
        }
    }
}

void cli_html_text(FILE *f, const char *s)
{
    cli_html_textn(f, s, s ? strlen(s) : 0);
}

void cli_html_number(FILE *f, double v, int digits)
{
    if (isfinite(v))
        fprintf(f, "%.*g", digits, v);
    else
        fputs("-", f);
}

/* Keys with a unit that their name does not carry (doc/manual.md). */
static const struct {
    const char *key, *unit;
} key_units[] = {
    {"x", "m"}, {"y", "m"}, {"z", "m"}, {"shape_error", "m"},
    {"lever", "m"}, {"tension", "N"}, {"top_tension", "N"},
    {"min_tension", "N"}, {"tow_force", "N"}, {"force_scale", "N"},
    {"speed", "m/s"}, {"turn_rate", "rad/s"}, {"re", "1/s"},
    {"im", "rad/s"}, {"max_real", "1/s"}, {"max_real_error", "1/s"},
    {"error_bound", "1/s"}, {"t_end", "s"}, {"sample", "s"},
    {"final_t", "s"}, {"t_reached", "s"}, {"h_last", "s"},
    {"transient", "s"}, {"vector_error", "rad"}, {"kinetic", "J"},
    {"potential", "J"}, {"t", "s"}};

/* Suffixes that say the unit (doc/manual.md, "Output conventions"). */
static const struct {
    const char *suffix, *unit;
} suffix_units[] = {{"_deg", "deg"}, {"_s", "s"},   {"_hz", "Hz"},
                    {"_Hz", "Hz"},   {"_pct", "%"}, {"_m", "m"},
                    {"_N", "N"}};

const char *cli_html_unit(const char *key)
{
    for (size_t i = 0; i < sizeof key_units / sizeof key_units[0]; i++)
        if (!strcmp(key, key_units[i].key))
            return key_units[i].unit;
    size_t n = strlen(key);
    for (size_t i = 0; i < sizeof suffix_units / sizeof suffix_units[0];
         i++) {
        size_t m = strlen(suffix_units[i].suffix);
        if (n > m && !strcmp(key + n - m, suffix_units[i].suffix))
            return suffix_units[i].unit;
    }
    return NULL;
}

static int is_scalar(const json_t *v)
{
    return !json_is_object(v) && !json_is_array(v);
}

/* A list whose every element passes `is` (and, with `nonempty`, is not
 * empty). */
static int list_of(const json_t *v, int (*is)(const json_t *), int nonempty)
{
    if (!json_is_array(v) || (nonempty && json_array_size(v) == 0))
        return 0;
    size_t i;
    const json_t *e;
    json_array_foreach(v, i, e) if (!is(e)) return 0;
    return 1;
}

static int is_string(const json_t *v) { return json_is_string(v); }
static int is_number(const json_t *v)
{
    return json_is_number(v) || json_is_null(v);
}
static int is_object(const json_t *v) { return json_is_object(v); }

/* A list of numbers (or nulls, for numbers that are not finite). */
static int is_number_list(const json_t *v)
{
    return list_of(v, is_number, 1);
}

static int is_string_list(const json_t *v)
{
    return list_of(v, is_string, 0);
}

static int is_object_list(const json_t *v)
{
    return list_of(v, is_object, 1);
}

/* An object whose members are all scalars. */
static int is_flat_object(const json_t *v)
{
    if (!json_is_object(v))
        return 0;
    const char *k;
    const json_t *e;
    json_object_foreach((json_t *)v, k, e) if (!is_scalar(e)) return 0;
    return 1;
}

static void scalar(FILE *f, const json_t *v)
{
    if (json_is_integer(v))
        fprintf(f, "%" JSON_INTEGER_FORMAT, json_integer_value(v));
    else if (json_is_real(v))
        cli_html_number(f, json_real_value(v), 6);
    else if (json_is_true(v))
        fputs("yes", f);
    else if (json_is_false(v))
        fputs("no", f);
    else if (json_is_string(v))
        cli_html_text(f, json_string_value(v));
    else
        fputs("-", f);
}

/* A value in a cell: a scalar, a short list inline, a long list of
 * numbers by its count and range, strings one per line, anything else by
 * its size. */
static void cell(FILE *f, const json_t *v)
{
    if (is_scalar(v)) {
        scalar(f, v);
        return;
    }
    size_t n = json_array_size(v), i;
    const json_t *e;
    if (is_number_list(v) && n > LIST_INLINE) {
        double lo = INFINITY, hi = -INFINITY;
        json_array_foreach(v, i, e) if (json_is_number(e))
        {
            double x = json_number_value(e);
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
        }
        fprintf(f, "%zu values in [", n);
        cli_html_number(f, lo, 6);
        fputs(", ", f);
        cli_html_number(f, hi, 6);
        fputs("]", f);
    } else if (is_string_list(v)) {
        json_array_foreach(v, i, e)
        {
            if (i)
                fputs("<br>", f);
            cli_html_text(f, json_string_value(e));
        }
        if (n == 0)
            fputs("none", f);
    } else if (json_is_array(v) && !is_object_list(v)) {
        json_array_foreach(v, i, e)
        {
            fputs(i ? ", " : "", f);
            if (is_scalar(e))
                scalar(f, e);
            else
                fputs("...", f);
        }
    } else if (json_is_array(v)) {
        fprintf(f, "%zu entries", n);
    } else {
        fprintf(f, "%zu members", json_object_size(v));
    }
}

static void heading(FILE *f, int level, const char *text)
{
    int h = level < 6 ? level : 6;
    fprintf(f, "<h%d>", h);
    cli_html_text(f, text);
    fprintf(f, "</h%d>\n", h);
}

/* A key in a heading cell, breakable after '_' and '.'. */
static void key_text(FILE *f, const char *key)
{
    for (const char *p = key; *p; p++) {
        size_t n = strcspn(p, "_.");
        cli_html_textn(f, p, n + (p[n] != '\0'));
        p += n;
        if (!*p)
            break;
        fputs("<wbr>", f);
    }
}

static void head_cell(FILE *f, const char *key, const char *sub)
{
    fputs("<th>", f);
    key_text(f, key);
    if (sub) {
        fputs(".<wbr>", f);
        key_text(f, sub);
    }
    const char *u = cli_html_unit(sub ? sub : key);
    if (u) {
        fputs(" [", f);
        cli_html_text(f, u);
        fputs("]", f);
    }
    fputs("</th>", f);
}

static int skipped(const char *key, const char *const skip[])
{
    for (int i = 0; skip && skip[i]; i++)
        if (!strcmp(key, skip[i]))
            return 1;
    return 0;
}

/* The scalars of o (and lists that are not tables) as rows of key, value,
 * unit; nothing when there are none. */
static void scalar_table(FILE *f, const json_t *o, const char *const skip[])
{
    const char *k;
    const json_t *v;
    int n = 0;
    json_object_foreach((json_t *)o, k, v)
    {
        if (skipped(k, skip) || json_is_object(v) || is_object_list(v))
            continue;
        if (!n++)
            fputs("<div class=\"wide\"><table class=\"kv\">\n"
                  "<tr><th>key</th><th>value</th><th>unit</th></tr>\n",
                  f);
        fputs("<tr><td>", f);
        cli_html_text(f, k);
        fputs(json_is_number(v) || is_number_list(v) ? "</td><td class=\"num\">"
                                                     : "</td><td>",
              f);
        cell(f, v);
        fputs("</td><td>", f);
        const char *u = cli_html_unit(k);
        cli_html_text(f, u ? u : "");
        fputs("</td></tr>\n", f);
    }
    if (n)
        fputs("</table></div>\n", f);
}

/* The columns of a list of objects: its members' keys in the order first
 * seen; a flat nested object becomes its sub-keys. */
typedef struct column {
    const char *key;
    const char *sub; /* NULL: the member itself */
} column;

static int has_column(const column *c, int n, const char *key,
                      const char *sub)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(c[i].key, key) &&
            ((!sub && !c[i].sub) || (sub && c[i].sub &&
                                     !strcmp(c[i].sub, sub))))
            return 1;
    return 0;
}

/* A row's "errors" object holds the errors of its "values" object: shown
 * in the value cells, not as columns of their own; relative errors and
 * orders are left to the tables of the study. */
static int merged_into_values(const json_t *row, const char *key)
{
    return json_is_object(json_object_get(row, "values")) &&
           (!strcmp(key, "errors") || !strcmp(key, "relative_errors") ||
            !strcmp(key, "orders"));
}

static int columns_of(const json_t *list, column *c)
{
    int n = 0;
    size_t i;
    const json_t *row;
    json_array_foreach(list, i, row)
    {
        const char *k;
        const json_t *v;
        json_object_foreach((json_t *)row, k, v)
        {
            if (merged_into_values(row, k))
                continue;
            if (is_flat_object(v) && json_object_size(v) > 0) {
                const char *s;
                const json_t *e;
                json_object_foreach((json_t *)v, s, e) if (
                    n < MAX_COLUMNS && !has_column(c, n, k, s))
                    c[n++] = (column){k, s};
            } else if (n < MAX_COLUMNS && !has_column(c, n, k, NULL)) {
                c[n++] = (column){k, NULL};
            }
        }
    }
    return n;
}

/* Columns [c0, c1) of the rows of `list` as one table, each row led by
 * its number when the columns are split over several tables. */
static void list_part(FILE *f, const json_t *list, const column *c, int c0,
                      int c1, int numbered)
{
    fputs("<div class=\"wide\"><table>\n<tr>", f);
    if (numbered)
        fputs("<th>#</th>", f);
    for (int j = c0; j < c1; j++)
        head_cell(f, c[j].key, c[j].sub);
    fputs("</tr>\n", f);
    size_t i;
    const json_t *row;
    json_array_foreach(list, i, row)
    {
        fputs("<tr>", f);
        if (numbered)
            fprintf(f, "<td class=\"num\">%zu</td>", i + 1);
        for (int j = c0; j < c1; j++) {
            const json_t *v = json_object_get(row, c[j].key);
            const json_t *e = NULL;
            if (c[j].sub) {
                v = json_object_get(v, c[j].sub);
                if (!strcmp(c[j].key, "values"))
                    e = json_object_get(json_object_get(row, "errors"),
                                        c[j].sub);
            }
            fputs(json_is_number(v) ? "<td class=\"num\">" : "<td>", f);
            if (v)
                cell(f, v);
            if (e && json_is_number(e)) {
                fputs(" &plusmn; ", f);
                cli_html_number(f, json_number_value(e), 2);
            }
            fputs("</td>", f);
        }
        fputs("</tr>\n", f);
    }
    fputs("</table></div>\n", f);
}

static void list_table(FILE *f, const char *key, const json_t *list,
                       int level)
{
    column c[MAX_COLUMNS];
    int nc = columns_of(list, c);
    size_t nrows = json_array_size(list);
    int fold = nrows > ROWS_OPEN;
    if (fold) {
        fputs("<details><summary>", f);
        cli_html_text(f, key);
        fprintf(f, ": %zu rows</summary>\n", nrows);
    } else {
        heading(f, level, key);
    }
    /* Too many columns for the page: several tables, rows numbered. */
    int numbered = nc > TABLE_COLUMNS;
    for (int c0 = 0; c0 < nc; c0 += TABLE_COLUMNS)
        list_part(f, list, c, c0,
                  c0 + TABLE_COLUMNS < nc ? c0 + TABLE_COLUMNS : nc,
                  numbered);
    if (fold)
        fputs("</details>\n", f);
}

void cli_html_json(FILE *f, const json_t *o, int level,
                   const char *const skip[])
{
    scalar_table(f, o, skip);
    const char *k;
    const json_t *v;
    json_object_foreach((json_t *)o, k, v)
    {
        if (skipped(k, skip))
            continue;
        if (is_object_list(v)) {
            list_table(f, k, v, level);
        } else if (json_is_object(v) && json_object_size(v) > 0 &&
                   level < MAX_LEVEL) {
            heading(f, level, k);
            cli_html_json(f, v, level + 1, NULL);
        }
    }
}

/* The file at `path`, whole, into *buf (caller frees) and *len. */
static int slurp(const char *path, char **buf, size_t *len, ts_err *err)
{
    *buf = NULL;
    *len = 0;
    FILE *in = fopen(path, "rb");
    if (!in)
        return ts_fail(err, TS_EIO, "%s: cannot read the picture", path);
    size_t cap = 0;
    int rc = TS_OK;
    for (;;) {
        if (*len == cap) {
            size_t want = cap ? 2 * cap : 65536;
            char *b = want <= (size_t)SVG_MAX + 1 ? realloc(*buf, want)
                                                  : NULL;
            if (!b) {
                rc = want > (size_t)SVG_MAX + 1
                         ? ts_fail(err, TS_EIO, "%s: larger than %ld bytes",
                                   path, SVG_MAX)
                         : ts_fail(err, TS_ENOMEM, "%s: out of memory",
                                   path);
                break;
            }
            *buf = b;
            cap = want;
        }
        size_t got = fread(*buf + *len, 1, cap - *len, in);
        *len += got;
        if (got == 0)
            break;
    }
    if (rc == TS_OK && ferror(in))
        rc = ts_fail(err, TS_EIO, "%s: cannot read the picture", path);
    fclose(in);
    if (rc != TS_OK) {
        free(*buf);
        *buf = NULL;
    }
    return rc;
}

/* The first `word` in buf[n], or NULL. */
static const char *find(const char *buf, size_t n, const char *word)
{
    size_t m = strlen(word);
    for (size_t i = 0; i + m <= n; i++)
        if (buf[i] == word[0] && !memcmp(buf + i, word, m))
            return buf + i;
    return NULL;
}

int cli_html_svg(FILE *f, const char *path, const char *caption,
                 ts_err *err)
{
    char *svg;
    size_t n;
    int rc = slurp(path, &svg, &n, err);
    if (rc != TS_OK)
        return rc;
    /* The title as the SVG holds it, XML-escaped: the same text in HTML
     * when it has no markup and no quote. */
    const char *t = find(svg, n, "<title>"), *te = NULL;
    if (t) {
        t += 7;
        te = find(t, n - (size_t)(t - svg), "</title>");
    }
    int titled = te && te > t && !memchr(t, '<', (size_t)(te - t)) &&
                 !memchr(t, '"', (size_t)(te - t));
    fputs("<figure><img alt=\"", f);
    if (titled)
        fwrite(t, 1, (size_t)(te - t), f);
    else
        cli_html_text(f, caption);
    fputs("\" src=\"data:image/svg+xml,", f);
    /* Percent-encode what a URI or the quoted attribute cannot hold:
     * controls, non-ASCII bytes and " # % & ' < >. */
    static const char hex[] = "0123456789ABCDEF";
    for (size_t i = 0; i < n; i++) {
        unsigned char ch = (unsigned char)svg[i];
        if (ch < 0x20 || ch >= 0x7f || strchr("\"#%&'<>", ch)) {
            fputc('%', f);
            fputc(hex[ch >> 4], f);
            fputc(hex[ch & 15], f);
        } else {
            fputc(ch, f);
        }
    }
    fputs("\"><figcaption>", f);
    if (titled)
        fwrite(t, 1, (size_t)(te - t), f);
    else
        cli_html_text(f, caption);
    fputs("</figcaption></figure>\n", f);
    free(svg);
    return TS_OK;
}
