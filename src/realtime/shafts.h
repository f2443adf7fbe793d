/* Seed 000's real-time underwater god-ray shafts (Lanza, ShaderX^5 ch. 5.5) as an OpenGL
 * pipeline through a headless EGL context: (1) shadow map of the occluders from P along the
 * refracted sun (scenegl's), (2) an N x N grid of extruded shafts blended additively into a reduced
 * render target, (3) a full-screen pass (4 bilinear taps, HG phase, bias, intensity) giving
 * the god-ray layer in linear float at the frame's resolution.
 * The renderer keeps its context, programs and buffers alive across renders: create it
 * once, render many parameter sets (sweeps, tuning), destroy it. Settings changes never
 * recompile shaders; buffers are rebuilt only when N, the frame or target size changes.
 * Decisions and their reasons: docs/realtime-shafts.md. */
#ifndef GR_SHAFTS_H
#define GR_SHAFTS_H

#include "common/status.h"
#include "gl/glctx.h"
#include "image/image.h"
#include "realtime/technique.h"
#include "scene/params.h"
#include "scene/scene.h"

/* The shafts as a technique of the harness (technique.h): name and scene section "shafts". */
extern const gr_technique_class gr_shafts_class;

/* The scene section "shafts": settings and their descriptor table (shafts.c). */
typedef enum gr_target_format { GR_TARGET_RGBA8 = 0, GR_TARGET_RGBA16F = 1 } gr_target_format;
/* What a shaft fragment adds (docs/realtime-shafts.md "Variants"): the seed's per-vertex
 * intensity per surface crossed; the length of shaft traversed (signed faces); the same with
 * each depth slab's irradiance from the area ratio of its cross-section (focusing). */
typedef enum gr_shafts_variant { GR_SHAFTS_SEED = 0, GR_SHAFTS_PATH = 1, GR_SHAFTS_FLUX = 2 } gr_shafts_variant;

/* Real-time shafts (seed 000), every undocumented choice exposed. */
typedef struct gr_shafts_settings {
    int N;                        /* grid vertices along each side (seed eq. 5.5.6) */
    double K;                     /* spacing adjustment factor (eq. 5.5.6), ~0.8 */
    double shaft_length_m;        /* extrusion length of bottom vertices (seed: e.g. 30 m) */
    double shaft_width;           /* shaft width as a fraction of the grid cell */
    int caps;                     /* draw top/bottom faces of each parallelepiped */
    double target_scale;          /* shaft target size / frame size, per axis (0.5 = quarter area) */
    int target_format;            /* gr_target_format */
    double extinction[3];         /* c in eq. 5.5.3 (1/m); default: the medium's sigma_t */
    double g;                     /* HG eccentricity in the final pass; default: the medium's g */
    double bias;                  /* the 0.15 added before the phase (seed, second pass) */
    double intensity[3];          /* user factor in the second pass */
    int shadow_map_size;          /* shadow map resolution (texels per side) */
    double shadow_bias;           /* depth bias of the shadow comparison (m) */
    int variant;                  /* gr_shafts_variant */
    double target_prescale;       /* factor on each fragment before blending, divided out after */
    int stable_grid;              /* P snapped to the grid, S quantized with a cross-fade */
    int depth_test;               /* shafts hidden behind occluders / seabed seen from the eye */
    int slabs;                    /* flux: depth slabs per shaft */
    double grid_eye_m[3];         /* eye the grid (P, S, stable_grid's levels) is built for, world m;
                                     default: the camera's position (the view stays the camera's) */
} gr_shafts_settings;

extern const gr_param_table gr_shafts_param_table;

/* The scene's shafts section (resolved by the loader). */
const gr_shafts_settings *gr_shafts_scene_settings(const gr_scene *scene);

typedef struct gr_shafts gr_shafts; /* opaque; used from the thread that created it */

typedef struct gr_shafts_options {
    const char *shader_dir; /* NULL: embedded shaders; else files there override them */
    gr_gl_options gl;       /* headless context options (zero = defaults) */
} gr_shafts_options;

enum { GR_SHAFTS_PASS_SHADOW = 0, GR_SHAFTS_PASS_SHAFTS = 1, GR_SHAFTS_PASS_FINAL = 2, GR_SHAFTS_NPASS = 3 };
extern const char *const gr_shafts_pass_names[GR_SHAFTS_NPASS]; /* "shadow", "shafts", "final" */

typedef struct gr_shafts_stats {
    long long gpu_ns[GR_SHAFTS_NPASS]; /* GL_TIME_ELAPSED per pass; -1 if unavailable */
    double cpu_ms;                     /* wall time of the render call, readback included */
    long long fragments;               /* shaft fragments blended (GL_SAMPLES_PASSED) */
    long long vertices_submitted;      /* indices drawn in the shaft pass */
    long long vs_invocations;          /* shaft pass, ARB_pipeline_statistics_query; -1 if absent */
    long long fs_invocations;          /* idem */
    int target_width, target_height;   /* shaft render target */
    int n_shafts;                      /* (N - 1)^2 */
    double spacing_m;                  /* S, seed eq. 5.5.6 */
    double center[3];                  /* P, seed eq. 5.5.5a */
    double refr_dir[3];                /* T, seed eq. 5.5.5b */
    gr_pass_cost cost[GR_SHAFTS_NPASS];/* per pass (technique.h; docs/realtime-shafts.md "Cost") */
} gr_shafts_stats;

/* One transformed shaft vertex read back by transform feedback (gr_shafts_capture). */
typedef struct gr_shafts_vertex {
    float cell[2];      /* grid cell centre, in cells, relative to P (x, z) */
    float corner[2];    /* corner offset in cells (+-0.5 before the width factor) */
    int bottom;         /* 1 for an extruded bottom vertex */
    double pos[3];      /* world position (m), as the vertex shader computed it */
    double intensity[3];/* per-vertex intensity exp(-c (len + |pos - E|)) (1 - Schlick) */
} gr_shafts_vertex;

/* Creates the GL context, compiles every program (a compile or link failure is GR_E_GL
 * with the GLSL log; a bad --shader-dir is GR_E_INPUT). opts may be NULL. */
gr_status gr_shafts_create(const gr_shafts_options *opts, gr_shafts **out, gr_error *err);
/* The same in an existing context gl (current on this thread), which outlives the renderer
 * (what the technique class uses). */
gr_status gr_shafts_create_in(gr_gl *gl, const char *shader_dir, gr_shafts **out, gr_error *err);
void gr_shafts_destroy(gr_shafts *r); /* accepts NULL */
const gr_gl *gr_shafts_gl(const gr_shafts *r);
/* Number of the renderer's shader files that came from --shader-dir. */
int gr_shafts_shaders_from_dir(const gr_shafts *r);

/* Range checks of every setting (the table in src/scene/settings.c) plus N >= 2; the
 * error names "shafts.KEY". NaN is accepted for scene-derived settings (extinction, g). */
gr_status gr_shafts_check_settings(const gr_shafts_settings *s, gr_error *err);
/* Copies s with scene-derived defaults (NaN) resolved from the scene's medium. */
void gr_shafts_resolve(const gr_scene *scene, const gr_shafts_settings *s, gr_shafts_settings *out);

/* Renders the god-ray layer of scene at scene->water.time_s with settings s (NULL: the
 * scene's own) into out, which must be camera.width x camera.height with channels "R",
 * "G", "B" (others are left alone). stats may be NULL. Never writes NaN or Inf. */
gr_status gr_shafts_render(gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s,
                           gr_image *out, gr_shafts_stats *stats, gr_error *err);

/* The shaft render target of the last render as an RGBA float image (top row first),
 * as stored (8-bit targets read back as code / 255). *out is the caller's. */
gr_status gr_shafts_read_target(gr_shafts *r, gr_image **out, gr_error *err);

/* Runs the shaft vertex shader alone over every grid vertex (8 per shaft) with transform
 * feedback and returns what it computed; *out is malloc'd (caller frees), *count = 8 (N-1)^2.
 * The seed and path variants only (flux draws a shared lattice: GR_E_INPUT).
 * stats (may be NULL) receives the placement (P, T, S). */
gr_status gr_shafts_capture(gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s,
                            gr_shafts_vertex **out, int *count, gr_shafts_stats *stats,
                            gr_error *err);

/* Adds the "godrays:*" metadata of a render: renderer, GL strings, scene name/hash, time,
 * every setting (resolved), placement, per-pass GPU ns, CPU ms, fragments, vertices. */
gr_status gr_shafts_metadata(const gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s,
                             const gr_shafts_stats *stats, gr_metadata *meta, gr_error *err);

#endif
