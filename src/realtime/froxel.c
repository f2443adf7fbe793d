/* Froxel fog lit through the caustic texture (froxel.h; docs/volume-techniques.md). */
#include "realtime/froxel.h"
#include "realtime/slicing.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl/gl.h"
#include "realtime/volume.h"
#include "realtime/shaders.h"
#include "realtime/frame.h"
#include "realtime/scenegl.h"

#define MAX_SLICES 256

#define LO_X GR_PF_MIN_EXCL
#define SL(f) offsetof(gr_froxel_settings, f)
static const char *const dist_names[] = {"linear", "exponential", NULL};

static const gr_param params[] = {
    {.name = "grid_x", .type = GR_PT_INT, .offset = SL(grid_x), .min = 1, .max = 1024, .def = 160, .unit = "",
     .doc = "froxels across the view"},
    {.name = "grid_y", .type = GR_PT_INT, .offset = SL(grid_y), .min = 1, .max = 1024, .def = 90, .unit = "",
     .doc = "froxels up the view"},
    {.name = "grid_z", .type = GR_PT_INT, .offset = SL(grid_z), .min = 1, .max = MAX_SLICES, .def = 64, .unit = "",
     .doc = "depth slices"},
    {.name = "distribution", .type = GR_PT_ENUM, .offset = SL(distribution), .min = 0, .max = 1,
     .def = GR_VOL_EXPONENTIAL, .enum_names = dist_names, .unit = "", .doc = "spacing of the depth slices"},
    {.name = "near_m", .type = GR_PT_DOUBLE, .offset = SL(near_m), .min = 0, .max = 1e4, .flags = LO_X, .def = 0.5,
     .unit = "m", .doc = "exponential spacing: the first slice's far face (view depth)", .tune_lo = 0.05, .tune_hi = 4.0},
    {.name = "jitter", .type = GR_PT_BOOL, .offset = SL(jitter), .min = 0, .max = 1, .def = 0, .unit = "",
     .doc = "sample each froxel at a deterministic noise depth instead of its middle"},
    {.name = "phase_per_pixel", .type = GR_PT_BOOL, .offset = SL(phase_per_pixel), .min = 0, .max = 1, .def = 0,
     .unit = "", .doc = "apply the HG phase per pixel (one directional light: constant along a ray) instead of per froxel"},
    GR_VOL_PARAMS_CAUSTICS(gr_froxel_settings),
    GR_VOL_PARAMS_MEDIUM(gr_froxel_settings),
    GR_VOL_PARAMS_SUN_DISC(gr_froxel_settings),
    GR_VOL_PARAMS_LIGHT(gr_froxel_settings),
};
#undef SL

static const gr_param_table table = {"froxel", params, sizeof params / sizeof params[0]};

static const gr_technique_level ladder[] = {
    /* under 1 ms class at 1080p (docs/volume-techniques.md "Cost"): 8 192 caustic triangles */
    {"grid_x=40,grid_y=23,grid_z=16,texture_size=64,grid=32,caustic_depths=4", 1},
    {"grid_x=40,grid_y=23,grid_z=16,texture_size=128,grid=64,caustic_depths=4", 1},
    {"grid_x=80,grid_y=45,grid_z=32,texture_size=128,grid=96,caustic_depths=6", 0},
    /* the cheapest caustic stack within 10 % of the default's verdict (1/16 of its triangles) */
    {"patch_m=12,texture_size=256,grid=64", 0},
    {"grid_x=160", 1},
    {"grid_x=320,grid_y=180,grid_z=128,texture_size=1024,grid=512,caustic_depths=16", 0},
};

typedef struct fx_state {
    gr_vol_base base;
    GLuint prog, prog_scatter, prog_integrate, vol_tex[2];
    int vol_dims[3];
    gr_vol_locs vl, vl_s;
    GLint l_inv, l_fwd, l_bounds, l_eye_depth, l_size, l_tmax, l_nz, l_integrated;
    GLint s_grid, s_bounds, s_inv, s_fwd, s_jitter, s_phase, l_phase;
    GLint i_grid, i_bounds, i_inv, i_fwd, i_sigma;
    long long triangles;
    int n_slices;
} fx_state;

static void fx_destroy(void *state)
{
    fx_state *r = state;
    if (!r) return;
    if (gr_vol_base_current(&r->base)) {
        if (r->prog) glDeleteProgram(r->prog);
        if (r->prog_scatter) glDeleteProgram(r->prog_scatter);
        if (r->prog_integrate) glDeleteProgram(r->prog_integrate);
        if (r->vol_tex[0]) glDeleteTextures(2, r->vol_tex);
    }
    gr_vol_base_release(&r->base);
    free(r);
}

static gr_status fx_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    (void)cls;
    *state = NULL;
    const char *dir = opts ? opts->shader_dir : NULL;
    fx_state *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "froxel: out of memory");
    gr_status st;
    if ((st = gr_vol_base_init(&r->base, gl, dir, 1, err)) != GR_OK) goto fail;
    const gr_shader_stage apply[2] = {
        {GL_VERTEX_SHADER, {"volume_screen.vert.glsl", NULL, NULL, NULL}},
        {GL_FRAGMENT_SHADER,
         {"volume_version.glsl", "volume_fragment.glsl", "caustic_stack.glsl", "volume_common.glsl",
          "froxel_apply.frag.glsl"}}};
    const gr_shader_stage scatter[1] = {
        {GL_COMPUTE_SHADER,
         {"volume_version.glsl", "caustic_stack.glsl", "volume_common.glsl", "froxel_scatter.comp.glsl"}}};
    const gr_shader_stage integrate[1] = {{GL_COMPUTE_SHADER, {"froxel_integrate.comp.glsl", NULL, NULL, NULL}}};
    if ((st = gr_shader_program_stages(dir, apply, 2, NULL, 0, &r->prog, NULL, err)) != GR_OK) goto fail;
    if ((st = gr_shader_program_stages(dir, scatter, 1, NULL, 0, &r->prog_scatter, NULL, err)) != GR_OK) goto fail;
    if ((st = gr_shader_program_stages(dir, integrate, 1, NULL, 0, &r->prog_integrate, NULL, err)) != GR_OK) goto fail;
    gr_vol_locations(r->prog, &r->vl);
    gr_vol_locations(r->prog_scatter, &r->vl_s);
    r->l_inv = glGetUniformLocation(r->prog, "u_inv_vp_rot");
    r->l_fwd = glGetUniformLocation(r->prog, "u_forward");
    r->l_bounds = glGetUniformLocation(r->prog, "u_bounds");
    r->l_eye_depth = glGetUniformLocation(r->prog, "u_eye_depth");
    r->l_size = glGetUniformLocation(r->prog, "u_size");
    r->l_tmax = glGetUniformLocation(r->prog, "u_tmax");
    r->l_nz = glGetUniformLocation(r->prog, "u_nz");
    r->l_integrated = glGetUniformLocation(r->prog, "u_integrated");
    r->s_grid = glGetUniformLocation(r->prog_scatter, "u_grid");
    r->s_bounds = glGetUniformLocation(r->prog_scatter, "u_bounds");
    r->s_inv = glGetUniformLocation(r->prog_scatter, "u_inv_vp_rot");
    r->s_fwd = glGetUniformLocation(r->prog_scatter, "u_forward");
    r->s_jitter = glGetUniformLocation(r->prog_scatter, "u_jitter");
    r->s_phase = glGetUniformLocation(r->prog_scatter, "u_phase_pixel");
    r->l_phase = glGetUniformLocation(r->prog, "u_phase_pixel");
    r->i_grid = glGetUniformLocation(r->prog_integrate, "u_grid");
    r->i_bounds = glGetUniformLocation(r->prog_integrate, "u_bounds");
    r->i_inv = glGetUniformLocation(r->prog_integrate, "u_inv_vp_rot");
    r->i_fwd = glGetUniformLocation(r->prog_integrate, "u_forward");
    r->i_sigma = glGetUniformLocation(r->prog_integrate, "u_sigma_t");
    if ((st = gr_gl_check("froxel setup", err)) != GR_OK) goto fail;
    *state = r;
    return GR_OK;
fail:
    fx_destroy(r);
    return st;
}

static gr_status ensure_volume(fx_state *r, int x, int y, int z, gr_error *err)
{
    if (r->vol_tex[0] && r->vol_dims[0] == x && r->vol_dims[1] == y && r->vol_dims[2] == z) return GR_OK;
    if (r->vol_tex[0]) glDeleteTextures(2, r->vol_tex);
    glGenTextures(2, r->vol_tex);
    for (int i = 0; i < 2; i++) {
        glBindTexture(GL_TEXTURE_3D, r->vol_tex[i]);
        glTexStorage3D(GL_TEXTURE_3D, 1, GL_RGBA32F, x, y, z);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    }
    glBindTexture(GL_TEXTURE_3D, 0);
    r->vol_dims[0] = x;
    r->vol_dims[1] = y;
    r->vol_dims[2] = z;
    return gr_gl_check("froxel.grid_x/grid_y/grid_z: froxel volume", err);
}

/* The table's ranges are checked by technique.c; what it cannot express: */
static gr_status fx_check(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    const gr_froxel_settings *s = settings;
    return gr_vol_check(cls->name, &s->vol, err);
}

enum { P_SCATTER = GR_VOL_PASS_OWN, P_INTEGRATE, P_APPLY };

/* The own passes' cost counters (technique.h): the dispatches' invocations (8 x 8 groups, the
 * grid rounded up), a froxel's caustic taps (up to 2) and shadow tap, one RGBA32F image write
 * per froxel in each compute pass, the integration's one image load per froxel; apply: a
 * full-screen pass with the eye-depth tap and two volume taps a pixel. */
static void count_cost(const gr_froxel_settings *s, int W, int H, int shadow, gr_technique_stats *stats)
{
    const long long gx = s->grid_x, gy = s->grid_y, nz = s->grid_z;
    const long long ix = (gx + 7) / 8 * 8, iy = (gy + 7) / 8 * 8, vox = gx * gy * nz;
    gr_pass_cost c;
    gr_pass_cost_clear(&c);
    c.v[GR_COST_FRAGMENTS] = c.v[GR_COST_VERTICES] = c.v[GR_COST_PRIMITIVES] = 0;
    c.v[GR_COST_INVOCATIONS] = ix * iy * nz;
    c.v[GR_COST_TAPS] = vox * (2 + shadow);
    c.v[GR_COST_BYTES] = vox * 16;
    gr_vol_cost_pass(stats, P_SCATTER, &c);
    c.v[GR_COST_INVOCATIONS] = ix * iy;
    c.v[GR_COST_TAPS] = vox;
    gr_vol_cost_pass(stats, P_INTEGRATE, &c);
    c = gr_pass_cost_screen(W, H, 3, 16);
    gr_vol_cost_pass(stats, P_APPLY, &c);
}

static gr_status fx_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    fx_state *r = state;
    const gr_froxel_settings *s = settings;
    gr_vol_prep prep;
    gr_status st = gr_vol_prepare("froxel", &r->base, scene, &s->vol, out, &prep, err);
    if (st != GR_OK) return st;
    const gr_frame *f = &prep.frame;
    int W = f->width, H = f->height;
    r->triangles = gr_caustics_triangles(r->base.caus);
    double tmax = prep.t_max;
    double far = gr_vol_far_depth(scene, f, tmax);
    double b[MAX_SLICES + 1];
    int nz = s->grid_z;
    gr_vol_bounds(nz, s->distribution == GR_VOL_EXPONENTIAL, s->near_m, far, b);
    float bf[MAX_SLICES + 1];
    for (int i = 0; i <= nz; i++) bf[i] = (float)b[i];
    double rot[16], inv[16];
    gr_frame_view_proj_rot(f, rot);
    if (gr_mat4_inverse(rot, inv) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");
    float m[16];
    gr_frame_matf(inv, m);
    if ((st = ensure_volume(r, s->grid_x, s->grid_y, nz, err)) != GR_OK) return st;

    /* pass: in-scattering per froxel */
    gr_gl_timer_begin(&r->base.timer, P_SCATTER);
    glUseProgram(r->prog_scatter);
    gr_vol_set(&r->vl_s, &prep.in);
    glUniform3i(r->s_grid, s->grid_x, s->grid_y, nz);
    glUniform1fv(r->s_bounds, nz + 1, bf);
    glUniformMatrix4fv(r->s_inv, 1, GL_FALSE, m);
    glUniform3f(r->s_fwd, (float)f->forward[0], (float)f->forward[1], (float)f->forward[2]);
    glUniform1i(r->s_jitter, s->jitter);
    glUniform1i(r->s_phase, s->phase_per_pixel);
    glBindImageTexture(0, r->vol_tex[0], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute((GLuint)((s->grid_x + 7) / 8), (GLuint)((s->grid_y + 7) / 8), (GLuint)nz);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    gr_gl_timer_end(&r->base.timer);

    /* pass: Hillaire's front-to-back integration */
    gr_gl_timer_begin(&r->base.timer, P_INTEGRATE);
    glUseProgram(r->prog_integrate);
    glUniform3i(r->i_grid, s->grid_x, s->grid_y, nz);
    glUniform1fv(r->i_bounds, nz + 1, bf);
    glUniformMatrix4fv(r->i_inv, 1, GL_FALSE, m);
    glUniform3f(r->i_fwd, (float)f->forward[0], (float)f->forward[1], (float)f->forward[2]);
    glUniform3f(r->i_sigma, (float)prep.in.sigma_t[0], (float)prep.in.sigma_t[1], (float)prep.in.sigma_t[2]);
    glBindImageTexture(0, r->vol_tex[0], 0, GL_TRUE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(1, r->vol_tex[1], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    glDispatchCompute((GLuint)((s->grid_x + 7) / 8), (GLuint)((s->grid_y + 7) / 8), 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);
    gr_gl_timer_end(&r->base.timer);

    /* pass: per pixel, the integrated volume at the ray's end */
    gr_gl_timer_begin(&r->base.timer, P_APPLY);
    glBindFramebuffer(GL_FRAMEBUFFER, r->base.out.fbo);
    glViewport(0, 0, W, H);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(r->prog);
    gr_vol_set(&r->vl, &prep.in);
    glUniformMatrix4fv(r->l_inv, 1, GL_FALSE, m);
    glUniform3f(r->l_fwd, (float)f->forward[0], (float)f->forward[1], (float)f->forward[2]);
    glUniform1fv(r->l_bounds, nz + 1, bf);
    glUniform1i(r->l_nz, nz);
    glUniform1i(r->l_phase, s->phase_per_pixel);
    glUniform1i(r->l_eye_depth, 1);
    glUniform1i(r->l_integrated, 4);
    glUniform2f(r->l_size, (float)W, (float)H);
    glUniform1f(r->l_tmax, (float)tmax);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, prep.depth_tex);
    glActiveTexture(GL_TEXTURE4);
    glBindTexture(GL_TEXTURE_3D, r->vol_tex[1]);
    glActiveTexture(GL_TEXTURE0);
    glBindVertexArray(r->base.vao);
    glBeginQuery(GL_SAMPLES_PASSED, r->base.q_samples);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glEndQuery(GL_SAMPLES_PASSED);
    gr_gl_timer_end(&r->base.timer);
    glBindVertexArray(0);
    glUseProgram(0);
    r->n_slices = nz;
    static const char *const names[6] = {"shadow", "eye_depth", "caustics", "scatter", "integrate", "apply"};
    st = gr_vol_finish("froxel", &r->base, &prep, out, names, 6, stats, err);
    if (stats) count_cost(s, W, H, prep.shadow_size > 0, stats);
    return st;
}

static void fx_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    const fx_state *r = state;
    (void)stats;
    snprintf(buf, n, "%dx%dx%d froxels, %lld caustic triangles", r->vol_dims[0], r->vol_dims[1], r->n_slices, r->triangles);
}

const gr_technique_class gr_froxel_class = {
    .name = "froxel",
    .description = "froxel fog (Wronski 2014, Hillaire 2015) lit through seed 002's caustic texture as a cookie",
    .params = &table,
    .settings_size = sizeof(gr_froxel_settings),
    .origin = "built-in",
    .gain_key = "intensity",
    .ladder = ladder,
    .n_ladder = sizeof ladder / sizeof ladder[0],
    .check = fx_check,
    .create = fx_create,
    .destroy = fx_destroy,
    .render = fx_render,
    .set_reuse = gr_vol_set_reuse,
    .summary = fx_summary,
};
