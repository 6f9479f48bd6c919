/* bigalloc.c: arrays of megabytes on transparent huge pages
 * (lib/bigalloc.h). */
#include "bigalloc.h"

#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

void *tsi_big_malloc(size_t size)
{
    if (size < TSI_HUGE_PAGE)
        return malloc(size);
    void *p = NULL;
    if (posix_memalign(&p, TSI_HUGE_PAGE, size) != 0)
        return NULL;
#ifdef MADV_HUGEPAGE
    /* Advice only: where huge pages are off, or the call fails (EINVAL on
     * a kernel without them), the pages stay the ordinary ones. */
    (void)madvise(p, size - size % TSI_HUGE_PAGE, MADV_HUGEPAGE);
#endif
    return p;
}

void *tsi_big_realloc(void *p, size_t old, size_t size)
{
    void *q = tsi_big_malloc(size);
    if (!q)
        return NULL;
    if (p) {
        memcpy(q, p, old < size ? old : size);
        free(p);
    }
    return q;
}
