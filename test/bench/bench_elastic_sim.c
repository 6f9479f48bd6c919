/* bench_elastic_sim.c: simulated seconds per wall second of the simulator
 * on a stiff elastic cable, and the error each run makes (doc/
 * performance.md, "Elastic cables").
 *
 * Case: Kamman example 1 elastic (examples/kamman_ex1_elastic.yaml: 100 ft
 * of 1 in cable, EA = 1e9 N, Cv = 4000 N s/m, 10 in sphere, 8.345 ft/s) at
 * 100 links (600 states), from the equilibrium, T_END simulated seconds,
 * output every 0.1 s, under three tow-point heaves of 0.1 ft:
 *  - crank: slider crank, rod 0.35 ft, period 4 s (starts at rest; its
 *    acceleration jumps, which rings the axial modes a little);
 *  - step: quintic step over 1 s (displacement, velocity and acceleration
 *    continuous);
 *  - sine: 0.25 Hz (its velocity jumps at t = 0: a blow that rings the
 *    axial modes hard; the ringing is physics, tension oscillations of
 *    tens of N).
 * Integrators: esdirk (SUNDIALS ARKODE, L-stable ESDIRK 5(4)) at three
 * tolerances and rk8pd (explicit); GSL's msbdf resolves the axial ringing
 * at these tolerances and manages 0.001-0.005 simulated s per wall s (its
 * figures in doc/performance.md; left out here, where one of its outputs
 * can take minutes). A run stops at the first output time after
 * WALL_BUDGET wall seconds; the speed is the simulated time reached over
 * the wall time of the integration (the equilibrium is solved once,
 * before).
 *
 * Error: against a reference run of esdirk at rtol 1e-10, atol 1e-12 of
 * the same excitation, the largest distance of the sphere from the
 * reference's over the samples reached (m) and the largest difference of
 * the top tension (N). The reference is itself checked by rk8pd, an
 * independent method that resolves everything: its error column is its
 * distance from the reference over the samples it reaches.
 * Tension is EA e + Cv l e': an absolute tolerance atol on the strain e
 * lets the tension err by up to about EA atol (1000 N at atol 1e-6, 10 N
 * at 1e-8), so tension needs the smaller atol; positions do not.
 * Target (issue 5): at least 1 simulated second per wall second at 100
 * links, EA = 1e9 N (a widely used code: 3.2 wall seconds per simulated
 * second); met when esdirk at rtol 1e-6, atol 1e-8 does it on the smooth
 * heaves (crank, step) with the sphere within 1e-6 m and the top tension
 * within 1 N (0.3 % of its 329 N). The sine's blow is reported, not
 * judged: the ringing it starts is physics that accurate tensions must
 * resolve.
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
#define TARGET_ERR 1e-6 /* m, sphere position */
#define TARGET_TERR 1.0 /* N, top tension */

typedef struct result {
    ts_history *h;
    ts_sim_stats st;
    int rc;
    char msg[sizeof(((ts_err *)0)->msg)];
} result;

/* Run from y0 under ex with integrator m at (rtol, atol), stopping at the
 * first output after `budget` wall seconds. */
static result run(ts_kernel *k, const ts_excitation *ex, const double *y0,
                  ts_integrator m, double rtol, double atol, double budget)
{
    result r = {0};
    ts_err err = {0};
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.integrator = m;
    o.t_end = T_END;
    o.dt_sample = 0.1;
    o.rel_tol = rtol;
    o.abs_tol = atol;
    int N = ts_sim_nsamples(&o);
    r.h = ts_history_alloc(ts_kernel_system(k), N, &err);
    ts_sim *sim = r.h ? ts_sim_alloc(k, ex, &o, &err) : NULL;
    r.rc = sim ? ts_sim_set_state(sim, 0.0, y0, &err) : 1;
    if (!r.rc)
        r.rc = ts_sim_record(sim, r.h, &err);
    for (int i = 1; !r.rc && i < N; i++) {
        r.rc = ts_sim_advance(sim, ts_sim_sample_time(&o, i), &err);
        if (!r.rc)
            r.rc = ts_sim_record(sim, r.h, &err);
        ts_sim_get_stats(sim, &r.st);
        if (r.st.wall_s > budget)
            break;
    }
    if (sim)
        ts_sim_get_stats(sim, &r.st);
    snprintf(r.msg, sizeof r.msg, "%s", err.msg);
    ts_sim_free(sim);
    return r;
}

/* Largest sphere distance (m) and top-tension difference (N) of a from
 * ref over the samples both hold. */
static void errors(const result *a, const result *ref, double *dr, double *dt)
{
    int nn = a->h->nnodes, ns = a->h->nsamples < ref->h->nsamples
                                    ? a->h->nsamples : ref->h->nsamples;
    *dr = *dt = 0;
    for (int i = 0; i < ns; i++) {
        const double *p = a->h->positions + (size_t)(3 * nn) * i + 3 * (nn - 1);
        const double *q = ref->h->positions + (size_t)(3 * nn) * i +
                          3 * (nn - 1);
        double d = hypot(hypot(p[0] - q[0], p[1] - q[1]), p[2] - q[2]);
        *dr = fmax(*dr, d);
        *dt = fmax(*dt, fabs(a->h->tensions[(size_t)a->h->nlinks * i] -
                             ref->h->tensions[(size_t)ref->h->nlinks * i]));
    }
}

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
        ts_integrator m;
        double rtol, atol;
    } bcase;
    const char *excites[3][2] = {
        {"crank", "tow.heave:type=crank,amplitude=0.1ft,rod=0.35ft,"
                  "period=4s"},
        {"step", "tow.heave:type=step,amplitude=0.1ft,rise=1s"},
        {"sine", "tow.heave:amplitude=0.1ft,frequency=0.25Hz"}};
    const bcase cases[] = {
        {TS_INT_ESDIRK, 1e-6, 1e-6}, {TS_INT_ESDIRK, 1e-6, 1e-8},
        {TS_INT_ESDIRK, 1e-8, 1e-10}, {TS_INT_RK8PD, 1e-6, 1e-9}};
    printf("Kamman ex. 1 elastic, 100 links (%d states), EA %.3g N, "
           "Cv %.0f N s/m, tow point at the surface, %g s, output every "
           "0.1 s\n", ts_kernel_nstate(k), s->cables[0].ea,
           s->cables[0].damping, T_END);
    printf("%-6s %-6s %-6s %-6s %9s %7s %6s %5s %8s %10s %10s %10s\n",
           "heave", "method", "rtol", "atol", "t reached", "steps", "rej",
           "jac", "wall [s]", "sim s/wall", "sphere [m]", "T top [N]");
    double worst_speed = INFINITY, worst_err = 0, worst_terr = 0;
    int fails = 0;
    for (int e = 0; e < 3; e++) {
        ts_excitation *ex = ts_excitation_alloc(&err);
        if (ts_excitation_parse(ex, excites[e][1], u, "bench", &err)) {
            fprintf(stderr, "bench_elastic_sim: %s\n", err.msg);
            return 1;
        }
        result ref = run(k, ex, eq->y, TS_INT_ESDIRK, 1e-10, 1e-12,
                         INFINITY);
        printf("%-6s %-6s %-6.0e %-6.0e %9.2f %7ld %6ld %5ld %8.2f %10.4g "
               "%10s %10s%s\n", excites[e][0], "esdirk", 1e-10, 1e-12,
               ref.st.t_reached, ref.st.steps, ref.st.rejected,
               ref.st.jacobians, ref.st.wall_s,
               ref.st.t_reached / ref.st.wall_s, "reference", "",
               ref.rc ? " (failed)" : "");
        if (ref.rc) {
            printf("  %s\n", ref.msg);
            fails++;
        }
        for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
            result r = run(k, ex, eq->y, cases[c].m, cases[c].rtol,
                           cases[c].atol, WALL_BUDGET);
            double dr, dt;
            errors(&r, &ref, &dr, &dt);
            double speed = r.st.t_reached / r.st.wall_s;
            printf("%-6s %-6s %-6.0e %-6.0e %9.2f %7ld %6ld %5ld %8.2f "
                   "%10.4g %10.2e %10.2e%s\n", excites[e][0],
                   ts_integrator_name(cases[c].m), cases[c].rtol,
                   cases[c].atol, r.st.t_reached, r.st.steps, r.st.rejected,
                   r.st.jacobians, r.st.wall_s, speed, dr, dt,
                   r.rc ? " (failed)" : "");
            if (r.rc) {
                printf("  %s\n", r.msg);
                fails++;
            }
            if (e < 2 && cases[c].m == TS_INT_ESDIRK &&
                cases[c].rtol == 1e-6 && cases[c].atol == 1e-8) {
                if (r.rc || r.st.t_reached < T_END)
                    speed = 0;
                worst_speed = fmin(worst_speed, speed);
                worst_err = fmax(worst_err, dr);
                worst_terr = fmax(worst_terr, dt);
            }
            ts_history_free(r.h);
        }
        ts_history_free(ref.h);
        ts_excitation_free(ex);
    }
    int met = worst_speed >= TARGET && worst_err < TARGET_ERR &&
              worst_terr < TARGET_TERR;
    printf("target: esdirk at rtol 1e-6, atol 1e-8 >= %g simulated s per "
           "wall s with the sphere within %g m and the top tension within "
           "%g N on the crank and the step: %s (slowest %.3g, largest errors "
           "%.2e m, %.2e N)\n", TARGET, TARGET_ERR, TARGET_TERR,
           met ? "met" : "NOT met", worst_speed, worst_err, worst_terr);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
    ts_units_free(u);
    return fails || !met;
}
