/* The scene colour a screen-space effect composites god rays over (issue 29; docs/techniques.md
 * "Harness textures"; derivation: docs/volume-techniques.md "Scene colour"): per pixel of a
 * target, in the light pass's normalization (realtime/toolkit.h gr_light_pass: 1 = the
 * flat-water peak of the refracted sun; radiance = value x gr_light_radiance):
 *  - where the view ray reaches the water surface first: the sky and sun seen through it, the
 *    light pass's value itself (the same program, drawn first);
 *  - where the seabed or an occluder is nearer: a Lambertian surface of albedo `albedo` lit by
 *    the refracted sun through the caustic stack (realtime/caustics.h),
 *      L = albedo / pi E_sun C(p) / mu_t max(N . l, 0) exp(-sigma_t d / mu_t) V(p) exp(-sigma_t t),
 *    N = +y on the seabed, from the eye depth's differences on occluders;
 *  - 0 where the ray meets nothing (dark water).
 * Alpha: 1 where the surface is seen first, else 0. No in-scattering (no god rays) in it; the
 * ground truth has no lit seabed (its seabed is black), so nothing scores this texture. */
#ifndef GR_SCENECOLOUR_H
#define GR_SCENECOLOUR_H

#include "common/status.h"
#include "realtime/frame.h"
#include "realtime/toolkit.h"
#include "realtime/volume.h"
#include "scene/scene.h"

typedef struct gr_scene_colour {
    gr_light_pass light;          /* the toolkit's light pass: the surface-first pixels */
    unsigned prog, vao;           /* the lit surfaces (scene_colour.frag.glsl) */
    gr_vol_locs locs;
    int inv_vp_rot, eye_depth, size, far, seabed, albedo, inv_unit, normal_offset;
} gr_scene_colour;

typedef struct gr_scene_colour_params {
    double radius_deg;            /* the light pass's sun kernel radius in air (its normalization) */
    double albedo[3];             /* Lambertian albedo of the seabed and the occluders, per channel */
    double shadow_texel_m;        /* the shadow map's texel side (2 half extent / size); 0: no map */
} gr_scene_colour_params;

/* Compiles both programs in the current context (shader_dir: --shader-dir, may be NULL); zero
 * sc first. */
gr_status gr_scene_colour_init(gr_scene_colour *sc, const char *shader_dir, gr_error *err);
void gr_scene_colour_free(gr_scene_colour *sc); /* accepts NULL and one never initialized */
/* Draws the scene colour into t (its size): depth_tex is the eye depth at t's size
 * (gr_scenegl_eye_depth); in carries the built caustic stack (in->caustics, in->cp, in->sun_disc;
 * not NULL), the shadow map (in->shadow_tex 0: none) with in->light_vp, in->sigma_t (the
 * extinction on both paths) and in->gain (1: physical). `who` names the caller in errors (those
 * of gr_light_pass_draw). Leaves t's framebuffer bound, blending off. */
gr_status gr_scene_colour_draw(gr_scene_colour *sc, const gr_scene *scene, const gr_vol_inputs *in,
                               const gr_scene_colour_params *p, const gr_target *t, unsigned depth_tex, const char *who,
                               gr_error *err);
/* Radiance (W m^-2 sr^-1, per channel) of the value 1: gr_light_radiance at p->radius_deg. */
void gr_scene_colour_radiance(const gr_frame *f, const gr_scene_colour_params *p, double out[3]);

#endif
