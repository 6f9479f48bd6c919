/* eigen.c: modes of the linear model z' = A z (towstab/eigen.h;
 * doc/model.md section 6; doc/linear.md).
 *
 * lapack: dgeevx on a copy of A (balancing, Hessenberg QR; ~25 n^3 flops
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
 * with the structured solver of eigen_impl.h (one nq x nq LU of
 * P(sigma) = K + sigma C - sigma^2 I). ARPACK's Ritz vectors are checked
 * by their residual ||A v - lambda v||.
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
#include <string.h>

#include "arpack.h"
#include "eigen_impl.h"
#include "lapack.h"
#include "towstab/system.h"

/* |Im lambda| below this fraction of |lambda| makes an eigenvalue from the
 * complex solver real (its imaginary part is rounding). */
#define REAL_IM_RTOL 1e-9
/* Two eigenvalues within this fraction of |lambda| are a conjugate match. */
#define CONJ_MATCH_RTOL 1e-7
/* The first-order error estimate of an eigenvalue is itself an estimate
 * (of a truncation error whose rounding part is random): error bounds are
 * this many times it. */
#define ERROR_SAFETY 10.0
/* Shape values below this fraction of the largest do not count as a sign
 * change when counting a mode's nodes. */
#define SHAPE_ZERO_RTOL 1e-8
/* Eigenvector health: the nearest eigenvalues whose first-order coupling
 * is computed (vector_health). */
#define VECTOR_NEIGHBOURS 8

void ts_eigen_opts_default(ts_eigen_opts *o)
{
    o->method = TS_EIG_AUTO;
    o->count = 0;
    o->target_hz = 0.0;
    o->arpack_min_states = 1200;
    o->arpack_tol = 0.0;
    o->arpack_max_iter = 1000;
    o->vectors = 1;
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

void ts_eigen_free(ts_eigen *e)
{
    if (!e)
        return;
    free(e->modes);
    free(e->vec_re);
    free(e->vec_im);
    free(e);
}

/* ---- Structured shift solver (eigen_impl.h) ---------------------------- */

int tsi_shift_factor(tsi_shift *sh, const ts_linear *lin, double complex s,
                     ts_err *err)
{
    memset(sh, 0, sizeof *sh);
    int nq = lin->nq, n = lin->nstate, info = 0;
    size_t nn = (size_t)nq * (size_t)nq;
    sh->lin = lin;
    sh->nq = nq;
    sh->n = n;
    sh->s = s;
    sh->is_complex = cimag(s) != 0.0;
    sh->ipiv = malloc((size_t)nq * sizeof(int));
    sh->w = malloc((size_t)nq * sizeof(double complex));
    sh->wr = malloc(2 * (size_t)nq * sizeof(double));
    if (sh->is_complex)
        sh->zlu = malloc(nn * sizeof(double complex));
    else
        sh->lu = malloc(nn * sizeof(double));
    if (!sh->ipiv || !sh->w || !sh->wr || (!sh->zlu && !sh->lu)) {
        tsi_shift_free(sh);
        return ts_fail_nomem(err, (sh->is_complex ? 16.0 : 8.0) * (double)nn,
                             "fewer links", "eigen: out of memory for the "
                             "%d x %d shifted matrix", nq, nq);
    }
    /* P = K + s C - s^2 I; K = A[nq:, :nq], C = A[nq:, nq:]. */
    const double *A = lin->A;
    double complex s2 = s * s;
    for (int j = 0; j < nq; j++) {
        const double *Kj = A + (size_t)j * n + nq;
        const double *Cj = A + (size_t)(j + nq) * n + nq;
        if (sh->is_complex) {
            double complex *Pj = sh->zlu + (size_t)j * nq;
            for (int i = 0; i < nq; i++)
                Pj[i] = Kj[i] + s * Cj[i];
            Pj[j] -= s2;
        } else {
            double *Pj = sh->lu + (size_t)j * nq;
            double sr = creal(s);
            for (int i = 0; i < nq; i++)
                Pj[i] = Kj[i] + sr * Cj[i];
            Pj[j] -= sr * sr;
        }
    }
    if (sh->is_complex)
        zgetrf_(&nq, &nq, sh->zlu, &nq, sh->ipiv, &info);
    else
        dgetrf_(&nq, &nq, sh->lu, &nq, sh->ipiv, &info);
    if (info < 0) {
        tsi_shift_free(sh);
        return ts_fail(err, TS_ELAPACK, "eigen: LAPACK %s info %d",
                       sh->is_complex ? "zgetrf" : "dgetrf", info);
    }
    if (info > 0) {
        tsi_shift_free(sh);
        return ts_fail(err, TS_ESINGULAR,
                       "eigen: A - s I is singular at s = %g%+gi 1/s (an "
                       "eigenvalue sits on the shift; move the target "
                       "slightly)",
                       creal(s), cimag(s));
    }
    return TS_OK;
}

void tsi_shift_free(tsi_shift *sh)
{
    free(sh->lu);
    free(sh->zlu);
    free(sh->ipiv);
    free(sh->w);
    free(sh->wr);
    memset(sh, 0, sizeof *sh);
}

void tsi_shift_solve_real(tsi_shift *sh, const double *b, double *x)
{
    int nq = sh->nq, n = sh->n, one = 1, info = 0;
    double sr = creal(sh->s), mone = -1.0, pone = 1.0;
    const double *b1 = b, *b2 = b + nq;
    double *x1 = x, *x2 = x + nq;
    /* x1 = b2 + s b1 - C b1 */
    for (int i = 0; i < nq; i++)
        x1[i] = b2[i] + sr * b1[i];
    dgemv_("N", &nq, &nq, &mone, sh->lin->A + (size_t)nq * n + nq, &n, b1,
           &one, &pone, x1, &one, 1);
    dgetrs_("N", &nq, &one, sh->lu, &nq, sh->ipiv, x1, &nq, &info, 1);
    for (int i = 0; i < nq; i++)
        x2[i] = b1[i] + sr * x1[i];
}

void tsi_shift_solve(tsi_shift *sh, const double complex *b,
                     double complex *x)
{
    int nq = sh->nq, n = sh->n, one = 1, two = 2, info = 0;
    double complex s = sh->s;
    const double complex *b1 = b, *b2 = b + nq;
    double complex *x1 = x, *x2 = x + nq;
    /* C b1 for complex b1 and real C: the interleaved (re, im) pairs form
     * a 2 x nq real matrix X, and (C b1) as pairs is X C^T. */
    double pone = 1.0, zero = 0.0;
    dgemm_("N", "T", &two, &nq, &nq, &pone, (const double *)b1, &two,
           sh->lin->A + (size_t)nq * n + nq, &n, &zero, (double *)sh->w, &two,
           1, 1);
    for (int i = 0; i < nq; i++)
        x1[i] = b2[i] + s * b1[i] - sh->w[i];
    if (sh->is_complex) {
        zgetrs_("N", &nq, &one, sh->zlu, &nq, sh->ipiv, x1, &nq, &info, 1);
    } else {
        /* Real factors: solve the real and imaginary parts together. */
        double *r = sh->wr;
        for (int i = 0; i < nq; i++) {
            r[i] = creal(x1[i]);
            r[nq + i] = cimag(x1[i]);
        }
        dgetrs_("N", &nq, &two, sh->lu, &nq, sh->ipiv, r, &nq, &info, 1);
        for (int i = 0; i < nq; i++)
            x1[i] = r[i] + I * r[nq + i];
    }
    for (int i = 0; i < nq; i++)
        x2[i] = b1[i] + s * x1[i];
}

/* ---- Candidate modes ----------------------------------------------------- */

typedef struct cand {
    double complex lam;   /* Im >= 0 */
    double cond, resid;
    double round;         /* rounding error allowance, kappa eps ||A|| */
    double dlam;          /* first-order change of lam by the linearization
                             error estimate, |u^H E v| / |u^H v| (or
                             |E v| / |v| without u); NaN if unknown */
    int vec;              /* column in the vector store */
    double dist;          /* |lam - sigma| */
    double vcond;         /* eigenvector conditioning, max kappa_k
                             ||A_bal|| / gap (lapack; vector_health) */
    double verr;          /* eigenvector error allowance, rad */
} cand;

typedef struct cand_list {
    int n, cap, nstate;
    cand *c;
    double complex *v;    /* [nstate * cap] */
} cand_list;

static int cand_init(cand_list *L, int cap, int nstate)
{
    L->n = 0;
    L->cap = cap > 0 ? cap : 1;
    L->nstate = nstate;
    L->c = malloc((size_t)L->cap * sizeof(cand));
    L->v = malloc((size_t)L->cap * (size_t)nstate * sizeof(double complex));
    return L->c && L->v ? TS_OK : TS_ENOMEM;
}

static void cand_free(cand_list *L)
{
    free(L->c);
    free(L->v);
}

/* Add an eigenvalue with its vector given as re/im parts (im may be NULL);
 * lam in the lower half plane is conjugated with its vector. */
static void cand_add(cand_list *L, double complex lam, const double *vr,
                     const double *vi, double cond, double resid,
                     double dlam)
{
    if (L->n >= L->cap)
        return;
    int sign = cimag(lam) < 0 ? -1 : 1;
    cand *c = &L->c[L->n];
    c->lam = sign > 0 ? lam : conj(lam);
    c->cond = cond;
    c->resid = resid;
    c->dlam = dlam;
    c->round = DBL_EPSILON * cond; /* times ||A||: set by the caller */
    c->vcond = NAN;
    c->verr = NAN;
    c->vec = L->n;
    double complex *v = L->v + (size_t)L->n * L->nstate;
    for (int i = 0; i < L->nstate; i++)
        v[i] = vr[i] + I * (vi ? sign * vi[i] : 0.0);
    L->n++;
}

static int cmp_dist(const void *a, const void *b)
{
    const cand *x = a, *y = b;
    if (x->dist != y->dist)
        return x->dist < y->dist ? -1 : 1;
    return x->vec - y->vec;
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
    return x->vec - y->vec;
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
                          const double *ev, double abnrm, int j, cand *c)
{
    int n = lin->nstate, nq = lin->nq;
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
    const double *er = ev ? ev + (size_t)j * nq : NULL;
    const double *ei = ev && wi[j] != 0.0 ? ev + (size_t)(j + 1) * nq : NULL;
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
        for (int i = 0; er && i < nq; i++) {
            /* conj(a + i b) (x + i y) = (a x + b y) + i (a y - b x) */
            double a = ur[i], b = ui ? sg * ui[i] : 0.0;
            double x = er[i], y = ei ? ei[i] : 0.0;
            sr += a * x + b * y;
            si += a * y - b * x;
        }
        double ck = er ? hypot(sr, si) * kap0[k] / gap
                       : (lin->Aerr ? lin->trunc_norm : 0.0) * kap0[k] / gap;
        ck += DBL_EPSILON * abnrm / (rconde[k] * gap);
        sum2 += ck * ck;
    }
    c->vcond = vcond;
    c->verr = sqrt(sum2);
}

static int solve_lapack(const ts_linear *lin, cand_list *L, ts_err *err)
{
    int n = lin->nstate, info = 0, lwork = -1;
    size_t nn = (size_t)n * (size_t)n;
    double *a = malloc(nn * sizeof(double));
    double *vl = malloc(nn * sizeof(double));
    double *vr = malloc(nn * sizeof(double));
    double *wr = malloc((size_t)n * sizeof(double));
    double *wi = malloc((size_t)n * sizeof(double));
    double *work = NULL, *ev = NULL, wq;
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
    /* dgeevx: balance (permute and scale), then QR; the reciprocal
     * condition numbers and the norm refer to the balanced matrix, the
     * one whose rounding errors matter. */
    int ilo, ihi;
    double abnrm;
    scale = malloc((size_t)n * sizeof(double));
    rconde = malloc((size_t)n * sizeof(double));
    rcondv = malloc((size_t)n * sizeof(double));
    if (!scale || !rconde || !rcondv) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    dgeevx_("B", "V", "V", "E", &n, a, &n, wr, wi, vl, &n, vr, &n, &ilo, &ihi,
            scale, &abnrm, rconde, rcondv, &wq, &lwork, NULL, &info, 1, 1, 1,
            1);
    lwork = info == 0 ? (int)wq : n * (n + 6);
    work = malloc((size_t)lwork * sizeof(double));
    if (!work) {
        rc = ts_fail_nomem(err, 8.0 * lwork, "fewer links, or method arpack "
                           "with a count", "eigen: out of memory for LAPACK "
                           "dgeevx's work of the %d x %d matrix", n, n);
        goto out;
    }
    dgeevx_("B", "V", "V", "E", &n, a, &n, wr, wi, vl, &n, vr, &n, &ilo, &ihi,
            scale, &abnrm, rconde, rcondv, work, &lwork, NULL, &info, 1, 1, 1,
            1);
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
     * eigenvector, one BLAS product, 2 nq n^2 flops. */
    int nq = lin->nq;
    if (lin->Aerr) {
        ev = malloc((size_t)nq * (size_t)n * sizeof(double));
        if (ev) {
            double pone = 1.0, zero = 0.0;
            dgemm_("N", "N", &nq, &n, &n, &pone, lin->Aerr, &nq, vr, &n,
                   &zero, ev, &nq, 1, 1);
        }
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
        const double *evj = ev ? ev + (size_t)j * nq : NULL;
        if (wi[j] == 0.0) {
            double uv = 0, uu = 0, vv = 0, uev = 0;
            for (int i = 0; i < n; i++) {
                uv += vlj[i] * vrj[i];
                uu += vlj[i] * vlj[i];
                vv += vrj[i] * vrj[i];
            }
            for (int i = 0; evj && i < nq; i++)
                uev += vlj[nq + i] * evj[i];
            (void)uu;
            (void)vv;
            cand_add(L, wr[j], vrj, NULL, 1.0 / rconde[j], NAN,
                     evj ? fabs(uev / uv) : NAN);
            L->c[L->n - 1].round = DBL_EPSILON * abnrm / rconde[j];
            vector_health(lin, vl, wr, wi, rconde, kap0, ev, abnrm, j,
                          &L->c[L->n - 1]);
        } else if (wi[j] > 0.0 && j + 1 < n) {
            const double *vrk = vrj + n, *vlk = vlj + n;
            double complex uv = 0, uev = 0;
            double uu = 0, vv = 0;
            for (int i = 0; i < n; i++) {
                double complex u = vlj[i] + I * vlk[i];
                double complex v = vrj[i] + I * vrk[i];
                uv += conj(u) * v;
                uu += vlj[i] * vlj[i] + vlk[i] * vlk[i];
                vv += vrj[i] * vrj[i] + vrk[i] * vrk[i];
            }
            for (int i = 0; evj && i < nq; i++)
                uev += conj(vlj[nq + i] + I * vlk[nq + i]) *
                       (evj[i] + I * evj[nq + i]);
            (void)uu;
            (void)vv;
            cand_add(L, wr[j] + I * wi[j], vrj, vrk, 1.0 / rconde[j], NAN,
                     evj ? cabs(uev / uv) : NAN);
            L->c[L->n - 1].round = DBL_EPSILON * abnrm / rconde[j];
            vector_health(lin, vl, wr, wi, rconde, kap0, ev, abnrm, j,
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
    free(a);
    free(vl);
    free(vr);
    free(wr);
    free(wi);
    free(work);
    return rc;
}

/* ---- ARPACK -------------------------------------------------------------- */

/* Residuals ||A v - lam v|| / (||A||_F |v|) and error estimates
 * ||E v|| / |v| (E the linearization's error estimate; kappa = 1 without a
 * left vector, exact for a normal matrix) of every candidate, with one
 * pass over A and one over E (BLAS dgemm on the real and imaginary parts
 * of all vectors at once): the matrices are the largest objects here, and
 * streaming them once per vector would dominate ARPACK's own cost. */
static int batch_checks(const ts_linear *lin, cand_list *L)
{
    int n = lin->nstate, nq = lin->nq, m = 2 * L->n;
    if (L->n == 0)
        return TS_OK;
    double *W = calloc((size_t)n * (size_t)m, sizeof(double));
    double *AW = malloc((size_t)n * (size_t)m * sizeof(double));
    double *EW = lin->Aerr ? malloc((size_t)nq * (size_t)m * sizeof(double))
                           : NULL;
    if (!W || !AW || (lin->Aerr && !EW)) {
        free(W);
        free(AW);
        free(EW);
        return TS_ENOMEM;
    }
    for (int c = 0; c < L->n; c++) {
        const double complex *v = L->v + (size_t)L->c[c].vec * n;
        for (int i = 0; i < n; i++) {
            W[(size_t)(2 * c) * n + i] = creal(v[i]);
            W[(size_t)(2 * c + 1) * n + i] = cimag(v[i]);
        }
    }
    double pone = 1.0, zero = 0.0;
    dgemm_("N", "N", &n, &m, &n, &pone, lin->A, &n, W, &n, &zero, AW, &n, 1,
           1);
    if (EW)
        dgemm_("N", "N", &nq, &m, &n, &pone, lin->Aerr, &nq, W, &n, &zero, EW,
               &nq, 1, 1);
    for (int c = 0; c < L->n; c++) {
        double complex lam = L->c[c].lam;
        const double complex *v = L->v + (size_t)L->c[c].vec * n;
        const double *ar = AW + (size_t)(2 * c) * n, *ai = ar + n;
        double r2 = 0, v2 = 0, e2 = 0;
        for (int i = 0; i < n; i++) {
            double complex d = ar[i] + I * ai[i] - lam * v[i];
            r2 += creal(d) * creal(d) + cimag(d) * cimag(d);
            v2 += creal(v[i]) * creal(v[i]) + cimag(v[i]) * cimag(v[i]);
        }
        L->c[c].resid = sqrt(r2 / v2) / lin->a_norm;
        if (EW) {
            const double *er = EW + (size_t)(2 * c) * nq, *ei = er + nq;
            for (int i = 0; i < nq; i++)
                e2 += er[i] * er[i] + ei[i] * ei[i];
            L->c[c].dlam = sqrt(e2 / v2);
        }
    }
    free(W);
    free(AW);
    free(EW);
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
    if (!(o.arpack_tol >= 0) || o.arpack_max_iter < 1)
        return ts_fail(err, TS_EINVAL,
                       "eigen: arpack_tol must be >= 0 and arpack_max_iter "
                       ">= 1");
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

static int solve_arpack_real(const ts_linear *lin, const ts_eigen_opts *o,
                             ts_eigen *e, cand_list *L, ts_err *err)
{
    int n = lin->nstate, nev, ncv, rc;
    if ((rc = arpack_sizes(n, o->count, &nev, &ncv, err)) != TS_OK)
        return rc;
    tsi_shift sh;
    double sigma = 0.0, sigmai = 0.0;
    if ((rc = tsi_shift_factor(&sh, lin, sigma, err)) != TS_OK)
        return rc;
    int lworkl = 3 * ncv * ncv + 6 * ncv;
    double *resid = malloc((size_t)n * sizeof(double));
    double *v = malloc((size_t)n * (size_t)ncv * sizeof(double));
    double *workd = malloc(3 * (size_t)n * sizeof(double));
    double *workl = malloc((size_t)lworkl * sizeof(double));
    double *dr = malloc((size_t)(nev + 1) * sizeof(double));
    double *di = malloc((size_t)(nev + 1) * sizeof(double));
    double *z = malloc((size_t)n * (size_t)(nev + 1) * sizeof(double));
    double *workev = malloc(3 * (size_t)ncv * sizeof(double));
    int *select = calloc((size_t)ncv, sizeof(int));
    if (!resid || !v || !workd || !workl || !dr || !di || !z || !workev ||
        !select) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
        goto out;
    }
    int iparam[11] = {0}, ipntr[14] = {0}, ido = 0, info = 0;
    iparam[0] = 1;                  /* exact shifts */
    iparam[2] = o->arpack_max_iter; /* restarts */
    iparam[3] = 1;
    iparam[6] = 3;                  /* shift-invert */
    double tol = o->arpack_tol;
    for (;;) {
        dnaupd_(&ido, "I", &n, "LM", &nev, &tol, resid, &ncv, v, &n, iparam,
                ipntr, workd, workl, &lworkl, &info, 1, 2);
        if (ido != -1 && ido != 1)
            break;
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
    int rvec = 1;
    dneupd_(&rvec, "A", select, dr, di, z, &n, &sigma, &sigmai, workev, "I",
            &n, "LM", &nev, &tol, resid, &ncv, v, &n, iparam, ipntr, workd,
            workl, &lworkl, &info, 1, 1, 2);
    if (info != 0) {
        rc = ts_fail(err, TS_ELAPACK, "eigen: ARPACK dneupd info %d (%s)",
                     info, arpack_info_text(info));
        goto out;
    }
    int nconv = iparam[4];
    if (cand_init(L, nconv + 1, n) != TS_OK) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    for (int j = 0; j < nconv; j++) {
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
    if (batch_checks(lin, L) != TS_OK)
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
out:
    tsi_shift_free(&sh);
    free(resid);
    free(v);
    free(workd);
    free(workl);
    free(dr);
    free(di);
    free(z);
    free(workev);
    free(select);
    return rc;
}

static int solve_arpack_complex(const ts_linear *lin, const ts_eigen_opts *o,
                                ts_eigen *e, cand_list *L, ts_err *err)
{
    int n = lin->nstate, nev, ncv, rc;
    if ((rc = arpack_sizes(n, o->count, &nev, &ncv, err)) != TS_OK)
        return rc;
    tsi_shift sh;
    double complex sigma = I * 2.0 * M_PI * o->target_hz;
    if ((rc = tsi_shift_factor(&sh, lin, sigma, err)) != TS_OK)
        return rc;
    int lworkl = 3 * ncv * ncv + 5 * ncv;
    size_t szc = sizeof(double complex);
    double complex *resid = malloc((size_t)n * szc);
    double complex *v = malloc((size_t)n * (size_t)ncv * szc);
    double complex *workd = malloc(3 * (size_t)n * szc);
    double complex *workl = malloc((size_t)lworkl * szc);
    double complex *d = malloc((size_t)(nev + 1) * szc);
    double complex *z = malloc((size_t)n * (size_t)(nev + 1) * szc);
    double complex *workev = malloc(2 * (size_t)ncv * szc);
    double *rwork = malloc((size_t)ncv * sizeof(double));
    int *select = calloc((size_t)ncv, sizeof(int));
    double *t1 = malloc(5 * (size_t)n * sizeof(double));
    double *lam_re = malloc((size_t)(nev + 1) * sizeof(double));
    int *used = calloc((size_t)(nev + 1), sizeof(int));
    if (!resid || !v || !workd || !workl || !d || !z || !workev || !rwork ||
        !select || !t1 || !lam_re || !used) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory for ARPACK");
        goto out;
    }
    int iparam[11] = {0}, ipntr[14] = {0}, ido = 0, info = 0;
    iparam[0] = 1;
    iparam[2] = o->arpack_max_iter;
    iparam[6] = 3;
    double tol = o->arpack_tol;
    for (;;) {
        znaupd_(&ido, "I", &n, "LM", &nev, &tol, resid, &ncv, v, &n, iparam,
                ipntr, workd, workl, &lworkl, rwork, &info, 1, 2);
        if (ido != -1 && ido != 1)
            break;
        tsi_shift_solve(&sh, workd + ipntr[0] - 1, workd + ipntr[1] - 1);
        e->arpack_ops++;
    }
    e->arpack_iterations = iparam[2];
    e->arpack_nconv = iparam[4];
    if (info == 1) {
        rc = ts_fail(err, TS_ECONV,
                     "eigen: ARPACK znaupd reached %d restarts with %d of %d "
                     "Ritz values converged",
                     o->arpack_max_iter, iparam[4], nev);
        goto out;
    }
    if (info != 0) {
        rc = ts_fail(err, TS_ELAPACK, "eigen: ARPACK znaupd info %d (%s)",
                     info, arpack_info_text(info));
        goto out;
    }
    int rvec = 1;
    zneupd_(&rvec, "A", select, d, z, &n, &sigma, workev, "I", &n, "LM",
            &nev, &tol, resid, &ncv, v, &n, iparam, ipntr, workd, workl,
            &lworkl, rwork, &info, 1, 1, 2);
    if (info != 0) {
        rc = ts_fail(err, TS_ELAPACK, "eigen: ARPACK zneupd info %d (%s)",
                     info, arpack_info_text(info));
        goto out;
    }
    int nconv = iparam[4];
    if (cand_init(L, nconv, n) != TS_OK) {
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
        goto out;
    }
    /* Rounding makes real eigenvalues slightly complex: snap them. */
    for (int j = 0; j < nconv; j++)
        if (fabs(cimag(d[j])) <= REAL_IM_RTOL * cabs(d[j]))
            d[j] = creal(d[j]);
    /* A lower-half eigenvalue whose conjugate was also found is dropped
     * (matched one to one, so double eigenvalues stay double). */
    for (int j = 0; j < nconv; j++) {
        if (cimag(d[j]) >= 0.0)
            continue;
        for (int k = 0; k < nconv; k++) {
            if (used[k] || cimag(d[k]) <= 0.0)
                continue;
            if (cabs(d[k] - conj(d[j])) <= CONJ_MATCH_RTOL * cabs(d[j])) {
                used[k] = 1;
                used[j] = -1;
                break;
            }
        }
    }
    for (int j = 0; j < nconv; j++) {
        if (used[j] < 0)
            continue;
        double complex *zj = z + (size_t)j * n;
        double *re = t1 + 3 * (size_t)n, *im = t1 + 4 * (size_t)n;
        for (int i = 0; i < n; i++) {
            re[i] = creal(zj[i]);
            im[i] = cimag(zj[i]);
        }
        cand_add(L, d[j], re, im, NAN, NAN, NAN);
    }
    if (batch_checks(lin, L) != TS_OK)
        rc = ts_fail(err, TS_ENOMEM, "eigen: out of memory");
out:
    tsi_shift_free(&sh);
    free(resid);
    free(v);
    free(workd);
    free(workl);
    free(d);
    free(z);
    free(workev);
    free(rwork);
    free(select);
    free(t1);
    free(lam_re);
    free(used);
    return rc;
}

/* ---- Driver -------------------------------------------------------------- */

int ts_eigen_solve(const ts_linear *lin, const ts_eigen_opts *opts,
                   ts_eigen **out, ts_err *err)
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
    ts_eigen *e = calloc(1, sizeof *e);
    if (!e)
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory");
    e->nstate = n;
    e->method = m;
    e->target_hz = o.target_hz;
    cand_list L = {0};
    if (m == TS_EIG_LAPACK) {
        rc = solve_lapack(lin, &L, err);
    } else {
        /* ARPACK keeps its state between calls in SAVE variables: one
         * solve at a time in a process (threads of a sweep). */
#ifdef _OPENMP
#pragma omp critical(ts_arpack)
#endif
        rc = o.target_hz == 0.0 ? solve_arpack_real(lin, &o, e, &L, err)
                                : solve_arpack_complex(lin, &o, e, &L, err);
    }
    if (rc != TS_OK) {
        cand_free(&L);
        ts_eigen_free(e);
        return rc;
    }

    /* ARPACK gives no separation estimate: the eigenvector allowance is
     * the eigenvalue's first-order change (plus rounding) over the
     * distance to the nearest other computed eigenvalue, its own
     * conjugate included (exact to first order for a normal matrix; at
     * the edge of the computed subset an uncomputed neighbour may be
     * nearer). */
    if (m != TS_EIG_LAPACK) {
        double rnd = DBL_EPSILON * lin->a_norm;
        for (int i = 0; i < L.n; i++) {
            double complex li = L.c[i].lam;
            double gap = cimag(li) > 0 ? 2.0 * cimag(li) : INFINITY;
            for (int k = 0; k < L.n; k++) {
                if (k == i)
                    continue;
                double complex lk = L.c[k].lam;
                gap = fmin(gap, fmin(cabs(li - lk), cabs(li - conj(lk))));
            }
            double dl = isfinite(L.c[i].dlam) ? L.c[i].dlam : 0.0;
            L.c[i].verr = gap > 0 ? (dl + rnd) / gap : INFINITY;
        }
    }

    /* Keep the `count` nearest sigma, then order by frequency. */
    double complex sigma = I * 2.0 * M_PI * o.target_hz;
    for (int i = 0; i < L.n; i++)
        L.c[i].dist = cabs(L.c[i].lam - sigma);
    qsort(L.c, (size_t)L.n, sizeof(cand), cmp_dist);
    int keep = L.n;
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
    double round_err = DBL_EPSILON * lin->a_norm;
    e->neig = 0;
    e->max_real = -INFINITY;
    e->max_real_error = 0.0;
    int any_unstable = 0, all_stable = 1;
    for (int i = 0; i < keep; i++) {
        const cand *c = &L.c[i];
        ts_mode *md = &e->modes[i];
        double re = creal(c->lam), im = cimag(c->lam), mag = cabs(c->lam);
        md->re = re;
        md->im = im;
        md->freq_hz = im / (2.0 * M_PI);
        md->period_s = im > 0 ? 1.0 / md->freq_hz : INFINITY;
        md->damping_ratio = mag > 0 ? -re / mag : 0.0;
        md->time_constant_s = re != 0 ? -1.0 / re : INFINITY;
        md->condition = c->cond;
        md->residual = c->resid;
        md->vector_condition = c->vcond;
        md->vector_error = c->verr;
        double rnd = m == TS_EIG_LAPACK ? c->round : round_err;
        md->error_bound =
            ERROR_SAFETY * ((isfinite(c->dlam) ? c->dlam : 0.0) + rnd);
        e->neig += im > 0 ? 2 : 1;
        if (re > e->max_real) {
            e->max_real = re;
            e->max_real_error = md->error_bound;
        }
        if (re - md->error_bound > 0)
            any_unstable = 1;
        if (!(re + md->error_bound < 0))
            all_stable = 0;
        if (o.vectors) {
            const double complex *v = L.v + (size_t)c->vec * n;
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
    e->complete = e->neig == n;
    e->verdict = any_unstable ? TS_UNSTABLE
                              : (all_stable && keep > 0 ? TS_STABLE
                                                        : TS_MARGINAL);
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

void ts_eigen_describe(const ts_system *sys, const ts_linear *lin,
                       const ts_eigen *e, int m, char *buf, size_t size)
{
    buf[0] = '\0';
    if (!e->vec_re || m < 0 || m >= e->nmodes || size == 0)
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
