/* outfile.c: writing an output file without damaging anything (outfile.h).
 *
 * The decision is made on the file a name resolves to: symbolic links are
 * followed by hand (readlink, at most MAX_LINK_HOPS) so that a link whose
 * target does not exist yet still names that target, and the rename goes
 * onto the target, not onto the link. A regular file or a name that does
 * not exist is replaced through a temporary file in the target's
 * directory (rename(2) is atomic within one file system); everything else
 * is opened and written in place: renaming over /dev/null would replace
 * the device for the whole machine. Standard output and /dev/fd/N are
 * written through a duplicate of the descriptor, after flushing stdout so
 * that the order of what the process wrote is kept. */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Symbolic links followed before giving up (as the kernel's ELOOP). */
#define MAX_LINK_HOPS 40
/* Attempts at a fresh temporary name. */
#define TMP_ATTEMPTS 100

static void release(tsi_outfile *o)
{
    free(o->name);
    free(o->target);
    free(o->tmp);
    o->f = NULL;
    o->name = o->target = o->tmp = NULL;
    o->shared = 0;
}

/* The descriptor a name denotes without being a file of its own: 1 for
 * "/dev/stdout", N for "/dev/fd/N" or "/proc/self/fd/N", 2 for
 * "/dev/stderr"; -1 otherwise. */
static int named_descriptor(const char *path)
{
    if (strcmp(path, "/dev/stdout") == 0)
        return 1;
    if (strcmp(path, "/dev/stderr") == 0)
        return 2;
    const char *rest = NULL;
    if (strncmp(path, "/dev/fd/", 8) == 0)
        rest = path + 8;
    else if (strncmp(path, "/proc/self/fd/", 14) == 0)
        rest = path + 14;
    if (!rest || *rest < '0' || *rest > '9')
        return -1;
    char *end;
    long fd = strtol(rest, &end, 10);
    return *end == '\0' && fd <= INT_MAX ? (int)fd : -1;
}

/* path with symbolic links followed (a new string), or NULL with errno. */
static char *follow_links(const char *path)
{
    char *cur = strdup(path);
    for (int hop = 0; cur; hop++) {
        struct stat st;
        if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode))
            return cur;
        if (hop == MAX_LINK_HOPS) {
            free(cur);
            errno = ELOOP;
            return NULL;
        }
        char link[PATH_MAX];
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0) {
            int e = errno;
            free(cur);
            errno = e;
            return NULL;
        }
        link[n] = '\0';
        char *next;
        const char *slash = strrchr(cur, '/');
        if (link[0] == '/' || !slash) {
            next = strdup(link);
        } else {
            /* Relative to the directory holding the link. */
            size_t dir = (size_t)(slash - cur) + 1;
            next = malloc(dir + (size_t)n + 1);
            if (next) {
                memcpy(next, cur, dir);
                memcpy(next + dir, link, (size_t)n + 1);
            }
        }
        free(cur);
        cur = next;
    }
    errno = ENOMEM;
    return NULL;
}

/* Write to a duplicate of descriptor fd. */
static int open_descriptor(tsi_outfile *o, int fd, ts_err *err)
{
    fflush(stdout); /* what stdout holds goes first */
    int d = dup(fd);
    o->f = d >= 0 ? fdopen(d, "w") : NULL;
    if (!o->f) {
        int e = errno;
        if (d >= 0)
            close(d);
        return ts_fail(err, TS_EIO, "%s: cannot write (%s)", o->name,
                       strerror(e));
    }
    return TS_OK;
}

int tsi_outfile_open(tsi_outfile *o, const char *path, ts_err *err)
{
    memset(o, 0, sizeof *o);
    if (!path || !path[0])
        return ts_fail(err, TS_EIO, "output file: expected a file name, got "
                                    "an empty one");
    o->name = strdup(path);
    if (!o->name)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
    if (strcmp(path, "-") == 0) {
        o->f = stdout;
        o->shared = 1;
        return TS_OK;
    }
    int fd = named_descriptor(path);
    if (fd >= 0) {
        int rc = open_descriptor(o, fd, err);
        if (rc)
            release(o);
        return rc;
    }
    o->target = follow_links(path);
    if (!o->target) {
        int e = errno;
        release(o);
        return ts_fail(err, e == ENOMEM ? TS_ENOMEM : TS_EIO,
                       "%s: cannot write (%s)", path, strerror(e));
    }
    struct stat st;
    if (stat(o->target, &st) == 0 && !S_ISREG(st.st_mode)) {
        /* A device, FIFO or socket: written in place, never replaced. A
         * FIFO's open waits for its reader, as in any Unix tool. */
        if (S_ISDIR(st.st_mode)) {
            release(o);
            return ts_fail(err, TS_EIO, "%s: cannot write (%s)", path,
                           strerror(EISDIR));
        }
        int d = open(o->target, O_WRONLY | O_NOCTTY);
        o->f = d >= 0 ? fdopen(d, "w") : NULL;
        if (!o->f) {
            int e = errno;
            if (d >= 0)
                close(d);
            release(o);
            return ts_fail(err, TS_EIO, "%s: cannot write (%s)", path,
                           strerror(e));
        }
        free(o->target);
        o->target = NULL;
        return TS_OK;
    }
    /* A fresh name beside the target, created exclusively with mode 0666
     * so that the user's umask applies as to any file (mkstemp would make
     * it 0600). The process id and an attempt count make the name unique;
     * O_EXCL makes sure. */
    size_t size = strlen(o->target) + 64;
    o->tmp = malloc(size);
    if (!o->tmp) {
        release(o);
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", path);
    }
    int d = -1, e = 0;
    for (int attempt = 0; attempt < TMP_ATTEMPTS && d < 0; attempt++) {
        snprintf(o->tmp, size, "%s.partial-%ld-%d", o->target,
                 (long)getpid(), attempt);
        d = open(o->tmp, O_WRONLY | O_CREAT | O_EXCL, 0666);
        e = errno;
        if (d < 0 && e != EEXIST)
            break;
    }
    o->f = d >= 0 ? fdopen(d, "w") : NULL;
    if (!o->f) {
        if (d >= 0) {
            e = errno;
            close(d);
            unlink(o->tmp);
        }
        release(o);
        return ts_fail(err, TS_EIO, "%s: cannot write (%s)", path,
                       strerror(e));
    }
    return TS_OK;
}

int tsi_outfile_commit(tsi_outfile *o, ts_err *err)
{
    if (!o->f) {
        release(o);
        return ts_fail(err, TS_EIO, "output file: not open");
    }
    int rc = TS_OK, e = 0;
    if (o->shared) {
        if (fflush(o->f) != 0)
            e = errno;
        if (e || ferror(o->f))
            rc = ts_fail(err, TS_EIO, "standard output: write failed%s%s%s",
                         e ? " (" : "", e ? strerror(e) : "", e ? ")" : "");
        release(o);
        return rc;
    }
    int bad = ferror(o->f);
    if (fflush(o->f) != 0)
        e = errno;
    if (fclose(o->f) != 0 && !e)
        e = errno;
    o->f = NULL;
    if (bad || e) {
        if (o->tmp)
            unlink(o->tmp);
        rc = ts_fail(err, TS_EIO, "%s: write failed%s%s%s", o->name,
                     e ? " (" : "", e ? strerror(e) : "", e ? ")" : "");
    } else if (o->tmp && rename(o->tmp, o->target) != 0) {
        e = errno;
        unlink(o->tmp);
        rc = ts_fail(err, TS_EIO, "%s: cannot write (%s)", o->name,
                     strerror(e));
    }
    release(o);
    return rc;
}

void tsi_outfile_abandon(tsi_outfile *o)
{
    if (o->f && !o->shared)
        fclose(o->f);
    if (o->f && o->tmp)
        unlink(o->tmp);
    release(o);
}

int tsi_outfile_identify(const char *path, tsi_outfile_id *id, ts_err *err)
{
    memset(id, 0, sizeof *id);
    int fd = strcmp(path, "-") == 0 ? 1 : named_descriptor(path);
    if (fd == 1) {
        id->kind = 2;
        return TS_OK;
    }
    struct stat st;
    if (fd >= 0 ? fstat(fd, &st) == 0 : stat(path, &st) == 0) {
        id->kind = S_ISREG(st.st_mode) ? 0 : 1;
        id->dev = st.st_dev;
        id->ino = st.st_ino;
        return TS_OK;
    }
    /* A file to be created: its directory and last name. */
    char *target = follow_links(path);
    if (!target)
        return ts_fail(err, TS_EIO, "%s: cannot write (%s)", path,
                       strerror(errno));
    char *slash = strrchr(target, '/');
    const char *last = slash ? slash + 1 : target;
    int ok;
    if (!slash)
        ok = stat(".", &st) == 0;
    else if (slash == target)
        ok = stat("/", &st) == 0;
    else {
        *slash = '\0';
        ok = stat(target, &st) == 0;
    }
    int e = errno;
    snprintf(id->last, sizeof id->last, "%s", last);
    free(target);
    if (!ok)
        return ts_fail(err, TS_EIO, "%s: cannot write (%s)", path,
                       strerror(e));
    id->dev = st.st_dev;
    id->ino = st.st_ino;
    return TS_OK;
}

void tsi_csv_number(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, ",%.17g", v);
    else
        fprintf(f, ",%s", isnan(v) ? "nan" : v > 0 ? "inf" : "-inf");
}
