/* test_units.c: quantities with units (towstab/units.h).
 *
 * References are independent of udunits: the exact definitions
 * 1 ft = 0.3048 m, 1 in = 0.0254 m, 1 lb = 0.45359237 kg,
 * 1 lbf = 1 lb * 9.80665 m/s^2, 1 knot = 1852 m / 3600 s,
 * 1 slug = 1 lbf s^2 / ft, 1 deg = pi/180 rad.
 * Every error path of ts_units_parse is provoked at least once. The small
 * unit system (the common units, built in memory) is checked against
 * udunits2's whole XML database: every word it reads, in three spellings,
 * against every SI unit, gives the same code and bit for bit the same
 * value or the same message. */
#include "towstab/units.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <ctype.h>
#include <stdio.h>
#include <udunits2.h>

#include "tcheck.h"
#include "units_impl.h"

#define FT 0.3048
#define INCH 0.0254
#define LB 0.45359237
#define G0 9.80665
#define LBF (LB * G0)
#define KNOT (1852.0 / 3600.0)
#define SLUG (LBF / FT)
#define DEG (M_PI / 180.0)

/* Conversions are exact up to a few rounding errors. */
#define RTOL 1e-14

static void test_conversions(const ts_units *u)
{
    static const struct {
        const char *text, *si;
        double want;
    } cases[] = {
        {"100 ft", "m", 100 * FT},
        {"10 in", "m", 10 * INCH},
        {"2.385 m", "m", 2.385},
        {"2.385 cm", "m", 0.02385},
        {"2.385 mm", "m", 0.002385},
        {"2.385 km", "m", 2385},
        {"50 lb", "kg", 50 * LB},
        {"2 lbs", "kg", 2 * LB},
        {"50 lbf", "N", 50 * LBF},
        {"1 lbf/ft", "N/m", LBF / FT},
        {"1 lb/ft", "kg/m", LB / FT},
        {"2.385 kg/m", "kg/m", 2.385},
        {"2.385 N/m", "N/m", 2.385},
        {"8.345 ft/s", "m/s", 8.345 * FT},
        {"5 knot", "m/s", 5 * KNOT},
        {"5 kn", "m/s", 5 * KNOT},
        {"5 kt", "m/s", 5 * KNOT},
        {"5 knots", "m/s", 5 * KNOT},
        {"5 kts", "m/s", 5 * KNOT},
        {"2.385 m/s", "m/s", 2.385},
        {"0.5 rad/s", "rad/s", 0.5},
        {"28.65 deg/s", "rad/s", 28.65 * DEG},
        {"28.65 degree/s", "rad/s", 28.65 * DEG},
        {"1.2 rad", "rad", 1.2},
        {"30 deg", "rad", 30 * DEG},
        {"0.25 Hz", "Hz", 0.25},
        {"2 1/s", "Hz", 2},
        {"1.6 s", "s", 1.6},
        {"1025 kg/m^3", "kg/m^3", 1025},
        {"1.9905 slug/ft^3", "kg/m^3", 1.9905 * SLUG / (FT * FT * FT)},
        {"2.385 N", "N", 2.385},
        {"2.385 kN", "N", 2385},
        {"2.385 N*m^2", "N*m^2", 2.385},
        {"1 lbf*ft^2", "N*m^2", LBF * FT * FT},
        {"9.80665 m/s^2", "m/s^2", G0},
        {"32.174 ft/s^2", "m/s^2", 32.174 * FT},
        {"1 nmi", "m", 1852},
        {"60 mph", "m/s", 60 * 1609.344 / 3600},
        /* Bare numbers are SI; spacing and exponents are free. */
        {"2.385", "m", 2.385},
        {"-3.5e-2", "m/s", -0.035},
        {"+7", "N", 7},
        {".5", "1", 0.5},
        {"  7 mm  ", "m", 0.007},
        {"100ft", "m", 100 * FT},
        {"1e3 mm", "m", 1},
        {"5 %", "1", 0.05},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        ts_err err;
        ts_err_clear(&err);
        double v = NAN;
        int rc = ts_units_parse(u, cases[i].text, cases[i].si, "q", &v, &err);
        CHECK(rc == TS_OK, "\"%s\" -> %s accepted (%s)", cases[i].text,
              cases[i].si, err.msg);
        char name[96];
        snprintf(name, sizeof name, "\"%s\" in %s", cases[i].text,
                 cases[i].si);
        CHECK_REL(v, cases[i].want, RTOL, name);
    }
    /* The reference values, to their printed digits. */
    double v;
    ts_units_parse(u, "1 lbf/ft", "N/m", "q", &v, NULL);
    CHECK_NEAR(v, 14.5939029372, 1e-10, "1 lbf/ft = 14.5939029372 N/m");
    ts_units_parse(u, "5 knot", "m/s", "q", &v, NULL);
    CHECK_NEAR(v, 2.57222, 1e-5, "5 knot = 2.57222 m/s");
    ts_units_parse(u, "100 ft", "m", "q", &v, NULL);
    CHECK(v == 30.48, "100 ft is exactly 30.48 m (got %.17g)", v);
}

/* One refused input: its code and the pieces its message must contain. */
static void refused(const ts_units *u, const char *text, const char *si,
                    int code, const char *part1, const char *part2)
{
    ts_err err;
    ts_err_clear(&err);
    double v = 2.385;
    int rc = ts_units_parse(u, text, si, "cables[0].weight (line 9)", &v,
                            &err);
    CHECK(rc == code && err.code == code, "\"%s\" as %s refused with %d "
          "(got %d)", text ? text : "(null)", si, code, rc);
    CHECK(v == 2.385, "\"%s\": the value is untouched", text ? text : "");
    CHECK(strncmp(err.msg, "cables[0].weight (line 9): ", 27) == 0,
          "\"%s\": message starts with where: %s", text ? text : "", err.msg);
    if (part1)
        CHECK(strstr(err.msg, part1) != NULL, "message has '%s'", part1);
    if (part2)
        CHECK(strstr(err.msg, part2) != NULL, "message has '%s'", part2);
    /* The same with a NULL error record. */
    rc = ts_units_parse(u, text, si, "x", &v, NULL);
    CHECK(rc == code, "\"%s\": same code with err == NULL", text ? text : "");
}

static void test_wrong_dimensions(const ts_units *u)
{
    refused(u, "50 lb", "N", TS_EUNIT,
            "\"50 lb\" is a mass (kg), expected a force (N)",
            "write \"50 lbf\", or give it as a mass");
    refused(u, "1 lb/ft", "N/m", TS_EUNIT,
            "is a mass per length (kg/m), expected a force per length (N/m)",
            "\"1 lbf/ft\"");
    refused(u, "2 kg/m", "N/m", TS_EUNIT, "mass per length", "\"2 kgf/m\"");
    refused(u, "50 lbf", "kg", TS_EUNIT,
            "is a force (N), expected a mass (kg)", "\"50 lb\"");
    refused(u, "1 lbf/ft", "kg/m", TS_EUNIT, "expected a mass per length",
            "\"1 lb/ft\"");
    refused(u, "3 ft", "m/s", TS_EUNIT,
            "is a length (m), expected a speed (m/s)", NULL);
    refused(u, "3 ft/s", "m", TS_EUNIT, "is a speed (m/s)", "a length (m)");
    refused(u, "3 N", "N*m^2", TS_EUNIT, "a force (N)", "bending stiffness");
    refused(u, "1 kg*m", "N", TS_EUNIT, "a quantity in m.kg", NULL);
    refused(u, "9 ft/s^2", "kg/m^3", TS_EUNIT, "an acceleration",
            "a density (kg/m^3)");
    /* Radians: udunits calls them dimensionless, we do not. */
    refused(u, "0.5 Hz", "rad/s", TS_EUNIT, "a frequency (Hz)",
            "expected an angular rate (rad/s)");
    refused(u, "0.5 rad/s", "Hz", TS_EUNIT, "an angular rate", "frequency");
    refused(u, "3 m/m", "rad", TS_EUNIT, "a plain number", "an angle (rad)");
    /* Reciprocal units: udunits converts 5 s to 0.2 Hz, we refuse. */
    refused(u, "5 s", "Hz", TS_EUNIT, "a time (s)", "a frequency (Hz)");
    refused(u, "2 m", "1/m", TS_EUNIT, "a length (m)", NULL);
    /* Offsets. */
    refused(u, "20 degC", "K", TS_EUNIT, "offset", NULL);
    /* Unknown units. */
    refused(u, "30 fathoms_deep", "m", TS_EUNIT, "unknown unit "
            "\"fathoms_deep\"", "expected a length (m)");
    refused(u, "3 m\xc2\xb2", "m^2", TS_EUNIT, "not printable ASCII",
            "\\xc2\\xb2");
}

static void test_garbage(const ts_units *u)
{
    refused(u, "", "m", TS_EINVAL, "empty value", "a length (m)");
    refused(u, "   ", "m", TS_EINVAL, "empty value", NULL);
    refused(u, NULL, "m", TS_EINVAL, "no value", NULL);
    refused(u, "ft", "m", TS_EINVAL, "\"ft\" does not start with a number",
            NULL);
    refused(u, "abc", "m", TS_EINVAL, "does not start with a number", NULL);
    refused(u, "nan", "m", TS_EINVAL, "not a finite number", NULL);
    refused(u, ".nan", "m", TS_EINVAL, "\".nan\" is not a finite number",
            NULL);
    refused(u, "NaN m", "m", TS_EINVAL, "not a finite number", NULL);
    refused(u, "inf", "m", TS_EINVAL, "not a finite number", NULL);
    refused(u, "-inf", "m", TS_EINVAL, "not a finite number", NULL);
    refused(u, ".inf", "m", TS_EINVAL, "not a finite number", NULL);
    refused(u, "Infinity", "m", TS_EINVAL, "not a finite number", NULL);
    refused(u, "1e999", "m", TS_EINVAL, "out of the range", NULL);
    refused(u, "1e308 km", "m", TS_EINVAL, "out of the range", NULL);
    refused(u, "0x10", "m", TS_EINVAL, "not a decimal number", NULL);
    refused(u, "12 ft 3", "m", TS_EINVAL, "unexpected number \"3\"", NULL);
    refused(u, "1.2.3", "m", TS_EINVAL, "unexpected number", NULL);
    refused(u, "12 m )", "m", TS_EINVAL, "parentheses", "do not pair up");
    /* udunits alone reads a trailing ')' as nothing: "1 ft)" would pass. */
    refused(u, "1 ft)", "m", TS_EINVAL, "parentheses", "\"1 ft)\"");
    refused(u, "1 (ft", "m", TS_EINVAL, "parentheses", NULL);
    refused(u, "5 ft//s", "m/s", TS_EINVAL, "not a unit expression", NULL);
    refused(u, "--1", "m", TS_EINVAL, "does not start with a number", NULL);

    /* An SI unit the caller should never pass. */
    ts_err err;
    double v;
    int rc = ts_units_parse(u, "1", "furlongz", "x", &v, &err);
    CHECK(rc == TS_EINVAL && strstr(err.msg, "unknown SI unit"),
          "a bad SI unit from the caller is TS_EINVAL: %s", err.msg);
    rc = ts_units_parse(NULL, "1", "m", "x", &v, &err);
    CHECK(rc == TS_EINVAL, "NULL unit system refused: %s", err.msg);
    /* Very long text is quoted shortened, not copied whole. */
    char longtext[4000];
    memset(longtext, 'q', sizeof longtext - 1);
    longtext[sizeof longtext - 1] = '\0';
    longtext[0] = '1';
    longtext[1] = ' ';
    rc = ts_units_parse(u, longtext, "m", "x", &v, &err);
    CHECK(rc == TS_EUNIT && strlen(err.msg) < 400 && strstr(err.msg, "..."),
          "a 4000-character unit is refused briefly (%zu chars)",
          strlen(err.msg));
}

static void test_from_si(const ts_units *u)
{
    static const struct {
        const char *text, *si, *unit;
    } trips[] = {
        {"12.5 ft", "m", "ft"},
        {"3 knot", "m/s", "knot"},
        {"2.385 lbf/ft", "N/m", "lbf/ft"},
        {"28.65 deg/s", "rad/s", "deg/s"},
        {"50 lbf", "N", "lbf"},
        {"1.9905 slug/ft^3", "kg/m^3", "slug/ft^3"},
    };
    for (size_t i = 0; i < sizeof trips / sizeof trips[0]; i++) {
        double si = NAN, back = NAN, number = strtod(trips[i].text, NULL);
        ts_err err;
        int rc = ts_units_parse(u, trips[i].text, trips[i].si, "q", &si, &err);
        rc = rc ? rc : ts_units_from_si(u, si, trips[i].si, trips[i].unit,
                                        &back, &err);
        CHECK(rc == TS_OK, "round trip of \"%s\" ok", trips[i].text);
        char name[64];
        snprintf(name, sizeof name, "round trip \"%s\"", trips[i].text);
        CHECK_REL(back, number, RTOL, name);
    }
    double out = 2.385;
    ts_err err;
    int rc = ts_units_from_si(u, 30.48, "m", "ft", &out, &err);
    CHECK(rc == TS_OK, "30.48 m to ft");
    CHECK_REL(out, 100, RTOL, "30.48 m = 100 ft");
    out = 2.385;
    rc = ts_units_from_si(u, 3, "m", "lbf", &out, &err);
    CHECK(rc == TS_EUNIT && out == 2.385 && strstr(err.msg, "a length (m)") &&
          strstr(err.msg, "a force (N)"), "m to lbf refused: %s", err.msg);
    rc = ts_units_from_si(u, 1, "rad/s", "Hz", &out, &err);
    CHECK(rc == TS_EUNIT, "rad/s to Hz refused: %s", err.msg);
    rc = ts_units_from_si(u, 1, "m", "furlongz", &out, &err);
    CHECK(rc == TS_EUNIT && strstr(err.msg, "furlongz"),
          "unknown unit refused: %s", err.msg);
}

/* Display units: presets with the exact definitions above, items from
 * udunits against the same definitions, a value shown and read back
 * (a round trip to 1e-15), ratios and degrees, names for CSV columns,
 * and every refusal. */
static void test_display(const ts_units *u)
{
    ts_err err = {0};
    ts_display d;
    ts_display_si(&d);
    CHECK(!strcmp(ts_display_unit(&d, TS_QTY_LENGTH), "m") &&
              ts_display_value(&d, TS_QTY_FORCE, 2.385) == 2.385 &&
              !strcmp(ts_display_unit(&d, TS_QTY_ANGLE), "deg"),
          "SI shows m, N as they are and angles in deg");
    CHECK_REL(ts_display_value(&d, TS_QTY_ANGLE, M_PI / 4), 45.0, RTOL,
              "SI: pi/4 rad shown as 45 deg");
    CHECK(ts_display_parse(u, "imperial", "--units", &d, &err) == TS_OK,
          "imperial parses (%s)", err.msg);
    CHECK_REL(ts_display_value(&d, TS_QTY_LENGTH, 30.48), 100.0, RTOL,
              "imperial: 30.48 m is 100 ft");
    CHECK_REL(ts_display_value(&d, TS_QTY_FORCE, 4.4482216152605), 1.0,
              RTOL, "imperial: 4.4482216152605 N is 1 lbf");
    CHECK_REL(ts_display_value(&d, TS_QTY_SPEED, 5 * KNOT), 5.0, RTOL,
              "imperial: 5 knot");
    CHECK_REL(ts_display_value(&d, TS_QTY_MASS, 50 * LB), 50.0, RTOL,
              "imperial: 50 lb");
    CHECK(!strcmp(ts_display_unit(&d, TS_QTY_ANGULAR_RATE), "rad/s") &&
              !strcmp(ts_display_unit(&d, TS_QTY_TIME), "s"),
          "imperial keeps rad/s and s");
    /* Items from udunits against the definitions. */
    CHECK(ts_display_parse(u, "imperial, force=kN,turn_rate=deg/s ,"
                              "length=in", "--units", &d, &err) == TS_OK,
          "items after a preset parse (%s)", err.msg);
    CHECK_REL(ts_display_value(&d, TS_QTY_FORCE, 2385.0), 2.385, RTOL,
              "force=kN: 2385 N is 2.385 kN");
    CHECK_REL(ts_display_value(&d, TS_QTY_ANGULAR_RATE, 0.5), 0.5 / DEG,
              RTOL, "turn_rate=deg/s: 0.5 rad/s");
    CHECK_REL(ts_display_value(&d, TS_QTY_LENGTH, 1.0), 1.0 / INCH, RTOL,
              "length=in: 1 m");
    CHECK(!strcmp(ts_display_unit(&d, TS_QTY_SPEED), "knot"),
          "the preset's speed stays knot");
    /* A round trip: shown, then read back through the parser. */
    double shown = ts_display_value(&d, TS_QTY_LENGTH, 12.3456789), back;
    char text[64];
    snprintf(text, sizeof text, "%.17g %s", shown,
             ts_display_unit(&d, TS_QTY_LENGTH));
    CHECK(ts_units_parse(u, text, "m", "round trip", &back, &err) == TS_OK,
          "'%s' reads back (%s)", text, err.msg);
    CHECK_REL(back, 12.3456789, 1e-15, "length shown in inches and read back");
    /* Ratios, degrees and names. */
    char unit[64], tok[64];
    ts_display_parse(u, "imperial", "--units", &d, &err);
    CHECK_REL(ts_display_convert(&d, "N/m", 1.0, unit, sizeof unit),
              FT / LBF, RTOL, "N/m shown in lbf/ft");
    CHECK(!strcmp(unit, "lbf/ft"), "its unit: %s", unit);
    CHECK(ts_display_convert(&d, "m/m", 0.25, unit, sizeof unit) == 0.25 &&
              !strcmp(unit, "m/m"),
          "m/m stays as it is");
    CHECK_REL(ts_display_convert(&d, "1/m", 1.0, unit, sizeof unit), FT, RTOL,
              "1/m shown in 1/ft");
    CHECK(ts_display_convert(&d, "1/s", 3.0, unit, sizeof unit) == 3.0 &&
              !strcmp(unit, "1/s"),
          "1/s stays");
    ts_display_parse(u, "angle=rad", "--units", &d, &err);
    CHECK_REL(ts_display_convert(&d, "deg", 90.0, unit, sizeof unit),
              M_PI / 2, RTOL, "a value in deg shown in rad");
    ts_display_unit_token("lbf/ft", tok, sizeof tok);
    CHECK(!strcmp(tok, "lbf_per_ft"), "lbf/ft as a name: %s", tok);
    ts_display_unit_token("m/s^2", tok, sizeof tok);
    CHECK(!strcmp(tok, "m_per_s2"), "m/s^2 as a name: %s", tok);
    /* Refusals, d left SI. */
    static const struct {
        const char *spec;
        int code;
        const char *part;
    } bad[] = {{"furlong", TS_EINVAL, "expected si, imperial"},
               {"weight=kg", TS_EINVAL, "unknown quantity 'weight'"},
               {"force=kg", TS_EUNIT, "not a unit of N"},
               {"length=", TS_EINVAL, "expected a unit of m"},
               {"length=parsec^2", TS_EUNIT, "not a unit of m"},
               {"si,", TS_EINVAL, "expected si"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        ts_err_clear(&err);
        int rc = ts_display_parse(u, bad[k].spec, "--units", &d, &err);
        CHECK(rc == bad[k].code && strstr(err.msg, "--units") &&
                  strstr(err.msg, bad[k].part) &&
                  !strcmp(ts_display_unit(&d, TS_QTY_LENGTH), "m"),
              "'%s' refused: %s", bad[k].spec, err.msg);
    }
}


/* The SI units the checks convert to: each dimension the library asks
 * for, and a few that no word has. */
static const char *const si_targets[] = {
    "m", "kg", "s", "N", "m/s", "m/s^2", "N/m", "kg/m", "rad", "rad/s",
    "Hz", "kg/m^3", "Pa", "W", "N*m", "K", "1", "N*s^2/m", "m^2"};

/* One conversion of `text` to `si` with `u`, in the small system (path
 * NULL) or in the whole database at `path`: code, value and message. */
static int convert(const ts_units *u, const char *path, const char *text,
                   const char *si, double *v, ts_err *err)
{
    if (path)
        setenv("UDUNITS2_XML_PATH", path, 1);
    ts_err_clear(err);
    *v = NAN;
    int rc = ts_units_parse(u, text, si, "x", v, err);
    if (path)
        unsetenv("UDUNITS2_XML_PATH");
    return rc;
}

/* 0 when `text` converts the same to every SI target in both systems;
 * the number of differences otherwise (each one reported). */
static int same_in_both(const ts_units *u, const char *full_path,
                        const char *text)
{
    int differ = 0;
    for (size_t t = 0; t < sizeof si_targets / sizeof si_targets[0]; t++) {
        ts_err es, ef;
        double vs, vf;
        int rs = convert(u, NULL, text, si_targets[t], &vs, &es);
        int rf = convert(u, full_path, text, si_targets[t], &vf, &ef);
        int same = rs == rf && (rs == TS_OK ? memcmp(&vs, &vf, sizeof vs) == 0
                                            : !strcmp(es.msg, ef.msg));
        if (!same) {
            differ++;
            CHECK(0, "\"%s\" as %s: small system %d %.17g (%s), whole "
                  "database %d %.17g (%s)", text, si_targets[t], rs, vs,
                  es.msg, rf, vf, ef.msg);
        }
    }
    return differ;
}

static void test_small_system(void)
{
    ut_status st;
    const char *full_path = ut_get_path_xml(NULL, &st);
    ts_err err;
    ts_err_clear(&err);
    ts_units *u = ts_units_alloc(&err);
    if (!CHECK(u && full_path, "a second unit converter and the database's "
               "path: %s", err.msg)) {
        ts_units_free(u);
        return;
    }
    int small, full;
    tsi_units_made(u, &small, &full);
    CHECK(!small && !full, "a new converter has made no unit system");
    double v;
    int rc = ts_units_parse(u, " 12.5 ", "m", "x", &v, &err);
    tsi_units_made(u, &small, &full);
    CHECK(rc == TS_OK && v == 12.5 && !small && !full,
          "a bare number is read without a unit system (%d, %g)", rc, v);
    rc = ts_units_parse(u, "8.345 ft/s", "m/s", "x", &v, &err);
    tsi_units_made(u, &small, &full);
    CHECK(rc == TS_OK && fabs(v - 8.345 * FT) <= RTOL * v && small && !full,
          "\"8.345 ft/s\" is read in the small system only (%d, %.17g)", rc,
          v);
    rc = ts_units_parse(u, "1 furlong", "m", "x", &v, &err);
    tsi_units_made(u, &small, &full);
    /* udunits2's furlong is 660 US survey feet of 1200/3937 m. */
    CHECK(rc == TS_OK && fabs(v - 660 * 1200.0 / 3937) <= RTOL * v && full,
          "\"1 furlong\", not in the small system, is read in the whole "
          "database (%d, %.17g m)", rc, v);

    /* Every word, as written, in capitals and capitalised, alone; as
     * written also squared and in a quotient. */
    int words = 0, differ = 0;
    for (size_t i = 0; tsi_units_small_word(i); i++, words++) {
        const char *w = tsi_units_small_word(i);
        char upper[64], cap[64], text[160];
        size_t n = strlen(w);
        if (n >= sizeof upper)
            continue;
        for (size_t k = 0; k <= n; k++) {
            upper[k] = (char)toupper((unsigned char)w[k]);
            cap[k] = k == 0 ? upper[0] : w[k];
        }
        const char *spell[] = {w, upper, cap};
        for (int k = 0; k < 3; k++) {
            static const char *const form[] = {"2.5 %s", "2.5 %s^2",
                                               "2.5 %s/s", "2.5 m/%s"};
            for (int f = 0; f < (k == 0 ? 4 : 1); f++) {
                snprintf(text, sizeof text, form[f], spell[k]);
                differ += same_in_both(u, full_path, text);
            }
        }
    }
    /* The documented compound units and the messages of a few wrong
     * ones (doc/scene-format.md, "Quantities and units"). */
    static const char *const compound[] = {
        "1 lbf*s^2/ft", "1 slug/ft^3", "1 ft/s^2", "1 N*m^2", "1 lbf*ft^2",
        "1 deg/s", "1 degree/s", "1 rpm", "1 m2", "1 s-1", "1 1/min",
        "1 kg.m/s2", "1 lbf ft^2", "1.5 kN/m", "3 MPa", "1 hr", "50 lb",
        "1 lb/ft", "0.1 Hz", "5 s", "2 ft//s", "1 ft)", "1 m m", "1 kgf",
        "1 mph", "1 nmi/h", "1 km/hr", "1 in^3", "1 g/cm^3", "1 kW",
        "1 %", "1 '", "2 s since 2000-01-01", "1 degC", "1 K"};
    for (size_t i = 0; i < sizeof compound / sizeof compound[0]; i++)
        differ += same_in_both(u, full_path, compound[i]);
    CHECK(words > 80 && differ == 0,
          "the small system's %d words (3 spellings alone, 4 forms as "
          "written; %zu SI "
          "units) and %zu compound units convert as in the whole database, "
          "values bit for bit, messages the same (%d differences)", words,
          sizeof si_targets / sizeof si_targets[0],
          sizeof compound / sizeof compound[0], differ);
    ts_units_free(u);

    /* A database that cannot be read is reported by the conversion that
     * needs it; a bare number needs none. */
    ts_units *bad = ts_units_alloc(&err);
    setenv("UDUNITS2_XML_PATH", "/nonexistent/udunits2.xml", 1);
    rc = ts_units_parse(bad, "3", "m", "x", &v, &err);
    CHECK(rc == TS_OK && v == 3, "an unreadable database: a bare number is "
          "still read (%d)", rc);
    rc = ts_units_parse(bad, "3 ft", "m", "x", &v, &err);
    unsetenv("UDUNITS2_XML_PATH");
    CHECK(rc != TS_OK && strstr(err.msg, "cannot read the udunits2 database")
              && strstr(err.msg, "/nonexistent/udunits2.xml"),
          "an unreadable database: a unit is refused naming it (%d: %s)", rc,
          err.msg);
    ts_units_free(bad);
}

int main(void)
{
    ts_err err;
    ts_err_clear(&err);
    ts_units *u = ts_units_alloc(&err);
    if (!CHECK(u != NULL, "ts_units_alloc: %s", err.msg))
        return tc_done();
    test_conversions(u);
    test_wrong_dimensions(u);
    test_garbage(u);
    test_from_si(u);
    test_display(u);
    ts_units_free(u);
    test_small_system();
    ts_units_free(NULL);
    CHECK(1, "ts_units_free(NULL) does nothing");
    return tc_done();
}
