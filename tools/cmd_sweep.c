/* cmd_sweep.c: `towstab sweep SCENE --vary PATH=FROM:TO:N ...`: one
 * analysis over a grid of scene values (towstab/sweep.h, doc/sweep.md).
 *
 * The analysis (--analysis, default equilibrium) takes its options from
 * its own table, on the command line and in the scene's first entry of
 * its type, exactly as `towstab <analysis>` does, so a point is the single
 * run at the same settings. The sweep's own options are extras of the
 * command. With --resume FILE every finished chain is appended to FILE
 * (one record per line after a header naming the sweep); run again, the
 * command restores the chains FILE holds and computes only the rest. Under
 * mpirun each process runs its share of the chains and process 0 collects
 * them (cli_mpi.h). Prints the table, writes JSON and CSV
 * (towstab/report_sweep.h) and draws maps (towstab/plot.h).
 *
 * One file although long: the grid, the chains, the resume file and the
 * three ways of running them (serial, threads, MPI) share the chain
 * records and must produce the same table point for point. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "cli.h"
#include "cli_mpi.h"
#include "towstab/report.h"
#include "towstab/report_sweep.h"
#include "towstab/sweep.h"

/* Columns printed and drawn, at most. */
#define SWEEP_MAX_OUTPUTS 8
/* Characters of one line of a resume file, at most (a chain's record). */
#define JOURNAL_LINE_MAX (64 * 1024 * 1024)

enum {
    X_ANALYSIS, X_VARY, X_OUTPUT, X_CHAIN, X_JOBS, X_NO_BOUNDARY,
    X_BOUNDARY_TOL, X_RESUME
};

static const cli_extra sweep_extras[] = {
    {"analysis", 1, 0, "A",
     "the analysis at every point: equilibrium (default), modes, response "
     "or simulate; its options follow"},
    {"vary", 1, 1, "PATH=FROM:TO:N",
     "a scene value to vary: N values from FROM to TO, or PATH=V1,V2,...; "
     "up to 4 for a grid (the last varies fastest)"},
    {"output", 1, 0, "NAMES",
     "columns to print and draw, comma-separated [default: the last "
     "body's z, top_tension, max_real]"},
    {"chain", 1, 0, "N",
     "points per continuation chain along the last --vary, at most (1: "
     "every point from a cold start) [default 8]"},
    {"jobs", 1, 0, "N",
     "threads [default: every core; one per process under mpirun]"},
    {"no-boundary", 0, 0, NULL,
     "modes: do not bisect the stability boundary"},
    {"boundary-tol", 1, 0, "X",
     "bisect the boundary to this fraction of the grid step [default "
     "1e-3]"},
    {"resume", 1, 0, "FILE",
     "record finished chains in FILE; run again, resume from it"},
    {NULL, 0, 0, NULL, NULL}};

typedef struct sweep_state {
    ts_sweep *s;
    double *values[TS_SWEEP_MAX_AXES];
    int nout, out[SWEEP_MAX_OUTPUTS];
    const char *resume;
    FILE *journal;
    int restored;            /* chains restored from the resume file */
    char **crossing_lines;   /* records of crossings read, for later */
    int ncrossing_lines;
    int journal_failed;
} sweep_state;

/* ---- options ------------------------------------------------------------ */

static int bad(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "towstab: error: sweep: ");
    fprintf(stderr, fmt, a, b);
    fprintf(stderr, "\n");
    return EXIT_BADINPUT;
}

/* --vary PATH=FROM:TO:N or PATH=V1,V2,... into axis a. */
static int parse_vary(cli_run *c, sweep_state *st, int a, const char *text,
                      ts_sweep_axis *ax)
{
    const char *eq = strchr(text, '=');
    if (!eq || eq == text)
        return bad("--vary: expected PATH=FROM:TO:N (e.g. speed=2:10:17) "
                   "or PATH=V1,V2,..., got '%s'%s", text, "");
    snprintf(ax->path, sizeof ax->path, "%.*s", (int)(eq - text), text);
    char unit[TS_PARAM_UNIT_MAX];
    ts_err err = {0};
    if (ts_param_unit(c->scene->system, ax->path, unit, sizeof unit,
                      &err) != TS_OK) {
        fprintf(stderr, "towstab: error: sweep: --vary: %s\n", err.msg);
        return EXIT_BADINPUT;
    }
    const char *spec = eq + 1;
    char where[TS_PARAM_PATH_MAX + 16];
    snprintf(where, sizeof where, "--vary %s", ax->path);
    int colon = strchr(spec, ':') != NULL;
    char buf[1024];
    if (strlen(spec) >= sizeof buf)
        return bad("--vary %s: too long%s", ax->path, "");
    strcpy(buf, spec);
    /* Fields: FROM, TO, N; or the listed values. */
    char *field[4096];
    int nf = 0;
    char *save = NULL;
    for (char *p = strtok_r(buf, colon ? ":" : ",", &save); p && nf < 4096;
         p = strtok_r(NULL, colon ? ":" : ",", &save))
        field[nf++] = p;
    if (nf == 0 || (colon && nf != 3))
        return bad("--vary %s: expected FROM:TO:N or V1,V2,..., got '%s'",
                   ax->path, spec);
    double v[2];
    int nv = colon ? 2 : nf;
    double *vals = malloc((size_t)(colon ? 1 : nf) * sizeof *vals +
                          sizeof *vals);
    if (!vals)
        return bad("--vary %s: out of memory%s", ax->path, "");
    st->values[a] = vals;
    /* A unit written on one value applies to those written without one
     * ("2:4 knot", "2,3,4 knot"). */
    if (cli_parse_values(c->units, "sweep", where, (const char *const *)field,
                         nv, unit, colon ? v : vals))
        return EXIT_BADINPUT;
    if (!colon) {
        ax->n = nf;
        ax->values = vals;
        return 0;
    }
    char *end;
    long n = strtol(field[2], &end, 10);
    if (end == field[2] || *end || n < 1 || n > TS_SWEEP_MAX_POINTS)
        return bad("--vary %s: N: expected a whole number of values >= 1, "
                   "got '%s'", ax->path, field[2]);
    if (n == 1 && v[0] != v[1])
        return bad("--vary %s: one value from FROM to TO: give FROM:FROM:1 "
                   "or more values (%s)", ax->path, spec);
    double *all = realloc(vals, (size_t)n * sizeof *all);
    if (!all)
        return bad("--vary %s: out of memory%s", ax->path, "");
    st->values[a] = all;
    for (long i = 0; i < n; i++)
        all[i] = i == n - 1 ? v[1] : v[0] + (v[1] - v[0]) * (double)i /
                                                 (double)(n - 1);
    ax->n = (int)n;
    ax->values = all;
    return 0;
}

/* The default columns: the last point's z, the top tension, the kind's
 * own headline value. */
static void default_outputs(sweep_state *st)
{
    const ts_sweep *s = st->s;
    int z = -1;
    for (int c = 0; c < s->ncolumns; c++) {
        size_t n = strlen(s->columns[c].name);
        if (n > 2 && !strcmp(s->columns[c].name + n - 2, ".z") &&
            !strcmp(s->columns[c].unit, "m"))
            z = c;
    }
    if (z >= 0)
        st->out[st->nout++] = z;
    int t = ts_sweep_column_find(s, "top_tension");
    if (t >= 0)
        st->out[st->nout++] = t;
    int m = ts_sweep_column_find(s, TS_SWEEP_MAX_REAL);
    if (m >= 0)
        st->out[st->nout++] = m;
    /* A simulation's or a response's first own column. */
    if (s->kind == TS_ANALYSIS_SIMULATE || s->kind == TS_ANALYSIS_RESPONSE)
        for (int c = t + 1; c < s->ncolumns && st->nout < 4; c++) {
            st->out[st->nout++] = c;
            break;
        }
}

static int parse_outputs(sweep_state *st, const char *text)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", text);
    char *save = NULL;
    for (char *p = strtok_r(buf, ",", &save); p;
         p = strtok_r(NULL, ",", &save)) {
        while (*p == ' ')
            p++;
        int c = ts_sweep_column_find(st->s, p);
        if (c < 0) {
            char list[2048] = "";
            size_t len = 0;
            for (int k = 0; k < st->s->ncolumns; k++)
                len += (size_t)snprintf(list + len,
                                        len < sizeof list ? sizeof list - len
                                                          : 0,
                                        "%s%s", k ? ", " : "",
                                        st->s->columns[k].name);
            return bad("--output: no column '%s'; the columns: %s", p, list);
        }
        if (st->nout == SWEEP_MAX_OUTPUTS)
            return bad("--output: at most 8 columns%s%s", "", "");
        st->out[st->nout++] = c;
    }
    return st->nout ? 0 : bad("--output: expected column names, got '%s'%s",
                              text, "");
}

/* ---- the resume file ------------------------------------------------------ */

/* FNV-1a 64 of a file's bytes, as 16 hex digits; "" when unreadable. */
static void file_hash(const char *path, char out[17])
{
    FILE *f = fopen(path, "rb");
    out[0] = '\0';
    if (!f)
        return;
    unsigned long long h = 1469598103934665603ULL;
    int ch;
    while ((ch = fgetc(f)) != EOF)
        h = (h ^ (unsigned char)ch) * 1099511628211ULL;
    fclose(f);
    snprintf(out, 17, "%016llx", h);
}

/* Options of the command line that do not change the table. */
static int outputs_only(const char *arg)
{
    static const char *const skip[] = {"--jobs", "--resume", "--output",
                                       NULL};
    for (int i = 0; skip[i]; i++) {
        size_t n = strlen(skip[i]);
        if (!strncmp(arg, skip[i], n) && (arg[n] == '\0' || arg[n] == '='))
            return 1;
    }
    return 0;
}

static int cmp_text(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The header that names the sweep a resume file belongs to: the scene
 * (name and file contents), the command's options that shape the table
 * (in any order) and the grid. */
static json_t *journal_header(const cli_run *c, const ts_sweep *s)
{
    char hash[17];
    file_hash(c->scene->path, hash);
    /* The options given, in any order. */
    const char **args = calloc((size_t)c->ngiven + 1, sizeof *args);
    int n = 0;
    for (int i = 0; args && i < c->ngiven; i++)
        if (!outputs_only(c->given[i]))
            args[n++] = c->given[i];
    if (args)
        qsort(args, (size_t)n, sizeof *args, cmp_text);
    json_t *cmd = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(cmd, json_string(args[i]));
    free(args);
    json_t *axes = json_array();
    for (int a = 0; a < s->spec.naxes; a++) {
        json_t *v = json_array();
        for (int i = 0; i < s->spec.axes[a].n; i++)
            json_array_append_new(v, json_real(s->spec.axes[a].values[i]));
        json_array_append_new(axes, json_pack("{s:s,s:o}", "path",
                                              s->spec.axes[a].path, "values",
                                              v));
    }
    return json_pack("{s:i,s:s,s:s,s:s,s:o,s:o,s:i,s:i}", "towstab_sweep", 1,
                     "scene", c->scene->system->name, "scene_file_hash",
                     hash, "analysis", ts_analysis_name(s->kind), "options",
                     cmd, "axes", axes, "points", s->npoints, "chains",
                     s->nchains);
}

/* The first key in which two headers differ. */
static const char *header_difference(json_t *a, json_t *b)
{
    static const char *const keys[] = {"towstab_sweep", "scene",
                                       "scene_file_hash", "analysis",
                                       "options", "axes", "points", "chains",
                                       NULL};
    for (int i = 0; keys[i]; i++)
        if (!json_equal(json_object_get(a, keys[i]),
                        json_object_get(b, keys[i])))
            return keys[i];
    return NULL;
}

/* Read `path` if it exists: check its header, restore its chains, keep
 * its crossing records for later; then open it for appending (writing
 * the header to a new file). A last line without its newline (the write
 * an interruption cut) is dropped from the file. Prints; returns the exit
 * status. */
static int journal_open(cli_run *c, sweep_state *st)
{
    ts_sweep *s = st->s;
    json_t *want = journal_header(c, s);
    if (!want) {
        fprintf(stderr, "towstab: error: sweep: out of memory\n");
        return EXIT_FAILED;
    }
    FILE *f = fopen(st->resume, "r");
    long good = 0; /* bytes of complete lines */
    int status = 0, lineno = 0;
    if (!f && errno != ENOENT) {
        fprintf(stderr, "towstab: error: sweep: --resume %s: cannot read it "
                        "(%s)\n", st->resume, strerror(errno));
        json_decref(want);
        return EXIT_BADINPUT;
    }
    char *line = NULL;
    size_t cap = 0;
    ssize_t len;
    while (f && !status && (len = getline(&line, &cap, f)) > 0) {
        lineno++;
        if (line[len - 1] != '\n')
            break; /* cut short: dropped */
        line[len - 1] = '\0';
        if (lineno == 1) {
            json_t *have = json_loads(line, 0, NULL);
            const char *d = have ? header_difference(have, want) : "header";
            if (d) {
                fprintf(stderr, "towstab: error: sweep: --resume %s: it "
                                "records another sweep (they differ in: %s); "
                                "give another file, or remove it to start "
                                "afresh\n", st->resume, d);
                status = EXIT_BADINPUT;
            }
            json_decref(have);
        } else if (strstr(line, "\"crossing\"")) {
            char **l = realloc(st->crossing_lines,
                               (size_t)(st->ncrossing_lines + 1) * sizeof *l);
            if (l) {
                st->crossing_lines = l;
                l[st->ncrossing_lines] = strdup(line);
                st->ncrossing_lines += l[st->ncrossing_lines] != NULL;
            }
        } else {
            ts_err err = {0};
            if (ts_report_sweep_restore(s, line, &err) != TS_OK) {
                fprintf(stderr, "towstab: error: sweep: --resume %s line %d: "
                                "%s\n", st->resume, lineno, err.msg);
                status = EXIT_BADINPUT;
            } else {
                st->restored++;
            }
        }
        good += len;
    }
    free(line);
    if (f)
        fclose(f);
    if (!status && f && truncate(st->resume, good) != 0) {
        fprintf(stderr, "towstab: error: sweep: --resume %s: cannot drop its "
                        "cut last line (%s)\n", st->resume, strerror(errno));
        status = EXIT_FAILED;
    }
    if (!status) {
        st->journal = fopen(st->resume, "a");
        if (!st->journal) {
            fprintf(stderr, "towstab: error: sweep: --resume %s: cannot write "
                            "it (%s)\n", st->resume, strerror(errno));
            status = EXIT_FAILED;
        } else if (good == 0) {
            char *h = json_dumps(want, JSON_COMPACT | JSON_REAL_PRECISION(17));
            if (!h || fprintf(st->journal, "%s\n", h) < 0 ||
                fflush(st->journal) != 0) {
                fprintf(stderr, "towstab: error: sweep: --resume %s: cannot "
                                "write it\n", st->resume);
                status = EXIT_FAILED;
            }
            free(h);
        }
    }
    json_decref(want);
    return status;
}

/* Append a record (process 0). Nonzero when it could not be written. */
static int journal_add(sweep_state *st, const char *text)
{
    if (!st->journal)
        return 0;
    if (fprintf(st->journal, "%s\n", text) < 0 || fflush(st->journal) != 0) {
        if (!st->journal_failed)
            fprintf(stderr, "towstab: error: sweep: --resume %s: write failed "
                            "(%s); stopping\n", st->resume, strerror(errno));
        st->journal_failed = 1;
        return 1;
    }
    return 0;
}

/* ---- running ------------------------------------------------------------ */

/* A record from another process: restore and append. */
static int on_record(const char *text, void *data)
{
    sweep_state *st = data;
    ts_err err = {0};
    if (ts_report_sweep_restore(st->s, text, &err) != TS_OK) {
        fprintf(stderr, "towstab: error: sweep: a record from another "
                        "process: %s\n", err.msg);
        return 1;
    }
    return journal_add(st, text);
}

static int on_chain(const ts_sweep *s, int chain, void *data)
{
    sweep_state *st = data;
    char *text = ts_report_sweep_record(s, chain);
    if (!text) {
        fprintf(stderr, "towstab: error: sweep: out of memory for a "
                        "record\n");
        return 1;
    }
    int stop = cli_mpi_rank() == 0 ? journal_add(st, text)
                                   : cli_mpi_send_record(text) != 0;
    free(text);
    int ends = 0, worst = 0;
    if (!stop && cli_mpi_rank() == 0)
        stop = cli_mpi_poll(0, on_record, st, &ends, &worst);
    return stop;
}

/* Progress: the signal handlers' flag, and process 0's stop request. */
static int sweep_progress(const ts_progress *p, void *data)
{
    (void)data;
    return cli_progress(p, NULL) || cli_mpi_stopped();
}

/* Wait for the other processes' ends (process 0), restoring their
 * records; the largest status any ended with. */
static int gather(sweep_state *st, int rc_here)
{
    if (cli_mpi_size() == 1)
        return 0;
    if (cli_mpi_rank() != 0) {
        cli_mpi_send_end(rc_here == TS_OK ? 0 : cli_exit_code(rc_here));
        return 0;
    }
    if (rc_here != TS_OK)
        cli_mpi_send_stop();
    int ends = 0, worst = 0;
    int stop = cli_mpi_poll(1, on_record, st, &ends, &worst);
    return stop ? EXIT_FAILED : worst;
}

/* Process 0 tells the others what it holds before a phase: per point
 * (or crossing) its state, and for the boundary the verdicts and margins
 * the crossings are laid out from. */
static int share_points(ts_sweep *s)
{
    if (cli_mpi_size() == 1)
        return 0;
    int n = s->npoints;
    int *iv = malloc(3 * (size_t)n * sizeof *iv);
    double *dv = malloc(2 * (size_t)n * sizeof *dv);
    int mr = ts_sweep_column_find(s, TS_SWEEP_MAX_REAL);
    int mf = ts_sweep_column_find(s, TS_SWEEP_MAX_REAL_FREQ);
    int rc = iv && dv ? 0 : -1;
    if (!rc && cli_mpi_rank() == 0)
        for (int p = 0; p < n; p++) {
            iv[3 * p] = s->points[p].state;
            iv[3 * p + 1] = s->points[p].status;
            iv[3 * p + 2] = s->points[p].verdict;
            size_t at = (size_t)p * (size_t)s->ncolumns;
            dv[2 * p] = mr >= 0 ? s->values[at + (size_t)mr] : NAN;
            dv[2 * p + 1] = mf >= 0 ? s->values[at + (size_t)mf] : NAN;
        }
    if (!rc)
        rc = cli_mpi_broadcast(iv, 3 * (size_t)n * sizeof *iv);
    if (!rc)
        rc = cli_mpi_broadcast(dv, 2 * (size_t)n * sizeof *dv);
    if (!rc && cli_mpi_rank() != 0)
        for (int p = 0; p < n; p++) {
            s->points[p].state = iv[3 * p];
            s->points[p].status = iv[3 * p + 1];
            s->points[p].verdict = iv[3 * p + 2];
            size_t at = (size_t)p * (size_t)s->ncolumns;
            if (mr >= 0)
                s->values[at + (size_t)mr] = dv[2 * p];
            if (mf >= 0)
                s->values[at + (size_t)mf] = dv[2 * p + 1];
        }
    free(iv);
    free(dv);
    return rc;
}

static int share_crossings(ts_sweep *s)
{
    if (cli_mpi_size() == 1 || s->ncrossings == 0)
        return 0;
    int *done = malloc((size_t)s->ncrossings * sizeof *done);
    if (!done)
        return -1;
    for (int i = 0; i < s->ncrossings; i++)
        done[i] = s->crossings[i].done;
    int rc = cli_mpi_broadcast(done, (size_t)s->ncrossings * sizeof *done);
    for (int i = 0; !rc && i < s->ncrossings; i++)
        s->crossings[i].done = done[i];
    free(done);
    return rc;
}

/* ---- printing --------------------------------------------------------- */

static void print_cell(double v, int width)
{
    if (isfinite(v))
        printf(" %*.7g", width, v);
    else
        printf(" %*s", width, "-");
}

static const char *point_result(const ts_sweep_point *pt)
{
    if (pt->state != TS_SWEEP_DONE)
        return "pending";
    if (pt->status != TS_OK)
        return "FAILED";
    if (pt->verdict == TS_UNSTABLE)
        return pt->trust.trustworthy ? "UNSTABLE" : "UNSTABLE, NOT TRUSTED";
    if (!pt->trust.trustworthy)
        return "NOT TRUSTWORTHY";
    return pt->verdict == TS_MARGINAL ? "marginal" : "ok";
}

static void print_table(const sweep_state *st, int quiet)
{
    const ts_sweep *s = st->s;
    int failed = 0, untrusted = 0, unstable = 0, warm = 0, done = 0;
    for (int p = 0; p < s->npoints; p++) {
        const ts_sweep_point *pt = &s->points[p];
        if (pt->state != TS_SWEEP_DONE)
            continue;
        done++;
        failed += pt->status != TS_OK;
        untrusted += pt->status == TS_OK && !pt->trust.trustworthy;
        unstable += pt->verdict == TS_UNSTABLE;
        warm += pt->warm;
    }
    if (!quiet) {
        /* Headers "path [unit]", each column as wide as its header. */
        int width[TS_SWEEP_MAX_AXES + SWEEP_MAX_OUTPUTS];
        char h[TS_PARAM_PATH_MAX + TS_VALUE_NAME_MAX];
        int nh = 0;
        printf("\n");
        for (int a = 0; a < s->spec.naxes; a++, nh++) {
            const char *u = s->spec.axes[a].unit;
            int n = snprintf(h, sizeof h, "%s%s%s%s", s->spec.axes[a].path,
                             u[0] ? " [" : "", u, u[0] ? "]" : "");
            width[nh] = n > 13 ? n : 13;
            printf(" %*s", width[nh], h);
        }
        for (int k = 0; k < st->nout; k++, nh++) {
            const ts_sweep_column *c = &s->columns[st->out[k]];
            int n = snprintf(h, sizeof h, "%s%s%s%s", c->name,
                             c->unit[0] ? " [" : "", c->unit,
                             c->unit[0] ? "]" : "");
            width[nh] = n > 13 ? n : 13;
            printf(" %*s", width[nh], h);
        }
        printf("  result\n");
        for (int p = 0; p < s->npoints; p++) {
            const ts_sweep_point *pt = &s->points[p];
            int idx[TS_SWEEP_MAX_AXES];
            ts_sweep_point_index(s, p, idx);
            for (int a = 0; a < s->spec.naxes; a++)
                print_cell(s->spec.axes[a].values[idx[a]], width[a]);
            for (int k = 0; k < st->nout; k++)
                print_cell(s->values[(size_t)p * (size_t)s->ncolumns +
                                     (size_t)st->out[k]],
                           width[s->spec.naxes + k]);
            printf("  %s", point_result(pt));
            if (pt->state == TS_SWEEP_DONE && pt->status != TS_OK)
                printf(": %s", pt->error);
            else if (pt->state == TS_SWEEP_DONE && !pt->trust.trustworthy &&
                     pt->trust.nreasons > 0)
                printf(": %s", pt->trust.reasons[0]);
            printf("\n");
        }
    }
    printf("\n%d of %d points done: %d failed, %d not trustworthy", done,
           s->npoints, failed, untrusted);
    if (s->kind == TS_ANALYSIS_MODES)
        printf(", %d unstable", unstable);
    printf("; %d continued from their neighbour\n", warm);
    for (int i = 0; i < s->ncrossings; i++) {
        const ts_sweep_crossing *x = &s->crossings[i];
        const ts_sweep_axis *ax = &s->spec.axes[x->axis];
        int idx[TS_SWEEP_MAX_AXES];
        ts_sweep_point_index(s, x->from, idx);
        printf("stability boundary: %s = %.8g %s (stable or marginal at "
               "%.8g, unstable at %.8g",
               ax->path, x->value, ax->unit, x->stable, x->unstable);
        for (int a = 0; a < s->spec.naxes; a++)
            if (a != x->axis)
                printf("; %s = %.6g %s", s->spec.axes[a].path,
                       s->spec.axes[a].values[idx[a]], s->spec.axes[a].unit);
        printf("), ");
        if (!x->done)
            printf("not bisected\n");
        else if (x->status != TS_OK)
            printf("bisection FAILED: %s\n", x->error);
        else if (isfinite(x->freq_hz) && x->freq_hz > 0)
            printf("a mode at %.4g Hz becomes unstable (flutter); %d runs, "
                   "%.3g s\n", x->freq_hz, x->runs, x->wall_s);
        else
            printf("a real mode becomes unstable (divergence); %d runs, "
                   "%.3g s\n", x->runs, x->wall_s);
    }
    printf("evaluations %ld; wall %.3f s in this run", s->evaluations,
           s->wall_s);
    if (s->wall_s > 0 && done > 0 && st->restored < s->nchains)
        printf(" (%.3g points per s)",
               (double)(done - 0) / s->wall_s);
    printf("\n");
    printf("trustworthy: %s\n", failed || untrusted || !s->completed
                                    ? "NO"
                                    : "yes");
}

/* ---- pictures --------------------------------------------------------- */

static ts_plot_quantity quantity_of(const char *unit)
{
    static const struct {
        const char *unit;
        ts_plot_quantity q;
    } map[] = {{"m", TS_PLOT_LENGTH},       {"m/s", TS_PLOT_SPEED},
               {"N", TS_PLOT_FORCE},        {"s", TS_PLOT_TIME},
               {"Hz", TS_PLOT_FREQUENCY},   {"1/s", TS_PLOT_RATE},
               {"rad/s", TS_PLOT_ANGULAR_RATE}, {"rad", TS_PLOT_ANGLE},
               {"kg", TS_PLOT_MASS}};
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (!strcmp(unit, map[i].unit))
            return map[i].q;
    return TS_PLOT_NONE;
}

static ts_plot_axis axis_of(const char *label, const char *unit)
{
    ts_plot_axis a = {label, quantity_of(unit),
                      strcmp(unit, "1") && unit[0] ? unit : NULL};
    return a;
}

/* A file name from a column name: [A-Za-z0-9_-]. */
static void picture_name(char *buf, size_t size, const char *prefix,
                         const char *column)
{
    snprintf(buf, size, "%s%s", prefix, column);
    for (char *p = buf; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
              (*p >= '0' && *p <= '9') || *p == '-' || *p == '_'))
            *p = '_';
}

static int point_marks(const ts_sweep_point *pt)
{
    if (pt->state != TS_SWEEP_DONE || pt->status != TS_OK)
        return TS_PLOT_MARK_FAILED;
    return (pt->verdict == TS_UNSTABLE ? TS_PLOT_MARK_UNSTABLE : 0) |
           (!pt->trust.trustworthy ? TS_PLOT_MARK_UNTRUSTED : 0);
}

/* Two axes: a map per output column. */
static int draw_maps(const cli_run *c, const sweep_state *st)
{
    const ts_sweep *s = st->s;
    const ts_sweep_axis *ax = &s->spec.axes[0], *ay = &s->spec.axes[1];
    int n = s->npoints;
    double *z = malloc(((size_t)n + 2 * (size_t)s->ncrossings + 1) *
                       sizeof *z);
    int *marks = malloc((size_t)n * sizeof *marks);
    if (!z || !marks) {
        free(z);
        free(marks);
        fprintf(stderr, "towstab: error: sweep: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    double *bx = z + n, *by = bx + s->ncrossings;
    int nb = 0;
    for (int i = 0; i < s->ncrossings; i++) {
        const ts_sweep_crossing *x = &s->crossings[i];
        if (!x->done || x->status != TS_OK)
            continue;
        int idx[TS_SWEEP_MAX_AXES];
        ts_sweep_point_index(s, x->from, idx);
        bx[nb] = x->axis == 0 ? x->value : ax->values[idx[0]];
        by[nb++] = x->axis == 1 ? x->value : ay->values[idx[1]];
    }
    for (int p = 0; p < n; p++)
        marks[p] = point_marks(&s->points[p]);
    int status = 0;
    for (int k = 0; k < st->nout && !status; k++) {
        const ts_sweep_column *col = &s->columns[st->out[k]];
        for (int p = 0; p < n; p++)
            z[p] = s->values[(size_t)p * (size_t)s->ncolumns +
                             (size_t)st->out[k]];
        char name[160], title[800];
        picture_name(name, sizeof name, "map_", col->name);
        snprintf(title, sizeof title, "%.200s: %.95s over %.159s and %.159s "
                 "(%s)", s->sys->name, col->name, ax->path, ay->path,
                 ts_analysis_name(s->kind));
        ts_plot_axis xa = axis_of(ax->path, ax->unit);
        ts_plot_axis ya = axis_of(ay->path, ay->unit);
        ts_plot_axis za = axis_of(col->name, col->unit);
        ts_plot_grid g = {ax->n, ay->n, ax->values, ay->values, z};
        ts_err err = {0};
        if (ts_plot_map(c->plot.dir, name, title, &xa, &ya, &za, &g, marks,
                        nb, bx, by, &c->plot.opts, &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            printf("wrote %s/%s.png and %s/%s.svg\n", c->plot.dir, name,
                   c->plot.dir, name);
    }
    free(z);
    free(marks);
    return status;
}

/* One axis: the output columns in panels against it, unstable and
 * untrustworthy points marked, the boundary as vertical lines. */
static int draw_lines(const cli_run *c, const sweep_state *st)
{
    const ts_sweep *s = st->s;
    const ts_sweep_axis *ax = &s->spec.axes[0];
    int n = s->npoints, np = st->nout;
    int maxser = np * (3 + s->ncrossings);
    double *buf = malloc((size_t)np * (6 * (size_t)n + 4 * (size_t)s->ncrossings +
                                       1) * sizeof *buf);
    ts_plot_series *ser = calloc((size_t)maxser + 1, sizeof *ser);
    ts_plot_axis *panels = calloc((size_t)np, sizeof *panels);
    if (!buf || !ser || !panels) {
        free(buf);
        free(ser);
        free(panels);
        fprintf(stderr, "towstab: error: sweep: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    int ns = 0, npanels = 0;
    double *at = buf;
    for (int k0 = 0; k0 < np; k0++) {
        const ts_sweep_column *col = &s->columns[st->out[k0]];
        int k = npanels, any = 0;
        for (int p = 0; p < n; p++)
            any |= isfinite(s->values[(size_t)p * (size_t)s->ncolumns +
                                      (size_t)st->out[k0]]);
        if (!any)
            continue; /* no value: no panel */
        panels[npanels++] = axis_of(col->name, col->unit);
        double *x[3], *y[3];
        int m[3] = {0, 0, 0};
        for (int j = 0; j < 3; j++) {
            x[j] = at;
            y[j] = at + n;
            at += 2 * n;
        }
        double lo = INFINITY, hi = -INFINITY;
        for (int p = 0; p < n; p++) {
            double v = s->values[(size_t)p * (size_t)s->ncolumns +
                                 (size_t)st->out[k0]];
            if (!isfinite(v))
                continue;
            lo = fmin(lo, v);
            hi = fmax(hi, v);
            int mk = point_marks(&s->points[p]);
            x[0][m[0]] = ax->values[p];
            y[0][m[0]++] = v;
            for (int j = 1; j < 3; j++)
                if (mk & (j == 1 ? TS_PLOT_MARK_UNSTABLE
                                 : TS_PLOT_MARK_UNTRUSTED)) {
                    x[j][m[j]] = ax->values[p];
                    y[j][m[j]++] = v;
                }
        }
        static const char *const label[3] = {NULL, "unstable",
                                             "not trustworthy"};
        static const int style[3] = {TS_PLOT_LINE_MARKERS, TS_PLOT_MARKERS,
                                     TS_PLOT_MARKERS};
        static const int color[3] = {1, 2, 6};
        for (int j = 0; j < 3; j++)
            if (m[j] > 0)
                ser[ns++] = (ts_plot_series){m[j], x[j], y[j],
                                             k == 0 ? label[j] : NULL, k,
                                             style[j], color[j], NULL};
        for (int i = 0; i < s->ncrossings && isfinite(lo); i++) {
            const ts_sweep_crossing *xc = &s->crossings[i];
            if (!xc->done || xc->status != TS_OK)
                continue;
            double *bx = at, *by = at + 2;
            at += 4;
            bx[0] = bx[1] = xc->value;
            by[0] = lo;
            by[1] = hi > lo ? hi : lo + 1;
            ser[ns++] = (ts_plot_series){2, bx, by,
                                         k == 0 && i == 0
                                             ? "stability boundary"
                                             : NULL,
                                         k, TS_PLOT_DASHED, 5, NULL};
        }
    }
    char title[400];
    snprintf(title, sizeof title, "%s: %s over %s", s->sys->name,
             ts_analysis_name(s->kind), ax->path);
    ts_plot_axis xa = axis_of(ax->path, ax->unit);
    ts_err err = {0};
    int status = 0;
    if (ns == 0) {
        fprintf(stderr, "towstab: error: sweep: --plot: no value to draw\n");
        status = EXIT_FAILED;
    } else if (ts_plot_panels(c->plot.dir, "sweep", title, &xa, npanels,
                              panels, ns, ser, &c->plot.opts,
                              &err) != TS_OK) {
        status = cli_report(&err, err.code);
    } else {
        printf("wrote %s/sweep.png and %s/sweep.svg\n", c->plot.dir,
               c->plot.dir);
    }
    free(buf);
    free(ser);
    free(panels);
    return status;
}

static int draw(const cli_run *c, const sweep_state *st)
{
    if (!c->plot.dir)
        return 0;
    const ts_sweep *s = st->s;
    if (s->spec.naxes == 1)
        return draw_lines(c, st);
    if (s->spec.naxes == 2 && s->spec.axes[0].n >= 2 &&
        s->spec.axes[1].n >= 2)
        return draw_maps(c, st);
    printf("note: --plot draws one --vary as curves and two (of at least 2 "
           "values each) as maps; this sweep has %d\n", s->spec.naxes);
    return 0;
}

/* ---- the command ------------------------------------------------------ */

static void sweep_release(cli_run *c)
{
    sweep_state *st = c->state;
    if (!st)
        return;
    ts_sweep_free(st->s);
    for (int a = 0; a < TS_SWEEP_MAX_AXES; a++)
        free(st->values[a]);
    for (int i = 0; i < st->ncrossing_lines; i++)
        free(st->crossing_lines[i]);
    free(st->crossing_lines);
    if (st->journal)
        fclose(st->journal);
    free(st);
    c->state = NULL;
}

static int sweep_prepare(cli_run *c)
{
    sweep_state *st = calloc(1, sizeof *st);
    if (!st) {
        fprintf(stderr, "towstab: error: sweep: out of memory\n");
        return EXIT_FAILED;
    }
    c->state = st;
    ts_sweep_spec sp;
    memset(&sp, 0, sizeof sp);
    sp.rq = c->rq;
    sp.naxes = c->nextra[X_VARY];
    if (sp.naxes == 0)
        return bad("expected at least one --vary PATH=FROM:TO:N (e.g. "
                   "--vary speed=2:10:17)%s%s", "", "");
    if (sp.naxes > TS_SWEEP_MAX_AXES)
        return bad("at most 4 --vary%s%s", "", "");
    for (int a = 0; a < sp.naxes; a++) {
        int status = parse_vary(c, st, a, c->extra[X_VARY][a], &sp.axes[a]);
        if (status)
            return status;
    }
    /* A value the sweep varies that the scene's entry also sets yields to
     * the sweep (one given on the command line is refused below). */
    for (int a = 0; a < sp.naxes; a++) {
        char canon[TS_PARAM_PATH_MAX];
        if (ts_param_canonical(sp.axes[a].path, canon, sizeof canon, NULL))
            continue;
        static const char *const own[2] = {"speed", "turn_rate"};
        double *val[2] = {&sp.rq.setup.speed, &sp.rq.setup.turn_rate};
        for (int k = 0; k < 2; k++) {
            const char *where = ts_optset_where(c->opts, own[k]);
            if (strcmp(canon + 4, own[k]) || strncmp(canon, "tow.", 4) ||
                !where || !strncmp(where, "--", 2))
                continue;
            printf("note: %s is varied; the value of %s is not used\n",
                   canon, where);
            *val[k] = NAN;
        }
    }
    long v = 0;
    if (c->nextra[X_CHAIN] &&
        cli_parse_int("sweep: --chain", c->extra[X_CHAIN][0], 1, 1000000, &v))
        return EXIT_BADINPUT;
    sp.chain = (int)v;
    v = 0;
    if (c->nextra[X_JOBS] &&
        cli_parse_int("sweep: --jobs", c->extra[X_JOBS][0], 1, 4096, &v))
        return EXIT_BADINPUT;
    sp.threads = c->nextra[X_JOBS] ? (int)v : cli_mpi_size() > 1 ? 1 : 0;
    sp.boundary = c->cmd->kind == TS_ANALYSIS_MODES &&
                  !c->nextra[X_NO_BOUNDARY];
    if (c->nextra[X_NO_BOUNDARY] && c->cmd->kind != TS_ANALYSIS_MODES)
        return bad("--no-boundary: the boundary belongs to --analysis modes%s"
                   "%s", "", "");
    if (c->nextra[X_BOUNDARY_TOL]) {
        char *end;
        const char *t = c->extra[X_BOUNDARY_TOL][0];
        sp.boundary_rtol = strtod(t, &end);
        if (end == t || *end || !(sp.boundary_rtol > 0 &&
                                  sp.boundary_rtol < 1))
            return bad("--boundary-tol: expected a fraction of the grid step "
                       "in (0, 1), got '%s'%s", t, "");
        if (!sp.boundary)
            return bad("--boundary-tol: the boundary is bisected by "
                       "--analysis modes (without --no-boundary)%s%s", "",
                       "");
    }
    sp.progress = sweep_progress;
    sp.on_chain = on_chain;
    sp.on_chain_data = st;
    ts_err err = {0};
    st->s = ts_sweep_alloc(c->scene->system, &sp, &err);
    if (!st->s) {
        ts_optset_locate(c->opts, &err);
        return cli_report(&err, err.code);
    }
    int status = c->nextra[X_OUTPUT]
                     ? parse_outputs(st, c->extra[X_OUTPUT][0])
                     : (default_outputs(st), 0);
    st->resume = c->nextra[X_RESUME] ? c->extra[X_RESUME][0] : NULL;
    if (!status && st->resume && cli_mpi_rank() == 0)
        status = journal_open(c, st);
    return status;
}

/* Mark the points of chains restored on process 0 as done on the others
 * (they skip them). */
static int share_done(ts_sweep *s)
{
    if (cli_mpi_size() == 1)
        return 0;
    int n = s->npoints;
    int *state = malloc((size_t)n * sizeof *state);
    if (!state)
        return -1;
    for (int p = 0; p < n; p++)
        state[p] = s->points[p].state;
    int rc = cli_mpi_broadcast(state, (size_t)n * sizeof *state);
    for (int p = 0; !rc && p < n; p++)
        s->points[p].state = state[p];
    free(state);
    return rc;
}

static int sweep_execute(cli_run *c)
{
    sweep_state *st = c->state;
    ts_sweep *s = st->s;
    int rank = cli_mpi_rank(), size = cli_mpi_size();
    int threads = s->spec.threads;
#ifdef _OPENMP
    if (threads == 0)
        threads = omp_get_max_threads();
#else
    threads = 1;
#endif
    printf("sweep: %s at %d point%s (", ts_analysis_name(s->kind), s->npoints,
           s->npoints == 1 ? "" : "s");
    for (int a = 0; a < s->spec.naxes; a++)
        printf("%s%s %d", a ? " x " : "", s->spec.axes[a].path,
               s->spec.axes[a].n);
    printf("), %d chain%s of at most %d along %s; %d thread%s", s->nchains,
           s->nchains == 1 ? "" : "s", s->chain_len,
           s->spec.axes[s->spec.naxes - 1].path, threads,
           threads == 1 ? "" : "s");
    if (size > 1)
        printf(" on each of %d processes", size);
    printf("\n");
    if (st->resume)
        printf("resume file %s: %d of %d chains restored\n", st->resume,
               st->restored, s->nchains);
    ts_err err = {0};
    int rc = share_done(s) ? ts_fail(&err, TS_EIO, "sweep: MPI broadcast "
                                                  "failed")
                           : TS_OK;
    if (!rc)
        rc = ts_sweep_run(s, rank, size, &err);
    int others = gather(st, rc);
    cli_progress_done();
    int grid_done = 1;
    for (int p = 0; p < s->npoints; p++)
        grid_done &= s->points[p].state == TS_SWEEP_DONE;
    /* The boundary, once the whole grid is known. */
    int go = rc == TS_OK && !others && grid_done && s->spec.boundary;
    if (size > 1 && cli_mpi_broadcast(&go, sizeof go))
        go = 0;
    if (go && share_points(s))
        go = 0;
    if (go) {
        rc = ts_sweep_crossings_find(s, &err);
        for (int i = 0; !rc && rank == 0 && i < st->ncrossing_lines; i++)
            if (ts_report_sweep_restore(s, st->crossing_lines[i], &err))
                rc = err.code;
        if (!rc && share_crossings(s))
            rc = ts_fail(&err, TS_EIO, "sweep: MPI broadcast failed");
        if (!rc)
            rc = ts_sweep_run_crossings(s, rank, size, &err);
        others = gather(st, rc);
        cli_progress_done();
    }
    ts_sweep_finish(s);
    if (rank != 0) {
        if (rc != TS_OK && rc != TS_ECANCEL)
            return cli_report(&err, rc);
        return rc == TS_OK ? 0 : cli_exit_code(rc);
    }
    print_table(st, c->quiet);
    int status = 0;
    if (rc != TS_OK)
        status = cli_report(&err, rc);
    else if (others)
        status = others;
    if (st->journal_failed && !status)
        status = EXIT_FAILED;
    int failed = 0, done = 0;
    for (int p = 0; p < s->npoints; p++) {
        done += s->points[p].state == TS_SWEEP_DONE;
        failed += s->points[p].state == TS_SWEEP_DONE &&
                  s->points[p].status != TS_OK;
    }
    if (!status && done > 0 && failed == done) {
        fprintf(stderr, "towstab: error: sweep: every point failed (first: "
                        "%s)\n", s->points[0].error);
        status = EXIT_FAILED;
    }
    /* What there is is written also after an interruption (marked
     * incomplete); nothing when no point was done. */
    ts_err werr = {0};
    if (c->json && done > 0)
        status = cli_put_json(ts_report_sweep_json(s), c->json, status);
    if (c->csv && done > 0)
        status = cli_put_status(ts_report_sweep_csv(s, c->csv, &werr),
                                &werr, status);
    if (done > 0) {
        int e = draw(c, st);
        status = status ? status : e;
    }
    return status;
}

/* `towstab sweep`: its command is made for the analysis --analysis names
 * (its option table), then run as every analysis command is. */
static int sweep_main(int argc, char **argv)
{
    int kind = TS_ANALYSIS_EQUILIBRIUM;
    const char *name = cli_analysis_arg(argc, argv);
    if (name) {
        kind = ts_analysis_find(name);
        if (kind < 0 || kind == TS_ANALYSIS_CONVERGE) {
            fprintf(stderr, "towstab: error: sweep: --analysis: '%s' is not "
                            "an analysis to sweep; expected equilibrium, "
                            "modes, response or simulate\n", name);
            return EXIT_BADINPUT;
        }
    }
    int status = cli_mpi_init(&argc, &argv);
    if (status)
        return status;
    /* Only process 0 prints its tables. */
    if (cli_mpi_rank() != 0 && !freopen("/dev/null", "w", stdout))
        status = EXIT_FAILED;
    cli_command cmd = {"sweep",
                       "an analysis over a grid of scene values (operating "
                       "envelopes, the stability boundary)",
                       kind, NULL, sweep_prepare, NULL, NULL, sweep_release,
                       NULL, sweep_extras, sweep_execute};
    if (!status)
        status = cli_main(&cmd, argc, argv);
    cli_mpi_finalize();
    return status;
}

const cli_command cli_cmd_sweep = {
    "sweep",
    "an analysis over a grid of scene values (operating envelopes, the "
    "stability boundary)",
    -1, sweep_main, NULL, NULL, NULL, NULL, NULL, NULL, NULL};
