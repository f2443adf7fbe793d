#include "image/png.h"

#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>

#include "common/outfile.h"

/* The simplified API's image for the codes (libpng 1.6, png.h "SIMPLIFIED API"); 0 when the
 * arguments cannot make a PNG. */
static int setup(png_image *im, int width, int height, int channels)
{
    static const png_uint_32 fmt[4] = {PNG_FORMAT_GRAY, PNG_FORMAT_GA, PNG_FORMAT_RGB, PNG_FORMAT_RGBA};
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4) return 0;
    if ((size_t)width > PNG_UINT_31_MAX / (size_t)channels || (size_t)height > PNG_UINT_31_MAX) return 0;
    memset(im, 0, sizeof *im);
    im->version = PNG_IMAGE_VERSION;
    im->width = (png_uint_32)width;
    im->height = (png_uint_32)height;
    im->format = fmt[channels - 1];
    /* 8-bit codes that are not linear: libpng writes an sRGB chunk */
    im->flags = 0;
    return 1;
}

/* Writes width x height pixels of `channels` (1 grey, 2 grey + alpha, 3 RGB, 4 RGBA) 8-bit
 * codes, row by row from the top, to path, tagged sRGB (an sRGB chunk). Through common/outfile:
 * a temporary name renamed into place, nothing half-written. */
static gr_status png_write(const char *path, int width, int height, int channels, const unsigned char *codes,
                           gr_error *err)
{
    if (!path || !path[0]) return gr_fail(err, GR_E_USAGE, "PNG: no output path");
    png_image im;
    if (!codes || !setup(&im, width, height, channels))
        return gr_fail(err, GR_E_INPUT, "%s: no image, or %d x %d pixels of %d channels cannot be a PNG", path, width,
                       height, channels);
    gr_outfile of;
    gr_status st = gr_outfile_open(&of, path, err);
    if (st != GR_OK) return st;
    if (!png_image_write_to_stdio(&im, of.f, 0, codes, 0, NULL)) {
        st = gr_fail(err, GR_E_IO, "%s: cannot write the PNG: %s", path, im.message[0] ? im.message : "libpng failed");
        png_image_free(&im);
        gr_outfile_abort(&of);
        return st;
    }
    png_image_free(&im);
    /* the smallest PNG: the signature, IHDR, one IDAT and IEND (8 + 25 + 12 + 12 bytes) */
    return gr_outfile_commit(&of, 57, err);
}

/* The same PNG in memory: *buf (malloc'd, the caller frees it) of *len bytes. */
static gr_status png_encode(int width, int height, int channels, const unsigned char *codes, unsigned char **buf,
                            size_t *len, gr_error *err)
{
    *buf = NULL;
    *len = 0;
    png_image im;
    if (!codes || !setup(&im, width, height, channels))
        return gr_fail(err, GR_E_INPUT, "PNG in memory: no image, or %d x %d pixels of %d channels cannot be a PNG", width,
                       height, channels);
    /* one encoding into a buffer of libpng's bound on the file's size, then trimmed */
    png_alloc_size_t cap = PNG_IMAGE_PNG_SIZE_MAX(im), n = cap;
    unsigned char *b = malloc(cap);
    if (!b) {
        png_image_free(&im);
        return gr_fail(err, GR_E_NOMEM, "PNG in memory: out of memory (%zu bytes)", (size_t)cap);
    }
    if (!png_image_write_to_memory(&im, b, &n, 0, codes, 0, NULL) || n == 0 || n > cap) {
        gr_status st = gr_fail(err, GR_E_RUNTIME, "PNG in memory: %s", im.message[0] ? im.message : "libpng failed");
        png_image_free(&im);
        free(b);
        return st;
    }
    unsigned char *t = realloc(b, n);
    if (t) b = t;
    png_image_free(&im);
    *buf = b;
    *len = (size_t)n;
    return GR_OK;
}

/* sRGB OETF, IEC 61966-2-1 (piecewise: linear toe below 0.0031308, 1/2.4 power above). */
static float srgb_encode(float v)
{
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

/* A display value's code: NaN and +-Inf (no display value) as 0, clamped to [0, 1], rounded. */
static unsigned char code_of(float v, int encode)
{
    if (!isfinite(v)) v = 0.0f;
    v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
    return (unsigned char)floorf((encode ? srgb_encode(v) : v) * 255.0f + 0.5f);
}

static int image_ok(const gr_image *img)
{
    return img && img->pixels && img->width > 0 && img->height > 0 && img->nchannels > 0 &&
           img->nchannels <= GR_IMAGE_MAX_CHANNELS;
}

/* The 8-bit codes of channels rgb[0..2] of img times e (malloc'd; NULL when out of memory). */
static unsigned char *codes_of(const gr_image *img, const int rgb[3], float e, int encode)
{
    const size_t n = (size_t)img->width * (size_t)img->height, nc = (size_t)img->nchannels;
    unsigned char *c = malloc(3 * n);
    if (!c) return NULL;
    for (size_t p = 0; p < n; p++)
        for (size_t k = 0; k < 3; k++) c[3 * p + k] = code_of(img->pixels[p * nc + (size_t)rgb[k]] * e, encode);
    return c;
}

gr_status gr_png_write_preview(const char *path, const gr_image *img, const int rgb[3], double exposure,
                               gr_error *err)
{
    if (!path || !path[0]) return gr_fail(err, GR_E_USAGE, "preview: no output path");
    if (!image_ok(img)) return gr_fail(err, GR_E_INPUT, "%s: no image or bad image size", path);
    if (!rgb) return gr_fail(err, GR_E_INPUT, "%s: no channels chosen for the preview", path);
    for (int k = 0; k < 3; k++)
        if (rgb[k] < 0 || rgb[k] >= img->nchannels)
            return gr_fail(err, GR_E_INPUT, "%s: preview channel %d is %d, the image has %d channels", path, k, rgb[k],
                           img->nchannels);
    if (!isfinite(exposure) || exposure < 0.0)
        return gr_fail(err, GR_E_INPUT, "%s: preview exposure %g is not a finite value >= 0", path, exposure);
    unsigned char *c = codes_of(img, rgb, (float)exposure, 1);
    if (!c) return gr_fail(err, GR_E_NOMEM, "%s: out of memory for the preview", path);
    gr_status st = png_write(path, img->width, img->height, 3, c, err);
    free(c);
    return st;
}

gr_status gr_png_encode_display(const gr_image *img, unsigned char **buf, size_t *len, gr_error *err)
{
    *buf = NULL;
    *len = 0;
    if (!image_ok(img) || img->nchannels < 3)
        return gr_fail(err, GR_E_INPUT, "PNG in memory: no image or fewer than 3 channels");
    static const int rgb[3] = {0, 1, 2};
    unsigned char *c = codes_of(img, rgb, 1.0f, 0);
    if (!c) return gr_fail(err, GR_E_NOMEM, "PNG in memory: out of memory");
    gr_status st = png_encode(img->width, img->height, 3, c, buf, len, err);
    free(c);
    return st;
}
