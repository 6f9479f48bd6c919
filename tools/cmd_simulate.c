/* cmd_simulate.c: `towstab simulate SCENE` and the `simulate` analysis of
 * a scene: nonlinear and linear time-domain runs, excitations, manoeuvres
 * and the linear-against-nonlinear comparison (doc/simulate.md), printed
 * as run statistics, a table of the output and the comparison.
 *
 * Pictures (--plot DIR): the time histories and snapshots of the cable
 * every --snapshot-interval seconds. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "towstab/excitation.h"
#include "towstab/report_result.h"

/* Largest number of table rows printed (longer runs are strided). */
#define TABLE_ROWS 60

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
    ts_system_node_name(sys, out->node, name, sizeof name);
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

/* ---- pictures (--plot) ------------------------------------------------- */

/* Snapshots of the cable drawn at most. */
#define MAX_SNAPSHOTS 21

/* Sample of h nearest time t. */
static int nearest_sample(const ts_history *h, double t)
{
    int best = 0;
    for (int i = 1; i < h->nsamples; i++)
        if (fabs(h->t[i] - t) < fabs(h->t[best] - t))
            best = i;
    return best;
}

/* Time histories: the output (nonlinear solid, linear dashed), the
 * tow-point displacement on every excited tow axis, and the top link's
 * tension (nonlinear run). */
static int plot_histories(const ts_system *sys, const ts_output *out,
                          const ts_excitation *ex, const ts_history *hn,
                          const ts_history *hl, const cli_plot *plot)
{
    const ts_history *hf = hn ? hn : hl;
    int n = hf->nsamples;
    double *buf = malloc(7 * (size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!buf) {
        fprintf(stderr, "towstab: error: simulate: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    double *xn = buf, *xl = buf + n, *tens = buf + 2 * n, *tow = buf + 3 * n;
    ts_plot_axis panels[3];
    ts_plot_series ser[6];
    int np = 0, ns = 0;
    char outlabel[160], towlabel[3][64];
    snprintf(outlabel, sizeof outlabel, "%s", out->name);
    panels[np].label = outlabel;
    panels[np].quantity = TS_PLOT_LENGTH;
    size_t st = 3 * (size_t)hf->nnodes;
    size_t off = 3 * (size_t)out->node + (size_t)out->comp;
    if (hn) {
        for (int i = 0; i < hn->nsamples; i++)
            xn[i] = hn->positions[st * (size_t)i + off];
        ts_plot_series a = {hn->nsamples, hn->t, xn, "nonlinear", np,
                            TS_PLOT_SOLID, 1};
        ser[ns++] = a;
    }
    if (hl) {
        for (int i = 0; i < hl->nsamples; i++)
            xl[i] = hl->positions[st * (size_t)i + off];
        ts_plot_series a = {hl->nsamples, hl->t, xl, "linear", np,
                            TS_PLOT_DASHED, 2};
        ser[ns++] = a;
    }
    np++;
    /* Tow axes some signal drives. */
    int used[3] = {0, 0, 0}, nused = 0;
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        ts_axis ax = ts_excitation_signal(ex, i)->axis;
        if (ax <= TS_AXIS_HEAVE && !used[ax]) {
            used[ax] = 1;
            nused++;
        }
    }
    if (nused > 0) {
        panels[np].label = "tow point";
        panels[np].quantity = TS_PLOT_LENGTH;
        for (int ax = 0, k = 0; ax < 3; ax++) {
            if (!used[ax])
                continue;
            double *d = tow + (size_t)k * n;
            for (int i = 0; i < n; i++)
                d[i] = hf->input[TS_NINPUT * (size_t)i + (size_t)ax];
            snprintf(towlabel[k], sizeof towlabel[k], "%s",
                     ts_axis_name((ts_axis)ax));
            ts_plot_series a = {n, hf->t, d, towlabel[k], np, TS_PLOT_SOLID,
                                3 + k};
            ser[ns++] = a;
            k++;
        }
        np++;
    }
    if (hn && hn->nlinks > 0) {
        for (int i = 0; i < hn->nsamples; i++)
            tens[i] = hn->tensions[(size_t)hn->nlinks * (size_t)i];
        panels[np].label = "top tension";
        panels[np].quantity = TS_PLOT_FORCE;
        ts_plot_series a = {hn->nsamples, hn->t, tens, "nonlinear", np,
                            TS_PLOT_SOLID, 1};
        ser[ns++] = a;
        np++;
    }
    char title[256];
    snprintf(title, sizeof title, "%s: time histories%s", sys->name,
             hn && hl ? ", linear and nonlinear" : hl ? ", linear model" : "");
    ts_err err = {0};
    int status = 0;
    if (ts_plot_histories(plot->dir, "histories", title, np, panels, ns, ser,
                          &plot->opts, &err) != TS_OK)
        status = cli_report(&err, err.code);
    else
        printf("wrote %s/histories.png and %s/histories.svg\n", plot->dir,
               plot->dir);
    free(buf);
    return status;
}

/* Snapshots of the cable every `interval` s from t = 0 (side and top
 * views, memo Figs. 9 and 11). */
static int plot_snapshots(const ts_system *sys, const ts_history *h,
                          double interval, const cli_plot *plot)
{
    double t_end = h->t[h->nsamples - 1];
    int nsnap = 0;
    int idx[MAX_SNAPSHOTS];
    for (int k = 0; k < MAX_SNAPSHOTS; k++) {
        double t = k * interval;
        if (t > t_end * (1 + 1e-9) + 1e-12)
            break;
        int i = nearest_sample(h, t);
        if (nsnap > 0 && idx[nsnap - 1] == i)
            continue;
        idx[nsnap++] = i;
    }
    cli_shape shapes[MAX_SNAPSHOTS];
    ts_plot_shape ps[MAX_SNAPSHOTS];
    int status = 0, made = 0;
    for (int k = 0; k < nsnap && !status; k++) {
        const double *pos = h->positions +
                            3 * (size_t)h->nnodes * (size_t)idx[k];
        if (cli_plot_shape(sys, pos, &shapes[k]) != 0) {
            fprintf(stderr,
                    "towstab: error: simulate: --plot: out of memory\n");
            status = EXIT_FAILED;
            break;
        }
        made++;
        snprintf(shapes[k].label, sizeof shapes[k].label, "t = %.4g s",
                 h->t[idx[k]]);
        ps[k] = shapes[k].shape;
        ps[k].style = k < 8 ? TS_PLOT_SOLID : TS_PLOT_DASHED;
        ps[k].color = k + 1;
    }
    static const char *const names[2] = {"snapshots_side", "snapshots_top"};
    static const char *const views[2] = {"side view", "top view"};
    for (int v = 0; v < 2 && !status; v++) {
        char title[256];
        snprintf(title, sizeof title, "%s: cable every %.4g s, %s",
                 sys->name, interval, views[v]);
        ts_err err = {0};
        if (ts_plot_shapes(plot->dir, names[v], title,
                           v == 0 ? TS_PLOT_SIDE : TS_PLOT_TOP,
                           TS_PLOT_WATER, nsnap, ps, &plot->opts,
                           &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            printf("wrote %s/%s.png and %s/%s.svg\n", plot->dir, names[v],
                   plot->dir, names[v]);
    }
    for (int k = 0; k < made; k++)
        cli_plot_shape_free(&shapes[k]);
    return status;
}

/* What --plot draws with: the interval of the snapshots (s). */
typedef struct sim_state {
    double snapshot;
} sim_state;

enum { X_SNAPSHOT };

static int sim_prepare(cli_run *c)
{
    const char *text = c->nextra[X_SNAPSHOT] ? c->extra[X_SNAPSHOT][0]
                                             : NULL;
    if (text && !c->plot.dir) {
        fprintf(stderr, "towstab: error: simulate: --snapshot-interval sets "
                        "the snapshots of the --plot pictures; add --plot "
                        "DIR\n");
        return EXIT_BADINPUT;
    }
    if (!c->plot.dir)
        return 0;
    sim_state *st = calloc(1, sizeof *st);
    if (!st) {
        fprintf(stderr, "towstab: error: simulate: out of memory\n");
        return EXIT_FAILED;
    }
    c->state = st;
    ts_err err = {0};
    if (text &&
        (ts_units_parse(c->units, text, "s", "--snapshot-interval",
                        &st->snapshot, &err) != TS_OK ||
         (!(st->snapshot > 0) &&
          ts_fail(&err, TS_EINVAL, "--snapshot-interval: expected a time "
                  "> 0 s, got '%s'", text) != TS_OK)))
        return cli_report(&err, err.code ? err.code : TS_EINVAL);
    double t_end = c->rq.simulate.sim.t_end;
    if (st->snapshot == 0)
        st->snapshot = t_end / 10;
    if (st->snapshot * (MAX_SNAPSHOTS - 1) < t_end * (1 - 1e-9)) {
        ts_fail(&err, TS_EINVAL, "--snapshot-interval: %g s gives more than "
                "%d snapshots of the %g s run; at least %g s",
                st->snapshot, MAX_SNAPSHOTS, t_end,
                t_end / (MAX_SNAPSHOTS - 1));
        return cli_report(&err, err.code);
    }
    if (st->snapshot > t_end) {
        ts_fail(&err, TS_EINVAL, "--snapshot-interval: %g s is longer than "
                "the run (%g s)", st->snapshot, t_end);
        return cli_report(&err, err.code);
    }
    return 0;
}

/* A record's statistics beside the spectral prediction. */
static void print_record(const char *what, const ts_record_stats *st)
{
    char tz[32] = "none", ind[32] = "none";
    if (isfinite(st->tz))
        snprintf(tz, sizeof tz, "%.4g", st->tz);
    if (isfinite(st->independent))
        snprintf(ind, sizeof ind, "%.4g", st->independent);
    printf("  %-10s %14.6g +- %-10.2g %14.6g +- %-10.2g %10s %8s %8.4g\n",
           what, st->sigma.value, st->sigma.error, st->mean, st->mean_error,
           tz, ind, st->maximum);
}

static void print_sea(const ts_result *r)
{
    printf("\nirregular sea, realisation: seed %lu, %d sinusoids, fade-in "
           "%.6g s\n", r->realisation.seed, r->realisation.components,
           r->realisation.rise);
    cli_print_seastate(r, 1);
    if (!r->has_records)
        return;
    printf("records of %s over t = %.6g .. %.6g s:\n", r->output.name,
           r->transient, r->sim.t_end);
    printf("  %-10s %14s    %-10s %14s    %-10s %10s %8s %8s\n", "", "sigma [m]",
           "(stat.)", "mean [m]", "(stat.)", "Tz [s]", "indep.", "max [m]");
    if (r->has_records & 2)
        print_record("linear", &r->record_linear);
    if (r->has_records & 1)
        print_record("nonlinear", &r->record_nonlinear);
    if (r->seastate)
        printf("  %-10s %14.6g +- %-10.2g %14.6g\n", "spectral",
               r->seastate->sigma.value, r->seastate->sigma.error,
               r->seastate->mean);
}

static void sim_print(const cli_run *c, const ts_result *r)
{
    const ts_system *sys = r->sys;
    if (!sys)
        return;
    char tow[256];
    cli_tow_text(sys, tow, sizeof tow);
    printf("simulate %s: %d links, %s\n", sys->name, sys->nlinks, tow);
    char d[256];
    const ts_excitation *ex = r->excitation;
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        ts_excitation_describe(ex, i, d, sizeof d);
        printf("input: %s\n", d);
    }
    ts_initial init = c->rq.simulate.initial;
    if (init == TS_INITIAL_EQUILIBRIUM && r->eq && r->eq->converged)
        printf("initial state: equilibrium (%s, residual %.3g of %.6g N)\n",
               ts_eq_method_name(r->eq->method), r->eq->residual,
               r->eq->force_scale);
    else if (init == TS_INITIAL_RELEASED && r->initial[0])
        printf("initial state: %s\n", r->initial);
    else if (init == TS_INITIAL_SHAPE && r->initial[0])
        printf("initial state: %s, at rest\n", r->initial);
    const ts_linear *lin = r->lin;
    if (r->linear) {
        if (lin && lin->kinks)
            printf("note: %d node%s within a step of the water surface "
                   "(%s): f is not smooth there, and the linear model uses "
                   "the mean of the one-sided derivatives (doc/model.md "
                   "section 6)\n", lin->kinks, lin->kinks == 1 ? " sits" :
                   "s sit", lin->kink_tow ? "the tow point among them"
                                          : "not the tow point");
        char method[64];
        snprintf(method, sizeof method, "%s, %s kinematics",
                 r->sim.linear_method == TS_LINSIM_EXPM
                     ? "exact discretisation (expm)"
                     : ts_integrator_name(r->sim.integrator),
                 r->sim.kinematics == TS_KIN_LINEAR ? "linear"
                                                    : "nonlinear");
        print_stats("linear", &r->linear_stats, method);
    }
    if (r->nonlinear) {
        char method[96];
        snprintf(method, sizeof method, "%s, rtol %g, atol %g",
                 ts_integrator_name(r->sim.integrator), r->sim.rel_tol,
                 r->sim.abs_tol);
        print_stats("nonlinear", &r->nonlinear_stats, method);
    }
    if (!c->quiet)
        print_table(sys, &r->output, r->nonlinear, r->linear);
    if (r->has_sea)
        print_sea(r);
    for (int v = 0; !r->has_sea && v < r->nvalues; v++) {
        char er[160];
        if (!isfinite(r->values[v].value))
            continue;
        if (v == 0)
            printf("\nkey values (nonlinear run, t >= %.6g s):\n",
                   r->transient);
        cli_value_error(&r->values[v], er, sizeof er);
        printf("%-34s %14.8g %s\n", r->values[v].name, r->values[v].value,
               er);
    }
    const ts_window *w = &r->window;
    if (w->checked) {
        printf("window: t >= %.6g s of %.6g s; ", w->transient, w->t_end);
        if (isfinite(w->slowest_tau))
            printf("slowest time constant %.4g s (%s%.4g Hz; %.4g of them "
                   "before the window)",
                   w->slowest_tau,
                   w->slowest_freq_hz > 0 ? "a mode at " : "a real mode, ",
                   w->slowest_freq_hz, w->transient / w->slowest_tau);
        else
            printf("slowest time constant not known");
        if (isfinite(w->drift))
            printf("; the last two periods differ by %.2g of the output's "
                   "amplitude", w->drift);
        printf(": %s, %s\n",
               w->settled > 0 ? "settled"
               : w->settled == 0 ? "NOT SETTLED"
                                 : "settling not known",
               w->periodic > 0 ? "periodic"
               : w->periodic == 0 ? "NOT PERIODIC"
                                  : "periodicity not known");
    }
    if (r->nonlinear || r->linear) {
        cli_print_accuracy(r);
        cli_print_trust(&r->trust);
    }
    /* Under a sea the records' table above is the comparison. */
    if (r->compared && !r->has_sea)
        print_compare(&r->compare);
}

static int sim_draw(cli_run *c, const ts_result *r)
{
    sim_state *st = c->state;
    const ts_history *h = r->nonlinear ? r->nonlinear : r->linear;
    if (!c->plot.dir || !st || !h || h->nsamples < 2)
        return 0;
    int status = plot_histories(r->sys, &r->output, r->excitation,
                                r->nonlinear, r->linear, &c->plot);
    if (!status)
        status = plot_snapshots(r->sys, h, st->snapshot, &c->plot);
    return status;
}

static void sim_release(cli_run *c)
{
    free(c->state);
    c->state = NULL;
}

static const cli_extra sim_extras[] = {
    {"snapshot-interval", 1, 0, "T",
     "time between the snapshots of --plot (default t_end/10)"},
    {NULL, 0, 0, NULL, NULL}};

static const char *const sim_pictures[] = {"histories", "snapshots_side",
                                           "snapshots_top", NULL};

const cli_command cli_cmd_simulate = {
    "simulate", "nonlinear and linear time-domain simulation, comparison",
    TS_ANALYSIS_SIMULATE, NULL, sim_prepare, sim_print, sim_draw,
    sim_release, sim_pictures, sim_extras};
