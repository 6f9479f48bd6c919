/* scene.c: scene files (YAML) -> ts_system plus a list of analyses
 * (see towstab/scene.h; the format is documented in doc/scene-format.md).
 *
 * Algorithm. libyaml's document API (yaml_parser_load) builds the whole
 * node graph first, so every node keeps its start mark (0-based line,
 * reported + 1). The graph is then walked along the fixed shape of the
 * format: top-level mapping -> blocks -> lists of entries -> scalars. The
 * walk never recurses on the input (its depth is that of the format, at
 * most four levels), so deep or self-referential YAML (aliases) cannot
 * exhaust the stack, and libyaml itself loads without recursion (0.2.x).
 *
 * Order of work: every mapping is first checked against its table of
 * accepted keys (unknown and duplicate keys, keys that are not scalars),
 * then its values are converted. Blocks are read in the order the
 * conversions need, whatever their order in the file: environment (g and
 * rho turn weights into masses), tow, bodies (names for the cables' from
 * and to), cables, analyses. ts_system_build() then checks the tree (loops,
 * bodies ending no cable or two) and builds links and nodes.
 *
 * Errors: TS_ESCENE for structure (YAML syntax, node types, missing,
 * unknown and duplicate keys), TS_EUNIT for units, TS_EINVAL for values out
 * of range, TS_EIO for files, TS_ENOMEM. Every message starts with the scene
 * name, then the key path and the line: "s.yaml: cables[1].length (line
 * 14): must be > 0 m, got -3 m". On every error path the scene and the
 * libyaml document are freed.
 *
 * Limits against hostile input (fuzzing): at most MAX_ENTRIES entries in a
 * list and TS_MAX_LINKS links in the whole system; files up to MAX_FILE_BYTES;
 * flow collections ([...], {...}) nested at most MAX_FLOW_DEPTH deep,
 * checked by a scan before libyaml sees the text: libyaml's scanner takes
 * time quadratic in that depth (100 000 '[' took 40 s).
 *
 * One module, though long: every block (environment, tow, cables, bodies,
 * analyses) is read with the same node walkers, key tables, quantity
 * parsing and line-numbered messages; the blocks apart, each would need
 * those internals.
 */
#include "towstab/scene.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "param_impl.h"
#include "scene_set.h"

/* Largest number of entries in any list (cables, bodies, analyses, options,
 * link_lengths): far beyond a real scene, small enough for int counts. */
#define MAX_ENTRIES 100000
/* Links in the whole system (sum over cables): TS_MAX_LINKS, towstab/system.h. */
/* Deepest nesting of flow collections: the format needs two levels. */
#define MAX_FLOW_DEPTH 64
/* Largest scene file read by ts_scene_load. */
#define MAX_FILE_BYTES (16L * 1024 * 1024)
/* Relative tolerance for link_lengths adding up to the cable length. */
#define LINK_SUM_RTOL 1e-9
/* Room for a key path such as "analyses[12].some_option". */
#define PATH_LEN 160
/* Longest user text (a key, a name) quoted in a message. */
#define SHOW_MAX 40

/* Defaults (doc/scene-format.md). */
#define DEFAULT_CDN 1.2
#define DEFAULT_CDT 0.01
#define DEFAULT_CAN 1.0
#define DEFAULT_SPHERE_CD 0.5
#define DEFAULT_SPHERE_CA 0.5
/* Cylinder (towfish) defaults: a blunt-ended cylinder of length about ten
 * diameters (Hoerner): axial drag on its end area, cross-flow drag on its
 * side area; slender-body added mass, small along the axis. */
#define DEFAULT_CYL_CD_AXIAL 0.8
#define DEFAULT_CYL_CD_CROSS 1.2
#define DEFAULT_CYL_CA_AXIAL 0.1
#define DEFAULT_CYL_CA_CROSS 1.0

typedef struct ctx {
    yaml_document_t *doc;
    const ts_units *units;
    ts_err *err;
} ctx;

/* One accepted key of a mapping and, after read_map(), its value. */
typedef struct field {
    const char *key;
    yaml_node_t *value;     /* NULL when the key is absent */
    int line;               /* line of the key, 1-based */
} field;

/* ------------------------------------------------------------------ */
/* Small helpers                                                        */

/* libyaml marks are 0-based; messages are 1-based. */
static int mark_line(yaml_mark_t m)
{
    return m.line >= (size_t)INT_MAX ? INT_MAX : (int)m.line + 1;
}

static int line_of(const yaml_node_t *n)
{
    return mark_line(n->start_mark);
}

static int mark_column(yaml_mark_t m)
{
    return m.column >= (size_t)INT_MAX ? INT_MAX : (int)m.column + 1;
}

const char *tsi_scene_kind_name(const yaml_node_t *n)
{
    switch (n->type) {
    case YAML_SCALAR_NODE: return "a scalar";
    case YAML_SEQUENCE_NODE: return "a list";
    case YAML_MAPPING_NODE: return "a mapping";
    default: return "an empty node";
    }
}

static int seq_len(const yaml_node_t *n)
{
    ptrdiff_t len = n->data.sequence.items.top - n->data.sequence.items.start;
    return len > INT_MAX ? INT_MAX : (int)len;
}

static yaml_node_t *seq_item(const ctx *c, const yaml_node_t *n, int i)
{
    return yaml_document_get_node(c->doc, n->data.sequence.items.start[i]);
}

/* YAML's null: an empty plain scalar, "~" or "null". */
static int is_null(const yaml_node_t *n)
{
    if (n->type != YAML_SCALAR_NODE ||
        n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE)
        return 0;
    const char *v = (const char *)n->data.scalar.value;
    return !strcmp(v, "") || !strcmp(v, "~") || !strcmp(v, "null") ||
           !strcmp(v, "Null") || !strcmp(v, "NULL");
}

/* Copy user text for a message: printable ASCII kept, other bytes as
 * "\xNN", at most SHOW_MAX characters. */
static const char *show(const char *text, size_t len, char *buf, size_t size)
{
    size_t n = 0;
    for (size_t i = 0; i < len && n + 8 < size; i++) {
        unsigned char ch = (unsigned char)text[i];
        if (i >= SHOW_MAX) {
            memcpy(buf + n, "...", 3);
            n += 3;
            break;
        }
        if (ch < 0x20 || ch >= 0x7f)
            n += (size_t)snprintf(buf + n, size - n, "\\x%02x", ch);
        else
            buf[n++] = (char)ch;
    }
    buf[n] = '\0';
    return buf;
}

#define SHOW_BUF (4 * SHOW_MAX + 16)

/* "path (line N): " + message. Returns code. */
#ifdef __GNUC__
__attribute__((format(printf, 5, 6)))
#endif
static int fail_at(const ctx *c, int code, const char *path, int line,
                   const char *fmt, ...)
{
    char what[TS_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return ts_fail(c->err, code, "%s (line %d): %s", path, line, what);
}

/* Format a key path into out[PATH_LEN]; a path too long to fit (only
 * with absurd user keys) ends in "...". */
#ifdef __GNUC__
__attribute__((format(printf, 2, 3)))
#endif
static const char *path_printf(char *out, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(out, PATH_LEN, fmt, ap);
    va_end(ap);
    if (n < 0)
        out[0] = '\0';
    else if (n >= PATH_LEN)
        memcpy(out + PATH_LEN - 4, "...", 4);
    return out;
}

/* "parent.key" (or "key" at the top level) into out[PATH_LEN]. */
static const char *join(char *out, const char *parent, const char *key)
{
    return parent[0] ? path_printf(out, "%s.%s", parent, key)
                     : path_printf(out, "%s", key);
}

/* "parent[i]" into out[PATH_LEN]. */
static const char *index_path(char *out, const char *parent, int i)
{
    return path_printf(out, "%s[%d]", parent, i);
}

/* ------------------------------------------------------------------ */
/* Mappings                                                             */

/* Check that `map` is a mapping whose keys are all in fields[nf] (each at
 * most once), and attach each value to its field. `path` names the
 * mapping ("" at the top level), `what` says what it should contain. */
static int read_map(const ctx *c, const yaml_node_t *map, const char *path,
                    const char *what, field f[], int nf)
{
    const char *where = path[0] ? path : "top level";
    for (int i = 0; i < nf; i++) {
        f[i].value = NULL;
        f[i].line = 0;
    }
    if (map->type != YAML_MAPPING_NODE)
        return fail_at(c, TS_ESCENE, where, line_of(map),
                       "expected a mapping (%s), got %s", what,
                       tsi_scene_kind_name(map));
    char p[PATH_LEN], s[SHOW_BUF];
    for (yaml_node_pair_t *pair = map->data.mapping.pairs.start;
         pair < map->data.mapping.pairs.top; pair++) {
        yaml_node_t *key = yaml_document_get_node(c->doc, pair->key);
        yaml_node_t *value = yaml_document_get_node(c->doc, pair->value);
        if (!key || !value)
            return ts_fail(c->err, TS_ESCENE, "%s: broken YAML document",
                           where);
        if (key->type != YAML_SCALAR_NODE)
            return fail_at(c, TS_ESCENE, where, line_of(key),
                           "keys must be plain names, got %s as a key",
                           tsi_scene_kind_name(key));
        const char *k = (const char *)key->data.scalar.value;
        size_t klen = key->data.scalar.length;
        int hit = -1;
        for (int i = 0; i < nf && hit < 0; i++)
            if (strlen(f[i].key) == klen && !memcmp(f[i].key, k, klen))
                hit = i;
        if (hit < 0) {
            char keys[512];
            size_t n = 0;
            keys[0] = '\0';
            for (int i = 0; i < nf && n < sizeof keys; i++)
                n += (size_t)snprintf(keys + n, sizeof keys - n, "%s%s",
                                      i ? ", " : "", f[i].key);
            return fail_at(c, TS_ESCENE,
                           join(p, path, show(k, klen, s, sizeof s)),
                           line_of(key),
                           "unknown key; expected one of %s", keys);
        }
        if (f[hit].value)
            return fail_at(c, TS_ESCENE, join(p, path, f[hit].key),
                           line_of(key), "duplicate key (first given on "
                           "line %d)", f[hit].line);
        if (is_null(value))
            return fail_at(c, TS_ESCENE, join(p, path, f[hit].key),
                           line_of(key), "no value; give one, or remove the "
                           "key to use the default");
        f[hit].value = value;
        f[hit].line = line_of(key);
    }
    return TS_OK;
}

static int missing(const ctx *c, const char *path, const yaml_node_t *map,
                   const char *key)
{
    return fail_at(c, TS_ESCENE, path[0] ? path : "top level", line_of(map),
                   "missing key '%s'", key);
}

/* ------------------------------------------------------------------ */
/* Scalars and quantities                                               */

/* The scalar text of a field, refusing other node types and NUL bytes. */
static int field_text(const ctx *c, const char *path, const field *f,
                      const char *expected, const char **text)
{
    const yaml_node_t *n = f->value;
    if (n->type != YAML_SCALAR_NODE)
        return fail_at(c, TS_ESCENE, path, f->line, "expected %s, got %s",
                       expected, tsi_scene_kind_name(n));
    const char *v = (const char *)n->data.scalar.value;
    if (strlen(v) != n->data.scalar.length)
        return fail_at(c, TS_ESCENE, path, f->line, "the value contains a "
                       "NUL character");
    *text = v;
    return TS_OK;
}

/* A quantity in `si` from a scalar node (`line` for messages). */
static int node_quantity(const ctx *c, const char *path, int line,
                         const yaml_node_t *n, const char *si, double *value)
{
    if (n->type != YAML_SCALAR_NODE)
        return fail_at(c, TS_ESCENE, path, line, "expected a number with an "
                       "optional unit, got %s", tsi_scene_kind_name(n));
    const char *v = (const char *)n->data.scalar.value;
    if (strlen(v) != n->data.scalar.length)
        return fail_at(c, TS_ESCENE, path, line, "the value contains a NUL "
                       "character");
    char where[PATH_LEN + 32];
    snprintf(where, sizeof where, "%s (line %d)", path, line);
    return ts_units_parse(c->units, v, si, where, value, c->err);
}

static int field_quantity(const ctx *c, const char *path, const field *f,
                          const char *si, double *value)
{
    return node_quantity(c, path, f->line, f->value, si, value);
}

/* Refuse v unless v > lo (strict) or v >= lo; names the value in SI and,
 * when the scene wrote it with a unit, as written. */
static int check_min(const ctx *c, const char *path, const field *f,
                     double v, double lo, int strict, const char *si)
{
    if (strict ? v > lo : v >= lo)
        return TS_OK;
    const char *unit = strcmp(si, "1") ? si : "";
    char written[SHOW_BUF + 16] = "";
    if (f->value && f->value->type == YAML_SCALAR_NODE) {
        char number[32], s[SHOW_BUF];
        snprintf(number, sizeof number, "%g", v);
        const char *t = (const char *)f->value->data.scalar.value;
        if (strcmp(number, t))
            snprintf(written, sizeof written, " (written \"%s\")",
                     show(t, f->value->data.scalar.length, s, sizeof s));
    }
    return fail_at(c, TS_EINVAL, path, f->line,
                   "must be %s %g%s%s, got %g%s%s%s", strict ? ">" : ">=",
                   lo, unit[0] ? " " : "", unit, v, unit[0] ? " " : "", unit,
                   written);
}

/* An optional quantity >= lo (or > lo) with a default. */
static int optional_min(const ctx *c, const char *parent, const field *f,
                        const char *si, double lo, int strict, double dflt,
                        double *value)
{
    char p[PATH_LEN];
    *value = dflt;
    if (!f->value)
        return TS_OK;
    int rc = field_quantity(c, join(p, parent, f->key), f, si, value);
    if (rc == TS_OK)
        rc = check_min(c, p, f, *value, lo, strict, si);
    return rc;
}

static int optional_any(const ctx *c, const char *parent, const field *f,
                        const char *si, double dflt, double *value);

/* An optional value of key f->key of table t, in the key's unit and
 * checked against its limit as the key table states them (param_impl.h:
 * the same unit and limit as a value set by path). */
static int key_value(const ctx *c, const char *parent, const field *f,
                     tsi_keys t, double dflt, double *value)
{
    const tsi_key *k = tsi_key_find(t, f->key);
    return isfinite(k->min) ? optional_min(c, parent, f, k->unit, k->min,
                                           k->strict, dflt, value)
                            : optional_any(c, parent, f, k->unit, dflt,
                                           value);
}

/* The unit of key f->key of table t (param_impl.h). */
static const char *key_unit(tsi_keys t, const field *f)
{
    return tsi_key_find(t, f->key)->unit;
}

/* A list of exactly three quantities ("[x, y, z]"). */
static int vector3(const ctx *c, const char *parent, const field *f,
                   const char *si, double v[3])
{
    char p[PATH_LEN], pi[PATH_LEN];
    join(p, parent, f->key);
    const yaml_node_t *n = f->value;
    if (n->type != YAML_SEQUENCE_NODE)
        return fail_at(c, TS_ESCENE, p, f->line, "expected a list of 3 "
                       "quantities [x, y, z], got %s", tsi_scene_kind_name(n));
    if (seq_len(n) != 3)
        return fail_at(c, TS_ESCENE, p, f->line, "expected a list of 3 "
                       "quantities [x, y, z], got %d entries", seq_len(n));
    for (int j = 0; j < 3; j++) {
        yaml_node_t *item = seq_item(c, n, j);
        if (!item)
            return ts_fail(c->err, TS_ESCENE, "%s: broken YAML document", p);
        int rc = node_quantity(c, index_path(pi, p, j), line_of(item), item,
                               si, &v[j]);
        if (rc != TS_OK)
            return rc;
    }
    return TS_OK;
}

/* A name: 1 to TS_NAME_MAX - 1 bytes, no control characters. */
static int read_name(const ctx *c, const char *path, const field *f,
                     char out[TS_NAME_MAX])
{
    const char *t = NULL;
    int rc = field_text(c, path, f, "a name", &t);
    if (rc != TS_OK)
        return rc;
    size_t len = strlen(t);
    if (len == 0 || len >= TS_NAME_MAX)
        return fail_at(c, TS_EINVAL, path, f->line, "a name must have 1 to "
                       "%d characters, got %zu", TS_NAME_MAX - 1, len);
    for (size_t i = 0; i < len; i++)
        if ((unsigned char)t[i] < 0x20 || (unsigned char)t[i] == 0x7f)
            return fail_at(c, TS_EINVAL, path, f->line, "a name must not "
                           "contain control characters");
    memcpy(out, t, len + 1);
    return TS_OK;
}

/* A whole number in [1, max] ("20"; "20.0" is accepted, "2.5" is not). */
static int read_count(const ctx *c, const char *path, const field *f,
                      int max, int *out)
{
    const char *t = NULL;
    char s[SHOW_BUF];
    int rc = field_text(c, path, f, "an integer", &t);
    if (rc != TS_OK)
        return rc;
    /* A plain number: no unit (ts_units_parse would take "2000 %" as 20). */
    double x = 0;
    size_t len = f->value->data.scalar.length;
    rc = strspn(t, "0123456789+-.eE \t") == len
             ? ts_units_parse(c->units, t, "1", path, &x, NULL)
             : TS_EINVAL;
    if (rc != TS_OK)
        return fail_at(c, TS_EINVAL, path, f->line, "must be an integer "
                       ">= 1, got \"%s\"", show(t, len, s, sizeof s));
    if (x != floor(x))
        return fail_at(c, TS_EINVAL, path, f->line, "must be an integer "
                       ">= 1, got %g", x);
    if (x < 1)
        return fail_at(c, TS_EINVAL, path, f->line, "must be an integer "
                       ">= 1, got %g", x);
    if (x > max)
        return fail_at(c, TS_EINVAL, path, f->line, "must be at most %d, "
                       "got %g", max, x);
    *out = (int)x;
    return TS_OK;
}

/* Exactly one (required) or at most one of fields f[i] for i in idx[n]:
 * returns the index present in *which (-1 if none). */
static int one_of(const ctx *c, const char *path, const yaml_node_t *map,
                  const field f[], const int idx[], int n, int required,
                  int *which)
{
    *which = -1;
    char names[160] = "", p[PATH_LEN];
    size_t len = 0;
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(names + len, sizeof names - len, "%s%s",
                                i == 0 ? "" : i == n - 1 ? " or " : ", ",
                                f[idx[i]].key);
    for (int i = 0; i < n; i++) {
        const field *fi = &f[idx[i]];
        if (!fi->value)
            continue;
        if (*which >= 0)
            return fail_at(c, TS_ESCENE, join(p, path, fi->key), fi->line,
                           "give only one of %s ('%s' is given on line %d)",
                           names, f[*which].key, f[*which].line);
        *which = idx[i];
    }
    if (required && *which < 0)
        return fail_at(c, TS_ESCENE, path, line_of(map), "missing key: give "
                       "one of %s", names);
    return TS_OK;
}

/* Weight with g > 0 needed: refuse a weight when g is zero. */
static int need_gravity(const ctx *c, const char *path, const field *f,
                        double g, const char *mass_key)
{
    if (g > 0)
        return TS_OK;
    return fail_at(c, TS_EINVAL, path, f->line, "environment.gravity is 0, "
                   "so a weight gives no mass: use '%s'", mass_key);
}

/* ------------------------------------------------------------------ */
/* Blocks                                                               */

static int parse_environment(const ctx *c, const yaml_node_t *n,
                             ts_environment *env)
{
    enum { E_RHO, E_G, E_CURRENT, E_N };
    field f[E_N] = {{"water_density", 0, 0}, {"gravity", 0, 0},
                    {"current", 0, 0}};
    int rc = read_map(c, n, "environment", "water_density, gravity, current",
                      f, E_N);
    if (rc == TS_OK)
        rc = key_value(c, "environment", &f[E_RHO], TSI_KEYS_ENV,
                       env->water_density, &env->water_density);
    if (rc == TS_OK)
        rc = key_value(c, "environment", &f[E_G], TSI_KEYS_ENV,
                       env->gravity, &env->gravity);
    if (rc == TS_OK && f[E_CURRENT].value)
        rc = vector3(c, "environment", &f[E_CURRENT],
                     key_unit(TSI_KEYS_ENV, &f[E_CURRENT]), env->current);
    return rc;
}

/* The scalar text of a field as written, into buf ("" when absent or
 * not a scalar). */
static void written(const field *f, char *buf, size_t size)
{
    buf[0] = '\0';
    if (f->value && f->value->type == YAML_SCALAR_NODE &&
        f->value->data.scalar.length < size)
        snprintf(buf, size, "%.*s", (int)f->value->data.scalar.length,
                 (const char *)f->value->data.scalar.value);
}

static int parse_tow(const ctx *c, const yaml_node_t *n, ts_tow *tow,
                     ts_scene *scene)
{
    enum { T_SPEED, T_TURN, T_POINT, T_N };
    field f[T_N] = {{"speed", 0, 0}, {"turn_rate", 0, 0}, {"point", 0, 0}};
    int rc = read_map(c, n, "tow", "speed, turn_rate, point", f, T_N);
    if (rc != TS_OK)
        return rc;
    if (!f[T_SPEED].value)
        return missing(c, "tow", n, "speed");
    rc = key_value(c, "tow", &f[T_SPEED], TSI_KEYS_TOW, 0.0, &tow->speed);
    if (rc == TS_OK)
        rc = key_value(c, "tow", &f[T_TURN], TSI_KEYS_TOW, tow->turn_rate,
                       &tow->turn_rate);
    if (rc == TS_OK && f[T_POINT].value)
        rc = vector3(c, "tow", &f[T_POINT], key_unit(TSI_KEYS_TOW,
                                                     &f[T_POINT]),
                     tow->point);
    written(&f[T_SPEED], scene->speed_text, sizeof scene->speed_text);
    written(&f[T_TURN], scene->turn_rate_text, sizeof scene->turn_rate_text);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Vehicles (doc/scene-format.md, "Vehicles"; towstab/vehicle.h)          */

/* A list node of the field, refusing other kinds; its length in *n. */
static int field_list(const ctx *c, const char *path, const field *f,
                      const char *what, int max, int *n)
{
    if (f->value->type != YAML_SEQUENCE_NODE)
        return fail_at(c, TS_ESCENE, path, f->line, "expected a list of %s, "
                       "got %s", what, tsi_scene_kind_name(f->value));
    *n = seq_len(f->value);
    if (*n > max)
        return fail_at(c, TS_EINVAL, path, f->line, "has %d entries, at "
                       "most %d are allowed", *n, max);
    return TS_OK;
}

/* A list of `n` quantities (lo <= n <= hi entries) in unit si. */
static int quantity_list(const ctx *c, const char *path, const field *f,
                         const char *si, int lo, int hi, double *v, int *n)
{
    char pi[PATH_LEN];
    int rc = field_list(c, path, f, "quantities", hi, n);
    if (rc == TS_OK && *n < lo)
        rc = fail_at(c, TS_EINVAL, path, f->line, "needs %d to %d entries, "
                     "got %d", lo, hi, *n);
    for (int j = 0; rc == TS_OK && j < *n; j++) {
        yaml_node_t *item = seq_item(c, f->value, j);
        rc = item ? node_quantity(c, index_path(pi, path, j), line_of(item),
                                  item, si, &v[j])
                  : ts_fail(c->err, TS_ESCENE, "%s: broken YAML document",
                            path);
    }
    return rc;
}

/* An optional quantity of any sign (finite), with a default. */
static int optional_any(const ctx *c, const char *parent, const field *f,
                        const char *si, double dflt, double *value)
{
    char p[PATH_LEN];
    *value = dflt;
    if (!f->value)
        return TS_OK;
    return field_quantity(c, join(p, parent, f->key), f, si, value);
}

/* A YAML boolean: true/false, yes/no, on/off. */
static int field_bool(const ctx *c, const char *path, const field *f,
                      int *value)
{
    const char *t = NULL;
    int rc = field_text(c, path, f, "true or false", &t);
    if (rc != TS_OK)
        return rc;
    static const char *const yes[] = {"true", "True", "TRUE", "yes", "Yes",
                                      "on"};
    static const char *const no[] = {"false", "False", "FALSE", "no", "No",
                                     "off"};
    for (int i = 0; i < 6; i++) {
        if (!strcmp(t, yes[i])) {
            *value = 1;
            return TS_OK;
        }
        if (!strcmp(t, no[i])) {
            *value = 0;
            return TS_OK;
        }
    }
    char s[SHOW_BUF];
    return fail_at(c, TS_EINVAL, path, f->line, "expected true or false, got "
                   "\"%s\"", show(t, f->value->data.scalar.length, s,
                                  sizeof s));
}

/* A lift/drag table: rows [alpha, C_L, C_D], alpha an angle. */
static int parse_table(const ctx *c, const char *path, const field *f,
                       ts_component *cp)
{
    char pr[PATH_LEN];
    int n = 0, rc = field_list(c, path, f, "rows [alpha, C_L, C_D]",
                           TS_CURVE_MAX_POINTS, &n);
    if (rc == TS_OK && n < 3)
        rc = fail_at(c, TS_EINVAL, path, f->line, "needs 3 to %d rows, got "
                     "%d", TS_CURVE_MAX_POINTS, n);
    for (int j = 0; rc == TS_OK && j < n; j++) {
        yaml_node_t *row = seq_item(c, f->value, j);
        if (!row)
            return ts_fail(c->err, TS_ESCENE, "%s: broken YAML document",
                           path);
        index_path(pr, path, j);
        if (row->type != YAML_SEQUENCE_NODE || seq_len(row) != 3)
            return fail_at(c, TS_ESCENE, pr, line_of(row), "expected a row "
                           "of 3 numbers [alpha, C_L, C_D]");
        /* The angle may carry its unit ("-10 deg"); C_L and C_D do not. */
        static const char *const unit[3] = {"rad", "1", "1"};
        double *out[3] = {&cp->alpha[j], &cp->cl[j], &cp->cd[j]};
        for (int q = 0; rc == TS_OK && q < 3; q++) {
            yaml_node_t *item = seq_item(c, row, q);
            char pq[PATH_LEN];
            rc = item ? node_quantity(c, index_path(pq, pr, q),
                                      line_of(item), item, unit[q], out[q])
                      : ts_fail(c->err, TS_ESCENE, "%s: broken YAML", pr);
        }
    }
    cp->npoints = n;
    cp->curve = TS_CURVE_TABLE;
    return rc;
}

static int parse_component(const ctx *c, const yaml_node_t *n,
                           const char *parent, int j, ts_component *cp)
{
    enum { K_NAME, K_TYPE, K_POS, K_LEN, K_DIAM, K_AXD, K_XD, K_AREA, K_DRAG,
           K_SPAN, K_ROLL, K_INC, K_SLOPE, K_STALL, K_WIDTH, K_CD0, K_EFF,
           K_CN90, K_TABLE, K_CONTROL, K_DEFL, K_LIMIT, K_RATE, K_TAU,
           K_CHORD, K_THICK, K_CAP, K_FILL, K_N };
    field f[K_N] = {{"name", 0, 0}, {"type", 0, 0}, {"position", 0, 0},
                    {"length", 0, 0}, {"diameter", 0, 0},
                    {"axial_drag", 0, 0}, {"cross_drag", 0, 0},
                    {"area", 0, 0}, {"drag", 0, 0}, {"span", 0, 0},
                    {"roll", 0, 0},
                    {"incidence", 0, 0}, {"lift_slope", 0, 0},
                    {"stall", 0, 0}, {"stall_width", 0, 0},
                    {"zero_lift_drag", 0, 0}, {"efficiency", 0, 0},
                    {"cn90", 0, 0}, {"table", 0, 0}, {"control", 0, 0},
                    {"deflection", 0, 0}, {"limit", 0, 0},
                    {"rate_limit", 0, 0}, {"time_constant", 0, 0},
                    {"chord", 0, 0}, {"thickness", 0, 0},
                    {"capacity", 0, 0}, {"fill", 0, 0}};
    char path[PATH_LEN], p[PATH_LEN], s[SHOW_BUF];
    index_path(path, parent, j);
    int rc = read_map(c, n, path, "name, type, position, ...", f, K_N);
    if (rc != TS_OK)
        return rc;
    for (int k = 0; k <= K_TYPE; k++)
        if (!f[k].value)
            return missing(c, path, n, f[k].key);
    const char *type = NULL;
    rc = field_text(c, join(p, path, "type"), &f[K_TYPE],
                    "hull, surface, bluff, mast or ballast", &type);
    if (rc != TS_OK)
        return rc;
    int hull = !strcmp(type, "hull"), bluff = !strcmp(type, "bluff");
    int mast = !strcmp(type, "mast"), tank = !strcmp(type, "ballast");
    if (!hull && !bluff && !mast && !tank && strcmp(type, "surface"))
        return fail_at(c, TS_EINVAL, p, f[K_TYPE].line, "unknown component "
                       "type \"%s\"; expected hull, surface, bluff, mast or "
                       "ballast",
                       show(type, f[K_TYPE].value->data.scalar.length, s,
                            sizeof s));
    ts_component_defaults(cp, hull    ? TS_COMP_HULL
                              : bluff ? TS_COMP_BLUFF
                              : mast  ? TS_COMP_MAST
                              : tank  ? TS_COMP_BALLAST
                                      : TS_COMP_SURFACE);
    cp->line = line_of(n);
    rc = read_name(c, join(p, path, "name"), &f[K_NAME], cp->name);
    if (rc != TS_OK)
        return rc;
    /* Keys of the other types are refused: a hull's run to K_XD, a
     * bluff part has an area and a drag, a mast a length, an area, a
     * chord and a thickness, a ballast tank a capacity, a fill, a rate
     * limit and a time constant, a surface an area and the rest. */
    for (int k = K_LEN; k <= K_FILL; k++) {
        int ok = hull    ? k <= K_XD
                 : bluff ? (k == K_AREA || k == K_DRAG)
                 : mast  ? (k == K_LEN || k == K_AREA || k == K_CHORD ||
                            k == K_THICK || k == K_DRAG)
                 : tank  ? (k == K_CAP || k == K_FILL || k == K_RATE ||
                            k == K_TAU)
                         : (k >= K_AREA && k != K_DRAG && k < K_CHORD);
        if (f[k].value && !ok)
            return fail_at(c, TS_ESCENE, join(p, path, f[k].key), f[k].line,
                           "does not apply to a %s component", type);
    }
    /* The key table of the component's type (param_impl.h). */
    tsi_keys keys = hull    ? TSI_KEYS_HULL
                    : bluff ? TSI_KEYS_BLUFF
                    : mast  ? TSI_KEYS_MAST
                    : tank  ? TSI_KEYS_BALLAST
                            : TSI_KEYS_SURFACE;
    if (f[K_POS].value)
        rc = vector3(c, path, &f[K_POS], key_unit(keys, &f[K_POS]),
                     cp->position);
    if (rc == TS_OK && hull) {
        for (int k = K_LEN; k <= K_DIAM; k++)
            if (!f[k].value)
                return missing(c, path, n, f[k].key);
        if ((rc = key_value(c, path, &f[K_LEN], keys, 0, &cp->length)) ||
            (rc = key_value(c, path, &f[K_DIAM], keys, 0, &cp->diameter)) ||
            (rc = key_value(c, path, &f[K_AXD], keys, cp->cd_axial,
                            &cp->cd_axial)) ||
            (rc = key_value(c, path, &f[K_XD], keys, cp->cd_cross,
                            &cp->cd_cross)))
            return rc;
        return TS_OK;
    }
    if (rc != TS_OK)
        return rc;
    if (tank) {
        /* A tank is a control component: its fill (kg) the deflection. */
        cp->control = 1;
        if (!f[K_CAP].value)
            return missing(c, path, n, "capacity");
        if ((rc = key_value(c, path, &f[K_CAP], keys, 0, &cp->capacity)) ||
            (rc = key_value(c, path, &f[K_FILL], keys, 0,
                            &cp->deflection)) ||
            (rc = key_value(c, path, &f[K_RATE], keys, INFINITY,
                            &cp->rate_limit)) ||
            (rc = key_value(c, path, &f[K_TAU], keys, 0,
                            &cp->time_constant)))
            return rc;
        if (cp->deflection > cp->capacity)
            return fail_at(c, TS_EINVAL, join(p, path, "fill"),
                           f[K_FILL].line, "%g kg is more than the tank's "
                           "capacity %g kg", cp->deflection, cp->capacity);
        return TS_OK;
    }
    if (mast) {
        static const int need[4] = {K_LEN, K_AREA, K_CHORD, K_THICK};
        for (int k = 0; k < 4; k++)
            if (!f[need[k]].value)
                return missing(c, path, n, f[need[k]].key);
        for (int k = 0; k < 4; k++) {
            double *dst = need[k] == K_LEN    ? &cp->length
                          : need[k] == K_AREA ? &cp->area
                          : need[k] == K_CHORD ? &cp->chord
                                               : &cp->thickness;
            if ((rc = key_value(c, path, &f[need[k]], keys, 0, dst)))
                return rc;
        }
        /* Optional: the drag on its submerged frontal area (0: none). */
        return key_value(c, path, &f[K_DRAG], keys, cp->drag, &cp->drag);
    }
    if (bluff) {
        if (!f[K_AREA].value)
            return missing(c, path, n, "area");
        if ((rc = key_value(c, path, &f[K_AREA], keys, 0, &cp->area)) ||
            (rc = key_value(c, path, &f[K_DRAG], keys, cp->drag,
                            &cp->drag)))
            return rc;
        return TS_OK;
    }
    if (!f[K_AREA].value)
        return missing(c, path, n, "area");
    if (!f[K_SPAN].value)
        return missing(c, path, n, "span");
    if ((rc = key_value(c, path, &f[K_AREA], TSI_KEYS_SURFACE, 0,
                        &cp->area)) ||
        (rc = key_value(c, path, &f[K_SPAN], TSI_KEYS_SURFACE, 0,
                        &cp->span)) ||
        (rc = key_value(c, path, &f[K_ROLL], TSI_KEYS_SURFACE, 0,
                        &cp->roll)) ||
        (rc = key_value(c, path, &f[K_INC], TSI_KEYS_SURFACE, 0,
                        &cp->incidence)) ||
        (rc = key_value(c, path, &f[K_SLOPE], TSI_KEYS_SURFACE, 0,
                        &cp->lift_slope)) ||
        (rc = key_value(c, path, &f[K_STALL], TSI_KEYS_SURFACE, cp->stall,
                        &cp->stall)) ||
        (rc = key_value(c, path, &f[K_WIDTH], TSI_KEYS_SURFACE,
                        cp->stall_width, &cp->stall_width)) ||
        (rc = key_value(c, path, &f[K_CD0], TSI_KEYS_SURFACE, cp->cd0,
                        &cp->cd0)) ||
        (rc = key_value(c, path, &f[K_EFF], TSI_KEYS_SURFACE,
                        cp->efficiency, &cp->efficiency)) ||
        (rc = key_value(c, path, &f[K_CN90], TSI_KEYS_SURFACE, cp->cn90,
                        &cp->cn90)))
        return rc;
    if (f[K_TABLE].value) {
        static const int curve_keys[] = {K_SLOPE, K_STALL, K_WIDTH, K_CD0,
                                         K_EFF, K_CN90};
        for (int k = 0; k < 6; k++)
            if (f[curve_keys[k]].value)
                return fail_at(c, TS_ESCENE,
                               join(p, path, f[curve_keys[k]].key),
                               f[curve_keys[k]].line, "a lifting-line "
                               "parameter; the surface's curves come from "
                               "its table (line %d)", f[K_TABLE].line);
        rc = parse_table(c, join(p, path, "table"), &f[K_TABLE], cp);
        if (rc != TS_OK)
            return rc;
    }
    if (f[K_CONTROL].value &&
        (rc = field_bool(c, join(p, path, "control"), &f[K_CONTROL],
                         &cp->control)))
        return rc;
    if (!cp->control)
        for (int k = K_DEFL; k <= K_TAU; k++)
            if (f[k].value)
                return fail_at(c, TS_ESCENE, join(p, path, f[k].key),
                               f[k].line, "applies to a control surface "
                               "(control: true)");
    if ((rc = key_value(c, path, &f[K_DEFL], TSI_KEYS_SURFACE, 0,
                        &cp->deflection)) ||
        (rc = key_value(c, path, &f[K_LIMIT], TSI_KEYS_SURFACE, INFINITY,
                           &cp->limit)) ||
        (rc = key_value(c, path, &f[K_RATE], TSI_KEYS_SURFACE, INFINITY,
                        &cp->rate_limit)) ||
        (rc = key_value(c, path, &f[K_TAU], TSI_KEYS_SURFACE, 0,
                        &cp->time_constant)))
        return rc;
    return TS_OK;
}

static int parse_loop(const ctx *c, const yaml_node_t *n, const char *parent,
                      int j, ts_vehicle *v)
{
    enum { L_NAME, L_MEASURE, L_SET, L_KP, L_KI, L_KD, L_SURF, L_N };
    field f[L_N] = {{"name", 0, 0}, {"measure", 0, 0}, {"setpoint", 0, 0},
                    {"kp", 0, 0}, {"ki", 0, 0}, {"kd", 0, 0},
                    {"surfaces", 0, 0}};
    char path[PATH_LEN], p[PATH_LEN], s[SHOW_BUF];
    index_path(path, parent, j);
    ts_loop *lp = &v->loop[j];
    memset(lp, 0, sizeof *lp);
    lp->line = line_of(n);
    int rc = read_map(c, n, path, "name, measure, setpoint, kp, ki, kd, "
                      "surfaces", f, L_N);
    if (rc != TS_OK)
        return rc;
    static const int required[] = {L_NAME, L_MEASURE, L_SET, L_SURF};
    for (int k = 0; k < 4; k++)
        if (!f[required[k]].value)
            return missing(c, path, n, f[required[k]].key);
    rc = read_name(c, join(p, path, "name"), &f[L_NAME], lp->name);
    const char *m = NULL;
    if (rc == TS_OK)
        rc = field_text(c, join(p, path, "measure"), &f[L_MEASURE],
                        "depth, pitch, roll or heading", &m);
    if (rc != TS_OK)
        return rc;
    static const char *const names[4] = {"depth", "pitch", "roll", "heading"};
    int mi = -1;
    for (int k = 0; k < 4; k++)
        if (!strcmp(m, names[k]))
            mi = k;
    if (mi < 0)
        return fail_at(c, TS_EINVAL, p, f[L_MEASURE].line, "unknown "
                       "measurement \"%s\"; expected depth, pitch, roll or "
                       "heading",
                       show(m, f[L_MEASURE].value->data.scalar.length, s,
                            sizeof s));
    lp->measure = (ts_measure)mi;
    /* Units from what the loop measures, as values by path take them. */
    int depth = lp->measure == TS_MEASURE_DEPTH;
    if ((rc = optional_any(c, path, &f[L_SET], tsi_loop_unit(depth, "setpoint"),
                           0, &lp->setpoint)) ||
        (rc = optional_any(c, path, &f[L_KP], tsi_loop_unit(depth, "kp"), 0,
                           &lp->kp)) ||
        (rc = optional_any(c, path, &f[L_KI], tsi_loop_unit(depth, "ki"), 0,
                           &lp->ki)) ||
        (rc = optional_any(c, path, &f[L_KD], tsi_loop_unit(depth, "kd"), 0,
                           &lp->kd)))
        return rc;
    /* surfaces: a list of surface names (gain 1 each) or a mapping of
     * surface names to gains. */
    const yaml_node_t *sn = f[L_SURF].value;
    join(p, path, "surfaces");
    if (sn->type == YAML_SEQUENCE_NODE || sn->type == YAML_MAPPING_NODE) {
        int count = sn->type == YAML_SEQUENCE_NODE
                        ? seq_len(sn)
                        : (int)(sn->data.mapping.pairs.top -
                                sn->data.mapping.pairs.start);
        if (count < 1 || count > v->ncomponents)
            return fail_at(c, TS_EINVAL, p, f[L_SURF].line, "needs 1 to %d "
                           "control surfaces, got %d",
                           v->ncomponents > 0 ? v->ncomponents : 1, count);
        for (int k = 0; k < count; k++) {
            yaml_node_t *name_node, *gain_node = NULL;
            if (sn->type == YAML_SEQUENCE_NODE) {
                name_node = seq_item(c, sn, k);
            } else {
                yaml_node_pair_t *pr = sn->data.mapping.pairs.start + k;
                name_node = yaml_document_get_node(c->doc, pr->key);
                gain_node = yaml_document_get_node(c->doc, pr->value);
            }
            if (!name_node || name_node->type != YAML_SCALAR_NODE)
                return fail_at(c, TS_ESCENE, p, f[L_SURF].line, "expected "
                               "surface names");
            const char *nm = (const char *)name_node->data.scalar.value;
            int ci = -1;
            for (int q = 0; q < v->ncomponents; q++)
                if (!strcmp(v->component[q].name, nm))
                    ci = q;
            if (ci < 0 || !v->component[ci].control)
                return fail_at(c, TS_EINVAL, p, line_of(name_node), "'%s' is "
                               "not a control surface of the vehicle (a "
                               "surface with control: true)",
                               show(nm, name_node->data.scalar.length, s,
                                    sizeof s));
            for (int q = 0; q < k; q++)
                if (lp->surface[q] == ci)
                    return fail_at(c, TS_EINVAL, p, line_of(name_node),
                                   "'%s' is listed twice", nm);
            lp->surface[k] = ci;
            lp->gain[k] = 1.0;
            if (gain_node) {
                char pg[PATH_LEN];
                path_printf(pg, "%s.%s", p, v->component[ci].name);
                rc = node_quantity(c, pg, line_of(gain_node), gain_node, "1",
                                   &lp->gain[k]);
                if (rc != TS_OK)
                    return rc;
            }
        }
        lp->nsurfaces = count;
        return TS_OK;
    }
    return fail_at(c, TS_ESCENE, p, f[L_SURF].line, "expected a list of "
                   "surface names or a mapping of names to gains, got %s",
                   tsi_scene_kind_name(sn));
}

/* added_mass of a vehicle: "spheroid" (of its first hull), "none", a
 * mapping {length, diameter, centre} or a 6x6 list of lists (SI). */
static int parse_added_mass(const ctx *c, const char *parent, const field *f,
                            double rho, ts_vehicle *v)
{
    char p[PATH_LEN], pr[PATH_LEN], s[SHOW_BUF];
    join(p, parent, "added_mass");
    const yaml_node_t *n = f ? f->value : NULL;
    const ts_component *hull = NULL;
    for (int j = 0; j < v->ncomponents && !hull; j++)
        if (v->component[j].type == TS_COMP_HULL)
            hull = &v->component[j];
    ts_err local = {0};
    if (!n || (n->type == YAML_SCALAR_NODE &&
               !strcmp((const char *)n->data.scalar.value, "spheroid"))) {
        if (!hull) {
            if (n)
                return fail_at(c, TS_EINVAL, p, f->line, "a spheroid "
                               "estimate needs a hull component (its length "
                               "and diameter), or give length and diameter");
            return TS_OK; /* no hull, nothing given: no added mass */
        }
        v->added_mass_estimated = 1;
        v->estimate_follows_hull = 1;
        v->estimate_length = hull->length;
        v->estimate_diameter = hull->diameter;
        memcpy(v->estimate_centre, hull->position, sizeof v->estimate_centre);
    } else if (n->type == YAML_SCALAR_NODE) {
        if (!strcmp((const char *)n->data.scalar.value, "none"))
            return TS_OK;
        return fail_at(c, TS_EINVAL, p, f->line, "expected spheroid, none, a "
                       "mapping {length, diameter, centre} or 6 rows of 6 "
                       "numbers, got \"%s\"",
                       show((const char *)n->data.scalar.value,
                            n->data.scalar.length, s, sizeof s));
    } else if (n->type == YAML_MAPPING_NODE) {
        enum { A_LEN, A_DIAM, A_CENTRE, A_N };
        field g[A_N] = {{"length", 0, 0}, {"diameter", 0, 0},
                        {"centre", 0, 0}};
        int rc = read_map(c, n, p, "length, diameter, centre", g, A_N);
        for (int k = 0; rc == TS_OK && k < 2; k++)
            if (!g[k].value)
                rc = missing(c, p, n, g[k].key);
        if (rc == TS_OK)
            rc = optional_min(c, p, &g[A_LEN], "m", 0, 1, 0,
                              &v->estimate_length);
        if (rc == TS_OK)
            rc = optional_min(c, p, &g[A_DIAM], "m", 0, 1, 0,
                              &v->estimate_diameter);
        if (rc == TS_OK && g[A_CENTRE].value)
            rc = vector3(c, p, &g[A_CENTRE], "m", v->estimate_centre);
        if (rc != TS_OK)
            return rc;
        v->added_mass_estimated = 1;
    } else {
        int nrow = 0;
        int rc = field_list(c, p, f, "6 rows of 6 numbers", 6, &nrow);
        if (rc == TS_OK && nrow != 6)
            rc = fail_at(c, TS_EINVAL, p, f->line, "needs 6 rows of 6 "
                         "numbers (SI: kg, kg m, kg m^2), got %d rows", nrow);
        for (int i = 0; rc == TS_OK && i < 6; i++) {
            yaml_node_t *row = seq_item(c, n, i);
            field fr = {"", row, row ? line_of(row) : f->line};
            int m = 0;
            if (!row)
                return ts_fail(c->err, TS_ESCENE, "%s: broken YAML", p);
            rc = quantity_list(c, index_path(pr, p, i), &fr, "1", 6, 6,
                               v->added_mass + 6 * i, &m);
        }
        return rc;
    }
    double A[36];
    if (ts_added_mass_spheroid(rho, v->estimate_length, v->estimate_diameter,
                               A, NULL, &local) != TS_OK)
        return fail_at(c, TS_EINVAL, p, f ? f->line : 0, "%s", local.msg);
    ts_added_mass_shift(A, v->estimate_centre, v->added_mass);
    return TS_OK;
}

/* The keys of vehicle body b (g[]: volume, inertia, mass_centre,
 * buoyancy_centre, attach, surface_diameter, components, controllers, as
 * parse_body lists them; `added` its added_mass or NULL) into a new
 * ts_vehicle; the mass keys are parse_body's. */
static int parse_vehicle(const ctx *c, const yaml_node_t *n, const char *path,
                         const field *g, const field *added, ts_system *sys,
                         int b)
{
    enum { V_VOLUME, V_INERTIA, V_MC, V_BC, V_ATTACH, V_SURF, V_COMPONENTS,
           V_CONTROLLERS };
    char p[PATH_LEN], pc[PATH_LEN];
    ts_vehicle *v = ts_body_set_vehicle(sys, b, c->err);
    if (!v)
        return TS_ENOMEM;
    static const int required[] = {V_VOLUME, V_INERTIA, V_ATTACH,
                                   V_COMPONENTS};
    for (int k = 0; k < 4; k++)
        if (!g[required[k]].value)
            return missing(c, path, n, g[required[k]].key);
    int rc = key_value(c, path, &g[V_VOLUME], TSI_KEYS_VEHICLE, 0,
                       &v->volume);
    double I[6] = {0};
    int ni = 0;
    if (rc == TS_OK)
        rc = quantity_list(c, join(p, path, "inertia"), &g[V_INERTIA],
                           key_unit(TSI_KEYS_VEHICLE, &g[V_INERTIA]), 3, 6,
                           I, &ni);
    if (rc == TS_OK && ni != 3 && ni != 6)
        rc = fail_at(c, TS_EINVAL, p, g[V_INERTIA].line, "expected [Ixx, "
                     "Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], got %d "
                     "entries", ni);
    memcpy(v->inertia, I, sizeof I);
    if (rc == TS_OK && g[V_MC].value)
        rc = vector3(c, path, &g[V_MC], key_unit(TSI_KEYS_VEHICLE, &g[V_MC]),
                     v->mass_centre);
    if (rc == TS_OK && g[V_BC].value)
        rc = vector3(c, path, &g[V_BC], key_unit(TSI_KEYS_VEHICLE, &g[V_BC]),
                     v->buoyancy_centre);
    if (rc == TS_OK)
        rc = vector3(c, path, &g[V_ATTACH], /* a towing vehicle's tow_point */
                     tsi_key_find(TSI_KEYS_VEHICLE, "attach")->unit,
                     v->attach);
    int nc = 0;
    if (rc == TS_OK)
        rc = field_list(c, join(p, path, "components"), &g[V_COMPONENTS],
                        "components", TS_VEHICLE_MAX_COMPONENTS, &nc);
    for (int j = 0; rc == TS_OK && j < nc; j++) {
        yaml_node_t *item = seq_item(c, g[V_COMPONENTS].value, j);
        rc = item ? parse_component(c, item, p, j, &v->component[j])
                  : ts_fail(c->err, TS_ESCENE, "%s: broken YAML", p);
        for (int q = 0; rc == TS_OK && q < j; q++)
            if (!strcmp(v->component[q].name, v->component[j].name))
                rc = fail_at(c, TS_EINVAL, index_path(pc, p, j),
                             v->component[j].line, "duplicate component "
                             "name '%s'", v->component[j].name);
        v->ncomponents = j + 1;
    }
    if (rc == TS_OK)
        rc = parse_added_mass(c, path, added, sys->env.water_density, v);
    /* The height that decides the submerged fraction near the surface:
     * given, or the first hull's diameter, or a sphere of the volume. */
    double dflt = cbrt(6.0 * v->volume / M_PI);
    for (int j = nc - 1; j >= 0; j--)
        if (v->component[j].type == TS_COMP_HULL)
            dflt = v->component[j].diameter;
    v->surface_diameter_derived = !g[V_SURF].value;
    if (rc == TS_OK)
        rc = key_value(c, path, &g[V_SURF], TSI_KEYS_VEHICLE, dflt,
                       &v->surface_diameter);
    int nl = 0;
    if (rc == TS_OK && g[V_CONTROLLERS].value)
        rc = field_list(c, join(p, path, "controllers"), &g[V_CONTROLLERS],
                        "controllers", TS_VEHICLE_MAX_LOOPS, &nl);
    for (int j = 0; rc == TS_OK && j < nl; j++) {
        yaml_node_t *item = seq_item(c, g[V_CONTROLLERS].value, j);
        rc = item ? parse_loop(c, item, p, j, v)
                  : ts_fail(c->err, TS_ESCENE, "%s: broken YAML", p);
        v->nloops = j + 1;
    }
    return rc;
}

/* A towing vehicle's propulsion (towstab/vehicle.h, ts_propulsion):
 * exactly one of thrust, power (with max_thrust) or speed (a speed
 * controller with gain and integral_gain, its bias solved, or with an
 * integral gain 0 and the integrator carrying the thrust, max_thrust its
 * cap), and the point `at` where the thrust acts. */
static int parse_propulsion(const ctx *c, const field *fp, const char *parent,
                            ts_propulsion *pr)
{
    enum { P_THRUST, P_POWER, P_SPEED, P_MAX, P_GAIN, P_KI, P_AT, P_N };
    field f[P_N] = {{"thrust", 0, 0},     {"power", 0, 0},
                    {"speed", 0, 0},      {"max_thrust", 0, 0},
                    {"gain", 0, 0},       {"integral_gain", 0, 0},
                    {"at", 0, 0}};
    char path[PATH_LEN], p[PATH_LEN];
    join(path, parent, "propulsion");
    pr->line = fp->line;
    int rc = read_map(c, fp->value, path, "thrust, power or speed, ...", f,
                      P_N);
    if (rc != TS_OK)
        return rc;
    static const int laws[] = {P_THRUST, P_POWER, P_SPEED};
    int which;
    rc = one_of(c, path, fp->value, f, laws, 3, 1, &which);
    if (rc != TS_OK)
        return rc;
    /* Units and limits: the key table's (param_impl.h), as by path. */
    const tsi_keys t = TSI_KEYS_PROPULSION;
    pr->max_thrust = INFINITY;
    if (which == P_THRUST) {
        pr->type = TS_PROP_THRUST;
        rc = key_value(c, path, &f[P_THRUST], t, 0.0, &pr->thrust);
    } else if (which == P_POWER) {
        pr->type = TS_PROP_POWER;
        if (!f[P_MAX].value)
            return fail_at(c, TS_ESCENE, path, fp->line, "missing key "
                           "'max_thrust': the constant-power law T = P / U "
                           "needs its cap at low speed (the bollard "
                           "thrust)");
        rc = key_value(c, path, &f[P_POWER], t, 0.0, &pr->power);
        if (rc == TS_OK)
            rc = key_value(c, path, &f[P_MAX], t, INFINITY, &pr->max_thrust);
    } else {
        pr->type = TS_PROP_SPEED;
        rc = key_value(c, path, &f[P_SPEED], t, 0.0, &pr->speed);
        if (rc == TS_OK)
            rc = key_value(c, path, &f[P_GAIN], t, 0.0, &pr->gain);
        if (rc == TS_OK)
            rc = key_value(c, path, &f[P_KI], t, 0.0, &pr->ki);
        if (rc == TS_OK)
            rc = key_value(c, path, &f[P_MAX], t, INFINITY, &pr->max_thrust);
    }
    if (rc == TS_OK && which == P_THRUST && f[P_MAX].value)
        rc = fail_at(c, TS_ESCENE, join(p, path, "max_thrust"), f[P_MAX].line,
                     "applies to a power law or a speed controller only");
    if (rc == TS_OK && which != P_SPEED && f[P_GAIN].value)
        rc = fail_at(c, TS_ESCENE, join(p, path, "gain"), f[P_GAIN].line,
                     "applies to a speed controller only");
    if (rc == TS_OK && which != P_SPEED && f[P_KI].value)
        rc = fail_at(c, TS_ESCENE, join(p, path, "integral_gain"),
                     f[P_KI].line, "applies to a speed controller only");
    if (rc == TS_OK && f[P_AT].value)
        rc = vector3(c, path, &f[P_AT], key_unit(t, &f[P_AT]), pr->position);
    return rc;
}

static int parse_body(const ctx *c, const yaml_node_t *n, int b,
                      ts_system *sys)
{
    /* A vehicle's own keys run from B_VOLUME to B_CONTROLLERS in the
     * order parse_vehicle reads them; its added_mass is B_CA's node. */
    enum { B_NAME, B_TYPE, B_DIAM, B_WEIGHT, B_MASS, B_WET, B_DRAG, B_CA,
           B_LEN, B_XDRAG, B_XCA, B_VOLUME, B_INERTIA, B_MC, B_BC, B_ATTACH,
           B_SURF, B_COMPONENTS, B_CONTROLLERS, B_PROP, B_TURN, B_DOF,
           B_N };
    /* The towing vehicle (sys->tow.vehicle == b): the top-level
     * towing_vehicle entry, a vehicle whose attach point is its tow
     * point, with propulsion. */
    int towing = b == sys->tow.vehicle;
    field f[B_N] = {{"name", 0, 0}, {"type", 0, 0}, {"diameter", 0, 0},
                    {"weight", 0, 0}, {"mass", 0, 0}, {"wet_weight", 0, 0},
                    {"drag", 0, 0}, {"added_mass", 0, 0}, {"length", 0, 0},
                    {"cross_drag", 0, 0}, {"cross_added_mass", 0, 0},
                    {"volume", 0, 0}, {"inertia", 0, 0},
                    {"mass_centre", 0, 0}, {"buoyancy_centre", 0, 0},
                    {"attach", 0, 0}, {"surface_diameter", 0, 0},
                    {"components", 0, 0}, {"controllers", 0, 0},
                    {"propulsion", 0, 0}, {"turn_by", 0, 0},
                    {"dof", 0, 0}};
    char path[PATH_LEN], p[PATH_LEN], s[SHOW_BUF];
    if (towing) {
        snprintf(path, sizeof path, "towing_vehicle");
        f[B_ATTACH].key = "tow_point";
    } else {
        index_path(path, "bodies", b);
    }
    ts_body *body = &sys->bodies[b];
    body->line = line_of(n);
    int rc = read_map(c, n, path, towing ? "name, mass, inertia, ..."
                                         : "name, type, diameter, weight, ...",
                      f, towing ? B_N : B_PROP);
    if (rc != TS_OK)
        return rc;
    for (int k = 0; k <= B_TYPE; k++)
        if (!f[k].value && !(towing && k == B_TYPE))
            return missing(c, path, n, f[k].key);
    if (towing && !f[B_PROP].value)
        return missing(c, path, n, "propulsion");

    rc = read_name(c, join(p, path, "name"), &f[B_NAME], body->name);
    if (rc != TS_OK)
        return rc;
    if (!strcmp(body->name, "tow"))
        return fail_at(c, TS_EINVAL, p, f[B_NAME].line, "'tow' is reserved "
                       "for the tow point; choose another name");
    for (int j = 0; j < b; j++)
        if (!strcmp(sys->bodies[j].name, body->name))
            return fail_at(c, TS_EINVAL, p, f[B_NAME].line, "duplicate body "
                           "name '%s' (bodies[%d], line %d)", body->name, j,
                           sys->bodies[j].line);

    const char *type = "vehicle";
    if (f[B_TYPE].value)
        rc = field_text(c, join(p, path, "type"), &f[B_TYPE],
                        "sphere, cylinder, junction or vehicle", &type);
    if (rc == TS_OK && towing && strcmp(type, "vehicle"))
        rc = fail_at(c, TS_EINVAL, p, f[B_TYPE].line, "a towing vehicle is "
                     "of type vehicle");
    if (rc != TS_OK)
        return rc;
    if (!strcmp(type, "sphere"))
        body->type = TS_BODY_SPHERE;
    else if (!strcmp(type, "junction"))
        body->type = TS_BODY_JUNCTION;
    else if (!strcmp(type, "cylinder"))
        body->type = TS_BODY_CYLINDER;
    else if (!strcmp(type, "vehicle"))
        body->type = TS_BODY_VEHICLE;
    else
        return fail_at(c, TS_EINVAL, p, f[B_TYPE].line, "unknown body type "
                       "\"%s\"; expected sphere, cylinder, junction or "
                       "vehicle",
                       show(type, f[B_TYPE].value->data.scalar.length, s,
                            sizeof s));
    int sphere = body->type == TS_BODY_SPHERE;
    int cyl = body->type == TS_BODY_CYLINDER;
    int veh = body->type == TS_BODY_VEHICLE;
    for (int k = B_VOLUME; k <= B_CONTROLLERS; k++)
        if (!veh && f[k].value)
            return fail_at(c, TS_ESCENE, join(p, path, f[k].key), f[k].line,
                           "applies to a vehicle body only, not to a %s",
                           type);
    static const int not_vehicle[] = {B_DIAM, B_DRAG, B_LEN, B_XDRAG, B_XCA};
    for (int k = 0; k < 5; k++)
        if (veh && f[not_vehicle[k]].value)
            return fail_at(c, TS_ESCENE,
                           join(p, path, f[not_vehicle[k]].key),
                           f[not_vehicle[k]].line, "does not apply to a "
                           "vehicle: give its hull and surfaces as "
                           "components");
    if (veh) {
        rc = parse_vehicle(c, n, path, f + B_VOLUME,
                           f[B_CA].value ? &f[B_CA] : NULL, sys, b);
        if (rc == TS_OK && towing)
            rc = parse_propulsion(c, &f[B_PROP], path,
                                  &body->vehicle->propulsion);
        if (rc == TS_OK && towing && f[B_DOF].value) {
            /* 3: a surface ship held to the free surface. */
            rc = read_count(c, join(p, path, "dof"), &f[B_DOF], 6,
                            &sys->tow.dof);
            if (rc == TS_OK && sys->tow.dof != 6 && sys->tow.dof != 3)
                rc = fail_at(c, TS_EINVAL, p, f[B_DOF].line, "must be 6 or "
                             "3 (a surface ship: surge, sway and yaw), got "
                             "%d", sys->tow.dof);
        }
        if (rc == TS_OK && towing && f[B_TURN].value) {
            /* The control surface the steady analyses deflect to turn at
             * tow.turn_rate. */
            const char *t = NULL;
            rc = field_text(c, join(p, path, "turn_by"), &f[B_TURN],
                            "a control surface's name", &t);
            const ts_vehicle *v = body->vehicle;
            sys->tow.turn_surface = -1;
            for (int j = 0; rc == TS_OK && j < v->ncomponents; j++)
                if (v->component[j].control && !strcmp(v->component[j].name, t))
                    sys->tow.turn_surface = j;
            if (rc == TS_OK && sys->tow.turn_surface < 0)
                rc = fail_at(c, TS_EINVAL, p, f[B_TURN].line, "'%s' is not "
                             "a control surface of the towing vehicle",
                             show(t, f[B_TURN].value->data.scalar.length, s,
                                  sizeof s));
        }
        if (rc != TS_OK)
            return rc;
    }
    /* Keys of one body type only. */
    static const int cyl_only[] = {B_LEN, B_XDRAG, B_XCA};
    for (int k = 0; k < 3; k++)
        if (!cyl && f[cyl_only[k]].value)
            return fail_at(c, TS_ESCENE, join(p, path, f[cyl_only[k]].key),
                           f[cyl_only[k]].line, "applies to a cylinder body "
                           "only, not to a %s", type);

    if ((sphere || cyl) && !f[B_DIAM].value)
        return missing(c, path, n, "diameter");
    if (cyl && !f[B_LEN].value)
        return missing(c, path, n, "length");
    const tsi_key *kd = tsi_key_find(TSI_KEYS_BODY, "diameter"),
                  *kl = tsi_key_find(TSI_KEYS_BODY, "length");
    /* A sphere's and a cylinder's size must be > 0, the key's limit
     * aside. */
    rc = optional_min(c, path, &f[B_DIAM], kd->unit, kd->min,
                      kd->strict || sphere || cyl, 0.0,
                      &body->diameter);
    if (rc == TS_OK)
        rc = optional_min(c, path, &f[B_LEN], kl->unit, kl->min,
                          kl->strict || cyl, 0.0,
                          &body->length);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[B_DRAG], TSI_KEYS_BODY,
                       sphere ? DEFAULT_SPHERE_CD
                                 : (cyl ? DEFAULT_CYL_CD_AXIAL : 0.0),
                          &body->cd);
    if (rc == TS_OK && !veh)
        rc = key_value(c, path, &f[B_CA], TSI_KEYS_BODY,
                       sphere ? DEFAULT_SPHERE_CA
                                 : (cyl ? DEFAULT_CYL_CA_AXIAL : 0.0),
                          &body->ca);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[B_XDRAG], TSI_KEYS_BODY,
                       cyl ? DEFAULT_CYL_CD_CROSS : 0.0, &body->cd_cross);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[B_XCA], TSI_KEYS_BODY,
                       cyl ? DEFAULT_CYL_CA_CROSS : 0.0, &body->ca_cross);
    if (rc != TS_OK)
        return rc;

    /* Mass: exactly one of weight, mass, wet_weight for a sphere; at most
     * one for a junction (default 0). */
    static const int mass_keys[] = {B_WEIGHT, B_MASS, B_WET};
    int which;
    rc = one_of(c, path, n, f, mass_keys, 3, sphere || cyl || veh, &which);
    if (rc != TS_OK)
        return rc;
    const ts_environment *env = &sys->env;
    double x = 0;
    body->mass = 0;
    if (which >= 0) {
        const field *fm = &f[which];
        const char *si = key_unit(TSI_KEYS_BODY, fm);
        rc = field_quantity(c, join(p, path, fm->key), fm, si, &x);
        if (rc == TS_OK && which != B_WET)
            rc = check_min(c, p, fm, x, 0, 0, si);
        if (rc == TS_OK && which != B_MASS)
            rc = need_gravity(c, p, fm, env->gravity, "mass");
        if (rc != TS_OK)
            return rc;
        double volume = ts_body_volume(body);
        if (which == B_MASS)
            body->mass = x;
        else if (which == B_WEIGHT)
            body->mass = x / env->gravity;
        else
            body->mass = x / env->gravity + env->water_density * volume;
        if (!(body->mass >= 0))
            return fail_at(c, TS_EINVAL, p, fm->line, "%g N in water gives "
                           "a negative mass in air (%g kg): the buoyancy "
                           "rho g V is only %g N", x, body->mass,
                           env->water_density * env->gravity * volume);
    }
    return TS_OK;
}

/* Resolve a body name for cables[i].from/to; -1 for "tow" (from only). */
static int resolve_body(const ctx *c, const char *path, const field *f,
                        const ts_system *sys, int allow_tow, int *body)
{
    const char *t = NULL;
    char s[SHOW_BUF];
    int rc = field_text(c, path, f, "a body name", &t);
    if (rc != TS_OK)
        return rc;
    if (!strcmp(t, "tow")) {
        if (!allow_tow)
            return fail_at(c, TS_EINVAL, path, f->line, "a cable cannot end "
                           "at the tow point; omit 'to' for a free end");
        *body = -1;
        return TS_OK;
    }
    *body = ts_system_find_body(sys, t);
    if (*body >= 0)
        return TS_OK;
    char list[400];
    size_t n = 0;
    list[0] = '\0';
    for (int b = 0; b < sys->nbodies; b++) {
        size_t need = strlen(sys->bodies[b].name) + 2;
        if (n + need + 5 >= sizeof list) {
            snprintf(list + n, sizeof list - n, ", ...");
            break;
        }
        n += (size_t)snprintf(list + n, sizeof list - n, "%s%s",
                              b ? ", " : "", sys->bodies[b].name);
    }
    show(t, f->value->data.scalar.length, s, sizeof s);
    if (sys->nbodies == 0)
        return fail_at(c, TS_EINVAL, path, f->line, "no body named '%s' (no "
                       "bodies are defined%s)", s,
                       allow_tow ? "; use 'tow' for the tow point" : "");
    return fail_at(c, TS_EINVAL, path, f->line, "no body named '%s' "
                   "(bodies: %s)", s, list);
}

static int parse_link_lengths(const ctx *c, const char *path, const field *f,
                              ts_cable *cable)
{
    char p[PATH_LEN], pi[PATH_LEN];
    join(p, path, f->key);
    const yaml_node_t *n = f->value;
    if (n->type != YAML_SEQUENCE_NODE)
        return fail_at(c, TS_ESCENE, p, f->line, "expected a list of link "
                       "lengths, got %s", tsi_scene_kind_name(n));
    int len = seq_len(n);
    if (len < 1)
        return fail_at(c, TS_EINVAL, p, f->line, "needs at least one link "
                       "length");
    if (len > TS_MAX_LINKS)
        return fail_at(c, TS_EINVAL, p, f->line, "has %d entries, at most %d "
                       "links are allowed", len, TS_MAX_LINKS);
    double *frac = malloc((size_t)len * sizeof *frac);
    if (!frac)
        return ts_fail(c->err, TS_ENOMEM, "%s: out of memory", p);
    double sum = 0;
    for (int j = 0; j < len; j++) {
        yaml_node_t *item = seq_item(c, n, j);
        int rc = item ? TS_OK
                      : ts_fail(c->err, TS_ESCENE, "%s: broken YAML document",
                                p);
        field fj = {"", item, item ? line_of(item) : 0};
        if (rc == TS_OK)
            rc = node_quantity(c, index_path(pi, p, j), fj.line, item, "m",
                               &frac[j]);
        if (rc == TS_OK)
            rc = check_min(c, pi, &fj, frac[j], 0, 1, "m");
        if (rc != TS_OK) {
            free(frac);
            return rc;
        }
        sum += frac[j];
    }
    if (!(isfinite(sum) &&
          fabs(sum - cable->length) <= LINK_SUM_RTOL * cable->length)) {
        free(frac);
        return fail_at(c, TS_EINVAL, p, f->line, "the %d lengths add up to "
                       "%.12g m, but the cable length is %.12g m (relative "
                       "tolerance %g)", len, sum, cable->length,
                       LINK_SUM_RTOL);
    }
    /* Normalised by their own sum, the fractions add up to 1 to rounding
     * (ts_system_build checks 1e-9). */
    for (int j = 0; j < len; j++)
        frac[j] /= sum;
    cable->link_fraction = frac;
    cable->nlinks = len;
    return TS_OK;
}

static int parse_cable(const ctx *c, const yaml_node_t *n, int i,
                       ts_system *sys)
{
    enum { C_NAME, C_FROM, C_TO, C_LENGTH, C_DIAM, C_WEIGHT, C_MPL, C_WET,
           C_LINKS, C_LINK_LENGTHS, C_CDN, C_CDT, C_CAN, C_LAW, C_EI, C_EA,
           C_DAMP, C_AT, C_N };
    field f[C_N] = {{"name", 0, 0}, {"from", 0, 0}, {"to", 0, 0},
                    {"length", 0, 0}, {"diameter", 0, 0}, {"weight", 0, 0},
                    {"mass_per_length", 0, 0}, {"wet_weight", 0, 0},
                    {"links", 0, 0}, {"link_lengths", 0, 0},
                    {"normal_drag", 0, 0}, {"tangential_drag", 0, 0},
                    {"added_mass", 0, 0}, {"drag_law", 0, 0}, {"EI", 0, 0},
                    {"EA", 0, 0}, {"damping", 0, 0}, {"at", 0, 0}};
    char path[PATH_LEN], p[PATH_LEN], s[SHOW_BUF];
    index_path(path, "cables", i);
    ts_cable *cable = &sys->cables[i];
    cable->line = line_of(n);
    int rc = read_map(c, n, path, "name, from, to, length, diameter, ...", f,
                      C_N);
    if (rc != TS_OK)
        return rc;
    static const int required[] = {C_NAME, C_FROM, C_LENGTH, C_DIAM};
    for (int k = 0; k < 4; k++)
        if (!f[required[k]].value)
            return missing(c, path, n, f[required[k]].key);
    if (!f[C_LINKS].value && !f[C_LINK_LENGTHS].value)
        return missing(c, path, n, "links");

    rc = read_name(c, join(p, path, "name"), &f[C_NAME], cable->name);
    if (rc != TS_OK)
        return rc;
    for (int j = 0; j < i; j++)
        if (!strcmp(sys->cables[j].name, cable->name))
            return fail_at(c, TS_EINVAL, p, f[C_NAME].line, "duplicate cable "
                           "name '%s' (cables[%d], line %d)", cable->name, j,
                           sys->cables[j].line);
    rc = resolve_body(c, join(p, path, "from"), &f[C_FROM], sys, 1,
                      &cable->from_body);
    if (rc == TS_OK && f[C_TO].value)
        rc = resolve_body(c, join(p, path, "to"), &f[C_TO], sys, 0,
                          &cable->to_body);
    if (rc == TS_OK && f[C_AT].value) {
        /* A point of the vehicle the cable starts from (body axes). */
        if (cable->from_body < 0 ||
            sys->bodies[cable->from_body].type != TS_BODY_VEHICLE)
            return fail_at(c, TS_EINVAL, join(p, path, "at"), f[C_AT].line,
                           "a starting point on a body needs a vehicle as "
                           "'from'");
        rc = vector3(c, path, &f[C_AT], "m", cable->from_point);
        cable->has_from_point = 1;
    }
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_LENGTH], TSI_KEYS_CABLE, 0.0,
                          &cable->length);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_DIAM], TSI_KEYS_CABLE, 0.0,
                          &cable->diameter);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_CDN], TSI_KEYS_CABLE, DEFAULT_CDN,
                          &cable->cdn);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_CDT], TSI_KEYS_CABLE, DEFAULT_CDT,
                          &cable->cdt);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_CAN], TSI_KEYS_CABLE, DEFAULT_CAN,
                          &cable->can);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_EI], TSI_KEYS_CABLE, 0.0, &cable->ei);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_EA], TSI_KEYS_CABLE, 0.0, &cable->ea);
    if (rc == TS_OK)
        rc = key_value(c, path, &f[C_DAMP], TSI_KEYS_CABLE, 0.0,
                          &cable->damping);
    if (rc == TS_OK && f[C_DAMP].value && !(cable->ea > 0))
        rc = fail_at(c, TS_EINVAL, join(p, path, "damping"), f[C_DAMP].line,
                     "internal damping applies to an elastic cable: give EA "
                     "> 0 as well");
    if (rc != TS_OK)
        return rc;

    cable->drag_law = TS_DRAG_STANDARD;
    if (f[C_LAW].value) {
        const char *law = NULL;
        rc = field_text(c, join(p, path, "drag_law"), &f[C_LAW],
                        "standard or loading_functions", &law);
        if (rc != TS_OK)
            return rc;
        if (!strcmp(law, "standard"))
            cable->drag_law = TS_DRAG_STANDARD;
        else if (!strcmp(law, "loading_functions"))
            cable->drag_law = TS_DRAG_LOADING;
        else
            return fail_at(c, TS_EINVAL, p, f[C_LAW].line, "unknown drag law "
                           "\"%s\"; expected standard or loading_functions",
                           show(law, f[C_LAW].value->data.scalar.length, s,
                                sizeof s));
    }

    /* Mass per length from exactly one of the three keys. */
    static const int mass_keys[] = {C_WEIGHT, C_MPL, C_WET};
    int which;
    rc = one_of(c, path, n, f, mass_keys, 3, 1, &which);
    if (rc != TS_OK)
        return rc;
    const field *fm = &f[which];
    const char *si = key_unit(TSI_KEYS_CABLE, fm);
    const ts_environment *env = &sys->env;
    double x;
    rc = field_quantity(c, join(p, path, fm->key), fm, si, &x);
    if (rc == TS_OK && which != C_WET)
        rc = check_min(c, p, fm, x, 0, 0, si);
    if (rc == TS_OK && which != C_MPL)
        rc = need_gravity(c, p, fm, env->gravity, "mass_per_length");
    if (rc != TS_OK)
        return rc;
    double area = M_PI * cable->diameter * cable->diameter / 4.0;
    if (which == C_MPL)
        cable->mass_per_length = x;
    else if (which == C_WEIGHT)
        cable->mass_per_length = x / env->gravity;
    else
        cable->mass_per_length = x / env->gravity + env->water_density * area;
    if (!(cable->mass_per_length >= 0))
        return fail_at(c, TS_EINVAL, p, fm->line, "%g N/m in water gives a "
                       "negative mass per length in air (%g kg/m): the "
                       "buoyancy rho g pi d^2/4 is only %g N/m", x,
                       cable->mass_per_length,
                       env->water_density * env->gravity * area);

    /* Links: a count, a list of lengths, or both (then they must agree). */
    int nlinks = 0;
    if (f[C_LINKS].value) {
        rc = read_count(c, join(p, path, "links"), &f[C_LINKS], TS_MAX_LINKS,
                        &nlinks);
        if (rc != TS_OK)
            return rc;
        cable->nlinks = nlinks;
    }
    if (f[C_LINK_LENGTHS].value) {
        rc = parse_link_lengths(c, path, &f[C_LINK_LENGTHS], cable);
        if (rc != TS_OK)
            return rc;
        if (nlinks && nlinks != cable->nlinks)
            return fail_at(c, TS_EINVAL, join(p, path, "links"),
                           f[C_LINKS].line, "%d does not match the %d "
                           "entries of link_lengths (line %d)", nlinks,
                           cable->nlinks, f[C_LINK_LENGTHS].line);
    }
    return TS_OK;
}

/* An analysis: a bare type name, or a mapping with `type` and scalar
 * options kept as text. */
/* The path of option key k of a's entry at `parent` into p[PATH_LEN];
 * refuses a name too long or given twice. */
static int option_key(const ctx *c, const ts_scene_analysis *a,
                      const yaml_node_t *k, const char *parent, char *p)
{
    char s[SHOW_BUF];
    const char *key = (const char *)k->data.scalar.value;
    size_t klen = k->data.scalar.length;
    join(p, parent, show(key, klen, s, sizeof s));
    if (klen == 0 || klen >= TS_NAME_MAX || strlen(key) != klen)
        return fail_at(c, TS_ESCENE, p, line_of(k), "an option name must "
                       "have 1 to %d characters", TS_NAME_MAX - 1);
    for (int j = 0; j < a->noptions; j++)
        if (!strcmp(a->options[j].key, key))
            return fail_at(c, TS_ESCENE, p, line_of(k), "duplicate key "
                           "(first given on line %d)", a->options[j].line);
    return TS_OK;
}

/* Keep scalar v as option `key` of a (room for it allocated); `p` names
 * it in messages. */
static int add_option(const ctx *c, ts_scene_analysis *a, const char *key,
                      int line, const yaml_node_t *v, const char *p)
{
    if (is_null(v))
        return fail_at(c, TS_ESCENE, p, line, "no value; give one, or "
                       "remove the key");
    size_t vlen = v->data.scalar.length;
    if (strlen((const char *)v->data.scalar.value) != vlen)
        return fail_at(c, TS_ESCENE, p, line, "the value contains a NUL "
                       "character");
    ts_scene_option *o = &a->options[a->noptions];
    o->value = malloc(vlen + 1);
    if (!o->value)
        return ts_fail(c->err, TS_ENOMEM, "%s: out of memory", p);
    memcpy(o->value, v->data.scalar.value, vlen + 1);
    snprintf(o->key, sizeof o->key, "%s", key);
    o->line = line;
    a->noptions++;
    return TS_OK;
}

static int parse_analysis(const ctx *c, const yaml_node_t *n, int i,
                          ts_scene_analysis *a)
{
    char path[PATH_LEN], p[PATH_LEN], s[SHOW_BUF];
    index_path(path, "analyses", i);
    a->line = line_of(n);
    const yaml_node_t *type_node = n;
    if (n->type == YAML_MAPPING_NODE) {
        type_node = NULL;
        for (yaml_node_pair_t *pr = n->data.mapping.pairs.start;
             pr < n->data.mapping.pairs.top; pr++) {
            yaml_node_t *k = yaml_document_get_node(c->doc, pr->key);
            if (k && k->type == YAML_SCALAR_NODE &&
                !strcmp((const char *)k->data.scalar.value, "type"))
                type_node = yaml_document_get_node(c->doc, pr->value);
        }
        if (!type_node)
            return missing(c, path, n, "type");
        join(p, path, "type");
    } else if (n->type == YAML_SCALAR_NODE) {
        snprintf(p, sizeof p, "%s", path);
    } else {
        return fail_at(c, TS_ESCENE, path, line_of(n), "expected an analysis "
                       "name or a mapping with 'type' and options, got %s",
                       tsi_scene_kind_name(n));
    }
    if (type_node->type != YAML_SCALAR_NODE)
        return fail_at(c, TS_ESCENE, p, line_of(type_node), "expected an "
                       "analysis name, got %s", tsi_scene_kind_name(type_node));
    const char *t = (const char *)type_node->data.scalar.value;
    size_t tlen = type_node->data.scalar.length;
    int ok = tlen > 0 && tlen < TS_NAME_MAX && strlen(t) == tlen;
    for (size_t j = 0; ok && j < tlen; j++)
        ok = (t[j] >= 'a' && t[j] <= 'z') || (t[j] >= 'A' && t[j] <= 'Z') ||
             (t[j] >= '0' && t[j] <= '9') || t[j] == '_' || t[j] == '-';
    if (!ok)
        return fail_at(c, TS_EINVAL, p, line_of(type_node), "\"%s\" is not "
                       "an analysis name (1 to %d letters, digits, '_', "
                       "'-')", show(t, tlen, s, sizeof s), TS_NAME_MAX - 1);
    memcpy(a->type, t, tlen + 1);
    if (n->type != YAML_MAPPING_NODE)
        return TS_OK;

    ptrdiff_t npairs = n->data.mapping.pairs.top - n->data.mapping.pairs.start;
    if (npairs > MAX_ENTRIES)
        return fail_at(c, TS_EINVAL, path, line_of(n), "too many options "
                       "(at most %d)", MAX_ENTRIES);
    a->options = calloc((size_t)npairs, sizeof *a->options);
    if (!a->options)
        return ts_fail(c->err, TS_ENOMEM, "%s: out of memory", path);
    for (yaml_node_pair_t *pr = n->data.mapping.pairs.start;
         pr < n->data.mapping.pairs.top; pr++) {
        yaml_node_t *k = yaml_document_get_node(c->doc, pr->key);
        yaml_node_t *v = yaml_document_get_node(c->doc, pr->value);
        if (!k || !v)
            return ts_fail(c->err, TS_ESCENE, "%s: broken YAML document",
                           path);
        if (k->type != YAML_SCALAR_NODE)
            return fail_at(c, TS_ESCENE, path, line_of(k), "keys must be "
                           "plain names, got %s as a key", tsi_scene_kind_name(k));
        const char *key = (const char *)k->data.scalar.value;
        if (!strcmp(key, "type"))
            continue;
        int rc = option_key(c, a, k, path, p);
        if (rc)
            return rc;
        if (v->type != YAML_SCALAR_NODE)
            return fail_at(c, TS_ESCENE, p, line_of(k), "an option value "
                           "must be a scalar, got %s", tsi_scene_kind_name(v));
        rc = add_option(c, a, key, line_of(k), v, p);
        if (rc)
            return rc;
    }
    return TS_OK;
}

/* The design section (doc/design.md, "Settings in the scene"): a mapping
 * of the study's settings, each a scalar or a list of scalars (one
 * option per item, in order), kept as text for `towstab design`. */
static int parse_design(const ctx *c, const yaml_node_t *n,
                        ts_scene_analysis *a)
{
    char p[PATH_LEN];
    snprintf(a->type, sizeof a->type, "design");
    a->line = line_of(n);
    if (n->type != YAML_MAPPING_NODE)
        return fail_at(c, TS_ESCENE, "design", line_of(n), "expected a "
                       "mapping of the study's settings, got %s",
                       tsi_scene_kind_name(n));
    /* Options: one per scalar or list item, at most MAX_ENTRIES. */
    size_t count = 0;
    for (yaml_node_pair_t *pr = n->data.mapping.pairs.start;
         pr < n->data.mapping.pairs.top; pr++) {
        yaml_node_t *v = yaml_document_get_node(c->doc, pr->value);
        count += v && v->type == YAML_SEQUENCE_NODE ? (size_t)seq_len(v) : 1;
        if (count > MAX_ENTRIES)
            return fail_at(c, TS_EINVAL, "design", line_of(n), "too many "
                           "settings (at most %d)", MAX_ENTRIES);
    }
    a->options = calloc(count ? count : 1, sizeof *a->options);
    if (!a->options)
        return ts_fail(c->err, TS_ENOMEM, "design: out of memory");
    for (yaml_node_pair_t *pr = n->data.mapping.pairs.start;
         pr < n->data.mapping.pairs.top; pr++) {
        yaml_node_t *k = yaml_document_get_node(c->doc, pr->key);
        yaml_node_t *v = yaml_document_get_node(c->doc, pr->value);
        if (!k || !v)
            return ts_fail(c->err, TS_ESCENE, "design: broken YAML document");
        if (k->type != YAML_SCALAR_NODE)
            return fail_at(c, TS_ESCENE, "design", line_of(k), "keys must be "
                           "plain names, got %s as a key",
                           tsi_scene_kind_name(k));
        const char *key = (const char *)k->data.scalar.value;
        int rc = option_key(c, a, k, "design", p);
        if (rc)
            return rc;
        if (v->type == YAML_MAPPING_NODE)
            return fail_at(c, TS_ESCENE, p, line_of(k), "expected a value "
                           "or a list of values, got a mapping");
        int items = v->type == YAML_SEQUENCE_NODE ? seq_len(v) : 1;
        if (items == 0)
            return fail_at(c, TS_ESCENE, p, line_of(k), "an empty list; "
                           "give values, or remove the key");
        for (int j = 0; j < items; j++) {
            yaml_node_t *item = v->type == YAML_SEQUENCE_NODE
                                    ? seq_item(c, v, j) : v;
            if (!item || item->type != YAML_SCALAR_NODE)
                return fail_at(c, TS_ESCENE, p, item ? line_of(item)
                                                     : line_of(k),
                               "expected a value, got %s",
                               item ? tsi_scene_kind_name(item) : "nothing");
            rc = add_option(c, a, key, line_of(item), item, p);
            if (rc)
                return rc;
        }
    }
    return TS_OK;
}

/* A list under a top-level key, its length in *n (0 when absent). */
static int top_list(const ctx *c, const field *f, int *n)
{
    *n = 0;
    if (!f->value)
        return TS_OK;
    if (f->value->type != YAML_SEQUENCE_NODE)
        return fail_at(c, TS_ESCENE, f->key, f->line, "expected a list of "
                       "entries (\"- ...\"), got %s", tsi_scene_kind_name(f->value));
    *n = seq_len(f->value);
    if (*n > MAX_ENTRIES)
        return fail_at(c, TS_EINVAL, f->key, f->line, "has %d entries, at "
                       "most %d are allowed", *n, MAX_ENTRIES);
    return TS_OK;
}

/* ------------------------------------------------------------------ */
/* Waypoints (doc/scene-format.md, "Waypoints"; towstab/guidance.h)      */

/* The waypoints entry: the autopilot of the towing vehicle. Needs a
 * towing vehicle (parsed before) whose rudders are its control surfaces. */
static int parse_waypoints(const ctx *c, const field *fw, ts_system *sys)
{
    enum { W_POINTS, W_RADIUS, W_GAIN, W_BIAS, W_RUDDERS, W_LIMIT,
           W_INTERVAL, W_N };
    field f[W_N] = {{"points", 0, 0}, {"radius", 0, 0}, {"gain", 0, 0},
                    {"bias", 0, 0}, {"rudders", 0, 0}, {"limit", 0, 0},
                    {"interval", 0, 0}};
    const char *path = "waypoints";
    char p[PATH_LEN], pi[PATH_LEN];
    ts_autopilot *ap = &sys->tow.autopilot;
    int rc = read_map(c, fw->value, path, "points, radius, gain, rudders, "
                      "...", f, W_N);
    if (rc != TS_OK)
        return rc;
    if (sys->tow.vehicle < 0)
        return fail_at(c, TS_ESCENE, path, fw->line, "waypoints steer a "
                       "towing vehicle's rudder: the scene has no "
                       "towing_vehicle (a prescribed tow point follows "
                       "tow.speed and tow.turn_rate)");
    static const int required[] = {W_POINTS, W_GAIN, W_RUDDERS};
    for (int k = 0; k < 3; k++)
        if (!f[required[k]].value)
            return missing(c, path, fw->value, f[required[k]].key);
    ts_guidance_defaults(&ap->g);
    ap->g.line = fw->line;
    int n = 0;
    rc = field_list(c, join(p, path, "points"), &f[W_POINTS],
                    "points [x, y]", TS_GUIDANCE_MAX_WAYPOINTS, &n);
    if (rc == TS_OK && n < 1)
        rc = fail_at(c, TS_EINVAL, p, f[W_POINTS].line, "needs at least "
                     "one point [x, y]");
    for (int i = 0; rc == TS_OK && i < n; i++) {
        yaml_node_t *item = seq_item(c, f[W_POINTS].value, i);
        if (!item)
            return ts_fail(c->err, TS_ESCENE, "%s: broken YAML document", p);
        field fi = {"", item, line_of(item)};
        double xy[2];
        int m = 0;
        rc = quantity_list(c, index_path(pi, p, i), &fi, "m", 2, 2, xy, &m);
        if (rc == TS_OK && m != 2)
            rc = fail_at(c, TS_EINVAL, pi, fi.line, "expected a point "
                         "[x, y], got %d entries", m);
        ap->g.waypoint[i][0] = xy[0];
        ap->g.waypoint[i][1] = xy[1];
    }
    ap->g.nwaypoints = n;
    if (rc == TS_OK)
        rc = optional_min(c, path, &f[W_RADIUS], "m", 0, 1,
                          TS_GUIDANCE_RADIUS, &ap->g.radius);
    if (rc == TS_OK)
        rc = optional_any(c, path, &f[W_GAIN], "1", 1.0, &ap->g.kp);
    if (rc == TS_OK)
        rc = optional_any(c, path, &f[W_BIAS], "rad", 0.0, &ap->g.delta0);
    if (rc == TS_OK)
        rc = optional_min(c, path, &f[W_LIMIT], "rad", 0, 1, INFINITY,
                          &ap->g.limit);
    if (rc == TS_OK)
        rc = optional_min(c, path, &f[W_INTERVAL], "s", 0, 1,
                          TS_AUTOPILOT_INTERVAL, &ap->interval);
    if (rc != TS_OK)
        return rc;
    /* The rudders: control surfaces of the towing vehicle. */
    const ts_vehicle *v = sys->bodies[sys->tow.vehicle].vehicle;
    join(p, path, "rudders");
    rc = field_list(c, p, &f[W_RUDDERS], "surface names",
                    TS_AUTOPILOT_MAX_RUDDERS, &ap->nrudders);
    if (rc == TS_OK && ap->nrudders < 1)
        rc = fail_at(c, TS_EINVAL, p, f[W_RUDDERS].line, "needs at least "
                     "one control surface of the towing vehicle");
    for (int i = 0; rc == TS_OK && i < ap->nrudders; i++) {
        yaml_node_t *item = seq_item(c, f[W_RUDDERS].value, i);
        if (!item)
            return ts_fail(c->err, TS_ESCENE, "%s: broken YAML document", p);
        field fi = {"", item, line_of(item)};
        char name[TS_NAME_MAX];
        rc = read_name(c, index_path(pi, p, i), &fi, name);
        int hit = -1;
        for (int k = 0; rc == TS_OK && k < v->ncomponents && hit < 0; k++)
            if (!strcmp(v->component[k].name, name))
                hit = k;
        if (rc == TS_OK && (hit < 0 || !v->component[hit].control))
            rc = fail_at(c, TS_EINVAL, pi, fi.line, "'%s' is not a control "
                         "surface of the towing vehicle '%s' (a component "
                         "with control: true)", name,
                         sys->bodies[sys->tow.vehicle].name);
        if (rc == TS_OK)
            snprintf(ap->rudder[i], sizeof ap->rudder[i], "%s", name);
    }
    if (rc == TS_OK)
        rc = ts_guidance_check(&ap->g, "waypoints", c->err);
    ap->on = rc == TS_OK;
    return rc;
}

static int parse_root(const ctx *c, const yaml_node_t *root, ts_scene *scene)
{
    enum { K_NAME, K_ENV, K_TOW, K_CABLES, K_BODIES, K_ANALYSES, K_TOWING,
           K_DESIGN, K_WAYPOINTS, K_N };
    field f[K_N] = {{"name", 0, 0}, {"environment", 0, 0}, {"tow", 0, 0},
                    {"cables", 0, 0}, {"bodies", 0, 0}, {"analyses", 0, 0},
                    {"towing_vehicle", 0, 0}, {"design", 0, 0},
                    {"waypoints", 0, 0}};
    int rc = read_map(c, root, "", "name, tow, cables, ...", f, K_N);
    if (rc != TS_OK)
        return rc;
    static const int required[] = {K_NAME, K_TOW, K_CABLES};
    for (int k = 0; k < 3; k++)
        if (!f[required[k]].value)
            return missing(c, "", root, f[required[k]].key);

    int ncables, nbodies, nanalyses;
    if ((rc = top_list(c, &f[K_CABLES], &ncables)) ||
        (rc = top_list(c, &f[K_BODIES], &nbodies)) ||
        (rc = top_list(c, &f[K_ANALYSES], &nanalyses)))
        return rc;
    if (ncables < 1)
        return fail_at(c, TS_EINVAL, "cables", f[K_CABLES].line, "at least "
                       "one cable is needed");

    /* A towing vehicle is the last body. */
    int towing = f[K_TOWING].value != NULL;
    ts_system *sys = ts_system_alloc(ncables, nbodies + towing, c->err);
    if (!sys)
        return c->err ? c->err->code : TS_ENOMEM;
    scene->system = sys;
    if (towing)
        sys->tow.vehicle = nbodies;
    rc = read_name(c, "name", &f[K_NAME], sys->name);
    if (rc == TS_OK && f[K_ENV].value)
        rc = parse_environment(c, f[K_ENV].value, &sys->env);
    if (rc == TS_OK)
        rc = parse_tow(c, f[K_TOW].value, &sys->tow, scene);
    for (int b = 0; rc == TS_OK && b < nbodies; b++) {
        yaml_node_t *item = seq_item(c, f[K_BODIES].value, b);
        rc = item ? parse_body(c, item, b, sys)
                  : ts_fail(c->err, TS_ESCENE, "bodies: broken YAML");
    }
    if (rc == TS_OK && towing &&
        (sys->tow.point[0] != 0 || sys->tow.point[1] != 0))
        rc = fail_at(c, TS_EINVAL, "tow.point", line_of(f[K_TOW].value),
                     "with a towing_vehicle the tow point starts the mean "
                     "frame's origin: x and y must be 0 m, got %g and %g m "
                     "(z is its starting depth)",
                     sys->tow.point[0], sys->tow.point[1]);
    if (rc == TS_OK && towing) {
        rc = parse_body(c, f[K_TOWING].value, nbodies, sys);
        for (int b = 0; rc == TS_OK && b < nbodies; b++)
            if (!strcmp(sys->bodies[b].name, sys->bodies[nbodies].name))
                rc = fail_at(c, TS_EINVAL, "towing_vehicle.name",
                             sys->bodies[nbodies].line, "'%s' is also the "
                             "name of bodies[%d]", sys->bodies[b].name, b);
    }
    if (rc == TS_OK && f[K_WAYPOINTS].value)
        rc = parse_waypoints(c, &f[K_WAYPOINTS], sys);
    long total_links = 0;
    for (int i = 0; rc == TS_OK && i < ncables; i++) {
        yaml_node_t *item = seq_item(c, f[K_CABLES].value, i);
        rc = item ? parse_cable(c, item, i, sys)
                  : ts_fail(c->err, TS_ESCENE, "cables: broken YAML");
        if (rc == TS_OK) {
            total_links += sys->cables[i].nlinks;
            if (total_links > TS_MAX_LINKS)
                rc = fail_at(c, TS_EINVAL, "cables", f[K_CABLES].line,
                             "more than %d links in total", TS_MAX_LINKS);
        }
    }
    if (rc != TS_OK)
        return rc;

    if (nanalyses > 0) {
        scene->analyses = calloc((size_t)nanalyses, sizeof *scene->analyses);
        if (!scene->analyses)
            return ts_fail(c->err, TS_ENOMEM, "analyses: out of memory");
        scene->nanalyses = nanalyses;
    }
    for (int i = 0; rc == TS_OK && i < nanalyses; i++) {
        yaml_node_t *item = seq_item(c, f[K_ANALYSES].value, i);
        rc = item ? parse_analysis(c, item, i, &scene->analyses[i])
                  : ts_fail(c->err, TS_ESCENE, "analyses: broken YAML");
    }
    if (rc == TS_OK && f[K_DESIGN].value) {
        scene->design = calloc(1, sizeof *scene->design);
        rc = scene->design ? parse_design(c, f[K_DESIGN].value, scene->design)
                           : ts_fail(c->err, TS_ENOMEM, "design: out of "
                                     "memory");
    }
    if (rc == TS_OK)
        rc = ts_system_build(sys, c->err);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Entry points                                                         */

/* The libyaml error as a message. */
static int yaml_failure(const yaml_parser_t *p, ts_err *err)
{
    const char *problem = p->problem ? p->problem : "unknown problem";
    switch (p->error) {
    case YAML_MEMORY_ERROR:
        return ts_fail(err, TS_ENOMEM, "out of memory reading YAML");
    case YAML_READER_ERROR:
        if (p->problem_value != -1)
            return ts_fail(err, TS_ESCENE, "YAML error at byte %zu: %s "
                           "(#%X)", p->problem_offset, problem,
                           (unsigned)p->problem_value);
        return ts_fail(err, TS_ESCENE, "YAML error at byte %zu: %s",
                       p->problem_offset, problem);
    default:
        if (p->context)
            return ts_fail(err, TS_ESCENE, "YAML syntax error (line %d, "
                           "column %d): %s (%s started on line %d, column "
                           "%d)",
                           mark_line(p->problem_mark),
                           mark_column(p->problem_mark), problem, p->context,
                           mark_line(p->context_mark),
                           mark_column(p->context_mark));
        return ts_fail(err, TS_ESCENE, "YAML syntax error (line %d, column "
                       "%d): %s", mark_line(p->problem_mark),
                       mark_column(p->problem_mark), problem);
    }
}

/* Refuse flow collections nested deeper than MAX_FLOW_DEPTH. A scan of
 * the YAML text that skips comments and quoted scalars and counts an
 * opening bracket or brace only where a flow collection can start (at the
 * start of a token), so that a plain scalar such as "a[1" is not one. */
static int check_flow_depth(const char *t, size_t len, ts_err *err)
{
    int depth = 0, line = 1;
    char prev = '\n'; /* the last character outside quotes and comments */
    for (size_t i = 0; i < len; i++) {
        char ch = t[i];
        int token_start = prev == '\n' || prev == ' ' || prev == '\t' ||
                          prev == '[' || prev == '{' || prev == ',';
        if (ch == '\n') {
            line++;
        } else if (ch == '#' && token_start) {
            while (i + 1 < len && t[i + 1] != '\n')
                i++;
            continue;
        } else if ((ch == '"' || ch == '\'') && token_start) {
            /* Skip the quoted scalar: "..." with backslash escapes, '...'
             * with '' for a quote. */
            for (i++; i < len; i++) {
                if (t[i] == '\n')
                    line++;
                if (ch == '"' && t[i] == '\\')
                    i++;
                else if (t[i] == ch && !(ch == '\'' && i + 1 < len &&
                                         t[i + 1] == '\''))
                    break;
                else if (t[i] == ch)
                    i++;
            }
            prev = ch;
            continue;
        } else if ((ch == '[' || ch == '{') && token_start) {
            if (++depth > MAX_FLOW_DEPTH)
                return ts_fail(err, TS_ESCENE, "line %d: lists or mappings "
                               "nested more than %d deep; a scene needs two "
                               "levels", line, MAX_FLOW_DEPTH);
        } else if ((ch == ']' || ch == '}') && depth > 0) {
            depth--;
        }
        prev = ch;
    }
    return TS_OK;
}

/* Parse without the name prefix; returns the scene or NULL. */
/* The text and settings a scene keeps: text[len] copied, the settings of
 * `base` (may be NULL) then keys[i] = values[i], each key once (a key set
 * again replaces its earlier setting). TS_OK or TS_ENOMEM. */
static int keep_source(ts_scene *scene, const char *text, size_t len,
                       const ts_scene *base, int n, const char *const keys[],
                       const char *const values[], ts_err *err)
{
    scene->text = malloc(len + 1);
    int cap = (base ? base->nsettings : 0) + n;
    scene->settings = cap > 0 ? calloc((size_t)cap, sizeof *scene->settings)
                              : NULL;
    if (!scene->text || (cap > 0 && !scene->settings))
        return ts_fail(err, TS_ENOMEM, "out of memory for the scene's text");
    if (len > 0)
        memcpy(scene->text, text, len);
    scene->text[len] = '\0';
    scene->text_len = len;
    for (int i = 0; i < cap; i++) {
        const char *k = i < cap - n ? base->settings[i].key : keys[i - (cap - n)];
        const char *v = i < cap - n ? base->settings[i].value
                                    : (values ? values[i - (cap - n)] : NULL);
        int later = 0;
        for (int j = i + 1; j < cap && !later; j++)
            later = !strcmp(k, j < cap - n ? base->settings[j].key
                                           : keys[j - (cap - n)]);
        if (later)
            continue;
        ts_scene_setting *t = &scene->settings[scene->nsettings++];
        t->key = strdup(k);
        t->value = v ? strdup(v) : NULL;
        if (!t->key || (v && !t->value))
            return ts_fail(err, TS_ENOMEM, "out of memory for the scene's "
                           "settings");
    }
    return TS_OK;
}

/* Read text[len] into a scene, after setting keys[i] = values[i] (i < n)
 * in its YAML document. */
static ts_scene *parse(const char *text, size_t len, const ts_units *units,
                       int n, const char *const keys[],
                       const char *const values[], ts_err *err)
{
    yaml_parser_t parser;
    yaml_document_t doc, extra;
    if (check_flow_depth(text, len, err) != TS_OK)
        return NULL;
    if (!yaml_parser_initialize(&parser)) {
        ts_fail(err, TS_ENOMEM, "out of memory starting the YAML parser");
        return NULL;
    }
    /* libyaml reads exactly len bytes: no NUL terminator is needed. */
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
    if (!yaml_parser_load(&parser, &doc)) {
        yaml_failure(&parser, err);
        yaml_parser_delete(&parser);
        return NULL;
    }
    ts_scene *scene = NULL;
    int rc = TS_OK;
    yaml_node_t *root = yaml_document_get_root_node(&doc);
    if (!root) {
        rc = ts_fail(err, TS_ESCENE, "the scene is empty; expected a mapping "
                     "with name, tow and cables");
        goto done;
    }
    /* A second document would be silently ignored: refuse it, and report
     * syntax errors after the first one. */
    if (!yaml_parser_load(&parser, &extra)) {
        rc = yaml_failure(&parser, err);
        goto done;
    }
    yaml_node_t *extra_root = yaml_document_get_root_node(&extra);
    if (extra_root)
        rc = ts_fail(err, TS_ESCENE, "a second YAML document starts on line "
                     "%d; a scene file holds one", line_of(extra_root));
    yaml_document_delete(&extra);
    if (rc != TS_OK)
        goto done;

    if (root->type != YAML_MAPPING_NODE) {
        rc = ts_fail(err, TS_ESCENE, "top level (line %d): expected a mapping "
                     "with name, tow and cables, got %s", line_of(root),
                     tsi_scene_kind_name(root));
        goto done;
    }
    scene = calloc(1, sizeof *scene);
    if (!scene) {
        rc = ts_fail(err, TS_ENOMEM, "out of memory");
        goto done;
    }
    rc = tsi_scene_apply(&doc, n, keys, values, err);
    if (rc != TS_OK)
        goto done;
    /* A setting may have replaced the root's contents; the root stays. */
    root = yaml_document_get_root_node(&doc);
    ctx c = {&doc, units, err};
    rc = parse_root(&c, root, scene);

done:
    yaml_document_delete(&doc);
    yaml_parser_delete(&parser);
    if (rc != TS_OK) {
        ts_scene_free(scene);
        return NULL;
    }
    return scene;
}

ts_scene *ts_scene_parse(const char *text, size_t len, const char *name,
                         const ts_units *units, ts_err *err)
{
    if (!name)
        name = "<string>";
    if (!units || (!text && len > 0)) {
        ts_fail(err, TS_EINVAL, "%s: ts_scene_parse called with a NULL %s",
                name, units ? "text" : "unit system");
        return NULL;
    }
    if (!text)
        text = "";
    ts_scene *scene = parse(text, len, units, 0, NULL, NULL, err);
    if (scene && keep_source(scene, text, len, NULL, 0, NULL, NULL, err)) {
        ts_scene_free(scene);
        scene = NULL;
    }
    if (!scene)
        ts_err_prefix(err, "%s: ", name);
    return scene;
}

ts_scene *ts_scene_set(const ts_scene *scene, int n, const char *const keys[],
                       const char *const values[], const ts_units *units,
                       ts_err *err)
{
    const char *name = scene && scene->path[0] ? scene->path : "<string>";
    if (!scene || !units || n < 0 || (n > 0 && !keys) || !scene->text) {
        ts_fail(err, TS_EINVAL, "ts_scene_set called with a NULL %s",
                !scene ? "scene" : !units ? "unit system"
                         : !scene->text ? "scene text" : "key list");
        return NULL;
    }
    /* The scene's settings first, then the new ones, each key once. */
    int total = scene->nsettings + n;
    const char **k = malloc((size_t)(total > 0 ? total : 1) * sizeof *k);
    const char **v = malloc((size_t)(total > 0 ? total : 1) * sizeof *v);
    ts_scene *out = NULL;
    if (!k || !v) {
        ts_fail(err, TS_ENOMEM, "%s: out of memory", name);
    } else {
        for (int i = 0; i < scene->nsettings; i++) {
            k[i] = scene->settings[i].key;
            v[i] = scene->settings[i].value;
        }
        for (int i = 0; i < n; i++) {
            k[scene->nsettings + i] = keys[i];
            v[scene->nsettings + i] = values ? values[i] : NULL;
        }
        out = parse(scene->text, scene->text_len, units, total, k, v, err);
        if (out && keep_source(out, scene->text, scene->text_len, scene, n,
                               keys, values, err)) {
            ts_scene_free(out);
            out = NULL;
        }
        if (out)
            memcpy(out->path, scene->path, sizeof out->path);
        else
            ts_err_prefix(err, "%s: ", name);
    }
    free(k);
    free(v);
    return out;
}

ts_scene *ts_scene_load(const char *path, const ts_units *units, ts_err *err)
{
    if (!path || !units) {
        ts_fail(err, TS_EINVAL, "ts_scene_load called with a NULL %s",
                path ? "unit system" : "path");
        return NULL;
    }
    if (!path[0]) {
        ts_fail(err, TS_EINVAL, "expected a scene file name, got an empty "
                "one");
        return NULL;
    }
    if (strlen(path) >= sizeof ((ts_scene *)0)->path) {
        ts_fail(err, TS_EINVAL, "%s: path longer than %zu characters", path,
                sizeof ((ts_scene *)0)->path - 1);
        return NULL;
    }
    /* "-" is standard input, as in other Unix tools. */
    int from_stdin = strcmp(path, "-") == 0;
    const char *name = from_stdin ? "standard input" : path;
    FILE *fp = from_stdin ? stdin : fopen(path, "rb");
    if (!fp) {
        ts_fail(err, TS_EIO, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    /* Read the whole file, growing the buffer geometrically. */
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    int rc = buf ? TS_OK
                 : ts_fail(err, TS_ENOMEM, "%s: out of memory for %zu bytes",
                           name, cap);
    while (rc == TS_OK) {
        if (len == cap) {
            /* The buffer grows to at most MAX_FILE_BYTES + 1: filling that
             * proves the file is too large. */
            if (cap > (size_t)MAX_FILE_BYTES) {
                rc = ts_fail(err, TS_EIO, "%s: larger than %ld bytes, not a "
                             "scene file", name, MAX_FILE_BYTES);
                break;
            }
            size_t bigger_cap = cap * 2 > (size_t)MAX_FILE_BYTES
                                    ? (size_t)MAX_FILE_BYTES + 1
                                    : cap * 2;
            char *bigger = realloc(buf, bigger_cap);
            if (!bigger) {
                rc = ts_fail(err, TS_ENOMEM, "%s: out of memory for %zu "
                             "bytes", name, bigger_cap);
                break;
            }
            buf = bigger;
            cap = bigger_cap;
        }
        size_t got = fread(buf + len, 1, cap - len, fp);
        len += got;
        if (got == 0) {
            if (ferror(fp))
                rc = ts_fail(err, TS_EIO, "%s: cannot read: %s", name,
                             strerror(errno));
            break;
        }
    }
    if (!from_stdin)
        fclose(fp);
    ts_scene *scene = NULL;
    if (rc == TS_OK) {
        scene = parse(buf, len, units, 0, NULL, NULL, err);
        if (scene &&
            keep_source(scene, buf, len, NULL, 0, NULL, NULL, err) != TS_OK) {
            ts_scene_free(scene);
            scene = NULL;
        }
        if (scene)
            snprintf(scene->path, sizeof scene->path, "%s", path);
        else
            ts_err_prefix(err, "%s: ", name);
    }
    free(buf);
    return scene;
}

void ts_scene_free(ts_scene *scene)
{
    if (!scene)
        return;
    for (int i = 0; i <= scene->nanalyses; i++) {
        ts_scene_analysis *a = i < scene->nanalyses ? &scene->analyses[i]
                                                    : scene->design;
        for (int j = 0; a && j < a->noptions; j++)
            free(a->options[j].value);
        if (a)
            free(a->options);
    }
    free(scene->analyses);
    free(scene->design);
    ts_system_free(scene->system);
    for (int i = 0; i < scene->nsettings; i++) {
        free(scene->settings[i].key);
        free(scene->settings[i].value);
    }
    free(scene->settings);
    free(scene->text);
    free(scene);
}

const ts_scene_option *ts_scene_analysis_option(const ts_scene_analysis *a,
                                                const char *key)
{
    if (!a || !key)
        return NULL;
    for (int j = 0; j < a->noptions; j++)
        if (!strcmp(a->options[j].key, key))
            return &a->options[j];
    return NULL;
}
