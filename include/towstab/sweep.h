/* towstab/sweep.h: operating envelopes: one analysis over a grid of scene
 * values, with continuation, in parallel, and the stability boundary
 * (doc/sweep.md).
 *
 * A sweep runs the pipeline of one analysis (equilibrium, modes, response
 * or simulate; towstab/analysis.h) at every point of a grid of 1 to
 * TS_SWEEP_MAX_AXES scene values given by path (towstab/param.h:
 * tow.speed, cables.main.length, bodies.fish.mass). Every point is
 * exactly the request with its values set (ts_setup_set) and so exactly
 * what the single command computes at those settings; it records the
 * result's columns (the equilibrium's key values, the analysis' own, and
 * for modes the stability margin max Re(lambda) of the resolved modes,
 * towstab/accuracy.h ts_stability), each with its error
 * estimate {discretisation, solver}, the verdict, the cost and whether it
 * failed.
 *
 * Points are numbered with the last axis fastest. The grid is cut into
 * chains: runs of at most `chain` consecutive points along the last axis
 * (a line is cut into ceil(n / chain) chains of near-equal length). The
 * first point of a chain starts cold, as the single command does; every
 * other point starts its equilibrium from the previous point's
 * (continuation, towstab/equilibrium.h opts.guess). A chain is the unit
 * of work: chains run in parallel over OpenMP threads, and may run on
 * different processes (ts_sweep_run_chain), and the result of a chain
 * depends on the chain alone, so a sweep's table is the same point for
 * point, to the last bit, whatever the number of threads or processes.
 * A continued point agrees with the cold single run within its solver
 * error estimate (rounding of the solver's last iterate); `chain` 1 makes
 * every point a cold start, equal to the single run bit for bit.
 *
 * The stability boundary (modes): between two neighbouring grid points
 * (along any axis) of which one is unstable (max Re(lambda) of the
 * resolved modes above its error bounds) and the other completed and not
 * unstable, the crossing is
 * found by bisection along that axis, the other values fixed, until the
 * bracket is below boundary_rtol of the grid step. Each crossing is a
 * chain of its own (its runs continue from one another).
 *
 * Memory: O(points x columns). Nothing here prints or writes files;
 * towstab/report_sweep.h writes tables and restores points (resume).
 * The analyses run inside a sweep take no progress callback of their
 * own: the sweep's is called between chains (and polled during long
 * runs) from one thread at a time.
 */
#ifndef TOWSTAB_SWEEP_H
#define TOWSTAB_SWEEP_H

#include "towstab/analysis.h"
#include "towstab/error.h"
#include "towstab/param.h"
#include "towstab/progress.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_SWEEP_MAX_AXES 4
/* Points of one sweep, at most. */
#define TS_SWEEP_MAX_POINTS 1000000
/* Points per continuation chain by default, at most. */
#define TS_SWEEP_CHAIN 8
/* A crossing is bisected until its bracket is below this fraction of the
 * grid step along its axis. */
#define TS_SWEEP_BOUNDARY_RTOL 1e-3
/* and never more than this many runs. */
#define TS_SWEEP_BOUNDARY_MAX_RUNS 60
/* The columns of the stability margin (modes): max Re(lambda), 1/s, and
 * the frequency of that mode, Hz (0 for a real mode). */
#define TS_SWEEP_MAX_REAL "max_real"
#define TS_SWEEP_MAX_REAL_FREQ "max_real_freq_hz"

typedef struct ts_sweep ts_sweep;

/* One varied value. */
typedef struct ts_sweep_axis {
    char path[TS_PARAM_PATH_MAX]; /* canonical ("tow.speed") */
    char unit[TS_PARAM_UNIT_MAX]; /* SI unit of its values */
    int n;                        /* values, >= 1 */
    double *values;               /* [n] SI; given by the caller in a spec,
                                     owned by the sweep */
} ts_sweep_axis;

/* What to sweep. */
typedef struct ts_sweep_spec {
    ts_request rq;         /* the analysis at every point (kind
                              equilibrium, modes, response or simulate);
                              shallow: an excitation is borrowed and must
                              outlive the sweep */
    int naxes;             /* 1..TS_SWEEP_MAX_AXES */
    ts_sweep_axis axes[TS_SWEEP_MAX_AXES]; /* first slowest; continuation
                              runs along the last */
    int chain;             /* points per chain, at most; 0: TS_SWEEP_CHAIN;
                              1: every point from a cold start */
    int boundary;          /* 1: find the stability boundary (modes) */
    double boundary_rtol;  /* 0: TS_SWEEP_BOUNDARY_RTOL */
    int threads;           /* OpenMP threads; 0: as many as OpenMP
                              offers; 1: serial */
    ts_progress_fn progress; /* between chains ("sweep", chains done of
                              the total), and polled in long runs; nonzero
                              stops the sweep, keeping finished chains */
    void *progress_data;
    /* Called after each chain is finished (also a crossing, with chain =
     * nchains + its index), one call at a time, e.g. to record it; a
     * nonzero return stops the sweep like progress. May be NULL. */
    int (*on_chain)(const ts_sweep *s, int chain, void *data);
    void *on_chain_data;
} ts_sweep_spec;

/* A column of the table. */
typedef struct ts_sweep_column {
    char name[TS_VALUE_NAME_MAX];  /* "sphere.z", "top_tension",
                                      "mode1.freq_hz", "max_real" */
    char unit[TS_VALUE_UNIT_MAX];
} ts_sweep_column;

/* Point states. */
enum {
    TS_SWEEP_PENDING = 0, /* not (yet) computed */
    TS_SWEEP_DONE = 1     /* computed, or restored from a record */
};

/* One point: its outcome. Its values are in the sweep's arrays. */
typedef struct ts_sweep_point {
    int state;             /* TS_SWEEP_PENDING or TS_SWEEP_DONE */
    int status;            /* TS_OK, or the failure's code */
    char error[TS_ERR_MSG_MAX]; /* the failure's message, "" */
    ts_trust trust;        /* the result's verdict */
    int verdict;           /* modes: TS_STABLE, TS_UNSTABLE, TS_MARGINAL
                              of the resolved modes; -1 otherwise, when
                              not reached or when no mode is resolved */
    int warm;              /* started from the previous point's
                              equilibrium */
    long evaluations;      /* kernel evaluations */
    int iterations;        /* of the equilibrium solver */
    double wall_s;         /* s */
} ts_sweep_point;

/* A crossing of the stability boundary. */
typedef struct ts_sweep_crossing {
    int axis;              /* the axis bisected */
    int from, to;          /* the grid points bracketing it: `from` not
                              unstable, `to` unstable */
    int status;            /* TS_OK; a failed run ends the bisection with
                              its code (the bracket so far is kept) */
    char error[TS_ERR_MSG_MAX];
    double stable, unstable; /* the final bracket along the axis, SI:
                              values where the run was not unstable and
                              where it was */
    double value;          /* its middle: the boundary's estimate */
    double max_real_stable, max_real_unstable; /* 1/s at the bracket */
    double freq_hz;        /* frequency of the rightmost mode on the
                              unstable side (0: a real mode, divergence) */
    int runs;              /* modes runs of the bisection */
    long evaluations;
    double wall_s;
    int done;              /* computed or restored */
} ts_sweep_crossing;

struct ts_sweep {
    ts_sweep_spec spec;    /* a copy; axes' values owned */
    ts_analysis_kind kind;
    int npoints;
    int nchains;
    int chain_len;         /* the `chain` in force */
    int ncolumns;
    ts_sweep_column *columns;  /* [ncolumns] */
    ts_sweep_point *points;    /* [npoints] */
    double *values;        /* [npoints * ncolumns], NAN where none */
    ts_estimate *errors;   /* [npoints * ncolumns] */
    int ncrossings;
    ts_sweep_crossing *crossings; /* [ncrossings], after the grid */
    int completed;         /* every chain (and crossing) done */
    double wall_s;         /* of the runs this process made */
    long evaluations;      /* of every point and crossing */
    const ts_system *sys;  /* the scene's system (borrowed) */
    /* Internal state of a run: do not touch. */
    int stop;              /* a callback asked to stop */
    int chains_done;       /* chains and crossings done, for progress */
};

/* A sweep of spec on sys, checked (axes, paths against the system, the
 * request with the first point's values through ts_analysis_check) and
 * laid out (columns, chains); nothing runs. NULL on failure with the
 * message naming the axis or option. sys and the spec's excitation are
 * borrowed. Free with ts_sweep_free. */
TS_API ts_sweep *ts_sweep_alloc(const ts_system *sys,
                                const ts_sweep_spec *spec, ts_err *err);
TS_API void ts_sweep_free(ts_sweep *s);

/* Grid coordinates of point p: idx[naxes]. */
TS_API void ts_sweep_point_index(const ts_sweep *s, int p, int idx[]);
/* The chain of point p, and the points [*first, *first + *n) of chain c. */
TS_API int ts_sweep_chain_of(const ts_sweep *s, int p);
TS_API void ts_sweep_chain_points(const ts_sweep *s, int c, int *first,
                                  int *n);
/* The column called `name`, or -1. */
TS_API int ts_sweep_column_find(const ts_sweep *s, const char *name);

/* Run chain c (0 <= c < nchains) into s. Thread-safe for different
 * chains. TS_OK (failed points are recorded, not returned), TS_ECANCEL
 * when stopped (the chain's points go back to pending), TS_ENOMEM. */
TS_API int ts_sweep_run_chain(ts_sweep *s, int c, ts_err *err);

/* Run every pending chain in chain order whose number is congruent to
 * `part` modulo `nparts` (a process's share; 0 and 1 for all), over
 * spec.threads threads. TS_OK, TS_ECANCEL (stopped: finished chains
 * kept) or TS_ENOMEM. */
TS_API int ts_sweep_run(ts_sweep *s, int part, int nparts, ts_err *err);

/* After the grid (every point done): find the crossings of the stability
 * boundary (spec.boundary, modes) and bisect those of this process's
 * share (`part` modulo `nparts`). ts_sweep_crossings_find alone lays them
 * out (a process that restores them calls it first). TS_OK, TS_ECANCEL,
 * TS_ENOMEM; TS_EINVAL when the grid is not done. */
TS_API int ts_sweep_crossings_find(ts_sweep *s, ts_err *err);
TS_API int ts_sweep_run_crossings(ts_sweep *s, int part, int nparts,
                                  ts_err *err);

/* Set completed from the points and crossings. */
TS_API void ts_sweep_finish(ts_sweep *s);

#ifdef __cplusplus
}
#endif
#endif
