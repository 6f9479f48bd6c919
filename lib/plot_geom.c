/* plot_geom.c: the parts of pictures (towstab/plot.h) that need no
 * PLplot, in the library in every build: default options, unit
 * conversions, the output directory, the label placement of log axes
 * (plot_impl.h), and the rigid motion of a body's outline in a mode
 * (Rodrigues' rotation formula). The drawing module
 * (lib/plot_draw.c, towstab-plot.so) is built with its own copy of this
 * file, so that it needs none of the library's hidden symbols.
 */
#include "towstab/plot.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "plot_impl.h"

/* Exact definitions: international foot, pound-force, knot. */
#define FT_M 0.3048
#define LBF_N 4.4482216152605
#define KNOT_MS (1852.0 / 3600.0)
#define LB_KG 0.45359237

void ts_plot_opts_default(ts_plot_opts *o)
{
    o->units = TS_PLOT_SI;
    o->display = NULL;
    o->bode_db = 0;
    o->width = TS_PLOT_MIN_WIDTH;
    o->height = TS_PLOT_MIN_HEIGHT;
    o->formats = TS_PLOT_PNG | TS_PLOT_SVG;
}

double ts_plot_convert(ts_plot_quantity q, ts_plot_units u, double v)
{
    if (q == TS_PLOT_ANGLE)
        return v * (180.0 / M_PI);
    if (u != TS_PLOT_IMPERIAL)
        return v;
    switch (q) {
    case TS_PLOT_LENGTH: return v / FT_M;
    case TS_PLOT_FORCE: return v / LBF_N;
    case TS_PLOT_SPEED: return v / KNOT_MS;
    case TS_PLOT_MASS: return v / LB_KG;
    default: return v;
    }
}

const char *ts_plot_unit(ts_plot_quantity q, ts_plot_units u)
{
    int imp = u == TS_PLOT_IMPERIAL;
    switch (q) {
    case TS_PLOT_LENGTH: return imp ? "ft" : "m";
    case TS_PLOT_FORCE: return imp ? "lbf" : "N";
    case TS_PLOT_SPEED: return imp ? "knot" : "m/s";
    case TS_PLOT_TIME: return "s";
    case TS_PLOT_FREQUENCY: return "Hz";
    case TS_PLOT_RATE: return "1/s";
    case TS_PLOT_ANGULAR_RATE: return "rad/s";
    case TS_PLOT_ANGLE: return "deg";
    case TS_PLOT_MASS: return imp ? "lb" : "kg";
    default: return "-";
    }
}
int ts_plot_prepare_dir(const char *dir, ts_err *err)
{
    if (!dir || !dir[0])
        return ts_fail(err, TS_EINVAL, "plot directory: expected a path, "
                                       "got an empty string");
    size_t len = strlen(dir);
    char *path = malloc(len + 1);
    if (!path)
        return ts_fail(err, TS_ENOMEM, "plot directory: out of memory");
    memcpy(path, dir, len + 1);
    /* Walk the prefixes "a", "a/b", ... and create those that are missing;
     * a prefix that exists must be a directory. */
    int rc = TS_OK;
    for (size_t i = 1; i <= len && rc == TS_OK; i++) {
        if (i < len && path[i] != '/')
            continue;
        char saved = path[i];
        path[i] = '\0';
        struct stat st;
        if (stat(path, &st) == 0) {
            if (!S_ISDIR(st.st_mode) && i == len)
                rc = ts_fail(err, TS_EINVAL,
                             "plot directory '%s': exists and is not a "
                             "directory",
                             dir);
            else if (!S_ISDIR(st.st_mode))
                rc = ts_fail(err, TS_EINVAL,
                             "plot directory '%s': '%s' exists and is not a "
                             "directory",
                             dir, path);
        } else if (errno == ENOENT) {
            if (mkdir(path, 0777) != 0 && errno != EEXIST)
                rc = ts_fail(err, TS_EIO,
                             "plot directory '%s': cannot create '%s' (%s)",
                             dir, path, strerror(errno));
        } else {
            rc = ts_fail(err, TS_EIO, "plot directory '%s': cannot use '%s' "
                                      "(%s)",
                         dir, path, strerror(errno));
        }
        path[i] = saved;
    }
    free(path);
    if (rc == TS_OK && access(dir, W_OK | X_OK) != 0)
        rc = ts_fail(err, TS_EIO, "plot directory '%s': not writable (%s)",
                     dir, strerror(errno));
    return rc;
}

/* ---- label placement (plot_impl.h) ----------------------------------- */

int tsi_plot_minor_ticks(double lo, double hi, double *out, int max)
{
    if (!(hi - lo <= TSI_PLOT_MINOR_DECADES) || !(hi > lo))
        return 0;
    int n = 0;
    static const double mult[2] = {2.0, 5.0};
    for (long e = lround(floor(lo)); e <= lround(ceil(hi)); e++)
        for (int k = 0; k < 2 && n < max; k++) {
            double v = mult[k] * pow(10.0, (double)e), l = log10(v);
            if (l > lo && l < hi)
                out[n++] = v;
        }
    return n;
}

void tsi_plot_label_rows(int n, const double *x, double width, int nrows,
                         int *row)
{
    enum { ROWS_MAX = 8 };
    double last[ROWS_MAX];
    if (nrows > ROWS_MAX)
        nrows = ROWS_MAX;
    for (int r = 0; r < nrows; r++)
        last[r] = -INFINITY;
    /* In increasing x: the next label is the smallest x not placed yet. */
    for (int i = 0; i < n; i++)
        row[i] = -2;
    for (int done = 0; done < n; done++) {
        int k = -1;
        for (int i = 0; i < n; i++)
            if (row[i] == -2 && (k < 0 || x[i] < x[k]))
                k = i;
        row[k] = -1;
        for (int r = 0; r < nrows; r++)
            if (x[k] - last[r] >= width) {
                row[k] = r;
                last[r] = x[k];
                break;
            }
    }
}

/* The rigid motion of ts_plot_outline_moved: point p of an outline with
 * anchor A to q = A + s t + mag R(s phi) (p - A), R by Rodrigues'
 * formula R v = v cos a + (k x v) sin a + k (k . v) (1 - cos a), a =
 * |s phi|, k its direction. */
void tsi_plot_outline_point(const double A[3], const double *motion,
                            double s, double mag, const double p[3],
                            double q[3])
{
    double v[3] = {mag * (p[0] - A[0]), mag * (p[1] - A[1]),
                   mag * (p[2] - A[2])};
    if (!motion) {
        for (int j = 0; j < 3; j++)
            q[j] = A[j] + v[j];
        return;
    }
    double w[3] = {s * motion[3], s * motion[4], s * motion[5]};
    double a = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (a > 0) {
        double k[3] = {w[0] / a, w[1] / a, w[2] / a}, c = cos(a),
               sn = sin(a);
        double kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
        double kx[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2],
                        k[0] * v[1] - k[1] * v[0]};
        for (int j = 0; j < 3; j++)
            v[j] = v[j] * c + kx[j] * sn + k[j] * kv * (1 - c);
    }
    for (int j = 0; j < 3; j++)
        q[j] = A[j] + s * motion[j] + v[j];
}

void ts_plot_outline_moved(const ts_plot_outline *o, const double motion[6],
                           double s, double mag, double out[])
{
    for (int k = 0; k < o->npoints; k++) {
        const double *p = o->pts + 3 * (size_t)k;
        double *q = out + 3 * (size_t)k;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
            q[0] = q[1] = q[2] = NAN;
        else
            tsi_plot_outline_point(o->anchor, motion, s, mag, p, q);
    }
}

/* Re((re + i im) e^{i ph}) (plot_impl.h). */
void tsi_plot_outline_phase_motion(const double re[6], const double im[6],
                                   double ph, double m[6])
{
    double c = cos(ph), sn = sin(ph);
    for (int j = 0; j < 6; j++)
        m[j] = re[j] * c - im[j] * sn;
}

void ts_plot_outline_at_phase(const ts_plot_outline *o,
                              const double motion_re[6],
                              const double motion_im[6], double phase,
                              double s, double mag, double out[])
{
    double m[6];
    tsi_plot_outline_phase_motion(motion_re, motion_im, phase, m);
    ts_plot_outline_moved(o, m, s, mag, out);
}
