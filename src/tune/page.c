/* index.html of the tuning folders (page.h). */
#include "tune/page.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "tune/session.h"

/* 1 if dir/../name is a regular file. */
static int parent_has(const char *dir, const char *name)
{
    char path[4300];
    struct stat sb;
    if (snprintf(path, sizeof path, "%s/../%s", dir, name) >= (int)sizeof path) return 0;
    return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

void gr_tune_page_begin(gr_strbuf *b, const char *dir, const char *title_fmt, ...)
{
    char title[512];
    va_list ap;
    va_start(ap, title_fmt);
    vsnprintf(title, sizeof title, title_fmt, ap);
    va_end(ap);
    gr_sb_puts(b, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>");
    gr_sb_html(b, title);
    gr_sb_puts(b, "</title><style>body{font-family:sans-serif;margin:2em;max-width:1100px;color:#222}"
                  "img{max-width:100%;border:1px solid #ccc}figure{margin:1.5em 0}"
                  "pre{background:#f4f4f4;padding:.8em;overflow-x:auto}</style></head><body>\n<h1>");
    gr_sb_html(b, title);
    gr_sb_puts(b, "</h1>\n");
    if (parent_has(dir, "index.html") && parent_has(dir, "metrics.json"))
        gr_sb_puts(b, "<p>Part of the report of <code>godrays run</code>: <a href=\"../index.html\">../index.html</a> "
                      "(ground truth against every technique at the scene's settings).</p>\n");
}

void gr_tune_page_figure(gr_strbuf *b, const char *file, const char *caption)
{
    gr_sb_puts(b, "<figure><img src=\"");
    gr_sb_html(b, file);
    gr_sb_puts(b, "\" alt=\"");
    gr_sb_html(b, caption);
    gr_sb_puts(b, "\"><figcaption>");
    gr_sb_html(b, caption);
    gr_sb_puts(b, "</figcaption></figure>\n");
}

void gr_tune_page_pre(gr_strbuf *b, const char *text)
{
    gr_sb_puts(b, "<pre>");
    gr_sb_html(b, text);
    gr_sb_puts(b, "</pre>\n");
}

gr_status gr_tune_page_write(gr_strbuf *b, const char *text, const char *data, const char *dir, gr_error *err)
{
    gr_tune_page_pre(b, text);
    gr_sb_puts(b, "<p>Data:");
    for (const char *f = data; *f;) {
        const size_t n = strcspn(f, ",");
        gr_sb_printf(b, "%s <a href=\"%.*s\">%.*s</a>", f == data ? "" : ",", (int)n, f, (int)n, f);
        f += n + (f[n] == ',');
    }
    gr_sb_puts(b, ".</p>\n<p>How to read this page: docs/tuning.md.</p>\n</body></html>\n");
    char path[4300];
    gr_status st = gr_sb_status(b, "index.html", err);
    if (st == GR_OK && snprintf(path, sizeof path, "%s/index.html", dir) >= (int)sizeof path)
        st = gr_fail(err, GR_E_USAGE, "%s: directory name too long", dir);
    if (st == GR_OK) st = gr_tune_write_text(path, gr_sb_str(b), err);
    gr_sb_free(b);
    return st;
}
