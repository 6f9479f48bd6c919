/* towstab/error.h: error codes and the caller-owned error record.
 *
 * Every fallible function returns an int: TS_OK (0) on success, a negative
 * TS_E* code on failure, and a positive code for a recoverable condition
 * (the state left the model's chart; the caller may re-chart or retry).
 * It takes a `ts_err *` last; NULL is allowed and discards the message.
 * There is no global error state: the message lives in the caller's record.
 */
#ifndef TOWSTAB_ERROR_H
#define TOWSTAB_ERROR_H

#include <stdarg.h>

#if defined(TS_BUILDING_LIB) && defined(__GNUC__)
#define TS_API __attribute__((visibility("default")))
#else
#define TS_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

enum {
    TS_OK = 0,
    TS_CHART = 1,        /* a link approached cos(theta2) = 0: re-chart */
    TS_EINVAL = -1,      /* an argument or a scene value is out of range */
    TS_ENOMEM = -2,      /* allocation failed */
    TS_EIO = -3,         /* a file could not be read or written */
    TS_ESCENE = -4,      /* malformed scene file (syntax, keys, structure) */
    TS_EUNIT = -5,       /* a quantity has the wrong unit or dimension */
    TS_ECONV = -6,       /* an iterative solver did not converge */
    TS_ELAPACK = -7,     /* LAPACK or ARPACK reported a failure */
    TS_ESINGULAR = -8,   /* a singular system (zero mass, zero tension, ...) */
    TS_EDOMAIN = -9,     /* a request the model cannot represent */
    TS_EINTEGRATOR = -10, /* the time integrator failed */
    TS_ECANCEL = -11     /* stopped on request (towstab/progress.h) */
};

#define TS_ERR_MSG_MAX 1024

typedef struct ts_err {
    int code;                  /* last code recorded, TS_OK if none */
    char msg[TS_ERR_MSG_MAX];  /* "where: what was expected, what was found" */
} ts_err;

/* Reset an error record to TS_OK with an empty message. */
TS_API void ts_err_clear(ts_err *err);

/* Record an error and return `code`. The printf format names the place
 * first, then what was expected and what was found, e.g.
 *   return ts_fail(err, TS_EINVAL, "cables[%d].length: must be > 0 m, "
 *                  "got %g m", i, len);
 * Safe with err == NULL. */
TS_API int ts_fail(ts_err *err, int code, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Record TS_ENOMEM for an allocation of `bytes` bytes: the message is the
 * printf text (where, and what was being allocated), then the size
 * ("(2.9 GB)") and, when `hint` is not NULL, "; " and the hint (the
 * option or setting that reduces it). Returns TS_ENOMEM. */
TS_API int ts_fail_nomem(ts_err *err, double bytes, const char *hint,
                         const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Prepend context to an existing message ("scene x.yaml: " + msg); a
 * message that no longer fits TS_ERR_MSG_MAX is cut, ending in "...". */
TS_API void ts_err_prefix(ts_err *err, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* A short name for a code ("invalid value", "no convergence", ...). */
TS_API const char *ts_strerror(int code);

#ifdef __cplusplus
}
#endif
#endif
