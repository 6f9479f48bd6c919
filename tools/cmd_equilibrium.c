/* cmd_equilibrium.c: `towstab equilibrium SCENE` and the `equilibrium`
 * analysis of a scene. */
#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "towstab/report.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: towstab equilibrium SCENE [options]\n"
            "  steady shape at the scene's speed and turn rate\n"
            "  --json FILE      write the result as JSON ('-' for stdout)\n"
            "  --csv FILE       write the node table as CSV\n"
            "  --speed Q        override tow.speed (e.g. '5 knot', 2.5)\n"
            "  --turn-rate Q    override tow.turn_rate (e.g. '0.5 rad/s')\n"
            "  --links N        use N links on every cable\n"
            "  --method M       auto (default), shooting or newton\n"
            "  --tol X          relative force residual (default 1e-10)\n"
            "  --quiet          print the summary only, not the tables\n");
}

static int eq_main(int argc, char **argv)
{
    cli_settings s = {0};
    cli_settings_from_options(&s);
    const char *json_path = NULL, *csv_path = NULL;
    int quiet = 0;
    static const struct option longopts[] = {
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        {"speed", required_argument, NULL, 's'},
        {"turn-rate", required_argument, NULL, 'w'},
        {"links", required_argument, NULL, 'n'},
        {"method", required_argument, NULL, 'm'},
        {"tol", required_argument, NULL, 't'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    long v;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (ch) {
        case 'j': json_path = optarg; break;
        case 'c': csv_path = optarg; break;
        case 's': s.speed = optarg; break;
        case 'w': s.turn_rate = optarg; break;
        case 'm': s.method = optarg; break;
        case 't': s.tol = optarg; break;
        case 'q': quiet = 1; break;
        case 'h': usage(stdout); return 0;
        case 'n':
            if (cli_parse_int("--links", optarg, 1, 10000000, &v))
                return EXIT_BADINPUT;
            s.links = (int)v;
            break;
        case ':':
            fprintf(stderr, "towstab equilibrium: missing value for '%s'\n",
                    argv[optind - 1]);
            return EXIT_BADINPUT;
        default:
            fprintf(stderr, "towstab equilibrium: unknown option '%s' "
                            "(towstab equilibrium --help)\n",
                    argv[optind - 1]);
            return EXIT_BADINPUT;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab equilibrium: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    ts_err err = {0};
    ts_equilibrium_opts eo;
    ts_system *sys = cli_system(scene, units, &s, &eo, &err);
    if (!sys) {
        status = cli_report(&err, err.code);
        cli_close(units, scene);
        return status;
    }
    printf("towstab equilibrium: %s (%s)\n", sys->name, scene->path);
    ts_equilibrium *eq = NULL;
    json_t *json = NULL;
    int rc = cli_equilibrium(sys, &eo, quiet, &eq, json_path ? &json : NULL,
                             &err);
    if (rc)
        status = cli_report(&err, rc);
    ts_err werr = {0};
    if (json && cli_write_json(json, json_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    if (csv_path && eq && eq->converged &&
        ts_report_equilibrium_csv(sys, eq, csv_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    json_decref(json);
    ts_equilibrium_free(eq);
    ts_system_free(sys);
    cli_close(units, scene);
    return status;
}

static const char *const eq_keys[] = {"speed", "turn_rate", "method",
                                      "tolerance", "links", NULL};

static int eq_run(const cli_ctx *ctx, const ts_scene_analysis *a, int index,
                  json_t *results)
{
    ts_err err = {0};
    cli_settings s = {0};
    if (cli_settings_from_analysis(&s, a, index, &err))
        return cli_report(&err, err.code);
    ts_equilibrium_opts eo;
    ts_system *sys = cli_system(ctx->scene, ctx->units, &s, &eo, &err);
    if (!sys)
        return cli_report(&err, err.code);
    ts_equilibrium *eq = NULL;
    json_t *j = NULL;
    int rc = cli_equilibrium(sys, &eo, ctx->quiet, &eq, &j, &err);
    int status = rc ? cli_report(&err, rc) : 0;
    if (j) {
        json_object_set_new(j, "type", json_string("equilibrium"));
        json_array_append_new(results, j);
    }
    ts_equilibrium_free(eq);
    ts_system_free(sys);
    return status;
}

/* An entry's settings parse and its system builds. */
static int eq_check(const cli_ctx *ctx, const ts_scene_analysis *a, int index)
{
    ts_err err = {0};
    cli_settings s = {0};
    if (cli_settings_from_analysis(&s, a, index, &err))
        return cli_report(&err, err.code);
    ts_equilibrium_opts eo;
    ts_system *sys = cli_system(ctx->scene, ctx->units, &s, &eo, &err);
    if (!sys)
        return cli_report(&err, err.code);
    ts_system_free(sys);
    return 0;
}

const cli_command cli_cmd_equilibrium = {
    "equilibrium", "steady shape at the scene's speed and turn rate",
    eq_main, eq_run, eq_keys, eq_check};
