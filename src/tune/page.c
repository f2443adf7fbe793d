/* index.html of the tuning folders (page.h). */
#include "tune/page.h"

#include <stdio.h>

#include "tune/session.h"

void gr_tune_page_begin(gr_strbuf *b, const char *title)
{
    gr_sb_puts(b, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>");
    gr_sb_html(b, title);
    gr_sb_puts(b, "</title><style>body{font-family:sans-serif;margin:2em;max-width:1100px;color:#222}"
                  "img{max-width:100%;border:1px solid #ccc}figure{margin:1.5em 0}"
                  "pre{background:#f4f4f4;padding:.8em;overflow-x:auto}</style></head><body>\n<h1>");
    gr_sb_html(b, title);
    gr_sb_puts(b, "</h1>\n");
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

gr_status gr_tune_page_write(gr_strbuf *b, const char *dir, gr_error *err)
{
    gr_sb_puts(b, "<p>How to read this page: docs/tuning.md.</p>\n</body></html>\n");
    gr_status st = gr_sb_status(b, "index.html", err);
    if (st != GR_OK) return st;
    char path[4300];
    if (snprintf(path, sizeof path, "%s/index.html", dir) >= (int)sizeof path)
        return gr_fail(err, GR_E_USAGE, "%s: directory name too long", dir);
    return gr_tune_write_text(path, gr_sb_str(b), err);
}
