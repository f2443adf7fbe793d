/* Which pixels are scored: the mask (first channel nonzero), the bound on the reference's
 * relative standard error (luminance, stderr_Y = SUM w_c stderr_c), the counts reported for
 * each, and the per-sample significance test |t - r| <= 2 stderr. Values by hand below. */
#include <string.h>

#include "check.h"
#include "compare/metrics.h"

static const char *ref_names[] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};

/* 4 x 1.   ref (R, G, B | stderr)            rel. stderr of Y     test
 *   p0  (1, 1, 1 | 0.1, 0.1, 0.1)           0.1 / 1 = 0.1        (1.15, 1.25, 1)
 *   p1  (1, 1, 1 | 0.6, 0.6, 0.6)           0.6 > 0.5: excluded  (5, 5, 5)
 *   p2  (0, 0, 0 | 0, 0, 0)                 0 / 0: counts as 0   (0, 0, 0.5)
 *   p3  (0, 0, 0 | 0.01, 0, 0)              > 0 over 0: inf      (9, 9, 9)
 * Scored with the default bound 0.5: p0, p2. Significance (z = 2):
 *   p0: |dR| 0.15 <= 0.2 no, |dG| 0.25 > 0.2 yes, |dB| 0 no; dY = 0.2126*0.15 + 0.7152*0.25
 *       = 0.21069 > 2 * 0.1 yes.   p2: dR = dG = 0 <= 0 no; dB = 0.5 > 0 yes; dY 0.0361 > 0 yes. */
static gr_image *make_ref(void)
{
    const float v[] = {1, 1, 1, 0.1f, 0.1f, 0.1f, 1, 1, 1, 0.6f, 0.6f, 0.6f,
                       0, 0, 0, 0, 0, 0, 0, 0, 0, 0.01f, 0, 0};
    gr_image *img = gr_image_create(4, 1, 6, ref_names);
    memcpy(img->pixels, v, sizeof v);
    return img;
}

static gr_image *make_test(void)
{
    const float v[] = {1.15f, 1.25f, 1, 5, 5, 5, 0, 0, 0.5f, 9, 9, 9};
    gr_image *img = gr_image_create(4, 1, 3, NULL);
    memcpy(img->pixels, v, sizeof v);
    return img;
}

static void test_stderr(void)
{
    gr_image *ref = make_ref(), *test = make_test();
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(ref, test, NULL, &m, &err), err);
    CHECK(m.have_stderr);
    CHECK_NEAR(m.stderr_bound, 0.5, 0);
    CHECK_NEAR(m.stderr_z, 2.0, 0);
    CHECK(m.n_scored == 2 && m.n_stderr_excluded == 2 && m.n_masked_out == 0);
    CHECK(m.raw.ch[GR_MCH_R].n_not_significant == 2);
    CHECK(m.raw.ch[GR_MCH_G].n_not_significant == 1);
    CHECK(m.raw.ch[GR_MCH_B].n_not_significant == 1);
    CHECK(m.raw.ch[GR_MCH_RGB].n_not_significant == 4);
    CHECK(m.raw.ch[GR_MCH_Y].n_not_significant == 0);
    /* metrics over p0 and p2 only: R bias (0.15 + 0) / 2, G MAE 0.25 / 2 */
    CHECK_NEAR(m.raw.ch[GR_MCH_R].bias, 0.15f / 2.0, 1e-7);
    CHECK_NEAR(m.raw.ch[GR_MCH_G].mae, 0.125, 1e-15);
    CHECK_NEAR(m.raw.ch[GR_MCH_B].max_abs_err, 0.5, 0);
    CHECK(m.raw.ch[GR_MCH_B].max_x == 2);

    /* A tighter bound 0.05 also drops p0 (0.1 > 0.05); p2 stays (rel. stderr 0). */
    gr_metrics_options o = {.stderr_bound = 0.05};
    CHECK_OK(gr_metrics_compute(ref, test, &o, &m, &err), err);
    CHECK(m.n_scored == 1 && m.n_stderr_excluded == 3);
    /* No bound: everything scored; p1 (|d| = 4 > 1.2) and p3 (|d| = 9) are significant except
     * p3's G and B (stderr 0, d 9: significant too): R not-significant = p0, p2. */
    o.stderr_bound = INFINITY;
    CHECK_OK(gr_metrics_compute(ref, test, &o, &m, &err), err);
    CHECK(m.n_scored == 4 && m.n_stderr_excluded == 0);
    CHECK(m.raw.ch[GR_MCH_R].n_not_significant == 2);
    CHECK(isinf(m.stderr_bound));

    /* A mask: 1-channel (1, 1, 0, 1): p2 masked out (counted as masked, not as excluded),
     * p1 and p3 excluded by the stderr bound: only p0 is scored. */
    const char *mname[] = {"Y"};
    gr_image *mask = gr_image_create(4, 1, 1, mname);
    const float mv[] = {1, 1, 0, 1};
    memcpy(mask->pixels, mv, sizeof mv);
    gr_metrics_options om = {.mask = mask};
    CHECK_OK(gr_metrics_compute(ref, test, &om, &m, &err), err);
    CHECK(m.n_masked_out == 1 && m.n_stderr_excluded == 2 && m.n_scored == 1);
    CHECK_NEAR(m.raw.ch[GR_MCH_G].bias, 0.25, 1e-15);
    /* only the mask's first channel counts: a 3-channel mask with zero R and nonzero G, B */
    gr_image *mask3 = gr_image_create(4, 1, 3, NULL);
    for (int p = 0; p < 4; p++) mask3->pixels[3 * p] = 0.0f, mask3->pixels[3 * p + 1] = mask3->pixels[3 * p + 2] = 1.0f;
    om.mask = mask3;
    CHECK_OK(gr_metrics_compute(ref, test, &om, &m, &err), err);
    CHECK(m.n_masked_out == 4 && m.n_scored == 0);
    /* nothing scored: every mean 0, PSNR +inf, SSIM 1, never NaN */
    CHECK(m.raw.ch[GR_MCH_Y].rmse == 0.0 && m.raw.ch[GR_MCH_Y].max_x == -1 && m.raw.ssim_y == 1.0);
    gr_image_destroy(mask);
    gr_image_destroy(mask3);
    gr_image_destroy(ref);
    gr_image_destroy(test);
}

/* Without stderr channels nothing is excluded whatever the bound, and no significance. */
static void test_no_stderr(void)
{
    gr_image *a = gr_image_create(3, 2, 3, NULL), *b = gr_image_create(3, 2, 3, NULL);
    b->pixels[0] = 1.0f;
    gr_metrics_options o = {.stderr_bound = 1e-9};
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(a, b, &o, &m, &err), err);
    CHECK(!m.have_stderr && m.n_scored == 6 && m.n_stderr_excluded == 0);
    CHECK(m.raw.ch[GR_MCH_R].n_not_significant == 0);
    gr_image_destroy(a);
    gr_image_destroy(b);
}

int main(void)
{
    test_stderr();
    test_no_stderr();
    CHECK_DONE();
}
