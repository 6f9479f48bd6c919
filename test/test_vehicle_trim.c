/* test_vehicle_trim.c: steady states and modes of systems with a vehicle
 * (lib/equilibrium.c with the kernel's vehicles), against independent
 * references.
 *
 *  1. The zero-length limit: a vehicle of size eps (its attach point eps
 *     above its mass, buoyancy and drag centre, inertia and rotational
 *     added mass ~ m eps^2) with a bluff part of a sphere's area and drag
 *     and the sphere's translational added mass, against that sphere on the
 *     same cable: the cable's shape and the sphere system's modes are
 *     reached as eps -> 0, the differences falling like eps.
 *  2. Global balance: in a straight steady tow the force on the tow point
 *     is the sum of every external load (cable, vehicle weight, buoyancy,
 *     hydrodynamics), which the tension recursion does not impose.
 *  3. The turning trim tends to the straight one as the turn rate goes to
 *     zero: attitude and shape differences proportional to the turn rate.
 *  4. A vehicle between two cables (a depressor-like body with a cable to
 *     a sphere from its tail) reaches a steady state; the balance holds.
 *  5. Two methods: shooting (the default) against Newton, on the vehicle
 *     examples, in turns and between two cables.
 * Tolerances are stated at each check with their reason. */
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"
#include "towstab/scene.h"

#include <gsl/gsl_errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "tcheck.h"
#include "vec3.h"

#define RHO 1025.0
#define G 9.80665

/* tow -> 10 links of 30 m, 1 in, 1.5 kg/m -> body 0 ("ball"): a sphere
 * (eps < 0) or a vehicle of size eps. */
static ts_system *ball_system(double eps, double speed)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(1, 1, &err);
    snprintf(s->name, sizeof s->name, "ball");
    s->env.water_density = RHO;
    s->env.gravity = G;
    s->tow.speed = speed;
    ts_cable *c = &s->cables[0];
    snprintf(c->name, sizeof c->name, "main");
    c->from_body = -1;
    c->to_body = 0;
    c->length = 30.0;
    c->diameter = 0.0254;
    c->mass_per_length = 1.5;
    c->nlinks = 10;
    c->cdn = 1.2;
    c->cdt = 0.01;
    c->can = 1.0;
    ts_body *b = &s->bodies[0];
    snprintf(b->name, sizeof b->name, "ball");
    double D = 0.3, V = M_PI * D * D * D / 6, m = 40.0;
    b->mass = m;
    if (eps < 0) {
        b->type = TS_BODY_SPHERE;
        b->diameter = D;
        b->cd = 0.5;
        b->ca = 0.5;
    } else {
        ts_vehicle *v = ts_body_set_vehicle(s, 0, &err);
        v->volume = V;
        v->attach[2] = -eps;
        for (int j = 0; j < 3; j++) {
            v->inertia[j] = 0.4 * m * eps * eps;
            v->added_mass[7 * j] = 0.5 * RHO * V;
            v->added_mass[7 * (3 + j)] = 0.2 * RHO * V * eps * eps;
        }
        v->ncomponents = 1;
        ts_component *cp = &v->component[0];
        ts_component_defaults(cp, TS_COMP_BLUFF);
        snprintf(cp->name, sizeof cp->name, "body");
        cp->area = M_PI * D * D / 4;
        cp->drag = 0.5;
    }
    if (ts_system_build(s, &err) != TS_OK) {
        printf("build: %s\n", err.msg);
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* Equilibrium and, when modes is not NULL, its lowest modes. */
static ts_equilibrium *solve(ts_system *s, ts_kernel **kout, ts_eigen **modes)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    if (ts_equilibrium_solve(k, NULL, eq, &err) != TS_OK)
        printf("equilibrium: %s\n", err.msg);
    if (modes) {
        *modes = NULL;
        ts_linear *lin = ts_linear_alloc(k, &err);
        if (ts_linearize_equilibrium(k, eq, NULL, lin, &err) == TS_OK)
            ts_eigen_solve(lin, NULL, modes, &err);
        else
            printf("linearize: %s\n", err.msg);
        ts_linear_free(lin);
    }
    *kout = k;
    return eq;
}

static void test_zero_length(void)
{
    ts_system *sph = ball_system(-1, 2.1);
    ts_kernel *ks;
    ts_eigen *es;
    ts_equilibrium *eqs = solve(sph, &ks, &es);
    CHECK(eqs->converged && es, "sphere system solved");
    double dpos[3], dmode[3];
    static const double eps[3] = {1e-2, 1e-3, 1e-4};
    for (int i = 0; i < 3; i++) {
        ts_system *veh = ball_system(eps[i], 2.1);
        ts_kernel *kv;
        ts_eigen *ev;
        ts_equilibrium *eqv = solve(veh, &kv, &ev);
        /* Shape: every cable node; the vehicle's node is its attach
         * point, eps from the ball's centre. */
        dpos[i] = 0;
        for (int j = 0; j < 3 * sph->nnodes; j++)
            dpos[i] = fmax(dpos[i], fabs(eqs->positions[j] - eqv->positions[j]));
        /* Modes: each of the sphere system's 20 lowest eigenvalues has a
         * vehicle eigenvalue near it (relative distance). */
        dmode[i] = 0;
        for (int m = 0; ev && m < es->nmodes && m < 20; m++) {
            double best = INFINITY, a = es->modes[m].re, b = es->modes[m].im;
            for (int q = 0; q < ev->nmodes; q++)
                best = fmin(best, hypot(ev->modes[q].re - a,
                                        ev->modes[q].im - b));
            dmode[i] = fmax(dmode[i], best / hypot(a, b));
        }
        CHECK(eqv->converged && ev,
              "vehicle of size %g m: converged, shape within %.3g m of the "
              "sphere's, 20 lowest modes within %.3g relative",
              eps[i], dpos[i], dmode[i]);
        ts_eigen_free(ev);
        ts_equilibrium_free(eqv);
        ts_kernel_free(kv);
        ts_system_free(veh);
    }
    /* In a straight tow the body pulls its node exactly as the sphere
     * does, whatever eps: the cable's shape is the sphere's to rounding
     * (1e-10 m of 30 m). The modes differ at first order in eps: ratios
     * ~10 per decade ([8, 12] allows the second-order term). */
    CHECK(dpos[0] < 1e-10 && dpos[1] < 1e-10 && dpos[2] < 1e-10 &&
              dmode[0] / dmode[1] > 8 && dmode[0] / dmode[1] < 12 &&
              dmode[1] / dmode[2] > 8 && dmode[1] / dmode[2] < 12,
          "shapes equal (%.3g, %.3g, %.3g m); mode differences fall like "
          "eps: %.3g, %.3g, %.3g",
          dpos[0], dpos[1], dpos[2], dmode[0], dmode[1], dmode[2]);
    ts_eigen_free(es);
    ts_equilibrium_free(eqs);
    ts_kernel_free(ks);
    ts_system_free(sph);
}

/* |tow_force - sum of every external load| / |tow_force| in a straight
 * steady tow, the loads summed whole (not as the kernel splits them
 * between nodes and bodies): each link's weight, buoyancy and drag from
 * its direction and ends (lib/forces.h), the bodies' loads, and each
 * vehicle's weight, buoyancy and hydrodynamic force. */
static double balance(const ts_system *s, const ts_equilibrium *eq)
{
    double sum[3] = {0, 0, 0}, w[3] = {s->tow.speed, 0, 0}, F[3], sub;
    for (int l = 0; l < s->nlinks; l++) {
        const ts_link *L = &s->links[l];
        const double *rk = eq->positions + 3 * L->lower;
        const double *n = eq->directions + 3 * l;
        double zu = rk[2] - L->length * n[2];
        tsi_link_load(L, s->env.water_density, s->env.gravity, n, zu, rk[2],
                      w, F, &sub);
        v3_axpy(1.0, F, sum);
    }
    for (int b = 0; b < s->nbodies; b++) {
        const ts_body *bd = &s->bodies[b];
        const double *r = eq->positions + 3 * ts_system_body_node(s, b);
        if (bd->type != TS_BODY_VEHICLE) {
            double frac, axis[3] = {1, 0, 0};
            tsi_body_load(bd, s->env.water_density, s->env.gravity, r[2], w,
                          axis, F, &frac);
            v3_axpy(1.0, F, sum);
        }
    }
    for (int v = 0; v < eq->nvehicles; v++) {
        const ts_vehicle_result *r = &eq->vehicles[v];
        const ts_body *b = &s->bodies[r->body];
        mat3_mul(r->R, r->hydro_force, F);
        v3_axpy(1.0, F, sum);
        sum[2] += (b->mass - r->submerged * s->env.water_density *
                                 b->vehicle->volume) *
                  s->env.gravity;
    }
    double d = 0;
    for (int j = 0; j < 3; j++)
        d = fmax(d, fabs(eq->tow_force[j] - sum[j]));
    return d / v3_norm(eq->tow_force);
}

static ts_system *load(const char *path, int links)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *sc = ts_scene_load(path, u, &err);
    ts_units_free(u);
    if (!sc) {
        printf("%s\n", err.msg);
        return NULL;
    }
    ts_system *s = ts_system_copy(sc->system, &err);
    ts_scene_free(sc);
    if (links > 0) {
        s->cables[0].nlinks = links;
        ts_system_build(s, &err);
    }
    return s;
}

static void test_balance(void)
{
    ts_system *s = load("examples/kamman_ex1_vehicle.yaml", 0);
    ts_kernel *k;
    ts_equilibrium *eq = solve(s, &k, NULL);
    /* The residual is 1e-10 of the largest force; the sum of ~25 loads
     * adds rounding: 1e-9 relative. */
    double d = balance(s, eq);
    CHECK(eq->converged && d < 1e-9,
          "example kamman_ex1_vehicle: the tow force is the sum of the "
          "external loads to %.3g", d);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
}

static void test_turn_limit(void)
{
    ts_system *s = load("examples/kamman_ex1_vehicle.yaml", 10);
    ts_kernel *k;
    ts_equilibrium *eq0 = solve(s, &k, NULL);
    ts_kernel_free(k);
    static const double W[3] = {1e-2, 1e-3, 1e-4};
    double dang[3], dpos[3];
    int ok = eq0->converged;
    for (int i = 0; i < 3; i++) {
        s->tow.turn_rate = W[i];
        ts_equilibrium *eq = solve(s, &k, NULL);
        ok = ok && eq->converged;
        const ts_vehicle_result *a = &eq->vehicles[0], *b = &eq0->vehicles[0];
        dang[i] = fmax(fabs(a->pitch - b->pitch),
                       fmax(fabs(a->roll - b->roll), fabs(a->yaw - b->yaw)));
        dpos[i] = 0;
        for (int j = 0; j < 3 * s->nnodes; j++)
            dpos[i] = fmax(dpos[i], fabs(eq->positions[j] - eq0->positions[j]));
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
    }
    /* Linear in the turn rate: differences fall 10 times per decade
     * ([9, 11]: the second-order term at 1e-2 rad/s is ~1 %). */
    CHECK(ok && dang[1] / dang[2] > 9 && dang[1] / dang[2] < 11 &&
              dpos[1] / dpos[2] > 9 && dpos[1] / dpos[2] < 11 &&
              dang[0] / dang[1] > 8 && dang[0] / dang[1] < 12,
          "turning trim -> straight trim: attitude differences %.3g, %.3g, "
          "%.3g rad and shape differences %.3g, %.3g, %.3g m at turn rates "
          "1e-2, 1e-3, 1e-4 rad/s",
          dang[0], dang[1], dang[2], dpos[0], dpos[1], dpos[2]);
    ts_equilibrium_free(eq0);
    ts_system_free(s);
}

/* tow -> upper (12 links) -> depressor (a vehicle with a hull and a
 * wing) -> lower (6 links, from a point under its tail) -> fish (a
 * sphere). */
static ts_system *between_system(void)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(2, 2, &err);
    snprintf(s->name, sizeof s->name, "between");
    s->env.water_density = RHO;
    s->env.gravity = G;
    s->tow.speed = 1.9;
    ts_cable *c = &s->cables[0];
    snprintf(c->name, sizeof c->name, "upper");
    c->from_body = -1;
    c->to_body = 0;
    c->length = 20;
    c->diameter = 0.012;
    c->mass_per_length = 0.35;
    c->nlinks = 12;
    c->cdn = 1.2;
    c->cdt = 0.01;
    c->can = 1;
    s->cables[1] = *c;
    c = &s->cables[1];
    snprintf(c->name, sizeof c->name, "lower");
    c->from_body = 0;
    c->to_body = 1;
    c->length = 6;
    c->nlinks = 6;
    c->has_from_point = 1;
    c->from_point[0] = -0.45;
    c->from_point[2] = 0.08;
    ts_body *b = &s->bodies[0];
    snprintf(b->name, sizeof b->name, "depressor");
    b->mass = 60;
    ts_vehicle *v = ts_body_set_vehicle(s, 0, &err);
    v->volume = 0.02;
    v->inertia[0] = 0.8;
    v->inertia[1] = v->inertia[2] = 4.5;
    v->mass_centre[2] = 0.03;
    v->attach[0] = 0.15;
    v->attach[2] = -0.12;
    v->surface_diameter = 0.2;
    v->ncomponents = 2;
    ts_component_defaults(&v->component[0], TS_COMP_HULL);
    snprintf(v->component[0].name, TS_VEHICLE_NAME_MAX, "hull");
    v->component[0].length = 1.1;
    v->component[0].diameter = 0.16;
    ts_component_defaults(&v->component[1], TS_COMP_SURFACE);
    snprintf(v->component[1].name, TS_VEHICLE_NAME_MAX, "wing");
    v->component[1].area = 0.25;
    v->component[1].span = 0.9;
    v->component[1].position[0] = -0.35;
    v->component[1].incidence = -0.12; /* pushes down */
    v->ncomponents = 3;
    ts_component_defaults(&v->component[2], TS_COMP_SURFACE);
    snprintf(v->component[2].name, TS_VEHICLE_NAME_MAX, "fin");
    v->component[2].area = 0.08;
    v->component[2].span = 0.3;
    v->component[2].roll = M_PI_2;
    v->component[2].position[0] = -0.45;
    ts_added_mass_spheroid(RHO, 1.1, 0.16, v->added_mass, NULL, &err);
    b = &s->bodies[1];
    snprintf(b->name, sizeof b->name, "fish");
    b->type = TS_BODY_SPHERE;
    b->diameter = 0.2;
    b->mass = 8;
    b->cd = 0.5;
    b->ca = 0.5;
    if (ts_system_build(s, &err) != TS_OK)
        printf("build: %s\n", err.msg);
    return s;
}

static void test_between(void)
{
    ts_system *s = between_system();
    ts_kernel *k;
    ts_eigen *e;
    ts_equilibrium *eq = solve(s, &k, &e);
    double d = eq->converged ? balance(s, eq) : INFINITY;
    CHECK(eq->converged && d < 1e-9,
          "a vehicle between two cables: converged (residual %.3g), the tow "
          "force is the sum of the external loads to %.3g; depressor pitch "
          "%.3f deg, depth %.3f m",
          eq->residual, d, eq->vehicles[0].pitch * 180 / M_PI,
          eq->vehicles[0].origin[2]);
    CHECK(e && e->verdict == TS_STABLE, "and it is stable: max Re %.4g 1/s",
          e ? e->max_real : NAN);
    ts_eigen_free(e);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
}

/* The trim of s by `method` into *eq (its kernel freed); TS_OK or the
 * solver's code. */
static int solve_by(const ts_system *s, ts_eq_method method,
                    ts_equilibrium **eq)
{
    ts_err err = {0};
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = method;
    ts_kernel *k = ts_kernel_alloc(s, &err);
    *eq = ts_equilibrium_alloc(s, &err);
    int rc = k && *eq ? ts_equilibrium_solve(k, &o, *eq, &err) : -1;
    if (rc != TS_OK)
        printf("  %s: %s\n", method == TS_EQ_NEWTON ? "newton" : "auto",
               err.msg);
    ts_kernel_free(k);
    return rc;
}

/* 5. Two methods: the default for vehicles without bending, shooting
 * (the march with the vehicles' attitudes and controllers as outer
 * unknowns, O(links)), against Newton on every coordinate (dense) on
 * the vehicle examples, a turn and a vehicle between two cables. */
static void test_shooting(void)
{
    struct {
        const char *what, *path;
        double turn;
    } cases[] = {
        {"kamman_ex1_vehicle", "examples/kamman_ex1_vehicle.yaml", 0},
        {"kamman_ex1_vehicle turning at 0.02 rad/s",
         "examples/kamman_ex1_vehicle.yaml", 0.02},
        {"aurora_towfish (3 loops)", "examples/aurora_towfish.yaml", 0},
        {"aurora_towfish turning at 0.01 rad/s",
         "examples/aurora_towfish.yaml", 0.01},
        {"a vehicle between two cables", NULL, 0},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        ts_system *s = cases[c].path ? load(cases[c].path, 0)
                                     : between_system();
        if (!s)
            continue;
        s->tow.turn_rate = cases[c].turn;
        ts_equilibrium *a = NULL, *b = NULL;
        int ra = solve_by(s, TS_EQ_AUTO, &a);
        int rb = solve_by(s, TS_EQ_NEWTON, &b);
        double L = 0, dpos = 0, datt = 0, dctl = 0;
        for (int l = 0; l < s->nlinks; l++)
            L += s->links[l].length;
        if (ra == TS_OK && rb == TS_OK) {
            for (int j = 0; j < 3 * s->nnodes; j++)
                dpos = fmax(dpos, fabs(a->positions[j] - b->positions[j]));
            for (int j = 0; j < 9 * s->nvehicles; j++)
                datt = fmax(datt, fabs(a->attitudes[j] - b->attitudes[j]));
            for (int j = 0; j < a->ncontrol; j++)
                dctl = fmax(dctl, fabs(a->controls[j] - b->controls[j]) /
                                      fmax(1.0, fabs(b->controls[j])));
        }
        /* Both balance the forces to 1e-10 of the largest: the shapes
         * they settle on differ by that times the condition of the
         * shape on the forces, a few thousand here: 1e-6 of the cable
         * length, 1e-6 in the rotation matrices and the controller
         * states (relative to 1), far below any physical difference. */
        CHECK(ra == TS_OK && rb == TS_OK && a->method == TS_EQ_SHOOTING &&
                  dpos <= 1e-6 * L && datt <= 1e-6 && dctl <= 1e-6,
              "%s: trimmed by shooting (%d outer iterations, %ld kernel "
              "calls and marches) as by Newton (%d iterations, %ld calls): "
              "positions within %.2g m (cable %.4g m), attitudes within "
              "%.2g, controller states within %.2g",
              cases[c].what, a ? a->iterations : 0,
              a ? a->evaluations : 0L, b ? b->iterations : 0,
              b ? b->evaluations : 0L, dpos, L, datt, dctl);
        ts_equilibrium_free(a);
        ts_equilibrium_free(b);
        ts_system_free(s);
    }
}

/* The message of solving s by `method` into msg[TS_ERR_MSG_MAX]; the
 * solve's code. */
static int failure_of(const ts_system *s, ts_eq_method method, char *msg)
{
    ts_err err = {0};
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = method;
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    int rc = k && eq ? ts_equilibrium_solve(k, &o, eq, &err) : -1;
    memcpy(msg, err.msg, TS_ERR_MSG_MAX);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return rc;
}

/* 6. Where shooting and then Newton both fail (a set point out of
 * reach), the message gives both reasons, shooting's first, and says
 * where shooting stopped: the worst outer equation (the depth loop and
 * its error) and a surface at its deflection limit. A message that no
 * longer fits when a place is put in front of it ends in "...". */
static void test_unreachable(void)
{
    ts_system *s = load("examples/aurora_towfish.yaml", 0);
    if (!CHECK(s, "the AURORA example loads"))
        return;
    ts_vehicle *v = s->bodies[s->cables[0].to_body].vehicle;
    char msg[TS_ERR_MSG_MAX];
    /* 400 m of depth on 150 m of cable. */
    v->loop[0].setpoint = 400;
    int rc = failure_of(s, TS_EQ_AUTO, msg);
    const char *sh = strstr(msg, "equilibrium: shooting with vehicles did "
                                 "not converge");
    const char *nw = strstr(msg, "; then Newton, the fallback, failed too: ");
    CHECK(rc == TS_ECONV && sh == msg && nw && nw > sh &&
              strstr(msg, "of the way from where the loops idle to their "
                          "set points") &&
              strstr(msg, "got no closer than outer mismatch") &&
              strstr(msg, "worst in loop 'depth' of vehicle 'aurora', its "
                          "error ") &&
              strstr(msg, "on the way to 400 m") &&
              strstr(nw, "Newton stopped after") &&
              strlen(msg) < TS_ERR_MSG_MAX - 1,
          "400 m of depth on 150 m of cable: shooting's stop, then "
          "Newton's (%zu characters): %s", strlen(msg), msg);
    rc = failure_of(s, TS_EQ_SHOOTING, msg);
    CHECK(rc == TS_ECONV && strstr(msg, "worst in loop 'depth'") &&
              !strstr(msg, "Newton"),
          "the same by shooting alone: its reason alone: %s", msg);
    /* The wing limited to 0.05 rad: it sits at its limit. */
    int wing = -1;
    for (int c = 0; c < v->ncomponents; c++)
        if (!strcmp(v->component[c].name, "wing"))
            wing = c;
    if (CHECK(wing >= 0, "the AURORA example has a wing")) {
        v->component[wing].limit = 0.05;
        v->loop[0].setpoint = 60;
        rc = failure_of(s, TS_EQ_SHOOTING, msg);
        CHECK(rc == TS_ECONV &&
                  strstr(msg, "with aurora.wing (2.865 deg) at its "
                              "deflection limit: a set point out of the "
                              "surfaces' reach?"),
              "60 m with the wing's limit at 0.05 rad: the wing named at "
              "its limit: %s", msg);
        CHECK(!strstr(msg, "stalling"), "the wing at 2.9 deg, its stall 15 "
              "deg: no stall named: %s", msg);
        /* Its stall at 2 +- 0.5 deg: the solve stops at its lift's
         * maximum, inside the stall's band, and says so. */
        v->component[wing].stall = 2.0 * M_PI / 180;
        v->component[wing].stall_width = 0.5 * M_PI / 180;
        rc = failure_of(s, TS_EQ_SHOOTING, msg);
        const char *w = strstr(msg, "with aurora.wing (angle of attack ");
        double a = w ? atof(w + strlen("with aurora.wing (angle of attack "))
                     : NAN;
        CHECK(rc == TS_ECONV && w && fabs(a) > 1.5 && fabs(a) < 2.5 &&
                  strstr(w, "deg, its stall 2 +- 0.5 deg) stalling: more "
                            "lift asked than it gives?"),
              "the wing's stall at 2 deg: the wing named stalling, its angle "
              "of attack within the stall's band: %s", msg);
    }
    ts_system_free(s);

    ts_err err = {0};
    char big[TS_ERR_MSG_MAX];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    ts_fail(&err, TS_ECONV, "%s", big);
    ts_err_prefix(&err, "%s: ", "examples/aurora_towfish.yaml");
    size_t n = strlen(err.msg);
    CHECK(n == TS_ERR_MSG_MAX - 1 && !strcmp(err.msg + n - 4, "x...") &&
              !strncmp(err.msg, "examples/aurora_towfish.yaml: x", 31),
          "a message cut by the place put in front ends in '...' (%zu "
          "characters)", n);
}

int main(void)
{
    gsl_set_error_handler_off();
    test_zero_length();
    test_balance();
    test_turn_limit();
    test_between();
    test_shooting();
    test_unreachable();
    return tc_done();
}
