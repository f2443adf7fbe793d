/* realtime/technique: the per-render time limit (docs/techniques.md "Time limit", issue 31),
 * with a CPU-only class ("unit_slow") whose render returns GR_E_TIMEOUT when its setting asks,
 * as a user technique's gr_technique_wait_pass does over the limit:
 *  - the limit's sources in order: gr_technique_set_time_limit (--time-limit), then
 *    $GODRAYS_TIME_LIMIT, then the 60 s default; bad values are GR_E_USAGE naming the source;
 *  - a render that timed out abandons its instance: every later render of it is GR_E_TIMEOUT
 *    without calling the class, and destroy does not call the class's destroy (its state
 *    belongs to the abandoned context); a render that did not time out leaves it usable. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/technique.h"
#include "scene/scene.h"

typedef struct slow_settings {
    double level;
    int time_out; /* 1: the render reports GR_E_TIMEOUT */
} slow_settings;

static const gr_param slow_params[] = {
    {.name = "level", .type = GR_PT_DOUBLE, .offset = offsetof(slow_settings, level), .min = 0, .max = 10,
     .def = 0.5, .unit = "", .doc = "output value"},
    {.name = "time_out", .type = GR_PT_BOOL, .offset = offsetof(slow_settings, time_out), .min = 0, .max = 1,
     .def = 0, .unit = "", .doc = "report a timeout"},
};
static const gr_param_table slow_table = {"unit_slow", slow_params, 2};
static int renders, destroyed;

static gr_status slow_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts,
                             void **state, gr_error *err)
{
    *state = &renders;
    return GR_OK;
}

static void slow_destroy(void *state) { destroyed++; }

static gr_status slow_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                             gr_technique_stats *stats, gr_error *err)
{
    const slow_settings *s = settings;
    renders++;
    if (s->time_out) return gr_fail(err, GR_E_TIMEOUT, "unit_slow: pass: over the time limit");
    for (size_t i = 0; i < (size_t)out->width * (size_t)out->height * (size_t)out->nchannels; i++)
        out->pixels[i] = (float)s->level;
    return GR_OK;
}

static const gr_technique_class slow_class = {
    .name = "unit_slow", .description = "CPU test class", .params = &slow_table,
    .settings_size = sizeof(slow_settings), .origin = "test", .create = slow_create,
    .destroy = slow_destroy, .render = slow_render,
};

int main(void)
{
    gr_error err = {GR_OK, ""};
    double s = 0;
    const char *src = NULL;

    /* sources and parsing */
    unsetenv("GODRAYS_TIME_LIMIT");
    CHECK_OK(gr_technique_time_limit(&s, &src, &err), err);
    CHECK(s == GR_TECH_TIME_LIMIT_DEFAULT_S && s == 60.0 && !strcmp(src, "default"));
    setenv("GODRAYS_TIME_LIMIT", "2.5", 1);
    CHECK_OK(gr_technique_time_limit(&s, &src, &err), err);
    CHECK(s == 2.5 && !strcmp(src, "GODRAYS_TIME_LIMIT"));
    gr_technique_set_time_limit(7);
    CHECK_OK(gr_technique_time_limit(&s, &src, &err), err);
    CHECK(s == 7 && !strcmp(src, "--time-limit"));
    gr_technique_set_time_limit(0);
    setenv("GODRAYS_TIME_LIMIT", "soon", 1);
    CHECK(gr_technique_time_limit(&s, &src, &err) == GR_E_USAGE && strstr(err.msg, "GODRAYS_TIME_LIMIT soon"));
    unsetenv("GODRAYS_TIME_LIMIT");
    const char *bad[] = {"0", "-1", "abc", "1e9", "nan", "inf", "", "3s"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK_MSG(gr_technique_parse_time_limit("--time-limit", bad[i], &s, &err) == GR_E_USAGE, "'%s' accepted", bad[i]);
    CHECK_OK(gr_technique_parse_time_limit("--time-limit", "0.25", &s, &err), err);
    CHECK(s == 0.25);

    /* abandonment after a timeout */
    CHECK_OK(gr_technique_register(&slow_class, &err), err);
    gr_scene *scene = calloc(1, sizeof *scene);
    CHECK(scene != NULL);
    CHECK_OK(gr_scene_load_string("{\"name\": \"t\", \"camera\": {\"width\": 4, \"height\": 3}}", "t", NULL, 0, scene, &err), err);
    gr_image *img = gr_image_create(4, 3, 3, NULL);
    gr_technique *t = NULL;
    CHECK_OK(gr_technique_create(&slow_class, NULL, NULL, &t, &err), err);
    slow_settings ok = {1.0, 0}, late = {1.0, 1};
    CHECK_OK(gr_technique_render(t, scene, &ok, img, NULL, &err), err);
    CHECK(renders == 1 && img->pixels[0] == 1.0f);
    CHECK(gr_technique_render(t, scene, &late, img, NULL, &err) == GR_E_TIMEOUT);
    CHECK(renders == 2);
    CHECK(gr_technique_render(t, scene, &ok, img, NULL, &err) == GR_E_TIMEOUT);
    CHECK_MSG(renders == 2, "an abandoned instance was rendered again");
    CHECK(strstr(err.msg, "unit_slow: abandoned after a render over the time limit") != NULL);
    gr_technique_destroy(t);
    CHECK_MSG(destroyed == 0, "an abandoned instance's state was destroyed");
    /* a fresh instance renders again */
    CHECK_OK(gr_technique_create(&slow_class, NULL, NULL, &t, &err), err);
    CHECK_OK(gr_technique_render(t, scene, &ok, img, NULL, &err), err);
    gr_technique_destroy(t);
    CHECK(destroyed == 1);
    gr_image_destroy(img);
    free(scene);
    CHECK_DONE();
}
