/* OpenImageIO behind a C interface (the only C++ in the project: oiio.cpp).
 * No exception crosses this boundary: every failure becomes a gr_status. */
#ifndef GR_OIIO_H
#define GR_OIIO_H

#include "image/image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* OpenImageIO's version string, e.g. "2.4.7" ("not loaded" when the module cannot be). */
const char *gr_oiio_version(void);
/* GR_OK when OpenImageIO can be used: its module loads (oiio.c; docs/images.md, "Loading
 * OpenImageIO"); else GR_E_RUNTIME naming the places tried. Every function below fails the
 * same way then; a caller that maps read failures to bad input asks this first. */
gr_status gr_oiio_available(gr_error *err);
/* Reads any format OpenImageIO reads (EXR, PNG, TIFF, HDR, ...) as float, all channels,
 * channel names as the file gives them (8-bit files are decoded to linear only if
 * linearize is nonzero; otherwise values are code/255). */
gr_status gr_oiio_read(const char *path, int linearize, gr_image **out, gr_error *err);

/* What a file says of its pixels beyond their values (compare's capture checks: docs/metrics.md,
 * "Capture warnings"). */
typedef struct gr_oiio_info {
    int bits;                /* bits per sample of the file's pixel type (8, 16, 32, ...) */
    int integer;             /* unsigned integer samples: display-encoded codes */
    int decoded;             /* the codes were sRGB-decoded to linear on reading */
    char colorspace[64];     /* oiio:ColorSpace as OpenImageIO reports it ("sRGB", "Linear", ...) */
    long long n_top_code;    /* integer files: pixels with a channel other than alpha at the top code */
} gr_oiio_info;

/* gr_oiio_read, and *info (may be NULL) filled. */
gr_status gr_oiio_read_info(const char *path, int linearize, gr_image **out, gr_oiio_info *info, gr_error *err);
/* (PNG previews and in-memory PNGs: image/png.h, through libpng.) */
/* Writes img as-is in the format the extension names (float data where the format allows). */
gr_status gr_oiio_write(const char *path, const gr_image *img, gr_error *err);

/* (compare module) Maps channel `channel` of src, values in [0, 1] (clamped), through the
 * OpenImageIO color map called `map` ("inferno", "viridis", "magma", "plasma", "turbo",
 * "blue-red", ...) into a new 3-channel "R","G","B" image of display-encoded values in [0, 1]
 * (write it with gr_oiio_write: no further encoding). *out must be destroyed by the caller. */
gr_status gr_oiio_color_map(const gr_image *src, int channel, const char *map, gr_image **out, gr_error *err);
/* (compare module) Draws one line of text into the first three channels of img, baseline at
 * y, starting at x (align 0), centred on x (1) or ending at x (2), in color rgb and size_px
 * pixels high; font DejaVuSans if found, else OpenImageIO's default. GR_E_RUNTIME when no
 * font can be loaded (callers may treat labels as optional). */
gr_status gr_oiio_render_text(gr_image *img, int x, int y, const char *text, int size_px, const float rgb[3],
                              int align, gr_error *err);

/* (report module) Writes n display-encoded frames (R, G, B in [0, 1], all the same size) as
 * one animated file, an animated GIF by extension (OpenImageIO's GIF writer: one subimage
 * per frame, 256 colours per frame, looping forever), at fps frames per second (GIF delays
 * are whole 1/100 s). Through a temporary name renamed into place; the file is read back and
 * must hold n subimages. */
gr_status gr_oiio_write_animation(const char *path, const gr_image *const *frames, int n, double fps, gr_error *err);

#ifdef __cplusplus
}
#endif
#endif
