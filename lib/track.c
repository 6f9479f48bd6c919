/* track.c: the mean frame's pose in the earth frame, and the points of a
 * run in it (towstab/track.h; doc/model.md section 1: M's origin moves at
 * V along its x axis, M turns at Omega).
 *
 * The heading is the excitation's closed form (ts_excitation_heading);
 * the origin's x and y are the integrals of V cos psi and V sin psi,
 * which have no closed form under a ramped turn rate: GSL's CQUAD
 * (doubly adaptive Clenshaw-Curtis) on each stretch between consecutive
 * times, each stretch split at the excitation's breakpoints so that the
 * integrand is smooth on every piece. Without manoeuvres the integrand is
 * the base frame's steady turn and the same quadrature applies (tested
 * against the circle of radius V / Omega). */
#include "towstab/track.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdlib.h>

/* CQUAD's workspace intervals: ample for smooth integrands. */
#define CQUAD_INTERVALS 100

typedef struct {
    const ts_excitation *ex;
    const ts_frame *base;
    int comp;   /* 0: V cos psi, 1: V sin psi */
} track_par;

static void frame_at(const track_par *p, double t, double *V, double *psi)
{
    if (!p->ex) {
        *V = p->base->speed;
        *psi = p->base->turn_rate * t;
        return;
    }
    ts_frame f;
    ts_excitation_frame(p->ex, p->base, t, &f);
    *V = f.speed;
    *psi = ts_excitation_heading(p->ex, p->base, t);
}

static double integrand(double t, void *params)
{
    const track_par *p = params;
    double V, psi;
    frame_at(p, t, &V, &psi);
    return p->comp == 0 ? V * cos(psi) : V * sin(psi);
}

/* integral over [a, b] of component comp, added to *sum. */
static int integrate(track_par *p, gsl_integration_cquad_workspace *w,
                     double a, double b, int comp, double *sum, ts_err *err)
{
    p->comp = comp;
    gsl_function F = {integrand, p};
    double r, e;
    size_t nev;
    /* The absolute tolerance is the relative one of the stretch's length
     * run at the base speed, so that a stretch along which a component
     * vanishes (sin psi on a straight run) does not ask for zero error. */
    double scale = fabs(p->base->speed) * (b - a) + 1e-300;
    int rc = gsl_integration_cquad(&F, a, b, TS_TRACK_RTOL * scale,
                                   TS_TRACK_RTOL, w, &r, &e, &nev);
    if (rc)
        return ts_fail(err, TS_ECONV, "track: the quadrature of the frame's "
                       "origin failed on [%g, %g] s (%s)", a, b,
                       gsl_strerror(rc));
    *sum += r;
    return TS_OK;
}

int ts_track_poses(const ts_excitation *ex, const ts_frame *base, int n,
                   const double t[], double pose[], ts_err *err)
{
    for (int i = 0; i < n; i++)
        if (!(t[i] >= (i ? t[i - 1] : 0.0)))
            return ts_fail(err, TS_EINVAL, "track: times must be >= 0 and "
                           "non-decreasing, got t[%d] = %g s", i, t[i]);
    if (n <= 0)
        return TS_OK;
    /* The breakpoints up to the last time (ends of steps and ramps). */
    int nb = ex ? ts_excitation_breakpoints(ex, t[n - 1], NULL, 0) : 0;
    double *brk = nb > 0 ? malloc((size_t)nb * sizeof *brk) : NULL;
    gsl_integration_cquad_workspace *w =
        gsl_integration_cquad_workspace_alloc(CQUAD_INTERVALS);
    if ((nb > 0 && !brk) || !w) {
        free(brk);
        gsl_integration_cquad_workspace_free(w);
        return ts_fail(err, TS_ENOMEM, "track: out of memory");
    }
    if (nb > 0)
        ts_excitation_breakpoints(ex, t[n - 1], brk, nb);
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    track_par p = {ex, base, 0};
    double x = 0.0, y = 0.0, t0 = 0.0;
    int rc = TS_OK, ib = 0;
    for (int i = 0; i < n && !rc; i++) {
        /* [t0, t[i]] in pieces cut at the breakpoints inside it. */
        double a = t0;
        while (!rc && a < t[i]) {
            while (ib < nb && brk[ib] <= a)
                ib++;
            double b = ib < nb && brk[ib] < t[i] ? brk[ib] : t[i];
            rc = integrate(&p, w, a, b, 0, &x, err);
            if (!rc)
                rc = integrate(&p, w, a, b, 1, &y, err);
            a = b;
        }
        double V, psi;
        frame_at(&p, t[i], &V, &psi);
        pose[3 * i] = x;
        pose[3 * i + 1] = y;
        pose[3 * i + 2] = psi;
        t0 = t[i];
    }
    gsl_set_error_handler(old);
    gsl_integration_cquad_workspace_free(w);
    free(brk);
    return rc;
}

void ts_track_to_earth(const double pose[3], const double r_M[3],
                       double r_E[3])
{
    double c = cos(pose[2]), s = sin(pose[2]);
    double x = r_M[0], y = r_M[1], z = r_M[2];
    r_E[0] = pose[0] + c * x - s * y;
    r_E[1] = pose[1] + s * x + c * y;
    r_E[2] = z;
}

int ts_track_history(ts_history *h, const ts_excitation *ex,
                     const ts_frame *base, ts_err *err)
{
    return ts_track_poses(ex, base, h->nsamples, h->t, h->frame, err);
}
