/* test_health.c: trust verdicts on results (towstab/health.h) and the
 * eigenvector error allowance they use (ts_mode.vector_error, lib/eigen.c).
 *
 *  1. The trust record: reasons clear `trustworthy`, notes do not, more
 *     than TS_TRUST_MAX are counted as dropped, merging prefixes.
 *  2. Equilibrium health: not converged, a link in compression (reasons),
 *     a residual near its target (note).
 *  3. The eigenvector allowance against an independent computation: a
 *     two-degree-of-freedom model z' = A z with two close modes (natural
 *     frequencies 2 and 2.0001 rad/s) and an error estimate E coupling
 *     them; the eigenvectors of A + E (LAPACK, through ts_eigen_solve on
 *     a second model) turn from those of A by an angle that the allowance
 *     of A's modes must match within a factor 2 (first-order theory; the
 *     mixing is 5e-3 rad, so second-order terms are ~1e-5 of it). With
 *     well separated modes (2 and 3 rad/s) the allowance and the angle
 *     are both below 1e-5. With a larger coupling the pair's shapes are
 *     not resolved and the health says so (a note naming both modes).
 *  4. A hanging chain in vacuum (no damping at all): every damping ratio
 *     is resolved (zero within 1e-6), the verdict is marginal (a note),
 *     the in-plane/out-of-plane pairs coincide (a note), the result is
 *     trustworthy.
 *  5. The same chain in still water: quadratic drag has no derivative at
 *     zero relative velocity, so the linearized damping is the
 *     difference step's artefact (exactly 0 in the limit); the error
 *     estimate sees it and the result is not trustworthy, with the modes
 *     named.
 *  6. A node at the water surface (tow point one link above it): a reason.
 *  7. JSON of the verdict and of the per-mode health.
 *  8. The surface: a sphere whose centre is nearer the water surface than
 *     its radius (0.0681 m deep, radius 0.127 m: Kamman's sphere at
 *     100 m/s) is noted, one 1 m deep is not; a cylinder hanging
 *     vertically crosses when its half-length exceeds its depth; the
 *     first link of a cable whose ends lie on both sides is named.
 */
#include "towstab/health.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "towstab/report_converge.h"
#include "towstab/report_linear.h"

/* ---- 1, 2. records and equilibria ------------------------------------- */

static void test_trust(void)
{
    ts_trust t;
    ts_trust_init(&t);
    CHECK(t.trustworthy && t.nreasons == 0 && t.nnotes == 0,
          "a fresh record is trustworthy with no reasons or notes");
    ts_trust_note(&t, "near %s", "a limit");
    CHECK(t.trustworthy && t.nnotes == 1 && strcmp(t.notes[0],
                                                    "near a limit") == 0,
          "a note keeps the result trustworthy");
    ts_trust_fail(&t, "bad %d", 1);
    CHECK(!t.trustworthy && t.nreasons == 1 && strcmp(t.reasons[0],
                                                       "bad 1") == 0,
          "a reason makes it untrustworthy");
    for (int i = 0; i < TS_TRUST_MAX + 3; i++)
        ts_trust_fail(&t, "more %d", i);
    CHECK(t.nreasons == TS_TRUST_MAX && t.dropped == 4,
          "reasons beyond %d are counted, not kept (dropped %d)",
          TS_TRUST_MAX, t.dropped);
    ts_trust d;
    ts_trust_init(&d);
    ts_trust_merge(&d, "equilibrium: ", &t);
    CHECK(!d.trustworthy && strncmp(d.reasons[0], "equilibrium: bad 1", 18) ==
                                0 &&
              d.nnotes == 1,
          "merge prefixes and carries the verdict: '%s'", d.reasons[0]);
}

/* The equilibrium health of eq with its solver's condition and shape
 * error estimate set, into t. */
static void health_at(const ts_system *sys, ts_equilibrium *eq,
                      double condition, double shape_error, ts_trust *t)
{
    eq->condition = condition;
    eq->shape_error = shape_error;
    ts_trust_init(t);
    ts_health_equilibrium(sys, eq, t);
}

static void test_equilibrium_health(void)
{
    ts_err err = {0};
    ts_system *sys = ts_system_alloc(1, 0, &err);
    sys->cables[0].from_body = -1;
    sys->cables[0].to_body = -1;
    sys->cables[0].length = 10;
    sys->cables[0].diameter = 0.01;
    sys->cables[0].mass_per_length = 0.5;
    sys->cables[0].nlinks = 3;
    snprintf(sys->cables[0].name, sizeof sys->cables[0].name, "wire");
    ts_system_build(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    double tens[3] = {5.0, -0.25, 1.0};
    memcpy(eq->tensions, tens, sizeof tens);
    eq->converged = 1;
    eq->residual = 1e-14;
    eq->tolerance = 1e-10;
    eq->force_scale = 5;
    eq->min_tension = -0.25;
    ts_trust t;
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(!t.trustworthy && t.nreasons == 1 && strstr(t.reasons[0], "link 2") &&
              strstr(t.reasons[0], "compression"),
          "compression names the link: %s", t.reasons[0]);
    eq->min_tension = 1.0;
    tens[1] = 2.0;
    memcpy(eq->tensions, tens, sizeof tens);
    eq->residual = 5e-11;
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(t.trustworthy && t.nnotes == 1 && strstr(t.notes[0], "residual"),
          "a residual within 10x of its target is a note: %s", t.notes[0]);
    /* The solver's condition: between 1e8 and 1 / (10 eps) a note, the
     * shape error estimate deciding; above, untrustworthy. */
    eq->residual = 1e-14;
    health_at(sys, eq, 6.2e12, 3.8e-10, &t);
    CHECK(t.trustworthy && t.nnotes == 1 &&
              strstr(t.notes[0], "ill-conditioned") &&
              strstr(t.notes[0], "about 2 digits"),
          "condition 6.2e12 with a shape error of 3.8e-10 m is a note: %s",
          t.nnotes ? t.notes[0] : "none");
    health_at(sys, eq, 6.2e12, NAN, &t); /* no estimate: the digits alone */
    CHECK(t.trustworthy && t.nnotes == 1 &&
              strstr(t.notes[0], "about 2 digits)") &&
              !strstr(t.notes[0], "estimate"),
          "condition 6.2e12 without a shape error estimate: %s",
          t.nnotes ? t.notes[0] : "none");
    health_at(sys, eq, 6.2e12, 1e-4, &t); /* above 1e-6 of the 10 m cable */
    CHECK(!t.trustworthy && t.nreasons == 1 &&
              strstr(t.reasons[0], "uncertain by 0.0001 m"),
          "the same with a shape error of 1e-4 m: %s",
          t.nreasons ? t.reasons[0] : "trustworthy");
    health_at(sys, eq, 1e15, 3.8e-10, &t);
    CHECK(!t.trustworthy && t.nreasons == 1 &&
              strstr(t.reasons[0], "nearly singular"),
          "condition 1e15: its solves keep no digit: %s",
          t.nreasons ? t.reasons[0] : "trustworthy");
    eq->condition = NAN;
    eq->shape_error = NAN;
    eq->converged = 0;
    eq->residual = 0.3;
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(!t.trustworthy && strstr(t.reasons[0], "did not converge"),
          "not converged: %s", t.reasons[0]);
    ts_equilibrium_free(eq);
    ts_system_free(sys);
}

/* ---- 3. eigenvector allowance ------------------------------------------- */

/* A hand-made linear model z' = A z, A = [[0, I], [K, C]] for two
 * coordinates, with an error estimate E (the lower block, 2 x 4). */
typedef struct model2 {
    ts_linear lin;
    double A[16], E[8];
} model2;

static void model_init(model2 *m, double k1, double k2, double c, double eps,
                       int with_error)
{
    memset(m, 0, sizeof *m);
    ts_linear *l = &m->lin;
    l->nstate = 4;
    l->nq = 2;
    l->ninput = TS_NINPUT;
    l->nlinks = 1;
    l->nnodes = 2;
    l->kink_node = -1;
    /* Column-major A[i + 4 j]. */
    m->A[0 + 4 * 2] = m->A[1 + 4 * 3] = 1.0;
    m->A[2 + 4 * 0] = -k1;
    m->A[3 + 4 * 1] = -k2;
    m->A[2 + 4 * 2] = m->A[3 + 4 * 3] = -c;
    /* E couples the two coordinates' stiffness: dq1'' / dq2 and back. */
    m->E[0 + 2 * 1] = m->E[1 + 2 * 0] = eps;
    l->A = m->A;
    l->Aerr = with_error ? m->E : NULL;
    double a2 = 0, amax = 0;
    for (int i = 0; i < 16; i++) {
        a2 += m->A[i] * m->A[i];
        amax = fmax(amax, fabs(m->A[i]));
    }
    l->a_norm = sqrt(a2);
    l->a_scale = amax;
    l->trunc_norm = with_error ? sqrt(2.0) * fabs(eps) : 0.0;
    l->trunc_err = with_error ? fabs(eps) : 0.0;
}

/* Angle between mode m's unit eigenvectors in e1 and e2 (complex). */
static double vec_angle(const ts_eigen *e1, const ts_eigen *e2, int m)
{
    double complex dot = 0;
    for (int i = 0; i < 4; i++) {
        double complex a = e1->vec_re[4 * m + i] + I * e1->vec_im[4 * m + i];
        double complex b = e2->vec_re[4 * m + i] + I * e2->vec_im[4 * m + i];
        dot += conj(a) * b;
    }
    double x = cabs(dot);
    return acos(x > 1 ? 1 : x);
}

static void check_allowance(const char *what, double k2, double eps,
                            double lo, double hi)
{
    model2 a, b;
    model_init(&a, 4.0, k2, 0.01, eps, 1);
    /* The perturbed model: A + E, no error estimate of its own. */
    model_init(&b, 4.0, k2, 0.01, eps, 0);
    b.A[2 + 4 * 1] += eps;
    b.A[3 + 4 * 0] += eps;
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    o.method = TS_EIG_LAPACK;
    ts_eigen *ea = NULL, *eb = NULL;
    ts_err err = {0};
    int rc = ts_eigen_solve(&a.lin, &o, &ea, &err);
    if (rc == TS_OK)
        rc = ts_eigen_solve(&b.lin, &o, &eb, &err);
    if (CHECK(rc == TS_OK && ea->nmodes == 2 && eb->nmodes == 2,
              "%s: two modes each (%s)", what, err.msg)) {
        for (int m = 0; m < 2; m++) {
            double ang = vec_angle(ea, eb, m), al = ea->modes[m].vector_error;
            if (lo > 0)
                CHECK(al >= lo * ang && al <= hi * ang,
                      "%s: mode %d allowance %.4g rad vs the eigenvector's "
                      "turn under A + E, %.4g rad (ratio in [%g, %g])",
                      what, m + 1, al, ang, lo, hi);
            else
                CHECK(al <= hi && ang <= hi,
                      "%s: mode %d allowance %.3g and turn %.3g both <= %g",
                      what, m + 1, al, ang, hi);
        }
    }
    ts_eigen_free(ea);
    ts_eigen_free(eb);
}

static void test_vector_allowance(void)
{
    /* Close modes, omega^2 = 4 and 4.0004: the coupling 2e-6 mixes them by
     * about 2e-6 / 4e-4 = 5e-3 rad. The allowance is ten times the
     * first-order turn (the safety of every error bound, lib/eigen.c),
     * which is exact to first order here. */
    check_allowance("close modes", 4.0004, 2e-6, 5.0, 20.0);
    /* Well separated, omega^2 = 4 and 9. */
    check_allowance("separated modes", 9.0, 2e-6, 0.0, 1e-5);

    /* A coupling as large as the gap: the shapes are not resolved. */
    model2 a;
    model_init(&a, 4.0, 4.0004, 0.01, 4e-4, 1);
    ts_eigen *e = NULL;
    ts_err err = {0};
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    ts_mode_health mh[2];
    ts_trust t;
    ts_trust_init(&t);
    if (CHECK(ts_eigen_solve(&a.lin, &o, &e, &err) == TS_OK &&
                  ts_health_modes(NULL, &a.lin, e, mh, &t, &err) == TS_OK,
              "health of a strongly coupled pair (%s)", err.msg)) {
        int found = 0;
        for (int i = 0; i < t.nnotes; i++)
            found |= strstr(t.notes[i], "modes 1 and 2") != NULL &&
                     strstr(t.notes[i], "mix") != NULL;
        CHECK(!mh[0].shape_resolved && !mh[1].shape_resolved &&
                  mh[0].nearest == 1 && mh[1].nearest == 0 && found,
              "coupling 4e-4 across a gap of 4e-4 in omega^2: both shapes "
              "unresolved (allowance %.3g rad), a note names the pair",
              mh[0].vector_error);
        json_t *j = json_pack("{s:[{},{}]}", "modes");
        CHECK(ts_report_modes_health_json(j, e, mh, &t) == TS_OK &&
                  json_is_boolean(json_object_get(j, "trustworthy")) &&
                  json_is_array(json_object_get(j, "reasons")) &&
                  json_is_array(json_object_get(j, "notes")) &&
                  json_is_false(json_object_get(
                      json_array_get(json_object_get(j, "modes"), 0),
                      "shape_trustworthy")) &&
                  json_integer_value(json_object_get(
                      json_array_get(json_object_get(j, "modes"), 0),
                      "nearest_mode")) == 2,
              "JSON: trustworthy, reasons, notes; per mode "
              "shape_trustworthy false and nearest_mode 2");
        json_decref(j);
    }
    ts_eigen_free(e);
}

/* ---- 4-6. hanging chains -------------------------------------------------- */

/* 6 links of 1 m, 0.8 kg/m, 5 mm, hanging at V = 0 from a tow point at
 * depth tow_z, fluid density rho. Health of its modes into t. */
static int chain_health(double rho, double tow_z, ts_trust *t,
                        ts_eigen **eout, ts_mode_health **mhout)
{
    ts_err err = {0};
    ts_system *sys = ts_system_alloc(1, 0, &err);
    snprintf(sys->name, sizeof sys->name, "chain");
    sys->env.water_density = rho;
    sys->tow.point[2] = tow_z;
    ts_cable *c = &sys->cables[0];
    snprintf(c->name, sizeof c->name, "chain");
    c->from_body = c->to_body = -1;
    c->length = 6;
    c->diameter = 0.005;
    c->mass_per_length = 0.8;
    c->nlinks = 6;
    c->cdn = 1.2;
    c->cdt = 0.01;
    c->can = 1.0;
    int rc = ts_system_build(sys, &err);
    ts_kernel *k = rc == TS_OK ? ts_kernel_alloc(sys, &err) : NULL;
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, &err) : NULL;
    ts_linear *lin = NULL;
    ts_eigen *e = NULL;
    ts_mode_health *mh = NULL;
    rc = eq ? ts_equilibrium_solve(k, NULL, eq, &err) : TS_ENOMEM;
    if (rc == TS_OK) {
        lin = ts_linear_alloc(k, &err);
        rc = lin ? ts_linearize_equilibrium(k, eq, NULL, lin, &err)
                 : TS_ENOMEM;
    }
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, NULL, &e, &err);
    if (rc == TS_OK) {
        mh = malloc((size_t)e->nmodes * sizeof *mh);
        rc = ts_health_modes(sys, lin, e, mh, t, &err);
    }
    if (rc != TS_OK)
        printf("     chain: %s\n", err.msg);
    *eout = e;
    *mhout = mh;
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(sys);
    return rc;
}

static int has_text(const ts_trust *t, int reasons, const char *a,
                    const char *b)
{
    int n = reasons ? t->nreasons : t->nnotes;
    for (int i = 0; i < n; i++) {
        const char *s = reasons ? t->reasons[i] : t->notes[i];
        if (strstr(s, a) && (!b || strstr(s, b)))
            return 1;
    }
    return 0;
}

static void test_chains(void)
{
    ts_trust t;
    ts_eigen *e;
    ts_mode_health *mh;
    ts_trust_init(&t);
    if (CHECK(chain_health(0.0, 0.0, &t, &e, &mh) == TS_OK,
              "vacuum chain: modes and health")) {
        int all = 1;
        for (int m = 0; m < e->nmodes; m++)
            all &= mh[m].damping_resolved && mh[m].trustworthy;
        CHECK(all && t.trustworthy && e->verdict == TS_MARGINAL,
              "vacuum chain: every damping (zero) resolved, trustworthy, "
              "verdict marginal");
        CHECK(has_text(&t, 0, "stability is not decided", NULL) &&
                  has_text(&t, 0, "coincide", "modes 1 and 2"),
              "vacuum chain: notes say the stability is undecided and that "
              "the pairs coincide");
    }
    ts_eigen_free(e);
    free(mh);

    ts_trust_init(&t);
    if (CHECK(chain_health(1025.0, 0.5, &t, &e, &mh) == TS_OK,
              "chain in still water: modes and health")) {
        int unresolved = 0;
        for (int m = 0; m < e->nmodes; m++)
            unresolved += !mh[m].damping_resolved;
        CHECK(!t.trustworthy && unresolved > 0 &&
                  has_text(&t, 1, "damping ratio not resolved", "mode 1"),
              "chain in still water: %d modes with unresolved damping (the "
              "linearized quadratic drag at rest is the step's artefact), "
              "not trustworthy: %s",
              unresolved, t.nreasons ? t.reasons[0] : "");
    }
    ts_eigen_free(e);
    free(mh);

    /* Tow point one link (1 m) above the water: node 1 at z = 0. */
    ts_trust_init(&t);
    if (CHECK(chain_health(1025.0, -1.0, &t, &e, &mh) == TS_OK,
              "chain from above the water: modes and health"))
        CHECK(!t.trustworthy &&
                  has_text(&t, 1, "water surface", "chain.1"),
              "a node at the water surface is a reason: %s",
              t.nreasons ? t.reasons[0] : "");
    ts_eigen_free(e);
    free(mh);
}

/* A built one-cable system of 3 links ending in body `type` (diameter
 * 0.254 m, length 2 m), its equilibrium record with every node hanging
 * straight down the z values given. */
static ts_system *surface_system(ts_body_type type, const double z[4],
                                 ts_equilibrium **eq)
{
    ts_err err = {0};
    ts_system *sys = ts_system_alloc(1, 1, &err);
    ts_cable *c = &sys->cables[0];
    snprintf(c->name, sizeof c->name, "wire");
    c->from_body = -1;
    c->to_body = 0;
    c->length = 3.0;
    c->diameter = 0.01;
    c->mass_per_length = 0.5;
    c->nlinks = 3;
    ts_body *b = &sys->bodies[0];
    snprintf(b->name, sizeof b->name, "fish");
    b->type = type;
    b->diameter = 0.254;
    b->length = 2.0;
    b->mass = 10;
    ts_system_build(sys, &err);
    *eq = ts_equilibrium_alloc(sys, &err);
    (*eq)->converged = 1;
    (*eq)->tolerance = 1e-10;
    (*eq)->force_scale = 100;
    (*eq)->min_tension = 1;
    for (int i = 0; i < 4; i++)
        (*eq)->positions[3 * i + 2] = z[i];
    for (int l = 0; l < 3; l++) {
        (*eq)->tensions[l] = 1;
        (*eq)->directions[3 * l + 2] = 1; /* hanging straight down */
    }
    return sys;
}

static int note_with(const ts_trust *t, const char *a, const char *b)
{
    for (int i = 0; i < t->nnotes; i++)
        if (strstr(t->notes[i], a) && (!b || strstr(t->notes[i], b)))
            return 1;
    return 0;
}

static void test_surface(void)
{
    ts_equilibrium *eq;
    ts_trust t;
    static const double awash[4] = {0, 0.02, 0.04, 0.0681};
    ts_system *sys = surface_system(TS_BODY_SPHERE, awash, &eq);
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(t.trustworthy && note_with(&t, "bodies[0] 'fish' breaks the water "
                                         "surface", "0.0681 m below") &&
              note_with(&t, "half-height 0.127 m", NULL) && t.nnotes == 1,
          "a sphere 0.0681 m deep with a 0.127 m radius is awash (a note): "
          "%s", t.nnotes ? t.notes[0] : "none");
    ts_equilibrium_free(eq);
    ts_system_free(sys);
    static const double deep[4] = {0, 0.3, 0.6, 1.0};
    sys = surface_system(TS_BODY_SPHERE, deep, &eq);
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(t.trustworthy && t.nnotes == 0, "a sphere 1 m deep: no note");
    ts_equilibrium_free(eq);
    ts_system_free(sys);
    /* A vertical cylinder 2 m long, 0.9 m deep: its top is 0.1 m above. */
    static const double fish[4] = {0, 0.3, 0.6, 0.9};
    sys = surface_system(TS_BODY_CYLINDER, fish, &eq);
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(note_with(&t, "'fish' breaks the water surface", "half-height 1 m"),
          "a vertical 2 m cylinder 0.9 m deep is awash: %s",
          t.nnotes ? t.notes[0] : "none");
    ts_equilibrium_free(eq);
    ts_system_free(sys);
    /* A tow point 1 m above the water: link 2 crosses. */
    static const double above[4] = {-1.0, -0.4, 0.2, 5.0};
    sys = surface_system(TS_BODY_SPHERE, above, &eq);
    ts_trust_init(&t);
    ts_health_equilibrium(sys, eq, &t);
    CHECK(t.trustworthy && t.nnotes == 1 &&
              note_with(&t, "cables[0] 'wire' crosses the water surface at "
                            "link 2", NULL),
          "the link whose ends lie on both sides is named: %s",
          t.nnotes ? t.notes[0] : "none");
    ts_equilibrium_free(eq);
    ts_system_free(sys);
}

int main(void)
{
    test_trust();
    test_equilibrium_health();
    test_vector_allowance();
    test_chains();
    test_surface();
    return tc_done();
}
