/* The per-channel fit (compare/fit.h, `--fit rgb`): a_c = <t_c, r_c> / <t_c, t_c> per channel.
 * A tint (test = truth with R x 0.5, G x 1, B x 2) is recovered exactly on clean data and within
 * 1 % under noise; the metrics after the fit are those of the per-channel-scaled test (zero error
 * for an exact tint, and each fitted channel's MSE a minimum by finite differences); a grey test
 * against a coloured truth, a black channel, the luminance-equivalent scale by hand; the single
 * scale keeps its three factors equal; the fit option's spellings. */
#include <string.h>

#include "check.h"
#include "compare/fit.h"
#include "compare/metrics.h"

/* A smooth coloured truth with structure: channel c of pixel (x, y). */
static float truth_at(int x, int y, int c)
{
    return (float)((0.2 + 0.1 * c) * (1.0 + sin(0.37 * x + 0.11 * c) * cos(0.23 * y)) + 0.05 * c);
}

static void make_pair(int w, int h, const double tint[3], double noise, gr_image **r, gr_image **t)
{
    *r = gr_image_create(w, h, 3, NULL);
    *t = gr_image_create(w, h, 3, NULL);
    unsigned s = 12345u;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                const size_t i = ((size_t)y * (size_t)w + (size_t)x) * 3 + (size_t)c;
                s = s * 1664525u + 1013904223u;
                const double u = (double)(s >> 8) / 16777216.0 - 0.5; /* uniform in [-0.5, 0.5) */
                (*r)->pixels[i] = truth_at(x, y, c);
                (*t)->pixels[i] = (float)((double)truth_at(x, y, c) * tint[c] * (1.0 + noise * u));
            }
}

/* R x 0.5, G x 1, B x 2 (powers of two: the tinted floats are exact): a = 2, 1, 0.5 exactly,
 * and every error after the fit is 0. */
static void test_exact_tint(void)
{
    const double tint[3] = {0.5, 1.0, 2.0};
    gr_image *r, *t;
    make_pair(40, 30, tint, 0.0, &r, &t);
    const int rgb[3] = {0, 1, 2};
    double a[3];
    CHECK(gr_fit_scales(r, t, NULL, rgb, rgb, GR_FIT_RGB, a) == 3);
    CHECK(a[0] == 2.0 && a[1] == 1.0 && a[2] == 0.5);
    gr_metrics m;
    gr_error err = {0};
    const gr_metrics_options opt = {.fit_scale = GR_FIT_RGB};
    CHECK_OK(gr_metrics_compute(r, t, &opt, &m, &err), err);
    CHECK(m.have_fit && m.fit_defined && m.fit_mode == GR_FIT_RGB);
    CHECK(m.fit.scale_rgb[0] == 2.0 && m.fit.scale_rgb[1] == 1.0 && m.fit.scale_rgb[2] == 0.5);
    CHECK(m.raw.scale_rgb[0] == 1.0 && m.raw.scale_rgb[2] == 1.0);
    for (int c = 0; c < GR_MCH_COUNT; c++) CHECK(m.fit.ch[c].rmse == 0.0 && m.fit.ch[c].rmse_blur[2] == 0.0);
    CHECK_NEAR(m.fit.ssim_y, 1.0, 1e-12);
    /* the one number: sum w_c a_c mean(t_c) / sum w_c mean(t_c), from the raw means by hand */
    double num = 0.0, den = 0.0;
    const double w[3] = {GR_LUM_R, GR_LUM_G, GR_LUM_B};
    for (int c = 0; c < 3; c++) {
        num += w[c] * m.fit.scale_rgb[c] * m.raw.ch[c].test_mean;
        den += w[c] * m.raw.ch[c].test_mean;
    }
    CHECK_REL(m.fit.scale, num / den, 1e-12);
    /* the single scale cannot undo a tint: a clearly larger error */
    const gr_metrics_options one = {.fit_scale = GR_FIT_SCALE};
    gr_metrics m1;
    CHECK_OK(gr_metrics_compute(r, t, &one, &m1, &err), err);
    CHECK(m1.fit_mode == GR_FIT_SCALE && m1.fit.scale_rgb[0] == m1.fit.scale && m1.fit.scale_rgb[2] == m1.fit.scale);
    CHECK(m1.fit.ch[GR_MCH_RGB].rmse > 0.05);
    gr_image_destroy(r);
    gr_image_destroy(t);
}

/* 5 % multiplicative noise on top of the tint: each factor within 1 % of 1 / tint. */
static void test_noisy_tint(void)
{
    const double tint[3] = {0.5, 1.0, 2.0};
    gr_image *r, *t;
    make_pair(96, 54, tint, 0.1, &r, &t);
    gr_metrics m;
    gr_error err = {0};
    const gr_metrics_options opt = {.fit_scale = GR_FIT_RGB, .skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(r, t, &opt, &m, &err), err);
    for (int c = 0; c < 3; c++) CHECK_REL(m.fit.scale_rgb[c], 1.0 / tint[c], 0.01);
    gr_image_destroy(r);
    gr_image_destroy(t);
}

/* The fitted MSE of each channel is a minimum: the test scaled by hand by a_c (1 +- 1e-3) in
 * one channel and compared without a fit has a larger MSE in that channel. */
static void test_minimum(void)
{
    const double tint[3] = {0.7, 1.3, 0.9};
    gr_image *r, *t;
    make_pair(21, 13, tint, 0.3, &r, &t);
    gr_metrics m;
    gr_error err = {0};
    const gr_metrics_options opt = {.fit_scale = GR_FIT_RGB, .skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(r, t, &opt, &m, &err), err);
    gr_image *ts = gr_image_create(21, 13, 3, NULL);
    for (int c = 0; c < 3; c++) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            const double a = m.fit.scale_rgb[c] * (1.0 + sgn * 1e-3);
            for (size_t i = 0; i < 21 * 13 * 3; i++) ts->pixels[i] = t->pixels[i];
            for (size_t p = 0; p < 21 * 13; p++) ts->pixels[3 * p + (size_t)c] = (float)(a * t->pixels[3 * p + (size_t)c]);
            gr_metrics mh;
            const gr_metrics_options none = {.skip_ssim = 1, .skip_blur = 1};
            CHECK_OK(gr_metrics_compute(r, ts, &none, &mh, &err), err);
            CHECK_MSG(mh.raw.ch[c].mse > m.fit.ch[c].mse, "channel %d, a (1 %+g e-3): %.9g <= %.9g", c, (double)sgn,
                      mh.raw.ch[c].mse, m.fit.ch[c].mse);
        }
    }
    gr_image_destroy(ts);
    gr_image_destroy(r);
    gr_image_destroy(t);
}

/* A grey test (one channel) against a coloured truth: a_c = <t, r_c> / <t, t> by hand on 2
 * pixels: t = (1, 2), r_R = (1, 2), r_G = (2, 4), r_B = (0, 1): a = 5/5, 10/5, 2/5. A black
 * channel keeps factor 1 and the fit stays defined. */
static void test_grey_and_black(void)
{
    const char *g[] = {"Y"};
    gr_image *r = gr_image_create(2, 1, 3, NULL), *t = gr_image_create(2, 1, 1, g);
    const float rv[6] = {1, 2, 0, 2, 4, 1};
    memcpy(r->pixels, rv, sizeof rv);
    t->pixels[0] = 1, t->pixels[1] = 2;
    gr_metrics m;
    gr_error err = {0};
    const gr_metrics_options opt = {.fit_scale = GR_FIT_RGB};
    CHECK_OK(gr_metrics_compute(r, t, &opt, &m, &err), err);
    CHECK_NEAR(m.fit.scale_rgb[0], 1.0, 1e-15);
    CHECK_NEAR(m.fit.scale_rgb[1], 2.0, 1e-15);
    CHECK_NEAR(m.fit.scale_rgb[2], 0.4, 1e-15);
    CHECK_NEAR(m.fit.ch[GR_MCH_R].rmse, 0.0, 1e-7);
    CHECK_NEAR(m.fit.ch[GR_MCH_G].rmse, 0.0, 1e-7);
    /* B: 0.4 t = (0.4, 0.8) against (0, 1): d = 0.4, -0.2, RMSE sqrt(0.1) */
    CHECK_NEAR(m.fit.ch[GR_MCH_B].rmse, sqrt(0.1), 1e-7);
    gr_image *t3 = gr_image_create(2, 1, 3, NULL);
    const float tv[6] = {1, 1, 0, 2, 2, 0}; /* B black */
    memcpy(t3->pixels, tv, sizeof tv);
    CHECK_OK(gr_metrics_compute(r, t3, &opt, &m, &err), err);
    CHECK(m.fit_defined && m.fit.scale_rgb[2] == 1.0);
    CHECK_NEAR(m.fit.scale_rgb[1], 2.0, 1e-15);
    const int rgb[3] = {0, 1, 2};
    double a[3];
    CHECK(gr_fit_scales(r, t3, NULL, rgb, rgb, GR_FIT_RGB, a) == 2);
    memset(t3->pixels, 0, sizeof tv);
    CHECK(gr_fit_scales(r, t3, NULL, rgb, rgb, GR_FIT_RGB, a) == 0 && a[0] == 1.0);
    CHECK(gr_fit_scales(r, t3, NULL, rgb, rgb, GR_FIT_SCALE, a) == 0);
    CHECK_OK(gr_metrics_compute(r, t3, &opt, &m, &err), err);
    CHECK(!m.fit_defined);
    gr_image_destroy(t3);
    gr_image_destroy(r);
    gr_image_destroy(t);
}

static void test_options(void)
{
    static const char *const words[] = {"x", "--fit", "rgb", "--fit", "ref.exr", "--fit=none", "--fit-scale",
                                        "--no-fit", "--fit=rbg", "--fitness", "--fit"};
    enum { argc = sizeof words / sizeof words[0] };
    char buf[argc][16], *argv[argc];
    for (int k = 0; k < argc; k++) argv[k] = strcpy(buf[k], words[k]);
    gr_fit_mode m = GR_FIT_NONE;
    gr_error err = {0};
    int i = 1;
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 1 && m == GR_FIT_RGB && i == 2);
    i = 3; /* a bare --fit before a path: scale, the path is not consumed */
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 1 && m == GR_FIT_SCALE && i == 3);
    i = 5;
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 1 && m == GR_FIT_NONE);
    i = 6;
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 1 && m == GR_FIT_SCALE);
    i = 7;
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 1 && m == GR_FIT_NONE);
    i = 8;
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == -1 && err.status == GR_E_USAGE && strstr(err.msg, "rbg"));
    i = 9;
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 0);
    i = 10; /* last argument */
    CHECK(gr_fit_mode_option(argc, argv, &i, &m, &err) == 1 && m == GR_FIT_SCALE && i == 10);
    CHECK(!strcmp(gr_fit_mode_name(GR_FIT_RGB), "rgb") && gr_fit_mode_name((gr_fit_mode)7) == NULL);
}

int main(void)
{
    test_exact_tint();
    test_noisy_tint();
    test_minimum();
    test_grey_and_black();
    test_options();
    CHECK_DONE();
}
