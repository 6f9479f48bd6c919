/* cli.c: helpers shared by the towstab subcommands (cli.h). */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "towstab/health.h"
#include "towstab/kernel.h"
#include "towstab/report.h"

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

int cli_write_json(const json_t *value, const char *path, ts_err *err)
{
    if (strcmp(path, "-") != 0 || json_fd < 0)
        return ts_report_write_json(value, path, err);
    int fd = dup(json_fd);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        if (fd >= 0)
            close(fd);
        return ts_fail(err, TS_EIO, "standard output: cannot write JSON");
    }
    int bad = json_dumpf(value, f, JSON_INDENT(2) | JSON_REAL_PRECISION(17)) ||
              fputc('\n', f) == EOF;
    bad |= fclose(f) != 0;
    return bad ? ts_fail(err, TS_EIO, "standard output: cannot write JSON")
               : TS_OK;
}

void cli_json_mark(json_t *j, int status, const char *msg)
{
    if (!j)
        return;
    json_object_set_new(j, "completed", json_boolean(status == 0));
    if (status == 0)
        return;
    json_object_set_new(j, "error", json_string(msg && msg[0] ? msg
                                                             : "failed"));
    json_object_set_new(j, "trustworthy", json_false());
    json_object_set_new(j, "reasons",
                        json_pack("[s]", msg && msg[0] ? msg : "failed"));
    if (!json_object_get(j, "notes"))
        json_object_set_new(j, "notes", json_array());
}

json_t *cli_json_failed(const char *msg)
{
    json_t *j = json_object();
    cli_json_mark(j, EXIT_FAILED, msg);
    return j;
}

int cli_write_result(json_t *j, const char *path, int status,
                     const char *msg)
{
    if (!path || status == EXIT_BADINPUT || (status && !j))
        return status;
    ts_err werr = {0};
    if (!j)
        ts_fail(&werr, TS_ENOMEM, "%s: out of memory", path);
    cli_json_mark(j, status, msg);
    if (!j || cli_write_json(j, path, &werr) != TS_OK) {
        int st = cli_report(&werr, werr.code);
        status = status ? status : st;
    }
    return status;
}

int cli_check_outputs(const char *cmd, int n, const char *const what[],
                      const char *const paths[], const char *plot_dir,
                      const char *const plot_names[])
{
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

int cli_finish(int status)
{
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

static void on_signal(int sig)
{
    /* A second signal, or nothing that polls the first: stop now. */
    if (stop_signal || !polled)
        _exit(128 + sig);
    stop_signal = sig;
}

void cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    progress_tty = isatty(STDERR_FILENO);
}

int cli_stop_signal(void) { return stop_signal; }

const char *cli_stop_signal_name(void)
{
    return stop_signal == SIGINT    ? "SIGINT"
           : stop_signal == SIGTERM ? "SIGTERM"
                                    : NULL;
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
    if (stop_signal)
        return 1;
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
    char left[32], text[160];
    duration_text(rate > 0 ? (p->total - p->done) / rate : INFINITY, left,
                  sizeof left);
    int n = snprintf(text, sizeof text, "towstab: %s: %.6g of %.6g %s "
                     "(%.0f%%), %.3g %s%s per s, %s left", p->what, p->done,
                     p->total, p->unit, 100 * p->done / p->total, rate,
                     strcmp(p->unit, "s") ? "" : "simulated ", p->unit,
                     left);
    fprintf(stderr, "\r%s%*s", text, line.shown > n ? line.shown - n : 0,
            "");
    fflush(stderr);
    line.shown = n;
    return 0;
}

void cli_progress_done(void)
{
    if (line.shown > 0) {
        fprintf(stderr, "\r%*s\r", line.shown, "");
        fflush(stderr);
    }
    line.shown = 0;
    line.what = NULL;
    polled = 0;
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

void cli_settings_from_options(cli_settings *s)
{
    snprintf(s->where[0], sizeof s->where[0], "--speed");
    snprintf(s->where[1], sizeof s->where[1], "--turn-rate");
    snprintf(s->where[2], sizeof s->where[2], "--method");
    snprintf(s->where[3], sizeof s->where[3], "--tol");
    snprintf(s->where[4], sizeof s->where[4], "--links");
}

int cli_settings_from_analysis(cli_settings *s, const ts_scene_analysis *a,
                               int index, ts_err *err)
{
    static const char *const keys[5] = {"speed", "turn_rate", "method",
                                        "tolerance", "links"};
    const char **dst[4] = {&s->speed, &s->turn_rate, &s->method, &s->tol};
    for (int j = 0; j < 5; j++) {
        const ts_scene_option *o = ts_scene_analysis_option(a, keys[j]);
        snprintf(s->where[j], sizeof s->where[j], "analyses[%d].%s (line %d)",
                 index, keys[j], o ? o->line : a->line);
        if (j < 4)
            *dst[j] = o ? o->value : NULL;
        else if (o) {
            char *end;
            long v = strtol(o->value, &end, 10);
            if (end == o->value || *end || v < 1 || v > 10000000)
                return ts_fail(err, TS_EINVAL,
                               "%s: expected a whole number >= 1, got '%s'",
                               s->where[4], o->value);
            s->links = (int)v;
        }
    }
    return TS_OK;
}

ts_system *cli_system(const ts_scene *scene, const ts_units *units,
                      const cli_settings *s, ts_equilibrium_opts *eo,
                      ts_err *err)
{
    ts_system *sys = ts_system_copy(scene->system, err);
    if (!sys)
        return NULL;
    ts_equilibrium_opts_default(eo);
    int rc = TS_OK;
    if (s->speed)
        rc = ts_units_parse(units, s->speed, "m/s", s->where[0],
                            &sys->tow.speed, err);
    if (!rc && s->turn_rate)
        rc = ts_units_parse(units, s->turn_rate, "rad/s", s->where[1],
                            &sys->tow.turn_rate, err);
    if (!rc && s->method) {
        if (strcmp(s->method, "auto") == 0)
            eo->method = TS_EQ_AUTO;
        else if (strcmp(s->method, "shooting") == 0)
            eo->method = TS_EQ_SHOOTING;
        else if (strcmp(s->method, "newton") == 0)
            eo->method = TS_EQ_NEWTON;
        else
            rc = ts_fail(err, TS_EINVAL,
                         "%s: '%s' is not a method; expected auto, shooting "
                         "or newton",
                         s->where[2], s->method);
    }
    if (!rc && s->tol) {
        char *end;
        double v = strtod(s->tol, &end);
        if (end == s->tol || *end != '\0' || !(v > 0) || !(v < 1))
            rc = ts_fail(err, TS_EINVAL,
                         "%s: expected a number in (0, 1), got '%s'",
                         s->where[3], s->tol);
        else
            eo->tol = v;
    }
    for (int c = 0; !rc && s->links > 0 && c < sys->ncables; c++) {
        if (sys->cables[c].link_fraction)
            rc = ts_fail(err, TS_EINVAL,
                         "%s: cables[%d] '%s' has link_lengths; remove them "
                         "to set the number of links",
                         s->where[4], c, sys->cables[c].name);
        sys->cables[c].nlinks = s->links;
    }
    if (!rc)
        rc = ts_system_build(sys, err);
    if (rc) {
        ts_system_free(sys);
        return NULL;
    }
    return sys;
}

int cli_check_keys(const ts_scene_analysis *a, const char *const keys[],
                   int index, ts_err *err)
{
    for (int i = 0; i < a->noptions; i++) {
        int ok = 0;
        for (int j = 0; keys[j]; j++)
            ok |= strcmp(a->options[i].key, keys[j]) == 0;
        if (ok)
            continue;
        char list[512] = "";
        for (int j = 0; keys[j]; j++) {
            strncat(list, keys[j], sizeof list - strlen(list) - 1);
            if (keys[j + 1])
                strncat(list, ", ", sizeof list - strlen(list) - 1);
        }
        return ts_fail(err, TS_ESCENE,
                       "analyses[%d].%s (line %d): unknown option for %s; "
                       "expected one of %s",
                       index, a->options[i].key, a->options[i].line, a->type,
                       list);
    }
    return TS_OK;
}

const char *cli_option(const ts_scene_analysis *a, const char *key)
{
    const ts_scene_option *o = ts_scene_analysis_option(a, key);
    return o ? o->value : NULL;
}

int cli_settings_option(cli_settings *s, int ch, const char *arg)
{
    long v;
    switch (ch) {
    case 's': s->speed = arg; return 1;
    case 'w': s->turn_rate = arg; return 1;
    case 'm': s->method = arg; return 1;
    case 't': s->tol = arg; return 1;
    case 'n':
        if (cli_parse_int("--links", arg, 1, 10000000, &v))
            return -1;
        s->links = (int)v;
        return 1;
    default: return 0;
    }
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

static void print_equilibrium(FILE *f, const ts_system *sys,
                              const ts_equilibrium *eq, double wall_s,
                              int quiet)
{
    fprintf(f, "speed %.6g m/s, turn rate %.6g rad/s, %d cable%s, %d links, "
               "%d bod%s\n",
            sys->tow.speed, sys->tow.turn_rate, sys->ncables,
            sys->ncables == 1 ? "" : "s", sys->nlinks, sys->nbodies,
            sys->nbodies == 1 ? "y" : "ies");
    /* A failed solve may end on forces that overflowed: no "nan". */
    char res[64];
    if (isfinite(eq->residual) && isfinite(eq->force_scale))
        snprintf(res, sizeof res, "%.3g of %.6g N", eq->residual,
                 eq->force_scale);
    else
        snprintf(res, sizeof res, "not finite");
    fprintf(f, "%s: %s, %d iterations, %ld evaluations, residual %s "
               "(target %.3g), %.3f ms\n",
            eq->converged ? "converged" : "NOT CONVERGED",
            ts_eq_method_name(eq->method), eq->iterations, eq->evaluations,
            res, eq->tolerance, wall_s * 1e3);
    if (!eq->converged)
        return;
    char name[2 * TS_NAME_MAX];
    if (!quiet) {
        fprintf(f, "\n%-20s %14s %14s %14s\n", "node", "x [m]", "y [m]",
                "z [m]");
        for (int i = 0; i < sys->nnodes; i++) {
            const double *r = eq->positions + 3 * i;
            ts_system_node_name(sys, i, name, sizeof name);
            fprintf(f, "%-20s %14.6f %14.6f %14.6f\n", name, r[0], r[1], r[2]);
        }
        fprintf(f, "\n%-20s %6s %14s %14s %14s\n", "cable", "link",
                "tension [N]", "theta1 [deg]", "theta2 [deg]");
        for (int l = 0; l < sys->nlinks; l++) {
            const ts_link *L = &sys->links[l];
            double t1, t2;
            ts_direction_angles(eq->directions + 3 * l, &t1, &t2);
            fprintf(f, "%-20s %6d %14.6f %14.6f %14.6f\n",
                    sys->cables[L->cable].name, L->index, eq->tensions[l],
                    t1 * 180 / M_PI, t2 * 180 / M_PI);
        }
    }
    if (sys->nbodies > 0) {
        fprintf(f, "\n%-20s %14s %14s %14s\n", "body", "x [m]", "y [m]",
                "z [m] (depth)");
        for (int b = 0; b < sys->nbodies; b++) {
            const double *r = eq->positions + 3 * ts_system_body_node(sys, b);
            fprintf(f, "%-20s %14.6f %14.6f %14.6f\n", sys->bodies[b].name,
                    r[0], r[1], r[2]);
        }
    }
    fprintf(f, "\ntop tension %.6f N (force on the tow point %.6f, %.6f, "
               "%.6f N)\n",
            eq->top_tension, eq->tow_force[0], eq->tow_force[1],
            eq->tow_force[2]);
    fprintf(f, "solver Jacobian condition %.3g, shape error estimate %.3g "
               "m\n",
            eq->condition, eq->shape_error);
    ts_trust t;
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    if (t.trustworthy)
        fprintf(f, "trustworthy: yes\n");
    else
        fprintf(f, "trustworthy: NO\n");
    for (int i = 0; i < t.nreasons; i++)
        fprintf(f, "  reason: %s\n", t.reasons[i]);
    for (int i = 0; i < t.nnotes; i++)
        fprintf(f, "  note: %s\n", t.notes[i]);
}

int cli_equilibrium(const ts_system *sys, const ts_equilibrium_opts *eo,
                    int quiet, ts_equilibrium **out, json_t **json,
                    ts_err *err)
{
    *out = NULL;
    ts_kernel *k = ts_kernel_alloc(sys, err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, err) : NULL;
    if (!k || !eq) {
        ts_kernel_free(k);
        return err->code;
    }
    double t0 = cli_wall_now();
    int rc = ts_equilibrium_solve(k, eo, eq, err);
    double wall = cli_wall_now() - t0;
    if (rc != TS_EINVAL && rc != TS_EDOMAIN) {
        print_equilibrium(stdout, sys, eq, wall, quiet);
        if (json)
            *json = ts_report_equilibrium_json(sys, eq, wall);
    }
    ts_kernel_free(k);
    *out = eq;
    return rc;
}
