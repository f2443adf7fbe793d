#include "common/status.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* src (n bytes) into dst (cap bytes): whole when it fits, else its head, "...", and its tail,
 * so that the reason at the end of a message survives a long path in the middle. */
static void fit_middle(char *dst, size_t cap, const char *src, size_t n)
{
    if (n < cap) {
        memmove(dst, src, n);
        dst[n] = '\0';
        return;
    }
    const size_t head = (cap - 4) / 3, tail = cap - 4 - head;
    memmove(dst, src, head);
    memcpy(dst + head, "...", 3);
    memmove(dst + head + 3, src + n - tail, tail);
    dst[cap - 1] = '\0';
}

/* The promise of one line: a file name, an attribute or a library's text quoted into a message
 * may hold line breaks or other control bytes (found by fuzzing the EXR reader). */
static void one_line(char *m)
{
    for (; *m; m++)
        if ((unsigned char)*m < 0x20 || *m == 0x7f) *m = ' ';
}

gr_status gr_fail(gr_error *err, gr_status st, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        va_start(ap, fmt);
        char *big = NULL;
        int n = vsnprintf(err->msg, sizeof err->msg, fmt, ap);
        va_end(ap);
        if (n >= (int)sizeof err->msg && (big = malloc((size_t)n + 1)) != NULL) {
            va_start(ap, fmt);
            vsnprintf(big, (size_t)n + 1, fmt, ap);
            va_end(ap);
            fit_middle(err->msg, sizeof err->msg, big, (size_t)n);
            free(big);
        }
        one_line(err->msg);
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
    /* "prefix: old", its middle cut to fit (fit_middle) */
    char both[2 * GR_ERROR_MSG_MAX + 2];
    const int n = snprintf(both, sizeof both, "%s: %s", prefix, old);
    fit_middle(err->msg, sizeof err->msg, both, n < 0 ? 0 : (size_t)n < sizeof both ? (size_t)n : sizeof both - 1);
    one_line(err->msg);
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
    case GR_E_TIMEOUT: return "time limit";
    }
    return "unknown error";
}

int gr_status_exit_code(gr_status st)
{
    if (st == GR_OK) return 0;
    if (st == GR_E_USAGE || st == GR_E_INPUT) return 2;
    return 1;
}
