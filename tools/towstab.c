/* towstab: the command line. One subcommand per analysis (tools/cmd_*.c);
 * each prints a table and optionally writes JSON or CSV (SI units).
 * Exit status: 0 success, 1 the analysis failed (no convergence, singular
 * system, output not written), 2 bad input (usage, scene, units, an
 * impossible configuration). Standard output and standard error are
 * checked when the command ends: a table that could not be written is a
 * failure too. The manual is doc/manual.md. */
#define _POSIX_C_SOURCE 200809L /* setenv */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "malloc_policy.h"

extern const cli_command cli_cmd_equilibrium, cli_cmd_run;
extern const cli_command cli_cmd_modes, cli_cmd_response;
extern const cli_command cli_cmd_simulate;
extern const cli_command cli_cmd_converge;
extern const cli_command cli_cmd_report;
extern const cli_command cli_cmd_sweep, cli_cmd_design;

/* `towstab options`: every analysis' option table as markdown, the
 * reference of doc/manual.md. */
static int options_main(int argc, char **argv)
{
    (void)argv;
    if (argc != 1) {
        fprintf(stderr, "towstab: error: options: takes no arguments\n");
        return EXIT_BADINPUT;
    }
    cli_options_markdown(stdout);
    return 0;
}

static const cli_command cli_cmd_options = {
    "options", "every option of the analyses, as a markdown reference", -1,
    options_main, NULL, NULL, NULL, NULL, NULL, NULL, NULL};

const cli_command *const cli_commands[] = {&cli_cmd_equilibrium, &cli_cmd_run,
                                           &cli_cmd_modes, &cli_cmd_response,
                                           &cli_cmd_simulate,
                                           &cli_cmd_converge,
                                           &cli_cmd_report,
                                           &cli_cmd_sweep, &cli_cmd_design,
                                           &cli_cmd_options, NULL};

static void usage(FILE *f)
{
    fprintf(f, "usage: towstab COMMAND SCENE [options]\n\ncommands:\n");
    for (int i = 0; cli_commands[i]; i++)
        fprintf(f, "  %-12s %s\n", cli_commands[i]->name,
                cli_commands[i]->summary);
    fprintf(f, "\n'towstab COMMAND --help' lists a command's options.\n"
               "Plain numbers are SI; strings may carry units ('100 ft').\n"
               "Exit status: 0 ok, 1 analysis failed, 2 bad input,\n"
               "130 or 143 stopped by SIGINT or SIGTERM.\n");
}

/* OpenBLAS on one thread unless OPENBLAS_NUM_THREADS (or
 * GOTO_NUM_THREADS) asks otherwise: the BLAS work of the analyses is
 * vector operations (ARPACK's orthogonalisation, the error estimates'
 * products), where a second thread costs more in waking and spinning than
 * it saves; a large dense LAPACK eigen analysis may ask for more (doc/
 * performance.md). LAPACK (OpenBLAS) is opened only when a run first uses
 * it (lib/lazylib.h) and reads the variable then, as it starts: set here,
 * before anything opens it, it starts no thread pool at all. Another
 * BLAS ignores the variable. */
static void blas_threads(void)
{
    if (!getenv("OPENBLAS_NUM_THREADS") && !getenv("GOTO_NUM_THREADS"))
        setenv("OPENBLAS_NUM_THREADS", "1", 0);
}

int main(int argc, char **argv)
{
    blas_threads();
    towstab_malloc_policy();
    if (argc < 2) {
        fprintf(stderr, "towstab: error: no command given (a COMMAND and a "
                        "SCENE file)\n");
        usage(stderr);
        return cli_finish(EXIT_BADINPUT);
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return cli_finish(0);
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("towstab " TOWSTAB_VERSION "\n");
        return cli_finish(0);
    }
    cli_signals_install();
    /* `--json -`: keep standard output for the JSON alone. */
    for (int i = 2; i < argc; i++)
        if ((strcmp(argv[i], "--json") == 0 && i + 1 < argc &&
             strcmp(argv[i + 1], "-") == 0) ||
            strcmp(argv[i], "--json=-") == 0)
            cli_stdout_for_json();
    for (int i = 0; cli_commands[i]; i++)
        if (strcmp(argv[1], cli_commands[i]->name) == 0)
            return cli_finish(
                cli_commands[i]->main
                    ? cli_commands[i]->main(argc - 1, argv + 1)
                    : cli_main(cli_commands[i], argc - 1, argv + 1));
    fprintf(stderr, "towstab: error: unknown command '%s' (towstab --help)\n",
            argv[1]);
    return cli_finish(EXIT_BADINPUT);
}
