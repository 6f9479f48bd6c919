/* kernel_impl.h: what lib/kernel.c shares with the modules above it
 * (internal): names of inputs, the flow past a vehicle, and the node
 * residual of the sparse descriptor model (lib/descriptor.c; doc/linear.md,
 * section 2b).
 *
 * f(y, u) = the kernel's kinematics (angles to node positions, velocities
 * and link directions), the link-local assembly of loads, nodal mass
 * matrices and frame accelerations, then the O(nlinks) articulated
 * elimination of the tensions. The residual below is the same assembly
 * before any elimination: every node's equation of motion written with
 * node positions, velocities and accelerations and the link tensions as
 * unknowns, so that each equation involves only a node and its
 * neighbours. */
#ifndef TOWSTAB_KERNEL_IMPL_H
#define TOWSTAB_KERNEL_IMPL_H

#include "towstab/kernel.h"
#include "vehicle.h"

/* Name of tow input j < TS_NINPUT ("tow.surge", ...), NULL outside. */
const char *tsi_tow_input_name(int j);

/* The flow past a vehicle whose kinematics st holds (tsi_vehicle_kinematics):
 * st->wO_b, the velocity of its origin relative to the water (frame f and
 * its current), and st->frac, its submerged fraction: the circular
 * segment of a horizontal cylinder of the vehicle's surface_diameter
 * centred at its buoyancy centre (1 below one radius; a step at z = 0
 * without a diameter). */
void tsi_vehicle_flow(const ts_frame *f, const ts_vehicle *d,
                      tsi_vehicle_state *st);

/* The residual of the node and vehicle equations before elimination.
 * Inputs: node positions r[3 nnodes], velocities v[3 nnodes] relative to
 * M (m, m/s; node 0 is the tow point, r_0 = point + tow displacement),
 * accelerations a[3 nnodes] relative to M (m/s^2; a_0 is not used), link
 * tensions t[nlinks] (N, rigid and elastic links alike); with vehicles,
 * yv[nstate], a state whose vehicle angles, angle rates and controller
 * states are read (the links' coordinates are not), the vehicles' angle
 * accelerations thdd[3 nvehicles] (rad/s^2), and the inputs u[ninput]
 * (NULL: zero). A prescribed tow point's inputs are not read (the tow
 * point is r_0, v_0); with a towing vehicle at the root (node 0 its
 * origin, free) the tow inputs move the points its cables start from
 * relative to the body, by the kernel's own code (as in ts_kernel_eval).
 * Output R[3 nnodes + 3 nvehicles + ncontrol]:
 *   R_k = M_k (a_k + afr_k) - Q_k + t_l n_l - sum_c t_c n_c (+ R_b r6[0..2])
 * for every node k >= 1 (l the link ending at k, c the links leaving it,
 * n = d / |d| from the positions, a cable leaving a vehicle starting at
 * its point P); R_0 = 0; then per vehicle the rotational rows r6[3..5]
 * of its body equations about the joint A in body axes, r6 = M6 (a_A,
 * alpha) - G - sum_P J_P^T (t n) (M6 and G those of ts_kernel_eval, with
 * its child cables' end masses and loads; the translational part, the
 * joint force R r6[0..2], is added to its node's row); then the
 * controller states' rates (integrators and actuators, in y's order).
 * The loads Q, masses M, frame accelerations afr are those of
 * ts_kernel_eval (the same code). At the state, tensions and
 * accelerations of an evaluation of f, R = 0 to rounding (the rates are
 * f's). Uses the kernel's frame and bending scale; overwrites its
 * last-evaluation results. Returns TS_OK, TS_ESINGULAR when two ends of a
 * link coincide, TS_CHART (a vehicle at its chart's singularity), or
 * TS_EINVAL (vehicles without yv or thdd). O(nlinks). */
int tsi_kernel_residual(ts_kernel *k, const double r[], const double v[],
                        const double a[], const double t[], const double yv[],
                        const double thdd[], const double u[], double R[]);

/* A vehicle's place in the state, the inputs and the outputs: its node,
 * the offset of its angles in q, its controller states y[2 nq + c0 ..]
 * (nc of them, c0 -1 when none), its inputs u[in0 ..] (nin, in0 -1 when
 * none) and its outputs out[out0 ..] (nout, ts_kernel_outputs). */
typedef struct tsi_vehicle_layout {
    int node, qoff, c0, nc, in0, nin, out0, nout;
} tsi_vehicle_layout;
void tsi_kernel_vehicle_layout(const ts_kernel *k, int v,
                               tsi_vehicle_layout *lay);

/* For link l leaving a vehicle at its point P, at the last evaluation
 * and for the link direction n[3]: pg[3] = (R E)^T (rho_P x n), the
 * displacement of P along n per change of the vehicle's angles (m/rad;
 * rho_P = R (P - A)), and pm[3] = -(rho_b x R^T n), the link tension's
 * coefficient in the vehicle's rotational rows (m; rho_b = P - A). */
void tsi_kernel_link_point(const ts_kernel *k, int l, const double n[3],
                           double pg[3], double pm[3]);

/* Vehicle v's inertia in the residual of the last evaluation:
 * Mv[36] (row-major) = d(R_node, r6[3..5]) / d(a_node, thdd_v), rows its
 * node's force (M axes) and its rotational rows (body axes), columns its
 * node's acceleration (M) and its angle accelerations; exact (the
 * residual is linear in them). R_node's own nodal mass M_k is not in it. */
void tsi_kernel_vehicle_mass(const ts_kernel *k, int v, double Mv[36]);

/* Nodal 3x3 mass matrices [6 nnodes] (kg, symmetric packed xx, yy, zz, xy,
 * xz, yz) of the last evaluation or residual: dR_k / da_k. */
const double *tsi_kernel_mass(const ts_kernel *k);

/* Link l's coordinates in y[2 nq] (the others untouched) from its link
 * vector d[3] (m) and rate ddot[3] (m/s; NULL: zero), as
 * ts_kernel_set_links does for every link. Returns 1 when re-charted. */
int tsi_kernel_set_link(ts_kernel *k, int l, const double d[3],
                        const double ddot[3], double threshold, double y[]);

/* The force (N, M) vehicle v pulls its node with at rest in the frame:
 * its own loads (weight, buoyancy, hydrodynamics, with the controller
 * states of y[] and zero inputs) at attitude y[] and joint position
 * rA[3] (m, M), less its mass and added mass times the frame's
 * acceleration there. Its child cables are not included. TS_OK, TS_CHART
 * (the attitude at its chart's singularity) or TS_EDOMAIN (not finite).
 * Overwrites the vehicle's last-evaluation results. O(1). */
int tsi_kernel_vehicle_pull(ts_kernel *k, int v, const double y[],
                            const double rA[3], double F[3]);

/* Where child link `link` of vehicle v starts relative to its joint at
 * the attitude of y[]: off[3] = R (P - A) (m, M). */
void tsi_kernel_vehicle_lever(const ts_kernel *k, int v, const double y[],
                              int link, double off[3]);

#endif
