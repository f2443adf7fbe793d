/* Error metrics between a reference (ground truth) and a test image: per RGB channel, pooled
 * over RGB (OpenImageIO idiff's convention) and on Rec. 709 luminance, and every metric of the
 * registry (compare/registry.h). Formulas, conventions and degenerate cases: docs/metrics.md.
 * All sums in double; no result is ever NaN (a registry metric not computed reads NaN).
 *
 * Cheap to call per render: one pass for the pointwise metrics, five radius-5 blurs for SSIM,
 * and one blur of the difference per multi-scale sigma (skippable through the options). */
#ifndef GR_METRICS_H
#define GR_METRICS_H

#include "common/status.h"
#include "compare/channels.h"
#include "compare/fit.h"
#include "compare/flip.h"
#include "compare/results.h"
#include "compare/structure.h"
#include "image/image.h"

/* Blur standard deviations (px) of the multi-scale RMSE. */
extern const double gr_metrics_blur_sigmas[GR_METRICS_NSCALES];

/* Defaults (docs/metrics.md says why). */
#define GR_METRICS_STDERR_Z 2.0        /* |t - r| <= z * stderr counts as "not significant" */
#define GR_METRICS_STDERR_BOUND 0.5    /* default bound on the reference's relative stderr */
#define GR_METRICS_RELMSE_K 1e-2       /* rel MSE epsilon = K * mean(|r|)^2 ... */
#define GR_METRICS_RELMSE_FLOOR 1e-30  /* ... but at least this (all-zero reference) */
/* FLIP of the raw and the fitted test share the reference's half when it takes at most this
 * (compare/flip.h: 40 bytes a pixel an exposure; 83 MB at 640 x 360 with 9 exposures) */
#define GR_METRICS_FLIP_PREPARE_MAX ((size_t)256 << 20)
/* ... and one shared by a whole set of comparisons (the report's techniques, the baselines):
 * it spares every FLIP its own reference planes (104 bytes a pixel per FLIP running), so it
 * pays for itself in memory too; 1 GiB covers 1920 x 1080 with 9 exposures (746 MB). */
#define GR_FLIP_SHARED_PREPARE_MAX ((size_t)1 << 30)
#define GR_SSIM_K1 0.01
#define GR_SSIM_K2 0.03
#define GR_SSIM_SIGMA 1.5
#define GR_SSIM_RADIUS 5               /* 11 x 11 window */

/* Options; a zero-initialized struct asks for the defaults. */
typedef struct gr_metrics_options {
    const gr_image *mask;         /* same size; its first channel nonzero = scored; NULL: all */
    double stderr_bound;          /* 0: GR_METRICS_STDERR_BOUND; INFINITY: no exclusion */
    int fit_scale;                /* a gr_fit_mode (compare/fit.h): 0 none; 1 (GR_FIT_SCALE) also the
                                     best single scale fit and the metrics after it; 2 (GR_FIT_RGB)
                                     one factor per channel, the metrics on the per-channel-scaled
                                     test (docs/metrics.md, "Scale fits") */
    int skip_ssim;                /* leave SSIM out (cheap sweeps) */
    int skip_blur;                /* leave the multi-scale RMSE out */
    int stderr_dof;               /* degrees of freedom of REF's stderr (batches - 1; the reference
                                     writes godrays:stderr_dof): z = Student t975; 0: z = 2 */
    const gr_flip_options *flip;  /* also FLIP with these options (scored and test_scale are
                                     set here); NULL: no FLIP */
    const gr_structure_options *structure; /* also the structure comparison (scored is set
                                     here; vanishing point required); NULL: none */
    int skip_extra;               /* leave out the registry's metrics that have their own compute
                                     function (compare/registry.h; cost GR_METRIC_COST_OWN) */
    gr_structure_ref **structure_ref; /* may be NULL; else the reference's structure half kept
                                     between calls (a search): used when it matches this ref and
                                     these options (gr_structure_ref_matches), else remade into
                                     it. The caller destroys *structure_ref */
    int flip_fit_only;            /* with fit_scale: FLIP of the fitted test only (the raw set's
                                     have_flip 0), for a search that reads only the fitted set */
    gr_flip_reference **flip_ref; /* may be NULL; else the reference's half of FLIP kept between
                                     calls, as structure_ref (gr_flip_reference_matches; made with
                                     at most GR_METRICS_FLIP_PREPARE_MAX, else left NULL). Without
                                     it, a call that computes FLIP twice (raw and fitted) prepares
                                     its own. The caller destroys *flip_ref */
} gr_metrics_options;

/* Computes every metric between ref and test (same size; any channel layouts). ref may carry
 * "stderr.R", "stderr.G", "stderr.B" channels (the standard error of each pixel's estimate):
 * then pixels whose luminance relative stderr exceeds the bound are not scored (counted in
 * n_stderr_excluded) and significance counts are reported. GR_E_INPUT for NULL or differently
 * sized images or mask, a negative or NaN bound; GR_E_NOMEM. */
gr_status gr_metrics_compute(const gr_image *ref, const gr_image *test, const gr_metrics_options *opt,
                             gr_metrics *out, gr_error *err);

/* The per-pixel scoring decision of gr_metrics_compute, for callers that draw or tabulate per
 * pixel: scored[p] = 1 if pixel p (row-major) is scored, 0 if the mask's first channel is 0 or
 * the reference luminance relative stderr exceeds stderr_bound (0: the default). The counts
 * (may be NULL) get the pixels dropped by each rule (the mask is tested first). GR_E_INPUT
 * for a mask of another size or a negative or NaN bound. */
gr_status gr_metrics_scored_pixels(const gr_image *ref, const gr_image *mask, double stderr_bound,
                                   unsigned char *scored, long long *n_masked_out, long long *n_stderr_excluded,
                                   gr_error *err);

/* The structure score of a comparison (see gr_metrics_set.structure_score). */
double gr_structure_score(const gr_structure_compare *c);

#endif
