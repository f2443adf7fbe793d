/* Identifiability: a shafts render with known settings stands in for the ground truth; tuning
 * K and the extinction scale from a different start must recover them within 2 % (issue 6).
 * The oracle is the known setting itself, not an earlier output of the optimizer. Both target
 * formats: rgba16f (smooth error surface) and the seed's rgba8 (stepped surface). */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "tune/optimize.h"
#include "tune_test.h"

static void identify(gr_technique *r, const char *format, double k_true, double s_true, const double *x0)
{
    char fmt[64];
    snprintf(fmt, sizeof fmt, "shafts.target_format=%s", format);
    const char *extra[1] = {fmt};
    gr_scene *scene = tune_test_default_scene(160, 90, extra, 1);
    gr_error err;
    gr_tune_problem *p = calloc(1, sizeof *p);
    CHECK(p != NULL);
    p->renderer = r;
    p->n_cases = 1;
    p->scenes[0] = scene;
    tune_test_base(p, scene);
    p->n_params = 2;
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.K", &p->params[0], &err), err);
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.extinction", &p->params[1], &err), err);
    p->params[0].lo = 0.4, p->params[0].hi = 1.6;
    p->params[1].lo = 0.3, p->params[1].hi = 3.0;
    p->metric = GR_METRIC_RMSE;
    p->fit = 0;

    /* the "ground truth": the same renderer at the known settings */
    gr_image *truth = gr_image_create(160, 90, 3, NULL);
    p->refs[0] = truth;
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    double xt[2] = {k_true, s_true};
    gr_shafts_settings st;
    CHECK_OK(gr_tune_settings_at(p, xt, &st, &err), err);
    CHECK_OK(gr_technique_render(r, scene, &st, truth, NULL, &err), err);

    double f_true = -1;
    CHECK_OK(gr_tune_evaluate(p, xt, &f_true, NULL, NULL, &err), err);
    CHECK_NEAR(f_true, 0.0, 0.0); /* deterministic renderer: the truth scores exactly 0 */

    gr_opt_options o = {.n_starts = 3, .x0 = x0, .max_evals = 90};
    gr_opt_result res;
    CHECK_OK(gr_opt_minimize(2, (double[]){0.4, 0.3}, (double[]){1.6, 3.0}, gr_tune_objective, p, &o, &res, &err),
             err);
    printf("%s: start (%.3g, %.3g) -> K %.5f (true %.3g), extinction scale %.5f (true %.3g), rmse %.3g, %d evals\n",
           format, x0[0], x0[1], res.x[0], k_true, res.x[1], s_true, res.f, res.evals);
    for (int j = 0; j < res.n_starts; j++)
        printf("  start %d: (%.3g, %.3g) -> (%.5f, %.5f) f %.4g, %d evals\n", j, res.starts[j].x0[0],
               res.starts[j].x0[1], res.starts[j].x[0], res.starts[j].x[1], res.starts[j].f, res.starts[j].evals);
    CHECK_REL(res.x[0], k_true, 0.02);
    CHECK_REL(res.x[1], s_true, 0.02);
    gr_tune_problem_free(p);
    free(p);
    gr_image_destroy(truth);
    free(scene);
}

int main(void)
{
    gr_technique *r = tune_test_renderer();
    identify(r, "rgba16f", 0.9, 1.3, (double[]){0.6, 0.7});
    identify(r, "rgba8", 0.9, 1.3, (double[]){1.3, 2.2});
    tune_test_renderer_destroy(r);
    CHECK_DONE();
}
