/* The tuning objective's FLIP, structure and weighted terms (tune/objective.c) are the
 * compare module's metrics of the same render: recomputed here directly with
 * gr_metrics_compute, gr_flip_compute and gr_structure_compare_images on a render at the
 * same settings, with the vanishing point and the angle field derived here, and the
 * documented combination (docs/tuning.md) written out. A shafts render at known settings
 * stands in for the ground truth: at those settings FLIP and the structure score are 0
 * (identical images); elsewhere the objective equals the independent sum. Several cases:
 * the evaluation compares case i on a second thread while case i + 1 renders; each case's value
 * must be, to the bit, what a problem of that case alone gives (compared inline), and the
 * mean their sum in case order. Also the --objective parser's errors. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "compare/flip.h"
#include "compare/structure.h"
#include "report/profile.h"
#include "tune_test.h"

int main(void)
{
    gr_technique *r = tune_test_renderer();
    const char *extra[1] = {"shafts.target_format=rgba16f"};
    gr_scene *scene = tune_test_default_scene(160, 90, extra, 1);
    gr_error err = {0};
    gr_tune_problem *p = calloc(1, sizeof *p);
    p->renderer = r;
    p->n_cases = 1;
    p->scenes[0] = scene;
    tune_test_base(p, scene);
    p->n_params = 2;
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.K", &p->params[0], &err), err);
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.shaft_width", &p->params[1], &err), err);
    p->params[0].lo = 0.2, p->params[0].hi = 2.0;
    p->params[1].lo = 0.1, p->params[1].hi = 1.0;
    p->fit = 1;
    p->metric = GR_TM_WEIGHTED;
    CHECK_OK(gr_tune_weights_parse("--objective", "rmse=1,flip=0.5,structure=2", p->weights, &err), err);
    CHECK(p->weights[GR_METRIC_RMSE] == 1.0 && p->weights[GR_METRIC_FLIP] == 0.5 && p->weights[GR_METRIC_STRUCTURE] == 2.0 &&
          p->weights[GR_METRIC_SSIM] == 0.0);
    gr_image *truth = gr_image_create(160, 90, 3, NULL);
    p->refs[0] = truth;
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    const double xt[2] = {0.9, 0.4}, x[2] = {0.5, 0.8};
    gr_shafts_settings st;
    CHECK_OK(gr_tune_settings_at(p, xt, &st, &err), err);
    CHECK_OK(gr_technique_render(r, scene, &st, truth, NULL, &err), err);

    /* at the truth's own settings every term is 0 */
    double f0 = -1;
    CHECK_OK(gr_tune_evaluate(p, xt, &f0, NULL, NULL, &err), err);
    printf("objective at the truth's settings: %.3g\n", f0);
    CHECK_NEAR(f0, 0.0, 1e-9);

    /* elsewhere: the independent sum */
    double f = -1, scale = 0;
    CHECK_OK(gr_tune_evaluate(p, x, &f, NULL, &scale, &err), err);
    gr_image *img = gr_image_create(160, 90, 3, NULL);
    CHECK_OK(gr_tune_settings_at(p, x, &st, &err), err);
    CHECK_OK(gr_technique_render(r, scene, &st, img, NULL, &err), err);
    gr_metrics m;
    gr_metrics_options mo = {.fit_scale = 1, .skip_ssim = 1, .skip_blur = 1};
    CHECK_OK(gr_metrics_compute(truth, img, &mo, &m, &err), err);
    const double a = m.fit.scale, rel_rmse = m.fit.ch[GR_MCH_Y].rmse / m.fit.ch[GR_MCH_Y].ref_mean;
    gr_flip_options fo = {.mode = GR_FLIP_HDR, .test_scale = a};
    gr_flip_result fr;
    CHECK_OK(gr_flip_compute(truth, img, &fo, NULL, &fr, &err), err);
    float *ang = malloc(160 * 90 * sizeof(float));
    double dir[3];
    gr_profile_sun_view_dir(scene, dir);
    gr_profile_angles(&scene->camera, dir, ang);
    gr_structure_options so = {.radial = ang, .radial_bin = scene->camera.fov_deg / 90.0};
    CHECK_OK(gr_structure_scene_vp(scene, 160, 90, &so.vp_x, &so.vp_y, &err), err);
    gr_structure_compare sc;
    CHECK_OK(gr_structure_compare_images(truth, img, &so, &sc, &err), err);
    const double s_score = (0.5 * (1.0 - sc.bandpass_corr) + fmin(sc.contrast_log_err, 3.0) / 3.0 +
                            fmin(sc.spectrum_log_dist, 3.0) / 3.0) / 3.0;
    const double expect = (1.0 * rel_rmse + 0.5 * fr.mean + 2.0 * s_score) / 3.5;
    printf("objective %.9f; independent: rel rmse %.6f, FLIP %.6f, structure %.6f (corr %.4f) -> %.9f; scale %.5g vs %.5g\n",
           f, rel_rmse, fr.mean, s_score, sc.bandpass_corr, expect, scale, a);
    CHECK_NEAR(f, expect, 1e-9);
    CHECK_NEAR(scale, a, 1e-12);
    CHECK(fr.mean > 0.0 && s_score > 0.0);

    /* one metric alone */
    p->metric = GR_METRIC_STRUCTURE;
    CHECK_OK(gr_tune_evaluate(p, x, &f, NULL, NULL, &err), err);
    CHECK_NEAR(f, s_score, 1e-12);
    p->metric = GR_METRIC_FLIP;
    CHECK_OK(gr_tune_evaluate(p, x, &f, NULL, NULL, &err), err);
    CHECK_NEAR(f, fr.mean, 1e-12);

    /* three cases (water times 0, 0.4, 0.8): the pipelined evaluation against one problem per case */
    {
        gr_scene *sc3[3];
        gr_image *tr3[3];
        gr_tune_problem *q = calloc(1, sizeof *q), *one = calloc(1, sizeof *one);
        *q = *p;
        q->scratch = q->scratch2 = NULL;
        q->n_cases = 3;
        for (int i = 0; i < 3; i++) {
            sc3[i] = malloc(sizeof *sc3[i]);
            CHECK_OK(gr_tune_make_case(scene, 0.4 * i, NULL, sc3[i], &err), err);
            tr3[i] = gr_image_create(160, 90, 3, NULL);
            CHECK_OK(gr_technique_render(r, sc3[i], &st, tr3[i], NULL, &err), err); /* st: settings x */
            q->scenes[i] = sc3[i];
            q->refs[i] = tr3[i];
        }
        q->metric = GR_TM_WEIGHTED;
        CHECK_OK(gr_tune_problem_init(q, &err), err);
        double mean3 = -1, per[3] = {-1, -1, -1}, sum = 0;
        CHECK_OK(gr_tune_evaluate(q, xt, &mean3, per, NULL, &err), err);
        for (int i = 0; i < 3; i++) {
            *one = *p;
            one->scratch = one->scratch2 = NULL;
            one->n_cases = 1;
            one->scenes[0] = sc3[i];
            one->refs[0] = tr3[i];
            one->metric = GR_TM_WEIGHTED;
            CHECK_OK(gr_tune_problem_init(one, &err), err);
            double f1 = -1;
            CHECK_OK(gr_tune_evaluate(one, xt, &f1, NULL, NULL, &err), err);
            printf("case %d: %.17g pipelined, %.17g alone\n", i, per[i], f1);
            CHECK(per[i] == f1 && f1 > 0);
            sum += f1;
            gr_tune_problem_free(one);
        }
        CHECK(mean3 == sum / 3.0);
        gr_tune_problem_free(q);
        free(q);
        free(one);
        for (int i = 0; i < 3; i++) gr_image_destroy(tr3[i]), free(sc3[i]);
    }

    /* the parser's errors */
    double w[GR_METRIC_MAX];
    CHECK(gr_tune_weights_parse("--objective", "rmse=-1", w, &err) == GR_E_USAGE && strstr(err.msg, "'-1'"));
    CHECK(gr_tune_weights_parse("--objective", "bogus=1", w, &err) == GR_E_USAGE && strstr(err.msg, "bogus"));
    CHECK(gr_tune_weights_parse("--objective", "rmse=0", w, &err) == GR_E_USAGE && strstr(err.msg, "no weight"));
    CHECK(gr_tune_weights_parse("--objective", "rmse", w, &err) == GR_E_USAGE && strstr(err.msg, "NAME=WEIGHT"));

    free(ang);
    gr_image_destroy(img);
    gr_tune_problem_free(p);
    free(p);
    gr_image_destroy(truth);
    free(scene);
    tune_test_renderer_destroy(r);
    CHECK_DONE();
}
