/* Status codes and error messages shared by every kernel. */
#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>

core_status core_fail(core_error *err, core_status status, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->status = status;
    }
    return status;
}

void core_error_clear(core_error *err)
{
    err->status = CORE_OK;
    err->msg[0] = '\0';
}

const char *core_status_name(core_status status)
{
    switch (status) {
    case CORE_OK: return "ok";
    case CORE_ERR_ARG: return "invalid argument";
    case CORE_ERR_NOMEM: return "out of memory";
    case CORE_ERR_IO: return "input/output error";
    case CORE_ERR_STATE: return "invalid state";
    case CORE_ERR_UNSTABLE: return "unstable run";
    case CORE_ERR_INTERRUPTED: return "interrupted";
    }
    return "unknown status";
}
