/* The command line's allocator policy (tools/towstab.c), shared with the
 * benchmarks that time analyses as `towstab` runs them (test/bench/
 * bench_sparse.c): glibc's allocator keeps freed memory for reuse up to
 * 256 MB per allocation and 512 MB at the heap's top. By default it maps
 * an allocation above a threshold (moving up to 32 MB) afresh and returns
 * it when freed, and trims the heap above twice that: a long cable's
 * eigen analysis allocates and frees arrays of tens of MB per ARPACK run
 * and per eigenvalue (the Arnoldi vectors, the Ritz vectors, the
 * factors), and every page of each was faulted in again. At 10 000
 * links: 53 600 page faults against 33 200 (peak memory 132 against 142
 * MB), doc/performance.md. A process-wide policy, so set by the program
 * and not by the library. */
#ifndef TOWSTAB_TOOLS_MALLOC_POLICY_H
#define TOWSTAB_TOOLS_MALLOC_POLICY_H

#ifdef __GLIBC__
#include <malloc.h>
#endif

static inline void towstab_malloc_policy(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}

#endif
