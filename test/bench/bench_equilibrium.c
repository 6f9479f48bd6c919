/* bench_equilibrium: time to a converged equilibrium (relative force
 * residual <= 1e-10) of Kamman example 1 at 100 and 1000 links, straight
 * and in two turns (radius twice the cable length, Omega = V / (2 L), and
 * radius 0.6 L, shorter than the cable), and of example 3 (6 ft, 0.5 rad/s)
 * refined to 100 and 1000 links. Median of 9 runs, each from scratch.
 * Then the two-part tow with bending stiffness (examples/two_part_tow.yaml,
 * Newton from a coarser copy, doc/equilibrium.md) at 35 and 100 links a
 * cable: median of 3. */
#include "bench_common.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"

static int run_reps(const char *label, ts_system *sys, int reps)
{
    ts_kernel *k = ts_kernel_alloc(sys, NULL);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, NULL);
    if (!k || !eq)
        return 1;
    double t[9];
    int conv = 1;
    for (int r = 0; r < reps; r++) {
        ts_kernel_free(k);
        k = ts_kernel_alloc(sys, NULL);
        double t0 = bench_now();
        int rc = ts_equilibrium_solve(k, NULL, eq, NULL);
        t[r] = bench_now() - t0;
        conv &= rc == TS_OK && eq->converged;
    }
    printf("%-34s %6d %10.3f %9.2e %6d %6ld %s\n", label, sys->nlinks,
           bench_median(t, reps) * 1e3, eq->residual, eq->iterations,
           eq->evaluations, conv ? ts_eq_method_name(eq->method)
                                 : "NOT CONVERGED");
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return conv ? 0 : 1;
}

static int run(const char *label, ts_system *sys)
{
    return run_reps(label, sys, 9);
}

/* Kamman example 3: 6 ft of 0.163 in cable, 0.008979 lbf/ft, 2 in sphere
 * of 0.246 lbf, 2.5 ft/s, turn rate 0.5 rad/s. */
static ts_system *kamman_ex3(int n)
{
    const double ft = 0.3048, in = 0.0254, lbf = 4.4482216152605;
    ts_system *s = bench_kamman_ex1(n, 0.5);
    double g = s->env.gravity;
    s->tow.speed = 2.5 * ft;
    s->cables[0].length = 6 * ft;
    s->cables[0].diameter = 0.163 * in;
    s->cables[0].mass_per_length = 0.008979 * lbf / ft / g;
    s->bodies[0].diameter = 2 * in;
    s->bodies[0].mass = 0.246 * lbf / g;
    ts_system_build(s, NULL);
    return s;
}

int main(void)
{
    printf("%-34s %6s %10s %9s %6s %6s %s\n", "case", "links", "ms",
           "residual", "iter", "evals", "method");
    int bad = 0;
    static const int sizes[] = {100, 1000};
    for (int i = 0; i < 2; i++) {
        int n = sizes[i];
        ts_system *s = bench_kamman_ex1(n, 0.0);
        double V = s->tow.speed, L = s->cables[0].length;
        bad |= run("ex1 straight", s);
        s->tow.turn_rate = V / (2 * L);
        bad |= run("ex1 turn, radius 2 L", s);
        s->tow.turn_rate = V / (0.6 * L);
        bad |= run("ex1 turn, radius 0.6 L", s);
        ts_system_free(s);
        s = kamman_ex3(n);
        bad |= run("ex3 turn 0.5 rad/s", s);
        ts_system_free(s);
    }
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = u ? ts_scene_load("examples/two_part_tow.yaml", u, &err)
                     : NULL;
    static const int per_cable[] = {35, 100};
    for (int i = 0; sc && i < 2; i++) {
        if (ts_system_set_links(sc->system, per_cable[i], &err) != TS_OK)
            break;
        bad |= run_reps("two-part tow, bending", sc->system, 3);
    }
    if (!sc || err.code) {
        printf("two-part tow: %s\n", err.msg);
        bad = 1;
    }
    ts_scene_free(sc);
    ts_units_free(u);
    return bad;
}
