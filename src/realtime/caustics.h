/* Seed 002's caustic texture (Jensen & Golias, beam tracing on the GPU): the water grid over a
 * square patch is displaced (seed 000 eq. 5.5.7), the sun refracted at each vertex (eq. 5.5.1,
 * exact Fresnel), the refracted rays intersected with horizontal planes at a stack of depths,
 * and each caustic triangle drawn additively with the intensity
 *     F_t * |to_sun . a_surface| / |A_projected|
 * (the flux its surface triangle receives per unit sun irradiance over its footprint), into a
 * texture tileable over the patch (copies across the edges), rendered at twice the size and
 * box-filtered (seed 002's 2x2 supersampling). A texel holds the HORIZONTAL irradiance at that
 * depth per unit E_sun, without extinction (consumers apply exp(-sigma_t depth / mu_t)): on
 * flat water cos(theta_i) F_t. Derivation: docs/volume-techniques.md.
 *
 * Also the volume techniques' shared GLSL program builder (vertex/geometry/fragment or
 * compute stages, each the concatenation of several files, --shader-dir overridable). */
#ifndef GR_CAUSTICS_H
#define GR_CAUSTICS_H

#include "common/status.h"
#include "image/image.h"
#include "realtime/frame.h"
#include "scene/scene.h"

#define GR_CAUSTICS_MAX_DEPTHS 64

typedef struct gr_caustics_params {
    int size;             /* texture side after the 2x2 box filter (rendered at 2 size) */
    int grid;             /* water grid cells per patch side */
    double patch_m;       /* patch side (m): the texture repeats with this period */
    int n_depths;         /* planes in the stack, 1..GR_CAUSTICS_MAX_DEPTHS */
    double depths_m[GR_CAUSTICS_MAX_DEPTHS]; /* below the rest height, increasing, > 0 */
    int fresnel;          /* 1: exact Fresnel transmittance; 0: F_t = 1 (flux tests) */
} gr_caustics_params;

typedef struct gr_caustics gr_caustics;

/* Needs a current GL 4.5 context; shader_dir may be NULL. */
gr_status gr_caustics_create(const char *shader_dir, gr_caustics **out, gr_error *err);
void gr_caustics_destroy(gr_caustics *c); /* accepts NULL */

/* Builds the stack for f's waves and sun at f->time_s. The patch's corner is
 * origin = (floor(eye.x / L) L, floor(eye.z / L) L); texture uv of world (x, z) is
 * ((x - origin.x) / L, (z - origin.z) / L) with GL_REPEAT. */
gr_status gr_caustics_build(gr_caustics *c, const gr_scene *scene, const gr_frame *f, const gr_caustics_params *p,
                            gr_error *err);
/* GL_TEXTURE_2D_ARRAY (R32F, linear, repeat), one layer per depth, base level = the filtered one. */
unsigned gr_caustics_texture(const gr_caustics *c);
void gr_caustics_origin(const gr_caustics *c, double origin[2]);
/* Reads layer `layer` of the last build (1 channel "Y", row y = texel row y, i.e. z increasing). */
gr_status gr_caustics_read(gr_caustics *c, int layer, gr_image **out, gr_error *err);
/* Triangles drawn in the last build (for the summary). */
long long gr_caustics_triangles(const gr_caustics *c);

/* Depths of a stack: n depths geometric between first_m and last_m (n = 1: first_m). */
void gr_caustics_depths(int n, double first_m, double last_m, double *out);

/* ---- shared program builder ---- */
typedef struct gr_vol_stage {
    unsigned type;           /* GL_VERTEX_SHADER, GL_GEOMETRY_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER */
    const char *files[4];    /* concatenated in order (the first starts with #version); NULL-ended */
} gr_vol_stage;
gr_status gr_vol_program(const char *dir, const gr_vol_stage *stages, int n, unsigned *program, gr_error *err);


/* ---- what the volume techniques share (volume_common.glsl's uniforms) ---- */
typedef struct gr_vol_locs {
    int caustics, n_depths, cdepth, corigin, patch, refr, rest, shadow, light_vp, use_shadow, sigma_t, sigma_s, g,
        esun, texel, sun_rw;
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
/* Sets the uniforms of the current program and binds the caustic stack to unit 2 and the
 * shadow map to unit 3. */
void gr_vol_set(const gr_vol_locs *l, const gr_vol_inputs *in);
/* The farthest view depth (along forward) any pixel's ray needs: rays through a 17 x 17 grid
 * to the surface / seabed, at most t_max (m). */
double gr_vol_far_depth(const gr_scene *scene, const gr_frame *f, double t_max);
/* Where the reference stops a camera ray in clear water: min(-ln(cutoff) / min sigma_t, max). */
double gr_vol_t_max(const gr_scene *scene);
/* Slab bounds b[0..n] in view depth: b[0] = 0, then linear to far, or geometric from near. */
void gr_vol_bounds(int n, int exponential, double near_m, double far_m, double *b);
/* Reads an RGBA32F framebuffer (w x h, bottom row first) into out's R, G, B (top row first). */
gr_status gr_vol_readback(unsigned fbo, int w, int h, gr_image *out, const char *what, gr_error *err);

#endif
