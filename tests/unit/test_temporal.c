/* Sequence metrics (src/compare/temporal.c) on synthetic sequences with known answers:
 *  - beams turning at a known rate (a radial pattern rotated 1.0 degree per frame in the truth,
 *    1.5 in the test): drifts 1.0 and 1.5 degrees, drift error 0.5;
 *  - a truth with Gaussian noise of known standard deviation s (and stderr channels saying so)
 *    against the noiseless test: raw frame-difference RMSE sqrt(2) s, 0 once the truth's noise
 *    is taken out; per-frame RMSE s;
 *  - a test that flickers by +-F on every pixel: frame-difference error 2 F (noise taken out),
 *    and the flicker ratio from the noiseless images' own changes. */
#include "check.h"

#include <string.h>

#include "compare/temporal.h"
#include "core/rng.h"

#define W 192
#define H 192
#define NF 4
#define PI 3.14159265358979323846

static gr_image *frame(double rot_deg, double noise, double flicker, int seed)
{
    static const char *const names[6] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    gr_image *img = gr_image_create(W, H, 6, names);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const double th = atan2(y + 0.5 - 96.0, x + 0.5 - 96.0);
            /* 12 beams plus a 5-beam component: not periodic within the drift search */
            double v = 1.0 + 0.4 * cos(12.0 * (th - rot_deg * PI / 180.0)) + 0.2 * cos(5.0 * (th - rot_deg * PI / 180.0));
            v += flicker;
            if (noise > 0) {
                gr_rng r = gr_rng_make((uint64_t)seed, 1, (uint64_t)(y * W + x));
                const double u1 = 1.0 - gr_rng_double(&r), u2 = gr_rng_double(&r);
                v += noise * sqrt(-2.0 * log(u1)) * cos(2.0 * PI * u2);
            }
            float *p = gr_image_pixel(img, x, y);
            p[0] = p[1] = p[2] = (float)v;
            p[3] = p[4] = p[5] = (float)noise;
        }
    return img;
}

int main(void)
{
    gr_error err = {0};
    gr_image *ref[NF], *test[NF];
    gr_temporal_pair pairs[NF - 1];
    gr_temporal_frame frames[NF];
    gr_temporal_summary sum;
    gr_temporal_options o = {.structure = {.vp_x = 96, .vp_y = 96, .sigma_fine_px = 1, .sigma_coarse_px = 4}};
    o.drift_r0 = 30, o.drift_r1 = 90;

    /* 1. drift */
    for (int i = 0; i < NF; i++) ref[i] = frame(1.0 * i, 0, 0, 0), test[i] = frame(1.5 * i, 0, 0, 0);
    CHECK_OK(gr_temporal_compute((const gr_image *const *)ref, (const gr_image *const *)test, NF, &o, frames, pairs,
                                 &sum, &err), err);
    CHECK(sum.have_drift && sum.have_stderr);
    for (int i = 0; i < NF - 1; i++) {
        printf("pair %d: drift truth %.4f deg, test %.4f deg\n", i, pairs[i].drift_ref_deg, pairs[i].drift_test_deg);
        CHECK_NEAR(pairs[i].drift_ref_deg, 1.0, 0.05);
        CHECK_NEAR(pairs[i].drift_test_deg, 1.5, 0.05);
    }
    CHECK_NEAR(sum.drift_err_mean_deg, 0.5, 0.05);
    for (int i = 0; i < NF; i++) gr_image_destroy(ref[i]), gr_image_destroy(test[i]);

    /* 2. a noisy truth (s = 0.05) against the noiseless test */
    const double s = 0.05;
    for (int i = 0; i < NF; i++) ref[i] = frame(1.0 * i, s, 0, 100 + i), test[i] = frame(1.0 * i, 0, 0, 0);
    o.skip_drift = 1;
    CHECK_OK(gr_temporal_compute((const gr_image *const *)ref, (const gr_image *const *)test, NF, &o, frames, pairs,
                                 &sum, &err), err);
    CHECK(sum.have_stderr && !sum.have_drift);
    for (int i = 0; i < NF - 1; i++) {
        printf("noise pair %d: raw %.5f (expect %.5f), truth noise %.5f, corrected %.5f\n", i, pairs[i].diff_rmse_raw,
               sqrt(2.0) * s, pairs[i].truth_noise_rms, pairs[i].diff_rmse);
        CHECK_REL(pairs[i].diff_rmse_raw, sqrt(2.0) * s, 0.02);
        CHECK_REL(pairs[i].truth_noise_rms, sqrt(2.0) * s, 1e-6);
        CHECK(pairs[i].diff_rmse < 0.15 * s); /* statistical: raw^2 - noise^2 ~ +-1 % of 2 s^2 */
    }
    for (int i = 0; i < NF; i++) CHECK_REL(frames[i].rmse_y, s, 0.02);

    /* 3. the test flickers by +-F: error 2 F after the noise is taken out */
    const double F = 0.03;
    for (int i = 0; i < NF; i++) gr_image_destroy(test[i]), test[i] = frame(1.0 * i, 0, (i & 1) ? F : -F, 0);
    CHECK_OK(gr_temporal_compute((const gr_image *const *)ref, (const gr_image *const *)test, NF, &o, frames, pairs,
                                 &sum, &err), err);
    /* flicker ratio: the noiseless truth's changes dS and the test's dS +- 2F */
    double sd2 = 0, st2 = 0;
    for (int i = 0; i + 1 < NF; i++) {
        gr_image *a = frame(1.0 * i, 0, 0, 0), *b = frame(1.0 * (i + 1), 0, 0, 0);
        const double sg = (i & 1) ? -2.0 * F : 2.0 * F;
        for (size_t p = 0; p < (size_t)W * H; p++) {
            const double d = (double)b->pixels[6 * p] - (double)a->pixels[6 * p];
            sd2 += d * d, st2 += (d + sg) * (d + sg);
        }
        gr_image_destroy(a), gr_image_destroy(b);
    }
    printf("flicker: error %.5f (expect %.5f), flicker ratio %.4f (expect %.4f)\n", sum.diff_rmse, 2 * F,
           sum.flicker_ratio, sqrt(st2 / sd2));
    CHECK_REL(sum.diff_rmse, 2.0 * F, 0.03);
    CHECK_REL(sum.flicker_ratio, sqrt(st2 / sd2), 0.03);
    CHECK(sum.flicker_ratio > 1.0);

    /* bad input */
    CHECK(gr_temporal_compute((const gr_image *const *)ref, (const gr_image *const *)test, 1, &o, NULL, NULL, &sum,
                              &err) == GR_E_INPUT && strstr(err.msg, "2 frames"));
    gr_image *small = gr_image_create(8, 8, 3, NULL);
    gr_image *keep = test[2];
    test[2] = small;
    CHECK(gr_temporal_compute((const gr_image *const *)ref, (const gr_image *const *)test, NF, &o, NULL, NULL, &sum,
                              &err) == GR_E_INPUT && strstr(err.msg, "test frame 2"));
    test[2] = keep;
    gr_image_destroy(small);
    for (int i = 0; i < NF; i++) gr_image_destroy(ref[i]), gr_image_destroy(test[i]);
    CHECK_DONE();
}
