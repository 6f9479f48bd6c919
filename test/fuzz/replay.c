/* replay.c: a plain main() that drives a libFuzzer harness without
 * libFuzzer, for the deterministic smoke run of the default test suite.
 *
 *   replay [--mutations N] [--seed S] [--dict FILE] [--only NAME:K]
 *          [--leak-check] [--verbose] PATH...
 *
 * Every regular file in the PATHs (directories are read one level deep,
 * names sorted, dot files skipped) is given to LLVMFuzzerTestOneInput as
 * it is, then N mutated copies of it. A mutant is the file with 1 to 4
 * edits drawn from: flip one bit; truncate; insert a byte (one of the
 * bytes YAML and unit text are made of, or any byte); delete up to 8
 * bytes; overwrite a byte; duplicate a chunk of up to 64 bytes elsewhere;
 * insert a token (built in, plus the strings of a libFuzzer dictionary
 * given with --dict). The generator is splitmix64 seeded from the seed and
 * the file's name, so mutant K of a file is the same on every machine and
 * does not depend on the other files: "--only NAME:K" replays exactly that
 * one (K = 0 is the file itself) and writes it to replay-input.bin.
 * --leak-check (LeakSanitizer builds only; slow, ~30 ms per input) runs a
 * leak check after every input and names the first input that leaked;
 * without it a leak is reported once, at exit, for the whole run.
 *
 * Inputs are copied into buffers of exactly their length, so a sanitizer
 * build catches any read past the end. A broken invariant aborts inside
 * the harness; a crash (signal or sanitizer report) first prints which
 * input it was, with the command that replays it, and saves the bytes to
 * replay-crash.bin in the working directory.
 *
 * Checks, one PASS/FAIL line per corpus file: the harness returned on the
 * file and on all its mutants (otherwise the process dies, which the test
 * harness reports as a failure); a file named good_* is accepted and a
 * file named bad_* refused, so a stale corpus is noticed. A closing
 * "N passed, N failed" line follows (test/tcheck.h). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../tcheck.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
extern int fuzz_accepted;

/* Sanitizer runtimes call this before they end the process; absent (NULL)
 * without a sanitizer. */
void __sanitizer_set_death_callback(void (*callback)(void))
    __attribute__((weak));
/* LeakSanitizer's check on demand (nonzero when something leaked). */
int __lsan_do_recoverable_leak_check(void) __attribute__((weak));

#define REPLAY_MAX_FILE (1 << 20)     /* largest corpus file read */
#define REPLAY_MAX_MUTANT (1 << 16)    /* mutants never grow beyond this */
#define REPLAY_MAX_TOKENS 512

/* ------------------------------------------------------------------ */
/* The input being run, for the crash report.                           */

static const char *cur_name = "";
static long cur_k;
static const uint8_t *cur_data;
static size_t cur_size;
static char repro[1024];        /* the command that replays it */

static void say(const char *s)
{
    ssize_t r = write(2, s, strlen(s));
    (void)r;
}

/* Save the current input to `path`; async-signal-safe. */
static void save_input(const char *path)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0)
        return;
    size_t off = 0;
    while (off < cur_size) {
        ssize_t w = write(fd, cur_data + off, cur_size - off);
        if (w <= 0)
            break;
        off += (size_t)w;
    }
    close(fd);
}

/* Async-signal-safe: write(), open(), no stdio. */
static void report_crash(void)
{
    static volatile sig_atomic_t once;
    if (once)
        return;
    once = 1;
    if (!cur_data) {
        say("\nreplay: died between inputs (");
        say(cur_name);
        say(")\nreplay: ");
        say(repro);
        say("\n");
        return;
    }
    say("\nreplay: the harness died on input ");
    say(cur_name);
    say(cur_k ? " (a mutant)" : " (the file itself)");
    say("\nreplay: reproduce with: ");
    say(repro);
    say("\n");
    save_input("replay-crash.bin");
    say("replay: the input is saved in replay-crash.bin\n");
}

static void on_signal(int sig)
{
    report_crash();
    signal(sig, SIG_DFL);
    raise(sig);
}

/* ------------------------------------------------------------------ */
/* Deterministic generator                                              */

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t below(uint64_t *s, uint64_t n)
{
    return n ? splitmix64(s) % n : 0;
}

static uint64_t fnv1a(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 0x100000001b3ULL;
    return h;
}

/* ------------------------------------------------------------------ */
/* Tokens                                                               */

typedef struct token {
    uint8_t *bytes;
    size_t len;
} token;

static token tokens[REPLAY_MAX_TOKENS];
static int ntokens;

static void add_token(const char *s, size_t len)
{
    if (ntokens == REPLAY_MAX_TOKENS || len == 0)
        return;
    tokens[ntokens].bytes = malloc(len);
    if (!tokens[ntokens].bytes)
        return;
    memcpy(tokens[ntokens].bytes, s, len);
    tokens[ntokens].len = len;
    ntokens++;
}

/* What YAML structure and quantities are made of. */
static void builtin_tokens(void)
{
    static const char *const t[] = {
        ": ", "- ", "\n", "\n  ", "\n- ", "  ", "[", "]", "{", "}", ", ",
        "&a ", "*a", "<<: *a", "!!str ", "!!map ", "---\n", "\n...\n", "\"",
        "'", "# ", "~", "null", "? ", "|\n  ", ">\n  ", "%YAML 1.1\n",
        "0", "-1", "1e308", "1e-320", "-0", ".5", "1.", "2e", "0x10", ".nan",
        ".inf", "-.inf", "nan", "inf", " ft", " in", " lbf", " lb", " kg",
        " m", " N", " kg/m", " lbf/ft", " lb/ft", " m/s", " knot", " kn",
        " rad/s", " deg", " deg/s", " Hz", " rad", " slug/ft^3", "^2",
        "^-1", "/", "*", ".", " since 1970-01-01", " degC", " 1/s", " m m",
        "\t", "\r\n", "\xef\xbb\xbf", "\xff\xfe", "\xc3\xa9", "\\x00",
        "name: ", "tow: ", "speed: ", "cables: ", "bodies: ", "analyses: ",
        "links: ", "links: 100000", "link_lengths: [1, 2]", "type: ",
        "from: tow", "to: ", "length: ", "diameter: ", "weight: ",
        "mass: ", "wet_weight: ", "environment: ", "gravity: 0",
        "current: [0, 0, 0]", "point: [0, 0, 0]", "sphere", "junction",
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        add_token(t[i], strlen(t[i]));
}

static int hexval(int c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

/* A libFuzzer dictionary: lines [name=]"text" with \\, \" and \xNN
 * escapes; '#' comments and blank lines ignored. Returns 0 or -1. */
static int read_dict(const char *path)
{
    FILE *fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "replay: %s: cannot open: %s\n", path,
                strerror(errno));
        return -1;
    }
    char line[1024];
    int lineno = 0, rc = 0;
    while (fgets(line, sizeof line, fp)) {
        lineno++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '#' || *p == '\n' || *p == '\0')
            continue;
        char *q = strchr(p, '"');
        if (!q) {
            fprintf(stderr, "replay: %s:%d: expected [name=]\"text\"\n", path,
                    lineno);
            rc = -1;
            break;
        }
        char buf[1024];
        size_t n = 0;
        int closed = 0;
        for (q++; *q && n < sizeof buf; q++) {
            if (*q == '"') {
                closed = 1;
                break;
            }
            if (*q == '\\' && q[1] == 'x' && hexval(q[2]) >= 0 &&
                hexval(q[3]) >= 0) {
                buf[n++] = (char)(hexval(q[2]) * 16 + hexval(q[3]));
                q += 3;
            } else if (*q == '\\' && (q[1] == '\\' || q[1] == '"')) {
                buf[n++] = *++q;
            } else {
                buf[n++] = *q;
            }
        }
        if (!closed) {
            fprintf(stderr, "replay: %s:%d: unterminated string\n", path,
                    lineno);
            rc = -1;
            break;
        }
        add_token(buf, n);
    }
    fclose(fp);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Mutation                                                             */

static const uint8_t interesting[] = {
    ':', '-', ' ', '\n', '\t', '[', ']', '{', '}', ',', '"', '\'', '&', '*',
    '!', '#', '|', '>', '?', '%', '~', '0', '1', '9', '.', 'e', '+', '/',
    '^', 'x', 0x00, 0x7f, 0x80, 0xc3, 0xff,
};

/* Insert len bytes at pos of buf[*n] (capacity REPLAY_MAX_MUTANT). */
static void insert(uint8_t *buf, size_t *n, size_t pos, const uint8_t *src,
                   size_t len)
{
    if (*n + len > REPLAY_MAX_MUTANT)
        len = REPLAY_MAX_MUTANT - *n;
    memmove(buf + pos + len, buf + pos, *n - pos);
    memmove(buf + pos, src, len);
    *n += len;
}

/* Apply 1 to 4 random edits to buf[*n]. */
static void mutate(uint8_t *buf, size_t *n, uint64_t *rng)
{
    int edits = 1 + (int)below(rng, 4);
    for (int e = 0; e < edits; e++) {
        size_t pos = (size_t)below(rng, *n + 1);
        switch (below(rng, 7)) {
        case 0: /* flip a bit */
            if (*n)
                buf[pos % *n] ^= (uint8_t)(1u << below(rng, 8));
            break;
        case 1: /* truncate */
            *n = pos;
            break;
        case 2: { /* insert a byte */
            uint8_t b = below(rng, 2)
                ? interesting[below(rng, sizeof interesting)]
                : (uint8_t)below(rng, 256);
            insert(buf, n, pos, &b, 1);
            break;
        }
        case 3: { /* delete up to 8 bytes */
            size_t len = 1 + (size_t)below(rng, 8);
            if (pos + len > *n)
                len = *n - pos;
            memmove(buf + pos, buf + pos + len, *n - pos - len);
            *n -= len;
            break;
        }
        case 4: /* overwrite a byte */
            if (*n)
                buf[pos % *n] = interesting[below(rng, sizeof interesting)];
            break;
        case 5: { /* duplicate a chunk elsewhere */
            if (!*n)
                break;
            size_t from = (size_t)below(rng, *n);
            size_t len = 1 + (size_t)below(rng, 64);
            if (from + len > *n)
                len = *n - from;
            uint8_t chunk[64];
            memcpy(chunk, buf + from, len);
            insert(buf, n, pos, chunk, len);
            break;
        }
        default: { /* insert a token */
            const token *t = &tokens[below(rng, (uint64_t)ntokens)];
            insert(buf, n, pos, t->bytes, t->len);
            break;
        }
        }
    }
}

/* ------------------------------------------------------------------ */
/* Files                                                                */

typedef struct input {
    char *path;
    const char *name;           /* base name */
    uint8_t *data;
    size_t size;
} input;

static int cmp_input(const void *a, const void *b)
{
    return strcmp(((const input *)a)->path, ((const input *)b)->path);
}

static int read_file(const char *path, input *in)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        fprintf(stderr, "replay: %s: cannot open: %s\n", path,
                strerror(errno));
        return -1;
    }
    uint8_t *buf = malloc(REPLAY_MAX_FILE);
    size_t n = buf ? fread(buf, 1, REPLAY_MAX_FILE, fp) : 0;
    int bad = !buf || ferror(fp) || !feof(fp);
    fclose(fp);
    if (bad) {
        fprintf(stderr, "replay: %s: cannot read (or larger than %d "
                "bytes)\n", path, REPLAY_MAX_FILE);
        free(buf);
        return -1;
    }
    in->path = strdup(path);
    const char *slash = strrchr(in->path, '/');
    in->name = slash ? slash + 1 : in->path;
    in->data = buf;
    in->size = n;
    return in->path ? 0 : -1;
}

/* Append the files of `path` (a file or a directory) to *list. */
static int collect(const char *path, input **list, int *n, int *cap)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "replay: %s: %s\n", path, strerror(errno));
        return -1;
    }
    char **names = NULL;
    int nnames = 0;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        if (!d) {
            fprintf(stderr, "replay: %s: %s\n", path, strerror(errno));
            return -1;
        }
        struct dirent *e;
        while ((e = readdir(d))) {
            if (e->d_name[0] == '.')
                continue;
            char full[4096];
            snprintf(full, sizeof full, "%s/%s", path, e->d_name);
            struct stat fs;
            if (stat(full, &fs) != 0 || !S_ISREG(fs.st_mode))
                continue;
            char **more = realloc(names, (size_t)(nnames + 1) * sizeof *more);
            if (!more)
                break;
            names = more;
            names[nnames++] = strdup(full);
        }
        closedir(d);
    } else {
        names = malloc(sizeof *names);
        if (names)
            names[nnames++] = strdup(path);
    }
    int rc = 0;
    for (int i = 0; i < nnames; i++) {
        if (rc == 0 && names[i]) {
            if (*n == *cap) {
                *cap = *cap ? 2 * *cap : 64;
                input *more = realloc(*list, (size_t)*cap * sizeof *more);
                if (!more)
                    return -1;
                *list = more;
            }
            rc = read_file(names[i], &(*list)[*n]);
            if (rc == 0)
                (*n)++;
        }
        free(names[i]);
    }
    free(names);
    return rc;
}

/* ------------------------------------------------------------------ */

/* Run the harness on a private copy of exactly `size` bytes. */
static int leak_check;
static int leaked;              /* a leak was found: stop checking */

static int run_one(const char *name, long k, const uint8_t *data, size_t size)
{
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy) {
        fprintf(stderr, "replay: out of memory\n");
        exit(2);
    }
    if (size)
        memcpy(copy, data, size);
    cur_name = name;
    cur_k = k;
    cur_data = copy;
    cur_size = size;
    fuzz_accepted = 0;
    LLVMFuzzerTestOneInput(copy, size);
    /* LeakSanitizer keeps reporting a leaked block at every later check,
     * so only the first leaking input can be named. */
    if (leak_check && !leaked && __lsan_do_recoverable_leak_check()) {
        leaked = 1;
        save_input("replay-leak.bin");
        fprintf(stderr, "replay: this input leaked (saved in "
                "replay-leak.bin): %s\n", repro);
    }
    cur_data = NULL;
    cur_size = 0;
    free(copy);
    return fuzz_accepted;
}

static void usage(void)
{
    fprintf(stderr, "usage: replay [--mutations N] [--seed S] [--dict FILE] "
            "[--only NAME:K] [--leak-check] [--verbose] PATH...\n");
}

int main(int argc, char **argv)
{
    long mutations = 100;
    uint64_t seed = 1;
    const char *only = NULL;
    int verbose = 0;
    input *list = NULL;
    int n = 0, cap = 0;
    builtin_tokens();

    int i = 1;
    for (; i < argc && argv[i][0] == '-' && argv[i][1] == '-'; i++) {
        const char *a = argv[i];
        char *end = NULL;
        if (!strcmp(a, "--verbose")) {
            verbose = 1;
            continue;
        }
        if (!strcmp(a, "--leak-check")) {
            if (!__lsan_do_recoverable_leak_check) {
                fprintf(stderr, "replay: --leak-check needs a build with "
                        "LeakSanitizer (-Db_sanitize=address)\n");
                return 2;
            }
            leak_check = 1;
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "replay: %s needs a value\n", a);
            return 2;
        }
        const char *v = argv[++i];
        errno = 0;
        if (!strcmp(a, "--mutations")) {
            mutations = strtol(v, &end, 10);
            if (errno || end == v || *end || mutations < 0) {
                fprintf(stderr, "replay: --mutations: expected a count >= "
                        "0, got \"%s\"\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--seed")) {
            seed = strtoull(v, &end, 10);
            if (errno || end == v || *end) {
                fprintf(stderr, "replay: --seed: expected an unsigned "
                        "integer, got \"%s\"\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--dict")) {
            if (read_dict(v) != 0)
                return 2;
        } else if (!strcmp(a, "--only")) {
            only = v;
            if (!strrchr(v, ':')) {
                fprintf(stderr, "replay: --only: expected NAME:K, got "
                        "\"%s\"\n", v);
                return 2;
            }
        } else {
            fprintf(stderr, "replay: unknown option %s\n", a);
            usage();
            return 2;
        }
    }
    if (i == argc) {
        usage();
        return 2;
    }
    for (int p = i; p < argc; p++)
        if (collect(argv[p], &list, &n, &cap) != 0)
            return 2;
    if (n == 0) {
        fprintf(stderr, "replay: no input files in the given paths\n");
        return 2;
    }
    qsort(list, (size_t)n, sizeof *list, cmp_input);

    if (__sanitizer_set_death_callback)
        __sanitizer_set_death_callback(report_crash);
    int sigs[] = {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL};
    for (size_t s = 0; s < sizeof sigs / sizeof sigs[0]; s++)
        signal(sigs[s], on_signal);

    const char *only_name = NULL;
    long only_k = -1;
    char only_buf[512];
    if (only) {
        snprintf(only_buf, sizeof only_buf, "%s", only);
        char *colon = strrchr(only_buf, ':');
        *colon = '\0';
        only_name = only_buf;
        char *end = NULL;
        only_k = strtol(colon + 1, &end, 10);
        if (end == colon + 1 || *end || only_k < 0) {
            fprintf(stderr, "replay: --only: expected NAME:K with K >= 0, "
                    "got \"%s\"\n", only);
            return 2;
        }
    }

    uint8_t *buf = malloc(REPLAY_MAX_MUTANT);
    if (!buf)
        return 2;
    long total = 0, accepted_mutants = 0;
    for (int f = 0; f < n; f++) {
        const input *in = &list[f];
        if (only_name && strcmp(in->name, only_name))
            continue;
        snprintf(repro, sizeof repro, "%s --seed %llu --only '%s:0' %s",
                 argv[0], (unsigned long long)seed, in->name, in->path);
        int ok = 1;
        if (!only || only_k == 0) {
            if (verbose)
                fprintf(stderr, "replay: %s\n", in->path);
            int acc = run_one(in->name, 0, in->data, in->size);
            total++;
            if (!strncmp(in->name, "good", 4) && !acc)
                ok = CHECK(0, "%s: a good_* file must be accepted",
                           in->path);
            else if (!strncmp(in->name, "bad", 3) && acc)
                ok = CHECK(0, "%s: a bad_* file must be refused", in->path);
        }
        uint64_t rng = seed ^ fnv1a(in->name);
        long last = only ? only_k : mutations;
        for (long k = 1; k <= last; k++) {
            size_t size = in->size < REPLAY_MAX_MUTANT ? in->size
                                                       : REPLAY_MAX_MUTANT;
            memcpy(buf, in->data, size);
            mutate(buf, &size, &rng);
            if (only && k != only_k)
                continue;
            snprintf(repro, sizeof repro, "%s --seed %llu --only '%s:%ld' "
                     "%s", argv[0], (unsigned long long)seed, in->name, k,
                     in->path);
            if (verbose)
                fprintf(stderr, "replay: %s mutant %ld (%zu bytes)\n",
                        in->path, k, size);
            if (only) {
                FILE *fp = fopen("replay-input.bin", "wb");
                if (fp) {
                    fwrite(buf, 1, size, fp);
                    fclose(fp);
                }
            }
            accepted_mutants += run_one(in->name, k, buf, size);
            total++;
        }
        if (ok)
            CHECK(1, "%s: the file and %ld mutants ran clean", in->path,
                  only ? (only_k > 0) : mutations);
    }
    printf("replay: %ld inputs from %d files, %ld mutants accepted\n", total,
           n, accepted_mutants);
    if (leak_check)
        CHECK(!leaked, "per-input leak check of %ld inputs: %s", total,
              leaked ? "a leak (the first leaking input is named above)"
                     : "no leak");
    /* From here on a sanitizer report (the leak check at exit) concerns
     * the whole run, not one input. */
    cur_name = "after the last input: a sanitizer check at exit, e.g. "
               "the leak check, covering the whole run";
    snprintf(repro, sizeof repro, "rerun with --leak-check to name the "
             "first input that leaks");
    free(buf);
    for (int f = 0; f < n; f++) {
        free(list[f].path);
        free(list[f].data);
    }
    free(list);
    for (int t = 0; t < ntokens; t++)
        free(tokens[t].bytes);
    if (only && total == 0) {
        fprintf(stderr, "replay: no file named %s in the given paths\n",
                only_buf);
        return 2;
    }
    return tc_done();
}
