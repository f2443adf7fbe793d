/* What the volume techniques (slicing, froxel, light_rays: seeds 002 and 001 and the engines'
 * froxel fog) share: their common settings block and its descriptors, the GL state every one
 * holds (scenegl, the caustic stack, the colour target, the pass timer), the prelude of each
 * render (frame, checks, shadow map, eye depth, caustic stack, the inputs of
 * volume_common.glsl), the uniforms of volume_common.glsl and volume_surface.glsl, the slab
 * bounds and the stats; their settings block is realtime/volsettings.h. Derivations:
 * docs/volume-techniques.md. */
#ifndef GR_VOLUME_H
#define GR_VOLUME_H

#include <stddef.h>

#include "common/status.h"
#include "image/image.h"
#include "realtime/caustics.h"
#include "realtime/frame.h"
#include "realtime/readback.h"
#include "realtime/scenegl.h"
#include "realtime/technique.h"
#include "realtime/toolkit.h"
#include "realtime/volsettings.h"
#include "scene/scene.h"

/* ---- what the volume techniques share (volume_common.glsl's uniforms) ---- */
/* The uniforms of caustic_stack.glsl (t_caustics, u_caustic_*): the one GLSL source that
 * samples the caustic stack, read by the volume techniques and by user techniques' "caustics"
 * input alike. */
typedef struct gr_vol_caustic_locs {
    int tex, layers, depth, origin, patch, texel, sun_rw;
} gr_vol_caustic_locs;
void gr_vol_caustic_locations(unsigned program, gr_vol_caustic_locs *l);
/* Sets them for the current program from the last build of c with parameters cp: positions
 * in a frame whose origin is world (frame_x, frame_z) (the eye for the volume techniques, 0 for
 * world positions), the sun's disc blur on when sun_disc (f's sun radius seen from below), and
 * binds the stack to texture unit `unit` (GL_TEXTURE_2D_ARRAY; leaves unit 0 active). */
void gr_vol_caustic_set(const gr_vol_caustic_locs *l, const gr_caustics *c, const gr_caustics_params *cp,
                        const gr_frame *f, int sun_disc, double frame_x, double frame_z, int unit);

typedef struct gr_vol_locs {
    gr_vol_caustic_locs caus;
    int refr, rest, shadow, light_vp, use_shadow, sigma_t, sigma_s, g, esun;
} gr_vol_locs;
typedef struct gr_vol_inputs {
    const gr_frame *f;
    const gr_caustics *caustics;
    const gr_caustics_params *cp;
    unsigned shadow_tex;          /* 0: no shadow map */
    double light_vp[16];          /* world -> shadow clip */
    double sigma_t[3], sigma_s[3], g, gain[3];
    int sun_disc;                 /* 1: blur the caustics by the sun's disc (mip level per plane) */
} gr_vol_inputs;
void gr_vol_locations(unsigned program, gr_vol_locs *l);
/* Sets the uniforms of the current program and binds the caustic stack (if in->caustics) to unit 2 and the
 * shadow map to unit 3. */
void gr_vol_set(const gr_vol_locs *l, const gr_vol_inputs *in);
/* The farthest view depth (along forward) any pixel's ray needs: rays through a 17 x 17 grid
 * to the surface / seabed, at most t_max (m). */
double gr_vol_far_depth(const gr_scene *scene, const gr_frame *f, double t_max);
/* The techniques' far end in clear water: min(-ln(1e-3) / min sigma_t, reference.max_distance_m). */
double gr_vol_t_max(const gr_scene *scene);
/* Slab bounds b[0..n] in view depth: b[0] = 0, then linear to far, or geometric from near. */
void gr_vol_bounds(int n, int exponential, double near_m, double far_m, double *b);

/* ---- the prelude every volume technique's render shares ---- */

/* The caustic stack's parameters from the block's caustic fields (texture_size, grid, patch_m,
 * caustic_depths and the geometric depths between caustic_first_m and caustic_last_m; exact
 * Fresnel): the one derivation, used by gr_vol_prepare and by the user techniques' "caustics"
 * input (realtime/usertech.c). */
void gr_vol_caustics_params(const gr_vol_settings *s, gr_caustics_params *cp);
/* The GL passes of the prelude, in this order in each technique's timer and stats; a
 * technique's own passes follow (GR_VOL_PASS_OWN, or GR_VOL_PASS_CAUSTICS without caustics). */
enum { GR_VOL_PASS_SHADOW = 0, GR_VOL_PASS_DEPTH = 1, GR_VOL_PASS_CAUSTICS = 2, GR_VOL_PASS_OWN = 3 };

/* What the prelude produced for one render. `in` points into the struct (in.f = &frame,
 * in.cp = &cp): do not copy it. */
typedef struct gr_vol_prep {
    gr_frame frame;
    gr_caustics_params cp;
    gr_vol_inputs in;            /* caustics NULL when the technique has none */
    unsigned depth_tex;          /* gr_scenegl_eye_depth at the frame's size */
    double t_max;                /* gr_vol_t_max */
    double t0_ms;                /* when the render started (for the wall time) */
    int shadow_size;             /* the shadow map's side; 0: none drawn (no occluders) */
} gr_vol_prep;

/* The waves for volume_surface.glsl (u_wa, u_wamp; GR_MAX_WAVES each): per wave (dir.x,
 * dir.z, k, c) with c = k dir . (ox, oz) - w t + phi0 folded in double, so the shader's phase
 * is k dir . x0 + c for x0 relative to the world point (ox, oz); unused entries zero. */
void gr_vol_waves(const gr_scene *scene, const gr_frame *f, double ox, double oz, float *wa, float *wamp);

/* What every volume technique holds: its GL context, scenegl (shadow map, eye depth), the
 * caustic stack (NULL for a technique without one), the screen VAO, the RGBA32F colour
 * target at the frame's size, the samples query, the pass timer and the read-back buffer. */
typedef struct gr_vol_base {
    gr_gl *gl;
    gr_scenegl *sg;
    gr_caustics *caus;
    unsigned vao, q_samples;
    gr_target out;
    gr_gl_timer timer;
    gr_readback rb;
} gr_vol_base;

/* Creates scenegl (shaders from dir, NULL: the embedded ones), the caustic stack when
 * with_caustics, the VAO, the query and the timer (gl must be current). On failure what
 * was made stays in b for gr_vol_base_release. */
gr_status gr_vol_base_init(gr_vol_base *b, gr_gl *gl, const char *dir, int with_caustics, gr_error *err);
/* Makes b's context current; 1 when the technique may delete its own GL objects now. */
int gr_vol_base_current(const gr_vol_base *b);
/* The class's set_reuse (technique.h) of a state whose first member is its gr_vol_base: the
 * caustic stack's reuse (caustics.h). */
void gr_vol_set_reuse(void *state, int on);
/* Deletes what gr_vol_base_init and gr_vol_prepare made (b may be partly made). */
void gr_vol_base_release(gr_vol_base *b);

/* The prelude of a volume technique's render (`name` starts its messages): the frame; out
 * must be camera.width x camera.height with R, G, B and the viewer under the water
 * (GR_E_INPUT otherwise); makes b's context current; resets its timer; the occluders' shadow
 * map (pass GR_VOL_PASS_SHADOW, only with occluders, centred on the eye), the eye depth (pass
 * GR_VOL_PASS_DEPTH), the caustic stack (pass GR_VOL_PASS_CAUSTICS, only if b->caus is not
 * NULL) from s's caustic fields; p->in filled from s and the scene's scattering; b->out made
 * at the frame's size. */
gr_status gr_vol_prepare(const char *name, gr_vol_base *b, const gr_scene *scene, const gr_vol_settings *s,
                         const gr_image *out, gr_vol_prep *p, gr_error *err);
/* The end of a volume technique's render: b->out read back into out's R, G, B; stats (may be
 * NULL) filled with the n passes of b's timer named by names, the samples of b's query, the
 * prelude passes' cost counters (gr_vol_cost_prelude) and the wall time since p->t0_ms; then
 * out checked for NaN and Inf (GR_E_RUNTIME). The technique counts its own passes after. */
gr_status gr_vol_finish(const char *name, gr_vol_base *b, const gr_vol_prep *p, gr_image *out,
                        const char *const *names, int n, gr_technique_stats *stats, gr_error *err);

/* The cost counters (technique.h) of the prelude's passes: shadow map (DEPTH32F, the side
 * squared), eye depth (R32F at the frame's size), the caustic stack's (gr_caustics_cost). */
void gr_vol_cost_prelude(const gr_vol_base *b, const gr_vol_prep *p, gr_technique_stats *stats);
/* Counter k of pass p set analytically, keeping the pass's queried primitives. */
void gr_vol_cost_pass(gr_technique_stats *stats, int p, const gr_pass_cost *c);
/* Pass p's counters from the caustic stack c (gr_caustics_cost), after the pass's timer
 * results are in stats: a drawn build's queried primitives are noted for its reuse. */
void gr_vol_cost_caustics(gr_technique_stats *stats, int p, gr_caustics *c);

#endif
