/* The results of a comparison as plain structs: per row (R, G, B, pooled RGB, Y) and per test
 * scaling (as given, after the best scale fit). Filled by gr_metrics_compute (compare/metrics.h);
 * read by the registry's extract functions (compare/registry.h), the text and JSON writers
 * (compare/metrics_io.h), the report and the tuning objective. Types only: this header sits
 * below both metrics and registry, so that neither includes the other's header back. */
#ifndef GR_RESULTS_H
#define GR_RESULTS_H

#include "compare/channels.h"
#include "compare/flip.h"

#define GR_METRICS_NSCALES 3  /* blur scales of the multi-scale RMSE (gr_metrics_blur_sigmas) */
#define GR_METRIC_MAX 32      /* registered metrics at most, built-ins included */

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
    double scale;                 /* factor applied to TEST before comparing (1 unless fitted); for
                                     the per-channel fit its luminance equivalent
                                     (gr_fit_luminance_scale): what a single factor stands for */
    double scale_rgb[3];          /* the factors applied to TEST's R, G, B (all = scale unless the
                                     fit is per channel) */
    gr_channel_metrics ch[GR_MCH_COUNT];
    double ssim_y;                /* mean SSIM of luminance over scored pixels (1 if none) */
    int have_ssim, have_blur;     /* 0 when skipped through the options */
    int have_flip;                /* options.flip given: */
    gr_flip_result flip;          /* FLIP of scale * TEST, pooled over the scored pixels */
    int have_structure;           /* options.structure given: (scale-invariant: the same in both sets) */
    double structure_corr;        /* band-pass correlation (compare/structure.h) */
    double structure_contrast_err;/* |ln(streak contrast ratio)| */
    double structure_contrast_ratio; /* streak contrast, test / truth (1 = as streaky as the truth) */
    double structure_lsd;         /* log-spectral distance */
    double structure_score;       /* ((1 - corr) / 2 + min(contrast_err, 3) / 3 + min(lsd, 3) / 3) / 3,
                                     in [0, 1], 0 = the truth's structure (docs/metrics.md) */
    int n_extra;                  /* registry size when the set was computed: */
    double extra[GR_METRIC_MAX];  /* extra[i]: registry metric i's value when it has its own compute
                                     function (compare/registry.h); NaN: not computed, or not such
                                     a metric (read every metric through gr_metric_value) */
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
    int fit_mode;                 /* its gr_fit_mode (compare/fit.h): 0 none, 1 scale, 2 rgb */
    int fit_defined;              /* <t, t> > 0 over the scored samples (else scale 1); per channel:
                                     for at least one channel (a black channel keeps factor 1) */
    gr_metrics_set fit;           /* TEST times a = <t, r> / <t, t> (RGB pooled), or each channel c
                                     times a_c = <t_c, r_c> / <t_c, t_c> (fit_mode rgb) */
} gr_metrics;


#endif
