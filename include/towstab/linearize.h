/* towstab/linearize.h: the linear model z' = A z + B v about a state
 * (MODEL.md section 6; Kamman & Nguyen eqs. 56-65).
 *
 * A = df/dy and B = df/du by second-order central differences through the
 * one kernel, column by column (columns are independent and computed in
 * parallel with OpenMP when available). The first nq rows of A are exactly
 * [0 I] and of B zero. The step of column j is h_j = rel_step *
 * max(|y_j|, scale_j) with rel_step ~ eps^(1/3); the truncation error is
 * estimated by comparing with steps 2 h_j and reported.
 *
 * Inputs v (TS_NINPUT = 9): tow-point displacement x, y, z (m), velocity
 * (m/s), acceleration (m/s^2) in the mean ship frame, named tow.surge,
 * tow.sway, tow.heave for displacement (their velocity and acceleration
 * columns follow in the same order). Matrices are column-major: A[i + j n].
 */
#ifndef TOWSTAB_LINEARIZE_H
#define TOWSTAB_LINEARIZE_H

#include "towstab/error.h"
#include "towstab/kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ts_linear {
    int nstate;        /* n = 2 nq */
    int ninput;        /* TS_NINPUT */
    double *A;         /* [n * n] column-major */
    double *B;         /* [n * ninput] column-major */
    double *y0;        /* [n] state linearized about (kernel's charts) */
    double *u0;        /* [ninput] input linearized about */
    double trunc_err;  /* max |A(h) - A(2h)| / 3 over entries, 1/s or 1/s^2 */
    double a_scale;    /* max |A_ij| of the lower block, for relative use */
    int kinks;         /* nodes within a step of the water surface: f is
                          not smooth there and A is the mean of one-sided
                          derivatives (MODEL.md section 6) */
    long evaluations;  /* kernel evaluations used */
} ts_linear;

typedef struct ts_linearize_opts {
    double rel_step;   /* default cbrt(DBL_EPSILON) ~ 6.1e-6 */
    int estimate_error;/* 1 (default): also differentiate with 2h */
    int threads;       /* 0 (default): OpenMP's choice; 1: serial */
} ts_linearize_opts;

TS_API void ts_linearize_opts_default(ts_linearize_opts *o);

TS_API ts_linear *ts_linear_alloc(int nstate, int ninput, ts_err *err);
TS_API void ts_linear_free(ts_linear *lin);

/* Linearize kernel k about state y0[nstate] and input u0[ninput] (NULL:
 * zero). The kernel's charts must be those of y0. Returns TS_OK, TS_CHART
 * (a perturbed state left the chart: re-chart y0 first) or TS_ENOMEM. */
TS_API int ts_linearize(ts_kernel *k, const double y0[], const double u0[],
                        const ts_linearize_opts *opts, ts_linear *lin,
                        ts_err *err);

/* Name of input column j ("tow.surge", "tow.sway", "tow.heave",
 * "tow.surge_velocity", ..., "tow.heave_acceleration"). */
TS_API const char *ts_input_name(int j);

#ifdef __cplusplus
}
#endif
#endif
