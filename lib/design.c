/* design.c: design by optimisation with NLopt (towstab/design.h,
 * doc/design.md).
 *
 * NLopt minimises over u in [0, 1]^n, the free values being lower + u
 * (upper - lower). The objective and every constraint of one u come from
 * one analysis run, cached for the last u asked (COBYLA asks the
 * objective first and then the constraints at the same point). A failed
 * run gives the objective HUGE_VAL and the constraints a violation of 1,
 * so the optimiser steps back. The best point is the feasible one (every
 * constraint within target_rtol) of the smallest objective, else the one
 * of the smallest violation; it is run again as the single command would.
 */
#include "towstab/design.h"

#include <math.h>
#include <nlopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "clock.h"
#include "lazylib.h"
#include "towstab/eigen.h"
#include "towstab/report_result.h"

const char *ts_design_goal_name(ts_design_goal_kind k)
{
    switch (k) {
    case TS_DESIGN_TARGET: return "target";
    case TS_DESIGN_MINIMISE: return "minimise";
    case TS_DESIGN_MAXIMISE: return "maximise";
    default: return "none";
    }
}

const char *ts_design_method_name(ts_design_method m)
{
    return m == TS_DESIGN_BOBYQA  ? "bobyqa"
           : m == TS_DESIGN_SLSQP ? "slsqp"
                                  : "cobyla";
}

/* ---- values ------------------------------------------------------------- */

static void value_set(ts_value *out, const char *name, const char *unit,
                      double v, double disc, double solver)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%.95s", name);
    snprintf(out->unit, sizeof out->unit, "%s", unit);
    out->value = v;
    out->error.discretisation = disc;
    out->error.solver = solver;
    out->order = NAN;
}

/* 1 when mode m moves a vehicle most: the largest node displacement of
 * its shape is at a vehicle's node (the "largest at" of the mode table,
 * ts_eigen_describe). 0 without shapes. */
static int vehicle_mode(const ts_result *r, int m, double *amp,
                        double *phase)
{
    const ts_system *sys = r->sys;
    if (!sys || !r->lin || !r->eigen->vec_re ||
        ts_eigen_mode_shape(sys, r->lin, r->eigen, m, amp, phase, NULL))
        return 0;
    int best = 0;
    for (int k = 1; k < 3 * sys->nnodes; k++)
        if (amp[k] > amp[best])
            best = k;
    int b = sys->nodes[best / 3].body;
    return b >= 0 && sys->bodies[b].type == TS_BODY_VEHICLE;
}

/* The smallest damping ratio of the resolved oscillatory modes; with
 * `vehicles`, of those that move a vehicle most (vehicle_mode). */
static int min_damping(const ts_result *r, int vehicles, ts_value *out)
{
    const ts_eigen *e = r->eigen;
    int n = r->nmodes_computed > 0 ? r->nmodes_computed : e ? e->nmodes : 0;
    int best = -1;
    double *amp = NULL, *phase = NULL;
    if (vehicles && r->sys) {
        amp = malloc(3 * (size_t)r->sys->nnodes * sizeof *amp);
        phase = malloc(3 * (size_t)r->sys->nnodes * sizeof *phase);
        if (!amp || !phase)
            n = 0;
    }
    for (int m = 0; e && m < n; m++) {
        if (!(e->modes[m].im > 0))
            continue;
        if (r->mode_accuracy && !r->mode_accuracy[m].resolved)
            continue;
        if (vehicles && !vehicle_mode(r, m, amp, phase))
            continue;
        if (best < 0 ||
            e->modes[m].damping_ratio < e->modes[best].damping_ratio)
            best = m;
    }
    free(amp);
    free(phase);
    if (best < 0)
        return 0;
    double disc = r->mode_accuracy ? r->mode_accuracy[best].damping_error
                                   : NAN;
    /* The solver's part: the eigenvalue's error bound over |lambda|. */
    const ts_mode *md = &e->modes[best];
    double solver = md->error_bound / hypot(md->re, md->im);
    value_set(out, vehicles ? "control_damping" : "min_damping", "1",
              md->damping_ratio, disc, solver);
    return 1;
}

/* The fin use: over every control component c with a finite range [lo,
 * hi] (ts_component_range: a surface's [-limit, limit] rad, a ballast
 * tank's [0, capacity] kg), (|delta_c - mid| + |sum over depth loops l of
 * kp_l g_lc step|) / half, mid and half the middle and half the width of
 * the range: the steady deflection (or fill) plus the command's jump when
 * the depth set points step by `step` (m; either sign; the derivative
 * term acts on the measured rate, the integral starts from its trim, so
 * the jump is the proportional term's), at its largest. 1 is the range's
 * end: for a surface (|delta| + |jump|) / limit, for a tank a fill that
 * empties or fills it. 0 when no vehicle has a limited control
 * component. */
static int fin_use(const ts_result *r, double step, ts_value *out)
{
    const ts_equilibrium *eq = r->eq;
    if (!r->sys || !eq || !eq->vehicles)
        return 0;
    double use = -1;
    for (int i = 0; i < eq->nvehicles; i++) {
        const ts_vehicle_result *vr = &eq->vehicles[i];
        const ts_vehicle *v = r->sys->bodies[vr->body].vehicle;
        for (int c = 0; v && c < v->ncomponents; c++) {
            const ts_component *cp = &v->component[c];
            double lo = -INFINITY, hi = INFINITY;
            if (cp->control)
                ts_component_range(cp, &lo, &hi);
            if (!isfinite(lo) || !isfinite(hi) || !(hi > lo))
                continue;
            double kick = 0;
            for (int l = 0; l < v->nloops; l++) {
                const ts_loop *lp = &v->loop[l];
                for (int k = 0; lp->measure == TS_MEASURE_DEPTH &&
                                k < lp->nsurfaces; k++)
                    if (lp->surface[k] == c)
                        kick += lp->kp * lp->gain[k] * step;
            }
            double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
            use = fmax(use, (fabs(vr->delta[c] - mid) + fabs(kick)) / half);
        }
    }
    if (!(use >= 0))
        return 0;
    value_set(out, "fin_use", "1", use, NAN, 0);
    return 1;
}

/* ts_design_value with the study's settings (the fin step). */
static int study_value(const ts_design_spec *sp, const ts_result *r,
                       const char *name, ts_value *out)
{
    if (r && !strcmp(name, "fin_use"))
        return fin_use(r, sp->fin_step, out);
    return ts_design_value(r, name, out);
}

int ts_design_value(const ts_result *r, const char *name, ts_value *out)
{
    if (!r || !name)
        return 0;
    const ts_value *v = ts_result_value(r, name);
    if (v) {
        *out = *v;
        return isfinite(out->value);
    }
    if (!strcmp(name, "max_real")) {
        ts_margin m;
        if (!ts_result_margin(r, &m))
            return 0;
        value_set(out, name, "1/s", m.max_real, m.error.discretisation,
                  m.error.solver);
        return isfinite(m.max_real);
    }
    if (!strcmp(name, "min_damping"))
        return min_damping(r, 0, out);
    if (!strcmp(name, "control_damping"))
        return min_damping(r, 1, out);
    if (!strcmp(name, "fin_use"))
        return fin_use(r, 0, out);
    ts_value *eqv = NULL;
    int neq = 0, found = 0;
    if (!r->sys || ts_result_equilibrium_values(r, &eqv, &neq, NULL))
        return 0;
    /* The points' x, y, z come first, then top_tension (a towing
     * vehicle's solved motion after it). */
    int top = 0;
    while (top < neq && strcmp(eqv[top].name, "top_tension"))
        top++;
    if (!strcmp(name, "layback") && top >= 3 && top < neq) {
        /* The last point's x and y. */
        const double *tp = r->sys->tow.point;
        const ts_value *x = &eqv[top - 3], *y = &eqv[top - 2];
        /* The result's own x and y carry the discretisation estimate. */
        const ts_value *rx = ts_result_value(r, x->name),
                       *ry = ts_result_value(r, y->name);
        double d = hypot(x->value - tp[0], y->value - tp[1]);
        value_set(out, name, "m", d,
                  rx && ry ? hypot(rx->error.discretisation,
                                   ry->error.discretisation)
                           : NAN,
                  hypot(x->error.solver, y->error.solver));
        found = isfinite(d);
    }
    for (int i = 0; !found && i < neq; i++)
        if (!strcmp(eqv[i].name, name)) {
            *out = eqv[i];
            found = isfinite(out->value);
        }
    free(eqv);
    if (found)
        return 1;
    char canon[TS_PARAM_PATH_MAX];
    double pv;
    if (!ts_param_canonical(name, canon, sizeof canon, NULL) &&
        !ts_param_get(r->sys, canon, &pv, NULL)) {
        char unit[TS_PARAM_UNIT_MAX] = "";
        ts_param_unit(r->sys, canon, unit, sizeof unit, NULL);
        value_set(out, canon, unit, pv, 0, 0);
        return 1;
    }
    return 0;
}

/* ---- checks ------------------------------------------------------------- */

/* The unit of `name` among names[n] (a run's key values and the
 * equilibrium's), the derived values and the paths; 0 when unknown. */
static int name_unit(const ts_system *sys, const ts_request *rq,
                     const ts_value *names, int n, const char *name,
                     char *unit, size_t size)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(names[i].name, name)) {
            snprintf(unit, size, "%s", names[i].unit);
            return 1;
        }
    static const char *const derived[5][2] = {
        {"layback", "m"}, {"fin_use", "1"}, {"max_real", "1/s"},
        {"min_damping", "1"}, {"control_damping", "1"}};
    for (int k = 0; k < 5; k++)
        if (!strcmp(name, derived[k][0]) &&
            (k < 2 || rq->kind == TS_ANALYSIS_MODES)) {
            snprintf(unit, size, "%s", derived[k][1]);
            return 1;
        }
    char canon[TS_PARAM_PATH_MAX];
    return !ts_param_canonical(name, canon, sizeof canon, NULL) &&
           !ts_param_unit(sys, canon, unit, size, NULL);
}

/* The value names of a run of rq (its own and the equilibrium's). */
static int run_names(const ts_system *sys, const ts_request *rq,
                     ts_value **names, int *n, ts_err *err)
{
    int rc = ts_analysis_value_names(sys, rq, names, n, err);
    if (rc)
        return rc;
    if (rq->kind == TS_ANALYSIS_EQUILIBRIUM)
        return TS_OK;
    ts_value *eqv = NULL;
    int neq = 0;
    ts_request eq = *rq;
    eq.kind = TS_ANALYSIS_EQUILIBRIUM;
    rc = ts_analysis_value_names(sys, &eq, &eqv, &neq, err);
    if (!rc) {
        ts_value *all = realloc(*names, (size_t)(*n + neq + 1) * sizeof *all);
        if (!all) {
            rc = ts_fail(err, TS_ENOMEM, "design: out of memory");
        } else {
            *names = all;
            memcpy(all + *n, eqv, (size_t)neq * sizeof *eqv);
            *n += neq;
        }
    }
    free(eqv);
    return rc;
}

static int check_name(const ts_system *sys, const ts_request *rq,
                      const ts_value *names, int n, const char *what,
                      const char *name, ts_err *err)
{
    char unit[TS_VALUE_UNIT_MAX];
    if (name_unit(sys, rq, names, n, name, unit, sizeof unit))
        return TS_OK;
    char list[600] = "";
    size_t len = 0;
    for (int i = 0; i < n && len < sizeof list - 100; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s",
                                i ? ", " : "", names[i].name);
    return ts_fail(err, TS_EINVAL, "%s: no value '%s' in the result of %s; "
                   "expected one of %s, layback, fin_use%s or a scene path",
                   what, name, ts_analysis_name(rq->kind), list,
                   rq->kind == TS_ANALYSIS_MODES
                       ? ", max_real, min_damping, control_damping" : "");
}

int ts_design_unit(const ts_system *sys, const ts_request *rq,
                   const char *what, const char *name, char *unit,
                   size_t size, ts_err *err)
{
    ts_value *names = NULL;
    int n = 0;
    int rc = run_names(sys, rq, &names, &n, err);
    if (!rc)
        rc = check_name(sys, rq, names, n, what, name, err);
    if (!rc)
        name_unit(sys, rq, names, n, name, unit, size);
    free(names);
    return rc;
}

int ts_design_check(const ts_system *sys, const ts_design_spec *sp,
                    ts_err *err)
{
    if (sp->rq.kind != TS_ANALYSIS_EQUILIBRIUM &&
        sp->rq.kind != TS_ANALYSIS_MODES)
        return ts_fail(err, TS_EINVAL, "analysis: a design study runs "
                       "equilibrium or modes, not %s",
                       ts_analysis_name(sp->rq.kind));
    if (sp->nfree < 1 || sp->nfree > TS_DESIGN_MAX_FREE)
        return ts_fail(err, TS_EINVAL, "free: expected 1 to %d free values, "
                       "got %d", TS_DESIGN_MAX_FREE, sp->nfree);
    if (sp->nconstraints < 0 ||
        sp->nconstraints > TS_DESIGN_MAX_CONSTRAINTS)
        return ts_fail(err, TS_EINVAL, "constraint: at most %d, got %d",
                       TS_DESIGN_MAX_CONSTRAINTS, sp->nconstraints);
    if (sp->goal.kind == TS_DESIGN_NONE && sp->nconstraints == 0)
        return ts_fail(err, TS_EINVAL, "goal: expected a target, a value to "
                       "minimise or maximise, or constraints");
    if (sp->method == TS_DESIGN_BOBYQA && sp->nconstraints > 0)
        return ts_fail(err, TS_EINVAL, "method: bobyqa takes bounds only; "
                       "use cobyla with constraints");
    if (sp->method != TS_DESIGN_COBYLA && sp->method != TS_DESIGN_BOBYQA &&
        sp->method != TS_DESIGN_SLSQP)
        return ts_fail(err, TS_EINVAL, "method: expected cobyla, bobyqa or "
                       "slsqp");
    if (!(isfinite(sp->fin_step) && sp->fin_step >= 0))
        return ts_fail(err, TS_EINVAL, "fin_step: expected a depth step >= "
                       "0 m, got %g m", sp->fin_step);
    if (sp->max_evals < 0 || !(sp->target_rtol >= 0 && sp->target_rtol < 1) ||
        !(sp->xtol >= 0 && sp->xtol < 1))
        return ts_fail(err, TS_EINVAL, "max_evals >= 0, target_rtol and xtol "
                       "in [0, 1) expected");
    for (int i = 0; i < sp->nfree; i++) {
        const ts_design_var *f = &sp->free[i];
        char canon[TS_PARAM_PATH_MAX], unit[TS_PARAM_UNIT_MAX];
        int rc = ts_param_canonical(f->path, canon, sizeof canon, err);
        if (!rc)
            rc = ts_param_unit(sys, canon, unit, sizeof unit, err);
        /* A towing vehicle's solved speed or turn rate: a flat
         * direction the optimiser would move along without effect. */
        if (!rc)
            rc = ts_param_solved(sys, canon, "the result would not change "
                                 "with it", "free", err);
        if (rc) {
            ts_err_prefix(err, "free: ");
            return rc;
        }
        size_t n = strlen(canon);
        if (n > 6 && !strcmp(canon + n - 6, ".links"))
            return ts_fail(err, TS_EINVAL, "free: %s: a whole number cannot "
                           "be optimised; sweep it (towstab sweep)", canon);
        if (!(isfinite(f->lower) && isfinite(f->upper) &&
              f->lower < f->upper))
            return ts_fail(err, TS_EINVAL, "free: %s: expected bounds LOWER < "
                           "UPPER, got %g and %g %s", canon, f->lower,
                           f->upper, unit);
        if (!isnan(f->start) && !(f->start >= f->lower &&
                                  f->start <= f->upper))
            return ts_fail(err, TS_EINVAL, "free: %s: the start %g %s is "
                           "outside [%g, %g]", canon, f->start, unit,
                           f->lower, f->upper);
        for (int j = 0; j < i; j++) {
            char other[TS_PARAM_PATH_MAX];
            ts_param_canonical(sp->free[j].path, other, sizeof other, NULL);
            if (!strcmp(other, canon))
                return ts_fail(err, TS_EINVAL, "free: %s is given twice",
                               canon);
        }
        /* Both bounds must be values the key takes. */
        ts_setup su = sp->rq.setup;
        ts_request rq = sp->rq;
        for (int k = 0; k < 2; k++) {
            su = sp->rq.setup;
            rc = ts_setup_set(&su, canon, k ? f->upper : f->lower, err);
            rq.setup = su;
            if (!rc)
                rc = ts_analysis_check(sys, &rq, err);
            if (rc) {
                ts_err_prefix(err, "free: ");
                return rc;
            }
        }
    }
    ts_value *names = NULL;
    int n = 0;
    int rc = run_names(sys, &sp->rq, &names, &n, err);
    if (!rc && sp->goal.kind != TS_DESIGN_NONE) {
        rc = check_name(sys, &sp->rq, names, n, "goal", sp->goal.name, err);
        if (!rc && sp->goal.kind == TS_DESIGN_TARGET &&
            !isfinite(sp->goal.target))
            rc = ts_fail(err, TS_EINVAL, "target: %s: expected a finite "
                         "value", sp->goal.name);
    }
    for (int i = 0; !rc && i < sp->nconstraints; i++) {
        rc = check_name(sys, &sp->rq, names, n, "constraint",
                        sp->constraints[i].name, err);
        if (!rc && !isfinite(sp->constraints[i].bound))
            rc = ts_fail(err, TS_EINVAL, "constraint: %s: expected a finite "
                         "bound", sp->constraints[i].name);
    }
    free(names);
    return rc;
}

/* ---- the study ------------------------------------------------------------ */

typedef struct study {
    const ts_system *sys;
    ts_design *d;
    double u[TS_DESIGN_MAX_FREE]; /* the point cached */
    int have;                     /* a point is cached */
    double f;                     /* its objective */
    double c[TS_DESIGN_MAX_CONSTRAINTS]; /* its constraints, scaled */
    double goal_scale;
    double *dir;                  /* the last converged link directions */
    int ndir;
    int cap;
    nlopt_opt opt;
    tsi_nlopt nl;      /* NLopt, opened by ts_design_run */
    /* SLSQP: the gradients at gu (scaled), by central differences. */
    double gu[TS_DESIGN_MAX_FREE];
    int have_grad;
    double gf[TS_DESIGN_MAX_FREE];
    double gc[TS_DESIGN_MAX_CONSTRAINTS][TS_DESIGN_MAX_FREE];
    int stop;
    int rc;                       /* TS_ENOMEM or TS_ECANCEL that stopped */
    ts_err err;
} study;

static void to_si(const ts_design *d, const double *u, double *x)
{
    for (int i = 0; i < d->spec.nfree; i++) {
        const ts_design_var *f = &d->spec.free[i];
        x[i] = f->lower + u[i] * (f->upper - f->lower);
    }
}

static double bound_scale(double b)
{
    return b != 0 ? fabs(b) : 1.0;
}

/* The request at SI values x. */
static int request_at(const ts_design *d, const double *x, ts_request *rq,
                      ts_err *err)
{
    *rq = d->spec.rq;
    rq->progress = NULL;
    rq->progress_data = NULL;
    rq->setup.equilibrium.guess = NULL;
    for (int i = 0; i < d->spec.nfree; i++) {
        int rc = ts_setup_set(&rq->setup, d->spec.free[i].path, x[i], err);
        if (rc)
            return rc;
    }
    return TS_OK;
}

/* Objective and constraints of result r (NULL: failed). */
static void score(study *st, const ts_result *r, int ok)
{
    const ts_design_spec *sp = &st->d->spec;
    ts_value v;
    st->f = 0;
    if (sp->goal.kind != TS_DESIGN_NONE) {
        if (!ok || !study_value(sp, r, sp->goal.name, &v)) {
            st->f = HUGE_VAL;
        } else {
            if (!(st->goal_scale > 0))
                st->goal_scale = sp->goal.kind == TS_DESIGN_TARGET
                                     ? bound_scale(sp->goal.target)
                                     : bound_scale(v.value);
            double g = v.value / st->goal_scale;
            st->f = sp->goal.kind == TS_DESIGN_TARGET
                        ? pow((v.value - sp->goal.target) / st->goal_scale, 2)
                    : sp->goal.kind == TS_DESIGN_MINIMISE ? g : -g;
        }
    }
    for (int i = 0; i < sp->nconstraints; i++) {
        const ts_design_constraint *c = &sp->constraints[i];
        if (!ok || !study_value(sp, r, c->name, &v)) {
            st->c[i] = 1.0;
            continue;
        }
        double g = (v.value - c->bound) / bound_scale(c->bound);
        st->c[i] = c->upper ? g : -g;
    }
}

static int grow_history(study *st)
{
    ts_design *d = st->d;
    if (d->neval < st->cap)
        return 0;
    int cap = st->cap ? 2 * st->cap : 64;
    ts_design_eval *h = realloc(d->history, (size_t)cap * sizeof *h);
    if (!h)
        return -1;
    d->history = h;
    st->cap = cap;
    return 0;
}

/* Run at u unless cached. */
static void evaluate(study *st, const double *u)
{
    ts_design *d = st->d;
    int n = d->spec.nfree;
    if (st->have && !memcmp(u, st->u, (size_t)n * sizeof *u))
        return;
    memcpy(st->u, u, (size_t)n * sizeof *u);
    st->have = 1;
    if (grow_history(st)) {
        st->rc = ts_fail(&st->err, TS_ENOMEM, "design: out of memory");
        st->stop = 1;
        score(st, NULL, 0);
        return;
    }
    ts_design_eval *h = &d->history[d->neval];
    memset(h, 0, sizeof *h);
    to_si(d, u, h->x);
    ts_request rq;
    ts_err e = {0};
    ts_result *r = NULL;
    int rc = request_at(d, h->x, &rq, &e);
    if (!rc) {
        rq.setup.discretisation_error = 0;
        rq.setup.refine = 0;
        rq.setup.equilibrium.guess = st->dir;
        double t0 = tsi_wall_now();
        rc = ts_analysis_run(st->sys, &rq, &r, &e);
        h->wall_s = tsi_wall_now() - t0;
    }
    h->status = rc;
    h->evaluations = r ? r->evaluations : 0;
    score(st, r, rc == TS_OK && r);
    h->goal = NAN;
    ts_value v;
    if (rc == TS_OK && d->spec.goal.kind != TS_DESIGN_NONE &&
        study_value(&d->spec, r, d->spec.goal.name, &v))
        h->goal = v.value;
    h->violation = 0;
    for (int i = 0; i < d->spec.nconstraints; i++)
        if (st->c[i] > h->violation)
            h->violation = st->c[i];
    d->neval++;
    /* Continuation: the next run starts from this equilibrium. */
    if (rc == TS_OK && r && r->eq && r->eq->converged) {
        int nd = 3 * r->eq->nlinks;
        if (nd != st->ndir) {
            double *p = realloc(st->dir, (size_t)nd * sizeof *p);
            if (p) {
                st->dir = p;
                st->ndir = nd;
            }
        }
        if (nd == st->ndir)
            memcpy(st->dir, r->eq->directions, (size_t)nd * sizeof *st->dir);
    }
    ts_result_free(r);
    const ts_design_spec *sp = &d->spec;
    if (sp->progress) {
        ts_progress p = {"design", (double)d->neval,
                         (double)(sp->max_evals), "evaluations"};
        if (sp->progress(&p, sp->progress_data)) {
            st->stop = 1;
            st->rc = ts_fail(&st->err, TS_ECANCEL, "design: stopped on "
                             "request");
        }
    }
}

/* The gradients of the objective and the constraints at u by central
 * differences of step TS_DESIGN_GRAD_STEP in the scaled values (one-sided
 * at a bound), two analysis runs per free value, each continuing from the
 * previous equilibrium; the values at u are kept as evaluate() left them.
 * A failed run gives the gradient of the failure's penalty, so the
 * method steps back. */
static void gradient(study *st, const double *u)
{
    ts_design *d = st->d;
    int n = d->spec.nfree, nc = d->spec.nconstraints;
    if (st->have_grad && !memcmp(u, st->gu, (size_t)n * sizeof *u))
        return;
    evaluate(st, u);
    double f0 = st->f, c0[TS_DESIGN_MAX_CONSTRAINTS];
    memcpy(c0, st->c, sizeof c0);
    for (int i = 0; i < n && !st->stop; i++) {
        double up[TS_DESIGN_MAX_FREE], dn[TS_DESIGN_MAX_FREE];
        memcpy(up, u, (size_t)n * sizeof *u);
        memcpy(dn, u, (size_t)n * sizeof *u);
        up[i] = fmin(1.0, u[i] + TS_DESIGN_GRAD_STEP);
        dn[i] = fmax(0.0, u[i] - TS_DESIGN_GRAD_STEP);
        double h = up[i] - dn[i];
        evaluate(st, up);
        double fp = st->f, cp[TS_DESIGN_MAX_CONSTRAINTS];
        memcpy(cp, st->c, sizeof cp);
        evaluate(st, dn);
        st->gf[i] = (fp - st->f) / h;
        for (int k = 0; k < nc; k++)
            st->gc[k][i] = (cp[k] - st->c[k]) / h;
    }
    memcpy(st->u, u, (size_t)n * sizeof *u);
    st->f = f0;
    memcpy(st->c, c0, sizeof c0);
    memcpy(st->gu, u, (size_t)n * sizeof *u);
    st->have_grad = 1;
    d->gradients++;
}

static double objective(unsigned n, const double *u, double *grad,
                        void *data)
{
    study *st = data;
    if (!st->stop && grad)
        gradient(st, u);
    else if (!st->stop)
        evaluate(st, u);
    if (grad)
        memcpy(grad, st->gf, n * sizeof *grad);
    if (st->stop)
        st->nl.nlopt_force_stop(st->opt);
    return st->f;
}

typedef struct cdata {
    study *st;
    int i;
} cdata;

static double constraint(unsigned n, const double *u, double *grad,
                         void *data)
{
    cdata *cd = data;
    if (!cd->st->stop && grad)
        gradient(cd->st, u);
    else if (!cd->st->stop)
        evaluate(cd->st, u);
    if (grad)
        memcpy(grad, cd->st->gc[cd->i], n * sizeof *grad);
    if (cd->st->stop)
        cd->st->nl.nlopt_force_stop(cd->st->opt);
    return cd->st->c[cd->i];
}

static const char *nlopt_reason(int code)
{
    switch (code) {
    case NLOPT_SUCCESS: return "success";
    case NLOPT_STOPVAL_REACHED: return "the target was met (stopval)";
    case NLOPT_FTOL_REACHED: return "the objective stopped changing (ftol)";
    case NLOPT_XTOL_REACHED: return "the free values stopped changing (xtol)";
    case NLOPT_MAXEVAL_REACHED: return "the evaluations ran out (max_evals)";
    case NLOPT_MAXTIME_REACHED: return "the time ran out";
    case NLOPT_FAILURE: return "NLopt failed";
    case NLOPT_INVALID_ARGS: return "NLopt: invalid arguments";
    case NLOPT_OUT_OF_MEMORY: return "NLopt: out of memory";
    case NLOPT_ROUNDOFF_LIMITED: return "rounding limited the progress";
    case NLOPT_FORCED_STOP: return "stopped";
    default: return "unknown";
    }
}

/* The best evaluation: feasible (violation within target_rtol) with the
 * smallest objective, else the smallest violation. -1 when none ran. */
static int best_eval(const study *st)
{
    const ts_design *d = st->d;
    double tol = d->spec.target_rtol;
    int best = -1;
    for (int k = 0; k < d->neval; k++) {
        const ts_design_eval *h = &d->history[k];
        if (h->status != TS_OK)
            continue;
        if (best < 0) {
            best = k;
            continue;
        }
        const ts_design_eval *b = &d->history[best];
        int fk = h->violation <= tol, fb = b->violation <= tol;
        if (fk != fb) {
            if (fk)
                best = k;
            continue;
        }
        if (!fk) {
            if (h->violation < b->violation)
                best = k;
            continue;
        }
        double gk = h->goal, gb = b->goal;
        const ts_design_goal *g = &d->spec.goal;
        double ok = g->kind == TS_DESIGN_TARGET ? fabs(gk - g->target)
                    : g->kind == TS_DESIGN_MINIMISE ? gk
                    : g->kind == TS_DESIGN_MAXIMISE ? -gk : 0;
        double ob = g->kind == TS_DESIGN_TARGET ? fabs(gb - g->target)
                    : g->kind == TS_DESIGN_MINIMISE ? gb
                    : g->kind == TS_DESIGN_MAXIMISE ? -gb : 0;
        if (ok < ob)
            best = k;
    }
    return best;
}

/* The single run at the optimum, and what it says of goal and
 * constraints. */
static int final_run(const ts_system *sys, ts_design *d, ts_err *err)
{
    ts_request rq;
    int rc = request_at(d, d->x, &rq, err);
    if (rc)
        return rc;
    double t0 = tsi_wall_now();
    rc = ts_analysis_run(sys, &rq, &d->result, err);
    d->final_wall_s = tsi_wall_now() - t0;
    d->status = rc;
    if (!d->result)
        return rc;
    d->evaluations += d->result->evaluations;
    const ts_design_spec *sp = &d->spec;
    double tol = sp->target_rtol;
    d->reached = 1;
    if (sp->goal.kind != TS_DESIGN_NONE) {
        if (!study_value(sp, d->result, sp->goal.name, &d->goal_value)) {
            d->reached = 0;
            d->goal_value.value = NAN;
        } else if (sp->goal.kind == TS_DESIGN_TARGET) {
            d->goal_misfit = fabs(d->goal_value.value - sp->goal.target);
            d->reached = d->goal_misfit <=
                         tol * bound_scale(sp->goal.target);
        }
    }
    d->feasible = 1;
    for (int i = 0; i < sp->nconstraints; i++) {
        const ts_design_constraint *c = &sp->constraints[i];
        ts_value *v = &d->constraint_value[i];
        if (!study_value(sp, d->result, c->name, v)) {
            v->value = NAN;
            d->constraint_met[i] = 0;
        } else {
            double g = (v->value - c->bound) / bound_scale(c->bound);
            d->constraint_met[i] = (c->upper ? g : -g) <= tol;
        }
        d->feasible &= d->constraint_met[i];
    }
    d->success = rc == TS_OK && d->reached && d->feasible;
    return rc;
}

int ts_design_run(const ts_system *sys, const ts_design_spec *sp,
                  ts_design **out, ts_err *err)
{
    *out = NULL;
    int rc = ts_design_check(sys, sp, err);
    if (rc)
        return rc;
    ts_design *d = calloc(1, sizeof *d);
    if (!d)
        return ts_fail(err, TS_ENOMEM, "design: out of memory");
    d->spec = *sp;
    ts_design_spec *s = &d->spec;
    if (s->max_evals == 0)
        s->max_evals = TS_DESIGN_MAX_EVALS;
    if (s->target_rtol == 0)
        s->target_rtol = TS_DESIGN_TARGET_RTOL;
    if (s->xtol == 0)
        s->xtol = TS_DESIGN_XTOL;
    int n = s->nfree;
    double u[TS_DESIGN_MAX_FREE], lo[TS_DESIGN_MAX_FREE],
        hi[TS_DESIGN_MAX_FREE];
    for (int i = 0; i < n; i++) {
        ts_design_var *f = &s->free[i];
        char canon[TS_PARAM_PATH_MAX];
        ts_param_canonical(f->path, canon, sizeof canon, NULL);
        snprintf(f->path, sizeof f->path, "%s", canon);
        ts_param_unit(sys, canon, d->unit[i], sizeof d->unit[i], NULL);
        double x0 = f->start;
        if (isnan(x0)) {
            if (ts_param_get(sys, canon, &x0, NULL))
                x0 = 0.5 * (f->lower + f->upper);
            /* The setup's own speed and turn rate, when given. */
            if (!strcmp(canon, "tow.speed") && !isnan(s->rq.setup.speed))
                x0 = s->rq.setup.speed;
            if (!strcmp(canon, "tow.turn_rate") &&
                !isnan(s->rq.setup.turn_rate))
                x0 = s->rq.setup.turn_rate;
            for (int k = 0; k < s->rq.setup.nsets; k++)
                if (!strcmp(s->rq.setup.sets[k].path, canon))
                    x0 = s->rq.setup.sets[k].value;
            x0 = fmin(fmax(x0, f->lower), f->upper);
            f->start = x0;
        }
        u[i] = (x0 - f->lower) / (f->upper - f->lower);
        lo[i] = 0;
        hi[i] = 1;
    }
    study st;
    memset(&st, 0, sizeof st);
    st.sys = sys;
    st.d = d;
    if (tsi_nlopt_open(&st.nl, err) != TS_OK) {
        ts_design_free(d);
        return TS_EIO;
    }
    double t0 = tsi_wall_now();
    nlopt_algorithm alg = s->method == TS_DESIGN_BOBYQA  ? NLOPT_LN_BOBYQA
                          : s->method == TS_DESIGN_SLSQP ? NLOPT_LD_SLSQP
                                                         : NLOPT_LN_COBYLA;
    st.opt = st.nl.nlopt_create(alg, (unsigned)n);
    cdata cd[TS_DESIGN_MAX_CONSTRAINTS];
    int nrc = NLOPT_OUT_OF_MEMORY;
    if (st.opt) {
        st.nl.nlopt_set_lower_bounds(st.opt, lo);
        st.nl.nlopt_set_upper_bounds(st.opt, hi);
        st.nl.nlopt_set_min_objective(st.opt, objective, &st);
        for (int i = 0; i < s->nconstraints; i++) {
            cd[i].st = &st;
            cd[i].i = i;
            st.nl.nlopt_add_inequality_constraint(st.opt, constraint, &cd[i],
                                                  0.0);
        }
        st.nl.nlopt_set_xtol_abs1(st.opt, s->xtol);
        st.nl.nlopt_set_maxeval(st.opt, s->max_evals);
        /* A target: stop once the misfit is well inside the tolerance. */
        if (s->goal.kind == TS_DESIGN_TARGET)
            st.nl.nlopt_set_stopval(st.opt, pow(0.1 * s->target_rtol, 2));
        else if (s->goal.kind == TS_DESIGN_NONE)
            st.nl.nlopt_set_stopval(st.opt, 0.0);
        /* A first step of a tenth of each range. */
        double step[TS_DESIGN_MAX_FREE];
        for (int i = 0; i < n; i++)
            step[i] = 0.1;
        st.nl.nlopt_set_initial_step(st.opt, step);
        double f = 0;
        nrc = st.nl.nlopt_optimize(st.opt, u, &f);
        st.nl.nlopt_destroy(st.opt);
    }
    d->nlopt_code = nrc;
    d->nlopt_reason = nlopt_reason(nrc);
    free(st.dir);
    for (int k = 0; k < d->neval; k++)
        d->evaluations += d->history[k].evaluations;
    if (st.rc == TS_ENOMEM || nrc == NLOPT_OUT_OF_MEMORY) {
        ts_design_free(d);
        return ts_fail(err, TS_ENOMEM, "design: out of memory");
    }
    int best = best_eval(&st);
    if (best < 0) {
        /* No run succeeded: the start, run as the command would, says
         * why. */
        for (int i = 0; i < n; i++)
            d->x[i] = s->free[i].start;
    } else {
        memcpy(d->x, d->history[best].x, (size_t)n * sizeof *d->x);
    }
    for (int i = 0; i < n; i++) {
        double w = 1e-6 * (s->free[i].upper - s->free[i].lower);
        d->at_bound[i] = d->x[i] <= s->free[i].lower + w   ? -1
                         : d->x[i] >= s->free[i].upper - w ? 1
                                                           : 0;
    }
    rc = final_run(sys, d, err);
    d->wall_s = tsi_wall_now() - t0;
    *out = d;
    if (rc == TS_OK && st.rc == TS_ECANCEL) {
        ts_fail(err, TS_ECANCEL, "%s", st.err.msg);
        return TS_ECANCEL;
    }
    return rc;
}

void ts_design_free(ts_design *d)
{
    if (!d)
        return;
    free(d->history);
    ts_result_free(d->result);
    free(d);
}

/* ---- JSON ------------------------------------------------------------------ */

static json_t *num(double v)
{
    return isfinite(v) ? json_real(v) : json_null();
}

static json_t *value_json(const ts_value *v)
{
    return json_pack("{s:s,s:s,s:o,s:{s:o,s:o}}", "name", v->name, "unit",
                     v->unit, "value", num(v->value), "error",
                     "discretisation", num(v->error.discretisation),
                     "solver", num(v->error.solver));
}

json_t *ts_design_json(const ts_design *d)
{
    const ts_design_spec *s = &d->spec;
    json_t *o = json_object(), *fr = json_array(), *cons = json_array(),
           *hist = json_array();
    if (!o || !fr || !cons || !hist) {
        json_decref(o);
        json_decref(fr);
        json_decref(cons);
        json_decref(hist);
        return NULL;
    }
    json_object_set_new(o, "analysis", json_string(ts_analysis_name(
                                           s->rq.kind)));
    json_object_set_new(o, "method", json_string(ts_design_method_name(
                                         s->method)));
    for (int i = 0; i < s->nfree; i++)
        json_array_append_new(
            fr, json_pack("{s:s,s:s,s:o,s:o,s:o,s:o,s:s}", "path",
                          s->free[i].path, "unit", d->unit[i], "lower",
                          num(s->free[i].lower), "upper",
                          num(s->free[i].upper), "start",
                          num(s->free[i].start), "optimum", num(d->x[i]),
                          "at_bound",
                          d->at_bound[i] < 0   ? "lower"
                          : d->at_bound[i] > 0 ? "upper"
                                               : "no"));
    json_object_set_new(o, "free", fr);
    json_t *g = json_pack("{s:s}", "kind", ts_design_goal_name(s->goal.kind));
    if (g && s->goal.kind != TS_DESIGN_NONE) {
        json_object_set_new(g, "name", json_string(s->goal.name));
        json_object_set_new(g, "value", value_json(&d->goal_value));
    }
    if (g && s->goal.kind == TS_DESIGN_TARGET) {
        json_object_set_new(g, "target", num(s->goal.target));
        json_object_set_new(g, "misfit", num(d->goal_misfit));
        json_object_set_new(g, "reached", json_boolean(d->reached));
    }
    json_object_set_new(o, "goal", g);
    for (int i = 0; i < s->nconstraints; i++)
        json_array_append_new(
            cons, json_pack("{s:s,s:s,s:o,s:o,s:b}", "name",
                            s->constraints[i].name, "kind",
                            s->constraints[i].upper ? "<=" : ">=", "bound",
                            num(s->constraints[i].bound), "value",
                            value_json(&d->constraint_value[i]), "met",
                            d->constraint_met[i]));
    json_object_set_new(o, "constraints", cons);
    json_object_set_new(o, "feasible", json_boolean(d->feasible));
    json_object_set_new(o, "success", json_boolean(d->success));
    json_object_set_new(o, "target_rtol", num(s->target_rtol));
    json_object_set_new(o, "nlopt", json_pack("{s:i,s:s}", "code",
                                              d->nlopt_code, "reason",
                                              d->nlopt_reason));
    json_object_set_new(o, "iterations", json_integer(d->neval));
    if (s->method == TS_DESIGN_SLSQP)
        json_object_set_new(o, "gradient", json_pack("{s:i,s:f}", "count",
                                                     d->gradients, "step",
                                                     TS_DESIGN_GRAD_STEP));
    json_object_set_new(o, "cost", json_pack("{s:I,s:o,s:o}", "evaluations",
                                             (json_int_t)d->evaluations,
                                             "wall_s", num(d->wall_s),
                                             "final_wall_s",
                                             num(d->final_wall_s)));
    for (int k = 0; k < d->neval; k++) {
        const ts_design_eval *h = &d->history[k];
        json_t *x = json_array();
        for (int i = 0; x && i < s->nfree; i++)
            json_array_append_new(x, num(h->x[i]));
        json_array_append_new(
            hist, json_pack("{s:o,s:i,s:o,s:o,s:I}", "x", x, "status",
                            h->status, "goal", num(h->goal), "violation",
                            num(h->violation), "evaluations",
                            (json_int_t)h->evaluations));
    }
    json_object_set_new(o, "history", hist);
    if (d->result)
        json_object_set_new(o, "result", ts_report_result_json(d->result, 0));
    return o;
}
