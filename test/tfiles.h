/* tfiles.h: the scratch folder of a test program that writes files. One
 * fresh folder under $TMPDIR (default /tmp), made by tf_begin and removed
 * by tf_end when only "." and ".." are left in it. State is per program. */
#ifndef TOWSTAB_TFILES_H
#define TOWSTAB_TFILES_H

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char tf_dir[512];

/* Make the folder "towstab-test-<name>-XXXXXX"; 0 on success. */
static inline int tf_begin(const char *name)
{
    const char *t = getenv("TMPDIR");
    snprintf(tf_dir, sizeof tf_dir, "%s/towstab-test-%s-XXXXXX",
             t && *t ? t : "/tmp", name);
    return mkdtemp(tf_dir) ? 0 : -1;
}

/* The path exists (a link counts, also a dangling one). */
static inline int tf_exists(const char *path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

/* Number of entries in the folder whose name contains `part` ("" counts
 * every entry, "." and ".." included). */
static inline int tf_count(const char *part)
{
    DIR *d = opendir(tf_dir);
    int n = 0;
    if (!d)
        return -1;
    for (struct dirent *e; (e = readdir(d));)
        if (strstr(e->d_name, part))
            n++;
    closedir(d);
    return n;
}

/* The text of a file (at most 64 KiB; a static buffer), NULL when it
 * cannot be read. */
static inline char *tf_slurp(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    static char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* Remove the folder; 1 when it was empty. */
static inline int tf_end(void)
{
    int empty = tf_count("") == 2;
    rmdir(tf_dir);
    return empty;
}

#endif
