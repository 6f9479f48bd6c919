/* test_eigen_search.c: the sparse eigen analysis (ARPACK on the sparse
 * model, with the rightmost search) against the dense one (LAPACK dgeevx
 * on the dense A, every eigenvalue) on every shipped example with an
 * equilibrium, at the sizes given on the command line (total links of the
 * scene, shared equally among its cables; "scene" for the scene's own).
 * Two linearizations and two eigensolvers:
 *
 *  1. the rightmost eigenvalue: the same real part within the sum of the
 *     two error bounds, and the search's is an eigenvalue of the dense
 *     spectrum (its nearest dense eigenvalue within the sum of the
 *     bounds); the real part alone when the rightmost is not unique (an
 *     undamped part of the system: many eigenvalues within rounding of
 *     zero);
 *  2. the 20 modes nearest 0 Hz: each sparse mode matches a distinct
 *     dense eigenvalue within the sum of their error bounds;
 *  3. the verdicts are equal, or the sparse one is marginal (its bounds
 *     may be wider: they cover the rightmost eigenvalues the search
 *     found, and the modes, with the pencil's left and right vectors and
 *     the model's entry-wise truncation and rounding, doc/linear.md
 *     section 3), or the dense one is marginal through its bounds alone
 *     (every dense eigenvalue has Re < 0) while the sparse one is stable
 *     (its bounds may be narrower: the dense bounds of ill-conditioned
 *     eigenvalues hold kappa eps ||A||, and a cable with bending has a
 *     large ||A||).
 *  4. a marginal verdict names an eigenvalue whose bound reaches 0;
 *  5. the sparse analysis on one thread and on two (the modes' checks
 *     beside the search) gives the same result, bit for bit.
 *
 * Scenes with towed vehicles take the same path: the sparse model holds
 * their attitude, rates and controller states (doc/linear.md, section
 * 2b); so does a towing vehicle at the root, its cyclic states cut in
 * the pencil (section 3a), and both methods must recognise the same
 * neutral modes by symmetry.
 *
 * The default run (suite unit) uses each scene's own size and 60 links;
 * suite slow runs 100, 200 and 400 links, suite huge 800 (doc/linear.md,
 * section 5). Arguments ending in .yaml (files or patterns) take the
 * scenes from them instead of every example, e.g.
 * test_eigen_search 800 'examples/kamman_ex[2-5]*.yaml'.
 * The drop tests have no equilibrium: they are reported and skipped. */
#include <complex.h>
#include <glob.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tcheck.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"

/* Modes compared, as towstab modes shows for large systems. */
#define COUNT 20

static void compare(const char *name, const ts_system *sys)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    if (ts_equilibrium_solve(k, NULL, eq, &err) != TS_OK) {
        printf("  %s (%d links): no equilibrium (%s): skipped\n", name,
               sys->nlinks, err.msg);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        return;
    }
    ts_linear *lin = ts_linear_alloc(k, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = TS_LIN_BOTH;
    int rc = ts_linearize_equilibrium(k, eq, &lo, lin, &err);
    ts_eigen *all = NULL, *ar = NULL;
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    o.method = TS_EIG_LAPACK;
    o.vectors = 0;
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, &o, &all, &err);
    o.method = TS_EIG_ARPACK;
    o.count = COUNT < (lin->nstate - 3) / 2 ? COUNT : (lin->nstate - 3) / 2;
    if (rc == TS_OK)
        rc = ts_eigen_solve(lin, &o, &ar, &err);
    if (!CHECK(rc == TS_OK && all->complete,
               "%s (%d links, %d states): both methods (%s)", name,
               sys->nlinks, lin ? lin->nstate : 0, err.msg)) {
        ts_eigen_free(all);
        ts_eigen_free(ar);
        ts_linear_free(lin);
        ts_equilibrium_free(eq);
        ts_kernel_free(k);
        return;
    }

    /* Every scene has the sparse model, towed vehicles and a towing
     * vehicle at the root included; with a towing vehicle ARPACK runs on
     * the sparse model too, its cyclic states cut, and both methods set
     * its neutral modes by symmetry apart (doc/linear.md section 3a). */
    if (sys->tow.vehicle >= 0)
        CHECK(lin->desc && ar->sweep_shifts > 0 && !ar->complete &&
                  all->nneutral == lin->nneutral &&
                  ar->nneutral == all->nneutral,
              "%s (%d links): a towing vehicle: ARPACK on the sparse model "
              "with the rightmost search (%d shifts, %d Ritz pairs "
              "dropped), not complete; %d and %d neutral modes recognised "
              "(%d by symmetry)", name, sys->nlinks, ar->sweep_shifts,
              ar->sweep_rejected, all->nneutral, ar->nneutral,
              lin->nneutral);
    else
        CHECK(lin->desc && ar->sweep_shifts > 0,
              "%s (%d links): ARPACK on the sparse model with the rightmost "
              "search (%d shifts)", name, sys->nlinks, ar->sweep_shifts);
    /* 1. The rightmost eigenvalue. */
    const ts_mode *ra = &ar->rightmost, *rl = &all->rightmost;
    double allow = ra->error_bound + rl->error_bound;
    int ties = 0;
    for (int m = 0; m < all->nmodes; m++)
        ties += all->modes[m].re >= rl->re - allow;
    double near = INFINITY, near_bound = 0;
    for (int m = 0; m < all->nmodes; m++) {
        double dd = hypot(all->modes[m].re - ra->re, all->modes[m].im - ra->im);
        if (dd < near) {
            near = dd;
            near_bound = all->modes[m].error_bound;
        }
    }
    CHECK(fabs(ra->re - rl->re) <= allow &&
              near <= ra->error_bound + near_bound,
          "%s (%d links): rightmost %.9g%+.6gi +- %.2g (%d shifts up to "
          "%.4g Hz) = dense %.9g%+.6gi +- %.2g (%.3g of the sum)%s; an "
          "eigenvalue of the dense spectrum (%.2g away)",
          name, sys->nlinks, ra->re, ra->im, ra->error_bound,
          ar->sweep_shifts, ar->top_hz, rl->re, rl->im, rl->error_bound,
          fabs(ra->re - rl->re) / allow,
          ties > 1 ? " (not unique: real part only)" : "", near);

    /* 2. The modes nearest 0 Hz, matched one to one: repeatedly the
     * pair (sparse, dense) of neither matched yet with the smallest
     * distance over its allowance (the sum of the two bounds). Matching
     * each sparse mode in turn to the nearest dense eigenvalue instead
     * lets a mode take the close partner of a later one: on the two-part
     * tow with a vehicle at 399 links, whose dense eigenvalues near 0 Hz
     * are ill-conditioned (bounds up to 105 1/s), -0.949+6.58i took the
     * dense -0.0241+7.97i that belongs to the sparse -0.0241+7.97i. */
    char *used = calloc((size_t)all->nmodes, 1);
    char *done = calloc((size_t)ar->nmodes + 1, 1);
    double worst = 0;
    for (int r = 0; used && done && r < ar->nmodes; r++) {
        int bi = -1, bm = -1;
        double br = INFINITY;
        for (int i = 0; i < ar->nmodes; i++) {
            const ts_mode *a = &ar->modes[i];
            for (int m = 0; !done[i] && m < all->nmodes; m++) {
                if (used[m])
                    continue;
                double dd = hypot(all->modes[m].re - a->re,
                                  all->modes[m].im - a->im);
                double q = dd / (a->error_bound + all->modes[m].error_bound);
                if (q < br) {
                    br = q;
                    bi = i;
                    bm = m;
                }
            }
        }
        if (bi < 0)
            break;
        done[bi] = used[bm] = 1;
        worst = fmax(worst, br);
    }
    free(used);
    free(done);
    CHECK(ar->nmodes == o.count && worst <= 1.0,
          "%s (%d links): the %d modes nearest 0 Hz match dense eigenvalues "
          "within their bounds (largest difference %.3g of the allowance)",
          name, sys->nlinks, ar->nmodes, worst);

    /* 3. The verdicts: equal, or the sparse one marginal, or the dense one
     * marginal through its bounds alone while the sparse one is stable:
     * every dense eigenvalue has Re < 0, and only the dense bounds of
     * ill-conditioned eigenvalues (the two-part tow's, condition numbers
     * up to 2.6e5 against an ||A|| set by its stiff bending tops) reach
     * the axis. */
    CHECK(ar->verdict == all->verdict ||
              ar->verdict == TS_MARGINAL ||
              (ar->verdict == TS_STABLE && all->verdict == TS_MARGINAL &&
               all->max_real < 0),
          "%s (%d links): verdict %s, dense %s (dense max Re %.3g 1/s)",
          name, sys->nlinks, ts_verdict_name(ar->verdict),
          ts_verdict_name(all->verdict), all->max_real);
    /* 4. What a marginal verdict names: an eigenvalue whose bound reaches
     * 0 (Re + bound >= 0), which need not be the rightmost; nothing
     * otherwise. */
    for (int w = 0; w < 2; w++) {
        const ts_eigen *e = w ? all : ar;
        int ok = e->verdict == TS_MARGINAL
                     ? isfinite(e->undecided_real) &&
                           e->undecided_real + e->undecided_error >= 0
                     : isnan(e->undecided_real) && isnan(e->undecided_error);
        CHECK(ok, "%s (%d links): %s: verdict %s names Re %.3g +- %.2g 1/s "
              "(the rightmost %.3g +- %.2g)", name, sys->nlinks,
              w ? "LAPACK" : "ARPACK", ts_verdict_name(e->verdict),
              e->undecided_real, e->undecided_error, e->max_real,
              e->max_real_error);
        /* Another eigenvalue than the rightmost is named exactly when
         * the rightmost is decided: it lies left of the rightmost. */
        if (ts_eigen_other_undecided(e))
            CHECK(e->undecided_real < e->max_real &&
                      e->max_real + e->max_real_error < 0,
                  "%s (%d links): %s: another eigenvalue, Re %.3g, named "
                  "beside the rightmost %.3g +- %.2g", name, sys->nlinks,
                  w ? "LAPACK" : "ARPACK", e->undecided_real, e->max_real,
                  e->max_real_error);
        else if (e->verdict == TS_MARGINAL)
            CHECK(e->max_real + e->max_real_error >= 0,
                  "%s (%d links): %s: marginal, the rightmost %.3g +- %.2g "
                  "decided, yet no other eigenvalue named", name,
                  sys->nlinks, w ? "LAPACK" : "ARPACK", e->max_real,
                  e->max_real_error);
    }
    /* 5. The modes' checks run beside the search on the linearization's
     * threads (lib/eigen.c, search_beside_checks): the same analysis on
     * one thread and on two, bit for bit. */
    {
        ts_eigen *one = NULL, *two = NULL;
        int threads = lin->threads;
        lin->threads = 1;
        rc = ts_eigen_solve(lin, &o, &one, &err);
        lin->threads = 2;
        if (rc == TS_OK)
            rc = ts_eigen_solve(lin, &o, &two, &err);
        lin->threads = threads;
        int same = rc == TS_OK && one->nmodes == two->nmodes &&
                   one->verdict == two->verdict &&
                   one->rightmost.re == two->rightmost.re &&
                   one->rightmost.im == two->rightmost.im &&
                   one->rightmost.error_bound == two->rightmost.error_bound &&
                   one->sweep_found == two->sweep_found;
        for (int i = 0; same && i < one->nmodes; i++)
            same = one->modes[i].re == two->modes[i].re &&
                   one->modes[i].im == two->modes[i].im &&
                   one->modes[i].error_bound == two->modes[i].error_bound &&
                   one->modes[i].vector_error == two->modes[i].vector_error;
        CHECK(same, "%s (%d links): ARPACK and the search on one thread and "
              "on two: the same modes, bounds and rightmost, bit for bit "
              "(%s)", name, sys->nlinks, rc == TS_OK ? "" : err.msg);
        ts_eigen_free(one);
        ts_eigen_free(two);
    }
    ts_eigen_free(all);
    ts_eigen_free(ar);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
}

int main(int argc, char **argv)
{
    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    /* Arguments: sizes ("scene" or a total link count) and, optionally,
     * scene files or patterns (anything ending in .yaml; default every
     * example). */
    static char *defaults[] = {"scene", "60"};
    char **sizes = calloc((size_t)argc + 2, sizeof *sizes);
    glob_t g;
    int nsizes = 0, npat = 0, grc = 0;
    for (int i = 1; sizes && i < argc && grc == 0; i++) {
        size_t len = strlen(argv[i]);
        if (len > 5 && strcmp(argv[i] + len - 5, ".yaml") == 0)
            grc = glob(argv[i], npat++ ? GLOB_APPEND : 0, NULL, &g);
        else
            sizes[nsizes++] = argv[i];
    }
    if (sizes && nsizes == 0) {
        sizes[0] = defaults[0];
        sizes[1] = defaults[1];
        nsizes = 2;
    }
    if (npat == 0)
        grc = glob("examples/*.yaml", 0, NULL, &g);
    if (!units || !sizes || grc != 0) {
        printf("FAIL setup: %s\n", units ? "no examples" : err.msg);
        free(sizes);
        return 1;
    }
    for (int si = 0; si < nsizes; si++) {
        int total = strcmp(sizes[si], "scene") ? atoi(sizes[si]) : 0;
        for (size_t i = 0; i < g.gl_pathc; i++) {
            ts_scene *sc = ts_scene_load(g.gl_pathv[i], units, &err);
            if (!CHECK(sc != NULL, "%s: %s", g.gl_pathv[i], err.msg))
                continue;
            ts_system *sys = sc->system;
            if (total > 0) {
                for (int c = 0; c < sys->ncables; c++) {
                    sys->cables[c].nlinks = total / sys->ncables;
                    free(sys->cables[c].link_fraction);
                    sys->cables[c].link_fraction = NULL;
                }
                if (ts_system_build(sys, &err) != TS_OK) {
                    CHECK(0, "%s: %s", g.gl_pathv[i], err.msg);
                    ts_scene_free(sc);
                    continue;
                }
            }
            compare(g.gl_pathv[i], sys);
            ts_scene_free(sc);
        }
    }
    globfree(&g);
    free(sizes);
    ts_units_free(units);
    return tc_done();
}
