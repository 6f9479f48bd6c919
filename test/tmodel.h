/* tmodel.h: model pieces the tests write out independently of lib/, shared
 * by several test programs: the submerged fractions of doc/model.md section 3
 * and doc/kernel.md, and one classical RK4 step of the kernel. The tests
 * check the library against these, so they must not call into it (except
 * the kernel evaluation the RK4 step integrates, and the energies an
 * energy drift compares). */
#ifndef TOWSTAB_TMODEL_H
#define TOWSTAB_TMODEL_H

#include <math.h>
#include <stdlib.h>

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

/* A 3-D state of every link of kernel k in y[2 nq]: angles and rates in
 * each link's chart, all different. */
static inline void tm_link_state(const ts_kernel *k, int nlinks, double *y)
{
    int nq = ts_kernel_nq(k);
    for (int l = 0; l < nlinks; l++) {
        int o = ts_kernel_link_offset(k, l);
        y[o] = 0.5 + 0.3 * sin(1.7 * l);
        y[o + 1] = 0.4 * cos(2.3 * l + 1);
        y[nq + o] = 0.5 * cos(l + 0.2);
        y[nq + o + 1] = -0.4 * sin(3.1 * l);
    }
}

/* The largest drift |E(t) - E(0)| of the kinetic plus potential energy
 * (J) over T s of RK4 at step h from y[n] (advanced in place), E(0) into
 * *E0; INFINITY when a step fails. */
static inline double tm_energy_drift(ts_kernel *k, double *y, double h,
                                     double T, double *E0)
{
    int n = ts_kernel_nstate(k);
    double *w = malloc(5 * (size_t)n * sizeof(double));
    double worst = w ? 0.0 : INFINITY;
    ts_kernel_eval(k, y, NULL, w);
    *E0 = ts_kernel_kinetic_energy(k) + ts_kernel_potential_energy(k);
    int steps = (int)lround(T / h);
    for (int i = 0; i < steps && w; i++) {
        if (rk4_step(k, y, h, n, w) != TS_OK) {
            worst = INFINITY;
            break;
        }
        ts_kernel_eval(k, y, NULL, w);
        double E = ts_kernel_kinetic_energy(k) + ts_kernel_potential_energy(k);
        worst = fmax(worst, fabs(E - *E0));
    }
    free(w);
    return worst;
}

#endif
