/* cli_mpi.h: a sweep across processes with MPI (tools only; the library
 * knows nothing of MPI). Built with Debian's OpenMPI when found (meson
 * option mpi) as a module, towstab-mpi.so (tools/mpi_module.c), that
 * cli_mpi_init opens under mpirun only; otherwise every function here
 * says there is one process.
 *
 * `mpirun -np N towstab sweep ...` starts N processes. Each runs its share
 * of the sweep's chains (chain c on process c mod N; towstab/sweep.h) and
 * sends every finished chain to process 0 as a record
 * (towstab/report_sweep.h); process 0 restores them, keeps the resume
 * file, prints and writes the table. The crossings of the stability
 * boundary are shared out the same way once process 0 has the whole grid
 * and has sent every process the points' verdicts. Processes other than
 * 0 print nothing on standard output.
 */
#ifndef TOWSTAB_CLI_MPI_H
#define TOWSTAB_CLI_MPI_H

#include <stddef.h>

/* Start MPI when the process was started by mpirun (OpenMPI or PMIx in
 * the environment), with calls from one thread at a time. Returns 0, or
 * the exit status after printing when MPI could not start. */
int cli_mpi_init(int *argc, char ***argv);
/* This process's rank and the number of processes (0 and 1 without
 * MPI). */
int cli_mpi_rank(void);
int cli_mpi_size(void);
/* End MPI (when it was started). */
void cli_mpi_finalize(void);
/* Stop every process at once with `status` (after an error on one). */
void cli_mpi_abort(int status);

/* Messages between the processes: a record (text) of a finished chain,
 * sent to process 0; the end of a process's share, with its status
 * (0 finished, else the exit status it stopped with); a request from
 * process 0 that the others stop. */
int cli_mpi_send_record(const char *text);
int cli_mpi_send_end(int status);
int cli_mpi_send_stop(void);

/* Process 0: take the messages that have arrived (wait: until every other
 * process has sent its end): records go to `on_record` (a nonzero return
 * stops the sweep: it is passed on as the status), ends are counted;
 * *ends receives how many processes have ended so far and *worst the
 * largest status they ended with. Returns 0 or on_record's status. */
int cli_mpi_poll(int wait, int (*on_record)(const char *text, void *data),
                 void *data, int *ends, int *worst);

/* The others: 1 once process 0 asked to stop. */
int cli_mpi_stopped(void);

/* Process 0 sends n bytes to every process (the others receive them into
 * buf[n]). Returns 0, or -1. */
int cli_mpi_broadcast(void *buf, size_t n);

#endif
