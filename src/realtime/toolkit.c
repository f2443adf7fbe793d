/* The technique toolkit (toolkit.h). */
#include "realtime/toolkit.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "gl/gl.h"
#include "core/optics.h"
#include "gl/glctx.h"
#include "realtime/shaders.h"

double gr_clock_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

/* ---- render targets ---------------------------------------------------------------------- */

void gr_target_release(gr_target *t)
{
    if (!t) return;
    if (t->fbo) glDeleteFramebuffers(1, &t->fbo);
    if (t->tex) glDeleteTextures(1, &t->tex);
    memset(t, 0, sizeof *t);
}

gr_status gr_target_ensure(gr_target *t, unsigned ifmt, int w, int h, int flags, const char *what, gr_error *err)
{
    if (t->tex && t->w == w && t->h == h && t->ifmt == ifmt) return GR_OK;
    gr_target_release(t);
    const int depth = (flags & GR_TARGET_DEPTH) != 0;
    const GLint filter = (flags & GR_TARGET_LINEAR) ? GL_LINEAR : GL_NEAREST;
    glGenTextures(1, &t->tex);
    glBindTexture(GL_TEXTURE_2D, t->tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, (GLenum)ifmt, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    if (depth || (flags & GR_TARGET_BLACK_BORDER)) {
        /* A shadow map stores nothing outside: border depth 1 = no caster = lit. A light pass
         * reads black outside the screen: taps that leave it add nothing (an edge clamp would
         * smear the border texels into streaks). */
        static const float one[4] = {1.0f, 1.0f, 1.0f, 1.0f}, black[4] = {0, 0, 0, 0};
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
        glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, depth ? one : black);
    } else {
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    if (depth) glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &t->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    if (depth) {
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, t->tex, 0);
        glDrawBuffer(GL_NONE);
        glReadBuffer(GL_NONE);
    } else {
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->tex, 0);
    }
    GLenum fs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    gr_status st = fs == GL_FRAMEBUFFER_COMPLETE
                       ? gr_gl_check(what, err)
                       : gr_fail(err, GR_E_GL, "%s (%dx%d): framebuffer incomplete (0x%04x)", what, w, h, (unsigned)fs);
    if (st != GR_OK) {
        gr_target_release(t);
        return st;
    }
    t->w = w;
    t->h = h;
    t->ifmt = ifmt;
    return GR_OK;
}

void gr_target_accumulate(const gr_target *t)
{
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->w, t->h);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
}

/* ---- GPU pass timers --------------------------------------------------------------------- */

void gr_gl_timer_init(gr_gl_timer *t)
{
    memset(t, 0, sizeof *t);
    glGenQueries(GR_GL_TIMER_PASSES, t->queries);
    glGenQueries(GR_GL_TIMER_PASSES, t->prims);
    t->have_timer = 1; /* GL_TIME_ELAPSED is core since 3.3 */
}

void gr_gl_timer_reset(gr_gl_timer *t)
{
    t->used = 0;
    t->n = 0;
}

void gr_gl_timer_begin(gr_gl_timer *t, int pass)
{
    if (pass < 0 || pass >= GR_GL_TIMER_PASSES || !t->have_timer) return;
    glBeginQuery(GL_TIME_ELAPSED, t->queries[pass]);
    glBeginQuery(GL_PRIMITIVES_GENERATED, t->prims[pass]);
    if (pass + 1 > t->n) t->n = pass + 1;
    t->used |= 1u << pass;
}

void gr_gl_timer_end(gr_gl_timer *t)
{
    if (!t->have_timer) return;
    glEndQuery(GL_PRIMITIVES_GENERATED);
    glEndQuery(GL_TIME_ELAPSED);
}

long long gr_gl_timer_primitives(gr_gl_timer *t, int pass)
{
    if (!t->have_timer || pass < 0 || pass >= t->n || !(t->used & (1u << pass))) return -1;
    return gr_gl_query_result(t->prims[pass]);
}

long long gr_gl_query_result(unsigned query)
{
    GLuint64 v = 0;
    glGetQueryObjectui64v(query, GL_QUERY_RESULT, &v);
    return (long long)v;
}

long long gr_gl_timer_ns(gr_gl_timer *t, int pass)
{
    if (!t->have_timer || pass < 0 || pass >= t->n || !(t->used & (1u << pass))) return -1;
    return gr_gl_query_result(t->queries[pass]);
}

long long gr_gl_timer_ns_within(gr_gl_timer *t, int pass, double wall_ns)
{
    long long ns = gr_gl_timer_ns(t, pass);
    return (ns >= 0 && (double)ns <= wall_ns) ? ns : -1;
}

void gr_gl_timer_free(gr_gl_timer *t)
{
    if (t->queries[0]) glDeleteQueries(GR_GL_TIMER_PASSES, t->queries);
    if (t->prims[0]) glDeleteQueries(GR_GL_TIMER_PASSES, t->prims);
    memset(t, 0, sizeof *t);
}

void gr_gl_timer_stats(gr_technique_stats *stats, gr_gl_timer *t, const char *const *names, int n, double t0_ms)
{
    memset(stats, 0, sizeof *stats);
    const double wall_ns = (gr_clock_ms() - t0_ms) * 1e6;
    if (n > GR_TECH_MAX_PASSES) n = GR_TECH_MAX_PASSES;
    stats->n_passes = n;
    for (int p = 0; p < n; p++) {
        snprintf(stats->pass_names[p], sizeof stats->pass_names[p], "%s", names[p]);
        stats->gpu_ns[p] = gr_gl_timer_ns_within(t, p, wall_ns);
    }
    for (int p = 0; p < GR_TECH_MAX_PASSES; p++) gr_pass_cost_clear(&stats->cost[p]);
    for (int p = 0; p < n; p++) {
        long long prims = gr_gl_timer_primitives(t, p);
        if (prims >= 0) gr_technique_cost_set(stats, p, GR_COST_PRIMITIVES, prims, 1);
    }
    stats->fragments = -1;
    stats->wall_ms = gr_clock_ms() - t0_ms;
}

/* ---- the light a screen-space effect reads ------------------------------------------------- */

#define LIGHT_MAX_WAVE_GROUPS 16 /* u_waves[16 * 5] in seed_waves.glsl */

/* Seed 004's listing defaults (GLSL version) that the units are derived at
 * (docs/radial-blur.md "Units"). */
#define SEED_SAMPLES 100
#define SEED_DECAY 0.96815
#define SEED_EXPOSURE 0.2
#define SEED_SAMPLE_SCALE 0.4
#define SEED_WEIGHT 0.58767

gr_status gr_light_pass_init(gr_light_pass *lp, const char *shader_dir, gr_error *err)
{
    static const gr_shader_stage light[2] = {{GL_VERTEX_SHADER, {"radial_blur_screen.vert.glsl", NULL}},
                                             {GL_FRAGMENT_SHADER, {"seed_waves.glsl", "radial_blur_light.frag.glsl", NULL}}};
    memset(lp, 0, sizeof *lp);
    gr_status st = gr_shader_program_stages(shader_dir, light, 2, NULL, 0, &lp->prog, NULL, err);
    if (st != GR_OK) return st;
    GLuint p = lp->prog;
    lp->inv_vp_rot = glGetUniformLocation(p, "u_inv_vp_rot");
    lp->depth = glGetUniformLocation(p, "u_depth");
    lp->wave_groups = glGetUniformLocation(p, "u_wave_groups");
    lp->waves = glGetUniformLocation(p, "u_waves");
    lp->ior = glGetUniformLocation(p, "u_ior");
    lp->to_sun = glGetUniformLocation(p, "u_to_sun");
    lp->a0 = glGetUniformLocation(p, "u_a0");
    lp->extinction = glGetUniformLocation(p, "u_extinction");
    lp->t_flat = glGetUniformLocation(p, "u_t_flat");
    lp->threshold = glGetUniformLocation(p, "u_threshold");
    lp->occluders = glGetUniformLocation(p, "u_occluders");
    lp->eye_depth = glGetUniformLocation(p, "u_eye_depth");
    lp->dither8 = glGetUniformLocation(p, "u_dither8");
    glGenVertexArrays(1, &lp->vao);
    return gr_gl_check("light pass setup", err);
}

void gr_light_pass_free(gr_light_pass *lp)
{
    if (!lp) return;
    if (lp->prog) glDeleteProgram(lp->prog);
    if (lp->vao) glDeleteVertexArrays(1, &lp->vao);
    memset(lp, 0, sizeof *lp);
}

gr_status gr_light_pass_draw(gr_light_pass *lp, const gr_scene *scene, const gr_frame *f, const gr_light_params *p,
                             const gr_target *t, unsigned depth_tex, const char *who, gr_error *err)
{
    double depth = scene->water.rest_height_m - f->eye[1];
    if (!(depth > 0))
        return gr_fail(err, GR_E_INPUT,
                       "camera.position_m: y = %g is not below the water surface (y = %g); %s needs an underwater viewer",
                       f->eye[1], scene->water.rest_height_m, who);
    if (scene->water.n_waves > LIGHT_MAX_WAVE_GROUPS * 4)
        return gr_fail(err, GR_E_INPUT, "water.waves: %d waves, %s takes at most %d", scene->water.n_waves, who,
                       LIGHT_MAX_WAVE_GROUPS * 4);
    /* Waves in the seed's packing with wt folded to the eye (phase at eye-relative x0, z0). */
    float waves[LIGHT_MAX_WAVE_GROUPS * 5 * 4];
    memset(waves, 0, sizeof waves);
    for (int i = 0; i < scene->water.n_waves; i++) {
        const gr_wave *wv = &scene->water.waves[i];
        int g = i / 4, lane = i % 4;
        double kx = wv->k * wv->dir[0], kz = wv->k * wv->dir[1];
        double c = fmod(wv->omega_rad_s * f->time_s - wv->phase_rad - kx * f->eye[0] - kz * f->eye[2], 2.0 * GR_PI);
        float *b = waves + (size_t)g * 20;
        b[0 * 4 + lane] = f->waves_seed[g * 5 + 0][lane];
        b[1 * 4 + lane] = f->waves_seed[g * 5 + 1][lane];
        b[2 * 4 + lane] = f->waves_seed[g * 5 + 2][lane];
        b[3 * 4 + lane] = f->waves_seed[g * 5 + 3][lane];
        b[4 * 4 + lane] = (float)c;
    }
    double vp_rot[16], inv_rot[16];
    float m[16];
    gr_frame_view_proj_rot(f, vp_rot);
    if (gr_mat4_inverse(vp_rot, inv_rot) != 0) return gr_fail(err, GR_E_INPUT, "camera: singular view-projection");

    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glViewport(0, 0, t->w, t->h);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_DITHER);
    glUseProgram(lp->prog);
    gr_frame_matf(inv_rot, m);
    glUniformMatrix4fv(lp->inv_vp_rot, 1, GL_FALSE, m);
    glUniform1f(lp->depth, (float)depth);
    glUniform1i(lp->wave_groups, f->n_wave_groups);
    glUniform4fv(lp->waves, LIGHT_MAX_WAVE_GROUPS * 5, waves);
    glUniform1f(lp->ior, (float)f->ior);
    glUniform3f(lp->to_sun, (float)f->to_sun[0], (float)f->to_sun[1], (float)f->to_sun[2]);
    glUniform1f(lp->a0, (float)(p->radius_deg * GR_PI / 180.0));
    glUniform3f(lp->extinction, (float)f->extinction[0], (float)f->extinction[1], (float)f->extinction[2]);
    glUniform1f(lp->t_flat, (float)f->transmittance_flat);
    glUniform1f(lp->threshold, (float)p->threshold);
    glUniform1i(lp->occluders, p->occluders);
    glUniform1i(lp->eye_depth, 1);
    glUniform1i(lp->dither8, p->dither8);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, depth_tex);
    glActiveTexture(GL_TEXTURE0);
    glBindVertexArray(lp->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    return GR_OK;
}

double gr_light_blur_gain(int samples, double decay, double weight)
{
    /* sum_{i=1..N} decay^(i-1) = (1 - decay^N) / (1 - decay) */
    double geo = decay == 1.0 ? (double)samples : (1.0 - pow(decay, samples)) / (1.0 - decay);
    return 1.0 + weight * geo;
}

double gr_light_kernel_solid_angle(double a0)
{
    /* 2 pi int_0^a0 (1 - (a/a0)^2)^2 sin a da, Simpson with 512 intervals. */
    const int n = 512;
    double h = a0 / n, sum = 0.0;
    for (int i = 0; i <= n; i++) {
        double a = i * h, x = a / a0, k = (1.0 - x * x) * (1.0 - x * x) * sin(a);
        sum += (i == 0 || i == n) ? k : (i % 2 ? 4.0 * k : 2.0 * k);
    }
    return 2.0 * GR_PI * sum * h / 3.0;
}

void gr_light_radiance(const gr_frame *f, double radius_deg, double out[3])
{
    double omega = gr_light_kernel_solid_angle(radius_deg * GR_PI / 180.0);
    for (int c = 0; c < 3; c++) out[c] = f->ior * f->ior * f->transmittance_flat * f->sun_irradiance[c] / omega;
}

/* Distance D from the eye to the flat surface along the refracted sun (m); <= 0 above it. */
static double sun_path_m(const gr_scene *scene, const gr_frame *f)
{
    double depth = scene->water.rest_height_m - scene->camera.position_m[1];
    return f->to_refr_sun[1] > 0 ? depth / f->to_refr_sun[1] : 0.0;
}

void gr_light_units(const gr_scene *scene, const gr_frame *f, double radius_deg, const double intensity[3],
                    double exposure, double sample_scale, double fade, double out[3])
{
    /* Looking straight at the refracted sun through flat water, with seed 004's defaults, the
     * layer equals the single-scattering closed form sigma_s p_HG(0) T E D exp(-sigma_t D)
     * (docs/radial-blur.md "Units"); the products keep radial_blur's order (its bytes). */
    double D = fmax(sun_path_m(scene, f), 0.0);
    double omega = gr_light_kernel_solid_angle(radius_deg * GR_PI / 180.0);
    double g_seed = gr_light_blur_gain(SEED_SAMPLES, SEED_DECAY, SEED_WEIGHT);
    double n = scene->medium.ior;
    for (int c = 0; c < 3; c++) {
        double k = scene->medium.scattering[c] * gr_hg_phase(1.0, scene->medium.g) * D * omega /
                   (n * n * SEED_EXPOSURE * SEED_SAMPLE_SCALE * g_seed);
        out[c] = k * intensity[c] * exposure * sample_scale * f->ior * f->ior * f->transmittance_flat *
                 f->sun_irradiance[c] / omega * fade;
    }
}
