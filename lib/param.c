/* param.c: a scalar of a towed system by its scene key path
 * (towstab/param.h; doc/scene-format.md, "Values by path").
 *
 * A path is split at its dots into a collection (tow, environment,
 * cables, bodies), an entry name where the collection has entries, and a
 * key; vehicle loops and surfaces add a second name. Each key is one row
 * of a table: its SI unit, its lower limit and where it lives in the
 * struct (an offset), or a conversion (weight and wet weight to mass, a
 * whole number of links). Names may contain dots only where the scene
 * allows them not to: cable and body names are matched whole against the
 * system's, longest first, so "cables.a.b.length" finds a cable "a.b".
 * The table is the scene reader's too (param_impl.h): a key's unit and
 * limit are stated once.
 */
#include "towstab/param.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "param_impl.h"

typedef tsi_key row;

#define CAB(m) offsetof(ts_cable, m)
#define BOD(m) offsetof(ts_body, m)

static const row tow_rows[] = {
    {"speed", "m/s", 0, 0, TSI_KEY_PLAIN, offsetof(ts_tow, speed)},
    {"turn_rate", "rad/s", -INFINITY, 0, TSI_KEY_PLAIN, offsetof(ts_tow, turn_rate)},
    {"point", "m", -INFINITY, 0, TSI_KEY_VECTOR, offsetof(ts_tow, point)},
};

static const row env_rows[] = {
    {"water_density", "kg/m^3", 0, 0, TSI_KEY_PLAIN,
     offsetof(ts_environment, water_density)},
    {"gravity", "m/s^2", 0, 0, TSI_KEY_PLAIN, offsetof(ts_environment, gravity)},
    {"current", "m/s", -INFINITY, 0, TSI_KEY_VECTOR,
     offsetof(ts_environment, current)},
};

static const row cable_rows[] = {
    {"length", "m", 0, 1, TSI_KEY_PLAIN, CAB(length)},
    {"diameter", "m", 0, 1, TSI_KEY_PLAIN, CAB(diameter)},
    {"mass_per_length", "kg/m", 0, 0, TSI_KEY_PLAIN, CAB(mass_per_length)},
    {"weight", "N/m", 0, 0, TSI_KEY_WEIGHT, CAB(mass_per_length)},
    {"wet_weight", "N/m", -INFINITY, 0, TSI_KEY_WET_WEIGHT, CAB(mass_per_length)},
    {"links", "1", 1, 0, TSI_KEY_LINKS, CAB(nlinks)},
    {"normal_drag", "1", 0, 0, TSI_KEY_PLAIN, CAB(cdn)},
    {"tangential_drag", "1", 0, 0, TSI_KEY_PLAIN, CAB(cdt)},
    {"added_mass", "1", 0, 0, TSI_KEY_PLAIN, CAB(can)},
    {"EI", "N*m^2", 0, 0, TSI_KEY_PLAIN, CAB(ei)},
    {"EA", "N", 0, 0, TSI_KEY_PLAIN, CAB(ea)},
    {"damping", "N*s/m", 0, 0, TSI_KEY_PLAIN, CAB(damping)},
};

static const row body_rows[] = {
    {"diameter", "m", 0, 0, TSI_KEY_PLAIN, BOD(diameter)},
    {"length", "m", 0, 0, TSI_KEY_PLAIN, BOD(length)},
    {"mass", "kg", 0, 0, TSI_KEY_PLAIN, BOD(mass)},
    {"weight", "N", 0, 0, TSI_KEY_WEIGHT, BOD(mass)},
    {"wet_weight", "N", -INFINITY, 0, TSI_KEY_WET_WEIGHT, BOD(mass)},
    {"drag", "1", 0, 0, TSI_KEY_PLAIN, BOD(cd)},
    {"added_mass", "1", 0, 0, TSI_KEY_PLAIN, BOD(ca)},
    {"cross_drag", "1", 0, 0, TSI_KEY_PLAIN, BOD(cd_cross)},
    {"cross_added_mass", "1", 0, 0, TSI_KEY_PLAIN, BOD(ca_cross)},
};

/* A loop's keys: units depend on what it measures (unit "" here). */
static const row loop_rows[] = {
    {"kp", "", -INFINITY, 0, TSI_KEY_PLAIN, offsetof(ts_loop, kp)},
    {"ki", "", -INFINITY, 0, TSI_KEY_PLAIN, offsetof(ts_loop, ki)},
    {"kd", "", -INFINITY, 0, TSI_KEY_PLAIN, offsetof(ts_loop, kd)},
    {"setpoint", "", -INFINITY, 0, TSI_KEY_PLAIN, offsetof(ts_loop, setpoint)},
};

static const row surface_rows[] = {
    {"area", "m^2", 0, 1, TSI_KEY_PLAIN, offsetof(ts_component, area)},
    {"span", "m", 0, 1, TSI_KEY_PLAIN, offsetof(ts_component, span)},
    {"deflection", "rad", -INFINITY, 0, TSI_KEY_PLAIN,
     offsetof(ts_component, deflection)},
    {"limit", "rad", 0, 1, TSI_KEY_PLAIN, offsetof(ts_component, limit)},
    {"incidence", "rad", -INFINITY, 0, TSI_KEY_PLAIN,
     offsetof(ts_component, incidence)},
    {"roll", "rad", -INFINITY, 0, TSI_KEY_PLAIN, offsetof(ts_component, roll)},
    {"lift_slope", "1/rad", 0, 0, TSI_KEY_PLAIN,
     offsetof(ts_component, lift_slope)},
    {"stall", "rad", 0, 1, TSI_KEY_PLAIN, offsetof(ts_component, stall)},
    {"stall_width", "rad", 0, 1, TSI_KEY_PLAIN,
     offsetof(ts_component, stall_width)},
    {"zero_lift_drag", "1", 0, 0, TSI_KEY_PLAIN,
     offsetof(ts_component, cd0)},
    {"efficiency", "1", 0, 1, TSI_KEY_PLAIN,
     offsetof(ts_component, efficiency)},
    {"cn90", "1", 0, 0, TSI_KEY_PLAIN, offsetof(ts_component, cn90)},
    {"rate_limit", "rad/s", 0, 1, TSI_KEY_PLAIN,
     offsetof(ts_component, rate_limit)},
    {"time_constant", "s", 0, 0, TSI_KEY_PLAIN,
     offsetof(ts_component, time_constant)},
};

#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

static const row *find_row(const row *t, int n, const char *key);

const tsi_key *tsi_key_find(tsi_keys t, const char *key)
{
    switch (t) {
    case TSI_KEYS_TOW: return find_row(tow_rows, COUNT(tow_rows), key);
    case TSI_KEYS_ENV: return find_row(env_rows, COUNT(env_rows), key);
    case TSI_KEYS_CABLE: return find_row(cable_rows, COUNT(cable_rows), key);
    case TSI_KEYS_BODY: return find_row(body_rows, COUNT(body_rows), key);
    case TSI_KEYS_LOOP: return find_row(loop_rows, COUNT(loop_rows), key);
    default: return find_row(surface_rows, COUNT(surface_rows), key);
    }
}

static const char *const forms =
    "tow.speed, tow.turn_rate, tow.point.x|y|z, "
    "environment.water_density|gravity|current.x|y|z, "
    "cables.<name>.<key>, bodies.<name>.<key>, "
    "bodies.<vehicle>.loops.<loop>.kp|ki|kd|setpoint, "
    "bodies.<vehicle>.surfaces.<surface>.area|span|deflection|limit|"
    "incidence|roll|lift_slope|stall|stall_width|zero_lift_drag|"
    "efficiency|cn90|rate_limit|time_constant";

/* A path resolved against a system (or only by its form when sys is
 * NULL). */
typedef struct target {
    const row *r;
    int vec;          /* TSI_KEY_VECTOR: 0, 1, 2 for x, y, z */
    char *base;       /* the struct the row's offset is in; NULL when
                         resolved by form only */
    int cable, body;  /* indices, -1 when not one */
    int loop;         /* loop index, -1 */
    const char *collection;
} target;

static const row *find_row(const row *t, int n, const char *key)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(t[i].key, key))
            return &t[i];
    return NULL;
}

static void keys_list(const row *t, int n, char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(buf + len, len < size ? size - len : 0,
                                "%s%s", i ? ", " : "", t[i].key);
}

/* What a table's entries are, for messages. */
static const char *table_noun(const row *t)
{
    return t == tow_rows       ? "tow"
           : t == env_rows     ? "environment"
           : t == cable_rows   ? "a cable"
           : t == body_rows    ? "a body"
           : t == loop_rows    ? "a loop"
                               : "a surface";
}

static int unknown_key(const char *path, const char *key, const row *t,
                       int n, ts_err *err)
{
    char list[400];
    keys_list(t, n, list, sizeof list);
    return ts_fail(err, TS_EINVAL, "%s: no key '%s' of %s; expected one of "
                   "%s", path, key, table_noun(t), list);
}

/* The key `key` of table t, or a vector component "<key>.x". */
static int resolve_key(const char *path, const char *key, const row *t,
                       int n, target *tg, ts_err *err)
{
    tg->r = find_row(t, n, key);
    tg->vec = 0;
    if (tg->r && tg->r->kind != TSI_KEY_VECTOR)
        return TS_OK;
    if (tg->r) /* a vector without its component */
        return ts_fail(err, TS_EINVAL, "%s: '%s' is a vector; name a "
                       "component: %s.x, %s.y or %s.z", path, key, key, key,
                       key);
    const char *dot = strrchr(key, '.');
    if (dot && dot[1] && !dot[2] && strchr("xyz", dot[1])) {
        char head[TS_PARAM_PATH_MAX];
        snprintf(head, sizeof head, "%.*s", (int)(dot - key), key);
        tg->r = find_row(t, n, head);
        if (tg->r && tg->r->kind == TSI_KEY_VECTOR) {
            tg->vec = dot[1] - 'x';
            return TS_OK;
        }
    }
    tg->r = NULL;
    return unknown_key(path, key, t, n, err);
}

/* Entry of `names` (count n, stride bytes apart, the name at the start of
 * each) that `rest` starts with followed by a dot, the longest such;
 * *key then points past that dot. -1 when none. */
static int match_name(const char *rest, const char *names, size_t stride,
                      int n, const char **key)
{
    int best = -1;
    size_t best_len = 0;
    for (int i = 0; i < n; i++) {
        const char *nm = names + (size_t)i * stride;
        size_t len = strlen(nm);
        if (len > best_len && !strncmp(rest, nm, len) && rest[len] == '.') {
            best = i;
            best_len = len;
        }
    }
    if (best >= 0)
        *key = rest + best_len + 1;
    return best;
}

static void names_list(const char *names, size_t stride, int n, char *buf,
                       size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(buf + len, len < size ? size - len : 0,
                                "%s%s", i ? ", " : "",
                                names + (size_t)i * stride);
}

/* bodies.<vehicle>.loops.<loop>.<key> or .surfaces.<surface>.<key>. */
/* The part after a vehicle's "loops." ("controllers.", the scene's
 * word) or "surfaces." ("components."); *loops says which. NULL for
 * neither. */
static const char *vehicle_part(const char *key, int *loops)
{
    static const char *const words[4] = {"loops.", "controllers.",
                                         "surfaces.", "components."};
    for (int i = 0; i < 4; i++)
        if (!strncmp(key, words[i], strlen(words[i]))) {
            *loops = i < 2;
            return key + strlen(words[i]);
        }
    return NULL;
}

static int resolve_vehicle(const char *path, const ts_system *sys, int b,
                           const char *key, target *tg, ts_err *err)
{
    int loops = 0;
    const char *rest = vehicle_part(key, &loops);
    const ts_body *bd = sys ? &sys->bodies[b] : NULL;
    if (bd && (bd->type != TS_BODY_VEHICLE || !bd->vehicle))
        return ts_fail(err, TS_EINVAL, "%s: body '%s' is not a vehicle; "
                       "only vehicles have %s", path, bd->name,
                       loops ? "loops" : "surfaces");
    const char *k = strrchr(rest, '.');
    if (!k || k == rest)
        return ts_fail(err, TS_EINVAL, "%s: expected %s.<name>.<key>", path,
                       loops ? "loops" : "surfaces");
    k++;
    const row *t = loops ? loop_rows : surface_rows;
    int n = loops ? COUNT(loop_rows) : COUNT(surface_rows);
    if (resolve_key(path, k, t, n, tg, err))
        return TS_EINVAL;
    if (!bd)
        return TS_OK;
    ts_vehicle *v = bd->vehicle;
    const char *kk = NULL;
    char list[600];
    if (loops) {
        int l = match_name(rest, v->loop[0].name, sizeof v->loop[0],
                           v->nloops, &kk);
        if (l < 0 || strcmp(kk, k)) {
            names_list(v->loop[0].name, sizeof v->loop[0], v->nloops, list,
                       sizeof list);
            return ts_fail(err, TS_EINVAL, "%s: vehicle '%s' has no loop "
                           "'%.*s'; its loops: %s", path, bd->name,
                           (int)(k - 1 - rest), rest,
                           list[0] ? list : "none");
        }
        tg->loop = l;
        tg->base = (char *)&v->loop[l];
        return TS_OK;
    }
    int c = match_name(rest, v->component[0].name, sizeof v->component[0],
                       v->ncomponents, &kk);
    if (c < 0 || strcmp(kk, k) || v->component[c].type != TS_COMP_SURFACE) {
        size_t len = 0;
        list[0] = '\0';
        for (int i = 0; i < v->ncomponents; i++)
            if (v->component[i].type == TS_COMP_SURFACE)
                len += (size_t)snprintf(list + len,
                                        len < sizeof list ? sizeof list - len
                                                          : 0,
                                        "%s%s", len ? ", " : "",
                                        v->component[i].name);
        return ts_fail(err, TS_EINVAL, "%s: vehicle '%s' has no lifting "
                       "surface '%.*s'; its surfaces: %s", path, bd->name,
                       (int)(k - 1 - rest), rest, list[0] ? list : "none");
    }
    tg->base = (char *)&v->component[c];
    return TS_OK;
}

/* The scene format's spelling of a path (doc/scene-format.md, "Setting
 * values": "cables[armour].length", "cables[0].length",
 * "bodies[fish].components[tailplane].area", "tow.point[2]") into ours
 * ("cables.armour.length", "tow.point.z"). An index selects by position
 * (with sys; without, its name is left as "[i]", which only the form
 * needs). Returns TS_OK or TS_EINVAL (an index out of range, an
 * unclosed bracket). */
static int spell(const ts_system *sys, const char *path, char *out,
                 size_t size, ts_err *err)
{
    size_t o = 0;
    for (const char *p = path; *p && o + 1 < size;) {
        if (*p != '[') {
            out[o++] = *p++;
            continue;
        }
        const char *close = strchr(p, ']');
        if (!close)
            return ts_fail(err, TS_EINVAL, "%s: an unclosed '['", path);
        char sel[TS_PARAM_PATH_MAX];
        snprintf(sel, sizeof sel, "%.*s", (int)(close - p - 1), p + 1);
        int digits = sel[0] != '\0';
        for (const char *q = sel; *q; q++)
            digits &= *q >= '0' && *q <= '9';
        /* What the bracket follows: "point", "cables", "components". */
        size_t start = o;
        while (start > 0 && out[start - 1] != '.')
            start--;
        char what[32];
        snprintf(what, sizeof what, "%.*s", (int)(o - start), out + start);
        const char *name = sel;
        char buf[TS_NAME_MAX + 8];
        long i = digits ? strtol(sel, NULL, 10) : -1;
        if (!strcmp(what, "point") || !strcmp(what, "current")) {
            if (!digits || i > 2)
                return ts_fail(err, TS_EINVAL, "%s: [%s]: expected a "
                               "component 0, 1 or 2", path, sel);
            snprintf(buf, sizeof buf, "%c", "xyz"[i]);
            name = buf;
        } else if (digits && sys && !strcmp(what, "cables")) {
            if (i >= sys->ncables)
                return ts_fail(err, TS_EINVAL, "%s: 'cables' has no entry "
                               "[%ld] (%d entries, from 0, or a name)", path,
                               i, sys->ncables);
            name = sys->cables[i].name;
        } else if (digits && sys && !strcmp(what, "bodies")) {
            if (i >= sys->nbodies)
                return ts_fail(err, TS_EINVAL, "%s: 'bodies' has no entry "
                               "[%ld] (%d entries, from 0, or a name)", path,
                               i, sys->nbodies);
            name = sys->bodies[i].name;
        } else if (digits) {
            snprintf(buf, sizeof buf, "[%ld]", i);
            name = buf;
        }
        /* A vehicle's components are its surfaces here. */
        if (!strcmp(what, "components")) {
            o = start;
            o += (size_t)snprintf(out + o, size - o, "surfaces");
        }
        o += (size_t)snprintf(out + o, o < size ? size - o : 0, ".%s", name);
        p = close + 1;
    }
    if (o >= size)
        return ts_fail(err, TS_EINVAL, "path: longer than %zu characters",
                       size - 1);
    out[o] = '\0';
    return TS_OK;
}

static int resolve_spelled(const ts_system *sys, const char *path,
                           target *tg, ts_err *err);

/* Resolve `path` in either spelling (sys may be NULL: by form only);
 * messages name the path as given. */
static int resolve(const ts_system *sys, const char *path, target *tg,
                   ts_err *err)
{
    char dotted[TS_PARAM_PATH_MAX];
    memset(tg, 0, sizeof *tg);
    tg->cable = tg->body = tg->loop = -1;
    if (path && strchr(path, '[')) {
        if (strlen(path) >= TS_PARAM_PATH_MAX)
            return ts_fail(err, TS_EINVAL, "path: longer than %d characters",
                           TS_PARAM_PATH_MAX - 1);
        int rc = spell(sys, path, dotted, sizeof dotted, err);
        if (rc)
            return rc;
        ts_err e = {0};
        rc = resolve_spelled(sys, dotted, tg, &e);
        if (rc)
            ts_fail(err, rc, "%s (%s)", e.msg, path);
        return rc;
    }
    return resolve_spelled(sys, path, tg, err);
}

static int resolve_spelled(const ts_system *sys, const char *path,
                           target *tg, ts_err *err)
{
    memset(tg, 0, sizeof *tg);
    tg->cable = tg->body = tg->loop = -1;
    if (!path || !path[0])
        return ts_fail(err, TS_EINVAL, "path: empty; expected one of %s",
                       forms);
    if (strlen(path) >= TS_PARAM_PATH_MAX)
        return ts_fail(err, TS_EINVAL, "path: longer than %d characters",
                       TS_PARAM_PATH_MAX - 1);
    ts_system *s = (ts_system *)sys;
    if (!strcmp(path, "speed") || !strcmp(path, "turn_rate")) {
        tg->collection = "tow";
        tg->r = find_row(tow_rows, COUNT(tow_rows), path);
        tg->base = s ? (char *)&s->tow : NULL;
        return TS_OK;
    }
    if (!strncmp(path, "tow.", 4)) {
        tg->collection = "tow";
        tg->base = s ? (char *)&s->tow : NULL;
        return resolve_key(path, path + 4, tow_rows, COUNT(tow_rows), tg,
                           err);
    }
    if (!strncmp(path, "environment.", 12)) {
        tg->collection = "environment";
        tg->base = s ? (char *)&s->env : NULL;
        return resolve_key(path, path + 12, env_rows, COUNT(env_rows), tg,
                           err);
    }
    int cables = !strncmp(path, "cables.", 7);
    if (!cables && strncmp(path, "bodies.", 7))
        return ts_fail(err, TS_EINVAL, "%s: not a path of the scene; expected "
                       "one of %s", path, forms);
    tg->collection = cables ? "cables" : "bodies";
    const char *rest = path + 7, *key = NULL;
    if (!s) {
        /* By form: the key is what follows the last dot, or a vehicle's
         * loops/surfaces part. */
        const char *p = NULL;
        int loops;
        for (const char *q = strchr(rest, '.'); q && !p;
             q = strchr(q + 1, '.'))
            if (vehicle_part(q + 1, &loops))
                p = q;
        if (!cables && p)
            return resolve_vehicle(path, NULL, -1, p + 1, tg, err);
        key = strrchr(rest, '.');
        if (!key || key == rest)
            return ts_fail(err, TS_EINVAL, "%s: expected %s.<name>.<key>",
                           path, tg->collection);
        return cables ? resolve_key(path, key + 1, cable_rows,
                                    COUNT(cable_rows), tg, err)
                      : resolve_key(path, key + 1, body_rows,
                                    COUNT(body_rows), tg, err);
    }
    char list[600];
    if (cables) {
        int c = match_name(rest, s->cables[0].name, sizeof s->cables[0],
                           s->ncables, &key);
        if (c < 0) {
            names_list(s->cables[0].name, sizeof s->cables[0], s->ncables,
                       list, sizeof list);
            return ts_fail(err, TS_EINVAL, "%s: no cable of that name; the "
                           "cables: %s", path, list);
        }
        tg->cable = c;
        tg->base = (char *)&s->cables[c];
        return resolve_key(path, key, cable_rows, COUNT(cable_rows), tg,
                           err);
    }
    int b = s->nbodies > 0 ? match_name(rest, s->bodies[0].name,
                                        sizeof s->bodies[0], s->nbodies, &key)
                           : -1;
    if (b < 0) {
        if (s->nbodies > 0)
            names_list(s->bodies[0].name, sizeof s->bodies[0], s->nbodies,
                       list, sizeof list);
        return ts_fail(err, TS_EINVAL, "%s: no body of that name; the "
                       "bodies: %s", path, s->nbodies > 0 ? list : "none");
    }
    tg->body = b;
    int loops;
    if (vehicle_part(key, &loops))
        return resolve_vehicle(path, s, b, key, tg, err);
    tg->base = (char *)&s->bodies[b];
    return resolve_key(path, key, body_rows, COUNT(body_rows), tg, err);
}

const char *tsi_loop_unit(int depth, const char *key)
{
    if (!strcmp(key, "setpoint"))
        return depth ? "m" : "rad";
    if (!strcmp(key, "kp"))
        return depth ? "rad/m" : "1";
    if (!strcmp(key, "ki"))
        return depth ? "rad/(m*s)" : "1/s";
    return depth ? "rad*s/m" : "s";
}

static const char *target_unit(const target *tg)
{
    if (tg->loop >= 0 && tg->base)
        return tsi_loop_unit(((const ts_loop *)tg->base)->measure ==
                                 TS_MEASURE_DEPTH,
                             tg->r->key);
    return tg->r->unit;
}

int ts_param_unit(const ts_system *sys, const char *path, char *unit,
                  size_t size, ts_err *err)
{
    target tg;
    int rc = resolve(sys, path, &tg, err);
    if (rc)
        return rc;
    snprintf(unit, size, "%s", target_unit(&tg));
    return TS_OK;
}

int ts_param_canonical(const char *path, char *out, size_t size,
                       ts_err *err)
{
    target tg;
    int rc = resolve(NULL, path, &tg, err);
    if (rc)
        return rc;
    /* A cable or body chosen by index keeps its spelling: which one it is
     * depends on the system. */
    char dotted[TS_PARAM_PATH_MAX];
    int by_index = 0;
    for (const char *q = strchr(path, '['); q; q = strchr(q + 1, '['))
        by_index |= q[1] >= '0' && q[1] <= '9' &&
                    ((q - path >= 6 && !strncmp(q - 6, "cables", 6)) ||
                     (q - path >= 6 && !strncmp(q - 6, "bodies", 6)));
    if (strchr(path, '[') && !by_index)
        spell(NULL, path, dotted, sizeof dotted, NULL);
    else
        snprintf(dotted, sizeof dotted, "%s", path);
    if (!strcmp(path, "speed") || !strcmp(path, "turn_rate")) {
        snprintf(out, size, "tow.%s", path);
        return TS_OK;
    }
    /* A vehicle's controllers and components by the scene's words are its
     * loops and surfaces. */
    size_t o = 0;
    int loops;
    for (const char *p = dotted; *p && o + 1 < size;) {
        const char *rest = p[0] == '.' ? vehicle_part(p + 1, &loops) : NULL;
        if (rest) {
            o += (size_t)snprintf(out + o, size - o, ".%s.",
                                  loops ? "loops" : "surfaces");
            p = rest;
        } else {
            out[o++] = *p++;
        }
    }
    if (o < size)
        out[o] = '\0';
    return TS_OK;
}

/* Volume for the buoyancy of a wet weight: a cable's per metre. */
static double wet_volume(const ts_system *sys, const target *tg)
{
    if (tg->cable >= 0) {
        double d = sys->cables[tg->cable].diameter;
        return M_PI * d * d / 4.0;
    }
    return ts_body_volume(&sys->bodies[tg->body]);
}

int ts_param_get(const ts_system *sys, const char *path, double *value,
                 ts_err *err)
{
    target tg;
    int rc = resolve(sys, path, &tg, err);
    if (rc)
        return rc;
    const char *at = tg.base + tg.r->offset;
    double g = sys->env.gravity;
    switch (tg.r->kind) {
    case TSI_KEY_LINKS: *value = *(const int *)at; break;
    case TSI_KEY_VECTOR: *value = ((const double *)at)[tg.vec]; break;
    case TSI_KEY_WEIGHT: *value = *(const double *)at * g; break;
    case TSI_KEY_WET_WEIGHT:
        *value = (*(const double *)at -
                  sys->env.water_density * wet_volume(sys, &tg)) * g;
        break;
    default: *value = *(const double *)at;
    }
    return TS_OK;
}

int ts_param_set(ts_system *sys, const char *path, double value,
                 ts_err *err)
{
    target tg;
    int rc = resolve(sys, path, &tg, err);
    if (rc)
        return rc;
    const row *r = tg.r;
    const char *unit = target_unit(&tg);
    const char *u = strcmp(unit, "1") ? unit : "";
    const char *sp = u[0] ? " " : "";
    int ok = isfinite(value) || (r == &surface_rows[3] && value == INFINITY);
    if (!ok)
        return ts_fail(err, TS_EINVAL, "%s: expected a finite number%s%s",
                       path, u[0] ? " in " : "", u);
    if (isfinite(r->min))
        ok = r->strict ? value > r->min : value >= r->min;
    if (!ok)
        return ts_fail(err, TS_EINVAL, "%s: must be %s %g%s%s, got %g%s%s",
                       path, r->strict ? ">" : ">=", r->min, sp, u, value, sp,
                       u);
    char *at = tg.base + r->offset;
    double g = sys->env.gravity;
    switch (r->kind) {
    case TSI_KEY_LINKS: {
        const ts_cable *c = &sys->cables[tg.cable];
        if (value != floor(value) || value > TS_MAX_LINKS)
            return ts_fail(err, TS_EINVAL, "%s: expected a whole number of "
                           "links from 1 to %d, got %g", path, TS_MAX_LINKS,
                           value);
        if (c->link_fraction)
            return ts_fail(err, TS_EINVAL, "%s: cable '%s' has link_lengths; "
                           "remove them to set the number of links", path,
                           c->name);
        *(int *)at = (int)value;
        break;
    }
    case TSI_KEY_VECTOR: ((double *)at)[tg.vec] = value; break;
    case TSI_KEY_WEIGHT:
    case TSI_KEY_WET_WEIGHT: {
        if (!(g > 0))
            return ts_fail(err, TS_EINVAL, "%s: without gravity a weight "
                           "gives no mass; set the mass instead", path);
        double m = value / g;
        if (r->kind == TSI_KEY_WET_WEIGHT)
            m += sys->env.water_density * wet_volume(sys, &tg);
        if (!(m >= 0))
            return ts_fail(err, TS_EINVAL, "%s: %g %s is a negative mass in "
                           "air (%g kg%s): the buoyancy is only %g %s", path,
                           value, unit, m, tg.cable >= 0 ? "/m" : "",
                           sys->env.water_density * wet_volume(sys, &tg) * g,
                           unit);
        *(double *)at = m;
        break;
    }
    default: *(double *)at = value;
    }
    return TS_OK;
}
