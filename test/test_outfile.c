/* test_outfile.c: writing output files without damaging anything
 * (lib/outfile.h, and ts_report_check_targets of towstab/report.h).
 *
 * Regular files: a write that fails (folder missing, target is a folder,
 * the stream fails before commit, an abandoned write) leaves no file and
 * no temporary file behind, and a failed replacement leaves the old file
 * as it was; a new file gets mode 0666 less the umask. Special files are
 * written in place and survive as what they were: a FIFO (read by a child
 * process), a character device made with mknod in the test folder (when
 * root), /dev/null (only written to, and checked to be the same device
 * afterwards), /dev/full (the write must fail loudly). Symbolic links are
 * followed and kept, also a dangling one and a chain; a loop is refused.
 * "-" and /dev/fd/N write to those descriptors. Two names of one file are
 * recognised as one (./a and a, a link and its target, a hard link);
 * devices may be shared, standard output may not. Files go to a fresh
 * folder under $TMPDIR (default /tmp). */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include "tcheck.h"
#include "tfiles.h"
#include "towstab/report.h"

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* Write `text` to `path` through an outfile; returns the code. */
static int write_text(const char *path, const char *text, ts_err *err)
{
    tsi_outfile o;
    int rc = tsi_outfile_open(&o, path, err);
    if (rc != TS_OK)
        return rc;
    fputs(text, o.f);
    return tsi_outfile_commit(&o, err);
}

static void test_regular(void)
{
    char path[600];
    ts_err err = {0};

    snprintf(path, sizeof path, "%s/no/such/folder/eq.json", tf_dir);
    int rc = write_text(path, "x", &err);
    CHECK(rc == TS_EIO && strstr(err.msg, path) && !tf_exists(path),
          "missing folder: TS_EIO naming the path, nothing written (%s)",
          err.msg);

    snprintf(path, sizeof path, "%s/a_folder", tf_dir);
    mkdir(path, 0700);
    ts_err_clear(&err);
    rc = write_text(path, "x", &err);
    CHECK(rc == TS_EIO && strstr(err.msg, "directory") &&
              tf_count("partial") == 0,
          "target is a folder: TS_EIO, no temporary left (%s)", err.msg);
    rmdir(path);

    ts_err_clear(&err);
    rc = write_text("", "x", &err);
    CHECK(rc == TS_EIO && err.msg[0], "empty name refused (%s)", err.msg);

    /* An existing file survives an abandoned replacement untouched. */
    snprintf(path, sizeof path, "%s/old.json", tf_dir);
    put(path, "{\"old\": true}\n");
    tsi_outfile o;
    rc = tsi_outfile_open(&o, path, &err);
    CHECK(rc == TS_OK && o.tmp && strstr(o.tmp, "old.json") &&
              tf_exists(o.tmp),
          "open writes to a temporary beside the target (%s)",
          o.tmp ? o.tmp : "none");
    if (rc == TS_OK) {
        fputs("{\"new\": ", o.f);
        tsi_outfile_abandon(&o);
    }
    const char *text = tf_slurp(path);
    CHECK(text && !strcmp(text, "{\"old\": true}\n") &&
              tf_count("partial") == 0,
          "abandon keeps the old file and removes the temporary");

    /* A stream that fails before commit (its descriptor is closed under
     * it, so the final flush fails): error, old file intact, no
     * temporary. */
    rc = tsi_outfile_open(&o, path, &err);
    if (rc == TS_OK) {
        for (int i = 0; i < 2000; i++)
            fputs("{\"half written\": 1234567890}\n", o.f);
        close(fileno(o.f));
        ts_err_clear(&err);
        rc = tsi_outfile_commit(&o, &err);
    }
    text = tf_slurp(path);
    CHECK(rc == TS_EIO && strstr(err.msg, path) && text &&
              !strcmp(text, "{\"old\": true}\n") &&
              tf_count("partial") == 0,
          "a failed write reports TS_EIO naming the file (%s), keeps the "
          "old file, leaves no temporary", err.msg);

    rc = write_text(path, "{\"new\": 1}\n", &err);
    text = tf_slurp(path);
    CHECK(rc == TS_OK && text && !strcmp(text, "{\"new\": 1}\n") &&
              tf_count("partial") == 0,
          "replacement by a complete file");
    unlink(path);

    /* The umask applies to a new file as to any program's. */
    mode_t old = umask(027);
    rc = write_text(path, "m", &err);
    umask(old);
    struct stat st;
    memset(&st, 0, sizeof st);
    int got = stat(path, &st) == 0;
    CHECK(rc == TS_OK && got && (st.st_mode & 0777) == 0640,
          "a new file has mode 0666 less the umask 027: %o",
          (unsigned)(st.st_mode & 0777));
    unlink(path);
}

static void test_links(void)
{
    char target[600], link[600], link2[600], path[600];
    ts_err err = {0};
    snprintf(target, sizeof target, "%s/target.json", tf_dir);
    snprintf(link, sizeof link, "%s/link.json", tf_dir);
    snprintf(link2, sizeof link2, "%s/link2.json", tf_dir);
    put(target, "old\n");
    int made = symlink("target.json", link) == 0;
    int rc = write_text(link, "new\n", &err);
    struct stat st;
    const char *text = tf_slurp(target);
    CHECK(made && rc == TS_OK && lstat(link, &st) == 0 &&
              S_ISLNK(st.st_mode) && text && !strcmp(text, "new\n") &&
              tf_count("partial") == 0,
          "a symbolic link is kept and the file it names replaced");

    /* A chain: link2 -> link -> target. */
    made = symlink(link, link2) == 0;
    rc = write_text(link2, "chain\n", &err);
    text = tf_slurp(target);
    CHECK(made && rc == TS_OK && lstat(link2, &st) == 0 &&
              S_ISLNK(st.st_mode) && lstat(link, &st) == 0 &&
              S_ISLNK(st.st_mode) && text && !strcmp(text, "chain\n"),
          "a chain of two links is followed to the file");
    unlink(link2);
    unlink(link);
    unlink(target);

    /* A dangling link: the file it names is created. */
    made = symlink("made.json", link) == 0;
    snprintf(path, sizeof path, "%s/made.json", tf_dir);
    rc = write_text(link, "made\n", &err);
    text = tf_slurp(path);
    CHECK(made && rc == TS_OK && lstat(link, &st) == 0 &&
              S_ISLNK(st.st_mode) && text && !strcmp(text, "made\n"),
          "a dangling link: the file it names is created, the link kept");
    unlink(link);
    unlink(path);

    /* A loop. */
    made = symlink("loop_b", link) == 0;
    snprintf(path, sizeof path, "%s/loop_b", tf_dir);
    made &= symlink("link.json", path) == 0;
    ts_err_clear(&err);
    rc = write_text(link, "x", &err);
    CHECK(made && rc == TS_EIO && strstr(err.msg, link) &&
              lstat(link, &st) == 0 && S_ISLNK(st.st_mode),
          "a loop of links is refused, naming the path (%s)", err.msg);
    unlink(link);
    unlink(path);
}

static void test_special(void)
{
    char path[600];
    ts_err err = {0};
    struct stat st, before;

    /* A FIFO, read by a child. */
    snprintf(path, sizeof path, "%s/pipe", tf_dir);
    if (CHECK(mkfifo(path, 0600) == 0, "mkfifo in the test folder")) {
        fflush(stdout);
        pid_t pid = fork();
        if (pid == 0) {
            int fd = open(path, O_RDONLY);
            char buf[64] = "";
            ssize_t n = fd >= 0 ? read(fd, buf, sizeof buf - 1) : -1;
            _exit(n == 9 && !memcmp(buf, "via fifo\n", 9) ? 0 : 1);
        }
        int rc = write_text(path, "via fifo\n", &err);
        int status = -1;
        waitpid(pid, &status, 0);
        CHECK(rc == TS_OK && WIFEXITED(status) &&
                  WEXITSTATUS(status) == 0 && lstat(path, &st) == 0 &&
                  S_ISFIFO(st.st_mode) && tf_count("partial") == 0,
              "a FIFO is written in place (the reader got the text) and is "
              "still a FIFO");
        unlink(path);
    }

    /* A character device made here (root only): the null device. */
    snprintf(path, sizeof path, "%s/null_dev", tf_dir);
    if (mknod(path, S_IFCHR | 0666, makedev(1, 3)) == 0) {
        stat(path, &before);
        int rc = write_text(path, "to a device\n", &err);
        CHECK(rc == TS_OK && lstat(path, &st) == 0 && S_ISCHR(st.st_mode) &&
                  st.st_rdev == before.st_rdev && st.st_ino == before.st_ino &&
                  tf_count("partial") == 0,
              "a device node made with mknod is written and stays the same "
              "device");
        unlink(path);
    } else {
        printf("SKIP mknod of a device node: %s (not root)\n",
               strerror(errno));
    }

    /* /dev/null: written, never replaced. */
    if (stat("/dev/null", &before) == 0) {
        int rc = write_text("/dev/null", "nothing\n", &err);
        CHECK(rc == TS_OK && stat("/dev/null", &st) == 0 &&
                  S_ISCHR(st.st_mode) && st.st_ino == before.st_ino &&
                  st.st_rdev == before.st_rdev,
              "/dev/null: written in place, still the same character "
              "device");
    }

    /* /dev/full: the write fails loudly and the device stays. */
    if (stat("/dev/full", &before) == 0) {
        ts_err_clear(&err);
        char big[9000];
        memset(big, 'x', sizeof big - 1);
        big[sizeof big - 1] = '\0';
        int rc = write_text("/dev/full", big, &err);
        CHECK(rc == TS_EIO && strstr(err.msg, "/dev/full") &&
                  stat("/dev/full", &st) == 0 && S_ISCHR(st.st_mode) &&
                  st.st_ino == before.st_ino,
              "/dev/full: TS_EIO naming it (%s), still the device",
              err.msg);
    }

    /* /dev/fd/N writes to that descriptor. */
    snprintf(path, sizeof path, "%s/fd.txt", tf_dir);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    char name[64];
    snprintf(name, sizeof name, "/dev/fd/%d", fd);
    int rc = write_text(name, "through fd\n", &err);
    close(fd);
    const char *text = tf_slurp(path);
    CHECK(rc == TS_OK && text && !strcmp(text, "through fd\n"),
          "%s writes to the descriptor", name);
    unlink(path);

    /* "-": standard output, no file. Capture fd 1 in a file. */
    fflush(stdout);
    int saved = dup(1);
    fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 1);
    close(fd);
    rc = write_text("-", "to stdout\n", &err);
    fflush(stdout);
    dup2(saved, 1);
    close(saved);
    text = tf_slurp(path);
    CHECK(rc == TS_OK && text && !strcmp(text, "to stdout\n") &&
              !tf_exists("-"),
          "'-' writes to standard output only");
    unlink(path);
}

/* Two outputs naming one file. */
static void test_same(void)
{
    char a[600], a2[600], l[600], h[600], b[600];
    snprintf(a, sizeof a, "%s/a.json", tf_dir);
    snprintf(a2, sizeof a2, "%s/./a.json", tf_dir);
    snprintf(l, sizeof l, "%s/l.json", tf_dir);
    snprintf(h, sizeof h, "%s/h.json", tf_dir);
    snprintf(b, sizeof b, "%s/b.json", tf_dir);
    const char *what[2] = {"--json", "--csv"};
    ts_err err = {0};

    const char *p1[2] = {a, a2};
    int rc = ts_report_check_targets(2, what, p1, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "--json") &&
              strstr(err.msg, "--csv") && strstr(err.msg, "same file"),
          "a new file under two spellings is one file (%s)", err.msg);

    put(a, "x");
    int ok = symlink("a.json", l) == 0 && link(a, h) == 0;
    const char *p2[2] = {l, a}, *p3[2] = {h, a2}, *p4[2] = {a, b};
    ts_err_clear(&err);
    CHECK(ok && ts_report_check_targets(2, what, p2, &err) == TS_EINVAL &&
              ts_report_check_targets(2, what, p3, &err) == TS_EINVAL,
          "a link and its target, a hard link and the file: the same");
    ts_err_clear(&err);
    CHECK(ts_report_check_targets(2, what, p4, &err) == TS_OK,
          "two different files pass");
    unlink(a);
    unlink(l);
    unlink(h);

    const char *p5[2] = {"/dev/null", "/dev/null"};
    CHECK(ts_report_check_targets(2, what, p5, &err) == TS_OK,
          "a device may receive two outputs");
    const char *p6[2] = {"-", "/dev/stdout"};
    rc = ts_report_check_targets(2, what, p6, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "standard output"),
          "'-' and /dev/stdout: both standard output, refused (%s)",
          err.msg);
    const char *p7[3] = {a, NULL, b};
    const char *w3[3] = {"--json", "--csv", "--shapes"};
    CHECK(ts_report_check_targets(3, w3, p7, &err) == TS_OK,
          "outputs not given (NULL) are skipped");
}

int main(void)
{
    if (tf_begin("outfile") != 0) {
        printf("FAIL cannot make a folder under %s: %s\n", tf_dir,
               strerror(errno));
        return 1;
    }
    test_regular();
    test_links();
    test_special();
    test_same();
    CHECK(tf_end(), "nothing left in the test folder");
    return tc_done();
}
