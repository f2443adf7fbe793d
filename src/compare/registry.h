/* The metric registry: one descriptor per headline metric (a single number per comparison and
 * test scaling), the one place a metric is defined. Everything that lists metrics iterates it:
 * `godrays compare` (text and JSON), `godrays run`'s metrics.json, report tables and
 * leaderboard, `sweep`/`tune --metric/--objective`. Adding a metric = one descriptor: a line in
 * registry.c's builtins[] (with its extract function), or gr_metric_register at run time with a
 * compute function (docs/architecture.md "Where a new metric goes"; formulas: docs/metrics.md).
 *
 * The per-row statistics of compare's big table (mean, MAE, PSNR, max error per R, G, B, RGB, Y)
 * are not registry metrics: they are the rows of compare/results.h, written by metrics_io. */
#ifndef GR_REGISTRY_H
#define GR_REGISTRY_H

#include "common/status.h"
#include "compare/results.h"
#include "image/image.h"

#define GR_METRIC_KEY_MAX 32 /* key length limit, terminator included */

/* Which way is better. NEARER: nearer `best` (a signed error such as a bias). */
typedef enum gr_metric_better { GR_METRIC_LOWER = 0, GR_METRIC_HIGHER, GR_METRIC_NEARER } gr_metric_better;

/* The unit of a value. RADIANCE: the images' own unit (scales with them; the tuning objective
 * divides it by the mean reference luminance to make it dimensionless); UNITLESS: a ratio or
 * score. */
typedef enum gr_metric_unit { GR_METRIC_UNITLESS = 0, GR_METRIC_RADIANCE } gr_metric_unit;

/* What a metric costs: the part of gr_metrics_compute it needs, cheapest first. A caller that
 * wants only some metrics (the tuning objective) turns on only their parts. */
typedef enum gr_metric_cost {
    GR_METRIC_COST_PASS = 0, /* the one pointwise pass every comparison makes */
    GR_METRIC_COST_SSIM,     /* five radius-5 blurs of luminance (gr_metrics_options.skip_ssim) */
    GR_METRIC_COST_BLUR,     /* one blur of the difference per scale (skip_blur) */
    GR_METRIC_COST_FLIP,     /* HDR-FLIP: several exposures of a perceptual filter (options.flip) */
    GR_METRIC_COST_STRUCTURE,/* beam structure around the vanishing point (options.structure) */
    GR_METRIC_COST_OWN,      /* the descriptor's own compute function (skip_extra) */
    GR_METRIC_COST_COUNT
} gr_metric_cost;

/* What a compute function sees: both images as given (the test NOT yet multiplied by scale),
 * the set's test scale, which pixels are scored and the channels compared. */
typedef struct gr_metric_input {
    const gr_image *ref, *test;
    double scale;                 /* compare scale * test with ref */
    const unsigned char *scored;  /* width * height, row-major: 1 = scored */
    long long n_scored;
    int ref_rgb[3], test_rgb[3];  /* channel indices (compare/channels.h) */
} gr_metric_input;

typedef struct gr_metric_desc {
    const char *key;              /* [a-z][a-z0-9_]*: JSON key, --metric/--objective name */
    const char *label;            /* short, for table headers ("RMSE Y") */
    const char *doc;              /* one line: what it is (docs/metrics.md has the formula) */
    gr_metric_unit unit;
    gr_metric_better better;
    double best;                  /* the value of identical images (0 for errors, 1 for SSIM) */
    int needs_scene;              /* needs the scene's geometry (the beams' vanishing point) */
    gr_metric_cost cost;
    int leaderboard;              /* a column of `godrays run`'s leaderboard (after the fit; raw too
                                     for those that are not the verdict's columns: report/leaderboard.h) */
    /* exactly one of: */
    double (*extract)(const gr_metrics_set *s); /* from a computed set; NaN: its part was not
                                     computed */
    gr_status (*compute)(const gr_metric_input *in, void *user, double *value, gr_error *err);
    void *user;                   /* passed to compute */
} gr_metric_desc;

/* The built-ins, in registry order (registry.c's builtins[]). */
enum {
    GR_METRIC_RMSE = 0, GR_METRIC_REL_RMSE, GR_METRIC_RELMSE, GR_METRIC_BIAS, GR_METRIC_SSIM, GR_METRIC_MSRMSE,
    GR_METRIC_FLIP, GR_METRIC_STRUCTURE, GR_METRIC_VERDICT, GR_METRIC_N_BUILTIN
};

/* The verdict (docs/metrics.md "The verdict"): the one score every ranking uses (`run`'s
 * leaderboard, `pareto`'s error axis) and `tune`'s default objective, the weighted mean of
 * these registry metrics' dimensionless losses (gr_metric_weighted): the relative RMSE of Y
 * (after the fit, on the fit set) and the beam-structure score, equal weights. Without a
 * vanishing point (no structure computed) it is the relative RMSE alone. The weights by
 * registry index are gr_metric_verdict_weights'; this text is the same as an --objective. */
#define GR_VERDICT_OBJECTIVE "rmse=1,structure=1"

/* w[GR_METRIC_MAX]: the verdict's weight per registry index (0 for the metrics it leaves out). */
void gr_metric_verdict_weights(double w[GR_METRIC_MAX]);

/* The weighted mean sum_k w_k L_k / sum_k w_k of the losses L_k = gr_metric_loss of each metric
 * with w_k > 0, each made dimensionless: metrics in image units (unit RADIANCE) divided by the
 * set's mean reference Y when it is > 0. A needs-scene metric that was not computed (NaN: no
 * vanishing point) is left out with its weight; a loss that is not finite counts 1e300, and so
 * does a result that is not finite or has no weight left. What `tune --objective` minimizes
 * per case (tune/objective.h) and, with the verdict's weights, the verdict. */
double gr_metric_weighted(const gr_metrics_set *s, const double w[GR_METRIC_MAX]);

int gr_metric_count(void);
const gr_metric_desc *gr_metric_at(int i); /* NULL outside 0..count-1 */
int gr_metric_find(const char *key);       /* index, or -1 */

/* Adds a metric (copied; its strings and user must outlive the registry's use). GR_E_INPUT
 * naming the key for a bad or taken key, missing label or doc, not exactly one of extract and
 * compute, compute without cost GR_METRIC_COST_OWN (or the reverse), a full registry. Not
 * thread-safe: register before computing anything, as the techniques are. */
gr_status gr_metric_register(const gr_metric_desc *d, gr_error *err);

/* Metric i's value in set s: extract(s), or the value its compute function gave. NaN when not
 * computed (its part was skipped, or i is not registered). */
double gr_metric_value(const gr_metrics_set *s, int i);

/* v as a loss: lower is better, 0 at `best` (v - best, best - v or |v - best|). NaN stays NaN. */
double gr_metric_loss(const gr_metric_desc *d, double v);

/* Whether a metric can be minimized: its best value is finite. */
int gr_metric_is_objective(const gr_metric_desc *d);

/* The registered keys joined by sep ("rmse, rel_rmse, ..."), objectives only if asked, into
 * buf (truncated to n). */
void gr_metric_keys(char *buf, size_t n, const char *sep, int objectives_only);

const char *gr_metric_unit_name(gr_metric_unit u);     /* "1", "radiance" */
const char *gr_metric_better_name(gr_metric_better b); /* "lower", "higher", "nearer best" */
const char *gr_metric_cost_name(gr_metric_cost c);     /* "pass", "ssim", "blur", "flip", "structure", "own" */

#endif
