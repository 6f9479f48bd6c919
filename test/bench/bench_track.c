/* bench_track.c: the cost of the earth-frame track (lib/track.c) that
 * every simulation computes after its run, per output sample, beside the
 * simulation's own cost per sample (doc/performance.md, "Time-domain
 * simulation").
 *
 * Cases over 1000 s sampled every 0.1 s (10001 samples): a steady turn
 * (no excitation), a ramped turn rate with a speed step (the quadrature
 * cut at their four breakpoints). Each figure is the median of 7 runs.
 * Then Kamman's example 3 (examples/kamman_ex3_into_turn.yaml, 20 links,
 * rk8pd, rtol 1e-6) simulated for 30 s sampled every 0.1 s: the
 * simulation's wall time per sample against the track's.
 * Run from the project root: meson test -C build --benchmark track. */
#include <stdio.h>
#include <stdlib.h>

#include "bench_common.h"
#include "towstab/analysis.h"
#include "towstab/scene.h"
#include "towstab/track.h"

#define NSAMPLES 10001
#define REPEAT 7

/* Median wall time of the poses (s); *cpu the median process CPU time
 * (on a loaded machine the wall time includes waiting). */
static double time_poses(const ts_excitation *ex, const ts_frame *base,
                         const double *t, double *pose, double *cpu)
{
    double w[REPEAT], c[REPEAT];
    for (int r = 0; r < REPEAT; r++) {
        double t0 = bench_now(), c0 = tsi_cpu_now();
        if (ts_track_poses(ex, base, NSAMPLES, t, pose, NULL) != TS_OK)
            return NAN;
        w[r] = bench_now() - t0;
        c[r] = tsi_cpu_now() - c0;
    }
    *cpu = bench_median(c, REPEAT);
    return bench_median(w, REPEAT);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    double *t = malloc(NSAMPLES * sizeof *t);
    double *pose = malloc(3 * NSAMPLES * sizeof *pose);
    ts_excitation *ex = ts_excitation_alloc(&err);
    if (!u || !t || !pose || !ex)
        return 1;
    for (int i = 0; i < NSAMPLES; i++)
        t[i] = 0.1 * i;
    ts_frame base = {0};
    base.speed = 2.5;
    base.turn_rate = 0.05;
    double cs, cm;
    double steady = time_poses(NULL, &base, t, pose, &cs);
    ts_excitation_parse(ex, "turn_rate:ramp,to=0.1rad/s,start=10,duration=20",
                        u, "bench", &err);
    ts_excitation_parse(ex, "speed:step,by=1,start=100,rise=5", u, "bench",
                        &err);
    double man = time_poses(ex, &base, t, pose, &cm);
    printf("track of %d samples (median of %d runs):\n", NSAMPLES, REPEAT);
    printf("  steady turn                  wall %8.3f ms  cpu %8.3f ms  "
           "%6.2f us/sample (cpu)\n", 1e3 * steady, 1e3 * cs,
           1e6 * cs / NSAMPLES);
    printf("  ramped turn and speed step   wall %8.3f ms  cpu %8.3f ms  "
           "%6.2f us/sample (cpu)\n", 1e3 * man, 1e3 * cm,
           1e6 * cm / NSAMPLES);

    ts_scene *sc = ts_scene_load("examples/kamman_ex3_into_turn.yaml", u,
                                 &err);
    if (!sc) {
        printf("%s\n", err.msg);
        return 1;
    }
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    rq.setup.links = 20;
    rq.simulate.sim.t_end = 30;
    rq.simulate.sim.dt_sample = 0.1;
    rq.simulate.excitation = ts_excitation_alloc(&err);
    ts_excitation_parse(rq.simulate.excitation,
                        "turn_rate:to=0.5rad/s,duration=1s", u, "bench",
                        &err);
    double w[REPEAT], c[REPEAT];
    int n = 0;
    for (int r = 0; r < REPEAT; r++) {
        ts_result *res = NULL;
        double t0 = bench_now(), c0 = tsi_cpu_now();
        int rc = ts_analysis_run(sc->system, &rq, &res, &err);
        w[r] = bench_now() - t0;
        c[r] = tsi_cpu_now() - c0;
        if (rc == TS_OK && res->nonlinear)
            n = res->nonlinear->nsamples;
        ts_result_free(res);
        if (rc != TS_OK) {
            printf("simulate: %s\n", err.msg);
            return 1;
        }
    }
    double sim = bench_median(w, REPEAT), simc = bench_median(c, REPEAT);
    printf("kamman_ex3_into_turn, 20 links, 30 s, %d samples: simulate "
           "wall %.1f ms, cpu %.1f ms, %.1f us/sample (cpu); the track's "
           "share %.2f %%\n", n, 1e3 * sim, 1e3 * simc, 1e6 * simc / n,
           100.0 * (cm / NSAMPLES) / (simc / n));
    ts_request_clear(&rq);
    ts_scene_free(sc);
    ts_excitation_free(ex);
    free(t);
    free(pose);
    ts_units_free(u);
    return 0;
}
