/* bench_seastate.c: cost of the sea-state analyses (doc/seastate.md,
 * doc/performance.md "Sea state"), on examples/survey_tow_sea.yaml with the
 * ship of examples/ship_rao.csv (reference point 30 m ahead of the tow
 * point), JONSWAP Hs 2 m, Tp 8 s, gamma 3.3, head seas:
 *  - the spectral response of fish.z at 512 intervals (1026 gains: two
 *    inputs driven) with 20 and 100 links per cable; target < 0.5 s at
 *    20 links;
 *  - one evaluation of a realisation's tow-point input (ts_excitation_input)
 *    with 64, 256 and 1024 components;
 *  - 600 s of irregular sea in the time domain, linear (expm) and
 *    nonlinear (rk8pd), 20 links, 256 components.
 * Each figure is the median of `reps` runs (wall clock). Prints one line
 * per case and "N passed, N failed" against the target. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_common.h"
#include "towstab/converge.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"
#include "towstab/seastate.h"

#define REPS 5
#define SPECTRAL_TARGET 0.5 /* s, 20 links */

static int npass, nfail;

typedef struct bcase {
    ts_system *sys;
    ts_kernel *k;
    ts_equilibrium *eq;
    ts_linear *lin;
} bcase;

static int open_case(const ts_system *base, int links, bcase *c)
{
    ts_err err = {0};
    memset(c, 0, sizeof *c);
    c->sys = ts_conv_system_with_links(base, links, &err);
    c->k = c->sys ? ts_kernel_alloc(c->sys, &err) : NULL;
    c->eq = c->k ? ts_equilibrium_alloc(c->sys, &err) : NULL;
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    if (!c->eq || ts_equilibrium_solve(c->k, &eo, c->eq, &err)) {
        fprintf(stderr, "bench_seastate: %s\n", err.msg);
        return 0;
    }
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    c->lin = ts_linear_alloc(c->k, &err);
    if (!c->lin || ts_linearize_equilibrium(c->k, c->eq, &lo, c->lin, &err)) {
        fprintf(stderr, "bench_seastate: %s\n", err.msg);
        return 0;
    }
    return 1;
}

static void close_case(bcase *c)
{
    ts_linear_free(c->lin);
    ts_equilibrium_free(c->eq);
    ts_kernel_free(c->k);
    ts_system_free(c->sys);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *scene =
        u ? ts_scene_load("examples/survey_tow_sea.yaml", u, &err) : NULL;
    ts_rao *rao = u ? ts_rao_read_csv("examples/ship_rao.csv", u, &err)
                    : NULL;
    ts_sea *sea = ts_sea_jonswap(2.0, 8.0, 3.3, M_PI, &err);
    if (!scene || !rao || !sea) {
        fprintf(stderr, "bench_seastate: %s (run from the project root)\n",
                err.msg);
        return 1;
    }
    const double reference[3] = {30, 0, 0};
    static const int links[2] = {20, 100};
    for (int L = 0; L < 2; L++) {
        bcase c;
        if (!open_case(scene->system, links[L], &c))
            return 1;
        ts_seaway w;
        ts_output out;
        if (ts_seaway_init(&w, c.sys, sea, rao, reference, &err) ||
            ts_response_output_find(c.sys, "fish.z", &out, &err)) {
            fprintf(stderr, "bench_seastate: %s\n", err.msg);
            return 1;
        }
        double t[REPS];
        ts_seastate *r = NULL;
        for (int i = 0; i < REPS; i++) {
            double t0 = bench_now();
            ts_seastate_free(r);
            if (ts_seastate_compute(c.sys, c.lin, &w, &out, NULL, &r,
                                    &err)) {
                fprintf(stderr, "bench_seastate: %s\n", err.msg);
                return 1;
            }
            t[i] = bench_now() - t0;
        }
        double med = bench_median(t, REPS);
        printf("spectral fish.z, %3d links, 512 intervals: %.4f s (%ld "
               "gains, %.1f us each); sigma %.6g +- %.2g m\n", links[L], med,
               r->responses, 1e6 * med / r->responses, r->sigma.value,
               r->sigma.error);
        if (links[L] == 20) {
            if (med < SPECTRAL_TARGET)
                npass++;
            else
                nfail++;
        }
        ts_seastate_free(r);
        close_case(&c);
    }

    bcase c;
    if (!open_case(scene->system, 20, &c))
        return 1;
    ts_seaway w;
    ts_seaway_init(&w, c.sys, sea, rao, reference, &err);
    static const int comps[3] = {64, 256, 1024};
    for (int j = 0; j < 3; j++) {
        ts_sea_realisation r;
        ts_sea_realisation_default(&w, &r);
        r.components = comps[j];
        ts_excitation *ex = ts_excitation_alloc(&err);
        ts_seaway_excitation(&w, &r, ex, NULL, &err);
        double t[REPS], u9[TS_NINPUT], sink = 0;
        const int calls = 20000;
        for (int i = 0; i < REPS; i++) {
            double t0 = bench_now();
            for (int q = 0; q < calls; q++) {
                ts_excitation_input(ex, 100.0 + 1e-3 * q, u9);
                sink += u9[2];
            }
            t[i] = (bench_now() - t0) / calls;
        }
        printf("realisation input, %4d components: %.2f us per evaluation "
               "(%s)\n", comps[j], 1e6 * bench_median(t, REPS),
               sink != 0 ? "heave and surge driven" : "?");
        ts_excitation_free(ex);
    }

    ts_sea_realisation r;
    ts_sea_realisation_default(&w, &r);
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_seaway_excitation(&w, &r, ex, NULL, &err);
    ts_sim_opts so;
    ts_sim_opts_default(&so);
    so.t_end = 600;
    so.dt_sample = 0.25;
    int ns = ts_sim_nsamples(&so);
    ts_history *h = ts_history_alloc(c.sys, ns, &err);
    double tl[3], tn[3];
    long steps_l = 0, steps_n = 0;
    for (int i = 0; i < 3; i++) {
        ts_sim_stats st;
        h->nsamples = 0;
        double t0 = bench_now();
        if (ts_simulate_linear(c.k, c.lin, ex, NULL, &so, h, &st, &err)) {
            fprintf(stderr, "bench_seastate: %s\n", err.msg);
            return 1;
        }
        tl[i] = bench_now() - t0;
        steps_l = st.steps;
        ts_kernel *knl = ts_kernel_clone(c.k, &err);
        h->nsamples = 0;
        t0 = bench_now();
        if (ts_simulate(knl, ex, c.eq->y, &so, h, &st, NULL, &err)) {
            fprintf(stderr, "bench_seastate: %s\n", err.msg);
            return 1;
        }
        tn[i] = bench_now() - t0;
        steps_n = st.steps;
        ts_kernel_free(knl);
    }
    printf("600 s of irregular sea, 20 links, 256 components: linear (expm) "
           "%.2f s (%ld steps), nonlinear (rk8pd) %.2f s (%ld steps)\n",
           bench_median(tl, 3), steps_l, bench_median(tn, 3), steps_n);
    ts_history_free(h);
    ts_excitation_free(ex);
    close_case(&c);
    ts_sea_free(sea);
    ts_rao_free(rao);
    ts_scene_free(scene);
    ts_units_free(u);
    printf("%d passed, %d failed\n", npass, nfail);
    return nfail ? 1 : 0;
}
