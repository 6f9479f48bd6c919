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
 */
#ifndef TOWSTAB_JSONOUT_H
#define TOWSTAB_JSONOUT_H

#include <jansson.h>
#include <stdio.h>

/* Bytes gathered before each write to the stream. */
#define TSI_JSON_BUFFER 65536
/* Deferred values of one document at most. */
#define TSI_JSON_DEFER_MAX 8

typedef struct tsi_json tsi_json;

/* A writer onto f (not closed by tsi_json_close), indented by two spaces
 * a level when `indent`, else compact. NULL when out of memory. */
tsi_json *tsi_json_open(FILE *f, int indent);

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

/* Add an entry to d (d may be NULL: nothing is added). -1 when d is
 * full, else 0. */
int tsi_json_defer_add(tsi_json_defer *d, const json_t *at,
                       tsi_json_emit_fn fn, const void *a, const void *b);

/* Emit tree v (objects in their keys' order), with d's entries (d may be
 * NULL). */
void tsi_json_tree(tsi_json *w, const json_t *v, const tsi_json_defer *d);

#endif
