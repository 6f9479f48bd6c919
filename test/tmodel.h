/* tmodel.h: model pieces the tests write out independently of lib/, shared
 * by several test programs: the submerged fractions of doc/model.md section 3
 * and doc/kernel.md, and one classical RK4 step of the kernel. The tests
 * check the library against these, so they must not call into it (except
 * the kernel evaluation the RK4 step integrates). */
#ifndef TOWSTAB_TMODEL_H
#define TOWSTAB_TMODEL_H

#include <math.h>

#include "towstab/kernel.h"

/* Fraction of a link below z = 0, linear in its end depths. */
static inline double link_sub(double za, double zb)
{
    if (za >= 0 && zb >= 0)
        return 1;
    if (za <= 0 && zb <= 0)
        return 0;
    return fmax(za, zb) / fabs(za - zb);
}

/* Submerged volume fraction of a sphere of diameter D at depth z (the
 * spherical cap below the surface). */
static inline double sphere_sub(double z, double D)
{
    double R = D / 2, h = z + R;
    if (h <= 0)
        return 0;
    if (h >= D)
        return 1;
    return h * h * (3 * R - h) / (4 * R * R * R);
}

/* One classical RK4 step of length h of y' = f(y) (kernel k, no input),
 * y[n] in place; w[5 n] is scratch. Returns the kernel's code. */
static inline int rk4_step(ts_kernel *k, double *y, double h, int n,
                           double *w)
{
    double *k1 = w, *k2 = w + n, *k3 = w + 2 * n, *k4 = w + 3 * n,
           *yt = w + 4 * n;
    int rc = ts_kernel_eval(k, y, NULL, k1);
    for (int i = 0; i < n && !rc; i++)
        yt[i] = y[i] + 0.5 * h * k1[i];
    if (!rc)
        rc = ts_kernel_eval(k, yt, NULL, k2);
    for (int i = 0; i < n && !rc; i++)
        yt[i] = y[i] + 0.5 * h * k2[i];
    if (!rc)
        rc = ts_kernel_eval(k, yt, NULL, k3);
    for (int i = 0; i < n && !rc; i++)
        yt[i] = y[i] + h * k3[i];
    if (!rc)
        rc = ts_kernel_eval(k, yt, NULL, k4);
    for (int i = 0; i < n && !rc; i++)
        y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    return rc;
}

#endif
