/* hostile.c: the hostile-input suite (suite 'hostile', doc/hostile-input.md).
 *
 *   hostile TOWSTAB EXAMPLES_DIR XFAIL_LIST [--jobs N] [--time-scale X]
 *           [--only TEXT] [--keep] [--list]
 *
 * Runs the towstab command line, as a hostile user would, on
 *   - deterministic mutants of every shipped example (values: NaN, inf,
 *     huge, negative, zero, wrong units, wrong types; deleted lines and
 *     blocks; truncations; garbage; sizes),
 *   - misuse of the command line (issue 20's list and more),
 *   - output faults: device nodes (made with mknod, root only) and FIFOs
 *     in a temporary directory, symlinks, a full standard output
 *     (/dev/full: the one real /dev path used, and only as stdout), a
 *     read-only directory (not root only), existing targets,
 *   - SIGINT and SIGTERM during long runs, and progress on a terminal
 *     (a pseudo-terminal) against a file.
 * Every case runs in its own temporary directory under a time limit (of
 * CPU time, and four times that of wall time), in parallel. A case passes when the run is
 *   refused cleanly: exit 1 or 2, a line "towstab: error: ..." naming a
 *     file, key, line or option (or what the case says it must name), no
 *     "nan" in any message (user text quoted in it excepted), no output
 *     file left behind by a refusal (exit 2) and an existing one
 *     untouched, any JSON of a failed run valid and marked incomplete,
 *     nothing saying "trustworthy: yes" (in `run`, in the part of the
 *     analysis that failed);
 *   or ran: exit 0 with finite output (no nan or inf in the printed
 *     report, valid JSON, CSV without non-finite numbers);
 *   or, for the signal cases, stopped: exit 130 (SIGINT) or 143 (SIGTERM)
 *     with what it had written marked incomplete.
 * A death by a signal, a sanitizer report, a time-out, a damaged target
 * (a device, FIFO or symlink replaced), exit 0 after a failed write, or a
 * refusal where a run was due (and the reverse) fail the case. A run that
 * announces its cost ("estimated" on standard error) and is still going at
 * the limit is interrupted (SIGINT) and must then stop cleanly.
 *
 * XFAIL_LIST names cases expected to fail for now, one per line: the
 * case name, a tab, and the issue that will fix it. Such a case that fails
 * prints XFAIL; one that passes is an error (XPASS: remove its line), and
 * so is a line that names no case. Nothing is skipped silently: a case
 * that needs root (mknod) or not root (permissions) prints SKIP with why.
 *
 * Prints one line per case and a summary; exit status 0 when every case
 * passed or failed as listed, 1 otherwise, 2 on bad usage. */
#define _GNU_SOURCE
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

/* Time limit of a case: CPU s (times --time-scale), so that a loaded
 * machine does not make a slow case a hang; a case blocked without using
 * the CPU is stopped after WALL_FACTOR times that in wall time. */
#define CASE_TIMEOUT 60.0
#define WALL_FACTOR 4.0
/* After SIGINT to a run that announced its cost: time to stop, s. */
#define INTERRUPT_GRACE 15.0
/* Most arguments of one case. */
#define MAX_ARGS 24
/* Poll interval of the runner, s. */
#define POLL_S 0.005
/* The text a run prints on standard error before a long computation. */
#define COST_MARKER "estimated"

/* ---- small helpers ------------------------------------------------------ */

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "hostile: out of memory (%zu bytes)\n", n);
        exit(2);
    }
    return p;
}

static char *xstrdup(const char *s)
{
    size_t n = strlen(s) + 1;
    return memcpy(xmalloc(n), s, n);
}

static char *fmt(const char *f, ...)
{
    va_list ap;
    va_start(ap, f);
    char *s = NULL;
    if (vasprintf(&s, f, ap) < 0) {
        fprintf(stderr, "hostile: out of memory\n");
        exit(2);
    }
    va_end(ap);
    return s;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Whole file into a NUL-terminated buffer (*len without the NUL); NULL
 * when it cannot be read. */
static char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t cap = 4096, n = 0;
    char *buf = xmalloc(cap);
    for (;;) {
        if (n + 1 >= cap) {
            cap *= 2;
            char *b = realloc(buf, cap);
            if (!b) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = b;
        }
        size_t got = fread(buf + n, 1, cap - 1 - n, f);
        n += got;
        if (got == 0)
            break;
    }
    fclose(f);
    buf[n] = '\0';
    if (len)
        *len = n;
    return buf;
}

static int write_file(const char *path, const char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    int bad = fwrite(data, 1, len, f) != len;
    bad |= fclose(f) != 0;
    return bad ? -1 : 0;
}

/* A growing string. */
typedef struct sbuf {
    char *s;
    size_t n, cap;
} sbuf;

static void sb_add(sbuf *b, const char *p, size_t n)
{
    if (b->n + n + 1 > b->cap) {
        b->cap = (b->n + n + 1) * 2;
        char *s = realloc(b->s, b->cap);
        if (!s) {
            fprintf(stderr, "hostile: out of memory\n");
            exit(2);
        }
        b->s = s;
    }
    memcpy(b->s + b->n, p, n);
    b->n += n;
    b->s[b->n] = '\0';
}

static void sb_str(sbuf *b, const char *s) { sb_add(b, s, strlen(s)); }

/* splitmix64: the deterministic choices of the mutants. */
static uint64_t mix(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

static uint64_t hash_str(const char *s)
{
    uint64_t h = 1469598103934665603ULL;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ULL;
    return mix(h);
}

/* ---- cases -------------------------------------------------------------- */

enum expect {
    E_ANY,         /* refused cleanly or ran */
    E_REFUSE,      /* must be refused (exit 1 or 2) */
    E_BADINPUT,    /* must be refused as bad input (exit 2) */
    E_RUN,         /* must run (exit 0) */
    E_WRITE_FAILS, /* a write fails: exit 1 naming the target */
    E_INTERRUPT    /* a signal is sent: exit 128 + signal, output incomplete */
};

/* Targets prepared in the case directory before the run and checked
 * after it. */
enum setup {
    S_FIFO = 1 << 0,     /* @D/pipe: a FIFO with a reader */
    S_DEVNULL = 1 << 1,  /* @D/null: a character device like /dev/null */
    S_DEVFULL = 1 << 2,  /* @D/full: a character device like /dev/full */
    S_SYMLINK = 1 << 3,  /* @D/link.json -> target.json (existing) */
    S_DANGLING = 1 << 4, /* @D/dangling.json -> new.json (absent) */
    S_RODIR = 1 << 5,    /* @D/ro: a read-only directory */
    S_EXISTING = 1 << 6, /* @D/out.json and out.csv exist ("previous") */
    S_ROFILE = 1 << 7,   /* @D/out.json exists, mode 0444 */
    S_SUBDIR = 1 << 8    /* @D/dir: an empty directory */
};

typedef struct hcase {
    char *name;
    char *args[MAX_ARGS]; /* after the program; "@D" -> the case directory */
    int nargs;
    char *scene;          /* written to @D/<scene_file> when not NULL */
    size_t scene_len;
    char *scene_file;     /* the scene's file name (messages must name it) */
    char *stdin_path;     /* "@D/..." or a path; NULL: empty input */
    int stdout_full;      /* standard output is /dev/full */
    int expect;
    char *must_name;      /* the message must contain this */
    int setup;
    int sig;              /* signal sent after sig_after s, times the time
                             scale (0: none) */
    double sig_after;
    int pty;              /* standard error on a pseudo-terminal */
    int progress;         /* 1: must show progress, -1: must show none */
    int need_root, need_nonroot;
    double timeout;       /* 0: CASE_TIMEOUT */
    char *user_text;      /* a value the scene gives, which the report may
                             echo (a name "nan"): not checked for nan */
    int announce_ok;      /* may be interrupted after announcing its cost */
    int vm_limit_mb;      /* its address space is limited to this (MiB,
                             RLIMIT_AS; not under the sanitizers, which
                             reserve terabytes of shadow memory); 0: no
                             limit */
    int must_start;       /* must not be refused: it runs, or announces
                             its cost and is stopped */
    int write_fault;      /* the analysis runs, writing its output fails:
                             the report may say trustworthy */
    /* the xfail list's reason, when the case is listed */
    const char *xfail;
} hcase;

static hcase *cases;
static int ncases, capcases;

static hcase *add_case(const char *name)
{
    if (ncases == capcases) {
        capcases = capcases ? 2 * capcases : 256;
        hcase *c = realloc(cases, (size_t)capcases * sizeof *c);
        if (!c) {
            fprintf(stderr, "hostile: out of memory\n");
            exit(2);
        }
        cases = c;
    }
    hcase *c = &cases[ncases++];
    memset(c, 0, sizeof *c);
    c->name = xstrdup(name);
    return c;
}

static void arg(hcase *c, const char *a)
{
    if (c->nargs == MAX_ARGS) {
        fprintf(stderr, "hostile: case '%s' has too many arguments\n",
                c->name);
        exit(2);
    }
    c->args[c->nargs++] = xstrdup(a);
}

/* Arguments from a NULL-terminated list. */
static void args(hcase *c, ...)
{
    va_list ap;
    va_start(ap, c);
    for (const char *a; (a = va_arg(ap, const char *));)
        arg(c, a);
    va_end(ap);
}

static void set_scene(hcase *c, const char *file, const char *text,
                      size_t len)
{
    c->scene_file = xstrdup(file);
    c->scene = xmalloc(len + 1);
    memcpy(c->scene, text, len);
    c->scene[len] = '\0';
    c->scene_len = len;
}

/* ---- the shipped examples ----------------------------------------------- */

typedef struct example {
    char *path, *file, *stem;
    char *text;
    size_t len;
} example;

static example *examples;
static int nexamples;

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int load_examples(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "hostile: cannot open %s: %s\n", dir,
                strerror(errno));
        return -1;
    }
    char **names = NULL;
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        size_t l = strlen(e->d_name);
        if (l > 5 && !strcmp(e->d_name + l - 5, ".yaml")) {
            names = realloc(names, (size_t)(n + 1) * sizeof *names);
            names[n++] = xstrdup(e->d_name);
        }
    }
    closedir(d);
    qsort(names, (size_t)n, sizeof *names, cmp_str);
    examples = xmalloc((size_t)n * sizeof *examples);
    for (int i = 0; i < n; i++) {
        example *x = &examples[i];
        x->file = names[i];
        x->path = fmt("%s/%s", dir, names[i]);
        x->stem = xstrdup(names[i]);
        x->stem[strlen(x->stem) - 5] = '\0';
        x->text = read_file(x->path, &x->len);
        if (!x->text) {
            fprintf(stderr, "hostile: cannot read %s\n", x->path);
            return -1;
        }
    }
    nexamples = n;
    free(names);
    return n > 0 ? 0 : -1;
}

static const example *find_example(const char *stem)
{
    for (int i = 0; i < nexamples; i++)
        if (!strcmp(examples[i].stem, stem))
            return &examples[i];
    fprintf(stderr, "hostile: examples/%s.yaml is missing\n", stem);
    exit(2);
}

/* ---- scene mutants ------------------------------------------------------ */

/* One line of a scene: its bytes [start, end) without the newline, the
 * value of a "key: value" line [vstart, vend) when it has a scalar or
 * flow value, and whether it lies in the analyses list. */
typedef struct sline {
    size_t start, end;
    size_t kstart, kend, vstart, vend;
    int has_value, in_analyses, is_item;
} sline;

static int split_lines(const char *t, size_t len, sline **out)
{
    int n = 0, cap = 64, in_an = 0;
    sline *L = xmalloc((size_t)cap * sizeof *L);
    size_t p = 0;
    while (p < len) {
        size_t e = p;
        while (e < len && t[e] != '\n')
            e++;
        if (n == cap) {
            cap *= 2;
            L = realloc(L, (size_t)cap * sizeof *L);
        }
        sline *l = &L[n++];
        memset(l, 0, sizeof *l);
        l->start = p;
        l->end = e;
        size_t k = p;
        while (k < e && t[k] == ' ')
            k++;
        if (k == p && e - p >= 9 && !strncmp(t + p, "analyses:", 9))
            in_an = 1;
        else if (k == p && k < e && t[k] != '#' && t[k] != ' ')
            in_an = 0;
        l->in_analyses = in_an;
        if (k + 1 < e && t[k] == '-' && t[k + 1] == ' ') {
            l->is_item = 1;
            k += 2;
        }
        size_t c = k;
        while (c < e && (isalnum((unsigned char)t[c]) || t[c] == '_'))
            c++;
        if (c > k && c + 1 < e && t[c] == ':' && t[c + 1] == ' ') {
            size_t v = c + 2;
            while (v < e && t[v] == ' ')
                v++;
            size_t ve = e;
            /* A comment after the value ends it (not inside quotes). */
            int q = 0;
            for (size_t j = v; j < e; j++) {
                if (t[j] == '"')
                    q = !q;
                if (!q && t[j] == '#' && j > v && t[j - 1] == ' ') {
                    ve = j;
                    break;
                }
            }
            while (ve > v && t[ve - 1] == ' ')
                ve--;
            if (ve > v && t[v] != '#') {
                l->has_value = 1;
                l->kstart = k;
                l->kend = c;
                l->vstart = v;
                l->vend = ve;
            }
        }
        p = e < len ? e + 1 : e;
    }
    *out = L;
    return n;
}

/* Replacement values of a "key: value" line. */
static const char *const mutant_values[] = {
    ".nan", "NaN", ".inf", "-.inf", "1e300", "-1e300", "1e-300", "-1",
    "0", "-0.0", "\"3 kg\"", "\"12 furlong\"", "\"2 m/s/s/s\"", "[1, 2]",
    "{a: 1}", "\"\"", "~", "abc", "\"1e400 m\"", "4.9e-324", "0x10",
    "99999999999999999999999", "\"5 knot\"", "\"2 rad/s\"", "true",
    "!!binary aGVsbG8=", "*nowhere", "'%s%n%x'", "\"1 lbf\"", "\"-3 ft\"",
    "1e-12", "\"1 ft)\"", "\"nan m\"", "100000", "2.5"};
#define NVALUES (sizeof mutant_values / sizeof mutant_values[0])
/* Values tried on each "key: value" line. */
#define VALUES_PER_LINE 1

/* Garbage inserted at the start of a line. */
static const struct {
    const char *label, *text;
    size_t len;
} garbage[] = {
    {"tab", "\t", 1},
    {"colons", ": : :\n", 6},
    {"open brace", "{\n", 2},
    {"brackets", "]]]\n", 4},
    {"anchor", "x: &a [1, 2]\n", 13},
    {"merge of an unknown alias", "<<: *zz\n", 8},
    {"bytes ff fe 00", "\xff\xfe\x00\n", 4},
    {"NUL", "\x00", 1},
    {"directive", "%TAG ! tag:x,2000:\n", 19},
    {"document marker", "---\n", 4},
    {"complex key", "? [a, b]\n: 1\n", 13},
    {"control bytes", "\x01\x02\x1b[31m\n", 8},
    {"duplicate name key", "name: again\n", 12},
    {"deep indent", "                                        x: 1\n", 45},
};
#define NGARBAGE (sizeof garbage / sizeof garbage[0])

/* The command a mutant of example x runs: `run` (all the scene's
 * analyses) or, for a long example and a line outside its analyses,
 * `equilibrium` (the physics). Every few mutants also `modes`. */
static void mutant_command(hcase *c, const example *x, int in_analyses,
                           int k)
{
    /* Long runs: kamman_ex4's simulations; dolphin_aurora's 150 s
     * waypoint turn behind a Newton trim (about 3 s a run). */
    int long_run = !strcmp(x->stem, "kamman_ex4") ||
                   !strcmp(x->stem, "dolphin_aurora");
    char *scene = fmt("@D/%s", x->file);
    if (k % 5 == 4 && !in_analyses) {
        args(c, "modes", scene, "--quiet", "--json", "@D/out.json", NULL);
    } else if ((long_run && !in_analyses) || k % 3 == 2) {
        args(c, "equilibrium", scene, "--quiet", "--json", "@D/out.json",
             "--csv", "@D/out.csv", NULL);
    } else {
        args(c, "run", scene, "--quiet", "--json", "@D/out.json", NULL);
    }
    free(scene);
    c->announce_ok = 1;
}

static hcase *mutant(const example *x, const char *what, const char *text,
                     size_t len, int in_analyses, int k)
{
    char *name = fmt("scene %s: %s", x->stem, what);
    hcase *c = add_case(name);
    free(name);
    set_scene(c, x->file, text, len);
    mutant_command(c, x, in_analyses, k);
    return c;
}

/* Text of x with bytes [a, b) replaced by r[rlen]. */
static char *replaced(const example *x, size_t a, size_t b, const char *r,
                    size_t rlen, size_t *len)
{
    *len = x->len - (b - a) + rlen;
    char *t = xmalloc(*len + 1);
    memcpy(t, x->text, a);
    memcpy(t + a, r, rlen);
    memcpy(t + a + rlen, x->text + b, x->len - b);
    t[*len] = '\0';
    return t;
}

static void gen_scene_mutants(void)
{
    for (int e = 0; e < nexamples; e++) {
        const example *x = &examples[e];
        sline *L;
        int n = split_lines(x->text, x->len, &L);
        int k = 0;
        uint64_t h = hash_str(x->stem);
        /* Values. */
        for (int i = 0; i < n; i++) {
            if (!L[i].has_value)
                continue;
            uint64_t hl = mix(h + (uint64_t)i);
            for (int j = 0; j < VALUES_PER_LINE; j++) {
                const char *v =
                    mutant_values[(hl + (uint64_t)j * 13) % NVALUES];
                size_t len;
                char *t = replaced(x, L[i].vstart, L[i].vend, v, strlen(v),
                                 &len);
                char *what = fmt("line %d %.*s := %s", i + 1,
                                 (int)(L[i].kend - L[i].kstart),
                                 x->text + L[i].kstart, v);
                hcase *c = mutant(x, what, t, len, L[i].in_analyses, k++);
                c->user_text = xstrdup(v[0] == '"' || v[0] == '\''
                                           ? v + 1 : v);
                size_t ul = strlen(c->user_text);
                if (ul && (c->user_text[ul - 1] == '"' ||
                           c->user_text[ul - 1] == '\''))
                    c->user_text[ul - 1] = '\0';
                free(what);
                free(t);
            }
        }
        /* Deleted lines: every third line with a key, from an offset
         * that depends on the example. */
        for (int i = (int)(h % 3); i < n; i += 3) {
            if (!L[i].has_value && !(L[i].end > L[i].start &&
                                     x->text[L[i].start] != '#'))
                continue;
            size_t b = L[i].end < x->len ? L[i].end + 1 : L[i].end;
            size_t len;
            char *t = replaced(x, L[i].start, b, "", 0, &len);
            char *what = fmt("line %d deleted", i + 1);
            mutant(x, what, t, len, L[i].in_analyses, k++);
            free(what);
            free(t);
        }
        /* Deleted blocks: each top-level section, and each list item's
         * lines (a cable, a body, an analysis). */
        for (int i = 0; i < n; i++) {
            size_t s = L[i].start;
            int top = L[i].end > s && x->text[s] != ' ' &&
                      x->text[s] != '#';
            int item = L[i].is_item && L[i].has_value;
            if (!top && !item)
                continue;
            size_t indent = 0;
            while (x->text[s + indent] == ' ')
                indent++;
            int j = i + 1;
            for (; j < n; j++) {
                size_t q = L[j].start, ind = 0;
                while (q + ind < L[j].end && x->text[q + ind] == ' ')
                    ind++;
                if (q + ind == L[j].end || x->text[q + ind] == '#')
                    continue;
                if (ind <= indent)
                    break;
            }
            if (j == i + 1 && !top)
                continue;
            size_t b = j < n ? L[j].start : x->len;
            size_t len;
            char *t = replaced(x, s, b, "", 0, &len);
            char *what = fmt("lines %d-%d deleted (%s)", i + 1, j,
                             top ? "a section" : "a list item");
            mutant(x, what, t, len, L[i].in_analyses, k++);
            free(what);
            free(t);
        }
        /* Truncations. */
        for (int f = 1; f <= 6; f++) {
            size_t at = x->len * (size_t)f / 7;
            char *what = fmt("truncated at byte %zu of %zu", at, x->len);
            mutant(x, what, x->text, at, 0, k++);
            free(what);
        }
        /* Garbage at the start of a line. */
        for (int g = 0; g < 4; g++) {
            int gi = (int)((h >> (8 * g)) % NGARBAGE);
            int li = (int)(mix(h + 1000 + (uint64_t)g) % (uint64_t)n);
            size_t len;
            char *t = replaced(x, L[li].start, L[li].start, garbage[gi].text,
                             garbage[gi].len, &len);
            char *what = fmt("%s inserted at line %d", garbage[gi].label,
                             li + 1);
            mutant(x, what, t, len, L[li].in_analyses, k++);
            free(what);
            free(t);
        }
        /* Byte-level damage: a byte flipped, a byte deleted. */
        for (int g = 0; g < 2; g++) {
            size_t at = (size_t)(mix(h + 2000 + (uint64_t)g) % x->len);
            char r = (char)(x->text[at] ^ (g ? 0x20 : 0x80));
            size_t len;
            char *t = g ? replaced(x, at, at + 1, "", 0, &len)
                        : replaced(x, at, at + 1, &r, 1, &len);
            char *what = fmt("byte %zu %s", at, g ? "deleted" : "flipped");
            mutant(x, what, t, len, 0, k++);
            free(what);
            free(t);
        }
        /* Windows line ends and a byte-order mark: accepted. */
        {
            sbuf b = {0};
            sb_str(&b, "\xef\xbb\xbf");
            for (size_t p = 0; p < x->len; p++) {
                if (x->text[p] == '\n')
                    sb_add(&b, "\r", 1);
                sb_add(&b, x->text + p, 1);
            }
            hcase *c = mutant(x, "CRLF line ends and a BOM", b.s, b.n, 0,
                              0);
            c->expect = E_RUN;
            free(b.s);
        }
        free(L);
    }
}

/* ---- sizes -------------------------------------------------------------- */

static const char *const small_head =
    "name: sizes\n"
    "environment: {water_density: 1025, gravity: 9.81}\n"
    "tow: {speed: 2.5}\n";

static void gen_sizes(void)
{
    const example *ex1 = find_example("kamman_ex1_submerged");
    const example *ex5 = find_example("kamman_ex5_drop");
    sbuf b = {0};
    hcase *c;

    /* Links at and past the scene's limit. */
    static const char *const nl[] = {"1", "100000", "100001", "10000000"};
    for (size_t i = 0; i < sizeof nl / sizeof nl[0]; i++) {
        size_t len;
        const char *at = strstr(ex1->text, "links: 40");
        size_t a = (size_t)(at - ex1->text);
        char *v = fmt("links: %s", nl[i]);
        char *t = replaced(ex1, a, a + 9, v, strlen(v), &len);
        char *name = fmt("size: kamman_ex1_submerged with %s links", nl[i]);
        c = add_case(name);
        set_scene(c, ex1->file, t, len);
        args(c, "equilibrium", "@D/kamman_ex1_submerged.yaml", "--quiet",
             "--json", "@D/out.json", NULL);
        c->announce_ok = 1;
        free(name);
        free(t);
        free(v);
    }
    /* The drop test with 100 000 links (issue 20): a long simulation must
     * say its cost first. */
    {
        size_t len;
        const char *at = strstr(ex5->text, "links: 10");
        size_t a = (size_t)(at - ex5->text);
        char *t = replaced(ex5, a, a + 9, "links: 100000", 13, &len);
        c = add_case("size: run kamman_ex5_drop with 100000 links");
        set_scene(c, ex5->file, t, len);
        args(c, "run", "@D/kamman_ex5_drop.yaml", "--quiet", "--json",
             "@D/out.json", NULL);
        c->announce_ok = 1;
        free(t);
    }
    /* 20 000 one-link cables (issue 20: out of memory without a size). */
    sb_str(&b, small_head);
    sb_str(&b, "cables:\n");
    for (int i = 0; i < 20000; i++) {
        char line[160];
        snprintf(line, sizeof line,
                 "  - {name: c%d, from: tow, length: 1.5, diameter: 0.01, "
                 "weight: 1.2, links: 1}\n", i);
        sb_str(&b, line);
    }
    c = add_case("size: 20000 one-link cables, equilibrium");
    set_scene(c, "many_cables.yaml", b.s, b.n);
    args(c, "equilibrium", "@D/many_cables.yaml", "--quiet", "--json",
         "@D/out.json", NULL);
    c->announce_ok = 1;
    c = add_case("size: 20000 one-link cables, modes");
    set_scene(c, "many_cables.yaml", b.s, b.n);
    args(c, "modes", "@D/many_cables.yaml", "--quiet", NULL);
    c->announce_ok = 1;
    b.n = 0;
    /* A scene file of 17 MB (a comment after a good scene). */
    sb_add(&b, ex1->text, ex1->len);
    {
        char pad[4096];
        memset(pad, 'x', sizeof pad);
        pad[0] = '#';
        pad[sizeof pad - 1] = '\n';
        while (b.n < 17u * 1024 * 1024)
            sb_add(&b, pad, sizeof pad);
    }
    c = add_case("size: a 17 MB scene file");
    set_scene(c, ex1->file, b.s, b.n);
    args(c, "equilibrium", "@D/kamman_ex1_submerged.yaml", "--quiet", NULL);
    c->expect = E_BADINPUT;
    b.n = 0;
    /* Billion laughs: aliases that expand exponentially. */
    sb_str(&b, small_head);
    sb_str(&b, "cables:\n  - &a0 [x, x, x, x, x, x, x, x, x, x]\n");
    for (int i = 1; i < 10; i++) {
        char line[128];
        snprintf(line, sizeof line, "  - &a%d [*a%d, *a%d, *a%d, *a%d, "
                 "*a%d, *a%d, *a%d, *a%d, *a%d, *a%d]\n", i, i - 1,
                 i - 1, i - 1, i - 1, i - 1, i - 1, i - 1, i - 1, i - 1,
                 i - 1);
        sb_str(&b, line);
    }
    c = add_case("size: billion laughs (nested aliases)");
    set_scene(c, "laughs.yaml", b.s, b.n);
    args(c, "equilibrium", "@D/laughs.yaml", NULL);
    c->expect = E_BADINPUT;
    b.n = 0;
    /* Deep nesting. */
    sb_str(&b, small_head);
    sb_str(&b, "cables: ");
    for (int i = 0; i < 100000; i++)
        sb_add(&b, "[", 1);
    sb_add(&b, "\n", 1);
    c = add_case("size: 100000 nested lists");
    set_scene(c, "deep.yaml", b.s, b.n);
    args(c, "equilibrium", "@D/deep.yaml", NULL);
    c->expect = E_BADINPUT;
    b.n = 0;
    /* A 1 MB name. */
    sb_str(&b, "name: ");
    for (int i = 0; i < 1 << 20; i++)
        sb_add(&b, "n", 1);
    sb_add(&b, "\n", 1);
    {
        const char *rest = strstr(ex1->text, "\nenvironment:");
        sb_str(&b, rest + 1);
    }
    c = add_case("size: a 1 MB scene name");
    set_scene(c, ex1->file, b.s, b.n);
    args(c, "equilibrium", "@D/kamman_ex1_submerged.yaml", "--quiet", NULL);
    b.n = 0;
    /* 200 000 analyses. */
    sb_add(&b, ex1->text, ex1->len);
    for (int i = 0; i < 200000; i++)
        sb_str(&b, "  - equilibrium\n");
    c = add_case("size: 200000 analyses");
    set_scene(c, ex1->file, b.s, b.n);
    args(c, "run", "@D/kamman_ex1_submerged.yaml", "--quiet", NULL);
    c->announce_ok = 1;
    b.n = 0;
    /* An empty scene, and a scene of NUL bytes. */
    c = add_case("size: an empty scene file");
    set_scene(c, "empty.yaml", "", 0);
    args(c, "equilibrium", "@D/empty.yaml", NULL);
    c->expect = E_BADINPUT;
    {
        char z[1024];
        memset(z, 0, sizeof z);
        c = add_case("size: 1024 NUL bytes");
        set_scene(c, "zeros.yaml", z, sizeof z);
        args(c, "equilibrium", "@D/zeros.yaml", NULL);
        c->expect = E_BADINPUT;
    }
    free(b.s);
}

/* ---- command-line misuse ------------------------------------------------ */

#define EX1 "examples/kamman_ex1_submerged.yaml"
#define EX2 "examples/kamman_ex2_branched_turn.yaml"
#define EX4 "examples/kamman_ex4.yaml"
#define EX5 "examples/kamman_ex5_drop.yaml"

/* A misuse case: `towstab ARGS...` must be refused (exit 2 by default)
 * naming `must` (NULL: the generic rule). */
static hcase *misuse(int expect, const char *must, ...)
{
    va_list ap;
    sbuf name = {0};
    sb_str(&name, "cli: towstab");
    va_start(ap, must);
    hcase *c = add_case("");
    for (const char *a; (a = va_arg(ap, const char *));) {
        arg(c, a);
        sb_str(&name, " ");
        if (!*a || strpbrk(a, " ;"))
            sb_str(&name, "'"), sb_str(&name, a), sb_str(&name, "'");
        else
            sb_str(&name, a);
    }
    va_end(ap);
    free(c->name);
    c->name = name.s;
    c->expect = expect;
    c->must_name = must ? xstrdup(must) : NULL;
    return c;
}

/* Analyses that fail after a converged equilibrium (issue 20 part 1: no
 * verdict for a result not delivered). `run` delivers the analyses before
 * the failed one: they may say trustworthy, the failed one's part not. */
static void gen_after_equilibrium(void)
{
    const example *ex1 = find_example("kamman_ex1_submerged");
    const example *sea = find_example("survey_tow_sea");
    hcase *c;
    size_t len;
    const char *at = strstr(ex1->text, "analyses:");
    if (at) {
        static const char more[] = "analyses:\n  - equilibrium\n"
                                   "  - type: simulate\n    max_steps: 10\n";
        size_t a = (size_t)(at - ex1->text);
        char *t = replaced(ex1, a, ex1->len, more, sizeof more - 1, &len);
        c = add_case("after equilibrium: run kamman_ex1_submerged, "
                     "equilibrium then simulate to a step limit");
        set_scene(c, ex1->file, t, len);
        args(c, "run", "@D/kamman_ex1_submerged.yaml", "--json",
             "@D/out.json", NULL);
        c->expect = E_REFUSE;
        c->must_name = xstrdup("step limit");
        free(t);
    }
    /* A towfish 1e30 m across: the equilibrium converges (buoyancy 1e64 N
     * is below the load limit); what follows may fail. */
    at = sea ? strstr(sea->text, "diameter: \"0.5 m\"") : NULL;
    if (!at)
        return;
    size_t a = (size_t)(at - sea->text);
    char *t = replaced(sea, a, a + 17, "diameter: 1e30", 14, &len);
    static const char *const cmd[][4] = {
        {"run", NULL},
        {"response", "--output", "fish.z", NULL},
        {"response", "--output", "fish.z", NULL},
        {"modes", NULL}};
    for (int i = 0; i < 4; i++) {
        char *name = fmt("after equilibrium: %s survey_tow_sea with a "
                         "1e30 m towfish%s", cmd[i][0],
                         i == 2 ? " in a sea" : "");
        c = add_case(name);
        set_scene(c, sea->file, t, len);
        arg(c, cmd[i][0]);
        arg(c, "@D/survey_tow_sea.yaml");
        for (int k = 1; k < 4 && cmd[i][k]; k++)
            arg(c, cmd[i][k]);
        if (i == 2)
            args(c, "--sea", "Hs=4m,Tp=8s", NULL);
        args(c, "--quiet", "--json", "@D/out.json", NULL);
        c->expect = E_ANY;
        free(name);
    }
    free(t);
}

static void gen_cli_misuse(void)
{
    hcase *c;
    const int R = E_BADINPUT;
    /* The program and its commands. */
    misuse(R, "no command", NULL);
    misuse(R, "bogus", "bogus", EX1, NULL);
    misuse(E_RUN, NULL, "--help", NULL);
    misuse(E_RUN, NULL, "--version", NULL);
    static const char *const cmds[] = {"equilibrium", "modes", "response",
                                       "simulate", "converge", "run"};
    for (int i = 0; i < 6; i++) {
        const char *cmd = cmds[i];
        misuse(E_RUN, NULL, cmd, "--help", NULL);
        misuse(R, "scene file", cmd, NULL);
        misuse(R, "scene file", cmd, EX1, EX2, NULL);
        misuse(R, "--bogus", cmd, EX1, "--bogus", NULL);
        misuse(R, "--json", cmd, EX1, "--json", NULL);
        misuse(R, "/nonexistent/scene.yaml", cmd, "/nonexistent/scene.yaml",
               NULL);
        misuse(R, NULL, cmd, "@D", NULL); /* a directory as the scene */
    }
    /* Shared settings. */
    static const struct {
        const char *opt, *val;
        int expect;
    } settings[] = {
        {"--speed", "-1", E_BADINPUT},
        {"--speed", "1e300", E_REFUSE},
        {"--speed", "nan", E_BADINPUT},
        {"--speed", "inf", E_BADINPUT},
        {"--speed", "", E_BADINPUT},
        {"--speed", "3 kg", E_BADINPUT},
        {"--speed", "5 knot", E_RUN},
        {"--speed", "0", E_ANY},
        {"--speed", "1e-300", E_ANY},
        {"--turn-rate", "nan", E_BADINPUT},
        {"--turn-rate", "1e300", E_REFUSE},
        {"--turn-rate", "1 m", E_BADINPUT},
        {"--links", "0", E_BADINPUT},
        {"--links", "-1", E_BADINPUT},
        {"--links", "abc", E_BADINPUT},
        {"--links", "2.5", E_BADINPUT},
        {"--links", "", E_BADINPUT},
        {"--links", "1e9", E_BADINPUT},
        {"--links", "10000000", E_BADINPUT},
        {"--equilibrium-method", "bogus", E_BADINPUT},
        {"--equilibrium-method", "", E_BADINPUT},
        {"--tol", "0", E_BADINPUT},
        {"--tol", "1", E_BADINPUT},
        {"--tol", "nan", E_BADINPUT},
        {"--tol", "-1e-8", E_BADINPUT},
        {"--tol", "1e-300", E_REFUSE},
    };
    for (size_t i = 0; i < sizeof settings / sizeof settings[0]; i++) {
        /* The option, or the quantity it sets ("turn rate"). */
        const char *must = settings[i].expect == E_RUN ||
                                   settings[i].expect == E_ANY
                               ? NULL
                           : !strcmp(settings[i].opt, "--turn-rate")
                               ? "turn"
                               : settings[i].opt + 2;
        misuse(settings[i].expect, must, "equilibrium", EX1, "--quiet",
               settings[i].opt, settings[i].val, NULL);
    }
    misuse(R, "speed", "modes", EX1, "--quiet", "--speed", "-1", NULL);
    misuse(R, "speed", "simulate", EX1, "--quiet", "--speed", "-1", NULL);
    misuse(R, "--speed", "run", EX1, "--speed", "1", NULL);
    misuse(R, "--quiet", "equilibrium", EX1, "--quiet=yes", NULL);
    misuse(R, "--json", "equilibrium", EX1, "--json", "", NULL);
    misuse(R, "--csv", "equilibrium", EX1, "--csv", "", NULL);
    misuse(R, "--units", "equilibrium", EX1, "--plot", "@D/p", "--units",
           "bogus", NULL);
    /* Overlays of the equilibrium pictures: each value checked, a failed
     * one refused without a crash or pictures. */
    static const char *const overlays[][2] = {
        {"--overlay-speeds", "1,-1"}, {"--overlay-speeds", "1,nan"},
        {"--overlay-speeds", ""}, {"--overlay-speeds", "1e300,2"},
        {"--overlay-turn-rates", "1e300"}, {"--overlay-turn-rates", "3 m"},
        {"--overlay", "/nonexistent.yaml"}, {"--overlay", ""}};
    for (int i = 0; i < 8; i++)
        misuse(R, NULL, "equilibrium", EX1, "--quiet", "--plot", "@D/p",
               overlays[i][0], overlays[i][1], NULL);
    /* Standard input as the scene. */
    c = misuse(E_RUN, NULL, "equilibrium", "-", "--quiet", NULL);
    c->stdin_path = xstrdup(EX1);
    c = misuse(R, "standard input", "equilibrium", "-", NULL);
    /* --set on a vehicle's keys: an unknown key names the path and lists
     * the keys a vehicle takes; a hull shorter than its diameter (no
     * spheroid added mass) names the vehicle. */
    misuse(R, "bodies.aurora.volum: no key 'volum' of a body; expected one "
              "of diameter, length, mass, weight, wet_weight, drag, "
              "added_mass, cross_drag, cross_added_mass; or of a vehicle "
              "volume, inertia.xx|yy|zz|xy|xz|yz", "equilibrium",
           "examples/aurora_towfish.yaml", "--quiet", "--set",
           "bodies.aurora.volum=0.2", NULL);
    misuse(R, "the added mass of vehicle 'aurora'", "equilibrium",
           "examples/aurora_towfish.yaml", "--quiet", "--set",
           "bodies.aurora.components.hull.length=0.3", NULL);
    misuse(R, "name an entry: inertia.xx|yy|zz|xy|xz|yz", "equilibrium",
           "examples/aurora_towfish.yaml", "--quiet", "--set",
           "bodies.aurora.inertia=3", NULL);
    /* --set on the towing vehicle (towing_vehicle.<key>): an unknown key
     * lists what it takes, a key of another propulsion law names the
     * law, a value beyond its limit, a non-number, a unit of another
     * quantity, the vehicle named as a body, and towing_vehicle in a
     * scene without one. */
    {
        static const char *const tv[][2] = {
            {"towing_vehicle.mas=4000", "no key 'mas' of the towing vehicle; "
             "expected one of mass, weight, wet_weight, volume"},
            {"towing_vehicle.propulsion.power=20kW", "propulsion is thrust, "
             "which has no 'power'; its keys: thrust, at.x|y|z"},
            {"towing_vehicle.propulsion.thrust=nan",
             "towing_vehicle.propulsion.thrust"},
            {"towing_vehicle.propulsion.thrust=3 kg",
             "towing_vehicle.propulsion.thrust"},
            {"towing_vehicle.propulsion.thrust=1e400",
             "towing_vehicle.propulsion.thrust"},
            {"towing_vehicle.volume=-1", "must be >= 0 m^3"},
            {"towing_vehicle.tow_point=1", "name an entry: tow_point.x|y|z"},
            {"towing_vehicle.attach.x=1", "no key 'attach.x' of the towing "
             "vehicle"},
            {"towing_vehicle.components.fin.area=1", "vehicle 'dolphin' has "
             "no component 'fin'"},
            {"towing_vehicle.controllers.depth.kq=1", "no key 'kq' of a loop"},
            {"bodies.dolphin.mass=1", "'dolphin' is the towing vehicle"},
            {"towing_vehicle.=1", "towing_vehicle."},
        };
        for (size_t i = 0; i < sizeof tv / sizeof tv[0]; i++)
            misuse(R, tv[i][1], "equilibrium", "examples/dolphin_aurora.yaml",
                   "--quiet", "--set", tv[i][0], NULL);
        misuse(R, "the scene has no towing_vehicle", "equilibrium",
               "examples/aurora_towfish.yaml", "--quiet", "--set",
               "towing_vehicle.mass=4000", NULL);
    }
    /* modes */
    misuse(R, "160 states", "modes", EX1, "--quiet", "--eigen-method",
           "arpack", "--count", "79", NULL);
    misuse(R, "--count", "modes", EX1, "--count", "0", NULL);
    misuse(R, "--count", "modes", EX1, "--count", "-3", NULL);
    misuse(R, "--count", "modes", EX1, "--count", "abc", NULL);
    misuse(R, "--count", "modes", EX1, "--count", "1000000000", NULL);
    misuse(R, "--eigen-method", "modes", EX1, "--eigen-method", "bogus",
           NULL);
    misuse(R, "--near", "modes", EX1, "--near", "nan", NULL);
    misuse(R, "--near", "modes", EX1, "--near", "3 kg", NULL);
    misuse(R, "--equilibrium-method", "modes", EX1, "--equilibrium-method",
           "bogus", NULL);
    /* response */
    misuse(R, "--input", "response", EX1, "--output", "sphere.z", "--input",
           "bogus", NULL);
    misuse(R, "--output", "response", EX1, "--output", "bogus.z", NULL);
    misuse(R, "--output", "response", EX1, "--output", "", NULL);
    misuse(R, "--from", "response", EX1, "--output", "sphere.z", "--from",
           "0", NULL);
    misuse(R, "--from", "response", EX1, "--output", "sphere.z", "--from",
           "-1", NULL);
    misuse(R, "--from", "response", EX1, "--output", "sphere.z", "--from",
           "nan", NULL);
    misuse(R, NULL, "response", EX1, "--output", "sphere.z", "--from", "10",
           "--to", "0.1", NULL);
    misuse(R, "--points", "response", EX1, "--output", "sphere.z",
           "--points", "0", NULL);
    misuse(R, "--points", "response", EX1, "--output", "sphere.z",
           "--points", "1000000000", NULL);
    /* simulate: one option with a bad value, named in the refusal. */
    static const struct {
        const char *opt, *val;
        int expect;
    } sim[] = {
        {"--excite", "", E_BADINPUT},
        {"--excite", "tow.heave:amplitude=nan,frequency=1Hz", E_BADINPUT},
        {"--excite", "tow.heave:amplitude=1e300m,frequency=1Hz", E_REFUSE},
        {"--excite", "tow.bogus:amplitude=0.1m,frequency=1Hz", E_BADINPUT},
        {"--excite", "tow.heave:type=csv,file=/nonexistent.csv", E_BADINPUT},
        {"--manoeuvre", "speed:to=-5,duration=1s", E_BADINPUT},
        {"--manoeuvre", "turn_rate:to=1e300rad/s,duration=1s", E_REFUSE},
        {"--manoeuvre", "speed:to=5m/s,duration=-1s", E_BADINPUT},
        {"--manoeuvre", "", E_BADINPUT},
        {"--t-end", "0", E_BADINPUT},
        {"--t-end", "-1", E_BADINPUT},
        {"--t-end", "nan", E_BADINPUT},
        {"--t-end", "3 kg", E_BADINPUT},
        {"--sample", "0", E_BADINPUT},
        {"--rtol", "0", E_BADINPUT},
        {"--rtol", "1", E_BADINPUT},
        {"--atol", "0", E_BADINPUT},
        {"--atol", "nan", E_BADINPUT},
        {"--integrator", "bogus", E_BADINPUT},
        {"--initial", "bogus", E_BADINPUT},
        {"--initial", "shape:", E_BADINPUT},
        {"--initial", "shape:/nonexistent.csv", E_BADINPUT},
        {"--initial", "released:theta1=nan", E_BADINPUT},
        {"--max-steps", "0", E_BADINPUT},
        {"--sea", "Hs=1e300m,Tp=10s", E_BADINPUT},
        {"--sea", "bogus", E_BADINPUT},
        {"--sea", "Hs=nan,Tp=10s", E_BADINPUT},
        {"--sea", "Hs=4m,Tp=0s", E_BADINPUT},
        {"--sea", "file=/nonexistent.csv", E_BADINPUT},
    };
    for (size_t i = 0; i < sizeof sim / sizeof sim[0]; i++)
        misuse(sim[i].expect, sim[i].opt, "simulate", EX1, "--quiet",
               sim[i].opt, sim[i].val, NULL);
    misuse(R, "--excite", "simulate", EX1, "--quiet", "--excite",
           "tow.heave:amplitude=0.1m,frequency=1e6Hz", "--t-end", "1", NULL);
    misuse(R, "--sample", "simulate", EX1, "--quiet", "--t-end", "1",
           "--sample", "100", NULL);
    misuse(R, "--rao", "simulate", EX1, "--quiet", "--rao",
           "/nonexistent.csv", "--sea", "Hs=4m,Tp=10s", NULL);
    /* Seas beyond any sea: refused as the spec is read, naming the key. */
    misuse(R, "--sea: Tp", "simulate", EX1, "--quiet", "--sea",
           "Hs=4m,Tp=1e-6s", "--json", "@D/out.json", NULL);
    static const char *const seas[][2] = {{"Hs=1e300m,Tp=10s", "--sea: Hs"},
                                          {"Hs=4m,Tp=1e-6s", "--sea: Tp"},
                                          {"Hs=4m,Tp=1e300s", "--sea: Tp"},
                                          {"Hs=4m,Tp=10s,heading=nan",
                                           "--sea: heading"}};
    for (int i = 0; i < 4; i++)
        misuse(R, seas[i][1], "response", EX1, "--quiet", "--output",
               "sphere.z", "--sea", seas[i][0], NULL);
    misuse(R, "--transient", "simulate", EX1, "--quiet", "--t-end", "10",
           "--transient", "100", NULL);
    misuse(R, NULL, "simulate", EX1, "--quiet", "--compare", "--linear",
           NULL);
    misuse(R, "--output", "simulate", EX1, "--quiet", "--output", "bogus.z",
           NULL);
    misuse(E_RUN, NULL, "simulate", EX1, "--quiet", "--output",
           "cable.1.tension", NULL);
    misuse(R, "--output", "simulate", EX1, "--quiet", "--output",
           "tow.force", "--compare", NULL);
    misuse(R, "--outputs", "simulate", EX1, "--quiet", "--outputs",
           "sphere.z,,tow.force", NULL);
    misuse(R, "--outputs", "simulate", EX1, "--quiet", "--outputs",
           "sphere.z,sphere.z", NULL);
    misuse(R, "--outputs", "simulate", EX1, "--quiet", "--outputs",
           "cable.1.strain", NULL);
    misuse(R, "--snapshot-interval", "simulate", EX1, "--quiet",
           "--snapshot-interval", "1", NULL);
    misuse(R, "--h-min", "simulate", EX1, "--quiet", "--h-min", "-1", NULL);
    /* Failed runs: exit 1, nothing says trustworthy (issue 20). */
    misuse(E_REFUSE, "h_min", "simulate", EX4, "--quiet", "--h-min", "0.5",
           "--json", "@D/out.json", NULL);
    misuse(E_REFUSE, "step limit", "simulate", EX1, "--quiet", "--max-steps",
           "10", "--json", "@D/out.json", NULL);
    /* Announced long runs (interrupted by the suite). */
    c = misuse(E_ANY, NULL, "simulate", EX1, "--quiet", "--t-end", "1e9",
               "--sample", "100", "--json", "@D/out.json", NULL);
    c->announce_ok = 1;
    /* The same in 1 GiB of address space: its history of 1e7 samples
     * (14 GB at 40 links) grows as the run fills it instead of being
     * reserved up front, so the run starts, says what it will cost and is
     * stopped (it was refused, out of memory, before). */
    c = misuse(E_ANY, NULL, "simulate", EX1, "--quiet", "--t-end", "1e9",
               "--sample", "100", "--json", "@D/out.json", NULL);
    char *in_1g = fmt("%s, in 1 GiB of address space", c->name);
    free(c->name);
    c->name = in_1g;
    c->announce_ok = 1;
    c->vm_limit_mb = 1024;
    c->must_start = 1;
    /* converge */
    misuse(R, "--links", "converge", EX1, "--links", "5,abc", NULL);
    misuse(R, "--links", "converge", EX1, "--links", "", NULL);
    misuse(R, "--links", "converge", EX1, "--links", "0,5", NULL);
    misuse(R, "--analysis", "converge", EX1, "--analysis", "bogus", NULL);
    misuse(R, "--target", "converge", EX1, "--target", "nan", NULL);
    misuse(R, "--tolerances", "converge", EX1, "--tolerances", "1e-3,-1",
           NULL);
    misuse(R, "--integrators", "converge", EX1, "--analysis", "simulate",
           "--integrators", "rk8pd,bogus", NULL);
}

/* ---- output faults ------------------------------------------------------ */

static hcase *fault(const char *name, int setup, int expect,
                    const char *must)
{
    char *n = fmt("output: %s", name);
    hcase *c = add_case(n);
    free(n);
    c->setup = setup;
    c->expect = expect;
    c->write_fault = expect == E_WRITE_FAILS || expect == E_REFUSE;
    c->must_name = must ? xstrdup(must) : NULL;
    return c;
}

static void gen_output_faults(void)
{
    hcase *c;
    /* The analyses on the FIFO and the devices: equilibrium JSON and CSV,
     * modes JSON, simulate JSON. */
    static const struct {
        const char *label, *cmd, *scene, *opt;
    } w[] = {
        {"equilibrium --json", "equilibrium", EX1, "--json"},
        {"equilibrium --csv", "equilibrium", EX1, "--csv"},
        {"modes --json", "modes", EX1, "--json"},
        {"simulate --json", "simulate", EX5, "--json"},
    };
    for (size_t i = 0; i < sizeof w / sizeof w[0]; i++) {
        char *n = fmt("%s to a FIFO", w[i].label);
        c = fault(n, S_FIFO, E_RUN, NULL);
        args(c, w[i].cmd, w[i].scene, "--quiet", w[i].opt, "@D/pipe", NULL);
        free(n);
        n = fmt("%s to a device like /dev/null", w[i].label);
        c = fault(n, S_DEVNULL, E_RUN, NULL);
        args(c, w[i].cmd, w[i].scene, "--quiet", w[i].opt, "@D/null", NULL);
        c->need_root = 1;
        free(n);
        n = fmt("%s to a device like /dev/full", w[i].label);
        c = fault(n, S_DEVFULL, E_WRITE_FAILS, "full");
        args(c, w[i].cmd, w[i].scene, "--quiet", w[i].opt, "@D/full", NULL);
        c->need_root = 1;
        free(n);
    }
    /* A full standard output. */
    static const char *const full_stdout[][8] = {
        {"equilibrium", EX1, NULL},
        {"equilibrium", EX1, "--quiet", NULL},
        {"modes", EX1, NULL},
        {"response", EX1, "--output", "sphere.z", NULL},
        {"simulate", EX5, NULL},
        {"run", EX2, NULL},
        {"equilibrium", EX1, "--quiet", "--json", "-", NULL},
        {"equilibrium", EX1, "--quiet", "--csv", "-", NULL},
        {"converge", EX1, "--links", "5,10,20", NULL},
        {"equilibrium", "--help", NULL},
    };
    for (size_t i = 0; i < sizeof full_stdout / sizeof full_stdout[0];
         i++) {
        sbuf n = {0};
        sb_str(&n, "stdout /dev/full:");
        for (int j = 0; full_stdout[i][j]; j++) {
            sb_str(&n, " ");
            sb_str(&n, full_stdout[i][j]);
        }
        c = fault(n.s, 0, E_WRITE_FAILS, "standard output");
        for (int j = 0; full_stdout[i][j]; j++)
            arg(c, full_stdout[i][j]);
        c->stdout_full = 1;
        free(n.s);
    }
    /* Symlinks: the link stays, its target is replaced. */
    c = fault("--json to a symlink", S_SYMLINK, E_RUN, NULL);
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/link.json", NULL);
    c = fault("--json to a dangling symlink", S_DANGLING, E_RUN, NULL);
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/dangling.json",
         NULL);
    /* The same file twice. */
    c = fault("--json and --csv to the same file", 0, E_BADINPUT,
              "same.out");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/same.out", "--csv",
         "@D/same.out", NULL);
    c = fault("--json and --csv to the same file by two paths", 0,
              E_BADINPUT, "same.out");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/same.out", "--csv",
         "@D/./same.out", NULL);
    c = fault("--json to a symlink and --csv to its target", S_SYMLINK,
              E_BADINPUT, "target.json");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/link.json",
         "--csv", "@D/target.json", NULL);
    /* Existing targets survive a refusal. */
    c = fault("refused run keeps an existing --json and --csv", S_EXISTING,
              E_BADINPUT, "--speed");
    args(c, "equilibrium", EX1, "--quiet", "--speed", "nan", "--json",
         "@D/out.json", "--csv", "@D/out.csv", NULL);
    c = fault("bad scene keeps an existing --json", S_EXISTING, E_BADINPUT,
              "nonexistent");
    args(c, "equilibrium", "@D/nonexistent.yaml", "--json", "@D/out.json",
         NULL);
    /* Directories and missing folders. */
    c = fault("--json to a directory", S_SUBDIR, E_REFUSE, "dir");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/dir", NULL);
    c = fault("--json into a missing folder", 0, E_REFUSE, "missing");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/missing/out.json",
         NULL);
    c = fault("--plot to a regular file", S_EXISTING, E_REFUSE, "out.json");
    args(c, "equilibrium", EX1, "--quiet", "--plot", "@D/out.json", NULL);
    /* Permissions (root ignores them). */
    c = fault("--json into a read-only directory", S_RODIR, E_REFUSE, "ro");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/ro/out.json", NULL);
    c->need_nonroot = 1;
    c = fault("--json over a read-only file", S_ROFILE, E_REFUSE,
              "out.json");
    args(c, "equilibrium", EX1, "--quiet", "--json", "@D/out.json", NULL);
    c->need_nonroot = 1;
    /* A failed analysis writes its JSON marked incomplete (issue 20). */
    {
        const example *ex1 = find_example("kamman_ex1_submerged");
        size_t len;
        const char *at = strstr(ex1->text, "weight: \"1 lbf/ft\"");
        size_t a = (size_t)(at - ex1->text);
        char *t = replaced(ex1, a, a + 18, "weight: 1e300", 13, &len);
        c = fault("failed equilibrium (cable weight 1e300) --json", 0,
                  E_REFUSE, NULL);
        set_scene(c, ex1->file, t, len);
        args(c, "equilibrium", "@D/kamman_ex1_submerged.yaml", "--quiet",
             "--json", "@D/out.json", NULL);
        free(t);
    }
}

/* ---- signals and progress ----------------------------------------------- */

/* A long simulation of example 1 (100 000 s), sent signal `sig` after
 * `after` s; it must stop with exit 128 + sig. */
static hcase *long_run(const char *name, int sig, double after)
{
    hcase *c = add_case(name);
    args(c, "simulate", EX1, "--quiet", "--t-end", "100000", "--sample", "10",
         NULL);
    c->expect = E_INTERRUPT;
    c->sig = sig;
    c->sig_after = after;
    return c;
}

static void gen_signals(void)
{
    hcase *c;
    static const struct {
        int sig;
        const char *name;
    } sigs[] = {{SIGINT, "SIGINT"}, {SIGTERM, "SIGTERM"}};
    for (int i = 0; i < 2; i++) {
        char *n = fmt("signal: %s during a long simulation", sigs[i].name);
        c = long_run(n, sigs[i].sig, 1.0);
        args(c, "--json", "@D/out.json", "--csv", "@D/out.csv", NULL);
        free(n);
        n = fmt("signal: %s during converge --analysis simulate",
                sigs[i].name);
        c = add_case(n);
        free(n);
        args(c, "converge", EX4, "--quiet", "--analysis", "simulate",
             "--tolerances", "1e-4,1e-6,1e-8,1e-10,1e-12", "--t-end", "200",
             "--json", "@D/out.json", NULL);
        c->expect = E_INTERRUPT;
        c->sig = sigs[i].sig;
        c->sig_after = 1.0;
    }
    c = long_run("signal: SIGINT during a long simulation, --json -", SIGINT,
                 1.0);
    args(c, "--json", "-", NULL);
    /* A frequency sweep stops after its current frequency; a dense
     * eigensolve cannot poll: the stop is taken after it (the equilibrium
     * written, marked incomplete), or at once, writing nothing, when it
     * has not returned within 5 s of the signal (issue 15). */
    c = add_case("signal: SIGINT during a response of 1e6 frequencies");
    args(c, "response", EX1, "--quiet", "--output", "sphere.z", "--points",
         "1000000", "--json", "@D/out.json", NULL);
    c->expect = E_INTERRUPT;
    c->sig = SIGINT;
    c->must_name = xstrdup("stopped on request after");
    c->sig_after = 2.0; /* well into the sweep */
    const example *ex1 = find_example("kamman_ex1_submerged");
    const char *at = ex1 ? strstr(ex1->text, "links: 40") : NULL;
    if (at) {
        size_t len, a = (size_t)(at - ex1->text);
        char *t = replaced(ex1, a, a + 9, "links: 400", 10, &len);
        c = add_case("signal: SIGTERM during a dense eigensolve of 1600 "
                     "states");
        set_scene(c, ex1->file, t, len);
        args(c, "modes", "@D/kamman_ex1_submerged.yaml", "--quiet",
             "--eigen-method", "lapack", "--json", "@D/out.json", NULL);
        c->expect = E_INTERRUPT;
        c->sig = SIGTERM;
        c->sig_after = 1.0;
        /* "stopped on request" after LAPACK's call, or "stopped at once"
         * when it has not returned within the grace (under load). */
        free(t);
    }
    /* Large modes (ARPACK on the sparse model), a Newton equilibrium and
     * a sea-state response stop at their next poll, writing what they
     * have marked incomplete: the equilibrium reached (with its
     * residual), the linear model. */
    c = add_case("signal: SIGINT during modes of 20000 links (ARPACK)");
    args(c, "modes", EX1, "--quiet", "--links", "20000",
         "--no-discretisation-error", "--json", "@D/out.json", NULL);
    c->expect = E_INTERRUPT;
    c->sig = SIGINT;
    /* Early (the run lasts about 4 s here, 8 s under the sanitizers): a
     * signal after its last poll would let it complete. */
    c->sig_after = 1.0;
    c->must_name = xstrdup("stopped on request");
    c->progress = -1;
    c = add_case("signal: SIGINT during a Newton equilibrium of 2000 links");
    args(c, "equilibrium", EX1, "--quiet", "--links", "2000",
         "--equilibrium-method", "newton", "--no-discretisation-error",
         "--json", "@D/out.json", NULL);
    c->expect = E_INTERRUPT;
    c->sig = SIGINT;
    c->sig_after = 1.0;
    c->must_name = xstrdup("stopped on request");
    c->progress = -1;
    c = add_case("progress: a sea-state response on a terminal, then SIGINT");
    args(c, "response", "examples/survey_tow_sea.yaml", "--quiet", "--output",
         "fish.z", "--sea", "Hs=4m,Tp=8s,gamma=3.3,heading=180deg",
         "--intervals", "524288", "--json", "@D/out.json", NULL);
    c->expect = E_INTERRUPT;
    c->sig = SIGINT;
    c->sig_after = 4.0; /* the grid takes about 2 s to set up */
    c->must_name = xstrdup("stopped on request after");
    c->pty = 1;
    c->progress = 1;
    /* Progress: on a terminal, not on a file. */
    c = long_run("progress: shown when standard error is a terminal", SIGINT,
                 2.5);
    c->pty = 1;
    c->progress = 1;
    c = long_run("progress: quiet when standard error is a file", SIGINT,
                 2.5);
    c->progress = -1;
}

/* ---- the xfail list ----------------------------------------------------- */

static int read_xfail(const char *path)
{
    char *text = read_file(path, NULL);
    if (!text) {
        fprintf(stderr, "hostile: cannot read %s\n", path);
        return -1;
    }
    int bad = 0, lineno = 0;
    for (char *save = NULL, *line = strtok_r(text, "\n", &save); line;
         line = strtok_r(NULL, "\n", &save)) {
        lineno++;
        if (line[0] == '#' || line[0] == '\0')
            continue;
        char *tab = strchr(line, '\t');
        if (!tab) {
            fprintf(stderr, "%s:%d: expected NAME<tab>ISSUE\n", path,
                    lineno);
            bad = 1;
            continue;
        }
        *tab = '\0';
        const char *why = tab + 1;
        while (*why == '\t')
            why++;
        int found = 0;
        for (int i = 0; i < ncases; i++)
            if (!strcmp(cases[i].name, line)) {
                cases[i].xfail = xstrdup(why);
                found = 1;
            }
        if (!found) {
            printf("FAIL xfail list %s:%d names no case: '%s' (remove it)\n",
                   path, lineno, line);
            bad = 1;
        }
    }
    free(text);
    return bad;
}

/* ---- checks ------------------------------------------------------------- */

/* Text with quoted parts ("..." and '...', user input echoed) blanked. */
static char *unquoted(const char *s)
{
    char *t = xstrdup(s);
    char q = 0;
    for (char *p = t; *p; p++) {
        if (q) {
            if (*p == q)
                q = 0;
            else if (*p != '\n')
                *p = ' ';
        } else if (*p == '"' || (*p == '\'' && (p == t || !isalnum(
                                                        (unsigned char)p[-1])))) {
            q = *p;
        }
    }
    return t;
}

/* s with every occurrence of the user's text u blanked (in place). */
static void blank_user_text(char *s, const char *u)
{
    size_t n = u ? strlen(u) : 0;
    if (!n)
        return;
    for (char *p = s; (p = strstr(p, u)); p += n)
        memset(p, ' ', n);
}

/* A word w (nan, inf) standing alone in s, case-insensitive. */
static int has_word(const char *s, const char *w)
{
    size_t n = strlen(w);
    for (const char *p = s; (p = strcasestr(p, w)); p++) {
        int before = p > s && isalpha((unsigned char)p[-1]);
        int after = isalpha((unsigned char)p[n]);
        if (!before && !after)
            return 1;
    }
    return 0;
}

/* "@D..." -> the case directory. */
static char *expand(const char *a, const char *dir)
{
    if (!strncmp(a, "@D", 2))
        return fmt("%s%s", dir, a + 2);
    return xstrdup(a);
}

/* The message names a file (the scene, or a path argument), a key, a line
 * or an option. */
static int names_something(const char *msg, const hcase *c, const char *dir)
{
    if (c->scene_file && strstr(msg, c->scene_file))
        return 1;
    for (int i = 0; i < c->nargs; i++) {
        const char *a = c->args[i];
        if (a[0] == '-' && a[1] == '-' && strstr(msg, a))
            return 1;
        if (a[0] == '-' || !a[0])
            continue;
        char *path = expand(a, dir);
        const char *b = strrchr(path, '/');
        int named = strchr(path, '/') && (strstr(msg, path) ||
                                          strstr(msg, b + 1));
        free(path);
        if (named)
            return 1;
    }
    if (strstr(msg, "standard input") || strstr(msg, "standard output"))
        return 1;
    for (const char *p = msg; (p = strstr(p, "line ")); p++)
        if (isdigit((unsigned char)p[5]))
            return 1;
    /* A key path: cables[0], bodies[1], analyses[2], tow.speed, ... */
    for (const char *p = msg; *p;) {
        if (!isalpha((unsigned char)*p)) {
            p++;
            continue;
        }
        const char *q = p;
        while (isalnum((unsigned char)*q) || *q == '_')
            q++;
        if (*q == '[' && isdigit((unsigned char)q[1]))
            return 1;
        if (*q == '.' && ((q - p == 3 && !strncmp(p, "tow", 3)) ||
                          (q - p == 11 && !strncmp(p, "environment", 11))))
            return 1;
        p = q;
    }
    return 0;
}

/* Files of directory d (names, sorted) with their content. */
typedef struct snapshot {
    int n;
    char **names;
    char **data;
    size_t *len;
} snapshot;

static void snap_free(snapshot *s)
{
    for (int i = 0; i < s->n; i++) {
        free(s->names[i]);
        free(s->data[i]);
    }
    free(s->names);
    free(s->data);
    free(s->len);
    memset(s, 0, sizeof *s);
}

static void snap_take(const char *dir, snapshot *s)
{
    memset(s, 0, sizeof *s);
    DIR *d = opendir(dir);
    if (!d)
        return;
    for (struct dirent *e; (e = readdir(d));) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        s->names = realloc(s->names, (size_t)(s->n + 1) * sizeof(char *));
        s->data = realloc(s->data, (size_t)(s->n + 1) * sizeof(char *));
        s->len = realloc(s->len, (size_t)(s->n + 1) * sizeof(size_t));
        char *p = fmt("%s/%s", dir, e->d_name);
        struct stat st;
        s->names[s->n] = xstrdup(e->d_name);
        s->data[s->n] = NULL;
        s->len[s->n] = 0;
        if (!lstat(p, &st) && S_ISREG(st.st_mode))
            s->data[s->n] = read_file(p, &s->len[s->n]);
        free(p);
        s->n++;
    }
    closedir(d);
}

static int snap_find(const snapshot *s, const char *name)
{
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->names[i], name))
            return i;
    return -1;
}

/* Problems found with a case, one line. */
typedef struct verdict {
    sbuf why;
    int nproblems;
} verdict;

static void problem(verdict *v, const char *f, ...)
{
    va_list ap;
    va_start(ap, f);
    char *s = NULL;
    if (vasprintf(&s, f, ap) < 0)
        s = NULL;
    va_end(ap);
    if (v->nproblems++)
        sb_str(&v->why, "; ");
    sb_str(&v->why, s ? s : "?");
    free(s);
}

/* A JSON output: valid; marked incomplete when the run failed; never
 * "trustworthy": true then. */
static void check_json_file(const char *path, const char *label, int failed,
                            verdict *v)
{
    json_error_t je;
    json_t *j = json_load_file(path, 0, &je);
    if (!j) {
        problem(v, "%s is not valid JSON (%s, line %d)", label, je.text,
                je.line);
        return;
    }
    if (failed) {
        json_t *comp = json_object_get(j, "completed");
        json_t *inc = json_object_get(j, "incomplete");
        if (!(json_is_false(comp) || json_is_true(inc)))
            problem(v, "%s of a failed run is not marked incomplete", label);
        json_t *tr = json_object_get(j, "trustworthy");
        if (json_is_true(tr))
            problem(v, "%s of a failed run says trustworthy", label);
    }
    json_decref(j);
}

static void check_csv_text(const char *text, const char *label, verdict *v)
{
    if (has_word(text, "nan") || has_word(text, "inf") ||
        has_word(text, "infinity"))
        problem(v, "%s holds a non-finite number", label);
}

static int is_char_dev(const char *path, unsigned maj, unsigned min)
{
    struct stat st;
    return !lstat(path, &st) && S_ISCHR(st.st_mode) &&
           major(st.st_rdev) == maj && minor(st.st_rdev) == min;
}

/* ---- running ------------------------------------------------------------ */

typedef struct run {
    int idx;             /* case */
    pid_t pid, reader;   /* towstab; the FIFO's reader (0: none) */
    char *dir;
    double start, deadline;
    int signalled;       /* the case's signal was sent */
    int interrupted;     /* the suite sent SIGINT after a cost announcement */
    int timed_out;
    int ptyfd;           /* master side, -1: none */
    sbuf ptyout;
    snapshot before;
    int status;
    double wall;
} run;

static const char *towstab;
static char *workdir;
static double time_scale = 1.0;
static int is_root;

static int prepare_dir(const hcase *c, const char *dir)
{
    if (mkdir(dir, 0700))
        return -1;
    if (c->scene) {
        char *p = fmt("%s/%s", dir, c->scene_file);
        int rc = write_file(p, c->scene, c->scene_len);
        free(p);
        if (rc)
            return -1;
    }
    char *p;
    int rc = 0;
    if (c->setup & S_FIFO) {
        p = fmt("%s/pipe", dir);
        rc |= mkfifo(p, 0600);
        free(p);
    }
    if (c->setup & S_DEVNULL) {
        p = fmt("%s/null", dir);
        rc |= mknod(p, S_IFCHR | 0666, makedev(1, 3));
        free(p);
    }
    if (c->setup & S_DEVFULL) {
        p = fmt("%s/full", dir);
        rc |= mknod(p, S_IFCHR | 0666, makedev(1, 7));
        free(p);
    }
    if (c->setup & S_SYMLINK) {
        p = fmt("%s/target.json", dir);
        rc |= write_file(p, "previous\n", 9);
        free(p);
        p = fmt("%s/link.json", dir);
        rc |= symlink("target.json", p);
        free(p);
    }
    if (c->setup & S_DANGLING) {
        p = fmt("%s/dangling.json", dir);
        rc |= symlink("new.json", p);
        free(p);
    }
    if (c->setup & S_RODIR) {
        p = fmt("%s/ro", dir);
        rc |= mkdir(p, 0555);
        free(p);
    }
    if (c->setup & (S_EXISTING | S_ROFILE)) {
        p = fmt("%s/out.json", dir);
        rc |= write_file(p, "previous\n", 9);
        if (c->setup & S_ROFILE)
            rc |= chmod(p, 0444);
        free(p);
        if (c->setup & S_EXISTING) {
            p = fmt("%s/out.csv", dir);
            rc |= write_file(p, "previous\n", 9);
            free(p);
        }
    }
    if (c->setup & S_SUBDIR) {
        p = fmt("%s/dir", dir);
        rc |= mkdir(p, 0700);
        free(p);
    }
    return rc ? -1 : 0;
}

/* The FIFO's reader: copies the FIFO into pipe.out. */
static pid_t start_reader(const char *dir)
{
    pid_t pid = fork();
    if (pid != 0)
        return pid;
    char *in = fmt("%s/pipe", dir), *out = fmt("%s/pipe.read", dir);
    int fi = open(in, O_RDONLY);
    int fo = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fi < 0 || fo < 0)
        _exit(3);
    char buf[65536];
    for (ssize_t n; (n = read(fi, buf, sizeof buf)) > 0;)
        if (write(fo, buf, (size_t)n) != n)
            _exit(3);
    _exit(0);
}

static int start_case(run *r, int idx, int serial)
{
    const hcase *c = &cases[idx];
    memset(r, 0, sizeof *r);
    r->idx = idx;
    r->ptyfd = -1;
    r->dir = fmt("%s/case-%04d", workdir, serial);
    if (prepare_dir(c, r->dir)) {
        fprintf(stderr, "hostile: cannot prepare %s: %s\n", r->dir,
                strerror(errno));
        return -1;
    }
    snap_take(r->dir, &r->before);
    if (c->setup & S_FIFO)
        r->reader = start_reader(r->dir);
    char *argv[MAX_ARGS + 2];
    argv[0] = (char *)towstab;
    for (int i = 0; i < c->nargs; i++)
        argv[i + 1] = expand(c->args[i], r->dir);
    argv[c->nargs + 1] = NULL;
    char *in = c->stdin_path ? expand(c->stdin_path, r->dir)
                             : fmt("%s/stdin.empty", r->dir);
    if (!c->stdin_path)
        write_file(in, "", 0);
    char *out = c->stdout_full ? xstrdup("/dev/full")
                               : fmt("%s/stdout.txt", r->dir);
    char *err = fmt("%s/stderr.txt", r->dir);
    char *slave = NULL;
    if (c->pty) {
        r->ptyfd = posix_openpt(O_RDWR | O_NOCTTY);
        if (r->ptyfd < 0 || grantpt(r->ptyfd) || unlockpt(r->ptyfd) ||
            !(slave = ptsname(r->ptyfd))) {
            fprintf(stderr, "hostile: no pseudo-terminal: %s\n",
                    strerror(errno));
            return -1;
        }
        slave = xstrdup(slave);
        fcntl(r->ptyfd, F_SETFL, O_NONBLOCK);
    }
    fflush(stdout);
    r->start = now();
    double limit = (c->timeout > 0 ? c->timeout : CASE_TIMEOUT) * time_scale;
    r->deadline = r->start + WALL_FACTOR * limit;
    r->pid = fork();
    if (r->pid == 0) {
        setpgid(0, 0);
        /* SIGXCPU at the limit, SIGKILL a little after. */
        struct rlimit cpu = {(rlim_t)(limit + 0.999), (rlim_t)(limit + 5.999)};
        setrlimit(RLIMIT_CPU, &cpu);
        if (c->vm_limit_mb > 0 && time_scale == 1.0) {
            rlim_t bytes = (rlim_t)c->vm_limit_mb << 20;
            struct rlimit as = {bytes, bytes};
            setrlimit(RLIMIT_AS, &as);
        }
        int fi = open(in, O_RDONLY);
        int fo = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        int fe = slave ? open(slave, O_RDWR | O_NOCTTY)
                       : open(err, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (fi < 0 || fo < 0 || fe < 0)
            _exit(125);
        dup2(fi, 0);
        dup2(fo, 1);
        dup2(fe, 2);
        if (r->ptyfd >= 0)
            close(r->ptyfd);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        signal(SIGPIPE, SIG_DFL);
        execv(towstab, argv);
        _exit(126);
    }
    for (int i = 1; i <= c->nargs; i++)
        free(argv[i]);
    free(in);
    free(out);
    free(err);
    free(slave);
    return r->pid > 0 ? 0 : -1;
}

static void drain_pty(run *r)
{
    if (r->ptyfd < 0)
        return;
    char buf[4096];
    for (ssize_t n; (n = read(r->ptyfd, buf, sizeof buf)) > 0;)
        sb_add(&r->ptyout, buf, (size_t)n);
}

/* Whether the run's standard error holds the cost announcement. */
static int announced(const run *r)
{
    char *p = fmt("%s/stderr.txt", r->dir);
    char *t = read_file(p, NULL);
    int yes = t && strstr(t, COST_MARKER);
    free(t);
    free(p);
    return yes;
}

/* Poll a running case: 1 when it has ended. */
static int poll_case(run *r)
{
    const hcase *c = &cases[r->idx];
    drain_pty(r);
    int st;
    pid_t w = waitpid(r->pid, &st, WNOHANG);
    if (w == r->pid) {
        r->status = st;
        r->wall = now() - r->start;
        drain_pty(r);
        return 1;
    }
    double t = now();
    /* A sanitizer build reaches the same point time_scale times later. */
    if (c->sig && !r->signalled && t - r->start >= c->sig_after * time_scale) {
        kill(r->pid, c->sig);
        r->signalled = 1;
    }
    if (c->announce_ok && !r->interrupted && !r->timed_out &&
        t - r->start > 1.0 && announced(r)) {
        kill(r->pid, SIGINT);
        r->interrupted = 1;
        r->deadline = t + INTERRUPT_GRACE * time_scale;
    }
    if (t > r->deadline && !r->timed_out) {
        kill(-r->pid, SIGKILL);
        kill(r->pid, SIGKILL);
        r->timed_out = 1;
    }
    return 0;
}

/* Counts by outcome. */
enum { O_REFUSED, O_RAN, O_STOPPED, O_CRASHED, O_HUNG, O_N };
static const char *const outcome_names[O_N] = {"refused", "ran", "stopped",
                                               "crashed", "hung"};
static int counts[O_N], npass, nfail, nxfail, nxpass, nskip;

/* The lines of text that start with "towstab: error:" (or any towstab
 * line for a signal case). */
static char *error_lines(const char *err)
{
    sbuf b = {0};
    sb_str(&b, "");
    for (const char *p = err; p && *p;) {
        const char *e = strchr(p, '\n');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        if (!strncmp(p, "towstab: error:", 15)) {
            sb_add(&b, p, n);
            sb_str(&b, "\n");
        }
        p = e ? e + 1 : NULL;
    }
    return b.s;
}

static void finish_case(run *r)
{
    const hcase *c = &cases[r->idx];
    verdict v = {{0}, 0};
    sb_str(&v.why, "");
    if (r->reader > 0) {
        /* The reader ends with its writer; one left waiting means the
         * FIFO was never opened (or replaced). */
        int st;
        double t0 = now();
        while (waitpid(r->reader, &st, WNOHANG) == 0) {
            if (now() - t0 > 0.5) {
                kill(r->reader, SIGKILL);
                waitpid(r->reader, &st, 0);
                break;
            }
            usleep(2000);
        }
    }
    char *pout = fmt("%s/stdout.txt", r->dir), *perr = fmt("%s/stderr.txt",
                                                           r->dir);
    char *out = c->stdout_full ? xstrdup("") : read_file(pout, NULL);
    char *err = c->pty ? xstrdup(r->ptyout.s ? r->ptyout.s : "")
                       : read_file(perr, NULL);
    if (!out)
        out = xstrdup("");
    if (!err)
        err = xstrdup("");
    int outcome;
    int st = r->status, code = -1;
    int sanitizer = strstr(err, "Sanitizer") || strstr(err, "runtime error:");
    double limit = (c->timeout > 0 ? c->timeout : CASE_TIMEOUT) * time_scale;
    if (r->timed_out) {
        outcome = O_HUNG;
        problem(&v, r->interrupted ? "did not stop within %.0f s of SIGINT "
                                     "after announcing its cost"
                                   : "no result within %.0f s (wall)",
                r->interrupted ? INTERRUPT_GRACE * time_scale
                               : WALL_FACTOR * limit);
    } else if (WIFSIGNALED(st) && (WTERMSIG(st) == SIGXCPU ||
                                   WTERMSIG(st) == SIGKILL)) {
        outcome = O_HUNG;
        problem(&v, "no result within %.0f s of CPU time", limit);
    } else if (WIFSIGNALED(st) || sanitizer) {
        outcome = O_CRASHED;
        if (sanitizer)
            problem(&v, "sanitizer report");
        else
            problem(&v, "killed by signal %d (%s)", WTERMSIG(st),
                    strsignal(WTERMSIG(st)));
    } else {
        code = WEXITSTATUS(st);
        int sig_code = (c->sig ? 128 + c->sig : -1);
        int asked_stop = r->interrupted ? 128 + SIGINT : -1;
        if (code == 0)
            outcome = O_RAN;
        else if (code == sig_code || code == asked_stop)
            outcome = O_STOPPED;
        else
            outcome = O_REFUSED;
        if (code == 125 || code == 126)
            problem(&v, "the suite could not start the program");
    }
    char *msgs = error_lines(err);
    char *uq = unquoted(err), *uqo = unquoted(out);
    blank_user_text(uq, c->user_text);
    blank_user_text(uqo, c->user_text);
    /* No "nan" in any message or report. */
    if (has_word(uq, "nan"))
        problem(&v, "standard error says nan");
    if (has_word(uqo, "nan"))
        problem(&v, "standard output says nan");
    /* Outputs in the case directory, against what was there before. */
    snapshot after;
    snap_take(r->dir, &after);
    if (code >= 0) {
        int failed = code != 0;
        for (int i = 0; i < after.n; i++) {
            const char *nm = after.names[i];
            if (!strcmp(nm, "stdout.txt") || !strcmp(nm, "stderr.txt") ||
                !strcmp(nm, "stdin.empty") || !strcmp(nm, "pipe.read") ||
                (c->scene_file && !strcmp(nm, c->scene_file)))
                continue;
            int b = snap_find(&r->before, nm);
            int changed = b < 0 || !r->before.data[b] != !after.data[i] ||
                          (after.data[i] &&
                           (r->before.len[b] != after.len[i] ||
                            memcmp(r->before.data[b], after.data[i],
                                   after.len[i])));
            if (!changed)
                continue;
            if (code == 2) {
                problem(&v, "a refusal %s %s", b < 0 ? "left" : "changed",
                        nm);
                continue;
            }
            size_t l = strlen(nm);
            char *p = fmt("%s/%s", r->dir, nm);
            if (after.data[i] && l > 5 && !strcmp(nm + l - 5, ".json"))
                check_json_file(p, nm, failed, &v);
            else if (after.data[i] && l > 4 && !strcmp(nm + l - 4, ".csv")) {
                blank_user_text(after.data[i], c->user_text);
                check_csv_text(after.data[i], nm, &v);
            }
            else if (after.data[i] && !strcmp(nm, "same.out") && failed)
                problem(&v, "a failed run wrote %s", nm);
            free(p);
        }
        /* JSON on standard output ("--json -"). */
        int json_stdout = 0;
        for (int i = 0; i + 1 < c->nargs; i++)
            if (!strcmp(c->args[i], "--json") && !strcmp(c->args[i + 1], "-"))
                json_stdout = 1;
        if (json_stdout && !c->stdout_full && (code == 0 || out[0]))
            check_json_file(pout, "the JSON on standard output", failed, &v);
        /* `run` prints each analysis after a "== analysis k of n" line:
         * the analyses before the failed one delivered their results, and
         * only the failed one's part must not say trustworthy. */
        const char *part = out;
        for (const char *h = out; (h = strstr(h, "== analysis ")); h++)
            if (h == out || h[-1] == '\n')
                part = h;
        if (failed && !c->write_fault && strstr(part, "trustworthy: yes"))
            problem(&v, "a failed %s says trustworthy: yes",
                    part == out ? "run" : "run's last analysis");
        if (!failed && (has_word(uqo, "inf") || has_word(uqo, "infinity")))
            problem(&v, "standard output holds a non-finite number");
    }
    /* Targets. */
    char *p;
    if (c->setup & S_FIFO) {
        struct stat sb;
        p = fmt("%s/pipe", r->dir);
        if (lstat(p, &sb) || !S_ISFIFO(sb.st_mode))
            problem(&v, "the FIFO was replaced");
        free(p);
        p = fmt("%s/pipe.read", r->dir);
        size_t n = 0;
        char *t = read_file(p, &n);
        if (code == 0 && !(t && n > 0))
            problem(&v, "nothing came through the FIFO");
        else if (code == 0 && c->nargs > 3 &&
                 !strcmp(c->args[c->nargs - 2], "--json"))
            check_json_file(p, "the JSON read from the FIFO", 0, &v);
        free(t);
        free(p);
    }
    static const struct {
        int setup;
        const char *node;
        unsigned maj, min;
    } devs[] = {{S_DEVNULL, "null", 1, 3}, {S_DEVFULL, "full", 1, 7}};
    for (int i = 0; i < 2; i++) {
        if (!(c->setup & devs[i].setup))
            continue;
        p = fmt("%s/%s", r->dir, devs[i].node);
        if (!is_char_dev(p, devs[i].maj, devs[i].min))
            problem(&v, "the device node '%s' was replaced", devs[i].node);
        free(p);
    }
    /* Symlinks stay links; after a run, their targets hold the JSON. */
    static const struct {
        int setup;
        const char *link, *target;
    } links[] = {{S_SYMLINK, "link.json", "target.json"},
                 {S_DANGLING, "dangling.json", "new.json"}};
    for (int i = 0; i < 2; i++) {
        if (!(c->setup & links[i].setup))
            continue;
        char buf[256];
        p = fmt("%s/%s", r->dir, links[i].link);
        if (readlink(p, buf, sizeof buf - 1) < 0) {
            problem(&v, "the symlink %s was replaced", links[i].link);
        } else if (code == 0) {
            free(p);
            p = fmt("%s/%s", r->dir, links[i].target);
            check_json_file(p, links[i].target, 0, &v);
        }
        free(p);
    }
    if (c->setup & S_RODIR) {
        p = fmt("%s/ro", r->dir);
        snapshot s;
        snap_take(p, &s);
        if (s.n)
            problem(&v, "something was written into the read-only folder");
        snap_free(&s);
        chmod(p, 0700);
        free(p);
    }
    /* The expectation. */
    if (code >= 0) {
        switch (c->expect) {
        case E_REFUSE:
            if (code != 1 && code != 2)
                problem(&v, "exit %d, expected a refusal (1 or 2)", code);
            break;
        case E_BADINPUT:
            if (code != 2)
                problem(&v, "exit %d, expected 2 (bad input)", code);
            break;
        case E_RUN:
            if (code != 0)
                problem(&v, "exit %d, expected a run", code);
            break;
        case E_WRITE_FAILS:
            if (code == 0)
                problem(&v, "exit 0 after a failed write");
            else if (code != 1)
                problem(&v, "exit %d after a failed write, expected 1",
                        code);
            break;
        case E_INTERRUPT:
            if (code != 128 + c->sig)
                problem(&v, "exit %d, expected %d after %s", code,
                        128 + c->sig, strsignal(c->sig));
            else if (!strstr(err, "interrupted") ||
                     (c->must_name && !strstr(err, c->must_name)))
                problem(&v, "stopped without saying %s",
                        c->must_name ? c->must_name : "interrupted");
            break;
        default:
            if (code > 2 && outcome != O_STOPPED)
                problem(&v, "exit %d", code);
            break;
        }
        if (c->must_start && outcome == O_REFUSED)
            problem(&v, "refused (exit %d), expected to run or to be "
                    "stopped after announcing its cost", code);
        if (code != 0 && outcome == O_REFUSED) {
            if (!msgs[0])
                problem(&v, "no 'towstab: error:' line on standard error");
            else if (c->must_name ? !strstr(msgs, c->must_name)
                                  : !names_something(msgs, c, r->dir))
                problem(&v, "the message does not name %s",
                        c->must_name ? c->must_name
                                     : "a file, key, line or option");
        }
    }
    if (c->progress > 0 && !(strstr(err, "\r") && strstr(err, " left")))
        problem(&v, "no progress on the terminal");
    if (c->progress < 0 && (strstr(err, "\r") || strstr(err, " left")))
        problem(&v, "progress written to a file");
    /* The verdict. */
    counts[outcome]++;
    int ok = v.nproblems == 0;
    const char *tag;
    if (ok && c->xfail) {
        tag = "XPASS";
        nxpass++;
    } else if (ok) {
        tag = "PASS";
        npass++;
    } else if (c->xfail) {
        tag = "XFAIL";
        nxfail++;
    } else {
        tag = "FAIL";
        nfail++;
    }
    char first[161] = "";
    const char *m = msgs[0] ? msgs : err;
    size_t n = strcspn(m, "\n");
    if (n > 160)
        n = 160;
    for (size_t i = 0; i < n; i++)
        first[i] = isprint((unsigned char)m[i]) ? m[i] : '?';
    first[n] = '\0';
    printf("%-5s %-7s %s [exit %s%d, %.2f s]", tag, outcome_names[outcome],
           c->name, code >= 0 ? "" : "signal ",
           code >= 0 ? code : (WIFSIGNALED(st) ? WTERMSIG(st) : 0), r->wall);
    if (!ok)
        printf(" -- %s", v.why.s);
    if (c->xfail)
        printf(" [%s]", c->xfail);
    if (ok && c->xfail)
        printf(" -- passes now: remove it from the xfail list");
    if (first[0])
        printf(" | %s", first);
    printf("\n");
    fflush(stdout);
    snap_free(&after);
    snap_free(&r->before);
    free(msgs);
    free(uq);
    free(uqo);
    free(out);
    free(err);
    free(pout);
    free(perr);
    free(v.why.s);
    free(r->ptyout.s);
    if (r->ptyfd >= 0)
        close(r->ptyfd);
}

static void remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st))
        return;
    if (S_ISDIR(st.st_mode)) {
        chmod(path, 0700);
        DIR *d = opendir(path);
        if (d) {
            for (struct dirent *e; (e = readdir(d));) {
                if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
                    continue;
                char *p = fmt("%s/%s", path, e->d_name);
                remove_tree(p);
                free(p);
            }
            closedir(d);
        }
        rmdir(path);
    } else {
        unlink(path);
    }
}

static void usage(void)
{
    fprintf(stderr, "usage: hostile TOWSTAB EXAMPLES_DIR XFAIL_LIST [--jobs "
                    "N] [--time-scale X] [--only TEXT] [--keep] [--list]\n");
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        usage();
        return 2;
    }
    towstab = argv[1];
    const char *exdir = argv[2], *xfail = argv[3], *only = NULL;
    int jobs = (int)sysconf(_SC_NPROCESSORS_ONLN), keep = 0, list = 0;
    for (int i = 4; i < argc; i++) {
        if (!strcmp(argv[i], "--jobs") && i + 1 < argc)
            jobs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--time-scale") && i + 1 < argc)
            time_scale = atof(argv[++i]);
        else if (!strcmp(argv[i], "--only") && i + 1 < argc)
            only = argv[++i];
        else if (!strcmp(argv[i], "--keep"))
            keep = 1;
        else if (!strcmp(argv[i], "--list"))
            list = 1;
        else {
            usage();
            return 2;
        }
    }
    if (jobs < 1)
        jobs = 1;
    if (jobs > 8)
        jobs = 8;
    if (!(time_scale > 0)) {
        usage();
        return 2;
    }
    if (access(towstab, X_OK)) {
        fprintf(stderr, "hostile: %s is not executable\n", towstab);
        return 2;
    }
    is_root = geteuid() == 0;
    signal(SIGPIPE, SIG_IGN);
    if (load_examples(exdir))
        return 2;
    gen_scene_mutants();
    int nmutants = ncases;
    gen_sizes();
    int nsizes = ncases - nmutants;
    gen_after_equilibrium();
    gen_cli_misuse();
    int ncli = ncases - nmutants - nsizes;
    gen_output_faults();
    int nfaults = ncases - nmutants - nsizes - ncli;
    gen_signals();
    int nsignals = ncases - nmutants - nsizes - ncli - nfaults;
    for (int i = 0; i < ncases; i++)
        for (int j = i + 1; j < ncases; j++)
            if (!strcmp(cases[i].name, cases[j].name)) {
                fprintf(stderr, "hostile: two cases named '%s'\n",
                        cases[i].name);
                return 2;
            }
    int bad_list = read_xfail(xfail);
    if (bad_list < 0)
        return 2;
    if (list) {
        for (int i = 0; i < ncases; i++)
            printf("%s\n", cases[i].name);
        return 0;
    }
    const char *tmp = getenv("TMPDIR");
    workdir = fmt("%s/towstab-hostile-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(workdir)) {
        fprintf(stderr, "hostile: cannot make a temporary directory: %s\n",
                strerror(errno));
        return 2;
    }
    printf("hostile: %d cases (%d scene mutants of %d examples, %d sizes, "
           "%d command-line misuses, %d output faults, %d signals and "
           "progress), %d jobs, time limit %.0f s of CPU (%.0f s of wall "
           "time) each%s\n",
           ncases, nmutants, nexamples, nsizes, ncli, nfaults, nsignals, jobs,
           CASE_TIMEOUT * time_scale, WALL_FACTOR * CASE_TIMEOUT * time_scale,
           is_root ? ", as root" : "");
    double t0 = now();
    run *slots = xmalloc((size_t)jobs * sizeof *slots);
    int *busy = calloc((size_t)jobs, sizeof *busy);
    int next = 0, running = 0, serial = 0, tried = 0;
    while (next < ncases || running > 0) {
        for (int s = 0; s < jobs && next < ncases; s++) {
            if (busy[s])
                continue;
            const hcase *c = &cases[next];
            if (only && !strstr(c->name, only)) {
                next++;
                s--;
                continue;
            }
            if ((c->need_root && !is_root) || (c->need_nonroot && is_root)) {
                printf("SKIP  %s -- %s\n", c->name,
                       c->need_root ? "needs root (mknod)"
                                    : "root ignores file permissions");
                nskip++;
                next++;
                s--;
                continue;
            }
            if (start_case(&slots[s], next, serial++)) {
                return 2;
            }
            busy[s] = 1;
            running++;
            tried++;
            next++;
        }
        int ended = 0;
        for (int s = 0; s < jobs; s++)
            if (busy[s] && poll_case(&slots[s])) {
                finish_case(&slots[s]);
                if (!keep)
                    remove_tree(slots[s].dir);
                free(slots[s].dir);
                busy[s] = 0;
                running--;
                ended = 1;
            }
        if (!ended)
            usleep((useconds_t)(POLL_S * 1e6));
    }
    if (!keep)
        remove_tree(workdir);
    printf("hostile: tried %d: refused %d, ran %d, stopped by a signal %d, "
           "crashed %d, hung %d; %d passed, %d failed, %d expected to fail "
           "(xfail list), %d passed but listed, %d skipped; %.1f s\n",
           tried, counts[O_REFUSED], counts[O_RAN], counts[O_STOPPED],
           counts[O_CRASHED], counts[O_HUNG], npass, nfail, nxfail, nxpass,
           nskip, now() - t0);
    if (keep)
        printf("hostile: case directories kept in %s\n", workdir);
    free(slots);
    free(busy);
    return nfail || nxpass || bad_list ? 1 : 0;
}
