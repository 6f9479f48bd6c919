/* jsonout.h: JSON written as it is made (internal), through yajl's
 * generator (yajl_gen) and a buffer of TSI_JSON_BUFFER bytes written to
 * a stream each time it fills.
 *
 * A large array (a node or a link per element) is emitted element by
 * element and never held as a tree. A number is printed as jansson
 * prints it with JSON_REAL_PRECISION(17): "%.17g" (17 significant
 * digits, read back to the same double), ".0" added to an integral value
 * so that it reads back as a real, the exponent without '+' or leading
 * zeros; null for a value that is not finite. A document written here is
 * byte for byte the document json_dumpf(JSON_INDENT(2) |
 * JSON_REAL_PRECISION(17)) writes of the same tree.
 *
 * The small parts of a document are still jansson trees: tsi_json_tree
 * emits one, and an element of it listed in a tsi_json_defer is replaced
 * by what that entry's function emits when the walk reaches it.
 *
 * A writer may also build a jansson tree from the same calls
 * (tsi_json_open_tree): the public functions that return trees and the
 * streamed documents share the functions that emit their parts.
 */
#ifndef TOWSTAB_JSONOUT_H
#define TOWSTAB_JSONOUT_H

#include <jansson.h>
#include <stdio.h>

/* Bytes gathered before each write to the stream. */
#define TSI_JSON_BUFFER 65536
/* Deferred values of one document at most. */
#define TSI_JSON_DEFER_MAX 8
/* Containers open at once in a tree being built, at most. */
#define TSI_JSON_DEPTH 64
/* tsi_json_open's `indent` for jansson's one-line form, the form of
 * json_dumps without JSON_INDENT: ", " between elements, ": " after a
 * key, no newline (not even at the end). */
#define TSI_JSON_SPACED 2

typedef struct tsi_json tsi_json;

/* A writer onto f (not closed by tsi_json_close): `indent` 1 indents by
 * two spaces a level (json_dumpf's JSON_INDENT(2), ending with a
 * newline), TSI_JSON_SPACED is the one-line form above, 0 compact (no
 * spaces). NULL when out of memory. */
tsi_json *tsi_json_open(FILE *f, int indent);

/* 0 while every call and write so far succeeded, else the errno of the
 * first failure (ENOMEM, EINVAL for a misuse, a write's). */
int tsi_json_status(const tsi_json *w);

/* A writer that builds a jansson tree of what it is given, one value
 * (the root) in all; NULL when out of memory. */
tsi_json *tsi_json_open_tree(void);

/* The tree built, a new reference, and release w; NULL when a value
 * could not be made or the calls did not make one whole value. */
json_t *tsi_json_take_tree(tsi_json *w);

/* Write what is buffered and release w. 0, or -1 when a generator call
 * or a write failed (errno set by the write, ENOMEM or EINVAL else). */
int tsi_json_close(tsi_json *w);

/* The document's parts, in order; a key only inside an object. */
void tsi_json_key(tsi_json *w, const char *key);
void tsi_json_num(tsi_json *w, double v);
void tsi_json_int(tsi_json *w, long long v);
void tsi_json_str(tsi_json *w, const char *s);
void tsi_json_bool(tsi_json *w, int v);
void tsi_json_null(tsi_json *w);
void tsi_json_object_open(tsi_json *w);
void tsi_json_object_close(tsi_json *w);
void tsi_json_array_open(tsi_json *w);
void tsi_json_array_close(tsi_json *w);

/* Write v's text (at most 31 characters and the NUL) into buf as above;
 * "null" when v is not finite. Returns the length. */
int tsi_json_format(char buf[32], double v);

/* A value of a tree emitted by a function instead: when the walk reaches
 * the element `at` (compared by address), fn(w, a, b) emits one whole
 * value in its place. */
typedef void (*tsi_json_emit_fn)(tsi_json *w, const void *a, const void *b);
typedef struct tsi_json_defer {
    int n;
    struct {
        const json_t *at;
        tsi_json_emit_fn fn;
        const void *a, *b;
    } item[TSI_JSON_DEFER_MAX];
} tsi_json_defer;

/* fn(w, a, b)'s value as a new tree; NULL when out of memory. */
json_t *tsi_json_build(tsi_json_emit_fn fn, const void *a, const void *b);

/* Add an entry to d (d may be NULL: nothing is added). -1 when d is
 * full, else 0. */
int tsi_json_defer_add(tsi_json_defer *d, const json_t *at,
                       tsi_json_emit_fn fn, const void *a, const void *b);

/* Emit tree v (objects in their keys' order), with d's entries (d may be
 * NULL). */
void tsi_json_tree(tsi_json *w, const json_t *v, const tsi_json_defer *d);

#endif
