/* fuzz_scene.c: libFuzzer target for the scene reader (towstab/scene.h).
 *
 * The input bytes are given to ts_scene_parse() as they are, with their
 * length and no NUL terminator (the reader promises not to need one, and
 * AddressSanitizer's redzone after libFuzzer's buffer catches any read
 * past the end). Build with clang -fsanitize=fuzzer,address,undefined
 * (meson -Dfuzz=true), or link with test/fuzz/replay.c for the
 * deterministic smoke run of the default test suite.
 *
 * Checked on every input (besides the sanitizers): the common invariants
 * of fuzz_common.h on the error record; a refused scene's message starts
 * with the scene name; an accepted scene is fully built and every value
 * the rest of towstab relies on holds: finite, in range, links and nodes
 * consistent and in topological order (ts_system_build's documented
 * result), elastic links exactly those with EA > 0 and damping only on
 * them, analyses well formed. */
#include <math.h>

#include "towstab/scene.h"
#include "towstab/system.h"

#include "fuzz_common.h"

#define NAME "fuzz.yaml"

int fuzz_accepted;

static int finite_min(double v, double lo, int strict)
{
    return isfinite(v) && (strict ? v > lo : v >= lo);
}

/* What an accepted scene guarantees. */
static void check_scene(const ts_scene *s)
{
    FUZZ_REQUIRE(s->system != NULL, "accepted scene without a system");
    const ts_system *sys = s->system;
    FUZZ_REQUIRE(strnlen(sys->name, TS_NAME_MAX) > 0 &&
                 strnlen(sys->name, TS_NAME_MAX) < TS_NAME_MAX,
                 "scene name empty or unterminated");
    FUZZ_REQUIRE(finite_min(sys->env.water_density, 0, 0) &&
                 finite_min(sys->env.gravity, 0, 0) &&
                 isfinite(sys->env.current[0]) &&
                 isfinite(sys->env.current[1]) &&
                 isfinite(sys->env.current[2]),
                 "environment out of range: rho %g, g %g",
                 sys->env.water_density, sys->env.gravity);
    FUZZ_REQUIRE(finite_min(sys->tow.speed, 0, 0) &&
                 isfinite(sys->tow.turn_rate) && isfinite(sys->tow.point[0])
                 && isfinite(sys->tow.point[1]) && isfinite(sys->tow.point[2]),
                 "tow out of range: speed %g, turn rate %g", sys->tow.speed,
                 sys->tow.turn_rate);
    FUZZ_REQUIRE(sys->ncables >= 1 && sys->nbodies >= 0,
                 "%d cables, %d bodies", sys->ncables, sys->nbodies);
    int links = 0;
    for (int i = 0; i < sys->ncables; i++) {
        const ts_cable *c = &sys->cables[i];
        FUZZ_REQUIRE(finite_min(c->length, 0, 1) &&
                     finite_min(c->diameter, 0, 1) &&
                     finite_min(c->mass_per_length, 0, 0) &&
                     finite_min(c->cdn, 0, 0) && finite_min(c->cdt, 0, 0) &&
                     finite_min(c->can, 0, 0) && finite_min(c->ei, 0, 0) &&
                     finite_min(c->ea, 0, 0) &&
                     finite_min(c->damping, 0, 0),
                     "cables[%d] out of range: length %g, diameter %g, "
                     "mass/length %g, EI %g, EA %g, damping %g", i,
                     c->length, c->diameter, c->mass_per_length, c->ei,
                     c->ea, c->damping);
        FUZZ_REQUIRE(!(c->damping > 0) || c->ea > 0,
                     "cables[%d]: damping %g on a rigid cable", i,
                     c->damping);
        FUZZ_REQUIRE(c->nlinks >= 1, "cables[%d] has %d links", i, c->nlinks);
        FUZZ_REQUIRE(c->from_body >= -1 && c->from_body < sys->nbodies &&
                     c->to_body >= -1 && c->to_body < sys->nbodies,
                     "cables[%d] ends out of range (%d, %d)", i, c->from_body,
                     c->to_body);
        links += c->nlinks;
    }
    for (int b = 0; b < sys->nbodies; b++) {
        const ts_body *bd = &sys->bodies[b];
        FUZZ_REQUIRE(finite_min(bd->diameter, 0, bd->type == TS_BODY_SPHERE)
                     && finite_min(bd->mass, 0, 0) && finite_min(bd->cd, 0, 0)
                     && finite_min(bd->ca, 0, 0),
                     "bodies[%d] out of range: diameter %g, mass %g", b,
                     bd->diameter, bd->mass);
    }
    FUZZ_REQUIRE(sys->nlinks == links && sys->nnodes == links + 1,
                 "%d links and %d nodes for cables with %d links",
                 sys->nlinks, sys->nnodes, links);
    for (int k = 0; k < sys->nlinks; k++) {
        const ts_link *l = &sys->links[k];
        FUZZ_REQUIRE(l->lower == k + 1 && l->upper >= 0 && l->upper <= k &&
                     l->parent >= -1 && l->parent < k &&
                     l->cable >= 0 && l->cable < sys->ncables,
                     "link %d: upper %d, lower %d, parent %d, cable %d", k,
                     l->upper, l->lower, l->parent, l->cable);
        FUZZ_REQUIRE(finite_min(l->length, 0, 1) && finite_min(l->mass, 0, 0),
                     "link %d: length %g, mass %g", k, l->length, l->mass);
        FUZZ_REQUIRE(l->elastic == (l->ea > 0) &&
                     (!l->elastic || sys->has_elastic),
                     "link %d: elastic %d with EA %g (system has_elastic %d)",
                     k, l->elastic, l->ea, sys->has_elastic);
    }
    for (int k = 0; k < sys->nnodes; k++)
        FUZZ_REQUIRE(finite_min(sys->nodes[k].mass, 0, 0),
                     "node %d: mass %g", k, sys->nodes[k].mass);

    FUZZ_REQUIRE(s->nanalyses >= 0 &&
                 (s->nanalyses == 0 || s->analyses != NULL),
                 "%d analyses", s->nanalyses);
    for (int i = 0; i < s->nanalyses; i++) {
        const ts_scene_analysis *a = &s->analyses[i];
        FUZZ_REQUIRE(strnlen(a->type, TS_NAME_MAX) > 0 &&
                     strnlen(a->type, TS_NAME_MAX) < TS_NAME_MAX,
                     "analyses[%d] type empty or unterminated", i);
        FUZZ_REQUIRE(a->noptions >= 0 &&
                     (a->noptions == 0 || a->options != NULL),
                     "analyses[%d]: %d options", i, a->noptions);
        for (int j = 0; j < a->noptions; j++) {
            FUZZ_REQUIRE(a->options[j].value != NULL,
                         "analyses[%d] option %d has no value", i, j);
            FUZZ_REQUIRE(ts_scene_analysis_option(a, a->options[j].key)
                         == &a->options[j],
                         "analyses[%d] option '%s' given twice", i,
                         a->options[j].key);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const ts_units *units = fuzz_units();
    ts_err err;
    ts_err_clear(&err);
    ts_scene *s = ts_scene_parse((const char *)data, size, NAME, units, &err);
    fuzz_check_error(s ? TS_OK : err.code, &err);
    fuzz_accepted = s != NULL;
    if (s) {
        check_scene(s);
        ts_scene_free(s);
    } else {
        FUZZ_REQUIRE(err.code < 0, "NULL scene with code %d", err.code);
        FUZZ_REQUIRE(!strncmp(err.msg, NAME ": ", strlen(NAME ": ")),
                     "message does not start with the scene name: \"%s\"",
                     err.msg);
    }
    return 0;
}
