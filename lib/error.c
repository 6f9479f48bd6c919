/* error.c: the caller-owned error record (see towstab/error.h).
 * Nothing here is global: the message lives in the caller's ts_err. */
#include "towstab/error.h"

#include <stdio.h>
#include <string.h>

void ts_err_clear(ts_err *err)
{
    if (!err)
        return;
    err->code = TS_OK;
    err->msg[0] = '\0';
}

int ts_fail(ts_err *err, int code, const char *fmt, ...)
{
    if (!err)
        return code;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    err->code = code;
    return code;
}

int ts_fail_nomem(ts_err *err, double bytes, const char *hint,
                  const char *fmt, ...)
{
    if (!err)
        return TS_ENOMEM;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    static const char *const unit[] = {"bytes", "kB", "MB", "GB", "TB",
                                       "PB"};
    int u = 0;
    double v = bytes;
    while (v >= 1000 && u < 5) {
        v /= 1000;
        u++;
    }
    size_t len = strlen(err->msg);
    snprintf(err->msg + len, sizeof err->msg - len, " (%.3g %s)%s%s", v,
             unit[u], hint ? "; " : "", hint ? hint : "");
    err->code = TS_ENOMEM;
    return TS_ENOMEM;
}

void ts_err_prefix(ts_err *err, const char *fmt, ...)
{
    if (!err)
        return;
    char old[TS_ERR_MSG_MAX];
    memcpy(old, err->msg, sizeof old);
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    if (n < 0)
        n = 0;
    if ((size_t)n < sizeof err->msg - 1) {
        size_t room = sizeof err->msg - 1 - (size_t)n;
        size_t len = strlen(old);
        /* A message cut to fit ends in "...". */
        int cut = len > room && room > 3;
        if (len > room)
            len = cut ? room - 3 : room;
        memcpy(err->msg + n, old, len);
        if (cut)
            memcpy(err->msg + n + len, "...", 3);
        err->msg[(size_t)n + len + (cut ? 3 : 0)] = '\0';
    }
}

const char *ts_strerror(int code)
{
    switch (code) {
    case TS_OK: return "ok";
    case TS_CHART: return "state outside the angle chart";
    case TS_EINVAL: return "invalid value";
    case TS_ENOMEM: return "out of memory";
    case TS_EIO: return "input/output error";
    case TS_ESCENE: return "malformed scene";
    case TS_EUNIT: return "wrong unit";
    case TS_ECONV: return "no convergence";
    case TS_ELAPACK: return "linear algebra failure";
    case TS_ESINGULAR: return "singular system";
    case TS_EDOMAIN: return "outside the model's domain";
    case TS_EINTEGRATOR: return "integrator failure";
    case TS_ECANCEL: return "stopped on request";
    default: return "unknown error";
    }
}
