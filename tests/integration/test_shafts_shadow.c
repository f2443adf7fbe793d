/* Acceptance (issue 12): the `path` and `flux` variants apply the occluders' shadows (scenegl's
 * shadow map; docs/realtime-shafts.md "Occluder shadows": path shafts end where their centre
 * ray meets an occluder, flux slabs are weighted by their lit fraction, so the shafts stay
 * closed solids and the signed sums stay paired). On the default scene (a pillar and a rock),
 * each variant with its default settings, rendered with and without the occluders:
 *  - occluders only take light away: the part of the difference where the layer with them is
 *    brighter is below 2 % of the whole difference (an unpaired face would brighten streaks);
 *  - shadows alone (no depth_test) change the layer (> 0.1 % of its mean);
 *  - with depth_test (silhouettes too) the change is at least 0.4 x the ground truth's own
 *    change for the same removal (Embree, cached; the oracle is independent of the shafts).
 * The issue's "> 2 % of its mean" is printed next to the truth's figure: the truth itself
 * changes by ~1 % (phase g 0.9 puts the shadows where little light is scattered toward the
 * eye), so 2 % is not asserted for the physically scaled variants. Slow (two ground truths):
 * 160 x 90, reduced variant (GODRAYS_TEST_REDUCED=1) 64 x 36 with 48 march steps. */
#include "check.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "realtime/shafts.h"
#include "scene/scene.h"
#include "reference/truth.h"

static int W = 160, H = 90;

static int reduced(void)
{
    const char *v = getenv("GODRAYS_TEST_REDUCED");
    return v && v[0] && strcmp(v, "0") != 0;
}

static gr_scene *load(const char *variant, int depth_test, int occluders)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[4096], sw[64], sh[64];
    snprintf(path, sizeof path, "%s/data/scenes/default.json", src ? src : GR_SOURCE_DIR);
    snprintf(sw, sizeof sw, "camera.width=%d", W);
    snprintf(sh, sizeof sh, "camera.height=%d", H);
    const char *sets[6] = {sw, sh, variant, depth_test ? "shafts.depth_test=true" : "shafts.depth_test=false",
                           reduced() ? "reference.steps=48" : "reference.steps=128", "occluders=[]"};
    gr_scene *s = malloc(sizeof *s);
    gr_error err;
    if (!s || gr_scene_load_file(path, sets, occluders ? 5 : 6, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

static void lum(const gr_image *img, double *out)
{
    int ch[3] = {gr_image_channel(img, "R"), gr_image_channel(img, "G"), gr_image_channel(img, "B")};
    for (size_t q = 0; q < (size_t)W * (size_t)H; q++) {
        const float *p = img->pixels + q * (size_t)img->nchannels;
        out[q] = 0.2126 * p[ch[0]] + 0.7152 * p[ch[1]] + 0.0722 * p[ch[2]];
    }
}

/* mean |with - without| / mean(without), and the brighter part: mean max(with - without, 0) /
 * mean |with - without| */
static void change(const double *with, const double *without, double *rel, double *brighter)
{
    double d = 0.0, pos = 0.0, m = 0.0;
    for (size_t q = 0; q < (size_t)W * (size_t)H; q++) {
        d += fabs(with[q] - without[q]);
        pos += fmax(with[q] - without[q], 0.0);
        m += without[q];
    }
    *rel = d / m;
    *brighter = d > 0 ? pos / d : 0.0;
}

int main(void)
{
    gr_error err = {0};
    gr_shafts *r = NULL;
    (void)gr_technique_count(); /* registers the built-in techniques' scene sections */
    CHECK_OK(gr_shafts_create(NULL, &r, &err), err);
    if (!r) CHECK_DONE();
    if (reduced()) W = 64, H = 36;
    size_t n = (size_t)W * (size_t)H;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    gr_image *img = gr_image_create(W, H, 3, NULL);
    if (!a || !b || !img) return 1;

    /* the ground truth's own change */
    gr_scene *sa = load("shafts.variant=seed", 0, 1), *sb = load("shafts.variant=seed", 0, 0);
    gr_image *ta = NULL, *tb = NULL;
    gr_truth_info info;
    CHECK_OK(gr_truth_image(sa, NULL, &ta, &info, &err), err);
    CHECK_OK(gr_truth_image(sb, NULL, &tb, &info, &err), err);
    if (!ta || !tb) return 1;
    lum(ta, a);
    lum(tb, b);
    double truth_rel, truth_pos;
    change(a, b, &truth_rel, &truth_pos);
    printf("%dx%d, removing the occluders: ground truth's change %.4f of its mean\n", W, H, truth_rel);
    gr_image_destroy(ta), gr_image_destroy(tb);
    free(sa), free(sb);

    static const char *const variants[] = {"shafts.variant=path", "shafts.variant=flux"};
    for (int v = 0; v < 2; v++)
        for (int dt = 0; dt < 2; dt++) {
            gr_scene *with = load(variants[v], dt, 1), *without = load(variants[v], dt, 0);
            CHECK_OK(gr_shafts_render(r, with, NULL, img, NULL, &err), err);
            lum(img, a);
            CHECK_OK(gr_shafts_render(r, without, NULL, img, NULL, &err), err);
            lum(img, b);
            double rel, pos;
            change(a, b, &rel, &pos);
            printf("  %s, depth_test %d: change %.4f of the mean (%.2f x the truth's; the issue's 2 %%: %s), "
                   "brighter part %.4f\n", variants[v], dt, rel, rel / truth_rel, rel > 0.02 ? "yes" : "no", pos);
            CHECK_MSG(pos < 0.02, "%s: occluders brighten the layer (%.4f of the change)", variants[v], pos);
            if (!dt) CHECK_MSG(rel > 0.001, "%s: the shadows change the layer by only %.5f", variants[v], rel);
            if (dt)
                CHECK_MSG(rel >= 0.4 * truth_rel, "%s with depth_test: change %.4f < 0.4 x the truth's %.4f",
                          variants[v], rel, truth_rel);
            free(with), free(without);
        }
    gr_image_destroy(img);
    free(a), free(b);
    gr_shafts_destroy(r);
    CHECK_DONE();
}
