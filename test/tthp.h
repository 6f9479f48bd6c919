/* tthp.h: transparent huge pages as a test sees them (test_bigalloc.c,
 * test_malloc_policy.c): whether the kernel offers them to advised
 * memory, and whether the mapping that holds an address carries the
 * advice. */
#ifndef TOWSTAB_TTHP_H
#define TOWSTAB_TTHP_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Whether this kernel gives huge pages to advised memory. */
static inline int thp_offered(void)
{
    FILE *f = fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!f)
        return 0;
    char line[128] = "";
    int ok = fgets(line, sizeof line, f) &&
             (strstr(line, "[always]") || strstr(line, "[madvise]"));
    fclose(f);
    return ok;
}

/* Of the mapping that holds p in /proc/self/smaps: whether its VmFlags
 * carry the huge-page advice ("hg"), and the kB of huge pages backing it
 * (*kb; -1 if not found). Returns -1 when no mapping holds p. */
static inline int advised_at(const void *p, long *kb)
{
    *kb = -1;
    FILE *f = fopen("/proc/self/smaps", "r");
    if (!f)
        return -1;
    char line[512];
    int inside = 0, found = -1;
    uintptr_t a = (uintptr_t)p;
    while (fgets(line, sizeof line, f)) {
        unsigned long lo, hi;
        /* A mapping's header, "lo-hi perms ...", or one of its fields,
         * "Name: value". */
        size_t word = strcspn(line, " ");
        if (memchr(line, '-', word) &&
            sscanf(line, "%lx-%lx ", &lo, &hi) == 2) {
            if (found >= 0)
                break;
            inside = a >= lo && a < hi;
            continue;
        }
        long v;
        if (inside && sscanf(line, "AnonHugePages: %ld kB", &v) == 1)
            *kb = v;
        if (inside && strncmp(line, "VmFlags:", 8) == 0) {
            found = 0;
            for (char *t = strtok(line + 8, " \n"); t;
                 t = strtok(NULL, " \n"))
                found |= strcmp(t, "hg") == 0;
        }
    }
    fclose(f);
    return found;
}

#endif
