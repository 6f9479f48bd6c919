/* vehicle.c: a towed vehicle as a rigid body built up from components
 * (towstab/vehicle.h, lib/vehicle.h; doc/vehicle.md, doc/model.md section
 * 8).
 *
 * References: Kamman & Nguyen 1990 (the 1-2-3 attitude relative to the
 * mean ship frame, eqs. 12-19; the vehicle's Newton-Euler equations with a
 * 6x6 added mass, eqs. 27-37); Buckham et al. 2003 (component build-up
 * after Nahon 1996: the velocity of each component's centre of pressure,
 * its angle of attack plus its control deflection, lift and drag curves,
 * the X tail at 45 degrees; PID/PD controllers, section 4); Newman 1977,
 * Marine Hydrodynamics, section 4.13 (added mass of a spheroid; Lamb's
 * coefficients); Helmbold 1942 (lift slope of a low-aspect-ratio wing);
 * Hoerner 1965, Fluid-Dynamic Drag (flat plate past the stall, the
 * cross-flow drag of a slender hull); Fossen 2011, Handbook of Marine
 * Craft Hydrodynamics and Motion Control, section 6.3 (the added mass's
 * velocity terms; Kirchhoff's equations).
 *
 * Everything here is O(1) per vehicle and allocation-free after
 * tsi_vehicle_ws_alloc.
 *
 * One module although long: the components' hydrodynamics, the added
 * mass, the kinematics and the controllers all act on one body's state
 * and workspace, and the kernel sees them through one narrow interface.
 */
#include "vehicle.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_interp.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vec3.h"

/* Gauss-Legendre points along a hull for its cross-flow drag: the
 * integrand |w| w is a polynomial of degree 3 in the station where the
 * cross flow keeps its direction (exact with 2 points); 8 points keep the
 * error of a hull whose cross flow reverses along it (a turn) below 1e-3
 * of the load. */
#define HULL_POINTS 8
/* Below this eccentricity the spheroid's coefficients come from their
 * series, SPHEROID_TERMS terms (the closed forms cancel: atanh e - e
 * ~ e^3 / 3 loses digits like 1/e^2; at 0.3 the series' next term is
 * 0.09^41 and the closed form keeps ~14 digits). */
#define SPHEROID_SERIES_E 0.3
#define SPHEROID_TERMS 40

struct tsi_vehicle_ws {
    gsl_interp *cl[TS_VEHICLE_MAX_COMPONENTS]; /* tables only */
    gsl_interp *cd[TS_VEHICLE_MAX_COMPONENTS];
    double gl_x[HULL_POINTS], gl_w[HULL_POINTS]; /* on [-1/2, 1/2] */
};

/* ------------------------------------------------------------------ */
/* Description                                                          */

void ts_component_defaults(ts_component *c, ts_component_type type)
{
    memset(c, 0, sizeof *c);
    c->type = type;
    c->cd_axial = 0.2;
    c->cd_cross = 1.2;
    c->drag = type == TS_COMP_MAST ? 0.0 : 0.5; /* a mast: no drag */
    c->curve = TS_CURVE_LIFTING_LINE;
    c->stall = 15.0 * M_PI / 180.0;
    c->stall_width = 3.0 * M_PI / 180.0;
    c->cd0 = 0.01;
    c->efficiency = 0.9;
    c->cn90 = 1.2;
    c->limit = INFINITY;
    c->rate_limit = INFINITY;
}

void ts_component_range(const ts_component *c, double *lo, double *hi)
{
    if (c->type == TS_COMP_BALLAST) {
        *lo = 0.0;
        *hi = c->capacity;
    } else {
        *lo = -c->limit;
        *hi = c->limit;
    }
}

double ts_lift_slope_helmbold(double ar)
{
    return 2.0 * M_PI * ar / (2.0 + sqrt(ar * ar + 4.0));
}

/* S(r) x = r x x, row-major. */
static void skew(const double r[3], double S[9])
{
    S[0] = 0;
    S[1] = -r[2];
    S[2] = r[1];
    S[3] = r[2];
    S[4] = 0;
    S[5] = -r[0];
    S[6] = -r[1];
    S[7] = r[0];
    S[8] = 0;
}

void ts_added_mass_shift(const double A_P[36], const double r[3],
                         double A_O[36])
{
    /* H = [[I, -S(r)], [0, I]]; A_O = H^T A_P H. */
    double H[36] = {0}, S[9], T[36], out[36];
    skew(r, S);
    for (int i = 0; i < 6; i++)
        H[6 * i + i] = 1.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            H[6 * i + 3 + j] = -S[3 * i + j];
    for (int i = 0; i < 6; i++) /* T = A_P H */
        for (int j = 0; j < 6; j++) {
            double s = 0;
            for (int k = 0; k < 6; k++)
                s += A_P[6 * i + k] * H[6 * k + j];
            T[6 * i + j] = s;
        }
    for (int i = 0; i < 6; i++) /* out = H^T T */
        for (int j = 0; j < 6; j++) {
            double s = 0;
            for (int k = 0; k < 6; k++)
                s += H[6 * k + i] * T[6 * k + j];
            out[6 * i + j] = s;
        }
    memcpy(A_O, out, sizeof out);
}

int ts_added_mass_spheroid(double rho, double length, double diameter,
                           double A[36], double k[3], ts_err *err)
{
    if (!(length > 0 && diameter > 0 && length >= diameter) ||
        !isfinite(length) || !(rho >= 0))
        return ts_fail(err, TS_EINVAL, "added mass estimate: needs a prolate "
                       "spheroid, length >= diameter > 0 m, got length %g m, "
                       "diameter %g m",
                       length, diameter);
    double a = 0.5 * length, b = 0.5 * diameter;
    double e2 = 1.0 - (b / a) * (b / a), e = sqrt(e2);
    double alpha0, beta0, diff;
    if (e < SPHEROID_SERIES_E) {
        /* alpha0 = 2/3 + 2 sum e^2k (1/(2k+3) - 1/(2k+1)), beta0 = 2/3 +
         * sum e^2k (1/(2k+1) - 1/(2k+3)), k >= 1; beta0 - alpha0 written
         * as one series so that it keeps its digits. */
        double sa = 0, sb = 0, p = 1;
        for (int kk = 1; kk <= SPHEROID_TERMS; kk++) {
            p *= e2;
            double d = 1.0 / (2 * kk + 1) - 1.0 / (2 * kk + 3);
            sa -= 2 * p * d;
            sb += p * d;
        }
        alpha0 = 2.0 / 3.0 + sa;
        beta0 = 2.0 / 3.0 + sb;
        diff = sb - sa;
    } else {
        double at = atanh(e);
        alpha0 = 2.0 * (1.0 - e2) / (e2 * e) * (at - e);
        beta0 = 1.0 / e2 - (1.0 - e2) / (e2 * e) * at;
        diff = beta0 - alpha0;
    }
    double k1 = alpha0 / (2.0 - alpha0), k2 = beta0 / (2.0 - beta0);
    double den = (2.0 - e2) * (2.0 * e2 - (2.0 - e2) * diff);
    double kp = den > 0 ? e2 * e2 * diff / den : 0.0;
    double mf = rho * M_PI * length * diameter * diameter / 6.0;
    double If = mf * (length * length + diameter * diameter) / 20.0;
    memset(A, 0, 36 * sizeof(double));
    A[0] = k1 * mf;
    A[7] = A[14] = k2 * mf;
    A[28] = A[35] = kp * If;
    if (k) {
        k[0] = k1;
        k[1] = k2;
        k[2] = kp;
    }
    return TS_OK;
}

/* Refuse with "where.key (line N): message" (key NULL: "where (line N):
 * message"; no line when line is 0): the scene's form of an error. */
#ifdef __GNUC__
__attribute__((format(printf, 5, 6)))
#endif
static int bad(ts_err *err, const char *where, int line, const char *key,
               const char *fmt, ...)
{
    char msg[TS_ERR_MSG_MAX], at[32] = "";
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (line > 0)
        snprintf(at, sizeof at, " (line %d)", line);
    return ts_fail(err, TS_EINVAL, "%s%s%s%s: %s", where, key ? "." : "",
                   key ? key : "", at, msg);
}

/* A finite value >= lo (strict: > lo). */
static int check_value(ts_err *err, const char *where, int line,
                       const char *key, double v, double lo, int strict)
{
    if (isfinite(v) && (strict ? v > lo : v >= lo))
        return TS_OK;
    return bad(err, where, line, key, "must be %s %g, got %g",
               strict ? ">" : ">=", lo, v);
}

static int check_finite3(ts_err *err, const char *where, int line,
                         const char *key, const double v[3])
{
    for (int j = 0; j < 3; j++)
        if (!isfinite(v[j]))
            return bad(err, where, line, key, "component %d must be finite",
                       j);
    return TS_OK;
}

static int check_component(const ts_component *c, const char *w,
                           ts_err *err)
{
    int rc, ln = c->line;
    if ((rc = check_finite3(err, w, ln, "position", c->position)))
        return rc;
    if (c->type == TS_COMP_HULL) {
        if ((rc = check_value(err, w, ln, "length", c->length, 0, 1)) ||
            (rc = check_value(err, w, ln, "diameter", c->diameter, 0, 1)) ||
            (rc = check_value(err, w, ln, "axial_drag", c->cd_axial, 0, 0)) ||
            (rc = check_value(err, w, ln, "cross_drag", c->cd_cross, 0, 0)))
            return rc;
        if (c->control)
            return bad(err, w, ln, "control", "a hull is not a control "
                       "surface");
        return TS_OK;
    }
    if (c->type == TS_COMP_BALLAST) {
        if ((rc = check_value(err, w, ln, "capacity", c->capacity, 0, 1)) ||
            (rc = check_value(err, w, ln, "time_constant", c->time_constant,
                              0, 0)))
            return rc;
        if (!c->control)
            return bad(err, w, ln, "control", "a ballast tank is a control "
                       "component");
        if (!(c->deflection >= 0 && c->deflection <= c->capacity))
            return bad(err, w, ln, "fill", "must lie in [0, capacity = %g "
                       "kg], got %g kg", c->capacity, c->deflection);
        if (!(c->rate_limit > 0))
            return bad(err, w, ln, "rate_limit", "must be > 0 kg/s, got %g",
                       c->rate_limit);
        if (isfinite(c->rate_limit) && !(c->time_constant > 0))
            return bad(err, w, ln, "rate_limit", "a rate limit needs an "
                       "actuator with time_constant > 0 s");
        return TS_OK;
    }
    if (c->type == TS_COMP_MAST) {
        if ((rc = check_value(err, w, ln, "length", c->length, 0, 1)) ||
            (rc = check_value(err, w, ln, "area", c->area, 0, 1)) ||
            (rc = check_value(err, w, ln, "chord", c->chord, 0, 1)) ||
            (rc = check_value(err, w, ln, "thickness", c->thickness, 0, 1)) ||
            (rc = check_value(err, w, ln, "drag", c->drag, 0, 0)))
            return rc;
        if (c->control)
            return bad(err, w, ln, "control", "a mast is not a control "
                       "surface");
        return TS_OK;
    }
    if (c->type == TS_COMP_BLUFF) {
        if ((rc = check_value(err, w, ln, "area", c->area, 0, 1)) ||
            (rc = check_value(err, w, ln, "drag", c->drag, 0, 0)))
            return rc;
        if (c->control)
            return bad(err, w, ln, "control", "a bluff part is not a "
                       "control surface");
        return TS_OK;
    }
    if ((rc = check_value(err, w, ln, "area", c->area, 0, 1)) ||
        (rc = check_value(err, w, ln, "span", c->span, 0, 1)) ||
        (rc = check_value(err, w, ln, "lift_slope", c->lift_slope, 0, 0)) ||
        (rc = check_value(err, w, ln, "zero_lift_drag", c->cd0, 0, 0)) ||
        (rc = check_value(err, w, ln, "efficiency", c->efficiency, 0, 1)) ||
        (rc = check_value(err, w, ln, "cn90", c->cn90, 0, 0)) ||
        (rc = check_value(err, w, ln, "stall_width", c->stall_width, 0, 1)))
        return rc;
    if (!isfinite(c->roll) || !isfinite(c->incidence) ||
        !isfinite(c->deflection))
        return bad(err, w, ln, NULL, "roll, incidence and deflection must "
                   "be finite");
    if (!(c->stall > c->stall_width && c->stall + c->stall_width < M_PI_2))
        return bad(err, w, ln, "stall", "must lie between the stall width "
                   "(%g deg) and 90 deg less it, got %g deg",
                   c->stall_width * 180 / M_PI, c->stall * 180 / M_PI);
    if (c->curve == TS_CURVE_TABLE) {
        if (c->npoints < 3 || c->npoints > TS_CURVE_MAX_POINTS)
            return bad(err, w, ln, "table", "needs 3 to %d rows, got %d",
                       TS_CURVE_MAX_POINTS, c->npoints);
        for (int i = 0; i < c->npoints; i++) {
            if (!isfinite(c->alpha[i]) || !isfinite(c->cl[i]) ||
                !isfinite(c->cd[i]))
                return bad(err, w, ln, "table", "row %d is not finite", i);
            if (i > 0 && !(c->alpha[i] > c->alpha[i - 1]))
                return bad(err, w, ln, "table", "angles must increase, row "
                           "%d has %g deg after %g deg", i,
                           c->alpha[i] * 180 / M_PI,
                           c->alpha[i - 1] * 180 / M_PI);
            if (c->cd[i] < 0)
                return bad(err, w, ln, "table", "row %d has a negative drag "
                           "coefficient %g", i, c->cd[i]);
        }
    }
    if (!(c->limit > 0))
        return bad(err, w, ln, "limit", "must be > 0 rad, got %g", c->limit);
    if (!(c->rate_limit > 0))
        return bad(err, w, ln, "rate_limit", "must be > 0 rad/s, got %g",
                   c->rate_limit);
    if ((rc = check_value(err, w, ln, "time_constant", c->time_constant, 0,
                          0)))
        return rc;
    if (isfinite(c->rate_limit) && !(c->time_constant > 0))
        return bad(err, w, ln, "rate_limit", "a rate limit needs an actuator "
                   "with time_constant > 0 s");
    if (!c->control &&
        (c->deflection != 0 || isfinite(c->limit) ||
         isfinite(c->rate_limit) || c->time_constant > 0))
        return bad(err, w, ln, NULL, "deflection, limit, rate_limit and "
                   "time_constant apply to control surfaces (control: "
                   "true)");
    if (fabs(c->deflection) > c->limit)
        return bad(err, w, ln, "deflection", "%g deg is beyond the limit %g "
                   "deg", c->deflection * 180 / M_PI, c->limit * 180 / M_PI);
    return TS_OK;
}

int ts_vehicle_check(const ts_vehicle *v, double mass, const char *where,
                     int line, ts_err *err)
{
    int rc;
    char w[160];
    if (!(mass > 0 && isfinite(mass)))
        return bad(err, where, line, "mass", "a vehicle needs a mass > 0 kg, "
                   "got %g", mass);
    if ((rc = check_finite3(err, where, line, "mass_centre",
                            v->mass_centre)) ||
        (rc = check_finite3(err, where, line, "buoyancy_centre",
                            v->buoyancy_centre)) ||
        (rc = check_finite3(err, where, line, "attach", v->attach)) ||
        (rc = check_value(err, where, line, "volume", v->volume, 0, 0)) ||
        (rc = check_value(err, where, line, "surface_diameter",
                          v->surface_diameter, 0, 0)))
        return rc;
    /* Inertia about the mass centre: symmetric positive definite (a body
     * of finite size; a point mass hanging off centre is the compound
     * pendulum with I -> 0, which needs some inertia to stay regular). */
    const double *I = v->inertia;
    for (int j = 0; j < 6; j++)
        if (!isfinite(I[j]))
            return bad(err, where, line, "inertia", "entry %d must be "
                       "finite", j);
    double S[6] = {I[0], I[1], I[2], I[3], I[4], I[5]}, L[6];
    if (sym3_chol(S, L) != 0)
        return bad(err, where, line, "inertia", "must be positive definite "
                   "(Ixx, Iyy, Izz > 0 and the products of inertia small "
                   "enough), got %g %g %g %g %g %g kg m^2",
                   I[0], I[1], I[2], I[3], I[4], I[5]);
    const double *A = v->added_mass;
    double big = 0;
    for (int i = 0; i < 36; i++) {
        if (!isfinite(A[i]))
            return bad(err, where, line, "added_mass", "entry (%d, %d) must "
                       "be finite", i / 6 + 1, i % 6 + 1);
        big = fmax(big, fabs(A[i]));
    }
    for (int i = 0; i < 6; i++) {
        if (A[7 * i] < 0)
            return bad(err, where, line, "added_mass", "diagonal entry (%d, "
                       "%d) must be >= 0, got %g", i + 1, i + 1, A[7 * i]);
        for (int j = 0; j < i; j++)
            if (fabs(A[6 * i + j] - A[6 * j + i]) > 1e-9 * big)
                return bad(err, where, line, "added_mass", "must be "
                           "symmetric, entries (%d, %d) = %g and (%d, %d) = "
                           "%g", i + 1, j + 1, A[6 * i + j], j + 1, i + 1,
                           A[6 * j + i]);
    }
    if (v->ncomponents < 0 || v->ncomponents > TS_VEHICLE_MAX_COMPONENTS)
        return bad(err, where, line, "components", "at most %d",
                   TS_VEHICLE_MAX_COMPONENTS);
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        snprintf(w, sizeof w, "%s.components[%d]", where, c);
        if ((rc = check_component(cp, w, err)))
            return rc;
        for (int d = 0; d < c; d++)
            if (!strcmp(cp->name, v->component[d].name))
                return bad(err, w, cp->line, "name", "duplicate component "
                           "name '%s'", cp->name);
    }
    if (v->nloops < 0 || v->nloops > TS_VEHICLE_MAX_LOOPS)
        return bad(err, where, line, "controllers", "at most %d",
                   TS_VEHICLE_MAX_LOOPS);
    for (int l = 0; l < v->nloops; l++) {
        const ts_loop *lp = &v->loop[l];
        int ln = lp->line;
        snprintf(w, sizeof w, "%s.controllers[%d]", where, l);
        if (!isfinite(lp->setpoint) || !isfinite(lp->kp) ||
            !isfinite(lp->ki) || !isfinite(lp->kd))
            return bad(err, w, ln, NULL, "setpoint and gains must be "
                       "finite");
        if (lp->nsurfaces < 1)
            return bad(err, w, ln, "surfaces", "a loop must drive at least "
                       "one control surface");
        for (int s = 0; s < lp->nsurfaces; s++) {
            int ci = lp->surface[s];
            if (ci < 0 || ci >= v->ncomponents ||
                !v->component[ci].control)
                return bad(err, w, ln, "surfaces", "entry %d is not a "
                           "control surface of the vehicle", s);
            if (!isfinite(lp->gain[s]))
                return bad(err, w, ln, "surfaces", "gain of entry %d must be "
                           "finite", s);
        }
        for (int d = 0; d < l; d++)
            if (!strcmp(lp->name, v->loop[d].name))
                return bad(err, w, ln, "name", "duplicate controller name "
                           "'%s'", lp->name);
        /* Loops and surfaces name the vehicle's inputs together. */
        for (int c = 0; c < v->ncomponents; c++)
            if (!strcmp(lp->name, v->component[c].name))
                return bad(err, w, ln, "name", "'%s' is also a component's "
                           "name; inputs are named <vehicle>.<surface> and "
                           "<vehicle>.<loop>", lp->name);
    }
    const ts_propulsion *pr = &v->propulsion;
    if (pr->type != TS_PROP_NONE) {
        snprintf(w, sizeof w, "%s.propulsion", where);
        int pl = pr->line;
        if ((rc = check_finite3(err, w, pl, "at", pr->position)))
            return rc;
        switch (pr->type) {
        case TS_PROP_THRUST:
            if (!isfinite(pr->thrust))
                return bad(err, w, pl, "thrust", "must be finite, got %g",
                           pr->thrust);
            break;
        case TS_PROP_POWER:
            if ((rc = check_value(err, w, pl, "power", pr->power, 0, 1)))
                return rc;
            if (!(pr->max_thrust > 0))
                return bad(err, w, pl, "max_thrust", "must be > 0 N, got %g",
                           pr->max_thrust);
            break;
        case TS_PROP_SPEED:
            if ((rc = check_value(err, w, pl, "speed", pr->speed, 0, 1)) ||
                (rc = check_value(err, w, pl, "gain", pr->gain, 0, 0)) ||
                (rc = check_value(err, w, pl, "integral_gain", pr->ki, 0,
                                  0)))
                return rc;
            if (!(pr->max_thrust > 0))
                return bad(err, w, pl, "max_thrust", "must be > 0 N, got %g",
                           pr->max_thrust);
            if (!isfinite(pr->thrust))
                return bad(err, w, pl, "thrust", "must be finite, got %g",
                           pr->thrust);
            break;
        default:
            return bad(err, w, pl, NULL, "unknown propulsion type %d",
                       (int)pr->type);
        }
    }
    return TS_OK;
}

double ts_propulsion_thrust(const ts_propulsion *p, double u, double bias,
                            double input)
{
    double T = 0.0;
    switch (p->type) {
    case TS_PROP_THRUST:
        T = p->thrust;
        break;
    case TS_PROP_POWER:
        /* T U = P while P / U is below the cap (U <= 0: the cap). */
        T = u > p->power / p->max_thrust ? p->power / u : p->max_thrust;
        break;
    case TS_PROP_SPEED:
        T = fmin(bias + p->gain * (p->speed - u), p->max_thrust);
        break;
    default:
        break;
    }
    return T + input;
}

double tsi_vehicle_lever(const ts_vehicle *v)
{
    double big = 0, d[3];
    const double *pts[2] = {v->mass_centre, v->buoyancy_centre};
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 3; j++)
            d[j] = pts[i][j] - v->attach[j];
        big = fmax(big, v3_norm(d));
    }
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        for (int j = 0; j < 3; j++)
            d[j] = cp->position[j] - v->attach[j];
        double r = v3_norm(d);
        if (cp->type == TS_COMP_HULL)
            r += 0.5 * cp->length;
        big = fmax(big, r);
    }
    return big;
}

/* ------------------------------------------------------------------ */
/* Work areas                                                           */

tsi_vehicle_ws *tsi_vehicle_ws_alloc(const ts_vehicle *v, ts_err *err)
{
    tsi_vehicle_ws *w = calloc(1, sizeof *w);
    if (!w) {
        ts_fail(err, TS_ENOMEM, "vehicle: out of memory");
        return NULL;
    }
    gsl_integration_glfixed_table *t =
        gsl_integration_glfixed_table_alloc(HULL_POINTS);
    if (!t) {
        free(w);
        ts_fail(err, TS_ENOMEM, "vehicle: out of memory");
        return NULL;
    }
    for (size_t i = 0; i < HULL_POINTS; i++)
        gsl_integration_glfixed_point(-0.5, 0.5, i, &w->gl_x[i], &w->gl_w[i],
                                      t);
    gsl_integration_glfixed_table_free(t);
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        if (cp->type != TS_COMP_SURFACE || cp->curve != TS_CURVE_TABLE)
            continue;
        size_t n = (size_t)cp->npoints;
        /* Steffen's interpolant is monotone between the points (no
         * overshoot of the table) and continuously differentiable. */
        w->cl[c] = gsl_interp_alloc(gsl_interp_steffen, n);
        w->cd[c] = gsl_interp_alloc(gsl_interp_steffen, n);
        if (!w->cl[c] || !w->cd[c] ||
            gsl_interp_init(w->cl[c], cp->alpha, cp->cl, n) != GSL_SUCCESS ||
            gsl_interp_init(w->cd[c], cp->alpha, cp->cd, n) != GSL_SUCCESS) {
            tsi_vehicle_ws_free(w);
            ts_fail(err, TS_EINVAL, "vehicle: component '%s': the lift/drag "
                    "table cannot be interpolated", cp->name);
            return NULL;
        }
    }
    return w;
}

void tsi_vehicle_ws_free(tsi_vehicle_ws *w)
{
    if (!w)
        return;
    for (int c = 0; c < TS_VEHICLE_MAX_COMPONENTS; c++) {
        if (w->cl[c])
            gsl_interp_free(w->cl[c]);
        if (w->cd[c])
            gsl_interp_free(w->cd[c]);
    }
    free(w);
}

/* ------------------------------------------------------------------ */
/* 6x6 solves: the kernel's per-vehicle elimination, O(1), in the hot     */
/* loop (a LAPACK call costs more than the 6x6 factorisation itself).    */

int tsi_chol6(const double A[36], double L[36])
{
    for (int j = 0; j < 6; j++) {
        double d = A[7 * j];
        for (int k = 0; k < j; k++)
            d -= L[6 * j + k] * L[6 * j + k];
        if (!(d > 0))
            return -1;
        d = sqrt(d);
        L[7 * j] = d;
        for (int i = j + 1; i < 6; i++) {
            double s = A[6 * i + j];
            for (int k = 0; k < j; k++)
                s -= L[6 * i + k] * L[6 * j + k];
            L[6 * i + j] = s / d;
        }
    }
    return 0;
}

void tsi_chol6_solve(const double L[36], double b[6])
{
    for (int i = 0; i < 6; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++)
            s -= L[6 * i + k] * b[k];
        b[i] = s / L[7 * i];
    }
    for (int i = 5; i >= 0; i--) {
        double s = b[i];
        for (int k = i + 1; k < 6; k++)
            s -= L[6 * k + i] * b[k];
        b[i] = s / L[7 * i];
    }
}

/* ------------------------------------------------------------------ */
/* Kinematics                                                           */

void tsi_rot123(const double th[3], double R[9])
{
    double c1 = cos(th[0]), s1 = sin(th[0]), c2 = cos(th[1]),
           s2 = sin(th[1]), c3 = cos(th[2]), s3 = sin(th[2]);
    R[0] = c2 * c3;
    R[1] = -c2 * s3;
    R[2] = s2;
    R[3] = s1 * s2 * c3 + c1 * s3;
    R[4] = -s1 * s2 * s3 + c1 * c3;
    R[5] = -s1 * c2;
    R[6] = -c1 * s2 * c3 + s1 * s3;
    R[7] = c1 * s2 * s3 + s1 * c3;
    R[8] = c1 * c2;
}

void tsi_rate_matrix(const double th[3], double E[9])
{
    double c2 = cos(th[1]), s2 = sin(th[1]), c3 = cos(th[2]),
           s3 = sin(th[2]);
    E[0] = c2 * c3;
    E[1] = s3;
    E[2] = 0;
    E[3] = -c2 * s3;
    E[4] = c3;
    E[5] = 0;
    E[6] = s2;
    E[7] = 0;
    E[8] = 1;
}

void tsi_rate_kappa(const double th[3], const double thd[3], double kap[3])
{
    double c2 = cos(th[1]), s2 = sin(th[1]), c3 = cos(th[2]),
           s3 = sin(th[2]);
    double d1 = thd[0], d2 = thd[1], d3 = thd[2];
    kap[0] = (-s2 * c3 * d2 - c2 * s3 * d3) * d1 + c3 * d3 * d2;
    kap[1] = (s2 * s3 * d2 - c2 * c3 * d3) * d1 - s3 * d3 * d2;
    kap[2] = c2 * d2 * d1;
}

void tsi_rates_from_omega(const double th[3], const double om[3],
                          double thd[3])
{
    double c2 = cos(th[1]), s2 = sin(th[1]), c3 = cos(th[2]),
           s3 = sin(th[2]);
    thd[0] = (c3 * om[0] - s3 * om[1]) / c2;
    thd[1] = s3 * om[0] + c3 * om[1];
    thd[2] = om[2] - s2 * thd[0];
}

void tsi_ypr_from_rot(const double R[9], double ypr[3])
{
    double s = -R[6];
    s = s > 1 ? 1 : (s < -1 ? -1 : s);
    ypr[0] = atan2(R[3], R[0]) + 0.0;
    ypr[1] = asin(s) + 0.0;
    ypr[2] = atan2(R[7], R[8]) + 0.0;
}

void tsi_ypr_rates(const double ypr[3], const double om[3], double yprd[3])
{
    double cp = cos(ypr[1]), tp = tan(ypr[1]);
    double cr = cos(ypr[2]), sr = sin(ypr[2]);
    double qr = om[1] * sr + om[2] * cr;
    yprd[0] = qr / cp;
    yprd[1] = om[1] * cr - om[2] * sr;
    yprd[2] = om[0] + qr * tp;
}

static void mat3_mulmat(const double A[9], const double B[9], double C[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] +
                           A[3 * i + 2] * B[6 + j];
}

void tsi_vehicle_kinematics(const ts_vehicle *v, const double C[9],
                            const double th[3], const double thd[3],
                            double turn_rate, const double rA[3],
                            const double rdA[3], tsi_vehicle_state *st)
{
    double R123[9], ez[3] = {0, 0, 1}, w[3];
    tsi_rot123(th, R123);
    mat3_mulmat(C, R123, st->R);
    tsi_rate_matrix(th, st->E);
    st->c2 = cos(th[1]);
    mat3_mul(st->E, thd, st->om_rel_b);
    mat3_tmul(st->R, ez, w);
    for (int j = 0; j < 3; j++) {
        st->om_b[j] = st->om_rel_b[j] + turn_rate * w[j];
        st->rA[j] = rA[j];
        st->rdA[j] = rdA[j];
    }
    tsi_vehicle_point(v, st, (const double[3]){0, 0, 0}, st->rO, st->rdO);
}

void tsi_vehicle_point(const ts_vehicle *v, const tsi_vehicle_state *st,
                       const double p_b[3], double r[3], double rd[3])
{
    double d_b[3], d[3], w_b[3], wd[3];
    for (int j = 0; j < 3; j++)
        d_b[j] = p_b[j] - v->attach[j];
    mat3_mul(st->R, d_b, d);
    v3_cross(st->om_rel_b, d_b, w_b);
    mat3_mul(st->R, w_b, wd);
    for (int j = 0; j < 3; j++) {
        r[j] = st->rA[j] + d[j];
        rd[j] = st->rdA[j] + wd[j];
    }
}

void tsi_vehicle_angle_accel(const tsi_vehicle_state *st, const double th[3],
                             const double thd[3], double turn_rate,
                             double turn_accel, const double alpha_m[3],
                             double thdd[3])
{
    double fr[3], a[3], omd_b[3], kap[3];
    tsi_vehicle_frame_alpha(st, turn_rate, turn_accel, fr);
    for (int j = 0; j < 3; j++)
        a[j] = alpha_m[j] - fr[j];
    mat3_tmul(st->R, a, omd_b);
    tsi_rate_kappa(th, thd, kap);
    for (int j = 0; j < 3; j++)
        omd_b[j] -= kap[j];
    tsi_rates_from_omega(th, omd_b, thdd);
}

void tsi_vehicle_frame_alpha(const tsi_vehicle_state *st, double turn_rate,
                             double turn_accel, double alpha_m[3])
{
    double om_m[3];
    mat3_mul(st->R, st->om_rel_b, om_m);
    /* W' e_z + W e_z x omega_rel */
    alpha_m[0] = -turn_rate * om_m[1];
    alpha_m[1] = turn_rate * om_m[0];
    alpha_m[2] = turn_accel;
}

/* ------------------------------------------------------------------ */
/* Inertia                                                              */

void tsi_vehicle_mass6(const ts_vehicle *v, double mass,
                       const tsi_vehicle_state *st, double M6[36])
{
    /* Rigid body about A: [[m I, -m S(rho)], [m S(rho), I_G - m S(rho)^2]],
     * rho = r_G - r_A. */
    double rho[3], S[9];
    for (int j = 0; j < 3; j++)
        rho[j] = v->mass_centre[j] - v->attach[j];
    skew(rho, S);
    const double *I = v->inertia;
    double IG[9] = {I[0], I[3], I[4], I[3], I[1], I[5], I[4], I[5], I[2]};
    memset(M6, 0, 36 * sizeof(double));
    double r2 = v3_dot(rho, rho);
    for (int i = 0; i < 3; i++) {
        M6[6 * i + i] = mass;
        for (int j = 0; j < 3; j++) {
            M6[6 * i + 3 + j] = -mass * S[3 * i + j];
            M6[6 * (3 + i) + j] = mass * S[3 * i + j];
            M6[6 * (3 + i) + 3 + j] =
                IG[3 * i + j] +
                mass * ((i == j ? r2 : 0.0) - rho[i] * rho[j]);
        }
    }
    if (!(st->frac > 0))
        return;
    /* Added mass about A: O is at -attach from A. */
    double A[36], rOA[3] = {-v->attach[0], -v->attach[1], -v->attach[2]};
    ts_added_mass_shift(v->added_mass, rOA, A);
    for (int i = 0; i < 36; i++)
        M6[i] += st->frac * A[i];
}

/* ------------------------------------------------------------------ */
/* Hydrodynamics                                                        */

/* Wrap an angle into (-pi, pi]. */
static double wrap_pi(double a)
{
    if (a > -M_PI && a <= M_PI)
        return a;
    a = fmod(a, 2 * M_PI);
    if (a > M_PI)
        a -= 2 * M_PI;
    else if (a <= -M_PI)
        a += 2 * M_PI;
    return a;
}

/* Quintic smoothstep on [0, 1]: S(0) = 0, S(1) = 1, S', S'' zero at both
 * ends. */
static double smoothstep(double x)
{
    if (x <= 0)
        return 0.0;
    if (x >= 1)
        return 1.0;
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}

void tsi_surface_coefficients(const ts_vehicle *v, const tsi_vehicle_ws *w,
                              int ci, double alpha, double *cl, double *cd)
{
    const ts_component *c = &v->component[ci];
    alpha = wrap_pi(alpha);
    if (c->curve == TS_CURVE_TABLE) {
        /* Outside the table the end values hold (doc/vehicle.md). */
        int n = c->npoints;
        double a = alpha < c->alpha[0] ? c->alpha[0]
                   : alpha > c->alpha[n - 1] ? c->alpha[n - 1]
                                              : alpha;
        *cl = gsl_interp_eval(w->cl[ci], c->alpha, c->cl, a, NULL);
        *cd = gsl_interp_eval(w->cd[ci], c->alpha, c->cd, a, NULL);
        return;
    }
    double ar = c->span * c->span / c->area;
    double slope = c->lift_slope > 0 ? c->lift_slope
                                     : ts_lift_slope_helmbold(ar);
    double cl_lin = slope * alpha;
    double cd_lin = c->cd0 + cl_lin * cl_lin / (M_PI * c->efficiency * ar);
    double s = sin(alpha), co = cos(alpha);
    double cl_fp = c->cn90 * s * co, cd_fp = c->cd0 + c->cn90 * s * s;
    double b = smoothstep((fabs(alpha) - (c->stall - c->stall_width)) /
                          (2.0 * c->stall_width));
    *cl = (1.0 - b) * cl_lin + b * cl_fp;
    *cd = (1.0 - b) * cd_lin + b * cd_fp;
}

/* Lift and drag of a surface whose centre of pressure moves at w (body
 * axes, relative to the water). */
static void surface_load(const ts_vehicle *v, const tsi_vehicle_ws *ws,
                         int ci, double qrho, const double w[3],
                         double delta, ts_component_load *out)
{
    const ts_component *c = &v->component[ci];
    double en[3] = {0, -sin(c->roll), cos(c->roll)};
    double wc = w[0], wn = v3_dot(w, en);
    double sp = sqrt(wc * wc + wn * wn);
    double alpha = atan2(wn, wc) + c->incidence + delta;
    v3_set(out->force, 0, 0, 0);
    out->alpha = wrap_pi(alpha);
    out->speed = sp;
    if (!(sp > 0) || !(qrho > 0))
        return;
    double cl, cd;
    tsi_surface_coefficients(v, ws, ci, alpha, &cl, &cd);
    /* Lift is normal to the flow in the chord-normal plane, drag along
     * it: q S (C_L (wn e_c - wc e_n) - C_D (wc e_c + wn e_n)) / |w|. */
    double q = 0.5 * qrho * c->area * sp;
    double fc = q * (cl * wn - cd * wc), fn = q * (-cl * wc - cd * wn);
    out->force[0] = fc;
    out->force[1] = fn * en[1];
    out->force[2] = fn * en[2];
}

/* Axial and cross-flow drag of a hull. */
static void hull_load(const ts_vehicle *v, const tsi_vehicle_ws *ws, int ci,
                      double qrho, const double wc[3], const double om[3],
                      ts_component_load *out)
{
    const ts_component *c = &v->component[ci];
    v3_set(out->force, 0, 0, 0);
    v3_set(out->moment, 0, 0, 0);
    out->alpha = atan2(wc[2], wc[0]);
    out->speed = v3_norm(wc);
    if (!(qrho > 0))
        return;
    double D = c->diameter, L = c->length;
    out->force[0] =
        -0.5 * qrho * c->cd_axial * (M_PI * 0.25 * D * D) * fabs(wc[0]) *
        wc[0];
    /* Cross flow at station s (from the centre, along x): w_y + s om_z,
     * w_z - s om_y; drag per length -1/2 rho Cd D |w_perp| w_perp. */
    double k = 0.5 * qrho * c->cd_cross * D * L;
    for (int i = 0; i < HULL_POINTS; i++) {
        double s = ws->gl_x[i] * L, wt = ws->gl_w[i];
        double vy = wc[1] + s * om[2], vz = wc[2] - s * om[1];
        double m = sqrt(vy * vy + vz * vz);
        double fy = -k * wt * m * vy, fz = -k * wt * m * vz;
        out->force[1] += fy;
        out->force[2] += fz;
        /* Moment about the hull centre of (0, fy, fz) at (s, 0, 0). */
        out->moment[1] -= s * fz;
        out->moment[2] += s * fy;
    }
}

void tsi_vehicle_hydro(const ts_vehicle *v, const tsi_vehicle_ws *w,
                       double rho, double frac, const double wO_b[3],
                       const double om_b[3], const double delta[],
                       double F[3], double Mo[3], ts_component_load *each)
{
    v3_set(F, 0, 0, 0);
    v3_set(Mo, 0, 0, 0);
    double qrho = rho * frac;
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        ts_component_load ld;
        double wp[3], x[3];
        v3_cross(om_b, cp->position, x);
        for (int j = 0; j < 3; j++)
            wp[j] = wO_b[j] + x[j];
        if (cp->type == TS_COMP_MAST || cp->type == TS_COMP_BALLAST) {
            /* Statics only (tsi_vehicle_statics). */
            memset(&ld, 0, sizeof ld);
            if (each)
                each[c] = ld;
            continue;
        }
        if (cp->type == TS_COMP_HULL) {
            hull_load(v, w, c, qrho, wp, om_b, &ld);
        } else if (cp->type == TS_COMP_BLUFF) {
            double sp = v3_norm(wp), k = -0.5 * qrho * cp->drag * cp->area * sp;
            for (int j = 0; j < 3; j++)
                ld.force[j] = k * wp[j];
            v3_set(ld.moment, 0, 0, 0);
            ld.alpha = atan2(wp[2], wp[0]);
            ld.speed = sp;
        } else {
            surface_load(v, w, c, qrho, wp,
                         delta && cp->control ? delta[c] : 0.0, &ld);
            v3_set(ld.moment, 0, 0, 0);
        }
        ld.submerged = 0.0;
        /* Moment about O: the component's own plus position x force. */
        v3_cross(cp->position, ld.force, x);
        v3_axpy(1.0, x, ld.moment);
        v3_axpy(1.0, ld.force, F);
        v3_axpy(1.0, ld.moment, Mo);
        if (each)
            each[c] = ld;
    }
}

/* The cumulative distributions over a unit disc of u = n.(X, Y) for a
 * unit vector n, as fractions of its area: P(u) the area with n.(X, Y) <
 * u, Q1 and Q2 its first and second moments in u (the semicircle law
 * (2 / pi) sqrt(1 - u^2) du, integrated in closed form). */
static void disc_moments(double u, double *P, double *Q1, double *Q2)
{
    double r = sqrt(fmax(0.0, 1.0 - u * u)), as = asin(u);
    *P = 0.5 + (u * r + as) / M_PI;
    *Q1 = -2.0 / (3.0 * M_PI) * r * r * r;
    *Q2 = (2.0 / M_PI) * (as / 8 - u * r * (1 - 2 * u * u) / 8 + M_PI / 16);
}

void tsi_mast_buoyancy(const ts_component *cp, double rho, double g,
                       double zO, const double ez_b[3], double F[3],
                       double Mo[3], double *submerged, double centre[3])
{
    /* Along the axis a = (0, 0, -1) from the foot p, at section offset q
     * = (xi, eta), a point is at depth z_p - s cz + xi ez0 + eta ez1:
     * under water (z > 0) below s = L(q) = s_c + k.q when cz > 0, with
     * s_c = z_p / cz, k = (ez0, ez1) / cz. Over the elliptic section
     * (semi-axes chord/2, thickness/2) k.q = m u with u distributed by
     * the semicircle law, so the clamped length f = clamp(L, 0, h) and
     * its moments integrate in closed form (doc/vehicle.md section 4):
     * I0 = <f>, I1 = <u f>, I2 = <f^2 / 2> over the section. */
    const double *p = cp->position;
    double h = cp->length, A = cp->area;
    double zp = zO + ez_b[0] * p[0] + ez_b[1] * p[1] + ez_b[2] * p[2];
    double cz = ez_b[2];
    if (fabs(cz) < 1e-12)
        cz = cz < 0 ? -1e-12 : 1e-12;
    double s = zp / cz, k0 = ez_b[0] / cz, k1 = ez_b[1] / cz;
    double a0 = 0.5 * cp->chord, a1 = 0.5 * cp->thickness;
    double m = hypot(k0 * a0, k1 * a1);
    double I0, I1, I2;
    if (!(m > 1e-12 * (h + fabs(s)))) {
        double f = fmax(0.0, fmin(h, s));
        I0 = f;
        I1 = 0.0;
        I2 = 0.5 * f * f;
    } else {
        double ul = fmax(-1.0, fmin(1.0, -s / m));
        double uh = fmax(-1.0, fmin(1.0, (h - s) / m));
        double Pl, Q1l, Q2l, Ph, Q1h, Q2h;
        disc_moments(ul, &Pl, &Q1l, &Q2l);
        disc_moments(uh, &Ph, &Q1h, &Q2h);
        double dP = Ph - Pl, d1 = Q1h - Q1l, d2 = Q2h - Q2l;
        I0 = s * dP + m * d1 + h * (1 - Ph);
        I1 = s * d1 + m * d2 - h * Q1h;
        I2 = 0.5 * (s * s * dP + 2 * s * m * d1 + m * m * d2) +
             0.5 * h * h * (1 - Ph);
    }
    if (cz < 0) {
        /* Mast pointing down: under water above L(q), the rest. */
        I0 = h - I0;
        I1 = -I1;
        I2 = 0.5 * h * h - I2;
    }
    /* First moment of the submerged volume about O: V p + a <s> A + the
     * section's, A I1 (a0^2 k0, a1^2 k1) / m (u's direction n = (a0 k0,
     * a1 k1) / m scaled back to the section). */
    double V = A * I0, S[3];
    for (int j = 0; j < 3; j++)
        S[j] = V * p[j];
    S[2] -= A * I2;
    if (I1 != 0.0) {
        S[0] += A * I1 * a0 * a0 * k0 / m;
        S[1] += A * I1 * a1 * a1 * k1 / m;
    }
    double wb = rho * g;
    for (int j = 0; j < 3; j++)
        F[j] = -wb * V * ez_b[j];
    /* Moment about O: S x F / V = -rho g S x ez_b. */
    double x[3];
    v3_cross(S, ez_b, x);
    for (int j = 0; j < 3; j++)
        Mo[j] = -wb * x[j];
    if (submerged)
        *submerged = I0;
    /* The submerged part's centroid S / V; the foot when it is dry. */
    for (int j = 0; centre && j < 3; j++)
        centre[j] = V > 0 ? S[j] / V : p[j];
}

void tsi_mast_drag(const ts_component *cp, double rho, double submerged,
                   const double centre[3], const double wO_b[3],
                   const double om_b[3], double F[3], double Mo[3])
{
    /* The flow across the mast (body x and y) at the submerged part's
     * centroid, on the frontal area thickness x submerged length. */
    double x[3], w[3];
    v3_cross(om_b, centre, x);
    for (int j = 0; j < 3; j++)
        w[j] = wO_b[j] + x[j];
    double k = -0.5 * rho * cp->drag * cp->thickness * submerged *
               hypot(w[0], w[1]);
    v3_set(F, k * w[0], k * w[1], 0.0);
    v3_cross(centre, F, Mo);
}

void tsi_vehicle_statics(const ts_vehicle *v, double rho, double g,
                         const tsi_vehicle_state *st, const double delta[],
                         double F[3], double Mo[3], ts_component_load *each)
{
    double ez[3] = {0, 0, 1}, ez_b[3];
    mat3_tmul(st->R, ez, ez_b);
    v3_set(F, 0, 0, 0);
    v3_set(Mo, 0, 0, 0);
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        ts_component_load ld = {{0, 0, 0}, {0, 0, 0}, 0, 0, 0};
        if (cp->type == TS_COMP_MAST) {
            /* Its buoyancy, and its drag on the same submerged part. */
            double centre[3];
            tsi_mast_buoyancy(cp, rho, g, st->rO[2], ez_b, ld.force,
                              ld.moment, &ld.submerged, centre);
            if (cp->drag > 0) {
                double Fd[3], Md[3];
                tsi_mast_drag(cp, rho, ld.submerged, centre, st->wO_b,
                              st->om_b, Fd, Md);
                v3_axpy(1.0, Fd, ld.force);
                v3_axpy(1.0, Md, ld.moment);
            }
        } else if (cp->type == TS_COMP_BALLAST) {
            /* The water beyond the fill in the vehicle's mass. */
            double dm = (delta ? delta[c] : cp->deflection) - cp->deflection;
            for (int j = 0; j < 3; j++)
                ld.force[j] = dm * g * ez_b[j];
            v3_cross(cp->position, ld.force, ld.moment);
        } else {
            continue;
        }
        v3_axpy(1.0, ld.force, F);
        v3_axpy(1.0, ld.moment, Mo);
        if (each)
            each[c] = ld;
    }
}

void tsi_vehicle_loads(const ts_vehicle *v, const tsi_vehicle_ws *w,
                       double mass, double rho, double g,
                       const tsi_vehicle_state *st, const double delta[],
                       double G[6], double munk[3])
{
    double ez_b[3], ez[3] = {0, 0, 1}, F[3], Mo[3], x[3], r[3];
    mat3_tmul(st->R, ez, ez_b);
    const double *om = st->om_b, *vr = st->wO_b;
    memset(G, 0, 6 * sizeof(double));
    /* Loads at O first (force, moment about O), then moved to A. */
    tsi_vehicle_hydro(v, w, rho, st->frac, vr, om, delta, F, Mo, NULL);
    double Fg[3], Fb[3];
    for (int j = 0; j < 3; j++) {
        Fg[j] = mass * g * ez_b[j];
        Fb[j] = -st->frac * rho * g * v->volume * ez_b[j];
    }
    v3_axpy(1.0, Fg, F);
    v3_axpy(1.0, Fb, F);
    v3_cross(v->mass_centre, Fg, x);
    v3_axpy(1.0, x, Mo);
    v3_cross(v->buoyancy_centre, Fb, x);
    v3_axpy(1.0, x, Mo);
    /* Surface-piercing masts (the buoyancy of their submerged parts) and
     * ballast tanks (the weight of their water beyond the trim fill). */
    double Fm[3], Mm[3];
    tsi_vehicle_statics(v, rho, g, st, delta, Fm, Mm, NULL);
    v3_axpy(1.0, Fm, F);
    v3_axpy(1.0, Mm, Mo);

    /* Added mass (Kirchhoff, Fossen 2011 eq. 6.43): with p = A11 v + A12
     * om and L = A21 v + A22 om about O, the velocity terms are
     * F = A11 (om x v) - om x p, M = A21 (om x v) - om x L - v x p,
     * and writing a_O = a_A + alpha x r_OA + om x (om x r_OA) adds
     * -A (om x (om x r_OA), 0). */
    if (munk)
        v3_set(munk, 0, 0, 0);
    if (st->frac > 0 && rho > 0) {
        const double *A = v->added_mass;
        double f = st->frac, p[3], L[3], oxv[3], t[3], rOA[3], c[3];
        double A1v[3], A2v[3];
        for (int i = 0; i < 3; i++) {
            p[i] = L[i] = A1v[i] = A2v[i] = 0;
            rOA[i] = -v->attach[i];
        }
        v3_cross(om, vr, oxv);
        v3_cross(om, rOA, t);
        v3_cross(om, t, c);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                p[i] += f * (A[6 * i + j] * vr[j] + A[6 * i + 3 + j] * om[j]);
                L[i] += f * (A[6 * (3 + i) + j] * vr[j] +
                             A[6 * (3 + i) + 3 + j] * om[j]);
                A1v[i] += f * A[6 * i + j] * (oxv[j] - c[j]);
                A2v[i] += f * A[6 * (3 + i) + j] * (oxv[j] - c[j]);
            }
        v3_cross(om, p, t);
        for (int j = 0; j < 3; j++)
            F[j] += A1v[j] - t[j];
        v3_cross(om, L, t);
        for (int j = 0; j < 3; j++)
            Mo[j] += A2v[j] - t[j];
        v3_cross(vr, p, t);
        for (int j = 0; j < 3; j++)
            Mo[j] -= t[j];
        if (munk)
            v3_set(munk, -t[0], -t[1], -t[2]);
    }
    /* Move to A: moment about A = moment about O + (O - A) x F. */
    for (int j = 0; j < 3; j++)
        r[j] = -v->attach[j];
    v3_cross(r, F, x);
    for (int j = 0; j < 3; j++) {
        G[j] = F[j];
        G[3 + j] = Mo[j] + x[j];
    }
    /* Rigid body: -(m om x (om x rho), om x I_G om + m rho x (om x (om x
     * rho))), rho = r_G - r_A. */
    double rho_g[3], oxr[3], cen[3], Iom[3];
    for (int j = 0; j < 3; j++)
        rho_g[j] = v->mass_centre[j] - v->attach[j];
    v3_cross(om, rho_g, oxr);
    v3_cross(om, oxr, cen);
    const double *I = v->inertia;
    double IG[6] = {I[0], I[1], I[2], I[3], I[4], I[5]};
    sym3_mul(IG, om, Iom);
    v3_cross(om, Iom, x);
    for (int j = 0; j < 3; j++)
        G[j] -= mass * cen[j];
    for (int j = 0; j < 3; j++)
        G[3 + j] -= x[j];
    v3_cross(rho_g, cen, x);
    for (int j = 0; j < 3; j++)
        G[3 + j] -= mass * x[j];
}

/* ------------------------------------------------------------------ */
/* Measurements and control                                             */

void tsi_vehicle_measure(const tsi_vehicle_state *st, double value[4],
                         double rate[4])
{
    double ypr[3], yd[3];
    tsi_ypr_from_rot(st->R, ypr);
    tsi_ypr_rates(ypr, st->om_rel_b, yd);
    value[TS_MEASURE_DEPTH] = st->rO[2];
    rate[TS_MEASURE_DEPTH] = st->rdO[2];
    value[TS_MEASURE_PITCH] = ypr[1];
    rate[TS_MEASURE_PITCH] = yd[1];
    value[TS_MEASURE_ROLL] = ypr[2];
    rate[TS_MEASURE_ROLL] = yd[2];
    value[TS_MEASURE_HEADING] = ypr[0];
    rate[TS_MEASURE_HEADING] = yd[0];
}

double tsi_loop_error(const ts_loop *l, const double value[4], double sp)
{
    double e = value[l->measure] - sp;
    return l->measure == TS_MEASURE_HEADING ? wrap_pi(e) : e;
}

void tsi_vehicle_control(const ts_vehicle *v, const tsi_control_in *in,
                         double out[], double delta[], double xi_dot[],
                         double act_dot[])
{
    double cmd[TS_VEHICLE_MAX_COMPONENTS];
    for (int c = 0; c < v->ncomponents; c++)
        cmd[c] = v->component[c].deflection +
                 (in->u_surf ? in->u_surf[c] : 0.0);
    for (int l = 0; l < v->nloops; l++) {
        const ts_loop *lp = &v->loop[l];
        int m = in->mode ? in->mode[l] : TS_LOOP_CLOSED;
        double sp = in->setpoint ? in->setpoint[l] : lp->setpoint;
        double e = tsi_loop_error(lp, in->value, sp);
        double x = lp->ki != 0 && m != TS_LOOP_OPEN && in->xi ? in->xi[l]
                                                              : 0.0;
        out[l] = lp->kp * e + lp->ki * x + lp->kd * in->rate[lp->measure];
        /* A steady state of an integrating loop has e = 0 (x' = e) and no
         * rates, so its output is ki x alone: the steady solve uses that,
         * which has the same solutions and keeps a high kp from making
         * the clamp below bite at every Newton iterate off the solution. */
        if (in->steady && lp->ki != 0 && m == TS_LOOP_CLOSED)
            out[l] = lp->ki * x;
        if (xi_dot)
            xi_dot[l] = e;
        double u = in->u_loop ? in->u_loop[l] : 0.0;
        double sig = m == TS_LOOP_CLOSED ? out[l] + u
                     : m == TS_LOOP_OPEN ? (in->frozen ? in->frozen[l] : 0.0) + u
                                         : u;
        for (int k = 0; k < lp->nsurfaces; k++)
            cmd[lp->surface[k]] += lp->gain[k] * sig;
    }
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        if (!cp->control) {
            delta[c] = 0.0;
            if (act_dot)
                act_dot[c] = 0.0;
            continue;
        }
        /* Deflection limit, then the actuator (a first-order lag whose
         * rate saturates). */
        double lo, hi;
        ts_component_range(cp, &lo, &hi);
        double d = fmax(lo, fmin(hi, cmd[c]));
        if (cp->time_constant > 0) {
            double a = in->act ? in->act[c] : d;
            double r = (d - a) / cp->time_constant;
            if (act_dot)
                act_dot[c] = in->steady ? r
                                        : fmax(-cp->rate_limit,
                                               fmin(cp->rate_limit, r));
            delta[c] = a;
        } else {
            delta[c] = d;
            if (act_dot)
                act_dot[c] = 0.0;
        }
    }
}

/* ------------------------------------------------------------------ */
/* Drawing                                                              */

void ts_vehicle_rotation(double yaw, double pitch, double roll, double R[9])
{
    double cy = cos(yaw), sy = sin(yaw), cp = cos(pitch), sp = sin(pitch),
           cr = cos(roll), sr = sin(roll);
    R[0] = cy * cp;
    R[1] = cy * sp * sr - sy * cr;
    R[2] = cy * sp * cr + sy * sr;
    R[3] = sy * cp;
    R[4] = sy * sp * sr + cy * cr;
    R[5] = sy * sp * cr - cy * sr;
    R[6] = -sp;
    R[7] = cp * sr;
    R[8] = cp * cr;
}

/* Append body point b (body axes from O) as a point in M; a NaN point
 * when b is NULL. */
static void outline_put(const double R[9], const double O[3],
                        const double *b, double pts[], int max, int *n)
{
    if (*n < max) {
        double *p = pts + 3 * (size_t)*n;
        for (int i = 0; i < 3; i++)
            p[i] = b ? O[i] + R[3 * i] * b[0] + R[3 * i + 1] * b[1] +
                           R[3 * i + 2] * b[2]
                     : NAN;
    }
    (*n)++;
}

int ts_vehicle_outline(const ts_vehicle *v, const double R[9],
                       const double origin[3], const double *delta,
                       double pts[], int max)
{
    int n = 0;
    for (int c = 0; c < v->ncomponents; c++) {
        const ts_component *cp = &v->component[c];
        const double *x0 = cp->position;
        if (n > 0)
            outline_put(R, origin, NULL, pts, max, &n);
        if (cp->type == TS_COMP_HULL) {
            /* Two ellipses: in the x-z plane (axis 2), then x-y (1). */
            for (int plane = 2; plane >= 1; plane--) {
                if (plane == 1)
                    outline_put(R, origin, NULL, pts, max, &n);
                for (int k = 0; k < TS_OUTLINE_HULL_POINTS; k++) {
                    double t = 2 * M_PI * k / (TS_OUTLINE_HULL_POINTS - 1);
                    double b[3] = {x0[0] + 0.5 * cp->length * cos(t), x0[1],
                                   x0[2]};
                    b[plane] += 0.5 * cp->diameter * sin(t);
                    outline_put(R, origin, b, pts, max, &n);
                }
            }
        } else if (cp->type == TS_COMP_SURFACE) {
            /* Span along (0, cos roll, sin roll); the chord along x,
             * turned by the deflection about the span: a positive
             * deflection (force along -normal) turns the leading edge
             * toward -normal. */
            double chord = cp->area / cp->span;
            double d = delta ? delta[c] : cp->deflection;
            double sa[3] = {0, cos(cp->roll), sin(cp->roll)};
            double nr[3] = {0, -sin(cp->roll), cos(cp->roll)};
            double ch[3];
            for (int i = 0; i < 3; i++)
                ch[i] = (i == 0 ? cos(d) : 0.0) - sin(d) * nr[i];
            static const int corner[5][2] = {
                {1, 1}, {-1, 1}, {-1, -1}, {1, -1}, {1, 1}};
            for (int k = 0; k < 5; k++) {
                double b[3];
                for (int i = 0; i < 3; i++)
                    b[i] = x0[i] + corner[k][0] * 0.5 * chord * ch[i] +
                           corner[k][1] * 0.5 * cp->span * sa[i];
                outline_put(R, origin, b, pts, max, &n);
            }
        } else if (cp->type == TS_COMP_MAST) {
            /* Its side: a rectangle of its chord and length, up the body's
             * -z axis from its foot. */
            static const double corner[5][2] = {
                {0.5, 0}, {0.5, 1}, {-0.5, 1}, {-0.5, 0}, {0.5, 0}};
            for (int k = 0; k < 5; k++) {
                double b[3] = {x0[0] + corner[k][0] * cp->chord, x0[1],
                               x0[2] - corner[k][1] * cp->length};
                outline_put(R, origin, b, pts, max, &n);
            }
        } else {
            /* A bluff part: a cross of its frontal area's side; a ballast
             * tank: of the side of a cube of its capacity's water. */
            double h = cp->type == TS_COMP_BALLAST
                           ? 0.5 * cbrt(cp->capacity / 1000.0)
                           : 0.5 * sqrt(cp->area);
            for (int axis = 0; axis < 3; axis++) {
                if (axis > 0)
                    outline_put(R, origin, NULL, pts, max, &n);
                for (int sgn = -1; sgn <= 1; sgn += 2) {
                    double b[3] = {x0[0], x0[1], x0[2]};
                    b[axis] += sgn * h;
                    outline_put(R, origin, b, pts, max, &n);
                }
            }
        }
    }
    return n;
}
