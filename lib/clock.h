/* clock.h (private): the wall clock of run times and progress reports. */
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

#endif
