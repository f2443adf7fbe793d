#include "common/status.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

gr_status gr_fail(gr_error *err, gr_status st, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        err->status = st;
    }
    return st;
}

gr_status gr_error_prefix(gr_error *err, const char *fmt, ...)
{
    if (!err) return GR_E_RUNTIME;
    char prefix[GR_ERROR_MSG_MAX], old[GR_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    memcpy(old, err->msg, sizeof old);
    /* "prefix: old", truncated to fit */
    size_t np = strlen(prefix), no = strlen(old), cap = sizeof err->msg - 1;
    if (np > cap) np = cap;
    memcpy(err->msg, prefix, np);
    size_t n = np;
    if (n + 2 <= cap) { err->msg[n++] = ':'; err->msg[n++] = ' '; }
    if (no > cap - n) no = cap - n;
    memcpy(err->msg + n, old, no);
    err->msg[n + no] = '\0';
    return err->status;
}

const char *gr_status_name(gr_status st)
{
    switch (st) {
    case GR_OK: return "ok";
    case GR_E_USAGE: return "usage error";
    case GR_E_INPUT: return "bad input";
    case GR_E_IO: return "I/O error";
    case GR_E_RUNTIME: return "runtime error";
    case GR_E_NOMEM: return "out of memory";
    case GR_E_GL: return "OpenGL error";
    case GR_E_EMBREE: return "Embree error";
    case GR_E_INTERRUPTED: return "interrupted";
    }
    return "unknown error";
}

int gr_status_exit_code(gr_status st)
{
    if (st == GR_OK) return 0;
    if (st == GR_E_USAGE || st == GR_E_INPUT) return 2;
    return 1;
}
