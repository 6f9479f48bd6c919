/* elastic_sim_table.c: the response columns of doc/elastic.md's EA table
 *: as EA grows, the elastic model's frequency response
 * and simulated response converge to the rigid model's.
 *
 * Scene: Kamman example 1 (examples/kamman_ex1_submerged.yaml), 20 links,
 * the tow point 1 ft below the surface (so that no link crosses it: the
 * kink of doc/model.md section 6 would make the linearization's one-sided
 * derivatives differ), Cv = 0 as in the equilibrium columns.
 *  - frequency response: the largest relative difference of the sphere's
 *    heave response H(i w) = sphere.z / tow.heave (complex) from the rigid
 *    model's, over 0.02, 0.05, 0.1, 0.25, 0.5 and 1 Hz (ts_response_at);
 *  - simulated response: the tow point stepped 0.3 m down over 1 s from
 *    the equilibrium, 3 s; the largest node position difference from the
 *    rigid run over all samples (every 0.05 s), over the cable length.
 *    Rigid: rk8pd, rtol 1e-10; elastic: msbdf, rtol 1e-9, atol 1e-7
 *    (integration error ~1e-9 of the positions, 1e-10 of L).
 * Prints a Markdown table. Run from the project root:
 *   ninja -C build test/elastic_sim_table && build/test/elastic_sim_table */
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "towstab/equilibrium.h"
#include "towstab/excitation.h"
#include "towstab/linearize.h"
#include "towstab/response.h"
#include "towstab/scene.h"
#include "towstab/simulate.h"
#include "towstab/units.h"

#define NF 6
static const double freqs[NF] = {0.02, 0.05, 0.1, 0.25, 0.5, 1.0};

static int prepare(ts_system *s, double ea, double complex H[NF],
                   ts_history **h, const ts_excitation *ex, ts_err *err)
{
    s->cables[0].ea = ea;
    s->cables[0].damping = 0.0;
    if (ts_system_build(s, err))
        return 1;
    ts_kernel *k = ts_kernel_alloc(s, err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, err);
    ts_linear *lin = k ? ts_linear_alloc(k, err) : NULL;
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    ts_output out;
    int rc = !k || !eq || !lin;
    if (!rc)
        rc = ts_equilibrium_solve(k, &eo, eq, err);
    if (!rc)
        rc = ts_linearize_equilibrium(k, eq, &lo, lin, err);
    if (!rc)
        rc = ts_response_output_find(s, "sphere.z", &out, err);
    for (int i = 0; i < NF && !rc; i++) {
        double re, im;
        rc = ts_response_at(s, lin, 2, &out, 2 * M_PI * freqs[i], &re, &im,
                            err);
        H[i] = re + I * im;
    }
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 3.0;
    o.dt_sample = 0.05;
    if (ea > 0) {
        o.integrator = TS_INT_MSBDF;
        o.rel_tol = 1e-9;
        o.abs_tol = 1e-7;
    } else {
        o.rel_tol = 1e-10;
        o.abs_tol = 1e-12;
    }
    *h = ts_history_alloc(s, ts_sim_nsamples(&o), err);
    if (!rc)
        rc = ts_linearize_equilibrium(k, eq, &lo, lin, err); /* charts */
    if (!rc && *h)
        rc = ts_simulate(k, ex, eq->y, &o, *h, NULL, NULL, err);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return rc;
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = u ? ts_scene_load("examples/kamman_ex1_submerged.yaml",
                                     u, &err) : NULL;
    if (!sc) {
        fprintf(stderr, "elastic_sim_table: %s\n", err.msg);
        return 1;
    }
    ts_system *s = sc->system;
    s->cables[0].nlinks = 20;
    s->tow.point[2] = 0.3048;
    double L = s->cables[0].length;
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_excitation_parse(ex, "tow.heave:type=step,amplitude=0.3m,rise=1s", u,
                        "table", &err);
    double complex H0[NF], H[NF];
    ts_history *h0 = NULL, *h = NULL;
    if (prepare(s, 0.0, H0, &h0, ex, &err)) {
        fprintf(stderr, "elastic_sim_table: rigid: %s\n", err.msg);
        return 1;
    }
    printf("| EA [N] | frequency response: max rel. diff | simulated: max dr "
           "/ L |\n|---:|---:|---:|\n");
    for (double ea = 1e4; ea <= 1e10 * 1.01; ea *= 10) {
        int rc = prepare(s, ea, H, &h, ex, &err);
        double dh = 0, dr = 0;
        for (int i = 0; i < NF; i++)
            dh = fmax(dh, cabs(H[i] - H0[i]) / cabs(H0[i]));
        for (int i = 0; h && i < h->nsamples && i < h0->nsamples; i++)
            for (int j = 0; j < 3 * h->nnodes; j++)
                dr = fmax(dr, fabs(h->positions[3 * h->nnodes * i + j] -
                                   h0->positions[3 * h0->nnodes * i + j]));
        printf("| %.0e | %.3e | %.3e |%s%s\n", ea, dh, dr / L,
               rc ? " failed: " : "", rc ? err.msg : "");
        ts_history_free(h);
        h = NULL;
    }
    ts_history_free(h0);
    ts_excitation_free(ex);
    ts_scene_free(sc);
    ts_units_free(u);
    return 0;
}
