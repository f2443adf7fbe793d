/* Ground-truth render with Ctrl-C handling (render.h). */
#include "cli/render.h"

#include "common/memlimit.h"
#include "common/signals.h"

#include <math.h>
#include <stdio.h>

gr_status gr_cli_render_reference(const gr_scene *scene, const gr_ref_options *opt, gr_ref_result *res,
                                  int *passes_per_round, gr_error *err)
{
    gr_ref_options o = *opt;
    o.interrupt = gr_signals_flag(); /* SIGINT and SIGTERM (common/signals, installed by main) */
    /* What the render allocates, estimated before any beam is built (docs/reliability.md): per
     * pixel the batch sums (3 doubles) and counts (uint32) of every batch, the two AOVs and
     * the 8-channel float image; per surface cell two beam triangles (128 B + 4 B drift each),
     * a vertex (24 B position, 40 B beam vertex, 16 B Jacobian) and up to two beam
     * primitives with their lookup grid (box, id, at most 32 grid entries: 160 B each, at most
     * REF's budget of 2^24), for the plain grid and, with local refinement, the camera cone's
     * set (its cells known once the renderer has the lit region; creating it builds no beam).
     * Building the scene and the beams renders nothing yet: a signal there ends the process at
     * once (nothing to keep, no temporary file open). */
    gr_ref_renderer *r = NULL;
    gr_status st = gr_ref_create(scene, &o, &r, err);
    if (st != GR_OK) return st;
    gr_ref_info info;
    gr_ref_get_info(r, &info);
    if (passes_per_round) *passes_per_round = info.passes_per_round;
    const double px = (double)scene->camera.width * (double)scene->camera.height;
    const double B = scene->reference.batches, sr = scene->reference.surface_res, cc = info.cone_cells;
    const double cells = sr * sr, need = px * (28.0 * B + 16.0 + 32.0) + (cells + cc) * 344.0 +
                                         (fmin(2.0 * cells, 16777216.0) + fmin(2.0 * cc, 16777216.0)) * 160.0;
    char detail[200], cone[80] = "";
    if (cc > 0.0) snprintf(cone, sizeof cone, ", refine_factor %d (%.0f cells near the camera)", scene->reference.refine_factor, cc);
    snprintf(detail, sizeof detail, "%d x %d pixels x %d batches, surface_res %d%s", scene->camera.width,
             scene->camera.height, scene->reference.batches, scene->reference.surface_res, cone);
    gr_status mst = gr_memlimit_check("the ground truth", need, detail, err);
    if (mst != GR_OK) {
        gr_ref_destroy(r);
        return mst;
    }
    gr_signals_hold_begin(); /* the first signal only sets the flag; the renderer stops at its next check */
    st = gr_ref_render(r, res, err);
    gr_signals_hold_end();
    gr_ref_destroy(r);
    return st;
}
