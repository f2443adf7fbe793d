/* An occluder removes the shafts behind it (along the refracted sun) and nothing else.
 * Same hand-checked setup as test_shafts_flat (sun at the zenith, flat water, one shaft
 * above a viewer looking straight up, caps on, float target):
 *  - a slab between the top cap (y = 0) and the bottom cap (y = -L) shadows the bottom
 *    cap's centre: the centre texel drops from top + bottom to top alone;
 *  - no texel gets brighter, and texels outside the slab's shadow keep their value;
 *  - the same slab below the whole shaft (between the shaft and the viewer) changes nothing:
 *    no shaft surface lies behind it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shafts_test.h"

#define SCENE_HEAD                                                                                              \
    "{\"name\": \"occluder\", \"water\": {\"waves\": []},"                                                      \
    "\"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 0},"                                                     \
    "\"medium\": {\"absorption_per_m\": [0.04, 0.07, 0.11], \"scattering_per_m\": 0.01, \"g\": 0.5},"           \
    "\"camera\": {\"position_m\": [0, -20, 0], \"yaw_deg\": 0, \"pitch_deg\": 90, \"fov_deg\": 60,"             \
    "\"width\": 161, \"height\": 91},"                                                                          \
    "\"shafts\": {\"N\": 2, \"K\": 0.8, \"shaft_length_m\": 10, \"target_format\": \"rgba16f\","    \
    "\"shaft_width\": 1, \"target_prescale\": 1},"

static const char *json_none = SCENE_HEAD "\"occluders\": []}";
static const char *json_between =
    SCENE_HEAD "\"occluders\": [{\"type\": \"box\", \"center_m\": [0, -5, 0], \"size_m\": [2, 0.5, 2]}]}";
static const char *json_below =
    SCENE_HEAD "\"occluders\": [{\"type\": \"box\", \"center_m\": [0, -15, 0], \"size_m\": [2, 0.5, 2]}]}";

int main(void)
{
    gr_shafts *r = shafts_test_renderer();
    gr_scene *s0 = shafts_test_scene(json_none, NULL, 0);
    gr_scene *s1 = shafts_test_scene(json_between, NULL, 0);
    gr_scene *s2 = shafts_test_scene(json_below, NULL, 0);
    gr_image *l0 = shafts_test_render(r, s0, NULL), *t0 = shafts_test_target(r);
    gr_image *l1 = shafts_test_render(r, s1, NULL), *t1 = shafts_test_target(r);
    gr_image *l2 = shafts_test_render(r, s2, NULL), *t2 = shafts_test_target(r);

    /* Hand values at the centre (see test_shafts_flat.c for the derivation). */
    const double d = 20.0, L = 10.0, fov = 60.0 * 3.14159265358979323846 / 180.0;
    const double S = 0.8 * 2.0 * d * tan(0.5 * fov) / 2.0, h = 0.5 * S, n = 1.333;
    const double r0 = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
    const double c[3] = {0.05, 0.08, 0.12};
    int cx = t0->width / 2, cy = t0->height / 2;
    const float *p0 = gr_image_pixel(t0, cx, cy), *p1 = gr_image_pixel(t1, cx, cy);
    for (int ch = 0; ch < 3; ch++) {
        double top = exp(-c[ch] * sqrt(2.0 * h * h + d * d)) * (1.0 - r0);
        double bot = exp(-c[ch] * (L + sqrt(2.0 * h * h + (d - L) * (d - L)))) * (1.0 - r0);
        printf("ch %d centre texel: no occluder %.5f (want %.5f), slab between caps %.5f (want %.5f)\n", ch, p0[ch],
               top + bot, p1[ch], top);
        CHECK_REL(p0[ch], top + bot, 3e-3);
        CHECK_REL(p1[ch], top, 3e-3);
    }
    CHECK_NEAR(p0[3], 2.0, 1e-6); /* two surfaces blended there either way */
    CHECK_NEAR(p1[3], 2.0, 1e-6);

    size_t nt = (size_t)t0->width * (size_t)t0->height, darker = 0, brighter = 0, changed_below = 0;
    for (size_t i = 0; i < nt; i++)
        for (int ch = 0; ch < 3; ch++) {
            float a = t0->pixels[i * 4 + ch], b = t1->pixels[i * 4 + ch], e = t2->pixels[i * 4 + ch];
            if (b < a - 1e-6f) darker++;
            if (b > a + 1e-6f) brighter++;
            if (e != a) changed_below++;
        }
    /* The slab's shadow on the bottom cap is the 2 m square |x|, |z| < 1 at 10 m from the
     * viewer: +-0.1 in tan units, and the target has (81/2) / tan(hfov/2) = (46/2) / tan(30 deg)
     * ~ 39.8 texels per tan unit, so ~8 x 8 texels (x 3 channels) get darker; nothing else. */
    double px_per_tan = 0.5 * t0->height / tan(0.5 * fov);
    double want_texels = (2.0 * 0.1 * px_per_tan) * (2.0 * 0.1 * px_per_tan);
    printf("slab between: %zu samples darker (expected ~%.0f), %zu brighter; slab below: %zu changed\n", darker,
           3.0 * want_texels, brighter, changed_below);
    CHECK(brighter == 0);
    CHECK((double)darker > 0.65 * 3.0 * want_texels);
    CHECK((double)darker < 1.35 * 3.0 * want_texels);
    CHECK(changed_below == 0);
    CHECK(memcmp(l0->pixels, l2->pixels, (size_t)l0->width * (size_t)l0->height * 3 * sizeof(float)) == 0);
    const float *c0 = gr_image_pixel(l0, l0->width / 2, l0->height / 2), *c1 = gr_image_pixel(l1, l1->width / 2, l1->height / 2);
    for (int ch = 0; ch < 3; ch++) CHECK(c1[ch] < c0[ch]);

    gr_image_destroy(l0); gr_image_destroy(l1); gr_image_destroy(l2);
    gr_image_destroy(t0); gr_image_destroy(t1); gr_image_destroy(t2);
    free(s0); free(s1); free(s2);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
