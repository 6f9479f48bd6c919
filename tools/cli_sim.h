/* cli_sim.h: the settings of a time-domain simulation as the command line
 * and scene entries give them (tools only): `towstab simulate` and the
 * simulate analysis of `towstab converge` read them the same way
 * (doc/simulate.md, doc/converge.md). Settings come from the command line,
 * else from a scene's `simulate` entry, else defaults. */
#ifndef TOWSTAB_CLI_SIM_H
#define TOWSTAB_CLI_SIM_H

#include "cli.h"
#include "towstab/excitation.h"
#include "towstab/response.h"
#include "towstab/simulate.h"

/* Default sample interval when none is given (s), the samples per period
 * it guarantees for a periodic excitation, and the default run length (s). */
#define CLI_SIM_DEFAULT_SAMPLE 0.05
#define CLI_SIM_DEFAULT_SAMPLES_PER_PERIOD 16
#define CLI_SIM_DEFAULT_T_END 10.0
/* Link lengths of a shape file must match the scene's to this (relative). */
#define CLI_SIM_SHAPE_RTOL 1e-6
/* --excite and --manoeuvre given at most this many times each. */
#define CLI_SIM_MAX_SPECS 32

/* The settings, by index. */
enum {
    SIM_A_T_END, SIM_A_SAMPLE, SIM_A_INITIAL, SIM_A_INTEGRATOR, SIM_A_RTOL,
    SIM_A_ATOL, SIM_A_H_MIN, SIM_A_MAX_STEPS, SIM_A_TRANSIENT, SIM_A_OUTPUT,
    SIM_A_LINEAR_METHOD, SIM_A_KINEMATICS, SIM_A_EXCITE, SIM_A_MANOEUVRE,
    SIM_A_COMPARE, SIM_A_LINEAR, SIM_A_CSV, SIM_A_N
};
/* Scene option keys and command-line options, in the order above. */
extern const char *const cli_sim_arg_keys[SIM_A_N];
extern const char *const cli_sim_arg_opts[SIM_A_N];

/* The settings as text; where[i] names their origin for messages (the
 * option, or "analyses[K].key (line L)"). */
typedef struct cli_sim_args {
    const char *val[SIM_A_N];
    char where[SIM_A_N][128];
    /* --excite and --manoeuvre may repeat (and hold ';'-separated lists). */
    const char *specs[2][CLI_SIM_MAX_SPECS];
    int nspecs[2];
    int quiet;
    const char *json;   /* command line only */
} cli_sim_args;

/* The settings parsed (system-independent parts, and the output). */
typedef struct cli_sim_setup {
    ts_sim_opts o;
    double transient;
    int compare, linear_only;
    enum { SIM_INIT_EQ, SIM_INIT_RELEASED, SIM_INIT_SHAPE } init;
    double theta1, theta2;
    char init_text[256];
    const char *shape_path;
    ts_output out;
} cli_sim_setup;

/* Everything a run needs that can be checked without running. */
typedef struct cli_sim_prep {
    ts_system *sys;
    ts_equilibrium_opts eo;
    ts_excitation *ex;
    cli_sim_setup s;
} cli_sim_prep;

/* Fill arguments missing from the command line (val[i] NULL, no specs)
 * with those of scene entry e (analyses[index]). */
void cli_sim_args_from_entry(cli_sim_args *a, const ts_scene_analysis *e,
                             int index);

/* Build the system (with the settings cs) and the excitation, parse every
 * setting and resolve the output (default: the last sphere's .z), checking
 * what a comparison will need. Prints nothing; the message is in err.
 * Release p with cli_sim_prep_free (also after a failure). */
int cli_sim_prepare(const cli_ctx *ctx, const cli_sim_args *a,
                    const cli_settings *cs, cli_sim_prep *p, ts_err *err);
void cli_sim_prep_free(cli_sim_prep *p);

#endif
