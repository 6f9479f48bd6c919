/* bench_sweep: points per second of equilibrium sweeps (towstab/sweep.h),
 * on one thread and on two (the parallel efficiency: rate on 2 threads /
 * (2 x rate on 1)), and what continuation saves: the same sweep with
 * every point from a cold start (chain 1) against chains of 8 that start
 * each point from its neighbour's equilibrium. Cases: Kamman example 1 at
 * 100 links over the turn rate, 0 to V / (0.6 L) in 32 steps (shooting
 * with its turn-rate schedule when cold); the same cable at 40 links with
 * bending stiffness EI = 50 N m^2 over the tow speed, 1.5 to 4.5 m/s in
 * 16 steps (Newton with continuation in turn rate and bending when
 * cold). Without the discretisation estimate (the equilibrium sweep
 * itself), and once with it (chain 8, one thread: its two coarser runs
 * per point start cold). Median of 3 runs of each sweep; each run
 * allocates and runs the whole sweep. */
#include "bench_common.h"
#include "towstab/sweep.h"

#ifdef _OPENMP
#include <omp.h>
#endif

typedef struct timing {
    double wall;     /* s, median */
    long evals;      /* kernel evaluations of the whole sweep */
    int ok;          /* every point converged */
} timing;

static timing time_sweep(const ts_system *sys, const char *path,
                         const double *v, int n, int chain, int threads,
                         int estimate)
{
    timing t = {0, 0, 1};
    double w[3];
    for (int r = 0; r < 3; r++) {
        ts_sweep_spec sp;
        memset(&sp, 0, sizeof sp);
        ts_request_init(&sp.rq, TS_ANALYSIS_EQUILIBRIUM);
        sp.rq.setup.discretisation_error = estimate;
        sp.naxes = 1;
        snprintf(sp.axes[0].path, sizeof sp.axes[0].path, "%s", path);
        sp.axes[0].n = n;
        sp.axes[0].values = (double *)v;
        sp.chain = chain;
        sp.threads = threads;
        double t0 = bench_now();
        ts_sweep *s = ts_sweep_alloc(sys, &sp, NULL);
        int rc = s ? ts_sweep_run(s, 0, 1, NULL) : TS_ENOMEM;
        w[r] = bench_now() - t0;
        if (s) {
            ts_sweep_finish(s);
            t.evals = s->evaluations;
            for (int p = 0; p < s->npoints; p++)
                t.ok &= s->points[p].status == TS_OK;
        }
        t.ok &= rc == TS_OK;
        ts_sweep_free(s);
    }
    t.wall = bench_median(w, 3);
    return t;
}

static int bench_case(const char *label, const ts_system *sys,
                      const char *path, const double *v, int n)
{
    timing cold = time_sweep(sys, path, v, n, 1, 1, 0);
    timing warm1 = time_sweep(sys, path, v, n, 8, 1, 0);
    timing warm2 = time_sweep(sys, path, v, n, 8, 2, 0);
    timing est = time_sweep(sys, path, v, n, 8, 1, 1);
    printf("%-34s %6d %6s %7s %8s %10s %9s %11s\n", label, n, "chain",
           "threads", "estimate", "wall [ms]", "points/s", "evaluations");
    const timing *t[4] = {&cold, &warm1, &warm2, &est};
    static const int ch[4] = {1, 8, 8, 8}, th[4] = {1, 1, 2, 1};
    for (int k = 0; k < 4; k++)
        printf("%-34s %6s %6d %7d %8s %10.2f %9.1f %11ld%s\n", "", "", ch[k],
               th[k], k == 3 ? "yes" : "no", t[k]->wall * 1e3,
               n / t[k]->wall, t[k]->evals,
               t[k]->ok ? "" : "  (a point FAILED)");
    printf("%-34s continuation: %.2fx fewer evaluations, %.2fx faster; "
           "2 threads: efficiency %.2f; the discretisation estimate "
           "(2 coarser runs per point) costs %.2fx\n\n",
           "", (double)cold.evals / (double)warm1.evals,
           cold.wall / warm1.wall, warm1.wall / (2.0 * warm2.wall),
           est.wall / warm1.wall);
    return cold.ok && warm1.ok && warm2.ok && est.ok ? 0 : 1;
}

int main(void)
{
    int cores = 1;
#ifdef _OPENMP
    cores = omp_get_num_procs();
#endif
    printf("bench_sweep: %d processors\n\n", cores);
    int bad = 0;
    ts_system *s = bench_kamman_ex1(100, 0.0);
    double V = s->tow.speed, L = s->cables[0].length, w[32], v[16];
    for (int i = 0; i < 32; i++)
        w[i] = V / (0.6 * L) * i / 31.0;
    bad |= bench_case("ex1, 100 links, turn rate", s, "tow.turn_rate", w,
                      32);
    ts_system_free(s);
    s = bench_kamman_ex1(40, 0.0);
    s->cables[0].ei = 50.0;
    ts_system_build(s, NULL);
    for (int i = 0; i < 16; i++)
        v[i] = 1.5 + 3.0 * i / 15.0;
    bad |= bench_case("ex1, 40 links, EI 50 N m^2, speed", s, "tow.speed", v,
                      16);
    ts_system_free(s);
    return bad;
}
