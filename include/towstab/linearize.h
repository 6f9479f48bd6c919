/* towstab/linearize.h: the linear model z' = A z + B v about a state
 * (doc/model.md section 6; Kamman & Nguyen eqs. 56-65; doc/linear.md).
 *
 * Two forms of the same model (ts_linearize_opts.model):
 *  - the sparse model (desc): the kernel's node equations before
 *    elimination, E x' = F x + G u with the node displacements, velocities
 *    and link tensions as unknowns, from coloured central differences of
 *    the node residual: a fixed number of residual evaluations (18 to 24
 *    groups on a cable), O(nlinks) time and memory. The eigen analysis
 *    (arpack), the frequency response and the stiff integrator solve with
 *    it at any size (doc/linear.md, section 2b);
 *  - the dense A and B below, O(nlinks^2): LAPACK's eigen analysis, the
 *    linear time-domain simulation, --matrices.
 *
 * Dense: A = df/dy and B = df/du by second-order central differences through the
 * one kernel, column by column (columns are independent and computed in
 * parallel with OpenMP when available, one ts_kernel_clone per thread).
 * The first nq rows of A are exactly [0 I] and of B zero. The step of
 * column j is h_j = rel_step * max(|x_j|, scale_j) (x_j the coordinate
 * perturbed), rounded so that x_j + h_j is exact; scale_j is 1 rad for an
 * angle, 1e-4 for the strain of an elastic link (and the angle-rate scale
 * times 1e-4 for its rate), (sqrt(g l) + |V|) / l for the rate of a link
 * of length l, the top
 * link's length for a tow displacement, sqrt(g l) + |V| for a tow velocity
 * and g for a tow acceleration. The truncation error is estimated by
 * differentiating again with steps 2 h_j: for a smooth f the error of the
 * h result is (A(2h) - A(h)) / 3 to leading order; the rounding noise of
 * the differences from the kernel's own scatter (fnoise).
 *
 * Inputs v (ts_kernel_ninput): tow-point displacement x, y, z (m),
 * velocity (m/s), acceleration (m/s^2) in the mean ship frame, named
 * tow.surge, tow.sway, tow.heave for displacement (their velocity and
 * acceleration columns follow in the same order), then the rotations
 * tow.roll, tow.pitch, tow.yaw (rad; rad/s, rad/s^2 after them; the
 * kernel's u[TS_TOW_ROT..], towstab/kernel.h): TS_NINPUT = 18; the
 * vehicles' inputs; last the frame's speed, turn rate and their rates
 * (tow.speed, tow.turn_rate, tow.speed_rate, tow.turn_accel; m/s, rad/s,
 * m/s^2, rad/s^2): a change of the mean frame's motion, the state staying
 * the deviation from y0 in the frame so moved (doc/linear.md, section
 * 1). Matrices are column-major: A[i + j n].
 *
 * Besides A and B the result holds what the mode and response reports map
 * through: the tension Jacobians (optional) and the derivatives of every
 * link direction with respect to its two angles, from which node
 * displacements follow exactly (ts_linear_node_displacements).
 */
#ifndef TOWSTAB_LINEARIZE_H
#define TOWSTAB_LINEARIZE_H

#include "towstab/equilibrium.h"
#include "towstab/error.h"
#include "towstab/kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Input channels (columns of B). */
enum {
    TS_IN_DISP = 0,   /* tow displacement x, y, z: columns 0, 1, 2 */
    TS_IN_VEL = 3,    /* tow velocity x, y, z: columns 3, 4, 5 */
    TS_IN_ACC = 6,    /* tow acceleration x, y, z: columns 6, 7, 8 */
    TS_IN_ROT = 9,    /* tow rotation about x, y, z: columns 9, 10, 11 */
    TS_IN_ROT_VEL = 12, /* its rate: 12, 13, 14 */
    TS_IN_ROT_ACC = 15  /* its acceleration: 15, 16, 17 */
};

/* The frame inputs, the last TS_NFRAME_INPUT columns of B (from
 * ts_linear.frame_input on): changes of the mean frame's speed V (m/s),
 * turn rate Omega (rad/s) and their rates (m/s^2, rad/s^2), added to the
 * kernel's frame (ts_kernel_set_frame) for each evaluation. */
#define TS_NFRAME_INPUT 4
enum {
    TS_FRAME_SPEED = 0,      /* "tow.speed" */
    TS_FRAME_TURN_RATE = 1,  /* "tow.turn_rate" */
    TS_FRAME_SPEED_RATE = 2, /* "tow.speed_rate" */
    TS_FRAME_TURN_ACCEL = 3  /* "tow.turn_accel" */
};

/* Room for an input or output name ("<vehicle>.<loop>.setpoint"). */
#define TS_IO_NAME (2 * TS_NAME_MAX + 16)

/* The sparse descriptor model (opaque; doc/linear.md, section 2). */
typedef struct ts_descriptor ts_descriptor;

/* Which linear models ts_linearize forms. */
typedef enum {
    TS_LIN_AUTO = 0,   /* the sparse model always; the dense A and B too
                          when nstate < dense_max_states (or at any size
                          when the sparse model does not cover the
                          system: a vehicle whose controller states are
                          not one block of its own) */
    TS_LIN_DENSE = 1,  /* the dense A and B only */
    TS_LIN_SPARSE = 2, /* the sparse model only */
    TS_LIN_BOTH = 3    /* the dense model at any size, and the sparse one */
} ts_lin_model;

/* A neutral mode by symmetry of a towing vehicle (ts_linear.neutral). */
#define TS_NEUTRAL_MAX 3
typedef struct ts_neutral {
    double re, im;     /* its exact eigenvalue, 1/s: 0, or i |Omega| */
    int cyclic;        /* the state the kernel does not read (its column
                          of A is zero; the eigen analysis cuts its
                          integrator chain), or -1 */
    char name[32];     /* "along-track position", "cross-track position",
                          "heading", "turn centre" */
} ts_neutral;

typedef struct ts_linear {
    int nstate;        /* n = 2 nq + nc (nc controller states) */
    int nq;            /* generalised coordinates (ts_kernel_nq) */
    int ninput;        /* ts_kernel_ninput + TS_NFRAME_INPUT: TS_NINPUT
                          tow inputs, the vehicles' surfaces and loops
                          (the kernel's inputs), then the frame inputs */
    int frame_input;   /* index of the first frame input, "tow.speed":
                          ts_kernel_ninput, the kernel's inputs before */
    int nlinks, nnodes;
    double *A;         /* [n * n] column-major; rows 0..nq-1 are [0 I 0];
                          NULL unless the dense model was formed */
    double *B;         /* [n * ninput] column-major; rows 0..nq-1 zero;
                          NULL with A */
    ts_descriptor *desc; /* the sparse model E x' = F x + G u of the node
                          and vehicles' equations (O(nlinks) memory), NULL
                          unless formed; the eigen, response and stiff
                          simulation solvers use it at any size, the
                          linear simulation without the dense A
                          (ts_simulate_linear) */
    double *y0;        /* [n] state linearized about (kernel's charts) */
    double *u0;        /* [ninput] input linearized about (its frame
                          inputs zero) */
    double *f0;        /* [n] f(y0, u0): zero at an exact equilibrium */
    double *r0;        /* [3 nnodes] node positions at y0, m */
    double *t0;        /* [nlinks] link tensions at y0, N */
    double *dn;        /* [6 nlinks] dn/dtheta1, dn/dtheta2 of each link at
                          y0 (1/rad, M frame, in the link's chart) */
    double *n0;        /* [3 nlinks] link unit directions at y0 */
    double *len0;      /* [nlinks] link lengths at y0, l (1 + e), m */
    int *qoff;         /* [nlinks] offset of each link's coordinates in q
                          (ts_kernel_link_offset) */
    char *elastic;     /* [nlinks] 1: the link's third coordinate is its
                          strain e */
    int nvehicles;
    int root_qoff;     /* offset in q of the towing vehicle's position
                          (its tow point, node 0), -1 without one */
    int root_dof;      /* its degrees of freedom (ts_kernel_root_dof): 6,
                          3 for a surface ship (x, y at root_qoff, its yaw
                          just before), 0 without one */
    int *up_qoff;      /* [nlinks] for a link starting at a point P of a
                          vehicle, the offset of that vehicle's angles in
                          q; -1 otherwise; NULL without vehicles */
    double *up_map;    /* [12 nlinks] for such a link, R E of its vehicle
                          at y0 (M frame, 9 row-major: the small rotation
                          of the body per angle change) and rho_P = R (P -
                          A) (3, m); NULL without vehicles */
    double *veh_rot;   /* [9 nvehicles] R E of each vehicle at y0 (M
                          frame, row-major): its small rotation (rad) per
                          change of its three angles, in kernel vehicle
                          order; NULL without vehicles */
    int *veh_qoff;     /* [nvehicles] offset of each vehicle's angles in
                          q; NULL without vehicles */
    double *tow_lever; /* [3 nnodes] the lever r (M axes, m, at y0) by
                          which a tow rotation theta moves node i with
                          the coordinates held (theta x r): the start
                          point of the cable it hangs on, from M's origin
                          (a prescribed tow: tow.point) or from the towing
                          vehicle's origin; ts_linear_tow_shift */
    double *Ty;        /* [nlinks * n] dT/dy (N/rad, N s/rad) column-major,
                          or NULL unless opts.tensions */
    double *Tu;        /* [nlinks * ninput] dT/du (N/m, N s/m, N s^2/m),
                          or NULL unless opts.tensions */
    int noutput;       /* the vehicles' outputs (ts_kernel_noutput): per
                          vehicle depth, pitch, roll, yaw and each loop's
                          output */
    double *v0;        /* [noutput] their values at y0 (m, rad) */
    double *Vy;        /* [noutput * n] d output / dy, column-major; NULL
                          without vehicles */
    double *Vu;        /* [noutput * ninput] d output / du; NULL without
                          vehicles */
    double *Terr;      /* [nlinks * (n + ninput)] the error estimate of Ty
                          (columns 0..n-1) and Tu (the rest), (T(2h) -
                          T(h)) / 3, column-major; NULL unless tensions
                          and estimate_error */
    double *Verr;      /* [noutput * (n + ninput)] the same of Vy and Vu;
                          NULL without vehicles or estimate_error */
    double *onoise;    /* [nlinks + noutput] rounding noise of one kernel
                          evaluation of each link tension (N) and vehicle
                          output (m, rad), measured with fnoise: entry
                          (i, j) of Ty or Vy carries onoise[i] / (sqrt(2)
                          h[j]); NULL unless estimate_error (tensions
                          NaN without opts.tensions) */
    char (*input_name)[TS_IO_NAME];  /* [ninput] ts_kernel_input_name */
    const char **input_unit;         /* [ninput] ts_kernel_input_unit */
    char (*output_name)[TS_IO_NAME]; /* [noutput] ts_kernel_output_name */
    const char **output_unit;        /* [noutput] ts_kernel_output_unit */
    double *Aerr;      /* [(n - nq) * n] estimated error of the lower block
                          of A (rows nq..n-1), (A(2h) - A(h)) / 3,
                          column-major with leading dimension n - nq
                          (A(h) - Aerr is the Richardson value); NULL
                          unless estimate_error */
    double *h;         /* [n + ninput] the step used for each column */
    double trunc_err;  /* max |A(h) - A(2h)| / 3 over the lower block */
    double trunc_norm; /* ||A(h) - A(2h)||_F / 3 over the lower block: the
                          size of the error matrix dA used for eigenvalue
                          error bounds (1/s, 1/s^2 mixed, as A) */
    double *fnoise;    /* [n - nq] rounding noise of one kernel evaluation
                          of each lower row of f (its scatter at 8 states a
                          ten-thousandth of a step from y0, less A's part):
                          entry (i, j) of A carries rounding noise
                          fnoise[i] / (sqrt(2) h[j]), which the truncation
                          estimate samples only by chance; NULL unless
                          estimate_error */
    double *Berr;      /* [(n - nq) * ninput] the same for B's lower
                          block; NULL unless estimate_error */
    double round_norm; /* the Frobenius norm of that noise over the state
                          columns (units of A); NaN unless estimate_error */
    double b_trunc_err;/* max |B(h) - B(2h)| / 3 */
    double t_trunc_err;/* max |T(h) - T(2h)| / 3 of the tension rows */
    double a_scale;    /* max |A_ij| of the lower block, for relative use */
    double a_norm;     /* ||A||_F (whole matrix) */
    int kinks;         /* nodes (tow point included) within 2 steps of the
                          water surface z = 0 while the fluid has density:
                          f is not smooth there and the central difference
                          is the mean of one-sided derivatives (doc/model.md
                          section 6) */
    int kink_tow;      /* 1 when the tow point is one of them: only B (and
                          Tu) are affected, not A */
    int kink_node;     /* first such node other than the tow point, or -1 */
    int threads;       /* threads used */
    long evaluations;  /* kernel evaluations used (dense model) */
    long residual_evaluations; /* node-residual evaluations (sparse) */
    int groups;        /* perturbation groups of the sparse model's
                          coloured differences (independent of nlinks) */
    double desc_err;   /* largest relative error estimate of the sparse
                          model, max(|dK|/max|K|, |dC|/max|C|); NaN
                          without the estimate or the model */
    double desc_round; /* largest relative rounding noise of one entry of
                          the sparse model, rnoise_i / (sqrt(2) h_j) over
                          max|K| (max|C|): the residual's own scatter
                          (doc/linear.md, section 2b); NaN without the
                          estimate or the model */
    /* A towing vehicle's neutral modes by symmetry (doc/linear.md section
     * 3c, doc/towing-vehicle.md section 6): motions of the whole system
     * that the physics cannot tell from its steady motion, each an exact
     * eigenpair (lambda, g) of the model, written from the geometry, not
     * from A. In a straight tow: the tow point's position along and
     * across the track (states the kernel reads nowhere: cyclic, their
     * columns of A zero) and the heading (every link, every vehicle
     * turned about the vertical, the tow point moving sideways at V); in
     * a steady turn: the heading about the turn's centre (lambda 0) and
     * the position of that centre (lambda = i |Omega|). A candidate is
     * kept only when the model confirms it, A g = lambda g within the
     * linearization's error (the dense A's, or without it the sparse
     * model's rows): a current, a heading loop or anything else that
     * breaks the symmetry leaves it out. Empty without a towing
     * vehicle. */
    int nneutral;                  /* 0 .. TS_NEUTRAL_MAX */
    ts_neutral neutral[TS_NEUTRAL_MAX];
    double *neutral_re, *neutral_im; /* [n * nneutral] g, column k for
                          neutral[k] (position m, angle rad per m or rad
                          of the motion); NULL when nneutral is 0 */
} ts_linear;

typedef struct ts_linearize_opts {
    double rel_step;   /* default cbrt(DBL_EPSILON) ~ 6.1e-6 */
    int estimate_error;/* 1 (default): also differentiate with 2h */
    int threads;       /* 0 (default): OpenMP's choice from 200 links on,
                          serial below; 1: serial; k: k threads */
    int tensions;      /* 1: also fill Ty and Tu (dense model; default 0) */
    ts_lin_model model;/* default TS_LIN_AUTO */
    int dense_max_states; /* TS_LIN_AUTO forms the dense model below this
                          many states; default 1200 (300 rigid links) */
    int frame_inputs;  /* 1: the sparse model has the frame inputs'
                          columns too (tow.speed, tow.turn_rate and their
                          rates; 4 perturbation groups more, 2 or 4
                          residual evaluations each), for a response to
                          them or a manoeuvre; 0 (default): not (a frame
                          input's response or a manoeuvre then needs the
                          dense model). Never with a towing vehicle */
} ts_linearize_opts;

TS_API void ts_linearize_opts_default(ts_linearize_opts *o);

/* Allocate a result sized for kernel k's system (O(nlinks); the dense A,
 * n x n doubles, 8 n^2 bytes, is allocated by ts_linearize only when the
 * dense model is formed). NULL on failure. */
TS_API ts_linear *ts_linear_alloc(const ts_kernel *k, ts_err *err);
TS_API void ts_linear_free(ts_linear *lin);

/* Linearize kernel k about state y0[nstate] and input
 * u0[ts_kernel_ninput(k)] (NULL: zero; the frame inputs are zero there:
 * the kernel's frame, used as set), forming the models opts->model asks
 * for. The kernel's charts must be those of y0. Cost: sparse model
 * 2 or 4 residual evaluations per group (18 to 24 groups), O(nlinks);
 * dense model (2 or 4) (n + 9) kernel evaluations, O(nlinks) each, so
 * O(nlinks^2); both divided among the threads. The sparse model is exact
 * about a state at rest relative to M (an equilibrium); elsewhere its maps
 * to the kernel's coordinates omit terms of first order in the link
 * rates. On return the kernel's
 * last-evaluation results are those of (y0, u0). Returns TS_OK, TS_CHART
 * (a perturbed state left the chart: re-chart y0 first), TS_ESINGULAR (the
 * kernel failed at a perturbed state), TS_EINVAL (sizes differ) or
 * TS_ENOMEM. */
TS_API int ts_linearize(ts_kernel *k, const double y0[], const double u0[],
                        const ts_linearize_opts *opts, ts_linear *lin,
                        ts_err *err);

/* Linearize about a solved equilibrium: refuses one that did not converge
 * (TS_ECONV, naming its residual and target); otherwise re-charts k from
 * eq->directions (ts_kernel_set_directions with TS_CHART_RECHART, so any
 * kernel of the system will do), sets the vehicles' attitudes and the
 * controller states (ts_equilibrium_set_bodies) and calls ts_linearize
 * with zero rates and zero input. */
TS_API int ts_linearize_equilibrium(ts_kernel *k, const ts_equilibrium *eq,
                                    const ts_linearize_opts *opts,
                                    ts_linear *lin, ts_err *err);

/* Node displacements dr[3 nnodes] (m, M frame; node 0, the tow point, is 0)
 * produced by coordinate perturbations dq[nq] (angles, rad; strains) about
 * lin->y0, to first order: dr_k = dr_p + l_k (dn/dt1 dq1 + dn/dt2 dq2)
 * (+ l n de for an elastic link; l_k its length at y0) down the tree; a
 * cable starting at a point P of a vehicle starts from dr_A + (R E
 * dtheta) x rho_P. Exact geometry, O(nlinks). */
/* The displacement d[3] (M axes) of node `node` per unit of tow input
 * `input` (a displacement channel: TS_IN_DISP + j, or TS_IN_ROT + j)
 * with the coordinates held: e_j for a translation, e_j x r for a
 * rotation (r = lin->tow_lever of the node); zero for node 0 of a towing
 * vehicle (its own point, which the inputs do not move) and for any
 * other input. */
TS_API void ts_linear_tow_shift(const ts_linear *lin, int node, int input,
                                double d[3]);

TS_API void ts_linear_node_displacements(const ts_system *sys,
                                         const ts_linear *lin,
                                         const double dq[], double dr[]);

/* The small rotation phi[3 nvehicles] (rad, M axes, kernel vehicle
 * order) of every vehicle produced by coordinate perturbations dq[nq]
 * about lin->y0, to first order: phi = R E dtheta (R the attitude at y0,
 * E the rate matrix of its angles). Nothing without vehicles. */
TS_API void ts_linear_vehicle_rotations(const ts_linear *lin,
                                        const double dq[], double phi[]);

/* Name of input column j ("tow.surge", "tow.sway", "tow.heave",
 * "tow.surge_velocity", ..., "tow.heave_acceleration"); NULL outside
 * [0, TS_NINPUT). */
TS_API const char *ts_input_name(int j);

/* Name and unit of frame input c (TS_FRAME_SPEED ...): "tow.speed",
 * "tow.turn_rate", "tow.speed_rate", "tow.turn_accel"; "m/s", "rad/s",
 * "m/s^2", "rad/s^2". NULL outside [0, TS_NFRAME_INPUT). Its column of B
 * is ts_linear.frame_input + c. */
TS_API const char *ts_frame_input_name(int c);
TS_API const char *ts_frame_input_unit(int c);

#ifdef __cplusplus
}
#endif
#endif
