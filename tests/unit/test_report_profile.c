/* report/profile: radial profiles against the refracted sun direction.
 *  - the view direction of the refracted sun against Snell's law written out in angles
 *    (sin theta_t = sin theta_i / n, same azimuth as the sun, elevation 90 - theta_t);
 *  - pixel angles against the pinhole model: for a camera looking along d, the ray through
 *    the pixel with image-plane offset (u, v) makes atan(hypot(u, v)) with d;
 *  - bin means of an image whose value is a known increasing function of the angle lie
 *    between the function's values at the bin's edges; counts add up to the pixels;
 *  - luminance is the Rec. 709 mix of the channel means, stderr bounds are mean stderrs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "report/profile.h"
#include "scene/scene.h"

#define PI 3.14159265358979323846

static gr_scene *load(const char *json)
{
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err = {GR_OK, ""};
    gr_status st = gr_scene_load_string(json, "t", NULL, 0, s, &err);
    CHECK_OK(st, err);
    return s;
}

int main(void)
{
    char json[1024];
    const double elev = 55.0, azim = 20.0, n = 1.333;
    snprintf(json, sizeof json,
             "{\"sun\": {\"elevation_deg\": %g, \"azimuth_deg\": %g}, \"medium\": {\"ior\": %g},"
             " \"camera\": {\"position_m\": [0, -5, 0], \"yaw_deg\": 0, \"pitch_deg\": 0, \"fov_deg\": 50,"
             " \"width\": 41, \"height\": 31}}",
             elev, azim, n);
    gr_scene *s = load(json);
    double d[3];
    gr_profile_sun_view_dir(s, d);
    const double ti = (90.0 - elev) * PI / 180.0, tt = asin(sin(ti) / n);
    const double el_t = PI / 2 - tt, az = azim * PI / 180.0;
    /* toward the sun from below: up by the refracted elevation, azimuth (sin a, cos a) */
    CHECK_NEAR(d[1], sin(el_t), 1e-12);
    CHECK_NEAR(d[0], cos(el_t) * sin(az), 1e-12);
    CHECK_NEAR(d[2], cos(el_t) * cos(az), 1e-12);

    /* A camera aimed exactly at the refracted sun. */
    snprintf(json, sizeof json,
             "{\"sun\": {\"elevation_deg\": %g, \"azimuth_deg\": %g}, \"medium\": {\"ior\": %g},"
             " \"camera\": {\"position_m\": [0, -5, 0], \"look_at_m\": [%.17g, %.17g, %.17g], \"fov_deg\": 50,"
             " \"width\": 41, \"height\": 31}}",
             elev, azim, n, 10 * d[0], -5 + 10 * d[1], 10 * d[2]);
    free(s);
    s = load(json);
    const int W = s->camera.width, H = s->camera.height;
    float *ang = malloc(sizeof(float) * (size_t)W * (size_t)H);
    gr_profile_angles(&s->camera, d, ang);
    const double th = tan(25.0 * PI / 180.0);
    double maxdev = 0.0, amax = 0.0;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            const double u = (2.0 * (px + 0.5) / W - 1.0) * th * W / H, v = (2.0 * (py + 0.5) / H - 1.0) * th;
            const double expect = atan(hypot(u, v)) * 180.0 / PI;
            const double got = ang[py * W + px];
            maxdev = fmax(maxdev, fabs(got - expect));
            amax = fmax(amax, got);
        }
    CHECK_MSG(maxdev < 2e-4, "max angle deviation %g deg", maxdev); /* float storage: ~1e-5 deg */
    CHECK_NEAR(ang[15 * W + 20], 0.0, 1e-3);                         /* the centre pixel looks at the sun */

    /* Orientation: a level camera and d = +y. Rows at the top of the image look up: the
     * ray f + u right - v up has the angle acos(-v / |ray|) with +y. */
    {
        snprintf(json, sizeof json,
                 "{\"camera\": {\"position_m\": [0, -5, 0], \"yaw_deg\": 30, \"pitch_deg\": 0, \"fov_deg\": 50,"
                 " \"width\": 41, \"height\": 31}}");
        gr_scene *lv = load(json);
        const double up[3] = {0, 1, 0};
        gr_profile_angles(&lv->camera, up, ang);
        double dev = 0.0;
        for (int py = 0; py < H; py++)
            for (int px = 0; px < W; px++) {
                const double u = (2.0 * (px + 0.5) / W - 1.0) * th * W / H, v = (2.0 * (py + 0.5) / H - 1.0) * th;
                const double expect = acos(-v / sqrt(1 + u * u + v * v)) * 180.0 / PI;
                dev = fmax(dev, fabs(ang[py * W + px] - expect));
            }
        CHECK_MSG(dev < 2e-4, "level camera: max angle deviation %g deg", dev);
        CHECK(ang[0] < 90.0f && ang[(H - 1) * W] > 90.0f); /* top row looks up */
        free(lv);
        gr_profile_angles(&s->camera, d, ang); /* back to the sun-aimed camera */
    }

    /* Profile of an image whose value is f(angle) = 1 + angle^2 / 100 (increasing). */
    static const char *const names[6] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    gr_image *img = gr_image_create(W, H, 6, names);
    for (int p = 0; p < W * H; p++) {
        const double f = 1.0 + (double)ang[p] * ang[p] / 100.0;
        float *px = img->pixels + (size_t)p * 6;
        px[0] = (float)f;
        px[1] = (float)(2.0 * f);
        px[2] = (float)(4.0 * f);
        px[3] = 0.1f;
        px[4] = 0.2f;
        px[5] = 0.4f;
    }
    const double bin = gr_profile_bin_width(amax, 12);
    const int nb = (int)floor(amax / bin) + 1;
    gr_radial_profile pr;
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_radial_profile_compute(img, ang, NULL, nb, bin, 0.5, &pr, &err), err);
    long long total = 0;
    for (int b = 0; b < pr.nbins; b++) {
        total += pr.count[b];
        CHECK_NEAR(pr.center_deg[b], (b + 0.5) * bin, 1e-12);
        if (pr.count[b] == 0) {
            CHECK(isnan(pr.mean[GR_PROFILE_R][b]));
            continue;
        }
        const double lo = b * bin, hi = (b + 1) * bin;
        const double flo = 0.5 * (1 + lo * lo / 100), fhi = 0.5 * (1 + hi * hi / 100);
        CHECK_MSG(pr.mean[GR_PROFILE_R][b] >= flo - 1e-6 && pr.mean[GR_PROFILE_R][b] <= fhi + 1e-6,
                  "bin %d [%g, %g): mean %g not in [%g, %g]", b, lo, hi, pr.mean[GR_PROFILE_R][b], flo, fhi);
        CHECK_NEAR(pr.mean[GR_PROFILE_G][b], 2 * pr.mean[GR_PROFILE_R][b], 1e-9);
        const double y = 0.2126 * pr.mean[0][b] + 0.7152 * pr.mean[1][b] + 0.0722 * pr.mean[2][b];
        CHECK_NEAR(pr.mean[GR_PROFILE_Y][b], y, 1e-9);
        CHECK(pr.stderr_bound[0] != NULL);
        if (pr.stderr_bound[0]) {
            CHECK_NEAR(pr.stderr_bound[GR_PROFILE_B][b], 0.5 * 0.4, 1e-7); /* scaled like the values */
            CHECK_NEAR(pr.stderr_bound[GR_PROFILE_Y][b], 0.5 * (0.2126 * 0.1 + 0.7152 * 0.2 + 0.0722 * 0.4), 1e-7);
        }
    }
    CHECK(total == (long long)W * H);
    CHECK(pr.bin_deg == bin && bin == 5.0); /* corner angle ~ 37.4 deg / 12 -> 3.1 -> the round 5 */
    gr_radial_profile_free(&pr);

    /* scored pixels only; fewer bins drop the pixels beyond them */
    unsigned char *scored = calloc((size_t)W * H, 1);
    for (int p = 0; p < W * H; p += 2) scored[p] = 1;
    CHECK_OK(gr_radial_profile_compute(img, ang, scored, 2, bin, 1.0, &pr, &err), err);
    long long expect = 0;
    for (int p = 0; p < W * H; p += 2)
        if (ang[p] < 2 * bin) expect++;
    CHECK(pr.count[0] + pr.count[1] == expect);
    gr_radial_profile_free(&pr);

    /* no stderr channels: no bounds */
    gr_image *rgb = gr_image_create(W, H, 3, NULL);
    CHECK_OK(gr_radial_profile_compute(rgb, ang, NULL, nb, bin, 1.0, &pr, &err), err);
    CHECK(pr.stderr_bound[0] == NULL && pr.mean[0][0] == 0.0);
    gr_radial_profile_free(&pr);
    gr_radial_profile_free(NULL);

    /* bad input */
    CHECK(gr_radial_profile_compute(rgb, ang, NULL, 0, bin, 1.0, &pr, &err) == GR_E_INPUT);
    CHECK(gr_radial_profile_compute(rgb, ang, NULL, 3, 0.0, 1.0, &pr, &err) == GR_E_INPUT);
    CHECK(gr_radial_profile_compute(rgb, ang, NULL, 3, NAN, 1.0, &pr, &err) == GR_E_INPUT);
    CHECK(gr_radial_profile_compute(rgb, NULL, NULL, 3, 1.0, 1.0, &pr, &err) == GR_E_INPUT);

    /* round bin widths: 1, 2 or 5 times a power of ten, at least max / target */
    CHECK_NEAR(gr_profile_bin_width(60.0, 60), 1.0, 1e-12);
    CHECK_NEAR(gr_profile_bin_width(61.0, 60), 2.0, 1e-12);
    CHECK_NEAR(gr_profile_bin_width(3.0, 10), 0.5, 1e-12);
    CHECK_NEAR(gr_profile_bin_width(170.0, 10), 20.0, 1e-12);
    CHECK_NEAR(gr_profile_bin_width(0.0, 10), 1.0, 1e-12);

    free(scored);
    free(ang);
    gr_image_destroy(img);
    gr_image_destroy(rgb);
    free(s);
    CHECK_DONE();
}
