/* cli.c: helpers shared by the towstab subcommands (cli.h): exit codes
 * and messages, the scene, JSON on standard output, output targets and
 * the closing check of the standard streams. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

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

int cli_exit_code(int rc)
{
    switch (rc) {
    case TS_OK: return 0;
    case TS_EINVAL:
    case TS_ESCENE:
    case TS_EUNIT:
    case TS_EDOMAIN: return EXIT_BADINPUT;
    default: return EXIT_FAILED;
    }
}

int cli_report(const ts_err *err, int rc)
{
    fprintf(stderr, "towstab: error: %s\n",
            err && err->msg[0] ? err->msg : ts_strerror(rc));
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

void cli_print_trust(const ts_trust *t)
{
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
