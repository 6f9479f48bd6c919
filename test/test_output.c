/* test_output.c: output channels by name (towstab/output.h).
 *
 *  1. Names: every kind is found with its canonical name, SI unit and
 *     index (a body's name for the link ending at it, <cable>.<k>, the
 *     tow force and its components, an elastic cable's strain and
 *     length); each refusal names the fault (no such node, rigid links do
 *     not stretch, tow is an input, an unknown suffix, a kind the caller
 *     does not take) and lists the valid names of the kinds asked for.
 *  2. Values from one state: positions, tensions and the tow force read
 *     back; the size of the tow force is the hypot of its components;
 *     strains and the stretched length against a hand-made state in
 *     which link 2 of an elastic cable of 3 links is stretched by 2.385 %
 *     (the others straight at their length): strain 0.02385 to 1e-13,
 *     length 3 l + 0.02385 l; NAN for arrays that are missing.
 */
#include "towstab/output.h"

#include <math.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/scene.h"
#include "towstab/units.h"

static const char *yaml =
    "name: outputs\n"
    "tow: {speed: 2, point: [0, 0, 0]}\n"
    "cables:\n"
    "  - {name: tow_cable, from: tow, to: fish, length: 30, diameter: 0.02,\n"
    "     mass_per_length: 1.1, links: 3, EA: 2e5, damping: 100}\n"
    "  - {name: tail, from: fish, length: 12, diameter: 0.01,\n"
    "     mass_per_length: 0.2, links: 4}\n"
    "bodies:\n"
    "  - {name: fish, type: sphere, diameter: 0.4, mass: 40}\n";

static void test_names(const ts_system *sys)
{
    ts_err err = {0};
    ts_output o;
    CHECK(ts_output_find(sys, "fish.z", TS_OUT_ALL, &o, &err) == TS_OK &&
              o.kind == TS_OUT_POSITION && o.comp == 2 &&
              o.node == ts_system_body_node(sys, 0) &&
              !strcmp(o.si_unit, "m") && !strcmp(o.name, "fish.z"),
          "fish.z: the body's node, z, m (%s)", err.msg);
    CHECK(ts_output_find(sys, "tow_cable.3.x", TS_OUT_ALL, &o, &err) ==
                  TS_OK &&
              !strcmp(o.name, "fish.x"),
          "tow_cable.3.x is the body's node, named fish.x (%s)", o.name);
    CHECK(ts_output_find(sys, "fish.tension", TS_OUT_ALL, &o, &err) ==
                  TS_OK &&
              o.kind == TS_OUT_TENSION && !strcmp(o.name, "tow_cable.3.tension") &&
              !strcmp(o.si_unit, "N") && !strcmp(o.unit, "N/m"),
          "fish.tension: the link ending at the body, N (%s)", o.name);
    CHECK(ts_output_find(sys, "tail.4.tension", TS_OUT_ALL, &o, &err) ==
                  TS_OK &&
              sys->links[o.link].cable == 1 && sys->links[o.link].index == 4,
          "tail.4.tension: link 4 of the second cable");
    CHECK(ts_output_find(sys, "tow.force", TS_OUT_ALL, &o, &err) == TS_OK &&
              o.kind == TS_OUT_TOW_FORCE && o.comp == TS_OUT_MAGNITUDE &&
              ts_output_is_force(&o),
          "tow.force: the size of the force on the tow point");
    CHECK(ts_output_find(sys, "tow.force.y", TS_OUT_ALL, &o, &err) ==
                  TS_OK &&
              o.kind == TS_OUT_TOW_FORCE && o.comp == 1,
          "tow.force.y: its y component");
    CHECK(ts_output_find(sys, "tow_cable.2.strain", TS_OUT_ALL, &o, &err) ==
                  TS_OK &&
              o.kind == TS_OUT_STRAIN && !strcmp(o.si_unit, "1") &&
              !ts_output_is_force(&o),
          "tow_cable.2.strain: an elastic link's strain (%s)", err.msg);
    CHECK(ts_output_find(sys, "tow_cable.length", TS_OUT_ALL, &o, &err) ==
                  TS_OK &&
              o.kind == TS_OUT_LENGTH && o.cable == 0,
          "tow_cable.length: an elastic cable's stretched length (%s)",
          err.msg);
    struct {
        const char *name, *why;
        int kinds;
    } bad[] = {
        {"tail.2.strain", "rigid", TS_OUT_ALL},
        {"tail.length", "rigid", TS_OUT_ALL},
        {"tow.z", "tow.force", TS_OUT_ALL},
        {"fish.q", "x, y, z, tension", TS_OUT_ALL},
        {"tail.9.x", "no such node", TS_OUT_ALL},
        {"fish", "expected", TS_OUT_ALL},
        {"tow.force", "not an output of this analysis",
         TS_OUT_BIT(TS_OUT_POSITION) | TS_OUT_BIT(TS_OUT_TENSION)},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ts_err_clear(&err);
        CHECK(ts_output_find(sys, bad[k].name, bad[k].kinds, &o, &err) ==
                      TS_EINVAL &&
                  strstr(err.msg, bad[k].why) &&
                  strstr(err.msg, "valid outputs: positions"),
              "'%s' refused: %s", bad[k].name, err.msg);
    }
    /* The list holds what the kinds asked for, and only that. */
    char list[1024];
    ts_output_names(sys, TS_OUT_ALL, list, sizeof list);
    CHECK(strstr(list, "tow_cable.1.strain .. tow_cable.3.strain") &&
              strstr(list, "tow_cable.length") && strstr(list, "tow.force") &&
              !strstr(list, "tail.1.strain"),
          "every name, strains of the elastic cable only: %s", list);
    ts_output_names(sys, TS_OUT_BIT(TS_OUT_TENSION), list, sizeof list);
    CHECK(!strstr(list, "tow.force") && !strstr(list, "positions") &&
              strstr(list, "tail.1.tension .. tail.4.tension"),
          "tensions only: %s", list);
    /* A small buffer is cut, not overrun. */
    char small[12];
    memset(small, 'x', sizeof small);
    ts_output_names(sys, TS_OUT_ALL, small, 8);
    CHECK(strlen(small) == 7 && small[9] == 'x',
          "a buffer of 8 holds 7 characters and its end: '%s'", small);
}

static void test_values(const ts_system *sys)
{
    ts_err err = {0};
    int nn = sys->nnodes, nl = sys->nlinks;
    double pos[3 * 16] = {0}, tens[16], F[3] = {-2.385, 1.5, 4.25};
    /* Every link straight down at its length, link 2 of the elastic
     * cable stretched by e. */
    const double e = 0.02385;
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &sys->links[l];
        double len = L->length * (L->cable == 0 && L->index == 2 ? 1 + e : 1);
        for (int c = 0; c < 3; c++)
            pos[3 * L->lower + c] = pos[3 * L->upper + c] + (c == 2 ? len : 0);
        tens[l] = 100.0 + 7.0 * l;
    }
    (void)nn;
    ts_output o;
    ts_output_find(sys, "tow_cable.2.strain", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F), e, 1e-13,
               "strain of the stretched link");
    ts_output_find(sys, "tow_cable.1.strain", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F), 0, 1e-13,
               "strain of a link at its length");
    ts_output_find(sys, "tow_cable.length", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F), 30.0 + 10.0 * e,
               1e-12, "stretched length 3 l + e l");
    ts_output_find(sys, "fish.z", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F), 30.0 + 10.0 * e,
               1e-12, "the fish's depth");
    ts_output_find(sys, "tail.3.tension", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F), 100.0 + 7.0 * o.link,
               0, "a tension read back");
    ts_output_find(sys, "tow.force.x", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F), -2.385, 0,
               "tow.force.x read back");
    ts_output_find(sys, "tow.force", TS_OUT_ALL, &o, &err);
    CHECK_NEAR(ts_output_value(sys, &o, pos, tens, F),
               sqrt(2.385 * 2.385 + 1.5 * 1.5 + 4.25 * 4.25), 1e-14,
               "tow.force: the size of the components");
    CHECK(isnan(ts_output_value(sys, &o, pos, tens, NULL)),
          "the tow force without its array is NAN");
    ts_output_find(sys, "tow_cable.length", TS_OUT_ALL, &o, &err);
    CHECK(isnan(ts_output_value(NULL, &o, pos, tens, F)),
          "a length without the system is NAN");
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *s = tscene_parse(u, yaml);
    if (s) {
        test_names(s->system);
        test_values(s->system);
    }
    ts_scene_free(s);
    ts_units_free(u);
    return tc_done();
}
