/* towstab/progress.h: progress reports from long runs, and stopping them.
 *
 * A long analysis (a simulation, a convergence sweep, an equilibrium by
 * Newton, an ARPACK eigensolve, a sea-state response) takes an optional
 * callback in its options (ts_sim_opts.progress, ts_convergence.progress,
 * ts_equilibrium_opts.progress, ts_eigen_opts.progress,
 * ts_seastate_opts.progress) and calls it as it goes: after every
 * accepted integrator step, after every run of a sweep, every Jacobian
 * column, every operator application, every frequency. The callback is
 * given what is done and of how much; a nonzero return asks the run to
 * stop. It then stops at once, at a state it can report (the last accepted
 * step, the last finished run, the Newton iterate reached), keeps what it
 * has computed and returns TS_ECANCEL with a message saying
 * how far it got. The callback must be cheap (it may be called millions of
 * times) and must not call back into the run. A run on several threads
 * calls it from one thread at a time, not always the caller's. Nothing is
 * global: whatever
 * the callback needs is in its `data`; a command line, for example, lets
 * its signal handler set a flag that its callback returns.
 */
#ifndef TOWSTAB_PROGRESS_H
#define TOWSTAB_PROGRESS_H

#ifdef __cplusplus
extern "C" {
#endif

/* How far a run is. */
typedef struct ts_progress {
    const char *what;   /* the run: "nonlinear", "linear", "sweep" */
    double done;        /* what is done, in `unit` */
    double total;       /* of this much (> 0); NAN when no end is known
                           (an iterative solver's work: no fraction or
                           time left can be given) */
    const char *unit;   /* "s" (simulated time), "runs", "frequencies",
                           "Jacobian columns", "operator applications",
                           "shifts" */
} ts_progress;

/* Called with the progress so far; returns 0 to go on, nonzero to stop. */
typedef int (*ts_progress_fn)(const ts_progress *p, void *data);

#ifdef __cplusplus
}
#endif
#endif
