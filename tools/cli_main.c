/* cli_main.c: parse -> run -> print for every analysis command (cli.h).
 *
 * The command line of `towstab KIND` is made from the analysis' option
 * table (towstab/options.h): every row is --name (with '-' for '_'), a
 * boolean also --no-name; then the outputs (--json, --csv, --plot,
 * --units, --quiet) and the command's extras. Options not given on the
 * command line come from the scene's first entry of the command's type,
 * else their defaults (one precedence rule; a convergence study of a
 * simulation also takes the scene's first simulate entry, below its own).
 * The library checks the request against the system before anything
 * runs, runs the pipeline, and the command prints the result and writes
 * its files. */
#include "cli.h"

#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "towstab/report_result.h"

/* getopt codes: table rows, their --no- forms, the extras. */
enum { CODE_ROW = 1000, CODE_NO = 2000, CODE_EXTRA = 3000 };

static int nextras(const cli_command *cmd)
{
    int n = 0;
    while (cmd->extras && cmd->extras[n].name && n < CLI_EXTRA_MAX)
        n++;
    return n;
}

void cli_usage(const cli_command *cmd, FILE *f)
{
    int n;
    const ts_option *t = ts_options(cmd->kind, &n);
    fprintf(f, "usage: towstab %s SCENE [options]\n  %s\n", cmd->name,
            cmd->summary);
    fprintf(f, "options (also keys of the scene's '%s' entries; a plain "
               "number is SI):\n", cmd->name);
    for (int i = 0; i < n; i++) {
        char name[TS_NAME_MAX], def[128], lim[256], left[2 * TS_NAME_MAX + 16];
        ts_option_cli_name(&t[i], name, sizeof name);
        ts_option_default_text(&t[i], cmd->kind, def, sizeof def);
        ts_option_limits_text(&t[i], lim, sizeof lim);
        if (t[i].type == TS_OPT_BOOL)
            snprintf(left, sizeof left, "--%s, --no-%s", name, name);
        else
            snprintf(left, sizeof left, "--%s %s", name, t[i].arg);
        fprintf(f, "  %-26s %s", left, t[i].help);
        if (def[0] && t[i].type != TS_OPT_BOOL)
            fprintf(f, " [default %s]", def);
        if (lim[0] && !t[i].choices)
            fprintf(f, " (%s)", lim);
        if (t[i].flags & TS_OPT_REPEAT)
            fprintf(f, " (repeatable)");
        fprintf(f, "\n");
    }
    fprintf(f, "outputs:\n"
               "  %-26s %s\n  %-26s %s\n  %-26s %s\n  %-26s %s\n  %-26s %s\n",
            "--json FILE", "the result as JSON ('-' for standard output)",
            "--csv FILE", "the result's table as CSV", "--plot DIR",
            "draw the pictures into DIR (created)", "--units U",
            "units of tables, CSV and pictures: si (default), imperial, "
            "or items like speed=knot,force=kN", "--quiet",
            "print the summary only");
    for (int k = 0; k < nextras(cmd); k++) {
        char left[96];
        snprintf(left, sizeof left, "--%s%s%s", cmd->extras[k].name,
                 cmd->extras[k].has_arg ? " " : "",
                 cmd->extras[k].has_arg ? cmd->extras[k].arg : "");
        fprintf(f, "  %-26s %s\n", left, cmd->extras[k].help);
    }
}

void cli_options_markdown(FILE *f)
{
    for (int k = 0; k < TS_ANALYSIS_COUNT; k++) {
        int n;
        const ts_option *t = ts_options(k, &n);
        fprintf(f, "### Options of %s\n\n", ts_analysis_name(k));
        fprintf(f, "| option | scene key | unit | default | range | "
                   "meaning |\n|---|---|---|---|---|---|\n");
        for (int i = 0; i < n; i++) {
            char name[TS_NAME_MAX], def[128], lim[256];
            ts_option_cli_name(&t[i], name, sizeof name);
            ts_option_default_text(&t[i], k, def, sizeof def);
            ts_option_limits_text(&t[i], lim, sizeof lim);
            fprintf(f, "| `--%s`%s | `%s` | %s | %s | %s | %s%s%s |\n", name,
                    t[i].type == TS_OPT_BOOL ? ", `--no-` form" : "",
                    t[i].name,
                    t[i].type == TS_OPT_QUANTITY ? t[i].unit : "",
                    def[0] ? def : "see meaning", lim[0] ? lim : "",
                    t[i].help,
                    t[i].flags & TS_OPT_REPEAT ? "; repeatable" : "",
                    t[i].only ? (t[i].only - 1 == TS_ANALYSIS_MODES
                                     ? " (a study of modes)"
                                     : " (a study of simulate)")
                              : "");
        }
        fprintf(f, "\n");
    }
}

ts_optset *cli_entry_options(const ts_scene *scene, int kind, int index,
                             int *status)
{
    ts_err err = {0};
    ts_optset *o = ts_optset_alloc(kind, &err);
    int rc = o ? ts_optset_give_scene(o, scene, index, &err) : TS_ENOMEM;
    if (rc) {
        *status = cli_report(&err, rc);
        ts_optset_free(o);
        return NULL;
    }
    *status = 0;
    return o;
}

int cli_prepare(cli_run *c)
{
    ts_err err = {0};
    char notes[TS_OPTSET_NOTES_MAX];
    int rc = ts_optset_request(c->opts, c->scene->system, c->units, &c->rq,
                               notes, sizeof notes, &err);
    /* A scene value that the command line's values contradict (and that
     * is fine without them) yielded to its default. */
    for (char *line = notes; *line;) {
        char *end = strchr(line, '\n');
        printf("note: %.*s; with the command line's options this scene "
               "value does not hold, so its default is used\n",
               end ? (int)(end - line) : (int)strlen(line), line);
        line = end ? end + 1 : line + strlen(line);
    }
    if (rc)
        return cli_report(&err, rc);
    /* tow.speed or tow.turn_rate set on a towing vehicle's scene: the
     * start of the solve it is in the scene file, so it runs, with a
     * word that the value is not the run's (doc/manual.md). */
    for (int i = 0; i < c->rq.setup.nsets; i++) {
        ts_err w = {0};
        const char *path = c->rq.setup.sets[i].path;
        if (ts_param_solved(c->scene->system, path, "the run's solve "
                            "starts there and ends at the solved value",
                            strcmp(path, "tow.speed") ? "to change the turn "
                            "rate, set" : "to change the speed, set", &w))
            fprintf(stderr, "towstab: warning: set: %s\n", w.msg);
    }
    /* Long runs poll SIGINT and SIGTERM and show their progress. */
    c->rq.progress = cli_progress;
    return c->cmd->prepare ? c->cmd->prepare(c) : 0;
}

/* A failed run writes its JSON and CSV when it has a result of its own
 * kind to show (an equilibrium that did not converge, the history so far,
 * the runs of a study stopped on request, the equilibrium and linear
 * model of modes or a response stopped on request). */
static int has_partial(const ts_result *r)
{
    return (r->kind == TS_ANALYSIS_EQUILIBRIUM && r->eq_attempted) ||
           ((r->kind == TS_ANALYSIS_MODES ||
             r->kind == TS_ANALYSIS_RESPONSE) &&
            r->status == TS_ECANCEL && r->eq_attempted) ||
           (r->kind == TS_ANALYSIS_SIMULATE && (r->nonlinear || r->linear)) ||
           (r->kind == TS_ANALYSIS_CONVERGE && r->status == TS_ECANCEL &&
            r->convergence && r->convergence->estimated);
}

/* A run estimated to take longer than this (s) is announced first, with
 * what would shorten it (towstab/cost.h). */
#define ANNOUNCE_S 60.0

int cli_execute(cli_run *c, json_t **result)
{
    if (c->cmd->execute)
        return c->cmd->execute(c);
    ts_err err = {0};
    ts_result *r = NULL;
    ts_cost cost;
    if (ts_analysis_cost(c->scene->system, &c->rq, &cost, NULL) == TS_OK &&
        cost.seconds > ANNOUNCE_S) {
        /* Every analysis keeps what it has when stopped (the
         * equilibrium reached, the linear model, the history, the runs
         * of a study). */
        fprintf(stderr, "towstab: warning: %s is estimated to take %s; to "
                        "shorten it: %s (Ctrl-C stops it, keeping what it "
                        "has)\n",
                ts_analysis_name(c->rq.kind), cost.what, cost.reduce);
        fflush(stderr);
    }
    int rc = ts_analysis_run(c->scene->system, &c->rq, &r, &err);
    cli_progress_done();
    if (!r)
        return cli_report(&err, rc);
    c->cmd->print(c, r);
    int status = 0;
    if (rc != TS_OK) {
        ts_optset_locate(c->opts, &err);
        status = cli_report(&err, rc);
        /* The JSON gives the reason standard error gave (the option and
         * the scene file located in it). */
        snprintf(r->error, sizeof r->error, "%s", err.msg);
    }
    ts_err werr = {0};
    int write = status == 0 || has_partial(r);
    json_t *extra = NULL;
    if (c->into) {
        /* `towstab run --json`: added to the document as it comes. */
        extra = json_object();
        if (extra && cli_stop_signal_name())
            json_object_set_new(extra, "interrupted",
                                json_string(cli_stop_signal_name()));
        c->added = 1;
        c->failed = r->status != TS_OK;
        snprintf(c->error, sizeof c->error, "%s", r->error);
        if (ts_report_results_add(c->into, r, c->json_flags, extra,
                                  &werr) != TS_OK) {
            int st = cli_report(&werr, werr.code);
            status = status ? status : st;
        }
        json_decref(extra);
    } else if (c->json && write && !result) {
        /* Streamed: the node and link arrays are never held whole. */
        extra = json_object();
        if (extra && cli_stop_signal_name())
            json_object_set_new(extra, "interrupted",
                                json_string(cli_stop_signal_name()));
        if (cli_write_result(r, c->json_flags, extra, c->json, &werr) !=
            TS_OK) {
            int st = cli_report(&werr, werr.code);
            status = status ? status : st;
        }
        json_decref(extra);
    } else if ((c->json && write) || result) {
        json_t *j = ts_report_result_json(r, c->json_flags);
        if (j && cli_stop_signal_name())
            json_object_set_new(j, "interrupted",
                                json_string(cli_stop_signal_name()));
        if (!j) {
            ts_fail(&werr, TS_ENOMEM, "%s: out of memory for the JSON",
                    c->json ? c->json : ts_analysis_name(r->kind));
            status = status ? status : cli_report(&werr, werr.code);
        } else if (c->json && write &&
                   cli_write_json(j, c->json, &werr) != TS_OK) {
            int st = cli_report(&werr, werr.code);
            status = status ? status : st;
        }
        if (result)
            *result = j;
        else
            json_decref(j);
    }
    if (c->csv && write && (status == 0 || has_partial(r)) &&
        ts_report_result_csv_display(r, &c->display, c->csv, &werr) !=
            TS_OK) {
        int st = cli_report(&werr, werr.code);
        status = status ? status : st;
    }
    if (c->cmd->draw) {
        int st = c->cmd->draw(c, r);
        status = status ? status : st;
    }
    ts_result_free(r);
    return status;
}

/* Keep "--name=value" (or "--name") of an option given. */
static void keep_given(cli_run *c, const char *name, const char *value)
{
    char **g = realloc(c->given, (size_t)(c->ngiven + 1) * sizeof *g);
    if (!g)
        return;
    c->given = g;
    size_t n = strlen(name) + (value ? strlen(value) : 0) + 4;
    g[c->ngiven] = malloc(n);
    if (!g[c->ngiven])
        return;
    snprintf(g[c->ngiven], n, "--%s%s%s", name, value ? "=" : "",
             value ? value : "");
    c->ngiven++;
}

static void free_given(cli_run *c)
{
    for (int i = 0; i < c->ngiven; i++)
        free(c->given[i]);
    free(c->given);
    c->given = NULL;
    c->ngiven = 0;
}

void cli_run_free(cli_run *c)
{
    free_given(c);
    if (c->cmd && c->cmd->release)
        c->cmd->release(c);
    ts_request_clear(&c->rq);
    ts_optset_free(c->opts);
    c->opts = NULL;
}

int cli_main(const cli_command *cmd, int argc, char **argv)
{
    int n;
    const ts_option *t = ts_options(cmd->kind, &n);
    int ne = nextras(cmd);
    struct option *lo = calloc((size_t)(2 * n + ne + 8), sizeof *lo);
    char (*names)[TS_NAME_MAX + 3] = calloc((size_t)(2 * n),
                                            sizeof *names);
    ts_err err = {0};
    ts_optset *opts = ts_optset_alloc(cmd->kind, &err);
    if (!lo || !names || !opts) {
        free(lo);
        free(names);
        ts_optset_free(opts);
        return cli_report(&err, ts_fail(&err, TS_ENOMEM, "out of memory"));
    }
    int m = 0;
    for (int i = 0; i < n; i++) {
        ts_option_cli_name(&t[i], names[2 * i], TS_NAME_MAX);
        int flag = t[i].type == TS_OPT_BOOL;
        lo[m++] = (struct option){names[2 * i],
                                  flag ? no_argument : required_argument,
                                  NULL, CODE_ROW + i};
        if (flag) {
            snprintf(names[2 * i + 1], TS_NAME_MAX + 3, "no-%s",
                     names[2 * i]);
            lo[m++] = (struct option){names[2 * i + 1], no_argument, NULL,
                                      CODE_NO + i};
        }
    }
    for (int k = 0; k < ne; k++)
        lo[m++] = (struct option){cmd->extras[k].name,
                                  cmd->extras[k].has_arg ? required_argument
                                                         : no_argument,
                                  NULL, CODE_EXTRA + k};
    static const struct option common[] = {
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        {"plot", required_argument, NULL, 'p'},
        {"units", required_argument, NULL, 'u'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'}};
    for (size_t k = 0; k < sizeof common / sizeof common[0]; k++)
        lo[m++] = common[k];
    cli_run c;
    memset(&c, 0, sizeof c);
    c.cmd = cmd;
    c.opts = opts;
    c.entry = -1;
    int status = 0;
    optind = 1;
    opterr = 0;
    int ch;
    while (!status && (ch = getopt_long(argc, argv, ":", lo, NULL)) != -1) {
        char where[TS_NAME_MAX + 8];
        if (ch >= CODE_ROW && ch < CODE_ROW + n) {
            int i = ch - CODE_ROW;
            snprintf(where, sizeof where, "--%s", names[2 * i]);
            keep_given(&c, names[2 * i], optarg);
            if (ts_optset_give(opts, t[i].name, optarg ? optarg : "true",
                               TS_OPTSET_COMMAND, where, &err))
                status = cli_report(&err, err.code);
        } else if (ch >= CODE_NO && ch < CODE_NO + n) {
            int i = ch - CODE_NO;
            snprintf(where, sizeof where, "--no-%s", names[2 * i]);
            keep_given(&c, names[2 * i + 1], NULL);
            if (ts_optset_give(opts, t[i].name, "false", TS_OPTSET_COMMAND,
                               where, &err))
                status = cli_report(&err, err.code);
        } else if (ch >= CODE_EXTRA && ch < CODE_EXTRA + ne) {
            int k = ch - CODE_EXTRA;
            if (c.nextra[k] > 0 && !cmd->extras[k].repeat)
                c.nextra[k] = 0; /* the last one counts */
            if (c.nextra[k] == CLI_EXTRA_VALUES) {
                fprintf(stderr, "towstab: error: %s: --%s: at most %d\n",
                        cmd->name, cmd->extras[k].name, CLI_EXTRA_VALUES);
                status = EXIT_BADINPUT;
            } else {
                c.extra[k][c.nextra[k]++] = optarg ? optarg : "";
                keep_given(&c, cmd->extras[k].name, optarg);
            }
        } else {
            switch (ch) {
            case 'j': c.json = optarg; break;
            case 'c': c.csv = optarg; break;
            case 'p': c.plot.dir = optarg; break;
            case 'u': c.plot.units = optarg; break;
            case 'q': c.quiet = 1; break;
            case 'h':
                cli_usage(cmd, stdout);
                status = -1;
                break;
            default:
                status = cli_option_error(cmd->name, ch, argv[optind - 1]);
            }
        }
    }
    free(lo);
    free(names);
    if (status) {
        ts_optset_free(opts);
        free_given(&c);
        return status < 0 ? 0 : status;
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: %s: expected one scene file\n",
                cmd->name);
        cli_usage(cmd, stderr);
        ts_optset_free(opts);
        free_given(&c);
        return EXIT_BADINPUT;
    }
    /* Outputs naming one file are refused before anything runs. */
    const char *what[2 + CLI_EXTRA_MAX] = {"--json", "--csv"};
    const char *paths[2 + CLI_EXTRA_MAX] = {c.json, c.csv};
    char ewhat[CLI_EXTRA_MAX][TS_NAME_MAX + 3];
    int nw = 2;
    for (int k = 0; k < ne; k++)
        if (cmd->extras[k].has_arg && c.nextra[k] > 0 &&
            !strcmp(cmd->extras[k].arg, "FILE")) {
            snprintf(ewhat[k], sizeof ewhat[k], "--%s", cmd->extras[k].name);
            what[nw] = ewhat[k];
            paths[nw++] = c.extra[k][0];
        }
    status = cli_check_outputs(cmd->name, nw, what, paths, c.plot.dir,
                               cmd->pictures);
    ts_units *units = NULL;
    ts_scene *scene = NULL;
    if (!status)
        status = cli_open(argv[optind], &units, &scene);
    /* --units before --plot makes its directory. */
    if (!status)
        status = cli_display_begin(units, c.plot.units, &c.display);
    if (!status)
        status = cli_plot_begin(&c.plot, cmd->name);
    if (status) {
        cli_plot_abandon(&c.plot);
        ts_optset_free(opts);
        free_given(&c);
        cli_close(units, scene);
        return status;
    }
    c.scene = scene;
    c.units = units;
    c.plot.opts.display = &c.display;
    /* Below the command line: the scene's first entry of this type. */
    int rc = ts_optset_give_scene(opts, scene, -1, &err);
    status = rc ? cli_report(&err, rc) : cli_prepare(&c);
    if (!status) {
        /* A simulation names itself with its settings (its print). */
        if (cmd->kind != TS_ANALYSIS_SIMULATE)
            printf("towstab %s: %s (%s)\n", cmd->name, scene->system->name,
                   scene->path);
        status = cli_execute(&c, NULL);
    }
    if (status)
        cli_plot_abandon(&c.plot);
    cli_run_free(&c);
    cli_close(units, scene);
    return status;
}
