/* cmd_simulate.c: `towstab simulate SCENE` and the `simulate` analysis of
 * a scene: nonlinear and linear time-domain runs, excitations, manoeuvres
 * and the linear-against-nonlinear comparison (doc/simulate.md).
 *
 * Settings come from the command line, else from the scene's first
 * `simulate` analysis entry, else defaults; so a scene can carry what a
 * case needs (the drop test's released shape, an excitation) and
 * `towstab simulate SCENE` reproduces it. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "towstab/compare.h"
#include "towstab/equilibrium.h"
#include "towstab/excitation.h"
#include "towstab/linearize.h"
#include "towstab/report.h"
#include "towstab/report_time.h"
#include "towstab/response.h"
#include "towstab/simulate.h"

/* Default sample interval when none is given, and the samples per period
 * it guarantees for a periodic excitation. */
#define DEFAULT_SAMPLE 0.05
#define DEFAULT_SAMPLES_PER_PERIOD 16
#define DEFAULT_T_END 10.0
/* Largest number of table rows printed (longer runs are strided). */
#define TABLE_ROWS 60
/* Link lengths of a shape file must match the scene's to this (relative). */
#define SHAPE_RTOL 1e-6
#define MAX_SPECS 32

enum {
    A_T_END, A_SAMPLE, A_INITIAL, A_INTEGRATOR, A_RTOL, A_ATOL, A_H_MIN,
    A_MAX_STEPS, A_TRANSIENT, A_OUTPUT, A_LINEAR_METHOD, A_KINEMATICS,
    A_EXCITE, A_MANOEUVRE, A_COMPARE, A_LINEAR, A_CSV, A_N
};
/* Scene option keys, in the order above. */
static const char *const arg_keys[A_N] = {
    "t_end", "sample", "initial", "integrator", "rtol", "atol", "h_min",
    "max_steps", "transient", "output", "linear_method", "kinematics",
    "excite", "manoeuvre", "compare", "linear", "csv"};
/* The same as command-line options. */
static const char *const arg_opts[A_N] = {
    "--t-end", "--sample", "--initial", "--integrator", "--rtol", "--atol",
    "--h-min", "--max-steps", "--transient", "--output", "--linear-method",
    "--kinematics", "--excite", "--manoeuvre", "--compare", "--linear",
    "--csv"};

typedef struct sim_args {
    const char *val[A_N];
    char where[A_N][128];
    /* --excite and --manoeuvre may repeat (and hold ';'-separated lists). */
    const char *specs[2][MAX_SPECS];
    int nspecs[2];
    int quiet;
    const char *json;   /* command line only */
} sim_args;

static void usage(FILE *f)
{
    fprintf(f,
        "usage: towstab simulate SCENE [options]\n"
        "  nonlinear (and linear) time-domain simulation; options not given\n"
        "  are taken from the scene's first 'simulate' analysis entry\n"
        "  --t-end T          run length (default %g s)\n"
        "  --sample DT        output interval (default %g s, finer for fast\n"
        "                     periodic excitations: %d samples per period)\n"
        "  --excite SPEC      tow-point excitation, repeatable, e.g.\n"
        "                     tow.heave:amplitude=0.1ft,frequency=0.25Hz\n"
        "                     AXIS tow.surge|tow.sway|tow.heave; type=sine\n"
        "                     (amplitude, frequency|period, phase), crank\n"
        "                     (+rod), step (amplitude, start, rise), ramp\n"
        "                     (+duration), csv (file=PATH: time_s,disp_m)\n"
        "  --manoeuvre SPEC   speed or turn_rate ramp/step, repeatable, e.g.\n"
        "                     turn_rate:to=0.5rad/s,duration=1s (or by=)\n"
        "  --initial S        equilibrium (default), released[:theta1=A,\n"
        "                     theta2=B] (straight, at rest; 0,0 = aft,\n"
        "                     horizontal), shape:FILE (node,x_m,y_m,z_m CSV)\n"
        "  --integrator M     rk8pd (default), rkf45, rk4imp, bsimp, msbdf\n"
        "  --rtol X, --atol X error tolerances (default 1e-6, 1e-9)\n"
        "  --h-min T          fail when the step falls below T (default 0)\n"
        "  --max-steps N      fail after N steps (default: no limit)\n"
        "  --linear           run the linear model only\n"
        "  --compare          run both and compare them\n"
        "  --linear-method M  expm (default) or ode\n"
        "  --kinematics K     linear (default) or nonlinear positions of the\n"
        "                     linear run\n"
        "  --transient T      discard T before comparing (default t_end/2)\n"
        "  --output NAME      compared and printed output (default: the\n"
        "                     first body's .z), e.g. sphere.z, cable.3.x\n"
        "  --json FILE        results and histories as JSON ('-': stdout)\n"
        "  --csv FILE         histories as CSV\n"
        "  --speed Q, --turn-rate Q, --links N, --method M, --tol X\n"
        "                     as for 'towstab equilibrium'\n"
        "  --quiet            summary only\n",
        DEFAULT_T_END, DEFAULT_SAMPLE, DEFAULT_SAMPLES_PER_PERIOD);
}

/* ---- parsing helpers --------------------------------------------------- */

static int parse_q(const cli_ctx *ctx, const sim_args *a, int i,
                   const char *unit, double *v, ts_err *err)
{
    return ts_units_parse(ctx->units, a->val[i], unit, a->where[i], v, err);
}

static int parse_flag(const sim_args *a, int i, int *v, ts_err *err)
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

/* Read "node,x_m,y_m,z_m[,...]" rows (a header first) into pos[3 nnodes],
 * matching node names. */
static int read_shape(const ts_system *sys, const char *path,
                      const char *where, double *pos, ts_err *err)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return ts_fail(err, TS_EINVAL, "%s: cannot read '%s': %s", where, path,
                       strerror(errno));
    char *seen = calloc((size_t)sys->nnodes, 1);
    char line[1024], name[2 * TS_NAME_MAX];
    int lineno = 0, rc = TS_OK;
    while (!rc && fgets(line, sizeof line, f)) {
        lineno++;
        line[strcspn(line, "\r\n")] = '\0';
        if (line[0] == '#' || line[0] == '\0')
            continue;
        if (lineno == 1 && !strncmp(line, "node,", 5))
            continue;
        char *c1 = strchr(line, ',');
        if (!c1) {
            rc = ts_fail(err, TS_EINVAL, "%s: %s line %d: expected "
                         "node,x_m,y_m,z_m", where, path, lineno);
            break;
        }
        *c1 = '\0';
        double v[3];
        char *p = c1 + 1, *end;
        for (int j = 0; j < 3 && !rc; j++) {
            v[j] = strtod(p, &end);
            if (end == p || !isfinite(v[j]) || (*end != ',' && *end != '\0'))
                rc = ts_fail(err, TS_EINVAL, "%s: %s line %d: coordinate %d "
                             "is not a number", where, path, lineno, j + 1);
            p = *end ? end + 1 : end;
        }
        int k = 0;
        for (; !rc && k < sys->nnodes; k++) {
            ts_report_node_name(sys, k, name, sizeof name);
            if (!strcmp(name, line))
                break;
        }
        if (!rc && k == sys->nnodes)
            rc = ts_fail(err, TS_EINVAL, "%s: %s line %d: '%.60s' is not a "
                         "node of the scene", where, path, lineno, line);
        if (!rc) {
            memcpy(pos + 3 * k, v, sizeof v);
            seen[k] = 1;
        }
    }
    fclose(f);
    for (int k = 1; !rc && k < sys->nnodes; k++)
        if (!seen[k]) {
            ts_report_node_name(sys, k, name, sizeof name);
            rc = ts_fail(err, TS_EINVAL, "%s: %s has no row for node '%s'",
                         where, path, name);
        }
    if (!rc && !seen[0])
        memcpy(pos, sys->tow.point, 3 * sizeof(double));
    free(seen);
    return rc;
}

/* ---- the run ----------------------------------------------------------- */

typedef struct sim_setup {
    ts_sim_opts o;
    double transient;
    int compare, linear_only;
    enum { INIT_EQ, INIT_RELEASED, INIT_SHAPE } init;
    double theta1, theta2;
    char init_text[256];
    const char *shape_path;
    ts_output out;
} sim_setup;

static int parse_initial(const cli_ctx *ctx, const sim_args *a, sim_setup *s,
                         ts_err *err)
{
    const char *v = a->val[A_INITIAL], *w = a->where[A_INITIAL];
    s->init = INIT_EQ;
    snprintf(s->init_text, sizeof s->init_text, "equilibrium");
    if (!v || !strcmp(v, "equilibrium"))
        return TS_OK;
    if (!strncmp(v, "shape:", 6)) {
        s->init = INIT_SHAPE;
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
    s->init = INIT_RELEASED;
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
static int parse_setup(const cli_ctx *ctx, const sim_args *a,
                       const ts_excitation *ex, sim_setup *s, ts_err *err)
{
    ts_sim_opts_default(&s->o);
    s->o.t_end = DEFAULT_T_END;
    int rc = TS_OK;
    if (a->val[A_T_END] &&
        (rc = parse_q(ctx, a, A_T_END, "s", &s->o.t_end, err)))
        return rc;
    if (!(s->o.t_end > 0))
        return ts_fail(err, TS_EINVAL, "%s: the run length must be > 0 s, "
                       "got %g s", a->where[A_T_END], s->o.t_end);
    if (a->val[A_SAMPLE]) {
        if ((rc = parse_q(ctx, a, A_SAMPLE, "s", &s->o.dt_sample, err)))
            return rc;
        if (!(s->o.dt_sample > 0))
            return ts_fail(err, TS_EINVAL, "%s: the sample interval must be "
                           "> 0 s, got %g s", a->where[A_SAMPLE],
                           s->o.dt_sample);
        if (s->o.dt_sample > s->o.t_end)
            return ts_fail(err, TS_EINVAL, "%s: the sample interval %g s is "
                           "longer than the run (%g s)", a->where[A_SAMPLE],
                           s->o.dt_sample, s->o.t_end);
    } else {
        double dt = DEFAULT_SAMPLE;
        int idx;
        if (ts_excitation_periodic(ex, &idx)) {
            double f = ts_excitation_signal(ex, idx)->frequency;
            dt = fmin(dt, 1.0 / (DEFAULT_SAMPLES_PER_PERIOD * f));
        }
        s->o.dt_sample = fmin(dt, s->o.t_end);
    }
    if (a->val[A_INTEGRATOR] &&
        ts_integrator_parse(a->val[A_INTEGRATOR], &s->o.integrator))
        return ts_fail(err, TS_EINVAL, "%s: '%s' is not an integrator; "
                       "expected rk8pd, rkf45, rk4imp, bsimp or msbdf",
                       a->where[A_INTEGRATOR], a->val[A_INTEGRATOR]);
    struct { int i; double *dst; double lo; int strict; } nums[] = {
        {A_RTOL, &s->o.rel_tol, TS_SIM_RTOL_MIN, 0},
        {A_ATOL, &s->o.abs_tol, 0, 1}};
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
    if (a->val[A_H_MIN]) {
        if ((rc = parse_q(ctx, a, A_H_MIN, "s", &s->o.h_min, err)))
            return rc;
        if (!(s->o.h_min >= 0))
            return ts_fail(err, TS_EINVAL, "%s: must be >= 0 s, got %g s",
                           a->where[A_H_MIN], s->o.h_min);
    }
    if (a->val[A_MAX_STEPS]) {
        char *end;
        long v = strtol(a->val[A_MAX_STEPS], &end, 10);
        if (end == a->val[A_MAX_STEPS] || *end || v < 1)
            return ts_fail(err, TS_EINVAL, "%s: expected a whole number >= "
                           "1, got '%s'", a->where[A_MAX_STEPS],
                           a->val[A_MAX_STEPS]);
        s->o.max_steps = v;
    }
    if (a->val[A_LINEAR_METHOD]) {
        const char *m = a->val[A_LINEAR_METHOD];
        if (!strcmp(m, "expm"))
            s->o.linear_method = TS_LINSIM_EXPM;
        else if (!strcmp(m, "ode"))
            s->o.linear_method = TS_LINSIM_ODE;
        else
            return ts_fail(err, TS_EINVAL, "%s: '%s' is not a linear method; "
                           "expected expm or ode", a->where[A_LINEAR_METHOD],
                           m);
    }
    if (a->val[A_KINEMATICS]) {
        const char *m = a->val[A_KINEMATICS];
        if (!strcmp(m, "linear"))
            s->o.kinematics = TS_KIN_LINEAR;
        else if (!strcmp(m, "nonlinear"))
            s->o.kinematics = TS_KIN_NONLINEAR;
        else
            return ts_fail(err, TS_EINVAL, "%s: '%s' is not a kinematics; "
                           "expected linear or nonlinear",
                           a->where[A_KINEMATICS], m);
    }
    if ((rc = parse_flag(a, A_COMPARE, &s->compare, err)) ||
        (rc = parse_flag(a, A_LINEAR, &s->linear_only, err)))
        return rc;
    if (s->compare && s->linear_only)
        return ts_fail(err, TS_EINVAL, "%s: --linear runs the linear model "
                       "alone; --compare runs both: give one",
                       a->where[A_LINEAR]);
    s->transient = s->o.t_end / 2;
    if (a->val[A_TRANSIENT]) {
        if ((rc = parse_q(ctx, a, A_TRANSIENT, "s", &s->transient, err)))
            return rc;
        if (!(s->transient >= 0) || !(s->transient < s->o.t_end))
            return ts_fail(err, TS_EINVAL, "%s: must be in [0, %g) s (the "
                           "run length), got %g s", a->where[A_TRANSIENT],
                           s->o.t_end, s->transient);
    }
    if ((rc = ts_sim_opts_check(&s->o, err)))
        return rc;
    return parse_initial(ctx, a, s, err);
}

static void print_stats(const char *what, const ts_sim_stats *st,
                        const char *method)
{
    printf("%s: %s, t = 0 .. %.6g s: %ld steps (%ld rejected), %ld "
           "evaluations, %ld Jacobians, %ld re-charts, %.3f s wall (%.4g "
           "simulated s per wall s)\n",
           what, method, st->t_reached, st->steps, st->rejected,
           st->evaluations, st->jacobians, st->recharts, st->wall_s,
           st->wall_s > 0 ? st->t_reached / st->wall_s : INFINITY);
}

static void print_table(const ts_system *sys, const ts_output *out,
                        const ts_history *nl, const ts_history *li)
{
    const ts_history *h = nl ? nl : li;
    if (!h || h->nsamples == 0)
        return;
    char name[2 * TS_NAME_MAX];
    ts_report_node_name(sys, out->node, name, sizeof name);
    int stride = (h->nsamples + TABLE_ROWS - 1) / TABLE_ROWS;
    printf("\n%10s %16s %16s %16s", "t [s]", "x [m]", "y [m]", "z [m]");
    if (nl && li)
        printf(" %16s", "linear");
    printf("    (%s%s%s)\n", name, nl ? "" : ", linear model",
           nl && li ? "; 'linear': the same coordinate of the linear run"
                    : "");
    size_t st = 3 * (size_t)h->nnodes;
    for (int i = 0; i < h->nsamples; i += stride) {
        const double *p = h->positions + st * i + 3 * (size_t)out->node;
        printf("%10.4f %16.9f %16.9f %16.9f", h->t[i], p[0], p[1], p[2]);
        if (nl && li && i < li->nsamples)
            printf(" %16.9f", li->positions[st * i + 3 * (size_t)out->node +
                                            out->comp]);
        printf("\n");
        if (i + stride >= h->nsamples && i != h->nsamples - 1)
            i = h->nsamples - 1 - stride; /* always show the last sample */
    }
    if (stride > 1)
        printf("(one sample in %d of %d shown; --csv for all)\n", stride,
               h->nsamples);
}

static void print_compare(const ts_compare *c)
{
    printf("\ncomparison of %s over t = %.6g .. %.6g s (%d samples; the "
           "transient before is discarded)\n",
           c->output.name, c->t_from, c->t_to, c->nsamples);
    if (c->periodic)
        printf("excitation %s %s, amplitude %.6g m, %.6g Hz\n",
               ts_axis_name(c->exc_axis), ts_signal_type_name(c->exc_type),
               c->exc_amplitude, c->exc_frequency_hz);
    printf("%-26s %16s %16s %16s\n", "", "linear", "nonlinear",
           "freq. response");
    printf("%-26s %16.6g %16.6g %16.6g\n", "amplitude ratio",
           c->linear.amplitude_ratio, c->nonlinear.amplitude_ratio,
           c->pred_ratio);
    printf("%-26s %16.4f %16.4f %16.4f\n", "phase [deg]", c->linear.phase_deg,
           c->nonlinear.phase_deg, c->pred_phase_deg);
    printf("%-26s %16.6g %16.6g\n", "mean offset [m]", c->linear.mean_offset,
           c->nonlinear.mean_offset);
    printf("%-26s %16.6g %16.6g\n", "half range [m]", c->linear.half_range,
           c->nonlinear.half_range);
    printf("amplitude difference %.4g %%, mean difference %.4g %% (linear "
           "less nonlinear, relative to nonlinear)\n",
           c->amplitude_difference_pct, c->mean_difference_pct);
    printf("rms difference %.6g m (%.4g %% of the excitation amplitude)\n",
           c->rms_difference, 100 * c->rms_difference_ratio);
}

/* Everything a run needs that can be checked without running. */
typedef struct sim_prep {
    ts_system *sys;
    ts_equilibrium_opts eo;
    ts_excitation *ex;
    sim_setup s;
} sim_prep;

static void prep_free(sim_prep *p)
{
    ts_excitation_free(p->ex);
    ts_system_free(p->sys);
}

/* Build the system and parse every setting. Prints nothing; the message
 * is in err. */
static int prepare(const cli_ctx *ctx, const sim_args *a,
                   const cli_settings *cs, sim_prep *p, ts_err *err)
{
    memset(p, 0, sizeof *p);
    sim_setup *s = &p->s;
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
                           a->where[m ? A_MANOEUVRE : A_EXCITE], m,
                           ctx->units, err);
    if (!rc)
        rc = parse_setup(ctx, a, p->ex, s, err);
    if (!rc && (rc = ts_excitation_check_span(p->ex, s->o.t_end, err)))
        ts_err_prefix(err, "%s: ", a->where[A_EXCITE]);
    if (!rc) {
        char def[2 * TS_NAME_MAX + 4];
        const char *name = a->val[A_OUTPUT];
        if (!name) {
            int node = sys->nnodes - 1;
            for (int b = sys->nbodies - 1; b >= 0; b--)
                if (sys->bodies[b].type == TS_BODY_SPHERE)
                    node = ts_system_body_node(sys, b);
            ts_report_node_name(sys, node, def, sizeof def - 2);
            strcat(def, ".z");
            name = def;
        }
        rc = ts_response_output_find(sys, name, &s->out, err);
        if (rc)
            ts_err_prefix(err, "%s: ", a->where[A_OUTPUT]);
        else if (s->out.kind != TS_OUT_POSITION)
            rc = ts_fail(err, TS_EINVAL, "%s: '%s' is a tension; the "
                         "simulation reports positions <node>.x|y|z",
                         a->where[A_OUTPUT], name);
    }
    int use_linear = s->compare || s->linear_only;
    const char *lw = a->where[s->compare ? A_COMPARE : A_LINEAR];
    if (!rc && use_linear && s->init != INIT_EQ)
        rc = ts_fail(err, TS_EINVAL, "%s: the linear model starts at the "
                     "equilibrium, so %s needs the initial state "
                     "'equilibrium'", a->where[A_INITIAL], lw);
    if (!rc && use_linear && ts_excitation_has_manoeuvre(p->ex))
        rc = ts_fail(err, TS_EINVAL, "%s: the linear model has no frame "
                     "inputs; a manoeuvre can only be simulated nonlinearly "
                     "(drop %s)", a->where[A_MANOEUVRE], lw);
    /* What the comparison will need, checked before anything runs. */
    int idx;
    if (!rc && s->compare && ts_excitation_periodic(p->ex, &idx)) {
        double f = ts_excitation_signal(p->ex, idx)->frequency;
        double period = 1.0 / f;
        if (s->o.dt_sample > period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD)
            rc = ts_fail(err, TS_EINVAL, "%s: the sample interval %g s is "
                         "too coarse to compare at %g Hz; at most %g s (%d "
                         "samples per period)", a->where[A_SAMPLE],
                         s->o.dt_sample, f,
                         period / TS_COMPARE_MIN_SAMPLES_PER_PERIOD,
                         TS_COMPARE_MIN_SAMPLES_PER_PERIOD);
        else if (s->o.t_end - s->transient < period)
            rc = ts_fail(err, TS_EINVAL, "%s: %g s are left after the "
                         "transient, less than one period (%g s) of the %g "
                         "Hz excitation", a->where[A_TRANSIENT],
                         s->o.t_end - s->transient, period, f);
    }
    return rc;
}

/* The whole analysis. *result receives the JSON (caller frees). With
 * `full`, histories of every node; else of the output node only. */
static int simulate(const cli_ctx *ctx, const sim_args *a,
                    const cli_settings *cs, int full, json_t **result)
{
    ts_err err = {0}, werr = {0};
    *result = NULL;
    sim_prep prep;
    int rc = prepare(ctx, a, cs, &prep, &err);
    if (rc) {
        prep_free(&prep);
        return cli_report(&err, rc);
    }
    ts_system *sys = prep.sys;
    ts_excitation *ex = prep.ex;
    ts_equilibrium_opts eo = prep.eo;
    sim_setup s = prep.s;
    ts_kernel *k = ts_kernel_alloc(sys, &err), *knl = NULL;
    ts_equilibrium *eq = NULL;
    ts_linear *lin = NULL;
    ts_history *hn = NULL, *hl = NULL;
    double *y0 = NULL, *pos = NULL;
    json_t *j = NULL;
    int status = 0, ran = 0;
    int rc_lin = TS_OK, rc_nl = TS_OK;
    ts_sim_stats st_nl = {0}, st_lin = {0};
    ts_compare cmp;
    int have_cmp = 0;
    int use_linear = s.compare || s.linear_only;
    if (!k) {
        status = cli_report(&err, err.code);
        goto done;
    }

    int n = ts_kernel_nstate(k);
    y0 = calloc((size_t)n, sizeof *y0);
    pos = calloc(3 * (size_t)sys->nnodes, sizeof *pos);
    if (!y0 || !pos) {
        status = cli_report(&err, ts_fail(&err, TS_ENOMEM, "out of memory"));
        goto done;
    }
    printf("simulate %s: %d links, speed %.6g m/s, turn rate %.6g rad/s\n",
           sys->name, sys->nlinks, sys->tow.speed, sys->tow.turn_rate);
    char d[256];
    for (int i = 0; i < ts_excitation_nsignals(ex); i++) {
        ts_excitation_describe(ex, i, d, sizeof d);
        printf("input: %s\n", d);
    }
    /* Initial state. */
    if (s.init == INIT_EQ) {
        eq = ts_equilibrium_alloc(sys, &err);
        rc = eq ? ts_equilibrium_solve(k, &eo, eq, &err) : TS_ENOMEM;
        if (rc) {
            ts_err_prefix(&err, "simulate: the initial equilibrium: ");
            status = cli_report(&err, rc);
            goto done;
        }
        memcpy(y0, eq->y, (size_t)n * sizeof *y0);
        printf("initial state: equilibrium (%s, residual %.3g of %.6g N)\n",
               ts_eq_method_name(eq->method), eq->residual, eq->force_scale);
    } else if (s.init == INIT_RELEASED) {
        rc = ts_sim_released_state(k, s.theta1, s.theta2, y0, &err);
        printf("initial state: %s\n", s.init_text);
    } else {
        rc = read_shape(sys, s.shape_path, a->where[A_INITIAL], pos, &err);
        if (!rc) {
            rc = ts_sim_shape_state(k, pos, SHAPE_RTOL, y0, &err);
            if (rc)
                ts_err_prefix(&err, "%s: %s: ", a->where[A_INITIAL],
                              s.shape_path);
        }
        printf("initial state: %s, at rest\n", s.init_text);
    }
    if (rc) {
        status = cli_report(&err, rc);
        goto done;
    }
    int N = ts_sim_nsamples(&s.o);
    if (use_linear) {
        lin = ts_linear_alloc(k, &err);
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        rc = lin ? ts_linearize_equilibrium(k, eq, &lo, lin, &err)
                 : TS_ENOMEM;
        if (rc) {
            status = cli_report(&err, rc);
            goto done;
        }
        if (lin->kinks)
            printf("note: %d node%s within a step of the water surface "
                   "(%s): f is not smooth there, and the linear model uses "
                   "the mean of the one-sided derivatives (MODEL.md "
                   "section 6)\n", lin->kinks, lin->kinks == 1 ? " sits" :
                   "s sit", lin->kink_tow ? "the tow point among them"
                                          : "not the tow point");
        hl = ts_history_alloc(sys, N, &err);
        if (!hl) {
            status = cli_report(&err, err.code);
            goto done;
        }
        rc_lin = ts_simulate_linear(k, lin, ex, NULL, &s.o, hl, &st_lin,
                                    &err);
        ran = 1;
        char method[64];
        snprintf(method, sizeof method, "%s, %s kinematics",
                 s.o.linear_method == TS_LINSIM_EXPM
                     ? "exact discretisation (expm)"
                     : ts_integrator_name(s.o.integrator),
                 s.o.kinematics == TS_KIN_LINEAR ? "linear" : "nonlinear");
        print_stats("linear", &st_lin, method);
        if (rc_lin)
            status = cli_report(&err, rc_lin);
        /* Both runs start from the linearization's charts. */
        memcpy(y0, lin->y0, (size_t)n * sizeof *y0);
    }
    if (!s.linear_only && !status) {
        knl = ts_kernel_clone(k, &err);
        hn = knl ? ts_history_alloc(sys, N, &err) : NULL;
        if (!hn) {
            status = cli_report(&err, err.code);
            goto done;
        }
        rc_nl = ts_simulate(knl, ex, y0, &s.o, hn, &st_nl, NULL, &err);
        ran = 1;
        char method[96];
        snprintf(method, sizeof method, "%s, rtol %g, atol %g",
                 ts_integrator_name(s.o.integrator), s.o.rel_tol,
                 s.o.abs_tol);
        print_stats("nonlinear", &st_nl, method);
        if (rc_nl)
            status = cli_report(&err, rc_nl);
    }
    if (!ctx->quiet)
        print_table(sys, &s.out, hn, hl);
    if (s.compare && !status) {
        rc = ts_compare_histories(sys, lin, ex, hn, hl, &s.out, s.transient,
                                  &cmp, &err);
        if (rc) {
            ts_err_prefix(&err, "%s: ", a->where[A_COMPARE]);
            status = cli_report(&err, rc);
        } else {
            have_cmp = 1;
            print_compare(&cmp);
        }
    }

    /* Results, also after a failed run (the history so far). */
    j = json_object();
    json_object_set_new(j, "scene", json_string(sys->name));
    json_object_set_new(j, "nlinks", json_integer(sys->nlinks));
    json_object_set_new(j, "output", json_string(s.out.name));
    json_object_set_new(j, "t_end", json_real(s.o.t_end));
    json_object_set_new(j, "sample", json_real(s.o.dt_sample));
    json_object_set_new(j, "initial", json_string(s.init_text));
    json_object_set_new(j, "excitation", ts_report_excitation_json(ex));
    json_object_set_new(j, "completed", json_boolean(ran && !status));
    if (status)
        json_object_set_new(j, "error", json_string(err.msg));
    if (hn) {
        json_t *o = json_object();
        char m[32];
        snprintf(m, sizeof m, "%s", ts_integrator_name(s.o.integrator));
        json_object_set_new(o, "stats", ts_report_sim_stats_json(&st_nl, m));
        json_object_set_new(o, "rel_tol", json_real(s.o.rel_tol));
        json_object_set_new(o, "abs_tol", json_real(s.o.abs_tol));
        json_object_set_new(o, "history", ts_report_history_json(
                                              sys, hn, full ? -1 : s.out.node));
        json_object_set_new(j, "nonlinear", o);
    }
    if (hl) {
        json_t *o = json_object();
        json_object_set_new(o, "stats", ts_report_sim_stats_json(
                                            &st_lin,
                                            s.o.linear_method == TS_LINSIM_EXPM
                                                ? "expm"
                                                : ts_integrator_name(
                                                      s.o.integrator)));
        json_object_set_new(o, "kinematics",
                            json_string(s.o.kinematics == TS_KIN_LINEAR
                                            ? "linear" : "nonlinear"));
        json_object_set_new(o, "history", ts_report_history_json(
                                              sys, hl, full ? -1 : s.out.node));
        json_object_set_new(j, "linear", o);
    }
    if (have_cmp)
        json_object_set_new(j, "compare", ts_report_compare_json(&cmp));
    /* Final positions of the bodies (nonlinear run when there is one). */
    const ts_history *hf = hn ? hn : hl;
    if (hf && hf->nsamples > 0) {
        json_t *bodies = json_array();
        const double *p = hf->positions +
                          3 * (size_t)hf->nnodes * (size_t)(hf->nsamples - 1);
        for (int b = 0; b < sys->nbodies; b++) {
            const double *r = p + 3 * ts_system_body_node(sys, b);
            json_array_append_new(bodies, json_pack("{s:s,s:f,s:f,s:f}",
                                                    "name", sys->bodies[b].name,
                                                    "x", r[0], "y", r[1], "z",
                                                    r[2]));
        }
        json_object_set_new(j, "final_t", json_real(hf->t[hf->nsamples - 1]));
        json_object_set_new(j, "final_bodies", bodies);
    }
    if (a->val[A_CSV] && (hn || hl) &&
        ts_report_history_csv(sys, hn, hl, a->val[A_CSV], &werr) != TS_OK) {
        int st2 = cli_report(&werr, werr.code);
        if (!status)
            status = st2;
    }
    *result = j;
    j = NULL;
done:
    json_decref(j);
    ts_history_free(hn);
    ts_history_free(hl);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(knl);
    ts_kernel_free(k);
    free(y0);
    free(pos);
    prep_free(&prep);
    return status;
}

/* Fill arguments missing from the command line with the entry's. */
static void args_from_entry(sim_args *a, const ts_scene_analysis *e,
                            int index)
{
    for (int i = 0; i < A_N; i++) {
        const ts_scene_option *o = ts_scene_analysis_option(e, arg_keys[i]);
        if (!o)
            continue;
        if (i == A_EXCITE || i == A_MANOEUVRE) {
            int m = i == A_MANOEUVRE;
            if (a->nspecs[m] > 0)
                continue; /* the command line replaces the scene's */
            a->specs[m][a->nspecs[m]++] = o->value;
        } else if (a->val[i]) {
            continue;
        } else {
            a->val[i] = o->value;
        }
        snprintf(a->where[i], sizeof a->where[i], "analyses[%d].%s (line %d)",
                 index, arg_keys[i], o->line);
    }
}

static const char *const sim_keys[] = {
    "t_end", "sample", "initial", "integrator", "rtol", "atol", "h_min",
    "max_steps", "transient", "output", "linear_method", "kinematics",
    "excite", "manoeuvre", "compare", "linear", "csv", "speed", "turn_rate",
    "method", "tolerance", "links", NULL};

static int sim_main(int argc, char **argv)
{
    sim_args a;
    memset(&a, 0, sizeof a);
    for (int i = 0; i < A_N; i++)
        snprintf(a.where[i], sizeof a.where[i], "%s", arg_opts[i]);
    cli_settings cs = {0};
    cli_settings_from_options(&cs);
    enum { O_JSON = 1000, O_QUIET, O_HELP, O_SPEED, O_TURN, O_LINKS,
           O_METHOD, O_TOL };
    static const struct option longopts[] = {
        {"t-end", required_argument, NULL, A_T_END},
        {"sample", required_argument, NULL, A_SAMPLE},
        {"initial", required_argument, NULL, A_INITIAL},
        {"integrator", required_argument, NULL, A_INTEGRATOR},
        {"rtol", required_argument, NULL, A_RTOL},
        {"atol", required_argument, NULL, A_ATOL},
        {"h-min", required_argument, NULL, A_H_MIN},
        {"max-steps", required_argument, NULL, A_MAX_STEPS},
        {"transient", required_argument, NULL, A_TRANSIENT},
        {"output", required_argument, NULL, A_OUTPUT},
        {"linear-method", required_argument, NULL, A_LINEAR_METHOD},
        {"kinematics", required_argument, NULL, A_KINEMATICS},
        {"excite", required_argument, NULL, A_EXCITE},
        {"manoeuvre", required_argument, NULL, A_MANOEUVRE},
        {"compare", no_argument, NULL, A_COMPARE},
        {"linear", no_argument, NULL, A_LINEAR},
        {"csv", required_argument, NULL, A_CSV},
        {"json", required_argument, NULL, O_JSON},
        {"quiet", no_argument, NULL, O_QUIET},
        {"help", no_argument, NULL, O_HELP},
        {"speed", required_argument, NULL, O_SPEED},
        {"turn-rate", required_argument, NULL, O_TURN},
        {"links", required_argument, NULL, O_LINKS},
        {"method", required_argument, NULL, O_METHOD},
        {"tol", required_argument, NULL, O_TOL},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    long v;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        if (ch >= 0 && ch < A_N) {
            if (ch == A_EXCITE || ch == A_MANOEUVRE) {
                int m = ch == A_MANOEUVRE;
                if (a.nspecs[m] == MAX_SPECS) {
                    fprintf(stderr, "towstab simulate: %s: at most %d\n",
                            arg_opts[ch], MAX_SPECS);
                    return EXIT_BADINPUT;
                }
                a.specs[m][a.nspecs[m]++] = optarg;
            } else {
                a.val[ch] = ch == A_COMPARE || ch == A_LINEAR ? "true"
                                                              : optarg;
            }
            continue;
        }
        switch (ch) {
        case O_JSON: a.json = optarg; break;
        case O_QUIET: a.quiet = 1; break;
        case O_HELP: usage(stdout); return 0;
        case O_SPEED: cs.speed = optarg; break;
        case O_TURN: cs.turn_rate = optarg; break;
        case O_METHOD: cs.method = optarg; break;
        case O_TOL: cs.tol = optarg; break;
        case O_LINKS:
            if (cli_parse_int("--links", optarg, 1, 10000000, &v))
                return EXIT_BADINPUT;
            cs.links = (int)v;
            break;
        case ':':
            fprintf(stderr, "towstab simulate: missing value for '%s'\n",
                    argv[optind - 1]);
            return EXIT_BADINPUT;
        default:
            fprintf(stderr, "towstab simulate: unknown option '%s' (towstab "
                            "simulate --help)\n",
                    argv[optind - 1]);
            return EXIT_BADINPUT;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab simulate: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    ts_err err = {0};
    /* Defaults from the scene's first simulate entry. */
    for (int i = 0; i < scene->nanalyses; i++) {
        const ts_scene_analysis *e = &scene->analyses[i];
        if (strcmp(e->type, "simulate"))
            continue;
        if (cli_check_keys(e, sim_keys, i, &err)) {
            status = cli_report(&err, err.code);
            cli_close(units, scene);
            return status;
        }
        args_from_entry(&a, e, i);
        cli_settings es;
        memset(&es, 0, sizeof es);
        if (cli_settings_from_analysis(&es, e, i, &err)) {
            status = cli_report(&err, err.code);
            cli_close(units, scene);
            return status;
        }
        const char **cl[4] = {&cs.speed, &cs.turn_rate, &cs.method, &cs.tol};
        const char *ev[4] = {es.speed, es.turn_rate, es.method, es.tol};
        for (int j = 0; j < 4; j++)
            if (!*cl[j] && ev[j]) {
                *cl[j] = ev[j];
                memcpy(cs.where[j], es.where[j], sizeof cs.where[j]);
            }
        if (!cs.links && es.links) {
            cs.links = es.links;
            memcpy(cs.where[4], es.where[4], sizeof cs.where[4]);
        }
        break;
    }
    cli_ctx ctx = {scene, units, a.quiet};
    json_t *j = NULL;
    status = simulate(&ctx, &a, &cs, 1, &j);
    ts_err werr = {0};
    if (j && a.json) {
        json_object_set_new(j, "type", json_string("simulate"));
        if (cli_write_json(j, a.json, &werr) != TS_OK) {
            int st2 = cli_report(&werr, werr.code);
            if (!status)
                status = st2;
        }
    }
    json_decref(j);
    cli_close(units, scene);
    return status;
}

static int sim_run(const cli_ctx *ctx, const ts_scene_analysis *e, int index,
                   json_t *results)
{
    ts_err err = {0};
    sim_args a;
    memset(&a, 0, sizeof a);
    args_from_entry(&a, e, index);
    for (int i = 0; i < A_N; i++)
        if (!a.where[i][0])
            snprintf(a.where[i], sizeof a.where[i], "analyses[%d].%s",
                     index, arg_keys[i]);
    cli_settings cs = {0};
    if (cli_settings_from_analysis(&cs, e, index, &err))
        return cli_report(&err, err.code);
    json_t *j = NULL;
    int status = simulate(ctx, &a, &cs, 0, &j);
    if (j) {
        json_object_set_new(j, "type", json_string("simulate"));
        json_array_append_new(results, j);
    }
    return status;
}

static int sim_check(const cli_ctx *ctx, const ts_scene_analysis *e,
                     int index)
{
    ts_err err = {0};
    sim_args a;
    memset(&a, 0, sizeof a);
    args_from_entry(&a, e, index);
    for (int i = 0; i < A_N; i++)
        if (!a.where[i][0])
            snprintf(a.where[i], sizeof a.where[i], "analyses[%d].%s",
                     index, arg_keys[i]);
    cli_settings cs = {0};
    if (cli_settings_from_analysis(&cs, e, index, &err))
        return cli_report(&err, err.code);
    sim_prep prep;
    int rc = prepare(ctx, &a, &cs, &prep, &err);
    prep_free(&prep);
    return rc ? cli_report(&err, rc) : 0;
}

const cli_command cli_cmd_simulate = {
    "simulate", "nonlinear and linear time-domain simulation, comparison",
    sim_main, sim_run, sim_keys, sim_check};
