/* job_json_cost.c: what ts_job_json costs on a simulation's full state
 * (doc/performance.md, "Histories, force extremes, run and ts_job_json").
 * Not a test: it prints one line.
 *
 *   build/test/job_json_cost SCENE LINKS T_END
 *
 * runs `simulate` on SCENE at LINKS links to T_END with every output and
 * no discretisation error, then times the one call to ts_job_json: the
 * text's length, the call's CPU (user + system) and the process's peak
 * resident memory before and after the call. */
#include "towstab/job.h"
#include "towstab/scene.h"
#include "towstab/units.h"

#include <stdio.h>
#include <string.h>
#include <sys/resource.h>

static double cpu_s(long *peak_kib)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    *peak_kib = u.ru_maxrss;
    return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: job_json_cost SCENE LINKS T_END\n");
        return 2;
    }
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = u ? ts_scene_load(argv[1], u, &err) : NULL;
    ts_job *j = sc ? ts_job_alloc(sc, u, "simulate", -1, &err) : NULL;
    int rc = 1;
    if (j && ts_job_give(j, "links", argv[2], &err) == TS_OK &&
        ts_job_give(j, "t_end", argv[3], &err) == TS_OK &&
        ts_job_give(j, "outputs", "all", &err) == TS_OK &&
        ts_job_give(j, "discretisation_error", "false", &err) == TS_OK &&
        ts_job_run(j, &err) == TS_OK) {
        long before, after;
        double c0 = cpu_s(&before);
        const char *text = ts_job_json(j, 0, &err);
        double c1 = cpu_s(&after);
        if (text) {
            printf("ts_job_json: %zu bytes, CPU %.3f s, peak %.1f MiB "
                   "before the call, %.1f MiB after\n",
                   strlen(text), c1 - c0, before / 1024.0, after / 1024.0);
            rc = 0;
        }
    }
    if (rc)
        fprintf(stderr, "job_json_cost: %s\n", err.msg);
    ts_job_free(j);
    ts_scene_free(sc);
    ts_units_free(u);
    return rc;
}
