/* plot_impl.h: the label placement and the outline motion of
 * lib/plot_geom.c, hidden, shared by the drawing module
 * (lib/plot_draw.c) and the tests (test/test_plot.c). */
#ifndef TOWSTAB_PLOT_IMPL_H
#define TOWSTAB_PLOT_IMPL_H

/* Decades (log10 units) up to which a log axis also labels 2 and 5 times
 * each power of ten. */
#define TSI_PLOT_MINOR_DECADES 2.0

/* The minor labels of a log axis spanning 10^lo .. 10^hi: the values 2
 * and 5 times a power of ten inside it when hi - lo is at most
 * TSI_PLOT_MINOR_DECADES, ascending, at most max of them; their count
 * (0 for a wider axis). */
int tsi_plot_minor_ticks(double lo, double hi, double *out, int max);

/* Rows for n labels at positions x[n] (any order), each `width` wide
 * (the units of x), so that labels of one row do not overlap: greedily
 * in increasing x, the first of nrows rows whose last label ends before
 * this one starts; row[i] = -1 when none has room (the label is left
 * out). */
void tsi_plot_label_rows(int n, const double *x, double width, int nrows,
                         int *row);

/* Point p[3] of an outline with anchor A[3] moved by a mode at scale s
 * and magnified by mag: q = A + s t + mag R(s phi) (p - A), motion =
 * (t, phi) [6] (m, rad) or NULL (no motion); as ts_plot_outline_moved
 * for one point. */
void tsi_plot_outline_point(const double A[3], const double *motion,
                            double s, double mag, const double p[3],
                            double q[3]);

/* The motion m[6] at phase ph (rad) of a mode whose real and imaginary
 * parts move an outline by re[6] and im[6]: Re((re + i im) e^{i ph}). */
void tsi_plot_outline_phase_motion(const double re[6], const double im[6],
                                   double ph, double m[6]);

#endif
