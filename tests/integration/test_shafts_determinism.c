/* Same scene, same settings: the same bytes, whether rendered twice in one renderer, after
 * a render with other settings in between, or in a fresh renderer (new context, programs,
 * buffers). Different settings must give different bytes (or the test could not fail).
 * Uses data/scenes/default.json (waves, a box and a sphere occluder) at 160x90. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_test.h"
#include "shafts_test.h"

static gr_scene *load_default(const char *const *sets, int n)
{
    return test_scene_file("default.json", sets, n);
}

static int same(const gr_image *a, const gr_image *b)
{
    return a->width == b->width && a->height == b->height &&
           memcmp(a->pixels, b->pixels, (size_t)a->width * (size_t)a->height * 3 * sizeof(float)) == 0;
}

int main(void)
{
    static const char *const base[] = {"camera.width=160", "camera.height=90", "water.time_s=2.5"};
    static const char *const other[] = {"camera.width=160", "camera.height=90", "water.time_s=2.5", "shafts.K=0.6",
                                        "shafts.target_format=rgba16f"};
    gr_scene *s = load_default(base, 3);
    gr_scene *s2 = load_default(other, 5);

    gr_shafts *r = shafts_test_renderer();
    gr_image *a = shafts_test_render(r, s, NULL);
    gr_image *b = shafts_test_render(r, s, NULL);
    gr_image *x = shafts_test_render(r, s2, NULL);
    gr_image *c = shafts_test_render(r, s, NULL);
    gr_shafts_destroy(r);
    gr_shafts *r2 = shafts_test_renderer();
    gr_image *d = shafts_test_render(r2, s, NULL);
    gr_shafts_destroy(r2);

    CHECK_MSG(same(a, b), "two renders in a row differ");
    CHECK_MSG(same(a, c), "a render after other settings differs");
    CHECK_MSG(same(a, d), "a fresh renderer gives other bytes");
    CHECK_MSG(!same(a, x), "other settings gave the same bytes");

    gr_image_destroy(a); gr_image_destroy(b); gr_image_destroy(c); gr_image_destroy(d); gr_image_destroy(x);
    free(s);
    free(s2);
    CHECK_DONE();
}
