/* Seed 004's volumetric light scattering as a post-process (GPU Gems 3 ch. 13, Mitchell),
 * underwater, and seed 003's localized variant, as techniques of the harness (technique.h):
 *
 *   radial_blur        light pass (the refracted sun seen through the Gerstner surface inside
 *                      Snell's window, occluders black, into a reduced target), then
 *                      NUM_SAMPLES taps toward the refracted sun's screen position weighted
 *                      by weight decay^i, spaced by density, times exposure; faded out when
 *                      the refracted sun leaves the screen or goes behind the camera.
 *   radial_blur_local  the same light pass; its brightest cells become "lights"; one screen
 *                      quad per light with a falloff to its edge, all in one draw, each
 *                      blurring toward its own light.
 *
 * Derivations and every decision: docs/radial-blur.md. */
#ifndef GR_RADIAL_BLUR_H
#define GR_RADIAL_BLUR_H

#include "common/status.h"
#include "image/image.h"
#include "realtime/technique.h"

typedef enum gr_rb_format { GR_RB_RGBA16F = 0, GR_RB_RGBA8 = 1 } gr_rb_format;

/* Settings of both classes (each class's table lists its own keys; the local-only fields
 * are unused by radial_blur). */
typedef struct gr_radial_blur_settings {
    /* GPU Gems 3 ch. 13 / seed 004's listing */
    int samples;             /* NUM_SAMPLES (100) */
    double decay;            /* 0.96815 */
    double exposure;         /* 0.2 */
    double density;          /* 0.926 */
    double weight;           /* 0.58767 */
    double sample_scale;     /* the listing's "* 0.4" on every sample */
    /* light pass */
    double target_scale;     /* light target size / frame size, per axis */
    int target_format;       /* gr_rb_format */
    double light_radius_deg; /* angular radius (in air) of the bright region around the sun */
    double threshold;        /* subtracted from the normalized light pass (1 = flat-water peak) */
    int occluders;           /* draw the occluders black in the light pass */
    /* output */
    double intensity[3];     /* factor on the derived scale to the ground truth's units (1) */
    int dither;              /* per-pixel jitter of the march (and of 8-bit storage) vs banding */
    double fade_margin;      /* NDC beyond the screen edge over which the rays fade out */
    double blur_scale;       /* radial_blur: blur target size / frame size (1: the blur at full size) */
    /* radial_blur_local */
    int lights;              /* at most this many lights (quads) */
    double quad_size;        /* quad half-size as a fraction of the frame height */
    double falloff;          /* (1 - r)^falloff to the quad's edge: 1 linear, 2 quadratic */
    double cell_size;        /* light-selection cell side / frame height */
    double min_fraction;     /* cells dimmer than this fraction of the brightest are no light */
    int normalize_overlap;   /* divide by the summed falloff where quads overlap (> 1) */
} gr_radial_blur_settings;

extern const gr_technique_class gr_radial_blur_class;
extern const gr_technique_class gr_radial_blur_local_class;
extern const gr_param_table gr_radial_blur_param_table;
extern const gr_param_table gr_radial_blur_local_param_table;

/* The listing's gain on a uniform light pass: 1 + weight (1 - decay^N) / (1 - decay)
 * (N samples; decay = 1 gives 1 + weight N). */
double gr_radial_blur_gain(int samples, double decay, double weight);
/* Fade of the rays with the refracted sun's screen position (docs/radial-blur.md, "Fade"):
 * 0 behind the camera (clip_w <= 0); else with e = max(|ndc.x|, |ndc.y|), 1 for e <= 1,
 * 1 - smoothstep(1, 1 + margin, e) beyond (0 beyond the margin; a step at the edge for
 * margin 0). */
double gr_radial_blur_fade(const double ndc[2], double clip_w, double margin);
/* Effective solid angle of the light pass kernel K(a) = (1 - (a/a0)^2)^2, a < a0:
 * (integral of K over the sphere) / K(0), by Simpson's rule in double. */
double gr_radial_blur_kernel_solid_angle(double a0_rad);

/* For tests: runs the blur pass alone on an injected light texture (RGBA, top row first,
 * any size; stored as RGBA32F with the target's bilinear filtering and black border) toward
 * sun_uv (GL uv, y up), with s's samples, decay, density, weight and dither, multiplied by
 * scale[3]; writes R, G, B of out (any size, its pixels' uv are (x + 0.5) / w, 1 - (y + 0.5) / h).
 * state: from the class's create. */
gr_status gr_radial_blur_blur_image(void *state, const gr_image *light, const double sun_uv[2],
                                    const gr_radial_blur_settings *s, const double scale[3], gr_image *out,
                                    gr_error *err);

/* For tests and metadata: the lights radial_blur_local chose in its last render (uv, GL
 * convention), at most max; returns the count. */
int gr_radial_blur_local_lights(void *state, double (*uv)[2], int max);

#endif
