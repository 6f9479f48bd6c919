/* test_scene.c: scene files -> ts_system (towstab/scene.h).
 *
 * Good fixtures in test/scenes/good_*.yaml: every converted value is
 * checked in SI against references computed here from the exact unit
 * definitions, and the built tree (links, nodes, node masses = half links
 * plus body). Bad fixtures test/scenes/bad_*.yaml: one check each of the
 * code, the file-name prefix, the key path, the line and the gist of the
 * message. Buffers: a scene that is not NUL-terminated, a length that cuts
 * the text, every prefix and many one-byte mutations of a good scene (no
 * crash, a message on every failure). Run from the project root. Under
 * valgrind --leak-check=full this also proves nothing leaks on any path. */
#include "towstab/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"

#define FT 0.3048
#define INCH 0.0254
#define LB 0.45359237
#define G0 9.80665
#define LBF (LB * G0)
#define KNOT (1852.0 / 3600.0)
#define SLUG (LBF / FT)
#define DEG (M_PI / 180.0)

/* Values pass through one unit conversion and a division by g. */
#define RTOL 1e-13

#define DIR "test/scenes/"

static ts_scene *load(const ts_units *u, const char *file)
{
    ts_err err;
    ts_err_clear(&err);
    ts_scene *s = ts_scene_load(file, u, &err);
    CHECK(s != NULL && err.code == TS_OK, "%s loads (%s)", file, err.msg);
    return s;
}

static double node_mass_sum(const ts_system *sys)
{
    double m = 0;
    for (int k = 0; k < sys->nnodes; k++)
        m += sys->nodes[k].mass;
    return m;
}

static void test_ex1(const ts_units *u)
{
    ts_scene *s = load(u, DIR "good_kamman_ex1.yaml");
    if (!s)
        return;
    const ts_system *sys = s->system;
    CHECK(!strcmp(s->path, DIR "good_kamman_ex1.yaml"), "path kept");
    CHECK(!strcmp(sys->name, "kamman_ex1"), "name");
    CHECK(sys->env.water_density == 1025, "water_density");
    CHECK(sys->env.gravity == 9.80665, "gravity");
    CHECK(sys->env.current[0] == 0 && sys->env.current[1] == 0 &&
          sys->env.current[2] == 0, "current");
    CHECK_REL(sys->tow.speed, 8.345 * FT, RTOL, "tow.speed 8.345 ft/s");
    CHECK(sys->tow.turn_rate == 0, "turn_rate");
    CHECK(sys->tow.point[2] == 0, "tow point");

    CHECK(sys->ncables == 1 && sys->nbodies == 1, "one cable, one body");
    const ts_cable *c = &sys->cables[0];
    CHECK(!strcmp(c->name, "main"), "cable name");
    CHECK(c->from_body == -1 && c->to_body == 0, "main: tow -> sphere");
    CHECK_REL(c->length, 30.48, RTOL, "length 100 ft");
    CHECK_REL(c->diameter, 0.0254, RTOL, "diameter 1 in");
    /* 1 lbf/ft over g0 is exactly 1 lb/ft. */
    CHECK_REL(c->mass_per_length, LB / FT, RTOL, "1 lbf/ft -> 1 lb/ft");
    CHECK(c->nlinks == 20 && c->link_fraction == NULL, "20 equal links");
    CHECK(c->cdn == 1.2 && c->cdt == 0.01 && c->can == 1.0, "coefficients");
    CHECK(c->drag_law == TS_DRAG_STANDARD && c->ei == 0, "drag law, EI");
    CHECK(c->line == 14, "cable line 14 (got %d)", c->line);

    const ts_body *b = &sys->bodies[0];
    CHECK(!strcmp(b->name, "sphere") && b->type == TS_BODY_SPHERE, "sphere");
    CHECK_REL(b->diameter, 0.254, RTOL, "sphere diameter 10 in");
    CHECK_REL(b->mass, 50 * LB, RTOL, "50 lbf -> 50 lb");
    CHECK(b->cd == 0.5 && b->ca == 0.5, "sphere coefficients");
    CHECK(b->line == 27, "body line 27 (got %d)", b->line);

    /* The tree: 20 links of 5 ft and 5 lb each. */
    CHECK(sys->nlinks == 20 && sys->nnodes == 21, "20 links, 21 nodes");
    double link_mass = 5 * LB;
    CHECK_REL(sys->links[7].length, 5 * FT, RTOL, "link length 5 ft");
    CHECK_REL(sys->links[7].mass, link_mass, RTOL, "link mass 5 lb");
    CHECK_REL(sys->nodes[0].mass, link_mass / 2, RTOL, "node 0: half link");
    CHECK_REL(sys->nodes[9].mass, link_mass, RTOL, "node 9: two halves");
    CHECK_REL(sys->nodes[20].mass, link_mass / 2 + 50 * LB, RTOL,
              "node 20: half link + sphere");
    CHECK(sys->nodes[20].body == 0 && ts_system_body_node(sys, 0) == 20,
          "sphere at node 20");
    CHECK_REL(node_mass_sum(sys), 100 * LB + 50 * LB, RTOL,
              "node masses add up to cable + sphere");
    CHECK(sys->has_added_mass == 1 && sys->has_bending == 0, "flags");

    CHECK(s->nanalyses == 2, "two analyses");
    if (s->nanalyses == 2) {
        CHECK(!strcmp(s->analyses[0].type, "equilibrium") &&
              s->analyses[0].noptions == 0, "bare analysis");
        const ts_scene_option *o =
            ts_scene_analysis_option(&s->analyses[1], "turn_rate");
        CHECK(o && !strcmp(o->value, "0.5 rad/s") && o->line == 36,
              "option turn_rate kept as text, line 36");
        CHECK(!ts_scene_analysis_option(&s->analyses[1], "speed"),
              "absent option is NULL");
        CHECK(s->analyses[1].line == 35, "analysis line 35 (got %d)",
              s->analyses[1].line);
    }
    ts_scene_free(s);
}

static void test_ex2(const ts_units *u)
{
    ts_scene *s = load(u, DIR "good_kamman_ex2.yaml");
    if (!s)
        return;
    const ts_system *sys = s->system;
    double g = 32.174 * FT;
    double rho = 1.9905 * SLUG / (FT * FT * FT);
    double d = 0.163 * INCH;
    CHECK(!strcmp(sys->name, "kamman_ex2"), "name");
    CHECK_REL(sys->env.gravity, g, RTOL, "gravity 32.174 ft/s^2");
    CHECK_REL(sys->env.water_density, rho, RTOL, "rho 1.9905 slug/ft^3");
    CHECK_REL(sys->env.current[0], 0.1 * KNOT, RTOL, "current x 0.1 knot");
    CHECK_REL(sys->env.current[1], -0.02, RTOL, "current y -2 cm/s");
    CHECK(sys->env.current[2] == 0, "current z");
    CHECK_REL(sys->tow.speed, 2.5 * FT, RTOL, "speed 2.5 ft/s");
    CHECK_REL(sys->tow.turn_rate, 0.5, RTOL, "turn 0.5 rad/s");
    CHECK_REL(sys->tow.point[0], FT, RTOL, "tow point x 1 ft");
    CHECK_REL(sys->tow.point[2], -35 * FT, RTOL, "tow point z -35 ft");

    int branch = ts_system_find_body(sys, "branch");
    int sa = ts_system_find_body(sys, "sphere_a");
    int sb = ts_system_find_body(sys, "sphere_b");
    CHECK(sa == 0 && branch == 1 && sb == 2, "bodies in file order");
    const ts_cable *lead = &sys->cables[0], *up = &sys->cables[1],
                   *lo = &sys->cables[2];
    CHECK(lead->from_body == -1 && lead->to_body == branch, "lead");
    CHECK(up->from_body == branch && up->to_body == sa, "upper");
    CHECK(lo->from_body == branch && lo->to_body == sb, "lower");

    double mpl_lead = 0.008979 * LBF / FT / g;
    double mpl_up = 0.008979 * LB / FT;
    double mpl_lo = 0.005 * LBF / FT / g + rho * M_PI * d * d / 4;
    CHECK_REL(lead->length, 3 * FT, RTOL, "lead length");
    CHECK_REL(lead->diameter, d, RTOL, "lead diameter 0.163 in");
    CHECK_REL(lead->mass_per_length, mpl_lead, RTOL, "lead weight / g");
    CHECK_REL(up->mass_per_length, mpl_up, RTOL, "upper mass_per_length");
    CHECK_REL(lo->mass_per_length, mpl_lo, RTOL, "lower wet_weight");
    CHECK_REL(ts_cable_wet_weight(sys, 2), 0.005 * LBF / FT, 1e-12,
              "lower: wet weight recovered");
    CHECK(up->nlinks == 3 && up->link_fraction, "upper: 3 given links");
    if (up->link_fraction) {
        CHECK_REL(up->link_fraction[0], 1.0 / 3, RTOL, "fraction 1 ft/3 ft");
        CHECK_REL(up->link_fraction[1], 0.5, RTOL, "fraction 1.5 ft/3 ft");
        CHECK_REL(up->link_fraction[2], 1.0 / 6, RTOL, "fraction 6 in/3 ft");
    }
    CHECK(lo->nlinks == 2 && lo->link_fraction, "lower: links 2 agrees");
    if (lo->link_fraction)
        CHECK_REL(lo->link_fraction[0], 0.3 / (1.8 * FT), RTOL,
                  "fraction 0.3 m / 1.8 ft");
    CHECK(up->cdn == 1.5 && up->cdt == 0.02 && up->can == 0.8,
          "upper coefficients");
    CHECK(up->drag_law == TS_DRAG_LOADING, "loading_functions");
    CHECK_REL(up->ei, 0.01 * LBF * FT * FT, RTOL, "EI 0.01 lbf ft^2");
    CHECK(lead->drag_law == TS_DRAG_STANDARD && lead->cdn == 1.2 &&
          lead->cdt == 0.01 && lead->can == 1.0 && lead->ei == 0,
          "lead defaults");

    const ts_body *A = &sys->bodies[sa], *J = &sys->bodies[branch],
                  *B = &sys->bodies[sb];
    CHECK_REL(A->diameter, 2 * INCH, RTOL, "sphere_a 2 in");
    CHECK_REL(A->mass, 0.246 * LBF / g, RTOL, "sphere_a weight / g");
    CHECK(A->cd == 0.5 && A->ca == 0.5, "sphere defaults");
    CHECK(J->type == TS_BODY_JUNCTION && J->diameter == 0 && J->mass == 0 &&
          J->cd == 0 && J->ca == 0, "junction defaults");
    CHECK_REL(B->mass, 0.492 * LB, RTOL, "sphere_b mass 0.492 lb");
    CHECK(B->cd == 0.6 && B->ca == 0.4, "sphere_b coefficients");

    /* Tree: lead (3), upper (3), lower (2). The junction node joins the
     * last lead link and the first links of both branches. */
    CHECK(sys->nlinks == 8 && sys->nnodes == 9, "8 links, 9 nodes");
    int jn = ts_system_body_node(sys, branch);
    CHECK(jn == 3, "junction at node 3 (got %d)", jn);
    if (jn == 3) {
        double want = 0.5 * (mpl_lead * FT + mpl_up * FT + mpl_lo * 0.3);
        CHECK_REL(sys->nodes[3].mass, want, RTOL, "junction node mass");
        CHECK(sys->nodes[3].child_end - sys->nodes[3].child_begin == 2,
              "two links hang from the junction");
    }
    double total = mpl_lead * 3 * FT + mpl_up * 3 * FT + mpl_lo * 1.8 * FT +
                   A->mass + B->mass;
    CHECK_REL(node_mass_sum(sys), total, RTOL, "node masses add up");
    CHECK(sys->has_bending == 1 && sys->has_added_mass == 1, "flags");

    CHECK(s->nanalyses == 3, "three analyses");
    if (s->nanalyses == 3) {
        const ts_scene_analysis *a = &s->analyses[1];
        CHECK(!strcmp(a->type, "modes") && a->noptions == 2, "modes, 2 opts");
        const ts_scene_option *o = ts_scene_analysis_option(a, "tolerance");
        CHECK(o && !strcmp(o->value, "1e-10"), "tolerance text");
        o = ts_scene_analysis_option(a, "turn_rate");
        CHECK(o && !strcmp(o->value, "28.65 deg/s"), "turn_rate text");
        CHECK(!strcmp(s->analyses[2].type, "response") &&
              s->analyses[2].noptions == 0, "map with type only");
    }
    ts_scene_free(s);
}

static void test_minimal_and_wet(const ts_units *u)
{
    ts_scene *s = load(u, DIR "good_minimal.yaml");
    if (s) {
        const ts_system *sys = s->system;
        const ts_cable *c = &sys->cables[0];
        CHECK(sys->env.water_density == 1025 && sys->env.gravity == 9.80665,
              "environment defaults");
        CHECK(sys->tow.speed == 2 && sys->tow.turn_rate == 0 &&
              sys->tow.point[0] == 0 && sys->tow.point[2] == 0,
              "tow defaults, bare SI numbers");
        CHECK(c->to_body == -1 && c->length == 50 && c->diameter == 0.02 &&
              c->mass_per_length == 0.5 && c->nlinks == 5, "free end cable");
        CHECK(c->cdn == 1.2 && c->cdt == 0.01 && c->can == 1.0 &&
              c->drag_law == TS_DRAG_STANDARD && c->ei == 0,
              "cable defaults");
        CHECK(sys->nbodies == 0 && s->nanalyses == 0 && !s->analyses,
              "no bodies, no analyses");
        CHECK_REL(sys->nodes[5].mass, 0.5 * 10 * 0.5, RTOL,
                  "free end node: half a link");
        ts_scene_free(s);
    }
    s = load(u, DIR "good_wet_weights.yaml");
    if (s) {
        const ts_system *sys = s->system;
        double rho = 1025, g = 9.80665;
        CHECK_REL(sys->cables[0].mass_per_length,
                  0.75 * LBF / FT / g + rho * M_PI * INCH * INCH / 4, RTOL,
                  "cable wet_weight -> mass in air");
        CHECK_REL(ts_cable_wet_weight(sys, 0), 0.75 * LBF / FT, 1e-12,
                  "cable wet weight recovered");
        CHECK_REL(sys->bodies[0].mass,
                  17 * LBF / g + rho * M_PI * pow(12 * INCH, 3) / 6, RTOL,
                  "sphere wet_weight -> mass in air");
        CHECK(sys->tow.speed == 0 && sys->cables[0].nlinks == 15, "drop");
        ts_scene_free(s);
    }
}

/* 1 when msg contains "line N" not followed by another digit. */
static int has_line(const char *msg, int n)
{
    char want[32];
    snprintf(want, sizeof want, "line %d", n);
    for (const char *p = strstr(msg, want); p; p = strstr(p + 1, want)) {
        char next = p[strlen(want)];
        if (next < '0' || next > '9')
            return 1;
    }
    return 0;
}

/* A vehicle with every key (good_vehicle.yaml). */
static void test_vehicle(const ts_units *u)
{
    ts_scene *s = load(u, DIR "good_vehicle.yaml");
    if (!s)
        return;
    const ts_system *sys = s->system;
    const ts_body *b = &sys->bodies[0];
    const ts_vehicle *v = b->vehicle;
    double deg = M_PI / 180;
    CHECK(b->type == TS_BODY_VEHICLE && v && sys->nvehicles == 1,
          "fish is a vehicle");
    CHECK_REL(b->mass, 500 / sys->env.gravity, RTOL, "weight -> mass");
    CHECK_REL(v->volume, 0.030, RTOL, "volume 30 L");
    CHECK(fabs(v->inertia[0] - 0.4) < 1e-15 && fabs(v->inertia[4] - 0.05) <
              1e-15 && v->inertia[3] == 0,
          "inertia with products (Ixz)");
    CHECK(fabs(v->mass_centre[2] - 0.02) < 1e-15 &&
              fabs(v->buoyancy_centre[0] - 0.01) < 1e-15 &&
              fabs(v->attach[0] - 0.2) < 1e-15 &&
              fabs(v->attach[2] + 0.12) < 1e-15,
          "mass centre, buoyancy centre, attach point in m");
    CHECK_REL(v->surface_diameter, 0.25, RTOL, "surface_diameter");
    /* The spheroid's added mass, moved from its centre (5 cm forward) to
     * O: A11 = k1 m_f unchanged; the shift couples sway and yaw. */
    double A[36], k[3];
    ts_added_mass_spheroid(sys->env.water_density, 1.6, 0.2, A, k, NULL);
    CHECK(v->added_mass_estimated && fabs(v->added_mass[0] - A[0]) <
              1e-12 * A[0] && fabs(v->added_mass[6 * 1 + 5]) > 0,
          "added mass: spheroid of 1.6 m x 0.2 m at 5 cm, A11 %.6g kg, "
          "A26 %.6g kg m",
          v->added_mass[0], v->added_mass[11]);
    CHECK(v->ncomponents == 4, "four components");
    const ts_component *h = &v->component[0], *w = &v->component[1];
    const ts_component *f = &v->component[2], *bl = &v->component[3];
    CHECK(h->type == TS_COMP_HULL && fabs(h->length - 1.6) < 1e-15 &&
              fabs(h->cd_axial - 0.25) < 1e-15,
          "hull");
    CHECK(w->type == TS_COMP_SURFACE && fabs(w->area - 0.12) < 1e-15 &&
              fabs(w->incidence + 3 * deg) < 1e-15 &&
              fabs(w->stall - 18 * deg) < 1e-15 &&
              fabs(w->lift_slope - 3.1) < 1e-15 &&
              fabs(w->cd0 - 0.012) < 1e-15 && !w->control,
          "wing: area, incidence, stall, slope, zero-lift drag");
    CHECK(f->curve == TS_CURVE_TABLE && f->npoints == 5 &&
              fabs(f->alpha[1] + 15 * deg) < 1e-15 &&
              fabs(f->roll - 90 * deg) < 1e-15 && f->cd[4] == 1.2,
          "fin: a 5-row table, rolled 90 deg");
    CHECK(bl->type == TS_COMP_BLUFF && fabs(bl->drag - 0.9) < 1e-15,
          "ballast: a bluff part");
    const ts_cable *t = &sys->cables[1];
    CHECK(t->has_from_point && fabs(t->from_point[0] + 0.8) < 1e-15,
          "the tail starts at (-0.8, 0, 0.05) m of the fish");
    int l = 0;
    while (l < sys->nlinks && sys->links[l].cable != 1)
        l++;
    CHECK(l < sys->nlinks && sys->links[l].up_body == 0 &&
              fabs(sys->links[l].up_point[2] - 0.05) < 1e-15,
          "its first link starts at that point of the vehicle");
    /* The vehicle's mass and the tail's first half link are the body's,
     * not its node's. */
    int node = ts_system_body_node(sys, 0);
    CHECK_REL(sys->nodes[node].mass, 0.5 * 50.0 / 8 * 0.4, RTOL,
              "the vehicle's node carries half a main link only");
    ts_scene_free(s);
}

static void test_bad_fixtures(const ts_units *u)
{
    static const struct {
        const char *file;
        int code;
        const char *path;   /* what follows "<file>: " */
        int line;           /* 0: no line in the message */
        const char *gist;
    } bad[] = {
        {"bad_missing_length", TS_ESCENE, "cables[0]", 6,
         "missing key 'length'"},
        {"bad_vehicle_no_components", TS_ESCENE, "bodies[0]", 15,
         "missing key 'components'"},
        {"bad_vehicle_component_type", TS_EINVAL,
         "bodies[0].components[0].type", 23,
         "unknown component type \"wing\"; expected hull, surface, bluff, "
         "mast or ballast"},
        {"bad_vehicle_inertia", TS_EINVAL, "bodies[0].inertia", 19,
         "needs 3 to 6 entries, got 2"},
        {"bad_vehicle_inertia_not_definite", TS_EINVAL, "bodies[0].inertia",
         15, "must be positive definite"},
        {"bad_vehicle_diameter", TS_ESCENE, "bodies[0].diameter", 18,
         "does not apply to a vehicle"},
        {"bad_vehicle_surface_hull_key", TS_ESCENE,
         "bodies[0].components[1].axial_drag", 30,
         "does not apply to a surface component"},
        {"bad_vehicle_table_order", TS_EINVAL,
         "bodies[0].components[1].table", 26,
         "angles must increase, row 2 has 5 deg after 10 deg"},
        {"bad_vehicle_added_mass_rows", TS_EINVAL, "bodies[0].added_mass",
         21, "needs 6 rows of 6 numbers"},
        {"bad_vehicle_at_sphere", TS_EINVAL, "cables[1].at", 16,
         "a starting point on a body needs a vehicle"},
        {"bad_unknown_key_top", TS_ESCENE, "tow_speed", 5,
         "unknown key; expected one of name, environment, tow, cables, "
         "bodies, analyses"},
        {"bad_unknown_key_cable", TS_ESCENE, "cables[0].diamter", 11,
         "unknown key; expected one of name, from, to, length, diameter"},
        {"bad_unknown_key_body", TS_ESCENE, "bodies[0].typo", 17,
         "unknown key; expected one of name, type, diameter, weight, mass, "
         "wet_weight, drag, added_mass"},
        {"bad_duplicate_key", TS_ESCENE, "cables[0].length", 11,
         "duplicate key (first given on line 9)"},
        {"bad_map_for_scalar", TS_ESCENE, "tow.speed", 4, "got a mapping"},
        {"bad_negative_length", TS_EINVAL, "cables[0].length", 9,
         "must be > 0 m, got -3 m"},
        {"bad_zero_length", TS_EINVAL, "cables[0].length", 9,
         "must be > 0 m, got 0 m (written \"0 ft\")"},
        {"bad_zero_links", TS_EINVAL, "cables[0].links", 12,
         "must be an integer >= 1, got 0"},
        {"bad_fractional_links", TS_EINVAL, "cables[0].links", 12,
         "must be an integer >= 1, got 2.5"},
        {"bad_nan", TS_EINVAL, "cables[0].diameter", 10,
         "\".nan\" is not a finite number"},
        {"bad_mass_as_weight", TS_EUNIT, "bodies[0].weight", 17,
         "\"50 lb\" is a mass (kg), expected a force (N): for a weight "
         "write \"50 lbf\""},
        {"bad_mass_per_length_as_weight", TS_EUNIT, "cables[0].weight", 11,
         "is a mass per length (kg/m), expected a force per length (N/m): "
         "for a weight write \"1 lbf/ft\""},
        {"bad_unknown_unit", TS_EUNIT, "cables[0].length", 9,
         "unknown unit \"fathoms_deep\""},
        {"bad_from_unknown_body", TS_EINVAL, "cables[1].from", 14,
         "no body named 'spehre' (bodies: sphere, junction1)"},
        {"bad_weight_and_mass", TS_ESCENE, "bodies[0].mass", 18,
         "give only one of weight, mass or wet_weight ('weight' is given "
         "on line 17)"},
        {"bad_missing_weight", TS_ESCENE, "bodies[0]", 14,
         "missing key: give one of weight, mass or wet_weight"},
        {"bad_scalar", TS_ESCENE, "top level", 2,
         "expected a mapping with name, tow and cables, got a scalar"},
        {"bad_syntax", TS_ESCENE, "YAML syntax error", 11, "column 11"},
        {"bad_empty", TS_ESCENE, "the scene is empty", 0, "name, tow"},
        {"bad_second_document", TS_ESCENE, "a second YAML document", 19,
         "holds one"},
        {"bad_tow_body_name", TS_EINVAL, "bodies[0].name", 14, "reserved"},
        {"bad_links_mismatch", TS_EINVAL, "cables[0].links", 12,
         "10 does not match the 2 entries of link_lengths (line 13)"},
        {"bad_link_lengths_sum", TS_EINVAL, "cables[0].link_lengths", 12,
         "add up to 29 m, but the cable length is 30 m"},
        {"bad_null_value", TS_ESCENE, "bodies[0].diameter", 16, "no value"},
        {"bad_drag_law", TS_EINVAL, "cables[0].drag_law", 13,
         "\"quadratic\"; expected standard or loading_functions"},
        {"bad_current_length", TS_ESCENE, "environment.current", 4,
         "expected a list of 3 quantities [x, y, z], got 2 entries"},
        {"bad_angle_unit", TS_EUNIT, "tow.turn_rate", 5,
         "is a frequency (Hz), expected an angular rate (rad/s)"},
        {"bad_body_type", TS_EINVAL, "bodies[0].type", 15, "\"cube\""},
        {"bad_wet_weight_buoyant", TS_EINVAL, "bodies[0].wet_weight", 17,
         "negative mass"},
        {"bad_duplicate_cable_name", TS_EINVAL, "cables[1].name", 13,
         "duplicate cable name 'main' (cables[0], line 6)"},
        {"bad_duplicate_body_name", TS_EINVAL, "bodies[1].name", 15,
         "duplicate body name 'ball' (bodies[0], line 14)"},
        {"bad_analysis_option_list", TS_ESCENE, "analyses[0].frequencies",
         20, "must be a scalar, got a list"},
        {"bad_no_cables", TS_EINVAL, "cables", 5, "at least one cable"},
        /* Found by ts_system_build, which appends the entry's line. */
        {"bad_loop", TS_EINVAL, "cables[1]", 12,
         "not connected to the tow point"},
        {"bad_body_two_cables", TS_EINVAL, "bodies[0]", 21, "it ends 2"},
        {"bad_body_no_cable", TS_EINVAL, "bodies[0]", 13, "it ends 0"},
        /* Elastic cables, bending, towfish (doc/elastic.md). */
        {"bad_negative_ea", TS_EINVAL, "cables[0].EA", 13,
         "must be >= 0 N, got -4.5e+06 N (written \"-4.5e6 N\")"},
        {"bad_negative_ei", TS_EINVAL, "cables[0].EI", 13,
         "must be >= 0 N*m^2, got -9.1 N*m^2"},
        {"bad_negative_damping", TS_EINVAL, "cables[0].damping", 14,
         "must be >= 0 N*s/m, got -50 N*s/m"},
        {"bad_damping_rigid", TS_EINVAL, "cables[0].damping", 13,
         "internal damping applies to an elastic cable: give EA > 0"},
        {"bad_ea_zero_diameter", TS_EINVAL, "cables[0].diameter", 11,
         "must be > 0 m, got 0 m"},
        {"bad_towfish_no_volume", TS_EINVAL, "bodies[0].length", 18,
         "must be > 0 m, got 0 m (written \"0 m\")"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char file[256], prefix[512];
        snprintf(file, sizeof file, DIR "%s.yaml", bad[i].file);
        ts_err err;
        ts_err_clear(&err);
        ts_scene *s = ts_scene_load(file, u, &err);
        CHECK(s == NULL && err.code == bad[i].code, "%s: refused with %d "
              "(got %d)", bad[i].file, bad[i].code, err.code);
        snprintf(prefix, sizeof prefix, "%s: %s", file, bad[i].path);
        CHECK(!strncmp(err.msg, prefix, strlen(prefix)),
              "%s: message starts with '%s': %s", bad[i].file, prefix,
              err.msg);
        if (bad[i].line)
            CHECK(has_line(err.msg, bad[i].line), "%s: names line %d",
                  bad[i].file, bad[i].line);
        CHECK(strstr(err.msg, bad[i].gist) != NULL, "%s: says '%s'",
              bad[i].file, bad[i].gist);
        ts_scene_free(s);
        /* And without an error record. */
        s = ts_scene_load(file, u, NULL);
        CHECK(s == NULL, "%s: refused with err == NULL", bad[i].file);
    }
}

static const char small_scene[] =
    "name: from_buffer\n"
    "tow: {speed: \"3 knots\"}\n"
    "cables:\n"
    "  - {name: c, from: tow, length: \"10 m\", diameter: \"1 cm\",\n"
    "     mass_per_length: 0.25, links: 4}\n"
    "bogus_key: 1\n";

static void test_buffers(const ts_units *u)
{
    ts_err err;
    /* Exactly the bytes up to (not including) the bogus key, copied to a
     * buffer with no terminating NUL: valgrind sees any overread. */
    size_t len = (size_t)(strstr(small_scene, "bogus_key") - small_scene);
    char *buf = malloc(len);
    memcpy(buf, small_scene, len);
    ts_scene *s = ts_scene_parse(buf, len, "buffer", u, &err);
    CHECK(s != NULL, "a buffer without NUL parses (%s)", s ? "" : err.msg);
    if (s) {
        CHECK(!strcmp(s->path, ""), "no path for a buffer");
        CHECK_REL(s->system->tow.speed, 3 * KNOT, RTOL, "3 knots");
        CHECK(s->system->cables[0].diameter == 0.01 && s->system->nlinks == 4,
              "flow-style cable");
    }
    ts_scene_free(s);
    free(buf);

    /* The whole text: the bogus key is seen, and the name is the prefix. */
    s = ts_scene_parse(small_scene, strlen(small_scene), "buffer.yaml", u,
                       &err);
    CHECK(!s && err.code == TS_ESCENE &&
          !strncmp(err.msg, "buffer.yaml: bogus_key (line 6): unknown key",
                   44), "full buffer: %s", err.msg);

    s = ts_scene_parse(NULL, 0, NULL, u, &err);
    CHECK(!s && err.code == TS_ESCENE && strstr(err.msg, "<string>: "),
          "NULL, 0: an empty scene: %s", err.msg);
    s = ts_scene_parse(NULL, 5, "x", u, &err);
    CHECK(!s && err.code == TS_EINVAL, "NULL text with a length: %s",
          err.msg);
    s = ts_scene_parse(small_scene, len, "x", NULL, &err);
    CHECK(!s && err.code == TS_EINVAL, "NULL units: %s", err.msg);

    /* NUL bytes, invalid UTF-8, aliases, a self-referential alias. */
    static const char nul[] = "name: a\0b\n";
    s = ts_scene_parse(nul, sizeof nul - 1, "nul", u, &err);
    CHECK(!s && err.code == TS_ESCENE, "a NUL byte: %s", err.msg);
    static const char latin1[] = "name: caf\xe9\n";
    s = ts_scene_parse(latin1, sizeof latin1 - 1, "latin1", u, &err);
    CHECK(!s && err.code == TS_ESCENE && strstr(err.msg, "byte"),
          "invalid UTF-8: %s", err.msg);
    static const char alias[] =
        "name: aliased\n"
        "tow: {speed: 1, point: &p [0, 0, 0]}\n"
        "environment: {current: *p}\n"
        "cables:\n"
        "  - &c {name: a, from: tow, to: s, length: 5, diameter: 0.01,\n"
        "        mass_per_length: 0.2, links: 2}\n"
        "bodies: [{name: s, type: sphere, diameter: 0.1, mass: 1}]\n";
    s = ts_scene_parse(alias, sizeof alias - 1, "alias", u, &err);
    CHECK(s != NULL, "aliases are followed (%s)", s ? "" : err.msg);
    ts_scene_free(s);
    static const char loop[] =
        "name: selfref\n"
        "tow: {speed: 1, point: &p [0, 0, *p]}\n"
        "cables: [{name: a, from: tow, length: 5, diameter: 0.01,\n"
        "          mass_per_length: 0.2, links: 2}]\n";
    s = ts_scene_parse(loop, sizeof loop - 1, "selfref", u, &err);
    CHECK(!s && err.code == TS_ESCENE && strstr(err.msg, "tow.point[2]"),
          "a list containing itself is refused: %s", err.msg);
    static const char loop2[] =
        "name: selfref\n"
        "tow: {speed: 1}\n"
        "cables: &q [*q]\n";
    s = ts_scene_parse(loop2, sizeof loop2 - 1, "selfref", u, &err);
    CHECK(!s && err.code == TS_ESCENE && strstr(err.msg, "cables[0]"),
          "a cable list containing itself is refused: %s", err.msg);
    static const char deep[] = "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]]]]]"
                               "]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]\n";
    s = ts_scene_parse(deep, sizeof deep - 1, "deep", u, &err);
    CHECK(!s && err.code == TS_ESCENE, "deep nesting: %s", err.msg);
    /* Flow collections nested 65 deep are refused before libyaml scans
     * them (its time grows with the square of the depth); 64 is allowed,
     * and brackets inside quotes, comments and plain scalars do not
     * count. */
    char nest[512];
    for (int depth = 64; depth <= 65; depth++) {
        int n = snprintf(nest, sizeof nest, "name: n\ntow: {speed: 1}\n"
                         "cables: ");
        for (int i = 0; i < depth; i++)
            nest[n++] = '[';
        for (int i = 0; i < depth; i++)
            nest[n++] = ']';
        nest[n++] = '\n';
        s = ts_scene_parse(nest, (size_t)n, "nest.yaml", u, &err);
        if (depth == 64)
            CHECK(!s && !strstr(err.msg, "nested more than"),
                  "64 levels reach the reader: %s", err.msg);
        else
            CHECK(!s && err.code == TS_ESCENE &&
                  strstr(err.msg, "nest.yaml: line 3: lists or mappings "
                                  "nested more than 64 deep"),
                  "65 levels are refused with the line: %s", err.msg);
    }
    {
        char q[1024];
        int n = snprintf(q, sizeof q, "name: \"q%s\"  # %s\n"
                         "description: '%s'\ntow: {speed: 1}\n",
                         "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["
                         "[[[[[[[[[[[[[[[[", "{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{"
                         "{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{{",
                         "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[["
                         "[[[[[[[[[[[[[[[[[[[");
        s = ts_scene_parse(q, (size_t)n, "quoted.yaml", u, &err);
        CHECK(!s && !strstr(err.msg, "nested more than"),
              "brackets in quotes and comments do not count: %s", err.msg);
    }

    s = ts_scene_load(DIR "no_such_file.yaml", u, &err);
    CHECK(!s && err.code == TS_EIO && strstr(err.msg, "no_such_file.yaml: "),
          "missing file: %s", err.msg);
    s = ts_scene_load(DIR, u, &err);
    CHECK(!s && err.code == TS_EIO, "a directory: %s", err.msg);
    /* "-" reads standard input; messages name it. */
    if (freopen(DIR "good_minimal.yaml", "rb", stdin)) {
        s = ts_scene_load("-", u, &err);
        CHECK(s && !strcmp(s->path, "-"), "'-' reads a scene from standard "
              "input (%s)", s ? "" : err.msg);
        ts_scene_free(s);
    }
    if (freopen(DIR "bad_empty.yaml", "rb", stdin)) {
        s = ts_scene_load("-", u, &err);
        CHECK(!s && !strncmp(err.msg, "standard input: ", 16),
              "a bad scene on standard input is named so: %s", err.msg);
    }
    ts_scene_free(NULL);
    CHECK(1, "ts_scene_free(NULL) does nothing");
    CHECK(ts_scene_analysis_option(NULL, "x") == NULL, "option of NULL");
}

/* Every prefix and one-byte mutations of a good scene: no crash, and a
 * message on every failure (valgrind checks the memory). */
static void test_mutations(const ts_units *u)
{
    FILE *fp = fopen(DIR "good_kamman_ex2.yaml", "rb");
    if (!CHECK(fp != NULL, "open good_kamman_ex2.yaml"))
        return;
    char text[8192];
    size_t len = fread(text, 1, sizeof text, fp);
    fclose(fp);
    int nok = 0, nfail = 0, silent = 0;
    for (size_t n = 0; n <= len; n++) {
        ts_err err;
        ts_err_clear(&err);
        char *buf = malloc(n ? n : 1);
        memcpy(buf, text, n);
        ts_scene *s = ts_scene_parse(buf, n, "prefix", u, &err);
        if (s)
            nok++;
        else if (err.code < 0 && err.msg[0])
            nfail++;
        else
            silent++;
        ts_scene_free(s);
        free(buf);
    }
    CHECK(silent == 0 && nok + nfail == (int)len + 1, "%zu prefixes: %d "
          "parse, %d refused with a message, %d silent", len + 1, nok, nfail,
          silent);
    CHECK(nok >= 1, "the whole file parses");

    static const char swaps[] = ":-[]{}&*#\"'\n 0.x\t|>!%@`,?";
    nok = nfail = silent = 0;
    for (size_t i = 0; i < len; i++) {
        ts_err err;
        ts_err_clear(&err);
        char *buf = malloc(len);
        memcpy(buf, text, len);
        buf[i] = swaps[i % (sizeof swaps - 1)];
        ts_scene *s = ts_scene_parse(buf, len, "mutant", u, &err);
        if (s)
            nok++;
        else if (err.code < 0 && err.msg[0])
            nfail++;
        else
            silent++;
        ts_scene_free(s);
        free(buf);
    }
    CHECK(silent == 0, "%zu one-byte mutants: %d parse, %d refused, %d "
          "silent", len, nok, nfail, silent);
}

/* ts_scene_set: one setting, expecting it to fail with `code` and a
 * message containing `gist` (NULL: no check of the text). */
static void set_fails(const ts_scene *s, const ts_units *u, const char *key,
                      const char *value, int code, const char *gist)
{
    ts_err err;
    ts_err_clear(&err);
    const char *k[1] = {key}, *v[1] = {value};
    ts_scene *t = ts_scene_set(s, 1, k, v, u, &err);
    CHECK(!t && err.code == code && (!gist || strstr(err.msg, gist)),
          "set %s = %s refused: %s", key, value ? value : "(removed)",
          err.msg);
    ts_scene_free(t);
}

/* Values set over the text (doc/scene-format.md, "Setting values"): each
 * converted as in a file, selected by index or name, added when absent,
 * removed; the scene set from is not changed; settings chain, a key set
 * again replaces its earlier value; every bad key or value is refused
 * naming it. */
static void test_settings(const ts_units *u)
{
    const char *file = DIR "good_kamman_ex2.yaml";
    ts_scene *s = load(u, file);
    if (!s)
        return;
    FILE *f = fopen(file, "rb");
    char want[4096];
    size_t n = f ? fread(want, 1, sizeof want, f) : 0;
    if (f)
        fclose(f);
    CHECK(s->text && s->text_len == n && !memcmp(s->text, want, n) &&
              s->text[n] == '\0' && s->nsettings == 0,
          "the text read is kept, byte for byte (%zu bytes), no settings",
          n);

    ts_err err;
    ts_err_clear(&err);
    const char *k1[] = {"tow.speed", "cables[upper].normal_drag",
                        "cables[2].diameter", "bodies[sphere_b].mass",
                        "tow.point", "environment.current[1]",
                        "cables[upper].EI", "analyses[1].tolerance"};
    const char *v1[] = {"5 knot", "1.7", "0.5 in", "2.385 kg",
                        "[0, 0, \"-2 m\"]", "3 cm/s", NULL, "1e-9"};
    ts_scene *t = ts_scene_set(s, 8, k1, v1, u, &err);
    if (CHECK(t != NULL, "eight values set (%s)", err.msg)) {
        const ts_system *a = t->system;
        CHECK_REL(a->tow.speed, 5 * KNOT, RTOL, "tow.speed 5 knot");
        CHECK_REL(a->cables[2].diameter, 0.5 * INCH, RTOL,
                  "cables[2].diameter 0.5 in");
        CHECK(a->cables[1].cdn == 1.7 && a->bodies[2].mass == 2.385,
              "by name: cables[upper].normal_drag, bodies[sphere_b].mass");
        CHECK(a->tow.point[0] == 0 && a->tow.point[2] == -2 &&
                  fabs(a->env.current[1] - 0.03) < 1e-15 &&
                  a->env.current[0] == s->system->env.current[0],
              "a list, and one entry of a list");
        CHECK(a->cables[1].ei == 0 && s->system->cables[1].ei > 0,
              "a key removed takes its default");
        const ts_scene_option *o =
            ts_scene_analysis_option(&t->analyses[1], "tolerance");
        CHECK(o && !strcmp(o->value, "1e-9"), "an analysis option");
        CHECK(s->system->tow.speed == 2.5 * FT && s->nsettings == 0,
              "the scene set from is unchanged");
        CHECK(t->nsettings == 8 && !strcmp(t->settings[3].key,
                                            "bodies[sphere_b].mass") &&
                  !strcmp(t->settings[3].value, "2.385 kg") &&
                  !t->settings[6].value && !strcmp(t->path, s->path) &&
                  t->text_len == s->text_len,
              "the new scene keeps the path, the text and its settings");

        /* Chained: the earlier settings stay; a key again replaces. */
        const char *k2[] = {"tow.turn_rate", "tow.speed"};
        const char *v2[] = {"0", "3"};
        ts_scene *c = ts_scene_set(t, 2, k2, v2, u, &err);
        if (CHECK(c != NULL, "chained (%s)", err.msg)) {
            CHECK(c->system->tow.speed == 3 && c->system->tow.turn_rate == 0 &&
                      c->system->cables[1].cdn == 1.7 &&
                      c->nsettings == 9 &&
                      !strcmp(c->settings[8].key, "tow.speed"),
                  "settings chain; tow.speed set again replaces its "
                  "earlier value (9 settings, speed %g)",
                  c->system->tow.speed);
            ts_scene_free(c);
        }
        ts_scene_free(t);
    }

    /* An absent block is added. */
    ts_scene *m = load(u, DIR "good_minimal.yaml");
    if (m) {
        const char *k[] = {"environment.gravity", "cables[only].links"};
        const char *v[] = {"9.7", "7"};
        ts_err_clear(&err);
        ts_scene *t2 = ts_scene_set(m, 2, k, v, u, &err);
        CHECK(t2 && t2->system->env.gravity == 9.7 &&
                  t2->system->nlinks == 7,
              "a block the file lacks is added (%s)", err.msg);
        ts_scene_free(t2);
        ts_scene_free(m);
    }

    /* Refused, naming the key; the checks of a file apply. */
    set_fails(s, u, "tow.sped", "3", TS_ESCENE,
              "tow.sped (line 45): unknown key");
    set_fails(s, u, "cables[0].length", "-3 m", TS_EINVAL,
              "cables[0].length (line 8): must be > 0 m");
    set_fails(s, u, "tow.speed", "3 kg", TS_EUNIT, "tow.speed (line 47)");
    set_fails(s, u, "cables[9].length", "1", TS_EINVAL,
              "cables[9].length: 'cables' has no entry [9] (3 entries");
    set_fails(s, u, "cables[nope].length", "1", TS_EINVAL,
              "has no entry [nope]");
    set_fails(s, u, "tow.speed.x", "1", TS_EINVAL,
              "'x' is inside a scalar, not a mapping");
    set_fails(s, u, "tow[0]", "1", TS_EINVAL, "'tow' is a mapping, not a "
              "list");
    set_fails(s, u, "nothing[0]", "1", TS_EINVAL, "the scene has no list");
    set_fails(s, u, "tow..speed", "1", TS_EINVAL, "expected a name");
    set_fails(s, u, "cables[0", "1", TS_EINVAL, "expected [index] or [name]");
    set_fails(s, u, "", "1", TS_EINVAL, "expected a key");
    set_fails(s, u, "tow.speed", "[1, 2", TS_EINVAL, "is not YAML");
    set_fails(s, u, "tow.speed", "", TS_EINVAL, "empty value");
    set_fails(s, u, "tow.nothing", NULL, TS_EINVAL, "no such key to remove");
    set_fails(s, u, "cables[0]", NULL, TS_EINVAL, "cannot be removed");
    set_fails(s, u, "tow.speed", "[[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]",
              TS_EINVAL, "nested deeper");
    set_fails(s, u, "tow.speed", NULL, TS_ESCENE, "speed");
    ts_err_clear(&err);
    CHECK(!ts_scene_set(NULL, 0, NULL, NULL, u, &err) &&
              err.code == TS_EINVAL,
          "a NULL scene is refused (%s)", err.msg);
    ts_scene_free(s);

    /* A scene read from a string keeps its text too. */
    static const char text[] = "name: s\ntow: {speed: 1}\ncables:\n"
                               "  - {name: c, from: tow, length: 10, "
                               "diameter: 0.01, mass_per_length: 0.2, links: 2}\n";
    ts_scene *p = ts_scene_parse(text, sizeof text - 1, "text", u, &err);
    const char *k[] = {"cables[c].length"}, *v[] = {"12"};
    ts_scene *q = p ? ts_scene_set(p, 1, k, v, u, &err) : NULL;
    CHECK(p && q && p->text_len == sizeof text - 1 &&
              q->system->cables[0].length == 12,
          "a scene from a string: text kept, values set (%s)", err.msg);
    ts_scene_free(q);
    ts_scene_free(p);
}

/* The design section: kept as text, a list's items as options of one key
 * in order; a mapping, an empty list and a missing value refused by
 * line; absent: NULL. */
static void test_design_section(const ts_units *u)
{
    static const char head[] =
        "name: d\n"
        "tow: {speed: 2}\n"
        "cables: [{name: c, from: tow, length: 10, diameter: 0.01,\n"
        "          mass_per_length: 0.1, links: 4}]\n";
    char text[1024];
    ts_err err;
    snprintf(text, sizeof text, "%s%s", head,
             "design:\n"
             "  free: [\"cables.c.length=5:20\", \"speed=1:3\"]\n"
             "  target: \"c.z=4 m\"\n");
    ts_scene *s = ts_scene_parse(text, strlen(text), "d.yaml", u, &err);
    const ts_scene_analysis *d = s ? s->design : NULL;
    CHECK(d && d->noptions == 3 && !strcmp(d->options[0].key, "free") &&
              !strcmp(d->options[0].value, "cables.c.length=5:20") &&
              !strcmp(d->options[1].key, "free") &&
              !strcmp(d->options[1].value, "speed=1:3") &&
              d->options[1].line == 6 && !strcmp(d->options[2].value,
                                                 "c.z=4 m"),
          "design: a list's items in order, then target (%s)",
          s ? "" : err.msg);
    ts_scene_free(s);
    s = ts_scene_parse(head, strlen(head), "d.yaml", u, &err);
    CHECK(s && !s->design, "no design section: NULL");
    ts_scene_free(s);
    static const struct {
        const char *section, *want;
    } bad[] = {
        {"design: 3\n", "design (line 5): expected a mapping"},
        {"design:\n  free: {a: 1}\n", "design.free (line 6): expected a "
                                      "value or a list of values"},
        {"design:\n  free: []\n", "design.free (line 6): an empty list"},
        {"design:\n  target:\n", "design.target (line 6): no value"},
        {"design:\n  free: [[1]]\n", "design.free (line 6): expected a "
                                     "value, got a list"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(text, sizeof text, "%s%s", head, bad[i].section);
        s = ts_scene_parse(text, strlen(text), "d.yaml", u, &err);
        CHECK(!s && err.code == TS_ESCENE && strstr(err.msg, bad[i].want),
              "refused: %s", s ? "(parsed)" : err.msg);
        ts_scene_free(s);
    }
}

int main(void)
{
    ts_err err;
    ts_units *u = ts_units_alloc(&err);
    if (!CHECK(u != NULL, "ts_units_alloc: %s", u ? "" : err.msg))
        return tc_done();
    test_ex1(u);
    test_ex2(u);
    test_minimal_and_wet(u);
    test_vehicle(u);
    test_bad_fixtures(u);
    test_buffers(u);
    test_mutations(u);
    test_settings(u);
    test_design_section(u);
    ts_units_free(u);
    return tc_done();
}
