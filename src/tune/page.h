/* A small self-contained index.html for the folders of sweep, tune and pareto (inline CSS,
 * relative links, no JavaScript), so that each result can be read in a browser next to the
 * report of `godrays run`. */
#ifndef GR_TUNE_PAGE_H
#define GR_TUNE_PAGE_H

#include "common/status.h"
#include "report/html.h"

/* Starts the page of folder dir: the head with the title (printf format; escaped), an h1,
 * and a link back to the report of `godrays run` when dir sits in that report's folder
 * (dir/../index.html and dir/../metrics.json exist: sweep, tune and pareto default to
 * out/SCENE/{sweep,tune,pareto}, inside the run's out/SCENE). */
void gr_tune_page_begin(gr_strbuf *b, const char *dir, const char *title_fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* A figure: <img src=file> with a caption (both escaped). */
void gr_tune_page_figure(gr_strbuf *b, const char *file, const char *caption);
/* Preformatted text (escaped), e.g. the snippet or a table printed by the command. */
void gr_tune_page_pre(gr_strbuf *b, const char *text);
/* Ends the page with text (as gr_tune_page_pre: the summary the command printed) and a
 * "Data:" line linking the files named in data (comma-separated, in dir), writes
 * dir/index.html (through a temporary name) and frees b. */
gr_status gr_tune_page_write(gr_strbuf *b, const char *text, const char *data, const char *dir, gr_error *err);

#endif
