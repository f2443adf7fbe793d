/* Light rays as line primitives (seed 001, Hu et al. 2010; lightrays.h,
 * docs/volume-techniques.md "Light rays"). */
#include "realtime/lightrays.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "gl/gl.h"
#include "realtime/frame.h"
#include "realtime/scenegl.h"
#include "realtime/shaders.h"

#define MAX_RAYS 4096
#define MAX_CELLS 2048
#define LR(f) offsetof(gr_light_rays_settings, f)
static const char *const footprint_names[] = {"prism", "ribbon", NULL};

static const gr_param params[] = {
    {.name = "rays", .type = GR_PT_INT, .offset = LR(rays), .min = 8, .max = MAX_RAYS, .def = 512, .unit = "texels",
     .doc = "texels per side of the sun's view of the water: rays^2 lines"},
    {.name = "footprint", .type = GR_PT_ENUM, .offset = LR(footprint), .min = 0, .max = 1, .def = GR_LIGHT_RAYS_PRISM,
     .enum_names = footprint_names, .unit = "",
     .doc = "prism: each pixel's ray through the line's beam, integrated exactly; ribbon: a camera-facing sheet"},
    {.name = "kernel", .type = GR_PT_INT, .offset = LR(kernel), .min = 1, .max = 8, .def = 1, .unit = "texels",
     .doc = "each line's beam is kernel x kernel texels wide, with 1 / kernel^2 of the flux per area (smooths waves)"},
    {.name = "line_width", .type = GR_PT_DOUBLE, .offset = LR(line_width), .min = 0, .max = 64, .flags = GR_PF_MIN_EXCL,
     .def = 1, .unit = "px",
     .doc = "the ribbon's least width (the prism is drawn as its own faces: no effect there)", .tune_lo = 0.5, .tune_hi = 8.0},
    {.name = "max_length_m", .type = GR_PT_DOUBLE, .offset = LR(max_length_m), .min = 0, .max = 1e4,
     .flags = GR_PF_MIN_EXCL, .def = 200, .unit = "m",
     .doc = "longest line from the surface (the seabed and the occluders end them first)",
     .tune_lo = 5.0, .tune_hi = 200.0},
    {.name = "margin_m", .type = GR_PT_DOUBLE, .offset = LR(margin_m), .min = 0, .max = 1e4, .def = 1, .unit = "m",
     .doc = "border of the sun's view around the surface that lights the visible volume"},
    GR_VOL_PARAMS_MEDIUM(gr_light_rays_settings),
    GR_VOL_PARAMS_LIGHT(gr_light_rays_settings),
};
#undef LR

static const gr_param_table table = {"light_rays", params, sizeof params / sizeof params[0]};

static const gr_technique_level ladder[] = {
    /* fewer, wider rays with the cheap footprint (docs/volume-techniques.md "Cost") */
    {"rays=64,footprint=ribbon", 1},
    {"rays=128,footprint=ribbon", 0},
    {"rays=128", 1},
    {"rays=256", 0},
    {"rays=512", 1},
    {"rays=1024", 0},
};

typedef struct lr_state {
    gr_vol_base base;
    GLuint prog_surf, prog_lines;
    GLuint surf_tex[2], surf_depth, surf_fbo;
    int surf_n;
    gr_vol_locs vl;
    GLint s_cells, s_half, s_win, s_zr, s_c, s_e1, s_e2, s_sun, s_nw, s_wa, s_wamp;
    GLint l_pos, l_nrm, l_rays, l_vp, l_sun, l_ior, l_area, l_footprint, l_pix, l_width, l_max, l_seabed, l_eye_depth,
        l_size, l_tmax, l_h1, l_h2, l_inv, l_kernel;
    int n_rays;
    double window_m;
} lr_state;

static void lr_destroy(void *state)
{
    lr_state *r = state;
    if (!r) return;
    if (gr_vol_base_current(&r->base)) {
        if (r->prog_surf) glDeleteProgram(r->prog_surf);
        if (r->prog_lines) glDeleteProgram(r->prog_lines);
        if (r->surf_fbo) glDeleteFramebuffers(1, &r->surf_fbo);
        if (r->surf_tex[0]) glDeleteTextures(2, r->surf_tex);
        if (r->surf_depth) glDeleteTextures(1, &r->surf_depth);
    }
    gr_vol_base_release(&r->base);
    free(r);
}

static gr_status lr_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                           gr_error *err)
{
    (void)cls;
    *state = NULL;
    const char *dir = opts ? opts->shader_dir : NULL;
    lr_state *r = calloc(1, sizeof *r);
    if (!r) return gr_fail(err, GR_E_NOMEM, "light_rays: out of memory");
    gr_status st;
    if ((st = gr_vol_base_init(&r->base, gl, dir, 0, err)) != GR_OK) goto fail;
    const gr_shader_stage surf[2] = {{GL_VERTEX_SHADER, {"volume_version.glsl", "volume_surface.glsl", "lightrays_surface.vert.glsl", NULL}},
                                  {GL_FRAGMENT_SHADER, {"lightrays_surface.frag.glsl", NULL, NULL, NULL}}};
    const gr_shader_stage lines[3] = {
        {GL_VERTEX_SHADER, {"lightrays.vert.glsl", NULL, NULL, NULL}},
        {GL_GEOMETRY_SHADER,
         {"volume_version.glsl", "caustic_stack.glsl", "volume_common.glsl", "volume_surface.glsl",
          "lightrays.geom.glsl"}},
        {GL_FRAGMENT_SHADER,
         {"volume_version.glsl", "volume_fragment.glsl", "caustic_stack.glsl", "volume_common.glsl",
          "lightrays.frag.glsl"}}};
    if ((st = gr_shader_program_stages(dir, surf, 2, NULL, 0, &r->prog_surf, NULL, err)) != GR_OK) goto fail;
    if ((st = gr_shader_program_stages(dir, lines, 3, NULL, 0, &r->prog_lines, NULL, err)) != GR_OK) goto fail;
    GLuint p = r->prog_surf;
    r->s_cells = glGetUniformLocation(p, "u_cells");
    r->s_half = glGetUniformLocation(p, "u_half");
    r->s_win = glGetUniformLocation(p, "u_win");
    r->s_zr = glGetUniformLocation(p, "u_zr");
    r->s_c = glGetUniformLocation(p, "u_c");
    r->s_e1 = glGetUniformLocation(p, "u_e1");
    r->s_e2 = glGetUniformLocation(p, "u_e2");
    r->s_sun = glGetUniformLocation(p, "u_sun_dir");
    r->s_nw = glGetUniformLocation(p, "u_n_waves");
    r->s_wa = glGetUniformLocation(p, "u_wa");
    r->s_wamp = glGetUniformLocation(p, "u_wamp");
    p = r->prog_lines;
    gr_vol_locations(p, &r->vl);
    r->l_pos = glGetUniformLocation(p, "u_pos");
    r->l_nrm = glGetUniformLocation(p, "u_nrm");
    r->l_rays = glGetUniformLocation(p, "u_rays");
    r->l_vp = glGetUniformLocation(p, "u_vp_rot");
    r->l_sun = glGetUniformLocation(p, "u_sun_dir");
    r->l_ior = glGetUniformLocation(p, "u_ior");
    r->l_area = glGetUniformLocation(p, "u_texel_area");
    r->l_footprint = glGetUniformLocation(p, "u_footprint");
    r->l_h1 = glGetUniformLocation(p, "u_h1");
    r->l_h2 = glGetUniformLocation(p, "u_h2");
    r->l_inv = glGetUniformLocation(p, "u_inv_vp_rot");
    r->l_kernel = glGetUniformLocation(p, "u_kernel");
    r->l_pix = glGetUniformLocation(p, "u_pix");
    r->l_width = glGetUniformLocation(p, "u_line_width");
    r->l_max = glGetUniformLocation(p, "u_max_len");
    r->l_seabed = glGetUniformLocation(p, "u_seabed");
    r->l_eye_depth = glGetUniformLocation(p, "u_eye_depth");
    r->l_size = glGetUniformLocation(p, "u_size");
    r->l_tmax = glGetUniformLocation(p, "u_tmax");
    if ((st = gr_gl_check("light_rays setup", err)) != GR_OK) goto fail;
    *state = r;
    return GR_OK;
fail:
    lr_destroy(r);
    return st;
}

/* The sun's view of the surface: position and normal (RGBA32F) and a depth buffer, n x n. */
static gr_status ensure_surface(lr_state *r, int n, gr_error *err)
{
    if (r->surf_fbo && r->surf_n == n) return GR_OK;
    if (r->surf_fbo) glDeleteFramebuffers(1, &r->surf_fbo);
    if (r->surf_tex[0]) glDeleteTextures(2, r->surf_tex);
    if (r->surf_depth) glDeleteTextures(1, &r->surf_depth);
    r->surf_fbo = r->surf_depth = r->surf_tex[0] = r->surf_tex[1] = 0;
    r->surf_n = 0;
    glGenTextures(2, r->surf_tex);
    for (int i = 0; i < 2; i++) {
        glBindTexture(GL_TEXTURE_2D, r->surf_tex[i]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, n, n);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glGenTextures(1, &r->surf_depth);
    glBindTexture(GL_TEXTURE_2D, r->surf_depth);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, n, n);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &r->surf_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, r->surf_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->surf_tex[0], 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, r->surf_tex[1], 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, r->surf_depth, 0);
    const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, bufs);
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (fs != GL_FRAMEBUFFER_COMPLETE)
        return gr_fail(err, GR_E_GL, "light_rays.rays: surface target %dx%d incomplete", n, n);
    r->surf_n = n;
    return gr_gl_check("light_rays.rays: surface target", err);
}

/* The light's window: the square (in the plane across the sun's direction I, frame e1, e2)
 * that holds the surface points whose refracted rays can reach the visible volume. Points of
 * the volume (rays through a 17 x 17 grid, 9 distances each, to the surface / seabed / far end)
 * are carried back up the flat refracted sun to the rest plane and projected along I; the
 * waves' displacement and tilt widen it by a margin. All eye-relative. */
typedef struct lr_window {
    double c[3], e1[3], e2[3];
    double half_m;   /* the window's half side */
    double mesh_m;   /* the grid's half side (covers the window after displacement) */
    double zr;       /* depth half range along I */
} lr_window;

static void make_window(const gr_scene *scene, const gr_frame *f, const gr_light_rays_settings *s, double t_max,
                        lr_window *w)
{
    const double *I = f->sun_dir, *T = f->refr_dir;
    double a[3] = {0, 1, 0};
    if (fabs(I[1]) > 0.9) a[0] = 1, a[1] = 0;
    double e1[3] = {I[1] * a[2] - I[2] * a[1], I[2] * a[0] - I[0] * a[2], I[0] * a[1] - I[1] * a[0]};
    double n1 = sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; k++) e1[k] /= n1;
    double e2[3] = {I[1] * e1[2] - I[2] * e1[1], I[2] * e1[0] - I[0] * e1[2], I[0] * e1[1] - I[1] * e1[0]};
    double rest = f->rest_height_m - f->eye[1], mu = -T[1];
    double rot[16], ip[16];
    gr_frame_view_proj_rot(f, rot);
    int have_inv = gr_mat4_inverse(rot, ip) == 0;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300}, dmax = 0.0;
    for (int j = 0; j <= 16; j++)
        for (int i = 0; i <= 16; i++) {
            double dir[3] = {f->forward[0], f->forward[1], f->forward[2]};
            if (have_inv) {
                double clip[4] = {-1.0 + i / 8.0, -1.0 + j / 8.0, 1.0, 1.0}, q[4];
                gr_mat4_apply(ip, clip, q);
                double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                for (int k = 0; k < 3; k++) dir[k] = q[k] / n;
            }
            double tend = t_max;
            if (dir[1] > 1e-9) tend = fmin(tend, rest / dir[1]);
            if (scene->has_seabed && dir[1] < -1e-9) tend = fmin(tend, (f->seabed_y - f->eye[1]) / dir[1]);
            for (int m = 0; m <= 8; m++) {
                double t = tend * m / 8.0, x[3] = {dir[0] * t, dir[1] * t, dir[2] * t};
                double d = rest - x[1]; /* depth below the rest height */
                if (d < 0) d = 0;
                if (d / mu > s->max_length_m) continue; /* no line reaches it */
                if (d > dmax) dmax = d;
                double xs[3] = {x[0] - T[0] * d / mu, rest, x[2] - T[2] * d / mu};
                double u = xs[0] * e1[0] + xs[1] * e1[1] + xs[2] * e1[2];
                double v = xs[0] * e2[0] + xs[1] * e2[1] + xs[2] * e2[2];
                lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u);
                lo[1] = fmin(lo[1], v), hi[1] = fmax(hi[1], v);
            }
        }
    if (!(hi[0] >= lo[0])) lo[0] = hi[0] = lo[1] = hi[1] = 0.0;
    /* waves: displacement up to sum A (both ways), tilted rays drift by about slope (1 - 1/n)
     * per metre of depth */
    double amp = 0.0, slope = 0.0;
    for (int i = 0; i < scene->water.n_waves; i++) {
        amp += scene->water.waves[i].amplitude_m;
        slope += scene->water.waves[i].amplitude_m * f->waves_a[i][2];
    }
    double margin = s->margin_m + 2.0 * amp / fabs(I[1]) + fmin(slope, 1.0) * (1.0 - 1.0 / f->ior) * dmax / mu;
    double cu = 0.5 * (lo[0] + hi[0]), cv = 0.5 * (lo[1] + hi[1]);
    w->half_m = 0.5 * fmax(hi[0] - lo[0], hi[1] - lo[1]) + margin;
    if (!(w->half_m > 0.01)) w->half_m = 0.01;
    /* the centre: the rest-plane point whose projection along I is (cu, cv) */
    double q[3];
    for (int k = 0; k < 3; k++) q[k] = e1[k] * cu + e2[k] * cv;
    double t = (rest - q[1]) / I[1];
    for (int k = 0; k < 3; k++) {
        w->c[k] = q[k] + I[k] * t;
        w->e1[k] = e1[k];
        w->e2[k] = e2[k];
    }
    w->mesh_m = w->half_m + 2.0 * amp / fabs(I[1]) + 2.0 * amp;
    double horiz = sqrt(I[0] * I[0] + I[2] * I[2]) / fabs(I[1]);
    w->zr = 1.5 * w->mesh_m * horiz + 4.0 * (amp + 1.0) / fabs(I[1]);
}

enum { P_SURFACE = GR_VOL_PASS_CAUSTICS, P_LINES };

static gr_status lr_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                           gr_technique_stats *stats, gr_error *err)
{
    lr_state *r = state;
    const gr_light_rays_settings *s = settings;
    gr_vol_prep prep;
    gr_status st = gr_vol_prepare("light_rays", &r->base, scene, &s->vol, out, &prep, err);
    if (st != GR_OK) return st;
    const gr_frame *f = &prep.frame;
    int W = f->width, H = f->height, N = s->rays;
    if ((st = ensure_surface(r, N, err)) != GR_OK) return st;
    lr_window win;
    make_window(scene, f, s, prep.t_max, &win);
    int cells = (int)ceil(N * win.mesh_m / win.half_m);
    if (cells > MAX_CELLS) cells = MAX_CELLS;

    /* pass 1: the surface from the sun */
    float wa[GR_MAX_WAVES * 4], wamp[GR_MAX_WAVES];
    gr_vol_waves(scene, f, f->eye[0], f->eye[2], wa, wamp); /* phases relative to the eye */
    gr_gl_timer_begin(&r->base.timer, P_SURFACE);
    glBindFramebuffer(GL_FRAMEBUFFER, r->surf_fbo);
    glViewport(0, 0, N, N);
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(r->prog_surf);
    glUniform1i(r->s_cells, cells);
    glUniform1f(r->s_half, (float)win.mesh_m);
    glUniform1f(r->s_win, (float)win.half_m);
    glUniform1f(r->s_zr, (float)win.zr);
    glUniform3f(r->s_c, (float)win.c[0], (float)win.c[1], (float)win.c[2]);
    glUniform3f(r->s_e1, (float)win.e1[0], (float)win.e1[1], (float)win.e1[2]);
    glUniform3f(r->s_e2, (float)win.e2[0], (float)win.e2[1], (float)win.e2[2]);
    glUniform3f(r->s_sun, (float)f->sun_dir[0], (float)f->sun_dir[1], (float)f->sun_dir[2]);
    glUniform1i(r->s_nw, scene->water.n_waves);
    glUniform4fv(r->s_wa, GR_MAX_WAVES, wa);
    glUniform1fv(r->s_wamp, GR_MAX_WAVES, wamp);
    glBindVertexArray(r->base.vao);
    glDrawArrays(GL_TRIANGLES, 0, cells * cells * 6);
    glDisable(GL_DEPTH_TEST);
    gr_gl_timer_end(&r->base.timer);

    /* pass 2: one ribbon per texel into the eye's view, additive */
    double rot[16], inv[16];
    gr_frame_view_proj_rot(f, rot);
    if (gr_mat4_inverse(rot, inv) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");
    float m[16], mi[16];
    gr_frame_matf(rot, m);
    gr_frame_matf(inv, mi);
    double texel = 2.0 * win.half_m / N, h[2][3];
    /* the texel's edges carried along the sun to the rest plane: h = a - I a.y / I.y */
    for (int k = 0; k < 3; k++) {
        h[0][k] = texel * (win.e1[k] - f->sun_dir[k] * win.e1[1] / f->sun_dir[1]);
        h[1][k] = texel * (win.e2[k] - f->sun_dir[k] * win.e2[1] / f->sun_dir[1]);
    }
    gr_gl_timer_begin(&r->base.timer, P_LINES);
    gr_target_accumulate(&r->base.out); /* W x H */
    glUseProgram(r->prog_lines);
    gr_vol_set(&r->vl, &prep.in);
    glUniform1i(r->l_pos, 5);
    glUniform1i(r->l_nrm, 6);
    glUniform1i(r->l_rays, N);
    glUniformMatrix4fv(r->l_vp, 1, GL_FALSE, m);
    glUniform3f(r->l_sun, (float)f->sun_dir[0], (float)f->sun_dir[1], (float)f->sun_dir[2]);
    glUniform1f(r->l_ior, (float)f->ior);
    glUniform1f(r->l_area, (float)(texel * texel));
    glUniform1i(r->l_footprint, s->footprint);
    glUniform1f(r->l_kernel, (float)s->kernel);
    glUniform3f(r->l_h1, (float)h[0][0], (float)h[0][1], (float)h[0][2]);
    glUniform3f(r->l_h2, (float)h[1][0], (float)h[1][1], (float)h[1][2]);
    glUniformMatrix4fv(r->l_inv, 1, GL_FALSE, mi);
    glUniform1f(r->l_pix, (float)(2.0 * tan(0.5 * f->fov_y_rad) / H));
    glUniform1f(r->l_width, (float)s->line_width);
    glUniform1f(r->l_max, (float)s->max_length_m);
    glUniform1f(r->l_seabed, scene->has_seabed ? (float)(f->seabed_y - f->eye[1]) : -1e30f);
    glUniform1i(r->l_eye_depth, 1);
    glUniform2f(r->l_size, (float)W, (float)H);
    glUniform1f(r->l_tmax, (float)prep.t_max);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, prep.depth_tex);
    glActiveTexture(GL_TEXTURE5);
    glBindTexture(GL_TEXTURE_2D, r->surf_tex[0]);
    glActiveTexture(GL_TEXTURE6);
    glBindTexture(GL_TEXTURE_2D, r->surf_tex[1]);
    glActiveTexture(GL_TEXTURE0);
    glBeginQuery(GL_SAMPLES_PASSED, r->base.q_samples);
    glDrawArrays(GL_POINTS, 0, N * N);
    glEndQuery(GL_SAMPLES_PASSED);
    glDisable(GL_BLEND);
    gr_gl_timer_end(&r->base.timer);
    glBindVertexArray(0);
    glUseProgram(0);
    r->n_rays = N;
    r->window_m = 2.0 * win.half_m;
    static const char *const names[4] = {"shadow", "eye_depth", "surface", "lines"};
    st = gr_vol_finish("light_rays", &r->base, &prep, out, names, 4, stats, err);
    if (stats) {
        /* surface: cells^2 quads into two RGBA32F targets and a DEPTH32F buffer, N x N, cleared
         * then written (each texel at least once); lines: N^2 points, the vertex stage fetching
         * 2 texels each; a kept fragment (queried) takes the eye-depth tap and blends one
         * RGBA32F texel after the clear (the shadow taps are the geometry stage's, per line) */
        const long long nn = (long long)N * N, frag = stats->fragments;
        gr_pass_cost c;
        gr_pass_cost_clear(&c);
        c.v[GR_COST_VERTICES] = 6LL * cells * cells;
        c.v[GR_COST_TAPS] = 0;
        c.v[GR_COST_BYTES] = nn * (16 + 16 + 4) * 2;
        c.v[GR_COST_INVOCATIONS] = 0;
        gr_vol_cost_pass(stats, P_SURFACE, &c);
        c.v[GR_COST_FRAGMENTS] = frag;
        c.queried = 1u << GR_COST_FRAGMENTS;
        c.v[GR_COST_VERTICES] = nn;
        c.v[GR_COST_TAPS] = 2 * nn + frag;
        c.v[GR_COST_BYTES] = (long long)W * H * 16 + frag * 16;
        gr_vol_cost_pass(stats, P_LINES, &c);
    }
    return st;
}

static void lr_summary(void *state, const gr_technique_stats *stats, char *buf, size_t n)
{
    const lr_state *r = state;
    (void)stats;
    snprintf(buf, n, "%d x %d lines over a %.1f m window (%.1f cm a texel)", r->n_rays, r->n_rays, r->window_m,
             100.0 * r->window_m / (r->n_rays > 0 ? r->n_rays : 1));
}

static gr_status lr_metadata(void *state, const gr_scene *scene, const void *settings,
                             const gr_technique_stats *stats, gr_metadata *meta, gr_error *err)
{
    const lr_state *r = state;
    (void)scene, (void)settings, (void)stats;
    if (gr_meta_set_double(meta, "godrays:light_rays_window_m", r->window_m) != GR_OK ||
        gr_meta_set_int(meta, "godrays:light_rays_lines", (long long)r->n_rays * r->n_rays) != GR_OK)
        return gr_fail(err, GR_E_NOMEM, "light_rays: out of memory for the metadata");
    return GR_OK;
}

const gr_technique_class gr_light_rays_class = {
    .name = "light_rays",
    .description = "seed 001 after Hu et al. 2010: refracted sun rays as lines from the surface, additive",
    .params = &table,
    .settings_size = sizeof(gr_light_rays_settings),
    .origin = "built-in",
    .gain_key = "intensity",
    .ladder = ladder,
    .n_ladder = sizeof ladder / sizeof ladder[0],
    .tune_keys = "extinction,g", /* the attenuation and the phase: line_width is the ribbon's alone */
    .create = lr_create,
    .destroy = lr_destroy,
    .render = lr_render,
    .set_reuse = gr_vol_set_reuse,
    .metadata = lr_metadata,
    .summary = lr_summary,
};
