/* Pointwise metrics (bias, MAE, MSE/RMSE, relative MSE, PSNR with both peaks, max error and
 * where) on tiny images whose values are worked out by hand in the comments; channel picking
 * (by name, first three, gray) and the scan-order tie rule of the max error; FLIP's truth half
 * kept between calls (options.flip_ref) gives the same FLIP, bit for bit, as does the fitted
 * set's FLIP alone (options.flip_fit_only). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compare/metrics.h"

static gr_image *make(int w, int h, int nc, const char *const *names, const float *v)
{
    gr_image *img = gr_image_create(w, h, nc, names);
    if (img) memcpy(img->pixels, v, sizeof(float) * (size_t)(w * h * nc));
    return img;
}

static const gr_metrics_options no_extras = {.skip_ssim = 1, .skip_blur = 1};

/* 3 x 1 RGB.
 *   ref  p0 = (1, 0.5, 0)     p1 = (0.5, 0.5, 0.5)   p2 = (0, 0.25, 1)
 *   test p0 = (1.5, 0.5, 0)   p1 = (0.25, 0.5, 0.5)  p2 = (0, 0.25, 0)
 *   d = t - r:  R: 0.5, -0.25, 0    G: 0, 0, 0    B: 0, 0, -1 */
static void test_hand_values(void)
{
    const float r[] = {1, 0.5f, 0, 0.5f, 0.5f, 0.5f, 0, 0.25f, 1};
    const float t[] = {1.5f, 0.5f, 0, 0.25f, 0.5f, 0.5f, 0, 0.25f, 0};
    gr_image *ref = make(3, 1, 3, NULL, r), *test = make(3, 1, 3, NULL, t);
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(ref, test, &no_extras, &m, &err), err);
    CHECK(m.n_pixels == 3 && m.n_scored == 3 && m.n_masked_out == 0 && !m.have_stderr);

    const gr_channel_metrics *R = &m.raw.ch[GR_MCH_R];
    CHECK_NEAR(R->bias, (0.5 - 0.25 + 0) / 3.0, 1e-15);
    CHECK_NEAR(R->mae, (0.5 + 0.25 + 0) / 3.0, 1e-15);
    CHECK_NEAR(R->mse, (0.25 + 0.0625) / 3.0, 1e-15);
    CHECK_NEAR(R->rmse, sqrt(0.3125 / 3.0), 1e-15);
    /* eps = 1e-2 mean(|r|)^2 = 1e-2 (1.5 / 3)^2 = 0.0025 */
    CHECK_NEAR(R->rel_mse_eps, 0.0025, 1e-17);
    CHECK_NEAR(R->rel_mse, (0.25 / (1.0 + 0.0025) + 0.0625 / (0.25 + 0.0025) + 0.0 / 0.0025) / 3.0, 1e-15);
    CHECK_NEAR(R->ref_mean, 0.5, 1e-15);
    CHECK_NEAR(R->test_mean, 1.75 / 3.0, 1e-15);
    /* HDR peak = max ref R = 1; idiff's peak = max(1, 1, 1.5) = 1.5 */
    CHECK_NEAR(R->peak_ref, 1.0, 0);
    CHECK_NEAR(R->psnr_ref_db, -10.0 * log10(0.3125 / 3.0), 1e-12);
    CHECK_NEAR(R->peak_idiff, 1.5, 0);
    CHECK_NEAR(R->psnr_idiff_db, 20.0 * log10(1.5) - 10.0 * log10(0.3125 / 3.0), 1e-12);
    CHECK_NEAR(R->max_abs_err, 0.5, 0);
    CHECK(R->max_x == 0 && R->max_y == 0 && R->max_c == -1);
    CHECK_NEAR(R->max_ref, 1.0, 0);
    CHECK_NEAR(R->max_test, 1.5, 0);
    CHECK(R->n_samples == 3);

    /* G is identical: every error 0 and PSNR +inf (stated convention), never NaN. */
    const gr_channel_metrics *G = &m.raw.ch[GR_MCH_G];
    CHECK(G->bias == 0.0 && G->mae == 0.0 && G->rmse == 0.0 && G->rel_mse == 0.0 && G->max_abs_err == 0.0);
    CHECK(isinf(G->psnr_ref_db) && G->psnr_ref_db > 0 && isinf(G->psnr_idiff_db));
    CHECK(G->max_x == 0 && G->max_y == 0); /* all equal: the first sample */

    const gr_channel_metrics *B = &m.raw.ch[GR_MCH_B];
    CHECK_NEAR(B->bias, -1.0 / 3.0, 1e-15);
    CHECK_NEAR(B->mae, 1.0 / 3.0, 1e-15);
    CHECK_NEAR(B->rmse, sqrt(1.0 / 3.0), 1e-15);
    CHECK(B->max_abs_err == 1.0 && B->max_x == 2 && B->max_y == 0);
    /* eps_B = 1e-2 (1.5/3)^2 = 0.0025 again; only p2 differs: 1 / (1 + 0.0025) / 3 */
    CHECK_NEAR(B->rel_mse, 1.0 / 1.0025 / 3.0, 1e-15);

    /* Pooled over the 9 samples (idiff's view): d = 0.5, 0, 0, -0.25, 0, 0, 0, 0, -1 */
    const gr_channel_metrics *P = &m.raw.ch[GR_MCH_RGB];
    CHECK(P->n_samples == 9);
    CHECK_NEAR(P->bias, (0.5 - 0.25 - 1.0) / 9.0, 1e-15);
    CHECK_NEAR(P->mae, 1.75 / 9.0, 1e-15);
    CHECK_NEAR(P->rmse, sqrt(1.3125 / 9.0), 1e-15);
    CHECK(P->max_abs_err == 1.0 && P->max_x == 2 && P->max_y == 0 && P->max_c == 2);
    CHECK_NEAR(P->peak_ref, 1.0, 0);
    CHECK_NEAR(P->peak_idiff, 1.5, 0);
    CHECK_NEAR(P->psnr_idiff_db, 20.0 * log10(1.5 / sqrt(1.3125 / 9.0)), 1e-12);
    /* eps = 1e-2 * (mean |r| over the 9 = 4.25/9)^2 */
    double e9 = 1e-2 * (4.25 / 9.0) * (4.25 / 9.0);
    CHECK_NEAR(P->rel_mse_eps, e9, 1e-17);
    CHECK_NEAR(P->rel_mse, (0.25 / (1.0 + e9) + 0.0625 / (0.25 + e9) + 1.0 / (1.0 + e9)) / 9.0, 1e-15);

    /* Luminance, Rec. 709: dY = 0.2126 dR + 0.7152 dG + 0.0722 dB per pixel:
     *   p0: 0.2126 * 0.5 = 0.1063   p1: 0.2126 * -0.25 = -0.05315   p2: 0.0722 * -1 = -0.0722
     *   Yr: p0 0.2126 + 0.3576 = 0.5702, p1 0.5, p2 0.1788 + 0.0722 = 0.251 (peak 0.5702) */
    const gr_channel_metrics *Y = &m.raw.ch[GR_MCH_Y];
    const double d0 = 0.1063, d1 = -0.05315, d2 = -0.0722;
    CHECK_NEAR(Y->bias, (d0 + d1 + d2) / 3.0, 1e-12);
    CHECK_NEAR(Y->mae, (0.1063 + 0.05315 + 0.0722) / 3.0, 1e-12);
    CHECK_NEAR(Y->mse, (d0 * d0 + d1 * d1 + d2 * d2) / 3.0, 1e-12);
    CHECK_NEAR(Y->peak_ref, 0.5702, 1e-12);
    CHECK_NEAR(Y->psnr_ref_db, 20.0 * log10(0.5702 / sqrt((d0 * d0 + d1 * d1 + d2 * d2) / 3.0)), 1e-9);
    CHECK(Y->max_x == 0);
    CHECK_NEAR(Y->max_abs_err, 0.1063, 1e-12);
    double ey = 1e-2 * pow((0.5702 + 0.5 + 0.251) / 3.0, 2.0);
    CHECK_NEAR(Y->rel_mse,
               (d0 * d0 / (0.5702 * 0.5702 + ey) + d1 * d1 / (0.25 + ey) + d2 * d2 / (0.251 * 0.251 + ey)) / 3.0, 1e-9);
    CHECK(!m.have_fit && !m.raw.have_ssim && !m.raw.have_blur);
    gr_image_destroy(ref);
    gr_image_destroy(test);
}

/* Two equal maxima: the first in scan order (row, then column, then channel) wins, as in
 * OpenImageIO's compare(). 2 x 2 gray, |d| = 0.5 at (1, 0) and (0, 1). */
static void test_ties(void)
{
    const float r[] = {0, 0, 0, 0}, t[] = {0, 0.5f, -0.5f, 0.25f};
    const char *gray[] = {"Y"};
    gr_image *ref = make(2, 2, 1, gray, r), *test = make(2, 2, 1, gray, t);
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(ref, test, &no_extras, &m, &err), err);
    CHECK(m.raw.ch[GR_MCH_G].max_x == 1 && m.raw.ch[GR_MCH_G].max_y == 0);
    /* pooled: gray counts three times, the first channel (R) is reported */
    CHECK(m.raw.ch[GR_MCH_RGB].max_c == 0 && m.raw.ch[GR_MCH_RGB].max_x == 1);
    /* all-zero reference: relative MSE uses the stated floor, huge but finite */
    CHECK_NEAR(m.raw.ch[GR_MCH_R].rel_mse_eps, GR_METRICS_RELMSE_FLOOR, 0);
    CHECK(isfinite(m.raw.ch[GR_MCH_R].rel_mse) && m.raw.ch[GR_MCH_R].rel_mse > 1e20);
    /* no positive reference value: the HDR peak falls back to 1 */
    CHECK_NEAR(m.raw.ch[GR_MCH_Y].peak_ref, 1.0, 0);
    CHECK_NEAR(m.raw.ch[GR_MCH_R].psnr_ref_db, -10.0 * log10((0.25 + 0.25 + 0.0625) / 4.0), 1e-12);
    gr_image_destroy(ref);
    gr_image_destroy(test);
}

/* Channel layouts: named RGB in any order (plus alpha and extras), first three, gray. */
static void test_layouts(void)
{
    int rgb[3];
    const char *abgr[] = {"A", "B", "G", "R", "Z"};
    gr_image *a = gr_image_create(1, 1, 5, abgr);
    gr_metrics_pick_rgb(a, rgb);
    CHECK(rgb[0] == 3 && rgb[1] == 2 && rgb[2] == 1);
    const char *xyz[] = {"X", "Yc", "Zc", "W"};
    gr_image *b = gr_image_create(1, 1, 4, xyz);
    gr_metrics_pick_rgb(b, rgb);
    CHECK(rgb[0] == 0 && rgb[1] == 1 && rgb[2] == 2);
    const char *ya[] = {"Y", "A"};
    gr_image *c = gr_image_create(1, 1, 2, ya);
    gr_metrics_pick_rgb(c, rgb);
    CHECK(rgb[0] == 0 && rgb[1] == 0 && rgb[2] == 0);

    /* A gray reference against an RGBA test stored B, G, R, A: pixel 1 differs in B by -0.5.
     * ref gray: 0.5, 1    test: (B, G, R, A) = (0.5, 0.5, 0.5, 1), (0.5, 1, 1, 1) */
    const char *gray[] = {"Y"}, *bgra[] = {"B", "G", "R", "A"};
    const float rv[] = {0.5f, 1.0f}, tv[] = {0.5f, 0.5f, 0.5f, 1, 0.5f, 1, 1, 1};
    gr_image *ref = make(2, 1, 1, gray, rv), *test = make(2, 1, 4, bgra, tv);
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(ref, test, &no_extras, &m, &err), err);
    CHECK(m.raw.ch[GR_MCH_R].mae == 0.0 && m.raw.ch[GR_MCH_G].mae == 0.0);
    CHECK_NEAR(m.raw.ch[GR_MCH_B].bias, -0.25, 0);
    CHECK(m.raw.ch[GR_MCH_B].max_x == 1);
    CHECK_NEAR(m.raw.ch[GR_MCH_Y].bias, -0.5 * 0.0722 / 2.0, 1e-15);
    CHECK(m.test_rgb[0] == 2 && m.test_rgb[2] == 0 && m.ref_rgb[1] == 0);
    gr_image_destroy(a);
    gr_image_destroy(b);
    gr_image_destroy(c);
    gr_image_destroy(ref);
    gr_image_destroy(test);
}

/* Bad inputs: each is an error with one line naming the problem, never a crash. */
static void test_errors(void)
{
    gr_image *a = gr_image_create(2, 2, 3, NULL), *b = gr_image_create(3, 2, 3, NULL);
    gr_metrics m;
    gr_error err = {0};
    CHECK(gr_metrics_compute(a, b, NULL, &m, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "2 x 2") && strstr(err.msg, "3 x 2") && !strchr(err.msg, '\n'));
    CHECK(gr_metrics_compute(NULL, a, NULL, &m, &err) == GR_E_INPUT);
    CHECK(gr_metrics_compute(a, a, NULL, NULL, &err) == GR_E_INPUT);
    gr_metrics_options o = {.mask = b};
    CHECK(gr_metrics_compute(a, a, &o, &m, &err) == GR_E_INPUT && strstr(err.msg, "mask"));
    gr_metrics_options o2 = {.stderr_bound = -1.0};
    CHECK(gr_metrics_compute(a, a, &o2, &m, &err) == GR_E_INPUT && strstr(err.msg, "bound"));
    gr_image *c = gr_image_create(2, 2, 3, NULL);
    a->pixels[4] = NAN;
    CHECK(gr_metrics_compute(a, c, NULL, &m, &err) == GR_E_INPUT && strstr(err.msg, "reference"));
    CHECK(gr_metrics_compute(c, a, NULL, &m, &err) == GR_E_INPUT && strstr(err.msg, "test"));
    gr_image_destroy(a);
    gr_image_destroy(c);
    gr_image_destroy(b);
}

/* options.flip_ref: made at the first call, kept while the truth and settings match, remade
 * for another truth; every FLIP result the same bytes as without it. */
static void test_flip_kept(void)
{
    const int w = 48, h = 32;
    gr_image *ref = gr_image_create(w, h, 3, NULL), *ref2 = gr_image_create(w, h, 3, NULL);
    gr_image *test = gr_image_create(w, h, 3, NULL);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                const size_t i = 3 * ((size_t)y * w + (size_t)x) + (size_t)c;
                ref->pixels[i] = 0.05f + 0.02f * (float)x * (float)(c + 1) + ((x / 6 + y / 6) % 2 ? 0.5f : 0.0f);
                ref2->pixels[i] = 2.0f * ref->pixels[i] + 0.1f;
                test->pixels[i] = 0.7f * ref->pixels[i] + (((x + y) % 5) ? 0.0f : 0.3f);
            }
    gr_flip_options fo = {.mode = GR_FLIP_HDR};
    gr_metrics_options o = {.fit_scale = 1, .skip_ssim = 1, .skip_blur = 1, .flip = &fo};
    gr_flip_reference *keep = NULL;
    gr_metrics_options ok = o;
    ok.flip_ref = &keep;
    gr_metrics *m = malloc(3 * sizeof *m);
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(ref, test, &o, &m[0], &err), err);
    CHECK_OK(gr_metrics_compute(ref, test, &ok, &m[1], &err), err);
    CHECK(keep != NULL && gr_flip_reference_matches(keep, ref, &fo));
    const gr_flip_reference *first = keep;
    CHECK_OK(gr_metrics_compute(ref, test, &ok, &m[2], &err), err);
    CHECK(keep == first); /* kept */
    CHECK(m[0].raw.have_flip && m[0].have_fit && m[0].fit.have_flip && m[0].raw.flip.mean > 0.0);
    for (int k = 1; k < 3; k++) {
        CHECK(memcmp(&m[0].raw.flip, &m[k].raw.flip, sizeof m[0].raw.flip) == 0);
        CHECK(memcmp(&m[0].fit.flip, &m[k].fit.flip, sizeof m[0].fit.flip) == 0);
    }
    /* the fitted set's FLIP alone (a search): the same bytes, none for the raw set */
    gr_metrics_options of = ok;
    of.flip_fit_only = 1;
    CHECK_OK(gr_metrics_compute(ref, test, &of, &m[1], &err), err);
    CHECK(!m[1].raw.have_flip && m[1].fit.have_flip);
    CHECK(memcmp(&m[0].fit.flip, &m[1].fit.flip, sizeof m[0].fit.flip) == 0);
    of.flip_ref = NULL;
    CHECK_OK(gr_metrics_compute(ref, test, &of, &m[1], &err), err);
    CHECK(!m[1].raw.have_flip && memcmp(&m[0].fit.flip, &m[1].fit.flip, sizeof m[0].fit.flip) == 0);
    /* another truth: remade for it, and its FLIP as without */
    CHECK_OK(gr_metrics_compute(ref2, test, &o, &m[0], &err), err);
    CHECK_OK(gr_metrics_compute(ref2, test, &ok, &m[1], &err), err);
    CHECK(gr_flip_reference_matches(keep, ref2, &fo) && !gr_flip_reference_matches(keep, ref, &fo));
    CHECK(memcmp(&m[0].raw.flip, &m[1].raw.flip, sizeof m[0].raw.flip) == 0);
    CHECK(memcmp(&m[0].fit.flip, &m[1].fit.flip, sizeof m[0].fit.flip) == 0);
    gr_flip_reference_destroy(keep);
    free(m);
    gr_image_destroy(ref);
    gr_image_destroy(ref2);
    gr_image_destroy(test);
}

int main(void)
{
    test_hand_values();
    test_ties();
    test_layouts();
    test_errors();
    test_flip_kept();
    CHECK_DONE();
}
