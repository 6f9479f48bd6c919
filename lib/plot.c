/* plot.c: pictures of results (towstab/plot.h, doc/plots.md): the loader
 * of the drawing module.
 *
 * The drawing itself (lib/plot_draw.c) is a module of its own,
 * towstab-plot.so, linked to PLplot and through it to cairo, pango,
 * fontconfig, freetype and a dozen more; the library is not. Each drawing
 * function, and ts_plot_check, opens the module with dlopen, calls the
 * entry of the same name in its table (plot_module.h) and closes it
 * again. The module is opened with RTLD_NODELETE, so only the first call
 * of a process maps it (and PLplot); later calls find it loaded and cost
 * a lookup. A run that draws nothing loads none of it (doc/performance.md,
 * "Start-up"). No state is kept here: the dynamic loader keeps the module.
 *
 * Where the module is looked for, the first that exists:
 *  1. TOWSTAB_PLOT_MODULE, when set: that file and no other (an
 *     environment variable, ignored in a set-user-ID process);
 *  2. beside the file the library was loaded from (the build tree:
 *     build/lib holds both), then in its towstab/ subdirectory (an
 *     installed tree, moved or not: LIBDIR/towstab holds the modules),
 *     both found with dladdr on an object of the library. Not $ORIGIN in
 *     dlopen's name: glibc expands it from the caller of dlopen, which
 *     under AddressSanitizer is the sanitizer's interceptor;
 *  3. TS_PLOT_MODULE, where meson installs it (a program linked to the
 *     static archive, whose file is the program's own).
 * When none can be opened, the message names the file and the dynamic
 * loader's reason (dlerror), and nothing is drawn or written.
 *
 * The pure parts (options, units, the output directory, outline motion)
 * are in lib/plot_geom.c and need no module.
 */
#define _GNU_SOURCE /* dladdr, RTLD_NODELETE, secure_getenv */
#include "towstab/plot.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef TS_HAVE_PLPLOT
#include <dlfcn.h>
#include <limits.h>
#endif

#include "plot_module.h"

#define NO_PLPLOT_MSG                                                         \
    "towstab was built without PLplot; install libplplot-dev and "           \
    "plplot-driver-cairo and rebuild"

/* An open module: the handle to close and its table. */
typedef struct module {
    void *handle;
    const tsi_plot_module *table;
} module;

#ifdef TS_HAVE_PLPLOT

/* An object of the library: dladdr maps its address to the file the
 * library was loaded from. */
static const char library_anchor = 0;

/* Open the module at `path`, check its table. TS_EDOMAIN naming the file
 * and the reason when it cannot be used; `also` ends the message of a file
 * that cannot be opened. */
static int open_path(const char *path, const char *also, module *m,
                     ts_err *err)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!h) {
        const char *why = dlerror();
        return ts_fail(err, TS_EDOMAIN,
                       "cannot load the plotting module %s: %s%s", path,
                       why ? why : "no reason given", also);
    }
    const tsi_plot_module *t = dlsym(h, TSI_PLOT_MODULE_SYMBOL);
    if (!t) {
        /* The reason first: dlclose may reuse dlerror's text. */
        const char *why = dlerror();
        int rc = ts_fail(err, TS_EDOMAIN,
                         "%s is not a towstab plotting module: %s", path,
                         why ? why : "no table " TSI_PLOT_MODULE_SYMBOL);
        dlclose(h);
        return rc;
    }
    if (t->version != TSI_PLOT_MODULE_VERSION ||
        strcmp(t->release, TSI_PLOT_RELEASE) != 0) {
        int version = t->version;
        const char *release = t->release;
        int rc = ts_fail(err, TS_EDOMAIN,
                         "the plotting module %s is of towstab %s (table "
                         "%d), the library of %s (table %d): install them "
                         "together",
                         path, release, version, TSI_PLOT_RELEASE,
                         TSI_PLOT_MODULE_VERSION);
        dlclose(h);
        return rc;
    }
    m->handle = h;
    m->table = t;
    return TS_OK;
}

/* The directory of the library's file into dir (without the final
 * '/'), or "" when dladdr does not say. */
static void library_dir(char *dir, size_t size)
{
    Dl_info info;
    dir[0] = '\0';
    if (!dladdr(&library_anchor, &info) || !info.dli_fname)
        return;
    const char *slash = strrchr(info.dli_fname, '/');
    if (!slash || (size_t)(slash - info.dli_fname) >= size)
        return;
    memcpy(dir, info.dli_fname, (size_t)(slash - info.dli_fname));
    dir[slash - info.dli_fname] = '\0';
}

static int module_open(module *m, ts_err *err)
{
    const char *forced = secure_getenv("TOWSTAB_PLOT_MODULE");
    if (forced && forced[0])
        return open_path(forced, " (TOWSTAB_PLOT_MODULE)", m, err);
    char dir[PATH_MAX], where[2][PATH_MAX + 32], also[2 * PATH_MAX + 96];
    int n = 0;
    library_dir(dir, sizeof dir);
    if (dir[0]) {
        snprintf(where[n++], sizeof where[0], "%s/%s", dir,
                 TSI_PLOT_MODULE_FILE);
        snprintf(where[n++], sizeof where[0], "%s/towstab/%s", dir,
                 TSI_PLOT_MODULE_FILE);
    }
    for (int i = 0; i < n; i++)
        if (access(where[i], F_OK) == 0)
            return open_path(where[i], "", m, err);
    /* Else where it is installed; when not there either, the message says
     * where else it was looked for. */
    also[0] = '\0';
    if (n == 2)
        snprintf(also, sizeof also, " (nor is it at %s or %s)", where[0],
                 where[1]);
    return open_path(TS_PLOT_MODULE, also, m, err);
}

static void module_close(module *m) { dlclose(m->handle); }

#else /* no PLplot */

static int module_open(module *m, ts_err *err)
{
    m->handle = NULL;
    m->table = NULL;
    return ts_fail(err, TS_EDOMAIN, NO_PLPLOT_MSG);
}

static void module_close(module *m) { (void)m; }

#endif

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
