/* What a ground-truth render allocates, estimated before any beam is built, and its check
 * against the memory limit (common/memlimit, docs/reliability.md "Memory"). The figures are
 * the integrator's own (reference/integrator.c, reference/beams.c), so they live beside it. */
#ifndef GR_REF_MEMORY_H
#define GR_REF_MEMORY_H

#include <stddef.h>
#include "common/status.h"
#include "reference/integrator.h"
#include "scene/scene.h"

/* Bytes a render of scene needs (the model and its measurements: docs/reliability.md
 * "Memory"), from the renderer's info (gr_ref_get_info, then gr_ref_sample_sets, after
 * gr_ref_create: the lit region, the sets' cells and their sampled primitives): *fixed for the process and its libraries,
 * *pixels for the per-pixel sums, AOVs and image, *sets for the beam sets at their peak
 * (pass 0's sets kept while the next is built, each set's triangles, vertices, Embree mesh,
 * primitives and lookup grid; 0 on flat water). */
void gr_ref_memory_parts(const gr_scene *scene, const gr_ref_info *info, double *fixed, double *pixels, double *sets);
/* Their sum. */
double gr_ref_memory_estimate(const gr_scene *scene, const gr_ref_info *info);

/* GR_OK when the estimate fits the limit, else GR_E_INPUT "the ground truth needs about X GiB
 * (W x H pixels x B batches, surface_res N[, refine_factor F (C cells near the camera)][, near_factor
 * F within D m of the camera (C cells)][; beam sets S GiB for P primitives]), over the memory
 * limit of Y GiB (SOURCE)" (gr_memlimit_check). */
gr_status gr_ref_memory_check(const gr_scene *scene, const gr_ref_info *info, gr_error *err);

#endif
