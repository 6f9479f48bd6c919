/* test_design.c: design by optimisation (towstab/design.h).
 *
 *  1. A target: the cable length of Kamman's example 1 that puts the
 *     sphere at 15 m depth. The study (COBYLA) reports it reached within
 *     its tolerance, and an independent bisection (GSL's, on single cold
 *     runs of the equilibrium) finds the same length within what the
 *     tolerances allow: |dL| <= (tolerance of z + bisection's z error) /
 *     |dz/dL|.
 *  2. An unreachable target (20 m: deeper than the longest cable allowed
 *     gives) is reported as not reached, at the bound, with the misfit of
 *     the single run there.
 *  3. Constraints: the highest speed with a top tension <= 600 N and a
 *     layback <= 25 m, the sphere's mass free too: both constraints met
 *     at the optimum (single run), one of them active (within 1e-4), and
 *     every evaluation faster than it broke one (no better feasible point
 *     was seen).
 *  4. Stability: the highest speed of Kamman's example 1 with the tow
 *     point above water at which max Re(lambda) <= 0: single modes runs
 *     just below and above it are not unstable and unstable (the sweep's
 *     boundary, test_sweep, brackets the same speed).
 *  5. ts_design_value: layback is the horizontal distance from the tow
 *     point to the sphere of the equilibrium; refusals name what is
 *     wrong.
 *  6. The gradient method (SLSQP, central differences) on the problems of
 *     1 and 3: the same optimum as COBYLA within what the tolerances
 *     allow (the target's length as in 1; the speed of 3 within 1e-6
 *     relative, its constraints met), with its runs counted.
 *  7. Controller gains: the AURORA towfish's depth loop kp and kd that
 *     maximise control_damping (the smallest damping ratio of the
 *     resolved modes that move the vehicle most) with fin_use <= 1 for a
 *     2 m depth step. The optimum is not beaten by any feasible point of a
 *     5 x 5 grid of the gains around it (spacing 1% of each range) beyond
 *     1e-6, and a separate modes run at the optimum's gains gives the
 *     reported damping to the last digit; fin_use there is |steady wing
 *     deflection| + kp 2 m over the 25 deg limit, recomputed here from the
 *     equilibrium's deflection.
 *  8. Ballast tanks in fin_use: DOLPHIN's tanks, driven by its depth
 *     loop, count by their fill range, |fill - capacity/2| / (capacity /
 *     2) plus the step's jump: the steady use against the trim's fill,
 *     and the largest depth kp for a 1 m step against fill / (400 kg/rad
 *     x 1 m), where the jump empties the tanks.
 */
#include "towstab/design.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"

static void spec_init(ts_design_spec *sp, ts_analysis_kind kind)
{
    memset(sp, 0, sizeof *sp);
    ts_request_init(&sp->rq, kind);
}

static void add_free(ts_design_spec *sp, const char *path, double lo,
                     double hi)
{
    ts_design_var *f = &sp->free[sp->nfree++];
    snprintf(f->path, sizeof f->path, "%s", path);
    f->lower = lo;
    f->upper = hi;
    f->start = NAN;
}

/* sphere.z of a single cold equilibrium with the cable of length L. */
typedef struct zdata {
    const ts_system *sys;
    double target;
    int runs;
} zdata;

static double z_at(double L, void *data)
{
    zdata *zd = data;
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_EQUILIBRIUM);
    rq.setup.discretisation_error = 0;
    ts_setup_set(&rq.setup, "cables.cable.length", L, NULL);
    ts_result *r = NULL;
    double z = NAN;
    if (ts_analysis_run(zd->sys, &rq, &r, NULL) == TS_OK) {
        const ts_value *v = ts_result_value(r, "sphere.z");
        z = v ? v->value : NAN;
    }
    ts_result_free(r);
    zd->runs++;
    return z - zd->target;
}

/* The cable length of example 1 that puts the sphere at 15 m. */
static void target_spec(ts_design_spec *sp)
{
    spec_init(sp, TS_ANALYSIS_EQUILIBRIUM);
    add_free(sp, "cables.cable.length", 10.0, 60.0);
    sp->goal.kind = TS_DESIGN_TARGET;
    snprintf(sp->goal.name, sizeof sp->goal.name, "sphere.z");
    sp->goal.target = 15.0;
}

static void test_target(const ts_system *ex1)
{
    ts_design_spec sp;
    target_spec(&sp);
    ts_design *d = NULL;
    ts_err err = {0};
    int rc = ts_design_run(ex1, &sp, &d, &err);
    if (!CHECK(rc == TS_OK && d, "target sphere.z = 15 m: the study ran (%s)",
               err.msg)) {
        ts_design_free(d);
        return;
    }
    double tol = d->spec.target_rtol * 15.0;
    CHECK(d->success && d->reached && d->goal_misfit <= tol &&
              d->status == TS_OK && d->result,
          "reached: L = %.9g m, sphere.z = %.9g m (misfit %.2g m, "
          "tolerance %.2g m) in %d runs, %ld kernel evaluations",
          d->x[0], d->goal_value.value, d->goal_misfit, tol, d->neval,
          d->evaluations);
    CHECK(isfinite(d->goal_value.error.discretisation) &&
              d->goal_value.error.discretisation > 0 &&
              isfinite(d->goal_value.error.solver),
          "the optimum carries its error estimates: +- %.2g (discretisation) "
          "+- %.2g (solver) m",
          d->goal_value.error.discretisation, d->goal_value.error.solver);
    /* The independent bisection. */
    zdata zd = {ex1, 15.0, 0};
    gsl_function F = {z_at, &zd};
    gsl_root_fsolver *s = gsl_root_fsolver_alloc(gsl_root_fsolver_bisection);
    gsl_root_fsolver_set(s, &F, 10.0, 60.0);
    double lo = 10, hi = 60;
    for (int it = 0; it < 100; it++) {
        gsl_root_fsolver_iterate(s);
        lo = gsl_root_fsolver_x_lower(s);
        hi = gsl_root_fsolver_x_upper(s);
        if (gsl_root_test_interval(lo, hi, 1e-10, 0) == GSL_SUCCESS)
            break;
    }
    gsl_root_fsolver_free(s);
    double Lb = 0.5 * (lo + hi);
    double slope = (z_at(Lb + 1e-3, &zd) - z_at(Lb - 1e-3, &zd)) / 2e-3;
    double allow = (tol + 1e-9) / fabs(slope);
    CHECK(fabs(d->x[0] - Lb) <= allow,
          "an independent bisection (GSL, %d cold runs) finds L = %.9g m: "
          "the study's differs by %.2g m, allowed %.2g m (dz/dL %.3f)",
          zd.runs, Lb, fabs(d->x[0] - Lb), allow, slope);
    ts_design_free(d);

    /* Unreachable. */
    sp.goal.target = 20.0;
    rc = ts_design_run(ex1, &sp, &d, &err);
    zdata z60 = {ex1, 0.0, 0};
    double zmax = z_at(60.0, &z60);
    CHECK(rc == TS_OK && d && !d->success && !d->reached &&
              d->at_bound[0] == 1 &&
              fabs(d->goal_misfit - (20.0 - zmax)) <= 1e-6,
          "sphere.z = 20 m is out of reach: not reached, the cable at its "
          "upper bound (%.6g m), misfit %.6g m = 20 m - %.6g m of the "
          "single run there",
          d ? d->x[0] : NAN, d ? d->goal_misfit : NAN, zmax);
    ts_design_free(d);
}

/* The highest speed of example 1 with top_tension <= 600 N and layback
 * <= 25 m, the sphere's mass and the speed free. */
static void constraints_spec(ts_design_spec *sp)
{
    spec_init(sp, TS_ANALYSIS_EQUILIBRIUM);
    add_free(sp, "bodies.sphere.mass", 1.0, 1000.0);
    add_free(sp, "tow.speed", 1.0, 5.0);
    sp->goal.kind = TS_DESIGN_MAXIMISE;
    snprintf(sp->goal.name, sizeof sp->goal.name, "tow.speed");
    ts_design_constraint *c = sp->constraints;
    snprintf(c[0].name, sizeof c[0].name, "top_tension");
    c[0].upper = 1;
    c[0].bound = 600.0;
    snprintf(c[1].name, sizeof c[1].name, "layback");
    c[1].upper = 1;
    c[1].bound = 25.0;
    sp->nconstraints = 2;
}

static void test_constraints(const ts_system *ex1)
{
    ts_design_spec sp;
    constraints_spec(&sp);
    ts_design *d = NULL;
    ts_err err = {0};
    int rc = ts_design_run(ex1, &sp, &d, &err);
    if (!CHECK(rc == TS_OK && d, "maximise speed, top_tension <= 600 N, "
               "layback <= 25 m: ran (%s)", err.msg)) {
        ts_design_free(d);
        return;
    }
    double T = d->constraint_value[0].value, lb = d->constraint_value[1].value;
    double tol = d->spec.target_rtol;
    int active = fabs(T - 600.0) <= 1e-4 * 600.0 ||
                 fabs(lb - 25.0) <= 1e-4 * 25.0;
    CHECK(d->success && d->feasible && T <= 600.0 * (1 + tol) &&
              lb <= 25.0 * (1 + tol) && active,
          "optimum: speed %.7g m/s, mass %.7g kg: top tension %.7g N, "
          "layback %.7g m, both met, one active; %d runs",
          d->x[1], d->x[0], T, lb, d->neval);
    int better = 0;
    for (int k = 0; k < d->neval; k++) {
        const ts_design_eval *h = &d->history[k];
        better += h->status == TS_OK && h->violation <= tol &&
                  h->x[1] > d->x[1] + 1e-12;
    }
    CHECK(better == 0, "no feasible evaluation was faster than the optimum "
          "(%d)", better);
    ts_design_free(d);
}

static void test_stability(const ts_system *above)
{
    ts_design_spec sp;
    spec_init(&sp, TS_ANALYSIS_MODES);
    add_free(&sp, "tow.speed", 2.0, 8.5);
    sp.goal.kind = TS_DESIGN_MAXIMISE;
    snprintf(sp.goal.name, sizeof sp.goal.name, "tow.speed");
    snprintf(sp.constraints[0].name, sizeof sp.constraints[0].name,
             "max_real");
    sp.constraints[0].upper = 1;
    sp.constraints[0].bound = 0.0;
    sp.nconstraints = 1;
    ts_design *d = NULL;
    ts_err err = {0};
    int rc = ts_design_run(above, &sp, &d, &err);
    if (!CHECK(rc == TS_OK && d && d->success, "the fastest stable tow: "
               "ran and met max_real <= 0 (%s)", err.msg)) {
        ts_design_free(d);
        return;
    }
    int verdict[2] = {-1, -1};
    double at[2] = {d->x[0] - 2e-3, d->x[0] + 2e-3};
    for (int k = 0; k < 2; k++) {
        ts_request rq;
        ts_request_init(&rq, TS_ANALYSIS_MODES);
        rq.setup.speed = at[k];
        ts_result *r = NULL;
        ts_margin m;
        if (ts_analysis_run(above, &rq, &r, NULL) == TS_OK &&
            ts_result_margin(r, &m))
            verdict[k] = m.verdict;
        ts_result_free(r);
    }
    CHECK(verdict[0] >= 0 && verdict[0] != TS_UNSTABLE &&
              verdict[1] == TS_UNSTABLE,
          "at %.7g m/s: single modes runs are %s (not unstable) at %.7g and "
          "%s at %.7g m/s",
          d->x[0], verdict[0] >= 0 ? ts_verdict_name(verdict[0]) : "failed",
          at[0], verdict[1] >= 0 ? ts_verdict_name(verdict[1]) : "failed",
          at[1]);
    ts_design_free(d);
}

static void test_values_and_refusals(const ts_system *ex1)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_EQUILIBRIUM);
    ts_result *r = NULL;
    ts_value v;
    if (ts_analysis_run(ex1, &rq, &r, NULL) == TS_OK &&
        ts_design_value(r, "layback", &v)) {
        const ts_value *x = ts_result_value(r, "sphere.x");
        const double *tp = ex1->tow.point;
        CHECK(x && fabs(v.value - fabs(x->value - tp[0])) <= 1e-12 &&
                  !strcmp(v.unit, "m"),
              "layback %.9g m is |sphere.x - tow.x| in a straight tow",
              v.value);
    } else {
        CHECK(0, "layback of example 1");
    }
    CHECK(!ts_design_value(r, "max_real", &v) &&
              !ts_design_value(r, "nothing", &v),
          "an equilibrium has no max_real and no 'nothing'");
    ts_result_free(r);

    struct {
        const char *what, *path, *goal;
        double lo, hi;
        int method, cons;
        const char *want;
    } cases[] = {
        {"an unknown path", "cables.rope.length", "sphere.z", 1, 2, 0, 0,
         "no cable of that name"},
        {"bounds reversed", "cables.cable.length", "sphere.z", 60, 10, 0, 0,
         "expected bounds LOWER < UPPER"},
        {"links free", "cables.cable.links", "sphere.z", 5, 50, 0, 0,
         "whole number"},
        {"an unknown value", "cables.cable.length", "sphere.depth", 10, 60,
         0, 0, "no value 'sphere.depth'"},
        {"max_real of an equilibrium", "cables.cable.length", "max_real", 10,
         60, 0, 0, "no value 'max_real'"},
        {"bobyqa with constraints", "cables.cable.length", "sphere.z", 10,
         60, TS_DESIGN_BOBYQA, 1, "bobyqa takes bounds only"},
        {"a bound the key refuses", "cables.cable.length", "sphere.z", -5,
         60, 0, 0, "must be > 0"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        ts_design_spec sp;
        spec_init(&sp, TS_ANALYSIS_EQUILIBRIUM);
        add_free(&sp, cases[i].path, cases[i].lo, cases[i].hi);
        sp.goal.kind = TS_DESIGN_TARGET;
        snprintf(sp.goal.name, sizeof sp.goal.name, "%s", cases[i].goal);
        sp.goal.target = 15;
        sp.method = cases[i].method;
        if (cases[i].cons) {
            snprintf(sp.constraints[0].name, sizeof sp.constraints[0].name,
                     "top_tension");
            sp.constraints[0].upper = 1;
            sp.constraints[0].bound = 600;
            sp.nconstraints = 1;
        }
        ts_design *d = NULL;
        ts_err err = {0};
        int rc = ts_design_run(ex1, &sp, &d, &err);
        CHECK(rc == TS_EINVAL && !d && strstr(err.msg, cases[i].want),
              "refused, %s: %s", cases[i].what, err.msg);
        ts_design_free(d);
    }
}

/* The problems of test_target and test_constraints with SLSQP against
 * COBYLA. */
static void test_gradient(const ts_system *ex1)
{
    ts_design_spec sp;
    target_spec(&sp);
    ts_design *d[2] = {NULL, NULL};
    ts_err err = {0};
    for (int k = 0; k < 2; k++) {
        sp.method = k ? TS_DESIGN_SLSQP : TS_DESIGN_COBYLA;
        ts_design_run(ex1, &sp, &d[k], &err);
    }
    if (CHECK(d[0] && d[1] && d[0]->success && d[1]->success,
              "target sphere.z = 15 m with cobyla and slsqp (%s)", err.msg)) {
        /* Both within the target's tolerance 1.5e-5 m of 15 m, dz/dL
         * about 0.3: lengths within 2 x 1.5e-5 / 0.29. */
        double allow = 2 * 1.5e-5 / 0.29;
        CHECK(fabs(d[0]->x[0] - d[1]->x[0]) <= allow &&
                  d[1]->gradients > 0,
              "slsqp: L = %.9g m in %d runs (%d gradients, step %g of the "
              "range), %ld kernel evaluations; cobyla %.9g m in %d runs, "
              "%ld: within %.2g m",
              d[1]->x[0], d[1]->neval, d[1]->gradients, TS_DESIGN_GRAD_STEP,
              d[1]->evaluations, d[0]->x[0], d[0]->neval,
              d[0]->evaluations, allow);
    }
    for (int k = 0; k < 2; k++) {
        ts_design_free(d[k]);
        d[k] = NULL;
    }

    constraints_spec(&sp);
    for (int k = 0; k < 2; k++) {
        sp.method = k ? TS_DESIGN_SLSQP : TS_DESIGN_COBYLA;
        ts_design_run(ex1, &sp, &d[k], &err);
    }
    if (CHECK(d[0] && d[1] && d[0]->success && d[1]->success,
              "maximise speed under two constraints with cobyla and slsqp "
              "(%s)", err.msg))
        CHECK(fabs(d[0]->x[1] - d[1]->x[1]) <= 1e-6 * d[0]->x[1],
              "slsqp: %.9g m/s (mass %.7g kg) in %d runs (%d gradients), "
              "%ld kernel evaluations; cobyla %.9g m/s in %d runs, %ld: "
              "within 1e-6 relative",
              d[1]->x[1], d[1]->x[0], d[1]->neval, d[1]->gradients,
              d[1]->evaluations, d[0]->x[1], d[0]->neval,
              d[0]->evaluations);
    for (int k = 0; k < 2; k++)
        ts_design_free(d[k]);
}

/* control_damping and fin_use of one modes run at depth gains kp, kd. */
static int aurora_at(const ts_system *sys, double kp, double kd,
                     double *damping, double *fin, double *wing)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_MODES);
    rq.setup.discretisation_error = 0;
    ts_setup_set(&rq.setup, "bodies.aurora.controllers.depth.kp", kp, NULL);
    ts_setup_set(&rq.setup, "bodies.aurora.controllers.depth.kd", kd, NULL);
    ts_result *r = NULL;
    ts_value v;
    int ok = ts_analysis_run(sys, &rq, &r, NULL) == TS_OK &&
             ts_design_value(r, "control_damping", &v);
    *damping = ok ? v.value : NAN;
    /* The wing is component 1; its steady deflection. */
    *wing = ok && r->eq && r->eq->nvehicles == 1 ? r->eq->vehicles[0].delta[1]
                                                  : NAN;
    *fin = NAN;
    if (ok && ts_design_value(r, "fin_use", &v))
        *fin = v.value;
    ts_result_free(r);
    return ok;
}

/* Maximise `goal` under fin_use <= 1 for a depth step of `step` m. */
static void maximise_within_fins(ts_design_spec *sp, const char *goal,
                                 double step)
{
    sp->goal.kind = TS_DESIGN_MAXIMISE;
    snprintf(sp->goal.name, sizeof sp->goal.name, "%s", goal);
    snprintf(sp->constraints[0].name, sizeof sp->constraints[0].name,
             "fin_use");
    sp->constraints[0].upper = 1;
    sp->constraints[0].bound = 1.0;
    sp->nconstraints = 1;
    sp->fin_step = step;
}

static void test_controller(const ts_system *aurora)
{
    ts_design_spec sp;
    spec_init(&sp, TS_ANALYSIS_MODES);
    sp.rq.setup.discretisation_error = 0;
    add_free(&sp, "bodies.aurora.controllers.depth.kp", 0.01, 0.3);
    add_free(&sp, "bodies.aurora.controllers.depth.kd", 0.0, 0.5);
    maximise_within_fins(&sp, "control_damping", 2.0);
    ts_design *d = NULL;
    ts_err err = {0};
    int rc = ts_design_run(aurora, &sp, &d, &err);
    if (!CHECK(rc == TS_OK && d && d->success,
               "AURORA: maximise control_damping, depth kp and kd free, "
               "fin_use <= 1 for a 2 m step: ran (%s)", err.msg)) {
        ts_design_free(d);
        return;
    }
    double best = d->goal_value.value, kp = d->x[0], kd = d->x[1];
    double dmp, fin, wing;
    int ok = aurora_at(aurora, kp, kd, &dmp, &fin, &wing);
    CHECK(ok && dmp == best,
          "optimum kp %.7g rad/m, kd %.7g rad s/m: control_damping %.10g in "
          "%d runs; a separate modes run there gives %.10g",
          kp, kd, best, d->neval, dmp);
    double limit = 25.0 * M_PI / 180.0;
    double fin_here = (fabs(wing) + kp * 2.0) / limit;
    CHECK(fabs(fin_here - d->constraint_value[0].value) <= 1e-12 &&
              fabs(fin - fabs(wing) / limit) <= 1e-12 &&
              d->constraint_value[0].value <= 1 + d->spec.target_rtol,
          "fin_use %.10g = (|wing %.5f deg| + kp x 2 m) / 25 deg = %.10g; "
          "without the step (ts_design_value) %.10g",
          d->constraint_value[0].value, wing * 180 / M_PI, fin_here, fin);
    double hp = 0.01 * (0.3 - 0.01), hd = 0.01 * 0.5;
    int feasible = 0, beaten = 0;
    double worst = -INFINITY;
    for (int i = -2; i <= 2; i++)
        for (int j = -2; j <= 2; j++) {
            double p = kp + i * hp, q = kd + j * hd;
            if ((i == 0 && j == 0) || p < 0.01 || p > 0.3 || q < 0 ||
                q > 0.5)
                continue;
            /* fin_use of the run is the steady part; the step's adds
             * kp 2 m on the wing, the only surface of the depth loop. */
            if (!aurora_at(aurora, p, q, &dmp, &fin, &wing) ||
                (fabs(wing) + 2.0 * p) / limit > 1)
                continue;
            feasible++;
            beaten += dmp > best + 1e-6;
            worst = fmax(worst, dmp - best);
        }
    CHECK(feasible >= 3 && beaten == 0,
          "a 5 x 5 grid around the optimum (kp +- %.4g, kd +- %.4g): %d "
          "feasible points, none better by 1e-6 (largest gain %.3g)",
          hp, hd, feasible, worst);
    ts_design_free(d);
}

/* 8. fin_use counts ballast tanks: DOLPHIN's depth loop drives its
 * foreplanes (20 deg) and two tanks of 130 kg (-400 kg per rad of the
 * loop's output). A tank's use is |fill - 65 kg| / 65 kg (1: empty or
 * full), plus its command's jump 400 kp step / 65 kg; the trim's fill
 * (11.89 kg) makes the tanks the largest use, 0.817 (the fins' 0.154).
 * With the depth integrator the trim does not depend on kp, so the
 * largest kp for a 1 m step is where the jump empties the tanks: kp* =
 * fill / (400 kg/rad x 1 m), by hand, against the study's optimum
 * (maximise kp, fin_use <= 1). AURORA's own depth loop (its wing, 25 deg,
 * kp 0.05) steps too but stays far inside. */
static void test_ballast(const ts_system *dolphin)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_EQUILIBRIUM);
    rq.setup.discretisation_error = 0;
    ts_result *r = NULL;
    ts_value v;
    int ok = ts_analysis_run(dolphin, &rq, &r, NULL) == TS_OK &&
             ts_design_value(r, "fin_use", &v);
    double fill = NAN, fins = 0;
    for (int i = 0; ok && i < r->eq->nvehicles; i++) {
        const ts_vehicle_result *vr = &r->eq->vehicles[i];
        const ts_vehicle *vd = dolphin->bodies[vr->body].vehicle;
        for (int c = 0; c < vd->ncomponents; c++) {
            const ts_component *cp = &vd->component[c];
            if (cp->type == TS_COMP_BALLAST &&
                !strcmp(cp->name, "ballast_front"))
                fill = vr->delta[c];
            else if (cp->control && isfinite(cp->limit))
                fins = fmax(fins, fabs(vr->delta[c]) / cp->limit);
        }
    }
    double want = fabs(fill - 65.0) / 65.0;
    CHECK(ok && fabs(v.value - want) <= 1e-12 && want > fins,
          "DOLPHIN: fin_use %.10g = |front tank's fill %.6f kg - 65 kg| / "
          "65 kg = %.10g, above every surface's |deflection| / limit "
          "(%.4f)", ok ? v.value : NAN, fill, want, fins);
    ts_result_free(r);

    ts_design_spec sp;
    spec_init(&sp, TS_ANALYSIS_EQUILIBRIUM);
    sp.rq.setup.discretisation_error = 0;
    add_free(&sp, "towing_vehicle.controllers.depth.kp", 0.005, 0.2);
    maximise_within_fins(&sp, "towing_vehicle.controllers.depth.kp", 1.0);
    ts_design *d = NULL;
    ts_err err = {0};
    int rc = ts_design_run(dolphin, &sp, &d, &err);
    double kp_hand = fill / 400.0;
    /* The study stops within its tolerances: xtol of the range in kp, the
     * constraint within target_rtol (a kp of target_rtol x 65 / 400). */
    double tol = d ? d->spec.xtol * (0.2 - 0.005) +
                         d->spec.target_rtol * 65.0 / 400.0
                   : 0;
    CHECK(rc == TS_OK && d && d->success &&
              fabs(d->x[0] - kp_hand) <= tol,
          "DOLPHIN: the largest depth kp with fin_use <= 1 for a 1 m step "
          "%.8f rad/m in %d runs, by hand fill / (400 kg/rad x 1 m) = "
          "%.8f (within %.2g); fin_use there %.6f (%s)",
          d ? d->x[0] : NAN, d ? d->neval : 0, kp_hand, tol,
          d ? d->constraint_value[0].value : NAN, err.msg);
    ts_design_free(d);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *ex1 = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    ts_scene *above = tscene_load(u, "examples/kamman_ex1_above.yaml");
    ts_scene *aurora = tscene_load(u, "examples/aurora_towfish.yaml");
    ts_scene *dolphin = tscene_load(u, "examples/dolphin_aurora.yaml");
    if (ex1 && above && aurora && dolphin) {
        test_target(ex1->system);
        test_constraints(ex1->system);
        test_stability(above->system);
        test_values_and_refusals(ex1->system);
        test_gradient(ex1->system);
        test_controller(aurora->system);
        test_ballast(dolphin->system);
    }
    ts_scene_free(ex1);
    ts_scene_free(above);
    ts_scene_free(aurora);
    ts_scene_free(dolphin);
    ts_units_free(u);
    return tc_done();
}
