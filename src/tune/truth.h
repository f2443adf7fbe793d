/* The ground truth for sweeps, tuning and the speed/error study: read from the reference
 * cache of `godrays run` (src/report/cache.h) when a valid entry exists, else rendered with
 * the Embree integrator (reference/integrator.h) and stored there for later runs. */
#ifndef GR_TUNE_TRUTH_H
#define GR_TUNE_TRUTH_H

#include "common/status.h"
#include "image/image.h"
#include "scene/scene.h"

typedef struct gr_truth_info {
    int cached;            /* 1: read from the cache */
    int stored;            /* 1: rendered and stored in the cache */
    double seconds;        /* time to obtain it (read or render) */
    char path[4200];       /* cache file ("" when the cache is off) */
    char note[1200];       /* why the cache was not used, if it was not */
} gr_truth_info;

/* Gets the ground truth of scene (its camera, time and reference settings). use_cache = 0
 * always renders and stores nothing. progress = 1 shows the integrator's progress bar.
 * *img is the caller's (R, G, B, stderr.R/G/B). GR_E_INTERRUPTED if stopped. */
gr_status gr_truth_get(const gr_scene *scene, int use_cache, int progress, gr_image **img, gr_truth_info *info,
                       gr_error *err);

/* Renders scene's ground truth without the cache; *seconds = wall time (for timing studies). */
gr_status gr_truth_render(const gr_scene *scene, int progress, gr_image **img, double *seconds, gr_error *err);

#endif
