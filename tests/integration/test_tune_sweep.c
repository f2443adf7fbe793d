/* The sweep (src/tune/sweep.h) on the default scene at 160x90 with a shafts render at known
 * settings standing in for the ground truth: that grid point must score exactly 0 and be the
 * minimum, every other point must score > 0, the grid must hold the documented values, and
 * the CSV must have one row per grid point with the same numbers. Also a one-axis sweep over
 * an integer setting (N). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "tune/sweep.h"
#include "tune_test.h"

int main(void)
{
    gr_scene *scene = tune_test_default_scene(160, 90, NULL, 0);
    gr_technique *r = tune_test_renderer();
    gr_error err;
    gr_tune_problem *p = calloc(1, sizeof *p);
    gr_image *truth = gr_image_create(160, 90, 3, NULL);
    if (!p || !truth) return 1;
    p->renderer = r;
    p->n_cases = 1;
    p->scenes[0] = scene;
    p->refs[0] = truth;
    tune_test_base(p, scene);
    p->n_params = 2;
    CHECK_OK(gr_tune_param_parse_sweep("--param", "shafts.K=0.5:1.1:4", &p->params[0], &err), err);
    CHECK_OK(gr_tune_param_parse_sweep("--param", "shafts.extinction=0.5:2:4", &p->params[1], &err), err);
    p->metric = GR_METRIC_RMSE;
    p->fit = 0;
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    /* truth = grid point (ix 2, iy 1): K = 0.9, extinction x 1.0 */
    gr_shafts_settings st;
    CHECK_OK(gr_tune_settings_at(p, (double[]){0.9, 1.0}, &st, &err), err);
    CHECK_OK(gr_technique_render(r, scene, &st, truth, NULL, &err), err);

    gr_sweep_result res;
    CHECK_OK(gr_sweep_run(p, &res, NULL, NULL, &err), err);
    CHECK(res.nx == 4 && res.ny == 4 && p->renders == 16);
    CHECK_NEAR(res.xs[2], 0.9, 1e-12);
    CHECK_NEAR(res.ys[1], 1.0, 1e-12);
    CHECK(res.best == 2 + 4 * 1);
    CHECK(res.err[res.best] == 0.0);
    for (int k = 0; k < 16; k++)
        if (k != res.best) CHECK_MSG(res.err[k] > 0.0, "grid point %d scores %g", k, res.err[k]);

    const char *out = getenv("GODRAYS_TEST_OUT");
    char path[4096];
    snprintf(path, sizeof path, "%s/tune_sweep.csv", out ? out : ".");
    const char *labels[1] = {"case0"};
    CHECK_OK(gr_sweep_write_csv(path, p, &res, labels, &err), err);
    FILE *f = fopen(path, "r");
    CHECK(f != NULL);
    if (f) {
        char line[512];
        int rows = 0;
        CHECK(fgets(line, sizeof line, f) && !strncmp(line, "shafts.K,shafts.extinction,rmse,scale,case0", 43));
        while (fgets(line, sizeof line, f)) {
            double k, s, e, a, c0;
            CHECK(sscanf(line, "%lf,%lf,%lf,%lf,%lf", &k, &s, &e, &a, &c0) == 5);
            CHECK_NEAR(e, res.err[rows], 1e-8 * fmax(1.0, fabs(res.err[rows])));
            CHECK(e == c0 && a == 1.0);
            rows++;
        }
        CHECK(rows == 16);
        fclose(f);
    }
    int drawn = 0;
    snprintf(path, sizeof path, "%s/tune_sweep.png", out ? out : ".");
    CHECK_OK(gr_sweep_write_plot(path, p, &res, &drawn, &err), err);
    CHECK(drawn == 1);
    gr_sweep_result_free(&res);

    /* --normalize: each case's RMSE over its mean reference luminance, the mean computed here
     * from the pixels with the Rec. 709 weights (the truth has no stderr: every pixel scored) */
    double mean_y = 0.0;
    for (int k = 0; k < 160 * 90; k++) {
        const float *px = truth->pixels + (size_t)k * 3;
        mean_y += 0.2126 * px[0] + 0.7152 * px[1] + 0.0722 * px[2];
    }
    mean_y /= 160.0 * 90.0;
    double f_raw, f_norm, xq[2] = {0.7, 1.5};
    CHECK_OK(gr_tune_evaluate(p, xq, &f_raw, NULL, NULL, &err), err);
    p->normalize = 1;
    CHECK_OK(gr_tune_evaluate(p, xq, &f_norm, NULL, NULL, &err), err);
    p->normalize = 0;
    CHECK(mean_y > 0 && f_raw > 0);
    CHECK_REL(f_norm, f_raw / mean_y, 1e-6);

    /* one integer axis: N = 5, 7, 9, 11 against a render at N = 9 */
    p->n_params = 1;
    CHECK_OK(gr_tune_param_parse_sweep("--param", "shafts.N=5:11:4", &p->params[0], &err), err);
    tune_test_base(p, scene);
    gr_tune_problem_free(p);
    CHECK_OK(gr_tune_problem_init(p, &err), err);
    CHECK_OK(gr_tune_settings_at(p, (double[]){9}, &st, &err), err);
    CHECK(st.N == 9);
    CHECK_OK(gr_technique_render(r, scene, &st, truth, NULL, &err), err);
    CHECK_OK(gr_sweep_run(p, &res, NULL, NULL, &err), err);
    CHECK(res.nx == 4 && res.ny == 1 && res.best == 2 && res.err[2] == 0.0 && res.err[0] > 0 && res.err[3] > 0);
    gr_sweep_result_free(&res);

    gr_tune_problem_free(p);
    free(p);
    gr_image_destroy(truth);
    tune_test_renderer_destroy(r);
    free(scene);
    CHECK_DONE();
}
