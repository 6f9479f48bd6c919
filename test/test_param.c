/* test_param.c: a scalar of a system by its scene key path
 * (towstab/param.h).
 *
 * The independent reference is the scene reader: a value set by path must
 * give the system (every built link and node) that the scene file with
 * that value written in it gives, to the last bit, including weights and
 * wet weights converted with the scene's gravity and water density.
 * Values read by path are the fields the reader filled. The scene
 * format's spelling (cables[0], bodies[fish], tow.point[2]) names the same
 * values, and ts_scene_set (which edits the text and reads it again)
 * gives the same system. Every error names the path; unknown names list
 * what the system has. A vehicle's controllers and components by the
 * scene's words give the modes run of the same text in the scene to the
 * last digit, and a value beyond a key's limit is refused with the same
 * limit by path and in the scene (one key table). So do a vehicle's own
 * keys (its inertia, centres, attach point) and its components'
 * positions and hull keys, whose spheroid added mass follows the hull as
 * the scene reader derives it; a hull that cannot have one is refused
 * with nothing changed. Unknown keys list the accepted ones. The towing
 * vehicle's values (towing_vehicle.<key>, its propulsion under each law)
 * give the runs of the scene with them written in, to the last digit. */
#include "towstab/param.h"

#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "towstab/analysis.h"
#include "towstab/scene.h"

/* A scene with one value left open: %s is replaced by `value` at `key`. */
static const char *const base =
    "name: param\n"
    "environment: {water_density: 1025, gravity: 9.81}\n"
    "tow: {speed: \"5 knot\", turn_rate: 0.05, point: [0, 0, -2]}\n"
    "cables:\n"
    "  - {name: main.a, from: tow, to: fish, length: %s, diameter: 0.02,\n"
    "     %s, links: %s, normal_drag: 1.3}\n"
    "bodies:\n"
    "  - {name: fish, type: sphere, diameter: 0.5, %s, drag: %s}\n";

typedef struct texts {
    const char *length, *cable_mass, *links, *body_mass, *drag;
} texts;

static ts_scene *scene_of(const ts_units *u, const texts *t)
{
    char buf[1024];
    snprintf(buf, sizeof buf, base, t->length, t->cable_mass, t->links,
             t->body_mass, t->drag);
    ts_err err = {0};
    ts_scene *s = ts_scene_parse(buf, strlen(buf), "param.yaml", u, &err);
    if (!s)
        printf("     scene: %s\n", err.msg);
    return s;
}

/* The built systems agree bit for bit in what the kernel reads. */
static int same_system(const ts_system *a, const ts_system *b)
{
    if (a->nlinks != b->nlinks || a->nnodes != b->nnodes)
        return 0;
    for (int l = 0; l < a->nlinks; l++)
        if (a->links[l].length != b->links[l].length ||
            a->links[l].mass != b->links[l].mass ||
            a->links[l].cdn != b->links[l].cdn)
            return 0;
    for (int k = 0; k < a->nnodes; k++)
        if (a->nodes[k].mass != b->nodes[k].mass)
            return 0;
    for (int i = 0; i < a->nbodies; i++)
        if (a->bodies[i].mass != b->bodies[i].mass ||
            a->bodies[i].cd != b->bodies[i].cd)
            return 0;
    return a->tow.speed == b->tow.speed &&
           a->tow.turn_rate == b->tow.turn_rate;
}

/* Set `path` to `text` (parsed in the path's unit) in scene `from`, build,
 * and compare with scene `to`. */
static void set_like_scene(const ts_units *u, const texts *from,
                           const texts *to, const char *path,
                           const char *text)
{
    ts_scene *a = scene_of(u, from), *b = scene_of(u, to);
    ts_err err = {0};
    char unit[TS_PARAM_UNIT_MAX];
    double v = NAN;
    int rc = a && b ? ts_param_unit(a->system, path, unit, sizeof unit, &err)
                    : TS_EINVAL;
    if (!rc)
        rc = ts_units_parse(u, text, unit, path, &v, &err);
    if (!rc)
        rc = ts_param_set(a->system, path, v, &err);
    if (!rc)
        rc = ts_system_build(a->system, &err);
    CHECK(!rc && same_system(a->system, b->system),
          "%s = %s by path gives the scene with it written in (%s)", path,
          text, rc ? err.msg : "bit for bit");
    ts_scene_free(a);
    ts_scene_free(b);
}

static void test_like_scene(const ts_units *u)
{
    texts t0 = {"100", "mass_per_length: 1.5", "10", "mass: 80", "0.5"};
    texts t = t0;
    t.length = "\"250 ft\"";
    set_like_scene(u, &t0, &t, "cables.main.a.length", "250 ft");
    t = t0;
    t.cable_mass = "weight: \"1.2 lbf/ft\"";
    set_like_scene(u, &t0, &t, "cables.main.a.weight", "1.2 lbf/ft");
    t = t0;
    t.cable_mass = "wet_weight: \"3.7 N/m\"";
    set_like_scene(u, &t0, &t, "cables.main.a.wet_weight", "3.7 N/m");
    t = t0;
    t.links = "37";
    set_like_scene(u, &t0, &t, "cables.main.a.links", "37");
    t = t0;
    t.body_mass = "weight: \"612 lbf\"";
    set_like_scene(u, &t0, &t, "bodies.fish.weight", "612 lbf");
    t = t0;
    t.body_mass = "wet_weight: \"1.234 kN\"";
    set_like_scene(u, &t0, &t, "bodies.fish.wet_weight", "1.234 kN");
    t = t0;
    t.drag = "0.837";
    set_like_scene(u, &t0, &t, "bodies.fish.drag", "0.837");
}

static void test_get(const ts_units *u)
{
    texts t0 = {"100", "wet_weight: \"3.7 N/m\"", "10", "mass: 80", "0.5"};
    ts_scene *s = scene_of(u, &t0);
    if (!s)
        return;
    const ts_system *sys = s->system;
    ts_err err = {0};
    double v = NAN;
    static const struct {
        const char *path;
        double want;
    } cases[] = {{"tow.speed", 5 * 1852.0 / 3600.0},
                 {"speed", 5 * 1852.0 / 3600.0},
                 {"turn_rate", 0.05},
                 {"tow.point.z", -2},
                 {"environment.gravity", 9.81},
                 {"environment.water_density", 1025},
                 {"environment.current.y", 0},
                 {"cables.main.a.length", 100},
                 {"cables.main.a.links", 10},
                 {"cables.main.a.normal_drag", 1.3},
                 {"cables.main.a.wet_weight", 3.7},
                 {"bodies.fish.mass", 80},
                 {"bodies.fish.diameter", 0.5}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int rc = ts_param_get(sys, cases[i].path, &v, &err);
        /* The wet weight goes through mass = w / g + rho A and back:
         * rounding of a few ulps of the mass. */
        double tol = !strcmp(cases[i].path, "cables.main.a.wet_weight")
                         ? 1e-13
                         : 0.0;
        CHECK(rc == TS_OK && fabs(v - cases[i].want) <= tol,
              "get %s = %.17g (want %.17g)", cases[i].path, v,
              cases[i].want);
    }
    char unit[TS_PARAM_UNIT_MAX], canon[TS_PARAM_PATH_MAX];
    static const struct {
        const char *path, *unit;
    } units[] = {{"speed", "m/s"},
                 {"tow.turn_rate", "rad/s"},
                 {"environment.water_density", "kg/m^3"},
                 {"cables.x.EI", "N*m^2"},
                 {"cables.x.damping", "N*s/m"},
                 {"cables.x.links", "1"},
                 {"bodies.y.wet_weight", "N"},
                 {"bodies.v.loops.depth.kp", ""},
                 {"bodies.v.surfaces.elevator.limit", "rad"},
                 {"bodies.v.volume", "m^3"},
                 {"bodies.v.inertia.xy", "kg*m^2"},
                 {"bodies.v.mass_centre.z", "m"},
                 {"bodies.v.components.hull.axial_drag", "1"},
                 {"bodies.v.components.fin.position.y", "m"},
                 {"bodies.v.components.nose.drag", "1"}};
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++) {
        int rc = ts_param_unit(NULL, units[i].path, unit, sizeof unit, &err);
        CHECK(rc == TS_OK && !strcmp(unit, units[i].unit),
              "unit of %s by its form: '%s'", units[i].path, unit);
    }
    CHECK(ts_param_canonical("speed", canon, sizeof canon, &err) == TS_OK &&
              !strcmp(canon, "tow.speed"),
          "speed is short for %s", canon);
    ts_scene_free(s);
}

/* The scene format's spelling ("cables[0].length", "bodies[fish].mass",
 * "tow.point[2]") names the same values; ts_scene_set, which edits the
 * scene's text and reads it again (a route of its own), gives the system
 * ts_param_set gives, bit for bit. */
static void test_scene_spelling(const ts_units *u)
{
    texts t0 = {"100", "mass_per_length: 1.5", "10", "mass: 80", "0.5"};
    ts_scene *s = scene_of(u, &t0);
    if (!s)
        return;
    ts_err err = {0};
    static const struct {
        const char *bracket, *dotted;
    } same[] = {{"cables[0].length", "cables.main.a.length"},
                {"cables[main.a].normal_drag", "cables.main.a.normal_drag"},
                {"bodies[fish].mass", "bodies.fish.mass"},
                {"bodies[0].drag", "bodies.fish.drag"},
                {"tow.point[2]", "tow.point.z"}};
    for (size_t i = 0; i < sizeof same / sizeof same[0]; i++) {
        double a = NAN, b = NAN;
        int rc = ts_param_get(s->system, same[i].bracket, &a, &err);
        int rc2 = ts_param_get(s->system, same[i].dotted, &b, NULL);
        CHECK(rc == TS_OK && rc2 == TS_OK && a == b,
              "%s is %s (%g)", same[i].bracket, same[i].dotted, a);
    }
    char canon[TS_PARAM_PATH_MAX];
    ts_param_canonical("cables[main.a].length", canon, sizeof canon, NULL);
    CHECK(!strcmp(canon, "cables.main.a.length"), "cables[main.a].length is "
          "spelled %s", canon);
    int rc = ts_param_get(s->system, "cables[3].length", NULL, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "has no entry [3]"),
          "an index past the cables refused: %s", err.msg);
    /* Against ts_scene_set. */
    static const struct {
        const char *key, *value;
    } set[] = {{"cables[0].length", "250 ft"},
               {"bodies[fish].mass", "612 lb"},
               {"tow.speed", "3.7 knot"},
               {"cables[main.a].normal_drag", "1.45"}};
    for (size_t i = 0; i < sizeof set / sizeof set[0]; i++) {
        const char *k[1] = {set[i].key}, *v[1] = {set[i].value};
        ts_scene *b = ts_scene_set(s, 1, k, v, u, &err);
        ts_system *c = ts_system_copy(s->system, &err);
        char unit[TS_PARAM_UNIT_MAX];
        double x = NAN;
        int ok = b && c &&
                 ts_param_unit(c, set[i].key, unit, sizeof unit, &err) ==
                     TS_OK &&
                 ts_units_parse(u, set[i].value, unit, set[i].key, &x,
                                &err) == TS_OK &&
                 ts_param_set(c, set[i].key, x, &err) == TS_OK &&
                 ts_system_build(c, &err) == TS_OK &&
                 same_system(b->system, c);
        CHECK(ok, "%s = %s: ts_param_set and ts_scene_set give one system, "
              "bit for bit (%s)", set[i].key, set[i].value,
              ok ? "ok" : err.msg);
        ts_scene_free(b);
        ts_system_free(c);
    }
    ts_scene_free(s);
}

/* Every refusal names the path and says what is expected. */
static void test_errors(const ts_units *u)
{
    texts t0 = {"100", "mass_per_length: 1.5", "10", "mass: 80", "0.5"};
    ts_scene *s = scene_of(u, &t0);
    if (!s)
        return;
    ts_system *sys = s->system;
    static const struct {
        const char *path;
        double value;
        const char *says;
    } bad[] = {
        {"cables.main.a.length", -3, "cables.main.a.length: must be > 0 m"},
        {"cables.main.a.length", NAN, "cables.main.a.length: expected a finite number in m"},
        {"cables.main.a.links", 2.5, "whole number of links"},
        {"cables.main.a.links", 0, "must be >= 1"},
        {"cables.main.a.wet_weight", -100, "negative mass in air"},
        {"cables.main.b.length", 1, "the cables: main.a"},
        {"cables.main.a.lenght", 1, "expected one of length, diameter"},
        {"bodies.fsh.mass", 1, "the bodies: fish"},
        {"bodies.fish.mass", -1, "bodies.fish.mass: must be >= 0 kg"},
        {"bodies.fish.loops.depth.kp", 1, "'fish' is not a vehicle"},
        {"tow.point", 1, "name an entry: point.x|y|z"},
        {"tow.speed", -2, "tow.speed: must be >= 0 m/s"},
        {"ship.speed", 1, "not a path of the scene"},
        {"", 1, "path: empty"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ts_err err = {0};
        double before = NAN;
        ts_param_get(sys, bad[i].path, &before, NULL);
        int rc = ts_param_set(sys, bad[i].path, bad[i].value, &err);
        double after = NAN;
        ts_param_get(sys, bad[i].path, &after, NULL);
        CHECK(rc == TS_EINVAL && strstr(err.msg, bad[i].says) &&
                  (isnan(before) || before == after),
              "refused, nothing set: %s", err.msg);
    }
    /* A cable with link_lengths keeps them. */
    sys->cables[0].link_fraction = calloc(10, sizeof(double));
    ts_err err = {0};
    int rc = ts_param_set(sys, "cables.main.a.links", 20, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "has link_lengths"),
          "links of a cable with link_lengths refused: %s", err.msg);
    /* Without gravity a weight gives no mass. */
    sys->env.gravity = 0;
    rc = ts_param_set(sys, "bodies.fish.weight", 100, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "without gravity"),
          "weight without gravity refused: %s", err.msg);
    ts_scene_free(s);
}

/* Loops and surfaces of a vehicle, by name; units from what the loop
 * measures. */
/* A system of one vehicle 'fish' with a depth loop and a pitch loop
 * (named so), without components; *v its vehicle. */
static ts_system *fish_loops(ts_vehicle **v, ts_err *err)
{
    ts_system *s = ts_system_alloc(1, 1, err);
    snprintf(s->bodies[0].name, TS_NAME_MAX, "fish");
    *v = ts_body_set_vehicle(s, 0, err);
    (*v)->nloops = 2;
    snprintf((*v)->loop[0].name, TS_VEHICLE_NAME_MAX, "depth");
    (*v)->loop[0].measure = TS_MEASURE_DEPTH;
    snprintf((*v)->loop[1].name, TS_VEHICLE_NAME_MAX, "pitch");
    (*v)->loop[1].measure = TS_MEASURE_PITCH;
    return s;
}

static void test_vehicle(void)
{
    ts_err err = {0};
    ts_vehicle *v;
    ts_system *s = fish_loops(&v, &err);
    v->ncomponents = 2;
    snprintf(v->component[0].name, TS_VEHICLE_NAME_MAX, "hull");
    v->component[0].type = TS_COMP_HULL;
    snprintf(v->component[1].name, TS_VEHICLE_NAME_MAX, "elevator");
    v->component[1].type = TS_COMP_SURFACE;
    v->component[1].limit = 0.3;
    v->loop[0].kp = 0.25;
    char unit[TS_PARAM_UNIT_MAX];
    double x = NAN;
    int rc = ts_param_get(s, "bodies.fish.loops.depth.kp", &x, &err);
    CHECK(rc == TS_OK && x == 0.25, "depth loop kp read: %g", x);
    rc = ts_param_unit(s, "bodies.fish.loops.depth.kd", unit, sizeof unit,
                       &err);
    CHECK(rc == TS_OK && !strcmp(unit, "rad*s/m"),
          "a depth loop's kd is in %s", unit);
    rc = ts_param_unit(s, "bodies.fish.loops.pitch.kp", unit, sizeof unit,
                       &err);
    CHECK(rc == TS_OK && !strcmp(unit, "1"), "a pitch loop's kp is in '%s'",
          unit);
    rc = ts_param_set(s, "bodies.fish.loops.pitch.kd", -1.75, &err);
    CHECK(rc == TS_OK && v->loop[1].kd == -1.75, "pitch loop kd set: %g",
          v->loop[1].kd);
    rc = ts_param_set(s, "bodies[fish].components[elevator].area", 0.035,
                      &err);
    CHECK(rc == TS_OK && v->component[1].area == 0.035,
          "elevator area set, the scene format's spelling: %g m^2",
          v->component[1].area);
    rc = ts_param_set(s, "bodies.fish.surfaces.elevator.limit", 0.2, &err);
    CHECK(rc == TS_OK && v->component[1].limit == 0.2,
          "elevator limit set: %g rad", v->component[1].limit);
    rc = ts_param_set(s, "bodies.fish.surfaces.hull.limit", 0.2, &err);
    CHECK(rc == TS_EINVAL &&
              strstr(err.msg, "no key 'limit' of a hull; expected one of "
                              "position.x|y|z, length, diameter"),
          "the hull is no surface, its keys listed: %s", err.msg);
    rc = ts_param_set(s, "bodies.fish.components.fin.area", 0.2, &err);
    CHECK(rc == TS_EINVAL &&
              strstr(err.msg, "its components: hull (hull), elevator "
                              "(surface)"),
          "no fin, the components listed: %s", err.msg);
    /* A vehicle's own keys, an inertia's entry and a vector's. */
    rc = ts_param_set(s, "bodies.fish.inertia.xz", -0.5, &err);
    CHECK(rc == TS_OK && v->inertia[4] == -0.5, "inertia.xz (Ixz) set: %g",
          v->inertia[4]);
    rc = ts_param_set(s, "bodies[fish].inertia[1]", 7.5, &err);
    CHECK(rc == TS_OK && v->inertia[1] == 7.5,
          "inertia[1] (Iyy), the scene format's spelling: %g", v->inertia[1]);
    rc = ts_param_set(s, "bodies.fish.attach.z", -0.25, &err);
    CHECK(rc == TS_OK && v->attach[2] == -0.25, "attach.z set: %g",
          v->attach[2]);
    rc = ts_param_set(s, "bodies.fish.components.elevator.position.x", -1.1,
                      &err);
    CHECK(rc == TS_OK && v->component[1].position[0] == -1.1,
          "a surface's position.x set: %g", v->component[1].position[0]);
    rc = ts_param_set(s, "bodies.fish.volum", 0.2, &err);
    CHECK(rc == TS_EINVAL &&
              strstr(err.msg, "bodies.fish.volum: no key 'volum' of a "
                              "vehicle; expected one of mass, weight, "
                              "wet_weight, volume, inertia.xx|yy|zz|xy|xz|yz"),
          "an unknown vehicle key lists the accepted ones: %s", err.msg);
    rc = ts_param_set(s, "bodies.fish.diameter", 0.2, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "no key 'diameter' of a "
                                             "vehicle"),
          "a sphere's key is not a vehicle's: %s", err.msg);
    rc = ts_param_set(s, "bodies.fish.inertia", 1, &err);
    CHECK(rc == TS_EINVAL &&
              strstr(err.msg, "name an entry: inertia.xx|yy|zz|xy|xz|yz"),
          "the inertia without an entry: %s", err.msg);
    rc = ts_param_set(s, "bodies.fish.loops.roll.kp", 1, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "its loops: depth, pitch"),
          "no roll loop: %s", err.msg);
    ts_system_free(s);
}

/* A vehicle's controllers and components by the scene's own words
 * (bodies.aurora.controllers.depth.kp, as the scene writes `controllers`):
 * each value set by path equals the same text written in the scene
 * (ts_scene_set) to the last digit of an equilibrium and a modes run. */
static void test_scene_words(const ts_units *u)
{
    ts_err err = {0};
    ts_scene *sc = ts_scene_load("examples/aurora_towfish.yaml", u, &err);
    if (!CHECK(sc != NULL, "the AURORA scene loads (%s)", err.msg))
        return;
    static const struct {
        const char *path, *key, *text;
    } cases[] = {
        {"bodies.aurora.controllers.depth.kp",
         "bodies[aurora].controllers[depth].kp", "0.12 rad/m"},
        {"bodies.aurora.controllers.pitch.kd",
         "bodies[aurora].controllers[pitch].kd", "0.45 s"},
        {"bodies.aurora.controllers.depth.setpoint",
         "bodies[aurora].controllers[depth].setpoint", "35 m"},
        {"bodies.aurora.components.wing.area",
         "bodies[aurora].components[wing].area", "0.55 m^2"},
        {"bodies.aurora.components.tail1.time_constant",
         "bodies[aurora].components[tail1].time_constant", "0.15 s"},
        {"bodies.aurora.inertia.yy", "bodies[aurora].inertia[1]",
         "80 kg*m^2"},
        {"bodies.aurora.mass_centre.z", "bodies[aurora].mass_centre[2]",
         "0.03 m"},
        {"bodies.aurora.buoyancy_centre.x",
         "bodies[aurora].buoyancy_centre[0]", "0.05 m"},
        {"bodies.aurora.attach.x", "bodies[aurora].attach[0]", "0.6 m"},
        {"bodies.aurora.components.wing.position.x",
         "bodies[aurora].components[wing].position[0]", "0.2 m"},
        /* The hull's: the spheroid added mass (and the surface diameter)
         * follow it, as the scene reader derives them. */
        {"bodies.aurora.components.hull.length",
         "bodies[aurora].components[hull].length", "2.4 m"},
        {"bodies.aurora.components.hull.diameter",
         "bodies[aurora].components[hull].diameter", "0.38 m"},
        {"bodies.aurora.components.hull.cross_drag",
         "bodies[aurora].components[hull].cross_drag", "1.0"},
    };
    /* The scene as written, to see each setting change the run. */
    ts_request r0;
    ts_request_init(&r0, TS_ANALYSIS_MODES);
    r0.setup.discretisation_error = 0;
    ts_result *base_run = NULL;
    if (ts_analysis_run(sc->system, &r0, &base_run, &err) != TS_OK) {
        CHECK(0, "the AURORA modes run (%s)", err.msg);
        ts_result_free(base_run);
        ts_scene_free(sc);
        return;
    }
    char canon[TS_PARAM_PATH_MAX];
    int rc = ts_param_canonical(cases[0].path, canon, sizeof canon, &err);
    CHECK(rc == TS_OK && !strcmp(canon, "bodies.aurora.loops.depth.kp"),
          "controllers is the loops' word in the scene: %s", canon);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char unit[TS_PARAM_UNIT_MAX];
        double x = NAN;
        rc = ts_param_unit(sc->system, cases[i].path, unit, sizeof unit,
                           &err);
        if (!rc)
            rc = ts_units_parse(u, cases[i].text, unit, cases[i].path, &x,
                                &err);
        ts_request rq;
        ts_request_init(&rq, TS_ANALYSIS_MODES);
        rq.setup.discretisation_error = 0;
        if (!rc)
            rc = ts_setup_set(&rq.setup, cases[i].path, x, &err);
        const char *key = cases[i].key, *text = cases[i].text;
        ts_scene *t = rc ? NULL
                         : ts_scene_set(sc, 1, &key, &text, u, &err);
        ts_request rt;
        ts_request_init(&rt, TS_ANALYSIS_MODES);
        rt.setup.discretisation_error = 0;
        ts_result *a = NULL, *b = NULL;
        int ok = t && ts_analysis_run(sc->system, &rq, &a, &err) == TS_OK &&
                 ts_analysis_run(t->system, &rt, &b, &err) == TS_OK;
        int same = ok && a->eigen && b->eigen &&
                   a->eigen->nmodes == b->eigen->nmodes;
        for (int k = 0; same && k < a->nvalues; k++)
            same = a->values[k].value == b->values[k].value;
        for (int m = 0; same && m < a->eigen->nmodes; m++)
            same = a->eigen->modes[m].re == b->eigen->modes[m].re &&
                   a->eigen->modes[m].im == b->eigen->modes[m].im;
        int changed = 0;
        for (int m = 0; same && m < a->eigen->nmodes &&
                        m < base_run->eigen->nmodes; m++)
            changed |= a->eigen->modes[m].re != base_run->eigen->modes[m].re;
        CHECK(same && changed, "%s = %s (%.17g %s) by path gives the modes "
              "run of the scene with %s: %s to the last digit, and not the "
              "scene's as written (%s)", cases[i].path, text, x, unit, key,
              same ? "the same" : "NOT the same", err.msg);
        ts_result_free(a);
        ts_result_free(b);
        ts_scene_free(t);
    }
    ts_result_free(base_run);

    /* One key table: a value beyond a key's limit is refused by path and
     * in the scene's text with the same limit and unit. */
    static const struct {
        const char *path, *key, *text, *limit;
    } lim[] = {
        {"cables.armoured.length", "cables[armoured].length", "-1",
         "must be > 0 m, got -1 m"},
        {"cables.armoured.EA", "cables[armoured].EA", "-5",
         "must be >= 0 N, got -5 N"},
        {"tow.speed", "tow.speed", "-1", "must be >= 0 m/s, got -1 m/s"},
        {"environment.water_density", "environment.water_density", "-1",
         "must be >= 0 kg/m^3, got -1 kg/m^3"},
        {"bodies.aurora.components.wing.limit",
         "bodies[aurora].components[wing].limit", "0",
         "must be > 0 rad, got 0 rad"},
        {"bodies.aurora.components.wing.area",
         "bodies[aurora].components[wing].area", "0",
         "must be > 0 m^2, got 0 m^2"},
        {"bodies.aurora.components.wing.rate_limit",
         "bodies[aurora].components[wing].rate_limit", "0",
         "must be > 0 rad/s, got 0 rad/s"},
        {"bodies.aurora.volume", "bodies[aurora].volume", "-1",
         "must be >= 0 m^3, got -1 m^3"},
        {"bodies.aurora.components.hull.length",
         "bodies[aurora].components[hull].length", "0",
         "must be > 0 m, got 0 m"},
        {"bodies.aurora.components.hull.axial_drag",
         "bodies[aurora].components[hull].axial_drag", "-1",
         "must be >= 0, got -1"},
    };
    for (size_t i = 0; i < sizeof lim / sizeof lim[0]; i++) {
        ts_err e1 = {0}, e2 = {0};
        ts_system *copy = ts_system_copy(sc->system, &e1);
        int r1 = copy ? ts_param_set(copy, lim[i].path, atof(lim[i].text),
                                     &e1)
                      : TS_ENOMEM;
        ts_system_free(copy);
        const char *key = lim[i].key, *text = lim[i].text;
        ts_scene *t = ts_scene_set(sc, 1, &key, &text, u, &e2);
        CHECK(r1 == TS_EINVAL && !t && strstr(e1.msg, lim[i].limit) &&
                  strstr(e2.msg, lim[i].limit),
              "%s = %s refused alike by path (%s) and in the scene (%s)",
              lim[i].path, text, e1.msg, e2.msg);
        ts_scene_free(t);
    }
    /* A hull shorter than its diameter has no spheroid estimate: refused,
     * the length and the added mass as they were. */
    {
        ts_err e = {0};
        ts_system *copy = ts_system_copy(sc->system, &e);
        ts_vehicle *v = copy ? copy->bodies[0].vehicle : NULL;
        double A11 = v ? v->added_mass[0] : NAN, L = NAN;
        int r = v ? ts_param_set(copy, "bodies.aurora.components.hull.length",
                                 0.3, &e)
                  : TS_ENOMEM;
        if (v)
            ts_param_get(copy, "bodies.aurora.components.hull.length", &L,
                         NULL);
        CHECK(r == TS_EINVAL && strstr(e.msg, "the added mass of vehicle "
                                              "'aurora'") &&
                  L == 2.6 && v->added_mass[0] == A11,
              "a hull of 0.3 m (diameter 0.35 m) refused, nothing changed: "
              "%s", e.msg);
        ts_system_free(copy);
    }
    ts_scene_free(sc);
}

/* Run `kind` on sys at 10 links with the settings of `set` (path,
 * value; NULL for none), no discretisation estimate. */
static ts_result *towing_run(const ts_system *sys, ts_analysis_kind kind,
                             const char *path, double value, ts_err *err)
{
    ts_request rq;
    ts_request_init(&rq, kind);
    rq.setup.discretisation_error = 0;
    rq.setup.links = 10;
    ts_result *r = NULL;
    if (path && ts_setup_set(&rq.setup, path, value, err) != TS_OK)
        return NULL;
    if (ts_analysis_run(sys, &rq, &r, err) != TS_OK) {
        ts_result_free(r);
        return NULL;
    }
    return r;
}

/* Results a and b agree to the last digit: key values, equilibrium
 * positions and controller states, eigenvalues. */
static int same_result(const ts_result *a, const ts_result *b)
{
    if (!a || !b || a->nvalues != b->nvalues)
        return 0;
    for (int k = 0; k < a->nvalues; k++)
        if (memcmp(&a->values[k].value, &b->values[k].value,
                   sizeof(double)))
            return 0;
    if (a->eq && b->eq) {
        if (a->eq->nnodes != b->eq->nnodes ||
            a->eq->ncontrol != b->eq->ncontrol ||
            memcmp(a->eq->positions, b->eq->positions,
                   3 * (size_t)a->eq->nnodes * sizeof(double)) ||
            (a->eq->ncontrol &&
             memcmp(a->eq->controls, b->eq->controls,
                    (size_t)a->eq->ncontrol * sizeof(double))))
            return 0;
    }
    if (!a->eigen != !b->eigen)
        return 0;
    if (a->eigen) {
        if (a->eigen->nmodes != b->eigen->nmodes)
            return 0;
        for (int m = 0; m < a->eigen->nmodes; m++)
            if (a->eigen->modes[m].re != b->eigen->modes[m].re ||
                a->eigen->modes[m].im != b->eigen->modes[m].im)
                return 0;
    }
    return 1;
}

/* Results a and b differ somewhere (the setting changed the run). */
static int changed_result(const ts_result *a, const ts_result *b)
{
    int d = 0;
    for (int k = 0; k < a->nvalues && k < b->nvalues; k++)
        d |= a->values[k].value != b->values[k].value;
    for (int m = 0; a->eigen && b->eigen && m < a->eigen->nmodes &&
                    m < b->eigen->nmodes; m++)
        d |= a->eigen->modes[m].re != b->eigen->modes[m].re;
    return d;
}

/* The towing vehicle's values by path (towing_vehicle.<key>): each set by
 * path gives the run of the scene with the same text written in at that
 * key (ts_scene_set) to the last digit, on DOLPHIN-AURORA with each of
 * its three propulsion laws; a static key by the equilibrium, an inertia
 * or a gain by the modes. Keys of another law, the vehicle's "attach"
 * (the scene says tow_point), a towing vehicle named as a body, and
 * towing_vehicle in a scene without one are refused by name. */
static void test_towing_paths(const ts_units *u)
{
    ts_err err = {0};
    ts_scene *sc = ts_scene_load("examples/dolphin_aurora.yaml", u, &err);
    if (!CHECK(sc != NULL, "the DOLPHIN-AURORA scene loads (%s)", err.msg))
        return;
    /* The same scene with constant power and with a PI speed
     * controller. */
    const char *pk = "towing_vehicle.propulsion";
    const char *power = "{power: \"22 kW\", max_thrust: \"9000 N\", "
                        "at: [\"-4 m\", 0, 0]}";
    const char *speed = "{speed: \"5 m/s\", gain: \"900 N*s/m\", "
                        "integral_gain: \"40 N/m\", max_thrust: "
                        "\"9000 N\", at: [\"-4 m\", 0, 0]}";
    ts_scene *scenes[3] = {sc, ts_scene_set(sc, 1, &pk, &power, u, &err),
                           ts_scene_set(sc, 1, &pk, &speed, u, &err)};
    CHECK(scenes[1] && scenes[2], "the power and speed laws written in "
          "(%s)", err.msg);
    enum { EQ = TS_ANALYSIS_EQUILIBRIUM, MO = TS_ANALYSIS_MODES };
    static const struct {
        int scene, kind;
        const char *path, *key, *text;
    } cases[] = {
        {0, EQ, "towing_vehicle.mass", "towing_vehicle.mass", "4100 kg"},
        {0, EQ, "towing_vehicle.volume", "towing_vehicle.volume",
         "3.9 m^3"},
        {0, MO, "towing_vehicle.inertia.yy", "towing_vehicle.inertia[1]",
         "16000 kg*m^2"},
        {0, EQ, "towing_vehicle.mass_centre.z",
         "towing_vehicle.mass_centre[2]", "0.15 m"},
        {0, EQ, "towing_vehicle.buoyancy_centre.x",
         "towing_vehicle.buoyancy_centre[0]", "0.02 m"},
        {0, EQ, "towing_vehicle.tow_point.z", "towing_vehicle.tow_point[2]",
         "1.0 m"},
        {0, EQ, "towing_vehicle.components.hull.length",
         "towing_vehicle.components[hull].length", "8.2 m"},
        {0, EQ, "towing_vehicle.components.keel.area",
         "towing_vehicle.components[keel].area", "0.65 m^2"},
        {0, EQ, "towing_vehicle.components.mast.drag",
         "towing_vehicle.components[mast].drag", "0.137"},
        {0, EQ, "towing_vehicle.controllers.depth.setpoint",
         "towing_vehicle.controllers[depth].setpoint", "2.4 m"},
        {0, MO, "towing_vehicle.controllers.depth.kp",
         "towing_vehicle.controllers[depth].kp", "0.12 rad/m"},
        {0, EQ, "towing_vehicle.propulsion.thrust",
         "towing_vehicle.propulsion.thrust", "4200 N"},
        {0, EQ, "towing_vehicle.propulsion.at.z",
         "towing_vehicle.propulsion.at[2]", "0.2 m"},
        {1, EQ, "towing_vehicle.propulsion.power",
         "towing_vehicle.propulsion.power", "20 kW"},
        {1, EQ, "towing_vehicle.propulsion.max_thrust",
         "towing_vehicle.propulsion.max_thrust", "4400 N"},
        {2, EQ, "towing_vehicle.propulsion.speed",
         "towing_vehicle.propulsion.speed", "4.5 m/s"},
        {2, MO, "towing_vehicle.propulsion.gain",
         "towing_vehicle.propulsion.gain", "1200 N*s/m"},
        {2, MO, "towing_vehicle.propulsion.integral_gain",
         "towing_vehicle.propulsion.integral_gain", "60 N/m"},
    };
    ts_result *base[3][2] = {{NULL}};
    for (size_t i = 0; scenes[1] && scenes[2] &&
                       i < sizeof cases / sizeof cases[0]; i++) {
        int s = cases[i].scene, kind = cases[i].kind;
        const ts_system *sys = scenes[s]->system;
        int bk = kind == MO;
        if (!base[s][bk])
            base[s][bk] = towing_run(sys, kind, NULL, 0, &err);
        char unit[TS_PARAM_UNIT_MAX];
        double x = NAN;
        int rc = ts_param_unit(sys, cases[i].path, unit, sizeof unit, &err);
        if (!rc)
            rc = ts_units_parse(u, cases[i].text, unit, cases[i].path, &x,
                                &err);
        const char *key = cases[i].key, *text = cases[i].text;
        ts_scene *t = rc ? NULL
                         : ts_scene_set(scenes[s], 1, &key, &text, u, &err);
        ts_result *a = t ? towing_run(sys, kind, cases[i].path, x, &err)
                         : NULL;
        ts_result *b = a ? towing_run(t->system, kind, NULL, 0, &err) : NULL;
        int same = same_result(a, b);
        int changed = same && base[s][bk] && changed_result(a, base[s][bk]);
        CHECK(same && changed, "%s = %s (%.17g %s) by path gives the %s run "
              "of the scene with %s: %s to the last digit, and not the "
              "scene's as written (%s)", cases[i].path, text, x, unit,
              kind == MO ? "modes" : "equilibrium", key,
              same ? "the same" : "NOT the same", err.msg);
        ts_result_free(a);
        ts_result_free(b);
        ts_scene_free(t);
    }
    for (int s = 0; s < 3; s++)
        for (int k = 0; k < 2; k++)
            ts_result_free(base[s][k]);

    /* Refusals, by path and alike in the scene's text where the scene has
     * the key (one key table). */
    static const struct {
        int scene;
        const char *path, *key, *text, *says;
    } bad[] = {
        {1, "towing_vehicle.propulsion.power",
         "towing_vehicle.propulsion.power", "0", "must be > 0 W, got 0 W"},
        {2, "towing_vehicle.propulsion.speed",
         "towing_vehicle.propulsion.speed", "-1",
         "must be > 0 m/s, got -1 m/s"},
        {2, "towing_vehicle.propulsion.gain",
         "towing_vehicle.propulsion.gain", "-1",
         "must be >= 0 N*s/m, got -1 N*s/m"},
        {2, "towing_vehicle.propulsion.max_thrust",
         "towing_vehicle.propulsion.max_thrust", "0",
         "must be > 0 N, got 0 N"},
        {0, "towing_vehicle.volume", "towing_vehicle.volume", "-1",
         "must be >= 0 m^3, got -1 m^3"},
    };
    for (size_t i = 0; scenes[1] && scenes[2] &&
                       i < sizeof bad / sizeof bad[0]; i++) {
        ts_err e1 = {0}, e2 = {0};
        ts_system *copy = ts_system_copy(scenes[bad[i].scene]->system, &e1);
        int r1 = copy ? ts_param_set(copy, bad[i].path, atof(bad[i].text),
                                     &e1)
                      : TS_ENOMEM;
        ts_system_free(copy);
        const char *key = bad[i].key, *text = bad[i].text;
        ts_scene *t = ts_scene_set(scenes[bad[i].scene], 1, &key, &text, u,
                                   &e2);
        CHECK(r1 == TS_EINVAL && !t && strstr(e1.msg, bad[i].says) &&
                  strstr(e2.msg, bad[i].says),
              "%s = %s refused alike by path (%s) and in the scene (%s)",
              bad[i].path, text, e1.msg, e2.msg);
        ts_scene_free(t);
    }
    static const struct {
        int scene;
        const char *path, *says;
    } refused[] = {
        {0, "towing_vehicle.propulsion.power",
         "propulsion is thrust, which has no 'power'; its keys: thrust, "
         "at.x|y|z"},
        {1, "towing_vehicle.propulsion.gain",
         "which has no 'gain'; its keys: power, max_thrust, at.x|y|z"},
        {2, "towing_vehicle.propulsion.thrust", "which has no 'thrust'"},
        {0, "towing_vehicle.attach.x",
         "no key 'attach.x' of the towing vehicle; expected one of mass, "
         "weight, wet_weight, volume"},
        {0, "towing_vehicle.drag", "tow_point.x|y|z"},
        {0, "towing_vehicle.propulsion.torque",
         "no key 'torque' of the propulsion; expected one of thrust, "
         "power, speed, max_thrust, gain, integral_gain, at.x|y|z"},
        {0, "towing_vehicle.tow_point", "'tow_point' is a vector; name an "
         "entry: tow_point.x|y|z"},
        {0, "towing_vehicle.controllers.heading.kp",
         "vehicle 'dolphin' has no loop 'heading'; its loops: depth"},
        /* Every kind of component named, a mast and ballast tanks
         * among them. */
        {0, "towing_vehicle.components.fin.area",
         "vehicle 'dolphin' has no component 'fin'; its components: hull "
         "(hull), mast (mast), mast_wave (bluff)"},
        {0, "towing_vehicle.components.fin.area",
         "ballast_front (ballast tank), ballast_rear (ballast tank)"},
        {0, "bodies.dolphin.mass", "'dolphin' is the towing vehicle; its "
         "values are towing_vehicle.<key> (towing_vehicle.mass)"},
        {0, "towing_vehicle.propulsion.thrust", NULL},
    };
    for (size_t i = 0; scenes[1] && scenes[2] &&
                       i < sizeof refused / sizeof refused[0]; i++) {
        ts_err e = {0};
        ts_system *copy = ts_system_copy(scenes[refused[i].scene]->system,
                                         &e);
        int r = copy ? ts_param_set(copy, refused[i].path, 1.0, &e)
                     : TS_ENOMEM;
        ts_system_free(copy);
        if (!refused[i].says)
            CHECK(r == TS_OK, "%s of the thrust law is set (%s)",
                  refused[i].path, e.msg);
        else
            CHECK(r == TS_EINVAL && strstr(e.msg, refused[i].path) &&
                      strstr(e.msg, refused[i].says),
                  "%s refused: %s", refused[i].path, e.msg);
    }
    {
        ts_scene *fish = ts_scene_load("examples/aurora_towfish.yaml", u,
                                       &err);
        ts_err e = {0};
        int r = fish ? ts_param_set(fish->system, "towing_vehicle.mass", 1,
                                    &e)
                     : TS_EINVAL;
        CHECK(r == TS_EINVAL && strstr(e.msg, "the scene has no "
                                              "towing_vehicle"),
              "towing_vehicle.mass without one: %s", e.msg);
        ts_scene_free(fish);
    }
    /* By form only (a sweep's canonical path): the scene's words. */
    char canon[TS_PARAM_PATH_MAX];
    int rc = ts_param_canonical("towing_vehicle.controllers[depth].kp",
                                canon, sizeof canon, &err);
    CHECK(rc == TS_OK && !strcmp(canon, "towing_vehicle.loops.depth.kp"),
          "towing_vehicle.controllers[depth].kp by form: %s", canon);
    rc = ts_param_canonical("towing_vehicle.propulsion.at[2]", canon,
                            sizeof canon, &err);
    CHECK(rc == TS_OK && !strcmp(canon, "towing_vehicle.propulsion.at.z"),
          "towing_vehicle.propulsion.at[2] by form: %s", canon);
    for (int s = 2; s >= 0; s--)
        ts_scene_free(scenes[s]);
}

/* A loop's gains and setpoint with a unit: without the system, in the
 * unit of a depth loop or of an angle loop, whichever the value's
 * dimension fits (a plain number stays SI, unit ""); with it, in the
 * loop's own; a unit the loop does not take refused, naming the path,
 * what the loop measures and the unit expected. */
static void test_loop_units(const ts_units *u)
{
    static const struct {
        const char *path, *text, *unit;
        double value;
    } ok[] = {
        {"bodies.fish.loops.depth.setpoint", "400 ft", "m", 121.92},
        {"bodies.fish.loops.depth.setpoint", "40", "", 40},
        {"bodies.fish.loops.pitch.setpoint", "5 deg", "rad", 5 * M_PI / 180},
        {"bodies.fish.loops.depth.kp", "2 deg/m", "rad/m", 2 * M_PI / 180},
        {"bodies.fish.loops.pitch.kp", "0.5 deg/deg", "1", 0.5},
        {"bodies.fish.loops.depth.ki", "0.1 deg/(m*s)", "rad/(m*s)",
         0.1 * M_PI / 180},
        {"bodies.fish.loops.pitch.ki", "6 1/min", "1/s", 0.1},
        {"bodies.fish.loops.depth.kd", "1 deg*s/m", "rad*s/m", M_PI / 180},
        {"bodies.fish.controllers.pitch.kd", "200 ms", "s", 0.2},
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        ts_err err = {0};
        char unit[TS_PARAM_UNIT_MAX] = "?";
        double x = NAN;
        int rc = ts_param_parse(NULL, u, ok[i].path, ok[i].text, NULL, &x,
                                unit, sizeof unit, &err);
        CHECK(rc == TS_OK && !strcmp(unit, ok[i].unit) &&
                  fabs(x - ok[i].value) <= 1e-12 * fabs(ok[i].value),
              "%s = '%s' without the system: %.12g in '%s' (%s)",
              ok[i].path, ok[i].text, x, unit, rc ? err.msg : "ok");
    }
    static const struct {
        const char *text;
        int code;
    } bad[] = {{"5 kg", TS_EUNIT}, {"abc", TS_EINVAL}, {"nan", TS_EINVAL},
               {"5 furlongz", TS_EUNIT}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ts_err err = {0};
        char unit[TS_PARAM_UNIT_MAX];
        double x;
        int rc = ts_param_parse(NULL, u, "bodies.fish.loops.depth.setpoint",
                                bad[i].text, "--set: x", &x, unit,
                                sizeof unit, &err);
        CHECK(rc == bad[i].code && strstr(err.msg, "--set: x: ") &&
                  strstr(err.msg, "m for depth or rad for an angle") &&
                  strstr(err.msg, bad[i].text),
              "setpoint '%s' refused without the system: %s", bad[i].text,
              err.msg);
    }
    /* A key whose unit is its own: taken in it, named. */
    {
        ts_err err = {0};
        char unit[TS_PARAM_UNIT_MAX];
        double x = NAN;
        int rc = ts_param_parse(NULL, u, "cables.main.length", "100 ft",
                                NULL, &x, unit, sizeof unit, &err);
        CHECK(rc == TS_OK && !strcmp(unit, "m") && fabs(x - 30.48) < 1e-12,
              "cables.main.length = '100 ft': %.12g %s", x, unit);
    }

    ts_err err = {0};
    ts_vehicle *v;
    ts_system *s = fish_loops(&v, &err);
    /* With the system: the loop's unit, and only it. */
    char unit[TS_PARAM_UNIT_MAX];
    double x = NAN;
    int rc = ts_param_parse(s, u, "bodies.fish.loops.pitch.setpoint",
                            "5 deg", NULL, &x, unit, sizeof unit, &err);
    CHECK(rc == TS_OK && !strcmp(unit, "rad") &&
              fabs(x - 5 * M_PI / 180) < 1e-15,
          "a pitch setpoint of '5 deg' with the system: %g %s", x, unit);
    rc = ts_param_parse(s, u, "bodies.fish.loops.pitch.setpoint", "400 m",
                        NULL, &x, unit, sizeof unit, &err);
    CHECK(rc == TS_EUNIT, "a pitch setpoint of '400 m' with the system "
                          "refused: %s", err.msg);
    /* The check once the system is known. */
    static const struct {
        const char *path, *unit, *given, *want[3];
    } mis[] = {
        {"bodies.fish.loops.pitch.setpoint", "m", "400 m",
         {"'400 m' is in m", "loop 'pitch' of vehicle 'fish' measures "
          "pitch", "expected rad"}},
        {"bodies.fish.loops.depth.setpoint", "rad", "5 deg",
         {"'5 deg' is in rad", "measures depth", "expected m (e.g. '40 m')"}},
        {"bodies.fish.loops.depth.kp", "1", "0.5 deg/deg",
         {"bodies.fish.loops.depth.kp", "measures depth", "expected rad/m"}},
        {"bodies.fish.loops.pitch.kp", "rad/m", NULL,
         {"the value is in rad/m", "measures pitch",
          "expected a plain number"}},
        {"bodies.fish.loops.pitch.kd", "rad*s/m", "1 deg*s/m",
         {"bodies.fish.loops.pitch.kd", "measures pitch", "expected s"}},
    };
    for (size_t i = 0; i < sizeof mis / sizeof mis[0]; i++) {
        rc = ts_param_fits(s, mis[i].path, mis[i].unit, mis[i].given, &err);
        CHECK(rc == TS_EUNIT && !strncmp(err.msg, mis[i].path,
                                         strlen(mis[i].path)) &&
                  strstr(err.msg, mis[i].want[0]) &&
                  strstr(err.msg, mis[i].want[1]) &&
                  strstr(err.msg, mis[i].want[2]),
              "%s in %s refused: %s", mis[i].path, mis[i].unit, err.msg);
    }
    rc = ts_param_fits(s, "bodies.fish.loops.depth.setpoint", "m", "40 m",
                       &err);
    int rc2 = ts_param_fits(s, "bodies.fish.loops.pitch.kp", "", "2", &err);
    int rc3 = ts_param_fits(s, "bodies.fish.loops.pitch.kd", "s", NULL, &err);
    CHECK(rc == TS_OK && rc2 == TS_OK && rc3 == TS_OK,
          "the loop's own unit, and a plain number, fit");
    ts_system_free(s);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    CHECK(u != NULL, "units load (%s)", u ? "ok" : err.msg);
    if (u) {
        test_like_scene(u);
        test_get(u);
        test_errors(u);
        test_scene_spelling(u);
        test_scene_words(u);
        test_towing_paths(u);
        test_loop_units(u);
    }
    test_vehicle();
    ts_units_free(u);
    return tc_done();
}
