/* cmd_converge.c: `towstab converge SCENE` and the `converge` analysis of a
 * scene: how accurate are the numbers, and what do they cost? The library
 * reruns an analysis (equilibrium, modes or simulate) at increasing
 * resolution (links per cable, solver or integrator tolerance,
 * linearization step; towstab/analysis.h); this prints, per value, the
 * value, its estimated error against a Richardson-extrapolated (or the
 * finest) reference, the observed order, wall time and kernel
 * evaluations, then the cheapest setting that meets a target relative
 * error (doc/converge.md). A simulate study takes its simulation's
 * settings as `towstab simulate` does, one series per integrator: a
 * work-precision comparison. --plot draws the error against run time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "towstab/converge.h"

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
                           int quiet, const ts_display *d)
{
    char u[64];
    const char *ph = param_heading(c->param);
    printf("%s against %s: %d run%s, target relative error %.3g\n",
           c->analysis, ts_conv_param_name(c->param), c->nrows,
           c->nrows == 1 ? "" : "s", c->target);
    for (int v = 0; v < c->nvalues && !quiet; v++) {
        const ts_conv_value *V = &c->values[v];
        /* Shown in the display units (a value's own unit when it has no
         * other). */
        double k = ts_display_convert(d, V->unit, 1.0, u, sizeof u);
        if (constant_value(c, v)) {
            double x = NAN;
            for (int i = 0; i < c->nrows && isnan(x); i++)
                if (c->rows[i].status == TS_OK)
                    x = c->rows[i].values[v];
            printf("\n%s: %.10g %s in every run\n", V->name, k * x, u);
            continue;
        }
        printf("\n%s [%s]: observed order ", V->name, u);
        if (isfinite(V->order))
            printf("%.3g", V->order);
        else
            printf("-");
        printf(", reference %.10g +- %.2g (%s)\n", k * V->reference,
               k * V->reference_error, ts_conv_ref_name(V->ref_kind));
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
            printf(" %18.10g", k * r->values[v]);
            print_g(k * r->errors[v], 11);
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
    /* Each point labelled with its setting. */
    char(*ptext)[32] = malloc((size_t)(n > 0 ? n : 1) * sizeof *ptext);
    const char **pl = malloc((size_t)(n > 0 ? n : 1) * sizeof *pl);
    if (!idx || !x || !y || !ser || !labels || !ptext || !pl) {
        free(idx);
        free(x);
        free(y);
        free(ser);
        free(labels);
        free(ptext);
        free(pl);
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
            y[m] = r->max_rel_error;
            if (c->param == TS_CONV_LINKS)
                snprintf(ptext[m], sizeof ptext[m], "%d", (int)r->setting);
            else
                snprintf(ptext[m], sizeof ptext[m], "%.2g", r->setting);
            pl[m] = ptext[m];
            m++;
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
                             TS_PLOT_LINE_MARKERS, 0, pl + first};
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
        ts_plot_axis xa = {"wall time of the run", TS_PLOT_TIME, NULL};
        ts_plot_axis ya = {"largest estimated relative error",
                           TS_PLOT_NONE, NULL};
        ts_err err = {0};
        if (ts_plot_loglog(plot->dir, "error_time", title, &xa, &ya, ns, ser,
                           &plot->opts, &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            cli_plot_wrote(plot, "error_time");
    }
    free(idx);
    free(x);
    free(y);
    free(ser);
    free(labels);
    free(ptext);
    free(pl);
    return status;
}

/* What a simulate study runs, in one line. */
static void print_sim_setup(const ts_result *r)
{
    char d[256];
    int idx = 0;
    ts_excitation_periodic(r->excitation, &idx);
    ts_excitation_describe(r->excitation, idx, d, sizeof d);
    printf("simulate: %s from the equilibrium, t = 0 .. %g s, sample %g s; "
           "%s fitted over t >= %g s; base tolerances rtol %g, atol %g\n",
           d, r->sim.t_end, r->sim.dt_sample, r->output.name, r->transient,
           r->sim.rel_tol, r->sim.abs_tol);
}

static void conv_print(const cli_run *c, const ts_result *r)
{
    if (r->excitation)
        print_sim_setup(r);
    const ts_convergence *cv = r->convergence;
    if (!cv || !cv->estimated)
        return;
    int *idx = malloc((size_t)(cv->nrows > 0 ? cv->nrows : 1) * sizeof *idx);
    if (!idx) {
        fprintf(stderr, "towstab: error: converge: out of memory\n");
        return;
    }
    ts_convergence_sorted_rows(cv, idx);
    print_converge(cv, idx, c->quiet, &c->display);
    free(idx);
}

static int conv_draw(cli_run *c, const ts_result *r)
{
    if (!c->plot.dir || r->status != TS_OK)
        return 0;
    return converge_plot(r->convergence, r->sys->name, &c->plot);
}

static const char *const conv_pictures[] = {"error_time", NULL};

const cli_command cli_cmd_converge = {
    "converge",
    "accuracy and cost against resolution (links, tolerance, step)",
    TS_ANALYSIS_CONVERGE, NULL, NULL, conv_print, conv_draw, NULL,
    conv_pictures, NULL, NULL};
