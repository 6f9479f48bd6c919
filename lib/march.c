/* march.c: marching and shooting for the steady rigid-link tree (march.h).
 *
 * Node i (the lower end of link l) is in static balance in the steadily
 * moving frame:  t_l n_l = K_i + F_l(n_l)/2 - A_l(n_l)/2 (I - n n^T) afr_i,
 * with K_i everything already known once its children are done (their
 * tensions and half loads, the body's load, minus mass times the frame
 * acceleration afr_i = (-W^2 x, W V - W^2 y, 0)) and F_l the load of link l
 * itself, which depends on its direction through drag, the submerged
 * fraction and the position of its upper end r_i - l n_l. So n_l is the
 * direction of the right-hand side H(n): the part of H normal to n must
 * vanish, two equations in the two coordinates of a gnomonic chart centred
 * on a first guess, solved with GSL's hybrid solver. Links are visited in decreasing index, which puts every child
 * before its parent (system.h).
 */
#include "march.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multiroots.h>
#include <gsl/gsl_vector.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "vec3.h"

/* Local root: |H_perp| below this fraction of |H| (rounding is ~1e-16). */
#define LOCAL_RTOL 1e-13
#define LOCAL_MAXIT 60
/* A link whose load is below this fraction of the forces that make it up
 * (its own weight and what hangs below) carries none: rounding. */
#define NO_LOAD_RTOL 1e-12
/* Elastic link length: relative change at which the stretch has settled,
 * and the most iterations allowed. */
#define ELASTIC_LEN_RTOL 1e-15
#define ELASTIC_MAXIT 200
/* The local Newton: iterations before GSL's hybrid solver takes over, and
 * its forward-difference step in chart coordinates (~ sqrt(eps)). */
#define LOCAL_NEWTON_MAXIT 30
/* Largest local Newton step in chart coordinates (tan 16.7 degrees). */
#define LOCAL_MAX_STEP 0.3
#define LOCAL_FD_STEP 1e-8
/* Relative step of the forward-difference shooting Jacobian (~sqrt(eps)):
 * it only feeds a condition estimate. */
#define FD_JAC_RSTEP 1.5e-8
/* Translation corrections tried before the hybrid solver takes over. */
#define MAX_CORRECTIONS 40

struct tsi_march {
    const ts_system *sys;
    int nl, nn, nleaf;
    int *leaf_node;     /* [nleaf] node of each free end */
    int *res_link;      /* [nleaf] link whose upper-end mismatch is residual j */
    char *member;       /* [nleaf * nleaf]: leaf b lies below residual a */
    double *jac0;       /* [nu * nu] row-major d e / d x of a translation */
    double *jlast;      /* [nu * nu] Jacobian for the condition estimate */
    double *xlast;      /* [nu] free-end positions the last solve ended at */
    double *elast;      /* [nu] and its mismatches */
    ts_frame flast;     /* and its frame */
    int hybrid;         /* the last solve needed the hybrid solver */
    int *res_of_link;   /* [nl] residual index or -1 */

    double *n, *t;      /* [3 nl], [nl] */
    double *len;        /* [nl] link lengths (stretched when elastic) */
    int have_n;         /* n holds the last solution (warm start) */
    double *r;          /* [3 nn] marched positions */
    char *rset;         /* [nn] position known */
    double *K;          /* [3 nn] known loads accumulated from children */
    double *Ma;         /* [6 nn] added mass from child links */
    double *extra;      /* [3 nn] extra nodal loads, or NULL */
    tsi_march_pull_fn pull; /* vehicles' loads, or NULL */
    void *pull_ctx;
    const double *up_off;   /* [3 nl] start of a link on a vehicle */
    double root[3];     /* node 0's position: the tow point, or a towing
                           vehicle's where its state places it */
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
    memcpy(m->root, sys->tow.point, sizeof m->root);
    m->nl = sys->nlinks;
    m->nn = sys->nnodes;
    for (int i = 1; i < m->nn; i++)
        if (sys->nodes[i].child_begin == sys->nodes[i].child_end)
            m->nleaf++;
    size_t nl = (size_t)m->nl, nn = (size_t)m->nn, nf = (size_t)m->nleaf;
    m->leaf_node = calloc(nf, sizeof(int));
    m->res_link = calloc(nf, sizeof(int));
    m->member = calloc(nf * nf, 1);
    m->jac0 = calloc(9 * nf * nf, sizeof(double));
    m->jlast = calloc(9 * nf * nf, sizeof(double));
    m->xlast = calloc(3 * nf, sizeof(double));
    m->elast = calloc(3 * nf, sizeof(double));
    m->res_of_link = malloc(nl * sizeof(int));
    m->n = calloc(3 * nl, sizeof(double));
    m->t = calloc(nl, sizeof(double));
    m->len = calloc(nl, sizeof(double));
    m->r = calloc(3 * nn, sizeof(double));
    m->rset = calloc(nn, 1);
    m->K = calloc(3 * nn, sizeof(double));
    m->Ma = calloc(6 * nn, sizeof(double));
    m->local = gsl_multiroot_fsolver_alloc(gsl_multiroot_fsolver_hybrids, 2);
    m->lx = gsl_vector_alloc(2);
    if (!m->leaf_node || !m->res_link || !m->member || !m->jac0 ||
        !m->jlast || !m->xlast || !m->elast ||
        !m->res_of_link ||
        !m->n || !m->t || !m->len || !m->r || !m->rset || !m->K || !m->Ma ||
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
    /* Translating the free ends below a link translates the marched
     * subtree: residual a grows by the shift of the ends below its link and
     * shrinks by that of the ends below the sibling that fixed the branch
     * node. That is the Jacobian wherever loads do not depend on position,
     * and the shooting solver starts from it. */
    int f = 0;
    size_t nu = 3 * nf;
    for (int i = 1; i < m->nn; i++)
        if (sys->nodes[i].child_begin == sys->nodes[i].child_end) {
            m->leaf_node[f] = i;
            for (int l = i - 1; l >= 0; l = sys->links[l].parent) {
                int a = m->res_of_link[l];
                if (a >= 0) {
                    m->member[(size_t)a * nf + f] = 1;
                    for (int j = 0; j < 3; j++)
                        m->jac0[(3 * (size_t)a + j) * nu + 3 * f + j] += 1.0;
                    continue;
                }
                const ts_node *up = &sys->nodes[sys->links[l].upper];
                if (sys->links[l].upper == 0)
                    continue;
                for (int c = up->child_begin; c < up->child_end; c++) {
                    int s = m->res_of_link[sys->child_links[c]];
                    if (s >= 0)
                        for (int j = 0; j < 3; j++)
                            m->jac0[(3 * (size_t)s + j) * nu + 3 * f + j] -= 1.0;
                }
            }
            f++;
        }
    (void)nres;
    return m;
nomem:
    {
        /* What the march holds: two dense 3f x 3f Jacobians of the f free
         * ends (the shooting problem) dominate. */
        double f = m ? m->nleaf : 0, n = sys->nnodes;
        double bytes = 8 * (18 * f * f + 6 * f) + f * f +
                       8 * (13 * n + 5 * n);
        tsi_march_free(m);
        ts_fail_nomem(err, bytes, "fewer cables with free ends (bodies "
                      "or junctions joining them)",
                      "equilibrium: out of memory for the shooting problem "
                      "of %.0f free ends and %.0f nodes, two %.0f x %.0f "
                      "Jacobians", f, n, 3 * f, 3 * f);
    }
    return NULL;
}

void tsi_march_free(tsi_march *m)
{
    if (!m)
        return;
    free(m->leaf_node);
    free(m->res_link);
    free(m->member);
    free(m->jac0);
    free(m->jlast);
    free(m->xlast);
    free(m->elast);
    free(m->res_of_link);
    free(m->n);
    free(m->t);
    free(m->len);
    free(m->r);
    free(m->rset);
    free(m->K);
    free(m->Ma);
    free(m->extra);
    if (m->local)
        gsl_multiroot_fsolver_free(m->local);
    if (m->lx)
        gsl_vector_free(m->lx);
    free(m);
}

int tsi_march_nunknown(const tsi_march *m) { return 3 * m->nleaf; }

void tsi_march_set_root(tsi_march *m, const double r[3])
{
    memcpy(m->root, r, sizeof m->root);
}
const double *tsi_march_positions(const tsi_march *m) { return m->r; }

void tsi_march_warm(tsi_march *m, const double *directions, double x[])
{
    const ts_system *sys = m->sys;
    memcpy(m->n, directions, 3 * (size_t)m->nl * sizeof(double));
    for (int l = 0; l < m->nl; l++)
        m->len[l] = sys->links[l].length;
    m->have_n = 1;
    /* Links run from the tow point down (every link after its parent):
     * each lower node is its upper node plus the link. */
    memcpy(m->r, m->root, 3 * sizeof(double));
    for (int l = 0; l < m->nl; l++) {
        const ts_link *L = &sys->links[l];
        for (int j = 0; j < 3; j++)
            m->r[3 * L->lower + j] =
                m->r[3 * L->upper + j] + L->length * directions[3 * l + j];
    }
    for (int j = 0; j < m->nleaf; j++)
        memcpy(x + 3 * j, m->r + 3 * m->leaf_node[j], 3 * sizeof(double));
}

const double *tsi_march_directions(const tsi_march *m) { return m->n; }
const double *tsi_march_tensions(const tsi_march *m) { return m->t; }

void tsi_march_strains(const tsi_march *m, double *e)
{
    for (int l = 0; l < m->nl; l++) {
        const ts_link *L = &m->sys->links[l];
        e[l] = L->elastic ? m->t[l] / L->ea : 0.0;
    }
}
double tsi_march_mismatch(const tsi_march *m) { return m->mismatch; }

/* Forward-difference Jacobian of the mismatches at x, where they are e0,
 * into m->jlast (row-major): nu marches; e is scratch. */
static int fd_jacobian(tsi_march *m, const ts_frame *f, double x[],
                       const double e0[], double e[], long *marches,
                       ts_err *err)
{
    int nu = 3 * m->nleaf, rc = TS_OK;
    double L = 0.0;
    for (int l = 0; l < m->nl; l++)
        L += m->sys->links[l].length;
    for (int j = 0; rc == TS_OK && j < nu; j++) {
        double xj = x[j], h = FD_JAC_RSTEP * fmax(fabs(xj), L);
        x[j] = xj + h;
        rc = tsi_march_eval(m, f, x, e, err);
        (*marches)++;
        x[j] = xj;
        for (int i = 0; rc == TS_OK && i < nu; i++)
            m->jlast[(size_t)i * nu + j] = (e[i] - e0[i]) / h;
    }
    return rc;
}

double tsi_norm1(const double *a, int n)
{
    double big = 0.0;
    for (int j = 0; j < n; j++) {
        double sum = 0.0;
        for (int i = 0; i < n; i++)
            sum += fabs(a[(size_t)i * n + j]);
        big = fmax(big, sum);
    }
    return big;
}

int tsi_march_condition(tsi_march *m, double *condition, double *shape_error,
                        long *marches)
{
    int n = 3 * m->nleaf, info = 0;
    *condition = NAN;
    *shape_error = NAN;
    /* Where the translation corrections closed the solve, the translation
     * Jacobian is exact; otherwise it is formed by forward differences
     * (the hybrid solver keeps its updates in QR factors, not in a
     * Jacobian one can read). The marches leave the stored shape at a
     * perturbed point: take the solution out first. */
    if (m->hybrid) {
        double *e = malloc((size_t)n * sizeof(double));
        ts_err ferr = {0};
        int frc = e ? fd_jacobian(m, &m->flast, m->xlast, m->elast, e,
                                  marches, &ferr)
                    : TS_ENOMEM;
        free(e);
        if (frc != TS_OK)
            return frc;
    } else {
        memcpy(m->jlast, m->jac0, (size_t)n * n * sizeof(double));
    }
    /* J has three rows per free end, a handful: its condition is taken
     * exactly, ||J||_1 ||J^-1||_1 from the inverse of GSL's LU (what
     * LAPACK's dgecon estimates from below), at no cost worth counting
     * and without loading LAPACK for a shooting run (doc/performance.md,
     * "Start-up"). J is row-major, as GSL's matrices are. */
    size_t nn = (size_t)n * (size_t)n;
    gsl_matrix *lu = gsl_matrix_alloc((size_t)n, (size_t)n);
    gsl_matrix *inv = gsl_matrix_alloc((size_t)n, (size_t)n);
    gsl_permutation *perm = gsl_permutation_alloc((size_t)n);
    if (!lu || !inv || !perm) {
        if (lu)
            gsl_matrix_free(lu);
        if (inv)
            gsl_matrix_free(inv);
        if (perm)
            gsl_permutation_free(perm);
        return TS_ENOMEM;
    }
    memcpy(lu->data, m->jlast, nn * sizeof(double));
    int signum = 0;
    gsl_linalg_LU_decomp(lu, perm, &signum);
    /* A zero pivot: J is singular (checked before inverting, which would
     * call GSL's error handler). */
    for (int k = 0; k < n; k++)
        if (gsl_matrix_get(lu, (size_t)k, (size_t)k) == 0.0)
            info = k + 1;
    if (info == 0 && gsl_linalg_LU_invert(lu, perm, inv) != GSL_SUCCESS)
        info = -1;
    if (info == 0) {
        double anorm = tsi_norm1(m->jlast, n), inorm = tsi_norm1(inv->data, n);
        *condition = anorm * inorm;
        /* Free-end positions move by about |J^-1| |mismatch|, at the
         * solution (the perturbed marches changed m->mismatch). */
        double mis = 0.0;
        for (int k = 0; k < n; k++)
            mis = fmax(mis, fabs(m->elast[k]));
        *shape_error = mis * inorm;
    }
    gsl_matrix_free(lu);
    gsl_matrix_free(inv);
    gsl_permutation_free(perm);
    return info == 0 ? TS_OK : TS_ESINGULAR;
}

/* The balance of one node, for the local root. */
typedef struct link_problem {
    const ts_system *sys;
    const ts_link *L;
    const ts_frame *f;
    const double *ri;   /* lower node position */
    double len;         /* link length (stretched when elastic) */
    const ts_body *body;/* a cylinder at the lower node: its load and added
                           mass turn with the link, NULL otherwise */
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
        rp[j] = P->ri[j] - P->len * n[j];
        rm[j] = 0.5 * (rp[j] + P->ri[j]);
    }
    tsi_rel_velocity(P->f, rm, zero, w);
    tsi_link_load(L, P->sys->env.water_density, P->sys->env.gravity, n,
                  rp[2], P->ri[2], w, F, &s);
    for (int j = 0; j < 3; j++)
        H[j] = P->K[j] + 0.5 * F[j];
    if (P->body) {
        double wb[3], Fb[3], frac, S[6] = {0, 0, 0, 0, 0, 0}, Sa[3];
        tsi_rel_velocity(P->f, P->ri, zero, wb);
        tsi_body_load(P->body, P->sys->env.water_density,
                      P->sys->env.gravity, P->ri[2], wb, n, Fb, &frac);
        tsi_body_added_mass(P->body, P->sys->env.water_density, frac, n, S);
        sym3_mul(S, P->afr, Sa);
        for (int j = 0; j < 3; j++)
            H[j] += Fb[j] - Sa[j];
    }
    if (P->sys->has_added_mass && L->can > 0 && s > 0) {
        double rho = P->sys->env.water_density;
        double A = L->can * rho * M_PI * 0.25 * L->diameter * L->diameter *
                   L->length * s;
        double an = v3_dot(P->afr, n);
        for (int j = 0; j < 3; j++)
            H[j] -= 0.5 * A * (P->afr[j] - an * n[j]);
    }
}

/* Gnomonic chart about the centre c of the local solve: n(a, b) is the unit
 * vector along c + a u + b v, with (c, u, v) orthonormal (columns of R).
 * No trigonometry, and regular for every direction in the hemisphere of
 * c. */
static void chart_dir(const double R[9], double a, double b, double n[3])
{
    double x[3];
    for (int j = 0; j < 3; j++)
        x[j] = -R[3 * j] + a * R[3 * j + 1] + b * R[3 * j + 2];
    double inv = 1.0 / v3_norm(x);
    for (int j = 0; j < 3; j++)
        n[j] = x[j] * inv;
}

/* Residual of the local root: the part of H normal to n, on the chart's
 * tangent axes u and v. Zero exactly when H is parallel to n. */
static int local_f(const gsl_vector *x, void *params, gsl_vector *out)
{
    const link_problem *P = params;
    double n[3], H[3], F[3];
    chart_dir(P->R, gsl_vector_get(x, 0), gsl_vector_get(x, 1), n);
    link_rhs(P, n, H, F);
    double hn = v3_dot(H, n), hp[3];
    for (int j = 0; j < 3; j++)
        hp[j] = H[j] - hn * n[j];
    gsl_vector_set(out, 0,
                   hp[0] * P->R[1] + hp[1] * P->R[4] + hp[2] * P->R[7]);
    gsl_vector_set(out, 1,
                   hp[0] * P->R[2] + hp[1] * P->R[5] + hp[2] * P->R[8]);
    return GSL_SUCCESS;
}

/* Local residual at chart coordinates (a, b), as plain numbers. */
static void local_eval(const link_problem *P, double a, double b, double r[2])
{
    double xv[2] = {a, b}, rv[2];
    gsl_vector_const_view x = gsl_vector_const_view_array(xv, 2);
    gsl_vector_view out = gsl_vector_view_array(rv, 2);
    local_f(&x.vector, (void *)P, &out.vector);
    r[0] = rv[0];
    r[1] = rv[1];
}

/* Damped Newton on the 2x2 local problem with a forward-difference
 * Jacobian. The direction moves little from one link, or one march, to the
 * next, so this converges in a step or two; GSL's general hybrid solver
 * (used when this does not converge within LOCAL_NEWTON_MAXIT) costs
 * several times the physics for so small a system in the innermost loop.
 * Returns 1 when |r| <= tol, with the coordinates in x. */
static int local_newton(const link_problem *P, double tol, double x[2])
{
    double r[2], r1[2], r2[2];
    local_eval(P, x[0], x[1], r);
    double rn = hypot(r[0], r[1]);
    for (int it = 0; it < LOCAL_NEWTON_MAXIT; it++) {
        if (rn <= tol)
            return 1;
        double h = LOCAL_FD_STEP;
        local_eval(P, x[0] + h, x[1], r1);
        local_eval(P, x[0], x[1] + h, r2);
        double j00 = (r1[0] - r[0]) / h, j10 = (r1[1] - r[1]) / h;
        double j01 = (r2[0] - r[0]) / h, j11 = (r2[1] - r[1]) / h;
        double det = j00 * j11 - j01 * j10;
        if (!(fabs(det) > 0))
            return 0;
        /* Where the residual turns much faster than H is long (huge normal
         * drag) rounding in the direction alone leaves eps |J| of it. */
        tol = fmax(tol, LOCAL_RTOL * fmax(fmax(fabs(j00), fabs(j01)),
                                          fmax(fabs(j10), fabs(j11))));
        double da = -(j11 * r[0] - j01 * r[1]) / det;
        double db = -(-j10 * r[0] + j00 * r[1]) / det;
        /* A full step may leave the part of the chart that is useful:
         * near its horizon (90 degrees from the centre, coordinates ->
         * infinity) the part of H normal to n can point along the centre,
         * where the residual's two components (on the centre's tangent
         * axes) do not see it: a false root the solver runs to (a bare
         * cable with Cdt = 0 did, from a centre 66 degrees off). Cap the
         * step. */
        double dn = hypot(da, db);
        if (dn > LOCAL_MAX_STEP) {
            da *= LOCAL_MAX_STEP / dn;
            db *= LOCAL_MAX_STEP / dn;
        }
        double lam = 1.0, trial[2], rt[2], rtn = INFINITY;
        for (int k = 0; k < 6; k++, lam *= 0.5) {
            trial[0] = x[0] + lam * da;
            trial[1] = x[1] + lam * db;
            local_eval(P, trial[0], trial[1], rt);
            rtn = hypot(rt[0], rt[1]);
            if (rtn < rn)
                break;
        }
        if (!(rtn < rn))
            return 0;
        x[0] = trial[0];
        x[1] = trial[1];
        r[0] = rt[0];
        r[1] = rt[1];
        rn = rtn;
    }
    return rn <= tol;
}

/* Direction n of link l parallel to H(n), its tension t = H.n and its load
 * F, for the link length in P. `guess` is a unit vector. */
static int solve_link(tsi_march *m, link_problem *P, const double guess[3],
                      int warm, double n[3], double *t, double F[3],
                      ts_err *err)
{
    double H[3];
    v3_copy(guess, n);
    /* Without a previous solution, two fixed-point sweeps put the chart
     * centre near the root. */
    for (int it = 0; it < (warm ? 0 : 2); it++) {
        link_rhs(P, n, H, F);
        double h = v3_norm(H);
        if (!(h > 0))
            break;
        for (int j = 0; j < 3; j++)
            n[j] = H[j] / h;
    }
    link_rhs(P, n, H, F);
    double hn = v3_norm(H);
    /* No load to align with: zero, or a cancellation (weight against
     * buoyancy) down at rounding level of the forces that cancel. */
    const ts_link *L = P->L;
    double gross = v3_norm(P->K) + L->mass * m->sys->env.gravity;
    /* Forces that overflowed: say so where it happens (the loads were
     * checked against TS_LOAD_MAX before, so an iterate far off the
     * solution made them). */
    if (!isfinite(hn) || !isfinite(gross))
        return ts_fail(err, TS_ECONV,
                       "equilibrium: the forces on cables[%d] '%s' link %d "
                       "overflowed (are not finite) in the march",
                       L->cable, m->sys->cables[L->cable].name, L->index);
    if (!(hn > NO_LOAD_RTOL * gross))
        return ts_fail(err, TS_ESINGULAR,
                       "equilibrium: cables[%d] '%s' link %d carries no load "
                       "(|force| = %.3g N against a weight of %.3g N), so its "
                       "direction is undefined: a neutrally buoyant end "
                       "without flow has no steady shape",
                       L->cable, m->sys->cables[L->cable].name, L->index, hn,
                       gross);
    tsi_chart_centred(n, P->R);
    double tol = LOCAL_RTOL * hn, xc[2] = {0.0, 0.0};
    if (!local_newton(P, tol, xc)) {
        gsl_multiroot_function fn = {local_f, 2, P};
        gsl_vector_set(m->lx, 0, 0.0);
        gsl_vector_set(m->lx, 1, 0.0);
        gsl_multiroot_fsolver_set(m->local, &fn, m->lx);
        int status = gsl_multiroot_test_residual(m->local->f, tol);
        for (int it = 0; status == GSL_CONTINUE && it < LOCAL_MAXIT; it++) {
            if (gsl_multiroot_fsolver_iterate(m->local))
                break;
            status = gsl_multiroot_test_residual(m->local->f, tol);
        }
        xc[0] = gsl_vector_get(m->local->x, 0);
        xc[1] = gsl_vector_get(m->local->x, 1);
    }
    chart_dir(P->R, xc[0], xc[1], n);
    link_rhs(P, n, H, F);
    double hnorm = v3_norm(H), along = v3_dot(H, n), hp[3];
    for (int j = 0; j < 3; j++)
        hp[j] = H[j] - along * n[j];
    double perp = v3_norm(hp);
    if (!(perp <= 1e3 * LOCAL_RTOL * hnorm)) {
        /* The floor rounding sets: eps times how fast the residual turns
         * with the direction, when that exceeds |H| (huge normal drag). */
        double r0[2], r1[2], r2[2], h = LOCAL_FD_STEP;
        local_eval(P, xc[0], xc[1], r0);
        local_eval(P, xc[0] + h, xc[1], r1);
        local_eval(P, xc[0], xc[1] + h, r2);
        double jn = fmax(hypot(r1[0] - r0[0], r1[1] - r0[1]),
                         hypot(r2[0] - r0[0], r2[1] - r0[1])) / h;
        hnorm = fmax(hnorm, jn);
    }
    if (!(perp <= 1e3 * LOCAL_RTOL * hnorm)) {
        const ts_link *L = P->L;
        return ts_fail(err, TS_ECONV,
                       "equilibrium: the direction of cables[%d] '%s' link "
                       "%d did not converge (unbalanced %.3g N of %.3g N)",
                       L->cable, m->sys->cables[L->cable].name, L->index,
                       perp, hnorm);
    }
    *t = v3_dot(H, n);
    return TS_OK;
}

/* Solve link l and pass its half load, tension and added mass up to its
 * upper node. An elastic link's length follows its tension,
 * l = l0 (1 + T / EA): iterated to rounding (the map contracts by about
 * T / EA per step). */
static int march_link(tsi_march *m, link_problem *P, int l,
                      const double guess[3], ts_err *err)
{
    const ts_link *L = P->L;
    double n[3], F[3], t = 0.0;
    P->len = L->elastic && m->have_n ? m->len[l] : L->length;
    int rc = solve_link(m, P, guess, m->have_n, n, &t, F, err);
    for (int it = 0; rc == TS_OK && L->elastic; it++) {
        /* A link aligned with its load carries |H| > 0; a negative
         * tension is the local root's other branch, met from a poor
         * shooting iterate, not a proof that no steady state exists (a link
         * with no load at all is refused above, TS_ESINGULAR). So this is
         * a failure to converge: the caller may continue in turn rate or
         * fall back to Newton. */
        if (!(t > 0))
            return ts_fail(err, TS_ECONV,
                           "equilibrium: elastic cables[%d] '%s' link %d "
                           "went slack in the march (tension %.3g N): the "
                           "march needs every elastic link taut",
                           L->cable, m->sys->cables[L->cable].name, L->index,
                           t);
        double len = L->length * (1.0 + t / L->ea); /* Hooke: e = T / EA */
        if (fabs(len - P->len) <= ELASTIC_LEN_RTOL * len)
            break;
        if (it >= ELASTIC_MAXIT)
            return ts_fail(err, TS_ECONV,
                           "equilibrium: the stretch of cables[%d] '%s' link "
                           "%d did not settle (EA %.3g N, tension %.3g N)",
                           L->cable, m->sys->cables[L->cable].name, L->index,
                           L->ea, t);
        P->len = len;
        rc = solve_link(m, P, n, 1, n, &t, F, err);
    }
    if (rc != TS_OK)
        return rc;
    v3_copy(n, m->n + 3 * l);
    m->t[l] = t;
    m->len[l] = P->len;
    int p = L->upper;
    double *Kp = m->K + 3 * p;
    for (int j = 0; j < 3; j++)
        Kp[j] += 0.5 * F[j] + t * n[j];
    if (m->sys->has_added_mass && L->can > 0) {
        double zp = P->ri[2] - P->len * n[2];
        double s = tsi_link_submerged(zp, P->ri[2]);
        double rho = m->sys->env.water_density;
        double A = L->can * rho * M_PI * 0.25 * L->diameter * L->diameter *
                   L->length * s;
        sym3_add_normal(m->Ma + 6 * p, 0.5 * A, n);
    }
    return TS_OK;
}

int tsi_march_set_loads(tsi_march *m, const double *F)
{
    if (!F) {
        free(m->extra);
        m->extra = NULL;
        return TS_OK;
    }
    if (!m->extra)
        m->extra = malloc(3 * (size_t)m->nn * sizeof(double));
    if (!m->extra)
        return TS_ENOMEM;
    memcpy(m->extra, F, 3 * (size_t)m->nn * sizeof(double));
    return TS_OK;
}

void tsi_march_set_vehicles(tsi_march *m, tsi_march_pull_fn pull, void *ctx,
                            const double *off)
{
    m->pull = pull;
    m->pull_ctx = ctx;
    m->up_off = pull ? off : NULL;
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
        double Fb[3] = {0, 0, 0}, *Mi = m->Ma + 6 * i;
        P.body = NULL;
        /* Structural mass, and a sphere's load and added mass, are known
         * here; a cylinder's depend on this link's direction (link_rhs). */
        Mi[0] += nd->mass;
        Mi[1] += nd->mass;
        Mi[2] += nd->mass;
        if (nd->body >= 0) {
            const ts_body *bd = &sys->bodies[nd->body];
            if (bd->type == TS_BODY_CYLINDER) {
                P.body = bd;
            } else if (bd->type == TS_BODY_VEHICLE) {
                int rc = m->pull ? m->pull(m->pull_ctx, i, ri, Fb) : TS_OK;
                if (rc != TS_OK) {
                    m->have_n = 0;
                    return ts_fail(err, rc, "equilibrium: bodies[%d] '%s' "
                                   "is outside the model's range in the "
                                   "march (%s)", nd->body, bd->name,
                                   ts_strerror(rc));
                }
            } else {
                double w[3], frac;
                tsi_rel_velocity(f, ri, zero, w);
                /* A sphere's load has no axis: the link's last direction
                 * stands in, unused. */
                const double *axis = m->n + 3 * l;
                tsi_body_load(bd, rho, g, ri[2], w, axis, Fb, &frac);
                if (sys->has_added_mass)
                    tsi_body_added_mass(bd, rho, frac, axis, Mi);
            }
        }
        double Maf[3];
        sym3_mul(Mi, P.afr, Maf);
        if (m->extra)
            v3_axpy(1.0, m->extra + 3 * i, Fb);
        for (int j = 0; j < 3; j++)
            P.K[j] = m->K[3 * i + j] + Fb[j] - Maf[j];
        /* First guess: this link's last direction, else its first child's,
         * else hanging straight down. */
        double guess[3] = {0, 0, 1};
        if (m->have_n)
            v3_copy(m->n + 3 * l, guess);
        else if (nd->child_begin < nd->child_end)
            v3_copy(m->n + 3 * sys->child_links[nd->child_end - 1], guess);
        int rc = march_link(m, &P, l, guess, err);
        if (rc != TS_OK) {
            m->have_n = 0;
            return rc;
        }
        /* The upper end: fixes the parent's position the first time,
         * otherwise gives a mismatch residual. */
        int p = L->upper;
        double rp[3];
        for (int j = 0; j < 3; j++)
            rp[j] = ri[j] - m->len[l] * m->n[3 * l + j];
        if (m->up_off && L->up_body >= 0)
            for (int j = 0; j < 3; j++)
                rp[j] -= m->up_off[3 * l + j]; /* the vehicle's joint */
        int a = m->res_of_link[l];
        if (a >= 0) {
            const double *target = p == 0 ? m->root : m->r + 3 * p;
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

/* The translation Jacobian: exact without position-dependent loads, and
 * refined by the hybrid solver's rank-one updates otherwise. */
static int shoot_df(const gsl_vector *x, void *params, gsl_matrix *J)
{
    (void)x;
    const shoot_ctx *c = params;
    memcpy(J->data, c->m->jac0, J->size1 * J->size2 * sizeof(double));
    return GSL_SUCCESS;
}

static int shoot_fdf(const gsl_vector *x, void *params, gsl_vector *out,
                     gsl_matrix *J)
{
    int rc = shoot_f(x, params, out);
    return rc ? rc : shoot_df(x, params, J);
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
            x[3 * j] = m->root[0];
            x[3 * j + 1] = m->root[1];
            x[3 * j + 2] = m->root[2] + depth;
        }
    }
    /* Translation corrections first: they close a straight tow exactly. */
    m->hybrid = 0;
    m->flast = *f;
    double last = INFINITY;
    int it = 0;
    for (; it < MAX_CORRECTIONS; it++) {
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
        gsl_multiroot_function_fdf fn = {shoot_f, shoot_df, shoot_fdf,
                                         (size_t)nu, &ctx};
        gsl_multiroot_fdfsolver *s =
            gsl_multiroot_fdfsolver_alloc(gsl_multiroot_fdfsolver_hybridsj,
                                          (size_t)nu);
        gsl_vector_view xv = gsl_vector_view_array(x, (size_t)nu);
        if (!s) {
            rc = ts_fail(err, TS_ENOMEM, "equilibrium: out of memory");
            goto out;
        }
        int status = gsl_multiroot_fdfsolver_set(s, &fn, &xv.vector);
        if (status == GSL_SUCCESS)
            status = GSL_CONTINUE;
        for (; status == GSL_CONTINUE && it < max_iter; it++) {
            status = gsl_multiroot_fdfsolver_iterate(s);
            if (status != GSL_SUCCESS)
                break;
            status = gsl_multiroot_test_residual(s->f, pos_tol);
        }
        /* Re-march at the solver's best point so the stored shape is its. */
        memcpy(x, s->x->data, (size_t)nu * sizeof(double));
        gsl_multiroot_fdfsolver_free(s);
        *marches += ctx.marches + 1;
        if (ctx.rc != TS_OK && status != GSL_SUCCESS) {
            rc = ctx.rc;
            goto out;
        }
        m->hybrid = 1;
        if ((rc = tsi_march_eval(m, f, x, e, err)) != TS_OK)
            goto out;
        if (!(m->mismatch <= pos_tol))
            rc = ts_fail(err, TS_ECONV,
                         "equilibrium: shooting stopped after %d iterations "
                         "with the branches %.3g m apart (target %.3g m)",
                         it, m->mismatch, pos_tol);
    }
out:
    if (rc == TS_OK) {
        memcpy(m->xlast, x, (size_t)nu * sizeof(double));
        memcpy(m->elast, e, (size_t)nu * sizeof(double));
    }
    *iterations += it;
    free(e);
    return rc;
}
