/* Helpers shared by the ground-truth tests (tests/unit/test_ref_*.c): scenes from JSON
 * text, one-call renders, and the reduced-run switch. */
#ifndef GR_TEST_REF_UTIL_H
#define GR_TEST_REF_UTIL_H
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "reference/integrator.h"
#include "scene/scene.h"

/* CI sets GODRAYS_TEST_REDUCED=1 for slow tests: a smaller variant that checks the same
 * property. GODRAYS_TEST_FULL=1 forces the full variant. */
static inline int ref_reduced(void)
{
    const char *f = getenv("GODRAYS_TEST_FULL"), *r = getenv("GODRAYS_TEST_REDUCED");
    if (f && *f == '1') return 0;
    return r && *r == '1';
}

/* Loads a scene from printf-formatted JSON; exits the test on failure (test code only). */
static inline gr_scene *ref_scene(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline gr_scene *ref_scene(const char *fmt, ...)
{
    char *json = malloc(1 << 16);
    gr_scene *s = malloc(sizeof *s);
    if (!json || !s) { fprintf(stderr, "out of memory\n"); exit(1); }
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(json, 1 << 16, fmt, ap);
    va_end(ap);
    gr_error err = {GR_OK, ""};
    if (gr_scene_load_string(json, "test scene", NULL, 0, s, &err) != GR_OK) {
        fprintf(stderr, "scene failed to load: %s\n%s\n", err.msg, json);
        exit(1);
    }
    free(json);
    return s;
}

/* Renders s with options o (NULL = defaults, quiet); exits the test on failure. */
static inline void ref_render(const gr_scene *s, const gr_ref_options *o, gr_ref_result *res)
{
    gr_ref_options opt;
    if (o) opt = *o;
    else gr_ref_options_default(&opt);
    opt.progress = 0;
    gr_error err = {GR_OK, ""};
    gr_ref_renderer *r = NULL;
    if (gr_ref_create(s, &opt, &r, &err) != GR_OK || gr_ref_render(r, res, &err) != GR_OK) {
        fprintf(stderr, "render failed: %s\n", err.msg);
        exit(1);
    }
    gr_ref_destroy(r);
}
#endif
