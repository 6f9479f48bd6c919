/* cmd_response.c: `towstab response SCENE` and the `response` analysis of
 * a scene: how tow-point motion passes down to a node, a body or a link
 * tension, over a log-spaced frequency list (doc/linear.md). */
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "towstab/report_converge.h"
#include "towstab/health.h"
#include "cli_plot.h"
#include "towstab/eigen.h"
#include "towstab/linearize.h"
#include "towstab/report.h"
#include "towstab/report_linear.h"
#include "towstab/response.h"

/* Defined in cmd_modes.c: equilibrium (printed) and linearization. */
int cli_linear_setup(const ts_system *sys, const ts_equilibrium_opts *eo,
                     ts_lin_model model, ts_equilibrium **eq,
                     json_t **eqjson, ts_linear **lin, ts_err *err);

#define DEFAULT_FROM_HZ 0.01
#define DEFAULT_TO_HZ 10.0
#define DEFAULT_POINTS 100
#define MAX_POINTS 1000000

static void usage(FILE *f)
{
    fprintf(f,
            "usage: towstab response SCENE --output NAME [options]\n"
            "  frequency response of a node, body or link tension to\n"
            "  tow-point displacement, about the equilibrium\n"
            "  --input NAME     tow.surge, tow.sway or tow.heave (default)\n"
            "  --output NAME    <node>.x|y|z (e.g. sphere.z, cable.3.x) or\n"
            "                   <cable>.<k>.tension (e.g. cable.3.tension)\n"
            "  --from F         lowest frequency (default %g Hz; > 0)\n"
            "  --to F           highest frequency (default %g Hz)\n"
            "  --points N       log-spaced points (default %d)\n"
            "  --json FILE      write the response as JSON ('-' for stdout)\n"
            "  --csv FILE       write the response as CSV\n"
            "  --speed Q        override tow.speed (e.g. '5 knot', 2.5)\n"
            "  --turn-rate Q    override tow.turn_rate (e.g. '0.5 rad/s')\n"
            "  --links N        use N links on every cable\n"
            "  --eq-method M    equilibrium method: auto, shooting, newton\n"
            "  --tol X          equilibrium relative force residual\n"
            "  --quiet          print the summary only, not the table\n"
            "  --plot DIR       draw the Bode plot (bode.png/svg) with the\n"
            "                   natural frequencies marked\n"
            "  --units U        units of the pictures: si or imperial\n",
            DEFAULT_FROM_HZ, DEFAULT_TO_HZ, DEFAULT_POINTS);
}

typedef struct resp_req {
    const char *input, *output;
    double from, to;
    int points;
} resp_req;

static void print_response(const ts_response *r, int quiet)
{
    printf("response of %s to %s (%s): static gain %.9g\n", r->output.name,
           ts_input_name(r->input), r->output.unit, r->static_gain);
    int ib = 0;
    for (int i = 1; i < r->npoints; i++)
        if (r->magnitude[i] > r->magnitude[ib])
            ib = i;
    printf("largest magnitude %.6g at %.6g Hz (phase %.3f deg)\n",
           r->magnitude[ib], r->freq_hz[ib], r->phase_deg[ib]);
    if (quiet)
        return;
    printf("\n%14s %16s %12s\n", "freq [Hz]", "magnitude", "phase [deg]");
    for (int i = 0; i < r->npoints; i++)
        printf("%14.6g %16.9g %12.4f\n", r->freq_hz[i], r->magnitude[i],
               r->phase_deg[i]);
}

/* Everything after the system is built; names are checked before the
 * equilibrium is solved. */
/* Natural frequencies marked on a Bode plot: at most this many. */
#define PLOT_NATURAL 12

/* nat (when not NULL): the natural frequencies (Hz, of the oscillatory
 * modes nearest 0 Hz, as many as PLOT_NATURAL) for the Bode plot. */
static int response_analysis(const ts_system *sys,
                             const ts_equilibrium_opts *eqo,
                             const resp_req *rq, int quiet, json_t **json,
                             ts_response **res, double *nat, int *nnat,
                             ts_err *err)
{
    *json = NULL;
    *res = NULL;
    int input;
    ts_output out;
    int rc = ts_response_input_find(rq->input, &input, err);
    if (rc == TS_OK)
        rc = ts_response_output_find(sys, rq->output, &out, err);
    double *freq = malloc((size_t)rq->points * sizeof(double));
    if (rc == TS_OK && !freq)
        rc = ts_fail(err, TS_ENOMEM, "response: out of memory");
    if (rc == TS_OK)
        rc = ts_response_logspace(rq->from, rq->to, rq->points, freq, err);
    if (rc != TS_OK) {
        free(freq);
        return rc;
    }
    ts_equilibrium *eq = NULL;
    json_t *eqjson = NULL;
    ts_linear *lin = NULL;
    rc = cli_linear_setup(sys, eqo, TS_LIN_SPARSE, &eq, &eqjson, &lin, err);
    if (rc == TS_OK)
        rc = ts_response_compute(sys, lin, input, &out, freq, rq->points, res,
                                 err);
    if (rc == TS_OK) {
        if (lin->kink_tow && input == 2)
            printf("warning: the tow point is at the water surface: the "
                   "heave response uses the mean of the one-sided "
                   "derivatives, and a real heave also shifts the mean "
                   "depth at first order (MODEL.md section 6)\n");
        print_response(*res, quiet);
        if (nat) {
            ts_eigen_opts o;
            ts_eigen_opts_default(&o);
            o.count = PLOT_NATURAL;
            if (o.count > lin->nstate / 2)
                o.count = 0;
            ts_eigen *e = NULL;
            *nnat = 0;
            if (ts_eigen_solve(lin, &o, &e, err) == TS_OK)
                for (int m = 0; m < e->nmodes && *nnat < PLOT_NATURAL; m++)
                    if (e->modes[m].im > 0)
                        nat[(*nnat)++] = e->modes[m].freq_hz;
            ts_eigen_free(e);
            ts_err_clear(err);
        }
        /* Is it trustworthy? The equilibrium linearized about, and the
         * waterline kink for a heave input (towstab/health.h). */
        ts_trust trust, te;
        ts_trust_init(&trust);
        ts_trust_init(&te);
        ts_health_equilibrium(sys, eq, &te);
        ts_trust_merge(&trust, "equilibrium: ", &te);
        if (lin->kink_tow && input == 2)
            ts_trust_note(&trust, "the tow point is at the water surface: "
                                  "a real heave also shifts the mean depth "
                                  "at first order, which a frequency "
                                  "response cannot show");
        if (lin->kinks && !(lin->kink_tow && lin->kinks == 1))
            ts_trust_note(&trust, "%d node%s within a linearization step of "
                                  "the water surface: f is not smooth there",
                          lin->kinks, lin->kinks == 1 ? "" : "s");
        printf("trustworthy: %s\n", trust.trustworthy ? "yes" : "NO");
        for (int i = 0; i < trust.nreasons; i++)
            printf("  reason: %s\n", trust.reasons[i]);
        for (int i = 0; i < trust.nnotes; i++)
            printf("  note: %s\n", trust.notes[i]);
        json_t *j = ts_report_response_json(*res);
        if (j) {
            json_t *tj = ts_report_trust_json(&trust);
            if (tj) {
                json_object_update(j, tj);
                json_decref(tj);
            }
        }
        if (j && eqjson)
            json_object_set(j, "equilibrium", eqjson);
        *json = j;
    }
    free(freq);
    json_decref(eqjson);
    ts_equilibrium_free(eq);
    ts_linear_free(lin);
    return rc;
}

static int parse_freq(const ts_units *units, const char *text,
                      const char *where, double *v, ts_err *err)
{
    return ts_units_parse(units, text, "Hz", where, v, err);
}

static int response_main(int argc, char **argv)
{
    cli_settings s = {0};
    cli_settings_from_options(&s);
    snprintf(s.where[2], sizeof s.where[2], "--eq-method");
    const char *json_path = NULL, *csv_path = NULL;
    const char *from = NULL, *to = NULL;
    int quiet = 0;
    resp_req rq = {"tow.heave", NULL, DEFAULT_FROM_HZ, DEFAULT_TO_HZ,
                   DEFAULT_POINTS};
    cli_plot plot = {0};
    static const struct option longopts[] = {
        {"input", required_argument, NULL, 'i'},
        {"output", required_argument, NULL, 'o'},
        {"from", required_argument, NULL, 'F'},
        {"to", required_argument, NULL, 'T'},
        {"points", required_argument, NULL, 'p'},
        {"json", required_argument, NULL, 'j'},
        {"csv", required_argument, NULL, 'c'},
        CLI_SETTINGS_LONGOPTS("eq-method"),
        {"quiet", no_argument, NULL, 'q'},
        {"plot", required_argument, NULL, 'P'},
        {"units", required_argument, NULL, 'U'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    optind = 1;
    opterr = 0;
    int ch;
    long v;
    while ((ch = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (ch) {
        case 'i': rq.input = optarg; break;
        case 'o': rq.output = optarg; break;
        case 'F': from = optarg; break;
        case 'T': to = optarg; break;
        case 'p':
            if (cli_parse_int("--points", optarg, 2, MAX_POINTS, &v))
                return EXIT_BADINPUT;
            rq.points = (int)v;
            break;
        case 'j': json_path = optarg; break;
        case 'c': csv_path = optarg; break;
        case 'q': quiet = 1; break;
        case 'P': plot.dir = optarg; break;
        case 'U': plot.units = optarg; break;
        case 'h': usage(stdout); return 0;
        default: {
            int r = cli_settings_option(&s, ch, optarg);
            if (r < 0)
                return EXIT_BADINPUT;
            if (r == 0)
                return cli_option_error("response", ch, argv[optind - 1]);
        }
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "towstab: error: response: expected one scene file\n");
        usage(stderr);
        return EXIT_BADINPUT;
    }
    int pstatus = cli_plot_begin(&plot, "response");
    if (pstatus)
        return pstatus;
    ts_units *units;
    ts_scene *scene;
    int status = cli_open(argv[optind], &units, &scene);
    if (status)
        return status;
    ts_err err = {0};
    int rc = TS_OK;
    if (from)
        rc = parse_freq(units, from, "--from", &rq.from, &err);
    if (rc == TS_OK && to)
        rc = parse_freq(units, to, "--to", &rq.to, &err);
    ts_equilibrium_opts eqo;
    ts_system *sys = NULL;
    if (rc == TS_OK) {
        sys = cli_system(scene, units, &s, &eqo, &err);
        if (!sys)
            rc = err.code;
    }
    if (rc == TS_OK && !rq.output) {
        char list[768];
        ts_response_output_names(sys, list, sizeof list);
        rc = ts_fail(&err, TS_EINVAL, "--output: required; valid outputs: %s",
                     list);
    }
    if (rc != TS_OK) {
        status = cli_report(&err, rc);
        ts_system_free(sys);
        cli_close(units, scene);
        return status;
    }
    printf("towstab response: %s (%s)\n", sys->name, scene->path);
    json_t *json = NULL;
    ts_response *res = NULL;
    double nat[PLOT_NATURAL];
    int nnat = 0;
    rc = response_analysis(sys, &eqo, &rq, quiet, &json, &res,
                           plot.dir ? nat : NULL, &nnat, &err);
    if (rc != TS_OK)
        status = cli_report(&err, rc);
    ts_err werr = {0};
    if (rc == TS_OK && json_path && json &&
        cli_write_json(json, json_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    if (rc == TS_OK && csv_path &&
        ts_report_response_csv(res, csv_path, &werr) != TS_OK)
        status = cli_report(&werr, werr.code);
    if (rc == TS_OK && plot.dir) {
        /* Phase unwrapped for drawing, in radians. */
        double *ph = malloc((size_t)res->npoints * sizeof(double));
        if (!ph) {
            fprintf(stderr, "towstab: error: response: --plot: out of "
                            "memory\n");
            status = EXIT_FAILED;
        } else {
            double shift = 0.0;
            for (int i = 0; i < res->npoints; i++) {
                double p = res->phase_deg[i] * M_PI / 180.0;
                if (i > 0) {
                    double prev = ph[i - 1] - shift;
                    if (p - prev > M_PI)
                        shift -= 2 * M_PI;
                    else if (p - prev < -M_PI)
                        shift += 2 * M_PI;
                }
                ph[i] = p + shift;
            }
            char title[256], mag_label[192];
            snprintf(title, sizeof title, "%s: frequency response",
                     sys->name);
            snprintf(mag_label, sizeof mag_label, "%s / %s",
                     res->output.name, ts_input_name(res->input));
            ts_plot_bode_curve c = {res->npoints, res->freq_hz,
                                    res->magnitude, ph, mag_label,
                                    TS_PLOT_SOLID, 0};
            int tension = res->output.kind == TS_OUT_TENSION;
            ts_err perr = {0};
            if (ts_plot_bode(plot.dir, "bode", title, mag_label,
                             tension ? TS_PLOT_FORCE : TS_PLOT_LENGTH,
                             TS_PLOT_LENGTH, 1, &c, nnat, nat, &plot.opts,
                             &perr) != TS_OK)
                status = cli_report(&perr, perr.code);
            else
                printf("wrote %s/bode.png and %s/bode.svg\n", plot.dir,
                       plot.dir);
            free(ph);
        }
    }
    json_decref(json);
    ts_response_free(res);
    ts_system_free(sys);
    cli_close(units, scene);
    return status;
}

static const char *const response_keys[] = {
    "speed", "turn_rate", "tolerance", "links", "equilibrium_method",
    "input", "output", "from", "to", "points", NULL};

/* One scene entry: parse and check its options (units, ranges, input and
 * output names), and with a result slot run it. Returns the exit
 * status. */
static int response_entry(const cli_ctx *ctx, const ts_scene_analysis *a,
                          int index, json_t **result)
{
    ts_err err = {0};
    cli_settings s = {0};
    if (cli_settings_from_analysis(&s, a, index, &err))
        return cli_report(&err, err.code);
    const ts_scene_option *o = ts_scene_analysis_option(a, "equilibrium_method");
    s.method = o ? o->value : NULL;
    snprintf(s.where[2], sizeof s.where[2],
             "analyses[%d].equilibrium_method (line %d)", index,
             o ? o->line : a->line);
    resp_req rq = {"tow.heave", NULL, DEFAULT_FROM_HZ, DEFAULT_TO_HZ,
                   DEFAULT_POINTS};
    char where[160];
    if ((o = ts_scene_analysis_option(a, "input")))
        rq.input = o->value;
    if ((o = ts_scene_analysis_option(a, "output")))
        rq.output = o->value;
    static const char *const fkeys[2] = {"from", "to"};
    double *fdst[2] = {&rq.from, &rq.to};
    for (int i = 0; i < 2; i++)
        if ((o = ts_scene_analysis_option(a, fkeys[i]))) {
            snprintf(where, sizeof where, "analyses[%d].%s (line %d)", index,
                     fkeys[i], o->line);
            if (parse_freq(ctx->units, o->value, where, fdst[i], &err))
                return cli_report(&err, err.code);
        }
    if ((o = ts_scene_analysis_option(a, "points"))) {
        char *end;
        long p = strtol(o->value, &end, 10);
        if (end == o->value || *end || p < 2 || p > MAX_POINTS) {
            ts_fail(&err, TS_EINVAL,
                    "analyses[%d].points (line %d): expected a whole number "
                    "in [2, %d], got '%s'",
                    index, o->line, MAX_POINTS, o->value);
            return cli_report(&err, err.code);
        }
        rq.points = (int)p;
    }
    ts_equilibrium_opts eqo;
    ts_system *sys = cli_system(ctx->scene, ctx->units, &s, &eqo, &err);
    if (!sys)
        return cli_report(&err, err.code);
    if (!rq.output) {
        char list[768];
        ts_response_output_names(sys, list, sizeof list);
        ts_fail(&err, TS_EINVAL,
                "analyses[%d] (line %d): response needs an 'output'; valid "
                "outputs: %s",
                index, a->line, list);
        ts_system_free(sys);
        return cli_report(&err, err.code);
    }
    if (!result) {
        int channel;
        ts_output out;
        double f[2];
        int rc = ts_response_input_find(rq.input, &channel, &err);
        if (rc == TS_OK)
            rc = ts_response_output_find(sys, rq.output, &out, &err);
        if (rc == TS_OK)
            rc = ts_response_logspace(rq.from, rq.to, 2, f, &err);
        ts_system_free(sys);
        if (rc != TS_OK)
            ts_err_prefix(&err, "analyses[%d] (line %d): ", index, a->line);
        return rc == TS_OK ? 0 : cli_report(&err, rc);
    }
    ts_response *res = NULL;
    int rc = response_analysis(sys, &eqo, &rq, ctx->quiet, result, &res, NULL,
                               NULL, &err);
    int status = rc ? cli_report(&err, rc) : 0;
    ts_response_free(res);
    ts_system_free(sys);
    return status;
}

const cli_command cli_cmd_response = {
    "response", "frequency response to tow-point motion", response_main,
    response_entry, response_keys};
