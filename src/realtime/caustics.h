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
 * What the volume techniques share around it (settings, the render's prelude): volume.h. */
#ifndef GR_CAUSTICS_H
#define GR_CAUSTICS_H

#include "common/status.h"
#include "image/image.h"
#include "realtime/frame.h"
#include "realtime/technique.h"
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
/* The texture's base level (1: a build's own texture, whose level 0 is the 2x supersampled
 * one; 0: a reused stack, which holds the sampled levels only). Sampling is the same. */
int gr_caustics_base_level(const gr_caustics *c);
/* Reuse (a search's renders, gr_technique_set_reuse): on, each build is kept (up to 1 GiB of
 * stacks, least recently used dropped) under everything its uniforms are made of (parameters,
 * the waves at the frame's time, sun, ior, patch origin), and a build with the same inputs
 * takes the kept stack instead of drawing: the same texels (the build is deterministic), the
 * same cost counters, no time. Off (the default; every timing): every build draws. */
void gr_caustics_set_reuse(gr_caustics *c, int on);
void gr_caustics_origin(const gr_caustics *c, double origin[2]);
/* Reads layer `layer` of the last build (1 channel "Y", row y = texel row y, i.e. z increasing). */
gr_status gr_caustics_read(gr_caustics *c, int layer, gr_image **out, gr_error *err);
/* Triangles drawn in the last build (for the summary). */
long long gr_caustics_triangles(const gr_caustics *c);

/* The cost counters of the last build (technique.h): fragments (GL_SAMPLES_PASSED), indices
 * drawn, texture taps and bytes of the mip chain, bytes cleared and blended; primitives are
 * the caller's timer's. */
void gr_caustics_cost(const gr_caustics *c, gr_pass_cost *out);
/* The primitives the caller's query counted around the last build, when it drew and was kept:
 * a later reuse of that stack reports them (its own pass draws nothing). */
void gr_caustics_note_primitives(gr_caustics *c, long long primitives);

/* Depths of a stack: n depths geometric between first_m and last_m (n = 1: first_m). */
void gr_caustics_depths(int n, double first_m, double last_m, double *out);

#endif
