/* mpi_module.c: the MPI side of a sweep across processes (tools/cli_mpi.h),
 * built as a module of its own (towstab-mpi.so) that tools/cli_mpi.c
 * opens only when the process was started by mpirun, so that every other
 * run of towstab does without loading MPI (doc/performance.md,
 * "Start-up").
 *
 * Threads: the sweep calls back from one thread at a time (its callbacks
 * sit in one critical section), so MPI_THREAD_SERIALIZED is asked for;
 * when the library offers less, MPI is ended and the sweep refused.
 * Messages are small and few (one per chain), sent with blocking MPI_Send
 * and taken by process 0 with MPI_Iprobe between its own chains. The
 * tool's state: one process, one command.
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_mpi_module.h"

enum { TAG_RECORD = 1, TAG_END = 2, TAG_STOP = 3 };

static int started, rank, size = 1, stopped;

static int mod_init(int *argc, char ***argv)
{
    int provided = 0;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided) !=
        MPI_SUCCESS) {
        fprintf(stderr, "towstab: error: MPI did not start\n");
        return 1;
    }
    started = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (provided < MPI_THREAD_SERIALIZED) {
        if (rank == 0)
            fprintf(stderr, "towstab: error: this MPI library does not "
                            "allow calls from several threads "
                            "(MPI_THREAD_SERIALIZED)\n");
        MPI_Finalize();
        started = 0;
        return 1;
    }
    return 0;
}

static int mod_rank(void) { return rank; }
static int mod_size(void) { return size; }

static void mod_finalize(void)
{
    if (started)
        MPI_Finalize();
    started = 0;
}

static void mod_abort(int status)
{
    if (started)
        MPI_Abort(MPI_COMM_WORLD, status);
}

static int mod_send_record(const char *text)
{
    if (!started || rank == 0)
        return 0;
    return MPI_Send(text, (int)strlen(text) + 1, MPI_CHAR, 0, TAG_RECORD,
                    MPI_COMM_WORLD) == MPI_SUCCESS
               ? 0
               : -1;
}

static int mod_send_end(int status)
{
    if (!started || rank == 0)
        return 0;
    return MPI_Send(&status, 1, MPI_INT, 0, TAG_END, MPI_COMM_WORLD) ==
                   MPI_SUCCESS
               ? 0
               : -1;
}

static int mod_send_stop(void)
{
    if (!started || rank != 0)
        return 0;
    int one = 1;
    for (int r = 1; r < size; r++)
        MPI_Send(&one, 1, MPI_INT, r, TAG_STOP, MPI_COMM_WORLD);
    return 0;
}

static int mod_poll(int wait, int (*on_record)(const char *text, void *data),
                 void *data, int *ends, int *worst)
{
    int status = 0;
    while (started && rank == 0) {
        MPI_Status st;
        int flag = 0;
        if (wait && *ends >= size - 1)
            break;
        if (wait) {
            MPI_Probe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
            flag = 1;
        } else {
            MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag,
                       &st);
        }
        if (!flag)
            break;
        if (st.MPI_TAG == TAG_END) {
            int s = 0;
            MPI_Recv(&s, 1, MPI_INT, st.MPI_SOURCE, TAG_END, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
            (*ends)++;
            if (s > *worst)
                *worst = s;
            continue;
        }
        int n = 0;
        MPI_Get_count(&st, MPI_CHAR, &n);
        char *text = malloc((size_t)(n > 0 ? n : 1));
        if (!text) {
            fprintf(stderr, "towstab: error: sweep: out of memory for a "
                            "record\n");
            mod_abort(1);
            return 1;
        }
        MPI_Recv(text, n, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG,
                 MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        text[n > 0 ? n - 1 : 0] = '\0';
        if (!status && on_record)
            status = on_record(text, data);
        free(text);
    }
    return status;
}

static int mod_stopped(void)
{
    if (!started || rank == 0 || stopped)
        return stopped;
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(0, TAG_STOP, MPI_COMM_WORLD, &flag, &st);
    if (flag) {
        int one;
        MPI_Recv(&one, 1, MPI_INT, 0, TAG_STOP, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        stopped = 1;
    }
    return stopped;
}

static int mod_broadcast(void *buf, size_t n)
{
    if (!started)
        return 0;
    /* In pieces: an int counts the bytes of one call. */
    const size_t piece = 1u << 30;
    for (size_t at = 0; at < n; at += piece) {
        size_t m = n - at < piece ? n - at : piece;
        if (MPI_Bcast((char *)buf + at, (int)m, MPI_BYTE, 0,
                      MPI_COMM_WORLD) != MPI_SUCCESS)
            return -1;
    }
    return 0;
}

/* What the loader looks up (CLI_MPI_MODULE_SYMBOL). */
__attribute__((visibility("default"))) const cli_mpi_module
    towstab_mpi_module = {
        CLI_MPI_MODULE_VERSION, mod_init, mod_rank, mod_size,
        mod_finalize, mod_abort, mod_send_record, mod_send_end,
        mod_send_stop, mod_poll, mod_stopped, mod_broadcast};
