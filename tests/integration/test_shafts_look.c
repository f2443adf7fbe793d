/* Acceptance (issue 12, part 1): the shafts' default settings have the seed's look on the
 * default scene.
 *  - Structure: the band-pass energy (streak contrast, compare/structure.h: RMS of the local
 *    band-pass contrast of the de-glowed luminance) of the default render is within a factor
 *    2 of the ground truth's. The oracle is the Embree ground truth (reference/truth.h: from the
 *    reference cache, rendered and stored when absent).
 *  - Shadows: removing both occluders changes the layer by more than 2 % of its mean
 *    (mean |dY| / mean Y, Rec. 709 luminance), i.e. the 8-bit target does not saturate.
 * Slow (a ground truth): the reduced variant (GODRAYS_TEST_REDUCED=1) runs at 160 x 90
 * (~1 min of Embree on 2 quiet cores the first time, then cached) and checks both. */
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/structure.h"
#include "realtime/shafts.h"
#include "report/profile.h"
#include "scene/scene.h"
#include "reference/truth.h"

static int reduced(void)
{
    const char *v = getenv("GODRAYS_TEST_REDUCED");
    return v && v[0] && strcmp(v, "0") != 0;
}

static gr_scene *load(int w, int h, int no_occluders)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[4096], sw[64], sh[64];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    snprintf(sw, sizeof sw, "camera.width=%d", w);
    snprintf(sh, sizeof sh, "camera.height=%d", h);
    const char *sets[3] = {sw, sh, "occluders=[]"};
    gr_scene *s = malloc(sizeof *s);
    gr_error err;
    if (!s || gr_scene_load_file(path, sets, no_occluders ? 3 : 2, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

static double lum(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

int main(void)
{
    const int w = reduced() ? 160 : 320, h = reduced() ? 90 : 180;
    gr_error err = {0};
    gr_shafts *r = NULL;
    CHECK_OK(gr_shafts_create(NULL, &r, &err), err);
    if (!r) CHECK_DONE();
    gr_scene *s = load(w, h, 0), *sn = load(w, h, 1);
    const gr_shafts_settings *d = gr_shafts_scene_settings(s);
    CHECK(d->variant == GR_SHAFTS_SEED && d->target_format == GR_TARGET_RGBA8 && d->g == 0.5);
    gr_image *img = gr_image_create(w, h, 3, NULL), *imgn = gr_image_create(w, h, 3, NULL);
    CHECK_OK(gr_shafts_render(r, s, NULL, img, NULL, &err), err);
    CHECK_OK(gr_shafts_render(r, sn, NULL, imgn, NULL, &err), err);

    /* shadows: the occluders change the layer by more than 2 % of its mean */
    double dy = 0.0, my = 0.0;
    for (size_t q = 0; q < (size_t)w * h; q++) {
        dy += fabs(lum(img->pixels + 3 * q) - lum(imgn->pixels + 3 * q));
        my += lum(imgn->pixels + 3 * q);
    }
    printf("occluders change the layer by %.2f %% of its mean\n", 100.0 * dy / my);
    CHECK_MSG(dy > 0.02 * my, "removing the occluders changes the layer by %.3f %% of its mean", 100.0 * dy / my);

    /* structure: band-pass energy within a factor 2 of the truth's */
    gr_image *truth = NULL;
    gr_truth_info info;
    CHECK_OK(gr_truth_image(s, NULL, &truth, &info, &err), err);
    if (truth) {
        printf("truth %d x %d %s (%.1f s)\n", w, h, info.cached ? "from the cache" : "rendered", info.seconds);
        float *ang = malloc((size_t)w * h * sizeof(float));
        double dir[3];
        gr_profile_sun_view_dir(s, dir);
        gr_profile_angles(&s->camera, dir, ang);
        gr_structure_options o = {.radial = ang, .radial_bin = s->camera.fov_deg / h};
        CHECK_OK(gr_structure_scene_vp(s, w, h, &o.vp_x, &o.vp_y, &err), err);
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(truth, img, &o, &c, &err), err);
        printf("streak contrast: truth %.4f, default shafts %.4f (ratio %.3f); band-pass corr %.3f\n",
               c.ref.streak_contrast, c.test.streak_contrast, c.contrast_ratio, c.bandpass_corr);
        CHECK_MSG(c.contrast_ratio >= 0.5 && c.contrast_ratio <= 2.0, "band-pass energy ratio %.3f outside [0.5, 2]",
                  c.contrast_ratio);
        free(ang);
        gr_image_destroy(truth);
    }
    gr_image_destroy(img), gr_image_destroy(imgn);
    free(s), free(sn);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
