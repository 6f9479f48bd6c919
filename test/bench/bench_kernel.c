/* bench_kernel: cost of one kernel evaluation f(y, u) against the number of
 * links (10, 100, 1000, 10000) on Kamman example 1 at its equilibrium-like
 * state with nonzero rates (added mass on: the 3x3 path). The cost per
 * link must stay flat: the kernel is O(links). */
#include "bench_common.h"
#include "towstab/kernel.h"

int main(void)
{
    static const int sizes[] = {10, 100, 1000, 10000};
    printf("%8s %14s %14s %12s\n", "links", "f(y,u) [us]", "per link [ns]",
           "calls");
    for (int s = 0; s < 4; s++) {
        int n = sizes[s];
        ts_system *sys = bench_kamman_ex1(n, 0.0);
        ts_kernel *k = sys ? ts_kernel_alloc(sys, NULL) : NULL;
        double *y = calloc(8 * (size_t)n, sizeof(double));
        double *f = calloc(8 * (size_t)n, sizeof(double));
        if (!k || !y || !f)
            return 1;
        for (int l = 0; l < n; l++) {
            y[2 * l] = 0.3 + 0.5 * l / n;    /* trailing, bending down */
            y[2 * l + 1] = 0.01 * sin(l);
            y[4 * n + 2 * l] = 0.02 * cos(l);
            y[4 * n + 2 * l + 1] = 0.01;
        }
        /* Calls per sample chosen for ~20 ms per sample. */
        int calls = 2000000 / n + 1;
        double t[9];
        for (int r = 0; r < 9; r++) {
            double t0 = bench_now();
            for (int c = 0; c < calls; c++)
                if (ts_kernel_eval(k, y, NULL, f) != TS_OK)
                    return 1;
            t[r] = (bench_now() - t0) / calls;
        }
        double med = bench_median(t, 9);
        printf("%8d %14.3f %14.1f %12d\n", n, med * 1e6, med * 1e9 / n, calls);
        free(y);
        free(f);
        ts_kernel_free(k);
        ts_system_free(sys);
    }
    return 0;
}
