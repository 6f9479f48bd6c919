/* report.c: JSON (jansson) and CSV output of results (towstab/report.h).
 * Files are written through tsi_outfile (lib/outfile.h): a regular file
 * under a temporary name renamed into place only when complete, so no
 * half-written file survives a failure, and a device or FIFO in place.
 * JSON goes out through lib/jsonout.h; an equilibrium's node and link
 * arrays can be left out of its tree and streamed in their place
 * (lib/report_impl.h), each element's keys listed once for both forms. */
#include "towstab/report.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jsonout.h"
#include "outfile.h"
#include "report_impl.h"
#include "towstab/kernel.h"

/* A JSON number, or null for a value that is not finite. */
static json_t *num(double v) { return isfinite(v) ? json_real(v) : json_null(); }

json_t *ts_report_trust_json(const ts_trust *t)
{
    json_t *o = json_object(), *r = json_array(), *n = json_array();
    if (!o || !r || !n) {
        json_decref(o);
        json_decref(r);
        json_decref(n);
        return NULL;
    }
    for (int i = 0; i < t->nreasons; i++)
        json_array_append_new(r, json_string(t->reasons[i]));
    for (int i = 0; i < t->nnotes; i++)
        json_array_append_new(n, json_string(t->notes[i]));
    json_object_set_new(o, "trustworthy", json_boolean(t->trustworthy));
    json_object_set_new(o, "reasons", r);
    json_object_set_new(o, "notes", n);
    if (t->dropped)
        json_object_set_new(o, "dropped", json_integer(t->dropped));
    return o;
}

/* [x, y, z] of a 3-vector. */
static json_t *vec3(const double v[3])
{
    return json_pack("[o,o,o]", num(v[0]), num(v[1]), num(v[2]));
}

#define DEG (180.0 / M_PI)

json_t *ts_report_vehicle_json(const ts_system *sys,
                               const ts_vehicle_result *r)
{
    const ts_body *bd = &sys->bodies[r->body];
    const ts_vehicle *d = bd->vehicle;
    json_t *comps = json_array(), *loops = json_array();
    json_t *o = json_pack(
        "{s:s,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o,s:o}",
        "name", bd->name, "x", num(r->origin[0]), "y", num(r->origin[1]),
        "depth", num(r->origin[2]), "pitch_deg", num(r->pitch * DEG),
        "roll_deg", num(r->roll * DEG), "yaw_deg", num(r->yaw * DEG),
        "alpha_deg", num(r->alpha * DEG), "beta_deg", num(r->beta * DEG),
        "speed", num(r->speed), "submerged", num(r->submerged),
        "joint_force", vec3(r->joint_force), "hydro_force",
        vec3(r->hydro_force), "hydro_moment", vec3(r->hydro_moment),
        "munk_moment", vec3(r->munk), "mass_centre", vec3(r->mass_centre));
    if (!o || !comps || !loops) {
        json_decref(o);
        json_decref(comps);
        json_decref(loops);
        return NULL;
    }
    for (int c = 0; c < r->ncomponents; c++) {
        const ts_component *cp = &d->component[c];
        const ts_component_load *ld = &r->load[c];
        json_t *e = json_pack(
            "{s:s,s:s,s:o,s:o,s:o,s:o}", "name", cp->name, "type",
            cp->type == TS_COMP_HULL    ? "hull"
            : cp->type == TS_COMP_BLUFF ? "bluff"
            : cp->type == TS_COMP_MAST  ? "mast"
            : cp->type == TS_COMP_BALLAST ? "ballast"
                                        : "surface",
            "force", vec3(ld->force), "moment", vec3(ld->moment), "alpha_deg",
            num(ld->alpha * DEG), "speed", num(ld->speed));
        if (e && cp->type == TS_COMP_BALLAST)
            json_object_set_new(e, "fill_kg", num(r->delta[c]));
        else if (e && cp->control)
            json_object_set_new(e, "deflection_deg", num(r->delta[c] * DEG));
        if (e && cp->type == TS_COMP_MAST)
            json_object_set_new(e, "submerged_length", num(ld->submerged));
        json_array_append_new(comps, e);
    }
    for (int l = 0; l < r->nloops; l++)
        json_array_append_new(
            loops, json_pack("{s:s,s:o,s:o}", "name", d->loop[l].name,
                             "error", num(r->loop_error[l]), "output_deg",
                             num(r->loop_output[l] * DEG)));
    json_object_set_new(o, "components", comps);
    json_object_set_new(o, "controllers", loops);
    if (r->towing) {
        json_object_set_new(o, "towing", json_true());
        json_object_set_new(o, "track_speed", num(r->track_speed));
        json_object_set_new(o, "turn_rate", num(r->turn_rate));
        json_object_set_new(o, "thrust", num(r->thrust));
        json_object_set_new(o, "power", num(r->power));
        json_object_set_new(o, "dof", json_integer(r->dof));
        if (r->dof == 3)
            json_object_set_new(
                o, "hydrostatic_reaction",
                json_pack("{s:o,s:o,s:o}", "force_z", num(r->held[0]),
                          "moment_x", num(r->held[1]), "moment_y",
                          num(r->held[2])));
    }
    return o;
}

int ts_report_trust_into(json_t *o, const ts_trust *t)
{
    json_t *j = ts_report_trust_json(t);
    int bad = !j || json_object_update(o, j) != 0;
    json_decref(j);
    return bad ? TS_ENOMEM : TS_OK;
}

/* One node's or one link's keys, written either into a tree (o) or to
 * a stream (w): the two forms of the document share one list of keys. */
typedef struct sink {
    json_t *o;
    tsi_json *w;
} sink;

static void put_num(sink *s, const char *key, double v)
{
    if (s->w) {
        tsi_json_key(s->w, key);
        tsi_json_num(s->w, v);
    } else {
        json_object_set_new(s->o, key, num(v));
    }
}

static void put_int(sink *s, const char *key, int v)
{
    if (s->w) {
        tsi_json_key(s->w, key);
        tsi_json_int(s->w, v);
    } else {
        json_object_set_new(s->o, key, json_integer(v));
    }
}

static void put_str(sink *s, const char *key, const char *v)
{
    if (s->w) {
        tsi_json_key(s->w, key);
        tsi_json_str(s->w, v);
    } else {
        json_object_set_new(s->o, key, json_string(v));
    }
}

/* nodes[i]: {name, x, y, z}. */
static void node_keys(sink *s, const ts_system *sys, const ts_equilibrium *eq,
                      int i)
{
    char name[2 * TS_NAME_MAX];
    const double *r = eq->positions + 3 * i;
    ts_system_node_name(sys, i, name, sizeof name);
    put_str(s, "name", name);
    put_num(s, "x", r[0]);
    put_num(s, "y", r[1]);
    put_num(s, "z", r[2]);
}

/* links[l]: {cable, index, tension, theta1_deg, theta2_deg} and, for an
 * elastic link, strain. */
static void link_keys(sink *s, const ts_system *sys, const ts_equilibrium *eq,
                      int l)
{
    const ts_link *L = &sys->links[l];
    double t1, t2;
    ts_direction_angles(eq->directions + 3 * l, &t1, &t2);
    put_str(s, "cable", sys->cables[L->cable].name);
    put_int(s, "index", L->index);
    put_num(s, "tension", eq->tensions[l]);
    put_num(s, "theta1_deg", t1 * 180 / M_PI);
    put_num(s, "theta2_deg", t2 * 180 / M_PI);
    if (L->elastic)
        put_num(s, "strain", ts_equilibrium_strain(sys, eq, l));
}

typedef void (*keys_fn)(sink *s, const ts_system *sys,
                        const ts_equilibrium *eq, int i);

/* An array of n objects, each made by keys, into tree a. */
static void fill_array(json_t *a, keys_fn keys, const ts_system *sys,
                       const ts_equilibrium *eq, int n)
{
    for (int i = 0; a && i < n; i++) {
        json_t *o = json_object();
        if (!o)
            return;
        keys(&(sink){o, NULL}, sys, eq, i);
        json_array_append_new(a, o);
    }
}

/* The same array written to a stream, one element at a time. */
static void stream_array(tsi_json *w, keys_fn keys, const ts_system *sys,
                         const ts_equilibrium *eq, int n)
{
    tsi_json_array_open(w);
    for (int i = 0; i < n; i++) {
        tsi_json_object_open(w);
        keys(&(sink){NULL, w}, sys, eq, i);
        tsi_json_object_close(w);
    }
    tsi_json_array_close(w);
}

static void stream_nodes(tsi_json *w, const void *sys, const void *eq)
{
    stream_array(w, node_keys, sys, eq, ((const ts_system *)sys)->nnodes);
}

static void stream_links(tsi_json *w, const void *sys, const void *eq)
{
    stream_array(w, link_keys, sys, eq, ((const ts_system *)sys)->nlinks);
}

json_t *ts_report_equilibrium_json(const ts_system *sys,
                                   const ts_equilibrium *eq, double wall_s,
                                   const ts_trust *trust)
{
    return tsi_report_equilibrium_tree(sys, eq, wall_s, trust, NULL);
}

json_t *tsi_report_equilibrium_tree(const ts_system *sys,
                                    const ts_equilibrium *eq, double wall_s,
                                    const ts_trust *trust,
                                    tsi_json_defer *defer)
{
    json_t *o = json_object();
    json_t *nodes = json_array(), *links = json_array(), *bodies = json_array();
    if (!o || !nodes || !links || !bodies ||
        tsi_json_defer_add(defer, nodes, stream_nodes, sys, eq) != 0 ||
        tsi_json_defer_add(defer, links, stream_links, sys, eq) != 0) {
        json_decref(o);
        json_decref(nodes);
        json_decref(links);
        json_decref(bodies);
        return NULL;
    }
    json_object_set_new(o, "converged", json_boolean(eq->converged));
    json_object_set_new(o, "iterations", json_integer(eq->iterations));
    json_object_set_new(o, "evaluations", json_integer(eq->evaluations));
    json_object_set_new(o, "residual", num(eq->residual));
    json_object_set_new(o, "force_scale", num(eq->force_scale));
    json_object_set_new(o, "tolerance", num(eq->tolerance));
    json_object_set_new(o, "method", json_string(ts_eq_method_name(eq->method)));
    /* With a towing vehicle the steady motion is solved. */
    int towing = sys->tow.vehicle >= 0;
    json_object_set_new(o, "speed", num(towing ? eq->speed : sys->tow.speed));
    json_object_set_new(o, "turn_rate",
                        num(towing ? eq->turn_rate : sys->tow.turn_rate));
    json_object_set_new(o, "wall_s", num(wall_s));
    json_object_set_new(o, "top_tension", num(eq->top_tension));
    json_object_set_new(o, "min_tension", num(eq->min_tension));
    json_object_set_new(o, "tow_force",
                        json_pack("[o,o,o]", num(eq->tow_force[0]),
                                  num(eq->tow_force[1]), num(eq->tow_force[2])));
    /* Streamed, the node and link arrays stay empty here and are written
     * in their place (defer); else they are filled now. */
    if (!defer) {
        fill_array(nodes, node_keys, sys, eq, sys->nnodes);
        fill_array(links, link_keys, sys, eq, sys->nlinks);
    }
    /* Elastic cables: their lengths at rest and stretched. */
    json_t *cables = json_array();
    for (int c = 0; cables && c < sys->ncables; c++)
        if (sys->cables[c].ea > 0)
            json_array_append_new(
                cables, json_pack("{s:s,s:o,s:o}", "name",
                                  sys->cables[c].name, "length",
                                  num(sys->cables[c].length),
                                  "stretched_length",
                                  num(ts_equilibrium_cable_length(sys, eq,
                                                                  c))));
    if (cables && json_array_size(cables) > 0)
        json_object_set_new(o, "elastic_cables", cables);
    else
        json_decref(cables);
    for (int b = 0; b < sys->nbodies; b++) {
        int k = ts_system_body_node(sys, b);
        const double *r = eq->positions + 3 * k;
        json_array_append_new(bodies, json_pack("{s:s,s:o,s:o,s:o}", "name",
                                                sys->bodies[b].name, "x",
                                                num(r[0]), "y", num(r[1]), "z",
                                                num(r[2])));
    }
    json_object_set_new(o, "condition", num(eq->condition));
    json_object_set_new(o, "shape_error", num(eq->shape_error));
    /* What an engineer must not overlook: trustworthy, reasons, notes. */
    json_t *tj = trust ? ts_report_trust_json(trust) : NULL;
    if (tj) {
        json_object_update(o, tj);
        json_decref(tj);
    }
    json_object_set_new(o, "nodes", nodes);
    json_object_set_new(o, "links", links);
    json_object_set_new(o, "bodies", bodies);
    if (eq->nvehicles > 0) {
        json_t *veh = json_array();
        for (int v = 0; veh && v < eq->nvehicles; v++)
            json_array_append_new(veh,
                                  ts_report_vehicle_json(sys, &eq->vehicles[v]));
        json_object_set_new(o, "vehicles", veh);
        json_object_set_new(o, "control_residual", num(eq->control_residual));
    }
    return o;
}

int tsi_report_dump_tree(const json_t *value, const tsi_json_defer *defer,
                         FILE *f, int indent)
{
    tsi_json *w = tsi_json_open(f, indent);
    if (!w) {
        errno = ENOMEM;
        return -1;
    }
    tsi_json_tree(w, value, defer);
    return tsi_json_close(w);
}

int tsi_report_write_tree(const json_t *value, const tsi_json_defer *defer,
                          const char *path, ts_err *err)
{
    tsi_outfile out;
    int rc = tsi_outfile_open(&out, path, err);
    if (rc != TS_OK)
        return rc;
    /* yajl ends an indented document with its newline. */
    if (tsi_report_dump_tree(value, defer, out.f, 1) != 0) {
        int e = errno;
        tsi_outfile_abandon(&out);
        return ts_fail(err, e == ENOMEM ? TS_ENOMEM : TS_EIO,
                       "%s: write failed (%s)", path, strerror(e));
    }
    return tsi_outfile_commit(&out, err);
}

int ts_report_write_json(const json_t *value, const char *path, ts_err *err)
{
    return tsi_report_write_tree(value, NULL, path, err);
}

int ts_report_write_text(const char *text, size_t len, const char *path,
                         ts_err *err)
{
    tsi_outfile out;
    int rc = tsi_outfile_open(&out, path, err);
    if (rc != TS_OK)
        return rc;
    if (len > 0 && fwrite(text, 1, len, out.f) != len) {
        int e = errno;
        tsi_outfile_abandon(&out);
        return ts_fail(err, TS_EIO, "%s: write failed (%s)", path,
                       strerror(e));
    }
    return tsi_outfile_commit(&out, err);
}

int ts_report_check_targets(int n, const char *const what[],
                            const char *const paths[], ts_err *err)
{
    for (int i = 0; i < n; i++) {
        if (!paths[i])
            continue;
        tsi_outfile_id a;
        if (tsi_outfile_identify(paths[i], &a, NULL) != TS_OK || a.kind == 1)
            continue; /* the write reports it; devices may be shared */
        for (int j = i + 1; j < n; j++) {
            tsi_outfile_id b;
            if (!paths[j] ||
                tsi_outfile_identify(paths[j], &b, NULL) != TS_OK ||
                a.kind != b.kind || a.dev != b.dev || a.ino != b.ino ||
                strcmp(a.last, b.last) != 0)
                continue;
            if (a.kind == 2)
                return ts_fail(err, TS_EINVAL,
                               "%s and %s: both write to standard output; "
                               "give one of them another file",
                               what[i], what[j]);
            return ts_fail(err, TS_EINVAL,
                           "%s '%s' and %s '%s' name the same file; give "
                           "each output its own",
                           what[i], paths[i], what[j], paths[j]);
        }
    }
    return TS_OK;
}

int ts_report_equilibrium_csv(const ts_system *sys, const ts_equilibrium *eq,
                              const char *path, ts_err *err)
{
    return ts_report_equilibrium_csv_display(sys, eq, NULL, path, err);
}

int ts_report_equilibrium_csv_display(const ts_system *sys,
                                      const ts_equilibrium *eq,
                                      const ts_display *d, const char *path,
                                      ts_err *err)
{
    d = ts_display_or_si(d);
    char name[2 * TS_NAME_MAX], lu[TS_DISPLAY_UNIT_MAX * 2],
        fu[TS_DISPLAY_UNIT_MAX * 2];
    ts_display_unit_token(ts_display_unit(d, TS_QTY_LENGTH), lu, sizeof lu);
    ts_display_unit_token(ts_display_unit(d, TS_QTY_FORCE), fu, sizeof fu);
    tsi_outfile out;
    int rc = tsi_outfile_open(&out, path, err);
    if (rc != TS_OK)
        return rc;
    FILE *f = out.f;
    fprintf(f, "node,x_%s,y_%s,z_%s,tension_above_%s\n", lu, lu, lu, fu);
    for (int i = 0; i < sys->nnodes; i++) {
        const double *r = eq->positions + 3 * i;
        ts_system_node_name(sys, i, name, sizeof name);
        fprintf(f, "%s", name);
        for (int c = 0; c < 3; c++)
            fprintf(f, ",%.17g", ts_display_value(d, TS_QTY_LENGTH, r[c]));
        fprintf(f, ",%.17g\n",
                ts_display_value(d, TS_QTY_FORCE,
                                 i == 0 ? eq->top_tension
                                        : eq->tensions[i - 1]));
    }
    return tsi_outfile_commit(&out, err);
}
