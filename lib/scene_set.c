/* scene_set.c: values set over a scene's YAML document (scene_set.h), the
 * part of the scene module behind ts_scene_set (towstab/scene.h).
 *
 * Algorithm. The value is parsed as a YAML document of its own and its
 * nodes are copied into the scene's document; then the key's path is
 * walked from the root, mapping key by mapping key and list entry by list
 * entry, adding the mappings that are missing, and the slot it ends at (a
 * mapping pair's value or a list item) is pointed at the copy. libyaml
 * keeps the nodes in one array that grows (and moves) when a node is
 * added, so nodes are held by index, never by pointer across an
 * addition. Nothing recurses on the document except the copy of the value,
 * whose depth is bounded by MAX_DEPTH.
 */
#include "scene_set.h"

#include <stdlib.h>
#include <string.h>

/* Longest key, and longest name or selector in it. */
#define KEY_MAX 512
#define STEP_MAX 128
/* Selectors after one name ("a[0][1]"), at most. */
#define SEL_MAX 4
/* Names in one key, at most. */
#define STEPS_MAX 16
/* Deepest nesting of a value (flow collections inside each other). */
#define MAX_DEPTH 16
/* Longest value text. */
#define VALUE_MAX 65536

typedef struct step {
    char name[STEP_MAX];
    int nsel;
    char sel[SEL_MAX][STEP_MAX];
} step;

static yaml_node_t *node(yaml_document_t *d, int i)
{
    return yaml_document_get_node(d, i);
}

static int scalar_is(const yaml_node_t *n, const char *s)
{
    return n && n->type == YAML_SCALAR_NODE &&
           n->data.scalar.length == strlen(s) &&
           !memcmp(n->data.scalar.value, s, n->data.scalar.length);
}

/* Split key into steps: "cables[armour].length" -> {cables [armour]},
 * {length}. */
static int split(const char *key, step *st, int *nst, ts_err *err)
{
    size_t len = strlen(key);
    if (len == 0 || len >= KEY_MAX)
        return ts_fail(err, TS_EINVAL, "%s%.64s: expected a key of 1 to %d "
                       "characters", len ? "" : "(empty key)", key,
                       KEY_MAX - 1);
    int n = 0;
    const char *p = key;
    while (*p) {
        if (n == STEPS_MAX)
            return ts_fail(err, TS_EINVAL, "%s: more than %d names", key,
                           STEPS_MAX);
        step *s = &st[n++];
        memset(s, 0, sizeof *s);
        size_t k = strcspn(p, ".[]");
        if (k == 0 || k >= STEP_MAX)
            return ts_fail(err, TS_EINVAL, "%s: expected a name at "
                           "character %d", key, (int)(p - key) + 1);
        memcpy(s->name, p, k);
        p += k;
        while (*p == '[') {
            size_t m = strcspn(p + 1, "]");
            if (p[1 + m] != ']' || m == 0 || m >= STEP_MAX ||
                s->nsel == SEL_MAX)
                return ts_fail(err, TS_EINVAL, "%s: expected [index] or "
                               "[name] at character %d", key,
                               (int)(p - key) + 1);
            memcpy(s->sel[s->nsel++], p + 1, m);
            p += m + 2;
        }
        if (*p == '.' && p[1])
            p++;
        else if (*p)
            return ts_fail(err, TS_EINVAL, "%s: unexpected '%c' at "
                           "character %d", key, *p, (int)(p - key) + 1);
    }
    *nst = n;
    return TS_OK;
}

/* Copy node i of src, with what it holds, into dst: its index there, or
 * 0 when out of memory or too deep. */
static int copy(yaml_document_t *dst, yaml_document_t *src, int i,
                int depth)
{
    yaml_node_t *n = node(src, i);
    if (!n || depth > MAX_DEPTH)
        return 0;
    int to = 0;
    switch (n->type) {
    case YAML_SCALAR_NODE:
        return yaml_document_add_scalar(dst, n->tag, n->data.scalar.value,
                                        (int)n->data.scalar.length,
                                        n->data.scalar.style);
    case YAML_SEQUENCE_NODE:
        to = yaml_document_add_sequence(dst, n->tag,
                                        n->data.sequence.style);
        for (yaml_node_item_t *it = n->data.sequence.items.start;
             to && it < n->data.sequence.items.top; it++) {
            int c = copy(dst, src, *it, depth + 1);
            if (!c || !yaml_document_append_sequence_item(dst, to, c))
                to = 0;
        }
        return to;
    case YAML_MAPPING_NODE:
        to = yaml_document_add_mapping(dst, n->tag, n->data.mapping.style);
        for (yaml_node_pair_t *pr = n->data.mapping.pairs.start;
             to && pr < n->data.mapping.pairs.top; pr++) {
            int k = copy(dst, src, pr->key, depth + 1);
            int v = k ? copy(dst, src, pr->value, depth + 1) : 0;
            if (!v || !yaml_document_append_mapping_pair(dst, to, k, v))
                to = 0;
        }
        return to;
    default:
        return 0;
    }
}

/* The value's text as nodes of doc: *out its index. */
static int value_nodes(yaml_document_t *doc, const char *key,
                       const char *value, int *out, ts_err *err)
{
    size_t len = strlen(value);
    if (len > VALUE_MAX)
        return ts_fail(err, TS_EINVAL, "%s: value longer than %d "
                       "characters", key, VALUE_MAX);
    /* Nesting is bounded before libyaml scans (its scanner is slow on
     * deep flow collections). */
    int depth = 0;
    for (size_t i = 0; i < len; i++)
        if ((value[i] == '[' || value[i] == '{') && ++depth > MAX_DEPTH)
            return ts_fail(err, TS_EINVAL, "%s: value nested deeper than "
                           "%d", key, MAX_DEPTH);
        else if ((value[i] == ']' || value[i] == '}') && depth > 0)
            depth--;
    yaml_parser_t p;
    yaml_document_t v;
    if (!yaml_parser_initialize(&p))
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", key);
    yaml_parser_set_input_string(&p, (const unsigned char *)value, len);
    int rc = TS_OK;
    if (!yaml_parser_load(&p, &v)) {
        rc = ts_fail(err, TS_EINVAL, "%s: the value '%.64s' is not YAML "
                     "(%s)", key, value,
                     p.problem ? p.problem : "syntax error");
        yaml_parser_delete(&p);
        return rc;
    }
    yaml_node_t *root = yaml_document_get_root_node(&v);
    if (!root)
        rc = ts_fail(err, TS_EINVAL, "%s: empty value; give one, or remove "
                     "the key", key);
    else if (!(*out = copy(doc, &v, 1, 0)))
        rc = ts_fail(err, TS_ENOMEM, "%s: out of memory, or the value is "
                     "nested deeper than %d", key, MAX_DEPTH);
    yaml_document_delete(&v);
    yaml_parser_delete(&p);
    return rc;
}

/* The pair of mapping m whose key is `name`, or NULL. */
static yaml_node_pair_t *pair_of(yaml_document_t *d, yaml_node_t *m,
                                 const char *name)
{
    for (yaml_node_pair_t *pr = m->data.mapping.pairs.start;
         pr < m->data.mapping.pairs.top; pr++)
        if (scalar_is(node(d, pr->key), name))
            return pr;
    return NULL;
}

/* The entry of list l that `sel` selects: an index from 0, or the
 * mapping whose `name` is sel. NULL when none. */
static yaml_node_item_t *item_of(yaml_document_t *d, yaml_node_t *l,
                                 const char *sel)
{
    long n = (long)(l->data.sequence.items.top - l->data.sequence.items.start);
    char *end;
    long i = strtol(sel, &end, 10);
    if (end != sel && !*end)
        return i >= 0 && i < n ? l->data.sequence.items.start + i : NULL;
    for (yaml_node_item_t *it = l->data.sequence.items.start;
         it < l->data.sequence.items.top; it++) {
        yaml_node_t *e = node(d, *it);
        yaml_node_pair_t *pr = e && e->type == YAML_MAPPING_NODE
                                   ? pair_of(d, e, "name")
                                   : NULL;
        if (pr && scalar_is(node(d, pr->value), sel))
            return it;
    }
    return NULL;
}

/* Give the nodes from index `first` on the line of `at`. */
static void mark_new(yaml_document_t *d, int first, yaml_mark_t at)
{
    for (yaml_node_t *n = d->nodes.start + first - 1; n < d->nodes.top; n++)
        n->start_mark = n->end_mark = at;
}

static int set_one(yaml_document_t *doc, const char *key, const char *value,
                   ts_err *err)
{
    step st[STEPS_MAX];
    int nst = 0;
    int rc = split(key, st, &nst, err);
    if (rc != TS_OK)
        return rc;
    int first = (int)(doc->nodes.top - doc->nodes.start) + 1;
    int val = 0;
    if (value && (rc = value_nodes(doc, key, value, &val, err)) != TS_OK)
        return rc;
    int cur = 1; /* the root */
    for (int s = 0; s < nst; s++) {
        yaml_node_t *m = node(doc, cur);
        const step *t = &st[s];
        int last = s == nst - 1 && t->nsel == 0;
        if (!m || m->type != YAML_MAPPING_NODE)
            return ts_fail(err, TS_EINVAL, "%s: '%s' is inside %s, not a "
                           "mapping", key, t->name, m ? tsi_scene_kind_name(m) : "nothing");
        yaml_mark_t at = m->start_mark;
        yaml_node_pair_t *pr = pair_of(doc, m, t->name);
        if (!pr) {
            if (!value && last)
                return ts_fail(err, TS_EINVAL, "%s: no such key to remove",
                               key);
            if (t->nsel > 0)
                return ts_fail(err, TS_EINVAL, "%s: the scene has no list "
                               "'%s'", key, t->name);
            int k = yaml_document_add_scalar(doc, NULL,
                                             (yaml_char_t *)t->name, -1,
                                             YAML_PLAIN_SCALAR_STYLE);
            int v = last ? val
                         : yaml_document_add_mapping(
                               doc, NULL, YAML_BLOCK_MAPPING_STYLE);
            if (!k || !v || !yaml_document_append_mapping_pair(doc, cur, k, v))
                return ts_fail(err, TS_ENOMEM, "%s: out of memory", key);
            if (last) {
                mark_new(doc, first, at);
                return TS_OK;
            }
            cur = v;
            continue;
        }
        if (last) {
            if (!value) {
                yaml_node_pair_t *top = m->data.mapping.pairs.top;
                memmove(pr, pr + 1, (size_t)(top - pr - 1) * sizeof *pr);
                m->data.mapping.pairs.top--;
                return TS_OK;
            }
            yaml_node_t *old = node(doc, pr->value);
            pr->value = val;
            mark_new(doc, first, old ? old->start_mark : at);
            return TS_OK;
        }
        cur = pr->value;
        for (int j = 0; j < t->nsel; j++) {
            yaml_node_t *l = node(doc, cur);
            if (!l || l->type != YAML_SEQUENCE_NODE)
                return ts_fail(err, TS_EINVAL, "%s: '%s' is %s, not a list",
                               key, t->name, l ? tsi_scene_kind_name(l) : "empty");
            yaml_node_item_t *it = item_of(doc, l, t->sel[j]);
            if (!it)
                return ts_fail(err, TS_EINVAL, "%s: '%s' has no entry [%s] "
                               "(%d entries, from 0%s)", key, t->name,
                               t->sel[j],
                               (int)(l->data.sequence.items.top -
                                     l->data.sequence.items.start),
                               l->data.sequence.items.top >
                                       l->data.sequence.items.start
                                   ? ", or a name"
                                   : "");
            if (s == nst - 1 && j == t->nsel - 1) {
                if (!value)
                    return ts_fail(err, TS_EINVAL, "%s: a list entry cannot "
                                   "be removed", key);
                yaml_node_t *old = node(doc, *it);
                *it = val;
                mark_new(doc, first, old ? old->start_mark : l->start_mark);
                return TS_OK;
            }
            cur = *it;
        }
    }
    return TS_OK;
}

int tsi_scene_apply(yaml_document_t *doc, int n, const char *const keys[],
                    const char *const values[], ts_err *err)
{
    for (int i = 0; i < n; i++) {
        if (!keys || !keys[i])
            return ts_fail(err, TS_EINVAL, "ts_scene_set: key %d is NULL", i);
        int rc = set_one(doc, keys[i], values ? values[i] : NULL, err);
        if (rc != TS_OK)
            return rc;
    }
    return TS_OK;
}
