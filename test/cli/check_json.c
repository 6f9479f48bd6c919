/* check_json.c: checks on the JSON that towstab writes, for test/cli/run.sh.
 *
 *   check_json parse FILE
 *       FILE ("-": standard input) is one complete JSON document.
 *   check_json compare RESULT EXPECTED
 *       EXPECTED is {"rtol": r, "atol": a, "expect": V}. Every key of every
 *       object in V must be in RESULT at the same place, arrays must have
 *       the same length, numbers must agree to |got - want| <= atol +
 *       rtol |want|, and strings, booleans and nulls must be equal. Keys
 *       RESULT has beyond V are not compared (V selects what matters).
 *   check_json equilibrium RESULT
 *       RESULT is an equilibrium result (towstab equilibrium --json), or a
 *       `towstab run` result, whose "equilibrium" analyses (others are
 *       checked by their own tests) are each
 *       converged, has iterations, residual <= 1e-10, nodes [{name, x, y,
 *       z}] with the tow point first, links [{cable, index, tension,
 *       theta1_deg, theta2_deg}] (one fewer than nodes), bodies [{name, x,
 *       y, z}] and top_tension. Prints the number of nodes of each.
 *   check_json keys COMMAND FILE
 *       Prints "SECTION KEY" for every object key in FILE, the result of
 *       `towstab COMMAND --json`, once per pair, for test/cli/manual_keys.sh:
 *       SECTION is the command whose part of doc/manual.md defines the key.
 *       It is COMMAND, except inside an "equilibrium" object (the
 *       equilibrium's keys), for `run`, inside each entry of
 *       "analyses" (its "type"), and for `design` inside its "result"
 *       (its "analysis"). Keys with a dot are names of quantities
 *       (sphere.z, mode1.freq_hz), not keys of the format: skipped.
 *
 * Every mismatch is printed with its path in the document (e.g.
 * analyses[1].bodies[0].x). Exit status: 0 all good, 1 a check failed,
 * 2 usage or unreadable input. */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int nbad;

static void bad(const char *path, const char *fmt, const char *detail)
{
    printf("  %s: ", path[0] ? path : "(top)");
    printf(fmt, detail);
    printf("\n");
    nbad++;
}

static json_t *load(const char *file)
{
    json_error_t e;
    json_t *v = strcmp(file, "-") == 0
                    ? json_loadf(stdin, 0, &e)
                    : json_load_file(file, 0, &e);
    if (!v)
        fprintf(stderr, "check_json: %s: not JSON: %s (line %d, column %d)\n",
                file, e.text, e.line, e.column);
    return v;
}

static const char *type_name(const json_t *v)
{
    switch (json_typeof(v)) {
    case JSON_OBJECT: return "an object";
    case JSON_ARRAY: return "an array";
    case JSON_STRING: return "a string";
    case JSON_INTEGER:
    case JSON_REAL: return "a number";
    case JSON_TRUE:
    case JSON_FALSE: return "a boolean";
    default: return "null";
    }
}

/* ---- keys --------------------------------------------------------------- */

/* Distinct "section key" pairs, printed once each. */
#define KEYS_MAX 4096
static char *seen[KEYS_MAX];
static int nseen;

static void key_out(const char *section, const char *key)
{
    char pair[512];
    snprintf(pair, sizeof pair, "%s %s", section, key);
    for (int i = 0; i < nseen; i++)
        if (strcmp(seen[i], pair) == 0)
            return;
    if (nseen < KEYS_MAX && (seen[nseen] = strdup(pair)))
        nseen++;
    printf("%s\n", pair);
}

/* run: 0 anywhere but in a run's result; 1 its top level and "analyses";
 * 2 an entry of "analyses", whose "type" key the run adds. */
static void keys(const json_t *v, const char *section, int run)
{
    if (json_is_array(v)) {
        size_t i;
        const json_t *x;
        json_array_foreach(v, i, x) {
            /* An entry of a run's "analyses" belongs to its type. */
            const json_t *ty = run ? json_object_get(x, "type") : NULL;
            keys(x, json_is_string(ty) ? json_string_value(ty) : section,
                 run ? 2 : 0);
        }
        return;
    }
    if (!json_is_object(v))
        return;
    const char *k;
    const json_t *x;
    json_object_foreach((json_t *)v, k, x) {
        if (strchr(k, '.'))
            continue;
        key_out(run == 2 && strcmp(k, "type") == 0 ? "run" : section, k);
        const json_t *an = json_object_get(v, "analysis");
        if (strcmp(k, "equilibrium") == 0 && json_is_object(x))
            keys(x, "equilibrium", 0);
        /* A design study's "result": the single run of its analysis. */
        else if (strcmp(section, "design") == 0 &&
                 strcmp(k, "result") == 0 && json_is_object(x) &&
                 json_is_string(an))
            keys(x, json_string_value(an), 0);
        else
            keys(x, section, run == 1 && strcmp(k, "analyses") == 0);
    }
}

/* ---- compare ------------------------------------------------------------ */

static void compare(const json_t *got, const json_t *want, const char *path,
                    double rtol, double atol)
{
    char sub[1024], msg[256];
    if (!got) {
        bad(path, "missing%s", "");
        return;
    }
    if (json_is_number(want)) {
        if (!json_is_number(got)) {
            bad(path, "expected a number, got %s", type_name(got));
            return;
        }
        double g = json_number_value(got), w = json_number_value(want);
        double tol = atol + rtol * fabs(w);
        if (!(fabs(g - w) <= tol)) {
            snprintf(msg, sizeof msg, "got %.12g, want %.12g, |diff| %.3g > "
                     "%.3g", g, w, fabs(g - w), tol);
            bad(path, "%s", msg);
        }
        return;
    }
    if (json_typeof(got) != json_typeof(want) &&
        !(json_is_boolean(got) && json_is_boolean(want))) {
        snprintf(msg, sizeof msg, "expected %s, got %s", type_name(want),
                 type_name(got));
        bad(path, "%s", msg);
        return;
    }
    if (json_is_object(want)) {
        const char *key;
        json_t *wv;
        json_object_foreach((json_t *)want, key, wv)
        {
            snprintf(sub, sizeof sub, "%s%s%s", path, path[0] ? "." : "",
                     key);
            compare(json_object_get(got, key), wv, sub, rtol, atol);
        }
    } else if (json_is_array(want)) {
        if (json_array_size(got) != json_array_size(want)) {
            snprintf(msg, sizeof msg, "%zu entries, expected %zu",
                     json_array_size(got), json_array_size(want));
            bad(path, "%s", msg);
            return;
        }
        for (size_t i = 0; i < json_array_size(want); i++) {
            snprintf(sub, sizeof sub, "%s[%zu]", path, i);
            compare(json_array_get(got, i), json_array_get(want, i), sub,
                    rtol, atol);
        }
    } else if (!json_equal((json_t *)got, (json_t *)want)) {
        char *g = json_dumps(got, JSON_ENCODE_ANY),
             *w = json_dumps(want, JSON_ENCODE_ANY);
        snprintf(msg, sizeof msg, "got %s, want %s", g ? g : "?",
                 w ? w : "?");
        bad(path, "%s", msg);
        free(g);
        free(w);
    }
}

/* ---- equilibrium ---------------------------------------------------------- */

static const json_t *need(const json_t *o, const char *key, int type,
                          const char *path)
{
    char sub[512];
    snprintf(sub, sizeof sub, "%s%s%s", path, path[0] ? "." : "", key);
    const json_t *v = json_object_get(o, key);
    if (!v) {
        bad(sub, "missing%s", "");
        return NULL;
    }
    int ok = type == JSON_REAL ? json_is_number(v)
             : type == JSON_TRUE ? json_is_boolean(v)
                                 : (int)json_typeof(v) == type;
    if (!ok) {
        bad(sub, "has the wrong type (%s)", type_name(v));
        return NULL;
    }
    return v;
}

static void check_points(const json_t *arr, const char *key,
                         const char *path)
{
    char sub[512];
    for (size_t i = 0; i < json_array_size(arr); i++) {
        snprintf(sub, sizeof sub, "%s%s%s[%zu]", path, path[0] ? "." : "",
                 key, i);
        const json_t *p = json_array_get(arr, i);
        if (!json_is_object(p)) {
            bad(sub, "is not an object%s", "");
            continue;
        }
        need(p, "name", JSON_STRING, sub);
        need(p, "x", JSON_REAL, sub);
        need(p, "y", JSON_REAL, sub);
        need(p, "z", JSON_REAL, sub);
    }
}

/* The residual bound of the project's default tolerance. */
#define RESIDUAL_MAX 1e-10

static void check_equilibrium(const json_t *o, const char *path)
{
    char sub[512];
    const json_t *v = need(o, "converged", JSON_TRUE, path);
    if (v && !json_is_true(v))
        bad(path, "converged is false%s", "");
    v = need(o, "iterations", JSON_INTEGER, path);
    if (v && json_integer_value(v) < 0)
        bad(path, "iterations < 0%s", "");
    v = need(o, "residual", JSON_REAL, path);
    if (v && !(json_number_value(v) <= RESIDUAL_MAX)) {
        snprintf(sub, sizeof sub, "%g", json_number_value(v));
        bad(path, "residual %s > 1e-10", sub);
    }
    v = need(o, "top_tension", JSON_REAL, path);
    if (v && !(json_number_value(v) > 0))
        bad(path, "top_tension is not > 0%s", "");
    const json_t *nodes = need(o, "nodes", JSON_ARRAY, path);
    const json_t *links = need(o, "links", JSON_ARRAY, path);
    const json_t *bodies = need(o, "bodies", JSON_ARRAY, path);
    if (nodes) {
        check_points(nodes, "nodes", path);
        const json_t *first = json_array_get(nodes, 0);
        const json_t *name = first ? json_object_get(first, "name") : NULL;
        if (!name || !json_is_string(name) ||
            strcmp(json_string_value(name), "tow") != 0)
            bad(path, "nodes[0] is not the tow point ('tow')%s", "");
        printf("nodes %zu\n", json_array_size(nodes));
    }
    if (bodies)
        check_points(bodies, "bodies", path);
    if (links) {
        if (nodes && json_array_size(links) + 1 != json_array_size(nodes))
            bad(path, "links: not one fewer than nodes%s", "");
        for (size_t i = 0; i < json_array_size(links); i++) {
            snprintf(sub, sizeof sub, "%s%slinks[%zu]", path,
                     path[0] ? "." : "", i);
            const json_t *l = json_array_get(links, i);
            if (!json_is_object(l)) {
                bad(sub, "is not an object%s", "");
                continue;
            }
            need(l, "cable", JSON_STRING, sub);
            v = need(l, "index", JSON_INTEGER, sub);
            if (v && json_integer_value(v) < 1)
                bad(sub, "index < 1%s", "");
            need(l, "tension", JSON_REAL, sub);
            need(l, "theta1_deg", JSON_REAL, sub);
            need(l, "theta2_deg", JSON_REAL, sub);
        }
    }
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "parse") == 0) {
        json_t *v = load(argv[2]);
        if (!v)
            return 1;
        json_decref(v);
        return 0;
    }
    if (argc == 4 && strcmp(argv[1], "compare") == 0) {
        json_t *got = load(argv[2]), *spec = load(argv[3]);
        if (!got || !spec)
            return 2;
        const json_t *rt = json_object_get(spec, "rtol");
        const json_t *at = json_object_get(spec, "atol");
        const json_t *want = json_object_get(spec, "expect");
        if (!json_is_number(rt) || !json_is_number(at) || !want) {
            fprintf(stderr, "check_json: %s: expected {\"rtol\": number, "
                            "\"atol\": number, \"expect\": ...}\n",
                    argv[3]);
            return 2;
        }
        compare(got, want, "", json_number_value(rt), json_number_value(at));
        json_decref(got);
        json_decref(spec);
        return nbad ? 1 : 0;
    }
    if (argc == 3 && strcmp(argv[1], "equilibrium") == 0) {
        json_t *got = load(argv[2]);
        if (!got)
            return 2;
        const json_t *list = json_object_get(got, "analyses");
        if (json_is_array(list)) {
            if (json_array_size(list) == 0)
                bad("analyses", "is empty%s", "");
            for (size_t i = 0; i < json_array_size(list); i++) {
                char path[64];
                snprintf(path, sizeof path, "analyses[%zu]", i);
                const json_t *ty = json_object_get(json_array_get(list, i),
                                                   "type");
                if (json_is_string(ty) &&
                    strcmp(json_string_value(ty), "equilibrium") != 0)
                    continue; /* other analyses: checked by their tests */
                check_equilibrium(json_array_get(list, i), path);
            }
        } else {
            check_equilibrium(got, "");
        }
        json_decref(got);
        return nbad ? 1 : 0;
    }
    if (argc == 4 && strcmp(argv[1], "keys") == 0) {
        json_t *got = load(argv[3]);
        if (!got)
            return 2;
        keys(got, argv[2], strcmp(argv[2], "run") == 0);
        json_decref(got);
        for (int i = 0; i < nseen; i++)
            free(seen[i]);
        return 0;
    }
    fprintf(stderr, "usage: check_json parse FILE | compare RESULT EXPECTED "
                    "| equilibrium RESULT | keys COMMAND FILE\n");
    return 2;
}
