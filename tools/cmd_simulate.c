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
#include "towstab/track.h"

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

/* Channels printed at most (more go to --json and --csv). */
#define TABLE_COLS 8

/* Column width of channel `name` with unit `unit`. */
static int col_width(const char *name, const char *unit)
{
    int w = (int)(strlen(name) + strlen(unit)) + 4;
    return w < 16 ? 16 : w;
}

/* One column of the table: channel o of history h, shown in d. */
typedef struct column {
    const ts_output *o;
    const ts_history *h;
    char head[TS_OUTPUT_NAME_MAX + 96];
    int width;
} column;

static void column_set(column *c, const ts_output *o, const ts_history *h,
                       const char *prefix, const ts_display *d)
{
    char u[64];
    ts_display_convert(d, o->si_unit, 1.0, u, sizeof u);
    c->o = o;
    c->h = h;
    snprintf(c->head, sizeof c->head, "%s%s [%s]", prefix, o->name, u);
    c->width = col_width(c->head, "");
}

/* The channels of the result, one row per sample (strided): those the
 * main run gives, and with both runs the compared output of the linear
 * run; in the display units d. */
static void print_table(const ts_result *r, const ts_display *d)
{
    const ts_system *sys = r->sys;
    const ts_history *nl = r->nonlinear, *li = r->linear;
    const ts_history *h = nl ? nl : li;
    if (!h || h->nsamples == 0)
        return;
    column cols[TABLE_COLS + 1];
    int nc = 0, more = 0;
    for (int k = 0; k < r->noutputs; k++) {
        if (!isfinite(ts_history_value(sys, h, &r->outputs[k], 0)))
            continue;
        if (nc < TABLE_COLS)
            column_set(&cols[nc++], &r->outputs[k], h, "", d);
        else
            more++;
    }
    if (nl && li)
        column_set(&cols[nc++], &r->output, li, "linear ", d);
    int stride = (h->nsamples + TABLE_ROWS - 1) / TABLE_ROWS;
    char th[40], u[64];
    snprintf(th, sizeof th, "t [%s]", ts_display_unit(d, TS_QTY_TIME));
    printf("\n%10s", th);
    for (int c = 0; c < nc; c++)
        printf(" %*s", cols[c].width, cols[c].head);
    printf("%s\n", nl ? "" : "    (linear model)");
    for (int i = 0; i < h->nsamples; i += stride) {
        printf("%10.4f", ts_display_value(d, TS_QTY_TIME, h->t[i]));
        for (int c = 0; c < nc; c++)
            if (i < cols[c].h->nsamples)
                printf(" %*.9f", cols[c].width,
                       ts_display_convert(d, cols[c].o->si_unit,
                                          ts_history_value(sys, cols[c].h,
                                                           cols[c].o, i),
                                          u, sizeof u));
        printf("\n");
        if (i + stride >= h->nsamples && i != h->nsamples - 1)
            i = h->nsamples - 1 - stride; /* always show the last sample */
    }
    if (stride > 1)
        printf("(one sample in %d of %d shown; --csv for all)\n", stride,
               h->nsamples);
    if (more)
        printf("(%d more channel%s in --json and --csv)\n", more,
               more == 1 ? "" : "s");
}

/* A number in a field of width w, "-" when it is not finite. */
static void field(double v, int w)
{
    if (isfinite(v))
        printf(" %*.6g", w, v);
    else
        printf(" %*s", w, "-");
}

/* One row of the forces table, in the display units d. */
static void print_extremes(const char *name, const ts_extremes *e,
                           const ts_display *d)
{
    printf("%-32s", name);
    double v[7] = {ts_display_value(d, TS_QTY_FORCE, e->max),
                   ts_display_value(d, TS_QTY_TIME, e->t_max),
                   ts_display_value(d, TS_QTY_FORCE, e->min),
                   ts_display_value(d, TS_QTY_TIME, e->t_min),
                   ts_display_value(d, TS_QTY_FORCE, e->mean),
                   ts_display_value(d, TS_QTY_FORCE, e->reference),
                   e->amplification};
    static const int w[7] = {14, 9, 14, 9, 14, 14, 13};
    for (int k = 0; k < 7; k++)
        field(v[k], w[k]);
    printf("\n");
}

/* Events of links out of range printed at most (all are in the JSON). */
#define SLACK_LINES 10

/* The forces of the nonlinear run: extremes of the tow force, of the
 * links with the largest and the smallest tension and of a tension
 * output; then the links that went into compression or slack. */
static void print_forces(const ts_result *r, const ts_display *d)
{
    const ts_system *sys = r->sys;
    if (!r->tensions || r->tow_force.samples == 0)
        return;
    const char *fu = ts_display_unit(d, TS_QTY_FORCE);
    const char *tu = ts_display_unit(d, TS_QTY_TIME);
    char h[5][40];
    snprintf(h[0], sizeof h[0], "max [%s]", fu);
    snprintf(h[1], sizeof h[1], "t [%s]", tu);
    snprintf(h[2], sizeof h[2], "min [%s]", fu);
    snprintf(h[3], sizeof h[3], "mean [%s]", fu);
    snprintf(h[4], sizeof h[4], "static [%s]", fu);
    if (r->forces_from > 0)
        printf("\nforces of the nonlinear run over the analysed window, t "
               ">= %.6g %s (the transient before it left out; static: the "
               "initial equilibrium's; amplification: max / static)\n",
               ts_display_value(d, TS_QTY_TIME, r->forces_from), tu);
    else
        printf("\nforces of the nonlinear run over the whole run (static: "
               "the initial equilibrium's; amplification: max / static)\n");
    printf("%-32s %14s %9s %14s %9s %14s %14s %13s\n", "channel", h[0], h[1],
           h[2], h[1], h[3], h[4], "amplification");
    print_extremes("tow.force (top tension)", &r->tow_force, d);
    double err = r->tow_force.max_error;
    int pick[2] = {r->peak_link, r->low_link};
    static const char *const what[2] = {"largest", "smallest"};
    char name[TS_OUTPUT_NAME_MAX + 16];
    for (int k = 0; k < 2; k++) {
        if (pick[k] < 0 || (k == 1 && pick[1] == pick[0]))
            continue;
        const ts_link *L = &sys->links[pick[k]];
        snprintf(name, sizeof name, "%s.%d.tension (%s)",
                 sys->cables[L->cable].name, L->index,
                 pick[1] == pick[0] ? "largest, smallest" : what[k]);
        print_extremes(name, &r->tensions[pick[k]], d);
        err = fmax(err, fmax(r->tensions[pick[k]].max_error,
                             r->tensions[pick[k]].min_error));
    }
    if (r->output.kind == TS_OUT_TENSION && r->output.link != pick[0] &&
        r->output.link != pick[1]) {
        print_extremes(r->output.name, &r->output_extremes, d);
        err = fmax(err, r->output_extremes.max_error);
    }
    if (err > 0)
        printf("between samples the extremes may reach up to %.3g %s "
               "further (sampling every %g %s; --sample shortens it)\n",
               ts_display_value(d, TS_QTY_FORCE, err), fu,
               ts_display_value(d, TS_QTY_TIME, r->sim.dt_sample), tu);
    for (int k = 0; k < r->nslack && k < SLACK_LINES; k++) {
        const ts_slack *e = &r->slack[k];
        const ts_link *L = &sys->links[e->link];
        printf("warning: %s link %s.%d %s at t = %.6g %s", e->elastic
               ? "elastic" : "rigid", sys->cables[L->cable].name, L->index,
               e->elastic ? "goes slack" : "is in compression",
               ts_display_value(d, TS_QTY_TIME, e->t_first), tu);
        if (e->samples > 1)
            printf(" (%d samples to t = %.6g %s)", e->samples,
                   ts_display_value(d, TS_QTY_TIME, e->t_last), tu);
        if (!e->elastic)
            printf(", lowest tension %.6g %s",
                   ts_display_value(d, TS_QTY_FORCE, e->min), fu);
        printf("\n");
    }
    if (r->nslack > SLACK_LINES)
        printf("warning: %d more links (forces.slack of --json)\n",
               r->nslack - SLACK_LINES);
}

/* The waypoint course of the nonlinear run: the waypoints reached and
 * when, and the depth excursion of every body through it. */
static void print_waypoints(const ts_result *r, const ts_display *d)
{
    const ts_system *sys = r->sys;
    const ts_history *h = r->nonlinear;
    if (!h || !sys->tow.autopilot.on)
        return;
    const ts_guidance *g = &sys->tow.autopilot.g;
    const char *lu = ts_display_unit(d, TS_QTY_LENGTH);
    const char *tu = ts_display_unit(d, TS_QTY_TIME);
    printf("\nwaypoints of %s (radius %.6g %s, autopilot every %.6g %s): "
           "%d of %d reached\n", sys->bodies[sys->tow.vehicle].name,
           ts_display_value(d, TS_QTY_LENGTH, g->radius), lu,
           ts_display_value(d, TS_QTY_TIME, sys->tow.autopilot.interval), tu,
           h->nreached, g->nwaypoints);
    char hx[40], hy[40], ht[40], hd[40];
    snprintf(hx, sizeof hx, "x [%s]", lu);
    snprintf(hy, sizeof hy, "y [%s]", lu);
    snprintf(ht, sizeof ht, "reached at t [%s]", tu);
    snprintf(hd, sizeof hd, "distance [%s]", lu);
    printf("%8s %12s %12s %18s %14s\n", "waypoint", hx, hy, ht, hd);
    for (int i = 0; i < g->nwaypoints; i++) {
        printf("%8d %12.6g %12.6g", i + 1,
               ts_display_value(d, TS_QTY_LENGTH, g->waypoint[i][0]),
               ts_display_value(d, TS_QTY_LENGTH, g->waypoint[i][1]));
        if (i < h->nreached)
            printf(" %18.6g %14.4g\n",
                   ts_display_value(d, TS_QTY_TIME, h->reached_t[i]),
                   ts_display_value(d, TS_QTY_LENGTH, h->reached_d[i]));
        else
            printf(" %18s %14s\n", "not reached", "-");
    }
    ts_depth_range dr[TS_MAX_DEPTH_RANGES];
    int nd = ts_history_depth_ranges(sys, h, r->forces_from, dr,
                                     TS_MAX_DEPTH_RANGES);
    char window[80] = "";
    if (r->forces_from > 0)
        snprintf(window, sizeof window, " over t >= %.6g %s",
                 ts_display_value(d, TS_QTY_TIME, r->forces_from), tu);
    for (int k = 0; k < nd; k++)
        printf("depth of %s%s: %.6g %s (t = %.6g %s) to %.6g %s (t = %.6g "
               "%s), excursion %.4g %s\n", sys->bodies[dr[k].body].name,
               window, ts_display_value(d, TS_QTY_LENGTH, dr[k].min), lu,
               ts_display_value(d, TS_QTY_TIME, dr[k].t_min), tu,
               ts_display_value(d, TS_QTY_LENGTH, dr[k].max), lu,
               ts_display_value(d, TS_QTY_TIME, dr[k].t_max), tu,
               ts_display_value(d, TS_QTY_LENGTH, dr[k].max - dr[k].min),
               lu);
}

/* A number of the comparison's table in `fmt` (a width of 16), or "-"
 * where it has none (an amplitude ratio or phase without a periodic
 * excitation): no "nan" printed. */
static void cmp_cell(const char *fmt, double v)
{
    if (isfinite(v))
        printf(fmt, v);
    else
        printf(" %16s", "-");
}

static void print_compare(const ts_compare *c, const ts_display *d)
{
    char u[64], ru[160], label[192], eu[64];
    double k = ts_display_convert(d, c->output.si_unit, 1.0, u, sizeof u);
    /* The ratio: the output's unit per the excited input's (m/m for a
     * tow displacement, per an angle for a rotation of the ship or a
     * fin, per N for a thrust); "-" without a periodic excitation. */
    double kr = 1.0, ke = 1.0;
    snprintf(ru, sizeof ru, "-");
    snprintf(eu, sizeof eu, "-");
    if (c->ratio_unit[0]) {
        ke = ts_display_convert(d, c->input_unit, 1.0, eu, sizeof eu);
        kr = ts_display_convert(d, c->ratio_unit, 1.0, ru, sizeof ru);
    }
    const char *tu = ts_display_unit(d, TS_QTY_TIME);
    printf("\ncomparison of %s over t = %.6g .. %.6g %s (%d samples; the "
           "transient before is discarded)\n",
           c->output.name, ts_display_value(d, TS_QTY_TIME, c->t_from),
           ts_display_value(d, TS_QTY_TIME, c->t_to), tu, c->nsamples);
    if (c->periodic)
        printf("excitation %s %s, amplitude %.6g %s, %.6g Hz\n", c->input,
               ts_signal_type_name(c->exc_type), ke * c->exc_amplitude, eu,
               c->exc_frequency_hz);
    if (c->step)
        printf("excitation %s %s, change %.6g %s (no amplitude or phase: "
               "the gain is the output's final change over it)\n", c->input,
               ts_signal_type_name(c->exc_type), ke * c->exc_amplitude, eu);
    printf("%-30s %16s %16s %16s\n", "", "linear", "nonlinear",
           c->step ? "static gain" : "freq. response");
    if (c->step) {
        snprintf(label, sizeof label, "final-value gain [%s]", ru);
        printf("%-30s", label);
        cmp_cell(" %16.6g", kr * c->linear.final_gain);
        cmp_cell(" %16.6g", kr * c->nonlinear.final_gain);
        cmp_cell(" %16.6g", kr * c->static_gain);
        printf("\n");
    } else {
        snprintf(label, sizeof label, "amplitude ratio [%s]", ru);
        printf("%-30s", label);
        cmp_cell(" %16.6g", kr * c->linear.amplitude_ratio);
        cmp_cell(" %16.6g", kr * c->nonlinear.amplitude_ratio);
        cmp_cell(" %16.6g", kr * c->pred_ratio);
        printf("\n%-30s", "phase [deg]");
        cmp_cell(" %16.4f", c->linear.phase_deg);
        cmp_cell(" %16.4f", c->nonlinear.phase_deg);
        cmp_cell(" %16.4f", c->pred_phase_deg);
        printf("\n");
    }
    snprintf(label, sizeof label, "mean offset [%s]", u);
    printf("%-30s %16.6g %16.6g\n", label, k * c->linear.mean_offset,
           k * c->nonlinear.mean_offset);
    snprintf(label, sizeof label, "half range [%s]", u);
    printf("%-30s %16.6g %16.6g\n", label, k * c->linear.half_range,
           k * c->nonlinear.half_range);
    if (isfinite(c->amplitude_difference_pct))
        printf("amplitude difference %.4g %%, ", c->amplitude_difference_pct);
    printf("mean difference %.4g %% (linear less nonlinear, relative to "
           "nonlinear)\n", c->mean_difference_pct);
    if (!isfinite(c->rms_difference_ratio))
        printf("rms difference %.6g %s\n", k * c->rms_difference, u);
    else if (!strcmp(c->ratio_unit, "m/m"))
        printf("rms difference %.6g %s (%.4g %% of the excitation "
               "amplitude)\n", k * c->rms_difference, u,
               100 * c->rms_difference_ratio);
    else
        printf("rms difference %.6g %s (%.6g %s of excitation)\n",
               k * c->rms_difference, u, kr * c->rms_difference_ratio, ru);
    if (c->step && c->static_note[0])
        printf("static gain %s\n", c->static_note);
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
 * tow-point displacement on every excited tow axis, the ship's rotation
 * on every excited rotation axis, and the force on the tow point (the top
 * tension; nonlinear run). */
static int plot_histories(const ts_system *sys, const ts_output *out,
                          const ts_excitation *ex, const ts_history *hn,
                          const ts_history *hl, const cli_plot *plot)
{
    const ts_history *hf = hn ? hn : hl;
    int n = hf->nsamples;
    double *buf = malloc(10 * (size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!buf) {
        fprintf(stderr, "towstab: error: simulate: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    double *xn = buf, *xl = buf + n, *tens = buf + 2 * n, *tow = buf + 3 * n;
    ts_plot_axis panels[4];
    ts_plot_series ser[9];
    int np = 0, ns = 0;
    char outlabel[160], towlabel[6][64];
    snprintf(outlabel, sizeof outlabel, "%s", out->name);
    panels[np].label = outlabel;
    panels[np].quantity = out->kind == TS_OUT_STRAIN ? TS_PLOT_NONE
                          : ts_output_is_force(out)  ? TS_PLOT_FORCE
                                                     : TS_PLOT_LENGTH;
    if (hn) {
        for (int i = 0; i < hn->nsamples; i++)
            xn[i] = ts_history_value(sys, hn, out, i);
        ts_plot_series a = {hn->nsamples, hn->t, xn, "nonlinear", np,
                            TS_PLOT_SOLID, 1, NULL};
        ser[ns++] = a;
    }
    if (hl) {
        for (int i = 0; i < hl->nsamples; i++)
            xl[i] = ts_history_value(sys, hl, out, i);
        ts_plot_series a = {hl->nsamples, hl->t, xl, "linear", np,
                            TS_PLOT_DASHED, 2, NULL};
        ser[ns++] = a;
    }
    np++;
    /* Tow axes some signal drives: the translations (k 0..2), then the
     * rotations (3..5, their axis TS_AXIS_ROLL + k - 3), a panel each. */
    int used[6] = {0}, nused[2] = {0, 0};
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        ts_axis ax = ts_excitation_signal(ex, i)->axis;
        int k = ax <= TS_AXIS_HEAVE ? (int)ax
                : ax >= TS_AXIS_ROLL && ax <= TS_AXIS_YAW
                    ? 3 + (int)(ax - TS_AXIS_ROLL)
                    : -1;
        if (k >= 0 && !used[k]) {
            used[k] = 1;
            nused[k / 3]++;
        }
    }
    for (int g = 0, m = 0; g < 2; g++) {
        if (nused[g] == 0)
            continue;
        panels[np].label = g ? "ship rotation" : "tow point";
        panels[np].quantity = g ? TS_PLOT_ANGLE : TS_PLOT_LENGTH;
        for (int k = 3 * g; k < 3 * g + 3; k++) {
            if (!used[k])
                continue;
            int ax = k < 3 ? k : TS_AXIS_ROLL + k - 3;
            double *d = tow + (size_t)m * n;
            for (int i = 0; i < n; i++)
                d[i] = hf->input[TS_NINPUT * (size_t)i + (size_t)ax];
            snprintf(towlabel[m], sizeof towlabel[m], "%s",
                     ts_axis_name((ts_axis)ax));
            ts_plot_series a = {n, hf->t, d, towlabel[m], np, TS_PLOT_SOLID,
                                3 + m, NULL};
            ser[ns++] = a;
            m++;
        }
        np++;
    }
    ts_output tow_force;
    if (hn && hn->nsamples > 0 && isfinite(hn->tow_force[0]) &&
        ts_output_find(sys, "tow.force", TS_OUT_ALL, &tow_force, NULL) ==
            TS_OK) {
        for (int i = 0; i < hn->nsamples; i++)
            tens[i] = ts_history_value(sys, hn, &tow_force, i);
        panels[np].label = "tow.force (top tension)";
        panels[np].quantity = TS_PLOT_FORCE;
        ts_plot_series a = {hn->nsamples, hn->t, tens, "nonlinear", np,
                            TS_PLOT_SOLID, 1, NULL};
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
        cli_plot_wrote(plot, "histories");
    free(buf);
    return status;
}

/* Value of the history's output "<body>.<what>" at sample i; NAN if
 * none. */
static double output_at(const ts_history *h, const char *body,
                        const char *what, int i)
{
    char name[2 * TS_NAME_MAX + 16];
    snprintf(name, sizeof name, "%s.%s", body, what);
    for (int j = 0; h->outputs && j < h->noutput; j++)
        if (!strcmp(h->output_name[j], name))
            return h->outputs[(size_t)h->noutput * i + j];
    return NAN;
}

/* The vehicles at sample i, with the attitude and deflections the history
 * recorded. */
static int snapshot_vehicles(const ts_system *sys, const ts_history *h,
                             int i, cli_shape *s)
{
    for (int b = 0; b < sys->nbodies; b++) {
        const ts_vehicle *v = sys->bodies[b].vehicle;
        const char *nm = sys->bodies[b].name;
        if (!v)
            continue;
        double yaw = output_at(h, nm, "yaw", i),
               pitch = output_at(h, nm, "pitch", i),
               roll = output_at(h, nm, "roll", i);
        if (!isfinite(yaw) || !isfinite(pitch) || !isfinite(roll))
            continue;
        double R[9], delta[TS_VEHICLE_MAX_COMPONENTS];
        ts_vehicle_rotation(yaw, pitch, roll, R);
        for (int c = 0; c < v->ncomponents; c++) {
            char what[TS_VEHICLE_NAME_MAX + 16];
            snprintf(what, sizeof what, "%s.deflection",
                     v->component[c].name);
            double d = output_at(h, nm, what, i);
            delta[c] = isfinite(d) ? d : v->component[c].deflection;
        }
        if (cli_plot_add_vehicle(s, sys, b, R, delta) != 0)
            return -1;
    }
    return 0;
}

/* Snapshots of the cable every `interval` s from t = 0 (side and top
 * views, memo Figs. 9 and 11). */
/* The plan view in the earth frame under a manoeuvre (plan_earth): the
 * snapshots ps[nsnap] at samples idx[], the ship's track (the path of M's
 * origin) and the track of the last body (the towfish), from the run's
 * poses of M in the earth frame (h->frame, towstab/track.h: integrated by
 * the library from V (cos psi, sin psi)); a node's earth position is the
 * pose's origin plus R_z(psi) times its position in M. The ship starts
 * at the origin heading +x. */
static int plot_earth(const ts_system *sys, const ts_history *h,
                      const int *idx, int nsnap, const ts_plot_shape *ps,
                      const char *title, const cli_plot *plot)
{
    int n = h->nsamples;
    size_t nn = 3 * (size_t)h->nnodes;
    double *track = malloc(6 * (size_t)n * sizeof *track);
    double *pos = malloc((size_t)nsnap * nn * sizeof *pos);
    ts_plot_shape *es = malloc(((size_t)nsnap + 2) * sizeof *es);
    if (!track || !pos || !es) {
        free(track);
        free(pos);
        free(es);
        fprintf(stderr, "towstab: error: simulate: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    /* The last body's node (else the last node): the towfish. */
    int fish = h->nnodes - 1;
    for (int b = sys->nbodies - 1; b >= 0; b--) {
        int node = ts_system_body_node(sys, b);
        if (node > 0) {
            fish = node;
            break;
        }
    }
    double *ship = track, *fish_track = track + 3 * (size_t)n;
    for (int i = 0; i < n; i++) {
        const double *f = h->frame + 3 * (size_t)i;
        ship[3 * i] = f[0];
        ship[3 * i + 1] = f[1];
        ship[3 * i + 2] = 0;
        ts_track_to_earth(f, h->positions + nn * (size_t)i + 3 * (size_t)fish,
                          fish_track + 3 * (size_t)i);
    }
    for (int k = 0; k < nsnap; k++) {
        const double *f = h->frame + 3 * (size_t)idx[k];
        const double *m = ps[k].pos;
        double *e = pos + nn * (size_t)k;
        for (int j = 0; j < h->nnodes; j++)
            ts_track_to_earth(f, m + 3 * j, e + 3 * j);
        es[k] = ps[k];
        es[k].pos = e;
        es[k].turn_radius = 0;
    }
    ts_plot_shape tr = {0};
    tr.nnodes = n;
    tr.pos = ship;
    tr.label = "ship's track";
    tr.style = TS_PLOT_DASHED;
    tr.color = nsnap + 1;
    es[nsnap] = tr;
    char fish_label[TS_NAME_MAX + 16];
    ts_system_node_name(sys, fish, fish_label, TS_NAME_MAX);
    strcat(fish_label, "'s track");
    tr.pos = fish_track;
    tr.label = fish_label;
    tr.color = nsnap + 2;
    es[nsnap + 1] = tr;
    ts_err err = {0};
    int status = 0;
    if (ts_plot_shapes(plot->dir, "plan_earth", title, TS_PLOT_TOP, 0,
                       nsnap + 2, es, &plot->opts, &err) != TS_OK)
        status = cli_report(&err, err.code);
    else
        printf("wrote %s/plan_earth.png and %s/plan_earth.svg\n", plot->dir,
               plot->dir);
    free(track);
    free(pos);
    free(es);
    return status;
}

/* The tracks in the earth frame (towstab/track.h) under a manoeuvre, in
 * a turn or with a towing vehicle: `tracks`, the ship's (M's origin; a
 * towing vehicle's tow point, with the scene's waypoints as markers) and
 * every body's in plan view
 * (ts_plot_tracks), from the run's poses of M; and `depths`, every body's
 * depth against time (the nonlinear run solid, the linear dashed). */
#define MAX_TRACKS 8
static int plot_tracks(const ts_system *sys, const ts_history *hn,
                       const ts_history *hl, const cli_plot *plot)
{
    const ts_history *h = hn ? hn : hl;
    int n = h->nsamples;
    int node[MAX_TRACKS], nb = 0;
    for (int b = 0; b < sys->nbodies && nb < MAX_TRACKS - 1; b++) {
        int k = ts_system_body_node(sys, b);
        if (k > 0)
            node[nb++] = k;
    }
    /* x, y of the ship and each body; z of each body in both runs. */
    double *buf = malloc((size_t)(2 * (nb + 1) + 2 * nb) * (size_t)n *
                         sizeof *buf);
    if (!buf) {
        fprintf(stderr, "towstab: error: simulate: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    char label[MAX_TRACKS][TS_NAME_MAX + 16];
    ts_plot_track tr[MAX_TRACKS];
    int towing = sys->tow.vehicle >= 0;
    const ts_autopilot *ap = &sys->tow.autopilot;
    int nwp = ap->on ? ap->g.nwaypoints : 0;
    ts_plot_marker wp[TS_GUIDANCE_MAX_WAYPOINTS];
    char wlabel[TS_GUIDANCE_MAX_WAYPOINTS][16];
    for (int i = 0; i < nwp; i++) {
        snprintf(wlabel[i], sizeof wlabel[i], "WP %d", i + 1);
        ts_plot_marker m = {ap->g.waypoint[i][0], ap->g.waypoint[i][1],
                            wlabel[i]};
        wp[i] = m;
    }
    size_t nn = 3 * (size_t)h->nnodes;
    for (int j = 0; j <= nb; j++) {
        double *x = buf + 2 * (size_t)j * (size_t)n, *y = x + n;
        for (int i = 0; i < n; i++) {
            const double *f = h->frame + 3 * (size_t)i;
            double e[3] = {f[0], f[1], 0};
            /* A towing vehicle's track is its tow point's (node 0). */
            if (j > 0 || towing)
                ts_track_to_earth(f, h->positions + nn * (size_t)i +
                                         3 * (size_t)(j ? node[j - 1] : 0),
                                  e);
            x[i] = e[0];
            y[i] = e[1];
        }
        if (j == 0 && towing)
            snprintf(label[j], sizeof label[j], "%.*s (tow point)",
                     TS_NAME_MAX, sys->bodies[sys->tow.vehicle].name);
        else if (j == 0)
            snprintf(label[j], sizeof label[j], "ship (M's origin)");
        else
            ts_system_node_name(sys, node[j - 1], label[j], TS_NAME_MAX);
        /* The waypoints, as markers on the towing vehicle's track. */
        ts_plot_track t = {n, x, y, label[j],
                           j == 0 ? TS_PLOT_DASHED : TS_PLOT_SOLID, j + 1,
                           j == 0 ? nwp : 0, j == 0 && nwp ? wp : NULL};
        tr[j] = t;
    }
    char title[256];
    snprintf(title, sizeof title, "%s: tracks in the earth frame%s",
             sys->name, hn ? "" : ", linear model");
    ts_err err = {0};
    int status = 0;
    if (ts_plot_tracks(plot->dir, "tracks", title, nb + 1, tr, &plot->opts,
                       &err) != TS_OK)
        status = cli_report(&err, err.code);
    else
        cli_plot_wrote(plot, "tracks");
    if (!status && nb > 0) {
        double *z = buf + 2 * (size_t)(nb + 1) * (size_t)n;
        ts_plot_series ser[2 * MAX_TRACKS];
        char slabel[2 * MAX_TRACKS][TS_NAME_MAX + 16];
        int ns = 0;
        const ts_history *runs[2] = {hn, hl};
        for (int r = 0; r < 2; r++) {
            if (!runs[r])
                continue;
            for (int j = 0; j < nb; j++, ns++) {
                double *d = z + (size_t)ns * (size_t)n;
                int m = runs[r]->nsamples < n ? runs[r]->nsamples : n;
                for (int i = 0; i < m; i++)
                    d[i] = runs[r]->positions[nn * (size_t)i +
                                              3 * (size_t)node[j] + 2];
                snprintf(slabel[ns], sizeof slabel[ns], "%s%s",
                         label[j + 1], hn && hl ? (r ? " linear" : "") : "");
                ts_plot_series a = {m, runs[r]->t, d, slabel[ns], 0,
                                    r ? TS_PLOT_DASHED : TS_PLOT_SOLID,
                                    j + 2, NULL};
                ser[ns] = a;
            }
        }
        ts_plot_axis panel = {"depth z (down)", TS_PLOT_LENGTH, NULL};
        snprintf(title, sizeof title, "%s: depths against time", sys->name);
        if (ts_plot_histories(plot->dir, "depths", title, 1, &panel, ns, ser,
                              &plot->opts, &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            cli_plot_wrote(plot, "depths");
    }
    free(buf);
    return status;
}

static int plot_snapshots(const ts_system *sys, const ts_equilibrium *eq,
                          const ts_history *h, const ts_excitation *ex,
                          double interval, double exaggerate,
                          const cli_plot *plot)
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
    /* Exaggerated: the first sample plus K times the displacement from
     * it. */
    size_t nn = 3 * (size_t)h->nnodes;
    double *xs = exaggerate != 1.0
                     ? malloc((size_t)nsnap * nn * sizeof *xs)
                     : NULL;
    int status = 0, made = 0;
    if (exaggerate != 1.0 && !xs) {
        fprintf(stderr, "towstab: error: simulate: --plot: out of memory\n");
        status = EXIT_FAILED;
    }
    for (int k = 0; k < nsnap && !status; k++) {
        const double *pos = h->positions + nn * (size_t)idx[k];
        if (xs) {
            double *e = xs + nn * (size_t)k;
            for (size_t j = 0; j < nn; j++)
                e[j] = h->positions[j] +
                       exaggerate * (pos[j] - h->positions[j]);
            pos = e;
        }
        if (cli_plot_shape(sys, eq, pos, &shapes[k]) != 0 ||
            snapshot_vehicles(sys, h, idx[k], &shapes[k]) != 0) {
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
        char title[256], ext[96] = "";
        if (exaggerate != 1.0)
            snprintf(ext, sizeof ext, ", displacements from t = %.4g s "
                     "x %.4g", h->t[0], exaggerate);
        snprintf(title, sizeof title, "%s: cable every %.4g s%s, %s",
                 sys->name, interval, ext, views[v]);
        ts_err err = {0};
        if (ts_plot_shapes(plot->dir, names[v], title,
                           v == 0 ? TS_PLOT_SIDE : TS_PLOT_TOP,
                           TS_PLOT_WATER, nsnap, ps, &plot->opts,
                           &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            cli_plot_wrote(plot, names[v]);
    }
    if (!status && ex && ts_excitation_has_manoeuvre(ex)) {
        char title[256];
        snprintf(title, sizeof title, "%s: manoeuvre in the earth frame, "
                 "cable every %.4g s%s and the tracks", sys->name,
                 interval, exaggerate != 1.0 ? " (exaggerated)" : "");
        status = plot_earth(sys, h, idx, nsnap, ps, title, plot);
    }
    for (int k = 0; k < made; k++)
        cli_plot_shape_free(&shapes[k]);
    free(xs);
    return status;
}

/* What --plot draws with: the interval of the snapshots (s). */
typedef struct sim_state {
    double snapshot;
    double exaggerate; /* --exaggerate: the snapshots' displacement scale */
} sim_state;

enum { X_SNAPSHOT, X_EXAGGERATE };

static int sim_prepare(cli_run *c)
{
    const char *text = c->nextra[X_SNAPSHOT] ? c->extra[X_SNAPSHOT][0]
                                             : NULL;
    const char *xtext = c->nextra[X_EXAGGERATE] ? c->extra[X_EXAGGERATE][0]
                                                : NULL;
    if ((text || xtext) && !c->plot.dir) {
        fprintf(stderr, "towstab: error: simulate: %s sets the snapshots of "
                        "the --plot pictures; add --plot DIR\n",
                text ? "--snapshot-interval" : "--exaggerate");
        return EXIT_BADINPUT;
    }
    if (!c->plot.dir)
        return 0;
    c->rq.simulate.tracks = 1; /* the tracks and plan_earth pictures */
    sim_state *st = calloc(1, sizeof *st);
    if (!st) {
        fprintf(stderr, "towstab: error: simulate: out of memory\n");
        return EXIT_FAILED;
    }
    c->state = st;
    st->exaggerate = 1.0;
    if (xtext) {
        char *end;
        double k = strtod(xtext, &end);
        if (end == xtext || *end || !(k >= 1) || !(k <= 1e6)) {
            fprintf(stderr, "towstab: error: simulate: --exaggerate: "
                            "expected a factor from 1 to 1e6, got '%s'\n",
                    xtext);
            return EXIT_BADINPUT;
        }
        st->exaggerate = k;
    }
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

/* A record's statistics beside the spectral prediction, the values times
 * k (the output's display unit) and the times times kt. */
static void print_record(const char *what, const ts_record_stats *st,
                         double k, double kt)
{
    char tz[32] = "none", ind[32] = "none";
    if (isfinite(st->tz))
        snprintf(tz, sizeof tz, "%.4g", kt * st->tz);
    if (isfinite(st->independent))
        snprintf(ind, sizeof ind, "%.4g", st->independent);
    printf("  %-10s %14.6g +- %-10.2g %14.6g +- %-10.2g %10s %8s %8.4g\n",
           what, k * st->sigma.value, k * st->sigma.error, k * st->mean,
           k * st->mean_error, tz, ind, k * st->maximum);
}

static void print_sea(const ts_result *r, const ts_display *d)
{
    const char *tu = ts_display_unit(d, TS_QTY_TIME);
    double kt = ts_display_value(d, TS_QTY_TIME, 1.0);
    printf("\nirregular sea, realisation: seed %lu, %d sinusoids, fade-in "
           "%.6g %s\n", r->realisation.seed, r->realisation.components,
           kt * r->realisation.rise, tu);
    cli_print_seastate(r, 1, d);
    if (!r->has_records)
        return;
    char ou[64], h[3][96];
    double k = ts_display_convert(d, r->output.si_unit, 1.0, ou, sizeof ou);
    printf("records of %s over t = %.6g .. %.6g %s:\n", r->output.name,
           kt * r->transient, kt * r->sim.t_end, tu);
    snprintf(h[0], sizeof h[0], "sigma [%s]", ou);
    snprintf(h[1], sizeof h[1], "mean [%s]", ou);
    snprintf(h[2], sizeof h[2], "Tz [%s]", tu);
    char mx[96];
    snprintf(mx, sizeof mx, "max [%s]", ou);
    printf("  %-10s %14s    %-10s %14s    %-10s %10s %8s %8s\n", "", h[0],
           "(stat.)", h[1], "(stat.)", h[2], "indep.", mx);
    if (r->has_records & 2)
        print_record("linear", &r->record_linear, k, kt);
    if (r->has_records & 1)
        print_record("nonlinear", &r->record_nonlinear, k, kt);
    if (r->seastate)
        printf("  %-10s %14.6g +- %-10.2g %14.6g\n", "spectral",
               k * r->seastate->sigma.value, k * r->seastate->sigma.error,
               k * r->seastate->mean);
}

static void sim_print(const cli_run *c, const ts_result *r)
{
    const ts_system *sys = r->sys;
    if (!sys)
        return;
    const ts_display *d = &c->display;
    char tow[256];
    cli_tow_text(sys, r->eq, d, tow, sizeof tow);
    printf("simulate %s: %d links, %s\n", sys->name, sys->nlinks, tow);
    char desc[256];
    const ts_excitation *ex = r->excitation;
    for (int i = 0; ex && i < ts_excitation_nsignals(ex); i++) {
        ts_excitation_describe_display(ex, i, d, desc, sizeof desc);
        printf("input: %s\n", desc);
    }
    ts_initial init = c->rq.simulate.initial;
    if (init == TS_INITIAL_EQUILIBRIUM && r->eq && r->eq->converged)
        printf("initial state: equilibrium (%s, residual %.3g of %.6g %s)\n",
               ts_eq_method_name(r->eq->method), r->eq->residual,
               ts_display_value(d, TS_QTY_FORCE, r->eq->force_scale),
               ts_display_unit(d, TS_QTY_FORCE));
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
        char method[96];
        const char *lm = ts_linear_method_name(&r->sim, &r->linear_stats);
        snprintf(method, sizeof method, "%s%s, %s kinematics",
                 strcmp(lm, "expm") ? lm : "exact discretisation (expm)",
                 r->linear_stats.newton == TS_NEWTON_SPARSE
                     ? " on the sparse model"
                     : "",
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
        print_table(r, d);
    print_forces(r, d);
    print_waypoints(r, d);
    if (r->has_sea)
        print_sea(r, d);
    for (int v = 0, head = 0; !r->has_sea && v < r->nvalues; v++) {
        char er[160];
        if (!isfinite(r->values[v].value))
            continue;
        if (!head++)
            printf("\nkey values (nonlinear run; fits and tension.max|min "
                   "over t >= %.6g %s, forces over %s):\n",
                   ts_display_value(d, TS_QTY_TIME, r->transient),
                   ts_display_unit(d, TS_QTY_TIME),
                   r->forces_from > 0 ? "the same window" : "the run");
        cli_value_error(&r->values[v], d, er, sizeof er);
        printf("%-34s %14.8g %s\n", r->values[v].name,
               cli_value_shown(&r->values[v], d), er);
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
        print_compare(&r->compare, d);
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
        status = plot_snapshots(r->sys, r->eq, h, r->excitation,
                                st->snapshot, st->exaggerate, &c->plot);
    if (!status && ((r->excitation &&
                     ts_excitation_has_manoeuvre(r->excitation)) ||
                    r->sys->tow.turn_rate != 0 || r->sys->tow.vehicle >= 0))
        status = plot_tracks(r->sys, r->nonlinear, r->linear, &c->plot);
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
    {"exaggerate", 1, 0, "K",
     "the snapshots show the first sample plus K times the displacement "
     "from it (default 1)"},
    {NULL, 0, 0, NULL, NULL}};

static const char *const sim_pictures[] = {"histories", "snapshots_side",
                                           "snapshots_top", "plan_earth",
                                           NULL};

const cli_command cli_cmd_simulate = {
    "simulate", "nonlinear and linear time-domain simulation, comparison",
    TS_ANALYSIS_SIMULATE, NULL, sim_prepare, sim_print, sim_draw,
    sim_release, sim_pictures, sim_extras, NULL};
