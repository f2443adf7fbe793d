/* Identifiability of the shipped user technique (issue 10): a shadow_march render at known
 * settings (extinction_scale = 1.3, caustics = 0.6) stands in for the ground truth; `tune`'s
 * objective and optimizer, started from the manifest's defaults (1, 1) and from the other side
 * of the box, must recover both within 2 %. The oracle is the known setting itself. The
 * technique is loaded from its folder through the registry exactly as --technique-dir does.
 * Small and fast: 64x36, 24 march steps. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "tune/objective.h"
#include "tune/optimize.h"

#define W 64
#define H 36

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char dir[1024], path[1024];
    snprintf(dir, sizeof dir, "%s/data/techniques/shadow_march", src ? src : GR_SOURCE_DIR);
    snprintf(path, sizeof path, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    gr_error err;
    CHECK_OK(gr_technique_add_dir(dir, &err), err);
    const gr_technique_class *cls = gr_technique_find("shadow_march");
    CHECK(cls != NULL);
    if (!cls) CHECK_DONE();
    const char *ov[] = {"camera.width=64", "camera.height=36", "shadow_march.steps=24"};
    gr_scene *scene = malloc(sizeof *scene);
    CHECK_OK(gr_scene_load_file(path, ov, 3, scene, &err), err);
    gr_gl *gl = NULL;
    gr_technique *t = NULL;
    CHECK_OK(gr_gl_create(NULL, &gl, &err), err);
    CHECK_OK(gr_technique_create(cls, gl, NULL, &t, &err), err);
    if (!t) CHECK_DONE();

    static const char *const keys[2] = {"shadow_march.extinction_scale", "shadow_march.caustics"};
    const double lo[2] = {0.3, 0.0}, hi[2] = {3.0, 1.0}, truth_x[2] = {1.3, 0.6};
    const double *starts[2] = {(const double[]){1.0, 1.0}, (const double[]){2.5, 0.1}};
    for (int run = 0; run < 2; run++) {
        gr_tune_problem *p = calloc(1, sizeof *p);
        p->renderer = t;
        p->cls = cls;
        p->n_cases = 1;
        p->scenes[0] = scene;
        memcpy(p->base.bytes, gr_technique_scene_settings(cls, scene), cls->settings_size);
        p->n_params = 2;
        for (int k = 0; k < 2; k++) {
            CHECK_OK(gr_tune_param_lookup("--params", keys[k], &p->params[k], &err), err);
            p->params[k].lo = lo[k];
            p->params[k].hi = hi[k];
        }
        p->metric = GR_METRIC_RMSE;
        p->fit = 0;
        gr_image *truth = gr_image_create(W, H, 3, NULL);
        p->refs[0] = truth;
        CHECK_OK(gr_tune_problem_init(p, &err), err);
        gr_section_store st;
        CHECK_OK(gr_tune_settings_at(p, truth_x, st.bytes, &err), err);
        CHECK_OK(gr_technique_render(t, scene, st.bytes, truth, NULL, &err), err);
        double f_true = -1;
        CHECK_OK(gr_tune_evaluate(p, truth_x, &f_true, NULL, NULL, &err), err);
        CHECK_NEAR(f_true, 0.0, 0.0); /* deterministic technique: the truth scores exactly 0 */

        gr_opt_options o = {.n_starts = 3, .x0 = starts[run], .max_evals = 90};
        gr_opt_result res;
        CHECK_OK(gr_opt_minimize(2, lo, hi, gr_tune_objective, p, &o, &res, &err), err);
        printf("start (%.3g, %.3g) -> extinction_scale %.5f (true %.3g), caustics %.5f (true %.3g), rmse %.3g, %d evals\n",
               starts[run][0], starts[run][1], res.x[0], truth_x[0], res.x[1], truth_x[1], res.f, res.evals);
        CHECK_REL(res.x[0], truth_x[0], 0.02);
        CHECK_REL(res.x[1], truth_x[1], 0.02);
        gr_tune_problem_free(p);
        free(p);
        gr_image_destroy(truth);
    }
    gr_technique_destroy(t);
    gr_gl_destroy(gl);
    free(scene);
    CHECK_DONE();
}
