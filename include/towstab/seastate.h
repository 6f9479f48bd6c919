/* towstab/seastate.h: the towed system's response to the ship's motion in
 * an irregular sea, by spectral analysis of the linear model and in the
 * time domain (doc/seastate.md; doc/model.md section 6).
 *
 * The sea (towstab/sea.h) moves the ship, and the ship's RAOs
 * (towstab/rao.h) give the tow point's translation T_j(w) per metre of
 * wave amplitude (j = surge, sway, heave of M), met at the encounter
 * frequency w_e(w). The sea reaches the cable only through the tow point:
 * wave kinematics on the cable and the bodies are not modelled (doc/model.md
 * section 3; at depth z they decay as exp(-w^2 z / g)).
 *
 * Spectral response. The linear model's gain H_j(i w_e) from tow-point
 * axis j to an output (towstab/response.h; H(-w) = conj H(w) for a
 * following sea's negative w_e) gives the output's complex amplitude per
 * metre of wave amplitude, summed coherently over the inputs,
 *   G(w) = sum_j H_j(w_e(w)) T_j(w),
 * and its one-sided spectral density over wave frequency
 *   S_out(w) = |G(w)|^2 S(w)     (unit^2 s/rad),
 * with the moments m0 = int S_out dw and m2 = int w_e^2 S_out dw (the
 * output oscillates at the encounter frequency), hence
 *   sigma = sqrt(m0), significant amplitude 2 sigma (single amplitude;
 *   the significant double amplitude is 4 sigma, as Hs is for waves),
 *   zero up-crossing period Tz = 2 pi sqrt(m0 / m2), and the most probable
 *   largest excursion from the mean in a duration D of N = D / Tz cycles,
 *   sigma sqrt(2 ln N) (Rayleigh distributed peaks of a narrow-band
 *   Gaussian process).
 * The moments are integrated by Simpson's rule on a grid uniform in ln w
 * (constant relative resolution: a resonance of damping ratio zeta needs
 * spacing below zeta wherever it sits) of `intervals` intervals, and again
 * on the grids of a half and a quarter as many: the fine result's error is
 * the full difference of the two finest, or, when the three show a steady
 * order p in [2, 8], the Richardson error at min(p, 4). The wave energy outside the grid's band adds a band error, the
 * edge values of |G|^2 (and w_e^2) times the wave moment outside (a
 * first-order estimate: the transfer held at its edge value). Both are
 * reported, and their sum is each statistic's error.
 *
 * Irregular-sea time domain. One realisation of the same sea is a sum of
 * sinusoids: n components in equal bins of the band, each at a frequency
 * drawn uniformly within its bin (so that the record does not repeat and
 * the expected variance is the band's integral, without grid bias), with
 * the amplitude sqrt(2 S(w_k) dw) and a phase uniform in [0, 2 pi), both
 * from GSL's MT19937 seeded with `seed` (reproducible). The tow point moves
 * by Re(T_j(w_k) a_k e^(i (w_e,k t + phi_k))), faded in over `rise`, as an
 * excitation (towstab/excitation.h) for ts_simulate and ts_simulate_linear.
 * Its statistics over a window: mean, sigma and sigma's statistical error
 * for the run's length, from the record's own autocovariance R: for a
 * Gaussian process the sample variance over a length L has the variance
 * (2 / L) int R(tau)^2 dtau, so sigma has the relative standard error
 * sqrt(int R^2 dtau / (2 L)) / R(0) (the integral over all lags, cut where
 * Sokal's automatic window stops it: at the first lag M >= 6 tau2(M), tau2
 * the running correlation time of R^2). With fixed amplitudes the
 * realisation varies less than a Gaussian sea between records, so this
 * error is an upper estimate.
 *
 * Units: SI; outputs in m or N (the unit of the response module's output
 * per m of tow motion, times m of wave amplitude).
 */
#ifndef TOWSTAB_SEASTATE_H
#define TOWSTAB_SEASTATE_H

#include "towstab/progress.h"
#include "towstab/converge.h"
#include "towstab/error.h"
#include "towstab/excitation.h"
#include "towstab/health.h"
#include "towstab/linearize.h"
#include "towstab/rao.h"
#include "towstab/response.h"
#include "towstab/sea.h"
#include "towstab/simulate.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The sea's inputs to the linear model: the three tow-point axes, and
 * with a towing vehicle its three rotations (channels of
 * ts_response_compute); room for more (fins). */
#define TS_SEA_MAX_INPUTS 8

/* Defaults. */
#define TS_SEASTATE_INTERVALS 512      /* fine grid, a multiple of 8 */
#define TS_SEASTATE_DURATION 10800.0   /* s: 3 h, for the largest value */
#define TS_SEASTATE_TAIL 1e-6          /* wave m0 left outside the band */
#define TS_SEA_COMPONENTS 256          /* components of a realisation */
/* Wave m0 a realisation leaves outside its band: its highest components
 * set the time scale the simulators resolve, and the last 1e-6 of m0 (PM
 * out to 40 wp) would cost 7 times shorter steps for nothing seen. */
#define TS_SEA_REALISATION_TAIL 1e-3
/* Sokal's window constant for the statistical error of a record. */
#define TS_SEA_SOKAL 6.0

/* The ship in a sea, as the tow point sees it. */
typedef struct ts_seaway {
    const ts_sea *sea;     /* used, not owned */
    const ts_rao *rao;     /* used, not owned; NULL: the tow point follows
                              the water surface (T = (0, 0, -1): a buoy) */
    double lever[3];       /* tow point less the RAO reference point, m, M */
    double speed;          /* ship speed, m/s */
    double gravity;        /* m/s^2 */
    /* With a towing vehicle the RAOs' rotations are the tow rotation
     * inputs (tow.roll, tow.pitch, tow.yaw: about the vehicle's origin O,
     * so that each cable start point r gets theta x r, towstab/kernel.h),
     * and the translation is the one of O: xi + theta x (O less the
     * reference point). Without one (a prescribed tow point, the one start
     * point) the rotations enter through the lever alone. */
    int rotations;         /* 1: drive the rotation inputs */
    double reference[3];   /* the RAO reference point, m, M */
    double origin[3];      /* the vehicle's origin O in M at its trim, m
                              (ts_seaway_set_trim; ts_seaway_init puts it
                              at tow.point less the attach point, the
                              vehicle level) */
} ts_seaway;

/* A seaway for system sys: lever = sys->tow.point - reference (reference
 * NULL: M's origin), the tow's speed and the environment's gravity.
 * Refuses (TS_EDOMAIN) a turning tow (the heading to the waves would
 * change all the time: the sea is not stationary in M), zero gravity (no
 * waves), and a heading outside the RAO table. */
TS_API int ts_seaway_init(ts_seaway *w, const ts_system *sys,
                          const ts_sea *sea, const ts_rao *rao,
                          const double reference[3], ts_err *err);

/* The tow inputs per metre of wave amplitude at wave frequency omega:
 * re[TS_SUM_AXES], im[TS_SUM_AXES] (M axes): the tow point's translation
 * (m/m; with rotations, the vehicle origin's) and, with rotations, the
 * ship's rotation (rad/m; zero without). TS_EDOMAIN outside the RAO
 * table. */
TS_API int ts_seaway_tow(const ts_seaway *w, double omega,
                         double re[TS_SUM_AXES], double im[TS_SUM_AXES],
                         ts_err *err);

/* The towing vehicle's origin at its trim y (ts_kernel_root; nothing
 * without a towing vehicle): w->origin. */
TS_API void ts_seaway_set_trim(ts_seaway *w, const ts_kernel *k,
                               const double y[]);

/* The band the analyses cover: the sea's band holding all but `tail` of
 * its m0, cut to the RAO table's frequencies. TS_EDOMAIN when they do not
 * overlap. */
TS_API int ts_seaway_band(const ts_seaway *w, double tail, double *lo,
                          double *hi, ts_err *err);

typedef struct ts_seastate_opts {
    int intervals;       /* of the fine grid, a multiple of 8 in [16,
                            2^20]; default TS_SEASTATE_INTERVALS */
    double omega_lo, omega_hi; /* band, rad/s (0: ts_seaway_band) */
    double tail;         /* for ts_seaway_band; default TS_SEASTATE_TAIL */
    double duration;     /* s, > 0: for the most probable maximum; default
                            TS_SEASTATE_DURATION */
    ts_progress_fn progress; /* towstab/progress.h: called after every
                            frequency of every driven tow axis (what "sea
                            state", done of total frequencies); a nonzero
                            return stops it with TS_ECANCEL and no
                            result. Default NULL */
    void *progress_data;
} ts_seastate_opts;

TS_API void ts_seastate_opts_default(ts_seastate_opts *o);

/* A statistic and its estimated error (>= 0, same unit). For a spectral
 * result, the error is the sum of the parts from the frequency grid, the
 * band and the discretisation (links; 0 until ts_seastate_discretisation
 * estimates it); for a record (ts_record_stats) it is the statistical
 * error and the parts are 0. */
typedef struct ts_stat {
    double value, error;
    double grid, band, discretisation;
} ts_stat;

typedef struct ts_seastate {
    ts_output output;
    const char *unit;     /* "m" or "N" */
    double mean;          /* the output at the equilibrium (m or N) */
    /* Grid (fine), npoints = intervals + 1. */
    int npoints;
    double *omega;        /* [npoints] wave frequency, rad/s, uniform */
    double *omega_e;      /* [npoints] encounter frequency, rad/s */
    double *wave;         /* [npoints] S(w), m^2 s/rad */
    int ninputs;
    int channel[TS_SEA_MAX_INPUTS];  /* response input of each input */
    double *input_re, *input_im;     /* [ninputs * npoints] input per m of
                                        wave amplitude (row i: input i) */
    double *gain_re, *gain_im;       /* [npoints] G(w), unit per m */
    double *density;      /* [npoints] S_out(w), unit^2 s/rad */
    /* Statistics (values with errors). */
    ts_stat m0;           /* unit^2 */
    ts_stat m2;           /* unit^2 / s^2 */
    ts_stat sigma;        /* unit */
    ts_stat significant;  /* 2 sigma: significant single amplitude */
    ts_stat tz;           /* s */
    ts_stat mpm;          /* sigma sqrt(2 ln N), unit: excursion from the
                             mean */
    double duration;      /* s */
    double cycles;        /* N = duration / Tz */
    /* Parts of the errors of m0 and m2. */
    double m0_grid_error, m0_band_error, m2_grid_error, m2_band_error;
    double order_m0, order_m2;  /* observed orders (NaN: none) */
    double band_lo, band_hi;    /* rad/s */
    /* Discretisation (ts_seastate_discretisation). */
    int disc_estimated;   /* 1 when estimated (the parts are then in the
                             statistics' errors) */
    int disc_links[3];    /* links per cable of the runs: coarse to fine */
    double disc_order;    /* observed order of sigma (NaN: none) */
    double disc_wall_s;   /* seconds the two coarser runs took */
    double disc_links_needed; /* links per cable the error model says meet
                                 TS_SEASTATE_RTOL for sigma (NaN: met, or
                                 unknown) */
    double wave_m0_band;  /* wave m0 on the grid, m^2 */
    double wave_m0_out;   /* wave m0 outside the band, m^2 */
    double wave_hs;       /* the sea's Hs, m */
    long responses;       /* gain evaluations (one LU each) */
    ts_trust trust;       /* trustworthy unless the errors are large */
} ts_seastate;

/* Relative error of sigma above which a result is not trustworthy. */
#define TS_SEASTATE_RTOL 1e-2

/* The spectral response of output `out` of sys about the linearization
 * lin (tension outputs need lin's tension Jacobians). On success *res is
 * new (ts_seastate_free). Cost: (intervals + 1) x (inputs driven) gain
 * evaluations (ts_response_compute). Returns TS_OK, TS_EINVAL (bad
 * options or output), TS_EDOMAIN (band outside the RAO table, ...),
 * TS_ESINGULAR (an undamped resonance on a grid point) or TS_ENOMEM. */
TS_API int ts_seastate_compute(const ts_system *sys, const ts_linear *lin,
                               const ts_seaway *w, const ts_output *out,
                               const ts_seastate_opts *o, ts_seastate **res,
                               ts_err *err);
TS_API void ts_seastate_free(ts_seastate *s);

/* Fewest links per cable for ts_seastate_discretisation: its coarsest
 * run has a quarter of them, and one link per cable tells nothing. */
#define TS_SEASTATE_DISC_LINKS_MIN 8

/* The discretisation error of r, a result computed (with options o,
 * NULL: defaults) on sys, every cable of which has the same number
 * N >= TS_SEASTATE_DISC_LINKS_MIN of equal links: the analysis is repeated on copies with ceil(N/2) and
 * ceil(N/4) links (the same sea, RAOs and reference point, the
 * equilibrium solved with eo, NULL: defaults) and ts_convergence_estimate
 * gives the error of the N-link values (Richardson at the observed order,
 * or its fallbacks: towstab/converge.h). The parts go into the
 * statistics' errors (`discretisation`), the trust verdict fails when
 * sigma's discretisation error exceeds TS_SEASTATE_RTOL (saying how many
 * links would meet it), and r->disc_* record the runs. Cost: the two
 * coarser analyses, about (1/8 + 1/64) of the first with dense gains.
 * Returns TS_OK; TS_EDOMAIN (r unchanged) when the links do not allow it
 * (unequal link counts, link_lengths, too few links); a failure of a
 * coarser run (its code and message). */
TS_API int ts_seastate_discretisation(const ts_system *sys,
                                      const ts_equilibrium_opts *eo,
                                      const ts_seaway *w,
                                      const ts_seastate_opts *o,
                                      ts_seastate *r, ts_err *err);

/* The spectral analysis as a convergence study's analysis
 * (towstab/converge.h): the equilibrium of sys (a copy is kept; eo, NULL:
 * defaults), its linearization, and the response of `output` to the sea
 * and RAOs (used, not owned: they must outlive it) with the RAO reference
 * point `reference` (NULL: M's origin) and options o (NULL: defaults).
 * Values "<output>.sigma" (m or N), "<output>.tz" (s) and "<output>.mpm"
 * (m or N), each relative to itself; noise: their grid and band errors.
 * Parameters: links (every cable N equal links), tolerance (the
 * equilibrium's), step (the linearization's). Health: the equilibrium's
 * and the spectral result's. TS_EINVAL for an unknown output, TS_ENOMEM. */
TS_API int ts_seastate_conv_analysis(const ts_system *sys,
                                     const ts_equilibrium_opts *eo,
                                     const ts_sea *sea, const ts_rao *rao,
                                     const double reference[3],
                                     const char *output,
                                     const ts_seastate_opts *o,
                                     ts_conv_analysis *an, ts_err *err);

/* --- Time domain ----------------------------------------------------- */

typedef struct ts_sea_realisation {
    int components;        /* n >= 1; default TS_SEA_COMPONENTS */
    unsigned long seed;    /* default 1 */
    double rise;           /* fade-in, s (>= 0); default 2 Tp */
    double omega_lo, omega_hi; /* band, rad/s (0: ts_seaway_band with
                                  TS_SEA_REALISATION_TAIL) */
} ts_sea_realisation;

TS_API void ts_sea_realisation_default(const ts_seaway *w,
                                       ts_sea_realisation *r);

/* Add one realisation of the seaway's tow-point motion to ex
 * (ts_excitation_add_sum). *band_m0 (may be NULL) receives the expected
 * wave variance of the realisation (m^2, the band's m0). TS_EINVAL for bad
 * options, TS_EDOMAIN as ts_seaway_band, TS_ENOMEM. */
TS_API int ts_seaway_excitation(const ts_seaway *w,
                                const ts_sea_realisation *r,
                                ts_excitation *ex, double *band_m0,
                                ts_err *err);

/* Statistics of a record. */
typedef struct ts_record_stats {
    int nsamples;
    double duration;      /* s: (nsamples - 1) dt */
    double mean;          /* unit */
    double mean_error;    /* its statistical error: sigma sqrt(tau1 / L),
                             tau1 = int R dtau / R(0) over the same lags
                             (at least one sample interval) */
    ts_stat sigma;        /* standard deviation, its statistical error */
    double corr_time;     /* s: int R^2 dtau / R(0)^2 over all lags */
    double independent;   /* duration / corr_time: independent samples */
    double tz;            /* s: mean zero up-crossing period (NaN: none) */
    double maximum, minimum; /* unit */
    int window_lags;      /* lags summed (Sokal's window) */
} ts_record_stats;

/* Statistics of x[n] sampled every dt (s) (n >= 16). TS_EINVAL for bad
 * sizes or non-finite samples; TS_ENOMEM. The autocovariance comes from
 * GSL's FFT, O(n log n). */
TS_API int ts_record_stats_compute(const double x[], int n, double dt,
                                   ts_record_stats *st, ts_err *err);

/* The values of output `out` in history h at the samples with t >= t_from
 * that are spaced evenly (the last sample, at t_end, is dropped when its
 * interval is shorter): x receives them (room for h->nsamples), *n their
 * number, *dt their spacing (outputs of towstab/output.h other than
 * strains and lengths). A value the run does not give is refused
 * (TS_EINVAL): tensions of a linear run made without the tension
 * Jacobians, the tow force of any linear run. */
TS_API int ts_record_from_history(const ts_history *h, const ts_output *out,
                                  double t_from, double x[], int *n,
                                  double *dt, ts_err *err);

#ifdef __cplusplus
}
#endif
#endif
