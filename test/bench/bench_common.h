/* bench_common.h: systems and timing shared by the benchmarks. Timing is
 * wall-clock (CLOCK_MONOTONIC); each figure is the median of repeated runs
 * so that a busy moment does not decide it. */
#ifndef TOWSTAB_BENCH_COMMON_H
#define TOWSTAB_BENCH_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "clock.h"
#include "towstab/system.h"

/* The library's wall clock (lib/clock.h). */
static inline double bench_now(void) { return tsi_wall_now(); }

/* The process's CPU time (s): under load, what a run itself cost. */
static inline double bench_cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int bench_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Kamman & Nguyen example 1 (examples/kamman_ex1_submerged.yaml) with
 * `nlinks` links: 100 ft of 1 in cable at 1 lbf/ft, 10 in sphere of 50 lbf,
 * 8.345 ft/s, Cdn 1.2, Cdt 0.01, Can 1.0, sphere Cd 0.5, Ca 0.5. */
static inline ts_system *bench_kamman_ex1(int nlinks, double turn_rate)
{
    const double ft = 0.3048, in = 0.0254, lbf = 4.4482216152605;
    const double g = 32.174 * ft;
    ts_system *s = ts_system_alloc(1, 1, NULL);
    if (!s)
        return NULL;
    snprintf(s->name, sizeof s->name, "kamman_ex1_%d", nlinks);
    s->env.water_density = 1.9905 * 14.59390293720636 / (ft * ft * ft);
    s->env.gravity = g;
    s->tow.speed = 8.345 * ft;
    s->tow.turn_rate = turn_rate;
    ts_cable *c = &s->cables[0];
    snprintf(c->name, sizeof c->name, "cable");
    c->from_body = -1;
    c->to_body = 0;
    c->length = 100 * ft;
    c->diameter = 1 * in;
    c->mass_per_length = lbf / ft / g;
    c->nlinks = nlinks;
    c->cdn = 1.2;
    c->cdt = 0.01;
    c->can = 1.0;
    ts_body *b = &s->bodies[0];
    snprintf(b->name, sizeof b->name, "sphere");
    b->type = TS_BODY_SPHERE;
    b->diameter = 10 * in;
    b->mass = 50 * lbf / g;
    b->cd = 0.5;
    b->ca = 0.5;
    if (ts_system_build(s, NULL) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

#endif
