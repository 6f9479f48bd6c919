/* test_plot.c: pictures (towstab/plot.h).
 *
 * With PLplot: every drawing function writes DIR/NAME.png (PNG signature,
 * the requested pixel size read from the IHDR chunk, more than 5 kB) and
 * DIR/NAME.svg (XML, carrying the title). The geometry is checked in the
 * SVG, whose paths cairo writes with the page coordinates: the side view's
 * water lies below the surface at the depth the window puts it (depth
 * grows downward), the top view has equal scales (the ship's arrowhead
 * keeps its 0.6 height/width ratio, the turning circle is round) with
 * starboard down the page, the unstable half-plane sits right of re = 0.
 * Bad arguments (no points, NaN, zero on a log axis, bad names, a file
 * where the directory should be, an unwritable directory) are refused
 * with TS_EINVAL or TS_EIO, a message, and no file left behind. The
 * caller's PLplot stream is current again after each call.
 *
 * Without PLplot (meson -Dplot=disabled): every drawing function returns
 * TS_EDOMAIN with the message naming the packages, and writes nothing.
 *
 * Unit conversions are checked against udunits2 (ts_units_from_si), an
 * independent implementation, to 1e-12 relative.
 *
 * Usage: test_plot [DIR] (pictures are kept in DIR when given, else made
 * in a temporary directory that is removed).
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "plot_impl.h"
#include "tcheck.h"
#include "towstab/plot.h"
#include "towstab/units.h"

#ifdef TS_HAVE_PLPLOT
#include <plplot.h>
#endif

static char dir[512];

/* ---- files ----------------------------------------------------------- */

#ifdef TS_HAVE_PLPLOT
static char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    if (buf) {
        buf[n] = '\0';
        *size = (size_t)n;
    }
    return buf;
}

static int file_exists(const char *name, const char *ext)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s.%s", dir, name, ext);
    struct stat st;
    return stat(path, &st) == 0;
}

#endif

/* No file of the directory starts with `name` (no picture and no
 * temporary file left behind). */
static int nothing_named(const char *name)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    int found = 0;
    while ((e = readdir(d)))
        found |= strncmp(e->d_name, name, strlen(name)) == 0;
    closedir(d);
    return !found;
}

#ifdef TS_HAVE_PLPLOT
static unsigned be32(const unsigned char *p)
{
    return (unsigned)p[0] << 24 | (unsigned)p[1] << 16 | (unsigned)p[2] << 8 |
           (unsigned)p[3];
}

/* Minimum size of a real picture, bytes: an empty 1000x700 white PNG is
 * about 3 kB, a plot with axes and text well over 20 kB. */
#define MIN_BYTES 5000

/* PNG: signature, IHDR width x height, size. */
static void check_png(const char *name, int width, int height)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    size_t n = 0;
    unsigned char *b = (unsigned char *)slurp(path, &n);
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G',
                                         '\r', '\n', 0x1a, '\n'};
    CHECK(b && n > 24 && memcmp(b, sig, 8) == 0, "%s.png has the PNG "
                                                 "signature",
          name);
    CHECK(b && n > 24 && memcmp(b + 12, "IHDR", 4) == 0 &&
              be32(b + 16) == (unsigned)width &&
              be32(b + 20) == (unsigned)height,
          "%s.png is %d x %d px (IHDR: %u x %u)", name, width, height,
          b && n > 24 ? be32(b + 16) : 0, b && n > 24 ? be32(b + 20) : 0);
    CHECK(n > MIN_BYTES, "%s.png has %zu bytes > %d", name, n, MIN_BYTES);
    free(b);
}

/* SVG: XML start, the title element, size. Returns the text (caller
 * frees) for geometry checks. */
static char *check_svg(const char *name, const char *title)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s.svg", dir, name);
    size_t n = 0;
    char *b = slurp(path, &n);
    CHECK(b && (strncmp(b, "<?xml", 5) == 0 || strncmp(b, "<svg", 4) == 0),
          "%s.svg starts with <?xml or <svg", name);
    char want[600];
    snprintf(want, sizeof want, "<title>%s</title>", title);
    CHECK(b && strstr(b, want), "%s.svg contains %s", name, want);
    CHECK(b && strstr(b, "</svg>"), "%s.svg is complete (</svg>)", name);
    CHECK(n > MIN_BYTES, "%s.svg has %zu bytes > %d", name, n, MIN_BYTES);
    return b;
}

/* ---- SVG geometry ---------------------------------------------------- */

/* Bounding box, in page coordinates (y down from the top), of the points
 * of every <path> whose style contains `style`. cairo writes paths with
 * transform="matrix(a,b,c,d,e,f)" (the page flip of PLplot's cairo
 * driver) or none. Returns the number of paths. */
typedef struct bbox {
    double x0, x1, y0, y1;
} bbox;

static int svg_bbox(const char *svg, const char *style, bbox *bb)
{
    bb->x0 = bb->y0 = INFINITY;
    bb->x1 = bb->y1 = -INFINITY;
    int npath = 0;
    for (const char *p = strstr(svg, "<path "); p;
         p = strstr(p + 1, "<path ")) {
        const char *end = strchr(p, '>');
        const char *st = strstr(p, "style=\"");
        if (!end || !st || st > end)
            continue;
        const char *st_end = strchr(st + 7, '"');
        size_t len = strlen(style);
        int match = 0;
        for (const char *q = st + 7; q + len <= st_end && !match; q++)
            match = strncmp(q, style, len) == 0;
        if (!match)
            continue;
        double m[6] = {1, 0, 0, 1, 0, 0};
        const char *tr = strstr(p, "transform=\"matrix(");
        if (tr && tr < end)
            sscanf(tr + 18, "%lf,%lf,%lf,%lf,%lf,%lf", &m[0], &m[1], &m[2],
                   &m[3], &m[4], &m[5]);
        const char *d = strstr(p, " d=\"");
        if (!d || d > end)
            continue;
        npath++;
        d += 4;
        while (*d && *d != '"') {
            if (*d == 'M' || *d == 'L') {
                double x, y;
                int used;
                if (sscanf(d + 1, "%lf %lf%n", &x, &y, &used) == 2) {
                    double X = m[0] * x + m[2] * y + m[4];
                    double Y = m[1] * x + m[3] * y + m[5];
                    bb->x0 = fmin(bb->x0, X);
                    bb->x1 = fmax(bb->x1, X);
                    bb->y0 = fmin(bb->y0, Y);
                    bb->y1 = fmax(bb->y1, Y);
                    d += used;
                    continue;
                }
            }
            d++;
        }
    }
    return npath;
}

/* Palette entries as cairo writes them (percent of 255). */
#define WATER_FILL "fill:rgb(87.058824%,92.54902%,98.039216%)"
#define SHIP_FILL "fill:rgb(54.901961%,54.901961%,54.901961%)"
#define UNSTABLE_FILL "fill:rgb(98.823529%,88.627451%,88.627451%)"
#define CIRCLE_STROKE "stroke-width:1.2;"
/* The plot box and its ticks (inside it): black lines 1 pt wide. */
#define AXIS_STROKE                                                           \
    "stroke-width:1;stroke-linecap:round;stroke-linejoin:bevel;"             \
    "stroke:rgb(0%,0%,0%)"

/* The plot box of single-panel pictures without a legend above it:
 * normalised y 0.11..0.89 of a 1000 x 700 page, x from a left edge that
 * depends on the tick labels' width (read from the SVG) to 0.97. */
#define BOX_RIGHT 970.0
#define BOX_TOP 77.0
#define BOX_BOTTOM 623.0

/* The plot box read from an SVG, checked against the fixed edges. */
static bbox svg_box(const char *svg, const char *name)
{
    bbox box = {NAN, NAN, NAN, NAN};
    int n = svg ? svg_bbox(svg, AXIS_STROKE, &box) : 0;
    CHECK(n >= 4 && fabs(box.x1 - BOX_RIGHT) < 0.5 &&
              fabs(box.y0 - BOX_TOP) < 0.5 &&
              fabs(box.y1 - BOX_BOTTOM) < 0.5 && box.x0 > 80 &&
              box.x0 < 160,
          "%s: plot box %.1f..%.1f x %.1f..%.1f pt", name, box.x0, box.x1,
          box.y0, box.y1);
    return box;
}
/* Tolerance of positions read from the SVG, pt: PLplot maps the page to
 * integer device units of 1/32 pt... cairo's coordinates are exact to
 * 0.01 pt; half a point covers the rounding of PLplot's device grid. */
#define POS_TOL 0.5

#endif /* TS_HAVE_PLPLOT */

/* ---- synthetic data -------------------------------------------------- */

enum { N = 21 };
/* A chain from a tow point 10 m above the water down to 30 m depth and
 * 50 m aft, a sphere at its end. */
static double chain[3 * N];
/* The same chain swung to starboard (a turn). */
static double chain_turn[3 * N];
/* A chain towed from the surface down to 40 m depth, 50 m aft. */
static double chain_sub[3 * N];
static const int end_mark[1] = {N - 1};

/* A branched tree: 6 links to a junction (node 6), then a branch of 4
 * links (nodes 7-10) and one of 3 links (nodes 11-13) from node 6. */
enum { NT = 14 };
static double tree[3 * NT];
#ifdef TS_HAVE_PLPLOT
static const int tree_upper[NT - 1] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 6, 11, 12};
static const int tree_marks[2] = {10, 13};
#endif

static void make_data(void)
{
    for (int k = 0; k < N; k++) {
        double s = (double)k / (N - 1);
        chain[3 * k] = -50 * s;
        chain[3 * k + 1] = 0;
        chain[3 * k + 2] = -10 + 50 * s - 10 * s * s;
        chain_turn[3 * k] = -45 * s;
        chain_turn[3 * k + 1] = 8.385 * s * s;
        chain_turn[3 * k + 2] = -10 + 35 * s;
        chain_sub[3 * k] = -50 * s;
        chain_sub[3 * k + 1] = 0;
        chain_sub[3 * k + 2] = 48 * s - 8 * s * s;
    }
    for (int k = 0; k < NT; k++) {
        double x, z;
        if (k <= 6) {
            x = -2.0 * k;
            z = 1.5 * k;
        } else if (k <= 10) {
            x = -12 - 3.0 * (k - 6);
            z = 9 + 0.5 * (k - 6);
        } else {
            x = -12 - 1.5 * (k - 10);
            z = 9 + 2.0 * (k - 10);
        }
        tree[3 * k] = x;
        tree[3 * k + 1] = 0.1 * x;
        tree[3 * k + 2] = z;
    }
}

/* ---- with PLplot ----------------------------------------------------- */

#ifdef TS_HAVE_PLPLOT

/* Occurrences of `what` in s. */
static int count_of(const char *s, const char *what)
{
    int n = 0;
    for (const char *p = strstr(s, what); p; p = strstr(p + 1, what))
        n++;
    return n;
}

static void test_shapes(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    /* Side view of a submerged chain without labels: no legend, so the
     * plot box is known. */
    ts_plot_shape one = {N, chain_sub, NULL, 1, end_mark, 0, NULL, 0, 0,
                         0, NULL, 0, NULL};
    int rc = ts_plot_shapes(dir, "side_si", "chain: side view", TS_PLOT_SIDE,
                            TS_PLOT_WATER, 1, &one, &o, &err);
    CHECK(rc == TS_OK, "side view drawn (%s)", err.msg);
    check_png("side_si", 1000, 700);
    char *svg = check_svg("side_si", "chain: side view");
    /* Window: depth 0..40 m, with a strip of air of 4 % of the largest
     * extent (50 m) above the surface: -2..40 m, padded by 8 % of 42 m
     * = 3.36 m on both sides; depth downward, so the surface z = 0 is
     * 5.36/48.72 of the box height below its top and the water fills the
     * box below it. */
    bbox water, box = svg_box(svg, "side view");
    int nw = svg ? svg_bbox(svg, WATER_FILL, &water) : 0;
    double surface = BOX_TOP + (BOX_BOTTOM - BOX_TOP) * 5.36 / 48.72;
    CHECK(nw == 1, "side view: one water fill (%d)", nw);
    CHECK_NEAR(water.y0, surface, POS_TOL, "water surface y, pt from top");
    CHECK_NEAR(water.y1, BOX_BOTTOM, POS_TOL, "water reaches the box bottom");
    CHECK_NEAR(water.x0, box.x0, POS_TOL, "water from the box's left");
    CHECK_NEAR(water.x1, BOX_RIGHT, POS_TOL, "water to the box's right");

    /* Imperial units: the same geometry, other labels. */
    o.units = TS_PLOT_IMPERIAL;
    rc = ts_plot_shapes(dir, "side_imp", "chain: side view", TS_PLOT_SIDE,
                        TS_PLOT_WATER, 1, &one, &o, &err);
    CHECK(rc == TS_OK, "imperial side view drawn (%s)", err.msg);
    char *svg_imp = check_svg("side_imp", "chain: side view");
    bbox w2;
    if (svg_imp)
        svg_bbox(svg_imp, WATER_FILL, &w2);
    CHECK(svg_imp && fabs(w2.y0 - water.y0) < 0.05 &&
              fabs(w2.y1 - water.y1) < 0.05,
          "imperial: water at the same place (%.2f..%.2f vs %.2f..%.2f pt)",
          svg_imp ? w2.y0 : NAN, svg_imp ? w2.y1 : NAN, water.y0, water.y1);
    size_t n1 = 0, n2 = 0;
    char p1[700], p2[700];
    snprintf(p1, sizeof p1, "%s/side_si.png", dir);
    snprintf(p2, sizeof p2, "%s/side_imp.png", dir);
    char *b1 = slurp(p1, &n1), *b2 = slurp(p2, &n2);
    CHECK(b1 && b2 && (n1 != n2 || memcmp(b1, b2, n1) != 0),
          "imperial and SI pictures differ (axis labels in ft, not m)");
    free(b1);
    free(b2);
    free(svg_imp);
    free(svg);
    o.units = TS_PLOT_SI;

    /* Overlay: straight and turning, side and top, with labels. */
    ts_plot_shape two[2] = {
        {N, chain, NULL, 1, end_mark, 0, "5 knot, straight", TS_PLOT_SOLID,
         0, 0, NULL, 0, NULL},
        {N, chain_turn, NULL, 1, end_mark, 38.5, "5 knot, turn",
         TS_PLOT_DASHED, 0, 0, NULL, 0, NULL}};
    rc = ts_plot_shapes(dir, "side", "overlay: side view", TS_PLOT_SIDE,
                        TS_PLOT_WATER | TS_PLOT_EQUAL, 2, two, &o, &err);
    CHECK(rc == TS_OK, "side view of two shapes drawn (%s)", err.msg);
    check_png("side", 1000, 700);
    free(check_svg("side", "overlay: side view"));
    rc = ts_plot_shapes(dir, "top", "overlay: top view", TS_PLOT_TOP,
                        TS_PLOT_WATER, 2, two, &o, &err);
    CHECK(rc == TS_OK, "top view drawn (%s)", err.msg);
    check_png("top", 1000, 700);
    svg = check_svg("top", "overlay: top view");
    bbox ship, circle;
    int ns = svg ? svg_bbox(svg, SHIP_FILL, &ship) : 0;
    int nc = svg ? svg_bbox(svg, CIRCLE_STROKE, &circle) : 0;
    CHECK(ns == 1, "top view: the ship is drawn (%d fill)", ns);
    /* The arrowhead is 2 s long and 1.2 s wide in world units. */
    CHECK_NEAR((ship.y1 - ship.y0) / (ship.x1 - ship.x0), 0.6, 0.005,
               "top view equal scales: ship's width/length on the page");
    CHECK(nc > 10, "top view: the turning circle is drawn (%d dots)", nc);
    CHECK_NEAR((circle.y1 - circle.y0) / (circle.x1 - circle.x0), 1.0, 0.005,
               "top view equal scales: the turning circle is round");
    /* Starboard turn: centre (0, R) is below the ship on the page; the
     * ship (origin) is the circle's top point. */
    double ship_y = 0.5 * (ship.y0 + ship.y1);
    CHECK_NEAR(circle.y0, ship_y, 1.5, "turning circle starts at the ship");
    CHECK(circle.y1 > ship_y + 100, "starboard is down the page (circle "
                                    "bottom %.1f pt, ship %.1f pt)",
          circle.y1, ship_y);
    free(svg);

    /* A branched tree in both views. */
    ts_plot_shape t = {NT,     tree, tree_upper, 2, tree_marks, -20,
                       "tree", 0,    3,          0, NULL, 0, NULL};
    rc = ts_plot_shapes(dir, "tree_side", "tree", TS_PLOT_SIDE,
                        TS_PLOT_WATER | TS_PLOT_EQUAL, 1, &t, &o, &err);
    CHECK(rc == TS_OK, "branched tree, side view (%s)", err.msg);
    rc = ts_plot_shapes(dir, "tree_top", "tree", TS_PLOT_TOP, 0, 1, &t, &o,
                        &err);
    CHECK(rc == TS_OK, "branched tree, top view, port turn (%s)", err.msg);
    check_png("tree_top", 1000, 700);

    /* A body outline (a square of 0.2 m at the end of the chain) drawn
     * with its attitude; a bad one refused. */
    const double *e = chain + 3 * (N - 1);
    double sq[15] = {e[0], e[1], e[2], e[0] - 0.2, e[1], e[2],
                     e[0] - 0.2, e[1], e[2] + 0.2, e[0], e[1], e[2] + 0.2,
                     e[0], e[1], e[2]};
    ts_plot_outline ol = {5, sq, {e[0], e[1], e[2]}};
    ts_plot_shape b = {N, chain, NULL, 1, end_mark, 0, "with a body", 0, 0,
                       0, NULL, 1, &ol};
    rc = ts_plot_shapes(dir, "outline", "outline", TS_PLOT_SIDE,
                        TS_PLOT_WATER, 1, &b, &o, &err);
    CHECK(rc == TS_OK && file_exists("outline", "png"),
          "a body's outline drawn (%s)", err.msg);
    ts_plot_outline bad = {5, NULL, {0, 0, 0}};
    b.outlines = &bad;
    ts_err e2 = {0};
    rc = ts_plot_shapes(dir, "outline_bad", "outline", TS_PLOT_SIDE, 0, 1,
                        &b, &o, &e2);
    CHECK(rc == TS_EINVAL && strstr(e2.msg, "outlines[0]"),
          "an outline without points refused (%s)", e2.msg);
}

/* A cylinder towfish: drawn as a filled outline (two paths more than
 * the same picture without it), and a bad one refused. */
static void test_cylinder(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    ts_plot_shape one = {N, chain_sub, NULL, 0, NULL, 0, NULL, 0, 0, 0, NULL, 0, NULL};
    int rc = ts_plot_shapes(dir, "cyl_without", "towfish", TS_PLOT_SIDE,
                            TS_PLOT_WATER, 1, &one, &o, &err);
    ts_plot_cylinder cy = {N - 1, 2.0, 0.4};
    one.ncylinders = 1;
    one.cylinders = &cy;
    rc = rc ? rc
            : ts_plot_shapes(dir, "cyl_with", "towfish", TS_PLOT_SIDE,
                             TS_PLOT_WATER, 1, &one, &o, &err);
    CHECK(rc == TS_OK, "a shape with a cylinder drawn (%s)", err.msg);
    check_png("cyl_with", 1000, 700);
    char *a = check_svg("cyl_without", "towfish");
    char *b = check_svg("cyl_with", "towfish");
    int na = a ? count_of(a, "<path ") : 0, nb = b ? count_of(b, "<path ")
                                                  : 0;
    CHECK(a && b && nb == na + 2, "the cylinder adds its fill and outline "
          "(%d paths, %d without)", nb, na);
    free(a);
    free(b);
    ts_plot_opts_default(&o);
    rc = ts_plot_shapes(dir, "top_cyl", "towfish, top", TS_PLOT_TOP, 0, 1,
                        &one, &o, &err);
    CHECK(rc == TS_OK, "the top view with a cylinder drawn (%s)", err.msg);
    cy.node = 0;
    rc = ts_plot_shapes(dir, "cyl_bad", "x", TS_PLOT_SIDE, 0, 1, &one, &o,
                        &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "cylinders[0].node"),
          "a cylinder on the tow point is refused: %s", err.msg);
    cy.node = N - 1;
    cy.diameter = 0;
    rc = ts_plot_shapes(dir, "cyl_bad", "x", TS_PLOT_SIDE, 0, 1, &one, &o,
                        &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "diameter"),
          "a cylinder of diameter 0 is refused: %s", err.msg);
    CHECK(nothing_named("cyl_bad"), "refused shapes left no file");
}

/* A mode as an animated SVG: the file, its title, one <animate> with
 * nframes + 1 path values, the first and the last the same (the loop
 * closes), the frames apart; no PNG; bad frame counts refused. */
static void test_animation(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    static double re[3 * N], im[3 * N];
    for (int k = 0; k < N; k++) {
        double s = (double)k / (N - 1);
        re[3 * k + 2] = sin(M_PI * s);
        im[3 * k] = 0.5 * sin(2 * M_PI * s);
    }
    ts_plot_shape eq = {N, chain_sub, NULL, 1, end_mark, 0, NULL, 0, 0,
                        0, NULL, 0, NULL};
    int rc = ts_plot_mode_animation(dir, "anim", "chain: mode 1", TS_PLOT_SIDE,
                                    TS_PLOT_WATER, &eq, re, im, NULL, NULL,
                                    "mode 1: 0.5 Hz", 12, 2.0, &o, &err);
    CHECK(rc == TS_OK, "mode animation written (%s)", err.msg);
    char *svg = check_svg("anim", "chain: mode 1");
    CHECK(!file_exists("anim", "png"), "an animation is an SVG only");
    const char *v = svg ? strstr(svg, "<animate ") : NULL;
    const char *vals = v ? strstr(v, "values=\"") : NULL;
    const char *end = vals ? strchr(vals + 8, '"') : NULL;
    int nsep = 0;
    for (const char *p = vals; p && p < end; p++)
        nsep += *p == ';';
    CHECK(v && end && nsep == 12, "one <animate> with 13 path values (%d "
          "separators)", nsep);
    if (v && end && nsep == 12) {
        const char *first = vals + 8, *f_end = strchr(first, ';');
        const char *last = end;
        while (last > first && last[-1] != ';')
            last--;
        size_t lf = (size_t)(f_end - first), ll = (size_t)(end - last);
        CHECK(lf == ll && strncmp(first, last, lf) == 0,
              "the cycle closes: the last frame is the first");
        const char *second = f_end + 1, *s_end = strchr(second, ';');
        CHECK((size_t)(s_end - second) != lf ||
                  strncmp(first, second, lf) != 0,
              "the second frame differs from the first");
    }
    free(svg);
    rc = ts_plot_mode_animation(dir, "anim_bad", "x", TS_PLOT_SIDE, 0, &eq,
                                re, im, NULL, NULL, NULL, 2, 2.0, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "nframes"),
          "2 frames are refused: %s", err.msg);
    rc = ts_plot_mode_animation(dir, "anim_bad", "x", TS_PLOT_SIDE, 0, &eq,
                                re, im, NULL, NULL, NULL, 12, 0.0, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "seconds"),
          "a cycle of 0 s is refused: %s", err.msg);
    CHECK(nothing_named("anim_bad"), "refused animations left no file");

    /* The plan view of the same cycle, and the cycle as PNG frames: four
     * frames in both views, PNG only, each its own picture, the
     * equilibrium's place the same in every frame (one window). */
    rc = ts_plot_mode_animation(dir, "anim_top", "chain: mode 1, plan",
                                TS_PLOT_TOP, 0, &eq, re, im, NULL, NULL,
                                NULL, 12, 2.0, &o, &err);
    CHECK(rc == TS_OK, "mode animation in plan view (%s)", err.msg);
    free(check_svg("anim_top", "chain: mode 1, plan"));
    for (int v = 0; v < 2; v++) {
        const char *nm = v ? "frames_top" : "frames_side";
        rc = ts_plot_mode_frames(dir, nm, "chain: mode 1", v ? TS_PLOT_TOP
                                                               : TS_PLOT_SIDE,
                                 TS_PLOT_WATER, &eq, re, im, NULL, NULL,
                                 "mode 1: 0.5 Hz", 4, &o, &err);
        CHECK(rc == TS_OK, "%s: four PNG frames written (%s)", nm, err.msg);
        char f[4][64];
        size_t n[4] = {0};
        char *b[4];
        for (int k = 0; k < 4; k++) {
            snprintf(f[k], sizeof f[k], "%s_%03d", nm, k);
            check_png(f[k], 1000, 700);
            char path[1024];
            snprintf(path, sizeof path, "%s/%s.png", dir, f[k]);
            b[k] = slurp(path, &n[k]);
        }
        snprintf(f[0], sizeof f[0], "%s_004", nm);
        CHECK(!file_exists(f[0], "png") && !file_exists(nm, "svg"),
              "%s: exactly four frames, no SVG", nm);
        CHECK(b[0] && b[1] && (n[0] != n[1] || memcmp(b[0], b[1], n[0])),
              "%s: the frames differ", nm);
        for (int k = 0; k < 4; k++)
            free(b[k]);
    }
    rc = ts_plot_mode_frames(dir, "frames_bad", "x", TS_PLOT_SIDE, 0, &eq, re,
                             im, NULL, NULL, NULL, 2, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "nframes"),
          "frames: 2 frames are refused: %s", err.msg);
    CHECK(nothing_named("frames_bad"), "refused frames left no file");
}

/* The first side of a vehicle's outline in SVG path data "Mx y Lx y ...":
 * its angle (rad, page axes) and length (px); 0 when it does not parse. */
static int first_side(const char *d, double *angle, double *length)
{
    double x0, y0, x1, y1;
    if (sscanf(d, "M%lf %lf L%lf %lf", &x0, &y0, &x1, &y1) != 4)
        return 0;
    *angle = atan2(y1 - y0, x1 - x0);
    *length = hypot(x1 - x0, y1 - y0);
    return 1;
}

/* A vehicle in the animations: its outline drawn grey at the trim and,
 * with the mode's outline motion, moved and rotated at every frame. A
 * square in the plan view yawed by Re((a + i b) e^{i phi}) per unit of
 * the mode: the first side of frame k turns from the trim's by
 * s (a cos phi_k - b sin phi_k), s the cycle's scale (0.15 of the
 * equilibrium's extent over the largest node amplitude), and keeps its
 * length (a yaw is a rigid motion in plan, equal scales). */
static void test_animation_vehicle(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    static double re[3 * N], im[3 * N];
    double amax = 0;
    for (int k = 0; k < N; k++) {
        double s = (double)k / (N - 1);
        re[3 * k + 2] = sin(M_PI * s);
        im[3 * k] = 0.5 * sin(2 * M_PI * s);
        amax = fmax(amax, hypot(re[3 * k + 2], im[3 * k]));
    }
    const double *e = chain_sub + 3 * (N - 1);
    double sq[15] = {e[0], e[1], e[2], e[0] - 0.2, e[1], e[2],
                     e[0] - 0.2, e[1] + 0.2, e[2], e[0], e[1] + 0.2, e[2],
                     e[0], e[1], e[2]};
    ts_plot_outline ol = {5, sq, {e[0], e[1], e[2]}};
    ts_plot_shape eq = {N, chain_sub, NULL, 1, end_mark, 0, NULL, 0, 0,
                        0, NULL, 1, &ol};
    /* The anchor moves with the chain's end; the yaw is a, b. */
    const double a = 0.04, b = 0.02;
    double ore[6] = {re[3 * (N - 1)], 0, re[3 * (N - 1) + 2], 0, 0, a};
    double oim[6] = {im[3 * (N - 1)], 0, im[3 * (N - 1) + 2], 0, 0, b};
    enum { NF = 12 };
    int rc = ts_plot_mode_animation(dir, "anim_vehicle", "vehicle: mode 1",
                                    TS_PLOT_TOP, 0, &eq, re, im, ore, oim,
                                    NULL, NF, 2.0, &o, &err);
    CHECK(rc == TS_OK, "animation with a vehicle written (%s)", err.msg);
    char *svg = check_svg("anim_vehicle", "vehicle: mode 1");
    const char *trim = svg ? strstr(svg, "class=\"vehicle-trim\"") : NULL;
    const char *veh = svg ? strstr(svg, "class=\"vehicle\"") : NULL;
    const char *vals = veh ? strstr(veh, "values=\"") : NULL;
    const char *td = trim ? strstr(trim, "d=\"") : NULL;
    double a0 = 0, l0 = 0;
    int ok = vals && td && first_side(td + 3, &a0, &l0);
    CHECK(ok, "the vehicle drawn grey at its trim and as an animated path");
    /* Extent 50 m (x from 0 to -50, y = 0 in plan). */
    double scale = 0.15 * 50 / amax, worst_angle = 0, worst_len = 0;
    double turned = 0;
    int nfr = 0;
    const char *p = ok ? vals + 8 : NULL;
    while (p && *p != '"' && nfr <= NF) {
        double ak, lk;
        if (!first_side(p, &ak, &lk))
            break;
        double phi = 2 * M_PI * (nfr % NF) / NF;
        double want = scale * (a * cos(phi) - b * sin(phi));
        double got = remainder(ak - a0, 2 * M_PI);
        worst_angle = fmax(worst_angle, fabs(got - want));
        worst_len = fmax(worst_len, fabs(lk - l0));
        turned = fmax(turned, fabs(got));
        nfr++;
        p += strcspn(p, ";\"");
        if (*p == ';')
            p++;
    }
    /* Coordinates are written to 0.01 px on a side of some 40 px: the
     * angle to about 5e-4 rad, the length to 0.02 px. */
    CHECK(nfr == NF + 1 && worst_angle < 2e-3 && worst_len < 0.03 &&
              turned > 0.2,
          "animation: the vehicle yawed by s Re((a + i b) e^{i phi}) in each "
          "of %d frames to %.2g rad (up to %.3f rad), its side kept to %.2g "
          "px", nfr, worst_angle, turned, worst_len);
    free(svg);

    /* Without the outline motion the vehicle stays at its trim: no
     * animated outline. */
    rc = ts_plot_mode_animation(dir, "anim_vehicle_trim", "trim",
                                TS_PLOT_SIDE, TS_PLOT_WATER, &eq, re, im,
                                NULL, NULL, NULL, NF, 2.0, &o, &err);
    svg = rc == TS_OK ? check_svg("anim_vehicle_trim", "trim") : NULL;
    CHECK(svg && strstr(svg, "class=\"vehicle-trim\"") &&
              !strstr(svg, "class=\"vehicle\""),
          "animation without outline motion: the vehicle at its trim only");
    free(svg);
    rc = ts_plot_mode_animation(dir, "anim_vehicle_bad", "x", TS_PLOT_SIDE,
                                0, &eq, re, im, ore, NULL, NULL, NF, 2.0, &o,
                                &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "outline_im"),
          "an outline motion without its imaginary part is refused: %s",
          err.msg);
    oim[5] = NAN;
    rc = ts_plot_mode_frames(dir, "anim_vehicle_bad", "x", TS_PLOT_SIDE, 0,
                             &eq, re, im, ore, oim, NULL, 4, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "outline_im"),
          "frames: a non-finite outline motion is refused: %s", err.msg);
    CHECK(nothing_named("anim_vehicle_bad"), "refused: no file");
    oim[5] = b;

    /* The PNG frames: with the motion, each frame differs from the same
     * frame with the vehicle at its trim (the cable is the same). */
    int differ = 0;
    for (int v = 0; v < 2; v++) {
        const char *nm[2] = {v ? "vframes_top" : "vframes_side",
                             v ? "vframes_top_trim" : "vframes_side_trim"};
        for (int t = 0; t < 2; t++) {
            rc = ts_plot_mode_frames(dir, nm[t], "vehicle", v ? TS_PLOT_TOP
                                                              : TS_PLOT_SIDE,
                                     TS_PLOT_WATER, &eq, re, im,
                                     t ? NULL : ore, t ? NULL : oim, NULL,
                                     4, &o, &err);
            CHECK(rc == TS_OK, "%s: frames written (%s)", nm[t], err.msg);
        }
        for (int k = 1; k < 4; k++) {
            char path[2][1024];
            size_t n[2] = {0};
            char *bf[2];
            for (int t = 0; t < 2; t++) {
                snprintf(path[t], sizeof path[t], "%s/%s_%03d.png", dir,
                         nm[t], k);
                bf[t] = slurp(path[t], &n[t]);
            }
            differ += bf[0] && bf[1] &&
                      (n[0] != n[1] || memcmp(bf[0], bf[1], n[0]));
            free(bf[0]);
            free(bf[1]);
        }
    }
    CHECK(differ == 6, "frames: the moved vehicle changes frames 1-3 of both "
          "views (%d of 6 differ from the trim-only frames)", differ);
}


static void test_modes(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    enum { NM = 4 };
    static double disp[NM][3 * N];
    ts_plot_mode modes[NM];
    char label[NM][64];
    for (int m = 0; m < NM; m++) {
        for (int k = 0; k < N; k++) {
            double s = (double)k / (N - 1);
            double a = sin((m / 2 + 1) * M_PI * s * 0.9);
            disp[m][3 * k] = 0.1 * a;
            disp[m][3 * k + 1] = m % 2 ? a : 0;
            disp[m][3 * k + 2] = m % 2 ? 0 : a;
        }
        snprintf(label[m], sizeof label[m], "mode %d: %.3f Hz", m + 1,
                 0.2385 * (m + 1));
        modes[m].disp = disp[m];
        modes[m].label = label[m];
        modes[m].outline_motion = NULL;
    }
    ts_plot_shape eq = {N, chain, NULL, 1, end_mark, 0, NULL, 0, 0, 0, NULL, 0, NULL};
    int rc = ts_plot_mode_shapes(dir, "modes", "chain: lowest modes",
                                 TS_PLOT_WATER, &eq, NM, modes, &o, &err);
    CHECK(rc == TS_OK, "mode shapes drawn (%s)", err.msg);
    /* 95 px title, 220 px per mode, 50 px axis title. */
    check_png("modes", 1000, 95 + 220 * NM + 50);
    free(check_svg("modes", "chain: lowest modes"));
    rc = ts_plot_mode_shapes(dir, "modes2", "two modes", TS_PLOT_WATER, &eq,
                             2, modes, &o, &err);
    CHECK(rc == TS_OK, "two mode shapes drawn (%s)", err.msg);
    check_png("modes2", 1000, 700);
    /* A cylinder towfish at the end: drawn on the equilibrium and on the
     * mode at both phases, in both views: 6 fills and 6 outlines per
     * mode row more than without it. */
    ts_plot_cylinder cy = {N - 1, 2.0, 0.4};
    ts_plot_shape eqc = eq;
    eqc.ncylinders = 1;
    eqc.cylinders = &cy;
    rc = ts_plot_mode_shapes(dir, "modes2_cyl", "two modes", TS_PLOT_WATER,
                             &eqc, 2, modes, &o, &err);
    CHECK(rc == TS_OK, "two mode shapes with a cylinder drawn (%s)",
          err.msg);
    char *a = check_svg("modes2", "two modes");
    char *b = check_svg("modes2_cyl", "two modes");
    int na = a ? count_of(a, "<path ") : 0, nb = b ? count_of(b, "<path ")
                                                  : 0;
    CHECK(a && b && nb == na + 2 * 2 * 6, "mode shapes: the cylinder drawn "
          "on the equilibrium and both phases of each mode, both views (%d "
          "paths, %d without)", nb, na);
    free(a);
    free(b);

    /* A vehicle's outline moved and rotated by the mode: drawn at both
     * phases in both views of each row, in the mode's colour, beside its
     * grey trim outline (a square of 4 points, 3 segments). */
    const double *e = chain + 3 * (N - 1);
    double sq[15] = {e[0], e[1], e[2], e[0] - 0.2, e[1], e[2],
                     e[0] - 0.2, e[1], e[2] + 0.2, e[0], e[1], e[2] + 0.2,
                     e[0], e[1], e[2]};
    ts_plot_outline ol = {5, sq, {e[0], e[1], e[2]}};
    ts_plot_shape eqo = eq;
    eqo.noutlines = 1;
    eqo.outlines = &ol;
    rc = ts_plot_mode_shapes(dir, "modes2_trim", "two modes", TS_PLOT_WATER,
                             &eqo, 2, modes, &o, &err);
    double motion[2][6] = {{0.01, 0, 0.02, 0, 0.3, 0},
                           {0, 0.02, 0, 0.1, 0, 0.2}};
    ts_plot_mode moved[2] = {modes[0], modes[1]};
    moved[0].outline_motion = motion[0];
    moved[1].outline_motion = motion[1];
    if (rc == TS_OK)
        rc = ts_plot_mode_shapes(dir, "modes2_moved", "two modes",
                                 TS_PLOT_WATER, &eqo, 2, moved, &o, &err);
    a = check_svg("modes2_trim", "two modes");
    b = check_svg("modes2_moved", "two modes");
    na = a ? count_of(a, "<path ") : 0;
    nb = b ? count_of(b, "<path ") : 0;
    CHECK(rc == TS_OK && a && b && nb - na >= 2 * 2 * 2,
          "mode shapes: the vehicle's outline moved by each mode at both "
          "phases, both views: %d paths more than at the trim only (%d; at "
          "least one per mode, phase and view)", nb - na, na);
    free(a);
    free(b);
    motion[1][4] = NAN;
    ts_err_clear(&err);
    rc = ts_plot_mode_shapes(dir, "modes_badmotion", "x", 0, &eqo, 2, moved,
                             &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "outline_motion"),
          "a non-finite outline motion is refused: %s", err.msg);

    static double zero[3 * N];
    ts_plot_mode bad = {zero, "nothing", NULL};
    ts_err_clear(&err);
    rc = ts_plot_mode_shapes(dir, "modes_zero", "x", 0, &eq, 1, &bad, &o,
                             &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "all zero"),
          "a mode of zero displacement is refused: %s", err.msg);
    rc = ts_plot_mode_shapes(dir, "modes_none", "x", 0, &eq, 0, modes, &o,
                             &err);
    CHECK(rc == TS_EINVAL, "nmodes = 0 is refused: %s", err.msg);
    rc = ts_plot_mode_shapes(dir, "modes_many", "x", 0, &eq, 9, modes, &o,
                             &err);
    CHECK(rc == TS_EINVAL, "nmodes = 9 is refused: %s", err.msg);
    CHECK(nothing_named("modes_"), "refused mode plots left no file");
}


static void test_eigenvalues(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    /* Pairs lambda = wn (-zeta +- i sqrt(1 - zeta^2)) and an unstable
     * pair. */
    static const double wn[4] = {0.5, 1.2, 2.0, 3.1},
                        zeta[4] = {0.03, 0.08, 0.15, 0.4};
    double re[8], im[8], ure[2] = {0.05, 0.05}, uim[2] = {0.8, -0.8};
    for (int i = 0; i < 4; i++) {
        re[2 * i] = re[2 * i + 1] = -zeta[i] * wn[i];
        im[2 * i] = wn[i] * sqrt(1 - zeta[i] * zeta[i]);
        im[2 * i + 1] = -im[2 * i];
    }
    ts_plot_series sets[2] = {{8, re, im, "2.385 m/s", 0, 0, 0, NULL},
                              {2, ure, uim, "4 m/s", 0, 0, 0, NULL}};
    int rc = ts_plot_eigenvalues(dir, "eig", "chain: eigenvalues", 2, sets,
                                 NULL, &o, &err);
    CHECK(rc == TS_OK, "eigenvalues drawn (%s)", err.msg);
    check_png("eig", 1000, 700);
    free(check_svg("eig", "chain: eigenvalues"));
    /* A given window -2..0.5 1/s: the unstable half-plane is the right
     * 0.5/2.5 of the box. */
    ts_plot_eig_window win = {-2, 0.5, 3};
    rc = ts_plot_eigenvalues(dir, "eig_win", "window", 2, sets, &win, &o,
                             &err);
    CHECK(rc == TS_OK, "eigenvalues in a given window (%s)", err.msg);
    size_t n;
    char path[700];
    snprintf(path, sizeof path, "%s/eig_win.svg", dir);
    char *svg = slurp(path, &n);
    bbox shade, box = svg_box(svg, "eigenvalue window");
    int nsh = svg ? svg_bbox(svg, UNSTABLE_FILL, &shade) : 0;
    CHECK(nsh == 1, "one unstable shade (%d)", nsh);
    CHECK_NEAR(shade.x0, box.x0 + (box.x1 - box.x0) * 2.0 / 2.5, POS_TOL,
               "stability boundary re = 0 at 4/5 of the width");
    CHECK_NEAR(shade.x1, BOX_RIGHT, POS_TOL, "shade to the box's right");
    CHECK_NEAR(shade.y0, BOX_TOP, POS_TOL, "shade from the box's top");
    CHECK_NEAR(shade.y1, BOX_BOTTOM, POS_TOL, "shade to the box's bottom");
    free(svg);

    ts_plot_eig_window badwin = {1, 0.5, 3};
    rc = ts_plot_eigenvalues(dir, "eig_bad", "x", 2, sets, &badwin, &o, &err);
    CHECK(rc == TS_EINVAL, "re_min > 0 is refused: %s", err.msg);
    double nan_im[8];
    memcpy(nan_im, im, sizeof nan_im);
    nan_im[5] = NAN;
    ts_plot_series nanset = {8, re, nan_im, "x", 0, 0, 0, NULL};
    rc = ts_plot_eigenvalues(dir, "eig_nan", "x", 1, &nanset, NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "y[5]"),
          "NaN imaginary part is refused, naming it: %s", err.msg);
    CHECK(nothing_named("eig_bad") && nothing_named("eig_nan"),
          "refused eigenvalue plots left no file");
}

static void test_bode(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    /* Two second-order sections in series, natural frequencies 0.3 and
     * 2 Hz. */
    enum { NF = 300 };
    static double f[NF], mag[NF], ph[NF], mag1[NF], ph1[NF];
    for (int i = 0; i < NF; i++) {
        f[i] = 0.01 * pow(10, 3.0 * i / (NF - 1));
        double w = 2 * M_PI * f[i], w1 = 2 * M_PI * 0.3, w2 = 2 * M_PI * 2;
        double r1 = w1 * w1 - w * w, i1 = 2 * 0.05 * w1 * w;
        double r2 = w2 * w2 - w * w, i2 = 2 * 0.1 * w2 * w;
        mag1[i] = w1 * w1 / hypot(r1, i1);
        mag[i] = mag1[i] * w2 * w2 / hypot(r2, i2);
        ph1[i] = -atan2(i1, r1);
        ph[i] = ph1[i] - atan2(i2, r2);
    }
    double nat[2] = {0.3, 2.0};
    ts_plot_bode_curve c[2] = {{NF, f, mag, ph, "sphere", 0, 0},
                               {NF, f, mag1, ph1, "midpoint", 1, 0}};
    int rc = ts_plot_bode(dir, "bode", "chain: heave response", "heave / "
                          "tow-point heave",
                          TS_PLOT_LENGTH, TS_PLOT_LENGTH, 2, c, 2, nat, &o,
                          &err);
    CHECK(rc == TS_OK, "Bode plot drawn (%s)", err.msg);
    check_png("bode", 1000, 700);
    free(check_svg("bode", "chain: heave response"));
    /* The magnitude in dB; a short span with minor labels; crowded
     * natural frequencies. */
    o.bode_db = 1;
    rc = ts_plot_bode(dir, "bode_db", "chain: heave response, dB", "heave "
                      "/ tow-point heave", TS_PLOT_LENGTH, TS_PLOT_LENGTH, 2,
                      c, 2, nat, &o, &err);
    CHECK(rc == TS_OK, "Bode plot in dB drawn (%s)", err.msg);
    check_png("bode_db", 1000, 700);
    free(check_svg("bode_db", "chain: heave response, dB"));
    o.bode_db = 0;
    double fs[NF], ms[NF], crowd[6] = {0.30, 0.31, 0.32, 0.33, 0.5, 0.9};
    for (int i = 0; i < NF; i++) {
        fs[i] = 0.2 + 0.8 * i / (NF - 1.0);
        ms[i] = 0.04 + 0.21 * i / (NF - 1.0);
    }
    ts_plot_bode_curve cs = {NF, fs, ms, ph, "short", 0, 0};
    rc = ts_plot_bode(dir, "bode_short", "short span", "m", TS_PLOT_LENGTH,
                      TS_PLOT_LENGTH, 1, &cs, 6, crowd, &o, &err);
    CHECK(rc == TS_OK, "Bode plot of 0.04 .. 0.25 with six close natural "
          "frequencies drawn (%s)", err.msg);
    check_png("bode_short", 1000, 700);
    free(check_svg("bode_short", "short span"));

    double fbad[3] = {0.1, 0.2, 0.2}, m3[3] = {1, 1, 1}, p3[3] = {0, 0, 0};
    ts_plot_bode_curve bad = {3, fbad, m3, p3, "x", 0, 0};
    rc = ts_plot_bode(dir, "bode_bad", "x", "x", TS_PLOT_LENGTH,
                      TS_PLOT_LENGTH, 1, &bad, 0, NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "increase"),
          "non-increasing frequencies are refused: %s", err.msg);
    double mzero[3] = {1, 0, 1}, fok[3] = {0.1, 0.2, 0.3};
    ts_plot_bode_curve bad2 = {3, fok, mzero, p3, "x", 0, 0};
    rc = ts_plot_bode(dir, "bode_bad", "x", "x", TS_PLOT_LENGTH,
                      TS_PLOT_LENGTH, 1, &bad2, 0, NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "log axis"),
          "zero magnitude on the log axis is refused: %s", err.msg);
    double natbad[1] = {-1};
    ts_plot_bode_curve ok = {3, fok, m3, p3, "x", 0, 0};
    rc = ts_plot_bode(dir, "bode_bad", "x", "x", TS_PLOT_LENGTH,
                      TS_PLOT_LENGTH, 1, &ok, 1, natbad, &o, &err);
    CHECK(rc == TS_EINVAL, "a negative natural frequency is refused: %s",
          err.msg);
    CHECK(nothing_named("bode_bad"), "refused Bode plots left no file");
}

static void test_histories(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    o.units = TS_PLOT_IMPERIAL;
    ts_err err = {0};
    enum { NS = 400, NS2 = 137 };
    static double t[NS], d1[NS], f1[NS], t2[NS2], d2[NS2], f2[NS2];
    for (int i = 0; i < NS; i++) {
        t[i] = 20.0 * i / (NS - 1);
        d1[i] = 9.144 + 0.15 * sin(1.3 * t[i]) * exp(-0.05 * t[i]);
        f1[i] = 2000 + 100 * sin(1.3 * t[i]);
    }
    /* The nonlinear run on its own (adaptive) time grid. */
    for (int i = 0; i < NS2; i++) {
        t2[i] = 20.0 * pow((double)i / (NS2 - 1), 1.1);
        d2[i] = 9.16 + 0.17 * sin(1.3 * t2[i]) * exp(-0.05 * t2[i]);
        f2[i] = 2010 + 120 * sin(1.3 * t2[i]);
    }
    ts_plot_axis panels[2] = {{"sphere depth", TS_PLOT_LENGTH, NULL},
                              {"top tension", TS_PLOT_FORCE, NULL}};
    ts_plot_series s[4] = {{NS, t, d1, "linear", 0, TS_PLOT_DASHED, 1, NULL},
                           {NS2, t2, d2, "nonlinear", 0, TS_PLOT_SOLID, 2,
                            NULL},
                           {NS, t, f1, "linear", 1, TS_PLOT_DASHED, 1, NULL},
                           {NS2, t2, f2, "nonlinear", 1, TS_PLOT_SOLID, 2,
                            NULL}};
    int rc = ts_plot_histories(dir, "hist", "chain: heave 0.1 ft at 0.25 Hz",
                               2, panels, 4, s, &o, &err);
    CHECK(rc == TS_OK, "time histories drawn (%s)", err.msg);
    check_png("hist", 1000, 700);
    free(check_svg("hist", "chain: heave 0.1 ft at 0.25 Hz"));

    ts_plot_series orphan = {NS, t, d1, "x", 2, 0, 0, NULL};
    rc = ts_plot_histories(dir, "hist_bad", "x", 2, panels, 1, &orphan, &o,
                           &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "panel"),
          "a series in a panel that does not exist is refused: %s", err.msg);
    rc = ts_plot_histories(dir, "hist_bad", "x", 2, panels, 2, s, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "panels[1]"),
          "an empty panel is refused: %s", err.msg);
    ts_plot_series empty = {0, t, d1, "x", 0, 0, 0, NULL};
    rc = ts_plot_histories(dir, "hist_bad", "x", 1, panels, 1, &empty, &o,
                           &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "n: must be >= 1"),
          "a series of n = 0 points is refused: %s", err.msg);
    double inf[3] = {1, INFINITY, 2};
    ts_plot_series infs = {3, t, inf, "x", 0, 0, 0, NULL};
    rc = ts_plot_histories(dir, "hist_bad", "x", 1, panels, 1, &infs, &o,
                           &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "finite"),
          "an infinite value is refused: %s", err.msg);
    CHECK(nothing_named("hist_bad"), "refused histories left no file");
}

/* Tracks in the earth frame: a full steady turn of the ship (radius
 * 100 m about (0, 100) m, starboard) and a quarter of a body's smaller
 * circle, with markers. Checked on the SVG: equal scales (the full
 * circle is round on the page), starboard down the page, one arrowhead
 * per track of several points, and refusals. */
#define TRACK_POINTS 181
static void test_tracks(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    double sx[TRACK_POINTS], sy[TRACK_POINTS], bx[TRACK_POINTS / 4 + 1],
        by[TRACK_POINTS / 4 + 1];
    for (int k = 0; k < TRACK_POINTS; k++) {
        double a = 2 * M_PI * k / (TRACK_POINTS - 1);
        sx[k] = 100 * sin(a);
        sy[k] = 100 - 100 * cos(a);
    }
    for (int k = 0; k <= TRACK_POINTS / 4; k++) {
        double a = 2 * M_PI * k / (TRACK_POINTS - 1);
        bx[k] = -30 + 60 * sin(a);
        by[k] = 100 - 60 * cos(a);
    }
    ts_plot_marker wp[2] = {{0, 0, "start"}, {100, 100, "WP #1"}};
    ts_plot_track t[3] = {
        {TRACK_POINTS, sx, sy, "ship", TS_PLOT_SOLID, 1, 2, wp},
        {TRACK_POINTS / 4 + 1, bx, by, "towfish", TS_PLOT_DASHED, 2, 0, NULL},
        {1, sx, sy, "one point", TS_PLOT_SOLID, 3, 0, NULL}};
    int rc = ts_plot_tracks(dir, "tracks", "a steady turn, earth frame", 3, t,
                            &o, &err);
    CHECK(rc == TS_OK, "tracks drawn (%s)", err.msg);
    check_png("tracks", 1000, 700);
    char *svg = check_svg("tracks", "a steady turn, earth frame");
    free(svg);
    /* The geometry, on a picture without a legend (its line samples are
     * strokes of the same colours) and without markers. */
    ts_plot_track g[2] = {t[0], t[1]};
    g[0].label = g[1].label = NULL;
    g[0].nmarkers = 0;
    rc = ts_plot_tracks(dir, "tracks_plain", "two tracks", 2, g, &o, &err);
    CHECK(rc == TS_OK, "tracks without a legend drawn (%s)", err.msg);
    svg = check_svg("tracks_plain", "two tracks");
    /* The ship's track in palette colour 1 (0 114 178), its arrowhead a
     * fill of that colour; the towfish's in colour 2 (213 94 0). */
    static const char stroke1[] = "fill:none;stroke-width:2.2;stroke-linecap:"
                                  "butt;stroke-linejoin:bevel;stroke:rgb("
                                  "0%,44.705882%,69.803922%)";
    static const char fill1[] = "fill-rule:nonzero;fill:rgb(0%,44.705882%,"
                                "69.803922%)";
    static const char fill2[] = "fill:rgb(83.529412%,36.862745%,0%)";
    bbox circle, head1, head2;
    int nc = svg ? svg_bbox(svg, stroke1, &circle) : 0;
    int nh1 = svg ? svg_bbox(svg, fill1, &head1) : 0;
    int nh2 = svg ? svg_bbox(svg, fill2, &head2) : 0;
    CHECK(nc >= 1, "the ship's track is drawn (%d paths)", nc);
    CHECK_NEAR((circle.y1 - circle.y0) / (circle.x1 - circle.x0), 1.0, 0.01,
               "equal scales: the full turn is round on the page");
    CHECK(nh1 == 1 && nh2 == 1, "one arrowhead on each track of several "
          "points (%d, %d)", nh1, nh2);
    /* The ship's arrowhead is at the start (the turn is closed), the
     * circle's top point; the centre is below it: starboard is down. */
    CHECK(fabs(0.5 * (head1.y0 + head1.y1) - circle.y0) < 10 &&
              circle.y1 > circle.y0 + 100,
          "starboard is down the page (arrow at %.1f pt, circle %.1f..%.1f)",
          0.5 * (head1.y0 + head1.y1), circle.y0, circle.y1);
    /* The towfish's quarter turn ends heading +y (down the page). */
    CHECK(nh2 == 1 && head2.y1 - head2.y0 > head2.x1 - head2.x0,
          "the towfish's arrowhead points along its last segment (%.1f x "
          "%.1f pt)", head2.x1 - head2.x0, head2.y1 - head2.y0);
    free(svg);
    o.units = TS_PLOT_IMPERIAL;
    rc = ts_plot_tracks(dir, "tracks_ft", "in feet", 2, t, &o, &err);
    CHECK(rc == TS_OK, "tracks in feet drawn (%s)", err.msg);
    free(check_svg("tracks_ft", "in feet"));
    ts_plot_opts_default(&o);

    double bad[2] = {0, NAN};
    ts_plot_track tb = {2, sx, bad, "x", 0, 0, 0, NULL};
    rc = ts_plot_tracks(dir, "tracks_bad", "x", 1, &tb, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "y[1]"),
          "a NaN point is refused: %s", err.msg);
    tb = (ts_plot_track){2, sx, sy, "x", 0, 0, 2, NULL};
    rc = ts_plot_tracks(dir, "tracks_bad", "x", 1, &tb, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tracks[0].markers"),
          "markers NULL with a count is refused: %s", err.msg);
    ts_plot_marker inf = {INFINITY, 0, "far"};
    tb = (ts_plot_track){2, sx, sy, "x", 0, 0, 1, &inf};
    rc = ts_plot_tracks(dir, "tracks_bad", "x", 1, &tb, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "markers[0]"),
          "an infinite marker is refused: %s", err.msg);
    tb = (ts_plot_track){0, sx, sy, "x", 0, 0, 0, NULL};
    rc = ts_plot_tracks(dir, "tracks_bad", "x", 1, &tb, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "tracks[0].n"),
          "an empty track is refused: %s", err.msg);
    rc = ts_plot_tracks(dir, "tracks_bad", "x", 0, t, &o, &err);
    CHECK(rc == TS_EINVAL, "no track is refused: %s", err.msg);
    CHECK(nothing_named("tracks_bad"), "refused tracks left no file");
}

static void test_loglog(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    double rt[6], e1[6], rt2[6], e2[6];
    for (int i = 0; i < 6; i++) {
        rt[i] = 0.001 * pow(2, i);
        rt2[i] = 0.003 * pow(2, i);
        e1[i] = 1e-3 * pow(2, -2.0 * i);
        e2[i] = 1e-2 * pow(2, -4.0 * i);
    }
    ts_plot_axis xa = {"run time", TS_PLOT_TIME, NULL},
                 ya = {"error in sphere depth", TS_PLOT_LENGTH, NULL};
    ts_plot_series s[2] = {
        {6, rt, e1, "RK45", 0, TS_PLOT_LINE_MARKERS, 0, NULL},
        {6, rt2, e2, "BDF", 0, TS_PLOT_LINE_MARKERS, 0, NULL}};
    int rc = ts_plot_loglog(dir, "loglog", "chain: error against run time",
                            &xa, &ya, 2, s, &o, &err);
    CHECK(rc == TS_OK, "log-log plot drawn (%s)", err.msg);
    check_png("loglog", 1000, 700);
    char *plain = check_svg("loglog", "chain: error against run time");
    /* Each point labelled: the picture has more glyphs drawn. */
    static const char *const pts[6] = {"5", "10", "20", "40", "80", "160"};
    ts_plot_series sl[2] = {s[0], s[1]};
    sl[0].point_labels = pts;
    rc = ts_plot_loglog(dir, "loglog_labels", "chain: labelled", &xa, &ya,
                        2, sl, &o, &err);
    CHECK(rc == TS_OK, "log-log plot with point labels drawn (%s)", err.msg);
    char *lab = check_svg("loglog_labels", "chain: labelled");
    /* cairo writes each text as a group filled in its colour: the six
     * labels of the first series are six more groups in its colour
     * (palette colour 1, rgb 0 114 178). */
    static const char g1[] = "<g style=\"fill:rgb(0%,44.705882%,69.803922%)";
    int gp = plain ? count_of(plain, g1) : 0, gl = lab ? count_of(lab, g1)
                                                       : 0;
    CHECK(plain && lab && gl == gp + 6, "six point labels drawn in the "
          "series' colour (%d text groups, %d without)", gl, gp);
    free(plain);
    free(lab);
    /* A short span on both axes (0.04 .. 0.25 and 0.3 .. 0.9): minor
     * labels (2 and 5 times a power of ten) beside the decades' own, as
     * on a Bode plot: more text drawn than the decades alone give. The
     * same data times 10^k (k of 6 decades) have no minor labels. */
    double sx[2] = {0.04, 0.25}, sy[2] = {0.3, 0.9};
    double wx[2] = {1e-4, 1e2}, wy[2] = {1e-3, 1e3};
    ts_plot_series ss = {2, sx, sy, "short", 0, TS_PLOT_LINE_MARKERS, 0, NULL};
    ts_plot_series ws = {2, wx, wy, "short", 0, TS_PLOT_LINE_MARKERS, 0, NULL};
    rc = ts_plot_loglog(dir, "loglog_short", "short spans", &xa, &ya, 1, &ss,
                        &o, &err);
    CHECK(rc == TS_OK, "log-log plot of short spans drawn (%s)", err.msg);
    char *sh = check_svg("loglog_short", "short spans");
    rc = ts_plot_loglog(dir, "loglog_wide", "short spans", &xa, &ya, 1, &ws,
                        &o, &err);
    char *wd = check_svg("loglog_wide", "short spans");
    /* Black text groups: the title, the two axis titles and the legend
     * (4), the decade labels (10^k: `per` groups each, base and
     * exponent; 14 on the wide picture, 3 on the short one: 10^-1 on x,
     * 10^-1 and 10^0 on y) and, on the short one only, the minor labels
     * 0.05, 0.2 (x) and 0.2, 0.5 (y). */
    static const char black[] = "<g style=\"fill:rgb(0%,0%,0%)";
    int ns = sh ? count_of(sh, black) : 0, nw = wd ? count_of(wd, black) : 0;
    int per = (nw - 4) / 14;
    CHECK(sh && wd && per >= 1 && nw - 4 == 14 * per &&
              ns - 4 - 3 * per == 4,
          "short spans: four minor labels (%d text groups; %d on the wide "
          "picture of 14 decade labels)", ns, nw);
    free(sh);
    free(wd);
    /* A title with XML specials and PLplot's escape character '#'. */
    rc = ts_plot_loglog(dir, "loglog_xml", "run #2: error & time <s>", &xa,
                        &ya, 2, s, &o, &err);
    CHECK(rc == TS_OK, "a title with '#', '&', '<' is drawn (%s)", err.msg);
    free(check_svg("loglog_xml", "run #2: error &amp; time &lt;s&gt;"));
    /* A bigger picture. */
    o.width = 1600;
    o.height = 1000;
    o.formats = TS_PLOT_PNG;
    rc = ts_plot_loglog(dir, "loglog_big", "big", &xa, &ya, 2, s, &o, &err);
    CHECK(rc == TS_OK, "1600 x 1000 PNG only (%s)", err.msg);
    check_png("loglog_big", 1600, 1000);
    CHECK(!file_exists("loglog_big", "svg"), "no SVG when only PNG is asked");

    double ezero[6] = {1e-3, 1e-4, 0, 1e-6, 1e-7, 1e-8};
    ts_plot_series z = {6, rt, ezero, "x", 0, 0, 0, NULL};
    ts_plot_opts_default(&o);
    rc = ts_plot_loglog(dir, "loglog_bad", "x", &xa, &ya, 1, &z, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "y[2]") &&
              strstr(err.msg, "log axis"),
          "an error of 0 on a log axis is refused: %s", err.msg);
    o.width = 640;
    rc = ts_plot_loglog(dir, "loglog_bad", "x", &xa, &ya, 2, s, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "size"),
          "a 640 px wide picture is refused: %s", err.msg);
    CHECK(nothing_named("loglog_bad"), "refused log-log plots left no file");
}

/* A map over two parameters (an operating envelope) and curves against a
 * parameter (ts_plot_panels). */
static void test_map(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    enum { NX = 6, NY = 4 };
    double x[NX], y[NY], z[NX * NY], bx[2] = {2.45, 2.6}, by[2] = {0, 0.3};
    int marks[NX * NY] = {0};
    for (int i = 0; i < NX; i++)
        x[i] = 1.0 + 0.3 * i;
    for (int j = 0; j < NY; j++)
        y[j] = 0.1 * j * j;
    for (int i = 0; i < NX; i++)
        for (int j = 0; j < NY; j++) {
            z[i * NY + j] = (x[i] - 2.4) * (1 + y[j]);
            marks[i * NY + j] = z[i * NY + j] > 0 ? TS_PLOT_MARK_UNSTABLE : 0;
        }
    z[2 * NY + 1] = NAN;
    marks[2 * NY + 1] = TS_PLOT_MARK_FAILED;
    marks[0] |= TS_PLOT_MARK_UNTRUSTED;
    ts_plot_axis xa = {"tow speed", TS_PLOT_SPEED, NULL};
    ts_plot_axis ya = {"cable mass", TS_PLOT_NONE, "kg/m"};
    ts_plot_axis za = {"max Re(λ)", TS_PLOT_RATE, NULL};
    ts_plot_grid g = {NX, NY, x, y, z};
    int rc = ts_plot_map(dir, "map", "envelope #1 & <margin>", &xa, &ya, &za,
                         &g, marks, 2, bx, by, &o, &err);
    CHECK(rc == TS_OK, "map with marks, a failed point and a boundary (%s)",
          err.msg);
    check_png("map", 1000, 700);
    free(check_svg("map", "envelope #1 &amp; &lt;margin&gt;"));
    o.units = TS_PLOT_IMPERIAL;
    rc = ts_plot_map(dir, "map_imperial", "imperial", &xa, &ya, &za, &g, NULL,
                     0, NULL, NULL, &o, &err);
    CHECK(rc == TS_OK, "map in imperial units, no marks (%s)", err.msg);
    ts_plot_opts_default(&o);
    /* Refusals. */
    double xbad[NX] = {1, 2, 2, 3, 4, 5}, znan[NX * NY];
    for (int k = 0; k < NX * NY; k++)
        znan[k] = NAN;
    ts_plot_grid gx = {NX, NY, xbad, y, z}, gz = {NX, NY, x, y, znan};
    ts_plot_grid g1 = {1, NY, x, y, z};
    rc = ts_plot_map(dir, "map_bad", "x", &xa, &ya, &za, &gx, NULL, 0, NULL,
                     NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "grid.x"),
          "x not increasing refused: %s", err.msg);
    rc = ts_plot_map(dir, "map_bad", "x", &xa, &ya, &za, &gz, NULL, 0, NULL,
                     NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "no finite value"),
          "no value at all refused: %s", err.msg);
    rc = ts_plot_map(dir, "map_bad", "x", &xa, &ya, &za, &g1, NULL, 0, NULL,
                     NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "2 x 2"),
          "a grid of one column refused: %s", err.msg);
    rc = ts_plot_map(dir, "map_bad", "x", &xa, &ya, &za, &g, NULL, 1, NULL,
                     NULL, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "boundary"),
          "boundary points without arrays refused: %s", err.msg);
    CHECK(nothing_named("map_bad"), "refused maps left no file");

    /* Curves against a parameter. */
    double d[NX], t[NX];
    for (int i = 0; i < NX; i++) {
        d[i] = 10.0 / x[i];
        t[i] = 400 + 50 * x[i] * x[i];
    }
    ts_plot_axis panels[2] = {{"sphere depth", TS_PLOT_LENGTH, NULL},
                              {"top tension", TS_PLOT_FORCE, NULL}};
    ts_plot_series s[3] = {
        {NX, x, d, NULL, 0, TS_PLOT_LINE_MARKERS, 1, NULL},
        {NX, x, t, NULL, 1, TS_PLOT_LINE_MARKERS, 1, NULL},
        {2, x + 4, t + 4, "unstable", 1, TS_PLOT_MARKERS, 2, NULL}};
    rc = ts_plot_panels(dir, "panels", "depth and tension over speed", &xa, 2,
                        panels, 3, s, &o, &err);
    CHECK(rc == TS_OK, "panels against the tow speed (%s)", err.msg);
    check_png("panels", 1000, 700);
    rc = ts_plot_panels(dir, "panels_bad", "x", NULL, 2, panels, 3, s, &o,
                        &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "xaxis"),
          "panels without an x axis refused: %s", err.msg);
}

/* Bad names, directories and shapes. */
static void test_bad_places(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    ts_plot_shape one = {N, chain, NULL, 1, end_mark, 0, NULL, 0, 0, 0, NULL, 0, NULL};
    static const char *const names[] = {"", ".hidden", "a/b", "x y", NULL};
    for (int i = 0; names[i]; i++) {
        ts_err_clear(&err);
        int rc = ts_plot_shapes(dir, names[i], "t", TS_PLOT_SIDE, 0, 1, &one,
                                &o, &err);
        CHECK(rc == TS_EINVAL && strstr(err.msg, "name"),
              "name '%s' is refused: %s", names[i], err.msg);
    }
    int rc = ts_plot_shapes(dir, "t_null", NULL, TS_PLOT_SIDE, 0, 1, &one, &o,
                            &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "title"),
          "a NULL title is refused: %s", err.msg);

    /* A file where the directory should be. */
    char file[700], sub[760];
    snprintf(file, sizeof file, "%s/plain_file", dir);
    FILE *f = fopen(file, "w");
    if (f) {
        fputs("not a directory\n", f);
        fclose(f);
    }
    rc = ts_plot_shapes(file, "side", "t", TS_PLOT_SIDE, 0, 1, &one, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "not a directory"),
          "a file as the directory is refused: %s", err.msg);
    snprintf(sub, sizeof sub, "%s/deeper", file);
    rc = ts_plot_shapes(sub, "side", "t", TS_PLOT_SIDE, 0, 1, &one, &o, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "not a directory"),
          "a directory under a file is refused: %s", err.msg);

    /* Missing directories are created, parents included. */
    snprintf(sub, sizeof sub, "%s/new/nested", dir);
    rc = ts_plot_shapes(sub, "side", "created", TS_PLOT_SIDE, 0, 1, &one, &o,
                        &err);
    struct stat st;
    char made[800];
    snprintf(made, sizeof made, "%s/side.png", sub);
    CHECK(rc == TS_OK && stat(made, &st) == 0 && st.st_size > MIN_BYTES,
          "a missing nested directory is created and used (%s)", err.msg);

    /* A directory that cannot be created: /proc does not take new
     * directories, even from root. */
    rc = ts_plot_shapes("/proc/towstab-plot-test", "side", "t", TS_PLOT_SIDE,
                        0, 1, &one, &o, &err);
    CHECK(rc == TS_EIO, "an uncreatable directory gives TS_EIO: %s", err.msg);
    /* A read-only directory (root may write anywhere: then skipped). */
    char ro[700];
    snprintf(ro, sizeof ro, "%s/readonly", dir);
    mkdir(ro, 0555);
    chmod(ro, 0555);
    if (geteuid() != 0) {
        rc = ts_plot_shapes(ro, "side", "t", TS_PLOT_SIDE, 0, 1, &one, &o,
                            &err);
        CHECK(rc == TS_EIO && strstr(err.msg, "not writable"),
              "a read-only directory gives TS_EIO: %s", err.msg);
    } else {
        printf("note: running as root, read-only directory check skipped\n");
    }
    chmod(ro, 0755);

    /* Shapes that are not trees, bad marks, bad views. */
    static const int up_bad[N - 1] = {0, 1, 5};
    ts_plot_shape s = one;
    s.link_upper = up_bad;
    rc = ts_plot_shapes(dir, "bad_shape", "t", TS_PLOT_SIDE, 0, 1, &s, &o,
                        &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "link_upper[2]"),
          "a link from a node below is refused: %s", err.msg);
    static const int mark_bad[1] = {N};
    s = one;
    s.marks = mark_bad;
    rc = ts_plot_shapes(dir, "bad_shape", "t", TS_PLOT_SIDE, 0, 1, &s, &o,
                        &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "marks[0]"),
          "a mark outside the nodes is refused: %s", err.msg);
    s = one;
    s.nnodes = 1;
    rc = ts_plot_shapes(dir, "bad_shape", "t", TS_PLOT_SIDE, 0, 1, &s, &o,
                        &err);
    CHECK(rc == TS_EINVAL, "a shape of one node is refused: %s", err.msg);
    double nanpos[3 * N];
    memcpy(nanpos, chain, sizeof nanpos);
    nanpos[3 * 7 + 2] = NAN;
    s = one;
    s.pos = nanpos;
    rc = ts_plot_shapes(dir, "bad_shape", "t", TS_PLOT_SIDE, 0, 1, &s, &o,
                        &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "pos[23]"),
          "a NaN depth is refused, naming pos[23]: %s", err.msg);
    rc = ts_plot_shapes(dir, "bad_shape", "t", (ts_plot_view)7, 0, 1, &one,
                        &o, &err);
    CHECK(rc == TS_EINVAL, "an unknown view is refused: %s", err.msg);
    rc = ts_plot_shapes(dir, "bad_shape", "t", TS_PLOT_SIDE, 0, 0, &one, &o,
                        &err);
    CHECK(rc == TS_EINVAL, "no shapes is refused: %s", err.msg);
    CHECK(nothing_named("bad_shape") && nothing_named("t_null"),
          "refused shapes left no file");
}

/* The caller's PLplot stream is current again after a call. */
static void test_streams(void)
{
    PLINT mine, cur;
    plmkstrm(&mine);
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    o.formats = TS_PLOT_PNG;
    ts_plot_shape one = {N, chain, NULL, 1, end_mark, 0, NULL, 0, 0, 0, NULL, 0, NULL};
    ts_err err = {0};
    int rc = ts_plot_shapes(dir, "stream", "t", TS_PLOT_TOP, 0, 1, &one, &o,
                            &err);
    plgstrm(&cur);
    CHECK(rc == TS_OK && cur == mine,
          "the caller's stream %d is current after a plot (%d)", (int)mine,
          (int)cur);
    rc = ts_plot_shapes(dir, "stream", "t", TS_PLOT_TOP, 0, 0, &one, &o,
                        &err);
    plgstrm(&cur);
    CHECK(rc == TS_EINVAL && cur == mine,
          "and after a refused call (%d)", (int)cur);
    plend1();
}

#else /* no PLplot */

static void test_without_plplot(void)
{
    ts_plot_opts o;
    ts_plot_opts_default(&o);
    ts_err err = {0};
    CHECK(ts_plot_check(&err) == TS_EDOMAIN &&
              strstr(err.msg, "built without PLplot") &&
              strstr(err.msg, "libplplot-dev") &&
              strstr(err.msg, "plplot-driver-cairo"),
          "ts_plot_check names the missing packages: %s", err.msg);
    ts_plot_shape one = {N, chain, NULL, 1, end_mark, 0, NULL, 0, 0, 0, NULL, 0, NULL};
    ts_plot_mode mode = {chain, "m", NULL};
    double x[2] = {1, 2}, y[2] = {1, 2}, ph[2] = {0, 0}, nat[1] = {1};
    ts_plot_series s = {2, x, y, "s", 0, 0, 0, NULL};
    ts_plot_bode_curve b = {2, x, y, ph, "b", 0, 0};
    ts_plot_axis a = {"a", TS_PLOT_NONE, NULL};
    double gz[4] = {1, 2, 3, 4};
    ts_plot_grid g = {2, 2, x, y, gz};
    ts_plot_track tr = {2, x, y, "t", 0, 0, 0, NULL};
    double zr[3 * N] = {0};
    int rc[10];
    rc[8] = ts_plot_tracks(dir, "n8", "t", 1, &tr, &o, &err);
    rc[9] = ts_plot_mode_frames(dir, "n9", "t", TS_PLOT_SIDE, 0, &one, chain,
                                zr, NULL, NULL, NULL, 4, &o, &err);
    rc[0] = ts_plot_shapes(dir, "n0", "t", TS_PLOT_SIDE, 0, 1, &one, &o, &err);
    rc[1] = ts_plot_mode_shapes(dir, "n1", "t", 0, &one, 1, &mode, &o, &err);
    rc[2] = ts_plot_eigenvalues(dir, "n2", "t", 1, &s, NULL, &o, &err);
    rc[3] = ts_plot_bode(dir, "n3", "t", "m", TS_PLOT_LENGTH, TS_PLOT_LENGTH,
                         1, &b, 1, nat, &o, &err);
    rc[4] = ts_plot_histories(dir, "n4", "t", 1, &a, 1, &s, &o, &err);
    rc[5] = ts_plot_loglog(dir, "n5", "t", &a, &a, 1, &s, &o, &err);
    rc[6] = ts_plot_panels(dir, "n6", "t", &a, 1, &a, 1, &s, &o, &err);
    rc[7] = ts_plot_map(dir, "n7", "t", &a, &a, &a, &g, NULL, 0, NULL, NULL,
                        &o, &err);
    for (int i = 0; i < 10; i++)
        CHECK(rc[i] == TS_EDOMAIN, "drawing function %d returns TS_EDOMAIN",
              i);
    CHECK(nothing_named("n"), "nothing was written");
}

#endif

/* The outline motion needs no PLplot (lib/plot_geom.c). */

/* ts_plot_outline_moved: the rigid motion of an outline in a mode,
 * against a rotation matrix written out independently and its
 * invariants. */
static void test_outline_moved(void)
{
    /* A triangle off its anchor, rotated about y (pitch) by s * 0.35 rad,
     * translated by s t, magnified 2.5 times; s = -1.7. */
    double pts[12] = {1.0, 0.5, 2.0, 1.4, 0.5, 2.0, 1.0, 0.9, 2.3,
                      NAN, NAN, NAN};
    ts_plot_outline o = {4, pts, {1.2, 0.3, 1.9}};
    double motion[6] = {0.05, -0.02, 0.11, 0, 0.35, 0};
    double s = -1.7, mag = 2.5, out[12];
    ts_plot_outline_moved(&o, motion, s, mag, out);
    double a = s * motion[4], c = cos(a), sn = sin(a), worst = 0;
    for (int k = 0; k < 3; k++) {
        double v[3], q[3];
        for (int j = 0; j < 3; j++)
            v[j] = mag * (pts[3 * k + j] - o.anchor[j]);
        /* R_y(a): x' = c x + s z, z' = -s x + c z. */
        q[0] = o.anchor[0] + s * motion[0] + c * v[0] + sn * v[2];
        q[1] = o.anchor[1] + s * motion[1] + v[1];
        q[2] = o.anchor[2] + s * motion[2] - sn * v[0] + c * v[2];
        for (int j = 0; j < 3; j++)
            worst = fmax(worst, fabs(out[3 * k + j] - q[j]));
    }
    CHECK(worst < 1e-15, "outline moved: a pitch of %.3f rad and a "
          "translation match the rotation matrix R_y to %.2g m", a, worst);
    CHECK(isnan(out[9]) && isnan(out[10]) && isnan(out[11]),
          "outline moved: a pen lift stays a pen lift");
    /* A general rotation: rigid (distances times mag), and the rotation
     * axis through the anchor fixed (but for the translation). */
    double axis[6] = {0, 0, 0, 0.2, -0.4, 0.7}, ax[3] = {0.2, -0.4, 0.7};
    double pa[6] = {o.anchor[0] + 0.1 * ax[0], o.anchor[1] + 0.1 * ax[1],
                    o.anchor[2] + 0.1 * ax[2], 0.3, -1.1, 2.9};
    ts_plot_outline oa = {2, pa, {o.anchor[0], o.anchor[1], o.anchor[2]}};
    double qa[6];
    ts_plot_outline_moved(&oa, axis, 1.3, 1.0, qa);
    double da = 0, d0 = 0, d1 = 0;
    for (int j = 0; j < 3; j++) {
        da = fmax(da, fabs(qa[j] - pa[j]));
        d0 += (pa[3 + j] - o.anchor[j]) * (pa[3 + j] - o.anchor[j]);
        d1 += (qa[3 + j] - o.anchor[j]) * (qa[3 + j] - o.anchor[j]);
    }
    double moved = 0;
    for (int j = 0; j < 3; j++)
        moved = fmax(moved, fabs(qa[3 + j] - pa[3 + j]));
    CHECK(da < 1e-15 && fabs(sqrt(d1) - sqrt(d0)) < 1e-14 && moved > 0.1,
          "outline moved: a point on the rotation axis stays (%.2g m), "
          "another keeps its distance from the anchor (%.2g m) and moves "
          "(%.3f m)", da, fabs(sqrt(d1) - sqrt(d0)), moved);
    double same[6];
    ts_plot_outline_moved(&oa, NULL, 1.3, 1.0, same);
    double dsame = 0;
    for (int j = 0; j < 6; j++)
        dsame = fmax(dsame, fabs(same[j] - pa[j]));
    CHECK(dsame < 1e-15, "outline moved: no motion, no magnification: the "
          "points themselves (to %.2g m, the rounding of A + (p - A))",
          dsame);
}

/* ts_plot_outline_at_phase: the motion Re((re + i im) e^{i phase}). At
 * phase 0 the real part's; at pi / 2 minus the imaginary part's, a yaw
 * written out as R_z; at pi minus the real part's. */
static void test_outline_at_phase(void)
{
    double pts[9] = {1.0, 0.5, 2.0, 1.4, 0.5, 2.0, 1.0, 0.9, 2.3};
    ts_plot_outline o = {3, pts, {1.2, 0.3, 1.9}};
    double mre[6] = {0.05, -0.02, 0.11, 0, 0.35, 0};
    double mim[6] = {0.01, 0.03, -0.04, 0, 0, 0.25};
    double s = 1.3, mag = 2.0, out[9], ref[9], neg[6];
    ts_plot_outline_at_phase(&o, mre, mim, 0.0, s, mag, out);
    ts_plot_outline_moved(&o, mre, s, mag, ref);
    double d0 = 0;
    for (int j = 0; j < 9; j++)
        d0 = fmax(d0, fabs(out[j] - ref[j]));
    ts_plot_outline_at_phase(&o, mre, mim, M_PI, s, mag, out);
    for (int j = 0; j < 6; j++)
        neg[j] = -mre[j];
    ts_plot_outline_moved(&o, neg, s, mag, ref);
    double dpi = 0;
    for (int j = 0; j < 9; j++)
        dpi = fmax(dpi, fabs(out[j] - ref[j]));
    ts_plot_outline_at_phase(&o, mre, mim, M_PI / 2, s, mag, out);
    double a = -s * mim[5], c = cos(a), sn = sin(a), d90 = 0;
    for (int k = 0; k < 3; k++) {
        double v[3], q[3];
        for (int j = 0; j < 3; j++)
            v[j] = mag * (pts[3 * k + j] - o.anchor[j]);
        /* R_z(a): x' = c x - s y, y' = s x + c y. */
        q[0] = o.anchor[0] - s * mim[0] + c * v[0] - sn * v[1];
        q[1] = o.anchor[1] - s * mim[1] + sn * v[0] + c * v[1];
        q[2] = o.anchor[2] - s * mim[2] + v[2];
        for (int j = 0; j < 3; j++)
            d90 = fmax(d90, fabs(out[3 * k + j] - q[j]));
    }
    /* cos(pi / 2) is 6e-17, not 0: the real part leaks in at that level. */
    CHECK(d0 < 1e-15 && dpi < 1e-14 && d90 < 1e-14,
          "outline at phase: 0 the real part's motion (%.2g m), pi its "
          "opposite (%.2g m), pi/2 a yaw of %.3f rad by R_z (%.2g m)", d0,
          dpi, a, d90);
}

/* Conversions and unit names (no PLplot needed), against udunits2. */
/* The label placement: minor labels of short log axes (2 and 5 times
 * each power of ten inside, none on a wider axis) and rows of labels
 * that do not overlap. */
static void test_labels(void)
{
    double v[16];
    int n = tsi_plot_minor_ticks(-2, 0, v, 16);
    CHECK(n == 4 && v[0] == 0.02 && v[1] == 0.05 && fabs(v[2] - 0.2) < 1e-15 &&
              fabs(v[3] - 0.5) < 1e-15,
          "10^-2 .. 10^0: minor labels 0.02, 0.05, 0.2, 0.5 (%d)", n);
    /* The span 0.04 .. 0.25 (padded: 0.035 .. 0.3). */
    n = tsi_plot_minor_ticks(log10(0.035), log10(0.3), v, 16);
    CHECK(n == 2 && fabs(v[0] - 0.05) < 1e-15 && fabs(v[1] - 0.2) < 1e-15,
          "0.035 .. 0.3: 0.05 and 0.2 (%d)", n);
    CHECK(tsi_plot_minor_ticks(-3, 0, v, 16) == 0,
          "three decades: no minor labels");
    CHECK(tsi_plot_minor_ticks(0, 1, v, 1) == 1, "at most max labels");
    /* Rows: 0, 0.01, 0.02 crowd, 0.5 is free; given out of order. */
    double x[4] = {0.5, 0.02, 0.0, 0.01};
    int row[4];
    tsi_plot_label_rows(4, x, 0.05, 2, row);
    CHECK(row[2] == 0 && row[3] == 1 && row[1] == -1 && row[0] == 0,
          "label rows: 0 -> 0, 0.01 -> 1, 0.02 left out, 0.5 -> 0 (%d %d "
          "%d %d)", row[2], row[3], row[1], row[0]);
    tsi_plot_label_rows(4, x, 0.009, 2, row);
    CHECK(row[2] == 0 && row[3] == 0 && row[1] == 0 && row[0] == 0,
          "labels 0.01 apart, 0.009 wide: one row");
}

static void test_units(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    CHECK(u != NULL, "udunits loaded (%s)", err.msg);
    if (!u)
        return;
    struct {
        ts_plot_quantity q;
        const char *si, *imp;
    } cases[] = {{TS_PLOT_LENGTH, "m", "ft"},
                 {TS_PLOT_FORCE, "N", "lbf"},
                 {TS_PLOT_SPEED, "m/s", "knot"},
                 {TS_PLOT_MASS, "kg", "lb"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double want = 0;
        int rc = ts_units_from_si(u, 2.385, cases[i].si, cases[i].imp, &want,
                                  &err);
        CHECK(rc == TS_OK, "udunits converts %s to %s", cases[i].si,
              cases[i].imp);
        CHECK_REL(ts_plot_convert(cases[i].q, TS_PLOT_IMPERIAL, 2.385), want,
                  1e-12, cases[i].imp);
        CHECK(ts_plot_convert(cases[i].q, TS_PLOT_SI, 2.385) == 2.385,
              "SI keeps %s", cases[i].si);
        CHECK(strcmp(ts_plot_unit(cases[i].q, TS_PLOT_SI), cases[i].si) == 0 &&
                  strcmp(ts_plot_unit(cases[i].q, TS_PLOT_IMPERIAL),
                         cases[i].imp) == 0,
              "unit names %s and %s", cases[i].si, cases[i].imp);
    }
    double deg = 0;
    ts_units_from_si(u, 0.4321, "rad", "degree", &deg, &err);
    CHECK_REL(ts_plot_convert(TS_PLOT_ANGLE, TS_PLOT_IMPERIAL, 0.4321), deg,
              1e-12, "rad to deg (imperial)");
    CHECK_REL(ts_plot_convert(TS_PLOT_ANGLE, TS_PLOT_SI, 0.4321), deg, 1e-12,
              "rad to deg (SI)");
    CHECK(ts_plot_convert(TS_PLOT_TIME, TS_PLOT_IMPERIAL, 2.385) == 2.385 &&
              ts_plot_convert(TS_PLOT_FREQUENCY, TS_PLOT_IMPERIAL, 2.385) ==
                  2.385,
          "seconds and hertz in both systems");
    CHECK(strcmp(ts_plot_unit(TS_PLOT_NONE, TS_PLOT_SI), "-") == 0 &&
              strcmp(ts_plot_unit(TS_PLOT_RATE, TS_PLOT_IMPERIAL), "1/s") ==
                  0,
          "dimensionless '-', rates 1/s");
    ts_units_free(u);

    /* ts_plot_prepare_dir works without PLplot. */
    char sub[700];
    snprintf(sub, sizeof sub, "%s/prepared/a/b", dir);
    struct stat st;
    CHECK(ts_plot_prepare_dir(sub, &err) == TS_OK && stat(sub, &st) == 0 &&
              S_ISDIR(st.st_mode),
          "ts_plot_prepare_dir creates %s", sub);
    CHECK(ts_plot_prepare_dir("", &err) == TS_EINVAL,
          "an empty directory name is refused: %s", err.msg);
}

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (!d) {
        unlink(path);
        return;
    }
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char p[1024];
        snprintf(p, sizeof p, "%s/%s", path, e->d_name);
        remove_tree(p);
    }
    closedir(d);
    rmdir(path);
}

int main(int argc, char **argv)
{
    int keep = argc > 1;
    if (keep) {
        snprintf(dir, sizeof dir, "%s", argv[1]);
        mkdir(dir, 0777);
    } else {
        const char *tmp = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/towstab-plot-XXXXXX",
                 tmp && tmp[0] ? tmp : "/tmp");
        if (!mkdtemp(dir)) {
            printf("FAIL cannot make a temporary directory (%s)\n",
                   strerror(errno));
            return 1;
        }
    }
    make_data();
    test_units();
    test_labels();
    test_outline_moved();
    test_outline_at_phase();
#ifdef TS_HAVE_PLPLOT
    ts_err err = {0};
    CHECK(ts_plot_check(&err) == TS_OK,
          "PLplot with its cairo devices is available (%s)", err.msg);
    test_shapes();
    test_cylinder();
    test_animation();
    test_animation_vehicle();
    test_modes();
    test_eigenvalues();
    test_bode();
    test_histories();
    test_loglog();
    test_tracks();
    test_map();
    test_bad_places();
    test_streams();
#else
    test_without_plplot();
#endif
    if (!keep)
        remove_tree(dir);
    return tc_done();
}
