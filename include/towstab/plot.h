/* towstab/plot.h: pictures of results, data in, files out (doc/plots.md).
 *
 * Every function takes plain arrays in SI units (m, N, m/s, s, Hz, rad),
 * draws one picture with PLplot and writes it as DIR/NAME.png (pngcairo)
 * and DIR/NAME.svg (svgcairo), whichever `opts->formats` asks for. Nothing
 * here knows the analyses' structs: the caller (tools/) copies node
 * positions, eigenvalues or time series into the arrays below.
 *
 * Units: numbers come in SI and are converted only when drawn, to the
 * display units of `opts->display` (any unit per quantity) or else to the
 * unit system of `opts->units` (SI: m, N, m/s; imperial: ft, lbf, knot;
 * times s, frequencies Hz, angles degrees in both). Every axis label ends
 * with its unit in brackets.
 *
 * Files: DIR is created when missing, parents included (as by
 * ts_plot_prepare_dir); a DIR that exists and is not a directory is
 * refused. NAME is [A-Za-z0-9._-], not starting with '.'. Each file is drawn
 * in memory and written under a temporary name that is renamed when
 * complete, so a failure leaves no file that looks finished. The SVG
 * carries the title as its <title> element (cairo draws text as glyph
 * outlines, so the title is otherwise not searchable text).
 *
 * Return codes: TS_OK; TS_EINVAL for bad arguments (n < 1, NaN or
 * infinite data, a non-positive value on a log axis, a bad name or size,
 * DIR not a directory); TS_EIO when a file cannot be written, or the
 * drawing module cannot be loaded (message names its file, the dynamic
 * loader's reason and the repair); TS_EDOMAIN when towstab was built
 * without PLplot or PLplot's cairo driver is missing (message says what
 * to install).
 *
 * The drawing functions and ts_plot_check open the drawing module
 * (towstab-plot.so, which alone links PLplot) when called: a program
 * that draws nothing does not load PLplot. It is looked for as
 * TOWSTAB_PLOT_MODULE names it, else beside the library's file or in its
 * towstab/ subdirectory, else where it is installed (doc/plots.md, "The
 * drawing module"). The other functions need neither PLplot nor the
 * module.
 *
 * Not thread-safe: PLplot keeps its stream table and current stream global
 * to the process, and its cairo driver has file-scope state. Call these
 * functions from one thread at a time. Each call makes its own PLplot
 * stream (plmkstrm), ends it (plend1) and makes the stream that was current
 * before the call current again, so a caller's own PLplot stream survives.
 */
#ifndef TOWSTAB_PLOT_H
#define TOWSTAB_PLOT_H

#include "towstab/error.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Unit system of the axes. */
typedef enum { TS_PLOT_SI = 0, TS_PLOT_IMPERIAL = 1 } ts_plot_units;

/* What an axis shows, for its unit. Values are always passed in SI (the
 * first unit); imperial drawing uses the second.
 *   NONE          dimensionless, "-"
 *   LENGTH        m      | ft    (1 ft = 0.3048 m)
 *   FORCE         N      | lbf   (1 lbf = 4.4482216152605 N)
 *   SPEED         m/s    | knot  (1 knot = 1852/3600 m/s)
 *   TIME          s      | s
 *   FREQUENCY     Hz     | Hz
 *   RATE          1/s    | 1/s   (real part of an eigenvalue)
 *   ANGULAR_RATE  rad/s  | rad/s (imaginary part, turn rate)
 *   ANGLE         passed in rad, drawn in deg in both systems
 *   MASS          kg     | lb    (1 lb = 0.45359237 kg) */
typedef enum {
    TS_PLOT_NONE = 0,
    TS_PLOT_LENGTH,
    TS_PLOT_FORCE,
    TS_PLOT_SPEED,
    TS_PLOT_TIME,
    TS_PLOT_FREQUENCY,
    TS_PLOT_RATE,
    TS_PLOT_ANGULAR_RATE,
    TS_PLOT_ANGLE,
    TS_PLOT_MASS
} ts_plot_quantity;

/* Output formats (bits of ts_plot_opts.formats). */
#define TS_PLOT_PNG 1
#define TS_PLOT_SVG 2

/* Picture size limits, px for PNG and pt for SVG. */
#define TS_PLOT_MIN_WIDTH 1000
#define TS_PLOT_MIN_HEIGHT 700
#define TS_PLOT_MAX_SIZE 8000

typedef struct ts_plot_opts {
    ts_plot_units units;  /* default TS_PLOT_SI */
    const ts_display *display; /* when set (default NULL), the units of
                              the axes per quantity (towstab/units.h),
                              instead of `units`; the caller keeps it */
    int width, height;    /* default 1000 x 700; each in [MIN, MAX_SIZE] */
    int formats;          /* default TS_PLOT_PNG | TS_PLOT_SVG */
    int bode_db;          /* ts_plot_bode: the magnitude in dB, 20 log10
                             |H| on a linear axis, instead of |H| on a log
                             axis; default 0 */
} ts_plot_opts;

/* Line styles. */
enum {
    TS_PLOT_SOLID = 0,
    TS_PLOT_DASHED = 1,
    TS_PLOT_DOTTED = 2,
    TS_PLOT_MARKERS = 3,      /* markers only, no line */
    TS_PLOT_LINE_MARKERS = 4  /* solid line with a marker at every point */
};

/* An axis: its name (e.g. "sphere depth") and quantity; the unit is added
 * to the label. */
typedef struct ts_plot_axis {
    const char *label;
    ts_plot_quantity quantity;
    const char *unit;   /* TS_PLOT_NONE only: the SI unit of a quantity
                           with none of its own ("N/m", "kg/m"), drawn as
                           is in both systems; NULL: dimensionless */
} ts_plot_axis;

/* A curve y(x): n points (n >= 1), both arrays [n] in SI. */
typedef struct ts_plot_series {
    int n;
    const double *x;
    const double *y;
    const char *label;  /* legend text; NULL or "" for no entry */
    int panel;          /* ts_plot_histories: index of its panel; else 0 */
    int style;          /* TS_PLOT_SOLID, ... */
    int color;          /* 0: automatic (next colour); k >= 1: colour k of
                           the palette, modulo its size */
    const char *const *point_labels; /* ts_plot_loglog: [n] a text beside
                           each point (NULL entries: none), or NULL */
} ts_plot_series;

/* A body drawn with its attitude (a vehicle, towstab/vehicle.h
 * ts_vehicle_outline): polylines of points in M (m), a point of NaNs
 * between two. The pictures magnify every outline about its anchor by one
 * common factor, so that the smallest is at least TS_PLOT_OUTLINE_MIN of
 * the picture's extent (a towfish is small beside its cable), and say so
 * in a note. */
typedef struct ts_plot_outline {
    int npoints;
    const double *pts;     /* [3 npoints] */
    double anchor[3];      /* fixed point of the magnification (the cable's
                              attach point), m */
} ts_plot_outline;

#define TS_PLOT_OUTLINE_MIN 0.06

/* A cylinder towfish of a shape: centred on its node, its axis along the
 * link that ends there (doc/model.md section 1). Drawn as its outline,
 * filled in the shape's colour, at least 3 % of the picture's extent long
 * with its proportions kept (a towfish is small beside its cable). */
typedef struct ts_plot_cylinder {
    int node;         /* >= 1: a node below a link */
    double length;    /* m, > 0 */
    double diameter;  /* m, > 0 */
} ts_plot_cylinder;

/* A cable shape: nodes and the links between them, in the mean ship
 * frame M (x forward, y starboard, z down = depth; the water surface is
 * z = 0), as the equilibrium and the simulation report them. */
typedef struct ts_plot_shape {
    int nnodes;              /* >= 2 */
    const double *pos;       /* [3 nnodes] node positions, m */
    const int *link_upper;   /* [nnodes - 1]: link k joins node
                                link_upper[k] (< k + 1) to node k + 1,
                                as ts_system's links; NULL for a chain
                                (link_upper[k] = k) */
    int nmarks;              /* bodies to mark with a dot */
    const int *marks;        /* [nmarks] node indices */
    double turn_radius;      /* ship's turning circle for the top view, m:
                                centre (0, R, 0) in M (R > 0 starboard
                                turn, R = V / Omega); 0: straight tow */
    const char *label;       /* legend text; NULL or "" for no entry */
    int style;               /* TS_PLOT_SOLID or TS_PLOT_DASHED (under
                                water; parts in air are always dashed) */
    int color;               /* as ts_plot_series */
    int ncylinders;          /* cylinder towfish to draw */
    const ts_plot_cylinder *cylinders; /* [ncylinders] */
    int noutlines;           /* bodies drawn with their attitude */
    const ts_plot_outline *outlines; /* [noutlines]; in ts_plot_mode_shapes
                                the equilibrium's */
} ts_plot_shape;

/* Views of ts_plot_shapes. */
typedef enum {
    TS_PLOT_SIDE = 0, /* x-z, depth downward */
    TS_PLOT_TOP = 1   /* x-y seen from above: x to the right, starboard
                         down the page; equal scales always */
} ts_plot_view;

/* Flags of ts_plot_shapes and ts_plot_mode_shapes. */
#define TS_PLOT_WATER 1 /* draw the water surface and the water below it;
                           parts of the cable in air (z < 0) are dashed */
#define TS_PLOT_EQUAL 2 /* side view: equal scales on x and z */

/* One mode for ts_plot_mode_shapes: a real displacement of every node.
 * For a complex mode vector v, pass Re(v e^{i phi}) with phi chosen to
 * maximise its norm (the shape at the phase of largest excursion). */
typedef struct ts_plot_mode {
    const double *disp;  /* [3 nnodes] node displacements (any scale) */
    const char *label;   /* e.g. "mode 1: 0.412 Hz, damping 3.1 %" */
    const double *outline_motion; /* [6 noutlines] of the equilibrium's
                            outlines, at the scale of disp: each one's
                            anchor displacement (3, m) and small rotation
                            vector (3, rad, M axes) in the mode; NULL:
                            the outlines are drawn at the trim only */
} ts_plot_mode;

/* The points out[3 npoints] of outline o moved by a mode at scale s and
 * magnified by mag about its anchor A: each point p goes to
 *     A + s t + mag R(s phi) (p - A),
 * (t, phi) = (motion[0..3), motion[3..6)) the anchor's displacement (m)
 * and small rotation vector (rad, M axes) per unit of the mode, R(w) the
 * rotation by the angle |w| about w / |w| (Rodrigues: a rigid motion at
 * any angle). motion NULL: no motion (the trim). Non-finite points (pen
 * lifts) stay non-finite. */
TS_API void ts_plot_outline_moved(const ts_plot_outline *o,
                                  const double motion[6], double s,
                                  double mag, double out[]);

/* The points out[3 npoints] of outline o at phase `phase` (rad) of a
 * complex mode: ts_plot_outline_moved with the motion
 *     Re((motion_re + i motion_im) e^{i phase}),
 * motion_re and motion_im [6] the anchor displacement (m) and small
 * rotation vector (rad, M axes) of the mode's real and imaginary parts
 * (as ts_plot_mode.outline_motion); s and mag as there. The frames of
 * ts_plot_mode_animation and ts_plot_mode_frames draw each outline so. */
TS_API void ts_plot_outline_at_phase(const ts_plot_outline *o,
                                     const double motion_re[6],
                                     const double motion_im[6],
                                     double phase, double s, double mag,
                                     double out[]);

/* A mode as an animation: DIR/NAME.svg only (whatever opts->formats), an
 * SVG whose cable path runs through one cycle of the mode every `seconds`
 * seconds and loops (SMIL <animate> of its path, nframes frames at phases
 * 2 pi k / nframes: eq + s Re((re + i im) e^{i phi}), s making the largest
 * node amplitude 15 % of the equilibrium's extent), over the equilibrium
 * in grey, in one view (side, with TS_PLOT_WATER the water; or top, equal
 * scales), titled, with `label` above the box (may be NULL). re and im:
 * [3 nnodes] node displacements of the mode's real and imaginary parts.
 * The outlines of eq (vehicles) are drawn grey at their trim and, when
 * outline_re and outline_im ([6 noutlines] each, as
 * ts_plot_mode.outline_motion, of the mode's real and imaginary parts) are
 * given, in the mode's colour at every frame moved and rotated by the mode
 * at the same phase and scale (ts_plot_outline_at_phase), magnified as in
 * ts_plot_mode_shapes; both NULL: the outlines stay at the trim.
 * nframes in [4, TS_PLOT_MAX_FRAMES]. Browsers play it; a still viewer
 * shows the first frame. */
#define TS_PLOT_MAX_FRAMES 360
TS_API int ts_plot_mode_animation(const char *dir, const char *name,
                                  const char *title, ts_plot_view view,
                                  int flags, const ts_plot_shape *eq,
                                  const double *re, const double *im,
                                  const double *outline_re,
                                  const double *outline_im,
                                  const char *label, int nframes,
                                  double seconds, const ts_plot_opts *opts,
                                  ts_err *err);

/* The same cycle as a PNG frame sequence (where an SVG animation is not
 * wanted: slides, video tools): DIR/NAME_000.png .. NAME_kkk.png, one per
 * phase 2 pi k / nframes (whatever opts->formats), each the equilibrium
 * in grey and the displaced shape (cylinder towfish drawn, vehicle
 * outlines moved and rotated at the frame's phase as in
 * ts_plot_mode_animation), in one fixed window for every frame (side, with
 * TS_PLOT_WATER the water; or top, equal scales), titled with the frame
 * and its phase, `label` above the box. Same scale and checks as
 * ts_plot_mode_animation; NAME at most 196 characters. */
TS_API int ts_plot_mode_frames(const char *dir, const char *name,
                               const char *title, ts_plot_view view,
                               int flags, const ts_plot_shape *eq,
                               const double *re, const double *im,
                               const double *outline_re,
                               const double *outline_im,
                               const char *label, int nframes,
                               const ts_plot_opts *opts, ts_err *err);

/* Axis window of ts_plot_eigenvalues; a field equal to 0 is automatic. */
typedef struct ts_plot_eig_window {
    double re_min;  /* left edge, 1/s (< 0) */
    double re_max;  /* right edge, 1/s (> 0) */
    double im_max;  /* the window is -im_max .. im_max, rad/s (> 0) */
} ts_plot_eig_window;

/* One frequency response: n >= 2 points. */
typedef struct ts_plot_bode_curve {
    int n;
    const double *freq;   /* [n] Hz, > 0 and increasing */
    const double *mag;    /* [n] |H|, output SI unit per input SI unit, > 0 */
    const double *phase;  /* [n] rad (unwrapped for drawing) */
    const char *label;
    int style;
    int color;
} ts_plot_bode_curve;

/* Defaults: SI, 1000 x 700, PNG and SVG. */
TS_API void ts_plot_opts_default(ts_plot_opts *o);

/* TS_OK when pictures can be drawn: towstab was built with PLplot and
 * PLplot's pngcairo and svgcairo devices are installed. Else TS_EDOMAIN
 * with a message naming the packages to install, or TS_EIO when the
 * drawing module cannot be loaded (missing, broken or of another build:
 * the message names the file and the repair). */
TS_API int ts_plot_check(ts_err *err);

/* Create directory `dir` if it does not exist, with its missing parents
 * (mode 0777 less the umask). TS_EINVAL if `dir` (or a parent) exists and
 * is not a directory; TS_EIO if it cannot be created or is not writable.
 * Works without PLplot. */
TS_API int ts_plot_prepare_dir(const char *dir, ts_err *err);

/* `value_si` of quantity q in the unit system u, and that unit's name
 * ("m", "ft", "deg", "-"). Work without PLplot. */
TS_API double ts_plot_convert(ts_plot_quantity q, ts_plot_units u,
                              double value_si);
TS_API const char *ts_plot_unit(ts_plot_quantity q, ts_plot_units u);

/* Cable shapes, overlaid: nshapes >= 1 shapes in one view (memo Figs. 7-8;
 * snapshots of a time history, Figs. 9 and 11). The side view shows x
 * forward against depth z downward; with TS_PLOT_WATER the water surface
 * z = 0 and the water below it, parts in air dashed. The top view shows x
 * against y (starboard down the page) with equal scales, the ship at the
 * origin heading right and, for every shape with a turn radius, the
 * ship's turning circle (dotted) and its centre. Bodies are dots. The
 * legend (labelled shapes, and the line styles "in air" and "the ship's
 * turning circle" when drawn) sits above the plot box. */
TS_API int ts_plot_shapes(const char *dir, const char *name,
                          const char *title, ts_plot_view view, int flags,
                          int nshapes, const ts_plot_shape shapes[],
                          const ts_plot_opts *opts, ts_err *err);

/* A marked point of a track plan (a waypoint, the start of a turn). */
typedef struct ts_plot_marker {
    double x, y;            /* in the earth frame R, m */
    const char *label;      /* text beside it ("WP 1"); NULL or "": none */
} ts_plot_marker;

/* One track: the path of a point (the ship, a body) in the horizontal
 * plane of the earth frame R (doc/model.md section 1: at t = 0 R
 * coincides with the mean ship frame M, x forward, y starboard). */
typedef struct ts_plot_track {
    int n;                  /* points, >= 1 */
    const double *x, *y;    /* [n] R's x and y, m */
    const char *label;      /* legend text; NULL or "": no entry */
    int style;              /* TS_PLOT_SOLID ... TS_PLOT_LINE_MARKERS */
    int color;              /* as ts_plot_series */
    int nmarkers;           /* >= 0 */
    const ts_plot_marker *markers; /* [nmarkers], drawn as open diamonds
                               in the track's colour with their text */
} ts_plot_track;

/* Tracks in plan view, the earth frame: ntracks >= 1 tracks overlaid, x
 * to the right and y (starboard at t = 0) down the page with equal
 * scales, the window holding every point and marker. Each track of two
 * or more points ends in an arrowhead pointing along its last segment (the
 * direction of travel); a track of one point is a marker. The legend sits
 * above the plot box. E.g. a ship's track and its towfish's under a
 * manoeuvre, with the waypoints as markers, or the circles a steady turn
 * traces. */
TS_API int ts_plot_tracks(const char *dir, const char *name,
                          const char *title, int ntracks,
                          const ts_plot_track tracks[],
                          const ts_plot_opts *opts, ts_err *err);

/* Mode shapes: one row per mode (1 <= nmodes <= 8), side view on the left
 * and top view (equal scales) on the right. Each shows the equilibrium
 * `eq` (grey) and eq +- s disp (solid and dashed), s chosen so that the
 * largest node displacement is 15 % of the cable's largest extent; the
 * outlines of eq at the trim (grey) and, for a mode with its
 * outline_motion, moved and rotated by +- s of it in the mode's colour
 * (ts_plot_outline_moved). The
 * picture is 95 + 220 nmodes + 50 px tall when that exceeds
 * opts->height (nmodes >= 3 at the default 700 px). `eq` gives nodes,
 * links and marks; its label, style, colour and turn radius are not
 * used. */
TS_API int ts_plot_mode_shapes(const char *dir, const char *name,
                               const char *title, int flags,
                               const ts_plot_shape *eq, int nmodes,
                               const ts_plot_mode modes[],
                               const ts_plot_opts *opts, ts_err *err);

/* The eigenvalue plane: real part (1/s) against imaginary part (rad/s) of
 * every eigenvalue of nsets sets (series: x = real parts, y = imaginary
 * parts; drawn as markers whatever their style), the stability boundary
 * (real part 0, the unstable half-plane shaded) and rays of constant
 * damping ratio zeta = 0.02, 0.05, 0.1, 0.2, 0.5 (lambda = omega_n
 * (-zeta +- i sqrt(1 - zeta^2))). `win` NULL or zero fields: a window
 * holding every eigenvalue and the origin; eigenvalues outside a given
 * window are counted in a note under the plot. */
TS_API int ts_plot_eigenvalues(const char *dir, const char *name,
                               const char *title, int nsets,
                               const ts_plot_series sets[],
                               const ts_plot_eig_window *win,
                               const ts_plot_opts *opts, ts_err *err);

/* Bode plot: magnitude (log-log, top) and phase in degrees (bottom) of
 * ncurves responses against frequency in Hz, with the nnat >= 0 natural
 * frequencies natural_hz[nnat] marked by vertical dotted lines labelled
 * f1, f2, ... The magnitude's unit is out_q per in_q ("m/m", "lbf/ft");
 * `mag_label` names it (e.g. "sphere heave / tow-point heave"). */
TS_API int ts_plot_bode(const char *dir, const char *name, const char *title,
                        const char *mag_label, ts_plot_quantity out_q,
                        ts_plot_quantity in_q, int ncurves,
                        const ts_plot_bode_curve curves[], int nnat,
                        const double natural_hz[], const ts_plot_opts *opts,
                        ts_err *err);

/* Time histories: npanels (1..6) panels stacked over a shared time axis
 * (s); panel p is labelled panels[p]; series (x = time in s, y in SI of
 * panels[series.panel].quantity) go to their panel. Linear and nonlinear
 * results overlay as two series of one panel (e.g. dashed and solid). */
TS_API int ts_plot_histories(const char *dir, const char *name,
                             const char *title, int npanels,
                             const ts_plot_axis panels[], int nseries,
                             const ts_plot_series series[],
                             const ts_plot_opts *opts, ts_err *err);

/* Panels of curves against a common x axis: as ts_plot_histories, with
 * the x axis given (e.g. the tow speed of a sweep) instead of time. */
TS_API int ts_plot_panels(const char *dir, const char *name,
                          const char *title, const ts_plot_axis *xaxis,
                          int npanels, const ts_plot_axis panels[],
                          int nseries, const ts_plot_series series[],
                          const ts_plot_opts *opts, ts_err *err);

/* Values on a grid for ts_plot_map: z at (x[i], y[j]) is z[i ny + j]
 * (x slowest); x[nx] and y[ny] strictly increasing, nx, ny >= 2; a NAN z
 * is a point without a value (a failed run). SI units. */
typedef struct ts_plot_grid {
    int nx, ny;
    const double *x, *y, *z;
} ts_plot_grid;

/* Marks of the points of a map (bits of marks[i ny + j]). */
#define TS_PLOT_MARK_UNSTABLE 1  /* the linear model is unstable there */
#define TS_PLOT_MARK_UNTRUSTED 2 /* the result is not trustworthy */
#define TS_PLOT_MARK_FAILED 4    /* the run failed (no value) */

/* A map of one quantity over two parameters (an operating envelope):
 * filled contours of z with contour lines and a colour bar (the 0 level
 * drawn bold when z changes sign, e.g. the stability margin), the points
 * marked (marks[nx ny], may be NULL: unstable points filled red diamonds,
 * untrustworthy ones open circles, failed ones crosses, their cells
 * hatched), and nb >= 0 points (bx[nb], by[nb], SI) of a boundary drawn
 * as black stars (e.g. the crossings of the stability boundary). Failed
 * points are drawn with their neighbours' values under the hatching.
 * TS_EINVAL when no z is finite. */
TS_API int ts_plot_map(const char *dir, const char *name, const char *title,
                       const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
                       const ts_plot_axis *zaxis, const ts_plot_grid *grid,
                       const int *marks, int nb, const double *bx,
                       const double *by, const ts_plot_opts *opts,
                       ts_err *err);

/* Log-log lines, e.g. error against run time (memo Fig. 12): one series
 * per analysis or integrator, every x and y > 0. */
TS_API int ts_plot_loglog(const char *dir, const char *name,
                          const char *title, const ts_plot_axis *xaxis,
                          const ts_plot_axis *yaxis, int nseries,
                          const ts_plot_series series[],
                          const ts_plot_opts *opts, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
