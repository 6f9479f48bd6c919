/* test_options.c: the option tables (towstab/options.h).
 *
 * The property the tables exist for: a value is checked the same way
 * whatever its source. For every row of every analysis, values that break
 * it (out of range, not finite, the wrong unit, not one of the names,
 * empty, a spec of the wrong kind) are fed once as a command-line option
 * (--name, into an option set) and once as the key of a scene entry
 * (YAML text through ts_scene_parse and ts_optset_give_entry), then
 * applied and checked against the system. Both must be refused, each
 * naming its source (--name; analyses[0].name with its line), and where
 * both reached the table the messages must agree after the source. Then:
 * a good value lands the same from both sources; the command line wins
 * over the scene entry, which wins over the default, per option; a group
 * (compare, linear) given by one source is refused, by two the higher
 * wins; a TS_OPT_YIELD value of the scene yields only when the command
 * line contradicts it; every row has help, a metavariable when it takes
 * a value, and a unique name. */
#include "towstab/options.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"

static const char *const scene_head =
    "name: t\n"
    "tow:\n"
    "  speed: 2\n"
    "cables:\n"
    "  - name: cable\n"
    "    from: tow\n"
    "    to: ball\n"
    "    length: 20\n"
    "    diameter: 0.02\n"
    "    mass_per_length: 1.2\n"
    "    links: 10\n"
    "bodies:\n"
    "  - name: ball\n"
    "    type: sphere\n"
    "    diameter: 0.2\n"
    "    mass: 15\n"
    "analyses:\n";

/* The excitation of a study of a simulation under test. */
#define STUDY_EXCITE "tow.heave:amplitude=0.1,frequency=1Hz"

static ts_units *units;
static ts_scene *base;

/* YAML single-quoted scalar of text. */
static void quote(const char *text, char *buf, size_t size)
{
    size_t n = 0;
    buf[n++] = '\'';
    for (const char *p = text; *p && n + 3 < size; p++) {
        if (*p == '\'')
            buf[n++] = '\'';
        buf[n++] = *p;
    }
    buf[n++] = '\'';
    buf[n] = '\0';
}

/* Apply set s (after giving it its texts with code rc) to rq and check
 * it against system sys; the message names where the value came from.
 * Frees s. */
static int finish_on(const ts_system *sys, ts_optset *s, int rc,
                     ts_request *rq, ts_err *err)
{
    if (!rc)
        rc = ts_optset_apply(s, TS_OPTSET_COMMAND, units, rq, err);
    if (!rc)
        rc = ts_analysis_check(sys, rq, err);
    if (rc)
        ts_optset_locate(s, err);
    ts_optset_free(s);
    return rc;
}

/* finish_on the test scene's system. */
static int finish(ts_optset *s, int rc, ts_request *rq, ts_err *err)
{
    return finish_on(base->system, s, rc, rq, err);
}

/* The refusal of `text` for row o of kind from the command line: code and
 * message. `study` (>= 0): also analysis=<study> (a converge row that
 * applies to one study only). */
static int via_command(ts_analysis_kind kind, const ts_option *o,
                       const char *text, const char *study, ts_request *rq,
                       ts_err *err)
{
    ts_optset *s = ts_optset_alloc(kind, err);
    char where[80], cli[64];
    ts_option_cli_name(o, cli, sizeof cli);
    snprintf(where, sizeof where, "--%s", cli);
    ts_request_init(rq, kind);
    int rc = ts_optset_give(s, o->name, text, TS_OPTSET_COMMAND, where, err);
    if (!rc && study)
        rc = ts_optset_give(s, "analysis", study, TS_OPTSET_COMMAND,
                            "--analysis", err);
    /* A study of a simulation needs a periodic excitation. */
    if (!rc && study && !strcmp(study, "simulate") &&
        strcmp(o->name, "excite") != 0)
        rc = ts_optset_give(s, "excite", STUDY_EXCITE, TS_OPTSET_COMMAND,
                            "--excite", err);
    return finish(s, rc, rq, err);
}

/* The same from a scene entry. *parsed is set when the scene reader
 * accepted the text (the table then judged it). */
static int via_scene(ts_analysis_kind kind, const ts_option *o,
                     const char *text, const char *study, ts_request *rq,
                     int *parsed, ts_err *err)
{
    char q[512], yaml[2048];
    quote(text, q, sizeof q);
    int sim = study && !strcmp(study, "simulate") &&
              strcmp(o->name, "excite") != 0;
    snprintf(yaml, sizeof yaml, "%s  - type: %s\n    %s: %s\n%s%s%s%s",
             scene_head, ts_analysis_name(kind), o->name, q,
             study ? "    analysis: " : "", study ? study : "",
             study ? "\n" : "",
             sim ? "    excite: '" STUDY_EXCITE "'\n" : "");
    ts_request_init(rq, kind);
    ts_scene *sc = ts_scene_parse(yaml, strlen(yaml), "t.yaml", units, err);
    *parsed = sc != NULL;
    if (!sc)
        return err->code;
    ts_optset *s = ts_optset_alloc(kind, err);
    int rc = ts_optset_give_entry(s, &sc->analyses[0], 0, "t.yaml",
                                  TS_OPTSET_SCENE, -1, err);
    rc = finish(s, rc, rq, err);
    ts_scene_free(sc);
    return rc;
}

/* Texts that break row o. */
static int bad_texts(const ts_option *o, const char *out[], int max)
{
    int n = 0;
#define ADD(t)                                                               \
    do {                                                                      \
        if (n < max)                                                          \
            out[n++] = (t);                                                   \
    } while (0)
    ADD("");
    switch (o->type) {
    case TS_OPT_QUANTITY:
        ADD("nan");
        ADD("1e999");
        ADD("5 kg");
        if (!isnan(o->min) && isfinite(o->min)) {
            ADD(o->min == 0 ? "-1" : "-1e300");
            if (o->flags & TS_OPT_MIN_OPEN && o->min == 0)
                ADD("0");
        }
        break;
    case TS_OPT_NUMBER:
        ADD("x");
        ADD("nan");
        ADD("inf");
        ADD(o->min > 0 ? "1e-15" : "-1");
        ADD("2");
        break;
    case TS_OPT_INT:
    case TS_OPT_LONG:
        ADD("x");
        ADD("1.5");
        if (o->min > 0)
            ADD("0");
        if (o->max < 100000001)
            ADD("100000001");
        break;
    case TS_OPT_BOOL: ADD("maybe"); break;
    case TS_OPT_ENUM: ADD("frobnicate"); break;
    case TS_OPT_TEXT:
        if (o->choices)
            ADD("tow.spin");
        else
            ADD("nowhere.w");
        break;
    case TS_OPT_SPECS:
        ADD(" ; ");
        ADD("tow.spin:amplitude=1,frequency=1");
        if (!strcmp(o->name, "manoeuvre")) {
            ADD("speed:to=-5,duration=1s");
            ADD("tow.heave:amplitude=1,frequency=1");
        } else {
            ADD("tow.heave:amplitude=1,frequency=-1Hz");
            ADD("speed:by=1,duration=1s");
        }
        break;
    case TS_OPT_LIST:
        ADD("x");
        if (!strcmp(o->name, "integrators")) {
            ADD("rk9");
            ADD("rk8pd,rk8pd");
        } else {
            ADD("5,5");
            ADD(!strcmp(o->name, "links") ? "7.5" : "2");
        }
        break;
    case TS_OPT_CUSTOM:
        if (!strcmp(o->name, "set")) {
            ADD("cables.cable.length=-1");
            ADD("cables.rope.length=5");
            ADD("cables.cable.length=5 kg");
            ADD("bodies.ball.mass=2; tow.sped=1");
            ADD("tow.speed");
            ADD("cables.cable.links=7.5");
            break;
        }
        ADD("upside_down");
        ADD("shape:");
        ADD("released:theta9=1");
        break;
    }
#undef ADD
    return n;
}

/* The message after its source: what follows the first ": " after the
 * where (the where itself differs between the sources). */
static const char *tail(const char *msg, const char *where_end)
{
    const char *p = strstr(msg, where_end);
    return p ? p + strlen(where_end) : msg;
}

static void test_property(void)
{
    int tried = 0, same = 0, bad = 0;
    for (int k = 0; k < TS_ANALYSIS_COUNT; k++) {
        int n;
        const ts_option *t = ts_options(k, &n);
        for (int i = 0; i < n; i++) {
            const ts_option *o = &t[i];
            const char *study = o->only == TS_ANALYSIS_MODES + 1 ? "modes"
                                : o->only == TS_ANALYSIS_SIMULATE + 1
                                    ? "simulate"
                                    : NULL;
            const char *texts[12];
            int nt = bad_texts(o, texts, 12);
            for (int j = 0; j < nt; j++) {
                ts_request r1, r2;
                ts_err e1 = {0}, e2 = {0};
                int parsed;
                int rc1 = via_command(k, o, texts[j], study, &r1, &e1);
                int rc2 = via_scene(k, o, texts[j], study, &r2, &parsed,
                                    &e2);
                ts_request_clear(&r1);
                ts_request_clear(&r2);
                tried++;
                char cli[64], w1[80], w2[96];
                ts_option_cli_name(o, cli, sizeof cli);
                snprintf(w1, sizeof w1, "--%s: ", cli);
                snprintf(w2, sizeof w2, "analyses[0].%s (line ", o->name);
                int ok = rc1 != TS_OK && rc2 != TS_OK &&
                         !strncmp(e1.msg, w1, strlen(w1) - 2) &&
                         strstr(e2.msg, w2);
                /* Where both went through the table: the same words. */
                if (ok && parsed) {
                    const char *a = tail(e1.msg, w1);
                    const char *b = strstr(e2.msg, "): ");
                    b = b ? b + 3 : e2.msg;
                    ok = !strcmp(a, b) && rc1 == rc2;
                    same += ok;
                }
                if (!ok) {
                    bad++;
                    printf("FAIL %s %s = '%s':\n     command line (%d): %s\n"
                           "     scene (%d): %s\n",
                           ts_analysis_name(k), o->name, texts[j], rc1,
                           e1.msg, rc2, e2.msg);
                }
            }
        }
    }
    CHECK(bad == 0, "%d bad values of every option of every analysis "
                    "refused from the command line and from a scene entry, "
                    "each naming its source; %d with the same words from "
                    "both (the rest refused by the scene reader first)",
          tried, same);
}

static void test_good_and_precedence(void)
{
    ts_request r1, r2;
    ts_err err = {0};
    const ts_option *o = ts_option_find(TS_ANALYSIS_SIMULATE, "speed");
    int parsed;
    int rc1 = via_command(TS_ANALYSIS_SIMULATE, o, "5 knot", NULL, &r1, &err);
    int rc2 = via_scene(TS_ANALYSIS_SIMULATE, o, "5 knot", NULL, &r2, &parsed,
                        &err);
    CHECK(rc1 == TS_OK && rc2 == TS_OK && r1.setup.speed == r2.setup.speed &&
              fabs(r1.setup.speed - 1852.0 / 720) < 1e-12,
          "'5 knot' lands as %.12g m/s from both sources", r1.setup.speed);
    ts_request_clear(&r1);
    ts_request_clear(&r2);

    /* Precedence: command line > scene entry > default, per option. */
    const char *yaml_tail = "  - type: simulate\n    t_end: 7 s\n"
                            "    rtol: 1e-7\n    compare: true\n";
    char yaml[2048];
    snprintf(yaml, sizeof yaml, "%s%s", scene_head, yaml_tail);
    ts_scene *sc = ts_scene_parse(yaml, strlen(yaml), "p.yaml", units, &err);
    ts_optset *s = sc ? ts_optset_alloc(TS_ANALYSIS_SIMULATE, &err) : NULL;
    int rc = s ? ts_optset_give_entry(s, &sc->analyses[0], 0, "p.yaml",
                                      TS_OPTSET_SCENE, -1, &err)
               : TS_ENOMEM;
    if (!rc)
        rc = ts_optset_give(s, "t-end", "9", TS_OPTSET_COMMAND, "--t-end",
                            &err);
    if (!rc)
        rc = ts_optset_give(s, "compare", "false", TS_OPTSET_COMMAND,
                            "--no-compare", &err);
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    if (!rc)
        rc = ts_optset_apply(s, TS_OPTSET_COMMAND, units, &rq, &err);
    CHECK(rc == TS_OK && rq.simulate.sim.t_end == 9 &&
              rq.simulate.sim.rel_tol == 1e-7 && rq.simulate.compare == 0 &&
              rq.simulate.sim.abs_tol == 1e-9,
          "precedence: --t-end 9 over the entry's 7 s, the entry's rtol "
          "1e-7 over the default, --no-compare over compare: true, atol "
          "its default (%s)", err.msg);
    const char *w = s ? ts_optset_where(s, "rtol") : NULL;
    CHECK(w && !strcmp(w, "p.yaml: analyses[0].rtol (line 20)"),
          "the entry's value names its file, key and line: %s",
          w ? w : "none");
    /* A group from one source is refused. */
    ts_optset *g = ts_optset_alloc(TS_ANALYSIS_SIMULATE, &err);
    ts_optset_give(g, "compare", "true", TS_OPTSET_COMMAND, "--compare", &err);
    ts_optset_give(g, "linear", "true", TS_OPTSET_COMMAND, "--linear", &err);
    ts_request rg;
    ts_request_init(&rg, TS_ANALYSIS_SIMULATE);
    ts_err_clear(&err);
    rc = ts_optset_apply(g, TS_OPTSET_COMMAND, units, &rg, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "--compare") &&
              strstr(err.msg, "--linear"),
          "--compare and --linear together refused: %s", err.msg);
    ts_optset_free(g);
    /* From two sources, the higher wins: --linear over compare: true. */
    ts_optset_drop(s, "compare");
    ts_optset_give_entry(s, &sc->analyses[0], 0, "p.yaml", TS_OPTSET_SCENE,
                         -1, &err);
    ts_optset_give(s, "linear", "true", TS_OPTSET_COMMAND, "--linear", &err);
    ts_request_clear(&rq);
    rc = ts_optset_apply(s, TS_OPTSET_COMMAND, units, &rq, &err);
    CHECK(rc == TS_OK && rq.simulate.linear == 1 && rq.simulate.compare == 0,
          "--linear over the entry's compare: true (the group's higher "
          "source wins)");
    ts_request_clear(&rq);
    ts_optset_free(s);
    ts_scene_free(sc);

    /* A scene transient yields to its default only when the command line
     * makes it wrong. */
    snprintf(yaml, sizeof yaml, "%s  - type: simulate\n    t_end: 60 s\n"
             "    transient: 30 s\n", scene_head);
    sc = ts_scene_parse(yaml, strlen(yaml), "y.yaml", units, &err);
    s = sc ? ts_optset_alloc(TS_ANALYSIS_SIMULATE, &err) : NULL;
    if (s) {
        ts_optset_give_entry(s, &sc->analyses[0], 0, "y.yaml",
                             TS_OPTSET_SCENE, -1, &err);
        ts_optset_give(s, "t_end", "20", TS_OPTSET_COMMAND, "--t-end", &err);
        ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
        ts_optset_apply(s, TS_OPTSET_COMMAND, units, &rq, &err);
        ts_err_clear(&err);
        rc = ts_analysis_check(base->system, &rq, &err);
        const char *y = ts_optset_yields(s, &err);
        CHECK(rc == TS_EINVAL && y && !strcmp(y, "transient"),
              "the entry's transient 30 s against --t-end 20 s: it yields "
              "(%s)", err.msg);
        ts_err e2 = {0};
        ts_fail(&e2, TS_EINVAL, "t_end: made up");
        CHECK(!ts_optset_yields(s, &e2),
              "the command line's own t_end never yields");
        ts_request_clear(&rq);
    }
    ts_optset_free(s);
    ts_scene_free(sc);
}

static void test_tables(void)
{
    int ok = 1, rows = 0;
    for (int k = 0; k < TS_ANALYSIS_COUNT; k++) {
        int n;
        const ts_option *t = ts_options(k, &n);
        for (int i = 0; i < n; i++) {
            rows++;
            ok &= t[i].help && t[i].help[0] &&
                  (t[i].type == TS_OPT_BOOL || (t[i].arg && t[i].arg[0]));
            ok &= ts_option_find(k, t[i].name) == &t[i];
            for (int j = 0; j < i; j++)
                ok &= strcmp(t[i].name, t[j].name) != 0;
        }
    }
    CHECK(ok, "%d rows in %d tables: each with help and a metavariable, "
              "names unique and found again", rows, TS_ANALYSIS_COUNT);
    const ts_option *m = ts_option_find(TS_ANALYSIS_MODES,
                                        "equilibrium-method");
    const ts_option *e = ts_option_find(TS_ANALYSIS_EQUILIBRIUM,
                                        "equilibrium_method");
    CHECK(m && e && m->offset == e->offset &&
              !ts_option_find(TS_ANALYSIS_EQUILIBRIUM, "method"),
          "one name for the equilibrium's method in every analysis "
          "(equilibrium_method, --equilibrium-method)");
    const ts_option *l = ts_option_find(TS_ANALYSIS_SIMULATE, "links");
    CHECK(l && l->max == TS_MAX_LINKS,
          "the link limit is TS_MAX_LINKS = %d", TS_MAX_LINKS);
}

/* The request of a vehicle scene's equilibrium with `set` from the
 * command line (entry < 0) or from the scene's entry analyses[entry],
 * checked against its system. */
static int vehicle_set(const ts_scene *sc, int entry, const char *text,
                       ts_request *rq, ts_err *err)
{
    ts_optset *s = ts_optset_alloc(TS_ANALYSIS_EQUILIBRIUM, err);
    if (!s)
        return TS_ENOMEM;
    int rc = entry < 0 ? ts_optset_give(s, "set", text, TS_OPTSET_COMMAND,
                                        "--set", err)
                       : ts_optset_give_entry(s, &sc->analyses[entry], entry,
                                              "v.yaml", TS_OPTSET_SCENE, -1,
                                              err);
    ts_request_init(rq, TS_ANALYSIS_EQUILIBRIUM);
    return finish_on(sc->system, s, rc, rq, err);
}

/* A vehicle loop's setpoint and gains given with a unit, from both
 * sources: converted to SI as the plain number would be; a unit of the
 * other kind of loop refused when checked against the system, naming
 * the source, the path, what the loop measures and the unit expected. */
static void test_loop_units(void)
{
    ts_err err = {0};
    ts_scene *file = ts_scene_load("examples/aurora_towfish.yaml", units,
                                   &err);
    if (!CHECK(file, "the AURORA scene loads (%s)", err.msg))
        return;
    static const char *const entries[] = {
        "bodies.aurora.loops.depth.setpoint=100 ft",
        "bodies.aurora.controllers.pitch.setpoint=2 deg; "
        "bodies.aurora.loops.depth.kp=3 deg/m",
        "bodies.aurora.loops.pitch.setpoint=400 m",
        "bodies.aurora.loops.depth.setpoint=5 deg",
    };
    size_t nentries = sizeof entries / sizeof entries[0];
    /* The scene's text with one equilibrium entry per text above. */
    size_t size = file->text_len + 4096;
    char *yaml = malloc(size);
    size_t n = yaml ? (size_t)snprintf(yaml, size, "%s", file->text) : 0;
    for (size_t i = 0; yaml && i < nentries; i++) {
        char q[256];
        quote(entries[i], q, sizeof q);
        n += (size_t)snprintf(yaml + n, size - n, "  - type: equilibrium\n"
                              "    set: %s\n", q);
    }
    ts_scene *sc = yaml ? ts_scene_parse(yaml, n, "v.yaml", units, &err)
                        : NULL;
    free(yaml);
    int first = sc ? sc->nanalyses - (int)nentries : 0;
    if (!CHECK(sc && first >= 0, "the scene with set entries (%s)",
               err.msg)) {
        ts_scene_free(file);
        return;
    }
    for (int src = 0; src < 2; src++) {
        const char *name = src ? "the scene's entry" : "--set";
        ts_request rq;
        int rc = vehicle_set(sc, src ? first : -1, entries[0], &rq, &err);
        CHECK(rc == TS_OK && rq.setup.nsets == 1 &&
                  rq.setup.sets[0].value == 100 * 0.3048 &&
                  !strcmp(rq.setup.sets[0].unit, "m"),
              "%s: a depth setpoint of '100 ft' is %.17g m (%s)", name,
              rc ? NAN : rq.setup.sets[0].value, rc ? err.msg : "ok");
        ts_request_clear(&rq);
        rc = vehicle_set(sc, src ? first + 1 : -1, entries[1], &rq, &err);
        CHECK(rc == TS_OK && rq.setup.nsets == 2 &&
                  fabs(rq.setup.sets[0].value - 2 * M_PI / 180) < 1e-15 &&
                  !strcmp(rq.setup.sets[0].unit, "rad") &&
                  fabs(rq.setup.sets[1].value - 3 * M_PI / 180) < 1e-15 &&
                  !strcmp(rq.setup.sets[1].unit, "rad/m"),
              "%s: a pitch setpoint of '2 deg' and a depth kp of "
              "'3 deg/m' in rad and rad/m (%s)", name,
              rc ? err.msg : "ok");
        ts_request_clear(&rq);
        /* Entries 2 and 3: refused, naming the source, the path and
         * value, what the loop measures and the unit expected. */
        static const char *const want[2][2] = {
            {"bodies.aurora.loops.pitch.setpoint: '400 m' is in m",
             "measures pitch: expected rad"},
            {"bodies.aurora.loops.depth.setpoint: '5 deg' is in rad",
             "measures depth: expected m"}};
        for (int e = 0; e < 2; e++) {
            rc = vehicle_set(sc, src ? first + 2 + e : -1, entries[2 + e],
                             &rq, &err);
            CHECK(rc == TS_EUNIT &&
                      strstr(err.msg, src ? "analyses[" : "--set: ") &&
                      strstr(err.msg, want[e][0]) &&
                      strstr(err.msg, want[e][1]),
                  "%s: '%s' refused: %s", name, entries[2 + e], err.msg);
            ts_request_clear(&rq);
        }
    }
    /* A plain number is SI, as before, whatever the loop. */
    ts_request rq;
    int rc = vehicle_set(sc, -1, "bodies.aurora.loops.pitch.setpoint=0.05",
                         &rq, &err);
    CHECK(rc == TS_OK && rq.setup.sets[0].value == 0.05 &&
              !rq.setup.sets[0].unit[0],
          "a plain number stays SI, no unit to check (%s)",
          rc ? err.msg : "ok");
    ts_request_clear(&rq);
    ts_scene_free(sc);
    ts_scene_free(file);
}

int main(void)
{
    ts_err err = {0};
    units = ts_units_alloc(&err);
    char yaml[1024];
    snprintf(yaml, sizeof yaml, "%s  - equilibrium\n", scene_head);
    base = units ? ts_scene_parse(yaml, strlen(yaml), "base.yaml", units,
                                  &err)
                 : NULL;
    if (CHECK(base, "the test scene (%s)", err.msg)) {
        test_tables();
        test_property();
        test_good_and_precedence();
        test_loop_units();
    }
    ts_scene_free(base);
    ts_units_free(units);
    return tc_done();
}
