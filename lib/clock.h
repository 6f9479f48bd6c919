/* clock.h (private): the wall clock of run times and progress reports,
 * and the process's CPU clock (benchmarks). tools/ may include public
 * headers only (doc/architecture.md), so the command line keeps its own
 * cli_wall_now. */
#ifndef TOWSTAB_LIB_CLOCK_H
#define TOWSTAB_LIB_CLOCK_H

#include <time.h>

/* Seconds of a monotonic wall clock (differences only). */
static inline double tsi_wall_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Seconds of CPU time of the whole process, every thread (differences
 * only). */
static inline double tsi_cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

#endif
