/* cli_mpi_module.h: the table of functions the MPI module
 * (tools/mpi_module.c, towstab-mpi.so) exports under the name
 * CLI_MPI_MODULE_SYMBOL, and tools/cli_mpi.c calls through once it has
 * opened the module. Each entry does what the cli_mpi_* function of the
 * same name does (cli_mpi.h) for a process started by mpirun; init also
 * starts MPI. A module whose version differs from the loader's is
 * refused. */
#ifndef TOWSTAB_CLI_MPI_MODULE_H
#define TOWSTAB_CLI_MPI_MODULE_H

#include <stddef.h>

#define CLI_MPI_MODULE_SYMBOL "towstab_mpi_module"
#define CLI_MPI_MODULE_VERSION 1

typedef struct cli_mpi_module {
    int version; /* CLI_MPI_MODULE_VERSION */
    int (*init)(int *argc, char ***argv);
    int (*rank)(void);
    int (*size)(void);
    void (*finalize)(void);
    void (*abort)(int status);
    int (*send_record)(const char *text);
    int (*send_end)(int status);
    int (*send_stop)(void);
    int (*poll)(int wait, int (*on_record)(const char *text, void *data),
                void *data, int *ends, int *worst);
    int (*stopped)(void);
    int (*broadcast)(void *buf, size_t n);
} cli_mpi_module;

#endif
