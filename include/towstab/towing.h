/* towstab/towing.h: how much the cable changes the towing vehicle's own
 * modes (doc/towing-vehicle.md, section 4; Buckham et al. 2003's
 * motivation).
 *
 * The free vehicle is the scene's towing vehicle alone, without its
 * cables and what hangs on them, at the coupled system's steady speed:
 * its propulsion's parameter is re-trimmed so that it holds that speed
 * alone (a thrust: its own drag; a power: its drag times its surge
 * speed; a speed controller: unchanged), its rudder and other deflections
 * as in the scene, its controllers closed. Its modes (LAPACK, with their
 * shapes) are matched to the coupled system's by shape over the vehicle's
 * own coordinates: each free mode takes the coupled mode with the largest
 * modal assurance criterion
 *
 *     MAC = |v_f^H v_c|^2 / (|v_f|^2 |v_c|^2),
 *
 * v_c the coupled mode's vector restricted to the vehicle's coordinates,
 * rates and controller states (the same coordinates as v_f's). A MAC near
 * 1 is the same motion of the vehicle; a small one says the cable has
 * mixed it into the cable's modes. Coincident modes (an exactly repeated
 * eigenvalue: the neutral modes at 0, equal actuator lags) have no
 * single shape, any mix of them being a mode: a free mode among them is
 * matched to the span of coincident coupled modes, MAC = |P v_f|^2 /
 * |v_f|^2 with P the projection on that span (ts_free_mode.span), and
 * paired within it by symmetry (a neutral mode with the coupled mode of
 * the same symmetry) or else one to one.
 */
#ifndef TOWSTAB_TOWING_H
#define TOWSTAB_TOWING_H

#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/linearize.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ts_free_mode {
    double re, im;              /* the free vehicle's eigenvalue, 1/s
                                   (im >= 0) */
    double freq_hz, damping_ratio;
    int coupled;                /* the coupled mode (index in the coupled
                                   ts_eigen's modes) it is, -1 if none */
    double coupled_re, coupled_im, coupled_freq_hz, coupled_damping_ratio;
    double mac;                 /* modal assurance criterion, 0 to 1:
                                   with the coupled mode, or, when span
                                   > 1, with the span of that many
                                   coincident coupled modes */
    int span;                   /* 1, or the size of that span: this
                                   mode is one of several coincident free
                                   modes (any mix of them is a mode), so
                                   its shape is matched to the span of a
                                   group of coincident coupled modes, no
                                   larger than its own; 0 without a
                                   partner */
    int neutral;                /* 1: a neutral mode by symmetry of the
                                   free vehicle (towstab/eigen.h) */
} ts_free_mode;

typedef struct ts_free_vehicle {
    double speed;               /* its steady speed (the coupled one's), m/s */
    double turn_rate;           /* its steady turn rate, rad/s */
    double thrust;              /* its thrust there, N */
    int nstate;                 /* states of the free vehicle */
    int nmodes;
    int nneutral;               /* its neutral modes by symmetry */
    ts_free_mode *modes;        /* [nmodes], by frequency then |lambda| */
} ts_free_vehicle;

/* Compare the towing vehicle of `sys` alone with the coupled system
 * whose equilibrium is eq, linear model lin (closed loop) and modes e
 * (with vectors, covering every eigenvalue: LAPACK). TS_OK with *out,
 * TS_EINVAL without a towing vehicle or vectors, or the free vehicle's
 * equilibrium or linearization's error (its message prefixed
 * "free vehicle: "). */
TS_API int ts_free_vehicle_compare(const ts_system *sys,
                                   const ts_equilibrium *eq,
                                   const ts_linear *lin, const ts_eigen *e,
                                   ts_free_vehicle **out, ts_err *err);
TS_API void ts_free_vehicle_free(ts_free_vehicle *f);

#ifdef __cplusplus
}
#endif
#endif
