/* cmd_run.c: `towstab run SCENE`: the scene's analyses, in order. Every
 * entry is checked before the first one runs; only what is listed runs. */
#include <getopt.h>
#include <string.h>

#include "cli.h"
#include "towstab/report.h"

static const cli_command *find(const char *type)
{
    for (int i = 0; cli_commands[i]; i++)
        if (cli_commands[i]->entry && strcmp(cli_commands[i]->name, type) == 0)
            return cli_commands[i];
    return NULL;
}

static int run_main(int argc, char **argv)
{
    const char *json_path = NULL;
    int quiet = 0;
    static const struct option longopts[] = {
        {"json", required_argument, NULL, 'j'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (ch) {
        case 'j': json_path = optarg; break;
        case 'q': quiet = 1; break;
        case 'h':
            printf("usage: towstab run SCENE [--json FILE] [--quiet]\n"
                   "  runs the scene's 'analyses' list in order\n");
            return 0;
        case ':':
            return cli_option_error("run", ch, argv[optind - 1]);
        default:
            fprintf(stderr, "towstab: error: run: unknown option '%s'; only "
                            "--json and --quiet apply (the scene's analyses "
                            "carry their own settings)\n",
                    argv[optind - 1]);
            return EXIT_BADINPUT;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: run: expected one scene file\n");
        return EXIT_BADINPUT;
    }
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    ts_err err = {0};
    if (scene->nanalyses == 0) {
        fprintf(stderr, "towstab: error: run: %s lists no analyses: nothing "
                        "to run (add an 'analyses' list)\n",
                scene->path);
        cli_close(units, scene);
        return EXIT_BADINPUT;
    }
    char types[256] = "";
    for (int i = 0; cli_commands[i]; i++)
        if (cli_commands[i]->entry) {
            if (types[0])
                strncat(types, ", ", sizeof types - strlen(types) - 1);
            strncat(types, cli_commands[i]->name,
                    sizeof types - strlen(types) - 1);
        }
    for (int i = 0; i < scene->nanalyses && !status; i++) {
        const ts_scene_analysis *a = &scene->analyses[i];
        const cli_command *c = find(a->type);
        if (!c) {
            ts_fail(&err, TS_ESCENE,
                    "analyses[%d] (line %d): unknown analysis type '%s'; "
                    "expected one of %s",
                    i, a->line, a->type, types);
            status = cli_report(&err, TS_ESCENE);
        } else if (cli_check_keys(a, c->keys, i, &err)) {
            status = cli_report(&err, err.code);
        } else {
            cli_ctx cctx = {scene, units, quiet};
            status = c->entry(&cctx, a, i, NULL);
        }
    }
    json_t *all = json_object(), *list = json_array();
    json_object_set_new(all, "scene", json_string(scene->system->name));
    json_object_set_new(all, "analyses", list);
    cli_ctx ctx = {scene, units, quiet};
    for (int i = 0; i < scene->nanalyses && !status; i++) {
        const ts_scene_analysis *a = &scene->analyses[i];
        printf("%s== analysis %d of %d: %s (%s) ==\n", i ? "\n" : "", i + 1,
               scene->nanalyses, a->type, scene->system->name);
        json_t *j = NULL;
        status = find(a->type)->entry(&ctx, a, i, &j);
        if (j) {
            json_object_set_new(j, "type", json_string(a->type));
            json_array_append_new(list, j);
        }
    }
    /* After a failure the results so far, marked as incomplete with the
     * failed analysis' message; nothing after bad input. */
    const char *msg = NULL;
    size_t nres = json_array_size(list);
    if (status && nres > 0)
        msg = json_string_value(
            json_object_get(json_array_get(list, nres - 1), "error"));
    status = cli_write_result(all, json_path, status, msg);
    json_decref(all);
    cli_close(units, scene);
    return status;
}

const cli_command cli_cmd_run = {"run", "the analyses the scene lists, in order",
                                 run_main, NULL, NULL};
