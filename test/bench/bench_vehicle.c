/* bench_vehicle: what a vehicle costs. The kernel f(y, u) at a fixed
 * state and the equilibrium solve (from scratch, relative residual
 * 1e-10) of Kamman's example-1 cable ending in a sphere
 * (examples/kamman_ex1_submerged.yaml) and in a towfish
 * (examples/kamman_ex1_vehicle.yaml), and of the controlled AURORA-like
 * towfish (examples/aurora_towfish.yaml: 5 control surfaces, 3 loops),
 * the kernel at 10 to 10000 links, the solve at 10 to 1000. The vehicle
 * adds O(1) work per kernel call: the difference to the sphere stays flat
 * as the links grow; its trim is shooting, O(links) per outer
 * iteration. Both also with a towing vehicle at the root
 * (examples/dolphin_aurora.yaml: DOLPHIN, 7 control surfaces and a depth
 * loop, towing the AURORA-like fish; its trim is shooting too, its
 * attitude, depth and speed among the outer unknowns). Medians of 9
 * kernel samples and of 3 solves. */
#include "bench_common.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"

/* One kernel evaluation (s) at a state of sys with every link at 0.3 rad
 * below the horizontal and small rates, the vehicles level (the cost
 * does not depend on the state). */
static double eval_time(const ts_system *sys)
{
    ts_kernel *k = ts_kernel_alloc(sys, NULL);
    int n = k ? ts_kernel_nstate(k) : 0, nq = k ? ts_kernel_nq(k) : 0;
    double *y = calloc((size_t)n + 1, sizeof(double));
    double *f = calloc((size_t)n + 1, sizeof(double));
    double t[9], med = NAN;
    if (k && y && f) {
        for (int l = 0; l < sys->nlinks; l++) {
            int o = ts_kernel_link_offset(k, l);
            y[o] = 0.3;
            y[nq + o + 1] = 0.01;
        }
        int calls = 200000 / (sys->nlinks + 10) + 1, ok = 1;
        for (int r = 0; r < 9; r++) {
            double t0 = bench_now();
            for (int c = 0; c < calls; c++)
                ok &= ts_kernel_eval(k, y, NULL, f) == TS_OK;
            t[r] = (bench_now() - t0) / calls;
        }
        med = ok ? bench_median(t, 9) : NAN;
    }
    free(y);
    free(f);
    ts_kernel_free(k);
    return med;
}

/* The equilibrium from scratch (s, median of 3; its CPU time in *cpu),
 * its iterations and method; NAN when it fails. */
static double solve_time(const ts_system *sys, int *iterations,
                         const char **method, double *cpu)
{
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, NULL);
    double t[3], c[3];
    int ok = eq != NULL;
    for (int r = 0; ok && r < 3; r++) {
        ts_kernel *k = ts_kernel_alloc(sys, NULL);
        double t0 = bench_now(), c0 = bench_cpu_now();
        ok &= k && ts_equilibrium_solve(k, NULL, eq, NULL) == TS_OK;
        t[r] = bench_now() - t0;
        c[r] = bench_cpu_now() - c0;
        ts_kernel_free(k);
    }
    *cpu = ok ? bench_median(c, 3) : NAN;
    *iterations = ok ? eq->iterations : 0;
    *method = ok && eq->method == TS_EQ_SHOOTING ? "shooting" : "newton";
    ts_equilibrium_free(eq);
    return ok ? bench_median(t, 3) : NAN;
}

/* sc's system at n links (NULL on failure). */
static ts_system *at_links(const ts_scene *sc, int n)
{
    ts_system *sys = ts_system_copy(sc->system, NULL);
    if (sys && ts_system_set_links(sys, n, NULL) != TS_OK) {
        ts_system_free(sys);
        sys = NULL;
    }
    return sys;
}

int main(void)
{
    enum { NSCENES = 4 };
    static const char *const scenes[NSCENES] = {
        "examples/kamman_ex1_submerged.yaml",
        "examples/kamman_ex1_vehicle.yaml", "examples/aurora_towfish.yaml",
        "examples/dolphin_aurora.yaml"};
    static const char *const labels[NSCENES] = {
        "ex1 + sphere", "ex1 + vehicle", "AURORA (3 loops)",
        "DOLPHIN + AURORA"};
    static const int ksizes[4] = {10, 100, 1000, 10000};
    static const int esizes[3] = {10, 100, 1000};
    setvbuf(stdout, NULL, _IOLBF, 0);
    ts_units *u = ts_units_alloc(NULL);
    ts_scene *sc[NSCENES] = {NULL, NULL, NULL, NULL};
    int bad = !u;
    for (int i = 0; i < NSCENES && u; i++) {
        sc[i] = ts_scene_load(scenes[i], u, NULL);
        bad |= !sc[i];
    }
    printf("%-18s %6s %12s %14s\n", "kernel", "links", "f(y,u) [us]",
           "per link [ns]");
    for (int s = 0; s < 4 && !bad; s++)
        for (int i = 0; i < NSCENES; i++) {
            ts_system *sys = at_links(sc[i], ksizes[s]);
            double te = sys ? eval_time(sys) : NAN;
            bad |= !isfinite(te);
            printf("%-18s %6d %12.3f %14.1f\n", labels[i], ksizes[s],
                   te * 1e6, te * 1e9 / ksizes[s]);
            ts_system_free(sys);
        }
    printf("\n%-18s %6s %12s %10s %6s  %s\n", "equilibrium", "links",
           "solve [ms]", "CPU [ms]", "iter", "method");
    for (int s = 0; s < 3 && !bad; s++)
        for (int i = 0; i < NSCENES; i++) {
            ts_system *sys = at_links(sc[i], esizes[s]);
            int it = 0;
            const char *method = "";
            double cpu = NAN;
            double ts = sys ? solve_time(sys, &it, &method, &cpu) : NAN;
            bad |= !isfinite(ts);
            printf("%-18s %6d %12.3f %10.3f %6d  %s\n", labels[i],
                   esizes[s], ts * 1e3, cpu * 1e3, it, method);
            ts_system_free(sys);
        }
    for (int i = 0; i < NSCENES; i++)
        ts_scene_free(sc[i]);
    ts_units_free(u);
    return bad;
}
