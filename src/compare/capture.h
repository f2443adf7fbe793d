/* Capture sanity: warnings about a test image (a frame captured from an engine, a render) that
 * is probably not what it should be before any metric is read: it matches the reference better
 * flipped vertically or horizontally than as given; an 8-bit input clips its highlights; an
 * 8- or 16-bit file's values look linear although it was decoded as sRGB, or the reverse; the
 * best scale fit is far from 1. Rules, thresholds and why: docs/metrics.md, "Capture warnings".
 * Pure computation on the two images and what the reader said of each file; `godrays compare`
 * prints the warnings and writes them to its JSON. */
#ifndef GR_CAPTURE_H
#define GR_CAPTURE_H

#include "common/status.h"
#include "image/image.h"

#define GR_CAPTURE_FLIP_MARGIN 0.8      /* a flip must bring the fitted error below 0.8 x as given */
#define GR_CAPTURE_CLIP_FRACTION 0.005  /* more than 0.5 % of an 8-bit file's pixels at the top code */
#define GR_CAPTURE_SCALE_LO 0.1         /* a scale fit outside [LO, HI] */
#define GR_CAPTURE_SCALE_HI 10.0
#define GR_CAPTURE_SLOPE 1.6            /* transfer check: log-log slope beyond 1.6 or below 1 / 1.6 ... */
#define GR_CAPTURE_TRANSFER_MARGIN 0.8  /* ... and the other reading's fitted error below 0.8 x */
#define GR_CAPTURE_MAX_WARNINGS 8

/* What the reader said of one input file (image/oiio.h's gr_oiio_info); zeros: a float file. */
typedef struct gr_capture_file {
    int bits;                     /* bits per sample (8, 16, 32, ...); 0 unknown */
    int integer;                  /* integer codes (display-encoded) */
    int decoded;                  /* the codes were sRGB-decoded to linear on reading */
    long long n_top_code;         /* pixels with a colour channel at the top code (integer files) */
} gr_capture_file;

typedef struct gr_capture_input {
    const gr_image *ref, *test;   /* same size (checked) */
    const int *ref_rgb, *test_rgb;/* the channels compared (compare/channels.h) */
    const unsigned char *scored;  /* width * height, 1 = scored; NULL: all */
    gr_capture_file ref_file, test_file;
    const double *fit_rgb;        /* the comparison's per-channel factors (checked against the
                                     scale range too), or NULL */
} gr_capture_input;

typedef struct gr_capture_warning {
    const char *code;             /* "flipped_vertically", "flipped_horizontally", "clipped_reference",
                                     "clipped_test", "srgb_looks_linear", "linear_looks_srgb",
                                     "scale_out_of_range" */
    char message[320];            /* one line, naming the numbers it rests on */
} gr_capture_warning;

/* The numbers behind the checks (NaN: not checked) and the warnings. */
typedef struct gr_capture_report {
    double err_given, err_vflip, err_hflip; /* relative RMSE of Y after a scale fit (>= 0) of the
                                     test as given, flipped upside down, mirrored left-right */
    double scale;                 /* the least-squares scale <t, r> / <t, t> (RGB pooled) */
    double top_fraction[2];       /* reference, test: fraction of pixels at the top code (8-bit) */
    double slope_given, slope_other; /* test: slope of ln Y(test) over ln Y(ref), as read and read
                                     the other way (codes decoded / not decoded) */
    double err_other;             /* relative RMSE of Y after a fit, read the other way (err_given:
                                     as read, over the same pixels) */
    double err_as_read;
    int n;
    gr_capture_warning w[GR_CAPTURE_MAX_WARNINGS];
} gr_capture_report;

/* Runs every check. GR_E_INPUT for missing or differently sized images. */
gr_status gr_capture_check(const gr_capture_input *in, gr_capture_report *out, gr_error *err);

#endif
