/* Acceptance (issue 26): on the default view and the side view (camera yaw 120, pitch 20, as
 * integration.structure_views), with the real ground truth:
 *  - a featureless glow tuned to the truth's radial profile (the truth's own mean colour per
 *    0.5-degree bin of the angle to the refracted sun: glow_test.h) scores WORSE by the verdict
 *    than a beam-showing image of the same error after the fit: the truth plus a smooth noise
 *    field (white noise blurred by a Gaussian of height / 12 px, this file's random numbers)
 *    scaled, by bisection, until its relative RMSE of Y after the fit equals the glow's;
 *  - the truth blurred by 5 px (this file's own direct Gaussian, renormalized at the edges)
 *    has an equivalent blur of 5 +- 0.5 px against the baselines' ladder.
 * The verdict and the structure options are the ones `godrays run` uses (compare/registry.h,
 * report/profile.h's gr_profile_structure_options). Ground truths from the reference cache
 * (shared with integration.structure_views at the same sizes). Slow: the reduced variant
 * (GODRAYS_TEST_REDUCED=1) runs at 160 x 90 and checks the same properties. */
#include "check.h"
#include "scene_test.h"
#include "glow_test.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "compare/baseline.h"
#include "compare/metrics.h"
#include "compare/registry.h"
#include "reference/truth.h"
#include "report/profile.h"

static int reduced(void)
{
    const char *v = getenv("GODRAYS_TEST_REDUCED");
    return v && v[0] && strcmp(v, "0") != 0;
}

/* direct Gaussian blur of the first three channels, weights renormalized at the edges */
static gr_image *blur_direct(const gr_image *src, double sigma)
{
    const int w = src->width, h = src->height, R = (int)ceil(3.0 * sigma), nc = src->nchannels;
    gr_image *o = gr_image_create(w, h, 3, NULL);
    double *k = malloc((size_t)(2 * R + 1) * sizeof *k);
    for (int i = -R; i <= R; i++) k[i + R] = exp(-(double)(i * i) / (2 * sigma * sigma));
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s[3] = {0, 0, 0}, ws = 0;
            for (int v = y - R; v <= y + R; v++) {
                if (v < 0 || v >= h) continue;
                for (int u = x - R; u <= x + R; u++) {
                    if (u < 0 || u >= w) continue;
                    const double wt = k[u - x + R] * k[v - y + R];
                    const float *p = src->pixels + ((size_t)v * w + u) * nc;
                    for (int c = 0; c < 3; c++) s[c] += wt * p[c];
                    ws += wt;
                }
            }
            for (int c = 0; c < 3; c++) o->pixels[((size_t)y * w + x) * 3 + c] = (float)(s[c] / ws);
        }
    free(k);
    return o;
}

/* a smooth noise field, zero mean, unit RMS (one channel in all three) */
static gr_image *smooth_noise(int w, int h, double sigma)
{
    gr_image *n = gr_image_create(w, h, 3, NULL);
    uint64_t st = 0x9E3779B97F4A7C15ull;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        st = st * 6364136223846793005ull + 1442695040888963407ull;
        const float v = (float)((double)(st >> 11) / 9007199254740992.0 - 0.5);
        for (int c = 0; c < 3; c++) n->pixels[i * 3 + c] = v;
    }
    gr_image *b = blur_direct(n, sigma);
    gr_image_destroy(n);
    double s = 0, s2 = 0;
    const size_t np = (size_t)w * h;
    for (size_t i = 0; i < np; i++) s += b->pixels[i * 3];
    for (size_t i = 0; i < np; i++) s2 += (b->pixels[i * 3] - s / np) * (b->pixels[i * 3] - s / np);
    for (size_t i = 0; i < np * 3; i++) b->pixels[i] = (float)((b->pixels[i] - s / np) / sqrt(s2 / np));
    return b;
}

static void score(const gr_image *truth, const gr_image *test, const gr_structure_options *so, gr_metrics *m)
{
    gr_error err = {GR_OK, ""};
    gr_metrics_options mo = {.fit_scale = 1, .structure = so, .skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(truth, test, &mo, m, &err), err);
}

/* truth x exp(k noise): a smooth error of brightness over the truth's beams (a gain field, so
 * that the beams stay visible where the truth is dim; an additive field of the glow's RMSE
 * buries them there: 1.1 x the mean Y everywhere on the default view) */
static void add_noise(const gr_image *truth, const gr_image *noise, double k, gr_image *out)
{
    for (size_t i = 0; i < (size_t)truth->width * truth->height; i++)
        for (int c = 0; c < 3; c++)
            out->pixels[i * 3 + c] = (float)(truth->pixels[i * truth->nchannels + c] * exp(k * noise->pixels[i * 3 + c]));
}

static void view(int w, int h, int side)
{
    gr_error err = {GR_OK, ""};
    /* the side view on the plain grid, as integration.structure_views (the same cached truth) */
    const char *sets[3] = {"camera.yaw_deg=120", "camera.pitch_deg=20", "reference.near_cells_per_wavelength=0"};
    gr_scene *s = test_data_scene("default.json", w, h, sets, side ? 3 : 0);
    gr_image *truth = NULL;
    gr_truth_info info;
    CHECK_OK(gr_truth_image(s, NULL, &truth, &info, &err), err);
    if (!truth) {
        free(s);
        return;
    }
    float *ang = malloc((size_t)w * h * sizeof *ang);
    gr_structure_options so;
    CHECK(gr_profile_structure_options(s, ang, &so)); /* both views have a vanishing point */
    gr_image *glow = glow_test_image(truth, ang), *noise = smooth_noise(w, h, h / 12.0);
    gr_image *beams = gr_image_create(w, h, 3, NULL);
    gr_metrics mg, mb;
    score(truth, glow, &so, &mg);
    const double target = gr_metric_value(&mg.fit, GR_METRIC_REL_RMSE);
    double lo = 0.0, hi = 8.0; /* the error after the fit grows with k */
    for (int it = 0; it < 60; it++) {
        const double k = 0.5 * (lo + hi);
        add_noise(truth, noise, k, beams);
        score(truth, beams, &so, &mb);
        if (gr_metric_value(&mb.fit, GR_METRIC_REL_RMSE) < target) lo = k;
        else hi = k;
    }
    add_noise(truth, noise, 0.5 * (lo + hi), beams);
    score(truth, beams, &so, &mb);
    const double vg = gr_metric_value(&mg.fit, GR_METRIC_VERDICT), vb = gr_metric_value(&mb.fit, GR_METRIC_VERDICT);
    printf("%s view %d x %d (truth %s): glow: rel. RMSE %.4f, structure %.4f, verdict %.4f; beams x exp(%.3f noise): "
           "rel. RMSE %.4f, structure %.4f, verdict %.4f\n", side ? "side" : "default", w, h,
           info.cached ? "from the cache" : "rendered", target, mg.fit.structure_score, vg, 0.5 * (lo + hi),
           gr_metric_value(&mb.fit, GR_METRIC_REL_RMSE), mb.fit.structure_score, vb);
    CHECK_REL(gr_metric_value(&mb.fit, GR_METRIC_REL_RMSE), target, 1e-3); /* the same error */
    CHECK_MSG(vb < vg, "%s view: the glow's verdict %.4f is not worse than the beams' %.4f", side ? "side" : "default",
              vg, vb);

    /* the truth blurred by 5 px reads 5 +- 0.5 px */
    gr_baselines *bl = malloc(sizeof *bl);
    gr_metrics_options bo = {.structure = &so};
    CHECK_OK(gr_baselines_compute(truth, &bo, bl, &err), err);
    gr_image *b5 = blur_direct(truth, 5.0);
    gr_metrics m5;
    score(truth, b5, &so, &m5);
    int where = 9;
    const double eq = gr_equivalent_blur(bl, gr_metric_value(&m5.fit, GR_METRIC_VERDICT), &where);
    printf("  truth blurred by 5 px: verdict %.4f, equivalent blur %.3f px; constant image %.4f, black %.4f\n",
           gr_metric_value(&m5.fit, GR_METRIC_VERDICT), eq,
           gr_metric_value(&bl->m[GR_BASELINE_CONSTANT].fit, GR_METRIC_VERDICT),
           gr_metric_value(&bl->m[GR_BASELINE_BLACK].fit, GR_METRIC_VERDICT));
    CHECK_NEAR(eq, 5.0, 0.5);
    CHECK(where == 0);
    free(bl);
    gr_image_destroy(b5);
    gr_image_destroy(beams);
    gr_image_destroy(noise);
    gr_image_destroy(glow);
    gr_image_destroy(truth);
    free(ang);
    free(s);
}

int main(void)
{
    const int w = reduced() ? 160 : 320, h = reduced() ? 90 : 180;
    for (int side = 0; side < 2; side++) view(w, h, side);
    CHECK_DONE();
}
