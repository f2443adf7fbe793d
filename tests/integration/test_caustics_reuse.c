/* The caustic stack's reuse for searches (caustics.h gr_caustics_set_reuse, technique.h
 * gr_technique_set_reuse): a build whose inputs recur takes the kept stack, texel for texel the
 * stack a fresh build draws; any changed input (water time, sun, a parameter, the patch origin)
 * draws anew; off, every build draws. Then through a volume technique: renders with reuse on,
 * in an order where stacks recur, give the bytes of renders with reuse off and the same cost
 * counters. The oracle of "the same" is a fresh build (a second instance, reuse off). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "gl/gl.h"
#include "gl/glctx.h"
#include "image/image.h"
#include "realtime/caustics.h"
#include "realtime/frame.h"
#include "realtime/technique.h"
#include "scene/scene.h"

static gr_scene *load_with(const char *json, const char *const *overrides, int n)
{
    gr_error err;
    gr_scene *s = malloc(sizeof *s);
    if (!s || gr_scene_load_string(json, "test scene", overrides, n, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load the test scene: %s\n", s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

/* 1 when every layer of a's current stack equals b's, texel for texel. */
static int same_stack(gr_caustics *a, gr_caustics *b, int layers)
{
    gr_error err;
    int same = 1;
    for (int l = 0; l < layers; l++) {
        gr_image *ia = NULL, *ib = NULL;
        CHECK_OK(gr_caustics_read(a, l, &ia, &err), err);
        CHECK_OK(gr_caustics_read(b, l, &ib, &err), err);
        if (!ia || !ib) exit(1);
        same = same && ia->width == ib->width &&
               !memcmp(ia->pixels, ib->pixels, sizeof(float) * (size_t)ia->width * (size_t)ia->height);
        gr_image_destroy(ia);
        gr_image_destroy(ib);
    }
    return same;
}

#define SCENE_FMT                                                                                                     \
    "{\"water\": {\"time_s\": %g, \"waves\": [{\"amplitude_m\": 0.1, \"wavelength_m\": 5, \"direction_deg\": 30}," \
    "{\"amplitude_m\": 0.05, \"wavelength_m\": 2.2, \"direction_deg\": 110}]},"                                      \
    "\"sun\": {\"elevation_deg\": %g, \"azimuth_deg\": 20}, \"camera\": {\"position_m\": [%g, -5, 0.2],"            \
    "\"width\": 48, \"height\": 27}, \"slicing\": {\"slices\": 8, \"texture_size\": 64, \"grid\": 32,"             \
    "\"caustic_depths\": 4}}"

static gr_scene *scene_at(double time_s, double elev, double eye_x, const char *override)
{
    char json[1024];
    snprintf(json, sizeof json, SCENE_FMT, time_s, elev, eye_x);
    return load_with(json, &override, override ? 1 : 0);
}

int main(void)
{
    gr_error err;
    gr_technique_count(); /* registers the techniques' scene sections */
    gr_gl *gl = NULL;
    CHECK_OK(gr_gl_create(NULL, &gl, &err), err);
    gr_caustics *c = NULL, *fresh = NULL;
    CHECK_OK(gr_caustics_create(NULL, &c, &err), err);
    CHECK_OK(gr_caustics_create(NULL, &fresh, &err), err);
    if (!c || !fresh) return 1;
    gr_caustics_params p = {.size = 64, .grid = 32, .patch_m = 16.0, .n_depths = 3, .fresnel = 1};
    p.depths_m[0] = 1.0;
    p.depths_m[1] = 4.0;
    p.depths_m[2] = 12.0;
    gr_caustics_params p2 = p;
    p2.grid = 48;

    /* scenes: A; A later; A with another sun; A with the eye in the next patch (another origin) */
    gr_scene *sc[4] = {scene_at(0.0, 60, 0.3, NULL), scene_at(0.5, 60, 0.3, NULL), scene_at(0.0, 50, 0.3, NULL),
                      scene_at(0.0, 60, 17.0, NULL)};
    const char *name[4] = {"A", "A at t = 0.5 s", "A, sun at 50 deg", "A, eye in the next patch"};
    gr_frame f[4];
    for (int i = 0; i < 4; i++) gr_frame_init(sc[i], &f[i]);

    gr_caustics_set_reuse(c, 1);
    /* first builds: each draws (base level 1) */
    for (int i = 0; i < 4; i++) {
        CHECK_OK(gr_caustics_build(c, sc[i], &f[i], &p, &err), err);
        CHECK_MSG(gr_caustics_base_level(c) == 1, "%s, first build: drawn", name[i]);
    }
    CHECK_OK(gr_caustics_build(c, sc[0], &f[0], &p2, &err), err);
    CHECK_MSG(gr_caustics_base_level(c) == 1, "A with another grid: drawn");
    /* again, in another order: each takes its kept stack, equal to a fresh build's */
    const int order[5] = {2, 0, 3, 1, 0};
    for (int k = 0; k < 5; k++) {
        const int i = order[k];
        CHECK_OK(gr_caustics_build(c, sc[i], &f[i], &p, &err), err);
        CHECK_MSG(gr_caustics_base_level(c) == 0, "%s again: the kept stack", name[i]);
        CHECK_OK(gr_caustics_build(fresh, sc[i], &f[i], &p, &err), err);
        CHECK_MSG(same_stack(c, fresh, p.n_depths), "%s: the kept stack = a fresh build, texel for texel", name[i]);
        gr_pass_cost ca, cb;
        gr_caustics_cost(c, &ca);
        gr_caustics_cost(fresh, &cb);
        CHECK_MSG(!memcmp(ca.v, cb.v, sizeof ca.v), "%s: the kept stack's cost counters = a build's", name[i]);
        CHECK_MSG(gr_caustics_triangles(c) == gr_caustics_triangles(fresh), "%s: triangles", name[i]);
    }
    CHECK_OK(gr_caustics_build(c, sc[0], &f[0], &p2, &err), err);
    CHECK_MSG(gr_caustics_base_level(c) == 0, "A with another grid again: its own kept stack");
    CHECK_OK(gr_caustics_build(fresh, sc[0], &f[0], &p2, &err), err);
    CHECK_MSG(same_stack(c, fresh, p2.n_depths), "A with another grid: = a fresh build");
    /* a kept stack read while the build's own texture holds another size and layer count */
    gr_caustics_params p3 = p;
    p3.size = 32;
    p3.n_depths = 2;
    CHECK_OK(gr_caustics_build(c, sc[1], &f[1], &p3, &err), err);
    CHECK_OK(gr_caustics_build(c, sc[0], &f[0], &p, &err), err);
    CHECK_MSG(gr_caustics_base_level(c) == 0, "A after a smaller build: the kept stack");
    CHECK_OK(gr_caustics_build(fresh, sc[0], &f[0], &p, &err), err);
    CHECK_MSG(same_stack(c, fresh, p.n_depths), "A after a smaller build: every layer at its own size");
    /* off: every build draws */
    gr_caustics_set_reuse(c, 0);
    CHECK_OK(gr_caustics_build(c, sc[0], &f[0], &p, &err), err);
    CHECK_MSG(gr_caustics_base_level(c) == 1, "reuse off: drawn");
    gr_caustics_destroy(c);
    gr_caustics_destroy(fresh);

    /* Through a volume technique: reuse on (a search), renders of A, B, A with another look
     * setting, B, A; each equals the render of an instance with reuse off, with the same cost. */
    const gr_technique_class *cls = gr_technique_find("slicing");
    CHECK_MSG(cls != NULL, "the slicing technique is registered");
    if (!cls) return 1;
    gr_technique *r = NULL, *o = NULL;
    CHECK_OK(gr_technique_create(cls, gl, NULL, &r, &err), err);
    CHECK_OK(gr_technique_create(cls, gl, NULL, &o, &err), err);
    gr_scene *look = scene_at(0.0, 60, 0.3, "slicing.g=0.7");
    gr_scene *seq[5] = {sc[0], sc[1], look, sc[1], sc[0]};
    static const char *const rgb[3] = {"R", "G", "B"};
    for (int k = 0; k < 5; k++) {
        gr_image *a = gr_image_create(48, 27, 3, rgb), *b = gr_image_create(48, 27, 3, rgb);
        if (!a || !b) return 1;
        gr_technique_stats sa, sb;
        gr_technique_set_reuse(r, 1);
        CHECK_OK(gr_technique_render(r, seq[k], NULL, a, &sa, &err), err);
        gr_technique_set_reuse(r, 0);
        CHECK_OK(gr_technique_render(o, seq[k], NULL, b, &sb, &err), err);
        CHECK_MSG(!memcmp(a->pixels, b->pixels, sizeof(float) * 3 * 48 * 27),
                  "render %d with reuse = without, byte for byte", k);
        int same_cost = sa.n_passes == sb.n_passes;
        for (int q = 0; same_cost && q < sa.n_passes; q++)
            same_cost = !memcmp(sa.cost[q].v, sb.cost[q].v, sizeof sa.cost[q].v);
        CHECK_MSG(same_cost, "render %d: the same cost counters", k);
        gr_image_destroy(a);
        gr_image_destroy(b);
    }
    gr_technique_destroy(r);
    gr_technique_destroy(o);
    for (int i = 0; i < 4; i++) free(sc[i]);
    free(look);
    gr_gl_destroy(gl);
    CHECK_DONE();
}
