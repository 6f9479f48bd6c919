/* report_impl.h: the JSON documents of lib/report*.c written as they are
 * made (internal; lib/jsonout.h).
 *
 * A document is a jansson tree of its small parts in which each large
 * array (an equilibrium's nodes and links) is an empty array listed in a
 * tsi_json_defer: writing the tree writes those arrays element by
 * element in their place, so they are never held in memory whole. So are
 * a simulation's histories and its links' force extremes. */
#ifndef TOWSTAB_REPORT_IMPL_H
#define TOWSTAB_REPORT_IMPL_H

#include <stdio.h>

#include "jsonout.h"
#include "towstab/analysis.h"
#include "towstab/report.h"

/* ts_report_equilibrium_json; with defer (may be NULL: the arrays are
 * filled) its nodes and links left empty and listed in defer. NULL on
 * allocation failure or a full defer. */
json_t *tsi_report_equilibrium_tree(const ts_system *sys,
                                    const ts_equilibrium *eq, double wall_s,
                                    const ts_trust *trust,
                                    tsi_json_defer *defer);

/* Write tree value with defer's arrays (defer may be NULL) to stream f,
 * indented by two spaces a level or compact, ending with a newline when
 * indented. 0, or -1 with errno set (f is not closed). */
int tsi_report_dump_tree(const json_t *value, const tsi_json_defer *defer,
                         FILE *f, int indent);

/* The same, indented, to path through tsi_outfile (towstab/report.h).
 * TS_OK, TS_ENOMEM or TS_EIO naming path. */
int tsi_report_write_tree(const json_t *value, const tsi_json_defer *defer,
                          const char *path, ts_err *err);

/* The result's document (ts_report_result_json, with the keys of extra
 * added last) to stream f: `indent` as tsi_json_open's (1: the command
 * line's files, TSI_JSON_SPACED: ts_job_json's text). Its large arrays
 * are written as they are made. TS_OK, or TS_ENOMEM or TS_EIO naming
 * `name`. */
int tsi_report_result_dump(const ts_result *r, int flags, const json_t *extra,
                           FILE *f, int indent, const char *name,
                           ts_err *err);

#endif
