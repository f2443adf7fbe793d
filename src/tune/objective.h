/* The error of a real-time technique against ground truth images, as a function of a few of
 * its settings: what `godrays sweep` tabulates and `godrays tune` minimizes. One technique
 * instance (context, programs, buffers) serves every evaluation; each case is one frame
 * (water time) and camera view with its own ground truth. docs/tuning.md. */
#ifndef GR_TUNE_OBJECTIVE_H
#define GR_TUNE_OBJECTIVE_H

#include "common/status.h"
#include "compare/metrics.h"
#include "compare/registry.h"
#include "image/image.h"
#include "realtime/technique.h"
#include "scene/scene.h"
#include "tune/paramspec.h"

#define GR_TUNE_MAX_CASES 64

/* The metric a problem minimizes: a registry index (compare/registry.h: "rmse", "ssim",
 * "flip", "structure", ... and any registered one), or GR_TM_WEIGHTED: sum_k w_k v_k /
 * sum_k w_k over the registry's metrics (problem.weights), those in image units (unit
 * "radiance": rmse, msrmse, ...) relative to the case's mean reference Y. Every value is the
 * metric's loss: lower is better, 0 for identical images (1 - SSIM for SSIM). */
typedef int gr_tune_metric;
#define GR_TM_WEIGHTED (-1)

/* A registered metric's key that can be minimized (a finite best value); GR_E_USAGE naming
 * flag and listing the keys for anything else. ("objective", the weighted sum, is chosen by
 * gr_tune_weights_parse.) */
gr_status gr_tune_metric_parse(const char *flag, const char *s, gr_tune_metric *m, gr_error *err);
const char *gr_tune_metric_name(gr_tune_metric m); /* the key; "objective" for GR_TM_WEIGHTED */
/* The metric's loss from a computed set (raw or fit): lower is better, always finite (1e300
 * for a value that is not finite or not computed: FLIP, structure and the registry's own-
 * function metrics need the set computed with them); GR_TM_WEIGHTED needs the weights: use
 * gr_tune_value. */
double gr_tune_metric_value(const gr_metrics_set *set, gr_tune_metric m);

/* "rmse=1,structure=0.5,flip=0.5": weights w[GR_METRIC_MAX] by registry index (unnamed
 * metrics 0; each >= 0, finite, at least one > 0). GR_E_USAGE naming flag and the bad part. */
gr_status gr_tune_weights_parse(const char *flag, const char *s, double w[GR_METRIC_MAX], gr_error *err);

/* `godrays tune`'s default objective (docs/tuning.md "The default objective"): the verdict
 * (compare/registry.h), the relative RMSE of Y after the scale fit (the radiance error,
 * dominated by the low frequencies: the glow) and the beam-structure score, equal weights;
 * the score the leaderboard ranks by. */
#define GR_TUNE_DEFAULT_OBJECTIVE GR_VERDICT_OBJECTIVE

/* A camera view for tuning beyond the scene's own: same position and fov, other direction. */
typedef struct gr_tune_view {
    double yaw_deg, pitch_deg;
} gr_tune_view;

/* Copies base into out with the water time set to time_s and, if view is not NULL, the
 * camera turned to (yaw, pitch) (a look_at camera becomes a yaw/pitch one); re-validated
 * through gr_scene_refresh (errors name the view). */
gr_status gr_tune_make_case(const gr_scene *base, double time_s, const gr_tune_view *view, gr_scene *out,
                            gr_error *err);

/* The cases' prepared FLIP halves kept across evaluations, at most this much in all
 * (compare/flip.h; 83 MB a case at 640 x 360 with 9 exposures). */
#define GR_TUNE_FLIP_KEEP_MAX ((size_t)512 << 20)

typedef struct gr_tune_problem {
    gr_technique *renderer;             /* created by the caller, reused for every render */
    const gr_technique_class *cls;      /* its class: every parameter is one of its settings */
    int n_cases;                        /* 1..GR_TUNE_MAX_CASES */
    const gr_scene *scenes[GR_TUNE_MAX_CASES];
    const gr_image *refs[GR_TUNE_MAX_CASES]; /* ground truth per case (R, G, B [, stderr]) */
    gr_section_store base;              /* settings (cls's struct) the parameters modify
                                           (resolved on init) */
    int n_params;
    gr_tune_param params[GR_TUNE_MAX_PARAMS];
    gr_tune_metric metric;
    int fit;                            /* a gr_fit_mode (compare/fit.h): score the test after the
                                           best scale fit (scale), one per channel (rgb), or not */
    int rgb_per_channel;                /* fold the per-channel factors into the gain_key (an RGB
                                           setting) in the snippet (gr_tune_snippet) */
    double scale_rgb[GR_TUNE_MAX_CASES][3]; /* per case, the per-channel factors of the last
                                           gr_tune_evaluate (1 without fit) */
    int normalize;                      /* a metric in image units (rmse, msrmse) divided by the
                                           case's mean reference Y, so that every frame and view
                                           weighs the same */
    double weights[GR_METRIC_MAX];      /* GR_TM_WEIGHTED: each registry metric's weight */
    /* filled by gr_tune_problem_init when a metric that needs the scene (structure) is used:
     * per case, the beams' vanishing point and the angle to the sun per pixel (its de-glow) */
    double vp[GR_TUNE_MAX_CASES][2];
    int no_vp[GR_TUNE_MAX_CASES];       /* 1: the case's god rays have no vanishing point on its
                                           image (sun direction across the view); a weighted
                                           objective then leaves its needs-scene terms out there */
    float *angles[GR_TUNE_MAX_CASES];
    double stderr_bound;                /* passed to the metrics (0: default) */
    /* filled by gr_tune_problem_init */
    gr_image *scratch, *scratch2;       /* two frames (R, G, B): one compared while the other renders */
    gr_structure_ref *sref[GR_TUNE_MAX_CASES]; /* each case's reference half of the structure
                                           comparison, kept across evaluations (metrics.h) */
    gr_flip_reference *fref[GR_TUNE_MAX_CASES]; /* each case's reference half of FLIP, kept across
                                           evaluations while they hold at most
                                           GR_TUNE_FLIP_KEEP_MAX together (metrics.h) */
    /* accounting since init */
    long long renders;
    double work;                        /* gr_technique_stats_work summed over the renders */
    double render_s, metrics_s;         /* wall time in gr_technique_render / gr_metrics_compute */
    double wall_ms_sum;                 /* sum of the technique's own wall_ms */
    double gpu_ms_sum;                  /* sum of per-pass GPU times (-1 entries skipped) */
    int gpu_timed;                      /* 1 if any GPU time was available */
} gr_tune_problem;

/* The problem's value of one case from its computed set: the metric (normalized as asked),
 * or the weighted sum. */
double gr_tune_value(const gr_tune_problem *p, const gr_metrics_set *set);

/* Resolves base (scene-derived defaults from case 0) and allocates the scratch frame. The
 * caller fills renderer, cls, cases, base, params, metric, fit first. GR_E_INPUT if the cases
 * differ in size from their references; GR_E_USAGE if a parameter is not a setting of cls;
 * GR_E_NOMEM. */
gr_status gr_tune_problem_init(gr_tune_problem *p, gr_error *err);
void gr_tune_problem_free(gr_tune_problem *p); /* frees what init allocated; accepts NULL */

/* The settings for parameter values x[0..n_params). */
/* The settings (cls's struct, settings_size bytes) for parameter values x[0..n_params). */
gr_status gr_tune_settings_at(const gr_tune_problem *p, const double *x, void *out, gr_error *err);

/* Renders every case at x and scores it: *mean = mean over the cases of the metric;
 * per_case[i] (may be NULL) = each case's value, scale[i] (may be NULL) = the fitted scale
 * (1 without fit). */
gr_status gr_tune_evaluate(gr_tune_problem *p, const double *x, double *mean, double *per_case, double *scale,
                           gr_error *err);

/* Renders case i at settings s into out (frame-sized, R, G, B) and computes all metrics
 * (SSIM and blurs included) into m (may be NULL). */
gr_status gr_tune_render_case(gr_tune_problem *p, int i, const void *s, gr_image *out, gr_metrics *m,
                              gr_error *err);

/* The settings at x as a snippet ready to paste into the scene: {"NAME": {KEY: value, ...}}
 * with every parameter (RGB settings as [r, g, b] = base x scale) rounded to 5 significant
 * digits; with scale given (the fitted factors, may be NULL: none) also the class's gain_key:
 * with p->rgb_per_channel its [r, g, b] x (scale[0], scale[1], scale[2]) (the per-channel fit
 * folded into the colour; a gain that is also a parameter gets it on top of its tuned value),
 * else, unless the gain is a parameter or the class has none, gain x scale[0] when scale[0] > 0
 * and != 1. malloc'd text (caller frees); NULL on failure. */
char *gr_tune_snippet(const gr_tune_problem *p, const double *x, const double *scale);

/* The mean over the cases of p->scale_rgb (the last evaluation's per-channel factors). */
void gr_tune_mean_scale_rgb(const gr_tune_problem *p, double out[3]);

/* The objective for gr_opt_minimize: user = gr_tune_problem. */
gr_status gr_tune_objective(void *user, const double *x, double *f, gr_error *err);

#endif
