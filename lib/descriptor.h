/* descriptor.h (internal): the sparse linear model of the node residual
 * (doc/linear.md, section 2; doc/model.md section 6).
 *
 * The kernel's equations before elimination (lib/kernel_impl.h) couple a
 * node only with its neighbours: with the node displacements dr, their
 * velocities dv and the link tensions dt as unknowns, the linear model
 * about a state is
 *
 *     M dr'' + C dr' + K dr + N dt = -(K_0 + s C_0) u     (3 per free node)
 *     rigid link l:    n_l . (dr_k - dr_p) = 0             (1 per link)
 *     elastic link l:  dt_l = (EA/l) n.dd + Cv n.dd'     (EA de + Cv l de')
 *
 * (k, p the link's lower and upper node, dd = dr_k - dr_p), i.e. the
 * descriptor system E x' = F x + G u with x = (dr, dv, dt),
 * E = diag(I, M, 0), F = [[0, I, 0], [-K, -C, -N], [constraints]]: E is
 * singular on the tensions (and, for rigid links, the constrained
 * components), whose infinite eigenvalues are never formed. M is the
 * nodal mass matrices (exact), N the link directions (exact), the
 * constraint rows exact; K = dR/dr and C = dR/dv are 3x3 blocks between
 * nodes within 2 links of each other (1 without bending), found by
 * coloured central differences of the residual: columns whose rows do not
 * overlap are perturbed together, so the number of residual evaluations is
 * fixed by the tree's local structure (18 to 24 groups for a cable, 2 or 4
 * evaluations each), not by its length.
 *
 * The kernel's state y = (q, q') (link angles and strains and their rates,
 * towstab/kernel.h) maps to node displacements locally: dr_k = dr_p +
 * D_l dq_l (D_l the derivative of l (1 + e) n with respect to the link's
 * coordinates), dr' = D dq' at a state at rest relative to M. So
 * (s I - A)^-1, A's action and the dense A itself follow from solves with
 * the sparse matrices
 *
 *     S(s)   = [[s^2 M + s C + K, N], [constraint rows]]     (shifted)
 *     S_inf  = [[M, N], [acceleration constraints]]          (A itself)
 *
 * in O(nlinks) each (lib/shift.c). The unknowns are ordered node by node:
 * free node j >= 1 owns columns 4 (j - 1) .. + 2 (its displacement) and
 * 4 (j - 1) + 3 (the tension of the link ending at it, link j - 1); its
 * rows likewise (its 3 force equations, then that link's row). Then each
 * towed vehicle's 3 angles (a point of their own: rows its rotational
 * equations), then the controller states (rows their rates): KLU orders
 * them for the factorisation.
 *
 * A towed vehicle (doc/linear.md, section 2b, "Vehicles") adds its angles
 * as a point beside its node, with blocks of K and C like a node's; its
 * inertia couples its node's acceleration and its angle accelerations
 * (Mv); its controller states, inputs and outputs are small dense local
 * blocks (Lv, Ov) on its node and angles.
 *
 * A towing vehicle at the root (doc/linear.md, section 2c) is a vehicle
 * whose node is node 0, the tow point, which is then free: its
 * displacement takes the three unknowns after the controller states, and
 * node 0's rows are the body's translational equations. A surface ship
 * (3 degrees of freedom) keeps the same points; the components it holds
 * (node 0's z, the roll and pitch of its angles) get identity rows
 * (their displacement is 0) and no inertia, no loads, no error. The tow
 * inputs then move the points the cables start from relative to the
 * body: their columns (Gt) are the residual's central differences, at
 * fixed points, over every row.
 */
#ifndef TOWSTAB_DESCRIPTOR_H
#define TOWSTAB_DESCRIPTOR_H

#include <complex.h>

#include "kernel_impl.h"
#include "lazylib.h"
#include "towstab/linearize.h"

/* Link kinds in the constraint rows. */
enum { TSI_LINK_RIGID = 0, TSI_LINK_TAUT = 1, TSI_LINK_SLACK = 2 };

/* Points: the nn nodes (3 unknowns each: the displacement), then one per
 * vehicle (its three angles, rad): the blocks, the colouring and the
 * steps treat both alike. A vehicle point is a neighbour of its node and
 * of the lower nodes of the cables leaving it (which start at its points
 * P, moving with its attitude). */

/* A vehicle's local block (tsi_desc Lv): rows its node's 3 force rows, its
 * 3 rotational rows, then its nc controller rows; columns its node's
 * displacement (3), its angles (3), their rates (3 + 3), its controller
 * states (nc), its inputs (nin). Only the parts the point blocks K and C
 * do not hold are filled: the force and rotational rows' controller and
 * input columns, and every column of the controller rows. */
enum { TSI_LV_R = 0, TSI_LV_TH = 3, TSI_LV_V = 6, TSI_LV_W = 9,
       TSI_LV_C = 12 };

struct ts_descriptor {
    const ts_system *sys;
    int nn, nl;          /* nodes (node 0 the tow point), links */
    int nv, np;          /* vehicles; points nn + nv */
    int nq, nstate;      /* the kernel's coordinates and states */
    int nc, nin;         /* controller states, inputs (ts_kernel_ninput) */
    tsi_vehicle_layout *vl; /* [nv] each vehicle's node, angles, controller
                            states and inputs */
    int nx;              /* unknowns 4 (nn - 1) + 3 nv + nc (+ 3 with a
                            towing vehicle: node 0's displacement) */
    int root;            /* the towing vehicle's index among the vehicles,
                            -1: the tow point is prescribed */
    int rdof;            /* its degrees of freedom, 6 or 3; 0 */
    int p0;              /* the first point with unknowns: 0 with a towing
                            vehicle, else 1 */
    double *Gt, *Gterr;  /* [TS_NINPUT (3 np + nc)] a towing vehicle's
                            tow inputs: the residual's change per unit
                            input at fixed points, and its estimate (NULL
                            without the towing vehicle / the estimate) */
    double *Gf, *Gferr;  /* [TS_NFRAME_INPUT (3 np + nc)] the frame inputs
                            (the mean frame's speed, turn rate and their
                            rates, towstab/linearize.h) the same way:
                            the residual's change per unit at fixed
                            points, and its estimate (NULL with a towing
                            vehicle, whose speed and turn rate are
                            solved, not inputs / without the estimate);
                            formed only when `frame` asks */
    double hf[TS_NFRAME_INPUT]; /* their steps (m/s, rad/s, m/s^2,
                            rad/s^2) */
    int frame;           /* 1: Gf (and Gferr) hold the frame columns: set
                            it before tsi_desc_linearize to ask for them
                            (4 perturbation groups more; the caller's
                            ts_linearize_opts.frame_inputs), which it
                            clears with a towing vehicle; 0: Gf is not
                            formed */
    /* The state linearized about. */
    double *r0, *v0, *a0; /* [3 np] node positions, velocities and
                            accelerations relative to M (m, m/s, m/s^2);
                            then each vehicle's angles, rates and angle
                            accelerations (rad, rad/s, rad/s^2) */
    double *t0;          /* [nl] tensions, N */
    double *y0;          /* [nstate] the state (vehicle rates and
                            controller states are read from it) */
    double *u0;          /* [nin] the input */
    double *M;           /* [6 nn] nodal mass matrices (sym packed), kg */
    double *Mv;          /* [36 nv] each vehicle's inertia in its rows
                            (tsi_kernel_vehicle_mass) */
    double *pg;          /* [3 nl] a link leaving a vehicle at P: the
                            displacement of P along n per angle change,
                            (R E)^T (rho_P x n) (m/rad); 0 otherwise */
    double *pm;          /* [3 nl] such a link's tension in its vehicle's
                            rotational rows, -(rho_b x R^T n) (m) */
    double *n;           /* [3 nl] link directions d / |d| */
    double *len;         /* [nl] |d|, m */
    double *ka, *ca;     /* [nl] EA / l (N/m) and Cv (N s/m) of elastic
                            links, 0 for rigid ones */
    char *kind;          /* [nl] TSI_LINK_* */
    /* K and C as 3x3 blocks: row point k >= 1 has blocks bptr[k] ..
     * bptr[k + 1] - 1 with column points bcol[] (sorted, node 0 included:
     * the tow point's columns are the inputs). Row-major blocks. */
    int *bptr;           /* [np + 1] */
    int *bcol;           /* [nblocks] */
    int *btr;            /* [nblocks] index of block (j, k) for (k, j) */
    char *bdist;         /* [nblocks] links between k and j */
    int nblocks;
    double *K, *C;       /* [9 nblocks] dR/dr (N/m), dR/dv (N s/m) */
    double *Kerr, *Cerr; /* [9 nblocks] (D(2h) - D(h)) / 3, or NULL */
    int *lv_off;         /* [nv + 1] offsets of the vehicles' local
                            blocks in Lv */
    double *Lv, *Lerr;   /* local blocks (TSI_LV_*), row-major with 12 +
                            nc + nin columns; Lerr NULL without the
                            estimate */
    int nout;            /* the vehicles' outputs (ts_kernel_noutput) */
    int *ov_off;         /* [nv + 1] offsets of the output blocks in Ov */
    double *Ov, *Oerr;   /* each vehicle's outputs (depth, pitch, roll,
                            yaw, loop outputs, deflections) on its local
                            columns (TSI_LV_*; rows its nout, row-major
                            with 12 + nc + nin columns); Oerr NULL
                            without the estimate */
    double *onoise;      /* [nout] the outputs' rounding noise (m, rad);
                            NULL without the estimate */
    double *hc, *hu;     /* [nc], [nin] steps of the controller states and
                            the vehicles' inputs */
    double *rnoise;      /* [3 np + nc] rounding noise of one residual
                            evaluation of each row (node force N,
                            vehicle moment N m, controller rate; rows of
                            node 0 unused): entry (i, j) of K carries
                            noise rnoise[i] / (sqrt(2) hr[j]), of C
                            rnoise[i] / (sqrt(2) hv[j]), of a controller
                            column rnoise[i] / (sqrt(2) hc[j]); NULL
                            without the estimate */
    /* Colouring of the finite differences. */
    int *rcolour, *vcolour; /* [np] */
    int nrcolour, nvcolour;
    int ncgroups, nugroups; /* the most controller states and inputs of a
                            vehicle: one group each */
    double *hr, *hv;     /* [3 np] steps of r and v, m and m/s (rad and
                            rad/s for a vehicle point) */
    /* Sparse pattern of S(s) (and S_inf) in compressed columns. */
    int nnz;
    int *Sp, *Si;        /* [nx + 1], [nnz] */
    int *pos;            /* the position arrays below, one block */
    int *pos_blk;        /* [9 nblocks] position of block (k, j) entry
                            (row a, column b) at 9 b' + 3 a + b, -1 when
                            j = 0 or k = 0 */
    int *pos_n;          /* [2 * 3 nl] positions of dR_lower/dt_l (3) and
                            dR_upper/dt_l (3, -1 at the tow point) */
    int *pos_row;        /* [2 * 3 nl] link row l on dr_lower (3) and
                            dr_upper (3, -1 at the tow point) */
    int *pos_diag;       /* [nl] link row l on dt_l */
    int *pos_pm;         /* [3 nl] rotational rows on dt_l (links leaving
                            a vehicle), -1 */
    int *pos_pg;         /* [3 nl] link row l on its vehicle's angles, -1 */
    int *pos_lv;         /* [per vehicle (6 + nc) (6 + nc)] the local
                            block's entries in S: rows as Lv, columns its
                            node's displacement, its angles, its
                            controller states; -1 where S has none */
    int *lvp_off;        /* [nv + 1] offsets in pos_lv */
    tsi_klu klu;         /* KLU, opened by tsi_desc_alloc */
    void *klu_symbolic;  /* KLU's ordering of the pattern (klu_symbolic *),
                            computed once by tsi_desc_alloc */
    void *klu_common;    /* KLU's default parameters (klu_common *); each
                            factorisation works on its own copy */
    /* Statistics. */
    int groups;          /* perturbation groups (colours x components,
                            controller states, inputs) */
    long evaluations;    /* residual evaluations */
    double k_scale, c_scale; /* max |K|, max |C| entries */
    double k_err, c_err; /* max |Kerr|, max |Cerr| */
    double k_round, c_round; /* max rnoise_i / (sqrt(2) h_j) over the
                            entries of K and C */
    /* A towing vehicle's cyclic states cut for the eigen analysis (its
     * copy of the model, tsi_desc_cut; none in the linearization's own):
     * the states cut[0 .. ncut) (the tow point's position along, across
     * the track: kernel state root_qoff + cut_comp[i]) whose columns of
     * A are zero. The solves of lib/shift.c then act with the cut A
     * (doc/linear.md section 3a). */
    int ncut;
    int cut[2], cut_comp[2];
};

/* Unknown of point k's component c (k >= 1), of link l's tension, of
 * controller state j. */
static inline int tsi_desc_xr(const ts_descriptor *d, int k, int c)
{
    if (k == 0)
        return 4 * (d->nn - 1) + 3 * d->nv + d->nc + c; /* a towing vehicle */
    return k < d->nn ? 4 * (k - 1) + c : 4 * (d->nn - 1) + 3 * (k - d->nn) + c;
}

/* Whether component c of point k is held by a surface ship (node 0's z,
 * its roll and pitch): an identity row, displacement 0. */
static inline int tsi_desc_held(const ts_descriptor *d, int k, int c)
{
    if (d->rdof != 3)
        return 0;
    return (k == 0 && c == 2) || (k == d->nn + d->root && c < 2);
}
#define TSI_XT(l) (4 * (l) + 3)
static inline int tsi_desc_xc(const ts_descriptor *d, int j)
{
    return 4 * (d->nn - 1) + 3 * d->nv + j;
}

/* A descriptor for kernel k's system (k gives the vehicles' places in
 * the state and the inputs): neighbours, colouring and the pattern of S
 * (O(nlinks)). NULL with err set on failure (TS_ENOMEM; TS_EINVAL when
 * a vehicle's controller states or inputs are not one block of its
 * own). */
ts_descriptor *tsi_desc_alloc(const ts_kernel *k, ts_err *err);
void tsi_desc_free(ts_descriptor *d);

/* Linearize the residual of kernel k about y0[nstate], u0[ninput] and
 * f0 = f(y0, u0), whose evaluation must be k's last (positions,
 * velocities, accelerations, tensions are read from it), with steps
 * rel_step * max(|x|, scale) (scales: the length of the link ending at
 * the node, m; sqrt(g l) + |V|, m/s; a vehicle's angles 1 rad and their
 * rates (sqrt(g l) + |V|) / l, l its hull's length; controller states
 * and inputs 1) and, with estimate, the error estimate from steps 2h.
 * threads: 1 serial, more with OpenMP (kernel clones). Returns TS_OK,
 * TS_ESINGULAR (a link of zero length) or TS_ENOMEM. */
int tsi_desc_linearize(ts_descriptor *d, ts_kernel *k, const double y0[],
                       const double u0[], const double f0[], double rel_step,
                       int estimate, int threads, ts_err *err);

/* The linearization's error in the bilinear form w^T dS(s) x over the
 * rows of points and controller states, dS(s) = dK + s dC and the local
 * blocks' errors (M, N and the link rows are exact): w[nx] (complex),
 * x[3 np + nc] point displacements then controller states (complex; x_0,
 * the tow point's, is an input column). *trunc = |w^T dS x|; *round =
 * the root mean square of w^T N x for the noise N of the differences,
 * independent entries rnoise_i / (sqrt(2) h_j) (|s| rnoise_i / (sqrt(2)
 * hv_j) in C, within one link), i.e. sqrt(sum_i |w_i|^2 rnoise_i^2 X_i
 * / 2), X_i = sum over row i's columns j of |x_j|^2 / h_j^2 (|s|^2 /
 * hv_j^2 for a rate). NaN without the estimate. O(nlinks). */
void tsi_desc_error_terms(const ts_descriptor *d, const double complex w[],
                          const double complex x[], double complex s,
                          double *trunc, double *round);

/* dq[nq] of node displacements dr[3 nn] (which must keep every rigid
 * link's length, n.dd = 0; the normal part is ignored), a cable leaving a
 * vehicle taken from the vehicle's attach node (its rotation ignored).
 * Real arrays; O(nlinks). */
void tsi_desc_from_nodes(const ts_system *sys, const ts_linear *lin,
                         const double dr[], double dq[]);

/* Point displacements p[3 np] (p_0 = 0) of coordinate perturbations
 * dq[nq] (node displacements by ts_linear_node_displacements, then the
 * vehicles' angles), and back: dq[nq] of point displacements that keep
 * the rigid links' lengths (a cable leaving a vehicle starts at its
 * point P, displaced with the body). Real arrays; O(nlinks). */
void tsi_desc_to_points(const ts_descriptor *d, const ts_linear *lin,
                        const double dq[], double p[]);
void tsi_desc_from_points(const ts_descriptor *d, const ts_linear *lin,
                          const double p[], double dq[]);

/* The same of nv vectors (1 or 2) at once: one walk of the links for
 * all (the solves map the real and imaginary parts, or the coordinates
 * and their rates, each time). tsi_node_displacements is
 * ts_linear_node_displacements's (lib/linearize.c). */
void tsi_node_displacements(const ts_system *sys, const ts_linear *lin,
                            int nv, const double *const dq[],
                            double *const dr[]);
void tsi_desc_to_points_n(const ts_descriptor *d, const ts_linear *lin,
                          int nv, const double *const dq[],
                          double *const p[]);
void tsi_desc_from_points_n(const ts_descriptor *d, const ts_linear *lin,
                            int nv, const double *const p[],
                            double *const dq[]);

/* y[3 np] = M x: the nodal masses and the vehicles' inertia (x[3 np],
 * the accelerations of the points; rows of node 0 zero). */
void tsi_desc_mass_mul(const ts_descriptor *d, const double x[], double y[]);

/* The controller rows' and the force rows' local terms (TSI_LV_*): with
 * the points' displacements p[3 np] and rates pv[3 np] (pv may be NULL:
 * zero), the controller states c[nc] (NULL: zero) and inputs u[nin]
 * (NULL: zero), into hc[nc] the controller rates' change (Hr p + Hv pv
 * + Hc c + Hu u) and with f[3 np] (may be NULL) f += the force rows'
 * change through the controller states and inputs (Kc c + Ku u). err:
 * the local blocks' error estimate instead (zero without it). */
void tsi_desc_local_mul(const ts_descriptor *d, const double p[],
                        const double pv[], const double c[], const double u[],
                        double hc[], double f[], int err);

/* Values of S(s) (S_inf when inf) into Sx[nnz] (real s) or Sz[2 nnz]
 * (interleaved complex s): see the head of this file. */
void tsi_desc_fill_real(const ts_descriptor *d, double s, int inf,
                        double Sx[]);
void tsi_desc_fill_complex(const ts_descriptor *d, double complex s,
                           double Sz[]);

/* S(s)'s values as Sk + s Sc + s^2 Sm, each [nnz] (real): for a
 * sequence of shifts (lib/shift.c, tsi_shift_refactor), each S(s) is
 * then one pass over the three. */
void tsi_desc_fill_parts(const ts_descriptor *d, double Sk[], double Sc[],
                         double Sm[]);

/* The row of a taut elastic link l at shift s: its coefficients g[3] on
 * dr_lower (and -g on dr_upper), (EA/l + s Cv) n. */
void tsi_desc_taut_row(const ts_descriptor *d, int l, double complex s,
                       double complex g[3]);

/* A motion of the whole system with the tensions unchanged (a towing
 * vehicle's neutral mode by symmetry, doc/linear.md section 3a) against
 * the sparse model: with the point displacements p[3 np], their rates
 * pv[3 np] and the controller states c[nc] (NULL: zero), all complex,
 * and the eigenvalue lam, the residuals of the point rows, lam M pv +
 * C pv + K p + Kc c, and of the controller rows, lam c - (Hr p + Hv pv
 * + Hc c), each against its error allowance: sum_j (|Kerr_ij| + rnoise_i
 * / (sqrt(2) hr_j)) |p_j| and the same of C on pv and of the local
 * blocks on p, pv and c, plus the rounding of the products (8 eps times
 * the sum of the terms' moduli); without the estimate, 1e-6 of that sum.
 * Returns the largest ratio over the rows (a surface ship's held rows
 * left out; 0 when every residual is 0). The link rows are left out:
 * such a motion keeps every link's length by its construction.
 * O(nlinks). */
double tsi_desc_motion_check(const ts_descriptor *d, double complex lam,
                             const double complex p[],
                             const double complex pv[],
                             const double complex c[]);

/* The eigen analysis's copy of d with the cyclic states comps[0 .. m)
 * (the tow point's translation components, 0 along and 1 across the
 * track; the kernel states root_qoff + comps[i]) cut, into *out: d's
 * arrays shared but for its own K and Lv, in which a translation of the
 * whole system along each component is an exact null vector (every
 * point row's sum over the translated columns, zero within its error
 * where the column of A was found zero, taken off its largest entry
 * there, and the controller rows' entries on the translated components
 * zeroed), as the dense analysis zeroes the cyclic columns of A. Free
 * with tsi_desc_cut_free (never tsi_desc_free). TS_OK or TS_ENOMEM. */
int tsi_desc_cut(const ts_descriptor *d, int root_qoff, const int comps[],
                 int m, ts_descriptor *out);
void tsi_desc_cut_free(ts_descriptor *cut);

/* y[3 np] = sum_j B[k, j] x[j] over the blocks of row points k >= 1
 * (B = K, C, Kerr or Cerr; x[3 np]; y_0 = 0); with acc, y += instead of
 * =. */
void tsi_desc_block_mul(const ts_descriptor *d, const double *B,
                        const double x[], double y[], int acc);

/* The size of frame input c (TS_FRAME_*) whose change moves velocities
 * and accelerations as much as the tow point's do: the speed sqrt(g l)
 * + |V| (l the first link's length), the turn rate that over the reach
 * (ts_system_reach; 1 m for none),
 * the speed rate g, the turn acceleration g over the reach. The dense
 * and the sparse models step the frame inputs by rel_step times it. */
double tsi_frame_input_scale(const ts_system *sys, const ts_frame *fr, int c);

#endif
