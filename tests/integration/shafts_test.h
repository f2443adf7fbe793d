/* Helpers shared by the tests/integration/test_shafts_*.c programs (header-only). */
#ifndef GR_SHAFTS_TEST_H
#define GR_SHAFTS_TEST_H

#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "realtime/shafts.h"
#include "scene/scene.h"

/* Loads a scene from JSON with optional "key=value" overrides; exits the test on failure. */
static inline gr_scene *shafts_test_scene(const char *json, const char *const *sets, int n_sets)
{
    gr_error err;
    gr_scene *s = malloc(sizeof *s);
    if (!s) exit(1);
    gr_technique_count(); /* the built-in techniques' sections ("shafts") */
    if (gr_scene_load_string(json, "test scene", sets, n_sets, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load the test scene: %s\n", err.msg);
        exit(1);
    }
    return s;
}

static inline gr_shafts *shafts_test_renderer(void)
{
    gr_error err;
    gr_shafts *r = NULL;
    if (gr_shafts_create(NULL, &r, &err) != GR_OK) {
        fprintf(stderr, "cannot create the shafts renderer: %s\n", err.msg);
        exit(1);
    }
    return r;
}

/* Renders scene with its own settings into a new image; exits the test on failure. */
static inline gr_image *shafts_test_render(gr_shafts *r, const gr_scene *s, gr_shafts_stats *stats)
{
    gr_error err;
    gr_image *img = gr_image_create(s->camera.width, s->camera.height, 3, NULL);
    if (!img) exit(1);
    if (gr_shafts_render(r, s, NULL, img, stats, &err) != GR_OK) {
        fprintf(stderr, "render failed: %s\n", err.msg);
        exit(1);
    }
    return img;
}

static inline gr_image *shafts_test_target(gr_shafts *r)
{
    gr_error err;
    gr_image *t = NULL;
    if (gr_shafts_read_target(r, &t, &err) != GR_OK) {
        fprintf(stderr, "target readback failed: %s\n", err.msg);
        exit(1);
    }
    return t;
}

#endif
