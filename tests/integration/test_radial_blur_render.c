/* radial_blur and radial_blur_local rendered end to end (light pass + blur) against
 * independent values (docs/radial-blur.md):
 * - Units: flat water, no occluders, seed 004's defaults, camera looking straight at the
 *   refracted sun (odd size: the centre pixel is the sun): the layer there equals the
 *   single-scattering closed form sigma_s p_HG(0) T E D exp(-sigma_t D) (D = depth / cos of the
 *   refracted sun's zenith angle, T from the exact Fresnel equations, p_HG normalized), the
 *   value the scene-derived intensity is defined to reproduce.
 * - Occluders drawn black: a sphere on the line to the sun zeroes the sun's pixel (all its taps
 *   sit on it) while a pixel beside it stays lit.
 * - Light behind the camera: the layer is exactly zero (no mirrored streaks), whatever the
 *   fade margin. Off screen in front: zero beyond the margin; inside it the layer is scaled by
 *   1 - smoothstep(1, 1 + margin, ndc_y) with ndc_y = tan(angle above the view axis) /
 *   tan(fov/2) computed here by trigonometry, and its energy lies on the sun's side of the
 *   image (top half; right half when the sun is to the right).
 * - Determinism: two renders (dither on, waves, occluders) are identical bytes; no NaN/Inf.
 * - radial_blur_local: at most `lights` lights, each inside the frame; zero outside every quad;
 *   with one light on flat water the light sits within 1.5 cells of the refracted sun. */
#include <math.h>
#include <string.h>

#include "gl/glctx.h"
#include "image/exr.h"
#include "image/png.h"
#include "rb_test.h"

#define PI 3.14159265358979323846

static const char *base =
    "{\"name\": \"rb\", \"water\": {\"waves\": []},"
    "\"sun\": {\"elevation_deg\": 60, \"azimuth_deg\": 30, \"irradiance\": [1, 2, 3]},"
    "\"medium\": {\"absorption_per_m\": [0.3, 0.06, 0.02], \"scattering_per_m\": [0.04, 0.05, 0.06], \"g\": 0.9, \"ior\": 1.333},"
    "\"camera\": {\"position_m\": [3, -8, -2], \"fov_deg\": 60, \"width\": 161, \"height\": 91}}";

static double fresnel(double ci, double n1, double n2)
{
    double st2 = (n1 / n2) * (n1 / n2) * (1 - ci * ci), ct = sqrt(1 - st2);
    double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct), rp = (n1 * ct - n2 * ci) / (n1 * ct + n2 * ci);
    return 0.5 * (rs * rs + rp * rp);
}

static double sum_rows(const gr_image *img, int y0, int y1, int x0, int x1)
{
    double s = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) s += gr_image_pixel((gr_image *)img, x, y)[2];
    return s;
}

static void preview(const gr_image *img, const char *name, double exposure)
{
    const char *dir = getenv("GODRAYS_TEST_OUT");
    if (!dir) return;
    char path[1024];
    gr_error err;
    int rgb[3] = {0, 1, 2};
    snprintf(path, sizeof path, "%s/%s.png", dir, name);
    if (gr_png_write_preview(path, img, rgb, exposure, &err) != GR_OK) fprintf(stderr, "preview: %s\n", err.msg);
    /* and the linear layer, for `godrays compare` against a ground truth by hand */
    snprintf(path, sizeof path, "%s/%s.exr", dir, name);
    if (gr_exr_write(path, img, NULL, &err) != GR_OK) fprintf(stderr, "exr: %s\n", err.msg);
}

int main(void)
{
    gr_gl *gl = NULL;
    const gr_technique_class *cls = &gr_radial_blur_class;
    void *st = rb_test_create(cls, &gl);
    const double n = 1.333, zt = asin(sin(30.0 * PI / 180.0) / n), az = 30.0 * PI / 180.0;
    const double dir[3] = {sin(zt) * sin(az), cos(zt), sin(zt) * cos(az)};
    char look[128];
    snprintf(look, sizeof look, "camera.look_at_m=[%.15g, %.15g, %.15g]", 3 + dir[0], -8 + dir[1], -2 + dir[2]);
    gr_radial_blur_settings s;

    /* Units at the sun's pixel. */
    {
        const char *sets[] = {look};
        gr_scene *sc = rb_test_scene(base, sets, 1);
        rb_test_settings(cls, sc, &s);
        s.dither = 0;
        s.target_scale = 1.0;
        gr_image *img = rb_test_render(cls, st, sc, &s, NULL);
        double D = 8.0 / cos(zt), T = 1.0 - fresnel(sin(60.0 * PI / 180.0), 1.0, n), g = 0.9;
        double phg = (1 - g * g) / (4 * PI * pow(1 - g, 3));
        const double sig_s[3] = {0.04, 0.05, 0.06}, sig_t[3] = {0.34, 0.11, 0.08}, E[3] = {1, 2, 3};
        const float *c = gr_image_pixel(img, 80, 45);
        for (int k = 0; k < 3; k++) {
            double want = sig_s[k] * phg * T * E[k] * D * exp(-sig_t[k] * D);
            printf("sun pixel ch %d: %.6f want %.6f\n", k, c[k], want);
            CHECK_REL(c[k], want, 0.01);
        }
        /* the same scene with the seed's exposure doubled: twice the layer (linear) */
        s.exposure = 0.4;
        gr_image *img2 = rb_test_render(cls, st, sc, &s, NULL);
        CHECK_REL(gr_image_pixel(img2, 80, 45)[1], 2.0 * c[1], 1e-5);
        CHECK_REL(gr_image_pixel(img2, 20, 70)[2], 2.0 * gr_image_pixel(img, 20, 70)[2], 1e-5);
        gr_image_destroy(img2);

        /* Occluder on the line to the sun. */
        char occ[256];
        snprintf(occ, sizeof occ, "occluders=[{\"type\": \"sphere\", \"center_m\": [%.9g, %.9g, %.9g], \"radius_m\": 0.06}]",
                 3 + 4 * dir[0], -8 + 4 * dir[1], -2 + 4 * dir[2]);
        const char *sets2[] = {look, occ};
        gr_scene *so = rb_test_scene(base, sets2, 2);
        s.exposure = 0.2;
        gr_image *io = rb_test_render(cls, st, so, &s, NULL);
        double open_sum = sum_rows(img, 0, 91, 0, 161), occ_sum = sum_rows(io, 0, 91, 0, 161);
        printf("occluded sun pixel %.3g (open %.3g); image sums %.4g vs %.4g\n", gr_image_pixel(io, 80, 45)[2], c[2],
               occ_sum, open_sum);
        CHECK(gr_image_pixel(io, 80, 45)[2] < 1e-6 * c[2]);
        CHECK(occ_sum > 0.3 * open_sum && occ_sum < open_sum);
        preview(io, "radial_blur_occluded", 0.3);
        gr_image_destroy(io);
        gr_image_destroy(img);
        free(so);
        free(sc);
    }

    /* Behind the camera: exactly zero, any margin. */
    {
        const char *sets[] = {"camera.yaw_deg=210", "camera.pitch_deg=-30"};
        gr_scene *sc = rb_test_scene(base, sets, 2);
        rb_test_settings(cls, sc, &s);
        for (int m = 0; m < 2; m++) {
            s.fade_margin = m ? 100.0 : 0.5;
            gr_image *img = rb_test_render(cls, st, sc, &s, NULL);
            double mx = 0;
            for (int i = 0; i < img->width * img->height * 3; i++) mx = fmax(mx, fabs(img->pixels[i]));
            printf("behind (margin %g): max %.3g\n", s.fade_margin, mx);
            CHECK(mx == 0.0);
            gr_image_destroy(img);
        }
        free(sc);
    }

    /* Off screen above the frame, in front: the fade and the side. */
    {
        const char *sets[] = {"camera.yaw_deg=30", "camera.pitch_deg=30"};
        gr_scene *sc = rb_test_scene(base, sets, 2);
        rb_test_settings(cls, sc, &s);
        s.dither = 0;
        s.light_radius_deg = 30; /* a bright region that reaches into the frame */
        double ndc_y = tan(PI / 2 - zt - 30.0 * PI / 180.0) / tan(30.0 * PI / 180.0);
        double e[2];
        gr_image *img[2];
        const double margins[2] = {1.5, 100.0};
        for (int m = 0; m < 2; m++) {
            double x = (ndc_y - 1.0) / margins[m];
            e[m] = x >= 1 ? 0 : 1 - x * x * (3 - 2 * x);
            s.fade_margin = margins[m];
            img[m] = rb_test_render(cls, st, sc, &s, NULL);
        }
        printf("off screen: ndc_y %.4f, fades %.4f %.4f\n", ndc_y, e[0], e[1]);
        CHECK(ndc_y > 1.0 && e[0] > 0.05 && e[0] < 0.95);
        double top = sum_rows(img[0], 0, 45, 0, 161), bottom = sum_rows(img[0], 46, 91, 0, 161);
        printf("top %.4g bottom %.4g\n", top, bottom);
        CHECK(top > 0 && top > 2.0 * bottom);
        double ratio = sum_rows(img[0], 0, 91, 0, 161) / sum_rows(img[1], 0, 91, 0, 161);
        CHECK_REL(ratio, e[0] / e[1], 1e-4);
        /* beyond the margin: zero */
        s.fade_margin = 0.3; /* ndc_y - 1 = 0.35 > 0.3 */
        gr_image *z = rb_test_render(cls, st, sc, &s, NULL);
        CHECK(sum_rows(z, 0, 91, 0, 161) == 0.0);
        gr_image_destroy(z);
        gr_image_destroy(img[0]);
        gr_image_destroy(img[1]);
        free(sc);
    }
    /* Sun to the right, in front, inside the margin: energy on the right. */
    {
        const char *sets[] = {"camera.yaw_deg=70", "camera.pitch_deg=50"};
        gr_scene *sc = rb_test_scene(base, sets, 2);
        rb_test_settings(cls, sc, &s);
        s.fade_margin = 2.0;
        double side = dir[0] * sc->camera.right[0] + dir[1] * sc->camera.right[1] + dir[2] * sc->camera.right[2];
        gr_image *img = rb_test_render(cls, st, sc, &s, NULL);
        double left = sum_rows(img, 0, 91, 0, 80), right = sum_rows(img, 0, 91, 81, 161);
        printf("side %.3f: left %.4g right %.4g\n", side, left, right);
        CHECK(side > 0 ? right > 2.0 * left : left > 2.0 * right);
        CHECK(left + right > 0);
        gr_image_destroy(img);
        free(sc);
    }

    /* Determinism with waves and occluders (the default scene). */
    {
        char path[1024];
        const char *src = getenv("GODRAYS_SOURCE_DIR");
        snprintf(path, sizeof path, "%s/data/scenes/default.json", src ? src : ".");
        gr_error err;
        gr_scene *sc = malloc(sizeof *sc);
        if (gr_scene_load_file(path, NULL, 0, sc, &err) != GR_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        rb_test_settings(cls, sc, &s);
        gr_technique_stats stats;
        gr_image *a = rb_test_render(cls, st, sc, &s, &stats);
        gr_image *b = rb_test_render(cls, st, sc, &s, NULL);
        CHECK(memcmp(a->pixels, b->pixels, (size_t)a->width * a->height * 3 * sizeof(float)) == 0);
        CHECK(stats.n_passes == 3 && stats.wall_ms > 0);
        printf("default scene: passes %s %lld ns, %s %lld ns, %s %lld ns; wall %.1f ms\n", stats.pass_names[0],
               stats.gpu_ns[0], stats.pass_names[1], stats.gpu_ns[1], stats.pass_names[2], stats.gpu_ns[2],
               stats.wall_ms);
        double mx = 0;
        for (int i = 0; i < a->width * a->height * 3; i++) mx = fmax(mx, a->pixels[i]);
        CHECK(mx > 0);
        preview(a, "radial_blur_default", 1.0);
        gr_image_destroy(a);
        gr_image_destroy(b);

        /* radial_blur_local on the same scene. */
        const gr_technique_class *lc = &gr_radial_blur_local_class;
        gr_gl *gl2 = NULL;
        void *ls = rb_test_create(lc, &gl2);
        rb_test_settings(lc, sc, &s);
        a = rb_test_render(lc, ls, sc, &s, &stats);
        b = rb_test_render(lc, ls, sc, &s, NULL);
        CHECK(memcmp(a->pixels, b->pixels, (size_t)a->width * a->height * 3 * sizeof(float)) == 0);
        double uv[256][2];
        int nl = gr_radial_blur_local_lights(ls, uv, 256);
        printf("local: %d lights, fragments %lld, wall %.1f ms\n", nl, stats.fragments, stats.wall_ms);
        CHECK(nl >= 1 && nl <= s.lights);
        int W = a->width, H = a->height, outside_bad = 0, outside_n = 0;
        for (int i = 0; i < nl; i++) CHECK(uv[i][0] >= 0 && uv[i][0] <= 1 && uv[i][1] >= 0 && uv[i][1] <= 1);
        for (int y = 0; y < H; y += 3)
            for (int x = 0; x < W; x += 3) {
                double u = (x + 0.5) / W, v = 1.0 - (y + 0.5) / H, rmin = 1e9;
                for (int i = 0; i < nl; i++) {
                    double dx = (u - uv[i][0]) * W / H / s.quad_size, dy = (v - uv[i][1]) / s.quad_size;
                    rmin = fmin(rmin, sqrt(dx * dx + dy * dy));
                }
                if (rmin > 1.01) {
                    outside_n++;
                    if (gr_image_pixel(a, x, y)[2] != 0.0f) outside_bad++;
                }
            }
        printf("pixels outside every quad: %d sampled, %d non-zero\n", outside_n, outside_bad);
        CHECK(outside_bad == 0);
        preview(a, "radial_blur_local_default", 1.0);
        gr_image_destroy(a);
        gr_image_destroy(b);

        /* one light on flat water sits on the refracted sun */
        const char *sets[] = {look};
        gr_scene *fl = rb_test_scene(base, sets, 1);
        rb_test_settings(lc, fl, &s);
        s.lights = 1;
        a = rb_test_render(lc, ls, fl, &s, NULL);
        nl = gr_radial_blur_local_lights(ls, uv, 1);
        double cpx = fmax(1.0, round(s.cell_size * lround(91 * s.target_scale)));
        double cell_u = 1.5 * cpx / lround(161 * s.target_scale), cell_v = 1.5 * cpx / lround(91 * s.target_scale);
        printf("one light at %.4f %.4f (sun 0.5 0.5)\n", uv[0][0], uv[0][1]);
        CHECK(nl == 1 && fabs(uv[0][0] - 0.5) < cell_u && fabs(uv[0][1] - 0.5) < cell_v);
        gr_image_destroy(a);
        free(fl);

        /* steep waves (data/scenes/hard/waves_near_loop.json): the sun seen through them breaks
         * into separate glints; each light sits on a bright texel of the light pass */
        snprintf(path, sizeof path, "%s/data/scenes/hard/waves_near_loop.json", src ? src : ".");
        gr_scene *wl = malloc(sizeof *wl);
        if (gr_scene_load_file(path, NULL, 0, wl, &err) != GR_OK) {
            fprintf(stderr, "%s\n", err.msg);
            return 1;
        }
        rb_test_settings(lc, wl, &s);
        a = rb_test_render(lc, ls, wl, &s, NULL);
        nl = gr_radial_blur_local_lights(ls, uv, 256);
        gr_image *lt = NULL;
        CHECK_OK(lc->read_target(ls, &lt, &err), err);
        if (lt) {
            double lmax = 0;
            for (int i = 0; i < lt->width * lt->height; i++) lmax = fmax(lmax, lt->pixels[i * 4 + 2]);
            for (int i = 0; i < nl; i++) {
                int tx = (int)(uv[i][0] * lt->width), ty = (int)((1.0 - uv[i][1]) * lt->height);
                float v = gr_image_pixel(lt, tx, ty)[2];
                printf("glint light %d at (%.3f, %.3f): light pass %.3g of max %.3g\n", i, uv[i][0], uv[i][1], v, lmax);
                CHECK(v > 0.05 * lmax);
            }
            gr_image_destroy(lt);
        }
        CHECK(nl >= 2);
        preview(a, "radial_blur_local_waves", 1.0);
        gr_image_destroy(a);
        free(wl);
        lc->destroy(ls);
        gr_gl_destroy(gl2);
        free(sc);
    }
    cls->destroy(st);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
