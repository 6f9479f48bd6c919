/* test_malloc_policy.c: the command line's allocator policy
 * (tools/malloc_policy.h).
 *
 * Set first, as towstab's main sets it. With glibc, on a kernel that
 * offers transparent huge pages to advised memory, without a sanitizer's
 * allocator and without a limit of the address space or data segment,
 * the policy says it advised the heap, and then:
 *  - a block of 8 MiB allocated after it, written and read back, lies
 *    (its middle: the advice starts at a huge-page boundary) in a mapping
 *    that carries the advice (VmFlags "hg" in /proc/self/smaps);
 *  - so does a block allocated by another thread (the policy's one arena:
 *    glibc would otherwise give the thread a heap of its own, mapped
 *    apart, without the advice);
 *  - after blocks of a quarter of the advised heap are allocated and freed
 *    in turn, one of half of it still lies in the advice (freed memory
 *    returns to the top, which is not trimmed).
 * Elsewhere the policy is advice not taken, and those checks are skipped
 * and said so; an allocation of more than the advised heap works
 * everywhere, mapped apart (where the heap was advised: without the
 * advice, so not cut from the advised top). First, in a child process under a limit of its
 * address space (RLIMIT_AS, 64 GiB), the policy reserves nothing and says
 * so. */
#include "malloc_policy.h"

#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "tcheck.h"
#include "tthp.h"

#define MIB ((size_t)1 << 20)

/* Write a pattern over p[n] and read it back. */
static int write_read(unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        p[i] = (unsigned char)(i * 13 + 5);
    for (size_t i = 0; i < n; i++)
        if (p[i] != (unsigned char)(i * 13 + 5))
            return 0;
    return 1;
}

/* A thread's block: allocated and written there, its mapping's advice
 * read there (hg as advised_at returns it), freed by main. */
typedef struct thread_block {
    unsigned char *p;
    int written, hg;
} thread_block;

static void *thread_alloc(void *arg)
{
    thread_block *b = arg;
    b->p = malloc(8 * MIB);
    if (b->p) {
        b->written = write_read(b->p, 8 * MIB);
        long kb;
        b->hg = advised_at(b->p + 4 * MIB, &kb);
    }
    return NULL;
}

/* The policy's answer in a child process whose address space is limited
 * (RLIMIT_AS), -1 when the child could not be run. */
static int limited_child(void)
{
    pid_t pid = fork();
    if (pid == 0) {
        /* The soft limit only (lowering it needs no privilege); one
         * already set is kept. */
        struct rlimit as;
        if (getrlimit(RLIMIT_AS, &as) != 0)
            _exit(3);
        if (as.rlim_cur == RLIM_INFINITY) {
            as.rlim_cur = (rlim_t)64 << 30;
            if (as.rlim_max != RLIM_INFINITY && as.rlim_cur > as.rlim_max)
                as.rlim_cur = as.rlim_max;
            if (setrlimit(RLIMIT_AS, &as) != 0)
                _exit(3);
        }
        _exit(towstab_malloc_policy());
    }
    int st;
    if (pid < 0 || waitpid(pid, &st, 0) != pid || !WIFEXITED(st))
        return -1;
    return WEXITSTATUS(st) <= 1 ? WEXITSTATUS(st) : -1;
}

int main(void)
{
    CHECK(limited_child() == 0, "under a limit of the address space the "
                                "policy reserves and advises nothing");
    int advised = towstab_malloc_policy();
    int expect = thp_offered();
#if defined(__GLIBC__)
    /* (Under a limit the policy reserves nothing: checked above.) */
    expect = expect && towstab_unlimited(RLIMIT_AS) &&
             towstab_unlimited(RLIMIT_DATA);
#else
    expect = 0;
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    expect = 0; /* the sanitizer's allocator, not glibc's heap */
#endif
    if (expect)
        CHECK(advised == 1, "the policy advised the heap onto huge pages "
                            "(%d MiB)",
              (int)(TOWSTAB_HEAP_HUGE / MIB));
    else
        printf("SKIP the heap's advice: no glibc heap, no transparent huge "
               "pages offered to advised memory, or a limit of the address "
               "space or data segment (the policy says %d)\n",
               advised);

    unsigned char *a = malloc(8 * MIB);
    CHECK(a != NULL && write_read(a, 8 * MIB),
          "a block of 8 MiB after the policy, written and read back");
    long kb;
    if (advised && a) {
        /* (The advice starts at the huge-page boundary after the top's
         * start: the first block may begin before it.) */
        CHECK(advised_at(a + 4 * MIB, &kb) == 1,
              "its middle's mapping carries the huge-page advice (VmFlags "
              "hg)");
        /* Whether the kernel found free huge pages is its affair. */
        printf("NOTE the written block is backed by %ld kB of huge pages\n",
               kb);
    }

    thread_block tb = {NULL, 0, -1};
    pthread_t th;
    int started = pthread_create(&th, NULL, thread_alloc, &tb) == 0;
    CHECK(started, "a second thread starts");
    if (started) {
        pthread_join(th, NULL);
        CHECK(tb.p != NULL && tb.written,
              "the thread's block of 8 MiB, written and read back");
        if (advised && tb.p)
            CHECK(tb.hg == 1, "the thread's block lies in the advised heap "
                              "(one arena)");
    }
    free(tb.p);
    free(a);

    /* Blocks of a quarter, allocated and freed in turn, then one of half:
     * from the same top, still advised. */
    for (int k = 0; k < 3; k++) {
        unsigned char *q = malloc(TOWSTAB_HEAP_HUGE / 4);
        CHECK(q != NULL, "block %d of a quarter of the advised heap", k);
        if (q)
            q[0] = q[TOWSTAB_HEAP_HUGE / 4 - 1] = 1;
        free(q);
    }
    unsigned char *h = malloc(TOWSTAB_HEAP_HUGE / 2);
    CHECK(h != NULL, "a block of half the advised heap");
    if (h && advised) {
        h[0] = h[TOWSTAB_HEAP_HUGE / 2 - 1] = 1;
        CHECK(advised_at(h + TOWSTAB_HEAP_HUGE / 4, &kb) == 1,
              "its middle lies in the advised heap after the frees");
    }
    free(h);

    /* More than the advised heap: mapped apart (over the mapping
     * threshold), not cut from the advised top, and it works. */
    size_t nb = TOWSTAB_HEAP_HUGE + 16 * MIB;
    unsigned char *big = malloc(nb);
    CHECK(big != NULL, "a block of %zu MiB, over the advised heap",
          nb / MIB);
    if (big) {
        big[0] = big[nb - 1] = 7;
        if (advised)
            CHECK(advised_at(big + nb / 2, &kb) == 0,
                  "it is mapped apart, without the advice (its middle's "
                  "VmFlags carry no hg)");
    }
    free(big);
    return tc_done();
}
