/* plot.c: pictures of results (towstab/plot.h, doc/plots.md): the loader
 * of the drawing module.
 *
 * The drawing itself (lib/plot_draw.c) is a module of its own,
 * towstab-plot.so, linked to PLplot and its eleven libraries (freetype,
 * png, qhull, ...; PLplot's cairo driver brings cairo, pango and
 * fontconfig when it draws); the library is not. Each drawing
 * function, and ts_plot_check, opens the module with dlopen, calls the
 * entry of the same name in its table (plot_module.h) and closes it
 * again. The module is opened with RTLD_NODELETE, so only the first call
 * of a process maps it (and PLplot); later calls find it loaded and cost
 * a lookup. A run that draws nothing loads none of it (doc/performance.md,
 * "Start-up"). No state is kept here: the dynamic loader keeps the module.
 *
 * Where the module is looked for: lib/dlmodule.h (TOWSTAB_PLOT_MODULE
 * names it for the tests). When it cannot be opened, the message names
 * the file and the dynamic loader's reason, and nothing is drawn or
 * written.
 *
 * The pure parts (options, units, the output directory, outline motion)
 * are in lib/plot_geom.c and need no module.
 */
#include "towstab/plot.h"

#include "dlmodule.h"
#include "plot_module.h"

#define NO_PLPLOT_MSG                                                         \
    "towstab was built without PLplot; install libplplot-dev and "           \
    "plplot-driver-cairo and rebuild"

/* An open module and its table. */
typedef struct module {
    tsi_module dl;
    const tsi_plot_module *table;
} module;

static int module_open(module *m, ts_err *err)
{
#ifdef TS_HAVE_PLPLOT
    int rc = tsi_module_open(&m->dl, "plotting module", TSI_PLOT_MODULE_FILE,
                             "TOWSTAB_PLOT_MODULE", TSI_PLOT_MODULE_SYMBOL,
                             TSI_PLOT_MODULE_VERSION, err);
    m->table = m->dl.table;
    return rc;
#else
    m->dl.handle = NULL;
    m->table = NULL;
    return ts_fail(err, TS_EDOMAIN, NO_PLPLOT_MSG);
#endif
}

static void module_close(module *m) { tsi_module_close(&m->dl); }

/* Open the module, call its entry with the arguments, close it. */
#define CALL_MODULE(entry, ...)                                               \
    do {                                                                      \
        module m_;                                                            \
        int rc_ = module_open(&m_, err);                                      \
        if (rc_ == TS_OK) {                                                   \
            rc_ = m_.table->entry(__VA_ARGS__);                               \
            module_close(&m_);                                                \
        }                                                                     \
        return rc_;                                                           \
    } while (0)

int ts_plot_check(ts_err *err) { CALL_MODULE(check, err); }

int ts_plot_shapes(const char *dir, const char *name, const char *title,
                   ts_plot_view view, int flags, int nshapes,
                   const ts_plot_shape shapes[], const ts_plot_opts *opts,
                   ts_err *err)
{
    CALL_MODULE(shapes, dir, name, title, view, flags, nshapes, shapes, opts,
                err);
}

int ts_plot_tracks(const char *dir, const char *name, const char *title,
                   int ntracks, const ts_plot_track tracks[],
                   const ts_plot_opts *opts, ts_err *err)
{
    CALL_MODULE(tracks, dir, name, title, ntracks, tracks, opts, err);
}

int ts_plot_mode_shapes(const char *dir, const char *name, const char *title,
                        int flags, const ts_plot_shape *eq, int nmodes,
                        const ts_plot_mode modes[], const ts_plot_opts *opts,
                        ts_err *err)
{
    CALL_MODULE(mode_shapes, dir, name, title, flags, eq, nmodes, modes, opts,
                err);
}

int ts_plot_eigenvalues(const char *dir, const char *name, const char *title,
                        int nsets, const ts_plot_series sets[],
                        const ts_plot_eig_window *win,
                        const ts_plot_opts *opts, ts_err *err)
{
    CALL_MODULE(eigenvalues, dir, name, title, nsets, sets, win, opts, err);
}

int ts_plot_mode_animation(const char *dir, const char *name,
                           const char *title, ts_plot_view view, int flags,
                           const ts_plot_shape *eq, const double *re,
                           const double *im, const double *outline_re,
                           const double *outline_im, const char *label,
                           int nframes, double seconds,
                           const ts_plot_opts *opts, ts_err *err)
{
    CALL_MODULE(mode_animation, dir, name, title, view, flags, eq, re, im,
                outline_re, outline_im, label, nframes, seconds, opts, err);
}

int ts_plot_mode_frames(const char *dir, const char *name, const char *title,
                        ts_plot_view view, int flags, const ts_plot_shape *eq,
                        const double *re, const double *im,
                        const double *outline_re, const double *outline_im,
                        const char *label, int nframes,
                        const ts_plot_opts *opts, ts_err *err)
{
    CALL_MODULE(mode_frames, dir, name, title, view, flags, eq, re, im,
                outline_re, outline_im, label, nframes, opts, err);
}

int ts_plot_bode(const char *dir, const char *name, const char *title,
                 const char *mag_label, ts_plot_quantity out_q,
                 ts_plot_quantity in_q, int ncurves,
                 const ts_plot_bode_curve curves[], int nnat,
                 const double natural_hz[], const ts_plot_opts *opts,
                 ts_err *err)
{
    CALL_MODULE(bode, dir, name, title, mag_label, out_q, in_q, ncurves,
                curves, nnat, natural_hz, opts, err);
}

int ts_plot_histories(const char *dir, const char *name, const char *title,
                      int npanels, const ts_plot_axis panels[], int nseries,
                      const ts_plot_series series[], const ts_plot_opts *opts,
                      ts_err *err)
{
    CALL_MODULE(histories, dir, name, title, npanels, panels, nseries, series,
                opts, err);
}

int ts_plot_loglog(const char *dir, const char *name, const char *title,
                   const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
                   int nseries, const ts_plot_series series[],
                   const ts_plot_opts *opts, ts_err *err)
{
    CALL_MODULE(loglog, dir, name, title, xaxis, yaxis, nseries, series, opts,
                err);
}

int ts_plot_panels(const char *dir, const char *name, const char *title,
                   const ts_plot_axis *xaxis, int npanels,
                   const ts_plot_axis panels[], int nseries,
                   const ts_plot_series series[], const ts_plot_opts *opts,
                   ts_err *err)
{
    CALL_MODULE(panels, dir, name, title, xaxis, npanels, panels, nseries,
                series, opts, err);
}

int ts_plot_map(const char *dir, const char *name, const char *title,
                const ts_plot_axis *xaxis, const ts_plot_axis *yaxis,
                const ts_plot_axis *zaxis, const ts_plot_grid *grid,
                const int *marks, int nb, const double *bx, const double *by,
                const ts_plot_opts *opts, ts_err *err)
{
    CALL_MODULE(map, dir, name, title, xaxis, yaxis, zaxis, grid, marks, nb,
                bx, by, opts, err);
}
