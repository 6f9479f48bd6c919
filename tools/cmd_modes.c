/* cmd_modes.c: `towstab modes SCENE` and the `modes` analysis of a scene:
 * equilibrium, linearization, eigen analysis, mode table and stability
 * verdict (doc/linear.md). Also defines cli_linear_setup(), which
 * cmd_response.c shares. */
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "towstab/eigen.h"
#include "towstab/health.h"
#include "towstab/linearize.h"
#include "towstab/report.h"
#include "towstab/report_converge.h"
#include "towstab/report_linear.h"

/* Modes shown when the system is large and no count is given. */
#define DEFAULT_LARGE_COUNT 20
/* Modes found around --near when no count is given. */
#define DEFAULT_NEAR_COUNT 10

int cli_linear_setup(const ts_system *sys, const ts_equilibrium_opts *eo,
                     ts_lin_model model, ts_equilibrium **eq,
                     json_t **eqjson, ts_linear **lin, ts_err *err);

/* Solve the equilibrium (printing its summary), then linearize about it
 * with a fresh kernel re-charted from the equilibrium's directions,
 * forming the models `model` asks for. On failure returns the library
 * code with the message in err; an equilibrium that did not converge is
 * never linearized. */
int cli_linear_setup(const ts_system *sys, const ts_equilibrium_opts *eo,
                     ts_lin_model model, ts_equilibrium **eq,
                     json_t **eqjson, ts_linear **lin, ts_err *err)
{
    *lin = NULL;
    int rc = cli_equilibrium(sys, eo, 1, eq, eqjson, err);
    if (rc != TS_OK) {
        if (*eq && !(*eq)->converged)
            ts_err_prefix(err, "the equilibrium did not converge, so it is "
                               "not linearized: ");
        return rc;
    }
    ts_kernel *k = ts_kernel_alloc(sys, err);
    if (!k)
        return err->code;
    ts_linear *l = ts_linear_alloc(k, err);
    if (!l) {
        ts_kernel_free(k);
        return err->code;
    }
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = model;
    double t0 = cli_wall_now();
    rc = ts_linearize_equilibrium(k, *eq, &lo, l, err);
    double wall = cli_wall_now() - t0;
    ts_kernel_free(k);
    if (rc != TS_OK) {
        ts_linear_free(l);
        return rc;
    }
    if (l->A)
        printf("linearized: %d states, %d inputs, %ld kernel evaluations on "
               "%d thread%s, %.3f ms; truncation error %.3g (max |A| %.6g, "
               "||dA||_F %.3g)\n",
               l->nstate, l->ninput, l->evaluations, l->threads,
               l->threads == 1 ? "" : "s", wall * 1e3, l->trunc_err,
               l->a_scale, l->trunc_norm);
    else
        printf("linearized: %d states, sparse model (%d perturbation groups, "
               "%ld residual evaluations on %d thread%s), %.3f ms; relative "
               "truncation error %.3g\n",
               l->nstate, l->groups, l->residual_evaluations, l->threads,
               l->threads == 1 ? "" : "s", wall * 1e3, l->desc_err);
    if (l->kinks > l->kink_tow) {
        char name[2 * TS_NAME_MAX];
        ts_report_node_name(sys, l->kink_node, name, sizeof name);
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
    *lin = l;
    return TS_OK;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: towstab modes SCENE [options]\n"
            "  stability verdict and mode table of the linearized system\n"
            "  about the equilibrium at the scene's speed and turn rate\n"
            "  --count N        modes to report (default: all; %d for large\n"
            "                   systems; %d with --near)\n"
            "  --near F         the modes nearest F (Hz, or with a unit)\n"
            "  --method M       auto (default), lapack (all eigenvalues) or\n"
            "                   arpack (shift-invert, needs a count)\n"
            "  --json FILE      write the modes as JSON ('-' for stdout)\n"
            "  --matrices       include A and B in the JSON\n"
            "  --csv FILE       write the mode table as CSV\n"
            "  --shapes FILE    write the mode shapes (CSV, or JSON when FILE\n"
            "                   ends in .json)\n"
            "  --speed Q        override tow.speed (e.g. '5 knot', 2.5)\n"
            "  --turn-rate Q    override tow.turn_rate (e.g. '0.5 rad/s')\n"
            "  --links N        use N links on every cable\n"
            "  --eq-method M    equilibrium method: auto, shooting, newton\n"
            "  --tol X          equilibrium relative force residual\n"
            "  --quiet          print the summary and verdict only\n"
            "  --plot DIR       draw the eigenvalue plane (eigenvalues.png/svg)\n"
            "                   and the lowest mode shapes (modes.png/svg)\n"
            "  --units U        units of the pictures: si or imperial\n",
            DEFAULT_LARGE_COUNT, DEFAULT_NEAR_COUNT);
}

/* What both entries (command line and scene) decide. */
typedef struct modes_req {
    ts_eigen_opts eo;
    int count_given;
    int near_given;
} modes_req;

static int parse_method(const char *text, const char *where,
                        ts_eig_method *m, ts_err *err)
{
    if (strcmp(text, "auto") == 0)
        *m = TS_EIG_AUTO;
    else if (strcmp(text, "lapack") == 0)
        *m = TS_EIG_LAPACK;
    else if (strcmp(text, "arpack") == 0)
        *m = TS_EIG_ARPACK;
    else
        return ts_fail(err, TS_EINVAL,
                       "%s: '%s' is not an eigen method; expected auto, "
                       "lapack or arpack",
                       where, text);
    return TS_OK;
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
    if (e->sweep_shifts > 0)
        printf("rightmost search: %d shifts up to %.4g Hz found %d more "
               "eigenvalues%s; the rightmost: Re %.6g 1/s at %.6g Hz\n",
               e->sweep_shifts, e->top_hz, e->sweep_found,
               e->sweep_failed || e->sweep_rejected ? " (some runs stopped "
                                                      "short)"
                                                    : "",
               e->rightmost.re, e->rightmost.freq_hz);
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
    const char *scope = e->complete         ? ""
                        : e->sweep_shifts > 0 ? " among the eigenvalues found"
                                              : " among the modes computed";
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
    if (!e->complete && e->sweep_shifts == 0)
        printf("note: only %d of %d eigenvalues were computed (those nearest "
               "%.6g Hz); modes elsewhere are not covered by the verdict\n",
               e->neig, e->nstate, e->target_hz);
    if (trust->trustworthy)
        printf("trustworthy: yes\n");
    else
        printf("trustworthy: NO\n");
    for (int i = 0; i < trust->nreasons; i++)
        printf("  reason: %s\n", trust->reasons[i]);
    for (int i = 0; i < trust->nnotes; i++)
        printf("  note: %s\n", trust->notes[i]);
}

/* Everything after the system is built. *json receives the result. */
static int modes_analysis(const ts_system *sys, const ts_equilibrium_opts *eqo,
                          modes_req *rq, int quiet, int matrices,
                          json_t **json, ts_linear **lin_out,
                          ts_eigen **eig_out, double **pos_out, ts_err *err)
{
    ts_equilibrium *eq = NULL;
    json_t *eqjson = NULL;
    ts_linear *lin = NULL;
    *json = NULL;
    *lin_out = NULL;
    *eig_out = NULL;
    /* LAPACK and --matrices need the dense model at any size. */
    int dense = matrices || rq->eo.method == TS_EIG_LAPACK;
    int rc = cli_linear_setup(sys, eqo, dense ? TS_LIN_BOTH : TS_LIN_AUTO,
                              &eq, &eqjson, &lin, err);
    if (rc != TS_OK) {
        json_decref(eqjson);
        ts_equilibrium_free(eq);
        return rc;
    }
    if (!rq->count_given) {
        if (rq->near_given)
            rq->eo.count = DEFAULT_NEAR_COUNT;
        else if (rq->eo.method == TS_EIG_ARPACK ||
                 (rq->eo.method == TS_EIG_AUTO &&
                  lin->nstate >= rq->eo.arpack_min_states))
            rq->eo.count = DEFAULT_LARGE_COUNT;
    }
    if (rq->eo.count > lin->nstate / 2 + 1)
        rq->eo.count = 0; /* more than exist: all of them */
    ts_eigen *e = NULL;
    double t0 = cli_wall_now();
    rc = ts_eigen_solve(lin, &rq->eo, &e, err);
    double wall = cli_wall_now() - t0;
    /* Health: the equilibrium's, then the modes' (towstab/health.h). */
    ts_mode_health *mh = NULL;
    ts_trust trust;
    ts_trust_init(&trust);
    if (rc == TS_OK) {
        ts_trust et;
        ts_trust_init(&et);
        ts_health_equilibrium(sys, eq, &et);
        ts_trust_merge(&trust, "equilibrium: ", &et);
        mh = malloc((size_t)(e->nmodes > 0 ? e->nmodes : 1) * sizeof *mh);
        rc = mh ? ts_health_modes(sys, lin, e, mh, &trust, err)
                : ts_fail(err, TS_ENOMEM, "modes: out of memory");
    }
    if (rc == TS_OK) {
        print_modes(sys, lin, e, mh, &trust, wall, quiet);
        json_t *j = ts_report_modes_json(sys, lin, e, 0);
        if (j && ts_report_modes_health_json(j, e, mh, &trust) != TS_OK) {
            json_decref(j);
            j = NULL;
        }
        if (j) {
            json_object_set_new(j, "linearization",
                                ts_report_linear_json(lin, matrices));
            if (eqjson)
                json_object_set(j, "equilibrium", eqjson);
        }
        *json = j;
    }
    free(mh);
    json_decref(eqjson);
    if (rc == TS_OK && pos_out) {
        size_t bytes = 3 * (size_t)sys->nnodes * sizeof(double);
        *pos_out = malloc(bytes);
        if (*pos_out)
            memcpy(*pos_out, eq->positions, bytes);
        else
            rc = ts_fail(err, TS_ENOMEM, "modes: out of memory");
    }
    ts_equilibrium_free(eq);
    if (rc != TS_OK) {
        ts_eigen_free(e);
        ts_linear_free(lin);
        return rc;
    }
    *lin_out = lin;
    *eig_out = e;
    return TS_OK;
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
        printf("wrote %s/eigenvalues.png and %s/eigenvalues.svg\n",
               plot->dir, plot->dir);
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
            printf("wrote %s/modes.png and %s/modes.svg\n", plot->dir,
                   plot->dir);
    }
    cli_plot_shape_free(&eqs);
    free(disp);
    return status;
}

static int modes_main(int argc, char **argv)
{
    cli_settings s = {0};
    cli_settings_from_options(&s);
    snprintf(s.where[2], sizeof s.where[2], "--eq-method");
    const char *json_path = NULL, *csv_path = NULL, *shapes_path = NULL;
    const char *near = NULL, *method = NULL;
    int quiet = 0, matrices = 0;
    modes_req rq = {0};
    ts_eigen_opts_default(&rq.eo);
    static const struct option longopts[] = {
        {"count", required_argument, NULL, 'k'},
        {"near", required_argument, NULL, 'f'},
        {"method", required_argument, NULL, 'M'},
        {"json", required_argument, NULL, 'j'},
        {"matrices", no_argument, NULL, 'A'},
        {"csv", required_argument, NULL, 'c'},
        {"shapes", required_argument, NULL, 'S'},
        CLI_SETTINGS_LONGOPTS("eq-method"),
        {"quiet", no_argument, NULL, 'q'},
        {"plot", required_argument, NULL, 'p'},
        {"units", required_argument, NULL, 'u'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    cli_plot plot = {0};
    optind = 1;
    opterr = 0;
    int ch;
    long v;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (ch) {
        case 'p': plot.dir = optarg; break;
        case 'u': plot.units = optarg; break;
        case 'k':
            if (cli_parse_int("--count", optarg, 1, 100000000, &v))
                return EXIT_BADINPUT;
            rq.eo.count = (int)v;
            rq.count_given = 1;
            break;
        case 'f': near = optarg; break;
        case 'M': method = optarg; break;
        case 'j': json_path = optarg; break;
        case 'A': matrices = 1; break;
        case 'c': csv_path = optarg; break;
        case 'S': shapes_path = optarg; break;
        case 'q': quiet = 1; break;
        case 'h': usage(stdout); return 0;
        default: {
            int r = cli_settings_option(&s, ch, optarg);
            if (r < 0)
                return EXIT_BADINPUT;
            if (r == 0)
                return cli_option_error("modes", ch, argv[optind - 1]);
        }
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: modes: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    ts_err err = {0};
    if (method && parse_method(method, "--method", &rq.eo.method, &err))
        return cli_report(&err, err.code);
    int pstatus = cli_plot_begin(&plot, "modes");
    if (pstatus)
        return pstatus;
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    if (near) {
        if (ts_units_parse(units, near, "Hz", "--near", &rq.eo.target_hz,
                           &err) != TS_OK ||
            (!(rq.eo.target_hz >= 0) &&
             ts_fail(&err, TS_EINVAL, "--near: expected a frequency >= 0 Hz, "
                                      "got '%s'",
                     near))) {
            status = cli_report(&err, err.code ? err.code : TS_EINVAL);
            cli_close(units, scene);
            return status;
        }
        rq.near_given = 1;
    }
    ts_equilibrium_opts eqo;
    ts_system *sys = cli_system(scene, units, &s, &eqo, &err);
    if (!sys) {
        status = cli_report(&err, err.code);
        cli_close(units, scene);
        return status;
    }
    printf("towstab modes: %s (%s)\n", sys->name, scene->path);
    json_t *json = NULL;
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    double *pos = NULL;
    int rc = modes_analysis(sys, &eqo, &rq, quiet, matrices, &json, &lin, &e,
                            plot.dir ? &pos : NULL, &err);
    if (rc != TS_OK)
        status = cli_report(&err, rc);
    ts_err werr = {0};
    if (rc == TS_OK && json_path && json &&
        cli_write_json(json, json_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    if (rc == TS_OK && csv_path &&
        ts_report_modes_csv(sys, lin, e, csv_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    if (rc == TS_OK && shapes_path) {
        int wrc;
        if (ends_with(shapes_path, ".json")) {
            json_t *sj = ts_report_modes_json(sys, lin, e, 1);
            wrc = sj ? cli_write_json(sj, shapes_path, &werr)
                     : ts_fail(&werr, TS_ENOMEM, "%s: out of memory",
                               shapes_path);
            json_decref(sj);
        } else {
            wrc = ts_report_shapes_csv(sys, lin, e, shapes_path, &werr);
        }
        if (wrc != TS_OK)
            status = cli_report(&werr, werr.code);
    }
    if (rc == TS_OK && plot.dir) {
        int prc = modes_plot(sys, lin, e, pos, &plot);
        if (prc)
            status = prc;
    }
    free(pos);
    json_decref(json);
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_system_free(sys);
    cli_close(units, scene);
    return status;
}

static const char *const modes_keys[] = {
    "speed", "turn_rate", "tolerance", "links", "equilibrium_method",
    "method", "count", "near", NULL};

/* One scene entry (cli_command.entry): parse and check its options, and
 * with a result slot run it. Returns the exit status. */
static int modes_entry(const cli_ctx *ctx, const ts_scene_analysis *a,
                       int index, json_t **result)
{
    ts_err err = {0};
    cli_settings s = {0};
    if (cli_settings_from_analysis(&s, a, index, &err))
        return cli_report(&err, err.code);
    /* In a modes entry `method` is the eigen method; the equilibrium's is
     * `equilibrium_method`. */
    const ts_scene_option *om = ts_scene_analysis_option(a, "equilibrium_method");
    s.method = om ? om->value : NULL;
    snprintf(s.where[2], sizeof s.where[2],
             "analyses[%d].equilibrium_method (line %d)", index,
             om ? om->line : a->line);
    modes_req rq = {0};
    ts_eigen_opts_default(&rq.eo);
    char where[160];
    const ts_scene_option *o;
    if ((o = ts_scene_analysis_option(a, "method"))) {
        snprintf(where, sizeof where, "analyses[%d].method (line %d)", index,
                 o->line);
        if (parse_method(o->value, where, &rq.eo.method, &err))
            return cli_report(&err, err.code);
    }
    if ((o = ts_scene_analysis_option(a, "count"))) {
        char *end;
        long c = strtol(o->value, &end, 10);
        if (end == o->value || *end || c < 1 || c > 100000000) {
            ts_fail(&err, TS_EINVAL,
                    "analyses[%d].count (line %d): expected a whole number "
                    ">= 1, got '%s'",
                    index, o->line, o->value);
            return cli_report(&err, err.code);
        }
        rq.eo.count = (int)c;
        rq.count_given = 1;
    }
    if ((o = ts_scene_analysis_option(a, "near"))) {
        snprintf(where, sizeof where, "analyses[%d].near (line %d)", index,
                 o->line);
        if (ts_units_parse(ctx->units, o->value, "Hz", where,
                           &rq.eo.target_hz, &err) != TS_OK)
            return cli_report(&err, err.code);
        if (!(rq.eo.target_hz >= 0)) {
            ts_fail(&err, TS_EINVAL, "%s: expected a frequency >= 0 Hz, got "
                                     "'%s'",
                    where, o->value);
            return cli_report(&err, err.code);
        }
        rq.near_given = 1;
    }
    ts_equilibrium_opts eqo;
    ts_system *sys = cli_system(ctx->scene, ctx->units, &s, &eqo, &err);
    if (!sys)
        return cli_report(&err, err.code);
    if (!result) {
        ts_system_free(sys);
        return 0;
    }
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    int rc = modes_analysis(sys, &eqo, &rq, ctx->quiet, 0, result, &lin, &e,
                            NULL, &err);
    int status = rc ? cli_report(&err, rc) : 0;
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_system_free(sys);
    return status;
}

const cli_command cli_cmd_modes = {
    "modes", "stability verdict and mode table of the linearized system",
    modes_main, modes_entry, modes_keys};
