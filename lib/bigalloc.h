/* bigalloc.h (private): arrays of megabytes (the eigensolvers' Arnoldi
 * bases and eigenvector stores, the shifted matrix's values) on
 * transparent huge pages where the kernel offers them (doc/performance.md,
 * "Huge pages").
 *
 * A fresh array of n MiB on 4 KiB pages is 256 n page faults, each a trap
 * into the kernel, and its reads walk 256 n entries of the page table; on
 * 2 MiB pages, n / 2 of each. With transparent huge pages set to
 * "madvise" (Debian's default) only memory advised so gets them; set to
 * "never", the advice is ignored and the pages are the ordinary ones. The
 * arrays are otherwise ordinary: free() releases them. */
#ifndef TOWSTAB_LIB_BIGALLOC_H
#define TOWSTAB_LIB_BIGALLOC_H

#include <stddef.h>

/* One huge page of x86-64 (and arm64 with 4 KiB pages), bytes. */
#define TSI_HUGE_PAGE ((size_t)2 << 20)

/* size bytes, uninitialised, as malloc; from TSI_HUGE_PAGE bytes on,
 * aligned to TSI_HUGE_PAGE with its whole huge pages advised to the kernel
 * as such (MADV_HUGEPAGE, where the system defines it). NULL when out of
 * memory. */
void *tsi_big_malloc(size_t size);

/* p (from tsi_big_malloc, of old bytes, or NULL) moved to a new array of
 * size bytes from tsi_big_malloc, its first min(old, size) bytes kept; p
 * is freed on success and left as it was on failure (NULL). */
void *tsi_big_realloc(void *p, size_t old, size_t size);

#endif
