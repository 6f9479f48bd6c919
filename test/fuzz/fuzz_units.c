/* fuzz_units.c: libFuzzer target for the quantity parser (towstab/units.h).
 *
 * Input layout: byte 0 chooses the SI unit the caller expects (one of the
 * units the scene reader and the command line ask for: byte 0 modulo 14),
 * and its top bit also sends the text, as a unit name, through
 * ts_units_from_si(); bytes 1.. are the quantity text, copied into a
 * buffer of exactly that many bytes plus the NUL (so AddressSanitizer
 * catches a read past the terminator). An embedded NUL simply ends the
 * text early, as it would for any C caller.
 *
 * Checked on every input (besides the sanitizers): the common invariants
 * of fuzz_common.h; a refusal's message starts with the `where` text;
 * TS_OK gives a finite value; the same text parsed twice gives the same
 * code and bit-identical value (udunits keeps process-wide parser state:
 * a leftover from the previous call must not change the next result);
 * from_si of the SI unit to itself is the identity. */
#include <math.h>

#include "fuzz_common.h"

#define WHERE "fuzz.quantity (line 1)"

static const char *const si_units[] = {
    "m",     "kg",     "N",     "N/m", "kg/m", "m/s", "rad/s",
    "kg/m^3", "m/s^2", "N*m^2", "s",   "Hz",   "rad", "1",
};
#define NSI (sizeof si_units / sizeof si_units[0])

int fuzz_accepted;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_accepted = 0;
    if (size < 1)
        return 0;
    const ts_units *units = fuzz_units();
    const char *si = si_units[data[0] % NSI];
    int also_from_si = (data[0] & 0x80) != 0;
    char *text = malloc(size);
    FUZZ_REQUIRE(text != NULL, "out of memory for %zu bytes", size);
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0';

    ts_err err;
    ts_err_clear(&err);
    double value = NAN;
    int rc = ts_units_parse(units, text, si, WHERE, &value, &err);
    fuzz_check_error(rc, &err);
    fuzz_accepted = rc == TS_OK;
    if (rc == TS_OK) {
        FUZZ_REQUIRE(isfinite(value), "accepted %s as %s but got %g", text,
                     si, value);
    } else {
        FUZZ_REQUIRE(rc == TS_EINVAL || rc == TS_EUNIT,
                     "code %d outside the documented TS_EINVAL/TS_EUNIT "
                     "(\"%s\")", rc, err.msg);
        FUZZ_REQUIRE(!strncmp(err.msg, WHERE ": ", strlen(WHERE ": ")),
                     "message does not start with where: \"%s\"", err.msg);
    }

    /* The same call again must give the same answer. */
    ts_err err2;
    ts_err_clear(&err2);
    double value2 = NAN;
    int rc2 = ts_units_parse(units, text, si, WHERE, &value2, &err2);
    FUZZ_REQUIRE(rc2 == rc && !strcmp(err2.msg, err.msg) &&
                 (rc != TS_OK || memcmp(&value, &value2, sizeof value) == 0),
                 "second parse differs: %d \"%s\" %.17g vs %d \"%s\" %.17g",
                 rc, err.msg, value, rc2, err2.msg, value2);

    if (rc == TS_OK) {
        /* SI to SI is the identity (the converter of a unit to itself). */
        double same = NAN;
        ts_err_clear(&err2);
        int rc3 = ts_units_from_si(units, value, si, si, &same, &err2);
        fuzz_check_error(rc3, &err2);
        FUZZ_REQUIRE(rc3 == TS_OK && same == value,
                     "from_si(%s -> %s) of %.17g gave %.17g (%s)", si, si,
                     value, same, err2.msg);
    }
    if (also_from_si) {
        /* The text as a target unit: any result, but a clean one. */
        double out = NAN;
        ts_err_clear(&err2);
        int rc4 = ts_units_from_si(units, 1.0, si, text, &out, &err2);
        fuzz_check_error(rc4, &err2);
        if (rc4 != TS_OK)
            FUZZ_REQUIRE(rc4 == TS_EUNIT || rc4 == TS_EINVAL,
                         "from_si code %d (\"%s\")", rc4, err2.msg);
    }
    free(text);
    return 0;
}
