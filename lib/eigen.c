/* eigen.c: modes of the linear model z' = A z (towstab/eigen.h;
 * doc/model.md section 6; doc/linear.md).
 *
 * lapack: dgeevx on a copy of A, its entries below their own error
 * estimate zeroed (balancing, Hessenberg QR; ~25 n^3 flops
 * with both eigenvector sets) gives every eigenvalue with its right
 * eigenvector v, left eigenvector u and condition number kappa (of the
 * balanced matrix). A perturbation dA moves a simple eigenvalue by
 * u^H dA v / (u^H v) to first order (Wilkinson): with dA the
 * linearization's error estimate E this is the eigenvalue's expected
 * error; rounding adds kappa eps ||A_bal||.
 *
 * arpack: implicitly restarted Arnoldi (Lehoucq, Sorensen & Yang, ARPACK
 * Users' Guide, 1998) on OP = (A - sigma I)^-1 with sigma = i 2 pi target,
 * whose largest eigenvalues mu = 1 / (lambda - sigma) belong to the
 * eigenvalues lambda nearest sigma. Real sigma: dnaupd/dneupd, mode 3;
 * complex sigma: znaupd/zneupd, mode 3 in complex arithmetic. OP is applied
 * with the sparse model (lib/shift.h: one KLU factorisation of the shifted
 * node equations, O(nlinks) per application). The Ritz values come from
 * dneupd/zneupd, their vectors from the Arnoldi factorisation ARPACK
 * leaves (ritz_vectors_real: one dgemm). ARPACK's Ritz vectors are
 * checked by their residual ||A v - lambda v||, A applied through the
 * same model.
 *
 * Modes: one eigenvalue of each conjugate pair (Im >= 0) and every real
 * eigenvalue; the `count` nearest sigma are kept and sorted by frequency.
 * Conjugate pairs found by the complex solver are matched one to one, so a
 * double eigenvalue (the in-plane and out-of-plane modes of a hanging
 * chain) stays two modes.
 *
 * One module, though long: LAPACK and ARPACK answer the same request with
 * the same mode table, error bounds, verdict and descriptions, which are
 * most of the file.
 */
#include "towstab/eigen.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdatomic.h>
#include <string.h>
#include <time.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "arpack.h"
#include "bigalloc.h"
#include "lazylib.h"
#include "shift.h"
#include "towstab/system.h"

/* |Im lambda| below this fraction of |lambda| makes an eigenvalue from the
 * complex solver real (its imaginary part is rounding). */
#define REAL_IM_RTOL 1e-9
/* Two eigenvalues within this fraction of |lambda| are a conjugate match. */
#define CONJ_MATCH_RTOL 1e-7
/* The first-order error estimate of an eigenvalue is itself an estimate
 * (of a truncation error whose rounding part is random): error bounds are
 * this many times it. The same for an eigenvector's allowance: its
 * first-order estimate over the nearest eigenvalues fell 3.4 times short
 * of the angle between two independent solutions (test_eigen_arpack). */
#define ERROR_SAFETY 10.0
/* Shape values below this fraction of the largest do not count as a sign
 * change when counting a mode's nodes. */
#define SHAPE_ZERO_RTOL 1e-8
/* Eigenvector health: the nearest eigenvalues whose first-order coupling
 * is computed (vector_health). */
#define VECTOR_NEIGHBOURS 8
/* ARPACK's relative Ritz tolerance of the modes' runs by default
 * (arpack_tol TS_ARPACK_TOL_AUTO). With the sparse model's error
 * estimate each mode's error bound holds its Ritz value's own error
 * (ritz_error, the pencil's Newton correction, first-order exact:
 * test_eigen), so the tolerance need only stop ARPACK where the Ritz
 * values' errors are small against the bounds (1e-8 to 1e-6 of |lambda|,
 * the linearization's): on Kamman's example 1 at 1000 and 10 000 links
 * 1e-6 takes 84 operator applications for the 20 lowest modes instead
 * of 105 at 1e-10 (126 at machine precision), the eigenvalues within
 * 4e-5 of their bounds and the bounds within 2e-4 of themselves. On the
 * dense A (or without the error estimate) the Ritz value's error is its
 * residual, which follows the tolerance: 1e-10 there. */
#define ARPACK_TOL_PENCIL 1e-6
#define ARPACK_TOL 1e-10

void ts_eigen_opts_default(ts_eigen_opts *o)
{
    o->method = TS_EIG_AUTO;
    o->count = 0;
    o->target_hz = 0.0;
    o->arpack_min_states = 1200;
    o->arpack_tol = TS_ARPACK_TOL_AUTO;
    o->arpack_max_iter = 1000;
    o->vectors = 1;
    o->rightmost = 1;
    o->progress = NULL;
    o->progress_data = NULL;
}

const char *ts_eig_method_name(ts_eig_method m)
{
    switch (m) {
    case TS_EIG_LAPACK: return "lapack";
    case TS_EIG_ARPACK: return "arpack";
    default: return "auto";
    }
}

const char *ts_verdict_name(int verdict)
{
    switch (verdict) {
    case TS_STABLE: return "stable";
    case TS_UNSTABLE: return "unstable";
    default: return "marginal";
    }
}

int ts_eigen_other_undecided(const ts_eigen *e)
{
    return e->verdict == TS_MARGINAL && isfinite(e->undecided_real) &&
           e->max_real + e->max_real_error < 0;
}

void ts_eigen_free(ts_eigen *e)
{
    if (!e)
        return;
    free(e->modes);
    free(e->vec_re);
    free(e->vec_im);
    free(e);
}

/* ---- Candidate modes ----------------------------------------------------- */

typedef struct cand {
    double complex lam;   /* Im >= 0 */
    double cond, resid;
    double round;         /* rounding error allowance, kappa eps ||A||
                             (lapack), the Ritz value's own error (arpack:
                             ritz) */
    double ritz;          /* the Ritz value's own error estimate (arpack):
                             the pencil's Newton correction with the sparse
                             model (tsi_shift_eig_error), the residual
                             ||A v - lam v|| / |v| on the dense A; NaN with
                             lapack */
    double dlam;          /* first-order change of lam by the linearization
                             error estimate, |u^H E v| / |u^H v| (or
                             |E v| / |v| without u); NaN if unknown */
    int vec;              /* column in the vector store */
    double dist;          /* |lam - sigma| */
    double vcond;         /* eigenvector conditioning, max kappa_k
                             ||A_bal|| / gap (lapack; vector_health) */
    double verr;          /* eigenvector error allowance, rad */
    int sweep;            /* found by the rightmost search, not among the
                             modes nearest the target */
    double slack;         /* the search: how far a Ritz value of a loose
                             run may lie from its eigenvalue (0 for the
                             other runs), widening the repeats' match */
    int checked;          /* residual and error estimate computed */
    int neutral;          /* the lin->neutral it was recognised as, or -1 */
} cand;

typedef struct cand_list {
    int n, cap, nstate;
    cand *c;
    double complex *v;    /* [nstate * cap] */
    double complex *v2;   /* a second store, taken over from another list
                             (merge_search): vec < 0 is its column
                             -1 - vec */
} cand_list;

/* The vector of column vec. */
static inline double complex *cand_v(const cand_list *L, int vec)
{
    return vec >= 0 ? L->v + (size_t)vec * L->nstate
                    : L->v2 + (size_t)(-1 - vec) * L->nstate;
}

static int cand_init(cand_list *L, int cap, int nstate)
{
    L->n = 0;
    L->cap = cap > 0 ? cap : 1;
    L->nstate = nstate;
    L->c = malloc((size_t)L->cap * sizeof(cand));
    L->v = tsi_big_malloc((size_t)L->cap * (size_t)nstate *
                          sizeof(double complex));
    return L->c && L->v ? TS_OK : TS_ENOMEM;
}

/* Room for `extra` more candidates. */
static int cand_grow(cand_list *L, int extra)
{
    if (L->n + extra <= L->cap)
        return TS_OK;
    int cap = 2 * L->cap > L->n + extra ? 2 * L->cap : L->n + extra;
    cand *c = realloc(L->c, (size_t)cap * sizeof(cand));
    if (!c)
        return TS_ENOMEM;
    L->c = c;
    /* The columns in use move; the rest, never written, stay unfaulted. */
    size_t col = (size_t)L->nstate * sizeof(double complex);
    double complex *v =
        tsi_big_realloc(L->v, (size_t)L->n * col, (size_t)cap * col);
    if (!v)
        return TS_ENOMEM;
    L->v = v;
    L->cap = cap;
    return TS_OK;
}

static void cand_free(cand_list *L)
{
    free(L->c);
    free(L->v);
    free(L->v2);
}

/* Add an eigenvalue with its vector given as re/im parts (im may be NULL);
 * lam in the lower half plane is conjugated with its vector. */
/* The root mean square of u^H N v for the rounding noise N of the
 * linearization's differences (independent entries of size fnoise_i /
 * (sqrt(2) h_j) in the lower rows, ts_linear.fnoise): sqrt(sum_i |u_(nq+i)|^2
 * fnoise_i^2) sqrt(sum_j |v_j|^2 / h_j^2) / sqrt(2). u = ur + i ui, v =
 * vr + i vi (ui, vi NULL for real vectors); without u (ARPACK) the
 * rounding's share of |N v|, with every |u_i| 1. 0 without fnoise. */
static double rounding_change(const ts_linear *lin, const double *ur,
                              const double *ui, const double *vr,
                              const double *vi)
{
    if (!lin->fnoise)
        return 0.0;
    int n = lin->nstate, nq = lin->nq;
    double su = 0, sv = 0;
    for (int i = 0; i < n - nq; i++) {
        double a = ur ? ur[nq + i] * ur[nq + i] +
                            (ui ? ui[nq + i] * ui[nq + i] : 0.0)
                      : 1.0;
        su += a * lin->fnoise[i] * lin->fnoise[i];
    }
    for (int j = 0; j < n; j++) {
        double b = vr[j] * vr[j] + (vi ? vi[j] * vi[j] : 0.0);
        sv += b / (lin->h[j] * lin->h[j]);
    }
    return sqrt(0.5 * su * sv);
}

/* The fields of a new candidate L->c[L->n] (its vector to be stored at
 * column L->n); lam in the lower half plane is conjugated. */
static cand *cand_new(cand_list *L, double complex lam, double cond,
                      double resid, double dlam)
{
    int sign = cimag(lam) < 0 ? -1 : 1;
    cand *c = &L->c[L->n];
    c->lam = sign > 0 ? lam : conj(lam);
    c->cond = cond;
    c->resid = resid;
    c->dlam = dlam;
    c->round = DBL_EPSILON * cond; /* times ||A||: set by the caller */
    c->ritz = NAN;
    c->vcond = NAN;
    c->verr = NAN;
    c->sweep = 0;
    c->slack = 0.0;
    c->checked = 0;
    c->neutral = -1;
    c->vec = L->n;
    return c;
}

/* x[m] = vr + i sign vi (vi NULL: vr alone), rows of a candidate's
 * vector from its real and imaginary parts, sign -1 where the value was
 * conjugated into the upper half plane (cand_new). */
static void pair_into(double complex *x, const double *vr, const double *vi,
                      double sign, size_t m)
{
    for (size_t i = 0; i < m; i++)
        x[i] = vr[i] + I * (vi ? sign * vi[i] : 0.0);
}

static void cand_add(cand_list *L, double complex lam, const double *vr,
                     const double *vi, double cond, double resid,
                     double dlam)
{
    if (L->n >= L->cap)
        return;
    double sign = cimag(lam) < 0 ? -1 : 1;
    cand_new(L, lam, cond, resid, dlam);
    pair_into(L->v + (size_t)L->n * L->nstate, vr, vi, sign,
              (size_t)L->nstate);
    L->n++;
}

/* A candidate for lam whose complex vector is already in L's store, at
 * its next column L->n: conjugated there with lam when lam is in the
 * lower half plane (cand_new conjugates lam). */
static void cand_take(cand_list *L, double complex lam)
{
    double complex *v = L->v + (size_t)L->n * L->nstate;
    if (cimag(lam) < 0)
        for (int i = 0; i < L->nstate; i++)
            v[i] = conj(v[i]);
    cand_new(L, lam, NAN, NAN, NAN);
    L->n++;
}

/* cand_add with a complex vector z (zneupd's): copied, then taken. */
static void cand_add_complex(cand_list *L, double complex lam,
                             const double complex *z)
{
    if (L->n >= L->cap)
        return;
    memcpy(L->v + (size_t)L->n * L->nstate, z,
           (size_t)L->nstate * sizeof *z);
    cand_take(L, lam);
}

/* Ties broken by the order of storage: L->v's columns, then those of
 * the store taken over (merge_search). */
static int cmp_vec(const cand *x, const cand *y)
{
    if ((x->vec < 0) != (y->vec < 0))
        return x->vec < 0 ? 1 : -1;
    return x->vec < 0 ? y->vec - x->vec : x->vec - y->vec;
}

static int cmp_dist(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    if (x->dist != y->dist)
        return x->dist < y->dist ? -1 : 1;
    return cmp_vec(x, y);
}

static int cmp_freq(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    double fx = cimag(x->lam), fy = cimag(y->lam);
    if (fx != fy)
        return fx < fy ? -1 : 1;
    double ax = cabs(x->lam), ay = cabs(y->lam);
    if (ax != ay)
        return ax < ay ? -1 : 1;
    return cmp_vec(x, y);
}

/* ---- LAPACK -------------------------------------------------------------- */

/* Eigenvalue k of dgeevx's output as a complex number, with its right and
 * left eigenvector entries i (a conjugate pair is stored as columns k, k+1
 * = re, im for wi[k] > 0; the second of the pair is the conjugate). */
static double complex eig_at(const double *wr, const double *wi, int k)
{
    return wr[k] + I * wi[k];
}

static double complex vec_at(const double *x, const double *wi, int n, int k,
                             int i)
{
    if (wi[k] == 0.0)
        return x[(size_t)k * n + i];
    if (wi[k] > 0.0)
        return x[(size_t)k * n + i] + I * x[(size_t)(k + 1) * n + i];
    return x[(size_t)(k - 1) * n + i] - I * x[(size_t)k * n + i];
}

/* Eigenvector health of eigenvalue j (wi[j] >= 0) from first-order
 * perturbation theory (Wilkinson; Stewart & Sun, Matrix Perturbation
 * Theory, V.2): under A + F the right eigenvector moves by
 *   dv_j = sum_{k != j} c_k v_k,  c_k = (u_k^H F v_j) / ((lambda_j -
 *   lambda_k) u_k^H v_k),
 * and the terms that matter are those of the nearest eigenvalues. The
 * allowance is sqrt(sum |c_k|^2) over the VECTOR_NEIGHBOURS eigenvalues
 * nearest lambda_j (conjugates included), with F the linearization's error
 * estimate E (exactly, through EV = E VR) plus rounding eps ||A_bal||
 * kappa_k / gap (kappa_k = 1 / RCONDE, of the balanced matrix); the far
 * terms are each small and incoherent and are left out (summing bounds on
 * them instead grew with n to 0.02 at 400 states for modes no perturbation
 * mixes). Also the conditioning max_k kappa_k ||A_bal|| / gap_jk, the
 * sensitivity of the shape to relative changes of A from its nearest
 * neighbour (~ 1 / RCONDV of dgeevx, whose SENSE = 'B' costs O(n^4): ten
 * times the whole eigen solve at 800 states). O(n) per eigenvalue plus
 * O(nq) per neighbour. */
static void vector_health(const ts_linear *lin, const double *vl,
                          const double *wr, const double *wi,
                          const double *rconde, const double *kap0,
                          const double *ev, const double *ez,
                          double abnrm, int j, cand *c)
{
    int n = lin->nstate, nq = lin->nq, nlow = n - nq;
    double complex lj = eig_at(wr, wi, j);
    int near[VECTOR_NEIGHBOURS], nn = 0;
    double gaps[VECTOR_NEIGHBOURS], vcond = 0.0;
    for (int k = 0; k < n; k++) {
        if (k == j)
            continue;
        double gap = cabs(lj - eig_at(wr, wi, k));
        vcond = fmax(vcond, abnrm / (rconde[k] * gap));
        /* Insert into the sorted list of the nearest. */
        int at = nn < VECTOR_NEIGHBOURS ? nn++ : VECTOR_NEIGHBOURS;
        for (; at > 0 && gaps[at - 1] > gap; at--)
            if (at < VECTOR_NEIGHBOURS) {
                gaps[at] = gaps[at - 1];
                near[at] = near[at - 1];
            }
        if (at < VECTOR_NEIGHBOURS) {
            gaps[at] = gap;
            near[at] = k;
        }
    }
    double sum2 = 0.0;
    const double *er = ev ? ev + (size_t)j * nlow : NULL;
    const double *ei = ev && wi[j] != 0.0 ? ev + (size_t)(j + 1) * nlow : NULL;
    const double *zr = ez ? ez + (size_t)j * nlow : NULL;
    const double *zi = ez && wi[j] != 0.0 ? ez + (size_t)(j + 1) * nlow : NULL;
    for (int m = 0; m < nn; m++) {
        int k = near[m];
        double gap = gaps[m];
        if (!(gap > 0)) {
            sum2 = INFINITY;
            break;
        }
        /* u_k = ur + i sg ui (the second of a pair is the conjugate). */
        const double *ur = vl + (size_t)(wi[k] < 0 ? k - 1 : k) * n + nq;
        const double *ui = wi[k] == 0.0 ? NULL
                                        : vl + (size_t)(wi[k] < 0 ? k : k + 1) *
                                                   n + nq;
        double sg = wi[k] < 0 ? -1.0 : 1.0, sr = 0.0, si = 0.0;
        double zsr = 0.0, zsi = 0.0;
        for (int i = 0; er && i < nlow; i++) {
            /* conj(a + i b) (x + i y) = (a x + b y) + i (a y - b x) */
            double a = ur[i], b = ui ? sg * ui[i] : 0.0;
            double x = er[i], y = ei ? ei[i] : 0.0;
            sr += a * x + b * y;
            si += a * y - b * x;
        }
        for (int i = 0; zr && i < nlow; i++) {
            double a = ur[i], b = ui ? sg * ui[i] : 0.0;
            double x = zr[i], y = zi ? zi[i] : 0.0;
            zsr += a * x + b * y;
            zsi += a * y - b * x;
        }
        /* F = E + Z: the error estimate and the entries zeroed below it
         * (clean_below_error), each term's size added. */
        double ck = er ? (hypot(sr, si) + hypot(zsr, zsi)) * kap0[k] / gap
                       : (lin->Aerr ? lin->trunc_norm : 0.0) * kap0[k] / gap;
        ck += DBL_EPSILON * abnrm / (rconde[k] * gap);
        sum2 += ck * ck;
    }
    c->vcond = vcond;
    /* An estimate as the eigenvalue's is: ERROR_SAFETY times it. */
    c->verr = ERROR_SAFETY * sqrt(sum2);
}

/* The error estimate of entry (i, j) of A: |Aerr_ij| + fnoise_i /
 * (sqrt(2) h_j) in the lower block (ts_linear), 0 in the exact upper
 * block [0 I] and without the estimate. */
static double entry_error(const ts_linear *lin, int i, int j)
{
    int nq = lin->nq, nlow = lin->nstate - nq;
    if (i < nq || !lin->Aerr)
        return 0.0;
    double bound = fabs(lin->Aerr[(i - nq) + (size_t)j * nlow]);
    if (lin->fnoise && lin->h)
        bound += lin->fnoise[i - nq] / (M_SQRT2 * lin->h[j]);
    return bound;
}

/* Zero the entries of the lower block of a (a copy of lin->A) smaller
 * than their own error estimate (entry_error): zero within the
 * linearization's accuracy. Left in, such
 * entries (1e-33 where central differences round an exact zero) make
 * dgeevx's scaling balance a row against nothing, by factors up to 1e30,
 * and the eigenvectors lose their accuracy (doc/linear.md section 3).
 * The entries zeroed go to z (the lower block, nlow x n, column-major;
 * the rest 0): a perturbation Z of A, A = a + Z, whose first-order
 * change of every eigenvalue and eigenvector the allowances add to the
 * error estimate's. Returns the number zeroed; nothing without the
 * error estimate. */
static long clean_below_error(const ts_linear *lin, double *a, double *z)
{
    int n = lin->nstate, nq = lin->nq, nlow = n - nq;
    long count = 0;
    if (!lin->Aerr)
        return 0;
    for (int j = 0; j < n; j++)
        for (int i = nq; i < n; i++) {
            double *aij = &a[i + (size_t)j * n];
            double *zij = &z[(i - nq) + (size_t)j * nlow];
            *zij = 0.0;
            if (*aij != 0.0 && fabs(*aij) < entry_error(lin, i, j)) {
                *zij = *aij;
                *aij = 0.0;
                count++;
            }
        }
    return count;
}

static int solve_lapack(const ts_linear *lin, cand_list *L, ts_err *err)
{
    tsi_lapack la;
    if (tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    int n = lin->nstate, info = 0, lwork = -1;
    size_t nn = (size_t)n * (size_t)n;
    double *a = malloc(nn * sizeof(double));
    double *vl = malloc(nn * sizeof(double));
    double *vr = malloc(nn * sizeof(double));
    double *wr = malloc((size_t)n * sizeof(double));
    double *wi = malloc((size_t)n * sizeof(double));
    double *work = NULL, *ev = NULL, *z = NULL, *ez = NULL, wq;
    long nzeroed = 0;
    double *scale = NULL, *rconde = NULL, *rcondv = NULL, *kap0 = NULL;
    int rc = TS_OK;
    if (!a || !vl || !vr || !wr || !wi) {
        rc = ts_fail_nomem(err, 3 * 8.0 * (double)nn, "fewer links, or "
                           "method arpack with a count (the modes near a "
                           "target)", "eigen: out of memory for dense %d x "
                           "%d eigenvectors", n, n);
        goto out;
    }
    memcpy(a, lin->A, nn * sizeof(double));
    if (lin->Aerr) {
        z = malloc((size_t)(n - lin->nq) * (size_t)n * sizeof(double));
        if (!z) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
            goto out;
        }
        nzeroed = clean_below_error(lin, a, z);
    }
    /* dgeevx: balance (permute and scale), then QR; the reciprocal
     * condition numbers and the norm refer to the balanced matrix, the
     * one whose rounding errors matter. Scaling is needed: without it
     * (BALANC 'P' or 'N') the stiff elastic examples' eigenvalues move by
     * some 40 times their error bounds (doc/linear.md section 3). */
    int ilo, ihi;
    double abnrm;
    scale = malloc((size_t)n * sizeof(double));
    rconde = malloc((size_t)n * sizeof(double));
    rcondv = malloc((size_t)n * sizeof(double));
    if (!scale || !rconde || !rcondv) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    la.dgeevx_("B", "V", "V", "E", &n, a, &n, wr, wi, vl, &n, vr, &n, &ilo,
               &ihi, scale, &abnrm, rconde, rcondv, &wq, &lwork, NULL, &info, 1,
               1, 1, 1);
    lwork = info == 0 ? (int)wq : n * (n + 6);
    work = malloc((size_t)lwork * sizeof(double));
    if (!work) {
        rc = ts_fail_nomem(err, 8.0 * lwork, "fewer links, or method arpack "
                           "with a count", "eigen: out of memory for LAPACK "
                           "dgeevx's work of the %d x %d matrix", n, n);
        goto out;
    }
    la.dgeevx_("B", "V", "V", "E", &n, a, &n, wr, wi, vl, &n, vr, &n, &ilo,
               &ihi, scale, &abnrm, rconde, rcondv, work, &lwork, NULL, &info,
               1, 1, 1, 1);
    if (info != 0) {
        rc = ts_fail(err, TS_ELAPACK,
                     "eigen: LAPACK dgeevx info %d (%s) for the %d x %d "
                     "matrix A",
                     info, info > 0 ? "QR iteration failed" : "bad argument",
                     n, n);
        goto out;
    }
    if (cand_init(L, n, n) != TS_OK) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    /* EV = E VR: the estimated error of A (lower block) on every right
     * eigenvector, one BLAS product, 2 (n - nq) n^2 flops. */
    int nq = lin->nq, nlow = n - nq;
    if (lin->Aerr) {
        ev = malloc((size_t)nlow * (size_t)n * sizeof(double));
        if (ev) {
            double pone = 1.0, zero = 0.0;
            la.dgemm_("N", "N", &nlow, &n, &n, &pone, lin->Aerr, &nlow, vr, &n,
                      &zero, ev, &nlow, 1, 1);
        }
    }
    /* EZ = Z VR: the entries zeroed, on every right eigenvector. */
    if (ev && nzeroed > 0) {
        ez = malloc((size_t)nlow * (size_t)n * sizeof(double));
        if (!ez) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
            goto out;
        }
        double pone = 1.0, zero = 0.0;
        la.dgemm_("N", "N", &nlow, &n, &n, &pone, z, &nlow, vr, &n, &zero, ez,
                  &nlow, 1, 1);
    }
    /* 1 / |u_k^H v_k| of every eigenvalue (unit vectors): O(n^2). */
    kap0 = malloc((size_t)n * sizeof(double));
    if (!kap0) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    for (int k = 0; k < n; k++) {
        double complex uv = 0;
        for (int i = 0; i < n; i++)
            uv += conj(vec_at(vl, wi, n, k, i)) * vec_at(vr, wi, n, k, i);
        kap0[k] = 1.0 / cabs(uv);
    }
    for (int j = 0; j < n; j++) {
        const double *vrj = vr + (size_t)j * n, *vlj = vl + (size_t)j * n;
        const double *evj = ev ? ev + (size_t)j * nlow : NULL;
        const double *ezj = ez ? ez + (size_t)j * nlow : NULL;
        if (wi[j] == 0.0) {
            double uv = 0, uu = 0, vv = 0, uev = 0, uez = 0;
            for (int i = 0; i < n; i++) {
                uv += vlj[i] * vrj[i];
                uu += vlj[i] * vlj[i];
                vv += vrj[i] * vrj[i];
            }
            for (int i = 0; evj && i < nlow; i++)
                uev += vlj[nq + i] * evj[i];
            for (int i = 0; ezj && i < nlow; i++)
                uez += vlj[nq + i] * ezj[i];
            (void)uu;
            (void)vv;
            cand_add(L, wr[j], vrj, NULL, 1.0 / rconde[j], NAN,
                     evj ? fabs(uev / uv) + fabs(uez / uv) +
                               rounding_change(lin, vlj, NULL, vrj, NULL) /
                                   fabs(uv)
                         : NAN);
            L->c[L->n - 1].round = DBL_EPSILON * abnrm / rconde[j];
            vector_health(lin, vl, wr, wi, rconde, kap0, ev, ez, abnrm, j,
                          &L->c[L->n - 1]);
        } else if (wi[j] > 0.0 && j + 1 < n) {
            const double *vrk = vrj + n, *vlk = vlj + n;
            double complex uv = 0, uev = 0, uez = 0;
            double uu = 0, vv = 0;
            for (int i = 0; i < n; i++) {
                double complex u = vlj[i] + I * vlk[i];
                double complex v = vrj[i] + I * vrk[i];
                uv += conj(u) * v;
                uu += vlj[i] * vlj[i] + vlk[i] * vlk[i];
                vv += vrj[i] * vrj[i] + vrk[i] * vrk[i];
            }
            for (int i = 0; evj && i < nlow; i++)
                uev += conj(vlj[nq + i] + I * vlk[nq + i]) *
                       (evj[i] + I * evj[nlow + i]);
            for (int i = 0; ezj && i < nlow; i++)
                uez += conj(vlj[nq + i] + I * vlk[nq + i]) *
                       (ezj[i] + I * ezj[nlow + i]);
            (void)uu;
            (void)vv;
            cand_add(L, wr[j] + I * wi[j], vrj, vrk, 1.0 / rconde[j], NAN,
                     evj ? cabs(uev / uv) + cabs(uez / uv) +
                               rounding_change(lin, vlj, vlk, vrj, vrk) /
                                   cabs(uv)
                         : NAN);
            L->c[L->n - 1].round = DBL_EPSILON * abnrm / rconde[j];
            vector_health(lin, vl, wr, wi, rconde, kap0, ev, ez, abnrm, j,
                          &L->c[L->n - 1]);
            j++;
        }
    }
out:
    free(scale);
    free(rconde);
    free(rcondv);
    free(kap0);
    free(ev);
    free(ez);
    free(z);
    free(a);
    free(vl);
    free(vr);
    free(wr);
    free(wi);
    free(work);
    return rc;
}

/* ---- ARPACK -------------------------------------------------------------- */

/* Checks of every ARPACK candidate through the sparse model (lib/shift.h:
 * A and the linearization's error estimate dA applied with one
 * factorisation of S_inf, O(nlinks) per vector): the residual
 * r = ||A v - lam v|| / |v|, reported relative to |lam|, and the
 * eigenvalue's first-order change by the error estimate, ||dA v|| / |v|
 * (kappa = 1 without a left vector, exact for a normal matrix). The
 * residual itself is the rounding allowance (Bauer-Fike with kappa = 1):
 * an exact eigenpair of a matrix within ||r|| of A. */
/* The same checks with the dense A and its error estimate (without the
 * sparse model: TS_LIN_DENSE), with one
 * pass over A and one over E (BLAS dgemm on the real and imaginary parts
 * of all the unchecked vectors at once). */
/* A candidate's residual ||A v - lam v|| / |v| (round) and relative to
 * |lam| (resid) from A v = ar + i ai; returns |v|^2. */
static double set_residual(cand *c, const double complex *v,
                           const double *ar, const double *ai, int n)
{
    double r2 = 0, v2 = 0;
    for (int i = 0; i < n; i++) {
        double complex d = ar[i] + I * ai[i] - c->lam * v[i];
        r2 += creal(d) * creal(d) + cimag(d) * cimag(d);
        v2 += creal(v[i]) * creal(v[i]) + cimag(v[i]) * cimag(v[i]);
    }
    double res = sqrt(r2 / v2);
    c->round = res;
    c->resid = cabs(c->lam) > 0 ? res / cabs(c->lam) : res;
    return v2;
}

static int dense_checks(const ts_linear *lin, cand_list *L, ts_err *err)
{
    tsi_lapack la;
    if (tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    int n = lin->nstate, nlow = n - lin->nq, m = 0;
    for (int c = 0; c < L->n; c++)
        m += L->c[c].checked ? 0 : 2;
    if (m == 0)
        return TS_OK;
    double *W = calloc((size_t)n * (size_t)m, sizeof(double));
    double *AW = malloc((size_t)n * (size_t)m * sizeof(double));
    double *EW = lin->Aerr ? malloc((size_t)nlow * (size_t)m * sizeof(double))
                           : NULL;
    if (!W || !AW || (lin->Aerr && !EW)) {
        free(W);
        free(AW);
        free(EW);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    for (int c = 0, j = 0; c < L->n; c++) {
        if (L->c[c].checked)
            continue;
        const double complex *v = cand_v(L, L->c[c].vec);
        for (int i = 0; i < n; i++) {
            W[(size_t)j * n + i] = creal(v[i]);
            W[(size_t)(j + 1) * n + i] = cimag(v[i]);
        }
        j += 2;
    }
    double pone = 1.0, zero = 0.0;
    la.dgemm_("N", "N", &n, &m, &n, &pone, lin->A, &n, W, &n, &zero, AW, &n, 1,
              1);
    if (EW)
        la.dgemm_("N", "N", &nlow, &m, &n, &pone, lin->Aerr, &nlow, W, &n,
                  &zero, EW, &nlow, 1, 1);
    for (int c = 0, j = 0; c < L->n; c++) {
        if (L->c[c].checked)
            continue;
        L->c[c].checked = 1;
        const double complex *v = cand_v(L, L->c[c].vec);
        const double *ar = AW + (size_t)j * n, *ai = ar + n;
        double v2 = set_residual(&L->c[c], v, ar, ai, n), e2 = 0;
        L->c[c].ritz = L->c[c].round;
        if (EW) {
            const double *er = EW + (size_t)j * nlow, *ei = er + nlow;
            for (int i = 0; i < nlow; i++)
                e2 += er[i] * er[i] + ei[i] * ei[i];
            L->c[c].dlam = sqrt(e2 / v2) +
                           rounding_change(lin, NULL, NULL,
                                           W + (size_t)j * n,
                                           W + (size_t)(j + 1) * n) /
                               sqrt(v2);
        }
        j += 2;
    }
    free(W);
    free(AW);
    free(EW);
    return TS_OK;
}

/* A Ritz pair of the search whose Ritz value's own error (ritz) exceeds
 * this fraction of |lambda| has not converged and is dropped. On the
 * dense A (no sparse model) ritz is the residual ||A v - lambda v|| / |v|,
 * which a pair converged to ARPACK's tolerance tau on (A - sigma I)^-1
 * keeps below tau ||A - sigma I||, not tau |lambda|: there the fraction is
 * of |lambda| + max |A_ij| (a lower bound of ||A||). */
#define SWEEP_RESIDUAL 1e-6

/* The residuals and error estimates of L's unchecked candidates: A
 * applied with acc (S_inf), S(lambda) factored in es (the caller's,
 * zeroed before the first call, tsi_shift_free after the last: each
 * estimate refactors the previous one's factors, lib/shift.h). */
static int batch_checks(const ts_linear *lin, tsi_shift *acc, tsi_shift *es,
                        cand_list *L, ts_err *err)
{
    int n = lin->nstate;
    double *w = malloc(4 * (size_t)n * sizeof(double));
    if (!w)
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    double *vr = w, *vi = w + n, *ar = w + 2 * n, *ai = w + 3 * n;
    int with_err = lin->desc_err == lin->desc_err; /* not NaN */
    /* The real eigenvalues first, then the complex ones: each estimate
     * refactors S(lambda) with the previous one's pivots, which a change
     * between real and complex arithmetic cannot reuse. */
    for (int pass = 0; pass < 2 * L->n; pass++) {
        int c = pass % L->n;
        if (L->c[c].checked ||
            (cimag(L->c[c].lam) != 0.0) != (pass >= L->n))
            continue;
        L->c[c].checked = 1;
        const double complex *v = cand_v(L, L->c[c].vec);
        int real = 1;
        for (int i = 0; i < n; i++) {
            vr[i] = creal(v[i]);
            vi[i] = cimag(v[i]);
            real &= vi[i] == 0.0;
        }
        tsi_shift_apply(acc, vr, ar, 0);
        /* A real vector's imaginary part maps to zero. */
        if (real)
            memset(ai, 0, (size_t)n * sizeof(double));
        else
            tsi_shift_apply(acc, vi, ai, 0);
        set_residual(&L->c[c], v, ar, ai, n);
        L->c[c].ritz = L->c[c].round;
        if (with_err) {
            double ritz;
            int rc = tsi_shift_eig_error(es, lin, L->c[c].lam, v,
                                         &L->c[c].dlam, &ritz, err);
            if (rc != TS_OK) {
                free(w);
                return rc;
            }
            /* The Ritz value's error from the pencil replaces the
             * residual, whose floor, the rounding of A's application
             * through S_inf, is not the Ritz pair's (doc/linear.md,
             * section 3). */
            if (isfinite(ritz))
                L->c[c].ritz = L->c[c].round = ritz;
        }
    }
    free(w);
    return TS_OK;
}

ts_eig_method ts_eigen_method(int n, const ts_eigen_opts *o)
{
    if (o->method != TS_EIG_AUTO)
        return o->method;
    return o->count > 0 && n >= o->arpack_min_states ? TS_EIG_ARPACK
                                                      : TS_EIG_LAPACK;
}

static int arpack_sizes(int n, int count, int *nev, int *ncv, ts_err *err);

int ts_eigen_check(int n, const ts_eigen_opts *opts, ts_err *err)
{
    ts_eigen_opts o;
    if (opts)
        o = *opts;
    else
        ts_eigen_opts_default(&o);
    if (o.count < 0 || o.count > n)
        return ts_fail(err, TS_EINVAL,
                       "eigen: count must be in [0, %d] (0: all modes; the "
                       "system has %d states), got %d",
                       n, n, o.count);
    if (!(o.target_hz >= 0) || !isfinite(o.target_hz))
        return ts_fail(err, TS_EINVAL,
                       "eigen: target must be a frequency >= 0 Hz, got %g",
                       o.target_hz);
    if (!(o.arpack_tol >= 0 || o.arpack_tol == TS_ARPACK_TOL_AUTO) ||
        o.arpack_max_iter < 1)
        return ts_fail(err, TS_EINVAL,
                       "eigen: arpack_tol must be >= 0 (or "
                       "TS_ARPACK_TOL_AUTO) and arpack_max_iter >= 1");
    if (ts_eigen_method(n, &o) != TS_EIG_ARPACK)
        return TS_OK;
    if (o.count == 0)
        return ts_fail(err, TS_EINVAL,
                       "eigen: method arpack needs a number of modes (count "
                       "> 0); it finds the modes nearest a target, not all");
    int nev, ncv;
    return arpack_sizes(n, o.count, &nev, &ncv, err);
}

static int arpack_sizes(int n, int count, int *nev, int *ncv, ts_err *err)
{
    *nev = 2 * count + 1;
    if (*nev > n - 2)
        return ts_fail(err, TS_EINVAL,
                       "eigen: arpack: %d modes need %d Ritz values, more "
                       "than the %d states allow (at most %d modes); use "
                       "method lapack",
                       count, 2 * count + 1, n, (n - 3) / 2);
    *ncv = 2 * *nev + 1;
    if (*ncv < *nev + 20)
        *ncv = *nev + 20;
    if (*ncv > n)
        *ncv = n;
    return TS_OK;
}

static const char *arpack_info_text(int info)
{
    switch (info) {
    case -1: return "n must be positive";
    case -2: return "nev must be positive";
    case -3: return "ncv out of range";
    case -4: return "maxiter must be positive";
    case -5: return "unknown 'which'";
    case -6: return "bmat must be I or G";
    case -7: return "workl too short";
    case -8: return "error in the Hessenberg eigensolver";
    case -9: return "starting vector is zero";
    case -9999: return "could not build an Arnoldi factorization";
    case 3: return "no shifts could be applied (increase ncv)";
    default: return "see the ARPACK documentation";
    }
}

/* Where an ARPACK run reports its progress (ts_eigen_opts.progress):
 * `what`, and `shift` of `shifts` for a run of the rightmost search (its
 * shifts are the measure), or shifts NAN: the operator applications. */
typedef struct eig_poll {
    const ts_eigen_opts *o;
    const char *what;
    double shift, shifts;
} eig_poll;

/* TS_OK to go on, TS_ECANCEL (message set) when the callback asks to
 * stop, after `ops` operator applications of the run. */
static int eig_poll_check(const eig_poll *pp, int ops, ts_err *err)
{
    if (!pp->o->progress)
        return TS_OK;
    int search = !isnan(pp->shifts);
    ts_progress p = {pp->what, search ? pp->shift : ops,
                     search ? pp->shifts : NAN,
                     search ? "shifts" : "operator applications"};
    if (!pp->o->progress(&p, pp->o->progress_data))
        return TS_OK;
    if (search)
        return ts_fail(err, TS_ECANCEL, "eigen: stopped on request in the "
                                        "rightmost search, at shift %.0f "
                                        "of %.0f",
                       pp->shift + 1, pp->shifts);
    return ts_fail(err, TS_ECANCEL, "eigen: stopped on request in ARPACK's "
                                    "run after %d operator applications "
                                    "(no eigenvalue is final before the "
                                    "run ends)",
                   ops);
}

/* Each Ritz value's own error is the pencil's Newton correction
 * (tsi_shift_eig_error: the sparse model with its error estimate), not
 * the residual. */
static int pencil_ritz(const ts_linear *lin)
{
    const ts_descriptor *d = lin->desc;
    return d && lin->desc_err == lin->desc_err && d->Kerr && d->rnoise;
}

/* The modes' runs' tolerance: arpack_tol, or by default (auto)
 * ARPACK_TOL_PENCIL where each Ritz value's error is measured
 * (pencil_ritz), ARPACK_TOL elsewhere. */
static double modes_tol(const ts_linear *lin, const ts_eigen_opts *o)
{
    if (o->arpack_tol != TS_ARPACK_TOL_AUTO)
        return o->arpack_tol;
    return pencil_ritz(lin) ? ARPACK_TOL_PENCIL : ARPACK_TOL;
}

/* ARPACK's start vector when none is given (info = 1: ARPACK starts from
 * resid): x[n] uniform in [-1, 1) from a fixed linear congruential
 * sequence. ARPACK's own random start (dgetv0) draws from a seed it keeps
 * between runs, so a run's rounding would depend on the runs made before
 * it in the process (the order of a sweep's points on its threads); this
 * one depends on n alone. */
static void start_vector(double *x, int n)
{
    unsigned long long r = 0x2545F4914F6CDD1DULL;
    for (int i = 0; i < n; i++) {
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        x[i] = (double)(r >> 11) * 0x1.0p-52 - 1.0;
    }
}

/* ARPACK keeps the state of a run between its calls in SAVE variables
 * (dnaupd, znaupd and the routines under them): one run of a family at a
 * time in a process. A run is therefore a critical section of its own,
 * whatever calls it (a sweep's threads, each with its modes and
 * rightmost search): ts_arpack_real for the real family (dnaupd, dneupd
 * and their routines: the modes nearest 0 Hz), ts_arpack_complex for the
 * complex one (znaupd, zneupd: the search's and a complex target's runs).
 * The two families share no SAVE variable; they share only the common
 * block /timing/ of ARPACK's statistics (operation counts and timers,
 * which a run writes and towstab never reads: iparam[8..10] are not
 * used), so a real run and a complex run may run at once: the modes'
 * run beside the rightmost search (modes_and_search). */
static int solve_arpack_real_run(const ts_linear *lin,
                                 const ts_eigen_opts *o, double sigma,
                                 ts_eigen *e, cand_list *L, tsi_shift *keep,
                                 ts_err *err);

/* keep (may be NULL; zeroed, holding no factorisation) takes over the
 * run's factorisation of S(sigma), for the caller's checks to refactor
 * (tsi_shift_eig_error); else it is freed. */
static int solve_arpack_real(const ts_linear *lin, const ts_eigen_opts *o,
                             double sigma, ts_eigen *e, cand_list *L,
                             tsi_shift *keep, ts_err *err)
{
    int rc;
#ifdef _OPENMP
#pragma omp critical(ts_arpack_real)
#endif
    rc = solve_arpack_real_run(lin, o, sigma, e, L, keep, err);
    return rc;
}

/* Rows of V per block of ritz_vectors_real's product (a block of the
 * vectors, RITZ_ROWS x nconv, stays in cache). */
#define RITZ_ROWS 256

/* The Ritz vectors of the nconv Ritz values dr + i di that dneupd
 * returned without vectors (rvec 0: lambda = sigma + 1/mu, mu a Ritz value
 * of OP), from the Arnoldi factorisation OP V = V H + f e^T that dnaupd
 * leaves: V [n x ncv], H [ncv x ncv] (hc, a copy taken before dneupd,
 * which zeroes its entry (3, 1), where dnaupd keeps ||f||), f in resid.
 * Each vector is x = V y with H y = mu y (dgeev on H; mu matched one to
 * one to the nearest of H's eigenvalues), |y| = 1, purified by one step
 * of inverse iteration as dneupd does it, x + f y_ncv / mu = OP x / mu.
 * Each becomes a candidate of L (room for nconv made by the caller),
 * its vector formed straight into L's store: a real eigenvalue's from one
 * column x_j, a pair's x_j + i x_(j+1) for dr_j + i di_j (either sign
 * first), as dneupd's columns z_j, z_(j+1) would give it (cand_add).
 * One pass over V by blocks of rows (a dgemm each, BLAS 3) in place of
 * dneupd's nconv Householder reflections applied to V one after another
 * (dorm2r, each a pass over V; doc/performance.md), and no n x nconv
 * array of real vectors beside the candidates'. TS_ELAPACK when a Ritz
 * value is not among H's eigenvalues (L is then left as it was, and the
 * caller asks dneupd for the vectors), TS_ENOMEM. */
static int ritz_vectors_real(const tsi_lapack *la, int n, int ncv, int nconv,
                             double sigma, const double *dr,
                             const double *di, double *hc,
                             const double *v, const double *f, cand_list *L)
{
    int lwork = 4 * ncv, info = 0, one = 1, rc = TS_OK;
    double *wr = malloc((size_t)ncv * (7 + (size_t)2 * ncv) * sizeof(double));
    int *used = calloc((size_t)ncv, sizeof(int));
    int *kcol = malloc(((size_t)nconv + 1) * 2 * sizeof(int));
    double *t = malloc((size_t)RITZ_ROWS * ((size_t)nconv + 1) *
                       sizeof(double));
    if (!wr || !used || !kcol || !t) {
        free(wr);
        free(used);
        free(kcol);
        free(t);
        return TS_ENOMEM;
    }
    double *wi = wr + ncv, *work = wi + ncv, *vr = work + lwork,
           *y = vr + (size_t)ncv * ncv, *c = y + (size_t)ncv * ncv;
    la->dgeev_("N", "V", &ncv, hc, &ncv, wr, wi, NULL, &one, vr, &ncv, work,
               &lwork, &info, 1, 1);
    if (info != 0)
        rc = TS_ELAPACK;
    double big = 0;
    for (int k = 0; k < ncv; k++)
        big = fmax(big, hypot(wr[k], wi[k]));
    for (int j = 0; rc == TS_OK && j < nconv; j++) {
        double complex lam = dr[j] + I * di[j];
        int pair = di[j] != 0.0;
        if (pair && j + 1 >= nconv) {
            rc = TS_ELAPACK; /* a pair's second value missing */
            break;
        }
        double complex mu = 1.0 / (lam - sigma);
        int best = -1;
        double dist = INFINITY;
        for (int k = 0; k < ncv; k++) {
            double d = cabs(wr[k] + I * wi[k] - mu);
            if (!used[k] && (wi[k] != 0.0) == pair && d < dist) {
                best = k;
                dist = d;
            }
        }
        if (best < 0 || !(dist <= 1e-8 * big)) {
            rc = TS_ELAPACK;
            break;
        }
        used[best] = 1;
        /* dgeev's pair: k (wi > 0) then k + 1, vectors vr_k +- i vr_(k+1)
         * in that order. */
        int k = best, sign = 1;
        if (pair) {
            if (wi[k] < 0.0) {
                k--;
                sign = -1;
            }
            used[k] = used[k + 1] = 1;
        }
        double *yr = y + (size_t)j * ncv, *yi = pair ? yr + ncv : NULL;
        double s = 0;
        for (int i = 0; i < ncv; i++) {
            yr[i] = vr[(size_t)k * ncv + i];
            s += yr[i] * yr[i];
            if (pair) {
                yi[i] = sign * vr[(size_t)(k + 1) * ncv + i];
                s += yi[i] * yi[i];
            }
        }
        s = s > 0 ? 1.0 / sqrt(s) : 0.0;
        for (int i = 0; i < ncv; i++) {
            yr[i] *= s;
            if (pair)
                yi[i] *= s;
        }
        double complex p = (yr[ncv - 1] + I * (pair ? yi[ncv - 1] : 0.0)) / mu;
        c[j] = creal(p);
        if (pair) {
            c[j + 1] = cimag(p);
            j++;
        }
    }
    if (rc == TS_OK) {
        /* The candidates, then their vectors by blocks of RITZ_ROWS rows
         * straight into L's store: the block's x_j = V y_j + c_j f in t,
         * a real value's column as it is, a pair's x_j + i x_(j+1),
         * conjugated with its value when di_j < 0 (as cand_add). */
        int base = L->n, nk = 0, *kpair = kcol + nconv + 1;
        for (int j = 0; j < nconv && L->n < L->cap; j++) {
            kcol[nk] = j;
            kpair[nk] = di[j] == 0.0 ? 0 : (di[j] < 0.0 ? -1 : 1);
            cand_new(L, dr[j] + I * di[j], NAN, NAN, NAN);
            L->n++;
            nk++;
            j += di[j] != 0.0;
        }
        double a1 = 1.0, b0 = 0.0;
        for (int r0 = 0; r0 < n; r0 += RITZ_ROWS) {
            int nb = n - r0 < RITZ_ROWS ? n - r0 : RITZ_ROWS;
            la->dgemm_("N", "N", &nb, &nconv, &ncv, &a1, v + r0, &n, y, &ncv,
                       &b0, t, &nb, 1, 1);
            for (int j = 0; j < nconv; j++)
                for (int i = 0; i < nb; i++)
                    t[(size_t)j * nb + i] += c[j] * f[r0 + i];
            for (int k = 0; k < nk; k++) {
                const double *tr = t + (size_t)kcol[k] * nb;
                pair_into(L->v + (size_t)(base + k) * n + r0, tr,
                          kpair[k] ? tr + nb : NULL, kpair[k], (size_t)nb);
            }
        }
    }
    free(wr);
    free(used);
    free(kcol);
    free(t);
    return rc;
}

/* ritz_vectors_real for a complex run (znaupd, zneupd without vectors):
 * the nconv Ritz values d, each its own vector x = V y, H y = mu y (zgeev),
 * purified as zneupd does it; those not dropped (drop[j] >= 0) become
 * candidates of L with the values lam[j] (room made by the caller), their
 * vectors formed straight into L's store. TS_ELAPACK leaves L as it was
 * (the caller then asks zneupd for the vectors), TS_ENOMEM. */
static int ritz_vectors_complex(const tsi_lapack *la, int n, int ncv,
                                int nconv, double complex sigma,
                                const double complex *d, double complex *hc,
                                const double complex *v,
                                const double complex *f,
                                const double complex *lam, const int *drop,
                                cand_list *L)
{
    int lwork = 4 * ncv, info = 0, one = 1, rc = TS_OK;
    double complex *w = malloc((size_t)ncv * (6 + (size_t)2 * ncv) *
                               sizeof(double complex));
    double *rwork = malloc(2 * (size_t)ncv * sizeof(double));
    int *used = calloc((size_t)ncv, sizeof(int));
    if (!w || !rwork || !used) {
        free(w);
        free(rwork);
        free(used);
        return TS_ENOMEM;
    }
    double complex *work = w + ncv, *vr = work + lwork,
                   *y = vr + (size_t)ncv * ncv, *c = y + (size_t)ncv * ncv;
    la->zgeev_("N", "V", &ncv, hc, &ncv, w, NULL, &one, vr, &ncv, work,
               &lwork, rwork, &info, 1, 1);
    if (info != 0)
        rc = TS_ELAPACK;
    double big = 0;
    for (int k = 0; k < ncv; k++)
        big = fmax(big, cabs(w[k]));
    for (int j = 0; rc == TS_OK && j < nconv; j++) {
        double complex mu = 1.0 / (d[j] - sigma);
        int best = -1;
        double dist = INFINITY;
        for (int k = 0; k < ncv; k++)
            if (!used[k] && cabs(w[k] - mu) < dist) {
                best = k;
                dist = cabs(w[k] - mu);
            }
        if (best < 0 || !(dist <= 1e-8 * big)) {
            rc = TS_ELAPACK;
            break;
        }
        used[best] = 1;
        double complex *yj = y + (size_t)j * ncv;
        double s = 0;
        for (int i = 0; i < ncv; i++) {
            yj[i] = vr[(size_t)best * ncv + i];
            s += creal(yj[i]) * creal(yj[i]) + cimag(yj[i]) * cimag(yj[i]);
        }
        s = s > 0 ? 1.0 / sqrt(s) : 0.0;
        for (int i = 0; i < ncv; i++)
            yj[i] *= s;
        c[j] = yj[ncv - 1] / mu;
    }
    if (rc == TS_OK) {
        /* The kept vectors' coefficients packed, then one product
         * straight into L's store (its columns from L->n on), purified
         * and conjugated there with their values (as cand_add_complex). */
        int nk = 0;
        for (int j = 0; j < nconv; j++) {
            if (drop[j] < 0)
                continue;
            if (nk != j)
                memcpy(y + (size_t)nk * ncv, y + (size_t)j * ncv,
                       (size_t)ncv * sizeof *y);
            c[nk++] = c[j];
        }
        int base = L->n;
        double complex a1 = 1.0, b0 = 0.0;
        if (nk > 0)
            la->zgemm_("N", "N", &n, &nk, &ncv, &a1, v, &n, y, &ncv, &b0,
                       L->v + (size_t)base * n, &n, 1, 1);
        for (int j = 0, k = 0; j < nconv; j++) {
            if (drop[j] < 0)
                continue;
            double complex *x = L->v + (size_t)(base + k) * n;
            for (int i = 0; i < n; i++)
                x[i] += c[k] * f[i];
            cand_take(L, lam[j]);
            k++;
        }
    }
    free(w);
    free(rwork);
    free(used);
    return rc;
}

static int solve_arpack_real_run(const ts_linear *lin,
                                 const ts_eigen_opts *o, double sigma,
                                 ts_eigen *e, cand_list *L, tsi_shift *keep,
                                 ts_err *err)
{
    int n = lin->nstate, nev, ncv, rc;
    tsi_arpack ar;
    tsi_lapack la;
    if (tsi_arpack_open(&ar, err) != TS_OK ||
        tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    if ((rc = arpack_sizes(n, o->count, &nev, &ncv, err)) != TS_OK)
        return rc;
    tsi_shift sh;
    double sigmai = 0.0;
    if ((rc = tsi_shift_factor(&sh, lin, sigma, err)) != TS_OK)
        return rc;
    int lworkl = 3 * ncv * ncv + 6 * ncv;
    double *resid = malloc((size_t)n * sizeof(double));
    double *v = tsi_big_malloc((size_t)n * (size_t)ncv * sizeof(double));
    double *workd = malloc(3 * (size_t)n * sizeof(double));
    double *workl = malloc((size_t)lworkl * sizeof(double));
    double *dr = malloc((size_t)(nev + 1) * sizeof(double));
    double *di = malloc((size_t)(nev + 1) * sizeof(double));
    double *z = NULL; /* dneupd's vectors, should ritz_vectors_real fail */
    double *workev = malloc(3 * (size_t)ncv * sizeof(double));
    double *hc = malloc((size_t)ncv * ncv * sizeof(double));
    int *select = calloc((size_t)ncv, sizeof(int));
    if (!resid || !v || !workd || !workl || !dr || !di || !workev || !hc ||
        !select) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
        goto out;
    }
    int iparam[11] = {0}, ipntr[14] = {0}, ido = 0, info = 1;
    start_vector(resid, n);
    iparam[0] = 1;                  /* exact shifts */
    iparam[2] = o->arpack_max_iter; /* restarts */
    iparam[3] = 1;
    iparam[6] = 3;                  /* shift-invert */
    double tol = modes_tol(lin, o);
    for (;;) {
        ar.dnaupd_(&ido, "I", &n, "LM", &nev, &tol, resid, &ncv, v, &n, iparam,
                   ipntr, workd, workl, &lworkl, &info, 1, 2);
        if (ido != -1 && ido != 1)
            break;
        eig_poll pp = {o, "eigensolve", 0, NAN};
        if ((rc = eig_poll_check(&pp, e->arpack_ops, err)) != TS_OK)
            goto out;
        tsi_shift_solve_real(&sh, workd + ipntr[0] - 1, workd + ipntr[1] - 1);
        e->arpack_ops++;
    }
    e->arpack_iterations = iparam[2];
    e->arpack_nconv = iparam[4];
    if (info == 1) {
        rc = ts_fail(err, TS_ECONV,
                     "eigen: ARPACK dnaupd reached %d restarts with %d of %d "
                     "Ritz values converged",
                     o->arpack_max_iter, iparam[4], nev);
        goto out;
    }
    if (info != 0) {
        rc = ts_fail(err, TS_ELAPACK, "eigen: ARPACK dnaupd info %d (%s)",
                     info, arpack_info_text(info));
        goto out;
    }
    /* The Ritz values from dneupd, their vectors from H and V
     * (ritz_vectors_real); dneupd's own vectors should H not hold one of
     * its values. */
    double *h = workl + ipntr[4] - 1, rnorm = h[2];
    memcpy(hc, h, (size_t)ncv * ncv * sizeof(double));
    hc[2] = 0.0;
    int rvec = 0, vrc = TS_ELAPACK;
    if (cand_init(L, iparam[4] + 1, n) != TS_OK) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    for (int pass = 0; pass < 2 && vrc == TS_ELAPACK; pass++, rvec = 1) {
        h[2] = rnorm;
        /* (Without vectors dneupd does not reference z: v stands in.) */
        if (rvec && !(z = tsi_big_malloc((size_t)n * (size_t)(nev + 1) *
                                         sizeof(double)))) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
            goto out;
        }
        ar.dneupd_(&rvec, "A", select, dr, di, rvec ? z : v, &n, &sigma,
                   &sigmai, workev, "I", &n, "LM", &nev, &tol, resid, &ncv,
                   v, &n, iparam, ipntr, workd, workl, &lworkl, &info, 1, 1,
                   2);
        if (info != 0) {
            rc = ts_fail(err, TS_ELAPACK,
                         "eigen: ARPACK dneupd info %d (%s)", info,
                         arpack_info_text(info));
            goto out;
        }
        vrc = rvec ? TS_OK
                   : ritz_vectors_real(&la, n, ncv, iparam[4], sigma, dr, di,
                                       hc, v, resid, L);
        if (vrc == TS_ENOMEM) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
            goto out;
        }
    }
    int nconv = iparam[4];
    /* dneupd's vectors (the fallback): into the candidates here. */
    for (int j = 0; z && j < nconv; j++) {
        const double *zj = z + (size_t)j * n;
        if (di[j] == 0.0) {
            cand_add(L, dr[j], zj, NULL, NAN, NAN, NAN);
        } else if (j + 1 < nconv) {
            /* A pair: z_j + i z_{j+1} belongs to dr + i di (di > 0 first). */
            double complex lam = dr[j] + I * di[j];
            const double *zk = zj + n;
            cand_add(L, lam, zj, zk, NAN, NAN, NAN);
            j++;
        }
    }
out:
    if (keep && rc == TS_OK)
        *keep = sh; /* taken over, not freed */
    else
        tsi_shift_free(&sh);
    free(resid);
    free(v);
    free(workd);
    free(workl);
    free(dr);
    free(di);
    free(z);
    free(workev);
    free(hc);
    free(select);
    return rc;
}

/* ARPACK statistics of one or more runs. */
typedef struct arpack_stats {
    int iterations, ops, nconv, partial;
} arpack_stats;

/* The nev eigenvalues nearest the complex shift sigma with their vectors,
 * appended to L (grown as needed): znaupd/zneupd in shift-invert mode on
 * OP = (A - sigma I)^-1 through the sparse model, ncv Arnoldi vectors,
 * relative tolerance tol (0: machine precision), at most maxiter restarts.
 * Eigenvalues in the lower half plane are conjugated; a conjugate pair
 * found whole is kept once (matched one to one, so double eigenvalues stay
 * double). */
static int arpack_near_run(const ts_linear *lin, double complex sigma,
                           int nev, int ncv, double tol, int maxiter,
                           int partial, const double complex *start,
                           const eig_poll *pp, cand_list *L,
                           arpack_stats *st, tsi_shift *fac, ts_err *err);

static int arpack_near(const ts_linear *lin, double complex sigma, int nev,
                       int ncv, double tol, int maxiter, int partial,
                       const double complex *start, const eig_poll *pp,
                       cand_list *L, arpack_stats *st, tsi_shift *fac,
                       ts_err *err)
{
    int rc;
#ifdef _OPENMP
#pragma omp critical(ts_arpack_complex)
#endif
    rc = arpack_near_run(lin, sigma, nev, ncv, tol, maxiter, partial, start,
                         pp, L, st, fac, err);
    return rc;
}

/* The candidates' values lam[n] of a complex run's Ritz values d[n]:
 * rounding makes real eigenvalues slightly complex (snapped to the real
 * axis), and of a conjugate pair found whole the lower member is dropped
 * (used -1; its partner used 1; the others 0), matched one to one so that
 * double eigenvalues stay double. */
static void complex_values(int n, const double complex *d,
                           double complex *lam, int *used)
{
    for (int j = 0; j < n; j++) {
        lam[j] = d[j];
        used[j] = 0;
        if (fabs(cimag(lam[j])) <= REAL_IM_RTOL * cabs(lam[j]))
            lam[j] = creal(lam[j]);
    }
    for (int j = 0; j < n; j++) {
        if (cimag(lam[j]) >= 0.0)
            continue;
        for (int k = 0; k < n; k++) {
            if (used[k] || cimag(lam[k]) <= 0.0)
                continue;
            if (cabs(lam[k] - conj(lam[j])) <=
                CONJ_MATCH_RTOL * cabs(lam[j])) {
                used[k] = 1;
                used[j] = -1;
                break;
            }
        }
    }
}

static int arpack_near_run(const ts_linear *lin, double complex sigma,
                           int nev, int ncv, double tol, int maxiter,
                           int partial, const double complex *start,
                           const eig_poll *pp, cand_list *L,
                           arpack_stats *st, tsi_shift *fac, ts_err *err)
{
    int n = lin->nstate, rc;
    tsi_arpack ar;
    tsi_lapack la;
    if (tsi_arpack_open(&ar, err) != TS_OK ||
        tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    tsi_shift own, *sh = fac ? fac : &own;
    if ((rc = fac ? tsi_shift_refactor_judged(sh, lin, sigma, NULL, err)
                  : tsi_shift_factor(sh, lin, sigma, err)) != TS_OK)
        return rc;
    int lworkl = 3 * ncv * ncv + 5 * ncv;
    size_t szc = sizeof(double complex);
    double complex *resid = malloc((size_t)n * szc);
    double complex *v = tsi_big_malloc((size_t)n * (size_t)ncv * szc);
    double complex *workd = malloc(3 * (size_t)n * szc);
    double complex *workl = malloc((size_t)lworkl * szc);
    double complex *d = malloc((size_t)(nev + 1) * szc);
    double complex *z = NULL; /* zneupd's vectors, the fallback's */
    double complex *lam = malloc((size_t)(nev + 1) * szc);
    double complex *workev = malloc(2 * (size_t)ncv * szc);
    double *rwork = malloc((size_t)ncv * sizeof(double));
    double complex *hc = malloc((size_t)ncv * ncv * szc);
    int *select = calloc((size_t)ncv, sizeof(int));
    int *used = calloc((size_t)(nev + 1), sizeof(int));
    if (!resid || !v || !workd || !workl || !d || !lam || !workev ||
        !rwork || !hc || !select || !used) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
        goto out;
    }
    int iparam[11] = {0}, ipntr[14] = {0}, ido = 0, info = 1;
    if (start)
        memcpy(resid, start, (size_t)n * szc);
    else
        start_vector((double *)resid, 2 * n);
    iparam[0] = 1;
    iparam[2] = maxiter;
    iparam[6] = 3;
    for (;;) {
        ar.znaupd_(&ido, "I", &n, "LM", &nev, &tol, resid, &ncv, v, &n, iparam,
                   ipntr, workd, workl, &lworkl, rwork, &info, 1, 2);
        if (ido != -1 && ido != 1)
            break;
        if ((rc = eig_poll_check(pp, st->ops, err)) != TS_OK)
            goto out;
        tsi_shift_solve(sh, workd + ipntr[0] - 1, workd + ipntr[1] - 1);
        st->ops++;
    }
    st->iterations += iparam[2];
    st->nconv += iparam[4];
    if (info == 1 && !(partial && iparam[4] > 0)) {
        rc = ts_fail(err, TS_ECONV,
                     "eigen: ARPACK znaupd reached %d restarts with %d of %d "
                     "Ritz values converged",
                     maxiter, iparam[4], nev);
        goto out;
    }
    if (info == 1) {
        /* The Ritz values that converged are exact to the tolerance;
         * zneupd extracts those. */
        st->partial++;
        info = 0;
    }
    if (info != 0) {
        rc = ts_fail(err, TS_ELAPACK, "eigen: ARPACK znaupd info %d (%s)",
                     info, arpack_info_text(info));
        goto out;
    }
    /* As in solve_arpack_real_run: the values from zneupd, the vectors
     * from H and V (ritz_vectors_complex), zneupd's own as the fallback. */
    double complex *h = workl + ipntr[4] - 1, rnorm = h[2];
    memcpy(hc, h, (size_t)ncv * ncv * sizeof(double complex));
    hc[2] = 0.0;
    int rvec = 0, vrc = TS_ELAPACK, nconv = 0;
    for (int pass = 0; pass < 2 && vrc == TS_ELAPACK; pass++, rvec = 1) {
        h[2] = rnorm;
        /* (Without vectors zneupd does not reference z: v stands in.) */
        if (rvec && !(z = tsi_big_malloc((size_t)n * (size_t)(nev + 1) *
                                         szc))) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
            goto out;
        }
        ar.zneupd_(&rvec, "A", select, d, rvec ? z : v, &n, &sigma, workev,
                   "I", &n, "LM", &nev, &tol, resid, &ncv, v, &n, iparam,
                   ipntr, workd, workl, &lworkl, rwork, &info, 1, 1, 2);
        if (info != 0) {
            rc = ts_fail(err, TS_ELAPACK,
                         "eigen: ARPACK zneupd info %d (%s)", info,
                         arpack_info_text(info));
            goto out;
        }
        nconv = iparam[4];
        if (cand_grow(L, nconv) != TS_OK) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
            goto out;
        }
        complex_values(nconv, d, lam, used);
        vrc = rvec ? TS_OK
                   : ritz_vectors_complex(&la, n, ncv, nconv, sigma, d, hc,
                                          v, resid, lam, used, L);
        if (vrc == TS_ENOMEM) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
            goto out;
        }
    }
    /* zneupd's vectors (the fallback): into the candidates here. */
    for (int j = 0; z && j < nconv; j++) {
        if (used[j] < 0)
            continue;
        cand_add_complex(L, lam[j], z + (size_t)j * n);
    }
out:
    if (!fac)
        tsi_shift_free(&own);
    free(resid);
    free(v);
    free(workd);
    free(workl);
    free(d);
    free(lam);
    free(z);
    free(workev);
    free(rwork);
    free(hc);
    free(select);
    free(used);
    return rc;
}

static int solve_arpack_complex(const ts_linear *lin, const ts_eigen_opts *o,
                                ts_eigen *e, cand_list *L, ts_err *err)
{
    int nev = 0, ncv = 0, rc;
    if ((rc = arpack_sizes(lin->nstate, o->count, &nev, &ncv, err)) != TS_OK)
        return rc;
    if (cand_init(L, nev + 1, lin->nstate) != TS_OK)
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    arpack_stats st = {0, 0, 0, 0};
    eig_poll pp = {o, "eigensolve", 0, NAN};
    rc = arpack_near(lin, I * 2.0 * M_PI * o->target_hz, nev, ncv,
                     modes_tol(lin, o), o->arpack_max_iter, 0, NULL, &pp, L,
                     &st, NULL, err);
    e->arpack_iterations = st.iterations;
    e->arpack_ops = st.ops;
    e->arpack_nconv = st.nconv;
    return rc;
}

/* ---- The rightmost eigenvalues (sparse model) ---------------------------- */

/* The search (doc/linear.md, section 3, "Rightmost eigenvalues"). */
#define SWEEP_NEV 8        /* eigenvalues found around each shift (the
                              grid's: SWEEP_GRID_NEV) */
#define SWEEP_NCV 20       /* Arnoldi vectors of each shift's run */
#define SWEEP_GRID_NEV 6   /* eigenvalues found around each grid point (at
                              SWEEP_GRID_TOL): as many as converge in the
                              first SWEEP_NCV Arnoldi steps on Kamman's
                              example 1 at 10 000 links, where 8 need a
                              restart (doc/linear.md section 3b, step 2) */
#define SWEEP_RATIO 4.0    /* frequency ratio of the grid of shifts */
#define SWEEP_PRE_GRID 2   /* points of the grid, from the top down, run
                              before the modes' highest frequency is known
                              (beside the modes' run: modes_and_search) */
#define SWEEP_RESTARTS 30  /* ARPACK restarts of a run; what converged by
                              then is kept */
#define SWEEP_SEED_RTOL 0.05 /* seeds closer than this are one */
#define SWEEP_CLIMBS 1     /* runs climbed towards a larger real part */
#define SWEEP_STEPS 4      /* re-centrings of each climb */
#define SWEEP_CHECKED 4    /* rightmost eigenvalues given error bounds */
#define SWEEP_TOL 1e-6     /* relative Ritz tolerance of the search's runs
                              (or arpack_tol when looser): the eigenvalues
                              it finds serve the verdict, whose error
                              bounds hold each Ritz value's own error
                              (ritz_error, first-order exact: test_eigen);
                              a third fewer operator applications than at
                              1e-10 on Kamman's example 1 at 1000 and
                              10 000 links, the same rightmost eigenvalue
                              and bound to 4 digits. Looser was measured
                              and not kept: at 1e-3 to 1e-5 the clusters
                              of nearly undamped modes (Kamman's example 1
                              above the water, the branched cable in the
                              turn, at 400 links) leave Ritz values whose
                              own error makes the rightmost's bound 400 to
                              650 times larger, or that are dropped as not
                              converged (doc/performance.md) */
#define SWEEP_GRID_TOL 1e-2 /* relative Ritz tolerance of the grid's runs
                              (SWEEP_TOL at the band tops and in the
                              climbs): they sample the band's damping. A
                              Ritz value of theirs that may be among the
                              2 SWEEP_CHECKED rightmost found has its own
                              error measured, and unless that is below
                              SWEEP_GRID_ACCEPT of the model's error term
                              its run is redone at SWEEP_TOL
                              (rightmost_search): the bounds stay those
                              of runs at SWEEP_TOL */
#define SWEEP_GRID_ACCEPT 0.01 /* a grid run's Ritz value whose own error
                              (ritz_error) is below this fraction of its
                              error estimate's term (dlambda) stands as it
                              is; otherwise its run is redone */
#define SWEEP_GRID_SAFETY 10.0 /* a Ritz value at tolerance tol of a run
                              of radius r lies within SWEEP_GRID_SAFETY
                              tol r of its eigenvalue (its error is about
                              tol |lambda - sigma|, times its condition) */
/* Two eigenvectors with |v1^H v2| above this (unit vectors) are one. */
#define SWEEP_SAME_VECTOR 0.99

/* Local band-top frequencies of node k (rad/s), the Rayleigh quotients of
 * its zig-zag: transverse, sum_j (-1)^dist(k,j) K_kj restricted to the
 * plane normal to the link ending at k, over the mass in that plane (the
 * top of a uniform chain's band exactly: 2 sqrt(T / (m l)) with tension
 * alone, with bending and drag stiffness as K has them); axial, twice the
 * EA / l of the elastic links at k over the mass along the link. */
static void zigzag_freq(const ts_descriptor *d, int k, double *wt,
                        double *wa)
{
    const ts_system *sys = d->sys;
    const double *n = d->n + 3 * sys->nodes[k].link;
    double G[9] = {0};
    for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
        /* The tow point's columns are inputs; a vehicle's angles are not
         * a displacement (N/rad): neither is in the zig-zag. */
        if (d->bcol[b] == 0 || d->bcol[b] >= d->nn)
            continue;
        double sg = d->bdist[b] % 2 ? -1.0 : 1.0;
        for (int i = 0; i < 9; i++)
            G[i] += sg * d->K[9 * (size_t)b + i];
    }
    /* An orthonormal pair normal to n. */
    double t[3] = {fabs(n[0]) < 0.6 ? 1.0 : 0.0, fabs(n[0]) < 0.6 ? 0.0 : 1.0,
                   0.0};
    double a[3], c[3], tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
    for (int i = 0; i < 3; i++)
        a[i] = t[i] - tn * n[i];
    double an = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (int i = 0; i < 3; i++)
        a[i] /= an;
    c[0] = n[1] * a[2] - n[2] * a[1];
    c[1] = n[2] * a[0] - n[0] * a[2];
    c[2] = n[0] * a[1] - n[1] * a[0];
    const double *e[2] = {a, c};
    static const int mi[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    const double *M = d->M + 6 * k;
    double g[2][2], m[2][2];
    for (int p = 0; p < 2; p++)
        for (int q = 0; q < 2; q++) {
            double gs = 0, ms = 0;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) {
                    gs += e[p][i] * G[3 * i + j] * e[q][j];
                    ms += e[p][i] * M[mi[i][j]] * e[q][j];
                }
            g[p][q] = gs;
            m[p][q] = ms;
        }
    /* Largest root of det(g_sym - w^2 m) = 0. */
    double g01 = 0.5 * (g[0][1] + g[1][0]);
    double A = m[0][0] * m[1][1] - m[0][1] * m[0][1];
    double B = -(g[0][0] * m[1][1] + g[1][1] * m[0][0] - 2 * g01 * m[0][1]);
    double C = g[0][0] * g[1][1] - g01 * g01;
    double disc = B * B - 4 * A * C;
    double w2 = A > 0 ? (-B + sqrt(disc > 0 ? disc : 0)) / (2 * A) : 0;
    *wt = w2 > 0 ? sqrt(w2) : 0.0;
    double ka = 0;
    int l = sys->nodes[k].link;
    if (d->kind[l] == TSI_LINK_TAUT)
        ka += d->ka[l];
    for (int ci = sys->nodes[k].child_begin; ci < sys->nodes[k].child_end;
         ci++) {
        int lc = sys->child_links[ci];
        if (d->kind[lc] == TSI_LINK_TAUT)
            ka += d->ka[lc];
    }
    double mn = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            mn += n[i] * M[mi[i][j]] * n[j];
    *wa = ka > 0 && mn > 0 ? sqrt(2 * ka / mn) : 0.0;
}

/* A shift of the search: its frequency (rad/s), and whether a band top
 * lies there (1) or it is a point of the grid between them (0). */
typedef struct sweep_seed {
    double w;
    int top;
} sweep_seed;

static int cmp_seed(const void *a, const void *b)
{
    double x = ((const sweep_seed *)a)->w, y = ((const sweep_seed *)b)->w;
    return x < y ? -1 : (x > y ? 1 : 0);
}

/* Whether candidate a of La and b of Lb are the same eigenpair: the same
 * eigenvalue within CONJ_MATCH_RTOL (and their slack) and the same
 * vector (|b^H a| > SWEEP_SAME_VECTOR |a| |b|). O(nstate). */
static int same_pair(const cand_list *La, const cand *a, const cand_list *Lb,
                     const cand *b)
{
    if (cabs(b->lam - a->lam) >
        CONJ_MATCH_RTOL * cabs(a->lam) + b->slack + a->slack)
        return 0;
    int n = La->nstate;
    const double complex *va = cand_v(La, a->vec);
    const double complex *vb = cand_v(Lb, b->vec);
    double complex dot = 0;
    double na = 0, nb = 0;
    for (int r = 0; r < n; r++) {
        dot += conj(vb[r]) * va[r];
        na += creal(va[r] * conj(va[r]));
        nb += creal(vb[r] * conj(vb[r]));
    }
    return cabs(dot) > SWEEP_SAME_VECTOR * sqrt(na * nb);
}

/* Mark the candidates from `from` on that repeat an earlier one (the same
 * eigenvalue within CONJ_MATCH_RTOL and the same vector); returns the
 * index of the one with the largest real part among the new, -1 if none,
 * and its distance to sigma's farthest new neighbour in *radius. */
static int sweep_new(cand_list *L, int from, double complex sigma,
                     double *radius)
{
    int best = -1;
    *radius = 0;
    for (int i = from; i < L->n; i++) {
        cand *c = &L->c[i];
        c->sweep = 1;
        *radius = fmax(*radius, cabs(c->lam - sigma));
        for (int j = 0; j < i && c->sweep == 1; j++) {
            const cand *o = &L->c[j];
            if (o->sweep != 2 && o->sweep != 4 && same_pair(L, c, L, o))
                c->sweep = 2;
        }
        if (c->sweep == 1 &&
            (best < 0 || creal(c->lam) > creal(L->c[best].lam)))
            best = i;
    }
    return best;
}

/* One run of the search at sigma, at the relative Ritz tolerance `tol`
 * (or arpack_tol when looser); best and radius as sweep_new. A shift
 * exactly on an eigenvalue is moved by 1e-9 of itself once. */
static int sweep_run(const ts_linear *lin, const ts_eigen_opts *o,
                     double complex sigma, double tol,
                     const double complex *start, int shift, int shifts,
                     cand_list *L, arpack_stats *st, tsi_shift *fac,
                     int *best, double *radius, ts_err *err)
{
    int from = L->n, ncv = SWEEP_NCV < lin->nstate ? SWEEP_NCV : lin->nstate;
    int want = tol > SWEEP_TOL ? SWEEP_GRID_NEV : SWEEP_NEV;
    int nev = want < ncv - 2 ? want : ncv - 2;
    tol = fmax(o->arpack_tol, tol);
    eig_poll pp = {o, "rightmost search", shift, shifts};
    int rc = arpack_near(lin, sigma, nev, ncv, tol, SWEEP_RESTARTS, 1, start,
                         &pp, L, st, fac, err);
    if (rc == TS_ESINGULAR) {
        sigma *= 1.0 + 1e-9;
        rc = arpack_near(lin, sigma, nev, ncv, tol, SWEEP_RESTARTS, 1, start,
                         &pp, L, st, fac, err);
    }
    if (rc != TS_OK)
        return rc;
    if (tol > SWEEP_TOL) {
        /* The Ritz values' slack, before the repeats are matched. */
        double r = 0;
        for (int i = from; i < L->n; i++)
            r = fmax(r, cabs(L->c[i].lam - sigma));
        for (int i = from; i < L->n; i++)
            L->c[i].slack = SWEEP_GRID_SAFETY * tol * r;
    }
    *best = sweep_new(L, from, sigma, radius);
    return TS_OK;
}

/* The real part that the SWEEP_CHECKED rightmost eigenvalues found by the
 * search must reach to be checked, and twice as many as a margin for
 * those a check drops: the (2 SWEEP_CHECKED)-th largest real part among
 * L's search candidates from `from` on (-inf when there are fewer). */
static double sweep_threshold(const cand_list *L, int from)
{
    double top[2 * SWEEP_CHECKED];
    int nt = 0;
    for (int i = from; i < L->n; i++) {
        if (L->c[i].sweep != 1)
            continue;
        double re = creal(L->c[i].lam);
        int k;
        if (nt < 2 * SWEEP_CHECKED)
            k = nt++;
        else if (re > top[nt - 1])
            k = nt - 1;
        else
            continue;
        top[k] = re;
        for (; k > 0 && top[k] > top[k - 1]; k--) {
            double t = top[k];
            top[k] = top[k - 1];
            top[k - 1] = t;
        }
    }
    return nt == 2 * SWEEP_CHECKED ? top[nt - 1] : -INFINITY;
}

/* The rightmost search: shifts i w at the local band tops of every cable
 * (zigzag_freq: transverse, and axial for elastic cables) and on a grid of
 * ratio SWEEP_RATIO from the highest frequency among the modes already
 * found to the highest band top, the discretisation's top frequency; at
 * each, the SWEEP_NEV eigenvalues nearest (SWEEP_GRID_NEV at
 * SWEEP_GRID_TOL on the grid,
 * SWEEP_TOL at the band tops; a grid run that holds a candidate for the
 * checked rightmost eigenvalues is run again at SWEEP_TOL). Then the
 * SWEEP_CLIMBS runs with the largest real parts climb: while the
 * rightmost eigenvalue a run found lies in the outer half of its disc,
 * the next shift is at its frequency. Adds the eigenvalues found to L
 * (sweep = 1, repeats and a rerun grid run's first values 2). keep (may
 * be NULL; zeroed) takes over the runs' factorisation at the last shift,
 * for the caller's checks to refactor (tsi_shift_eig_error); else it is
 * freed. */
static int rightmost_search(const ts_linear *lin, const ts_descriptor *d,
                            const ts_eigen_opts *o, ts_eigen *e, cand_list *L,
                            double (*get_wlo)(void *), void *wctx,
                            tsi_shift *keep, ts_err *err)
{
    const ts_system *sys = d->sys;
    int nc = sys->ncables;
    double *top = calloc(2 * (size_t)nc, sizeof(double));
    sweep_seed *seed = calloc(64, sizeof *seed);
    if (!top || !seed) {
        free(top);
        free(seed);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    for (int k = 1; k < d->nn; k++) {
        double wt, wa;
        zigzag_freq(d, k, &wt, &wa);
        int c = sys->links[sys->nodes[k].link].cable;
        top[2 * c] = fmax(top[2 * c], wt);
        top[2 * c + 1] = fmax(top[2 * c + 1], wa);
    }
    double wtop = 0;
    for (int i = 0; i < 2 * nc; i++)
        wtop = fmax(wtop, top[i]);
    e->top_hz = wtop / (2 * M_PI);
    /* First the band tops and the grid's top SWEEP_PRE_GRID points (down
     * from the top in steps of SWEEP_RATIO), which need not know the
     * modes; then (get_wlo, which may wait for the modes' run) the grid's
     * points down to the highest frequency among the modes, the lowest
     * of them within SWEEP_RATIO of it. */
    int ns = 0;
    for (int i = 0; i < 2 * nc && ns < 32; i++)
        if (top[i] > 0)
            seed[ns++] = (sweep_seed){top[i], 1};
    double w = wtop;
    for (int k = 0; k < SWEEP_PRE_GRID && ns < 62; k++)
        seed[ns++] = (sweep_seed){w /= SWEEP_RATIO, 0};
    qsort(seed, (size_t)ns, sizeof *seed, cmp_seed);
    int nu = 0;
    for (int i = 0; i < ns; i++) {
        if (nu == 0 || seed[i].w > seed[nu - 1].w * (1 + SWEEP_SEED_RTOL))
            seed[nu++] = seed[i];
        else
            seed[nu - 1].top |= seed[i].top; /* a band top: SWEEP_TOL */
    }
    int npre = nu;
    /* Room for the runs' eigenvalues at once: the vectors are tens of
     * MB, and each growth copies them all. */
    if (cand_grow(L, (nu + 4 + SWEEP_CLIMBS * SWEEP_STEPS) *
                         (SWEEP_NEV + 1)) != TS_OK) {
        free(top);
        free(seed);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    arpack_stats st = {0, 0, 0, 0};
    /* The runs' factorisation, refactored from shift to shift with the
     * previous pivots while a solve's backward error stays small
     * (tsi_shift_refactor_judged). */
    tsi_shift fac = {0};
    int rc = TS_OK, runs = 0, first = L->n;
    /* The grid's runs are loose only where each Ritz value's own error
     * can be measured (the sparse model with its error estimate). */
    double grid_tol = pencil_ritz(lin) ? SWEEP_GRID_TOL : SWEEP_TOL;
    double run_re[64], run_w[64], run_r[64];
    int run_best[64], run_from[64], run_to[64], run_loose[64];
    for (int i = 0; (i < nu || i == npre) && rc == TS_OK; i++) {
        if (i == npre) {
            /* The rest of the grid, once the modes are known. */
            double wlo = get_wlo(wctx);
            if (isnan(wlo)) {
                rc = TS_ECANCEL; /* the modes' run failed: its error */
                break;
            }
            if (!(wlo > 0))
                wlo = wtop / 1024;
            for (; w / SWEEP_RATIO > wlo && nu < 62;) {
                w /= SWEEP_RATIO;
                int near = 0;
                for (int j = 0; j < npre; j++)
                    near |= fabs(w - seed[j].w) <= SWEEP_SEED_RTOL * seed[j].w;
                if (!near)
                    seed[nu++] = (sweep_seed){w, 0};
            }
            qsort(seed + npre, (size_t)(nu - npre), sizeof *seed, cmp_seed);
            if (cand_grow(L, (nu - npre) * (SWEEP_NEV + 1)) != TS_OK) {
                rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
                break;
            }
            if (i == nu)
                break;
        }
        int best, from = L->n;
        double r;
        rc = sweep_run(lin, o, I * seed[i].w,
                       seed[i].top ? SWEEP_TOL : grid_tol, NULL, i,
                       nu + SWEEP_CLIMBS * SWEEP_STEPS, L, &st, &fac, &best,
                       &r, err);
        if (rc == TS_ECONV) {
            /* A run that did not converge leaves a gap, counted; it does
             * not make the analysis fail. */
            e->sweep_failed++;
            ts_err_clear(err);
            rc = TS_OK;
            continue;
        }
        if (rc == TS_OK && best >= 0) {
            run_best[runs] = best;
            run_re[runs] = creal(L->c[best].lam);
            run_w[runs] = seed[i].w;
            run_r[runs] = r;
            run_from[runs] = from;
            run_to[runs] = L->n;
            run_loose[runs] = !seed[i].top;
            runs++;
        }
    }
    /* A grid run's Ritz value that may be among the checked rightmost (its
     * real part, with its slack, reaching the 2 SWEEP_CHECKED-th largest
     * found) has its own error measured; unless that is negligible, the
     * run is redone at SWEEP_TOL in its place, so that the rightmost
     * eigenvalues' bounds are those of runs at SWEEP_TOL. Each run is
     * redone at most once. */
    tsi_shift es = {0};
    double complex *start = malloc((size_t)L->nstate * sizeof *start);
    if (!start)
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    for (int pass = 0; pass < runs && rc == TS_OK; pass++) {
        double thr = sweep_threshold(L, first);
        int redo = -1;
        for (int j = 0; j < runs && redo < 0 && rc == TS_OK; j++)
            for (int i = run_from[j]; run_loose[j] && i < run_to[j]; i++) {
                cand *c = &L->c[i];
                if (c->sweep != 1 || c->slack == 0 ||
                    creal(c->lam) + c->slack < thr)
                    continue;
                /* Its own error decides: small against the model's
                 * error, the value serves as a run at SWEEP_TOL would. */
                double dlam, ritz;
                rc = tsi_shift_eig_error(&es, lin, c->lam,
                                         cand_v(L, c->vec),
                                         &dlam, &ritz, err);
                if (rc != TS_OK)
                    break;
                if (ritz <= SWEEP_GRID_ACCEPT * dlam) {
                    c->slack = 0.0;
                    continue;
                }
                redo = j;
                break;
            }
        if (rc != TS_OK)
            break;
        if (redo < 0)
            break;
        /* The rerun starts from the sum of the run's Ritz vectors, each
         * of unit length: near the eigenvectors it is to find. */
        int nst = L->nstate;
        memset(start, 0, (size_t)nst * sizeof *start);
        for (int i = run_from[redo]; i < run_to[redo]; i++) {
            if (L->c[i].sweep != 1)
                continue;
            L->c[i].sweep = 4; /* superseded if the rerun converges */
            const double complex *v = cand_v(L, L->c[i].vec);
            double nv = 0;
            for (int k = 0; k < nst; k++)
                nv += creal(v[k]) * creal(v[k]) + cimag(v[k]) * cimag(v[k]);
            nv = nv > 0 ? 1.0 / sqrt(nv) : 0.0;
            for (int k = 0; k < nst; k++)
                start[k] += nv * v[k];
        }
        run_loose[redo] = 0;
        if (cand_grow(L, SWEEP_NEV + 1) != TS_OK) {
            rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
            break;
        }
        int best, from = L->n;
        double r;
        rc = sweep_run(lin, o, I * run_w[redo], SWEEP_TOL,
                       start, redo,
                       nu + SWEEP_CLIMBS * SWEEP_STEPS, L, &st, &fac, &best,
                       &r, err);
        /* A rerun that did not converge leaves the grid's values. */
        int keep_loose = rc == TS_ECONV;
        for (int i = run_from[redo]; i < run_to[redo]; i++)
            if (L->c[i].sweep == 4)
                L->c[i].sweep = keep_loose ? 1 : 2;
        if (keep_loose) {
            ts_err_clear(err);
            rc = TS_OK;
            continue;
        }
        run_re[redo] = NAN;
        if (rc == TS_OK && best >= 0) {
            run_best[redo] = best;
            run_re[redo] = creal(L->c[best].lam);
            run_r[redo] = r;
            run_from[redo] = from;
            run_to[redo] = L->n;
        }
    }
    tsi_shift_free(&es);
    free(start);
    int shifts = nu;
    for (int climb = 0; climb < SWEEP_CLIMBS && rc == TS_OK; climb++) {
        /* The run with the largest real part not climbed yet. */
        int pick = -1;
        for (int i = 0; i < runs; i++)
            if (!isnan(run_re[i]) && (pick < 0 || run_re[i] > run_re[pick]))
                pick = i;
        if (pick < 0)
            break;
        int best = run_best[pick];
        double w = run_w[pick], r = run_r[pick];
        run_re[pick] = NAN;
        for (int step = 0; step < SWEEP_STEPS && rc == TS_OK; step++) {
            double complex lb = L->c[best].lam;
            if (cabs(lb - I * w) <= 0.5 * r)
                break;
            /* Towards a region another run has covered: nothing new. */
            int seen = 0;
            for (int j = 0; j < runs && !seen; j++)
                seen = j != pick &&
                       fabs(cimag(lb) - run_w[j]) <= 0.5 * run_r[j];
            if (seen)
                break;
            w = cimag(lb);
            int nb;
            rc = sweep_run(lin, o, I * w, SWEEP_TOL, NULL, shifts,
                           nu + SWEEP_CLIMBS * SWEEP_STEPS, L, &st, &fac,
                           &nb, &r, err);
            shifts++;
            if (rc == TS_ECONV) {
                e->sweep_failed++;
                ts_err_clear(err);
                rc = TS_OK;
                break;
            }
            if (rc == TS_OK && nb >= 0 &&
                creal(L->c[nb].lam) >= creal(L->c[best].lam))
                best = nb;
            else
                break;
        }
    }
    if (keep && rc == TS_OK)
        *keep = fac; /* taken over, not freed */
    else
        tsi_shift_free(&fac);
    free(top);
    free(seed);
    e->sweep_shifts = shifts;
    e->arpack_iterations += st.iterations;
    e->arpack_ops += st.ops;
    e->arpack_nconv += st.nconv;
    return rc;
}

/* A mode's fields from a candidate. */
static void fill_mode(ts_mode *md, const cand *c)
{
    double re = creal(c->lam), im = cimag(c->lam), mag = cabs(c->lam);
    md->re = re;
    md->im = im;
    md->freq_hz = im / (2.0 * M_PI);
    md->period_s = im > 0 ? 1.0 / md->freq_hz : INFINITY;
    md->damping_ratio = mag > 0 ? -re / mag : 0.0;
    md->time_constant_s = re != 0 ? -1.0 / re : INFINITY;
    md->condition = c->cond;
    md->residual = c->resid;
    md->ritz_error = c->ritz;
    md->vector_condition = c->vcond;
    md->vector_error = c->verr;
    md->neutral = -1;
    md->error_bound =
        ERROR_SAFETY * ((isfinite(c->dlam) ? c->dlam : 0.0) + c->round);
}

/* ---- Neutral modes by symmetry ------------------------------------------ */

/* ARPACK's real shift when the model has neutral modes at 0 (where A is
 * singular): this fraction of max |A_ij| to the left of 0, far below any
 * damped mode of a towed system (the slowest, ~1e-3 1/s, against max
 * |A_ij| >= 1) and far above rounding. */
#define NEUTRAL_SHIFT_REL 1e-8
/* A computed eigenvector is recognised as a neutral mode when its angle
 * to the span of that eigenvalue's generators is below this many times
 * the first-order allowance max(|dA g|, |dlambda|) / gap (gap the
 * distance to the nearest other eigenvalue, dlambda the computed
 * eigenvalue's distance from the exact one). The generators g are exact
 * eigenvectors of the exact A (by symmetry), so dA g = A g - s g is the
 * computed A's residual on them, measured, not bounded: it is what moves
 * the computed eigenvector off their span, by more where the eigenvalue
 * is ill-conditioned, which dlambda shows. Without the dense A the bound ||dA|| of the
 * linearization's error estimate stands in for it (far larger on a long
 * cable: its norm is that of the finest links' rows). The allowance
 * itself must be below NEUTRAL_ANGLE_MAX (rad), else the cluster is too
 * close to tell. */
#define NEUTRAL_SAFETY 10.0
#define NEUTRAL_ANGLE_MAX 0.01

/* A copy of A with the cyclic states' rows and columns zero: a cyclic
 * state is read nowhere (its column is zero within the error) and its row
 * [0 I] makes it the integral of its rate; cut, it is a neutral mode of
 * its own (eigenvector e_j, eigenvalue 0) and the other eigenvalues are
 * unchanged (A is block triangular in it). NULL on failure. */
static double *cut_cyclic(const ts_linear *lin)
{
    int n = lin->nstate;
    size_t nn = (size_t)n * (size_t)n;
    double *a = malloc(nn * sizeof(double));
    if (!a)
        return NULL;
    memcpy(a, lin->A, nn * sizeof(double));
    for (int k = 0; k < lin->nneutral; k++) {
        int j = lin->neutral[k].cyclic;
        if (j < 0)
            continue;
        for (int i = 0; i < n; i++) {
            a[i + (size_t)j * n] = 0.0;
            a[j + (size_t)i * n] = 0.0;
        }
    }
    return a;
}

/* The largest |A g - s g| / |g| over the generators gk[0..m) of s on
 * the sparse model (lin's, its cyclic states cut: lib/shift.c), A applied
 * through S_inf, O(nlinks) per generator; INFINITY on failure. */
static double generator_residual_sparse(const ts_linear *lin,
                                        double complex s, const int *gk,
                                        int m)
{
    int n = lin->nstate;
    tsi_shift acc;
    if (tsi_shift_factor_inf(&acc, lin, NULL) != TS_OK)
        return INFINITY;
    double *w = malloc(4 * (size_t)n * sizeof(double));
    if (!w) {
        tsi_shift_free(&acc);
        return INFINITY;
    }
    double *ar = w + 2 * (size_t)n, *ai = ar + n;
    double worst = 0;
    for (int r = 0; r < m; r++) {
        const double *gr = lin->neutral_re + (size_t)gk[r] * n;
        const double *gi = lin->neutral_im + (size_t)gk[r] * n;
        memcpy(w, gr, (size_t)n * sizeof(double));
        memcpy(w + n, gi, (size_t)n * sizeof(double));
        tsi_shift_apply(&acc, w, ar, 0);
        tsi_shift_apply(&acc, w + n, ai, 0);
        double g2 = 0, r2 = 0;
        for (int i = 0; i < n; i++) {
            double complex g = gr[i] + I * gi[i];
            double complex d = ar[i] + I * ai[i] - s * g;
            g2 += creal(g * conj(g));
            r2 += creal(d * conj(d));
        }
        if (g2 > 0)
            worst = fmax(worst, sqrt(r2 / g2));
    }
    free(w);
    tsi_shift_free(&acc);
    return worst;
}

/* max |A_ij| of the lower block (ts_linear.a_scale), or without the
 * dense A an estimate from the sparse model: the largest local band top
 * squared (zigzag_freq), the order of the largest entries of -M^-1 K. */
static double a_scale_of(const ts_linear *lin)
{
    if (isfinite(lin->a_scale) || !lin->desc)
        return lin->a_scale;
    const ts_descriptor *d = lin->desc;
    double w2 = 0;
    for (int k = 1; k < d->nn; k++) {
        double wt, wa;
        zigzag_freq(d, k, &wt, &wa);
        w2 = fmax(w2, fmax(wt * wt, wa * wa));
    }
    return w2;
}

/* The largest |A' g - s g| / |g| over the generators gk[0..m) of s, A'
 * the dense A with the cyclic states' rows and columns cut as the
 * eigensolvers see it (cut_cyclic), with `cleaned` also its entries below
 * their error zeroed as LAPACK sees it (clean_below_error); INFINITY
 * without the dense A. O(n^2) per generator: the dense path's cost, below
 * its eigensolver's. */
static double generator_residual(const ts_linear *lin, double complex s,
                                 const int *gk, int m, int cleaned)
{
    if (!lin->A && lin->desc)
        return generator_residual_sparse(lin, s, gk, m);
    if (!lin->A)
        return INFINITY;
    int n = lin->nstate;
    char *cut = calloc((size_t)n, 1);
    if (!cut)
        return INFINITY;
    for (int k = 0; k < lin->nneutral; k++)
        if (lin->neutral[k].cyclic >= 0)
            cut[lin->neutral[k].cyclic] = 1;
    double worst = 0;
    for (int r = 0; r < m; r++) {
        const double *gr = lin->neutral_re + (size_t)gk[r] * n;
        const double *gi = lin->neutral_im + (size_t)gk[r] * n;
        double g2 = 0, r2 = 0;
        for (int i = 0; i < n; i++)
            g2 += gr[i] * gr[i] + gi[i] * gi[i];
        for (int i = 0; i < n; i++) {
            double complex ag = 0;
            if (!cut[i])
                for (int j = 0; j < n; j++) {
                    double aij = lin->A[i + (size_t)j * n];
                    if (!cut[j] &&
                        !(cleaned && fabs(aij) < entry_error(lin, i, j)))
                        ag += aij * (gr[j] + I * gi[j]);
                }
            ag -= s * (gr[i] + I * gi[i]);
            r2 += creal(ag * conj(ag));
        }
        if (g2 > 0)
            worst = fmax(worst, sqrt(r2 / g2));
    }
    free(cut);
    return worst;
}

/* Mark the candidates that are lin's neutral modes: for each eigenvalue s
 * of the generators, the candidates within their bound of s (nearest
 * first, at most as many as its generators) whose vectors lie in the
 * generators' span within the allowance. */
static int recognise_neutral(const ts_linear *lin, cand_list *L,
                             int cleaned)
{
    int n = lin->nstate, ng = lin->nneutral;
    double dA = isfinite(lin->trunc_norm) ? lin->trunc_norm : 1e-6 * lin->a_norm;
    if (isfinite(lin->round_norm))
        dA += lin->round_norm;
    if (!isfinite(dA)) /* the sparse model: the residual alone */
        dA = INFINITY;
    double complex *q = malloc((size_t)n * (size_t)(ng > 0 ? ng : 1) *
                               sizeof *q);
    if (!q)
        return TS_ENOMEM;
    char *done = calloc((size_t)(ng > 0 ? ng : 1), 1);
    if (!done) {
        free(q);
        return TS_ENOMEM;
    }
    for (int k0 = 0; k0 < ng; k0++) {
        if (done[k0])
            continue;
        double complex s = lin->neutral[k0].re + I * lin->neutral[k0].im;
        /* The generators of s, orthonormalised (modified Gram-Schmidt). */
        int gk[TS_NEUTRAL_MAX], m = 0;
        for (int k = k0; k < ng; k++) {
            if (lin->neutral[k].re != creal(s) ||
                lin->neutral[k].im != cimag(s))
                continue;
            done[k] = 1;
            double complex *qk = q + (size_t)m * n;
            for (int i = 0; i < n; i++)
                qk[i] = lin->neutral_re[(size_t)k * n + i] +
                        I * lin->neutral_im[(size_t)k * n + i];
            for (int r = 0; r < m; r++) {
                double complex d = 0;
                for (int i = 0; i < n; i++)
                    d += conj(q[(size_t)r * n + i]) * qk[i];
                for (int i = 0; i < n; i++)
                    qk[i] -= d * q[(size_t)r * n + i];
            }
            double nr = 0;
            for (int i = 0; i < n; i++)
                nr += creal(qk[i] * conj(qk[i]));
            nr = sqrt(nr);
            if (!(nr > 0))
                continue;
            for (int i = 0; i < n; i++)
                qk[i] /= nr;
            gk[m++] = k;
        }
        /* Near s: within the bound (or rounding of A) of it. */
        double floor = 100.0 * DBL_EPSILON *
                       (isfinite(lin->a_norm) ? lin->a_norm : a_scale_of(lin));
        double gap = INFINITY;
        for (int c = 0; c < L->n; c++) {
            if (L->c[c].sweep >= 2) /* a repeat, dropped or superseded */
                continue;
            double b = ERROR_SAFETY * ((isfinite(L->c[c].dlam) ? L->c[c].dlam
                                                               : 0.0) +
                                       L->c[c].round);
            double d = cabs(L->c[c].lam - s);
            if (!(d <= fmax(b, floor)))
                gap = fmin(gap, d);
        }
        double res = generator_residual(lin, s, gk, m, cleaned);
        if (!(NEUTRAL_SAFETY * fmin(dA, res + floor) / gap <=
              NEUTRAL_ANGLE_MAX))
            continue;
        /* The modes first, one per generator; then the search's
         * eigenvalues (sweep 1), which may repeat them. */
        for (int taken = 0, pass = 0; pass < 2;) {
            int best = -1;
            double bd = INFINITY;
            for (int c = 0; c < L->n; c++) {
                cand *cc = &L->c[c];
                if (cc->sweep != pass)
                    continue;
                double b = ERROR_SAFETY * ((isfinite(cc->dlam) ? cc->dlam
                                                               : 0.0) +
                                           cc->round);
                double d = cabs(cc->lam - s);
                if (cc->neutral >= 0 || !(d <= fmax(b, floor)) || d >= bd)
                    continue;
                best = c;
                bd = d;
            }
            if (best < 0 || (pass == 0 && taken >= m)) {
                pass++;
                continue;
            }
            /* The angle to the span: |v - Q Q^H v| / |v|. */
            const double complex *v = cand_v(L, L->c[best].vec);
            double v2 = 0, p2 = 0;
            for (int i = 0; i < n; i++)
                v2 += creal(v[i] * conj(v[i]));
            for (int r = 0; r < m; r++) {
                double complex d = 0;
                for (int i = 0; i < n; i++)
                    d += conj(q[(size_t)r * n + i]) * v[i];
                p2 += creal(d * conj(d));
            }
            double sin_angle = sqrt(fmax(0.0, 1.0 - p2 / v2));
            /* The same dA moved the eigenvalue by bd: through its
             * condition number that can exceed |dA g|, and the vector
             * moves with it. */
            double tol = NEUTRAL_SAFETY * fmin(dA, fmax(res, bd) + floor) / gap;
            if (!(sin_angle <= tol && tol <= NEUTRAL_ANGLE_MAX)) {
                pass++;
                continue;
            }
            /* The generator it overlaps most, not yet taken by a mode
             * (any, for a repeat found by the search). */
            int kb = -1;
            double ob = -1;
            for (int r = 0; r < m; r++) {
                int used = 0;
                for (int c = 0; pass == 0 && c < L->n; c++)
                    used |= L->c[c].neutral == gk[r];
                if (used)
                    continue;
                double complex d = 0;
                double g2 = 0;
                for (int i = 0; i < n; i++) {
                    double complex g = lin->neutral_re[(size_t)gk[r] * n + i] +
                                       I * lin->neutral_im[(size_t)gk[r] * n +
                                                           i];
                    d += conj(g) * v[i];
                    g2 += creal(g * conj(g));
                }
                double o = creal(d * conj(d)) / g2;
                if (o > ob) {
                    ob = o;
                    kb = gk[r];
                }
            }
            L->c[best].neutral = kb;
            L->c[best].verr = sin_angle;
            taken++;
        }
    }
    free(q);
    free(done);
    return TS_OK;
}

/* The bounds of L's recognised neutral modes on the sparse model: dlam
 * = |dA v| / |v| (the error estimate applied through S_inf), round and
 * ritz the residual |A v - lam v| / |v|, A the cut one. */
static int neutral_bounds(const ts_linear *lin, cand_list *L, ts_err *err)
{
    int n = lin->nstate, any = 0;
    for (int c = 0; c < L->n; c++)
        any |= L->c[c].neutral >= 0;
    if (!any)
        return TS_OK;
    tsi_shift acc;
    int rc = tsi_shift_factor_inf(&acc, lin, err);
    if (rc != TS_OK)
        return rc;
    double *w = malloc(4 * (size_t)n * sizeof(double));
    if (!w) {
        tsi_shift_free(&acc);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    double *vr = w, *vi = w + n, *ar = w + 2 * n, *ai = w + 3 * n;
    int with_err = lin->desc_err == lin->desc_err; /* not NaN */
    for (int c = 0; c < L->n; c++) {
        cand *cc = &L->c[c];
        if (cc->neutral < 0)
            continue;
        const double complex *v = cand_v(L, cc->vec);
        for (int i = 0; i < n; i++) {
            vr[i] = creal(v[i]);
            vi[i] = cimag(v[i]);
        }
        tsi_shift_apply(&acc, vr, ar, 0);
        tsi_shift_apply(&acc, vi, ai, 0);
        double v2 = set_residual(cc, v, ar, ai, n);
        cc->ritz = cc->round;
        if (with_err) {
            tsi_shift_apply(&acc, vr, ar, 1);
            tsi_shift_apply(&acc, vi, ai, 1);
            double e2 = 0;
            for (int i = 0; i < n; i++)
                e2 += ar[i] * ar[i] + ai[i] * ai[i];
            cc->dlam = sqrt(e2 / v2);
        }
    }
    free(w);
    tsi_shift_free(&acc);
    return TS_OK;
}

/* ---- Driver -------------------------------------------------------------- */

static int eigen_solve(const ts_linear *lin, const ts_descriptor *bands,
                       const ts_eigen_opts *opts, ts_eigen **out,
                       ts_err *err);

int ts_eigen_solve(const ts_linear *lin, const ts_eigen_opts *opts,
                   ts_eigen **out, ts_err *err)
{
    ts_eigen_opts o;
    if (opts)
        o = *opts;
    else
        ts_eigen_opts_default(&o);
    /* The sparse model's band tops set the rightmost search's shifts. */
    const ts_descriptor *bands = lin->desc;
    int ncyclic = 0, comps[2];
    for (int k = 0; k < lin->nneutral; k++)
        if (lin->neutral[k].cyclic >= 0 && ncyclic < 2)
            comps[ncyclic++] = lin->neutral[k].cyclic - lin->root_qoff;
    int n = lin->nstate;
    ts_eig_method m = ts_eigen_method(n, &o);
    if (o.method == TS_EIG_AUTO && m == TS_EIG_LAPACK && !lin->A &&
        o.count > 0)
        m = TS_EIG_ARPACK;
    if (lin->root_qoff >= 0 && lin->desc && m == TS_EIG_ARPACK) {
        /* A towing vehicle on the sparse model (doc/linear.md section
         * 3a): its cyclic states cut in a copy of the model, their
         * translations exact null vectors of its K; the shift-invert
         * operator and A's action then act with the cut A (lib/shift.c). */
        if (ncyclic == 0)
            return eigen_solve(lin, bands, &o, out, err);
        *out = NULL;
        ts_descriptor dc;
        if (tsi_desc_cut(lin->desc, lin->root_qoff, comps, ncyclic, &dc) !=
            TS_OK)
            return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        ts_linear cut = *lin;
        cut.desc = &dc;
        int rc = eigen_solve(&cut, &dc, &o, out, err);
        tsi_desc_cut_free(&dc);
        return rc;
    }
    ts_linear dense;
    if (lin->root_qoff >= 0 && lin->desc && lin->A) {
        /* LAPACK (or ARPACK without the sparse model) on the dense A,
         * where the neutral modes are cut as below. */
        dense = *lin;
        dense.desc = NULL;
        dense.desc_err = dense.desc_round = NAN;
        lin = &dense;
    }
    if (ncyclic == 0 || !lin->A)
        return eigen_solve(lin, bands, &o, out, err);
    /* The cyclic states' integrator chains cut (cut_cyclic): the same
     * eigenvalues, each neutral mode a simple eigenvector. */
    *out = NULL;
    ts_linear cut = *lin;
    cut.A = cut_cyclic(lin);
    if (!cut.A)
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    int rc = eigen_solve(&cut, bands, &o, out, err);
    free(cut.A);
    return rc;
}

/* The highest frequency (rad/s) among L's candidates: the modes, before
 * the search adds to L. */
static double modes_top(const cand_list *L)
{
    double w = 0;
    for (int i = 0; i < L->n; i++)
        w = fmax(w, cimag(L->c[i].lam));
    return w;
}

/* rightmost_search's get_wlo for a search after the modes: a value. */
static double wlo_given(void *ctx) { return *(const double *)ctx; }

/* This thread's number and its team's size (0 and 1 without OpenMP). */
static void thread_ids(int *t, int *team)
{
    *t = 0;
    *team = 1;
#ifdef _OPENMP
    *t = omp_get_thread_num();
    *team = omp_get_num_threads();
#endif
}

/* The rightmost search (thread 0) beside the checks of the modes, the
 * `count` candidates of L nearest the target (another thread), on the
 * linearization's threads: the checks read copies of the modes (the
 * search grows L, which moves it), and their results are copied back.
 * L is first sorted by distance to the target, as eigen_solve sorts it
 * after the search (the search only appends). acc is factored here and
 * es holds the checks' factors for the search's checks after them: the
 * same sequence of factorisations as the search then the checks, so the
 * results are the same, bit for bit, on one thread (where the checks run
 * first) or two. *checked is set when the modes were checked. */
static int search_beside_checks(const ts_linear *lin,
                                const ts_descriptor *bands,
                                const ts_eigen_opts *o, ts_eigen *e,
                                cand_list *L, tsi_shift *acc, tsi_shift *es,
                                int *checked, ts_err *err)
{
    *checked = 0;
    double complex sigma = I * 2.0 * M_PI * o->target_hz;
    for (int i = 0; i < L->n; i++)
        L->c[i].dist = cabs(L->c[i].lam - sigma);
    qsort(L->c, (size_t)L->n, sizeof(cand), cmp_dist);
    int keep = o->count < L->n ? o->count : L->n;
    double wlo = modes_top(L);
    if (keep < o->count) /* eigen_solve says so after the search */
        return rightmost_search(lin, bands, o, e, L, wlo_given, &wlo, NULL,
                                err);
    int n = L->nstate, rc = tsi_shift_factor_inf(acc, lin, err);
    if (rc != TS_OK)
        return rc;
    cand_list M = {0};
    if (cand_init(&M, keep, n) != TS_OK) {
        cand_free(&M);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    for (int i = 0; i < keep; i++) {
        M.c[i] = L->c[i];
        M.c[i].vec = i;
        M.c[i].checked = 0;
        memcpy(M.v + (size_t)i * n, cand_v(L, L->c[i].vec),
               (size_t)n * sizeof(double complex));
    }
    M.n = keep;
    int nt = lin->threads > 1 ? 2 : 1, rs = TS_OK, rk = TS_OK;
    ts_err ek = {0};
#ifdef _OPENMP
#pragma omp parallel num_threads(nt)
#endif
    {
        int t, team;
        thread_ids(&t, &team);
        if (t == (team > 1 ? 1 : 0))
            rk = batch_checks(lin, acc, es, &M, &ek);
        if (t == 0)
            rs = rightmost_search(lin, bands, o, e, L, wlo_given, &wlo,
                                  NULL, err);
    }
    if (rs == TS_OK && rk != TS_OK) {
        rs = rk;
        if (err)
            *err = ek;
    }
    for (int i = 0; rs == TS_OK && i < keep; i++) {
        int vec = L->c[i].vec;
        L->c[i] = M.c[i];
        L->c[i].vec = vec;
    }
    cand_free(&M);
    *checked = rs == TS_OK;
    return rs;
}

/* What the modes' run (modes_and_search) shares with the search beside
 * it: its state (0 running, 1 done, -1 failed), the highest frequency
 * among its modes, whether the caller asked it to stop (user_stop) and
 * whether the search failed (stop: the modes' run then stops too). The
 * caller's progress is called by one thread at a time: the modes' run
 * while it goes (its operator applications, as "eigensolve"), the search
 * once it is done (its shifts). */
typedef struct modes_share {
    atomic_int state;
    double wlo;
    atomic_int user_stop;
    atomic_int stop;
    const ts_eigen_opts *o; /* the caller's progress */
} modes_share;

/* The modes' run's poll: the caller's progress, and the search's
 * failure. */
static int modes_poll(const ts_progress *p, void *data)
{
    modes_share *m = data;
    if (m->o->progress && m->o->progress(p, m->o->progress_data)) {
        atomic_store(&m->user_stop, 1);
        return 1;
    }
    return atomic_load(&m->stop);
}

/* The search's poll: a stop the caller asked of the modes' run; while
 * that goes, nothing more; after, the caller's progress. */
static int search_poll(const ts_progress *p, void *data)
{
    modes_share *m = data;
    if (atomic_load(&m->user_stop))
        return 1;
    if (atomic_load(&m->state) == 0)
        return 0;
    return m->o->progress ? m->o->progress(p, m->o->progress_data) : 0;
}

/* rightmost_search's get_wlo beside the modes' run: waits for it (which
 * polls the caller meanwhile); NaN when it failed or was stopped. */
static double share_wlo(void *ctx)
{
    modes_share *m = ctx;
    int state;
    while (!(state = atomic_load(&m->state))) {
        struct timespec ts = {0, 50000};
        nanosleep(&ts, NULL);
    }
    return state > 0 ? m->wlo : NAN;
}

/* The rightmost of the search (L's candidates from `from` on), checked
 * one by one until SWEEP_CHECKED stand: a Ritz pair whose own error shows
 * it has not converged (a run stopped at its restart limit in a cluster)
 * is no eigenvalue and is dropped (sweep 3, counted in *rejected). Those
 * to check have checked -1. acc and es as for batch_checks (the sparse
 * model; dense_checks without it). */
static int check_rightmost(const ts_linear *lin, cand_list *L, int from,
                           tsi_shift *acc, tsi_shift *es, int *rejected,
                           ts_err *err)
{
    int rc = TS_OK;
    for (int t = 0; rc == TS_OK && t < SWEEP_CHECKED;) {
        int best = -1;
        for (int i = from; i < L->n; i++)
            if (L->c[i].sweep == 1 && L->c[i].checked == -1 &&
                (best < 0 || creal(L->c[i].lam) > creal(L->c[best].lam)))
                best = i;
        if (best < 0)
            break;
        L->c[best].checked = 0;
        rc = lin->desc ? batch_checks(lin, acc, es, L, err)
                       : dense_checks(lin, L, err);
        double scale = cabs(L->c[best].lam) +
                       (lin->desc ? 0.0 : lin->a_scale);
        if (L->c[best].ritz > SWEEP_RESIDUAL * scale) {
            L->c[best].sweep = 3;
            (*rejected)++;
        } else {
            t++;
        }
    }
    return rc;
}

/* Mark the search's candidates S that repeat one of the modes L (the
 * same eigenpair: same_pair) as repeats (sweep 2). */
static void mark_repeats(cand_list *S, const cand_list *L)
{
    for (int i = 0; i < S->n; i++) {
        cand *a = &S->c[i];
        for (int j = 0; j < L->n && a->sweep == 1; j++)
            if (same_pair(S, a, L, &L->c[j]))
                a->sweep = 2;
    }
}

/* Append the search's candidates S (their repeats marked: mark_repeats)
 * to L, taking over S's vector store (L's second, S's emptied: no
 * copy). */
static int merge_search(cand_list *L, cand_list *S)
{
    cand *c = realloc(L->c, (size_t)(L->n + S->n + 1) * sizeof(cand));
    if (!c)
        return TS_ENOMEM;
    L->c = c;
    L->v2 = S->v;
    S->v = NULL;
    for (int i = 0; i < S->n; i++) {
        cand *a = &L->c[L->n++];
        *a = S->c[i];
        a->vec = -1 - S->c[i].vec;
    }
    /* L->v holds the first columns only: no more candidates after. */
    L->cap = L->n;
    return TS_OK;
}

/* The modes nearest 0 Hz (one real ARPACK run, solve_arpack_real at
 * sigma) and the rightmost search at once on the linearization's threads:
 * the search (thread 0) runs the band tops and the grid's top points
 * while the modes' run (another thread) goes, then the rest of the grid
 * once the modes' highest frequency is known (share_wlo), while the
 * modes' residuals and error estimates are computed (the `count` nearest
 * 0 Hz); then the search's SWEEP_CHECKED rightmost are checked
 * (check_rightmost, in shifts of the search's own), beside the modes'
 * checks still. The search fills a list of its own, merged into L after;
 * the two runs are of ARPACK's two families (real and complex), which may
 * run at once (solve_arpack_real). On one thread: the modes' run, their
 * checks, the search, its checks, in that order, with the same results
 * bit for bit (each ARPACK run starts from a fixed vector and factors
 * afresh, each list's checks have shifts of their own, and the search
 * reads of the modes only their eigenvalues and vectors, once their run
 * is done, to mark its repeats). acc and es as for search_beside_checks;
 * *checked is set when the modes were checked, *search_checked when the
 * search's rightmost were. */
static int modes_and_search(const ts_linear *lin, const ts_descriptor *bands,
                            const ts_eigen_opts *o, double sigma,
                            ts_eigen *e, cand_list *L, tsi_shift *acc,
                            tsi_shift *es, int *checked, int *search_checked,
                            ts_err *err)
{
    *checked = *search_checked = 0;
    tsi_shift sacc = {0}, ses = {0}; /* the search's checks' */
    int n = lin->nstate;
    cand_list S = {0};
    if (cand_init(&S, 1, n) != TS_OK) {
        cand_free(&S);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    /* The search's statistics apart from the modes' run's. */
    ts_eigen se;
    memset(&se, 0, sizeof se);
    modes_share share;
    atomic_init(&share.state, 0);
    atomic_init(&share.user_stop, 0);
    atomic_init(&share.stop, 0);
    share.wlo = NAN;
    share.o = o;
    int nt = lin->threads > 1 ? 2 : 1, rr = TS_OK, rs = TS_OK, rk = TS_OK;
    int keep = 0;
    ts_err er = {0}, ek = {0};
    ts_eigen_opts ro = *o, so = *o;
    ro.progress = modes_poll;
    ro.progress_data = &share;
    so.progress = search_poll;
    so.progress_data = &share;
#ifdef _OPENMP
#pragma omp parallel num_threads(nt)
#endif
    {
        int t, team;
        thread_ids(&t, &team);
        if (t == (team > 1 ? 1 : 0)) {
            rr = solve_arpack_real(lin, &ro, sigma, e, L, es, &er);
            if (rr == TS_OK) {
                share.wlo = modes_top(L);
                double complex target = I * 2.0 * M_PI * o->target_hz;
                for (int i = 0; i < L->n; i++)
                    L->c[i].dist = cabs(L->c[i].lam - target);
                qsort(L->c, (size_t)L->n, sizeof(cand), cmp_dist);
                keep = o->count < L->n ? o->count : L->n;
            }
            atomic_store(&share.state, rr == TS_OK ? 1 : -1);
            if (rr == TS_OK && keep == o->count) {
                for (int i = 0; i < L->n; i++)
                    L->c[i].checked = i < keep ? 0 : -1;
                rk = tsi_shift_factor_inf(acc, lin, &ek);
                if (rk == TS_OK)
                    rk = batch_checks(lin, acc, es, L, &ek);
            }
        }
        if (t == 0) {
            rs = rightmost_search(lin, bands, &so, &se, &S, share_wlo,
                                  &share, &ses, err);
            /* Its rightmost checked here, in shifts of its own, while the
             * modes' checks go on: the modes are known once the search is
             * done (it waited for them), and only their eigenvalues and
             * vectors are read, which the checks leave. The checks' first
             * S(lambda) refactors the search's last shift (ses, taken
             * over from the search), judged as each next one is. */
            if (rs == TS_OK) {
                mark_repeats(&S, L);
                for (int i = 0; i < S.n; i++)
                    S.c[i].checked = -1;
                rs = tsi_shift_factor_inf(&sacc, lin, err);
                if (rs == TS_OK)
                    rs = check_rightmost(lin, &S, 0, &sacc, &ses,
                                         &se.sweep_rejected, err);
                *search_checked = rs == TS_OK;
            }
            /* A failure of its own (not a stop the caller asked for in
             * the modes' run) stops the modes' run too. */
            if (rs != TS_OK && !atomic_load(&share.user_stop))
                atomic_store(&share.stop, 1);
        }
    }
    tsi_shift_free(&sacc);
    tsi_shift_free(&ses);
    int rc = TS_OK;
    if (rr != TS_OK && !(rr == TS_ECANCEL && atomic_load(&share.stop))) {
        /* The modes' run failed, or the caller stopped it. */
        rc = rr;
        if (err)
            *err = er;
    } else if (rs != TS_OK) {
        rc = rs;
    } else if (rk != TS_OK) {
        rc = rk;
        if (err)
            *err = ek;
    }
    e->top_hz = se.top_hz;
    e->sweep_failed += se.sweep_failed;
    e->sweep_rejected += se.sweep_rejected;
    e->sweep_shifts = se.sweep_shifts;
    e->arpack_iterations += se.arpack_iterations;
    e->arpack_ops += se.arpack_ops;
    e->arpack_nconv += se.arpack_nconv;
    if (rc == TS_OK && merge_search(L, &S) != TS_OK)
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    cand_free(&S);
    *checked = rc == TS_OK && keep == o->count;
    return rc;
}

static int eigen_solve(const ts_linear *lin, const ts_descriptor *bands,
                       const ts_eigen_opts *opts, ts_eigen **out,
                       ts_err *err)
{
    ts_eigen_opts o;
    if (opts)
        o = *opts;
    else
        ts_eigen_opts_default(&o);
    *out = NULL;
    int n = lin->nstate;
    int rc = ts_eigen_check(n, &o, err);
    if (rc != TS_OK)
        return rc;
    ts_eig_method m = ts_eigen_method(n, &o);
    /* Without the dense A (a large system) the modes come from ARPACK on
     * the sparse model. */
    if (o.method == TS_EIG_AUTO && m == TS_EIG_LAPACK && !lin->A &&
        o.count > 0)
        m = TS_EIG_ARPACK;
    if (m == TS_EIG_LAPACK && !lin->A)
        return ts_fail(err, TS_EINVAL,
                       "eigen: method lapack needs the dense A of %d states "
                       "(%.3g MB; linearize with model TS_LIN_DENSE or "
                       "BOTH), or ask for a number of modes for the sparse "
                       "method",
                       n, 8e-6 * (double)n * (double)n);
    if (m == TS_EIG_ARPACK && !lin->desc && !lin->A)
        return ts_fail(err, TS_EINVAL,
                       "eigen: method arpack needs a linear model (sparse "
                       "or dense)");
    ts_eigen *e = calloc(1, sizeof *e);
    if (!e)
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    e->nstate = n;
    e->method = m;
    e->target_hz = o.target_hz;
    cand_list L = {0};
    /* The modes nearest 0 Hz with the sparse model: their run beside the
     * rightmost search (modes_and_search, below). */
    int together = m == TS_EIG_ARPACK && o.rightmost && bands && lin->desc &&
                   o.target_hz == 0.0;
    /* (Each ARPACK run is a critical section: solve_arpack_real.)
     * Neutral modes at 0 make A singular there: shift just off it. */
    double sigma0 = 0.0;
    for (int k = 0; k < lin->nneutral; k++)
        if (lin->neutral[k].re == 0.0 && lin->neutral[k].im == 0.0)
            sigma0 = -NEUTRAL_SHIFT_REL * a_scale_of(lin);
    if (m == TS_EIG_LAPACK)
        rc = solve_lapack(lin, &L, err);
    else if (together)
        rc = TS_OK; /* modes_and_search fills L */
    else
        rc = o.target_hz == 0.0
                 ? solve_arpack_real(lin, &o, sigma0, e, &L, NULL, err)
                 : solve_arpack_complex(lin, &o, e, &L, err);
    if (rc != TS_OK) {
        cand_free(&L);
        ts_eigen_free(e);
        return rc;
    }

    e->top_hz = NAN;
    /* With the sparse model the modes' checks (their residuals and error
     * estimates) run beside the rightmost search (search_beside_checks);
     * es and acc then carry on to the search's own checks below. */
    tsi_shift acc = {0}, es = {0};
    int modes_checked = 0, search_checked = 0;
    if (together) {
        rc = modes_and_search(lin, bands, &o, sigma0, e, &L, &acc, &es,
                              &modes_checked, &search_checked, err);
    } else if (m == TS_EIG_ARPACK && o.rightmost && bands && lin->desc) {
        rc = search_beside_checks(lin, bands, &o, e, &L, &acc, &es,
                                  &modes_checked, err);
    } else if (m == TS_EIG_ARPACK && o.rightmost && bands) {
        double wlo = modes_top(&L);
        rc = rightmost_search(lin, bands, &o, e, &L, wlo_given, &wlo, NULL,
                              err);
    }
    if (rc != TS_OK) {
        if (acc.numeric || acc.lu || acc.zlu)
            tsi_shift_free(&acc);
        tsi_shift_free(&es);
        cand_free(&L);
        ts_eigen_free(e);
        return rc;
    }

    /* The modes: the `count` nearest sigma among those found for them
     * (the search's are found elsewhere). */
    double complex sigma = I * 2.0 * M_PI * o.target_hz;
    for (int i = 0; i < L.n; i++)
        L.c[i].dist = L.c[i].sweep ? INFINITY : cabs(L.c[i].lam - sigma);
    qsort(L.c, (size_t)L.n, sizeof(cand), cmp_dist);
    int keep = 0;
    while (keep < L.n && !L.c[keep].sweep)
        keep++;
    if (o.count > 0 && o.count < keep)
        keep = o.count;
    if (m == TS_EIG_ARPACK && keep < o.count) {
        rc = ts_fail(err, TS_ECONV,
                     "eigen: ARPACK converged on %d of the %d modes asked "
                     "for",
                     keep, o.count);
        cand_free(&L);
        ts_eigen_free(e);
        return rc;
    }
    /* What the verdict covers: with LAPACK every eigenvalue (all have
     * bounds), with ARPACK the modes and the SWEEP_CHECKED rightmost of
     * the search, whose residuals and error estimates are computed here
     * (O(nlinks) each; the other eigenvalues it found lie further left). */
    int *cover = malloc((size_t)(L.n > 0 ? L.n : 1) * sizeof(int));
    if (!cover) {
        cand_free(&L);
        ts_eigen_free(e);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    int ncover = 0;
    if (m == TS_EIG_LAPACK) {
        for (int i = 0; i < L.n; i++)
            cover[ncover++] = i;
    } else {
        /* The modes checked or to check, the others not (the search's
         * own kept as they are when it checked them itself). */
        for (int i = 0; i < L.n; i++) {
            if (i < keep)
                L.c[i].checked = modes_checked;
            else if (!(search_checked && L.c[i].sweep))
                L.c[i].checked = -1;
        }
        if (modes_checked) {
            /* Done beside the search. */
        } else if (lin->desc) {
            rc = tsi_shift_factor_inf(&acc, lin, err);
            if (rc == TS_OK)
                rc = batch_checks(lin, &acc, &es, &L, err);
        } else {
            rc = dense_checks(lin, &L, err);
        }
        if (rc == TS_OK && !search_checked)
            rc = check_rightmost(lin, &L, keep, &acc, &es,
                                 &e->sweep_rejected, err);
        if (acc.numeric || acc.lu || acc.zlu)
            tsi_shift_free(&acc);
        tsi_shift_free(&es);
        for (int i = 0; i < L.n; i++)
            if (L.c[i].checked == 1 && L.c[i].sweep != 3)
                cover[ncover++] = i;
        if (rc != TS_OK) {
            free(cover);
            cand_free(&L);
            ts_eigen_free(e);
            return rc;
        }
        /* ARPACK gives no separation estimate: the eigenvector allowance
         * is the eigenvalue's first-order change (plus rounding) over the
         * distance to the nearest other computed eigenvalue, its own
         * conjugate included (exact to first order for a normal matrix;
         * at the edge of the computed subset an uncomputed neighbour may
         * be nearer). */
        for (int q = 0; q < ncover; q++) {
            int i = cover[q];
            double complex li = L.c[i].lam;
            double gap = cimag(li) > 0 ? 2.0 * cimag(li) : INFINITY;
            for (int k = 0; k < L.n; k++) {
                if (k == i || L.c[k].sweep == 2)
                    continue;
                double complex lk = L.c[k].lam;
                gap = fmin(gap, fmin(cabs(li - lk), cabs(li - conj(lk))));
            }
            double dl = isfinite(L.c[i].dlam) ? L.c[i].dlam : 0.0;
            L.c[i].verr = gap > 0 ? ERROR_SAFETY * (dl + L.c[i].round) / gap
                                  : INFINITY;
        }
        for (int i = keep; i < L.n; i++)
            e->sweep_found += L.c[i].sweep == 1 ? (cimag(L.c[i].lam) > 0 ? 2
                                                                       : 1)
                                                : 0;
    }

    /* A towing vehicle's neutral modes: recognised, and left out of the
     * verdict (doc/linear.md section 3a). */
    if (lin->nneutral > 0 &&
        recognise_neutral(lin, &L, m == TS_EIG_LAPACK) != TS_OK) {
        free(cover);
        cand_free(&L);
        ts_eigen_free(e);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }

    /* On the sparse model a neutral mode's pencil estimate is that of
     * the whole model, where the cut states' chains make 0 a multiple,
     * defective eigenvalue (lib/shift.c keeps the pencil whole): its
     * bound is the one without a left vector instead, the error
     * estimate's ||dA v|| / |v| and the residual, A the cut one. */
    if (lin->desc && lin->nneutral > 0 && m == TS_EIG_ARPACK &&
        neutral_bounds(lin, &L, err) != TS_OK) {
        free(cover);
        cand_free(&L);
        ts_eigen_free(e);
        return TS_ENOMEM;
    }
    /* Verdict and the rightmost eigenvalue over what is covered. */
    e->max_real = -INFINITY;
    e->max_real_error = 0.0;
    int any_unstable = 0, all_stable = 1, right = -1;
    double reach = -INFINITY; /* the largest Re + bound */
    e->undecided_real = e->undecided_error = NAN;
    for (int q = 0; q < ncover; q++) {
        const cand *c = &L.c[cover[q]];
        if (c->neutral >= 0)
            continue;
        double re = creal(c->lam);
        double bound = ERROR_SAFETY * ((isfinite(c->dlam) ? c->dlam : 0.0) +
                                       c->round);
        if (re > e->max_real) {
            e->max_real = re;
            e->max_real_error = bound;
            right = cover[q];
        }
        if (re - bound > 0)
            any_unstable = 1;
        if (!(re + bound < 0))
            all_stable = 0;
        if (re + bound > reach) {
            reach = re + bound;
            e->undecided_real = re;
            e->undecided_error = bound;
        }
    }
    free(cover);
    if (right >= 0)
        fill_mode(&e->rightmost, &L.c[right]);
    e->verdict = any_unstable ? TS_UNSTABLE
                              : (all_stable && right >= 0 ? TS_STABLE
                                                          : TS_MARGINAL);
    if (e->verdict != TS_MARGINAL)
        e->undecided_real = e->undecided_error = NAN;

    qsort(L.c, (size_t)keep, sizeof(cand), cmp_freq);
    e->nmodes = keep;
    e->modes = calloc((size_t)(keep > 0 ? keep : 1), sizeof(ts_mode));
    if (o.vectors) {
        e->vec_re = malloc((size_t)n * (size_t)(keep > 0 ? keep : 1) *
                           sizeof(double));
        e->vec_im = malloc((size_t)n * (size_t)(keep > 0 ? keep : 1) *
                           sizeof(double));
    }
    if (!e->modes || (o.vectors && (!e->vec_re || !e->vec_im))) {
        cand_free(&L);
        ts_eigen_free(e);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    e->neig = 0;
    e->nneutral = 0;
    double complex *gv = lin->nneutral > 0 && o.vectors
                             ? malloc((size_t)n * sizeof *gv)
                             : NULL;
    if (lin->nneutral > 0 && o.vectors && !gv) {
        cand_free(&L);
        ts_eigen_free(e);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    }
    for (int i = 0; i < keep; i++) {
        cand *c = &L.c[i];
        fill_mode(&e->modes[i], c);
        e->modes[i].neutral = c->neutral;
        e->neig += cimag(c->lam) > 0 ? 2 : 1;
        if (c->neutral >= 0) {
            /* Its eigenvalue and shape are the symmetry's, exactly; the
             * computed ones lie within their allowances of them. */
            const ts_neutral *nm = &lin->neutral[c->neutral];
            double bound = e->modes[i].error_bound;
            double verr = e->modes[i].vector_error;
            cand exact = *c;
            exact.lam = nm->re + I * nm->im;
            fill_mode(&e->modes[i], &exact);
            e->modes[i].error_bound = bound;
            e->modes[i].vector_error = verr;
            e->modes[i].neutral = c->neutral;
            e->nneutral++;
        }
        if (o.vectors) {
            const double complex *v = cand_v(&L, c->vec);
            if (c->neutral >= 0) {
                for (int k = 0; k < n; k++)
                    gv[k] = lin->neutral_re[(size_t)c->neutral * n + k] +
                            I * lin->neutral_im[(size_t)c->neutral * n + k];
                v = gv;
            } else {
                /* A cyclic state is the integral of its rate: its entry of
                 * the eigenvector of A is the rate's over lambda. */
                double complex *vw = cand_v(&L, c->vec);
                for (int k = 0; k < lin->nneutral; k++) {
                    int j = lin->neutral[k].cyclic;
                    if (j >= 0 && cabs(c->lam) > 0)
                        vw[j] = vw[lin->nq + j] / c->lam;
                }
            }
            /* Unit 2-norm, largest entry real and positive. */
            double nrm = 0, big = -1;
            int ib = 0;
            for (int k = 0; k < n; k++) {
                double a = cabs(v[k]);
                nrm += a * a;
                if (a > big) {
                    big = a;
                    ib = k;
                }
            }
            double complex rot = conj(v[ib]) / (cabs(v[ib]) * sqrt(nrm));
            for (int k = 0; k < n; k++) {
                double complex w = v[k] * rot;
                e->vec_re[(size_t)i * n + k] = creal(w);
                e->vec_im[(size_t)i * n + k] = cimag(w);
            }
        }
    }
    /* Complete: the verdict covers every eigenvalue (the neutral modes
     * recognised and set apart). */
    e->complete = m == TS_EIG_LAPACK;
    free(gv);
    cand_free(&L);
    *out = e;
    return TS_OK;
}

/* ---- Mode shapes --------------------------------------------------------- */

/* Complex node displacements dr[3 nnodes] of mode m. */
static void node_shape(const ts_system *sys, const ts_linear *lin,
                       const ts_eigen *e, int m, double *dq, double *rre,
                       double *rim)
{
    int n = e->nstate, nq = lin->nq;
    memcpy(dq, e->vec_re + (size_t)m * n, (size_t)nq * sizeof(double));
    ts_linear_node_displacements(sys, lin, dq, rre);
    memcpy(dq, e->vec_im + (size_t)m * n, (size_t)nq * sizeof(double));
    ts_linear_node_displacements(sys, lin, dq, rim);
}

int ts_eigen_mode_shape(const ts_system *sys, const ts_linear *lin,
                        const ts_eigen *e, int m, double amp[], double phase[],
                        ts_err *err)
{
    if (!e->vec_re || m < 0 || m >= e->nmodes)
        return ts_fail(err, TS_EINVAL,
                       "mode shape: mode %d of %d %s", m, e->nmodes,
                       e->vec_re ? "does not exist" : "(no eigenvectors kept)");
    int nn = sys->nnodes, nq = lin->nq;
    double *dq = malloc((size_t)nq * sizeof(double));
    double *rre = malloc(3 * (size_t)nn * sizeof(double));
    double *rim = malloc(3 * (size_t)nn * sizeof(double));
    if (!dq || !rre || !rim) {
        free(dq);
        free(rre);
        free(rim);
        return ts_fail(err, TS_ENOMEM, "mode shape: out of memory");
    }
    node_shape(sys, lin, e, m, dq, rre, rim);
    double big = -1;
    int ib = 0;
    for (int i = 0; i < 3 * nn; i++) {
        double a = hypot(rre[i], rim[i]);
        if (a > big) {
            big = a;
            ib = i;
        }
    }
    double complex ref = big > 0 ? rre[ib] + I * rim[ib] : 1.0;
    for (int i = 0; i < 3 * nn; i++) {
        double complex w = (rre[i] + I * rim[i]) / ref;
        amp[i] = cabs(w);
        phase[i] = amp[i] > 0 ? carg(w) : 0.0;
    }
    free(dq);
    free(rre);
    free(rim);
    return TS_OK;
}

/* A mode is the towing vehicle's when the vehicle carries more than this
 * share of its kinetic energy. */
#define VEHICLE_MODE_SHARE 0.5
/* Within the vehicle, a second degree of freedom with at least this share
 * of the vehicle's energy is named beside the first ("sway/yaw"). */
#define VEHICLE_DOF_SECOND 0.25

/* The towing vehicle's label of mode m ("vehicle 'dolphin': heave/pitch,
 * 87% of the kinetic energy") into buf when the vehicle carries most of
 * the mode's kinetic energy; 0 otherwise. The energy of the mode's
 * velocity part: the vehicle's m |r_A'|^2 + omega^T I omega (omega = R E
 * theta', its degrees of freedom along M's axes, the body's within its
 * trim angles; the inertia's diagonal; added mass left out) against each
 * node's lumped mass, a towed vehicle's mass included, times its speed
 * squared (ts_linear_node_displacements on the rates). */
static int vehicle_label(const ts_system *sys, const ts_linear *lin,
                         const ts_eigen *e, int m, char *buf, size_t size)
{
    int ro = lin->root_qoff;
    if (ro < 0 || sys->tow.vehicle < 0 || !lin->up_map)
        return 0;
    const ts_body *tb = &sys->bodies[sys->tow.vehicle];
    const double *RE = NULL;
    for (int l = 0; l < sys->nlinks && !RE; l++)
        if (sys->links[l].up_body == sys->tow.vehicle)
            RE = lin->up_map + 12 * l;
    if (!RE || !tb->vehicle)
        return 0;
    int n = lin->nstate, nq = lin->nq, nn = sys->nnodes;
    int ship = sys->tow.dof == 3;
    const double *vr = e->vec_re + (size_t)m * n, *vi = e->vec_im +
                                                        (size_t)m * n;
    double *dq = malloc(2 * (size_t)nq * sizeof(double));
    double *dr = malloc(6 * (size_t)nn * sizeof(double));
    if (!dq || !dr) {
        free(dq);
        free(dr);
        return 0;
    }
    /* Velocities: the rate half of the eigenvector, real and imaginary
     * parts apart (the energy is their sum). */
    double dof[6] = {0}, cable = 0;
    for (int part = 0; part < 2; part++) {
        const double *v = part ? vi : vr;
        memcpy(dq + (size_t)part * nq, v + nq, (size_t)nq * sizeof(double));
        ts_linear_node_displacements(sys, lin, dq + (size_t)part * nq,
                                     dr + 3 * (size_t)part * nn);
        const double *qd = v + nq;
        for (int c = 0; c < 3; c++) {
            /* omega = R E theta' (a surface ship: its yaw rate alone,
             * about z; its depth held). */
            double w = 0;
            if (ship)
                w = c == 2 ? qd[ro - 1] : 0.0;
            else
                for (int j = 0; j < 3; j++)
                    w += RE[3 * c + j] * qd[ro - 3 + j];
            double u = ship && c == 2 ? 0.0 : qd[ro + c];
            dof[c] += tb->mass * u * u;
            dof[3 + c] += tb->vehicle->inertia[c] * w * w;
        }
        /* Node 0 is the tow point, part of the vehicle; a towed
         * vehicle's own mass is not its node's (system.h): added, moving
         * with its attach point. */
        for (int k = 1; k < nn; k++) {
            const double *d = dr + 3 * ((size_t)part * nn + k);
            int bk = sys->nodes[k].body;
            double mk = sys->nodes[k].mass +
                        (bk >= 0 && sys->bodies[bk].vehicle
                             ? sys->bodies[bk].mass
                             : 0.0);
            cable += mk * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
    }
    free(dq);
    free(dr);
    double veh = 0;
    for (int c = 0; c < 6; c++)
        veh += dof[c];
    if (!(veh > VEHICLE_MODE_SHARE * (veh + cable)))
        return 0;
    static const char *const names[6] = {"surge", "sway", "heave",
                                          "roll",  "pitch", "yaw"};
    int a = 0, b = -1;
    for (int c = 1; c < 6; c++)
        if (dof[c] > dof[a])
            a = c;
    for (int c = 0; c < 6; c++)
        if (c != a && (b < 0 || dof[c] > dof[b]))
            b = c;
    char what[32];
    if (b >= 0 && dof[b] >= VEHICLE_DOF_SECOND * veh)
        snprintf(what, sizeof what, "%s/%s", names[a < b ? a : b],
                 names[a < b ? b : a]);
    else
        snprintf(what, sizeof what, "%s", names[a]);
    snprintf(buf, size, "%svehicle '%s': %s, %.0f%% of the kinetic energy",
             e->modes[m].im > 0 ? "" : "real: ", tb->name, what,
             100.0 * veh / (veh + cable));
    return 1;
}

void ts_eigen_describe(const ts_system *sys, const ts_linear *lin,
                       const ts_eigen *e, int m, char *buf, size_t size)
{
    buf[0] = '\0';
    if (m < 0 || m >= e->nmodes || size == 0)
        return;
    int nk = e->modes[m].neutral;
    if (nk >= 0 && nk < lin->nneutral) {
        snprintf(buf, size, "neutral by symmetry: %s (not counted in the "
                 "verdict)", lin->neutral[nk].name);
        return;
    }
    if (!e->vec_re)
        return;
    if (vehicle_label(sys, lin, e, m, buf, size))
        return;
    int nn = sys->nnodes, nq = lin->nq, nl = sys->nlinks;
    double *dq = malloc((size_t)nq * sizeof(double));
    double *rre = malloc(3 * (size_t)nn * sizeof(double));
    double *rim = malloc(3 * (size_t)nn * sizeof(double));
    double *cab = calloc((size_t)sys->ncables, sizeof(double));
    double *val = malloc((size_t)(nl > 0 ? nl : 1) * sizeof(double));
    if (!dq || !rre || !rim || !cab || !val)
        goto out;
    node_shape(sys, lin, e, m, dq, rre, rim);

    /* The equilibrium's vertical plane: vertical plus the principal
     * horizontal direction of the node positions (x when they have none,
     * e.g. a chain hanging straight down). nrm is its normal. */
    const double *r0 = lin->r0;
    double mx = 0, my = 0, sxx = 0, syy = 0, sxy = 0, L = 0;
    for (int i = 0; i < nn; i++) {
        mx += r0[3 * i] / nn;
        my += r0[3 * i + 1] / nn;
    }
    for (int i = 0; i < nn; i++) {
        double dx = r0[3 * i] - mx, dy = r0[3 * i + 1] - my;
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
    }
    for (int l = 0; l < nl; l++)
        L += sys->links[l].length;
    double hx = 1, hy = 0;
    if (sxx + syy > 1e-12 * L * L * nn) {
        double ang = 0.5 * atan2(2 * sxy, sxx - syy);
        hx = cos(ang);
        hy = sin(ang);
    }
    double nrm[3] = {-hy, hx, 0};

    /* Phase-align on the largest component; share out of plane. */
    double big = -1, out2 = 0, all2 = 0, nbig = -1;
    int ib = 0, inode = 0;
    for (int i = 0; i < nn; i++) {
        double a2 = 0, o_re = 0, o_im = 0;
        for (int c = 0; c < 3; c++) {
            double a = hypot(rre[3 * i + c], rim[3 * i + c]);
            a2 += a * a;
            o_re += rre[3 * i + c] * nrm[c];
            o_im += rim[3 * i + c] * nrm[c];
            if (a > big) {
                big = a;
                ib = 3 * i + c;
            }
        }
        all2 += a2;
        out2 += o_re * o_re + o_im * o_im;
        if (a2 > nbig) {
            nbig = a2;
            inode = i;
        }
    }
    if (!(all2 > 0))
        goto out;
    double share = out2 / all2;
    double complex rot = conj(rre[ib] + I * rim[ib]) / big;
    int out_of_plane = share >= 0.5;

    /* Cable that moves most (sum of squared amplitudes of its nodes). */
    for (int l = 0; l < nl; l++) {
        int k = sys->links[l].lower;
        double a2 = 0;
        for (int c = 0; c < 3; c++)
            a2 += rre[3 * k + c] * rre[3 * k + c] +
                  rim[3 * k + c] * rim[3 * k + c];
        cab[sys->links[l].cable] += a2;
    }
    int cb = 0;
    for (int c = 1; c < sys->ncables; c++)
        if (cab[c] > cab[cb])
            cb = c;

    /* Transverse component along that cable, top to bottom: out of plane
     * along nrm; in plane along nrm x n (perpendicular to the link). */
    int nv = 0, first = -1;
    for (int l = 0; l < nl; l++)
        if (sys->links[l].cable == cb && sys->links[l].index == 1)
            first = l;
    double vmax = 0;
    for (int l = first; l >= 0; l = sys->links[l].next) {
        int k = sys->links[l].lower;
        double dir[3];
        if (out_of_plane) {
            memcpy(dir, nrm, sizeof dir);
        } else {
            double nl_[3];
            const double *rk = r0 + 3 * k, *rp = r0 + 3 * sys->links[l].upper;
            for (int c = 0; c < 3; c++)
                nl_[c] = (rk[c] - rp[c]) / sys->links[l].length;
            dir[0] = nrm[1] * nl_[2] - nrm[2] * nl_[1];
            dir[1] = nrm[2] * nl_[0] - nrm[0] * nl_[2];
            dir[2] = nrm[0] * nl_[1] - nrm[1] * nl_[0];
        }
        double complex w = 0;
        for (int c = 0; c < 3; c++)
            w += (rre[3 * k + c] + I * rim[3 * k + c]) * dir[c];
        val[nv] = creal(w * rot);
        if (fabs(val[nv]) > vmax)
            vmax = fabs(val[nv]);
        nv++;
    }
    int crossings = 0, last = 0;
    for (int i = 0; i < nv; i++) {
        if (fabs(val[i]) <= SHAPE_ZERO_RTOL * vmax)
            continue;
        int sgn = val[i] > 0 ? 1 : -1;
        if (last && sgn != last)
            crossings++;
        last = sgn;
    }
    char plane[48], node[2 * TS_NAME_MAX];
    if (share >= 0.9)
        snprintf(plane, sizeof plane, "out-of-plane");
    else if (share <= 0.1)
        snprintf(plane, sizeof plane, "in-plane");
    else
        snprintf(plane, sizeof plane, "mixed (%.0f%% out-of-plane)",
                 100 * share);
    ts_system_node_name(sys, inode, node, sizeof node);
    snprintf(buf, size, "%s%s, cable '%s' order %d (%d node%s), largest at %s",
             e->modes[m].im > 0 ? "" : "real: ", plane, sys->cables[cb].name,
             crossings + 1, crossings, crossings == 1 ? "" : "s", node);
out:
    free(dq);
    free(rre);
    free(rim);
    free(cab);
    free(val);
}
