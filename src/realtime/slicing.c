/* Slicing of the view volume with the caustic texture (slicing.h; docs/volume-techniques.md). */
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

#define MAX_SLICES 512

#define LO_X GR_PF_MIN_EXCL
#define SL(f) offsetof(gr_slicing_settings, f)
static const char *const dist_names[] = {"linear", "exponential", NULL};

static const gr_param params[] = {
    {.name = "slices", .type = GR_PT_INT, .offset = SL(slices), .min = 1, .max = MAX_SLICES, .def = 32, .unit = "",
     .doc = "planes across the view volume (seed 002: about 32)"},
    {.name = "distribution", .type = GR_PT_ENUM, .offset = SL(distribution), .min = 0, .max = 1,
     .def = GR_VOL_EXPONENTIAL, .enum_names = dist_names, .unit = "", .doc = "spacing of the planes in view depth"},
    {.name = "near_m", .type = GR_PT_DOUBLE, .offset = SL(near_m), .min = 0, .max = 1e4, .flags = LO_X, .def = 0.5,
     .unit = "m", .doc = "exponential spacing: the first plane's view depth", .tune_lo = 0.05, .tune_hi = 4.0},
    {.name = "target_scale", .type = GR_PT_DOUBLE, .offset = SL(target_scale), .min = 0, .max = 1, .flags = LO_X,
     .def = 1, .unit = "", .doc = "slices' target size / frame size, per axis (< 1: sliced there, upsampled bilinearly)"},
    GR_VOL_PARAMS_CAUSTICS(gr_slicing_settings),
    GR_VOL_PARAMS_MEDIUM(gr_slicing_settings),
    GR_VOL_PARAMS_SUN_DISC(gr_slicing_settings),
    GR_VOL_PARAMS_LIGHT(gr_slicing_settings),
};
#undef SL

static const gr_param_table table = {"slicing", params, sizeof params / sizeof params[0]};

static const gr_technique_level ladder[] = {
    /* the cheap end (docs/volume-techniques.md "Cost"): 4 full-screen slices, 8 192 triangles */
    {"slices=4,texture_size=64,grid=32,caustic_depths=4", 1},
    {"slices=8,texture_size=128,grid=64,caustic_depths=4", 1},
    {"slices=16,texture_size=128,grid=96,caustic_depths=6", 0},
    /* the cheapest caustic stack within 10 % of the default's verdict on the default and the
     * side view (65 536 triangles, 1/16; docs/volume-techniques.md "Cost"), at half resolution */
    {"slices=16,patch_m=12,texture_size=256,grid=64,target_scale=0.5", 0},
    {"slices=32,patch_m=12,texture_size=256,grid=64", 0},
    {"slices=32", 1},
    {"slices=64,texture_size=1024,grid=512,caustic_depths=16", 0},
};

typedef struct sl_state {
    gr_vol_base base;
    GLuint prog, prog_up;
    GLint l_up_src, l_up_size;
    gr_target small; /* target_scale < 1: the reduced slices' target */
    int sw, sh;      /* the slices' target size of the last render */
    gr_vol_locs vl;
    GLint l_inv, l_fwd, l_bounds, l_eye_depth, l_size, l_tmax;
    long long triangles;
    int n_slices;
} sl_state;

static void sl_destroy(void *state)
{
    sl_state *r = state;
    if (!r) return;
    if (gr_vol_base_current(&r->base)) {
        if (r->prog) glDeleteProgram(r->prog);
        if (r->prog_up) glDeleteProgram(r->prog_up);
        gr_target_release(&r->small);
    }
    gr_vol_base_release(&r->base);
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
    gr_status st;
    if ((st = gr_vol_base_init(&r->base, gl, dir, 1, err)) != GR_OK) goto fail;
    const gr_shader_stage stages[2] = {
        {GL_VERTEX_SHADER, {"volume_screen.vert.glsl", NULL, NULL, NULL}},
        {GL_FRAGMENT_SHADER,
         {"volume_version.glsl", "volume_fragment.glsl", "caustic_stack.glsl", "volume_common.glsl",
          "slicing.frag.glsl"}}};
    if ((st = gr_shader_program_stages(dir, stages, 2, NULL, 0, &r->prog, NULL, err)) != GR_OK) goto fail;
    /* the bilinear upsample of target_scale < 1: the radial blur's (the same reduced-resolution
     * post-process, docs/radial-blur.md "Cost") */
    if ((st = gr_shader_program(dir, "radial_blur_screen.vert.glsl", "radial_blur_upsample.frag.glsl", NULL, 0,
                                &r->prog_up, NULL, err)) != GR_OK)
        goto fail;
    r->l_up_src = glGetUniformLocation(r->prog_up, "u_src");
    r->l_up_size = glGetUniformLocation(r->prog_up, "u_size");
    gr_vol_locations(r->prog, &r->vl);
    r->l_inv = glGetUniformLocation(r->prog, "u_inv_vp_rot");
    r->l_fwd = glGetUniformLocation(r->prog, "u_forward");
    r->l_bounds = glGetUniformLocation(r->prog, "u_bounds");
    r->l_eye_depth = glGetUniformLocation(r->prog, "u_eye_depth");
    r->l_size = glGetUniformLocation(r->prog, "u_size");
    r->l_tmax = glGetUniformLocation(r->prog, "u_tmax");
    if ((st = gr_gl_check("slicing setup", err)) != GR_OK) goto fail;
    *state = r;
    return GR_OK;
fail:
    sl_destroy(r);
    return st;
}

/* The table's ranges are checked by technique.c; what it cannot express: */
static gr_status sl_check(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    const gr_slicing_settings *s = settings;
    return gr_vol_check(cls->name, &s->vol, err);
}

enum { P_SLICES = GR_VOL_PASS_OWN, P_UPSAMPLE };

static gr_status sl_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    sl_state *r = state;
    const gr_slicing_settings *s = settings;
    gr_vol_prep prep;
    gr_status st = gr_vol_prepare("slicing", &r->base, scene, &s->vol, out, &prep, err);
    if (st != GR_OK) return st;
    const gr_frame *f = &prep.frame;
    int W = f->width, H = f->height;
    r->triangles = gr_caustics_triangles(r->base.caus);
    double tmax = prep.t_max;
    double far = gr_vol_far_depth(scene, f, tmax);
    double b[MAX_SLICES + 1];
    gr_vol_bounds(s->slices, s->distribution == GR_VOL_EXPONENTIAL, s->near_m, far, b);
    float bf[MAX_SLICES + 1];
    for (int i = 0; i <= s->slices; i++) bf[i] = (float)b[i];
    double rot[16], inv[16];
    gr_frame_view_proj_rot(f, rot);
    if (gr_mat4_inverse(rot, inv) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");
    float m[16];
    gr_frame_matf(inv, m);

    /* target_scale < 1: the slices on a reduced target (the fragments fall by target_scale^2),
     * each reading the eye depth at its pixel's centre, then a bilinear upsample (docs/
     * volume-techniques.md "Cost") */
    const int reduced = s->target_scale < 1.0;
    const gr_target *dst = &r->base.out;
    int sw = W, sh = H;
    if (reduced) {
        sw = (int)lround(W * s->target_scale);
        sh = (int)lround(H * s->target_scale);
        if (sw < 1) sw = 1;
        if (sh < 1) sh = 1;
        st = gr_target_ensure(&r->small, GL_RGBA32F, sw, sh, GR_TARGET_LINEAR, "slicing.target_scale: slices' target",
                              err);
        if (st != GR_OK) return st;
        dst = &r->small;
    }
    gr_gl_timer_begin(&r->base.timer, P_SLICES);
    glDisable(GL_DEPTH_TEST);
    gr_target_accumulate(dst); /* sw x sh */
    glUseProgram(r->prog);
    gr_vol_set(&r->vl, &prep.in);
    glUniformMatrix4fv(r->l_inv, 1, GL_FALSE, m);
    glUniform3f(r->l_fwd, (float)f->forward[0], (float)f->forward[1], (float)f->forward[2]);
    glUniform1fv(r->l_bounds, s->slices + 1, bf);
    glUniform1i(r->l_eye_depth, 1);
    glUniform2f(r->l_size, (float)sw, (float)sh);
    glUniform1f(r->l_tmax, (float)tmax);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, prep.depth_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindVertexArray(r->base.vao);
    glBeginQuery(GL_SAMPLES_PASSED, r->base.q_samples);
    glDrawArraysInstanced(GL_TRIANGLES, 0, 3, s->slices);
    glEndQuery(GL_SAMPLES_PASSED);
    glDisable(GL_BLEND);
    gr_gl_timer_end(&r->base.timer);
    if (reduced) {
        gr_gl_timer_begin(&r->base.timer, P_UPSAMPLE);
        glBindFramebuffer(GL_FRAMEBUFFER, r->base.out.fbo);
        glViewport(0, 0, W, H);
        glUseProgram(r->prog_up);
        glUniform1i(r->l_up_src, 0);
        glUniform2f(r->l_up_size, (float)W, (float)H);
        glBindTexture(GL_TEXTURE_2D, r->small.tex);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        gr_gl_timer_end(&r->base.timer);
    }
    glBindVertexArray(0);
    glUseProgram(0);
    r->sw = sw;
    r->sh = sh;
    r->n_slices = s->slices;
    static const char *const names[5] = {"shadow", "eye_depth", "caustics", "slices", "upsample"};
    st = gr_vol_finish("slicing", &r->base, &prep, out, names, 4 + reduced, stats, err);
    if (stats) {
        /* every slice is a full-screen triangle: W H fragments each, all taking the eye-depth
         * tap; those kept (queried) take up to 2 caustic taps (trilinear between 2 mip levels
         * counted as 2) and the shadow tap, and blend one RGBA32F texel after the clear */
        const long long px = (long long)sw * sh, kept = stats->fragments;
        gr_pass_cost c = gr_pass_cost_screen(sw, sh, 1, 16);
        c.v[GR_COST_FRAGMENTS] = px * s->slices;
        c.v[GR_COST_TAPS] = px * s->slices + kept * (2 + (prep.shadow_size > 0));
        c.v[GR_COST_VERTICES] = 3LL * s->slices;
        c.v[GR_COST_PRIMITIVES] = s->slices;
        c.v[GR_COST_BYTES] = px * 16 + kept * 16;
        gr_vol_cost_pass(stats, P_SLICES, &c);
        /* the upsample: one bilinear fetch a frame pixel into the RGBA32F output */
        if (reduced) c = gr_pass_cost_screen(W, H, 1, 16);
        if (reduced) gr_vol_cost_pass(stats, P_UPSAMPLE, &c);
    }
    return st;
}

static void sl_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    const sl_state *r = state;
    (void)stats;
    snprintf(buf, n, "%d slices at %dx%d, %lld caustic triangles", r->n_slices, r->sw, r->sh, r->triangles);
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
    .set_reuse = gr_vol_set_reuse,
    .summary = sl_summary,
};
