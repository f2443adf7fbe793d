/* What makes `pareto --suite --tune` affordable (docs/tuning.md "Continuation along the
 * ladder", "Warm timing"), checked without GL:
 *  - capped warm timing (realtime/timing.h): a CPU-only class ("unit_clock") reports the wall
 *    time its setting asks for; after the warm-up, timed renders stop once they took the cap
 *    together (at least one), all of them without a cap, and the count and median are those
 *    of the renders made (counted by the class itself);
 *  - the continuation's order: the anchor (the middle), the points above it upwards, then the
 *    points below it downwards, each after the neighbour it starts from;
 *  - its starts: the anchor's and the neighbour's tuned values, an untuned point left out, one
 *    point given twice taken once. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/timing.h"
#include "scene/scene.h"
#include "tune/suitetune.h"

typedef struct clock_settings {
    double ms;
} clock_settings;

static const gr_param clock_params[] = {
    {.name = "ms", .type = GR_PT_DOUBLE, .offset = offsetof(clock_settings, ms), .min = 0, .max = 1e6, .def = 1,
     .unit = "ms", .doc = "the wall time the render reports"},
};
static const gr_param_table clock_table = {"unit_clock", clock_params, 1};
static int renders;

static gr_status clock_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts, void **state,
                              gr_error *err)
{
    *state = &renders;
    return GR_OK;
}

static void clock_destroy(void *state) {}

static gr_status clock_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                              gr_technique_stats *stats, gr_error *err)
{
    renders++;
    for (size_t i = 0; i < (size_t)out->width * (size_t)out->height * (size_t)out->nchannels; i++) out->pixels[i] = 0.5f;
    stats->wall_ms = ((const clock_settings *)settings)->ms; /* the harness keeps a class's own figure */
    return GR_OK;
}

static const gr_technique_class clock_class = {
    .name = "unit_clock", .description = "CPU test class", .params = &clock_table,
    .settings_size = sizeof(clock_settings), .origin = "test", .create = clock_create,
    .destroy = clock_destroy, .render = clock_render,
};

/* Timed renders of ms each, up to n after one warm-up, capped at cap_s: the count timed. */
static int timed(gr_technique *t, const gr_scene *scene, gr_image *img, double ms, int n, double cap_s, int *made,
                 int warmup)
{
    gr_error err = {GR_OK, ""};
    gr_timing res;
    clock_settings s = {ms};
    renders = 0;
    CHECK_OK(gr_timing_measure_capped(t, scene, &s, img, 1, n, cap_s, &res, &err), err);
    *made = renders;
    CHECK(res.warmup == warmup);
    CHECK_MSG(res.wall_ms == ms && res.cost_ms == ms, "median %g ms of renders of %g ms", res.wall_ms, ms);
    return res.n;
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    CHECK_OK(gr_technique_register(&clock_class, &err), err);
    gr_scene *scene = calloc(1, sizeof *scene);
    CHECK(scene != NULL);
    CHECK_OK(gr_scene_load_string("{\"name\": \"t\", \"camera\": {\"width\": 4, \"height\": 3}}", "t", NULL, 0, scene, &err), err);
    gr_image *img = gr_image_create(4, 3, 3, NULL);
    gr_technique *t = NULL;
    CHECK_OK(gr_technique_create(&clock_class, NULL, NULL, &t, &err), err);
    int made = 0;
    /* 2 s cap: 10 ms renders all 5; 800 ms ones stop after the third (2.4 s >= 2 s); a 3 s
     * render is timed once; a 10 s one (5 caps) is its warm-up alone, timed as it is; without a
     * cap every render is */
    CHECK(timed(t, scene, img, 10, 5, 2.0, &made, 1) == 5 && made == 6);
    CHECK(timed(t, scene, img, 800, 5, 2.0, &made, 1) == 3 && made == 4);
    CHECK(timed(t, scene, img, 3000, 5, 2.0, &made, 1) == 1 && made == 2);
    CHECK(timed(t, scene, img, 9999, 5, 2.0, &made, 1) == 1 && made == 2);
    CHECK(timed(t, scene, img, 10000, 5, 2.0, &made, 0) == 1 && made == 1);
    CHECK(timed(t, scene, img, 10000, 5, 0, &made, 1) == 5 && made == 6);
    CHECK(timed(t, scene, img, 3000, 5, 0, &made, 1) == 5 && made == 6);
    CHECK(timed(t, scene, img, 3000, 3, -1, &made, 1) == 3 && made == 4);
    gr_technique_destroy(t);
    gr_image_destroy(img);
    free(scene);

    /* the continuation's order */
    int order[8], prev[8];
    CHECK(gr_st_continuation_order(5, order, prev) == 2);
    const int o5[5] = {2, 3, 4, 1, 0}, p5[5] = {-1, 0, 1, 0, 3};
    CHECK(!memcmp(order, o5, sizeof o5) && !memcmp(prev, p5, sizeof p5));
    CHECK(gr_st_continuation_order(2, order, prev) == 1 && order[0] == 1 && order[1] == 0 && prev[0] == -1 && prev[1] == 0);
    CHECK(gr_st_continuation_order(1, order, prev) == 0 && order[0] == 0 && prev[0] == -1);
    for (int n = 1; n <= 8; n++) { /* each point once, each after the neighbour it starts from */
        gr_st_continuation_order(n, order, prev);
        int seen = 0;
        for (int k = 0; k < n; k++) {
            seen |= 1 << order[k];
            if (k > 0) CHECK(prev[k] >= 0 && prev[k] < k && abs(order[prev[k]] - order[k]) == 1);
        }
        CHECK(seen == (1 << n) - 1);
    }

    /* its starts */
    gr_st_point a, b, u;
    memset(&a, 0, sizeof a), memset(&b, 0, sizeof b), memset(&u, 0, sizeof u);
    a.tuned = b.tuned = 1;
    a.x[0] = 1, b.x[0] = 2, u.x[0] = 3;
    gr_st_options o;
    memset(&o, 0, sizeof o);
    gr_st_continue_from(&o, &a, &b);
    CHECK(o.n_from == 2 && o.from[0][0] == 2 && o.from[1][0] == 1); /* the neighbour first */
    gr_st_continue_from(&o, &a, &a);
    CHECK(o.n_from == 1 && o.from[0][0] == 1);
    gr_st_continue_from(&o, &a, &u);
    CHECK(o.n_from == 1 && o.from[0][0] == 1);
    gr_st_continue_from(&o, NULL, NULL);
    CHECK(o.n_from == 0);
    CHECK(gr_st_local_evals(2) == 44 && gr_st_local_evals(4) == 68);
    CHECK_DONE();
}
