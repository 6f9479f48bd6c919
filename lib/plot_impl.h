/* plot_impl.h: the label placement of lib/plot.c, hidden, for its tests
 * (test/test_plot.c). */
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

#endif
