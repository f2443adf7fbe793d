/* What the volume techniques share (volume.h; docs/volume-techniques.md). */
#include "realtime/volume.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/optics.h"
#include "gl/gl.h"
#include "gl/glctx.h"

/* ---- shared by the volume techniques ------------------------------------------------------ */

void gr_vol_caustic_locations(unsigned p, gr_vol_caustic_locs *l)
{
    l->tex = glGetUniformLocation(p, "t_caustics");
    l->layers = glGetUniformLocation(p, "u_caustic_layers");
    l->depth = glGetUniformLocation(p, "u_caustic_depth");
    l->origin = glGetUniformLocation(p, "u_caustic_origin");
    l->patch = glGetUniformLocation(p, "u_caustic_patch");
    l->texel = glGetUniformLocation(p, "u_caustic_texel");
    l->sun_rw = glGetUniformLocation(p, "u_caustic_sun_rw");
}

void gr_vol_caustic_set(const gr_vol_caustic_locs *l, const gr_caustics *c, const gr_caustics_params *cp,
                        const gr_frame *f, int sun_disc, double frame_x, double frame_z, int unit)
{
    float d[GR_CAUSTICS_MAX_DEPTHS];
    for (int i = 0; i < cp->n_depths; i++) d[i] = (float)cp->depths_m[i];
    double o[2];
    gr_caustics_origin(c, o);
    glUniform1i(l->tex, unit);
    glUniform1i(l->layers, cp->n_depths);
    glUniform1fv(l->depth, cp->n_depths, d);
    glUniform2f(l->origin, (float)(o[0] - frame_x), (float)(o[1] - frame_z));
    glUniform1f(l->patch, (float)cp->patch_m);
    glUniform1f(l->texel, (float)(cp->patch_m / cp->size));
    /* the disc seen from below: Snell's law shrinks its angular radius to asin(sin(r) / n) */
    glUniform1f(l->sun_rw, sun_disc ? (float)asin(sin(f->sun_angular_radius_rad) / f->ior) : 0.0f);
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    glBindTexture(GL_TEXTURE_2D_ARRAY, gr_caustics_texture(c));
    glActiveTexture(GL_TEXTURE0);
}

void gr_vol_locations(unsigned p, gr_vol_locs *l)
{
    gr_vol_caustic_locations(p, &l->caus);
    l->refr = glGetUniformLocation(p, "u_refr");
    l->rest = glGetUniformLocation(p, "u_rest");
    l->shadow = glGetUniformLocation(p, "u_shadow");
    l->light_vp = glGetUniformLocation(p, "u_light_vp");
    l->use_shadow = glGetUniformLocation(p, "u_use_shadow");
    l->sigma_t = glGetUniformLocation(p, "u_sigma_t");
    l->sigma_s = glGetUniformLocation(p, "u_sigma_s");
    l->g = glGetUniformLocation(p, "u_g");
    l->esun = glGetUniformLocation(p, "u_esun");
}

void gr_vol_set(const gr_vol_locs *l, const gr_vol_inputs *in)
{
    const gr_frame *f = in->f;
    /* the stack on unit 2, its origin eye-relative */
    if (in->caustics) gr_vol_caustic_set(&l->caus, in->caustics, in->cp, f, in->sun_disc, f->eye[0], f->eye[2], 2);
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
    if (!in->caustics) {
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    }
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, in->shadow_tex);
    glActiveTexture(GL_TEXTURE0);
}

/* The volume techniques' far end: where the view's transmittance in the least attenuated
 * channel falls to 1e-3, as a fog volume's far plane would be set. A constant of these
 * techniques, not the ground truth's reference.transmittance_cutoff (an accuracy setting of
 * the truth, which bounds the integrand instead, docs/reference.md 1, and whose default fell
 * to 1e-4 on 2026-11-29): tightening the truth must not move or slow the techniques. */
#define VOL_FAR_TRANSMITTANCE 1e-3

double gr_vol_t_max(const gr_scene *scene)
{
    double smin = fmin(scene->medium.extinction[0], fmin(scene->medium.extinction[1], scene->medium.extinction[2]));
    double t = scene->reference.max_distance_m;
    if (smin > 0) t = fmin(t, -log(VOL_FAR_TRANSMITTANCE) / smin);
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

/* ---- the prelude of a volume technique's render ------------------------------------------- */

void gr_vol_caustics_params(const gr_vol_settings *s, gr_caustics_params *cp)
{
    memset(cp, 0, sizeof *cp);
    cp->size = s->texture_size;
    cp->grid = s->grid;
    cp->patch_m = s->patch_m;
    cp->n_depths = s->caustic_depths;
    cp->fresnel = 1;
    gr_caustics_depths(cp->n_depths, s->caustic_first_m, s->caustic_last_m, cp->depths_m);
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

void gr_vol_set_reuse(void *state, int on)
{
    gr_vol_base *b = state; /* the state's first member */
    if (b && b->caus) gr_caustics_set_reuse(b->caus, on);
}

void gr_vol_base_release(gr_vol_base *b)
{
    if (gr_vol_base_current(b)) {
        if (b->vao) glDeleteVertexArrays(1, &b->vao);
        gr_target_release(&b->out);
        if (b->q_samples) glDeleteQueries(1, &b->q_samples);
        gr_gl_timer_free(&b->timer);
    }
    gr_caustics_destroy(b->caus);
    gr_scenegl_destroy(b->sg);
    gr_readback_free(&b->rb);
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
    p->t0_ms = gr_clock_ms();
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
    gr_gl_timer_reset(timer);

    gr_vol_inputs *in = &p->in;
    gr_caustics_params *cp = &p->cp;
    if (caus) gr_vol_caustics_params(s, cp);
    in->f = f;
    in->caustics = caus;
    in->cp = cp;
    if (scene->n_occluders > 0) {
        gr_gl_timer_begin(timer, GR_VOL_PASS_SHADOW);
        st = gr_scenegl_shadow_map(sg, scene, f, s->shadow_map_size, f->eye, s->shadow_extent_m, &in->shadow_tex,
                                   in->light_vp, err);
        gr_gl_timer_end(timer);
        p->shadow_size = s->shadow_map_size;
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
    char what[64];
    snprintf(what, sizeof what, "camera.width/height: %s target", name);
    return gr_target_ensure(&b->out, GL_RGBA32F, W, H, 0, what, err);
}

gr_status gr_vol_finish(const char *name, gr_vol_base *b, const gr_vol_prep *p, gr_image *out,
                        const char *const *names, int n, gr_technique_stats *stats, gr_error *err)
{
    char what[64];
    snprintf(what, sizeof what, "%s readback", name);
    gr_status st = gr_readback_rgb(&b->rb, b->out.fbo, out, NULL, what, err);
    if (st != GR_OK) return st;
    if (stats) {
        gr_gl_timer_stats(stats, &b->timer, names, n, p->t0_ms);
        if (b->q_samples) stats->fragments = gr_gl_query_result(b->q_samples);
        gr_vol_cost_prelude(b, p, stats);
        stats->wall_ms = gr_clock_ms() - p->t0_ms;
    }
    return gr_image_check_finite(out, name, err);
}

void gr_vol_cost_pass(gr_technique_stats *stats, int p, const gr_pass_cost *c)
{
    if (p < 0 || p >= stats->n_passes) return;
    gr_pass_cost m = *c;
    const gr_pass_cost *q = &stats->cost[p];
    if ((q->queried & (1u << GR_COST_PRIMITIVES)) && !(m.queried & (1u << GR_COST_PRIMITIVES))) {
        m.v[GR_COST_PRIMITIVES] = q->v[GR_COST_PRIMITIVES];
        m.queried |= 1u << GR_COST_PRIMITIVES;
    }
    stats->cost[p] = m;
}

void gr_vol_cost_prelude(const gr_vol_base *b, const gr_vol_prep *p, gr_technique_stats *stats)
{
    gr_pass_cost c;
    gr_pass_cost_clear(&c);
    c.v[GR_COST_TAPS] = 0;
    c.v[GR_COST_INVOCATIONS] = 0;
    if (p->shadow_size > 0) {
        c.v[GR_COST_BYTES] = (long long)p->shadow_size * p->shadow_size * 4;
        gr_vol_cost_pass(stats, GR_VOL_PASS_SHADOW, &c);
    }
    c.v[GR_COST_BYTES] = (long long)p->frame.width * p->frame.height * 4;
    gr_vol_cost_pass(stats, GR_VOL_PASS_DEPTH, &c);
    if (b->caus) gr_vol_cost_caustics(stats, GR_VOL_PASS_CAUSTICS, b->caus);
}

void gr_vol_cost_caustics(gr_technique_stats *stats, int p, gr_caustics *c)
{
    if (p < 0 || p >= stats->n_passes) return;
    const gr_pass_cost *q = &stats->cost[p]; /* the timer's queried primitives of the build */
    if (q->queried & (1u << GR_COST_PRIMITIVES)) gr_caustics_note_primitives(c, q->v[GR_COST_PRIMITIVES]);
    gr_pass_cost m;
    gr_caustics_cost(c, &m);
    gr_vol_cost_pass(stats, p, &m);
}
