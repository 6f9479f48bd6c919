/* response_impl.h: the frequency response with a progress callback, for
 * the analysis pipeline (lib/analysis.c). Private to the library. */
#ifndef TOWSTAB_RESPONSE_IMPL_H
#define TOWSTAB_RESPONSE_IMPL_H

#include <complex.h>

#include "towstab/progress.h"
#include "towstab/response.h"

/* ts_response_compute, calling progress(data) (when not NULL) after every
 * frequency with what = "response", unit "frequencies"; a nonzero return
 * stops it with TS_ECANCEL ("response: stopped on request after K of N
 * frequencies") and no result. */
int tsi_response_compute(const ts_system *sys, const ts_linear *lin,
                         int input, const ts_output *out,
                         const double freq_hz[], int npoints,
                         ts_progress_fn progress, void *data,
                         ts_response **res, ts_err *err);

/* Append "; vehicles: <names>" (every output of k's vehicles,
 * ts_kernel_output_name) to err's message, the list of valid names of
 * a bad output. Nothing without vehicles or err. */
void tsi_response_list_vehicle_outputs(const ts_kernel *k, ts_err *err);

/* The gain of one input to one output at many frequencies, one at a
 * time (the loop margins' scan and its refinements): one work area and
 * one factorisation kept from frequency to frequency, refactored with the
 * last one's pivots while they serve (tsi_shift_refactor); the same gain
 * as ts_response_at to rounding. NULL with err set on a bad input or
 * output (ts_response_at's checks) or no memory. */
typedef struct tsi_gain tsi_gain;
tsi_gain *tsi_gain_alloc(const ts_system *sys, const ts_linear *lin,
                         int input, const ts_output *out, ts_err *err);
/* The gain at omega (rad/s, >= 0) into *val. */
int tsi_gain_at(tsi_gain *g, double omega, double complex *val, ts_err *err);
void tsi_gain_free(tsi_gain *g);

#endif
