/* cli_sim.c: the settings of a time-domain simulation from the command
 * line and scene entries (cli_sim.h). */
#include "cli_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "towstab/compare.h"
#include "towstab/report.h"

/* Scene option keys, in the order above. */
const char *const cli_sim_arg_keys[SIM_A_N] = {
    "t_end", "sample", "initial", "integrator", "rtol", "atol", "h_min",
    "max_steps", "transient", "output", "linear_method", "kinematics",
    "excite", "manoeuvre", "compare", "linear", "csv"};
/* The same as command-line options. */
const char *const cli_sim_arg_opts[SIM_A_N] = {
    "--t-end", "--sample", "--initial", "--integrator", "--rtol", "--atol",
    "--h-min", "--max-steps", "--transient", "--output", "--linear-method",
    "--kinematics", "--excite", "--manoeuvre", "--compare", "--linear",
    "--csv"};

/* ---- parsing helpers --------------------------------------------------- */

static int parse_q(const cli_ctx *ctx, const cli_sim_args *a, int i,
                   const char *unit, double *v, ts_err *err)
{
    return ts_units_parse(ctx->units, a->val[i], unit, a->where[i], v, err);
}

static int parse_flag(const cli_sim_args *a, int i, int *v, ts_err *err)
{
    const char *s = a->val[i];
    if (!s) {
        *v = 0;
        return TS_OK;
    }
    if (!strcmp(s, "true") || !strcmp(s, "yes") || !strcmp(s, "1"))
        *v = 1;
    else if (!strcmp(s, "false") || !strcmp(s, "no") || !strcmp(s, "0"))
        *v = 0;
    else
        return ts_fail(err, TS_EINVAL, "%s: expected true or false, got '%s'",
                       a->where[i], s);
    return TS_OK;
}

/* Add every ';'-separated spec of `text` to ex. */
static int add_specs(ts_excitation *ex, const char *text, const char *where,
                     int manoeuvre, const ts_units *units, ts_err *err)
{
    char *copy = strdup(text);
    if (!copy)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", where);
    int rc = TS_OK;
    char *save = NULL;
    for (char *p = strtok_r(copy, ";", &save); p && !rc;
         p = strtok_r(NULL, ";", &save)) {
        while (*p == ' ')
            p++;
        if (!*p)
            continue;
        int n = ts_excitation_nsignals(ex);
        rc = ts_excitation_parse(ex, p, units, where, err);
        if (rc == TS_EIO)
            rc = err->code = TS_EINVAL; /* a missing series file is bad
                                           input, like a missing scene */
        if (!rc) {
            const ts_signal *s = ts_excitation_signal(ex, n);
            int is_man = s->axis == TS_AXIS_SPEED ||
                         s->axis == TS_AXIS_TURN_RATE;
            if (is_man != manoeuvre)
                rc = ts_fail(err, TS_EINVAL, "%s: '%s' is %s; give it with "
                             "%s", where, ts_axis_name(s->axis),
                             is_man ? "a manoeuvre of the ship"
                                    : "a tow-point excitation",
                             is_man ? "--manoeuvre (scene key manoeuvre)"
                                    : "--excite (scene key excite)");
        }
    }
    free(copy);
    return rc;
}


static int parse_initial(const cli_ctx *ctx, const cli_sim_args *a,
                         cli_sim_setup *s, ts_err *err)
{
    const char *v = a->val[SIM_A_INITIAL], *w = a->where[SIM_A_INITIAL];
    s->init = SIM_INIT_EQ;
    snprintf(s->init_text, sizeof s->init_text, "equilibrium");
    if (!v || !strcmp(v, "equilibrium"))
        return TS_OK;
    if (!strncmp(v, "shape:", 6)) {
        s->init = SIM_INIT_SHAPE;
        s->shape_path = v + 6;
        snprintf(s->init_text, sizeof s->init_text, "shape from %s", v + 6);
        return *s->shape_path ? TS_OK
                              : ts_fail(err, TS_EINVAL, "%s: shape: needs a "
                                        "file name", w);
    }
    if (strncmp(v, "released", 8) || (v[8] != '\0' && v[8] != ':'))
        return ts_fail(err, TS_EINVAL, "%s: '%s' is not an initial state; "
                       "expected equilibrium, released[:theta1=A,theta2=B] "
                       "or shape:FILE", w, v);
    s->init = SIM_INIT_RELEASED;
    s->theta1 = s->theta2 = 0.0;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", v[8] ? v + 9 : "");
    char *save = NULL;
    for (char *p = strtok_r(buf, ",", &save); p;
         p = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(p, '=');
        if (eq)
            *eq = '\0';
        double *dst = !strcmp(p, "theta1") ? &s->theta1
                      : !strcmp(p, "theta2") ? &s->theta2 : NULL;
        if (!eq || !dst)
            return ts_fail(err, TS_EINVAL, "%s: released: expected theta1= "
                           "and/or theta2= (angles), got '%s'", w, p);
        char where[160];
        snprintf(where, sizeof where, "%s: released: %s", w, p);
        int rc = ts_units_parse(ctx->units, eq + 1, "rad", where, dst, err);
        if (rc)
            return rc;
    }
    snprintf(s->init_text, sizeof s->init_text,
             "released straight at rest, theta1 %.6g deg, theta2 %.6g deg",
             s->theta1 * 180 / M_PI, s->theta2 * 180 / M_PI);
    return TS_OK;
}

/* Options into a setup (system-independent parts). */
static int parse_setup(const cli_ctx *ctx, const cli_sim_args *a,
                       const ts_excitation *ex, cli_sim_setup *s, ts_err *err)
{
    ts_sim_opts_default(&s->o);
    s->o.t_end = CLI_SIM_DEFAULT_T_END;
    s->o.progress = cli_progress; /* SIGINT and SIGTERM stop the run */
    int rc = TS_OK;
    if (a->val[SIM_A_T_END] &&
        (rc = parse_q(ctx, a, SIM_A_T_END, "s", &s->o.t_end, err)))
        return rc;
    if (!(s->o.t_end > 0))
        return ts_fail(err, TS_EINVAL, "%s: the run length must be > 0 s, "
                       "got %g s", a->where[SIM_A_T_END], s->o.t_end);
    if (a->val[SIM_A_SAMPLE]) {
        if ((rc = parse_q(ctx, a, SIM_A_SAMPLE, "s", &s->o.dt_sample, err)))
            return rc;
        if (!(s->o.dt_sample > 0))
            return ts_fail(err, TS_EINVAL, "%s: the sample interval must be "
                           "> 0 s, got %g s", a->where[SIM_A_SAMPLE],
                           s->o.dt_sample);
        if (s->o.dt_sample > s->o.t_end)
            return ts_fail(err, TS_EINVAL, "%s: the sample interval %g s is "
                           "longer than the run (%g s)",
                           a->where[SIM_A_SAMPLE],
                           s->o.dt_sample, s->o.t_end);
    } else {
        double dt = CLI_SIM_DEFAULT_SAMPLE;
        int idx;
        if (ts_excitation_periodic(ex, &idx)) {
            double f = ts_excitation_signal(ex, idx)->frequency;
            dt = fmin(dt, 1.0 / (CLI_SIM_DEFAULT_SAMPLES_PER_PERIOD * f));
        }
        s->o.dt_sample = fmin(dt, s->o.t_end);
    }
    if (a->val[SIM_A_INTEGRATOR] &&
        ts_integrator_parse(a->val[SIM_A_INTEGRATOR], &s->o.integrator))
        return ts_fail(err, TS_EINVAL, "%s: '%s' is not an integrator; "
                       "expected rk8pd, rkf45, rk4imp, bsimp, msbdf or esdirk",
                       a->where[SIM_A_INTEGRATOR], a->val[SIM_A_INTEGRATOR]);
    struct { int i; double *dst; double lo; int strict; } nums[] = {
        {SIM_A_RTOL, &s->o.rel_tol, TS_SIM_RTOL_MIN, 0},
        {SIM_A_ATOL, &s->o.abs_tol, 0, 1}};
    for (int j = 0; j < 2; j++) {
        const char *t = a->val[nums[j].i];
        if (!t)
            continue;
        char *end;
        double v = strtod(t, &end);
        int ok = end != t && *end == '\0' && isfinite(v) && v < 1 &&
                 (nums[j].strict ? v > nums[j].lo : v >= nums[j].lo);
        if (!ok)
            return ts_fail(err, TS_EINVAL, "%s: expected a number in %s%g, "
                           "1), got '%s'", a->where[nums[j].i],
                           nums[j].strict ? "(" : "[", nums[j].lo, t);
        *nums[j].dst = v;
    }
    if (a->val[SIM_A_H_MIN]) {
        if ((rc = parse_q(ctx, a, SIM_A_H_MIN, "s", &s->o.h_min, err)))
            return rc;
        if (!(s->o.h_min >= 0))
            return ts_fail(err, TS_EINVAL, "%s: must be >= 0 s, got %g s",
                           a->where[SIM_A_H_MIN], s->o.h_min);
    }
    if (a->val[SIM_A_MAX_STEPS]) {
        char *end;
        long v = strtol(a->val[SIM_A_MAX_STEPS], &end, 10);
        if (end == a->val[SIM_A_MAX_STEPS] || *end || v < 1)
            return ts_fail(err, TS_EINVAL, "%s: expected a whole number >= "
                           "1, got '%s'", a->where[SIM_A_MAX_STEPS],
                           a->val[SIM_A_MAX_STEPS]);
        s->o.max_steps = v;
    }
    if (a->val[SIM_A_LINEAR_METHOD]) {
        const char *m = a->val[SIM_A_LINEAR_METHOD];
        if (!strcmp(m, "expm"))
            s->o.linear_method = TS_LINSIM_EXPM;
        else if (!strcmp(m, "ode"))
            s->o.linear_method = TS_LINSIM_ODE;
        else
            return ts_fail(err, TS_EINVAL, "%s: '%s' is not a linear method; "
                           "expected expm or ode",
                           a->where[SIM_A_LINEAR_METHOD],
                           m);
    }
    if (a->val[SIM_A_KINEMATICS]) {
        const char *m = a->val[SIM_A_KINEMATICS];
        if (!strcmp(m, "linear"))
            s->o.kinematics = TS_KIN_LINEAR;
        else if (!strcmp(m, "nonlinear"))
            s->o.kinematics = TS_KIN_NONLINEAR;
        else
            return ts_fail(err, TS_EINVAL, "%s: '%s' is not a kinematics; "
                           "expected linear or nonlinear",
                           a->where[SIM_A_KINEMATICS], m);
    }
    if ((rc = parse_flag(a, SIM_A_COMPARE, &s->compare, err)) ||
        (rc = parse_flag(a, SIM_A_LINEAR, &s->linear_only, err)))
        return rc;
    if (s->compare && s->linear_only)
        return ts_fail(err, TS_EINVAL, "%s: --linear runs the linear model "
                       "alone; --compare runs both: give one",
                       a->where[SIM_A_LINEAR]);
    s->transient = s->o.t_end / 2;
    if (a->val[SIM_A_TRANSIENT]) {
        if ((rc = parse_q(ctx, a, SIM_A_TRANSIENT, "s", &s->transient, err)))
            return rc;
        if (!(s->transient >= 0) || !(s->transient < s->o.t_end))
            return ts_fail(err, TS_EINVAL, "%s: must be in [0, %g) s (the "
                           "run length), got %g s", a->where[SIM_A_TRANSIENT],
                           s->o.t_end, s->transient);
    }
    if ((rc = ts_sim_opts_check(&s->o, err)))
        return rc;
    return parse_initial(ctx, a, s, err);
}

void cli_sim_prep_free(cli_sim_prep *p)
{
    ts_excitation_free(p->ex);
    ts_system_free(p->sys);
}

/* Build the system and parse every setting. Prints nothing; the message
 * is in err. */
int cli_sim_prepare(const cli_ctx *ctx, const cli_sim_args *a,
                   const cli_settings *cs, cli_sim_prep *p, ts_err *err)
{
    memset(p, 0, sizeof *p);
    cli_sim_setup *s = &p->s;
    p->sys = cli_system(ctx->scene, ctx->units, cs, &p->eo, err);
    if (!p->sys)
        return err->code ? err->code : TS_ENOMEM;
    ts_system *sys = p->sys;
    p->ex = ts_excitation_alloc(err);
    if (!p->ex)
        return TS_ENOMEM;
    int rc = TS_OK;
    for (int m = 0; m < 2 && !rc; m++)
        for (int i = 0; i < a->nspecs[m] && !rc; i++)
            rc = add_specs(p->ex, a->specs[m][i],
                           a->where[m ? SIM_A_MANOEUVRE : SIM_A_EXCITE], m,
                           ctx->units, err);
    if (!rc)
        rc = parse_setup(ctx, a, p->ex, s, err);
    if (!rc && (rc = ts_excitation_check_span(p->ex, s->o.t_end, err)))
        ts_err_prefix(err, "%s: ", a->where[SIM_A_EXCITE]);
    /* Loads the excitation or a manoeuvre makes overflow: refused here,
     * naming the option (the library refuses them too, naming only the
     * input). */
    if (!rc) {
        ts_frame f0 = {sys->tow.speed, sys->tow.turn_rate, 0, 0,
                       {sys->env.current[0], sys->env.current[1],
                        sys->env.current[2]}};
        ts_motion_bound mb;
        ts_excitation_bound(p->ex, &f0, &mb);
        if ((rc = ts_system_check_loads(sys, &mb, err))) {
            mb.tow_speed = mb.tow_accel = 0.0;
            ts_motion_bound st;
            ts_motion_bound_steady(sys, &st);
            int i = ts_system_check_loads(sys, &mb, NULL) ? SIM_A_MANOEUVRE
                                                          : SIM_A_EXCITE;
            if (ts_system_check_loads(sys, &st, NULL))
                ts_err_prefix(err, "simulate: ");
            else
                ts_err_prefix(err, "%s: ", a->where[i]);
        }
    }
    if (!rc) {
        char def[2 * TS_NAME_MAX + 4];
        const char *name = a->val[SIM_A_OUTPUT];
        if (!name) {
            int node = sys->nnodes - 1;
            for (int b = sys->nbodies - 1; b >= 0; b--)
                if (sys->bodies[b].type == TS_BODY_SPHERE)
                    node = ts_system_body_node(sys, b);
            ts_system_node_name(sys, node, def, sizeof def - 2);
            strcat(def, ".z");
            name = def;
        }
        rc = ts_response_output_find(sys, name, &s->out, err);
        if (rc)
            ts_err_prefix(err, "%s: ", a->where[SIM_A_OUTPUT]);
        else if (s->out.kind != TS_OUT_POSITION)
            rc = ts_fail(err, TS_EINVAL, "%s: '%s' is a tension; the "
                         "simulation reports positions <node>.x|y|z",
                         a->where[SIM_A_OUTPUT], name);
    }
    int use_linear = s->compare || s->linear_only;
    const char *lw = a->where[s->compare ? SIM_A_COMPARE : SIM_A_LINEAR];
    if (!rc && use_linear && s->init != SIM_INIT_EQ)
        rc = ts_fail(err, TS_EINVAL, "%s: the linear model starts at the "
                     "equilibrium, so %s needs the initial state "
                     "'equilibrium'", a->where[SIM_A_INITIAL], lw);
    if (!rc && use_linear && ts_excitation_has_manoeuvre(p->ex))
        rc = ts_fail(err, TS_EINVAL, "%s: the linear model has no frame "
                     "inputs; a manoeuvre can only be simulated nonlinearly "
                     "(drop %s)", a->where[SIM_A_MANOEUVRE], lw);
    /* What the comparison will need, checked before anything runs. */
    int idx;
    if (!rc && s->compare && ts_excitation_periodic(p->ex, &idx)) {
        double f = ts_excitation_signal(p->ex, idx)->frequency;
        double period = 1.0 / f;
        if (s->o.dt_sample > period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD)
            rc = ts_fail(err, TS_EINVAL, "%s: the sample interval %g s is "
                         "too coarse to compare at %g Hz; at most %g s (%d "
                         "samples per period)", a->where[SIM_A_SAMPLE],
                         s->o.dt_sample, f,
                         period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD,
                         TS_COMPARE_MIN_SAMPLES_PER_PERIOD);
        else if (s->o.t_end - s->transient < period)
            rc = ts_fail(err, TS_EINVAL, "%s: %g s are left after the "
                         "transient, less than one period (%g s) of the %g "
                         "Hz excitation", a->where[SIM_A_TRANSIENT],
                         s->o.t_end - s->transient, period, f);
    }
    return rc;
}

/* Fill arguments missing from the command line with the entry's. */
void cli_sim_args_from_entry(cli_sim_args *a, const ts_scene_analysis *e,
                            int index)
{
    for (int i = 0; i < SIM_A_N; i++) {
        const ts_scene_option *o =
            ts_scene_analysis_option(e, cli_sim_arg_keys[i]);
        if (!o)
            continue;
        if (i == SIM_A_EXCITE || i == SIM_A_MANOEUVRE) {
            int m = i == SIM_A_MANOEUVRE;
            if (a->nspecs[m] > 0)
                continue; /* the command line replaces the scene's */
            a->specs[m][a->nspecs[m]++] = o->value;
        } else if (a->val[i]) {
            continue;
        } else {
            a->val[i] = o->value;
        }
        snprintf(a->where[i], sizeof a->where[i], "analyses[%d].%s (line %d)",
                 index, cli_sim_arg_keys[i], o->line);
    }
}