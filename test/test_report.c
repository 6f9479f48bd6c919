/* test_report.c: JSON and CSV writers (towstab/report.h).
 *
 * Content: an equilibrium filled by hand with awkward numbers (a branched
 * system: tow point, cable nodes, a junction and two spheres) goes to JSON
 * and CSV; every value must come back bit for bit (17 significant digits),
 * names follow the documented rule, angles are the directions' angles in
 * degrees, a non-finite number becomes null. Writing: a failed write
 * reports and leaves nothing (the rest of safe writing is
 * test_outfile.c). Streaming (lib/jsonout.h): every number is the
 * text jansson writes, checked against jansson itself over edge cases
 * and random bit patterns, and a streamed document is byte for byte
 * jansson's dump of the same tree, strings to escape included, indented
 * and in jansson's one-line form; the same calls build the same tree, and
 * a value where a key belongs builds none. Files go
 * to a fresh folder under $TMPDIR (default /tmp). */
#include "towstab/report.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "jsonout.h"
#include "report_impl.h"
#include "tcheck.h"
#include "tfiles.h"

/* Lead cable (2 links) to a junction, branches "up" (2 links) to sphere
 * "s1" and "lo" (1 link) to sphere "s2". */
static ts_system *branched(void)
{
    ts_system *s = ts_system_alloc(3, 3, NULL);
    if (!s)
        return NULL;
    snprintf(s->name, sizeof s->name, "report test");
    s->tow.speed = 1.2345678901234567;
    s->tow.turn_rate = -0.0123456789;
    const char *names[3] = {"lead", "up", "lo"};
    int from[3] = {-1, 0, 0}, to[3] = {0, 1, 2}, nl[3] = {2, 2, 1};
    for (int i = 0; i < 3; i++) {
        ts_cable *c = &s->cables[i];
        snprintf(c->name, sizeof c->name, "%s", names[i]);
        c->from_body = from[i];
        c->to_body = to[i];
        c->length = 1.7 + i;
        c->diameter = 0.01;
        c->mass_per_length = 0.3;
        c->nlinks = nl[i];
        c->cdn = 1.2;
    }
    const char *bn[3] = {"junction", "s1", "s2"};
    for (int b = 0; b < 3; b++) {
        snprintf(s->bodies[b].name, sizeof s->bodies[b].name, "%s", bn[b]);
        s->bodies[b].type = b ? TS_BODY_SPHERE : TS_BODY_JUNCTION;
        s->bodies[b].diameter = b ? 0.1 : 0;
        s->bodies[b].mass = 0.5;
    }
    ts_err err = {0};
    if (ts_system_build(s, &err) != TS_OK) {
        printf("build: %s\n", err.msg);
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* Fill an equilibrium with values that need all 17 digits. */
static void fill(const ts_system *s, ts_equilibrium *eq)
{
    eq->converged = 1;
    eq->iterations = 7;
    eq->evaluations = 123456789012L;
    eq->residual = 3.141592653589793e-13;
    eq->force_scale = 2.718281828459045;
    eq->tolerance = 1e-10;
    eq->method = TS_EQ_NEWTON;
    eq->top_tension = 12.345678901234567;
    eq->min_tension = -0.1;
    eq->tow_force[0] = -1.0 / 3;
    eq->tow_force[1] = 2.0 / 7;
    eq->tow_force[2] = 1e-300;
    for (int i = 0; i < s->nnodes; i++)
        for (int j = 0; j < 3; j++)
            eq->positions[3 * i + j] = (i + 1) / 3.0 + j * M_PI - 1e-17 * i;
    for (int l = 0; l < s->nlinks; l++) {
        double t1 = 0.1 + 0.37 * l, t2 = 0.05 * (l % 3) - 0.04;
        eq->directions[3 * l] = -cos(t1) * cos(t2);
        eq->directions[3 * l + 1] = -sin(t2);
        eq->directions[3 * l + 2] = sin(t1) * cos(t2);
        eq->tensions[l] = 10.0 / (l + 3);
    }
}

static double num(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static void test_json_content(const ts_system *s, const ts_equilibrium *eq)
{
    json_t *o = ts_report_equilibrium_json(s, eq, 0.0625, NULL);
    if (!CHECK(o != NULL, "json: object built"))
        return;
    CHECK(json_is_true(json_object_get(o, "converged")), "json: converged");
    CHECK(json_integer_value(json_object_get(o, "iterations")) == 7 &&
              json_integer_value(json_object_get(o, "evaluations")) ==
                  123456789012L,
          "json: iterations, evaluations (64-bit)");
    CHECK(num(o, "residual") == eq->residual &&
              num(o, "force_scale") == eq->force_scale &&
              num(o, "tolerance") == eq->tolerance &&
              num(o, "top_tension") == eq->top_tension &&
              num(o, "min_tension") == eq->min_tension &&
              num(o, "wall_s") == 0.0625,
          "json: residual, force_scale, tolerance, top/min tension, wall_s "
          "exact");
    CHECK(num(o, "speed") == s->tow.speed &&
              num(o, "turn_rate") == s->tow.turn_rate,
          "json: speed, turn_rate from the system");
    CHECK(!strcmp(json_string_value(json_object_get(o, "method")), "newton"),
          "json: method name");
    const json_t *tf = json_object_get(o, "tow_force");
    CHECK(json_array_size(tf) == 3 &&
              json_number_value(json_array_get(tf, 0)) == eq->tow_force[0] &&
              json_number_value(json_array_get(tf, 1)) == eq->tow_force[1] &&
              json_number_value(json_array_get(tf, 2)) == eq->tow_force[2],
          "json: tow_force [3]");

    /* Nodes: tow first, then in node order; names by the rule. */
    const json_t *nodes = json_object_get(o, "nodes");
    CHECK((int)json_array_size(nodes) == s->nnodes, "json: %d nodes",
          s->nnodes);
    static const char *want_names[] = {"tow",   "lead.1", "junction", "up.1",
                                       "s1",    "s2"};
    int names_ok = 1, pos_ok = 1;
    for (int i = 0; i < s->nnodes && i < 6; i++) {
        const json_t *n = json_array_get(nodes, (size_t)i);
        const char *nm = json_string_value(json_object_get(n, "name"));
        names_ok &= nm && !strcmp(nm, want_names[i]);
        pos_ok &= num(n, "x") == eq->positions[3 * i] &&
                  num(n, "y") == eq->positions[3 * i + 1] &&
                  num(n, "z") == eq->positions[3 * i + 2];
    }
    CHECK(s->nnodes == 6 && names_ok, "json: node names tow, lead.1, "
                                      "junction, up.1, s1, s2");
    CHECK(pos_ok, "json: node positions exact");
    char buf[64];
    ts_system_node_name(s, 3, buf, sizeof buf);
    CHECK(!strcmp(buf, "up.1"), "node_name: cable node 'up.1' (%s)", buf);
    ts_system_node_name(s, 0, buf, 3);
    CHECK(!strcmp(buf, "to"), "node_name: truncated to the buffer ('%s')",
          buf);

    /* Links: cable, index, tension, angles in degrees. */
    const json_t *links = json_object_get(o, "links");
    int links_ok = (int)json_array_size(links) == s->nlinks;
    double worst = 0;
    for (int l = 0; links_ok && l < s->nlinks; l++) {
        const json_t *L = json_array_get(links, (size_t)l);
        const ts_link *sl = &s->links[l];
        links_ok &= !strcmp(json_string_value(json_object_get(L, "cable")),
                            s->cables[sl->cable].name) &&
                    json_integer_value(json_object_get(L, "index")) ==
                        sl->index &&
                    num(L, "tension") == eq->tensions[l];
        double t1 = 0.1 + 0.37 * l, t2 = 0.05 * (l % 3) - 0.04;
        worst = fmax(worst, fabs(num(L, "theta1_deg") - t1 * 180 / M_PI));
        worst = fmax(worst, fabs(num(L, "theta2_deg") - t2 * 180 / M_PI));
    }
    CHECK(links_ok, "json: links carry cable, index, tension exactly");
    /* Angles pass through cos/sin and atan2/asin: rounding, 1e-12 deg. */
    CHECK(worst <= 1e-12, "json: theta1_deg, theta2_deg are the links' "
                          "angles in degrees (%.2g deg)", worst);

    /* Bodies: in body order at their nodes. */
    const json_t *bodies = json_object_get(o, "bodies");
    int bodies_ok = (int)json_array_size(bodies) == s->nbodies;
    for (int b = 0; bodies_ok && b < s->nbodies; b++) {
        const json_t *B = json_array_get(bodies, (size_t)b);
        int k = ts_system_body_node(s, b);
        bodies_ok &= !strcmp(json_string_value(json_object_get(B, "name")),
                             s->bodies[b].name) &&
                     num(B, "x") == eq->positions[3 * k] &&
                     num(B, "y") == eq->positions[3 * k + 1] &&
                     num(B, "z") == eq->positions[3 * k + 2];
    }
    CHECK(bodies_ok, "json: bodies named, at their nodes");

    /* Written and read back: the same document, every number exact. */
    char path[600];
    snprintf(path, sizeof path, "%s/eq.json", tf_dir);
    ts_err err = {0};
    int rc = ts_report_write_json(o, path, &err);
    json_error_t je;
    json_t *back = json_load_file(path, 0, &je);
    CHECK(rc == TS_OK && back && json_equal(o, back),
          "json: written file reads back equal, bit for bit (%s)",
          back ? "parsed" : je.text);
    CHECK(tf_count("partial") == 0, "json: no temporary file left");
    const char *text = tf_slurp(path);
    CHECK(text && text[strlen(text) - 1] == '\n' && strstr(text, "\n  \""),
          "json: indented, ends with a newline");
    json_decref(back);
    unlink(path);
    json_decref(o);
}

static void test_json_nonfinite(const ts_system *s, ts_equilibrium *eq)
{
    double keep = eq->residual, kx = eq->positions[4];
    eq->residual = NAN;
    eq->positions[4] = INFINITY;
    json_t *o = ts_report_equilibrium_json(s, eq, NAN, NULL);
    const json_t *n1 = json_array_get(json_object_get(o, "nodes"), 1);
    CHECK(o && json_is_null(json_object_get(o, "residual")) &&
              json_is_null(json_object_get(o, "wall_s")) &&
              json_is_null(json_object_get(n1, "y")),
          "json: NaN and Inf become null (JSON has no such numbers)");
    char path[600];
    snprintf(path, sizeof path, "%s/nan.json", tf_dir);
    int rc = ts_report_write_json(o, path, NULL);
    json_t *back = json_load_file(path, 0, NULL);
    CHECK(rc == TS_OK && back != NULL, "json: such a document is valid JSON");
    json_decref(back);
    json_decref(o);
    unlink(path);
    eq->residual = keep;
    eq->positions[4] = kx;
}

static void test_csv(const ts_system *s, const ts_equilibrium *eq)
{
    char path[600];
    snprintf(path, sizeof path, "%s/eq.csv", tf_dir);
    ts_err err = {0};
    int rc = ts_report_equilibrium_csv(s, eq, path, &err);
    CHECK(rc == TS_OK, "csv: written (%s)", err.msg);
    FILE *f = fopen(path, "r");
    if (!CHECK(f != NULL, "csv: file exists"))
        return;
    char line[1024];
    int row = -1, ok = 1;
    while (fgets(line, sizeof line, f)) {
        if (row < 0) {
            CHECK(!strcmp(line, "node,x_m,y_m,z_m,tension_above_N\n"),
                  "csv: header node,x_m,y_m,z_m,tension_above_N");
            row++;
            continue;
        }
        char name[128];
        double v[4];
        char *p = strchr(line, ',');
        if (!p || row >= s->nnodes) {
            ok = 0;
            break;
        }
        snprintf(name, sizeof name, "%.*s", (int)(p - line), line);
        for (int j = 0; j < 4; j++) {
            char *end;
            v[j] = strtod(p + 1, &end);
            ok &= end != p + 1 && (*end == ',' || *end == '\n');
            p = end;
        }
        char want[128];
        ts_system_node_name(s, row, want, sizeof want);
        double t = row == 0 ? eq->top_tension : eq->tensions[row - 1];
        ok &= !strcmp(name, want) && v[0] == eq->positions[3 * row] &&
              v[1] == eq->positions[3 * row + 1] &&
              v[2] == eq->positions[3 * row + 2] && v[3] == t;
        row++;
    }
    fclose(f);
    CHECK(ok && row == s->nnodes,
          "csv: one row per node (%d), names, positions and the tension "
          "above each node (top tension at the tow point) exact", row);
    unlink(path);
}

/* The writers go through lib/outfile.h (test_outfile.c tests it); here
 * only that a failed write reports and leaves nothing, and a good one
 * writes the document. */
static void test_write(const ts_system *s, const ts_equilibrium *eq)
{
    json_t *o = ts_report_equilibrium_json(s, eq, 0, NULL);
    char path[600];
    ts_err err = {0};

    snprintf(path, sizeof path, "%s/no/such/folder/eq.json", tf_dir);
    int rc = ts_report_write_json(o, path, &err);
    CHECK(rc == TS_EIO && strstr(err.msg, path) && !tf_exists(path),
          "write: missing folder: TS_EIO naming the path, nothing written "
          "(%s)", err.msg);
    ts_err_clear(&err);
    rc = ts_report_equilibrium_csv(s, eq, path, &err);
    CHECK(rc == TS_EIO && !tf_exists(path),
          "write: csv to a missing folder: TS_EIO (%s)", err.msg);

    snprintf(path, sizeof path, "%s/eq.json", tf_dir);
    rc = ts_report_write_json(o, path, &err);
    json_t *back = json_load_file(path, 0, NULL);
    CHECK(rc == TS_OK && back && json_equal(back, o) &&
              tf_count("partial") == 0,
          "write: the complete document, no temporary left");
    json_decref(back);
    unlink(path);
    json_decref(o);

    /* Text (a page): every byte, a NUL inside included; a failed write
     * leaves nothing. */
    static const char page[] = "<p>2.385 \xc2\xb1 0.01 m</p>\0tail\n";
    snprintf(path, sizeof path, "%s/page.html", tf_dir);
    rc = ts_report_write_text(page, sizeof page - 1, path, &err);
    FILE *f = fopen(path, "rb");
    char back_text[64] = {0};
    size_t got = f ? fread(back_text, 1, sizeof back_text, f) : 0;
    if (f)
        fclose(f);
    CHECK(rc == TS_OK && got == sizeof page - 1 &&
              !memcmp(back_text, page, got) && tf_count("partial") == 0,
          "write text: every byte (%zu of %zu), no temporary left", got,
          sizeof page - 1);
    unlink(path);
    snprintf(path, sizeof path, "%s/no/such/folder/page.html", tf_dir);
    ts_err_clear(&err);
    rc = ts_report_write_text(page, sizeof page - 1, path, &err);
    CHECK(rc == TS_EIO && strstr(err.msg, path) && !tf_exists(path),
          "write text: missing folder: TS_EIO naming the path, nothing "
          "written (%s)", err.msg);
}

/* jansson's text of v with JSON_REAL_PRECISION(17), the reference. */
static int jansson_text(double v, char *buf, size_t n)
{
    json_t *r = json_real(v);
    char *t = r ? json_dumps(r, JSON_ENCODE_ANY | JSON_REAL_PRECISION(17))
                : NULL;
    int ok = t && strlen(t) < n;
    if (ok)
        snprintf(buf, n, "%s", t);
    free(t);
    json_decref(r);
    return ok;
}

static void test_number_format(void)
{
    static const double edge[] = {0.0, -0.0, 1.0, -1.0, 0.1, 1e-5, 1e-4,
                                  1e16, 1e17, 123456789012345678.0,
                                  1e22, 1e100, -1e-100, 1e-300, 5e-324,
                                  2.2250738585072014e-308, 1.7976931348623157e308,
                                  1.0 / 3, 2.5435560000000002, 330.00518375772225};
    char mine[32], ref[64];
    int same = 1, exact = 1, n = 0;
    const char *bad = "";
    for (size_t i = 0; i < sizeof edge / sizeof edge[0]; i++, n++) {
        tsi_json_format(mine, edge[i]);
        if (!jansson_text(edge[i], ref, sizeof ref) || strcmp(mine, ref)) {
            same = 0;
            bad = ref;
        }
        exact &= strtod(mine, NULL) == edge[i] &&
                 signbit(strtod(mine, NULL)) == signbit(edge[i]);
    }
    /* Random doubles over every exponent: 64 random bits each (a fixed
     * xorshift sequence), the non-finite ones skipped. */
    unsigned long long x = 0x9E3779B97F4A7C15ULL;
    for (int k = 0; k < 200000; k++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        double v;
        memcpy(&v, &x, sizeof v);
        if (!isfinite(v))
            continue;
        n++;
        tsi_json_format(mine, v);
        if (!jansson_text(v, ref, sizeof ref) || strcmp(mine, ref)) {
            if (same)
                bad = ref;
            same = 0;
        }
        exact &= strtod(mine, NULL) == v;
    }
    CHECK(same, "stream: %d numbers printed as jansson prints them (%s)", n,
          same ? "all" : bad);
    CHECK(exact, "stream: every number reads back to the same double");
    tsi_json_format(mine, NAN);
    CHECK(!strcmp(mine, "null"), "stream: NaN is null (%s)", mine);
}

/* The equilibrium streamed, against jansson's dump of the whole tree. */
static void test_stream(ts_system *s, ts_equilibrium *eq)
{
    /* Names with what JSON must escape: a quote, a backslash, a tab, a
     * control character, and UTF-8 (written as it is). */
    char keep[sizeof s->cables[1].name];
    memcpy(keep, s->cables[1].name, sizeof keep);
    snprintf(s->cables[1].name, sizeof s->cables[1].name,
             "u\"p\\\t\x01\xc3\xa9/");
    double kx = eq->positions[4];
    eq->positions[4] = NAN;
    ts_trust t = {0};
    t.trustworthy = 1;
    json_t *full = ts_report_equilibrium_json(s, eq, 0.5, &t);
    char *ref = full ? json_dumps(full, JSON_INDENT(2) |
                                            JSON_REAL_PRECISION(17))
                     : NULL;
    tsi_json_defer d = {0};
    json_t *part = tsi_report_equilibrium_tree(s, eq, 0.5, &t, &d);
    CHECK(part && d.n == 2 &&
              json_array_size(json_object_get(part, "nodes")) == 0 &&
              json_array_size(json_object_get(part, "links")) == 0,
          "stream: nodes and links left out of the tree (%d deferred)", d.n);
    char path[600];
    snprintf(path, sizeof path, "%s/stream.json", tf_dir);
    ts_err err = {0};
    int rc = part ? tsi_report_write_tree(part, &d, path, &err) : -1;
    char *text = tf_slurp(path);
    size_t nref = ref ? strlen(ref) : 0;
    CHECK(rc == TS_OK && ref && text && strlen(text) == nref + 1 &&
              !strncmp(text, ref, nref) && text[nref] == '\n',
          "stream: the file is byte for byte jansson's dump of the full "
          "tree and a newline (%zu bytes)", nref);
    json_t *back = text ? json_loads(text, 0, NULL) : NULL;
    CHECK(back && json_equal(back, full), "stream: reads back equal");
    json_decref(back);
    unlink(path);

    /* The whole tree through the streaming writer (the public
     * ts_report_write_json) gives the same bytes. */
    rc = ts_report_write_json(full, path, &err);
    text = tf_slurp(path);
    CHECK(rc == TS_OK && ref && text && strlen(text) == nref + 1 &&
              !strncmp(text, ref, nref),
          "stream: ts_report_write_json writes jansson's text");
    unlink(path);

    /* The same calls building a tree: the full tree again. */
    tsi_json *tw = tsi_json_open_tree();
    if (tw && part)
        tsi_json_tree(tw, part, &d);
    json_t *built = tsi_json_take_tree(tw);
    CHECK(built && json_equal(built, full),
          "stream: a tree-building writer makes the full tree");
    json_decref(built);

    /* jansson's one-line form (json_dumps without JSON_INDENT), into
     * memory, byte for byte. */
    char *line = full ? json_dumps(full, JSON_REAL_PRECISION(17)) : NULL;
    char *mem = NULL;
    size_t nmem = 0;
    FILE *mf = open_memstream(&mem, &nmem);
    rc = mf && part ? tsi_report_dump_tree(part, &d, mf, TSI_JSON_SPACED)
                    : -1;
    if (mf)
        fclose(mf);
    CHECK(rc == 0 && line && mem && !strcmp(mem, line),
          "stream: the one-line form is jansson's (%zu bytes)",
          line ? strlen(line) : 0);
    free(mem);
    free(line);

    /* A misuse (a value where a key belongs) makes no tree. */
    tw = tsi_json_open_tree();
    if (tw) {
        tsi_json_object_open(tw);
        tsi_json_num(tw, 1.0);
        tsi_json_object_close(tw);
    }
    built = tsi_json_take_tree(tw);
    CHECK(tw && !built, "stream: a value without its key makes no tree");
    json_decref(built);

    /* A device that refuses the bytes: TS_EIO naming it. */
    if (tf_exists("/dev/full") && part) {
        ts_err_clear(&err);
        rc = tsi_report_write_tree(part, &d, "/dev/full", &err);
        CHECK(rc == TS_EIO && strstr(err.msg, "/dev/full"),
              "stream: /dev/full: TS_EIO (%s)", err.msg);
    }
    free(ref);
    json_decref(full);
    json_decref(part);
    eq->positions[4] = kx;
    memcpy(s->cables[1].name, keep, sizeof keep);
}

int main(void)
{
    if (tf_begin("report") != 0) {
        printf("FAIL cannot make a folder under %s: %s\n", tf_dir,
               strerror(errno));
        return 1;
    }
    ts_system *s = branched();
    ts_equilibrium *eq = s ? ts_equilibrium_alloc(s, NULL) : NULL;
    if (CHECK(s && eq, "system and result allocated")) {
        fill(s, eq);
        test_json_content(s, eq);
        test_json_nonfinite(s, eq);
        test_csv(s, eq);
        test_write(s, eq);
        test_number_format();
        test_stream(s, eq);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);
    CHECK(tf_end(), "nothing left in the test folder");
    return tc_done();
}
