/* Additive blending into an 8-bit target saturates at 1.0 where many shafts overlap; an
 * RGBA16F target does not. A viewer looking horizontally through a dense grid of vertical
 * shafts in clear water sees dozens of shaft surfaces per pixel, each worth ~0.8.
 * Also: where the float target stays below 1, the 8-bit sum differs from it by at most half
 * a code (0.5/255) per blended fragment (the float target's alpha counts the fragments). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "shafts_test.h"

static const char *scene_json =
    "{\"name\": \"overlap\", \"water\": {\"waves\": []},"
    "\"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 0},"
    "\"medium\": {\"absorption_per_m\": 0.005, \"scattering_per_m\": 0.005, \"g\": 0.5},"
    "\"camera\": {\"position_m\": [0, -6, 0], \"yaw_deg\": 0, \"pitch_deg\": 0, \"fov_deg\": 60,"
    "\"width\": 160, \"height\": 90},"
    "\"shafts\": {\"N\": 33, \"K\": 2.0, \"shaft_length_m\": 30, \"shaft_width\": 0.5, \"target_prescale\": 1}}";

int main(void)
{
    gr_shafts *r = shafts_test_renderer();
    static const char *const set8[] = {"shafts.target_format=rgba8"};
    static const char *const set16[] = {"shafts.target_format=rgba16f"};
    gr_scene *s8 = shafts_test_scene(scene_json, set8, 1);
    gr_scene *s16 = shafts_test_scene(scene_json, set16, 1);
    gr_shafts_stats st8, st16;

    gr_image *img8 = shafts_test_render(r, s8, &st8);
    gr_image *t8 = shafts_test_target(r);
    gr_image *img16 = shafts_test_render(r, s16, &st16);
    gr_image *t16 = shafts_test_target(r);
    CHECK(t8->width == t16->width && t8->height == t16->height);
    CHECK(st8.fragments == st16.fragments); /* same geometry, same coverage */

    size_t n = (size_t)t8->width * (size_t)t8->height;
    float max8 = 0.0f, max16 = 0.0f, max_count = 0.0f;
    size_t saturated = 0, compared = 0, over = 0;
    for (size_t i = 0; i < n; i++) {
        const float *a = t8->pixels + i * 4, *b = t16->pixels + i * 4;
        for (int c = 0; c < 3; c++) {
            if (a[c] > max8) max8 = a[c];
            if (b[c] > max16) max16 = b[c];
            CHECK(a[c] <= 1.0f);
            if (a[c] == 1.0f) {
                saturated++;
                if (b[c] > 1.5f) over++;
            }
            if (b[c] < 0.9f) {
                /* each fragment's contribution is rounded to 1/255 before the add */
                double tol = (double)b[3] * 0.5 / 255.0 + 2e-3 * b[c] + 1e-6;
                CHECK_MSG(fabs((double)a[c] - (double)b[c]) <= tol, "texel %zu ch %d: rgba8 %.5f rgba16f %.5f count %.0f",
                          i, c, a[c], b[c], b[3]);
                compared++;
            }
        }
        if (b[3] > max_count) max_count = b[3];
    }
    printf("rgba8: max %.4f, %zu saturated samples; rgba16f: max %.4f, up to %.0f surfaces per texel; "
           "%zu unsaturated samples compared; fragments %lld (overdraw %.1f)\n",
           max8, saturated, max16, max_count, compared, st8.fragments,
           (double)st8.fragments / ((double)t8->width * (double)t8->height));
    CHECK(max8 == 1.0f);            /* 8 bits clamp at exactly 1.0 */
    CHECK(saturated > n / 20);      /* in a good part of the image */
    CHECK(max16 > 3.0f);            /* the float target keeps counting */
    CHECK(over > saturated / 2);    /* where 8 bits clamp, the true sum is well above 1 */
    CHECK(max_count >= 8.0f);
    CHECK(compared > 0);

    /* The final layer inherits the clamp: with a saturated 8-bit target the layer cannot
     * exceed (bias + intensity) * peak phase; the float pipeline does. */
    const gr_shafts_settings *sh8 = gr_shafts_scene_settings(s8);
    double g = sh8->g, peak = (1.0 - g * g) / pow(1.0 - g, 3.0);
    double cap = (sh8->bias + sh8->intensity[0]) * peak;
    float lmax8 = 0.0f, lmax16 = 0.0f;
    for (size_t i = 0; i < (size_t)img8->width * (size_t)img8->height * 3; i++) {
        if (img8->pixels[i] > lmax8) lmax8 = img8->pixels[i];
        if (img16->pixels[i] > lmax16) lmax16 = img16->pixels[i];
    }
    printf("layer max: rgba8 %.4f (bound %.4f), rgba16f %.4f\n", lmax8, cap, lmax16);
    CHECK(lmax8 <= cap * (1.0 + 1e-5));
    CHECK(lmax16 > lmax8 * 1.5f);

    gr_image_destroy(img8);
    gr_image_destroy(img16);
    gr_image_destroy(t8);
    gr_image_destroy(t16);
    free(s8);
    free(s16);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
