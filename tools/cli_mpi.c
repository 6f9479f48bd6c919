/* cli_mpi.c: a sweep across processes with MPI (cli_mpi.h): the loader.
 *
 * MPI is started only when the process was launched by mpirun (its
 * environment names a rank), so that a build with MPI runs alone exactly
 * as one without. Only then is the MPI module (tools/mpi_module.c,
 * towstab-mpi.so) opened with dlopen: first beside the executable (the
 * build tree; its directory read from /proc/self/exe, not $ORIGIN in
 * dlopen's name, which glibc expands from the caller of dlopen: under
 * AddressSanitizer the sanitizer's interceptor), then where it is
 * installed (TS_MPI_MODULE). Every other
 * run loads neither the module nor MPI's libraries, which would cost
 * several of the few milliseconds a small analysis takes (doc/
 * performance.md, "Start-up"). Without the module (a build without MPI,
 * or before cli_mpi_init) every function says there is one process.
 */
#include "cli_mpi.h"

#include <stdio.h>
#include <stdlib.h>

#ifdef TS_MPI_MODULE
#include <dlfcn.h>
#include <limits.h>
#include <string.h>
#include <unistd.h>
#endif

#include "cli.h"
#include "cli_mpi_module.h"

/* The tool's state (one process, one command): the module's table once
 * opened and MPI started (NULL: one process). */
static const cli_mpi_module *mod;

#ifdef TS_MPI_MODULE
/* The module beside the running executable into path, or "" when its
 * directory is not known. */
static void beside_executable(char *path, size_t size)
{
    static const char file[] = "/towstab-mpi.so";
    ssize_t n = readlink("/proc/self/exe", path, size - sizeof file);
    char *slash = NULL;
    if (n > 0) {
        path[n] = '\0';
        slash = strrchr(path, '/');
    }
    if (!slash) {
        path[0] = '\0';
        return;
    }
    memcpy(slash, file, sizeof file);
}

/* Open the module and check its table; prints why not and returns NULL
 * when it cannot. */
static const cli_mpi_module *open_module(void)
{
    char beside[PATH_MAX];
    beside_executable(beside, sizeof beside);
    const char *const where[] = {beside, TS_MPI_MODULE};
    const char *why = "";
    for (size_t i = 0; i < sizeof where / sizeof where[0]; i++) {
        if (!where[i][0])
            continue;
        /* Global: MPI's own plugins look up its symbols. */
        void *h = dlopen(where[i], RTLD_NOW | RTLD_GLOBAL);
        if (!h) {
            why = dlerror();
            continue;
        }
        const cli_mpi_module *m = dlsym(h, CLI_MPI_MODULE_SYMBOL);
        if (m && m->version == CLI_MPI_MODULE_VERSION)
            return m;
        why = m ? "a module of another version" : dlerror();
        dlclose(h);
    }
    fprintf(stderr, "towstab: error: mpirun: cannot open the MPI module "
                    "towstab-mpi.so (beside the executable or %s): %s\n",
            TS_MPI_MODULE, why ? why : "unknown reason");
    return NULL;
}
#endif

int cli_mpi_init(int *argc, char ***argv)
{
    if (!getenv("OMPI_COMM_WORLD_SIZE") && !getenv("PMIX_RANK") &&
        !getenv("PMI_RANK"))
        return 0;
#ifdef TS_MPI_MODULE
    const cli_mpi_module *m = open_module();
    if (!m)
        return EXIT_FAILED;
    int status = m->init(argc, argv);
    if (status == 0)
        mod = m;
    return status;
#else
    (void)argc;
    (void)argv;
    return 0;
#endif
}

int cli_mpi_rank(void) { return mod ? mod->rank() : 0; }
int cli_mpi_size(void) { return mod ? mod->size() : 1; }

void cli_mpi_finalize(void)
{
    if (mod)
        mod->finalize();
    mod = NULL;
}

void cli_mpi_abort(int status)
{
    if (mod)
        mod->abort(status);
}

int cli_mpi_send_record(const char *text)
{
    return mod ? mod->send_record(text) : 0;
}

int cli_mpi_send_end(int status) { return mod ? mod->send_end(status) : 0; }
int cli_mpi_send_stop(void) { return mod ? mod->send_stop() : 0; }

int cli_mpi_poll(int wait, int (*on_record)(const char *text, void *data),
                 void *data, int *ends, int *worst)
{
    return mod ? mod->poll(wait, on_record, data, ends, worst) : 0;
}

int cli_mpi_stopped(void) { return mod ? mod->stopped() : 0; }

int cli_mpi_broadcast(void *buf, size_t n)
{
    return mod ? mod->broadcast(buf, n) : 0;
}
