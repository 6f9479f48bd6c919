/* system.c: validation of a towed system and its discretisation into a tree
 * of rigid links and lumped nodes (doc/model.md section 2).
 *
 * Cables are ordered breadth-first from the tow point, so every link comes
 * after the link above it: a forward loop over links runs from the tow
 * point to the free ends and a backward loop from the free ends up. Node 0
 * is the tow point and node k+1 the lower end of link k. Each link's mass is
 * split half to each end; a body's mass is added to the node it ends on.
 */
#include "towstab/system.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

ts_system *ts_system_alloc(int ncables, int nbodies, ts_err *err)
{
    if (ncables < 0 || nbodies < 0) {
        ts_fail(err, TS_EINVAL, "ts_system_alloc: " "negative counts %d, %d",
                ncables, nbodies);
        return NULL;
    }
    ts_system *s = calloc(1, sizeof *s);
    if (!s)
        goto nomem;
    s->ncables = ncables;
    s->nbodies = nbodies;
    s->cables = calloc(ncables > 0 ? ncables : 1, sizeof *s->cables);
    s->bodies = calloc(nbodies > 0 ? nbodies : 1, sizeof *s->bodies);
    if (!s->cables || !s->bodies)
        goto nomem;
    for (int i = 0; i < ncables; i++) {
        s->cables[i].from_body = -1;
        s->cables[i].to_body = -1;
    }
    s->env.water_density = 1025.0;
    s->env.gravity = 9.80665;
    s->tow.vehicle = -1;
    s->tow.turn_surface = -1;
    s->tow.dof = 6;
    return s;
nomem:
    ts_system_free(s);
    ts_fail(err, TS_ENOMEM, "ts_system_alloc: " "out of memory");
    return NULL;
}

static void free_discretisation(ts_system *s)
{
    free(s->links);
    free(s->nodes);
    free(s->child_links);
    s->links = NULL;
    s->nodes = NULL;
    s->child_links = NULL;
    s->nlinks = 0;
    s->nnodes = 0;
}

void ts_system_free(ts_system *s)
{
    if (!s)
        return;
    free_discretisation(s);
    if (s->cables)
        for (int i = 0; i < s->ncables; i++)
            free(s->cables[i].link_fraction);
    if (s->bodies)
        for (int b = 0; b < s->nbodies; b++)
            free(s->bodies[b].vehicle);
    free(s->cables);
    free(s->bodies);
    free(s);
}

ts_vehicle *ts_body_set_vehicle(ts_system *s, int b, ts_err *err)
{
    if (b < 0 || b >= s->nbodies) {
        ts_fail(err, TS_EINVAL, "ts_body_set_vehicle: no body %d", b);
        return NULL;
    }
    ts_vehicle *v = calloc(1, sizeof *v);
    if (!v) {
        ts_fail(err, TS_ENOMEM, "ts_body_set_vehicle: out of memory");
        return NULL;
    }
    free(s->bodies[b].vehicle);
    s->bodies[b].vehicle = v;
    s->bodies[b].type = TS_BODY_VEHICLE;
    return v;
}

ts_system *ts_system_copy(const ts_system *src, ts_err *err)
{
    ts_system *s = ts_system_alloc(src->ncables, src->nbodies, err);
    if (!s)
        return NULL;
    memcpy(s->name, src->name, sizeof s->name);
    s->env = src->env;
    s->tow = src->tow;
    memcpy(s->bodies, src->bodies, (size_t)src->nbodies * sizeof *s->bodies);
    for (int b = 0; b < src->nbodies; b++) {
        s->bodies[b].vehicle = NULL;
        if (!src->bodies[b].vehicle)
            continue;
        s->bodies[b].vehicle = malloc(sizeof(ts_vehicle));
        if (!s->bodies[b].vehicle) {
            ts_system_free(s);
            ts_fail(err, TS_ENOMEM, "ts_system_copy: " "out of memory");
            return NULL;
        }
        memcpy(s->bodies[b].vehicle, src->bodies[b].vehicle,
               sizeof(ts_vehicle));
    }
    for (int i = 0; i < src->ncables; i++) {
        s->cables[i] = src->cables[i];
        s->cables[i].link_fraction = NULL;
        if (src->cables[i].link_fraction) {
            size_t n = (size_t)src->cables[i].nlinks;
            s->cables[i].link_fraction = malloc(n * sizeof(double));
            if (!s->cables[i].link_fraction) {
                ts_system_free(s);
                ts_fail(err, TS_ENOMEM, "ts_system_copy: " "out of memory");
                return NULL;
            }
            memcpy(s->cables[i].link_fraction, src->cables[i].link_fraction,
                   n * sizeof(double));
        }
    }
    if (src->links && ts_system_build(s, err) != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

int ts_system_find_cable(const ts_system *s, const char *name)
{
    for (int i = 0; i < s->ncables; i++)
        if (strcmp(s->cables[i].name, name) == 0)
            return i;
    return -1;
}

int ts_system_find_body(const ts_system *s, const char *name)
{
    for (int i = 0; i < s->nbodies; i++)
        if (strcmp(s->bodies[i].name, name) == 0)
            return i;
    return -1;
}

int ts_system_set_links(ts_system *sys, int links, ts_err *err)
{
    if (links < 1 || links > TS_MAX_LINKS)
        return ts_fail(err, TS_EINVAL,
                       "links: expected 1 to %d per cable, got %d",
                       TS_MAX_LINKS, links);
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].link_fraction)
            return ts_fail(err, TS_EINVAL,
                           "links: cables[%d] '%s' has link_lengths; remove "
                           "them to set the number of links",
                           c, sys->cables[c].name);
    for (int c = 0; c < sys->ncables; c++)
        sys->cables[c].nlinks = links;
    return ts_system_build(sys, err);
}

int ts_system_can_coarsen(const ts_system *sys)
{
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].nlinks < 2)
            return 0;
    return sys->ncables > 0;
}

/* Cable c of s with its links merged in pairs (coarser) or split in two
 * (finer). */
static int relink(ts_cable *c, int coarser, double *ratio, ts_err *err)
{
    int n = c->nlinks;
    int m = coarser ? (n + 1) / 2 : 2 * n;
    if (m > TS_MAX_LINKS)
        return ts_fail(err, TS_EINVAL, "links: cable '%s' would need %d "
                       "links (at most %d) for the error estimate",
                       c->name, m, TS_MAX_LINKS);
    if (c->link_fraction) {
        double *f = malloc((size_t)m * sizeof *f);
        if (!f)
            return ts_fail(err, TS_ENOMEM, "links: out of memory");
        for (int i = 0; i < m; i++) {
            if (coarser)
                f[i] = c->link_fraction[2 * i] +
                       (2 * i + 1 < n ? c->link_fraction[2 * i + 1] : 0.0);
            else
                f[i] = 0.5 * c->link_fraction[i / 2];
        }
        free(c->link_fraction);
        c->link_fraction = f;
    }
    c->nlinks = m;
    double r = (double)n / m;
    if (coarser && r < *ratio)
        *ratio = r;
    return TS_OK;
}

ts_system *ts_system_level(const ts_system *sys, int coarser,
                           double *ratio, ts_err *err)
{
    ts_system *s = ts_system_copy(sys, err);
    if (!s)
        return NULL;
    coarser = coarser && ts_system_can_coarsen(sys);
    *ratio = coarser ? INFINITY : 0.5;
    int rc = TS_OK;
    for (int c = 0; rc == TS_OK && c < s->ncables; c++)
        rc = relink(&s->cables[c], coarser, ratio, err);
    if (rc == TS_OK)
        rc = ts_system_build(s, err);
    if (rc != TS_OK) {
        ts_system_free(s);
        return NULL;
    }
    return s;
}

void ts_system_node_name(const ts_system *sys, int node, char *buf,
                         size_t size)
{
    if (node == 0) {
        snprintf(buf, size, "tow");
        return;
    }
    const ts_node *nd = &sys->nodes[node];
    if (nd->body >= 0) {
        snprintf(buf, size, "%s", sys->bodies[nd->body].name);
        return;
    }
    const ts_link *L = &sys->links[nd->link];
    snprintf(buf, size, "%s.%d", sys->cables[L->cable].name, L->index);
}

int ts_system_body_node(const ts_system *s, int b)
{
    if (!s->nodes || b < 0 || b >= s->nbodies)
        return -1;
    if (b == s->tow.vehicle)
        return 0;
    for (int k = 1; k < s->nnodes; k++)
        if (s->nodes[k].body == b)
            return k;
    return -1;
}

double ts_body_volume(const ts_body *b)
{
    double D = b->diameter;
    switch (b->type) {
    case TS_BODY_SPHERE: return M_PI * D * D * D / 6.0;
    case TS_BODY_CYLINDER: return M_PI * 0.25 * D * D * b->length;
    case TS_BODY_VEHICLE: return b->vehicle ? b->vehicle->volume : 0.0;
    default: return 0.0;
    }
}

double ts_cable_wet_weight(const ts_system *s, int c)
{
    const ts_cable *cb = &s->cables[c];
    double area = M_PI * cb->diameter * cb->diameter / 4.0;
    return (cb->mass_per_length - s->env.water_density * area) * s->env.gravity;
}

void ts_motion_bound_steady(const ts_system *sys, ts_motion_bound *m)
{
    m->speed = fabs(sys->tow.speed);
    m->turn_rate = fabs(sys->tow.turn_rate);
    m->tow_speed = 0.0;
    m->tow_accel = 0.0;
    m->rot_rate = 0.0;
    m->rot_accel = 0.0;
}

/* The load sizes of one part (a link or a body) under the bounds: mass in
 * air and displaced mass (kg), drag area times coefficient (m^2) and added
 * mass (kg). */
typedef struct part_load {
    double mass, displaced, drag_area, added;
} part_load;

/* Which load of which part is the largest, and what it is. */
typedef struct load_worst {
    double size;      /* N; NaN sorts first */
    int kind;         /* 0 weight, 1 buoyancy, 2 drag, 3 inertia */
    int link, body;   /* the part: a link index or a body index, -1 */
} load_worst;

static void consider(load_worst *w, double size, int kind, int link,
                     int body)
{
    if (!(size <= w->size) && !(isnan(w->size))) {
        w->size = size;
        w->kind = kind;
        w->link = link;
        w->body = body;
    }
}

/* Consider the loads of part p; returns their sum. */
static double part_loads(load_worst *w, const part_load *p, double g,
                         double rho, double flow, double acc, int link,
                         int body)
{
    double f[4] = {p->mass * g, rho * p->displaced * g,
                   0.5 * rho * flow * flow * p->drag_area,
                   (p->mass + p->added) * acc};
    for (int i = 0; i < 4; i++)
        consider(w, f[i], i, link, body);
    return f[0] + f[1] + f[2] + f[3];
}

/* The part's own input behind its worst load w (a drag, an inertia or a
 * buoyancy that overflows under moderate motion): a mass, drag
 * coefficients, or a size, named by its scene key. */
static void part_cause(const ts_system *sys, const load_worst *w, char *buf,
                       size_t size)
{
    if (w->link >= 0) {
        const ts_link *L = &sys->links[w->link];
        int c = L->cable;
        const char *nm = sys->cables[c].name;
        double added = sys->env.water_density * L->can * M_PI * 0.25 *
                       L->diameter * L->diameter * L->length;
        if (w->kind == 3 && L->mass >= added)
            snprintf(buf, size, "a link mass of %.3g kg (cables[%d] '%s' "
                     "mass_per_length %.3g kg/m)", L->mass, c, nm,
                     sys->cables[c].mass_per_length);
        else if (w->kind == 2 && !(L->cdn + M_PI * L->cdt <= 1e3))
            snprintf(buf, size, "drag coefficients %.3g (normal) and %.3g "
                     "(tangential) of cables[%d] '%s'", L->cdn, L->cdt, c,
                     nm);
        else if (L->length > L->diameter)
            snprintf(buf, size, "length %.3g m of cables[%d] '%s' (links "
                     "of %.3g m)", sys->cables[c].length, c, nm, L->length);
        else
            snprintf(buf, size, "diameter %.3g m of cables[%d] '%s'",
                     L->diameter, c, nm);
        return;
    }
    const ts_body *B = &sys->bodies[w->body];
    double added = sys->env.water_density * fmax(B->ca, B->ca_cross) *
                   ts_body_volume(B);
    int cyl = B->type == TS_BODY_CYLINDER;
    if (w->kind == 3 && B->mass >= added)
        snprintf(buf, size, "a body mass of %.3g kg (bodies[%d] '%s')",
                 B->mass, w->body, B->name);
    else if (w->kind == 2 && !(B->cd + B->cd_cross <= 1e3))
        snprintf(buf, size, "drag coefficients %.3g and %.3g of bodies[%d] "
                 "'%s'", B->cd, B->cd_cross, w->body, B->name);
    else if (B->type == TS_BODY_VEHICLE)
        snprintf(buf, size, "the size of the vehicle bodies[%d] '%s' (its "
                 "volume %.3g m^3)", w->body, B->name, ts_body_volume(B));
    else if (cyl && B->length > B->diameter)
        snprintf(buf, size, "length %.3g m of bodies[%d] '%s' (diameter "
                 "%.3g m)", B->length, w->body, B->name, B->diameter);
    else
        snprintf(buf, size, "diameter %.3g m of bodies[%d] '%s'",
                 B->diameter, w->body, B->name);
}

double ts_system_reach(const ts_system *sys)
{
    const double *p = sys->tow.point;
    double R = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < sys->ncables; k++)
        R += sys->cables[k].length;
    return R;
}

int ts_system_check_loads(const ts_system *sys, const ts_motion_bound *m,
                          ts_err *err)
{
    const double rho = sys->env.water_density, g = fabs(sys->env.gravity);
    const double *c = sys->env.current;
    double R = ts_system_reach(sys);
    double current = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    /* The flow speed bound and what makes it up, largest named. */
    /* A tow rotation moves a point at R by its rate times R. */
    const double tow_speed = m->tow_speed + m->rot_rate * R;
    const double tow_accel = m->tow_accel + m->rot_accel * R;
    const double flow_part[4] = {m->speed, m->turn_rate * R, current,
                                 tow_speed};
    double flow = flow_part[0] + flow_part[1] + flow_part[2] + flow_part[3];
    double acc = m->turn_rate * m->turn_rate * R + m->turn_rate * m->speed +
                 tow_accel;
    load_worst w = {0.0, 0, -1, -1};
    double total = 0.0; /* bounds every tension */
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        double vol = M_PI * 0.25 * L->diameter * L->diameter * L->length;
        part_load pl = {L->mass, vol,
                        L->diameter * L->length *
                            (L->cdn + M_PI * L->cdt),
                        rho * L->can * vol};
        total += part_loads(&w, &pl, g, rho, flow, acc, l, -1);
    }
    for (int b = 0; b < sys->nbodies; b++) {
        const ts_body *B = &sys->bodies[b];
        double vol = ts_body_volume(B), D = B->diameter;
        part_load pl = {B->mass, vol,
                        B->cd * M_PI * 0.25 * D * D +
                            (B->type == TS_BODY_CYLINDER
                                 ? B->cd_cross * D * B->length
                                 : 0.0),
                        rho * fmax(B->ca, B->ca_cross) * vol};
        total += part_loads(&w, &pl, g, rho, flow, acc, -1, b);
    }
    if (w.size <= TS_LOAD_MAX) {
        /* Strains T / EA of elastic links under the largest tension: a
         * stiffness near zero makes them overflow. */
        for (int c = 0; c < sys->ncables; c++) {
            const ts_cable *C = &sys->cables[c];
            double strain = total / C->ea;
            if (C->ea > 0 && !(strain <= TS_LOAD_MAX))
                return ts_fail(err, TS_EDOMAIN, "forces overflow at EA "
                               "%.3g N of cables[%d] '%s': a tension of up "
                               "to %.3g N would stretch its links without "
                               "bound (strains beyond %.3g)", C->ea, c,
                               C->name, total, TS_LOAD_MAX);
        }
        return TS_OK;
    }
    /* The input to blame: the largest factor of the worst load. A drag or
     * an inertia whose motion factor is moderate is the part's own (a drag
     * coefficient, a size, a mass); a buoyancy is the part's size. */
    char cause[2 * TS_NAME_MAX + 160];
    double q = 0.5 * rho * flow * flow;
    if ((w.kind == 2 && q <= 1e100) || (w.kind == 3 && acc <= 1e100) ||
        (w.kind == 1 && rho <= 1e100 && g <= 1e100))
        part_cause(sys, &w, cause, sizeof cause);
    else if (w.kind == 2 || w.kind == 3) {
        static const char *const what[4] = {"speed %.3g m/s",
                                            "turn rate %.3g rad/s",
                                            "current %.3g m/s",
                                            "tow-point velocity %.3g m/s"};
        int big = 0;
        double val[4] = {m->speed, m->turn_rate, current, tow_speed};
        for (int i = 1; i < 4; i++)
            if (!(flow_part[i] <= flow_part[big]))
                big = i;
        if (w.kind == 3 && !(tow_accel <= acc - tow_accel))
            snprintf(cause, sizeof cause, "tow-point acceleration %.3g "
                     "m/s^2", tow_accel);
        else
            snprintf(cause, sizeof cause, what[big], val[big]);
    } else if (w.kind == 1 && !(rho <= 1e100))
        snprintf(cause, sizeof cause, "water density %.3g kg/m^3", rho);
    else if (!(g <= 1e100))
        snprintf(cause, sizeof cause, "gravity %.3g m/s^2", g);
    else if (w.link >= 0) {
        /* A weight: the cable's mass per length (a weight given in the
         * scene is converted to it). */
        int k = sys->links[w.link].cable;
        snprintf(cause, sizeof cause, "a mass of %.3g kg/m (a weight in air "
                 "of %.3g N/m) of cables[%d] '%s'",
                 sys->cables[k].mass_per_length,
                 sys->cables[k].mass_per_length * g, k, sys->cables[k].name);
    } else
        snprintf(cause, sizeof cause, "a mass of %.3g kg of bodies[%d] '%s'",
                 sys->bodies[w.body].mass, w.body, sys->bodies[w.body].name);
    static const char *const load[4] = {"weight", "buoyancy", "drag",
                                        "inertia"};
    char part[2 * TS_NAME_MAX + 64];
    if (w.link >= 0)
        snprintf(part, sizeof part, "cables[%d] '%s' link %d",
                 sys->links[w.link].cable,
                 sys->cables[sys->links[w.link].cable].name,
                 sys->links[w.link].index);
    else
        snprintf(part, sizeof part, "bodies[%d] '%s'", w.body,
                 sys->bodies[w.body].name);
    char size[48];
    if (isfinite(w.size))
        snprintf(size, sizeof size, "is about %.3g N", w.size);
    else
        snprintf(size, sizeof size, "is not a finite number");
    return ts_fail(err, TS_EDOMAIN, "forces overflow at %s: the %s on %s "
                   "%s, beyond the %.3g N the solvers can take", cause,
                   load[w.kind], part, size, TS_LOAD_MAX);
}

/* " (line N)" for messages about a scene entry, "" when built in code;
 * written into a buffer that lives for the enclosing statement. */
#define at_line(line) line_text((line), (char[32]){0})
static const char *line_text(int line, char *buf)
{
    if (line > 0)
        snprintf(buf, 32, " (line %d)", line);
    return buf;
}

/* A finite number >= lo (or > lo when strict). */
static int check_min(ts_err *err, const char *kind, int i, int line,
                     const char *key, double v, double lo, int strict,
                     const char *unit)
{
    int ok = isfinite(v) && (strict ? v > lo : v >= lo);
    if (!ok)
        return ts_fail(err, TS_EINVAL, "%s[%d].%s%s: " "must be %s %g %s, got %g",
                       kind, i, key, at_line(line), strict ? ">" : ">=", lo,
                       unit, v);
    return TS_OK;
}

static int validate(const ts_system *s, ts_err *err)
{
    const ts_environment *e = &s->env;
    if (!(isfinite(e->water_density) && e->water_density >= 0))
        return ts_fail(err, TS_EINVAL, "environment.water_density: "
                       "must be >= 0 kg/m^3, got %g", e->water_density);
    if (!(isfinite(e->gravity) && e->gravity >= 0))
        return ts_fail(err, TS_EINVAL, "environment.gravity: "
                       "must be >= 0 m/s^2, got %g", e->gravity);
    for (int j = 0; j < 3; j++)
        if (!isfinite(e->current[j]))
            return ts_fail(err, TS_EINVAL, "environment.current: "
                           "component %d must be finite", j);
    if (!isfinite(s->tow.speed))
        return ts_fail(err, TS_EINVAL, "tow.speed: " "must be finite");
    if (!isfinite(s->tow.turn_rate))
        return ts_fail(err, TS_EINVAL, "tow.turn_rate: " "must be finite");
    for (int j = 0; j < 3; j++)
        if (!isfinite(s->tow.point[j]))
            return ts_fail(err, TS_EINVAL, "tow.point: "
                           "component %d must be finite", j);
    /* (A towing vehicle alone is a system: the free vehicle of
     * towstab/towing.h.) */
    if (s->ncables < 1 && s->tow.vehicle < 0)
        return ts_fail(err, TS_EINVAL, "cables: " "at least one cable needed");

    int rc;
    for (int i = 0; i < s->ncables; i++) {
        const ts_cable *c = &s->cables[i];
        if ((rc = check_min(err, "cables", i, c->line, "length", c->length, 0, 1, "m")) ||
            (rc = check_min(err, "cables", i, c->line, "diameter", c->diameter, 0, 0,
                            "m")) ||
            (rc = check_min(err, "cables", i, c->line, "mass_per_length",
                            c->mass_per_length, 0, 0, "kg/m")) ||
            (rc = check_min(err, "cables", i, c->line, "normal_drag", c->cdn, 0, 0,
                            "")) ||
            (rc = check_min(err, "cables", i, c->line, "tangential_drag", c->cdt, 0, 0,
                            "")) ||
            (rc = check_min(err, "cables", i, c->line, "added_mass", c->can, 0, 0, "")) ||
            (rc = check_min(err, "cables", i, c->line, "EI", c->ei, 0, 0, "N m^2")) ||
            (rc = check_min(err, "cables", i, c->line, "EA", c->ea, 0, 0, "N")) ||
            (rc = check_min(err, "cables", i, c->line, "damping", c->damping, 0,
                            0, "N s/m")))
            return rc;
        if (c->nlinks < 1)
            return ts_fail(err, TS_EINVAL, "cables[%d].links%s: "
                           "must be >= 1, got %d", i, at_line(c->line), c->nlinks);
        if (c->from_body < -1 || c->from_body >= s->nbodies)
            return ts_fail(err, TS_EINVAL, "cables[%d].from%s: "
                           "no such body (index %d)", i, at_line(c->line),
                           c->from_body);
        if (c->to_body < -1 || c->to_body >= s->nbodies)
            return ts_fail(err, TS_EINVAL, "cables[%d].to%s: "
                           "no such body (index %d)", i, at_line(c->line),
                           c->to_body);
        if (c->from_body >= 0 && c->from_body == c->to_body)
            return ts_fail(err, TS_EINVAL, "cables[%d]%s: "
                           "starts and ends at the same body '%s'", i,
                           at_line(c->line),
                           s->bodies[c->to_body].name);
        if (c->link_fraction) {
            double sum = 0;
            for (int k = 0; k < c->nlinks; k++) {
                if (!(c->link_fraction[k] > 0 && isfinite(c->link_fraction[k])))
                    return ts_fail(err, TS_EINVAL, "cables[%d].link_lengths%s: "
                                   "entry %d must be > 0", i,
                                   at_line(c->line), k);
                sum += c->link_fraction[k];
            }
            if (fabs(sum - 1.0) > 1e-9)
                return ts_fail(err, TS_EINVAL, "cables[%d].link_lengths%s: "
                               "must add up to the cable length", i,
                               at_line(c->line));
        }
        if (c->has_from_point) {
            if (c->from_body < 0 ||
                s->bodies[c->from_body].type != TS_BODY_VEHICLE)
                return ts_fail(err, TS_EINVAL, "cables[%d].at%s: "
                               "a starting point on a body needs a vehicle "
                               "as 'from'", i, at_line(c->line));
            for (int j = 0; j < 3; j++)
                if (!isfinite(c->from_point[j]))
                    return ts_fail(err, TS_EINVAL, "cables[%d].at%s: "
                                   "component %d must be finite", i,
                                   at_line(c->line), j);
        }
        if (c->damping > 0 && !(c->ea > 0))
            return ts_fail(err, TS_EINVAL, "cables[%d].damping%s: "
                           "internal damping needs an elastic cable (EA > 0)",
                           i, at_line(c->line));
        if (c->ei > 0 && c->nlinks < 2)
            return ts_fail(err, TS_EINVAL, "cables[%d].EI%s: "
                           "bending needs at least 2 links, got %d", i,
                           at_line(c->line), c->nlinks);
    }
    if (s->tow.vehicle != -1 &&
        (s->tow.vehicle < 0 || s->tow.vehicle >= s->nbodies ||
         s->bodies[s->tow.vehicle].type != TS_BODY_VEHICLE))
        return ts_fail(err, TS_EINVAL, "tow.vehicle: the towing vehicle "
                       "must be a body of type vehicle, got index %d",
                       s->tow.vehicle);
    if (s->tow.turn_surface >= 0 &&
        (s->tow.vehicle < 0 ||
         s->tow.turn_surface >=
             s->bodies[s->tow.vehicle].vehicle->ncomponents ||
         !s->bodies[s->tow.vehicle].vehicle->component[s->tow.turn_surface]
              .control))
        return ts_fail(err, TS_EINVAL, "towing_vehicle.turn_by: must be a "
                       "control surface of the towing vehicle");
    if (s->tow.dof != 6 && s->tow.dof != 3)
        return ts_fail(err, TS_EINVAL, "towing_vehicle.dof: must be 6 or 3 "
                       "(a surface ship), got %d", s->tow.dof);
    if (s->tow.vehicle >= 0 && (s->tow.point[0] != 0 || s->tow.point[1] != 0))
        return ts_fail(err, TS_EINVAL, "tow.point: with a towing vehicle the "
                       "tow point starts the mean frame's origin: x and y "
                       "must be 0 m, got %g and %g m (z is its starting "
                       "depth)", s->tow.point[0], s->tow.point[1]);
    for (int b = 0; b < s->nbodies; b++)
        if (b != s->tow.vehicle && s->bodies[b].vehicle &&
            s->bodies[b].vehicle->propulsion.type != TS_PROP_NONE)
            return ts_fail(err, TS_EINVAL, "bodies[%d].propulsion%s: only "
                           "the towing vehicle has propulsion",
                           b, at_line(s->bodies[b].line));
    for (int b = 0; b < s->nbodies; b++) {
        const ts_body *bd = &s->bodies[b];
        if ((rc = check_min(err, "bodies", b, bd->line, "diameter", bd->diameter, 0, 0,
                            "m")) ||
            (rc = check_min(err, "bodies", b, bd->line, "mass", bd->mass, 0, 0, "kg")) ||
            (rc = check_min(err, "bodies", b, bd->line, "drag", bd->cd, 0, 0, "")) ||
            (rc = check_min(err, "bodies", b, bd->line, "added_mass", bd->ca, 0, 0, "")) ||
            (rc = check_min(err, "bodies", b, bd->line, "length", bd->length, 0, 0, "m")) ||
            (rc = check_min(err, "bodies", b, bd->line, "cross_drag", bd->cd_cross, 0, 0, "")) ||
            (rc = check_min(err, "bodies", b, bd->line, "cross_added_mass", bd->ca_cross, 0, 0, "")))
            return rc;
        if (bd->type == TS_BODY_CYLINDER &&
            !(bd->diameter > 0 && bd->length > 0))
            return ts_fail(err, TS_EINVAL, "bodies[%d]%s: a cylinder needs a "
                           "volume: diameter and length > 0 m, got %g m and "
                           "%g m",
                           b, at_line(bd->line), bd->diameter, bd->length);
        if (bd->type == TS_BODY_VEHICLE) {
            char where[64];
            snprintf(where, sizeof where, "bodies[%d]", b);
            if (!bd->vehicle)
                return ts_fail(err, TS_EINVAL, "%s%s: a vehicle without a "
                               "description", where, at_line(bd->line));
            if ((rc = ts_vehicle_check(bd->vehicle, bd->mass, where,
                                       bd->line, err)))
                return rc;
        } else if (bd->vehicle) {
            return ts_fail(err, TS_EINVAL, "bodies[%d]%s: only a vehicle "
                           "has a vehicle description", b, at_line(bd->line));
        }
        if (bd->type == TS_BODY_SPHERE && !(bd->diameter > 0))
            return ts_fail(err, TS_EINVAL, "bodies[%d].diameter%s: "
                           "a sphere needs a diameter > 0 m, got %g", b,
                           at_line(bd->line),
                           bd->diameter);
        int ends = 0;
        for (int i = 0; i < s->ncables; i++)
            ends += s->cables[i].to_body == b;
        if (b == s->tow.vehicle) {
            if (ends != 0)
                return ts_fail(err, TS_EINVAL, "towing_vehicle%s: '%s' is "
                               "the root of the tree: no cable may end at "
                               "it, %d do",
                               at_line(bd->line), bd->name, ends);
            continue;
        }
        if (ends != 1)
            return ts_fail(err, TS_EINVAL, "bodies[%d]%s: "
                           "'%s' must end exactly one cable (the cable "
                           "above it), it ends %d",
                           b, at_line(bd->line), bd->name, ends);
    }
    return TS_OK;
}

int ts_system_build(ts_system *s, ts_err *err)
{
    int rc = validate(s, err);
    if (rc != TS_OK)
        return rc;
    free_discretisation(s);

    /* Breadth-first order of cables from the tow point. */
    int nc = s->ncables;
    int *order = malloc((size_t)nc * sizeof *order);
    int *done = calloc((size_t)nc, sizeof *done);
    if (!order || !done) {
        free(order);
        free(done);
        return ts_fail(err, TS_ENOMEM, "ts_system_build: " "out of memory");
    }
    int norder = 0;
    for (int i = 0; i < nc; i++)
        if (s->cables[i].from_body == -1 ||
            (s->tow.vehicle >= 0 && s->cables[i].from_body == s->tow.vehicle)) {
            order[norder++] = i;
            done[i] = 1;
        }
    for (int head = 0; head < norder; head++) {
        int body = s->cables[order[head]].to_body;
        if (body < 0)
            continue;
        for (int i = 0; i < nc; i++)
            if (!done[i] && s->cables[i].from_body == body) {
                order[norder++] = i;
                done[i] = 1;
            }
    }
    if (norder < nc) {
        int bad = 0;
        while (done[bad])
            bad++;
        free(order);
        free(done);
        return ts_fail(err, TS_EINVAL, "cables[%d]%s: "
                       "'%s' is not connected to the tow point: its 'from' "
                       "body '%s' hangs on no cable reached from the tow "
                       "(a loop or a detached branch)",
                       bad, at_line(s->cables[bad].line), s->cables[bad].name,
                       s->bodies[s->cables[bad].from_body].name);
    }
    free(done);

    long long total = 0;
    for (int i = 0; i < nc; i++)
        total += s->cables[i].nlinks;
    if (total > TS_MAX_LINKS) {
        free(order);
        return ts_fail(err, TS_EINVAL,
                       "cables: %lld links in all, more than the %d a "
                       "system may have",
                       total, TS_MAX_LINKS);
    }
    int nl = (int)total;
    s->nlinks = nl;
    s->nnodes = nl + 1;
    /* (nl is 0 for a towing vehicle alone.) */
    s->links = calloc((size_t)nl + 1, sizeof *s->links);
    s->nodes = calloc((size_t)nl + 1, sizeof *s->nodes);
    s->child_links = calloc((size_t)nl + 1, sizeof *s->child_links);
    int *body_node = malloc((size_t)(s->nbodies + 1) * sizeof *body_node);
    if (!s->links || !s->nodes || !s->child_links || !body_node) {
        free(order);
        free(body_node);
        free_discretisation(s);
        return ts_fail(err, TS_ENOMEM, "ts_system_build: " "out of memory");
    }
    for (int b = 0; b < s->nbodies; b++)
        body_node[b] = -1;
    for (int k = 0; k < s->nnodes; k++) {
        s->nodes[k].body = -1;
        s->nodes[k].link = k - 1;
    }
    /* A towing vehicle roots the tree: its attach point is node 0. */
    if (s->tow.vehicle >= 0) {
        body_node[s->tow.vehicle] = 0;
        s->nodes[0].body = s->tow.vehicle;
    }

    double rho = s->env.water_density;
    s->has_bending = 0;
    s->has_added_mass = 0;
    s->has_elastic = 0;
    s->nvehicles = 0;
    for (int b = 0; b < s->nbodies; b++)
        s->nvehicles += s->bodies[b].type == TS_BODY_VEHICLE;
    int k = 0;
    for (int o = 0; o < nc; o++) {
        int ci = order[o];
        const ts_cable *c = &s->cables[ci];
        /* Upper node of the first link: the tow point or the body node. */
        int from = c->from_body < 0 ? s->tow.vehicle : c->from_body;
        int top = from < 0 ? 0 : body_node[from];
        for (int j = 0; j < c->nlinks; j++, k++) {
            ts_link *L = &s->links[k];
            double frac = c->link_fraction ? c->link_fraction[j]
                                           : 1.0 / c->nlinks;
            L->cable = ci;
            L->index = j + 1;
            L->upper = j == 0 ? top : k;
            L->lower = k + 1;
            L->parent = L->upper == 0 ? -1 : L->upper - 1;
            L->next = j + 1 < c->nlinks ? k + 1 : -1;
            L->length = c->length * frac;
            L->diameter = c->diameter;
            L->mass = c->mass_per_length * L->length;
            L->cdn = c->cdn;
            L->cdt = c->cdt;
            L->can = c->can;
            L->drag_law = c->drag_law;
            L->ei = L->next >= 0 ? c->ei : 0.0;
            L->elastic = c->ea > 0;
            L->ea = c->ea;
            L->damping = c->damping;
            /* The first link of a cable from a vehicle starts at a point of
             * the vehicle, which carries half the link's mass. */
            L->up_body = -1;
            if (j == 0 && from >= 0 &&
                s->bodies[from].type == TS_BODY_VEHICLE) {
                const ts_vehicle *v = s->bodies[from].vehicle;
                L->up_body = from;
                for (int q = 0; q < 3; q++)
                    L->up_point[q] = c->has_from_point ? c->from_point[q]
                                                       : v->attach[q];
            }
            if (L->elastic)
                s->has_elastic = 1;
            if (L->ei > 0)
                s->has_bending = 1;
            if (L->can > 0 && rho > 0 && L->diameter > 0)
                s->has_added_mass = 1;
            if (L->up_body < 0)
                s->nodes[L->upper].mass += 0.5 * L->mass;
            s->nodes[L->lower].mass += 0.5 * L->mass;
        }
        if (c->to_body >= 0) {
            body_node[c->to_body] = k;
            s->nodes[k].body = c->to_body;
            const ts_body *bd = &s->bodies[c->to_body];
            if (bd->type != TS_BODY_VEHICLE)
                s->nodes[k].mass += bd->mass;
            if ((bd->ca > 0 || bd->ca_cross > 0) && rho > 0 &&
                bd->type != TS_BODY_JUNCTION && bd->type != TS_BODY_VEHICLE)
                s->has_added_mass = 1;
        }
    }
    free(order);
    free(body_node);

    /* Children grouped by upper node (counting sort keeps link order). */
    for (int n = 0; n <= s->nnodes - 1; n++)
        s->nodes[n].child_begin = s->nodes[n].child_end = 0;
    int *count = calloc((size_t)s->nnodes + 1, sizeof *count);
    if (!count) {
        free_discretisation(s);
        return ts_fail(err, TS_ENOMEM, "ts_system_build: " "out of memory");
    }
    for (int l = 0; l < nl; l++)
        count[s->links[l].upper + 1]++;
    for (int n = 0; n < s->nnodes; n++)
        count[n + 1] += count[n];
    for (int n = 0; n < s->nnodes; n++) {
        s->nodes[n].child_begin = count[n];
        s->nodes[n].child_end = count[n];
    }
    for (int l = 0; l < nl; l++) {
        ts_node *nd = &s->nodes[s->links[l].upper];
        s->child_links[nd->child_end++] = l;
    }
    free(count);

    /* A node without mass cannot be accelerated by finite tensions: every
     * free node needs structural mass (a junction between massless
     * cables would make the tension system singular). A vehicle lends its
     * node the inertia of its body. */
    for (int n = 1; n < s->nnodes; n++)
        if (!(s->nodes[n].mass > 0) &&
            !(s->nodes[n].body >= 0 &&
              s->bodies[s->nodes[n].body].type == TS_BODY_VEHICLE)) {
            const ts_link *L = &s->links[n - 1];
            ts_fail(err, TS_EINVAL, "cables[%d]%s: "
                    "'%s' link %d ends at a node with zero mass: give the "
                    "cable a mass_per_length > 0 or the body a mass",
                    L->cable, at_line(s->cables[L->cable].line),
                    s->cables[L->cable].name, L->index);
            free_discretisation(s);
            return TS_EINVAL;
        }
    return TS_OK;
}
