/* tfile.h: temporary files for the tests that read tables (test_sea.c,
 * test_rao.c). State is per program. */
#ifndef TOWSTAB_TFILE_H
#define TOWSTAB_TFILE_H

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/* Write `text` to a new file /tmp/towstab_<tag>_XXXXXX and return its
 * path (static storage: valid until the next call), NULL on failure. The
 * caller unlinks it. */
static inline char *tf_write_temp(const char *tag, const char *text)
{
    static char path[96];
    snprintf(path, sizeof path, "/tmp/towstab_%s_XXXXXX", tag);
    int fd = mkstemp(path);
    if (fd < 0)
        return NULL;
    FILE *f = fdopen(fd, "w");
    if (!f) {
        close(fd);
        return NULL;
    }
    fputs(text, f);
    fclose(f);
    return path;
}

#endif
