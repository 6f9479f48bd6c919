/* test_extreme.c: extreme and stiff cases. Each
 * case asserts either a correct answer, checked by something that does
 * not come from the solver (an invariant, a symmetry, a limit, an
 * independent computation), or a clear refusal. Per case, what is
 * asserted and why its tolerance:
 *
 *  hanging       V = 0: every node straight below the tow point (1e-12 L)
 *                and each link's tension the wet weight below its midpoint
 *                plus the sphere's (1e-12 relative: sums of exact loads).
 *  knots30       a 30-knot tow: Newton from a perturbed shape finds the
 *                shooting answer (1e-9 L, two methods); the force on the
 *                tow point equals the sum of all external nodal loads
 *                (1e-9 of the largest force: a straight tow has no
 *                inertia); every node stays in the water.
 *  long          10 km of cable in 2000 links, bare, Cdt = 0: every link at
 *                the critical angle w cos(phi) = 1/2 rho Cdn d V^2
 *                sin^2(phi) (GSL root; 1e-9 rad: the lumped balance puts
 *                each link exactly there).
 *  neutral       a nearly neutrally buoyant cable (wet weight 1e-6 of its
 *                weight): hanging at V = 0 with tensions equal to the wet
 *                weight below (1e-6 relative: the wet weight is a
 *                difference of numbers 1e6 times larger); towed, at its
 *                (tiny, 2.3e-4 rad) critical angle (1e-9 rad); an exactly
 *                neutral free end at V = 0 has no steady shape: refused
 *                (TS_ESINGULAR, naming the link).
 *  heavy body    a sphere 1000 times the cable's mass: the sphere's offset
 *                aft is the small-angle quadrature -int (D_s + q u) /
 *                (W + w u) du of the taut cable (1e-3: lumping O(1/N^2)
 *                at 100 links ~1e-4, small angles O(theta^2) ~5e-5).
 *  light body    a sphere 1/1000 of the cable's mass (no drag): the shape
 *                tends to the bare cable's (within 2e-3 L) and the change
 *                is linear in the body's load: half the body (mass and
 *                volume) moves the end half as far (0.5 +- 0.012; the
 *                bare end carries only half a link, so the body is a 6 %
 *                change there and the ratio measured is 0.5095), and the
 *                ratio's distance from 0.5 halves again with the next
 *                halving (a smooth second-order term: 0.5 +- 0.05 of it).
 *  tight turn    a 0.5 rad/s turn at 1 m/s (radius 2 m) with 30 m of
 *                cable, no added mass: converges; mirror symmetry under
 *                Omega -> -Omega (1e-8 L); total force balance including
 *                the centripetal terms m_k a_frame_k (1e-9) and moment
 *                balance about the turn axis (1e-9).
 *  in air        tow point 27 m above the water on 30 m of cable: in the
 *                air part the horizontal tension is constant and the
 *                vertical one changes by each node's weight (1e-9
 *                relative: no air drag), most nodes in air.
 *  chart         links near cos(theta2) = 0: a cable streaming sideways in
 *                a side current at V = 0 is the forward tow rotated by 90
 *                degrees about z (positions 1e-9 L, tensions 1e-9); a
 *                nearly neutral bare cable makes |cos theta2| ~ 1e-4.
 *  EA 1e12       elastic links 1e12 N: the equilibrium equals the rigid
 *                one (1e-7 L, tensions 1e-8); the axial modes of a hanging
 *                4-link chain against the spring-mass chain K x = w^2 M x
 *                (GSL gensymm): within each mode's own error bound
 *                (honesty) and equal to 1e-6 (the linearizer steps a
 *                strain by a fraction of itself, so a taut link stays
 *                taut). Control at EA 1e8: equal to 1e-6.
 *  mm links      1 m of cable in 1000 links: order 2 in links from 250,
 *                500, 1000 (+- 0.2) with an estimated error below 1e-6 L
 *                at 1000; hanging tensions exact (1e-9); a 5 cm chain of
 *                1 mm links in vacuum: its lowest frequency within 1 % of
 *                the continuum's (j01 / 2) sqrt(g / L) / 2 pi.
 *  drag          zero drag (cable and sphere): the towed shape is the
 *                hanging one (1e-12 L); Cdn 1e6 with Cdt 0 (bare): the
 *                critical angle (1e-9 rad); Cdn = Cdt = 1e6 with a
 *                sphere: the horizontal tow force is the skin friction of
 *                a horizontal cable plus the sphere's drag (1e-3); a deep
 *                tow point with Cdn 1e6 and a sphere, and Cdn 1e4 with the
 *                sphere awash at the surface: force balance (1e-9).
 *  overflow      inputs whose loads overflow double precision are refused
 *                before any solve (TS_EDOMAIN), each message naming the
 *                input and the part and holding no "nan": speed and turn
 *                rate 1e300, a drag coefficient 1e300, a cable weight of
 *                1e300 N/m, gravity 1e300, EA 5e-324 N, a tow-point heave
 *                of 1e300 m at 1 Hz and a turn-rate manoeuvre to 1e300
 *                rad/s (ts_sim_alloc). The bound is the loads' size, not
 *                the solve: 1e60 m/s (drag ~1e122 N) still converges,
 *                1e80 m/s (~1e162 N) is refused. The motion bounds of
 *                ts_excitation_bound: a sine's A w and A w^2 (exact), a
 *                manoeuvre's change added to the base speed.
 *
 * With --report, one line per case, "CASE", name, what is asserted,
 * result, run time in ms and verdict separated by tabs, is printed for
 * tools/make_verification.sh (doc/verification.md). */
#include <gsl/gsl_eigen.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tcheck.h"
#include "towstab/analysis.h"
#include "towstab/converge.h"
#include "towstab/eigen.h"
#include "towstab/excitation.h"
#include "towstab/simulate.h"
#include "towstab/equilibrium.h"
#include "towstab/health.h"
#include "towstab/linearize.h"

#define RHO 1025.9
#define G 9.80665

/* ---- case bookkeeping ------------------------------------------------- */

static int report;
static struct {
    const char *name, *what;
    double t0;
    int pass0, fail0;
    char result[512];
} cur;

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void begin(const char *name, const char *what)
{
    cur.name = name;
    cur.what = what;
    cur.pass0 = tc_npass;
    cur.fail0 = tc_nfail;
    cur.result[0] = '\0';
    printf("---- %s\n", name);
    cur.t0 = now();
}

/* Append to the case's one-line result. */
static void result(const char *fmt, ...)
{
    size_t len = strlen(cur.result);
    if (len && len + 2 < sizeof cur.result) {
        strcat(cur.result, "; ");
        len += 2;
    }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cur.result + len, sizeof cur.result - len, fmt, ap);
    va_end(ap);
}

static void end(void)
{
    double ms = (now() - cur.t0) * 1e3;
    int np = tc_npass - cur.pass0, nf = tc_nfail - cur.fail0;
    const char *verdict = nf ? "FAIL" : "pass";
    if (report)
        printf("CASE\t%s\t%s\t%s\t%.1f\t%s, %d checks\n", cur.name,
               cur.what, cur.result, ms, verdict, np + nf);
}

/* ---- systems ---------------------------------------------------------- */

typedef struct spec {
    double rho, V, omega, tow_z, cur[3];
    double L, d, mpl;      /* cable: length m, diameter m, kg/m */
    int N;
    double cdn, cdt, can, ea;
    int body;              /* 1: a sphere at the end */
    double bD, bm, bcd, bca;
} spec;

/* Kamman ex. 1 in SI (doc/model.md section 9) at 2.5 m/s, 20 links. */
static spec ex1(void)
{
    spec s = {RHO, 2.5, 0, 0, {0, 0, 0}, 30.48, 0.0254, 1.488, 20,
              1.2, 0.01, 1.0, 0, 1, 0.254, 22.68, 0.5, 0.5};
    return s;
}

static ts_system *make(const spec *p)
{
    ts_err err = {0};
    ts_system *s = ts_system_alloc(1, p->body ? 1 : 0, &err);
    if (!s)
        return NULL;
    snprintf(s->name, sizeof s->name, "extreme");
    s->env.water_density = p->rho;
    s->env.gravity = G;
    memcpy(s->env.current, p->cur, sizeof s->env.current);
    s->tow.speed = p->V;
    s->tow.turn_rate = p->omega;
    s->tow.point[2] = p->tow_z;
    ts_cable *c = &s->cables[0];
    snprintf(c->name, sizeof c->name, "cable");
    c->from_body = -1;
    c->to_body = p->body ? 0 : -1;
    c->length = p->L;
    c->diameter = p->d;
    c->mass_per_length = p->mpl;
    c->nlinks = p->N;
    c->cdn = p->cdn;
    c->cdt = p->cdt;
    c->can = p->can;
    c->ea = p->ea;
    if (p->body) {
        ts_body *b = &s->bodies[0];
        snprintf(b->name, sizeof b->name, "sphere");
        b->type = TS_BODY_SPHERE;
        b->diameter = p->bD;
        b->mass = p->bm;
        b->cd = p->bcd;
        b->ca = p->bca;
    }
    if (ts_system_build(s, &err) != TS_OK) {
        printf("     build: %s\n", err.msg);
        ts_system_free(s);
        return NULL;
    }
    return s;
}

/* Solve; *rc the return code; err's message printed on failure. */
static ts_equilibrium *solve_opts(const ts_system *s,
                                  const ts_equilibrium_opts *o, int *rc,
                                  ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(s, err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(s, err) : NULL;
    *rc = eq ? ts_equilibrium_solve(k, o, eq, err) : TS_ENOMEM;
    if (*rc != TS_OK)
        printf("     solve: %s\n", err->msg);
    ts_kernel_free(k);
    return eq;
}

static ts_equilibrium *solve(const ts_system *s, int *rc)
{
    ts_err err = {0};
    return solve_opts(s, NULL, rc, &err);
}

/* External nodal loads (weight, buoyancy, drag) at an equilibrium. */
static double *loads_at(const ts_system *s, const ts_equilibrium *eq)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    double *y = calloc(6 * (size_t)s->nlinks, sizeof(double));
    double *f = malloc(6 * (size_t)s->nlinks * sizeof(double));
    double *Q = malloc(3 * (size_t)s->nnodes * sizeof(double));
    if (k && y && f && Q) {
        ts_kernel_set_directions(k, eq->directions, NULL, TS_CHART_RECHART,
                                 y);
        ts_kernel_eval(k, y, NULL, f);
        memcpy(Q, ts_kernel_loads(k), 3 * (size_t)s->nnodes * sizeof(double));
    }
    ts_kernel_free(k);
    free(y);
    free(f);
    return Q;
}

static double max_pos_diff(const ts_equilibrium *a, const ts_equilibrium *b)
{
    double m = 0;
    for (int i = 0; i < 3 * a->nnodes; i++)
        m = fmax(m, fabs(a->positions[i] - b->positions[i]));
    return m;
}

/* Angle of link l below the horizontal, in its vertical plane. */
static double dip(const ts_equilibrium *eq, int l)
{
    const double *n = eq->directions + 3 * l;
    return atan2(n[2], hypot(n[0], n[1]));
}

typedef struct crit_params {
    double w, q;
} crit_params;

static double crit_f(double phi, void *p)
{
    const crit_params *c = p;
    return c->w * cos(phi) - c->q * sin(phi) * sin(phi);
}

/* The critical angle from the horizontal: w cos(phi) = q sin^2(phi), one
 * root on (0, pi/2), by GSL's Brent solver. */
static double critical_angle(double w, double q)
{
    crit_params c = {w, q};
    gsl_function F = {crit_f, &c};
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    gsl_root_fsolver_set(s, &F, 0.0, M_PI / 2);
    double phi = NAN;
    int status = GSL_CONTINUE;
    for (int it = 0; it < 300 && status == GSL_CONTINUE; it++) {
        gsl_root_fsolver_iterate(s);
        phi = gsl_root_fsolver_root(s);
        status = gsl_root_test_interval(gsl_root_fsolver_x_lower(s),
                                        gsl_root_fsolver_x_upper(s), 0,
                                        1e-16);
    }
    gsl_root_fsolver_free(s);
    return phi;
}

/* Largest |dip - phi| over the links of a bare cable at the critical
 * angle; *side the largest |n_y|. */
static double critical_check(const spec *p, double *phi_out, int *rc,
                             double *side)
{
    double w = (p->mpl - p->rho * M_PI * p->d * p->d / 4) * G;
    double phi = critical_angle(w, 0.5 * p->rho * p->cdn * p->d * p->V *
                                       p->V);
    *phi_out = phi;
    ts_system *s = make(p);
    ts_equilibrium *eq = s ? solve(s, rc) : NULL;
    double worst = INFINITY;
    *side = INFINITY;
    if (eq && *rc == TS_OK) {
        worst = *side = 0;
        for (int l = 0; l < s->nlinks; l++) {
            worst = fmax(worst, fabs(dip(eq, l) - phi));
            *side = fmax(*side, fabs(eq->directions[3 * l + 1]));
        }
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);
    return worst;
}

/* Tension of each link = wet weight of everything below its midpoint
 * (straight hanging chain). Largest relative deviation. */
static double hanging_check(const ts_system *s, const ts_equilibrium *eq,
                            double *xy)
{
    double rho = s->env.water_density, worst = 0;
    const ts_cable *c = &s->cables[0];
    double w = (c->mass_per_length - rho * M_PI * c->diameter * c->diameter /
                                         4) *
               G;
    double Wb = 0;
    if (s->nbodies)
        Wb = (s->bodies[0].mass - rho * ts_body_volume(&s->bodies[0])) * G;
    double l = c->length / c->nlinks;
    *xy = 0;
    for (int k = 0; k < s->nlinks; k++) {
        double below = w * (c->length - (k + 0.5) * l) + Wb;
        worst = fmax(worst, fabs(eq->tensions[k] - below) / fabs(below));
    }
    for (int i = 0; i < s->nnodes; i++)
        *xy = fmax(*xy, hypot(eq->positions[3 * i], eq->positions[3 * i + 1]));
    return worst;
}

/* ---- the cases ----------------------------------------------------------- */

static void case_hanging(void)
{
    begin("hanging", "V = 0: nodes below the tow point, tensions = wet "
                     "weight below");
    spec p = ex1();
    p.V = 0;
    ts_system *s = make(&p);
    int rc;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (CHECK(eq && rc == TS_OK, "hanging: converged")) {
        double xy, dev = hanging_check(s, eq, &xy);
        CHECK(xy <= 1e-12 * p.L && dev <= 1e-12,
              "hanging: nodes below the tow point (%.2g m), tensions = wet "
              "weight below the link midpoints (max rel. dev. %.2g <= "
              "1e-12)",
              xy, dev);
        result("converged; max |x,y| %.1g m; tension deviation %.1g",
               xy, dev);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);
    end();
}

static void case_knots30(void)
{
    begin("30-knot tow", "Newton = shooting; tow force = sum of loads; all "
                         "nodes in water");
    spec p = ex1();
    p.V = 30 * 1852.0 / 3600.0;
    ts_system *s = make(&p);
    int rc, rc2;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (CHECK(eq && rc == TS_OK, "30 knots: converged (%s)",
              eq ? ts_eq_method_name(eq->method) : "")) {
        double *guess = malloc(3 * (size_t)s->nlinks * sizeof(double));
        for (int l = 0; l < s->nlinks; l++) {
            double t1, t2, n[3];
            ts_direction_angles(eq->directions + 3 * l, &t1, &t2);
            t1 += 0.05;
            t2 += 0.03;
            n[0] = -cos(t1) * cos(t2);
            n[1] = -sin(t2);
            n[2] = sin(t1) * cos(t2);
            memcpy(guess + 3 * l, n, sizeof n);
        }
        ts_equilibrium_opts o;
        ts_equilibrium_opts_default(&o);
        o.method = TS_EQ_NEWTON;
        o.guess = guess;
        ts_err err = {0};
        ts_equilibrium *eq2 = solve_opts(s, &o, &rc2, &err);
        double d = eq2 && rc2 == TS_OK ? max_pos_diff(eq, eq2) : INFINITY;
        CHECK(d <= 1e-9 * p.L,
              "30 knots: Newton from a shape 0.05 rad off finds the "
              "shooting answer (max |dr| %.2g m <= 1e-9 L)",
              d);
        double *Q = loads_at(s, eq), sum[3] = {0, 0, 0}, zmin = INFINITY;
        for (int i = 0; i < s->nnodes; i++) {
            for (int j = 0; j < 3; j++)
                sum[j] += Q[3 * i + j];
            zmin = fmin(zmin, eq->positions[3 * i + 2]);
        }
        double bal = 0;
        for (int j = 0; j < 3; j++)
            bal = fmax(bal, fabs(eq->tow_force[j] - sum[j]));
        CHECK(bal <= 1e-9 * eq->force_scale,
              "30 knots: the force on the tow point is the sum of the "
              "nodal loads (|diff| %.2g N <= 1e-9 of %.4g N)",
              bal, eq->force_scale);
        CHECK(zmin >= 0, "30 knots: every node in the water (min depth "
                         "%.3g m)",
              zmin);
        result("converged (%s); sphere depth %.4g m, top tension %.6g N; "
               "Newton agrees to %.1g m; balance %.1g N",
               ts_eq_method_name(eq->method),
               eq->positions[3 * s->nlinks + 2], eq->top_tension, d, bal);
        free(Q);
        free(guess);
        ts_equilibrium_free(eq2);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);
    end();
}

static void case_long(void)
{
    begin("10 km, 2000 links", "bare cable, Cdt = 0: every link at the "
                               "critical angle");
    spec p = ex1();
    p.L = 10000;
    p.N = 2000;
    p.cdt = 0;
    p.body = 0;
    double phi, side;
    int rc;
    double worst = critical_check(&p, &phi, &rc, &side);
    CHECK(rc == TS_OK && worst <= 1e-9 && side <= 1e-12,
          "10 km / 2000 links: all links at the critical angle %.9f deg "
          "(max |angle - phi| %.2g rad <= 1e-9)",
          phi * 180 / M_PI, worst);
    result("converged; critical angle %.6f deg, max deviation %.1g rad",
           phi * 180 / M_PI, worst);
    end();
}

static void case_neutral(void)
{
    begin("nearly neutral cable", "hanging tensions; critical angle; exact "
                                  "neutral refused");
    spec p = ex1();
    p.body = 0;
    double neutral = p.rho * M_PI * p.d * p.d / 4;
    p.mpl = neutral * (1 + 1e-6);
    p.V = 0;
    ts_system *s = make(&p);
    int rc;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (CHECK(eq && rc == TS_OK, "nearly neutral, V = 0: converged")) {
        double xy, dev = hanging_check(s, eq, &xy);
        CHECK(xy <= 1e-9 * p.L && dev <= 1e-6,
              "nearly neutral, V = 0: hanging straight (%.2g m), tensions = "
              "wet weight below (rel. dev. %.2g <= 1e-6)",
              xy, dev);
        result("hanging: top tension %.3g N, deviation %.1g", eq->top_tension,
               dev);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);

    p.V = 2.5;
    p.cdt = 0;
    double phi, side;
    double worst = critical_check(&p, &phi, &rc, &side);
    CHECK(rc == TS_OK && worst <= 1e-9,
          "nearly neutral, towed: links at the critical angle %.3g rad "
          "(max |angle - phi| %.2g rad <= 1e-9)",
          phi, worst);
    result("towed: critical angle %.3g rad, deviation %.1g rad", phi, worst);

    p.V = 0;
    p.mpl = neutral;
    s = make(&p);
    ts_err err = {0};
    eq = s ? solve_opts(s, NULL, &rc, &err) : NULL;
    CHECK(rc == TS_ESINGULAR && strstr(err.msg, "link") &&
              strstr(err.msg, "neutrally buoyant"),
          "exactly neutral free end at V = 0: refused (TS_ESINGULAR): %s",
          err.msg);
    result("exactly neutral: refused (%s)", ts_strerror(rc));
    ts_equilibrium_free(eq);
    ts_system_free(s);
    end();
}

static void case_heavy(void)
{
    begin("body 1000x heavier", "sphere offset = small-angle taut-cable "
                                "quadrature");
    spec p = ex1();
    p.N = 100;
    p.bm = 1000 * p.mpl * p.L;
    ts_system *s = make(&p);
    int rc;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (CHECK(eq && rc == TS_OK, "heavy body: converged")) {
        double W = (p.bm - p.rho * M_PI * pow(p.bD, 3) / 6) * G;
        double Ds = 0.5 * p.rho * p.bcd * M_PI * p.bD * p.bD / 4 * p.V * p.V;
        double w = (p.mpl - p.rho * M_PI * p.d * p.d / 4) * G;
        double q = 0.5 * p.rho * p.cdn * p.d * p.V * p.V;
        /* int_0^L (Ds + q u) / (W + w u) du */
        double xb = -((q / w) * p.L +
                      (Ds - q * W / w) / w * log1p(w * p.L / W));
        int node = ts_system_body_node(s, 0);
        double x = eq->positions[3 * node], z = eq->positions[3 * node + 2];
        CHECK(fabs(x - xb) <= 1e-3 * fabs(xb) && fabs(z - p.L) <= 1e-4 * p.L,
              "heavy body: sphere x %.6f m vs taut-cable quadrature %.6f m "
              "(1e-3), depth %.6f m vs L (1e-4)",
              x, xb, z);
        result("sphere x %.5f m (quadrature %.5f m), depth %.5f m", x, xb, z);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);
    end();
}

/* End-node position of the cable with a light, dragless sphere of mass m
 * and diameter D (or none when m = 0). */
static int light_end(double m, double D, double r[3])
{
    spec p = ex1();
    p.body = m > 0;
    p.bm = m;
    p.bD = D;
    p.bcd = 0;
    ts_system *s = make(&p);
    int rc;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (eq && rc == TS_OK)
        memcpy(r, eq->positions + 3 * s->nlinks, 3 * sizeof(double));
    ts_equilibrium_free(eq);
    ts_system_free(s);
    return eq ? rc : TS_ENOMEM;
}

static void case_light(void)
{
    begin("body 1000x lighter", "shape tends to the bare cable's, linearly "
                                "in the body's load");
    spec p = ex1();
    double m = p.mpl * p.L / 1000, D = 0.01;
    double r0[3], r[3][3], d[3];
    int ok = light_end(0, 0, r0) == TS_OK;
    for (int i = 0; i < 3; i++) {
        double f = pow(0.5, i);
        ok &= light_end(m * f, D * cbrt(f), r[i]) == TS_OK;
        d[i] = 0;
        for (int j = 0; j < 3; j++)
            d[i] += (r[i][j] - r0[j]) * (r[i][j] - r0[j]);
        d[i] = sqrt(d[i]);
    }
    if (CHECK(ok, "light body: bare and three light bodies converged")) {
        CHECK(d[0] > 0 && d[0] <= 2e-3 * p.L,
              "light body: the end moves %.3g m (> 0, <= 2e-3 L) from the "
              "bare cable's",
              d[0]);
        double q1 = d[1] / d[0], q2 = d[2] / d[1];
        CHECK(fabs(q1 - 0.5) <= 0.012 &&
                  fabs((q2 - 0.5) / (q1 - 0.5) - 0.5) <= 0.05,
              "light body: half the body moves it half as far (ratio %.5f "
              "= 0.5 +- 0.012), and the deviation halves with it (next "
              "ratio %.5f)",
              q1, q2);
        result("end moves %.3g m from the bare cable's; half body: ratio "
               "%.4f, quarter: %.4f",
               d[0], q1, q2);
    }
    end();
}

static void case_turn(void)
{
    begin("turn radius < cable", "mirror symmetry; force and moment "
                                 "balance in the rotating frame");
    spec p = ex1();
    p.V = 1.0;
    p.omega = 0.5;
    p.can = 0;
    p.bca = 0;
    ts_system *s = make(&p);
    int rc, rc2;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    p.omega = -0.5;
    ts_system *sm = make(&p);
    ts_equilibrium *em = sm ? solve(sm, &rc2) : NULL;
    if (CHECK(eq && em && rc == TS_OK && rc2 == TS_OK,
              "turn of radius 2 m with 30 m of cable: converged (%s)",
              eq ? ts_eq_method_name(eq->method) : "")) {
        double mir = 0;
        for (int i = 0; i < s->nnodes; i++)
            for (int j = 0; j < 3; j++) {
                double b = em->positions[3 * i + j] * (j == 1 ? -1 : 1);
                mir = fmax(mir, fabs(eq->positions[3 * i + j] - b));
            }
        CHECK(mir <= 1e-8 * p.L,
              "turn: Omega -> -Omega mirrors y (max |dr| %.2g m <= 1e-8 L)",
              mir);
        double *Q = loads_at(s, eq), sum[3] = {0, 0, 0}, mom = 0, momt;
        double W = 0.5, V = 1.0, cy = V / W, fscale = eq->force_scale;
        for (int i = 0; i < s->nnodes; i++) {
            const double *r = eq->positions + 3 * i, *q = Q + 3 * i;
            double m = s->nodes[i].mass;
            double afr[3] = {-W * W * r[0], W * V - W * W * r[1], 0};
            for (int j = 0; j < 3; j++)
                sum[j] += q[j] - m * afr[j];
            mom += r[0] * q[1] - (r[1] - cy) * q[0];
        }
        const double *r0 = eq->positions, *F = eq->tow_force;
        momt = r0[0] * F[1] - (r0[1] - cy) * F[0];
        double bal = 0;
        for (int j = 0; j < 3; j++)
            bal = fmax(bal, fabs(F[j] - sum[j]));
        CHECK(bal <= 1e-9 * fscale,
              "turn: tow force = sum of (load - m a_frame) (|diff| %.2g N "
              "<= 1e-9 of %.4g N)",
              bal, fscale);
        CHECK(fabs(mom - momt) <= 1e-9 * fscale * p.L,
              "turn: moment of the loads about the turn axis = that of the "
              "tow force (%.6g vs %.6g N m)",
              mom, momt);
        int node = s->nlinks;
        result("converged (%s); sphere at (%.3f, %.3f, %.3f) m; mirror %.1g "
               "m; balance %.1g N",
               ts_eq_method_name(eq->method), eq->positions[3 * node],
               eq->positions[3 * node + 1], eq->positions[3 * node + 2], mir,
               bal);
        free(Q);
    }
    ts_equilibrium_free(eq);
    ts_equilibrium_free(em);
    ts_system_free(s);
    ts_system_free(sm);
    end();
}

static void case_air(void)
{
    begin("tow point far above water", "catenary invariants of the part "
                                       "in air");
    spec p = ex1();
    p.tow_z = -27;
    p.N = 40;
    ts_system *s = make(&p);
    int rc;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (CHECK(eq && rc == TS_OK, "tow point 27 m above: converged")) {
        int inair = 0;
        double hx = 0, vz = 0;
        for (int k = 1; k < s->nlinks; k++) {
            /* Node k + 1 joins links k and k + 1 (0-based k - 1, k). */
            const double *ra = eq->positions + 3 * (k - 1);
            const double *rb = eq->positions + 3 * k;
            const double *rc_ = eq->positions + 3 * (k + 1);
            if (!(ra[2] < 0 && rb[2] < 0 && rc_[2] < 0))
                continue;
            inair++;
            const double *na = eq->directions + 3 * (k - 1);
            const double *nb = eq->directions + 3 * k;
            double ta = eq->tensions[k - 1], tb = eq->tensions[k];
            hx = fmax(hx, fabs(ta * na[0] - tb * nb[0]) / eq->top_tension);
            vz = fmax(vz, fabs(ta * na[2] - tb * nb[2] -
                               s->nodes[k].mass * G) /
                              eq->top_tension);
        }
        CHECK(inair > s->nlinks / 2,
              "tow point 27 m above: most nodes in air (%d of %d)", inair,
              s->nlinks);
        CHECK(hx <= 1e-9 && vz <= 1e-9,
              "in air: horizontal tension constant (%.2g) and vertical "
              "tension changes by the node weight (%.2g), relative 1e-9",
              hx, vz);
        result("%d of %d nodes in air; invariants to %.1g, %.1g", inair,
               s->nlinks, hx, vz);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);
    end();
}

static void case_chart(void)
{
    begin("links near the chart singularity", "sideways cable = forward "
                                              "tow rotated 90 degrees");
    static const double mplf[2] = {1.0, 0.0};
    for (int c = 0; c < 2; c++) {
        spec f = ex1(), sd;
        if (c == 1) {
            f.body = 0;
            f.mpl = f.rho * M_PI * f.d * f.d / 4 * (1 + 2e-7);
            f.V = 3;
        } else {
            f.V = 15;
        }
        (void)mplf;
        sd = f;
        sd.V = 0;
        sd.cur[1] = f.V;
        ts_system *sf = make(&f), *ss = make(&sd);
        int r1, r2;
        ts_equilibrium *ef = sf ? solve(sf, &r1) : NULL;
        ts_equilibrium *es = ss ? solve(ss, &r2) : NULL;
        const char *what = c ? "nearly neutral bare cable, 3 m/s"
                             : "ex. 1 at 15 m/s";
        if (!CHECK(ef && es && r1 == TS_OK && r2 == TS_OK,
                   "%s: forward and sideways converged", what)) {
            ts_equilibrium_free(ef);
            ts_equilibrium_free(es);
            ts_system_free(sf);
            ts_system_free(ss);
            continue;
        }
        double dr = 0, dt = 0, cmin = 1;
        for (int i = 0; i < sf->nnodes; i++) {
            const double *a = ef->positions + 3 * i, *b = es->positions + 3 * i;
            /* Rotation by -90 degrees about z: (x, y) -> (y, -x). */
            dr = fmax(dr, fmax(fabs(b[0] - a[1]),
                               fmax(fabs(b[1] + a[0]), fabs(b[2] - a[2]))));
        }
        for (int l = 0; l < sf->nlinks; l++) {
            dt = fmax(dt, fabs(es->tensions[l] - ef->tensions[l]) /
                              ef->top_tension);
            double t1, t2;
            ts_direction_angles(es->directions + 3 * l, &t1, &t2);
            cmin = fmin(cmin, fabs(cos(t2)));
        }
        CHECK(dr <= 1e-9 * f.L && dt <= 1e-9,
              "%s: the sideways cable is the forward one rotated (|dr| %.2g "
              "m <= 1e-9 L, tensions %.2g <= 1e-9); min |cos theta2| %.2g",
              what, dr, dt, cmin);
        if (c == 1)
            CHECK(cmin < 1e-3, "%s: links within 1e-3 of the singularity "
                               "(min |cos theta2| %.2g)",
                  what, cmin);
        result("%s: min |cos theta2| %.1g, rotation symmetry to %.1g m",
               what, cmin, dr);
        ts_equilibrium_free(ef);
        ts_equilibrium_free(es);
        ts_system_free(sf);
        ts_system_free(ss);
    }
    end();
}

/* Axial angular frequencies of a hanging elastic chain of N links (fixed
 * top): K x = w^2 M x with springs EA / l and node masses (half links,
 * plus the sphere with its added mass at the end). GSL gensymm. */
static void chain_axial(const spec *p, double *w)
{
    int N = p->N;
    double l = p->L / N, k = p->ea / l;
    gsl_matrix *K = gsl_matrix_calloc(N, N), *M = gsl_matrix_calloc(N, N);
    for (int i = 0; i < N; i++) {
        gsl_matrix_set(K, i, i, i + 1 < N ? 2 * k : k);
        if (i + 1 < N) {
            gsl_matrix_set(K, i, i + 1, -k);
            gsl_matrix_set(K, i + 1, i, -k);
        }
        double m = p->mpl * l * (i + 1 < N ? 1.0 : 0.5);
        if (i + 1 == N && p->body)
            m += p->bm + p->bca * p->rho * M_PI * pow(p->bD, 3) / 6;
        gsl_matrix_set(M, i, i, m);
    }
    gsl_vector *ev = gsl_vector_alloc(N);
    gsl_eigen_gensymm_workspace *ws = gsl_eigen_gensymm_alloc(N);
    gsl_eigen_gensymm(K, M, ev, ws);
    for (int i = 0; i < N; i++)
        w[i] = sqrt(gsl_vector_get(ev, i));
    for (int i = 1; i < N; i++) /* ascending */
        for (int j = i; j > 0 && w[j - 1] > w[j]; j--) {
            double t = w[j];
            w[j] = w[j - 1];
            w[j - 1] = t;
        }
    gsl_eigen_gensymm_free(ws);
    gsl_vector_free(ev);
    gsl_matrix_free(K);
    gsl_matrix_free(M);
}

/* The N highest modes of a hanging elastic chain against chain_axial:
 * *worst_rel the largest relative frequency error, *honest 1 when every
 * error is within the mode's error bound, *trusted the health verdict. */
static int axial_modes(double ea, double *worst_rel, int *honest,
                       int *trusted)
{
    spec p = ex1();
    p.V = 0;
    p.N = 4;
    p.ea = ea;
    ts_system *s = make(&p);
    ts_err err = {0};
    ts_kernel *k = s ? ts_kernel_alloc(s, &err) : NULL;
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(s, &err) : NULL;
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    int rc = eq ? ts_equilibrium_solve(k, NULL, eq, &err) : TS_ENOMEM;
    if (rc == TS_OK) {
        lin = ts_linear_alloc(k, &err);
        rc = lin ? ts_linearize_equilibrium(k, eq, NULL, lin, &err)
                 : TS_ENOMEM;
    }
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, NULL, &e, &err);
    *worst_rel = INFINITY;
    *honest = *trusted = 0;
    if (rc == TS_OK && e->nmodes >= p.N) {
        double w[16];
        chain_axial(&p, w);
        *worst_rel = 0;
        *honest = 1;
        for (int i = 0; i < p.N; i++) {
            const ts_mode *md = &e->modes[e->nmodes - p.N + i];
            double wc = hypot(md->re, md->im);
            *worst_rel = fmax(*worst_rel, fabs(wc - w[i]) / w[i]);
            *honest &= fabs(wc - w[i]) <= md->error_bound;
        }
        ts_trust t;
        ts_trust_init(&t);
        ts_health_modes(s, lin, e, NULL, &t, &err);
        *trusted = t.trustworthy;
    } else if (rc != TS_OK) {
        printf("     axial modes at EA %g: %s\n", ea, err.msg);
    }
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
    return rc;
}

static void case_stiff(void)
{
    begin("EA = 1e12 N", "equilibrium = rigid; axial modes vs spring-mass "
                         "chain");
    spec p = ex1();
    ts_system *sr = make(&p);
    p.ea = 1e12;
    ts_system *se = make(&p);
    int r1, r2;
    ts_equilibrium *er = sr ? solve(sr, &r1) : NULL;
    ts_equilibrium *ee = se ? solve(se, &r2) : NULL;
    if (CHECK(er && ee && r1 == TS_OK && r2 == TS_OK,
              "EA 1e12: rigid and elastic equilibria converged")) {
        double dr = max_pos_diff(er, ee), dt = 0;
        for (int l = 0; l < sr->nlinks; l++)
            dt = fmax(dt, fabs(ee->tensions[l] - er->tensions[l]) /
                              er->top_tension);
        CHECK(dr <= 1e-7 * p.L && dt <= 1e-8,
              "EA 1e12: the equilibrium is the rigid one (|dr| %.2g m <= "
              "1e-7 L, tensions %.2g <= 1e-8)",
              dr, dt);
        result("equilibrium = rigid to %.1g m", dr);
    }
    ts_equilibrium_free(er);
    ts_equilibrium_free(ee);
    ts_system_free(sr);
    ts_system_free(se);

    double rel, rel8;
    int honest, trusted, honest8, trusted8;
    int rc = axial_modes(1e12, &rel, &honest, &trusted);
    int rc8 = axial_modes(1e8, &rel8, &honest8, &trusted8);
    CHECK(rc == TS_OK && honest,
          "EA 1e12: each axial frequency is within its own error bound of "
          "the spring-mass chain's (largest rel. error %.3g)",
          rel);
    CHECK(rc == TS_OK && rel <= 1e-6,
          "EA 1e12: axial frequencies equal the spring-mass chain's to 1e-6 "
          "(largest rel. error %.3g)",
          rel);
    CHECK(rc8 == TS_OK && rel8 <= 1e-6,
          "EA 1e8 (control): axial frequencies equal the spring-mass "
          "chain's to 1e-6 (%.2g)",
          rel8);
    result("axial modes off by %.2g at 1e12, %.1g at 1e8", rel, rel8);
    end();
}

static void case_mm(void)
{
    begin("millimetre links", "order 2 in links to 1000 links of 1 mm; "
                              "hanging tensions; chain frequency");
    spec p = {RHO, 0.5, 0, 0, {0, 0, 0}, 1.0, 0.002, 0.01, 1000,
              1.2, 0.01, 1.0, 0, 1, 0.01, 0.01, 0.5, 0.5};
    ts_system *s = make(&p);
    ts_err err = {0};
    ts_conv_analysis an;
    ts_convergence *c = NULL;
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_CONVERGE);
    int rc = s ? ts_analysis_sweep(s, &rq, 0, &an, &err) : TS_ENOMEM;
    if (rc == TS_OK) {
        c = ts_convergence_alloc(an.name, TS_CONV_LINKS, an.nvalues,
                                 an.values, 3, &err);
        static const double N[3] = {250, 500, 1000};
        rc = c ? ts_convergence_add_series(c, "", &err) : TS_ENOMEM;
        if (rc == 0)
            rc = ts_convergence_sweep(c, 0, &an, N, 3, &err);
        if (rc == TS_OK)
            rc = ts_convergence_estimate(c, 1e-6, &err);
        ts_conv_analysis_free(&an);
    }
    if (CHECK(rc == TS_OK, "1 mm links: sweep 250, 500, 1000 (%s)",
              err.msg)) {
        const ts_conv_value *x = &c->values[0], *z = &c->values[2];
        const ts_conv_row *fin = NULL;
        for (int i = 0; i < c->nrows; i++)
            if (c->rows[i].setting == 1000)
                fin = &c->rows[i];
        CHECK(fabs(x->order - 2) <= 0.2 && fabs(z->order - 2) <= 0.2 &&
                  fin->errors[0] <= 1e-6 * p.L &&
                  fin->errors[2] <= 1e-6 * p.L,
              "1 mm links: order %.3f (x), %.3f (z) = 2 +- 0.2; error at "
              "1000 links %.2g, %.2g m <= 1e-6 L",
              x->order, z->order, fin->errors[0], fin->errors[2]);
        result("order %.2f, error at 1000 links %.1g m", z->order,
               fin->errors[2]);
    }
    ts_convergence_free(c);
    ts_system_free(s);

    p.V = 0;
    s = make(&p);
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    if (CHECK(eq && rc == TS_OK, "1 mm links hanging: converged")) {
        double xy, dev = hanging_check(s, eq, &xy);
        CHECK(dev <= 1e-9 && xy <= 1e-12,
              "1 mm links hanging: tensions = wet weight below (%.2g <= "
              "1e-9)",
              dev);
    }
    ts_equilibrium_free(eq);
    ts_system_free(s);

    /* 5 cm chain of 50 links in vacuum. */
    spec v = {0.0, 0, 0, 0, {0, 0, 0}, 0.05, 0.001, 0.01, 50,
              1.2, 0.01, 1.0, 0, 0, 0, 0, 0, 0};
    s = make(&v);
    ts_kernel *k = s ? ts_kernel_alloc(s, &err) : NULL;
    eq = k ? ts_equilibrium_alloc(s, &err) : NULL;
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    rc = eq ? ts_equilibrium_solve(k, NULL, eq, &err) : TS_ENOMEM;
    if (rc == TS_OK) {
        lin = ts_linear_alloc(k, &err);
        rc = lin ? ts_linearize_equilibrium(k, eq, NULL, lin, &err)
                 : TS_ENOMEM;
    }
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, NULL, &e, &err);
    if (CHECK(rc == TS_OK, "5 cm chain of 1 mm links in vacuum: modes (%s)",
              err.msg)) {
        double f1 = 2.404825557695773 / 2 * sqrt(G / v.L) / (2 * M_PI);
        double fl = e->modes[0].freq_hz;
        CHECK(fabs(fl - f1) <= 0.01 * f1 && e->verdict == TS_MARGINAL,
              "5 cm chain: lowest frequency %.5f Hz within 1 %% of the "
              "continuum's %.5f Hz; marginal (undamped)",
              fl, f1);
        result("5 cm chain: f1 %.4f Hz (continuum %.4f)", fl, f1);
    }
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
    end();
}

static void case_drag(void)
{
    begin("zero and huge drag", "no drag = hanging; critical angle at Cdn "
                                "1e6; skin-friction limit");
    /* Zero drag: speed does not matter. */
    spec p = ex1();
    p.cdn = p.cdt = p.bcd = 0;
    ts_system *s = make(&p);
    p.V = 0;
    ts_system *s0 = make(&p);
    int r1, r2;
    ts_equilibrium *e1 = s ? solve(s, &r1) : NULL;
    ts_equilibrium *e0 = s0 ? solve(s0, &r2) : NULL;
    if (CHECK(e1 && e0 && r1 == TS_OK && r2 == TS_OK,
              "zero drag: converged")) {
        double d = max_pos_diff(e1, e0);
        CHECK(d <= 1e-12 * p.L,
              "zero drag: towed at 2.5 m/s = hanging (|dr| %.2g m)", d);
        result("no drag: towed = hanging to %.1g m", d);
    }
    ts_equilibrium_free(e1);
    ts_equilibrium_free(e0);
    ts_system_free(s);
    ts_system_free(s0);

    /* Huge normal drag, bare: the critical angle. */
    p = ex1();
    p.body = 0;
    p.cdn = 1e6;
    p.cdt = 0;
    double phi, side;
    double worst = critical_check(&p, &phi, &r1, &side);
    CHECK(r1 == TS_OK && worst <= 1e-9,
          "Cdn 1e6, bare: links at the critical angle %.3g rad (max "
          "deviation %.2g rad <= 1e-9)",
          phi, worst);
    result("Cdn 1e6 bare: critical angle %.2g rad to %.1g", phi, worst);

    /* Huge normal and tangential drag: skin-friction limit. */
    p = ex1();
    p.cdn = p.cdt = 1e6;
    s = make(&p);
    e1 = s ? solve(s, &r1) : NULL;
    if (CHECK(e1 && r1 == TS_OK, "Cdn = Cdt = 1e6: converged")) {
        double fx = 0.5 * p.rho * p.cdt * M_PI * p.d * p.L * p.V * p.V +
                    0.5 * p.rho * p.bcd * M_PI * p.bD * p.bD / 4 * p.V * p.V;
        CHECK(fabs(-e1->tow_force[0] - fx) <= 1e-3 * fx,
              "Cdn = Cdt = 1e6: horizontal tow force %.6g N = skin friction "
              "of a horizontal cable + sphere drag %.6g N (1e-3)",
              -e1->tow_force[0], fx);
        result("Cdt 1e6: tow force %.4g N (limit %.4g N)", -e1->tow_force[0],
               fx);
    }
    ts_equilibrium_free(e1);
    ts_system_free(s);

    /* Huge normal drag with a sphere. */
    for (int surf = 0; surf < 2; surf++) {
        p = ex1();
        p.cdt = 0;
        p.cdn = surf ? 1e4 : 1e6;
        p.tow_z = surf ? 0 : 5;
        s = make(&p);
        e1 = s ? solve(s, &r1) : NULL;
        int conv = e1 && r1 == TS_OK;
        double bal = INFINITY;
        if (conv) {
            double *Q = loads_at(s, e1), sum[3] = {0, 0, 0};
            for (int i = 0; i < s->nnodes; i++)
                for (int j = 0; j < 3; j++)
                    sum[j] += Q[3 * i + j];
            bal = 0;
            for (int j = 0; j < 3; j++)
                bal = fmax(bal, fabs(e1->tow_force[j] - sum[j]));
            bal /= e1->force_scale;
            free(Q);
        }
        if (!surf) {
            CHECK(conv && bal <= 1e-9,
                  "Cdn 1e6, sphere, tow point 5 m deep: converged (%s), "
                  "force balance %.2g <= 1e-9",
                  conv ? ts_eq_method_name(e1->method) : "failed", bal);
            result("Cdn 1e6 with sphere, deep tow: %s",
                   conv ? "converged" : "FAILED");
        } else {
            CHECK(conv && bal <= 1e-9,
                  "Cdn 1e4, sphere, tow point at the surface: converged "
                  "(%s), force balance %.2g <= 1e-9",
                  conv ? ts_eq_method_name(e1->method) : "failed", bal);
            result("Cdn 1e4 with sphere at the surface: %s",
                   conv ? "converged" : "FAILED");
        }
        ts_equilibrium_free(e1);
        ts_system_free(s);
    }
    end();
}

/* Solve s; 1 when refused with TS_EDOMAIN and a message holding every
 * text of want[] (NULL-terminated) and no "nan". */
static int refused(const ts_system *s, const char *const want[],
                   char *msg, size_t size)
{
    ts_err err = {0};
    int rc;
    ts_equilibrium *eq = solve_opts(s, NULL, &rc, &err);
    ts_equilibrium_free(eq);
    snprintf(msg, size, "%s", err.msg);
    int ok = rc == TS_EDOMAIN && !strstr(err.msg, "nan");
    for (int i = 0; want[i]; i++)
        ok &= strstr(err.msg, want[i]) != NULL;
    return ok;
}

static void case_overflow(void)
{
    begin("overflowing loads", "refused before the solve, naming the input");
    static const struct {
        const char *what;
        double V, omega, cdt, mpl, g_scale, ea, d, bD;
        const char *want[4]; /* NULL-terminated */
    } c[] = {
        {"speed 1e300", 1e300, 0, 0.01, 1.488, 1, 0, 0.0254, 0.254,
         {"forces overflow at speed 1e+300 m/s", "drag", "cables[0]"}},
        {"turn rate 1e300", 2.5, 1e300, 0.01, 1.488, 1, 0, 0.0254, 0.254,
         {"turn rate 1e+300 rad/s", "drag", NULL}},
        {"Cdt 1e300", 2.5, 0, 1e300, 1.488, 1, 0, 0.0254, 0.254,
         {"drag coefficients 1.2 (normal) and 1e+300", "cables[0]", NULL}},
        {"weight 1e300 N/m", 2.5, 0, 0.01, 1e300 / G, 1, 0, 0.0254, 0.254,
         {"the weight on cables[0] 'cable' link 1", "a mass of", NULL}},
        {"gravity 1e300", 2.5, 0, 0.01, 1.488, 1e300 / G, 0, 0.0254, 0.254,
         {"gravity 1e+300 m/s^2", NULL, NULL}},
        {"EA 5e-324", 2.5, 0, 0.01, 1.488, 1, 4.9e-324, 0.0254, 0.254,
         {"EA 4.94e-324 N of cables[0]", "without bound", NULL}},
        /* A size, not the mass or the motion: the added mass (inertia)
         * or the buoyancy of the part, its diameter named. */
        {"cable diameter 1e300", 2.5, 0, 0.01, 1.488, 1, 0, 1e300, 0.254,
         {"at diameter 1e+300 m of cables[0] 'cable'", NULL, NULL}},
        {"cable diameter 1e120", 2.5, 0, 0.01, 1.488, 1, 0, 1e120, 0.254,
         {"at diameter 1e+120 m of cables[0]", "buoyancy", NULL}},
        {"sphere diameter 1e300", 2.5, 0, 0.01, 1.488, 1, 0, 0.0254, 1e300,
         {"at diameter 1e+300 m of bodies[0] 'sphere'", NULL, NULL}},
    };
    char msg[TS_ERR_MSG_MAX];
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        spec p = ex1();
        p.V = c[i].V;
        p.omega = c[i].omega;
        p.cdt = c[i].cdt;
        p.mpl = c[i].mpl;
        p.ea = c[i].ea;
        p.d = c[i].d;
        p.bD = c[i].bD;
        ts_system *s = make(&p);
        if (s)
            s->env.gravity *= c[i].g_scale;
        CHECK(s && refused(s, c[i].want, msg, sizeof msg), "%s refused: %s",
              c[i].what, msg);
        ts_system_free(s);
    }
    result("every overflowing input refused, named in its message");
    /* The threshold is on the loads: 1e60 m/s solves, 1e80 m/s does not. */
    spec p = ex1();
    p.V = 1e60;
    ts_system *s = make(&p);
    int rc;
    ts_equilibrium *eq = s ? solve(s, &rc) : NULL;
    CHECK(eq && rc == TS_OK, "speed 1e60 m/s (drag ~1e122 N): solved");
    ts_equilibrium_free(eq);
    ts_system_free(s);
    p.V = 1e80;
    s = make(&p);
    static const char *const w80[] = {"speed 1e+80 m/s", "is about", NULL};
    CHECK(s && refused(s, w80, msg, sizeof msg),
          "speed 1e80 m/s (drag ~1e162 N) refused: %s", msg);
    ts_system_free(s);

    /* Excitations: the bounds, and the simulator's refusal. */
    p = ex1();
    s = make(&p);
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_units *u = ts_units_alloc(&err);
    ts_frame f0 = {2.5, 0, 0, 0, {0, 0, 0}};
    ts_motion_bound mb;
    int prc = ts_excitation_parse(ex, "tow.heave:amplitude=0.37m,frequency="
                                  "1.3Hz", u, "test", &err);
    prc |= ts_excitation_parse(ex, "speed:by=1.25m/s,duration=4s", u, "test",
                               &err);
    ts_excitation_bound(ex, &f0, &mb);
    double w = 2 * M_PI * 1.3;
    CHECK(prc == TS_OK && mb.speed == 2.5 + 1.25 && mb.turn_rate == 0 &&
              fabs(mb.tow_speed - 0.37 * w) <= 1e-15 * mb.tow_speed &&
              fabs(mb.tow_accel - 0.37 * w * w) <= 1e-15 * mb.tow_accel,
          "bounds of a 1.3 Hz heave and a speed ramp: speed %g, tow %g m/s, "
          "%g m/s^2", mb.speed, mb.tow_speed, mb.tow_accel);
    ts_excitation_free(ex);
    static const struct {
        const char *spec, *want;
    } e[] = {{"tow.heave:amplitude=1e300m,frequency=1Hz",
              "tow-point velocity 6.28e+300 m/s"},
             {"turn_rate:to=1e300rad/s,duration=1s",
              "turn rate 1e+300 rad/s"}};
    for (int i = 0; i < 2 && s; i++) {
        ex = ts_excitation_alloc(&err);
        ts_excitation_parse(ex, e[i].spec, u, "test", &err);
        ts_kernel *k = ts_kernel_alloc(s, &err);
        ts_sim_opts so;
        ts_sim_opts_default(&so);
        ts_sim *sim = ts_sim_alloc(k, ex, &so, &err);
        CHECK(!sim && err.code == TS_EDOMAIN && strstr(err.msg, e[i].want) &&
                  !strstr(err.msg, "nan"),
              "simulate %s refused: %s", e[i].spec, err.msg);
        ts_sim_free(sim);
        ts_kernel_free(k);
        ts_excitation_free(ex);
    }
    ts_units_free(u);
    ts_system_free(s);
    end();
}

int main(int argc, char **argv)
{
    report = argc > 1 && strcmp(argv[1], "--report") == 0;
    gsl_set_error_handler_off();
    case_hanging();
    case_knots30();
    case_long();
    case_neutral();
    case_heavy();
    case_light();
    case_turn();
    case_air();
    case_chart();
    case_stiff();
    case_mm();
    case_drag();
    case_overflow();
    return tc_done();
}
