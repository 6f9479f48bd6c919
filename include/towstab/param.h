/* towstab/param.h: a scalar of a towed system by its scene key path
 * (doc/scene-format.md, "Values by path").
 *
 * Sweeps, design studies, `--set` and bindings change one number of a
 * scene at a time: a cable's length, a body's mass, the tow speed. A path
 * names it as the scene file does, with cables and bodies by name:
 *
 *   tow.speed, tow.turn_rate, tow.point.x|y|z (also `speed`, `turn_rate`)
 *   environment.water_density, environment.gravity,
 *   environment.current.x|y|z
 *   cables.<name>.length | diameter | mass_per_length | weight |
 *       wet_weight | links | normal_drag | tangential_drag | added_mass |
 *       EI | EA | damping
 *   bodies.<name>.diameter | length | mass | weight | wet_weight | drag |
 *       added_mass | cross_drag | cross_added_mass
 *   bodies.<vehicle>.mass | weight | wet_weight | volume |
 *       surface_diameter | inertia.xx|yy|zz|xy|xz|yz |
 *       mass_centre.x|y|z | buoyancy_centre.x|y|z | attach.x|y|z
 *   bodies.<vehicle>.loops.<loop>.kp | ki | kd | setpoint
 *   bodies.<vehicle>.components.<surface>.area | span | deflection |
 *       limit | incidence | roll | lift_slope | stall | stall_width |
 *       zero_lift_drag | efficiency | cn90 | rate_limit | time_constant |
 *       position.x|y|z
 *   bodies.<vehicle>.components.<hull>.length | diameter | axial_drag |
 *       cross_drag | position.x|y|z
 *   bodies.<vehicle>.components.<bluff part>.area | drag | position.x|y|z
 *   towing_vehicle.<a vehicle's key above>, with tow_point.x|y|z for
 *     attach (the towing vehicle is not named as a body)
 *   towing_vehicle.propulsion.thrust | power | speed | max_thrust | gain |
 *     integral_gain | at.x|y|z (those of the scene's law)
 *   (the scene's word `controllers` and the word `loops` name the same
 *   loops; `surfaces` the same components)
 *
 * Values are SI in the unit ts_param_unit() names (the scene's unit of
 * the key). The system stores masses: `weight` and `wet_weight` are
 * converted with the environment's gravity and water density at the time
 * of the call (as the scene reader does), and changing a diameter keeps
 * the mass (so does a vehicle's volume). A loop's gains take the unit of
 * what it measures (depth: rad per m; an angle: rad per rad). What the
 * scene reader derives from a vehicle's values follows them: the
 * spheroid added mass of its first hull (in the water density) and a
 * surface diameter not given (towstab/vehicle.h).
 *
 * The keys' units and limits are the scene reader's: one table serves
 * both (lib/param_impl.h).
 *
 * ts_param_set() checks the value against the key's own limits (naming
 * the path); the system must then be rebuilt (ts_system_build, or
 * ts_system_set_links), which checks the whole description again.
 * ts_analysis_run() does that for the settings of a request
 * (towstab/analysis.h, ts_setup.sets). Nothing here allocates.
 */
#ifndef TOWSTAB_PARAM_H
#define TOWSTAB_PARAM_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/system.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Characters of a path, with its terminating zero. */
#define TS_PARAM_PATH_MAX 160
/* Characters of a unit name ("N*m^2", "kg/m^3"), with the zero. */
#define TS_PARAM_UNIT_MAX 16

/* The SI unit of path's key into unit[size] ("m", "kg/m", "1" for a
 * coefficient or a count, "rad/s"). sys may be NULL: the unit is then
 * that of the path's form, and "" (empty) for a form whose unit depends
 * on the system (a loop's gains and setpoint). TS_OK, or TS_EINVAL for a
 * path of no known form (the message lists the forms; with sys, also a
 * cable, body, loop or surface name the system does not have, listing
 * those it has). */
TS_API int ts_param_unit(const ts_system *sys, const char *path, char *unit,
                         size_t size, ts_err *err);

/* Parse `text`, the value of path's key with an optional unit, into
 * *value (SI) and the SI unit it is in into unit[size]. With sys, or for
 * a key whose unit does not depend on the system, that is the key's unit
 * (ts_param_unit; a plain number is taken in it). Without sys, a loop's
 * gain or setpoint takes the unit of what the loop measures, not known
 * yet: a plain number is SI and unit is "" (the loop's unit, whichever
 * it is); a value with a unit is converted to the unit of a depth loop
 * or of an angle loop (m or rad for the setpoint; rad/m or 1 for kp,
 * rad/(m*s) or 1/s for ki, rad*s/m or s for kd), whichever its dimension
 * fits, and unit names it: ts_param_fits checks it against the loop once
 * the system is known. `where` names the value in messages. TS_OK,
 * TS_EINVAL (a path of no known form, not a number) or TS_EUNIT (a unit
 * of another dimension: without sys, for a loop's key, one that fits
 * neither kind of loop). */
TS_API int ts_param_parse(const ts_system *sys, const ts_units *u,
                          const char *path, const char *text,
                          const char *where, double *value, char *unit,
                          size_t size, ts_err *err);

/* Whether a value in the SI unit `unit` (ts_param_parse's) fits path's
 * key in sys: unit "" or NULL (the key's own), or the key's unit. TS_OK;
 * TS_EINVAL as ts_param_unit; TS_EUNIT when it does not fit, with
 * "PATH: 'GIVEN' is in UNIT, the unit of a loop measuring depth (an
 * angle), but loop 'NAME' of vehicle 'VEHICLE' measures pitch: expected
 * rad ..." (given: the text as given, may be NULL). */
TS_API int ts_param_fits(const ts_system *sys, const char *path,
                         const char *unit, const char *given, ts_err *err);

/* The value at `path`, SI. TS_OK or TS_EINVAL (as ts_param_unit). */
TS_API int ts_param_get(const ts_system *sys, const char *path,
                        double *value, ts_err *err);

/* Set the value at `path` (SI) in the description. TS_OK, or TS_EINVAL
 * naming the path when the value breaks the key's limits (a length > 0
 * m, a mass >= 0 kg, links a whole number 1 to TS_MAX_LINKS on a cable
 * without link_lengths, a weight without gravity, ...). Nothing is set on
 * failure. The discretisation is stale until the system is rebuilt. */
TS_API int ts_param_set(ts_system *sys, const char *path, double value,
                        ts_err *err);

/* The canonical spelling of `path` (`speed` -> `tow.speed`) into
 * out[size]; paths of one key compare equal after it. TS_OK or TS_EINVAL
 * for a path of no known form. */
TS_API int ts_param_canonical(const char *path, char *out, size_t size,
                              ts_err *err);

/* Whether the canonical path `canon` is a value the towing vehicle of
 * sys solves (doc/towing-vehicle.md section 3): tow.speed, solved from its
 * propulsion, and tow.turn_rate, solved at its deflections unless
 * `turn_by` names the surface deflected for it, are then only the start
 * values of its equilibrium's V and Omega. TS_OK when it is not (no
 * towing vehicle, another path); else TS_EINVAL with "CANON: the towing
 * vehicle 'NAME' solves ..., and CANON is only the solve's start value
 * (WHY); VERB <the key that sets it>", naming
 * towing_vehicle.propulsion.thrust, .power or .speed (the scene's law),
 * or turn_by. */
TS_API int ts_param_solved(const ts_system *sys, const char *canon,
                           const char *why, const char *verb, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
