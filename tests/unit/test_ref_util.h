/* Helpers shared by the ground-truth tests (tests/unit/test_ref_*.c): scenes from JSON
 * text, one-call renders, and the reduced-run switch. */
#ifndef GR_TEST_REF_UTIL_H
#define GR_TEST_REF_UTIL_H
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/optics.h"
#include "reference/beams.h"
#include "reference/integrator.h"
#include "reference/sums.h"
#include "scene/scene.h"

/* the default scene's waves and water (data/scenes/default.json), as JSON members */
#define REF_DEFAULT_WAVES                                                                                                         \
    "\"water\":{\"waves\":[{\"amplitude_m\":0.115,\"wavelength_m\":12,\"direction_deg\":40},"                         \
    "{\"amplitude_m\":0.079,\"wavelength_m\":9,\"direction_deg\":25,\"phase_rad\":1.3},"                              \
    "{\"amplitude_m\":0.056,\"wavelength_m\":7,\"direction_deg\":58,\"phase_rad\":2.9},"                              \
    "{\"amplitude_m\":0.044,\"wavelength_m\":5.5,\"direction_deg\":32,\"phase_rad\":4.4},"                            \
    "{\"amplitude_m\":0.029,\"wavelength_m\":4,\"direction_deg\":70,\"phase_rad\":0.7},"                              \
    "{\"amplitude_m\":0.028,\"wavelength_m\":2.4,\"direction_deg\":12,\"phase_rad\":3.6},"                            \
    "{\"amplitude_m\":0.019,\"wavelength_m\":1.6,\"direction_deg\":50,\"phase_rad\":5.5},"                            \
    "{\"amplitude_m\":0.012,\"wavelength_m\":1.0,\"direction_deg\":85,\"phase_rad\":2.2}]}"
#define REF_DEFAULT_MEDIUM "\"medium\":{\"absorption_per_m\":[0.342,0.0585,0.0212],\"scattering_per_m\":[0.041,0.049,0.062],\"g\":0.9}"

/* CI sets GODRAYS_TEST_REDUCED=1 for slow tests: a smaller variant that checks the same
 * property. GODRAYS_TEST_FULL=1 forces the full variant. */
static inline int ref_reduced(void)
{
    const char *f = getenv("GODRAYS_TEST_FULL"), *r = getenv("GODRAYS_TEST_REDUCED");
    if (f && *f == '1') return 0;
    return r && *r == '1';
}

/* Loads a scene from printf-formatted JSON; exits the test on failure (test code only). */
static inline gr_scene *ref_scene(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline gr_scene *ref_scene(const char *fmt, ...)
{
    char *json = malloc(1 << 16);
    gr_scene *s = malloc(sizeof *s);
    if (!json || !s) { fprintf(stderr, "out of memory\n"); exit(1); }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(json, 1 << 16, fmt, ap);
    va_end(ap);
    gr_error err = {GR_OK, ""};
    if (gr_scene_load_string(json, "test scene", NULL, 0, s, &err) != GR_OK) {
        fprintf(stderr, "scene failed to load: %s\n%s\n", err.msg, json);
        exit(1);
    }
    free(json);
    return s;
}

/* Loads a scene file with "key=value" overrides; exits the test on failure (test code only). */
static inline gr_scene *ref_scene_file(const char *path, const char *const *ov, int nov)
{
    gr_scene *s = malloc(sizeof *s);
    gr_error err = {GR_OK, ""};
    if (!s || gr_scene_load_file(path, ov, nov, s, &err) != GR_OK) {
        fprintf(stderr, "%s: %s\n", path, s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

/* Beam parameters for scene s's water, sun and medium, as a render sets them (the shear
 * along the flat-water refracted sun, exact Fresnel, the sun's 0.53-degree disc convolved),
 * over the square sheared region [-half, half]^2 down to y_min, pad 0.7 m, at surface_res
 * res, slabs of `slab_cells`, jitter 0.5; the caller sets the rest (test code only). */
static inline void ref_beam_params(const gr_scene *s, double half, double y_min, int res, double slab_cells,
                                   gr_beam_params *p)
{
    gr_dvec3 I0 = gr_d3_norm(gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]));
    gr_dvec3 T0 = gr_refract_d(I0, gr_d3(0, 1, 0), 1.0 / s->medium.ior);
    memset(p, 0, sizeof *p);
    p->water = &s->water;
    p->ior = s->medium.ior;
    p->fresnel = 1;
    p->sun_dir = I0;
    p->shear_x = T0.x / T0.y;
    p->shear_z = T0.z / T0.y;
    p->region.u0 = p->region.w0 = -half;
    p->region.u1 = p->region.w1 = half;
    p->region.y_min = y_min;
    p->pad_m = 0.7;
    p->res = res;
    p->jitter[0] = p->jitter[1] = 0.5;
    p->max_prims = (size_t)1 << 24;
    p->slab_cells = slab_cells;
    p->disc_radius = 0.5 * 0.53 * GR_PI / 180.0;
    p->disc_e1 = gr_d3_norm(gr_d3_cross(I0, gr_d3(0, 1, 0)));
    p->disc_e2 = gr_d3_cross(I0, p->disc_e1);
}

/* Renders s with options o (NULL = defaults, quiet); exits the test on failure. */
static inline void ref_render(const gr_scene *s, const gr_ref_options *o, gr_ref_result *res)
{
    gr_ref_options opt;
    if (o) opt = *o;
    else gr_ref_options_default(&opt);
    opt.progress = 0;
    gr_error err = {GR_OK, ""};
    gr_ref_renderer *r = NULL;
    if (gr_ref_create(s, &opt, &r, &err) != GR_OK || gr_ref_render(r, res, &err) != GR_OK) {
        fprintf(stderr, "render failed: %s\n", err.msg);
        exit(1);
    }
    gr_ref_destroy(r);
}
/* The RGB mean of batch b's pixel estimates over [x0, x1) x [y0, y1) (with keep_sums). */
static inline double ref_batch_region_mean(const gr_ref_sums *s, int b, int x0, int x1, int y0, int y1)
{
    double v = 0.0;
    int n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++, n++) {
            size_t p = (size_t)y * s->W + x;
            const double *q = s->sum + (p * s->B + b) * 3;
            v += (q[0] + q[1] + q[2]) / (3.0 * s->count[p * s->B + b]);
        }
    return n ? v / n : 0.0;
}

/* Two renders' batch values a[b], c[b] (b < B) paired: the mean of d_b = a_b - c_b in *mean,
 * its standard error in *se (batches independent: sd(d) / sqrt(B)), c's mean in *mean_c;
 * returns mean / se, Student t with B - 1 degrees of freedom when the two agree on average. */
static inline double ref_paired_t(const double *a, const double *c, int B, double *mean, double *se, double *mean_c)
{
    double m = 0.0, m2 = 0.0, f = 0.0;
    for (int b = 0; b < B; b++) {
        double d = a[b] - c[b];
        m += d;
        m2 += d * d;
        f += c[b];
    }
    m /= B;
    *mean = m;
    *mean_c = f / B;
    *se = sqrt(fmax(0.0, (m2 - B * m * m) / (B - 1)) / B);
    return *se > 0.0 ? m / *se : (m == 0.0 ? 0.0 : INFINITY);
}
#endif
