/* towstab/control.h: what a control engineer designs against, for the
 * vehicles' controller loops (doc/vehicle.md section 5; doc/linear.md):
 * the open-loop plant about the closed-loop trim, and the gain and phase
 * margins of each loop broken at its output with the other loops closed.
 *
 * Both start from a solved equilibrium of the closed loop, whose surface
 * deflections they keep: opening a loop freezes its output at the trim
 * value (TS_LOOP_OPEN), breaking it feeds its surfaces an input set to
 * that value (TS_LOOP_BROKEN), so the linearization point is the same
 * physical state.
 */
#ifndef TOWSTAB_CONTROL_H
#define TOWSTAB_CONTROL_H

#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Open every loop of every vehicle of k (all closed, the layout of eq's
 * solve) at eq's trim: each loop's output frozen at its trim value, its
 * integrator out of the state. y[] (room for ts_kernel_nstate(k) before
 * the call) receives the trim's state in the open layout
 * (ts_kernel_nstate(k) after it), ready to simulate or linearize. TS_OK,
 * or a code with every loop left closed. */
TS_API int ts_control_open(ts_kernel *k, const ts_equilibrium *eq,
                           double y[], ts_err *err);

/* Every loop of every vehicle of k closed again. */
TS_API void ts_control_close(ts_kernel *k);

/* The linear model about equilibrium eq (solved with every loop closed)
 * with every loop of every vehicle open: its integrators leave the state,
 * its surfaces hold the trim's deflections, and the inputs (surface
 * commands, loop inputs) act on the plant alone. k is a kernel of eq's
 * system with every loop closed; it is left so on return. *out is a new
 * result (ts_linear_free). TS_OK, or the equilibrium's or linearizer's
 * code. */
TS_API int ts_linearize_open_loop(ts_kernel *k, const ts_equilibrium *eq,
                                  const ts_linearize_opts *opts,
                                  ts_linear **out, ts_err *err);

/* Margins of one loop, broken at its output (the other loops closed).
 * With G(s) the transfer from the input at the break to the loop's own
 * output, the loop transfer in the negative-feedback convention is
 * L(s) = -G(s) (closing the loop makes 1 + L(s) = 0). */
typedef struct ts_loop_margin {
    int vehicle, loop;        /* ts_kernel_vehicle_body order, loop index */
    char name[TS_IO_NAME];    /* "<vehicle>.<loop>" */
    double gain_margin;       /* 1 / |L| where arg L = -180 deg (the
                                 smallest over such frequencies); INFINITY
                                 when the phase never reaches -180 deg in
                                 the band; < 1: unstable */
    double phase_crossover_hz;/* that frequency, NaN without one */
    double phase_margin_deg;  /* 180 + arg L where |L| = 1 (the smallest
                                 over such frequencies), deg; NaN when |L|
                                 never crosses 1 in the band */
    double gain_crossover_hz; /* that frequency, NaN without one */
} ts_loop_margin;

/* Margins of every loop of every vehicle, from a frequency scan of
 * `points` log-spaced frequencies over [from_hz, to_hz] refined by
 * bisection to 1e-9 relative at each crossing. m[] holds one entry per
 * loop (sum of the vehicles' nloops, in order). k as for
 * ts_linearize_open_loop. Cost: one linearization and `points`
 * structured solves per loop. TS_OK or a code with its message. */
TS_API int ts_loop_margins(ts_kernel *k, const ts_equilibrium *eq,
                           double from_hz, double to_hz, int points,
                           ts_loop_margin m[], ts_err *err);

/* Number of loops of all the vehicles of k's system. */
TS_API int ts_control_nloops(const ts_kernel *k);

#ifdef __cplusplus
}
#endif
#endif
