/* cmd_modes.c: `towstab modes SCENE` and the `modes` analysis of a scene:
 * equilibrium, linearization, eigen analysis, mode table and stability
 * verdict (doc/linear.md). Also defines cli_print_linearization(), which
 * cmd_response.c shares. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "towstab/eigen.h"
#include "towstab/health.h"
#include "towstab/linearize.h"
#include "towstab/report.h"
#include "towstab/report_linear.h"
#include "towstab/report_result.h"

void cli_print_linearization(const ts_result *r)
{
    const ts_linear *l = r->lin;
    if (!l)
        return;
    if (l->A)
        printf("linearized: %d states, %d inputs, %ld kernel evaluations on "
               "%d thread%s, %.3f ms; truncation error %.3g (max |A| %.6g, "
               "||dA||_F %.3g), rounding noise ||N||_F %.3g\n",
               l->nstate, l->ninput, l->evaluations, l->threads,
               l->threads == 1 ? "" : "s", r->lin_wall_s * 1e3, l->trunc_err,
               l->a_scale, l->trunc_norm, l->round_norm);
    else
        printf("linearized: %d states, sparse model (%d perturbation groups, "
               "%ld residual evaluations on %d thread%s), %.3f ms; relative "
               "truncation error %.3g, rounding noise %.3g\n",
               l->nstate, l->groups, l->residual_evaluations, l->threads,
               l->threads == 1 ? "" : "s", r->lin_wall_s * 1e3, l->desc_err,
               l->desc_round);
    if (r->open_loop)
        printf("open loop: the vehicles' controller loops are open, their "
               "surfaces held at the trim's deflections\n");
    if (l->kinks > l->kink_tow) {
        char name[2 * TS_NAME_MAX];
        ts_system_node_name(r->sys, l->kink_node, name, sizeof name);
        printf("warning: %d node%s (first %s, depth %.3g m) within a step "
               "of the water surface: f is not smooth there, A is the mean "
               "of one-sided derivatives and the modes near it are not "
               "trustworthy\n",
               l->kinks - l->kink_tow, l->kinks - l->kink_tow == 1 ? "" : "s",
               name, l->r0[3 * l->kink_node + 2]);
    }
    if (l->kink_tow)
        printf("note: the tow point is at the water surface: the heave "
               "input (column of B) is the mean of the one-sided "
               "derivatives; the modes (A) are not affected\n");
}

/* The label of an unresolved mode. */
static void unresolved_label(const ts_result *r, int m, char *buf,
                             size_t size)
{
    const ts_mode_accuracy *a = &r->mode_accuracy[m];
    const ts_result_accuracy *acc = &r->accuracy;
    const ts_mode *md = &r->eigen->modes[m];
    buf[0] = '\0';
    if (a->resolved)
        return;
    if (a->grid_scale)
        snprintf(buf, size, " [UNRESOLVED: %.2g links per half-wave]",
                 a->half_wave_links);
    else if (isfinite(a->error))
        snprintf(buf, size, " [UNRESOLVED: error %.2g of |lambda| from %d "
                 "and %d links]", a->error / hypot(md->re, md->im),
                 acc->links[0], acc->links[1]);
    else
        snprintf(buf, size, " [UNRESOLVED: no counterpart at %d links]",
                 acc->links[1]);
}

/* The stability verdict: the resolved modes' margin, and apart the
 * unresolved modes'; without an estimate, every mode computed. */
static void print_verdict(const ts_result *r)
{
    const ts_eigen *e = r->eigen;
    const ts_stability *st = &r->stability;
    const char *scope = e->complete         ? ""
                        : e->sweep_shifts > 0 ? " among the eigenvalues found"
                                              : " among the modes computed";
    if (!st->estimated) {
        switch (e->verdict) {
        case TS_STABLE:
            printf("verdict: stable%s: max Re(lambda) = %.6g 1/s, error "
                   "bound %.2g 1/s (the margin is %.3g times its error)\n",
                   scope, e->max_real, e->max_real_error,
                   e->max_real_error > 0 ? -e->max_real / e->max_real_error
                                         : INFINITY);
            break;
        case TS_UNSTABLE:
            printf("verdict: UNSTABLE%s: max Re(lambda) = %.6g 1/s > 0, "
                   "error bound %.2g 1/s\n",
                   scope, e->max_real, e->max_real_error);
            break;
        default:
            if (ts_eigen_other_undecided(e))
                /* The rightmost is decided; another's bound is wider. */
                printf("verdict: marginal%s: max Re(lambda) = %.3g 1/s "
                       "(error bound %.2g 1/s), but Re(lambda) = %.3g 1/s "
                       "is within its error bound %.2g 1/s of 0; the "
                       "linear model does not decide stability\n",
                       scope, e->max_real, e->max_real_error,
                       e->undecided_real, e->undecided_error);
            else
                printf("verdict: marginal%s: max Re(lambda) = %.3g 1/s is "
                       "within its error bound %.2g 1/s of 0; the linear "
                       "model does not decide stability (undamped or "
                       "nearly so)\n",
                       scope, e->max_real, e->max_real_error);
        }
        printf("note: the verdict covers every mode, resolved or not (the "
               "discretisation error was not estimated); %d mode%s vary on "
               "the scale of one or two links\n",
               st->nunresolved, st->nunresolved == 1 ? "" : "s");
        return;
    }
    /* The verdict of the discrete model (every mode computed), then whose
     * margin it is. */
    const char *all = e->verdict == TS_STABLE     ? "stable"
                      : e->verdict == TS_UNSTABLE ? "UNSTABLE"
                                                  : "marginal";
    printf("verdict: %s%s", all, scope);
    if (st->verdict < 0) {
        printf(" as computed, but no mode is resolved to the accuracy %.3g "
               "at %d links: max Re(lambda) = %.6g 1/s (mode %d, "
               "unresolved) is no margin of the cable\n",
               r->accuracy.accuracy, r->accuracy.links[0],
               st->unresolved_max_real, st->unresolved_mode + 1);
        return;
    }
    double err = st->solver_error + (isfinite(st->discretisation_error)
                                         ? st->discretisation_error
                                         : 0.0);
    printf(": the %d resolved mode%s %s: max Re(lambda) = %.6g 1/s (mode "
           "%d) +- %.2g (discretisation) +- %.2g (solver)",
           st->nresolved, st->nresolved == 1 ? " is" : "s are",
           st->verdict == TS_STABLE     ? "stable"
           : st->verdict == TS_UNSTABLE ? "UNSTABLE"
                                        : "marginal",
           st->max_real, st->mode + 1, st->discretisation_error,
           st->solver_error);
    if (st->verdict == TS_STABLE)
        printf(", the margin %.3g times its error", -st->max_real / err);
    printf("\n");
    if (st->unresolved_verdict >= 0)
        printf("unresolved modes (%d: grid-scale, or not resolved to the "
               "accuracy at %d links): %s as computed, max Re(lambda) = "
               "%.6g 1/s (mode %d), error bound %.2g 1/s%s\n",
               st->nunresolved, r->accuracy.links[0],
               st->unresolved_verdict == TS_STABLE     ? "stable"
               : st->unresolved_verdict == TS_UNSTABLE ? "UNSTABLE"
                                                       : "marginal",
               st->unresolved_max_real, st->unresolved_mode + 1,
               st->unresolved_error,
               st->unresolved_verdict == TS_UNSTABLE
                   ? "; an artefact of the links, or an instability they "
                     "cannot resolve"
                   : "");
}

/* The towing vehicle's neutral modes by symmetry, which the verdict
 * leaves out (doc/linear.md section 3a). */
static void print_neutral(const ts_result *r)
{
    const ts_eigen *e = r->eigen;
    const ts_linear *lin = r->lin;
    if (e->nneutral == 0)
        return;
    printf("neutral by symmetry, not counted in the verdict (%d):",
           e->nneutral);
    int k = 0;
    for (int m = 0; m < e->nmodes; m++) {
        const ts_mode *md = &e->modes[m];
        if (md->neutral < 0)
            continue;
        printf("%s mode %d, %s, lambda = %.6g%+.6gi 1/s exactly (computed "
               "within %.2g of it)",
               k++ ? ";" : "", m + 1, lin->neutral[md->neutral].name, md->re,
               md->im, md->error_bound);
    }
    printf("\n");
}

static void print_modes(const ts_result *r, int quiet, const ts_display *d)
{
    const ts_system *sys = r->sys;
    const ts_linear *lin = r->lin;
    const ts_eigen *e = r->eigen;
    const ts_mode_health *mh = r->mode_health;
    printf("eigen: %s, %d mode%s (%d of %d eigenvalues)%s, %.3f ms",
           ts_eig_method_name(e->method), r->nmodes_computed,
           r->nmodes_computed == 1 ? "" : "s", e->neig, e->nstate,
           e->complete ? "" : " nearest the target", r->eigen_wall_s * 1e3);
    if (e->method == TS_EIG_ARPACK)
        printf(", %d restarts, %d operator applications", e->arpack_iterations,
               e->arpack_ops);
    printf("\n");
    if (e->sweep_shifts > 0)
        printf("rightmost search: %d shifts up to %.4g Hz found %d more "
               "eigenvalues%s; the rightmost: Re %.6g 1/s at %.6g Hz\n",
               e->sweep_shifts, e->top_hz, e->sweep_found,
               e->sweep_failed || e->sweep_rejected ? " (some runs stopped "
                                                      "short)"
                                                    : "",
               e->rightmost.re, e->rightmost.freq_hz);
    if (e->nmodes < r->nmodes_computed)
        printf("listed: %d of them (%s)\n", e->nmodes,
               r->nmodes_computed > 0 && e->nmodes > 0 &&
                       e->modes[0].im > 0
                   ? "oscillatory"
                   : "chosen");
    if (!quiet) {
        char desc[256], label[128], hi[64], hf[64], hp[64];
        /* The display units (--units): Im as a turn rate (rad/s or
         * deg/s), the frequency and the period in theirs. */
        double ki = ts_display_value(d, TS_QTY_ANGULAR_RATE, 1.0);
        double kf = ts_display_value(d, TS_QTY_FREQUENCY, 1.0);
        double kt = ts_display_value(d, TS_QTY_TIME, 1.0);
        snprintf(hi, sizeof hi, "Im [%s]",
                 ts_display_unit(d, TS_QTY_ANGULAR_RATE));
        snprintf(hf, sizeof hf, "freq [%s]",
                 ts_display_unit(d, TS_QTY_FREQUENCY));
        snprintf(hp, sizeof hp, "period [%s]",
                 ts_display_unit(d, TS_QTY_TIME));
        printf("\n%4s %14s %14s %12s %12s %10s %8s  %s\n", "mode",
               "Re [1/s]", hi, hf, hp, "damping", "disc.err", "shape");
        for (int m = 0; m < e->nmodes; m++) {
            const ts_mode *md = &e->modes[m];
            ts_eigen_describe(sys, lin, e, m, desc, sizeof desc);
            double rel = r->mode_accuracy
                             ? r->mode_accuracy[m].error /
                                   hypot(md->re, md->im)
                             : NAN;
            char er[16];
            if (isfinite(rel))
                snprintf(er, sizeof er, "%.2g", rel);
            else
                snprintf(er, sizeof er, "-");
            printf("%4d %14.6g %14.6g %12.6g %12.6g %10.6f %8s  %s", m + 1,
                   md->re, ki * md->im, kf * md->freq_hz, kt * md->period_s,
                   md->damping_ratio, er, desc);
            if (r->mode_accuracy) {
                unresolved_label(r, m, label, sizeof label);
                printf("%s", label);
            }
            /* Health labels (towstab/health.h). */
            if (!mh[m].trustworthy)
                printf(" [NOT TRUSTWORTHY: damping +-%.2g]",
                       mh[m].damping_error);
            if (!mh[m].shape_resolved) {
                if (mh[m].nearest >= 0)
                    printf(" [shape mixes with mode %d]", mh[m].nearest + 1);
                else
                    printf(" [shape not resolved: nearly real]");
            }
            printf("\n");
        }
        printf("(disc.err: the discretisation error of lambda relative to "
               "|lambda|)\n\n");
    }
    for (int v = 0; v < r->nvalues; v++) {
        char er[160];
        if (!isfinite(r->values[v].value))
            continue;
        cli_value_error(&r->values[v], d, er, sizeof er);
        printf("%-22s %14.8g %s\n", r->values[v].name,
               cli_value_shown(&r->values[v], d), er);
    }
    if (r->mode_accuracy)
        print_verdict(r);
    print_neutral(r);
    if (!e->complete && e->sweep_shifts == 0)
        printf("note: only %d of %d eigenvalues were computed (those nearest "
               "%.6g Hz); modes elsewhere are not covered by the verdict\n",
               e->neig, e->nstate, e->target_hz);
    cli_print_accuracy(r);
    cli_print_trust(&r->trust);
}

static int ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

/* Largest number of mode shapes drawn. */
#define PLOT_MODES 4

/* Real node displacements of mode m at the phase of largest excursion:
 * with d = a + i b (node displacements of the real and imaginary parts of
 * the eigenvector's coordinate half), Re(d e^{i phi}) = a cos phi -
 * b sin phi is largest at tan 2 phi = -2 a.b / (|a|^2 - |b|^2). With
 * rot, each vehicle's small rotation at that phase, rot[3 nvehicles]
 * (ts_linear_vehicle_rotations), and with rot_im that of the imaginary
 * part of v e^{i phi} (as im_out of the displacements). */
static int mode_disp(const ts_system *sys, const ts_linear *lin,
                     const ts_eigen *e, int m, double *out, double *im_out,
                     double *rot, double *rot_im)
{
    int nq = lin->nq, nn = sys->nnodes;
    double *dq = malloc((size_t)nq * sizeof(double));
    double *b = malloc(3 * (size_t)nn * sizeof(double));
    if (!dq || !b) {
        free(dq);
        free(b);
        return -1;
    }
    const double *vr = e->vec_re + (size_t)m * e->nstate;
    const double *vi = e->vec_im + (size_t)m * e->nstate;
    memcpy(dq, vr, (size_t)nq * sizeof(double));
    ts_linear_node_displacements(sys, lin, dq, out);
    memcpy(dq, vi, (size_t)nq * sizeof(double));
    ts_linear_node_displacements(sys, lin, dq, b);
    double aa = 0, bb = 0, ab = 0;
    for (int i = 0; i < 3 * nn; i++) {
        aa += out[i] * out[i];
        bb += b[i] * b[i];
        ab += out[i] * b[i];
    }
    double phi = 0.5 * atan2(-2 * ab, aa - bb), c = cos(phi), sn = sin(phi);
    /* d e^{i phi}: its real part, and its imaginary part when asked. */
    for (int i = 0; i < 3 * nn; i++) {
        if (im_out)
            im_out[i] = out[i] * sn + b[i] * c;
        out[i] = out[i] * c - b[i] * sn;
    }
    /* Each vehicle's small rotation at the same phase. */
    if (rot) {
        for (int i = 0; i < nq; i++)
            dq[i] = vr[i] * c - vi[i] * sn;
        ts_linear_vehicle_rotations(lin, dq, rot);
    }
    if (rot_im) {
        for (int i = 0; i < nq; i++)
            dq[i] = vr[i] * sn + vi[i] * c;
        ts_linear_vehicle_rotations(lin, dq, rot_im);
    }
    free(dq);
    free(b);
    return 0;
}

/* --plot: the eigenvalue plane (resolved and unresolved modes apart) and
 * the shapes of the lowest resolved oscillatory modes (the lowest
 * oscillatory ones, labelled unresolved, when none is resolved). */
/* Frames a cycle of the PNG sequences of --frames (30 degrees apart). */
#define FRAMES_PNG 12

static int modes_plot(const ts_result *r, const cli_plot *plot, int frames)
{
    const ts_system *sys = r->sys;
    const ts_linear *lin = r->lin;
    const ts_eigen *e = r->eigen;
    const double *pos = r->eq->positions;
    ts_err err = {0};
    int n = e->nmodes, status = 0;
    /* Set 0: resolved (or all, without the estimate), set 1: unresolved;
     * each eigenvalue with its conjugate, so at most 2 n each. */
    double *buf = malloc(8 * (size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!buf) {
        fprintf(stderr, "towstab: error: modes: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    double *sre[2] = {buf, buf + 2 * n}, *sim[2] = {buf + 4 * n, buf + 6 * n};
    int nset[2] = {0, 0};
    for (int m = 0; m < n; m++) {
        int s = r->mode_accuracy && !r->mode_accuracy[m].resolved;
        sre[s][nset[s]] = e->modes[m].re;
        sim[s][nset[s]++] = e->modes[m].im;
        if (e->modes[m].im > 0) {
            sre[s][nset[s]] = e->modes[m].re;
            sim[s][nset[s]++] = -e->modes[m].im;
        }
    }
    char title[256], label[2][96];
    snprintf(title, sizeof title, "%s: eigenvalues", sys->name);
    ts_plot_series set[2];
    int nsets = 0;
    for (int s = 0; s < 2; s++) {
        if (nset[s] == 0)
            continue;
        if (!r->mode_accuracy)
            snprintf(label[s], sizeof label[s], "%d eigenvalues%s", nset[s],
                     e->complete ? "" : " (nearest the target)");
        else
            snprintf(label[s], sizeof label[s], "%d %s", nset[s],
                     s ? "unresolved (grid-scale, or beyond the accuracy)" : "resolved");
        ts_plot_series a = {nset[s], sre[s], sim[s], label[s], 0,
                            TS_PLOT_MARKERS, s ? 2 : 1, NULL};
        set[nsets++] = a;
    }
    if (nsets > 0 &&
        ts_plot_eigenvalues(plot->dir, "eigenvalues", title, nsets, set,
                            NULL, &plot->opts, &err) != TS_OK)
        status = cli_report(&err, err.code);
    else if (nsets > 0)
        cli_plot_wrote(plot, "eigenvalues");
    free(buf);

    /* The shapes: the lowest resolved oscillatory modes (the listing is
     * oscillatory first, by frequency). */
    int pick[PLOT_MODES], np = 0, unresolved = 0;
    for (int m = 0; m < n && np < PLOT_MODES; m++)
        if (e->modes[m].im > 0 &&
            (!r->mode_accuracy || r->mode_accuracy[m].resolved))
            pick[np++] = m;
    if (np == 0) {
        unresolved = r->mode_accuracy != NULL;
        for (int m = 0; m < n && np < PLOT_MODES; m++)
            if (e->modes[m].im > 0)
                pick[np++] = m;
    }
    if (np < 1 || !e->vec_re || !e->vec_im)
        return status;
    cli_shape eqs;
    /* Per mode: the displacements at two phases (the real and imaginary
     * parts of the mode at its phase of largest excursion), then each
     * vehicle's rotation in both parts and its outline's motion in both
     * (ts_plot_mode.outline_motion the real part's). */
    size_t per = 6 * (size_t)sys->nnodes + 18 * (size_t)lin->nvehicles;
    double *disp = malloc((size_t)np * per * sizeof(double));
    char labels[PLOT_MODES][160];
    ts_plot_mode modes[PLOT_MODES];
    if (!disp || cli_plot_shape(sys, r->eq, pos, &eqs) != 0 ||
        (r->eq && cli_plot_add_vehicles(&eqs, sys, r->eq) != 0)) {
        free(disp);
        fprintf(stderr, "towstab: error: modes: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    for (int i = 0; i < np; i++) {
        int m = pick[i];
        const ts_mode *md = &e->modes[m];
        double *d = disp + (size_t)i * per;
        double *rot = d + 6 * sys->nnodes, *rot_im = rot + 3 * lin->nvehicles;
        double *motion = rot_im + 3 * lin->nvehicles;
        double *motion_im = motion + 6 * lin->nvehicles;
        if (mode_disp(sys, lin, e, m, d, d + 3 * sys->nnodes, rot,
                      rot_im) != 0) {
            status = EXIT_FAILED;
            break;
        }
        /* The outlines are the equilibrium's vehicles in order
         * (cli_plot_add_vehicles), each anchored at its body's node. */
        int nout = r->eq ? eqs.shape.noutlines : 0;
        for (int v = 0; v < nout; v++) {
            int node = ts_system_body_node(sys, r->eq->vehicles[v].body);
            for (int j = 0; j < 3; j++) {
                motion[6 * v + j] = d[3 * node + j];
                motion[6 * v + 3 + j] = rot[3 * v + j];
                motion_im[6 * v + j] = d[3 * (sys->nnodes + node) + j];
                motion_im[6 * v + 3 + j] = rot_im[3 * v + j];
            }
        }
        modes[i].outline_motion = nout > 0 ? motion : NULL;
        snprintf(labels[i], sizeof labels[i],
                 "mode %d: %.4g Hz, damping ratio %.3g%s", m + 1,
                 md->freq_hz, md->damping_ratio,
                 unresolved ? " (unresolved)" : "");
        modes[i].disp = d;
        modes[i].label = labels[i];
    }
    snprintf(title, sizeof title, "%s: lowest %soscillatory modes",
             sys->name, unresolved || !r->mode_accuracy ? "" : "resolved ");
    if (status == 0) {
        if (ts_plot_mode_shapes(plot->dir, "modes", title, TS_PLOT_WATER,
                                &eqs.shape, np, modes, &plot->opts,
                                &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            cli_plot_wrote(plot, "modes");
    }
    /* Each drawn mode as an animated SVG, one cycle in 2 s, in the side
     * view (modeK_animation) and in plan (modeK_animation_top); with
     * --frames also as PNG frame sequences (modeK_side_kkk,
     * modeK_top_kkk), FRAMES_PNG frames a cycle; the vehicles moved and
     * rotated at every frame's phase. */
    static const char *const vname[2] = {"side", "top"};
    for (int i = 0; i < np && status == 0; i++) {
        const double *d = disp + (size_t)i * per;
        const double *ore = modes[i].outline_motion;
        const double *oim = ore ? ore + 6 * lin->nvehicles : NULL;
        for (int v = 0; v < 2 && status == 0; v++) {
            char name[48], at[300];
            snprintf(name, sizeof name, "mode%d_animation%s", pick[i] + 1,
                     v ? "_top" : "");
            snprintf(at, sizeof at, "%s: mode %d, %s view, one cycle",
                     sys->name, pick[i] + 1, vname[v]);
            ts_plot_view view = v ? TS_PLOT_TOP : TS_PLOT_SIDE;
            if (ts_plot_mode_animation(plot->dir, name, at, view,
                                       TS_PLOT_WATER, &eqs.shape, d,
                                       d + 3 * sys->nnodes, ore, oim,
                                       labels[i], 36,
                                       2.0, &plot->opts, &err) != TS_OK) {
                status = cli_report(&err, err.code);
                break;
            }
            printf("wrote %s/%s.svg\n", plot->dir, name);
            if (!frames)
                continue;
            snprintf(name, sizeof name, "mode%d_%s", pick[i] + 1, vname[v]);
            if (ts_plot_mode_frames(plot->dir, name, at, view, TS_PLOT_WATER,
                                    &eqs.shape, d, d + 3 * sys->nnodes, ore,
                                    oim, labels[i], FRAMES_PNG, &plot->opts,
                                    &err) != TS_OK)
                status = cli_report(&err, err.code);
            else
                printf("wrote %s/%s_000.png .. %s_%03d.png\n", plot->dir,
                       name, name, FRAMES_PNG - 1);
        }
    }
    cli_plot_shape_free(&eqs);
    free(disp);
    return status;
}


/* The loops' gain and phase margins, one loop broken at a time. */
static void print_margins(const ts_result *r)
{
    if (r->nmargins == 0)
        return;
    printf("\nloop margins, each loop broken at its output with the others "
           "closed (%g to %g Hz, %.3f ms):\n", TS_MARGINS_FROM_HZ,
           TS_MARGINS_TO_HZ, r->margins_wall_s * 1e3);
    printf("%-28s %12s %10s %14s %14s %14s\n", "loop", "gain margin", "[dB]",
           "at [Hz]", "phase margin", "at [Hz]");
    for (int i = 0; i < r->nmargins; i++) {
        const ts_loop_margin *m = &r->margins[i];
        char gm[32], db[32], gf[32], pm[32], pf[32];
        if (isfinite(m->gain_margin)) {
            snprintf(gm, sizeof gm, "%.4g", m->gain_margin);
            snprintf(db, sizeof db, "%.2f", 20 * log10(m->gain_margin));
            snprintf(gf, sizeof gf, "%.4g", m->phase_crossover_hz);
        } else {
            snprintf(gm, sizeof gm, "infinite");
            snprintf(db, sizeof db, "-");
            snprintf(gf, sizeof gf, "-");
        }
        if (isfinite(m->phase_margin_deg)) {
            snprintf(pm, sizeof pm, "%.2f deg", m->phase_margin_deg);
            snprintf(pf, sizeof pf, "%.4g", m->gain_crossover_hz);
        } else {
            snprintf(pm, sizeof pm, "no crossover");
            snprintf(pf, sizeof pf, "-");
        }
        printf("%-28s %12s %10s %14s %14s %14s\n", m->name, gm, db, gf, pm,
               pf);
    }
}

/* The towing vehicle alone against the coupled system, mode by mode. */
static void print_free_vehicle(const ts_result *r)
{
    const ts_free_vehicle *f = r->free_vehicle;
    if (!f)
        return;
    printf("\nthe towing vehicle alone (no cable) at %.6g m/s, turn rate "
           "%.6g rad/s, thrust %.6g N: %d states; each of its modes beside "
           "the coupled mode of the most similar shape over the vehicle's "
           "coordinates (MAC 1: the same motion)\n",
           f->speed, f->turn_rate, f->thrust, f->nstate);
    printf("%4s %12s %12s %9s   %5s %12s %12s %9s %6s\n", "free", "Re [1/s]",
           "Im [rad/s]", "damping", "mode", "Re [1/s]", "Im [rad/s]",
           "damping", "MAC");
    int spans = 0;
    for (int i = 0; i < f->nmodes; i++) {
        const ts_free_mode *m = &f->modes[i];
        char cm[16];
        snprintf(cm, sizeof cm, "%d", m->coupled + 1);
        printf("%4d %12.6g %12.6g %9.4g   %5s %12.6g %12.6g %9.4g %6.3f%s\n",
               i + 1, m->re, m->im, m->damping_ratio,
               m->coupled >= 0 ? cm : "-", m->coupled_re, m->coupled_im,
               m->coupled_damping_ratio, m->mac, m->span > 1 ? " *" : "");
        spans |= m->span > 1;
    }
    if (spans)
        printf("* one of coincident modes (any mix of them is a mode): "
               "the MAC is over the span of the coincident coupled modes "
               "it is paired within\n");
}

static void modes_print(const cli_run *c, const ts_result *r)
{
    cli_print_equilibrium(r, 1, &c->display);
    cli_print_linearization(r);
    if (r->eigen && r->mode_health)
        print_modes(r, c->quiet, ts_display_or_si(&c->display));
    print_margins(r);
    print_free_vehicle(r);
}

/* The extras. */
enum { X_MATRICES, X_SHAPES, X_FRAMES };

static int modes_prepare(cli_run *c)
{
    if (c->nextra[X_FRAMES] && !c->plot.dir) {
        ts_err err = {0};
        ts_fail(&err, TS_EINVAL, "--frames: draws the modes' frames into "
                                 "--plot DIR; give --plot DIR");
        return cli_report(&err, err.code);
    }
    if (c->nextra[X_MATRICES]) {
        c->json_flags |= TS_REPORT_MATRICES;
        /* The dense A and B at any size, beside the sparse model. */
        c->rq.modes.linearize.model = TS_LIN_BOTH;
    }
    return 0;
}

/* --shapes FILE (CSV, or JSON when it ends in .json) and the pictures. */
static int modes_draw_or_shapes(cli_run *c, const ts_result *r)
{
    if (r->status != TS_OK)
        return 0;
    int status = 0;
    const char *shapes = c->nextra[X_SHAPES] ? c->extra[X_SHAPES][0] : NULL;
    ts_err werr = {0};
    if (shapes) {
        int wrc;
        if (ends_with(shapes, ".json")) {
            json_t *sj = ts_report_modes_json(r->sys, r->lin, r->eigen, 1);
            wrc = sj ? cli_write_json(sj, shapes, &werr)
                     : ts_fail(&werr, TS_ENOMEM, "%s: out of memory",
                               shapes);
            json_decref(sj);
        } else {
            wrc = ts_report_shapes_csv_display(r->sys, r->lin, r->eigen,
                                               &c->display, shapes, &werr);
        }
        if (wrc != TS_OK)
            status = cli_report(&werr, werr.code);
    }
    if (c->plot.dir) {
        int s = modes_plot(r, &c->plot, c->nextra[X_FRAMES] > 0);
        status = status ? status : s;
    }
    return status;
}

static const cli_extra modes_extras[] = {
    {"matrices", 0, 0, NULL, "include A and B in the JSON"},
    {"shapes", 1, 0, "FILE",
     "write the mode shapes (CSV, or JSON when FILE ends in .json)"},
    {"frames", 0, 0, NULL,
     "with --plot: each animated mode also as PNG frames, 12 a cycle "
     "(modeK_side_000.png .., modeK_top_000.png ..)"},
    {NULL, 0, 0, NULL, NULL}};

static const char *const modes_pictures[] = {"eigenvalues", "modes", NULL};

const cli_command cli_cmd_modes = {
    "modes", "stability verdict and mode table of the linearized system",
    TS_ANALYSIS_MODES, NULL, modes_prepare, modes_print, modes_draw_or_shapes,
    NULL, modes_pictures, modes_extras, NULL};
