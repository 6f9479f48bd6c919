/* outfile.h: writing an output file without damaging anything (internal).
 *
 * A regular file, or a name that does not exist yet, is written under a
 * temporary name beside it and renamed into place only when every write,
 * the flush and the close succeeded: a failed run leaves no file that
 * looks finished and the old file, if any, untouched. Anything else is
 * written directly, as any Unix tool writes it: a device (/dev/null,
 * /dev/full, a terminal), a FIFO, a socket that accepts it; "-",
 * /dev/stdout and /dev/fd/N write to that descriptor. A symbolic link is
 * followed (also one whose target does not exist yet): the file it names
 * is replaced and the link kept. New files are created with mode 0666
 * less the umask, as by any program. Every message names the target as
 * the caller gave it.
 */
#ifndef TOWSTAB_OUTFILE_H
#define TOWSTAB_OUTFILE_H

#include <stdio.h>
#include <sys/types.h>

#include "towstab/error.h"

/* One output being written. */
typedef struct tsi_outfile {
    FILE *f;          /* the stream to write to (NULL when closed) */
    char *name;       /* the target as given, for messages (owned) */
    char *target;     /* the file replaced: the name with symbolic links
                         followed (owned); NULL when written directly */
    char *tmp;        /* the temporary name, NULL when written directly */
    int shared;       /* f is the process's stdout: flushed, not closed */
} tsi_outfile;

/* Open `path` for writing as described above. On failure returns TS_EIO
 * (TS_ENOMEM) with the message in err and leaves nothing behind. */
int tsi_outfile_open(tsi_outfile *o, const char *path, ts_err *err);

/* Finish: check the stream's error flag, flush and close, then rename the
 * temporary file onto the target. TS_OK, or TS_EIO naming the target (the
 * temporary file is then removed). Releases o either way. */
int tsi_outfile_commit(tsi_outfile *o, ts_err *err);

/* Give up: close and remove the temporary file (a direct write cannot be
 * undone and is only closed). Releases o. Safe on a zeroed o. */
void tsi_outfile_abandon(tsi_outfile *o);

/* What a path names, to tell whether two outputs are the same file: for
 * an existing file its device and inode (links followed), else the
 * directory's device and inode and the last name. kind is 0 for a
 * regular or future file, 1 for anything written directly (a device, a
 * FIFO), 2 for standard output ("-", /dev/stdout, /dev/fd/1). */
typedef struct tsi_outfile_id {
    int kind;
    dev_t dev;
    ino_t ino;
    char last[256];
} tsi_outfile_id;

/* Fill id for path. Returns TS_OK, or TS_EIO when the path cannot be
 * resolved (its directory does not exist: the write would fail too). */
int tsi_outfile_identify(const char *path, tsi_outfile_id *id, ts_err *err);

/* A CSV field ",<v>": 17 significant digits (read back to the same
 * double), "nan", "inf" or "-inf" for what is not finite. */
void tsi_csv_number(FILE *f, double v);

#endif
