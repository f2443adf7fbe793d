/* Ground-truth render with Ctrl-C handling (render.h). */
#include "cli/render.h"

#include <signal.h>
#include <string.h>

static volatile sig_atomic_t g_interrupt = 0;

static void on_sigint(int sig)
{
    (void)sig;
    g_interrupt = 1;
    signal(SIGINT, SIG_DFL); /* a second Ctrl-C ends the process at once */
}

gr_status gr_cli_render_reference(const gr_scene *scene, const gr_ref_options *opt, gr_ref_result *res,
                                  int *passes_per_round, gr_error *err)
{
    gr_ref_options o = *opt;
    o.interrupt = &g_interrupt;
    gr_ref_renderer *r = NULL;
    gr_status st = gr_ref_create(scene, &o, &r, err);
    if (st != GR_OK) return st;
    if (passes_per_round) {
        gr_ref_info info;
        gr_ref_get_info(r, &info);
        *passes_per_round = info.passes_per_round;
    }
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old);
    st = gr_ref_render(r, res, err);
    sigaction(SIGINT, &old, NULL);
    gr_ref_destroy(r);
    return st;
}
