/* Multi-scale RMSE (RMSE of the difference after a Gaussian blur of sigma 1, 4, 16 px,
 * normalized over the scored pixels). Oracles: a constant offset keeps its RMSE at every scale;
 * a +-d checkerboard (no large-scale error) vanishes at sigma 16 away from the edges; and a
 * brute-force 2-D evaluation, written independently here, on a random image with a mask. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compare/metrics.h"

static const gr_metrics_options blur_only = {.skip_ssim = 1};

static void test_offset(void)
{
    gr_image *a = gr_image_create(20, 10, 3, NULL), *b = gr_image_create(20, 10, 3, NULL);
    for (int i = 0; i < 20 * 10 * 3; i++) {
        a->pixels[i] = (float)(i % 7) * 0.125f;
        b->pixels[i] = a->pixels[i] + 0.0625f; /* exact in float */
    }
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, b, &blur_only, &m, &err), err);
    CHECK(m.raw.have_blur);
    for (int s = 0; s < GR_METRICS_NSCALES; s++)
        for (int c = 0; c < GR_MCH_COUNT; c++) CHECK_NEAR(m.raw.ch[c].rmse_blur[s], 0.0625, 1e-14);
    CHECK_NEAR(gr_metrics_blur_sigmas[0], 1.0, 0);
    CHECK_NEAR(gr_metrics_blur_sigmas[1], 4.0, 0);
    CHECK_NEAR(gr_metrics_blur_sigmas[2], 16.0, 0);
    gr_image_destroy(a);
    gr_image_destroy(b);
}

/* Pixel-scale error with the right large-scale distribution: the checkerboard +-0.25 has
 * RMSE 0.25, but its blur is tiny: in the interior the amplitude is 0.25 (SUM_i (-1)^i w_i)^2,
 * 5e-5 at sigma 1 and ~1e-30 at sigma 16; only the renormalized edges keep a residue. */
static void test_checkerboard(void)
{
    enum { W = 96, H = 96 };
    gr_image *a = gr_image_create(W, H, 3, NULL), *b = gr_image_create(W, H, 3, NULL);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                a->pixels[3 * (y * W + x) + c] = 1.0f;
                b->pixels[3 * (y * W + x) + c] = ((x + y) % 2) ? 1.25f : 0.75f;
            }
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, b, &blur_only, &m, &err), err);
    const gr_channel_metrics *g = &m.raw.ch[GR_MCH_G];
    CHECK_NEAR(g->rmse, 0.25, 1e-15);
    /* measured 5.1e-4, 1.1e-4, 2.6e-5 (edge residue only); bounds with a 5-10x margin */
    CHECK_MSG(g->rmse_blur[0] < 1e-2 * 0.25, "sigma 1 RMSE %g", g->rmse_blur[0]);
    CHECK_MSG(g->rmse_blur[2] < 1e-3 * 0.25, "sigma 16 RMSE %g", g->rmse_blur[2]);
    CHECK(g->rmse_blur[2] < g->rmse_blur[1] && g->rmse_blur[1] < g->rmse_blur[0]);
    gr_image_destroy(a);
    gr_image_destroy(b);
}

static double g1(int d, double s) { return exp(-(double)d * d / (2.0 * s * s)); }

static void test_against_direct(void)
{
    enum { W = 17, H = 12 };
    gr_image *a = gr_image_create(W, H, 3, NULL), *b = gr_image_create(W, H, 3, NULL);
    const char *mn[] = {"M"};
    gr_image *mask = gr_image_create(W, H, 1, mn);
    unsigned s = 99u;
    double d[3][W * H];
    unsigned char on[W * H];
    long n_on = 0;
    for (int p = 0; p < W * H; p++) {
        for (int c = 0; c < 3; c++) {
            s = s * 1664525u + 1013904223u;
            a->pixels[3 * p + c] = (float)((s >> 8) % 1000) / 500.0f;
            s = s * 1664525u + 1013904223u;
            b->pixels[3 * p + c] = (float)((s >> 8) % 1000) / 500.0f;
            d[c][p] = (double)b->pixels[3 * p + c] - (double)a->pixels[3 * p + c];
        }
        on[p] = (p % 3) != 1 && p % W < 14; /* an irregular mask */
        mask->pixels[p] = on[p] ? 1.0f : 0.0f;
        n_on += on[p];
    }
    gr_metrics_options o = blur_only;
    o.mask = mask;
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, b, &o, &m, &err), err);
    CHECK(m.n_scored == n_on);
    for (int si = 0; si < GR_METRICS_NSCALES; si++) {
        const double sig = gr_metrics_blur_sigmas[si];
        const int r = (int)ceil(3.0 * sig);
        double s2[GR_MCH_COUNT] = {0};
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                if (!on[y * W + x]) continue;
                double num[3] = {0}, den = 0.0;
                for (int qy = 0; qy < H; qy++)
                    for (int qx = 0; qx < W; qx++) {
                        if (!on[qy * W + qx] || abs(qx - x) > r || abs(qy - y) > r) continue;
                        double w = g1(qx - x, sig) * g1(qy - y, sig);
                        den += w;
                        for (int c = 0; c < 3; c++) num[c] += w * d[c][qy * W + qx];
                    }
                double dy = 0.0;
                for (int c = 0; c < 3; c++) {
                    double v = num[c] / den;
                    s2[c] += v * v;
                    dy += (c == 0 ? 0.2126 : c == 1 ? 0.7152 : 0.0722) * v;
                }
                s2[GR_MCH_Y] += dy * dy;
            }
        s2[GR_MCH_RGB] = s2[0] + s2[1] + s2[2];
        for (int c = 0; c < GR_MCH_COUNT; c++) {
            double want = sqrt(s2[c] / (double)(c == GR_MCH_RGB ? 3 * n_on : n_on));
            CHECK_MSG(fabs(m.raw.ch[c].rmse_blur[si] - want) <= 1e-12 * want, "sigma %g row %d: %.17g vs %.17g", sig, c,
                      m.raw.ch[c].rmse_blur[si], want);
        }
    }
    gr_image_destroy(a);
    gr_image_destroy(b);
    gr_image_destroy(mask);
}

int main(void)
{
    test_offset();
    test_checkerboard();
    test_against_direct();
    CHECK_DONE();
}
