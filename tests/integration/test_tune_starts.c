/* Robustness of `godrays tune` on the default scene (issue 6): two runs from different
 * starting points (one near the lower corner of the box, one near the upper) must reach the
 * same optimum: the same settings within 1 % of each box side and the same error within 1 %.
 * The ground truth is the Embree integrator at 160x90 with reduced sampling (its noise is far
 * below the shafts' error); the comparison is between the two runs, each started elsewhere,
 * so no earlier output of the optimizer is an input. Also checks the result is no worse than
 * the scene's own settings. GODRAYS_TEST_REDUCED=1: fewer evaluations. */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "tune/optimize.h"
#include "reference/truth.h"
#include "tune_test.h"

int main(void)
{
    const char *q[4] = {"reference.sun_samples=2", "reference.batches=2", "reference.steps=32",
                        "reference.surface_res=128"};
    gr_scene *scene = tune_test_default_scene(160, 90, q, 4);
    gr_error err;
    gr_image *truth = NULL;
    gr_truth_options to;
    gr_truth_options_default(&to);
    to.use_cache = 0;
    gr_truth_info info;
    CHECK_OK(gr_truth_image(scene, &to, &truth, &info, &err), err);
    if (!truth) return 1;
    printf("ground truth 160x90 in %.1f s\n", info.seconds);
    gr_technique *r = tune_test_renderer();
    gr_tune_problem *p = calloc(1, sizeof *p);
    if (!p) return 1;
    p->renderer = r;
    p->n_cases = 1;
    p->scenes[0] = scene;
    p->refs[0] = truth;
    tune_test_base(p, scene);
    p->n_params = 2;
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.K", &p->params[0], &err), err);
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.extinction", &p->params[1], &err), err);
    p->metric = GR_METRIC_RMSE;
    p->fit = 1;
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    double lo[2] = {p->params[0].lo, p->params[1].lo}, hi[2] = {p->params[0].hi, p->params[1].hi};
    double xa[2] = {lo[0] + 0.1 * (hi[0] - lo[0]), lo[1] + 0.15 * (hi[1] - lo[1])};
    double xb[2] = {lo[0] + 0.9 * (hi[0] - lo[0]), lo[1] + 0.85 * (hi[1] - lo[1])};
    int reduced = tune_test_reduced();
    gr_opt_options oa = {.n_starts = reduced ? 6 : 8, .x0 = xa, .max_evals = reduced ? 160 : 240};
    gr_opt_options ob = oa;
    ob.x0 = xb;
    gr_opt_result ra, rb;
    CHECK_OK(gr_opt_minimize(2, lo, hi, gr_tune_objective, p, &oa, &ra, &err), err);
    CHECK_OK(gr_opt_minimize(2, lo, hi, gr_tune_objective, p, &ob, &rb, &err), err);
    printf("from (%.3g, %.3g): K %.5g, extinction x %.5g, rmse %.6g (%d evals)\n", xa[0], xa[1], ra.x[0], ra.x[1], ra.f,
           ra.evals);
    printf("from (%.3g, %.3g): K %.5g, extinction x %.5g, rmse %.6g (%d evals)\n", xb[0], xb[1], rb.x[0], rb.x[1], rb.f,
           rb.evals);
    for (int d = 0; d < 2; d++) CHECK_NEAR(ra.x[d], rb.x[d], 0.01 * (hi[d] - lo[d]));
    CHECK_REL(ra.f, rb.f, 0.01);
    /* the scene's own settings (K 0.8, extinction x 1) are a feasible point: never worse */
    double f0;
    CHECK_OK(gr_tune_evaluate(p, (double[]){0.8, 1.0}, &f0, NULL, NULL, &err), err);
    CHECK(ra.f <= f0 && rb.f <= f0);
    printf("scene's own settings: rmse %.6g\n", f0);
    gr_tune_problem_free(p);
    free(p);
    tune_test_renderer_destroy(r);
    gr_image_destroy(truth);
    free(scene);
    CHECK_DONE();
}
