/* plot_draw.c: pictures of results with PLplot's cairo devices
 * (towstab/plot.h, doc/plots.md), built as a module of its own,
 * towstab-plot.so, that the library (lib/plot.c) opens only when a picture
 * is asked for: a run that draws nothing does not load PLplot and its
 * libraries (doc/performance.md, "Start-up"). The
 * module exports one table (plot_module.h); each entry is the public
 * function of the same name less its prefix.
 *
 * Algorithm, per call:
 *  1. Validate every argument (sizes, finite data, positive values on log
 *     axes, the file name) before anything is drawn or written, and make
 *     sure the output directory exists.
 *  2. For each requested format, make a private PLplot stream (plmkstrm),
 *     point it at an in-memory FILE (open_memstream + plsfile, so PLplot
 *     never opens a file by name: its plOpenFile would prompt on stdin and
 *     finally end the process if a name could not be opened), select pngcairo or
 *     svgcairo, set the page size in px (PNG) or pt (SVG), the palette and
 *     a white background, draw, and end the stream with plend1, which
 *     closes the FILE (cairo's tidy calls plCloseFile). The previously
 *     current stream is made current again.
 *  3. Write the bytes under a temporary name and rename (tsi_outfile,
 *     lib/outfile.h), so no half-written picture is left behind. The
 *     SVG gets a <title> element right after its root tag.
 *
 * Drawing: every number is converted to the requested unit system first
 * (ts_plot_convert); axes carry "name [unit]". The side view flips the
 * vertical axis so that depth grows downward (plwind with bottom > top),
 * the top view flips it so that starboard is down the page (x forward to
 * the right, z into the page: a right-handed view from above). Equal
 * scales are made by widening the shorter data range to the viewport's
 * physical aspect ratio (plgspa, plgvpd), so the plot box keeps its size.
 * Legends go to the corner of the plot box that covers the fewest drawn
 * points (points, markers weighted more, and samples along drawn segments
 * and labels are counted per corner as they are drawn); time histories
 * first raise the top of each panel's window to leave the legend's corner
 * empty; cable shapes, which leave no corner reliably free, put it above
 * the plot box. Tick labels are formatted by a label callback that also
 * measures the widest y label, so that the axis title clears it.
 *
 * PLplot's state (stream table, current stream, the cairo driver's
 * options) is global to the process: these functions are not thread-safe.
 *
 * References: PLplot 5.15 API (plmkstrm, plsfile, plspage, plvpor,
 * plwind, plbox, pllegend); src/plctrl.c (plOpenFile, plCloseFile) and
 * drivers/cairo.c (plD_init_pngcairo, plD_tidy_cairo) of PLplot 5.15;
 * memo Figs. 7-12 (Kamman & Nguyen 1990) for what is drawn.
 *
 * One module, though long: every picture goes through the same stream
 * handling, page set-up, unit conversion, axes and legend code, and only
 * its draw callback differs (a few dozen lines each); split by picture,
 * each file would repeat or export that machinery.
 */
#include "towstab/plot.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <plplot.h>

#include "outfile.h"
#include "plot_impl.h"
#include "plot_module.h"

/* The display quantity of a plot quantity, -1 for those shown as they
 * are (dimensionless, 1/s). */
static int display_quantity(ts_plot_quantity q)
{
    switch (q) {
    case TS_PLOT_LENGTH: return TS_QTY_LENGTH;
    case TS_PLOT_FORCE: return TS_QTY_FORCE;
    case TS_PLOT_SPEED: return TS_QTY_SPEED;
    case TS_PLOT_TIME: return TS_QTY_TIME;
    case TS_PLOT_FREQUENCY: return TS_QTY_FREQUENCY;
    case TS_PLOT_ANGULAR_RATE: return TS_QTY_ANGULAR_RATE;
    case TS_PLOT_ANGLE: return TS_QTY_ANGLE;
    default: return -1;
    }
}

/* An SI value as drawn, and the unit of its axis: opts->display when
 * set, else opts->units. */
static double pconv(ts_plot_quantity q, const ts_plot_opts *o, double v)
{
    int dq = display_quantity(q);
    if (o->display && dq >= 0)
        return ts_display_value(o->display, (ts_quantity)dq, v);
    return ts_plot_convert(q, o->units, v);
}

static const char *punit(ts_plot_quantity q, const ts_plot_opts *o)
{
    int dq = display_quantity(q);
    if (o->display && dq >= 0)
        return ts_display_unit(o->display, (ts_quantity)dq);
    return ts_plot_unit(q, o->units);
}

/* ---- palette (cmap0) ------------------------------------------------- */

enum {
    COL_BG = 0,      /* white background */
    COL_FG = 1,      /* axes and text */
    COL_GRID = 2,
    COL_GREY = 3,    /* reference shapes, rays */
    COL_WATER = 4,   /* water below the surface */
    COL_SURFACE = 5, /* the water line */
    COL_UNSTABLE = 6,
    COL_CURVE0 = 7,  /* first of NCURVE curve colours */
    NCURVE = 8,
    NCOL0 = COL_CURVE0 + NCURVE
};

/* Curve colours: the Okabe-Ito set (distinct for colour-blind readers)
 * without its yellow, plus a wine red. */
static const int palette_rgb[NCOL0][3] = {
    {255, 255, 255}, {0, 0, 0},       {222, 222, 222}, {140, 140, 140},
    {222, 236, 250}, {50, 110, 190},  {252, 226, 226}, {0, 114, 178},
    {213, 94, 0},    {0, 158, 115},   {204, 121, 167}, {230, 159, 0},
    {86, 180, 233},  {80, 80, 80},    {136, 34, 85}};

/* PLplot line styles (pllsty): 1 continuous, 2 short dashes, 3 long. */
#define LSTY_SOLID 1
#define LSTY_DOTTED 2
#define LSTY_DASHED 3

#define CURVE_WIDTH 2.2
#define AXIS_WIDTH 1.0
#define GRID_WIDTH 0.6

/* At most this many legend entries are drawn per legend. */
#define MAX_LEGEND 20
/* Text passed to PLplot, after escaping. */
#define TEXT_MAX 512

static int color_index(int color, int ordinal)
{
    int k = color > 0 ? color - 1 : ordinal;
    return COL_CURVE0 + ((k % NCURVE) + NCURVE) % NCURVE;
}

static int line_style(int style)
{
    return style == TS_PLOT_DASHED ? LSTY_DASHED
           : style == TS_PLOT_DOTTED ? LSTY_DOTTED
                                     : LSTY_SOLID;
}

/* Marker glyphs by ordinal (DejaVu Sans has them all). */
static const char *marker_glyph(int ordinal)
{
    static const char *const g[] = {"●", "■", "▲", "◆", "▼", "✖", "★", "⬟"};
    return g[((ordinal % 8) + 8) % 8];
}

/* PLplot text: '#' is its escape character, so a literal '#' is "##". */
static void pl_text(char *dst, size_t size, const char *src)
{
    size_t j = 0;
    for (size_t i = 0; src && src[i] && j + 2 < size; i++) {
        if (src[i] == '#')
            dst[j++] = '#';
        dst[j++] = src[i];
    }
    dst[j] = '\0';
}

static void axis_label(char *dst, size_t size, const char *name,
                       ts_plot_quantity q, const ts_plot_opts *u)
{
    char raw[TEXT_MAX];
    snprintf(raw, sizeof raw, "%s [%s]", name ? name : "",
             punit(q, u));
    pl_text(dst, size, raw);
}

/* The label of an axis, with its own unit when it has one. */
static void axis_label_of(char *dst, size_t size, const ts_plot_axis *a,
                          const ts_plot_opts *u)
{
    if (a->quantity != TS_PLOT_NONE || !a->unit || !a->unit[0]) {
        axis_label(dst, size, a->label, a->quantity, u);
        return;
    }
    char raw[TEXT_MAX];
    snprintf(raw, sizeof raw, "%s [%s]", a->label ? a->label : "", a->unit);
    pl_text(dst, size, raw);
}

/* ---- frame: world window and legend placement ------------------------ */

/* Width of a digit or sign relative to the character height. */
#define DIGIT_WIDTH 0.75
/* Width of text relative to the character height, on average. */
#define TEXT_WIDTH 0.8

/* Physical size of the current viewport, mm. */
static void viewport_mm(double *w, double *h)
{
    PLFLT sx0, sx1, sy0, sy1, vx0, vx1, vy0, vy1;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    plgvpd(&vx0, &vx1, &vy0, &vy1);
    *w = (vx1 - vx0) * (sx1 - sx0);
    *h = (vy1 - vy0) * (sy1 - sy0);
}

/* Number of characters (UTF-8 code points) of a string. */
static int text_chars(const char *s)
{
    int n = 0;
    for (; s && *s; s++)
        n += ((unsigned char)*s & 0xC0) != 0x80;
    return n;
}


#define SEGMENT_SAMPLES 12

typedef struct frame {
    double left, right, bottom, top; /* as passed to plwind */
    int logx, logy;                  /* axes in log10 of the value */
    double ylabel_width;             /* widest y tick label, in character
                                        heights (set while the box is
                                        drawn) */
    double corner_w, corner_h;       /* legend size, fractions of the
                                        viewport */
    long count[4];                   /* points in TR, BR, TL, BL corners */
} frame;

/* Set the world window of the current viewport. The legend's expected
 * size (nlegend entries, the longest `label_chars` long) sets the corner
 * regions in which drawn points are counted. */
static void frame_set(frame *f, double left, double right, double bottom,
                      double top, int nlegend, int label_chars)
{
    f->left = left;
    f->right = right;
    f->bottom = bottom;
    f->top = top;
    f->logx = f->logy = 0;
    f->ylabel_width = 0;
    double w, h;
    PLFLT def, ht;
    viewport_mm(&w, &h);
    plgchr(&def, &ht);
    /* pllegend below: text at 0.9 of the character size, 2 lines per
     * entry, a line sample of 7 % of the width. */
    f->corner_h = fmin(0.95, (2.0 * nlegend + 1.0) * 0.9 * ht / h + 0.03);
    f->corner_w = fmin(0.95, 0.07 + 0.03 +
                                 (TEXT_WIDTH * 0.9 * label_chars + 2.5) * ht /
                                     w);
    memset(f->count, 0, sizeof f->count);
    plwind(left, right, bottom, top);
}

/* A drawn marker hides data if the legend covers it: it counts as many
 * points as a drawn segment or label. */
#define MARKER_WEIGHT 20

static void frame_point_w(frame *f, double x, double y, int weight)
{
    double u = (x - f->left) / (f->right - f->left);
    double v = (y - f->bottom) / (f->top - f->bottom);
    if (!(u >= 0 && u <= 1 && v >= 0 && v <= 1))
        return;
    int right = u >= 1 - f->corner_w, left = u <= f->corner_w;
    int top = v >= 1 - f->corner_h, bottom = v <= f->corner_h;
    f->count[0] += weight * (right && top);
    f->count[1] += weight * (right && bottom);
    f->count[2] += weight * (left && top);
    f->count[3] += weight * (left && bottom);
}

static void frame_point(frame *f, double x, double y)
{
    frame_point_w(f, x, y, 1);
}

/* Record a drawn segment (its ends and samples along it). */
static void frame_segment(frame *f, double x0, double y0, double x1,
                          double y1)
{
    for (int s = 0; s <= SEGMENT_SAMPLES; s++) {
        double t = (double)s / SEGMENT_SAMPLES;
        frame_point(f, x0 + t * (x1 - x0), y0 + t * (y1 - y0));
    }
}

/* A polyline in the current colour and style, recorded in the frame. */
static void draw_line(frame *f, int n, const double *x, const double *y)
{
    if (n >= 2)
        plline(n, x, y);
    for (int i = 0; i + 1 < n; i++)
        frame_segment(f, x[i], y[i], x[i + 1], y[i + 1]);
    if (n == 1)
        frame_point(f, x[0], y[0]);
}

static void draw_markers(frame *f, int n, const double *x, const double *y,
                         const char *glyph)
{
    plstring(n, x, y, glyph);
    for (int i = 0; i < n; i++)
        frame_point_w(f, x[i], y[i], MARKER_WEIGHT);
}

/* PLplot legend position of the emptiest corner. */
static int frame_corner(const frame *f)
{
    static const int pos[4] = {PL_POSITION_TOP | PL_POSITION_RIGHT,
                               PL_POSITION_BOTTOM | PL_POSITION_RIGHT,
                               PL_POSITION_TOP | PL_POSITION_LEFT,
                               PL_POSITION_BOTTOM | PL_POSITION_LEFT};
    int best = 0;
    for (int c = 1; c < 4; c++)
        if (f->count[c] < f->count[best])
            best = c;
    return pos[best];
}

/* ---- legends --------------------------------------------------------- */

/* Count a legend entry and its length (for the legend's expected size). */
static void legend_count(const char *label, int *n, int *chars)
{
    if (!label || !label[0] || *n >= MAX_LEGEND)
        return;
    (*n)++;
    int c = text_chars(label);
    if (c > *chars)
        *chars = c;
}

typedef struct legend {
    int n;
    PLINT opt[MAX_LEGEND];
    PLINT color[MAX_LEGEND];
    PLINT style[MAX_LEGEND];
    PLFLT width[MAX_LEGEND];
    PLFLT scale[MAX_LEGEND];
    PLINT nsym[MAX_LEGEND];
    PLINT textcol[MAX_LEGEND];
    char text[MAX_LEGEND][TEXT_MAX];
    const char *textp[MAX_LEGEND];
    const char *sym[MAX_LEGEND];
} legend;

/* Add an entry (style: a TS_PLOT_ style; glyph for marker styles). */
static void legend_add(legend *L, const char *label, int color, int style,
                       const char *glyph)
{
    if (!label || !label[0] || L->n >= MAX_LEGEND)
        return;
    int i = L->n++;
    int line = style != TS_PLOT_MARKERS;
    int sym = style == TS_PLOT_MARKERS || style == TS_PLOT_LINE_MARKERS;
    L->opt[i] = (line ? PL_LEGEND_LINE : 0) | (sym ? PL_LEGEND_SYMBOL : 0);
    L->color[i] = color;
    L->style[i] = line_style(style);
    L->width[i] = CURVE_WIDTH;
    L->scale[i] = 0.9;
    L->nsym[i] = style == TS_PLOT_MARKERS ? 1 : 2;
    L->textcol[i] = COL_FG;
    pl_text(L->text[i], sizeof L->text[i], label);
    L->textp[i] = L->text[i];
    L->sym[i] = glyph ? glyph : "●";
}

/* Layout of a legend above the plot box: columns and rows that fit the
 * page width `width_mm`, and the height it takes, mm. */
typedef struct legend_layout {
    int ncol, nrow;
    double height_mm;
} legend_layout;

static legend_layout legend_plan(const legend *L, double width_mm)
{
    legend_layout g = {1, 0, 0};
    if (L->n == 0)
        return g;
    PLFLT def, ht;
    plgchr(&def, &ht);
    int chars = 0;
    for (int i = 0; i < L->n; i++)
        if (text_chars(L->text[i]) > chars)
            chars = text_chars(L->text[i]);
    /* Sample, gap and text of the widest entry. */
    double entry = 0.07 * width_mm + (TEXT_WIDTH * 0.9 * chars + 2.0) * ht;
    g.ncol = (int)(0.98 * width_mm / entry);
    if (g.ncol < 1)
        g.ncol = 1;
    if (g.ncol > L->n)
        g.ncol = L->n;
    g.nrow = (L->n + g.ncol - 1) / g.ncol;
    g.height_mm = (2.0 * g.nrow + 0.6) * 0.9 * ht;
    return g;
}

/* Draw the legend just above the current viewport, row by row. */
static void legend_draw_above(const legend *L, legend_layout g)
{
    if (L->n == 0)
        return;
    PLFLT w, h;
    pllsty(LSTY_SOLID);
    pllegend(&w, &h,
             PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX |
                 PL_LEGEND_ROW_MAJOR,
             PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT | PL_POSITION_TOP,
             0.0, 0.012, 0.07, COL_BG, COL_GREY, LSTY_SOLID, g.nrow, g.ncol,
             L->n, L->opt, 0.8, 0.9, 2.0, 0.0, L->textcol, L->textp, NULL,
             NULL, NULL, NULL, L->color, L->style, L->width, L->color,
             L->scale, L->nsym, L->sym);
}

static void legend_draw(const legend *L, const frame *f)
{
    if (L->n == 0)
        return;
    PLFLT w, h;
    /* Room for a line sample, or a single marker. */
    double sample = 0.03;
    for (int i = 0; i < L->n; i++)
        if (L->opt[i] & PL_LEGEND_LINE)
            sample = 0.07;
    pllsty(LSTY_SOLID);
    pllegend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
             PL_POSITION_INSIDE | PL_POSITION_VIEWPORT | frame_corner(f),
             0.015, 0.02, sample, COL_BG, COL_GREY, LSTY_SOLID, 0, 0, L->n,
             L->opt, 0.8, 0.9, 2.0, 0.0, L->textcol, L->textp, NULL, NULL,
             NULL, NULL, L->color, L->style, L->width, L->color, L->scale,
             L->nsym, L->sym);
}

/* ---- axes, labels, title --------------------------------------------- */

/* Format a tick value of a linear axis spanning [lo, hi] with as many
 * decimals as ticks finer than a tenth of the span need (PLplot puts 3 to
 * 10 ticks on an axis), trailing zeros removed: 29.6 and 29.8, not 29.6
 * twice; values within rounding of zero print as 0. Very large or small
 * magnitudes use the exponent form with as many digits. Returns the
 * number of characters. */
static int format_tick(char *label, size_t size, double value, double lo,
                       double hi)
{
    double span = fabs(hi - lo), mag = fmax(fabs(lo), fabs(hi));
    double tick = span / 10;
    if (!(tick > 0))
        return snprintf(label, size, "%g", value);
    if (fabs(value) < 1e-9 * span)
        value = 0;
    int dec = (int)ceil(-log10(tick));
    if (dec < 0)
        dec = 0;
    if (value == 0)
        return snprintf(label, size, "0");
    if (mag >= 1e7 || mag < 1e-4 || dec > 8) {
        int digits = (int)ceil(log10(mag / tick));
        digits = digits < 1 ? 1 : digits > 15 ? 15 : digits;
        return snprintf(label, size, "%.*e", digits, value);
    }
    int n = snprintf(label, size, "%.*f", dec, value);
    if (dec > 0 && n > 0 && (size_t)n < size) {
        while (n > 0 && label[n - 1] == '0')
            label[--n] = '\0';
        if (n > 0 && label[n - 1] == '.')
            label[--n] = '\0';
    }
    if (strcmp(label, "-0") == 0)
        n = snprintf(label, size, "0");
    return n;
}

/* Tick labels (plslabelfunc): "%.6g" of the value, exact zero for values
 * within rounding of zero, and 10^k on log axes. Records the widest y
 * label so that the axis title can be set clear of it. */
static void tick_label(PLINT axis, PLFLT value, char *label, PLINT length,
                       PLPointer data)
{
    frame *f = data;
    int log = axis == PL_X_AXIS ? f->logx : f->logy;
    double width;
    if (log) {
        long e = lround(value);
        snprintf(label, (size_t)length, "10#u%ld#d", e);
        char digits[24];
        int nd = snprintf(digits, sizeof digits, "%ld", e);
        width = (2 + 0.85 * nd) * DIGIT_WIDTH + 0.2;
    } else {
        double lo = axis == PL_X_AXIS ? f->left : f->bottom;
        double hi = axis == PL_X_AXIS ? f->right : f->top;
        width = DIGIT_WIDTH * format_tick(label, (size_t)length, value, lo, hi);
    }
    if (axis == PL_Y_AXIS && width > f->ylabel_width)
        f->ylabel_width = width;
}

/* Width of the y tick labels of a window [lo, hi], in character heights:
 * the labels of its ends and middle (ticks lie between; one digit more
 * for safety). */
static double tick_width(double lo, double hi, int log)
{
    if (log) {
        char digits[24];
        long e = fabs(lo) > fabs(hi) ? lround(floor(lo)) : lround(ceil(hi));
        int nd = snprintf(digits, sizeof digits, "%ld", e);
        return (2 + 0.85 * (nd + 1)) * DIGIT_WIDTH + 0.2;
    }
    char t[64];
    int n = 0;
    double v[3] = {lo, hi, 0.5 * (lo + hi)};
    for (int i = 0; i < 3; i++) {
        int k = format_tick(t, sizeof t, v[i], lo, hi);
        n = k > n ? k : n;
    }
    return (n + 1) * DIGIT_WIDTH;
}

/* Left edge of the plot box (normalised page coordinate) that leaves room
 * for y tick labels `width` character heights wide at character scale
 * `scale`, the axis title and a margin; at least LEFT_MIN. */
#define LEFT_MIN 0.085
static double left_edge(double width, double scale)
{
    PLFLT sx0, sx1, sy0, sy1, def, ht;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    plgchr(&def, &ht);
    double mm = (width + 1.8 + 1.4) * def * scale;
    double x = mm / (sx1 - sx0);
    return x > LEFT_MIN ? x : LEFT_MIN;
}

/* Grid, then the box with ticks and labels; xopt/yopt as plbox ("l" for
 * a log axis, "n" for labels). */
static void frame_axes(frame *f, const char *xopt, const char *yopt,
                       double ytick)
{
    char gx[16], gy[16], bx[32], by[32];
    f->logx = strchr(xopt, 'l') != NULL;
    f->logy = strchr(yopt, 'l') != NULL;
    snprintf(gx, sizeof gx, "g%s", f->logx ? "hl" : "");
    snprintf(gy, sizeof gy, "g%s", f->logy ? "hl" : "");
    snprintf(bx, sizeof bx, "%so", xopt);
    snprintf(by, sizeof by, "%sov", yopt);
    plslabelfunc(tick_label, f);
    plcol0(COL_GRID);
    plwidth(GRID_WIDTH);
    pllsty(LSTY_SOLID);
    plbox(gx, 0, 0, gy, ytick, 0);
    plcol0(COL_FG);
    plwidth(AXIS_WIDTH);
    f->ylabel_width = 0;
    plbox(bx, 0, 0, by, ytick, 0);
    plslabelfunc(NULL, NULL);
}

/* plmtex with the character size reduced, if needed, so that the text
 * fits `avail_mm`. */
static void mtex_fit(const char *side, double disp, double pos, double just,
                     const char *text, double avail_mm, double scale)
{
    PLFLT def, ht;
    plgchr(&def, &ht);
    double need = TEXT_WIDTH * text_chars(text) * def * scale;
    double s = need > avail_mm ? scale * avail_mm / need : scale;
    plschr(0, s);
    plmtex(side, disp * scale / s, pos, just, text);
    plschr(0, 1.0);
}

/* Axis titles: x under the tick labels, y left of the widest y tick
 * label; `scale` is the character size used for the ticks. */
static void label_axes(const frame *f, const char *xlabel,
                       const char *ylabel, double scale)
{
    double w, h;
    viewport_mm(&w, &h);
    plcol0(COL_FG);
    if (xlabel)
        mtex_fit("b", 3.0, 0.5, 0.5, xlabel, w, scale);
    if (ylabel) {
        /* Left of the widest tick label, but on the page: at most the
         * margin left of the viewport less half a line. */
        PLFLT sx0, sx1, sy0, sy1, vx0, vx1, vy0, vy1, def, ht;
        plgspa(&sx0, &sx1, &sy0, &sy1);
        plgvpd(&vx0, &vx1, &vy0, &vy1);
        plgchr(&def, &ht);
        double disp = 1.8 + f->ylabel_width;
        double room = vx0 * (sx1 - sx0) / ht - 0.7;
        mtex_fit("l", disp < room ? disp : room, 0.5, 0.5, ylabel, h, scale);
    }
}

/* A small explanatory note above the top right corner of the viewport. */
static void note(const char *text)
{
    plcol0(COL_FG);
    plschr(0, 0.78);
    plmtex("t", 0.6, 1.0, 1.0, text);
    plschr(0, 1.0);
}

static void page_title(const char *title)
{
    char t[TEXT_MAX];
    pl_text(t, sizeof t, title);
    plvpor(0, 1, 0, 1);
    plwind(0, 1, 0, 1);
    plcol0(COL_FG);
    double w, h;
    viewport_mm(&w, &h);
    mtex_fit("t", -1.7, 0.5, 0.5, t, 0.96 * w, 1.3);
}

/* Physical height / width of the current viewport (mm / mm). */
static double viewport_aspect(void)
{
    double w, h;
    viewport_mm(&w, &h);
    return h / w;
}

/* Data range [lo, hi] padded by `pad` of its span; a zero span gets a
 * width of `fallback`. */
static void pad_range(double *lo, double *hi, double pad, double fallback)
{
    double span = *hi - *lo;
    if (!(span > 0)) {
        double w = fallback > 0 ? fallback : 1.0;
        *lo -= 0.5 * w;
        *hi += 0.5 * w;
        return;
    }
    *lo -= pad * span;
    *hi += pad * span;
}

/* A logarithmic range [lo, hi] (log10 units) that holds no whole decade
 * would get no tick label (PLplot labels decades only): widen it to the
 * decades around it. */
static void whole_decade(double *lo, double *hi)
{
    if (floor(*hi) < *lo) {
        *lo = floor(*lo);
        *hi = ceil(*hi);
    }
}

/* Widen [x0,x1] or [y0,y1] about its centre so that world units per mm
 * are equal on both axes of the current viewport. */
static void equalize(double *x0, double *x1, double *y0, double *y1)
{
    double aspect = viewport_aspect();
    double w = *x1 - *x0, h = *y1 - *y0;
    if (h < aspect * w) {
        double c = 0.5 * (*y0 + *y1), nh = aspect * w;
        *y0 = c - 0.5 * nh;
        *y1 = c + 0.5 * nh;
    } else {
        double c = 0.5 * (*x0 + *x1), nw = h / aspect;
        *x0 = c - 0.5 * nw;
        *x1 = c + 0.5 * nw;
    }
}

/* ---- output: streams, memory, files ---------------------------------- */

typedef int (*draw_fn)(const void *ctx, const ts_plot_opts *o, int height,
                       ts_err *err);

static void set_palette(void)
{
    PLINT r[NCOL0], g[NCOL0], b[NCOL0];
    for (int i = 0; i < NCOL0; i++) {
        r[i] = palette_rgb[i][0];
        g[i] = palette_rgb[i][1];
        b[i] = palette_rgb[i][2];
    }
    plscmap0n(NCOL0);
    plscmap0(r, g, b, NCOL0);
}

/* Draw into memory with device `dev`; *buf (malloc'd) and *size on
 * success. */
static int render_one(const char *dev, int width, int height, draw_fn draw,
                      const void *ctx, const ts_plot_opts *o, char **buf,
                      size_t *size, ts_err *err)
{
    *buf = NULL;
    *size = 0;
    FILE *f = open_memstream(buf, size);
    if (!f)
        return ts_fail(err, TS_ENOMEM, "plot: cannot open a memory stream "
                                       "(%s)",
                       strerror(errno));
    PLINT old, strm;
    plgstrm(&old);
    plmkstrm(&strm);
    if (strm < 0) {
        plsstrm(old);
        fclose(f);
        free(*buf);
        *buf = NULL;
        return ts_fail(err, TS_ENOMEM, "plot: PLplot has no free stream");
    }
    plsdev(dev);
    plsfile(f);
    plspage(0, 0, width, height, 0, 0);
    set_palette();
    plinit();
    pladv(0);
    plschr(0, 1.0);
    int rc = draw(ctx, o, height, err);
    plend1(); /* closes f: *buf and *size are final */
    plsstrm(old);
    if (rc == TS_OK && *size == 0)
        rc = ts_fail(err, TS_EIO, "plot: PLplot's %s device wrote nothing",
                     dev);
    if (rc != TS_OK) {
        free(*buf);
        *buf = NULL;
    }
    return rc;
}

static void xml_escape(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* Write one picture to its temporary file (committed by the caller). */
static int write_bytes(FILE *f, const char *path, const char *buf,
                       size_t size, int svg, const char *title, ts_err *err)
{
    size_t head = 0;
    if (svg) {
        const char *root = NULL;
        for (size_t i = 0; i + 4 < size && !root; i++)
            if (memcmp(buf + i, "<svg", 4) == 0)
                root = buf + i;
        const char *end = root ? memchr(root, '>', size - (root - buf))
                               : NULL;
        if (!end)
            return ts_fail(err, TS_EIO, "%s: svgcairo output has no <svg> "
                                        "element",
                           path);
        head = (size_t)(end - buf) + 1;
        fwrite(buf, 1, head, f);
        fputs("\n<title>", f);
        xml_escape(f, title);
        fputs("</title>", f);
    }
    fwrite(buf + head, 1, size - head, f);
    if (ferror(f))
        return ts_fail(err, TS_EIO, "%s: write failed", path);
    return TS_OK;
}

static int check_name(const char *name)
{
    if (!name || !name[0] || name[0] == '.')
        return 0;
    for (const char *p = name; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
              (*p >= '0' && *p <= '9') || *p == '_' || *p == '-' ||
              *p == '.'))
            return 0;
    return strlen(name) <= 200;
}

static int check_opts(const char *fn, const ts_plot_opts *o, ts_err *err)
{
    if (o->units != TS_PLOT_SI && o->units != TS_PLOT_IMPERIAL)
        return ts_fail(err, TS_EINVAL, "%s: opts.units: expected SI or "
                                       "imperial, got %d",
                       fn, (int)o->units);
    if (o->width < TS_PLOT_MIN_WIDTH || o->width > TS_PLOT_MAX_SIZE ||
        o->height < TS_PLOT_MIN_HEIGHT || o->height > TS_PLOT_MAX_SIZE)
        return ts_fail(err, TS_EINVAL,
                       "%s: opts size: expected %d..%d x %d..%d px, got "
                       "%d x %d",
                       fn, TS_PLOT_MIN_WIDTH, TS_PLOT_MAX_SIZE,
                       TS_PLOT_MIN_HEIGHT, TS_PLOT_MAX_SIZE, o->width,
                       o->height);
    if (o->formats <= 0 || (o->formats & ~(TS_PLOT_PNG | TS_PLOT_SVG)))
        return ts_fail(err, TS_EINVAL, "%s: opts.formats: expected "
                                       "TS_PLOT_PNG and/or TS_PLOT_SVG, got "
                                       "%d",
                       fn, o->formats);
    return TS_OK;
}

/* Check, draw every requested format, write the files. */
static int render(const char *fn, const char *dir, const char *name,
                  const char *title, const ts_plot_opts *o, int height,
                  draw_fn draw, const void *ctx, ts_err *err)
{
    static const char *const dev[2] = {"pngcairo", "svgcairo"};
    static const char *const ext[2] = {"png", "svg"};
    int rc = ts_plot_prepare_dir(dir, err);
    if (rc)
        return rc;
    char *buf[2] = {NULL, NULL};
    size_t size[2] = {0, 0};
    for (int k = 0; k < 2 && rc == TS_OK; k++)
        if (o->formats & (1 << k))
            rc = render_one(dev[k], o->width, height, draw, ctx, o, &buf[k],
                            &size[k], err);
    if (rc) {
        ts_err_prefix(err, "%s: ", fn);
        free(buf[0]);
        free(buf[1]);
        return rc;
    }
    /* Both temporary files first, then both renames. */
    char path[2][1200];
    tsi_outfile f[2];
    memset(f, 0, sizeof f);
    for (int k = 0; k < 2 && rc == TS_OK; k++) {
        if (!buf[k])
            continue;
        int n = snprintf(path[k], sizeof path[k], "%s/%s.%s", dir, name,
                         ext[k]);
        if (n < 0 || (size_t)n >= sizeof path[k]) {
            rc = ts_fail(err, TS_EINVAL, "%s: path '%s/%s.%s' is too long",
                         fn, dir, name, ext[k]);
            break;
        }
        rc = tsi_outfile_open(&f[k], path[k], err);
        if (rc == TS_OK)
            rc = write_bytes(f[k].f, path[k], buf[k], size[k], k == 1, title,
                             err);
    }
    for (int k = 0; k < 2; k++) {
        if (!f[k].f)
            continue;
        if (rc == TS_OK)
            rc = tsi_outfile_commit(&f[k], err);
        else
            tsi_outfile_abandon(&f[k]);
    }
    free(buf[0]);
    free(buf[1]);
    return rc;
}

/* The devices this module needs. */
static int check_devices(ts_err *err)
{
    enum { MAXDEV = 256 };
    const char *menu_store[MAXDEV], *name_store[MAXDEV];
    const char **menu = menu_store, **names = name_store;
    int ndev = MAXDEV, have_png = 0, have_svg = 0;
    plgDevs(&menu, &names, &ndev);
    for (int i = 0; i < ndev; i++) {
        have_png |= strcmp(names[i], "pngcairo") == 0;
        have_svg |= strcmp(names[i], "svgcairo") == 0;
    }
    if (!have_png || !have_svg)
        return ts_fail(err, TS_EDOMAIN,
                       "PLplot's cairo driver (pngcairo, svgcairo) is not "
                       "installed; install plplot-driver-cairo");
    return TS_OK;
}

/* Common argument checks of every public drawing function. */
static int begin(const char *fn, const char *dir, const char *name,
                 const char *title, const ts_plot_opts **o,
                 ts_plot_opts *defaults, ts_err *err)
{
    int rc = check_devices(err);
    if (rc)
        return rc;
    if (!*o) {
        ts_plot_opts_default(defaults);
        *o = defaults;
    }
    if (!dir || !dir[0])
        return ts_fail(err, TS_EINVAL, "%s: dir: expected a directory, got "
                                       "none",
                       fn);
    if (!check_name(name))
        return ts_fail(err, TS_EINVAL,
                       "%s: name: expected letters, digits, '_', '-' or "
                       "'.' (not first), at most 200, got '%s'",
                       fn, name ? name : "(null)");
    if (!title)
        return ts_fail(err, TS_EINVAL, "%s: title: expected text, got NULL",
                       fn);
    return check_opts(fn, *o, err);
}

/* A list argument: at least one entry, the array given. */
static int check_list(const char *fn, const char *what, const void *list,
                      int n, ts_err *err)
{
    if (n < 1 || !list)
        return ts_fail(err, TS_EINVAL, "%s: expected at least one %s, got "
                       "%d", fn, what, n);
    return TS_OK;
}

/* The point count n of entry i of list `what`: at least `min`. */
static int check_points(const char *fn, const char *what, int i, int n,
                        int min, ts_err *err)
{
    if (n < min)
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].n: must be >= %d, got "
                       "%d", fn, what, i, min, n);
    return TS_OK;
}

static int check_array(const char *fn, const char *what, int index,
                       const double *a, int n, int positive, ts_err *err)
{
    if (!a)
        return ts_fail(err, TS_EINVAL, "%s: %s (item %d): expected an array "
                                       "of %d values, got NULL",
                       fn, what, index, n);
    for (int i = 0; i < n; i++) {
        if (!isfinite(a[i]))
            return ts_fail(err, TS_EINVAL,
                           "%s: %s[%d] (item %d): must be finite, got %g", fn,
                           what, i, index, a[i]);
        if (positive && !(a[i] > 0))
            return ts_fail(err, TS_EINVAL,
                           "%s: %s[%d] (item %d): must be > 0 on a log axis, "
                           "got %g",
                           fn, what, i, index, a[i]);
    }
    return TS_OK;
}

static int check_series(const char *fn, int nseries,
                        const ts_plot_series s[], int xpos, int ypos,
                        ts_err *err)
{
    int rc = check_list(fn, "series", s, nseries, err);
    if (rc)
        return rc;
    for (int i = 0; i < nseries; i++) {
        if ((rc = check_points(fn, "series", i, s[i].n, 1, err)))
            return rc;
        rc = check_array(fn, "x", i, s[i].x, s[i].n, xpos, err);
        if (!rc)
            rc = check_array(fn, "y", i, s[i].y, s[i].n, ypos, err);
        if (rc)
            return rc;
        if (s[i].style < TS_PLOT_SOLID || s[i].style > TS_PLOT_LINE_MARKERS)
            return ts_fail(err, TS_EINVAL, "%s: series[%d].style: unknown "
                                           "style %d",
                           fn, i, s[i].style);
    }
    return TS_OK;
}

static int check_quantity(const char *fn, const char *what,
                          ts_plot_quantity q, ts_err *err)
{
    if ((int)q < TS_PLOT_NONE || (int)q > TS_PLOT_MASS)
        return ts_fail(err, TS_EINVAL, "%s: %s: unknown quantity %d", fn,
                       what, (int)q);
    return TS_OK;
}

/* Draw a series' line and/or markers. */
static void draw_series(frame *f, const ts_plot_series *s, int color,
                        int ordinal, const double *x, const double *y)
{
    plcol0(color);
    plwidth(CURVE_WIDTH);
    pllsty(line_style(s->style));
    if (s->style != TS_PLOT_MARKERS)
        draw_line(f, s->n, x, y);
    pllsty(LSTY_SOLID);
    if (s->style == TS_PLOT_MARKERS || s->style == TS_PLOT_LINE_MARKERS ||
        s->n == 1)
        draw_markers(f, s->n, x, y, marker_glyph(ordinal));
}

/* ---- cable shapes ---------------------------------------------------- */

/* Converted coordinates of one shape: h (horizontal), v (vertical) and
 * depth z (for the water test), [nnodes] each. */
typedef struct shape_xy {
    double *h, *v, *z;
} shape_xy;

static int check_shape(const char *fn, const char *what, int i,
                       const ts_plot_shape *s, ts_err *err)
{
    if (s->nnodes < 2)
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].nnodes: must be >= 2, got "
                                       "%d",
                       fn, what, i, s->nnodes);
    int rc = check_array(fn, "pos", i, s->pos, 3 * s->nnodes, 0, err);
    if (rc)
        return rc;
    for (int k = 0; s->link_upper && k < s->nnodes - 1; k++)
        if (s->link_upper[k] < 0 || s->link_upper[k] > k)
            return ts_fail(err, TS_EINVAL,
                           "%s: %s[%d].link_upper[%d]: must be in [0, %d] "
                           "(a node above), got %d",
                           fn, what, i, k, k, s->link_upper[k]);
    if (s->nmarks < 0 || (s->nmarks > 0 && !s->marks))
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].marks: expected %d node "
                                       "indices",
                       fn, what, i, s->nmarks);
    for (int m = 0; m < s->nmarks; m++)
        if (s->marks[m] < 0 || s->marks[m] >= s->nnodes)
            return ts_fail(err, TS_EINVAL,
                           "%s: %s[%d].marks[%d]: must be a node in [0, %d), "
                           "got %d",
                           fn, what, i, m, s->nnodes, s->marks[m]);
    if (s->ncylinders < 0 || (s->ncylinders > 0 && !s->cylinders))
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].cylinders: expected %d "
                                       "cylinders",
                       fn, what, i, s->ncylinders);
    for (int m = 0; m < s->ncylinders; m++) {
        const ts_plot_cylinder *cy = &s->cylinders[m];
        if (cy->node < 1 || cy->node >= s->nnodes)
            return ts_fail(err, TS_EINVAL,
                           "%s: %s[%d].cylinders[%d].node: must be a node "
                           "below a link, in [1, %d), got %d",
                           fn, what, i, m, s->nnodes, cy->node);
        if (!(cy->length > 0) || !isfinite(cy->length) ||
            !(cy->diameter > 0) || !isfinite(cy->diameter))
            return ts_fail(err, TS_EINVAL,
                           "%s: %s[%d].cylinders[%d]: length and diameter "
                           "must be finite and > 0, got %g m and %g m",
                           fn, what, i, m, cy->length, cy->diameter);
    }
    if (!isfinite(s->turn_radius))
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].turn_radius: must be "
                                       "finite, got %g m",
                       fn, what, i, s->turn_radius);
    if (s->style != TS_PLOT_SOLID && s->style != TS_PLOT_DASHED)
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].style: expected solid or "
                                       "dashed, got %d",
                       fn, what, i, s->style);
    if (s->noutlines < 0 || (s->noutlines > 0 && !s->outlines))
        return ts_fail(err, TS_EINVAL, "%s: %s[%d].outlines: expected %d",
                       fn, what, i, s->noutlines);
    for (int b = 0; b < s->noutlines; b++) {
        const ts_plot_outline *o = &s->outlines[b];
        if (o->npoints < 0 || (o->npoints > 0 && !o->pts) ||
            !isfinite(o->anchor[0]) || !isfinite(o->anchor[1]) ||
            !isfinite(o->anchor[2]))
            return ts_fail(err, TS_EINVAL, "%s: %s[%d].outlines[%d]: "
                           "expected points and a finite anchor", fn, what,
                           i, b);
    }
    return TS_OK;
}

/* The magnification of the outlines of shapes[nshapes]: the smallest
 * drawn at least TS_PLOT_OUTLINE_MIN of `extent` (m), at least 1. */
static double outline_scale(int nshapes, const ts_plot_shape *shapes,
                            double extent)
{
    double smallest = INFINITY;
    for (int i = 0; i < nshapes; i++)
        for (int b = 0; b < shapes[i].noutlines; b++) {
            const ts_plot_outline *o = &shapes[i].outlines[b];
            double lo[3] = {INFINITY, INFINITY, INFINITY};
            double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int k = 0; k < o->npoints; k++)
                for (int j = 0; j < 3; j++)
                    if (isfinite(o->pts[3 * k + j])) {
                        lo[j] = fmin(lo[j], o->pts[3 * k + j]);
                        hi[j] = fmax(hi[j], o->pts[3 * k + j]);
                    }
            double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1],
                                                   hi[2] - lo[2]));
            if (size > 0)
                smallest = fmin(smallest, size);
        }
    if (!isfinite(smallest) || !(extent > 0))
        return 1.0;
    return fmax(1.0, TS_PLOT_OUTLINE_MIN * extent / smallest);
}

/* Draw the outlines of s in the side view (top 0) or the top view,
 * magnified by `scale` about their anchors; moved by a mode at scale
 * `ms` when motion ([6 noutlines], ts_plot_mode.outline_motion) is not
 * NULL. */
static void draw_outlines(frame *f, const ts_plot_shape *s, int top,
                          double scale, const double *motion, double ms,
                          const ts_plot_opts *u)
{
    for (int b = 0; b < s->noutlines; b++) {
        const ts_plot_outline *o = &s->outlines[b];
        double ph[2], pv[2];
        int have = 0;
        for (int k = 0; k < o->npoints; k++) {
            const double *p = o->pts + 3 * (size_t)k;
            if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
                have = 0;
                continue;
            }
            double q[3];
            tsi_plot_outline_point(o->anchor, motion ? motion + 6 * b : NULL, ms,
                          scale, p, q);
            ph[1] = pconv(TS_PLOT_LENGTH, u, q[0]);
            pv[1] = pconv(TS_PLOT_LENGTH, u, top ? q[1] : q[2]);
            if (have)
                draw_line(f, 2, ph, pv);
            ph[0] = ph[1];
            pv[0] = pv[1];
            have = 1;
        }
    }
}

/* Fill xy from pos (+ scale * disp when disp is not NULL). */
static int shape_coords(const ts_plot_shape *s, const double *disp,
                        double scale, ts_plot_view view,
                        const ts_plot_opts *u,
                        shape_xy *xy)
{
    int n = s->nnodes;
    xy->h = malloc(3 * (size_t)n * sizeof(double));
    if (!xy->h)
        return TS_ENOMEM;
    xy->v = xy->h + n;
    xy->z = xy->h + 2 * n;
    for (int k = 0; k < n; k++) {
        double r[3];
        for (int j = 0; j < 3; j++)
            r[j] = s->pos[3 * k + j] + (disp ? scale * disp[3 * k + j] : 0);
        xy->h[k] = pconv(TS_PLOT_LENGTH, u, r[0]);
        xy->v[k] = pconv(TS_PLOT_LENGTH, u,
                                   view == TS_PLOT_SIDE ? r[2] : r[1]);
        xy->z[k] = r[2];
    }
    return TS_OK;
}

/* Draw a run of points in one medium. */
static void flush_run(frame *f, int n, const double *h, const double *v,
                      int in_air, int style)
{
    pllsty(in_air ? LSTY_DASHED : line_style(style));
    draw_line(f, n, h, v);
}

/* Draw the links of a shape as polylines: a link continues the previous
 * polyline when its upper node is the previous link's lower node. With
 * `water`, each polyline is split where it crosses z = 0 and the parts in
 * air (z < 0) are dashed. `work` holds 2 (2 nnodes + 2) doubles. */
static void draw_shape_links(frame *f, const ts_plot_shape *s,
                             const shape_xy *xy, int water, double *work)
{
    int n = s->nnodes;
    double *rh = work, *rv = work + 2 * n + 2;
    int len = 0, air = 0;
    for (int k = 0; k + 1 < n; k++) {
        int a = s->link_upper ? s->link_upper[k] : k, b = k + 1;
        int cont = k > 0 && a == k;
        if (!cont) {
            if (len >= 2)
                flush_run(f, len, rh, rv, air, s->style);
            len = 0;
            rh[len] = xy->h[a];
            rv[len++] = xy->v[a];
            air = water && xy->z[a] < 0;
        }
        int b_air = water && xy->z[b] < 0;
        if (b_air != air) {
            /* The link crosses the surface (z = 0 counts as water): end
             * the run at the crossing and start the next one there. The
             * run's medium is that of node a, so z[a] != z[b]. */
            double t = xy->z[a] / (xy->z[a] - xy->z[b]);
            double ch = xy->h[a] + t * (xy->h[b] - xy->h[a]);
            double cv = xy->v[a] + t * (xy->v[b] - xy->v[a]);
            rh[len] = ch;
            rv[len++] = cv;
            flush_run(f, len, rh, rv, air, s->style);
            len = 0;
            rh[len] = ch;
            rv[len++] = cv;
            air = b_air;
        }
        rh[len] = xy->h[b];
        rv[len++] = xy->v[b];
    }
    if (len >= 2)
        flush_run(f, len, rh, rv, air, s->style);
    pllsty(LSTY_SOLID);
}

/* Points of a cylinder seen end on (a circle). */
#define CYL_POINTS 33
/* A cylinder is drawn at least this fraction of the picture's extent
 * long. */
#define CYL_MIN 0.03

/* The cylinders of s (ts_plot_cylinder) at xy: the outline of each,
 * centred on its node, its axis the projection of its link's direction,
 * filled in the current colour and edged in the foreground's; at least
 * minlen long (display units) with its proportions kept; a circle of its
 * diameter when the axis points out of the view. Leaves colour col
 * current. */
static void draw_cylinders(frame *f, const ts_plot_shape *s,
                           const shape_xy *xy, const ts_plot_opts *u,
                           double minlen, int col)
{
    for (int b = 0; b < s->ncylinders; b++) {
        const ts_plot_cylinder *cy = &s->cylinders[b];
        int k = cy->node;
        int up = s->link_upper ? s->link_upper[k - 1] : k - 1;
        double d = 0;
        for (int j = 0; j < 3; j++) {
            double dj = s->pos[3 * k + j] - s->pos[3 * up + j];
            d += dj * dj;
        }
        d = pconv(TS_PLOT_LENGTH, u, sqrt(d));
        double L = pconv(TS_PLOT_LENGTH, u, cy->length);
        double D = pconv(TS_PLOT_LENGTH, u, cy->diameter);
        double g = L < minlen ? minlen / L : 1.0;
        L *= g;
        D *= g;
        double eh = d > 0 ? (xy->h[k] - xy->h[up]) / d : 0;
        double ev = d > 0 ? (xy->v[k] - xy->v[up]) / d : 0;
        double p = hypot(eh, ev);
        double px[CYL_POINTS + 1], py[CYL_POINTS + 1];
        int n = 4;
        if (p < 1e-3) {
            n = CYL_POINTS;
            for (int i = 0; i < n; i++) {
                double a = 2 * M_PI * i / n;
                px[i] = xy->h[k] + 0.5 * D * cos(a);
                py[i] = xy->v[k] + 0.5 * D * sin(a);
            }
        } else {
            double nh = -ev / p, nv = eh / p;
            static const double sa[4] = {1, 1, -1, -1}, sb[4] = {1, -1, -1, 1};
            for (int i = 0; i < 4; i++) {
                px[i] = xy->h[k] + 0.5 * (sa[i] * L * eh + sb[i] * D * nh);
                py[i] = xy->v[k] + 0.5 * (sa[i] * L * ev + sb[i] * D * nv);
            }
        }
        plcol0(col);
        plfill(n, px, py);
        px[n] = px[0];
        py[n] = py[0];
        plcol0(COL_FG);
        plwidth(1.0);
        draw_line(f, n + 1, px, py);
    }
    plcol0(col);
}

static void draw_marks(frame *f, const ts_plot_shape *s, const shape_xy *xy,
                       double size)
{
    plschr(0, size);
    for (int m = 0; m < s->nmarks; m++)
        draw_markers(f, 1, &xy->h[s->marks[m]], &xy->v[s->marks[m]], "●");
    plschr(0, 1.0);
}

typedef struct shapes_ctx {
    const char *title;
    ts_plot_view view;
    int flags;
    int nshapes;
    const ts_plot_shape *shapes;
} shapes_ctx;

#define CIRCLE_POINTS 721
/* A turning circle larger than this many cable extents is not fitted into
 * the window (it is clipped to the cable's surroundings). */
#define CIRCLE_FIT 3.0

static void bbox_update(double *lo, double *hi, double v)
{
    if (v < *lo)
        *lo = v;
    if (v > *hi)
        *hi = v;
}

static void draw_water(frame *f, double x0, double x1, double zdeep,
                       const ts_plot_opts *u)
{
    if (zdeep > 0) {
        double px[4] = {x0, x1, x1, x0}, pz[4] = {0, 0, zdeep, zdeep};
        plcol0(COL_WATER);
        plfill(4, px, pz);
    }
    plcol0(COL_SURFACE);
    plwidth(1.6);
    pllsty(LSTY_SOLID);
    pljoin(x0, 0, x1, 0);
    frame_segment(f, x0, 0, x1, 0);
    char t[64];
    snprintf(t, sizeof t, "water surface (z = 0 %s)",
             punit(TS_PLOT_LENGTH, u));
    plschr(0, 0.85);
    /* Just above the line at the left end (depth axis points down). */
    double ty = -0.03 * fabs(f->top - f->bottom);
    plptex(x0 + 0.01 * (x1 - x0), ty, 1, 0, 0.0, t);
    frame_segment(f, x0, ty, x0 + 0.3 * (x1 - x0), ty);
    plschr(0, 1.0);
}

static int draw_shapes(const void *vctx, const ts_plot_opts *o, int height,
                       ts_err *err)
{
    (void)height;
    const shapes_ctx *c = vctx;
    const ts_plot_opts *u = o;
    int top = c->view == TS_PLOT_TOP;
    int water = (c->flags & TS_PLOT_WATER) != 0;
    shape_xy *xy = calloc((size_t)c->nshapes, sizeof *xy);
    if (!xy)
        return ts_fail(err, TS_ENOMEM, "out of memory");
    int maxn = 0, rc = TS_OK;
    double h0 = INFINITY, h1 = -INFINITY, v0 = INFINITY, v1 = -INFINITY;
    for (int i = 0; i < c->nshapes && rc == TS_OK; i++) {
        rc = shape_coords(&c->shapes[i], NULL, 0, c->view, u, &xy[i]);
        for (int k = 0; rc == TS_OK && k < c->shapes[i].nnodes; k++) {
            bbox_update(&h0, &h1, xy[i].h[k]);
            bbox_update(&v0, &v1, xy[i].v[k]);
        }
        if (c->shapes[i].nnodes > maxn)
            maxn = c->shapes[i].nnodes;
    }
    double *work = rc ? NULL : malloc(4 * ((size_t)maxn + 1) * sizeof *work);
    if (rc || !work) {
        for (int i = 0; i < c->nshapes; i++)
            free(xy[i].h);
        free(xy);
        return ts_fail(err, TS_ENOMEM, "out of memory");
    }
    double extent = fmax(h1 - h0, v1 - v0);
    if (!(extent > 0))
        extent = pconv(TS_PLOT_LENGTH, u, 1.0);
    if (top) {
        /* The ship at the origin, and turning circles that are not much
         * larger than the cable. */
        bbox_update(&h0, &h1, 0);
        bbox_update(&v0, &v1, 0);
        for (int i = 0; i < c->nshapes; i++) {
            double R = pconv(TS_PLOT_LENGTH, u,
                                       c->shapes[i].turn_radius);
            if (R != 0 && fabs(R) <= CIRCLE_FIT * extent) {
                bbox_update(&h0, &h1, -fabs(R));
                bbox_update(&h0, &h1, fabs(R));
                bbox_update(&v0, &v1, 0);
                bbox_update(&v0, &v1, 2 * R);
            }
        }
    } else if (water) {
        /* Always show the surface with some air above it. */
        bbox_update(&v0, &v1, 0);
        bbox_update(&v0, &v1, -0.04 * extent);
    }
    pad_range(&h0, &h1, 0.06, extent);
    pad_range(&v0, &v1, 0.08, extent);

    /* The legend goes above the plot box (cable shapes leave no corner
     * reliably free), with entries for the line styles in use. */
    legend L = {0};
    int in_air = 0, circles = 0;
    for (int i = 0; i < c->nshapes; i++) {
        const ts_plot_shape *s = &c->shapes[i];
        legend_add(&L, s->label, color_index(s->color, i), s->style, NULL);
        for (int k = 0; water && k < s->nnodes; k++)
            in_air |= xy[i].z[k] < 0;
        circles |= top && s->turn_radius != 0;
    }
    if (in_air)
        legend_add(&L, "in air", COL_FG, TS_PLOT_DASHED, NULL);
    if (circles)
        legend_add(&L, "the ship's turning circle", COL_FG, TS_PLOT_DOTTED,
                   NULL);
    /* extent is in the axes' unit, the outlines in m. */
    double oscale = outline_scale(
        c->nshapes, c->shapes,
        extent / pconv(TS_PLOT_LENGTH, u, 1.0));
    char olab[TEXT_MAX];
    int outlines = 0;
    for (int i = 0; i < c->nshapes; i++)
        outlines |= c->shapes[i].noutlines > 0;
    if (outlines) {
        if (oscale > 1.0)
            snprintf(olab, sizeof olab, "vehicles at their attitude, drawn "
                     "%.3g times their size", oscale);
        else
            snprintf(olab, sizeof olab, "vehicles at their attitude");
        legend_add(&L, olab, COL_FG, TS_PLOT_SOLID, NULL);
    }
    PLFLT sx0, sx1, sy0, sy1;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    legend_layout lay = legend_plan(&L, 0.87 * (sx1 - sx0));
    double box_top = 0.89 - (lay.height_mm > 0 ? lay.height_mm + 2.0 : 0) /
                                (sy1 - sy0);
    plvpor(left_edge(tick_width(v0, v1, 0), 1.0), 0.97, 0.11, box_top);
    if (top || (c->flags & TS_PLOT_EQUAL))
        equalize(&h0, &h1, &v0, &v1);
    frame f;
    /* Depth and starboard grow downward: bottom edge = largest value. */
    frame_set(&f, h0, h1, v1, v0, 0, 0);

    if (water && !top)
        draw_water(&f, h0, h1, v1, u);
    frame_axes(&f, "bcnst", "bcnst", 0);

    if (top) {
        /* Ship at the origin heading +x: a small grey arrowhead. */
        double s = 0.025 * (h1 - h0);
        double ax[3] = {s, -s, -s}, ay[3] = {0, -0.6 * s, 0.6 * s};
        plcol0(COL_GREY);
        plfill(3, ax, ay);
        frame_point(&f, 0, 0);
        plschr(0, 0.85);
        plptex(0, -1.1 * s, 1, 0, 0.5, "ship");
        plschr(0, 1.0);
        for (int i = 0; i < c->nshapes; i++) {
            double R = pconv(TS_PLOT_LENGTH, u,
                                       c->shapes[i].turn_radius);
            if (R == 0)
                continue;
            double cx[CIRCLE_POINTS], cy[CIRCLE_POINTS];
            for (int k = 0; k < CIRCLE_POINTS; k++) {
                double a = 2 * M_PI * k / (CIRCLE_POINTS - 1);
                cx[k] = fabs(R) * sin(a);
                cy[k] = R - R * cos(a);
            }
            plcol0(color_index(c->shapes[i].color, i));
            plwidth(1.2);
            pllsty(LSTY_DOTTED);
            draw_line(&f, CIRCLE_POINTS, cx, cy);
            pllsty(LSTY_SOLID);
            double zero = 0;
            plschr(0, 0.9);
            draw_markers(&f, 1, &zero, &R, "+");
            plptex(0.02 * (h1 - h0), R, 1, 0, 0.0, "turn centre");
            frame_segment(&f, 0, R, 0.15 * (h1 - h0), R);
            plschr(0, 1.0);
        }
    }
    for (int i = 0; i < c->nshapes; i++) {
        const ts_plot_shape *s = &c->shapes[i];
        plcol0(color_index(s->color, i));
        plwidth(CURVE_WIDTH);
        draw_shape_links(&f, s, &xy[i], water, work);
        draw_cylinders(&f, s, &xy[i], u, CYL_MIN * extent,
                       color_index(s->color, i));
        plwidth(CURVE_WIDTH);
        draw_marks(&f, s, &xy[i], 1.1);
        plwidth(1.4);
        draw_outlines(&f, s, top, oscale, NULL, 0.0, u);
    }
    char xl[TEXT_MAX], yl[TEXT_MAX];
    axis_label(xl, sizeof xl, "x, forward", TS_PLOT_LENGTH, u);
    axis_label(yl, sizeof yl, top ? "y, starboard" : "z, depth",
               TS_PLOT_LENGTH, u);
    label_axes(&f, xl, yl, 1.0);
    legend_draw_above(&L, lay);
    page_title(c->title);
    for (int i = 0; i < c->nshapes; i++)
        free(xy[i].h);
    free(xy);
    free(work);
    return TS_OK;
}

/* begin(), and a view that is side or top. */
static int begin_view(const char *fn, const char *dir, const char *name,
                      const char *title, const ts_plot_opts **o,
                      ts_plot_opts *defaults, ts_plot_view view, ts_err *err)
{
    int rc = begin(fn, dir, name, title, o, defaults, err);
    if (rc)
        return rc;
    if (view != TS_PLOT_SIDE && view != TS_PLOT_TOP)
        return ts_fail(err, TS_EINVAL, "%s: view: expected side or top, got "
                                       "%d",
                       fn, (int)view);
    return TS_OK;
}

static int plot_shapes(const char *dir, const char *name, const char *title,
                       ts_plot_view view, int flags, int nshapes,
                       const ts_plot_shape shapes[], const ts_plot_opts *opts,
                       ts_err *err)
{
    static const char fn[] = "ts_plot_shapes";
    ts_plot_opts def;
    int rc = begin_view(fn, dir, name, title, &opts, &def, view, err);
    if (rc)
        return rc;
    if (flags & ~(TS_PLOT_WATER | TS_PLOT_EQUAL))
        return ts_fail(err, TS_EINVAL, "%s: flags: unknown bits in %#x", fn,
                       (unsigned)flags);
    if ((rc = check_list(fn, "shape", shapes, nshapes, err)))
        return rc;
    for (int i = 0; i < nshapes; i++)
        if ((rc = check_shape(fn, "shapes", i, &shapes[i], err)))
            return rc;
    shapes_ctx c = {title, view, flags, nshapes, shapes};
    return render(fn, dir, name, title, opts, opts->height, draw_shapes, &c,
                  err);
}

/* ---- tracks in the earth frame ---------------------------------------- */

typedef struct tracks_ctx {
    const char *title;
    int ntracks;
    const ts_plot_track *tracks;
} tracks_ctx;

/* Arrowhead length, a fraction of the window's width. */
#define ARROW_SIZE 0.022

static int draw_tracks(const void *vctx, const ts_plot_opts *o, int height,
                       ts_err *err)
{
    (void)height;
    const tracks_ctx *c = vctx;
    int nmax = 1;
    for (int i = 0; i < c->ntracks; i++)
        if (c->tracks[i].n > nmax)
            nmax = c->tracks[i].n;
    double *px = malloc(2 * (size_t)nmax * sizeof *px);
    if (!px)
        return ts_fail(err, TS_ENOMEM, "out of memory");
    double *py = px + nmax;
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    legend L = {0};
    int markers = 0;
    for (int i = 0; i < c->ntracks; i++) {
        const ts_plot_track *t = &c->tracks[i];
        for (int k = 0; k < t->n; k++) {
            bbox_update(&x0, &x1, pconv(TS_PLOT_LENGTH, o, t->x[k]));
            bbox_update(&y0, &y1, pconv(TS_PLOT_LENGTH, o, t->y[k]));
        }
        for (int k = 0; k < t->nmarkers; k++) {
            bbox_update(&x0, &x1, pconv(TS_PLOT_LENGTH, o, t->markers[k].x));
            bbox_update(&y0, &y1, pconv(TS_PLOT_LENGTH, o, t->markers[k].y));
        }
        markers |= t->nmarkers > 0;
        legend_add(&L, t->label, color_index(t->color, i),
                   t->n == 1 ? TS_PLOT_MARKERS : t->style, marker_glyph(i));
    }
    double extent = fmax(x1 - x0, y1 - y0);
    if (!(extent > 0))
        extent = pconv(TS_PLOT_LENGTH, o, 1.0);
    pad_range(&x0, &x1, 0.06, extent);
    pad_range(&y0, &y1, 0.06, extent);
    if (markers)
        legend_add(&L, "marked points", COL_FG, TS_PLOT_MARKERS, "◇");
    PLFLT sx0, sx1, sy0, sy1;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    legend_layout lay = legend_plan(&L, 0.87 * (sx1 - sx0));
    double box_top = 0.89 - (lay.height_mm > 0 ? lay.height_mm + 2.0 : 0) /
                                (sy1 - sy0);
    plvpor(left_edge(tick_width(y0, y1, 0), 1.0), 0.97, 0.11, box_top);
    equalize(&x0, &x1, &y0, &y1);
    frame f;
    /* y (starboard at t = 0) grows down the page, as in the top view. */
    frame_set(&f, x0, x1, y1, y0, 0, 0);
    frame_axes(&f, "bcnst", "bcnst", 0);
    for (int i = 0; i < c->ntracks; i++) {
        const ts_plot_track *t = &c->tracks[i];
        int col = color_index(t->color, i);
        for (int k = 0; k < t->n; k++) {
            px[k] = pconv(TS_PLOT_LENGTH, o, t->x[k]);
            py[k] = pconv(TS_PLOT_LENGTH, o, t->y[k]);
        }
        ts_plot_series s = {t->n, px, py, NULL, 0, t->style, 0, NULL};
        draw_series(&f, &s, col, i, px, py);
        /* The direction of travel: an arrowhead on the last segment that
         * has a length. */
        int k = t->n - 1;
        while (k > 0 && px[k - 1] == px[k] && py[k - 1] == py[k])
            k--;
        if (k > 0 && t->style != TS_PLOT_MARKERS) {
            double dx = px[t->n - 1] - px[k - 1], dy = py[t->n - 1] - py[k - 1];
            double len = hypot(dx, dy), a = ARROW_SIZE * (x1 - x0);
            double ux = dx / len, uy = dy / len;
            double ax[3] = {px[t->n - 1], px[t->n - 1] - a * ux + 0.4 * a * uy,
                            px[t->n - 1] - a * ux - 0.4 * a * uy};
            double ay[3] = {py[t->n - 1], py[t->n - 1] - a * uy - 0.4 * a * ux,
                            py[t->n - 1] - a * uy + 0.4 * a * ux};
            plcol0(col);
            plfill(3, ax, ay);
            frame_point(&f, ax[0], ay[0]);
        }
        plschr(0, 0.85);
        for (int m = 0; m < t->nmarkers; m++) {
            const ts_plot_marker *mk = &t->markers[m];
            double mx = pconv(TS_PLOT_LENGTH, o, mk->x);
            double my = pconv(TS_PLOT_LENGTH, o, mk->y);
            plcol0(col);
            draw_markers(&f, 1, &mx, &my, "◇");
            if (mk->label && mk->label[0]) {
                char txt[TEXT_MAX];
                pl_text(txt, sizeof txt, mk->label);
                plcol0(COL_FG);
                /* Just right of the marker and above it (y grows down). */
                plptex(mx + 0.012 * (x1 - x0), my - 0.02 * (y1 - y0), 1, 0,
                       0.0, txt);
            }
        }
        plschr(0, 1.0);
    }
    char xl[TEXT_MAX], yl[TEXT_MAX];
    axis_label(xl, sizeof xl, "x, earth frame (initial heading)",
               TS_PLOT_LENGTH, o);
    axis_label(yl, sizeof yl, "y, earth frame (initial starboard)",
               TS_PLOT_LENGTH, o);
    label_axes(&f, xl, yl, 1.0);
    legend_draw_above(&L, lay);
    page_title(c->title);
    free(px);
    return TS_OK;
}

static int plot_tracks(const char *dir, const char *name, const char *title,
                       int ntracks, const ts_plot_track tracks[],
                       const ts_plot_opts *opts, ts_err *err)
{
    static const char fn[] = "ts_plot_tracks";
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc)
        return rc;
    if ((rc = check_list(fn, "track", tracks, ntracks, err)))
        return rc;
    for (int i = 0; i < ntracks; i++) {
        const ts_plot_track *t = &tracks[i];
        if ((rc = check_points(fn, "tracks", i, t->n, 1, err)) ||
            (rc = check_array(fn, "x", i, t->x, t->n, 0, err)) ||
            (rc = check_array(fn, "y", i, t->y, t->n, 0, err)))
            return rc;
        if (t->style < TS_PLOT_SOLID || t->style > TS_PLOT_LINE_MARKERS)
            return ts_fail(err, TS_EINVAL, "%s: tracks[%d].style: unknown "
                                           "style %d",
                           fn, i, t->style);
        if (t->nmarkers < 0 || (t->nmarkers > 0 && !t->markers))
            return ts_fail(err, TS_EINVAL, "%s: tracks[%d].markers: expected "
                                           "%d markers, got %s",
                           fn, i, t->nmarkers,
                           t->nmarkers < 0 ? "a negative count" : "NULL");
        for (int m = 0; m < t->nmarkers; m++)
            if (!isfinite(t->markers[m].x) || !isfinite(t->markers[m].y))
                return ts_fail(err, TS_EINVAL, "%s: tracks[%d].markers[%d]: "
                                               "must be finite, got (%g, %g)",
                               fn, i, m, t->markers[m].x, t->markers[m].y);
    }
    tracks_ctx c = {title, ntracks, tracks};
    return render(fn, dir, name, title, opts, opts->height, draw_tracks, &c,
                  err);
}

/* ---- mode shapes ----------------------------------------------------- */

/* Largest displacement is this fraction of the cable's largest extent. */
#define MODE_AMPLITUDE 0.15
#define MODE_ROW_PX 220
#define MODE_TOP_PX 95    /* title and note */
#define MODE_TITLE_PX 55  /* the title alone */
#define MODE_BOTTOM_PX 50 /* the x axis title */
#define MODE_TEXT 0.8     /* character size in the small panels */
#define MAX_MODES 8

typedef struct modes_ctx {
    const char *title;
    int flags;
    const ts_plot_shape *eq;
    int nmodes;
    const ts_plot_mode *modes;
    const double *scale; /* [nmodes] */
} modes_ctx;

static int draw_modes(const void *vctx, const ts_plot_opts *o, int height,
                      ts_err *err)
{
    const modes_ctx *c = vctx;
    const ts_plot_opts *u = o;
    int water = (c->flags & TS_PLOT_WATER) != 0;
    int n = c->eq->nnodes;
    /* xy[view][0] equilibrium, [1 + 2m] +mode, [2 + 2m] -mode. */
    int nsh = 1 + 2 * c->nmodes;
    shape_xy *xy = calloc(2 * (size_t)nsh, sizeof *xy);
    double *work = malloc(4 * ((size_t)n + 1) * sizeof *work);
    int rc = xy && work ? TS_OK : TS_ENOMEM;
    double lo[2][2] = {{INFINITY, INFINITY}, {INFINITY, INFINITY}};
    double hi[2][2] = {{-INFINITY, -INFINITY}, {-INFINITY, -INFINITY}};
    for (int view = 0; view < 2 && rc == TS_OK; view++)
        for (int j = 0; j < nsh && rc == TS_OK; j++) {
            int m = (j - 1) / 2;
            double sgn = j == 0 ? 0 : (j % 2 ? 1 : -1);
            shape_xy *s = &xy[view * nsh + j];
            rc = shape_coords(c->eq, j ? c->modes[m].disp : NULL,
                              j ? sgn * c->scale[m] : 0, (ts_plot_view)view,
                              u, s);
            for (int k = 0; rc == TS_OK && k < n; k++) {
                bbox_update(&lo[view][0], &hi[view][0], s->h[k]);
                bbox_update(&lo[view][1], &hi[view][1], s->v[k]);
            }
        }
    if (rc) {
        for (int j = 0; xy && j < 2 * nsh; j++)
            free(xy[j].h);
        free(xy);
        free(work);
        return ts_fail(err, TS_ENOMEM, "out of memory");
    }
    double extent = 0;
    for (int view = 0; view < 2; view++)
        for (int a = 0; a < 2; a++)
            extent = fmax(extent, hi[view][a] - lo[view][a]);
    if (!(extent > 0))
        extent = pconv(TS_PLOT_LENGTH, u, 1.0);
    if (water) {
        bbox_update(&lo[0][1], &hi[0][1], 0);
        bbox_update(&lo[0][1], &hi[0][1], -0.04 * extent);
    }
    for (int view = 0; view < 2; view++) {
        pad_range(&lo[view][0], &hi[view][0], 0.05, extent);
        pad_range(&lo[view][1], &hi[view][1], 0.10, extent);
    }
    double oscale = outline_scale(1, c->eq,
                                  extent / pconv(TS_PLOT_LENGTH, u, 1.0));
    /* Rows from the top; normalised page coordinates. */
    double top_frac = (double)MODE_TOP_PX / height;
    double bottom_frac = (double)MODE_BOTTOM_PX / height;
    double row = (1 - top_frac - bottom_frac) / c->nmodes;
    char xl[TEXT_MAX], yl[2][TEXT_MAX], lab[TEXT_MAX];
    axis_label(xl, sizeof xl, "x, forward", TS_PLOT_LENGTH, u);
    axis_label(yl[0], sizeof yl[0], "z, depth", TS_PLOT_LENGTH, u);
    axis_label(yl[1], sizeof yl[1], "y, starboard", TS_PLOT_LENGTH, u);
    for (int m = 0; m < c->nmodes; m++) {
        /* The box takes 68 % of the row; the rest is the mode's label
         * above and the tick labels below. */
        double y1 = 1 - top_frac - m * row - 0.12 * row;
        double y0 = y1 - 0.68 * row;
        for (int view = 0; view < 2; view++) {
            double x0 = view ? 0.59 : 0.10, x1 = view ? 0.98 : 0.49;
            plvpor(x0, x1, y0, y1);
            double h0 = lo[view][0], h1 = hi[view][0];
            double v0 = lo[view][1], v1 = hi[view][1];
            if (view == 1 || (c->flags & TS_PLOT_EQUAL))
                equalize(&h0, &h1, &v0, &v1);
            frame f;
            frame_set(&f, h0, h1, v1, v0, 0, 0);
            if (water && view == 0) {
                double px[4] = {h0, h1, h1, h0}, pz[4] = {0, 0, v1, v1};
                if (v1 > 0) {
                    plcol0(COL_WATER);
                    plfill(4, px, pz);
                }
                plcol0(COL_SURFACE);
                plwidth(1.4);
                pljoin(h0, 0, h1, 0);
            }
            plschr(0, MODE_TEXT);
            frame_axes(&f, "bcnst", "bcnst", 0);
            label_axes(&f, m == c->nmodes - 1 ? xl : NULL, yl[view],
                       MODE_TEXT);
            plschr(0, 1.0);
            const shape_xy *s = &xy[view * nsh];
            plcol0(COL_GREY);
            plwidth(1.6);
            draw_shape_links(&f, c->eq, &s[0], water, work);
            draw_cylinders(&f, c->eq, &s[0], u, CYL_MIN * extent, COL_GREY);
            plwidth(1.6);
            draw_marks(&f, c->eq, &s[0], 0.8);
            plwidth(1.2);
            draw_outlines(&f, c->eq, view == 1, oscale, NULL, 0.0, u);
            int col = color_index(0, m);
            for (int j = 1; j <= 2; j++) {
                ts_plot_shape style = *c->eq;
                style.style = j == 1 ? TS_PLOT_SOLID : TS_PLOT_DASHED;
                plcol0(col);
                plwidth(CURVE_WIDTH);
                /* The -mode is dashed everywhere; in-air dashing would
                 * not show on it, so only the +mode marks air parts. */
                draw_shape_links(&f, &style, &s[2 * m + j], water && j == 1,
                                 work);
                /* Cylinder towfish at the displaced node, along the
                 * displaced link (its length from the equilibrium). */
                draw_cylinders(&f, c->eq, &s[2 * m + j], u, CYL_MIN * extent,
                               col);
                plwidth(CURVE_WIDTH);
                draw_marks(&f, c->eq, &s[2 * m + j], 0.8);
                /* The vehicles moved and rotated by the mode at its
                 * scale, about their magnified size. */
                if (c->modes[m].outline_motion) {
                    plwidth(1.2);
                    draw_outlines(&f, c->eq, view == 1, oscale,
                                  c->modes[m].outline_motion,
                                  (j == 1 ? 1 : -1) * c->scale[m], u);
                }
            }
            if (view == 0) {
                pl_text(lab, sizeof lab, c->modes[m].label);
                plcol0(col);
                plmtex("t", 0.6, 0.0, 0.0, lab);
            }
        }
    }
    page_title(c->title);
    plvpor(0, 1, 0, 1 - (double)MODE_TITLE_PX / height);
    plwind(0, 1, 0, 1);
    plcol0(COL_FG);
    plschr(0, 0.8);
    int nl = snprintf(lab, sizeof lab,
                      "grey: equilibrium; solid, dashed: the mode at "
                      "opposite phases, largest displacement %.0f %% of the "
                      "cable's extent",
                      100 * MODE_AMPLITUDE);
    int moved = 0;
    for (int m = 0; m < c->nmodes; m++)
        moved |= c->modes[m].outline_motion != NULL;
    if (c->eq->noutlines > 0 && nl > 0 && (size_t)nl < sizeof lab)
        nl += snprintf(lab + nl, sizeof lab - (size_t)nl, "; vehicles %s",
                       moved ? "at trim grey, moved and turned by the mode "
                               "coloured"
                             : "at their trim attitude");
    if (oscale > 1.0 && nl > 0 && (size_t)nl < sizeof lab)
        snprintf(lab + nl, sizeof lab - (size_t)nl, ", drawn %.3g times "
                 "their size", oscale);
    plschr(0, 1.0);
    {
        double w, h;
        viewport_mm(&w, &h);
        mtex_fit("t", -1.0, 0.5, 0.5, lab, 0.96 * w, 0.8);
    }
    for (int j = 0; j < 2 * nsh; j++)
        free(xy[j].h);
    free(xy);
    free(work);
    return TS_OK;
}

static int plot_mode_shapes(const char *dir, const char *name, const char *title,
                            int flags, const ts_plot_shape *eq, int nmodes,
                            const ts_plot_mode modes[], const ts_plot_opts *opts,
                            ts_err *err)
{
    static const char fn[] = "ts_plot_mode_shapes";
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc)
        return rc;
    if (flags & ~(TS_PLOT_WATER | TS_PLOT_EQUAL))
        return ts_fail(err, TS_EINVAL, "%s: flags: unknown bits in %#x", fn,
                       (unsigned)flags);
    if (!eq)
        return ts_fail(err, TS_EINVAL, "%s: eq: expected the equilibrium "
                                       "shape, got NULL",
                       fn);
    ts_plot_shape e = *eq;
    e.style = TS_PLOT_SOLID;
    e.turn_radius = 0;
    if ((rc = check_shape(fn, "eq", 0, &e, err)))
        return rc;
    if (nmodes < 1 || nmodes > MAX_MODES || !modes)
        return ts_fail(err, TS_EINVAL, "%s: nmodes: expected 1..%d modes, got "
                                       "%d",
                       fn, MAX_MODES, nmodes);
    double extent = 0, scale[MAX_MODES];
    for (int a = 0; a < 3; a++) {
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < eq->nnodes; k++)
            bbox_update(&lo, &hi, eq->pos[3 * k + a]);
        extent = fmax(extent, hi - lo);
    }
    if (!(extent > 0))
        return ts_fail(err, TS_EINVAL, "%s: eq.pos: all nodes coincide", fn);
    for (int m = 0; m < nmodes; m++) {
        if ((rc = check_array(fn, "modes.disp", m, modes[m].disp,
                              3 * eq->nnodes, 0, err)))
            return rc;
        if (modes[m].outline_motion && eq->noutlines > 0 &&
            (rc = check_array(fn, "modes.outline_motion", m,
                              modes[m].outline_motion, 6 * eq->noutlines, 0,
                              err)))
            return rc;
        double dmax = 0;
        for (int k = 0; k < eq->nnodes; k++)
            dmax = fmax(dmax, hypot(hypot(modes[m].disp[3 * k],
                                          modes[m].disp[3 * k + 1]),
                                    modes[m].disp[3 * k + 2]));
        if (!(dmax > 0))
            return ts_fail(err, TS_EINVAL, "%s: modes[%d].disp: all zero",
                           fn, m);
        scale[m] = MODE_AMPLITUDE * extent / dmax;
    }
    int height = MODE_TOP_PX + MODE_ROW_PX * nmodes + MODE_BOTTOM_PX;
    if (height < opts->height)
        height = opts->height;
    if (height > TS_PLOT_MAX_SIZE)
        height = TS_PLOT_MAX_SIZE;
    modes_ctx c = {title, flags, &e, nmodes, modes, scale};
    return render(fn, dir, name, title, opts, height, draw_modes, &c, err);
}

/* ---- eigenvalues ----------------------------------------------------- */

typedef struct eig_ctx {
    const char *title;
    int nsets;
    const ts_plot_series *sets;
    ts_plot_eig_window win;
} eig_ctx;

static int draw_eigenvalues(const void *vctx, const ts_plot_opts *o,
                            int height, ts_err *err)
{
    (void)o, (void)height, (void)err;
    const eig_ctx *c = vctx;
    double r0 = 0, r1 = 0, im = 0;
    for (int s = 0; s < c->nsets; s++)
        for (int i = 0; i < c->sets[s].n; i++) {
            bbox_update(&r0, &r1, c->sets[s].x[i]);
            im = fmax(im, fabs(c->sets[s].y[i]));
        }
    double span = r1 - r0;
    if (!(span > 0))
        span = im > 0 ? im : 1;
    if (!(im > 0))
        im = 0.5 * span;
    r0 -= 0.08 * span;
    /* Keep a visible strip of the unstable half-plane. */
    r1 = fmax(r1 + 0.08 * span, 0.12 * span);
    im *= 1.1;
    if (c->win.re_min < 0)
        r0 = c->win.re_min;
    if (c->win.re_max > 0)
        r1 = c->win.re_max;
    if (c->win.im_max > 0)
        im = c->win.im_max;

    plvpor(left_edge(tick_width(-im, im, 0), 1.0), 0.97, 0.11, 0.89);
    int nlegend = 0, lchars = 0;
    for (int s = 0; s < c->nsets; s++)
        legend_count(c->sets[s].label, &nlegend, &lchars);
    frame f;
    frame_set(&f, r0, r1, -im, im, nlegend, lchars);
    double ux[4] = {0, r1, r1, 0}, uy[4] = {-im, -im, im, im};
    plcol0(COL_UNSTABLE);
    plfill(4, ux, uy);
    frame_axes(&f, "bcnst", "bcnst", 0);
    /* Rays of constant damping ratio from the origin into the left
     * half-plane, each labelled inside the window where its upper half
     * leaves it (top or left edge); labels closer than LABEL_GAP of the
     * width to the previous one are left out. */
    static const double zetas[] = {0.5, 0.2, 0.1, 0.05, 0.02};
    const double LABEL_GAP = 0.07;
    double w = r1 - r0, last_x = -INFINITY, last_y = INFINITY;
    plwidth(1.0);
    plschr(0, 0.8);
    double reach = 4 * (fabs(r0) + fabs(r1) + im);
    for (size_t z = 0; z < sizeof zetas / sizeof zetas[0]; z++) {
        double zeta = zetas[z], wd = sqrt(1 - zeta * zeta);
        double rx[3] = {-zeta * reach, 0, -zeta * reach};
        double ry[3] = {wd * reach, 0, -wd * reach};
        plcol0(COL_GREY);
        pllsty(LSTY_DASHED);
        plline(3, rx, ry);
        pllsty(LSTY_SOLID);
        double ex = -zeta / wd * im, ey = im;
        if (ex < r0) {
            ex = r0;
            ey = -r0 * wd / zeta;
        }
        char t[32];
        snprintf(t, sizeof t, "ζ=%g", zeta);
        if (ey >= im) {
            double x = ex - 0.008 * w, y = im - 0.045 * im;
            if (x - last_x < LABEL_GAP * w)
                continue;
            plptex(x, y, 1, 0, 1.0, t);
            frame_segment(&f, x - 0.06 * w, y, x, y);
            last_x = x;
        } else {
            double x = r0 + 0.008 * w, y = ey + 0.05 * im;
            if (fabs(last_y - y) < 0.08 * im)
                continue;
            plptex(x, y, 1, 0, 0.0, t);
            frame_segment(&f, x, y, x + 0.06 * w, y);
            last_y = y;
            last_x = x + 0.06 * w;
        }
    }
    plschr(0, 1.0);
    plcol0(COL_GREY);
    plwidth(1.0);
    pljoin(r0, 0, r1, 0);
    plcol0(COL_FG);
    plwidth(1.8);
    pljoin(0, -im, 0, im);
    plschr(0, 0.85);
    plptex(0.5 * r1, -0.93 * im, 1, 0, 0.5, "unstable");
    frame_segment(&f, 0, -0.93 * im, r1, -0.93 * im);
    frame_segment(&f, 0, -im, 0, im);
    plschr(0, 1.0);
    legend L = {0};
    int outside = 0;
    for (int s = 0; s < c->nsets; s++) {
        const ts_plot_series *S = &c->sets[s];
        int col = color_index(S->color, s);
        plcol0(col);
        plschr(0, 1.1);
        draw_markers(&f, S->n, S->x, S->y, marker_glyph(s));
        plschr(0, 1.0);
        for (int i = 0; i < S->n; i++)
            outside += S->x[i] < r0 || S->x[i] > r1 || fabs(S->y[i]) > im;
        legend_add(&L, S->label, col, TS_PLOT_MARKERS, marker_glyph(s));
    }
    char xl[TEXT_MAX], yl[TEXT_MAX];
    axis_label(xl, sizeof xl, "real part σ", TS_PLOT_RATE, o);
    axis_label(yl, sizeof yl, "imaginary part ω", TS_PLOT_ANGULAR_RATE,
               o);
    label_axes(&f, xl, yl, 1.0);
    char text[160];
    if (outside)
        snprintf(text, sizeof text, "dashed: constant damping ratio ζ; %d "
                                    "eigenvalue%s outside the window",
                 outside, outside == 1 ? "" : "s");
    else
        snprintf(text, sizeof text, "dashed: constant damping ratio ζ");
    note(text);
    legend_draw(&L, &f);
    page_title(c->title);
    return TS_OK;
}

static int plot_eigenvalues(const char *dir, const char *name, const char *title,
                            int nsets, const ts_plot_series sets[],
                            const ts_plot_eig_window *win,
                            const ts_plot_opts *opts, ts_err *err)
{
    static const char fn[] = "ts_plot_eigenvalues";
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc || (rc = check_series(fn, nsets, sets, 0, 0, err)))
        return rc;
    eig_ctx c = {title, nsets, sets, {0, 0, 0}};
    if (win) {
        if (!isfinite(win->re_min) || win->re_min > 0 ||
            !isfinite(win->re_max) || win->re_max < 0 ||
            !isfinite(win->im_max) || win->im_max < 0)
            return ts_fail(err, TS_EINVAL,
                           "%s: win: expected re_min <= 0, re_max >= 0, "
                           "im_max >= 0 (0: automatic), got %g, %g, %g",
                           fn, win->re_min, win->re_max, win->im_max);
        c.win = *win;
    }
    return render(fn, dir, name, title, opts, opts->height, draw_eigenvalues,
                  &c, err);
}

/* ---- Bode ------------------------------------------------------------ */

typedef struct bode_ctx {
    const char *title, *mag_label;
    ts_plot_quantity out_q, in_q;
    int ncurves;
    const ts_plot_bode_curve *curves;
    int nnat;
    const double *nat;
} bode_ctx;

/* Character scale of the minor labels of a log axis. */
#define MINOR_SCALE 0.8

/* The minor labels v[n] (tsi_plot_minor_ticks) of the log axis [lo, hi]
 * (log10 units) of the current viewport: under the x axis (`x` 1) or left
 * of the y axis, at MINOR_SCALE. */
static void minor_labels(int x, double lo, double hi, const double *v, int n)
{
    plschr(0, MINOR_SCALE);
    plcol0(COL_FG);
    for (int k = 0; k < n; k++) {
        char t[32];
        snprintf(t, sizeof t, "%g", v[k]);
        if (x)
            plmtex("b", 1.6, (log10(v[k]) - lo) / (hi - lo), 0.5, t);
        else
            plmtex("lv", 0.7, (log10(v[k]) - lo) / (hi - lo), 1.0, t);
    }
    plschr(0, 1.0);
}

/* The width of the widest minor label v[n] of a y axis, in character
 * heights, or `width` when wider. */
static double minor_width(double width, const double *v, int n)
{
    for (int k = 0; k < n; k++) {
        char t[32];
        width = fmax(width, MINOR_SCALE * (snprintf(t, sizeof t, "%g", v[k]) +
                                           1) * DIGIT_WIDTH);
    }
    return width;
}
/* Rows and labels of the natural frequencies of a Bode plot. */
#define NAT_ROWS 4
#define NAT_LABELS_MAX 64

/* A magnitude as drawn: log10 |H| on the log axis, 20 log10 |H| in dB. */
static double mag_y(double m, int db)
{
    return db ? 20.0 * log10(m) : log10(m);
}

static int draw_bode(const void *vctx, const ts_plot_opts *o, int height,
                     ts_err *err)
{
    (void)height;
    const bode_ctx *c = vctx;
    const ts_plot_opts *u = o;
    int db = o->bode_db;
    double gain = pconv(c->out_q, u, 1.0) /
                  pconv(c->in_q, u, 1.0);
    int nmax = 0;
    for (int i = 0; i < c->ncurves; i++)
        if (c->curves[i].n > nmax)
            nmax = c->curves[i].n;
    double *lf = malloc(3 * (size_t)nmax * sizeof *lf);
    if (!lf)
        return ts_fail(err, TS_ENOMEM, "out of memory");
    double *lm = lf + nmax, *ph = lf + 2 * nmax;
    double f0 = INFINITY, f1 = -INFINITY, m0 = INFINITY, m1 = -INFINITY;
    double p0 = INFINITY, p1 = -INFINITY;
    for (int i = 0; i < c->ncurves; i++) {
        const ts_plot_bode_curve *C = &c->curves[i];
        double wrap = 0;
        for (int k = 0; k < C->n; k++) {
            bbox_update(&f0, &f1, log10(C->freq[k]));
            bbox_update(&m0, &m1, mag_y(gain * C->mag[k], db));
            /* Unwrap: consecutive phases differ by at most pi. */
            if (k > 0) {
                double d = C->phase[k] - C->phase[k - 1];
                wrap -= 2 * M_PI * floor((d + M_PI) / (2 * M_PI));
            }
            bbox_update(&p0, &p1, (C->phase[k] + wrap) * 180 / M_PI);
        }
    }
    pad_range(&f0, &f1, 0.0, 1.0);
    pad_range(&m0, &m1, 0.08, db ? 20.0 : 1.0);
    whole_decade(&f0, &f1);
    if (!db)
        whole_decade(&m0, &m1);
    pad_range(&p0, &p1, 0.08, 90.0);
    char xl[TEXT_MAX], ml[TEXT_MAX], raw[TEXT_MAX];
    axis_label(xl, sizeof xl, "frequency", TS_PLOT_FREQUENCY, u);
    snprintf(raw, sizeof raw, db ? "%s [dB re 1 %s/%s]" : "%s [%s/%s]",
             c->mag_label ? c->mag_label : "magnitude",
             punit(c->out_q, u), punit(c->in_q, u));
    pl_text(ml, sizeof ml, raw);
    /* Minor labels (2 and 5 times a power of ten) on short log axes. */
    double fminor[16], mminor[16];
    int nfm = tsi_plot_minor_ticks(f0, f1, fminor, 16);
    int nmm = db ? 0 : tsi_plot_minor_ticks(m0, m1, mminor, 16);
    double mwidth = minor_width(db ? tick_width(m0, m1, 0)
                                   : tick_width(m0, m1, 1),
                                mminor, nmm);
    int nlegend = 0, lchars = 0;
    for (int i = 0; i < c->ncurves; i++)
        legend_count(c->curves[i].label, &nlegend, &lchars);
    legend L = {0};
    double left = fmax(left_edge(mwidth, 1.0),
                       left_edge(tick_width(p0, p1, 0), 1.0));
    /* Natural-frequency labels in rows that do not overlap (about four
     * characters wide each, in log10 Hz). */
    int nat_row[NAT_LABELS_MAX];
    int nnat = c->nnat < NAT_LABELS_MAX ? c->nnat : NAT_LABELS_MAX;
    {
        double lx[NAT_LABELS_MAX];
        PLFLT sx0, sx1, sy0, sy1, def, ht;
        plgspa(&sx0, &sx1, &sy0, &sy1);
        plgchr(&def, &ht);
        double mm = (0.97 - left) * (sx1 - sx0) / (f1 - f0); /* per unit */
        double w = fmax(4.0 * 0.8 * DIGIT_WIDTH * def / mm,
                        0.035 * (f1 - f0));
        for (int j = 0; j < nnat; j++)
            lx[j] = log10(c->nat[j]);
        tsi_plot_label_rows(nnat, lx, w, NAT_ROWS, nat_row);
    }
    for (int panel = 0; panel < 2; panel++) {
        if (panel == 0)
            plvpor(left, 0.97, 0.52, 0.89);
        else
            plvpor(left, 0.97, 0.11, 0.46);
        frame f;
        if (panel == 0)
            frame_set(&f, f0, f1, m0, m1, nlegend, lchars);
        else
            frame_set(&f, f0, f1, p0, p1, 0, 0);
        /* Phase ticks at multiples of 90 or 45 degrees. */
        double ptick = p1 - p0 > 200 ? 90 : p1 - p0 > 60 ? 45 : 0;
        frame_axes(&f, panel ? "bcnstl" : "bcstl",
                   panel ? "bcnst" : db ? "bcnst" : "bcnstl",
                   panel ? ptick : 0);
        if (panel == 0)
            minor_labels(0, m0, m1, mminor, nmm);
        else
            minor_labels(1, f0, f1, fminor, nfm);
        /* Natural frequencies. */
        plwidth(1.2);
        for (int j = 0; j < c->nnat; j++) {
            double x = log10(c->nat[j]);
            if (x < f0 || x > f1)
                continue;
            int row = j < nnat ? nat_row[j] : -1;
            plcol0(COL_GREY);
            pllsty(LSTY_DOTTED);
            pljoin(x, panel ? p0 : m0, x, panel ? p1 : m1);
            pllsty(LSTY_SOLID);
            if (panel == 0 && row >= 0) {
                char t[32];
                snprintf(t, sizeof t, "f%d", j + 1);
                plschr(0, 0.8);
                plcol0(COL_FG);
                double y = m1 - (0.06 + 0.07 * row) * (m1 - m0);
                plptex(x, y, 1, 0, -0.15, t);
                frame_segment(&f, x, y, x + 0.03 * (f1 - f0), y);
                plschr(0, 1.0);
            }
        }
        for (int i = 0; i < c->ncurves; i++) {
            const ts_plot_bode_curve *C = &c->curves[i];
            double wrap = 0;
            for (int k = 0; k < C->n; k++) {
                lf[k] = log10(C->freq[k]);
                lm[k] = mag_y(gain * C->mag[k], db);
                if (k > 0) {
                    double d = C->phase[k] - C->phase[k - 1];
                    wrap -= 2 * M_PI * floor((d + M_PI) / (2 * M_PI));
                }
                ph[k] = (C->phase[k] + wrap) * 180 / M_PI;
            }
            ts_plot_series s = {C->n, lf, panel ? ph : lm, C->label, 0,
                                C->style, C->color, NULL};
            int col = color_index(C->color, i);
            draw_series(&f, &s, col, i, lf, panel ? ph : lm);
            if (panel == 0)
                legend_add(&L, C->label, col, C->style, marker_glyph(i));
        }
        if (panel == 0) {
            label_axes(&f, NULL, ml, 1.0);
            if (c->nnat > 0)
                note("dotted: natural frequencies f1, f2, ... (labels "
                     "that would overlap are staggered or left out)");
            legend_draw(&L, &f);
        } else {
            char pl[TEXT_MAX];
            axis_label(pl, sizeof pl, "phase", TS_PLOT_ANGLE, u);
            label_axes(&f, xl, pl, 1.0);
        }
    }
    page_title(c->title);
    free(lf);
    return TS_OK;
}

static int plot_bode(const char *dir, const char *name, const char *title,
                     const char *mag_label, ts_plot_quantity out_q,
                     ts_plot_quantity in_q, int ncurves,
                     const ts_plot_bode_curve curves[], int nnat,
                     const double natural_hz[], const ts_plot_opts *opts,
                     ts_err *err)
{
    static const char fn[] = "ts_plot_bode";
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc || (rc = check_quantity(fn, "out_q", out_q, err)) ||
        (rc = check_quantity(fn, "in_q", in_q, err)))
        return rc;
    if ((rc = check_list(fn, "curve", curves, ncurves, err)))
        return rc;
    for (int i = 0; i < ncurves; i++) {
        const ts_plot_bode_curve *C = &curves[i];
        if ((rc = check_points(fn, "curves", i, C->n, 2, err)) ||
            (rc = check_array(fn, "freq", i, C->freq, C->n, 1, err)) ||
            (rc = check_array(fn, "mag", i, C->mag, C->n, 1, err)) ||
            (rc = check_array(fn, "phase", i, C->phase, C->n, 0, err)))
            return rc;
        for (int k = 1; k < C->n; k++)
            if (!(C->freq[k] > C->freq[k - 1]))
                return ts_fail(err, TS_EINVAL,
                               "%s: curves[%d].freq[%d]: must increase, got "
                               "%g Hz after %g Hz",
                               fn, i, k, C->freq[k], C->freq[k - 1]);
        if (C->style < TS_PLOT_SOLID || C->style > TS_PLOT_LINE_MARKERS)
            return ts_fail(err, TS_EINVAL, "%s: curves[%d].style: unknown "
                                           "style %d",
                           fn, i, C->style);
    }
    if (nnat < 0 || (nnat > 0 &&
                     (rc = check_array(fn, "natural_hz", 0, natural_hz, nnat,
                                       1, err))))
        return rc ? rc
                  : ts_fail(err, TS_EINVAL, "%s: nnat: must be >= 0, got %d",
                            fn, nnat);
    bode_ctx c = {title,   mag_label, out_q, in_q, ncurves,
                  curves,  nnat,      natural_hz};
    return render(fn, dir, name, title, opts, opts->height, draw_bode, &c,
                  err);
}

/* ---- mode animation (hand-written SVG) --------------------------------- */

#define ANIM_LEFT 95.0
#define ANIM_RIGHT 30.0
#define ANIM_TOP 80.0
#define ANIM_BOTTOM 70.0

/* A step of about span / 5 of 1, 2 or 5 times a power of ten. */
static double nice_step(double span)
{
    double p = pow(10.0, floor(log10(span / 5.0)));
    double r = span / 5.0 / p;
    return p * (r < 1.5 ? 1.0 : r < 3.5 ? 2.0 : r < 7.5 ? 5.0 : 10.0);
}

typedef struct anim_map {
    double h0, h1, v0, v1;     /* window, display units */
    double x0, x1, y0, y1;     /* plot box, px */
} anim_map;

static double anim_x(const anim_map *m, double h)
{
    return m->x0 + (h - m->h0) / (m->h1 - m->h0) * (m->x1 - m->x0);
}

/* Depth and starboard both grow down the page. */
static double anim_y(const anim_map *m, double v)
{
    return m->y0 + (v - m->v0) / (m->v1 - m->v0) * (m->y1 - m->y0);
}

/* The links of a shape at xy as SVG path data ("M x y L x y ..."). */
static void anim_path(FILE *f, const ts_plot_shape *s, const shape_xy *xy,
                      const anim_map *m)
{
    for (int k = 0; k + 1 < s->nnodes; k++) {
        int a = s->link_upper ? s->link_upper[k] : k, b = k + 1;
        if (k == 0 || a != k)
            fprintf(f, "%sM%.2f %.2f", k ? " " : "", anim_x(m, xy->h[a]),
                    anim_y(m, xy->v[a]));
        fprintf(f, " L%.2f %.2f", anim_x(m, xy->h[b]), anim_y(m, xy->v[b]));
    }
}

static void anim_text(FILE *f, double x, double y, const char *anchor,
                      double size, const char *text)
{
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"%s\" "
               "font-family=\"sans-serif\" font-size=\"%.0f\">",
            x, y, anchor, size);
    xml_escape(f, text);
    fputs("</text>\n", f);
}

/* The checks of a mode's cycle (ts_plot_mode_animation, _frames). */
static int check_mode_cycle(const char *fn, const ts_plot_shape *eq,
                            const double *re, const double *im,
                            const double *ore, const double *oim,
                            int nframes, ts_err *err)
{
    int rc;
    if (!eq || !re || !im)
        return ts_fail(err, TS_EINVAL, "%s: eq, re and im: expected a shape "
                                       "and two displacement arrays",
                       fn);
    if ((rc = check_shape(fn, "eq", 0, eq, err)) ||
        (rc = check_array(fn, "re", 0, re, 3 * eq->nnodes, 0, err)) ||
        (rc = check_array(fn, "im", 0, im, 3 * eq->nnodes, 0, err)))
        return rc;
    if (!ore != !oim)
        return ts_fail(err, TS_EINVAL, "%s: outline_re and outline_im: "
                                       "expected both or neither",
                       fn);
    if (ore && eq->noutlines > 0 &&
        ((rc = check_array(fn, "outline_re", 0, ore, 6 * eq->noutlines, 0,
                           err)) ||
         (rc = check_array(fn, "outline_im", 0, oim, 6 * eq->noutlines, 0,
                           err))))
        return rc;
    if (nframes < 4 || nframes > TS_PLOT_MAX_FRAMES)
        return ts_fail(err, TS_EINVAL, "%s: nframes: must be in [4, %d], got "
                                       "%d",
                       fn, TS_PLOT_MAX_FRAMES, nframes);
    return TS_OK;
}

/* One cycle of a mode in a view (mode_cycle). */
typedef struct mode_cyc {
    shape_xy base;      /* the equilibrium's coordinates */
    shape_xy *frames;   /* [nframes], phase 2 pi k / nframes */
    int nframes;
    double scale;       /* the mode's scale: m of displacement (and rad of
                           rotation) per unit of re, im */
    double oscale;      /* the outlines' magnification (outline_scale) */
    double *motion;     /* [nframes][6 noutlines]: each outline's motion
                           per unit of the mode at each frame's phase;
                           NULL: the outlines stay at the trim */
    double lo[2], hi[2]; /* the padded window holding it all */
    double extent;      /* the equilibrium's, in the axes' unit */
} mode_cyc;

/* Widen lo[2], hi[2] to hold the outlines of eq in `view`, moved by
 * motion ([6 noutlines] or NULL) at scale s, magnified by mag. */
static void outline_bbox(const ts_plot_shape *eq, const double *motion,
                         double s, double mag, ts_plot_view view,
                         const ts_plot_opts *u, double lo[2], double hi[2])
{
    for (int b = 0; b < eq->noutlines; b++) {
        const ts_plot_outline *o = &eq->outlines[b];
        for (int k = 0; k < o->npoints; k++) {
            const double *p = o->pts + 3 * (size_t)k;
            if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
                continue;
            double q[3];
            tsi_plot_outline_point(o->anchor, motion ? motion + 6 * b : NULL, s, mag,
                          p, q);
            bbox_update(&lo[0], &hi[0], pconv(TS_PLOT_LENGTH, u, q[0]));
            bbox_update(&lo[1], &hi[1],
                        pconv(TS_PLOT_LENGTH, u,
                              view == TS_PLOT_TOP ? q[1] : q[2]));
        }
    }
}

/* One cycle of a mode in `view` (*c): the equilibrium's coordinates and
 * nframes frames at phases 2 pi k / nframes, eq + s Re((re + i im)
 * e^{i phi}), s making the largest node amplitude 15 % of the
 * equilibrium's extent; with ore, oim ([6 noutlines] each) each outline's
 * motion Re((ore + i oim) e^{i phi}) at every frame, drawn at the same s;
 * the padded window holding it all, outlines included (with the water
 * surface in a side view with TS_PLOT_WATER). TS_OK or TS_ENOMEM; release
 * with mode_cycle_free. */
static int mode_cycle(const ts_plot_shape *eq, const double *re,
                      const double *im, const double *ore, const double *oim,
                      ts_plot_view view, int flags, int nframes,
                      const ts_plot_opts *opts, mode_cyc *cy)
{
    int n = eq->nnodes, rc;
    double *lo = cy->lo, *hi = cy->hi;
    memset(cy, 0, sizeof *cy);
    cy->nframes = nframes;
    /* Scale: the largest node displacement over the cycle (|v| per node)
     * is 15 % of the equilibrium's extent. */
    if ((rc = shape_coords(eq, NULL, 0, view, opts, &cy->base)))
        return TS_ENOMEM;
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    double amax = 0;
    for (int k = 0; k < n; k++) {
        bbox_update(&lo[0], &hi[0], cy->base.h[k]);
        bbox_update(&lo[1], &hi[1], cy->base.v[k]);
        double a = 0;
        for (int j = 0; j < 3; j++)
            a += re[3 * k + j] * re[3 * k + j] + im[3 * k + j] * im[3 * k + j];
        amax = fmax(amax, sqrt(a));
    }
    cy->extent = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(cy->extent > 0))
        cy->extent = pconv(TS_PLOT_LENGTH, opts, 1.0);
    double unit = pconv(TS_PLOT_LENGTH, opts, 1.0);
    cy->scale = amax > 0 ? 0.15 * cy->extent / unit / amax : 0;
    /* The outlines magnified as in ts_plot_mode_shapes (extent in m). */
    cy->oscale = outline_scale(1, eq, cy->extent / unit);
    outline_bbox(eq, NULL, 0, cy->oscale, view, opts, lo, hi);
    int no = eq->noutlines;
    if (ore && no > 0) {
        cy->motion = malloc((size_t)nframes * 6 * (size_t)no *
                            sizeof *cy->motion);
        if (!cy->motion)
            rc = TS_ENOMEM;
    }
    /* The frames, phase 2 pi k / nframes: eq + scale Re(v e^{i phi}). */
    shape_xy *fr = calloc((size_t)nframes, sizeof *fr);
    double *d = malloc(3 * (size_t)n * sizeof *d);
    for (int i = 0; fr && d && rc == TS_OK && i < nframes; i++) {
        double ph = 2 * M_PI * i / nframes, c = cos(ph), s = sin(ph);
        for (int j = 0; j < 3 * n; j++)
            d[j] = re[j] * c - im[j] * s;
        rc = shape_coords(eq, d, cy->scale, view, opts, &fr[i]);
        for (int k = 0; rc == TS_OK && k < n; k++) {
            bbox_update(&lo[0], &hi[0], fr[i].h[k]);
            bbox_update(&lo[1], &hi[1], fr[i].v[k]);
        }
        if (cy->motion) {
            double *m = cy->motion + (size_t)i * 6 * (size_t)no;
            for (int b = 0; b < no; b++)
                tsi_plot_outline_phase_motion(ore + 6 * b, oim + 6 * b, ph,
                                     m + 6 * b);
            outline_bbox(eq, m, cy->scale, cy->oscale, view, opts, lo, hi);
        }
    }
    if (!fr || !d)
        rc = TS_ENOMEM;
    free(d);
    cy->frames = fr;
    if ((flags & TS_PLOT_WATER) && view == TS_PLOT_SIDE)
        bbox_update(&lo[1], &hi[1], 0);
    pad_range(&lo[0], &hi[0], 0.06, 1.0);
    pad_range(&lo[1], &hi[1], 0.06, 1.0);
    return rc == TS_OK ? TS_OK : TS_ENOMEM;
}

static void mode_cycle_free(mode_cyc *cy)
{
    for (int i = 0; cy->frames && i < cy->nframes; i++)
        free(cy->frames[i].h);
    free(cy->frames);
    free(cy->base.h);
    free(cy->motion);
    memset(cy, 0, sizeof *cy);
}

/* Outline o moved by motion ([6] or NULL) at scale s, magnified by mag,
 * as SVG path data: a move at the start and after each pen lift. */
static void anim_outline(FILE *f, const ts_plot_outline *o,
                         const double *motion, double s, double mag,
                         ts_plot_view view, const ts_plot_opts *u,
                         const anim_map *m)
{
    int pen = 0, first = 1;
    for (int k = 0; k < o->npoints; k++) {
        const double *p = o->pts + 3 * (size_t)k;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) {
            pen = 0;
            continue;
        }
        double q[3];
        tsi_plot_outline_point(o->anchor, motion, s, mag, p, q);
        double h = pconv(TS_PLOT_LENGTH, u, q[0]);
        double v = pconv(TS_PLOT_LENGTH, u, view == TS_PLOT_TOP ? q[1] : q[2]);
        fprintf(f, "%s%c%.2f %.2f", first ? "" : " ", pen ? 'L' : 'M',
                anim_x(m, h), anim_y(m, v));
        pen = 1;
        first = 0;
    }
}

static int plot_mode_animation(const char *dir, const char *name,
                               const char *title, ts_plot_view view, int flags,
                               const ts_plot_shape *eq, const double *re,
                               const double *im, const double *outline_re,
                               const double *outline_im, const char *label,
                               int nframes, double seconds,
                               const ts_plot_opts *opts, ts_err *err)
{
    static const char fn[] = "ts_plot_mode_animation";
    ts_plot_opts def;
    int rc = begin_view(fn, dir, name, title, &opts, &def, view, err);
    if (rc)
        return rc;
    if ((rc = check_mode_cycle(fn, eq, re, im, outline_re, outline_im,
                               nframes, err)))
        return rc;
    if (!(seconds > 0) || !isfinite(seconds))
        return ts_fail(err, TS_EINVAL, "%s: seconds: must be > 0, got %g",
                       fn, seconds);
    mode_cyc cy;
    rc = mode_cycle(eq, re, im, outline_re, outline_im, view, flags, nframes,
                    opts, &cy);
    const double *lo = cy.lo, *hi = cy.hi;
    int water = (flags & TS_PLOT_WATER) && view == TS_PLOT_SIDE;
    anim_map m = {lo[0], hi[0], lo[1], hi[1], ANIM_LEFT,
                  opts->width - ANIM_RIGHT, ANIM_TOP,
                  opts->height - ANIM_BOTTOM};
    if (view == TS_PLOT_TOP) {
        /* Equal scales: widen the shorter range to the box's aspect. */
        double sx = (hi[0] - lo[0]) / (m.x1 - m.x0);
        double sy = (hi[1] - lo[1]) / (m.y1 - m.y0);
        double s = fmax(sx, sy), ch = 0.5 * (lo[0] + hi[0]),
               cv = 0.5 * (lo[1] + hi[1]);
        m.h0 = ch - 0.5 * s * (m.x1 - m.x0);
        m.h1 = ch + 0.5 * s * (m.x1 - m.x0);
        m.v0 = cv - 0.5 * s * (m.y1 - m.y0);
        m.v1 = cv + 0.5 * s * (m.y1 - m.y0);
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.svg", dir, name);
    tsi_outfile out;
    if (rc == TS_OK)
        rc = tsi_outfile_open(&out, path, err);
    else
        ts_fail(err, rc, "%s: out of memory", fn);
    if (rc == TS_OK) {
        FILE *f = out.f;
        int W = opts->width, H = opts->height;
        fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                   "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%dpt\" "
                   "height=\"%dpt\" viewBox=\"0 0 %d %d\">\n<title>",
                W, H, W, H);
        xml_escape(f, title);
        fprintf(f, "</title>\n<rect width=\"%d\" height=\"%d\" "
                   "fill=\"white\"/>\n", W, H);
        if (water && m.v1 > 0) {
            double yw = anim_y(&m, fmax(0, m.v0));
            fprintf(f, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" "
                       "height=\"%.2f\" fill=\"rgb(222,236,250)\"/>\n"
                       "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" "
                       "stroke=\"rgb(50,110,190)\"/>\n",
                    m.x0, yw, m.x1 - m.x0, m.y1 - yw, m.x0, yw, m.x1, yw);
        }
        /* Grid, ticks and their labels. */
        char t[64];
        for (int a = 0; a < 2; a++) {
            double a0 = a ? m.v0 : m.h0, a1 = a ? m.v1 : m.h1;
            double st = nice_step(a1 - a0);
            for (double v = ceil(a0 / st) * st; v <= a1 + 1e-9 * st;
                 v += st) {
                double p = a ? anim_y(&m, v) : anim_x(&m, v);
                snprintf(t, sizeof t, "%g", fabs(v) < 1e-9 * st ? 0.0 : v);
                if (a)
                    fprintf(f, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" "
                               "y2=\"%.2f\" stroke=\"rgb(222,222,222)\"/>\n",
                            m.x0, p, m.x1, p);
                else
                    fprintf(f, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" "
                               "y2=\"%.2f\" stroke=\"rgb(222,222,222)\"/>\n",
                            p, m.y0, p, m.y1);
                if (a)
                    anim_text(f, m.x0 - 8, p + 5, "end", 16, t);
                else
                    anim_text(f, p, m.y1 + 22, "middle", 16, t);
            }
        }
        fprintf(f, "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" "
                   "height=\"%.2f\" fill=\"none\" stroke=\"black\"/>\n",
                m.x0, m.y0, m.x1 - m.x0, m.y1 - m.y0);
        char axis[TEXT_MAX];
        snprintf(axis, sizeof axis, "x, forward [%s]",
                 punit(TS_PLOT_LENGTH, opts));
        anim_text(f, 0.5 * (m.x0 + m.x1), H - 18, "middle", 18, axis);
        snprintf(axis, sizeof axis, "%s [%s]",
                 view == TS_PLOT_TOP ? "y, starboard" : "z, depth",
                 punit(TS_PLOT_LENGTH, opts));
        fprintf(f, "<g transform=\"translate(24,%.1f) rotate(-90)\">",
                0.5 * (m.y0 + m.y1));
        anim_text(f, 0, 0, "middle", 18, axis);
        fputs("</g>\n", f);
        anim_text(f, 0.5 * W, 32, "middle", 22, title);
        if (label)
            anim_text(f, m.x0, ANIM_TOP - 12, "start", 17, label);
        /* The equilibrium (grey), then the mode's cycle. */
        fputs("<path fill=\"none\" stroke=\"rgb(140,140,140)\" "
              "stroke-width=\"1.6\" d=\"", f);
        anim_path(f, eq, &cy.base, &m);
        fputs("\"/>\n<path fill=\"none\" stroke=\"rgb(0,114,178)\" "
              "stroke-width=\"2.2\" d=\"", f);
        anim_path(f, eq, &cy.frames[0], &m);
        fprintf(f, "\">\n<animate attributeName=\"d\" dur=\"%gs\" "
                   "repeatCount=\"indefinite\" values=\"",
                seconds);
        for (int i = 0; i <= nframes; i++) {
            anim_path(f, eq, &cy.frames[i % nframes], &m);
            fputs(i < nframes ? ";" : "", f);
        }
        fputs("\"/>\n</path>\n", f);
        /* The vehicles: grey at their trim; with the mode's motion, each
         * moved and rotated at every frame's phase (one <animate> of its
         * outline's path, the same geometry as ts_plot_mode_shapes). */
        for (int b = 0; b < eq->noutlines; b++) {
            const ts_plot_outline *o = &eq->outlines[b];
            fprintf(f, "<path class=\"vehicle-trim\" fill=\"none\" "
                       "stroke=\"rgb(140,140,140)\" stroke-width=\"1.2\" "
                       "d=\"");
            anim_outline(f, o, NULL, 0, cy.oscale, view, opts, &m);
            fputs("\"/>\n", f);
            if (!cy.motion)
                continue;
            size_t per = 6 * (size_t)eq->noutlines;
            fprintf(f, "<path class=\"vehicle\" fill=\"none\" "
                       "stroke=\"rgb(0,114,178)\" stroke-width=\"1.6\" "
                       "d=\"");
            anim_outline(f, o, cy.motion + 6 * b, cy.scale, cy.oscale, view,
                         opts, &m);
            fprintf(f, "\">\n<animate attributeName=\"d\" dur=\"%gs\" "
                       "repeatCount=\"indefinite\" values=\"",
                    seconds);
            for (int i = 0; i <= nframes; i++) {
                anim_outline(f, o, cy.motion + (size_t)(i % nframes) * per +
                                       6 * b,
                             cy.scale, cy.oscale, view, opts, &m);
                fputs(i < nframes ? ";" : "", f);
            }
            fputs("\"/>\n</path>\n", f);
        }
        if (eq->noutlines > 0 && cy.oscale > 1.0) {
            char note[TEXT_MAX];
            snprintf(note, sizeof note, "vehicles drawn %.3g times their "
                     "size", cy.oscale);
            anim_text(f, m.x1, ANIM_TOP - 12, "end", 15, note);
        }
        fputs("</svg>\n", f);
        rc = ferror(f) ? ts_fail(err, TS_EIO, "%s: write failed", path)
                       : TS_OK;
        if (rc == TS_OK)
            rc = tsi_outfile_commit(&out, err);
        else
            tsi_outfile_abandon(&out);
    }
    mode_cycle_free(&cy);
    return rc;
}

/* ---- a mode as a PNG frame sequence ------------------------------------ */

typedef struct mframe_ctx {
    const char *title, *label;
    ts_plot_view view;
    int water;
    const ts_plot_shape *eq;
    const mode_cyc *cy;  /* the cycle, its window the same in every frame */
    int k;               /* the frame drawn */
} mframe_ctx;

static int draw_mode_frame(const void *vctx, const ts_plot_opts *o,
                           int height, ts_err *err)
{
    (void)height;
    const mframe_ctx *c = vctx;
    const mode_cyc *cy = c->cy;
    const shape_xy *base = &cy->base, *cur = &cy->frames[c->k];
    double extent = cy->extent; /* the equilibrium's, for the cylinders */
    int top = c->view == TS_PLOT_TOP;
    double *work = malloc(4 * ((size_t)c->eq->nnodes + 1) * sizeof *work);
    if (!work)
        return ts_fail(err, TS_ENOMEM, "out of memory");
    double h0 = cy->lo[0], h1 = cy->hi[0], v0 = cy->lo[1], v1 = cy->hi[1];
    plvpor(left_edge(tick_width(v0, v1, 0), 1.0), 0.97, 0.11, 0.85);
    if (top)
        equalize(&h0, &h1, &v0, &v1);
    frame f;
    /* Depth and starboard grow downward. */
    frame_set(&f, h0, h1, v1, v0, 0, 0);
    if (c->water)
        draw_water(&f, h0, h1, v1, o);
    frame_axes(&f, "bcnst", "bcnst", 0);
    ts_plot_shape solid = *c->eq;
    solid.style = TS_PLOT_SOLID;
    plcol0(COL_GREY);
    plwidth(1.6);
    draw_shape_links(&f, &solid, base, c->water, work);
    draw_cylinders(&f, c->eq, base, o, CYL_MIN * extent, COL_GREY);
    plwidth(1.6);
    draw_marks(&f, c->eq, base, 0.9);
    plcol0(COL_GREY);
    plwidth(1.2);
    draw_outlines(&f, c->eq, top, cy->oscale, NULL, 0.0, o);
    int col = color_index(0, 0);
    plcol0(col);
    plwidth(CURVE_WIDTH);
    draw_shape_links(&f, &solid, cur, c->water, work);
    draw_cylinders(&f, c->eq, cur, o, CYL_MIN * extent, col);
    plwidth(CURVE_WIDTH);
    draw_marks(&f, c->eq, cur, 1.1);
    /* The vehicles moved and rotated at this frame's phase. */
    if (cy->motion) {
        plcol0(col);
        plwidth(1.6);
        draw_outlines(&f, c->eq, top, cy->oscale,
                      cy->motion + (size_t)c->k * 6 * c->eq->noutlines,
                      cy->scale, o);
    }
    char xl[TEXT_MAX], yl[TEXT_MAX];
    axis_label(xl, sizeof xl, "x, forward", TS_PLOT_LENGTH, o);
    axis_label(yl, sizeof yl, top ? "y, starboard" : "z, depth",
               TS_PLOT_LENGTH, o);
    label_axes(&f, xl, yl, 1.0);
    if (c->label) {
        char t[TEXT_MAX];
        pl_text(t, sizeof t, c->label);
        plcol0(col);
        plmtex("t", 0.6, 0.0, 0.0, t);
    }
    if (c->eq->noutlines > 0 && cy->oscale > 1.0) {
        char t[TEXT_MAX];
        snprintf(t, sizeof t, "vehicles drawn %.3g times their size",
                 cy->oscale);
        plcol0(COL_FG);
        plschr(0, 0.8);
        plmtex("t", 2.4, 1.0, 1.0, t);
        plschr(0, 1.0);
    }
    page_title(c->title);
    free(work);
    return TS_OK;
}

static int plot_mode_frames(const char *dir, const char *name, const char *title,
                            ts_plot_view view, int flags, const ts_plot_shape *eq,
                            const double *re, const double *im,
                            const double *outline_re, const double *outline_im,
                            const char *label, int nframes,
                            const ts_plot_opts *opts, ts_err *err)
{
    static const char fn[] = "ts_plot_mode_frames";
    ts_plot_opts def;
    int rc = begin_view(fn, dir, name, title, &opts, &def, view, err);
    if (rc)
        return rc;
    if ((rc = check_mode_cycle(fn, eq, re, im, outline_re, outline_im,
                               nframes, err)))
        return rc;
    /* NAME_kkk must stay a valid name. */
    if (strlen(name) + 4 > 200)
        return ts_fail(err, TS_EINVAL, "%s: name: at most 196 characters "
                                       "(frames add _kkk), got %zu",
                       fn, strlen(name));
    mode_cyc cy;
    mframe_ctx c = {title, label, view, 0, eq, &cy, 0};
    rc = mode_cycle(eq, re, im, outline_re, outline_im, view, flags, nframes,
                    opts, &cy);
    if (rc)
        ts_fail(err, rc, "%s: out of memory", fn);
    c.water = (flags & TS_PLOT_WATER) && view == TS_PLOT_SIDE;
    ts_plot_opts po = *opts;
    po.formats = TS_PLOT_PNG;
    for (int i = 0; rc == TS_OK && i < nframes; i++) {
        char fname[256], ftitle[TEXT_MAX];
        snprintf(fname, sizeof fname, "%s_%03d", name, i);
        snprintf(ftitle, sizeof ftitle, "%s (frame %d of %d, phase %.0f "
                 "deg)", title, i + 1, nframes, 360.0 * i / nframes);
        c.k = i;
        c.title = ftitle;
        rc = render(fn, dir, fname, ftitle, &po, po.height, draw_mode_frame,
                    &c, err);
    }
    mode_cycle_free(&cy);
    return rc;
}

/* ---- histories ------------------------------------------------------- */

#define MAX_PANELS 6

typedef struct hist_ctx {
    const char *title;
    int npanels;
    const ts_plot_axis *panels;
    int nseries;
    const ts_plot_series *series;
    const ts_plot_axis *xaxis; /* NULL: time */
} hist_ctx;

static int draw_histories(const void *vctx, const ts_plot_opts *o,
                          int height, ts_err *err)
{
    (void)height;
    const hist_ctx *c = vctx;
    const ts_plot_opts *u = o;
    int nmax = 0;
    for (int i = 0; i < c->nseries; i++)
        if (c->series[i].n > nmax)
            nmax = c->series[i].n;
    double *yv = malloc((size_t)nmax * sizeof *yv);
    if (!yv)
        return ts_fail(err, TS_ENOMEM, "out of memory");
    ts_plot_axis time = {"time t", TS_PLOT_TIME, NULL};
    const ts_plot_axis *xa = c->xaxis ? c->xaxis : &time;
    double *xv = malloc((size_t)nmax * sizeof *xv);
    if (!xv) {
        free(yv);
        return ts_fail(err, TS_ENOMEM, "out of memory");
    }
    double t0 = INFINITY, t1 = -INFINITY;
    for (int i = 0; i < c->nseries; i++)
        for (int k = 0; k < c->series[i].n; k++)
            bbox_update(&t0, &t1, pconv(xa->quantity, u,
                                                  c->series[i].x[k]));
    pad_range(&t0, &t1, c->xaxis ? 0.03 : 0.0, 1.0);
    double gap = 0.035, top = 0.89, bottom = 0.11;
    double ph = (top - bottom - gap * (c->npanels - 1)) / c->npanels;
    double cs = c->npanels > 2 ? 0.85 : 1.0;
    /* The panels' windows first: the widest tick labels of any panel set
     * the common left edge. */
    double lo[MAX_PANELS], hi[MAX_PANELS], left = LEFT_MIN;
    for (int p = 0; p < c->npanels; p++) {
        ts_plot_quantity q = c->panels[p].quantity;
        lo[p] = INFINITY;
        hi[p] = -INFINITY;
        for (int i = 0; i < c->nseries; i++)
            for (int k = 0; c->series[i].panel == p && k < c->series[i].n;
                 k++)
                bbox_update(&lo[p], &hi[p],
                            pconv(q, u, c->series[i].y[k]));
        /* A constant series gets a window of 10 % of its value (1 when
         * it is 0). */
        pad_range(&lo[p], &hi[p], 0.08, lo[p] != 0 ? 0.1 * fabs(lo[p]) : 1.0);
        left = fmax(left, left_edge(tick_width(lo[p], hi[p], 0), cs));
    }
    plschr(0, cs);
    for (int p = 0; p < c->npanels; p++) {
        ts_plot_quantity q = c->panels[p].quantity;
        double v0 = lo[p], v1 = hi[p];
        int nlegend = 0, lchars = 0;
        for (int i = 0; i < c->nseries; i++)
            if (c->series[i].panel == p)
                legend_count(c->series[i].label, &nlegend, &lchars);
        double y1 = top - p * (ph + gap);
        plvpor(left, 0.97, y1 - ph, y1);
        int last = p == c->npanels - 1;
        plschr(0, cs);
        frame f;
        frame_set(&f, t0, t1, v0, v1, nlegend, lchars);
        /* Time histories fill the width: make room for the legend above
         * the data instead of covering it. */
        if (nlegend > 0 && f.corner_h < 0.6) {
            v1 += f.corner_h / (1 - f.corner_h) * (v1 - v0);
            frame_set(&f, t0, t1, v0, v1, nlegend, lchars);
        }
        frame_axes(&f, last ? "bcnst" : "bcst", "bcnst", 0);
        legend L = {0};
        int ord = 0;
        for (int i = 0; i < c->nseries; i++) {
            const ts_plot_series *S = &c->series[i];
            if (S->panel != p)
                continue;
            for (int k = 0; k < S->n; k++) {
                xv[k] = pconv(xa->quantity, u, S->x[k]);
                yv[k] = pconv(q, u, S->y[k]);
            }
            int col = color_index(S->color, ord);
            draw_series(&f, S, col, ord, xv, yv);
            legend_add(&L, S->label, col, S->style, marker_glyph(ord));
            ord++;
        }
        char yl[TEXT_MAX], xl[TEXT_MAX];
        axis_label_of(yl, sizeof yl, &c->panels[p], u);
        axis_label_of(xl, sizeof xl, xa, u);
        label_axes(&f, last ? xl : NULL, yl, cs);
        plschr(0, 1.0);
        legend_draw(&L, &f);
    }
    page_title(c->title);
    free(yv);
    free(xv);
    return TS_OK;
}

static int panels_common(const char *fn, const char *dir, const char *name,
                         const char *title, const ts_plot_axis *xaxis,
                         int npanels, const ts_plot_axis panels[],
                         int nseries, const ts_plot_series series[],
                         const ts_plot_opts *opts, ts_err *err);

static int plot_histories(const char *dir, const char *name, const char *title,
                          int npanels, const ts_plot_axis panels[], int nseries,
                          const ts_plot_series series[], const ts_plot_opts *opts,
                          ts_err *err)
{
    return panels_common("ts_plot_histories", dir, name, title, NULL,
                         npanels, panels, nseries, series, opts, err);
}

static int plot_panels(const char *dir, const char *name, const char *title,
                       const ts_plot_axis *xaxis, int npanels,
                       const ts_plot_axis panels[], int nseries,
                       const ts_plot_series series[], const ts_plot_opts *opts,
                       ts_err *err)
{
    if (!xaxis)
        return ts_fail(err, TS_EINVAL, "ts_plot_panels: xaxis: expected an "
                       "axis, got NULL");
    int rc = check_quantity("ts_plot_panels", "xaxis.quantity",
                            xaxis->quantity, err);
    return rc ? rc : panels_common("ts_plot_panels", dir, name, title, xaxis,
                                   npanels, panels, nseries, series, opts,
                                   err);
}

static int panels_common(const char *fn, const char *dir, const char *name,
                         const char *title, const ts_plot_axis *xaxis,
                         int npanels, const ts_plot_axis panels[],
                         int nseries, const ts_plot_series series[],
                         const ts_plot_opts *opts, ts_err *err)
{
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc || (rc = check_series(fn, nseries, series, 0, 0, err)))
        return rc;
    if (npanels < 1 || npanels > MAX_PANELS || !panels)
        return ts_fail(err, TS_EINVAL, "%s: npanels: expected 1..%d panels, "
                                       "got %d",
                       fn, MAX_PANELS, npanels);
    int used[MAX_PANELS] = {0};
    for (int p = 0; p < npanels; p++)
        if ((rc = check_quantity(fn, "panels.quantity", panels[p].quantity,
                                 err)))
            return rc;
    for (int i = 0; i < nseries; i++) {
        if (series[i].panel < 0 || series[i].panel >= npanels)
            return ts_fail(err, TS_EINVAL,
                           "%s: series[%d].panel: must be in [0, %d), got %d",
                           fn, i, npanels, series[i].panel);
        used[series[i].panel] = 1;
    }
    for (int p = 0; p < npanels; p++)
        if (!used[p])
            return ts_fail(err, TS_EINVAL, "%s: panels[%d]: no series is "
                                           "drawn in it",
                           fn, p);
    hist_ctx c = {title, npanels, panels, nseries, series, xaxis};
    return render(fn, dir, name, title, opts, opts->height, draw_histories,
                  &c, err);
}

/* ---- log-log --------------------------------------------------------- */

typedef struct loglog_ctx {
    const char *title;
    const ts_plot_axis *xa, *ya;
    int nseries;
    const ts_plot_series *series;
} loglog_ctx;

static int draw_loglog(const void *vctx, const ts_plot_opts *o, int height,
                       ts_err *err)
{
    (void)height;
    const loglog_ctx *c = vctx;
    const ts_plot_opts *u = o;
    int nmax = 0, nlegend = 0, lchars = 0;
    for (int i = 0; i < c->nseries; i++) {
        if (c->series[i].n > nmax)
            nmax = c->series[i].n;
        legend_count(c->series[i].label, &nlegend, &lchars);
    }
    double *lx = malloc(2 * (size_t)nmax * sizeof *lx);
    if (!lx)
        return ts_fail(err, TS_ENOMEM, "out of memory");
    double *ly = lx + nmax;
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int i = 0; i < c->nseries; i++)
        for (int k = 0; k < c->series[i].n; k++) {
            bbox_update(&x0, &x1, log10(pconv(c->xa->quantity, u,
                                                        c->series[i].x[k])));
            bbox_update(&y0, &y1, log10(pconv(c->ya->quantity, u,
                                                        c->series[i].y[k])));
        }
    pad_range(&x0, &x1, 0.06, 1.0);
    pad_range(&y0, &y1, 0.06, 1.0);
    whole_decade(&x0, &x1);
    whole_decade(&y0, &y1);
    /* Minor labels (2 and 5 times a power of ten) on short axes. */
    double xminor[16], yminor[16];
    int nxm = tsi_plot_minor_ticks(x0, x1, xminor, 16);
    int nym = tsi_plot_minor_ticks(y0, y1, yminor, 16);
    plvpor(left_edge(minor_width(tick_width(y0, y1, 1), yminor, nym), 1.0),
           0.97, 0.11, 0.89);
    frame f;
    frame_set(&f, x0, x1, y0, y1, nlegend, lchars);
    frame_axes(&f, "bcnstl", "bcnstl", 0);
    minor_labels(1, x0, x1, xminor, nxm);
    minor_labels(0, y0, y1, yminor, nym);
    legend L = {0};
    for (int i = 0; i < c->nseries; i++) {
        const ts_plot_series *S = &c->series[i];
        for (int k = 0; k < S->n; k++) {
            lx[k] = log10(pconv(c->xa->quantity, u, S->x[k]));
            ly[k] = log10(pconv(c->ya->quantity, u, S->y[k]));
        }
        int col = color_index(S->color, i);
        draw_series(&f, S, col, i, lx, ly);
        legend_add(&L, S->label, col, S->style, marker_glyph(i));
        /* Each point's text, just right of and above it. */
        plschr(0, 0.75);
        for (int k = 0; S->point_labels && k < S->n; k++) {
            if (!S->point_labels[k] || !S->point_labels[k][0])
                continue;
            char t[TEXT_MAX];
            pl_text(t, sizeof t, S->point_labels[k]);
            double tx = lx[k] + 0.01 * (x1 - x0);
            double ty = ly[k] + 0.025 * (y1 - y0);
            plptex(tx, ty, 1, 0, 0.0, t);
            frame_segment(&f, tx, ty, tx + 0.02 * (x1 - x0), ty);
        }
        plschr(0, 1.0);
    }
    char xl[TEXT_MAX], yl[TEXT_MAX];
    axis_label_of(xl, sizeof xl, c->xa, u);
    axis_label_of(yl, sizeof yl, c->ya, u);
    label_axes(&f, xl, yl, 1.0);
    legend_draw(&L, &f);
    page_title(c->title);
    free(lx);
    return TS_OK;
}

static int plot_loglog(const char *dir, const char *name, const char *title,
                       const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
                       int nseries, const ts_plot_series series[],
                       const ts_plot_opts *opts, ts_err *err)
{
    static const char fn[] = "ts_plot_loglog";
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc)
        return rc;
    if (!xaxis || !yaxis)
        return ts_fail(err, TS_EINVAL, "%s: xaxis, yaxis: expected both "
                                       "axes, got NULL",
                       fn);
    if ((rc = check_quantity(fn, "xaxis.quantity", xaxis->quantity, err)) ||
        (rc = check_quantity(fn, "yaxis.quantity", yaxis->quantity, err)) ||
        (rc = check_series(fn, nseries, series, 1, 1, err)))
        return rc;
    loglog_ctx c = {title, xaxis, yaxis, nseries, series};
    return render(fn, dir, name, title, opts, opts->height, draw_loglog, &c,
                  err);
}

/* ---- maps ------------------------------------------------------------ */

/* Filled contour levels of a map. */
#define MAP_LEVELS 12

typedef struct map_ctx {
    const char *title;
    const ts_plot_axis *xa, *ya, *za;
    const ts_plot_grid *g;
    const int *marks;
    int nb;
    const double *bx, *by;
} map_ctx;

/* z converted, its missing values filled with the mean of their finite
 * neighbours, pass by pass (each pass reads the previous one's values);
 * tmp[nx ny] is scratch. Returns the number still missing. */
static int map_values(const map_ctx *c, const ts_plot_opts *u, double *z,
                      double *tmp)
{
    int nx = c->g->nx, ny = c->g->ny, n = nx * ny, missing = 0;
    for (int k = 0; k < n; k++) {
        z[k] = pconv(c->za->quantity, u, c->g->z[k]);
        missing += !isfinite(z[k]);
    }
    static const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
    while (missing > 0) {
        memcpy(tmp, z, (size_t)n * sizeof *z);
        int filled = 0;
        for (int k = 0; k < n; k++) {
            if (isfinite(tmp[k]))
                continue;
            int i = k / ny, j = k % ny, m = 0;
            double sum = 0;
            for (int d = 0; d < 4; d++) {
                int a = i + di[d], b = j + dj[d];
                if (a >= 0 && a < nx && b >= 0 && b < ny &&
                    isfinite(tmp[a * ny + b])) {
                    sum += tmp[a * ny + b];
                    m++;
                }
            }
            if (m > 0) {
                z[k] = sum / m;
                filled++;
            }
        }
        if (filled == 0)
            break;
        missing -= filled;
    }
    return missing;
}

/* Half-way points between grid values (cell edges), converted: e[n + 1]. */
static void cell_edges(const double *v, int n, ts_plot_quantity q,
                       const ts_plot_opts *u, double *e)
{
    for (int i = 1; i < n; i++)
        e[i] = 0.5 * (pconv(q, u, v[i - 1]) +
                      pconv(q, u, v[i]));
    e[0] = pconv(q, u, v[0]) - (e[1] - pconv(q, u, v[0]));
    e[n] = pconv(q, u, v[n - 1]) +
           (pconv(q, u, v[n - 1]) - e[n - 1]);
}

/* Hatch the cell around grid point (i, j) with pattern `pattern`. */
static void hatch_cell(const double *ex, const double *ey, int i, int j,
                       int color, int pattern)
{
    double x[4] = {ex[i], ex[i + 1], ex[i + 1], ex[i]};
    double y[4] = {ey[j], ey[j], ey[j + 1], ey[j + 1]};
    plcol0(color);
    plpsty(pattern);
    plfill(4, x, y);
    plpsty(0);
}

static int draw_map(const void *vctx, const ts_plot_opts *o, int height,
                    ts_err *err)
{
    (void)height;
    const map_ctx *c = vctx;
    const ts_plot_grid *g = c->g;
    const ts_plot_opts *u = o;
    int nx = g->nx, ny = g->ny, n = nx * ny;
    double *z = malloc((4 * (size_t)n + 2 * (size_t)(nx + ny) + 4) *
                       sizeof *z);
    const double **rows = malloc((size_t)nx * sizeof *rows);
    if (!z || !rows) {
        free(z);
        free(rows);
        return ts_fail(err, TS_ENOMEM, "out of memory");
    }
    double *tmp = z + n, *xg = tmp + n, *yg = xg + nx, *ex = yg + ny;
    double *ey = ex + nx + 1, *mx = ey + ny + 1, *my = mx + n;
    map_values(c, u, z, tmp);
    double z0 = INFINITY, z1 = -INFINITY;
    for (int k = 0; k < n; k++)
        if (isfinite(z[k]))
            bbox_update(&z0, &z1, z[k]);
    if (!(z1 > z0)) {
        double w = z0 != 0 ? 0.05 * fabs(z0) : 1.0;
        z0 -= w;
        z1 += w;
    }
    for (int i = 0; i < nx; i++) {
        xg[i] = pconv(c->xa->quantity, u, g->x[i]);
        rows[i] = z + (size_t)i * (size_t)ny;
    }
    for (int j = 0; j < ny; j++)
        yg[j] = pconv(c->ya->quantity, u, g->y[j]);
    cell_edges(g->x, nx, c->xa->quantity, u, ex);
    cell_edges(g->y, ny, c->ya->quantity, u, ey);
    /* The data's extent, a little more for the marks on its edges; the
     * hatching of an edge cell stops there. */
    double x0 = xg[0], x1 = xg[nx - 1], y0 = yg[0], y1 = yg[ny - 1];
    pad_range(&x0, &x1, 0.025, 1.0);
    pad_range(&y0, &y1, 0.025, 1.0);
    ex[0] = fmax(ex[0], x0);
    ex[nx] = fmin(ex[nx], x1);
    ey[0] = fmax(ey[0], y0);
    ey[ny] = fmin(ey[ny], y1);

    /* The colour map: a perceptual blue-green-yellow ramp (viridis'
     * end points and middle). */
    static const PLFLT pos[5] = {0.0, 0.25, 0.5, 0.75, 1.0};
    static const PLFLT cr[5] = {0.267, 0.231, 0.128, 0.369, 0.993};
    static const PLFLT cg[5] = {0.005, 0.322, 0.567, 0.789, 0.906};
    static const PLFLT cb[5] = {0.329, 0.546, 0.551, 0.383, 0.144};
    plscmap1n(256);
    plscmap1l(1, 5, pos, cr, cg, cb, NULL);
    PLFLT shade[MAP_LEVELS + 1];
    for (int k = 0; k <= MAP_LEVELS; k++)
        shade[k] = z0 + (z1 - z0) * k / MAP_LEVELS;

    /* What the marks mean, above the map. */
    int marks_seen[3] = {0, 0, 0};
    static const int bit[3] = {TS_PLOT_MARK_UNSTABLE, TS_PLOT_MARK_UNTRUSTED,
                               TS_PLOT_MARK_FAILED};
    static const char *const glyph[3] = {"◆", "○", "✖"};
    static const int color[3] = {COL_CURVE0 + 1, COL_FG, COL_FG};
    static const char *const what[3] = {"unstable",
                                        "not trustworthy (hatched)",
                                        "failed (hatched)"};
    legend L = {0};
    for (int k = 0; c->marks && k < 3; k++) {
        for (int i = 0; i < n && !marks_seen[k]; i++)
            marks_seen[k] = (c->marks[i] & bit[k]) != 0;
        if (marks_seen[k])
            legend_add(&L, what[k], color[k], TS_PLOT_MARKERS, glyph[k]);
    }
    if (c->nb > 0)
        legend_add(&L, "stability boundary (bisection)", COL_FG,
                   TS_PLOT_MARKERS, "★");
    PLFLT sx0, sx1, sy0, sy1;
    plgspa(&sx0, &sx1, &sy0, &sy1);
    legend_layout lay = legend_plan(&L, 0.7 * (sx1 - sx0));
    double box_top = 0.88 - (lay.height_mm > 0 ? lay.height_mm + 2.0 : 0) /
                                (sy1 - sy0);
    plvpor(left_edge(tick_width(y0, y1, 0), 1.0), 0.84, 0.11, box_top);
    frame f;
    frame_set(&f, x0, x1, y0, y1, 0, 0);
    PLcGrid cgrid = {xg, yg, NULL, nx, ny, 0};
    plshades(rows, nx, ny, NULL, x0, x1, y0, y1, shade, MAP_LEVELS + 1, 0, 0,
             0, plfill, 1, pltr1, &cgrid);
    /* Contour lines at the shade boundaries, and 0 in bold when z
     * changes sign. */
    plcol0(COL_FG);
    plwidth(0.5);
    plcont(rows, nx, ny, 1, nx, 1, ny, shade + 1, MAP_LEVELS - 1, pltr1,
           &cgrid);
    if (z0 < 0 && z1 > 0) {
        PLFLT zero = 0;
        plwidth(3.0);
        plcont(rows, nx, ny, 1, nx, 1, ny, &zero, 1, pltr1, &cgrid);
    }
    plwidth(AXIS_WIDTH);
    /* Untrustworthy and failed cells hatched. */
    for (int i = 0; c->marks && i < nx; i++)
        for (int j = 0; j < ny; j++) {
            int m = c->marks[i * ny + j];
            if (m & TS_PLOT_MARK_FAILED)
                hatch_cell(ex, ey, i, j, COL_FG, 3);
            else if (m & TS_PLOT_MARK_UNTRUSTED)
                hatch_cell(ex, ey, i, j, COL_GREY, 1);
        }
    frame_axes(&f, "bcnst", "bcnst", 0);
    /* Marks: unstable (red diamonds), untrustworthy (open circles),
     * failed (crosses). */
    for (int k = 0; c->marks && k < 3; k++) {
        int m = 0;
        for (int i = 0; i < nx; i++)
            for (int j = 0; j < ny; j++)
                if (c->marks[i * ny + j] & bit[k]) {
                    mx[m] = xg[i];
                    my[m++] = yg[j];
                }
        if (m == 0)
            continue;
        plcol0(color[k]);
        plschr(0, 0.9);
        draw_markers(&f, m, mx, my, glyph[k]);
        plschr(0, 1.0);
    }
    if (c->nb > 0) {
        double *bx = tmp, *by = tmp + c->nb;
        if (2 * c->nb > n) {
            bx = malloc(2 * (size_t)c->nb * sizeof *bx);
            by = bx ? bx + c->nb : NULL;
        }
        if (bx) {
            for (int k = 0; k < c->nb; k++) {
                bx[k] = pconv(c->xa->quantity, u, c->bx[k]);
                by[k] = pconv(c->ya->quantity, u, c->by[k]);
            }
            plcol0(COL_FG);
            plschr(0, 1.2);
            draw_markers(&f, c->nb, bx, by, "★");
            plschr(0, 1.0);
            if (bx != tmp)
                free(bx);
        }
    }
    char xl[TEXT_MAX], yl[TEXT_MAX], zl[TEXT_MAX];
    axis_label_of(xl, sizeof xl, c->xa, u);
    axis_label_of(yl, sizeof yl, c->ya, u);
    axis_label_of(zl, sizeof zl, c->za, u);
    label_axes(&f, xl, yl, 1.0);
    /* The colour bar, right of the map, labelled with z. */
    PLFLT cw, ch;
    const char *labels[1] = {zl};
    PLINT label_opts[1] = {PL_COLORBAR_LABEL_RIGHT};
    const char *axis_opts[1] = {"bcvtm"};
    PLFLT ticks[1] = {0.0};
    PLINT sub_ticks[1] = {0};
    PLINT n_values[1] = {MAP_LEVELS + 1};
    const PLFLT *values[1] = {shade};
    plcol0(COL_FG);
    plschr(0, 0.85);
    plcolorbar(&cw, &ch, PL_COLORBAR_SHADE | PL_COLORBAR_SHADE_LABEL,
               PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT,
               0.03, 0.0, 0.035, 0.9, COL_BG, COL_FG, LSTY_SOLID, 0, 0, 0, 0,
               1, label_opts, labels, 1, axis_opts, ticks, sub_ticks,
               n_values, values);
    plschr(0, 1.0);
    legend_draw_above(&L, lay);
    page_title(c->title);
    free(z);
    free(rows);
    return TS_OK;
}

static int check_increasing(const char *fn, const char *what,
                            const double *v, int n, ts_err *err)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]) || (i > 0 && !(v[i] > v[i - 1])))
            return ts_fail(err, TS_EINVAL, "%s: grid.%s: expected finite, "
                           "strictly increasing values; entry %d is %g", fn,
                           what, i, v[i]);
    return TS_OK;
}

static int plot_map(const char *dir, const char *name, const char *title,
                    const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
                    const ts_plot_axis *zaxis, const ts_plot_grid *grid,
                    const int *marks, int nb, const double *bx, const double *by,
                    const ts_plot_opts *opts, ts_err *err)
{
    static const char fn[] = "ts_plot_map";
    ts_plot_opts def;
    int rc = begin(fn, dir, name, title, &opts, &def, err);
    if (rc)
        return rc;
    if (!xaxis || !yaxis || !zaxis || !grid)
        return ts_fail(err, TS_EINVAL, "%s: expected the three axes and a "
                       "grid", fn);
    if ((rc = check_quantity(fn, "xaxis.quantity", xaxis->quantity, err)) ||
        (rc = check_quantity(fn, "yaxis.quantity", yaxis->quantity, err)) ||
        (rc = check_quantity(fn, "zaxis.quantity", zaxis->quantity, err)))
        return rc;
    if (grid->nx < 2 || grid->ny < 2 || !grid->x || !grid->y || !grid->z)
        return ts_fail(err, TS_EINVAL, "%s: grid: expected at least 2 x 2 "
                       "values, got %d x %d", fn, grid->nx, grid->ny);
    if ((rc = check_increasing(fn, "x", grid->x, grid->nx, err)) ||
        (rc = check_increasing(fn, "y", grid->y, grid->ny, err)))
        return rc;
    int finite = 0;
    for (int k = 0; k < grid->nx * grid->ny; k++)
        finite += isfinite(grid->z[k]);
    if (!finite)
        return ts_fail(err, TS_EINVAL, "%s: grid.z: no finite value to draw",
                       fn);
    if (nb < 0 || (nb > 0 && (!bx || !by)))
        return ts_fail(err, TS_EINVAL, "%s: expected nb >= 0 boundary points "
                       "with bx and by, got %d", fn, nb);
    for (int k = 0; k < nb; k++)
        if (!isfinite(bx[k]) || !isfinite(by[k]))
            return ts_fail(err, TS_EINVAL, "%s: boundary point %d is not "
                           "finite", fn, k);
    map_ctx c = {title, xaxis, yaxis, zaxis, grid, marks, nb, bx, by};
    return render(fn, dir, name, title, opts, opts->height, draw_map, &c,
                  err);
}

/* What the library looks up (TSI_PLOT_MODULE_SYMBOL). */
__attribute__((visibility("default"))) const tsi_plot_module
    towstab_plot_module = {
        {TSI_PLOT_MODULE_VERSION, TSI_MODULE_RELEASE},
        check_devices, plot_shapes, plot_tracks, plot_mode_shapes,
        plot_eigenvalues, plot_mode_animation, plot_mode_frames, plot_bode,
        plot_histories, plot_loglog, plot_panels, plot_map};
