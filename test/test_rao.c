/* test_rao.c: ship RAOs and the tow point's motion (towstab/rao.h).
 *
 *  1. Interpolation: exact at the table's points; rows linear in frequency
 *     reproduced exactly (Steffen's cubic), no overshoot between rows; a
 *     phase passing through 180 deg between two rows is followed the short
 *     way (the amplitude does not collapse); linear in heading;
 *     a frequency or heading outside the table is TS_EDOMAIN, and a table
 *     without headings serves every heading.
 *  2. Tow point: for random complex RAOs and lever arms, Re(T e^(i w t))
 *     equals the displacement of the lever arm's end under the exact
 *     rotation (Rodrigues' formula, written out here) by eps times the
 *     instantaneous angles plus the translation, divided by eps, at
 *     several t (eps = 1e-7: agreement to 1e-6 relative, the second-order
 *     term); the senses: roll lowers starboard, pitch raises the bow, yaw
 *     turns the bow to starboard.
 *  3. CSV: the same RAOs read in M's axes with leads, in the z-up frame
 *     (sway, heave, pitch, yaw reversed) with lags, with frequencies in Hz
 *     or as periods, rotations in deg/m: all equal the table built by hand
 *     (1e-12); every refusal names the file and line.
 */
#include "towstab/rao.h"

#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tcheck.h"
#include "tfile.h"

static ts_units *units;

#define D2R (M_PI / 180)

static void test_interpolation(void)
{
    ts_err err = {0};
    const double hd[2] = {120 * D2R, 180 * D2R};
    const double w[3] = {0.3, 0.5, 0.8};
    ts_rao *r = ts_rao_alloc(2, hd, 3, w, &err);
    if (!CHECK(r, "alloc: %s", err.msg))
        return;
    /* Heave at 180: amplitude 1.0, 0.8, 0.2; phase 10, 170, -170 deg. */
    const double a180[3] = {1.0, 0.8, 0.2}, p180[3] = {10, 170, -170};
    const double a120[3] = {0.9, 0.5, 0.1}, p120[3] = {20, 150, 160};
    for (int k = 0; k < 3; k++) {
        ts_rao_set(r, TS_DOF_HEAVE, 1, k, a180[k], p180[k] * D2R, &err);
        ts_rao_set(r, TS_DOF_HEAVE, 0, k, a120[k], p120[k] * D2R, &err);
    }
    ts_rao_finish(r, &err);
    double re[TS_NDOF], im[TS_NDOF];
    for (int k = 0; k < 3; k++) {
        ts_rao_eval(r, M_PI, w[k], re, im, &err);
        double complex z = re[2] + I * im[2];
        CHECK(fabs(cabs(z) - a180[k]) < 1e-15 &&
                  cabs(cexp(I * p180[k] * D2R) - z / cabs(z)) < 1e-14,
              "exact at row %d", k);
    }
    /* Between 0.5 and 0.8 the phase goes 170 -> 190 deg (the short way
     * through 180), the amplitude 0.8 -> 0.2 without overshoot. */
    int ok = 1;
    for (int i = 1; i < 20; i++) {
        ts_rao_eval(r, M_PI, 0.5 + 0.015 * i, re, im, &err);
        double complex z = re[2] + I * im[2];
        double ph = carg(z) * 180 / M_PI;
        ok &= cabs(z) < 0.8 && cabs(z) > 0.2 && (ph >= 170 || ph <= -170);
    }
    CHECK(ok, "phase through 180 deg the short way, amplitude within its "
          "rows (monotone interpolation)");
    ts_rao_eval(r, M_PI, 0.65, re, im, &err);
    double complex z = re[2] + I * im[2];
    CHECK(re[0] == 0 && im[0] == 0 && re[4] == 0 && im[4] == 0,
          "degrees of freedom not given are zero");
    CHECK(ts_rao_has_dof(r, TS_DOF_HEAVE) && !ts_rao_has_dof(r, TS_DOF_ROLL),
          "given degrees of freedom");
    /* Heading 150: halfway between the rows of 120 and 180, at 0.3. */
    ts_rao_eval(r, 150 * D2R, 0.3, re, im, &err);
    z = re[2] + I * im[2];
    CHECK_NEAR(cabs(z), 0.95, 1e-14, "amplitude linear in heading");
    CHECK_NEAR(carg(z), 15 * D2R, 1e-14, "phase linear in heading");
    /* Another turn of the same heading. */
    double re2[TS_NDOF], im2[TS_NDOF];
    ts_rao_eval(r, (150 - 360) * D2R, 0.3, re2, im2, &err);
    CHECK(fabs(re2[2] - re[2]) < 1e-14 && fabs(im2[2] - im[2]) < 1e-14,
          "heading - 360 deg is the same heading");
    ts_err e = {0};
    CHECK(ts_rao_eval(r, 90 * D2R, 0.3, re, im, &e) == TS_EDOMAIN &&
              strstr(e.msg, "120, 180"),
          "heading outside the table: %s", e.msg);
    CHECK(ts_rao_eval(r, M_PI, 0.9, re, im, &e) == TS_EDOMAIN &&
              strstr(e.msg, "0.3 to 0.8"),
          "frequency outside the table: %s", e.msg);
    CHECK(ts_rao_check_heading(r, 179.9999 * D2R, &e) == TS_OK,
          "heading inside");
    CHECK(ts_rao_set(r, 7, 0, 0, 1, 0, &e) == TS_EINVAL &&
              ts_rao_set(r, 0, 0, 0, -1, 0, &e) == TS_EINVAL,
          "bad set refused");
    ts_rao_free(r);
    const double nanh = NAN;
    r = ts_rao_alloc(1, &nanh, 3, w, &err);
    CHECK(r && ts_rao_eval(r, 0.123, 0.4, re, im, &e) == TS_EINVAL,
          "evaluation before ts_rao_finish refused: %s", e.msg);
    /* Rows linear in frequency: the cubic reproduces them exactly. */
    for (int k = 0; k < 3; k++)
        ts_rao_set(r, TS_DOF_SURGE, 0, k, 0.1 + 2 * w[k], 0.5 - w[k], &err);
    ts_rao_finish(r, &err);
    double worst = 0;
    for (int i = 0; i <= 50; i++) {
        double x = 0.3 + i * 0.01;
        ts_rao_eval(r, 0.123, x, re, im, &err);
        double complex want = (0.1 + 2 * x) * cexp(I * (0.5 - x));
        worst = fmax(worst, cabs(re[0] + I * im[0] - want));
    }
    CHECK(r && worst < 1e-14, "a table without headings serves any heading; "
          "linear rows interpolated exactly (max diff %.2g)", worst);
    ts_rao_free(r);
    /* Two rows: linear. */
    const double w2[2] = {0.4, 0.6};
    r = ts_rao_alloc(1, &nanh, 2, w2, &err);
    ts_rao_set(r, TS_DOF_HEAVE, 0, 0, 1.0, 0, &err);
    ts_rao_set(r, TS_DOF_HEAVE, 0, 1, 0.5, 0, &err);
    ts_rao_finish(r, &err);
    ts_rao_eval(r, 0, 0.45, re, im, &err);
    CHECK_NEAR(re[2], 0.875, 1e-15, "two rows: linear");
    ts_rao_free(r);
    const double wbad[2] = {0.5, 0.5};
    CHECK(!ts_rao_alloc(2, hd, 2, wbad, &e), "repeated frequency refused");
    const double hbad[2] = {0, 7};
    CHECK(!ts_rao_alloc(2, hbad, 3, w, &e) && strstr(e.msg, "one turn"),
          "headings beyond one turn refused: %s", e.msg);
}

/* Rodrigues: R(v) x for the rotation vector v. */
static void rotate(const double v[3], const double x[3], double out[3])
{
    double th = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (th == 0) {
        memcpy(out, x, 3 * sizeof(double));
        return;
    }
    double k[3] = {v[0] / th, v[1] / th, v[2] / th};
    double kx[3] = {k[1] * x[2] - k[2] * x[1], k[2] * x[0] - k[0] * x[2],
                    k[0] * x[1] - k[1] * x[0]};
    double kd = k[0] * x[0] + k[1] * x[1] + k[2] * x[2];
    for (int i = 0; i < 3; i++)
        out[i] = x[i] * cos(th) + kx[i] * sin(th) + k[i] * kd * (1 - cos(th));
}

static void test_tow_point(void)
{
    ts_err err = {0};
    const double hd = M_PI, w[2] = {0.4, 0.9};
    ts_rao *r = ts_rao_alloc(1, &hd, 2, w, &err);
    srand(7);
    double amp[TS_NDOF], ph[TS_NDOF];
    for (int d = 0; d < TS_NDOF; d++) {
        amp[d] = (d < 3 ? 1.0 : 0.05) * (0.2 + rand() / (double)RAND_MAX);
        ph[d] = 2 * M_PI * rand() / (double)RAND_MAX;
        for (int k = 0; k < 2; k++)
            ts_rao_set(r, d, 0, k, amp[d], ph[d], &err);
    }
    ts_rao_finish(r, &err);
    const double levers[3][3] = {{-31.7, 2.3, -6.1}, {12, -4.5, 3.3},
                                 {0, 0, 0}};
    double worst = 0;
    const double eps = 1e-7, omega = 0.61;
    for (int L = 0; L < 3; L++) {
        double tr[3], ti[3];
        ts_rao_tow_point(r, hd, 0.6, levers[L], tr, ti, &err);
        for (int it = 0; it < 7; it++) {
            double t = 0.37 + 1.9 * it;
            double complex e = cexp(I * omega * t);
            double x[TS_NDOF];
            for (int d = 0; d < TS_NDOF; d++)
                x[d] = creal(amp[d] * cexp(I * ph[d]) * e);
            double v[3] = {eps * x[3], eps * x[4], eps * x[5]}, rr[3];
            rotate(v, levers[L], rr);
            for (int c = 0; c < 3; c++) {
                double want = x[c] + (rr[c] - levers[L][c]) / eps;
                double got = creal((tr[c] + I * ti[c]) * e);
                worst = fmax(worst, fabs(got - want) / (1 + fabs(want)));
            }
        }
    }
    CHECK(worst <= 1e-6, "tow point = exact rotation of the lever arm, to "
          "first order (max rel diff %.2g)", worst);
    ts_rao_free(r);
    /* Senses. */
    r = ts_rao_alloc(1, &hd, 2, w, &err);
    const double starboard[3] = {0, 5, 0}, bow[3] = {20, 0, 0};
    double tr[3], ti[3];
    ts_rao_set(r, TS_DOF_ROLL, 0, 0, 0.1, 0, &err);
    ts_rao_set(r, TS_DOF_ROLL, 0, 1, 0.1, 0, &err);
    ts_rao_finish(r, &err);
    ts_rao_tow_point(r, hd, 0.5, starboard, tr, ti, &err);
    CHECK(tr[2] > 0, "roll > 0 lowers the starboard side (z down: %g)",
          tr[2]);
    ts_rao_set(r, TS_DOF_ROLL, 0, 0, 0, 0, &err);
    ts_rao_set(r, TS_DOF_ROLL, 0, 1, 0, 0, &err);
    ts_rao_set(r, TS_DOF_PITCH, 0, 0, 0.1, 0, &err);
    ts_rao_set(r, TS_DOF_PITCH, 0, 1, 0.1, 0, &err);
    ts_rao_finish(r, &err);
    ts_rao_tow_point(r, hd, 0.5, bow, tr, ti, &err);
    CHECK(tr[2] < 0, "pitch > 0 raises the bow (z: %g)", tr[2]);
    ts_rao_set(r, TS_DOF_PITCH, 0, 0, 0, 0, &err);
    ts_rao_set(r, TS_DOF_PITCH, 0, 1, 0, 0, &err);
    ts_rao_set(r, TS_DOF_YAW, 0, 0, 0.1, 0, &err);
    ts_rao_set(r, TS_DOF_YAW, 0, 1, 0.1, 0, &err);
    ts_rao_finish(r, &err);
    ts_rao_tow_point(r, hd, 0.5, bow, tr, ti, &err);
    CHECK(tr[1] > 0, "yaw > 0 turns the bow to starboard (y: %g)", tr[1]);
    ts_rao_free(r);
}

/* The reference table: heave and pitch (M axes, leads) at two headings,
 * three frequencies. */
static const double ref_w[3] = {0.35, 0.6, 1.1};
static const double ref_h[2] = {150, 180};
static const double ref_heave[2][3][2] = {{{0.95, 5}, {0.7, -20}, {0.2, -95}},
                                          {{0.98, 2}, {0.8, -30}, {0.1, -120}}};
static const double ref_pitch[2][3][2] = {
    {{1.1, 92}, {2.1, 60}, {0.3, -10}}, {{1.3, 95}, {2.6, 70}, {0.4, 5}}};

static ts_rao *reference(void)
{
    ts_err err = {0};
    double hd[2] = {ref_h[0] * D2R, ref_h[1] * D2R};
    ts_rao *r = ts_rao_alloc(2, hd, 3, ref_w, &err);
    for (int h = 0; h < 2; h++)
        for (int k = 0; k < 3; k++) {
            ts_rao_set(r, TS_DOF_HEAVE, h, k, ref_heave[h][k][0],
                       ref_heave[h][k][1] * D2R, &err);
            ts_rao_set(r, TS_DOF_PITCH, h, k, ref_pitch[h][k][0] * D2R,
                       ref_pitch[h][k][1] * D2R, &err);
        }
    ts_rao_finish(r, &err);
    return r;
}

/* The reference written as CSV: `zup` reverses heave and pitch, `lag`
 * negates phases, fkind 0 Hz, 1 rad/s, 2 period; rows shuffled. */
static char *reference_csv(int zup, int lag, int fkind)
{
    static char text[4096];
    static const char *const fcol[3] = {"frequency [Hz]", "omega [rad/s]",
                                        "period [s]"};
    int n = snprintf(text, sizeof text,
                     "# test table\naxes: %s\nphase: %s\n%s, heading [deg], "
                     "heave amp [m/m], heave phase [deg], pitch_amplitude "
                     "[deg/m], Pitch Phase [deg]\n",
                     zup ? "z-up" : "z-down", lag ? "lag" : "lead",
                     fcol[fkind]);
    static const int order[6][2] = {{1, 2}, {0, 0}, {1, 0}, {0, 2},
                                    {1, 1}, {0, 1}};
    for (int i = 0; i < 6; i++) {
        int h = order[i][0], k = order[i][1];
        double w = ref_w[k];
        double f = fkind == 0 ? w / (2 * M_PI) : fkind == 1 ? w
                                                           : 2 * M_PI / w;
        double hp = ref_heave[h][k][1] + (zup ? 180 : 0);
        double pp = ref_pitch[h][k][1] + (zup ? 180 : 0);
        if (lag) {
            hp = -hp;
            pp = -pp;
        }
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "%.17g, %g, %.17g, %.17g, %.17g, %.17g\n", f, ref_h[h],
                      ref_heave[h][k][0], hp, ref_pitch[h][k][0], pp);
    }
    return text;
}

static void test_csv(void)
{
    ts_rao *ref = reference();
    for (int v = 0; v < 4; v++) {
        int zup = v & 1, lag = (v >> 1) & 1, fkind = v % 3;
        char *path = tf_write_temp("test_rao", reference_csv(zup, lag, fkind));
        ts_err err = {0};
        ts_rao *r = ts_rao_read_csv(path, units, &err);
        if (CHECK(r, "CSV %s, %s, column %d: %s", zup ? "z-up" : "z-down",
                  lag ? "lag" : "lead", fkind, err.msg)) {
            double worst = 0;
            for (int i = 0; i <= 20; i++)
                for (int h = 0; h < 3; h++) {
                    double w = 0.35 + i * 0.0375, hd = (150 + 15 * h) * D2R;
                    double a[TS_NDOF], b[TS_NDOF], c[TS_NDOF], d[TS_NDOF];
                    ts_rao_eval(r, hd, w, a, b, &err);
                    ts_rao_eval(ref, hd, w, c, d, &err);
                    for (int j = 0; j < TS_NDOF; j++)
                        worst = fmax(worst, fabs(a[j] - c[j]) +
                                                fabs(b[j] - d[j]));
                }
            CHECK(worst <= 1e-12, "CSV equals the reference table (max "
                  "diff %.2g)", worst);
            int nh = ts_rao_headings(r, NULL, 0);
            CHECK(nh == 2 && ts_rao_has_dof(r, TS_DOF_PITCH) &&
                      !ts_rao_has_dof(r, TS_DOF_SURGE),
                  "headings and degrees of freedom read");
        }
        ts_rao_free(r);
        unlink(path);
    }
    ts_rao_free(ref);

    static const struct {
        const char *text, *expect;
    } bad[] = {
        {"phase: lead\nomega [rad/s], heave amp [m/m], heave phase [deg]\n"
         "0.5, 1, 0\n1, 1, 0\n", "must come before the header"},
        {"axes: z-down\nphase: early\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg]\n0.5, 1, 0\n", "phase: expected lead or lag"},
        {"axes: up\nphase: lead\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg]\n0.5, 1, 0\n", "axes: expected z-down"},
        {"axes: z-up\nphase: lead\nspeed: 3\nomega [rad/s], heave amp "
         "[m/m], heave phase [deg]\n0.5, 1, 0\n", "unknown property"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp [m/m]\n"
         "0.5, 1\n1, 1\n", "no phase column"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg], swell [m]\n0.5, 1, 0, 1\n", "unknown column"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp, heave phase "
         "[deg]\n0.5, 1, 0\n1, 1, 0\n", "give its unit"},
        {"axes: z-up\nphase: lead\nomega [rad/s], pitch amp [m/m], pitch "
         "phase [deg]\n0.5, 1, 0\n1, 1, 0\n", "pitch amp"},
        {"axes: z-up\nphase: lead\nheading [deg], heave amp [m/m], heave "
         "phase [deg]\n180, 1, 0\n", "no frequency column"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heading [deg], heave amp "
         "[m/m], heave phase [deg]\n0.5, 180, 1, 0\n1, 180, 1, 0\n"
         "0.5, 150, 1, 0\n0.9, 150, 1, 0\n", "same frequencies"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg]\n0.5, 1, 0\n0.5, 1, 0\n", "appears twice"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg]\n0.5, -1, 0\n1, 1, 0\n", "line 4"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg]\n0.5, 1, 0\n", "at least 2 frequencies"},
        {"axes: z-up\nphase: lead\nomega [rad/s]\n0.5\n1\n",
         "no RAO columns"},
        {"axes: z-up\nphase: lead\nomega [rad/s], heave amp [m/m], heave "
         "phase [deg]\n0.5, 1\n", "expected 3 numbers"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char *p = tf_write_temp("test_rao", bad[i].text);
        ts_err e = {0};
        ts_rao *x = ts_rao_read_csv(p, units, &e);
        CHECK(!x && strstr(e.msg, bad[i].expect) && strstr(e.msg, p),
              "CSV refused (%s): %s", bad[i].expect, e.msg);
        ts_rao_free(x);
        unlink(p);
    }
    ts_err e = {0};
    CHECK(!ts_rao_read_csv("/nonexistent/rao.csv", units, &e) &&
              e.code == TS_EIO,
          "missing file: TS_EIO");
}

int main(void)
{
    ts_err err = {0};
    units = ts_units_alloc(&err);
    if (!units) {
        printf("FAIL units: %s\n", err.msg);
        return 1;
    }
    test_interpolation();
    test_tow_point();
    test_csv();
    ts_units_free(units);
    return tc_done();
}
