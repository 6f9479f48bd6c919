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

/* Neighbours of node x in the tree: its parent and its children. */
static int tree_nbrs(const ts_system *sys, int x, int *out)
{
    int m = 0;
    if (x > 0)
        out[m++] = sys->links[sys->nodes[x].link].upper;
    for (int c = sys->nodes[x].child_begin; c < sys->nodes[x].child_end; c++)
        out[m++] = sys->links[sys->child_links[c]].lower;
    return m;
}

/* Work for breadth-first balls: a stamp per node and a queue. */
typedef struct ball_ws {
    int *stamp, *dist, *queue, *adj;
    int now;
} ball_ws;

/* Nodes within `depth` links of x (x included) into out[] with their
 * distances in dist_out (may be NULL); returns how many. */
static int ball(const ts_system *sys, ball_ws *w, int x, int depth, int *out,
                int *dist_out)
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
        int m = tree_nbrs(sys, y, w->adj);
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
static int colour_tree(const ts_system *sys, ball_ws *w, int sep, int *colour,
                       int *buf)
{
    int nn = sys->nnodes, ncol = 0;
    int *used = calloc((size_t)nn + 1, sizeof(int));
    if (!used)
        return -1;
    for (int x = 0; x < nn; x++)
        colour[x] = -1;
    for (int x = 0; x < nn; x++) {
        int m = ball(sys, w, x, sep, buf, NULL);
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
    free(d->r0);
    free(d->v0);
    free(d->a0);
    free(d->t0);
    free(d->M);
    free(d->n);
    free(d->len);
    free(d->ka);
    free(d->ca);
    free(d->kind);
    free(d->bptr);
    free(d->bcol);
    free(d->btr);
    free(d->bdist);
    free(d->K);
    free(d->C);
    free(d->Kerr);
    free(d->Cerr);
    free(d->rnoise);
    free(d->rcolour);
    free(d->vcolour);
    free(d->hr);
    free(d->hv);
    free(d->Sp);
    free(d->Si);
    free(d->pos);
    if (d->klu_symbolic)
        klu_free_symbolic((klu_symbolic **)&d->klu_symbolic, d->klu_common);
    free(d->klu_common);
    free(d);
}

/* One entry of the pattern: column, row and where its position goes. */
typedef struct entry {
    int col, row, tag;
} entry;

static int cmp_entry(const void *a, const void *b)
{
    const entry *x = a, *y = b;
    if (x->col != y->col)
        return x->col < y->col ? -1 : 1;
    if (x->row != y->row)
        return x->row < y->row ? -1 : 1;
    return 0;
}

/* Row or column of node k's component c (k >= 1), of link l's row or
 * tension. */
#define XR(k, c) (4 * ((k)-1) + (c))
#define XT(l) (4 * (l) + 3)

static int build_pattern(ts_descriptor *d)
{
    const ts_system *sys = d->sys;
    int nl = d->nl;
    size_t cap = 9 * (size_t)d->nblocks + 13 * (size_t)nl;
    entry *e = malloc((cap > 0 ? cap : 1) * sizeof *e);
    /* Tags index d->pos: [9 nblocks] blocks, then [6 nl] tension columns
     * of the node rows, [6 nl] link rows on positions, [nl] diagonals. */
    size_t npos = 9 * (size_t)d->nblocks + 13 * (size_t)nl;
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
    size_t m = 0;
    for (int k = 1; k < d->nn; k++)
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b];
            if (j == 0)
                continue;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++)
                    e[m++] = (entry){XR(j, c), XR(k, a), 9 * b + 3 * a + c};
        }
    int base_n = 9 * d->nblocks, base_row = base_n + 6 * nl,
        base_diag = base_row + 6 * nl;
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &sys->links[l];
        for (int c = 0; c < 3; c++) {
            e[m++] = (entry){XT(l), XR(L->lower, c), base_n + 6 * l + c};
            e[m++] = (entry){XR(L->lower, c), XT(l), base_row + 6 * l + c};
            if (L->upper > 0) {
                e[m++] = (entry){XT(l), XR(L->upper, c),
                                 base_n + 6 * l + 3 + c};
                e[m++] = (entry){XR(L->upper, c), XT(l),
                                 base_row + 6 * l + 3 + c};
            }
        }
        e[m++] = (entry){XT(l), XT(l), base_diag + l};
    }
    qsort(e, m, sizeof *e, cmp_entry);
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

ts_descriptor *tsi_desc_alloc(const ts_system *sys, ts_err *err)
{
    ts_descriptor *d = calloc(1, sizeof *d);
    if (!d) {
        ts_fail(err, TS_ENOMEM, "descriptor: out of memory");
        return NULL;
    }
    int nn = sys->nnodes, nl = sys->nlinks;
    size_t snn = (size_t)nn, snl = (size_t)(nl > 0 ? nl : 1);
    d->sys = sys;
    d->nn = nn;
    d->nl = nl;
    d->nx = 4 * (nn - 1);
    int dist_r = sys->has_bending ? 2 : 1;
    ball_ws w = {0};
    w.stamp = calloc(snn, sizeof(int));
    w.dist = calloc(snn, sizeof(int));
    w.queue = malloc(snn * sizeof(int));
    w.adj = malloc(snn * sizeof(int));
    int *buf = malloc(snn * sizeof(int)), *bd = malloc(snn * sizeof(int));
    d->r0 = calloc(3 * snn, sizeof(double));
    d->v0 = calloc(3 * snn, sizeof(double));
    d->a0 = calloc(3 * snn, sizeof(double));
    d->t0 = calloc(snl, sizeof(double));
    d->M = calloc(6 * snn, sizeof(double));
    d->n = calloc(3 * snl, sizeof(double));
    d->len = calloc(snl, sizeof(double));
    d->ka = calloc(snl, sizeof(double));
    d->ca = calloc(snl, sizeof(double));
    d->kind = calloc(snl, 1);
    d->bptr = calloc(snn + 1, sizeof(int));
    d->rcolour = malloc(snn * sizeof(int));
    d->vcolour = malloc(snn * sizeof(int));
    d->hr = calloc(3 * snn, sizeof(double));
    d->hv = calloc(3 * snn, sizeof(double));
    int ok = w.stamp && w.dist && w.queue && w.adj && buf && bd && d->r0 &&
             d->v0 && d->a0 && d->t0 && d->M && d->n && d->len && d->ka &&
             d->ca && d->kind && d->bptr && d->rcolour && d->vcolour &&
             d->hr && d->hv;
    /* Blocks: every node's ball of radius dist_r, sorted. */
    for (int k = 0; ok && k < nn; k++)
        d->bptr[k + 1] = d->bptr[k] + ball(sys, &w, k, dist_r, buf, NULL);
    if (ok) {
        d->nblocks = d->bptr[nn];
        size_t nb = (size_t)d->nblocks;
        d->bcol = malloc(nb * sizeof(int));
        d->btr = malloc(nb * sizeof(int));
        d->bdist = malloc(nb);
        d->K = calloc(9 * nb, sizeof(double));
        d->C = calloc(9 * nb, sizeof(double));
        ok = d->bcol && d->btr && d->bdist && d->K && d->C;
    }
    for (int k = 0; ok && k < nn; k++) {
        int m = ball(sys, &w, k, dist_r, buf, bd);
        /* Insertion sort by node (balls are small). */
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
    for (int k = 0; ok && k < nn; k++)
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
        d->nrcolour = colour_tree(sys, &w, 2 * dist_r, d->rcolour, buf);
        d->nvcolour = colour_tree(sys, &w, 2, d->vcolour, buf);
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
        ok = kc && klu_defaults(kc);
        if (ok && d->nx > 0) {
            d->klu_symbolic = klu_analyze(d->nx, d->Sp, d->Si, kc);
            ok = d->klu_symbolic != NULL;
        }
    }
    free(w.stamp);
    free(w.dist);
    free(w.queue);
    free(w.adj);
    free(buf);
    free(bd);
    if (!ok) {
        tsi_desc_free(d);
        ts_fail(err, TS_ENOMEM, "descriptor: out of memory for %d links",
                nl);
        return NULL;
    }
    d->groups = 3 * (d->nrcolour + d->nvcolour);
    return d;
}

/* ---- Coloured central differences --------------------------------------- */

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
    double *r, *v;     /* [3 nn] perturbed copies */
    double *R[4];      /* [3 nn] residuals at +h, -h, +2h, -2h */
} grp_ws;

static void grp_ws_free(grp_ws *w, const ts_kernel *owner)
{
    if (w->k && w->k != owner)
        ts_kernel_free(w->k);
    free(w->r);
    free(w->v);
    for (int i = 0; i < 4; i++)
        free(w->R[i]);
}

static int grp_ws_alloc(grp_ws *w, ts_kernel *k, int own, const ts_descriptor *d)
{
    size_t n3 = 3 * (size_t)d->nn;
    memset(w, 0, sizeof *w);
    w->k = own ? k : ts_kernel_clone(k, NULL);
    w->r = malloc(n3 * sizeof(double));
    w->v = malloc(n3 * sizeof(double));
    int ok = w->k && w->r && w->v;
    for (int i = 0; i < 4; i++)
        ok = ok && (w->R[i] = malloc(n3 * sizeof(double)));
    if (!ok)
        return TS_ENOMEM;
    memcpy(w->r, d->r0, n3 * sizeof(double));
    memcpy(w->v, d->v0, n3 * sizeof(double));
    return TS_OK;
}

/* Group g: kind (0 position, 1 velocity), colour, component. Evaluates
 * the residual at the perturbed states and writes the columns of the
 * group's nodes into K or C (and the error estimate). */
static int group(ts_descriptor *d, grp_ws *w, int g, int estimate)
{
    int nr = 3 * d->nrcolour;
    int kind = g < nr ? 0 : 1, gg = g < nr ? g : g - nr;
    int colour = gg / 3, comp = gg % 3;
    const int *col = kind ? d->vcolour : d->rcolour;
    const double *h = kind ? d->hv : d->hr;
    double *x = kind ? w->v : w->r;
    static const double mult[4] = {1.0, -1.0, 2.0, -2.0};
    int nev = estimate ? 4 : 2, rc = TS_OK;
    for (int s = 0; s < nev && rc == TS_OK; s++) {
        for (int j = 0; j < d->nn; j++)
            if (col[j] == colour)
                x[3 * j + comp] = (kind ? d->v0 : d->r0)[3 * j + comp] +
                                  mult[s] * h[3 * j + comp];
        rc = tsi_kernel_residual(w->k, w->r, w->v, d->a0, d->t0, w->R[s]);
    }
    for (int j = 0; j < d->nn; j++)
        if (col[j] == colour)
            x[3 * j + comp] = (kind ? d->v0 : d->r0)[3 * j + comp];
    if (rc != TS_OK)
        return rc;
    double *D = kind ? d->C : d->K, *E = kind ? d->Cerr : d->Kerr;
    for (int j = 0; j < d->nn; j++) {
        if (col[j] != colour)
            continue;
        double hj = h[3 * j + comp];
        double inv = 1.0 / (2.0 * hj), inv2 = 1.0 / (4.0 * hj);
        for (int b = d->bptr[j]; b < d->bptr[j + 1]; b++) {
            int k = d->bcol[b];
            if (k == 0)
                continue;
            /* A velocity reaches one link only: farther blocks of C are
             * zero, and their rows may see another node of the colour. */
            double *blk = D + 9 * (size_t)d->btr[b];
            double *eblk = E ? E + 9 * (size_t)d->btr[b] : NULL;
            int far = kind && d->bdist[b] > 1;
            for (int a = 0; a < 3; a++) {
                double dh = far ? 0.0
                                : (w->R[0][3 * k + a] - w->R[1][3 * k + a]) *
                                      inv;
                blk[3 * a + comp] = dh;
                if (eblk) {
                    double d2 = far ? 0.0
                                    : (w->R[2][3 * k + a] -
                                       w->R[3][3 * k + a]) *
                                          inv2;
                    eblk[3 * a + comp] = (d2 - dh) / 3.0;
                }
            }
        }
    }
    return TS_OK;
}

#define NOISE_SAMPLES 8
#define NOISE_REL 1e-4

/* The residual's rounding noise d->rnoise (see the head of the file).
 * Needs K and C. */
static int residual_noise(ts_descriptor *d, ts_kernel *k)
{
    size_t n3 = 3 * (size_t)d->nn;
    double *r = malloc(n3 * sizeof *r), *v = malloc(n3 * sizeof *v);
    double *dr = malloc(n3 * sizeof *dr), *dv = malloc(n3 * sizeof *dv);
    double *R0 = malloc(n3 * sizeof *R0), *R = malloc(n3 * sizeof *R);
    double *f = malloc(n3 * sizeof *f), *acc = calloc(n3, sizeof *acc);
    int rc = r && v && dr && dv && R0 && R && f && acc ? TS_OK : TS_ENOMEM;
    if (rc == TS_OK)
        rc = tsi_kernel_residual(k, d->r0, d->v0, d->a0, d->t0, R0);
    unsigned long long seq = 0x9E3779B97F4A7C15ULL;
    int used = 0;
    for (int s = 0; rc == TS_OK && s < NOISE_SAMPLES; s++) {
        for (size_t i = 0; i < 2 * n3; i++) {
            seq = seq * 6364136223846793005ULL + 1442695040888963407ULL;
            double sg = seq >> 63 ? 1.0 : -1.0;
            size_t j = i < n3 ? i : i - n3;
            double *x = i < n3 ? r : v, *dx = i < n3 ? dr : dv;
            const double *x0 = i < n3 ? d->r0 : d->v0;
            /* The tow point stays: at the waterline its columns are
             * kinked (counted as kink_tow), not noisy. */
            double h = j < 3 ? 0.0 : (i < n3 ? d->hr : d->hv)[j];
            x[j] = x0[j] + sg * NOISE_REL * h;
            dx[j] = x[j] - x0[j]; /* exactly what was added */
        }
        if (tsi_kernel_residual(k, r, v, d->a0, d->t0, R) != TS_OK)
            continue; /* a state off the chart: another sample */
        tsi_desc_block_mul(d, d->K, dr, f, 0);
        tsi_desc_block_mul(d, d->C, dv, f, 1);
        for (size_t i = 3; i < n3; i++) {
            double e = R[i] - R0[i] - f[i];
            acc[i] += e * e;
        }
        used++;
    }
    if (rc == TS_OK && used == 0)
        rc = TS_ECONV;
    if (rc == TS_OK) {
        d->k_round = d->c_round = 0.0;
        for (size_t i = 0; i < n3; i++)
            d->rnoise[i] = sqrt(acc[i] / (2.0 * used));
        for (int kk = 1; kk < d->nn; kk++)
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
    return rc;
}

void tsi_desc_error_terms(const ts_descriptor *d, const double complex w[],
                          const double complex x[], double complex s,
                          double *trunc, double *round)
{
    if (!d->Kerr || !d->Cerr || !d->rnoise) {
        *trunc = *round = NAN;
        return;
    }
    double complex t = 0;
    double r2 = 0, as2 = creal(s) * creal(s) + cimag(s) * cimag(s);
    for (int k = 1; k < d->nn; k++) {
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
                double ax = creal(xj[c]) * creal(xj[c]) +
                            cimag(xj[c]) * cimag(xj[c]);
                double hr = d->hr[3 * j + c], hv = d->hv[3 * j + c];
                xk += ax / (hr * hr) + (d->bdist[b] <= 1 ? as2 * ax / (hv * hv)
                                                         : 0.0);
            }
        }
        double wk = 0;
        for (int a = 0; a < 3; a++) {
            double complex wa = w[XR(k, a)];
            t += wa * e[a];
            double rho = d->rnoise[3 * k + a];
            wk += (creal(wa) * creal(wa) + cimag(wa) * cimag(wa)) * rho * rho;
        }
        r2 += wk * xk;
    }
    *trunc = cabs(t);
    *round = sqrt(0.5 * r2);
}

int tsi_desc_linearize(ts_descriptor *d, ts_kernel *k, double rel_step,
                       int estimate, int threads, ts_err *err)
{
    const ts_system *sys = d->sys;
    int nn = d->nn, nl = d->nl;
    size_t n3 = 3 * (size_t)nn;
    memcpy(d->r0, ts_kernel_positions(k), n3 * sizeof(double));
    memcpy(d->v0, ts_kernel_velocities(k), n3 * sizeof(double));
    memcpy(d->a0, ts_kernel_rel_accelerations(k), n3 * sizeof(double));
    memcpy(d->t0, ts_kernel_tensions(k), (size_t)nl * sizeof(double));
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
        if (!(len > 0))
            return ts_fail(err, TS_ESINGULAR, "descriptor: link %d has zero "
                           "length", l);
        d->len[l] = len;
        d->ka[l] = L->elastic ? L->ea / L->length : 0.0;
        d->ca[l] = L->elastic ? L->damping : 0.0;
        d->kind[l] = !L->elastic ? TSI_LINK_RIGID
                     : d->t0[l] > 0 ? TSI_LINK_TAUT : TSI_LINK_SLACK;
    }
    if (estimate && (!d->Kerr || !d->Cerr)) {
        d->Kerr = calloc(9 * (size_t)d->nblocks, sizeof(double));
        d->Cerr = calloc(9 * (size_t)d->nblocks, sizeof(double));
        if (!d->Kerr || !d->Cerr)
            return ts_fail(err, TS_ENOMEM, "descriptor: out of memory for "
                           "the error estimate");
    }
    if (estimate && !d->rnoise &&
        !(d->rnoise = calloc(3 * (size_t)nn, sizeof(double))))
        return ts_fail(err, TS_ENOMEM, "descriptor: out of memory for the "
                       "error estimate");
    if (!estimate) {
        free(d->Kerr);
        free(d->Cerr);
        free(d->rnoise);
        d->Kerr = d->Cerr = d->rnoise = NULL;
    }
    /* Steps. */
    ts_frame fr;
    ts_kernel_get_frame(k, &fr);
    double g = sys->env.gravity > 0 ? sys->env.gravity : 1.0;
    for (int j = 0; j < nn; j++) {
        double l = sys->links[j > 0 ? sys->nodes[j].link : 0].length;
        double vs = sqrt(g * l) + fabs(fr.speed);
        for (int c = 0; c < 3; c++) {
            /* Loads vary on the scale of a link, l: truncation error
             * ~(h / l)^2. A position |x| far from the origin costs
             * eps |x| in every link vector, rounding ~eps |x| / h: the
             * two balance at h ~ eps^(1/3) (|x| l^2)^(1/3). */
            double x = d->r0[3 * j + c], v = d->v0[3 * j + c];
            d->hr[3 * j + c] = step_for(x, fmax(l, cbrt(fabs(x) * l * l)),
                                        rel_step);
            d->hv[3 * j + c] = step_for(v, fmax(fabs(v), vs), rel_step);
        }
    }
    /* The base residual sets the mass matrices. */
    double *R = malloc(n3 * sizeof(double));
    if (!R)
        return ts_fail(err, TS_ENOMEM, "descriptor: out of memory");
    int rc = tsi_kernel_residual(k, d->r0, d->v0, d->a0, d->t0, R);
    free(R);
    if (rc != TS_OK)
        return ts_fail(err, rc, "descriptor: the residual fails at the base "
                       "state (%s)", ts_strerror(rc));
    memcpy(d->M, tsi_kernel_mass(k), 6 * (size_t)nn * sizeof(double));

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

void tsi_desc_from_nodes(const ts_system *sys, const ts_linear *lin,
                         const double dr[], double dq[])
{
    for (int l = 0; l < lin->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        const double *d1 = lin->dn + 6 * l, *d2 = d1 + 3;
        int o = lin->qoff[l];
        const double *rk = dr + 3 * L->lower, *rp = dr + 3 * L->upper;
        double dd[3] = {rk[0] - rp[0], rk[1] - rp[1], rk[2] - rp[2]};
        double len = lin->len0[l];
        dq[o] = (d1[0] * dd[0] + d1[1] * dd[1] + d1[2] * dd[2]) /
                (len * (d1[0] * d1[0] + d1[1] * d1[1] + d1[2] * d1[2]));
        dq[o + 1] = (d2[0] * dd[0] + d2[1] * dd[1] + d2[2] * dd[2]) /
                    (len * (d2[0] * d2[0] + d2[1] * d2[1] + d2[2] * d2[2]));
        if (lin->elastic[l]) {
            const double *n = lin->n0 + 3 * l;
            dq[o + 2] = (n[0] * dd[0] + n[1] * dd[1] + n[2] * dd[2]) /
                        L->length;
        }
    }
}

void tsi_desc_block_mul(const ts_descriptor *d, const double *B,
                        const double x[], double y[], int acc)
{
    if (!acc)
        y[0] = y[1] = y[2] = 0.0;
    for (int k = 1; k < d->nn; k++) {
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

/* The link row's coefficients on dr_lower (g, and -g on dr_upper) at
 * shift s for a taut elastic link: (EA/l + s Cv) n + Cv (I - n n^T) dd'
 * / |d| (dd' the base rate of the link vector). */
void tsi_desc_taut_row(const ts_descriptor *d, int l, double complex s,
                       double complex g[3])
{
    const double *n = d->n + 3 * l;
    for (int c = 0; c < 3; c++)
        g[c] = (d->ka[l] + s * d->ca[l]) * n[c];
}

/* The symmetric 3x3 mass matrix entry (a, b) of node k. */
static double mass_at(const ts_descriptor *d, int k, int a, int b)
{
    static const int idx[3][3] = {{0, 3, 4}, {3, 1, 5}, {4, 5, 2}};
    return d->M[6 * k + idx[a][b]];
}

/* S's entries as k + s c + s^2 m (S_inf: k + m, with the blocks' K and C
 * and the elastic rows left out): each entry's three parts into kp, cp,
 * mp when kp is given, else S(s) for complex s into z (interleaved) or
 * real s into x. */
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
    for (int k = 1; k < d->nn; k++)
        for (int b = d->bptr[k]; b < d->bptr[k + 1]; b++) {
            int j = d->bcol[b];
            if (j == 0)
                continue;
            const double *Kb = d->K + 9 * (size_t)b, *Cb = d->C + 9 * (size_t)b;
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++)
                    PUT(d->pos_blk[9 * b + 3 * a + c],
                        inf ? 0.0 : Kb[3 * a + c], inf ? 0.0 : Cb[3 * a + c],
                        j == k ? mass_at(d, k, a, c) : 0.0);
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
            if (L->upper > 0) {
                PUT(d->pos_n[6 * l + 3 + c], -n[c], 0.0, 0.0);
                PUT(d->pos_row[6 * l + 3 + c], -gk * n[c], -gc * n[c], 0.0);
            }
        }
        PUT(d->pos_diag[l], d->kind[l] == TSI_LINK_RIGID ? 0.0 : -1.0, 0.0,
            0.0);
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
