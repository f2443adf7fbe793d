/* `godrays sweep`: the error surface of a technique over a grid of one or two settings, each
 * grid point rendered once per case (frame, view) with one renderer and scored against that
 * case's ground truth; written as CSV, JSON and a plot (heat map with its minimum marked, or a
 * line chart for one axis). docs/tuning.md. */
#ifndef GR_TUNE_SWEEP_H
#define GR_TUNE_SWEEP_H

#include "common/status.h"
#include "tune/objective.h"

typedef struct gr_sweep_result {
    int n_axes;              /* 1 or 2 (the problem's params) */
    int nx, ny;              /* values along axis 0 and axis 1 (ny = 1 for one axis) */
    int n_cases;
    double *xs, *ys;         /* axis values (ys: one 0 for one axis) */
    double *err;             /* nx * ny: mean over cases, index ix + nx * iy */
    double *case_err;        /* nx * ny * n_cases: index (ix + nx * iy) * n_cases + case */
    double *scale;           /* nx * ny: mean fitted scale over cases (1 without fit) */
    int best;                /* index of the minimum of err (first in scan order on ties) */
    double wall_s;           /* time of the sweep loop */
} gr_sweep_result;

/* Progress callback (may be NULL): after each grid point. */
typedef void (*gr_sweep_progress_fn)(void *user, int done, int total);

/* Runs the sweep over p->params[0] (and [1]) with their count values. p must be initialized
 * (gr_tune_problem_init) with 1 or 2 params of count >= 2. res is the caller's; free with
 * gr_sweep_result_free. */
gr_status gr_sweep_run(gr_tune_problem *p, gr_sweep_result *res, gr_sweep_progress_fn cb, void *user,
                       gr_error *err);
void gr_sweep_result_free(gr_sweep_result *res); /* accepts NULL; leaves it empty */

/* CSV: one row per grid point: axis values, metric (mean), fitted scale, per-case values. */
gr_status gr_sweep_write_csv(const char *path, const gr_tune_problem *p, const gr_sweep_result *res,
                             const char *const *case_labels, gr_error *err);

/* The plot: two axes -> heat map (viridis, dark = low error) with the minimum marked by a
 * white cross and a labelled colorbar; one axis -> line chart (PLplot, src/report/plot.h) with
 * the minimum marked. *drawn = 0 (and GR_OK) when the chart could not be drawn in this build
 * (no PLplot for a line chart). */
gr_status gr_sweep_write_plot(const char *path, const gr_tune_problem *p, const gr_sweep_result *res, int *drawn,
                              gr_error *err);

/* Heat map of z (nx * ny, index ix + nx * iy, iy growing upward) into an RGB display image:
 * axes labelled with their ends, a colorbar with its range, the cell `mark` (-1: none) crossed.
 * Text is optional (no font: unlabelled). */
gr_status gr_tune_heatmap(const double *z, int nx, int ny, double x0, double x1, double y0, double y1,
                          const char *xlabel, const char *ylabel, const char *title, int mark, gr_image **out,
                          gr_error *err);

#endif
