/* test_bigalloc.c: arrays of megabytes on transparent huge pages
 * (lib/bigalloc.h).
 *
 * Small arrays are plain malloc; from one huge page (2 MiB) on they are
 * aligned to it, and a move (tsi_big_realloc) keeps the bytes asked for,
 * growing or shrinking. Where the kernel offers transparent huge pages to
 * advised memory ("always" or "madvise" in
 * /sys/kernel/mm/transparent_hugepage/enabled), the mapping of an 8 MiB
 * array carries the advice (VmFlags "hg" in /proc/self/smaps), and how
 * much of it huge pages back once written is printed (the kernel gives
 * them when it finds them free: not a property of the code); elsewhere
 * that check is skipped and said so. */
#include "bigalloc.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tthp.h"

/* Byte i of the test pattern. */
static unsigned char pat(size_t i) { return (unsigned char)(i * 7 + 3); }

/* Whether p[0..n) holds the pattern. */
static int holds_pattern(const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i] != pat(i))
            return 0;
    return 1;
}

int main(void)
{
    /* Small: plain malloc, written and read back. */
    size_t ns = 1000;
    unsigned char *s = tsi_big_malloc(ns);
    CHECK(s != NULL, "a small array (%zu bytes) is allocated", ns);
    if (s) {
        for (size_t i = 0; i < ns; i++)
            s[i] = pat(i);
        CHECK(holds_pattern(s, ns), "the small array holds what was written");
    }
    /* Grown past a huge page: the bytes kept, the new array aligned. */
    size_t nb = 5 * TSI_HUGE_PAGE / 2 + 123;
    unsigned char *b = tsi_big_realloc(s, ns, nb);
    CHECK(b != NULL, "grown to %zu bytes", nb);
    if (!b)
        return tc_done();
    CHECK((uintptr_t)b % TSI_HUGE_PAGE == 0,
          "an array of %zu bytes starts on a huge page boundary", nb);
    CHECK(holds_pattern(b, ns), "growing keeps the first %zu bytes", ns);
    for (size_t i = 0; i < nb; i++)
        b[i] = pat(i);
    /* Grown again, then shrunk: each keeps what it was asked to. */
    size_t ng = 9 * TSI_HUGE_PAGE / 2;
    unsigned char *g = tsi_big_realloc(b, nb, ng);
    CHECK(g != NULL && (uintptr_t)g % TSI_HUGE_PAGE == 0,
          "grown to %zu bytes, aligned", ng);
    if (!g)
        return tc_done();
    CHECK(holds_pattern(g, nb), "growing keeps all %zu bytes", nb);
    /* Shrunk, moving only the first 1000 bytes (those in use). */
    unsigned char *h = tsi_big_realloc(g, 1000, nb);
    CHECK(h != NULL && holds_pattern(h, 1000),
          "a move of the first 1000 bytes keeps them");
    free(h);
    unsigned char *z = tsi_big_realloc(NULL, 0, TSI_HUGE_PAGE);
    CHECK(z != NULL && (uintptr_t)z % TSI_HUGE_PAGE == 0,
          "from NULL: a new array of one huge page, aligned");
    free(z);

    /* Huge pages where the kernel offers them. */
    if (!thp_offered()) {
        printf("SKIP huge-page advice: the kernel offers no transparent "
               "huge pages to advised memory\n");
    } else {
        size_t n8 = 4 * TSI_HUGE_PAGE;
        unsigned char *e = tsi_big_malloc(n8);
        CHECK(e != NULL, "an array of 8 MiB");
        if (e) {
            memset(e, 1, n8);
            long kb;
            int hg = advised_at(e, &kb);
            CHECK(hg == 1, "its mapping carries the huge-page advice "
                           "(VmFlags hg)");
            /* Whether the kernel found free huge pages at the fault is
             * its affair (memory may be fragmented): said, not judged. */
            printf("NOTE the written array is backed by %ld kB of huge "
                   "pages\n", kb);
            free(e);
        }
    }
    return tc_done();
}
