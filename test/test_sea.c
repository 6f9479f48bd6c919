/* test_sea.c: wave spectra (towstab/sea.h) against closed forms and the
 * test's own quadrature.
 *
 *  1. Pierson-Moskowitz: the density equals the formula written out here;
 *     4 sqrt(m0) = Hs by this test's own composite Simpson rule in ln w
 *     (400 000 intervals over [0.1 wp, 1000 wp], error below 1e-12 of m0;
 *     the part outside, by PM's closed-form distribution, is below 1e-11)
 *     to 1e-9; ts_sea_moment: m0 = Hs^2/16 and m2 = 5 sqrt(pi) /
 *     (64 sqrt(1.25)) Hs^2 wp^2 (the closed form, so Tz = 0.7104 Tp) to
 *     1e-10; the peak is at wp. (Density comparisons: 1e-13 relative, the
 *     rounding of the formula's evaluation order.)
 *  2. JONSWAP: for gamma 2, 3.3 and 7
 *     the test's quadrature gives 4 sqrt(m0) = Hs to 1e-9 (the exact
 *     normalisation) and the normalisation lies within 3 % of DNV's
 *     1 - 0.287 ln gamma (the approximation it replaces); the peak stays
 *     at wp.
 *  3. The band: for PM the wave energy below lo and above hi is exactly
 *     tail / 2 each (closed-form distribution), to 1e-9 relative.
 *  4. Tables: the density is linear between samples and zero outside;
 *     moments against the segments' polynomial integrals; a CSV in Hz with
 *     a density per Hz equals the table per rad/s (2 pi); mismatched,
 *     missing and unknown units, bad rows and properties are refused with
 *     the file and line.
 *  5. The spec parser: defaults (DNV's gamma, head seas), units, every
 *     refusal.
 *  6. Encounter frequency: head, beam and following seas.
 */
#include "towstab/sea.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcheck.h"
#include "tfile.h"

static ts_units *units;

/* The PM density written out independently. */
static double pm(double hs, double tp, double w)
{
    double wp = 2 * M_PI / tp;
    return 5.0 / 16.0 * hs * hs * pow(wp, 4) * pow(w, -5) *
           exp(-1.25 * pow(wp / w, 4));
}

/* m0 by composite Simpson in u = ln w over [0.1 wp, 1000 wp]. */
static double m0_quad(const ts_sea *s, double wp)
{
    const int n = 400000;
    double a = log(0.1 * wp), b = log(1000 * wp), h = (b - a) / n, sum = 0;
    for (int i = 0; i <= n; i++) {
        double w = exp(a + i * h);
        double f = ts_sea_density(s, w) * w;
        sum += (i == 0 || i == n ? 1 : i % 2 ? 4 : 2) * f;
    }
    return sum * h / 3;
}

/* Where the density peaks, on a scan of [0.5, 2.5] wp in steps of 1e-4
 * wp. */
static double peak(const ts_sea *s, double wp)
{
    double best = 0, wbest = 0;
    for (int i = 0; i <= 20000; i++) {
        double w = wp * (0.5 + i * 1e-4);
        if (ts_sea_density(s, w) > best) {
            best = ts_sea_density(s, w);
            wbest = w;
        }
    }
    return wbest;
}

static void test_pm(void)
{
    ts_err err = {0};
    double hs = 3.217, tp = 9.43, wp = 2 * M_PI / tp;
    ts_sea *s = ts_sea_jonswap(hs, tp, 1.0, M_PI, &err);
    if (!CHECK(s, "PM sea: %s", err.msg))
        return;
    ts_sea_info in;
    ts_sea_get_info(s, &in);
    CHECK(in.kind == TS_SEA_PM && in.norm == 1.0, "gamma 1 is PM, C = 1");
    double worst = 0;
    for (int i = 1; i <= 50; i++) {
        double w = wp * (0.3 + 0.1 * i);
        double want = pm(hs, tp, w);
        worst = fmax(worst, fabs(ts_sea_density(s, w) - want) / want);
    }
    CHECK(worst <= 1e-13, "PM density = the formula, to rounding (rel diff "
          "%.2g)", worst);
    CHECK(ts_sea_density(s, 0) == 0 && ts_sea_density(s, -1) == 0,
          "PM density 0 at w <= 0");
    double m0 = m0_quad(s, wp);
    CHECK_REL(4 * sqrt(m0), hs, 1e-9, "PM: 4 sqrt(m0), own quadrature");
    double v;
    CHECK(ts_sea_moment(s, 0, 0, INFINITY, &v, &err) == TS_OK, "moment 0");
    CHECK_REL(v, hs * hs / 16, 1e-10, "PM m0 = Hs^2/16 (ts_sea_moment)");
    CHECK(ts_sea_moment(s, 2, 0, INFINITY, &v, &err) == TS_OK, "moment 2");
    double m2 = 5 * sqrt(M_PI) / (64 * sqrt(1.25)) * hs * hs * wp * wp;
    CHECK_REL(v, m2, 1e-10, "PM m2 closed form");
    CHECK_REL(2 * M_PI * sqrt(hs * hs / 16 / v) / tp, 0.71036, 1e-4,
              "PM Tz / Tp = 0.7104");
    CHECK_NEAR(peak(s, wp) / wp, 1.0, 1e-4, "PM peak at wp");
    /* The band: tail/2 each side, exactly for PM. */
    double lo, hi, below, above, tail = 1e-4;
    ts_sea_band(s, tail, &lo, &hi);
    ts_sea_moment(s, 0, 0, lo, &below, &err);
    ts_sea_moment(s, 0, hi, INFINITY, &above, &err);
    CHECK_REL(below / (hs * hs / 16), tail / 2, 1e-8, "PM band: below lo");
    CHECK_REL(above / (hs * hs / 16), tail / 2, 1e-8, "PM band: above hi");
    /* Encounter frequency. */
    double w = 0.7, U = 2.5, g = 9.80665;
    CHECK_REL(ts_sea_encounter(w, U, M_PI, g), w + w * w * U / g, 1e-15,
              "head seas: w + w^2 U / g");
    CHECK_NEAR(ts_sea_encounter(w, U, M_PI / 2, g), w, 1e-15,
               "beam seas: w_e = w");
    CHECK_REL(ts_sea_encounter(w, U, 0, g), w - w * w * U / g, 1e-15,
              "following seas: w - w^2 U / g");
    ts_sea_free(s);
}

static void test_jonswap(void)
{
    ts_err err = {0};
    double hs = 5.31, tp = 11.2, wp = 2 * M_PI / tp;
    const double gammas[3] = {2.0, 3.3, 7.0};
    for (int i = 0; i < 3; i++) {
        double g = gammas[i];
        ts_sea *s = ts_sea_jonswap(hs, tp, g, 2.5, &err);
        if (!CHECK(s, "JONSWAP gamma %g: %s", g, err.msg))
            continue;
        ts_sea_info in;
        ts_sea_get_info(s, &in);
        CHECK_REL(4 * sqrt(m0_quad(s, wp)), hs, 1e-9,
                  "JONSWAP: 4 sqrt(m0) = Hs, own quadrature");
        double dnv = 1 - 0.287 * log(g);
        printf("  gamma %g: normalisation %.6f, DNV's approximation %.6f "
               "(%.2f %% apart)\n", g, in.norm, dnv,
               100 * (dnv - in.norm) / in.norm);
        CHECK(fabs(dnv - in.norm) <= 0.03 * in.norm,
              "normalisation within 3 %% of DNV's 1 - 0.287 ln gamma");
        CHECK_NEAR(peak(s, wp) / wp, 1.0, 1e-4, "JONSWAP peak at wp");
        /* Enhancement at the peak: gamma times PM, normalised. */
        CHECK_REL(ts_sea_density(s, wp), in.norm * g * pm(hs, tp, wp),
                  1e-14, "S(wp) = C gamma S_PM(wp)");
        double v;
        ts_sea_moment(s, 0, 0, INFINITY, &v, &err);
        CHECK_REL(v, hs * hs / 16, 1e-10, "ts_sea_moment m0 = Hs^2/16");
        ts_sea_free(s);
    }
}

static void test_table(void)
{
    ts_err err = {0};
    const double w[5] = {0.2, 0.4, 0.55, 0.9, 1.6};
    const double d[5] = {0.0, 1.2, 2.9, 0.7, 0.05};
    ts_sea *s = ts_sea_table(5, w, d, M_PI, &err);
    if (!CHECK(s, "table: %s", err.msg))
        return;
    CHECK_REL(ts_sea_density(s, 0.5), 1.2 + (2.9 - 1.2) * (0.1 / 0.15),
              1e-14, "table: linear between samples");
    CHECK(ts_sea_density(s, 0.1) == 0 && ts_sea_density(s, 1.7) == 0,
          "table: zero outside");
    /* Moments from each segment's polynomial. */
    double m0 = 0, m2 = 0;
    for (int i = 0; i < 4; i++) {
        double a = w[i], b = w[i + 1];
        double beta = (d[i + 1] - d[i]) / (b - a), alpha = d[i] - beta * a;
        m0 += alpha * (b - a) + beta * (b * b - a * a) / 2;
        m2 += alpha * (b * b * b - a * a * a) / 3 +
              beta * (pow(b, 4) - pow(a, 4)) / 4;
    }
    double v;
    ts_sea_moment(s, 0, 0, INFINITY, &v, &err);
    CHECK_REL(v, m0, 1e-14, "table m0");
    ts_sea_moment(s, 2, 0, INFINITY, &v, &err);
    CHECK_REL(v, m2, 1e-14, "table m2");
    ts_sea_info in;
    ts_sea_get_info(s, &in);
    CHECK_REL(in.hs, 4 * sqrt(m0), 1e-14, "table Hs = 4 sqrt(m0)");
    CHECK_REL(in.tp, 2 * M_PI / 0.55, 1e-14, "table Tp from its largest "
              "sample");
    /* Part of the range. */
    double part;
    ts_sea_moment(s, 0, 0.3, 0.7, &part, &err);
    double want = 0.5 * (0.6 + 1.2) * 0.1 + 0.5 * (1.2 + 2.9) * 0.15 +
                  0.5 * (2.9 + (2.9 + (0.7 - 2.9) * 0.15 / 0.35)) * 0.15;
    CHECK_REL(part, want, 1e-13, "table moment over [0.3, 0.7]");

    /* The same table as CSV per Hz. */
    char text[1024];
    int n = snprintf(text, sizeof text, "# a test spectrum\nfrequency [Hz], "
                     "S [m^2/Hz]\n");
    for (int i = 0; i < 5; i++)
        n += snprintf(text + n, sizeof text - (size_t)n, "%.17g, %.17g\n",
                      w[i] / (2 * M_PI), d[i] * 2 * M_PI);
    char *path = tf_write_temp("test_sea", text);
    ts_sea *c = ts_sea_read_csv(path, units, M_PI, &err);
    if (CHECK(c, "CSV per Hz: %s", err.msg)) {
        double worst = 0;
        for (int i = 0; i < 40; i++) {
            double x = 0.2 + i * 0.035;
            worst = fmax(worst, fabs(ts_sea_density(c, x) -
                                     ts_sea_density(s, x)));
        }
        CHECK(worst <= 1e-13, "CSV in Hz, per Hz = table per rad/s (max "
              "diff %.2g)", worst);
    }
    ts_sea_free(c);
    unlink(path);
    ts_sea_free(s);

    /* Refusals. */
    static const struct {
        const char *text, *expect;
    } bad[] = {
        {"omega [rad/s], S [m^2/Hz]\n0.5, 1\n1, 2\n", "per rad/s"},
        {"frequency [Hz], S [m^2 s/rad]\n0.5, 1\n1, 2\n", "per Hz"},
        {"omega, S [m^2 s/rad]\n0.5, 1\n1, 2\n", "give its unit"},
        {"omega [rad/s], S [m^2 s/rad]\n0.5, 1\n1, x\n", "line 3"},
        {"omega [rad/s], S [m^2 s/rad]\n0.5, 1\n0.4, 2\n", "line 3"},
        {"omega [rad/s], S [m^2 s/rad]\n0.5, -1\n1, 2\n", "line 2"},
        {"period [s], S [m^2 s/rad]\n5, 1\n10, 2\n", "not a frequency"},
        {"omega [rad/s], S [m^2 s/rad], x [m]\n0.5, 1, 2\n", "two columns"},
        {"omega [rad/s], S [m^2 s/rad]\n", "no data rows"},
        {"axes: z-up\nomega [rad/s], S [m^2 s/rad]\n0.5,1\n1,2\n",
         "no properties"},
        {"omega [m], S [m^2 s/rad]\n0.5, 1\n1, 2\n", "column 1"},
        {"omega [rad/s], S [m^2 s/rad]\n0.5, 0\n1, 0\n", "zero everywhere"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char *p = tf_write_temp("test_sea", bad[i].text);
        ts_err e = {0};
        ts_sea *x = ts_sea_read_csv(p, units, M_PI, &e);
        CHECK(!x && strstr(e.msg, bad[i].expect) && strstr(e.msg, p),
              "CSV refused (%s): %s", bad[i].expect, e.msg);
        ts_sea_free(x);
        unlink(p);
    }
    ts_err e = {0};
    CHECK(!ts_sea_read_csv("/nonexistent/spectrum.csv", units, 0, &e) &&
              e.code == TS_EIO,
          "missing file: TS_EIO: %s", e.msg);
    const double w2[3] = {0.2, 0.2, 0.3}, d2[3] = {1, 1, 1};
    CHECK(!ts_sea_table(3, w2, d2, 0, &e) && strstr(e.msg, "increase"),
          "table: repeated frequency refused: %s", e.msg);
    CHECK(!ts_sea_table(1, w2, d2, 0, &e), "table: one sample refused");
}

static void test_parse(void)
{
    ts_err err = {0};
    ts_sea_info in;
    ts_sea *s = ts_sea_parse("Hs=4m,Tp=10s", units, "--sea", &err);
    if (CHECK(s, "parse Hs=4m,Tp=10s: %s", err.msg)) {
        ts_sea_get_info(s, &in);
        CHECK(in.hs == 4 && in.tp == 10 && in.gamma == 1.0 &&
                  in.kind == TS_SEA_PM &&
                  fabs(in.heading - M_PI) < 1e-15,
              "Tp/sqrt(Hs) = 5: DNV's gamma 1 (PM), head seas");
    }
    ts_sea_free(s);
    s = ts_sea_parse(" hs = 13.1 ft , TP=8 s,gamma=3.3, heading = 150 deg",
                     units, "--sea", &err);
    if (CHECK(s, "parse with units: %s", err.msg)) {
        ts_sea_get_info(s, &in);
        CHECK_REL(in.hs, 13.1 * 0.3048, 1e-14, "Hs in ft");
        CHECK(in.gamma == 3.3 && fabs(in.heading - 150 * M_PI / 180) < 1e-14,
              "gamma and heading");
    }
    ts_sea_free(s);
    s = ts_sea_parse("Hs=4,Tp=8", units, NULL, &err);
    if (CHECK(s, "parse SI numbers: %s", err.msg)) {
        ts_sea_get_info(s, &in);
        CHECK_REL(in.gamma, exp(5.75 - 1.15 * 4), 1e-14,
                  "DNV's gamma for Tp/sqrt(Hs) = 4");
    }
    ts_sea_free(s);
    CHECK(ts_sea_default_gamma(4, 7) == 5 && ts_sea_default_gamma(1, 6) == 1,
          "DNV's gamma: 5 below 3.6, 1 above 5");
    s = ts_sea_parse("type=pm,Hs=2m,Tp=7s", units, "--sea", &err);
    CHECK(s && fabs(ts_sea_density(s, 1.0) / pm(2, 7, 1.0) - 1) < 1e-13,
          "type=pm: %s", err.msg);
    ts_sea_free(s);
    static const struct {
        const char *spec, *expect;
    } bad[] = {
        {"Hs=4m", "needs Hs and Tp"},
        {"Hs=4m,Tp=10s,Hs=3m", "given twice"},
        {"Hs=4m,Tp=10s,wind=3", "unknown key 'wind'"},
        {"Hs=4s,Tp=10s", "Hs"},
        {"Hs=4m,Tp=10s,gamma=0.5", "gamma must be in [1, 10]"},
        {"Hs=-4m,Tp=10s", "Hs must be"},
        {"Hs=4m,Tp=0s", "Tp must be"},
        /* Beyond any sea (their integrals overflow or diverge): refused
         * as the spec is read, before any analysis runs. */
        {"Hs=1e300m,Tp=10s", "Hs must be a height > 0 m and at most 100 m"},
        {"Hs=101m,Tp=10s", "Hs must be"},
        {"Hs=4m,Tp=1e-6s", "Tp must be a period from 0.1 s"},
        {"Hs=4m,Tp=1e300s", "to 100 s, got 1e+300 s"},
        {"type=pm,Hs=4m,Tp=10s,gamma=2", "no gamma"},
        {"type=bretschneider,Hs=4m,Tp=10s", "unknown type"},
        {"file=x.csv,Hs=4m", "leave out"},
        {"Hs=4m,Tp=10s,heading=5m", "heading"},
        {"Hs", "not key=value"},
        {"Hs=,Tp=3", "no value"},
        {"", "expected Hs"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ts_err e = {0};
        ts_sea *x = ts_sea_parse(bad[i].spec, units, "--sea", &e);
        CHECK(!x && strstr(e.msg, bad[i].expect) &&
                  !strncmp(e.msg, "--sea", 5),
              "parse '%s' refused: %s", bad[i].spec, e.msg);
        ts_sea_free(x);
    }
    ts_err e = {0};
    CHECK(!ts_sea_parse("file=/nonexistent.csv", units, "--sea", &e) &&
              e.code == TS_EIO && strstr(e.msg, "--sea"),
          "file missing: %s", e.msg);
}

int main(void)
{
    ts_err err = {0};
    units = ts_units_alloc(&err);
    if (!units) {
        printf("FAIL units: %s\n", err.msg);
        return 1;
    }
    test_pm();
    test_jonswap();
    test_table();
    test_parse();
    ts_units_free(units);
    return tc_done();
}
