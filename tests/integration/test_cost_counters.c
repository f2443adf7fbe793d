/* The per-pass cost counters (realtime/technique.h, docs/techniques.md "Cost counters") against
 * closed forms on small synthetic cases: the radial blur's taps = pixels x (samples + 1), its
 * queried fragments = pixels; the shafts' final pass = 4 taps a pixel, their pass's vertices =
 * 36 (N - 1)^2; the slices' queried primitives = the slice count (one instanced triangle
 * each; at target_scale 0.5 a quarter of the pixels, + an upsample of W x H); the froxel dispatches' invocations = the grid rounded up to 8 x 8 groups; the caustic
 * stack's indices = 6 grid^2 depths; light rays' points = rays^2; the sums and the EXR
 * metadata. Counters read from GL queries are checked against the analytic expectation, so a
 * broken query fails too. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gl/glctx.h"
#include "realtime/technique.h"
#include "scene_test.h"

#define W 64
#define H 36

static int pass_index(const gr_technique_stats *st, const char *name)
{
    for (int p = 0; p < st->n_passes; p++)
        if (strcmp(st->pass_names[p], name) == 0) return p;
    return -1;
}

/* Counter k of pass `name`, -2 if the pass is missing. */
static long long cost(const gr_technique_stats *st, const char *name, int k)
{
    int p = pass_index(st, name);
    return p < 0 ? -2 : st->cost[p].v[k];
}

static void render(gr_gl *gl, const char *tech, const char *const *sets, int n, gr_technique_stats *st,
                   gr_metadata *meta)
{
    gr_error err;
    gr_scene *s = test_data_scene("default.json", W, H, sets, n);
    const gr_technique_class *cls = gr_technique_find(tech);
    CHECK_MSG(cls != NULL, "%s: not registered", tech);
    if (!cls) exit(1);
    gr_technique *t = NULL;
    CHECK_OK(gr_technique_create(cls, gl, NULL, &t, &err), err);
    gr_image *img = gr_image_create(W, H, 3, NULL);
    if (!t || !img) exit(1);
    gr_technique_stats_clear(st);
    CHECK_OK(gr_technique_render(t, s, NULL, img, st, &err), err);
    if (meta) CHECK_OK(gr_technique_metadata(t, s, NULL, st, meta, &err), err);
    char line[512];
    for (int p = 0; p < st->n_passes; p++) {
        gr_pass_cost_text(&st->cost[p], line, sizeof line);
        printf("%s %s: %s\n", tech, st->pass_names[p], line);
    }
    gr_image_destroy(img);
    gr_technique_destroy(t);
    free(s);
}

static void check_radial_blur(gr_gl *gl)
{
    const char *sets[] = {"radial_blur.samples=10", "radial_blur.target_scale=0.5"};
    gr_technique_stats st;
    gr_metadata meta;
    gr_meta_init(&meta);
    render(gl, "radial_blur", sets, 2, &st, &meta);
    const long long px = (long long)W * H;
    CHECK(cost(&st, "blur", GR_COST_FRAGMENTS) == px); /* GL_SAMPLES_PASSED */
    CHECK(st.cost[pass_index(&st, "blur")].queried & (1u << GR_COST_FRAGMENTS));
    CHECK(cost(&st, "blur", GR_COST_TAPS) == px * (10 + 1));
    CHECK(cost(&st, "blur", GR_COST_BYTES) == px * 16);
    CHECK(cost(&st, "blur", GR_COST_VERTICES) == 3);
    CHECK(cost(&st, "blur", GR_COST_PRIMITIVES) == 1); /* GL_PRIMITIVES_GENERATED */
    CHECK(cost(&st, "light", GR_COST_FRAGMENTS) == (W / 2) * (H / 2));
    gr_pass_cost tot;
    gr_technique_cost_total(&st, &tot);
    long long sum = 0;
    for (int p = 0; p < st.n_passes; p++) sum += st.cost[p].v[GR_COST_TAPS] > 0 ? st.cost[p].v[GR_COST_TAPS] : 0;
    CHECK(tot.v[GR_COST_TAPS] == sum);
    const gr_meta_item *it = gr_meta_get(&meta, "godrays:cost.blur.taps");
    CHECK(it && it->type != GR_META_STRING && (long long)it->num == px * 11);
    it = gr_meta_get(&meta, "godrays:cost_queried");
    CHECK(it && it->type == GR_META_STRING && strstr(it->str, "blur.fragments"));
    gr_meta_free(&meta);
}

static void check_shafts(gr_gl *gl)
{
    const char *sets[] = {"shafts.N=5", "shafts.caps=true", "shafts.stable_grid=false", "shafts.variant=seed"};
    gr_technique_stats st;
    render(gl, "shafts", sets, 4, &st, NULL);
    CHECK(cost(&st, "final", GR_COST_FRAGMENTS) == (long long)W * H);
    CHECK(cost(&st, "final", GR_COST_TAPS) == 4LL * W * H);
    CHECK(cost(&st, "final", GR_COST_PRIMITIVES) == 2); /* a 4-vertex strip, queried */
    CHECK(cost(&st, "shafts", GR_COST_VERTICES) == 36LL * 4 * 4);
    CHECK(cost(&st, "shafts", GR_COST_PRIMITIVES) == 12LL * 4 * 4); /* queried */
    CHECK(cost(&st, "shafts", GR_COST_FRAGMENTS) == st.fragments);
}

static void check_volumes(gr_gl *gl)
{
    const char *sl[] = {"slicing.slices=4", "slicing.texture_size=16", "slicing.grid=8", "slicing.caustic_depths=2"};
    gr_technique_stats st;
    render(gl, "slicing", sl, 4, &st, NULL);
    CHECK(cost(&st, "slices", GR_COST_FRAGMENTS) == 4LL * W * H);
    CHECK(cost(&st, "slices", GR_COST_PRIMITIVES) == 4); /* queried: one triangle an instance */
    CHECK(cost(&st, "caustics", GR_COST_VERTICES) == 6LL * 8 * 8 * 2);
    CHECK(cost(&st, "caustics", GR_COST_FRAGMENTS) > 0);
    CHECK(cost(&st, "upsample", GR_COST_FRAGMENTS) == -2); /* no upsample at target_scale 1 */
    /* at target_scale 0.5 the slices cover (W / 2) x (H / 2), the upsample one pass of W x H */
    const char *slh[] = {"slicing.slices=4", "slicing.texture_size=16", "slicing.grid=8", "slicing.caustic_depths=2",
                         "slicing.target_scale=0.5"};
    render(gl, "slicing", slh, 5, &st, NULL);
    CHECK(cost(&st, "slices", GR_COST_FRAGMENTS) == 4LL * (W / 2) * (H / 2));
    CHECK(cost(&st, "slices", GR_COST_BYTES) == (W / 2) * (H / 2) * 16LL + st.fragments * 16);
    CHECK(st.fragments > 0 && st.fragments <= 4LL * (W / 2) * (H / 2)); /* queried: the slices' only */
    CHECK(cost(&st, "upsample", GR_COST_FRAGMENTS) == (long long)W * H);
    CHECK(cost(&st, "upsample", GR_COST_TAPS) == (long long)W * H);
    CHECK(cost(&st, "upsample", GR_COST_PRIMITIVES) == 1); /* queried */
    const char *fx[] = {"froxel.grid_x=10", "froxel.grid_y=6", "froxel.grid_z=4", "froxel.texture_size=16",
                        "froxel.grid=8", "froxel.caustic_depths=2"};
    render(gl, "froxel", fx, 6, &st, NULL);
    CHECK(cost(&st, "scatter", GR_COST_INVOCATIONS) == 16LL * 8 * 4);
    CHECK(cost(&st, "integrate", GR_COST_INVOCATIONS) == 16LL * 8);
    CHECK(cost(&st, "scatter", GR_COST_BYTES) == 10LL * 6 * 4 * 16);
    CHECK(cost(&st, "apply", GR_COST_FRAGMENTS) == (long long)W * H);
    CHECK(cost(&st, "scatter", GR_COST_PRIMITIVES) == 0); /* queried: a dispatch draws nothing */
    const char *lr[] = {"light_rays.rays=16"};
    render(gl, "light_rays", lr, 1, &st, NULL);
    CHECK(cost(&st, "lines", GR_COST_VERTICES) == 256);
    CHECK(cost(&st, "lines", GR_COST_FRAGMENTS) == st.fragments);
}

int main(void)
{
    gr_error err;
    gr_gl *gl = NULL;
    gr_technique_count();
    CHECK_OK(gr_gl_create(NULL, &gl, &err), err);
    if (!gl) return 1;
    check_radial_blur(gl);
    check_shafts(gl);
    check_volumes(gl);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
