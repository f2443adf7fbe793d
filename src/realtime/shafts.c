/* Seed 000's real-time god-ray shafts as an OpenGL pipeline (see shafts.h and
 * docs/realtime-shafts.md for every decision and its reason). */
#include "realtime/shafts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "core/shaftgeom.h"
#include "gl/gl.h"
#include "realtime/frame.h"
#include "realtime/readback.h"
#include "realtime/scenegl.h"
#include "realtime/shaders.h"
#include "realtime/toolkit.h"

#define MAX_WAVE_GROUPS 16 /* must match shafts.vert.glsl */
#define GRID_FLOATS 6
#define TARGET_RGBA32F 2 /* path and flux: signed sums need a float target */

const char *const gr_shafts_pass_names[GR_SHAFTS_NPASS] = {"shadow", "shafts", "final"};

/* ---- the scene section "shafts" ------------------------------------------------------
 * One row per field: key, type, range, default, unit, doc. docs/scene-format.md lists the
 * same rows (tests/unit/test_scene_doc.c checks that every key is documented there). */
#define LO_X GR_PF_MIN_EXCL
#define HI_X GR_PF_MAX_EXCL
#define FROM GR_PF_FROM_SCENE
static const char *const target_format_names[] = {"rgba8", "rgba16f", NULL};
static const char *const variant_names[] = {"seed", "path", "flux", NULL};

#define SH(field) offsetof(gr_shafts_settings, field)
static const gr_param shafts_params[] = {
    {.name = "N", .type = GR_PT_INT, .offset = SH(N), .min = 2, .max = 1024, .def = 11, .unit = "",
     .doc = "grid vertices along each side of the shaft grid (seed eq. 5.5.6); (N-1)^2 shafts"},
    {.name = "K", .type = GR_PT_DOUBLE, .offset = SH(K), .min = 0, .max = 10, .flags = LO_X,
     .def = 1.2, .unit = "", .doc = "spacing adjustment factor K of seed eq. 5.5.6",
     .tune_lo = 0.2, .tune_hi = 2.0},
    {.name = "shaft_length_m", .type = GR_PT_DOUBLE, .offset = SH(shaft_length_m), .min = 0,
     .max = 10000, .flags = LO_X, .def = 30, .unit = "m",
     .doc = "extrusion length of the bottom vertices along the refracted sun ray",
     .tune_lo = 5.0, .tune_hi = 100.0},
    {.name = "shaft_width", .type = GR_PT_DOUBLE, .offset = SH(shaft_width), .min = 0, .max = 1,
     .flags = LO_X, .def = 0.7, .unit = "", .doc = "shaft width as a fraction of the grid cell",
     .tune_lo = 0.1, .tune_hi = 1.0},
    {.name = "caps", .type = GR_PT_BOOL, .offset = SH(caps), .min = 0, .max = 1, .def = 1, .unit = "",
     .doc = "draw the top and bottom faces of each parallelepiped"},
    {.name = "target_scale", .type = GR_PT_DOUBLE, .offset = SH(target_scale), .min = 0, .max = 1,
     .flags = LO_X, .def = 0.5, .unit = "",
     .doc = "shaft render target size / frame size, per axis (0.5 = a quarter of the area)",
     .tune_lo = 0.125, .tune_hi = 1.0},
    {.name = "target_format", .type = GR_PT_ENUM, .offset = SH(target_format), .min = 0, .max = 1,
     .def = GR_TARGET_RGBA8, .enum_names = target_format_names, .unit = "",
     .doc = "shaft render target format (the seed uses 8 bits per channel)"},
    {.name = "extinction", .type = GR_PT_RGB, .offset = SH(extinction), .min = 0, .max = 10000,
     .flags = FROM, .def = NAN, .unit = "1/m", .scene_source = "medium.extinction",
     .doc = "extinction c of seed eq. 5.5.3; default: the medium's sigma_t",
     .tune_lo = 0.1, .tune_hi = 4.0},
    {.name = "g", .type = GR_PT_DOUBLE, .offset = SH(g), .min = -1, .max = 1,
     .flags = LO_X | HI_X, .def = 0.5, .unit = "",
     .doc = "HG eccentricity of the seed variant's final pass (seed eq. 5.5.4: \"use g equal to 0.5\")",
     .tune_lo = 0.0, .tune_hi = 0.99},
    {.name = "bias", .type = GR_PT_DOUBLE, .offset = SH(bias), .min = 0, .max = 10, .def = 0.15,
     .unit = "", .doc = "constant added to the shaft intensity before the phase (seed, second pass)",
     .tune_lo = 0.0, .tune_hi = 1.0},
    {.name = "intensity", .type = GR_PT_RGB, .offset = SH(intensity), .min = 0, .max = 1e6, .def = 1,
     .unit = "", .doc = "user factor on the shaft intensity in the second pass",
     .tune_lo = 0.05, .tune_hi = 20.0},
    {.name = "shadow_map_size", .type = GR_PT_INT, .offset = SH(shadow_map_size), .min = 16,
     .max = 16384, .def = 1024, .unit = "texels", .doc = "shadow map resolution per side"},
    {.name = "shadow_bias", .type = GR_PT_DOUBLE, .offset = SH(shadow_bias), .min = 0, .max = 100,
     .def = 0.05, .unit = "m", .doc = "depth bias of the shadow comparison",
     .tune_lo = 0.0, .tune_hi = 1.0},
    {.name = "variant", .type = GR_PT_ENUM, .offset = SH(variant), .min = 0, .max = 2, .def = GR_SHAFTS_SEED,
     .enum_names = variant_names, .unit = "",
     .doc = "seed (the listings), path (length of shaft traversed), flux (area-ratio slabs, focusing)"},
    {.name = "target_prescale", .type = GR_PT_DOUBLE, .offset = SH(target_prescale), .min = 0, .max = 1e6,
     .flags = LO_X, .def = 0.125, .unit = "",
     .doc = "seed variant: factor on each shaft fragment before blending, divided out in the final pass"},
    {.name = "stable_grid", .type = GR_PT_BOOL, .offset = SH(stable_grid), .min = 0, .max = 1, .def = 0, .unit = "",
     .doc = "snap P to the grid spacing and quantize S (cross-fade between levels): shafts stay put"},
    {.name = "depth_test", .type = GR_PT_BOOL, .offset = SH(depth_test), .min = 0, .max = 1, .def = 0, .unit = "",
     .doc = "hide shaft surfaces behind the occluders and the seabed as seen from the eye"},
    {.name = "slabs", .type = GR_PT_INT, .offset = SH(slabs), .min = 1, .max = 256, .def = 16, .unit = "",
     .doc = "flux variant: depth slabs per shaft (each with its own cross-section area)"},
    {.name = "grid_eye_m", .type = GR_PT_RGB, .offset = SH(grid_eye_m), .min = -1e7, .max = 1e7, .flags = FROM,
     .def = NAN, .unit = "m", .scene_source = "camera.position_m",
     .doc = "[x, y, z] the shaft grid (P, S) is built for, the view staying the camera's (a debug freeze)"},
};
#undef SH

const gr_param_table gr_shafts_param_table = {
    "shafts", shafts_params, sizeof shafts_params / sizeof shafts_params[0]};
#undef LO_X
#undef HI_X
#undef FROM

const gr_shafts_settings *gr_shafts_scene_settings(const gr_scene *scene)
{
    return gr_technique_scene_settings(&gr_shafts_class, scene);
}

/* Uniform locations of a program built from shafts.vert.glsl (shaft pass and capture). */
typedef struct shaft_locs {
    GLint origin, spacing, width, length, extinction, sun_dir, eta, r0;
    GLint view_proj, shadow_matrix, wave_groups, waves, shadow_map, shadow_bias;
    GLint variant, ratio, refr_flat, sun_radius_w, prescale, depth_test, eye_depth, target_size;
    GLint half, corner_pos, corner_refr, shadow_dz;
} shaft_locs;

struct gr_shafts {
    gr_gl *gl;
    int owns_gl;     /* 1: made by gr_shafts_create, destroyed with the renderer */
    char *shader_dir;
    int from_dir;
    GLuint prog_shafts, prog_final, prog_capture;
    shaft_locs ls, lc;
    GLint loc_inv_vp, loc_texel, loc_shafts, loc_hgg, loc_refr_sun, loc_intensity, loc_bias;

    GLuint vao_grid, vbo_grid, ibo_grid;
    int grid_N, grid_slabs, grid_nshafts;
    float *grid_cpu; /* GRID_FLOATS floats per vertex: cell.xy, corner.xy, bottom, mid */
    gr_scenegl *scenegl; /* the occluders' shadow map, eye depth for depth_test (shared) */
    /* flux pre-pass: one texel per shaft corner (2 (N-1) per side), position + transmittance
     * and refracted direction (shafts_corner.frag.glsl) */
    GLuint prog_corner, corner_tex[2], corner_fbo;
    int corner_size;
    shaft_locs lk;
    /* flux: the shaft lattice (one vertex per lattice point and level, one quad per boundary
     * between regions) and the second pre-pass, irradiance per cell and slab */
    GLuint vao_lat, vbo_lat, ibo_lat;
    int lat_N, lat_slabs, lat_tiled, lat_M;
    long long lat_nidx;
    GLuint prog_flux;
    gr_target flux;
    GLint lf_corner_pos, lf_corner_refr, lf_tiled, lf_cells, lf_slabs, lf_length, lf_width, lf_sun_dir, lf_refr_flat,
        lf_sun_radius_w, lf_shadow_matrix, lf_shadow_map, lf_shadow_bias, lf_shadows;
    GLint ls_flux_e, ls_tiled, ls_lattice, ls_cells, ls_slabs, lk_tiled;

    GLuint vao_empty;
    gr_target target, frame; /* the shafts' reduced target, the god-ray layer */
    int target_fmt;          /* the format of the last render (TARGET_RGBA32F or a gr_shafts_format) */

    gr_gl_timer timer;       /* passes GR_SHAFTS_PASS_* */
    GLuint q_samples, q_vs, q_fs;
    int have_pipeline_stats;

    gr_readback rb;
    int rendered;
};

/* Everything one render needs, computed on the CPU in double. Matrices are row-major. */
typedef struct frame_setup {
    gr_shafts_settings s;
    int W, H, tw, th, N, nshafts;
    gr_dvec3 eye, P, T;
    double S;
    float origin_rel[3];
    int groups;
    float waves[MAX_WAVE_GROUPS * 5 * 4];
    /* stable_grid: two grid levels (spacing, snapped P, wave constants) and their weights */
    int n_levels;
    double lvl_S[2], lvl_weight[2];
    float lvl_origin[2][3];
    float lvl_waves[2][MAX_WAVE_GROUPS * 5 * 4];
    int fmt;          /* target format actually used (TARGET_RGBA32F for path, flux) */
    int caps, slabs;  /* caps drawn; slabs per shaft */
    float ratio;      /* path: cos(theta_i) / cos(theta_t) / width^2 */
    float sun_radius_w;
    float final_intensity[3], final_hgg[3], final_bias;
    gr_frame fr;      /* camera matrices, refracted sun (realtime/frame.h) */
    float view_proj[16], inv_view_proj[16]; /* column-major, viewer-relative (rotation only) */
    double shadow_half_m; /* half extent of the shared shadow map around P */
    double shadow_center[3]; /* P; with stable_grid snapped to whole map texels across the beam */
    float shadow_matrix[16]; /* column-major: viewer-relative -> shadow texture [0,1]^3 */
    float shadow_bias_depth, shadow_dz;  /* bias in depth units; metres per depth unit */
    float hgg[3];
} frame_setup;

/* ---- settings ------------------------------------------------------------------- */

/* The class's check (technique.c validated the table's ranges first): structural limits the
 * table may not express. */
static gr_status check_structure(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    const gr_shafts_settings *s = settings;
    (void)cls;
    if (s->N < 2) return gr_fail(err, GR_E_INPUT, "shafts.N = %d: must be >= 2 (N grid vertices make (N-1)^2 shafts)", s->N);
    if (s->N > 1024) return gr_fail(err, GR_E_INPUT, "shafts.N = %d: must be <= 1024", s->N);
    if (!(s->K > 0)) return gr_fail(err, GR_E_INPUT, "shafts.K = %g: must be > 0", s->K);
    if (!(s->target_scale > 0)) return gr_fail(err, GR_E_INPUT, "shafts.target_scale = %g: must be > 0", s->target_scale);
    if (!(s->shaft_width > 0)) return gr_fail(err, GR_E_INPUT, "shafts.shaft_width = %g: must be > 0", s->shaft_width);
    if (s->shadow_map_size < 1 || s->shadow_map_size > 16384)
        return gr_fail(err, GR_E_INPUT, "shafts.shadow_map_size = %d: must be in [1, 16384]", s->shadow_map_size);
    if (s->target_format != GR_TARGET_RGBA8 && s->target_format != GR_TARGET_RGBA16F)
        return gr_fail(err, GR_E_INPUT, "shafts.target_format: invalid choice %d", s->target_format);
    return GR_OK;
}

gr_status gr_shafts_check_settings(const gr_shafts_settings *s, gr_error *err)
{
    return gr_technique_check(&gr_shafts_class, s, err);
}

void gr_shafts_resolve(const gr_scene *scene, const gr_shafts_settings *s, gr_shafts_settings *out)
{
    *out = *s;
    for (int c = 0; c < 3; c++)
        if (isnan(out->extinction[c])) out->extinction[c] = scene->medium.extinction[c];
    if (isnan(out->g)) out->g = scene->medium.g;
    for (int c = 0; c < 3; c++)
        if (isnan(out->grid_eye_m[c])) out->grid_eye_m[c] = scene->camera.position_m[c];
}

/* ---- GL resources ------------------------------------------------------------------ */

static void get_shaft_locs(GLuint prog, shaft_locs *l)
{
    l->origin = glGetUniformLocation(prog, "u_origin");
    l->spacing = glGetUniformLocation(prog, "u_spacing");
    l->width = glGetUniformLocation(prog, "u_width");
    l->length = glGetUniformLocation(prog, "u_length");
    l->extinction = glGetUniformLocation(prog, "u_extinction");
    l->sun_dir = glGetUniformLocation(prog, "u_sun_dir");
    l->eta = glGetUniformLocation(prog, "u_eta");
    l->r0 = glGetUniformLocation(prog, "u_r0");
    l->view_proj = glGetUniformLocation(prog, "u_view_proj");
    l->shadow_matrix = glGetUniformLocation(prog, "u_shadow_matrix");
    l->wave_groups = glGetUniformLocation(prog, "u_wave_groups");
    l->waves = glGetUniformLocation(prog, "u_waves");
    l->shadow_map = glGetUniformLocation(prog, "u_shadow_map");
    l->shadow_bias = glGetUniformLocation(prog, "u_shadow_bias");
    l->variant = glGetUniformLocation(prog, "u_variant");
    l->ratio = glGetUniformLocation(prog, "u_ratio");
    l->refr_flat = glGetUniformLocation(prog, "u_refr_flat");
    l->sun_radius_w = glGetUniformLocation(prog, "u_sun_radius_w");
    l->prescale = glGetUniformLocation(prog, "u_prescale");
    l->depth_test = glGetUniformLocation(prog, "u_depth_test");
    l->eye_depth = glGetUniformLocation(prog, "u_eye_depth");
    l->target_size = glGetUniformLocation(prog, "u_target_size");
    l->half = glGetUniformLocation(prog, "u_half");
    l->corner_pos = glGetUniformLocation(prog, "u_corner_pos");
    l->corner_refr = glGetUniformLocation(prog, "u_corner_refr");
    l->shadow_dz = glGetUniformLocation(prog, "u_shadow_dz");
}

static int has_extension(const char *name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; i++) {
        const char *e = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
        if (e && !strcmp(e, name)) return 1;
    }
    return 0;
}

/* Programs, buffers and queries in r->gl (current). */
static gr_status setup_gl(gr_shafts *r, gr_error *err);

gr_status gr_shafts_create(const gr_shafts_options *opts, gr_shafts **out, gr_error *err)
{
    gr_shafts_options defaults;
    gr_status st;
    gr_gl *gl = NULL;
    *out = NULL;
    if (!opts) {
        memset(&defaults, 0, sizeof defaults);
        opts = &defaults;
    }
    if ((st = gr_shader_check_dir(opts->shader_dir, err)) != GR_OK) return st;
    if ((st = gr_gl_create(&opts->gl, &gl, err)) != GR_OK) return st;
    if ((st = gr_shafts_create_in(gl, opts->shader_dir, out, err)) != GR_OK) {
        gr_gl_destroy(gl);
        return st;
    }
    (*out)->owns_gl = 1;
    return GR_OK;
}

gr_status gr_shafts_create_in(gr_gl *gl, const char *shader_dir, gr_shafts **out, gr_error *err)
{
    gr_status st;
    *out = NULL;
    if ((st = gr_shader_check_dir(shader_dir, err)) != GR_OK) return st;
    gr_shafts *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "shafts renderer: out of memory");
    if (shader_dir) {
        size_t n = strlen(shader_dir) + 1;
        r->shader_dir = malloc(n);
        if (!r->shader_dir) {
            free(r);
            return gr_fail(err, GR_E_NOMEM, "shafts renderer: out of memory");
        }
        memcpy(r->shader_dir, shader_dir, n);
    }
    r->gl = gl;
    if ((st = setup_gl(r, err)) != GR_OK) {
        gr_shafts_destroy(r);
        return st;
    }
    *out = r;
    return GR_OK;
}

/* The shaft pass and the flux pre-pass compile seed_waves.glsl (the seed's waves and
 * surface function) in front of their own file. */
static const gr_shader_stage shaft_stages[2] = {{GL_VERTEX_SHADER, {"seed_waves.glsl", "shafts.vert.glsl", NULL}},
                                                {GL_FRAGMENT_SHADER, {"shafts.frag.glsl", NULL}}};
static const gr_shader_stage corner_stages[2] = {{GL_VERTEX_SHADER, {"shafts_final.vert.glsl", NULL}},
                                                 {GL_FRAGMENT_SHADER, {"seed_waves.glsl", "shafts_corner.frag.glsl", NULL}}};

static gr_status setup_gl(gr_shafts *r, gr_error *err)
{
    gr_status st;
    int nd = 0;
    /* the occluders' shadow map and eye depth are scenegl's, shared with every technique */
    if ((st = gr_scenegl_create_dir(r->gl, r->shader_dir, &r->scenegl, err)) != GR_OK) return st;
    if ((st = gr_shader_program_stages(r->shader_dir, shaft_stages, 2, NULL, 0, &r->prog_shafts, &nd, err)) != GR_OK)
        return st;
    r->from_dir += nd;
    if ((st = gr_shader_program(r->shader_dir, "shafts_final.vert.glsl", "shafts_final.frag.glsl", NULL, 0,
                                &r->prog_final, &nd, err)) != GR_OK)
        return st;
    r->from_dir += nd;

    if ((st = gr_shader_program_stages(r->shader_dir, corner_stages, 2, NULL, 0, &r->prog_corner, &nd, err)) != GR_OK)
        return st;
    r->from_dir += nd;
    get_shaft_locs(r->prog_corner, &r->lk);
    r->lk_tiled = glGetUniformLocation(r->prog_corner, "u_tiled");
    if ((st = gr_shader_program(r->shader_dir, "shafts_final.vert.glsl", "shafts_flux.frag.glsl", NULL, 0,
                                &r->prog_flux, &nd, err)) != GR_OK)
        return st;
    r->from_dir += nd;
    r->lf_corner_pos = glGetUniformLocation(r->prog_flux, "u_corner_pos");
    r->lf_corner_refr = glGetUniformLocation(r->prog_flux, "u_corner_refr");
    r->lf_tiled = glGetUniformLocation(r->prog_flux, "u_tiled");
    r->lf_cells = glGetUniformLocation(r->prog_flux, "u_cells");
    r->lf_slabs = glGetUniformLocation(r->prog_flux, "u_slabs");
    r->lf_length = glGetUniformLocation(r->prog_flux, "u_length");
    r->lf_width = glGetUniformLocation(r->prog_flux, "u_width");
    r->lf_sun_dir = glGetUniformLocation(r->prog_flux, "u_sun_dir");
    r->lf_refr_flat = glGetUniformLocation(r->prog_flux, "u_refr_flat");
    r->lf_sun_radius_w = glGetUniformLocation(r->prog_flux, "u_sun_radius_w");
    r->lf_shadow_matrix = glGetUniformLocation(r->prog_flux, "u_shadow_matrix");
    r->lf_shadow_map = glGetUniformLocation(r->prog_flux, "u_shadow_map");
    r->lf_shadow_bias = glGetUniformLocation(r->prog_flux, "u_shadow_bias");
    r->lf_shadows = glGetUniformLocation(r->prog_flux, "u_shadows");
    get_shaft_locs(r->prog_shafts, &r->ls);
    r->ls_flux_e = glGetUniformLocation(r->prog_shafts, "u_flux_e");
    r->ls_tiled = glGetUniformLocation(r->prog_shafts, "u_tiled");
    r->ls_lattice = glGetUniformLocation(r->prog_shafts, "u_lattice");
    r->ls_cells = glGetUniformLocation(r->prog_shafts, "u_cells");
    r->ls_slabs = glGetUniformLocation(r->prog_shafts, "u_slabs");
    r->loc_inv_vp = glGetUniformLocation(r->prog_final, "u_inv_view_proj");
    r->loc_texel = glGetUniformLocation(r->prog_final, "u_texel");
    r->loc_shafts = glGetUniformLocation(r->prog_final, "u_shafts");
    r->loc_hgg = glGetUniformLocation(r->prog_final, "u_hgg");
    r->loc_refr_sun = glGetUniformLocation(r->prog_final, "u_refr_sun");
    r->loc_intensity = glGetUniformLocation(r->prog_final, "u_intensity");
    r->loc_bias = glGetUniformLocation(r->prog_final, "u_bias");

    glGenVertexArrays(1, &r->vao_grid);
    glGenBuffers(1, &r->vbo_grid);
    glGenBuffers(1, &r->ibo_grid);
    glGenVertexArrays(1, &r->vao_empty);
    glGenVertexArrays(1, &r->vao_lat);
    glGenBuffers(1, &r->vbo_lat);
    glGenBuffers(1, &r->ibo_lat);
    gr_gl_timer_init(&r->timer);
    glGenQueries(1, &r->q_samples);
    /* Pipeline statistics need GL 4.6 or the ARB extension. */
    int major = 0, minor = 0;
    gr_gl_context_version(r->gl, &major, &minor);
    r->have_pipeline_stats = (major > 4 || (major == 4 && minor >= 6)) ||
                             has_extension("GL_ARB_pipeline_statistics_query");
    if (r->have_pipeline_stats) {
        glGenQueries(1, &r->q_vs);
        glGenQueries(1, &r->q_fs);
    }
    return gr_gl_check("shafts renderer setup", err);
}

void gr_shafts_destroy(gr_shafts *r)
{
    if (!r) return;
    if (r->gl) {
        gr_gl_make_current(r->gl, NULL);
        if (r->prog_shafts) glDeleteProgram(r->prog_shafts);
        if (r->prog_final) glDeleteProgram(r->prog_final);
        if (r->prog_capture) glDeleteProgram(r->prog_capture);
        if (r->prog_corner) glDeleteProgram(r->prog_corner);
        if (r->corner_fbo) glDeleteFramebuffers(1, &r->corner_fbo);
        if (r->corner_tex[0]) glDeleteTextures(2, r->corner_tex);
        if (r->vao_grid) glDeleteVertexArrays(1, &r->vao_grid);
        if (r->vbo_grid) glDeleteBuffers(1, &r->vbo_grid);
        if (r->ibo_grid) glDeleteBuffers(1, &r->ibo_grid);
        if (r->vao_empty) glDeleteVertexArrays(1, &r->vao_empty);
        if (r->prog_flux) glDeleteProgram(r->prog_flux);
        if (r->vao_lat) glDeleteVertexArrays(1, &r->vao_lat);
        if (r->vbo_lat) glDeleteBuffers(1, &r->vbo_lat);
        if (r->ibo_lat) glDeleteBuffers(1, &r->ibo_lat);
        gr_target_release(&r->flux);
        gr_gl_timer_free(&r->timer);
        if (r->q_samples) glDeleteQueries(1, &r->q_samples);
        if (r->q_vs) glDeleteQueries(1, &r->q_vs);
        if (r->q_fs) glDeleteQueries(1, &r->q_fs);
        gr_target_release(&r->target);
        gr_target_release(&r->frame);
        gr_scenegl_destroy(r->scenegl);
        if (r->owns_gl) gr_gl_destroy(r->gl);
    }
    free(r->grid_cpu);
    gr_readback_free(&r->rb);
    free(r->shader_dir);
    free(r);
}

const gr_gl *gr_shafts_gl(const gr_shafts *r) { return r ? r->gl : NULL; }
int gr_shafts_shaders_from_dir(const gr_shafts *r) { return r ? r->from_dir : 0; }

/* Static shaft geometry for N grid vertices per side: (N-1)^2 separate parallelepipeds,
 * one per grid cell, each cut into `slabs` closed slabs along its length (1 but for the flux
 * variant), 8 vertices per slab; indices: all lateral faces first, then all caps, so one draw
 * call covers "caps off" (24 per slab) or "caps on" (36 per slab). Every face is wound
 * counter-clockwise seen from outside the slab (outward normals), which the path and flux
 * variants need to tell entry faces (front-facing) from exit faces. */
static gr_status ensure_grid(gr_shafts *r, int N, int slabs, gr_error *err)
{
    if (r->grid_N == N && r->grid_slabs == slabs) return GR_OK;
    int cells = N - 1;
    int ns = cells * cells * slabs;
    size_t nv = (size_t)ns * 8;
    float *v = malloc(nv * GRID_FLOATS * sizeof *v);
    GLuint *idx = malloc((size_t)ns * 36 * sizeof *idx);
    if (!v || !idx) {
        free(v);
        free(idx);
        return gr_fail(err, GR_E_NOMEM, "shafts.N = %d: out of memory for the shaft grid", N);
    }
    static const float corners[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};
    /* x right, z forward, y up: face 0-1-5-4 (z = -0.5 side) has normal (1,0,0) x (1,-1,0) =
     * (0,0,-1), outward; the top cap 0-3-2-1 faces +y, the bottom cap 4-5-6-7 faces -y. */
    static const int lateral[4][4] = {{0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    static const int cap[2][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}};
    double half = 0.5 * (double)(N - 1);
    GLuint *lat = idx, *caps = idx + (size_t)ns * 24;
    for (int j = 0; j < cells; j++)
        for (int i = 0; i < cells; i++)
            for (int b = 0; b < slabs; b++) {
                int sh = (j * cells + i) * slabs + b;
                float cx = (float)((double)i + 0.5 - half), cz = (float)((double)j + 0.5 - half);
                for (int k = 0; k < 8; k++) {
                    float *p = v + ((size_t)sh * 8 + (size_t)k) * GRID_FLOATS;
                    p[0] = cx;
                    p[1] = cz;
                    p[2] = corners[k & 3][0];
                    p[3] = corners[k & 3][1];
                    p[4] = (float)((double)(b + (k >= 4 ? 1 : 0)) / (double)slabs);
                    p[5] = (float)(((double)b + 0.5) / (double)slabs);
                }
                GLuint base = (GLuint)sh * 8u;
                for (int f = 0; f < 4; f++) {
                    const int *q = lateral[f];
                    GLuint *o = lat + (size_t)sh * 24 + (size_t)f * 6;
                    o[0] = base + (GLuint)q[0]; o[1] = base + (GLuint)q[1]; o[2] = base + (GLuint)q[2];
                    o[3] = base + (GLuint)q[0]; o[4] = base + (GLuint)q[2]; o[5] = base + (GLuint)q[3];
                }
                for (int f = 0; f < 2; f++) {
                    const int *q = cap[f];
                    GLuint *o = caps + (size_t)sh * 12 + (size_t)f * 6;
                    o[0] = base + (GLuint)q[0]; o[1] = base + (GLuint)q[1]; o[2] = base + (GLuint)q[2];
                    o[3] = base + (GLuint)q[0]; o[4] = base + (GLuint)q[2]; o[5] = base + (GLuint)q[3];
                }
            }
    glBindVertexArray(r->vao_grid);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_grid);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * GRID_FLOATS * sizeof *v), v, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->ibo_grid);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)((size_t)ns * 36 * sizeof *idx), idx, GL_STATIC_DRAW);
    GLsizei stride = (GLsizei)(GRID_FLOATS * sizeof(float));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, (const void *)0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, stride, (const void *)(2 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, (const void *)(4 * sizeof(float)));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, stride, (const void *)(5 * sizeof(float)));
    glBindVertexArray(0);
    free(idx);
    free(r->grid_cpu);
    r->grid_cpu = v;
    r->grid_N = N;
    r->grid_slabs = slabs;
    r->grid_nshafts = ns;
    return gr_gl_check("shafts.N: uploading the shaft grid", err);
}

/* The flux pre-pass's two RGBA32F lattice textures, M texels per side. */
static gr_status ensure_corners(gr_shafts *r, int N, int n, gr_error *err)
{
    if (r->corner_size == n && r->corner_fbo) return GR_OK;
    if (r->corner_fbo) glDeleteFramebuffers(1, &r->corner_fbo);
    if (r->corner_tex[0]) glDeleteTextures(2, r->corner_tex);
    r->corner_size = 0;
    glGenTextures(2, r->corner_tex);
    glGenFramebuffers(1, &r->corner_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, r->corner_fbo);
    for (int i = 0; i < 2; i++) {
        glBindTexture(GL_TEXTURE_2D, r->corner_tex[i]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, n, n);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, r->corner_tex[i], 0);
    }
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, bufs);
    glBindTexture(GL_TEXTURE_2D, 0);
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (fs != GL_FRAMEBUFFER_COMPLETE)
        return gr_fail(err, GR_E_GL, "shafts.N = %d: flux corner target %dx%d incomplete (0x%04x)", N, n, n, (unsigned)fs);
    r->corner_size = n;
    return gr_gl_check("shafts.N: flux corner target", err);
}

/* Flux: the shaft lattice for N grid vertices, `slabs` depth slabs, tiled (shaft_width 1: the
 * lattice points are the N grid lines per side) or not (M = 2 (N - 1): each cell's two
 * corners). Vertices: (p, q, level / slabs) for every lattice point and level 0..slabs. Quads,
 * each wound counter-clockwise seen from the side its normal points to (docs "flux"):
 * x faces (normal +x) on every lattice line p, across each cell's z extent, per slab; z faces
 * (normal +z) likewise; caps (normal down) of every cell at every level. The fragment shader
 * finds a quad's two regions from gl_PrimitiveID / 2 in exactly this order. */
static gr_status ensure_lattice(gr_shafts *r, int N, int slabs, int tiled, gr_error *err)
{
    if (r->lat_N == N && r->lat_slabs == slabs && r->lat_tiled == tiled) return GR_OK;
    int C = N - 1, M = tiled ? N : 2 * (N - 1), L = slabs + 1;
    size_t nv = (size_t)M * (size_t)M * (size_t)L;
    size_t nq = 2 * (size_t)M * (size_t)C * (size_t)slabs + (size_t)L * (size_t)C * (size_t)C;
    if (nv > 0x7fffffffu / 4 || nq * 6 > 0x7fffffffu)
        return gr_fail(err, GR_E_INPUT, "shafts.N = %d, shafts.slabs = %d: flux lattice too large", N, slabs);
    float *v = malloc(nv * 3 * sizeof *v);
    GLuint *idx = malloc(nq * 6 * sizeof *idx);
    if (!v || !idx) {
        free(v);
        free(idx);
        return gr_fail(err, GR_E_NOMEM, "shafts.N = %d, shafts.slabs = %d: out of memory for the flux lattice", N, slabs);
    }
#define LV(p, q, b) ((GLuint)((((size_t)(b) * (size_t)M) + (size_t)(q)) * (size_t)M + (size_t)(p)))
    for (int b = 0; b < L; b++)
        for (int q = 0; q < M; q++)
            for (int p = 0; p < M; p++) {
                float *o = v + (size_t)LV(p, q, b) * 3;
                o[0] = (float)p;
                o[1] = (float)q;
                o[2] = (float)((double)b / (double)slabs);
            }
    GLuint *o = idx;
#define QUAD(a, b2, c, d) do { o[0] = (a); o[1] = (b2); o[2] = (c); o[3] = (a); o[4] = (c); o[5] = (d); o += 6; } while (0)
    for (int b = 0; b < slabs; b++) /* x faces: (p, z0, b) (p, z1, b) (p, z1, b+1) (p, z0, b+1): normal +x */
        for (int p = 0; p < M; p++)
            for (int j = 0; j < C; j++) {
                int z0 = tiled ? j : 2 * j;
                QUAD(LV(p, z0, b), LV(p, z0 + 1, b), LV(p, z0 + 1, b + 1), LV(p, z0, b + 1));
            }
    for (int b = 0; b < slabs; b++) /* z faces: (x0, q, b) (x0, q, b+1) (x1, q, b+1) (x1, q, b): normal +z */
        for (int q = 0; q < M; q++)
            for (int i = 0; i < C; i++) {
                int x0 = tiled ? i : 2 * i;
                QUAD(LV(x0, q, b), LV(x0, q, b + 1), LV(x0 + 1, q, b + 1), LV(x0 + 1, q, b));
            }
    for (int b = 0; b < L; b++) /* caps: (x0, z0) (x1, z0) (x1, z1) (x0, z1): normal down */
        for (int j = 0; j < C; j++)
            for (int i = 0; i < C; i++) {
                int x0 = tiled ? i : 2 * i, z0 = tiled ? j : 2 * j;
                QUAD(LV(x0, z0, b), LV(x0 + 1, z0, b), LV(x0 + 1, z0 + 1, b), LV(x0, z0 + 1, b));
            }
#undef QUAD
#undef LV
    glBindVertexArray(r->vao_lat);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_lat);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof *v), v, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, r->ibo_lat);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(nq * 6 * sizeof *idx), idx, GL_STATIC_DRAW);
    GLsizei stride = (GLsizei)(3 * sizeof(float));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, (const void *)0);
    glDisableVertexAttribArray(1);
    glVertexAttrib2f(1, 0.0f, 0.0f);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, (const void *)(2 * sizeof(float)));
    glBindVertexArray(0);
    free(v);
    free(idx);
    r->lat_N = N;
    r->lat_slabs = slabs;
    r->lat_tiled = tiled;
    r->lat_M = M;
    r->lat_nidx = (long long)nq * 6;
    return gr_gl_check("shafts.N: uploading the flux lattice", err);
}

static gr_status ensure_targets(gr_shafts *r, const frame_setup *f, gr_error *err)
{
    GLenum ifmt = f->fmt == TARGET_RGBA32F ? GL_RGBA32F : f->fmt == GR_TARGET_RGBA16F ? GL_RGBA16F : GL_RGBA8;
    gr_status st = gr_target_ensure(&r->target, ifmt, f->tw, f->th, GR_TARGET_LINEAR,
                                    "shafts.target_scale: shaft render target", err);
    if (st != GR_OK) return st;
    r->target_fmt = f->fmt;
    return gr_target_ensure(&r->frame, GL_RGBA32F, f->W, f->H, 0, "camera.width/height: god-ray layer target", err);
}

/* ---- per-render setup on the CPU ----------------------------------------------------- */

/* checked: the settings passed gr_technique_check already (the class's render); the direct
 * API (gr_shafts_render, gr_shafts_capture) checks them here, through the same function. */
static gr_status setup_frame(const gr_scene *scene, const gr_shafts_settings *in, int checked, frame_setup *f,
                             gr_error *err)
{
    memset(f, 0, sizeof *f);
    gr_shafts_resolve(scene, in ? in : gr_shafts_scene_settings(scene), &f->s);
    gr_status st = checked ? GR_OK : gr_shafts_check_settings(&f->s, err);
    if (st != GR_OK) return st;
    const gr_shafts_settings *s = &f->s;
    for (int c = 0; c < 3; c++) {
        if (!(isfinite(s->extinction[c]) && s->extinction[c] >= 0))
            return gr_fail(err, GR_E_INPUT, "shafts.extinction[%d] = %g: must be a finite number >= 0", c, s->extinction[c]);
    }
    if (!(isfinite(s->g) && fabs(s->g) < 1.0))
        return gr_fail(err, GR_E_INPUT, "shafts.g = %g: must be in (-1, 1)", s->g);

    const gr_camera *cam = &scene->camera;
    f->W = cam->width;
    f->H = cam->height;
    if (f->W < 1 || f->H < 1 || f->W > 16384 || f->H > 16384)
        return gr_fail(err, GR_E_INPUT, "camera.width/height = %dx%d: must be in [1, 16384]", f->W, f->H);
    f->tw = (int)lround((double)f->W * s->target_scale);
    f->th = (int)lround((double)f->H * s->target_scale);
    if (f->tw < 1) f->tw = 1;
    if (f->th < 1) f->th = 1;
    if (f->tw > 16384 || f->th > 16384)
        return gr_fail(err, GR_E_INPUT, "shafts.target_scale = %g: target %dx%d is too large", s->target_scale, f->tw, f->th);
    f->N = s->N;
    f->nshafts = (s->N - 1) * (s->N - 1);

    /* Seed eqs. 5.5.5-5.5.6: recentering point P and spacing S from the viewer's depth. */
    const gr_water *w = &scene->water;
    double h0 = w->rest_height_m;
    f->eye = gr_d3(cam->position_m[0], cam->position_m[1], cam->position_m[2]);
    double depth = h0 - f->eye.y;
    if (!(depth > 0))
        return gr_fail(err, GR_E_INPUT, "camera.position_m: y = %g is not below the water surface (y = %g); "
                       "the shafts renderer needs an underwater viewer", f->eye.y, h0);
    /* The grid is built for shafts.grid_eye_m (resolved: the camera's position unless set),
     * the view stays the camera's: P and S below come from that eye, every position sent to
     * GL is relative to the camera's (docs "stable_grid": the layer's own change). */
    const gr_dvec3 ge = gr_d3(s->grid_eye_m[0], s->grid_eye_m[1], s->grid_eye_m[2]);
    const double grid_depth = h0 - ge.y;
    if (!(grid_depth > 0))
        return gr_fail(err, GR_E_INPUT, "shafts.grid_eye_m: y = %g is not below the water surface (y = %g)", ge.y, h0);
    gr_dvec3 I = gr_d3(scene->sun.dir[0], scene->sun.dir[1], scene->sun.dir[2]);
    double ior = scene->medium.ior;
    f->P = gr_shafts_center(ge, I, h0, ior, &f->T);
    f->S = gr_shafts_spacing(s->K, grid_depth, cam->fov_deg * GR_PI / 180.0, s->N);
    if (!(isfinite(f->P.x) && isfinite(f->P.z) && f->S > 0 && isfinite(f->S)))
        return gr_fail(err, GR_E_INPUT, "sun.elevation_deg: no finite recentering point P for this sun and camera");
    if (w->n_waves > MAX_WAVE_GROUPS * 4)
        return gr_fail(err, GR_E_INPUT, "water.waves: %d waves, the shafts renderer takes at most %d",
                       w->n_waves, MAX_WAVE_GROUPS * 4);
    f->groups = (w->n_waves + 3) / 4;
    double amp_sum = 0.0, steep = 0.0;
    for (int i = 0; i < w->n_waves; i++) {
        amp_sum += fabs(w->waves[i].amplitude_m);
        steep += fabs(w->waves[i].amplitude_m) * w->waves[i].k;
    }
    /* Grid levels: one at (P, S); with stable_grid, S quantized to powers of two 2^l <= S <
     * 2^(l+1), cross-faded by the fraction of log2 S, and P snapped to each level's spacing
     * (docs/realtime-shafts.md "stable_grid"). */
    f->n_levels = 1;
    f->lvl_S[0] = f->S;
    f->lvl_weight[0] = 1.0;
    gr_dvec3 lvl_P[2] = {f->P, f->P};
    if (s->stable_grid) {
        double L = log2(f->S), l = floor(L), a = L - l;
        f->lvl_S[0] = exp2(l);
        f->lvl_S[1] = exp2(l + 1.0);
        f->lvl_weight[0] = 1.0 - a;
        f->lvl_weight[1] = a;
        f->n_levels = 2;
        for (int k = 0; k < 2; k++) {
            double Sk = f->lvl_S[k];
            lvl_P[k] = gr_d3(Sk * floor(f->P.x / Sk + 0.5), f->P.y, Sk * floor(f->P.z / Sk + 0.5));
        }
    }
    /* Wave constants, packed by groups of 4 like the seed: kx, kz, A/|k|, A, c, with
     * c = w t - phi0 - k.P folded mod 2 pi in double (eq. 5.5.7: phase = k.X0 - w t + phi0). */
    double t = w->time_s;
    for (int k = 0; k < f->n_levels; k++) {
        gr_dvec3 rel = gr_d3_sub(lvl_P[k], f->eye);
        f->lvl_origin[k][0] = (float)rel.x;
        f->lvl_origin[k][1] = (float)rel.y;
        f->lvl_origin[k][2] = (float)rel.z;
        for (int i = 0; i < w->n_waves; i++) {
            const gr_wave *wv = &w->waves[i];
            int g = i / 4, lane = i % 4;
            double kx = wv->k * wv->dir[0], kz = wv->k * wv->dir[1];
            double c = wv->omega_rad_s * t - wv->phase_rad - (kx * lvl_P[k].x + kz * lvl_P[k].z);
            c = fmod(c, 2.0 * GR_PI);
            float *base = f->lvl_waves[k] + (size_t)g * 20;
            base[0 * 4 + lane] = (float)kx;
            base[1 * 4 + lane] = (float)kz;
            base[2 * 4 + lane] = wv->k > 0 ? (float)(wv->amplitude_m / wv->k) : 0.0f;
            base[3 * 4 + lane] = (float)wv->amplitude_m;
            base[4 * 4 + lane] = (float)c;
        }
    }
    memcpy(f->origin_rel, f->lvl_origin[0], sizeof f->origin_rel);
    memcpy(f->waves, f->lvl_waves[0], sizeof f->waves);

    /* Variant: target format, caps, slabs, physical factors (docs "Variants"). */
    double cos_i = fabs(I.y), cos_t = fabs(f->T.y);
    f->fmt = s->variant == GR_SHAFTS_SEED ? s->target_format : TARGET_RGBA32F;
    f->caps = s->variant == GR_SHAFTS_SEED ? s->caps : 1; /* signed sums need closed shafts */
    f->slabs = 1; /* the per-shaft grid of seed and path; flux draws the lattice (ensure_lattice) */
    f->ratio = (float)(cos_i / fmax(cos_t, 1e-9) / (s->shaft_width * s->shaft_width));
    double alpha = 0.5 * scene->sun.angular_diameter_deg * GR_PI / 180.0;
    f->sun_radius_w = (float)(alpha * cos_i / (ior * fmax(cos_t, 1e-9)));
    double gv = s->variant == GR_SHAFTS_SEED ? s->g : scene->medium.g;
    f->final_hgg[0] = (float)(1.0 - gv * gv);
    f->final_hgg[1] = (float)(1.0 + gv * gv);
    f->final_hgg[2] = (float)(2.0 * gv);
    for (int c = 0; c < 3; c++) {
        double phys = s->variant == GR_SHAFTS_SEED ? 1.0
                                                   : scene->medium.scattering[c] * scene->sun.irradiance[c] / (4.0 * GR_PI);
        f->final_intensity[c] = (float)(s->intensity[c] * phys / s->target_prescale);
    }
    f->final_bias = s->variant == GR_SHAFTS_SEED ? (float)s->bias : 0.0f;

    /* Camera: frame.h's matrices without the eye translation (positions are viewer-relative). */
    gr_frame_init(scene, &f->fr);
    double vp[16], ivp[16];
    gr_frame_view_proj_rot(&f->fr, vp);
    if (gr_mat4_inverse(vp, ivp) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection matrix");
    gr_frame_matf(vp, f->view_proj);
    gr_frame_matf(ivp, f->inv_view_proj);

    /* Shadow map: scenegl's, orthographic along T, centred on P, covering the grid's diagonal
     * plus the waves' amplitude plus the extrusion's possible spread (docs: D13). */
    double half_grid = 0.5 * (double)s->N * f->lvl_S[f->n_levels - 1] * fmax(1.0, s->shaft_width)
                       + (s->stable_grid ? f->lvl_S[f->n_levels - 1] : 0.0);
    f->shadow_half_m = sqrt(2.0) * half_grid + amp_sum + s->shaft_length_m * fmin(1.0, steep + 0.05);
    /* stable_grid: the map's texels fixed in the world too (its centre snapped to whole texels
     * across the beam; half_m depends on the depth only), so shadow edges do not shimmer */
    f->shadow_center[0] = f->P.x, f->shadow_center[1] = f->P.y, f->shadow_center[2] = f->P.z;
    if (s->stable_grid)
        gr_scenegl_shadow_snap(&f->fr, s->shadow_map_size, f->shadow_half_m, f->shadow_center, f->shadow_center);
    /* Seed's packed Mie parameters HGg = (1 - g^2, 1 + g^2, 2 g). */
    f->hgg[0] = (float)(1.0 - s->g * s->g);
    f->hgg[1] = (float)(1.0 + s->g * s->g);
    f->hgg[2] = (float)(2.0 * s->g);
    return GR_OK;
}

static void set_shaft_uniforms(GLuint prog, const shaft_locs *l, const frame_setup *f, const gr_scene *scene)
{
    const gr_shafts_settings *s = &f->s;
    glUseProgram(prog);
    glUniform3fv(l->origin, 1, f->origin_rel);
    glUniform1f(l->spacing, (float)f->lvl_S[0]);
    glUniform1f(l->width, (float)s->shaft_width);
    glUniform1f(l->length, (float)s->shaft_length_m);
    glUniform3f(l->extinction, (float)s->extinction[0], (float)s->extinction[1], (float)s->extinction[2]);
    glUniform3f(l->sun_dir, (float)scene->sun.dir[0], (float)scene->sun.dir[1], (float)scene->sun.dir[2]);
    glUniform1f(l->eta, (float)(1.0 / scene->medium.ior));
    glUniform1f(l->r0, (float)gr_fresnel_r0(1.0, scene->medium.ior));
    glUniformMatrix4fv(l->view_proj, 1, GL_FALSE, f->view_proj);
    glUniformMatrix4fv(l->shadow_matrix, 1, GL_FALSE, f->shadow_matrix);
    glUniform1i(l->wave_groups, f->groups);
    if (f->groups > 0) glUniform4fv(l->waves, f->groups * 5, f->waves);
    glUniform1i(l->shadow_map, 0);
    glUniform1f(l->shadow_bias, f->shadow_bias_depth);
    /* path, flux: shafts end where the shadow map has a caster (0: no map, capture) */
    glUniform1f(l->shadow_dz, s->variant == GR_SHAFTS_SEED ? 0.0f : f->shadow_dz);
    glUniform1i(l->variant, s->variant);
    glUniform1f(l->ratio, f->ratio);
    glUniform3f(l->refr_flat, (float)f->T.x, (float)f->T.y, (float)f->T.z);
    glUniform1f(l->sun_radius_w, f->sun_radius_w);
    glUniform1f(l->prescale, (float)s->target_prescale);
    glUniform1i(l->depth_test, s->depth_test);
    glUniform1i(l->eye_depth, 1);
    glUniform2f(l->target_size, (float)f->tw, (float)f->th);
    glUniform1f(l->half, (float)(0.5 * (double)(f->N - 1)));
    glUniform1i(l->corner_pos, 2);
    glUniform1i(l->corner_refr, 3);
}

/* The passes' cost counters (technique.h) after a render: queried primitives (the timer's)
 * and shaft fragments (GL_SAMPLES_PASSED), the rest from what was drawn (docs/realtime-shafts.md,
 * "Cost"). */
static void count_cost(gr_shafts *r, const frame_setup *f, long long n_idx, gr_shafts_stats *st)
{
    for (int p = 0; p < GR_SHAFTS_NPASS; p++) {
        gr_pass_cost_clear(&st->cost[p]);
        long long prims = gr_gl_timer_primitives(&r->timer, p);
        if (prims >= 0) {
            st->cost[p].v[GR_COST_PRIMITIVES] = prims;
            st->cost[p].queried |= 1u << GR_COST_PRIMITIVES;
        }
        st->cost[p].v[GR_COST_INVOCATIONS] = 0;
    }
    /* shadow: scenegl's depth map, DEPTH_COMPONENT32F, cleared then drawn (each texel once at least) */
    const long long sm = (long long)f->s.shadow_map_size * f->s.shadow_map_size;
    st->cost[GR_SHAFTS_PASS_SHADOW].v[GR_COST_BYTES] = sm * 4;
    st->cost[GR_SHAFTS_PASS_SHADOW].v[GR_COST_TAPS] = 0;
    /* shafts: every level with a weight draws the index buffer; a fragment takes the shadow
     * tap, the eye-depth tap with depth_test, and blends one texel (read + write counted once) */
    int levels = 0;
    for (int k = 0; k < f->n_levels; k++) levels += f->lvl_weight[k] > 0.0;
    const int bpp = f->fmt == TARGET_RGBA32F ? 16 : f->fmt == GR_TARGET_RGBA16F ? 8 : 4;
    const long long frag = st->fragments, tpx = (long long)f->tw * f->th;
    gr_pass_cost *c = &st->cost[GR_SHAFTS_PASS_SHAFTS];
    c->v[GR_COST_FRAGMENTS] = frag;
    c->queried |= 1u << GR_COST_FRAGMENTS;
    c->v[GR_COST_VERTICES] = n_idx * levels;
    c->v[GR_COST_TAPS] = frag * (1 + (f->s.depth_test ? 1 : 0) + (f->s.variant == GR_SHAFTS_FLUX ? 1 : 0));
    c->v[GR_COST_BYTES] = tpx * bpp + frag * bpp; /* the clear, then each blended fragment */
    /* final: a full-screen strip (4 vertices, 2 triangles), 4 bilinear taps, one RGBA32F write */
    gr_pass_cost fin = gr_pass_cost_screen(f->W, f->H, 4, 16);
    fin.v[GR_COST_VERTICES] = 4;
    fin.v[GR_COST_PRIMITIVES] = st->cost[GR_SHAFTS_PASS_FINAL].v[GR_COST_PRIMITIVES];
    fin.queried = st->cost[GR_SHAFTS_PASS_FINAL].queried;
    st->cost[GR_SHAFTS_PASS_FINAL] = fin;
}

static gr_status render_frame(gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s, int checked,
                              gr_image *out, gr_shafts_stats *stats, gr_error *err)
{
    double t0 = gr_clock_ms();
    frame_setup *f = malloc(sizeof *f);
    gr_status st;
    if (!f) return gr_fail(err, GR_E_NOMEM, "shafts: out of memory");
    if ((st = setup_frame(scene, s, checked, f, err)) != GR_OK) goto done;
    int ch[3] = {gr_image_channel(out, "R"), gr_image_channel(out, "G"), gr_image_channel(out, "B")};
    if (out->width != f->W || out->height != f->H || ch[0] < 0 || ch[1] < 0 || ch[2] < 0) {
        st = gr_fail(err, GR_E_INPUT, "shafts: output image is %dx%d (needs %dx%d with R, G, B channels)",
                     out->width, out->height, f->W, f->H);
        goto done;
    }
    if ((st = gr_gl_make_current(r->gl, err)) != GR_OK) goto done;
    gr_gl_timer_reset(&r->timer);
    if ((st = ensure_grid(r, f->N, f->slabs, err)) != GR_OK) goto done;
    if ((st = ensure_targets(r, f, err)) != GR_OK) goto done;
    const int tiled = f->s.shaft_width >= 1.0;
    if (f->s.variant == GR_SHAFTS_FLUX) {
        int C = f->N - 1;
        if ((long long)C * f->s.slabs > 16384) {
            st = gr_fail(err, GR_E_INPUT, "shafts.slabs = %d: (N - 1) x slabs = %lld must be <= 16384", f->s.slabs,
                         (long long)C * f->s.slabs);
            goto done;
        }
        if ((st = ensure_lattice(r, f->N, f->s.slabs, tiled, err)) != GR_OK) goto done;
        if ((st = ensure_corners(r, f->N, r->lat_M, err)) != GR_OK) goto done;
        if ((st = gr_target_ensure(&r->flux, GL_R32F, C, C * f->s.slabs, 0, "shafts.slabs: flux irradiance target",
                                   err)) != GR_OK)
            goto done;
    }
    GLuint eye_depth_tex = 0;
    if (f->s.depth_test) {
        /* scenegl's eye depth of the occluders and seabed at the target's resolution */
        unsigned tex = 0;
        if ((st = gr_scenegl_eye_depth(r->scenegl, scene, &f->fr, f->tw, f->th, &tex, err)) != GR_OK) goto done;
        eye_depth_tex = tex;
    }
    /* Pass 1: scenegl's shadow map of the occluders from P along T (seed: "from the point of
     * view of the light source P"; docs: D13). */
    gr_gl_timer_begin(&r->timer, GR_SHAFTS_PASS_SHADOW);
    unsigned shadow_tex = 0;
    double light_vp[16];
    st = gr_scenegl_shadow_map(r->scenegl, scene, &f->fr, f->s.shadow_map_size, f->shadow_center, f->shadow_half_m,
                               &shadow_tex, light_vp, err);
    gr_gl_timer_end(&r->timer);
    if (st != GR_OK) goto done;
    {
        /* viewer-relative -> world -> light clip -> [0,1]^3 texture space, in double (GL: origin
         * at the bottom-left, no D3D y flip or half-texel offset); light_vp's z row is
         * 2 T / dz, so a texture depth unit is dz metres */
        const double *e = f->fr.eye;
        double to_world[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, e[0], e[1], e[2], 1};
        double bias[16] = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0.5, 0.5, 0.5, 1};
        double sm[16];
        gr_mat4_mul(light_vp, to_world, sm);
        gr_mat4_mul(bias, sm, sm);
        gr_frame_matf(sm, f->shadow_matrix);
        double zr = sqrt(light_vp[2] * light_vp[2] + light_vp[6] * light_vp[6] + light_vp[10] * light_vp[10]);
        double dz = zr > 0 ? 2.0 / zr : 1.0;
        f->shadow_dz = (float)dz;
        f->shadow_bias_depth = (float)(f->s.shadow_bias / dz);
    }

    /* Pass 2: shafts, additive, no depth test, no culling, into the reduced target. */
    GLsizei n_idx = f->s.variant == GR_SHAFTS_FLUX ? (GLsizei)r->lat_nidx
                                                   : (GLsizei)(f->nshafts * f->slabs * (f->caps ? 36 : 24));
    gr_gl_timer_begin(&r->timer, GR_SHAFTS_PASS_SHAFTS);
    glBeginQuery(GL_SAMPLES_PASSED, r->q_samples);
    if (r->have_pipeline_stats) {
        glBeginQuery(GL_VERTEX_SHADER_INVOCATIONS, r->q_vs);
        glBeginQuery(GL_FRAGMENT_SHADER_INVOCATIONS, r->q_fs);
    }
    glDisable(GL_DITHER); /* dithering would make 8-bit sums depend on the pixel position */
    gr_target_accumulate(&r->target); /* tw x th */
    set_shaft_uniforms(r->prog_shafts, &r->ls, f, scene);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, eye_depth_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, shadow_tex);
    glBindVertexArray(r->vao_grid);
    for (int k = 0; k < f->n_levels; k++) {
        if (f->lvl_weight[k] <= 0.0) continue;
        if (f->s.variant == GR_SHAFTS_FLUX) {
            /* pre-passes: the level's lattice points, then each cell's and slab's irradiance,
             * then back to the shaft pass's state with the lattice bound */
            glDisable(GL_BLEND);
            for (GLenum u = GL_TEXTURE2; u <= GL_TEXTURE4; u++) {
                glActiveTexture(u);
                glBindTexture(GL_TEXTURE_2D, 0);
            }
            glActiveTexture(GL_TEXTURE0);
            glBindFramebuffer(GL_FRAMEBUFFER, r->corner_fbo);
            glViewport(0, 0, r->corner_size, r->corner_size);
            set_shaft_uniforms(r->prog_corner, &r->lk, f, scene);
            glUniform3fv(r->lk.origin, 1, f->lvl_origin[k]);
            glUniform1f(r->lk.spacing, (float)f->lvl_S[k]);
            glUniform1i(r->lk_tiled, tiled);
            if (f->groups > 0) glUniform4fv(r->lk.waves, f->groups * 5, f->lvl_waves[k]);
            glBindVertexArray(r->vao_empty);
            glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
            glActiveTexture(GL_TEXTURE2);
            glBindTexture(GL_TEXTURE_2D, r->corner_tex[0]);
            glActiveTexture(GL_TEXTURE3);
            glBindTexture(GL_TEXTURE_2D, r->corner_tex[1]);
            glActiveTexture(GL_TEXTURE0);
            glBindFramebuffer(GL_FRAMEBUFFER, r->flux.fbo);
            glViewport(0, 0, r->flux.w, r->flux.h);
            glUseProgram(r->prog_flux);
            glUniform1i(r->lf_corner_pos, 2);
            glUniform1i(r->lf_corner_refr, 3);
            glUniform1i(r->lf_tiled, tiled);
            glUniform1i(r->lf_cells, f->N - 1);
            glUniform1i(r->lf_slabs, f->s.slabs);
            glUniform1f(r->lf_length, (float)f->s.shaft_length_m);
            glUniform1f(r->lf_width, (float)f->s.shaft_width);
            glUniform3f(r->lf_sun_dir, (float)scene->sun.dir[0], (float)scene->sun.dir[1], (float)scene->sun.dir[2]);
            glUniform3f(r->lf_refr_flat, (float)f->T.x, (float)f->T.y, (float)f->T.z);
            glUniform1f(r->lf_sun_radius_w, f->sun_radius_w);
            glUniformMatrix4fv(r->lf_shadow_matrix, 1, GL_FALSE, f->shadow_matrix);
            glUniform1i(r->lf_shadow_map, 0);
            glUniform1f(r->lf_shadow_bias, f->shadow_bias_depth);
            glUniform1i(r->lf_shadows, 1);
            glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
            glActiveTexture(GL_TEXTURE4);
            glBindTexture(GL_TEXTURE_2D, r->flux.tex);
            glActiveTexture(GL_TEXTURE0);
            glBindFramebuffer(GL_FRAMEBUFFER, r->target.fbo);
            glViewport(0, 0, f->tw, f->th);
            glEnable(GL_BLEND);
            set_shaft_uniforms(r->prog_shafts, &r->ls, f, scene);
            glUniform1i(r->ls_flux_e, 4);
            glUniform1i(r->ls_tiled, tiled);
            glUniform1i(r->ls_lattice, r->lat_M);
            glUniform1i(r->ls_cells, f->N - 1);
            glUniform1i(r->ls_slabs, f->s.slabs);
            glBindVertexArray(r->vao_lat);
        }
        /* stable_grid: each level drawn with its weight folded into the prescale */
        glUniform3fv(r->ls.origin, 1, f->lvl_origin[k]);
        glUniform1f(r->ls.spacing, (float)f->lvl_S[k]);
        if (f->groups > 0) glUniform4fv(r->ls.waves, f->groups * 5, f->lvl_waves[k]);
        glUniform1f(r->ls.prescale, (float)(f->s.target_prescale * f->lvl_weight[k]));
        glDrawElements(GL_TRIANGLES, n_idx, GL_UNSIGNED_INT, (const void *)0);
    }
    for (GLenum u = GL_TEXTURE1; u <= GL_TEXTURE4; u++) {
        glActiveTexture(u);
        glBindTexture(GL_TEXTURE_2D, 0);
    }
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_BLEND);
    if (r->have_pipeline_stats) {
        glEndQuery(GL_FRAGMENT_SHADER_INVOCATIONS);
        glEndQuery(GL_VERTEX_SHADER_INVOCATIONS);
    }
    glEndQuery(GL_SAMPLES_PASSED);
    gr_gl_timer_end(&r->timer);

    /* Pass 3: full-screen pass at the frame's resolution into a float target. */
    gr_gl_timer_begin(&r->timer, GR_SHAFTS_PASS_FINAL);
    glBindFramebuffer(GL_FRAMEBUFFER, r->frame.fbo);
    glViewport(0, 0, f->W, f->H);
    glUseProgram(r->prog_final);
    glUniformMatrix4fv(r->loc_inv_vp, 1, GL_FALSE, f->inv_view_proj);
    glUniform2f(r->loc_texel, 1.0f / (float)f->tw, 1.0f / (float)f->th);
    glUniform1i(r->loc_shafts, 0);
    glUniform3fv(r->loc_hgg, 1, f->final_hgg);
    glUniform3f(r->loc_refr_sun, (float)f->T.x, (float)f->T.y, (float)f->T.z);
    glUniform3fv(r->loc_intensity, 1, f->final_intensity);
    glUniform1f(r->loc_bias, f->final_bias);
    glBindTexture(GL_TEXTURE_2D, r->target.tex);
    glBindVertexArray(r->vao_empty);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    gr_gl_timer_end(&r->timer);

    /* Read the layer back (GL rows bottom-up; gr_image top row first). */
    /* NaN/Inf: gr_image_check_finite below */
    if ((st = gr_readback_rgb(&r->rb, r->frame.fbo, out, NULL, "shafts layer", err)) != GR_OK) goto unbind;
    if (stats) {
        memset(stats, 0, sizeof *stats);
        /* Every pass ran between t0 and the synchronous readback: a GPU time longer than
         * that wall time is a broken timer (llvmpipe's first query after context creation
         * reads ~1e12 ns) and is reported as unavailable (-1). */
        double wall_ns = (gr_clock_ms() - t0) * 1e6;
        for (int p = 0; p < GR_SHAFTS_NPASS; p++) {
            stats->gpu_ns[p] = gr_gl_timer_ns_within(&r->timer, p, wall_ns);
        }
        stats->fragments = gr_gl_query_result(r->q_samples);
        stats->vertices_submitted = n_idx;
        stats->vs_invocations = r->have_pipeline_stats ? gr_gl_query_result(r->q_vs) : -1;
        stats->fs_invocations = r->have_pipeline_stats ? gr_gl_query_result(r->q_fs) : -1;
        stats->target_width = f->tw;
        stats->target_height = f->th;
        stats->n_shafts = f->nshafts;
        stats->spacing_m = f->S;
        stats->center[0] = f->P.x; stats->center[1] = f->P.y; stats->center[2] = f->P.z;
        stats->refr_dir[0] = f->T.x; stats->refr_dir[1] = f->T.y; stats->refr_dir[2] = f->T.z;
        count_cost(r, f, n_idx, stats);
    }
    if ((st = gr_gl_check("shafts render", err)) != GR_OK) goto unbind;
    r->rendered = 1;
    st = gr_image_check_finite(out, "shafts layer", err);
unbind:
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(0);
done:
    if (stats && st == GR_OK) stats->cpu_ms = gr_clock_ms() - t0;
    free(f);
    return st;
}

gr_status gr_shafts_render(gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s,
                           gr_image *out, gr_shafts_stats *stats, gr_error *err)
{
    return render_frame(r, scene, s, 0, out, stats, err);
}

gr_status gr_shafts_read_target(gr_shafts *r, gr_image **out, gr_error *err)
{
    *out = NULL;
    if (!r->rendered) return gr_fail(err, GR_E_RUNTIME, "shafts: no render yet, no target to read");
    gr_status st = gr_gl_make_current(r->gl, err);
    if (st != GR_OK) return st;
    if ((st = gr_readback_fbo(&r->rb, r->target.fbo, r->target.w, r->target.h, "shafts target", err)) != GR_OK)
        return st;
    *out = gr_readback_image(&r->rb);
    return *out ? GR_OK : gr_fail(err, GR_E_NOMEM, "shafts: out of memory for the target image");
}

gr_status gr_shafts_capture(gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s,
                            gr_shafts_vertex **out, int *count, gr_shafts_stats *stats, gr_error *err)
{
    *out = NULL;
    *count = 0;
    frame_setup *f = malloc(sizeof *f);
    gr_status st;
    GLuint tfb = 0;
    float *data = NULL;
    if (!f) return gr_fail(err, GR_E_NOMEM, "shafts: out of memory");
    if ((st = setup_frame(scene, s, 0, f, err)) != GR_OK) goto done;
    if (f->s.variant == GR_SHAFTS_FLUX) {
        /* flux draws the shared lattice (ensure_lattice), not the per-shaft grid captured here */
        st = gr_fail(err, GR_E_INPUT, "shafts.variant = flux: the vertex capture takes the seed and path variants");
        goto done;
    }
    if ((st = gr_gl_make_current(r->gl, err)) != GR_OK) goto done;
    if (!r->prog_capture) {
        static const char *const varyings[] = {"v_world", "v_intensity"};
        if ((st = gr_shader_program_stages(r->shader_dir, shaft_stages, 2, varyings, 2, &r->prog_capture, NULL, err)) !=
            GR_OK)
            goto done;
        get_shaft_locs(r->prog_capture, &r->lc);
    }
    if ((st = ensure_grid(r, f->N, 1, err)) != GR_OK) goto done;
    if ((st = ensure_targets(r, f, err)) != GR_OK) goto done;
    /* A surfaceless context has no default framebuffer: draw calls need a complete FBO
     * bound even with rasterizer discard on. */
    glBindFramebuffer(GL_FRAMEBUFFER, r->target.fbo);
    int nv = r->grid_nshafts * 8;
    size_t bytes = (size_t)nv * 6 * sizeof(float);
    glGenBuffers(1, &tfb);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, tfb);
    glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, (GLsizeiptr)bytes, NULL, GL_STATIC_READ);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, tfb);
    set_shaft_uniforms(r->prog_capture, &r->lc, f, scene);
    glBindVertexArray(r->vao_grid);
    glEnable(GL_RASTERIZER_DISCARD);
    glBeginTransformFeedback(GL_POINTS);
    glDrawArrays(GL_POINTS, 0, nv);
    glEndTransformFeedback();
    glDisable(GL_RASTERIZER_DISCARD);
    data = malloc(bytes);
    *out = calloc((size_t)nv, sizeof **out);
    if (!data || !*out) {
        free(*out);
        *out = NULL;
        st = gr_fail(err, GR_E_NOMEM, "shafts: out of memory for the vertex capture");
        goto done;
    }
    glGetBufferSubData(GL_TRANSFORM_FEEDBACK_BUFFER, 0, (GLsizeiptr)bytes, data);
    for (int i = 0; i < nv; i++) {
        gr_shafts_vertex *v = &(*out)[i];
        const float *g = r->grid_cpu + (size_t)i * GRID_FLOATS;
        const float *d = data + (size_t)i * 6;
        v->cell[0] = g[0];
        v->cell[1] = g[1];
        v->corner[0] = g[2];
        v->corner[1] = g[3];
        v->bottom = g[4] > 0.5f;
        v->pos[0] = f->eye.x + d[0];
        v->pos[1] = f->eye.y + d[1];
        v->pos[2] = f->eye.z + d[2];
        for (int c = 0; c < 3; c++) v->intensity[c] = d[3 + c];
    }
    *count = nv;
    if (stats) {
        memset(stats, 0, sizeof *stats);
        stats->n_shafts = f->nshafts;
        stats->spacing_m = f->S;
        stats->center[0] = f->P.x; stats->center[1] = f->P.y; stats->center[2] = f->P.z;
        stats->refr_dir[0] = f->T.x; stats->refr_dir[1] = f->T.y; stats->refr_dir[2] = f->T.z;
    }
    st = gr_gl_check("shafts vertex capture", err);
    if (st != GR_OK) {
        free(*out);
        *out = NULL;
        *count = 0;
    }
done:
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (tfb) {
        glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
        glDeleteBuffers(1, &tfb);
    }
    glBindVertexArray(0);
    glUseProgram(0);
    free(data);
    free(f);
    return st;
}

/* ---- metadata -------------------------------------------------------------------------- */

gr_status gr_shafts_metadata(const gr_shafts *r, const gr_scene *scene, const gr_shafts_settings *s,
                             const gr_shafts_stats *stats, gr_metadata *meta, gr_error *err)
{
    gr_shafts_settings rs;
    char key[64], val[256];
    gr_status st = GR_OK;
    gr_shafts_resolve(scene, s ? s : gr_shafts_scene_settings(scene), &rs);
#define CK(call) do { if ((st = (call)) != GR_OK) goto fail; } while (0)
    CK(gr_meta_set_string(meta, "godrays:renderer", "shafts"));
    CK(gr_meta_set_string(meta, "godrays:technique", "shafts"));
    CK(gr_meta_set_string(meta, "godrays:technique_description", gr_shafts_class.description));
    CK(gr_meta_set_string(meta, "godrays:gl_renderer", gr_gl_renderer(r->gl)));
    CK(gr_meta_set_string(meta, "godrays:gl_version", gr_gl_version(r->gl)));
    CK(gr_meta_set_string(meta, "godrays:gl_platform", gr_gl_platform_name(r->gl)));
    CK(gr_meta_set_string(meta, "godrays:shaders", r->shader_dir && r->from_dir ? r->shader_dir : "embedded"));
    CK(gr_meta_set_string(meta, "godrays:scene", scene->name));
    CK(gr_meta_set_string(meta, "godrays:scene_hash", scene->hash));
    CK(gr_meta_set_double(meta, "godrays:time_s", scene->water.time_s));
    const gr_param_table *t = &gr_shafts_param_table;
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        snprintf(key, sizeof key, "godrays:shafts.%s", p->name);
        switch (p->type) {
        case GR_PT_RGB:
            snprintf(val, sizeof val, "%.9g %.9g %.9g", gr_param_get_number(p, &rs, 0), gr_param_get_number(p, &rs, 1),
                     gr_param_get_number(p, &rs, 2));
            CK(gr_meta_set_string(meta, key, val));
            break;
        case GR_PT_ENUM: {
            int idx = (int)gr_param_get_number(p, &rs, 0);
            CK(gr_meta_set_string(meta, key, p->enum_names && idx >= 0 ? p->enum_names[idx] : "?"));
            break;
        }
        case GR_PT_INT:
        case GR_PT_BOOL:
        case GR_PT_U64:
            CK(gr_meta_set_int(meta, key, (long long)gr_param_get_number(p, &rs, 0)));
            break;
        default:
            CK(gr_meta_set_double(meta, key, gr_param_get_number(p, &rs, 0)));
        }
    }
    if (stats) {
        snprintf(val, sizeof val, "%.9g %.9g %.9g", stats->center[0], stats->center[1], stats->center[2]);
        CK(gr_meta_set_string(meta, "godrays:shafts_center_m", val));
        snprintf(val, sizeof val, "%.9g %.9g %.9g", stats->refr_dir[0], stats->refr_dir[1], stats->refr_dir[2]);
        CK(gr_meta_set_string(meta, "godrays:shafts_refracted_sun", val));
        CK(gr_meta_set_double(meta, "godrays:shafts_spacing_m", stats->spacing_m));
        CK(gr_meta_set_int(meta, "godrays:shafts_count", stats->n_shafts));
        snprintf(val, sizeof val, "%dx%d", stats->target_width, stats->target_height);
        CK(gr_meta_set_string(meta, "godrays:shafts_target_size", val));
        for (int p = 0; p < GR_SHAFTS_NPASS; p++) {
            snprintf(key, sizeof key, "godrays:gpu_ns.%s", gr_shafts_pass_names[p]);
            CK(gr_meta_set_int(meta, key, stats->gpu_ns[p]));
        }
        CK(gr_meta_set_double(meta, "godrays:cpu_ms", stats->cpu_ms));
        CK(gr_meta_set_int(meta, "godrays:fragments_blended", stats->fragments));
        CK(gr_meta_set_double(meta, "godrays:overdraw",
                              (double)stats->fragments / ((double)stats->target_width * (double)stats->target_height)));
        CK(gr_meta_set_int(meta, "godrays:vertices_submitted", stats->vertices_submitted));
        CK(gr_meta_set_int(meta, "godrays:vertex_shader_invocations", stats->vs_invocations));
        CK(gr_meta_set_int(meta, "godrays:fragment_shader_invocations", stats->fs_invocations));
    }
#undef CK
    return GR_OK;
fail:
    return gr_fail(err, st, "shafts metadata: cannot add an entry (%s)", gr_status_name(st));
}

/* ---- the technique class (technique.h) ----------------------------------------------- */

typedef struct shafts_tech {
    gr_shafts *r;
    gr_shafts_stats last; /* the renderer's own figures of the last render */
} shafts_tech;

static void tech_resolve(const gr_technique_class *cls, const gr_scene *scene, const void *in, void *out)
{
    gr_shafts_resolve(scene, in, out);
}

static gr_status tech_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts,
                             void **state, gr_error *err)
{
    *state = NULL;
    shafts_tech *t = calloc(1, sizeof *t);
    if (!t) return gr_fail(err, GR_E_NOMEM, "shafts renderer: out of memory");
    gr_status st = gr_shafts_create_in(gl, opts ? opts->shader_dir : NULL, &t->r, err);
    if (st != GR_OK) {
        free(t);
        return st;
    }
    *state = t;
    return GR_OK;
}

static void tech_destroy(void *state)
{
    shafts_tech *t = state;
    if (!t) return;
    gr_shafts_destroy(t->r);
    free(t);
}

static gr_status tech_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                             gr_technique_stats *stats, gr_error *err)
{
    shafts_tech *t = state;
    gr_status st = render_frame(t->r, scene, settings, 1, out, &t->last, err);
    if (st != GR_OK || !stats) return st;
    stats->n_passes = GR_SHAFTS_NPASS;
    for (int p = 0; p < GR_SHAFTS_NPASS; p++) {
        snprintf(stats->pass_names[p], sizeof stats->pass_names[p], "%s", gr_shafts_pass_names[p]);
        stats->gpu_ns[p] = t->last.gpu_ns[p];
        stats->cost[p] = t->last.cost[p];
    }
    stats->wall_ms = t->last.cpu_ms;
    stats->fragments = t->last.fragments;
    return GR_OK;
}

/* The renderer's own figures of the last render, with the (possibly median) timings given. */
static gr_shafts_stats last_with(const shafts_tech *t, const gr_technique_stats *stats)
{
    gr_shafts_stats s = t->last;
    if (stats) {
        for (int p = 0; p < GR_SHAFTS_NPASS && p < stats->n_passes; p++) s.gpu_ns[p] = stats->gpu_ns[p];
        s.cpu_ms = stats->wall_ms;
    }
    return s;
}

static gr_status tech_metadata(void *state, const gr_scene *scene, const void *settings,
                               const gr_technique_stats *stats, gr_metadata *meta, gr_error *err)
{
    shafts_tech *t = state;
    gr_shafts_stats s = last_with(t, stats);
    return gr_shafts_metadata(t->r, scene, settings, stats ? &s : NULL, meta, err);
}

static void tech_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    const shafts_tech *t = state;
    gr_shafts_stats s = last_with(t, stats);
    double tpx = (double)s.target_width * (double)s.target_height;
    snprintf(buf, n, "%d shafts, target %dx%d (%s), fragments blended %lld (overdraw %.2f), vertices %lld "
             "(VS invocations %lld)", s.n_shafts, s.target_width, s.target_height,
             t->r->target_fmt == TARGET_RGBA32F ? "rgba32f" : t->r->target_fmt == GR_TARGET_RGBA16F ? "rgba16f" : "rgba8", s.fragments,
             tpx > 0 ? (double)s.fragments / tpx : 0.0, s.vertices_submitted, s.vs_invocations);
}

static gr_status tech_read_target(void *state, gr_image **out, gr_error *err)
{
    shafts_tech *t = state;
    return gr_shafts_read_target(t->r, out, err);
}

/* `godrays pareto`: shaft counts, target sizes and formats that trade speed for quality. */
static const gr_technique_level shafts_ladder[] = {
    {"N=6,target_scale=0.25,target_format=rgba8", 0},
    {"N=6,target_scale=0.25,target_format=rgba16f", 0},
    {"N=6,target_scale=0.5,target_format=rgba8", 1},
    {"N=6,target_scale=0.5,target_format=rgba16f", 1},
    {"N=6,target_scale=1,target_format=rgba8", 1},
    {"N=6,target_scale=1,target_format=rgba16f", 1},
    {"N=11,target_scale=0.25,target_format=rgba8", 0},
    {"N=11,target_scale=0.25,target_format=rgba16f", 0},
    {"N=11,target_scale=0.5,target_format=rgba8", 1},
    {"N=11,target_scale=0.5,target_format=rgba16f", 1},
    {"N=11,target_scale=1,target_format=rgba8", 1},
    {"N=11,target_scale=1,target_format=rgba16f", 1},
    {"N=21,target_scale=0.25,target_format=rgba8", 0},
    {"N=21,target_scale=0.25,target_format=rgba16f", 0},
    {"N=21,target_scale=0.5,target_format=rgba8", 0},
    {"N=21,target_scale=0.5,target_format=rgba16f", 0},
    {"N=21,target_scale=1,target_format=rgba8", 0},
    {"N=21,target_scale=1,target_format=rgba16f", 0},
};

const gr_technique_class gr_shafts_class = {
    .name = "shafts",
    .description = "seed 000 (Lanza, ShaderX^5 5.5): extruded light shafts under the waves, blended into a reduced target",
    .params = &gr_shafts_param_table,
    .settings_size = sizeof(gr_shafts_settings),
    .origin = "built-in",
    .gain_key = "intensity", /* final pass: (bias + shafts) x intensity x phase (seed, second pass) */
    .ladder = shafts_ladder,
    .tune_keys = "K,extinction,shaft_width,g", /* spacing, attenuation, gaps, phase: the beams' look */
    .n_ladder = (int)(sizeof shafts_ladder / sizeof shafts_ladder[0]),
    .check = check_structure,
    .resolve = tech_resolve,
    .create = tech_create,
    .destroy = tech_destroy,
    .render = tech_render,
    .metadata = tech_metadata,
    .summary = tech_summary,
    .read_target = tech_read_target,
};
