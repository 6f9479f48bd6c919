/* dlmodule.c: opening towstab's modules (dlmodule.h). */
#define _GNU_SOURCE /* dladdr, RTLD_NODELETE, secure_getenv */
#include "dlmodule.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* An object of the library: dladdr maps its address to the file the
 * library was loaded from. */
static const char library_anchor = 0;

/* Defined only in the programs of the build tree linked to the static
 * archive (dlmodule_build.c): the directory of this build's modules. A
 * weak, hidden reference: in the shared library and in any other program
 * it is absent and its address is NULL. */
extern const char *const tsi_module_build_dir
    __attribute__((weak, visibility("hidden")));

/* What a module that cannot be used asks for: the installation is
 * incomplete or mixed, which is no fault of the run's input. */
#define REPAIR "reinstall towstab, or rebuild it (the modules are built " \
               "and installed with the library)"

/* Open the module at `path` and check its table. `also` ends the message
 * of a file that cannot be opened; `fix` says how to repair it. */
static int open_path(tsi_module *m, const char *what, const char *path,
                     const char *also, const char *fix, const char *symbol,
                     int version, ts_err *err)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!h) {
        const char *why = dlerror();
        return ts_fail(err, TS_EIO, "cannot load the %s %s: %s%s: %s", what,
                       path, why ? why : "no reason given", also, fix);
    }
    const tsi_module_head *t = dlsym(h, symbol);
    if (!t) {
        /* The reason first: dlclose may reuse dlerror's text. */
        const char *why = dlerror();
        int rc = ts_fail(err, TS_EIO, "%s is not a towstab %s: %s: %s", path,
                         what, why ? why : "no table", fix);
        dlclose(h);
        return rc;
    }
    if (t->version != version ||
        strcmp(t->release, TSI_MODULE_RELEASE) != 0) {
        int rc = ts_fail(err, TS_EIO,
                         "the %s %s is of towstab %s (table %d), the "
                         "library of %s (table %d): %s",
                         what, path, t->release, t->version,
                         TSI_MODULE_RELEASE, version, fix);
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

int tsi_module_open(tsi_module *m, const char *what, const char *file,
                    const char *env, const char *symbol, int version,
                    ts_err *err)
{
    m->handle = NULL;
    m->table = NULL;
    char also[4 * PATH_MAX];
    const char *forced = secure_getenv(env);
    if (forced && forced[0]) {
        char fix[128];
        snprintf(also, sizeof also, " (%s)", env);
        snprintf(fix, sizeof fix, "unset %s, or set it to the %s of this "
                 "towstab", env, what);
        return open_path(m, what, forced, also, fix, symbol, version, err);
    }
    char dir[PATH_MAX], where[3][PATH_MAX + 64], installed[PATH_MAX + 64];
    int n = 0;
    library_dir(dir, sizeof dir);
    if (dir[0]) {
        snprintf(where[n++], sizeof where[0], "%s/%s", dir, file);
        snprintf(where[n++], sizeof where[0], "%s/towstab/%s", dir, file);
    }
    if (&tsi_module_build_dir != NULL)
        snprintf(where[n++], sizeof where[0], "%s/%s", tsi_module_build_dir,
                 file);
    for (int i = 0; i < n; i++)
        if (access(where[i], F_OK) == 0)
            return open_path(m, what, where[i], "", REPAIR, symbol, version,
                             err);
    /* Else where it is installed; when not there either, the message says
     * where else it was looked for. */
    snprintf(installed, sizeof installed, "%s/%s", TS_MODULE_DIR, file);
    size_t used = 0;
    also[0] = '\0';
    for (int i = 0; i < n && used < sizeof also; i++)
        used += (size_t)snprintf(also + used, sizeof also - used, "%s%s%s",
                                 i == 0 ? " (nor is it at " : " or ",
                                 where[i], i == n - 1 ? ")" : "");
    return open_path(m, what, installed, also, REPAIR, symbol, version, err);
}

void tsi_module_close(tsi_module *m)
{
    if (m->handle)
        dlclose(m->handle);
    m->handle = NULL;
    m->table = NULL;
}
