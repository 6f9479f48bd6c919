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

typedef struct design_state {
    ts_design_spec spec;
} design_state;

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
    ts_err err = {0};
    int rc;
    if (unit[0] && strcmp(unit, "1")) {
        rc = ts_units_parse(c->units, text, unit, where, out, &err);
    } else {
        char *end;
        *out = strtod(text, &end);
        while (*end == ' ')
            end++;
        rc = end == text || *end || !isfinite(*out) ? TS_EINVAL : TS_OK;
        if (rc)
            ts_fail(&err, rc, "%s: expected a plain number, got '%s'", where,
                    text);
    }
    if (rc)
        fprintf(stderr, "towstab: error: design: %s\n", err.msg);
    return rc ? EXIT_BADINPUT : 0;
}

/* --free PATH=LOWER:UPPER[:START]. */
static int parse_free(const cli_run *c, const char *text, ts_design_var *f)
{
    const char *eq = strchr(text, '=');
    if (!eq || eq == text)
        return bad("--free: expected PATH=LOWER:UPPER[:START] (e.g. "
                   "cables.main.length=100m:800m), got '%s'%s", text, "");
    snprintf(f->path, sizeof f->path, "%.*s", (int)(eq - text), text);
    char unit[TS_PARAM_UNIT_MAX];
    ts_err err = {0};
    if (ts_param_unit(c->scene->system, f->path, unit, sizeof unit, &err)) {
        fprintf(stderr, "towstab: error: design: --free: %s\n", err.msg);
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
    if (nf < 2 || nf > 3)
        return bad("--free %s: expected LOWER:UPPER or LOWER:UPPER:START, "
                   "got '%s'", f->path, eq + 1);
    char where[TS_PARAM_PATH_MAX + 16];
    snprintf(where, sizeof where, "--free %s", f->path);
    double *dst[3] = {&f->lower, &f->upper, &f->start};
    f->start = NAN;
    for (int i = 0; i < nf; i++)
        if (quantity(c, where, field[i], unit, dst[i]))
            return EXIT_BADINPUT;
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
static int parse_constraint(const cli_run *c, const char *text,
                            ts_design_constraint *k)
{
    const char *op = strstr(text, "<=");
    k->upper = 1;
    if (!op) {
        op = strstr(text, ">=");
        k->upper = 0;
    }
    if (!op || op == text)
        return bad("--constraint: expected NAME<=Q or NAME>=Q (e.g. "
                   "'top_tension<=40kN'), got '%s'%s", text, "");
    snprintf(k->name, sizeof k->name, "%.*s", (int)(op - text), text);
    char unit[TS_VALUE_UNIT_MAX];
    if (value_unit(c, "--constraint", k->name, unit, sizeof unit))
        return EXIT_BADINPUT;
    char where[TS_VALUE_NAME_MAX + 16];
    snprintf(where, sizeof where, "--constraint %s", k->name);
    return quantity(c, where, op + 2, unit, &k->bound);
}

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
    sp->nfree = c->nextra[X_FREE];
    if (sp->nfree == 0)
        return bad("expected at least one --free PATH=LOWER:UPPER (e.g. "
                   "--free cables.main.length=100m:800m)%s%s", "", "");
    if (sp->nfree > TS_DESIGN_MAX_FREE)
        return bad("at most 8 --free%s%s", "", "");
    for (int i = 0; i < sp->nfree; i++)
        if (parse_free(c, c->extra[X_FREE][i], &sp->free[i]))
            return EXIT_BADINPUT;
    int ngoals = c->nextra[X_TARGET] + c->nextra[X_MINIMISE] +
                 c->nextra[X_MAXIMISE];
    if (ngoals > 1)
        return bad("give one of --target, --minimise and --maximise%s%s", "",
                   "");
    char unit[TS_VALUE_UNIT_MAX];
    if (c->nextra[X_TARGET]) {
        const char *t = c->extra[X_TARGET][0], *eq = strchr(t, '=');
        if (!eq || eq == t)
            return bad("--target: expected NAME=Q (e.g. fish.z=300m), got "
                       "'%s'%s", t, "");
        sp->goal.kind = TS_DESIGN_TARGET;
        snprintf(sp->goal.name, sizeof sp->goal.name, "%.*s", (int)(eq - t),
                 t);
        char where[TS_VALUE_NAME_MAX + 16];
        snprintf(where, sizeof where, "--target %s", sp->goal.name);
        if (value_unit(c, "--target", sp->goal.name, unit, sizeof unit) ||
            quantity(c, where, eq + 1, unit, &sp->goal.target))
            return EXIT_BADINPUT;
    } else if (ngoals == 1) {
        int k = c->nextra[X_MINIMISE] ? X_MINIMISE : X_MAXIMISE;
        sp->goal.kind = k == X_MINIMISE ? TS_DESIGN_MINIMISE
                                        : TS_DESIGN_MAXIMISE;
        snprintf(sp->goal.name, sizeof sp->goal.name, "%s", c->extra[k][0]);
        if (value_unit(c, k == X_MINIMISE ? "--minimise" : "--maximise",
                       sp->goal.name, unit, sizeof unit))
            return EXIT_BADINPUT;
    }
    sp->nconstraints = c->nextra[X_CONSTRAINT];
    if (sp->nconstraints > TS_DESIGN_MAX_CONSTRAINTS)
        return bad("at most 8 --constraint%s%s", "", "");
    for (int i = 0; i < sp->nconstraints; i++)
        if (parse_constraint(c, c->extra[X_CONSTRAINT][i],
                             &sp->constraints[i]))
            return EXIT_BADINPUT;
    if (c->nextra[X_METHOD]) {
        const char *m = c->extra[X_METHOD][0];
        if (!strcmp(m, "cobyla"))
            sp->method = TS_DESIGN_COBYLA;
        else if (!strcmp(m, "bobyqa"))
            sp->method = TS_DESIGN_BOBYQA;
        else if (!strcmp(m, "slsqp"))
            sp->method = TS_DESIGN_SLSQP;
        else
            return bad("--method: expected cobyla, bobyqa or slsqp, got "
                       "'%s'%s", m, "");
    }
    long v = 0;
    if (c->nextra[X_MAX_EVALS] &&
        cli_parse_int("design: --max-evals", c->extra[X_MAX_EVALS][0], 1,
                      100000, &v))
        return EXIT_BADINPUT;
    sp->max_evals = (int)v;
    if (c->nextra[X_TARGET_TOL]) {
        char *end;
        const char *t = c->extra[X_TARGET_TOL][0];
        sp->target_rtol = strtod(t, &end);
        if (end == t || *end || !(sp->target_rtol > 0 &&
                                  sp->target_rtol < 1))
            return bad("--target-tol: expected a fraction in (0, 1), got "
                       "'%s'%s", t, "");
    }
    if (c->nextra[X_FIN_STEP] &&
        quantity(c, "--fin-step", c->extra[X_FIN_STEP][0], "m",
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

static int design_main(int argc, char **argv)
{
    int kind = TS_ANALYSIS_EQUILIBRIUM;
    const char *name = cli_analysis_arg(argc, argv);
    if (name) {
        kind = ts_analysis_find(name);
        if (kind != TS_ANALYSIS_EQUILIBRIUM && kind != TS_ANALYSIS_MODES) {
            fprintf(stderr, "towstab: error: design: --analysis: '%s' is not "
                            "an analysis to design with; expected "
                            "equilibrium or modes\n", name);
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
