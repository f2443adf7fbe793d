/* Gaussian blur (normalized convolution) used by the multi-scale RMSE and SSIM. Oracles: the
 * kernel's closed form and unit sum, a constant image staying constant up to the edges (the
 * truncated kernel is renormalized there), a brute-force 2-D weighted convolution written
 * independently here, and mass conservation of an interior impulse. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compare/blur.h"

static void test_kernel(void)
{
    CHECK(gr_blur_radius(1.0) == 3 && gr_blur_radius(4.0) == 12 && gr_blur_radius(16.0) == 48);
    CHECK(gr_blur_radius(0.1) == 1);
    double w[2 * 48 + 1];
    gr_error err = {0};
    const double sig[] = {0.5, 1.0, 1.5, 4.0, 16.0};
    for (int k = 0; k < 5; k++) {
        int r = gr_blur_radius(sig[k]);
        CHECK_OK(gr_gaussian_kernel(sig[k], r, w, &err), err);
        double sum = 0.0;
        for (int i = 0; i <= 2 * r; i++) sum += w[i];
        CHECK_NEAR(sum, 1.0, 1e-15);
        for (int i = 0; i < r; i++) {
            CHECK(w[i] == w[2 * r - i]); /* symmetric */
            /* neighbouring taps: w(i+1)/w(i) = exp(-((i+1)^2 - i^2) / (2 sigma^2)) */
            const int a = i - r;
            CHECK_REL(w[i + 1] / w[i], exp(-((double)(a + 1) * (a + 1) - (double)a * a) / (2.0 * sig[k] * sig[k])), 1e-13);
        }
    }
    CHECK(gr_gaussian_kernel(0.0, 3, w, &err) == GR_E_INPUT && strstr(err.msg, "sigma"));
    CHECK(gr_gaussian_kernel(NAN, 3, w, &err) == GR_E_INPUT);
    CHECK(gr_gaussian_kernel(1.0, -1, w, &err) == GR_E_INPUT);
}

/* A constant image keeps its value everywhere, corners included, at every scale: the
 * renormalized kernel is an average (blur.h). The image is smaller than the kernel. */
static void test_constant(void)
{
    const int W = 7, H = 5;
    double src[7 * 5], dst[7 * 5], dw[7 * 5];
    for (int i = 0; i < W * H; i++) src[i] = 0.375;
    const double *s[1] = {src};
    double *d[1] = {dst};
    gr_error err = {0};
    const double sig[] = {1.0, 4.0, 16.0};
    for (int k = 0; k < 3; k++) {
        CHECK_OK(gr_blur_fields(s, 1, NULL, W, H, sig[k], gr_blur_radius(sig[k]), d, dw, &err), err);
        for (int i = 0; i < W * H; i++) CHECK_NEAR(dst[i], 0.375, 1e-15);
        /* the blurred weight is 1 in the interior only: at a corner it is < 1 */
        CHECK(dw[0] < 1.0 && dw[0] > 0.0);
    }
    gr_image *img = gr_image_create(W, H, 2, NULL), *out = NULL;
    for (int i = 0; i < W * H * 2; i++) img->pixels[i] = (i % 2) ? 2.5f : -1.0f;
    CHECK_OK(gr_blur_image(img, 4.0, &out, &err), err);
    for (int i = 0; out && i < W * H * 2; i++) CHECK_NEAR(out->pixels[i], (i % 2) ? 2.5 : -1.0, 1e-6);
    gr_image_destroy(img);
    gr_image_destroy(out);
}

static double gauss(double x, double s) { return exp(-x * x / (2.0 * s * s)); }

/* Brute force: for every pixel, the 2-D weighted average over the (2r+1)^2 in-image taps. */
static void test_against_direct(void)
{
    enum { W = 13, H = 9 };
    double x[2][W * H], wt[W * H], out[2][W * H];
    unsigned s = 12345u;
    for (int i = 0; i < W * H; i++) {
        s = s * 1664525u + 1013904223u;
        x[0][i] = (double)(s >> 8) / 16777216.0;
        s = s * 1664525u + 1013904223u;
        x[1][i] = (double)(s >> 8) / 16777216.0 - 0.5;
        wt[i] = (i % 5 == 2) ? 0.0 : 1.0; /* a sparse mask */
    }
    /* A masked-out sample holds a huge value: it must have no influence at all. */
    x[0][2] = 1e30;
    const double sigma = 1.3;
    const int r = 4;
    const double *src[2] = {x[0], x[1]};
    double *dst[2] = {out[0], out[1]};
    gr_error err = {0};
    for (int pass = 0; pass < 2; pass++) {
        const double *w = pass ? wt : NULL;
        if (!pass) x[0][2] = 0.25; /* unweighted pass: an ordinary value */
        else x[0][2] = 1e30;
        CHECK_OK(gr_blur_fields(src, 2, w, W, H, sigma, r, dst, NULL, &err), err);
        for (int y = 0; y < H; y++)
            for (int xx = 0; xx < W; xx++)
                for (int c = 0; c < 2; c++) {
                    double num = 0.0, den = 0.0;
                    for (int dy = -r; dy <= r; dy++)
                        for (int dx = -r; dx <= r; dx++) {
                            int qx = xx + dx, qy = y + dy;
                            if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
                            double ww = w ? w[qy * W + qx] : 1.0;
                            if (ww == 0.0) continue;
                            double g = gauss(dx, sigma) * gauss(dy, sigma) * ww;
                            num += g * x[c][qy * W + qx];
                            den += g;
                        }
                    double want = den > 0.0 ? num / den : 0.0;
                    CHECK_MSG(fabs(out[c][y * W + xx] - want) <= 1e-13 * (1.0 + fabs(want)),
                              "pass %d (%d, %d) c %d: %.17g vs %.17g", pass, xx, y, c, out[c][y * W + xx], want);
                }
    }
}

/* An impulse far from the edges spreads its mass exactly once: the sum of the output is 1
 * and the centre value is w(0)^2 with w(0) = 1 / SUM_i exp(-i^2 / (2 sigma^2)). */
static void test_impulse(void)
{
    enum { W = 61, H = 61 }; /* the spread (radius 12) stays 12 px clear of the edges */
    static double src[W * H], dst[W * H];
    src[30 * W + 30] = 1.0;
    const double *s[1] = {src};
    double *d[1] = {dst};
    gr_error err = {0};
    CHECK_OK(gr_blur_fields(s, 1, NULL, W, H, 4.0, 12, d, NULL, &err), err);
    double sum = 0.0, k = 0.0;
    for (int i = 0; i < W * H; i++) sum += dst[i];
    for (int i = -12; i <= 12; i++) k += gauss(i, 4.0);
    CHECK_NEAR(sum, 1.0, 1e-14);
    CHECK_NEAR(dst[30 * W + 30], 1.0 / (k * k), 1e-15);
    CHECK(dst[30 * W + 30 + 13] == 0.0); /* beyond the 3-sigma truncation */
    CHECK(gr_blur_fields(s, 1, NULL, 0, H, 4.0, 12, d, NULL, &err) == GR_E_INPUT);
}

int main(void)
{
    test_kernel();
    test_constant();
    test_against_direct();
    test_impulse();
    CHECK_DONE();
}
