/* bench_elastic_sim.c: simulated seconds per wall second of the simulator
 * on a stiff elastic cable (doc/performance.md, "Elastic cables").
 *
 * Case: Kamman example 1 elastic (examples/kamman_ex1_elastic.yaml: 100 ft
 * of 1 in cable, EA = 1e9 N, Cv = 4000 N s/m, 10 in sphere, 8.345 ft/s) at
 * 100 links, from the equilibrium, the tow point heaved 0.1 ft at 0.25 Hz
 * (a sine: its velocity starts at once, which rings the axial modes), over
 * T_END simulated seconds, output every 0.1 s, relative tolerance 1e-6.
 * Integrators: msbdf (implicit BDF, Jacobian by the linearizer) and rk8pd
 * (explicit), each with the default absolute tolerance 1e-9 and with 1e-6
 * (the axial ringing has strain rates of ~1e-7 1/s: a 1e-9 tolerance makes
 * every integrator resolve it; doc/elastic.md section 7). A run stops at
 * the first output time after WALL_BUDGET wall seconds; the figure is the
 * simulated time reached over the wall time of the integration (the
 * equilibrium is solved once, before). Target (issue 5): at least 1
 * simulated second per wall second at 100 links, EA = 1e9 N (a widely used
 * code: 3.2 wall seconds per simulated second).
 * Run from the project root: meson test -C build --benchmark elastic_sim. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "towstab/equilibrium.h"
#include "towstab/excitation.h"
#include "towstab/scene.h"
#include "towstab/simulate.h"
#include "towstab/units.h"

#define T_END 10.0
#define WALL_BUDGET 10.0
#define TARGET 1.0

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = u ? ts_scene_load("examples/kamman_ex1_elastic.yaml", u,
                                     &err) : NULL;
    if (!sc) {
        fprintf(stderr, "bench_elastic_sim: %s\n", err.msg);
        return 1;
    }
    ts_system *s = sc->system;
    s->cables[0].nlinks = 100;
    if (ts_system_build(s, &err)) {
        fprintf(stderr, "bench_elastic_sim: %s\n", err.msg);
        return 1;
    }
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    if (!k || !eq || ts_equilibrium_solve(k, &eo, eq, &err)) {
        fprintf(stderr, "bench_elastic_sim: equilibrium: %s\n", err.msg);
        return 1;
    }
    typedef struct bcase {
        const char *excite;
        ts_integrator m;
        double rtol, atol;
    } bcase;
    const char *sine = "tow.heave:amplitude=0.1ft,frequency=0.25Hz";
    const char *step = "tow.heave:type=step,amplitude=0.1ft,rise=1s";
    const bcase cases[] = {
        {step, TS_INT_MSBDF, 1e-6, 1e-6}, {step, TS_INT_RK8PD, 1e-6, 1e-9},
        {sine, TS_INT_MSBDF, 1e-4, 1e-3}, {sine, TS_INT_MSBDF, 1e-6, 1e-6},
        {sine, TS_INT_RK8PD, 1e-6, 1e-9}};
    printf("Kamman ex. 1 elastic, 100 links (%d states), EA %.3g N, "
           "Cv %.0f N s/m, tow point at the surface\n", ts_kernel_nstate(k),
           s->cables[0].ea, s->cables[0].damping);
    printf("%-44s %-6s %-6s %-6s %9s %8s %8s %5s %8s %10s\n", "excitation",
           "method", "rtol", "atol", "t reached", "steps", "rejected",
           "jac", "wall [s]", "sim s/wall");
    double best_implicit = 0;
    int fails = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        ts_excitation *ex = ts_excitation_alloc(&err);
        ts_excitation_parse(ex, cases[c].excite, u, "bench", &err);
        ts_sim_opts o;
        ts_sim_opts_default(&o);
        o.integrator = cases[c].m;
        o.t_end = T_END;
        o.dt_sample = 0.1;
        o.rel_tol = cases[c].rtol;
        o.abs_tol = cases[c].atol;
        ts_sim *sim = ts_sim_alloc(k, ex, &o, &err);
        int rc = sim ? ts_sim_set_state(sim, 0.0, eq->y, &err) : 1;
        ts_sim_stats st;
        for (int i = 1; !rc && i < ts_sim_nsamples(&o); i++) {
            rc = ts_sim_advance(sim, ts_sim_sample_time(&o, i), &err);
            ts_sim_get_stats(sim, &st);
            if (st.wall_s > WALL_BUDGET)
                break;
        }
        ts_sim_get_stats(sim, &st);
        double ratio = st.t_reached / st.wall_s;
        printf("%-44s %-6s %-6.0e %-6.0e %9.2f %8ld %8ld %5ld %8.2f %10.4g%s\n",
               cases[c].excite, ts_integrator_name(cases[c].m), cases[c].rtol,
               cases[c].atol, st.t_reached, st.steps, st.rejected,
               st.jacobians, st.wall_s, ratio, rc ? " (failed)" : "");
        if (rc) {
            printf("  %s\n", err.msg);
            fails++;
        }
        if (cases[c].m == TS_INT_MSBDF && !rc && st.t_reached >= T_END &&
            ratio > best_implicit)
            best_implicit = ratio;
        ts_sim_free(sim);
        ts_excitation_free(ex);
    }
    printf("target: implicit >= %g simulated s per wall s: %s (%.3g)\n",
           TARGET, best_implicit >= TARGET ? "met" : "NOT met",
           best_implicit);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
    ts_units_free(u);
    return fails || best_implicit < TARGET;
}
