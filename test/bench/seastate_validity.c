/* seastate_validity.c: the linear-validity map of doc/seastate.md: how far
 * the linear prediction of the response to an irregular sea drifts from
 * the nonlinear model as Hs grows. Not a test: it prints the table.
 *
 *   build/test/seastate_validity [SCENE [RAO [OUTPUT [T_END [SEED]]]]]
 *
 * defaults: examples/survey_tow_sea.yaml, examples/ship_rao.csv, fish.z,
 * 2400 s, seed 1; RAO reference point 30 m ahead of the tow point (midship
 * on the waterline of the ship of examples/ship_rao.csv), JONSWAP Tp 8 s,
 * gamma 3.3, head seas. For each Hs the same realisation (same seed:
 * common random numbers, scaled) drives a linear and a nonlinear
 * simulation; the first 600 s are discarded (more than five of the
 * slowest time constant, 106 s, of the default scene). Columns:
 *   sigma spectral: the linear model's standard deviation, spectral
 *     (doc/seastate.md section 3), with its integration and band error;
 *   sigma linear, nonlinear: the records' standard deviations with their
 *     statistical error;
 *   nl / lin: the ratio of the two records' standard deviations, which
 *     share the realisation, so that its statistical error (batch means
 *     over 6 parts) is far smaller than each one's; drift = ratio - 1;
 *   mean shift: the nonlinear record's mean less the equilibrium value;
 *   top tension: the spectral standard deviation and the nonlinear
 *     record's, and the record's smallest and largest values (below zero
 *     the rigid links push: a real cable would go slack);
 *   wall: seconds of the two runs.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "towstab/equilibrium.h"
#include "towstab/linearize.h"
#include "towstab/scene.h"
#include "towstab/seastate.h"
#include "towstab/simulate.h"

#define TRANSIENT 600.0
#define DT_SAMPLE 0.25
#define TP 8.0
#define GAMMA 3.3
/* Parts of the record for the ratio's error (batch means). */
#define BATCHES 6

static int fail(const char *what, const ts_err *err)
{
    fprintf(stderr, "seastate_validity: %s: %s\n", what, err->msg);
    return 1;
}

int main(int argc, char **argv)
{
    const char *scene_path = argc > 1 ? argv[1]
                                      : "examples/survey_tow_sea.yaml";
    const char *rao_path = argc > 2 ? argv[2] : "examples/ship_rao.csv";
    const char *out_name = argc > 3 ? argv[3] : "fish.z";
    double t_end = argc > 4 ? atof(argv[4]) : 2400.0;
    unsigned long seed = argc > 5 ? strtoul(argv[5], NULL, 10) : 1;
    const double reference[3] = {30.0, 0.0, 0.0};
    static const double hs_list[] = {0.25, 0.5, 1, 2, 3, 4, 5};
    const int nhs = (int)(sizeof hs_list / sizeof hs_list[0]);

    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ts_scene *scene = units ? ts_scene_load(scene_path, units, &err) : NULL;
    if (!scene)
        return fail(scene_path, &err);
    const ts_system *sys = scene->system;
    ts_rao *rao = ts_rao_read_csv(rao_path, units, &err);
    if (!rao)
        return fail(rao_path, &err);
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    if (ts_equilibrium_solve(k, &eo, eq, &err))
        return fail("equilibrium", &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.tensions = 1;
    ts_linear *lin = ts_linear_alloc(k, &err);
    if (ts_linearize_equilibrium(k, eq, &lo, lin, &err))
        return fail("linearization", &err);
    ts_output out, top;
    if (ts_response_output_find(sys, out_name, &out, &err) ||
        ts_response_output_find(sys, "cable.1.tension", &top, &err))
        return fail("output", &err);
    ts_sim_opts so;
    ts_sim_opts_default(&so);
    so.t_end = t_end;
    so.dt_sample = DT_SAMPLE;
    int ns = ts_sim_nsamples(&so);
    ts_history *hl = ts_history_alloc(sys, ns, &err);
    ts_history *hn = ts_history_alloc(sys, ns, &err);
    double *x = malloc((size_t)ns * sizeof *x);
    double *xl = malloc((size_t)ns * sizeof *xl);
    if (!hl || !hn || !x || !xl)
        return fail("memory", &err);

    printf("%s, %s at %s, JONSWAP Tp %g s, gamma %g, head seas, seed %lu, "
           "%g s analysed of %g s\n\n", sys->name, out_name, rao_path, TP,
           GAMMA, seed, t_end - TRANSIENT, t_end);
    printf("| Hs [m] | sigma spectral [m] | sigma linear [m] | sigma "
           "nonlinear [m] | nl / lin | mean shift [m] | top tension sigma "
           "spectral [N] | sigma nonlinear [N] | min .. max [N] | wall [s] "
           "|\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int i = 0; i < nhs; i++) {
        double hs = hs_list[i];
        ts_sea *sea = ts_sea_jonswap(hs, TP, GAMMA, M_PI, &err);
        ts_seaway w;
        if (!sea || ts_seaway_init(&w, sys, sea, rao, reference, &err))
            return fail("sea", &err);
        ts_sea_realisation r;
        ts_sea_realisation_default(&w, &r);
        r.seed = seed;
        double lo_w, hi_w;
        ts_seaway_band(&w, TS_SEA_REALISATION_TAIL, &lo_w, &hi_w, &err);
        ts_seastate_opts o;
        ts_seastate_opts_default(&o);
        o.omega_lo = lo_w;
        o.omega_hi = hi_w;
        ts_seastate *sp = NULL, *spt = NULL;
        if (ts_seastate_compute(sys, lin, &w, &out, &o, &sp, &err) ||
            ts_seastate_compute(sys, lin, &w, &top, &o, &spt, &err))
            return fail("spectral", &err);
        ts_excitation *ex = ts_excitation_alloc(&err);
        if (!ex || ts_seaway_excitation(&w, &r, ex, NULL, &err))
            return fail("realisation", &err);
        double t0 = tsi_wall_now();
        hl->nsamples = hn->nsamples = 0;
        int n, nl;
        double dt;
        ts_record_stats sl, sn;
        if (ts_simulate_linear(k, lin, ex, NULL, &so, hl, NULL, &err) ||
            ts_record_from_history(hl, &out, TRANSIENT, xl, &nl, &dt, &err) ||
            ts_record_stats_compute(xl, nl, dt, &sl, &err))
            return fail("linear run", &err);
        ts_kernel *knl = ts_kernel_clone(k, &err);
        int rc = ts_simulate(knl, ex, eq->y, &so, hn, NULL, NULL, &err);
        double wall = tsi_wall_now() - t0;
        if (rc) {
            printf("| %g | %.4g +- %.1g | %.4g +- %.1g | failed: %s | | | "
                   "%.4g +- %.1g | | | %.0f |\n", hs, sp->sigma.value,
                   sp->sigma.error, sl.sigma.value, sl.sigma.error, err.msg,
                   spt->sigma.value, spt->sigma.error, wall);
        } else {
            ts_record_from_history(hn, &out, TRANSIENT, x, &n, &dt, &err);
            ts_record_stats_compute(x, n, dt, &sn, &err);
            /* The ratio's error by batch means: the spread of the ratio
             * over BATCHES consecutive parts of the paired records. */
            double ratio = sn.sigma.value / sl.sigma.value, s1 = 0, s2 = 0;
            int m = n / BATCHES;
            for (int b = 0; b < BATCHES; b++) {
                double vn = 0, vl = 0, mn = 0, ml = 0;
                for (int j = b * m; j < (b + 1) * m; j++) {
                    mn += x[j];
                    ml += xl[j];
                }
                mn /= m;
                ml /= m;
                for (int j = b * m; j < (b + 1) * m; j++) {
                    vn += (x[j] - mn) * (x[j] - mn);
                    vl += (xl[j] - ml) * (xl[j] - ml);
                }
                double q = sqrt(vn / vl);
                s1 += q;
                s2 += q * q;
            }
            double qm = s1 / BATCHES;
            double ratio_err = sqrt(fmax(s2 / BATCHES - qm * qm, 0) /
                                    (BATCHES - 1));
            ts_record_stats st;
            ts_record_from_history(hn, &top, TRANSIENT, x, &n, &dt, &err);
            ts_record_stats_compute(x, n, dt, &st, &err);
            printf("| %g | %.4g +- %.1g | %.4g +- %.1g | %.4g +- %.1g | "
                   "%.4f +- %.1g | %+.3g | %.4g +- %.1g | %.4g +- %.1g | "
                   "%.0f .. %.0f | %.0f |\n",
                   hs, sp->sigma.value, sp->sigma.error, sl.sigma.value,
                   sl.sigma.error, sn.sigma.value, sn.sigma.error, ratio,
                   ratio_err, sn.mean - sp->mean, spt->sigma.value,
                   spt->sigma.error, st.sigma.value, st.sigma.error,
                   st.minimum, st.maximum, wall);
        }
        fflush(stdout);
        ts_kernel_free(knl);
        ts_excitation_free(ex);
        ts_seastate_free(sp);
        ts_seastate_free(spt);
        ts_sea_free(sea);
    }
    free(x);
    free(xl);
    ts_history_free(hl);
    ts_history_free(hn);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_rao_free(rao);
    ts_scene_free(scene);
    ts_units_free(units);
    return 0;
}
