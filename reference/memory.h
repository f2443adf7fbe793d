/* What a ground-truth render allocates, estimated before any beam is built, and its check
 * against the memory limit (common/memlimit, docs/reliability.md "Memory"). The figures are
 * the integrator's own (reference/integrator.c, reference/beams.c), so they live beside it. */
#ifndef GR_REF_MEMORY_H
#define GR_REF_MEMORY_H

#include <stddef.h>
#include "common/status.h"
#include "reference/integrator.h"
#include "scene/scene.h"

/* Bytes a render of scene needs, from the renderer's info (gr_ref_get_info after
 * gr_ref_create: the camera cone's cells are known once the lit region is): per pixel the
 * batch sums (3 doubles) and counts (uint32) of every batch, the two AOVs and the 8-channel
 * float image; per surface cell two beam triangles (128 B + 4 B drift each), a vertex (24 B
 * position, 40 B beam vertex, 16 B Jacobian) and up to two beam primitives with their lookup
 * grid (box, id, at most 16 grid entries of 10 B: 160 B each, at most the budget of 2^24), for the
 * plain grid and, with local refinement, the camera cone's set and the set near the camera. */
double gr_ref_memory_estimate(const gr_scene *scene, const gr_ref_info *info);

/* GR_OK when the estimate fits the limit, else GR_E_INPUT "the ground truth needs about X GiB
 * (W x H pixels x B batches, surface_res N[, refine_factor F (C cells near the camera)][, near_factor
 * F within D m of the camera (C cells)]), over
 * the memory limit of Y GiB (SOURCE)" (gr_memlimit_check). */
gr_status gr_ref_memory_check(const gr_scene *scene, const gr_ref_info *info, gr_error *err);

#endif
