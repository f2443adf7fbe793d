/* The surface-bias probe's figures (reference/probe.c, gr_ref_probe_stats; docs/reference.md 4)
 * on hand-made per-level sums whose answers are worked out here. 4 probe pixels, one camera
 * sample each (count 1), levels h, 2h, 4h:
 *  - every pixel G = B = 1 at every level (no difference);
 *  - R = 0.5 at h, 0.5 + 0.01 at 2h, 0.5 + 0.01 + 0.04 at 4h (d2 / d1 = 4 in R alone).
 * The RGB mean's differences: d1 = 4 x 0.01 / 3, d2 = 4 x 0.04 / 3, v = 4 x 2.5 / 3, so the
 * order is log2(4) = 2 and the mean's relative difference d1 / v = 0.004; R's own is
 * d1_R / v_R = 0.04 / 2 = 0.02. The estimate is the worst channel's (issue 30: per channel),
 * 0.02 / 3, and the measured-order figure 0.02 / (2^2 - 1), the same here; the RGB mean's
 * figure (the code before) would have been 0.004 / 3, five times lower.
 * Then R's light is cut to 1e-4 of G's (R = 1e-4 x the above): below 1e-3 of the brightest
 * channel, it is left out of the worst, and the figures are the mean's: d1 / v with the mean
 * now (1e-4 x 0.01) / (2 + 0.5e-4) per pixel; the order stays 2 (both differences scale).
 * The signed per-pixel estimates (bias channels): (L_2h - L_h) / 3 per channel.
 * The block figure (gr_ref_block_bias): the 2 x 2 probe pixels make one block of 2 PROBE_STRIDE
 * image pixels a side; on an image with R = 0.5, G = B = 1 everywhere, the block's R estimate
 * (0.01 / 3) over max(block mean, image mean) = 0.5 is 0.02 / 3 (the RGB mean's, the code
 * before: (0.01 / 9) / (2.5 / 3), five times lower); with R at 1e-4 of G (image and sums),
 * R is left out and G, B have no bias: 0.
 * A fourth level (h with the cells near the camera 2x finer, where the probe holds them:
 * docs/reference.md 4, "The probe and the cells near the camera"): R = 0.5 - 0.003 and
 * G = 1 - 0.0075 there (B unchanged), so the near cells' own error is (L_h - L_h/2) 4/3 =
 * 0.004 in R and 0.01 in G for the estimate (order 2), twice the difference, 0.006 and 0.015,
 * for the conservative figures (order 1). Per pixel the errors add: the estimate is R's
 * (0.01 / 3 + 0.004) / 0.5 = 0.0146667 (G's 0.01 / 1 below it), the measured-order figure
 * R's (0.01 / 3 + 0.006) / 0.5 = 0.0186667 (the order stays 2 from the first three levels),
 * the signed bias channels R 0.0093333, G 0.015, B 0, and the block figure R's 0.0186667. */
#include <math.h>
#include <stdlib.h>
#include "check.h"
#include "image/image.h"
#include "reference/probe.h"
#include "reference/renderer.h"

enum { NP = 4 };

static void fill(double *sum[3], uint32_t *cnt[3], double scale_r)
{
    const double r[3] = {0.5, 0.51, 0.55};
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < NP; i++) {
            cnt[k][i] = 1;
            sum[k][i * 3 + 0] = scale_r * r[k];
            sum[k][i * 3 + 1] = 1.0;
            sum[k][i * 3 + 2] = 1.0;
        }
}

int main(void)
{
    double *sum[3];
    uint32_t *cnt[3];
    for (int k = 0; k < 3; k++) {
        sum[k] = malloc(NP * 3 * sizeof **sum);
        cnt[k] = malloc(NP * sizeof **cnt);
        if (!sum[k] || !cnt[k]) return 1;
    }
    gr_ref_renderer *r = calloc(1, sizeof *r);
    if (!r) return 1;

    fill(sum, cnt, 1.0);
    CHECK(gr_ref_probe_stats(r, sum, cnt, 3, NP, 2, 2, 0) == 0);
    printf("R carries the difference: estimate %.9g (expected %.9g), measured order %.9g, order %.6g\n", r->bias_rel,
           0.02 / 3.0, r->bias_rel_cons, r->bias_order);
    CHECK_MSG(fabs(r->bias_order - 2.0) < 1e-9, "order %.9g, expected 2", r->bias_order);
    CHECK_MSG(fabs(r->bias_rel - 0.02 / 3.0) < 1e-12, "estimate %.12g, expected the worst channel's %.12g (the mean's: %.12g)",
              r->bias_rel, 0.02 / 3.0, 0.004 / 3.0);
    CHECK_MSG(fabs(r->bias_rel_cons - 0.02 / 3.0) < 1e-12, "measured-order figure %.12g", r->bias_rel_cons);
    const int side = 2 * PROBE_STRIDE;
    gr_image *img = gr_image_create(side, side, 3, NULL);
    if (!img) return 1;
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) {
            float *px = gr_image_pixel(img, x, y);
            px[0] = 0.5f;
            px[1] = px[2] = 1.0f;
        }
    gr_ref_block_bias(r, img);
    printf("block figure %.9g (expected %.9g)\n", r->bias_block_p95, 0.02 / 3.0);
    CHECK_MSG(r->bias_blocks == 1 && fabs(r->bias_block_p95 - 0.02 / 3.0) < 1e-7, "block figure %.9g over %d blocks",
              r->bias_block_p95, r->bias_blocks);
    CHECK(r->bias_px != NULL);
    for (int i = 0; i < NP && r->bias_px; i++) {
        CHECK_MSG(fabs(r->bias_px[i * 3] - 0.01f / 3.0f) < 1e-7, "pixel %d: R's signed estimate %.9g", i, r->bias_px[i * 3]);
        CHECK_MSG(r->bias_px[i * 3 + 1] == 0.0f && r->bias_px[i * 3 + 2] == 0.0f, "pixel %d: G, B estimates not 0", i);
    }

    fill(sum, cnt, 1e-4);
    CHECK(gr_ref_probe_stats(r, sum, cnt, 3, NP, 2, 2, 0) == 0);
    const double mean_rel = (1e-4 * 0.01 / 3.0) / ((2.0 + 0.5e-4) / 3.0);
    printf("R at 1e-4 of G: estimate %.9g (expected the mean's %.9g)\n", r->bias_rel, mean_rel / 3.0);
    CHECK_MSG(fabs(r->bias_rel - mean_rel / 3.0) < 1e-15, "estimate %.12g, expected %.12g", r->bias_rel, mean_rel / 3.0);
    CHECK_MSG(fabs(r->bias_order - 2.0) < 1e-6, "order %.9g, expected 2", r->bias_order);
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) gr_image_pixel(img, x, y)[0] = 0.5e-4f;
    gr_ref_block_bias(r, img);
    CHECK_MSG(r->bias_blocks == 1 && r->bias_block_p95 == 0.0, "R at 1e-4: block figure %.9g, expected 0", r->bias_block_p95);

    /* the fourth level */
    fill(sum, cnt, 1.0);
    double *sum4[4] = {sum[0], sum[1], sum[2], malloc(NP * 3 * sizeof(double))};
    uint32_t *cnt4[4] = {cnt[0], cnt[1], cnt[2], malloc(NP * sizeof(uint32_t))};
    if (!sum4[3] || !cnt4[3]) return 1;
    for (int i = 0; i < NP; i++) {
        cnt4[3][i] = 1;
        sum4[3][i * 3 + 0] = 0.5 - 0.003;
        sum4[3][i * 3 + 1] = 1.0 - 0.0075;
        sum4[3][i * 3 + 2] = 1.0;
    }
    CHECK(gr_ref_probe_stats(r, sum4, cnt4, 4, NP, 2, 2, 0) == 0);
    printf("fourth level: estimate %.9g (expected %.9g), measured-order figure %.9g (expected %.9g), order %.6g\n",
           r->bias_rel, (0.01 / 3.0 + 0.004) / 0.5, r->bias_rel_cons, (0.01 / 3.0 + 0.006) / 0.5, r->bias_order);
    CHECK_MSG(fabs(r->bias_order - 2.0) < 1e-9, "fourth level: order %.9g, expected 2", r->bias_order);
    CHECK_MSG(fabs(r->bias_rel - (0.01 / 3.0 + 0.004) / 0.5) < 1e-12, "fourth level: estimate %.12g", r->bias_rel);
    CHECK_MSG(fabs(r->bias_rel_cons - (0.01 / 3.0 + 0.006) / 0.5) < 1e-12, "fourth level: measured-order figure %.12g",
              r->bias_rel_cons);
    for (int i = 0; i < NP && r->bias_px; i++) {
        CHECK_MSG(fabs(r->bias_px[i * 3] - (0.01 / 3.0 + 0.006)) < 1e-7, "fourth level: pixel %d R %.9g", i, r->bias_px[i * 3]);
        CHECK_MSG(fabs(r->bias_px[i * 3 + 1] - 0.015) < 1e-7, "fourth level: pixel %d G %.9g", i, r->bias_px[i * 3 + 1]);
        CHECK_MSG(r->bias_px[i * 3 + 2] == 0.0f, "fourth level: pixel %d B %.9g", i, r->bias_px[i * 3 + 2]);
    }
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) gr_image_pixel(img, x, y)[0] = 0.5f;
    gr_ref_block_bias(r, img);
    CHECK_MSG(r->bias_blocks == 1 && fabs(r->bias_block_p95 - (0.01 / 3.0 + 0.006) / 0.5) < 1e-6,
              "fourth level: block figure %.9g", r->bias_block_p95);
    free(sum4[3]);
    free(cnt4[3]);
    gr_image_destroy(img);

    free(r->bias_px);
    free(r);
    for (int k = 0; k < 3; k++) {
        free(sum[k]);
        free(cnt[k]);
    }
    CHECK_DONE();
}
