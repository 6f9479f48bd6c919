/* linearize.c: A = df/dy, B = df/du about a state (towstab/linearize.h;
 * doc/model.md section 6; Kamman & Nguyen 1990, eqs. 56-65; doc/linear.md).
 *
 * Algorithm. For every column j (n state columns, then TS_NINPUT input
 * columns) the coordinate x_j is perturbed by +-h_j and the kernel is
 * evaluated; column j of the lower block is (f(x+h) - f(x-h)) / (2h)
 * (second-order central difference, error (h^2/6) f''' plus rounding
 * ~eps |f| / h; h ~ eps^(1/3) scale balances the two at ~eps^(2/3)).
 * With estimate_error the same column is formed again with 2h; for a smooth
 * f, D(2h) - D(h) = 3 c h^2 + O(h^4), so |D(h) - D(2h)| / 3 estimates the
 * truncation error of D(h) (rounding noise included). The link tensions
 * returned by the kernel at the same perturbed states give dT/dy and dT/du
 * at no extra evaluation.
 *
 * The upper block of A is [0 I] by the definition of the state (q' is the
 * second half of y): it is written exactly, not differenced. Columns are
 * independent: with OpenMP each thread differentiates a share of them on
 * its own kernel clone (kernels keep per-call work arrays). Cost: 2 or 4
 * evaluations of O(nlinks) per column, O(nlinks^2) in all, plus O(n^2)
 * memory traffic to fill A.
 *
 * Non-smooth points: the submerged fraction of a link is kinked where one
 * of its end nodes crosses z = 0 (lib/forces.h). A node closer to the
 * surface than twice the largest step that moves it makes the difference
 * straddle the kink; such nodes are counted in lin->kinks and reported.
 *
 * Direction derivatives: with n = R nh(t1, t2) (R the link's chart),
 * dnh/dt2 = nh(t1, t2 + pi/2) and dnh/dt1 = nh(t1 + pi/2, t2)
 * - sin t2 nh(0, pi/2), so both follow exactly from ts_kernel_direction.
 */
#include "towstab/linearize.h"

#include <complex.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "descriptor.h"
#include "vec3.h"
#include "kernel_impl.h"
#include "lazylib.h"
#include "vehicle.h"

#ifdef _OPENMP
/* Below this many links a column costs a few microseconds and starting a
 * thread team costs more than it saves (measured: doc/performance-
 * linear.md); opts.threads > 0 overrides. */
#define TS_LINEARIZE_PARALLEL_LINKS 200
#endif

void ts_linearize_opts_default(ts_linearize_opts *o)
{
    o->rel_step = cbrt(DBL_EPSILON);
    o->estimate_error = 1;
    o->threads = 0;
    o->tensions = 0;
    o->model = TS_LIN_AUTO;
    o->dense_max_states = 1200;
    o->frame_inputs = 0;
}

ts_linear *ts_linear_alloc(const ts_kernel *k, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_linear *lin = calloc(1, sizeof *lin);
    if (!lin) {
        ts_fail(err, TS_ENOMEM, "ts_linear_alloc: out of memory");
        return NULL;
    }
    int n = ts_kernel_nstate(k), fin = ts_kernel_ninput(k);
    int ni = fin + TS_NFRAME_INPUT;
    size_t sn = (size_t)n;
    lin->nstate = n;
    lin->nq = ts_kernel_nq(k);
    lin->ninput = ni;
    lin->frame_input = fin;
    lin->nlinks = sys->nlinks;
    lin->nnodes = sys->nnodes;
    lin->y0 = calloc(sn, sizeof(double));
    lin->f0 = calloc(sn, sizeof(double));
    lin->r0 = calloc(3 * (size_t)sys->nnodes, sizeof(double));
    lin->t0 = calloc((size_t)sys->nlinks, sizeof(double));
    lin->dn = calloc(6 * (size_t)sys->nlinks, sizeof(double));
    lin->n0 = calloc(3 * (size_t)sys->nlinks, sizeof(double));
    lin->len0 = calloc((size_t)sys->nlinks, sizeof(double));
    lin->tow_lever = calloc(3 * (size_t)sys->nnodes, sizeof(double));
    lin->qoff = calloc((size_t)sys->nlinks, sizeof(int));
    lin->elastic = calloc((size_t)sys->nlinks, 1);
    for (int l = 0; lin->qoff && lin->elastic && l < sys->nlinks; l++) {
        lin->qoff[l] = ts_kernel_link_offset(k, l);
        lin->elastic[l] = (char)(sys->links[l].elastic != 0);
    }
    lin->h = calloc(sn + (size_t)ni, sizeof(double));
    lin->u0 = calloc((size_t)ni, sizeof(double));
    lin->kink_node = -1;
    lin->desc_err = lin->desc_round = NAN;
    lin->nvehicles = ts_kernel_nvehicles(k);
    lin->root_qoff = ts_kernel_root_offset(k);
    lin->root_dof = ts_kernel_root_dof(k);
    lin->noutput = ts_kernel_noutput(k);
    if (lin->noutput > 0) {
        size_t no = (size_t)lin->noutput;
        lin->Vy = calloc(no * sn, sizeof(double));
        lin->Vu = calloc(no * (size_t)ni, sizeof(double));
        lin->v0 = calloc(no, sizeof(double));
    }
    lin->input_name = calloc((size_t)ni, sizeof *lin->input_name);
    lin->input_unit = calloc((size_t)ni, sizeof *lin->input_unit);
    lin->output_name = calloc((size_t)lin->noutput + 1,
                              sizeof *lin->output_name);
    lin->output_unit = calloc((size_t)lin->noutput + 1,
                              sizeof *lin->output_unit);
    for (int j = 0; lin->input_name && lin->input_unit && j < ni; j++) {
        if (j < fin) {
            ts_kernel_input_name(k, j, lin->input_name[j], TS_IO_NAME);
            lin->input_unit[j] = ts_kernel_input_unit(k, j);
        } else {
            snprintf(lin->input_name[j], TS_IO_NAME, "%s",
                     ts_frame_input_name(j - fin));
            lin->input_unit[j] = ts_frame_input_unit(j - fin);
        }
    }
    for (int j = 0; lin->output_name && lin->output_unit &&
                    j < lin->noutput;
         j++) {
        ts_kernel_output_name(k, j, lin->output_name[j], TS_IO_NAME);
        lin->output_unit[j] = ts_kernel_output_unit(k, j);
    }
    if (lin->nvehicles > 0) {
        lin->up_qoff = malloc((size_t)sys->nlinks * sizeof(int));
        lin->up_map = calloc(12 * (size_t)sys->nlinks, sizeof(double));
        lin->veh_rot = calloc(9 * (size_t)lin->nvehicles, sizeof(double));
        lin->veh_qoff = malloc((size_t)lin->nvehicles * sizeof(int));
    }
    if (!lin->y0 || !lin->f0 || !lin->r0 || !lin->t0 || !lin->dn ||
        !lin->n0 || !lin->len0 || !lin->qoff || !lin->elastic || !lin->h ||
        !lin->tow_lever ||
        !lin->u0 ||
        (lin->nvehicles > 0 && (!lin->up_qoff || !lin->up_map ||
                                !lin->veh_rot || !lin->veh_qoff)) ||
        (lin->noutput > 0 && (!lin->Vy || !lin->Vu || !lin->v0)) ||
        !lin->input_name || !lin->input_unit || !lin->output_name ||
        !lin->output_unit) {
        ts_linear_free(lin);
        ts_fail(err, TS_ENOMEM, "ts_linear_alloc: out of memory for %d "
                "states", n);
        return NULL;
    }
    return lin;
}

void ts_linear_free(ts_linear *lin)
{
    if (!lin)
        return;
    free(lin->A);
    free(lin->B);
    free(lin->y0);
    free(lin->f0);
    free(lin->r0);
    free(lin->t0);
    free(lin->dn);
    free(lin->n0);
    free(lin->len0);
    free(lin->tow_lever);
    free(lin->qoff);
    free(lin->elastic);
    free(lin->Ty);
    free(lin->Tu);
    free(lin->Aerr);
    free(lin->fnoise);
    free(lin->Berr);
    free(lin->h);
    tsi_desc_free(lin->desc);
    free(lin->u0);
    free(lin->up_qoff);
    free(lin->up_map);
    free(lin->veh_rot);
    free(lin->veh_qoff);
    free(lin->Vy);
    free(lin->Vu);
    free(lin->Terr);
    free(lin->Verr);
    free(lin->onoise);
    free(lin->v0);
    free(lin->input_name);
    free(lin->input_unit);
    free(lin->output_name);
    free(lin->output_unit);
    free(lin->neutral_re);
    free(lin->neutral_im);
    free(lin);
}

const char *ts_input_name(int j) { return tsi_tow_input_name(j); }

static const char *const frame_names[TS_NFRAME_INPUT] = {
    "tow.speed", "tow.turn_rate", "tow.speed_rate", "tow.turn_accel"};
static const char *const frame_units[TS_NFRAME_INPUT] = {
    "m/s", "rad/s", "m/s^2", "rad/s^2"};

const char *ts_frame_input_name(int c)
{
    return c >= 0 && c < TS_NFRAME_INPUT ? frame_names[c] : NULL;
}

const char *ts_frame_input_unit(int c)
{
    return c >= 0 && c < TS_NFRAME_INPUT ? frame_units[c] : NULL;
}

/* f(y, u) into f with the frame inputs u[fin .. fin + TS_NFRAME_INPUT)
 * added to the frame `base` for this evaluation (the kernel reads its own
 * inputs u[0 .. fin) only); k's frame is base again on return, its
 * last-evaluation results (positions, tensions, outputs) those of the
 * moved frame. */
static int eval_frame(ts_kernel *k, const ts_frame *base, int fin,
                      const double *y, const double *u, double *f)
{
    const double *du = u + fin;
    if (du[0] == 0 && du[1] == 0 && du[2] == 0 && du[3] == 0)
        return ts_kernel_eval(k, y, u, f);
    ts_frame fr = *base;
    fr.speed += du[TS_FRAME_SPEED];
    fr.turn_rate += du[TS_FRAME_TURN_RATE];
    fr.speed_rate += du[TS_FRAME_SPEED_RATE];
    fr.turn_accel += du[TS_FRAME_TURN_ACCEL];
    ts_kernel_set_frame(k, &fr);
    int rc = ts_kernel_eval(k, y, u, f);
    ts_kernel_set_frame(k, base);
    return rc;
}

/* The step of one column: rel * max(|x|, scale), rounded so that x + h is
 * a machine number (then (x + h) - x == h exactly). */
static double step_for(double x, double scale, double rel)
{
    double h = rel * fmax(fabs(x), scale);
    volatile double t = x + h;
    return t - x;
}

/* Per-thread work: state and input copies, four f and tension vectors. */
typedef struct col_ws {
    ts_kernel *k;
    double *y, *u;
    int fin;        /* the frame inputs' offset in u */
    ts_frame base;  /* the frame they move */
    double *f[4];   /* f(x+h), f(x-h), f(x+2h), f(x-2h) */
    double *t[4];   /* tensions at the same states */
} col_ws;

static void col_ws_free(col_ws *w, const ts_kernel *owner)
{
    if (w->k && w->k != owner)
        ts_kernel_free(w->k);
    free(w->y);
    free(w->u);
    for (int i = 0; i < 4; i++) {
        free(w->f[i]);
        free(w->t[i]);
    }
}

static int col_ws_alloc(col_ws *w, ts_kernel *k, int use_k, const double *y0,
                        const double *u0, int n, int ni, int nl, int nout,
                        ts_err *err)
{
    memset(w, 0, sizeof *w);
    w->k = use_k ? k : ts_kernel_clone(k, err);
    w->y = malloc((size_t)n * sizeof(double));
    w->u = malloc((size_t)ni * sizeof(double));
    int ok = w->k && w->y && w->u;
    for (int i = 0; i < 4; i++) {
        w->f[i] = malloc((size_t)n * sizeof(double));
        w->t[i] = malloc((size_t)(nl + nout > 0 ? nl + nout : 1) *
                         sizeof(double));
        ok = ok && w->f[i] && w->t[i];
    }
    if (!ok)
        return TS_ENOMEM;
    memcpy(w->y, y0, (size_t)n * sizeof(double));
    memcpy(w->u, u0, (size_t)ni * sizeof(double));
    w->fin = ni - TS_NFRAME_INPUT;
    ts_kernel_get_frame(k, &w->base);
    return TS_OK;
}

/* Evaluate at the current (w->y, w->u) into f[slot] and t[slot] (the
 * tensions, then the vehicles' outputs). */
static int eval_into(col_ws *w, int slot, int nl)
{
    int rc = eval_frame(w->k, &w->base, w->fin, w->y, w->u, w->f[slot]);
    if (rc == TS_OK) {
        memcpy(w->t[slot], ts_kernel_tensions(w->k),
               (size_t)nl * sizeof(double));
        ts_kernel_outputs(w->k, w->t[slot] + nl);
    }
    return rc;
}

/* Rounding noise of the kernel, lin->fnoise[n - nq]: at NOISE_SAMPLES
 * states y0 + d, d_j = +-NOISE_REL h_j (signs from a fixed sequence),
 * f(y0 + d) - f(y0) - A d is the rounding of the two evaluations (A's
 * own error times d, and the second-order term NOISE_REL^2 h^2 f'', are
 * far below it); its root mean square over the samples, over sqrt(2), is
 * the noise of one evaluation of each lower row. A central difference
 * with step h_j then carries noise fnoise_i / (sqrt(2) h_j) in entry (i,
 * j), which the truncation estimate (A(h) - A(2h)) / 3 samples only by
 * chance. Cost: NOISE_SAMPLES evaluations and matrix-vector products. */
#define NOISE_SAMPLES 8
#define NOISE_REL 1e-4

static int kernel_noise(ts_kernel *k, const double *y0, const double *u0,
                        ts_linear *lin, ts_err *err)
{
    tsi_lapack la;
    if (tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    int n = lin->nstate, nq = lin->nq, nlow = n - nq;
    int nl = lin->nlinks, nout = lin->noutput, no = nl + nout;
    double *y = malloc((size_t)n * sizeof *y);
    double *d = malloc((size_t)n * sizeof *d);
    double *f = malloc((size_t)n * sizeof *f);
    double *ad = malloc((size_t)(nlow > 0 ? nlow : 1) * sizeof *ad);
    double *acc = calloc((size_t)(nlow > 0 ? nlow : 1), sizeof *acc);
    /* The output rows: tensions (with Ty) and the vehicles' outputs. */
    double *od = malloc((size_t)(no > 0 ? no : 1) * sizeof *od);
    double *oacc = calloc((size_t)(no > 0 ? no : 1), sizeof *oacc);
    int rc = y && d && f && ad && acc && od && oacc ? TS_OK : TS_ENOMEM;
    unsigned long long seq = 0x9E3779B97F4A7C15ULL;
    int used = 0;
    for (int s = 0; rc == TS_OK && s < NOISE_SAMPLES; s++) {
        for (int j = 0; j < n; j++) {
            seq = seq * 6364136223846793005ULL + 1442695040888963407ULL;
            double dj = (seq >> 63 ? 1.0 : -1.0) * NOISE_REL * lin->h[j];
            y[j] = y0[j] + dj;
            d[j] = y[j] - y0[j]; /* exactly what was added */
        }
        lin->evaluations++;
        if (ts_kernel_eval(k, y, u0, f) != TS_OK)
            continue; /* a state off the chart: another sample */
        double one = 1.0, zero = 0.0;
        int inc = 1;
        la.dgemv_("N", &nlow, &n, &one, lin->A + nq, &n, d, &inc, &zero, ad,
                  &inc, 1);
        for (int i = 0; i < nlow; i++) {
            double r = f[nq + i] - lin->f0[nq + i] - ad[i];
            acc[i] += r * r;
        }
        if (lin->onoise) {
            memcpy(od, ts_kernel_tensions(k), (size_t)nl * sizeof(double));
            ts_kernel_outputs(k, od + nl);
            for (int i = 0; i < no; i++) {
                const double *J = i < nl ? lin->Ty : lin->Vy;
                int rows = i < nl ? nl : nout, r0 = i < nl ? i : i - nl;
                double r = od[i] - (i < nl ? lin->t0[i] : lin->v0[i - nl]);
                for (int j = 0; J && j < n; j++)
                    r -= J[r0 + (size_t)j * rows] * d[j];
                oacc[i] += r * r;
            }
        }
        used++;
    }
    if (rc == TS_OK && used > 0) {
        for (int i = 0; i < nlow; i++)
            lin->fnoise[i] = sqrt(acc[i] / (2.0 * used));
        for (int i = 0; lin->onoise && i < no; i++)
            lin->onoise[i] = i < nl && !lin->Ty ? NAN
                                                : sqrt(oacc[i] / (2.0 * used));
    } else if (rc == TS_OK) {
        rc = TS_ECONV;
    }
    free(od);
    free(oacc);
    free(y);
    free(d);
    free(f);
    free(ad);
    free(acc);
    return rc;
}

/* Column results beside A/B: error statistics of this column. */
typedef struct col_err {
    double max_a, sum2_a, max_t;
} col_err;

/* Differentiate column j (j < n: state, else input j - n). Writes the lower
 * block of the column, rows nq..n-1, into `col` (n - nq entries, stride 1),
 * when `tcol` is not NULL the tension derivatives (nl entries), and when
 * `ocol` is not NULL the vehicles' output derivatives (nout entries). */
static int column(col_ws *w, int j, int n, int nq, int nl, int nout,
                  double h, int estimate, double *col, double *ecol,
                  double *tcol, double *ocol, double *tecol,
                  double *oecol, col_err *ce)
{
    double *x = j < n ? &w->y[j] : &w->u[j - n];
    double x0 = *x;
    static const double mult[4] = {1.0, -1.0, 2.0, -2.0};
    int nev = estimate ? 4 : 2, rc = TS_OK;
    for (int s = 0; s < nev && rc == TS_OK; s++) {
        *x = x0 + mult[s] * h;
        rc = eval_into(w, s, nl);
    }
    *x = x0;
    if (rc != TS_OK)
        return rc;
    const double *fp = w->f[0] + nq, *fm = w->f[1] + nq;
    double inv = 1.0 / (2.0 * h), inv2 = 1.0 / (4.0 * h);
    ce->max_a = ce->sum2_a = ce->max_t = 0.0;
    for (int i = 0; i < n - nq; i++) {
        col[i] = (fp[i] - fm[i]) * inv;
        if (estimate) {
            double d2 = (w->f[2][nq + i] - w->f[3][nq + i]) * inv2;
            double e = fabs(col[i] - d2) / 3.0;
            if (ecol)
                ecol[i] = (d2 - col[i]) / 3.0;
            if (!(e <= ce->max_a))
                ce->max_a = e;
            ce->sum2_a += e * e;
        }
    }
    for (int o = 0; ocol && o < nout; o++) {
        ocol[o] = (w->t[0][nl + o] - w->t[1][nl + o]) * inv;
        if (estimate && oecol)
            oecol[o] = ((w->t[2][nl + o] - w->t[3][nl + o]) * inv2 -
                        ocol[o]) / 3.0;
    }
    if (tcol)
        for (int l = 0; l < nl; l++) {
            tcol[l] = (w->t[0][l] - w->t[1][l]) * inv;
            if (estimate) {
                double d2 = (w->t[2][l] - w->t[3][l]) * inv2;
                double e = fabs(tcol[l] - d2) / 3.0;
                if (tecol)
                    tecol[l] = (d2 - tcol[l]) / 3.0;
                if (!(e <= ce->max_t))
                    ce->max_t = e;
            }
        }
    return TS_OK;
}

/* The lever of every node for the tow rotations (ts_linear.tow_lever):
 * the start point of the cable each node hangs on, from M's origin (a
 * prescribed tow point: tow.point, node 0 included) or from the towing
 * vehicle's origin O (R p, p the cable's start in body axes), as the
 * kernel's root_tow_inputs moves it. Links come in tree order, so a
 * link's upper node is done before its lower one. */
static void tow_levers(const ts_kernel *k, const ts_system *sys,
                       const double y0[], double lever[])
{
    int root = ts_kernel_root(k);
    double R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, om[3];
    if (root >= 0)
        ts_kernel_get_vehicle(k, root, y0, R, om);
    for (int j = 0; j < 3; j++)
        lever[j] = root >= 0 ? 0.0 : sys->tow.point[j];
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        double *r = lever + 3 * L->lower;
        if (L->upper == 0 && root >= 0 && L->up_body >= 0)
            for (int j = 0; j < 3; j++)
                r[j] = R[3 * j] * L->up_point[0] +
                       R[3 * j + 1] * L->up_point[1] +
                       R[3 * j + 2] * L->up_point[2];
        else
            memcpy(r, lever + 3 * L->upper, 3 * sizeof(double));
    }
}

/* Scale of a strain rate's column: equilibrium strains are ~T/EA, 1e-10
 * to 1e-3, and their rates zero. */
#define STRAIN_SCALE 1e-4
/* Floor of a strain's own scale: its step is rel_step |e|, so that a taut
 * link stays taut on both sides (T = max(0, EA e) has its kink at e = 0;
 * at EA = 1e12 N the equilibrium strain is ~4e-10, below any fixed step
 * worth taking). The tension is EA e exactly, with no cancellation, so a
 * relative step loses nothing to rounding. */
#define STRAIN_FLOOR 1e-14

/* Scale of column j (see linearize.h): scale[] holds the coordinates'
 * and rates' own (state columns), then the inputs follow; the frame
 * inputs start at input `fin`. A turn rate moves a point at distance r
 * from the tow point by Omega r, so its scale is the tow velocity's over
 * the system's reach (every link's length and the tow point's distance
 * from M's origin): the step then changes no velocity by more than a
 * tow velocity's step does. */
static double column_scale(const ts_system *sys, const ts_frame *fr, int j,
                           int n, int fin, const double *scale)
{
    if (j < n)
        return scale[j];
    double g = sys->env.gravity > 0 ? sys->env.gravity : 1.0;
    double V = fabs(fr->speed);
    double l0 = sys->nlinks > 0 ? sys->links[0].length : 1.0;
    int c = j - n;
    double reach = ts_system_reach(sys);
    if (!(reach > 0))
        reach = 1.0;
    if (c < TS_IN_VEL)
        return l0;
    if (c < TS_IN_ACC)
        return sqrt(g * l0) + V;
    if (c < TS_IN_ROT)
        return g;
    /* A tow rotation moves a point at distance r by theta r: over the
     * reach, as the turn rate below. */
    if (c < TS_IN_ROT_VEL)
        return l0 / reach;
    if (c < TS_IN_ROT_ACC)
        return (sqrt(g * l0) + V) / reach;
    if (c < TS_NINPUT)
        return g / reach;
    if (c >= fin && c < fin + TS_NFRAME_INPUT)
        return tsi_frame_input_scale(sys, fr, c - fin);
    return 1.0; /* a deflection or a loop input, rad */
}

/* The state columns' scales (see linearize.h): a link's angle 1 rad, its
 * strain STRAIN_FLOOR, their rates (sqrt(g l) + |V|) / l (times
 * STRAIN_SCALE for a strain); a vehicle's angle 1 rad and its rates
 * (sqrt(g l) + |V|) / l with l its hull's length (or 1 m); a controller
 * state 1 (rad, or m s / rad s for an integrator). */
static void state_scales(const ts_kernel *k, const ts_frame *fr,
                         double *scale)
{
    const ts_system *sys = ts_kernel_system(k);
    int nq = ts_kernel_nq(k), n = ts_kernel_nstate(k);
    double g = sys->env.gravity > 0 ? sys->env.gravity : 1.0;
    double V = fabs(fr->speed);
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        int o = ts_kernel_link_offset(k, l);
        double rate = (sqrt(g * L->length) + V) / L->length;
        scale[o] = scale[o + 1] = 1.0;
        scale[nq + o] = scale[nq + o + 1] = rate;
        if (L->elastic) {
            scale[o + 2] = STRAIN_FLOOR;
            scale[nq + o + 2] = STRAIN_SCALE * rate;
        }
    }
    for (int v = 0; v < ts_kernel_nvehicles(k); v++) {
        const ts_vehicle *d = sys->bodies[ts_kernel_vehicle_body(k, v)].vehicle;
        double l = 1.0;
        for (int c = 0; c < d->ncomponents; c++)
            if (d->component[c].type == TS_COMP_HULL)
                l = d->component[c].length;
        int o = ts_kernel_vehicle_offset(k, v);
        /* A surface ship's yaw alone, then x and y. */
        int root = v == ts_kernel_root(k);
        int na = root && ts_kernel_root_dof(k) == 3 ? 1 : 3;
        for (int j = 0; j < na; j++) {
            scale[o + j] = 1.0;
            scale[nq + o + j] = (sqrt(g * l) + V) / l;
        }
        if (root)
            /* The towing vehicle's position: its length, and speeds. */
            for (int j = na; j < ts_kernel_root_dof(k); j++) {
                scale[o + j] = l;
                scale[nq + o + j] = sqrt(g * l) + V;
            }
    }
    for (int j = 2 * nq; j < n; j++)
        scale[j] = 1.0;
}

/* Count nodes within twice the largest step that moves them of z = 0. */
static void find_kinks(const ts_system *sys, ts_linear *lin, int n)
{
    lin->kinks = 0;
    lin->kink_tow = 0;
    lin->kink_node = -1;
    if (!(sys->env.water_density > 0))
        return;
    double hz = lin->h[n + TS_IN_DISP + 2];
    double *reach = calloc((size_t)sys->nnodes, sizeof(double));
    if (!reach)
        return;
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        int o = lin->qoff[l];
        double hl = lin->len0[l] * fmax(lin->h[o], lin->h[o + 1]);
        if (lin->elastic[l])
            hl = fmax(hl, L->length * lin->h[o + 2]);
        reach[L->lower] = fmax(reach[L->upper], hl);
    }
    for (int i = 0; i < sys->nnodes; i++) {
        double dz = 2.0 * fmax(reach[i], hz);
        if (fabs(lin->r0[3 * i + 2]) <= dz) {
            lin->kinks++;
            if (i == 0)
                lin->kink_tow = 1;
            else if (lin->kink_node < 0)
                lin->kink_node = i;
        }
    }
    free(reach);
}

/* Kinks of the sparse model: nodes (the tow point included) within twice
 * their own vertical position step of z = 0 while the fluid has density. */
static void sparse_kinks(const ts_system *sys, ts_linear *lin)
{
    const ts_descriptor *d = lin->desc;
    lin->kinks = 0;
    lin->kink_tow = 0;
    lin->kink_node = -1;
    if (!(sys->env.water_density > 0))
        return;
    for (int i = 0; i < sys->nnodes; i++)
        if (fabs(d->r0[3 * i + 2]) <= 2.0 * d->hr[3 * i + 2]) {
            lin->kinks++;
            if (i == 0)
                lin->kink_tow = 1;
            else if (lin->kink_node < 0)
                lin->kink_node = i;
        }
}

/* ---- Neutral modes by symmetry (a towing vehicle) ------------------------ */

/* A generator is confirmed when every row of A g - lambda g lies within
 * this many times its error allowance (the truncation estimate and the
 * rounding noise of the row, applied to |g|), the safety factor of the
 * eigenvalue bounds (lib/eigen.c). */
#define NEUTRAL_SAFETY 10.0
/* Without the error estimate: rows within this fraction of max |A_ij|
 * times |g|_1. */
#define NEUTRAL_RTOL 1e-6
/* A finite rotation of the vehicles' attitudes (rad), differenced
 * centrally for their angle change per radian of heading: its error,
 * (1e-5)^2 / 6 relative, is far below the linearization's. */
#define NEUTRAL_ROTATION 1e-5

/* The error allowance of entry (i, j) of A's lower block (row i of it). */
static double entry_allowance(const ts_linear *lin, int i, int j)
{
    int n = lin->nstate, nlow = n - lin->nq;
    if (!lin->Aerr)
        return NEUTRAL_RTOL * lin->a_scale;
    double a = fabs(lin->Aerr[i + (size_t)j * nlow]);
    if (lin->fnoise)
        a += lin->fnoise[i] / (M_SQRT2 * lin->h[j]);
    return a;
}

static int column_cyclic_sparse(const ts_linear *lin, int j);

/* Whether state column j of A is zero within its error: a state the
 * kernel does not read (without the dense A: column_cyclic_sparse). */
static int column_cyclic(const ts_linear *lin, int j)
{
    if (!lin->A)
        return column_cyclic_sparse(lin, j);
    int n = lin->nstate, nq = lin->nq;
    const double *col = lin->A + (size_t)j * n;
    for (int i = nq; i < n; i++)
        if (!(fabs(col[i]) <= NEUTRAL_SAFETY *
                                  entry_allowance(lin, i - nq, j)))
            return 0;
    return 1;
}

/* The sparse model's test of a motion y (lambda, g; complex, kernel
 * states) against its error: the point and controller rows
 * (tsi_desc_motion_check) with the states of `cut` (NULL: none) taken as
 * zero in the displacements, within NEUTRAL_SAFETY of their allowances.
 * The upper rows (q' = q') are the caller's. */
static int motion_confirmed(const ts_linear *lin, double complex lambda,
                            const double complex *g, const char *cut)
{
    const ts_descriptor *d = lin->desc;
    int nq = lin->nq;
    size_t n3 = 3 * (size_t)d->np;
    double *q = malloc(((size_t)nq + 1 + 2 * n3) * sizeof(double));
    double complex *p = malloc((2 * n3 + (size_t)d->nc + 1) * sizeof *p);
    if (!q || !p) {
        free(q);
        free(p);
        return 0;
    }
    double *u = q + nq + 1;
    double complex *pv = p + n3, *c = pv + n3;
    for (int rate = 0; rate < 2; rate++) {
        for (int part = 0; part < 2; part++) {
            for (int i = 0; i < nq; i++) {
                double complex z = g[rate * nq + i];
                q[i] = !rate && cut && cut[i] ? 0.0
                                              : (part ? cimag(z) : creal(z));
            }
            tsi_desc_to_points(d, lin, q, u + part * n3);
        }
        double complex *out = rate ? pv : p;
        for (size_t i = 0; i < n3; i++)
            out[i] = u[i] + I * u[n3 + i];
    }
    for (int j = 0; j < d->nc; j++)
        c[j] = g[2 * nq + j];
    double ratio = tsi_desc_motion_check(d, lambda, p, pv, c);
    free(q);
    free(p);
    return ratio <= NEUTRAL_SAFETY;
}

/* column_cyclic on the sparse model (no dense A): the translation of the
 * whole system by state j (every node moved alike, the angles kept)
 * meets no force and no controller rate within the error. */
static int column_cyclic_sparse(const ts_linear *lin, int j)
{
    int n = lin->nstate;
    double complex *g = calloc((size_t)n, sizeof *g);
    if (!g)
        return 0;
    g[j] = 1.0;
    int ok = motion_confirmed(lin, 0.0, g, NULL);
    free(g);
    return ok;
}

/* Whether (lambda, g) is an eigenpair of A with the cyclic states' rows
 * and columns removed (the model the eigen analysis factors), within the
 * linearization's error. */
static int neutral_confirmed(const ts_linear *lin, double complex lambda,
                             const double complex *g, const char *cyclic)
{
    int n = lin->nstate, nq = lin->nq;
    double gmax = 0;
    for (int j = 0; j < n; j++)
        gmax = fmax(gmax, cabs(g[j]));
    if (!lin->A) {
        /* The sparse model: the upper rows [0 I 0] here, exact; the
         * lower ones as the point and controller rows' residuals. */
        for (int i = 0; i < nq; i++)
            if (!cyclic[i] && !(cabs(g[nq + i] - lambda * g[i]) <=
                                8 * DBL_EPSILON * (1.0 + cabs(lambda)) *
                                    gmax))
                return 0;
        return motion_confirmed(lin, lambda, g, cyclic);
    }
    for (int i = 0; i < n; i++) {
        double complex r = cyclic[i] ? 0.0 : -lambda * g[i];
        double allow = 0;
        for (int j = 0; j < n; j++) {
            if (cyclic[i] || cyclic[j] || g[j] == 0.0)
                continue;
            r += lin->A[i + (size_t)j * n] * g[j];
            if (i >= nq)
                allow += entry_allowance(lin, i - nq, j) * cabs(g[j]);
        }
        /* The upper rows [0 I 0] are exact: rounding of g only. */
        allow = i < nq ? 8 * DBL_EPSILON * (1.0 + cabs(lambda)) * gmax
                       : NEUTRAL_SAFETY * allow;
        if (!(cabs(r) <= allow))
            return 0;
    }
    return 1;
}

/* The heading generator: every link direction and every vehicle's
 * attitude turned about M's vertical, per radian, into g (angles and
 * strains; the tow point's part is the caller's). */
static int heading_generator(ts_kernel *k, const ts_linear *lin,
                             double complex *g)
{
    const ts_system *sys = ts_kernel_system(k);
    int n = lin->nstate;
    for (int l = 0; l < sys->nlinks; l++) {
        /* w = e_z x n0, the direction's change; solve dn dtheta = w. */
        const double *nn = lin->n0 + 3 * l, *d1 = lin->dn + 6 * l,
                     *d2 = d1 + 3;
        double w[3] = {-nn[1], nn[0], 0.0};
        double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
        for (int c = 0; c < 3; c++) {
            a11 += d1[c] * d1[c];
            a12 += d1[c] * d2[c];
            a22 += d2[c] * d2[c];
            b1 += d1[c] * w[c];
            b2 += d2[c] * w[c];
        }
        double det = a11 * a22 - a12 * a12;
        if (!(fabs(det) > 0))
            return -1;
        g[lin->qoff[l]] = (a22 * b1 - a12 * b2) / det;
        g[lin->qoff[l] + 1] = (a11 * b2 - a12 * b1) / det;
    }
    double *y = malloc((size_t)n * sizeof(double));
    double *y2 = malloc((size_t)n * sizeof(double));
    if (!y || !y2) {
        free(y);
        free(y2);
        return -1;
    }
    const double eps = NEUTRAL_ROTATION;
    for (int v = 0; v < lin->nvehicles; v++) {
        double R[9], om[3], Rr[2][9];
        ts_kernel_get_vehicle(k, v, lin->y0, R, om);
        for (int s = 0; s < 2; s++) {
            double c = cos(s ? -eps : eps), sn = sin(s ? -eps : eps);
            for (int j = 0; j < 3; j++) {
                Rr[s][j] = c * R[j] - sn * R[3 + j];
                Rr[s][3 + j] = sn * R[j] + c * R[3 + j];
                Rr[s][6 + j] = R[6 + j];
            }
        }
        memcpy(y, lin->y0, (size_t)n * sizeof(double));
        memcpy(y2, lin->y0, (size_t)n * sizeof(double));
        ts_kernel_set_vehicle(k, v, Rr[0], om, 0.0, y);
        ts_kernel_set_vehicle(k, v, Rr[1], om, 0.0, y2);
        /* Its angles: three, or a surface ship's yaw alone. */
        int qo = ts_kernel_vehicle_offset(k, v);
        int na = v == ts_kernel_root(k) && ts_kernel_root_dof(k) == 3 ? 1 : 3;
        for (int j = 0; j < na; j++)
            g[qo + j] = (y[qo + j] - y2[qo + j]) / (2 * eps);
    }
    free(y);
    free(y2);
    return 0;
}

/* Add neutral mode `name` (lambda, g) to lin when A confirms it. */
static int neutral_add(ts_linear *lin, const char *name, double complex lambda,
                       const double complex *g, int cyclic_state,
                       const char *cyclic)
{
    if (!neutral_confirmed(lin, lambda, g, cyclic))
        return TS_OK;
    int n = lin->nstate, m = lin->nneutral;
    double *re = realloc(lin->neutral_re, (size_t)n * (m + 1) * sizeof *re);
    if (!re)
        return TS_ENOMEM;
    lin->neutral_re = re;
    double *im = realloc(lin->neutral_im, (size_t)n * (m + 1) * sizeof *im);
    if (!im)
        return TS_ENOMEM;
    lin->neutral_im = im;
    for (int i = 0; i < n; i++) {
        re[(size_t)m * n + i] = creal(g[i]);
        im[(size_t)m * n + i] = cimag(g[i]);
    }
    ts_neutral *nm = &lin->neutral[m];
    nm->re = creal(lambda);
    nm->im = cimag(lambda);
    nm->cyclic = cyclic_state;
    snprintf(nm->name, sizeof nm->name, "%s", name);
    lin->nneutral = m + 1;
    return TS_OK;
}

/* The towing vehicle's neutral modes (ts_linear.neutral; doc/linear.md
 * section 3a): candidates from the geometry, each kept when the dense A
 * confirms it. */
static int neutral_modes(ts_kernel *k, const ts_frame *fr, ts_linear *lin,
                         ts_err *err)
{
    lin->nneutral = 0;
    free(lin->neutral_re);
    free(lin->neutral_im);
    lin->neutral_re = lin->neutral_im = NULL;
    if (lin->root_qoff < 0 || (!lin->A && !lin->desc))
        return TS_OK;
    int n = lin->nstate, nq = lin->nq, ro = lin->root_qoff;
    double complex *g = calloc((size_t)n, sizeof *g);
    char *cyclic = calloc((size_t)n, 1);
    int rc = g && cyclic ? TS_OK : TS_ENOMEM;
    /* Straight: the position along and across the track are read
     * nowhere (no frame rotation to make them matter); their columns of A
     * are zero within the error and their rows [0 I] make each a pure
     * integrator of its rate. */
    int straight = rc == TS_OK &&
                   column_cyclic(lin, ro) && column_cyclic(lin, ro + 1);
    if (straight) {
        cyclic[ro] = cyclic[ro + 1] = 1;
        static const char *const names[2] = {"along-track position",
                                             "cross-track position"};
        for (int c = 0; c < 2 && rc == TS_OK; c++) {
            memset(g, 0, (size_t)n * sizeof *g);
            g[ro + c] = 1.0;
            rc = neutral_add(lin, names[c], 0.0, g, ro + c, cyclic);
        }
    }
    double V = fr->speed, W = fr->turn_rate;
    if (rc == TS_OK && (straight || W != 0.0)) {
        /* Heading: the whole system turned about the vertical. In a
         * straight tow the turned motion moves sideways in M at the speed
         * through the water (the tow point's rate per radian); in a turn
         * it is the same circle
         * at another phase, every point turned about the centre C = (0,
         * V/Omega, 0): the tow point (on M's z axis) moves by e_z x (r_A -
         * C) = (V/Omega, 0, 0), at rest in M. */
        memset(g, 0, (size_t)n * sizeof *g);
        if (heading_generator(k, lin, g) != 0)
            rc = TS_ENOMEM;
        if (straight) {
            /* The turned motion through the water, e_z x (V e_x - c) per
             * radian relative to M (a uniform current c turns nothing). */
            g[nq + ro] = fr->current[1];
            g[nq + ro + 1] = V - fr->current[0];
        } else
            g[ro] = V / W;
        if (rc == TS_OK)
            rc = neutral_add(lin, "heading", 0.0, g, -1, cyclic);
    }
    if (rc == TS_OK && !straight && W != 0.0) {
        /* The turn's centre moved by d: in M, turning at Omega, a fixed
         * offset of the earth frame is d(t) = e^(i |Omega| t) (1, i sgn
         * Omega, 0), at the tow point and its rate; the shape unchanged. */
        double complex lam = I * fabs(W);
        double sg = W > 0 ? 1.0 : -1.0;
        memset(g, 0, (size_t)n * sizeof *g);
        g[ro] = 1.0;
        g[ro + 1] = I * sg;
        g[nq + ro] = lam;
        g[nq + ro + 1] = lam * I * sg;
        rc = neutral_add(lin, "turn centre", lam, g, -1, cyclic);
    }
    free(g);
    free(cyclic);
    if (rc != TS_OK)
        return ts_fail(err, TS_ENOMEM, "linearize: out of memory for the "
                                       "neutral modes");
    return TS_OK;
}

int ts_linearize(ts_kernel *k, const double y0[], const double u0[],
                 const ts_linearize_opts *opts, ts_linear *lin, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    ts_linearize_opts o;
    if (opts)
        o = *opts;
    else
        ts_linearize_opts_default(&o);
    int n = ts_kernel_nstate(k), nq = ts_kernel_nq(k), nl = sys->nlinks;
    int fin = ts_kernel_ninput(k), ni = fin + TS_NFRAME_INPUT;
    int ncol = n + ni, nlow = n - nq;
    int nout = lin->noutput;
    if (lin->nstate != n || lin->nlinks != nl || lin->ninput != ni ||
        lin->nq != nq)
        return ts_fail(err, TS_EINVAL,
                       "linearize: result sized for %d states and %d "
                       "inputs, kernel has %d and %d",
                       lin->nstate, lin->ninput, n, ni);
    if (!(o.rel_step > 0 && o.rel_step < 0.1))
        return ts_fail(err, TS_EINVAL,
                       "linearize: rel_step must be in (0, 0.1), got %g",
                       o.rel_step);
    if (o.model < TS_LIN_AUTO || o.model > TS_LIN_BOTH)
        return ts_fail(err, TS_EINVAL, "linearize: unknown model %d",
                       (int)o.model);
    /* The sparse model covers cables, links, lumped bodies, towed
     * vehicles (their attitude and controller states) and a towing
     * vehicle at the root (its position, attitude and controller
     * states). */
    int dense = o.model == TS_LIN_DENSE || o.model == TS_LIN_BOTH ||
                (o.model == TS_LIN_AUTO && n < o.dense_max_states);
    int sparse = o.model != TS_LIN_DENSE;
    ts_err derr = {0};
    if (sparse && !lin->desc && !(lin->desc = tsi_desc_alloc(k, &derr))) {
        /* A system the sparse model does not cover (a vehicle whose
         * controller states are not one block of its own): the dense
         * model, when the caller left the choice. */
        if (derr.code != TS_EINVAL || o.model != TS_LIN_AUTO)
            return ts_fail(err, derr.code, "%s", derr.msg);
        sparse = 0;
        dense = 1;
    }
    memset(lin->u0, 0, (size_t)ni * sizeof(double));
    if (u0)
        memcpy(lin->u0, u0, (size_t)fin * sizeof(double));
    u0 = lin->u0;
    memcpy(lin->y0, y0, (size_t)n * sizeof(double));
    lin->evaluations = 0;
    lin->residual_evaluations = 0;
    /* Dense arrays only for the dense model: a result reused with another
     * model keeps nothing stale. */
    if (!dense) {
        free(lin->A);
        free(lin->B);
        free(lin->Ty);
        free(lin->Tu);
        free(lin->Aerr);
        lin->A = lin->B = lin->Ty = lin->Tu = lin->Aerr = NULL;
    }
    if (!sparse) {
        tsi_desc_free(lin->desc);
        lin->desc = NULL;
    }
    if (dense && (!lin->A || !lin->B)) {
        size_t sn = (size_t)n;
        free(lin->A);
        free(lin->B);
        lin->A = calloc(sn * sn, sizeof(double));
        lin->B = calloc(sn * (size_t)ni, sizeof(double));
        if (!lin->A || !lin->B) {
            free(lin->A);
            free(lin->B);
            lin->A = lin->B = NULL;
            return ts_fail(err, TS_ENOMEM,
                           "linearize: out of memory for a %d x %d matrix A "
                           "(%.3g MB); the sparse model (TS_LIN_SPARSE) "
                           "needs O(links) memory",
                           n, n, 8e-6 * (double)sn * (double)sn);
        }
    }
    if (dense && o.tensions && (!lin->Ty || !lin->Tu)) {
        free(lin->Ty);
        free(lin->Tu);
        lin->Ty = malloc((size_t)nl * (size_t)n * sizeof(double));
        lin->Tu = malloc((size_t)nl * (size_t)ni * sizeof(double));
        if (!lin->Ty || !lin->Tu)
            return ts_fail_nomem(err, 8.0 * nl * (double)(n + ni),
                                 "fewer links", "linearize: out of memory "
                                 "for the %d x %d tension Jacobian", nl, n);
    }

    if (dense && o.estimate_error && !lin->Aerr) {
        lin->Aerr = malloc((size_t)nlow * (size_t)n * sizeof(double));
        if (!lin->Aerr)
            return ts_fail_nomem(err, 8.0 * nlow * (double)n, "fewer links, "
                                 "or estimate_error = 0", "linearize: out "
                                 "of memory for the %d x %d error estimate",
                                 nlow, n);
    }
    if (o.estimate_error && !lin->fnoise) {
        lin->fnoise = calloc((size_t)(nlow > 0 ? nlow : 1), sizeof(double));
        lin->Berr = malloc((size_t)(nlow > 0 ? nlow : 1) * (size_t)ni *
                           sizeof(double));
        if (!lin->fnoise || !lin->Berr)
            return ts_fail(err, TS_ENOMEM, "linearize: out of memory");
    }
    /* The output rows' own errors: tensions (with opts.tensions) and the
     * vehicles' outputs, beside their Jacobians. */
    free(lin->Terr);
    free(lin->Verr);
    free(lin->onoise);
    lin->Terr = lin->Verr = lin->onoise = NULL;
    if (dense && o.estimate_error) {
        size_t cols = (size_t)n + (size_t)ni;
        if (o.tensions)
            lin->Terr = calloc((size_t)nl * cols, sizeof(double));
        if (nout > 0)
            lin->Verr = calloc((size_t)nout * cols, sizeof(double));
        lin->onoise = malloc(((size_t)nl + (size_t)nout + 1) *
                             sizeof(double));
        if ((o.tensions && !lin->Terr) || (nout > 0 && !lin->Verr) ||
            !lin->onoise)
            return ts_fail(err, TS_ENOMEM, "linearize: out of memory for "
                           "the output rows' error estimate");
        for (int i = 0; i < nl + nout; i++)
            lin->onoise[i] = NAN;
    }
    if (!o.estimate_error) {
        free(lin->Aerr);
        lin->Aerr = NULL;
        free(lin->fnoise);
        lin->fnoise = NULL;
        free(lin->Berr);
        lin->Berr = NULL;
    }
    lin->round_norm = NAN;

    /* Base point: f0, positions, tensions, direction derivatives. */
    int rc = ts_kernel_eval(k, y0, u0, lin->f0);
    lin->evaluations++;
    if (rc != TS_OK)
        return ts_fail(err, rc, "linearize: the kernel fails at the state "
                                "to linearize about (%s)",
                       ts_strerror(rc));
    memcpy(lin->r0, ts_kernel_positions(k),
           3 * (size_t)sys->nnodes * sizeof(double));
    memcpy(lin->t0, ts_kernel_tensions(k), (size_t)nl * sizeof(double));
    if (nout > 0)
        ts_kernel_outputs(k, lin->v0);
    const double *nk = ts_kernel_directions(k);
    for (int l = 0; l < nl; l++) {
        int qo = lin->qoff[l];
        memcpy(lin->n0 + 3 * l, nk + 3 * l, 3 * sizeof(double));
        lin->len0[l] = sys->links[l].length *
                       (lin->elastic[l] ? 1.0 + y0[qo + 2] : 1.0);
    }
    for (int l = 0; l < nl; l++) {
        int qo = lin->qoff[l];
        double t1 = y0[qo], t2 = y0[qo + 1], a[3], b[3], ey[3];
        double *d1 = lin->dn + 6 * l, *d2 = d1 + 3;
        ts_kernel_direction(k, l, t1 + M_PI_2, t2, a);
        ts_kernel_direction(k, l, 0.0, M_PI_2, ey);
        ts_kernel_direction(k, l, t1, t2 + M_PI_2, b);
        double s2 = sin(t2);
        for (int c = 0; c < 3; c++) {
            d1[c] = a[c] - s2 * ey[c];
            d2[c] = b[c];
        }
    }

    /* Each vehicle's small rotation per change of its angles, R E. */
    for (int v = 0; v < lin->nvehicles; v++) {
        double R[9], om[3], E[9];
        int qo = ts_kernel_vehicle_offset(k, v);
        int ship = v == ts_kernel_root(k) && ts_kernel_root_dof(k) == 3;
        double th[3] = {0, 0, y0[qo]};
        ts_kernel_get_vehicle(k, v, y0, R, om);
        tsi_rate_matrix(ship ? th : y0 + qo, E);
        double *map = lin->veh_rot + 9 * v;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                map[3 * i + j] = R[3 * i] * E[j] + R[3 * i + 1] * E[3 + j] +
                                 R[3 * i + 2] * E[6 + j];
        if (ship)
            /* A surface ship's one angle is its yaw, followed in q by its
             * position: the yaw's column first, the others none. */
            for (int i = 0; i < 3; i++) {
                map[3 * i] = map[3 * i + 2];
                map[3 * i + 1] = map[3 * i + 2] = 0.0;
            }
        lin->veh_qoff[v] = qo;
    }

    /* A cable starting at a point P of a vehicle moves with the body:
     * dr_P = dr_A + (R E dtheta) x rho_P (rho_P = R (P - A)). */
    for (int l = 0; lin->nvehicles > 0 && l < nl; l++) {
        const ts_link *L = &sys->links[l];
        lin->up_qoff[l] = -1;
        if (L->up_body < 0)
            continue;
        int v = 0;
        while (ts_kernel_vehicle_body(k, v) != L->up_body)
            v++;
        const ts_vehicle *d = sys->bodies[L->up_body].vehicle;
        double R[9], om[3], lev[3];
        int qo = ts_kernel_vehicle_offset(k, v);
        ts_kernel_get_vehicle(k, v, y0, R, om);
        double *map = lin->up_map + 12 * l;
        memcpy(map, lin->veh_rot + 9 * v, 9 * sizeof(double));
        for (int j = 0; j < 3; j++)
            lev[j] = L->up_point[j] - d->attach[j];
        for (int j = 0; j < 3; j++)
            map[9 + j] = R[3 * j] * lev[0] + R[3 * j + 1] * lev[1] +
                         R[3 * j + 2] * lev[2];
        lin->up_qoff[l] = qo;
    }
    tow_levers(k, sys, y0, lin->tow_lever);

    ts_frame fr;
    ts_kernel_get_frame(k, &fr);
    double *scale = malloc((size_t)n * sizeof(double));
    if (!scale)
        return ts_fail(err, TS_ENOMEM, "linearize: out of memory");
    state_scales(k, &fr, scale);
    for (int j = 0; j < ncol; j++) {
        double x = j < n ? y0[j] : u0[j - n];
        lin->h[j] = step_for(x, column_scale(sys, &fr, j, n, fin, scale),
                             o.rel_step);
    }
    free(scale);
    find_kinks(sys, lin, n);

    int nthreads = 1;
#ifdef _OPENMP
    nthreads = o.threads > 0 ? o.threads
               : (nl >= TS_LINEARIZE_PARALLEL_LINKS ? omp_get_max_threads()
                                                    : 1);
    if (nthreads < 1)
        nthreads = 1;
#endif
    lin->threads = nthreads;
    lin->groups = 0;
    lin->desc_err = lin->desc_round = NAN;
    if (sparse) {
        /* The kernel's last evaluation is the base point: the sparse model
         * starts from its positions, velocities, accelerations and
         * tensions. */
        lin->desc->frame = o.frame_inputs;
        rc = tsi_desc_linearize(lin->desc, k, y0, u0, lin->f0, o.rel_step,
                                o.estimate_error, nthreads, err);
        if (rc != TS_OK)
            return rc;
        const ts_descriptor *d = lin->desc;
        lin->residual_evaluations = d->evaluations;
        lin->groups = d->groups;
        if (o.estimate_error) {
            lin->desc_err = fmax(d->k_scale > 0 ? d->k_err / d->k_scale : 0,
                                 d->c_scale > 0 ? d->c_err / d->c_scale : 0);
            lin->desc_round =
                fmax(d->k_scale > 0 ? d->k_round / d->k_scale : 0,
                     d->c_scale > 0 ? d->c_round / d->c_scale : 0);
        }
    }
    if (!dense) {
        /* Kinks: nodes within twice their own position step of the
         * surface. */
        if (sparse)
            sparse_kinks(sys, lin);
        lin->trunc_err = lin->trunc_norm = lin->b_trunc_err = NAN;
        lin->t_trunc_err = lin->a_scale = lin->a_norm = NAN;
        double *ftmp = malloc((size_t)n * sizeof(double));
        if (!ftmp)
            return ts_fail(err, TS_ENOMEM, "linearize: out of memory");
        ts_kernel_eval(k, y0, u0, ftmp);
        lin->evaluations++;
        free(ftmp);
        return neutral_modes(k, &fr, lin, err);
    }

    /* Upper blocks: [0 I 0] and 0, exactly. */
    for (int j = 0; j < n; j++) {
        double *colj = lin->A + (size_t)j * n;
        memset(colj, 0, (size_t)nq * sizeof(double));
        if (j >= nq && j < 2 * nq)
            colj[j - nq] = 1.0;
    }
    for (int j = 0; j < ni; j++)
        memset(lin->B + (size_t)j * n, 0, (size_t)nq * sizeof(double));

    if (nthreads > ncol)
        nthreads = ncol;
    lin->threads = nthreads;
    col_ws *ws = calloc((size_t)nthreads, sizeof *ws);
    if (!ws)
        return ts_fail(err, TS_ENOMEM, "linearize: out of memory");
    for (int t = 0; t < nthreads && rc == TS_OK; t++)
        rc = col_ws_alloc(&ws[t], k, t == 0, y0, u0, n, ni, nl, nout, err);
    if (rc != TS_OK) {
        for (int t = 0; t < nthreads; t++)
            col_ws_free(&ws[t], k);
        free(ws);
        return ts_fail(err, TS_ENOMEM, "linearize: out of memory for %d "
                                       "thread work areas",
                       nthreads);
    }

    double max_a = 0, sum2_a = 0, max_b = 0, max_t = 0;
    int bad_col = -1, bad_rc = TS_OK;
    const int estimate = o.estimate_error != 0;
    const int with_t = o.tensions != 0;
#ifdef _OPENMP
#pragma omp parallel num_threads(nthreads) reduction(max : max_a, max_b, max_t) \
    reduction(+ : sum2_a)
#endif
    {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        col_ws *w = &ws[tid];
#ifdef _OPENMP
#pragma omp for schedule(dynamic, 8)
#endif
        for (int j = 0; j < ncol; j++) {
            double *col = j < n ? lin->A + (size_t)j * n + nq
                                : lin->B + (size_t)(j - n) * n + nq;
            double *tcol = NULL;
            if (with_t)
                tcol = j < n ? lin->Ty + (size_t)j * nl
                             : lin->Tu + (size_t)(j - n) * nl;
            double *ecol = !estimate ? NULL
                           : j < n   ? lin->Aerr + (size_t)j * nlow
                                     : lin->Berr + (size_t)(j - n) * nlow;
            double *ocol = NULL;
            if (nout > 0)
                ocol = j < n ? lin->Vy + (size_t)j * nout
                             : lin->Vu + (size_t)(j - n) * nout;
            double *tecol = lin->Terr ? lin->Terr + (size_t)j * nl : NULL;
            double *oecol = lin->Verr ? lin->Verr + (size_t)j * nout : NULL;
            col_err ce;
            int crc = column(w, j, n, nq, nl, nout, lin->h[j], estimate, col,
                             ecol, tcol, ocol, tecol, oecol, &ce);
            if (crc != TS_OK) {
#ifdef _OPENMP
#pragma omp critical(ts_linearize_fail)
#endif
                if (bad_col < 0 || j < bad_col) {
                    bad_col = j;
                    bad_rc = crc;
                }
                continue;
            }
            if (j < n) {
                max_a = fmax(max_a, ce.max_a);
                sum2_a += ce.sum2_a;
            } else {
                max_b = fmax(max_b, ce.max_a);
            }
            max_t = fmax(max_t, ce.max_t);
        }
    }
    for (int t = 0; t < nthreads; t++)
        col_ws_free(&ws[t], k);
    free(ws);
    lin->evaluations += (long)ncol * (estimate ? 4 : 2);

    /* The kernel's rounding noise (beside the truncation error). */
    int noise_rc = estimate && bad_col < 0
                       ? kernel_noise(k, y0, u0, lin, err) : TS_ECONV;
    if (noise_rc == TS_EIO)
        return noise_rc; /* LAPACK missing: err says so */
    if (noise_rc == TS_OK) {
        double sr = 0, sh = 0;
        for (int i = 0; i < nlow; i++)
            sr += lin->fnoise[i] * lin->fnoise[i];
        for (int j = 0; j < n; j++)
            sh += 1.0 / (2.0 * lin->h[j] * lin->h[j]);
        lin->round_norm = sqrt(sr * sh);
    }

    /* Leave the kernel's results at the base point. */
    double *ftmp = malloc((size_t)n * sizeof(double));
    if (ftmp) {
        ts_kernel_eval(k, y0, u0, ftmp);
        lin->evaluations++;
        free(ftmp);
    }
    if (bad_col >= 0) {
        if (bad_col < 2 * nq)
            return ts_fail(err, bad_rc < 0 ? bad_rc : TS_CHART,
                           "linearize: state column %d (%s of q[%d]) "
                           "perturbed by %.3g left the model (%s)",
                           bad_col, bad_col < nq ? "coordinate" : "rate",
                           bad_col % nq, lin->h[bad_col],
                           ts_strerror(bad_rc));
        if (bad_col < n)
            return ts_fail(err, bad_rc < 0 ? bad_rc : TS_CHART,
                           "linearize: controller state %d perturbed by "
                           "%.3g left the model (%s)",
                           bad_col - 2 * nq, lin->h[bad_col],
                           ts_strerror(bad_rc));
        return ts_fail(err, bad_rc < 0 ? bad_rc : TS_CHART,
                       "linearize: input %s perturbed by %.3g left the model "
                       "(%s)",
                       lin->input_name[bad_col - n], lin->h[bad_col],
                       ts_strerror(bad_rc));
    }
    lin->trunc_err = estimate ? max_a : NAN;
    lin->trunc_norm = estimate ? sqrt(sum2_a) : NAN;
    lin->b_trunc_err = estimate ? max_b : NAN;
    lin->t_trunc_err = estimate && with_t ? max_t : NAN;
    double amax = 0, afro = 0;
    for (int j = 0; j < n; j++) {
        const double *colj = lin->A + (size_t)j * n;
        for (int i = 0; i < n; i++) {
            afro += colj[i] * colj[i];
            if (i >= nq && fabs(colj[i]) > amax)
                amax = fabs(colj[i]);
        }
    }
    lin->a_scale = amax;
    lin->a_norm = sqrt(afro);
    return neutral_modes(k, &fr, lin, err);
}

int ts_linearize_equilibrium(ts_kernel *k, const ts_equilibrium *eq,
                             const ts_linearize_opts *opts, ts_linear *lin,
                             ts_err *err)
{
    if (!eq->converged)
        return ts_fail(err, TS_ECONV,
                       "linearize: the equilibrium did not converge "
                       "(relative residual %.3g, target %.3g); a linear model "
                       "about it would describe no steady state, so it is "
                       "not linearized",
                       eq->residual, eq->tolerance);
    int n = ts_kernel_nstate(k);
    double *y = calloc((size_t)n, sizeof(double));
    if (!y)
        return ts_fail(err, TS_ENOMEM, "linearize: out of memory");
    int rc = ts_equilibrium_state(k, eq, y, err);
    if (rc == TS_OK)
        rc = ts_linearize(k, y, NULL, opts, lin, err);
    free(y);
    return rc;
}

void ts_linear_vehicle_rotations(const ts_linear *lin, const double dq[],
                                 double phi[])
{
    for (int v = 0; v < lin->nvehicles; v++) {
        const double *map = lin->veh_rot + 9 * v;
        const double *dth = dq + lin->veh_qoff[v];
        for (int c = 0; c < 3; c++)
            phi[3 * v + c] = map[3 * c] * dth[0] + map[3 * c + 1] * dth[1] +
                             map[3 * c + 2] * dth[2];
    }
}

void ts_linear_tow_shift(const ts_linear *lin, int node, int input,
                         double d[3])
{
    d[0] = d[1] = d[2] = 0.0;
    if (node == 0 && lin->root_qoff >= 0)
        return;
    if (input >= TS_IN_DISP && input < TS_IN_DISP + 3) {
        d[input - TS_IN_DISP] = 1.0;
    } else if (input >= TS_IN_ROT && input < TS_IN_ROT + 3) {
        double e[3] = {0, 0, 0};
        e[input - TS_IN_ROT] = 1.0;
        v3_cross(e, lin->tow_lever + 3 * node, d);
    }
}

void tsi_node_displacements(const ts_system *sys, const ts_linear *lin,
                            int nv, const double *const dq[],
                            double *const dr[])
{
    for (int v = 0; v < nv; v++) {
        dr[v][0] = dr[v][1] = dr[v][2] = 0.0;
        if (lin->root_qoff >= 0)
            for (int c = 0; c < (lin->root_dof == 3 ? 2 : 3); c++)
                dr[v][c] = dq[v][lin->root_qoff + c];
    }
    for (int l = 0; l < sys->nlinks; l++) {
        const ts_link *L = &sys->links[l];
        const double *d1 = lin->dn + 6 * l, *d2 = d1 + 3;
        const double *map = L->up_body >= 0 ? lin->up_map + 12 * l : NULL;
        int o = lin->qoff[l], el = lin->elastic[l];
        double len = lin->len0[l], ln = L->length;
        const double *n0 = lin->n0 + 3 * l;
        for (int v = 0; v < nv; v++) {
            const double *q = dq[v], *rp = dr[v] + 3 * L->upper;
            double *rk = dr[v] + 3 * L->lower, rP[3];
            double de = el ? q[o + 2] : 0.0;
            if (map) {
                /* dr_P = dr_A + (R E dtheta) x rho_P */
                const double *dth = q + lin->up_qoff[l];
                double phi[3];
                for (int c = 0; c < 3; c++)
                    phi[c] = map[3 * c] * dth[0] + map[3 * c + 1] * dth[1] +
                             map[3 * c + 2] * dth[2];
                rP[0] = rp[0] + phi[1] * map[11] - phi[2] * map[10];
                rP[1] = rp[1] + phi[2] * map[9] - phi[0] * map[11];
                rP[2] = rp[2] + phi[0] * map[10] - phi[1] * map[9];
                rp = rP;
            }
            for (int c = 0; c < 3; c++)
                rk[c] = rp[c] + len * (d1[c] * q[o] + d2[c] * q[o + 1]) +
                        ln * n0[c] * de;
        }
    }
}

void ts_linear_node_displacements(const ts_system *sys, const ts_linear *lin,
                                  const double dq[], double dr[])
{
    tsi_node_displacements(sys, lin, 1, &dq, &dr);
}
