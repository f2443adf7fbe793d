/* Loading the project's scenes in integration tests (header-only): exits the test with a
 * message when a scene cannot be loaded. */
#ifndef GR_SCENE_TEST_H
#define GR_SCENE_TEST_H

#include <stdio.h>
#include <stdlib.h>

#include "realtime/technique.h"
#include "scene/scene.h"

/* data/scenes/NAME (e.g. "default.json") with "key=value" overrides. */
static inline gr_scene *test_scene_file(const char *name, const char *const *sets, int n_sets)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    char path[4096];
    snprintf(path, sizeof path, "%s/data/scenes/%s", src ? src : GR_SOURCE_DIR, name);
    gr_scene *s = malloc(sizeof *s);
    gr_error err;
    gr_technique_count(); /* the built-in techniques' sections ("shafts") */
    if (!s || gr_scene_load_file(path, sets, n_sets, s, &err) != GR_OK) {
        fprintf(stderr, "cannot load %s: %s\n", path, s ? err.msg : "out of memory");
        exit(1);
    }
    return s;
}

/* The same at w x h, then the overrides (at most 30). */
static inline gr_scene *test_data_scene(const char *name, int w, int h, const char *const *extra, int n_extra)
{
    char sw[64], sh[64];
    snprintf(sw, sizeof sw, "camera.width=%d", w);
    snprintf(sh, sizeof sh, "camera.height=%d", h);
    const char *sets[32] = {sw, sh};
    int n = 2;
    for (int i = 0; i < n_extra && n < 32; i++) sets[n++] = extra[i];
    return test_scene_file(name, sets, n);
}

#endif
