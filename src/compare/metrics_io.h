/* The metrics as text (a table for people) and as JSON (every number, for scripts and the
 * report). Conventions travel with the numbers: the JSON carries a "conventions" object. */
#ifndef GR_METRICS_IO_H
#define GR_METRICS_IO_H

#include <stdio.h>

#include <cjson/cJSON.h>

#include "compare/flip.h"
#include "compare/metrics.h"
#include "compare/structure.h"

/* A new JSON object with every field of m and the conventions used (luminance weights, rel
 * MSE epsilon rule, PSNR peaks, SSIM constants, blur sigmas, stderr z and bound). Each set
 * ("metrics": as given, "fitted" with its "fit_mode") carries "scale", "scale_rgb" and "registry": every registered metric by key
 * (compare/registry.h), each described under conventions.registry. +inf PSNR and metrics not computed are written as
 * null (JSON has no infinity). NULL if out of memory. */
cJSON *gr_metrics_to_json(const gr_metrics *m);

/* Prints the metrics as an aligned table (rows: metrics, columns R G B RGB Y) with the
 * scoring counts, exclusions and conventions stated; the fitted table follows if present. */
void gr_metrics_print_table(FILE *f, const gr_metrics *m);

/* The registry's metrics (compare/registry.h) whose cost class is in costs (bit 1 << cost;
 * ~0u: all) and that were computed: one line each with the value as given and after the scale
 * fit ("n/a": not computed for that set), under a header line. Nothing when none is left. */
void gr_metrics_print_summary(FILE *f, const gr_metrics *m, unsigned costs);

/* FLIP (compare/flip.h) as JSON: mode, ppd, tone mapper and exposures (HDR), the scale the
 * test was multiplied by, and the pooled statistics. NULL if out of memory. */
cJSON *gr_flip_to_json(const gr_flip_result *r, double scale);

/* One or two lines stating a FLIP result and its settings, under `label`. */
void gr_flip_print(FILE *f, const char *label, const gr_flip_result *r, double scale);

/* Beam-structure comparison (compare/structure.h) as JSON: the vanishing point, both images'
 * measures (streak contrast, angular power, peak m, annuli with their spectra) and the
 * comparison. NULL if out of memory. */
cJSON *gr_structure_to_json(const gr_structure_compare *c, double vp_x, double vp_y);

/* The structure comparison as a few table lines. */
void gr_structure_print(FILE *f, const gr_structure_compare *c, double vp_x, double vp_y);

#endif
