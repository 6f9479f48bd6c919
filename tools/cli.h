/* cli.h: what the towstab subcommands share (tools only; the library never
 * prints). Each subcommand lives in tools/cmd_<name>.c and exports one
 * cli_command; tools/towstab.c lists them. */
#ifndef TOWSTAB_CLI_H
#define TOWSTAB_CLI_H

#include <jansson.h>
#include <stdio.h>

#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/progress.h"
#include "towstab/scene.h"
#include "towstab/system.h"
#include "towstab/units.h"

#define EXIT_FAILED 1   /* the analysis failed: no convergence, I/O */
#define EXIT_BADINPUT 2 /* usage, scene, units, impossible configuration */

/* What a scene analysis entry runs with. */
typedef struct cli_ctx {
    const ts_scene *scene;
    const ts_units *units;
    int quiet;
} cli_ctx;

typedef struct cli_command {
    const char *name;
    const char *summary;
    /* `towstab NAME ...`: argv[0] is NAME. Returns the exit status. */
    int (*main)(int argc, char **argv);
    /* One `analyses:` entry of type NAME. With result == NULL it only
     * checks the entry's option values (units, ranges, names), so that
     * `run` refuses a bad entry before the first runs; otherwise it runs
     * the entry and sets *result to its JSON (NULL when there is none).
     * Prints its messages; returns the exit status. NULL when the command
     * is not an analysis. */
    int (*entry)(const cli_ctx *ctx, const ts_scene_analysis *a, int index,
                 json_t **result);
    /* Option keys the scene entry accepts (NULL-terminated). */
    const char *const *keys;
} cli_command;

double cli_wall_now(void);

/* Exit status for a library code. */
int cli_exit_code(int rc);

/* Print "towstab: error: <message>" and return the exit status. A message
 * about the scene's analysis (a failed analysis, an option of an
 * `analyses` entry) gets the scene file in front, in err too, so that a
 * JSON written afterwards gives the same reason. */
int cli_report(ts_err *err, int rc);

/* Load units and a scene; on failure prints and returns NULL with *status
 * set. Free with cli_close(). */
int cli_open(const char *path, ts_units **units, ts_scene **scene);
void cli_close(ts_units *units, ts_scene *scene);

/* Settings that override a scene's tow or solver, as text with units.
 * `where` names the origin of each for messages. */
typedef struct cli_settings {
    const char *speed, *turn_rate, *method, *tol;
    int links;                  /* 0: keep the scene's */
    char where[5][128];         /* speed, turn_rate, method, tol, links */
} cli_settings;

/* Settings named as command-line options (--speed, ...). */
void cli_settings_from_options(cli_settings *s);

/* Settings from a scene analysis entry (keys speed, turn_rate, method,
 * tolerance, links). */
int cli_settings_from_analysis(cli_settings *s, const ts_scene_analysis *a,
                               int index, ts_err *err);

/* A copy of the scene's system with the settings applied and rebuilt, and
 * the solver options. NULL on failure (message in err). */
ts_system *cli_system(const ts_scene *scene, const ts_units *units,
                      const cli_settings *s, ts_equilibrium_opts *eo,
                      ts_err *err);

/* Refuse analysis options outside `keys`. */
int cli_check_keys(const ts_scene_analysis *a, const char *const keys[],
                   int index, ts_err *err);

/* Text of option `key` of a scene analysis, or NULL. */
const char *cli_option(const ts_scene_analysis *a, const char *key);

/* Solve and print an equilibrium (summary always, tables unless quiet).
 * *out receives the result (caller frees, may be partial on failure);
 * *json, when not NULL, its JSON. Returns the library code. */
int cli_equilibrium(const ts_system *sys, const ts_equilibrium_opts *eo,
                    int quiet, ts_equilibrium **out, json_t **json,
                    ts_err *err);

/* The getopt entries of the shared settings: --speed, --turn-rate,
 * --links, the equilibrium method's option (named `method`) and --tol,
 * with the codes cli_settings_option() takes. */
#define CLI_SETTINGS_LONGOPTS(method)                                        \
    {"speed", required_argument, NULL, 's'},                                 \
        {"turn-rate", required_argument, NULL, 'w'},                         \
        {"links", required_argument, NULL, 'n'},                             \
        {method, required_argument, NULL, 'm'},                              \
        {"tol", required_argument, NULL, 't'}

/* Take a shared setting (getopt code ch, value arg) into s: 1 when ch was
 * one, 0 when not, -1 (message printed) when its value is bad. */
int cli_settings_option(cli_settings *s, int ch, const char *arg);

/* Report a getopt failure of command `cmd` (ch ':' for a missing value,
 * anything else an unknown option; `arg` the offending argument) and
 * return EXIT_BADINPUT. */
int cli_option_error(const char *cmd, int ch, const char *arg);

/* Parse a whole number option value in [lo, hi]. */
int cli_parse_int(const char *opt, const char *text, long lo, long hi,
                  long *value);



/* Standard output for JSON. When a command is given `--json -`, main()
 * moves standard output to standard error for the text report and keeps
 * the original descriptor for the JSON, so that stdout is JSON alone:
 * cli_stdout_for_json() does that once, before anything is printed. */
void cli_stdout_for_json(void);

/* Write JSON to `path` ("-": the JSON standard output), as
 * ts_report_write_json writes files. */
int cli_write_json(const json_t *value, const char *path, ts_err *err);

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

/* Mark a result: "completed": true, or for a failed run (status != 0)
 * "completed": false, "error": msg (the text standard error got) and the
 * verdict "trustworthy": false with msg as its reason. */
void cli_json_mark(json_t *j, int status, const char *msg);

/* The JSON of a run that failed before it had a result: {"completed":
 * false, "error", "trustworthy": false, "reasons": [msg], "notes": []}. */
json_t *cli_json_failed(const char *msg);

/* Write the result j of a run that ended with `status` and message `msg`
 * to `path` (may be NULL): a failed analysis (status 1) writes what it has
 * (j, may be NULL: then nothing) marked as incomplete (cli_json_mark);
 * bad input (status 2) writes nothing. Returns the new status (1 when the
 * write failed, after printing). */
int cli_write_result(json_t *j, const char *path, int status,
                     const char *msg);

/* Refuse, before anything runs, outputs that name the same file
 * (ts_report_check_targets): the n options what[i] with paths[i] (NULL
 * when not given), and the pictures `plot_names` (NULL-terminated, each
 * written as NAME.png and NAME.svg) that --plot writes into plot_dir (may
 * be NULL). Prints and returns EXIT_BADINPUT, or 0. */
int cli_check_outputs(const char *cmd, int n, const char *const what[],
                      const char *const paths[], const char *plot_dir,
                      const char *const plot_names[]);

/* At the end of main: flush and close standard output and standard error,
 * checking both; a failed write turns status 0 into EXIT_FAILED (with a
 * message naming standard output). Returns the status. */
int cli_finish(int status);

/* All subcommands, NULL-terminated (tools/towstab.c). */
extern const cli_command *const cli_commands[];
#endif
