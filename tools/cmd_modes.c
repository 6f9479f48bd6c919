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
    printf("linearized: %d states, %d inputs, %ld kernel evaluations on %d "
           "thread%s, %.3f ms; truncation error %.3g (max |A| %.6g, "
           "||dA||_F %.3g)\n",
           l->nstate, l->ninput, l->evaluations, l->threads,
           l->threads == 1 ? "" : "s", r->lin_wall_s * 1e3, l->trunc_err,
           l->a_scale, l->trunc_norm);
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

static void print_modes(const ts_system *sys, const ts_linear *lin,
                        const ts_eigen *e, const ts_mode_health *mh,
                        const ts_trust *trust, double wall, int quiet)
{
    printf("eigen: %s, %d mode%s (%d of %d eigenvalues)%s, %.3f ms",
           ts_eig_method_name(e->method), e->nmodes, e->nmodes == 1 ? "" : "s",
           e->neig, e->nstate, e->complete ? "" : " nearest the target",
           wall * 1e3);
    if (e->method == TS_EIG_ARPACK)
        printf(", %d restarts, %d operator applications", e->arpack_iterations,
               e->arpack_ops);
    printf("\n");
    if (!quiet) {
        char desc[256];
        printf("\n%4s %14s %14s %12s %12s %10s  %s\n", "mode", "Re [1/s]",
               "Im [rad/s]", "freq [Hz]", "period [s]", "damping",
               "shape");
        for (int m = 0; m < e->nmodes; m++) {
            const ts_mode *md = &e->modes[m];
            ts_eigen_describe(sys, lin, e, m, desc, sizeof desc);
            printf("%4d %14.6g %14.6g %12.6g %12.6g %10.6f  %s", m + 1,
                   md->re, md->im, md->freq_hz, md->period_s,
                   md->damping_ratio, desc);
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
        printf("\n");
    }
    const char *scope = e->complete ? "" : " among the modes computed";
    switch (e->verdict) {
    case TS_STABLE:
        printf("verdict: stable%s: max Re(lambda) = %.6g 1/s, error bound "
               "%.2g 1/s (the margin is %.3g times its error: trustworthy)\n",
               scope, e->max_real, e->max_real_error,
               e->max_real_error > 0 ? -e->max_real / e->max_real_error
                                     : INFINITY);
        break;
    case TS_UNSTABLE:
        printf("verdict: UNSTABLE%s: max Re(lambda) = %.6g 1/s > 0, error "
               "bound %.2g 1/s\n",
               scope, e->max_real, e->max_real_error);
        break;
    default:
        printf("verdict: marginal%s: max Re(lambda) = %.3g 1/s is within its "
               "error bound %.2g 1/s of 0; the linear model does not decide "
               "stability (undamped or nearly so)\n",
               scope, e->max_real, e->max_real_error);
    }
    if (!e->complete)
        printf("note: only %d of %d eigenvalues were computed (those nearest "
               "%.6g Hz); modes elsewhere are not covered by the verdict\n",
               e->neig, e->nstate, e->target_hz);
    cli_print_trust(trust);
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
 * b sin phi is largest at tan 2 phi = -2 a.b / (|a|^2 - |b|^2). */
static int mode_disp(const ts_system *sys, const ts_linear *lin,
                     const ts_eigen *e, int m, double *out)
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
    for (int i = 0; i < 3 * nn; i++)
        out[i] = out[i] * c - b[i] * sn;
    free(dq);
    free(b);
    return 0;
}

/* --plot: the eigenvalue plane and the shapes of the lowest modes. */
static int modes_plot(const ts_system *sys, const ts_linear *lin,
                      const ts_eigen *e, const double *pos,
                      const cli_plot *plot)
{
    ts_err err = {0};
    int n = e->nmodes, status = 0;
    double *re = malloc(2 * (size_t)(n > 0 ? n : 1) * sizeof(double));
    double *im = malloc(2 * (size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!re || !im) {
        free(re);
        free(im);
        fprintf(stderr, "towstab: error: modes: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    int k = 0;
    for (int m = 0; m < n; m++) {
        re[k] = e->modes[m].re;
        im[k++] = e->modes[m].im;
        if (e->modes[m].im > 0) {
            re[k] = e->modes[m].re;
            im[k++] = -e->modes[m].im;
        }
    }
    char title[256], label[96];
    snprintf(title, sizeof title, "%s: eigenvalues", sys->name);
    snprintf(label, sizeof label, "%d eigenvalues%s", k,
             e->complete ? "" : " (nearest the target)");
    ts_plot_series set = {k, re, im, label, 0, TS_PLOT_MARKERS, 0};
    if (ts_plot_eigenvalues(plot->dir, "eigenvalues", title, 1, &set, NULL,
                            &plot->opts, &err) != TS_OK)
        status = cli_report(&err, err.code);
    else
        cli_plot_wrote(plot, "eigenvalues");
    free(re);
    free(im);

    int nm = n < PLOT_MODES ? n : PLOT_MODES;
    if (nm < 1 || !e->vec_re || !e->vec_im)
        return status;
    cli_shape eqs;
    double *disp = malloc((size_t)nm * 3 * (size_t)sys->nnodes * sizeof(double));
    char labels[PLOT_MODES][128];
    ts_plot_mode modes[PLOT_MODES];
    if (!disp || cli_plot_shape(sys, pos, &eqs) != 0) {
        free(disp);
        fprintf(stderr, "towstab: error: modes: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    for (int m = 0; m < nm; m++) {
        const ts_mode *md = &e->modes[m];
        double *d = disp + (size_t)m * 3 * sys->nnodes;
        if (mode_disp(sys, lin, e, m, d) != 0) {
            status = EXIT_FAILED;
            break;
        }
        if (md->im > 0)
            snprintf(labels[m], sizeof labels[m],
                     "mode %d: %.4g Hz, damping ratio %.3g", m + 1,
                     md->freq_hz, md->damping_ratio);
        else
            snprintf(labels[m], sizeof labels[m],
                     "mode %d: real, %.4g 1/s", m + 1, md->re);
        modes[m].disp = d;
        modes[m].label = labels[m];
    }
    snprintf(title, sizeof title, "%s: lowest mode shapes", sys->name);
    if (status == 0) {
        if (ts_plot_mode_shapes(plot->dir, "modes", title, TS_PLOT_WATER,
                                &eqs.shape, nm, modes, &plot->opts,
                                &err) != TS_OK)
            status = cli_report(&err, err.code);
        else
            cli_plot_wrote(plot, "modes");
    }
    cli_plot_shape_free(&eqs);
    free(disp);
    return status;
}


static void modes_print(const cli_run *c, const ts_result *r)
{
    cli_print_equilibrium(r, 1);
    cli_print_linearization(r);
    if (r->eigen && r->mode_health)
        print_modes(r->sys, r->lin, r->eigen, r->mode_health, &r->trust,
                    r->eigen_wall_s, c->quiet);
}

/* The extras. */
enum { X_MATRICES, X_SHAPES };

static int modes_prepare(cli_run *c)
{
    if (c->nextra[X_MATRICES])
        c->json_flags |= TS_REPORT_MATRICES;
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
            wrc = ts_report_shapes_csv(r->sys, r->lin, r->eigen, shapes,
                                       &werr);
        }
        if (wrc != TS_OK)
            status = cli_report(&werr, werr.code);
    }
    if (c->plot.dir) {
        int s = modes_plot(r->sys, r->lin, r->eigen, r->eq->positions,
                           &c->plot);
        status = status ? status : s;
    }
    return status;
}

static const cli_extra modes_extras[] = {
    {"matrices", 0, 0, NULL, "include A and B in the JSON"},
    {"shapes", 1, 0, "FILE",
     "write the mode shapes (CSV, or JSON when FILE ends in .json)"},
    {NULL, 0, 0, NULL, NULL}};

static const char *const modes_pictures[] = {"eigenvalues", "modes", NULL};

const cli_command cli_cmd_modes = {
    "modes", "stability verdict and mode table of the linearized system",
    TS_ANALYSIS_MODES, NULL, modes_prepare, modes_print, modes_draw_or_shapes,
    NULL, modes_pictures, modes_extras};
