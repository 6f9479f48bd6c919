/* cmd_run.c: `towstab run SCENE`: the scene's analyses, in order. Every
 * entry is read through its analysis' option table and checked against
 * the system before the first one runs; only what is listed runs. With
 * --csv DIR and --plot DIR every analysis writes its own file set,
 * DIR/<k>_<type>.csv and DIR/<k>_<type>/ (k from 1). */
#include <errno.h>
#include <getopt.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "towstab/report_result.h"

/* Room for one file name under a DIR. */
#define RUN_PATH_MAX 1200

/* Make directory `dir` (one level) unless it exists; 0 or the status
 * after printing. */
static int make_dir(const char *opt, const char *dir)
{
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return 0;
        fprintf(stderr, "towstab: error: run: %s: '%s' is not a directory\n",
                opt, dir);
        return EXIT_BADINPUT;
    }
    if (mkdir(dir, 0777) != 0) {
        fprintf(stderr, "towstab: error: run: %s: cannot make '%s' (%s)\n",
                opt, dir, strerror(errno));
        return EXIT_FAILED;
    }
    return 0;
}

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
               "  --units U     units of the pictures: si or imperial\n"
               "  --quiet       print the summaries only\n");
}

static int run_main(int argc, char **argv)
{
    const char *json_path = NULL, *csv_dir = NULL, *plot_dir = NULL;
    const char *plot_units = NULL;
    int quiet = 0;
    static const struct option longopts[] = {
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        {"plot", required_argument, NULL, 'p'},
        {"units", required_argument, NULL, 'u'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (ch) {
        case 'j': json_path = optarg; break;
        case 'c': csv_dir = optarg; break;
        case 'p': plot_dir = optarg; break;
        case 'u': plot_units = optarg; break;
        case 'q': quiet = 1; break;
        case 'h': usage(stdout); return 0;
        case ':': return cli_option_error("run", ch, argv[optind - 1]);
        default:
            fprintf(stderr, "towstab: error: run: unknown option '%s'; the "
                            "scene's analyses carry their own settings "
                            "(towstab run --help)\n",
                    argv[optind - 1]);
            return EXIT_BADINPUT;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: run: expected one scene file\n");
        return EXIT_BADINPUT;
    }
    const char *given[3] = {json_path, csv_dir, plot_dir};
    static const char *const opt[3] = {"--json", "--csv", "--plot"};
    for (int k = 0; k < 3; k++)
        if (given[k] && !given[k][0]) {
            fprintf(stderr, "towstab: error: run: %s: expected a %s name, "
                            "got an empty one\n",
                    opt[k], k ? "directory" : "file");
            return EXIT_BADINPUT;
        }
    if (plot_units && !plot_dir) {
        fprintf(stderr, "towstab: error: run: --units sets the units of the "
                        "--plot pictures; add --plot DIR\n");
        return EXIT_BADINPUT;
    }
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    int n = scene->nanalyses;
    if (n == 0) {
        fprintf(stderr, "towstab: error: run: %s lists no analyses: nothing "
                        "to run (add an 'analyses' list)\n",
                scene->path);
        cli_close(units, scene);
        return EXIT_BADINPUT;
    }
    cli_run *runs = calloc((size_t)n, sizeof *runs);
    char (*csv)[RUN_PATH_MAX] = calloc((size_t)n, sizeof *csv);
    char (*dirs)[RUN_PATH_MAX] = calloc((size_t)n, sizeof *dirs);
    const char **what = calloc((size_t)n + 1, sizeof *what);
    const char **paths = calloc((size_t)n + 1, sizeof *paths);
    if (!runs || !csv || !dirs || !what || !paths) {
        fprintf(stderr, "towstab: error: run: out of memory for %d "
                        "analyses\n", n);
        status = EXIT_FAILED;
    }
    char types[256] = "";
    for (int i = 0; cli_commands[i]; i++)
        if (cli_commands[i]->kind >= 0) {
            if (types[0])
                strncat(types, ", ", sizeof types - strlen(types) - 1);
            strncat(types, cli_commands[i]->name,
                    sizeof types - strlen(types) - 1);
        }
    /* Every entry is read and checked before the first runs. */
    for (int i = 0; i < n && !status; i++) {
        const ts_scene_analysis *a = &scene->analyses[i];
        int kind = ts_analysis_find(a->type);
        const cli_command *cmd = kind >= 0 ? cli_command_of(kind) : NULL;
        if (!cmd) {
            ts_err err = {0};
            ts_fail(&err, TS_ESCENE, "%s: analyses[%d] (line %d): unknown "
                    "analysis type '%s'; expected one of %s",
                    scene->path, i, a->line, a->type, types);
            status = cli_report(&err, TS_ESCENE);
            break;
        }
        cli_run *c = &runs[i];
        c->cmd = cmd;
        c->scene = scene;
        c->units = units;
        c->entry = i;
        c->quiet = quiet;
        if (csv_dir) {
            snprintf(csv[i], sizeof csv[i], "%s/%d_%s.csv", csv_dir, i + 1,
                     a->type);
            c->csv = csv[i];
            what[i] = "--csv";
            paths[i] = csv[i];
        }
        if (plot_dir) {
            snprintf(dirs[i], sizeof dirs[i], "%s/%d_%s", plot_dir, i + 1,
                     a->type);
            c->plot.dir = dirs[i];
            c->plot.units = plot_units;
        }
        c->opts = cli_entry_options(scene, kind, i, &status);
        if (!status)
            status = cli_prepare(c);
    }
    what[n] = "--json";
    paths[n] = json_path;
    if (!status)
        status = cli_check_outputs("run", n + 1, what, paths, NULL, NULL);
    if (!status && csv_dir)
        status = make_dir("--csv", csv_dir);
    if (!status && plot_dir)
        status = make_dir("--plot", plot_dir);
    for (int i = 0; i < n && !status && plot_dir; i++)
        status = cli_plot_begin(&runs[i].plot, "run");
    json_t *all = json_object(), *list = json_array();
    json_object_set_new(all, "scene", json_string(scene->system->name));
    json_object_set_new(all, "analyses", list);
    int ran = 0;
    for (int i = 0; i < n && !status; i++) {
        printf("%s== analysis %d of %d: %s (%s) ==\n", i ? "\n" : "", i + 1,
               n, scene->analyses[i].type, scene->system->name);
        json_t *j = NULL;
        status = cli_execute(&runs[i], &j);
        ran = 1;
        if (j)
            json_array_append_new(list, j);
    }
    /* After a failure the results so far, marked as incomplete with the
     * failed analysis' message; nothing after bad input found before the
     * first run. */
    if (json_path &&
        (status == 0 || (ran && status != EXIT_BADINPUT))) {
        size_t nres = json_array_size(list);
        const char *msg = status && nres > 0
                              ? json_string_value(json_object_get(
                                    json_array_get(list, nres - 1), "error"))
                              : NULL;
        json_object_set_new(all, "completed", json_boolean(status == 0));
        if (status) {
            json_object_set_new(all, "error", json_string(msg ? msg
                                                              : "failed"));
            json_object_set_new(all, "trustworthy", json_false());
        }
        if (cli_stop_signal_name())
            json_object_set_new(all, "interrupted",
                                json_string(cli_stop_signal_name()));
        ts_err werr = {0};
        if (cli_write_json(all, json_path, &werr) != TS_OK) {
            int st = cli_report(&werr, werr.code);
            status = status ? status : st;
        }
    }
    json_decref(all);
    for (int i = 0; runs && i < n; i++)
        cli_run_free(&runs[i]);
    free(runs);
    free(csv);
    free(dirs);
    free(what);
    free(paths);
    cli_close(units, scene);
    return status;
}

const cli_command cli_cmd_run = {"run", "the analyses the scene lists, in order",
                                 -1, run_main, NULL, NULL, NULL, NULL, NULL,
                                 NULL};
