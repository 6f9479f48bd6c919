/* bench_linear.c: time of the linear-stability pipeline (doc/linear.md,
 * doc/performance-linear.md). Towed cable with a sphere and drag, straight
 * tow:
 *  - 100 links (400 states): linearize + full LAPACK eigen report (all
 *    modes, vectors, descriptions); target < 0.3 s total;
 *  - 400 links (1600 states): the same;
 *  - 2000 links (8000 states): sparse linearization + ARPACK 10 lowest
 *    modes and the rightmost search; target < 20 s.
 * Each figure is the best of `reps` runs (wall clock); linearization is
 * timed with 1 thread and with OpenMP's default. Prints one line per case
 * and "N passed, N failed" against the targets. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"

static ts_scene *make(ts_units *u, int links)
{
    char yaml[1024];
    snprintf(yaml, sizeof yaml,
             "name: bench\n"
             "tow: {speed: 2.2, point: [0, 0, 0.5]}\n"
             "cables:\n"
             "  - {name: cable, from: tow, to: fish, length: %g,\n"
             "     diameter: 0.021, mass_per_length: 0.77, links: %d,\n"
             "     normal_drag: 1.2, tangential_drag: 0.01, added_mass: 1.0}\n"
             "bodies:\n"
             "  - {name: fish, type: sphere, diameter: 0.5, mass: 150.0,\n"
             "     drag: 0.5, added_mass: 0.5}\n",
             links * 1.0, links);
    ts_err err = {0};
    ts_scene *s = ts_scene_parse(yaml, strlen(yaml), "bench", u, &err);
    if (!s)
        fprintf(stderr, "bench: %s\n", err.msg);
    return s;
}

static int npass, nfail;

static void run(ts_units *u, int links, int arpack, int reps, double target)
{
    ts_scene *sc = make(u, links);
    if (!sc) {
        nfail++;
        return;
    }
    const ts_system *sys = sc->system;
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    double t0 = tsi_wall_now();
    int rc = ts_equilibrium_solve(k, NULL, eq, &err);
    double t_eq = tsi_wall_now() - t0;
    ts_linear *lin = rc == TS_OK ? ts_linear_alloc(k, &err) : NULL;
    if (!lin) {
        printf("FAIL %d links: %s\n", links, err.msg);
        nfail++;
        return;
    }
    double best_lin1 = INFINITY, best_lin = INFINITY, best_eig = INFINITY;
    int threads = 1, nmodes = 0;
    double cpu_lin = INFINITY, cpu_eig = INFINITY;
    for (int r = 0; r < reps; r++) {
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        /* LAPACK needs the dense A (formed by default below 1200 states
         * only); ARPACK runs on the sparse model. */
        lo.model = arpack ? TS_LIN_AUTO : TS_LIN_DENSE;
        if (links <= 400) {
            lo.threads = 1;
            t0 = tsi_wall_now();
            rc |= ts_linearize_equilibrium(k, eq, &lo, lin, &err);
            best_lin1 = fmin(best_lin1, tsi_wall_now() - t0);
        }
        lo.threads = 0;
        t0 = tsi_wall_now();
        double c0 = tsi_cpu_now();
        rc |= ts_linearize_equilibrium(k, eq, &lo, lin, &err);
        best_lin = fmin(best_lin, tsi_wall_now() - t0);
        cpu_lin = fmin(cpu_lin, tsi_cpu_now() - c0);
        threads = lin->threads;
        ts_eigen_opts eo;
        ts_eigen_opts_default(&eo);
        if (arpack) {
            eo.method = TS_EIG_ARPACK;
            eo.count = 10;
        }
        ts_eigen *e = NULL;
        t0 = tsi_wall_now();
        c0 = tsi_cpu_now();
        rc |= ts_eigen_solve(lin, &eo, &e, &err);
        if (e) {
            char d[256];
            for (int m = 0; m < e->nmodes; m++)
                ts_eigen_describe(sys, lin, e, m, d, sizeof d);
            nmodes = e->nmodes;
        }
        best_eig = fmin(best_eig, tsi_wall_now() - t0);
        cpu_eig = fmin(cpu_eig, tsi_cpu_now() - c0);
        ts_eigen_free(e);
    }
    double total = best_lin + best_eig;
    int ok = rc == TS_OK && total < target;
    printf("%s %4d links (%5d states): equilibrium %.3f s; linearize %.3f s "
           "(%d threads)",
           ok ? "PASS" : "FAIL", links, 4 * links, t_eq, best_lin, threads);
    if (isfinite(best_lin1))
        printf(", %.3f s (1 thread)", best_lin1);
    printf("; %s %d modes + descriptions %.3f s; total %.3f s (target < %g "
           "s); CPU time linearize %.3f s, eigen %.3f s%s%s\n",
           arpack ? "arpack" : "lapack", nmodes, best_eig, total, target,
           cpu_lin, cpu_eig, rc ? ": " : "", rc ? err.msg : "");
    if (ok)
        npass++;
    else
        nfail++;
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    if (!u) {
        printf("FAIL units: %s\n", err.msg);
        return 1;
    }
    run(u, 100, 0, 5, 0.3);
    run(u, 400, 0, 2, 60.0);
    run(u, 2000, 1, 1, 20.0);
    ts_units_free(u);
    printf("%d passed, %d failed\n", npass, nfail);
    return nfail ? 1 : 0;
}
