/* towstab/vehicle.h: a towed vehicle as a rigid body built up from
 * components, with control surfaces and PID controllers (doc/vehicle.md;
 * doc/model.md section 8; Kamman & Nguyen 1990, eqs. 12-19, 27-42;
 * Buckham et al. 2003, sections 3-4).
 *
 * Body axes b: origin O (a reference point the scene chooses, usually the
 * hull centre), x forward (the nose), y starboard, z down: at zero attitude
 * they are parallel to the mean ship frame M. Every position of the
 * description (mass centre, buoyancy centre, cable attach point,
 * components) is in body axes relative to O, in m. The attitude is a
 * dextral 1-2-3 rotation sequence relative to M (Kamman's angles theta1,
 * theta2, theta3 about the body x, y, z axes); reports give the usual
 * yaw-pitch-roll (Z-Y-X) angles of the same rotation (towstab/kernel.h).
 *
 * The description is a flat struct with fixed-size arrays (no pointers),
 * so a ts_system copies it with memcpy. SI units, angles in rad.
 */
#ifndef TOWSTAB_VEHICLE_H
#define TOWSTAB_VEHICLE_H

#include "towstab/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_VEHICLE_NAME_MAX 64
#define TS_VEHICLE_MAX_COMPONENTS 16  /* hull and lifting surfaces */
#define TS_VEHICLE_MAX_LOOPS 8        /* controller loops */
#define TS_CURVE_MAX_POINTS 64        /* rows of a lift/drag table */

typedef enum {
    TS_COMP_HULL = 0,     /* slender hull: axial and cross-flow drag */
    TS_COMP_SURFACE = 1,  /* lifting surface: lift and drag curves */
    TS_COMP_BLUFF = 2,    /* bluff part (a ballast weight, a bulb): drag
                             -1/2 rho Cd A |w| w whatever the direction */
    TS_COMP_MAST = 3,     /* surface-piercing mast: a straight prism up
                             the body's -z axis from its foot `position`,
                             `length` high, of section `area` (chord along
                             x, thickness along y); the buoyancy of its
                             part under the free surface z = 0, which
                             follows the vehicle's depth and attitude
                             (doc/vehicle.md section 4); with `drag`
                             (default 0), the drag of that part across
                             the flow on thickness x submerged length,
                             at its centroid */
    TS_COMP_BALLAST = 4   /* ballast tank at `position`: controlled
                             buoyancy. Its fill (kg of water, in [0,
                             capacity]) is a control component's
                             deflection (control is 1): an input, an
                             output, driven by loops, through an actuator
                             with a rate limit (kg/s); the fill beyond
                             `deflection` (the fill included in the
                             vehicle's mass) weighs at the tank. */
} ts_component_type;

typedef enum {
    TS_CURVE_LIFTING_LINE = 0, /* Helmbold lift slope from the aspect ratio,
                                  induced drag, flat plate past the stall */
    TS_CURVE_TABLE = 1         /* C_L(alpha), C_D(alpha) tabulated */
} ts_curve_type;

/* One component. Fields of the other type are ignored. */
typedef struct ts_component {
    char name[TS_VEHICLE_NAME_MAX];
    ts_component_type type;
    double position[3];   /* hull, bluff part: its centre; surface: its
                             centre of pressure; body axes from O, m */
    /* Bluff part (and a surface's planform area below). */
    double drag;          /* drag coefficient on `area`; a mast's on its
                             submerged frontal area (0 by default) */
    /* Hull (axis along body x). */
    double length;        /* m, > 0 */
    double diameter;      /* m, > 0 */
    double cd_axial;      /* axial drag coefficient on pi D^2 / 4 */
    double cd_cross;      /* cross-flow drag coefficient on D dx */
    /* Mast (and `length`, `area`): its section's chord (along body x)
     * and thickness (along y), m, > 0; the waterplane's second moments
     * are those of an ellipse of the section's area, area chord^2 / 16
     * and area thickness^2 / 16 (exact for an elliptic or circular
     * section). */
    double chord, thickness;
    /* Ballast tank: the most water it holds, kg, > 0 (its fill, the
     * deflection, lies in [0, capacity]; `limit` stays INFINITY). */
    double capacity;
    /* Lifting surface: chord along body x, normal (0, -sin roll, cos
     * roll): roll 0 is a horizontal surface with its normal down, +-pi/2
     * a vertical fin, +-pi/4 and +-3pi/4 an X tail. */
    double area;          /* planform area S (a bluff part: frontal
                             area), m^2, > 0 */
    double span;          /* m, > 0; aspect ratio span^2 / area */
    double roll;          /* rad */
    double incidence;     /* rad, fixed setting added to the angle of attack */
    ts_curve_type curve;
    double lift_slope;    /* dC_L/dalpha, 1/rad; 0: Helmbold from the
                             aspect ratio (ts_lift_slope_helmbold) */
    double stall;         /* stall angle of attack, rad, > 0 */
    double stall_width;   /* half-width of the blend into the flat plate,
                             rad, in (0, stall) */
    double cd0;           /* zero-lift drag coefficient */
    double efficiency;    /* Oswald span efficiency of the induced drag */
    double cn90;          /* flat-plate normal-force coefficient at 90 deg */
    int npoints;          /* table rows (curve table), 3..TS_CURVE_MAX_POINTS */
    double alpha[TS_CURVE_MAX_POINTS]; /* rad, strictly increasing */
    double cl[TS_CURVE_MAX_POINTS];
    double cd[TS_CURVE_MAX_POINTS];
    /* Control surface (all-moving): the deflection adds to the angle of
     * attack; a positive deflection gives force along -normal (up for a
     * horizontal surface). */
    int control;          /* 1: a control surface, with a named input */
    double deflection;    /* open-loop (bias) deflection delta0, rad */
    double limit;         /* largest |deflection|, rad (INFINITY: none) */
    double rate_limit;    /* largest |d deflection / dt|, rad/s
                             (INFINITY: none; needs time_constant > 0) */
    double time_constant; /* s: actuator lag tau, delta' =
                             sat((delta_cmd - delta) / tau); 0: ideal */
    int line;             /* scene line, 0 if none */
} ts_component;

/* What a loop measures (relative to M; yaw-pitch-roll angles). */
typedef enum {
    TS_MEASURE_DEPTH = 0,   /* z of the body origin O, m */
    TS_MEASURE_PITCH = 1,   /* rad, nose up > 0 */
    TS_MEASURE_ROLL = 2,    /* rad, starboard down > 0 */
    TS_MEASURE_HEADING = 3  /* rad, yaw relative to M, to starboard > 0 */
} ts_measure;

/* One PID loop: e = measured - setpoint (a heading error wrapped into
 * (-pi, pi]), e' its rate, x the integral of e (a state when ki != 0):
 *   v = kp e + ki x + kd e',
 * and each surface it drives is commanded delta0 + input + sum of
 * gain[i] v over the loops driving it. */
typedef struct ts_loop {
    char name[TS_VEHICLE_NAME_MAX];
    ts_measure measure;
    double setpoint;      /* m or rad */
    double kp, ki, kd;    /* rad per m (rad), per m s (rad s), per m/s
                             (rad/s) */
    int nsurfaces;
    int surface[TS_VEHICLE_MAX_COMPONENTS]; /* component indices */
    double gain[TS_VEHICLE_MAX_COMPONENTS]; /* mixing weights */
    int line;
} ts_loop;

/* How a loop drives its surfaces (ts_kernel_set_loop_mode). */
enum {
    TS_LOOP_CLOSED = 0, /* its output plus its input (a disturbance at the
                           loop's output) drives its surfaces */
    TS_LOOP_OPEN = 1,   /* its surfaces see a frozen output (the trim's)
                           plus its input; no integrator state: the open
                           loop plant */
    TS_LOOP_BROKEN = 2  /* its surfaces see its input alone, the other
                           loops staying closed: the loop broken at its
                           output, for its gain and phase margins */
};

/* Propulsion of a towing vehicle (doc/towing-vehicle.md, section 2): a
 * thrust T along the body x axis at `position`. */
typedef enum {
    TS_PROP_NONE = 0,   /* no thrust (a towed vehicle) */
    TS_PROP_THRUST = 1, /* T = thrust, constant */
    TS_PROP_POWER = 2,  /* constant power: T = min(power / U, max_thrust),
                           U the surge speed through the water (Buckham's
                           T = T_E U_steady / U with T_E U_steady = power) */
    TS_PROP_SPEED = 3   /* speed controller: T = thrust + gain (speed - U)
                           + ki z, z' = speed - U, with U the tow point's
                           speed through the water; proportional (ki = 0):
                           `thrust` the bias the steady analyses trim so
                           that U = speed; PI (ki > 0): the integrator z
                           a controller state, `thrust` a fixed bias, T
                           at most max_thrust, z held while T is capped
                           and U below the set speed (anti-windup) */
} ts_propulsion_type;

typedef struct ts_propulsion {
    ts_propulsion_type type;
    double thrust;      /* N: the thrust (TS_PROP_THRUST) or the speed
                           controller's bias (TS_PROP_SPEED) */
    double power;       /* W, > 0 (TS_PROP_POWER) */
    double max_thrust;  /* N, > 0: the power law's cap at low speed (its
                           bollard thrust), the PI speed controller's
                           cap; INFINITY: none */
    double speed;       /* m/s, > 0: the speed controller's set speed */
    double gain;        /* N s/m, >= 0: the speed controller's gain */
    double ki;          /* N/m, >= 0: the speed controller's integral
                           gain; 0: proportional only */
    double position[3]; /* where the thrust acts, body axes from O, m */
    int line;           /* scene line, 0 if none */
} ts_propulsion;

typedef struct ts_vehicle {
    double inertia[6];    /* about the mass centre, body axes, kg m^2:
                             Ixx, Iyy, Izz, Ixy, Ixz, Iyz (products as
                             tensor entries, I_xy = -sum m x y) */
    double mass_centre[3];
    double buoyancy_centre[3];
    double attach[3];     /* cable attach point (spherical joint) */
    double volume;        /* displaced volume, m^3 */
    double added_mass[36];/* 6x6 about O, body axes, row-major, symmetric:
                             rows/columns surge, sway, heave, roll, pitch,
                             yaw (kg, kg m, kg m^2) */
    int added_mass_estimated; /* 1: added_mass is the Newman ellipsoid
                             estimate of estimate_length/diameter */
    double estimate_length, estimate_diameter; /* m */
    double estimate_centre[3]; /* ellipsoid centre, body axes, m */
    int estimate_follows_hull; /* 1: the estimate is the first hull's
                             (added_mass: spheroid): its length, diameter
                             and position, in the water density; a value
                             set by path re-derives it (towstab/param.h) */
    double surface_diameter;  /* m: height of the hull used for the
                             submerged fraction near z = 0 */
    int surface_diameter_derived; /* 1: not given: the first hull's
                             diameter, or without a hull that of a sphere
                             of the volume (re-derived as they are set by
                             path) */
    int ncomponents;
    ts_component component[TS_VEHICLE_MAX_COMPONENTS];
    int nloops;
    ts_loop loop[TS_VEHICLE_MAX_LOOPS];
    ts_propulsion propulsion; /* a towing vehicle's (TS_PROP_NONE for a
                             towed one) */
} ts_vehicle;

/* The thrust law of propulsion p at speed u (m/s: the power law's is
 * the surge, the velocity of the body origin relative to the water along
 * body x; the speed controller's the tow point's speed through the water)
 * with `bias` the
 * speed controller's trimmed bias, with an integral gain its bias plus
 * ki z (N; ignored by the other laws), plus
 * `input` (N, the thrust input of a linear model or an excitation); a
 * speed controller's law (before the input) at most max_thrust.
 * The one place the law is written (the kernel and the manoeuvres). */
TS_API double ts_propulsion_thrust(const ts_propulsion *p, double u,
                                   double bias, double input);

/* Loads of one component (body axes): force (N), moment about the body
 * origin O (N m) (a mast: its buoyancy), its angle of attack (a surface: with incidence and
 * deflection; the hull: of the flow at its centre, atan2(w_z, w_x)) and
 * the speed of the flow past it (m/s; a surface: in its chord-normal
 * plane). */
typedef struct ts_component_load {
    double force[3], moment[3];
    double alpha, speed;
    double submerged;     /* a mast: its mean submerged length along its
                             axis (its submerged volume over its section
                             area), m; 0 for the other components */
} ts_component_load;

/* A vehicle at one state (ts_kernel_vehicle_result). Angles in rad. */
typedef struct ts_vehicle_result {
    int body;             /* body index */
    double R[9];          /* attitude: body to M, row-major */
    double yaw, pitch, roll; /* Z-Y-X angles relative to M: yaw > 0 to
                             starboard, pitch > 0 nose up, roll > 0
                             starboard down */
    double alpha, beta;   /* angle of attack atan2(w_z, w_x) and sideslip
                             asin(w_y / |w|) of the flow at O, w the
                             velocity of O relative to the water (body
                             axes) */
    double speed;         /* |w|, m/s */
    double origin[3];     /* O in M, m (origin[2] is the depth) */
    double mass_centre[3];/* G in M, m */
    double omega[3];      /* angular velocity relative to M, body axes */
    double submerged;     /* fraction under water */
    double joint_force[3];/* force of the cable's end node on the vehicle
                             through the joint, M frame, N (the towing
                             vehicle: the cables' pull at its tow point) */
    int towing;           /* 1: the towing vehicle */
    double thrust, power; /* the towing vehicle's thrust (N) and its power
                             T U (W), U its surge speed through the water */
    double track_speed, turn_rate; /* the towing vehicle's: the frame's
                             speed V (m/s) and turn rate Omega (rad/s), its
                             steady motion in an equilibrium */
    int dof;              /* the towing vehicle's degrees of freedom: 6, or
                             3 for a surface ship (0: a towed vehicle) */
    double held[3];       /* a surface ship's: the hull's hydrostatic
                             reaction that holds its heave, roll and pitch:
                             the vertical force on the hull at its tow
                             point (N, down > 0: a negative value carries
                             weight and the cable's downward pull), the
                             roll and pitch moments about it (N m, body
                             axes) */
    double hydro_force[3], hydro_moment[3]; /* all components, body axes,
                             moment about O */
    double munk[3];       /* the added mass's -v x p moment, body axes */
    int ncomponents;
    double delta[TS_VEHICLE_MAX_COMPONENTS];      /* deflections, rad */
    ts_component_load load[TS_VEHICLE_MAX_COMPONENTS];
    int nloops;
    double loop_error[TS_VEHICLE_MAX_LOOPS];  /* measured - setpoint */
    double loop_output[TS_VEHICLE_MAX_LOOPS]; /* the law's value, rad */
} ts_vehicle_result;

/* Defaults of a component of `type` (doc/vehicle.md): hull Cd axial 0.2,
 * cross 1.2; surface lifting line, Helmbold slope, stall 15 deg, width 3
 * deg, cd0 0.01, efficiency 0.9, cn90 1.2, no limits, ideal actuator. */
TS_API void ts_component_defaults(ts_component *c, ts_component_type type);

/* The range of a control component's command: a surface's [-limit,
 * limit] (rad), a ballast tank's [0, capacity] (kg). */
TS_API void ts_component_range(const ts_component *c, double *lo,
                               double *hi);

/* Validate a vehicle description (finite values, ranges, tables, loops
 * referring to control surfaces, symmetric added mass with a
 * non-negative diagonal). `where` and `line` name it in messages
 * ("bodies[2].inertia (line 14): ..."; line 0: none; components and loops
 * give their own lines). TS_OK or TS_EINVAL. */
TS_API int ts_vehicle_check(const ts_vehicle *v, double mass,
                            const char *where, int line, ts_err *err);

/* Added mass of a prolate spheroid of length L and diameter D (L >= D > 0)
 * in fluid of density rho, about its centre, in its axes (x along the
 * length), Newman (1977) section 4.13 with Lamb's coefficients:
 * A11 = k1 m_f, A22 = A33 = k2 m_f, A55 = A66 = k' I_f, A44 = 0, with
 * m_f = rho pi L D^2 / 6 and I_f = m_f (L^2 + D^2) / 20. A[36] row-major;
 * k[3] (may be NULL) receives k1, k2, k'. TS_EINVAL when L < D. */
TS_API int ts_added_mass_spheroid(double rho, double length, double diameter,
                                  double A[36], double k[3], ts_err *err);

/* Move a 6x6 added-mass matrix about point P to one about point O, both
 * in the same axes: r is P relative to O. A_O = H^T A_P H with
 * H = [[I, -S(r)], [0, I]] (S(r) x = r x x). In place allowed. */
TS_API void ts_added_mass_shift(const double A_P[36], const double r[3],
                                 double A_O[36]);

/* Helmbold's lift slope of a wing of aspect ratio ar (> 0):
 * 2 pi ar / (2 + sqrt(ar^2 + 4)), 1/rad: 2 pi for ar -> infinity and
 * pi ar / 2 (slender wing) for ar -> 0. */
TS_API double ts_lift_slope_helmbold(double ar);

/* The attitude body to M of yaw, pitch and roll (Z-Y-X, as
 * ts_vehicle_result), row-major: R = Rz(yaw) Ry(pitch) Rx(roll). */
TS_API void ts_vehicle_rotation(double yaw, double pitch, double roll,
                                double R[9]);

/* Points per hull outline (a closed ellipse) of ts_vehicle_outline. */
#define TS_OUTLINE_HULL_POINTS 33

/* The vehicle drawn in M with attitude R and origin O (m): polylines of
 * points pts[3 k] (x, y, z in M), one after the other, separated by a
 * point of NaNs: each hull as its outline in the body's x-z plane and in
 * its x-y plane (ellipses of its length and diameter: the side view shows
 * its pitch, the top view its yaw), each lifting surface as its planform
 * (a rectangle of its span and mean chord area / span in its own plane,
 * turned by its deflection delta[c] about its span when delta is given),
 * each bluff part as a cross of its frontal area's side. Writes at most
 * max points; returns how many the outline has. */
TS_API int ts_vehicle_outline(const ts_vehicle *v, const double R[9],
                              const double origin[3], const double *delta,
                              double pts[], int max);

#ifdef __cplusplus
}
#endif
#endif
