/* Status codes and error messages shared by every module.
 * A function that can fail returns gr_status and, on failure, fills a caller-provided
 * gr_error with one line naming the input (file, JSON path, flag) and the reason. */
#ifndef GR_STATUS_H
#define GR_STATUS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum gr_status {
    GR_OK = 0,
    GR_E_USAGE,       /* bad command line (exit 2) */
    GR_E_INPUT,       /* bad input file or value (exit 2) */
    GR_E_IO,          /* file could not be read or written (exit 1) */
    GR_E_RUNTIME,     /* anything else that went wrong at run time (exit 1) */
    GR_E_NOMEM,       /* allocation failed (exit 1) */
    GR_E_GL,          /* OpenGL/EGL failure, shader compile/link error (exit 1) */
    GR_E_EMBREE,      /* Embree reported an error (exit 1) */
    GR_E_INTERRUPTED, /* stopped by the user (Ctrl-C); partial results may exist (exit 1) */
    GR_E_TIMEOUT      /* a time limit passed (a technique's render: --time-limit) (exit 1) */
} gr_status;

#define GR_ERROR_MSG_MAX 1024
typedef struct gr_error {
    gr_status status;
    char msg[GR_ERROR_MSG_MAX];
} gr_error;

/* Sets err (may be NULL) to status st and a printf-formatted message; returns st. */
gr_status gr_fail(gr_error *err, gr_status st, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Prefixes the message already in err with "prefix: " (e.g. a file name); returns err->status. */
gr_status gr_error_prefix(gr_error *err, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Short name of a status ("bad input", "I/O error", ...). */
const char *gr_status_name(gr_status st);
/* Process exit code for a status: 0 ok, 2 usage/input, 1 otherwise. */
int gr_status_exit_code(gr_status st);

#ifdef __cplusplus
}
#endif
#endif
