/* bench_sparse.c: the analyses in O(links) (doc/performance.md, "Long
 * cables"; doc/linear.md section 2b). Cases, through the library's
 * analysis pipeline (ts_analysis_run, as `towstab` runs them, without the
 * discretisation estimate):
 *  - modes: examples/kamman_ex1_submerged.yaml with 1000 and 10 000
 *    links: equilibrium, sparse linearization, ARPACK's 20 lowest modes
 *    and the rightmost search of the whole spectrum (the verdict);
 *  - response: the same cable, sphere.z to tow.heave at 100 frequencies
 *    (0.01 to 10 Hz, the default), without the natural frequencies;
 *  - vehicle modes and response: examples/aurora_towfish.yaml (a towed
 *    vehicle with lagged control surfaces and a PID depth loop in the
 *    sparse model) at 100, 1000 and 10 000 links: modes as above (20
 *    modes, ARPACK at every size; the loop margins left out), and
 *    aurora.depth to aurora.wing at 100 frequencies;
 *  - towing response: examples/dolphin_aurora.yaml (a towing vehicle at
 *    the root, which tows the AURORA towfish) at 100 and 1000 links,
 *    aurora.z to tow.heave at 100 frequencies, with the sparse model
 *    (the default) and with the dense one (TS_LIN_DENSE: how such a
 *    scene ran before the sparse model covered a towing vehicle);
 *  - esdirk: examples/kamman_ex1_elastic.yaml (EA 1e9 N) with 100 and 500
 *    links, heaved 0.1 ft at 0.25 Hz (smooth start over two periods, the
 *    default) for T_SIM simulated seconds, rtol 1e-6, atol 1e-9: wall
 *    seconds of the integration per simulated second;
 *  - linear simulation: examples/kamman_ex1_submerged.yaml with 1000 and
 *    10 000 links, the linear model alone (`simulate --linear`, the
 *    default method: above 1200 states esdirk on the sparse model) heaved
 *    as esdirk's case for T_SIM simulated seconds, sampled every 0.1 s:
 *    wall seconds of the linear integration per simulated second, and
 *    the whole analysis's.
 * Each case runs in a child process, so that its peak memory (the child's
 * maximum resident set, getrusage) is its own; the figure is the median
 * of REPS runs (peak: the largest). Targets (issue: stability, response
 * and stiff simulation in O(links)): modes and response < 0.1 s at 1000
 * links, < 1 s at 10 000, growth < 15x; peak memory of modes < 50 MB and
 * < 300 MB; esdirk <= 1.5 wall s per simulated s at 500 links, growth
 * from 100 to 500 links < 8x. The targets are reported, met or missed; the
 * program fails only when an analysis fails.
 * OpenBLAS on one thread, as towstab runs it (tools/towstab.c): meson
 * sets OPENBLAS_NUM_THREADS=1 for it. glibc's allocator as towstab sets
 * it (tools/malloc_policy.h), before the children are forked.
 * Run from the project root: meson test -C build --benchmark sparse, or
 * OPENBLAS_NUM_THREADS=1 build/test/bench_sparse [REPS
 * [vehicle|towing|linear|modes]] (vehicle: the towed vehicle cases only;
 * towing: the towing vehicle's only; linear: the linear simulation's
 * only; modes: Kamman's cable's modes only). */
#define _GNU_SOURCE /* wait4 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench_common.h"
#include "malloc_policy.h"
#include "towstab/analysis.h"
#include "towstab/excitation.h"
#include "towstab/scene.h"
#include "towstab/units.h"

#define REPS 3
#define T_SIM 2.0

enum { MODES, RESPONSE, ESDIRK, VMODES, VRESPONSE, TRESPONSE, TDENSE,
       LINSIM };

/* What a child reports back through its pipe. */
typedef struct figures {
    int ok;
    double wall, eq, lin, eig;    /* s */
    double per_sim;               /* esdirk, linear: wall s per
                                     simulated s */
    int sparse;                   /* linear: ran on the sparse model */
    double rightmost, top_hz;     /* modes */
    int nmodes, shifts, complete; /* modes */
    long steps;                   /* esdirk */
    char msg[TS_ERR_MSG_MAX];
} figures;

static void run_case(int kind, int links, figures *f)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    int veh = kind == VMODES || kind == VRESPONSE;
    int tow = kind == TRESPONSE || kind == TDENSE;
    const char *path = kind == ESDIRK ? "examples/kamman_ex1_elastic.yaml"
                       : veh          ? "examples/aurora_towfish.yaml"
                       : tow          ? "examples/dolphin_aurora.yaml"
                                      : "examples/kamman_ex1_submerged.yaml";
    ts_scene *sc = u ? ts_scene_load(path, u, &err) : NULL;
    if (!sc) {
        snprintf(f->msg, sizeof f->msg, "%s", err.msg);
        return;
    }
    ts_request rq;
    ts_request_init(&rq, kind == MODES || kind == VMODES ? TS_ANALYSIS_MODES
                         : kind == RESPONSE || kind == VRESPONSE || tow
                             ? TS_ANALYSIS_RESPONSE
                             : TS_ANALYSIS_SIMULATE);
    rq.setup.links = links;
    rq.setup.discretisation_error = 0;
    if (kind == RESPONSE || kind == VRESPONSE) {
        snprintf(rq.response.output, sizeof rq.response.output, "%s",
                 veh ? "aurora.depth" : "sphere.z");
        if (veh)
            snprintf(rq.response.input, sizeof rq.response.input,
                     "aurora.wing");
        rq.response.natural = 0;
    }
    if (tow) {
        snprintf(rq.response.output, sizeof rq.response.output, "aurora.z");
        snprintf(rq.response.input, sizeof rq.response.input, "tow.heave");
        rq.response.natural = 0;
        if (kind == TDENSE)
            rq.modes.linearize.model = TS_LIN_DENSE;
    }
    if (kind == VMODES) {
        rq.modes.margins = 0;
        rq.modes.count = 20; /* ARPACK at every size, as at 10 000 */
        rq.modes.eigen.method = TS_EIG_ARPACK;
    }
    if (kind == ESDIRK || kind == LINSIM) {
        ts_sim_opts *o = &rq.simulate.sim;
        if (kind == ESDIRK)
            o->integrator = TS_INT_ESDIRK;
        o->t_end = T_SIM;
        o->dt_sample = 0.1;
        o->rel_tol = 1e-6;
        o->abs_tol = 1e-9;
        rq.simulate.linear = kind == LINSIM;
        rq.simulate.compare = 0;
        rq.simulate.check_window = 0;
        rq.simulate.excitation = ts_excitation_alloc(&err);
        if (!rq.simulate.excitation ||
            ts_excitation_parse(rq.simulate.excitation,
                                "tow.heave:amplitude=0.1ft,frequency=0.25Hz",
                                u, "bench", &err) != TS_OK) {
            snprintf(f->msg, sizeof f->msg, "%s", err.msg);
            return;
        }
    }
    ts_result *r = NULL;
    double t0 = bench_now();
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    f->wall = bench_now() - t0;
    if (rc != TS_OK || !r || r->status != TS_OK) {
        snprintf(f->msg, sizeof f->msg, "%s",
                 r && r->error[0] ? r->error : err.msg);
    } else {
        f->ok = 1;
        f->eq = r->eq_wall_s;
        f->lin = r->lin_wall_s;
        f->eig = r->eigen_wall_s;
        if (r->eigen) {
            f->rightmost = r->eigen->max_real;
            f->top_hz = r->eigen->top_hz;
            f->nmodes = r->eigen->nmodes;
            f->shifts = r->eigen->sweep_shifts;
            f->complete = r->eigen->complete;
        }
        if (kind == ESDIRK || kind == LINSIM) {
            const ts_sim_stats *st = kind == ESDIRK ? &r->nonlinear_stats
                                                    : &r->linear_stats;
            f->steps = st->steps;
            f->per_sim = st->wall_s / st->t_reached;
            f->sparse = st->newton == TS_NEWTON_SPARSE;
        }
    }
    ts_result_free(r);
    ts_request_clear(&rq);
    ts_scene_free(sc);
    ts_units_free(u);
}

/* One case in a child: its figures and its peak memory (MB). */
static int run_child(int kind, int links, figures *f, double *peak_mb,
                     double *cpu_s)
{
    int fd[2];
    memset(f, 0, sizeof *f);
    if (pipe(fd) != 0)
        return -1;
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fd[0]);
        figures g = {0};
        run_case(kind, links, &g);
        ssize_t w = write(fd[1], &g, sizeof g);
        _exit(w == (ssize_t)sizeof g ? 0 : 1);
    }
    close(fd[1]);
    ssize_t got = read(fd[0], f, sizeof *f);
    close(fd[0]);
    int status = 0;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) < 0 || got != (ssize_t)sizeof *f)
        return -1;
    *peak_mb = ru.ru_maxrss / 1024.0;
    *cpu_s = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
             (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? 0 : -1;
}

static int failures;

/* The median of reps runs of a case; returns the median of `wall` (or of
 * per_sim for esdirk), the largest peak and the median CPU time of the
 * child (all threads; it includes loading the scene). */
static double measure(int kind, int links, int reps, figures *last,
                      double *peak, double *cpu)
{
    double v[16], c[16];
    int n = 0;
    *peak = 0;
    for (int r = 0; r < reps && r < 16; r++) {
        double p;
        if (run_child(kind, links, last, &p, &c[n]) != 0 || !last->ok) {
            static const char *const names[] = {
                "modes",           "response",        "esdirk",
                "vehicle modes",   "vehicle response", "towing response",
                "towing dense",    "linear simulation"};
            printf("FAIL %s at %d links: %s\n", names[kind], links,
                   last->msg[0] ? last->msg : "child failed");
            failures++;
            return NAN;
        }
        v[n++] = kind == ESDIRK || kind == LINSIM ? last->per_sim
                                                  : last->wall;
        *peak = fmax(*peak, p);
    }
    *cpu = bench_median(c, n);
    return bench_median(v, n);
}

static const char *met(int ok)
{
    return ok ? "met" : "MISSED";
}

int main(int argc, char **argv)
{
    towstab_malloc_policy();
    int reps = argc > 1 ? atoi(argv[1]) : REPS;
    int only_vehicle = argc > 2 && strcmp(argv[2], "vehicle") == 0;
    int only_towing = argc > 2 && strcmp(argv[2], "towing") == 0;
    int only_linear = argc > 2 && strcmp(argv[2], "linear") == 0;
    int only_modes = argc > 2 && strcmp(argv[2], "modes") == 0;
    if (reps < 1)
        reps = 1;
    figures f;
    double t[2] = {NAN, NAN}, mem[2], cpu;
    const int sizes[2] = {1000, 10000};
    printf("medians of %d runs; wall s of the whole analysis (equilibrium, "
           "linearization, solve)\n", reps);
    for (int i = 0; i < 2 && (only_linear || argc <= 2); i++) {
        t[i] = measure(LINSIM, sizes[i], reps, &f, &mem[i], &cpu);
        if (isnan(t[i]))
            continue;
        printf("linear simulation %5d links: %.3f wall s per simulated s "
               "(%ld steps over %g s, %s; the whole analysis %.3f s: "
               "equilibrium %.3f, linearize %.3f; process CPU %.3f s), "
               "peak %.0f MB\n",
               sizes[i], t[i], f.steps, T_SIM,
               f.sparse ? "esdirk on the sparse model" : "the dense model",
               f.wall, f.eq, f.lin, cpu, mem[i]);
    }
    if (only_linear) {
        if (!isnan(t[0]) && !isnan(t[1]))
            printf("linear simulation growth 1000 -> 10000: %.1fx time, "
                   "%.1fx memory\n", t[1] / t[0], mem[1] / mem[0]);
        printf("%d failed\n", failures);
        return failures ? 1 : 0;
    }
    for (int i = 0; i < 2 && !only_vehicle && !only_towing; i++) {
        t[i] = measure(MODES, sizes[i], reps, &f, &mem[i], &cpu);
        if (isnan(t[i]))
            continue;
        printf("modes    %5d links: %.3f s (equilibrium %.3f, linearize "
               "%.3f, eigen %.3f; CPU %.3f s), peak %.0f MB; %d modes, rightmost "
               "search %d shifts to %.4g Hz, max Re %.3g 1/s%s; target "
               "< %g s %s, < %g MB %s\n",
               sizes[i], t[i], f.eq, f.lin, f.eig, cpu, mem[i], f.nmodes,
               f.shifts, f.top_hz, f.rightmost,
               f.complete ? " (complete)" : "", i ? 1.0 : 0.1,
               met(t[i] < (i ? 1.0 : 0.1)), i ? 300.0 : 50.0,
               met(mem[i] < (i ? 300.0 : 50.0)));
    }
    if (!only_vehicle && !isnan(t[0]) && !isnan(t[1]))
        printf("modes    growth 1000 -> 10000: %.1fx time, %.1fx memory; "
               "target < 15x %s\n", t[1] / t[0], mem[1] / mem[0],
               met(t[1] / t[0] < 15 && mem[1] / mem[0] < 15));
    if (only_modes) {
        printf("%d failed\n", failures);
        return failures ? 1 : 0;
    }
    for (int i = 0; i < 2 && !only_vehicle && !only_towing; i++) {
        t[i] = measure(RESPONSE, sizes[i], reps, &f, &mem[i], &cpu);
        if (isnan(t[i]))
            continue;
        printf("response %5d links: %.3f s (equilibrium %.3f, linearize "
               "%.3f, 100 frequencies %.3f; CPU %.3f s), peak %.0f MB; "
               "target < %g s "
               "%s\n",
               sizes[i], t[i], f.eq, f.lin, t[i] - f.eq - f.lin, cpu, mem[i],
               i ? 1.0 : 0.1, met(t[i] < (i ? 1.0 : 0.1)));
    }
    if (!only_vehicle && !isnan(t[0]) && !isnan(t[1]))
        printf("response growth 1000 -> 10000: %.1fx; target < 15x %s\n",
               t[1] / t[0], met(t[1] / t[0] < 15));
    const int tsizes[2] = {100, 1000};
    for (int m = 0; m < 2 && !only_vehicle; m++)
        for (int i = 0; i < 2; i++) {
            int kind = m ? TDENSE : TRESPONSE;
            double tt = measure(kind, tsizes[i], reps, &f, &mem[0], &cpu);
            if (isnan(tt))
                continue;
            printf("towing response %s %5d links: %.3f s (equilibrium "
                   "%.3f, linearize %.3f, 100 frequencies %.3f; CPU %.3f "
                   "s), peak %.0f MB\n",
                   m ? "dense " : "sparse", tsizes[i], tt, f.eq, f.lin,
                   tt - f.eq - f.lin, cpu, mem[0]);
        }
    if (only_towing) {
        printf("%d failed\n", failures);
        return failures ? 1 : 0;
    }
    const int vsizes[3] = {100, 1000, 10000};
    double tv[3];
    for (int i = 0; i < 3; i++) {
        tv[i] = measure(VMODES, vsizes[i], reps, &f, &mem[0], &cpu);
        if (isnan(tv[i]))
            continue;
        printf("vehicle modes    %5d links: %.3f s (equilibrium %.3f, "
               "linearize %.3f, eigen %.3f; CPU %.3f s), peak %.0f MB; %d "
               "modes, rightmost search %d shifts to %.4g Hz, max Re %.3g "
               "1/s\n",
               vsizes[i], tv[i], f.eq, f.lin, f.eig, cpu, mem[0], f.nmodes,
               f.shifts, f.top_hz, f.rightmost);
    }
    if (!isnan(tv[1]) && !isnan(tv[2]))
        printf("vehicle modes    growth 1000 -> 10000: %.1fx\n",
               tv[2] / tv[1]);
    for (int i = 0; i < 3; i++) {
        tv[i] = measure(VRESPONSE, vsizes[i], reps, &f, &mem[0], &cpu);
        if (isnan(tv[i]))
            continue;
        printf("vehicle response %5d links: %.3f s (equilibrium %.3f, "
               "linearize %.3f, 100 frequencies %.3f; CPU %.3f s), peak "
               "%.0f MB\n",
               vsizes[i], tv[i], f.eq, f.lin, tv[i] - f.eq - f.lin, cpu,
               mem[0]);
    }
    if (!isnan(tv[1]) && !isnan(tv[2]))
        printf("vehicle response growth 1000 -> 10000: %.1fx\n",
               tv[2] / tv[1]);
    const int elastic[2] = {100, 500};
    for (int i = 0; i < 2 && !only_vehicle; i++) {
        t[i] = measure(ESDIRK, elastic[i], reps, &f, &mem[i], &cpu);
        if (isnan(t[i]))
            continue;
        printf("esdirk   %5d links (EA 1e9 N): %.3f wall s per simulated s "
               "(%ld steps over %g s; process CPU %.3f s), peak %.0f MB%s\n",
               elastic[i], t[i], f.steps, T_SIM, cpu, mem[i],
               i ? (t[i] <= 1.5 ? "; target <= 1.5 met"
                                : "; target <= 1.5 MISSED")
                 : "");
    }
    if (!only_vehicle && !isnan(t[0]) && !isnan(t[1]))
        printf("esdirk   growth 100 -> 500: %.1fx; target < 8x %s\n",
               t[1] / t[0], met(t[1] / t[0] < 8));
    printf("%d failed\n", failures);
    return failures ? 1 : 0;
}
