/* startup_pairs.c: whole-process CPU of two commands, paired, to the
 * microsecond (doc/performance.md, "Start-up").
 *
 *     startup_pairs RUNS LABEL A [ARGS...] -- B [ARGS...]
 *
 * Runs A and B in turn (A B A B ...) RUNS times each after one unrecorded
 * run of each, with their output thrown away, and prints one table row:
 * LABEL, the median CPU of A and of B in milliseconds (user + system, as
 * wait4 returns them for the finished child: the kernel's own accounting,
 * to the microsecond), and the median of the RUNS ratios A/B taken pair by
 * pair (pairing keeps the ratio meaningful when the machine's load drifts
 * during the call), with the lower and upper quartiles of those ratios.
 * A command that does not start, or exits non-zero, ends the benchmark with
 * status 1: a figure for a command that failed would mean nothing. B may
 * be the same command as A, which measures the bench's own scatter (a ratio
 * near 1). Environment for one side goes through env(1):
 *     startup_pairs 101 x towstab --version -- env LD_PRELOAD=m.so towstab --version
 */
#define _GNU_SOURCE /* wait4 */
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

/* CPU seconds of one run of argv, or a negative value when it failed. */
static double run_cpu(char *const argv[])
{
    pid_t pid = fork();
    if (pid < 0)
        return -1.0;
    if (pid == 0) {
        int null = open("/dev/null", O_RDWR);
        if (null >= 0) {
            dup2(null, 0);
            dup2(null, 1);
            dup2(null, 2);
        }
        execvp(argv[0], argv);
        _exit(127);
    }
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid)
        return -1.0;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fprintf(stderr, "startup_pairs: %s exited with %s %d\n", argv[0],
                WIFEXITED(status) ? "status" : "signal",
                WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
        return -1.0;
    }
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile (0 <= q <= 1) of v[n], sorted in place: the nearest rank. */
static double quantile(double *v, int n, double q)
{
    qsort(v, (size_t)n, sizeof *v, by_value);
    int i = (int)(q * (n - 1) + 0.5);
    return v[i];
}

int main(int argc, char **argv)
{
    int split = 0;
    for (int i = 3; i < argc; i++)
        if (strcmp(argv[i], "--") == 0) {
            split = i;
            break;
        }
    int runs = argc > 1 ? atoi(argv[1]) : 0;
    if (argc < 6 || runs < 1 || split < 4 || split == argc - 1) {
        fprintf(stderr, "usage: startup_pairs RUNS LABEL A [ARGS...] -- B "
                        "[ARGS...]\n");
        return 2;
    }
    argv[split] = NULL;
    char **a = argv + 3, **b = argv + split + 1;
    double *ta = malloc(sizeof *ta * (size_t)runs);
    double *tb = malloc(sizeof *tb * (size_t)runs);
    double *ratio = malloc(sizeof *ratio * (size_t)runs);
    if (!ta || !tb || !ratio) {
        fprintf(stderr, "startup_pairs: out of memory\n");
        return 1;
    }
    if (run_cpu(a) < 0 || run_cpu(b) < 0)
        return 1;
    for (int i = 0; i < runs; i++) {
        ta[i] = run_cpu(a);
        tb[i] = run_cpu(b);
        if (ta[i] < 0 || tb[i] < 0)
            return 1;
        /* A process costs at least one microsecond of accounting. */
        ratio[i] = ta[i] / (tb[i] > 0 ? tb[i] : 1e-6);
    }
    double q1 = quantile(ratio, runs, 0.25), q3 = quantile(ratio, runs, 0.75);
    printf("| %s | %.3f | %.3f | %.3f (%.3f-%.3f) |\n", argv[2],
           1e3 * quantile(ta, runs, 0.5), 1e3 * quantile(tb, runs, 0.5),
           quantile(ratio, runs, 0.5), q1, q3);
    free(ta);
    free(tb);
    free(ratio);
    return 0;
}
