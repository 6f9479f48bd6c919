/* The command line's allocator policy (tools/towstab.c), shared with the
 * benchmarks that time analyses as `towstab` runs them (test/bench/
 * bench_sparse.c). A process-wide policy, so set by the program, once,
 * before any thread starts, and not by the library (doc/performance.md,
 * "The command line's allocator" and "The heap on huge pages"):
 *  - glibc's allocator keeps freed memory for reuse, up to 256 MB per
 *    allocation and 512 MB at the heap's top. By default it maps an
 *    allocation above a threshold (moving up to 32 MB) afresh and returns
 *    it when freed, and trims the heap above twice that: a long cable's
 *    eigen analysis allocates and frees arrays of tens of MB per ARPACK
 *    run and per eigenvalue, and every page of each was faulted in again;
 *  - one arena: every thread (the linearization's, the modes' run beside
 *    the rightmost search, a sweep's points) allocates from the main heap,
 *    where glibc would give each thread a heap of its own, mapped apart;
 *  - the heap's next TOWSTAB_HEAP_HUGE bytes advised to the kernel as
 *    transparent huge pages (madvise MADV_HUGEPAGE): one fault per
 *    2 MiB of memory first written, where there were 512, wherever it
 *    is allocated (KLU's factors, ARPACK's work, the descriptor's
 *    arrays). Only address space is reserved: a page is backed when first
 *    written, as before. Memory beyond it, in another allocator (a
 *    sanitizer's), on a kernel without huge pages or under a limit of
 *    the address space or data segment (nothing reserved) stays as it
 *    was.
 *    A huge page is cleared whole when first written (2 MiB, where a
 *    small run writes little of it): the advised heap costs a
 *    20-link equilibrium nothing measurable (doc/performance.md).
 * Returns 1 when the heap was advised, 0 when not (the policy is advice:
 * the program runs the same either way). */
#ifndef TOWSTAB_TOOLS_MALLOC_POLICY_H
#define TOWSTAB_TOOLS_MALLOC_POLICY_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#ifdef __GLIBC__
#include <malloc.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>
#endif

/* The heap advised onto huge pages: more than a 10 000-link eigen
 * analysis's peak (about 200 MB with the libraries), below the mapping
 * threshold (an allocation of 256 MB or more is mapped apart). */
#define TOWSTAB_HEAP_HUGE ((size_t)240 << 20)
#define TOWSTAB_HUGE_PAGE ((uintptr_t)2 << 20)

#ifdef __GLIBC__
/* Whether the process's limit of resource (getrlimit) is infinite. */
static inline int towstab_unlimited(int resource)
{
    struct rlimit r;
    return getrlimit(resource, &r) == 0 && r.rlim_cur == RLIM_INFINITY;
}
#endif

static inline int towstab_malloc_policy(void)
{
    int advised = 0;
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 512 << 20);
    mallopt(M_ARENA_MAX, 1);
#ifdef MADV_HUGEPAGE
    /* The heap's top grown by TOWSTAB_HEAP_HUGE beyond a first block
     * (M_TOP_PAD, for that growth only), and the growth advised: the
     * block is freed to the top, from which later allocations are cut, and
     * the mapping keeps the advice. Nothing of the growth is written (not
     * even by MALLOC_PERTURB_, which fills the blocks given out), and
     * only when the heap's break moved by it (not mapped apart, not
     * another allocator's). The first block is larger than the top of a
     * program that has allocated little yet, so that the top grows. Not
     * under a limit of the address space or of the data segment (ulimit
     * -v, -d), against which the reserved space would count. */
    if (!towstab_unlimited(RLIMIT_AS) || !towstab_unlimited(RLIMIT_DATA))
        return 0;
    char *brk0 = sbrk(0);
    mallopt(M_TOP_PAD, (int)TOWSTAB_HEAP_HUGE);
    char *p = malloc(1 << 20);
    mallopt(M_TOP_PAD, 128 << 10); /* glibc's default */
    char *brk1 = sbrk(0);
    if (p && brk0 != (char *)-1 && brk1 != (char *)-1 &&
        brk1 - brk0 >= (ptrdiff_t)TOWSTAB_HEAP_HUGE) {
        uintptr_t lo = ((uintptr_t)brk0 + TOWSTAB_HUGE_PAGE - 1) &
                       ~(TOWSTAB_HUGE_PAGE - 1);
        uintptr_t hi = (uintptr_t)brk1 & ~(TOWSTAB_HUGE_PAGE - 1);
        advised = hi > lo && madvise((void *)lo, hi - lo, MADV_HUGEPAGE) == 0;
    }
    free(p);
#endif
#endif
    return advised;
}

#endif
