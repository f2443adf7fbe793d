/* realtime/technique: the registry, scene integration and instances, with a CPU-only test
 * class ("unit_flat": a uniform image of value level x gain, no GL) whose output is known in
 * closed form:
 *  - registration: the built-ins come first; bad names, duplicates, a table whose section is
 *    not the name, settings over the size limit and reserved names are refused;
 *  - the scene loader knows the new section only once it is registered: defaults, values from
 *    the file, --set NAME.KEY overrides, range errors naming "NAME.KEY", unknown keys, the
 *    normalized print and its round trip, scene-derived defaults (scene_source) resolved;
 *  - lists (--techniques), KEY=VALUE text, stats helpers (median, GPU sum);
 *  - an instance renders the closed form, measures its wall time when the class does not, and
 *    refuses a non-finite image and out-of-range settings. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/technique.h"
#include "scene/scene.h"

typedef struct flat_settings {
    double level;      /* output value before the gain */
    double gain[3];    /* RGB factor */
    double g;          /* default from medium.g */
    int poison;        /* 1: write a NaN (the harness must refuse it) */
} flat_settings;

#define FS(f) offsetof(flat_settings, f)
static const gr_param flat_params[] = {
    {.name = "level", .type = GR_PT_DOUBLE, .offset = FS(level), .min = 0, .max = 10, .def = 0.5, .unit = "",
     .doc = "output value", .tune_lo = 0.1, .tune_hi = 2},
    {.name = "gain", .type = GR_PT_RGB, .offset = FS(gain), .min = 0, .max = 100, .def = 1, .unit = "",
     .doc = "RGB factor"},
    {.name = "g", .type = GR_PT_DOUBLE, .offset = FS(g), .min = -1, .max = 1,
     .flags = GR_PF_MIN_EXCL | GR_PF_MAX_EXCL | GR_PF_FROM_SCENE, .def = NAN, .unit = "",
     .scene_source = "medium.g", .doc = "from the medium"},
    {.name = "poison", .type = GR_PT_BOOL, .offset = FS(poison), .min = 0, .max = 1, .def = 0, .unit = "",
     .doc = "write a NaN"},
};
static const gr_param_table flat_table = {"unit_flat", flat_params, sizeof flat_params / sizeof flat_params[0]};

static int created, destroyed;

static gr_status flat_check(const gr_technique_class *cls, const void *settings, gr_error *err)
{
    const flat_settings *s = settings;
    if (s->level == 3.0) return gr_fail(err, GR_E_INPUT, "unit_flat.level: 3 is not allowed (test)");
    return GR_OK;
}

static gr_status flat_create(const gr_technique_class *cls, gr_gl *gl, const gr_technique_options *opts,
                             void **state, gr_error *err)
{
    created++;
    *state = &created;
    return GR_OK;
}

static void flat_destroy(void *state)
{
    if (state) destroyed++;
}

static gr_status flat_render(void *state, const gr_scene *scene, const void *settings, gr_image *out,
                             gr_technique_stats *stats, gr_error *err)
{
    const flat_settings *s = settings;
    for (int y = 0; y < out->height; y++)
        for (int x = 0; x < out->width; x++)
            for (int c = 0; c < 3; c++) gr_image_pixel(out, x, y)[c] = (float)(s->level * s->gain[c]);
    if (s->poison) gr_image_pixel(out, 1, 2)[1] = NAN;
    stats->n_passes = 2;
    snprintf(stats->pass_names[0], sizeof stats->pass_names[0], "a");
    snprintf(stats->pass_names[1], sizeof stats->pass_names[1], "b");
    stats->gpu_ns[0] = 1000000;
    stats->gpu_ns[1] = -1; /* untimed pass */
    return GR_OK;
}

static const gr_technique_class flat_class = {
    .name = "unit_flat",
    .description = "uniform test image",
    .params = &flat_table,
    .settings_size = sizeof(flat_settings),
    .origin = "test",
    .gain_key = "gain",
    .check = flat_check,
    .create = flat_create,
    .destroy = flat_destroy,
    .render = flat_render,
};

static gr_technique_class bad_class(const char *name, const gr_param_table *t, size_t size)
{
    gr_technique_class c = flat_class;
    c.name = name;
    c.params = t;
    c.settings_size = size;
    return c;
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    /* the built-ins are registered on first use, before anything else */
    const int n0 = gr_technique_count();
    CHECK(n0 >= 1);
    for (int i = 0; i < n0; i++) {
        const gr_technique_class *c = gr_technique_at(i);
        CHECK(c && gr_technique_find(c->name) == c && gr_technique_index(c) == i);
        CHECK(c->params && !strcmp(c->params->section, c->name));
        CHECK(gr_sections_find(c->name) >= 0);
    }
    CHECK(gr_technique_at(n0) == NULL && gr_technique_find("unit_flat") == NULL);

    /* a scene loaded now does not know the section */
    gr_scene *s = calloc(1, sizeof *s);
    CHECK(gr_scene_load_string("{\"unit_flat\": {\"level\": 2}}", "t.json", NULL, 0, s, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "unit_flat") && strstr(err.msg, "--technique-dir"), "%s", err.msg);

    /* bad classes */
    gr_technique_class b = bad_class("Bad", &flat_table, sizeof(flat_settings));
    CHECK(gr_technique_register(&b, &err) == GR_E_INPUT && strstr(err.msg, "[a-z]"));
    b = bad_class("a_name_that_is_far_too_long_for_it", &flat_table, sizeof(flat_settings));
    CHECK(gr_technique_register(&b, &err) == GR_E_INPUT);
    b = bad_class("other", &flat_table, sizeof(flat_settings)); /* table section differs */
    CHECK(gr_technique_register(&b, &err) == GR_E_INPUT && strstr(err.msg, "section"));
    b = bad_class("unit_flat", &flat_table, GR_TECH_SETTINGS_MAX + 8);
    CHECK(gr_technique_register(&b, &err) == GR_E_INPUT && strstr(err.msg, "bytes"));
    static const gr_param_table camera_table = {"camera", flat_params, 1};
    b = bad_class("camera", &camera_table, sizeof(flat_settings)); /* a key of the format itself */
    CHECK(gr_technique_register(&b, &err) == GR_E_INPUT);
    b = *gr_technique_at(0); /* a duplicate of a built-in */
    CHECK(gr_technique_register(&b, &err) == GR_E_INPUT && strstr(err.msg, "already"));
    CHECK(gr_technique_count() == n0);

    CHECK_OK(gr_technique_register(&flat_class, &err), err);
    CHECK(gr_technique_count() == n0 + 1 && gr_technique_find("unit_flat") == &flat_class);
    CHECK(gr_technique_register(&flat_class, &err) == GR_E_INPUT);

    /* the scene loader now parses, validates, overrides and prints the section */
    const char *json = "{\"medium\": {\"g\": 0.7}, \"camera\": {\"width\": 8, \"height\": 6}, "
                       "\"unit_flat\": {\"level\": 2, \"gain\": [1, 2, 3]}}";
    CHECK_OK(gr_scene_load_string(json, "t.json", NULL, 0, s, &err), err);
    const flat_settings *fs = gr_technique_scene_settings(&flat_class, s);
    CHECK(fs && fs->level == 2 && fs->gain[0] == 1 && fs->gain[2] == 3 && fs->poison == 0);
    CHECK(fs->g == 0.7); /* scene_source medium.g, resolved by the loader */
    const char *ov[2] = {"unit_flat.level=0.25", "unit_flat.gain=4"};
    CHECK_OK(gr_scene_load_string(json, "t.json", ov, 2, s, &err), err);
    fs = gr_technique_scene_settings(&flat_class, s);
    CHECK(fs->level == 0.25 && fs->gain[0] == 4 && fs->gain[1] == 4 && fs->gain[2] == 4);
    const char *bad1 = "unit_flat.level=11";
    CHECK(gr_scene_load_string(json, "t.json", &bad1, 1, s, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "--set unit_flat.level=11") && strstr(err.msg, "unit_flat.level"), "%s", err.msg);
    CHECK(gr_scene_load_string("{\"unit_flat\": {\"levl\": 1}}", "t.json", NULL, 0, s, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "unit_flat.levl") && strstr(err.msg, "level"), "%s", err.msg);
    /* the normalized print holds the section and reads back the same */
    CHECK_OK(gr_scene_load_string(json, "t.json", ov, 2, s, &err), err);
    char *text = gr_scene_to_json(s);
    CHECK(text && strstr(text, "\"unit_flat\": {"));
    gr_scene *s2 = calloc(1, sizeof *s2);
    CHECK_OK(gr_scene_load_string(text, "printed", NULL, 0, s2, &err), err);
    CHECK(!strcmp(s->hash, s2->hash));
    CHECK(!memcmp(gr_technique_scene_settings(&flat_class, s2), fs, sizeof *fs));
    free(text);
    /* a NaN scene-derived setting is taken from the scene again by refresh and by resolve */
    flat_settings *rw = gr_technique_scene_settings_rw(&flat_class, s);
    rw->g = NAN;
    flat_settings res;
    gr_technique_resolve(&flat_class, s, rw, &res);
    CHECK(res.g == 0.7 && res.level == 0.25);
    CHECK_OK(gr_scene_refresh(s, &err), err);
    CHECK(rw->g == 0.7);

    /* lists */
    const gr_technique_class *list[GR_TECH_MAX];
    int n = 0;
    CHECK_OK(gr_technique_parse_list("--techniques", NULL, list, GR_TECH_MAX, &n, &err), err);
    int n_default = 0; /* the default set leaves out by-name-only and unavailable techniques (eevee) */
    for (int i = 0; i < n0; i++) {
        const gr_technique_class *c = gr_technique_at(i);
        if (!c->by_name_only && gr_technique_available(c, NULL, 0)) n_default++;
    }
    CHECK(n == n_default + 1 && list[n_default] == &flat_class);
    CHECK_OK(gr_technique_parse_list("--techniques", "unit_flat", list, GR_TECH_MAX, &n, &err), err);
    CHECK(n == 1 && list[0] == &flat_class);
    CHECK(gr_technique_parse_list("--techniques", "unit_flat,nope", list, GR_TECH_MAX, &n, &err) == GR_E_USAGE);
    CHECK_MSG(strstr(err.msg, "--techniques unit_flat,nope") && strstr(err.msg, "'nope'") &&
                  strstr(err.msg, "unit_flat"), "%s", err.msg);
    CHECK(gr_technique_parse_list("--techniques", "unit_flat,unit_flat", list, GR_TECH_MAX, &n, &err) == GR_E_USAGE);
    CHECK(gr_technique_parse_list("--techniques", "unit_flat,", list, GR_TECH_MAX, &n, &err) == GR_E_USAGE);

    /* KEY=VALUE text (pareto ladders) */
    flat_settings t = *fs;
    CHECK_OK(gr_technique_apply_text(&flat_class, &t, "level=1.5,poison=true,gain=2", &err), err);
    CHECK(t.level == 1.5 && t.poison == 1 && t.gain[1] == 2);
    CHECK(gr_technique_apply_text(&flat_class, &t, "level=x", &err) == GR_E_INPUT);
    CHECK(gr_technique_apply_text(&flat_class, &t, "nope=1", &err) == GR_E_INPUT && strstr(err.msg, "unit_flat.nope"));
    CHECK(gr_technique_apply_text(&flat_class, &t, "level=20", &err) == GR_E_INPUT);

    /* an instance (no GL needed by this class) */
    gr_technique *inst = NULL;
    CHECK_OK(gr_technique_create(&flat_class, NULL, NULL, &inst, &err), err);
    CHECK(created == 1 && gr_technique_class_of(inst) == &flat_class);
    gr_image *img = gr_image_create(8, 6, 3, NULL);
    gr_technique_stats st;
    CHECK_OK(gr_technique_render(inst, s, NULL, img, &st, &err), err); /* the scene's own settings */
    CHECK(img->pixels[0] == 1.0f && img->pixels[5 * 3 + 2] == 1.0f); /* 0.25 x 4 */
    CHECK(st.n_passes == 2 && st.wall_ms >= 0 && st.fragments == -1);
    CHECK_NEAR(gr_technique_stats_gpu_ms(&st), 1.0, 0.0); /* the untimed pass is skipped */
    flat_settings mine = *fs;
    mine.level = 0.5;
    mine.gain[1] = 3;
    mine.g = NAN; /* unresolved: resolved from the scene before the class sees it */
    CHECK_OK(gr_technique_render(inst, s, &mine, img, NULL, &err), err);
    CHECK(img->pixels[1] == 1.5f);
    mine.level = 3.0; /* the class's own check */
    CHECK(gr_technique_render(inst, s, &mine, img, NULL, &err) == GR_E_INPUT && strstr(err.msg, "unit_flat.level"));
    mine.level = -1; /* the table's range */
    CHECK(gr_technique_render(inst, s, &mine, img, NULL, &err) == GR_E_INPUT && strstr(err.msg, "unit_flat.level"));
    mine.level = 1;
    mine.poison = 1; /* the harness refuses a non-finite image, naming the pixel */
    CHECK(gr_technique_render(inst, s, &mine, img, NULL, &err) == GR_E_RUNTIME);
    CHECK_MSG(strstr(err.msg, "unit_flat") && strstr(err.msg, "(1, 2)"), "%s", err.msg);
    gr_image *small = gr_image_create(4, 6, 3, NULL);
    CHECK(gr_technique_render(inst, s, NULL, small, NULL, &err) != GR_OK);
    gr_image_destroy(small);
    /* metadata: the generic keys */
    gr_metadata meta;
    gr_meta_init(&meta);
    CHECK_OK(gr_technique_metadata(inst, s, NULL, &st, &meta, &err), err);
    const gr_meta_item *it = gr_meta_get(&meta, "godrays:technique");
    CHECK(it && it->type == GR_META_STRING && !strcmp(it->str, "unit_flat"));
    it = gr_meta_get(&meta, "godrays:unit_flat.level");
    CHECK(it && it->num == 0.25);
    it = gr_meta_get(&meta, "godrays:unit_flat.gain");
    CHECK(it && it->type == GR_META_STRING && !strcmp(it->str, "4 4 4"));
    it = gr_meta_get(&meta, "godrays:gpu_ns.a");
    CHECK(it && it->num == 1000000);
    it = gr_meta_get(&meta, "godrays:gpu_ms");
    CHECK(it && it->num == 1.0);
    gr_meta_free(&meta);
    /* no read_target: a clear error */
    gr_image *target = NULL;
    CHECK(gr_technique_read_target(inst, &target, &err) == GR_E_USAGE && target == NULL);
    gr_technique_destroy(inst);
    gr_technique_destroy(NULL);
    CHECK(destroyed == 1);

    /* median of stats: per figure */
    gr_technique_stats all[3];
    for (int i = 0; i < 3; i++) {
        gr_technique_stats_clear(&all[i]);
        all[i].n_passes = 1;
        all[i].gpu_ns[0] = (long long[]){30, 10, 20}[i];
        all[i].wall_ms = (double[]){1.0, 3.0, 2.0}[i];
    }
    gr_technique_stats med;
    gr_technique_stats_median(all, 3, &med);
    CHECK(med.gpu_ns[0] == 20 && med.wall_ms == 2.0);
    gr_technique_stats_clear(&med);
    CHECK(med.n_passes == 0 && gr_technique_stats_gpu_ms(&med) == -1.0);

    gr_image_destroy(img);
    free(s);
    free(s2);
    CHECK_DONE();
}
