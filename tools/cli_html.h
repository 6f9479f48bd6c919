/* cli_html.h: an HTML page made in memory, and the pieces of it that
 * `towstab report` writes (tools only): escaped text, numbers, tables made
 * from a result's JSON (towstab/report_result.h), pictures as data URIs.
 * Nothing here fetches anything: a page made with these is one
 * self-contained file. */
#ifndef TOWSTAB_CLI_HTML_H
#define TOWSTAB_CLI_HTML_H

#include <jansson.h>
#include <stddef.h>
#include <stdio.h>

#include "towstab/error.h"

/* A page being written: fprintf into f, then cli_page_close. */
typedef struct cli_page {
    FILE *f;      /* the stream (open_memstream) */
    char *buf;    /* after cli_page_close: the page, len bytes */
    size_t len;
} cli_page;

/* Open an empty page. TS_OK or TS_ENOMEM. */
int cli_page_open(cli_page *p, ts_err *err);
/* Finish writing: buf and len hold the page. TS_OK or TS_ENOMEM (a write
 * into memory failed). */
int cli_page_close(cli_page *p, ts_err *err);
void cli_page_free(cli_page *p);

/* Text with & < > " ' escaped; the first n bytes (cli_html_textn). */
void cli_html_text(FILE *f, const char *s);
void cli_html_textn(FILE *f, const char *s, size_t n);

/* A number with `digits` significant digits ("-" when not finite; the
 * minus sign and exponent as C prints them). */
void cli_html_number(FILE *f, double v, int digits);

/* The unit of a JSON key of the results (doc/manual.md, "Output
 * conventions": the suffixes _deg, _s, _hz, _pct, _m, _N and the keys
 * defined there with a unit), or NULL when it has none or it depends on
 * the result (a response's magnitude). */
const char *cli_html_unit(const char *key);

/* The members of JSON object `o` as tables, headed at level `level`
 * (h3..h6): its scalars (and short lists) as one table of key, value and
 * unit; each list of objects as a table with a column per key (nested
 * objects flattened as key.sub; a row's "values" and "errors" objects as
 * "value +- error" cells), long ones folded; each nested object as a
 * table of its own, recursively. Members named in `skip` (NULL-ended;
 * may be NULL) are left out at the top level. Long lists of numbers are
 * summarised by their count and range. */
void cli_html_json(FILE *f, const json_t *o, int level,
                   const char *const skip[]);

/* A picture: the SVG file at `path` as <img> with a data URI (the SVG
 * percent-encoded, so that one page holds it and nothing is fetched),
 * inside a <figure> captioned with the SVG's <title> (towstab/plot.h
 * writes one), else with `caption`. TS_OK, TS_EIO (cannot read it) or
 * TS_ENOMEM. */
int cli_html_svg(FILE *f, const char *path, const char *caption,
                 ts_err *err);

#endif
