/* The image and its statistics (internal to reference/): from a render's sums (or merged
 * parts') to the pixels, the per-pixel standard errors, the image-level errors, the
 * metadata; the same code and floating-point order either way (docs/reference.md,
 * "Error bars"). */
#ifndef GR_REF_STATS_H
#define GR_REF_STATS_H

#include "reference/march.h"
#include "reference/renderer.h"

typedef struct ref_errors {
    double rel_mean, rel_p95, frac_1pct, mean, p95;      /* of the RGB mean */
    double ch_rel_mean[3], ch_rel_p95[3], ch_frac_1pct[3]; /* the same per channel (issue 30) */
    double block8[3]; /* 8 x 8 block noise: median, p95, max of se / max(block mean, image mean), worst channel */
    double block8_p99;  /* its 99th percentile (steadier than the max of thousands of 7-dof estimates) */
    int block8_at[2];   /* the worst block's first pixel (x, y); -1 without blocks */
} ref_errors;

/* The q-quantile of v[0 .. n) (sorts v; linear between ranks). */
double gr_ref_percentile(double *v, size_t n, double q);
/* --target-error E: the relative standard errors come from B batch means, B - 1 degrees of
 * freedom; the target is met when their Student-t 95 % half-widths are within those a
 * known standard error E would give, t_{0.975, B-1} se <= 1.96 E (docs/reference.md); for the
 * RGB mean and for each of R, G and B. */
int gr_ref_target_met(const ref_errors *e, int batches, double target);
/* Image-level error estimates from the batch images (docs/reference.md, "Error bars"): the
 * RGB mean's and each channel's, and with `blocks` the 8 x 8 block noise (else block8 is
 * zero), computed on up to `threads` threads (the same values for any count). *st: GR_OK, or
 * GR_E_NOMEM (no message) when out of memory. Returns the time with two or more of its threads
 * busy (for the phases' serial part). */
double gr_ref_image_errors(const ref_accum *acc, int threads, int blocks, ref_errors *e, gr_status *st);
/* The end of a render from its sums: image, error bars, statistics, metadata (shared by
 * gr_ref_render and gr_ref_assemble, so merged parts give the same bytes). */
gr_status gr_ref_finish(gr_ref_renderer *r, const ref_accum *acc, const ref_march_totals *tot, double wall_s,
                        gr_ref_result *out, gr_error *err);

#endif
