/* cli.c: helpers shared by the towstab subcommands (cli.h): exit codes
 * and messages, the scene, JSON on standard output, output targets and
 * the closing check of the standard streams. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "towstab/report.h"
#include "towstab/report_result.h"

/* The descriptor JSON for "-" goes to, once standard output has been moved
 * to standard error (cli_stdout_for_json); -1 otherwise. The command line
 * is one process and one command: this is the tool's state, not the
 * library's. */
static int json_fd = -1;

void cli_stdout_for_json(void)
{
    if (json_fd >= 0)
        return;
    fflush(stdout);
    json_fd = dup(STDOUT_FILENO);
    if (json_fd >= 0)
        dup2(STDERR_FILENO, STDOUT_FILENO);
}

/* A stream onto the JSON's standard output, a duplicate of its
 * descriptor (closing the stream leaves that open); NULL with err set. */
static FILE *json_stdout(ts_err *err)
{
    int fd = dup(json_fd);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        if (fd >= 0)
            close(fd);
        ts_fail(err, TS_EIO, "standard output: cannot write JSON");
    }
    return f;
}

int cli_write_json(const json_t *value, const char *path, ts_err *err)
{
    if (strcmp(path, "-") != 0 || json_fd < 0)
        return ts_report_write_json(value, path, err);
    FILE *f = json_stdout(err);
    if (!f)
        return TS_EIO;
    int bad = json_dumpf(value, f, JSON_INDENT(2) | JSON_REAL_PRECISION(17)) ||
              fputc('\n', f) == EOF;
    bad |= fclose(f) != 0;
    return bad ? ts_fail(err, TS_EIO, "standard output: cannot write JSON")
               : TS_OK;
}

ts_report_results *cli_results_open(const char *path, const char *scene,
                                    FILE **stream, ts_err *err)
{
    *stream = NULL;
    if (strcmp(path, "-") == 0 && json_fd >= 0) {
        *stream = json_stdout(err);
        if (!*stream)
            return NULL;
        path = "standard output";
    }
    ts_report_results *d = ts_report_results_open(path, *stream, scene, err);
    if (!d && *stream) {
        fclose(*stream);
        *stream = NULL;
    }
    return d;
}

int cli_results_close(ts_report_results *d, FILE *stream, const json_t *tail,
                      ts_err *err)
{
    int rc = ts_report_results_close(d, tail, err);
    if (stream && fclose(stream) != 0 && rc == TS_OK)
        rc = ts_fail(err, TS_EIO, "standard output: cannot write JSON");
    return rc;
}

int cli_write_result(const ts_result *r, int flags, const json_t *extra,
                     const char *path, ts_err *err)
{
    if (strcmp(path, "-") != 0 || json_fd < 0)
        return ts_report_result_write_json(r, flags, extra, path, err);
    FILE *f = json_stdout(err);
    if (!f)
        return TS_EIO;
    int rc = ts_report_result_dumpf(r, flags, extra, f, "standard output",
                                    err);
    if (fclose(f) != 0 && rc == TS_OK)
        rc = ts_fail(err, TS_EIO, "standard output: cannot write JSON");
    return rc;
}

int cli_put_json(json_t *j, const char *path, int status)
{
    ts_err err = {0};
    if (j && cli_stop_signal_name())
        json_object_set_new(j, "interrupted",
                            json_string(cli_stop_signal_name()));
    int rc = j ? cli_write_json(j, path, &err)
               : ts_fail(&err, TS_ENOMEM, "%s: out of memory for the JSON",
                         path);
    json_decref(j);
    return cli_put_status(rc, &err, status);
}

int cli_put_status(int rc, ts_err *err, int status)
{
    if (rc == TS_OK)
        return status;
    int e = cli_report(err, rc);
    return status ? status : e;
}

int cli_check_outputs(const char *cmd, int n, const char *const what[],
                      const char *const paths[], const char *plot_dir,
                      const char *const plot_names[])
{
    for (int i = 0; i < n; i++)
        if (paths[i] && !paths[i][0]) {
            fprintf(stderr, "towstab: error: %s: %s: expected a file name, "
                            "got an empty one\n", cmd, what[i]);
            return EXIT_BADINPUT;
        }
    if (plot_dir && !plot_dir[0]) {
        fprintf(stderr, "towstab: error: %s: --plot: expected a directory, "
                        "got an empty name\n", cmd);
        return EXIT_BADINPUT;
    }
    enum { MAX_OUT = 32 };
    const char *w[MAX_OUT], *p[MAX_OUT];
    char files[MAX_OUT][1200];
    int m = 0;
    for (int i = 0; i < n && m < MAX_OUT; i++, m++) {
        w[m] = what[i];
        p[m] = paths[i];
    }
    static const char *const ext[2] = {"png", "svg"};
    for (int i = 0; plot_dir && plot_names && plot_names[i]; i++)
        for (int k = 0; k < 2 && m < MAX_OUT; k++, m++) {
            snprintf(files[m], sizeof files[m], "%s/%s.%s", plot_dir,
                     plot_names[i], ext[k]);
            w[m] = "--plot";
            p[m] = files[m];
        }
    ts_err err = {0};
    if (ts_report_check_targets(m, w, p, &err) != TS_OK) {
        fprintf(stderr, "towstab: error: %s: %s\n", cmd, err.msg);
        return EXIT_BADINPUT;
    }
    return 0;
}

double cli_wall_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ---- interruption and progress ---------------------------------------- */

/* The tool's state (one process, one command), not the library's: the
 * signal that asked to stop, whether a running analysis polls it, and the
 * progress line. */
static volatile sig_atomic_t stop_signal, polled;
static int progress_tty;
/* A progress line appears once a run has lasted PROGRESS_DELAY s and is
 * rewritten at most every PROGRESS_INTERVAL s. */
#define PROGRESS_DELAY 1.0
#define PROGRESS_INTERVAL 0.25
static struct {
    const char *what;      /* the run being shown */
    double start, last;    /* wall time of its start and of the last line */
    double done0;          /* its progress at the start */
    int shown;             /* characters of the line on the terminal */
} line;

/* After a first signal, the run must reach a poll within this many
 * seconds (a stage that cannot poll: LAPACK's dense eigensolve, a large
 * allocation); else towstab stops at once, writing nothing. */
#define STOP_GRACE_S 5
#define STR_(x) #x
#define STR(x) STR_(x)

static void on_alarm(int sig)
{
    (void)sig;
    static const char late[] = "towstab: error: interrupted in a stage "
                               "that cannot stop on request (no stop point "
                               "within " STR(STOP_GRACE_S) " s): stopped "
                               "at once, writing nothing\n";
    if (write(STDERR_FILENO, late, sizeof late - 1) < 0)
        _exit(128 + (stop_signal ? stop_signal : SIGINT));
    _exit(128 + (stop_signal ? stop_signal : SIGINT));
}

static void on_signal(int sig)
{
    /* A second signal, or nothing that polls the first (a dense
     * eigensolve, reading the scene): stop now, saying so (write() is
     * async-signal-safe; stdio is not). */
    if (stop_signal || !polled) {
        static const char again[] = "towstab: error: interrupted again: "
                                    "stopped at once, writing nothing\n";
        static const char now[] = "towstab: error: interrupted in a stage "
                                  "that cannot stop on request: stopped at "
                                  "once, writing nothing\n";
        const char *m = stop_signal ? again : now;
        size_t n = stop_signal ? sizeof again - 1 : sizeof now - 1;
        if (write(STDERR_FILENO, m, n) < 0)
            _exit(128 + sig);
        _exit(128 + sig);
    }
    stop_signal = sig;
    alarm(STOP_GRACE_S);
}

void cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sa.sa_handler = on_alarm;
    sigaction(SIGALRM, &sa, NULL);
    progress_tty = isatty(STDERR_FILENO);
}

int cli_stop_signal(void) { return stop_signal; }

const char *cli_stop_signal_name(void)
{
    return stop_signal == SIGINT    ? "SIGINT"
           : stop_signal == SIGTERM ? "SIGTERM"
                                    : NULL;
}

int cli_finish(int status)
{
    /* A signal between the run's last stop point and its end: the run
     * completed and its outputs are whole; say so. */
    alarm(0);
    if (stop_signal && status == 0)
        fprintf(stderr, "towstab: note: %s arrived after the run's last "
                        "stop point: the run completed and its outputs "
                        "are complete\n",
                cli_stop_signal_name() ? cli_stop_signal_name() : "a signal");
    int e = 0, bad = ferror(stdout);
    if (fflush(stdout) != 0)
        e = errno;
    if (fclose(stdout) != 0 && !e)
        e = errno;
    if (bad || e) {
        fprintf(stderr, "towstab: error: standard output: write failed%s%s%s"
                        "\n",
                e ? " (" : "", e ? strerror(e) : "", e ? ")" : "");
        if (status == 0)
            status = EXIT_FAILED;
    }
    if ((fflush(stderr) != 0 || ferror(stderr)) && status == 0)
        status = EXIT_FAILED;
    return status;
}

/* A duration for the progress line: "42 s", "3.5 min", "2.1 h". */
static void duration_text(double s, char *buf, size_t size)
{
    if (!isfinite(s))
        snprintf(buf, size, "unknown");
    else if (s < 120)
        snprintf(buf, size, "%.0f s", s);
    else if (s < 7200)
        snprintf(buf, size, "%.1f min", s / 60);
    else
        snprintf(buf, size, "%.1f h", s / 3600);
}

int cli_progress(const ts_progress *p, void *data)
{
    (void)data;
    polled = 1;
    if (stop_signal) {
        /* A stop point: the run stops here and writes what it has. */
        alarm(0);
        return 1;
    }
    if (!progress_tty)
        return 0;
    double now = cli_wall_now();
    if (line.what != p->what || p->done < line.done0) {
        line.what = p->what;
        line.start = line.last = now;
        line.done0 = p->done;
        return 0;
    }
    double elapsed = now - line.start;
    if (elapsed < PROGRESS_DELAY || now - line.last < PROGRESS_INTERVAL)
        return 0;
    line.last = now;
    double rate = (p->done - line.done0) / elapsed;
    char left[32], text[200];
    int n;
    if (isnan(p->total)) {
        /* An iterative solver's work, of no known end: what is done and
         * the rate only. */
        n = snprintf(text, sizeof text, "towstab: %s: %.6g %s, %.3g per s, "
                     "%.0f s so far", p->what, p->done, p->unit, rate,
                     elapsed);
    } else {
        duration_text(rate > 0 ? (p->total - p->done) / rate : INFINITY,
                      left, sizeof left);
        n = snprintf(text, sizeof text, "towstab: %s: %.6g of %.6g %s "
                     "(%.0f%%), %.3g %s%s per s, %s left", p->what, p->done,
                     p->total, p->unit, 100 * p->done / p->total, rate,
                     strcmp(p->unit, "s") ? "" : "simulated ", p->unit,
                     left);
    }
    if (n >= (int)sizeof text)
        n = (int)sizeof text - 1;
    fprintf(stderr, "\r%s%*s", text, line.shown > n ? line.shown - n : 0,
            "");
    fflush(stderr);
    line.shown = n;
    return 0;
}

void cli_progress_done(void)
{
    /* The run is over: what follows (writing the outputs) is not cut
     * short. */
    alarm(0);
    if (line.shown > 0) {
        fprintf(stderr, "\r%*s\r", line.shown, "");
        fflush(stderr);
    }
    line.shown = 0;
    line.what = NULL;
    polled = 0;
}

const char *cli_analysis_arg(int argc, char **argv)
{
    const char *name = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--analysis") && i + 1 < argc)
            name = argv[i + 1];
        else if (!strncmp(argv[i], "--analysis=", 11))
            name = argv[i] + 11;
    }
    return name;
}

int cli_exit_code(int rc)
{
    switch (rc) {
    case TS_OK: return 0;
    case TS_ECANCEL: return 128 + (stop_signal ? stop_signal : SIGINT);
    case TS_EINVAL:
    case TS_ESCENE:
    case TS_EUNIT:
    case TS_EDOMAIN: return EXIT_BADINPUT;
    default: return EXIT_FAILED;
    }
}

/* The scene file the command read (cli_open), for messages: its path, or
 * "standard input". The tool's state, like json_fd. */
static char scene_label[512];

/* Whether a message about the scene's analysis should be prefixed with
 * the scene file: an analysis that failed (its message names the part,
 * not the file), or an option of an `analyses` entry; not a message about
 * a command-line option or one that names the file already. */
static int needs_scene(const char *msg, int rc)
{
    if (!scene_label[0] || !strncmp(msg, "--", 2) || strstr(msg, scene_label))
        return 0;
    if (!strncmp(msg, "analyses[", 9))
        return 1;
    switch (rc) {
    case TS_ECONV:
    case TS_ESINGULAR:
    case TS_ELAPACK:
    case TS_EINTEGRATOR:
    case TS_ENOMEM:
    case TS_EDOMAIN: return 1;
    default: return 0;
    }
}

int cli_report(ts_err *err, int rc)
{
    cli_progress_done();
    /* The prefix goes into the record, so that a JSON written after this
     * gives the same reason as standard error. */
    if (err && err->msg[0] && needs_scene(err->msg, rc))
        ts_err_prefix(err, "%s: ", scene_label);
    const char *msg = err && err->msg[0] ? err->msg : ts_strerror(rc);
    if (rc == TS_ECANCEL)
        fprintf(stderr, "towstab: error: interrupted (%s): ",
                cli_stop_signal_name() ? cli_stop_signal_name() : "stop");
    else
        fprintf(stderr, "towstab: error: ");
    fprintf(stderr, "%s\n", msg);
    return cli_exit_code(rc);
}

int cli_open(const char *path, ts_units **units, ts_scene **scene)
{
    ts_err err = {0};
    *scene = NULL;
    *units = ts_units_alloc(&err);
    if (!*units)
        return cli_report(&err, err.code ? err.code : TS_EUNIT);
    *scene = ts_scene_load(path, *units, &err);
    if (*scene)
        snprintf(scene_label, sizeof scene_label, "%s",
                 strcmp(path, "-") ? path : "standard input");
    if (!*scene) {
        int rc = err.code ? err.code : TS_ESCENE;
        ts_units_free(*units);
        *units = NULL;
        /* A missing or unreadable scene is bad input too. */
        return cli_report(&err, rc == TS_EIO ? TS_ESCENE : rc);
    }
    return 0;
}

void cli_close(ts_units *units, ts_scene *scene)
{
    ts_scene_free(scene);
    ts_units_free(units);
}

int cli_option_error(const char *cmd, int ch, const char *arg)
{
    if (ch == ':')
        fprintf(stderr, "towstab: error: %s: missing value for '%s'\n", cmd,
                arg);
    else
        fprintf(stderr, "towstab: error: %s: unknown option '%s' (towstab %s "
                        "--help)\n",
                cmd, arg, cmd);
    return EXIT_BADINPUT;
}

int cli_parse_int(const char *opt, const char *text, long lo, long hi,
                  long *value)
{
    char *end;
    long v = strtol(text, &end, 10);
    if (end == text || *end || v < lo || v > hi) {
        fprintf(stderr, "towstab: error: %s: expected a whole number in "
                        "[%ld, %ld], got '%s'\n",
                opt, lo, hi, text);
        return EXIT_BADINPUT;
    }
    *value = v;
    return 0;
}

/* A towing vehicle's solved turn rate below this fraction of V / L (L the
 * cables' length: the turn whose radius is that length) is rounding: a
 * symmetric vehicle solves to 1e-19 rad/s, 1e-17 of V / L. */
#define TURN_ROUNDING 1e-12

void cli_steady_motion(const ts_system *sys, const ts_equilibrium *eq,
                       double *speed, double *turn_rate)
{
    *speed = sys->tow.speed;
    *turn_rate = sys->tow.turn_rate;
    if (!cli_motion_solved(sys, eq))
        return;
    *speed = eq->speed;
    *turn_rate = eq->turn_rate;
    double L = 0.0;
    for (int c = 0; c < sys->ncables; c++)
        L += sys->cables[c].length;
    if (sys->tow.turn_surface < 0 &&
        fabs(eq->turn_rate) * L <= TURN_ROUNDING * fabs(eq->speed))
        *turn_rate = 0.0;
}

int cli_motion_solved(const ts_system *sys, const ts_equilibrium *eq)
{
    return sys->tow.vehicle >= 0 && eq && eq->converged &&
           isfinite(eq->speed) && isfinite(eq->turn_rate);
}

void cli_tow_text(const ts_system *sys, const ts_equilibrium *eq,
                  const ts_display *d, char *buf, size_t size)
{
    d = ts_display_or_si(d);
    double speed, turn_rate;
    cli_steady_motion(sys, eq, &speed, &turn_rate);
    const char *vu = ts_display_unit(d, TS_QTY_SPEED);
    const char *wu = ts_display_unit(d, TS_QTY_ANGULAR_RATE);
    char v[160], w[96];
    /* SI speeds and turn rates also in knots and deg/s. With a towing
     * vehicle the steady motion is solved: its speed and turn rate once
     * the equilibrium converged (the scene's are where the solve starts,
     * or its targets), else the scene's, said so. */
    const char *what = sys->tow.vehicle < 0 ? ""
                       : cli_motion_solved(sys, eq) ? "towing vehicle, solved "
                                                    : "towing vehicle, scene ";
    int n = snprintf(v, sizeof v, "%sspeed %.6g %s", what,
                     ts_display_value(d, TS_QTY_SPEED, speed), vu);
    int knots = !strcmp(vu, "m/s"), solved = cli_motion_solved(sys, eq);
    if (knots && n > 0 && (size_t)n < sizeof v)
        n += snprintf(v + n, sizeof v - (size_t)n, " (%.4g knots%s",
                      speed / (1852.0 / 3600.0), solved ? "; " : ")");
    else if (solved && n > 0 && (size_t)n < sizeof v)
        n += snprintf(v + n, sizeof v - (size_t)n, " (");
    if (solved && n > 0 && (size_t)n < sizeof v)
        snprintf(v + n, sizeof v - (size_t)n, "scene %.6g %s)",
                 ts_display_value(d, TS_QTY_SPEED, sys->tow.speed), vu);
    if (turn_rate == 0.0) {
        snprintf(buf, size, "%s, turn rate 0 %s (straight)", v, wu);
        return;
    }
    n = snprintf(w, sizeof w, "turn rate %.6g %s",
                 ts_display_value(d, TS_QTY_ANGULAR_RATE, turn_rate), wu);
    if (!strcmp(wu, "rad/s") && n > 0 && (size_t)n < sizeof w)
        snprintf(w + n, sizeof w - (size_t)n, " (%.4g deg/s,",
                 turn_rate * 180.0 / M_PI);
    else if (n > 0 && (size_t)n < sizeof w)
        snprintf(w + n, sizeof w - (size_t)n, " (");
    double R = speed / fabs(turn_rate);
    snprintf(buf, size, "%s, %s%sturn radius %.4g %s, to %s)", v, w,
             strcmp(wu, "rad/s") ? "" : " ",
             ts_display_value(d, TS_QTY_LENGTH, R),
             ts_display_unit(d, TS_QTY_LENGTH),
             turn_rate > 0 ? "starboard" : "port");
}

/* The longest bare value given the shared unit. */
#define CLI_VALUE_TEXT_MAX 256

/* The unit written after the number of `text` (spaces trimmed) into
 * unit: "" for a bare number; -1 when text does not start with a number
 * (ts_units_parse then names it). */
static int written_unit(const char *text, char *unit, size_t size)
{
    char *end;
    strtod(text, &end);
    if (end == text)
        return -1;
    while (*end == ' ')
        end++;
    size_t len = strlen(end);
    while (len > 0 && end[len - 1] == ' ')
        len--;
    snprintf(unit, size, "%.*s", (int)len, end);
    return 0;
}

int cli_shared_unit(const char *cmd, const char *where,
                    const char *const text[], int n, char *unit,
                    size_t size)
{
    unit[0] = '\0';
    int bare = 0, mixed = 0;
    char u[CLI_UNIT_TEXT_MAX];
    for (int i = 0; i < n; i++) {
        if (written_unit(text[i], u, sizeof u))
            continue;
        if (!u[0])
            bare = 1;
        else if (!unit[0])
            snprintf(unit, size, "%s", u);
        else if (strcmp(unit, u))
            mixed = 1;
    }
    if (bare && mixed) {
        fprintf(stderr, "towstab: error: %s: %s: values in different units "
                        "('%s' and others) and values without one: give "
                        "each value its unit\n", cmd, where, unit);
        return EXIT_BADINPUT;
    }
    if (mixed || !bare)
        unit[0] = '\0';
    return 0;
}

int cli_parse_values(const ts_units *units, const char *cmd,
                     const char *where, const char *const text[], int n,
                     const char *si_unit, double *out)
{
    ts_err err = {0};
    int plain = !si_unit[0] || !strcmp(si_unit, "1");
    char shared[CLI_UNIT_TEXT_MAX];
    if (!plain &&
        cli_shared_unit(cmd, where, text, n, shared, sizeof shared))
        return EXIT_BADINPUT;
    for (int i = 0; i < n; i++) {
        int rc;
        char u[CLI_UNIT_TEXT_MAX], with[CLI_VALUE_TEXT_MAX + CLI_UNIT_TEXT_MAX];
        if (plain) {
            char *end;
            out[i] = strtod(text[i], &end);
            while (*end == ' ')
                end++;
            rc = end == text[i] || *end || !isfinite(out[i]) ? TS_EINVAL
                                                             : TS_OK;
            if (rc)
                ts_fail(&err, rc, "%s: expected a plain number, got '%s'",
                        where, text[i]);
        } else {
            /* A bare value takes the unit the others are written in. */
            const char *t = text[i];
            if (shared[0] && !written_unit(t, u, sizeof u) && !u[0] &&
                strlen(t) < CLI_VALUE_TEXT_MAX - 1) {
                snprintf(with, sizeof with, "%.*s %.*s",
                         CLI_VALUE_TEXT_MAX - 2, t, CLI_UNIT_TEXT_MAX - 1,
                         shared);
                t = with;
            }
            rc = ts_units_parse(units, t, si_unit, where, &out[i], &err);
        }
        if (rc) {
            fprintf(stderr, "towstab: error: %s: %s\n", cmd, err.msg);
            return EXIT_BADINPUT;
        }
    }
    return 0;
}

/* An error for a table: "%.2g", or "-" when not known. */
static void err_text(double e, char *buf, size_t size)
{
    if (isfinite(e))
        snprintf(buf, size, "%.2g", e);
    else
        snprintf(buf, size, "-");
}

double cli_value_shown(const ts_value *v, const ts_display *d)
{
    char u[64];
    return ts_display_convert(ts_display_or_si(d), v->unit, v->value, u,
                              sizeof u);
}

void cli_value_error(const ts_value *v, const ts_display *d, char *buf,
                     size_t size)
{
    char e1[32], e2[32], u[64];
    double k = ts_display_convert(ts_display_or_si(d), v->unit, 1.0, u,
                                  sizeof u);
    err_text(k * v->error.discretisation, e1, sizeof e1);
    err_text(k * v->error.solver, e2, sizeof e2);
    snprintf(buf, size, "+- %s (discretisation) +- %s (solver) %s", e1, e2,
             u);
}

void cli_print_accuracy(const ts_result *r)
{
    const ts_result_accuracy *a = &r->accuracy;
    if (!(a->accuracy > 0))
        return;
    if (a->refinements > 0)
        printf("refined: %d rerun%s from %d to %d links per cable to meet "
               "the accuracy\n",
               a->refinements, a->refinements == 1 ? "" : "s",
               a->refined_from, a->links[0]);
    if (!a->estimated) {
        printf("discretisation error: not estimated: %s\n",
               a->not_estimated);
        return;
    }
    char lev[96] = "";
    for (int k = 0; k < a->nlevels; k++) {
        size_t n = strlen(lev);
        snprintf(lev + n, sizeof lev - n, "%s%d",
                 k == 0 ? "" : k + 1 == a->nlevels ? " and " : ", ",
                 a->links[k]);
    }
    printf("discretisation error: Richardson from %s links (order %.3g in "
           "1/links), %.3f ms, %ld evaluations",
           lev, a->order, a->wall_s * 1e3, a->evaluations);
    if (isfinite(a->max_rel_error))
        printf("; largest relative %.2g (%s) against the accuracy %.3g: "
               "%s\n",
               a->max_rel_error, a->limiting, a->accuracy,
               a->met > 0 ? "met" : "NOT MET");
    else
        printf("\n");
}

void cli_print_vehicles(FILE *f, const ts_system *sys,
                        const ts_vehicle_result *vr, int nv, int quiet,
                        const ts_display *d)
{
    if (nv == 0)
        return;
    d = ts_display_or_si(d);
    /* Angles, depths, forces and moments (force times length) in the
     * display units. */
    double ka = ts_display_value(d, TS_QTY_ANGLE, 1.0);
    double kl = ts_display_value(d, TS_QTY_LENGTH, 1.0);
    double kf = ts_display_value(d, TS_QTY_FORCE, 1.0);
    const char *au = ts_display_unit(d, TS_QTY_ANGLE);
    const char *lu = ts_display_unit(d, TS_QTY_LENGTH);
    const char *fu = ts_display_unit(d, TS_QTY_FORCE);
    char h[7][48];
    static const char *const ang[5] = {"pitch", "roll", "yaw", "alpha",
                                       "beta"};
    for (int i = 0; i < 5; i++)
        snprintf(h[i], sizeof h[i], "%s[%s]", ang[i], au);
    snprintf(h[5], sizeof h[5], "depth [%s]", lu);
    fprintf(f, "\n%-20s %10s %10s %10s %10s %10s %12s\n", "vehicle", h[0],
            h[1], h[2], h[3], h[4], h[5]);
    for (int v = 0; v < nv; v++) {
        const ts_vehicle_result *r = &vr[v];
        fprintf(f, "%-20s %10.4f %10.4f %10.4f %10.4f %10.4f %12.6f\n",
                sys->bodies[r->body].name, r->pitch * ka, r->roll * ka,
                r->yaw * ka, r->alpha * ka, r->beta * ka,
                r->origin[2] * kl);
    }
    for (int v = 0; v < nv; v++) {
        const ts_vehicle_result *r = &vr[v];
        const ts_vehicle *vd = sys->bodies[r->body].vehicle;
        for (int c = 0; c < r->ncomponents; c++)
            if (vd->component[c].type == TS_COMP_BALLAST)
                fprintf(f, "%s.%s fill %.4f kg\n", sys->bodies[r->body].name,
                        vd->component[c].name, r->delta[c]);
            else if (vd->component[c].control)
                fprintf(f, "%s.%s deflection %.4f %s\n",
                        sys->bodies[r->body].name, vd->component[c].name,
                        r->delta[c] * ka, au);
        if (quiet)
            continue;
        char hf[3][48], hm[3][64], ha[48];
        for (int i = 0; i < 3; i++) {
            snprintf(hf[i], sizeof hf[i], "F%c [%s]", "xyz"[i], fu);
            snprintf(hm[i], sizeof hm[i], "M%c [%s %s]", "xyz"[i], fu, lu);
        }
        snprintf(ha, sizeof ha, "alpha[%s]", au);
        fprintf(f, "\n%-20s %11s %11s %11s %11s %11s %11s %9s\n",
                "component (body axes)", hf[0], hf[1], hf[2], hm[0], hm[1],
                hm[2], ha);
        for (int c = 0; c < r->ncomponents; c++) {
            const ts_component_load *ld = &r->load[c];
            char nm[2 * TS_NAME_MAX];
            snprintf(nm, sizeof nm, "%s.%s", sys->bodies[r->body].name,
                     vd->component[c].name);
            fprintf(f, "%-20s %11.4f %11.4f %11.4f %11.4f %11.4f %11.4f "
                       "%9.3f\n",
                    nm, kf * ld->force[0], kf * ld->force[1],
                    kf * ld->force[2], kf * kl * ld->moment[0],
                    kf * kl * ld->moment[1], kf * kl * ld->moment[2],
                    ld->alpha * ka);
        }
        fprintf(f, "%-20s %11s %11s %11s %11.4f %11.4f %11.4f\n",
                "Munk moment", "", "", "", kf * kl * r->munk[0],
                kf * kl * r->munk[1], kf * kl * r->munk[2]);
        for (int c = 0; c < r->ncomponents; c++)
            if (vd->component[c].type == TS_COMP_MAST)
                fprintf(f, "%s.%s submerged length %.4f %s (its force: "
                           "buoyancy%s)\n",
                        sys->bodies[r->body].name, vd->component[c].name,
                        r->load[c].submerged * kl, lu,
                        vd->component[c].drag > 0 ? " and drag" : "");
        fprintf(f, "%s (M) %.4f, %.4f, %.4f %s\n",
                r->towing ? "cable pull at the tow point" : "joint force",
                kf * r->joint_force[0], kf * r->joint_force[1],
                kf * r->joint_force[2], fu);
    }
    for (int v = 0; v < nv; v++) {
        const ts_vehicle_result *r = &vr[v];
        if (r->towing)
            fprintf(f, "%s: towing at %.6g m/s (%.4g knots), turn rate %.6g "
                       "rad/s, thrust %.6g N, power %.6g W, cable pull %.6g "
                       "N\n",
                    sys->bodies[r->body].name, r->track_speed,
                    r->track_speed / (1852.0 / 3600.0), r->turn_rate,
                    r->thrust, r->power,
                    sqrt(r->joint_force[0] * r->joint_force[0] +
                         r->joint_force[1] * r->joint_force[1] +
                         r->joint_force[2] * r->joint_force[2]));
        if (r->towing && r->dof == 3)
            fprintf(f, "%s: surface ship (3 dof), the hull's hydrostatic "
                       "reaction at the tow point: vertical force %.6g N "
                       "(down > 0), roll moment %.6g N m, pitch moment "
                       "%.6g N m (body axes)\n",
                    sys->bodies[r->body].name, r->held[0], r->held[1],
                    r->held[2]);
    }
}

void cli_print_trust(const ts_trust *t)
{
    cli_print_trust_as(t, NULL);
}

void cli_print_trust_as(const ts_trust *t, const char *what)
{
    if (what)
        printf("%s trustworthy: %s\n", what, t->trustworthy ? "yes" : "NO");
    else
        printf("trustworthy: %s\n", t->trustworthy ? "yes" : "NO");
    for (int i = 0; i < t->nreasons; i++)
        printf("  reason: %s\n", t->reasons[i]);
    for (int i = 0; i < t->nnotes; i++)
        printf("  note: %s\n", t->notes[i]);
}

const cli_command *cli_command_of(int kind)
{
    for (int i = 0; cli_commands[i]; i++)
        if (cli_commands[i]->kind == kind)
            return cli_commands[i];
    return NULL;
}
