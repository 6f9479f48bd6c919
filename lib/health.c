/* health.c: trustworthiness of results (towstab/health.h; doc/converge.md,
 * "Numerical health").
 *
 * The checks compare what a solver reports about its own accuracy with
 * the size of the result it qualifies:
 *  - equilibrium: the force residual against its target; links in
 *    compression (a rigid link may push, a cable cannot);
 *  - modes: each eigenvalue's error allowance (ts_mode.error_bound: the
 *    first-order change by the linearization's error estimate plus
 *    rounding, lib/eigen.c) against its damping, |Re lambda|: the damping
 *    ratio is resolved when its allowance error_bound / |lambda| is within
 *    10 % of it (or below 1e-6 absolute); each eigenvector's allowance
 *    (ts_mode.vector_error, first-order perturbation theory) against 0.1
 *    rad: two modes closer than their errors allow have shapes that can
 *    mix (Stewart & Sun, Matrix Perturbation Theory, 1990, ch. V); the
 *    stability margin against its error; nodes at the water surface, where
 *    A is the mean of one-sided derivatives (doc/model.md section 6); ARPACK
 *    residuals.
 * The verdict is a ts_trust: trustworthy or not, with reasons and notes as
 * sentences that name the quantity, its size and the limit.
 */
#include "towstab/health.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "towstab/system.h"

/* An ARPACK Ritz pair whose Ritz value's own error (ritz_error, relative
 * to |lambda|) is larger is not an eigenpair to trust. */
#define ARPACK_RESIDUAL_MAX 1e-6
/* Modes listed by name in one aggregated reason. */
#define LIST_MAX 4

void ts_trust_init(ts_trust *t)
{
    memset(t, 0, sizeof *t);
    t->trustworthy = 1;
}

static void add(ts_trust *t, int reason, const char *prefix, const char *fmt,
                va_list ap)
{
    int *n = reason ? &t->nreasons : &t->nnotes;
    char(*list)[TS_TRUST_TEXT] = reason ? t->reasons : t->notes;
    if (reason)
        t->trustworthy = 0;
    if (*n >= TS_TRUST_MAX) {
        t->dropped++;
        return;
    }
    size_t len = 0;
    if (prefix) {
        snprintf(list[*n], TS_TRUST_TEXT, "%s", prefix);
        len = strlen(list[*n]);
    }
    int w = vsnprintf(list[*n] + len, TS_TRUST_TEXT - len, fmt, ap);
    /* A longer text (a failed run's message) is cut visibly. */
    if (w > 0 && (size_t)w >= TS_TRUST_TEXT - len && TS_TRUST_TEXT > 4)
        memcpy(list[*n] + TS_TRUST_TEXT - 4, "...", 4);
    (*n)++;
}

void ts_trust_fail(ts_trust *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    add(t, 1, NULL, fmt, ap);
    va_end(ap);
}

void ts_trust_note(ts_trust *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    add(t, 0, NULL, fmt, ap);
    va_end(ap);
}

/* add() with a fixed text and a prefix. */
static void add_text(ts_trust *t, int reason, const char *prefix,
                     const char *text, ...)
{
    va_list ap;
    va_start(ap, text);
    add(t, reason, prefix, text, ap);
    va_end(ap);
}

void ts_trust_merge(ts_trust *dst, const char *prefix, const ts_trust *src)
{
    for (int i = 0; i < src->nreasons; i++)
        add_text(dst, 1, prefix, "%s", src->reasons[i]);
    for (int i = 0; i < src->nnotes; i++)
        add_text(dst, 0, prefix, "%s", src->notes[i]);
    dst->dropped += src->dropped;
    if (!src->trustworthy)
        dst->trustworthy = 0;
}

/* Notes on what crosses the water surface (z = 0) at an equilibrium: the
 * model takes it in its stride (doc/model.md section 3: buoyancy, drag
 * and added mass by the submerged fraction), but a body awash or a cable
 * leaving the water is worth saying. A sphere crosses when its centre is
 * nearer the surface than its radius; a cylinder when its vertical half
 * extent (L/2 |a_z| + D/2 sqrt(1 - a_z^2), a its axis, along the link
 * ending at it) exceeds that distance; a link when its ends lie on both
 * sides (the first such link of each cable is named). */
static void surface_notes(const ts_system *sys, const ts_equilibrium *eq,
                          ts_trust *t)
{
    for (int b = 0; b < sys->nbodies; b++) {
        const ts_body *B = &sys->bodies[b];
        int node = ts_system_body_node(sys, b);
        double z = eq->positions[3 * node + 2], half;
        if (B->type == TS_BODY_SPHERE) {
            half = 0.5 * B->diameter;
        } else if (B->type == TS_BODY_CYLINDER && node > 0) {
            double az = fabs(eq->directions[3 * (node - 1) + 2]);
            half = 0.5 * B->length * az +
                   0.5 * B->diameter * sqrt(fmax(0.0, 1.0 - az * az));
        } else {
            continue;
        }
        if (fabs(z) < half)
            ts_trust_note(t, "bodies[%d] '%s' breaks the water surface: its "
                             "centre is %.3g m %s the water, its half-height "
                             "%.3g m; its buoyancy, drag and added mass are "
                             "those of the submerged part (doc/model.md "
                             "section 3)",
                          b, B->name, fabs(z), z >= 0 ? "below" : "above",
                          half);
    }
    int noted = -1;
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        double zu = eq->positions[3 * L->upper + 2];
        double zl = eq->positions[3 * L->lower + 2];
        if (L->cable == noted || !((zu < 0 && zl > 0) || (zu > 0 && zl < 0)))
            continue;
        noted = L->cable;
        ts_trust_note(t, "cables[%d] '%s' crosses the water surface at link "
                         "%d (its ends %.3g m and %.3g m deep); the "
                         "submerged fraction of that link carries its "
                         "buoyancy and drag (doc/model.md section 3)",
                      L->cable, sys->cables[L->cable].name, L->index, zu, zl);
    }
}

void ts_health_equilibrium(const ts_system *sys, const ts_equilibrium *eq,
                           ts_trust *t)
{
    if (!eq->converged) {
        if (isfinite(eq->residual) && isfinite(eq->force_scale))
            ts_trust_fail(t, "the equilibrium did not converge: residual "
                             "%.3g of the largest force %.6g N (target %.3g)",
                          eq->residual, eq->force_scale, eq->tolerance);
        else
            ts_trust_fail(t, "the equilibrium did not converge: its forces "
                             "are not finite");
        return;
    }
    if (eq->min_tension < 0) {
        int worst = 0;
        for (int l = 1; l < eq->nlinks; l++)
            if (eq->tensions[l] < eq->tensions[worst])
                worst = l;
        const ts_link *L = &sys->links[worst];
        ts_trust_fail(t, "cables[%d] '%s' link %d is in compression (%.6g "
                         "N): a rigid link can push, a cable cannot, so "
                         "the shape is not physical there",
                      L->cable, sys->cables[L->cable].name, L->index,
                      eq->min_tension);
    }
    if (eq->residual > TS_HEALTH_RESIDUAL_NOTE * eq->tolerance)
        ts_trust_note(t, "the residual %.3g is within a factor %.3g of its "
                         "target %.3g",
                      eq->residual, eq->tolerance / eq->residual,
                      eq->tolerance);
    double L = 0.0;
    for (int l = 0; l < sys->nlinks; l++)
        L += sys->links[l].length;
    if (eq->condition > TS_HEALTH_CONDITION_FAIL)
        ts_trust_fail(t, "the solver's Jacobian is nearly singular "
                         "(condition %.3g > %.3g): its solves keep less "
                         "than one digit, and neither the shape nor its "
                         "error estimate is determined",
                      eq->condition, TS_HEALTH_CONDITION_FAIL);
    else if (eq->condition > TS_HEALTH_CONDITION_NOTE) {
        char est[64] = "";
        if (isfinite(eq->shape_error))
            snprintf(est, sizeof est,
                     "; the shape error estimate %.3g m stands",
                     eq->shape_error);
        ts_trust_note(t, "the solver's Jacobian is ill-conditioned "
                         "(condition %.3g: its solves keep about %.0f "
                         "digits%s)",
                      eq->condition,
                      floor(-log10(eq->condition * DBL_EPSILON)), est);
    }
    if (eq->shape_error > TS_HEALTH_SHAPE_RTOL * L)
        ts_trust_fail(t, "node positions are uncertain by %.3g m, more than "
                         "%.3g of the cable length %.6g m",
                      eq->shape_error, TS_HEALTH_SHAPE_RTOL, L);
    surface_notes(sys, eq, t);
}

void ts_health_simulation(const ts_sim_opts *o, const ts_sim_stats *st,
                          ts_trust *trust)
{
    if (st->steps > 0 &&
        (double)st->rejected > TS_HEALTH_SIM_REJECT_NOTE * (double)st->steps)
        ts_trust_note(trust,
                      "%s rejected %ld trial steps for %ld accepted: the "
                      "tolerance %.3g is near what the method delivers, or "
                      "the scene is stiff for it",
                      ts_integrator_name(o->integrator), st->rejected,
                      st->steps, o->rel_tol);
    if (st->recharts > 0)
        ts_trust_note(trust,
                      "%ld re-chart%s of links near the angle singularity, "
                      "each restarting the integrator",
                      st->recharts, st->recharts == 1 ? "" : "s");
    double mean = st->steps > 0 ? st->t_reached / (double)st->steps : NAN;
    if (st->steps > 0 && mean < TS_HEALTH_SIM_STEP_FAIL * o->t_end)
        ts_trust_fail(trust,
                      "mean accepted step %.3g s is below %.0e of the run "
                      "(%g s): rounding of the time, not the tolerance, "
                      "sets the error",
                      mean, TS_HEALTH_SIM_STEP_FAIL, o->t_end);
}

/* Distance from mode m to the nearest other eigenvalue among the computed
 * modes and their conjugates (its own conjugate included: a complex pair
 * close to the real axis is about to split). *who = -1 for its own
 * conjugate. */
static double nearest_mode(const ts_eigen *e, int m, int *who)
{
    double complex lm = e->modes[m].re + I * e->modes[m].im;
    double gap = e->modes[m].im > 0 ? 2.0 * e->modes[m].im : INFINITY;
    *who = -1;
    for (int k = 0; k < e->nmodes; k++) {
        /* Neutral modes by symmetry share an exact eigenvalue with exact,
         * separate shapes: not close modes of each other. */
        if (k == m || (e->modes[m].neutral >= 0 && e->modes[k].neutral >= 0))
            continue;
        double complex lk = e->modes[k].re + I * e->modes[k].im;
        double d = fmin(cabs(lm - lk), cabs(lm - conj(lk)));
        if (d < gap) {
            gap = d;
            *who = k;
        }
    }
    return gap;
}

int ts_health_modes(const ts_system *sys, const ts_linear *lin,
                    const ts_eigen *e, ts_mode_health mh[], ts_trust *t,
                    ts_err *err)
{
    int nm = e->nmodes;
    ts_mode_health *h = mh ? mh : malloc((size_t)(nm > 0 ? nm : 1) *
                                          sizeof *h);
    if (!h)
        return ts_fail(err, TS_ENOMEM, "health: out of memory for %d modes",
                       nm);
    int nbad = 0, nres = 0, list[LIST_MAX];
    for (int m = 0; m < nm; m++) {
        const ts_mode *md = &e->modes[m];
        ts_mode_health *x = &h[m];
        double mag = hypot(md->re, md->im);
        x->freq_error_hz = md->error_bound / (2.0 * M_PI);
        x->damping_error = mag > 0 ? md->error_bound / mag : INFINITY;
        x->damping_resolved =
            x->damping_error <=
            fmax(TS_HEALTH_DAMPING_RTOL * fabs(md->damping_ratio),
                 TS_HEALTH_DAMPING_ATOL);
        x->gap = nearest_mode(e, m, &x->nearest);
        x->vector_error = md->vector_error;
        x->shape_resolved = md->vector_error <= TS_HEALTH_VECTOR_ERROR;
        if (md->neutral >= 0) {
            /* A neutral mode by symmetry: its eigenvalue and shape are
             * exact (eigen.h), its damping is 0 by the symmetry. */
            x->damping_error = 0.0;
            x->damping_resolved = x->shape_resolved = 1;
        }
        x->trustworthy = x->damping_resolved;
        if (!x->damping_resolved) {
            if (nbad < LIST_MAX)
                list[nbad] = m;
            nbad++;
        }
        if (e->method == TS_EIG_ARPACK && md->neutral < 0 &&
            !(md->ritz_error <= ARPACK_RESIDUAL_MAX * mag)) {
            x->trustworthy = 0;
            nres++;
        }
    }

    if (lin->kinks > lin->kink_tow) {
        char name[2 * TS_NAME_MAX];
        if (sys)
            ts_system_node_name(sys, lin->kink_node, name, sizeof name);
        else
            snprintf(name, sizeof name, "node %d", lin->kink_node);
        ts_trust_fail(t, "%d node%s (first %s, depth %.3g m) within a "
                         "linearization step of the water surface: f is "
                         "not smooth there and A is the mean of one-sided "
                         "derivatives",
                      lin->kinks - lin->kink_tow,
                      lin->kinks - lin->kink_tow == 1 ? "" : "s", name,
                      lin->r0[3 * lin->kink_node + 2]);
    }
    if (nbad > 0) {
        char buf[TS_TRUST_TEXT] = "";
        for (int i = 0; i < nbad && i < LIST_MAX; i++) {
            const ts_mode *md = &e->modes[list[i]];
            size_t len = strlen(buf);
            snprintf(buf + len, sizeof buf - len,
                     "%smode %d (%.4g Hz): %.3g +- %.2g", i ? "; " : "",
                     list[i] + 1, md->freq_hz, md->damping_ratio,
                     h[list[i]].damping_error);
        }
        ts_trust_fail(t, "%d mode%s ha%s a damping ratio not resolved by "
                         "the linearization error (%s%s)",
                      nbad, nbad == 1 ? "" : "s", nbad == 1 ? "s" : "ve", buf,
                      nbad > LIST_MAX ? "; ..." : "");
    }
    if (nres > 0)
        ts_trust_fail(t, "%d ARPACK Ritz pair%s whose Ritz value's error "
                         "exceeds %.0e of |lambda|",
                      nres, nres == 1 ? "" : "s", ARPACK_RESIDUAL_MAX);

    /* The stability margin: the linearization error against the smallest
     * damping. */
    if (nm > 0 && isfinite(e->max_real)) {
        double ratio = e->max_real_error > 0
                           ? fabs(e->max_real) / e->max_real_error
                           : INFINITY;
        if (ts_eigen_other_undecided(e))
            ts_trust_note(t, "stability is not decided: Re(lambda) = %.3g "
                             "1/s is within its error bound %.2g 1/s of 0 "
                             "(the smallest damping, max Re(lambda) = %.3g "
                             "1/s, is decided)",
                          e->undecided_real, e->undecided_error,
                          e->max_real);
        else if (e->verdict == TS_MARGINAL)
            ts_trust_note(t, "stability is not decided: the smallest "
                             "damping, max Re(lambda) = %.3g 1/s, is within "
                             "its error bound %.2g 1/s",
                          e->max_real, e->max_real_error);
        else if (ratio < TS_HEALTH_MARGIN_NOTE)
            ts_trust_note(t, "the stability margin max Re(lambda) = %.3g 1/s "
                             "is only %.3g times its error bound %.2g 1/s",
                          e->max_real, ratio, e->max_real_error);
    }
    /* Close modes: each pair once. */
    for (int m = 0; m < nm; m++) {
        const ts_mode_health *x = &h[m];
        if (x->shape_resolved)
            continue;
        int k = x->nearest;
        if (k >= 0 && k < m && !h[k].shape_resolved && h[k].nearest == m)
            continue;
        if (k < 0)
            ts_trust_note(t, "mode %d (%.4g Hz) is a complex pair close to "
                             "the real axis (Im %.3g 1/s): its shape is not "
                             "resolved (eigenvector error allowance %.2g "
                             "rad)",
                          m + 1, e->modes[m].freq_hz, e->modes[m].im,
                          x->vector_error);
        else if (!isfinite(x->vector_error))
            /* An exactly repeated eigenvalue (identical actuators, say):
             * no allowance is finite. */
            ts_trust_note(t, "modes %d and %d (%.6g and %.6g Hz) are %.3g "
                             "1/s apart, an exactly repeated eigenvalue: "
                             "each shape may be any mix of the two; "
                             "together they are determined",
                          m < k ? m + 1 : k + 1, m < k ? k + 1 : m + 1,
                          e->modes[m < k ? m : k].freq_hz,
                          e->modes[m < k ? k : m].freq_hz, x->gap);
        else
            ts_trust_note(t, "modes %d and %d (%.6g and %.6g Hz) are %.3g "
                             "1/s apart, closer than their errors allow "
                             "(eigenvector error allowance %.2g rad): each "
                             "shape may be any mix of the two; together "
                             "they are determined",
                          m < k ? m + 1 : k + 1, m < k ? k + 1 : m + 1,
                          e->modes[m < k ? m : k].freq_hz,
                          e->modes[m < k ? k : m].freq_hz, x->gap,
                          x->vector_error);
    }
    /* Coinciding modes (a symmetric pair: in-plane and out-of-plane of a
     * hanging chain): the eigenvalue is double within its error, so any
     * mix of the two shapes is a mode too, whatever the shapes printed. */
    int ncoinc = 0, first = -1;
    for (int m = 0; m < nm; m++) {
        int k = h[m].nearest;
        if (k > m && h[m].gap <= fmax(e->modes[m].error_bound,
                                      e->modes[k].error_bound)) {
            if (first < 0)
                first = m;
            ncoinc++;
        }
    }
    if (ncoinc > 0)
        ts_trust_note(t, "%d pair%s of modes coincide within their error "
                         "bounds (first: modes %d and %d, %.6g Hz): any mix "
                         "of a pair's shapes is also a mode",
                      ncoinc, ncoinc == 1 ? "" : "s", first + 1,
                      h[first].nearest + 1, e->modes[first].freq_hz);
    if (lin->a_scale > 0 &&
        lin->trunc_err > TS_HEALTH_LINEAR_NOTE * lin->a_scale)
        ts_trust_note(t, "the linearization error estimate is %.2g of max "
                         "|A| (%.3g of %.6g)",
                      lin->trunc_err / lin->a_scale, lin->trunc_err,
                      lin->a_scale);
    if (!e->complete && e->sweep_shifts > 0)
        ts_trust_note(t, "the verdict covers the %d eigenvalues of the modes "
                         "nearest %.6g Hz and the rightmost that a search of "
                         "the whole spectrum found (%d shifts up to %.4g Hz, "
                         "%d eigenvalues): not a proof that none lies "
                         "further right",
                      e->neig, e->target_hz, e->sweep_shifts, e->top_hz,
                      e->sweep_found);
    else if (!e->complete)
        ts_trust_note(t, "only %d of %d eigenvalues were computed (those "
                         "nearest %.6g Hz): the verdict covers those only",
                      e->neig, e->nstate, e->target_hz);
    if (!mh)
        free(h);
    return TS_OK;
}
