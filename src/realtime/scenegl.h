/* GL resources every technique may share within one context: the occluders as a triangle
 * mesh, their shadow map along the refracted sun (orthographic, centred where the camera
 * looks) and their depth as seen from the eye. Built once per context and refreshed per
 * scene; techniques bind the textures, they do not redraw the occluders. (GPU pass timers
 * and render targets: realtime/toolkit.h.) */
#ifndef GR_SCENEGL_H
#define GR_SCENEGL_H

#include <stddef.h>

#include "common/status.h"
#include "gl/glctx.h"
#include "realtime/frame.h"
#include "scene/scene.h"

typedef struct gr_scenegl gr_scenegl; /* opaque; current context only */

/* The occluders as world-space triangles (no GL): boxes as 12 triangles, spheres as a
 * 24 x 48 stack/slice tessellation. gr_occluder_mesh writes gr_occluder_mesh_count(scene)
 * vertices, 3 doubles each, into xyz. Every technique draws the same occluders. */
size_t gr_occluder_mesh_count(const gr_scene *scene);
void gr_occluder_mesh(const gr_scene *scene, double *xyz);

/* Compiles the shared programs in the current context gl (embedded shaders; shader_dir, may
 * be NULL, overrides them file by file as for the shafts). Textures returned below belong to
 * s and stay valid until the next call that makes the same kind of texture, or destroy.
 * The calls leave framebuffer 0 and program 0 bound, blending, depth test and depth clamp
 * off. */
gr_status gr_scenegl_create(gr_gl *gl, gr_scenegl **out, gr_error *err);
gr_status gr_scenegl_create_dir(gr_gl *gl, const char *shader_dir, gr_scenegl **out, gr_error *err);
void gr_scenegl_destroy(gr_scenegl *s); /* accepts NULL */

/* Shadow map of the occluders along f->refr_dir: size x size, depth texture (GL_DEPTH_COMPONENT32F,
 * compare mode off), covering a square of half_extent_m around center. *light_vp receives
 * the light's view-projection (column-major) mapping world -> clip. Returns the texture.
 * Orthographic: x, y across the beam (a frame e1, e2 perpendicular to refr_dir), z along
 * refr_dir; the depth range spans the occluders' extent along refr_dir with 1 m margins, so
 * stored depth 0.5 (z + 1) is < 1 where a caster is; points deeper than every caster map to
 * depth > 1 (shadowed where a caster is stored), shallower ones to < 0 (lit). Border and
 * empty texels read 1 (lit). GL_NEAREST filtering. */
gr_status gr_scenegl_shadow_map(gr_scenegl *s, const gr_scene *scene, const gr_frame *f, int size,
                                const double center[3], double half_extent_m, unsigned *texture,
                                double light_vp[16], gr_error *err);
/* center moved across the beam (in the map's e1, e2) to the nearest multiple of the map's
 * texel size 2 half_extent_m / size, its component along refr_dir kept: a map centred there
 * has its texels at the same world places whatever center was (the standard shadow-map
 * stabilization; docs/realtime-shafts.md "stable_grid"). out may alias center. */
void gr_scenegl_shadow_snap(const gr_frame *f, int size, double half_extent_m, const double center[3],
                            double out[3]);
/* Linear distance (m) from the eye to the first occluder or the seabed along each pixel's
 * view ray, at width x height (R32F; GR_FRAME_FAR_M where nothing is hit). Returns the texture. */
gr_status gr_scenegl_eye_depth(gr_scenegl *s, const gr_scene *scene, const gr_frame *f, int width, int height,
                               unsigned *texture, gr_error *err);

#endif
