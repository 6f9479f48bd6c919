/* param.c: a scalar of a towed system by its scene key path
 * (towstab/param.h; doc/scene-format.md, "Values by path").
 *
 * A path is split at its dots into a collection (tow, environment,
 * cables, bodies, towing_vehicle: the body ts_tow.vehicle, with its
 * propulsion), an entry name where the collection has entries, and a
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
#include "towstab/vehicle.h"

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

/* A vehicle's own keys (bodies.<vehicle>.<key>; its mass keys are a
 * body's). */
#define VEH(m) offsetof(ts_vehicle, m)
static const row vehicle_rows[] = {
    {"volume", "m^3", 0, 0, TSI_KEY_PLAIN, VEH(volume)},
    {"inertia", "kg*m^2", -INFINITY, 0, TSI_KEY_INERTIA, VEH(inertia)},
    {"mass_centre", "m", -INFINITY, 0, TSI_KEY_VECTOR, VEH(mass_centre)},
    {"buoyancy_centre", "m", -INFINITY, 0, TSI_KEY_VECTOR,
     VEH(buoyancy_centre)},
    {"attach", "m", -INFINITY, 0, TSI_KEY_VECTOR, VEH(attach)},
    {"surface_diameter", "m", 0, 0, TSI_KEY_PLAIN, VEH(surface_diameter)},
};

/* The body keys a vehicle has besides its own. */
static const char *const vehicle_body_keys[] = {"mass", "weight",
                                                "wet_weight"};

/* A hull's and a bluff part's keys. */
#define CMP(m) offsetof(ts_component, m)
static const row hull_rows[] = {
    {"position", "m", -INFINITY, 0, TSI_KEY_VECTOR, CMP(position)},
    {"length", "m", 0, 1, TSI_KEY_PLAIN, CMP(length)},
    {"diameter", "m", 0, 1, TSI_KEY_PLAIN, CMP(diameter)},
    {"axial_drag", "1", 0, 0, TSI_KEY_PLAIN, CMP(cd_axial)},
    {"cross_drag", "1", 0, 0, TSI_KEY_PLAIN, CMP(cd_cross)},
};

static const row bluff_rows[] = {
    {"position", "m", -INFINITY, 0, TSI_KEY_VECTOR, CMP(position)},
    {"area", "m^2", 0, 1, TSI_KEY_PLAIN, CMP(area)},
    {"drag", "1", 0, 0, TSI_KEY_PLAIN, CMP(drag)},
};

static const row mast_rows[] = {
    {"position", "m", -INFINITY, 0, TSI_KEY_VECTOR, CMP(position)},
    {"length", "m", 0, 1, TSI_KEY_PLAIN, CMP(length)},
    {"area", "m^2", 0, 1, TSI_KEY_PLAIN, CMP(area)},
    {"chord", "m", 0, 1, TSI_KEY_PLAIN, CMP(chord)},
    {"thickness", "m", 0, 1, TSI_KEY_PLAIN, CMP(thickness)},
    {"drag", "1", 0, 0, TSI_KEY_PLAIN, CMP(drag)},
};

static const row ballast_rows[] = {
    {"position", "m", -INFINITY, 0, TSI_KEY_VECTOR, CMP(position)},
    {"capacity", "kg", 0, 1, TSI_KEY_PLAIN, CMP(capacity)},
    {"fill", "kg", 0, 0, TSI_KEY_PLAIN, CMP(deflection)},
    {"rate_limit", "kg/s", 0, 1, TSI_KEY_PLAIN, CMP(rate_limit)},
    {"time_constant", "s", 0, 0, TSI_KEY_PLAIN, CMP(time_constant)},
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
    {"position", "m", -INFINITY, 0, TSI_KEY_VECTOR,
     offsetof(ts_component, position)},
};

/* The surface row whose value may be infinite (no limit). */
static const row *const surface_limit = &surface_rows[3];

/* A towing vehicle's propulsion (towing_vehicle.propulsion.<key>; each
 * key but `at` belongs to one law or two, prop_laws). */
#define PRP(m) offsetof(ts_propulsion, m)
static const row propulsion_rows[] = {
    {"thrust", "N", -INFINITY, 0, TSI_KEY_PLAIN, PRP(thrust)},
    {"power", "W", 0, 1, TSI_KEY_PLAIN, PRP(power)},
    {"speed", "m/s", 0, 1, TSI_KEY_PLAIN, PRP(speed)},
    {"max_thrust", "N", 0, 1, TSI_KEY_PLAIN, PRP(max_thrust)},
    {"gain", "N*s/m", 0, 0, TSI_KEY_PLAIN, PRP(gain)},
    {"integral_gain", "N/m", 0, 0, TSI_KEY_PLAIN, PRP(ki)},
    {"at", "m", -INFINITY, 0, TSI_KEY_VECTOR, PRP(position)},
};

/* The propulsion row whose value may be infinite (no cap). */
static const row *const propulsion_cap = &propulsion_rows[3];

/* The laws (bits of 1 << ts_propulsion_type) each propulsion row
 * applies to, in the rows' order. */
static const unsigned prop_laws[] = {
    1u << TS_PROP_THRUST, 1u << TS_PROP_POWER, 1u << TS_PROP_SPEED,
    1u << TS_PROP_POWER | 1u << TS_PROP_SPEED, 1u << TS_PROP_SPEED,
    1u << TS_PROP_SPEED,
    1u << TS_PROP_THRUST | 1u << TS_PROP_POWER | 1u << TS_PROP_SPEED};

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
    case TSI_KEYS_VEHICLE:
        return find_row(vehicle_rows, COUNT(vehicle_rows), key);
    case TSI_KEYS_HULL: return find_row(hull_rows, COUNT(hull_rows), key);
    case TSI_KEYS_BLUFF: return find_row(bluff_rows, COUNT(bluff_rows), key);
    case TSI_KEYS_PROPULSION:
        return find_row(propulsion_rows, COUNT(propulsion_rows), key);
    case TSI_KEYS_MAST: return find_row(mast_rows, COUNT(mast_rows), key);
    case TSI_KEYS_BALLAST:
        return find_row(ballast_rows, COUNT(ballast_rows), key);
    default: return find_row(surface_rows, COUNT(surface_rows), key);
    }
}

static const char *const forms =
    "tow.speed, tow.turn_rate, tow.point.x|y|z, "
    "environment.water_density|gravity|current.x|y|z, "
    "cables.<name>.<key>, bodies.<name>.<key>, "
    "bodies.<vehicle>.volume|surface_diameter|inertia.xx|yy|zz|xy|xz|yz|"
    "mass_centre.x|y|z|buoyancy_centre.x|y|z|attach.x|y|z, "
    "bodies.<vehicle>.loops.<loop>.kp|ki|kd|setpoint, "
    "bodies.<vehicle>.components.<surface>.area|span|deflection|limit|"
    "incidence|roll|lift_slope|stall|stall_width|zero_lift_drag|"
    "efficiency|cn90|rate_limit|time_constant|position.x|y|z, "
    "bodies.<vehicle>.components.<hull>.length|diameter|axial_drag|"
    "cross_drag|position.x|y|z, "
    "bodies.<vehicle>.components.<bluff part>.area|drag|position.x|y|z, "
    "towing_vehicle.<key> (a vehicle's keys, its attach point tow_point), "
    "towing_vehicle.propulsion.thrust|power|speed|max_thrust|gain|"
    "integral_gain|at.x|y|z";

/* A path resolved against a system (or only by its form when sys is
 * NULL). */
typedef struct target {
    const row *r;
    int vec;          /* TSI_KEY_VECTOR: 0, 1, 2 for x, y, z */
    char *base;       /* the struct the row's offset is in; NULL when
                         resolved by form only */
    int cable, body;  /* indices, -1 when not one */
    int loop;         /* loop index, -1 */
    int comp;         /* a vehicle's component index, -1 */
    const char *collection;
} target;

static const row *find_row(const row *t, int n, const char *key)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(t[i].key, key))
            return &t[i];
    return NULL;
}

/* The names of a vector's or an inertia's entries, "" for a scalar. */
static const char *entries_of(const row *r)
{
    return r->kind == TSI_KEY_VECTOR    ? ".x|y|z"
           : r->kind == TSI_KEY_INERTIA ? ".xx|yy|zz|xy|xz|yz"
                                        : "";
}

/* The index of entry `name` of row r (x, y, z; xx, yy, zz, xy, xz, yz),
 * -1 when it has none of that name. */
static int entry_index(const row *r, const char *name)
{
    static const char *const vec[3] = {"x", "y", "z"};
    static const char *const inertia[6] = {"xx", "yy", "zz",
                                           "xy", "xz", "yz"};
    const char *const *names = r->kind == TSI_KEY_VECTOR ? vec : inertia;
    int n = r->kind == TSI_KEY_VECTOR ? 3 : r->kind == TSI_KEY_INERTIA ? 6
                                                                        : 0;
    for (int i = 0; i < n; i++)
        if (!strcmp(name, names[i]))
            return i;
    return -1;
}

static void keys_list(const row *t, int n, char *buf, size_t size)
{
    size_t len = strlen(buf);
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(buf + len, len < size ? size - len : 0,
                                "%s%s%s", len ? ", " : "", t[i].key,
                                entries_of(&t[i]));
}

/* What a table's entries are, for messages. */
static const char *table_noun(const row *t)
{
    return t == tow_rows       ? "tow"
           : t == env_rows     ? "environment"
           : t == cable_rows   ? "a cable"
           : t == body_rows    ? "a body"
           : t == loop_rows    ? "a loop"
           : t == vehicle_rows ? "a vehicle"
           : t == hull_rows    ? "a hull"
           : t == bluff_rows   ? "a bluff part"
           : t == propulsion_rows ? "the propulsion"
           : t == mast_rows    ? "a mast"
           : t == ballast_rows ? "a ballast tank"
                               : "a surface";
}

static int unknown_key(const char *path, const char *key, const row *t,
                       int n, ts_err *err)
{
    char list[600] = "";
    keys_list(t, n, list, sizeof list);
    return ts_fail(err, TS_EINVAL, "%s: no key '%s' of %s; expected one of "
                   "%s", path, key, table_noun(t), list);
}

/* The key `key` of table t, or an entry "<key>.x" of a vector or
 * "<key>.xy" of an inertia, into tg->r and tg->vec: TS_OK, or TS_EINVAL
 * with tg->r the row of a vector or inertia named without its entry
 * (NULL for no such key). No message. */
static int find_key(const char *key, const row *t, int n, target *tg)
{
    tg->r = find_row(t, n, key);
    tg->vec = 0;
    if (tg->r)
        return tg->r->kind == TSI_KEY_VECTOR ||
                       tg->r->kind == TSI_KEY_INERTIA
                   ? TS_EINVAL
                   : TS_OK;
    const char *dot = strrchr(key, '.');
    if (dot) {
        char head[TS_PARAM_PATH_MAX];
        snprintf(head, sizeof head, "%.*s", (int)(dot - key), key);
        const row *r = find_row(t, n, head);
        int e = r ? entry_index(r, dot + 1) : -1;
        if (e >= 0) {
            tg->r = r;
            tg->vec = e;
            return TS_OK;
        }
    }
    return TS_EINVAL;
}

/* The key `key` of table t, or an entry of a vector or an inertia. */
static int resolve_key(const char *path, const char *key, const row *t,
                       int n, target *tg, ts_err *err)
{
    if (find_key(key, t, n, tg) == TS_OK)
        return TS_OK;
    if (tg->r) /* a vector or an inertia without its entry */
        return ts_fail(err, TS_EINVAL, "%s: '%s' is a %s; name an entry: "
                       "%s%s", path, key, tg->r->kind == TSI_KEY_VECTOR
                       ? "vector" : "list", key, entries_of(tg->r));
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

/* The part after a vehicle's "loops." ("controllers.", the scene's
 * word) or "components." ("surfaces."); *loops says which. NULL for
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

/* The key table of a component of `type`. */
static const row *component_rows(ts_component_type type, int *n)
{
    *n = type == TS_COMP_HULL    ? COUNT(hull_rows)
         : type == TS_COMP_BLUFF ? COUNT(bluff_rows)
         : type == TS_COMP_MAST  ? COUNT(mast_rows)
         : type == TS_COMP_BALLAST ? COUNT(ballast_rows)
                                 : COUNT(surface_rows);
    return type == TS_COMP_HULL    ? hull_rows
           : type == TS_COMP_BLUFF ? bluff_rows
           : type == TS_COMP_MAST  ? mast_rows
           : type == TS_COMP_BALLAST ? ballast_rows
                                   : surface_rows;
}

/* By form only: `rest` (after "components.") ends in a key of a surface,
 * a hull or a bluff part, one name ("area") or an entry ("position.x"). */
static int component_form(const char *path, const char *rest, target *tg,
                          ts_err *err)
{
    static const ts_component_type types[5] = {
        TS_COMP_SURFACE, TS_COMP_HULL, TS_COMP_BLUFF, TS_COMP_MAST,
        TS_COMP_BALLAST};
    const char *last = strrchr(rest, '.');
    for (const char *k = last; k && k > rest; k--) {
        if (*k != '.')
            continue;
        for (int i = 0; i < 5; i++) {
            int n;
            const row *t = component_rows(types[i], &n);
            if (find_key(k + 1, t, n, tg) == TS_OK)
                return TS_OK;
        }
        if (k != last) /* at most two names: "position.x" */
            break;
    }
    char list[800] = "";
    for (int i = 0; i < 5; i++) {
        int n;
        const row *t = component_rows(types[i], &n);
        keys_list(t, n, list, sizeof list);
    }
    return ts_fail(err, TS_EINVAL, "%s: expected components.<name>.<key> "
                   "with a key of a surface, a hull, a bluff part, a mast "
                   "or a ballast tank: %s",
                   path, list);
}

/* bodies.<vehicle>.loops.<loop>.<key> or .components.<component>.<key>
 * (key: the part after the vehicle's name). */
static int resolve_vehicle(const char *path, const ts_system *sys, int b,
                           const char *key, target *tg, ts_err *err)
{
    int loops = 0;
    const char *rest = vehicle_part(key, &loops);
    const ts_body *bd = sys ? &sys->bodies[b] : NULL;
    if (bd && (bd->type != TS_BODY_VEHICLE || !bd->vehicle))
        return ts_fail(err, TS_EINVAL, "%s: body '%s' is not a vehicle; "
                       "only vehicles have %s", path, bd->name,
                       loops ? "loops" : "components");
    const char *k = strrchr(rest, '.');
    if (!k || k == rest)
        return ts_fail(err, TS_EINVAL, "%s: expected %s.<name>.<key>", path,
                       loops ? "loops" : "components");
    if (!bd && !loops)
        return component_form(path, rest, tg, err);
    if (!bd)
        return resolve_key(path, k + 1, loop_rows, COUNT(loop_rows), tg,
                           err);
    ts_vehicle *v = bd->vehicle;
    const char *kk = NULL;
    char list[600];
    if (loops) {
        int l = match_name(rest, v->loop[0].name, sizeof v->loop[0],
                           v->nloops, &kk);
        if (l < 0) {
            names_list(v->loop[0].name, sizeof v->loop[0], v->nloops, list,
                       sizeof list);
            return ts_fail(err, TS_EINVAL, "%s: vehicle '%s' has no loop "
                           "'%.*s'; its loops: %s", path, bd->name,
                           (int)(k - rest), rest, list[0] ? list : "none");
        }
        tg->loop = l;
        tg->base = (char *)&v->loop[l];
        return resolve_key(path, kk, loop_rows, COUNT(loop_rows), tg, err);
    }
    int c = match_name(rest, v->component[0].name, sizeof v->component[0],
                       v->ncomponents, &kk);
    if (c < 0) {
        size_t len = 0;
        list[0] = '\0';
        static const char *const kind[] = {"hull", "surface", "bluff",
                                           "mast", "ballast tank"};
        for (int i = 0; i < v->ncomponents; i++)
            len += (size_t)snprintf(list + len,
                                    len < sizeof list ? sizeof list - len : 0,
                                    "%s%s (%s)", len ? ", " : "",
                                    v->component[i].name,
                                    (int)v->component[i].type < COUNT(kind)
                                        ? kind[v->component[i].type]
                                        : "component");
        return ts_fail(err, TS_EINVAL, "%s: vehicle '%s' has no component "
                       "'%.*s'; its components: %s", path, bd->name,
                       (int)(k - rest), rest, list[0] ? list : "none");
    }
    int n;
    const row *t = component_rows(v->component[c].type, &n);
    tg->comp = c;
    tg->base = (char *)&v->component[c];
    return resolve_key(path, kk, t, n, tg, err);
}

/* bodies.<body>.<key> of body b (key: the part after its name): a body's
 * key, and a vehicle's own (vehicle_rows) where b is a vehicle, which has
 * only the mass keys of a body. By form (sys NULL) the key is the last
 * name, or the last two for an entry ("attach.x"). */
static int resolve_body(const char *path, const ts_system *sys, int b,
                        const char *rest, target *tg, ts_err *err)
{
    ts_body *bd = sys ? &((ts_system *)sys)->bodies[b] : NULL;
    const char *key = rest;
    if (!bd) {
        key = strrchr(rest, '.');
        if (!key || key == rest)
            return ts_fail(err, TS_EINVAL, "%s: expected bodies.<name>.<key>",
                           path);
        key++;
        /* An entry of a vector or an inertia: its key is two names. */
        for (const char *q = key - 2; q > rest; q--)
            if (*q == '.') {
                if (find_key(q + 1, vehicle_rows, COUNT(vehicle_rows), tg) ==
                    TS_OK)
                    return TS_OK;
                break;
            }
    }
    int vehicle = bd ? bd->type == TS_BODY_VEHICLE && bd->vehicle : 1;
    if (vehicle && find_key(key, vehicle_rows, COUNT(vehicle_rows), tg) ==
                       TS_OK) {
        tg->base = bd ? (char *)bd->vehicle : NULL;
        return TS_OK;
    }
    if (vehicle && tg->r)
        return resolve_key(path, key, vehicle_rows, COUNT(vehicle_rows), tg,
                           err);
    tg->base = (char *)bd;
    int known = find_key(key, body_rows, COUNT(body_rows), tg) == TS_OK;
    if (known && bd && vehicle) {
        known = 0;
        for (int i = 0; i < COUNT(vehicle_body_keys); i++)
            known |= !strcmp(key, vehicle_body_keys[i]);
    }
    if (known)
        return TS_OK;
    if (bd && !vehicle)
        return resolve_key(path, key, body_rows, COUNT(body_rows), tg, err);
    if (!bd) {
        if (tg->r) /* a vector or an inertia without its entry */
            return resolve_key(path, key, body_rows, COUNT(body_rows), tg,
                               err);
        char keys[400] = "", vkeys[400] = "";
        keys_list(body_rows, COUNT(body_rows), keys, sizeof keys);
        keys_list(vehicle_rows, COUNT(vehicle_rows), vkeys, sizeof vkeys);
        return ts_fail(err, TS_EINVAL, "%s: no key '%s' of a body; expected "
                       "one of %s; or of a vehicle %s, "
                       "controllers.<loop>.<key>, "
                       "components.<component>.<key>", path, key, keys,
                       vkeys);
    }
    char list[600] = "";
    for (int i = 0; i < COUNT(vehicle_body_keys); i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                 i ? ", " : "", vehicle_body_keys[i]);
    keys_list(vehicle_rows, COUNT(vehicle_rows), list, sizeof list);
    return ts_fail(err, TS_EINVAL, "%s: no key '%s' of a vehicle; expected "
                   "one of %s, controllers.<loop>.<key> or "
                   "components.<component>.<key>", path, key, list);
}

/* The names of a towing vehicle's propulsion laws, for messages. */
static const char *law_name(ts_propulsion_type t)
{
    return t == TS_PROP_THRUST  ? "thrust"
           : t == TS_PROP_POWER ? "power (the constant-power law)"
           : t == TS_PROP_SPEED ? "speed (a speed controller)"
                                : "none";
}

/* Refuse a propulsion key of a law other than p's: the scene takes it
 * only with its law (lib/scene.c), so the path does too. */
static int propulsion_applies(const char *path, const ts_propulsion *p,
                              const row *r, ts_err *err)
{
    unsigned laws = prop_laws[r - propulsion_rows];
    if (laws & 1u << p->type)
        return TS_OK;
    char list[200] = "";
    for (int i = 0; i < COUNT(propulsion_rows); i++)
        if (prop_laws[i] & 1u << p->type)
            snprintf(list + strlen(list), sizeof list - strlen(list),
                     "%s%s%s", list[0] ? ", " : "", propulsion_rows[i].key,
                     entries_of(&propulsion_rows[i]));
    return ts_fail(err, TS_EINVAL, "%s: the towing vehicle's propulsion is "
                   "%s, which has no '%s'; its keys: %s", path,
                   law_name(p->type), r->key, list);
}

/* What a towing vehicle takes by path, for messages: its mass keys, a
 * vehicle's own (its attach point named tow_point, as in the scene),
 * controllers, components and propulsion. */
static int towing_unknown(const char *path, const char *key, ts_err *err)
{
    char list[900] = "";
    for (int i = 0; i < COUNT(vehicle_body_keys); i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                 i ? ", " : "", vehicle_body_keys[i]);
    for (int i = 0; i < COUNT(vehicle_rows); i++) {
        const row *r = &vehicle_rows[i];
        snprintf(list + strlen(list), sizeof list - strlen(list), ", %s%s",
                 strcmp(r->key, "attach") ? r->key : "tow_point",
                 entries_of(r));
    }
    snprintf(list + strlen(list), sizeof list - strlen(list),
             ", controllers.<loop>.<key>, components.<component>.<key>, "
             "propulsion.<key> (");
    keys_list(propulsion_rows, COUNT(propulsion_rows), list + strlen(list),
              sizeof list - strlen(list));
    snprintf(list + strlen(list), sizeof list - strlen(list), ")");
    return ts_fail(err, TS_EINVAL, "%s: no key '%s' of the towing vehicle; "
                   "expected one of %s", path, key, list);
}

/* towing_vehicle.<key> (rest: the part after "towing_vehicle."): the
 * towing vehicle is a body of the system (ts_tow.vehicle) whose attach
 * point the scene calls tow_point, with a propulsion. By form when s is
 * NULL. */
static int resolve_towing(const char *path, ts_system *s, const char *rest,
                          target *tg, ts_err *err)
{
    tg->collection = "towing_vehicle";
    if (s && s->tow.vehicle < 0)
        return ts_fail(err, TS_EINVAL, "%s: the scene has no towing_vehicle "
                       "(its tow point is prescribed: tow.speed, "
                       "tow.turn_rate, tow.point.x|y|z)", path);
    int b = s ? s->tow.vehicle : -1;
    ts_vehicle *v = s ? s->bodies[b].vehicle : NULL;
    tg->body = b;
    if (!strncmp(rest, "propulsion.", 11)) {
        tg->base = v ? (char *)&v->propulsion : NULL;
        int rc = resolve_key(path, rest + 11, propulsion_rows,
                             COUNT(propulsion_rows), tg, err);
        return rc || !v ? rc
                        : propulsion_applies(path, &v->propulsion, tg->r,
                                             err);
    }
    int loops;
    if (vehicle_part(rest, &loops))
        return resolve_vehicle(path, s, b, rest, tg, err);
    /* The scene's tow_point is the vehicle's attach point; "attach" is
     * not a key of the towing vehicle. */
    char key[TS_PARAM_PATH_MAX];
    const char *tp = "tow_point";
    size_t n = strlen(tp);
    int attach = !strncmp(rest, "attach", 6) &&
                 (rest[6] == '\0' || rest[6] == '.');
    if (!strncmp(rest, tp, n) && (rest[n] == '\0' || rest[n] == '.'))
        snprintf(key, sizeof key, "attach%s", rest + n);
    else
        snprintf(key, sizeof key, "%s", rest);
    if (!attach && find_key(key, vehicle_rows, COUNT(vehicle_rows), tg) ==
                       TS_OK) {
        tg->base = (char *)v;
        return TS_OK;
    }
    if (!attach && tg->r) /* a vector or an inertia without its entry */
        return ts_fail(err, TS_EINVAL, "%s: '%s' is a %s; name an entry: "
                       "%s%s", path, rest, tg->r->kind == TSI_KEY_VECTOR
                       ? "vector" : "list", rest, entries_of(tg->r));
    for (int i = 0; !attach && i < COUNT(vehicle_body_keys); i++)
        if (!strcmp(key, vehicle_body_keys[i])) {
            tg->r = find_row(body_rows, COUNT(body_rows), key);
            tg->base = s ? (char *)&s->bodies[b] : NULL;
            return TS_OK;
        }
    return towing_unknown(path, rest, err);
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
        static const char *const vectors[] = {
            "point", "current", "position", "mass_centre",
            "buoyancy_centre", "attach", "tow_point", "at"};
        static const char *const inertia[6] = {"xx", "yy", "zz",
                                               "xy", "xz", "yz"};
        int vector = 0;
        for (int k = 0; k < COUNT(vectors); k++)
            vector |= !strcmp(what, vectors[k]);
        if (vector) {
            if (!digits || i > 2)
                return ts_fail(err, TS_EINVAL, "%s: [%s]: expected a "
                               "component 0, 1 or 2", path, sel);
            snprintf(buf, sizeof buf, "%c", "xyz"[i]);
            name = buf;
        } else if (!strcmp(what, "inertia")) {
            if (!digits || i > 5)
                return ts_fail(err, TS_EINVAL, "%s: [%s]: expected an entry "
                               "0 to 5 of [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]",
                               path, sel);
            name = inertia[i];
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
    tg->cable = tg->body = tg->loop = tg->comp = -1;
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
    tg->cable = tg->body = tg->loop = tg->comp = -1;
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
    if (!strncmp(path, "towing_vehicle.", 15))
        return resolve_towing(path, s, path + 15, tg, err);
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
        if (!cables)
            return resolve_body(path, NULL, -1, rest, tg, err);
        key = strrchr(rest, '.');
        if (!key || key == rest)
            return ts_fail(err, TS_EINVAL, "%s: expected %s.<name>.<key>",
                           path, tg->collection);
        return resolve_key(path, key + 1, cable_rows, COUNT(cable_rows), tg,
                           err);
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
    if (b == s->tow.vehicle)
        return ts_fail(err, TS_EINVAL, "%s: '%s' is the towing vehicle; its "
                       "values are towing_vehicle.<key> (towing_vehicle.%s)",
                       path, s->bodies[b].name, key);
    tg->body = b;
    int loops;
    if (vehicle_part(key, &loops))
        return resolve_vehicle(path, s, b, key, tg, err);
    return resolve_body(path, s, b, key, tg, err);
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

/* A plain number: strtod's whole text but blanks, finite. */
static int plain_number(const char *text, double *value)
{
    char *end;
    double v = strtod(text, &end);
    while (*end == ' ' || *end == '\t')
        end++;
    if (end == text || *end || !isfinite(v))
        return 0;
    *value = v;
    return 1;
}

int ts_param_parse(const ts_system *sys, const ts_units *u, const char *path,
                   const char *text, const char *where, double *value,
                   char *unit, size_t size, ts_err *err)
{
    target tg;
    int rc = resolve(sys, path, &tg, err);
    if (rc)
        return rc;
    const char *own = target_unit(&tg);
    if (!where)
        where = path;
    if (own[0]) {
        snprintf(unit, size, "%s", own);
        return ts_units_parse(u, text, own, where, value, err);
    }
    /* A loop's key without the system: the unit of a depth loop or of an
     * angle loop, whichever the value's fits (their dimensions differ by
     * a length: udunits takes rad as 1). */
    unit[0] = '\0';
    while (text && (*text == ' ' || *text == '\t'))
        text++;
    if (text && plain_number(text, value))
        return TS_OK;
    const char *cand[2] = {tsi_loop_unit(1, tg.r->key),
                           tsi_loop_unit(0, tg.r->key)};
    for (int k = 0; k < 2 && rc != TS_EINVAL; k++) {
        rc = ts_units_parse(u, text, cand[k], where, value, NULL);
        if (rc == TS_OK) {
            snprintf(unit, size, "%s", cand[k]);
            return TS_OK;
        }
    }
    /* Not a number (TS_EINVAL), or a unit of neither kind of loop. */
    return ts_fail(err, rc, "%s: expected a plain SI number or a number "
                   "with the unit of what the loop measures, %s for depth "
                   "or %s for an angle (pitch, roll, heading); got '%s'",
                   where, cand[0], cand[1], text ? text : "");
}

int ts_param_fits(const ts_system *sys, const char *path, const char *unit,
                  const char *given, ts_err *err)
{
    target tg;
    int rc = resolve(sys, path, &tg, err);
    if (rc || !unit || !unit[0])
        return rc;
    const char *own = target_unit(&tg);
    if (!strcmp(own, unit))
        return TS_OK;
    if (tg.loop < 0 || !tg.base || tg.body < 0 || !sys)
        return ts_fail(err, TS_EUNIT, "%s: the value is in %s; expected %s",
                       path, unit, own);
    static const char *const measures[4] = {"depth", "pitch", "roll",
                                            "heading"};
    const ts_loop *lp = (const ts_loop *)tg.base;
    int depth = lp->measure == TS_MEASURE_DEPTH;
    int mi = (int)lp->measure;
    char shown[96];
    if (given && given[0])
        snprintf(shown, sizeof shown, "'%.40s' is in %s", given, unit);
    else
        snprintf(shown, sizeof shown, "the value is in %s", unit);
    /* An example in the loop's unit, by key: setpoint, kp, ki, kd. */
    static const char *const keys[4] = {"setpoint", "kp", "ki", "kd"};
    static const char *const example[2][4] = {
        {"'5 deg'", "'0.5'", "'0.1 1/s'", "'0.2 s'"},
        {"'40 m'", "'2 deg/m'", "'0.1 deg/(m*s)'", "'1 deg*s/m'"}};
    int ki = 0;
    for (int k = 0; k < 4; k++)
        if (!strcmp(tg.r->key, keys[k]))
            ki = k;
    char expected[96];
    if (!strcmp(own, "1")) /* an angle per angle */
        snprintf(expected, sizeof expected, "a plain number (rad per rad, "
                 "e.g. %s)", example[depth][ki]);
    else
        snprintf(expected, sizeof expected, "%s (e.g. %s), or a plain "
                 "number in %s", own, example[depth][ki], own);
    return ts_fail(err, TS_EUNIT, "%s: %s, the unit of a loop measuring "
                   "%s, but loop '%s' of vehicle '%s' measures %s: expected "
                   "%s", path, shown, depth ? "an angle" : "depth", lp->name,
                   sys->bodies[tg.body].name,
                   mi >= 0 && mi < 4 ? measures[mi] : "?", expected);
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
    /* A vehicle's controllers are its loops, its surfaces (the word of
     * old) its components. */
    size_t o = 0;
    int loops;
    for (const char *p = dotted; *p && o + 1 < size;) {
        const char *rest = p[0] == '.' ? vehicle_part(p + 1, &loops) : NULL;
        if (rest) {
            o += (size_t)snprintf(out + o, size - o, ".%s.",
                                  loops ? "loops" : "components");
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
    case TSI_KEY_VECTOR:
    case TSI_KEY_INERTIA: *value = ((const double *)at)[tg.vec]; break;
    case TSI_KEY_WEIGHT: *value = *(const double *)at * g; break;
    case TSI_KEY_WET_WEIGHT:
        *value = (*(const double *)at -
                  sys->env.water_density * wet_volume(sys, &tg)) * g;
        break;
    default: *value = *(const double *)at;
    }
    return TS_OK;
}

/* The values of sys's vehicles that the scene reader derives from
 * others (towstab/vehicle.h): the spheroid added-mass estimate (of the
 * first hull when the scene said `spheroid`) in the water density, and a
 * surface diameter not given (the first hull's, or a sphere's of the
 * volume). The same formulas as the reader's, so a value set by path
 * gives the system of the scene with it written in. TS_OK or TS_EINVAL
 * (an estimate that cannot be made: a hull shorter than its diameter). */
static int derive_vehicles(ts_system *sys, ts_err *err)
{
    for (int b = 0; b < sys->nbodies; b++) {
        ts_vehicle *v = sys->bodies[b].type == TS_BODY_VEHICLE
                            ? sys->bodies[b].vehicle
                            : NULL;
        if (!v)
            continue;
        const ts_component *hull = NULL;
        for (int j = 0; j < v->ncomponents && !hull; j++)
            if (v->component[j].type == TS_COMP_HULL)
                hull = &v->component[j];
        if (v->surface_diameter_derived)
            v->surface_diameter = hull ? hull->diameter
                                       : cbrt(6.0 * v->volume / M_PI);
        if (!v->added_mass_estimated)
            continue;
        double L = v->estimate_length, D = v->estimate_diameter;
        const double *centre = v->estimate_centre;
        if (v->estimate_follows_hull && hull) {
            L = hull->length;
            D = hull->diameter;
            centre = hull->position;
        }
        double A[36];
        ts_err local = {0};
        if (ts_added_mass_spheroid(sys->env.water_density, L, D, A, NULL,
                                   &local) != TS_OK)
            return ts_fail(err, TS_EINVAL, "the added mass of vehicle '%s' "
                           "(its spheroid estimate): %s", sys->bodies[b].name,
                           local.msg);
        v->estimate_length = L;
        v->estimate_diameter = D;
        memmove(v->estimate_centre, centre, sizeof v->estimate_centre);
        ts_added_mass_shift(A, v->estimate_centre, v->added_mass);
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
    int ok = isfinite(value) ||
             ((r == surface_limit || r == propulsion_cap) &&
              value == INFINITY);
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
    double old = r->kind == TSI_KEY_LINKS ? 0
                 : r->kind == TSI_KEY_VECTOR || r->kind == TSI_KEY_INERTIA
                     ? ((double *)at)[tg.vec]
                     : *(double *)at;
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
    case TSI_KEY_VECTOR:
    case TSI_KEY_INERTIA: ((double *)at)[tg.vec] = value; break;
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
    /* What the scene reader derives from the value follows it; when that
     * cannot be (a hull shorter than its diameter), the value is put
     * back and so is what was derived from it. */
    if (r->kind != TSI_KEY_LINKS && (rc = derive_vehicles(sys, err))) {
        if (r->kind == TSI_KEY_VECTOR || r->kind == TSI_KEY_INERTIA)
            ((double *)at)[tg.vec] = old;
        else
            *(double *)at = old;
        derive_vehicles(sys, NULL);
        ts_err_prefix(err, "%s: ", path);
        return rc;
    }
    return TS_OK;
}

int ts_param_solved(const ts_system *sys, const char *canon, const char *why,
                    const char *verb, ts_err *err)
{
    if (sys->tow.vehicle < 0)
        return TS_OK;
    const ts_body *b = &sys->bodies[sys->tow.vehicle];
    if (!strcmp(canon, "tow.speed")) {
        ts_propulsion_type t = b->vehicle->propulsion.type;
        const char *key = t == TS_PROP_POWER   ? "power"
                          : t == TS_PROP_SPEED ? "speed"
                                               : "thrust";
        const char *what =
            t == TS_PROP_POWER   ? "its power: the speed is solved at it"
            : t == TS_PROP_SPEED ? "its speed controller's set speed, which "
                                   "the steady speed equals"
                                 : "its thrust: the speed is solved at it";
        return ts_fail(err, TS_EINVAL, "tow.speed: the towing vehicle '%s' "
                       "solves its speed from its propulsion, and tow.speed "
                       "is only the solve's start value (%s); %s "
                       "towing_vehicle.propulsion.%s (%s)", b->name, why,
                       verb, key, what);
    }
    if (!strcmp(canon, "tow.turn_rate") && sys->tow.turn_surface < 0)
        return ts_fail(err, TS_EINVAL, "tow.turn_rate: the towing vehicle "
                       "'%s' solves its turn rate at its control "
                       "deflections, and tow.turn_rate is only the solve's "
                       "start value (%s); give it `turn_by: <rudder>` in the "
                       "scene (the rudder's deflection is then solved at the "
                       "turn rate), or %s "
                       "towing_vehicle.components.<rudder>.deflection",
                       b->name, why, verb);
    return TS_OK;
}
