/* descriptor.c: the sparse linear model of the node residual
 * (lib/descriptor.h; doc/linear.md, section 2).
 *
 * Structure. Node k's residual R_k (lib/kernel_impl.h) depends on the
 * positions of the nodes within dist_r links of k (2 with bending: a
 * joint's force on k depends on the next node but one; 1 without) and on
 * the velocities within 1 link (drag at link midpoints, Coriolis). K and C
 * are stored as 3x3 blocks (k, j) over those neighbours.
 *
 * Coloured central differences (Curtis, Powell & Reid 1974). Two position
 * columns j, j' may be perturbed in the same residual evaluation when no
 * row depends on both, i.e. when they are more than 2 dist_r links apart;
 * velocity columns when more than 2 apart. A greedy distance colouring of
 * the tree (in node order) gives 2 dist_r + 1 colours on a cable and a few
 * more at junctions; each colour and each of x, y, z is one group, and each
 * group costs two residual evaluations (R(x + h) - R(x - h)) / 2h, four
 * with the error estimate (the same with 2h; (D(2h) - D(h)) / 3 estimates
 * D(h)'s truncation error, as in lib/linearize.c). The count is independent
 * of the number of links: 18 to 24 groups for a cable.
 *
 * Steps: rel_step times a scale, rounded so that x + h is exact: for
 * velocities max(|v|, sqrt(g l) + |V|) (lib/linearize.c's scale), for
 * positions max(l, (|x| l^2)^(1/3)), l the length of the link ending at
 * the node (see tsi_desc_linearize).
 *
 * Rounding. (D(2h) - D(h)) / 3 samples the rounding noise of the
 * differences only by chance. The residual's own noise is measured as in
 * lib/linearize.c: at NOISE_SAMPLES states a ten-thousandth of a step
 * from the base (every position and velocity but the tow point's at
 * once, signs from a fixed sequence), R(x0 + d) - R(x0) - K d_r - C d_v is the rounding of two
 * evaluations; its root mean square over sqrt(2) is the noise rnoise_i of
 * one evaluation of row i, and entry (i, j) of a central difference
 * carries rnoise_i / (sqrt(2) h_j). Cost: NOISE_SAMPLES + 1 residual
 * evaluations and block products, O(nlinks).
 *
 * Vehicles. A towed vehicle's angles are a point of their own (its
 * rotational rows; a neighbour of its node and of the lower nodes of the
 * cables leaving it), coloured and differenced as a node; its controller
 * states and inputs get one group each (the vehicles' k-th together: each
 * reaches its own vehicle's rows only), which fills the local blocks Lv
 * (controller rows, and the force rows' controller and input columns)
 * and Ov (its outputs, from ts_kernel_outputs after each evaluation).
 * Its inertia Mv and the coefficients of the cables leaving it at points
 * P (pg, pm) are exact, from the kernel (tsi_kernel_vehicle_mass,
 * tsi_kernel_link_point).
 *
 * The mass matrices M (dR/da), the tension columns N (dR/dt = +-n) and the
 * link rows are exact: they are read off the base state, not differenced.
 * An elastic link's tension enters the residual as an unknown, so that a
 * position step (6e-6 of the link length, a strain step of the same size)
 * never meets the slack kink of max(0, EA e): at EA = 1e9 N that step is a
 * tension step of 6000 N, far beyond a cable's tension. Its linear law is
 * written out instead: dt = (EA/l) n.dd + Cv n.dd', or dt = 0 when slack.
 * In the kernel's coordinates that is EA de + Cv l de', exactly its
 * tension's: n.dd = l de and n.dd' = l de' for any change of the link's
 * angles and their rates. (The node-form term Cv dd'0.(I - n n^T) dd / |d|
 * of a link that turns while stretching is left out: with the velocity map
 * J dq' it would make the tension depend on the link's angles, which it
 * does not, by Cv l |n'| per rad, a large error on a stiff link.)
 */
#include "descriptor.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <klu.h>

#include "kernel_impl.h"

/* ---- The tree's neighbourhoods ----------------------------------------- */

/* Neighbours of point x: a node's parent, children and vehicle point; a
 * vehicle point's node and the lower nodes of the cables leaving it (they
 * start at its points P). */
static int point_nbrs(const ts_descriptor *d, const int *node_vp, int x,
                      int *out)
{
    const ts_system *sys = d->sys;
    int m = 0;
    if (x >= d->nn) {
        int i = d->vl[x - d->nn].node;
        out[m++] = i;
        for (int c = sys->nodes[i].child_begin; c < sys->nodes[i].child_end;
             c++)
            out[m++] = sys->links[sys->child_links[c]].lower;
        return m;
    }
    if (x > 0) {
        const ts_link *L = &sys->links[sys->nodes[x].link];
        out[m++] = L->upper;
        if (L->up_body >= 0)
            out[m++] = node_vp[L->upper];
    }
    for (int c = sys->nodes[x].child_begin; c < sys->nodes[x].child_end; c++)
        out[m++] = sys->links[sys->child_links[c]].lower;
    if (node_vp[x] >= 0)
        out[m++] = node_vp[x];
    return m;
}

/* Work for breadth-first balls: a stamp per node and a queue. */
typedef struct ball_ws {
    int *stamp, *dist, *queue, *adj;
    const int *node_vp; /* [nn] the vehicle point at a node, -1 */
    int now;
} ball_ws;

/* Nodes within `depth` links of x (x included) into out[] with their
 * distances in dist_out (may be NULL); returns how many. */
static int ball(const ts_descriptor *d, ball_ws *w, int x, int depth,
                int *out, int *dist_out)
{
    w->now++;
    int head = 0, tail = 0;
    w->queue[tail++] = x;
    w->stamp[x] = w->now;
    w->dist[x] = 0;
    while (head < tail) {
        int y = w->queue[head++];
        if (w->dist[y] == depth)
            continue;
        int m = point_nbrs(d, w->node_vp, y, w->adj);
        for (int i = 0; i < m; i++) {
            int z = w->adj[i];
            if (w->stamp[z] == w->now)
                continue;
            w->stamp[z] = w->now;
            w->dist[z] = w->dist[y] + 1;
            w->queue[tail++] = z;
        }
    }
    for (int i = 0; i < tail; i++) {
        out[i] = w->queue[i];
        if (dist_out)
            dist_out[i] = w->dist[w->queue[i]];
    }
    return tail;
}

/* Greedy colouring: nodes more than `sep` links apart may share a colour.
 * Returns the number of colours, or -1 when out of memory. */
static int colour_tree(const ts_descriptor *d, ball_ws *w, int sep,
                       int *colour, int *buf)
{
    int nn = d->np, ncol = 0;
    int *used = calloc((size_t)nn + 1, sizeof(int));
    if (!used)
        return -1;
    for (int x = 0; x < nn; x++)
        colour[x] = -1;
    for (int x = 0; x < nn; x++) {
        int m = ball(d, w, x, sep, buf, NULL);
        for (int i = 0; i < m; i++)
            if (colour[buf[i]] >= 0)
                used[colour[buf[i]]] = x + 1;
        int c = 0;
        while (used[c] == x + 1)
            c++;
        colour[x] = c;
        if (c + 1 > ncol)
            ncol = c + 1;
    }
    free(used);
    return ncol;
}

/* ---- Allocation and pattern -------------------------------------------- */

void tsi_desc_free(ts_descriptor *d)
{
    if (!d)
        return;
    void *arrays[] = {d->vl,     d->r0,     d->v0,      d->a0,   d->t0,
                      d->y0,     d->u0,     d->M,       d->Mv,   d->pg,
                      d->pm,     d->n,      d->len,     d->ka,   d->ca,
                      d->kind,   d->bptr,   d->bcol,    d->btr,  d->bdist,
                      d->K,      d->C,      d->Kerr,    d->Cerr, d->lv_off,
                      d->Lv,     d->Lerr,   d->hc,      d->hu,   d->rnoise,
                      d->rcolour, d->vcolour, d->hr,    d->hv,   d->Sp,
                      d->Si,     d->pos,    d->lvp_off, d->ov_off, d->Ov,
                      d->Oerr,   d->onoise, d->Gt,   d->Gterr, d->Gf,
                      d->Gferr};
    for (size_t i = 0; i < sizeof arrays / sizeof arrays[0]; i++)
        free(arrays[i]);
    if (d->klu_symbolic)
        d->klu.klu_free_symbolic((klu_symbolic **)&d->klu_symbolic,
                                 d->klu_common);
    free(d->klu_common);
    free(d);
}

/* One entry of the pattern: column, row and where its position goes. */
typedef struct entry {
    int col, row, tag;
} entry;

/* Sort e[m] by column, then row (no two entries share both): two stable
 * counting passes, by row and then by column, O(m + nx) (qsort was
 * O(m log m): doc/performance.md, "Less work beside the search"). */
static int sort_entries(entry *e, size_t m, int nx)
{
    entry *t = malloc((m > 0 ? m : 1) * sizeof *t);
    size_t *at = malloc(((size_t)nx + 1) * sizeof *at);
    if (!t || !at) {
        free(t);
        free(at);
        return TS_ENOMEM;
    }
    for (int pass = 0; pass < 2; pass++) {
        const entry *from = pass ? t : e;
        entry *to = pass ? e : t;
        memset(at, 0, ((size_t)nx + 1) * sizeof *at);
        for (size_t i = 0; i < m; i++)
            at[(pass ? from[i].col : from[i].row) + 1]++;
        for (int c = 0; c < nx; c++)
            at[c + 1] += at[c];
        for (size_t i = 0; i < m; i++)
            to[at[pass ? from[i].col : from[i].row]++] = from[i];
    }
    free(t);
    free(at);
    return TS_OK;
}

#define XR(k, c) tsi_desc_xr(d, (k), (c))
#define XT(l) TSI_XT(l)
#define XC(j) tsi_desc_xc(d, (j))

/* The vehicle point a link leaves from (at its point P), -1. */
static int link_vp(const ts_descriptor *d, int l)
{
    const ts_link *L = &d->sys->links[l];
    if (L->up_body < 0)
        return -1;
    for (int v = 0; v < d->nv; v++)
        if (d->vl[v].node == L->upper)
            return d->nn + v;
    return -1;
}

/* Columns of a vehicle's local block that S holds (its node's
 * displacement, its angles, its controller states): unknown of local
 * column lc, -1 for the rates and inputs. */
static int lv_unknown(const ts_descriptor *d, int v, int lc)
{
    const tsi_vehicle_layout *L = &d->vl[v];
    if (lc < TSI_LV_TH)
        return XR(L->node, lc);
    if (lc < TSI_LV_V)
        return XR(d->nn + v, lc - TSI_LV_TH);
    if (lc < TSI_LV_C)
        return -1;
    if (lc < TSI_LV_C + L->nc)
        return XC(L->c0 + lc - TSI_LV_C);
    return -1;
}

/* Row of a vehicle's local block: its node's force rows, its rotational
 * rows, its controller rows. */
static int lv_row(const ts_descriptor *d, int v, int lr)
{
    const tsi_vehicle_layout *L = &d->vl[v];
    if (lr < 3)
        return XR(L->node, lr);
    if (lr < 6)
        return XR(d->nn + v, lr - 3);
    return XC(L->c0 + lr - 6);
}

static int build_pattern(ts_descriptor *d)
{
    const ts_system *sys = d->sys;
    int nl = d->nl;
    size_t nlv = d->lvp_off[d->nv];
    size_t cap = 9 * (size_t)d->nblocks + 19 * (size_t)nl + nlv;
    entry *e = malloc((cap > 0 ? cap : 1) * sizeof *e);
    /* Tags index d->pos: [9 nblocks] blocks, then [6 nl] tension columns
     * of the node rows, [6 nl] link rows on positions, [nl] diagonals,
     * [3 nl] tension columns of rotational rows, [3 nl] link rows on a
     * vehicle's angles, then the local blocks. */
    size_t npos = cap;
    d->pos = malloc((npos > 0 ? npos : 1) * sizeof(int));
    if (!e || !d->pos) {
        free(e);
        return TS_ENOMEM;
    }
    for (size_t i = 0; i < npos; i++)
        d->pos[i] = -1;
    d->pos_blk = d->pos;
    d->pos_n = d->pos + 9 * (size_t)d->nblocks;
    d->pos_row = d->pos_n + 6 * (size_t)nl;
    d->pos_diag = d->pos_row + 6 * (size_t)nl;
    d->pos_pm = d->pos_diag + nl;
    d->pos_pg = d->pos_pm + 3 * (size_t)nl;
    d->pos_lv = d->pos_pg + 3 * (size_t)nl;
    size_t m = 0;
    for (int k = d->p0; k < d->np; k++)
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b];
            if (j < d->p0)
                continue;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++)
                    e[m++] = (entry){XR(j, c), XR(k, a), 9 * b + 3 * a + c};
        }
    int base_n = 9 * d->nblocks, base_row = base_n + 6 * nl,
        base_diag = base_row + 6 * nl, base_pm = base_diag + nl,
        base_pg = base_pm + 3 * nl, base_lv = base_pg + 3 * nl;
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &sys->links[l];
        int vp = link_vp(d, l);
        for (int c = 0; c < 3; c++) {
            e[m++] = (entry){XT(l), XR(L->lower, c), base_n + 6 * l + c};
            e[m++] = (entry){XR(L->lower, c), XT(l), base_row + 6 * l + c};
            if (L->upper >= d->p0) {
                e[m++] = (entry){XT(l), XR(L->upper, c),
                                 base_n + 6 * l + 3 + c};
                e[m++] = (entry){XR(L->upper, c), XT(l),
                                 base_row + 6 * l + 3 + c};
            }
            if (vp >= 0) {
                e[m++] = (entry){XT(l), XR(vp, c), base_pm + 3 * l + c};
                e[m++] = (entry){XR(vp, c), XT(l), base_pg + 3 * l + c};
            }
        }
        e[m++] = (entry){XT(l), XT(l), base_diag + l};
    }
    /* The local blocks: the controller columns of the force and
     * rotational rows, the controller rows on the node's displacement,
     * the angles and the controller states (the diagonal always: s). */
    for (int v = 0; v < d->nv; v++) {
        int nr = 6 + d->vl[v].nc, p0 = d->lvp_off[v];
        for (int lr = 0; lr < nr; lr++)
            for (int c = 0; c < nr; c++) {
                int lc = c < 6 ? c : TSI_LV_C + c - 6;
                if (lr < 6 && c < 6)
                    continue; /* the point blocks' */
                e[m++] = (entry){lv_unknown(d, v, lc), lv_row(d, v, lr),
                                 base_lv + p0 + nr * lr + c};
            }
    }
    if (sort_entries(e, m, d->nx) != TS_OK) {
        free(e);
        return TS_ENOMEM;
    }
    d->nnz = (int)m;
    d->Sp = calloc((size_t)d->nx + 1, sizeof(int));
    d->Si = malloc((m > 0 ? m : 1) * sizeof(int));
    if (!d->Sp || !d->Si) {
        free(e);
        return TS_ENOMEM;
    }
    for (size_t i = 0; i < m; i++) {
        d->Si[i] = e[i].row;
        d->Sp[e[i].col + 1]++;
        d->pos[e[i].tag] = (int)i;
    }
    for (int c = 0; c < d->nx; c++)
        d->Sp[c + 1] += d->Sp[c];
    free(e);
    return TS_OK;
}

/* Whether the vehicles' controller states and inputs are disjoint
 * blocks that, with the tow inputs, cover every one (each vehicle's
 * local block then holds its own alone). */
static int layouts_disjoint(const ts_descriptor *d)
{
    int nc = 0, nin = TS_NINPUT;
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *A = &d->vl[v];
        nc += A->nc;
        nin += A->nin;
        for (int u = 0; u < v; u++) {
            const tsi_vehicle_layout *B = &d->vl[u];
            if (A->nc > 0 && B->nc > 0 && A->c0 < B->c0 + B->nc &&
                B->c0 < A->c0 + A->nc)
                return 0;
            if (A->nin > 0 && B->nin > 0 && A->in0 < B->in0 + B->nin &&
                B->in0 < A->in0 + A->nin)
                return 0;
        }
    }
    return nc == d->nc && nin == d->nin;
}

/* The perturbation groups but the frame inputs': the colours' times x,
 * y, z, the controller states' and inputs', a towing vehicle's tow
 * inputs. */
static int base_groups(const ts_descriptor *d)
{
    return 3 * (d->nrcolour + d->nvcolour) + d->ncgroups + d->nugroups +
           (d->root >= 0 ? TS_NINPUT : 0);
}

ts_descriptor *tsi_desc_alloc(const ts_kernel *kern, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(kern);
    ts_descriptor *d = calloc(1, sizeof *d);
    if (!d) {
        ts_fail(err, TS_ENOMEM, "descriptor: out of memory");
        return NULL;
    }
    /* KLU orders the pattern below and factors every shift of it. */
    if (tsi_klu_open(&d->klu, err) != TS_OK) {
        free(d);
        return NULL;
    }
    int nn = sys->nnodes, nl = sys->nlinks, nv = ts_kernel_nvehicles(kern);
    d->sys = sys;
    d->nn = nn;
    d->nl = nl;
    d->nv = nv;
    d->np = nn + nv;
    d->nq = ts_kernel_nq(kern);
    d->nstate = ts_kernel_nstate(kern);
    d->nc = ts_kernel_ncontrol(kern);
    d->nin = ts_kernel_ninput(kern);
    d->root = ts_kernel_root(kern);
    d->rdof = d->root >= 0 ? ts_kernel_root_dof(kern) : 0;
    d->p0 = d->root >= 0 ? 0 : 1;
    d->nx = 4 * (nn - 1) + 3 * nv + d->nc + (d->root >= 0 ? 3 : 0);
    size_t snp = (size_t)d->np, snl = (size_t)(nl > 0 ? nl : 1);
    size_t snv = (size_t)(nv > 0 ? nv : 1);
    int dist_r = sys->has_bending ? 2 : 1;
    ball_ws w = {0};
    w.stamp = calloc(snp, sizeof(int));
    w.dist = calloc(snp, sizeof(int));
    w.queue = malloc(snp * sizeof(int));
    w.adj = malloc(snp * sizeof(int));
    int *node_vp = malloc((size_t)nn * sizeof(int));
    w.node_vp = node_vp;
    int *buf = malloc(snp * sizeof(int)), *bd = malloc(snp * sizeof(int));
    d->vl = calloc(snv, sizeof *d->vl);
    d->lv_off = calloc(snv + 1, sizeof(int));
    d->lvp_off = calloc(snv + 1, sizeof(int));
    d->ov_off = calloc(snv + 1, sizeof(int));
    d->r0 = calloc(3 * snp, sizeof(double));
    d->v0 = calloc(3 * snp, sizeof(double));
    d->a0 = calloc(3 * snp, sizeof(double));
    d->t0 = calloc(snl, sizeof(double));
    d->y0 = calloc((size_t)d->nstate + 1, sizeof(double));
    d->u0 = calloc((size_t)d->nin + 1, sizeof(double));
    d->M = calloc(6 * (size_t)nn, sizeof(double));
    d->Mv = calloc(36 * snv, sizeof(double));
    d->pg = calloc(3 * snl, sizeof(double));
    d->pm = calloc(3 * snl, sizeof(double));
    d->n = calloc(3 * snl, sizeof(double));
    d->len = calloc(snl, sizeof(double));
    d->ka = calloc(snl, sizeof(double));
    d->ca = calloc(snl, sizeof(double));
    d->kind = calloc(snl, 1);
    d->bptr = calloc(snp + 1, sizeof(int));
    d->rcolour = malloc(snp * sizeof(int));
    d->vcolour = malloc(snp * sizeof(int));
    d->hr = calloc(3 * snp, sizeof(double));
    d->hv = calloc(3 * snp, sizeof(double));
    d->hc = calloc((size_t)d->nc + 1, sizeof(double));
    d->hu = calloc((size_t)d->nin + 1, sizeof(double));
    int ok = w.stamp && w.dist && w.queue && w.adj && node_vp && buf && bd &&
             d->vl && d->lv_off && d->lvp_off && d->ov_off && d->r0 && d->v0 && d->a0 &&
             d->t0 && d->y0 && d->u0 && d->M && d->Mv && d->pg && d->pm &&
             d->n && d->len && d->ka && d->ca && d->kind && d->bptr &&
             d->rcolour && d->vcolour && d->hr && d->hv && d->hc && d->hu;
    for (int i = 0; ok && i < nn; i++)
        node_vp[i] = -1;
    for (int v = 0; ok && v < nv; v++) {
        tsi_vehicle_layout *L = &d->vl[v];
        tsi_kernel_vehicle_layout(kern, v, L);
        node_vp[L->node] = nn + v;
        int nr = 6 + L->nc;
        d->lv_off[v + 1] = d->lv_off[v] + nr * (TSI_LV_C + L->nc + L->nin);
        d->lvp_off[v + 1] = d->lvp_off[v] + nr * nr;
        d->ov_off[v + 1] =
            d->ov_off[v] + L->nout * (TSI_LV_C + L->nc + L->nin);
        d->nout += L->nout;
        if (L->nc > d->ncgroups)
            d->ncgroups = L->nc;
        if (L->nin > d->nugroups)
            d->nugroups = L->nin;
    }
    int disjoint = !ok || layouts_disjoint(d);
    ok = ok && disjoint;
    if (ok && d->root >= 0) {
        size_t ng = TS_NINPUT * (3 * snp + (size_t)d->nc);
        d->Gt = calloc(ng, sizeof(double));
        ok = d->Gt != NULL;
    } else if (ok) {
        size_t ng = TS_NFRAME_INPUT * (3 * snp + (size_t)d->nc);
        d->Gf = calloc(ng, sizeof(double));
        ok = d->Gf != NULL;
    }
    if (ok) {
        d->Lv = calloc((size_t)d->lv_off[nv] + 1, sizeof(double));
        d->Ov = calloc((size_t)d->ov_off[nv] + 1, sizeof(double));
        ok = d->Lv && d->Ov;
    }
    /* Blocks: every point's ball of radius dist_r, sorted. */
    for (int k = 0; ok && k < d->np; k++)
        d->bptr[k + 1] = d->bptr[k] + ball(d, &w, k, dist_r, buf, NULL);
    if (ok) {
        d->nblocks = d->bptr[d->np];
        size_t nb = (size_t)d->nblocks;
        d->bcol = malloc(nb * sizeof(int));
        d->btr = malloc(nb * sizeof(int));
        d->bdist = malloc(nb);
        d->K = calloc(9 * nb, sizeof(double));
        d->C = calloc(9 * nb, sizeof(double));
        ok = d->bcol && d->btr && d->bdist && d->K && d->C;
    }
    for (int k = 0; ok && k < d->np; k++) {
        int m = ball(d, &w, k, dist_r, buf, bd);
        /* Insertion sort by point (balls are small). */
        for (int i = 1; i < m; i++)
            for (int j = i; j > 0 && buf[j - 1] > buf[j]; j--) {
                int t = buf[j];
                buf[j] = buf[j - 1];
                buf[j - 1] = t;
                t = bd[j];
                bd[j] = bd[j - 1];
                bd[j - 1] = t;
            }
        for (int i = 0; i < m; i++) {
            d->bcol[d->bptr[k] + i] = buf[i];
            d->bdist[d->bptr[k] + i] = (char)bd[i];
        }
    }
    /* The transpose of every block, by binary search in j's sorted row. */
    for (int k = 0; ok && k < d->np; k++)
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b], lo = d->bptr[j], hi = d->bptr[j + 1] - 1;
            while (lo < hi) {
                int mid = (lo + hi) / 2;
                if (d->bcol[mid] < k)
                    lo = mid + 1;
                else
                    hi = mid;
            }
            d->btr[b] = lo;
        }
    if (ok) {
        d->nrcolour = colour_tree(d, &w, 2 * dist_r, d->rcolour, buf);
        d->nvcolour = colour_tree(d, &w, 2, d->vcolour, buf);
        ok = d->nrcolour > 0 && d->nvcolour > 0;
    }
    if (ok)
        ok = build_pattern(d) == TS_OK;
    /* KLU's ordering (block triangular form, then AMD on each block) of
     * the pattern, once: every shift and every Jacobian of the run share
     * it. */
    if (ok) {
        klu_common *kc = malloc(sizeof *kc);
        d->klu_common = kc;
        ok = kc && d->klu.klu_defaults(kc);
        /* With a towing vehicle (node 0 free) AMD's symmetric ordering,
         * made for pivots on the diagonal, let partial pivoting leave the
         * rigid links' tension columns (zero on the diagonal) down the
         * whole cable: on dolphin_aurora at 100 links the factors held
         * 105 000 entries against S's 4384. COLAMD orders the columns
         * for any row pivots: 7600 to 8800 there. */
        if (ok && d->root >= 0)
            kc->ordering = 1;
        if (ok && d->nx > 0) {
            d->klu_symbolic = d->klu.klu_analyze(d->nx, d->Sp, d->Si, kc);
            ok = d->klu_symbolic != NULL;
        }
    }
    free(w.stamp);
    free(w.dist);
    free(w.queue);
    free(w.adj);
    free(node_vp);
    free(buf);
    free(bd);
    if (!ok) {
        tsi_desc_free(d);
        if (!disjoint)
            ts_fail(err, TS_EINVAL, "descriptor: a vehicle's controller "
                    "states or inputs are not one block of its own");
        else
            ts_fail(err, TS_ENOMEM, "descriptor: out of memory for %d "
                    "links", nl);
        return NULL;
    }
    d->groups = base_groups(d);
    return d;
}

/* ---- Coloured central differences --------------------------------------- */

double tsi_frame_input_scale(const ts_system *sys, const ts_frame *fr, int c)
{
    double g = sys->env.gravity > 0 ? sys->env.gravity : 1.0;
    double V = fabs(fr->speed);
    double l0 = sys->nlinks > 0 ? sys->links[0].length : 1.0;
    double reach = ts_system_reach(sys);
    if (!(reach > 0))
        reach = 1.0;
    switch (c) {
    case TS_FRAME_SPEED: return sqrt(g * l0) + V;           /* m/s */
    case TS_FRAME_TURN_RATE: return (sqrt(g * l0) + V) / reach; /* rad/s */
    case TS_FRAME_SPEED_RATE: return g;                     /* m/s^2 */
    default: return g / reach;                              /* rad/s^2 */
    }
}


/* The step rel * scale, rounded so that x + h is exact (then
 * (x + h) - x == h). */
static double step_for(double x, double scale, double rel)
{
    double h = rel * scale;
    volatile double t = x + h;
    return t - x;
}

/* Per-thread work. */
typedef struct grp_ws {
    ts_kernel *k;
    double *r, *v;     /* [3 np] perturbed copies */
    double *y, *u;     /* [nstate], [nin] the state (vehicle angles, rates,
                          controller states) and inputs */
    double *thdd;      /* [3 nv] angle accelerations */
    double *R[4];      /* [3 np + nc] residuals at +h, -h, +2h, -2h */
    double *O[4];      /* [nout] the vehicles' outputs there */
} grp_ws;

static void grp_ws_free(grp_ws *w, const ts_kernel *owner)
{
    if (w->k && w->k != owner)
        ts_kernel_free(w->k);
    free(w->r);
    free(w->v);
    free(w->y);
    free(w->u);
    free(w->thdd);
    for (int i = 0; i < 4; i++) {
        free(w->R[i]);
        free(w->O[i]);
    }
}

static int grp_ws_alloc(grp_ws *w, ts_kernel *k, int own, const ts_descriptor *d)
{
    size_t n3 = 3 * (size_t)d->np, nr = n3 + (size_t)d->nc;
    memset(w, 0, sizeof *w);
    w->k = own ? k : ts_kernel_clone(k, NULL);
    w->r = malloc(n3 * sizeof(double));
    w->v = malloc(n3 * sizeof(double));
    w->y = malloc(((size_t)d->nstate + 1) * sizeof(double));
    w->u = malloc(((size_t)d->nin + 1) * sizeof(double));
    w->thdd = malloc((3 * (size_t)d->nv + 1) * sizeof(double));
    int ok = w->k && w->r && w->v && w->y && w->u && w->thdd;
    for (int i = 0; i < 4; i++) {
        ok = ok && (w->R[i] = malloc(nr * sizeof(double)));
        ok = ok && (w->O[i] = malloc(((size_t)d->nout + 1) * sizeof(double)));
    }
    if (!ok)
        return TS_ENOMEM;
    memcpy(w->r, d->r0, n3 * sizeof(double));
    memcpy(w->v, d->v0, n3 * sizeof(double));
    memcpy(w->y, d->y0, (size_t)d->nstate * sizeof(double));
    memcpy(w->u, d->u0, (size_t)d->nin * sizeof(double));
    return TS_OK;
}

/* The residual at the points' positions r and velocities pv[3 np] (the
 * vehicles' angles and rates into y), the controller states and inputs
 * of y and u. */
static int residual_at(const ts_descriptor *d, ts_kernel *k, const double *r,
                       const double *pv, double *y, const double *u,
                       double *thdd, double *R)
{
    for (int v = 0; v < d->nv; v++) {
        int o = d->vl[v].qoff;
        for (int c = 0; c < 3; c++) {
            thdd[3 * v + c] = d->a0[3 * (d->nn + v) + c];
            /* A surface ship's one angle is its yaw (its roll and pitch
             * are held at 0). */
            if (v == d->root && d->rdof == 3 && c < 2)
                continue;
            int q = v == d->root && d->rdof == 3 ? o : o + c;
            y[q] = r[3 * (d->nn + v) + c];
            y[d->nq + q] = pv[3 * (d->nn + v) + c];
        }
    }
    return tsi_kernel_residual(k, r, pv, d->a0, d->t0, d->nv > 0 ? y : NULL,
                               d->nv > 0 ? thdd : NULL, u, R);
}

/* The vehicle whose node or angles point j is: its index, with *col its
 * local column of a displacement (TSI_LV_R or TSI_LV_TH); -1. */
static int point_vehicle(const ts_descriptor *d, int j, int *col)
{
    if (j >= d->nn) {
        *col = TSI_LV_TH;
        return j - d->nn;
    }
    for (int v = 0; v < d->nv; v++)
        if (d->vl[v].node == j) {
            *col = TSI_LV_R;
            return v;
        }
    return -1;
}

/* Central difference of row i between the residuals at +-h (and +-2h):
 * into *D, and its truncation estimate into *E when E. */
static void central(double *const R[4], size_t i, double h, double *D,
                    double *E)
{
    double dh = (R[0][i] - R[1][i]) / (2.0 * h);
    *D = dh;
    if (E)
        *E = ((R[2][i] - R[3][i]) / (4.0 * h) - dh) / 3.0;
}

/* The residual (and the vehicles' outputs) of evaluation s of a group. */
static int group_eval(const ts_descriptor *d, grp_ws *w, int s)
{
    int rc = residual_at(d, w->k, w->r, w->v, w->y, w->u, w->thdd, w->R[s]);
    if (rc == TS_OK && d->nout > 0)
        ts_kernel_outputs(w->k, w->O[s]);
    return rc;
}

/* The output rows of vehicle v at local column lc, step h. */
static void output_column(ts_descriptor *d, const grp_ws *w, int v, int lc,
                          double h)
{
    const tsi_vehicle_layout *L = &d->vl[v];
    int ncol = TSI_LV_C + L->nc + L->nin;
    for (int r = 0; r < L->nout; r++) {
        size_t at = (size_t)d->ov_off[v] + (size_t)r * ncol + lc;
        central(w->O, (size_t)(L->out0 + r), h, d->Ov + at,
                d->Oerr ? d->Oerr + at : NULL);
    }
}

static const double mult[4] = {1.0, -1.0, 2.0, -2.0};

/* A group of controller states (kind 2) or inputs (kind 3): local index
 * m of every vehicle that has one, perturbed together (each reaches its
 * own vehicle's rows only). */
static int local_group(ts_descriptor *d, grp_ws *w, int kind, int m,
                       int estimate)
{
    int nev = estimate ? 4 : 2, rc = TS_OK;
    size_t n3 = 3 * (size_t)d->np;
    for (int s = 0; s < nev && rc == TS_OK; s++) {
        for (int v = 0; v < d->nv; v++) {
            const tsi_vehicle_layout *L = &d->vl[v];
            if (kind == 2 && m < L->nc) {
                int j = 2 * d->nq + L->c0 + m;
                w->y[j] = d->y0[j] + mult[s] * d->hc[L->c0 + m];
            } else if (kind == 3 && m < L->nin) {
                int j = L->in0 + m;
                w->u[j] = d->u0[j] + mult[s] * d->hu[j];
            }
        }
        rc = group_eval(d, w, s);
    }
    memcpy(w->y, d->y0, (size_t)d->nstate * sizeof(double));
    memcpy(w->u, d->u0, (size_t)d->nin * sizeof(double));
    if (rc != TS_OK)
        return rc;
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *L = &d->vl[v];
        if (m >= (kind == 2 ? L->nc : L->nin))
            continue;
        int nr = 6 + L->nc, ncol = TSI_LV_C + L->nc + L->nin;
        int lc = kind == 2 ? TSI_LV_C + m : TSI_LV_C + L->nc + m;
        double h = kind == 2 ? d->hc[L->c0 + m] : d->hu[L->in0 + m];
        for (int lr = 0; lr < nr; lr++) {
            size_t i = lr < 3 ? 3 * (size_t)L->node + lr
                       : lr < 6 ? 3 * (size_t)(d->nn + v) + lr - 3
                                : n3 + (size_t)(L->c0 + lr - 6);
            size_t at = (size_t)d->lv_off[v] + (size_t)lr * ncol + lc;
            central(w->R, i, h, d->Lv + at, d->Lerr ? d->Lerr + at : NULL);
        }
        output_column(d, w, v, lc, h);
    }
    return TS_OK;
}

/* A whole-row input's column (a tow input's of Gt, a frame input's of
 * Gf) and its estimate E (or NULL) from the group's evaluations at step
 * h: every row. */
static void row_column(const ts_descriptor *d, const grp_ws *w, double h,
                       double *G, double *E)
{
    size_t nrow = 3 * (size_t)d->np + (size_t)d->nc;
    for (size_t i = 0; i < nrow; i++)
        central(w->R, i, h, G + i, E ? E + i : NULL);
}

/* A towing vehicle's tow input j alone: its column of Gt over every row
 * (the points stay; what the input moves, the residual says). */
static int tow_group(ts_descriptor *d, grp_ws *w, int j, int estimate)
{
    int nev = estimate ? 4 : 2, rc = TS_OK;
    for (int s = 0; s < nev && rc == TS_OK; s++) {
        w->u[j] = d->u0[j] + mult[s] * d->hu[j];
        rc = group_eval(d, w, s);
    }
    w->u[j] = d->u0[j];
    if (rc != TS_OK)
        return rc;
    size_t nrow = 3 * (size_t)d->np + (size_t)d->nc;
    row_column(d, w, d->hu[j], d->Gt + (size_t)j * nrow,
               d->Gterr ? d->Gterr + (size_t)j * nrow : NULL);
    return TS_OK;
}

/* Frame input c alone (towstab/linearize.h: the mean frame's speed, turn
 * rate, their rates): its column of Gf over every row, the frame moved
 * in the group's kernel for the evaluations (the points stay). */
static int frame_group(ts_descriptor *d, grp_ws *w, int c, int estimate)
{
    int nev = estimate ? 4 : 2, rc = TS_OK;
    ts_frame base, fr;
    ts_kernel_get_frame(w->k, &base);
    for (int s = 0; s < nev && rc == TS_OK; s++) {
        fr = base;
        double h = mult[s] * d->hf[c];
        if (c == TS_FRAME_SPEED)
            fr.speed += h;
        else if (c == TS_FRAME_TURN_RATE)
            fr.turn_rate += h;
        else if (c == TS_FRAME_SPEED_RATE)
            fr.speed_rate += h;
        else
            fr.turn_accel += h;
        ts_kernel_set_frame(w->k, &fr);
        rc = group_eval(d, w, s);
    }
    ts_kernel_set_frame(w->k, &base);
    if (rc != TS_OK)
        return rc;
    size_t nrow = 3 * (size_t)d->np + (size_t)d->nc;
    row_column(d, w, d->hf[c], d->Gf + (size_t)c * nrow,
               d->Gferr ? d->Gferr + (size_t)c * nrow : NULL);
    return TS_OK;
}

/* Group g: kind (0 position, 1 velocity), colour, component; after them
 * the controller and input groups, then a towing vehicle's tow inputs or
 * the frame inputs. Evaluates the residual at the
 * perturbed states and writes the columns of the group's points into K
 * or C, and the controller rows' (and the error estimate). */
static int group(ts_descriptor *d, grp_ws *w, int g, int estimate)
{
    int nr = 3 * d->nrcolour, nv3 = 3 * d->nvcolour;
    int nlocal = d->ncgroups + d->nugroups;
    if (g >= nr + nv3 + nlocal)
        return d->root >= 0
                   ? tow_group(d, w, g - nr - nv3 - nlocal, estimate)
                   : frame_group(d, w, g - nr - nv3 - nlocal, estimate);
    if (g >= nr + nv3) {
        int m = g - nr - nv3;
        return m < d->ncgroups ? local_group(d, w, 2, m, estimate)
                               : local_group(d, w, 3, m - d->ncgroups,
                                             estimate);
    }
    int kind = g < nr ? 0 : 1, gg = g < nr ? g : g - nr;
    int colour = gg / 3, comp = gg % 3;
    const int *col = kind ? d->vcolour : d->rcolour;
    const double *h = kind ? d->hv : d->hr;
    double *x = kind ? w->v : w->r;
    int nev = estimate ? 4 : 2, rc = TS_OK;
    size_t n3 = 3 * (size_t)d->np;
    for (int s = 0; s < nev && rc == TS_OK; s++) {
        for (int j = 0; j < d->np; j++)
            if (col[j] == colour)
                x[3 * j + comp] = (kind ? d->v0 : d->r0)[3 * j + comp] +
                                  mult[s] * h[3 * j + comp];
        rc = group_eval(d, w, s);
    }
    for (int j = 0; j < d->np; j++)
        if (col[j] == colour)
            x[3 * j + comp] = (kind ? d->v0 : d->r0)[3 * j + comp];
    if (rc != TS_OK)
        return rc;
    double *D = kind ? d->C : d->K, *E = kind ? d->Cerr : d->Kerr;
    for (int j = 0; j < d->np; j++) {
        if (col[j] != colour)
            continue;
        double hj = h[3 * j + comp];
        for (int b = d->bptr[j]; b < d->bptr[j + 1]; b++) {
            int k = d->bcol[b];
            if (k < d->p0)
                continue;
            /* A velocity reaches one link only: farther blocks of C are
             * zero, and their rows may see another point of the colour. */
            double *blk = D + 9 * (size_t)d->btr[b];
            double *eblk = E ? E + 9 * (size_t)d->btr[b] : NULL;
            int far = kind && d->bdist[b] > 1;
            for (int a = 0; a < 3; a++) {
                double dh = 0.0, eh = 0.0;
                if (!far)
                    central(w->R, 3 * (size_t)k + a, hj, &dh,
                            eblk ? &eh : NULL);
                blk[3 * a + comp] = dh;
                if (eblk)
                    eblk[3 * a + comp] = eh;
            }
        }
        /* The controller rows of the vehicle at this point. */
        int lc0, v = point_vehicle(d, j, &lc0);
        if (v < 0)
            continue;
        const tsi_vehicle_layout *L = &d->vl[v];
        int ncol = TSI_LV_C + L->nc + L->nin;
        int lc = lc0 + comp + (kind ? TSI_LV_V : 0);
        for (int m = 0; m < L->nc; m++) {
            size_t at = (size_t)d->lv_off[v] + (size_t)(6 + m) * ncol + lc;
            central(w->R, n3 + (size_t)(L->c0 + m), hj, d->Lv + at,
                    d->Lerr ? d->Lerr + at : NULL);
        }
        output_column(d, w, v, lc, hj);
    }
    return TS_OK;
}

#define NOISE_SAMPLES 8
#define NOISE_REL 1e-4

/* out[nout] = Ov z over the vehicles' local columns: the point
 * displacements p and rates pv (may be NULL) and the controller states c
 * (may be NULL); inputs zero. */
static void outputs_mul(const ts_descriptor *d, const double *p,
                        const double *pv, const double *c, double *out)
{
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *L = &d->vl[v];
        int ncol = TSI_LV_C + L->nc + L->nin;
        for (int r = 0; r < L->nout; r++) {
            const double *row = d->Ov + d->ov_off[v] + r * ncol;
            double acc = 0;
            for (int lc = 0; lc < 6; lc++) {
                int i = lc < 3 ? 3 * L->node + lc : 3 * (d->nn + v) + lc - 3;
                acc += row[lc] * p[i] + (pv ? row[TSI_LV_V + lc] * pv[i] : 0);
            }
            for (int m = 0; c && m < L->nc; m++)
                acc += row[TSI_LV_C + m] * c[L->c0 + m];
            out[L->out0 + r] = acc;
        }
    }
}

/* The residual's rounding noise d->rnoise (see the head of the file),
 * and the outputs' d->onoise. Needs K, C and the local blocks. */
static int residual_noise(ts_descriptor *d, ts_kernel *k)
{
    size_t n3 = 3 * (size_t)d->np, nr = n3 + (size_t)d->nc;
    size_t nc = (size_t)d->nc;
    double *r = malloc(n3 * sizeof *r), *v = malloc(n3 * sizeof *v);
    double *dr = malloc(n3 * sizeof *dr), *dv = malloc(n3 * sizeof *dv);
    double *R0 = malloc(nr * sizeof *R0), *R = malloc(nr * sizeof *R);
    double *f = malloc(nr * sizeof *f), *acc = calloc(nr, sizeof *acc);
    double *y = malloc(((size_t)d->nstate + 1) * sizeof *y);
    double *dc = malloc((nc + 1) * sizeof *dc);
    double *thdd = malloc((3 * (size_t)d->nv + 1) * sizeof *thdd);
    size_t no = (size_t)d->nout + 1;
    double *O0 = malloc(no * sizeof *O0), *O = malloc(no * sizeof *O);
    double *Of = malloc(no * sizeof *Of), *oacc = calloc(no, sizeof *oacc);
    int rc = r && v && dr && dv && R0 && R && f && acc && y && dc && thdd &&
                     O0 && O && Of && oacc
                 ? TS_OK
                 : TS_ENOMEM;
    if (rc == TS_OK) {
        memcpy(y, d->y0, (size_t)d->nstate * sizeof *y);
        rc = residual_at(d, k, d->r0, d->v0, y, d->u0, thdd, R0);
        if (d->nout > 0)
            ts_kernel_outputs(k, O0);
    }
    unsigned long long seq = 0x9E3779B97F4A7C15ULL;
    int used = 0;
    for (int s = 0; rc == TS_OK && s < NOISE_SAMPLES; s++) {
        for (size_t i = 0; i < 2 * n3 + nc; i++) {
            seq = seq * 6364136223846793005ULL + 1442695040888963407ULL;
            double sg = seq >> 63 ? 1.0 : -1.0;
            if (i >= 2 * n3) {
                size_t j = i - 2 * n3, yj = 2 * (size_t)d->nq + j;
                y[yj] = d->y0[yj] + sg * NOISE_REL * d->hc[j];
                dc[j] = y[yj] - d->y0[yj];
                continue;
            }
            size_t j = i < n3 ? i : i - n3;
            double *x = i < n3 ? r : v, *dx = i < n3 ? dr : dv;
            const double *x0 = i < n3 ? d->r0 : d->v0;
            /* A prescribed tow point stays: at the waterline its columns
             * are kinked (counted as kink_tow), not noisy. */
            double h = j < 3 && d->root < 0 ? 0.0 : (i < n3 ? d->hr : d->hv)[j];
            x[j] = x0[j] + sg * NOISE_REL * h;
            dx[j] = x[j] - x0[j]; /* exactly what was added */
        }
        if (residual_at(d, k, r, v, y, d->u0, thdd, R) != TS_OK)
            continue; /* a state off the chart: another sample */
        tsi_desc_block_mul(d, d->K, dr, f, 0);
        tsi_desc_block_mul(d, d->C, dv, f, 1);
        tsi_desc_local_mul(d, dr, dv, dc, NULL, f + n3, f, 0);
        for (size_t i = 3 * (size_t)d->p0; i < nr; i++) {
            double e = R[i] - R0[i] - f[i];
            acc[i] += e * e;
        }
        if (d->nout > 0) {
            ts_kernel_outputs(k, O);
            outputs_mul(d, dr, dv, dc, Of);
            for (int i = 0; i < d->nout; i++) {
                double e = O[i] - O0[i] - Of[i];
                oacc[i] += e * e;
            }
        }
        used++;
    }
    if (rc == TS_OK && used == 0)
        rc = TS_ECONV;
    if (rc == TS_OK) {
        d->k_round = d->c_round = 0.0;
        for (size_t i = 0; i < nr; i++)
            d->rnoise[i] = sqrt(acc[i] / (2.0 * used));
        for (int i = 0; i < d->nout; i++)
            d->onoise[i] = sqrt(oacc[i] / (2.0 * used));
        for (int kk = d->p0; kk < d->np; kk++)
            for (int b = d->bptr[kk]; b < d->bptr[kk + 1]; b++) {
                int j = d->bcol[b];
                for (int a = 0; a < 3; a++)
                    for (int c = 0; c < 3; c++) {
                        double rho = d->rnoise[3 * kk + a] / sqrt(2.0);
                        d->k_round = fmax(d->k_round, rho / d->hr[3 * j + c]);
                        if (d->bdist[b] <= 1)
                            d->c_round =
                                fmax(d->c_round, rho / d->hv[3 * j + c]);
                    }
            }
    }
    free(r);
    free(v);
    free(dr);
    free(dv);
    free(R0);
    free(R);
    free(f);
    free(acc);
    free(y);
    free(dc);
    free(thdd);
    free(O0);
    free(O);
    free(Of);
    free(oacc);
    return rc;
}

static double abs2(double complex z)
{
    return creal(z) * creal(z) + cimag(z) * cimag(z);
}

/* Point displacement of a vehicle's local column lc < 6 in x[3 np]. */
static double complex lv_point(const ts_descriptor *d, int v, int lc,
                               const double complex *x, int *idx)
{
    int i = lc < 3 ? 3 * d->vl[v].node + lc : 3 * (d->nn + v) + lc - 3;
    *idx = i;
    return x[i];
}

void tsi_desc_error_terms(const ts_descriptor *d, const double complex w[],
                          const double complex x[], double complex s,
                          double *trunc, double *round)
{
    if (!d->Kerr || !d->Cerr || !d->rnoise || (d->nv > 0 && !d->Lerr)) {
        *trunc = *round = NAN;
        return;
    }
    double complex t = 0;
    double r2 = 0, as2 = abs2(s);
    const double complex *xc = x + 3 * (size_t)d->np;
    for (int k = d->p0; k < d->np; k++) {
        double complex e[3] = {0, 0, 0};
        double xk = 0;
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b];
            const double *Kb = d->Kerr + 9 * (size_t)b;
            const double *Cb = d->Cerr + 9 * (size_t)b;
            const double complex *xj = x + 3 * j;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++)
                    e[a] += (Kb[3 * a + c] + s * Cb[3 * a + c]) * xj[c];
            for (int c = 0; c < 3; c++) {
                double ax = abs2(xj[c]);
                double hr = d->hr[3 * j + c], hv = d->hv[3 * j + c];
                xk += ax / (hr * hr) + (d->bdist[b] <= 1 ? as2 * ax / (hv * hv)
                                                         : 0.0);
            }
        }
        /* A vehicle's force and rotational rows on its controller
         * states. */
        int lc0, v = point_vehicle(d, k, &lc0);
        if (v >= 0) {
            const tsi_vehicle_layout *L = &d->vl[v];
            int ncol = TSI_LV_C + L->nc + L->nin, lr0 = lc0 == TSI_LV_R ? 0 : 3;
            for (int m = 0; m < L->nc; m++) {
                double complex x_m = xc[L->c0 + m];
                double hc = d->hc[L->c0 + m];
                for (int a = 0; a < 3; a++)
                    e[a] += d->Lerr[d->lv_off[v] + (lr0 + a) * ncol +
                                    TSI_LV_C + m] * x_m;
                xk += abs2(x_m) / (hc * hc);
            }
        }
        double wk = 0;
        for (int a = 0; a < 3; a++) {
            double complex wa = w[XR(k, a)];
            t += wa * e[a];
            double rho = d->rnoise[3 * k + a];
            wk += abs2(wa) * rho * rho;
        }
        r2 += wk * xk;
    }
    /* Controller rows: -(dHr + s dHv) x_points - dHc x_c. */
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *L = &d->vl[v];
        int ncol = TSI_LV_C + L->nc + L->nin;
        for (int m = 0; m < L->nc; m++) {
            const double *row = d->Lerr + d->lv_off[v] + (6 + m) * ncol;
            double complex e = 0;
            double xk = 0;
            for (int lc = 0; lc < 6; lc++) {
                int i;
                double complex xp = lv_point(d, v, lc, x, &i);
                e += (row[lc] + s * row[lc + TSI_LV_V]) * xp;
                xk += abs2(xp) * (1.0 / (d->hr[i] * d->hr[i]) +
                                  as2 / (d->hv[i] * d->hv[i]));
            }
            for (int m2 = 0; m2 < L->nc; m2++) {
                double hc = d->hc[L->c0 + m2];
                e += row[TSI_LV_C + m2] * xc[L->c0 + m2];
                xk += abs2(xc[L->c0 + m2]) / (hc * hc);
            }
            double complex wm = w[XC(L->c0 + m)];
            double rho = d->rnoise[3 * (size_t)d->np + L->c0 + m];
            t -= wm * e;
            r2 += abs2(wm) * rho * rho * xk;
        }
    }
    *trunc = cabs(t);
    *round = sqrt(0.5 * r2);
}

double tsi_desc_motion_check(const ts_descriptor *d, double complex lam,
                             const double complex p[],
                             const double complex pv[],
                             const double complex c[])
{
    const int est = d->Kerr && d->Cerr && d->rnoise &&
                    (d->nv == 0 || d->Lerr);
    const double rt = 8.0 * DBL_EPSILON;
    size_t n3 = 3 * (size_t)d->np;
    double worst = 0;
    /* The inertia's part lam M pv, real and imaginary parts apart. */
    double *pr = malloc(4 * n3 * sizeof(double));
    if (!pr)
        return INFINITY;
    double *pi = pr + n3, *mr = pi + n3, *mi = mr + n3;
    for (size_t i = 0; i < n3; i++) {
        pr[i] = creal(pv[i]);
        pi[i] = cimag(pv[i]);
    }
    tsi_desc_mass_mul(d, pr, mr);
    tsi_desc_mass_mul(d, pi, mi);
#define RATIO(r_, a_)                                                         \
    do {                                                                      \
        double q_ = cabs(r_) > 0 ? cabs(r_) / (a_) : 0.0;                     \
        if (!(q_ <= worst))                                                   \
            worst = q_ == q_ ? q_ : INFINITY;                                 \
    } while (0)
    for (int k = d->p0; k < d->np; k++) {
        double complex r[3], mass[3];
        double size[3], err[3] = {0, 0, 0}, xk = 0;
        for (int a = 0; a < 3; a++) {
            mass[a] = lam * (mr[3 * k + a] + I * mi[3 * k + a]);
            r[a] = mass[a];
            size[a] = cabs(mass[a]);
        }
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b];
            const double *Kb = d->K + 9 * (size_t)b, *Cb = d->C + 9 * (size_t)b;
            for (int a = 0; a < 3; a++)
                for (int e = 0; e < 3; e++) {
                    int i = 3 * a + e;
                    double complex tk = Kb[i] * p[3 * j + e],
                                   tc = Cb[i] * pv[3 * j + e];
                    r[a] += tk + tc;
                    size[a] += cabs(tk) + cabs(tc);
                    if (est)
                        err[a] += fabs(d->Kerr[9 * (size_t)b + i]) *
                                      cabs(p[3 * j + e]) +
                                  fabs(d->Cerr[9 * (size_t)b + i]) *
                                      cabs(pv[3 * j + e]);
                }
            for (int e = 0; e < 3; e++) {
                double hr = d->hr[3 * j + e], hv = d->hv[3 * j + e];
                xk += cabs(p[3 * j + e]) / hr +
                      (d->bdist[b] <= 1 ? cabs(pv[3 * j + e]) / hv : 0.0);
            }
        }
        /* A vehicle's force and rotational rows on its controller
         * states. */
        int lc0, v = point_vehicle(d, k, &lc0);
        if (v >= 0 && c) {
            const tsi_vehicle_layout *L = &d->vl[v];
            int ncol = TSI_LV_C + L->nc + L->nin, lr0 = lc0 == TSI_LV_R ? 0 : 3;
            for (int m = 0; m < L->nc; m++) {
                double complex cm = c[L->c0 + m];
                for (int a = 0; a < 3; a++) {
                    size_t at = (size_t)d->lv_off[v] +
                                (size_t)(lr0 + a) * ncol + TSI_LV_C + m;
                    r[a] += d->Lv[at] * cm;
                    size[a] += cabs(d->Lv[at] * cm);
                    if (est)
                        err[a] += fabs(d->Lerr[at]) * cabs(cm);
                }
                xk += cabs(cm) / d->hc[L->c0 + m];
            }
        }
        for (int a = 0; a < 3; a++) {
            if (tsi_desc_held(d, k, a))
                continue;
            double allow = est ? err[a] + d->rnoise[3 * k + a] * xk / M_SQRT2
                               : 1e-6 * size[a];
            RATIO(r[a], allow + rt * size[a]);
        }
    }
    /* Controller rows: lam c - (Hr p + Hv pv + Hc c). */
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *L = &d->vl[v];
        int ncol = TSI_LV_C + L->nc + L->nin;
        for (int m = 0; m < L->nc; m++) {
            size_t at = (size_t)d->lv_off[v] + (size_t)(6 + m) * ncol;
            const double *row = d->Lv + at;
            const double *erow = est ? d->Lerr + at : NULL;
            double complex r = c ? lam * c[L->c0 + m] : 0.0;
            double size = cabs(r), err = 0, xk = 0;
            for (int lc = 0; lc < 6; lc++) {
                int i;
                double complex xp = lv_point(d, v, lc, p, &i),
                               xv = lv_point(d, v, lc, pv, &i);
                double complex t = row[lc] * xp + row[lc + TSI_LV_V] * xv;
                r -= t;
                size += cabs(row[lc] * xp) + cabs(row[lc + TSI_LV_V] * xv);
                if (erow)
                    err += fabs(erow[lc]) * cabs(xp) +
                           fabs(erow[lc + TSI_LV_V]) * cabs(xv);
                xk += cabs(xp) / d->hr[i] + cabs(xv) / d->hv[i];
            }
            for (int m2 = 0; c && m2 < L->nc; m2++) {
                double complex cm = c[L->c0 + m2];
                r -= row[TSI_LV_C + m2] * cm;
                size += cabs(row[TSI_LV_C + m2] * cm);
                if (erow)
                    err += fabs(erow[TSI_LV_C + m2]) * cabs(cm);
                xk += cabs(cm) / d->hc[L->c0 + m2];
            }
            double allow =
                est ? err + d->rnoise[n3 + L->c0 + m] * xk / M_SQRT2
                    : 1e-6 * size;
            RATIO(r, allow + rt * size);
        }
    }
#undef RATIO
    free(pr);
    return worst;
}

int tsi_desc_cut(const ts_descriptor *d, int root_qoff, const int comps[],
                 int m, ts_descriptor *out)
{
    *out = *d;
    out->ncut = 0;
    size_t nk = 9 * (size_t)d->nblocks;
    size_t nlv = d->nv > 0 ? (size_t)d->lv_off[d->nv] : 0;
    out->K = malloc((nk + 1) * sizeof(double));
    out->Lv = malloc((nlv + 1) * sizeof(double));
    if (!out->K || !out->Lv) {
        free(out->K);
        free(out->Lv);
        out->K = out->Lv = NULL;
        return TS_ENOMEM;
    }
    memcpy(out->K, d->K, nk * sizeof(double));
    if (nlv > 0)
        memcpy(out->Lv, d->Lv, nlv * sizeof(double));
    for (int t = 0; t < m && t < 2; t++) {
        int e = comps[t];
        out->cut[out->ncut] = root_qoff + e;
        out->cut_comp[out->ncut++] = e;
        /* Point rows: the translation's sum off the row's largest entry
         * on a translated (node) column. */
        for (int k = d->p0; k < d->np; k++)
            for (int a = 0; a < 3; a++) {
                if (tsi_desc_held(d, k, a))
                    continue;
                double sum = 0, big = -1;
                size_t at = 0;
                for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
                    if (d->bcol[b] >= d->nn)
                        continue;
                    size_t i = 9 * (size_t)b + 3 * (size_t)a + (size_t)e;
                    sum += out->K[i];
                    if (fabs(out->K[i]) > big) {
                        big = fabs(out->K[i]);
                        at = i;
                    }
                }
                if (big >= 0)
                    out->K[at] -= sum;
            }
        /* Controller rows: their entries on the vehicle's node. */
        for (int v = 0; v < d->nv; v++) {
            const tsi_vehicle_layout *L = &d->vl[v];
            int ncol = TSI_LV_C + L->nc + L->nin;
            for (int j = 0; j < L->nc; j++)
                out->Lv[(size_t)d->lv_off[v] + (size_t)(6 + j) * ncol +
                        TSI_LV_R + e] = 0.0;
        }
    }
    return TS_OK;
}

void tsi_desc_cut_free(ts_descriptor *cut)
{
    free(cut->K);
    free(cut->Lv);
    cut->K = cut->Lv = NULL;
    cut->ncut = 0;
}

/* A surface ship's held components (tsi_desc_held): their rows' K the
 * identity, their C, inertia, tension coefficients, local blocks, tow
 * input columns, errors and noise zero, so that every product with them
 * gives 0 there and S(s), S_inf hold them at 0. */
static void hold_rows(ts_descriptor *d)
{
    size_t n3 = 3 * (size_t)d->np, nrow = n3 + (size_t)d->nc;
    for (int k = 0; k < d->np; k++)
        for (int a = 0; a < 3; a++) {
            if (!tsi_desc_held(d, k, a))
                continue;
            for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++)
                for (int c = 0; c < 3; c++) {
                    size_t i = 9 * (size_t)b + 3 * (size_t)a + (size_t)c;
                    d->K[i] = d->bcol[b] == k && c == a ? 1.0 : 0.0;
                    d->C[i] = 0.0;
                    if (d->Kerr) {
                        d->Kerr[i] = 0.0;
                        d->Cerr[i] = 0.0;
                    }
                }
            size_t i = 3 * (size_t)k + (size_t)a;
            for (int j = 0; j < TS_NINPUT; j++) {
                d->Gt[(size_t)j * nrow + i] = 0.0;
                if (d->Gterr)
                    d->Gterr[(size_t)j * nrow + i] = 0.0;
            }
            if (d->rnoise)
                d->rnoise[i] = 0.0;
        }
    const tsi_vehicle_layout *L = &d->vl[d->root];
    int ncol = TSI_LV_C + L->nc + L->nin;
    double *Mv = d->Mv + 36 * d->root;
    /* Local rows: node 0's z (2), roll (3) and pitch (4). */
    static const int held_lr[3] = {2, 3, 4};
    for (int h = 0; h < 3; h++) {
        int lr = held_lr[h];
        for (int c = 0; c < 6; c++)
            Mv[6 * lr + c] = 0.0;
        for (int c = 0; c < ncol; c++) {
            d->Lv[d->lv_off[d->root] + lr * ncol + c] = 0.0;
            if (d->Lerr)
                d->Lerr[d->lv_off[d->root] + lr * ncol + c] = 0.0;
        }
    }
    for (int l = 0; l < d->nl; l++)
        if (d->sys->links[l].upper == 0)
            d->pm[3 * l] = d->pm[3 * l + 1] = 0.0;
}

int tsi_desc_linearize(ts_descriptor *d, ts_kernel *k, const double y0[],
                       const double u0[], const double f0[], double rel_step,
                       int estimate, int threads, ts_err *err)
{
    const ts_system *sys = d->sys;
    int nn = d->nn, nl = d->nl, np = d->np;
    size_t n3 = 3 * (size_t)nn, nr = 3 * (size_t)np + (size_t)d->nc;
    memcpy(d->r0, ts_kernel_positions(k), n3 * sizeof(double));
    memcpy(d->v0, ts_kernel_velocities(k), n3 * sizeof(double));
    memcpy(d->a0, ts_kernel_rel_accelerations(k), n3 * sizeof(double));
    memcpy(d->t0, ts_kernel_tensions(k), (size_t)nl * sizeof(double));
    memcpy(d->y0, y0, (size_t)d->nstate * sizeof(double));
    if (u0)
        memcpy(d->u0, u0, (size_t)d->nin * sizeof(double));
    else
        memset(d->u0, 0, (size_t)d->nin * sizeof(double));
    for (int v = 0; v < d->nv; v++) {
        int o = d->vl[v].qoff;
        for (int c = 0; c < 3; c++) {
            /* A surface ship: roll and pitch 0, its yaw at o. */
            int ship = v == d->root && d->rdof == 3;
            int q = ship ? o : o + c;
            int held = ship && c < 2;
            d->r0[3 * (nn + v) + c] = held ? 0.0 : y0[q];
            d->v0[3 * (nn + v) + c] = held ? 0.0 : y0[d->nq + q];
            d->a0[3 * (nn + v) + c] = held ? 0.0 : f0[d->nq + q];
        }
    }
    /* The kernel's link directions, not d / |d| of the positions: the maps
     * to and from the kernel's coordinates use the kernel's direction
     * derivatives, orthogonal to these to rounding (1e-16), while d / |d|
     * differs by eps |r| / |d|, which a stiff link's EA / l would turn
     * into a tension. */
    memcpy(d->n, ts_kernel_directions(k), 3 * (size_t)nl * sizeof(double));
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &sys->links[l];
        const double *rp = d->r0 + 3 * L->upper, *rk = d->r0 + 3 * L->lower;
        double dv[3] = {rk[0] - rp[0], rk[1] - rp[1], rk[2] - rp[2]};
        double len = sqrt(dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]);
        if (L->up_body >= 0)
            len = L->length; /* from P, which the kernel placed */
        if (!(len > 0))
            return ts_fail(err, TS_ESINGULAR, "descriptor: link %d has zero "
                           "length", l);
        d->len[l] = len;
        d->ka[l] = L->elastic ? L->ea / L->length : 0.0;
        d->ca[l] = L->elastic ? L->damping : 0.0;
        d->kind[l] = !L->elastic ? TSI_LINK_RIGID
                     : d->t0[l] > 0 ? TSI_LINK_TAUT : TSI_LINK_SLACK;
    }
    size_t nlv = (size_t)d->lv_off[d->nv] + 1;
    size_t nov = (size_t)d->ov_off[d->nv] + 1;
    size_t ngt = d->root >= 0 ? TS_NINPUT * nr : 0;
    size_t ngf = d->root >= 0 ? 0 : TS_NFRAME_INPUT * nr;
    if (estimate && (!d->Kerr || !d->Cerr || !d->Lerr || !d->Oerr ||
                     (ngt > 0 && !d->Gterr) || (ngf > 0 && !d->Gferr))) {
        free(d->Kerr);
        free(d->Cerr);
        free(d->Lerr);
        free(d->Oerr);
        free(d->Gterr);
        free(d->Gferr);
        d->Kerr = calloc(9 * (size_t)d->nblocks, sizeof(double));
        d->Cerr = calloc(9 * (size_t)d->nblocks, sizeof(double));
        d->Lerr = calloc(nlv, sizeof(double));
        d->Oerr = calloc(nov, sizeof(double));
        d->Gterr = ngt > 0 ? calloc(ngt, sizeof(double)) : NULL;
        d->Gferr = ngf > 0 ? calloc(ngf, sizeof(double)) : NULL;
        if (!d->Kerr || !d->Cerr || !d->Lerr || !d->Oerr ||
            (ngt > 0 && !d->Gterr) || (ngf > 0 && !d->Gferr))
            return ts_fail(err, TS_ENOMEM, "descriptor: out of memory for "
                           "the error estimate");
    }
    if (estimate && !d->rnoise &&
        (!(d->rnoise = calloc(nr, sizeof(double))) ||
         !(d->onoise = calloc((size_t)d->nout + 1, sizeof(double)))))
        return ts_fail(err, TS_ENOMEM, "descriptor: out of memory for the "
                       "error estimate");
    if (!estimate) {
        free(d->Kerr);
        free(d->Cerr);
        free(d->Lerr);
        free(d->Oerr);
        free(d->Gterr);
        free(d->Gferr);
        free(d->rnoise);
        free(d->onoise);
        d->Kerr = d->Cerr = d->Lerr = d->Oerr = d->rnoise = d->onoise = NULL;
        d->Gterr = d->Gferr = NULL;
    }
    /* Steps. */
    ts_frame fr;
    ts_kernel_get_frame(k, &fr);
    double g = sys->env.gravity > 0 ? sys->env.gravity : 1.0;
    for (int j = 0; j < np; j++) {
        int node = j < nn ? j : d->vl[j - nn].node;
        double l = sys->links[node > 0 ? sys->nodes[node].link : 0].length;
        double vs = sqrt(g * l) + fabs(fr.speed);
        if (j >= nn) {
            /* A vehicle's angles: 1 rad; their rates (sqrt(g l) + |V|) /
             * l, l its hull's length (or 1 m), as the dense model's. */
            const ts_vehicle *vd =
                sys->bodies[sys->nodes[node].body].vehicle;
            l = 1.0;
            for (int c = 0; c < vd->ncomponents; c++)
                if (vd->component[c].type == TS_COMP_HULL)
                    l = vd->component[c].length;
            vs = (sqrt(g * l) + fabs(fr.speed)) / l;
        }
        for (int c = 0; c < 3; c++) {
            /* Loads vary on the scale of a link, l: truncation error
             * ~(h / l)^2. A position |x| far from the origin costs
             * eps |x| in every link vector, rounding ~eps |x| / h: the
             * two balance at h ~ eps^(1/3) (|x| l^2)^(1/3). */
            double x = d->r0[3 * j + c], v = d->v0[3 * j + c];
            double sc = j < nn ? fmax(l, cbrt(fabs(x) * l * l))
                               : fmax(fabs(x), 1.0);
            d->hr[3 * j + c] = step_for(x, sc, rel_step);
            d->hv[3 * j + c] = step_for(v, fmax(fabs(v), vs), rel_step);
        }
    }
    for (int j = 0; j < d->nc; j++) {
        double x = y0[2 * d->nq + j];
        d->hc[j] = step_for(x, fmax(fabs(x), 1.0), rel_step);
    }
    for (int j = 0; j < d->nin; j++)
        d->hu[j] = step_for(d->u0[j], fmax(fabs(d->u0[j]), 1.0), rel_step);
    const double fbase[TS_NFRAME_INPUT] = {fr.speed, fr.turn_rate,
                                           fr.speed_rate, fr.turn_accel};
    for (int c = 0; c < TS_NFRAME_INPUT; c++)
        d->hf[c] = step_for(fbase[c], tsi_frame_input_scale(sys, &fr, c),
                            rel_step);
    /* The base residual sets the mass matrices, the vehicles' inertia and
     * the coefficients of the links leaving a vehicle. */
    double *R = malloc(nr * sizeof(double));
    double *yw = malloc(((size_t)d->nstate + 1) * sizeof(double));
    double *thdd = malloc((3 * (size_t)d->nv + 1) * sizeof(double));
    int rc = R && yw && thdd ? TS_OK : TS_ENOMEM;
    if (rc == TS_OK) {
        memcpy(yw, y0, (size_t)d->nstate * sizeof(double));
        rc = residual_at(d, k, d->r0, d->v0, yw, d->u0, thdd, R);
    }
    free(R);
    free(yw);
    free(thdd);
    if (rc != TS_OK)
        return ts_fail(err, rc, "descriptor: the residual fails at the base "
                       "state (%s)", ts_strerror(rc));
    memcpy(d->M, tsi_kernel_mass(k), 6 * (size_t)nn * sizeof(double));
    if (d->root >= 0)
        /* Node 0 is the towing vehicle's attach point: its inertia is
         * the body's (Mv), and no node's. */
        memset(d->M, 0, 6 * sizeof(double));
    for (int v = 0; v < d->nv; v++)
        tsi_kernel_vehicle_mass(k, v, d->Mv + 36 * v);
    for (int l = 0; l < nl; l++)
        if (sys->links[l].up_body >= 0)
            tsi_kernel_link_point(k, l, d->n + 3 * l, d->pg + 3 * l,
                                  d->pm + 3 * l);

    /* The frame inputs' groups after the rest, when asked for. */
    d->frame = d->frame && d->Gf;
    d->groups = base_groups(d) + (d->frame ? TS_NFRAME_INPUT : 0);
    int ngroups = d->groups, nthreads = threads > 0 ? threads : 1;
#ifdef _OPENMP
    if (nthreads > ngroups)
        nthreads = ngroups;
#else
    nthreads = 1;
#endif
    grp_ws *ws = calloc((size_t)nthreads, sizeof *ws);
    if (!ws)
        return ts_fail(err, TS_ENOMEM, "descriptor: out of memory");
    for (int t = 0; t < nthreads && rc == TS_OK; t++)
        rc = grp_ws_alloc(&ws[t], k, t == 0, d);
    int bad = TS_OK;
    if (rc == TS_OK) {
#ifdef _OPENMP
#pragma omp parallel for num_threads(nthreads) schedule(dynamic, 1)
#endif
        for (int gi = 0; gi < ngroups; gi++) {
            int tid = 0;
#ifdef _OPENMP
            tid = omp_get_thread_num();
#endif
            int grc = group(d, &ws[tid], gi, estimate);
            if (grc != TS_OK) {
#ifdef _OPENMP
#pragma omp critical(tsi_desc_fail)
#endif
                bad = grc;
            }
        }
    }
    for (int t = 0; t < nthreads; t++)
        grp_ws_free(&ws[t], k);
    free(ws);
    if (rc != TS_OK)
        return ts_fail(err, TS_ENOMEM, "descriptor: out of memory for %d "
                       "thread work areas", nthreads);
    if (bad != TS_OK)
        return ts_fail(err, bad, "descriptor: the residual fails at a "
                       "perturbed state (%s)", ts_strerror(bad));
    d->evaluations = 1 + (long)ngroups * (estimate ? 4 : 2);
    d->k_round = d->c_round = NAN;
    if (estimate) {
        rc = residual_noise(d, k);
        if (rc != TS_OK)
            return ts_fail(err, rc, "descriptor: the residual's rounding "
                           "noise (%s)", ts_strerror(rc));
        d->evaluations += 1 + NOISE_SAMPLES;
    }
    if (d->rdof == 3)
        hold_rows(d);
    d->k_scale = d->c_scale = d->k_err = d->c_err = 0.0;
    for (size_t i = 0; i < 9 * (size_t)d->nblocks; i++) {
        d->k_scale = fmax(d->k_scale, fabs(d->K[i]));
        d->c_scale = fmax(d->c_scale, fabs(d->C[i]));
        if (estimate) {
            d->k_err = fmax(d->k_err, fabs(d->Kerr[i]));
            d->c_err = fmax(d->c_err, fabs(d->Cerr[i]));
        }
    }
    if (!estimate)
        d->k_err = d->c_err = NAN;
    return TS_OK;
}

/* ---- Maps and products -------------------------------------------------- */

/* dq of the links from node (point) displacements dr, for nv vectors;
 * with th, a cable leaving a vehicle starts at P, displaced by (R E
 * dtheta) x rho_P, the vehicle's angles dtheta read from dq (set
 * before). */
static void links_from_nodes(const ts_system *sys, const ts_linear *lin,
                             int nv, const double *const dr[],
                             double *const dq[], int th)
{
    for (int l = 0; l < lin->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        const double *d1 = lin->dn + 6 * l, *d2 = d1 + 3;
        int o = lin->qoff[l], up = th && lin->up_qoff && lin->up_qoff[l] >= 0;
        double len = lin->len0[l];
        double a1 = len * (d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]);
        double a2 = len * (d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2]);
        for (int v = 0; v < nv; v++) {
            const double *rk = dr[v] + 3 * L->lower, *rp = dr[v] + 3 * L->upper;
            double *q = dq[v];
            double dd[3] = {rk[0] - rp[0], rk[1] - rp[1], rk[2] - rp[2]};
            if (up) {
                const double *map = lin->up_map + 12 * l;
                const double *dth = q + lin->up_qoff[l];
                double om[3], x[3];
                for (int i = 0; i < 3; i++)
                    om[i] = map[3 * i] * dth[0] + map[3 * i + 1] * dth[1] +
                            map[3 * i + 2] * dth[2];
                x[0] = om[1] * map[11] - om[2] * map[10];
                x[1] = om[2] * map[9] - om[0] * map[11];
                x[2] = om[0] * map[10] - om[1] * map[9];
                for (int c = 0; c < 3; c++)
                    dd[c] -= x[c];
            }
            q[o] = (d1[0] * dd[0] + d1[1] * dd[1] + d1[2] * dd[2]) / a1;
            q[o + 1] = (d2[0] * dd[0] + d2[1] * dd[1] + d2[2] * dd[2]) / a2;
            if (lin->elastic[l]) {
                const double *n = lin->n0 + 3 * l;
                q[o + 2] = (n[0] * dd[0] + n[1] * dd[1] + n[2] * dd[2]) /
                           L->length;
            }
        }
    }
}

void tsi_desc_from_nodes(const ts_system *sys, const ts_linear *lin,
                         const double dr[], double dq[])
{
    links_from_nodes(sys, lin, 1, &dr, &dq, 0);
}

/* The coordinate of component c of vehicle v's angle point in q, -1 for
 * a surface ship's held roll and pitch. */
static int angle_coordinate(const ts_descriptor *d, int v, int c)
{
    if (v == d->root && d->rdof == 3)
        return c == 2 ? d->vl[v].qoff : -1;
    return d->vl[v].qoff + c;
}

void tsi_desc_to_points_n(const ts_descriptor *d, const ts_linear *lin,
                          int nv, const double *const dq[],
                          double *const p[])
{
    tsi_node_displacements(d->sys, lin, nv, dq, p);
    for (int k = 0; k < nv; k++)
        for (int v = 0; v < d->nv; v++)
            for (int c = 0; c < 3; c++) {
                int q = angle_coordinate(d, v, c);
                p[k][3 * (d->nn + v) + c] = q >= 0 ? dq[k][q] : 0.0;
            }
}

void tsi_desc_to_points(const ts_descriptor *d, const ts_linear *lin,
                        const double dq[], double p[])
{
    tsi_desc_to_points_n(d, lin, 1, &dq, &p);
}

void tsi_desc_from_points_n(const ts_descriptor *d, const ts_linear *lin,
                            int nv, const double *const p[],
                            double *const dq[])
{
    for (int k = 0; k < nv; k++) {
        for (int v = 0; v < d->nv; v++)
            for (int c = 0; c < 3; c++) {
                int q = angle_coordinate(d, v, c);
                if (q >= 0)
                    dq[k][q] = p[k][3 * (d->nn + v) + c];
            }
        if (d->root >= 0) {
            /* The towing vehicle's position: node 0's displacement (a
             * surface ship's x and y). */
            int ro = lin->root_qoff, npos = d->rdof == 3 ? 2 : 3;
            for (int c = 0; c < npos; c++)
                dq[k][ro + c] = p[k][c];
        }
    }
    links_from_nodes(d->sys, lin, nv, p, dq, 1);
}

void tsi_desc_from_points(const ts_descriptor *d, const ts_linear *lin,
                          const double p[], double dq[])
{
    tsi_desc_from_points_n(d, lin, 1, &p, &dq);
}

void tsi_desc_block_mul(const ts_descriptor *d, const double *B,
                        const double x[], double y[], int acc)
{
    if (!acc)
        y[0] = y[1] = y[2] = 0.0;
    for (int k = d->p0; k < d->np; k++) {
        double s0 = 0, s1 = 0, s2 = 0;
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            const double *blk = B + 9 * (size_t)b, *xj = x + 3 * d->bcol[b];
            s0 += blk[0] * xj[0] + blk[1] * xj[1] + blk[2] * xj[2];
            s1 += blk[3] * xj[0] + blk[4] * xj[1] + blk[5] * xj[2];
            s2 += blk[6] * xj[0] + blk[7] * xj[1] + blk[8] * xj[2];
        }
        if (acc) {
            y[3 * k] += s0;
            y[3 * k + 1] += s1;
            y[3 * k + 2] += s2;
        } else {
            y[3 * k] = s0;
            y[3 * k + 1] = s1;
            y[3 * k + 2] = s2;
        }
    }
}

/* The symmetric 3x3 mass matrix entry (a, b) of node k. */
static double mass_at(const ts_descriptor *d, int k, int a, int b)
{
    static const int idx[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    return d->M[6 * k + idx[a][b]];
}

/* The inertia entry of row point k, component a, on the acceleration of
 * point j, component c: the node's mass, and a vehicle's Mv between its
 * node and its angles. */
static double inertia_at(const ts_descriptor *d, int k, int a, int j, int c)
{
    double m = j == k && k < d->nn ? mass_at(d, k, a, c) : 0.0;
    int rk, rj;
    int vk = point_vehicle(d, k, &rk), vj = point_vehicle(d, j, &rj);
    if (vk >= 0 && vk == vj) {
        int r = (rk == TSI_LV_R ? 0 : 3) + a, q = (rj == TSI_LV_R ? 0 : 3) + c;
        m += d->Mv[36 * vk + 6 * r + q];
    }
    return m;
}

void tsi_desc_mass_mul(const ts_descriptor *d, const double x[], double y[])
{
    memset(y, 0, 3 * (size_t)d->np * sizeof(double));
    for (int k = 1; k < d->nn; k++) {
        const double *S = d->M + 6 * k, *xk = x + 3 * k;
        y[3 * k] = S[0] * xk[0] + S[3] * xk[1] + S[4] * xk[2];
        y[3 * k + 1] = S[3] * xk[0] + S[1] * xk[1] + S[5] * xk[2];
        y[3 * k + 2] = S[4] * xk[0] + S[5] * xk[1] + S[2] * xk[2];
    }
    for (int v = 0; v < d->nv; v++) {
        const double *Mv = d->Mv + 36 * v;
        int i = d->vl[v].node;
        double z[6], out[6];
        for (int c = 0; c < 3; c++) {
            z[c] = x[3 * i + c];
            z[3 + c] = x[3 * (d->nn + v) + c];
        }
        for (int r = 0; r < 6; r++) {
            out[r] = 0;
            for (int c = 0; c < 6; c++)
                out[r] += Mv[6 * r + c] * z[c];
        }
        for (int c = 0; c < 3; c++) {
            y[3 * i + c] += out[c];
            y[3 * (d->nn + v) + c] += out[3 + c];
        }
    }
}

void tsi_desc_local_mul(const ts_descriptor *d, const double p[],
                        const double pv[], const double c[], const double u[],
                        double hc[], double f[], int err)
{
    const double *Lv = err ? d->Lerr : d->Lv;
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *L = &d->vl[v];
        int ncol = TSI_LV_C + L->nc + L->nin, nr = 6 + L->nc;
        double z[TSI_LV_C];
        for (int lc = 0; lc < 6; lc++) {
            int i;
            i = lc < 3 ? 3 * L->node + lc : 3 * (d->nn + v) + lc - 3;
            z[lc] = p ? p[i] : 0.0;
            z[lc + TSI_LV_V] = pv ? pv[i] : 0.0;
        }
        for (int lr = 0; lr < nr; lr++) {
            const double *row = Lv ? Lv + d->lv_off[v] + lr * ncol : NULL;
            double acc = 0;
            if (row) {
                if (lr >= 6)
                    for (int lc = 0; lc < TSI_LV_C; lc++)
                        acc += row[lc] * z[lc];
                for (int m = 0; c && m < L->nc; m++)
                    acc += row[TSI_LV_C + m] * c[L->c0 + m];
                for (int m = 0; u && m < L->nin; m++)
                    acc += row[TSI_LV_C + L->nc + m] * u[L->in0 + m];
            }
            if (lr >= 6)
                hc[L->c0 + lr - 6] = acc;
            else if (f)
                f[lr < 3 ? 3 * L->node + lr : 3 * (d->nn + v) + lr - 3] += acc;
        }
    }
}

/* The link row's coefficients on dr_lower (g, and -g on dr_upper) at
 * shift s for a taut elastic link: (EA/l + s Cv) n. */
void tsi_desc_taut_row(const ts_descriptor *d, int l, double complex s,
                       double complex g[3])
{
    const double *n = d->n + 3 * l;
    for (int c = 0; c < 3; c++)
        g[c] = (d->ka[l] + s * d->ca[l]) * n[c];
}

/* S's entries as k + s c + s^2 m (S_inf: k + m, with the blocks' K and C
 * and the elastic rows left out; the controller rows the identity): each
 * entry's three parts into kp, cp, mp when kp is given, else S(s) for
 * complex s into z (interleaved) or real s into x. */
static void fill(const ts_descriptor *d, double complex s, int inf,
                 double *x, double *z, double *kp, double *cp, double *mp)
{
    const ts_system *sys = d->sys;
    double complex s2 = inf ? 1.0 : s * s, s1 = inf ? 0.0 : s;
#define PUT(p, k_, c_, m_)                                                    \
    do {                                                                      \
        int p_ = (p);                                                         \
        double k1 = (k_), c1 = (c_), m1 = (m_);                               \
        if (kp) {                                                             \
            kp[p_] = k1;                                                      \
            cp[p_] = c1;                                                      \
            mp[p_] = m1;                                                      \
        } else {                                                              \
            double complex v_ = k1 + s1 * c1 + s2 * m1;                       \
            if (z) {                                                          \
                z[2 * p_] = creal(v_);                                        \
                z[2 * p_ + 1] = cimag(v_);                                    \
            } else {                                                          \
                x[p_] = creal(v_);                                            \
            }                                                                 \
        }                                                                     \
    } while (0)
    for (int k = d->p0; k < d->np; k++)
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b];
            if (j < d->p0)
                continue;
            const double *Kb = d->K + 9 * (size_t)b, *Cb = d->C + 9 * (size_t)b;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++) {
                    if (tsi_desc_held(d, k, a)) {
                        /* An identity row, in S_inf too. */
                        PUT(d->pos_blk[9 * b + 3 * a + c],
                            j == k && c == a ? 1.0 : 0.0, 0.0, 0.0);
                        continue;
                    }
                    PUT(d->pos_blk[9 * b + 3 * a + c],
                        inf ? 0.0 : Kb[3 * a + c], inf ? 0.0 : Cb[3 * a + c],
                        inertia_at(d, k, a, j, c));
                }
        }
    for (int l = 0; l < d->nl; l++) {
        const ts_link *L = &sys->links[l];
        const double *n = d->n + 3 * l;
        /* The link row (tsi_desc_taut_row): (EA/l + s Cv) n when taut,
         * n when rigid, 0 when slack (and S_inf's elastic rows). */
        int taut = d->kind[l] == TSI_LINK_TAUT && !inf;
        double gk = taut ? d->ka[l] : (d->kind[l] == TSI_LINK_RIGID ? 1.0
                                                                     : 0.0);
        double gc = taut ? d->ca[l] : 0.0;
        for (int c = 0; c < 3; c++) {
            PUT(d->pos_n[6 * l + c], n[c], 0.0, 0.0);
            PUT(d->pos_row[6 * l + c], gk * n[c], gc * n[c], 0.0);
            if (L->upper >= d->p0) {
                PUT(d->pos_n[6 * l + 3 + c],
                    tsi_desc_held(d, L->upper, c) ? 0.0 : -n[c], 0.0, 0.0);
                PUT(d->pos_row[6 * l + 3 + c], -gk * n[c], -gc * n[c], 0.0);
            }
            if (d->pos_pm[3 * l + c] >= 0) {
                /* From a vehicle's point P: its rotational rows, and the
                 * link row on its angles (P moves with them). */
                PUT(d->pos_pm[3 * l + c], d->pm[3 * l + c], 0.0, 0.0);
                PUT(d->pos_pg[3 * l + c], -gk * d->pg[3 * l + c],
                    -gc * d->pg[3 * l + c], 0.0);
            }
        }
        PUT(d->pos_diag[l], d->kind[l] == TSI_LINK_RIGID ? 0.0 : -1.0, 0.0,
            0.0);
    }
    /* Controller rows s dc - (Hr + s Hv) dp - Hc dc, and the force and
     * rotational rows' Kc dc (S_inf: the identity, Kc to the right). */
    for (int v = 0; v < d->nv; v++) {
        const tsi_vehicle_layout *L = &d->vl[v];
        int nr = 6 + L->nc, ncol = TSI_LV_C + L->nc + L->nin;
        const int *pp = d->pos_lv + d->lvp_off[v];
        for (int lr = 0; lr < nr; lr++)
            for (int c = 0; c < nr; c++) {
                if (lr < 6 && c < 6)
                    continue;
                const double *row = d->Lv + d->lv_off[v] + lr * ncol;
                int lc = c < 6 ? c : TSI_LV_C + c - 6;
                double kk = 0, cc = 0;
                if (inf) {
                    kk = lr == c ? 1.0 : 0.0;
                } else if (lr < 6) {
                    kk = row[lc];
                } else {
                    kk = -row[lc];
                    cc = c < 6 ? -row[lc + TSI_LV_V] : (lr == c ? 1.0 : 0.0);
                }
                PUT(pp[nr * lr + c], kk, cc, 0.0);
            }
    }
#undef PUT
}

void tsi_desc_fill_real(const ts_descriptor *d, double s, int inf,
                        double Sx[])
{
    fill(d, s, inf, Sx, NULL, NULL, NULL, NULL);
}

void tsi_desc_fill_complex(const ts_descriptor *d, double complex s,
                           double Sz[])
{
    fill(d, s, 0, NULL, Sz, NULL, NULL, NULL);
}

void tsi_desc_fill_parts(const ts_descriptor *d, double Sk[], double Sc[],
                         double Sm[])
{
    fill(d, 0.0, 0, NULL, NULL, Sk, Sc, Sm);
}
