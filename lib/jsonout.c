/* jsonout.c: JSON written as it is made (jsonout.h).
 *
 * yajl's generator (yajl_gen: structure, separators, indentation, the
 * escaping of strings) prints each token through a callback that copies
 * it into the writer's buffer; the buffer goes to the stream with one
 * fwrite each time it fills and at the end. jansson's one-line form
 * (", " and ": ") is yajl's beautified form with no indentation and its
 * newlines mapped in the callback. A tree-building writer has no
 * generator: each call adds its value to a jansson tree instead, so that
 * a document's parts are written by one function for both forms. Numbers are formatted here
 * (tsi_json_format) and handed to yajl_gen_number as text: yajl's own
 * yajl_gen_double prints 20 significant digits, jansson's 17, and the
 * files must stay as they were. */
#include "jsonout.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <yajl/yajl_gen.h>

struct tsi_json {
    yajl_gen g;  /* NULL when building a tree */
    FILE *f;
    int failed;  /* a write or a generator call failed */
    int err;     /* errno of the failure */
    int spaced;  /* TSI_JSON_SPACED: yajl's newlines become jansson's */
    char last;   /* the last byte given to the buffer */
    /* A tree being built (tsi_json_open_tree): the open containers,
     * innermost last, and the key waiting for its value (owned). */
    json_t *root;
    json_t *open[TSI_JSON_DEPTH];
    int depth;
    char *key;
    size_t len;  /* bytes in buf */
    char buf[];  /* TSI_JSON_BUFFER bytes when writing text */
};

static void flush(tsi_json *w)
{
    if (!w->g)
        return;
    if (w->len > 0 && !w->failed && fwrite(w->buf, 1, w->len, w->f) != w->len) {
        w->failed = 1;
        w->err = errno ? errno : EIO;
    }
    w->len = 0;
}

/* yajl's print callback: gather the token. */
static void put(void *ctx, const char *s, size_t n)
{
    tsi_json *w = ctx;
    if (w->spaced && n == 1 && s[0] == '\n') {
        /* yajl prints every newline of its beautified form alone (a
         * string's own are escaped): after a comma it becomes jansson's
         * space, after an opening bracket, before a closing one and at
         * the end nothing. */
        if (w->last != ',')
            return;
        s = " ";
    }
    if (n > 0)
        w->last = s[n - 1];
    if (w->len + n > TSI_JSON_BUFFER)
        flush(w);
    if (n > TSI_JSON_BUFFER) {
        if (!w->failed && fwrite(s, 1, n, w->f) != n) {
            w->failed = 1;
            w->err = errno ? errno : EIO;
        }
        return;
    }
    memcpy(w->buf + w->len, s, n);
    w->len += n;
}

/* A generator call's status: anything but ok is a misuse (a value where
 * a key belongs, a key outside an object). */
static void check(tsi_json *w, yajl_gen_status st)
{
    if (st != yajl_gen_status_ok && !w->failed) {
        w->failed = 1;
        w->err = EINVAL;
    }
}

/* A writer of either kind, zeroed, with `buffer` bytes of buffer. */
static tsi_json *writer(size_t buffer)
{
    tsi_json *w = malloc(sizeof *w + buffer);
    if (w)
        memset(w, 0, sizeof *w);
    return w;
}

tsi_json *tsi_json_open(FILE *f, int indent)
{
    tsi_json *w = writer(TSI_JSON_BUFFER);
    if (!w)
        return NULL;
    w->g = yajl_gen_alloc(NULL);
    if (!w->g) {
        free(w);
        return NULL;
    }
    w->f = f;
    yajl_gen_config(w->g, yajl_gen_print_callback, put, (void *)w);
    if (indent) {
        yajl_gen_config(w->g, yajl_gen_beautify, 1);
        yajl_gen_config(w->g, yajl_gen_indent_string,
                        indent == TSI_JSON_SPACED ? "" : "  ");
        w->spaced = indent == TSI_JSON_SPACED;
    }
    return w;
}

/* Release w; -1 with errno set when something failed, else 0. */
static int release(tsi_json *w)
{
    int failed = w->failed, e = w->err;
    if (w->g)
        yajl_gen_free(w->g);
    while (w->depth > 0)
        json_decref(w->open[--w->depth]);
    json_decref(w->root);
    free(w->key);
    free(w);
    if (failed)
        errno = e;
    return failed ? -1 : 0;
}

int tsi_json_close(tsi_json *w)
{
    if (!w)
        return -1;
    flush(w);
    return release(w);
}

int tsi_json_status(const tsi_json *w) { return w->failed ? w->err : 0; }

tsi_json *tsi_json_open_tree(void) { return writer(0); }

json_t *tsi_json_take_tree(tsi_json *w)
{
    if (!w)
        return NULL;
    json_t *root = NULL;
    if (!w->failed && w->depth == 0) {
        root = w->root;
        w->root = NULL;
    }
    release(w);
    return root;
}

json_t *tsi_json_build(tsi_json_emit_fn fn, const void *a, const void *b)
{
    tsi_json *w = tsi_json_open_tree();
    if (!w)
        return NULL;
    fn(w, a, b);
    return tsi_json_take_tree(w);
}

/* Tree mode: place value v (a new reference, NULL when it could not be
 * made) in the open container, or as the root; `container` pushes it. */
static void add(tsi_json *w, json_t *v, int container)
{
    json_t *parent = w->depth > 0 ? w->open[w->depth - 1] : NULL;
    int bad = w->failed || !v;
    if (!bad && !parent) {
        bad = w->root != NULL;
        if (!bad)
            w->root = json_incref(v);
    } else if (!bad && json_is_object(parent)) {
        bad = !w->key || json_object_set(parent, w->key, v) != 0;
        free(w->key);
        w->key = NULL;
    } else if (!bad) {
        bad = json_array_append(parent, v) != 0;
    }
    if (!bad && container) {
        bad = w->depth >= TSI_JSON_DEPTH;
        if (!bad)
            w->open[w->depth++] = json_incref(v);
    }
    json_decref(v);
    if (bad && !w->failed) {
        w->failed = 1;
        w->err = v ? EINVAL : ENOMEM;
    }
}

/* Tree mode: close the innermost container. */
static void end(tsi_json *w)
{
    if (w->depth == 0 || w->key) {
        w->failed = 1;
        w->err = EINVAL;
        return;
    }
    json_decref(w->open[--w->depth]);
}

int tsi_json_format(char buf[32], double v)
{
    if (!isfinite(v)) {
        memcpy(buf, "null", 5);
        return 4;
    }
    int n = snprintf(buf, 32, "%.17g", v);
    /* A decimal point of another locale (LC_NUMERIC) becomes '.'. */
    for (int i = 0; i < n; i++)
        if (buf[i] != '-' && buf[i] != '+' && buf[i] != 'e' &&
            (buf[i] < '0' || buf[i] > '9'))
            buf[i] = '.';
    char *e = memchr(buf, 'e', (size_t)n);
    if (!e && !memchr(buf, '.', (size_t)n)) {
        /* Integral: ".0" keeps it a real when read back. */
        memcpy(buf + n, ".0", 3);
        return n + 2;
    }
    if (e) {
        /* The exponent without '+' and without leading zeros, as
         * jansson writes it. */
        char *digits = e + 1, *from = e + 1;
        if (*from == '-')
            digits = ++from;
        else if (*from == '+')
            from++;
        while (*from == '0' && from[1] != '\0')
            from++;
        memmove(digits, from, strlen(from) + 1);
        n = (int)strlen(buf);
    }
    return n;
}

void tsi_json_key(tsi_json *w, const char *key)
{
    if (!w->g) {
        if (w->key || !(w->key = strdup(key))) {
            w->failed = 1;
            w->err = w->key ? EINVAL : ENOMEM;
        }
        return;
    }
    check(w, yajl_gen_string(w->g, (const unsigned char *)key, strlen(key)));
}

void tsi_json_num(tsi_json *w, double v)
{
    if (!isfinite(v)) {
        tsi_json_null(w);
        return;
    }
    if (!w->g) {
        add(w, json_real(v), 0);
        return;
    }
    char buf[32];
    int n = tsi_json_format(buf, v);
    check(w, yajl_gen_number(w->g, buf, (size_t)n));
}

void tsi_json_int(tsi_json *w, long long v)
{
    if (!w->g)
        add(w, json_integer(v), 0);
    else
        check(w, yajl_gen_integer(w->g, v));
}

/* A string of n bytes. */
static void str_n(tsi_json *w, const char *s, size_t n)
{
    if (!w->g)
        add(w, json_stringn(s, n), 0);
    else
        check(w, yajl_gen_string(w->g, (const unsigned char *)s, n));
}

void tsi_json_str(tsi_json *w, const char *s) { str_n(w, s, strlen(s)); }

void tsi_json_bool(tsi_json *w, int v)
{
    if (!w->g)
        add(w, json_boolean(v), 0);
    else
        check(w, yajl_gen_bool(w->g, v));
}

void tsi_json_null(tsi_json *w)
{
    if (!w->g)
        add(w, json_null(), 0);
    else
        check(w, yajl_gen_null(w->g));
}

void tsi_json_object_open(tsi_json *w)
{
    if (!w->g)
        add(w, json_object(), 1);
    else
        check(w, yajl_gen_map_open(w->g));
}

void tsi_json_object_close(tsi_json *w)
{
    if (!w->g)
        end(w);
    else
        check(w, yajl_gen_map_close(w->g));
}

void tsi_json_array_open(tsi_json *w)
{
    if (!w->g)
        add(w, json_array(), 1);
    else
        check(w, yajl_gen_array_open(w->g));
}

void tsi_json_array_close(tsi_json *w)
{
    if (!w->g)
        end(w);
    else
        check(w, yajl_gen_array_close(w->g));
}

int tsi_json_defer_add(tsi_json_defer *d, const json_t *at,
                       tsi_json_emit_fn fn, const void *a, const void *b)
{
    if (!d)
        return 0;
    if (d->n >= TSI_JSON_DEFER_MAX)
        return -1;
    d->item[d->n].at = at;
    d->item[d->n].fn = fn;
    d->item[d->n].a = a;
    d->item[d->n].b = b;
    d->n++;
    return 0;
}

void tsi_json_tree(tsi_json *w, const json_t *v, const tsi_json_defer *d)
{
    for (int i = 0; d && i < d->n; i++)
        if (d->item[i].at == v) {
            d->item[i].fn(w, d->item[i].a, d->item[i].b);
            return;
        }
    /* yajl opens a container on a line of its own even when it stays
     * empty; "[]" and "{}" are handed over whole, as an atom, to write
     * them as jansson does. */
    if (w->g && ((json_is_object(v) && json_object_size(v) == 0) ||
                 (json_is_array(v) && json_array_size(v) == 0))) {
        check(w, yajl_gen_number(w->g, json_is_array(v) ? "[]" : "{}", 2));
        return;
    }
    switch (json_typeof(v)) {
    case JSON_OBJECT: {
        const char *key;
        json_t *e;
        tsi_json_object_open(w);
        json_object_foreach((json_t *)v, key, e)
        {
            tsi_json_key(w, key);
            tsi_json_tree(w, e, d);
        }
        tsi_json_object_close(w);
        break;
    }
    case JSON_ARRAY: {
        size_t i;
        json_t *e;
        tsi_json_array_open(w);
        json_array_foreach(v, i, e) tsi_json_tree(w, e, d);
        tsi_json_array_close(w);
        break;
    }
    case JSON_STRING:
        str_n(w, json_string_value(v), json_string_length(v));
        break;
    case JSON_INTEGER: tsi_json_int(w, json_integer_value(v)); break;
    case JSON_REAL: tsi_json_num(w, json_real_value(v)); break;
    case JSON_TRUE: tsi_json_bool(w, 1); break;
    case JSON_FALSE: tsi_json_bool(w, 0); break;
    case JSON_NULL: tsi_json_null(w); break;
    }
}
