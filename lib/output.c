/* output.c: output channels by name (towstab/output.h).
 *
 * A name is split at its last '.': the suffix says the kind (x, y, z,
 * tension, strain, length, force), the base the node, link or cable.
 * Links are looked up by cable and index (O(nlinks), once per name);
 * values are read from the arrays the kernel fills for one state. A
 * strain is |r_lower - r_upper| / l - 1 from the node positions, which
 * keeps ~1e-15 m / |d| of absolute accuracy: 8 digits of the ~1e-7
 * strain of a 1e9 N cable.
 */
#include "towstab/output.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Link with index k (1-based) of cable c, or -1. */
static int cable_link(const ts_system *sys, int c, int k)
{
    for (int l = 0; l < sys->nlinks; l++)
        if (sys->links[l].cable == c && sys->links[l].index == k)
            return l;
    return -1;
}

/* Appending to a buffer that may fill up: it is cut, never overrun. */
typedef struct text {
    char *buf;
    size_t size, len;
} text;

static void append(text *t, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void append(text *t, const char *fmt, ...)
{
    if (t->len >= t->size)
        return;
    va_list ap;
    va_start(ap, fmt);
    int w = vsnprintf(t->buf + t->len, t->size - t->len, fmt, ap);
    va_end(ap);
    if (w > 0)
        t->len += (size_t)w;
}

/* A cable's first link starts at a point of a vehicle (its upper end is
 * not a node). */
static int starts_at_vehicle(const ts_system *sys, int c)
{
    for (int l = 0; l < sys->nlinks; l++)
        if (sys->links[l].cable == c && sys->links[l].index == 1)
            return sys->links[l].up_body >= 0;
    return 0;
}

/* "<cable>.1<suffix> .. <cable>.N<suffix>" of every cable (elastic ones
 * only when `elastic`). */
static void list_links(text *t, const ts_system *sys, const char *suffix,
                       int elastic)
{
    int first = 1;
    for (int c = 0; c < sys->ncables; c++) {
        const ts_cable *cb = &sys->cables[c];
        if (elastic && (!(cb->ea > 0) || starts_at_vehicle(sys, c)))
            continue;
        append(t, "%s", first ? "" : ", ");
        first = 0;
        if (cb->nlinks == 1)
            append(t, "%s.1%s", cb->name, suffix);
        else
            append(t, "%s.1%s .. %s.%d%s", cb->name, suffix, cb->name,
                   cb->nlinks, suffix);
    }
}

void ts_output_names(const ts_system *sys, int kinds, char *buf, size_t size)
{
    text t = {buf, size, 0};
    if (size == 0)
        return;
    buf[0] = '\0';
    const char *sep = "";
    if (kinds & TS_OUT_BIT(TS_OUT_POSITION)) {
        append(&t, "positions <node>.x|y|z with <node> one of ");
        for (int c = 0; c < sys->ncables; c++) {
            const ts_cable *cb = &sys->cables[c];
            int last = cb->nlinks - (cb->to_body >= 0 ? 1 : 0);
            if (c)
                append(&t, "; ");
            if (last == 1)
                append(&t, "%s.1", cb->name);
            else if (last > 1)
                append(&t, "%s.1 .. %s.%d", cb->name, cb->name, last);
            if (cb->to_body >= 0)
                append(&t, "%s%s", last > 0 ? ", " : "",
                       sys->bodies[cb->to_body].name);
        }
        sep = "; ";
    }
    if (kinds & TS_OUT_BIT(TS_OUT_TENSION)) {
        append(&t, "%stensions ", sep);
        list_links(&t, sys, ".tension", 0);
        sep = "; ";
    }
    if (kinds & TS_OUT_BIT(TS_OUT_TOW_FORCE)) {
        append(&t, "%sthe force on the tow point tow.force (its size) or "
                   "tow.force.x|y|z", sep);
        sep = "; ";
    }
    int elastic = 0;
    for (int c = 0; c < sys->ncables; c++)
        elastic |= sys->cables[c].ea > 0 && !starts_at_vehicle(sys, c);
    if (elastic && (kinds & TS_OUT_BIT(TS_OUT_STRAIN))) {
        append(&t, "%sstrains ", sep);
        list_links(&t, sys, ".strain", 1);
        sep = "; ";
    }
    if (elastic && (kinds & TS_OUT_BIT(TS_OUT_LENGTH))) {
        append(&t, "%sstretched lengths ", sep);
        int first = 1;
        for (int c = 0; c < sys->ncables; c++)
            if (sys->cables[c].ea > 0 && !starts_at_vehicle(sys, c)) {
                append(&t, "%s%s.length", first ? "" : ", ",
                       sys->cables[c].name);
                first = 0;
            }
        sep = "; ";
    }
    if (kinds & TS_OUT_BIT(TS_OUT_EARTH))
        append(&t, "%searth-frame positions <node>.earth_x|earth_y (the "
                   "nodes above) and tow.earth_x|earth_y", sep);
}

static int bad_output(const ts_system *sys, int kinds, const char *name,
                      const char *why, ts_err *err)
{
    char list[1024];
    ts_output_names(sys, kinds, list, sizeof list);
    return ts_fail(err, TS_EINVAL, "output '%s': %s; valid outputs: %s",
                   name, why, list);
}

/* The tow force: "tow.force" or "tow.force.x|y|z". */
static int find_tow_force(const char *name, ts_output *out)
{
    static const char *const names[4] = {"tow.force.x", "tow.force.y",
                                         "tow.force.z", "tow.force"};
    for (int c = 0; c < 4; c++)
        if (strcmp(name, names[c]) == 0) {
            out->kind = TS_OUT_TOW_FORCE;
            out->comp = c;
            out->unit = "N/m";
            out->si_unit = "N";
            snprintf(out->name, sizeof out->name, "%s", names[c]);
            return 1;
        }
    return 0;
}

/* The link that `base` names: a body (the link ending at it) or
 * "<cable>.<k>"; -1 when none. */
static int find_link(const ts_system *sys, const char *base)
{
    int b = ts_system_find_body(sys, base);
    if (b >= 0) {
        int node = ts_system_body_node(sys, b);
        return node > 0 ? sys->nodes[node].link : -1;
    }
    const char *d2 = strrchr(base, '.');
    if (!d2 || d2 == base)
        return -1;
    char cname[TS_OUTPUT_NAME_MAX];
    memcpy(cname, base, (size_t)(d2 - base));
    cname[d2 - base] = '\0';
    char *end;
    long k = strtol(d2 + 1, &end, 10);
    int c = ts_system_find_cable(sys, cname);
    if (c >= 0 && end != d2 + 1 && *end == '\0' && k >= 1 &&
        k <= sys->cables[c].nlinks)
        return cable_link(sys, c, (int)k);
    return -1;
}

/* The channel `name` of any kind; `kinds` only for the list of valid
 * names in a message. */
static int find(const ts_system *sys, const char *name, int kinds,
                ts_output *out, ts_err *err)
{
    memset(out, 0, sizeof *out);
    if (find_tow_force(name, out))
        return TS_OK;
    const char *dot = strrchr(name, '.');
    if (!dot || dot == name || strlen(name) >= TS_OUTPUT_NAME_MAX - 8)
        return bad_output(sys, kinds, name, "expected <node>.<x|y|z>, "
                          "<cable>.<k>.tension or tow.force", err);
    char base[TS_OUTPUT_NAME_MAX];
    size_t nb = (size_t)(dot - name);
    memcpy(base, name, nb);
    base[nb] = '\0';
    const char *suffix = dot + 1;
    if (strcmp(suffix, "length") == 0) {
        int c = ts_system_find_cable(sys, base);
        if (c < 0)
            return bad_output(sys, kinds, name, "no such cable", err);
        if (!(sys->cables[c].ea > 0))
            return bad_output(sys, kinds, name, "the cable is rigid: its "
                              "length does not change (give it an axial "
                              "stiffness ea for the elastic model)", err);
        if (starts_at_vehicle(sys, c))
            return bad_output(sys, kinds, name, "the cable starts at a "
                              "point of a vehicle, not at a node", err);
        out->kind = TS_OUT_LENGTH;
        out->cable = c;
        out->unit = "m/m";
        out->si_unit = "m";
        snprintf(out->name, sizeof out->name, "%s.length",
                 sys->cables[c].name);
        return TS_OK;
    }
    int comp = -1;
    ts_output_kind kind = TS_OUT_POSITION;
    if (strcmp(suffix, "earth_x") == 0 || strcmp(suffix, "earth_y") == 0) {
        kind = TS_OUT_EARTH;
        comp = suffix[6] == 'x' ? 0 : 1;
        if (strcmp(base, "tow") == 0) {
            out->kind = kind;
            out->node = 0;
            out->comp = comp;
            out->unit = "m/m";
            out->si_unit = "m";
            snprintf(out->name, sizeof out->name, "tow.%s", suffix);
            return TS_OK;
        }
    } else if (strcmp(suffix, "x") == 0)
        comp = 0;
    else if (strcmp(suffix, "y") == 0)
        comp = 1;
    else if (strcmp(suffix, "z") == 0)
        comp = 2;
    else if (strcmp(suffix, "tension") == 0)
        kind = TS_OUT_TENSION;
    else if (strcmp(suffix, "strain") == 0)
        kind = TS_OUT_STRAIN;
    else
        return bad_output(sys, kinds, name, "the part after the last '.' "
                          "must be x, y, z, tension, strain, length, "
                          "earth_x or earth_y", err);
    if (strcmp(base, "tow") == 0)
        return bad_output(sys, kinds, name, "tow is the input (tow.surge, "
                          "tow.sway, tow.heave), not an output; the force "
                          "on the tow point is tow.force", err);
    int link = find_link(sys, base);
    if (link < 0)
        return bad_output(sys, kinds, name, "no such node, body or link",
                          err);
    const ts_link *L = &sys->links[link];
    const char *cname = sys->cables[L->cable].name;
    if (kind == TS_OUT_STRAIN && !L->elastic)
        return bad_output(sys, kinds, name, "the link is rigid: it does not "
                          "stretch (give its cable an axial stiffness ea "
                          "for the elastic model)", err);
    if (kind == TS_OUT_STRAIN && L->up_body >= 0)
        return bad_output(sys, kinds, name, "the link starts at a point of "
                          "a vehicle, not at a node", err);
    switch (kind) {
    case TS_OUT_TENSION:
    case TS_OUT_STRAIN: {
        int t = kind == TS_OUT_TENSION;
        out->kind = kind;
        out->link = link;
        out->unit = t ? "N/m" : "1/m";
        out->si_unit = t ? "N" : "1";
        snprintf(out->name, sizeof out->name, "%s.%d.%s", cname, L->index,
                 t ? "tension" : "strain");
        break;
    }
    default: {
        out->kind = kind;
        out->node = L->lower;
        out->comp = comp;
        out->unit = "m/m";
        out->si_unit = "m";
        char nm[2 * TS_NAME_MAX];
        ts_system_node_name(sys, out->node, nm, sizeof nm);
        if (kind == TS_OUT_EARTH)
            snprintf(out->name, sizeof out->name, "%s.%s", nm, suffix);
        else
            snprintf(out->name, sizeof out->name, "%s.%c", nm,
                     "xyz"[comp]);
    }
    }
    return TS_OK;
}

int ts_output_find(const ts_system *sys, const char *name, int kinds,
                   ts_output *out, ts_err *err)
{
    int rc = find(sys, name, kinds, out, err);
    if (rc != TS_OK || (kinds & TS_OUT_BIT(out->kind)))
        return rc;
    static const char *const what[TS_OUT_EARTH + 1] = {
        "a position", "a tension", "the force on the tow point", "a strain",
        "a stretched length", "a vehicle's output",
        "an earth-frame position (a simulation's)"};
    char why[160];
    snprintf(why, sizeof why, "%s is not an output of this analysis",
             what[out->kind]);
    return bad_output(sys, kinds, name, why, err);
}

int ts_output_is_force(const ts_output *out)
{
    return out->kind == TS_OUT_TENSION || out->kind == TS_OUT_TOW_FORCE;
}

/* Length of link l from the node positions (its upper end a node). */
static double link_length(const ts_system *sys, const double pos[], int l)
{
    const double *a = pos + 3 * (size_t)sys->links[l].upper;
    const double *b = pos + 3 * (size_t)sys->links[l].lower;
    double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

double ts_output_value(const ts_system *sys, const ts_output *out,
                       const double pos[], const double tens[],
                       const double tow_force[])
{
    switch (out->kind) {
    case TS_OUT_VEHICLE: /* needs a kernel (ts_kernel_outputs) */
    case TS_OUT_EARTH:   /* needs the frame's track (ts_history_value) */
        return NAN;
    case TS_OUT_POSITION:
        return pos ? pos[3 * (size_t)out->node + (size_t)out->comp] : NAN;
    case TS_OUT_TENSION: return tens ? tens[out->link] : NAN;
    case TS_OUT_TOW_FORCE:
        if (!tow_force)
            return NAN;
        if (out->comp < 3)
            return tow_force[out->comp];
        return sqrt(tow_force[0] * tow_force[0] +
                    tow_force[1] * tow_force[1] +
                    tow_force[2] * tow_force[2]);
    case TS_OUT_STRAIN:
        return pos && sys ? link_length(sys, pos, out->link) /
                             sys->links[out->link].length -
                         1.0
                   : NAN;
    case TS_OUT_LENGTH: {
        if (!pos || !sys)
            return NAN;
        double len = 0;
        for (int l = 0; l < sys->nlinks; l++)
            if (sys->links[l].cable == out->cable)
                len += link_length(sys, pos, l);
        return len;
    }
    }
    return NAN;
}
