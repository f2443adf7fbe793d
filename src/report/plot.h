/* Line charts drawn by PLplot (libplplot, C API) for the report: the radial profile and the
 * error against blur scale. PLplot's "mem" device draws into an RGB buffer of ours, so no
 * display, Qt or cairo is needed; the chart is drawn at twice the size with each pass offset
 * by one device pixel (thicker strokes) and box-filtered down (antialiasing), then written as
 * PNG through OpenImageIO. The legend is drawn on its own white buffer and pasted over the
 * chart as an opaque box (PLplot's legend background needs solid fills, which the memory
 * device lacks). Built without PLplot (GR_HAVE_PLPLOT unset), every drawing call
 * returns GR_E_RUNTIME and the report says the charts are missing. */
#ifndef GR_PLOT_H
#define GR_PLOT_H

#include "common/status.h"
#include "image/image.h"

#define GR_PLOT_MAX_SERIES 66 /* pareto: points + front for the ground truth and 32 techniques */
/* The plot area (PLplot viewport) as fractions of the chart, from the left and bottom. */
#define GR_PLOT_VP_X0 0.11
#define GR_PLOT_VP_X1 0.97
#define GR_PLOT_VP_Y0 0.13
#define GR_PLOT_VP_Y1 0.90

typedef enum gr_plot_style { GR_PLOT_SOLID = 0, GR_PLOT_DASHED = 1, GR_PLOT_LONG_DASHED = 2 } gr_plot_style;

typedef struct gr_plot_series {
    const char *label;           /* legend text (NULL or "": not in the legend) */
    const double *x, *y;         /* n points; a point with a non-finite coordinate, or a
                                    non-positive one on a log axis, is skipped and breaks the line */
    int n;
    unsigned char rgb[3];
    gr_plot_style style;
    int markers;                 /* 1: also mark each point */
} gr_plot_series;

typedef struct gr_plot_spec {
    int width, height;           /* chart size in pixels (0: 800 x 450); 64..4096 */
    const char *title, *xlabel, *ylabel;
    int log_x, log_y;            /* logarithmic axes (decades) */
    /* Axis ranges in data units; xmin == xmax (e.g. both 0) takes the range of the data
     * (with a 4 % margin on linear axes, whole decades on log axes). */
    double xmin, xmax, ymin, ymax;
    /* With the y range from the data: this fraction of it is added above the data (room for
     * the legend, drawn opaque in the top right corner). */
    double legend_headroom;
    /* > 0: the legend goes right of the plot area, in this fraction of the chart's width (the
     * plot area narrowed by it), instead of inside its top right corner. */
    double legend_outside;
    const gr_plot_series *series;
    int n_series;                /* 0..GR_PLOT_MAX_SERIES */
    /* Categorical x axis (n_categories > 0, log_x = 0): x values are the indices 0..n-1 and
     * the axis shows these labels at them (e.g. blur sigmas "none", "1", "4", "16"). */
    const char *const *x_categories;
    int n_categories;            /* 0..32 */
} gr_plot_spec;

/* 1 if this build can draw charts (PLplot found at configure time). */
int gr_plot_available(void);

/* Draws the chart into a new 3-channel "R","G","B" image of display values in [0, 1] (write it
 * with gr_oiio_write). GR_E_INPUT for a bad size, a NULL array with n > 0, n < 0, too many
 * series, or an explicit log range that is not > 0; GR_E_RUNTIME without PLplot. */
gr_status gr_plot_render(const gr_plot_spec *spec, gr_image **out, gr_error *err);

/* gr_plot_render, then written to path (PNG by extension) through a temporary name renamed
 * into place. */
gr_status gr_plot_write(const char *path, const gr_plot_spec *spec, gr_error *err);

#endif
