/* Text buffer and HTML escaping (see html.h). */
#include "report/html.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void gr_sb_init(gr_strbuf *b)
{
    b->data = NULL;
    b->len = b->cap = 0;
    b->failed = 0;
}

void gr_sb_free(gr_strbuf *b)
{
    if (!b) return;
    free(b->data);
    gr_sb_init(b);
}

const char *gr_sb_str(const gr_strbuf *b)
{
    return b->data ? b->data : "";
}

gr_status gr_sb_status(const gr_strbuf *b, const char *what, gr_error *err)
{
    if (!b->failed) return GR_OK;
    return gr_fail(err, GR_E_NOMEM, "%s: out of memory building the text", what ? what : "text");
}

/* Makes room for n more bytes plus the terminator; 0 on failure (sticky). */
static int reserve(gr_strbuf *b, size_t n)
{
    if (b->failed) return 0;
    if (n > ((size_t)-1) / 4 - b->len) {
        b->failed = 1;
        return 0;
    }
    size_t need = b->len + n + 1;
    if (need <= b->cap) return 1;
    size_t cap = b->cap ? b->cap : 256;
    while (cap < need) cap *= 2;
    char *p = realloc(b->data, cap);
    if (!p) {
        b->failed = 1;
        return 0;
    }
    b->data = p;
    b->cap = cap;
    return 1;
}

static void append(gr_strbuf *b, const char *s, size_t n)
{
    if (!reserve(b, n)) return;
    memcpy(b->data + b->len, s, n);
    b->len += n;
    b->data[b->len] = '\0';
}

void gr_sb_puts(gr_strbuf *b, const char *s)
{
    if (s) append(b, s, strlen(s));
}

static void vprintf_into(gr_strbuf *b, int escape, const char *fmt, va_list ap)
{
    char small[512];
    va_list ap2;
    va_copy(ap2, ap);
    int n = vsnprintf(small, sizeof small, fmt, ap);
    if (n < 0) {
        va_end(ap2);
        return;
    }
    if ((size_t)n < sizeof small) {
        if (escape) gr_sb_html(b, small);
        else append(b, small, (size_t)n);
        va_end(ap2);
        return;
    }
    char *big = malloc((size_t)n + 1);
    if (!big) {
        b->failed = 1;
        va_end(ap2);
        return;
    }
    vsnprintf(big, (size_t)n + 1, fmt, ap2);
    va_end(ap2);
    if (escape) gr_sb_html(b, big);
    else append(b, big, (size_t)n);
    free(big);
}

void gr_sb_printf(gr_strbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf_into(b, 0, fmt, ap);
    va_end(ap);
}

void gr_sb_htmlf(gr_strbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf_into(b, 1, fmt, ap);
    va_end(ap);
}

void gr_sb_html(gr_strbuf *b, const char *s)
{
    if (!s) return;
    const char *run = s; /* start of the pending run of characters that need no escape */
    for (const char *p = s;; p++) {
        const unsigned char c = (unsigned char)*p;
        const char *rep = NULL;
        switch (c) {
        case '&': rep = "&amp;"; break;
        case '<': rep = "&lt;"; break;
        case '>': rep = "&gt;"; break;
        case '"': rep = "&quot;"; break;
        case '\'': rep = "&#39;"; break;
        default:
            if ((c < 0x20 && c != '\t' && c != '\n' && c != '\0') || c == 0x7f) rep = "\xEF\xBF\xBD";
        }
        if (!rep && c != '\0') continue;
        append(b, run, (size_t)(p - run));
        if (c == '\0') break;
        gr_sb_puts(b, rep);
        run = p + 1;
    }
}

void gr_sb_shell_word(gr_strbuf *b, const char *s)
{
    int plain = s[0] != '\0';
    for (const char *p = s; *p && plain; p++)
        plain = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                strchr("_./=:,+%@-", *p) != NULL;
    if (plain) {
        gr_sb_puts(b, s);
        return;
    }
    gr_sb_puts(b, "'");
    for (const char *p = s; *p; p++) {
        if (*p == '\'') gr_sb_puts(b, "'\\''");
        else append(b, p, 1);
    }
    gr_sb_puts(b, "'");
}
