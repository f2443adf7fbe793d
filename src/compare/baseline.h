/* Baselines: what a technique's verdict (compare/registry.h) is read against. Three images made
 * from the ground truth itself and scored exactly as a technique is (same metrics options,
 * after the same scale fit):
 *   black     every pixel 0 (its fit is undefined: scored as given);
 *   constant  every pixel at the truth's mean R, G, B (any constant fits to it);
 *   blur      the truth blurred by a Gaussian of GR_BASELINE_BLUR_SIGMA px;
 * and a ladder of blurred truths (sigma 0.5 .. 64 px, half-octave steps) whose verdicts turn any
 * verdict into an *equivalent blur*: the Gaussian sigma at which the blurred truth scores the
 * same ("as good as the truth blurred by 6 px"). docs/metrics.md "Baselines". */
#ifndef GR_BASELINE_H
#define GR_BASELINE_H

#include "common/status.h"
#include "compare/metrics.h"
#include "image/image.h"

enum { GR_BASELINE_BLACK = 0, GR_BASELINE_CONSTANT, GR_BASELINE_BLUR, GR_BASELINE_COUNT };

#define GR_BASELINE_BLUR_SIGMA 4.0 /* px: the blurred baseline's Gaussian */
#define GR_BASELINE_LADDER_N 15    /* sigma_k = 0.5 * 2^(k/2) px, k = 0..14: 0.5 .. 64 px */

typedef struct gr_baselines {
    gr_metrics m[GR_BASELINE_COUNT]; /* each baseline's metrics (raw and after the fit) */
    int n_ladder;                    /* rungs computed (GR_BASELINE_LADDER_N) */
    double sigma_px[GR_BASELINE_LADDER_N];
    double verdict[GR_BASELINE_LADDER_N];  /* the blurred truth's verdict after the fit */
    double envelope[GR_BASELINE_LADDER_N]; /* its running maximum: the monotone curve the
                                                equivalent blur is read from */
} gr_baselines;

/* "black", "constant", "blur" (metrics.json keys); NULL outside 0..GR_BASELINE_COUNT-1. */
const char *gr_baseline_key(int i);
/* One line for tables: "black frame", "constant: the truth's mean", "truth blurred, sigma 4 px". */
const char *gr_baseline_label(int i);

/* Scores the three baselines and the ladder against ref (R, G, B [, stderr]) with opt (as a
 * technique's: mask, stderr bound and dof, structure; fit_scale is forced on; FLIP, SSIM and the
 * multi-scale RMSE only for the three baselines, as opt asks). GR_E_INPUT, GR_E_NOMEM. */
gr_status gr_baselines_compute(const gr_image *ref, const gr_metrics_options *opt, gr_baselines *out,
                               gr_error *err);

/* The equivalent blur of a verdict v: the sigma (px) where the ladder's envelope reaches v,
 * linear in (log sigma, verdict) between rungs. *where (may be NULL): 0 inside the ladder, -1
 * when v is below the first rung (returns sigma_px[0]: "< 0.5 px"), +1 above the last (returns
 * the last sigma: "> 64 px"). NaN (and *where 0) for a NaN v or an empty ladder. */
double gr_equivalent_blur(const gr_baselines *b, double v, int *where);

/* "6.2 px", "< 0.5 px", "> 64 px" or "n/a" into buf. */
const char *gr_equivalent_blur_text(const gr_baselines *b, double v, char *buf, size_t n);

#endif
