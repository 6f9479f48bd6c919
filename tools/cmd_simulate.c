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
#include "towstab/report_converge.h"
#include "towstab/health.h"
#include "cli_plot.h"
#include "cli_sim.h"
#include "towstab/compare.h"
#include "towstab/equilibrium.h"
#include "towstab/excitation.h"
#include "towstab/linearize.h"
#include "towstab/report.h"
#include "towstab/report_time.h"
#include "towstab/response.h"
#include "towstab/simulate.h"

/* Largest number of table rows printed (longer runs are strided). */
#define TABLE_ROWS 60

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
        "  --integrator M     rk8pd (default), rkf45, rk4imp, bsimp, msbdf,\n"
        "                     esdirk (L-stable: use it on elastic cables)\n"
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
        "  --plot DIR         draw the time histories (histories.png/svg)\n"
        "                     and snapshots of the cable (snapshots_side,\n"
        "                     snapshots_top)\n"
        "  --units U          units of the pictures: si or imperial\n"
        "  --snapshot-interval T  time between snapshots (default t_end/10)\n"
        "  --quiet            summary only\n",
        CLI_SIM_DEFAULT_T_END, CLI_SIM_DEFAULT_SAMPLE,
        CLI_SIM_DEFAULT_SAMPLES_PER_PERIOD);
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

/* ---- pictures (--plot) ------------------------------------------------- */

/* Snapshots of the cable drawn at most. */
#define MAX_SNAPSHOTS 21

/* What --plot draws with: the directory and units, and the interval of
 * the snapshots (s; 0: t_end / 10). */
typedef struct sim_plot {
    const cli_plot *plot;
    double snapshot;
} sim_plot;

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
static int plot_histories(const ts_system *sys, const cli_sim_setup *s,
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
    snprintf(outlabel, sizeof outlabel, "%s", s->out.name);
    panels[np].label = outlabel;
    panels[np].quantity = TS_PLOT_LENGTH;
    size_t st = 3 * (size_t)hf->nnodes;
    size_t off = 3 * (size_t)s->out.node + (size_t)s->out.comp;
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
    for (int i = 0; i < ts_excitation_nsignals(ex); i++) {
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

/* The whole analysis. *result receives the JSON (caller frees). With
 * `full`, histories of every node; else of the output node only. */
static int simulate(const cli_ctx *ctx, const cli_sim_args *a,
                    const cli_settings *cs, int full, const sim_plot *sp,
                    json_t **result)
{
    ts_err err = {0}, werr = {0};
    *result = NULL;
    cli_sim_prep prep;
    int rc = cli_sim_prepare(ctx, a, cs, &prep, &err);
    double snap = sp ? sp->snapshot : 0;
    if (!rc && sp && snap == 0)
        snap = prep.s.o.t_end / 10;
    if (!rc && sp && snap * (MAX_SNAPSHOTS - 1) < prep.s.o.t_end * (1 - 1e-9))
        rc = ts_fail(&err, TS_EINVAL, "--snapshot-interval: %g s gives more "
                     "than %d snapshots of the %g s run; at least %g s",
                     snap, MAX_SNAPSHOTS, prep.s.o.t_end,
                     prep.s.o.t_end / (MAX_SNAPSHOTS - 1));
    if (!rc && sp && snap > prep.s.o.t_end)
        rc = ts_fail(&err, TS_EINVAL, "--snapshot-interval: %g s is longer "
                     "than the run (%g s)", snap, prep.s.o.t_end);
    if (rc) {
        cli_sim_prep_free(&prep);
        return cli_report(&err, rc);
    }
    ts_system *sys = prep.sys;
    ts_excitation *ex = prep.ex;
    ts_equilibrium_opts eo = prep.eo;
    cli_sim_setup s = prep.s;
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
    if (s.init == SIM_INIT_EQ) {
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
    } else if (s.init == SIM_INIT_RELEASED) {
        rc = ts_sim_released_state(k, s.theta1, s.theta2, y0, &err);
        printf("initial state: %s\n", s.init_text);
    } else {
        rc = read_shape(sys, s.shape_path, a->where[SIM_A_INITIAL], pos, &err);
        if (!rc) {
            rc = ts_sim_shape_state(k, pos, CLI_SIM_SHAPE_RTOL, y0, &err);
            if (rc)
                ts_err_prefix(&err, "%s: %s: ", a->where[SIM_A_INITIAL],
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
        /* The linear simulation uses the dense A and B, the response
         * prediction of --compare the sparse model. */
        lo.model = TS_LIN_BOTH;
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
    /* Is the result trustworthy? The start, the linear model's kinks and
     * the integrations' statistics (towstab/health.h). */
    ts_trust trust;
    ts_trust_init(&trust);
    if (eq) {
        ts_trust te;
        ts_trust_init(&te);
        ts_health_equilibrium(sys, eq, &te);
        ts_trust_merge(&trust, "initial equilibrium: ", &te);
    }
    if (lin && lin->kink_tow && s.compare)
        ts_trust_note(&trust, "the tow point is at the water surface: a "
                              "heave shifts the mean depth at first order, "
                              "which the linear model cannot show");
    if (hn)
        ts_health_simulation(&s.o, &st_nl, &trust);
    if (hl && s.o.linear_method != TS_LINSIM_EXPM)
        ts_health_simulation(&s.o, &st_lin, &trust);
    if (ran) {
        printf("trustworthy: %s\n", trust.trustworthy ? "yes" : "NO");
        for (int i = 0; i < trust.nreasons; i++)
            printf("  reason: %s\n", trust.reasons[i]);
        for (int i = 0; i < trust.nnotes; i++)
            printf("  note: %s\n", trust.notes[i]);
    }
    if (s.compare && !status) {
        rc = ts_compare_histories(sys, lin, ex, hn, hl, &s.out, s.transient,
                                  &cmp, &err);
        if (rc) {
            ts_err_prefix(&err, "%s: ", a->where[SIM_A_COMPARE]);
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
    {
        json_t *tj = ts_report_trust_json(&trust);
        if (tj) {
            json_object_update(j, tj);
            json_decref(tj);
        }
    }
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
    if (a->val[SIM_A_CSV] && (hn || hl) &&
        ts_report_history_csv(sys, hn, hl, a->val[SIM_A_CSV], &werr) != TS_OK) {
        int st2 = cli_report(&werr, werr.code);
        if (!status)
            status = st2;
    }
    if (sp && (hn || hl) && (hn ? hn : hl)->nsamples > 1) {
        int ps = plot_histories(sys, &s, ex, hn, hl, sp->plot);
        if (!ps)
            ps = plot_snapshots(sys, hn ? hn : hl, snap, sp->plot);
        if (ps && !status)
            status = ps;
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
    cli_sim_prep_free(&prep);
    return status;
}


static const char *const sim_keys[] = {
    "t_end", "sample", "initial", "integrator", "rtol", "atol", "h_min",
    "max_steps", "transient", "output", "linear_method", "kinematics",
    "excite", "manoeuvre", "compare", "linear", "csv", "speed", "turn_rate",
    "method", "tolerance", "links", NULL};

static int sim_main(int argc, char **argv)
{
    cli_sim_args a;
    memset(&a, 0, sizeof a);
    for (int i = 0; i < SIM_A_N; i++)
        snprintf(a.where[i], sizeof a.where[i], "%s", cli_sim_arg_opts[i]);
    cli_settings cs = {0};
    cli_settings_from_options(&cs);
    cli_plot plot = {0};
    const char *snap_text = NULL;
    enum { O_JSON = 1000, O_QUIET, O_HELP, O_SPEED, O_TURN, O_LINKS,
           O_METHOD, O_TOL, O_PLOT, O_UNITS, O_SNAP };
    static const struct option longopts[] = {
        {"t-end", required_argument, NULL, SIM_A_T_END},
        {"sample", required_argument, NULL, SIM_A_SAMPLE},
        {"initial", required_argument, NULL, SIM_A_INITIAL},
        {"integrator", required_argument, NULL, SIM_A_INTEGRATOR},
        {"rtol", required_argument, NULL, SIM_A_RTOL},
        {"atol", required_argument, NULL, SIM_A_ATOL},
        {"h-min", required_argument, NULL, SIM_A_H_MIN},
        {"max-steps", required_argument, NULL, SIM_A_MAX_STEPS},
        {"transient", required_argument, NULL, SIM_A_TRANSIENT},
        {"output", required_argument, NULL, SIM_A_OUTPUT},
        {"linear-method", required_argument, NULL, SIM_A_LINEAR_METHOD},
        {"kinematics", required_argument, NULL, SIM_A_KINEMATICS},
        {"excite", required_argument, NULL, SIM_A_EXCITE},
        {"manoeuvre", required_argument, NULL, SIM_A_MANOEUVRE},
        {"compare", no_argument, NULL, SIM_A_COMPARE},
        {"linear", no_argument, NULL, SIM_A_LINEAR},
        {"csv", required_argument, NULL, SIM_A_CSV},
        {"json", required_argument, NULL, O_JSON},
        {"quiet", no_argument, NULL, O_QUIET},
        {"help", no_argument, NULL, O_HELP},
        {"speed", required_argument, NULL, O_SPEED},
        {"turn-rate", required_argument, NULL, O_TURN},
        {"links", required_argument, NULL, O_LINKS},
        {"method", required_argument, NULL, O_METHOD},
        {"tol", required_argument, NULL, O_TOL},
        {"plot", required_argument, NULL, O_PLOT},
        {"units", required_argument, NULL, O_UNITS},
        {"snapshot-interval", required_argument, NULL, O_SNAP},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    long v;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        if (ch >= 0 && ch < SIM_A_N) {
            if (ch == SIM_A_EXCITE || ch == SIM_A_MANOEUVRE) {
                int m = ch == SIM_A_MANOEUVRE;
                if (a.nspecs[m] == CLI_SIM_MAX_SPECS) {
                    fprintf(stderr, "towstab: error: simulate: %s: at most %d\n",
                            cli_sim_arg_opts[ch], CLI_SIM_MAX_SPECS);
                    return EXIT_BADINPUT;
                }
                a.specs[m][a.nspecs[m]++] = optarg;
            } else {
                a.val[ch] = ch == SIM_A_COMPARE || ch == SIM_A_LINEAR ? "true"
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
        case O_PLOT: plot.dir = optarg; break;
        case O_UNITS: plot.units = optarg; break;
        case O_SNAP: snap_text = optarg; break;
        case O_LINKS:
            if (cli_parse_int("--links", optarg, 1, 10000000, &v))
                return EXIT_BADINPUT;
            cs.links = (int)v;
            break;
        case ':':
        default:
            return cli_option_error("simulate", ch, argv[optind - 1]);
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: simulate: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    if (snap_text && !plot.dir) {
        fprintf(stderr, "towstab: error: simulate: --snapshot-interval sets the "
                        "snapshots of the --plot pictures; add --plot DIR\n");
        return EXIT_BADINPUT;
    }
    int pstatus = cli_plot_begin(&plot, "simulate");
    if (pstatus)
        return pstatus;
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
        cli_sim_args_from_entry(&a, e, i);
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
    sim_plot sp = {&plot, 0};
    if (snap_text &&
        (ts_units_parse(units, snap_text, "s", "--snapshot-interval",
                        &sp.snapshot, &err) != TS_OK ||
         (!(sp.snapshot > 0) &&
          ts_fail(&err, TS_EINVAL, "--snapshot-interval: expected a time "
                  "> 0 s, got '%s'", snap_text) != TS_OK))) {
        status = cli_report(&err, err.code ? err.code : TS_EINVAL);
        cli_close(units, scene);
        return status;
    }
    status = simulate(&ctx, &a, &cs, 1, plot.dir ? &sp : NULL, &j);
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

/* One scene entry (cli_command.entry): without a result slot, check that
 * the entry prepares (options, excitation, output, initial state); with
 * one, run it. */
static int sim_entry(const cli_ctx *ctx, const ts_scene_analysis *e,
                     int index, json_t **result)
{
    ts_err err = {0};
    cli_sim_args a;
    memset(&a, 0, sizeof a);
    cli_sim_args_from_entry(&a, e, index);
    for (int i = 0; i < SIM_A_N; i++)
        if (!a.where[i][0])
            snprintf(a.where[i], sizeof a.where[i], "analyses[%d].%s",
                     index, cli_sim_arg_keys[i]);
    cli_settings cs = {0};
    if (cli_settings_from_analysis(&cs, e, index, &err))
        return cli_report(&err, err.code);
    if (result)
        return simulate(ctx, &a, &cs, 0, NULL, result);
    cli_sim_prep prep;
    int rc = cli_sim_prepare(ctx, &a, &cs, &prep, &err);
    cli_sim_prep_free(&prep);
    return rc ? cli_report(&err, rc) : 0;
}

const cli_command cli_cmd_simulate = {
    "simulate", "nonlinear and linear time-domain simulation, comparison",
    sim_main, sim_entry, sim_keys};
