/* SSIM on luminance (Wang et al. 2004: 11 x 11 Gaussian window, sigma 1.5, K1 0.01, K2 0.03,
 * L = the reference luminance peak). Oracles: 1 for identical images; the closed form
 * (2 a b + C1) / (a^2 + b^2 + C1) for two constant images (no variance); and an independent
 * brute-force evaluation of the windowed statistics on a small random image. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compare/metrics.h"

static const gr_metrics_options ssim_only = {.skip_blur = 1};

static void fill(gr_image *img, float r, float g, float b)
{
    for (int p = 0; p < img->width * img->height; p++) {
        img->pixels[3 * p] = r, img->pixels[3 * p + 1] = g, img->pixels[3 * p + 2] = b;
    }
}

static void test_identical(void)
{
    gr_image *a = gr_image_create(16, 12, 3, NULL);
    for (int i = 0; i < 16 * 12 * 3; i++) a->pixels[i] = (float)((i * 37) % 101) / 50.0f;
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, a, &ssim_only, &m, &err), err);
    CHECK(m.raw.have_ssim);
    CHECK_NEAR(m.raw.ssim_y, 1.0, 1e-12);
    gr_image_destroy(a);
}

/* ref luminance a = 0.5 everywhere (gray 0.5), test b = 0.25: sigma terms vanish, so
 * SSIM = (2ab + C1)/(a^2 + b^2 + C1) * C2/C2, C1 = (0.01 L)^2 with L = 0.5. */
static void test_constant(void)
{
    gr_image *a = gr_image_create(5, 4, 3, NULL), *b = gr_image_create(5, 4, 3, NULL);
    fill(a, 0.5f, 0.5f, 0.5f);
    fill(b, 0.25f, 0.25f, 0.25f);
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, b, &ssim_only, &m, &err), err);
    const double L = 0.5, C1 = (0.01 * L) * (0.01 * L);
    CHECK_NEAR(m.ssim_L, 0.5, 1e-15);
    CHECK_NEAR(m.ssim_c1, C1, 1e-18);
    CHECK_NEAR(m.ssim_c2, (0.03 * L) * (0.03 * L), 1e-18);
    CHECK_NEAR(m.raw.ssim_y, (2 * 0.5 * 0.25 + C1) / (0.25 + 0.0625 + C1), 1e-12);

    /* Both black: every term is C/C, SSIM 1, L falls back to 1; nothing is NaN. */
    fill(a, 0, 0, 0);
    fill(b, 0, 0, 0);
    CHECK_OK(gr_metrics_compute(a, b, NULL, &m, &err), err);
    CHECK_NEAR(m.raw.ssim_y, 1.0, 1e-15);
    CHECK_NEAR(m.ssim_L, 1.0, 0);
    /* Black reference, white test: (C1) / (1 + C1), with L = 1. */
    fill(b, 1, 1, 1);
    CHECK_OK(gr_metrics_compute(a, b, NULL, &m, &err), err);
    CHECK_NEAR(m.raw.ssim_y, 1e-4 / (1.0 + 1e-4), 1e-12);
    gr_image_destroy(a);
    gr_image_destroy(b);
}

static double g1(int d) { return exp(-(double)d * d / (2.0 * 1.5 * 1.5)); }

/* Brute force: per pixel, Gaussian-weighted means, variances and covariance over the 11 x 11
 * window clipped to the image (weights renormalized), then eq. 13 of Wang et al.; averaged. */
static void test_against_direct(void)
{
    enum { W = 14, H = 11 };
    gr_image *a = gr_image_create(W, H, 3, NULL), *b = gr_image_create(W, H, 3, NULL);
    unsigned s = 777u;
    double ya[W * H], yb[W * H], peak = 0.0;
    for (int p = 0; p < W * H; p++) {
        for (int c = 0; c < 3; c++) {
            s = s * 1664525u + 1013904223u;
            a->pixels[3 * p + c] = (float)((s >> 8) % 1000) / 400.0f; /* HDR: up to 2.5 */
            s = s * 1664525u + 1013904223u;
            b->pixels[3 * p + c] = a->pixels[3 * p + c] * 0.8f + (float)((s >> 8) % 100) / 300.0f;
        }
        const float *pa = a->pixels + 3 * p, *pb = b->pixels + 3 * p;
        ya[p] = 0.2126 * pa[0] + 0.7152 * pa[1] + 0.0722 * pa[2];
        yb[p] = 0.2126 * pb[0] + 0.7152 * pb[1] + 0.0722 * pb[2];
        if (ya[p] > peak) peak = ya[p];
    }
    const double C1 = (0.01 * peak) * (0.01 * peak), C2 = (0.03 * peak) * (0.03 * peak);
    double sum = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double sw = 0, mx = 0, my = 0;
            for (int dy = -5; dy <= 5; dy++)
                for (int dx = -5; dx <= 5; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
                    double w = g1(dx) * g1(dy);
                    sw += w, mx += w * ya[qy * W + qx], my += w * yb[qy * W + qx];
                }
            mx /= sw, my /= sw;
            double vx = 0, vy = 0, cxy = 0;
            for (int dy = -5; dy <= 5; dy++)
                for (int dx = -5; dx <= 5; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
                    double w = g1(dx) * g1(dy) / sw, u = ya[qy * W + qx] - mx, v = yb[qy * W + qx] - my;
                    vx += w * u * u, vy += w * v * v, cxy += w * u * v;
                }
            sum += (2 * mx * my + C1) * (2 * cxy + C2) / ((mx * mx + my * my + C1) * (vx + vy + C2));
        }
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, b, &ssim_only, &m, &err), err);
    CHECK_NEAR(m.ssim_L, peak, 1e-12);
    CHECK_NEAR(m.raw.ssim_y, sum / (W * H), 1e-12);
    CHECK(m.raw.ssim_y < 0.99 && m.raw.ssim_y > 0.0); /* a real difference, not a trivial 1 */
    gr_image_destroy(a);
    gr_image_destroy(b);
}

int main(void)
{
    test_identical();
    test_constant();
    test_against_direct();
    CHECK_DONE();
}
