/* towing.c: the towing vehicle alone against the coupled system, mode by
 * mode (towstab/towing.h, doc/towing-vehicle.md section 4).
 *
 * The free vehicle is a system of its own: the towing vehicle's body, no
 * cables, the coupled steady speed. Its equilibrium, linear model and
 * modes come from the same library calls as any scene's; the comparison
 * is a shape match over the coordinates the two systems share.
 */
#include "towstab/towing.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "towstab/kernel.h"

void ts_free_vehicle_free(ts_free_vehicle *f)
{
    if (!f)
        return;
    free(f->modes);
    free(f);
}

/* The towing vehicle of sys alone, at steady speed `speed` through the
 * water, its propulsion a speed controller holding it (gain: the scene's
 * speed controller's, else 0, a constant thrust once trimmed). */
static ts_system *free_system(const ts_system *sys, const ts_equilibrium *eq,
                              double speed, ts_err *err)
{
    const ts_body *tb = &sys->bodies[sys->tow.vehicle];
    ts_system *f = ts_system_alloc(0, 1, err);
    if (!f)
        return NULL;
    snprintf(f->name, sizeof f->name, "%s", tb->name);
    f->env = sys->env;
    f->tow = sys->tow;
    f->tow.speed = eq->speed;
    f->tow.turn_rate = eq->turn_rate;
    f->tow.point[2] = eq->positions[2];
    f->tow.vehicle = 0;
    ts_vehicle *v = ts_body_set_vehicle(f, 0, err);
    if (!v) {
        ts_system_free(f);
        return NULL;
    }
    f->bodies[0] = *tb;
    f->bodies[0].vehicle = v;
    *v = *tb->vehicle;
    ts_propulsion *p = &v->propulsion;
    double gain = p->type == TS_PROP_SPEED ? p->gain : 0.0;
    p->type = TS_PROP_SPEED;
    p->speed = speed;
    p->gain = gain;
    p->thrust = 0.0; /* the bias: solved */
    if (ts_system_build(f, err) != TS_OK) {
        ts_system_free(f);
        return NULL;
    }
    return f;
}

/* Solve, linearize (dense) and find every mode of system s; *kk, *eqq,
 * *linn, *ee are the caller's to free. */
static int solve_modes(const ts_system *s, ts_kernel **kk,
                       ts_equilibrium **eqq, ts_linear **linn, ts_eigen **ee,
                       ts_err *err)
{
    *kk = ts_kernel_alloc(s, err);
    *eqq = *kk ? ts_equilibrium_alloc(s, err) : NULL;
    *linn = *eqq ? ts_linear_alloc(*kk, err) : NULL;
    *ee = NULL;
    if (!*linn)
        return err && err->code ? err->code : TS_ENOMEM;
    int rc = ts_equilibrium_solve(*kk, NULL, *eqq, err);
    ts_linearize_opts lo;
    ts_linearize_opts_default(&lo);
    lo.model = TS_LIN_DENSE;
    if (rc == TS_OK)
        rc = ts_linearize_equilibrium(*kk, *eqq, &lo, *linn, err);
    ts_eigen_opts eo;
    ts_eigen_opts_default(&eo);
    eo.method = TS_EIG_LAPACK;
    eo.vectors = 1;
    if (rc == TS_OK)
        rc = ts_eigen_solve(*linn, &eo, ee, err);
    return rc;
}

static void release(ts_kernel *k, ts_equilibrium *eq, ts_linear *lin,
                    ts_eigen *e)
{
    ts_eigen_free(e);
    ts_linear_free(lin);
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
}

/* Free mode fm's partner: coupled mode cm of e, with its MAC. */
static void pair(ts_free_mode *fm, const ts_eigen *e, int cm, double mac)
{
    const ts_mode *c2 = &e->modes[cm];
    fm->mac = mac;
    fm->coupled = cm;
    fm->coupled_re = c2->re;
    fm->coupled_im = c2->im;
    fm->coupled_freq_hz = c2->freq_hz;
    fm->coupled_damping_ratio = c2->damping_ratio;
}

/* Modes of e that coincide (within the sum of their error bounds, or to
 * rounding, 1e-12 of their size) form a group; g[m] its first mode. */
static int coincide(const ts_mode *a, const ts_mode *b)
{
    double d = hypot(a->re - b->re, a->im - b->im);
    double ea = isfinite(a->error_bound) ? a->error_bound : 0.0;
    double eb = isfinite(b->error_bound) ? b->error_bound : 0.0;
    double size = fmax(1.0, fmax(hypot(a->re, a->im), hypot(b->re, b->im)));
    return d <= fmax(ea + eb, 1e-12 * size);
}

static void groups(const ts_eigen *e, int g[])
{
    for (int m = 0; m < e->nmodes; m++) {
        g[m] = m;
        for (int j = 0; j < m; j++)
            if (g[j] == j && coincide(&e->modes[j], &e->modes[m])) {
                g[m] = j;
                break;
            }
    }
}

static int group_size(const int g[], int n, int id)
{
    int c = 0;
    for (int m = 0; m < n; m++)
        c += g[m] == id;
    return c;
}

/* The vector of mode m of e (n states) at the states map[0..nf). */
static void restricted(const ts_eigen *e, int n, int m, const int *map,
                       int nf, double complex *v)
{
    const double *re = e->vec_re + (size_t)m * n, *im = e->vec_im +
                                                         (size_t)m * n;
    for (int i = 0; i < nf; i++)
        v[i] = map ? re[map[i]] + I * im[map[i]] : re[i] + I * im[i];
}

/* Free mode m is one of several coincident free modes (group fg[m]):
 * any mix of them is a mode too, so its vector is compared with the span
 * of each group of coincident coupled modes no larger than its own (a
 * larger span would match anything better), the MAC being the share of
 * its norm in that span, |P v_f|^2 / |v_f|^2. The best group, unless
 * the single best MAC beats it, is its partner; within it the mode of the
 * same symmetry for a neutral mode, else the best single MAC not taken
 * by an earlier member of its own group. */
static void match_span(const ts_eigen *fe, const ts_linear *fl,
                       const ts_eigen *e, const ts_linear *lin,
                       const int *fg, const int *cg, const int *map, int nf,
                       int m, ts_free_mode *modes)
{
    int n = lin->nstate, fsize = group_size(fg, fe->nmodes, fg[m]);
    double complex *v = malloc((size_t)nf * (size_t)(fsize + 2) *
                               sizeof *v);
    if (!v)
        return;
    double complex *Q = v + nf;
    restricted(fe, fl->nstate, m, NULL, nf, v);
    double vn = 0;
    for (int i = 0; i < nf; i++)
        vn += creal(v[i] * conj(v[i]));
    ts_free_mode *fm = &modes[m];
    double best = fm->mac;
    int bestg = -1, bests = 0;
    for (int c0 = 0; c0 < e->nmodes; c0++) {
        int cs = cg[c0] == c0 ? group_size(cg, e->nmodes, c0) : 0;
        if (cs < 2 || cs > fsize)
            continue;
        /* Orthonormal basis of the group's vectors (Gram-Schmidt, twice),
         * then the share of v in it. */
        int r = 0;
        for (int cm = c0; cm < e->nmodes; cm++) {
            if (cg[cm] != c0)
                continue;
            double complex *q = Q + (size_t)r * nf;
            restricted(e, n, cm, map, nf, q);
            for (int pass = 0; pass < 2; pass++)
                for (int j = 0; j < r; j++) {
                    const double complex *p = Q + (size_t)j * nf;
                    double complex d = 0;
                    for (int i = 0; i < nf; i++)
                        d += conj(p[i]) * q[i];
                    for (int i = 0; i < nf; i++)
                        q[i] -= d * p[i];
                }
            double qn = 0;
            for (int i = 0; i < nf; i++)
                qn += creal(q[i] * conj(q[i]));
            if (qn > 1e-20) {
                for (int i = 0; i < nf; i++)
                    q[i] /= sqrt(qn);
                r++;
            }
        }
        double share = 0;
        for (int j = 0; j < r; j++) {
            const double complex *p = Q + (size_t)j * nf;
            double complex d = 0;
            for (int i = 0; i < nf; i++)
                d += conj(p[i]) * v[i];
            share += creal(d * conj(d));
        }
        share = vn > 0 ? share / vn : 0.0;
        if (share > best - 1e-12) { /* the span, at a tie too */
            best = share;
            bestg = c0;
            bests = cs;
        }
    }
    free(v);
    if (bestg < 0)
        return;
    /* The partner within the group. */
    int pick = -1;
    const ts_mode *md = &fe->modes[m];
    for (int cm = bestg; cm < e->nmodes && md->neutral >= 0; cm++)
        if (cg[cm] == bestg && e->modes[cm].neutral >= 0 &&
            !strcmp(fl->neutral[md->neutral].name,
                    lin->neutral[e->modes[cm].neutral].name))
            pick = cm;
    for (int cm = bestg; cm < e->nmodes && pick < 0; cm++) {
        if (cg[cm] != bestg)
            continue;
        int taken = 0;
        for (int j = 0; j < m; j++)
            taken |= fg[j] == fg[m] && modes[j].coupled == cm;
        if (!taken)
            pick = cm;
    }
    if (pick < 0)
        pick = bestg;
    pair(fm, e, pick, best);
    fm->span = bests;
}

int ts_free_vehicle_compare(const ts_system *sys, const ts_equilibrium *eq,
                            const ts_linear *lin, const ts_eigen *e,
                            ts_free_vehicle **out, ts_err *err)
{
    *out = NULL;
    if (sys->tow.vehicle < 0 || lin->root_qoff < 0)
        return ts_fail(err, TS_EINVAL, "free vehicle: the scene has no "
                       "towing vehicle");
    if (!e->vec_re || !e->vec_im || !e->complete)
        return ts_fail(err, TS_EINVAL, "free vehicle: needs every coupled "
                       "mode with its shape (eigen method lapack)");
    /* The tow point's speed through the water in the coupled trim (the
     * frame's origin): the free vehicle holds it. */
    const double *c = sys->env.current;
    double speed = sqrt((eq->speed - c[0]) * (eq->speed - c[0]) +
                        c[1] * c[1] + c[2] * c[2]);
    ts_system *fs = free_system(sys, eq, speed, err);
    if (!fs) {
        ts_err_prefix(err, "free vehicle: ");
        return err && err->code ? err->code : TS_ENOMEM;
    }
    ts_kernel *k = NULL;
    ts_equilibrium *feq = NULL;
    ts_linear *fl = NULL;
    ts_eigen *fe = NULL;
    int rc = solve_modes(fs, &k, &feq, &fl, &fe, err);
    const ts_propulsion *p0 = &sys->bodies[sys->tow.vehicle].vehicle->propulsion;
    if (rc == TS_OK && p0->type == TS_PROP_POWER) {
        /* The same law: the power that holds this speed alone. */
        double power = feq->vehicles[0].power;
        release(k, feq, fl, fe);
        ts_propulsion *p = &fs->bodies[0].vehicle->propulsion;
        *p = *p0;
        p->power = power;
        rc = solve_modes(fs, &k, &feq, &fl, &fe, err);
    }
    ts_free_vehicle *f = NULL;
    if (rc == TS_OK) {
        f = calloc(1, sizeof *f);
        if (f)
            f->modes = calloc((size_t)fe->nmodes + 1, sizeof *f->modes);
        if (!f || !f->modes)
            rc = ts_fail(err, TS_ENOMEM, "free vehicle: out of memory");
    }
    if (rc != TS_OK) {
        ts_free_vehicle_free(f);
        release(k, feq, fl, fe);
        ts_system_free(fs);
        if (err && strncmp(err->msg, "free vehicle", 12))
            ts_err_prefix(err, "free vehicle: ");
        return rc;
    }
    f->speed = feq->speed;
    f->turn_rate = feq->turn_rate;
    f->thrust = feq->vehicles[0].thrust;
    f->nstate = fl->nstate;
    f->nmodes = fe->nmodes;
    /* Free state i is coupled state map[i]: the vehicle's angles and
     * position (a surface ship's yaw, x and y), their rates, then its
     * controller states: a PI speed controller's integrator first in
     * both, the others the last block of the coupled system's (the
     * towing vehicle is its last body). */
    int nf = fl->nstate, nqf = fl->nq, ncf = nf - 2 * nqf;
    int dof = lin->root_dof, qo = lin->root_qoff - (dof == 3 ? 1 : 3);
    int nc = lin->nstate - 2 * lin->nq;
    int *map = malloc((size_t)nf * sizeof *map);
    if (!map || nqf != dof || ncf > nc) {
        free(map);
        ts_free_vehicle_free(f);
        release(k, feq, fl, fe);
        ts_system_free(fs);
        return ts_fail(err, map ? TS_EINVAL : TS_ENOMEM, "free vehicle: "
                       "its states do not map onto the coupled system's");
    }
    for (int i = 0; i < dof; i++) {
        map[i] = qo + i;
        map[dof + i] = lin->nq + qo + i;
    }
    int speed_pi = p0->type == TS_PROP_SPEED && p0->ki > 0;
    for (int j = 0; j < ncf; j++)
        map[2 * dof + j] = speed_pi && j == 0
                               ? 2 * lin->nq
                               : 2 * lin->nq + nc - ncf + j;
    int n = lin->nstate;
    /* Coincident modes: each the first index of its group. */
    int *fg = malloc(((size_t)fe->nmodes + (size_t)e->nmodes) * sizeof *fg);
    if (!fg) {
        free(map);
        ts_free_vehicle_free(f);
        release(k, feq, fl, fe);
        ts_system_free(fs);
        return ts_fail(err, TS_ENOMEM, "free vehicle: out of memory");
    }
    int *cg = fg + fe->nmodes;
    groups(fe, fg);
    groups(e, cg);
    for (int m = 0; m < fe->nmodes; m++) {
        ts_free_mode *fm = &f->modes[m];
        const ts_mode *md = &fe->modes[m];
        fm->re = md->re;
        fm->im = md->im;
        fm->freq_hz = md->freq_hz;
        fm->damping_ratio = md->damping_ratio;
        fm->coupled = -1;
        fm->neutral = md->neutral >= 0;
        f->nneutral += fm->neutral;
        const double *fr = fe->vec_re + (size_t)m * nf;
        const double *fi = fe->vec_im + (size_t)m * nf;
        double nf2 = 0;
        for (int i = 0; i < nf; i++)
            nf2 += fr[i] * fr[i] + fi[i] * fi[i];
        for (int cm = 0; cm < e->nmodes; cm++) {
            const double *cr = e->vec_re + (size_t)cm * n;
            const double *ci = e->vec_im + (size_t)cm * n;
            double complex dot = 0;
            double nc2 = 0;
            for (int i = 0; i < nf; i++) {
                double complex a = fr[i] + I * fi[i];
                double complex b = cr[map[i]] + I * ci[map[i]];
                dot += conj(a) * b;
                nc2 += creal(b) * creal(b) + cimag(b) * cimag(b);
            }
            double mac = nc2 > 0 && nf2 > 0
                             ? creal(dot * conj(dot)) / (nf2 * nc2)
                             : 0.0;
            if (mac > fm->mac)
                pair(fm, e, cm, mac);
        }
        fm->span = fm->coupled >= 0;
        if (group_size(fg, fe->nmodes, fg[m]) > 1)
            match_span(fe, fl, e, lin, fg, cg, map, nf, m, f->modes);
    }
    free(fg);
    free(map);
    release(k, feq, fl, fe);
    ts_system_free(fs);
    *out = f;
    return TS_OK;
}
