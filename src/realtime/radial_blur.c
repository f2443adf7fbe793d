/* Seed 004's radial blur and seed 003's localized variant (radial_blur.h;
 * docs/radial-blur.md for the derivations and decisions). */
#include "realtime/radial_blur.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "gl/gl.h"
#include "realtime/frame.h"
#include "realtime/readback.h"
#include "realtime/scenegl.h"
#include "realtime/shaders.h"
#include "realtime/toolkit.h"

#define MAX_LIGHTS 256

/* Seed 004's listing defaults (GLSL version). */
#define SEED_SAMPLES 100
#define SEED_DECAY 0.96815
#define SEED_EXPOSURE 0.2
#define SEED_DENSITY 0.926
#define SEED_WEIGHT 0.58767
#define SEED_SAMPLE_SCALE 0.4

/* ---- settings tables -------------------------------------------------------------------- */

#define NONE 0u
#define LO_X GR_PF_MIN_EXCL
#define HI_X GR_PF_MAX_EXCL
#define RB(field) offsetof(gr_radial_blur_settings, field)

static const char *const format_names[] = {"rgba16f", "rgba8", NULL};

#define COMMON_PARAMS                                                                                            \
    {.name = "samples", .type = GR_PT_INT, .offset = RB(samples), .min = 1, .max = 1024, .def = SEED_SAMPLES,   \
     .unit = "", .doc = "NUM_SAMPLES: taps marched toward the light (seed 004 / GPU Gems 3 ch. 13)"},            \
    {.name = "decay", .type = GR_PT_DOUBLE, .offset = RB(decay), .min = 0, .max = 1, .flags = LO_X,            \
     .def = SEED_DECAY, .unit = "", .doc = "per-tap decay: tap i weighs weight decay^(i-1)", .tune_lo = 0.85, .tune_hi = 0.999},                    \
    {.name = "exposure", .type = GR_PT_DOUBLE, .offset = RB(exposure), .min = 0, .max = 1e6, .def = SEED_EXPOSURE, \
     .unit = "", .doc = "final multiplier of the sum", .tune_lo = 0.02, .tune_hi = 2.0},                                                          \
    {.name = "density", .type = GR_PT_DOUBLE, .offset = RB(density), .min = 0, .max = 2, .flags = LO_X,        \
     .def = SEED_DENSITY, .unit = "", .doc = "fraction of the way to the light the N taps span", .tune_lo = 0.3, .tune_hi = 1.5},                \
    {.name = "weight", .type = GR_PT_DOUBLE, .offset = RB(weight), .min = 0, .max = 1e6, .def = SEED_WEIGHT,    \
     .unit = "", .doc = "weight of the marched taps (the centre tap has 1)", .tune_lo = 0.1, .tune_hi = 3.0},                                   \
    {.name = "sample_scale", .type = GR_PT_DOUBLE, .offset = RB(sample_scale), .min = 0, .max = 1e6,           \
     .def = SEED_SAMPLE_SCALE, .unit = "", .doc = "seed 004's '* 0.4' on every tap (GPU Gems 3 has 1)"},        \
    {.name = "target_scale", .type = GR_PT_DOUBLE, .offset = RB(target_scale), .min = 0, .max = 1,             \
     .flags = LO_X, .def = 0.5, .unit = "", .doc = "light pass target size / frame size, per axis", .tune_lo = 0.125, .tune_hi = 1.0},             \
    {.name = "target_format", .type = GR_PT_ENUM, .offset = RB(target_format), .min = 0, .max = 1,             \
     .def = GR_RB_RGBA16F, .enum_names = format_names, .unit = "",                                              \
     .doc = "light pass storage (rgba8 bands; dither adds half-step noise before it)"},                         \
    {.name = "light_radius_deg", .type = GR_PT_DOUBLE, .offset = RB(light_radius_deg), .min = 0, .max = 90,    \
     .flags = LO_X, .def = 4.0, .unit = "deg",                                                                  \
     .doc = "angular radius in air of the bright region around the sun (kernel (1-(a/a0)^2)^2)", .tune_lo = 0.5, .tune_hi = 20.0},               \
    {.name = "threshold", .type = GR_PT_DOUBLE, .offset = RB(threshold), .min = 0, .max = 1, .flags = HI_X,    \
     .def = 0, .unit = "", .doc = "subtracted from the light pass (1 = the flat-water peak)", .tune_lo = 0.0, .tune_hi = 0.5},                   \
    {.name = "occluders", .type = GR_PT_BOOL, .offset = RB(occluders), .min = 0, .max = 1, .def = 1,           \
     .unit = "", .doc = "draw occluders (and the seabed) black in the light pass"},                              \
    {.name = "intensity", .type = GR_PT_RGB, .offset = RB(intensity), .min = 0, .max = 1e9, .def = 1,          \
     .unit = "", .doc = "factor on the derived scale to the ground truth's units (1: exact at the sun, flat water)", \
     .tune_lo = 0.05, .tune_hi = 20.0},                                                                           \
    {.name = "dither", .type = GR_PT_BOOL, .offset = RB(dither), .min = 0, .max = 1, .def = 1, .unit = "",     \
     .doc = "per-pixel jitter of the march start against banding (deterministic noise)"}

static const gr_param blur_params[] = {
    COMMON_PARAMS,
    {.name = "fade_margin", .type = GR_PT_DOUBLE, .offset = RB(fade_margin), .min = 0, .max = 100, .def = 0.5,
     .unit = "", .doc = "NDC beyond the screen edge over which the rays fade out (smoothstep)", .tune_lo = 0.1, .tune_hi = 3.0},
    {.name = "blur_scale", .type = GR_PT_DOUBLE, .offset = RB(blur_scale), .min = 0, .max = 1, .flags = LO_X,
     .def = 1, .unit = "", .doc = "blur target size / frame size, per axis (< 1: blurred there, upsampled bilinearly)"},
};

static const gr_param local_params[] = {
    COMMON_PARAMS,
    {.name = "lights", .type = GR_PT_INT, .offset = RB(lights), .min = 1, .max = MAX_LIGHTS, .def = 16, .unit = "",
     .doc = "at most this many lights: the brightest cells of the light pass"},
    {.name = "quad_size", .type = GR_PT_DOUBLE, .offset = RB(quad_size), .min = 0, .max = 4, .flags = LO_X,
     .def = 0.3, .unit = "", .doc = "quad half-size as a fraction of the frame height", .tune_lo = 0.05, .tune_hi = 1.0},
    {.name = "falloff", .type = GR_PT_DOUBLE, .offset = RB(falloff), .min = 0, .max = 16, .def = 2, .unit = "",
     .doc = "(1 - r)^falloff to the quad's edge: 1 linear, 2 quadratic (seed 003)", .tune_lo = 0.5, .tune_hi = 4.0},
    {.name = "cell_size", .type = GR_PT_DOUBLE, .offset = RB(cell_size), .min = 0, .max = 1, .flags = LO_X,
     .def = 0.05, .unit = "", .doc = "light-selection cell side as a fraction of the frame height",
     .tune_lo = 0.01, .tune_hi = 0.2},
    {.name = "min_fraction", .type = GR_PT_DOUBLE, .offset = RB(min_fraction), .min = 0, .max = 1, .def = 0.02,
     .unit = "", .doc = "cells dimmer than this fraction of the brightest one are no light"},
    {.name = "normalize_overlap", .type = GR_PT_BOOL, .offset = RB(normalize_overlap), .min = 0, .max = 1,
     .def = 1, .unit = "", .doc = "where quads overlap, divide by the summed falloff (if > 1)"},
};
#undef RB

const gr_param_table gr_radial_blur_param_table = {"radial_blur", blur_params,
                                                   sizeof blur_params / sizeof blur_params[0]};
const gr_param_table gr_radial_blur_local_param_table = {"radial_blur_local", local_params,
                                                         sizeof local_params / sizeof local_params[0]};

/* ---- closed forms shared with the docs and tests ---------------------------------------- */

double gr_radial_blur_gain(int samples, double decay, double weight)
{
    return gr_light_blur_gain(samples, decay, weight);
}

double gr_radial_blur_fade(const double ndc[2], double clip_w, double margin)
{
    if (!(clip_w > 0)) return 0.0;
    double e = fmax(fabs(ndc[0]), fabs(ndc[1]));
    if (!(e > 1.0)) return 1.0;
    if (!(margin > 0)) return 0.0;
    double x = (e - 1.0) / margin;
    if (x >= 1.0) return 0.0;
    return 1.0 - x * x * (3.0 - 2.0 * x);
}

double gr_radial_blur_kernel_solid_angle(double a0) { return gr_light_kernel_solid_angle(a0); }

/* ---- state ------------------------------------------------------------------------------- */

enum { PASS_DEPTH = 0, PASS_LIGHT = 1, PASS_BLUR = 2, PASS_RESOLVE = 3 };

typedef struct rb_state rb_state;

/* What tells the two classes apart: one descriptor per class, its class_data. Both share
 * the eye depth and light passes; then the variant's screen pass (inside the samples query)
 * and its optional resolve. */
typedef struct rb_variant {
    int quads;      /* radial_blur_local: light selection, one quad per light, an accumulator */
    int fade;       /* fade the rays out as the refracted sun leaves the screen */
    gr_status (*screen)(rb_state *r, const gr_radial_blur_settings *s, int w, int h, const double sun_uv[2],
                        const double scale[3], gr_error *err);
    void (*resolve)(rb_state *r, const gr_radial_blur_settings *s, int w, int h, const double scale[3]);
    int n_passes;
    const char *pass_names[4];
} rb_variant;

struct rb_state {
    gr_gl *gl;
    const rb_variant *v;
    const char *name; /* the class's */
    char *shader_dir;
    gr_scenegl *sg;
    gr_light_pass light_pass; /* the toolkit's, shared with the user techniques' "sun_light" */
    GLuint prog_blur, prog_local, prog_resolve, prog_up;
    GLint loc_up_src, loc_up_size;
    gr_target small;   /* radial_blur at blur_scale < 1: the reduced blur target */
    int upsampled;     /* the last render blurred at a reduced size */
    struct {
        GLint light, sun_uv, size, samples, density, decay, weight, scale, dither, falloff;
    } lb, lq;
    GLint loc_acc, loc_rscale, loc_normalize;
    GLuint vao_empty, vao_quads, vbo_quads;
    gr_target light, out, acc; /* acc: radial_blur_local's quads, then resolved */
    GLuint q_samples;
    gr_gl_timer timer;
    gr_readback rb;
    /* last render */
    int rendered;
    double sun_uv[2], fade;
    int n_lights;
    double light_uv[MAX_LIGHTS][2];
};

static void get_blur_locs(GLuint p, GLint *light, GLint *sun_uv, GLint *size, GLint *samples, GLint *density,
                          GLint *decay, GLint *weight, GLint *scale, GLint *dither, GLint *falloff)
{
    *light = glGetUniformLocation(p, "u_light");
    *sun_uv = glGetUniformLocation(p, "u_sun_uv");
    *size = glGetUniformLocation(p, "u_size");
    *samples = glGetUniformLocation(p, "u_samples");
    *density = glGetUniformLocation(p, "u_density");
    *decay = glGetUniformLocation(p, "u_decay");
    *weight = glGetUniformLocation(p, "u_weight");
    *scale = glGetUniformLocation(p, "u_scale");
    *dither = glGetUniformLocation(p, "u_dither");
    *falloff = glGetUniformLocation(p, "u_falloff");
}

static void rb_destroy(void *state)
{
    rb_state *r = state;
    if (!r) return;
    gr_scenegl_destroy(r->sg);
    gr_light_pass_free(&r->light_pass);
    if (r->prog_blur) glDeleteProgram(r->prog_blur);
    if (r->prog_local) glDeleteProgram(r->prog_local);
    if (r->prog_resolve) glDeleteProgram(r->prog_resolve);
    if (r->prog_up) glDeleteProgram(r->prog_up);
    if (r->vao_empty) glDeleteVertexArrays(1, &r->vao_empty);
    if (r->vao_quads) glDeleteVertexArrays(1, &r->vao_quads);
    if (r->vbo_quads) glDeleteBuffers(1, &r->vbo_quads);
    if (r->q_samples) glDeleteQueries(1, &r->q_samples);
    if (r->timer.queries[0]) gr_gl_timer_free(&r->timer);
    gr_target_release(&r->light);
    gr_target_release(&r->out);
    gr_target_release(&r->acc);
    gr_target_release(&r->small);
    gr_readback_free(&r->rb);
    free(r->shader_dir);
    free(r);
}

static gr_status rb_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    gr_status st;
    const char *dir = opts ? opts->shader_dir : NULL;
    *state = NULL;
    if ((st = gr_shader_check_dir(dir, err)) != GR_OK) return st;
    rb_state *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "%s: out of memory", cls->name);
    r->gl = gl;
    r->v = cls->class_data;
    r->name = cls->name;
    if (dir) {
        size_t n = strlen(dir) + 1;
        if (!(r->shader_dir = malloc(n))) {
            free(r);
            return gr_fail(err, GR_E_NOMEM, "%s: out of memory", cls->name);
        }
        memcpy(r->shader_dir, dir, n);
    }
    if ((st = gr_scenegl_create_dir(gl, dir, &r->sg, err)) != GR_OK) goto fail;
    if ((st = gr_light_pass_init(&r->light_pass, dir, err)) != GR_OK) goto fail;
    if ((st = gr_shader_program(dir, "radial_blur_screen.vert.glsl", "radial_blur.frag.glsl", NULL, 0, &r->prog_blur,
                                NULL, err)) != GR_OK)
        goto fail;
    if (!r->v->quads) {
        if ((st = gr_shader_program(dir, "radial_blur_screen.vert.glsl", "radial_blur_upsample.frag.glsl", NULL, 0,
                                    &r->prog_up, NULL, err)) != GR_OK)
            goto fail;
        r->loc_up_src = glGetUniformLocation(r->prog_up, "u_src");
        r->loc_up_size = glGetUniformLocation(r->prog_up, "u_size");
    }
    if (r->v->quads) {
        if ((st = gr_shader_program(dir, "radial_blur_local.vert.glsl", "radial_blur_local.frag.glsl", NULL, 0,
                                    &r->prog_local, NULL, err)) != GR_OK)
            goto fail;
        if ((st = gr_shader_program(dir, "radial_blur_screen.vert.glsl", "radial_blur_resolve.frag.glsl", NULL, 0,
                                    &r->prog_resolve, NULL, err)) != GR_OK)
            goto fail;
        get_blur_locs(r->prog_local, &r->lq.light, &r->lq.sun_uv, &r->lq.size, &r->lq.samples, &r->lq.density,
                      &r->lq.decay, &r->lq.weight, &r->lq.scale, &r->lq.dither, &r->lq.falloff);
        r->loc_acc = glGetUniformLocation(r->prog_resolve, "u_acc");
        r->loc_rscale = glGetUniformLocation(r->prog_resolve, "u_scale");
        r->loc_normalize = glGetUniformLocation(r->prog_resolve, "u_normalize");
    }
    get_blur_locs(r->prog_blur, &r->lb.light, &r->lb.sun_uv, &r->lb.size, &r->lb.samples, &r->lb.density,
                  &r->lb.decay, &r->lb.weight, &r->lb.scale, &r->lb.dither, &r->lb.falloff);
    glGenVertexArrays(1, &r->vao_empty);
    glGenVertexArrays(1, &r->vao_quads);
    glGenBuffers(1, &r->vbo_quads);
    glBindVertexArray(r->vao_quads);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_quads);
    GLsizei stride = (GLsizei)(6 * sizeof(float));
    for (GLuint a = 0; a < 3; a++) {
        glEnableVertexAttribArray(a);
        glVertexAttribPointer(a, 2, GL_FLOAT, GL_FALSE, stride, (const void *)(a * 2 * sizeof(float)));
    }
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glGenQueries(1, &r->q_samples);
    gr_gl_timer_init(&r->timer);
    if ((st = gr_gl_check("radial blur setup", err)) != GR_OK) goto fail;
    *state = r;
    return GR_OK;
fail:
    rb_destroy(r);
    return st;
}

/* The light pass target: reduced size, the chosen storage (fmt 2, internal: RGBA32F), bilinear,
 * black outside the screen. */
static gr_status ensure_light(rb_state *r, int w, int h, int fmt, const char *name, gr_error *err)
{
    char what[96];
    snprintf(what, sizeof what, "%s.target_scale: light pass target", name);
    GLenum ifmt = fmt == GR_RB_RGBA8 ? GL_RGBA8 : fmt == GR_RB_RGBA16F ? GL_RGBA16F : GL_RGBA32F;
    return gr_target_ensure(&r->light, ifmt, w, h, GR_TARGET_LINEAR | GR_TARGET_BLACK_BORDER, what, err);
}

static gr_status ensure_out(rb_state *r, int w, int h, gr_error *err)
{
    return gr_target_ensure(&r->out, GL_RGBA32F, w, h, 0, "camera.width/height: god-ray layer target", err);
}

static void set_blur_uniforms(GLuint prog, GLint light, GLint size, GLint samples, GLint density, GLint decay,
                              GLint weight, GLint dither, const gr_radial_blur_settings *s, int w, int h)
{
    glUseProgram(prog);
    glUniform1i(light, 0);
    glUniform2f(size, (float)w, (float)h);
    glUniform1i(samples, s->samples);
    glUniform1f(density, (float)s->density);
    glUniform1f(decay, (float)s->decay);
    glUniform1f(weight, (float)s->weight);
    glUniform1i(dither, s->dither);
}

/* Runs the full-screen blur from r->light.tex into fbo (w x h). */
static void blur_pass(rb_state *r, unsigned fbo, const gr_radial_blur_settings *s, const double sun_uv[2],
                      const double scale[3], int w, int h)
{
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, w, h);
    glDisable(GL_BLEND);
    set_blur_uniforms(r->prog_blur, r->lb.light, r->lb.size, r->lb.samples, r->lb.density, r->lb.decay, r->lb.weight,
                      r->lb.dither, s, w, h);
    glUniform2f(r->lb.sun_uv, (float)sun_uv[0], (float)sun_uv[1]);
    glUniform3f(r->lb.scale, (float)scale[0], (float)scale[1], (float)scale[2]);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r->light.tex);
    glBindVertexArray(r->vao_empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/* Reads r->out.fbo (w x h) into out's R, G, B (top row first). */
static gr_status read_out(rb_state *r, gr_image *out, const char *what, gr_error *err)
{
    return gr_readback_rgb(&r->rb, r->out.fbo, out, NULL, what, err); /* NaN/Inf: checked by the harness */
}

/* ---- light selection (radial_blur_local) -------------------------------------------------- */

typedef struct cell { double sum; int idx; } cell;

static int cell_cmp(const void *a, const void *b)
{
    const cell *x = a, *y = b;
    if (x->sum != y->sum) return x->sum < y->sum ? 1 : -1; /* brightest first */
    return x->idx - y->idx;                                /* ties: deterministic */
}

/* The brightest cells of the light pass (luminance sums), each suppressing its 8 neighbours,
 * at most s->lights, each placed at its cell's luminance-weighted centroid (docs, "Lights"). */
static gr_status select_lights(rb_state *r, const gr_radial_blur_settings *s, gr_error *err)
{
    int w = r->light.w, h = r->light.h;
    /* cells relative to the frame, so the lights (and their overlap) do not grow in number
     * with the resolution */
    int cp = (int)lround(s->cell_size * h);
    if (cp < 1) cp = 1;
    int cw = (w + cp - 1) / cp, chh = (h + cp - 1) / cp;
    gr_status st = gr_readback_fbo(&r->rb, r->light.fbo, w, h, "radial_blur_local: light pass", err);
    if (st != GR_OK) return st;
    cell *cells = malloc((size_t)cw * chh * sizeof *cells);
    double *cx = calloc((size_t)cw * chh * 2, sizeof *cx);
    unsigned char *taken = calloc((size_t)cw * chh, 1);
    if (!cells || !cx || !taken) {
        free(cells);
        free(cx);
        free(taken);
        return gr_fail(err, GR_E_NOMEM, "radial_blur_local: out of memory for the light cells");
    }
    for (int i = 0; i < cw * chh; i++) {
        cells[i].sum = 0.0;
        cells[i].idx = i;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *p = r->rb.rgba + ((size_t)y * w + x) * 4; /* GL rows: y = 0 at the bottom */
            double lum = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            if (!(lum > 0)) continue;
            int c = (y / cp) * cw + x / cp;
            cells[c].sum += lum;
            cx[2 * c] += lum * (x + 0.5);
            cx[2 * c + 1] += lum * (y + 0.5);
        }
    /* centroids before sorting (cx is indexed by cell) */
    qsort(cells, (size_t)cw * chh, sizeof *cells, cell_cmp);
    double top = cells[0].sum;
    r->n_lights = 0;
    for (int k = 0; k < cw * chh && r->n_lights < s->lights; k++) {
        const cell *c = &cells[k];
        if (!(c->sum > 0) || c->sum < s->min_fraction * top) break;
        if (taken[c->idx]) continue;
        int ix = c->idx % cw, iy = c->idx / cw;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int x = ix + dx, y = iy + dy;
                if (x >= 0 && x < cw && y >= 0 && y < chh) taken[y * cw + x] = 1;
            }
        r->light_uv[r->n_lights][0] = cx[2 * c->idx] / c->sum / w;
        r->light_uv[r->n_lights][1] = cx[2 * c->idx + 1] / c->sum / h;
        r->n_lights++;
    }
    free(cells);
    free(cx);
    free(taken);
    return gr_gl_check("radial_blur_local: light selection", err);
}

/* ---- the variants' screen passes -------------------------------------------------------- */

/* radial_blur: one full-screen blur toward the refracted sun. */
static gr_status stage_blur(rb_state *r, const gr_radial_blur_settings *s, int W, int H, const double sun_uv[2],
                            const double scale[3], gr_error *err)
{
    r->upsampled = s->blur_scale < 1.0;
    if (!r->upsampled) {
        gr_gl_timer_begin(&r->timer, PASS_BLUR);
        blur_pass(r, r->out.fbo, s, sun_uv, scale, W, H);
        gr_gl_timer_end(&r->timer);
        return GR_OK;
    }
    /* blur_scale < 1: the march on a reduced target (the taps fall by blur_scale^2), then a
     * bilinear upsample (docs/radial-blur.md, "Cost") */
    int bw = (int)lround(W * s->blur_scale), bh = (int)lround(H * s->blur_scale);
    if (bw < 1) bw = 1;
    if (bh < 1) bh = 1;
    gr_status st = gr_target_ensure(&r->small, GL_RGBA32F, bw, bh, GR_TARGET_LINEAR,
                                    "radial_blur.blur_scale: reduced blur target", err);
    if (st != GR_OK) return st;
    gr_gl_timer_begin(&r->timer, PASS_BLUR);
    blur_pass(r, r->small.fbo, s, sun_uv, scale, bw, bh);
    gr_gl_timer_end(&r->timer);
    gr_gl_timer_begin(&r->timer, PASS_RESOLVE);
    glBindFramebuffer(GL_FRAMEBUFFER, r->out.fbo);
    glViewport(0, 0, W, H);
    glUseProgram(r->prog_up);
    glUniform1i(r->loc_up_src, 0);
    glUniform2f(r->loc_up_size, (float)W, (float)H);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r->small.tex);
    glBindVertexArray(r->vao_empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    gr_gl_timer_end(&r->timer);
    return GR_OK;
}

/* radial_blur_local: CPU light selection, then all quads in one draw into the float
 * accumulator. */
static gr_status stage_quads(rb_state *r, const gr_radial_blur_settings *s, int W, int H, const double sun_uv[2],
                             const double scale[3], gr_error *err)
{
    (void)sun_uv;
    (void)scale;
    gr_status st;
    if ((st = select_lights(r, s, err)) != GR_OK) return st;
    float *v = malloc((size_t)(r->n_lights > 0 ? r->n_lights : 1) * 6 * 6 * sizeof *v);
    if (!v) return gr_fail(err, GR_E_NOMEM, "radial_blur_local: out of memory for the quads");
    static const float corners[6][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, -1}, {1, 1}, {-1, 1}};
    float hx = (float)(s->quad_size * (double)H / (double)W), hy = (float)s->quad_size;
    for (int l = 0; l < r->n_lights; l++)
        for (int k = 0; k < 6; k++) {
            float *p = v + ((size_t)l * 6 + (size_t)k) * 6;
            p[0] = corners[k][0];
            p[1] = corners[k][1];
            p[2] = (float)r->light_uv[l][0];
            p[3] = (float)r->light_uv[l][1];
            p[4] = hx;
            p[5] = hy;
        }
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_quads);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)r->n_lights * 36 * sizeof *v), r->n_lights ? v : NULL,
                 GL_STREAM_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    free(v);
    gr_gl_timer_begin(&r->timer, PASS_BLUR);
    gr_target_accumulate(&r->acc); /* W x H */
    set_blur_uniforms(r->prog_local, r->lq.light, r->lq.size, r->lq.samples, r->lq.density, r->lq.decay,
                      r->lq.weight, r->lq.dither, s, W, H);
    glUniform1f(r->lq.falloff, (float)s->falloff);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r->light.tex);
    glBindVertexArray(r->vao_quads);
    if (r->n_lights > 0) glDrawArrays(GL_TRIANGLES, 0, r->n_lights * 6);
    glDisable(GL_BLEND);
    gr_gl_timer_end(&r->timer);
    return GR_OK;
}

/* radial_blur_local's resolve: accumulator -> god-ray layer (divide by the summed falloff,
 * scale). */
static void stage_resolve(rb_state *r, const gr_radial_blur_settings *s, int W, int H, const double scale[3])
{
    gr_gl_timer_begin(&r->timer, PASS_RESOLVE);
    glBindFramebuffer(GL_FRAMEBUFFER, r->out.fbo);
    glViewport(0, 0, W, H);
    glUseProgram(r->prog_resolve);
    glUniform1i(r->loc_acc, 0);
    glUniform3f(r->loc_rscale, (float)scale[0], (float)scale[1], (float)scale[2]);
    glUniform1i(r->loc_normalize, s->normalize_overlap);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, r->acc.tex);
    glBindVertexArray(r->vao_empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    gr_gl_timer_end(&r->timer);
}

/* ---- cost counters (technique.h; docs/radial-blur.md, "Cost") -------------------------------- */

/* Sets the analytic counters of pass p (keeping its queried primitives). */
static void set_pass(gr_technique_stats *stats, int p, gr_pass_cost c)
{
    const gr_pass_cost q = stats->cost[p];
    if (q.queried & (1u << GR_COST_PRIMITIVES)) {
        c.v[GR_COST_PRIMITIVES] = q.v[GR_COST_PRIMITIVES];
        c.queried |= 1u << GR_COST_PRIMITIVES;
    }
    stats->cost[p] = c;
}

/* eye depth: R32F at the light target's size; light: a full-screen pass into the light target
 * (one eye-depth fetch with occluders); blur: samples + 1 taps a pixel at the frame's size into
 * RGBA32F; quads: the same taps per (queried) fragment, 6 vertices a light, after a clear of
 * the accumulator; resolve: one fetch a pixel. */
static void count_cost(const rb_state *r, const gr_radial_blur_settings *s, int W, int H, gr_technique_stats *stats)
{
    const long long tw = r->light.w, th = r->light.h, taps = (long long)s->samples + 1;
    gr_pass_cost c;
    gr_pass_cost_clear(&c);
    c.v[GR_COST_BYTES] = tw * th * 4;
    c.v[GR_COST_TAPS] = 0;
    c.v[GR_COST_INVOCATIONS] = 0;
    set_pass(stats, PASS_DEPTH, c);
    set_pass(stats, PASS_LIGHT, gr_pass_cost_screen(tw, th, s->occluders ? 1 : 0,
                                                    s->target_format == GR_RB_RGBA8 ? 4 : 8));
    if (!r->v->quads) {
        const long long bw = r->upsampled ? r->small.w : W, bh = r->upsampled ? r->small.h : H;
        set_pass(stats, PASS_BLUR, gr_pass_cost_screen(bw, bh, taps, 16));
        if (r->upsampled) { /* the samples query spans both passes: the blur's fragments analytic */
            set_pass(stats, PASS_RESOLVE, gr_pass_cost_screen(W, H, 1, 16));
            return;
        }
        stats->cost[PASS_BLUR].v[GR_COST_FRAGMENTS] = stats->fragments;
        stats->cost[PASS_BLUR].queried |= 1u << GR_COST_FRAGMENTS;
        return;
    }
    const long long frag = stats->fragments;
    gr_pass_cost_clear(&c);
    c.v[GR_COST_FRAGMENTS] = frag;
    c.queried = 1u << GR_COST_FRAGMENTS;
    c.v[GR_COST_TAPS] = frag * taps;
    c.v[GR_COST_VERTICES] = 6LL * r->n_lights;
    c.v[GR_COST_PRIMITIVES] = 2LL * r->n_lights;
    c.v[GR_COST_BYTES] = (long long)W * H * 16 + frag * 16;
    c.v[GR_COST_INVOCATIONS] = 0;
    set_pass(stats, PASS_BLUR, c);
    set_pass(stats, PASS_RESOLVE, gr_pass_cost_screen(W, H, 1, 16));
}

/* ---- render ---------------------------------------------------------------------------------- */


static gr_status rb_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    rb_state *r = state;
    const gr_radial_blur_settings *s = settings;
    const char *name = r->name;
    double t0 = gr_clock_ms();
    gr_status st;
    gr_frame f;
    gr_frame_init(scene, &f);
    int W = f.width, H = f.height;
    int ch[3] = {gr_image_channel(out, "R"), gr_image_channel(out, "G"), gr_image_channel(out, "B")};
    if (out->width != W || out->height != H || ch[0] < 0 || ch[1] < 0 || ch[2] < 0)
        return gr_fail(err, GR_E_INPUT, "%s: output image is %dx%d (needs %dx%d with R, G, B channels)", name,
                       out->width, out->height, W, H);
    int tw = (int)lround(W * s->target_scale), th = (int)lround(H * s->target_scale);
    if (tw < 1) tw = 1;
    if (th < 1) th = 1;
    if ((st = gr_gl_make_current(r->gl, err)) != GR_OK) return st;
    if ((st = ensure_light(r, tw, th, s->target_format, name, err)) != GR_OK) return st;
    if ((st = ensure_out(r, W, H, err)) != GR_OK) return st;
    if (r->v->quads && (st = gr_target_ensure(&r->acc, GL_RGBA32F, W, H, 0,
                                              "camera.width/height: radial_blur_local accumulator", err)) != GR_OK)
        return st;

    gr_gl_timer_reset(&r->timer);
    /* Pass 0: occluders' (and the seabed's) distance from the eye at the light target's size. */
    unsigned depth_tex = 0;
    gr_gl_timer_begin(&r->timer, PASS_DEPTH);
    st = gr_scenegl_eye_depth(r->sg, scene, &f, tw, th, &depth_tex, err);
    gr_gl_timer_end(&r->timer);
    if (st != GR_OK) return st;

    /* Pass 1: light pass into the reduced target (the toolkit's, realtime/toolkit.h). */
    gr_gl_timer_begin(&r->timer, PASS_LIGHT);
    const gr_light_params lp = {.radius_deg = s->light_radius_deg,
                                .threshold = s->threshold,
                                .occluders = s->occluders,
                                .dither8 = s->dither && s->target_format == GR_RB_RGBA8};
    st = gr_light_pass_draw(&r->light_pass, scene, &f, &lp, &r->light, depth_tex, name, err);
    gr_gl_timer_end(&r->timer);
    if (st != GR_OK) return st;

    /* Output scale: k * intensity * exposure * sample_scale * peak * fade, where peak = n^2 T_flat
     * E / Omega_eff is the flat-water light-pass radiance at the sun (docs, "Units"). */
    double fade = r->v->fade ? gr_radial_blur_fade(f.sun_ndc, f.sun_clip_w, s->fade_margin) : 1.0;
    double scale[3];
    gr_light_units(scene, &f, s->light_radius_deg, s->intensity, s->exposure, s->sample_scale, fade, scale);
    r->sun_uv[0] = f.sun_uv[0];
    r->sun_uv[1] = f.sun_uv[1];
    r->fade = fade;

    glBeginQuery(GL_SAMPLES_PASSED, r->q_samples);
    st = r->v->screen(r, s, W, H, f.sun_uv, scale, err);
    glEndQuery(GL_SAMPLES_PASSED);
    if (st != GR_OK) return st;
    if (r->v->resolve) r->v->resolve(r, s, W, H, scale);
    st = read_out(r, out, name, err);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (st != GR_OK) return st;
    if (stats) {
        gr_gl_timer_stats(stats, &r->timer, r->v->pass_names, r->v->n_passes + (r->upsampled && !r->v->quads), t0);
        stats->fragments = gr_gl_query_result(r->q_samples);
        count_cost(r, s, W, H, stats);
        stats->wall_ms = gr_clock_ms() - t0;
    }
    r->rendered = 1;
    return gr_image_check_finite(out, name, err);
}

/* ---- tests' entry points ------------------------------------------------------------------- */

gr_status gr_radial_blur_blur_image(void *state, const gr_image *light, const double sun_uv[2],
                                    const gr_radial_blur_settings *s, const double scale[3], gr_image *out,
                                    gr_error *err)
{
    rb_state *r = state;
    gr_status st;
    if (light->nchannels < 3) return gr_fail(err, GR_E_INPUT, "injected light image: needs at least 3 channels");
    if ((st = gr_gl_make_current(r->gl, err)) != GR_OK) return st;
    /* format 2 (internal): RGBA32F, so the injected values are exact */
    if ((st = ensure_light(r, light->width, light->height, 2, "radial_blur", err)) != GR_OK) return st;
    if ((st = ensure_out(r, out->width, out->height, err)) != GR_OK) return st;
    float *px = malloc((size_t)light->width * light->height * 4 * sizeof *px);
    if (!px) return gr_fail(err, GR_E_NOMEM, "injected light image: out of memory");
    for (int y = 0; y < light->height; y++)
        for (int x = 0; x < light->width; x++) {
            const float *src = light->pixels + ((size_t)y * light->width + x) * (size_t)light->nchannels;
            float *d = px + ((size_t)(light->height - 1 - y) * light->width + x) * 4;
            for (int c = 0; c < 3; c++) d[c] = src[c];
            d[3] = 1.0f;
        }
    glBindTexture(GL_TEXTURE_2D, r->light.tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, light->width, light->height, GL_RGBA, GL_FLOAT, px);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(px);
    blur_pass(r, r->out.fbo, s, sun_uv, scale, out->width, out->height);
    st = read_out(r, out, "radial_blur (injected light)", err);
    glBindVertexArray(0);
    glUseProgram(0);
    return st;
}

int gr_radial_blur_local_lights(void *state, double (*uv)[2], int max)
{
    rb_state *r = state;
    int n = r->n_lights < max ? r->n_lights : max;
    for (int i = 0; i < n; i++) {
        uv[i][0] = r->light_uv[i][0];
        uv[i][1] = r->light_uv[i][1];
    }
    return r->n_lights;
}

/* The light pass of the last render (RGBA float, top row first, as stored: the normalized
 * light pass s of docs/radial-blur.md). */
static gr_status rb_read_target(void *state, gr_image **out, gr_error *err)
{
    rb_state *r = state;
    *out = NULL;
    if (!r->rendered) return gr_fail(err, GR_E_RUNTIME, "radial blur: no render yet, no light pass to read");
    gr_status st = gr_gl_make_current(r->gl, err);
    if (st != GR_OK) return st;
    if ((st = gr_readback_fbo(&r->rb, r->light.fbo, r->light.w, r->light.h, "radial blur light pass", err)) != GR_OK)
        return st;
    *out = gr_readback_image(&r->rb);
    return *out ? GR_OK : gr_fail(err, GR_E_NOMEM, "radial blur: out of memory for the light pass image");
}

/* ---- metadata ----------------------------------------------------------------------------- */

static gr_status rb_metadata(void *state, const gr_scene *scene, const void *settings, const gr_technique_stats *stats,
                             gr_metadata *meta, gr_error *err)
{
    rb_state *r = state;
    (void)scene;
    (void)settings;
    (void)stats;
    char val[128];
    gr_status st;
    snprintf(val, sizeof val, "%.9g %.9g", r->sun_uv[0], r->sun_uv[1]);
    if ((st = gr_meta_set_string(meta, "godrays:radial_blur_sun_uv", val)) != GR_OK) goto fail;
    if ((st = gr_meta_set_double(meta, "godrays:radial_blur_fade", r->fade)) != GR_OK) goto fail;
    snprintf(val, sizeof val, "%dx%d", r->light.w, r->light.h);
    if ((st = gr_meta_set_string(meta, "godrays:radial_blur_target_size", val)) != GR_OK) goto fail;
    if (r->v->quads && (st = gr_meta_set_int(meta, "godrays:radial_blur_lights", r->n_lights)) != GR_OK) goto fail;
    return GR_OK;
fail:
    return gr_fail(err, st, "radial blur metadata: cannot add an entry (%s)", gr_status_name(st));
}

static void rb_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    rb_state *r = state;
    (void)stats;
    int k = snprintf(buf, n, "light target %dx%d, refracted sun at uv (%.3f, %.3f), fade %.3g", r->light.w,
                     r->light.h, r->sun_uv[0], r->sun_uv[1], r->fade);
    if (r->v->quads && k > 0 && (size_t)k < n) snprintf(buf + k, n - (size_t)k, ", %d light(s)", r->n_lights);
}

/* `godrays pareto` (docs/radial-blur.md, "Cost"): fewer taps with the decay and weight rescaled
 * so that the march keeps its length and gain (decay^(100/N), weight 100/N), at reduced blur
 * and light resolutions; the last point is the seed's. */
static const gr_technique_level blur_ladder[] = {
    {"samples=16,decay=0.8168,weight=3.673,blur_scale=0.25,target_scale=0.25", 1},
    {"samples=32,decay=0.9038,weight=1.8365,blur_scale=0.5,target_scale=0.25", 1},
    {"samples=50,decay=0.9373,weight=1.1753,blur_scale=0.5", 0},
    {"samples=100,blur_scale=0.5", 1},
    {"samples=100", 1},
};
static const gr_technique_level local_ladder[] = {
    {"samples=16,decay=0.8168,weight=3.673,lights=4,target_scale=0.25", 1},
    {"samples=32,decay=0.9038,weight=1.8365,lights=8", 1},
    {"samples=100", 1},
};

static const rb_variant variant_blur = {
    .quads = 0,
    .fade = 1,
    .screen = stage_blur,
    .resolve = NULL,
    .n_passes = 3, /* + "upsample" at blur_scale < 1 */
    .pass_names = {"eye_depth", "light", "blur", "upsample"},
};

static const rb_variant variant_local = {
    .quads = 1,
    .fade = 0,
    .screen = stage_quads,
    .resolve = stage_resolve,
    .n_passes = 4,
    .pass_names = {"eye_depth", "light", "quads", "resolve"},
};

const gr_technique_class gr_radial_blur_class = {
    .name = "radial_blur",
    .description = "seeds 004/GPU Gems 3 ch. 13: radial blur of the refracted sun seen through the surface",
    .params = &gr_radial_blur_param_table,
    .settings_size = sizeof(gr_radial_blur_settings),
    .origin = "built-in",
    .class_data = &variant_blur,
    .gain_key = "intensity",
    /* the look: the march's length and falloff, the light's size and cut, the fade; not exposure
     * (a multiplier, the gain's twin) nor target_scale (a cost the ladder sets) */
    .tune_keys = "decay,density,weight,light_radius_deg,threshold,fade_margin",
    .ladder = blur_ladder,
    .n_ladder = (int)(sizeof blur_ladder / sizeof blur_ladder[0]),
    .create = rb_create,
    .destroy = rb_destroy,
    .render = rb_render,
    .metadata = rb_metadata,
    .read_target = rb_read_target,
    .summary = rb_summary,
};

const gr_technique_class gr_radial_blur_local_class = {
    .name = "radial_blur_local",
    .description = "seed 003: localized radial blur, one quad per bright surface patch, one draw",
    .params = &gr_radial_blur_local_param_table,
    .settings_size = sizeof(gr_radial_blur_settings),
    .origin = "built-in",
    .class_data = &variant_local,
    .gain_key = "intensity",
    /* as radial_blur's, with the quads' size and falloff and the selection's cell for the fade */
    .tune_keys = "decay,density,weight,light_radius_deg,threshold,quad_size,falloff,cell_size",
    .ladder = local_ladder,
    .n_ladder = (int)(sizeof local_ladder / sizeof local_ladder[0]),
    .create = rb_create,
    .destroy = rb_destroy,
    .render = rb_render,
    .metadata = rb_metadata,
    .read_target = rb_read_target,
    .summary = rb_summary,
};
