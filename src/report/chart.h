/* Interactive charts in the pages of `godrays pareto` and `pareto --suite` (docs/report.md,
 * "Interactive charts"): time (log axis) against error, one series per family, drawn in the
 * browser by Chart.js (Debian's libjs-chart.js, read at run time and inlined into the page so
 * that it opens offline). Hover a point: its tooltip (the lines the caller gives: technique,
 * settings, time, errors) and its thumbnail; click a legend entry: hide or show that family;
 * drag a box: zoom into it ("reset zoom" undoes it; a button switches the error axis between
 * log and linear); hover a table row marked with gr_chart_row_attrs: its point is highlighted.
 * Each family's front (its points with on_front) is joined by a line.
 *
 * The PNG chart that PLplot drew stays in the page as the fallback: shown when Chart.js cannot
 * be found when the page is written (the page says why) or when the script fails in the browser
 * (the status line says why). When the chart is drawn, the element ID-status gets data-ready="1"
 * and data-points="N" (the points drawn), which the browser test reads. */
#ifndef GR_REPORT_CHART_H
#define GR_REPORT_CHART_H

#include <stddef.h>

#include "common/status.h"
#include "image/image.h"
#include "report/html.h"

#define GR_CHART_MAX_SERIES 64

typedef struct gr_chart_series {
    char name[64];   /* legend text */
    int color;       /* palette index: the same index, the same colour (e.g. the technique) */
    int hollow;      /* 1: hollow markers and a dashed front (e.g. untuned), 0: filled, solid */
} gr_chart_series;

typedef struct gr_chart_point {
    int series;      /* index into gr_chart.series */
    double x, y;     /* time (ms, > 0: log axis) and error; points not finite or x <= 0 are left out */
    int on_front;
    char title[128]; /* tooltip heading */
    char lines[1024]; /* tooltip lines, separated by '\n' */
    char thumb[96];  /* relative path of the point's thumbnail PNG; "" none */
} gr_chart_point;

typedef struct gr_chart {
    const char *id;          /* DOM id prefix, [A-Za-z0-9_-] */
    const char *title;       /* first title line (e.g. names GL_RENDERER) */
    const char *subtitle;    /* second title line; NULL none */
    const char *x_label, *y_label;
    const char *png;         /* the PLplot chart in the page's folder (fallback); NULL none */
    int log_y;               /* the error axis starts logarithmic */
    int n_series;
    gr_chart_series series[GR_CHART_MAX_SERIES];
    int n_points;
    const gr_chart_point *points; /* caller-owned */
} gr_chart;

/* The Chart.js file used: $GODRAYS_CHARTJS if set, else the first readable of Debian's
 * /usr/share/javascript/chart.js/chart.min.js and chart.js. NULL when none is readable. */
const char *gr_chart_library_path(void);

/* Appends the chart (container, fallback, inlined library, data, script) to b. Returns 1 when
 * the interactive chart was written, 0 when only the fallback was (why: one line, e.g. the
 * library missing). Memory failures are b's (gr_sb_status). One chart per page. */
int gr_chart_html(gr_strbuf *b, const gr_chart *c, char *why, size_t n_why);

/* ` data-gr-chart="ID" data-gr-point="K"`: inside a <tr ...> (or any element) of the same page,
 * hovering it highlights point K (an index into gr_chart.points) of chart ID. */
void gr_chart_row_attrs(gr_strbuf *b, const char *id, int k);

/* "thumbs/pK.png": the thumbnail name of point K, relative to the page's folder. */
void gr_chart_thumb_name(int k, char *buf, size_t n);

/* Writes dir/name (a PNG, dir/thumbs made when missing): img times its least-squares scale
 * fit to truth (compare/fit.h), at truth's preview exposure (99th percentile -> 0.8, as the
 * report's T.png), sRGB. truth NULL: img at its own exposure. */
gr_status gr_chart_write_thumb(const char *dir, const char *name, const gr_image *truth, const gr_image *img,
                               gr_error *err);

#endif
