/* plot_module.h: the table of functions the drawing module
 * (lib/plot_draw.c, towstab-plot.so) exports under the name
 * TSI_PLOT_MODULE_SYMBOL, and the library (lib/plot.c) calls through once
 * it has opened the module. Each entry does what the public function of
 * the same name with the prefix ts_plot_ does (towstab/plot.h); `check`
 * is ts_plot_check's test of PLplot's devices. The library opens it as
 * lib/dlmodule.h says. */
#ifndef TOWSTAB_PLOT_MODULE_H
#define TOWSTAB_PLOT_MODULE_H

#include "dlmodule.h"
#include "towstab/plot.h"

#define TSI_PLOT_MODULE_SYMBOL "towstab_plot_module"
#define TSI_PLOT_MODULE_VERSION 1
#define TSI_PLOT_MODULE_FILE "towstab-plot.so"

typedef struct tsi_plot_module {
    tsi_module_head head; /* TSI_PLOT_MODULE_VERSION */
    int (*check)(ts_err *err);
    int (*shapes)(const char *dir, const char *name, const char *title,
                  ts_plot_view view, int flags, int nshapes,
                  const ts_plot_shape shapes[], const ts_plot_opts *opts,
                  ts_err *err);
    int (*tracks)(const char *dir, const char *name, const char *title,
                  int ntracks, const ts_plot_track tracks[],
                  const ts_plot_opts *opts, ts_err *err);
    int (*mode_shapes)(const char *dir, const char *name, const char *title,
                       int flags, const ts_plot_shape *eq, int nmodes,
                       const ts_plot_mode modes[], const ts_plot_opts *opts,
                       ts_err *err);
    int (*eigenvalues)(const char *dir, const char *name, const char *title,
                       int nsets, const ts_plot_series sets[],
                       const ts_plot_eig_window *win,
                       const ts_plot_opts *opts, ts_err *err);
    int (*mode_animation)(const char *dir, const char *name,
                          const char *title, ts_plot_view view, int flags,
                          const ts_plot_shape *eq, const double *re,
                          const double *im, const double *outline_re,
                          const double *outline_im, const char *label,
                          int nframes, double seconds,
                          const ts_plot_opts *opts, ts_err *err);
    int (*mode_frames)(const char *dir, const char *name, const char *title,
                       ts_plot_view view, int flags, const ts_plot_shape *eq,
                       const double *re, const double *im,
                       const double *outline_re, const double *outline_im,
                       const char *label, int nframes,
                       const ts_plot_opts *opts, ts_err *err);
    int (*bode)(const char *dir, const char *name, const char *title,
                const char *mag_label, ts_plot_quantity out_q,
                ts_plot_quantity in_q, int ncurves,
                const ts_plot_bode_curve curves[], int nnat,
                const double natural_hz[], const ts_plot_opts *opts,
                ts_err *err);
    int (*histories)(const char *dir, const char *name, const char *title,
                     int npanels, const ts_plot_axis panels[], int nseries,
                     const ts_plot_series series[], const ts_plot_opts *opts,
                     ts_err *err);
    int (*loglog)(const char *dir, const char *name, const char *title,
                  const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
                  int nseries, const ts_plot_series series[],
                  const ts_plot_opts *opts, ts_err *err);
    int (*panels)(const char *dir, const char *name, const char *title,
                  const ts_plot_axis *xaxis, int npanels,
                  const ts_plot_axis panels[], int nseries,
                  const ts_plot_series series[], const ts_plot_opts *opts,
                  ts_err *err);
    int (*map)(const char *dir, const char *name, const char *title,
               const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
               const ts_plot_axis *zaxis, const ts_plot_grid *grid,
               const int *marks, int nb, const double *bx, const double *by,
               const ts_plot_opts *opts, ts_err *err);
} tsi_plot_module;

#endif
