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
 * rows likewise (its 3 force equations, then that link's row).
 *
 * A node with extra unknowns (a rigid body's rotations) would add its
 * rows and columns to its own block: the layout is per node.
 */
#ifndef TOWSTAB_DESCRIPTOR_H
#define TOWSTAB_DESCRIPTOR_H

#include <complex.h>

#include "towstab/linearize.h"

/* Link kinds in the constraint rows. */
enum { TSI_LINK_RIGID = 0, TSI_LINK_TAUT = 1, TSI_LINK_SLACK = 2 };

struct ts_descriptor {
    const ts_system *sys;
    int nn, nl;          /* nodes (node 0 the tow point), links */
    int nx;              /* unknowns 4 (nn - 1) */
    /* The state linearized about. */
    double *r0, *v0, *a0; /* [3 nn] node positions, velocities and
                            accelerations relative to M (m, m/s, m/s^2) */
    double *t0;          /* [nl] tensions, N */
    double *M;           /* [6 nn] nodal mass matrices (sym packed), kg */
    double *n;           /* [3 nl] link directions d / |d| */
    double *len;         /* [nl] |d|, m */
    double *ka, *ca;     /* [nl] EA / l (N/m) and Cv (N s/m) of elastic
                            links, 0 for rigid ones */
    char *kind;          /* [nl] TSI_LINK_* */
    /* K and C as 3x3 blocks: row node k >= 1 has blocks bptr[k] ..
     * bptr[k + 1] - 1 with column nodes bcol[] (sorted, node 0 included:
     * the tow point's columns are the inputs). Row-major blocks. */
    int *bptr;           /* [nn + 1] */
    int *bcol;           /* [nblocks] */
    int *btr;            /* [nblocks] index of block (j, k) for (k, j) */
    char *bdist;         /* [nblocks] links between k and j */
    int nblocks;
    double *K, *C;       /* [9 nblocks] dR/dr (N/m), dR/dv (N s/m) */
    double *Kerr, *Cerr; /* [9 nblocks] (D(2h) - D(h)) / 3, or NULL */
    double *rnoise;      /* [3 nn] rounding noise of one residual
                            evaluation of each node row (N; rows of node
                            0 unused): entry (i, j) of K carries noise
                            rnoise[i] / (sqrt(2) hr[j]), of C
                            rnoise[i] / (sqrt(2) hv[j]); NULL without the
                            estimate */
    /* Colouring of the finite differences. */
    int *rcolour, *vcolour; /* [nn] */
    int nrcolour, nvcolour;
    double *hr, *hv;     /* [3 nn] steps of r and v, m and m/s */
    /* Sparse pattern of S(s) (and S_inf) in compressed columns. */
    int nnz;
    int *Sp, *Si;        /* [nx + 1], [nnz] */
    int *pos;            /* the four position arrays below, one block */
    int *pos_blk;        /* [9 nblocks] position of block (k, j) entry
                            (row a, column b) at 9 b' + 3 a + b, -1 when
                            j = 0 or k = 0 */
    int *pos_n;          /* [2 * 3 nl] positions of dR_lower/dt_l (3) and
                            dR_upper/dt_l (3, -1 at the tow point) */
    int *pos_row;        /* [2 * 3 nl] link row l on dr_lower (3) and
                            dr_upper (3, -1 at the tow point) */
    int *pos_diag;       /* [nl] link row l on dt_l */
    void *klu_symbolic;  /* KLU's ordering of the pattern (klu_symbolic *),
                            computed once by tsi_desc_alloc */
    void *klu_common;    /* KLU's default parameters (klu_common *); each
                            factorisation works on its own copy */
    /* Statistics. */
    int groups;          /* perturbation groups (colours x components) */
    long evaluations;    /* residual evaluations */
    double k_scale, c_scale; /* max |K|, max |C| entries */
    double k_err, c_err; /* max |Kerr|, max |Cerr| */
    double k_round, c_round; /* max rnoise_i / (sqrt(2) h_j) over the
                            entries of K and C */
};

/* A descriptor for the built system sys: neighbours, colouring and the
 * pattern of S (O(nlinks)). NULL with err set on failure. */
ts_descriptor *tsi_desc_alloc(const ts_system *sys, ts_err *err);
void tsi_desc_free(ts_descriptor *d);

/* Linearize the node residual of kernel k about the state of its last
 * evaluation (positions, velocities, accelerations, tensions), with
 * steps rel_step * max(|x|, scale) (scales: the length of the link ending
 * at the node, m; sqrt(g l) + |V|, m/s) and, with estimate, the error
 * estimate from steps 2h. threads: 1 serial, more with OpenMP (kernel
 * clones). Returns TS_OK, TS_ESINGULAR (a link of zero length) or
 * TS_ENOMEM. */
int tsi_desc_linearize(ts_descriptor *d, ts_kernel *k, double rel_step,
                       int estimate, int threads, ts_err *err);

/* The linearization's error in the bilinear form w^T dS(s) x over the
 * node rows, dS(s) = dK + s dC (the errors of K and C; M, N and the link
 * rows are exact): w[nx] (complex; its node rows XR(k, a) are used),
 * x[3 nn] node displacements (complex; x_0, the tow point's, is an input
 * column). *trunc = |w^T (Kerr + s Cerr) x|; *round = the root mean
 * square of w^T N x for the noise N of the differences, independent
 * entries rnoise_i / (sqrt(2) hr_j) in K and |s| rnoise_i / (sqrt(2)
 * hv_j) in C (within one link), i.e. sqrt(sum_k sum_a |w_ka|^2
 * rnoise_ka^2 X_k / 2), X_k = sum over k's blocks j of sum_c |x_jc|^2
 * (1 / hr_jc^2 + |s|^2 / hv_jc^2). NaN without the estimate. O(nlinks). */
void tsi_desc_error_terms(const ts_descriptor *d, const double complex w[],
                          const double complex x[], double complex s,
                          double *trunc, double *round);

/* Node displacements dr[3 nn] (dr_0 = 0) of coordinate perturbations
 * dq[nq] (ts_linear_node_displacements), and back: dq[nq] of node
 * displacements dr (which must keep every rigid link's length, n.dd = 0;
 * the normal part is ignored). Real arrays; O(nlinks). */
void tsi_desc_from_nodes(const ts_system *sys, const ts_linear *lin,
                         const double dr[], double dq[]);

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

/* y[3 nn] = sum_j B[k, j] x[j] over the blocks of row nodes k >= 1
 * (B = K, C, Kerr or Cerr; y_0 = 0); with acc, y += instead of =. */
void tsi_desc_block_mul(const ts_descriptor *d, const double *B,
                        const double x[], double y[], int acc);

#endif
