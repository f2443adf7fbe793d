/* Acceptance (issue 11): `godrays tune SCENE` with its defaults (the technique's default
 * parameters, the default objective GR_TUNE_DEFAULT_OBJECTIVE and the default search) on the
 * default scene ends with visible beams: the tuned image's streak contrast is within a factor
 * 1.5 of the ground truth's, and its structure score is better (lower) than a featureless
 * glow's. The glow is the best image that depends only on the angle to the refracted sun (the
 * truth's own mean R, G, B per 0.5-degree bin of that angle, as in
 * integration.structure_views). Both criteria are computed here with
 * gr_structure_compare_images and the documented score formula, on a fresh render at the
 * tuned settings, with the vanishing point and the angle field derived here (not the tuner's).
 *
 * The ground truth comes from the reference cache ($GODRAYS_CACHE, else ~/.cache/godrays;
 * rendered and stored when absent). Slow: 320 x 180 (about 1000 evaluations); the reduced
 * variant (GODRAYS_TEST_REDUCED=1) runs at 160 x 90 with the same checks.
 * GODRAYS_TUNE_DEFAULT_SIZE=WxH overrides the size (docs/tuning.md's 640 x 360 figures) and
 * GODRAYS_TUNE_OBJECTIVE=W another objective, GODRAYS_TUNE_STARTS=N and GODRAYS_TUNE_SEED=S
 * another search (the tables of candidates there). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "glow_test.h"
#include "compare/structure.h"
#include "report/profile.h"
#include "tune/cliopts.h"
#include "reference/truth.h"
#include "tune_test.h"

/* docs/metrics.md: S = ((1 - corr) / 2 + min(|ln ratio|, 3) / 3 + min(LSD, 3) / 3) / 3 */
static double score_of(const gr_structure_compare *c)
{
    return (0.5 * (1.0 - c->bandpass_corr) + fmin(c->contrast_log_err, 3.0) / 3.0 +
            fmin(c->spectrum_log_dist, 3.0) / 3.0) / 3.0;
}

int main(void)
{
    int w = tune_test_reduced() ? 160 : 320, h = tune_test_reduced() ? 90 : 180;
    const char *sz = getenv("GODRAYS_TUNE_DEFAULT_SIZE");
    if (sz && sscanf(sz, "%dx%d", &w, &h) != 2) w = 160, h = 90;
    gr_error err = {0};
    gr_scene *s = tune_test_default_scene(w, h, NULL, 0);
    gr_image *truth = NULL;
    gr_truth_info info;
    CHECK_OK(gr_truth_image(s, NULL, &truth, &info, &err), err);
    if (!truth) CHECK_DONE();
    printf("default scene %d x %d: truth %s (%.1f s)\n", w, h, info.cached ? "from the cache" : "rendered",
           info.seconds);

    /* the problem as `godrays tune SCENE` sets it up */
    gr_technique *r = tune_test_renderer();
    gr_tune_problem *p = calloc(1, sizeof *p);
    p->renderer = r;
    p->n_cases = 1;
    p->scenes[0] = s;
    p->refs[0] = truth;
    tune_test_base(p, s);
    char list[512];
    CHECK(gr_tune_default_params(&gr_shafts_class, list, sizeof list) == 0);
    CHECK_OK(gr_tune_param_parse_list("--params", list, p->params, GR_TUNE_MAX_PARAMS, &p->n_params, &err), err);
    p->metric = GR_TM_WEIGHTED;
    const char *objective = getenv("GODRAYS_TUNE_OBJECTIVE");
    if (!objective || !objective[0]) objective = GR_TUNE_DEFAULT_OBJECTIVE;
    CHECK_OK(gr_tune_weights_parse("--objective", objective, p->weights, &err), err);
    p->fit = 1;
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    double x0[GR_TUNE_MAX_PARAMS], lo[GR_TUNE_MAX_PARAMS], hi[GR_TUNE_MAX_PARAMS];
    for (int k = 0; k < p->n_params; k++) {
        lo[k] = p->params[k].lo, hi[k] = p->params[k].hi;
        x0[k] = fmin(hi[k], fmax(lo[k], gr_tune_param_current(&p->params[k], p->base.bytes, p->base.bytes)));
    }
    gr_opt_options o;
    gr_tune_search_defaults(&o, p->n_params, x0);
    if (getenv("GODRAYS_TUNE_STARTS")) o.n_starts = atoi(getenv("GODRAYS_TUNE_STARTS"));
    if (getenv("GODRAYS_TUNE_SEED")) o.seed = strtoull(getenv("GODRAYS_TUNE_SEED"), NULL, 10);
    if (o.n_starts < 1 || o.n_starts > GR_OPT_MAX_STARTS) o.n_starts = 4;
    gr_opt_result res;
    CHECK_OK(gr_opt_minimize(p->n_params, lo, hi, gr_tune_objective, p, &o, &res, &err), err);
    printf("%s over %s: %d evaluations, objective %.4f; tuned:", objective, list, res.evals, res.f);
    for (int k = 0; k < p->n_params; k++) printf(" %s %.4g", p->params[k].key, res.x[k]);
    printf("\n");
    for (int j = 0; j < res.n_starts; j++) {
        printf("  start %d (sample rank %d): objective %.4f at", j, res.starts[j].coarse_rank, res.starts[j].f);
        for (int k = 0; k < p->n_params; k++) printf(" %.4g", res.starts[j].x[k]);
        printf(", %d evaluations\n", res.starts[j].evals);
    }

    /* independent check on fresh renders: the scene's settings, the tuned ones, the glow */
    float *ang = malloc((size_t)w * h * sizeof(float));
    double dir[3];
    gr_profile_sun_view_dir(s, dir);
    gr_profile_angles(&s->camera, dir, ang);
    gr_structure_options so = {.radial = ang, .radial_bin = s->camera.fov_deg / h};
    CHECK_OK(gr_structure_scene_vp(s, w, h, &so.vp_x, &so.vp_y, &err), err);
    gr_image *img[2] = {gr_image_create(w, h, 3, NULL), gr_image_create(w, h, 3, NULL)};
    gr_section_store st;
    CHECK_OK(gr_tune_settings_at(p, x0, st.bytes, &err), err);
    CHECK_OK(gr_technique_render(r, s, st.bytes, img[0], NULL, &err), err);
    CHECK_OK(gr_tune_settings_at(p, res.x, st.bytes, &err), err);
    CHECK_OK(gr_technique_render(r, s, st.bytes, img[1], NULL, &err), err);
    gr_image *glow = glow_test_image(truth, ang);
    const gr_image *tests[3] = {img[0], img[1], glow};
    const char *names[3] = {"scene's settings", "tuned (default)", "featureless glow"};
    gr_structure_compare sc[3];
    for (int k = 0; k < 3; k++) {
        CHECK_OK(gr_structure_compare_images(truth, tests[k], &so, &sc[k], &err), err);
        gr_metrics m;
        gr_metrics_options mo = {.fit_scale = 1, .skip_ssim = 1, .skip_blur = 1};
        CHECK_OK(gr_metrics_compute(truth, tests[k], &mo, &m, &err), err);
        printf("  %-17s RMSE of Y (fit) %.4f (relative %.3f)  streak contrast %.4f (truth %.4f, ratio %.3f)  "
               "corr %.3f  LSD %.3f  structure score %.3f\n",
               names[k], m.fit.ch[GR_MCH_Y].rmse, m.fit.ch[GR_MCH_Y].rmse / m.fit.ch[GR_MCH_Y].ref_mean,
               sc[k].test.streak_contrast, sc[k].ref.streak_contrast, sc[k].contrast_ratio, sc[k].bandpass_corr,
               sc[k].spectrum_log_dist, score_of(&sc[k]));
    }
    CHECK_MSG(sc[1].contrast_ratio >= 1.0 / 1.5 && sc[1].contrast_ratio <= 1.5,
              "tuned streak contrast %.4f is not within a factor 1.5 of the truth's %.4f", sc[1].test.streak_contrast,
              sc[1].ref.streak_contrast);
    CHECK_MSG(score_of(&sc[1]) < score_of(&sc[2]), "tuned structure score %.3f is not below the glow's %.3f",
              score_of(&sc[1]), score_of(&sc[2]));
    gr_image_destroy(img[0]), gr_image_destroy(img[1]), gr_image_destroy(glow), gr_image_destroy(truth);
    free(ang);
    gr_tune_problem_free(p);
    free(p);
    tune_test_renderer_destroy(r);
    free(s);
    CHECK_DONE();
}
