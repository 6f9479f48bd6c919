/* vehicle.h: the towed vehicle's physics for the kernel (internal;
 * towstab/vehicle.h describes it, doc/vehicle.md derives it).
 *
 * The kernel treats a vehicle as a rigid body hanging on the spherical
 * joint at its attach point A, the lower node of the cable that ends at
 * it. This module gives the kernel what it needs per vehicle, all O(1):
 *  - kinematics: the rotation R (body to M) from the 1-2-3 angles in the
 *    vehicle's chart, the angular velocities, positions and velocities of
 *    body points, and the angle accelerations from the angular one;
 *  - the 6x6 spatial inertia about A in body axes, rigid body plus added
 *    mass (tsi_vehicle_mass6);
 *  - the known generalised force about A in body axes: weight, buoyancy,
 *    component hydrodynamics, the velocity terms of the rigid body and of
 *    the added mass (Kirchhoff; the hull's Munk moment is one of them)
 *    (tsi_vehicle_loads);
 *  - the measurements and the controller law.
 * The kernel does the coupling: the articulated elimination of the six
 * body degrees of freedom into the 3x3 W^-1 of the attach node, W =
 * J M6^-1 J^T, and the child cables at other body points (lib/kernel.c).
 *
 * Conventions: positions in body axes are relative to the body origin O;
 * "_b" quantities are body components, "_m" components in M. Spatial
 * 6-vectors are (force, moment) or (acceleration, angular acceleration),
 * 6x6 matrices row-major.
 */
#ifndef TOWSTAB_VEHICLE_IMPL_H
#define TOWSTAB_VEHICLE_IMPL_H

#include "towstab/vehicle.h"

/* Work areas that outlive one evaluation: interpolators of tabulated
 * curves and the hull quadrature. Allocated per vehicle with the kernel. */
typedef struct tsi_vehicle_ws tsi_vehicle_ws;

tsi_vehicle_ws *tsi_vehicle_ws_alloc(const ts_vehicle *v, ts_err *err);
void tsi_vehicle_ws_free(tsi_vehicle_ws *w);

/* The kinematic state of one vehicle at one evaluation. */
typedef struct tsi_vehicle_state {
    double R[9];        /* body to M, row-major: x_m = R x_b */
    double E[9];        /* omega_rel_b = E theta' (1-2-3 rate matrix) */
    double c2;          /* cos theta2 of the chart angles */
    double om_rel_b[3]; /* angular velocity relative to M, body axes */
    double om_b[3];     /* inertial angular velocity, body axes */
    double rA[3], rdA[3]; /* attach point, M frame, position and velocity
                             relative to M */
    double rO[3], rdO[3]; /* body origin */
    double wO_b[3];     /* velocity of O relative to the water, body axes
                           (the kernel's, from the frame and the current) */
    double frac;        /* submerged fraction (buoyancy, fluid forces,
                           added mass; the kernel's) */
} tsi_vehicle_state;

/* Rotation of the 1-2-3 sequence: R123 = R1(t1) R2(t2) R3(t3), body to
 * the chart's frame (Kamman eq. 2). */
void tsi_rot123(const double th[3], double R[9]);

/* omega_b = E(theta) theta' for the 1-2-3 sequence (Kamman eqs. 13-15
 * without the ship's turn), and kappa = E'(theta, theta') theta', the
 * part of omega_b' quadratic in the rates. */
void tsi_rate_matrix(const double th[3], double E[9]);
void tsi_rate_kappa(const double th[3], const double thd[3], double kap[3]);

/* theta' from omega_b (inverse of E; c2 = cos theta2 != 0). */
void tsi_rates_from_omega(const double th[3], const double om_b[3],
                          double thd[3]);

/* Yaw, pitch, roll (Z-Y-X) of a rotation R (body to M), rad, and their
 * rates from the angular velocity relative to M in body axes. */
void tsi_ypr_from_rot(const double R[9], double ypr[3]);
void tsi_ypr_rates(const double ypr[3], const double om_b[3],
                   double yprd[3]);

/* Kinematics: chart C (row-major, body-chart to M), angles th and rates
 * thd, the frame's turn rate W (rad/s), and the attach point's position
 * and velocity (M, relative to M). Fills st but wO_b and frac. */
void tsi_vehicle_kinematics(const ts_vehicle *v, const double C[9],
                            const double th[3], const double thd[3],
                            double turn_rate, const double rA[3],
                            const double rdA[3], tsi_vehicle_state *st);

/* Position and velocity relative to M of body point p_b (from O). */
void tsi_vehicle_point(const ts_vehicle *v, const tsi_vehicle_state *st,
                       const double p_b[3], double r[3], double rd[3]);

/* Spatial inertia about A in body axes: rigid body of `mass` plus the
 * added mass times the submerged fraction. M6[36] symmetric. */
void tsi_vehicle_mass6(const ts_vehicle *v, double mass,
                       const tsi_vehicle_state *st, double M6[36]);

/* Lift and drag coefficients of surface c (index ci of v) at effective
 * angle of attack alpha (rad, any value: wrapped into (-pi, pi]). */
void tsi_surface_coefficients(const ts_vehicle *v, const tsi_vehicle_ws *w,
                              int ci, double alpha, double *cl, double *cd);

/* Hydrodynamic force and moment about O (body axes) of every component
 * for the velocity of O relative to the water wO_b, the inertial angular
 * velocity om_b (body axes), density rho times fraction frac, and the
 * deflections delta[ncomponents] (rad; 0 for fixed surfaces). each (may
 * be NULL) receives every component's load. */
void tsi_vehicle_hydro(const ts_vehicle *v, const tsi_vehicle_ws *w,
                       double rho, double frac, const double wO_b[3],
                       const double om_b[3], const double delta[],
                       double F[3], double Mo[3], ts_component_load *each);

/* The buoyancy of mast component cp (TS_COMP_MAST) with the body origin
 * at depth zO (m, down > 0) and ez_b the body components of M's e_z:
 * force (body axes, N) and moment about O (N m) of its part under the
 * free surface z = 0, exact for its elliptic section however the
 * waterline cuts it (doc/vehicle.md section 4); `submerged` (may be
 * NULL) receives the mean submerged length, m, and `centre` (may be
 * NULL) the centroid of the submerged part (body axes from O, m; the
 * foot when none is submerged). */
void tsi_mast_buoyancy(const ts_component *cp, double rho, double g,
                       double zO, const double ez_b[3], double F[3],
                       double Mo[3], double *submerged, double centre[3]);

/* The drag of mast cp on its submerged part (tsi_mast_buoyancy's mean
 * submerged length `submerged`, m, and centroid `centre`, body axes from
 * O): with w the velocity of that centroid through the water (wO_b + om_b
 * x centre, body axes, m/s) and w_perp = (w_x, w_y, 0) its part across
 * the mast, F = -1/2 rho drag thickness submerged |w_perp| w_perp at the
 * centroid: force (body axes, N) and moment about O (N m). */
void tsi_mast_drag(const ts_component *cp, double rho, double submerged,
                   const double centre[3], const double wO_b[3],
                   const double om_b[3], double F[3], double Mo[3]);

/* The static loads of v's masts and ballast tanks at state st (R and
 * rO) with fills delta (rad or kg per component; NULL: the trim fills):
 * each mast's buoyancy (tsi_mast_buoyancy) with its drag on the same
 * submerged part (tsi_mast_drag, from st's wO_b and om_b; none with drag
 * 0, the default) and each tank's water beyond
 * its trim fill (`deflection`, in the vehicle's mass), (delta - fill) g
 * down at the tank. Force and moment about O in body axes; each (may be
 * NULL) receives every mast's and tank's load. */
void tsi_vehicle_statics(const ts_vehicle *v, double rho, double g,
                         const tsi_vehicle_state *st, const double delta[],
                         double F[3], double Mo[3], ts_component_load *each);

/* Everything on the body but the joint and the child cables, as the
 * generalised force about A in body axes, G[6] = (force, moment): weight
 * at the mass centre, buoyancy at the buoyancy centre (times frac) and
 * of the masts' submerged parts, the ballast beyond its trim fill
 * (tsi_vehicle_statics), the
 * components' hydrodynamics, the added mass's velocity terms (Kirchhoff)
 * and the rigid body's (gyroscopic and centripetal), both written about A:
 * M6 (a_A, alpha) = G + (F_joint, 0) + child cables. `munk` (may be NULL)
 * receives the moment about O of the added mass's -v x p term, the Munk
 * moment (body axes). */
void tsi_vehicle_loads(const ts_vehicle *v, const tsi_vehicle_ws *w,
                       double mass, double rho, double g,
                       const tsi_vehicle_state *st, const double delta[],
                       double G[6], double munk[3]);

/* Angle accelerations from the inertial angular acceleration alpha_m (M
 * components), the frame's turn rate W and its rate W' (rad/s, rad/s^2):
 * omega_rel_b' = R^T (alpha - W' e_z - W e_z x omega_rel),
 * theta'' = E^-1 (omega_rel_b' - kappa). */
void tsi_vehicle_angle_accel(const tsi_vehicle_state *st, const double th[3],
                             const double thd[3], double turn_rate,
                             double turn_accel, const double alpha_m[3],
                             double thdd[3]);

/* The frame part of the angular acceleration, W' e_z + W e_z x
 * omega_rel_m (what alpha is when the attitude is steady in M). */
void tsi_vehicle_frame_alpha(const tsi_vehicle_state *st, double turn_rate,
                             double turn_accel, double alpha_m[3]);

/* Measurements (ts_measure order: depth, pitch, roll, heading) and their
 * rates: depth is z of O, the angles yaw-pitch-roll relative to M. */
void tsi_vehicle_measure(const tsi_vehicle_state *st, double value[4],
                         double rate[4]);

/* What the controller law of one vehicle takes (towstab/vehicle.h,
 * ts_loop). Any pointer may be NULL: zero, or the description's set
 * points, or every loop closed. */
typedef struct tsi_control_in {
    const double *value, *rate; /* [4] measurements and their rates
                                   (tsi_vehicle_measure) */
    const double *xi;       /* [nloops] integrators (loops without ki, or
                               open, are ignored) */
    const double *act;      /* [ncomponents] actuators (surfaces with a
                               time constant); NULL: settled on their
                               commands */
    const double *u_surf;   /* [ncomponents] deflection commands, added to
                               delta0 */
    const double *u_loop;   /* [nloops] added to each loop's output */
    const double *setpoint; /* [nloops] set points in force */
    const int *mode;        /* [nloops] TS_LOOP_* */
    const double *frozen;   /* [nloops] outputs of open loops */
    int steady;             /* 1: a steady state is solved: no rate
                               limits (no actuator moves), and an
                               integrating closed loop's output is ki x
                               (its e and rates vanish there) */
} tsi_control_in;

/* The controller law: the loop outputs out[nloops] (the law's value from
 * the state, whatever the mode), the deflections delta[ncomponents] the
 * hydrodynamics sees, xi_dot[nloops] (= e) and act_dot[ncomponents] (the
 * last two may be NULL). */
void tsi_vehicle_control(const ts_vehicle *v, const tsi_control_in *in,
                         double out[], double delta[], double xi_dot[],
                         double act_dot[]);

/* Error of loop l at set point sp: measured - sp, a heading wrapped into
 * (-pi, pi]. */
double tsi_loop_error(const ts_loop *l, const double value[4], double sp);

/* Cholesky factor of a symmetric positive definite 6x6 A (row-major) into
 * the lower triangle of L; 0, or -1 when A is not positive definite. */
int tsi_chol6(const double A[36], double L[36]);
/* Solve (L L^T) x = b in place. */
void tsi_chol6_solve(const double L[36], double b[6]);

/* Largest distance of a described point (mass and buoyancy centres,
 * components and hull ends, child attach points) from the attach point,
 * m: the lever that turns the body's unbalanced moment into a force. */
double tsi_vehicle_lever(const ts_vehicle *v);

#endif
