/* Slicing of the view volume with the caustic texture (slicing.h; docs/volume-techniques.md). */
#include "realtime/slicing.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gl/gl.h"
#include "realtime/caustics.h"
#include "realtime/frame.h"
#include "realtime/scenegl.h"

#define MAX_SLICES 512

#define LO_X GR_PF_MIN_EXCL
#define FROM GR_PF_FROM_SCENE
#define SL(f) offsetof(gr_slicing_settings, f)
static const char *const dist_names[] = {"linear", "exponential", NULL};

static const gr_param params[] = {
    {.name = "slices", .type = GR_PT_INT, .offset = SL(slices), .min = 1, .max = MAX_SLICES, .def = 32, .unit = "",
     .doc = "planes across the view volume (seed 002: about 32)"},
    {.name = "distribution", .type = GR_PT_ENUM, .offset = SL(distribution), .min = 0, .max = 1,
     .def = GR_VOL_EXPONENTIAL, .enum_names = dist_names, .unit = "", .doc = "spacing of the planes in view depth"},
    {.name = "near_m", .type = GR_PT_DOUBLE, .offset = SL(near_m), .min = 0, .max = 1e4, .flags = LO_X, .def = 0.5,
     .unit = "m", .doc = "exponential spacing: the first plane's view depth", .tune_lo = 0.05, .tune_hi = 4.0},
    {.name = "texture_size", .type = GR_PT_INT, .offset = SL(texture_size), .min = 8, .max = 4096, .def = 512,
     .unit = "texels", .doc = "caustic texture side (rendered at twice this, 2x2 box filtered)"},
    {.name = "grid", .type = GR_PT_INT, .offset = SL(grid), .min = 2, .max = 2048, .def = 256, .unit = "cells",
     .doc = "water grid cells per patch side (beam-traced triangles: 2 grid^2 per depth)"},
    {.name = "patch_m", .type = GR_PT_DOUBLE, .offset = SL(patch_m), .min = 0, .max = 1e4, .flags = LO_X, .def = 24,
     .unit = "m", .doc = "caustic patch side: the texture repeats with this period"},
    {.name = "caustic_depths", .type = GR_PT_INT, .offset = SL(caustic_depths), .min = 1, .max = GR_CAUSTICS_MAX_DEPTHS,
     .def = 8, .unit = "", .doc = "planes of the caustic stack"},
    {.name = "caustic_first_m", .type = GR_PT_DOUBLE, .offset = SL(caustic_first_m), .min = 0, .max = 1e4,
     .flags = LO_X, .def = 1, .unit = "m", .doc = "shallowest caustic plane below the rest height"},
    {.name = "caustic_last_m", .type = GR_PT_DOUBLE, .offset = SL(caustic_last_m), .min = 0, .max = 1e4,
     .flags = LO_X, .def = 25, .unit = "m", .doc = "deepest caustic plane (geometric spacing between)"},
    {.name = "extinction", .type = GR_PT_RGB, .offset = SL(extinction), .min = 0, .max = 1e4, .flags = FROM,
     .def = NAN, .unit = "1/m", .scene_source = "medium.extinction",
     .doc = "sigma_t along the sun's and the view path; default: the medium's", .tune_lo = 0.5, .tune_hi = 2.0},
    {.name = "g", .type = GR_PT_DOUBLE, .offset = SL(g), .min = -1, .max = 1, .flags = LO_X | GR_PF_MAX_EXCL | FROM,
     .def = NAN, .unit = "", .scene_source = "medium.g", .doc = "HG asymmetry; default: the medium's",
     .tune_lo = 0.5, .tune_hi = 0.98},
    {.name = "sun_disc", .type = GR_PT_BOOL, .offset = SL(sun_disc), .min = 0, .max = 1, .def = 1, .unit = "",
     .doc = "blur each caustic plane by the sun's disc (the mip level of its blur diameter)"},
    {.name = "intensity", .type = GR_PT_RGB, .offset = SL(intensity), .min = 0, .max = 1e9, .def = 1, .unit = "",
     .doc = "gain on the physical radiance (1: no fit)", .tune_lo = 0.2, .tune_hi = 5.0},
    {.name = "shadow_map_size", .type = GR_PT_INT, .offset = SL(shadow_map_size), .min = 16, .max = 8192, .def = 1024,
     .unit = "texels", .doc = "occluders' shadow map side"},
    {.name = "shadow_extent_m", .type = GR_PT_DOUBLE, .offset = SL(shadow_extent_m), .min = 0, .max = 1e5,
     .flags = LO_X, .def = 40, .unit = "m", .doc = "half side of the shadow map's square around the eye"},
};
#undef SL

static const gr_param_table table = {"slicing", params, sizeof params / sizeof params[0]};

static const gr_technique_level ladder[] = {
    {"slices=8,texture_size=128,grid=64,caustic_depths=4", 1},
    {"slices=16,texture_size=128,grid=96,caustic_depths=6", 0},
    {"slices=32", 1},
    {"slices=64,texture_size=1024,grid=512,caustic_depths=16", 0},
};

typedef struct sl_state {
    gr_gl *gl;
    gr_scenegl *sg;
    gr_caustics *caus;
    GLuint prog, vao, out_tex, out_fbo;
    int out_w, out_h;
    gr_vol_locs vl;
    GLint l_inv, l_fwd, l_bounds, l_eye_depth, l_size, l_tmax;
    gr_gl_timer timer;
    GLuint q_samples;
    long long triangles;
    int n_slices;
} sl_state;

static void sl_destroy(void *state)
{
    sl_state *r = state;
    if (!r) return;
    if (r->gl && gr_gl_make_current(r->gl, NULL) == GR_OK) {
        if (r->prog) glDeleteProgram(r->prog);
        if (r->vao) glDeleteVertexArrays(1, &r->vao);
        if (r->out_fbo) glDeleteFramebuffers(1, &r->out_fbo);
        if (r->out_tex) glDeleteTextures(1, &r->out_tex);
        if (r->q_samples) glDeleteQueries(1, &r->q_samples);
        gr_gl_timer_free(&r->timer);
    }
    gr_caustics_destroy(r->caus);
    gr_scenegl_destroy(r->sg);
    free(r);
}

static gr_status sl_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    (void)cls;
    *state = NULL;
    const char *dir = opts ? opts->shader_dir : NULL;
    sl_state *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "slicing: out of memory");
    r->gl = gl;
    gr_status st;
    if ((st = gr_scenegl_create_dir(gl, dir, &r->sg, err)) != GR_OK) goto fail;
    if ((st = gr_caustics_create(dir, &r->caus, err)) != GR_OK) goto fail;
    const gr_vol_stage stages[2] = {
        {GL_VERTEX_SHADER, {"volume_screen.vert.glsl", NULL, NULL, NULL}},
        {GL_FRAGMENT_SHADER, {"volume_version.glsl", "volume_fragment.glsl", "volume_common.glsl", "slicing.frag.glsl"}}};
    if ((st = gr_vol_program(dir, stages, 2, &r->prog, err)) != GR_OK) goto fail;
    gr_vol_locations(r->prog, &r->vl);
    r->l_inv = glGetUniformLocation(r->prog, "u_inv_vp_rot");
    r->l_fwd = glGetUniformLocation(r->prog, "u_forward");
    r->l_bounds = glGetUniformLocation(r->prog, "u_bounds");
    r->l_eye_depth = glGetUniformLocation(r->prog, "u_eye_depth");
    r->l_size = glGetUniformLocation(r->prog, "u_size");
    r->l_tmax = glGetUniformLocation(r->prog, "u_tmax");
    glGenVertexArrays(1, &r->vao);
    glGenQueries(1, &r->q_samples);
    gr_gl_timer_init(&r->timer);
    if ((st = gr_gl_check("slicing setup", err)) != GR_OK) goto fail;
    *state = r;
    return GR_OK;
fail:
    sl_destroy(r);
    return st;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static gr_status sl_check(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    const gr_slicing_settings *s = settings;
    gr_status st = gr_param_validate(cls->params, settings, 1, err);
    if (st != GR_OK) return st;
    if (!(s->caustic_last_m >= s->caustic_first_m))
        return gr_fail(err, GR_E_INPUT, "slicing.caustic_last_m = %g: must be >= slicing.caustic_first_m (%g)",
                       s->caustic_last_m, s->caustic_first_m);
    return GR_OK;
}

static gr_status ensure_out(sl_state *r, int w, int h, gr_error *err)
{
    if (r->out_tex && r->out_w == w && r->out_h == h) return GR_OK;
    if (r->out_fbo) glDeleteFramebuffers(1, &r->out_fbo);
    if (r->out_tex) glDeleteTextures(1, &r->out_tex);
    glGenTextures(1, &r->out_tex);
    glBindTexture(GL_TEXTURE_2D, r->out_tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &r->out_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, r->out_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->out_tex, 0);
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (fs != GL_FRAMEBUFFER_COMPLETE)
        return gr_fail(err, GR_E_GL, "camera.width/height: slicing target %dx%d incomplete", w, h);
    r->out_w = w;
    r->out_h = h;
    return gr_gl_check("slicing target", err);
}

enum { P_SHADOW, P_DEPTH, P_CAUSTICS, P_SLICES };

static gr_status sl_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    sl_state *r = state;
    const gr_slicing_settings *s = settings;
    double t0 = now_ms();
    gr_frame f;
    gr_frame_init(scene, &f);
    int W = f.width, H = f.height;
    gr_status st;
    if (out->width != W || out->height != H || gr_image_channel(out, "R") < 0 || gr_image_channel(out, "G") < 0 ||
        gr_image_channel(out, "B") < 0)
        return gr_fail(err, GR_E_INPUT, "slicing: output image is %dx%d (needs %dx%d with R, G, B)", out->width,
                       out->height, W, H);
    if (!(f.rest_height_m - f.eye[1] > 0))
        return gr_fail(err, GR_E_INPUT, "camera.position_m: y = %g is not below the water surface; slicing needs an underwater viewer",
                       f.eye[1]);
    if ((st = gr_gl_make_current(r->gl, err)) != GR_OK) return st;
    if ((st = ensure_out(r, W, H, err)) != GR_OK) return st;
    r->timer.used = 0;
    r->timer.n = 0;

    gr_vol_inputs in;
    memset(&in, 0, sizeof in);
    gr_caustics_params cp = {.size = s->texture_size, .grid = s->grid, .patch_m = s->patch_m,
                             .n_depths = s->caustic_depths, .fresnel = 1};
    gr_caustics_depths(cp.n_depths, s->caustic_first_m, s->caustic_last_m, cp.depths_m);
    in.f = &f;
    in.caustics = r->caus;
    in.cp = &cp;
    if (scene->n_occluders > 0) {
        gr_gl_timer_begin(&r->timer, P_SHADOW);
        st = gr_scenegl_shadow_map(r->sg, scene, &f, s->shadow_map_size, f.eye, s->shadow_extent_m, &in.shadow_tex,
                                   in.light_vp, err);
        gr_gl_timer_end(&r->timer);
        if (st != GR_OK) return st;
    } else {
        for (int i = 0; i < 16; i++) in.light_vp[i] = i % 5 == 0;
    }
    unsigned depth_tex = 0;
    gr_gl_timer_begin(&r->timer, P_DEPTH);
    st = gr_scenegl_eye_depth(r->sg, scene, &f, W, H, &depth_tex, err);
    gr_gl_timer_end(&r->timer);
    if (st != GR_OK) return st;
    gr_gl_timer_begin(&r->timer, P_CAUSTICS);
    st = gr_caustics_build(r->caus, scene, &f, &cp, err);
    gr_gl_timer_end(&r->timer);
    if (st != GR_OK) return st;
    r->triangles = gr_caustics_triangles(r->caus);
    for (int c = 0; c < 3; c++) {
        in.sigma_t[c] = s->extinction[c];
        in.sigma_s[c] = scene->medium.scattering[c];
        in.gain[c] = s->intensity[c];
    }
    in.g = s->g;
    in.sun_disc = s->sun_disc;

    double tmax = gr_vol_t_max(scene);
    double far = gr_vol_far_depth(scene, &f, tmax);
    double b[MAX_SLICES + 1];
    gr_vol_bounds(s->slices, s->distribution == GR_VOL_EXPONENTIAL, s->near_m, far, b);
    float bf[MAX_SLICES + 1];
    for (int i = 0; i <= s->slices; i++) bf[i] = (float)b[i];
    double rot[16], inv[16];
    gr_frame_view_proj_rot(&f, rot);
    if (gr_mat4_inverse(rot, inv) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");
    float m[16];
    gr_frame_matf(inv, m);

    gr_gl_timer_begin(&r->timer, P_SLICES);
    glBindFramebuffer(GL_FRAMEBUFFER, r->out_fbo);
    glViewport(0, 0, W, H);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(r->prog);
    gr_vol_set(&r->vl, &in);
    glUniformMatrix4fv(r->l_inv, 1, GL_FALSE, m);
    glUniform3f(r->l_fwd, (float)f.forward[0], (float)f.forward[1], (float)f.forward[2]);
    glUniform1fv(r->l_bounds, s->slices + 1, bf);
    glUniform1i(r->l_eye_depth, 1);
    glUniform2f(r->l_size, (float)W, (float)H);
    glUniform1f(r->l_tmax, (float)tmax);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, depth_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindVertexArray(r->vao);
    glBeginQuery(GL_SAMPLES_PASSED, r->q_samples);
    glDrawArraysInstanced(GL_TRIANGLES, 0, 3, s->slices);
    glEndQuery(GL_SAMPLES_PASSED);
    glDisable(GL_BLEND);
    gr_gl_timer_end(&r->timer);
    glBindVertexArray(0);
    glUseProgram(0);
    r->n_slices = s->slices;
    st = gr_vol_readback(r->out_fbo, W, H, out, "slicing readback", err);
    if (st != GR_OK) return st;
    if (stats) {
        static const char *const names[4] = {"shadow", "eye_depth", "caustics", "slices"};
        memset(stats, 0, sizeof *stats);
        double wall_ns = (now_ms() - t0) * 1e6;
        stats->n_passes = 4;
        for (int p = 0; p < 4; p++) {
            snprintf(stats->pass_names[p], sizeof stats->pass_names[p], "%s", names[p]);
            long long ns = gr_gl_timer_ns(&r->timer, p);
            stats->gpu_ns[p] = (ns >= 0 && (double)ns <= wall_ns) ? ns : -1;
        }
        GLuint64 n = 0;
        glGetQueryObjectui64v(r->q_samples, GL_QUERY_RESULT, &n);
        stats->fragments = (long long)n;
        stats->wall_ms = now_ms() - t0;
    }
    return gr_image_check_finite(out, "slicing", err);
}

static void sl_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    const sl_state *r = state;
    (void)stats;
    snprintf(buf, n, "%d slices, %lld caustic triangles", r->n_slices, r->triangles);
}

const gr_technique_class gr_slicing_class = {
    .name = "slicing",
    .description = "seed 002: view-volume slices textured with beam-traced caustics (area ratio), additive",
    .params = &table,
    .settings_size = sizeof(gr_slicing_settings),
    .origin = "built-in",
    .gain_key = "intensity",
    .ladder = ladder,
    .n_ladder = sizeof ladder / sizeof ladder[0],
    .check = sl_check,
    .create = sl_create,
    .destroy = sl_destroy,
    .render = sl_render,
    .summary = sl_summary,
};
