/* shift.c: solves with the sparse linear model (lib/shift.h; doc/linear.md,
 * sections 2-4).
 *
 * Each solve maps the kernel's coordinates to node displacements (J, down
 * the tree), builds the right-hand side node by node, runs KLU's
 * triangular solves (klu_solve, or klu_z_solve in complex arithmetic) and
 * maps back (J^-1, link by link): O(nlinks) throughout. The equations
 * behind each right-hand side are in lib/shift.h and lib/descriptor.h.
 */
#include "shift.h"

#include "bigalloc.h"

#include <klu.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define XR(k, c) tsi_desc_xr(d, (k), (c))
#define XT(l) TSI_XT(l)
#define XC(j) tsi_desc_xc(d, (j))

/* Release KLU's factors (of the kind sh->is_complex says). */
static void free_numeric(tsi_shift *sh)
{
    if (sh->numeric) {
        klu_numeric *num = sh->numeric;
        if (sh->is_complex)
            sh->klu.klu_z_free_numeric(&num, sh->common);
        else
            sh->klu.klu_free_numeric(&num, sh->common);
    }
    sh->numeric = NULL;
}

void tsi_shift_free(tsi_shift *sh)
{
    free(sh->lu);
    free(sh->zlu);
    free(sh->ipiv);
    free(sh->zw);
    free(sh->wr);
    free_numeric(sh);
    free(sh->common);
    free(sh->Sx);
    free(sh->Sk);
    free(sh->Sc);
    free(sh->Sm);
    free(sh->rhs);
    free(sh->cols);
    free(sh->u1);
    free(sh->u2);
    free(sh->w);
    free(sh->ework);
    free(sh->hlu);
    free(sh->hpiv);
    free(sh->wc);
    free(sh->full);
    free(sh->fpiv);
    memset(sh, 0, sizeof *sh);
}

/* ---- Dense backend (lib/shift.h: systems with vehicles) -------------- */

/* A failed LU of the shifted matrix (LAPACK `what`, its info). */
static int factor_failed(int info, const char *what, double complex s,
                         ts_err *err)
{
    if (info < 0)
        return ts_fail(err, TS_ELAPACK, "eigen: LAPACK %s info %d", what,
                       info);
    return ts_fail(err, TS_ESINGULAR,
                   "eigen: A - s I is singular at s = %g%+gi 1/s (an "
                   "eigenvalue sits on the shift; move the target slightly)",
                   creal(s), cimag(s));
}

/* The whole A - s I, factored (complex LU): the fallback when the
 * controller block H - s I is singular. */
static int full_factor(tsi_shift *sh, ts_err *err)
{
    int n = sh->n, info = 0;
    const double *A = sh->lin->A;
    sh->full = malloc((size_t)n * (size_t)n * sizeof(double complex));
    sh->fpiv = malloc((size_t)n * sizeof(int));
    if (!sh->full || !sh->fpiv) {
        tsi_shift_free(sh);
        return ts_fail(err, TS_ENOMEM, "eigen: out of memory for the %d x "
                       "%d shifted matrix", n, n);
    }
    for (size_t i = 0; i < (size_t)n * (size_t)n; i++)
        sh->full[i] = A[i];
    for (int i = 0; i < n; i++)
        sh->full[(size_t)i * n + i] -= sh->s;
    sh->la.zgetrf_(&n, &n, sh->full, &n, sh->fpiv, &info);
    if (info != 0) {
        double complex s = sh->s;
        tsi_shift_free(sh);
        return factor_failed(info, "zgetrf", s, err);
    }
    return TS_OK;
}

static int dense_factor(tsi_shift *sh, const ts_linear *lin, double complex s,
                        ts_err *err)
{
    memset(sh, 0, sizeof *sh);
    if (tsi_lapack_open(&sh->la, err) != TS_OK)
        return TS_EIO;
    int nq = lin->nq, n = lin->nstate, nc = n - 2 * nq, info = 0;
    size_t nn = (size_t)nq * (size_t)nq;
    sh->lin = lin;
    sh->nq = nq;
    sh->n = n;
    sh->nc = nc;
    sh->s = s;
    /* Controller states: the Schur complement is complex in general. */
    sh->is_complex = cimag(s) != 0.0 || nc > 0;
    sh->ipiv = malloc((size_t)nq * sizeof(int));
    sh->zw = malloc((size_t)nq * sizeof(double complex));
    sh->wr = malloc(2 * (size_t)nq * sizeof(double));
    if (sh->is_complex)
        sh->zlu = malloc(nn * sizeof(double complex));
    else
        sh->lu = malloc(nn * sizeof(double));
    double complex *MF = NULL;
    if (nc > 0) {
        sh->hlu = malloc((size_t)nc * (size_t)nc * sizeof(double complex));
        sh->hpiv = malloc((size_t)nc * sizeof(int));
        sh->wc = malloc(2 * (size_t)nc * sizeof(double complex));
        MF = malloc((size_t)nc * (size_t)nq * sizeof(double complex));
    }
    if (!sh->ipiv || !sh->zw || !sh->wr || (!sh->zlu && !sh->lu) ||
        (nc > 0 && (!sh->hlu || !sh->hpiv || !sh->wc || !MF))) {
        free(MF);
        tsi_shift_free(sh);
        return ts_fail_nomem(err, (sh->is_complex ? 16.0 : 8.0) * (double)nn,
                             "fewer links", "eigen: out of memory for the "
                             "%d x %d shifted matrix", nq, nq);
    }
    /* P = K + s C - s^2 I; K = A[nq:2nq, :nq], C = A[nq:2nq, nq:2nq]. */
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
    if (nc > 0) {
        /* H - s I, factored; MF = (H - sI)^-1 (F + s G), then
         * P -= E MF with E = A[nq:2nq, 2nq:], F = A[2nq:, :nq],
         * G = A[2nq:, nq:2nq], H = A[2nq:, 2nq:]. */
        for (int j = 0; j < nc; j++)
            for (int i = 0; i < nc; i++)
                sh->hlu[(size_t)j * nc + i] =
                    A[(size_t)(2 * nq + j) * n + 2 * nq + i] -
                    (i == j ? s : 0.0);
        sh->la.zgetrf_(&nc, &nc, sh->hlu, &nc, sh->hpiv, &info);
        if (info == 0) {
            for (int j = 0; j < nq; j++)
                for (int i = 0; i < nc; i++)
                    MF[(size_t)j * nc + i] =
                        A[(size_t)j * n + 2 * nq + i] +
                        s * A[(size_t)(nq + j) * n + 2 * nq + i];
            sh->la.zgetrs_("N", &nc, &nq, sh->hlu, &nc, sh->hpiv, MF, &nc,
                           &info, 1);
        }
        for (int j = 0; info == 0 && j < nq; j++) {
            double complex *Pj = sh->zlu + (size_t)j * nq;
            for (int k = 0; k < nc; k++) {
                double complex m = MF[(size_t)j * nc + k];
                const double *Ek = A + (size_t)(2 * nq + k) * n + nq;
                for (int i = 0; i < nq; i++)
                    Pj[i] -= Ek[i] * m;
            }
        }
        free(MF);
        if (info < 0) {
            tsi_shift_free(sh);
            return ts_fail(err, TS_ELAPACK, "eigen: LAPACK zgetrf info %d "
                           "on the controller block", info);
        }
        if (info > 0)
            return full_factor(sh, err);
    }
    if (sh->is_complex)
        sh->la.zgetrf_(&nq, &nq, sh->zlu, &nq, sh->ipiv, &info);
    else
        sh->la.dgetrf_(&nq, &nq, sh->lu, &nq, sh->ipiv, &info);
    if (info != 0) {
        const char *what = sh->is_complex ? "zgetrf" : "dgetrf";
        tsi_shift_free(sh);
        return factor_failed(info, what, s, err);
    }
    return TS_OK;
}

static void dense_solve_real(tsi_shift *sh, const double *b, double *x)
{
    int nq = sh->nq, n = sh->n, one = 1, info = 0;
    if (sh->nc > 0) {
        /* Complex factors (the Schur complement); real s, real answer. */
        double complex *bc = malloc((size_t)n * sizeof(double complex));
        double complex *xc = malloc((size_t)n * sizeof(double complex));
        if (bc && xc) {
            for (int i = 0; i < n; i++)
                bc[i] = b[i];
            tsi_shift_solve(sh, bc, xc);
            for (int i = 0; i < n; i++)
                x[i] = creal(xc[i]);
        } else {
            for (int i = 0; i < n; i++)
                x[i] = NAN;
        }
        free(bc);
        free(xc);
        return;
    }
    double sr = creal(sh->s), mone = -1.0, pone = 1.0;
    const double *b1 = b, *b2 = b + nq;
    double *x1 = x, *x2 = x + nq;
    /* x1 = b2 + s b1 - C b1 */
    for (int i = 0; i < nq; i++)
        x1[i] = b2[i] + sr * b1[i];
    sh->la.dgemv_("N", &nq, &nq, &mone, sh->lin->A + (size_t)nq * n + nq, &n,
                  b1, &one, &pone, x1, &one, 1);
    sh->la.dgetrs_("N", &nq, &one, sh->lu, &nq, sh->ipiv, x1, &nq, &info, 1);
    for (int i = 0; i < nq; i++)
        x2[i] = b1[i] + sr * x1[i];
}

/* y[nc] = M x for the real block M of A at rows 2nq.., columns c0..c0+m
 * (y += when acc). */
static void ctl_rows(const tsi_shift *sh, int c0, int m,
                     const double complex *x, double complex *y, int acc)
{
    int n = sh->n, r0 = 2 * sh->nq;
    const double *A = sh->lin->A;
    for (int i = 0; i < sh->nc; i++) {
        double complex sum = acc ? y[i] : 0.0;
        for (int j = 0; j < m; j++)
            sum += A[(size_t)(c0 + j) * n + r0 + i] * x[j];
        y[i] = sum;
    }
}

static void dense_solve(tsi_shift *sh, const double complex *b,
                        double complex *x)
{
    int nq = sh->nq, n = sh->n, nc = sh->nc, one = 1, two = 2, info = 0;
    if (sh->full) {
        memcpy(x, b, (size_t)n * sizeof(double complex));
        sh->la.zgetrs_("N", &n, &one, sh->full, &n, sh->fpiv, x, &n, &info, 1);
        return;
    }
    double complex s = sh->s;
    const double complex *b1 = b, *b2 = b + nq, *b3 = b + 2 * nq;
    double complex *x1 = x, *x2 = x + nq, *x3 = x + 2 * nq;
    /* C b1 for complex b1 and real C: the interleaved (re, im) pairs form
     * a 2 x nq real matrix X, and (C b1) as pairs is X C^T. */
    double pone = 1.0, zero = 0.0;
    sh->la.dgemm_("N", "T", &two, &nq, &nq, &pone, (const double *)b1, &two,
                  sh->lin->A + (size_t)nq * n + nq, &n, &zero, (double *)sh->zw,
                  &two, 1, 1);
    for (int i = 0; i < nq; i++)
        x1[i] = b2[i] + s * b1[i] - sh->zw[i];
    if (nc > 0) {
        /* t3 = (H - sI)^-1 (b3 - G b1); x1 -= E t3. */
        double complex *t3 = sh->wc;
        ctl_rows(sh, nq, nq, b1, t3, 0);
        for (int i = 0; i < nc; i++)
            t3[i] = b3[i] - t3[i];
        sh->la.zgetrs_("N", &nc, &one, sh->hlu, &nc, sh->hpiv, t3, &nc, &info,
                       1);
        const double *A = sh->lin->A;
        for (int k = 0; k < nc; k++) {
            const double *Ek = A + (size_t)(2 * nq + k) * n + nq;
            for (int i = 0; i < nq; i++)
                x1[i] -= Ek[i] * t3[k];
        }
    }
    if (sh->is_complex) {
        sh->la.zgetrs_("N", &nq, &one, sh->zlu, &nq, sh->ipiv, x1, &nq, &info,
                       1);
    } else {
        /* Real factors: solve the real and imaginary parts together. */
        double *r = sh->wr;
        for (int i = 0; i < nq; i++) {
            r[i] = creal(x1[i]);
            r[nq + i] = cimag(x1[i]);
        }
        sh->la.dgetrs_("N", &nq, &two, sh->lu, &nq, sh->ipiv, r, &nq, &info, 1);
        for (int i = 0; i < nq; i++)
            x1[i] = r[i] + I * r[nq + i];
    }
    for (int i = 0; i < nq; i++)
        x2[i] = b1[i] + s * x1[i];
    if (nc > 0) {
        /* x3 = (H - sI)^-1 (b3 - F x1 - G x2). */
        ctl_rows(sh, 0, nq, x1, x3, 0);
        ctl_rows(sh, nq, nq, x2, x3, 1);
        for (int i = 0; i < nc; i++)
            x3[i] = b3[i] - x3[i];
        sh->la.zgetrs_("N", &nc, &one, sh->hlu, &nc, sh->hpiv, x3, &nc, &info,
                       1);
    }
}

/* ---- Sparse backend ------------------------------------------------------ */

static int setup(tsi_shift *sh, const ts_linear *lin, ts_err *err)
{
    memset(sh, 0, sizeof *sh);
    if (!lin->desc)
        return ts_fail(err, TS_EINVAL, "shift: the linear model has no sparse "
                       "form (linearize with model TS_LIN_AUTO, SPARSE or "
                       "BOTH)");
    if (tsi_klu_open(&sh->klu, err) != TS_OK)
        return TS_EIO;
    const ts_descriptor *d = lin->desc;
    sh->lin = lin;
    sh->d = d;
    sh->sys = d->sys;
    size_t n3 = 3 * (size_t)d->np + (size_t)d->nc;
    sh->common = malloc(sizeof(klu_common));
    sh->Sx = tsi_big_malloc(2 * ((size_t)d->nnz + 1) * sizeof(double));
    sh->rhs = malloc(2 * ((size_t)d->nx + 1) * sizeof(double));
    sh->cols = malloc(2 * ((size_t)d->nx + 1) * sizeof(double));
    sh->u1 = malloc(2 * n3 * sizeof(double));
    sh->u2 = malloc((6 * n3 + (size_t)d->nin) * sizeof(double));
    sh->w = malloc(2 * ((size_t)lin->nq + 1) * sizeof(double));
    if (!sh->common || !sh->Sx || !sh->rhs || !sh->cols || !sh->u1 ||
        !sh->u2 || !sh->w) {
        tsi_shift_free(sh);
        return ts_fail(err, TS_ENOMEM, "shift: out of memory for %d "
                       "unknowns", d->nx);
    }
    memcpy(sh->common, d->klu_common, sizeof(klu_common));
    return TS_OK;
}

/* The rcond estimate min |u_ii| / max |u_ii| of the factors of the
 * unscaled matrix with the same pivots. KLU factors R^-1 A (R = diag(Rs),
 * Rs[i] row i's scale); with the row permutation P, P A Q = (P R P^T) L U
 * with L unit lower triangular, so the unscaled factors' diagonal is
 * u_ii Rs[Pnum[i]]. */
static double raw_rcond(const tsi_shift *sh)
{
    const klu_numeric *num = sh->numeric;
    double lo = INFINITY, hi = 0.0;
    for (int i = 0; i < num->n; i++) {
        double u = sh->is_complex ? cabs(((const double complex *)
                                              num->Udiag)[i])
                                  : fabs(((const double *)num->Udiag)[i]);
        if (num->Rs)
            u *= num->Rs[num->Pnum[i]];
        lo = fmin(lo, u);
        hi = fmax(hi, u);
    }
    return hi > 0 ? lo / hi : 0.0;
}

static int factor(tsi_shift *sh, ts_err *err)
{
    const ts_descriptor *d = sh->d;
    klu_common *kc = sh->common;
    klu_symbolic *sym = d->klu_symbolic;
    if (sh->is_complex)
        sh->numeric = sh->klu.klu_z_factor(d->Sp, d->Si, sh->Sx, sym, kc);
    else
        sh->numeric = sh->klu.klu_factor(d->Sp, d->Si, sh->Sx, sym, kc);
    if (sh->numeric) {
        /* KLU's cheap estimate, min |u_ii| / max |u_ii|, against which a
         * refactorisation is judged. */
        int ok = sh->is_complex ? sh->klu.klu_z_rcond(sym, sh->numeric, kc)
                                : sh->klu.klu_rcond(sym, sh->numeric, kc);
        sh->rcond = ok ? kc->rcond : 0.0;
        sh->rcond_raw = ok ? raw_rcond(sh) : 0.0;
        return TS_OK;
    }
    int status = kc->status;
    double complex s = sh->s;
    tsi_shift_free(sh);
    if (status == KLU_OUT_OF_MEMORY)
        return ts_fail(err, TS_ENOMEM, "shift: out of memory for the sparse "
                       "factors");
    if (status == KLU_SINGULAR)
        return ts_fail(err, TS_ESINGULAR, "the shifted system is singular "
                       "at s = %g%+gi 1/s (an eigenvalue sits on the shift)",
                       creal(s), cimag(s));
    return ts_fail(err, TS_ELAPACK, "shift: KLU failed (status %d)", status);
}

int tsi_shift_factor(tsi_shift *sh, const ts_linear *lin, double complex s,
                     ts_err *err)
{
    if (!lin->desc && lin->A)
        return dense_factor(sh, lin, s, err);
    int rc = setup(sh, lin, err);
    if (rc != TS_OK)
        return rc;
    sh->s = s;
    sh->is_complex = cimag(s) != 0.0;
    if (sh->is_complex)
        tsi_desc_fill_complex(sh->d, s, sh->Sx);
    else
        tsi_desc_fill_real(sh->d, creal(s), 0, sh->Sx);
    return factor(sh, err);
}

/* S's parts Sk, Sc, Sm (tsi_desc_fill_parts), computed once per sh. */
static int ensure_parts(tsi_shift *sh, ts_err *err)
{
    if (sh->Sk)
        return TS_OK;
    const ts_descriptor *d = sh->d;
    size_t nz = (size_t)d->nnz + 1;
    sh->Sk = tsi_big_malloc(nz * sizeof(double));
    sh->Sc = tsi_big_malloc(nz * sizeof(double));
    sh->Sm = tsi_big_malloc(nz * sizeof(double));
    if (!sh->Sk || !sh->Sc || !sh->Sm) {
        tsi_shift_free(sh);
        return ts_fail(err, TS_ENOMEM, "shift: out of memory for %d "
                       "unknowns", d->nx);
    }
    tsi_desc_fill_parts(d, sh->Sk, sh->Sc, sh->Sm);
    return TS_OK;
}

/* S(sh->s), already in sh->Sx, factored afresh, with pivoting and scaling
 * (real or complex as cplx), in the arrays sh holds; sh is freed when it
 * fails (factor). */
static int afresh(tsi_shift *sh, int cplx, ts_err *err)
{
    free_numeric(sh);
    sh->is_complex = cplx;
    return factor(sh, err);
}

/* tsi_shift_refactor; with test 0 the old pivots serve whenever KLU's
 * refactorisation succeeds (the caller judges its solves:
 * tsi_shift_eig_error). *fresh (may be NULL) is set when it factored
 * afresh. */
static int refactor(tsi_shift *sh, const ts_linear *lin, double complex s,
                    int test, int *fresh, ts_err *err)
{
    int cplx = cimag(s) != 0.0;
    if (fresh)
        *fresh = 1;
    if (!sh->numeric || sh->inf || sh->lin != lin) {
        tsi_shift_free(sh);
        return tsi_shift_factor(sh, lin, s, err);
    }
    int rc = ensure_parts(sh, err);
    if (rc != TS_OK)
        return rc;
    const ts_descriptor *d = sh->d;
    klu_common *kc = sh->common;
    klu_symbolic *sym = d->klu_symbolic;
    klu_numeric *num = sh->numeric;
    sh->s = s;
    /* S(s) from its parts: one pass, the same values as
     * tsi_desc_fill_complex and _real. */
    const double *Sk = sh->Sk, *Sc = sh->Sc, *Sm = sh->Sm;
    double complex s2 = s * s;
    double sr = creal(s), si = cimag(s), qr = creal(s2), qi = cimag(s2);
    if (cplx) {
        for (int p = 0; p < d->nnz; p++) {
            sh->Sx[2 * p] = Sk[p] + sr * Sc[p] + qr * Sm[p];
            sh->Sx[2 * p + 1] = si * Sc[p] + qi * Sm[p];
        }
    } else {
        for (int p = 0; p < d->nnz; p++)
            sh->Sx[p] = Sk[p] + sr * Sc[p] + qr * Sm[p];
    }
    if (cplx == sh->is_complex) {
        int ok, scale = kc->scale;
        kc->scale = -1;
        ok = cplx ? sh->klu.klu_z_refactor(d->Sp, d->Si, sh->Sx, sym, num,
                                           kc) &&
                        sh->klu.klu_z_rcond(sym, num, kc)
                  : sh->klu.klu_refactor(d->Sp, d->Si, sh->Sx, sym, num, kc) &&
                        sh->klu.klu_rcond(sym, num, kc);
        kc->scale = scale;
        /* The old pivots serve while the factors stay as well conditioned
         * as a fresh factorisation's, within SHIFT_REFACTOR_RCOND (both
         * unscaled). */
        if (ok && (!test ||
                   kc->rcond >= SHIFT_REFACTOR_RCOND * sh->rcond_raw)) {
            if (fresh)
                *fresh = 0;
            return TS_OK;
        }
    }
    return afresh(sh, cplx, err);
}

int tsi_shift_refactor(tsi_shift *sh, const ts_linear *lin, double complex s,
                       ts_err *err)
{
    return refactor(sh, lin, s, 1, NULL, err);
}

int tsi_shift_factor_inf(tsi_shift *sh, const ts_linear *lin, ts_err *err)
{
    int rc = setup(sh, lin, err);
    if (rc != TS_OK)
        return rc;
    sh->inf = 1;
    tsi_desc_fill_real(sh->d, 0.0, 1, sh->Sx);
    rc = factor(sh, err);
    if (rc == TS_ESINGULAR)
        ts_fail(err, TS_ESINGULAR, "the nodal mass system is singular");
    return rc;
}

void tsi_shift_nodes_to_q(const tsi_shift *sh, const double *dr, double *dq)
{
    tsi_desc_from_points(sh->d, sh->lin, dr, dq);
}

/* p[3 np] (p_0 = 0) and c[nc] from a real solution at stride. */
static void solution_points(const ts_descriptor *d, const double *x,
                            int stride, double *p, double *c)
{
    p[0] = p[1] = p[2] = 0.0;
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++)
            p[3 * k + a] = x[stride * XR(k, a)];
    for (int j = 0; c && j < d->nc; j++)
        c[j] = x[stride * XC(j)];
}

/* The link rows' right-hand side of taut elastic links, the damping's
 * part of a prescribed rate: Cv n.(J w_q)_k - Cv n.(J w_q)_p = Cv l w_e
 * (w_e the link's strain entry of w_q), taken from the coordinate itself
 * so that no rounding of n against the direction derivatives is
 * multiplied by a stiff link's constants. Into rhs at stride. */
static void taut_rates(const tsi_shift *sh, const double *wq, double *rhs,
                       int stride)
{
    const ts_descriptor *d = sh->d;
    for (int l = 0; l < d->nl; l++) {
        double v = 0.0;
        if (d->kind[l] == TSI_LINK_TAUT)
            v = d->ca[l] * d->sys->links[l].length * wq[sh->lin->qoff[l] + 2];
        rhs[stride * XT(l)] = v;
    }
}

/* One real part of (s I - A)^-1 w's right-hand side, w = (wq, wqd, wc)
 * (nq, nq, nc): into rhs at stride the parts free of s, M J wqd + C J wq
 * in the point rows, Cv n.(J wq) in the taut links' rows and wc - Hv J wq
 * in the controller rows, and J wq into u1 and M J wq into mu (the
 * caller adds s mu). u2 [3 np + nc] work. */
static void rhs_part(const tsi_shift *sh, const double *w, double *u1,
                     double *mu, double *u2, double *rhs, int stride)
{
    const ts_descriptor *d = sh->d;
    int nq = sh->lin->nq;
    size_t n3 = 3 * (size_t)d->np;
    double *hc = u2 + n3;
    const double *wv[2] = {w, w + nq};
    double *uv[2] = {u1, u2};
    tsi_desc_to_points_n(d, sh->lin, 2, wv, uv);
    tsi_desc_mass_mul(d, u2, mu);
    tsi_desc_block_mul(d, d->C, u1, mu, 1);
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++)
            rhs[stride * XR(k, a)] = mu[3 * k + a];
    taut_rates(sh, w, rhs, stride);
    tsi_desc_local_mul(d, NULL, u1, NULL, NULL, hc, NULL, 0);
    for (int j = 0; j < d->nc; j++)
        rhs[stride * XC(j)] = w[2 * nq + j] - hc[j];
    tsi_desc_mass_mul(d, u1, mu);
}

void tsi_shift_solve_real(tsi_shift *sh, const double *b, double *x)
{
    if (!sh->d) {
        dense_solve_real(sh, b, x);
        return;
    }
    const ts_descriptor *d = sh->d;
    int nq = sh->lin->nq, nc = d->nc;
    size_t m = 3 * (size_t)d->np + (size_t)nc;
    double s = creal(sh->s);
    double *u1 = sh->u1, *mu = sh->u1 + m, *u2 = sh->u2, *p = sh->u2 + 2 * m;
    double *w = sh->cols;
    /* (A - s I) x = b  <=>  (s I - A) x = -b = w. */
    for (int i = 0; i < 2 * nq + nc; i++)
        w[i] = -b[i];
    /* A cut state (d->cut): its column of A is zero, so the other
     * unknowns are those of the whole system with its entry of b zero;
     * its own row, cut to -s x_j = b_j, gives it. */
    for (int t = 0; t < d->ncut; t++)
        w[d->cut[t]] = 0.0;
    rhs_part(sh, w, u1, mu, u2, sh->rhs, 1);
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++)
            sh->rhs[XR(k, a)] += s * mu[3 * k + a];
    sh->klu.klu_solve(d->klu_symbolic, sh->numeric, d->nx, 1, sh->rhs,
                      sh->common);
    solution_points(d, sh->rhs, 1, p, x + 2 * nq);
    tsi_shift_nodes_to_q(sh, p, x);
    for (int i = 0; i < nq; i++)
        x[nq + i] = s * x[i] - w[i];
    for (int t = 0; t < d->ncut; t++)
        x[d->cut[t]] = s != 0.0 ? -b[d->cut[t]] / s : 0.0;
}

/* Solve with real factors for the interleaved complex right-hand side in
 * sh->rhs: its real and imaginary parts as two columns. */
static void two_columns(tsi_shift *sh)
{
    int nx = sh->d->nx;
    double *cols = sh->cols, *rhs = sh->rhs;
    for (int i = 0; i < nx; i++) {
        cols[i] = rhs[2 * i];
        cols[nx + i] = rhs[2 * i + 1];
    }
    sh->klu.klu_solve(sh->d->klu_symbolic, sh->numeric, nx, 2, cols,
                      sh->common);
    for (int i = 0; i < nx; i++) {
        rhs[2 * i] = cols[i];
        rhs[2 * i + 1] = cols[nx + i];
    }
}

void tsi_shift_solve(tsi_shift *sh, const double complex *b,
                     double complex *x)
{
    if (!sh->d) {
        dense_solve(sh, b, x);
        return;
    }
    const ts_descriptor *d = sh->d;
    int nq = sh->lin->nq, nc = d->nc, n = 2 * nq + nc;
    size_t m = 3 * (size_t)d->np + (size_t)nc;
    double complex s = sh->s;
    double *u1 = sh->u1, *u2 = sh->u2, *mu = sh->u2 + 2 * m;
    double *w = sh->cols, *rhs = sh->rhs;
    /* The real and imaginary parts of w = -b, one map each; then + s M J
     * wq, complex. */
    for (int part = 0; part < 2; part++) {
        for (int i = 0; i < n; i++)
            w[i] = part ? -cimag(b[i]) : -creal(b[i]);
        for (int t = 0; t < d->ncut; t++) /* as tsi_shift_solve_real */
            w[d->cut[t]] = 0.0;
        rhs_part(sh, w, u1 + part * m, mu + part * m, u2, rhs + part, 2);
    }
    const double *mr = mu, *mi = mu + m;
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++) {
            double complex v = s * (mr[3 * k + a] + I * mi[3 * k + a]);
            rhs[2 * XR(k, a)] += creal(v);
            rhs[2 * XR(k, a) + 1] += cimag(v);
        }
    if (sh->is_complex) {
        sh->klu.klu_z_solve(d->klu_symbolic, sh->numeric, d->nx, 1, rhs,
                            sh->common);
    } else {
        /* Real factors: the real and imaginary parts as two right-hand
         * sides. */
        two_columns(sh);
    }
    double *xr = sh->w, *xi = sh->w + nq, *p = u2, *cr = u1, *ci = u1 + m;
    solution_points(d, rhs, 2, p, cr);
    solution_points(d, rhs + 1, 2, p + m, ci);
    const double *pv[2] = {p, p + m};
    double *xv[2] = {xr, xi};
    tsi_desc_from_points_n(d, sh->lin, 2, pv, xv);
    for (int i = 0; i < nq; i++) {
        x[i] = xr[i] + I * xi[i];
        x[nq + i] = s * x[i] + b[i]; /* s x_q - w_q, w = -b */
    }
    for (int j = 0; j < nc; j++)
        x[2 * nq + j] = cr[j] + I * ci[j];
    for (int t = 0; t < d->ncut; t++) {
        int j = d->cut[t];
        x[nq + j] = s * x[j]; /* its b_j taken as zero */
        x[j] = s != 0.0 ? -b[j] / s : 0.0;
    }
}

/* Solve with S_inf for the force change f[3 np] (rhs -f), the link rows
 * rhs_t (NULL: zero) and the controller rates hc[nc]; into y the
 * accelerations' coordinates q''[nq] and the rates c'[nc]. */
static void inf_solve(tsi_shift *sh, const double *f, const double *rhs_t,
                      const double *hc, double *qdd, double *cd)
{
    const ts_descriptor *d = sh->d;
    size_t m = 3 * (size_t)d->np + (size_t)d->nc;
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++)
            sh->rhs[XR(k, a)] = -f[3 * k + a];
    for (int l = 0; l < d->nl; l++)
        sh->rhs[XT(l)] = rhs_t ? rhs_t[l] : 0.0;
    for (int j = 0; j < d->nc; j++)
        sh->rhs[XC(j)] = hc[j];
    sh->klu.klu_solve(d->klu_symbolic, sh->numeric, d->nx, 1, sh->rhs,
                      sh->common);
    double *p = sh->u1 + m;
    solution_points(d, sh->rhs, 1, p, cd);
    tsi_shift_nodes_to_q(sh, p, qdd);
}

void tsi_shift_apply(tsi_shift *sh, const double *x, double *y, int err)
{
    const ts_descriptor *d = sh->d;
    int nq = sh->lin->nq, nc = d->nc;
    size_t n3 = 3 * (size_t)d->np, m = n3 + (size_t)nc;
    double *u1 = sh->u1, *u2 = sh->u2, *f = sh->u2 + m, *hc = sh->u2 + 2 * m;
    double *rt = sh->u2 + 3 * m;
    const double *K = err ? d->Kerr : d->K, *C = err ? d->Cerr : d->C;
    const double *xq = x;
    if (d->ncut > 0) {
        /* The cut A: the cut states' columns and rows zero. */
        memcpy(sh->w, x, (size_t)nq * sizeof(double));
        for (int t = 0; t < d->ncut; t++)
            sh->w[d->cut[t]] = 0.0;
        xq = sh->w;
    }
    tsi_desc_to_points(d, sh->lin, xq, u1);
    tsi_desc_to_points(d, sh->lin, x + nq, u2);
    if (K && C) {
        tsi_desc_block_mul(d, K, u1, f, 0);
        tsi_desc_block_mul(d, C, u2, f, 1);
    } else {
        memset(f, 0, n3 * sizeof(double));
    }
    tsi_desc_local_mul(d, u1, u2, x + 2 * nq, NULL, hc, f, err);
    /* Link rows: rigid n.(a_k - a_p) = 0; elastic -dt = -(the tension
     * change), EA de + Cv l de' from the coordinates themselves (exact,
     * so zero for the error estimate). */
    for (int l = 0; l < d->nl; l++) {
        double v = 0.0;
        if (d->kind[l] == TSI_LINK_TAUT && !err) {
            const ts_link *L = &sh->sys->links[l];
            int o = sh->lin->qoff[l];
            v = L->ea * x[o + 2] + d->ca[l] * L->length * x[nq + o + 2];
        }
        rt[l] = -v;
    }
    memcpy(y, x + nq, (size_t)nq * sizeof(double));
    for (int t = 0; t < d->ncut; t++)
        y[d->cut[t]] = 0.0;
    inf_solve(sh, f, rt, hc, y + nq, y + 2 * nq);
}

/* e[3 np] = the displacement of every point per unit of tow input j
 * (any of the TS_NINPUT: a displacement, a velocity or an acceleration)
 * with the coordinates fixed: ts_linear_tow_shift of its displacement
 * channel (a translation e_a, a rotation e_a x the node's lever; node 0 of
 * a towing vehicle and the vehicles' angle points stay), as the kernel's
 * root_tow_inputs moves the points the cables start from. The order 0, 1,
 * 2 (displacement, velocity, acceleration) into *order; returns the
 * channel (TS_IN_DISP + a or TS_IN_ROT + a). */
static int tow_shift(const tsi_shift *sh, int j, double *e, int *order)
{
    const ts_descriptor *d = sh->d;
    int rot = j >= TS_TOW_ROT, c = rot ? j - TS_TOW_ROT : j;
    int chan = (rot ? TS_IN_ROT : TS_IN_DISP) + c % 3;
    *order = c / 3;
    memset(e, 0, 3 * (size_t)d->np * sizeof(double));
    for (int k = 0; k < d->nn; k++)
        ts_linear_tow_shift(sh->lin, k, chan, e + 3 * k);
    return chan;
}

/* The right-hand side of a towing vehicle's harmonic tow input on
 * displacement channel chan at s (its rate s, its acceleration s^2) into
 * sh->rhs (interleaved complex; zeroed before), for the unknowns relative
 * to it: every node but node 0 moves with the point its cable starts
 * from, x_k = x'_k + e_k (tow_shift), so the link rows keep 0 and the
 * point and controller rows take the input's own columns Gt and (K + s C
 * + s^2 M) e, (Hr + s Hv) e. */
static void root_tow_rhs(tsi_shift *sh, int chan)
{
    const ts_descriptor *d = sh->d;
    double complex s = sh->s, s2 = s * s;
    size_t n3 = 3 * (size_t)d->np, m = n3 + (size_t)d->nc;
    double *e = sh->u2, *fk = sh->u2 + m, *fc = sh->u2 + 2 * m;
    double *fm = sh->u2 + 3 * m, *hr = sh->u2 + 4 * m, *hv = sh->u2 + 5 * m;
    int order;
    tow_shift(sh, chan, e, &order);
    tsi_desc_block_mul(d, d->K, e, fk, 0);
    tsi_desc_block_mul(d, d->C, e, fc, 0);
    tsi_desc_mass_mul(d, e, fm);
    tsi_desc_local_mul(d, e, NULL, NULL, NULL, hr, NULL, 0);
    tsi_desc_local_mul(d, NULL, e, NULL, NULL, hv, NULL, 0);
    const double *Gd = d->Gt + (size_t)chan * m;
    const double *Gv = d->Gt + (size_t)(chan + 3) * m;
    const double *Ga = d->Gt + (size_t)(chan + 6) * m;
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++) {
            size_t i = 3 * (size_t)k + (size_t)a;
            double complex v = -(Gd[i] + fk[i]) - s * (Gv[i] + fc[i]) -
                               s2 * (Ga[i] + fm[i]);
            sh->rhs[2 * XR(k, a)] = creal(v);
            sh->rhs[2 * XR(k, a) + 1] = cimag(v);
        }
    for (int j = 0; j < d->nc; j++) {
        size_t i = n3 + (size_t)j;
        double complex v = Gd[i] + s * Gv[i] + s2 * Ga[i] + hr[j] +
                           s * hv[j];
        sh->rhs[2 * XC(j)] = creal(v);
        sh->rhs[2 * XC(j) + 1] = cimag(v);
    }
}

/* A frame input's right-hand side (frame input c: TS_FRAME_SPEED or
 * TS_FRAME_TURN_RATE): its column and its rate's at s, -(G_c + s
 * G_c'), in the force and rotational rows, +(G_c + s G_c') in the
 * controller rows (the residual's sign there, as root_tow_rhs); the
 * points stay. */
static void frame_rhs(tsi_shift *sh, int c)
{
    const ts_descriptor *d = sh->d;
    double complex s = sh->s;
    size_t n3 = 3 * (size_t)d->np, m = n3 + (size_t)d->nc;
    const double *G = d->Gf + (size_t)c * m;
    const double *Gr = d->Gf + (size_t)(c + 2) * m; /* its rate's */
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++) {
            size_t i = 3 * (size_t)k + (size_t)a;
            double complex v = -(G[i] + s * Gr[i]);
            sh->rhs[2 * XR(k, a)] = creal(v);
            sh->rhs[2 * XR(k, a) + 1] = cimag(v);
        }
    for (int j = 0; j < d->nc; j++) {
        size_t i = n3 + (size_t)j;
        double complex v = G[i] + s * Gr[i];
        sh->rhs[2 * XC(j)] = creal(v);
        sh->rhs[2 * XC(j) + 1] = cimag(v);
    }
}

void tsi_shift_input(tsi_shift *sh, int input, double complex *dr,
                     double complex *dt)
{
    const ts_descriptor *d = sh->d;
    const ts_system *sys = sh->sys;
    double complex s = sh->s;
    int nx = d->nx;
    double *rhs = sh->rhs;
    memset(rhs, 0, 2 * (size_t)nx * sizeof(double));
    int tow_root = -1;
    if (input >= 0 && input < TS_NINPUT && d->root >= 0) {
        root_tow_rhs(sh, input);
        tow_root = input;
        input = -1;
    }
    if (d->frame && input >= sh->lin->frame_input) {
        frame_rhs(sh, input - sh->lin->frame_input);
        input = -1;
    }
    if (input >= TS_NINPUT) {
        /* A vehicle's input: its own rows, -Ku in the force and
         * rotational rows, +Hu in the controller rows; the tow point
         * stays. */
        size_t m = 3 * (size_t)d->np + (size_t)d->nc;
        double *f = sh->u2, *hc = sh->u2 + m, *u = sh->u2 + 3 * m;
        memset(f, 0, 3 * (size_t)d->np * sizeof(double));
        memset(u, 0, (size_t)d->nin * sizeof(double));
        u[input] = 1.0;
        tsi_desc_local_mul(d, NULL, NULL, NULL, u, hc, f, 0);
        for (int k = d->p0; k < d->np; k++)
            for (int a = 0; a < 3; a++)
                rhs[2 * XR(k, a)] = -f[3 * k + a];
        for (int j = 0; j < d->nc; j++)
            rhs[2 * XC(j)] = hc[j];
        input = -1;
    }
    /* A tow input moves the tow point by d0 (a rotation: about M's
     * origin, the tow point's translation). */
    double d0[3] = {0, 0, 0};
    if (input >= 0)
        ts_linear_tow_shift(sh->lin, 0, input, d0);
    /* Point rows: -(K_k0 + s C_k0) e_input, the tow point's displacement
     * and velocity seen by its neighbours. */
    for (int k = 1; input >= 0 && k < d->np; k++)
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            if (d->bcol[b] != 0)
                continue;
            const double *Kb = d->K + 9 * (size_t)b, *Cb = d->C + 9 * (size_t)b;
            for (int a = 0; a < 3; a++) {
                double complex v = 0;
                for (int c = 0; c < 3; c++)
                    v -= (Kb[3 * a + c] + s * Cb[3 * a + c]) * d0[c];
                rhs[2 * XR(k, a)] = creal(v);
                rhs[2 * XR(k, a) + 1] = cimag(v);
            }
        }
    /* Rows of the links leaving the tow point: their constraint (or
     * tension law) on dr_k - e_input. */
    for (int l = 0; l < d->nl; l++) {
        if (sys->links[l].upper != 0 || input < 0)
            continue;
        double complex g[3] = {d->n[3 * l], d->n[3 * l + 1], d->n[3 * l + 2]};
        if (d->kind[l] == TSI_LINK_TAUT)
            tsi_desc_taut_row(d, l, s, g);
        /* A slack link's row does not see the tow point. */
        double complex gd = 0;
        for (int c = 0; d->kind[l] != TSI_LINK_SLACK && c < 3; c++)
            gd += g[c] * d0[c];
        rhs[2 * XT(l)] = creal(gd);
        rhs[2 * XT(l) + 1] = cimag(gd);
    }
    if (sh->is_complex)
        sh->klu.klu_z_solve(d->klu_symbolic, sh->numeric, nx, 1, rhs,
                            sh->common);
    else
        two_columns(sh);
    for (int c = 0; c < 3; c++)
        dr[c] = d0[c];
    for (int k = d->p0; k < d->np; k++)
        for (int c = 0; c < 3; c++)
            dr[3 * k + c] = rhs[2 * XR(k, c)] + I * rhs[2 * XR(k, c) + 1];
    /* A towing vehicle's tow input: the nodes move with the points their
     * cables start from, e (tow_shift), still at the head of sh->u2 from
     * root_tow_rhs (the solves work in sh->rhs and sh->cols). */
    if (tow_root >= 0)
        for (size_t i = 3; i < 3 * (size_t)d->nn; i++)
            dr[i] += sh->u2[i];
    for (int j = 0; j < d->nc; j++)
        dr[3 * d->np + j] = rhs[2 * XC(j)] + I * rhs[2 * XC(j) + 1];
    for (int l = 0; l < d->nl; l++)
        dt[l] = rhs[2 * XT(l)] + I * rhs[2 * XT(l) + 1];
}

void tsi_shift_apply_input(tsi_shift *sh, int j, double *col, int err)
{
    const ts_descriptor *d = sh->d;
    int nq = sh->lin->nq, nc = d->nc;
    size_t n3 = 3 * (size_t)d->np, m = n3 + (size_t)nc;
    double *f = sh->u2, *hc = sh->u2 + m, *e = sh->u2 + 2 * m;
    double *u = sh->u2 + 3 * m;
    memset(f, 0, n3 * sizeof(double));
    memset(e, 0, n3 * sizeof(double));
    if (j < TS_NINPUT) {
        /* The force change of a tow input with the coordinates fixed:
         * every node moves with a tow displacement or velocity (the
         * vehicles' angles do not). With a towing vehicle, every node
         * but node 0 moves (displaced, moving or accelerating) with the
         * point its cable starts from, the unknowns relative to that
         * motion (so the link rows keep 0), and the residual's own
         * column Gt adds what the input does there. */
        int order;
        tow_shift(sh, j, e, &order);
        if (order < 2) {
            const double *B = order == 0 ? (err ? d->Kerr : d->K)
                                         : (err ? d->Cerr : d->C);
            if (B)
                tsi_desc_block_mul(d, B, e, f, 0);
            tsi_desc_local_mul(d, order == 0 ? e : NULL,
                               order == 0 ? NULL : e, NULL, NULL, hc, NULL,
                               err);
        } else {
            if (!err)
                tsi_desc_mass_mul(d, e, f);
            memset(hc, 0, (size_t)nc * sizeof(double));
        }
        const double *G = d->root >= 0 ? (err ? d->Gterr : d->Gt) : NULL;
        for (size_t i = 0; G && i < n3; i++)
            f[i] += G[(size_t)j * m + i];
        for (int q = 0; G && q < nc; q++)
            hc[q] += G[(size_t)j * m + n3 + (size_t)q];
    } else if (j >= sh->lin->frame_input) {
        /* A frame input (without a towing vehicle): the residual's own
         * column Gf, every row. */
        const double *G = !d->frame ? NULL : err ? d->Gferr : d->Gf;
        size_t c = (size_t)(j - sh->lin->frame_input);
        for (size_t i = 0; G && i < n3; i++)
            f[i] = G[c * m + i];
        for (int q = 0; q < nc; q++)
            hc[q] = G ? G[c * m + n3 + (size_t)q] : 0.0;
    } else {
        /* A vehicle's input: its own rows only. */
        memset(u, 0, (size_t)d->nin * sizeof(double));
        u[j] = 1.0;
        tsi_desc_local_mul(d, NULL, NULL, NULL, u, hc, f, err);
    }
    memset(col, 0, (size_t)nq * sizeof(double));
    inf_solve(sh, f, NULL, hc, col + nq, col + 2 * nq);
}

void tsi_shift_tsolve(tsi_shift *sh, double complex *w)
{
    const ts_descriptor *d = sh->d;
    int nx = d->nx;
    if (sh->is_complex) {
        sh->klu.klu_z_tsolve(d->klu_symbolic, sh->numeric, nx, 1, (double *)w,
                             0, sh->common);
        return;
    }
    double *cols = sh->cols;
    for (int i = 0; i < nx; i++) {
        cols[i] = creal(w[i]);
        cols[nx + i] = cimag(w[i]);
    }
    sh->klu.klu_tsolve(d->klu_symbolic, sh->numeric, nx, 2, cols, sh->common);
    for (int i = 0; i < nx; i++)
        w[i] = cols[i] + I * cols[nx + i];
}

/* Entry i of the start b of the left vector's inverse iteration
 * (tsi_shift_eig_error): no multiple of a mode's left vector by any
 * symmetry. */
static inline double left_start_entry(int i)
{
    return 1.0 + (double)(i % 7) / 7.0;
}

/* The left vector's first iterate w = S^-T b, b the start above, with
 * sh's factors. */
static void left_first(tsi_shift *sh, double complex *w, int nx)
{
    for (int i = 0; i < nx; i++)
        w[i] = left_start_entry(i);
    tsi_shift_tsolve(sh, w);
}

/* The componentwise backward error of w = S^-T b, b the start
 * (left_start_entry) (Oettli and Prager: max_j |S^T w - b|_j / (|S|^T |w| + |b|)_j, S the
 * matrix sh factored, in sh->Sx): how far S must move, entry by entry,
 * for w to solve it exactly. The moduli as |Re| + |Im| (within a factor
 * sqrt 2 of them, and no hypot per entry). O(nnz). */
static double left_backward(const tsi_shift *sh, const double complex *w)
{
    const ts_descriptor *d = sh->d;
    const double *a = sh->Sx;
    double om = 0;
    for (int j = 0; j < d->nx; j++) {
        double b = left_start_entry(j);
        double rr = -b, ri = 0, den = b;
        for (int p = d->Sp[j]; p < d->Sp[j + 1]; p++) {
            double sr = sh->is_complex ? a[2 * p] : a[p];
            double si = sh->is_complex ? a[2 * p + 1] : 0.0;
            double wr = creal(w[d->Si[p]]), wi = cimag(w[d->Si[p]]);
            rr += sr * wr - si * wi;
            ri += sr * wi + si * wr;
            den += (fabs(sr) + fabs(si)) * (fabs(wr) + fabs(wi));
        }
        if (den > 0)
            om = fmax(om, (fabs(rr) + fabs(ri)) / den);
    }
    return om;
}

/* The error estimates' work in sh->ework (tsi_shift_eig_error: w, z, X
 * complex [nx + 1] each, x complex [m], q [nq + 1], u [2 m], m = 3 np +
 * nc), kept for the next eigenvalue. */
static int ensure_ework(tsi_shift *sh)
{
    if (sh->ework)
        return TS_OK;
    const ts_descriptor *d = sh->d;
    size_t m = 3 * (size_t)d->np + (size_t)d->nc;
    size_t nw = 6 * ((size_t)d->nx + 1) + 4 * m + (size_t)sh->lin->nq + 1;
    sh->ework = malloc(nw * sizeof(double));
    return sh->ework ? TS_OK : TS_ENOMEM;
}

/* Factor at s reusing the old pivots (refactor, test 0), judged by what
 * they give: the componentwise backward error of the first iterate w0 =
 * S^-T b of the left vector's inverse iteration (left_first,
 * left_backward; w0 at the head of sh->ework). Over SHIFT_NEAR_BACKWARD,
 * S(s) is factored afresh and w0 solved again. *fresh is set when it
 * factored afresh. Codes as refactor's; err may be NULL. */
static int refactor_judged(tsi_shift *sh, const ts_linear *lin,
                           double complex s, int *fresh, ts_err *err)
{
    int rc = refactor(sh, lin, s, 0, fresh, err);
    if (rc == TS_OK && ensure_ework(sh) != TS_OK)
        rc = ts_fail(err, TS_ENOMEM, "shift: out of memory");
    if (rc != TS_OK)
        return rc;
    double complex *w0 = (double complex *)sh->ework;
    int nx = sh->d->nx;
    left_first(sh, w0, nx);
    if (*fresh || left_backward(sh, w0) <= SHIFT_NEAR_BACKWARD)
        return TS_OK;
    *fresh = 1;
    rc = afresh(sh, sh->is_complex, err);
    if (rc == TS_OK)
        left_first(sh, w0, nx);
    return rc;
}

int tsi_shift_refactor_judged(tsi_shift *sh, const ts_linear *lin,
                              double complex s, int *fresh, ts_err *err)
{
    int f = 1, rc = refactor_judged(sh, lin, s, &f, err);
    if (fresh)
        *fresh = f;
    return rc;
}

/* Scale w[m] to largest |Re| + |Im| 1 (w nonzero): the estimates are of
 * w's direction only, and this needs no hypot per entry. */
static void unit_max(double complex *w, int m)
{
    double big = 0;
    for (int i = 0; i < m; i++)
        big = fmax(big, fabs(creal(w[i])) + fabs(cimag(w[i])));
    if (big > 0 && isfinite(big))
        for (int i = 0; i < m; i++)
            w[i] /= big;
}

/* w^T S(lam) X and w^T S'(lam) X (S'(s) = Sc + 2 s Sm) from S's parts
 * in sh (Sk, Sc, Sm: S(s) = Sk + s Sc + s^2 Sm), X[nx] the unknowns
 * (points and controller states; the tensions' entries zero, skipped),
 * summed against w[nx]: one pass, O(nnz). */
static void pencil_forms(const tsi_shift *sh, const double complex *w,
                         const double complex *X, double complex lam,
                         double complex *form, double complex *dform)
{
    const ts_descriptor *d = sh->d;
    const double *Sk = sh->Sk, *Sc = sh->Sc, *Sm = sh->Sm;
    double complex sum = 0, dsum = 0, lam2 = 2.0 * lam;
    for (int j = 0; j < d->nx; j++) {
        if (X[j] == 0)
            continue;
        double complex a = 0, b = 0;
        for (int p = d->Sp[j]; p < d->Sp[j + 1]; p++) {
            double complex wi = w[d->Si[p]];
            a += wi * (Sk[p] + lam * (Sc[p] + lam * Sm[p]));
            b += wi * (Sc[p] + lam2 * Sm[p]);
        }
        sum += a * X[j];
        dsum += b * X[j];
    }
    *form = sum;
    *dform = dsum;
}

/* z[nx] = S'(lam)^T w[nx], S'(s) = Sc + 2 s Sm from S's parts in sh
 * (zero on the tensions' columns). O(nnz). */
static void pencil_dtmul(const tsi_shift *sh, const double complex *w,
                         double complex lam, double complex *z)
{
    const ts_descriptor *d = sh->d;
    const double *Sc = sh->Sc, *Sm = sh->Sm;
    for (int j = 0; j < d->nx; j++) {
        double complex sum = 0;
        for (int p = d->Sp[j]; p < d->Sp[j + 1]; p++)
            sum += w[d->Si[p]] * (Sc[p] + 2.0 * lam * Sm[p]);
        z[j] = sum;
    }
}

int tsi_shift_eig_error(tsi_shift *sh, const ts_linear *lin,
                        double complex lam, const double complex v[],
                        double *dlam, double *ritz, ts_err *err)
{
    const ts_descriptor *d = lin->desc;
    *dlam = NAN;
    *ritz = NAN;
    if (!d)
        return ts_fail(err, TS_EINVAL, "shift: the linear model has no "
                       "sparse form");
    if (!d->Kerr || !d->rnoise)
        return TS_OK;
    int nx = d->nx, nq = lin->nq, nc = d->nc;
    size_t m = 3 * (size_t)d->np + (size_t)nc;
    /* S(lam), or a shift beside it when lam is an eigenvalue to working
     * precision (inverse iteration needs only to be near), refactored
     * with the previous eigenvalue's pivots; the first solve with them
     * judges them: over SHIFT_NEAR_BACKWARD of backward error, S(lam)
     * is factored afresh (doc/linear.md section 3). The work (w, z, X
     * complex [nx + 1] each, x complex [m], q [nq + 1], u [2 m]) and S's
     * parts are kept in sh for the next eigenvalue. */
    int rc = TS_ESINGULAR, fresh = 1;
    double nudge = 1e-10 * (cabs(lam) > 0 ? cabs(lam) : 1.0);
    for (int t = 0; t < 3 && rc == TS_ESINGULAR; t++, nudge *= 100.0) {
        double complex st = t == 0 ? lam : lam + nudge;
        rc = refactor_judged(sh, lin, st, &fresh, NULL);
        if (rc == TS_OK && ensure_parts(sh, NULL) != TS_OK)
            rc = TS_ENOMEM;
    }
    if (rc == TS_ENOMEM)
        return ts_fail(err, rc, "eigen: out of memory for the error "
                       "estimate");
    if (rc == TS_ESINGULAR)
        return ts_fail(err, rc, "eigen: the pencil is singular beside "
                       "%g%+gi 1/s", creal(lam), cimag(lam));
    if (rc != TS_OK)
        return ts_fail(err, rc, "eigen: KLU failed at %g%+gi 1/s",
                       creal(lam), cimag(lam));
    double complex *w = (double complex *)sh->ework;
    double complex *z = w + nx + 1, *X = z + nx + 1, *x = X + nx + 1;
    double *q = (double *)(x + m), *u = q + nq + 1;
    memset(X, 0, ((size_t)nx + 1) * sizeof *X);
    /* Inverse iteration for the left vector of the quadratic pencil:
     * S(lam)^-T b grows along w by x^T b / (lam - lam*), so from the
     * second step on b = S'(lam)^T w (x^T S'^T w = w^T S' x is the
     * pencil's normalisation, never zero for a simple eigenvalue, while
     * w^T x itself may vanish: then S^-T w would not grow along w at
     * all). */
    for (int it = 0; it < 2; it++) {
        if (it > 0) {
            /* (The first solve is done above.) */
            pencil_dtmul(sh, w, lam, z);
            memcpy(w, z, (size_t)nx * sizeof *w);
            tsi_shift_tsolve(sh, w);
        }
        unit_max(w, nx);
    }
    /* The right vector as point displacements and controller states (x),
     * and in the unknowns (X; tensions 0: S' has no tension columns). */
    for (int part = 0; part < 2; part++) {
        for (int i = 0; i < nq; i++)
            q[i] = part ? cimag(v[i]) : creal(v[i]);
        /* A cut state (d->cut): the eigenvector of the whole model holds
         * it as the integral of its rate, v_j = v_(nq+j) / lam (zero in
         * the cut model's); the pencil is the whole model's. */
        for (int t = 0; t < d->ncut && cabs(lam) > 0; t++) {
            int j = d->cut[t];
            double complex vj = v[nq + j] / lam;
            if (isfinite(creal(vj)) && isfinite(cimag(vj)))
                q[j] = part ? cimag(vj) : creal(vj);
        }
        tsi_desc_to_points(d, lin, q, u + part * m);
    }
    size_t n3 = 3 * (size_t)d->np;
    for (size_t i = 0; i < n3; i++)
        x[i] = u[i] + I * u[m + i];
    for (int j = 0; j < nc; j++)
        x[n3 + j] = v[2 * nq + j];
    for (int k = d->p0; k < d->np; k++)
        for (int a = 0; a < 3; a++)
            X[XR(k, a)] = x[3 * k + a];
    for (int j = 0; j < nc; j++)
        X[XC(j)] = x[n3 + j];
    /* w^T S'(lam) X, the normalisation, and w^T S(lam) X. */
    double complex num, den;
    pencil_forms(sh, w, X, lam, &num, &den);
    double tr, ro;
    tsi_desc_error_terms(d, w, x, lam, &tr, &ro);
    *dlam = cabs(den) > 0 ? (tr + ro) / cabs(den) : INFINITY;
    /* The Ritz value's own error: the pencil's Newton correction. */
    *ritz = cabs(den) > 0 ? cabs(num) / cabs(den) : INFINITY;
    return TS_OK;
}

/* ---- The linear simulation's outputs ------------------------------------ */

void tsi_shift_tensions(const tsi_shift *sh, double *dt)
{
    const ts_descriptor *d = sh->d;
    for (int l = 0; l < d->nl; l++)
        dt[l] = sh->rhs[XT(l)];
}

void tsi_shift_outputs(tsi_shift *sh, const double *z, const double *v,
                       int m, double *out)
{
    const ts_descriptor *d = sh->d;
    const ts_linear *lin = sh->lin;
    int nq = lin->nq;
    size_t n3 = 3 * (size_t)d->np + (size_t)d->nc;
    double *p = sh->u1, *pv = sh->u1 + n3;
    const double *c = z + 2 * nq;
    tsi_desc_to_points(d, lin, z, p);
    tsi_desc_to_points(d, lin, z + nq, pv);
    for (int iv = 0; iv < d->nv; iv++) {
        const tsi_vehicle_layout *L = &d->vl[iv];
        int ncol = TSI_LV_C + L->nc + L->nin;
        /* The tow inputs move the vehicle's node with the coordinates
         * held (ts_linear_tow_shift), its displacement channels the
         * displacement and its rate channels the velocity; its angles
         * stay. */
        double dn[3] = {0, 0, 0}, vn[3] = {0, 0, 0};
        for (int j = 0; j < m && j < TS_NINPUT; j++) {
            int rot = j >= TS_TOW_ROT, cj = rot ? j - TS_TOW_ROT : j;
            int order = cj / 3;
            if (v[j] == 0 || order > 1)
                continue;
            double e[3];
            ts_linear_tow_shift(lin, L->node,
                                (rot ? TS_IN_ROT : TS_IN_DISP) + cj % 3, e);
            for (int a = 0; a < 3; a++)
                (order ? vn : dn)[a] += e[a] * v[j];
        }
        for (int r = 0; r < L->nout; r++) {
            const double *row = d->Ov + d->ov_off[iv] + r * ncol;
            double acc = 0;
            for (int lc = 0; lc < 3; lc++) {
                int i = 3 * L->node + lc, th = 3 * (d->nn + iv) + lc;
                acc += row[TSI_LV_R + lc] * (p[i] + dn[lc]) +
                       row[TSI_LV_TH + lc] * p[th] +
                       row[TSI_LV_V + lc] * (pv[i] + vn[lc]) +
                       row[TSI_LV_W + lc] * pv[th];
            }
            for (int k = 0; k < L->nc; k++)
                acc += row[TSI_LV_C + k] * c[L->c0 + k];
            for (int k = 0; k < L->nin; k++)
                if (L->in0 + k < m)
                    acc += row[TSI_LV_C + L->nc + k] * v[L->in0 + k];
            out[L->out0 + r] = acc;
        }
    }
}
