/* The interactive comparison of `godrays run`'s index.html: one canvas in which a reader flips
 * between the ground truth and a technique (a click on the image, or the space bar: FLIP's own
 * premise, alternate the images), wipes between them (a slider), zooms (wheel, +/-) and pans
 * (drag), changes the exposure (a slider, in stops around the report's exposure) and shows the
 * FLIP map the report computed (HDR-FLIP of a T against the truth, magma colour map,
 * compare/flip.h). Vanilla JavaScript inside the page, no external resource, works from file://.
 *
 * The images stay linear: each is embedded as a data: URL of an 8-bit RGB PNG twice as tall as
 * the image, the top half the RGBE mantissas, the bottom half the shared exponent (Ward's
 * RGBE: relative precision 2^-8 of each pixel's largest channel); the script decodes them
 * to floats and tone maps them (exposure, sRGB) in the canvas. data: URLs because a page
 * opened from file:// may not read the pixels of files beside it (the canvas is tainted).
 * Format and controls: docs/report.md "Interactive comparison". Library code: prints nothing. */
#ifndef GR_VIEWER_H
#define GR_VIEWER_H

#include "common/status.h"
#include "image/image.h"
#include "report/html.h"

typedef struct gr_viewer_item {
    const char *name;          /* the technique's name (shown, HTML-escaped) */
    const gr_image *test;      /* R, G, B (linear) */
    double scale;              /* the fitted a applied to the test */
    const gr_image *flip_map;  /* its FLIP heat map (display-encoded RGB, the image's size;
                                  gr_flip_heatmap), NULL: none */
    double flip_mean;          /* its mean FLIP (shown with the map) */
} gr_viewer_item;

/* Images wider than this are shrunk by an integer box factor in the page. */
#define GR_VIEWER_MAX_WIDTH 1280

/* Appends the comparison block (its canvas, controls and <script>) to html; dir is the
 * report's folder (for temporary files only: nothing stays there). exposure: the report's
 * preview exposure (the slider's 0 EV). GR_E_INPUT for sizes that differ from ref's; GR_E_IO;
 * GR_E_NOMEM. */
gr_status gr_viewer_write(const char *dir, const gr_image *ref, const gr_viewer_item *items, int n, double exposure,
                          gr_strbuf *html, gr_error *err);

/* RGBE of one linear RGB pixel (Ward, Graphics Gems II "Real pixels"): out[0..2] the
 * mantissas, out[3] the exponent byte (0: black). Decoding: (m + 0.5) * 2^(e - 136). */
void gr_viewer_rgbe(float r, float g, float b, unsigned char out[4]);

/* Standard base64 (RFC 4648, with padding) of n bytes, appended to b. */
void gr_viewer_base64(gr_strbuf *b, const unsigned char *data, size_t n);

#endif
