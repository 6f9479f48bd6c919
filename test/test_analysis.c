/* test_analysis.c: the pipelines of towstab/analysis.h.
 *
 * Each pipeline is held against the same chain written out by hand from
 * the modules below it (a second route to the same numbers, which must
 * agree bit for bit: the pipeline adds no numerics of its own):
 *  1. equilibrium: positions, top tension, evaluations and the verdict of
 *     ts_health_equilibrium; key values (bodies, top tension) with a
 *     solver error of 10 x residual x length; settings (speed, links)
 *     applied to a copy, the scene's system untouched.
 *  2. modes: the eigenvalues of eq -> fresh kernel -> linearize -> eigen;
 *     per-mode health; key values = the lowest oscillatory modes.
 *  3. simulate with --compare on Kamman ex. 4 at 1 Hz: the key values
 *     (amplitude ratio, phase) against ts_compare_histories of the same
 *     histories (a second fit of the same run) to 1e-9.
 *  4. converge: a sweep's row at N links carries exactly the key values of
 *     a pipeline run with links = N (the study calls the pipeline).
 *  5. failures: an unreachable tolerance fails with the solver's message,
 *     completed 0, never trustworthy (the failure is the first reason);
 *     bad settings are refused by ts_analysis_check naming the option by
 *     its scene key (speed -1, links with link_lengths, an unknown
 *     response output, a sample interval longer than the run).
 *  6. settings by path (ts_setup_set): the run equals the one on a system
 *     with the fields edited, bit for bit; conflicts and bad values are
 *     refused naming the path. */
#include "towstab/analysis.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"

static double total_length(const ts_system *sys)
{
    double L = 0;
    for (int c = 0; c < sys->ncables; c++)
        L += sys->cables[c].length;
    return L;
}

static void test_equilibrium(const ts_scene *sc)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_EQUILIBRIUM);
    rq.setup.speed = 2.385;
    rq.setup.links = 13;
    /* The solver's part alone (the estimate adds its own verdict; test
     * 6 and test/test_accuracy.c). */
    rq.setup.discretisation_error = 0;
    ts_result *r = NULL;
    ts_err err = {0};
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (!CHECK(rc == TS_OK && r && r->completed && r->eq,
               "equilibrium pipeline runs (%s)", err.msg)) {
        ts_result_free(r);
        return;
    }
    CHECK(r->sys->tow.speed == 2.385 && r->sys->nlinks == 13 &&
              sc->system->nlinks == 40 && sc->system->tow.speed != 2.385,
          "settings applied to a copy: speed %g, %d links; the scene keeps "
          "%d links", r->sys->tow.speed, r->sys->nlinks,
          sc->system->nlinks);
    /* The same by hand. */
    ts_system *s = ts_system_copy(sc->system, &err);
    s->tow.speed = 2.385;
    ts_system_set_links(s, 13, &err);
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    rc = ts_equilibrium_solve(k, &eo, eq, &err);
    int same = rc == TS_OK && eq->top_tension == r->eq->top_tension &&
               eq->evaluations == r->eq->evaluations &&
               r->evaluations == eq->evaluations;
    for (int i = 0; same && i < 3 * s->nnodes; i++)
        same = eq->positions[i] == r->eq->positions[i];
    CHECK(same, "positions, top tension %.12g N and %ld evaluations equal "
                "the solver's own, bit for bit",
          r->eq->top_tension, r->evaluations);
    ts_trust t;
    ts_trust_init(&t);
    ts_health_equilibrium(s, eq, &t);
    CHECK(t.trustworthy == r->trust.trustworthy &&
              t.nreasons == r->trust.nreasons && t.nnotes == r->trust.nnotes,
          "verdict: that of ts_health_equilibrium (%s, %d notes)",
          t.trustworthy ? "trustworthy" : "not trustworthy", t.nnotes);
    const ts_value *z = ts_result_value(r, "sphere.z");
    const ts_value *T = ts_result_value(r, "top_tension");
    int node = ts_system_body_node(s, 0);
    double L = total_length(s);
    CHECK(r->nvalues == 4 && z && T &&
              z->value == eq->positions[3 * node + 2] &&
              T->value == eq->top_tension && !strcmp(z->unit, "m") &&
              z->scale == L && isnan(z->error.discretisation) &&
              fabs(z->error.solver -
                   10 * fmax(eq->residual, 16 * 2.220446049250313e-16) * L) <=
                  1e-15 * L,
          "key values: sphere.x|y|z and top_tension; sphere.z %.9g m with a "
          "solver error %.3g m = 10 residual x %.4g m; discretisation not "
          "estimated",
          z ? z->value : NAN, z ? z->error.solver : NAN, L);
    CHECK(r->wall_s > 0 && r->eq_wall_s > 0 && r->eq_wall_s <= r->wall_s,
          "wall times: solve %.3g s within the whole %.3g s", r->eq_wall_s,
          r->wall_s);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_system_free(s);
    ts_result_free(r);
}

static void test_modes(const ts_scene *sc)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_MODES);
    ts_result *r = NULL;
    ts_err err = {0};
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (!CHECK(rc == TS_OK && r && r->eigen && r->mode_health && r->lin,
               "modes pipeline runs (%s)", err.msg)) {
        ts_result_free(r);
        return;
    }
    ts_system *s = ts_system_copy(sc->system, &err);
    ts_system_build(s, &err);
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    rc = ts_equilibrium_solve(k, &eo, eq, &err);
    ts_kernel *k2 = ts_kernel_alloc(s, &err);
    ts_linear *lin = ts_linear_alloc(k2, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    if (rc == TS_OK)
        rc = ts_linearize_equilibrium(k2, eq, &lo, lin, &err);
    ts_eigen_opts go;
    ts_eigen_opts_default(&go);
    ts_eigen *e = NULL;
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, &go, &e, &err);
    /* The same eigenvalues, listed oscillatory first. */
    int same = rc == TS_OK && e->nmodes == r->eigen->nmodes;
    char *used = calloc((size_t)e->nmodes + 1, 1);
    for (int m = 0; same && m < e->nmodes; m++) {
        int found = 0;
        for (int j = 0; !found && j < e->nmodes; j++)
            if (!used[j] && e->modes[m].re == r->eigen->modes[j].re &&
                e->modes[m].im == r->eigen->modes[j].im)
                used[j] = found = 1;
        same = found;
    }
    free(used);
    int order = 1, nosc = 0;
    for (int m = 0; m < r->eigen->nmodes; m++) {
        const ts_mode *md = &r->eigen->modes[m];
        if (md->im > 0) {
            order &= nosc == m &&
                     (m == 0 || md->freq_hz >= r->eigen->modes[m - 1].freq_hz);
            nosc++;
        }
    }
    CHECK(same, "%d modes: the eigenvalues of eq -> linearize -> eigen by "
                "hand, bit for bit", r->eigen->nmodes);
    CHECK(order && nosc > 0 && nosc < r->eigen->nmodes,
          "listed oscillatory first (%d of them), by frequency, then the "
          "real modes", nosc);
    CHECK(r->evaluations == eq->evaluations + lin->evaluations,
          "evaluations: the equilibrium's and the linearization's (%ld)",
          r->evaluations);
    /* Key values: the lowest oscillatory modes. */
    int k3 = 0, ok = 1;
    for (int m = 0; m < e->nmodes && k3 < TS_MODES_FOLLOW; m++) {
        if (!(e->modes[m].im > 0) ||
            !(e->modes[m].damping_ratio < TS_CONV_MODE_DAMPING_MAX))
            continue;
        ok &= r->values[2 * k3].value == e->modes[m].freq_hz &&
              r->values[2 * k3 + 1].value == e->modes[m].damping_ratio;
        k3++;
    }
    CHECK(ok && k3 == TS_MODES_FOLLOW && r->nvalues == 2 * TS_MODES_FOLLOW &&
              !strcmp(r->values[0].name, "mode1.freq_hz"),
          "key values: mode1..3 frequency and damping of the lowest "
          "oscillatory modes (mode1 %.6g Hz)", r->values[0].value);
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k2);
    ts_kernel_free(k);
    ts_system_free(s);
    ts_result_free(r);
}

static void test_simulate(const ts_scene *sc, const ts_units *u)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_SIMULATE);
    ts_err err = {0};
    rq.simulate.excitation = ts_excitation_alloc(&err);
    ts_excitation_parse(rq.simulate.excitation,
                        "tow.heave:amplitude=0.1ft,frequency=1Hz", u, "test",
                        &err);
    rq.simulate.sim.t_end = 8;
    rq.simulate.compare = 1;
    ts_result *r = NULL;
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    if (CHECK(rc == TS_OK && r && r->compared && r->nonlinear && r->linear,
              "simulate --compare at 1 Hz runs (%s)", err.msg)) {
        CHECK(r->sim.dt_sample == 0.05 && r->transient == 4.0 &&
                  !strcmp(r->output.name, "sphere.z"),
              "defaults resolved: sample 0.05 s (below 1/16 of the period), "
              "transient t_end/2 = %g s, output %s", r->transient,
              r->output.name);
        ts_compare c;
        rc = ts_compare_histories(r->sys, r->lin, r->excitation,
                                  r->nonlinear, r->linear, &r->output,
                                  r->transient, &c, &err);
        const ts_value *ar = ts_result_value(r, "sphere.z.amplitude_ratio");
        const ts_value *ph = ts_result_value(r, "sphere.z.phase_deg");
        CHECK(rc == TS_OK && ar && ph &&
                  fabs(ar->value - c.nonlinear.amplitude_ratio) <=
                      1e-9 * fabs(ar->value) &&
                  fabs(ph->value - c.nonlinear.phase_deg) <= 1e-9 * 360,
              "key values: amplitude ratio %.9g and phase %.6g deg equal "
              "the comparison's fit of the nonlinear run (%.9g, %.6g)",
              ar ? ar->value : NAN, ph ? ph->value : NAN,
              c.nonlinear.amplitude_ratio, c.nonlinear.phase_deg);
        CHECK(r->excitation == rq.simulate.excitation &&
                  r->evaluations >= r->nonlinear_stats.evaluations +
                                        r->linear_stats.evaluations,
              "the result refers to the request's excitation; %ld "
              "evaluations in all", r->evaluations);
    }
    ts_result_free(r);
    ts_request_clear(&rq);
}

static void test_converge(const ts_scene *sc)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_CONVERGE);
    rq.converge.analysis = TS_ANALYSIS_MODES;
    rq.converge.nsettings = 2;
    rq.converge.settings[0] = 10;
    rq.converge.settings[1] = 20;
    ts_result *r = NULL;
    ts_err err = {0};
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    const ts_convergence *c = r ? r->convergence : NULL;
    if (!CHECK(rc == TS_OK && c && c->nrows == 2,
               "a modes study over 10, 20 links runs (%s)", err.msg)) {
        ts_result_free(r);
        return;
    }
    ts_request one;
    ts_request_init(&one, TS_ANALYSIS_MODES);
    one.setup.links = 20;
    ts_result *p = NULL;
    rc = ts_analysis_run(sc->system, &one, &p, &err);
    const ts_conv_row *row = c->rows[0].setting == 20 ? &c->rows[0]
                                                      : &c->rows[1];
    int same = rc == TS_OK && p->nvalues == c->nvalues &&
               row->evaluations == p->evaluations;
    for (int v = 0; same && v < c->nvalues; v++)
        same = row->values[v] == p->values[v].value &&
               !strcmp(c->values[v].name, p->values[v].name);
    CHECK(same, "the study's 20-link row holds the modes pipeline's key "
                "values at 20 links, bit for bit (%s = %.9g)",
          c->values[0].name, row->values[0]);
    ts_result_free(p);
    ts_result_free(r);
}

static void test_failures(const ts_scene *sc)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_MODES);
    rq.setup.equilibrium.tol = 1e-300;
    ts_result *r = NULL;
    ts_err err = {0};
    int rc = ts_analysis_run(sc->system, &rq, &r, &err);
    CHECK(rc != TS_OK && r && r->status == rc && !r->completed &&
              !r->trust.trustworthy && r->trust.nreasons >= 1 &&
              !strncmp(r->trust.reasons[0], "the run failed: ", 16) &&
              !strcmp(r->error, err.msg) && strstr(r->error, "residual") &&
              r->eq_attempted && !r->lin && !r->eigen,
          "tolerance 1e-300: fails with the solver's message (%s), not "
          "completed, not trustworthy, the equilibrium kept, nothing "
          "linearized", r ? r->error : "no result");
    ts_result_free(r);

    struct {
        ts_analysis_kind kind;
        const char *key;
    } bad[5] = {{TS_ANALYSIS_EQUILIBRIUM, "speed"},
                {TS_ANALYSIS_EQUILIBRIUM, "links"},
                {TS_ANALYSIS_RESPONSE, "output"},
                {TS_ANALYSIS_SIMULATE, "sample"},
                {TS_ANALYSIS_EQUILIBRIUM, "tolerance"}};
    ts_system *ll = ts_system_copy(sc->system, &err);
    double frac[4] = {0.1, 0.2, 0.3, 0.4};
    ll->cables[0].nlinks = 4;
    ll->cables[0].link_fraction = frac;
    for (int i = 0; i < 5; i++) {
        ts_request_init(&rq, bad[i].kind);
        const ts_system *sys = sc->system;
        switch (i) {
        case 0: rq.setup.speed = -1; break;
        case 1: rq.setup.links = 10; sys = ll; break;
        case 2: snprintf(rq.response.output, sizeof rq.response.output,
                         "sphere.w");
            break;
        case 3:
            rq.simulate.sim.t_end = 5;
            rq.simulate.sim.dt_sample = 10;
            break;
        default: rq.setup.equilibrium.tol = 2; break;
        }
        ts_err_clear(&err);
        rc = ts_analysis_check(sys, &rq, &err);
        size_t n = strlen(bad[i].key);
        CHECK(rc == TS_EINVAL && !strncmp(err.msg, bad[i].key, n) &&
                  err.msg[n] == ':',
              "%s: refused naming '%s': %s", ts_analysis_name(bad[i].kind),
              bad[i].key, err.msg);
    }
    ll->cables[0].link_fraction = NULL; /* the array is the test's */
    ts_system_free(ll);
}

/* 6. Settings by path: a request that sets cable length and sphere mass
 * gives, bit for bit, the run on a copy of the system with those fields
 * written in; the scene's system is untouched; tow.speed set by path and
 * as speed both is refused. */
static void test_sets(const ts_scene *sc)
{
    ts_request rq;
    ts_request_init(&rq, TS_ANALYSIS_MODES);
    ts_err err = {0};
    int rc = ts_setup_set(&rq.setup, "cables.cable.length", 37.25, &err);
    if (!rc)
        rc = ts_setup_set(&rq.setup, "bodies.sphere.mass", 31.5, &err);
    if (!rc)
        rc = ts_setup_set(&rq.setup, "cables.cable.length", 35.75, &err);
    CHECK(rc == TS_OK && rq.setup.nsets == 2,
          "two settings, the second length replacing the first (%d)",
          rq.setup.nsets);
    ts_result *r = NULL, *h = NULL;
    rc = ts_analysis_run(sc->system, &rq, &r, &err);
    ts_system *edit = ts_system_copy(sc->system, &err);
    edit->cables[0].length = 35.75;
    edit->bodies[0].mass = 31.5;
    ts_system_build(edit, &err);
    ts_request plain;
    ts_request_init(&plain, TS_ANALYSIS_MODES);
    int rc2 = ts_analysis_run(edit, &plain, &h, &err);
    int same = rc == TS_OK && rc2 == TS_OK && r->nvalues == h->nvalues &&
               r->eigen->nmodes == h->eigen->nmodes;
    for (int i = 0; same && i < r->nvalues; i++)
        same = r->values[i].value == h->values[i].value;
    for (int m = 0; same && m < r->eigen->nmodes; m++)
        same = r->eigen->modes[m].re == h->eigen->modes[m].re &&
               r->eigen->modes[m].im == h->eigen->modes[m].im;
    CHECK(same && sc->system->cables[0].length != 35.75,
          "modes with cables.cable.length and bodies.sphere.mass set by path "
          "equal those of the edited system bit for bit (%d modes); the "
          "scene keeps %g m", same ? r->eigen->nmodes : -1,
          sc->system->cables[0].length);
    ts_result_free(r);
    ts_result_free(h);
    ts_system_free(edit);
    ts_request_clear(&plain);
    rq.setup.speed = 3;
    ts_setup_set(&rq.setup, "tow.speed", 2, NULL);
    rc = ts_analysis_check(sc->system, &rq, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "set: tow.speed is also given "
                                             "as speed"),
          "tow.speed by path and speed both refused: %s", err.msg);
    rq.setup.speed = NAN;
    ts_setup_set(&rq.setup, "cables.cable.diameter", -1, NULL);
    rc = ts_analysis_check(sc->system, &rq, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "set: cables.cable.diameter: "
                                             "must be > 0 m"),
          "a bad value by path refused naming it: %s", err.msg);
    ts_request_clear(&rq);
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    ts_scene *ex1 = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    ts_scene *ex4 = tscene_load(u, "examples/kamman_ex4.yaml");
    if (ex1 && ex4) {
        test_equilibrium(ex1);
        test_modes(ex4);
        test_simulate(ex4, u);
        test_converge(ex4);
        test_failures(ex1);
        test_sets(ex1);
    }
    ts_scene_free(ex1);
    ts_scene_free(ex4);
    ts_units_free(u);
    return tc_done();
}
