/* cmd_equilibrium.c: `towstab equilibrium SCENE` and the `equilibrium`
 * analysis of a scene.
 *
 * Pictures (--plot DIR): side and top views of the cable (side.png/svg,
 * top.png/svg), with overlays of other speeds, turn rates or scenes
 * solved with the same settings (doc/plots.md). */
#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "towstab/kernel.h"
#include "towstab/report.h"

/* At most this many overlay curves (speeds, turn rates and scenes). */
#define MAX_OVERLAYS 8
#define ITEM_MAX 128

/* One curve of the pictures: a system and its equilibrium (owned). */
typedef struct eq_curve {
    ts_system *sys;
    ts_equilibrium *eq;
    ts_scene *scene;   /* an --overlay scene (owned), else NULL */
    ts_equilibrium_opts eo;
    char what[ITEM_MAX + 64];
} eq_curve;

/* Split "2,4,6 knot" into items; items without a unit take the unit of
 * the last item ("2 knot", "4 knot", "6 knot"). Returns the number of
 * items, or -1 after printing a message. */
static int split_list(const char *opt, const char *text,
                      char items[][ITEM_MAX], int max)
{
    char buf[MAX_OVERLAYS * ITEM_MAX];
    if (strlen(text) >= sizeof buf) {
        fprintf(stderr, "towstab: error: equilibrium: %s: list too long\n", opt);
        return -1;
    }
    strcpy(buf, text);
    int n = 0;
    /* Split at every comma (an empty item is an error, unlike strtok). */
    for (char *tok = buf, *next; tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        while (*tok == ' ')
            tok++;
        size_t len = strlen(tok);
        while (len > 0 && tok[len - 1] == ' ')
            tok[--len] = '\0';
        if (len == 0 || len >= ITEM_MAX || n == max) {
            fprintf(stderr, "towstab: error: equilibrium: %s: expected 1 to %d "
                            "comma-separated values like '2,4,6 knot', got "
                            "'%s'\n",
                    opt, max, text);
            return -1;
        }
        strcpy(items[n++], tok);
    }
    if (n == 0) {
        fprintf(stderr, "towstab: error: equilibrium: %s: expected values like "
                        "'2,4,6 knot', got '%s'\n",
                opt, text);
        return -1;
    }
    /* The unit of the last item, if any: the text after its number. */
    char *end;
    strtod(items[n - 1], &end);
    while (*end == ' ')
        end++;
    for (int i = 0; *end && i < n - 1; i++) {
        char *e;
        strtod(items[i], &e);
        while (*e == ' ')
            e++;
        if (*e == '\0' && strlen(items[i]) + strlen(end) + 2 < ITEM_MAX) {
            strcat(items[i], " ");
            strcat(items[i], end);
        }
    }
    return n;
}

/* Build the system of an overlay (settings validated now, before any
 * analysis runs). Returns 0 or the exit status after printing. */
static int overlay_system(eq_curve *c, const ts_scene *scene,
                          const ts_units *units, const cli_settings *s)
{
    ts_err err = {0};
    c->sys = cli_system(scene, units, s, &c->eo, &err);
    if (!c->sys) {
        ts_err_prefix(&err, "%s: ", c->what);
        return cli_report(&err, err.code);
    }
    return 0;
}

/* Solve an overlay's equilibrium and print one line. Returns the exit
 * status (0 when converged). */
static int overlay_solve(eq_curve *c)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(c->sys, &err);
    c->eq = k ? ts_equilibrium_alloc(c->sys, &err) : NULL;
    int rc = c->eq ? ts_equilibrium_solve(k, &c->eo, c->eq, &err)
                   : (err.code ? err.code : TS_ENOMEM);
    ts_kernel_free(k);
    if (rc != TS_OK) {
        ts_err_prefix(&err, "%s: ", c->what);
        return cli_report(&err, rc);
    }
    printf("overlay %s: converged (%s), top tension %.6f N\n", c->what,
           ts_eq_method_name(c->eq->method), c->eq->top_tension);
    return 0;
}

/* "a", "a and b", "a, b and c" of the distinct scene names. */
static void scene_names(const eq_curve *curves, int n, char *buf,
                        size_t size, int *distinct)
{
    const char *names[MAX_OVERLAYS + 1];
    int nn = 0;
    for (int i = 0; i < n; i++) {
        int seen = 0;
        for (int j = 0; j < nn; j++)
            seen |= strcmp(names[j], curves[i].sys->name) == 0;
        if (!seen)
            names[nn++] = curves[i].sys->name;
    }
    buf[0] = '\0';
    for (int j = 0; j < nn; j++) {
        size_t len = strlen(buf);
        snprintf(buf + len, size - len, "%s%s",
                 j == 0 ? "" : j == nn - 1 ? " and " : ", ", names[j]);
    }
    *distinct = nn;
}

/* Side and top views of the converged curves. Returns the exit status. */
static int eq_plot(const cli_plot *plot, eq_curve *curves, int ncurves)
{
    cli_shape shapes[MAX_OVERLAYS + 1];
    ts_plot_shape sh[MAX_OVERLAYS + 1];
    int n = 0, water = 0, status = 0;
    char names[512];
    int distinct;
    scene_names(curves, ncurves, names, sizeof names, &distinct);
    double x0 = 0, x1 = 0, z0 = 0, z1 = 0;
    for (int i = 0; i < ncurves; i++) {
        const eq_curve *c = &curves[i];
        if (!c->eq || !c->eq->converged)
            continue;
        if (cli_plot_shape(c->sys, c->eq->positions, &shapes[n]) != 0) {
            fprintf(stderr, "towstab: error: equilibrium: --plot: out of memory\n");
            status = EXIT_FAILED;
            break;
        }
        char tow[128];
        cli_plot_tow_label(c->sys, plot->opts.units, tow, sizeof tow);
        if (distinct > 1)
            snprintf(shapes[n].label, sizeof shapes[n].label, "%.63s: %.120s",
                     c->sys->name, tow);
        else
            snprintf(shapes[n].label, sizeof shapes[n].label, "%s", tow);
        water |= c->sys->env.water_density > 0;
        for (int k = 0; k < c->sys->nnodes; k++) {
            const double *r = c->eq->positions + 3 * k;
            x0 = r[0] < x0 ? r[0] : x0;
            x1 = r[0] > x1 ? r[0] : x1;
            z0 = r[2] < z0 ? r[2] : z0;
            z1 = r[2] > z1 ? r[2] : z1;
        }
        sh[n] = shapes[n].shape;
        n++;
    }
    if (n == 0 && status == 0) {
        fprintf(stderr, "towstab: error: equilibrium: --plot: no converged "
                        "equilibrium to draw\n");
        status = EXIT_FAILED;
    }
    /* The side view keeps the true shape (equal scales) unless the cable
     * is so flat that its depth would be under 5 % of its length. */
    int flags = (water ? TS_PLOT_WATER : 0) |
                (z1 - z0 >= 0.05 * (x1 - x0) ? TS_PLOT_EQUAL : 0);
    static const char *const view_name[2] = {"side", "top"};
    for (int v = 0; v < 2 && status == 0; v++) {
        char title[640];
        snprintf(title, sizeof title, "%s: equilibrium, %s view", names,
                 view_name[v]);
        ts_err err = {0};
        int rc = ts_plot_shapes(plot->dir, view_name[v], title,
                                v ? TS_PLOT_TOP : TS_PLOT_SIDE, flags, n, sh,
                                &plot->opts, &err);
        if (rc != TS_OK)
            status = cli_report(&err, rc);
        else
            printf("wrote %s/%s.png and %s/%s.svg\n", plot->dir,
                   view_name[v], plot->dir, view_name[v]);
    }
    for (int i = 0; i < n; i++)
        cli_plot_shape_free(&shapes[i]);
    return status;
}

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
            "  --quiet          print the summary only, not the tables\n"
            "  --plot DIR       draw side and top views into DIR (side.png,\n"
            "                   side.svg, top.png, top.svg); DIR is created\n"
            "  --units U        units of the pictures: si (default) or\n"
            "                   imperial (ft, lbf, knot)\n"
            "  --overlay-speeds LIST      also draw these speeds ('2,4,6 "
            "knot')\n"
            "  --overlay-turn-rates LIST  also draw these turn rates "
            "('0.2,0.5 rad/s')\n"
            "  --overlay SCENE  also draw this scene (repeatable); the\n"
            "                   options above apply to every curve\n");
}

static int eq_main(int argc, char **argv)
{
    cli_settings s = {0};
    cli_settings_from_options(&s);
    const char *json_path = NULL, *csv_path = NULL;
    const char *overlay_speeds = NULL, *overlay_turns = NULL;
    const char *overlay_scenes[MAX_OVERLAYS];
    int noverlay_scenes = 0;
    cli_plot plot = {0};
    int quiet = 0;
    static const struct option longopts[] = {
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        CLI_SETTINGS_LONGOPTS("method"),
        {"quiet", no_argument, NULL, 'q'},
        {"plot", required_argument, NULL, 'p'},
        {"units", required_argument, NULL, 'u'},
        {"overlay-speeds", required_argument, NULL, 'V'},
        {"overlay-turn-rates", required_argument, NULL, 'W'},
        {"overlay", required_argument, NULL, 'O'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (ch) {
        case 'j': json_path = optarg; break;
        case 'c': csv_path = optarg; break;
        case 'q': quiet = 1; break;
        case 'p': plot.dir = optarg; break;
        case 'u': plot.units = optarg; break;
        case 'V': overlay_speeds = optarg; break;
        case 'W': overlay_turns = optarg; break;
        case 'O':
            if (noverlay_scenes == MAX_OVERLAYS) {
                fprintf(stderr, "towstab: error: equilibrium: --overlay: at most %d "
                                "scenes\n",
                        MAX_OVERLAYS);
                return EXIT_BADINPUT;
            }
            overlay_scenes[noverlay_scenes++] = optarg;
            break;
        case 'h': usage(stdout); return 0;
        default: {
            int r = cli_settings_option(&s, ch, optarg);
            if (r < 0)
                return EXIT_BADINPUT;
            if (r == 0)
                return cli_option_error("equilibrium", ch, argv[optind - 1]);
        }
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: equilibrium: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    char speed_items[MAX_OVERLAYS][ITEM_MAX];
    char turn_items[MAX_OVERLAYS][ITEM_MAX];
    int nspeeds = 0, nturns = 0;
    if ((overlay_speeds || overlay_turns || noverlay_scenes) && !plot.dir) {
        fprintf(stderr, "towstab: error: equilibrium: --overlay-speeds, "
                        "--overlay-turn-rates and --overlay add curves to the "
                        "--plot pictures; add --plot DIR\n");
        return EXIT_BADINPUT;
    }
    if (overlay_speeds && (nspeeds = split_list("--overlay-speeds",
                                                overlay_speeds, speed_items,
                                                MAX_OVERLAYS)) < 0)
        return EXIT_BADINPUT;
    if (overlay_turns && (nturns = split_list("--overlay-turn-rates",
                                              overlay_turns, turn_items,
                                              MAX_OVERLAYS)) < 0)
        return EXIT_BADINPUT;
    if (nspeeds + nturns + noverlay_scenes > MAX_OVERLAYS) {
        fprintf(stderr, "towstab: error: equilibrium: at most %d overlay curves in "
                        "all, got %d\n",
                MAX_OVERLAYS, nspeeds + nturns + noverlay_scenes);
        return EXIT_BADINPUT;
    }
    static const char *const what[2] = {"--json", "--csv"};
    static const char *const pictures[] = {"side", "top", NULL};
    const char *paths[2] = {json_path, csv_path};
    int status = cli_check_outputs("equilibrium", 2, what, paths, plot.dir,
                                   pictures);
    if (!status)
        status = cli_plot_begin(&plot, "equilibrium");
    if (status)
        return status;
    ts_units *units;
    ts_scene *scene;
    status = cli_open(argv[optind], &units, &scene);
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
    /* Overlays: every setting is checked before the first solve. */
    eq_curve curves[MAX_OVERLAYS + 1];
    memset(curves, 0, sizeof curves);
    int ncurves = 1;
    for (int i = 0; i < nspeeds + nturns + noverlay_scenes && !status; i++) {
        eq_curve *c = &curves[ncurves++];
        cli_settings o = s;
        const ts_scene *from = scene;
        if (i < nspeeds) {
            o.speed = speed_items[i];
            snprintf(c->what, sizeof c->what, "--overlay-speeds '%.120s'",
                     speed_items[i]);
        } else if (i < nspeeds + nturns) {
            o.turn_rate = turn_items[i - nspeeds];
            snprintf(c->what, sizeof c->what, "--overlay-turn-rates '%.120s'",
                     turn_items[i - nspeeds]);
        } else {
            const char *path = overlay_scenes[i - nspeeds - nturns];
            snprintf(c->what, sizeof c->what, "--overlay '%.120s'", path);
            c->scene = ts_scene_load(path, units, &err);
            if (!c->scene) {
                ts_err_prefix(&err, "%s: ", c->what);
                status = cli_report(&err, err.code == TS_EIO ? TS_ESCENE
                                                             : err.code);
                break;
            }
            from = c->scene;
        }
        status = overlay_system(c, from, units, &o);
    }
    if (!status) {
        printf("towstab equilibrium: %s (%s)\n", sys->name, scene->path);
        ts_equilibrium *eq = NULL;
        json_t *json = NULL;
        int rc = cli_equilibrium(sys, &eo, quiet, &eq,
                                 json_path ? &json : NULL, &err);
        if (rc)
            status = cli_report(&err, rc);
        status = cli_write_result(json, json_path, status, err.msg);
        ts_err werr = {0};
        if (csv_path && eq && eq->converged &&
            ts_report_equilibrium_csv(sys, eq, csv_path, &werr) != TS_OK)
            status = cli_report(&werr, werr.code);
        json_decref(json);
        curves[0].sys = sys;
        curves[0].eq = eq;
        if (plot.dir) {
            for (int i = 1; i < ncurves; i++) {
                int st = overlay_solve(&curves[i]);
                if (st && !status)
                    status = st;
            }
            int st = eq_plot(&plot, curves, ncurves);
            if (st && !status)
                status = st;
        }
    } else {
        ts_system_free(sys);
    }
    for (int i = 0; i < ncurves; i++) {
        ts_equilibrium_free(curves[i].eq);
        ts_system_free(curves[i].sys);
        ts_scene_free(curves[i].scene);
    }
    cli_close(units, scene);
    return status;
}

static const char *const eq_keys[] = {"speed", "turn_rate", "method",
                                      "tolerance", "links", NULL};

static int eq_entry(const cli_ctx *ctx, const ts_scene_analysis *a,
                    int index, json_t **result)
{
    ts_err err = {0};
    cli_settings s = {0};
    if (cli_settings_from_analysis(&s, a, index, &err))
        return cli_report(&err, err.code);
    ts_equilibrium_opts eo;
    ts_system *sys = cli_system(ctx->scene, ctx->units, &s, &eo, &err);
    if (!sys)
        return cli_report(&err, err.code);
    int status = 0;
    if (result) {
        ts_equilibrium *eq = NULL;
        int rc = cli_equilibrium(sys, &eo, ctx->quiet, &eq, result, &err);
        status = rc ? cli_report(&err, rc) : 0;
        cli_json_mark(*result, status, err.msg);
        ts_equilibrium_free(eq);
    }
    ts_system_free(sys);
    return status;
}

const cli_command cli_cmd_equilibrium = {
    "equilibrium", "steady shape at the scene's speed and turn rate",
    eq_main, eq_entry, eq_keys};
