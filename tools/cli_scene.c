/* cli_scene.c: the analyses a scene lists, prepared and run in order, for
 * `towstab run` and `towstab report` (cli.h). Every entry is read through
 * its analysis' option table and checked against the system before the
 * first one runs; the results are collected as one JSON document. */
#include <errno.h>
#include <getopt.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "towstab/report_result.h"

int cli_make_dir(const char *cmd, const char *opt, const char *dir)
{
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return 0;
        fprintf(stderr, "towstab: error: %s: %s: '%s' is not a directory\n",
                cmd, opt, dir);
        return EXIT_BADINPUT;
    }
    if (mkdir(dir, 0777) != 0) {
        fprintf(stderr, "towstab: error: %s: %s: cannot make '%s' (%s)\n",
                cmd, opt, dir, strerror(errno));
        return EXIT_FAILED;
    }
    return 0;
}

int cli_scene_args_parse(const char *cmd, int argc, char **argv,
                         const char *shortopts,
                         const struct option *longopts, void (*usage)(FILE *),
                         cli_scene_args *a)
{
    memset(a, 0, sizeof *a);
    optind = 1;
    opterr = 0;
    int ch;
    while ((ch = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
        switch (ch) {
        case 'j': a->json = optarg; break;
        case 'c': a->csv = optarg; break;
        case 'p': a->plot = optarg; break;
        case 'o': a->output = optarg; break;
        case 'u': a->units = optarg; break;
        case 'q': a->quiet = 1; break;
        case 'h': usage(stdout); return 0;
        case ':': return cli_option_error(cmd, ch, argv[optind - 1]);
        default:
            fprintf(stderr, "towstab: error: %s: unknown option '%s'; the "
                            "scene's analyses carry their own settings "
                            "(towstab %s --help)\n",
                    cmd, argv[optind - 1], cmd);
            return EXIT_BADINPUT;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: %s: expected one scene file\n", cmd);
        usage(stderr);
        return EXIT_BADINPUT;
    }
    a->scene = argv[optind];
    return -1;
}

void cli_scene_free(cli_scene_runs *s)
{
    for (int i = 0; s->runs && i < s->n; i++)
        cli_run_free(&s->runs[i]);
    free(s->runs);
    free(s->csv);
    free(s->dirs);
    free(s->wall_s);
    memset(s, 0, sizeof *s);
}

int cli_scene_prepare(const char *cmd, const ts_scene *scene,
                      const ts_units *units, int quiet, const char *csv_dir,
                      const char *plot_dir, const char *plot_units,
                      int plot_optional, cli_scene_runs *s)
{
    memset(s, 0, sizeof *s);
    int n = scene->nanalyses;
    if (n == 0) {
        fprintf(stderr, "towstab: error: %s: %s lists no analyses: nothing "
                        "to run (add an 'analyses' list)\n",
                cmd, scene->path);
        return EXIT_BADINPUT;
    }
    s->n = n;
    s->runs = calloc((size_t)n, sizeof *s->runs);
    s->csv = calloc((size_t)n, sizeof *s->csv);
    s->dirs = calloc((size_t)n, sizeof *s->dirs);
    s->wall_s = calloc((size_t)n, sizeof *s->wall_s);
    if (!s->runs || !s->csv || !s->dirs || !s->wall_s) {
        fprintf(stderr, "towstab: error: %s: out of memory for %d "
                        "analyses\n", cmd, n);
        cli_scene_free(s);
        return EXIT_FAILED;
    }
    char types[256] = "";
    for (int i = 0; cli_commands[i]; i++)
        if (cli_commands[i]->kind >= 0) {
            if (types[0])
                strncat(types, ", ", sizeof types - strlen(types) - 1);
            strncat(types, cli_commands[i]->name,
                    sizeof types - strlen(types) - 1);
        }
    ts_display display;
    int status = cli_display_begin(units, plot_units, &display);
    for (int i = 0; i < n && !status; i++) {
        const ts_scene_analysis *a = &scene->analyses[i];
        int kind = ts_analysis_find(a->type);
        const cli_command *c_cmd = kind >= 0 ? cli_command_of(kind) : NULL;
        if (!c_cmd) {
            ts_err err = {0};
            ts_fail(&err, TS_ESCENE, "%s: analyses[%d] (line %d): unknown "
                    "analysis type '%s'; expected one of %s",
                    scene->path, i, a->line, a->type, types);
            status = cli_report(&err, TS_ESCENE);
            break;
        }
        cli_run *c = &s->runs[i];
        c->cmd = c_cmd;
        c->scene = scene;
        c->units = units;
        c->entry = i;
        c->quiet = quiet;
        c->display = display;
        c->plot.opts.display = &c->display;
        if (csv_dir) {
            snprintf(s->csv[i], sizeof s->csv[i], "%s/%d_%s.csv", csv_dir,
                     i + 1, a->type);
            c->csv = s->csv[i];
        }
        if (plot_dir) {
            snprintf(s->dirs[i], sizeof s->dirs[i], "%s/%d_%s", plot_dir,
                     i + 1, a->type);
            c->plot.dir = s->dirs[i];
            c->plot.units = plot_units;
            c->plot_optional = plot_optional;
        }
        c->opts = cli_entry_options(scene, kind, i, &status);
        if (!status)
            status = cli_prepare(c);
    }
    if (status)
        cli_scene_free(s);
    return status;
}

int cli_scene_execute(const ts_scene *scene, cli_scene_runs *s,
                      json_t **all, ts_report_results *into)
{
    int status = 0;
    /* The results as trees only for a document of them held here;
     * streamed (into) or not asked for, the document is only the keys
     * after the list. */
    int trees = all && !into;
    json_t *doc = json_object(), *list = trees ? json_array() : NULL;
    if (!doc || (trees && !list) ||
        (trees && (json_object_set_new(doc, "scene",
                                       json_string(scene->system->name)) ||
                   json_object_set(doc, "analyses", list)))) {
        json_decref(doc);
        json_decref(list);
        fprintf(stderr, "towstab: error: out of memory for the results\n");
        if (all)
            *all = NULL;
        return EXIT_FAILED;
    }
    json_decref(list); /* the document holds it */
    const cli_run *last = NULL; /* the last that gave a result */
    for (int i = 0; i < s->n && !status; i++) {
        printf("%s== analysis %d of %d: %s (%s) ==\n", i ? "\n" : "", i + 1,
               s->n, scene->analyses[i].type, scene->system->name);
        json_t *j = NULL;
        double t0 = cli_wall_now();
        s->runs[i].into = into;
        status = cli_execute(&s->runs[i], trees ? &j : NULL);
        s->wall_s[i] = cli_wall_now() - t0;
        s->ran = i + 1;
        if (j)
            json_array_append_new(list, j);
        if (s->runs[i].added)
            last = &s->runs[i];
    }
    /* After a failure the results so far, marked as incomplete with the
     * failed analysis' message. */
    size_t nres = json_array_size(list);
    const char *msg = NULL;
    if (status && nres > 0)
        msg = json_string_value(json_object_get(
            json_array_get(list, nres - 1), "error"));
    else if (status && last && last->failed)
        msg = last->error;
    json_object_set_new(doc, "completed", json_boolean(status == 0));
    if (status) {
        json_object_set_new(doc, "error", json_string(msg ? msg : "failed"));
        json_object_set_new(doc, "trustworthy", json_false());
    }
    if (cli_stop_signal_name())
        json_object_set_new(doc, "interrupted",
                            json_string(cli_stop_signal_name()));
    if (all)
        *all = doc;
    else
        json_decref(doc);
    return status;
}
