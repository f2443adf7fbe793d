/* False-color difference images with a labelled colorbar, for `godrays compare` and the
 * report. The quantity is the luminance difference dY = a Y(test) - Y(ref) (Rec. 709). */
#ifndef GR_DIFFMAP_H
#define GR_DIFFMAP_H

#include "compare/metrics.h"
#include "image/image.h"

typedef enum gr_diffmap_kind {
    GR_DIFFMAP_ABS = 0,   /* |dY| on [0, vmax], OpenImageIO's "inferno" */
    GR_DIFFMAP_SIGNED = 1 /* dY on [-vmax, vmax], "blue-red" (blue: test too dark) */
} gr_diffmap_kind;

typedef struct gr_diffmap_options {
    gr_diffmap_kind kind;
    double scale;          /* a applied to the test (0: 1) */
    double vmax;           /* colorbar end; 0: the 99th percentile of |dY| over scored pixels */
    const gr_image *mask;  /* as in gr_metrics_options (NULL: all pixels) */
    double stderr_bound;   /* as in gr_metrics_options (0: the default bound) */
} gr_diffmap_options;

/* What was drawn (for metrics.json and the report). */
typedef struct gr_diffmap_info {
    double vmin, vmax;     /* the colorbar's range */
    const char *map;       /* color map name */
    int labelled;          /* 1 if the colorbar's numbers were drawn (a font was found) */
    long long n_unscored;  /* pixels drawn gray: masked out or reference stderr over the bound */
} gr_diffmap_info;

/* Builds an RGB display image: the color-mapped difference (unscored pixels mid gray) above a
 * colorbar strip with its end values written under it. Same size rules as gr_metrics_compute.
 * *out must be destroyed by the caller; write it with gr_oiio_write (display values). */
gr_status gr_diffmap_create(const gr_image *ref, const gr_image *test, const gr_diffmap_options *opt,
                            gr_image **out, gr_diffmap_info *info, gr_error *err);

#endif
