/* The ground-truth render as `godrays reference` and `godrays run` start it: Ctrl-C (SIGINT)
 * or SIGTERM stops the render at the renderer's next check instead of ending the process, so
 * that what is done can be kept or dropped by the command; a second signal ends the process
 * at once (common/signals). */
#ifndef GR_CLI_RENDER_H
#define GR_CLI_RENDER_H

#include "reference/integrator.h"

/* gr_ref_create + gr_ref_render + gr_ref_destroy with opt (its interrupt field is replaced by
 * the Ctrl-C flag). An interrupted render returns GR_OK with res->partial = 1 (reference/
 * integrator.h). passes_per_round (may be NULL): the renderer's passes per round of
 * --target-error refinement. */
gr_status gr_cli_render_reference(const gr_scene *scene, const gr_ref_options *opt, gr_ref_result *res,
                                  int *passes_per_round, gr_error *err);

#endif
