/* Identifiability (issue 10): a radial_blur render at known settings stands in for the ground
 * truth; tuning decay and density from a different start must recover them within 2 %. The
 * oracle is the known setting itself, not an earlier output of the optimizer. 160x90, 50 taps,
 * dither on (deterministic noise: the truth scores exactly 0). */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "realtime/radial_blur.h"
#include "tune/optimize.h"
#include "tune_test.h"

int main(void)
{
    gr_error err;
    gr_gl *gl = NULL;
    gr_technique *r = NULL;
    const char *extra[1] = {"radial_blur.samples=50"};
    gr_scene *scene = tune_test_default_scene(160, 90, extra, 1);
    if (gr_gl_create(NULL, &gl, &err) != GR_OK ||
        gr_technique_create(&gr_radial_blur_class, gl, NULL, &r, &err) != GR_OK) {
        fprintf(stderr, "cannot create radial_blur: %s\n", err.msg);
        return 1;
    }
    gr_tune_problem *p = calloc(1, sizeof *p);
    CHECK(p != NULL);
    p->renderer = r;
    p->cls = &gr_radial_blur_class;
    memcpy(p->base.bytes, gr_technique_scene_settings(&gr_radial_blur_class, scene), sizeof(gr_radial_blur_settings));
    p->n_cases = 1;
    p->scenes[0] = scene;
    p->n_params = 2;
    CHECK_OK(gr_tune_param_lookup("--params", "radial_blur.decay", &p->params[0], &err), err);
    CHECK_OK(gr_tune_param_lookup("--params", "radial_blur.density", &p->params[1], &err), err);
    const double lo[2] = {0.9, 0.5}, hi[2] = {0.995, 1.2};
    for (int i = 0; i < 2; i++) {
        p->params[i].lo = lo[i];
        p->params[i].hi = hi[i];
    }
    p->metric = GR_METRIC_RMSE;
    p->fit = 0;
    gr_image *truth = gr_image_create(160, 90, 3, NULL);
    p->refs[0] = truth;
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    const double xt[2] = {0.975, 0.8};
    gr_radial_blur_settings st;
    CHECK_OK(gr_tune_settings_at(p, xt, &st, &err), err);
    CHECK_OK(gr_technique_render(r, scene, &st, truth, NULL, &err), err);
    double f_true = -1;
    CHECK_OK(gr_tune_evaluate(p, xt, &f_true, NULL, NULL, &err), err);
    CHECK_NEAR(f_true, 0.0, 0.0);

    gr_opt_options o = {.n_starts = 2, .x0 = (double[]){0.94, 1.05}, .max_evals = 70};
    gr_opt_result res;
    CHECK_OK(gr_opt_minimize(2, lo, hi, gr_tune_objective, p, &o, &res, &err), err);
    printf("decay %.5f (true %.3g), density %.5f (true %.3g), rmse %.3g, %d evals\n", res.x[0], xt[0], res.x[1],
           xt[1], res.f, res.evals);
    CHECK_REL(res.x[0], xt[0], 0.02);
    CHECK_REL(res.x[1], xt[1], 0.02);
    gr_tune_problem_free(p);
    free(p);
    gr_image_destroy(truth);
    free(scene);
    gr_technique_destroy(r);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
