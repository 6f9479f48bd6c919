/* test_eigen_arpack.c: ARPACK (shift-invert Arnoldi on the sparse model)
 * against LAPACK (dense QR of the column-difference A) on the 10 lowest
 * modes of a 500-link towed cable (2000 states), with a real shift
 * (sigma = 0: the modes of smallest |lambda|) and a complex shift (the 10
 * modes nearest 2 Hz). Two independent linearizations and two independent
 * eigensolvers must agree within the sum of their error bounds in every
 * shared eigenvalue, ARPACK's Ritz vectors must have residuals below
 * 1e-6 of |lambda|, and each must lie within the two methods' vector
 * error allowances of LAPACK's eigenvector (the angle between them).
 * Third, LAPACK on the sparse model's own A (E^-1 F, formed column by
 * column): its eigenvectors against ARPACK's on the same model, and
 * against the dense model's, each within the two allowances. Kept apart
 * from test_eigen for its run time (dense 2000 x 2000 dgeevx, twice). */
#include "towstab/eigen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "shift.h"
#include "tcheck.h"
#include "towstab/equilibrium.h"
#include "towstab/scene.h"

/* The sine of the angle between mode ma of a and mode mb of b (unit
 * vectors of n entries). */
static double vec_sine(const ts_eigen *a, int ma, const ts_eigen *b, int mb,
                       int n)
{
    const double *ar = a->vec_re + (size_t)ma * n,
                 *ai = a->vec_im + (size_t)ma * n,
                 *br = b->vec_re + (size_t)mb * n,
                 *bi = b->vec_im + (size_t)mb * n;
    double pr = 0, pi = 0;
    for (int i = 0; i < n; i++) {
        pr += ar[i] * br[i] + ai[i] * bi[i];
        pi += ar[i] * bi[i] - ai[i] * br[i];
    }
    return sqrt(fmax(0.0, 1.0 - (pr * pr + pi * pi)));
}

/* The mode of e nearest lambda = re + i im. */
static int nearest_mode(const ts_eigen *e, double re, double im)
{
    int best = 0;
    for (int m = 1; m < e->nmodes; m++)
        if (hypot(e->modes[m].re - re, e->modes[m].im - im) <
            hypot(e->modes[best].re - re, e->modes[best].im - im))
            best = m;
    return best;
}

/* LAPACK's modes of the sparse model's A, formed column by column
 * through S_inf (lib/shift.h); lin->A is put back. */
static ts_eigen *sparse_lapack(ts_linear *lin, const ts_eigen_opts *o)
{
    int n = lin->nstate;
    ts_err err = {0};
    double *keep = malloc((size_t)n * n * sizeof(double));
    double *x = calloc((size_t)n, sizeof(double));
    tsi_shift acc;
    ts_eigen *e = NULL;
    if (keep && x && tsi_shift_factor_inf(&acc, lin, &err) == TS_OK) {
        memcpy(keep, lin->A, (size_t)n * n * sizeof(double));
        for (int j = 0; j < n; j++) {
            x[j] = 1.0;
            tsi_shift_apply(&acc, x, lin->A + (size_t)j * n, 0);
            x[j] = 0.0;
        }
        tsi_shift_free(&acc);
        if (ts_eigen_solve(lin, o, &e, &err) != TS_OK)
            e = NULL;
        memcpy(lin->A, keep, (size_t)n * n * sizeof(double));
    }
    free(keep);
    free(x);
    return e;
}

static const char *yaml =
    "name: long\n"
    "tow: {speed: 1.93, point: [0, 0, 0.5]}\n"
    "cables:\n"
    "  - {name: cable, from: tow, to: fish, length: 503.0, diameter: 0.021,\n"
    "     mass_per_length: 0.77, links: 500, normal_drag: 1.2,\n"
    "     tangential_drag: 0.01, added_mass: 1.0}\n"
    "bodies:\n"
    "  - {name: fish, type: sphere, diameter: 0.5, mass: 150.0, drag: 0.5,\n"
    "     added_mass: 0.5}\n";

int main(void)
{
    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ts_scene *sc = units ? ts_scene_parse(yaml, strlen(yaml), "long", units,
                                          &err)
                         : NULL;
    if (!sc) {
        printf("FAIL setup: %s\n", err.msg);
        return 1;
    }
    const ts_system *sys = sc->system;
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(sys, &err);
    int rc = ts_equilibrium_solve(k, NULL, eq, &err);
    CHECK(rc == TS_OK, "500 links: equilibrium (%s)", err.msg);
    ts_linear *lin = ts_linear_alloc(k, &err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = TS_LIN_BOTH;
    rc = ts_linearize_equilibrium(k, eq, &lo, lin, &err);
    CHECK(rc == TS_OK && lin->nstate == 2000, "500 links: linearized, %d "
                                              "states (%s)",
          lin->nstate, err.msg);
    ts_eigen_opts o;
    ts_eigen_opts_default(&o);
    o.method = TS_EIG_LAPACK;
    o.vectors = 1;
    ts_eigen *all = NULL;
    rc = ts_eigen_solve(lin, &o, &all, &err);
    CHECK(rc == TS_OK && all->complete, "500 links: lapack, all %d "
                                        "eigenvalues (%s)",
          all ? all->neig : 0, err.msg);
    ts_eigen *spl = rc == TS_OK ? sparse_lapack(lin, &o) : NULL;
    CHECK(spl && spl->complete, "500 links: lapack on the sparse model's A, "
                                "all %d eigenvalues",
          spl ? spl->neig : 0);
    for (int pass = 0; pass < 2 && rc == TS_OK && spl; pass++) {
        double target = pass ? 2.0 : 0.0;
        ts_eigen *ar = NULL;
        o.count = 10;
        o.target_hz = target;
        o.method = TS_EIG_ARPACK;
        rc = ts_eigen_solve(lin, &o, &ar, &err);
        /* LAPACK's 10 modes nearest i 2 pi target, by frequency (the same
         * selection ts_eigen_solve makes; done here on the full set). */
        ts_mode lpm[10];
        int lpi[10];
        int taken[2000] = {0};
        for (int s = 0; s < 10; s++) {
            int best = -1;
            double bd = INFINITY;
            for (int m = 0; m < all->nmodes; m++) {
                double d = hypot(all->modes[m].re,
                                 all->modes[m].im - 2 * M_PI * target);
                if (!taken[m] && d < bd) {
                    bd = d;
                    best = m;
                }
            }
            taken[best] = 1;
        }
        for (int m = 0, s = 0; m < all->nmodes; m++)
            if (taken[m]) {
                lpi[s] = m;
                lpm[s++] = all->modes[m];
            }
        CHECK(rc == TS_OK && ar->nmodes == 10,
              "arpack, target %g Hz: 10 modes, %d restarts, %d solves (%s)",
              target, ar ? ar->arpack_iterations : 0,
              ar ? ar->arpack_ops : 0, err.msg);
        double worst = 0, resid = 0, vworst = 0, sworst = 0;
        int n = lin->nstate;
        for (int m = 0; rc == TS_OK && m < 10; m++) {
            const ts_mode *a = &ar->modes[m], *b = &lpm[m];
            double d = hypot(a->re - b->re, a->im - b->im) /
                       (a->error_bound + b->error_bound);
            double sine = vec_sine(ar, m, all, lpi[m], n);
            double vallow = a->vector_error + b->vector_error;
            printf("  mode %2d: vectors %.3g rad apart, allowance %.3g "
                   "(arpack %.3g, lapack %.3g)\n",
                   m + 1, sine, vallow, a->vector_error, b->vector_error);
            vworst = fmax(vworst, sine / vallow);
            /* LAPACK on the sparse model's A against both. */
            int ms = nearest_mode(spl, a->re, a->im);
            double s_as = vec_sine(ar, m, spl, ms, n),
                   s_ds = vec_sine(all, lpi[m], spl, ms, n);
            double al_s = spl->modes[ms].vector_error;
            printf("  mode %2d: lapack on the sparse A: %.3g rad from "
                   "arpack (allowance %.3g), %.3g from the dense model's "
                   "(allowance %.3g)\n",
                   m + 1, s_as, a->vector_error + al_s, s_ds,
                   b->vector_error + al_s);
            sworst = fmax(sworst, fmax(s_as / (a->vector_error + al_s),
                                       s_ds / (b->vector_error + al_s)));
            printf("  mode %2d: arpack %.12g%+.12gi +- %.2g  lapack "
                   "%.12g%+.12gi +- %.2g\n",
                   m + 1, a->re, a->im, a->error_bound, b->re, b->im,
                   b->error_bound);
            worst = fmax(worst, d);
            resid = fmax(resid, a->residual);
        }
        CHECK(rc == TS_OK && worst <= 1.0,
              "target %g Hz: arpack (sparse model) and lapack (dense A) "
              "agree on the 10 nearest modes within their error bounds "
              "(largest difference %.3g of the allowance)",
              target, worst);
        /* The Ritz vectors of OP = (A - sigma I)^-1 are exact to rounding
         * relative to ||A||, ~1e4 1/s here: for |lambda| ~ 1e-2 1/s that
         * is a residual of up to ~1e-7 |lambda|. */
        CHECK(rc == TS_OK && resid < 1e-6,
              "target %g Hz: arpack residuals %.3g < 1e-6 of |lambda|",
              target, resid);
        CHECK(rc == TS_OK && vworst <= 1.0,
              "target %g Hz: arpack's Ritz vectors and lapack's "
              "eigenvectors agree within their vector error allowances "
              "(largest angle %.3g of the allowance)",
              target, vworst);
        CHECK(rc == TS_OK && sworst <= 1.0,
              "target %g Hz: lapack's eigenvectors of the sparse model's A "
              "agree with arpack's and with the dense model's within the "
              "allowances (largest angle %.3g of the allowance)",
              target, sworst);
        ts_eigen_free(ar);
    }
    ts_eigen_free(all);
    ts_eigen_free(spl);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    ts_scene_free(sc);
    ts_units_free(units);
    return tc_done();
}
