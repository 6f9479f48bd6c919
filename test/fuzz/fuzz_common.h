/* fuzz_common.h: what both fuzz harnesses share.
 *
 * The harnesses are test code, not library code: they keep one unit
 * system in a static (loading the udunits XML database costs ~20 ms, far
 * more than one input), and they abort() on a broken invariant so that
 * libFuzzer (or test/fuzz/replay.c) reports the input that broke it.
 *
 * Invariants checked on every input, whatever the outcome:
 *   - the result and the error record agree: TS_OK with an empty record,
 *     or a negative code equal to err.code with a non-empty message;
 *   - the message is one line of printable text: no control bytes (user
 *     text must reach a message escaped, never raw);
 *   - the message is NUL-terminated within TS_ERR_MSG_MAX.
 * AddressSanitizer and UndefinedBehaviorSanitizer, when compiled in,
 * check memory and arithmetic on every path the input reaches. */
#ifndef TOWSTAB_FUZZ_COMMON_H
#define TOWSTAB_FUZZ_COMMON_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "towstab/error.h"
#include "towstab/units.h"

/* The libFuzzer entry point, defined by each harness. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Set by each harness: 1 when the last input was accepted, 0 when it was
 * refused with a message. Read by test/fuzz/replay.c (corpus files named
 * good_* must be accepted, bad_* refused); libFuzzer ignores it. */
extern int fuzz_accepted;

/* Abort with a message naming the broken invariant. */
#define FUZZ_REQUIRE(cond, ...)                                               \
    do {                                                                      \
        if (!(cond)) {                                                        \
            fprintf(stderr, "fuzz invariant broken at %s:%d: %s\n  ",         \
                    __FILE__, __LINE__, #cond);                               \
            fprintf(stderr, __VA_ARGS__);                                     \
            fputc('\n', stderr);                                              \
            abort();                                                          \
        }                                                                     \
    } while (0)

/* The unit system, loaded on first use and kept for the whole run. */
static const ts_units *fuzz_units(void)
{
    static ts_units *units;
    if (!units) {
        ts_err err;
        ts_err_clear(&err);
        units = ts_units_alloc(&err);
        FUZZ_REQUIRE(units != NULL, "cannot load the unit database: %s",
                     err.msg);
    }
    return units;
}

/* The invariants above for a call that returned rc with record err. */
static void fuzz_check_error(int rc, const ts_err *err)
{
    size_t len = strnlen(err->msg, sizeof err->msg);
    FUZZ_REQUIRE(len < sizeof err->msg, "error message not terminated");
    if (rc == TS_OK) {
        FUZZ_REQUIRE(err->code == TS_OK && len == 0,
                     "success left an error record (code %d, \"%s\")",
                     err->code, err->msg);
        return;
    }
    FUZZ_REQUIRE(rc < 0, "unexpected positive code %d (\"%s\")", rc,
                 err->msg);
    FUZZ_REQUIRE(err->code == rc, "returned %d but recorded %d (\"%s\")", rc,
                 err->code, err->msg);
    FUZZ_REQUIRE(len > 0, "failure %d without a message", rc);
    for (size_t i = 0; i < len; i++)
        FUZZ_REQUIRE((unsigned char)err->msg[i] >= 0x20 &&
                     (unsigned char)err->msg[i] != 0x7f,
                     "control byte 0x%02x at offset %zu of the message "
                     "\"%s\"", (unsigned char)err->msg[i], i, err->msg);
}

#endif
