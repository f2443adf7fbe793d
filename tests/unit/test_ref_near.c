/* Refinement near the camera (docs/reference.md 2.2, "Near the camera"). The default scene
 * with the camera pitched 5 degrees up (a level view, the commonest in a game): its lit region
 * is wide, so the plain grid has few cells across the shortest wave, and the tessellation's
 * bias, which lives near the camera, is large. The oracle is a render with a 3x finer uniform
 * tessellation and no refinement near the camera (an independent discretization of the same
 * surface, converging to the exact one):
 *  - without the refinement the coarse render's image mean is off by more than 3 % in some
 *    channel (the effect the refinement exists for: the check would pass vacuously otherwise);
 *  - with it (the defaults: factor 3 within 24 plain cells of P_s) every channel's image mean is within
 *    2 % of the fine render, and the error is at most a third of the unrefined one's;
 *  - the metadata states the refinement (godrays:surface_refine_near) and the plain grid's
 *    cells per shortest wave;
 *  - the default scene, whose plain grid has 8.2 cells across its shortest wave (above the
 *    default's 6.4), builds no set near the camera (its pixels are those of before).
 * 48 x 27 pixels, 4 passes in 4 batches, no bias probe, surface_res 128 and 384: about 9 s
 * on 2 cores (the fine render's builds). */
#include "check.h"
#include "test_ref_util.h"

#include <math.h>
#include <string.h>

static void image_mean(const gr_ref_result *res, double m[3])
{
    const gr_image *im = res->image;
    m[0] = m[1] = m[2] = 0.0;
    size_t n = (size_t)im->width * (size_t)im->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) m[c] += im->pixels[i * (size_t)im->nchannels + (size_t)c];
    for (int c = 0; c < 3; c++) m[c] /= (double)n;
}

static gr_ref_result render(const char *scene, int res, double cpw)
{
    char r_[64], c_[64];
    snprintf(r_, sizeof r_, "reference.surface_res=%d", res);
    snprintf(c_, sizeof c_, "reference.near_cells_per_wavelength=%g", cpw);
    /* cpw < 0: the default rule */
    const char *ov[] = {"camera.width=48", "camera.height=27", "reference.sun_samples=4", "reference.batches=4",
                        "reference.bias_probe=false", r_, cpw >= 0.0 ? c_ : "reference.seed=1", "camera.pitch_deg=5"};
    gr_scene *s = ref_scene_file(scene, ov, 8);
    gr_ref_result out;
    ref_render(s, NULL, &out);
    free(s);
    return out;
}

static const char *meta_string(const gr_ref_result *r, const char *key)
{
    const gr_meta_item *it = gr_meta_get(&r->meta, key);
    return it ? (it->type == GR_META_STRING ? it->str : "") : NULL;
}

static double meta_num(const gr_ref_result *r, const char *key)
{
    const gr_meta_item *it = gr_meta_get(&r->meta, key);
    return it && it->type != GR_META_STRING ? it->num : NAN;
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char scene[4096];
    snprintf(scene, sizeof scene, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    gr_ref_result off = render(scene, 128, 0.0), on = render(scene, 128, -1.0), fine = render(scene, 384, 0.0);
    double mo[3], mn[3], mf[3], eo = 0.0, en = 0.0;
    image_mean(&off, mo);
    image_mean(&on, mn);
    image_mean(&fine, mf);
    for (int c = 0; c < 3; c++) {
        double a = fabs(mo[c] - mf[c]) / mf[c], b = fabs(mn[c] - mf[c]) / mf[c];
        printf("channel %c: fine %.6g, unrefined %+.2f %%, refined near the camera %+.2f %%\n", "RGB"[c], mf[c],
               100.0 * (mo[c] - mf[c]) / mf[c], 100.0 * (mn[c] - mf[c]) / mf[c]);
        eo = fmax(eo, a);
        en = fmax(en, b);
        CHECK_MSG(b <= 0.02, "channel %c: refined near the camera, within 2 %% of the 3x finer surface (%.2f %%)",
                  "RGB"[c], 100.0 * b);
    }
    CHECK_MSG(eo > 0.03, "the unrefined render is off by more than 3 %% in some channel (%.2f %%): the case needs it",
              100.0 * eo);
    CHECK_MSG(en <= eo / 3.0, "the refinement takes the worst channel's error to a third or less (%.2f %% -> %.2f %%)",
              100.0 * eo, 100.0 * en);
    const char *near = meta_string(&on, "godrays:surface_refine_near");
    CHECK_MSG(near && strstr(near, "factor 3 within"), "the metadata states the refinement: %s", near ? near : "(none)");
    if (near) printf("%s\n", near);
    CHECK(meta_string(&off, "godrays:surface_refine_near") == NULL);
    /* the plain grid's cells across the 1 m wave: the lit region's side over surface_res */
    double cpw = meta_num(&on, "godrays:surface_cells_per_wave"), cell = meta_num(&on, "godrays:surface_cell_m");
    printf("plain grid: %.4g m cells, %.4g across the shortest wave\n", cell, cpw);
    CHECK_REL(cpw, 1.0 / cell, 1e-6);
    gr_ref_result_free(&off);
    gr_ref_result_free(&on);
    gr_ref_result_free(&fine);

    /* the default scene at its own settings: no set near the camera (gr_ref_get_info: the
     * decision is made when the renderer is created) */
    gr_scene *ds = ref_scene_file(scene, NULL, 0);
    gr_ref_options opt;
    gr_ref_options_default(&opt);
    opt.progress = 0;
    gr_error err = {GR_OK, ""};
    gr_ref_renderer *r = NULL;
    CHECK_OK(gr_ref_create(ds, &opt, &r, &err), err);
    if (r) {
        gr_ref_info info;
        gr_ref_get_info(r, &info);
        printf("default scene: %.4g cells across the shortest wave, near factor %d\n", info.cells_per_wave, info.near_factor);
        CHECK(info.cells_per_wave > ds->reference.near_cells_per_wavelength);
        CHECK(info.near_factor == 1);
        CHECK(info.near_cells == 0.0);
        gr_ref_destroy(r);
    }
    free(ds);
    CHECK_DONE();
}
