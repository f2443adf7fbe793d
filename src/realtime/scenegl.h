/* GL resources every technique may share within one context: the occluders as a triangle
 * mesh, their shadow map along the refracted sun (orthographic, centred where the camera
 * looks), their depth as seen from the eye, and GPU pass timers. Built once per context
 * and refreshed per scene; techniques bind the textures, they do not redraw the occluders. */
#ifndef GR_SCENEGL_H
#define GR_SCENEGL_H

#include "common/status.h"
#include "gl/glctx.h"
#include "realtime/frame.h"
#include "scene/scene.h"

typedef struct gr_scenegl gr_scenegl; /* opaque; current context only */

gr_status gr_scenegl_create(gr_gl *gl, gr_scenegl **out, gr_error *err);
void gr_scenegl_destroy(gr_scenegl *s); /* accepts NULL */

/* Shadow map of the occluders along f->refr_dir: size x size, depth texture (GL_DEPTH_COMPONENT32F,
 * compare mode off), covering a square of half_extent_m around center. *light_vp receives
 * the light's view-projection (column-major) mapping world -> clip. Returns the texture. */
gr_status gr_scenegl_shadow_map(gr_scenegl *s, const gr_scene *scene, const gr_frame *f, int size,
                                const double center[3], double half_extent_m, unsigned *texture,
                                double light_vp[16], gr_error *err);
/* Linear distance (m) from the eye to the first occluder or the seabed along each pixel's
 * view ray, at width x height (R32F; GR_FRAME_FAR_M where nothing is hit). Returns the texture. */
gr_status gr_scenegl_eye_depth(gr_scenegl *s, const gr_scene *scene, const gr_frame *f, int width, int height,
                               unsigned *texture, gr_error *err);

/* GPU pass timing: begin/end around a pass; results collected after the frame. */
typedef struct gr_gl_timer {
    unsigned queries[8];
    int n, have_timer;
} gr_gl_timer;
void gr_gl_timer_init(gr_gl_timer *t);            /* needs a current context */
void gr_gl_timer_begin(gr_gl_timer *t, int pass); /* pass < 8 */
void gr_gl_timer_end(gr_gl_timer *t);
long long gr_gl_timer_ns(gr_gl_timer *t, int pass); /* -1 if no timer */
void gr_gl_timer_free(gr_gl_timer *t);

#endif
