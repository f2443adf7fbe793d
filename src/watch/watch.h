/* `godrays watch`: the edit-to-verdict loop (docs/techniques.md "The edit-to-verdict loop").
 * A user technique's folder is watched with inotify; every save of a file in it (after a
 * quiet spell of debounce_ms, so that an editor's burst of writes is one render) reloads the
 * technique from its folder, renders it, compares it with the ground truth (compare/metrics.h,
 * the registry's metrics and the verdict, as `godrays run` scores them) and publishes the
 * result to the server (watch/server.h): the state JSON and the PNG images "test" (the render
 * at the truth's exposure, fixed for the session), "truth", "diff" (|dY| after the scale fit)
 * and "flip" (HDR-FLIP of the fitted render). A manifest, compile or render error is
 * published as such, with the message (a compiler's log: one diagnostic per line).
 *
 * Library code: it prints nothing; each finished render is told to the caller's log function. */
#ifndef GR_WATCH_H
#define GR_WATCH_H

#include <signal.h>

#include "common/status.h"
#include "gl/glctx.h"
#include "image/image.h"
#include "realtime/technique.h"
#include "scene/scene.h"
#include "watch/server.h"

typedef struct gr_watch_options {
    const char *dir;                 /* the technique's folder (its manifest.json) */
    const gr_technique_class *cls;   /* the same technique as registered when the scene was loaded:
                                        its scene settings (--set) are used while the manifest's
                                        settings table keeps their keys, types and layout */
    const gr_scene *scene;
    const gr_image *truth;           /* R, G, B (+ stderr.*): reference/truth.h */
    const gr_metadata *truth_meta;   /* may be NULL (its godrays:stderr_dof sets the significance) */
    gr_gl_platform platform;
    double debounce_ms;              /* 0: 100 */
    volatile sig_atomic_t *stop;     /* nonzero ends the loop (common/signals' flag) */
    /* After each render (may be NULL): its line, without a final newline: "render 3 (pass.frag):
     * NAME verdict 0.1234 ..." or "render 4 (pass.frag): compile error: MESSAGE" (a compiler's
     * log follows on more lines, one diagnostic each). */
    void (*log)(void *user, const char *line);
    void *user;
} gr_watch_options;

/* Renders once, then again after every save, until *o->stop. GR_OK when stopped; an error only
 * for what ends the loop itself (inotify, memory, the server), never for the technique's own
 * failures, which are published. */
gr_status gr_watch_run(const gr_watch_options *o, gr_watch_server *srv, gr_error *err);

/* The page served at "/" (static: polls /state.json every 0.5 s). */
const char *gr_watch_page(void);

#endif
