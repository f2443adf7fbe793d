/* A growable text buffer with HTML escaping, for the report's index.html (and any other
 * generated text). Allocation failures are sticky: every append after one is a no-op and
 * gr_sb_status() reports GR_E_NOMEM, so callers check once at the end. */
#ifndef GR_HTML_H
#define GR_HTML_H

#include <stddef.h>
#include "common/status.h"

typedef struct gr_strbuf {
    char *data;   /* NUL-terminated once anything was appended; NULL before */
    size_t len, cap;
    int failed;   /* an allocation failed: content is incomplete */
} gr_strbuf;

void gr_sb_init(gr_strbuf *b);
void gr_sb_free(gr_strbuf *b); /* accepts NULL; leaves b empty */
/* The content ("" when empty); valid until the next append or gr_sb_free. */
const char *gr_sb_str(const gr_strbuf *b);
/* GR_OK, or GR_E_NOMEM (with a message naming `what`) if an append failed. */
gr_status gr_sb_status(const gr_strbuf *b, const char *what, gr_error *err);

void gr_sb_puts(gr_strbuf *b, const char *s);          /* verbatim (s may be NULL: nothing) */
void gr_sb_printf(gr_strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* s escaped for HTML text and attribute values: & < > " ' become entities; control
 * characters other than tab and newline (which no HTML text should carry) become U+FFFD. */
void gr_sb_html(gr_strbuf *b, const char *s);
/* printf, then escaped as gr_sb_html. */
void gr_sb_htmlf(gr_strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* s as one word of a POSIX shell command: as is when it holds only [A-Za-z0-9_./=:,+%@-] (and
 * is not empty), else in single quotes, each ' written as '\''. Not HTML-escaped. */
void gr_sb_shell_word(gr_strbuf *b, const char *s);

#endif
