/* towstab/kernel.h: the one dynamics kernel, y' = f(y, u), of the rigid-link
 * tree (doc/model.md sections 1-4, 7 and 8; Kamman & Nguyen 1990, eqs. 4-11,
 * 12-22, 43-44).
 *
 * State y[2 nq + nc]: y[0..nq) the generalised coordinates, y[nq..2nq)
 * their rates, y[2nq..2nq+nc) the controllers' states. A rigid link has
 * two coordinates, its angles theta1, theta2 in its chart (rad); an
 * elastic link (EA > 0, doc/model.md section 7) three, its angles and its
 * strain e (length l (1 + e)); a vehicle (towstab/vehicle.h) three, its
 * 1-2-3 attitude angles in its chart, after all the links. Link l's
 * coordinates start at ts_kernel_link_offset(k, l), vehicle v's at
 * ts_kernel_vehicle_offset(k, v); with rigid links only and no vehicle,
 * nq = 2 nlinks, link l is at 2l and nc = 0. An elastic link's tension is
 * EA e + Cv l e', never compressive (slack: 0); keeping the strain itself
 * as a coordinate keeps that tension exact however stiff the link. The
 * controller states are the integrals of the loops' errors (loops with an
 * integral gain) and the deflections of control surfaces with an actuator
 * (time constant > 0), vehicle by vehicle.
 *
 * Input u[ninput]: u[0..9) the tow-point displacement (m), velocity
 * (m/s) and acceleration (m/s^2) relative to its nominal position in the
 * mean ship frame M, each as x, y, z; u[9..18) a small rotation theta of
 * the ship about M's axes (rad), its rate (rad/s) and its acceleration
 * (rad/s^2), each as roll, pitch, yaw (x, y, z): it moves a cable's start
 * point r by theta x r (r from M's origin for a prescribed tow point,
 * from the towing vehicle's origin O otherwise; TS_TOW_ROT); then,
 * vehicle by vehicle, a
 * deflection command (rad) per control surface, added to its open-loop
 * deflection, and two inputs per controller loop: one added to the loop's
 * output (rad), one to its set point (m or rad) (ts_kernel_input_name). The motion of M (speed V, turn
 * rate Omega and their rates) and the current are set with
 * ts_kernel_set_frame() (default: the system's steady tow, no current
 * rotation).
 *
 * Cost: O(nlinks) per evaluation; the link tensions come from a tree
 * recursion (free ends to tow point and back) on 3x3 nodal mass matrices,
 * never a dense matrix. Nothing is allocated after ts_kernel_alloc().
 *
 * Charts: link k's direction is n = R_k (-c1 c2, -s2, s1 c2) with R_k the
 * identity by default. The chart is singular where cos(theta2) = 0; an
 * evaluation with |cos(theta2)| < TS_CHART_MIN on any link returns TS_CHART
 * and writes NaN to dydt. ts_kernel_rechart() moves links that come near
 * (|cos theta2| below a threshold) to a chart centred on their current
 * direction and rewrites y accordingly; positions and velocities are
 * unchanged, so a solver may continue from the rewritten state.
 */
#ifndef TOWSTAB_KERNEL_H
#define TOWSTAB_KERNEL_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_NINPUT 18
/* The tow inputs: translation along axis j (0 x, 1 y, 2 z) at u[j],
 * rotation about axis j at u[TS_TOW_ROT + j]; each displacement's
 * velocity is 3 after it, its acceleration 6 after it. */
#define TS_TOW_ROT 9
#define TS_CHART_MIN 1e-6        /* |cos theta2| below which f refuses */
#define TS_CHART_RECHART 0.25    /* default re-chart threshold */

/* dy/dt = f(t, y, u). y[n_state], u[n_input], dydt[n_state]; SI units.
 * Returns 0 on success, > 0 when the state is outside the model's chart
 * (the caller may re-chart or retry with a smaller step), < 0 on a fatal
 * error. */
typedef int (*ts_rhs_fn)(double t, const double y[], const double u[],
                         double dydt[], void *params);

/* Motion of the mean ship frame and the water, in M. */
typedef struct ts_frame {
    double speed;        /* V, m/s */
    double turn_rate;    /* Omega, rad/s */
    double speed_rate;   /* dV/dt, m/s^2 */
    double turn_accel;   /* dOmega/dt, rad/s^2 */
    double current[3];   /* current in M components, m/s */
} ts_frame;

typedef struct ts_kernel ts_kernel;

/* Allocate the kernel of a built system. The kernel keeps a pointer to
 * `sys`, which must outlive it and must not be rebuilt meanwhile. */
TS_API ts_kernel *ts_kernel_alloc(const ts_system *sys, ts_err *err);
TS_API void ts_kernel_free(ts_kernel *k);

/* A new kernel on the same system with the same frame and charts (for
 * evaluating from several threads: a kernel is not shared between
 * threads). NULL on failure. */
TS_API ts_kernel *ts_kernel_clone(const ts_kernel *k, ts_err *err);

TS_API const ts_system *ts_kernel_system(const ts_kernel *k);
TS_API int ts_kernel_nq(const ts_kernel *k);      /* coordinates */
TS_API int ts_kernel_nstate(const ts_kernel *k);  /* 2 nq + nc */
TS_API int ts_kernel_ncontrol(const ts_kernel *k);/* nc */
TS_API int ts_kernel_ninput(const ts_kernel *k);  /* TS_NINPUT + the
                                                     vehicles' inputs */
/* Name of input j into buf: "tow.surge" ... (ts_input_name order), then
 * "<vehicle>.<surface>", "<vehicle>.<loop>" and
 * "<vehicle>.<loop>.setpoint". Returns buf, or NULL when j is out of
 * range. */
TS_API const char *ts_kernel_input_name(const ts_kernel *k, int j, char *buf,
                                        size_t size);
/* Index of the input called `name`, -1 if none. */
TS_API int ts_kernel_input_find(const ts_kernel *k, const char *name);
/* Unit of input j ("m", "m/s", "m/s^2", "rad", "rad/s", "rad/s^2", ...),
 * NULL out of range. */
TS_API const char *ts_kernel_input_unit(const ts_kernel *k, int j);
/* 1 when input j is a control surface's deflection. */
TS_API int ts_kernel_input_is_surface(const ts_kernel *k, int j);
/* 1 when input j is a loop's set point ("<vehicle>.<loop>.setpoint"): the
 * one kind of input that does nothing with the loops open (a loop's
 * input adds to its frozen output, a towing vehicle's thrust, forces,
 * moments and speed set point act on the plant). */
TS_API int ts_kernel_input_is_setpoint(const ts_kernel *k, int j);
/* Offset of link `link`'s coordinates in q (2 for rigid, 3 for elastic). */
TS_API int ts_kernel_link_offset(const ts_kernel *k, int link);

/* The towing vehicle (doc/towing-vehicle.md): its index among the
 * vehicles, or -1 when the tow point is prescribed; the offset in q of
 * the position of its attach point (the tow point, node 0) in M, three
 * coordinates after its three angles (-1 without one). Its inputs follow
 * its controllers': "<name>.thrust" (N), "<name>.force.x|y|z" (N) and
 * "<name>.moment.x|y|z" (N m, about its tow point), body axes, and with
 * a speed controller "<name>.speed_set" (m/s, added to its set speed).
 * With a towing vehicle the tow-point inputs (the first TS_NINPUT) move the
 * points its cables start from relative to the body, in M axes, on top
 * of its own motion (a wave-induced motion of the tow point; zero in
 * the steady analyses): a start point at r from the vehicle's origin O
 * (M axes, r = R p, p its body-axes position) moves by x + theta x r,
 * with velocity x' + theta' x r and acceleration x'' + theta'' x r.
 * The speed controller's thrust bias (N, towstab/vehicle.h) is a kernel
 * parameter, trimmed by the equilibrium; ts_kernel_thrust is the thrust
 * of the last evaluation. */
TS_API int ts_kernel_root(const ts_kernel *k);
TS_API int ts_kernel_root_offset(const ts_kernel *k);
/* Its degrees of freedom: 6, or 3 for a surface ship held to the free
 * surface (ts_tow.dof: surge, sway and yaw; roll and pitch 0, the tow
 * point's depth the scene's tow.point z); 0 without a towing vehicle. A
 * surface ship's q holds its yaw alone at ts_kernel_vehicle_offset and
 * the tow point's x and y at ts_kernel_root_offset (one after it). */
TS_API int ts_kernel_root_dof(const ts_kernel *k);
/* The tow point's position r_A (M, m) in state y: its coordinates, with a
 * surface ship's depth the scene's; tow.point without a towing vehicle. */
TS_API void ts_kernel_root_position(const ts_kernel *k, const double y[],
                                    double r[3]);
TS_API void ts_kernel_set_thrust_bias(ts_kernel *k, double thrust);
TS_API double ts_kernel_thrust_bias(const ts_kernel *k);
TS_API double ts_kernel_thrust(const ts_kernel *k);
/* A PI speed controller's integrator z (m, the integral of the speed
 * error; T includes ki z): its offset in the controller states (it is
 * the first, y[2 nq], whatever the loops' modes), or -1 without one. */
TS_API int ts_kernel_speed_integrator(const ts_kernel *k);
/* The deflection (rad) added to the towing vehicle's turn surface
 * (ts_tow.turn_surface), trimmed by the equilibrium to turn at the
 * scene's turn rate; 0 without one. */
TS_API void ts_kernel_set_turn_deflection(ts_kernel *k, double delta);
TS_API double ts_kernel_turn_deflection(const ts_kernel *k);

/* Set / read the frame motion. The default is the system's tow (speed,
 * turn rate, zero rates) with its current. */
TS_API void ts_kernel_set_frame(ts_kernel *k, const ts_frame *f);
TS_API void ts_kernel_get_frame(const ts_kernel *k, ts_frame *f);

/* Multiply every bending stiffness by `scale` (default 1): a homotopy
 * parameter for continuation from the unbent shape, not physics. */
TS_API void ts_kernel_set_bending_scale(ts_kernel *k, double scale);

/* Evaluate f(y, u) into dydt[2 nq]. u may be NULL (all zero). Returns
 * TS_OK, TS_CHART (a link too close to the chart singularity; dydt is
 * NaN) or TS_ESINGULAR (a nodal mass matrix not positive definite, or an
 * elastic link of zero length; dydt is NaN). */
TS_API int ts_kernel_eval(ts_kernel *k, const double y[], const double u[],
                          double dydt[]);

/* The same with the ts_rhs_fn signature; `params` is the kernel. */
TS_API int ts_kernel_rhs(double t, const double y[], const double u[],
                         double dydt[], void *params);

/* Results of the last evaluation (valid until the next one):
 * node positions [3 nnodes] (m, M frame, node 0 the tow point), node
 * velocities relative to M [3 nnodes], link tensions [nlinks] (N, > 0 in
 * tension), link unit directions [3 nlinks] (upper to lower node), node
 * accelerations relative to M, r'' [3 nnodes], external loads on the nodes
 * [3 nnodes] (N: weight, buoyancy, drag, bending). */
TS_API const double *ts_kernel_positions(const ts_kernel *k);
TS_API const double *ts_kernel_velocities(const ts_kernel *k);
TS_API const double *ts_kernel_tensions(const ts_kernel *k);
TS_API const double *ts_kernel_directions(const ts_kernel *k);
TS_API const double *ts_kernel_rel_accelerations(const ts_kernel *k);
TS_API const double *ts_kernel_loads(const ts_kernel *k);

/* After an evaluation: the force the cables exert on the tow point (N, M
 * frame), i.e. the tensions of the links leaving it plus the loads lumped
 * at node 0 less its inertia. Returns its magnitude. */
TS_API double ts_kernel_tow_force(const ts_kernel *k, double F[3]);

/* After an evaluation: the largest unbalanced nodal force
 * max_k |M_k r''_k| (N) and, in *scale, the largest force in the system
 * (largest |link tension| or |nodal load|, N). At an equilibrium the
 * first is zero; equilibrium residuals are reported relative to *scale. */
TS_API double ts_kernel_unbalanced(const ts_kernel *k, double *scale);

/* Kinetic energy relative to the inertial frame minus nothing else (J), and
 * potential energy of gravity and bending (J, z down), of the last
 * evaluation. Used to check energy conservation in vacuum. */
TS_API double ts_kernel_kinetic_energy(const ts_kernel *k);
TS_API double ts_kernel_potential_energy(const ts_kernel *k);

/* What controller state i (0 <= i < nc, at y[2 nq + i]) is: the
 * integral of loop `index`'s error (rad s or m s), the deflection of
 * control surface `index` (its actuator, rad), or the integral of the
 * towing vehicle's speed error (m; TS_CONTROL_SPEED, index -1), of
 * vehicle `vehicle`. */
#define TS_CONTROL_SPEED 2
typedef struct ts_control_state {
    int vehicle;      /* vehicle index (ts_kernel_vehicle_body) */
    int actuator;     /* 1: an actuator, 0: an integrator, TS_CONTROL_SPEED:
                         the speed controller's integrator */
    int index;        /* component (actuator) or loop (integrator); -1 */
} ts_control_state;
TS_API void ts_kernel_control_state(const ts_kernel *k, int i,
                                    ts_control_state *cs);

/* Set how loop `loop` of vehicle v drives its surfaces (TS_LOOP_CLOSED,
 * TS_LOOP_OPEN with its output frozen at `frozen` rad, TS_LOOP_BROKEN;
 * towstab/vehicle.h). An open loop has no integrator state, so the
 * state's layout (nc, ts_kernel_nstate) changes: move states between
 * layouts with ts_kernel_get_controls / ts_kernel_set_controls. TS_OK or
 * TS_EINVAL (no such loop or mode). */
TS_API int ts_kernel_set_loop_mode(ts_kernel *k, int v, int loop, int mode,
                                   double frozen, ts_err *err);
TS_API int ts_kernel_loop_mode(const ts_kernel *k, int v, int loop);

/* The set point in force of loop `loop` of vehicle v (m or rad; the
 * scene's by default; the input "<vehicle>.<loop>.setpoint" adds to it). */
TS_API void ts_kernel_set_setpoint(ts_kernel *k, int v, int loop,
                                   double value);
TS_API double ts_kernel_setpoint(const ts_kernel *k, int v, int loop);

/* 1: actuators follow their commands without rate limits (a steady
 * state, where no actuator moves, is then a smooth root); 0 (default):
 * the scene's rate limits. */
TS_API void ts_kernel_set_steady(ts_kernel *k, int steady);

/* Vehicle v's controller states in y: xi[nloops] (integrators; 0 where a
 * loop has none) and act[ncomponents] (actuators; 0 where a surface has
 * none); and the reverse (entries without a state are ignored). */
TS_API void ts_kernel_get_controls(const ts_kernel *k, int v, const double y[],
                                   double xi[], double act[]);
TS_API void ts_kernel_set_controls(const ts_kernel *k, int v,
                                   const double xi[], const double act[],
                                   double y[]);

/* Outputs of the vehicles, for the linear model's output rows: per
 * vehicle (in order) its depth (m), pitch, roll and yaw (rad, towstab/
 * vehicle.h ts_vehicle_result), then each loop's output (rad, the law's
 * value whatever the loop's mode), then each control surface's deflection
 * (rad, what the hydrodynamics sees: limited, through its actuator).
 * Their number, names ("<vehicle>.depth", "<vehicle>.pitch",
 * "<vehicle>.roll", "<vehicle>.yaw", "<vehicle>.<loop>.output",
 * "<vehicle>.<surface>.deflection"; NULL out of range), the
 * index of a name (-1: none), and their values after an evaluation into
 * out[noutput]. */
TS_API int ts_kernel_noutput(const ts_kernel *k);
TS_API const char *ts_kernel_output_name(const ts_kernel *k, int j,
                                         char *buf, size_t size);
TS_API int ts_kernel_output_find(const ts_kernel *k, const char *name);
/* Unit of output j ("m" or "rad"), NULL out of range. */
TS_API const char *ts_kernel_output_unit(const ts_kernel *k, int j);
TS_API void ts_kernel_outputs(const ts_kernel *k, double out[]);

/* Vehicles, in body order: their number, body index and the offset of
 * their three angles in q. */
TS_API int ts_kernel_nvehicles(const ts_kernel *k);
TS_API int ts_kernel_vehicle_body(const ts_kernel *k, int v);
TS_API int ts_kernel_vehicle_offset(const ts_kernel *k, int v);

/* Set vehicle v's angles and rates in y for attitude R[9] (body to M,
 * row-major) and angular velocity omega[3] relative to M in body axes
 * (NULL: zero). A vehicle whose |cos theta2| would fall below threshold
 * is first moved to a chart centred on R. Returns 1 when re-charted. */
TS_API int ts_kernel_set_vehicle(ts_kernel *k, int v, const double R[9],
                                 const double omega[3], double threshold,
                                 double y[]);
/* Read them back from y (omega may be NULL). */
TS_API void ts_kernel_get_vehicle(const ts_kernel *k, int v, const double y[],
                                  double R[9], double omega[3]);

/* After an evaluation: vehicle v's attitude, flow angles, position, loads
 * (per component, the Munk moment, the joint force), deflections and
 * loop errors and outputs (towstab/vehicle.h). */
TS_API void ts_kernel_vehicle_result(const ts_kernel *k, int v,
                                     ts_vehicle_result *r);

/* Unit direction of link `link` for angles (t1, t2) in its chart. */
TS_API void ts_kernel_direction(const ts_kernel *k, int link, double t1,
                                double t2, double n[3]);

/* The state y[2 nq] of a shape given by unit link directions n[3 nlinks],
 * strains strain[nlinks] of elastic links (NULL: zero; ignored for rigid
 * links) and their rates ndot[3 nlinks] (1/s) and strain_rate[nlinks]
 * (NULL: zero). Angles are in the current charts; a link whose
 * |cos theta2| would fall below `threshold` is first moved to a chart
 * centred on its direction. Returns the number of links re-charted. */
TS_API int ts_kernel_set_shape(ts_kernel *k, const double n[],
                               const double strain[], const double ndot[],
                               const double strain_rate[], double threshold,
                               double y[]);

/* The same from link vectors d[3 nlinks] (r_lower - r_upper, m) and their
 * rates ddot (NULL: at rest): rigid links take the direction only; an
 * elastic link's strain is |d|/l - 1 (use ts_kernel_set_shape for stiff
 * links, where that difference loses digits). */
TS_API int ts_kernel_set_links(ts_kernel *k, const double d[],
                               const double ddot[], double threshold,
                               double y[]);

/* The same from unit directions n[3 nlinks] and their rates (NULL: zero),
 * every link at its unstretched length. */
TS_API int ts_kernel_set_directions(ts_kernel *k, const double n[],
                                    const double ndot[], double threshold,
                                    double y[]);

/* Re-chart every link and vehicle of state y with |cos theta2| <
 * threshold and rewrite its angles and rates in place (a vehicle's chart
 * is centred on its attitude: its angles become 0). Returns the number
 * re-charted. */
TS_API int ts_kernel_rechart(ts_kernel *k, double y[], double threshold);

/* Restore the standard chart (R = I) on every link whose direction allows
 * it (|cos theta2| >= threshold there) and rewrite y. Returns the number of
 * links left in a non-standard chart. */
TS_API int ts_kernel_reset_charts(ts_kernel *k, double y[], double threshold);

/* Standard-chart angles of a unit direction n: theta1 = atan2(n_z, -n_x),
 * theta2 = asin(-n_y) (rad). */
TS_API void ts_direction_angles(const double n[3], double *theta1,
                                double *theta2);

#ifdef __cplusplus
}
#endif
#endif
