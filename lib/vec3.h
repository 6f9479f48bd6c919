/* vec3.h: inline 3-vector and 3x3 symmetric-matrix helpers (internal).
 * Symmetric matrices are stored as 6 numbers: xx, yy, zz, xy, xz, yz. */
#ifndef TOWSTAB_VEC3_H
#define TOWSTAB_VEC3_H

#include <math.h>

static inline double v3_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline double v3_norm(const double a[3]) { return sqrt(v3_dot(a, a)); }

static inline void v3_cross(const double a[3], const double b[3], double c[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    c[0] = x;
    c[1] = y;
    c[2] = z;
}

/* y += s x */
static inline void v3_axpy(double s, const double x[3], double y[3])
{
    y[0] += s * x[0];
    y[1] += s * x[1];
    y[2] += s * x[2];
}

static inline void v3_set(double y[3], double a, double b, double c)
{
    y[0] = a;
    y[1] = b;
    y[2] = c;
}

static inline void v3_copy(const double x[3], double y[3])
{
    y[0] = x[0];
    y[1] = x[1];
    y[2] = x[2];
}

/* S += s (I - n n^T) */
static inline void sym3_add_normal(double S[6], double s, const double n[3])
{
    S[0] += s * (1 - n[0] * n[0]);
    S[1] += s * (1 - n[1] * n[1]);
    S[2] += s * (1 - n[2] * n[2]);
    S[3] -= s * n[0] * n[1];
    S[4] -= s * n[0] * n[2];
    S[5] -= s * n[1] * n[2];
}

/* S += s n n^T */
static inline void sym3_add_outer(double S[6], double s, const double n[3])
{
    S[0] += s * n[0] * n[0];
    S[1] += s * n[1] * n[1];
    S[2] += s * n[2] * n[2];
    S[3] += s * n[0] * n[1];
    S[4] += s * n[0] * n[2];
    S[5] += s * n[1] * n[2];
}

/* y = S x */
static inline void sym3_mul(const double S[6], const double x[3], double y[3])
{
    double a = S[0] * x[0] + S[3] * x[1] + S[4] * x[2];
    double b = S[3] * x[0] + S[1] * x[1] + S[5] * x[2];
    double c = S[4] * x[0] + S[5] * x[1] + S[2] * x[2];
    y[0] = a;
    y[1] = b;
    y[2] = c;
}

/* Cholesky factor of a symmetric positive definite S into L (lower,
 * stored l00 l11 l22 l10 l20 l21). Returns 0, or -1 if S is not positive
 * definite. */
static inline int sym3_chol(const double S[6], double L[6])
{
    double l00 = S[0];
    if (!(l00 > 0))
        return -1;
    l00 = sqrt(l00);
    double l10 = S[3] / l00, l20 = S[4] / l00;
    double d1 = S[1] - l10 * l10;
    if (!(d1 > 0))
        return -1;
    double l11 = sqrt(d1);
    double l21 = (S[5] - l20 * l10) / l11;
    double d2 = S[2] - l20 * l20 - l21 * l21;
    if (!(d2 > 0))
        return -1;
    L[0] = l00;
    L[1] = l11;
    L[2] = sqrt(d2);
    L[3] = l10;
    L[4] = l20;
    L[5] = l21;
    return 0;
}

/* Solve (L L^T) x = b in place. */
static inline void sym3_chol_solve(const double L[6], double b[3])
{
    double y0 = b[0] / L[0];
    double y1 = (b[1] - L[3] * y0) / L[1];
    double y2 = (b[2] - L[4] * y0 - L[5] * y1) / L[2];
    double x2 = y2 / L[2];
    double x1 = (y1 - L[5] * x2) / L[1];
    double x0 = (y0 - L[3] * x1 - L[4] * x2) / L[0];
    b[0] = x0;
    b[1] = x1;
    b[2] = x2;
}

/* y = R x (row-major R) */
static inline void mat3_mul(const double R[9], const double x[3], double y[3])
{
    y[0] = R[0] * x[0] + R[1] * x[1] + R[2] * x[2];
    y[1] = R[3] * x[0] + R[4] * x[1] + R[5] * x[2];
    y[2] = R[6] * x[0] + R[7] * x[1] + R[8] * x[2];
}

/* y = R^T x */
static inline void mat3_tmul(const double R[9], const double x[3], double y[3])
{
    y[0] = R[0] * x[0] + R[3] * x[1] + R[6] * x[2];
    y[1] = R[1] * x[0] + R[4] * x[1] + R[7] * x[2];
    y[2] = R[2] * x[0] + R[5] * x[1] + R[8] * x[2];
}

/* A chart whose reference direction (-x) maps to n: columns -n, u, v with
 * (u, v) completing a right-handed orthonormal frame. */
static inline void tsi_chart_centred(const double n[3], double R[9])
{
    double a[3] = {-n[0], -n[1], -n[2]}, u[3], v[3];
    /* Pick the coordinate axis least aligned with n to build u. */
    double ax[3] = {0, 0, 0};
    int m = 0;
    for (int j = 1; j < 3; j++)
        if (fabs(n[j]) < fabs(n[m]))
            m = j;
    ax[m] = 1.0;
    v3_cross(ax, a, v);
    double nv = v3_norm(v);
    v[0] /= nv;
    v[1] /= nv;
    v[2] /= nv;
    v3_cross(v, a, u); /* a x u = v, so (a, u, v) is right-handed */
    for (int j = 0; j < 3; j++) {
        R[3 * j] = a[j];
        R[3 * j + 1] = u[j];
        R[3 * j + 2] = v[j];
    }
}

#endif
