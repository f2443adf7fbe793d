/* Best scale fit a = <t, r> / <t, t> (least squares over the scored RGB samples) and the
 * degenerate cases: a known factor is recovered exactly, the fitted error is the minimum
 * (finite differences in a), an all-zero test leaves the fit undefined (a = 1), and no field
 * of the result is NaN for constant or zero images. */
#include <string.h>

#include "check.h"
#include "compare/metrics.h"

static int set_has_nan(const gr_metrics_set *s)
{
    int bad = isnan(s->scale) || isnan(s->ssim_y);
    for (int c = 0; c < GR_MCH_COUNT; c++) {
        const gr_channel_metrics *m = &s->ch[c];
        const double v[] = {m->ref_mean, m->test_mean, m->bias, m->mae, m->mse, m->rmse, m->rel_mse, m->rel_mse_eps,
                            m->peak_ref, m->psnr_ref_db, m->peak_idiff, m->psnr_idiff_db, m->max_abs_err, m->max_ref,
                            m->max_test, m->rmse_blur[0], m->rmse_blur[1], m->rmse_blur[2]};
        for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
            bad |= isnan(v[i]);
            if (i != 9 && i != 11) bad |= isinf(v[i]); /* only the PSNRs may be +inf */
        }
    }
    return bad;
}

static const gr_metrics_options fit_all = {.fit_scale = 1};

static void test_known_factor(void)
{
    gr_image *r = gr_image_create(9, 7, 3, NULL), *t = gr_image_create(9, 7, 3, NULL);
    for (int i = 0; i < 9 * 7 * 3; i++) {
        r->pixels[i] = (float)((i * 13) % 17) * 0.5f;
        t->pixels[i] = r->pixels[i] * 0.25f; /* exact: the real-time image at a quarter */
    }
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(r, t, &fit_all, &m, &err), err);
    CHECK(m.have_fit && m.fit_defined);
    CHECK(m.fit.scale == 4.0);
    CHECK(m.raw.scale == 1.0);
    for (int c = 0; c < GR_MCH_COUNT; c++) {
        CHECK(m.fit.ch[c].rmse == 0.0 && m.fit.ch[c].max_abs_err == 0.0 && m.fit.ch[c].bias == 0.0);
        CHECK(m.fit.ch[c].rmse_blur[2] == 0.0);
    }
    CHECK_NEAR(m.fit.ssim_y, 1.0, 1e-12);
    CHECK(m.raw.ch[GR_MCH_R].rmse > 0.5);
    CHECK(!set_has_nan(&m.raw) && !set_has_nan(&m.fit));
    gr_image_destroy(r);
    gr_image_destroy(t);
}

/* Gray 2 x 1: r = (1, 2), t = (1, 1): a = (1 + 2) / (1 + 1) = 1.5; fitted t = 1.5, 1.5 gives
 * d = 0.5, -0.5: bias 0, RMSE 0.5, max 0.5 at the first pixel. */
static void test_hand(void)
{
    const char *g[] = {"Y"};
    gr_image *r = gr_image_create(2, 1, 1, g), *t = gr_image_create(2, 1, 1, g);
    r->pixels[0] = 1, r->pixels[1] = 2, t->pixels[0] = 1, t->pixels[1] = 1;
    gr_metrics m;
    gr_error err = {0};
    CHECK_OK(gr_metrics_compute(r, t, &fit_all, &m, &err), err);
    CHECK(m.fit.scale == 1.5);
    CHECK(m.fit.ch[GR_MCH_Y].bias == 0.0);
    CHECK_NEAR(m.fit.ch[GR_MCH_Y].rmse, 0.5, 1e-15);
    CHECK(m.fit.ch[GR_MCH_Y].max_x == 0);
    gr_image_destroy(r);
    gr_image_destroy(t);
}

/* The fitted pooled MSE is a minimum: scaling the test by a (1 +- 1e-3) by hand and
 * comparing without a fit gives a larger MSE on both sides. */
static void test_minimum(void)
{
    gr_image *r = gr_image_create(11, 5, 3, NULL), *t = gr_image_create(11, 5, 3, NULL);
    gr_image *ts = gr_image_create(11, 5, 3, NULL);
    unsigned s = 4242u;
    for (int i = 0; i < 11 * 5 * 3; i++) {
        s = s * 1664525u + 1013904223u;
        r->pixels[i] = (float)((s >> 8) % 1000) / 100.0f;
        s = s * 1664525u + 1013904223u;
        t->pixels[i] = r->pixels[i] * 0.3f + (float)((s >> 8) % 1000) / 1000.0f;
    }
    gr_metrics m, mm;
    gr_error err = {0};
    gr_metrics_options o = {.fit_scale = 1, .skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(r, t, &o, &m, &err), err);
    const double a = m.fit.scale, best = m.fit.ch[GR_MCH_RGB].mse;
    CHECK(a > 2.0 && a < 4.0);
    CHECK(best < m.raw.ch[GR_MCH_RGB].mse);
    for (int k = -1; k <= 1; k += 2) {
        for (int i = 0; i < 11 * 5 * 3; i++) ts->pixels[i] = (float)(t->pixels[i] * a * (1.0 + k * 1e-3));
        gr_metrics_options no = {.skip_ssim = 1, .skip_blur = 1};
        CHECK_OK(gr_metrics_compute(r, ts, &no, &mm, &err), err);
        CHECK_MSG(mm.raw.ch[GR_MCH_RGB].mse > best, "a (1 %+d e-3): %.17g vs %.17g", k, mm.raw.ch[GR_MCH_RGB].mse, best);
    }
    gr_image_destroy(r);
    gr_image_destroy(t);
    gr_image_destroy(ts);
}

/* Constant and zero images, every option on: no NaN anywhere, degenerate fit stated. */
static void test_degenerate(void)
{
    const float vals[][2] = {{0, 0}, {0.5f, 0}, {0, 0.5f}, {2, 2}, {-1, 3}};
    for (int k = 0; k < 5; k++) {
        gr_image *r = gr_image_create(6, 4, 3, NULL), *t = gr_image_create(6, 4, 3, NULL);
        for (int i = 0; i < 6 * 4 * 3; i++) r->pixels[i] = vals[k][0], t->pixels[i] = vals[k][1];
        gr_metrics m;
        gr_error err = {0};
        CHECK_OK(gr_metrics_compute(r, t, &fit_all, &m, &err), err);
        CHECK_MSG(!set_has_nan(&m.raw) && !set_has_nan(&m.fit), "case %d", k);
        CHECK(!isnan(m.ssim_L) && m.ssim_L > 0.0);
        if (vals[k][1] == 0.0f) {
            CHECK(!m.fit_defined && m.fit.scale == 1.0); /* <t, t> = 0: no scale can be fitted */
        } else {
            CHECK(m.fit_defined && m.fit.scale == (double)vals[k][0] / vals[k][1]);
        }
        gr_image_destroy(r);
        gr_image_destroy(t);
    }
}

int main(void)
{
    test_known_factor();
    test_hand();
    test_minimum();
    test_degenerate();
    CHECK_DONE();
}
