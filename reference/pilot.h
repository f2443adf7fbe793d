/* The step pilot (internal to reference/; docs/reference.md 2.5, "Adaptive steps"): a sparse
 * render with its own random numbers before the first pass, from which every pixel gets its
 * march steps and their allotment along the ray. */
#ifndef GR_REF_PILOT_H
#define GR_REF_PILOT_H

#include "reference/renderer.h"

/* Adaptive steps: the pilot rays and the steps map, or r->steps_px = NULL (fixed steps:
 * adaptive_steps off, or steps no more than min_steps). *complete = 0 when interrupted. */
gr_status gr_ref_step_pilot(gr_ref_renderer *r, gr_ref_pool *pool, gr_progress *prog, int *complete, gr_error *err);

#endif
