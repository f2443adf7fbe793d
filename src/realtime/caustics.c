/* Seed 002's caustic texture on the GPU (caustics.h; docs/volume-techniques.md). */
#include "realtime/caustics.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/optics.h"
#include "gl/gl.h"
#include "gl/glctx.h"
#include "realtime/readback.h"
#include "realtime/shaders.h"

struct gr_caustics {
    GLuint prog, vao, fbo, tex;
    int tex_size, tex_layers;
    GLint l_grid, l_L, l_nw, l_wa, l_wamp, l_sun, l_ior, l_fresnel, l_gL, l_plane, l_to_sun, l_texel;
    double origin[2];
    long long triangles;
};

/* ---- program builder ---------------------------------------------------------------------- */

/* ---- caustics ------------------------------------------------------------------------------ */

void gr_caustics_depths(int n, double first_m, double last_m, double *out)
{
    for (int i = 0; i < n; i++)
        out[i] = n == 1 ? first_m : first_m * pow(last_m / first_m, (double)i / (double)(n - 1));
}

gr_status gr_caustics_create(const char *shader_dir, gr_caustics **out, gr_error *err)
{
    *out = NULL;
    gr_caustics *c = calloc(1, sizeof *c);
    if (!c) return gr_fail(err, GR_E_NOMEM, "caustics: out of memory");
    const gr_shader_stage st3[3] = {{GL_VERTEX_SHADER, {"volume_version.glsl", "volume_surface.glsl", "caustics.vert.glsl", NULL}},
                                 {GL_GEOMETRY_SHADER, {"caustics.geom.glsl", NULL, NULL, NULL}},
                                 {GL_FRAGMENT_SHADER, {"caustics.frag.glsl", NULL, NULL, NULL}}};
    gr_status st = gr_shader_program_stages(shader_dir, st3, 3, NULL, 0, &c->prog, NULL, err);
    if (st != GR_OK) {
        free(c);
        return st;
    }
    GLuint p = c->prog;
    c->l_grid = glGetUniformLocation(p, "u_grid");
    c->l_L = glGetUniformLocation(p, "u_L");
    c->l_nw = glGetUniformLocation(p, "u_n_waves");
    c->l_wa = glGetUniformLocation(p, "u_wa");
    c->l_wamp = glGetUniformLocation(p, "u_wamp");
    c->l_sun = glGetUniformLocation(p, "u_sun_dir");
    c->l_ior = glGetUniformLocation(p, "u_ior");
    c->l_fresnel = glGetUniformLocation(p, "u_fresnel");
    c->l_plane = glGetUniformLocation(p, "u_plane_y");
    c->l_to_sun = glGetUniformLocation(p, "u_to_sun");
    c->l_texel = glGetUniformLocation(p, "u_texel");
    glGenVertexArrays(1, &c->vao);
    glGenFramebuffers(1, &c->fbo);
    *out = c;
    return gr_gl_check("caustics setup", err);
}

void gr_caustics_destroy(gr_caustics *c)
{
    if (!c) return;
    if (c->prog) glDeleteProgram(c->prog);
    if (c->vao) glDeleteVertexArrays(1, &c->vao);
    if (c->fbo) glDeleteFramebuffers(1, &c->fbo);
    if (c->tex) glDeleteTextures(1, &c->tex);
    free(c);
}

unsigned gr_caustics_texture(const gr_caustics *c) { return c->tex; }
long long gr_caustics_triangles(const gr_caustics *c) { return c->triangles; }
void gr_caustics_origin(const gr_caustics *c, double origin[2])
{
    origin[0] = c->origin[0];
    origin[1] = c->origin[1];
}

gr_status gr_caustics_build(gr_caustics *c, const gr_scene *scene, const gr_frame *f, const gr_caustics_params *p,
                            gr_error *err)
{
    if (p->n_depths < 1 || p->n_depths > GR_CAUSTICS_MAX_DEPTHS || p->size < 1 || p->grid < 1 || !(p->patch_m > 0))
        return gr_fail(err, GR_E_INPUT, "caustics: bad parameters (size %d, grid %d, %d depths, patch %g m)", p->size,
                       p->grid, p->n_depths, p->patch_m);
    int S2 = 2 * p->size;
    if (!c->tex || c->tex_size != p->size || c->tex_layers != p->n_depths) {
        if (c->tex) glDeleteTextures(1, &c->tex);
        glGenTextures(1, &c->tex);
        glBindTexture(GL_TEXTURE_2D_ARRAY, c->tex);
        /* the whole mip chain: level 1 is the 2x2 supersampled texture, the coarser ones
         * filter distant lookups (fragment shaders; compute shaders read level 1) */
        int levels = 1;
        while ((S2 >> levels) >= 1) levels++;
        glTexStorage3D(GL_TEXTURE_2D_ARRAY, levels, GL_R32F, S2, S2, p->n_depths);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_REPEAT);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
        c->tex_size = p->size;
        c->tex_layers = p->n_depths;
        gr_status st = gr_gl_check("caustics.texture_size: caustic texture", err);
        if (st != GR_OK) return st;
    }
    double L = p->patch_m;
    c->origin[0] = floor(f->eye[0] / L) * L;
    c->origin[1] = floor(f->eye[2] / L) * L;
    float wa[GR_MAX_WAVES * 4], wamp[GR_MAX_WAVES];
    gr_vol_waves(scene, f, c->origin[0], c->origin[1], wa, wamp);
    glBindTexture(GL_TEXTURE_2D_ARRAY, c->tex);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BASE_LEVEL, 0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    glUseProgram(c->prog);
    glUniform1i(c->l_grid, p->grid);
    glUniform1f(c->l_L, (float)L);
    glUniform1i(c->l_nw, scene->water.n_waves);
    glUniform4fv(c->l_wa, GR_MAX_WAVES, wa);
    glUniform1fv(c->l_wamp, GR_MAX_WAVES, wamp);
    glUniform3f(c->l_sun, (float)f->sun_dir[0], (float)f->sun_dir[1], (float)f->sun_dir[2]);
    glUniform3f(c->l_to_sun, (float)f->to_sun[0], (float)f->to_sun[1], (float)f->to_sun[2]);
    glUniform1f(c->l_ior, (float)f->ior);
    glUniform1i(c->l_fresnel, p->fresnel);
    glUniform1f(c->l_texel, (float)(L / S2));
    glBindVertexArray(c->vao);
    glBindFramebuffer(GL_FRAMEBUFFER, c->fbo);
    glViewport(0, 0, S2, S2);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glClearColor(0, 0, 0, 0);
    for (int d = 0; d < p->n_depths; d++) {
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, c->tex, 0, d);
        glClear(GL_COLOR_BUFFER_BIT);
        glUniform1f(c->l_plane, (float)-p->depths_m[d]);
        glDrawArrays(GL_TRIANGLES, 0, p->grid * p->grid * 6);
    }
    c->triangles = 2LL * p->grid * p->grid * p->n_depths;
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    /* 2x2 supersampling: level 1 is the box filter of level 0; sample from it. */
    glBindTexture(GL_TEXTURE_2D_ARRAY, c->tex);
    glGenerateMipmap(GL_TEXTURE_2D_ARRAY);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BASE_LEVEL, 1);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    return gr_gl_check("caustic texture build", err);
}

gr_status gr_caustics_read(gr_caustics *c, int layer, gr_image **out, gr_error *err)
{
    *out = NULL;
    if (!c->tex || layer < 0 || layer >= c->tex_layers)
        return gr_fail(err, GR_E_USAGE, "caustics: no layer %d to read", layer);
    int n = c->tex_size;
    static const char *const names[1] = {"Y"};
    gr_image *img = gr_image_create(n, n, 1, names);
    if (!img) return gr_fail(err, GR_E_NOMEM, "caustics: out of memory");
    glBindFramebuffer(GL_FRAMEBUFFER, c->fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, c->tex, 1, layer);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, n, n, GL_RED, GL_FLOAT, img->pixels);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, c->tex, 0, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    gr_status st = gr_gl_check("caustic texture readback", err);
    if (st != GR_OK) {
        gr_image_destroy(img);
        return st;
    }
    *out = img;
    return GR_OK;
}

/* ---- shared by the volume techniques ------------------------------------------------------ */

void gr_vol_locations(unsigned p, gr_vol_locs *l)
{
    l->caustics = glGetUniformLocation(p, "u_caustics");
    l->n_depths = glGetUniformLocation(p, "u_n_depths");
    l->cdepth = glGetUniformLocation(p, "u_cdepth");
    l->corigin = glGetUniformLocation(p, "u_corigin");
    l->patch = glGetUniformLocation(p, "u_patch");
    l->refr = glGetUniformLocation(p, "u_refr");
    l->rest = glGetUniformLocation(p, "u_rest");
    l->shadow = glGetUniformLocation(p, "u_shadow");
    l->light_vp = glGetUniformLocation(p, "u_light_vp");
    l->use_shadow = glGetUniformLocation(p, "u_use_shadow");
    l->sigma_t = glGetUniformLocation(p, "u_sigma_t");
    l->sigma_s = glGetUniformLocation(p, "u_sigma_s");
    l->g = glGetUniformLocation(p, "u_g");
    l->esun = glGetUniformLocation(p, "u_esun");
    l->texel = glGetUniformLocation(p, "u_texel");
    l->sun_rw = glGetUniformLocation(p, "u_sun_rw");
}

void gr_vol_set(const gr_vol_locs *l, const gr_vol_inputs *in)
{
    const gr_frame *f = in->f;
    if (in->caustics) {
        float d[GR_CAUSTICS_MAX_DEPTHS];
        for (int i = 0; i < in->cp->n_depths; i++) d[i] = (float)in->cp->depths_m[i];
        double o[2];
        gr_caustics_origin(in->caustics, o);
        glUniform1i(l->caustics, 2);
        glUniform1i(l->n_depths, in->cp->n_depths);
        glUniform1fv(l->cdepth, in->cp->n_depths, d);
        glUniform2f(l->corigin, (float)(o[0] - f->eye[0]), (float)(o[1] - f->eye[2]));
        glUniform1f(l->patch, (float)in->cp->patch_m);
    }
    glUniform3f(l->refr, (float)f->refr_dir[0], (float)f->refr_dir[1], (float)f->refr_dir[2]);
    glUniform1f(l->rest, (float)(f->rest_height_m - f->eye[1]));
    /* light_vp * translate(eye): eye-relative positions */
    double tr[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, f->eye[0], f->eye[1], f->eye[2], 1}, m[16];
    gr_mat4_mul(in->light_vp, tr, m);
    float mf[16];
    gr_frame_matf(m, mf);
    glUniformMatrix4fv(l->light_vp, 1, GL_FALSE, mf);
    glUniform1i(l->shadow, 3);
    glUniform1i(l->use_shadow, in->shadow_tex != 0);
    glUniform3f(l->sigma_t, (float)in->sigma_t[0], (float)in->sigma_t[1], (float)in->sigma_t[2]);
    glUniform3f(l->sigma_s, (float)in->sigma_s[0], (float)in->sigma_s[1], (float)in->sigma_s[2]);
    glUniform1f(l->g, (float)in->g);
    glUniform3f(l->esun, (float)(f->sun_irradiance[0] * in->gain[0]), (float)(f->sun_irradiance[1] * in->gain[1]),
                (float)(f->sun_irradiance[2] * in->gain[2]));
    if (in->caustics) glUniform1f(l->texel, (float)(in->cp->patch_m / in->cp->size));
    /* the disc seen from below: Snell's law shrinks its angular radius to asin(sin(r) / n) */
    glUniform1f(l->sun_rw, in->sun_disc ? (float)asin(sin(f->sun_angular_radius_rad) / f->ior) : 0.0f);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D_ARRAY, in->caustics ? gr_caustics_texture(in->caustics) : 0);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, in->shadow_tex);
    glActiveTexture(GL_TEXTURE0);
}

double gr_vol_t_max(const gr_scene *scene)
{
    double smin = fmin(scene->medium.extinction[0], fmin(scene->medium.extinction[1], scene->medium.extinction[2]));
    double t = scene->reference.max_distance_m;
    if (smin > 0) t = fmin(t, -log(scene->reference.transmittance_cutoff) / smin);
    return t;
}

double gr_vol_far_depth(const gr_scene *scene, const gr_frame *f, double t_max)
{
    double far = 0.0;
    for (int j = 0; j <= 16; j++)
        for (int i = 0; i <= 16; i++) {
            double clip[4] = {-1.0 + i / 8.0, -1.0 + j / 8.0, 1.0, 1.0}, w[4], ip[16];
            if (gr_mat4_inverse(f->view_proj, ip) != 0) return t_max;
            double rot[16];
            gr_frame_view_proj_rot(f, rot);
            gr_mat4_inverse(rot, ip);
            gr_mat4_apply(ip, clip, w);
            double n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
            double dir[3] = {w[0] / n, w[1] / n, w[2] / n};
            double t = t_max;
            if (dir[1] > 1e-9) t = fmin(t, (f->rest_height_m - f->eye[1]) / dir[1]);
            if (scene->has_seabed && dir[1] < -1e-9) t = fmin(t, (f->seabed_y - f->eye[1]) / dir[1]);
            double z = t * (dir[0] * f->forward[0] + dir[1] * f->forward[1] + dir[2] * f->forward[2]);
            if (z > far) far = z;
        }
    return far > 0 ? far : t_max;
}

void gr_vol_bounds(int n, int exponential, double near_m, double far_m, double *b)
{
    b[0] = 0.0;
    if (near_m >= far_m) near_m = 0.5 * far_m;
    for (int i = 1; i <= n; i++)
        b[i] = exponential ? near_m * pow(far_m / near_m, (double)(i - 1) / (double)(n - 1 > 0 ? n - 1 : 1))
                           : far_m * i / n;
    if (exponential && n == 1) b[1] = far_m;
}

gr_status gr_vol_readback(unsigned fbo, int w, int h, gr_image *out, const char *what, gr_error *err)
{
    gr_readback rb = {0};
    gr_status st = gr_readback_fbo(&rb, fbo, w, h, what, err);
    if (st == GR_OK) gr_readback_to_rgb(&rb, out); /* NaN/Inf: checked by the harness */
    gr_readback_free(&rb);
    return st;
}

/* ---- the prelude of a volume technique's render ------------------------------------------- */

double gr_vol_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

void gr_vol_waves(const gr_scene *scene, const gr_frame *f, double ox, double oz, float *wa, float *wamp)
{
    memset(wa, 0, GR_MAX_WAVES * 4 * sizeof *wa);
    memset(wamp, 0, GR_MAX_WAVES * sizeof *wamp);
    for (int i = 0; i < scene->water.n_waves; i++) {
        double dx = f->waves_a[i][0], dz = f->waves_a[i][1], k = f->waves_a[i][2];
        const gr_wave *w = &scene->water.waves[i];
        /* phase = k dir . (origin + x0) - w t + phi0 (seed eq. 5.5.7), the constant in double */
        double cst = fmod(k * (dx * ox + dz * oz) - w->omega_rad_s * f->time_s + w->phase_rad, 2.0 * GR_PI);
        wa[i * 4 + 0] = (float)dx;
        wa[i * 4 + 1] = (float)dz;
        wa[i * 4 + 2] = (float)k;
        wa[i * 4 + 3] = (float)cst;
        wamp[i] = (float)w->amplitude_m;
    }
}

gr_status gr_vol_base_init(gr_vol_base *b, gr_gl *gl, const char *dir, int with_caustics, gr_error *err)
{
    memset(b, 0, sizeof *b);
    b->gl = gl;
    gr_status st = gr_scenegl_create_dir(gl, dir, &b->sg, err);
    if (st == GR_OK && with_caustics) st = gr_caustics_create(dir, &b->caus, err);
    if (st != GR_OK) return st;
    glGenVertexArrays(1, &b->vao);
    glGenQueries(1, &b->q_samples);
    gr_gl_timer_init(&b->timer);
    return GR_OK;
}

int gr_vol_base_current(const gr_vol_base *b)
{
    return b->gl && gr_gl_make_current(b->gl, NULL) == GR_OK;
}

void gr_vol_base_release(gr_vol_base *b)
{
    if (gr_vol_base_current(b)) {
        if (b->vao) glDeleteVertexArrays(1, &b->vao);
        if (b->out_fbo) glDeleteFramebuffers(1, &b->out_fbo);
        if (b->out_tex) glDeleteTextures(1, &b->out_tex);
        if (b->q_samples) glDeleteQueries(1, &b->q_samples);
        gr_gl_timer_free(&b->timer);
    }
    gr_caustics_destroy(b->caus);
    gr_scenegl_destroy(b->sg);
    memset(b, 0, sizeof *b);
}

gr_status gr_vol_prepare(const char *name, gr_vol_base *b, const gr_scene *scene, const gr_vol_settings *s,
                         const gr_image *out, gr_vol_prep *p, gr_error *err)
{
    gr_gl *gl = b->gl;
    gr_scenegl *sg = b->sg;
    gr_caustics *caus = b->caus;
    gr_gl_timer *timer = &b->timer;
    memset(p, 0, sizeof *p);
    p->t0_ms = gr_vol_now_ms();
    gr_frame *f = &p->frame;
    gr_frame_init(scene, f);
    int W = f->width, H = f->height;
    gr_status st;
    if (out->width != W || out->height != H || gr_image_channel(out, "R") < 0 || gr_image_channel(out, "G") < 0 ||
        gr_image_channel(out, "B") < 0)
        return gr_fail(err, GR_E_INPUT, "%s: output image is %dx%d (needs %dx%d with R, G, B)", name, out->width,
                       out->height, W, H);
    if (!(f->rest_height_m - f->eye[1] > 0))
        return gr_fail(err, GR_E_INPUT,
                       "camera.position_m: y = %g is not below the water surface; %s needs an underwater viewer",
                       f->eye[1], name);
    if ((st = gr_gl_make_current(gl, err)) != GR_OK) return st;
    timer->used = 0;
    timer->n = 0;

    gr_vol_inputs *in = &p->in;
    gr_caustics_params *cp = &p->cp;
    if (caus) {
        cp->size = s->texture_size;
        cp->grid = s->grid;
        cp->patch_m = s->patch_m;
        cp->n_depths = s->caustic_depths;
        cp->fresnel = 1;
        gr_caustics_depths(cp->n_depths, s->caustic_first_m, s->caustic_last_m, cp->depths_m);
    }
    in->f = f;
    in->caustics = caus;
    in->cp = cp;
    if (scene->n_occluders > 0) {
        gr_gl_timer_begin(timer, GR_VOL_PASS_SHADOW);
        st = gr_scenegl_shadow_map(sg, scene, f, s->shadow_map_size, f->eye, s->shadow_extent_m, &in->shadow_tex,
                                   in->light_vp, err);
        gr_gl_timer_end(timer);
        if (st != GR_OK) return st;
    } else {
        for (int i = 0; i < 16; i++) in->light_vp[i] = i % 5 == 0;
    }
    gr_gl_timer_begin(timer, GR_VOL_PASS_DEPTH);
    st = gr_scenegl_eye_depth(sg, scene, f, W, H, &p->depth_tex, err);
    gr_gl_timer_end(timer);
    if (st != GR_OK) return st;
    if (caus) {
        gr_gl_timer_begin(timer, GR_VOL_PASS_CAUSTICS);
        st = gr_caustics_build(caus, scene, f, cp, err);
        gr_gl_timer_end(timer);
        if (st != GR_OK) return st;
    }
    for (int c = 0; c < 3; c++) {
        in->sigma_t[c] = s->extinction[c];
        in->sigma_s[c] = scene->medium.scattering[c];
        in->gain[c] = s->intensity[c];
    }
    in->g = s->g;
    in->sun_disc = s->sun_disc;
    p->t_max = gr_vol_t_max(scene);
    return GR_OK;
}

gr_status gr_vol_target(gr_vol_base *b, int w, int h, const char *name, gr_error *err)
{
    unsigned *tex = &b->out_tex, *fbo = &b->out_fbo;
    int *tw = &b->out_w, *th = &b->out_h;
    if (*tex && *tw == w && *th == h) return GR_OK;
    if (*fbo) glDeleteFramebuffers(1, fbo);
    if (*tex) glDeleteTextures(1, tex);
    *fbo = *tex = 0;
    *tw = *th = 0;
    glGenTextures(1, tex);
    glBindTexture(GL_TEXTURE_2D, *tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, w, h);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, *fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, *tex, 0);
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (fs != GL_FRAMEBUFFER_COMPLETE)
        return gr_fail(err, GR_E_GL, "camera.width/height: %s target %dx%d incomplete", name, w, h);
    *tw = w;
    *th = h;
    char what[64];
    snprintf(what, sizeof what, "%s target", name);
    return gr_gl_check(what, err);
}

void gr_vol_stats(gr_technique_stats *stats, gr_vol_base *b, const char *const *names, int n, double t0_ms)
{
    gr_gl_timer *timer = &b->timer;
    unsigned q_samples = b->q_samples;
    memset(stats, 0, sizeof *stats);
    double wall_ns = (gr_vol_now_ms() - t0_ms) * 1e6;
    stats->n_passes = n;
    for (int p = 0; p < n; p++) {
        snprintf(stats->pass_names[p], sizeof stats->pass_names[p], "%s", names[p]);
        long long ns = gr_gl_timer_ns(timer, p);
        stats->gpu_ns[p] = (ns >= 0 && (double)ns <= wall_ns) ? ns : -1;
    }
    stats->fragments = -1;
    if (q_samples) {
        GLuint64 k = 0;
        glGetQueryObjectui64v(q_samples, GL_QUERY_RESULT, &k);
        stats->fragments = (long long)k;
    }
    stats->wall_ms = gr_vol_now_ms() - t0_ms;
}
