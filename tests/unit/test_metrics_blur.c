/* Gaussian blur (normalized convolution) used by the multi-scale RMSE and SSIM. Oracles: the
 * kernel's closed form and unit sum, a constant image staying constant up to the edges (the
 * truncated kernel is renormalized there), a brute-force 2-D weighted convolution written
 * independently here, and mass conservation of an interior impulse; and the same bits as a
 * plain scalar copy of the separable loops in the same order (gr_blur_fields may run as its
 * AVX2 clone, common/clones.h: its numbers must not depend on the CPU). */
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

/* gr_blur_fields against the same separable sums written here one element at a time, in its
 * order (horizontal taps left to right from 0.0, then vertical taps top to bottom from 0.0,
 * then the division by the weight's sum): equal to the bit, on a 67 x 41 image (odd widths:
 * the vector loops' remainders) with and without a weight field, sigma 3 and 9 (radius 9 and
 * 27: kernels wider than the image in y). */
static void test_same_bits_as_scalar(void)
{
    enum { W = 67, H = 41, N = W * H };
    static double x[2][N], wt[N], out[2][N], ow[N], hor[3][N], want[2][N], wantw[N];
    unsigned s = 777u;
    for (int i = 0; i < N; i++) {
        s = s * 1664525u + 1013904223u;
        x[0][i] = (double)(s >> 8) / 16777216.0 * 3.0;
        s = s * 1664525u + 1013904223u;
        x[1][i] = (double)(s >> 8) / 16777216.0 - 0.5;
        wt[i] = (i % 7 == 3) ? 0.0 : 0.25 + (double)(i % 4) * 0.5;
    }
    const double *src[2] = {x[0], x[1]};
    double *dst[2] = {out[0], out[1]};
    gr_error err = {0};
    const double sig[2] = {3.0, 9.0};
    for (int k = 0; k < 2; k++)
        for (int pass = 0; pass < 2; pass++) {
            const double *w = pass ? wt : NULL;
            const int r = gr_blur_radius(sig[k]);
            double g[2 * 27 + 1];
            CHECK_OK(gr_gaussian_kernel(sig[k], r, g, &err), err);
            CHECK_OK(gr_blur_fields(src, 2, w, W, H, sig[k], r, dst, ow, &err), err);
            /* volatile: one multiply and one add at a time, as the library's loops */
            for (int f = 0; f < 3; f++)
                for (int y = 0; y < H; y++)
                    for (int xx = 0; xx < W; xx++) {
                        volatile double a = 0.0;
                        for (int i = -r; i <= r; i++) {
                            if (xx + i < 0 || xx + i >= W) continue;
                            const int q = y * W + xx + i;
                            const double pw = w ? w[q] : 1.0;
                            const double v = f == 2 ? pw : (!w ? x[f][q] : (w[q] == 0.0 ? 0.0 : w[q] * x[f][q]));
                            volatile double t = g[i + r] * v;
                            a = a + t;
                        }
                        hor[f][y * W + xx] = a;
                    }
            for (int y = 0; y < H; y++)
                for (int xx = 0; xx < W; xx++) {
                    double a3[3];
                    for (int f = 0; f < 3; f++) {
                        volatile double a = 0.0;
                        for (int j = -r; j <= r; j++) {
                            if (y + j < 0 || y + j >= H) continue;
                            volatile double t = g[j + r] * hor[f][(y + j) * W + xx];
                            a = a + t;
                        }
                        a3[f] = a;
                    }
                    for (int c = 0; c < 2; c++) want[c][y * W + xx] = a3[2] > 0.0 ? a3[c] / a3[2] : 0.0;
                    wantw[y * W + xx] = a3[2];
                }
            int bad = 0;
            for (int i = 0; i < N; i++)
                bad += out[0][i] != want[0][i] || out[1][i] != want[1][i] || ow[i] != wantw[i];
            CHECK_MSG(bad == 0, "sigma %g, %s weights: %d pixels differ from the scalar loops in some bit", sig[k],
                      w ? "with" : "without", bad);
        }
}

int main(void)
{
    test_kernel();
    test_same_bits_as_scalar();
    test_constant();
    test_against_direct();
    test_impulse();
    CHECK_DONE();
}
