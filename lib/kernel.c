/* kernel.c: f(y, u) of the rigid-link tree (MODEL.md sections 1-4).
 *
 * Algorithm, O(nlinks) per call:
 *  1. Kinematics, tow point to free ends: link directions n, e1, e2 and
 *     direction rates from the angles; node positions r_k = r_p + l n_k and
 *     velocities relative to M.
 *  2. Loads: weight, buoyancy, drag of every link (half to each end),
 *     spheres, bending joints (forces.h); nodal 3x3 mass matrices with the
 *     normal added mass of the adjacent links (a scalar when the system has
 *     no added mass); the frame part afr of each node's acceleration.
 *  3. Tensions. Node k obeys M_k a_k = Q_k - t_k n_k + sum_c t_c n_c and each
 *     link the rigidity condition n_k.(a_k - a_p) = n_k.(afr_k - afr_p)
 *     - l |n_k'|^2. From the free ends up, each node's children are
 *     eliminated: a child c contributes t_c = beta_c - n_c.a_k / D_c, so
 *     node k sees the articulated mass Mh_k = M_k + sum_c n_c n_c^T / D_c and
 *     load Fh_k = Q_k + sum_c beta_c n_c, with D_k = n_k.Mh_k^-1 n_k and
 *     beta_k = (n_k.Mh_k^-1 Fh_k - rhs_k) / D_k. Going down from the tow
 *     point (a_0 prescribed) gives t_k = beta_k - n_k.a_p / D_k and
 *     a_k = Mh_k^-1 (Fh_k - t_k n_k). This is the elimination of the
 *     symmetric positive definite tension system G M^-1 G^T t = b, leaves
 *     first, without fill-in.
 *  4. Angles: r''_k = a_k - afr_k, n'' = (r''_k - r''_p) / l and
 *     t1'' = (e1.n'' + 2 s2 t1' t2') / c2, t2'' = e2.n'' - c2 s2 t1'^2.
 */
#include "towstab/kernel.h"

#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "kernel_impl.h"
#include "vec3.h"

struct ts_kernel {
    const ts_system *sys;
    int nl, nn;
    int nq;            /* generalised coordinates: 2 per rigid link, 3 per
                          elastic link */
    int *off;          /* [nl] offset of link l's coordinates in q */
    ts_frame frame;
    double bend_scale; /* multiplies every EI (continuation), default 1 */

    double *chart;     /* [9 nl] row-major rotation per link */
    char *charted;     /* [nl] 1 when chart is not the identity */

    /* Per link. */
    double *n, *e1, *e2, *nd; /* [3 nl] direction, chart axes, rate */
    double *c2, *s2;          /* [nl] */
    double *sub;              /* [nl] submerged fraction */
    double *t;                /* [nl] tension */
    double *strain;           /* [nl] strain e of an elastic link (0 for a
                                 rigid one): its length is l (1 + e) */
    double *D, *beta;         /* [nl] articulated elimination */
    /* Per node. */
    double *r, *rd;           /* [3 nn] position, velocity relative to M */
    double *Q;                /* [3 nn] external load */
    double *M;                /* [6 nn] nodal mass matrix (sym) */
    double *afr;              /* [3 nn] frame part of acceleration */
    double *Mh;               /* [6 nn] articulated mass */
    double *Fh;               /* [3 nn] articulated load */
    double *g, *w;            /* [3 nn] Mh^-1 Fh, Mh^-1 n */
    double *a;                /* [3 nn] inertial acceleration */
    double *rdd;              /* [3 nn] acceleration relative to M */
};

static void *zalloc(size_t n, size_t size, int *fail)
{
    void *p = calloc(n > 0 ? n : 1, size);
    if (!p)
        *fail = 1;
    return p;
}

ts_kernel *ts_kernel_alloc(const ts_system *sys, ts_err *err)
{
    if (!sys || !sys->links) {
        ts_fail(err, TS_EINVAL, "ts_kernel_alloc: the system is not built");
        return NULL;
    }
    ts_kernel *k = calloc(1, sizeof *k);
    if (!k) {
        ts_fail(err, TS_ENOMEM, "ts_kernel_alloc: out of memory");
        return NULL;
    }
    int nl = sys->nlinks, nn = sys->nnodes, fail = 0;
    size_t snl = (size_t)nl, snn = (size_t)nn;
    k->sys = sys;
    k->nl = nl;
    k->nn = nn;
    k->off = zalloc(snl, sizeof(int), &fail);
    k->chart = zalloc(9 * snl, sizeof(double), &fail);
    k->charted = zalloc(snl, 1, &fail);
    k->n = zalloc(3 * snl, sizeof(double), &fail);
    k->e1 = zalloc(3 * snl, sizeof(double), &fail);
    k->e2 = zalloc(3 * snl, sizeof(double), &fail);
    k->nd = zalloc(3 * snl, sizeof(double), &fail);
    k->c2 = zalloc(snl, sizeof(double), &fail);
    k->s2 = zalloc(snl, sizeof(double), &fail);
    k->sub = zalloc(snl, sizeof(double), &fail);
    k->t = zalloc(snl, sizeof(double), &fail);
    k->strain = zalloc(snl, sizeof(double), &fail);
    k->D = zalloc(snl, sizeof(double), &fail);
    k->beta = zalloc(snl, sizeof(double), &fail);
    k->r = zalloc(3 * snn, sizeof(double), &fail);
    k->rd = zalloc(3 * snn, sizeof(double), &fail);
    k->Q = zalloc(3 * snn, sizeof(double), &fail);
    k->M = zalloc(6 * snn, sizeof(double), &fail);
    k->afr = zalloc(3 * snn, sizeof(double), &fail);
    k->Mh = zalloc(6 * snn, sizeof(double), &fail);
    k->Fh = zalloc(3 * snn, sizeof(double), &fail);
    k->g = zalloc(3 * snn, sizeof(double), &fail);
    k->w = zalloc(3 * snn, sizeof(double), &fail);
    k->a = zalloc(3 * snn, sizeof(double), &fail);
    k->rdd = zalloc(3 * snn, sizeof(double), &fail);
    if (fail) {
        ts_kernel_free(k);
        ts_fail(err, TS_ENOMEM, "ts_kernel_alloc: out of memory for %d links",
                nl);
        return NULL;
    }
    for (int l = 0; l < nl; l++) {
        double *R = k->chart + 9 * l;
        R[0] = R[4] = R[8] = 1.0;
        k->off[l] = k->nq;
        k->nq += sys->links[l].elastic ? 3 : 2;
    }
    k->bend_scale = 1.0;
    k->frame.speed = sys->tow.speed;
    k->frame.turn_rate = sys->tow.turn_rate;
    memcpy(k->frame.current, sys->env.current, sizeof k->frame.current);
    return k;
}

void ts_kernel_free(ts_kernel *k)
{
    if (!k)
        return;
    free(k->off);
    free(k->chart);
    free(k->charted);
    free(k->n);
    free(k->e1);
    free(k->e2);
    free(k->nd);
    free(k->c2);
    free(k->s2);
    free(k->sub);
    free(k->t);
    free(k->strain);
    free(k->D);
    free(k->beta);
    free(k->r);
    free(k->rd);
    free(k->Q);
    free(k->M);
    free(k->afr);
    free(k->Mh);
    free(k->Fh);
    free(k->g);
    free(k->w);
    free(k->a);
    free(k->rdd);
    free(k);
}

ts_kernel *ts_kernel_clone(const ts_kernel *k, ts_err *err)
{
    ts_kernel *c = ts_kernel_alloc(k->sys, err);
    if (!c)
        return NULL;
    c->frame = k->frame;
    c->bend_scale = k->bend_scale;
    memcpy(c->chart, k->chart, 9 * (size_t)k->nl * sizeof(double));
    memcpy(c->charted, k->charted, (size_t)k->nl);
    return c;
}

const ts_system *ts_kernel_system(const ts_kernel *k) { return k->sys; }
int ts_kernel_nq(const ts_kernel *k) { return k->nq; }
int ts_kernel_nstate(const ts_kernel *k) { return 2 * k->nq; }
int ts_kernel_link_offset(const ts_kernel *k, int link) { return k->off[link]; }
int ts_kernel_ninput(const ts_kernel *k)
{
    (void)k;
    return TS_NINPUT;
}

void ts_kernel_set_frame(ts_kernel *k, const ts_frame *f) { k->frame = *f; }

void ts_kernel_get_frame(const ts_kernel *k, ts_frame *f) { *f = k->frame; }

void ts_kernel_set_bending_scale(ts_kernel *k, double scale)
{
    k->bend_scale = scale;
}

/* Direction and chart axes of a link from its angles. */
static inline void link_axes(const ts_kernel *k, int l, double t1, double t2,
                             double n[3], double e1[3], double e2[3],
                             double *c2out, double *s2out)
{
    double c1 = cos(t1), s1 = sin(t1), c2 = cos(t2), s2 = sin(t2);
    double nh[3] = {-c1 * c2, -s2, s1 * c2};
    double e1h[3] = {s1, 0.0, c1};
    double e2h[3] = {c1 * s2, -c2, -s1 * s2};
    if (k->charted[l]) {
        const double *R = k->chart + 9 * l;
        mat3_mul(R, nh, n);
        mat3_mul(R, e1h, e1);
        mat3_mul(R, e2h, e2);
    } else {
        v3_copy(nh, n);
        v3_copy(e1h, e1);
        v3_copy(e2h, e2);
    }
    *c2out = c2;
    *s2out = s2;
}

void ts_kernel_direction(const ts_kernel *k, int link, double t1, double t2,
                         double n[3])
{
    double e1[3], e2[3], c2, s2;
    link_axes(k, link, t1, t2, n, e1, e2, &c2, &s2);
}

/* 2. The link-local assembly shared by f(y, u) and the node residual:
 * from node positions k->r and velocities k->rd (relative to M), link
 * directions k->n and strains k->strain, the external load Q, the 3x3
 * mass matrix M and the frame part afr of the acceleration of every node,
 * and each link's submerged fraction. Each link adds to its two end nodes
 * (and a bending joint to three), each body to its node: O(nlinks). */
static void assemble(ts_kernel *k)
{
    const ts_system *sys = k->sys;
    const ts_link *links = sys->links;
    const ts_node *nodes = sys->nodes;
    const int nl = k->nl, nn = k->nn;
    const double rho = sys->env.water_density, g = sys->env.gravity;
    const int added = sys->has_added_mass;
    for (int i = 0; i < nn; i++) {
        double *Q = k->Q + 3 * i, *M = k->M + 6 * i;
        v3_set(Q, 0, 0, 0);
        M[0] = M[1] = M[2] = nodes[i].mass;
        M[3] = M[4] = M[5] = 0.0;
        tsi_frame_accel(&k->frame, k->r + 3 * i, k->rd + 3 * i,
                        k->afr + 3 * i);
        int b = nodes[i].body;
        if (b >= 0) {
            /* A cylinder's axis lies along the link that ends at it. */
            const double *axis = k->n + 3 * nodes[i].link;
            double w[3], F[3], frac;
            tsi_rel_velocity(&k->frame, k->r + 3 * i, k->rd + 3 * i, w);
            tsi_body_load(&sys->bodies[b], rho, g, k->r[3 * i + 2], w, axis,
                          F, &frac);
            v3_axpy(1.0, F, Q);
            if (added)
                tsi_body_added_mass(&sys->bodies[b], rho, frac, axis, M);
        }
    }
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const double *n = k->n + 3 * l;
        const double *rp = k->r + 3 * L->upper, *rk = k->r + 3 * L->lower;
        double rm[3], vm[3], w[3], F[3];
        for (int j = 0; j < 3; j++) {
            rm[j] = 0.5 * (rp[j] + rk[j]);
            vm[j] = 0.5 * (k->rd[3 * L->upper + j] + k->rd[3 * L->lower + j]);
        }
        tsi_rel_velocity(&k->frame, rm, vm, w);
        tsi_link_load(L, rho, g, n, rp[2], rk[2], w, F, &k->sub[l]);
        v3_axpy(0.5, F, k->Q + 3 * L->upper);
        v3_axpy(0.5, F, k->Q + 3 * L->lower);
        if (added && L->can > 0 && k->sub[l] > 0) {
            double A = L->can * rho * M_PI * 0.25 * L->diameter *
                       L->diameter * L->length * k->sub[l];
            sym3_add_normal(k->M + 6 * L->upper, 0.5 * A, n);
            sym3_add_normal(k->M + 6 * L->lower, 0.5 * A, n);
        }
        if (L->ei > 0) {
            /* U = 1/2 (EI / lbar) alpha^2 with lbar from the unstretched
             * lengths (a spring constant of the cable), so -dU/dr divides
             * by the current lengths l (1 + e): tsi_bending takes the
             * current lengths and EI scaled by their mean over lbar. */
            const ts_link *B = &links[L->next];
            double la = L->length * (1.0 + k->strain[l]);
            double lb = B->length * (1.0 + k->strain[L->next]);
            double ei = L->ei * k->bend_scale * (la + lb) /
                        (L->length + B->length);
            double Fi[3], Fj[3], Fk[3];
            tsi_bending(ei, la, lb, n, k->n + 3 * L->next, Fi, Fj, Fk);
            v3_axpy(1.0, Fi, k->Q + 3 * L->upper);
            v3_axpy(1.0, Fj, k->Q + 3 * L->lower);
            v3_axpy(1.0, Fk, k->Q + 3 * B->lower);
        }
    }
}

int ts_kernel_eval(ts_kernel *k, const double y[], const double u[],
                   double dydt[])
{
    const ts_system *sys = k->sys;
    const ts_link *links = sys->links;
    const int nl = k->nl, nn = k->nn, nq = k->nq;
    const double *qd = y + nq;
    static const double zero[TS_NINPUT] = {0};
    if (!u)
        u = zero;

    /* 1. Kinematics. */
    for (int j = 0; j < 3; j++) {
        k->r[j] = sys->tow.point[j] + u[j];
        k->rd[j] = u[3 + j];
    }
    int chart_bad = 0, slack_bad = 0;
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const int o = k->off[l];
        double *n = k->n + 3 * l, *nd = k->nd + 3 * l;
        const double *rp = k->r + 3 * L->upper, *rdp = k->rd + 3 * L->upper;
        double *rk = k->r + 3 * L->lower, *rdk = k->rd + 3 * L->lower;
        double *e1 = k->e1 + 3 * l, *e2 = k->e2 + 3 * l;
        double c2, s2;
        link_axes(k, l, y[o], y[o + 1], n, e1, e2, &c2, &s2);
        k->c2[l] = c2;
        k->s2[l] = s2;
        if (!(fabs(c2) >= TS_CHART_MIN))
            chart_bad = 1;
        double a1 = c2 * qd[o], a2 = qd[o + 1];
        for (int j = 0; j < 3; j++)
            nd[j] = a1 * e1[j] + a2 * e2[j];
        /* An elastic link's third coordinate is its strain e: length
         * l (1 + e), tension EA e + Cv l e', never compressive. */
        double len = L->length, lrate = 0.0;
        if (L->elastic) {
            double e = y[o + 2], ed = qd[o + 2];
            k->strain[l] = e;
            len = L->length * (1.0 + e);
            lrate = L->length * ed;
            if (!(len > 0))
                slack_bad = 1;
            double T = L->ea * e + L->damping * lrate;
            k->t[l] = T > 0 ? T : 0.0;
        }
        for (int j = 0; j < 3; j++) {
            rk[j] = rp[j] + len * n[j];
            rdk[j] = rdp[j] + len * nd[j] + lrate * n[j];
        }
    }
    if (slack_bad) {
        for (int i = 0; i < 2 * nq; i++)
            dydt[i] = NAN;
        return TS_ESINGULAR;
    }
    if (chart_bad) {
        for (int i = 0; i < 2 * nq; i++)
            dydt[i] = NAN;
        return TS_CHART;
    }

    /* 2. Loads, mass matrices and frame accelerations. */
    assemble(k);

    /* 3a. Free ends to tow point: articulated mass and load. An elastic
     * link passes no inertia up: its known tension pulls both ends. */
    for (int i = 1; i < nn; i++) {
        memcpy(k->Mh + 6 * i, k->M + 6 * i, 6 * sizeof(double));
        v3_copy(k->Q + 3 * i, k->Fh + 3 * i);
    }
    if (sys->has_elastic)
        for (int l = 0; l < nl; l++)
            if (links[l].elastic) {
                if (links[l].upper > 0)
                    v3_axpy(k->t[l], k->n + 3 * l, k->Fh + 3 * links[l].upper);
                v3_axpy(-k->t[l], k->n + 3 * l, k->Fh + 3 * links[l].lower);
            }
    for (int l = nl - 1; l >= 0; l--) {
        const ts_link *L = &links[l];
        int i = L->lower, p = L->upper;
        const double *n = k->n + 3 * l, *nd = k->nd + 3 * l;
        double *Mh = k->Mh + 6 * i, *gi = k->g + 3 * i, *wi = k->w + 3 * i;
        double Lc[6];
        if (sym3_chol(Mh, Lc) != 0) {
            for (int j = 0; j < 2 * nq; j++)
                dydt[j] = NAN;
            return TS_ESINGULAR;
        }
        v3_copy(k->Fh + 3 * i, gi);
        sym3_chol_solve(Lc, gi);
        if (L->elastic)
            continue;
        v3_copy(n, wi);
        sym3_chol_solve(Lc, wi);
        double D = v3_dot(n, wi);
        double da[3] = {k->afr[3 * i] - k->afr[3 * p],
                        k->afr[3 * i + 1] - k->afr[3 * p + 1],
                        k->afr[3 * i + 2] - k->afr[3 * p + 2]};
        double rhs = v3_dot(n, da) - L->length * v3_dot(nd, nd);
        double beta = (v3_dot(n, gi) - rhs) / D;
        k->D[l] = D;
        k->beta[l] = beta;
        if (p > 0) {
            sym3_add_outer(k->Mh + 6 * p, 1.0 / D, n);
            v3_axpy(beta, n, k->Fh + 3 * p);
        }
    }

    /* 3b. Tow point to free ends: tensions and accelerations. */
    for (int j = 0; j < 3; j++)
        k->a[j] = k->afr[j] + u[6 + j];
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        int i = L->lower, p = L->upper;
        const double *n = k->n + 3 * l;
        if (L->elastic) {
            v3_copy(k->g + 3 * i, k->a + 3 * i);
            continue;
        }
        double t = k->beta[l] - v3_dot(n, k->a + 3 * p) / k->D[l];
        k->t[l] = t;
        double *ai = k->a + 3 * i;
        for (int j = 0; j < 3; j++)
            ai[j] = k->g[3 * i + j] - t * k->w[3 * i + j];
    }

    /* 4. Relative accelerations and angle accelerations. */
    for (int j = 0; j < 3; j++)
        k->rdd[j] = u[6 + j];
    for (int i = 1; i < nn; i++)
        for (int j = 0; j < 3; j++)
            k->rdd[3 * i + j] = k->a[3 * i + j] - k->afr[3 * i + j];
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const double *ri = k->rdd + 3 * L->lower, *rp = k->rdd + 3 * L->upper;
        const int o = k->off[l];
        const double *e1 = k->e1 + 3 * l, *e2 = k->e2 + 3 * l;
        double dd2[3] = {ri[0] - rp[0], ri[1] - rp[1], ri[2] - rp[2]};
        double t1d = qd[o], t2d = qd[o + 1];
        double c2 = k->c2[l], s2 = k->s2[l];
        /* d'' = len n'' + 2 len' n' + len'' n with n.n' = 0 and
         * n.n'' = -|n'|^2: the e1, e2 parts of n'' and the strain's. */
        double len = L->length, a1 = v3_dot(e1, dd2), a2 = v3_dot(e2, dd2);
        if (L->elastic) {
            double e = y[o + 2], ed = qd[o + 2];
            len = L->length * (1.0 + e);
            double lrate2 = 2.0 * L->length * ed;
            a1 -= lrate2 * c2 * t1d;
            a2 -= lrate2 * t2d;
            const double *nd = k->nd + 3 * l;
            dydt[o + 2] = ed;
            dydt[nq + o + 2] = v3_dot(k->n + 3 * l, dd2) / L->length +
                               (1.0 + e) * v3_dot(nd, nd);
        }
        a1 /= len;
        a2 /= len;
        dydt[o] = t1d;
        dydt[o + 1] = t2d;
        dydt[nq + o] = (a1 + 2.0 * s2 * t1d * t2d) / c2;
        dydt[nq + o + 1] = a2 - c2 * s2 * t1d * t1d;
    }
    return TS_OK;
}

int ts_kernel_rhs(double t, const double y[], const double u[], double dydt[],
                  void *params)
{
    (void)t;
    return ts_kernel_eval((ts_kernel *)params, y, u, dydt);
}

int tsi_kernel_residual(ts_kernel *k, const double r[], const double v[],
                        const double a[], const double t[], double R[])
{
    const ts_system *sys = k->sys;
    const ts_link *links = sys->links;
    const int nl = k->nl, nn = k->nn;
    memcpy(k->r, r, 3 * (size_t)nn * sizeof(double));
    memcpy(k->rd, v, 3 * (size_t)nn * sizeof(double));
    /* Directions and strains from the positions: n = d / |d|, the strain
     * of an elastic link |d| / l - 1 (it sets only the bending lengths
     * here: the tensions are given). */
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const double *rp = r + 3 * L->upper, *rk = r + 3 * L->lower;
        double d[3] = {rk[0] - rp[0], rk[1] - rp[1], rk[2] - rp[2]};
        double len = v3_norm(d);
        if (!(len > 0))
            return TS_ESINGULAR;
        for (int j = 0; j < 3; j++)
            k->n[3 * l + j] = d[j] / len;
        k->strain[l] = L->elastic ? len / L->length - 1.0 : 0.0;
        k->t[l] = t[l];
    }
    assemble(k);
    memset(R, 0, 3 * sizeof(double));
    for (int i = 1; i < nn; i++) {
        double ia[3] = {a[3 * i] + k->afr[3 * i], a[3 * i + 1] +
                        k->afr[3 * i + 1], a[3 * i + 2] + k->afr[3 * i + 2]};
        sym3_mul(k->M + 6 * i, ia, R + 3 * i);
        v3_axpy(-1.0, k->Q + 3 * i, R + 3 * i);
    }
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        v3_axpy(t[l], k->n + 3 * l, R + 3 * L->lower);
        if (L->upper > 0)
            v3_axpy(-t[l], k->n + 3 * l, R + 3 * L->upper);
    }
    return TS_OK;
}

const double *tsi_kernel_mass(const ts_kernel *k) { return k->M; }

const double *ts_kernel_positions(const ts_kernel *k) { return k->r; }
const double *ts_kernel_velocities(const ts_kernel *k) { return k->rd; }
const double *ts_kernel_tensions(const ts_kernel *k) { return k->t; }
const double *ts_kernel_directions(const ts_kernel *k) { return k->n; }
const double *ts_kernel_rel_accelerations(const ts_kernel *k)
{
    return k->rdd;
}
const double *ts_kernel_loads(const ts_kernel *k) { return k->Q; }

double ts_kernel_tow_force(const ts_kernel *k, double F[3])
{
    const ts_system *sys = k->sys;
    double M0a[3];
    sym3_mul(k->M, k->a, M0a);
    for (int j = 0; j < 3; j++)
        F[j] = k->Q[j] - M0a[j];
    const ts_node *n0 = &sys->nodes[0];
    for (int c = n0->child_begin; c < n0->child_end; c++) {
        int l = sys->child_links[c];
        v3_axpy(k->t[l], k->n + 3 * l, F);
    }
    return v3_norm(F);
}

double ts_kernel_unbalanced(const ts_kernel *k, double *scale)
{
    double worst = 0.0, big = 0.0;
    for (int i = 1; i < k->nn; i++) {
        double f[3];
        sym3_mul(k->M + 6 * i, k->rdd + 3 * i, f);
        double m = v3_norm(f);
        if (!(m <= worst))
            worst = m; /* NaN propagates */
        double q = v3_norm(k->Q + 3 * i);
        if (q > big)
            big = q;
    }
    for (int l = 0; l < k->nl; l++)
        if (fabs(k->t[l]) > big)
            big = fabs(k->t[l]);
    if (scale)
        *scale = big;
    return worst;
}

double ts_kernel_kinetic_energy(const ts_kernel *k)
{
    /* Inertial velocity v = V e_x + Omega e_z x r + r'; the fluid's
     * added mass is counted with the nodal mass matrix. */
    double T = 0.0;
    for (int i = 1; i < k->nn; i++) {
        const double *r = k->r + 3 * i, *rd = k->rd + 3 * i;
        double v[3] = {k->frame.speed - k->frame.turn_rate * r[1] + rd[0],
                       k->frame.turn_rate * r[0] + rd[1], rd[2]};
        double Mv[3];
        sym3_mul(k->M + 6 * i, v, Mv);
        T += 0.5 * v3_dot(v, Mv);
    }
    return T;
}

double ts_kernel_potential_energy(const ts_kernel *k)
{
    const ts_system *sys = k->sys;
    double U = 0.0, g = sys->env.gravity;
    for (int i = 1; i < k->nn; i++)
        U -= sys->nodes[i].mass * g * k->r[3 * i + 2];
    for (int l = 0; l < k->nl; l++) {
        const ts_link *L = &sys->links[l];
        /* Strain energy 1/2 EA l e^2 while taut (e > 0): the potential
         * of the elastic part EA e of the tension, whatever the damping. */
        if (L->elastic && k->strain[l] > 0) {
            double e = k->strain[l];
            U += 0.5 * L->ea * L->length * e * e;
        }
        if (L->ei > 0)
            U += tsi_bending_energy(L->ei * k->bend_scale, L->length,
                                    sys->links[L->next].length, k->n + 3 * l,
                                    k->n + 3 * L->next);
    }
    return U;
}

void ts_direction_angles(const double n[3], double *theta1, double *theta2)
{
    double ny = n[1] > 1 ? 1 : (n[1] < -1 ? -1 : n[1]);
    /* + 0.0 turns a negative zero into zero for display. */
    *theta2 = asin(-ny) + 0.0;
    *theta1 = atan2(n[2], -n[0]) + 0.0;
}

/* Angles and rates of link l in its chart for direction n and rate nd. */
static void link_set(ts_kernel *k, int l, const double n[3],
                     const double nd[3], double *t1, double *t2, double *t1d,
                     double *t2d)
{
    double nh[3];
    if (k->charted[l])
        mat3_tmul(k->chart + 9 * l, n, nh);
    else
        v3_copy(n, nh);
    ts_direction_angles(nh, t1, t2);
    if (t1d) {
        double nn_[3], e1[3], e2[3], c2, s2;
        link_axes(k, l, *t1, *t2, nn_, e1, e2, &c2, &s2);
        *t1d = nd ? v3_dot(e1, nd) / c2 : 0.0;
        *t2d = nd ? v3_dot(e2, nd) : 0.0;
    }
}

/* Coordinates of link l for unit direction n, direction rate nd (NULL:
 * zero), strain e and strain rate ed (elastic links; ignored for rigid
 * ones). A link whose |cos theta2| would fall below threshold is first
 * moved to a chart centred on n. Returns 1 when re-charted. */
static int set_one_link(ts_kernel *k, int l, const double n[3],
                        const double nd[3], double e, double ed,
                        double threshold, double y[])
{
    const int o = k->off[l], nq = k->nq;
    if (k->sys->links[l].elastic) {
        y[o + 2] = e;
        y[nq + o + 2] = ed;
    }
    double t1, t2, t1d, t2d;
    int moved = 0;
    link_set(k, l, n, nd, &t1, &t2, &t1d, &t2d);
    if (fabs(cos(t2)) < threshold) {
        tsi_chart_centred(n, k->chart + 9 * l);
        k->charted[l] = 1;
        link_set(k, l, n, nd, &t1, &t2, &t1d, &t2d);
        moved = 1;
    }
    y[o] = t1;
    y[o + 1] = t2;
    y[nq + o] = t1d;
    y[nq + o + 1] = t2d;
    return moved;
}

int ts_kernel_set_shape(ts_kernel *k, const double n[], const double strain[],
                        const double ndot[], const double strain_rate[],
                        double threshold, double y[])
{
    int moved = 0;
    for (int l = 0; l < k->nl; l++)
        moved += set_one_link(k, l, n + 3 * l, ndot ? ndot + 3 * l : NULL,
                              strain ? strain[l] : 0.0,
                              strain_rate ? strain_rate[l] : 0.0, threshold,
                              y);
    return moved;
}

int tsi_kernel_set_link(ts_kernel *k, int l, const double d[3],
                        const double ddot[3], double threshold, double y[])
{
    const ts_link *L = &k->sys->links[l];
    double len = v3_norm(d), n[3], nd[3], along = 0.0;
    for (int j = 0; j < 3; j++)
        n[j] = d[j] / len;
    if (ddot) {
        along = v3_dot(n, ddot);
        for (int j = 0; j < 3; j++)
            nd[j] = (ddot[j] - along * n[j]) / len;
    }
    return set_one_link(k, l, n, ddot ? nd : NULL, len / L->length - 1.0,
                        along / L->length, threshold, y);
}

int ts_kernel_set_links(ts_kernel *k, const double d[], const double ddot[],
                        double threshold, double y[])
{
    int moved = 0;
    for (int l = 0; l < k->nl; l++)
        moved += tsi_kernel_set_link(k, l, d + 3 * l,
                                     ddot ? ddot + 3 * l : NULL, threshold, y);
    return moved;
}

int ts_kernel_set_directions(ts_kernel *k, const double n[],
                             const double ndot[], double threshold,
                             double y[])
{
    return ts_kernel_set_shape(k, n, NULL, ndot, NULL, threshold, y);
}

/* Direction and direction rate of rigid link l for state y. */
static void link_dir_rate(const ts_kernel *k, int l, const double y[],
                          double n[3], double nd[3])
{
    const int o = k->off[l], nq = k->nq;
    double e1[3], e2[3], c2, s2;
    link_axes(k, l, y[o], y[o + 1], n, e1, e2, &c2, &s2);
    for (int j = 0; j < 3; j++)
        nd[j] = c2 * y[nq + o] * e1[j] + y[nq + o + 1] * e2[j];
}

int ts_kernel_rechart(ts_kernel *k, double y[], double threshold)
{
    int nq = k->nq, moved = 0;
    for (int l = 0; l < k->nl; l++) {
        const int o = k->off[l];
        if (fabs(cos(y[o + 1])) >= threshold)
            continue;
        double n[3], nd[3];
        link_dir_rate(k, l, y, n, nd);
        tsi_chart_centred(n, k->chart + 9 * l);
        k->charted[l] = 1;
        link_set(k, l, n, nd, &y[o], &y[o + 1], &y[nq + o], &y[nq + o + 1]);
        moved++;
    }
    return moved;
}

int ts_kernel_reset_charts(ts_kernel *k, double y[], double threshold)
{
    int nq = k->nq, left = 0;
    for (int l = 0; l < k->nl; l++) {
        if (!k->charted[l])
            continue;
        const int o = k->off[l];
        double n[3], nd[3], t1, t2;
        link_dir_rate(k, l, y, n, nd);
        ts_direction_angles(n, &t1, &t2);
        if (fabs(cos(t2)) < threshold) {
            left++;
            continue;
        }
        k->charted[l] = 0;
        link_set(k, l, n, nd, &y[o], &y[o + 1], &y[nq + o], &y[nq + o + 1]);
    }
    return left;
}
