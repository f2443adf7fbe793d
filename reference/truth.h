/* The ground-truth provider: the one way a command gets a ground truth (docs/reference.md,
 * "Getting a ground truth"). gr_truth_get
 *  - looks the scene's truth up in the cache (reference/cache.h) and returns it on a hit;
 *  - else creates the renderer (reference/integrator.h), checks its memory estimate against
 *    the limit before any beam is built (reference/memory.h: --max-memory,
 *    $GODRAYS_MAX_MEMORY), and renders in a held region of common/signals: a first Ctrl-C
 *    (SIGINT) or SIGTERM stops the render at its next check instead of ending the process, a
 *    second ends it at once;
 *  - stores a complete render in the cache for later commands (never a partial one).
 * gr_truth_assemble (merged farm parts) and gr_truth_store (a truth made elsewhere, e.g. by
 * `godrays merge --cache`) are the other two doors; nothing outside reference/ creates a
 * renderer. Library code: it prints nothing (but the progress bar when asked). */
#ifndef GR_REF_TRUTH_H
#define GR_REF_TRUTH_H

#include "common/status.h"
#include "image/image.h"
#include "reference/integrator.h"
#include "scene/scene.h"

typedef struct gr_truth_info {
    int cache_on;          /* 1: a cache directory is in use for this truth */
    int cached;            /* 1: read from the cache */
    int stored;            /* 1: rendered and stored in the cache */
    int passes_per_round;  /* the renderer's passes per round of --target-error (0 when cached) */
    double seconds;        /* time to obtain it (read, or create + render + store) */
    char path[4200];       /* the cache file ("" when the cache is off) */
    char note[1400];       /* why the cache was not used, if it was not: "cache off: ...",
                              "cache entry PATH: ignored: ..." or "not cached: ..." ("" if none) */
    double bias_rel_est;   /* its godrays:bias_surface_rel_est (worst channel, order 2; -1: not
                              estimated), rendered or read from the cache: docs/reference.md 4 */
} gr_truth_info;

/* The line above which the commands call a truth coarse: its surface bias estimate (worst
 * channel, order 2) above 1 % of its image mean (issue 30's quality line) */
#define GR_TRUTH_COARSE_BIAS 0.01

/* 1 when the truth's surface bias estimate (info->bias_rel_est) is above GR_TRUTH_COARSE_BIAS
 * (docs/reference.md 4, "Views with a wide lit region"); msg (if not NULL) gets one line saying
 * so with the remedy (twice scene's surface_res), for the commands' warnings. */
int gr_truth_coarse(const gr_truth_info *info, const gr_scene *scene, char *msg, size_t n);

typedef struct gr_truth_options {
    int use_cache;         /* 1: read the cache first, store a complete render (the renderer's
                              options must then be the defaults but progress: GR_E_USAGE) */
    int keep_partial;      /* 1: a render stopped by a signal is GR_OK with res->partial = 1
                              (godrays reference writes it); 0: GR_E_INTERRUPTED, nothing kept */
    gr_ref_options ref;    /* the integrator's options (progress, aovs, a part's rows and
                              batches, keep_sums); its interrupt is the signals' flag */
    /* Called after a cache miss, just before the render starts (may be NULL): the command
     * says what is coming (info: the cache's state and note so far). */
    void (*before_render)(void *user, const gr_scene *scene, const gr_truth_info *info);
    void *user;
} gr_truth_options;

/* Cache on, partial renders refused, the integrator's defaults (no progress bar). */
void gr_truth_options_default(gr_truth_options *o);

/* The ground truth of scene (its camera, time and reference settings) into res (the caller's;
 * gr_ref_result_free it). From the cache only res->image and res->meta are filled (the
 * statistics are in the metadata). Errors: the renderer's; GR_E_INPUT when over the memory
 * limit (nothing rendered); GR_E_INTERRUPTED when a signal stopped it and !keep_partial. A
 * cache that cannot be read or written is not an error (info->note says why). */
gr_status gr_truth_get(const gr_scene *scene, const gr_truth_options *o, gr_ref_result *res, gr_truth_info *info,
                       gr_error *err);

/* gr_truth_get for the image alone (R, G, B, stderr.R/G/B: *img is the caller's); o NULL:
 * gr_truth_options_default. */
gr_status gr_truth_image(const gr_scene *scene, const gr_truth_options *o, gr_image **img, gr_truth_info *info,
                         gr_error *err);

/* The memory a render of scene would need, renderer's default options (reference/memory.h:
 * *fixed for the process, *pixels for its sums and image, *sets for its beam sets at their
 * peak), from its lit region and its sets sampled; nothing rendered. For sizing jobs
 * (`godrays farm --mem auto`). */
gr_status gr_truth_memory(const gr_scene *scene, double *fixed, double *pixels, double *sets, gr_error *err);

/* What a render of the scene gives (its passes and samples per pass), for checking sums
 * that came from elsewhere before they are assembled; a status other than GR_OK stops. */
typedef gr_status (*gr_truth_sums_check)(void *user, const gr_ref_info *info, gr_error *err);

/* The result a single render of scene gives, from its full sums (merged farm parts,
 * src/farm/parts.h): a renderer with the default options, no pass rendered, check (may be
 * NULL) on the sums, then gr_ref_assemble (the same bytes). wall_s is the parts' time. */
gr_status gr_truth_assemble(const gr_scene *scene, const gr_ref_sums *sums, double wall_s, gr_truth_sums_check check,
                            void *user, gr_ref_result *out, gr_error *err);

/* Stores img and meta as scene's ground truth in the cache, under scene's key (a truth that
 * did not come from gr_truth_get, e.g. merged parts); info->path names the entry. GR_E_IO
 * when there is no usable cache directory or the file cannot be written. */
gr_status gr_truth_store(const gr_scene *scene, const gr_image *img, const gr_metadata *meta, gr_truth_info *info,
                         gr_error *err);

#endif
