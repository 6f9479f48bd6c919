/* towstab/system.h: the towed system as a tree of cables, links, nodes and
 * bodies (doc/model.md sections 1-3, 8).
 *
 * A ts_system holds the description (environment, tow, cables, bodies) and,
 * after ts_system_build(), its discretisation: links in topological order
 * (every link after the link above it), node 0 the tow point and node k+1
 * the lower end of link k. All quantities are SI: m, kg, s, N, rad.
 * Frames: mean ship frame M, x forward, y starboard, z down (depth).
 */
#ifndef TOWSTAB_SYSTEM_H
#define TOWSTAB_SYSTEM_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/vehicle.h"
#include "towstab/guidance.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TS_NAME_MAX 64
/* Links in one system, and so on any cable: the one limit of the scene
 * format, the command line and the convergence sweeps. */
#define TS_MAX_LINKS 100000

typedef enum { TS_DRAG_STANDARD = 0, TS_DRAG_LOADING = 1 } ts_drag_law;

/* A cylinder is a towfish lumped at its node: its axis lies along the link
 * that ends at it (the cable pulls its nose), with axial and cross-flow drag
 * and added mass (doc/kernel.md). A vehicle is a rigid body with its own
 * attitude (three more coordinates) hanging on a spherical joint at its
 * node (towstab/vehicle.h, doc/vehicle.md). */
typedef enum {
    TS_BODY_SPHERE = 0,
    TS_BODY_JUNCTION = 1,
    TS_BODY_CYLINDER = 2,
    TS_BODY_VEHICLE = 3
} ts_body_type;

typedef struct ts_environment {
    double water_density;   /* rho, kg/m^3 (0: vacuum) */
    double gravity;         /* g, m/s^2, along +z */
    double current[3];      /* uniform current, inertial, m/s (M at t = 0) */
} ts_environment;

typedef struct ts_tow {
    double speed;           /* V, m/s along +x_M */
    double turn_rate;       /* Omega, rad/s about +z_M (> 0: starboard turn) */
    double point[3];        /* nominal tow point in M, m (z < 0: above water) */
    int vehicle;            /* body index of the towing vehicle, the
                               dynamic root of the tree (its attach point,
                               the tow point r_tow, is node 0, starting at
                               `point`; doc/towing-vehicle.md), or -1: the
                               tow point is prescribed */
    int turn_surface;       /* with a towing vehicle: the component index
                               of its control surface the steady analyses
                               deflect to turn at `turn_rate`, or -1: the
                               turn rate is solved at the deflections */
    int dof;                /* with a towing vehicle: its degrees of
                               freedom, 6 (default) or 3: a surface ship
                               held to the free surface, surge, sway and
                               yaw dynamic, roll and pitch 0 and its tow
                               point at the depth point[2] (the hull's
                               hydrostatics react the rest) */
    ts_autopilot autopilot; /* the scene's waypoints (on = 0: none): a
                               simulation steers the towing vehicle's
                               rudder toward them (towstab/guidance.h) */
} ts_tow;

typedef struct ts_cable {
    char name[TS_NAME_MAX];
    int from_body;          /* index into bodies, -1 for the tow point */
    int to_body;            /* index into bodies, -1 for a free end */
    double length;          /* m */
    double diameter;        /* m (hydrodynamic and buoyancy diameter) */
    double mass_per_length; /* kg/m in air */
    int nlinks;             /* number of rigid links */
    double *link_fraction;  /* [nlinks] fractions of length summing to 1, or
                               NULL for equal links; owned by the system */
    double cdn;             /* normal drag coefficient */
    double cdt;             /* tangential drag coefficient */
    double can;             /* normal added-mass coefficient */
    ts_drag_law drag_law;
    double ei;              /* bending stiffness EI, N m^2 (0: none) */
    double ea;              /* axial stiffness EA, N (0: rigid links) */
    double damping;         /* internal axial damping Cv, N s/m (elastic) */
    int has_from_point;     /* 1: the cable starts at from_point of its
                               `from` vehicle */
    double from_point[3];   /* body axes of the `from` vehicle, from its
                               origin, m (default: its attach point) */
    int line;               /* scene line of the entry, 0 if none */
} ts_cable;

typedef struct ts_body {
    char name[TS_NAME_MAX];
    ts_body_type type;
    double diameter;        /* m (sphere, cylinder) */
    double length;          /* m (cylinder) */
    double mass;            /* kg in air */
    double cd;              /* drag coefficient on the frontal area (sphere);
                               axial, on pi D^2/4 (cylinder) */
    double ca;              /* added-mass coefficient on the volume (sphere);
                               axial (cylinder) */
    double cd_cross;        /* cylinder: cross-flow drag on D * length */
    double ca_cross;        /* cylinder: cross-flow added mass on the volume */
    ts_vehicle *vehicle;    /* vehicle: its description, owned by the
                               system (NULL for other types) */
    int line;
} ts_body;

/* Volume of a body, m^3 (0 for a junction; a vehicle's displaced
 * volume). */
TS_API double ts_body_volume(const ts_body *b);

/* One rigid link of the discretisation. */
typedef struct ts_link {
    int cable;              /* index into cables */
    int index;              /* 1 at the top of its cable */
    int upper;              /* upper node (closer to the tow point) */
    int lower;              /* lower node, always link index + 1 */
    int parent;             /* link whose lower node is `upper`, -1 at tow */
    int next;               /* next link of the same cable, -1 at its end */
    double length;          /* m */
    double diameter;        /* m */
    double mass;            /* kg */
    double cdn, cdt, can;
    ts_drag_law drag_law;
    double ei;              /* of the joint at `lower` with `next`, N m^2 */
    int elastic;            /* 1: an elastic link (ea > 0), 0: rigid */
    double ea;              /* N */
    double damping;         /* N s/m */
    int up_body;            /* a vehicle body whose point up_point is this
                               link's upper end (the first link of a cable
                               starting at a vehicle), else -1: the upper
                               end is node `upper` itself */
    double up_point[3];     /* that point, body axes from the vehicle's
                               origin, m */
} ts_link;

typedef struct ts_node {
    int body;               /* index into bodies, -1 if none */
    int link;               /* link ending here, -1 for the tow point */
    int child_begin;        /* children are child_links[child_begin..end) */
    int child_end;
    double mass;            /* lumped structural mass: half links + body, kg
                               (a vehicle's mass is its own, not the
                               node's, and so is half of each link that
                               starts at a point of the vehicle) */
} ts_node;

typedef struct ts_system {
    char name[TS_NAME_MAX];
    ts_environment env;
    ts_tow tow;
    int ncables;
    ts_cable *cables;
    int nbodies;
    ts_body *bodies;

    /* Discretisation, filled by ts_system_build(). */
    int nlinks;
    int nnodes;             /* nlinks + 1 */
    ts_link *links;         /* [nlinks] */
    ts_node *nodes;         /* [nnodes] */
    int *child_links;       /* [nlinks] link indices grouped by upper node */
    int has_added_mass;     /* any can > 0 or body ca > 0 with rho > 0 */
    int has_bending;        /* any ei > 0 */
    int has_elastic;        /* any elastic link */
    int nvehicles;          /* bodies of type vehicle */
} ts_system;

/* Allocate a system with `ncables` zeroed cables and `nbodies` zeroed
 * bodies (environment: rho 1025 kg/m^3, g 9.80665 m/s^2). NULL on failure.
 * A vehicle body's description is allocated with ts_body_set_vehicle. */
TS_API ts_system *ts_system_alloc(int ncables, int nbodies, ts_err *err);

/* Make body b a vehicle with a zeroed description (owned by the system;
 * replaces any previous one) and return it, or NULL when out of memory. */
TS_API ts_vehicle *ts_body_set_vehicle(ts_system *sys, int b, ts_err *err);

/* Free a system and everything it owns. ts_system_free(NULL) does nothing. */
TS_API void ts_system_free(ts_system *sys);

/* A deep copy (description and discretisation). NULL on failure. */
TS_API ts_system *ts_system_copy(const ts_system *sys, ts_err *err);

/* Validate the description and build links and nodes. Checks every value
 * (finite, in range; a vehicle's description with ts_vehicle_check), that
 * `from`/`to` form a tree rooted at the tow point, that each body ends
 * exactly one cable, and that no cable is unreachable.
 * May be called again after changing the description (e.g. nlinks).
 * Returns TS_OK, TS_EINVAL or TS_ENOMEM. */
TS_API int ts_system_build(ts_system *sys, ts_err *err);

/* Index of the cable or body called `name`, -1 if none. */
TS_API int ts_system_find_cable(const ts_system *sys, const char *name);
TS_API int ts_system_find_body(const ts_system *sys, const char *name);

/* Node at which body b sits (lower node of the cable that ends at it), or
 * -1 before ts_system_build(). */
TS_API int ts_system_body_node(const ts_system *sys, int b);

/* Cut every cable into `links` equal links and rebuild. TS_EINVAL for
 * links outside [1, TS_MAX_LINKS] or a cable with link_lengths (the
 * message starts with "links: " and names the cable), TS_ENOMEM. */
TS_API int ts_system_set_links(ts_system *sys, int links, ts_err *err);

/* The next discretisation of `sys` (built): coarser when every cable has
 * at least 2 links (each cable's links halved, rounded up; link_lengths
 * merged in consecutive pairs, an odd last link kept), else finer (every
 * link split in two). *ratio receives the resolution ratio between the
 * two: the smallest ratio of a cable's links to its coarse links (>= 1.5;
 * a cable whose count is odd makes it smaller than 2, and the smallest
 * ratio gives the larger, safe estimate), or 2 when refined. NULL on
 * failure (TS_ENOMEM, or TS_EINVAL when the links would exceed
 * TS_MAX_LINKS). The levels of the discretisation-error estimate
 * (towstab/accuracy.h) and of the equilibrium's start with bending
 * (towstab/equilibrium.h). */
TS_API ts_system *ts_system_level(const ts_system *sys, int coarser,
                                  double *ratio, ts_err *err);

/* Whether sys can be coarsened (every cable has at least 2 links). */
TS_API int ts_system_can_coarsen(const ts_system *sys);

/* Name of node `node` (built system) into buf[size] (cut to fit): "tow"
 * for node 0, the body's name where a body sits, else "<cable>.<k>" for
 * the lower end of link k of that cable. The names every output uses
 * (tables, JSON, CSV, response outputs). */
TS_API void ts_system_node_name(const ts_system *sys, int node, char *buf,
                                size_t size);

/* Wet weight per length of a cable in N/m (weight minus buoyancy). */
TS_API double ts_cable_wet_weight(const ts_system *sys, int c);

/* Largest load (N) on one link or body the solvers take: they form
 * squares and products of forces, which overflow double precision (about
 * 1e308) beyond it. Real towed systems stay below 1e9 N. */
#define TS_LOAD_MAX 1e150

/* The system's reach, m: the tow point's distance from the origin of M
 * plus the length of every cable. A rotation theta about the origin
 * moves no point by more than theta times it. */
TS_API double ts_system_reach(const ts_system *sys);

/* Bounds of the motion over an analysis (all >= 0; NaN or inf where an
 * input is). */
typedef struct ts_motion_bound {
    double speed;      /* |V|, m/s */
    double turn_rate;  /* |Omega|, rad/s */
    double tow_speed;  /* tow-point velocity of an excitation, m/s */
    double tow_accel;  /* its acceleration, m/s^2 */
    double rot_rate;   /* the rate of a tow rotation (tow.roll ...),
                          rad/s: it moves a point at r by rot_rate r */
    double rot_accel;  /* its acceleration, rad/s^2 */
} ts_motion_bound;

/* The bounds of a steady tow at the system's speed and turn rate. */
TS_API void ts_motion_bound_steady(const ts_system *sys, ts_motion_bound *m);

/* Check, before an analysis, that the loads on every link and body are
 * finite and at most TS_LOAD_MAX under motion m: weight, buoyancy, drag at
 * the flow speed bound |V| + |Omega| R + |current| + tow_speed and
 * inertia (added mass included) at the acceleration bound
 * Omega^2 R + |Omega| |V| + tow_accel, R being the tow point's distance
 * from the origin plus the length of the cables. These are sizes, not the
 * forces themselves (no solve): a load that fails here makes the kernel's
 * forces overflow. O(links). Returns TS_OK, or TS_EDOMAIN naming the
 * input that makes the loads too large, the part and the size:
 *   "forces overflow at speed 1e+300 m/s: the drag on cables[0] 'cable'
 *    link 1 is about inf N, beyond the 1e+150 N the solvers can take" */
TS_API int ts_system_check_loads(const ts_system *sys,
                                 const ts_motion_bound *m, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
