/* A small self-contained index.html for the folders of sweep, tune and pareto (inline CSS,
 * relative links, no JavaScript), so that each result can be read in a browser next to the
 * report of `godrays run`. */
#ifndef GR_TUNE_PAGE_H
#define GR_TUNE_PAGE_H

#include "common/status.h"
#include "report/html.h"

/* Starts a page: the head with the title (escaped) and an h1. */
void gr_tune_page_begin(gr_strbuf *b, const char *title);
/* A figure: <img src=file> with a caption (both escaped). */
void gr_tune_page_figure(gr_strbuf *b, const char *file, const char *caption);
/* Preformatted text (escaped), e.g. the snippet or a table printed by the command. */
void gr_tune_page_pre(gr_strbuf *b, const char *text);
/* Ends the page and writes dir/index.html (through a temporary name). */
gr_status gr_tune_page_write(gr_strbuf *b, const char *dir, gr_error *err);

#endif
