/* Ground-truth render with Ctrl-C handling (render.h). */
#include "cli/render.h"

#include "common/signals.h"

gr_status gr_cli_render_reference(const gr_scene *scene, const gr_ref_options *opt, gr_ref_result *res,
                                  int *passes_per_round, gr_error *err)
{
    gr_ref_options o = *opt;
    o.interrupt = gr_signals_flag(); /* SIGINT and SIGTERM (common/signals, installed by main) */
    gr_ref_renderer *r = NULL;
    /* Building the scene and the beams renders nothing yet: a signal there ends the process
     * at once (nothing to keep, no temporary file open). */
    gr_status st = gr_ref_create(scene, &o, &r, err);
    if (st != GR_OK) return st;
    if (passes_per_round) {
        gr_ref_info info;
        gr_ref_get_info(r, &info);
        *passes_per_round = info.passes_per_round;
    }
    gr_signals_hold_begin(); /* the first signal only sets the flag; the renderer stops at its next check */
    st = gr_ref_render(r, res, err);
    gr_signals_hold_end();
    gr_ref_destroy(r);
    return st;
}
