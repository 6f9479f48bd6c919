/* towstab/response.h: frequency response of the linear model to tow-point
 * motion (doc/model.md section 6; doc/linear.md).
 *
 * For a tow-point displacement X(i w) along x, y or z (input tow.surge,
 * tow.sway, tow.heave) the tow point also moves with velocity i w X and
 * acceleration -w^2 X, so the state responds as
 *   Z(i w) = (i w I - A)^-1 (B_x + i w B_v - w^2 B_a) X,
 * B_x, B_v, B_a the input's displacement, velocity and acceleration columns
 * of B. Outputs:
 *  - a node's or body's displacement along x, y or z (m per m of input):
 *    the tow displacement (every node moves with the tow point) plus the
 *    node displacement of the angle response through the link geometry
 *    (ts_linear_node_displacements);
 *  - a link's tension (N per m), the tension unknown of the same solve.
 * Each frequency is one sparse solve with the linear model's node
 * equations (ts_linear.desc; doc/linear.md, sections 2b and 4): O(nlinks)
 * per point, at any size. At w = 0 the response is the static gain, which
 * must equal the change of the equilibrium with the tow point displaced.
 */
#ifndef TOWSTAB_RESPONSE_H
#define TOWSTAB_RESPONSE_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"
#include "towstab/output.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Input channel (0, 1, 2) of "tow.surge", "tow.sway" or "tow.heave".
 * Returns TS_OK or TS_EINVAL with a message listing the valid names. */
TS_API int ts_response_input_find(const char *name, int *channel,
                                  ts_err *err);

/* Parse an output of the frequency response (towstab/output.h): a
 * position "<node>.x|y|z" (node as ts_system_node_name writes it: a
 * body's name or "<cable>.<k>", k = 1..links of that cable) or a tension
 * "<cable>.<k>.tension" ("<body>.tension" is the link ending at the
 * body). Returns TS_OK or TS_EINVAL with a message that lists the valid
 * names (and says that tow is the input); the other channels (the tow
 * force, strains) are refused as outputs of simulate. */
TS_API int ts_response_output_find(const ts_system *sys, const char *name,
                                   ts_output *out, ts_err *err);

/* Write the valid response output names, compactly ("cable.1 .. cable.19, sphere"
 * per cable), into buf. */
TS_API void ts_response_output_names(const ts_system *sys, char *buf,
                                     size_t size);

/* The same with a vehicle's inputs: a tow displacement, or one of the
 * kernel's vehicle inputs (ts_kernel_input_name: "<vehicle>.<surface>",
 * "<vehicle>.<loop>", "<vehicle>.<loop>.setpoint"); k is any kernel of
 * the system. TS_OK or TS_EINVAL listing the valid names. */
TS_API int ts_response_input_lookup(const ts_kernel *k, const char *name,
                                    int *channel, ts_err *err);

/* The same for outputs: ts_response_output_find's names, or a vehicle's
 * outputs ("<vehicle>.depth", ".pitch", ".roll", ".yaw",
 * "<vehicle>.<loop>.output", "<vehicle>.<surface>.deflection"). */
TS_API int ts_response_output_lookup(const ts_kernel *k, const char *name,
                                     ts_output *out, ts_err *err);

/* Log-spaced frequencies freq[points] from `from` to `to` Hz inclusive.
 * Refuses (TS_EINVAL) from <= 0, to <= from, non-finite values or
 * points < 2. */
TS_API int ts_response_logspace(double from, double to, int points,
                                double freq[], ts_err *err);

typedef struct ts_response {
    int input;          /* channel: 0..2 a tow displacement, from
                           TS_NINPUT on a vehicle's input */
    char input_name[TS_IO_NAME];
    char unit[32];      /* output unit per input unit, e.g. "m/rad" */
    ts_output output;
    int npoints;
    double *freq_hz;    /* [npoints] Hz */
    double *re, *im;    /* [npoints] complex gain, output unit per m */
    double *magnitude;  /* [npoints] |gain| */
    double *phase_deg;  /* [npoints] arg(gain), degrees in (-180, 180] */
    double static_gain; /* the w = 0 limit (real) */
    double *error;      /* [npoints] error allowance of the complex gain
                           (so of the magnitude; of the phase over the
                           magnitude, rad) from the linearization's
                           truncation and rounding (doc/linear.md,
                           section 4); NaN without its error estimate */
    double static_error;/* the same of the static gain */
    char static_note[256]; /* why static_gain is NaN ("" when it is a
                           number): the output drifts with a towing
                           vehicle's neutral modes by symmetry (named),
                           or the model is singular at 0 Hz beyond them,
                           or (the sparse model alone) the limit's
                           extrapolation does not settle (doc/linear.md
                           sections 3a, 4a); with them and an output
                           they do not move, static_gain is the limit
                           w -> 0 */
} ts_response;

/* Frequency response of output `out` to input channel `input` at
 * freq_hz[npoints] (Hz, each >= 0): lin's sparse model, or its dense A
 * and B for a system with vehicles. A tow displacement input (0..2)
 * brings its velocity and acceleration; a vehicle input (>= TS_NINPUT)
 * is its column of B alone, and a vehicle output (TS_OUT_VEHICLE) a row
 * of the output Jacobians Vy, Vu (dense model). On success *res is new
 * (free with ts_response_free). Returns TS_OK, TS_EINVAL (bad channel,
 * negative frequency, no model, a system other than lin's),
 * TS_ESINGULAR (i w is an eigenvalue: an undamped resonance exactly on a
 * point) or TS_ENOMEM. */
TS_API int ts_response_compute(const ts_system *sys, const ts_linear *lin,
                               int input, const ts_output *out,
                               const double freq_hz[], int npoints,
                               ts_response **res, ts_err *err);
TS_API void ts_response_free(ts_response *r);

/* The gain at one angular frequency w (rad/s, >= 0) into (*re, *im). */
TS_API int ts_response_at(const ts_system *sys, const ts_linear *lin,
                          int input, const ts_output *out, double omega,
                          double *re, double *im, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
