/* The ground truth's memory estimate (memory.h). */
#include "reference/memory.h"

#include <math.h>
#include <stdio.h>

#include "common/memlimit.h"

/* Bytes per item of what a render allocates (memory.h): per pixel and batch a 3-double sum
 * and a uint32 count; per pixel the two AOVs (2 floats) and the 8-channel float image; per
 * surface cell two triangles (2 x (128 + 4) B) and a vertex (24 + 40 + 16 B); per beam
 * primitive its box, id and grid entries; the primitive budget (reference/beams.h). */
enum { PER_PIXEL_BATCH = 3 * 8 + 4, PER_PIXEL_AOV = 16, PER_PIXEL_IMAGE = 32, PER_CELL = 344, PER_PRIM = 160 };
static const double PRIM_BUDGET = 16777216.0; /* 2^24 */

double gr_ref_memory_estimate(const gr_scene *scene, const gr_ref_info *info)
{
    const double px = (double)scene->camera.width * (double)scene->camera.height;
    const double B = scene->reference.batches, sr = scene->reference.surface_res, cc = info->cone_cells;
    /* the sets of one pass at a time; the bias probe's fourth level replaces the near set by
     * its finer one (reference/probe.c, gr_ref_near_fine): the larger counts */
    const double cells = sr * sr, nc = fmax(info->near_cells, info->probe_near_cells);
    return px * (PER_PIXEL_BATCH * B + PER_PIXEL_AOV + PER_PIXEL_IMAGE) + (cells + cc + nc) * PER_CELL +
           (fmin(2.0 * cells, PRIM_BUDGET) + fmin(2.0 * cc, PRIM_BUDGET) + fmin(2.0 * nc, PRIM_BUDGET)) * PER_PRIM;
}

gr_status gr_ref_memory_check(const gr_scene *scene, const gr_ref_info *info, gr_error *err)
{
    char detail[340], cone[80] = "";
    if (info->cone_cells > 0.0)
        snprintf(cone, sizeof cone, ", refine_factor %d (%.0f cells near the camera)", scene->reference.refine_factor,
                 info->cone_cells);
    char near[160] = "";
    if (info->near_cells > 0.0)
        snprintf(near, sizeof near, ", near_factor %d within %.1f m of the camera (%.0f cells%s)", info->near_factor,
                 info->near_radius_m, fmax(info->near_cells, info->probe_near_cells),
                 info->probe_near_cells > info->near_cells ? " at the bias probe's 2x finer level" : "");
    snprintf(detail, sizeof detail, "%d x %d pixels x %d batches, surface_res %d%s%s", scene->camera.width,
             scene->camera.height, scene->reference.batches, scene->reference.surface_res, cone, near);
    return gr_memlimit_check("the ground truth", gr_ref_memory_estimate(scene, info), detail, err);
}
