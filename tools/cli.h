/* cli.h: what the towstab subcommands share (tools only; the library never
 * prints). A command is parse -> run -> print: its options come from the
 * analysis' option table (towstab/options.h) on the command line and in
 * the scene's entry, the library runs the pipeline (towstab/analysis.h),
 * and the command prints the result, writes its JSON and CSV
 * (towstab/report_result.h) and draws it. Each subcommand lives in
 * tools/cmd_<name>.c and exports one cli_command; tools/towstab.c lists
 * them. */
#ifndef TOWSTAB_CLI_H
#define TOWSTAB_CLI_H

#include <jansson.h>
#include <stdio.h>

#include "cli_plot.h"
#include "towstab/analysis.h"
#include "towstab/error.h"
#include "towstab/options.h"
#include "towstab/progress.h"
#include "towstab/report_result.h"
#include "towstab/scene.h"
#include "towstab/system.h"
#include "towstab/units.h"

#define EXIT_FAILED 1   /* the analysis failed: no convergence, I/O */
#define EXIT_BADINPUT 2 /* usage, scene, units, impossible configuration */

/* An option of a command beyond its analysis' table: what to write or
 * draw (command line only). */
typedef struct cli_extra {
    const char *name;   /* "shapes" (--shapes) */
    int has_arg;        /* 1: takes a value; 0: a flag */
    int repeat;         /* 1: may be given several times */
    const char *arg;    /* metavariable */
    const char *help;
} cli_extra;

#define CLI_EXTRA_MAX 10
#define CLI_EXTRA_VALUES 8

/* One run of an analysis command (or of one entry of `towstab run`). */
typedef struct cli_run {
    const struct cli_command *cmd;
    const ts_scene *scene;
    const ts_units *units;
    ts_request rq;
    ts_optset *opts;
    int quiet;
    int entry;              /* -1: the command line; else analyses[entry] */
    const char *json, *csv; /* output paths, NULL when not asked for */
    cli_plot plot;          /* --plot DIR and --units */
    int plot_optional;      /* 1: an analysis that has no pictures runs
                               without them (towstab report); 0: it
                               refuses --plot */
    ts_display display;     /* --units: what tables, CSV and pictures show
                               (cli_display_begin) */
    int json_flags;         /* TS_REPORT_* */
    /* The extras given: values[k][0..nvalues[k]) for cmd->extras[k]. */
    const char *extra[CLI_EXTRA_MAX][CLI_EXTRA_VALUES];
    int nextra[CLI_EXTRA_MAX];
    void *state;            /* the command's own (released by release) */
    /* Every option of the table and every extra given on the command
     * line, as "--name=value" ("--name" for a flag), in order (outputs
     * apart): what a command that records its settings keeps. */
    char **given;
    int ngiven;
    /* `towstab run --json`: the document each result is added to as it
     * comes (cli_execute), NULL when none; after the run, whether a
     * result was added and, when it failed, its "error". */
    ts_report_results *into;
    int added, failed;
    char error[TS_ERR_MSG_MAX];
} cli_run;

typedef struct cli_command {
    const char *name;
    const char *summary;
    int kind;               /* ts_analysis_kind; -1 for run */
    /* `towstab run`: its own main. NULL for analyses (cli_main runs
     * them). */
    int (*main)(int argc, char **argv);
    /* Check the extras and prepare what the pictures need before anything
     * runs; prints and returns the exit status. May be NULL. */
    int (*prepare)(cli_run *c);
    /* Print the result (tables, verdict): everything but the header. */
    void (*print)(const cli_run *c, const ts_result *r);
    /* Pictures and extra files; prints and returns the exit status. May
     * be NULL. */
    int (*draw)(cli_run *c, const ts_result *r);
    void (*release)(cli_run *c);
    const char *const *pictures;  /* what --plot writes (NAME.png/.svg) */
    const cli_extra *extras;      /* NULL-name-terminated, may be NULL */
    /* Run a prepared c in place of cli_execute (a sweep of the analysis
     * `kind`): prints, writes, draws; returns the exit status. May be
     * NULL. */
    int (*execute)(cli_run *c);
} cli_command;

double cli_wall_now(void);

/* The value of the last `--analysis A` (or `--analysis=A`) of argv, NULL
 * when none: commands built for another analysis (sweep, design) read it
 * before their option table is known. */
const char *cli_analysis_arg(int argc, char **argv);

/* Exit status for a library code. */
int cli_exit_code(int rc);

/* Print "towstab: error: <message>" and return the exit status. A message
 * about the scene's analysis (a failed analysis, an option of an
 * `analyses` entry) gets the scene file in front, in err too, so that a
 * JSON written afterwards gives the same reason. */
int cli_report(ts_err *err, int rc);

/* Load units and a scene; on failure prints and returns the status. Free
 * with cli_close(). */
int cli_open(const char *path, ts_units **units, ts_scene **scene);
void cli_close(ts_units *units, ts_scene *scene);

/* The command line of an analysis command: options of the table, the
 * outputs, the command's extras, one scene; then the run (cli_execute).
 * Returns the exit status. */
int cli_main(const struct cli_command *cmd, int argc, char **argv);

/* Prepare c (c->cmd, scene, units, entry and c->opts filled) into
 * c->rq: apply the options, check the request against the system (a scene
 * value the command line contradicts yields to its default, with a
 * note), then the command's prepare. Prints; returns the exit status. */
int cli_prepare(cli_run *c);

/* Run a prepared c, print, write and draw. Sets *result (may be NULL) to
 * its JSON when asked (caller frees). Returns the exit status. */
int cli_execute(cli_run *c, json_t **result);

/* Release what cli_prepare and cli_execute took. */
void cli_run_free(cli_run *c);

/* The option set of an analysis entry of `scene` (analyses[index], of
 * type kind) with its related entry (a study's first simulate entry);
 * with command-line texts added by the caller. NULL after printing. */
ts_optset *cli_entry_options(const ts_scene *scene, int kind, int index,
                             int *status);

/* The analyses a scene lists (`towstab run`, `towstab report`). */
typedef struct cli_scene_runs {
    int n;                  /* the scene's analyses */
    cli_run *runs;          /* [n], prepared */
    char (*csv)[1200];      /* [n] DIR/<k>_<type>.csv when asked for */
    char (*dirs)[1200];     /* [n] DIR/<k>_<type> of the pictures */
    double *wall_s;         /* [n] s, each analysis with its printing and
                               pictures (cli_scene_execute); 0 when not
                               run */
    int ran;                /* analyses run (the last may have failed) */
} cli_scene_runs;

/* Read every entry of the scene's analyses list through its option table
 * and check it against the system (cli_prepare) before anything runs;
 * with csv_dir each writes csv_dir/<k>_<type>.csv, with plot_dir its
 * pictures into plot_dir/<k>_<type>/ (k from 1) in plot_units, with
 * plot_optional (cli_run) set as given. `cmd` names the command in
 * messages. Prints and returns the exit status (a
 * scene without analyses is bad input); on success release s with
 * cli_scene_free. */
int cli_scene_prepare(const char *cmd, const ts_scene *scene,
                      const ts_units *units, int quiet, const char *csv_dir,
                      const char *plot_dir, const char *plot_units,
                      int plot_optional, cli_scene_runs *s);

/* Run the prepared analyses in order, each after a line "== analysis k of
 * n: TYPE (SCENE) ==", until one fails. *all receives the JSON document
 * {"scene", "analyses": [result, ...], "completed"} (with "error" and
 * "trustworthy": false after a failure; "interrupted" after a signal),
 * NULL only when out of memory. With `into` (not NULL) each result is
 * added to that document as it comes instead, and *all receives only
 * the keys after "analyses" (ts_report_results_close's tail). all NULL:
 * no document (no tree is built). Returns the exit status. */
int cli_scene_execute(const ts_scene *scene, cli_scene_runs *s,
                      json_t **all, ts_report_results *into);

void cli_scene_free(cli_scene_runs *s);

/* The command line of `towstab run` and `report`: the options `longopts`
 * offers among --json FILE, --csv DIR, --plot DIR, --output (-o) DIR,
 * --units U, --quiet and --help (their val 'j', 'c', 'p', 'o', 'u', 'q',
 * 'h'; short options in `shortopts`, which starts with ':'), then one
 * scene file. A missing value, an unknown option (the analyses' options
 * belong in the scene) or not one scene is reported naming `cmd`, with
 * `usage` after the last. Returns -1 to go on, 0 after --help (usage on
 * standard output) or EXIT_BADINPUT. */
typedef struct cli_scene_args {
    const char *scene, *json, *csv, *plot, *output, *units;
    int quiet;
} cli_scene_args;
struct option;
int cli_scene_args_parse(const char *cmd, int argc, char **argv,
                         const char *shortopts,
                         const struct option *longopts, void (*usage)(FILE *),
                         cli_scene_args *a);

/* Make directory `dir` (one level) unless it is one; 0, or the status
 * after printing a message naming `cmd` and the option `opt`. */
int cli_make_dir(const char *cmd, const char *opt, const char *dir);

/* The option help of an analysis command (towstab CMD --help). */
void cli_usage(const struct cli_command *cmd, FILE *f);

/* The vehicles' attitudes, flow angles and depths, their control
 * deflections and (unless quiet) their components' loads, in the display
 * units d (NULL: SI, angles in deg). */
void cli_print_vehicles(FILE *f, const ts_system *sys,
                        const ts_vehicle_result *vr, int nv, int quiet,
                        const ts_display *d);

/* Markdown of every option of the analyses: the reference of
 * doc/manual.md (towstab options --markdown). */
void cli_options_markdown(FILE *f);

/* Parse a whole number option value in [lo, hi]. */
int cli_parse_int(const char *opt, const char *text, long lo, long hi,
                  long *value);

/* Report a getopt failure of command `cmd` (ch ':' for a missing value,
 * anything else an unknown option; `arg` the offending argument) and
 * return EXIT_BADINPUT. */
int cli_option_error(const char *cmd, int ch, const char *arg);

/* Standard output for JSON. When a command is given `--json -`, main()
 * moves standard output to standard error for the text report and keeps
 * the original descriptor for the JSON, so that stdout is JSON alone:
 * cli_stdout_for_json() does that once, before anything is printed. */
void cli_stdout_for_json(void);

/* Write JSON to `path` ("-": the JSON standard output), as
 * ts_report_write_json writes files. */
int cli_write_json(const json_t *value, const char *path, ts_err *err);

/* The document of several results (ts_report_results_open) for `path`
 * ("-": the JSON standard output, *stream the stream opened for it, to
 * pass to cli_results_close; else NULL). NULL with err set. */
ts_report_results *cli_results_open(const char *path,
                                           const char *scene, FILE **stream,
                                           ts_err *err);

/* Close d with the keys of tail (ts_report_results_close) and stream. */
int cli_results_close(ts_report_results *d, FILE *stream,
                      const json_t *tail, ts_err *err);

/* Write result r's JSON with the keys of `extra` (may be NULL) to `path`
 * as cli_write_json does, its node and link arrays streamed
 * (ts_report_result_write_json). */
int cli_write_result(const ts_result *r, int flags, const json_t *extra,
                     const char *path, ts_err *err);

/* Write j (taken over; NULL: it could not be made, out of memory) to
 * `path`, with "interrupted" when a signal stopped the run; prints a
 * failure. Returns `status`, or the failure's exit status when `status`
 * is 0. */
int cli_put_json(json_t *j, const char *path, int status);

/* A writer's outcome rc (err its message): prints a failure; returns
 * `status`, or the failure's exit status when `status` is 0. */
int cli_put_status(int rc, ts_err *err, int status);

/* ---- Interruption and progress (doc/manual.md, "Long runs") ----------
 * main() installs handlers for SIGINT and SIGTERM. A run that takes
 * cli_progress as its progress callback (simulations, convergence sweeps)
 * polls them: the first signal makes it stop at its next step, write what
 * it has marked incomplete, and exit with 128 + the signal (130 for
 * SIGINT, 143 for SIGTERM). A second signal, or one that comes while
 * nothing polls (reading the scene, an equilibrium, an eigensolver), ends
 * the process at once with the same status. */
void cli_signals_install(void);

/* The signal that asked to stop, 0 if none came, and its name ("SIGINT",
 * "SIGTERM"; NULL if none). */
int cli_stop_signal(void);
const char *cli_stop_signal_name(void);

/* A ts_progress_fn: nonzero once SIGINT or SIGTERM came. When standard
 * error is a terminal and the run has lasted a second, it also shows one
 * line there, rewritten at most four times a second: what is done of how
 * much, the rate and the time left. Quiet when standard error is not a
 * terminal. `data` is unused. */
int cli_progress(const ts_progress *p, void *data);

/* Clear the progress line, if one is shown; a run that polled is over. */
void cli_progress_done(void);

/* Refuse, before anything runs, an empty output name and outputs that
 * name the same file
 * (ts_report_check_targets): the n options what[i] with paths[i] (NULL
 * when not given), and the pictures `plot_names` (NULL-terminated, each
 * written as NAME.png and NAME.svg) that --plot writes into plot_dir (may
 * be NULL). Prints and returns EXIT_BADINPUT, or 0. */
int cli_check_outputs(const char *cmd, int n, const char *const what[],
                      const char *const paths[], const char *plot_dir,
                      const char *const plot_names[]);

/* The verdict lines: "trustworthy: yes|NO", reasons, notes. */
void cli_print_trust(const ts_trust *t);
/* The same with the line "WHAT trustworthy: ..." (what NULL: as above). */
void cli_print_trust_as(const ts_trust *t, const char *what);

/* "speed V m/s (K knots), turn rate W rad/s (D deg/s, turn radius R m, to
 * starboard)" or "... turn rate 0 rad/s (straight)" in SI; in the display
 * units d otherwise ("speed 5 knot, turn rate 2 deg/s (turn radius 480
 * ft, to port)"). With a towing vehicle, the steady motion eq solved
 * ("towing vehicle, solved speed 3.19825 m/s (6.217 knots; scene 3
 * m/s) ..."), or the scene's when eq is NULL or did not converge ("towing
 * vehicle, scene speed ..."). */
void cli_tow_text(const ts_system *sys, const ts_equilibrium *eq,
                  const ts_display *d, char *buf, size_t size);
/* The longest unit text of a value (after its number). */
#define CLI_UNIT_TEXT_MAX 64

/* The unit shared by the values of a range or list (text[n], each a
 * number with or without a unit, "2", "4 knot"): when some are written
 * without a unit and the others all in one, that unit ("knot"); else ""
 * (none written, or every value has its own). Values in different units
 * beside bare ones are ambiguous: a message "towstab: error: CMD: WHERE:
 * ..." and EXIT_BADINPUT; else 0. */
int cli_shared_unit(const char *cmd, const char *where,
                    const char *const text[], int n, char *unit,
                    size_t size);
/* The values text[n] of a range or list into out[n], SI, in the key's
 * unit si_unit ("" or "1": plain numbers only): a value without a unit
 * takes the one the others are written in (cli_shared_unit: "2:4 knot"
 * is 2 to 4 knots), or is SI when none has one. 0, or EXIT_BADINPUT with
 * a message naming `where`. */
int cli_parse_values(const ts_units *units, const char *cmd,
                     const char *where, const char *const text[], int n,
                     const char *si_unit, double *out);
/* 1 when sys has a towing vehicle whose steady motion eq solved. */
int cli_motion_solved(const ts_system *sys, const ts_equilibrium *eq);
/* The steady motion of the mean frame: the scene's speed and turn rate
 * (m/s, rad/s), or, when cli_motion_solved, those eq solved (a turn rate
 * that is rounding of a straight tow, below 1e-12 of V / L, as 0). */
void cli_steady_motion(const ts_system *sys, const ts_equilibrium *eq,
                       double *speed, double *turn_rate);

/* A key value as shown in the display units d, and "+- D
 * (discretisation) +- S (solver) UNIT" of it, "-" where not estimated. */
double cli_value_shown(const ts_value *v, const ts_display *d);
void cli_value_error(const ts_value *v, const ts_display *d, char *buf,
                     size_t size);

/* The discretisation-error line of a result: the levels compared, the
 * order, the cost, the largest relative error against the accuracy (or
 * why it was not estimated), and a --refine's reruns. */
void cli_print_accuracy(const ts_result *r);

/* At the end of main: flush and close standard output and standard error,
 * checking both; a failed write turns status 0 into EXIT_FAILED (with a
 * message naming standard output). Returns the status. */
int cli_finish(int status);

/* All subcommands, NULL-terminated (tools/towstab.c). */
extern const cli_command *const cli_commands[];
/* The command of analysis `kind`. */
const cli_command *cli_command_of(int kind);

/* Printing shared by the commands (cmd_equilibrium.c, cmd_modes.c). */
void cli_print_equilibrium(const ts_result *r, int quiet,
                           const ts_display *d);
void cli_print_linearization(const ts_result *r);
/* The sea state and its statistics in the display units d (NULL: SI)
 * (cmd_response.c; simulate too). */
void cli_print_seastate(const ts_result *r, int quiet, const ts_display *d);
#endif
