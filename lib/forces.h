/* forces.h: the external loads of doc/model.md section 3, shared by the kernel
 * and the equilibrium solver so that the physics is written once (internal).
 *
 * Conventions: M frame (x forward, y starboard, z down), SI. The fluid is at
 * rest in the inertial frame apart from a uniform current; `w` is the
 * velocity of a point relative to the water, in M components.
 */
#ifndef TOWSTAB_FORCES_H
#define TOWSTAB_FORCES_H

#include <math.h>

#include "towstab/kernel.h"
#include "towstab/system.h"
#include "vec3.h"

/* Velocity relative to the water of a point at r moving at rd relative to
 * M: w = V e_x + Omega e_z x r + rd - v_c (doc/model.md section 1). */
static inline void tsi_rel_velocity(const ts_frame *f, const double r[3],
                                    const double rd[3], double w[3])
{
    w[0] = f->speed - f->turn_rate * r[1] + rd[0] - f->current[0];
    w[1] = f->turn_rate * r[0] + rd[1] - f->current[1];
    w[2] = rd[2] - f->current[2];
}

/* The frame part of the inertial acceleration of a point at r moving at rd
 * relative to M (everything but r''):
 * V' e_x + Omega V e_y + Omega' e_z x r + Omega e_z x (Omega e_z x r)
 * + 2 Omega e_z x rd. */
static inline void tsi_frame_accel(const ts_frame *f, const double r[3],
                                   const double rd[3], double a[3])
{
    double W = f->turn_rate, W2 = W * W, Wd = f->turn_accel;
    a[0] = f->speed_rate - Wd * r[1] - W2 * r[0] - 2 * W * rd[1];
    a[1] = W * f->speed + Wd * r[0] - W2 * r[1] + 2 * W * rd[0];
    a[2] = 0.0;
}

/* Fraction of a straight link below the surface z = 0, linear in the end
 * depths (doc/model.md section 3). Kinked where an end crosses z = 0. */
static inline double tsi_link_submerged(double z_upper, double z_lower)
{
    if (z_upper >= 0 && z_lower >= 0)
        return 1.0;
    if (z_upper <= 0 && z_lower <= 0)
        return 0.0;
    double deep = z_upper > z_lower ? z_upper : z_lower;
    return deep / fabs(z_upper - z_lower);
}

/* Submerged volume fraction of a sphere of diameter D centred at depth z:
 * the spherical cap below z = 0, h^2 (3R - h) / (4 R^3) with h the
 * submerged height clipped to [0, 2R]. It is 0 for a sphere wholly in air,
 * 1 when wholly under water, and continuous in between (doc/kernel.md). */
static inline double tsi_sphere_submerged(double z, double D)
{
    if (!(D > 0))
        return z > 0 ? 1.0 : 0.0;
    double R = 0.5 * D, h = z + R;
    if (h <= 0)
        return 0.0;
    if (h >= 2 * R)
        return 1.0;
    return h * h * (3 * R - h) / (4 * R * R * R);
}

/* Loading functions of Driscoll & Nahon as used by Buckham et al. 2003,
 * h the angle between link and flow in [0, pi/2]. */
static inline double tsi_loading_fp(double h)
{
    return 0.5 - 0.1 * cos(h) + 0.1 * sin(h) - 0.4 * cos(2 * h) +
           0.11 * sin(2 * h);
}

static inline double tsi_loading_fq(double h)
{
    return 0.01 * (2.008 + h * (-0.3858 + h * (1.9159 + h * (-4.1615 +
                   h * (3.5064 - 1.1873 * h)))));
}

/* Total external load on a link of direction n (weight, buoyancy, drag;
 * doc/model.md section 3): to be split half to each end. `w` is the
 * velocity of the link midpoint relative to the water, z_upper/z_lower the
 * end depths.
 * Writes the submerged fraction to *s. */
static inline void tsi_link_load(const ts_link *L, double rho, double g,
                                 const double n[3], double z_upper,
                                 double z_lower, const double w[3],
                                 double F[3], double *s)
{
    double sub = tsi_link_submerged(z_upper, z_lower);
    double l = L->length, d = L->diameter;
    F[0] = 0.0;
    F[1] = 0.0;
    F[2] = (L->mass - sub * rho * (M_PI * 0.25 * d * d) * l) * g;
    *s = sub;
    if (!(sub > 0) || !(rho > 0))
        return;
    double wn_dot = v3_dot(w, n);
    double wt[3] = {wn_dot * n[0], wn_dot * n[1], wn_dot * n[2]};
    double wn[3] = {w[0] - wt[0], w[1] - wt[1], w[2] - wt[2]};
    double qn = 0.5 * rho * d * l * sub; /* 1/2 rho d l s */
    if (L->drag_law == TS_DRAG_STANDARD) {
        double cn = qn * L->cdn * v3_norm(wn);
        double ct = qn * M_PI * L->cdt * fabs(wn_dot);
        F[0] -= cn * wn[0] + ct * wt[0];
        F[1] -= cn * wn[1] + ct * wt[1];
        F[2] -= cn * wn[2] + ct * wt[2];
    } else {
        double w2 = v3_dot(w, w);
        if (!(w2 > 0))
            return;
        double wnn = v3_norm(wn);
        double h = atan2(wnn, fabs(wn_dot)); /* in [0, pi/2] */
        double fp = tsi_loading_fp(h), fq = tsi_loading_fq(h);
        double base = qn * L->cdn * w2;
        if (wnn > 0) {
            double a = base * fp / wnn;
            F[0] -= a * wn[0];
            F[1] -= a * wn[1];
            F[2] -= a * wn[2];
        }
        double sg = wn_dot > 0 ? 1.0 : (wn_dot < 0 ? -1.0 : 0.0);
        double b = base * fq * sg;
        F[0] -= b * n[0];
        F[1] -= b * n[1];
        F[2] -= b * n[2];
    }
}

/* Submerged fraction of a cylinder of diameter D whose axis is at depth
 * z, taken as that of a horizontal one: the circular segment below z = 0,
 * (R^2 acos((R - h)/R) - (R - h) sqrt(2 R h - h^2)) / (pi R^2), h = z + R
 * clipped to [0, 2R]. Continuous, 0 in air and 1 under water. */
static inline double tsi_cylinder_submerged(double z, double D)
{
    double R = 0.5 * D, h = z + R;
    if (h <= 0)
        return 0.0;
    if (h >= 2 * R)
        return 1.0;
    double u = R - h;
    return (R * R * acos(u / R) - u * sqrt(2 * R * h - h * h)) /
           (M_PI * R * R);
}

/* Submerged fraction of a body whose node is at depth z. */
static inline double tsi_body_submerged(const ts_body *b, double z)
{
    switch (b->type) {
    case TS_BODY_SPHERE: return tsi_sphere_submerged(z, b->diameter);
    case TS_BODY_CYLINDER: return tsi_cylinder_submerged(z, b->diameter);
    default: return 0.0;
    }
}

/* Load on a body at depth z moving at w relative to the water: weight,
 * and buoyancy and drag times the submerged fraction (written to *frac).
 * A sphere's drag is on its frontal area; a cylinder's is split along its
 * unit axis `axis` (axial, on pi D^2/4) and across it (on D times its
 * length). A junction carries its weight only. */
static inline void tsi_body_load(const ts_body *b, double rho, double g,
                                 double z, const double w[3],
                                 const double axis[3], double F[3],
                                 double *frac)
{
    F[0] = 0.0;
    F[1] = 0.0;
    F[2] = b->mass * g;
    *frac = 0.0;
    if (b->type == TS_BODY_JUNCTION || !(rho > 0))
        return;
    double D = b->diameter;
    double fr = tsi_body_submerged(b, z);
    *frac = fr;
    if (!(fr > 0))
        return;
    F[2] -= fr * rho * g * ts_body_volume(b);
    if (b->type == TS_BODY_SPHERE) {
        double c = 0.5 * rho * b->cd * (M_PI * 0.25 * D * D) * fr * v3_norm(w);
        v3_axpy(-c, w, F);
        return;
    }
    double wa = v3_dot(w, axis), wc[3];
    for (int j = 0; j < 3; j++)
        wc[j] = w[j] - wa * axis[j];
    double ca = 0.5 * rho * fr * b->cd * (M_PI * 0.25 * D * D) * fabs(wa);
    double cc = 0.5 * rho * fr * b->cd_cross * D * b->length * v3_norm(wc);
    for (int j = 0; j < 3; j++)
        F[j] -= ca * wa * axis[j] + cc * wc[j];
}

/* Add a body's added-mass matrix to the symmetric S: Ca rho V f I for a
 * sphere; f rho V (Ca a a^T + Ca_cross (I - a a^T)) for a cylinder of
 * axis a. */
static inline void tsi_body_added_mass(const ts_body *b, double rho,
                                       double frac, const double axis[3],
                                       double S[6])
{
    double m = frac * rho * ts_body_volume(b);
    if (!(m > 0))
        return;
    if (b->type == TS_BODY_SPHERE) {
        S[0] += b->ca * m;
        S[1] += b->ca * m;
        S[2] += b->ca * m;
    } else if (b->type == TS_BODY_CYLINDER) {
        sym3_add_normal(S, b->ca_cross * m, axis);
        sym3_add_outer(S, b->ca * m, axis);
    }
}

/* Bending at a joint between link a (above, direction na) and link b
 * (below, nb) with U = 1/2 (EI / lbar) alpha^2, alpha the angle between
 * them (doc/model.md section 3). Forces -dU/dr on the upper node of a (Fi),
 * the joint (Fj) and the lower node of b (Fk), with lengths la, lb. */
static inline void tsi_bending(double ei, double la, double lb,
                               const double na[3], const double nb[3],
                               double Fi[3], double Fj[3], double Fk[3])
{
    double c = v3_dot(na, nb), x[3];
    v3_cross(na, nb, x);
    double sn = v3_norm(x);
    double alpha = atan2(sn, c);
    /* alpha / sin(alpha), 1 + alpha^2/6 near zero. */
    double ratio = sn > 1e-8 ? alpha / sn : 1.0 + alpha * alpha / 6.0;
    double k = ei / (0.5 * (la + lb)) * ratio;
    for (int i = 0; i < 3; i++) {
        Fi[i] = -k * (nb[i] - c * na[i]) / la;
        Fk[i] = k * (na[i] - c * nb[i]) / lb;
        Fj[i] = -(Fi[i] + Fk[i]);
    }
}

/* Bending energy of the same joint, J. */
static inline double tsi_bending_energy(double ei, double la, double lb,
                                        const double na[3],
                                        const double nb[3])
{
    double x[3];
    v3_cross(na, nb, x);
    double alpha = atan2(v3_norm(x), v3_dot(na, nb));
    return 0.5 * ei / (0.5 * (la + lb)) * alpha * alpha;
}

#endif
