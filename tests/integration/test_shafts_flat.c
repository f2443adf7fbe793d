/* Flat water, no occluders, sun at the zenith, one shaft (N = 2) straight above a viewer
 * who looks straight up: the god-ray layer at chosen pixels against values derived by hand
 * from the pipeline's formulas (docs/realtime-shafts.md, "Checking by hand").
 *
 * Geometry: T = (0,-1,0); P is straight above the eye E = (0,-d,0); the single shaft is the
 * box |x|,|z| <= h = S/2 (S = K 2 d tan(fov/2) / N), -L <= y <= 0, with L < d. The centre
 * pixel's ray runs up the box's axis and crosses only the two caps, whose four vertices
 * each have the same intensity (symmetry), so the shaft target there is
 *   top:    exp(-c sqrt(2 h^2 + d^2)) (1 - R0)
 *   bottom: exp(-c (L + sqrt(2 h^2 + (d - L)^2))) (1 - R0)      (normal (0,1,0): R = R0)
 * and the layer is (bias + intensity * (top + bottom)) * (1 - g^2) / (1 - g)^3 (view along
 * -T, cos = 1). A corner pixel sees no shaft: bias * HG_seed(cos) with cos = -T . w = w_y
 * for the pixel's view direction w, derived from the pinhole camera. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "shafts_test.h"

static const char *scene_json =
    "{\"name\": \"flat-zenith\", \"water\": {\"waves\": []},"
    "\"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 0},"
    "\"medium\": {\"absorption_per_m\": [0.04, 0.07, 0.11], \"scattering_per_m\": 0.01, \"g\": 0.5, \"ior\": 1.333},"
    "\"camera\": {\"position_m\": [0, -20, 0], \"yaw_deg\": 0, \"pitch_deg\": 90, \"fov_deg\": 60,"
    "\"width\": 161, \"height\": 91},"
    "\"shafts\": {\"N\": 2, \"K\": 0.8, \"shaft_length_m\": 10, \"shaft_width\": 1, \"bias\": 0.15,"
    "\"intensity\": [1, 2, 3], \"target_format\": \"rgba16f\", \"target_prescale\": 1}}";

static double hg_seed(double cos_t, double g)
{
    return (1.0 - g * g) / pow(1.0 + g * g - 2.0 * g * cos_t, 1.5);
}

int main(void)
{
    gr_shafts *r = shafts_test_renderer();
    const double d = 20.0, L = 10.0, K = 0.8, g = 0.5, bias = 0.15, fov = 60.0 * 3.14159265358979323846 / 180.0;
    const double n = 1.333, r0 = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
    const double c[3] = {0.05, 0.08, 0.12}, inten[3] = {1, 2, 3};
    const int W = 161, H = 91;
    const double S = K * 2.0 * d * tan(0.5 * fov) / 2.0, h = 0.5 * S;
    const double d_top = sqrt(2.0 * h * h + d * d), d_bot = L + sqrt(2.0 * h * h + (d - L) * (d - L));
    const double peak = hg_seed(1.0, g);

    /* Corner pixel (0, 0): camera right = (-1,0,0), up = (0,0,-1) for yaw 0 looking up. */
    double ndc_x = 2.0 * 0.5 / W - 1.0, ndc_y = 1.0 - 2.0 * 0.5 / H, tf = tan(0.5 * fov);
    double wx = ndc_x * tf * W / H, wz = ndc_y * tf;
    double corner_cos = 1.0 / sqrt(1.0 + wx * wx + wz * wz);

    for (int caps = 0; caps <= 1; caps++) {
        for (int fmt = 0; fmt <= 1; fmt++) {
            char set_caps[32], set_fmt[48];
            snprintf(set_caps, sizeof set_caps, "shafts.caps=%s", caps ? "true" : "false");
            snprintf(set_fmt, sizeof set_fmt, "shafts.target_format=%s", fmt ? "rgba16f" : "rgba8");
            const char *sets[2] = {set_caps, set_fmt};
            gr_scene *s = shafts_test_scene(scene_json, sets, 2);
            gr_image *img = shafts_test_render(r, s, NULL);
            const float *centre = gr_image_pixel(img, W / 2, H / 2);
            const float *corner = gr_image_pixel(img, 0, 0);
            for (int ch = 0; ch < 3; ch++) {
                double top = exp(-c[ch] * d_top) * (1.0 - r0), bot = exp(-c[ch] * d_bot) * (1.0 - r0);
                double shafts = caps ? top + bot : 0.0;
                /* Storage error: 8 bits round each of the 2 fragments to 1/255 (the blend
                 * adds stored values); 16F keeps ~11 bits. */
                double q = fmt ? 2e-3 * shafts : 2.0 * 0.5 / 255.0;
                double want = (bias + inten[ch] * shafts) * peak;
                printf("caps %d %s ch %d: centre %.6f want %.6f (shafts %.6f)\n", caps, fmt ? "rgba16f" : "rgba8", ch,
                       centre[ch], want, shafts);
                CHECK_NEAR(centre[ch], want, inten[ch] * q * peak + 1e-5 * want);
                CHECK_REL(corner[ch], bias * hg_seed(corner_cos, g), 1e-4);
            }
            gr_image_destroy(img);
            free(s);
        }
    }
    gr_shafts_destroy(r);
    CHECK_DONE();
}
