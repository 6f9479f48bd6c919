/* towstab/options.h: one declarative table of options per analysis, read
 * by the command line and by the scene's `analyses` entries alike
 * (doc/manual.md, "Options").
 *
 * Every option of an analysis is one row: its name (the scene key; the
 * command line spells it --name with '-' for '_'), its type (a quantity
 * with the SI unit of its dimension, a plain number, a whole number, a
 * boolean, one of a list of names, a list, text, or excitation specs),
 * its limits, its help text and where its value lands in a ts_request
 * (towstab/analysis.h); the default is what ts_request_init puts there.
 * A value is parsed and checked by the row alone, whatever its source:
 * `--speed -1` is refused exactly as `speed: -1` in a scene entry is,
 * naming where it came from ("--speed", "scene.yaml: analyses[0].speed
 * (line 12)").
 *
 * An option set collects the texts given for one analysis from several
 * sources with a priority (the command line over the scene's entry over
 * a related entry, e.g. the first simulate entry of a convergence study
 * of a simulation), and applies, for every option, the texts of the
 * highest priority that gave it; options not given keep their default.
 * Options of one group (compare and linear; the sweeps links, tolerances
 * and steps) exclude each other: given from different sources the higher
 * one wins, from the same source both are refused.
 */
#ifndef TOWSTAB_OPTIONS_H
#define TOWSTAB_OPTIONS_H

#include <stddef.h>

#include "towstab/analysis.h"
#include "towstab/error.h"
#include "towstab/scene.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_OPT_QUANTITY = 0, /* number with a unit of the dimension of `unit`
                            (bare: SI) -> double */
    TS_OPT_NUMBER = 1,   /* plain number -> double */
    TS_OPT_INT = 2,      /* whole number -> int */
    TS_OPT_LONG = 3,     /* whole number -> long */
    TS_OPT_BOOL = 4,     /* true/false, yes/no, 1/0 -> int; the command
                            line has --name and --no-name */
    TS_OPT_ENUM = 5,     /* one of `choices` -> int (`values`, or the
                            index) */
    TS_OPT_TEXT = 6,     /* non-empty text -> char[size]; with `choices`
                            one of them */
    TS_OPT_SPECS = 7,    /* excitation specs (towstab/excitation.h),
                            ';'-separated, repeatable on the command line
                            -> the request's excitation */
    TS_OPT_LIST = 8,     /* comma-separated values (custom) */
    TS_OPT_CUSTOM = 9    /* parsed by `parse` */
} ts_opt_type;

/* Flags of a row. */
#define TS_OPT_MIN_OPEN 1  /* the lower limit is excluded */
#define TS_OPT_MAX_OPEN 2  /* the upper limit is excluded */
#define TS_OPT_REPEAT 4    /* may be given several times on the command
                              line (its texts add up) */
#define TS_OPT_YIELD 8     /* a setting whose valid range follows from
                              other options (the run length): given by a
                              lower source, it yields to its default when
                              a higher source's values contradict it */

/* Sections: the part of a request an option sets. */
typedef enum {
    TS_SEC_SETUP = 0, TS_SEC_MODES = 1, TS_SEC_RESPONSE = 2,
    TS_SEC_SIMULATE = 3, TS_SEC_CONVERGE = 4
} ts_opt_section;

typedef struct ts_option ts_option;

/* A custom parser: set the value of row `o` from `text` into rq; `where`
 * names the source in messages. */
typedef int (*ts_opt_parse_fn)(const ts_option *o, ts_request *rq,
                               const char *text, const char *where,
                               const ts_units *u, ts_err *err);

struct ts_option {
    const char *name;     /* scene key */
    ts_opt_type type;
    ts_opt_section section;
    const char *unit;     /* QUANTITY: the SI unit ("s", "m/s", "Hz") */
    double min, max;      /* limits of numbers (NAN: none) */
    int flags;
    const char *const *choices; /* ENUM and TEXT: the names, NULL-ended */
    const int *values;    /* ENUM: the value of each name (NULL: index) */
    size_t offset;        /* where the value lands in ts_request */
    size_t size;          /* TEXT: capacity of the char array */
    size_t flag_offset;   /* when nonzero: an int set to 1 when given */
    int group;            /* nonzero: options of one group exclude each
                             other */
    int only;             /* converge: applies to a study of this kind + 1
                             only (0: always) */
    ts_opt_parse_fn parse;/* CUSTOM and LIST */
    const char *arg;      /* the command line's metavariable ("Q", "N") */
    const char *help;     /* one line */
    const char *deftext;  /* the default in words when the value a fresh
                             request holds does not say it ("the scene's
                             tow.speed"); NULL otherwise */
};

/* The table of an analysis: *n rows. */
TS_API const ts_option *ts_options(ts_analysis_kind kind, int *n);

/* The row of `kind` named `name` (scene key, or the command line's
 * spelling with '-'), or NULL. */
TS_API const ts_option *ts_option_find(ts_analysis_kind kind,
                                       const char *name);

/* The command line's name of a row ("turn-rate"), into buf. */
TS_API void ts_option_cli_name(const ts_option *o, char *buf, size_t size);

/* Parse `text` as row o and set it in rq. TS_OK, or TS_EINVAL/TS_EUNIT
 * with a message starting with `where`. SPECS add to what rq has. */
TS_API int ts_option_set(const ts_option *o, ts_request *rq,
                         const char *text, const char *where,
                         const ts_units *u, ts_err *err);

/* The default of row o as text ("10 s", "auto", "" when none), from a
 * request of `kind` fresh from ts_request_init. */
TS_API void ts_option_default_text(const ts_option *o, ts_analysis_kind kind,
                                   char *buf, size_t size);

/* The limits of row o in words ("> 0", "[1, 100000]", "auto, shooting,
 * newton"), into buf. */
TS_API void ts_option_limits_text(const ts_option *o, char *buf,
                                  size_t size);

/* ---- option sets ------------------------------------------------------- */

/* Priorities of the sources. */
#define TS_OPTSET_RELATED 0   /* a related entry (a study's simulation) */
#define TS_OPTSET_SCENE 1     /* the analysis' own scene entry */
#define TS_OPTSET_COMMAND 2   /* the command line */

typedef struct ts_optset ts_optset;

TS_API ts_optset *ts_optset_alloc(ts_analysis_kind kind, ts_err *err);
TS_API void ts_optset_free(ts_optset *s);

/* Give option `name` (scene key or command-line spelling) the text `text`
 * from a source of `priority`; `where` names it. A second text of a
 * non-repeatable option from one source replaces the first (the last one
 * counts, as on any command line). TS_EINVAL for a name the table does
 * not have. Texts are copied. */
TS_API int ts_optset_give(ts_optset *s, const char *name, const char *text,
                          int priority, const char *where, ts_err *err);

/* Give every option of scene entry `a` (analyses[index] of `file`) at
 * `priority`: refuses (TS_ESCENE) a key the table of the entry's type
 * does not have. With `section` >= 0 only options of that section are
 * taken (a related entry). */
TS_API int ts_optset_give_entry(ts_optset *s, const ts_scene_analysis *a,
                                int index, const char *file, int priority,
                                int section, ts_err *err);

/* The scene's options for the set: its entry analyses[index] (of the
 * set's kind), or with index -1 the scene's first entry of the set's
 * kind when it has one, at TS_OPTSET_SCENE; and for a convergence study
 * of a simulation (its `analysis` given as "simulate" by then) the
 * scene's first simulate entry's simulation settings at
 * TS_OPTSET_RELATED. So `towstab KIND SCENE` and a binding take a scene's
 * options alike (doc/manual.md, "Options"). TS_OK, or TS_ESCENE/TS_EINVAL
 * naming the entry's option, TS_EINVAL for an index out of range or of
 * another kind. */
TS_API int ts_optset_give_scene(ts_optset *s, const ts_scene *scene,
                                int index, ts_err *err);

/* Longest text of the notes of ts_optset_request. */
#define TS_OPTSET_NOTES_MAX 2048

/* The request of the set, checked against sys (ts_request_init of the
 * set's kind, ts_optset_apply of every source, ts_analysis_check): a
 * value of a lower source with TS_OPT_YIELD (a scene's transient or
 * sample) that the higher source's values contradict, and that holds
 * without them, is dropped so that its default is used; the located
 * message that made it yield is added to `notes` (size bytes, may be
 * NULL; one line each, cut to fit). Any other failure is returned with
 * its message located (ts_optset_locate). On TS_OK rq holds the request
 * (release with ts_request_clear); on failure rq is cleared. */
TS_API int ts_optset_request(ts_optset *s, const ts_system *sys,
                             const ts_units *u, ts_request *rq, char *notes,
                             size_t size, ts_err *err);

/* The winning text of option `name` (the first, for a repeatable one),
 * or NULL when it was not given. */
TS_API const char *ts_optset_text(const ts_optset *s, const char *name);

/* Where the winning value of option `name` came from, or NULL. */
TS_API const char *ts_optset_where(const ts_optset *s, const char *name);

/* Apply the winners among the sources of priority <= `max_priority` to
 * rq (initialised for the set's kind): parse and check every value
 * (ts_option_set), refuse options of one group given by one source and
 * options of a convergence study that do not apply to its analysis. */
TS_API int ts_optset_apply(const ts_optset *s, int max_priority,
                           const ts_units *u, ts_request *rq, ts_err *err);

/* The highest priority any option was given at, -1 when none. */
TS_API int ts_optset_top(const ts_optset *s);

/* A message of the library naming an option by its key ("t_end: ...")
 * is made to name where its value came from ("--t-end: ..."). */
TS_API void ts_optset_locate(const ts_optset *s, ts_err *err);

/* Drop option `name`: it returns to its default. */
TS_API void ts_optset_drop(ts_optset *s, const char *name);

/* The key an error message starts with ("transient" of "transient:
 * ..."), when it is a TS_OPT_YIELD option given at a priority below the
 * highest given; NULL otherwise. Used to let a scene value that the
 * command line's values contradict yield to its default. */
TS_API const char *ts_optset_yields(const ts_optset *s, const ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
