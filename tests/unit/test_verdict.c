/* The verdict (compare/registry.h) and the baselines (compare/baseline.h), on synthetic images:
 *  - the verdict's weights are tune's default objective (GR_TUNE_DEFAULT_OBJECTIVE parsed as
 *    `tune --objective` parses it), and the verdict of a set equals gr_tune_value of the default
 *    objective, and (rel. RMSE of Y + structure score) / 2 computed here from the set's fields;
 *    without the structure term it is the relative RMSE alone;
 *  - the equivalent blur: a beam pattern around a vanishing point blurred by a 5 px Gaussian
 *    (this file's own direct convolution, renormalized at the edges) reads 5 +- 0.5 px; the
 *    ladder is monotone; the ends say "<" and ">";
 *  - the baselines: the constant image's error after the fit is the truth's coefficient of
 *    variation of Y (std / mean), black's is sqrt(1 + cv^2) (the fit is undefined for black),
 *    both computed here; a technique whose verdict is not below the constant's is flagged. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "compare/baseline.h"
#include "compare/blur.h"
#include "compare/metrics.h"
#include "compare/registry.h"
#include "report/leaderboard.h"
#include "scene/scene.h"
#include "tune/objective.h"

#define W 160
#define H 90
#define VPX 80.0
#define VPY 24.0

/* beams around (VPX, VPY): 23 streaks per turn over a glow falling with the distance */
static gr_image *beams_image(void)
{
    gr_image *img = gr_image_create(W, H, 3, NULL);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const double dx = x + 0.5 - VPX, dy = y + 0.5 - VPY, r = sqrt(dx * dx + dy * dy), th = atan2(dy, dx);
            const double streak = pow(0.5 + 0.5 * cos(23.0 * th + 0.02 * r), 6.0);
            const double v = (0.2 + 2.0 * streak) * 30.0 / (r + 10.0) + 0.05;
            float *p = gr_image_pixel(img, x, y);
            p[0] = (float)(0.4 * v), p[1] = (float)(0.8 * v), p[2] = (float)(1.0 * v);
        }
    return img;
}

/* independent Gaussian blur: direct 2-D sum over the image, weights renormalized at the edges */
static gr_image *blur_direct(const gr_image *src, double sigma)
{
    gr_image *o = gr_image_create(W, H, 3, NULL);
    const int R = (int)ceil(3.0 * sigma);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double s[3] = {0, 0, 0}, ws = 0;
            for (int v = y - R; v <= y + R; v++)
                for (int u = x - R; u <= x + R; u++) {
                    if (u < 0 || v < 0 || u >= W || v >= H || abs(u - x) > R || abs(v - y) > R) continue;
                    const double w = exp(-((u - x) * (u - x) + (v - y) * (v - y)) / (2 * sigma * sigma));
                    const float *p = gr_image_pixel((gr_image *)src, u, v);
                    for (int c = 0; c < 3; c++) s[c] += w * p[c];
                    ws += w;
                }
            float *q = gr_image_pixel(o, x, y);
            for (int c = 0; c < 3; c++) q[c] = (float)(s[c] / ws);
        }
    return o;
}

static double lum(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

static void weights_test(void)
{
    gr_error err = {GR_OK, ""};
    double wt[GR_METRIC_MAX], wv[GR_METRIC_MAX];
    CHECK_OK(gr_tune_weights_parse("--objective", GR_TUNE_DEFAULT_OBJECTIVE, wt, &err), err);
    gr_metric_verdict_weights(wv);
    for (int k = 0; k < GR_METRIC_MAX; k++) CHECK_MSG(wt[k] == wv[k], "weight %d: tune %g, verdict %g", k, wt[k], wv[k]);
    CHECK(wv[GR_METRIC_RMSE] > 0 && wv[GR_METRIC_STRUCTURE] == wv[GR_METRIC_RMSE]);
    const gr_metric_desc *d = gr_metric_at(gr_metric_find("verdict"));
    CHECK(d && d->better == GR_METRIC_LOWER && d->best == 0.0 && d->leaderboard);
}

/* verdict == tune's default objective == (rel RMSE + S) / 2 on a computed set */
static void value_test(const gr_image *truth, const gr_image *test, const gr_structure_options *so)
{
    gr_error err = {GR_OK, ""};
    gr_metrics m;
    gr_metrics_options mo = {.fit_scale = 1, .structure = so};
    CHECK_OK(gr_metrics_compute(truth, test, &mo, &m, &err), err);
    gr_tune_problem *p = calloc(1, sizeof *p);
    p->metric = GR_TM_WEIGHTED;
    CHECK_OK(gr_tune_weights_parse("--objective", GR_TUNE_DEFAULT_OBJECTIVE, p->weights, &err), err);
    const gr_channel_metrics *y = &m.fit.ch[GR_MCH_Y];
    const double by_hand = (y->rmse / y->ref_mean + m.fit.structure_score) / 2.0;
    const double v = gr_metric_value(&m.fit, GR_METRIC_VERDICT);
    CHECK(m.fit.have_structure);
    CHECK_NEAR(v, by_hand, 1e-12 * by_hand);
    CHECK_NEAR(v, gr_tune_value(p, &m.fit), 1e-12 * by_hand);
    mo.structure = NULL; /* no vanishing point: the error term alone */
    CHECK_OK(gr_metrics_compute(truth, test, &mo, &m, &err), err);
    CHECK_NEAR(gr_metric_value(&m.fit, GR_METRIC_VERDICT), m.fit.ch[GR_MCH_Y].rmse / m.fit.ch[GR_MCH_Y].ref_mean, 1e-12);
    CHECK_NEAR(gr_metric_value(&m.fit, GR_METRIC_VERDICT), gr_tune_value(p, &m.fit), 1e-12);
    free(p);
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    weights_test();
    gr_image *truth = beams_image(), *b5 = blur_direct(truth, 5.0);
    gr_structure_options so = {.vp_x = VPX, .vp_y = VPY};
    value_test(truth, b5, &so);

    gr_baselines *bl = calloc(1, sizeof *bl);
    gr_metrics_options mo = {.structure = &so};
    CHECK_OK(gr_baselines_compute(truth, &mo, bl, &err), err);
    CHECK(bl->n_ladder == GR_BASELINE_LADDER_N);
    CHECK_NEAR(bl->sigma_px[0], 0.5, 1e-12);
    CHECK_NEAR(bl->sigma_px[GR_BASELINE_LADDER_N - 1], 64.0, 1e-9);
    for (int k = 1; k < bl->n_ladder; k++) CHECK(bl->envelope[k] >= bl->envelope[k - 1]);
    for (int k = 0; k < bl->n_ladder; k++) printf("ladder sigma %6.3f px: verdict %.4f\n", bl->sigma_px[k], bl->verdict[k]);
    /* the baselines run as jobs on a few threads (common/parallel.h): each rung's verdict and the
     * constant baseline's numbers are those of the same computation done here, one at a time */
    {
        int rgb[3];
        gr_metrics_pick_rgb(truth, rgb);
        gr_image *tr = gr_image_create(truth->width, truth->height, 3, NULL), *flat = gr_image_create(truth->width, truth->height, 3, NULL);
        CHECK(tr && flat);
        const size_t np = (size_t)truth->width * (size_t)truth->height;
        double mean[3] = {0, 0, 0};
        for (size_t p = 0; tr && p < np; p++)
            for (int c = 0; c < 3; c++) {
                tr->pixels[3 * p + (size_t)c] = truth->pixels[p * (size_t)truth->nchannels + (size_t)rgb[c]];
                mean[c] += tr->pixels[3 * p + (size_t)c];
            }
        gr_metrics_options lo = mo;
        lo.fit_scale = 1, lo.flip = NULL, lo.skip_ssim = 1, lo.skip_blur = 1, lo.skip_extra = 1;
        gr_metrics *m1 = malloc(sizeof *m1);
        CHECK(m1 != NULL);
        for (int k = 0; tr && m1 && k < bl->n_ladder; k++) {
            gr_image *bk = NULL;
            CHECK_OK(gr_blur_image(tr, bl->sigma_px[k], &bk, &err), err);
            CHECK_OK(gr_metrics_compute(truth, bk, &lo, m1, &err), err);
            const double v = gr_metric_value(&m1->fit, GR_METRIC_VERDICT);
            CHECK_MSG(v == bl->verdict[k] || (isnan(v) && isnan(bl->verdict[k])), "rung %d: %.17g here, %.17g in the jobs", k, v,
                      bl->verdict[k]);
            gr_image_destroy(bk);
        }
        gr_metrics_options co = mo;
        co.fit_scale = 1;
        for (size_t p = 0; flat && p < np; p++)
            for (int c = 0; c < 3; c++) flat->pixels[3 * p + (size_t)c] = (float)(mean[c] / (double)np);
        if (flat && m1) {
            CHECK_OK(gr_metrics_compute(truth, flat, &co, m1, &err), err);
            CHECK(gr_metric_value(&m1->fit, GR_METRIC_VERDICT) == gr_metric_value(&bl->m[GR_BASELINE_CONSTANT].fit, GR_METRIC_VERDICT));
            CHECK(gr_metric_value(&m1->raw, GR_METRIC_VERDICT) == gr_metric_value(&bl->m[GR_BASELINE_CONSTANT].raw, GR_METRIC_VERDICT));
        }
        free(m1);
        gr_image_destroy(tr);
        gr_image_destroy(flat);
    }

    /* the truth blurred by 5 px reads 5 +- 0.5 px */
    gr_metrics m;
    gr_metrics_options fo = {.fit_scale = 1, .structure = &so, .skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(truth, b5, &fo, &m, &err), err);
    int where = 9;
    const double eq = gr_equivalent_blur(bl, gr_metric_value(&m.fit, GR_METRIC_VERDICT), &where);
    printf("truth blurred by 5 px (direct convolution): verdict %.4f, equivalent blur %.3f px\n",
           gr_metric_value(&m.fit, GR_METRIC_VERDICT), eq);
    CHECK_NEAR(eq, 5.0, 0.5);
    CHECK(where == 0);
    char t[32];
    CHECK(gr_equivalent_blur(bl, 0.0, &where) == 0.5 && where == -1);
    CHECK(!strcmp(gr_equivalent_blur_text(bl, 0.0, t, sizeof t), "< 0.5 px"));
    CHECK(gr_equivalent_blur(bl, 1e9, &where) == 64.0 && where == 1);
    CHECK(!strcmp(gr_equivalent_blur_text(bl, 1e9, t, sizeof t), "> 64 px"));
    CHECK(isnan(gr_equivalent_blur(bl, NAN, &where)) && where == 0);

    /* the constant and black baselines against the truth's own statistics */
    double s = 0, s2 = 0;
    for (int p = 0; p < W * H; p++) {
        const double yv = lum(truth->pixels + 3 * p);
        s += yv, s2 += yv * yv;
    }
    const double mean = s / (W * H), cv = sqrt(s2 / (W * H) - mean * mean) / mean;
    CHECK_REL(gr_metric_value(&bl->m[GR_BASELINE_CONSTANT].fit, GR_METRIC_REL_RMSE), cv, 1e-4);
    CHECK_REL(gr_metric_value(&bl->m[GR_BASELINE_BLACK].fit, GR_METRIC_REL_RMSE), sqrt(1 + cv * cv), 1e-4);
    CHECK(!bl->m[GR_BASELINE_BLACK].fit_defined);

    /* the leaderboard: the blurred truth ranks among the baselines; a constant "technique" is flagged */
    gr_scene *scene = calloc(1, sizeof *scene);
    gr_metrics mc;
    gr_image *flat = gr_image_create(W, H, 3, NULL);
    for (int p = 0; p < W * H * 3; p++) flat->pixels[p] = 0.3f;
    gr_metrics_options to = {.fit_scale = 1, .structure = &so};
    CHECK_OK(gr_metrics_compute(truth, flat, &to, &mc, &err), err);
    const gr_report_technique ts[2] = {{.name = "blurry", .test = b5, .metrics = &m}, {.name = "flat", .test = flat, .metrics = &mc}};
    const gr_report_failure fl = {.name = "broken", .reason = "does not compile"};
    gr_report_input in = {.scene = scene, .ref = truth, .n_techniques = 2, .techniques = ts, .n_failed = 1,
                          .failed = &fl, .baselines = bl};
    gr_leaderboard *lb = calloc(1, sizeof *lb);
    gr_leaderboard_build(&in, NULL, lb);
    CHECK(lb->n == 2 + GR_BASELINE_COUNT + 1);
    CHECK(lb->rows[0].kind == GR_LB_BASELINE || lb->rows[0].kind == GR_LB_TECHNIQUE);
    CHECK(lb->rows[lb->n - 1].kind == GR_LB_FAILED && !strcmp(lb->rows[lb->n - 1].text, "does not compile"));
    for (int i = 1; i < lb->n - 1; i++) CHECK(lb->rows[i].verdict >= lb->rows[i - 1].verdict);
    const gr_lb_row *rb = gr_lb_technique_row(lb, 0), *rf = gr_lb_technique_row(lb, 1);
    CHECK(rb && rf && rb->rank == 1 && rf->rank == 2);
    CHECK(rb && !rb->no_better && fabs(rb->eq_blur_px - 5.0) <= 0.5);
    CHECK(rf && rf->no_better && lb->n_flagged == 1); /* a constant is no better than the constant */
    free(lb);
    free(scene);
    gr_image_destroy(flat);
    free(bl);
    gr_image_destroy(truth);
    gr_image_destroy(b5);
    CHECK_DONE();
}
