/* The technique toolkit: the GL plumbing every real-time technique (the built-ins and a
 * user's manifest) needs and used to copy: render targets (a texture with its framebuffer,
 * remade only when its size or format changes), the wall clock, GPU pass timers and the
 * stats filled from them. Reading a target back is realtime/readback.h; what the volume
 * techniques share is realtime/volume.h. Every GL call needs the owning context current. */
#ifndef GR_TOOLKIT_H
#define GR_TOOLKIT_H

#include "common/status.h"
#include "realtime/frame.h"
#include "realtime/technique.h"
#include "scene/scene.h"

/* ---- clock ----------------------------------------------------------------------------- */

/* Monotonic wall clock (ms, arbitrary origin): the wall time of a render. */
double gr_clock_ms(void);

/* ---- render targets -------------------------------------------------------------------- */

/* A 2D texture (one level) and a framebuffer with it attached; zero-initialize. */
typedef struct gr_target {
    unsigned tex, fbo;
    int w, h;          /* 0 x 0 until made */
    unsigned ifmt;     /* GL internal format it was made with */
} gr_target;

enum {
    /* depth attachment (no colour buffer), clamped to a border depth 1 ("no caster" for a
     * shadow map), compare mode off; else a colour attachment 0 */
    GR_TARGET_DEPTH = 1,
    GR_TARGET_LINEAR = 2,       /* GL_LINEAR filtering; else GL_NEAREST */
    GR_TARGET_BLACK_BORDER = 4, /* colour: reads black outside [0,1]^2; else clamped to the edge */
};

/* Makes t a w x h target of internal format ifmt with flags, unless it already is one of that
 * size and format (then nothing happens: the flags of one target must not change). `what`
 * names the target in errors (GR_E_GL: framebuffer incomplete; a GL error). On failure t is
 * left empty. Leaves framebuffer 0 and texture 0 bound. */
gr_status gr_target_ensure(gr_target *t, unsigned ifmt, int w, int h, int flags, const char *what, gr_error *err);
void gr_target_release(gr_target *t); /* deletes the GL objects; accepts NULL and an empty one */
/* The start of a pass that sums contributions into t: binds t's framebuffer with a viewport
 * of its size, clears it to zero and enables additive blending (GL_FUNC_ADD, ONE, ONE). */
void gr_target_accumulate(const gr_target *t);

/* ---- GPU pass timers ------------------------------------------------------------------- */

#define GR_GL_TIMER_PASSES 8

/* GPU pass timing: begin/end around a pass; results collected after the frame. Each pass
 * also counts its primitives (GL_PRIMITIVES_GENERATED, core since 3.0): the stats' queried
 * primitive counter (technique.h, "cost counters"). */
typedef struct gr_gl_timer {
    unsigned queries[GR_GL_TIMER_PASSES];
    unsigned prims[GR_GL_TIMER_PASSES]; /* GL_PRIMITIVES_GENERATED per pass */
    int n, have_timer;
    unsigned used;      /* bit p: pass p was timed in this frame */
} gr_gl_timer;
void gr_gl_timer_init(gr_gl_timer *t);            /* needs a current context */
void gr_gl_timer_reset(gr_gl_timer *t);           /* a new frame: no pass timed yet */
void gr_gl_timer_begin(gr_gl_timer *t, int pass); /* pass < GR_GL_TIMER_PASSES */
void gr_gl_timer_end(gr_gl_timer *t);
/* -1 if no timer or the pass was not timed. Waits for the result. On llvmpipe the first query
 * of a context may read ~1e12 ns: callers drop a figure longer than the frame's wall time
 * (gr_gl_timer_ns_within). */
long long gr_gl_timer_ns(gr_gl_timer *t, int pass);
/* The same, -1 also when longer than wall_ns: every pass ran within the render's wall time,
 * so a longer figure is a broken timer (llvmpipe's first query after context creation). */
long long gr_gl_timer_ns_within(gr_gl_timer *t, int pass, double wall_ns);
void gr_gl_timer_free(gr_gl_timer *t);            /* accepts one never initialized (zeroed) */

/* The result of a query object (GL_SAMPLES_PASSED, ...); waits for it. */
long long gr_gl_query_result(unsigned query);

/* Primitives pass `pass` generated (GL_PRIMITIVES_GENERATED); -1 if it was not timed. */
long long gr_gl_timer_primitives(gr_gl_timer *t, int pass);
/* Fills stats after a render that started at t0_ms (gr_clock_ms): n passes named names[p]
 * with t's times (gr_gl_timer_ns_within the wall time so far), fragments -1 (the caller sets
 * it), each pass's cost counters -1 but its queried primitives (the caller counts the rest),
 * wall_ms the time since t0_ms. */
void gr_gl_timer_stats(gr_technique_stats *stats, gr_gl_timer *t, const char *const *names, int n, double t0_ms);

/* ---- the light a screen-space effect reads ------------------------------------------------ */

/* The sky and sun seen through the wavy surface from the eye (docs/radial-blur.md "Light
 * pass"; docs/techniques.md "Harness textures"): per pixel of a target,
 *   s = T(d, N) / T_flat * K(angle(refract(d, -N, n), to_sun)) * exp(-sigma_t t) * V
 * dimensionless, 1 = the flat-water peak at the refracted sun (radiance: s times
 * gr_light_radiance), Snell's window and exact Fresnel included, occluders and the seabed
 * black (V). radial_blur's light pass and the user techniques' "light" input are this one
 * program. */
typedef struct gr_light_pass {
    unsigned prog, vao;
    int inv_vp_rot, depth, wave_groups, waves, ior, to_sun, a0, extinction, t_flat, threshold, occluders, eye_depth,
        dither8;
} gr_light_pass;

typedef struct gr_light_params {
    double radius_deg; /* angular radius in air of the bright kernel (1 - (a/a0)^2)^2 */
    double threshold;  /* subtracted from s (1 = the flat-water peak), then clamped at 0 */
    int occluders;     /* 1: occluders and the seabed black (needs the eye depth at the target's size) */
    int dither8;       /* +-half an 8-bit step of noise before 8-bit storage */
} gr_light_params;

/* Compiles the program in the current context (shader_dir: --shader-dir, may be NULL); zero
 * lp first. */
gr_status gr_light_pass_init(gr_light_pass *lp, const char *shader_dir, gr_error *err);
void gr_light_pass_free(gr_light_pass *lp); /* accepts NULL and one never initialized */
/* Draws s into t (its size), reading depth_tex (R32F eye depth at t's size, metres:
 * gr_scenegl_eye_depth) for the occluders. `who` names the caller in errors (GR_E_INPUT: the
 * camera not under the water, more waves than the shader takes, a singular view). Leaves
 * t's framebuffer bound, blending, depth test and dithering off. */
gr_status gr_light_pass_draw(gr_light_pass *lp, const gr_scene *scene, const gr_frame *f,
                             const gr_light_params *p, const gr_target *t, unsigned depth_tex, const char *who,
                             gr_error *err);
/* Effective solid angle (sr) of the kernel (1 - (a/a0)^2)^2 of radius a0 (rad). */
double gr_light_kernel_solid_angle(double a0);
/* Gain of a radial blur's taps: 1 + weight sum_{i=1..N} decay^(i-1). */
double gr_light_blur_gain(int samples, double decay, double weight);
/* Radiance (W m^-2 sr^-1, per channel) of s = 1: n^2 T_flat E_sun / Omega_eff(radius). */
void gr_light_radiance(const gr_frame *f, double radius_deg, double out[3]);
/* The factor that puts a radial blur of s into the ground truth's units (docs/radial-blur.md
 * "Units"): k_c intensity_c exposure sample_scale n^2 T_flat E_c / Omega_eff fade, with
 * k_c = sigma_s,c p_HG(0; g) D Omega_eff / (n^2 0.2 0.4 G_seed) (seed 004's exposure 0.2,
 * sample scale 0.4 and tap gain G_seed). With intensity 1, exposure 0.2, sample scale 0.4
 * and fade 1 it is sigma_s p_HG(0) D T_flat E / G_seed: the user techniques' u_light_units. */
void gr_light_units(const gr_scene *scene, const gr_frame *f, double radius_deg,
                    const double intensity[3], double exposure, double sample_scale, double fade, double out[3]);

#endif
