/* response.c: frequency response to tow-point motion (towstab/response.h;
 * doc/model.md section 6; Kamman & Nguyen 1990, eqs. 56-65; doc/linear.md,
 * section 4).
 *
 * Algorithm, per frequency w: one solve with the sparse linear model at
 * s = i w driven by the tow point itself (lib/shift.h, tsi_shift_input):
 * the tow point moves by e_input, its neighbours feel -(K_k0 + s C_k0)
 * e_input, the links leaving it are constrained relative to it. One KLU
 * factorisation of S(s) and one solve give every node's absolute
 * displacement and every link's tension: O(nlinks) per frequency. At
 * w = 0 the solve is real and gives the static gain.
 *
 * A towed vehicle's input (a control surface, a loop, a set point) is a
 * column of the model's G, its own rows' -Ku and +Hu, with the tow point
 * at rest; a vehicle's output (depth, pitch, roll, yaw, a loop's output,
 * a deflection) is its row Ov on its node's displacement, its angles,
 * their rates, its controller states and its inputs (lib/descriptor.h).
 *
 * A system the sparse model does not cover (a towing vehicle at the
 * root) takes the dense way: b = B_x + s B_v + s^2 B_a, Z = (s I - A)^-1
 * b by the dense shifted
 * solve of lib/shift.h (one LU of P(s), O(nq^3)), then positions through
 * the link geometry plus the tow displacement, tensions through dT/dy and
 * dT/du. Each gain gets the linearization's error allowance, the sparse
 * way from the model's entry-wise truncation and rounding
 * (sparse_gain_error), the dense way from A's (gain_error).
 */
#include "towstab/response.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "lazylib.h"
#include "response_impl.h"
#include "shift.h"
#include "towstab/system.h"

int ts_response_input_find(const char *name, int *channel, ts_err *err)
{
    for (int a = 0; a < 6; a++) {
        int j = a < 3 ? TS_IN_DISP + a : TS_IN_ROT + a - 3;
        if (strcmp(name, ts_input_name(j)) == 0) {
            *channel = j;
            return TS_OK;
        }
    }
    return ts_fail(err, TS_EINVAL,
                   "input '%s': not an input; expected tow.surge, tow.sway, "
                   "tow.heave (tow-point displacement along x, y, z) or "
                   "tow.roll, tow.pitch, tow.yaw (a small rotation about "
                   "them)",
                   name);
}

void ts_response_output_names(const ts_system *sys, char *buf, size_t size)
{
    ts_output_names(sys, TS_OUT_BIT(TS_OUT_POSITION) |
                             TS_OUT_BIT(TS_OUT_TENSION),
                    buf, size);
    size_t len = strlen(buf);
    if (len < size)
        snprintf(buf + len, size - len, " (tow is the input, not an "
                                        "output)");
}

int ts_response_input_lookup(const ts_kernel *k, const char *name,
                             int *channel, ts_err *err)
{
    /* With a towing vehicle the tow-point inputs move the tow point
     * relative to the vehicle (a wave-induced motion; the kernel). */
    if (ts_response_input_find(name, channel, NULL) == TS_OK)
        return TS_OK;
    int j = ts_kernel_input_find(k, name);
    int fin = ts_kernel_ninput(k);
    for (int c = 0; c < TS_NFRAME_INPUT && j < 0; c++)
        if (!strcmp(name, ts_frame_input_name(c)))
            j = fin + c;
    if (j >= fin + 2)
        return ts_fail(err, TS_EINVAL, "input '%s': the rate of a frame "
                       "input comes with it; give %s", name,
                       j == fin + 2 ? "tow.speed" : "tow.turn_rate");
    if (j >= fin) {
        const ts_system *sys = ts_kernel_system(k);
        if (ts_kernel_root(k) >= 0)
            return ts_fail(err, TS_EINVAL, "input '%s': the mean frame is "
                           "the towing vehicle's own steady motion, not "
                           "prescribed; its speed and turn come from its "
                           "thrust, rudder and loops", name);
        if (j == fin + 1 && (sys->env.current[0] != 0 ||
                             sys->env.current[1] != 0))
            return ts_fail(err, TS_EINVAL, "input '%s': a horizontal "
                           "current (%g, %g m/s) turns in the mean frame "
                           "by the heading change, which the linear model "
                           "has no state for", name, sys->env.current[0],
                           sys->env.current[1]);
    }
    if (j >= TS_NINPUT) {
        *channel = j;
        return TS_OK;
    }
    char list[1024], nm[TS_IO_NAME];
    size_t len = 0;
    list[0] = '\0';
    for (int i = TS_NINPUT; i < fin + 2 && len < sizeof list; i++)
        len += (size_t)snprintf(list + len, sizeof list - len, ", %s",
                                i < fin ? ts_kernel_input_name(k, i, nm,
                                                               sizeof nm)
                                        : ts_frame_input_name(i - fin));
    return ts_fail(err, TS_EINVAL,
                   "input '%s': not an input; expected tow.surge, tow.sway, "
                   "tow.heave, tow.roll, tow.pitch, tow.yaw%s",
                   name, list);
}

/* The columns of B an input brings, into cols, with their factors at s
 * (the input's value X: its velocity s X, its acceleration s^2 X), and
 * how many: a tow displacement its velocity and acceleration columns, a
 * frame input (speed, turn rate) its rate's, a vehicle's input its own
 * column alone. */
static int input_columns(const ts_linear *lin, int input, double complex s,
                         int cols[3], double complex fac[3])
{
    if (input < TS_NINPUT) {
        /* A displacement's velocity is 3 columns after it, its
         * acceleration 6 (TS_IN_VEL, TS_IN_ROT_VEL, ...). */
        for (int q = 0; q < 3; q++)
            cols[q] = input + 3 * q;
        fac[0] = 1.0;
        fac[1] = s;
        fac[2] = s * s;
        return 3;
    }
    cols[0] = input;
    fac[0] = 1.0;
    if (input == lin->frame_input || input == lin->frame_input + 1) {
        cols[1] = input + 2;
        fac[1] = s;
        return 2;
    }
    return 1;
}

int ts_response_output_lookup(const ts_kernel *k, const char *name,
                              ts_output *out, ts_err *err)
{
    const ts_system *sys = ts_kernel_system(k);
    int j = ts_kernel_output_find(k, name);
    if (j >= 0) {
        memset(out, 0, sizeof *out);
        out->kind = TS_OUT_VEHICLE;
        out->index = j;
        out->unit = out->si_unit = ts_kernel_output_unit(k, j);
        snprintf(out->name, sizeof out->name, "%s", name);
        return TS_OK;
    }
    int rc = ts_response_output_find(sys, name, out, err);
    if (rc != TS_OK)
        tsi_response_list_vehicle_outputs(k, err);
    return rc;
}

void tsi_response_list_vehicle_outputs(const ts_kernel *k, ts_err *err)
{
    char nm[TS_IO_NAME];
    size_t len = err ? strlen(err->msg) : 0;
    for (int i = 0; err && i < ts_kernel_noutput(k) && len < sizeof err->msg;
         i++)
        len += (size_t)snprintf(err->msg + len, sizeof err->msg - len,
                                "%s%s", i ? ", " : "; vehicles: ",
                                ts_kernel_output_name(k, i, nm, sizeof nm));
}

int ts_response_output_find(const ts_system *sys, const char *name,
                            ts_output *out, ts_err *err)
{
    int kinds = TS_OUT_BIT(TS_OUT_POSITION) | TS_OUT_BIT(TS_OUT_TENSION);
    int rc = ts_output_find(sys, name, kinds, out, err);
    if (rc == TS_OK || out->kind != TS_OUT_TOW_FORCE)
        return rc;
    char list[768];
    ts_response_output_names(sys, list, sizeof list);
    return ts_fail(err, TS_EINVAL, "output '%s': the frequency response "
                   "covers node positions and link tensions; the force on "
                   "the tow point is an output of simulate (close to it: "
                   "the first link's tension, <cable>.1.tension); valid "
                   "outputs: %s", name, list);
}

int ts_response_logspace(double from, double to, int points, double freq[],
                         ts_err *err)
{
    if (!isfinite(from) || !isfinite(to))
        return ts_fail(err, TS_EINVAL,
                       "frequency range: 'from' and 'to' must be finite, got "
                       "%g .. %g Hz",
                       from, to);
    if (!(from > 0))
        return ts_fail(err, TS_EINVAL,
                       "frequency range: 'from' must be a finite frequency "
                       "> 0 Hz (log spacing), got %g Hz",
                       from);
    if (!(to > from))
        return ts_fail(err, TS_EINVAL,
                       "frequency range: 'to' must be above 'from' (%g Hz), "
                       "got %g Hz: the range is empty",
                       from, to);
    if (points < 2)
        return ts_fail(err, TS_EINVAL,
                       "frequency range: points must be >= 2, got %d",
                       points);
    double a = log(from), b = log(to);
    for (int i = 0; i < points; i++)
        freq[i] = exp(a + (b - a) * i / (points - 1));
    freq[0] = from;
    freq[points - 1] = to;
    return TS_OK;
}

void ts_response_free(ts_response *r)
{
    if (!r)
        return;
    free(r->freq_hz);
    free(r->re);
    free(r->im);
    free(r->magnitude);
    free(r->phase_deg);
    free(r->error);
    free(r);
}

/* Work for one evaluation: node displacements and link tensions (the
 * sparse way), state and input vectors (the dense way). */
typedef struct resp_ws {
    double complex *dr, *dt;
    double complex *b, *x;
    double complex *c, *W, *t3; /* [n], [n], [nc]: the gain's weights, the
                                   transposed solution, work */
    double *dq, *drr, *m; /* m: a position output's row of the node
                             displacement map (for the error) */
    double complex *wt;   /* [nx] the sparse way's transposed solution */
    double complex *z;    /* a vehicle output's local vector (TSI_LV_*) */
    double *zh;           /* its columns' steps */
} resp_ws;

/* The dense way's error allowance of the gain g = c^T x (+ parts free of
 * A, B and the output rows' Jacobian), x = (sI - A)^-1 b, c the output's
 * weights on the state (c1, c2, c3 on q, q' and the controller states):
 * errors dA, db in the lower rows change it by dg = W^T (dA x + db)
 * (up to sign) with W the lower part of (A - sI)^-T c. Without
 * controller states W = P(s)^-T (c1 + s c2) (x2 = s x1 for lower-row
 * z); with them, through the Schur complement of lib/shift.h,
 *
 *     W2 = P^-T (c1 + s c2 - (F + s G)^T (H - sI)^-T c3),
 *     W3 = (H - sI)^-T (c3 - E^T W2),
 *
 * and where H - sI is singular (the whole A - sI factored) W from one
 * transposed solve of it. Parts:
 * - truncation: W^T (Aerr x + db_err), db_err = Berr_x + s Berr_v +
 *   s^2 Berr_a for a tow input, Berr_j for a vehicle's input j;
 * - rounding: the root mean square of W^T N x over the noise N of the
 *   differences, entries fnoise_i / (sqrt(2) h_j) (doc/linear.md,
 *   section 2), and the same for b's columns,
 *   sqrt(sum_i |W_i|^2 fnoise_i^2 / 2) sqrt(sum_j |x_j|^2 / h_j^2 + X_b),
 *   X_b = 1 / h_x^2 + |s|^2 / h_v^2 + |s|^4 / h_a^2 (tow) or 1 / h_j^2;
 * - the output row's own Jacobian (a tension's Ty, Tu; a vehicle
 *   output's Vy, Vu; none for a position, whose map is exact): its
 *   truncation |Jerr_y x + Jerr_u b| and rounding onoise /
 *   sqrt(2) sqrt(sum_j |x_j|^2 / h_j^2 + X_b).
 * Returns 10 times their sum (the factor of the eigenvalues' allowance,
 * doc/linear.md section 3), NaN without an error estimate. Cost: one
 * transposed solve, products with Aerr and the controller blocks,
 * O(nq^2 + nq nc). */
/* An output's weights on the state (w->c: the row of its Jacobian, or of
 * the node displacement map w->m for a position) and what its error
 * allowance needs of its Jacobian (none for a position, whose map is
 * exact). */
typedef struct out_row {
    const double *J, *Jerr; /* [rows x ...] Ty/Terr, Vy/Verr; NULL */
    int rows, row;
    double onoise;          /* the output's own rounding noise */
} out_row;

static void output_weights(const ts_linear *lin, const ts_output *out,
                           resp_ws *w, out_row *o)
{
    int n = lin->nstate, nq = lin->nq, nl = lin->nlinks;
    memset(o, 0, sizeof *o);
    if (out->kind == TS_OUT_TENSION) {
        o->J = lin->Ty;
        o->Jerr = lin->Terr;
        o->rows = nl;
        o->row = out->link;
        o->onoise = lin->onoise ? lin->onoise[o->row] : NAN;
    } else if (out->kind == TS_OUT_VEHICLE) {
        o->J = lin->Vy;
        o->Jerr = lin->Verr;
        o->rows = lin->noutput;
        o->row = out->index;
        o->onoise = lin->onoise ? lin->onoise[nl + o->row] : NAN;
    }
    for (int j = 0; j < n; j++)
        w->c[j] = o->J ? o->J[o->row + (size_t)j * o->rows]
                       : (j < nq ? w->m[j] : 0.0);
}

static double error_terms(const ts_linear *lin, int input, double complex s,
                          const out_row *o, resp_ws *w);

static double gain_error(tsi_shift *sh, const ts_linear *lin, int input,
                         const ts_output *out, resp_ws *w)
{
    if (!lin->Aerr || !lin->Berr || !lin->fnoise)
        return NAN;
    int n = lin->nstate, nq = lin->nq, nc = n - 2 * nq, nlow = n - nq;
    int one = 1, info = 0;
    double complex s = sh->s;
    const double *A = lin->A;
    /* The output's weights c on the state and its Jacobian's error. */
    out_row o;
    output_weights(lin, out, w, &o);
    if (o.J && (!o.Jerr || !(o.onoise >= 0)))
        return NAN;
    double complex *c = w->c, *W = w->W;
    if (sh->full) {
        /* H - sI singular: W from the whole (A - sI)^T. */
        memcpy(W, c, (size_t)n * sizeof(double complex));
        sh->la.zgetrs_("T", &n, &one, sh->full, &n, sh->fpiv, W, &n, &info, 1);
        memmove(W, W + nq, (size_t)nlow * sizeof(double complex));
    } else {
        double complex *w2 = W, *w3 = W + nq;
        for (int i = 0; i < nq; i++)
            w2[i] = c[i] + s * c[nq + i];
        if (nc > 0) {
            /* t = (H - sI)^-T c3; w2 -= (F + s G)^T t. */
            double complex *t = w->t3;
            memcpy(t, c + 2 * nq, (size_t)nc * sizeof(double complex));
            sh->la.zgetrs_("T", &nc, &one, sh->hlu, &nc, sh->hpiv, t, &nc,
                           &info, 1);
            for (int i = 0; i < nq; i++) {
                const double *Fi = A + (size_t)i * n + 2 * nq;
                const double *Gi = A + (size_t)(nq + i) * n + 2 * nq;
                double complex acc = 0;
                for (int k = 0; k < nc; k++)
                    acc += (Fi[k] + s * Gi[k]) * t[k];
                w2[i] -= acc;
            }
        }
        if (sh->is_complex) {
            sh->la.zgetrs_("T", &nq, &one, sh->zlu, &nq, sh->ipiv, w2, &nq,
                           &info, 1);
        } else {
            double *re = sh->wr, *im = sh->wr + nq;
            for (int i = 0; i < nq; i++) {
                re[i] = creal(w2[i]);
                im[i] = cimag(w2[i]);
            }
            sh->la.dgetrs_("T", &nq, &one, sh->lu, &nq, sh->ipiv, re, &nq,
                           &info, 1);
            sh->la.dgetrs_("T", &nq, &one, sh->lu, &nq, sh->ipiv, im, &nq,
                           &info, 1);
            for (int i = 0; i < nq; i++)
                w2[i] = re[i] + I * im[i];
        }
        if (nc > 0) {
            /* w3 = (H - sI)^-T (c3 - E^T w2), E = A[nq:2nq, 2nq:]. */
            for (int k = 0; k < nc; k++) {
                const double *Ek = A + (size_t)(2 * nq + k) * n + nq;
                double complex acc = 0;
                for (int i = 0; i < nq; i++)
                    acc += Ek[i] * w2[i];
                w3[k] = c[2 * nq + k] - acc;
            }
            sh->la.zgetrs_("T", &nc, &one, sh->hlu, &nc, sh->hpiv, w3, &nc,
                           &info, 1);
        }
    }
    return error_terms(lin, input, s, &o, w);
}

/* The parts of the error allowance (gain_error) from W (w->W, the lower
 * part of the transposed solution) and the state response w->x at s. */
static double error_terms(const ts_linear *lin, int input, double complex s,
                          const out_row *o, resp_ws *w)
{
    int n = lin->nstate, nlow = n - lin->nq;
    const double *J = o->J, *Jerr = o->Jerr;
    int rows = o->rows, row = o->row;
    double onoise = o->onoise;
    double complex *W = w->W;
    /* The input's columns of B and their factors. */
    int cols[3];
    double complex fac[3];
    int ncols = input_columns(lin, input, s, cols, fac);
    const double *hu = lin->h + n;
    double complex trunc = 0, otrunc = 0;
    double wn2 = 0, xh2 = 0;
    for (int j = 0; j < n; j++) {
        const double *ej = lin->Aerr + (size_t)j * nlow;
        double complex acc = 0;
        for (int i = 0; i < nlow; i++)
            acc += W[i] * ej[i];
        trunc += acc * w->x[j];
        if (J)
            otrunc += Jerr[row + (size_t)j * rows] * w->x[j];
        double a = cabs(w->x[j]) / lin->h[j];
        xh2 += a * a;
    }
    for (int q = 0; q < ncols; q++) {
        const double *be = lin->Berr + (size_t)cols[q] * nlow;
        for (int i = 0; i < nlow; i++)
            trunc += fac[q] * W[i] * be[i];
        if (J)
            otrunc += fac[q] * Jerr[row + (size_t)(n + cols[q]) * rows];
        double a = cabs(fac[q]) / hu[cols[q]];
        xh2 += a * a;
    }
    for (int i = 0; i < nlow; i++) {
        double a = cabs(W[i]) * lin->fnoise[i];
        wn2 += a * a;
    }
    double e = cabs(trunc) + sqrt(0.5 * wn2 * xh2);
    if (J)
        e += cabs(otrunc) + onoise * sqrt(0.5 * xh2);
    return 10.0 * e;
}

/* Row `row` of an output Jacobian pair (Jy [rows x n], Ju [rows x
 * ninput], column-major with leading dimension `rows`) applied to the
 * state response x and the input columns cols[ncols] with their factors
 * fac (input_columns): Jy x + sum_q fac_q Ju[:, cols_q]. */
static double complex row_gain(const double *Jy, const double *Ju, int row,
                               int rows, int n, const double complex *x,
                               int ncols, const int cols[3],
                               const double complex fac[3])
{
    double complex acc = 0;
    for (int j = 0; j < n; j++)
        acc += Jy[row + (size_t)j * rows] * x[j];
    for (int q = 0; q < ncols; q++)
        acc += fac[q] * Ju[row + (size_t)cols[q] * rows];
    return acc;
}

static double complex output_gain(const ts_system *sys, const ts_linear *lin,
                                  int input, const ts_output *out,
                                  resp_ws *w, int ncols, const int cols[3],
                                  const double complex fac[3]);

/* The dense way (see the head of the file); lin holds A, B, Ty, Tu and
 * the vehicles' output Jacobians Vy, Vu. A tow displacement input brings
 * its velocity and acceleration columns, a frame input (speed, turn
 * rate) its rate's; a vehicle's input is its column alone
 * (input_columns). With gerr, the gain's error allowance
 * (gain_error) into *gerr. */
static void dense_gain(const ts_system *sys, const ts_linear *lin, int input,
                       const ts_output *out, tsi_shift *sh, resp_ws *w,
                       double complex *g, double *gerr)
{
    int n = lin->nstate;
    int cols[3];
    double complex fac[3];
    int ncols = input_columns(lin, input, sh->s, cols, fac);
    for (int i = 0; i < n; i++)
        w->b[i] = 0.0;
    for (int q = 0; q < ncols; q++) {
        const double *Bq = lin->B + (size_t)cols[q] * n;
        for (int i = 0; i < n; i++)
            w->b[i] -= fac[q] * Bq[i];
    }
    tsi_shift_solve(sh, w->b, w->x); /* x = -(A - sI)^-1 b = (sI - A)^-1 B */
    if (gerr)
        *gerr = gain_error(sh, lin, input, out, w);
    *g = output_gain(sys, lin, input, out, w, ncols, cols, fac);
}

/* The output of the state response w->x and the input's columns cols
 * with their factors fac (input_columns): a position through the node
 * displacement map (plus the tow displacement itself), a tension or a
 * vehicle's output through its Jacobians. */
static double complex output_gain(const ts_system *sys, const ts_linear *lin,
                                  int input, const ts_output *out,
                                  resp_ws *w, int ncols, const int cols[3],
                                  const double complex fac[3])
{
    int n = lin->nstate, nq = lin->nq, nl = lin->nlinks;
    int tow = input < TS_NINPUT;
    double complex g;
    if (out->kind == TS_OUT_POSITION) {
        int idx = 3 * out->node + out->comp;
        for (int i = 0; i < nq; i++)
            w->dq[i] = creal(w->x[i]);
        ts_linear_node_displacements(sys, lin, w->dq, w->drr);
        double gr = w->drr[idx];
        for (int i = 0; i < nq; i++)
            w->dq[i] = cimag(w->x[i]);
        ts_linear_node_displacements(sys, lin, w->dq, w->drr);
        double gi = w->drr[idx];
        double shift[3];
        ts_linear_tow_shift(lin, out->node, tow ? input : -1, shift);
        g = gr + I * gi + shift[out->comp];
    } else if (out->kind == TS_OUT_TENSION) {
        g = row_gain(lin->Ty, lin->Tu, out->link, nl, n, w->x, ncols, cols,
                     fac);
    } else {
        g = row_gain(lin->Vy, lin->Vu, out->index, lin->noutput, n, w->x,
                     ncols, cols, fac);
    }
    return g;
}

/* An output sees a neutral mode g when |c^T g| > NEUTRAL_SEEN |c| |g| (c
 * its weights on the state): doc/linear.md section 4a. */
#define NEUTRAL_SEEN 1e-6
/* The bordered system below counts as singular under this reciprocal
 * condition number (another mode at 0 that no symmetry explains). */
#define BORDER_RCOND 1e-13

/* The static gain of a towing vehicle's scene, whose A is singular at 0
 * (its neutral modes by symmetry, doc/linear.md section 3a): the limit w
 * -> 0 of the gain, finite for an output whose weights c are orthogonal
 * to every neutral mode R of eigenvalue 0 (the generalised null space of
 * A: the poles' residues at 0 lie in its span, and (sI - J)^-1 of the
 * nilpotent block J there has no constant term). Then the limit is c^T z
 * with
 *
 *     [A   R] [z ]   [-b]
 *     [R^T 0] [mu] = [ 0],
 *
 * regular when R spans that null space (z is the part of the response
 * outside it, mu its drive). Its error allowance comes from the
 * transposed system's W as for any gain (gain_error: errors dA change g
 * by -W^T dA z). Returns TS_OK with *g, *gerr; otherwise note says why
 * the gain is undefined (the output drifts with the named mode, or the
 * system is singular beyond the symmetries) and the return is
 * TS_ESINGULAR. */
static int neutral_static(const ts_system *sys, const ts_linear *lin,
                          int input, const ts_output *out, resp_ws *w,
                          double *g, double *gerr, char *note, size_t size,
                          ts_err *err)
{
    tsi_lapack la;
    if (tsi_lapack_open(&la, err) != TS_OK)
        return TS_EIO;
    int n = lin->nstate, nq = lin->nq, nlow = n - nq;
    int idx[TS_NEUTRAL_MAX], k = 0;
    for (int j = 0; j < lin->nneutral && lin->neutral_re; j++)
        if (lin->neutral[j].re == 0 && lin->neutral[j].im == 0)
            idx[k++] = j;
    if (k == 0 || !lin->A)
        return TS_ESINGULAR;
    out_row o;
    output_weights(lin, out, w, &o);
    double cn = 0;
    for (int i = 0; i < n; i++)
        cn += creal(w->c[i]) * creal(w->c[i]);
    cn = sqrt(cn);
    size_t len = 0;
    for (int j = 0; j < k; j++) {
        const double *r = lin->neutral_re + (size_t)idx[j] * n;
        double dot = 0, rn = 0;
        for (int i = 0; i < n; i++) {
            dot += creal(w->c[i]) * r[i];
            rn += r[i] * r[i];
        }
        if (fabs(dot) > NEUTRAL_SEEN * cn * sqrt(rn))
            len += (size_t)snprintf(note + len, len < size ? size - len : 0,
                                    "%s%s", len ? ", " : "undefined: the "
                                    "output drifts with the towing "
                                    "vehicle's neutral modes by symmetry "
                                    "(", lin->neutral[idx[j]].name);
    }
    if (len) {
        if (len < size)
            snprintf(note + len, size - len, "): a steady input moves it "
                     "without bound");
        return TS_ESINGULAR;
    }
    int N = n + k, one = 1, info = 0;
    double *M = calloc((size_t)N * N + 2 * (size_t)N + 4 * (size_t)N,
                       sizeof(double));
    int *piv = malloc((size_t)N * 2 * sizeof(int));
    if (!M || !piv) {
        free(M);
        free(piv);
        return TS_ENOMEM;
    }
    double *z = M + (size_t)N * N, *Wt = z + N, *work = Wt + N;
    for (int j = 0; j < n; j++)
        memcpy(M + (size_t)j * N, lin->A + (size_t)j * n,
               (size_t)n * sizeof(double));
    for (int j = 0; j < k; j++) {
        const double *r = lin->neutral_re + (size_t)idx[j] * n;
        for (int i = 0; i < n; i++) {
            M[i + (size_t)(n + j) * N] = r[i];
            M[n + j + (size_t)i * N] = r[i];
        }
    }
    int cols[3];
    double complex fac[3];
    int ncols = input_columns(lin, input, 0.0, cols, fac);
    for (int q = 0; q < ncols; q++) {
        const double *Bq = lin->B + (size_t)cols[q] * n;
        for (int i = 0; i < n; i++)
            z[i] -= creal(fac[q]) * Bq[i];
    }
    double anorm = la.dlange_("1", &N, &N, M, &N, work, 1), rcond = 0;
    la.dgetrf_(&N, &N, M, &N, piv, &info);
    if (info == 0)
        la.dgecon_("1", &N, M, &N, &anorm, &rcond, work, piv + N, &info, 1);
    if (info != 0 || !(rcond > BORDER_RCOND)) {
        snprintf(note, size, "undefined: the model is singular at 0 Hz "
                 "beyond the towing vehicle's neutral modes by symmetry "
                 "(reciprocal condition %.2g)", rcond);
        free(M);
        free(piv);
        return TS_ESINGULAR;
    }
    la.dgetrs_("N", &N, &one, M, &N, piv, z, &N, &info, 1);
    for (int i = 0; i < n; i++)
        w->x[i] = z[i];
    *g = creal(output_gain(sys, lin, input, out, w, ncols, cols, fac));
    *gerr = NAN;
    if (lin->Aerr && lin->Berr && lin->fnoise &&
        !(o.J && (!o.Jerr || !(o.onoise >= 0)))) {
        for (int i = 0; i < N; i++)
            Wt[i] = i < n ? creal(w->c[i]) : 0.0;
        la.dgetrs_("T", &N, &one, M, &N, piv, Wt, &N, &info, 1);
        for (int i = 0; i < nlow; i++)
            w->W[i] = Wt[nq + i];
        *gerr = error_terms(lin, input, 0.0, &o, w);
    }
    free(M);
    free(piv);
    return TS_OK;
}

/* The vehicle of output j (its index; *row its row in the vehicle's
 * output block), -1. */
static int output_vehicle(const ts_descriptor *d, int j, int *row)
{
    for (int v = 0; v < d->nv; v++)
        if (j >= d->vl[v].out0 && j < d->vl[v].out0 + d->vl[v].nout) {
            *row = j - d->vl[v].out0;
            return v;
        }
    return -1;
}

/* A vehicle output's local vector z (TSI_LV_*: its node's displacement,
 * its angles, their rates s x, its controller states, its inputs) of the
 * solution x[3 np + nc] to the input `input` at s; with h, the steps of
 * those columns. Returns the number of columns. */
static int local_vector(const ts_descriptor *d, int v, int input,
                        double complex s, const double complex *x,
                        double complex *z, double *h)
{
    const tsi_vehicle_layout *L = &d->vl[v];
    for (int lc = 0; lc < 6; lc++) {
        int i = lc < 3 ? 3 * L->node + lc : 3 * (d->nn + v) + lc - 3;
        z[lc] = x[i];
        z[TSI_LV_V + lc] = s * x[i];
        if (h) {
            h[lc] = d->hr[i];
            h[TSI_LV_V + lc] = d->hv[i];
        }
    }
    for (int m = 0; m < L->nc; m++) {
        z[TSI_LV_C + m] = x[3 * (size_t)d->np + L->c0 + m];
        if (h)
            h[TSI_LV_C + m] = d->hc[L->c0 + m];
    }
    for (int m = 0; m < L->nin; m++) {
        z[TSI_LV_C + L->nc + m] = L->in0 + m == input ? 1.0 : 0.0;
        if (h)
            h[TSI_LV_C + L->nc + m] = d->hu[L->in0 + m];
    }
    return TSI_LV_C + L->nc + L->nin;
}

/* The gain of output out in the sparse solution (dr, dt) to `input`. */
static double complex sparse_gain(const ts_descriptor *d, int input,
                                  const ts_output *out, double complex s,
                                  resp_ws *w)
{
    if (out->kind == TS_OUT_POSITION)
        return w->dr[3 * out->node + out->comp];
    if (out->kind == TS_OUT_TENSION)
        return w->dt[out->link];
    int row = 0, v = output_vehicle(d, out->index, &row);
    int ncol = local_vector(d, v, input, s, w->dr, w->z, NULL);
    const double *Ov = d->Ov + d->ov_off[v] + row * ncol;
    double complex g = 0;
    for (int lc = 0; lc < ncol; lc++)
        g += Ov[lc] * w->z[lc];
    return g;
}

/* The truncation (into *tb) and rounding (into *rb2, squared) of
 * whole-row input columns in a gain: n columns with estimates Ge[q],
 * factors fac[q] at s (1, s, s^2) and steps h[q] (a towing vehicle's
 * tow input and its rates, Gt; a frame input and its rate, Gf), weighed
 * by the transposed solution w->wt over every row but the tow point's. */
static void row_column_terms(const ts_descriptor *d, const resp_ws *w,
                             int n, const double *const Ge[],
                             const double complex fac[], const double h[],
                             double complex *tb, double *rb2)
{
    size_t n3 = 3 * (size_t)d->np, nrow = n3 + (size_t)d->nc;
    double sh = 0.0;
    for (int q = 0; q < n; q++)
        sh += cabs(fac[q]) / h[q];
    for (size_t i = 3 * (size_t)d->p0; i < nrow; i++) {
        int x = i < n3 ? tsi_desc_xr(d, (int)(i / 3), (int)(i % 3))
                       : tsi_desc_xc(d, (int)(i - n3));
        double complex ge = 0;
        for (int q = 0; q < n; q++)
            ge += fac[q] * Ge[q][i];
        *tb += w->wt[x] * (i < n3 ? -ge : ge);
        double a = cabs(w->wt[x]) * d->rnoise[i] * sh;
        *rb2 += 0.5 * a * a;
    }
}

/* The sparse way's error allowance of the gain g = c^T x (+ a vehicle
 * output's input term), S(s) x = b (x the point displacements, link
 * tensions and controller states, c the output's row: a unit vector for
 * a position or a tension, a vehicle output's Ov on its local columns at
 * s): errors dS of the model and db of a vehicle input's column change it
 * by dg = w^T (db - dS x_full) with S(s)^T w = c (one transposed solve
 * with the same factors) and x_full the point displacements with the tow
 * point's (the input columns of K and C are the right-hand side's).
 * tsi_desc_error_terms gives dS's truncation and rounding parts
 * (doc/linear.md, section 4), db's are its local block's (Lerr, and
 * rnoise_i / (sqrt(2) hu) per row); a vehicle output adds its own row's
 * truncation |Oerr z| and rounding onoise sqrt(sum |z_j|^2 / h_j^2) /
 * sqrt 2. The allowance is 10 times their sum, as the dense way's. NaN
 * without the estimate. Cost: one transposed solve, O(nlinks). */
/* W = S(s)^-T c into w->wt, c the output's row in the sparse unknowns at
 * s (a unit vector for a position or a tension, a vehicle output's Ov
 * on its local columns) with sh's factors; *v the output's vehicle (-1),
 * *row and *ncol its row and columns there. One transposed solve. */
static void output_transposed(tsi_shift *sh, const ts_output *out,
                              resp_ws *w, int *v, int *row, int *ncol)
{
    const ts_descriptor *d = sh->d;
    double complex s = sh->s;
    memset(w->wt, 0, (size_t)d->nx * sizeof(double complex));
    *v = -1;
    *row = *ncol = 0;
    if (out->kind == TS_OUT_POSITION) {
        w->wt[tsi_desc_xr(d, out->node, out->comp)] = 1.0;
    } else if (out->kind == TS_OUT_TENSION) {
        w->wt[TSI_XT(out->link)] = 1.0;
    } else {
        *v = output_vehicle(d, out->index, row);
        const tsi_vehicle_layout *L = &d->vl[*v];
        *ncol = TSI_LV_C + L->nc + L->nin;
        const double *Ov = d->Ov + d->ov_off[*v] + *row * *ncol;
        for (int a = 0; a < 3; a++) {
            w->wt[tsi_desc_xr(d, L->node, a)] = Ov[a] + s * Ov[TSI_LV_V + a];
            w->wt[tsi_desc_xr(d, d->nn + *v, a)] =
                Ov[TSI_LV_TH + a] + s * Ov[TSI_LV_W + a];
        }
        for (int m = 0; m < L->nc; m++)
            w->wt[tsi_desc_xc(d, L->c0 + m)] = Ov[TSI_LV_C + m];
    }
    tsi_shift_tsolve(sh, w->wt);
}

static double sparse_gain_error(tsi_shift *sh, int input,
                                const ts_output *out, resp_ws *w)
{
    const ts_descriptor *d = sh->d;
    double complex s = sh->s;
    if (!d->Oerr || !d->onoise)
        return NAN;
    int row, v, ncol;
    output_transposed(sh, out, w, &v, &row, &ncol);
    double tr, ro;
    tsi_desc_error_terms(d, w->wt, w->dr, s, &tr, &ro);
    double complex tb = 0;
    double rb2 = 0;
    for (int u = 0; input >= TS_NINPUT && u < d->nv; u++) {
        const tsi_vehicle_layout *L = &d->vl[u];
        if (input < L->in0 || input >= L->in0 + L->nin)
            continue;
        int nc = TSI_LV_C + L->nc + L->nin, uc = TSI_LV_C + L->nc +
                                                 input - L->in0;
        double hu = d->hu[input];
        for (int lr = 0; lr < 6 + L->nc; lr++) {
            int x = lr < 3 ? tsi_desc_xr(d, L->node, lr)
                    : lr < 6 ? tsi_desc_xr(d, d->nn + u, lr - 3)
                             : tsi_desc_xc(d, L->c0 + lr - 6);
            size_t ri = lr < 3 ? 3 * (size_t)L->node + lr
                        : lr < 6 ? 3 * (size_t)(d->nn + u) + lr - 3
                                 : 3 * (size_t)d->np + L->c0 + lr - 6;
            double e = d->Lerr[d->lv_off[u] + lr * nc + uc];
            tb += w->wt[x] * (lr < 6 ? -e : e);
            double a = cabs(w->wt[x]) * d->rnoise[ri] / hu;
            rb2 += 0.5 * a * a;
        }
    }
    if (input < TS_NINPUT && d->root >= 0 && d->Gterr) {
        /* A towing vehicle's tow input: its own columns' (Gt) truncation
         * and rounding, at velocity s and acceleration s^2 per metre. */
        size_t nrow = 3 * (size_t)d->np + (size_t)d->nc;
        const double *Ge[3] = {
            d->Gterr + (size_t)(TS_IN_DISP + input) * nrow,
            d->Gterr + (size_t)(TS_IN_VEL + input) * nrow,
            d->Gterr + (size_t)(TS_IN_ACC + input) * nrow};
        const double complex fac[3] = {1.0, s, s * s};
        const double hs[3] = {d->hu[TS_IN_DISP + input],
                              d->hu[TS_IN_VEL + input],
                              d->hu[TS_IN_ACC + input]};
        row_column_terms(d, w, 3, Ge, fac, hs, &tb, &rb2);
    }
    if (d->frame && d->Gferr && input >= sh->lin->frame_input) {
        /* A frame input: its column's and its rate's (Gf) truncation and
         * rounding, the rate's at s per unit. */
        size_t nrow = 3 * (size_t)d->np + (size_t)d->nc;
        int c = input - sh->lin->frame_input;
        const double *Ge[2] = {d->Gferr + (size_t)c * nrow,
                               d->Gferr + (size_t)(c + 2) * nrow};
        const double complex fac[2] = {1.0, s};
        const double hs[2] = {d->hf[c], d->hf[c + 2]};
        row_column_terms(d, w, 2, Ge, fac, hs, &tb, &rb2);
    }
    double e = tr + cabs(tb) + sqrt(ro * ro + rb2);
    if (v >= 0) {
        local_vector(d, v, input, s, w->dr, w->z, w->zh);
        const double *Oe = d->Oerr + d->ov_off[v] + row * ncol;
        double complex ot = 0;
        double zh2 = 0;
        for (int lc = 0; lc < ncol; lc++) {
            ot += Oe[lc] * w->z[lc];
            double a = cabs(w->z[lc]) / w->zh[lc];
            zh2 += a * a;
        }
        e += cabs(ot) + d->onoise[out->index] * sqrt(0.5 * zh2);
    }
    return 10.0 * e;
}

/* The gain at omega; sh holds the factors of the previous frequency
 * (zeroed before the first), which are refactored (tsi_shift_refactor);
 * the caller frees them. With gerr, the gain's linearization error
 * allowance into *gerr. */
static int gain_at(const ts_system *sys, const ts_linear *lin, int input,
                   const ts_output *out, double omega, resp_ws *w,
                   tsi_shift *sh, double complex *g, double *gerr,
                   ts_err *err)
{
    int rc = tsi_shift_refactor(sh, lin, I * omega, err);
    if (rc != TS_OK) {
        if (rc == TS_ESINGULAR)
            ts_fail(err, TS_ESINGULAR,
                    "response: i w is an eigenvalue of A at %g Hz (an "
                    "undamped resonance): the response is infinite there",
                    omega / (2 * M_PI));
        return rc;
    }
    if (lin->desc) {
        tsi_shift_input(sh, input, w->dr, w->dt);
        *g = sparse_gain(lin->desc, input, out, sh->s, w);
        if (gerr)
            *gerr = sparse_gain_error(sh, input, out, w);
    } else {
        dense_gain(sys, lin, input, out, sh, w, g, gerr);
    }
    return TS_OK;
}

/* The sparse model's static gain of a towing vehicle's scene (below). */
#define SPARSE_STATIC_W0 1e-3   /* rad/s: the first frequency, at most */
#define SPARSE_STATIC_LEVELS 8  /* frequencies, each half the last */
/* The output sees a neutral mode when its transposed solution grows
 * more than this from the first frequency to the last (2^7 apart: a
 * 1 / w growth gives 128, a bounded one about 1). */
#define SPARSE_STATIC_SEEN 8.0
/* The extrapolation has settled when its move is below this fraction of
 * the gain, or within the allowance. */
#define SPARSE_STATIC_RTOL 1e-6

/* The static gain of a towing vehicle's scene with the sparse model
 * alone (doc/linear.md section 4a, "With the sparse model alone"): the
 * limit w -> 0 of g(i w) from the sparse gains at w_k = w_0 2^-k, k = 0
 * .. SPARSE_STATIC_LEVELS - 1, w_0 = SPARSE_STATIC_W0 or an eighth of a
 * neutral mode's frequency (a turn's centre, i |Omega|) if lower.
 *
 * Whether the output sees a neutral mode of eigenvalue 0 (as the dense
 * way's c^T g): near s = 0 the transposed solution W = S(s)^-T c of the
 * output's row c is h (g^T c) / s plus a regular part (h, g the mode's
 * left and right vectors in the sparse unknowns; with the heading's
 * Jordan chain, 1 / s^2), so |W| grows like 1 / w exactly when c sees a
 * mode; then the gain is undefined, as the dense way says. Otherwise the
 * limit exists, Re g(i w) is even in w and analytic about 0 (the model
 * is real: g(conj s) = conj g(s)), and Richardson extrapolation in w^2
 * (Romberg's table) removes its w^2, w^4, ... terms. Of the table's
 * diagonal entries T_kk the one with the least error estimate is taken:
 * its move from T_(k-1)(k-1) plus 1.5 times the largest gain allowance
 * up to w_k (the sum of the table's weights is below 1.5). The
 * allowances grow like 1 / w (each multiplies the model's error
 * estimate by the solution, whose neutral part grows so: the estimate
 * does not know that the true model keeps the symmetry), so the entry
 * taken is an early one, where the table has already settled. Returns
 * TS_OK with *g, *gerr (NaN without the allowances); else note says why
 * the gain is undefined and the return is TS_ESINGULAR; or a solve's
 * failure. Cost: SPARSE_STATIC_LEVELS sparse complex factorisations and
 * solves and 2 transposed solves, O(nlinks). */
static int sparse_static(const ts_system *sys, const ts_linear *lin,
                         int input, const ts_output *out, resp_ws *w,
                         double *g, double *gerr, char *note, size_t size,
                         ts_err *err)
{
    enum { K = SPARSE_STATIC_LEVELS };
    double w0 = SPARSE_STATIC_W0;
    for (int k = 0; k < lin->nneutral; k++)
        if (lin->neutral[k].im > 0)
            w0 = fmin(w0, 0.125 * lin->neutral[k].im);
    double T[K][K], wn[2] = {0, 0}, emax = 0.0;
    double best = NAN, best_err = INFINITY, best_move = INFINITY;
    tsi_shift sh = {0};
    int rc = TS_OK;
    for (int k = 0; k < K && rc == TS_OK; k++) {
        double complex gk;
        double ek = NAN;
        rc = gain_at(sys, lin, input, out, ldexp(w0, -k), w, &sh, &gk, &ek,
                     err);
        if (rc != TS_OK)
            break;
        if (k == 0 || k == K - 1) {
            int v, row, ncol;
            output_transposed(&sh, out, w, &v, &row, &ncol);
            for (int i = 0; i < lin->desc->nx; i++)
                wn[k > 0] = fmax(wn[k > 0], cabs(w->wt[i]));
        }
        T[k][0] = creal(gk);
        emax = ek >= 0 ? fmax(emax, ek) : NAN;
        for (int j = 1; j <= k; j++)
            T[k][j] = T[k][j - 1] + (T[k][j - 1] - T[k - 1][j - 1]) /
                                        (ldexp(1.0, 2 * j) - 1);
        if (k == 0)
            continue;
        double move = fabs(T[k][k] - T[k - 1][k - 1]);
        double ke = move + (isnan(emax) ? 0.0 : 1.5 * emax);
        if (ke < best_err) {
            best_err = ke;
            best_move = move;
            best = T[k][k];
        }
    }
    tsi_shift_free(&sh);
    if (rc != TS_OK)
        return rc;
    size_t len = 0;
    if (!(wn[1] <= SPARSE_STATIC_SEEN * wn[0]))
        len = (size_t)snprintf(
            note, size, "undefined: the output drifts with the towing "
            "vehicle's neutral modes by symmetry (its transposed solution "
            "grows %.3g times from %.3g to %.3g Hz, as 1 / w)",
            wn[1] / wn[0], w0 / (2 * M_PI), ldexp(w0, 1 - K) / (2 * M_PI));
    else if (!(best_move <= SPARSE_STATIC_RTOL * fabs(best) ||
               best_move <= best_err - best_move))
        len = (size_t)snprintf(
            note, size, "undefined: the gain does not settle as w -> 0 "
            "(its extrapolation moved by %.3g at best, %.3g of it)",
            best_move, best_move / fabs(best));
    if (len) {
        int n = 0;
        for (int j = 0; j < lin->nneutral && len < size; j++)
            if (lin->neutral[j].re == 0 && lin->neutral[j].im == 0)
                len += (size_t)snprintf(note + len, size - len, "%s%s",
                                        n++ ? ", " : "; the neutral modes "
                                                     "at 0 Hz: ",
                                        lin->neutral[j].name);
        return TS_ESINGULAR;
    }
    *g = best;
    *gerr = isnan(emax) ? NAN : best_err;
    return TS_OK;
}

static int check_args(const ts_system *sys, const ts_linear *lin, int input,
                      const ts_output *out, ts_err *err)
{
    if (sys->nlinks != lin->nlinks)
        return ts_fail(err, TS_EINVAL,
                       "response: the linear model has %d links, the system "
                       "%d",
                       lin->nlinks, sys->nlinks);
    if (!((input >= TS_IN_DISP && input < TS_IN_DISP + 3) ||
          (input >= TS_IN_ROT && input < TS_IN_ROT + 3) ||
          (input >= TS_NINPUT && input < lin->frame_input + 2)))
        return ts_fail(err, TS_EINVAL,
                       "response: input channel must be 0, 1 or 2 "
                       "(tow.surge, tow.sway, tow.heave), %d, %d or %d "
                       "(tow.roll, tow.pitch, tow.yaw), a vehicle's "
                       "input or tow.speed or tow.turn_rate, %d to %d, "
                       "got %d",
                       TS_IN_ROT, TS_IN_ROT + 1, TS_IN_ROT + 2,
                       TS_NINPUT, lin->frame_input + 1, input);
    if (lin->desc && !lin->desc->frame && input >= lin->frame_input)
        return ts_fail(err, TS_EINVAL, "response: %s needs %s",
                       lin->input_name[input],
                       lin->desc->root >= 0
                           ? "the dense model with a towing vehicle "
                             "(linearize with TS_LIN_DENSE)"
                           : "the sparse model's frame columns "
                             "(linearize with frame_inputs 1) or the "
                             "dense model (TS_LIN_DENSE)");
    if (!lin->desc && !lin->A)
        return ts_fail(err, TS_EINVAL,
                       "response: output %s needs a linear model (sparse, "
                       "or dense)",
                       out->name);
    if (!lin->desc && out->kind == TS_OUT_TENSION && (!lin->Ty || !lin->Tu))
        return ts_fail(err, TS_EINVAL,
                       "response: output %s needs the tension Jacobians "
                       "of the dense model; linearize with opts.tensions = "
                       "1",
                       out->name);
    if (out->kind == TS_OUT_POSITION &&
        (out->node < 1 || out->node >= lin->nnodes || out->comp < 0 ||
         out->comp > 2))
        return ts_fail(err, TS_EINVAL, "response: output node %d comp %d "
                                       "out of range",
                       out->node, out->comp);
    if (out->kind == TS_OUT_TENSION &&
        (out->link < 0 || out->link >= lin->nlinks))
        return ts_fail(err, TS_EINVAL, "response: output link %d out of "
                                       "range",
                       out->link);
    if (out->kind == TS_OUT_VEHICLE &&
        (out->index < 0 || out->index >= lin->noutput))
        return ts_fail(err, TS_EINVAL, "response: vehicle output %d out of "
                                       "range",
                       out->index);
    return TS_OK;
}

/* Work for lin; with sys (the dense way), the output row m of a position
 * output, for the error allowance. */
static int ws_alloc(resp_ws *w, const ts_linear *lin, const ts_system *sys,
                    const ts_output *out)
{
    memset(w, 0, sizeof *w);
    size_t ndr = lin->desc ? 3 * (size_t)lin->desc->np + (size_t)lin->desc->nc
                           : 3 * (size_t)lin->nnodes;
    w->dr = malloc(ndr * sizeof(double complex));
    w->dt = malloc((size_t)(lin->nlinks > 0 ? lin->nlinks : 1) *
                   sizeof(double complex));
    if (lin->desc) {
        w->wt = malloc(((size_t)lin->desc->nx + 1) * sizeof(double complex));
        size_t nz = TSI_LV_C + (size_t)lin->desc->nc + (size_t)lin->ninput;
        w->z = malloc(nz * sizeof(double complex));
        w->zh = malloc(nz * sizeof(double));
        if (!w->wt || !w->z || !w->zh)
            return 0;
    }
    if (!lin->desc || lin->A) {
        /* The dense way's work; with both models, for a towing vehicle's
         * static gain (neutral_static). */
        w->b = malloc((size_t)lin->nstate * sizeof(double complex));
        w->x = malloc((size_t)lin->nstate * sizeof(double complex));
        w->c = malloc((size_t)lin->nstate * sizeof(double complex));
        w->W = malloc((size_t)lin->nstate * sizeof(double complex));
        w->t3 = malloc((size_t)(lin->nstate - 2 * lin->nq + 1) *
                       sizeof(double complex));
        w->dq = malloc((size_t)lin->nq * sizeof(double));
        w->drr = malloc(3 * (size_t)lin->nnodes * sizeof(double));
        w->m = calloc((size_t)lin->nq, sizeof(double));
        if (!w->b || !w->x || !w->c || !w->W || !w->t3 || !w->dq ||
            !w->drr || !w->m)
            return 0;
        if (sys && out->kind == TS_OUT_POSITION) {
            /* O(nq nlinks) once: the map applied to each unit vector. */
            int idx = 3 * out->node + out->comp;
            memset(w->dq, 0, (size_t)lin->nq * sizeof(double));
            for (int i = 0; i < lin->nq; i++) {
                w->dq[i] = 1.0;
                ts_linear_node_displacements(sys, lin, w->dq, w->drr);
                w->m[i] = w->drr[idx];
                w->dq[i] = 0.0;
            }
        }
    }
    return w->dr && w->dt;
}

static void ws_free(resp_ws *w)
{
    free(w->dr);
    free(w->dt);
    free(w->b);
    free(w->x);
    free(w->dq);
    free(w->drr);
    free(w->c);
    free(w->W);
    free(w->t3);
    free(w->m);
    free(w->wt);
    free(w->z);
    free(w->zh);
}

struct tsi_gain {
    const ts_system *sys;
    const ts_linear *lin;
    int input;
    ts_output out;
    resp_ws w;
    tsi_shift sh;
};

tsi_gain *tsi_gain_alloc(const ts_system *sys, const ts_linear *lin,
                         int input, const ts_output *out, ts_err *err)
{
    if (check_args(sys, lin, input, out, err) != TS_OK)
        return NULL;
    tsi_gain *g = calloc(1, sizeof *g);
    if (!g) {
        ts_fail(err, TS_ENOMEM, "response: out of memory");
        return NULL;
    }
    g->sys = sys;
    g->lin = lin;
    g->input = input;
    g->out = *out;
    if (!ws_alloc(&g->w, lin, NULL, &g->out)) {
        tsi_gain_free(g);
        ts_fail(err, TS_ENOMEM, "response: out of memory");
        return NULL;
    }
    return g;
}

int tsi_gain_at(tsi_gain *g, double omega, double complex *val, ts_err *err)
{
    *val = 0;
    if (!(omega >= 0) || !isfinite(omega))
        return ts_fail(err, TS_EINVAL,
                       "response: angular frequency must be >= 0 rad/s, got "
                       "%g",
                       omega);
    return gain_at(g->sys, g->lin, g->input, &g->out, omega, &g->w, &g->sh,
                   val, NULL, err);
}

void tsi_gain_free(tsi_gain *g)
{
    if (!g)
        return;
    tsi_shift_free(&g->sh);
    ws_free(&g->w);
    free(g);
}

int ts_response_at(const ts_system *sys, const ts_linear *lin, int input,
                   const ts_output *out, double omega, double *re, double *im,
                   ts_err *err)
{
    tsi_gain *g = tsi_gain_alloc(sys, lin, input, out, err);
    if (!g)
        return err && err->code ? err->code : TS_EINVAL;
    double complex v = 0;
    int rc = tsi_gain_at(g, omega, &v, err);
    tsi_gain_free(g);
    *re = creal(v);
    *im = cimag(v);
    return rc;
}

static void set_point(ts_response *r, int i, double f, double complex g)
{
    r->freq_hz[i] = f;
    r->re[i] = creal(g);
    r->im[i] = cimag(g);
    r->magnitude[i] = cabs(g);
    r->phase_deg[i] = carg(g) * 180.0 / M_PI;
}

/* The sweep in chunks from this many links on (the sparse model): each
 * chunk of consecutive frequencies factors afresh at its first and
 * refactors from there (tsi_shift_refactor), so the chunks are
 * independent and run on the linearization's threads (ts_linear.threads).
 * Their number is fixed by the sweep alone, never by the threads, so the
 * results are the same on any number of threads. Below, one chunk: every
 * frequency refactors the previous one's factors. */
#define RESP_CHUNK_LINKS 200
#define RESP_CHUNKS 4          /* chunks of a long sweep */
#define RESP_CHUNK_MIN 4       /* frequencies a chunk holds at least */

static int resp_chunks(const ts_linear *lin, int npoints)
{
    if (!lin->desc || lin->nlinks < RESP_CHUNK_LINKS)
        return 1;
    int c = npoints / RESP_CHUNK_MIN;
    return c < 1 ? 1 : (c > RESP_CHUNKS ? RESP_CHUNKS : c);
}

/* The frequencies of r in `chunks` chunks (resp_chunks), each with its
 * own factors and work, on up to lin->threads threads. A chunk that fails
 * stops at its failure; the others run on, so the error reported is that
 * of the lowest frequency that failed, whatever the threads. A stop asked
 * for through progress (called by one thread at a time, whichever
 * finished a frequency, with the count of frequencies done) ends every
 * chunk at its next frequency. */
static int sweep_chunks(const ts_system *sys, const ts_linear *lin,
                        int input, const ts_output *out,
                        const double freq_hz[], int npoints, int chunks,
                        ts_progress_fn progress, void *data, ts_response *r,
                        ts_err *err)
{
    int *crc = calloc((size_t)chunks, sizeof *crc);
    int *cat = calloc((size_t)chunks, sizeof *cat);
    ts_err *cerr = calloc((size_t)chunks, sizeof *cerr);
    if (!crc || !cat || !cerr) {
        free(crc);
        free(cat);
        free(cerr);
        return ts_fail(err, TS_ENOMEM, "response: out of memory");
    }
    int nthreads = lin->threads > 1 ? lin->threads : 1;
    if (nthreads > chunks)
        nthreads = chunks;
    int done = 0, stop = 0;
#ifdef _OPENMP
#pragma omp parallel for num_threads(nthreads) schedule(dynamic, 1)
#endif
    for (int c = 0; c < chunks; c++) {
        int i0 = (int)((long)npoints * c / chunks);
        int i1 = (int)((long)npoints * (c + 1) / chunks);
        resp_ws w;
        tsi_shift sh = {0};
        cat[c] = npoints;
        if (!ws_alloc(&w, lin, NULL, out)) {
            crc[c] = ts_fail(&cerr[c], TS_ENOMEM, "response: out of memory");
            cat[c] = i0;
            i1 = i0;
        }
        for (int i = i0; i < i1; i++) {
            int halt;
#ifdef _OPENMP
#pragma omp atomic read
#endif
            halt = stop;
            if (halt)
                break;
            double complex g = 0;
            int rc = gain_at(sys, lin, input, out, 2 * M_PI * freq_hz[i], &w,
                             &sh, &g, &r->error[i], &cerr[c]);
            set_point(r, i, freq_hz[i], g);
            if (rc != TS_OK) {
                crc[c] = rc;
                cat[c] = i;
                break;
            }
            if (!progress)
                continue;
            /* Whichever thread did it reports (one at a time): with a
             * dynamic schedule the first thread may get no chunk. */
#ifdef _OPENMP
#pragma omp critical(ts_response_progress)
#endif
            {
                ts_progress p = {"response", ++done, npoints, "frequencies"};
                if (progress(&p, data)) {
#ifdef _OPENMP
#pragma omp atomic write
#endif
                    stop = done;
                }
            }
        }
        tsi_shift_free(&sh);
        ws_free(&w);
    }
    int rc = TS_OK, at = npoints;
    for (int c = 0; c < chunks; c++)
        if (crc[c] != TS_OK && cat[c] < at) {
            rc = crc[c];
            at = cat[c];
            if (err)
                *err = cerr[c];
        }
    if (rc == TS_OK && stop)
        rc = ts_fail(err, TS_ECANCEL, "response: stopped on request after "
                     "%d of %d frequencies", stop, npoints);
    free(crc);
    free(cat);
    free(cerr);
    return rc;
}

int ts_response_compute(const ts_system *sys, const ts_linear *lin,
                        int input, const ts_output *out,
                        const double freq_hz[], int npoints,
                        ts_response **res, ts_err *err)
{
    return tsi_response_compute(sys, lin, input, out, freq_hz, npoints, NULL,
                                NULL, res, err);
}

int tsi_response_compute(const ts_system *sys, const ts_linear *lin,
                         int input, const ts_output *out,
                         const double freq_hz[], int npoints,
                         ts_progress_fn progress, void *data,
                         ts_response **res, ts_err *err)
{
    *res = NULL;
    int rc = check_args(sys, lin, input, out, err);
    if (rc != TS_OK)
        return rc;
    if (npoints < 1)
        return ts_fail(err, TS_EINVAL, "response: no frequencies");
    for (int i = 0; i < npoints; i++)
        if (!(freq_hz[i] >= 0) || !isfinite(freq_hz[i]))
            return ts_fail(err, TS_EINVAL,
                           "response: frequency %d must be >= 0 Hz, got %g",
                           i, freq_hz[i]);
    ts_response *r = calloc(1, sizeof *r);
    resp_ws w;
    int ok = r && ws_alloc(&w, lin, sys, out);
    if (r) {
        size_t np = (size_t)npoints;
        r->freq_hz = malloc(np * sizeof(double));
        r->re = malloc(np * sizeof(double));
        r->im = malloc(np * sizeof(double));
        r->magnitude = malloc(np * sizeof(double));
        r->phase_deg = malloc(np * sizeof(double));
        r->error = malloc(np * sizeof(double));
        ok = ok && r->freq_hz && r->re && r->im && r->magnitude &&
             r->phase_deg && r->error;
    }
    if (!ok) {
        if (r)
            ws_free(&w);
        ts_response_free(r);
        return ts_fail(err, TS_ENOMEM, "response: out of memory");
    }
    r->input = input;
    r->output = *out;
    r->npoints = npoints;
    snprintf(r->input_name, sizeof r->input_name, "%s",
             lin->input_name[input]);
    const char *ou = out->kind == TS_OUT_POSITION  ? "m"
                     : out->kind == TS_OUT_TENSION ? "N"
                                                   : out->unit;
    const char *iu = lin->input_unit[input];
    snprintf(r->unit, sizeof r->unit, strchr(iu, '/') ? "%s/(%s)" : "%s/%s",
             ou, iu);
    double complex g = 0;
    tsi_shift sh = {0};
    int neutral0 = 0;
    for (int k = 0; k < lin->nneutral; k++)
        neutral0 |= lin->neutral[k].re == 0 && lin->neutral[k].im == 0;
    if (lin->desc && lin->root_qoff >= 0 && !lin->A) {
        /* A towing vehicle with the sparse model alone: S(0) is singular
         * on its neutral modes, and the bordered solve that sets them
         * apart (neutral_static) is written on the dense A: the limit
         * w -> 0 by extrapolation instead. */
        rc = sparse_static(sys, lin, input, out, &w, &r->static_gain,
                           &r->static_error, r->static_note,
                           sizeof r->static_note, err);
    } else if (neutral0) {
        /* A towing vehicle's neutral modes at 0 (its position along and
         * across its track, its heading: doc/linear.md section 3a) make
         * A singular, exactly or to its rounding (in a turn the heading's
         * column is not exactly dependent): the limit w -> 0 for an
         * output they do not move, else no static gain; the frequencies
         * above 0 are regular. */
        rc = neutral_static(sys, lin, input, out, &w, &r->static_gain,
                            &r->static_error, r->static_note,
                            sizeof r->static_note, err);
    } else {
        rc = gain_at(sys, lin, input, out, 0.0, &w, &sh, &g,
                     &r->static_error, err);
        r->static_gain = creal(g);
    }
    if (rc == TS_ENOMEM) {
        rc = ts_fail(err, rc, "response: out of memory");
    } else if (rc == TS_ESINGULAR && lin->root_qoff >= 0) {
        ts_err_clear(err);
        tsi_shift_free(&sh);
        memset(&sh, 0, sizeof sh);
        rc = TS_OK;
        r->static_gain = r->static_error = NAN;
        if (!r->static_note[0]) {
            char names[128] = "";
            for (int k = 0; k < lin->nneutral; k++) {
                size_t len = strlen(names);
                if (lin->neutral[k].re == 0 && lin->neutral[k].im == 0)
                    snprintf(names + len, sizeof names - len, "%s%s",
                             len ? ", " : ": ", lin->neutral[k].name);
            }
            snprintf(r->static_note, sizeof r->static_note,
                     "undefined: the model is singular at 0 Hz, where the "
                     "towing vehicle's neutral modes by symmetry lie%s; a "
                     "steady input may drift them without bound", names);
        }
    }
    int chunks = resp_chunks(lin, npoints);
    for (int i = 0; i < npoints && rc == TS_OK && chunks == 1; i++) {
        rc = gain_at(sys, lin, input, out, 2 * M_PI * freq_hz[i], &w, &sh, &g,
                     &r->error[i], err);
        set_point(r, i, freq_hz[i], g);
        ts_progress p = {"response", i + 1.0, npoints, "frequencies"};
        if (rc == TS_OK && progress && progress(&p, data))
            rc = ts_fail(err, TS_ECANCEL, "response: stopped on request "
                         "after %d of %d frequencies (%.6g Hz)", i + 1,
                         npoints, freq_hz[i]);
    }
    tsi_shift_free(&sh);
    ws_free(&w);
    if (rc == TS_OK && chunks > 1)
        rc = sweep_chunks(sys, lin, input, out, freq_hz, npoints, chunks,
                          progress, data, r, err);
    if (rc != TS_OK) {
        ts_response_free(r);
        return rc;
    }
    *res = r;
    return TS_OK;
}
