/* cmd_design.c: `towstab design SCENE --free PATH=LOWER:UPPER
 * [--target NAME=Q | --minimise NAME | --maximise NAME]
 * [--constraint "NAME<=Q"] ...`: design by optimisation
 * (towstab/design.h, doc/design.md).
 *
 * The analysis at every evaluation (--analysis equilibrium, the default,
 * or modes) takes its options from its own table, on the command line and
 * in the scene's first entry of its type, as `towstab <analysis>` does;
 * the study's own options are extras of the command. Prints the study,
 * then the single run at the optimum as the analysis command prints it;
 * writes the JSON (ts_design_json). Exit 0 when the target is reached and
 * the constraints are met, 1 when not (the closest point is reported), 2
 * for bad input. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "towstab/design.h"

extern const cli_command cli_cmd_equilibrium, cli_cmd_modes;

enum {
    X_ANALYSIS, X_FREE, X_TARGET, X_MINIMISE, X_MAXIMISE, X_CONSTRAINT,
    X_METHOD, X_MAX_EVALS, X_TARGET_TOL, X_FIN_STEP
};

static const cli_extra design_extras[] = {
    {"analysis", 1, 0, "A",
     "the analysis at every evaluation: equilibrium (default) or modes; "
     "its options follow"},
    {"free", 1, 1, "PATH=LOWER:UPPER[:START]",
     "a scene value to adjust within its bounds (START: the scene's), "
     "e.g. cables.main.length=100m:800m; up to 8"},
    {"target", 1, 0, "NAME=Q",
     "the value to bring to Q, e.g. fish.z=300m (within --target-tol)"},
    {"minimise", 1, 0, "NAME", "the value to minimise"},
    {"maximise", 1, 0, "NAME",
     "the value to maximise (e.g. min_damping with --analysis modes)"},
    {"constraint", 1, 1, "NAME<=Q",
     "an inequality NAME<=Q or NAME>=Q, e.g. 'top_tension<=40kN'; up to 8"},
    {"method", 1, 0, "M",
     "cobyla (default: bounds and constraints), bobyqa (bounds only) or "
     "slsqp (gradients by central differences; bounds and constraints)"},
    {"max-evals", 1, 0, "N",
     "analysis runs at most [default 200]"},
    {"target-tol", 1, 0, "X",
     "a target is reached within this fraction of it [default 1e-6]"},
    {"fin-step", 1, 0, "Q",
     "fin_use adds the command's jump for this step of the depth set "
     "points, e.g. 2m [default 0: the steady deflections]"},
    {NULL, 0, 0, NULL, NULL}};


static int bad(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "towstab: error: design: ");
    fprintf(stderr, fmt, a, b);
    fprintf(stderr, "\n");
    return EXIT_BADINPUT;
}

/* A quantity in `unit` ("" for a plain number) from text. */
static int quantity(const cli_run *c, const char *where, const char *text,
                    const char *unit, double *out)
{
    return cli_parse_values(c->units, "design", where, &text, 1, unit, out);
}

/* A setting's value: `text`, given where `src` says ("--free", or
 * "scene.yaml: design.free (line 12)"). */
typedef struct given {
    const char *text;
    char src[600];
} given;

/* --free PATH=LOWER:UPPER[:START]. */
static int parse_free(const cli_run *c, const given *g, ts_design_var *f)
{
    const char *text = g->text;
    const char *eq = strchr(text, '=');
    if (!eq || eq == text)
        return bad("%s: expected PATH=LOWER:UPPER[:START] (e.g. "
                   "cables.main.length=100m:800m), got '%s'", g->src, text);
    snprintf(f->path, sizeof f->path, "%.*s", (int)(eq - text), text);
    char unit[TS_PARAM_UNIT_MAX];
    ts_err err = {0};
    if (ts_param_unit(c->scene->system, f->path, unit, sizeof unit, &err)) {
        fprintf(stderr, "towstab: error: design: %s: %s\n", g->src, err.msg);
        return EXIT_BADINPUT;
    }
    char buf[512];
    snprintf(buf, sizeof buf, "%s", eq + 1);
    char *field[4];
    int nf = 0;
    char *save = NULL;
    for (char *p = strtok_r(buf, ":", &save); p && nf < 4;
         p = strtok_r(NULL, ":", &save))
        field[nf++] = p;
    char where[TS_PARAM_PATH_MAX + 620];
    snprintf(where, sizeof where, "%s %s", g->src, f->path);
    if (nf < 2 || nf > 3)
        return bad("%s: expected LOWER:UPPER or LOWER:UPPER:START, got '%s'",
                   where, eq + 1);
    /* A unit written on one bound applies to those written without one
     * ("1:5 knot"). */
    double v[3] = {NAN, NAN, NAN};
    if (cli_parse_values(c->units, "design", where,
                         (const char *const *)field, nf, unit, v))
        return EXIT_BADINPUT;
    f->lower = v[0];
    f->upper = v[1];
    f->start = v[2];
    return 0;
}

/* The unit of value `name` of a run, or bad input. */
static int value_unit(const cli_run *c, const char *what, const char *name,
                      char *unit, size_t size)
{
    ts_err err = {0};
    if (ts_design_unit(c->scene->system, &c->rq, what, name, unit, size,
                       &err)) {
        fprintf(stderr, "towstab: error: design: %s\n", err.msg);
        return EXIT_BADINPUT;
    }
    return 0;
}

/* --constraint NAME<=Q or NAME>=Q. */
static int parse_constraint(const cli_run *c, const given *g,
                            ts_design_constraint *k)
{
    const char *text = g->text;
    const char *op = strstr(text, "<=");
    k->upper = 1;
    if (!op) {
        op = strstr(text, ">=");
        k->upper = 0;
    }
    if (!op || op == text)
        return bad("%s: expected NAME<=Q or NAME>=Q (e.g. "
                   "'top_tension<=40kN'), got '%s'", g->src, text);
    snprintf(k->name, sizeof k->name, "%.*s", (int)(op - text), text);
    char unit[TS_VALUE_UNIT_MAX];
    if (value_unit(c, g->src, k->name, unit, sizeof unit))
        return EXIT_BADINPUT;
    char where[TS_VALUE_NAME_MAX + 620];
    snprintf(where, sizeof where, "%s %s", g->src, k->name);
    return quantity(c, where, op + 2, unit, &k->bound);
}

/* The settings of the study, extra by extra: the command line's values
 * of an extra when it gives any, else the scene's `design` section's
 * (the option table's rule: the higher source's texts of an option
 * replace the lower's; the goals --target, --minimise and --maximise are
 * one group). Refuses a section key that is no setting. */
typedef struct settings {
    int n[X_FIN_STEP + 1];
    given g[X_FIN_STEP + 1][CLI_EXTRA_VALUES];
} settings;

static int gather(const cli_run *c, settings *s)
{
    memset(s, 0, sizeof *s);
    const ts_scene_analysis *d = c->scene->design;
    int cmd_goal = c->nextra[X_TARGET] + c->nextra[X_MINIMISE] +
                   c->nextra[X_MAXIMISE];
    for (int i = 0; d && i < d->noptions; i++) {
        const ts_scene_option *o = &d->options[i];
        int k = -1;
        for (int j = 0; j <= X_FIN_STEP && k < 0; j++) {
            char name[TS_NAME_MAX];
            snprintf(name, sizeof name, "%s", design_extras[j].name);
            for (char *q = name; *q; q++)
                *q = *q == '-' ? '_' : *q;
            if (!strcmp(name, o->key))
                k = j;
        }
        if (k < 0) {
            fprintf(stderr, "towstab: error: design: %s: design.%s (line "
                            "%d): unknown setting; expected one of analysis, "
                            "free, target, minimise, maximise, constraint, "
                            "method, max_evals, target_tol, fin_step (the "
                            "analysis' own options go in its entry of "
                            "'analyses')\n",
                    c->scene->path, o->key, o->line);
            return EXIT_BADINPUT;
        }
        int goal = k == X_TARGET || k == X_MINIMISE || k == X_MAXIMISE;
        if (c->nextra[k] > 0 || (goal && cmd_goal) || k == X_ANALYSIS)
            continue;
        if (s->n[k] == CLI_EXTRA_VALUES || (s->n[k] && !design_extras[k].repeat))
            return bad("%s: design.%s: given more than once", c->scene->path,
                       o->key);
        given *g = &s->g[k][s->n[k]++];
        g->text = o->value;
        snprintf(g->src, sizeof g->src, "%s: design.%s (line %d)",
                 c->scene->path, o->key, o->line);
    }
    for (int k = 0; k <= X_FIN_STEP; k++) {
        if (c->nextra[k] == 0)
            continue;
        s->n[k] = c->nextra[k];
        for (int i = 0; i < c->nextra[k]; i++) {
            s->g[k][i].text = c->extra[k][i];
            snprintf(s->g[k][i].src, sizeof s->g[k][i].src, "--%s",
                     design_extras[k].name);
        }
    }
    return 0;
}

typedef struct design_state {
    ts_design_spec spec;
    settings settings;
} design_state;

static int design_prepare(cli_run *c)
{
    design_state *st = calloc(1, sizeof *st);
    if (!st) {
        fprintf(stderr, "towstab: error: design: out of memory\n");
        return EXIT_FAILED;
    }
    c->state = st;
    ts_design_spec *sp = &st->spec;
    sp->rq = c->rq;
    sp->rq.progress = NULL;
    settings *se = &st->settings;
    if (gather(c, se))
        return EXIT_BADINPUT;
    sp->nfree = se->n[X_FREE];
    if (sp->nfree == 0)
        return bad("expected at least one --free PATH=LOWER:UPPER (e.g. "
                   "--free cables.main.length=100m:800m), or free: in the "
                   "scene's design section%s%s", "", "");
    if (sp->nfree > TS_DESIGN_MAX_FREE)
        return bad("at most 8 free values (%s)%s", se->g[X_FREE][0].src, "");
    for (int i = 0; i < sp->nfree; i++)
        if (parse_free(c, &se->g[X_FREE][i], &sp->free[i]))
            return EXIT_BADINPUT;
    int ngoals = se->n[X_TARGET] + se->n[X_MINIMISE] + se->n[X_MAXIMISE];
    if (ngoals > 1)
        return bad("give one of --target, --minimise and --maximise (in the "
                   "scene: target, minimise, maximise)%s%s", "", "");
    char unit[TS_VALUE_UNIT_MAX];
    if (se->n[X_TARGET]) {
        const given *g = &se->g[X_TARGET][0];
        const char *t = g->text, *eq = strchr(t, '=');
        if (!eq || eq == t)
            return bad("%s: expected NAME=Q (e.g. fish.z=300m), got '%s'",
                       g->src, t);
        sp->goal.kind = TS_DESIGN_TARGET;
        snprintf(sp->goal.name, sizeof sp->goal.name, "%.*s", (int)(eq - t),
                 t);
        char where[TS_VALUE_NAME_MAX + 620];
        snprintf(where, sizeof where, "%s %s", g->src, sp->goal.name);
        if (value_unit(c, g->src, sp->goal.name, unit, sizeof unit) ||
            quantity(c, where, eq + 1, unit, &sp->goal.target))
            return EXIT_BADINPUT;
    } else if (ngoals == 1) {
        int k = se->n[X_MINIMISE] ? X_MINIMISE : X_MAXIMISE;
        sp->goal.kind = k == X_MINIMISE ? TS_DESIGN_MINIMISE
                                        : TS_DESIGN_MAXIMISE;
        snprintf(sp->goal.name, sizeof sp->goal.name, "%s",
                 se->g[k][0].text);
        if (value_unit(c, se->g[k][0].src, sp->goal.name, unit, sizeof unit))
            return EXIT_BADINPUT;
    }
    sp->nconstraints = se->n[X_CONSTRAINT];
    if (sp->nconstraints > TS_DESIGN_MAX_CONSTRAINTS)
        return bad("at most 8 constraints (%s)%s",
                   se->g[X_CONSTRAINT][0].src, "");
    for (int i = 0; i < sp->nconstraints; i++)
        if (parse_constraint(c, &se->g[X_CONSTRAINT][i],
                             &sp->constraints[i]))
            return EXIT_BADINPUT;
    if (se->n[X_METHOD]) {
        const char *m = se->g[X_METHOD][0].text;
        if (!strcmp(m, "cobyla"))
            sp->method = TS_DESIGN_COBYLA;
        else if (!strcmp(m, "bobyqa"))
            sp->method = TS_DESIGN_BOBYQA;
        else if (!strcmp(m, "slsqp"))
            sp->method = TS_DESIGN_SLSQP;
        else
            return bad("%s: expected cobyla, bobyqa or slsqp, got '%s'",
                       se->g[X_METHOD][0].src, m);
    }
    long v = 0;
    char what[700];
    snprintf(what, sizeof what, "design: %s", se->g[X_MAX_EVALS][0].src);
    if (se->n[X_MAX_EVALS] &&
        cli_parse_int(what, se->g[X_MAX_EVALS][0].text, 1, 100000, &v))
        return EXIT_BADINPUT;
    sp->max_evals = (int)v;
    if (se->n[X_TARGET_TOL]) {
        char *end;
        const char *t = se->g[X_TARGET_TOL][0].text;
        sp->target_rtol = strtod(t, &end);
        if (end == t || *end || !(sp->target_rtol > 0 &&
                                  sp->target_rtol < 1))
            return bad("%s: expected a fraction in (0, 1), got '%s'",
                       se->g[X_TARGET_TOL][0].src, t);
    }
    if (se->n[X_FIN_STEP] &&
        quantity(c, se->g[X_FIN_STEP][0].src, se->g[X_FIN_STEP][0].text, "m",
                 &sp->fin_step))
        return EXIT_BADINPUT;
    sp->progress = cli_progress;
    ts_err err = {0};
    int rc = ts_design_check(c->scene->system, sp, &err);
    if (rc) {
        fprintf(stderr, "towstab: error: design: %s\n", err.msg);
        return EXIT_BADINPUT;
    }
    return 0;
}

static void design_release(cli_run *c)
{
    free(c->state);
    c->state = NULL;
}

static void print_value(const char *label, const ts_value *v,
                        const ts_display *d)
{
    char e[128];
    cli_value_error(v, d, e, sizeof e);
    printf("%-28s %.10g %s\n", label, cli_value_shown(v, d), e);
}

/* x in `unit` as the display shows it, its unit into u. */
static double shown(const ts_display *d, const char *unit, double x,
                    char *u, size_t size)
{
    return ts_display_convert(ts_display_or_si(d), unit, x, u, size);
}

static void print_study(const ts_design *d, const ts_display *dsp)
{
    char u[64];
    const ts_design_spec *s = &d->spec;
    printf("design: %s, %d free value%s, %s at every evaluation\n",
           ts_design_method_name(s->method), s->nfree,
           s->nfree == 1 ? "" : "s", ts_analysis_name(s->rq.kind));
    double wall = 0;
    int failed = 0;
    for (int k = 0; k < d->neval; k++) {
        wall += d->history[k].wall_s;
        failed += d->history[k].status != TS_OK;
    }
    printf("iterations: %d analysis runs (%d failed), %.3f s; NLopt: %s; "
           "%ld kernel evaluations in all, %.3f s with the final run "
           "(%.3f s)\n",
           d->neval, failed, wall, d->nlopt_reason, d->evaluations,
           d->wall_s, d->final_wall_s);
    printf("\n%-28s %14s %14s %14s %14s\n", "free value", "optimum",
           "start", "lower", "upper");
    for (int i = 0; i < s->nfree; i++) {
        const ts_design_var *f = &s->free[i];
        printf("%-28s %14.8g %14.8g %14.8g %14.8g %s%s\n", f->path, d->x[i],
               f->start, f->lower, f->upper, d->unit[i],
               d->at_bound[i] < 0   ? "  AT THE LOWER BOUND"
               : d->at_bound[i] > 0 ? "  AT THE UPPER BOUND"
                                    : "");
    }
    printf("\n");
    char label[TS_VALUE_NAME_MAX + 40];
    if (s->goal.kind == TS_DESIGN_TARGET) {
        snprintf(label, sizeof label, "target %s", s->goal.name);
        print_value(label, &d->goal_value, dsp);
        double sc = s->goal.target != 0 ? fabs(s->goal.target) : 1.0;
        const char *gu = d->goal_value.unit;
        double t = shown(dsp, gu, s->goal.target, u, sizeof u);
        printf("  wanted %.10g %s: %s, misfit %.3g %s (tolerance %.3g %s)\n",
               t, u, d->reached ? "reached" : "NOT REACHED",
               shown(dsp, gu, d->goal_misfit, u, sizeof u), u,
               shown(dsp, gu, s->target_rtol * sc, u, sizeof u), u);
    } else if (s->goal.kind != TS_DESIGN_NONE) {
        snprintf(label, sizeof label, "%s %s",
                 ts_design_goal_name(s->goal.kind), s->goal.name);
        print_value(label, &d->goal_value, dsp);
    }
    for (int i = 0; i < s->nconstraints; i++) {
        const ts_design_constraint *k = &s->constraints[i];
        snprintf(label, sizeof label, "constraint %s", k->name);
        print_value(label, &d->constraint_value[i], dsp);
        double b = shown(dsp, d->constraint_value[i].unit, k->bound, u,
                         sizeof u);
        printf("  wanted %s %.10g %s: %s\n", k->upper ? "<=" : ">=", b, u,
               d->constraint_met[i] ? "met" : "NOT MET");
    }
    if (!d->success)
        printf("design: the %s cannot be met within the bounds; the closest "
               "point is reported\n",
               s->goal.kind == TS_DESIGN_TARGET && !d->reached
                   ? "target" : "constraints");
    printf("\nthe single run at the optimum:\n");
}

static int design_execute(cli_run *c)
{
    design_state *st = c->state;
    ts_design *d = NULL;
    ts_err err = {0};
    int rc = ts_design_run(c->scene->system, &st->spec, &d, &err);
    cli_progress_done();
    if (!d)
        return cli_report(&err, rc);
    print_study(d, &c->display);
    if (d->result) {
        cli_run pc = *c;
        pc.cmd = d->spec.rq.kind == TS_ANALYSIS_MODES ? &cli_cmd_modes
                                                      : &cli_cmd_equilibrium;
        pc.state = NULL;
        pc.cmd->print(&pc, d->result);
    }
    int status = 0;
    if (rc != TS_OK)
        status = cli_report(&err, rc);
    else if (!d->success)
        status = EXIT_FAILED;
    if (c->json) {
        json_t *j = ts_design_json(d);
        status = cli_put_json(j, c->json, status);
    }
    ts_design_free(d);
    return status;
}

/* 1 when the command-line option `arg` ("--links") takes a value as the
 * next argument: an extra, an output, or a row of the equilibrium or
 * modes table that is not a flag. */
static int takes_value(const char *arg)
{
    const char *name = arg + 2;
    if (strchr(name, '='))
        return 0;
    for (int k = 0; design_extras[k].name; k++)
        if (!strcmp(name, design_extras[k].name))
            return design_extras[k].has_arg;
    static const char *const outputs[] = {"json", "csv", "plot", "units"};
    for (int k = 0; k < 4; k++)
        if (!strcmp(name, outputs[k]))
            return 1;
    static const ts_analysis_kind kinds[2] = {TS_ANALYSIS_EQUILIBRIUM,
                                              TS_ANALYSIS_MODES};
    for (int j = 0; j < 2; j++) {
        int n;
        const ts_option *t = ts_options(kinds[j], &n);
        for (int i = 0; i < n; i++) {
            char cli[TS_NAME_MAX];
            ts_option_cli_name(&t[i], cli, sizeof cli);
            if (!strcmp(name, cli))
                return t[i].type != TS_OPT_BOOL;
        }
    }
    return 0;
}

/* The analysis the scene's design section names (its `analysis`), or
 * NULL: the scene is the argument that is neither an option nor an
 * option's value. Its errors are left to the run proper. */
static int scene_analysis(int argc, char **argv, char *out, size_t size)
{
    const char *path = NULL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--")) {
            path = i + 1 < argc ? argv[i + 1] : NULL;
            break;
        }
        if (a[0] == '-' && a[1]) {
            i += a[1] == '-' && takes_value(a);
            continue;
        }
        path = a;
    }
    if (!path || !strcmp(path, "-"))
        return 0;
    ts_units *u = ts_units_alloc(NULL);
    ts_scene *sc = u ? ts_scene_load(path, u, NULL) : NULL;
    const ts_scene_option *o =
        sc && sc->design ? ts_scene_analysis_option(sc->design, "analysis")
                         : NULL;
    if (o)
        snprintf(out, size, "%s", o->value);
    ts_scene_free(sc);
    ts_units_free(u);
    return o != NULL;
}

static int design_main(int argc, char **argv)
{
    int kind = TS_ANALYSIS_EQUILIBRIUM;
    const char *name = cli_analysis_arg(argc, argv);
    char from_scene[TS_NAME_MAX + 64];
    if (!name && scene_analysis(argc, argv, from_scene, sizeof from_scene))
        name = from_scene;
    if (name) {
        kind = ts_analysis_find(name);
        if (kind != TS_ANALYSIS_EQUILIBRIUM && kind != TS_ANALYSIS_MODES) {
            fprintf(stderr, "towstab: error: design: %s: '%s' is not "
                            "an analysis to design with; expected "
                            "equilibrium or modes\n",
                    name == from_scene ? "the scene's design.analysis"
                                       : "--analysis", name);
            return EXIT_BADINPUT;
        }
    }
    cli_command cmd = {"design",
                       "scene values that meet a target or optimum under "
                       "constraints (NLopt)",
                       kind, NULL, design_prepare, NULL, NULL, design_release,
                       NULL, design_extras, design_execute};
    return cli_main(&cmd, argc, argv);
}

const cli_command cli_cmd_design = {
    "design",
    "scene values that meet a target or optimum under constraints (NLopt)",
    -1, design_main, NULL, NULL, NULL, NULL, NULL, NULL, NULL};
