/* test_elastic_sim.c: time-domain simulation of elastic cables (doc/model.md
 * section 7; doc/elastic.md section 7; doc/two-part-tow.md), against the
 * rigid model and the linear frequency response, which do not come from
 * the elastic simulation itself.
 *
 *  1. Rigid limit in time: Kamman example 1 (examples/kamman_ex1_submerged.
 *     yaml, 10 links, tow point 1 ft deep so that no link crosses the
 *     surface), the tow point stepped 0.3 m down over 1 s. The elastic run
 *     (esdirk, EA = 1e8 and 1e9 N; its Newton matrix kept over steps, at
 *     most one Jacobian and one rejection in five steps) is compared with
 *     the rigid run (same
 *     scene, EA = 0, rk8pd at 1e-10) node by node at every sample: the
 *     difference is the cable's stretch, O(1/EA), so it must fall ten times
 *     from 1e8 to 1e9 N and sit near the static stretch T L / EA.
 *  2. Stiffness and the explicit integrator: the same scene at EA = 1e10 N.
 *     rk8pd completes a short run (its steps shrink to the axial stability
 *     limit; it agrees with msbdf and esdirk), and with a step limit it
 *     fails with a message that names stiffness, the step it needed, the
 *     axial period and esdirk.
 *  3. Slack during a run: the tow point of a soft elastic cable moved
 *     2 m down toward the body in 0.4 s: links go slack (tension exactly 0)
 *     and the run stays finite.
 *  4. The two-part tow (examples/two_part_tow.yaml, coarser: 10 + 2 + 6
 *     links) under the slider crank (r 0.1 m, rod 0.35 m, 1.6 s): the run
 *     completes, and the towfish/tow-point heave ratio at the crank
 *     frequency is compared with the linear frequency response at that
 *     frequency (ts_response_at), an independent estimate; a towfish
 *     5 N buoyant instead of neutral heaves several times more, in both.
 *  5. An impulsive start (ts_sim_start_state): a sine heave at full
 *     amplitude from t = 0 (ramp 0, phase 0.7: at t = 0 the tow point is
 *     displaced and jumps in velocity). On the elastic cable no node but
 *     the tow point jumps in velocity (1e-12 m/s): the top link starts to
 *     stretch instead of the cable translating; the displacement carries
 *     the cable with it (the place the tow point rested). A short esdirk
 *     run from there completes. On the rigid cable the top link keeps its
 *     length and turns, and node 1's velocity jumps only along the link
 *     (the part of the jump a rigid link passes on).
 *  6. bdf (SUNDIALS CVODE, order <= 2) against esdirk on the elastic
 *     examples: both within their tolerance of a tight esdirk run.
 * Run from the project root (it reads examples/). */
#include "towstab/equilibrium.h"
#include "towstab/excitation.h"
#include "towstab/compare.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"
#include "towstab/response.h"
#include "towstab/scene.h"
#include "towstab/simulate.h"
#include "towstab/units.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "tscene.h"

#define FT 0.3048

/* A run from the equilibrium of sys: the history (caller frees), the
 * code, the statistics and the error. */
static ts_history *run(const ts_system *sys, const ts_excitation *ex,
                       const ts_sim_opts *o, int *rc, ts_sim_stats *st,
                       ts_err *err)
{
    ts_kernel *k = ts_kernel_alloc(sys, err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, err);
    ts_history *h = ts_history_alloc(sys, ts_sim_nsamples(o), err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    *rc = k && eq && h ? ts_equilibrium_solve(k, &eo, eq, err) : TS_ENOMEM;
    if (*rc == TS_OK)
        *rc = ts_simulate(k, ex, eq->y, o, h, st, NULL, err);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return h;
}

/* Largest node position difference over all common samples, m. */
static double hist_diff(const ts_history *a, const ts_history *b)
{
    double d = 0;
    int n = a->nsamples < b->nsamples ? a->nsamples : b->nsamples;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 3 * a->nnodes; j++)
            d = fmax(d, fabs(a->positions[3 * a->nnodes * i + j] -
                             b->positions[3 * b->nnodes * i + j]));
    return d;
}

static int hist_finite(const ts_history *h)
{
    for (int i = 0; i < h->nsamples; i++) {
        for (int j = 0; j < 3 * h->nnodes; j++)
            if (!isfinite(h->positions[3 * h->nnodes * i + j]))
                return 0;
        for (int j = 0; j < h->nlinks; j++)
            if (!isfinite(h->tensions[h->nlinks * i + j]))
                return 0;
    }
    return 1;
}

/* ---- 1 and 2: rigid limit and stiffness ------------------------------- */

static void set_ea(ts_system *s, double ea, double cv)
{
    s->cables[0].ea = ea;
    s->cables[0].damping = ea > 0 ? cv : 0.0;
    ts_err err = {0};
    int rc = ts_system_build(s, &err);
    CHECK(rc == TS_OK, "rebuild at EA %g N (%s)", ea, err.msg);
}

static void test_rigid_limit(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/kamman_ex1_submerged.yaml");
    if (!sc)
        return;
    ts_system *s = sc->system;
    s->cables[0].nlinks = 10;
    s->tow.point[2] = 1.0 * FT;
    double L = s->cables[0].length;
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal sig = {0};
    sig.type = TS_SIGNAL_STEP;
    sig.axis = TS_AXIS_HEAVE;
    sig.amplitude = 0.3;
    sig.start = 0.0;
    sig.rise = 1.0;
    ts_excitation_add(ex, &sig, &err);

    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 2.0;
    o.dt_sample = 0.1;
    o.rel_tol = 1e-10;
    o.abs_tol = 1e-12;
    int rc;
    ts_sim_stats st;
    set_ea(s, 0.0, 0.0);
    ts_history *hr = run(s, ex, &o, &rc, &st, &err);
    CHECK(rc == TS_OK, "rigid run completes (%s)", err.msg);
    double T0 = hr->tensions[0]; /* top tension at t = 0, N */

    /* Elastic, implicit. Tolerances: rel 1e-9 keeps the integration error
     * (about 1e-9 of the 30 m positions, 3e-8 m) far below the stretch at
     * EA = 1e9 N (T L / EA ~ 1e-5 m); abs 1e-7 on the rates: the axial
     * ringing has strain-rate amplitudes of ~1e-7 here (doc/elastic.md
     * section 7), which esdirk, L-stable, damps instead of resolving. */
    ts_sim_opts oi = o;
    oi.integrator = TS_INT_ESDIRK;
    oi.rel_tol = 1e-9;
    oi.abs_tol = 1e-7;
    double d[2];
    const double eas[2] = {1e8, 1e9};
    for (int i = 0; i < 2; i++) {
        set_ea(s, eas[i], 4000.0);
        ts_history *he = run(s, ex, &oi, &rc, &st, &err);
        CHECK(rc == TS_OK, "esdirk at EA %g N completes (%s; %ld steps)",
              eas[i], err.msg, st.steps);
        /* The modified Newton iteration keeps its matrix over many steps
         * (lib/esdirk_sundials.c, NEWTON_ITERS): with too few iterations allowed
         * each stage that needs one more fails, with a new Jacobian, about
         * once a step. */
        CHECK(st.jacobians * 5 <= st.steps && st.rejected * 5 <= st.steps,
              "EA %g N: %ld Jacobians and %ld rejected steps in %ld steps "
              "(at most one in 5)",
              eas[i], st.jacobians, st.rejected, st.steps);
        d[i] = hist_diff(hr, he);
        /* The static stretch of the cable is about T0 L / EA (the tension
         * falls along the cable, so the sum of the stretches is below
         * that); the dynamic part of the tension is a few per cent of T0. */
        double stretch = T0 * L / eas[i];
        CHECK(d[i] < 2.0 * stretch && d[i] > 0.1 * stretch,
              "EA %g N: elastic - rigid %.3e m, within [0.1, 2] of the "
              "stretch T0 L / EA = %.3e m", eas[i], d[i], stretch);
        ts_history_free(he);
    }
    /* O(1/EA): the ratio is 10 up to terms of relative size strain
     * (~1e-6) and the integration error (3e-8 m against d = 1e-5 m). */
    CHECK(d[0] / d[1] > 9.0 && d[0] / d[1] < 11.0,
          "elastic - rigid falls like 1/EA: %.3e m at 1e8 N, %.3e m at 1e9 "
          "N, ratio %.3f in [9, 11]", d[0], d[1], d[0] / d[1]);
    CHECK(d[1] < 1e-4 * L, "EA 1e9 N: within 1e-4 of the length of the "
          "rigid run (%.2e of L)", d[1] / L);

    /* 2. EA = 1e10 N, explicit. A short run completes and agrees with
     * msbdf; with a step limit rk8pd fails and says why. */
    set_ea(s, 1e10, 4000.0);
    ts_sim_opts oe = o;
    oe.t_end = 0.02;
    oe.dt_sample = 0.01;
    oe.rel_tol = 1e-9;
    oe.abs_tol = 1e-7;
    ts_history *he = run(s, ex, &oe, &rc, &st, &err);
    CHECK(rc == TS_OK, "rk8pd at EA 1e10 N completes 0.02 s (%ld steps)",
          st.steps);
    /* 20 links' worth of axial frequency: pi sqrt(l m / EA) is the
     * shortest axial period; rk8pd's stability limit is a fraction of it,
     * so the mean step must be below it. */
    const ts_link *l0 = &s->links[0];
    double per = M_PI * sqrt(l0->length * l0->mass / l0->ea);
    double mean = oe.t_end / (double)st.steps;
    CHECK(mean < per, "rk8pd's mean step %.2e s is set by stiffness: below "
          "the axial period %.2e s", mean, per);
    ts_sim_opts oim = oe;
    oim.integrator = TS_INT_MSBDF;
    ts_history *hm = run(s, ex, &oim, &rc, &st, &err);
    CHECK(rc == TS_OK, "msbdf at EA 1e10 N completes (%s)", err.msg);
    double dd = hist_diff(he, hm);
    CHECK(dd < 1e-6, "rk8pd and msbdf agree at EA 1e10 N: %.2e m (both "
          "at 1e-9 relative of 30 m positions)", dd);
    ts_history_free(hm);
    oim.integrator = TS_INT_ESDIRK;
    hm = run(s, ex, &oim, &rc, &st, &err);
    CHECK(rc == TS_OK, "esdirk at EA 1e10 N completes (%s)", err.msg);
    dd = hist_diff(he, hm);
    CHECK(dd < 1e-6, "rk8pd and esdirk agree at EA 1e10 N: %.2e m (both "
          "at 1e-9 relative of 30 m positions)", dd);
    ts_history_free(hm);
    ts_history_free(he);

    oe.max_steps = 200;
    ts_err e2 = {0};
    he = run(s, ex, &oe, &rc, &st, &e2);
    CHECK(rc == TS_EINTEGRATOR, "rk8pd with a 200-step limit fails: %s",
          ts_strerror(rc));
    CHECK(strstr(e2.msg, "stiff") && strstr(e2.msg, "needed steps of") &&
              strstr(e2.msg, "axial period") && strstr(e2.msg, "esdirk"),
          "the message names stiffness, the step needed, the axial period "
          "and esdirk: \"%s\"", e2.msg);
    /* The step it quotes: "needed steps of X s". */
    const char *p = strstr(e2.msg, "needed steps of ");
    double hq = p ? strtod(p + strlen("needed steps of "), NULL) : NAN;
    CHECK(hq > 0 && hq < per, "the quoted step %.2e s is below the axial "
          "period %.2e s", hq, per);
    ts_history_free(he);

    ts_history_free(hr);
    ts_excitation_free(ex);
    ts_scene_free(sc);
}

/* ---- 3: slack --------------------------------------------------------- */

static void test_slack(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/kamman_ex1_elastic.yaml");
    if (!sc)
        return;
    ts_system *s = sc->system;
    s->cables[0].nlinks = 10;
    s->tow.point[2] = 1.0 * FT;
    set_ea(s, 1e6, 400.0);
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal sig = {0};
    sig.type = TS_SIGNAL_STEP;
    sig.axis = TS_AXIS_HEAVE;
    sig.amplitude = 2.0;   /* 2 m down, toward the sphere (12 m deeper) */
    sig.start = 0.1;
    sig.rise = 0.4;        /* peak 9.4 m/s: faster than the sphere sinks */
    ts_excitation_add(ex, &sig, &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.t_end = 3.0;
    o.dt_sample = 0.01;
    o.integrator = TS_INT_RK8PD;
    o.abs_tol = 1e-7;
    int rc;
    ts_sim_stats st;
    ts_history *h = run(s, ex, &o, &rc, &st, &err);
    CHECK(rc == TS_OK, "slack run completes (%s; %ld steps)", err.msg,
          st.steps);
    CHECK(hist_finite(h), "positions and tensions finite at all %d samples",
          h->nsamples);
    int slack = 0;
    double tmin = INFINITY;
    for (int i = 0; i < h->nsamples * h->nlinks; i++) {
        slack += h->tensions[i] == 0.0;
        tmin = fmin(tmin, h->tensions[i]);
    }
    CHECK(slack > 0, "links went slack: %d link-samples at exactly zero "
          "tension", slack);
    CHECK(tmin >= 0.0, "no compressive tension (smallest %g N)", tmin);
    ts_history_free(h);
    ts_excitation_free(ex);
    ts_scene_free(sc);
}

/* ---- 4: the two-part tow ---------------------------------------------- */

/* One crank run of radius r (rod 3.5 r, period 1.6 s) on the coarse
 * two-part tow, esdirk at rtol 1e-4 and atol 1e-4 r (rad, rad/s, strain,
 * 1/s: scaled with the crank, whose motion sets the size of the
 * perturbation; at r = 0.1 m the ratio agrees with that at rtol 1e-7,
 * atol 1e-8 to 4e-5 relative, and esdirk at the diameter table's
 * tolerances gives rk8pd's ratios on the full example to 4 significant
 * figures: doc/two-part-tow.md): heave ratio (fundamental of
 * towfish z over that of the tow point, least squares over t = 20..40 s)
 * and the peak-to-peak ratio; *H the linear frequency response at the
 * crank frequency. Why 40 s and not less: the run starts from the
 * equilibrium with the crank at bottom dead centre, which rings the
 * towfish's slow in-plane mode (-0.27 +- 0.65i 1/s here: the neutral
 * towfish is held vertically only by its cable and its drag); after 20 s it
 * has decayed to 0.5 % of its start (after 8 s, 12 %: with an 8..16 s
 * window the 5 mm run's fundamental was 8 % off and its peak-to-peak
 * three times the fundamental). Returns the run's code. */
static int two_part_ratio(ts_system *s, const char *what, double r,
                          double *ratio, double *pp, double *H)
{
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal sig = {0};
    sig.type = TS_SIGNAL_CRANK;
    sig.axis = TS_AXIS_HEAVE;
    sig.amplitude = r;
    sig.rod = 3.5 * r;
    sig.frequency = 1.0 / 1.6;
    ts_excitation_add(ex, &sig, &err);
    ts_sim_opts o;
    ts_sim_opts_default(&o);
    o.integrator = TS_INT_ESDIRK;
    o.rel_tol = 1e-4;
    o.abs_tol = 1e-4 * r;
    o.t_end = 40.0;
    o.dt_sample = 0.05;
    int rc;
    ts_sim_stats st;
    ts_history *h = run(s, ex, &o, &rc, &st, &err);
    CHECK(rc == TS_OK, "two-part (%s) crank r = %g m: run completes (%s; "
          "%ld steps)", what, r, err.msg, st.steps);
    CHECK(hist_finite(h), "two-part (%s) crank r = %g m: history finite",
          what, r);
    ts_output out;
    ts_response_output_find(s, "towfish.z", &out, &err);
    int n0 = (int)(20.0 / o.dt_sample + 0.5), n = h->nsamples - n0;
    double *t = malloc((size_t)n * sizeof(double));
    double *zf = malloc((size_t)n * sizeof(double));
    double *zt = malloc((size_t)n * sizeof(double));
    double pmin = INFINITY, pmax = -INFINITY;
    for (int i = 0; i < n; i++) {
        t[i] = h->t[n0 + i];
        zf[i] = h->positions[3 * h->nnodes * (n0 + i) + 3 * out.node + 2];
        zt[i] = h->positions[3 * h->nnodes * (n0 + i) + 2];
        pmin = fmin(pmin, zf[i]);
        pmax = fmax(pmax, zf[i]);
    }
    double cf, af, phf, ct, at, pht;
    ts_compare_fit_sinusoid(t, zf, n, sig.frequency, &cf, &af, &phf, &err);
    ts_compare_fit_sinusoid(t, zt, n, sig.frequency, &ct, &at, &pht, &err);
    /* The rod term of the crank has even harmonics only: the tow
     * point's fundamental is the crank radius, up to the fit's leakage of
     * the even harmonics (the window is 12.5 periods plus one sample, and
     * the second harmonic is (r/l)^2/4 = 2 % of r: ~1e-3 of r). */
    CHECK(fabs(at - r) < 2e-3 * r, "tow-point fundamental %.9g m = crank "
          "radius %g m", at, r);
    *ratio = af / at;
    *pp = (pmax - pmin) / (2 * r); /* the crank's peak-to-peak is 2 r */

    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    ts_equilibrium_opts eo;
    ts_equilibrium_opts_default(&eo);
    ts_equilibrium_solve(k, &eo, eq, &err);
    ts_linear *lin = ts_linear_alloc(k, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    int lrc = ts_linearize_equilibrium(k, eq, &lo, lin, &err);
    CHECK(lrc == TS_OK, "two-part (%s) linearization (%s)", what, err.msg);
    double re, im;
    ts_response_at(s, lin, 2, &out, 2 * M_PI * sig.frequency, &re, &im,
                   &err);
    *H = hypot(re, im);
    printf("  two-part (coarse, %s), crank r = %g m: heave ratio %.6f "
           "(fundamental), %.6f (peak-to-peak), linear response %.6f "
           "(ratio / response - 1 = %+.2e; %ld steps)\n", what, r, *ratio,
           *pp, *H, *ratio / *H - 1, st.steps);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    free(t);
    free(zf);
    free(zt);
    ts_history_free(h);
    ts_excitation_free(ex);
    return rc;
}

static void test_two_part(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/two_part_tow.yaml");
    if (!sc)
        return;
    ts_system *s = sc->system;
    s->cables[0].nlinks = 10;
    s->cables[1].nlinks = 2;
    s->cables[2].nlinks = 6;
    ts_err err = {0};
    CHECK(ts_system_build(s, &err) == TS_OK, "coarse two-part tow builds");
    double rs, pps, Hs, rl, ppl, Hl;
    two_part_ratio(s, "neutral", 0.005, &rs, &pps, &Hs);
    two_part_ratio(s, "neutral", 0.1, &rl, &ppl, &Hl);
    /* Small crank (5 mm): the heave velocity (0.02 m/s) is 1 % of the tow
     * speed, so the drag is linear in it to ~1 %; the tow point at the
     * waterline (a kink, doc/model.md section 6) shifts the mean, not the
     * fundamental; the start's transient is down to 0.5 % (above). 2 %
     * allows for these (observed 3e-5). */
    CHECK(fabs(rs - Hs) < 0.02 * Hs, "5 mm crank: heave ratio %.5f within "
          "2 %% of the linear response %.5f", rs, Hs);
    /* Lalu's crank (0.1 m): heave velocity 0.39 m/s, 22 % of the tow
     * speed: the quadratic drag damps the towfish's heave more than its
     * linearization, so the ratio is below the linear one and further
     * than at 5 mm. Here the margin is small (observed 0.8 %, 1e-2 of the
     * ratio against an integration error of 4e-5), because the neutral
     * towfish's drag also drives its heave at second order in the
     * amplitude (doc/two-part-tow.md: with thin cables that term makes the
     * nonlinear ratio several times the linear one). */
    CHECK(rl < Hl && fabs(rl - Hl) > fabs(rs - Hs),
          "0.1 m crank: heave ratio %.5f below the linear response %.5f, "
          "further than at 5 mm (nonlinear drag)", rl, Hl);
    /* A loose floor: the towfish's own heave velocity (~8 mm/s) is far
     * below the tow speed, so the drag cannot suppress most of the linear
     * response (observed 0.99 of it). */
    CHECK(rl > 0.3 * Hl, "0.1 m crank: heave ratio %.5f within a factor "
          "0.3 of the linear response %.5f", rl, Hl);
    /* The towfish 5 N buoyant: it flies at an incidence (-7.4 deg on the
     * full example, against +2.0 deg when neutral) where the slope of its
     * cross-flow drag in the incidence is no longer nearly zero, which
     * couples the secondary cable's pitching to its heave at first order
     * (doc/two-part-tow.md). The linear response
     * predicts a ratio six times the neutral one (0.118 against 0.0196 on
     * this model); require more than three times in both, and the
     * nonlinear 5 mm ratio within 2 % of its linear response, as above
     * (observed 7e-4). */
    int fish = -1;
    for (int b = 0; b < s->nbodies; b++)
        if (strcmp(s->bodies[b].name, "towfish") == 0)
            fish = b;
    if (!CHECK(fish >= 0, "the two-part tow has a body 'towfish'")) {
        ts_scene_free(sc);
        return;
    }
    ts_body *tf = &s->bodies[fish];
    tf->mass = s->env.water_density * ts_body_volume(tf) -
               5.0 / s->env.gravity; /* wet weight -5 N */
    CHECK(ts_system_build(s, &err) == TS_OK, "buoyant towfish builds");
    double rb, ppb, Hb;
    two_part_ratio(s, "5 N buoyant", 0.005, &rb, &ppb, &Hb);
    CHECK(fabs(rb - Hb) < 0.02 * Hb, "buoyant, 5 mm crank: heave ratio "
          "%.5f within 2 %% of the linear response %.5f", rb, Hb);
    CHECK(Hb > 3 * Hs && rb > 3 * rs, "buoyant towfish heaves more than "
          "three times the neutral one: linear %.5f against %.5f, "
          "nonlinear %.5f against %.5f", Hb, Hs, rb, rs);
    ts_scene_free(sc);
}

/* Section 5. */
static void test_impulsive_start(const ts_units *u)
{
    ts_scene *sc = tscene_load(u, "examples/kamman_ex1_elastic.yaml");
    if (!sc)
        return;
    ts_system *s = sc->system;
    s->cables[0].nlinks = 12;
    s->tow.point[2] = 1.0 * FT;
    ts_err err = {0};
    ts_excitation *ex = ts_excitation_alloc(&err);
    ts_signal sig = {0};
    sig.type = TS_SIGNAL_SINE;
    sig.axis = TS_AXIS_HEAVE;
    sig.amplitude = 0.1 * FT;
    sig.frequency = 0.25;
    sig.phase = 0.7;
    ts_excitation_add(ex, &sig, &err);
    double du[TS_NINPUT];
    ts_excitation_start_jump(ex, du);
    for (int pass = 0; pass < 2; pass++) {
        set_ea(s, pass ? 0.0 : 1e9, 4000.0);
        int nn = s->nnodes;
        ts_kernel *k = ts_kernel_alloc(s, &err);
        ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
        int rc = ts_equilibrium_solve(k, NULL, eq, &err);
        int n = ts_kernel_nstate(k);
        double *y = malloc((size_t)n * sizeof(double));
        double *f = malloc((size_t)n * sizeof(double));
        double *r0 = malloc(6 * (size_t)nn * sizeof(double)), *v0 = r0 + 3 * nn;
        memcpy(y, eq->y, (size_t)n * sizeof(double));
        ts_kernel_eval(k, y, NULL, f);
        memcpy(r0, ts_kernel_positions(k), 3 * (size_t)nn * sizeof(double));
        memcpy(v0, ts_kernel_velocities(k), 3 * (size_t)nn * sizeof(double));
        if (rc == TS_OK)
            rc = ts_sim_start_state(k, ex, y, y, &err);
        double u0[TS_NINPUT];
        ts_excitation_input(ex, 0.0, u0);
        ts_kernel_eval(k, y, u0, f);
        const double *r = ts_kernel_positions(k), *v = ts_kernel_velocities(k);
        double moved = 0, vmoved = 0, tow = 0;
        for (int c = 0; c < 3; c++)
            tow = fmax(tow, fabs(r[c] - r0[c] - du[c]) +
                                fabs(v[c] - v0[c] - du[3 + c]));
        if (pass == 0) {
            for (int i = 3; i < 3 * nn; i++) {
                moved = fmax(moved, fabs(r[i] - r0[i] - du[i % 3]));
                vmoved = fmax(vmoved, fabs(v[i] - v0[i]));
            }
            CHECK(rc == TS_OK && moved < 1e-12 && vmoved < 1e-12 &&
                      tow < 1e-15,
                  "impulsive start, elastic: the tow point jumps in "
                  "velocity, no other node does (%.2g m/s); the signal's "
                  "displacement at t = 0 carries the cable with it "
                  "(%.2g m)",
                  vmoved, moved);
            ts_sim_opts o;
            ts_sim_opts_default(&o);
            o.integrator = TS_INT_ESDIRK;
            o.t_end = 0.2;
            o.dt_sample = 0.1;
            o.abs_tol = 1e-8;
            ts_history *h = ts_history_alloc(s, ts_sim_nsamples(&o), &err);
            ts_sim_stats st;
            /* The run with phase 0, a jump in velocity only (the jump in
             * place stretches the top link by 2 %: 2e7 N of ringing that
             * takes thousands of steps to resolve). */
            ts_excitation *ev = ts_excitation_alloc(&err);
            ts_signal sv = sig;
            sv.phase = 0.0;
            ts_excitation_add(ev, &sv, &err);
            rc = ts_simulate(k, ev, eq->y, &o, h, &st, NULL, &err);
            ts_excitation_free(ev);
            double first = 0;
            for (int i = 3; i < 3 * nn; i++)
                first = fmax(first, fabs(h->positions[i] - r0[i]));
            CHECK(rc == TS_OK && first < 1e-12 && hist_finite(h),
                  "impulsive start (phase 0), elastic: the run's first "
                  "sample has every node where it was (%.2g m); esdirk "
                  "completes 0.2 s (%ld steps) (%s)",
                  first, st.steps, err.msg);
            ts_history_free(h);
        } else {
            /* Node 1: the rigid top link keeps its length; its jump is
             * along the link. */
            const double *n1 = ts_kernel_directions(k);
            double d[3], len = 0, jv[3], cr[3];
            for (int c = 0; c < 3; c++) {
                d[c] = r[3 + c] - r[c];
                len += d[c] * d[c];
                jv[c] = v[3 + c] - v0[3 + c];
            }
            /* |jump x n| (along n: zero) for the velocity. */
            cr[0] = jv[1] * n1[2] - jv[2] * n1[1];
            cr[1] = jv[2] * n1[0] - jv[0] * n1[2];
            cr[2] = jv[0] * n1[1] - jv[1] * n1[0];
            double normal = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            CHECK(rc == TS_OK && fabs(sqrt(len) - s->links[0].length) < 1e-12 &&
                      normal < 1e-12 && tow < 1e-15,
                  "impulsive start, rigid: the top link keeps its length "
                  "(%.2g m off) and node 1's velocity jumps along it only "
                  "(normal part %.2g m/s)",
                  fabs(sqrt(len) - s->links[0].length), normal);
        }
        free(y);
        free(f);
        free(r0);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
    }
    ts_excitation_free(ex);
    ts_scene_free(sc);
}

/* ---- 6: bdf against esdirk --------------------------------------------- */

/* Largest tension difference over all common samples, N. */
static double tension_diff(const ts_history *a, const ts_history *b,
                           double *tmax)
{
    double d = 0;
    int n = a->nsamples < b->nsamples ? a->nsamples : b->nsamples;
    *tmax = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < a->nlinks; j++) {
            *tmax = fmax(*tmax, fabs(a->tensions[a->nlinks * i + j]));
            d = fmax(d, fabs(a->tensions[a->nlinks * i + j] -
                             b->tensions[b->nlinks * i + j]));
        }
    return d;
}

/* A heave of 0.05 m at freq Hz from a smooth start (ramp 2 s). */
static ts_excitation *heave(double freq, ts_err *err)
{
    ts_excitation *ex = ts_excitation_alloc(err);
    ts_signal sig = {0};
    sig.type = TS_SIGNAL_SINE;
    sig.axis = TS_AXIS_HEAVE;
    sig.amplitude = 0.05;
    sig.frequency = freq;
    sig.ramp = 2.0;
    if (ex)
        ts_excitation_add(ex, &sig, err);
    return ex;
}

/* A reference run's options: integrator m to t_end, samples every dt,
 * rtol 1e-10, atol 1e-12. */
static void sim_opts(ts_sim_opts *o, ts_integrator m, double t_end,
                     double dt)
{
    ts_sim_opts_default(o);
    o->integrator = m;
    o->t_end = t_end;
    o->dt_sample = dt;
    o->rel_tol = 1e-10;
    o->abs_tol = 1e-12;
}

/* The elastic examples (kamman_ex1_elastic at its 20 links, EA 1e9 N;
 * the two-part tow at 10 + 2 + 6 links, EA 4.5e6 N), heaved 0.05 m at
 * 0.5 Hz from a smooth start for 2 s: bdf (CVODE, order <= 2, the sparse
 * Newton matrix) and esdirk at rtol 1e-6, atol 1e-9 against esdirk at
 * rtol 1e-10, atol 1e-12. Every node position and link tension of every
 * sample within the tolerance asked for: rtol times the largest position
 * (m); for a tension, which the integrator does not control (EA e + Cv l
 * e' of the strain states), rtol times the largest tension plus EA times
 * atol, the tension of a strain error atol. A global error, which local
 * error control does not bound strictly: observed 1e-3 to 0.27 of the
 * allowance. */
static void test_bdf(const ts_units *u)
{
    static const char *const scenes[2] = {"examples/kamman_ex1_elastic.yaml",
                                          "examples/two_part_tow.yaml"};
    for (int sc_i = 0; sc_i < 2; sc_i++) {
        ts_scene *sc = tscene_load(u, scenes[sc_i]);
        if (!sc)
            continue;
        ts_system *s = sc->system;
        ts_err err = {0};
        if (sc_i == 1) {
            s->cables[0].nlinks = 10;
            s->cables[1].nlinks = 2;
            s->cables[2].nlinks = 6;
            CHECK(ts_system_build(s, &err) == TS_OK, "coarse two-part tow");
        }
        ts_excitation *ex = heave(0.5, &err);
        ts_sim_opts o;
        sim_opts(&o, TS_INT_ESDIRK, 2.0, 0.05);
        int rc;
        ts_sim_stats st;
        ts_history *ref = run(s, ex, &o, &rc, &st, &err);
        CHECK(rc == TS_OK, "%s: reference esdirk run (%s)", s->name, err.msg);
        double xmax = 0, eamax = 0;
        for (int l = 0; l < s->nlinks; l++)
            eamax = fmax(eamax, s->links[l].ea);
        for (int i = 0; rc == TS_OK && i < 3 * ref->nnodes * ref->nsamples;
             i++)
            xmax = fmax(xmax, fabs(ref->positions[i]));
        o.rel_tol = 1e-6;
        o.abs_tol = 1e-9;
        for (int m = 0; rc == TS_OK && m < 2; m++) {
            o.integrator = m ? TS_INT_BDF : TS_INT_ESDIRK;
            ts_history *h = run(s, ex, &o, &rc, &st, &err);
            double tmax = 0, dt = 0, dx = 0;
            if (rc == TS_OK) {
                dx = hist_diff(ref, h);
                dt = tension_diff(ref, h, &tmax);
            }
            double tallow = o.rel_tol * tmax + eamax * o.abs_tol;
            CHECK(rc == TS_OK && dx <= o.rel_tol * xmax && dt <= tallow,
                  "%s: %s at rtol 1e-6 (%ld steps, %ld Jacobians): "
                  "positions within %.2e m (allowed %.2e), tensions within "
                  "%.2e N (allowed %.2e) of the reference (%s)",
                  s->name, m ? "bdf" : "esdirk", st.steps, st.jacobians, dx,
                  o.rel_tol * xmax, dt, tallow,
                  rc == TS_OK ? "" : err.msg);
            ts_history_free(h);
        }
        ts_history_free(ref);
        ts_excitation_free(ex);
        ts_scene_free(sc);
    }
}

/* The sparse Newton matrix with vehicles: esdirk and bdf on a towed
 * vehicle with its controllers (examples/aurora_towfish.yaml, a
 * prescribed tow point) and on a towing vehicle towing it
 * (examples/dolphin_aurora.yaml, node 0 free), heaved 0.05 m at 0.2 Hz
 * from a smooth start (ramp 2 s) for 4 s, at rtol 1e-6, atol 1e-9,
 * against rk8pd at rtol 1e-10, atol 1e-12 (explicit: no Newton matrix,
 * an independent method). Each run says it made the sparse Newton
 * matrix; every node position of every sample within rtol times the
 * largest position (a global error, which local error control does not
 * bound strictly). */
static void test_vehicles_sparse(const ts_units *u)
{
    static const char *const scenes[2] = {"examples/aurora_towfish.yaml",
                                          "examples/dolphin_aurora.yaml"};
    for (int sc_i = 0; sc_i < 2; sc_i++) {
        ts_scene *sc = tscene_load(u, scenes[sc_i]);
        if (!sc)
            continue;
        ts_system *s = sc->system;
        ts_err err = {0};
        ts_excitation *ex = heave(0.2, &err);
        ts_sim_opts o;
        sim_opts(&o, TS_INT_RK8PD, 4.0, 0.1);
        int rc;
        ts_sim_stats st;
        ts_history *ref = run(s, ex, &o, &rc, &st, &err);
        CHECK(rc == TS_OK && st.newton == TS_NEWTON_NONE,
              "%s: reference rk8pd run (%s)", scenes[sc_i], err.msg);
        double xmax = 0;
        for (int i = 0; rc == TS_OK && i < 3 * ref->nnodes * ref->nsamples;
             i++)
            xmax = fmax(xmax, fabs(ref->positions[i]));
        o.rel_tol = 1e-6;
        o.abs_tol = 1e-9;
        for (int m = 0; rc == TS_OK && m < 2; m++) {
            o.integrator = m ? TS_INT_BDF : TS_INT_ESDIRK;
            ts_history *h = run(s, ex, &o, &rc, &st, &err);
            double dx = rc == TS_OK ? hist_diff(ref, h) : INFINITY;
            CHECK(rc == TS_OK && st.newton == TS_NEWTON_SPARSE &&
                      dx <= o.rel_tol * xmax,
                  "%s: %s with the sparse Newton matrix (%s; %ld steps, %ld "
                  "Jacobians): positions within %.2e m of rk8pd's (allowed "
                  "%.2e) (%s)",
                  scenes[sc_i], m ? "bdf" : "esdirk",
                  st.newton == TS_NEWTON_SPARSE ? "sparse" : "NOT sparse",
                  st.steps, st.jacobians, dx, o.rel_tol * xmax,
                  rc == TS_OK ? "" : err.msg);
            ts_history_free(h);
        }
        ts_history_free(ref);
        ts_excitation_free(ex);
        ts_scene_free(sc);
    }
}

int main(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    if (!u) {
        printf("FAIL units: %s\n", err.msg);
        return 1;
    }
    test_rigid_limit(u);
    test_slack(u);
    test_two_part(u);
    test_impulsive_start(u);
    test_bdf(u);
    test_vehicles_sparse(u);
    ts_units_free(u);
    return tc_done();
}
