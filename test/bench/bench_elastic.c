/* bench_elastic: elastic cables (doc/elastic.md).
 *
 * 1. Time to a converged equilibrium (relative force residual <= 1e-10)
 *    of Kamman example 1 with an elastic cable, EA = 1e9 N and Cv = 4000
 *    N s/m (examples/kamman_ex1_elastic.yaml) at 100 and 1000 links:
 *    straight and in a turn of radius 2 L by the default method (marching
 *    with Hooke's stretch, and shooting), and by Newton started from the
 *    rigid solution's directions (opts.guess; the rigid solve is not
 *    timed). The target: 100 links straight under 20 ms.
 * 2. The two-part tow (examples/two_part_tow.yaml): 35 elastic links with
 *    bending, Newton with continuation in turn rate and bending stiffness.
 * 3. One kernel evaluation, elastic against rigid, at 100 and 1000 links.
 * Each figure is the median of 9 runs (timing: bench_common.h), each from
 * a fresh kernel. Run from the project root. */
#include "bench_common.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"
#include "towstab/units.h"

#define RUNS 9

static ts_system *elastic_ex1(int nlinks, double turn_rate)
{
    ts_system *s = bench_kamman_ex1(nlinks, turn_rate);
    if (!s)
        return NULL;
    s->cables[0].ea = 1e9;
    s->cables[0].damping = 4000;
    if (ts_system_build(s, NULL) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* Median time of RUNS solves of sys by method m from guess (or NULL). */
static int run(const char *label, const ts_system *sys, ts_eq_method m,
               const double *guess)
{
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, NULL);
    if (!eq)
        return 1;
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = m;
    o.guess = guess;
    double t[RUNS];
    int conv = 1;
    for (int r = 0; r < RUNS; r++) {
        ts_kernel *k = ts_kernel_alloc(sys, NULL);
        if (!k)
            return 1;
        double t0 = bench_now();
        int rc = ts_equilibrium_solve(k, &o, eq, NULL);
        t[r] = bench_now() - t0;
        conv &= rc == TS_OK && eq->converged;
        ts_kernel_free(k);
    }
    printf("%-40s %6d %10.3f %9.2e %6d %7ld %s\n", label, sys->nlinks,
           bench_median(t, RUNS) * 1e3, eq->residual, eq->iterations,
           eq->evaluations, conv ? ts_eq_method_name(eq->method)
                                 : "NOT CONVERGED");
    ts_equilibrium_free(eq);
    return conv ? 0 : 1;
}

/* The rigid solution's link directions, [3 nlinks] (caller frees). */
static double *rigid_directions(int nlinks, double turn_rate)
{
    ts_system *r = bench_kamman_ex1(nlinks, turn_rate);
    ts_kernel *k = r ? ts_kernel_alloc(r, NULL) : NULL;
    ts_equilibrium *eq = r ? ts_equilibrium_alloc(r, NULL) : NULL;
    double *n = NULL;
    if (k && eq && ts_equilibrium_solve(k, NULL, eq, NULL) == TS_OK) {
        n = malloc(3 * (size_t)nlinks * sizeof(double));
        if (n)
            memcpy(n, eq->directions, 3 * (size_t)nlinks * sizeof(double));
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(r);
    return n;
}

/* Median time of one kernel evaluation at a trailing, moving state. */
static double eval_time(const ts_system *s)
{
    ts_kernel *k = ts_kernel_alloc(s, NULL);
    int nq = ts_kernel_nq(k), ns = 2 * nq;
    double *y = calloc((size_t)ns, sizeof(double));
    double *d = calloc((size_t)ns, sizeof(double));
    for (int l = 0; l < s->nlinks; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o] = 0.35 + 0.3 * l / s->nlinks;
        y[o + 1] = 0.05 * sin(0.1 * l);
        y[nq + o] = 0.01 * cos(0.2 * l);
        y[nq + o + 1] = -0.01;
        if (s->links[l].elastic) {
            y[o + 2] = 3e-7;
            y[nq + o + 2] = 1e-6;
        }
    }
    int reps = 2000000 / s->nlinks;
    double t[RUNS];
    for (int r = 0; r < RUNS; r++) {
        double t0 = bench_now();
        for (int i = 0; i < reps; i++)
            ts_kernel_eval(k, y, NULL, d);
        t[r] = (bench_now() - t0) / reps;
    }
    free(y);
    free(d);
    ts_kernel_free(k);
    return bench_median(t, RUNS);
}

int main(void)
{
    int bad = 0;
    printf("%-40s %6s %10s %9s %6s %7s %s\n", "case", "links", "ms",
           "residual", "iter", "evals", "method");
    static const int sizes[] = {100, 1000};
    for (int i = 0; i < 2; i++) {
        int n = sizes[i];
        ts_system *s = elastic_ex1(n, 0.0);
        double V = s->tow.speed, L = s->cables[0].length;
        double *guess = rigid_directions(n, 0.0);
        bad |= run("ex1 EA 1e9 straight, default", s, TS_EQ_AUTO, NULL);
        if (n <= 100)
            bad |= run("ex1 EA 1e9 straight, Newton from rigid", s,
                       TS_EQ_NEWTON, guess);
        free(guess);
        ts_system_free(s);
        s = elastic_ex1(n, V / (2 * L));
        guess = rigid_directions(n, V / (2 * L));
        bad |= run("ex1 EA 1e9 turn radius 2 L, default", s, TS_EQ_AUTO,
                   NULL);
        if (n <= 100)
            bad |= run("ex1 EA 1e9 turn 2 L, Newton from rigid", s,
                       TS_EQ_NEWTON, guess);
        free(guess);
        ts_system_free(s);
    }

    ts_units *u = ts_units_alloc(NULL);
    ts_scene *sc = u ? ts_scene_load("examples/two_part_tow.yaml", u, NULL)
                     : NULL;
    if (sc)
        bad |= run("two-part tow (bending continuation)", sc->system,
                   TS_EQ_AUTO, NULL);
    else
        bad = 1;

    printf("\n%-40s %6s %12s %12s\n", "kernel f(y, u)", "links", "us",
           "ns per link");
    for (int i = 0; i < 2; i++) {
        int n = sizes[i];
        ts_system *r = bench_kamman_ex1(n, 0.0), *e = elastic_ex1(n, 0.0);
        double tr = eval_time(r), te = eval_time(e);
        printf("%-40s %6d %12.3f %12.1f\n", "ex1 rigid", n, tr * 1e6,
               tr * 1e9 / n);
        printf("%-40s %6d %12.3f %12.1f\n", "ex1 elastic", n, te * 1e6,
               te * 1e9 / n);
        ts_system_free(r);
        ts_system_free(e);
    }
    if (sc) {
        double t2 = eval_time(sc->system);
        printf("%-40s %6d %12.3f %12.1f\n", "two-part tow (bending, bodies)",
               sc->system->nlinks, t2 * 1e6, t2 * 1e9 / sc->system->nlinks);
    }
    ts_scene_free(sc);
    ts_units_free(u);
    return bad;
}
