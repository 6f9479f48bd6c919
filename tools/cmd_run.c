/* cmd_run.c: `towstab run SCENE`: the scene's analyses, in order. Every
 * entry is read through its analysis' option table and checked against
 * the system before the first one runs; only what is listed runs. With
 * --csv DIR and --plot DIR every analysis writes its own file set,
 * DIR/<k>_<type>.csv and DIR/<k>_<type>/ (k from 1). */
#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: towstab run SCENE [--json FILE] [--csv DIR] "
               "[--plot DIR] [--units U] [--quiet]\n"
               "  runs the scene's 'analyses' list in order, each with its "
               "own settings\n"
               "  --json FILE   every result as one JSON document ('-' for "
               "standard output)\n"
               "  --csv DIR     each analysis' table as DIR/<k>_<type>.csv\n"
               "  --plot DIR    each analysis' pictures in DIR/<k>_<type>/\n"
               "  --units U     units of tables, CSV and pictures: si, "
               "imperial or items\n"
               "                like speed=knot,force=kN\n"
               "  --quiet       print the summaries only\n");
}

static int run_main(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        {"plot", required_argument, NULL, 'p'},
        {"units", required_argument, NULL, 'u'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    cli_scene_args a;
    int st = cli_scene_args_parse("run", argc, argv, ":", longopts, usage, &a);
    if (st >= 0)
        return st;
    const char *json_path = a.json, *csv_dir = a.csv, *plot_dir = a.plot;
    const char *given[3] = {json_path, csv_dir, plot_dir};
    static const char *const opt[3] = {"--json", "--csv", "--plot"};
    for (int k = 0; k < 3; k++)
        if (given[k] && !given[k][0]) {
            fprintf(stderr, "towstab: error: run: %s: expected a %s name, "
                            "got an empty one\n",
                    opt[k], k ? "directory" : "file");
            return EXIT_BADINPUT;
        }
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(a.scene, &units, &scene);
    if (status)
        return status;
    cli_scene_runs s;
    status = cli_scene_prepare("run", scene, units, a.quiet, csv_dir,
                               plot_dir, a.units, 0, &s);
    if (status) {
        cli_close(units, scene);
        return status;
    }
    int n = s.n;
    const char **what = calloc((size_t)n + 1, sizeof *what);
    const char **paths = calloc((size_t)n + 1, sizeof *paths);
    if (!what || !paths) {
        fprintf(stderr, "towstab: error: run: out of memory for %d "
                        "analyses\n", n);
        status = EXIT_FAILED;
    }
    for (int i = 0; i < n && !status; i++) {
        what[i] = "--csv";
        paths[i] = s.runs[i].csv;
    }
    if (!status) {
        what[n] = "--json";
        paths[n] = json_path;
        status = cli_check_outputs("run", n + 1, what, paths, NULL, NULL);
    }
    if (!status && csv_dir)
        status = cli_make_dir("run", "--csv", csv_dir);
    if (!status && plot_dir)
        status = cli_make_dir("run", "--plot", plot_dir);
    for (int i = 0; i < n && !status && plot_dir; i++)
        status = cli_plot_begin(&s.runs[i].plot, "run");
    if (!status) {
        /* The results are written as they come; nothing reaches the
         * file before the last (ts_report_results). A target that cannot
         * be opened is reported after the run, as a write is. */
        ts_err werr = {0};
        FILE *stream = NULL;
        ts_report_results *doc =
            json_path ? cli_results_open(json_path, scene->system->name,
                                         &stream, &werr)
                      : NULL;
        json_t *tail = NULL;
        status = cli_scene_execute(scene, &s, doc ? &tail : NULL, doc);
        /* After a failure the results so far, marked as incomplete with
         * the failed analysis' message; nothing after bad input. */
        if (json_path && (!doc || (tail && status != EXIT_BADINPUT))) {
            if (!doc || cli_results_close(doc, stream, tail, &werr) !=
                            TS_OK) {
                int st = cli_report(&werr, werr.code);
                status = status ? status : st;
            }
        } else if (doc) {
            ts_report_results_abandon(doc);
            if (stream)
                fclose(stream);
        }
        json_decref(tail);
    }
    free(what);
    free(paths);
    cli_scene_free(&s);
    cli_close(units, scene);
    return status;
}

const cli_command cli_cmd_run = {"run", "the analyses the scene lists, in order",
                                 -1, run_main, NULL, NULL, NULL, NULL, NULL,
                                 NULL, NULL};
