/* Metrics of image sequences: per frame, and between consecutive frames (flicker, swimming).
 * Derivations: docs/metrics.md "Time".
 *
 *  - frame-difference error: e_i = a (T_{i+1} - T_i) - (R_{i+1} - R_i) on luminance, whose
 *    mean square over scored pixels is the test's error in how the image *changes*, plus the
 *    truth's own Monte Carlo noise in R_{i+1} - R_i. The truth's renders are independent, so
 *    that noise has variance s_{i+1}^2 + s_i^2 per pixel (s = the luminance standard error from
 *    the stderr.R/G/B channels); its mean is subtracted (an unbiased estimate of the noiseless
 *    error's mean square, clamped at 0);
 *  - flicker ratio: RMS of the test's change over RMS of the truth's (noise taken out): 1 moves
 *    as much as the truth, > 1 flickers, < 1 is too static;
 *  - beam drift: the angle by which the angular fluctuation around the vanishing point
 *    (compare/structure.h) moves from frame to frame (the lag of the circular cross-correlation
 *    peak), in the test and in the truth; their difference is how far the test's beams swim
 *    away from the truth's motion. */
#ifndef GR_TEMPORAL_H
#define GR_TEMPORAL_H

#include "common/status.h"
#include "compare/structure.h"
#include "image/image.h"

typedef struct gr_temporal_options {
    double scale;                    /* a applied to the test frames; 0: 1 */
    const unsigned char *scored;     /* per pixel, may be NULL (all) */
    gr_structure_options structure;  /* vanishing point and angular sampling for the drift */
    double drift_r0, drift_r1;       /* radii of the ring followed; 0 0: the structure defaults' span */
    double max_drift_deg;            /* largest drift searched per frame; 0: 20 */
    int skip_drift;                  /* 1: no drift (no vanishing point needed) */
} gr_temporal_options;

typedef struct gr_temporal_frame {   /* frame i alone */
    double rmse_y;                   /* RMS of a T_i - R_i (luminance) over scored pixels */
    double rel_rmse_y;               /* rmse_y / RMS of R_i */
} gr_temporal_frame;

typedef struct gr_temporal_pair {    /* frames i -> i + 1 */
    double diff_rmse_raw;            /* RMS of a dT - dR */
    double truth_noise_rms;          /* RMS standard error of dR (0 without stderr channels) */
    double diff_rmse;                /* sqrt(max(0, raw^2 - noise^2)) */
    double truth_diff_rms;           /* sqrt(max(0, mean dR^2 - noise^2)) */
    double test_diff_rms;            /* RMS of a dT */
    double drift_ref_deg, drift_test_deg; /* signed: + toward larger theta = atan2(y - vy, x - vx),
                                             y down (clockwise as seen) */
    double drift_err_deg;            /* |test - ref| */
} gr_temporal_pair;

typedef struct gr_temporal_summary {
    int n_frames, have_stderr, have_drift;
    double frame_rmse_mean;          /* mean of rmse_y over the frames */
    double diff_rmse;                /* sqrt(mean over pairs of diff_rmse^2) */
    double rel_diff_rmse;            /* diff_rmse / sqrt(mean truth_diff_rms^2) (0 if that is 0) */
    double flicker_ratio;            /* sqrt(sum test_diff_rms^2 / sum truth_diff_rms^2) */
    double drift_err_mean_deg;       /* mean of drift_err_deg */
} gr_temporal_summary;

/* n >= 2 frames of ref and test, all the same size. frames (n entries) and pairs (n - 1) may
 * be NULL. ref frames may carry stderr.R/G/B. GR_E_INPUT for sizes, n < 2, non-finite samples
 * and (unless skip_drift) structure options; GR_E_NOMEM. */
gr_status gr_temporal_compute(const gr_image *const *ref, const gr_image *const *test, int n,
                              const gr_temporal_options *opt, gr_temporal_frame *frames, gr_temporal_pair *pairs,
                              gr_temporal_summary *sum, gr_error *err);

/* The drift (degrees, signed) between two angular profiles of n_theta samples (from
 * gr_structure_angular_profile): the lag of the largest circular cross-correlation over the
 * angles valid in both, within +- max_deg, refined by a parabola through the peak. */
double gr_temporal_profile_drift(const double *f0, const unsigned char *v0, const double *f1, const unsigned char *v1,
                                 int n_theta, double max_deg);

#endif
