/* towstab/sea.h: a long-crested irregular sea, its wave spectrum and its
 * heading (doc/seastate.md, section 1).
 *
 * The wave elevation at a point is a stationary Gaussian process with the
 * one-sided spectral density S(w) (m^2 s/rad, w in rad/s > 0), so that its
 * variance is m0 = int_0^inf S(w) dw and the significant wave height is
 * Hs = 4 sqrt(m0). Spectra:
 *  - Pierson-Moskowitz (in the two-parameter form of DNV-RP-C205 3.5.5):
 *      S_PM(w) = 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (wp/w)^4),  wp = 2 pi / Tp,
 *    whose zeroth moment is exactly Hs^2 / 16;
 *  - JONSWAP: S_J(w) = C(gamma) S_PM(w) gamma^r(w),
 *      r = exp(-(w - wp)^2 / (2 sigma^2 wp^2)), sigma = 0.07 for w <= wp
 *      and 0.09 above; the normalisation C(gamma) is computed (GSL
 *      quadrature) so that m0 = Hs^2 / 16 exactly, not taken from DNV's
 *      approximation 1 - 0.287 ln gamma; gamma = 1 is Pierson-Moskowitz
 *      (C = 1). Without a gamma the spec parser takes DNV-RP-C205's
 *      default: 5 for Tp / sqrt(Hs) <= 3.6 (s, m), exp(5.75 - 1.15 Tp /
 *      sqrt(Hs)) up to 5, 1 above;
 *  - a table (w_i, S_i), linear between points and zero outside; its Hs is
 *    4 sqrt of the exact integral of that piecewise-linear density.
 * Heading beta (rad): the angle between the ship's course and the
 * direction in which the waves travel, in the convention of the ship's RAO
 * table, with 180 deg head seas and 0 deg following seas. A ship moving at
 * speed U meets a wave of frequency w at the encounter frequency
 *   w_e = w - w^2 U cos(beta) / g    (deep water, k = w^2 / g),
 * negative when a following wave overtakes the ship.
 */
#ifndef TOWSTAB_SEA_H
#define TOWSTAB_SEA_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_SEA_PM = 0,       /* Pierson-Moskowitz */
    TS_SEA_JONSWAP = 1,  /* JONSWAP */
    TS_SEA_TABLE = 2     /* tabulated density */
} ts_sea_kind;

/* Limits of the parameters accepted. */
#define TS_SEA_GAMMA_MAX 10.0   /* JONSWAP peak enhancement (DNV: 1..7) */
#define TS_SEA_HS_MAX 100.0     /* m: five times the largest Hs measured */
#define TS_SEA_TP_MIN 0.1       /* s: shorter waves are capillary (1.6 cm) */
#define TS_SEA_TP_MAX 100.0     /* s: four times the longest swell's Tp */
#define TS_SEA_HEADING_DEFAULT 3.14159265358979323846 /* head seas, rad */

typedef struct ts_sea ts_sea;

/* What a sea is made of (read-only view, SI). */
typedef struct ts_sea_info {
    ts_sea_kind kind;
    double hs;        /* m: 4 sqrt(m0) of the density as defined */
    double tp;        /* s: peak period (a table: of its largest sample) */
    double gamma;     /* JONSWAP peak enhancement (1 for PM, NaN: table) */
    double norm;      /* JONSWAP normalisation C(gamma) (1 for PM) */
    double heading;   /* rad */
    double m0;        /* m^2: zeroth moment */
    int npoints;      /* table samples (0 for a parametric spectrum) */
    const char *source; /* table: the file read, or "" */
} ts_sea_info;

/* A JONSWAP sea: Hs (m, in (0, TS_SEA_HS_MAX]), Tp (s, in [TS_SEA_TP_MIN,
 * TS_SEA_TP_MAX]), gamma in [1,
 * TS_SEA_GAMMA_MAX] (1: Pierson-Moskowitz), heading (rad, finite). NULL
 * on failure (TS_EINVAL naming the parameter, TS_ENOMEM). */
TS_API ts_sea *ts_sea_jonswap(double hs, double tp, double gamma,
                              double heading, ts_err *err);

/* A tabulated sea: n >= 2 samples, omega[n] (rad/s, >= 0, strictly
 * increasing) and density[n] (m^2 s/rad, >= 0, not all zero; its Hs at
 * most TS_SEA_HS_MAX); copied.
 * NULL on failure (TS_EINVAL naming the sample). */
TS_API ts_sea *ts_sea_table(int n, const double omega[],
                            const double density[], double heading,
                            ts_err *err);

/* Read a tabulated sea from a CSV file. Lines starting with '#' are
 * comments. The first other line is the header naming the two columns
 * with their units in brackets: the frequency as "omega [rad/s]" (angular)
 * or "frequency [Hz]" (cyclic; any unit of that dimension, e.g. [1/min]),
 * then the density per unit of that frequency, e.g. "S [m^2 s/rad]" or
 * "S [m^2/Hz]" (a density per Hz is divided by 2 pi). A density whose
 * unit does not match the frequency column (per Hz against omega, per
 * rad/s against frequency) is refused: that 2 pi is the classic slip.
 * Then one row of two numbers per sample. TS_EIO when the file cannot be
 * read; TS_EINVAL or TS_EUNIT naming the file, line and column. */
TS_API ts_sea *ts_sea_read_csv(const char *path, const ts_units *units,
                               double heading, ts_err *err);

/* Parse a sea description "key=value,key=value,...":
 *   Hs=4m,Tp=10s[,gamma=3.3][,heading=150deg]   JONSWAP (gamma absent:
 *                                               DNV's default from Tp, Hs)
 *   type=pm,Hs=..,Tp=..[,heading=..]            Pierson-Moskowitz
 *   file=PATH[,heading=..]                      a CSV table (above)
 * Keys are case-insensitive (hs, Hs); values may carry units (plain
 * numbers are SI: m, s, rad). heading defaults to TS_SEA_HEADING_DEFAULT
 * (180 deg, head seas). `where` names the origin in messages ("--sea").
 * NULL on failure (TS_EINVAL, TS_EUNIT, TS_EIO for an unreadable file). */
TS_API ts_sea *ts_sea_parse(const char *spec, const ts_units *units,
                            const char *where, ts_err *err);

TS_API void ts_sea_free(ts_sea *s);

/* DNV-RP-C205's default gamma for Tp (s) and Hs (m), as above. */
TS_API double ts_sea_default_gamma(double hs, double tp);

TS_API void ts_sea_get_info(const ts_sea *s, ts_sea_info *info);

/* S(w), m^2 s/rad (0 for w <= 0). */
TS_API double ts_sea_density(const ts_sea *s, double omega);

/* The moment int_lo^hi w^k S(w) dw for k = 0, 1 or 2 (m^2 rad^k / s^k),
 * 0 <= lo < hi (hi may be INFINITY). Parametric spectra by GSL adaptive
 * quadrature to 1e-12 relative (split at the peak, where the JONSWAP
 * shape's slope jumps), tables exactly. TS_EINVAL for a bad range or k,
 * TS_EDOMAIN when the quadrature fails. */
TS_API int ts_sea_moment(const ts_sea *s, int k, double lo, double hi,
                         double *value, ts_err *err);

/* A band [lo, hi] (rad/s) outside which lies at most `tail` (in (0, 0.5))
 * of m0, about half below lo and half above hi (closed form from the
 * Pierson-Moskowitz tails, exact for PM, scaled by C(gamma) for JONSWAP,
 * whose peak enhancement is nil that far out); a table's own range (from
 * its second sample when the first is at 0: a band starts above 0). */
TS_API void ts_sea_band(const ts_sea *s, double tail, double *lo,
                        double *hi);

/* Encounter frequency w - w^2 U cos(beta) / g (rad/s) of a wave of
 * frequency w for a ship at speed U (m/s) and heading beta (rad), g > 0
 * (m/s^2). */
TS_API double ts_sea_encounter(double omega, double speed, double heading,
                               double gravity);

/* One line, e.g. "JONSWAP Hs 4 m, Tp 10 s, gamma 3.3 (C 0.6241),
 * heading 180 deg". */
TS_API void ts_sea_describe(const ts_sea *s, char *buf, size_t size);

#ifdef __cplusplus
}
#endif
#endif
