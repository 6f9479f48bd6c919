/* cmd_report.c: `towstab report SCENE -o DIR`: the scene's analyses, run
 * as `towstab run` runs them (tools/cli_scene.c), and one self-contained
 * HTML page of them, DIR/index.html: the command that reproduces it, a
 * summary, the inputs with their units (the system as read, in SI, and the
 * scene's text), and for each analysis its options, its verdict, its key
 * values with their error estimates, its pictures (SVG inside the page as
 * data URIs) and its result tables (made from its JSON). Beside the page:
 * DIR/results.json (what `towstab run --json` writes) and the pictures as
 * files, DIR/pictures/<k>_<type>/NAME.svg. The page fetches nothing. */
#include <dirent.h>
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "cli_html.h"
#include "towstab/plot.h"
#include "towstab/report.h"

#ifndef TOWSTAB_VERSION
#define TOWSTAB_VERSION "unknown"
#endif

/* Room for a file name under DIR. */
#define REPORT_PATH_MAX 1200
/* Pictures of one analysis, at most. */
#define MAX_PICTURES 32
/* m/s per knot, rad per degree. */
#define KNOT (1852.0 / 3600.0)
#define DEG (M_PI / 180.0)

/* The page's style: readable tables that fit the page (long words wrap,
 * wide tables scroll inside their box), a verdict that stands out. */
static const char style[] =
    "body{font:15px/1.45 system-ui,-apple-system,'Segoe UI',sans-serif;"
    "margin:0;color:#1b1b1b;background:#fff}"
    "main{max-width:1150px;margin:0 auto;padding:1em 1.5em 3em}"
    "h1{font-size:1.6em;margin:.4em 0}"
    "h2{font-size:1.3em;border-bottom:2px solid #2c4a6e;margin-top:2em}"
    "h3{font-size:1.1em;margin-top:1.4em}h4,h5,h6{font-size:1em}"
    "table{border-collapse:collapse;margin:.4em 0 .8em}"
    "th,td{border:1px solid #c9cfd8;padding:.15em .5em;text-align:left;"
    "vertical-align:top;overflow-wrap:break-word}"
    "th{background:#eef1f6;font-weight:600}"
    "td.num{text-align:right;font-variant-numeric:tabular-nums;"
    "white-space:nowrap}"
    ".wide{max-width:100%;overflow-x:auto}"
    "pre,code{font-family:ui-monospace,'DejaVu Sans Mono',monospace;"
    "font-size:.92em}"
    "pre{white-space:pre-wrap;overflow-wrap:anywhere;background:#f5f6f8;"
    "border:1px solid #dde;padding:.6em .8em}"
    "p,li,figcaption,summary{overflow-wrap:anywhere}"
    ".verdict{padding:.4em 1em;border-left:6px solid;margin:.8em 0}"
    ".ok{border-color:#2a7a4b;background:#eef8f1}"
    ".bad{border-color:#b3261e;background:#fcefee}"
    ".verdict p{margin:.3em 0}"
    "figure{margin:1em 0}"
    "img{display:block;width:900px;max-width:100%;height:auto;"
    "border:1px solid #dde}"
    "figcaption{font-size:.9em;color:#444;margin-top:.3em}"
    "details{margin:.4em 0}summary{cursor:pointer}"
    ".meta{color:#444}";

static void usage(FILE *f)
{
    fprintf(f, "usage: towstab report SCENE -o DIR [--units U] [--quiet]\n"
               "  runs the scene's 'analyses' list as towstab run does and "
               "writes DIR/index.html,\n"
               "  one self-contained page: inputs with units, each result's "
               "tables, pictures,\n"
               "  error estimates and verdict, and the command that "
               "reproduces it\n"
               "  -o, --output DIR  the directory of the page (made); also "
               "DIR/results.json\n"
               "                    and the pictures under DIR/pictures/\n"
               "  --units U         units of the pictures and printed "
               "tables: si (default),\n"
               "                    imperial or items like speed=knot,"
               "force=kN\n"
               "  --quiet           print the summaries only\n");
}

/* The command line as a shell reads it: words of [A-Za-z0-9_./:=,+@%-]
 * as they are, others in single quotes. */
static void shell_words(FILE *f, int argc, char **argv)
{
    fputs("towstab", f);
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int plain = a[0] != '\0';
        for (const char *p = a; *p && plain; p++)
            plain = strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                           "0123456789_./:=,+@%-", *p) != NULL;
        fputc(' ', f);
        if (plain) {
            fputs(a, f);
            continue;
        }
        fputc('\'', f);
        for (const char *p = a; *p; p++)
            if (*p == '\'')
                fputs("'\\''", f);
            else
                fputc(*p, f);
        fputc('\'', f);
    }
}

/* One row of a table of inputs: name, value, unit. */
static void input_row(FILE *f, const char *name, double v, const char *unit)
{
    fputs("<tr><td>", f);
    cli_html_text(f, name);
    fputs("</td><td class=\"num\">", f);
    cli_html_number(f, v, 8);
    fputs("</td><td>", f);
    cli_html_text(f, unit);
    fputs("</td></tr>\n", f);
}

static void num_cell(FILE *f, double v, int digits)
{
    fputs("<td class=\"num\">", f);
    cli_html_number(f, v, digits);
    fputs("</td>", f);
}

static const char *body_type(ts_body_type t)
{
    switch (t) {
    case TS_BODY_SPHERE: return "sphere";
    case TS_BODY_JUNCTION: return "junction";
    case TS_BODY_CYLINDER: return "cylinder";
    default: return "vehicle";
    }
}

/* The system as read, in SI, and the scene's text. */
static void inputs(FILE *f, const ts_scene *scene)
{
    const ts_system *s = scene->system;
    fputs("<section id=\"inputs\"><h2>Inputs</h2>\n<p>The system as towstab "
          "read it, in SI units (the scene may give other units; its text "
          "follows). Quantities are defined in doc/scene-format.md.</p>\n",
          f);
    fputs("<h3>Water and tow</h3>\n<div class=\"wide\"><table>\n<tr><th>"
          "quantity</th><th>value</th><th>unit</th></tr>\n", f);
    input_row(f, "water density", s->env.water_density, "kg/m^3");
    input_row(f, "gravity", s->env.gravity, "m/s^2");
    static const char *const axis[3] = {"x", "y", "z"};
    char name[64];
    for (int k = 0; k < 3; k++) {
        snprintf(name, sizeof name, "current %s", axis[k]);
        input_row(f, name, s->env.current[k], "m/s");
    }
    /* With a towing vehicle these are where its solve starts (or its
     * targets): the solved motion is the results' (the vehicle's line). */
    int towing = s->tow.vehicle >= 0;
    const char *sp = towing ? "tow speed (the towing vehicle's start)"
                            : "tow speed";
    const char *tr = towing ? "turn rate (the towing vehicle's start)"
                            : "turn rate";
    input_row(f, sp, s->tow.speed, "m/s");
    input_row(f, sp, s->tow.speed / KNOT, "knot");
    input_row(f, tr, s->tow.turn_rate, "rad/s");
    input_row(f, tr, s->tow.turn_rate / DEG, "deg/s");
    if (s->tow.turn_rate != 0 && !towing)
        input_row(f, "turn radius V/Omega", s->tow.speed / s->tow.turn_rate,
                  "m");
    for (int k = 0; k < 3; k++) {
        snprintf(name, sizeof name, "tow point %s", axis[k]);
        input_row(f, name, s->tow.point[k], "m");
    }
    fputs("</table></div>\n", f);

    fputs("<h3>Cables</h3>\n<div class=\"wide\"><table>\n<tr><th>name</th>"
          "<th>from</th><th>to</th><th>length [m]</th><th>diameter [m]</th>"
          "<th>mass per length [kg/m]</th><th>wet weight [N/m]</th><th>"
          "links</th></tr>\n", f);
    for (int c = 0; c < s->ncables; c++) {
        const ts_cable *cb = &s->cables[c];
        fputs("<tr><td>", f);
        cli_html_text(f, cb->name);
        fputs("</td><td>", f);
        cli_html_text(f, cb->from_body < 0 ? "tow"
                                           : s->bodies[cb->from_body].name);
        fputs("</td><td>", f);
        cli_html_text(f, cb->to_body < 0 ? "(free end)"
                                         : s->bodies[cb->to_body].name);
        fputs("</td>", f);
        num_cell(f, cb->length, 8);
        num_cell(f, cb->diameter, 6);
        num_cell(f, cb->mass_per_length, 6);
        num_cell(f, ts_cable_wet_weight(s, c), 6);
        fprintf(f, "<td class=\"num\">%d%s</td></tr>\n", cb->nlinks,
                cb->link_fraction ? " (unequal)" : "");
    }
    fputs("</table></div>\n<div class=\"wide\"><table>\n<tr><th>cable</th>"
          "<th>normal drag Cdn</th><th>tangential drag Cdt</th><th>added "
          "mass Can</th><th>EA [N]</th><th>EI [N m^2]</th><th>damping "
          "[N s/m]</th></tr>\n", f);
    for (int c = 0; c < s->ncables; c++) {
        const ts_cable *cb = &s->cables[c];
        fputs("<tr><td>", f);
        cli_html_text(f, cb->name);
        fputs("</td>", f);
        num_cell(f, cb->cdn, 4);
        num_cell(f, cb->cdt, 4);
        num_cell(f, cb->can, 4);
        num_cell(f, cb->ea, 6);
        num_cell(f, cb->ei, 6);
        num_cell(f, cb->damping, 6);
        fputs("</tr>\n", f);
    }
    fputs("</table></div>\n", f);

    if (s->nbodies > 0) {
        fputs("<h3>Bodies</h3>\n<div class=\"wide\"><table>\n<tr><th>name"
              "</th><th>type</th><th>mass [kg]</th><th>volume [m^3]</th>"
              "<th>diameter [m]</th><th>length [m]</th><th>Cd</th><th>Ca"
              "</th><th>Cd cross</th><th>Ca cross</th></tr>\n", f);
        for (int b = 0; b < s->nbodies; b++) {
            const ts_body *bd = &s->bodies[b];
            fputs("<tr><td>", f);
            cli_html_text(f, bd->name);
            fputs("</td><td>", f);
            cli_html_text(f, body_type(bd->type));
            fputs("</td>", f);
            num_cell(f, bd->mass, 8);
            num_cell(f, ts_body_volume(bd), 6);
            num_cell(f, bd->diameter, 6);
            num_cell(f, bd->length, 6);
            num_cell(f, bd->cd, 4);
            num_cell(f, bd->ca, 4);
            num_cell(f, bd->cd_cross, 4);
            num_cell(f, bd->ca_cross, 4);
            fputs("</tr>\n", f);
        }
        fputs("</table></div>\n", f);
    }

    int lines = 0;
    for (size_t i = 0; i < scene->text_len; i++)
        lines += scene->text[i] == '\n';
    fprintf(f, "<details open><summary>The scene file as read (%d lines)"
               "</summary>\n<pre>", lines);
    cli_html_textn(f, scene->text, scene->text_len);
    fputs("</pre></details>\n</section>\n", f);
}

/* The verdict of a result's JSON: trustworthy, completed, error, reasons
 * and notes. */
static void verdict(FILE *f, const json_t *j)
{
    int trust = json_is_true(json_object_get(j, "trustworthy"));
    int done = json_is_true(json_object_get(j, "completed"));
    fprintf(f, "<div class=\"verdict %s\"><p><strong>trustworthy: %s"
               "</strong>%s</p>\n",
            trust && done ? "ok" : "bad", trust ? "yes" : "NO",
            done ? "" : " (the analysis did not complete)");
    const char *error = json_string_value(json_object_get(j, "error"));
    if (error) {
        fputs("<p>error: ", f);
        cli_html_text(f, error);
        fputs("</p>\n", f);
    }
    const char *const lists[2] = {"reasons", "notes"};
    for (int k = 0; k < 2; k++) {
        const json_t *l = json_object_get(j, lists[k]);
        if (json_array_size(l) == 0)
            continue;
        fprintf(f, "<p>%s:</p><ul>\n", lists[k]);
        size_t i;
        const json_t *e;
        json_array_foreach(l, i, e)
        {
            fputs("<li>", f);
            cli_html_text(f, json_string_value(e));
            fputs("</li>\n", f);
        }
        fputs("</ul>\n", f);
    }
    fputs("</div>\n", f);
}

/* The key values with their error estimates. */
static void key_values(FILE *f, const json_t *j)
{
    const json_t *kv = json_object_get(j, "key_values");
    if (json_array_size(kv) == 0)
        return;
    fputs("<h3>Key values and their error estimates</h3>\n<div class=\"wide"
          "\"><table>\n<tr><th>name</th><th>value</th><th>unit</th><th>"
          "discretisation error</th><th>solver error</th></tr>\n", f);
    size_t i;
    const json_t *v;
    json_array_foreach(kv, i, v)
    {
        const json_t *e = json_object_get(v, "error");
        const json_t *x[3] = {json_object_get(v, "value"),
                              json_object_get(e, "discretisation"),
                              json_object_get(e, "solver")};
        fputs("<tr><td>", f);
        cli_html_text(f, json_string_value(json_object_get(v, "name")));
        fputs("</td>", f);
        num_cell(f, json_is_number(x[0]) ? json_number_value(x[0]) : NAN, 10);
        fputs("<td>", f);
        cli_html_text(f, json_string_value(json_object_get(v, "unit")));
        fputs("</td>", f);
        for (int k = 1; k < 3; k++) {
            if (json_is_number(x[k]))
                num_cell(f, json_number_value(x[k]), 2);
            else
                fputs("<td>not estimated</td>", f);
        }
        fputs("</tr>\n", f);
    }
    fputs("</table></div>\n<p>The errors are estimates in the value's unit "
          "(doc/manual.md, \"Output conventions\"): the discretisation "
          "error from the same analysis at a half and a quarter of the "
          "links (doc/accuracy.md; \"accuracy\" under Results says how "
          "it was made and whether it meets the accuracy asked).</p>\n", f);
}

/* The order of a picture: its place in the command's list, else after. */
static const char *const *rank_list;
static int picture_rank(const char *name)
{
    for (int i = 0; rank_list && rank_list[i]; i++) {
        size_t n = strlen(rank_list[i]);
        if (!strncmp(name, rank_list[i], n) && !strcmp(name + n, ".svg"))
            return i;
    }
    return 1000;
}

static int svg_file(const struct dirent *d)
{
    size_t n = strlen(d->d_name);
    return n > 4 && d->d_name[0] != '.' && !strcmp(d->d_name + n - 4, ".svg");
}

static int by_rank(const struct dirent **a, const struct dirent **b)
{
    int ra = picture_rank((*a)->d_name), rb = picture_rank((*b)->d_name);
    return ra != rb ? ra - rb : strcmp((*a)->d_name, (*b)->d_name);
}

/* The SVG pictures in dir, in the command's order; the count or -1. */
static int pictures(FILE *f, const char *dir, const cli_command *cmd,
                    int *npictures, ts_err *err)
{
    struct dirent **list = NULL;
    rank_list = cmd->pictures;
    int n = scandir(dir, &list, svg_file, by_rank);
    rank_list = NULL;
    if (n < 0)
        return TS_OK; /* no pictures were drawn */
    int rc = TS_OK;
    if (n > 0)
        fputs("<h3>Pictures</h3>\n", f);
    for (int i = 0; i < n; i++) {
        char path[REPORT_PATH_MAX];
        snprintf(path, sizeof path, "%s/%s", dir, list[i]->d_name);
        if (rc == TS_OK && i < MAX_PICTURES) {
            rc = cli_html_svg(f, path, list[i]->d_name, err);
            *npictures += rc == TS_OK;
        }
        free(list[i]);
    }
    free(list);
    return rc;
}

/* Analysis i: its options, verdict, key values, pictures and tables. */
static int analysis(FILE *f, const ts_scene *scene, const cli_scene_runs *s,
                    int i, const json_t *j, int *npictures, ts_err *err)
{
    const ts_scene_analysis *a = &scene->analyses[i];
    fprintf(f, "<section id=\"a%d\"><h2>%d. ", i + 1, i + 1);
    cli_html_text(f, a->type);
    fputs("</h2>\n<p>", f);
    fprintf(f, "analyses[%d] of the scene (line %d), ", i, a->line);
    if (a->noptions == 0)
        fputs("every option at its default", f);
    else
        fputs("with these options, the others at their defaults", f);
    fputs(" (<code>towstab ", f);
    cli_html_text(f, a->type);
    fprintf(f, " --help</code> lists them)%s</p>\n",
            a->noptions ? ":" : ".");
    if (a->noptions > 0) {
        fputs("<div class=\"wide\"><table>\n<tr><th>option</th><th>value as "
              "written</th><th>line</th></tr>\n", f);
        for (int k = 0; k < a->noptions; k++) {
            fputs("<tr><td>", f);
            cli_html_text(f, a->options[k].key);
            fputs("</td><td>", f);
            cli_html_text(f, a->options[k].value);
            fprintf(f, "</td><td class=\"num\">%d</td></tr>\n",
                    a->options[k].line);
        }
        fputs("</table></div>\n", f);
    }
    int first = 1;
    for (int k = 0; k < i && first; k++)
        first = strcmp(scene->analyses[k].type, a->type) != 0;
    if (first && scene->path[0] && strcmp(scene->path, "-")) {
        fputs("<p>Alone: <code>towstab ", f);
        cli_html_text(f, a->type);
        fputs(" ", f);
        cli_html_text(f, scene->path);
        fputs("</code> (a command takes its options from the first entry of "
              "its type).</p>\n", f);
    }
    if (i >= s->ran || !j) {
        fputs("<div class=\"verdict bad\"><p><strong>not run</strong>: an "
              "analysis before it failed.</p></div>\n</section>\n", f);
        return TS_OK;
    }
    verdict(f, j);
    fprintf(f, "<p class=\"meta\">%.3g s with printing and pictures.</p>\n",
            s->wall_s[i]);
    key_values(f, j);
    int rc = pictures(f, s->dirs[i], s->runs[i].cmd, npictures, err);
    fputs("<h3>Results</h3>\n<p>Every key is defined in doc/manual.md; "
          "results.json beside this page holds every number in full "
          "precision.</p>\n", f);
    static const char *const skip[] = {
        "type", "completed", "trustworthy", "reasons", "notes",
        "key_values", "error", "interrupted", "dropped", NULL};
    cli_html_json(f, j, 4, skip);
    fputs("</section>\n", f);
    return rc;
}

/* The whole page into p. */
static int page(cli_page *p, const ts_scene *scene, const cli_scene_runs *s,
                const json_t *all, int status, int argc, char **argv,
                const char *plot_note, int *npictures, ts_err *err)
{
    FILE *f = p->f;
    const char *name = scene->system->name;
    fputs("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
          "<meta name=\"viewport\" content=\"width=device-width, "
          "initial-scale=1\">\n<meta name=\"generator\" content=\"towstab "
          TOWSTAB_VERSION "\">\n<title>towstab report: ", f);
    cli_html_text(f, name);
    fprintf(f, "</title>\n<style>%s</style>\n</head><body><main>\n", style);
    fputs("<h1>towstab report: ", f);
    cli_html_text(f, name);
    fputs("</h1>\n<p class=\"meta\">Scene ", f);
    cli_html_text(f, strcmp(scene->path, "-") ? scene->path
                                              : "read from standard input");
    fprintf(f, "; %d analys%s; towstab " TOWSTAB_VERSION ".</p>\n",
            s->n, s->n == 1 ? "is" : "es");
    if (status) {
        const char *e = json_string_value(json_object_get(all, "error"));
        fputs("<div class=\"verdict bad\"><p><strong>The run did not "
              "complete.</strong> ", f);
        cli_html_text(f, e ? e : "an analysis failed");
        fputs("</p></div>\n", f);
    }

    char cwd[REPORT_PATH_MAX];
    fputs("<section id=\"reproduce\"><h2>Reproduce</h2>\n<p>This page was "
          "made by</p>\n<pre>", f);
    char *cmd = NULL;
    size_t cmd_len = 0;
    FILE *c = open_memstream(&cmd, &cmd_len);
    if (c) {
        shell_words(c, argc, argv);
        fclose(c);
        cli_html_text(f, cmd);
        free(cmd);
    }
    fputs("</pre>\n<p>run in ", f);
    cli_html_text(f, getcwd(cwd, sizeof cwd) ? cwd : "(unknown directory)");
    fputs(" with towstab " TOWSTAB_VERSION ". <code>towstab run", f);
    fputs(" ", f);
    cli_html_text(f, scene->path);
    fputs("</code> runs the same analyses and prints the same tables; "
          "results.json beside this page is its <code>--json</code>.</p>\n"
          "</section>\n", f);

    fputs("<section id=\"summary\"><h2>Summary</h2>\n<div class=\"wide\">"
          "<table>\n<tr><th>#</th><th>analysis</th><th>completed</th><th>"
          "trustworthy</th><th>time [s]</th></tr>\n", f);
    const json_t *list = json_object_get(all, "analyses");
    for (int i = 0; i < s->n; i++) {
        const json_t *j = i < s->ran ? json_array_get(list, (size_t)i) : NULL;
        fprintf(f, "<tr><td class=\"num\">%d</td><td><a href=\"#a%d\">",
                i + 1, i + 1);
        cli_html_text(f, scene->analyses[i].type);
        fputs("</a></td>", f);
        if (j)
            fprintf(f, "<td>%s</td><td>%s</td>",
                    json_is_true(json_object_get(j, "completed")) ? "yes"
                                                                  : "NO",
                    json_is_true(json_object_get(j, "trustworthy")) ? "yes"
                                                                    : "NO");
        else
            fputs("<td>not run</td><td>-</td>", f);
        num_cell(f, j ? s->wall_s[i] : NAN, 3);
        fputs("</tr>\n", f);
    }
    fputs("</table></div>\n", f);
    if (plot_note) {
        fputs("<p>No pictures: ", f);
        cli_html_text(f, plot_note);
        fputs("</p>\n", f);
    }
    fputs("</section>\n", f);

    inputs(f, scene);
    int rc = TS_OK;
    for (int i = 0; i < s->n && rc == TS_OK; i++)
        rc = analysis(f, scene, s, i,
                      i < s->ran ? json_array_get(list, (size_t)i) : NULL,
                      npictures, err);
    fputs("</main></body></html>\n", f);
    return rc;
}

/* The command: `words` are argv as given (getopt reorders argv). */
static int report_run(int argc, char **argv, char **words)
{
    static const struct option longopts[] = {
        {"output", required_argument, NULL, 'o'},
        {"units", required_argument, NULL, 'u'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    cli_scene_args a;
    int st = cli_scene_args_parse("report", argc, argv, ":o:", longopts,
                                  usage, &a);
    if (st >= 0)
        return st;
    const char *dir = a.output;
    if (!dir || !dir[0]) {
        fprintf(stderr, "towstab: error: report: -o DIR: expected the "
                        "directory of the page, got %s\n",
                dir ? "an empty name" : "none");
        return EXIT_BADINPUT;
    }
    char html[REPORT_PATH_MAX], json[REPORT_PATH_MAX], pics[REPORT_PATH_MAX];
    if (snprintf(html, sizeof html, "%s/index.html", dir) >= (int)sizeof html
        || snprintf(json, sizeof json, "%s/results.json", dir) >=
               (int)sizeof json ||
        snprintf(pics, sizeof pics, "%s/pictures", dir) >= (int)sizeof pics) {
        fprintf(stderr, "towstab: error: report: -o: the name '%.64s...' is "
                        "too long\n", dir);
        return EXIT_BADINPUT;
    }
    /* Pictures need PLplot; without it the page says so. */
    ts_err perr = {0};
    const char *plot_note = NULL;
    if (ts_plot_check(&perr) != TS_OK)
        plot_note = perr.msg;
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(a.scene, &units, &scene);
    if (status)
        return status;
    cli_scene_runs s;
    status = cli_scene_prepare("report", scene, units, a.quiet, NULL,
                               plot_note ? NULL : pics, a.units, 1, &s);
    if (status) {
        cli_close(units, scene);
        return status;
    }
    ts_err err = {0};
    status = cli_make_dir("report", "-o", dir);
    if (!status && !plot_note && ts_plot_prepare_dir(pics, &err) != TS_OK) {
        fprintf(stderr, "towstab: error: report: -o: %s\n", err.msg);
        status = err.code == TS_EINVAL ? EXIT_BADINPUT : EXIT_FAILED;
    }
    for (int i = 0; i < s.n && !status && !plot_note; i++)
        if (s.runs[i].plot.dir) {
            status = cli_plot_begin(&s.runs[i].plot, "report");
            s.runs[i].plot.opts.formats = TS_PLOT_SVG;
        }
    json_t *all = NULL;
    if (!status)
        status = cli_scene_execute(scene, &s, &all, NULL);
    /* As `towstab run`: after a failure what ran, marked; nothing after
     * bad input. */
    if (all && status != EXIT_BADINPUT) {
        cli_page p;
        int npictures = 0;
        int rc = cli_page_open(&p, &err);
        if (rc == TS_OK) {
            rc = page(&p, scene, &s, all, status, argc, words, plot_note,
                      &npictures, &err);
            int crc = cli_page_close(&p, &err);
            rc = rc ? rc : crc;
        }
        if (rc == TS_OK)
            rc = ts_report_write_json(all, json, &err);
        if (rc == TS_OK)
            rc = ts_report_write_text(p.buf, p.len, html, &err);
        if (rc == TS_OK)
            printf("\nwrote %s (%d analys%s, %d picture%s, %zu bytes) and "
                   "%s\n",
                   html, s.ran, s.ran == 1 ? "is" : "es", npictures,
                   npictures == 1 ? "" : "s", p.len, json);
        else {
            int st = cli_report(&err, rc);
            status = status ? status : st;
        }
        cli_page_free(&p);
    }
    json_decref(all);
    cli_scene_free(&s);
    cli_close(units, scene);
    return status;
}

static int report_main(int argc, char **argv)
{
    /* The words as given, for the page. */
    char **words = malloc(((size_t)argc + 1) * sizeof *words);
    if (!words) {
        fprintf(stderr, "towstab: error: report: out of memory\n");
        return EXIT_FAILED;
    }
    memcpy(words, argv, (size_t)argc * sizeof *words);
    int status = report_run(argc, argv, words);
    free(words);
    return status;
}

const cli_command cli_cmd_report = {
    "report", "the scene's analyses as one self-contained HTML page", -1,
    report_main, NULL, NULL, NULL, NULL, NULL, NULL, NULL};
