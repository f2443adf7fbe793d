/* Error metrics between a reference (ground truth) and a test image: per RGB channel, pooled
 * over RGB (OpenImageIO idiff's convention) and on Rec. 709 luminance. Formulas, conventions
 * and degenerate cases: docs/metrics.md. All sums in double; no result is ever NaN.
 *
 * Cheap to call per render: one pass for the pointwise metrics, five radius-5 blurs for SSIM,
 * and one blur of the difference per multi-scale sigma (skippable through the options). */
#ifndef GR_METRICS_H
#define GR_METRICS_H

#include "common/status.h"
#include "compare/flip.h"
#include "compare/structure.h"
#include "image/image.h"

/* Rows of the result. GR_MCH_RGB pools the three channels' values (3 N samples): its MAE,
 * RMSE, PSNR (idiff peak) and max error are what `idiff` prints for an RGB image. */
typedef enum gr_metric_channel {
    GR_MCH_R = 0, GR_MCH_G, GR_MCH_B, GR_MCH_RGB, GR_MCH_Y, GR_MCH_COUNT
} gr_metric_channel;

#define GR_METRICS_NSCALES 3
/* Blur standard deviations (px) of the multi-scale RMSE. */
extern const double gr_metrics_blur_sigmas[GR_METRICS_NSCALES];

/* Rec. 709 luminance weights (linear RGB). */
#define GR_LUM_R 0.2126
#define GR_LUM_G 0.7152
#define GR_LUM_B 0.0722

/* Defaults (docs/metrics.md says why). */
#define GR_METRICS_STDERR_Z 2.0        /* |t - r| <= z * stderr counts as "not significant" */
#define GR_METRICS_STDERR_BOUND 0.5    /* default bound on the reference's relative stderr */
#define GR_METRICS_RELMSE_K 1e-2       /* rel MSE epsilon = K * mean(|r|)^2 ... */
#define GR_METRICS_RELMSE_FLOOR 1e-30  /* ... but at least this (all-zero reference) */
#define GR_SSIM_K1 0.01
#define GR_SSIM_K2 0.03
#define GR_SSIM_SIGMA 1.5
#define GR_SSIM_RADIUS 5               /* 11 x 11 window */

typedef struct gr_channel_metrics {
    double ref_mean, test_mean;   /* over scored samples */
    double bias;                  /* mean(t - r) */
    double mae;                   /* mean |t - r| */
    double mse, rmse;             /* mean (t - r)^2, its root */
    double rel_mse;               /* mean (t - r)^2 / (r^2 + rel_mse_eps) */
    double rel_mse_eps;           /* max(K mean(|r|)^2, FLOOR) */
    double peak_ref;              /* max r over scored samples; 1 if none is > 0 */
    double psnr_ref_db;           /* 20 log10(peak_ref / rmse); +INFINITY when rmse = 0 */
    double peak_idiff;            /* max(1, max r, max t): OpenImageIO compare()'s peak */
    double psnr_idiff_db;         /* 20 log10(peak_idiff / rmse); 20 log10(1 / rmse) for LDR */
    double max_abs_err;           /* max |t - r|; first in scan order (y, x, channel) */
    int max_x, max_y;             /* where (x right, y down from the top row); -1 if no sample */
    int max_c;                    /* the channel (0 R, 1 G, 2 B) for GR_MCH_RGB, else -1 */
    double max_ref, max_test;     /* the two values there */
    double rmse_blur[GR_METRICS_NSCALES]; /* RMSE after blurring at gr_metrics_blur_sigmas[] */
    long long n_not_significant;  /* with stderr: samples with |t - r| <= z stderr (+ |bias| when REF
                                     has bias channels): what noise and bias together explain */
    long long n_samples;          /* scored samples of this row (3 n_scored for GR_MCH_RGB) */
} gr_channel_metrics;

/* One complete set of metrics for one test scaling. */
typedef struct gr_metrics_set {
    double scale;                 /* factor applied to TEST before comparing (1 unless fitted) */
    gr_channel_metrics ch[GR_MCH_COUNT];
    double ssim_y;                /* mean SSIM of luminance over scored pixels (1 if none) */
    int have_ssim, have_blur;     /* 0 when skipped through the options */
    int have_flip;                /* options.flip given: */
    gr_flip_result flip;          /* FLIP of scale * TEST, pooled over the scored pixels */
    int have_structure;           /* options.structure given: (scale-invariant: the same in both sets) */
    double structure_corr;        /* band-pass correlation (compare/structure.h) */
    double structure_contrast_err;/* |ln(streak contrast ratio)| */
    double structure_lsd;         /* log-spectral distance */
    double structure_score;       /* ((1 - corr) / 2 + min(contrast_err, 3) / 3 + min(lsd, 3) / 3) / 3,
                                     in [0, 1], 0 = the truth's structure (docs/metrics.md) */
} gr_metrics_set;

typedef struct gr_metrics {
    int width, height;
    int ref_rgb[3], test_rgb[3];  /* channel indices used (the same index 3 times: gray) */
    long long n_pixels;           /* width * height */
    long long n_scored;           /* pixels that every metric uses */
    long long n_masked_out;       /* mask value 0 */
    long long n_stderr_excluded;  /* in the mask, but reference luminance rel. stderr > bound */
    int have_stderr;              /* REF carried stderr.R/G/B */
    double stderr_bound;          /* the bound used (INFINITY: none) */
    double stderr_z;              /* Student t975(stderr_dof), or GR_METRICS_STDERR_Z when unknown */
    int stderr_dof;               /* degrees of freedom of the stderr (0: unknown, normal) */
    int have_bias;                /* REF carried bias.R/G/B: not significant = |d| <= z stderr + |bias| */
    double ssim_L;                /* SSIM dynamic range: peak_ref of luminance */
    double ssim_c1, ssim_c2;      /* (K1 L)^2, (K2 L)^2 */
    gr_metrics_set raw;           /* TEST as given */
    int have_fit;                 /* options.fit_scale was set */
    int fit_defined;              /* <t, t> > 0 over the scored samples (else scale 1) */
    gr_metrics_set fit;           /* TEST times a = <t, r> / <t, t> (RGB pooled) */
} gr_metrics;

/* Options; a zero-initialized struct asks for the defaults. */
typedef struct gr_metrics_options {
    const gr_image *mask;         /* same size; its first channel nonzero = scored; NULL: all */
    double stderr_bound;          /* 0: GR_METRICS_STDERR_BOUND; INFINITY: no exclusion */
    int fit_scale;                /* also compute the best scale fit and the metrics after it */
    int skip_ssim;                /* leave SSIM out (cheap sweeps) */
    int skip_blur;                /* leave the multi-scale RMSE out */
    int stderr_dof;               /* degrees of freedom of REF's stderr (batches - 1; the reference
                                     writes godrays:stderr_dof): z = Student t975; 0: z = 2 */
    const gr_flip_options *flip;  /* also FLIP with these options (scored and test_scale are
                                     set here); NULL: no FLIP */
    const gr_structure_options *structure; /* also the structure comparison (scored is set
                                     here; vanishing point required); NULL: none */
} gr_metrics_options;

/* The channels compared in img: "R","G","B" by name; else the first three channels; a 1- or
 * 2-channel image is gray (channel 0 three times). */
void gr_metrics_pick_rgb(const gr_image *img, int rgb[3]);

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

/* Short name of a row: "R", "G", "B", "RGB", "Y". */
const char *gr_metric_channel_name(gr_metric_channel ch);

#endif
