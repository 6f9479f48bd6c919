/* dlmodule.h (internal): opening a module of towstab's own, a shared
 * object that carries a heavy dependency the library loads only when a
 * run needs it: the drawing module (towstab-plot.so: PLplot, and through
 * its cairo driver cairo, pango and fontconfig) and the SUNDIALS module
 * (towstab-sundials.so: ARKODE, CVODE). doc/performance.md, "Start-up".
 *
 * A module exports one table under a name of its own; the table starts
 * with a tsi_module_head, checked against the library's: the table's
 * version and the release of towstab both were built from (a module of
 * another build is refused). Each use opens the module with dlopen and
 * closes it when done; it is opened with RTLD_NODELETE, so only the first
 * opening of a process maps it and later ones find it loaded. Nothing is
 * kept here: the dynamic loader holds the module.
 *
 * Where a module FILE is looked for, the first that exists:
 *  1. the file named by the environment variable ENV, when set: that file
 *     and no other (ignored in a set-user-ID process; the tests name the
 *     build's modules so);
 *  2. beside the file the library was loaded from (the build tree, where
 *     build/lib holds the library and its modules), then in its towstab/
 *     subdirectory (an installed tree, wherever it was moved); the
 *     library's file is found with dladdr on an object of its own, not
 *     with $ORIGIN in dlopen's name, which glibc expands from the caller
 *     of dlopen: under AddressSanitizer the sanitizer's interceptor;
 *  3. in a program of the build tree linked to the static archive (the
 *     tests and benchmarks), whose file is the program's own: the build's
 *     lib/ directory (dlmodule_build.c);
 *  4. TS_MODULE_DIR/FILE, where meson installs it (any other program
 *     linked to the static archive).
 * When none can be opened, TS_EIO names the file, the dynamic loader's
 * reason (dlerror) and the repair: a module that is missing, broken or of
 * another build is a fault of the installation, not of a run's input. */
#ifndef TOWSTAB_LIB_DLMODULE_H
#define TOWSTAB_LIB_DLMODULE_H

#include "towstab/error.h"

/* The build passes TSI_MODULE_RELEASE (the project version) to the
 * library and to every module. */
#ifndef TSI_MODULE_RELEASE
#define TSI_MODULE_RELEASE "unknown"
#endif

/* The start of every module's table. */
typedef struct tsi_module_head {
    int version;         /* the table's layout, the module's own number */
    const char *release; /* TSI_MODULE_RELEASE of the module's build */
} tsi_module_head;

/* An open module. */
typedef struct tsi_module {
    void *handle;
    const void *table; /* starts with a tsi_module_head */
} tsi_module;

/* Open module `file` (e.g. "towstab-plot.so"), called `what` in messages
 * ("plotting module"), looked for as above with the environment variable
 * `env`, and find its table `symbol` of layout `version`. TS_OK, or
 * TS_EIO with the file, the reason and the repair in err (m is then not
 * open). */
int tsi_module_open(tsi_module *m, const char *what, const char *file,
                    const char *env, const char *symbol, int version,
                    ts_err *err);

/* Close what tsi_module_open opened (the module stays loaded). */
void tsi_module_close(tsi_module *m);

#endif
