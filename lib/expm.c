/* expm.c: the matrix exponential by scaling and squaring with Pade
 * approximants (lib/expm.h).
 *
 * Reference: N. J. Higham, "The scaling and squaring method for the matrix
 * exponential revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005, 1179-1193,
 * algorithm 2.3 (the method of MATLAB's expm up to R2015).
 *
 * Algorithm. With theta_m the largest ||A||_1 for which the [m/m] Pade
 * approximant r_m has backward error below 2^-53 (Higham's table 2.3):
 * if ||A||_1 <= theta_m for m in {3, 5, 7, 9}, r_m(A) is used directly;
 * otherwise A is scaled by 2^-s with s = ceil(log2(||A||_1 / theta_13)),
 * r_13 is formed and squared s times. r_m = q_m^-1 p_m with p_m = U + V,
 * q_m = V - U, U holding the odd and V the even powers; for m = 13,
 *   U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I],
 *   V = A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I,
 * six products. The solve (V - U) E = (U + V) is one LAPACK dgesv; products
 * are BLAS dgemm. Memory: six n x n work matrices. The coefficients b_j
 * of p_m are (2m - j)! m! / ((2m)! j! (m - j)!), scaled to b_m = 1.
 */
#include "expm.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lazylib.h"

/* Higham 2005, table 2.3 (double precision). */
static const double theta[5] = {1.495585217958292e-2, 2.539398330063230e-1,
                                 9.504178996162932e-1, 2.097847961257068e0,
                                 5.371920351148152e0};
static const int degree[5] = {3, 5, 7, 9, 13};

static const double b3[4] = {120., 60., 12., 1.};
static const double b5[6] = {30240., 15120., 3360., 420., 30., 1.};
static const double b7[8] = {17297280., 8648640., 1995840., 277200.,
                             25200.,    1512.,    56.,      1.};
static const double b9[10] = {17643225600., 8821612800., 2075673600.,
                              302702400.,   30270240.,   2162160.,
                              110880.,      3960.,       90.,
                              1.};
static const double b13[14] = {
    64764752532480000., 32382376266240000., 7771770303897600.,
    1187353796428800.,  129060195264000.,   10559470521600.,
    670442572800.,      33522128640.,       1323241920.,
    40840800.,          960960.,            16380.,
    182.,               1.};

/* C = A B (n x n, column-major). */
static void mul(const tsi_lapack *la, int n, const double *A,
                const double *B, double *C)
{
    const double one = 1.0, zero = 0.0;
    la->dgemm_("N", "N", &n, &n, &n, &one, A, &n, B, &n, &zero, C, &n, 1, 1);
}

static double norm1(int n, const double *A)
{
    double best = 0.0;
    for (int j = 0; j < n; j++) {
        double s = 0.0;
        for (int i = 0; i < n; i++)
            s += fabs(A[i + (size_t)j * n]);
        if (!isfinite(s))
            return s; /* NaN or infinity: refused by the caller */
        if (s > best)
            best = s;
    }
    return best;
}

int tsi_expm(int n, const double *A, double *E, int *squarings, ts_err *err)
{
    if (squarings)
        *squarings = 0;
    if (n < 1)
        return ts_fail(err, TS_EINVAL, "expm: order must be >= 1, got %d", n);
    double anorm = norm1(n, A);
    if (!isfinite(anorm))
        return ts_fail(err, TS_EINVAL, "expm: the matrix has a non-finite "
                       "entry");
    tsi_lapack la;
    if (tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    size_t nn = (size_t)n * (size_t)n;
    double *work = malloc(6 * nn * sizeof(double));
    int *ipiv = malloc((size_t)n * sizeof(int));
    if (!work || !ipiv) {
        free(work);
        free(ipiv);
        return ts_fail_nomem(err, 6 * 8.0 * (double)nn, "fewer links, or "
                             "linear_method ode", "expm: out of memory for "
                             "the exponential of order %d", n);
    }
    double *As = work, *A2 = work + nn, *A4 = work + 2 * nn,
           *A6 = work + 3 * nn, *U = work + 4 * nn, *V = work + 5 * nn;

    int m = -1;
    for (int i = 0; i < 4; i++)
        if (anorm <= theta[i]) {
            m = i;
            break;
        }
    int s = 0;
    memcpy(As, A, nn * sizeof(double));
    if (m < 0) {
        m = 4;
        if (anorm > theta[4]) {
            s = (int)ceil(log2(anorm / theta[4]));
            double scale = ldexp(1.0, -s);
            for (size_t i = 0; i < nn; i++)
                As[i] *= scale;
        }
    }
    mul(&la, n, As, As, A2);
    /* E temporarily holds the odd-power sum before U = A * sum. */
    if (degree[m] == 13) {
        mul(&la, n, A2, A2, A4);
        mul(&la, n, A4, A2, A6);
        const double *b = b13;
        for (size_t i = 0; i < nn; i++) {
            U[i] = b[13] * A6[i] + b[11] * A4[i] + b[9] * A2[i];
            V[i] = b[12] * A6[i] + b[10] * A4[i] + b[8] * A2[i];
        }
        mul(&la, n, A6, U, E);
        for (size_t i = 0; i < nn; i++)
            E[i] += b[7] * A6[i] + b[5] * A4[i] + b[3] * A2[i];
        for (int i = 0; i < n; i++)
            E[i + (size_t)i * n] += b[1];
        mul(&la, n, As, E, U);
        mul(&la, n, A6, V, E);
        for (size_t i = 0; i < nn; i++)
            V[i] = E[i] + b[6] * A6[i] + b[4] * A4[i] + b[2] * A2[i];
        for (int i = 0; i < n; i++)
            V[i + (size_t)i * n] += b[0];
    } else {
        const double *b = degree[m] == 3 ? b3
                          : degree[m] == 5 ? b5
                          : degree[m] == 7 ? b7 : b9;
        int deg = degree[m];
        /* Powers A2, A4 = A2^2, ... kept one at a time: P holds A^(2k). */
        double *P = A4, *Q = A6;
        memcpy(P, A2, nn * sizeof(double));
        for (size_t i = 0; i < nn; i++) {
            E[i] = b[3] * A2[i];
            V[i] = b[2] * A2[i];
        }
        for (int i = 0; i < n; i++) {
            E[i + (size_t)i * n] += b[1];
            V[i + (size_t)i * n] += b[0];
        }
        for (int k = 4; k <= deg - 1; k += 2) {
            mul(&la, n, P, A2, Q);
            double *t = P;
            P = Q;
            Q = t;
            for (size_t i = 0; i < nn; i++) {
                E[i] += b[k + 1] * P[i];
                V[i] += b[k] * P[i];
            }
        }
        mul(&la, n, As, E, U);
    }
    /* Solve (V - U) X = (V + U). */
    for (size_t i = 0; i < nn; i++) {
        double u = U[i], v = V[i];
        A2[i] = v - u;
        E[i] = v + u;
    }
    int info = 0;
    la.dgesv_(&n, &n, A2, &n, ipiv, E, &n, &info);
    if (info != 0) {
        free(work);
        free(ipiv);
        return ts_fail(err, TS_ELAPACK, "expm: dgesv failed on the Pade "
                       "denominator (info %d, order %d, ||A||_1 %g)", info, n,
                       anorm);
    }
    for (int k = 0; k < s; k++) {
        mul(&la, n, E, E, A2);
        memcpy(E, A2, nn * sizeof(double));
    }
    if (squarings)
        *squarings = s;
    free(work);
    free(ipiv);
    return TS_OK;
}
