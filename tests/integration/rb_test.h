/* Helpers shared by tests/integration/test_radial_blur_*.c (header-only). */
#ifndef GR_RB_TEST_H
#define GR_RB_TEST_H

#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "realtime/radial_blur.h"

static inline gr_scene *rb_test_scene(const char *json, const char *const *sets, int n)
{
    gr_error err;
    gr_scene *s = malloc(sizeof *s);
    if (!s || gr_scene_load_string(json, "test scene", sets, n, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load the test scene: %s\n", s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

/* Creates a GL context and an instance of cls in it. */
static inline void *rb_test_create(const gr_technique_class *cls, gr_gl **gl)
{
    gr_error err;
    void *state = NULL;
    if (gr_gl_create(NULL, gl, &err) != GR_OK || cls->create(cls, *gl, NULL, &state, &err) != GR_OK) {
        fprintf(stderr, "cannot create %s: %s\n", cls->name, err.msg);
        exit(1);
    }
    return state;
}

/* cls's defaults, resolved for scene. */
static inline void rb_test_settings(const gr_technique_class *cls, const gr_scene *scene, gr_radial_blur_settings *out)
{
    gr_radial_blur_settings d;
    gr_param_defaults(cls->params, &d);
    gr_technique_resolve(cls, scene, &d, out);
}

static inline gr_image *rb_test_render(const gr_technique_class *cls, void *state, const gr_scene *scene,
                                       const gr_radial_blur_settings *s, gr_technique_stats *stats)
{
    gr_error err;
    gr_image *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    if (!img) exit(1);
    if (gr_technique_check(cls, s, &err) != GR_OK || cls->render(state, scene, s, img, stats, &err) != GR_OK) {
        fprintf(stderr, "%s render failed: %s\n", cls->name, err.msg);
        exit(1);
    }
    return img;
}

#endif
