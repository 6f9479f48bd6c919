/* cmd_converge.c: `towstab converge SCENE` and the `converge` analysis of a
 * scene: how accurate are the numbers, and what do they cost? Reruns an
 * analysis (equilibrium or modes) at increasing resolution (links per
 * cable, solver tolerance, linearization step) and prints, per value, the
 * value, its estimated error against a Richardson-extrapolated (or the
 * finest) reference, the observed order, wall time and kernel
 * evaluations, then the cheapest setting that meets a target relative
 * error (doc/converge.md). The simulate analysis reruns the scene's
 * simulation (settings as `towstab simulate` reads them, tools/cli_sim.h)
 * at each integrator tolerance or link count, one series per integrator:
 * a work-precision comparison. --plot draws the error against run time. */
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "cli_sim.h"
#include "towstab/converge.h"
#include "towstab/report.h"
#include "towstab/report_converge.h"
#include "towstab/report_time.h"

#define DEFAULT_TARGET 1e-3
#define DEFAULT_MODES 3
#define MAX_MODES 100
/* Default sweeps. */
static const char *const default_eq_links = "5,10,20,40,80,160,320";
static const char *const default_modes_links = "10,20,40,80";
static const char *const default_sim_tols = "1e-3,1e-5,1e-7,1e-9";
/* Integrators of one simulate study. */
#define MAX_INTEGRATORS 5

/* What both entries (command line and scene) decide. */
typedef struct conv_req {
    const char *analysis;   /* "equilibrium", "modes" or "simulate" */
    ts_conv_param param;
    double settings[TS_CONV_MAX_SETTINGS];
    int nsettings;
    double target;
    int nmodes;
    ts_integrator integrators[MAX_INTEGRATORS]; /* simulate: one series
                                                   each */
    int nintegrators;       /* 0: the simulation's own integrator */
} conv_req;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: towstab converge SCENE [options]\n"
            "  reruns an analysis at increasing resolution and reports each\n"
            "  value's estimated error, the observed order of convergence,\n"
            "  the run time and kernel evaluations, and the cheapest setting\n"
            "  whose error is below the target\n"
            "  --analysis A     equilibrium (default), modes or simulate\n"
            "  --links LIST     links per cable, e.g. 5,10,20,40 (default\n"
            "                   %s; modes: %s)\n"
            "  --tolerances LIST  the equilibrium's residual target, e.g.\n"
            "                   1e-4,1e-6,1e-8; simulate: the integrator's\n"
            "                   relative tolerance (default %s;\n"
            "                   the absolute one scales with it)\n"
            "  --integrators LIST  simulate: one series per integrator,\n"
            "                   e.g. rk8pd,msbdf,esdirk (work precision)\n"
            "  simulate takes the simulation's settings from the scene's\n"
            "  first 'simulate' entry, or from --excite SPEC, --output NAME,\n"
            "  --t-end T, --sample DT, --transient T (the fit's window\n"
            "  starts there), --rtol X, --atol X, --integrator M (as for\n"
            "  'towstab simulate'); it reports <output>.amplitude_ratio,\n"
            "  .mean_offset and .phase_deg against the periodic excitation\n"
            "  --steps LIST     relative linearization steps (modes), e.g.\n"
            "                   1e-3,1e-4,1e-5\n"
            "  --target X       relative error wanted (default %g)\n"
            "  --modes K        lowest oscillatory modes to follow (modes;\n"
            "                   default %d)\n"
            "  --json FILE      write the study as JSON ('-' for stdout)\n"
            "  --csv FILE       write the runs as CSV\n"
            "  --speed Q        override tow.speed (e.g. '5 knot', 2.5)\n"
            "  --turn-rate Q    override tow.turn_rate (e.g. '0.5 rad/s')\n"
            "  --eq-method M    equilibrium method: auto, shooting, newton\n"
            "  --tol X          equilibrium relative force residual\n"
            "  --plot DIR       draw the error against run time\n"
            "                   (error_time.png/svg), a line per series\n"
            "  --units U        units of the pictures: si or imperial\n"
            "  --quiet          print the summary table only\n",
            default_eq_links, default_modes_links, default_sim_tols,
            DEFAULT_TARGET, DEFAULT_MODES);
}

/* "5,10,20" into settings; plain numbers only (counts, tolerances and
 * steps have no unit). */
static int parse_list(const char *where, const char *text, double *out,
                      int *n, ts_err *err)
{
    char buf[2048];
    if (strlen(text) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: list too long", where);
    strcpy(buf, text);
    *n = 0;
    for (char *tok = buf, *next; tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        while (*tok == ' ')
            tok++;
        char *end;
        double v = strtod(tok, &end);
        while (*end == ' ')
            end++;
        if (end == tok || *end || *n == TS_CONV_MAX_SETTINGS)
            return ts_fail(err, TS_EINVAL,
                           "%s: expected 1 to %d comma-separated numbers "
                           "like '5,10,20', got '%s'",
                           where, TS_CONV_MAX_SETTINGS, text);
        out[(*n)++] = v;
    }
    return TS_OK;
}

/* Fill the sweep of rq from the option texts (at most one of links,
 * tolerances, steps; none: the default links) and check it. */
static int request_sweep(conv_req *rq, const char *links, const char *tols,
                         const char *steps, const char *where[3],
                         ts_err *err)
{
    int given = (links != NULL) + (tols != NULL) + (steps != NULL);
    if (given > 1)
        return ts_fail(err, TS_EINVAL,
                       "%s, %s and %s: give one of them (a study sweeps one "
                       "parameter)",
                       where[0], where[1], where[2]);
    const char *text = links, *w = where[0];
    rq->param = TS_CONV_LINKS;
    if (tols) {
        text = tols;
        w = where[1];
        rq->param = TS_CONV_TOLERANCE;
    } else if (steps) {
        text = steps;
        w = where[2];
        rq->param = TS_CONV_STEP;
        if (strcmp(rq->analysis, "modes") != 0)
            return ts_fail(err, TS_EINVAL,
                           "%s: the linearization step applies to the modes "
                           "analysis, not to %s",
                           w, rq->analysis);
    } else if (!links && strcmp(rq->analysis, "simulate") == 0) {
        text = default_sim_tols;
        w = where[1];
        rq->param = TS_CONV_TOLERANCE;
    } else if (!links) {
        text = strcmp(rq->analysis, "modes") == 0 ? default_modes_links
                                                  : default_eq_links;
    }
    int rc = parse_list(w, text, rq->settings, &rq->nsettings, err);
    if (rc)
        return rc;
    return ts_conv_check_settings(rq->param, rq->settings, rq->nsettings, w,
                                  err);
}

static int parse_analysis(const char *text, const char *where, conv_req *rq,
                          ts_err *err)
{
    static const char *const names[3] = {"equilibrium", "modes",
                                         "simulate"};
    for (int i = 0; i < 3; i++)
        if (strcmp(text, names[i]) == 0) {
            rq->analysis = names[i];
            return TS_OK;
        }
    return ts_fail(err, TS_EINVAL,
                   "%s: '%s' is not an analysis to converge; expected "
                   "equilibrium, modes or simulate",
                   where, text);
}

/* "rk8pd,rkf45,msbdf" into rq's integrators (simulate only). */
static int parse_integrators(const char *text, const char *where,
                             conv_req *rq, ts_err *err)
{
    if (strcmp(rq->analysis, "simulate") != 0)
        return ts_fail(err, TS_EINVAL,
                       "%s: applies to the simulate analysis, not to %s",
                       where, rq->analysis);
    char buf[256];
    if (strlen(text) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: list too long", where);
    strcpy(buf, text);
    rq->nintegrators = 0;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ", ", &save); tok;
         tok = strtok_r(NULL, ", ", &save)) {
        ts_integrator m;
        if (ts_integrator_parse(tok, &m) != 0)
            return ts_fail(err, TS_EINVAL,
                           "%s: '%s' is not an integrator; expected rk8pd, "
                           "rkf45, rk4imp, bsimp, msbdf or esdirk",
                           where, tok);
        for (int i = 0; i < rq->nintegrators; i++)
            if (rq->integrators[i] == m)
                return ts_fail(err, TS_EINVAL, "%s: %s is given twice",
                               where, tok);
        if (rq->nintegrators == MAX_INTEGRATORS)
            return ts_fail(err, TS_EINVAL, "%s: at most %d integrators",
                           where, MAX_INTEGRATORS);
        rq->integrators[rq->nintegrators++] = m;
    }
    if (rq->nintegrators == 0)
        return ts_fail(err, TS_EINVAL,
                       "%s: expected integrators like 'rk8pd,rkf45', got "
                       "'%s'",
                       where, text);
    return TS_OK;
}

static int parse_target(const char *text, const char *where, double *t,
                        ts_err *err)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || *end || !(v > 0 && v < 1))
        return ts_fail(err, TS_EINVAL,
                       "%s: expected a relative error in (0, 1), got '%s'",
                       where, text);
    *t = v;
    return TS_OK;
}

static int parse_modes(const char *text, const char *where, int *k,
                       ts_err *err)
{
    char *end;
    long v = strtol(text, &end, 10);
    if (end == text || *end || v < 1 || v > MAX_MODES)
        return ts_fail(err, TS_EINVAL,
                       "%s: expected a whole number in [1, %d], got '%s'",
                       where, MAX_MODES, text);
    *k = (int)v;
    return TS_OK;
}

static void print_setting(const ts_convergence *c, double s, int width)
{
    if (c->param == TS_CONV_LINKS)
        printf("%*d", width, (int)s);
    else
        printf("%*.3g", width, s);
}

static const char *param_heading(ts_conv_param p)
{
    switch (p) {
    case TS_CONV_LINKS: return "links";
    case TS_CONV_TOLERANCE: return "tol";
    default: return "step";
    }
}

/* Print an error that may be NaN. */
static void print_g(double v, int width)
{
    if (isfinite(v))
        printf(" %*.3g", width, v);
    else
        printf(" %*s", width, "-");
}

/* Value v is the same in every successful run (e.g. a y of 0 in a
 * straight tow). */
static int constant_value(const ts_convergence *c, int v)
{
    int seen = 0;
    double first = 0;
    for (int i = 0; i < c->nrows; i++) {
        const ts_conv_row *r = &c->rows[i];
        if (r->status != TS_OK || !isfinite(r->values[v]))
            continue;
        if (seen && r->values[v] != first)
            return 0;
        first = r->values[v];
        seen = 1;
    }
    return seen;
}

static void print_converge(const ts_convergence *c, const int *idx,
                           int quiet)
{
    const char *ph = param_heading(c->param);
    printf("%s against %s: %d run%s, target relative error %.3g\n",
           c->analysis, ts_conv_param_name(c->param), c->nrows,
           c->nrows == 1 ? "" : "s", c->target);
    for (int v = 0; v < c->nvalues && !quiet; v++) {
        const ts_conv_value *V = &c->values[v];
        if (constant_value(c, v)) {
            double x = NAN;
            for (int i = 0; i < c->nrows && isnan(x); i++)
                if (c->rows[i].status == TS_OK)
                    x = c->rows[i].values[v];
            printf("\n%s: %.10g %s in every run\n", V->name, x, V->unit);
            continue;
        }
        printf("\n%s [%s]: observed order ", V->name, V->unit);
        if (isfinite(V->order))
            printf("%.3g", V->order);
        else
            printf("-");
        printf(", reference %.10g +- %.2g (%s)\n", V->reference,
               V->reference_error, ts_conv_ref_name(V->ref_kind));
        printf("%8s", ph);
        if (c->nseries > 1)
            printf(" %-10s", "series");
        printf(" %18s %11s %11s %7s\n", "value", "est. error", "rel. error",
               "order");
        for (int i = 0; i < c->nrows; i++) {
            const ts_conv_row *r = &c->rows[idx[i]];
            print_setting(c, r->setting, 8);
            if (c->nseries > 1)
                printf(" %-10.10s", c->series[r->series].name);
            if (r->status != TS_OK) {
                printf(" %18s\n", "failed");
                continue;
            }
            printf(" %18.10g", r->values[v]);
            print_g(r->errors[v], 11);
            print_g(r->rel_errors[v], 11);
            if (isfinite(r->order[v]))
                printf(" %7.3f\n", r->order[v]);
            else
                printf(" %7s\n", "-");
        }
    }
    printf("\n%8s", ph);
    if (c->nseries > 1)
        printf(" %-10s", "series");
    printf(" %14s %12s %12s  %s\n", "max rel. err", "wall [ms]",
           "evaluations", "result");
    for (int i = 0; i < c->nrows; i++) {
        const ts_conv_row *r = &c->rows[idx[i]];
        print_setting(c, r->setting, 8);
        if (c->nseries > 1)
            printf(" %-10.10s", c->series[r->series].name);
        print_g(r->max_rel_error, 14);
        printf(" %12.3f %12ld  ", r->wall_s * 1e3, r->evaluations);
        if (r->status != TS_OK)
            printf("FAILED: %s\n", r->message);
        else if (!r->trust.trustworthy)
            printf("NOT TRUSTWORTHY: %s%s\n", r->trust.reasons[0],
                   r->trust.nreasons > 1 ? " (and more: see the JSON)" : "");
        else
            printf("%s\n", r->meets_target ? "meets target" : "ok");
    }
    /* Notes of the finest run (the same limits apply to the others). */
    if (c->nrows > 0) {
        const ts_conv_row *fin = &c->rows[idx[c->nrows - 1]];
        for (int k = 0; k < fin->trust.nnotes; k++)
            printf("note (finest run): %s\n", fin->trust.notes[k]);
    }
    printf("\n");
    if (c->recommended >= 0) {
        const ts_conv_row *r = &c->rows[c->recommended];
        printf("recommended: ");
        print_setting(c, r->setting, 0);
        printf(" %s%s%s%s: largest estimated relative error %.2g <= %.3g "
               "here and at every finer setting; %.3f ms, %ld evaluations\n",
               ts_conv_param_name(c->param),
               c->nseries > 1 ? " (" : "",
               c->nseries > 1 ? c->series[r->series].name : "",
               c->nseries > 1 ? ")" : "", r->max_rel_error, c->target,
               r->wall_s * 1e3, r->evaluations);
        return;
    }
    printf("recommended: none: no trustworthy setting meets %.3g", c->target);
    if (c->limiting_value >= 0)
        printf(" (limited by %s)", c->values[c->limiting_value].name);
    printf("\n");
    if (isfinite(c->predicted_setting)) {
        printf("prediction: at the observed order %.3g, ",
               c->values[c->limiting_value].order);
        print_setting(c, c->predicted_setting, 0);
        printf(" %s would meet it", ts_conv_param_name(c->param));
        if (isfinite(c->predicted_wall_s))
            printf(", in about %.3g s (run time extrapolated from the two "
                   "finest runs)",
                   c->predicted_wall_s);
        printf("\n");
    } else if (c->limiting_value >= 0 &&
               c->values[c->limiting_value].ref_kind ==
                   TS_CONV_REF_CONVERGED) {
        printf("the finest runs agree within their own noise (solver "
               "tolerance, rounding): a finer %s will not help\n",
               ts_conv_param_name(c->param));
    }
}

/* A link sweep needs equal links on every cable: refuse link_lengths
 * before the first run. */
static int check_links(const ts_system *sys, const char *where, ts_err *err)
{
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].link_fraction)
            return ts_fail(err, TS_EINVAL,
                           "%s: cables[%d] '%s' has link_lengths; a link "
                           "sweep needs equal links (remove link_lengths, or "
                           "sweep --tolerances)",
                           where, c, sys->cables[c].name);
    return TS_OK;
}

/* The analysis of series k (simulate: with integrator k). */
static int make_analysis(const ts_system *sys, const ts_equilibrium_opts *eqo,
                         const conv_req *rq, const cli_sim_prep *sp, int k,
                         ts_conv_analysis *an, char *series, size_t size,
                         ts_err *err)
{
    series[0] = '\0';
    if (strcmp(rq->analysis, "modes") == 0)
        return ts_conv_modes_analysis(sys, eqo, NULL, NULL, rq->nmodes, an,
                                      err);
    if (strcmp(rq->analysis, "simulate") != 0)
        return ts_conv_equilibrium_analysis(sys, eqo, an, err);
    ts_sim_opts o = sp->s.o;
    if (rq->nintegrators > 0)
        o.integrator = rq->integrators[k];
    snprintf(series, size, "%s", ts_integrator_name(o.integrator));
    return ts_conv_simulate_analysis(sp->sys, &sp->eo, &o, sp->ex,
                                     sp->s.out.name, sp->s.transient, an,
                                     err);
}

/* What a simulate study runs, in one line. */
static void print_sim_setup(const cli_sim_prep *sp)
{
    char d[256];
    int idx = 0;
    ts_excitation_periodic(sp->ex, &idx);
    ts_excitation_describe(sp->ex, idx, d, sizeof d);
    printf("simulate: %s from the equilibrium, t = 0 .. %g s, sample %g s; "
           "%s fitted over t >= %g s; base tolerances rtol %g, atol %g\n",
           d, sp->s.o.t_end, sp->s.o.dt_sample, sp->s.out.name,
           sp->s.transient, sp->s.o.rel_tol, sp->s.o.abs_tol);
}

/* Run the study on sys (simulate: on sp's system). *json receives its
 * JSON, *out the table. */
static int converge_analysis(const ts_system *sys,
                             const ts_equilibrium_opts *eqo,
                             const conv_req *rq, const cli_sim_prep *sp,
                             int quiet, json_t **json, ts_convergence **out,
                             ts_err *err)
{
    *json = NULL;
    *out = NULL;
    int simulate = strcmp(rq->analysis, "simulate") == 0;
    int nseries = simulate && rq->nintegrators > 0 ? rq->nintegrators : 1;
    if (simulate)
        print_sim_setup(sp);
    ts_convergence *c = NULL;
    int rc = TS_OK;
    for (int k = 0; k < nseries && rc == TS_OK; k++) {
        ts_conv_analysis an;
        char series[TS_CONV_NAME_MAX];
        rc = make_analysis(sys, eqo, rq, sp, k, &an, series, sizeof series,
                           err);
        if (rc)
            break;
        if (!c) {
            c = ts_convergence_alloc(an.name, rq->param, an.nvalues,
                                     an.values, rq->nsettings * nseries,
                                     err);
            if (c)
                c->progress = cli_progress; /* SIGINT, SIGTERM stop it */
        }
        if (!c) {
            ts_conv_analysis_free(&an);
            return err->code ? err->code : TS_ENOMEM;
        }
        int s = ts_convergence_add_series(c, series, err);
        rc = s < 0 ? s
                   : ts_convergence_sweep(c, s, &an, rq->settings,
                                          rq->nsettings, err);
        ts_conv_analysis_free(&an);
    }
    cli_progress_done();
    /* Interrupted: the runs so far, estimated as far as they go, are the
     * result, marked incomplete. */
    ts_err stop = {0};
    if (rc == TS_ECANCEL && c && c->nrows > 0) {
        stop = *err;
        rc = TS_OK;
    }
    if (rc == TS_OK)
        rc = ts_convergence_estimate(c, rq->target, err);
    if (rc != TS_OK) {
        ts_convergence_free(c);
        return rc;
    }
    int *idx = malloc((size_t)c->nrows * sizeof(int));
    if (!idx) {
        ts_convergence_free(c);
        return ts_fail(err, TS_ENOMEM, "converge: out of memory");
    }
    ts_convergence_sorted_rows(c, idx);
    print_converge(c, idx, quiet);
    free(idx);
    /* Every run failed: nothing was learnt. */
    int nok = 0;
    for (int i = 0; i < c->nrows; i++)
        nok += c->rows[i].status == TS_OK;
    if (nok == 0 && !stop.code) {
        rc = ts_fail(err, TS_ECONV,
                     "converge: every run failed (first: %s)",
                     c->rows[0].message);
        ts_convergence_free(c);
        return rc;
    }
    *json = ts_report_convergence_json(c);
    if (!*json) {
        ts_convergence_free(c);
        return ts_fail(err, TS_ENOMEM, "converge: out of memory");
    }
    if (simulate) {
        json_t *o = json_pack("{s:s,s:f,s:f,s:f,s:f,s:f}", "output",
                              sp->s.out.name, "t_end", sp->s.o.t_end,
                              "sample", sp->s.o.dt_sample, "transient",
                              sp->s.transient, "rel_tol", sp->s.o.rel_tol,
                              "abs_tol", sp->s.o.abs_tol);
        json_t *ej = ts_report_excitation_json(sp->ex);
        if (o && ej)
            json_object_set_new(o, "excitation", ej);
        else
            json_decref(ej);
        if (!o || json_object_set_new(*json, "simulation", o) != 0) {
            json_decref(*json);
            *json = NULL;
            ts_convergence_free(c);
            return ts_fail(err, TS_ENOMEM, "converge: out of memory");
        }
    }
    json_object_set_new(*json, "completed", json_boolean(!stop.code));
    if (stop.code) {
        json_object_set_new(*json, "error", json_string(stop.msg));
        if (cli_stop_signal_name())
            json_object_set_new(*json, "interrupted",
                                json_string(cli_stop_signal_name()));
        *err = stop;
    }
    *out = c;
    return stop.code ? stop.code : TS_OK;
}

/* --plot: the largest estimated relative error of every run against its
 * wall time, log-log, one line per series (memo Fig. 12). Runs without a
 * positive error or time (failed, not estimated) are left out. */
static int converge_plot(const ts_convergence *c, const char *scene,
                         const cli_plot *plot)
{
    int n = c->nrows;
    int *idx = malloc((size_t)n * sizeof(int));
    double *x = malloc((size_t)n * sizeof(double));
    double *y = malloc((size_t)n * sizeof(double));
    ts_plot_series *ser = malloc((size_t)c->nseries * sizeof *ser);
    char(*labels)[160] = malloc((size_t)c->nseries * sizeof *labels);
    if (!idx || !x || !y || !ser || !labels) {
        free(idx);
        free(x);
        free(y);
        free(ser);
        free(labels);
        fprintf(stderr, "towstab: error: converge: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    ts_convergence_sorted_rows(c, idx);
    int m = 0, ns = 0;
    for (int s = 0; s < c->nseries; s++) {
        int first = m;
        double lo = INFINITY, hi = -INFINITY;
        for (int i = 0; i < n; i++) {
            const ts_conv_row *r = &c->rows[idx[i]];
            if (r->series != s || r->status != TS_OK ||
                !(r->max_rel_error > 0) || !isfinite(r->max_rel_error) ||
                !(r->wall_s > 0))
                continue;
            x[m] = r->wall_s;
            y[m++] = r->max_rel_error;
            lo = fmin(lo, r->setting);
            hi = fmax(hi, r->setting);
        }
        if (m == first)
            continue;
        const char *pn = ts_conv_param_name(c->param);
        if (c->param == TS_CONV_LINKS)
            snprintf(labels[ns], sizeof labels[ns], "%s%s%d to %d %s",
                     c->series[s].name, c->series[s].name[0] ? ": " : "",
                     (int)lo, (int)hi, pn);
        else
            snprintf(labels[ns], sizeof labels[ns], "%s%s%s %.3g to %.3g",
                     c->series[s].name, c->series[s].name[0] ? ": " : "",
                     pn, hi, lo);
        ts_plot_series ps = {m - first, x + first, y + first, labels[ns], 0,
                             TS_PLOT_LINE_MARKERS, 0};
        ser[ns++] = ps;
    }
    int status = 0;
    if (ns == 0) {
        fprintf(stderr, "towstab: error: converge: --plot: no run has an "
                        "estimated error to draw\n");
        status = EXIT_FAILED;
    } else {
        char title[256];
        snprintf(title, sizeof title, "%s: %s, error against run time (%s "
                 "sweep)", scene, c->analysis, ts_conv_param_name(c->param));
        ts_plot_axis xa = {"wall time of the run", TS_PLOT_TIME};
        ts_plot_axis ya = {"largest estimated relative error",
                           TS_PLOT_NONE};
        ts_err err = {0};
        if (ts_plot_loglog(plot->dir, "error_time", title, &xa, &ya, ns, ser,
                           &plot->opts, &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            printf("wrote %s/error_time.png and %s/error_time.svg\n",
                   plot->dir, plot->dir);
    }
    free(idx);
    free(x);
    free(y);
    free(ser);
    free(labels);
    return status;
}

/* The settings of a simulate study: the command line's, else those of the
 * scene's first simulate entry (checked against its keys). */
static int sim_settings(const ts_scene *scene, cli_sim_args *a, ts_err *err)
{
    for (int i = 0; i < scene->nanalyses; i++) {
        const ts_scene_analysis *e = &scene->analyses[i];
        if (strcmp(e->type, "simulate") != 0)
            continue;
        const cli_command *cmd = NULL;
        for (int j = 0; cli_commands[j]; j++)
            if (strcmp(cli_commands[j]->name, "simulate") == 0)
                cmd = cli_commands[j];
        if (cmd && cli_check_keys(e, cmd->keys, i, err) != TS_OK)
            return err->code;
        cli_sim_args_from_entry(a, e, i);
        break;
    }
    return TS_OK;
}

/* Prepare the simulation of a simulate study and refuse what it cannot
 * sweep. */
static int sim_prepare(const cli_ctx *ctx, const cli_sim_args *a,
                       const cli_settings *s, cli_sim_prep *sp, ts_err *err)
{
    int rc = cli_sim_prepare(ctx, a, s, sp, err);
    if (rc)
        return rc;
    if (sp->s.init != SIM_INIT_EQ)
        return ts_fail(err, TS_EINVAL,
                       "%s: the simulate study starts from the equilibrium "
                       "(its values are the steady response to a periodic "
                       "excitation); got '%s'",
                       a->where[SIM_A_INITIAL], a->val[SIM_A_INITIAL]);
    if (sp->s.linear_only)
        return ts_fail(err, TS_EINVAL,
                       "%s: the simulate study sweeps the nonlinear "
                       "integrator; drop linear",
                       a->where[SIM_A_LINEAR]);
    int idx;
    if (!ts_excitation_periodic(sp->ex, &idx))
        return ts_fail(err, TS_EINVAL,
                       "%s: the simulate study needs a single periodic "
                       "tow-point excitation (one sine or crank), e.g. "
                       "--excite tow.heave:amplitude=0.1ft,frequency=1Hz",
                       a->where[SIM_A_EXCITE]);
    /* Check the window and sampling as the runs will. */
    ts_conv_analysis an;
    rc = ts_conv_simulate_analysis(sp->sys, &sp->eo, &sp->s.o, sp->ex,
                                   sp->s.out.name, sp->s.transient, &an, err);
    ts_conv_analysis_free(&an);
    return rc;
}

/* Simulation options converge takes from the command line. */
static const int sim_opt_index[] = {
    SIM_A_T_END, SIM_A_SAMPLE, SIM_A_INTEGRATOR, SIM_A_RTOL, SIM_A_ATOL,
    SIM_A_TRANSIENT, SIM_A_OUTPUT, SIM_A_EXCITE};
#define NSIM_OPTS ((int)(sizeof sim_opt_index / sizeof sim_opt_index[0]))
enum { O_SIM = 1000, O_PLOT = 1100, O_UNITS, O_INTEGRATORS };

static int conv_main(int argc, char **argv)
{
    cli_settings s = {0};
    cli_settings_from_options(&s);
    snprintf(s.where[2], sizeof s.where[2], "--eq-method");
    const char *json_path = NULL, *csv_path = NULL;
    const char *links = NULL, *tols = NULL, *steps = NULL;
    const char *analysis = "equilibrium", *target = NULL, *modes = NULL;
    const char *integrators = NULL;
    int quiet = 0;
    cli_plot plot = {0};
    cli_sim_args sa;
    memset(&sa, 0, sizeof sa);
    for (int i = 0; i < SIM_A_N; i++)
        snprintf(sa.where[i], sizeof sa.where[i], "%s", cli_sim_arg_opts[i]);
    int given_sim = 0;
    struct option longopts[32] = {
        {"analysis", required_argument, NULL, 'a'},
        {"links", required_argument, NULL, 'n'},
        {"tolerances", required_argument, NULL, 'T'},
        {"steps", required_argument, NULL, 'H'},
        {"target", required_argument, NULL, 'g'},
        {"modes", required_argument, NULL, 'k'},
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        {"speed", required_argument, NULL, 's'},
        {"turn-rate", required_argument, NULL, 'w'},
        {"eq-method", required_argument, NULL, 'm'},
        {"tol", required_argument, NULL, 't'},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {"plot", required_argument, NULL, O_PLOT},
        {"units", required_argument, NULL, O_UNITS},
        {"integrators", required_argument, NULL, O_INTEGRATORS}};
    int nlong = 17;
    for (int i = 0; i < NSIM_OPTS; i++) {
        struct option o = {cli_sim_arg_opts[sim_opt_index[i]] + 2,
                           required_argument, NULL, O_SIM + sim_opt_index[i]};
        longopts[nlong++] = o;
    }
    memset(&longopts[nlong], 0, sizeof longopts[nlong]);
    optind = 1;
    opterr = 0;
    int ch;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        if (ch >= O_SIM && ch < O_SIM + SIM_A_N) {
            int k = ch - O_SIM;
            given_sim = 1;
            if (k == SIM_A_EXCITE) {
                if (sa.nspecs[0] == CLI_SIM_MAX_SPECS) {
                    fprintf(stderr, "towstab: error: converge: --excite: at most "
                                    "%d\n", CLI_SIM_MAX_SPECS);
                    return EXIT_BADINPUT;
                }
                sa.specs[0][sa.nspecs[0]++] = optarg;
            } else {
                sa.val[k] = optarg;
            }
            continue;
        }
        switch (ch) {
        case 'a': analysis = optarg; break;
        case 'n': links = optarg; break;
        case 'T': tols = optarg; break;
        case 'H': steps = optarg; break;
        case 'g': target = optarg; break;
        case 'k': modes = optarg; break;
        case 'j': json_path = optarg; break;
        case 'c': csv_path = optarg; break;
        case 'q': quiet = 1; break;
        case O_PLOT: plot.dir = optarg; break;
        case O_UNITS: plot.units = optarg; break;
        case O_INTEGRATORS: integrators = optarg; break;
        case 'h': usage(stdout); return 0;
        default: {
            int r = cli_settings_option(&s, ch, optarg);
            if (r < 0)
                return EXIT_BADINPUT;
            if (r == 0)
                return cli_option_error("converge", ch, argv[optind - 1]);
        }
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: converge: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    ts_err err = {0};
    conv_req rq = {0};
    rq.target = DEFAULT_TARGET;
    rq.nmodes = DEFAULT_MODES;
    static const char *const where[3] = {"--links", "--tolerances",
                                         "--steps"};
    if (parse_analysis(analysis, "--analysis", &rq, &err) ||
        (target && parse_target(target, "--target", &rq.target, &err)) ||
        (modes && parse_modes(modes, "--modes", &rq.nmodes, &err)) ||
        (integrators &&
         parse_integrators(integrators, "--integrators", &rq, &err)) ||
        request_sweep(&rq, links, tols, steps, (const char **)where, &err))
        return cli_report(&err, err.code);
    if (modes && strcmp(rq.analysis, "modes") != 0) {
        fprintf(stderr, "towstab: error: --modes: applies to --analysis "
                        "modes\n");
        return EXIT_BADINPUT;
    }
    int simulate = strcmp(rq.analysis, "simulate") == 0;
    if (given_sim && !simulate) {
        fprintf(stderr, "towstab: error: --excite, --output, --t-end, "
                        "--sample, --transient, --rtol, --atol and "
                        "--integrator apply to --analysis simulate\n");
        return EXIT_BADINPUT;
    }
    static const char *const what[2] = {"--json", "--csv"};
    static const char *const pictures[] = {"error_time", NULL};
    const char *paths[2] = {json_path, csv_path};
    int pstatus = cli_check_outputs("converge", 2, what, paths, plot.dir,
                                    pictures);
    if (!pstatus)
        pstatus = cli_plot_begin(&plot, "converge");
    if (pstatus)
        return pstatus;
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    ts_equilibrium_opts eqo;
    ts_system *sys = NULL;
    cli_sim_prep sp;
    memset(&sp, 0, sizeof sp);
    cli_ctx ctx = {scene, units, quiet};
    if (simulate) {
        if (sim_settings(scene, &sa, &err) == TS_OK &&
            sim_prepare(&ctx, &sa, &s, &sp, &err) == TS_OK) {
            sys = ts_system_copy(sp.sys, &err);
            eqo = sp.eo;
        }
    } else {
        sys = cli_system(scene, units, &s, &eqo, &err);
    }
    if (!sys || (rq.param == TS_CONV_LINKS &&
                 check_links(sys, "--links", &err) != TS_OK)) {
        status = cli_report(&err, err.code ? err.code : TS_EINVAL);
        ts_system_free(sys);
        cli_sim_prep_free(&sp);
        cli_close(units, scene);
        return status;
    }
    printf("towstab converge: %s (%s)\n", sys->name, scene->path);
    json_t *json = NULL;
    ts_convergence *c = NULL;
    int rc = converge_analysis(sys, &eqo, &rq, &sp, quiet, &json, &c, &err);
    if (rc != TS_OK)
        status = cli_report(&err, rc);
    status = cli_write_result(json, json_path, status, err.msg);
    /* An interrupted study still has its runs so far (the JSON marked
     * incomplete above). */
    int have = rc == TS_OK || (rc == TS_ECANCEL && c);
    ts_err werr = {0};
    if (have && csv_path &&
        ts_report_convergence_csv(c, csv_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    if (rc == TS_OK && plot.dir) {
        int prc = converge_plot(c, sys->name, &plot);
        if (prc && !status)
            status = prc;
    }
    json_decref(json);
    ts_convergence_free(c);
    ts_system_free(sys);
    cli_sim_prep_free(&sp);
    cli_close(units, scene);
    return status;
}

static const char *const conv_keys[] = {
    "analysis", "links", "tolerances", "steps", "target", "modes", "speed",
    "turn_rate", "tolerance", "equilibrium_method", "integrators", NULL};

/* One scene entry (cli_command.entry): parse and check its options, and
 * with a result slot run it. Returns the exit status. */
static int conv_entry(const cli_ctx *ctx, const ts_scene_analysis *a,
                      int index, json_t **result)
{
    ts_err err = {0};
    cli_settings s = {0};
    /* The shared settings reader takes `links` as one number and `method`
     * as the equilibrium's: give it a view without them. */
    ts_scene_analysis view = *a;
    ts_scene_option opts[64];
    view.noptions = 0;
    view.options = opts;
    if (a->noptions > 64) {
        ts_fail(&err, TS_ESCENE, "analyses[%d] (line %d): %d options; a "
                                 "converge entry takes at most 10",
                index, a->line, a->noptions);
        return cli_report(&err, err.code);
    }
    for (int i = 0; i < a->noptions; i++)
        if (strcmp(a->options[i].key, "links") != 0)
            opts[view.noptions++] = a->options[i];
    if (cli_settings_from_analysis(&s, &view, index, &err))
        return cli_report(&err, err.code);
    const ts_scene_option *om =
        ts_scene_analysis_option(a, "equilibrium_method");
    s.method = om ? om->value : NULL;
    snprintf(s.where[2], sizeof s.where[2],
             "analyses[%d].equilibrium_method (line %d)", index,
             om ? om->line : a->line);
    conv_req rq = {0};
    rq.target = DEFAULT_TARGET;
    rq.nmodes = DEFAULT_MODES;
    rq.analysis = "equilibrium";
    char w[5][160];
    const ts_scene_option *o;
    static const char *const keys[5] = {"analysis", "target", "modes",
                                        "links", "tolerances"};
    for (int j = 0; j < 5; j++) {
        o = ts_scene_analysis_option(a, keys[j]);
        snprintf(w[j], sizeof w[j], "analyses[%d].%s (line %d)", index,
                 keys[j], o ? o->line : a->line);
    }
    const char *lt = cli_option(a, "links"), *tt = cli_option(a, "tolerances");
    const char *st = cli_option(a, "steps"), *mt = cli_option(a, "modes");
    char wsteps[160];
    o = ts_scene_analysis_option(a, "steps");
    snprintf(wsteps, sizeof wsteps, "analyses[%d].steps (line %d)", index,
             o ? o->line : a->line);
    const char *where[3] = {w[3], w[4], wsteps};
    if ((cli_option(a, "analysis") &&
         parse_analysis(cli_option(a, "analysis"), w[0], &rq, &err)) ||
        (cli_option(a, "target") &&
         parse_target(cli_option(a, "target"), w[1], &rq.target, &err)) ||
        (mt && parse_modes(mt, w[2], &rq.nmodes, &err)) ||
        request_sweep(&rq, lt, tt, st, where, &err))
        return cli_report(&err, err.code);
    if (mt && strcmp(rq.analysis, "modes") != 0) {
        ts_fail(&err, TS_EINVAL, "%s: applies to analysis modes", w[2]);
        return cli_report(&err, err.code);
    }
    const char *it = cli_option(a, "integrators");
    if (it) {
        char wi[160];
        o = ts_scene_analysis_option(a, "integrators");
        snprintf(wi, sizeof wi, "analyses[%d].integrators (line %d)", index,
                 o ? o->line : a->line);
        if (parse_integrators(it, wi, &rq, &err))
            return cli_report(&err, err.code);
    }
    ts_equilibrium_opts eqo;
    ts_system *sys = NULL;
    cli_sim_prep sp;
    memset(&sp, 0, sizeof sp);
    if (strcmp(rq.analysis, "simulate") == 0) {
        /* The simulation of the scene's first simulate entry. */
        cli_sim_args sa;
        memset(&sa, 0, sizeof sa);
        for (int i = 0; i < SIM_A_N; i++)
            snprintf(sa.where[i], sizeof sa.where[i],
                     "analyses[%d] (simulate settings: %s)", index,
                     cli_sim_arg_keys[i]);
        if (sim_settings(ctx->scene, &sa, &err) == TS_OK &&
            sim_prepare(ctx, &sa, &s, &sp, &err) == TS_OK) {
            sys = ts_system_copy(sp.sys, &err);
            eqo = sp.eo;
        }
    } else {
        sys = cli_system(ctx->scene, ctx->units, &s, &eqo, &err);
    }
    if (!sys) {
        cli_sim_prep_free(&sp);
        return cli_report(&err, err.code ? err.code : TS_EINVAL);
    }
    if (rq.param == TS_CONV_LINKS && check_links(sys, w[3], &err) != TS_OK) {
        ts_system_free(sys);
        cli_sim_prep_free(&sp);
        return cli_report(&err, err.code);
    }
    if (!result) {
        ts_system_free(sys);
        cli_sim_prep_free(&sp);
        return 0;
    }
    ts_convergence *c = NULL;
    int rc = converge_analysis(sys, &eqo, &rq, &sp, ctx->quiet, result, &c,
                               &err);
    int status = rc ? cli_report(&err, rc) : 0;
    if (status && !*result)
        *result = cli_json_failed(err.msg);
    cli_json_mark(*result, status, err.msg);
    ts_convergence_free(c);
    ts_system_free(sys);
    cli_sim_prep_free(&sp);
    return status;
}

const cli_command cli_cmd_converge = {
    "converge",
    "accuracy and cost against resolution (links, tolerance, step)",
    conv_main, conv_entry, conv_keys};
