/* The 8 x 8 block noise of a render (reference/stats.c, block_noise; docs/reference.md 2.6
 * "Block noise") on hand-made batch sums whose answers are worked out here: a 32 x 24 image
 * (12 blocks), 8 batches, every pixel 1.0 in every batch except
 *  - block (2, 1), pixels x 16-23, y 8-15: G alternates 1 -+ 0.02 over the batches, so its
 *    block means do too: se = sqrt(8 * 0.02^2 / (8 * 7)) = 0.02 / sqrt 7 over the block mean 1;
 *  - block (0, 2): R alternates 1 -+ 0.01: 0.01 / sqrt 7;
 *  - block (3, 0): every channel 0.1, B alternating 0.1 -+ 0.003: normalized by the image's
 *    mean B (0.925), not its own mean 0.1 (which would make it the worst block at 0.0113).
 * The worst block, its place, and the percentiles (linear between ranks over the 12 sorted
 * values 0 x 9, 0.003/sqrt7/0.925, 0.01/sqrt7, 0.02/sqrt7); without blocks no place. */
#include <math.h>
#include <stdlib.h>
#include "check.h"
#include "reference/renderer.h"
#include "reference/stats.h"

enum { W = 32, H = 24, B = 8 };

static void set_block(ref_accum *a, int bx, int by, int ch, double base, double d, double other)
{
    for (int y = by * 8; y < by * 8 + 8; y++)
        for (int x = bx * 8; x < bx * 8 + 8; x++)
            for (int b = 0; b < B; b++)
                for (int c = 0; c < 3; c++) {
                    double v = c == ch ? base + (b % 2 ? d : -d) : other;
                    a->sum[(((size_t)y * W + x) * B + b) * 3 + c] = v;
                }
}

int main(void)
{
    ref_accum a = {W, H, B, NULL, NULL, NULL};
    a.sum = malloc((size_t)W * H * B * 3 * sizeof *a.sum);
    a.count = malloc((size_t)W * H * B * sizeof *a.count);
    if (!a.sum || !a.count) return 1;
    for (size_t i = 0; i < (size_t)W * H * B; i++) {
        a.count[i] = 1;
        for (int c = 0; c < 3; c++) a.sum[i * 3 + c] = 1.0;
    }
    set_block(&a, 2, 1, 1, 1.0, 0.02, 1.0);
    set_block(&a, 0, 2, 0, 1.0, 0.01, 1.0);
    set_block(&a, 3, 0, 2, 0.1, 0.003, 0.1);
    const double s7 = sqrt(7.0), mean_b = (704.0 + 64.0 * 0.1) / 768.0;
    const double v[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0.003 / s7 / mean_b, 0.01 / s7, 0.02 / s7};
    const double p95 = v[10] + 0.45 * (v[11] - v[10]), p99 = v[10] + 0.89 * (v[11] - v[10]);
    for (int threads = 1; threads <= 3; threads += 2) {
        ref_errors e;
        gr_status st;
        gr_ref_image_errors(&a, threads, 1, &e, &st);
        CHECK(st == GR_OK);
        CHECK_MSG(fabs(e.block8[2] - v[11]) < 1e-12, "worst block %.9g, expected %.9g", e.block8[2], v[11]);
        CHECK_MSG(e.block8_at[0] == 16 && e.block8_at[1] == 8, "worst block at (%d, %d), expected (16, 8)", e.block8_at[0],
                  e.block8_at[1]);
        CHECK_MSG(fabs(e.block8[1] - p95) < 1e-12 && fabs(e.block8_p99 - p99) < 1e-12 && e.block8[0] == 0.0,
                  "p95 %.9g (expected %.9g), p99 %.9g (%.9g), median %.9g (0)", e.block8[1], p95, e.block8_p99, p99, e.block8[0]);
        printf("%d threads: worst block %.6f %% at (%d, %d), p99 %.6f %%, p95 %.6f %%\n", threads, 100 * e.block8[2],
               e.block8_at[0], e.block8_at[1], 100 * e.block8_p99, 100 * e.block8[1]);
    }
    ref_errors e;
    gr_status st;
    gr_ref_image_errors(&a, 2, 0, &e, &st);
    CHECK_MSG(st == GR_OK && e.block8_at[0] == -1 && e.block8_at[1] == -1 && e.block8[2] == 0.0,
              "without blocks: at (%d, %d), max %g", e.block8_at[0], e.block8_at[1], e.block8[2]);
    free(a.sum);
    free(a.count);
    CHECK_DONE();
}
