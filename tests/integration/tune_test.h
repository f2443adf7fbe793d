/* Helpers shared by tests/integration/test_tune_*.c (header-only). */
#ifndef GR_TUNE_TEST_H
#define GR_TUNE_TEST_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "scene_test.h"
#include "realtime/shafts.h"
#include "scene/scene.h"
#include "tune/objective.h"

/* The default scene (data/scenes/default.json) at w x h plus overrides; exits on failure. */
static inline gr_scene *tune_test_default_scene(int w, int h, const char *const *extra, int n_extra)
{
    return test_data_scene("default.json", w, h, extra, n_extra);
}

/* The context of tune_test_renderer's instances (one per test process). */
static gr_gl *tune_test_gl;

/* The shafts technique in a context of its own; destroy with tune_test_renderer_destroy. */
static inline gr_technique *tune_test_renderer(void)
{
    gr_error err;
    gr_technique *r = NULL;
    if (gr_gl_create(NULL, &tune_test_gl, &err) != GR_OK ||
        gr_technique_create(&gr_shafts_class, tune_test_gl, NULL, &r, &err) != GR_OK) {
        fprintf(stderr, "cannot create the shafts renderer: %s\n", err.msg);
        exit(1);
    }
    return r;
}

static inline void tune_test_renderer_destroy(gr_technique *r)
{
    gr_technique_destroy(r);
    gr_gl_destroy(tune_test_gl);
    tune_test_gl = NULL;
}

/* p's class and base settings: the scene's shafts section. */
static inline void tune_test_base(gr_tune_problem *p, const gr_scene *scene)
{
    p->cls = &gr_shafts_class;
    memcpy(p->base.bytes, gr_shafts_scene_settings(scene), sizeof(gr_shafts_settings));
}

/* 1 if GODRAYS_TEST_REDUCED is set to a non-empty value other than "0" */
static inline int tune_test_reduced(void)
{
    const char *v = getenv("GODRAYS_TEST_REDUCED");
    return v && v[0] && strcmp(v, "0") != 0;
}

#endif
