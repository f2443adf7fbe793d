/* Refinement near the camera (docs/reference.md 2.2, "Near the camera"). The default scene
 * with the camera pitched 5 degrees up (a level view, the commonest in a game): its lit region
 * is wide, so the plain grid has few cells across the shortest wave, and the tessellation's
 * bias, which lives near the camera, is large. The oracle is a render with a 3x finer uniform
 * tessellation and no refinement near the camera (an independent discretization of the same
 * surface, converging to the exact one; its cells near the camera are those of the refined
 * render, so this part checks that the bias lives near the camera, not the near cells' own
 * error, which the probe part below checks):
 *  - without the refinement the coarse render's image mean is off by more than 3 % in some
 *    channel (the effect the refinement exists for: the check would pass vacuously otherwise);
 *  - with it (the defaults: factor 3 within 24 plain cells of P_s) every channel's image mean is within
 *    2 % of the fine render, and the error is at most a third of the unrefined one's;
 *  - the metadata states the refinement (godrays:surface_refine_near) and the plain grid's
 *    cells per shortest wave;
 *  - the default scene, whose plain grid has 8.2 cells across its shortest wave (above the
 *    default's 6.4), builds no set near the camera (its pixels are those of before).
 * 48 x 27 pixels, 4 passes in 4 batches, no bias probe, surface_res 128 and 384: about 9 s
 * on 2 cores (the fine render's builds).
 * Then the bias probe with the near set (probe_with_near_set, below). */
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

/* 10 x 10 pixel blocks: the 95th percentile over blocks of the worst channel's |a - b| /
 * max(block mean of b, image mean of b) (the normalization of godrays:bias_block_p95_rel) */
static double block_p95(const gr_image *a, const gr_image *b)
{
    enum { B = 10 };
    const int W = b->width, H = b->height, na = a->nchannels, nc = b->nchannels;
    double im[3] = {0.0, 0.0, 0.0}, v[256];
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 3; c++) im[c] += b->pixels[(size_t)i * (size_t)nc + (size_t)c] / (W * H);
    int n = 0;
    for (int by = 0; by + B <= H; by += B)
        for (int bx = 0; bx + B <= W && n < 256; bx += B) {
            double w = 0.0;
            for (int c = 0; c < 3; c++) {
                double sa = 0.0, sb = 0.0;
                for (int y = by; y < by + B; y++)
                    for (int x = bx; x < bx + B; x++) {
                        size_t i = (size_t)y * (size_t)W + (size_t)x;
                        sa += a->pixels[i * (size_t)na + (size_t)c];
                        sb += b->pixels[i * (size_t)nc + (size_t)c];
                    }
                w = fmax(w, fabs(sa - sb) / (B * B) / fmax(sb / (B * B), im[c]));
            }
            int j = n++;
            for (; j > 0 && v[j - 1] > w; j--) v[j] = v[j - 1];
            v[j] = w;
        }
    return n ? v[(int)(0.95 * (n - 1) + 0.5)] : 0.0;
}

/* The bias probe with the set near the camera (docs/reference.md 4, "The probe and the cells
 * near the camera"): where the set reaches its target (surface_res 256: 2.8 plain cells per
 * wave, factor 3, 8.4 near the camera) the probe holds its cells at their size at 2h and 4h
 * and measures their own error with a fourth level, the cells near the camera 2x finer. The
 * oracle is the same render with the near cells 7/3 as fine (factor 7, 19.6 per wave; an
 * independent finer discretization, whose difference from the limit is a fifth of factor 3's
 * at order 2; CI's reduced variant below): the image
 * mean's and the 10 x 10 blocks' differences from it must lie under the figures the render
 * states. The near cells' error is visible at this size (over 1 % at the blocks' 95th
 * percentile, checked), so the check is not vacuous: a probe that held the near cells without
 * the fourth level stated 1.79 % against 2.65 % (factor 9) here. About 20 s on 2 cores. The same render without the near set
 * differs by over 2 % in the image mean: the error of this view lives near the camera. */
static void probe_with_near_set(const char *scene)
{
    /* CI's reduced variant: the oracle's near cells factor 5 (5/3 as fine: 64 % of factor 3's
     * error shows at order 2) instead of 7, both renders' near discs 12 plain cells instead of
     * 24 (the error sits within a few metres of P_s: docs/benchmarks.md, twelfth session), and
     * no render without the near set (the first part of the test shows that at 128 cells):
     * 14 instead of 38 CPU-s */
    const int red = ref_reduced(), Ff = red ? 5 : 7;
    const char *base[] = {"camera.width=64", "camera.height=36", "reference.sun_samples=4", "reference.batches=4",
                          "reference.surface_res=256", "camera.pitch_deg=5", "reference.seed=3",
                          red ? "reference.near_radius_cells=12" : "reference.near_radius_cells=24"};
    enum { NB = 8 };
    const char *ov_rule[NB + 1], *ov_fine[NB + 3], *ov_off[NB + 2];
    for (int i = 0; i < NB; i++) ov_rule[i] = ov_fine[i] = ov_off[i] = base[i];
    ov_rule[NB] = "reference.bias_probe=true";
    ov_fine[NB] = "reference.bias_probe=false";
    char cpw_fine[64], max_fine[64], want_fine[32];
    snprintf(cpw_fine, sizeof cpw_fine, "reference.near_cells_per_wavelength=%d", 2 * Ff + 5);
    snprintf(max_fine, sizeof max_fine, "reference.near_max_factor=%d", Ff);
    snprintf(want_fine, sizeof want_fine, "factor %d within", Ff);
    ov_fine[NB + 1] = cpw_fine;
    ov_fine[NB + 2] = max_fine;
    ov_off[NB] = "reference.bias_probe=false";
    ov_off[NB + 1] = "reference.near_cells_per_wavelength=0";
    gr_scene *s_rule = ref_scene_file(scene, ov_rule, NB + 1), *s_fine = ref_scene_file(scene, ov_fine, NB + 3);
    gr_ref_result rule, fine, off;
    ref_render(s_rule, NULL, &rule);
    ref_render(s_fine, NULL, &fine);
    free(s_rule);
    free(s_fine);
    if (!red) {
        gr_scene *s_off = ref_scene_file(scene, ov_off, NB + 2);
        ref_render(s_off, NULL, &off);
        free(s_off);
    }
    const char *near_fine = meta_string(&fine, "godrays:surface_refine_near");
    CHECK_MSG(near_fine && strstr(near_fine, want_fine), "the finer near set: %s", near_fine ? near_fine : "(none)");
    CHECK_MSG(meta_num(&rule, "godrays:bias_probe_near_held") == 1.0, "the probe held the near cells (%g)",
              meta_num(&rule, "godrays:bias_probe_near_held"));
    const double est = rule.bias_surface_rel, blk = meta_num(&rule, "godrays:bias_block_p95_rel");
    double mr[3], mf[3], mo[3], near_err = 0.0, off_err = 0.0;
    image_mean(&rule, mr);
    image_mean(&fine, mf);
    if (!red) image_mean(&off, mo);
    for (int c = 0; c < 3; c++) {
        near_err = fmax(near_err, fabs(mr[c] - mf[c]) / mf[c]);
        if (!red) off_err = fmax(off_err, fabs(mo[c] - mf[c]) / mf[c]);
    }
    double b_rule = block_p95(rule.image, fine.image);
    printf("probe with the near set: estimate %.3f %%, block p95 %.3f %%; against the near cells %d/3 as fine: "
           "image mean %.3f %%, block p95 %.3f %%",
           100.0 * est, 100.0 * blk, Ff, 100.0 * near_err, 100.0 * b_rule);
    if (!red) printf("; without the near set: image mean %.2f %%", 100.0 * off_err);
    printf("\n");
    if (!red)
        CHECK_MSG(off_err > 0.02, "without the near set the image mean is off by over 2 %% (%.2f %%)", 100.0 * off_err);
    CHECK_MSG(near_err <= est, "the near cells' own error (%.3f %%) lies under the estimate (%.3f %%)", 100.0 * near_err,
              100.0 * est);
    CHECK_MSG(b_rule <= blk, "the near cells' own block error (%.3f %%) lies under the block figure (%.3f %%)",
              100.0 * b_rule, 100.0 * blk);
    CHECK_MSG(b_rule > 0.01, "the near cells' own error is visible at the blocks (%.3f %% over 1 %%)", 100.0 * b_rule);
    gr_ref_result_free(&rule);
    gr_ref_result_free(&fine);
    if (!red) gr_ref_result_free(&off);
}

int main(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char scene[4096];
    snprintf(scene, sizeof scene, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    probe_with_near_set(scene);
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
