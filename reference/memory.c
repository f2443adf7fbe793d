/* The ground truth's memory estimate (memory.h; the model: docs/reliability.md "Memory"). */
#include "reference/memory.h"

#include <math.h>
#include <stdio.h>

#include "common/memlimit.h"

/* Bytes of what a render allocates (reference/integrator.c, beams.c, beam_grid.c):
 * - per pixel and batch a 3-double sum and a uint32 count; per pixel the two AOVs (2 floats)
 *   and the 8-channel float image;
 * - per surface triangle its beam_tri (128 B) and its share of Embree's surface mesh (85 B:
 *   buffers and BVH after rtcCommitScene at build quality low, 75-85 B measured with Embree's
 *   memory monitor on 2^17-2^19 triangles); per vertex its beam_vertex (40 B);
 * - per beam-slab primitive its triangle index (4 B) and its lookup-grid entries, 10 B each
 *   (cell_prim 4 + cell_q 6), as many as the sampled boxes give (gr_beams_entries_per_prim:
 *   7.5-15.4 measured, at most 16);
 * - while a set is built, per vertex its double position and disc Jacobian (40 B) and per
 *   primitive the grid's cell ranges and box ends (2 x 6 int32) and its layer lists (8 B);
 * - FIXED: the process without any set (14 MB peak RSS: flat water at 8 x 8 without its
 *   preview) and the libraries of the OpenImageIO module that writes the PNG preview (their
 *   pages: 136-137 MiB peak with it at 8 x 8 and 160 x 90, of which 30 MB heap by valgrind's
 *   massif);
 * - SLACK: the memory the arrays above do not name (Embree's build, the threads' arenas) and
 *   the allocator's pages not given back between passes: a render's peak RSS above the
 *   process's 14 MB was 0.96-1.30 times these arrays on 15 random views with beam sets
 *   (scripts/random_views.py --memory, seed 5) and 1.15-1.19 on the default scene. */
enum { PER_PIXEL_BATCH = 3 * 8 + 4, PER_PIXEL_AOV = 16, PER_PIXEL_IMAGE = 32 };
enum { PER_TRI = 128 + 85, PER_VERT = 40, PER_ENTRY = 10 };
enum { BUILD_VERT = 24 + 16, BUILD_PRIM = 2 * 6 * 4 + 8 };
static const double FIXED = 144.0 * 1048576.0, SLACK = 1.35;
static const double PRIM_BUDGET = 16777216.0; /* 2^24 per set (reference/integrator.c) */

/* A set of `cells` surface cells (two triangles and a vertex each) and `prims` primitives:
 * what it keeps, and what its build adds while it runs. */
static double kept(double cells, double prims, double entries)
{
    return cells * (2.0 * PER_TRI + PER_VERT) + fmin(prims, PRIM_BUDGET) * (4.0 + entries * PER_ENTRY);
}
static double building(double cells, double prims) { return cells * BUILD_VERT + fmin(prims, PRIM_BUDGET) * BUILD_PRIM; }

void gr_ref_memory_parts(const gr_scene *scene, const gr_ref_info *info, double *fixed, double *pixels, double *sets)
{
    const double px = (double)scene->camera.width * (double)scene->camera.height;
    *fixed = FIXED;
    *pixels = px * (PER_PIXEL_BATCH * (double)scene->reference.batches + PER_PIXEL_AOV + PER_PIXEL_IMAGE);
    *sets = 0.0;
    if (info->flat) return; /* closed-form sunlight: no beam set */
    const double sr = scene->reference.surface_res;
    /* pass 0's sets, built one after the other and kept through the pass: the plain set, the
     * camera cone's, the near set, whose place the bias probe's fourth level gives to its
     * finer one (reference/probe.c, gr_ref_near_fine); the peak is the largest of the kept
     * sets plus the one being built */
    const double p = kept(sr * sr, info->plain_prims, info->plain_entries);
    const double c = kept(info->cone_cells, info->cone_prims, info->cone_entries);
    double peak = p + building(sr * sr, info->plain_prims);
    peak = fmax(peak, p + c + building(info->cone_cells, info->cone_prims));
    peak = fmax(peak, p + c + kept(info->near_cells, info->near_prims, info->near_entries) +
                          building(info->near_cells, info->near_prims));
    peak = fmax(peak, p + c + kept(info->probe_near_cells, info->probe_near_prims, info->probe_near_entries) +
                          building(info->probe_near_cells, info->probe_near_prims));
    *sets = SLACK * peak;
}

double gr_ref_memory_estimate(const gr_scene *scene, const gr_ref_info *info)
{
    double fixed, pixels, sets;
    gr_ref_memory_parts(scene, info, &fixed, &pixels, &sets);
    return fixed + pixels + sets;
}

gr_status gr_ref_memory_check(const gr_scene *scene, const gr_ref_info *info, gr_error *err)
{
    char detail[400], cone[80] = "";
    if (info->cone_cells > 0.0)
        snprintf(cone, sizeof cone, ", refine_factor %d (%.0f cells near the camera)", scene->reference.refine_factor,
                 info->cone_cells);
    char near[160] = "";
    if (info->near_cells > 0.0)
        snprintf(near, sizeof near, ", near_factor %d within %.1f m of the camera (%.0f cells%s)", info->near_factor,
                 info->near_radius_m, fmax(info->near_cells, info->probe_near_cells),
                 info->probe_near_cells > info->near_cells ? " at the bias probe's 2x finer level" : "");
    char prims[96] = "";
    double fixed, pixels, sets;
    gr_ref_memory_parts(scene, info, &fixed, &pixels, &sets);
    const double np = fmin(info->plain_prims, PRIM_BUDGET) + fmin(info->cone_prims, PRIM_BUDGET) +
                      fmin(fmax(info->near_prims, info->probe_near_prims), PRIM_BUDGET);
    if (sets > 0.0) snprintf(prims, sizeof prims, "; beam sets %.2f GiB for %.3g primitives", sets / 1073741824.0, np);
    snprintf(detail, sizeof detail, "%d x %d pixels x %d batches, surface_res %d%s%s%s", scene->camera.width,
             scene->camera.height, scene->reference.batches, scene->reference.surface_res, cone, near, prims);
    return gr_memlimit_check("the ground truth", gr_ref_memory_estimate(scene, info), detail, err);
}
