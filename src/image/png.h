/* 8-bit PNG files and in-memory PNGs through libpng, without OpenImageIO: the previews every
 * render writes (docs/images.md, "PNG previews"), so that a command writing one does not load
 * OpenImageIO's module (0.4-0.6 s of CPU a process). */
#ifndef GR_PNG_H
#define GR_PNG_H

#include <stddef.h>
#include "common/status.h"
#include "image/image.h"

/* Writes a display-encoded 8-bit RGB preview to path (a PNG whatever the name): the channels
 * rgb[0..2] of img times `exposure`, clamped to [0, 1], then sRGB-encoded (docs/images.md, "PNG
 * previews"); NaN and +-Inf as 0. */
gr_status gr_png_write_preview(const char *path, const gr_image *img, const int rgb[3], double exposure,
                               gr_error *err);
/* The first three channels of img, display-encoded values in [0, 1] (gr_report_display,
 * gr_diffmap_create, gr_flip_heatmap; clamped, not encoded further, code = round(255 v)), as an
 * 8-bit RGB PNG in memory: *buf (malloc'd, the caller frees it) of *len bytes. For `godrays
 * watch`'s page. */
gr_status gr_png_encode_display(const gr_image *img, unsigned char **buf, size_t *len, gr_error *err);

#endif
