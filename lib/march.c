/* march.c: marching and shooting for the steady rigid-link tree (march.h).
 *
 * Node i (the lower end of link l) is in static balance in the steadily
 * moving frame:  t_l n_l = K_i + F_l(n_l)/2 - A_l(n_l)/2 (I - n n^T) afr_i,
 * with K_i everything already known once its children are done (their
 * tensions and half loads, the body's load, minus mass times the frame
 * acceleration afr_i = (-W^2 x, W V - W^2 y, 0)) and F_l the load of link l
 * itself, which depends on its direction through drag, the submerged
 * fraction and the position of its upper end r_i - l n_l. So n_l is the
 * direction of the right-hand side H(n): two equations H.e1 = H.e2 = 0 in
 * two angles of a chart centred on a first guess, solved with GSL's hybrid
 * solver. Links are visited in decreasing index, which puts every child
 * before its parent (system.h).
 */
#include "march.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multiroots.h>
#include <gsl/gsl_vector.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "vec3.h"

/* Local root: |H_perp| below this fraction of |H| (rounding is ~1e-16). */
#define LOCAL_RTOL 1e-13
#define LOCAL_MAXIT 60

struct tsi_march {
    const ts_system *sys;
    int nl, nn, nleaf;
    int *leaf_node;     /* [nleaf] node of each free end */
    int *res_link;      /* [nleaf] link whose upper-end mismatch is residual j */
    char *member;       /* [nleaf * nleaf]: leaf b lies below residual a */
    int *res_of_link;   /* [nl] residual index or -1 */

    double *n, *t;      /* [3 nl], [nl] */
    int have_n;         /* n holds the last solution (warm start) */
    double *r;          /* [3 nn] marched positions */
    char *rset;         /* [nn] position known */
    double *K;          /* [3 nn] known loads accumulated from children */
    double *Ma;         /* [6 nn] added mass from child links */
    double mismatch;

    gsl_multiroot_fsolver *local;
    gsl_vector *lx;
};

tsi_march *tsi_march_alloc(const ts_system *sys, ts_err *err)
{
    tsi_march *m = calloc(1, sizeof *m);
    if (!m)
        goto nomem;
    m->sys = sys;
    m->nl = sys->nlinks;
    m->nn = sys->nnodes;
    for (int i = 1; i < m->nn; i++)
        if (sys->nodes[i].child_begin == sys->nodes[i].child_end)
            m->nleaf++;
    size_t nl = (size_t)m->nl, nn = (size_t)m->nn, nf = (size_t)m->nleaf;
    m->leaf_node = calloc(nf, sizeof(int));
    m->res_link = calloc(nf, sizeof(int));
    m->member = calloc(nf * nf, 1);
    m->res_of_link = malloc(nl * sizeof(int));
    m->n = calloc(3 * nl, sizeof(double));
    m->t = calloc(nl, sizeof(double));
    m->r = calloc(3 * nn, sizeof(double));
    m->rset = calloc(nn, 1);
    m->K = calloc(3 * nn, sizeof(double));
    m->Ma = calloc(6 * nn, sizeof(double));
    m->local = gsl_multiroot_fsolver_alloc(gsl_multiroot_fsolver_hybrids, 2);
    m->lx = gsl_vector_alloc(2);
    if (!m->leaf_node || !m->res_link || !m->member || !m->res_of_link ||
        !m->n || !m->t || !m->r || !m->rset || !m->K || !m->Ma ||
        !m->local || !m->lx)
        goto nomem;

    /* Residuals: every child of the tow point, and every child of a branch
     * node but the one visited first (the highest link index), which fixes
     * the branch node's position. */
    int nres = 0;
    for (int l = 0; l < m->nl; l++)
        m->res_of_link[l] = -1;
    for (int i = 0; i < m->nn; i++) {
        const ts_node *nd = &sys->nodes[i];
        int last = nd->child_end - 1;
        for (int c = nd->child_begin; c < nd->child_end; c++)
            if (i == 0 || c != last) {
                m->res_link[nres] = sys->child_links[c];
                m->res_of_link[sys->child_links[c]] = nres++;
            }
    }
    int f = 0;
    for (int i = 1; i < m->nn; i++)
        if (sys->nodes[i].child_begin == sys->nodes[i].child_end) {
            m->leaf_node[f] = i;
            /* Walk up to the tow point, marking the residuals passed. */
            for (int l = i - 1; l >= 0; l = sys->links[l].parent)
                if (m->res_of_link[l] >= 0)
                    m->member[(size_t)m->res_of_link[l] * nf + f] = 1;
            f++;
        }
    (void)nres;
    return m;
nomem:
    tsi_march_free(m);
    ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
    return NULL;
}

void tsi_march_free(tsi_march *m)
{
    if (!m)
        return;
    free(m->leaf_node);
    free(m->res_link);
    free(m->member);
    free(m->res_of_link);
    free(m->n);
    free(m->t);
    free(m->r);
    free(m->rset);
    free(m->K);
    free(m->Ma);
    if (m->local)
        gsl_multiroot_fsolver_free(m->local);
    if (m->lx)
        gsl_vector_free(m->lx);
    free(m);
}

int tsi_march_nunknown(const tsi_march *m) { return 3 * m->nleaf; }
const double *tsi_march_directions(const tsi_march *m) { return m->n; }
const double *tsi_march_tensions(const tsi_march *m) { return m->t; }
double tsi_march_mismatch(const tsi_march *m) { return m->mismatch; }

/* The balance of one node, for the local root. */
typedef struct link_problem {
    const ts_system *sys;
    const ts_link *L;
    const ts_frame *f;
    const double *ri;   /* lower node position */
    double K[3];        /* known part of the right-hand side */
    double afr[3];      /* frame acceleration of the lower node */
    double R[9];        /* local chart */
} link_problem;

/* H(n), the force the link must carry, for direction n. */
static void link_rhs(const link_problem *P, const double n[3], double H[3],
                     double F[3])
{
    const ts_link *L = P->L;
    double rp[3], rm[3], w[3], zero[3] = {0, 0, 0}, s;
    for (int j = 0; j < 3; j++) {
        rp[j] = P->ri[j] - L->length * n[j];
        rm[j] = 0.5 * (rp[j] + P->ri[j]);
    }
    tsi_rel_velocity(P->f, rm, zero, w);
    tsi_link_load(L, P->sys->env.water_density, P->sys->env.gravity, n,
                  rp[2], P->ri[2], w, F, &s);
    for (int j = 0; j < 3; j++)
        H[j] = P->K[j] + 0.5 * F[j];
    if (P->sys->has_added_mass && L->can > 0 && s > 0) {
        double rho = P->sys->env.water_density;
        double A = L->can * rho * M_PI * 0.25 * L->diameter * L->diameter *
                   L->length * s;
        double an = v3_dot(P->afr, n);
        for (int j = 0; j < 3; j++)
            H[j] -= 0.5 * A * (P->afr[j] - an * n[j]);
    }
}

static void chart_dir(const double R[9], double a, double b, double n[3],
                      double e1[3], double e2[3])
{
    double c1 = cos(a), s1 = sin(a), c2 = cos(b), s2 = sin(b);
    double nh[3] = {-c1 * c2, -s2, s1 * c2};
    double e1h[3] = {s1, 0.0, c1};
    double e2h[3] = {c1 * s2, -c2, -s1 * s2};
    mat3_mul(R, nh, n);
    mat3_mul(R, e1h, e1);
    mat3_mul(R, e2h, e2);
}

static int local_f(const gsl_vector *x, void *params, gsl_vector *out)
{
    const link_problem *P = params;
    double n[3], e1[3], e2[3], H[3], F[3];
    chart_dir(P->R, gsl_vector_get(x, 0), gsl_vector_get(x, 1), n, e1, e2);
    link_rhs(P, n, H, F);
    gsl_vector_set(out, 0, v3_dot(H, e1));
    gsl_vector_set(out, 1, v3_dot(H, e2));
    return GSL_SUCCESS;
}

/* Direction of link l: n_l parallel to H(n_l). `guess` is a unit vector. */
static int solve_link(tsi_march *m, link_problem *P, int l,
                      const double guess[3], ts_err *err)
{
    double H[3], F[3], n[3];
    v3_copy(guess, n);
    /* Two fixed-point sweeps put the chart centre near the root. */
    for (int it = 0; it < 2; it++) {
        link_rhs(P, n, H, F);
        double h = v3_norm(H);
        if (!(h > 0))
            break;
        for (int j = 0; j < 3; j++)
            n[j] = H[j] / h;
    }
    link_rhs(P, n, H, F);
    double hn = v3_norm(H);
    if (!(hn > 0) || !isfinite(hn)) {
        const ts_link *L = P->L;
        return ts_fail(err, TS_ESINGULAR,
                       "equilibrium: cables[%d] '%s' link %d carries no load "
                       "(|force| = %g N), so its direction is undefined: a "
                       "neutrally buoyant free end without flow has no "
                       "steady shape",
                       L->cable, m->sys->cables[L->cable].name, L->index, hn);
    }
    tsi_chart_centred(n, P->R);
    gsl_multiroot_function fn = {local_f, 2, P};
    gsl_vector_set(m->lx, 0, 0.0);
    gsl_vector_set(m->lx, 1, 0.0);
    gsl_multiroot_fsolver_set(m->local, &fn, m->lx);
    double tol = LOCAL_RTOL * hn;
    int status = gsl_multiroot_test_residual(m->local->f, tol);
    for (int it = 0; status == GSL_CONTINUE && it < LOCAL_MAXIT; it++) {
        if (gsl_multiroot_fsolver_iterate(m->local))
            break;
        status = gsl_multiroot_test_residual(m->local->f, tol);
    }
    double e1[3], e2[3];
    chart_dir(P->R, gsl_vector_get(m->local->x, 0),
              gsl_vector_get(m->local->x, 1), n, e1, e2);
    link_rhs(P, n, H, F);
    double perp = hypot(v3_dot(H, e1), v3_dot(H, e2));
    double hnorm = v3_norm(H);
    if (!(perp <= 1e3 * LOCAL_RTOL * hnorm)) {
        const ts_link *L = P->L;
        return ts_fail(err, TS_ECONV,
                       "equilibrium: the direction of cables[%d] '%s' link "
                       "%d did not converge (unbalanced %.3g N of %.3g N)",
                       L->cable, m->sys->cables[L->cable].name, L->index,
                       perp, hnorm);
    }
    v3_copy(n, m->n + 3 * l);
    m->t[l] = v3_dot(H, n);
    /* Pass the link's half load, tension and added mass up. */
    const ts_link *L = P->L;
    int p = L->upper;
    double *Kp = m->K + 3 * p;
    for (int j = 0; j < 3; j++)
        Kp[j] += 0.5 * F[j] + m->t[l] * n[j];
    if (m->sys->has_added_mass && L->can > 0) {
        double rp[3];
        for (int j = 0; j < 3; j++)
            rp[j] = P->ri[j] - L->length * n[j];
        double s = tsi_link_submerged(rp[2], P->ri[2]);
        double rho = m->sys->env.water_density;
        double A = L->can * rho * M_PI * 0.25 * L->diameter * L->diameter *
                   L->length * s;
        sym3_add_normal(m->Ma + 6 * p, 0.5 * A, n);
    }
    return TS_OK;
}

int tsi_march_eval(tsi_march *m, const ts_frame *f, const double x[],
                   double e[], ts_err *err)
{
    const ts_system *sys = m->sys;
    const double rho = sys->env.water_density, g = sys->env.gravity;
    memset(m->rset, 0, (size_t)m->nn);
    memset(m->K, 0, 3 * (size_t)m->nn * sizeof(double));
    memset(m->Ma, 0, 6 * (size_t)m->nn * sizeof(double));
    for (int j = 0; j < m->nleaf; j++) {
        v3_copy(x + 3 * j, m->r + 3 * m->leaf_node[j]);
        m->rset[m->leaf_node[j]] = 1;
    }
    link_problem P;
    P.sys = sys;
    P.f = f;
    double big = 0.0;
    for (int l = m->nl - 1; l >= 0; l--) {
        const ts_link *L = &sys->links[l];
        int i = L->lower;
        const double *ri = m->r + 3 * i;
        const ts_node *nd = &sys->nodes[i];
        double zero[3] = {0, 0, 0};
        P.L = L;
        P.ri = ri;
        tsi_frame_accel(f, ri, zero, P.afr);
        double mass = nd->mass, Fb[3] = {0, 0, 0};
        if (nd->body >= 0) {
            double w[3], frac;
            const ts_body *bd = &sys->bodies[nd->body];
            tsi_rel_velocity(f, ri, zero, w);
            tsi_body_load(bd, rho, g, ri[2], w, Fb, &frac);
            if (sys->has_added_mass && bd->type == TS_BODY_SPHERE)
                mass += frac * bd->ca * rho * M_PI * bd->diameter *
                        bd->diameter * bd->diameter / 6.0;
        }
        double Maf[3];
        sym3_mul(m->Ma + 6 * i, P.afr, Maf);
        for (int j = 0; j < 3; j++)
            P.K[j] = m->K[3 * i + j] + Fb[j] - mass * P.afr[j] - Maf[j];
        /* First guess: this link's last direction, else its first child's,
         * else hanging straight down. */
        double guess[3] = {0, 0, 1};
        if (m->have_n)
            v3_copy(m->n + 3 * l, guess);
        else if (nd->child_begin < nd->child_end)
            v3_copy(m->n + 3 * sys->child_links[nd->child_end - 1], guess);
        int rc = solve_link(m, &P, l, guess, err);
        if (rc != TS_OK) {
            m->have_n = 0;
            return rc;
        }
        /* The upper end: fixes the parent's position the first time,
         * otherwise gives a mismatch residual. */
        int p = L->upper;
        double rp[3];
        for (int j = 0; j < 3; j++)
            rp[j] = ri[j] - L->length * m->n[3 * l + j];
        int a = m->res_of_link[l];
        if (a >= 0) {
            const double *target = p == 0 ? sys->tow.point : m->r + 3 * p;
            for (int j = 0; j < 3; j++) {
                e[3 * a + j] = rp[j] - target[j];
                if (fabs(e[3 * a + j]) > big)
                    big = fabs(e[3 * a + j]);
            }
        } else {
            v3_copy(rp, m->r + 3 * p);
            m->rset[p] = 1;
        }
    }
    m->have_n = 1;
    m->mismatch = big;
    return TS_OK;
}

/* x -= P e: move the free ends below each mismatch by it. Exact when the
 * loads do not depend on position (a translation of a subtree). */
static void correct(const tsi_march *m, double x[], const double e[])
{
    size_t nf = (size_t)m->nleaf;
    for (size_t a = 0; a < nf; a++)
        for (size_t b = 0; b < nf; b++)
            if (m->member[a * nf + b])
                for (int j = 0; j < 3; j++)
                    x[3 * b + j] -= e[3 * a + j];
}

typedef struct shoot_ctx {
    tsi_march *m;
    const ts_frame *f;
    ts_err *err;
    int rc;
    long marches;
} shoot_ctx;

static int shoot_f(const gsl_vector *x, void *params, gsl_vector *out)
{
    shoot_ctx *c = params;
    c->marches++;
    c->rc = tsi_march_eval(c->m, c->f, x->data, out->data, c->err);
    return c->rc == TS_OK ? GSL_SUCCESS : GSL_EBADFUNC;
}

int tsi_march_solve(tsi_march *m, const ts_frame *f, double x[], int fresh,
                    double pos_tol, int max_iter, int *iterations,
                    long *marches, ts_err *err)
{
    const ts_system *sys = m->sys;
    int nu = 3 * m->nleaf, rc;
    double *e = malloc((size_t)nu * sizeof(double));
    if (!e)
        return ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
    if (fresh) {
        /* Every free end below the tow point by the length above it. */
        m->have_n = 0;
        for (int j = 0; j < m->nleaf; j++) {
            double depth = 0.0;
            for (int l = m->leaf_node[j] - 1; l >= 0; l = sys->links[l].parent)
                depth += sys->links[l].length;
            x[3 * j] = sys->tow.point[0];
            x[3 * j + 1] = sys->tow.point[1];
            x[3 * j + 2] = sys->tow.point[2] + depth;
        }
    }
    /* Translation corrections first: they close a straight tow exactly. */
    double last = INFINITY;
    int it = 0;
    for (; it < 8; it++) {
        (*marches)++;
        if ((rc = tsi_march_eval(m, f, x, e, err)) != TS_OK)
            goto out;
        double mm = m->mismatch;
        if (mm <= pos_tol)
            goto out;
        if (!(mm < 0.25 * last) && it >= 1)
            break; /* not contracting fast: hand over to the hybrid solver */
        last = mm;
        correct(m, x, e);
    }
    {
        shoot_ctx ctx = {m, f, err, TS_OK, 0};
        gsl_multiroot_function fn = {shoot_f, (size_t)nu, &ctx};
        gsl_multiroot_fsolver *s =
            gsl_multiroot_fsolver_alloc(gsl_multiroot_fsolver_hybrids,
                                        (size_t)nu);
        gsl_vector_view xv = gsl_vector_view_array(x, (size_t)nu);
        if (!s) {
            rc = ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
            goto out;
        }
        int status = gsl_multiroot_fsolver_set(s, &fn, &xv.vector);
        if (status == GSL_SUCCESS)
            status = GSL_CONTINUE;
        for (; status == GSL_CONTINUE && it < max_iter; it++) {
            status = gsl_multiroot_fsolver_iterate(s);
            if (status != GSL_SUCCESS)
                break;
            status = gsl_multiroot_test_residual(s->f, pos_tol);
        }
        /* Re-march at the solver's best point so the stored shape is its. */
        memcpy(x, s->x->data, (size_t)nu * sizeof(double));
        gsl_multiroot_fsolver_free(s);
        *marches += ctx.marches + 1;
        if (ctx.rc != TS_OK && status != GSL_SUCCESS) {
            rc = ctx.rc;
            goto out;
        }
        if ((rc = tsi_march_eval(m, f, x, e, err)) != TS_OK)
            goto out;
        if (!(m->mismatch <= pos_tol))
            rc = ts_fail(err, TS_ECONV,
                         "equilibrium: shooting stopped after %d iterations "
                         "with the branches %.3g m apart (target %.3g m)",
                         it, m->mismatch, pos_tol);
    }
out:
    *iterations += it;
    free(e);
    return rc;
}
