/* Normalized JSON: load(to_json(s)) reproduces s bit for bit for every shipped scene and
 * for awkward doubles; to_json is a fixed point; the hash is FNV-1a 64 of the normalized
 * text (checked with an independent FNV implementation validated on published vectors),
 * is stable across formatting of the same scene and changes when a value changes. */
#include <dirent.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/technique.h"
#include "scene/scene.h"

/* Reference FNV-1a 64 (Fowler/Noll/Vo): basis 0xcbf29ce484222325, prime 0x100000001b3. */
static uint64_t fnv_ref(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ull;
    while (*s) {
        h ^= (uint64_t)(unsigned char)*s++;
        h *= 0x100000001b3ull;
    }
    return h;
}

/* Compares two scenes as the loader fills them (it zeroes the whole struct first). */
static int same_scene(const gr_scene *a, const gr_scene *b)
{
    return memcmp(a, b, sizeof *a) == 0;
}

static void roundtrip(const gr_scene *s, const char *what)
{
    gr_error err;
    char *j1 = gr_scene_to_json(s);
    CHECK(j1 != NULL);
    if (!j1) return;
    gr_scene *t = calloc(1, sizeof *t);
    gr_status st = gr_scene_load_string(j1, what, NULL, 0, t, &err);
    CHECK_MSG(st == GR_OK, "%s: reload failed: %s", what, err.msg);
    /* source_path is provenance, not content */
    gr_scene *u = malloc(sizeof *u);
    memcpy(u, s, sizeof *u);
    memset(u->source_path, 0, sizeof u->source_path);
    CHECK_MSG(same_scene(u, t), "%s: load(to_json(s)) differs from s", what);
    char *j2 = gr_scene_to_json(t);
    CHECK_MSG(j2 && !strcmp(j1, j2), "%s: to_json not a fixed point", what);
    CHECK_MSG(!strcmp(s->hash, t->hash), "%s: hash changed on reload", what);
    char hex[17];
    snprintf(hex, sizeof hex, "%016llx", (unsigned long long)fnv_ref(j1));
    CHECK_MSG(!strcmp(s->hash, hex), "%s: hash %s, FNV-1a of the JSON %s", what, s->hash, hex);
    free(j1);
    free(j2);
    free(t);
    free(u);
}

static void test_fnv_vectors(void)
{
    /* published FNV-1a 64 test vectors */
    CHECK(fnv_ref("") == 0xcbf29ce484222325ull);
    CHECK(fnv_ref("a") == 0xaf63dc4c8601ec8cull);
    CHECK(fnv_ref("foobar") == 0x85944171f73967e8ull);
}

static void test_shipped_scenes(void)
{
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    if (!src) src = GR_SOURCE_DIR;
    const char *dirs[] = {"data/scenes", "data/scenes/hard"};
    int n = 0;
    for (int d = 0; d < 2; d++) {
        char dir[1024];
        snprintf(dir, sizeof dir, "%s/%s", src, dirs[d]);
        DIR *dp = opendir(dir);
        CHECK_MSG(dp != NULL, "cannot open %s", dir);
        if (!dp) continue;
        struct dirent *e;
        while ((e = readdir(dp))) {
            size_t l = strlen(e->d_name);
            if (l < 6 || strcmp(e->d_name + l - 5, ".json")) continue;
            char path[2048];
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            gr_scene *s = calloc(1, sizeof *s);
            gr_error err;
            gr_status st = gr_scene_load_file(path, NULL, 0, s, &err);
            CHECK_MSG(st == GR_OK, "%s", err.msg);
            if (st == GR_OK) roundtrip(s, path);
            free(s);
            n++;
        }
        closedir(dp);
    }
    CHECK_MSG(n >= 13, "only %d shipped scenes found", n);
}

static void test_awkward_values(void)
{
    /* doubles that need 17 digits, tiny and huge magnitudes, negative zero, escapes */
    const char *json =
        "{\"name\": \"q\\\"uote\\\\ tab\\t nl\\n \\u00e9\","
        " \"water\": {\"rest_height_m\": 0.1, \"time_s\": 1e-300, \"waves\": ["
        "{\"amplitude_m\": 0.012345678901234567, \"wavelength_m\": 3.0000000000000004, \"direction_deg\": -0.0,"
        " \"phase_rad\": 6.283185307179586}]},"
        " \"sun\": {\"elevation_deg\": 89.99999999999999, \"azimuth_deg\": -1e5, \"irradiance\": [1e-9, 2, 1e9]},"
        " \"camera\": {\"position_m\": [100000.00000000001, -7.3, 1e5], \"look_at_m\": [100001, -1, 100000.5],"
        " \"width\": 1, \"height\": 16384},"
        " \"occluders\": [{\"type\": \"sphere\", \"center_m\": [0.1, -3, 0.7], \"radius_m\": 0.30000000000000004}],"
        " \"seabed\": {\"depth_m\": 12.5},"
        " \"reference\": {\"seed\": 9007199254740991, \"target_error\": 0.01},"
        " \"shafts\": {\"caps\": false, \"target_format\": \"rgba16f\", \"intensity\": [0.1, 0.2, 0.3]}}";
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err;
    gr_status st = gr_scene_load_string(json, "awkward", NULL, 0, s, &err);
    CHECK_OK(st, err);
    if (st == GR_OK) {
        CHECK(s->reference.seed == 9007199254740991ull);
        CHECK(s->camera.position_m[0] == 100000.00000000001);
        roundtrip(s, "awkward");
    }
    free(s);
}

static void test_hash(void)
{
    gr_scene *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
    gr_error err;
    /* same scene, different formatting and explicit defaults: same hash */
    CHECK(gr_scene_load_string("{}", "a", NULL, 0, a, &err) == GR_OK);
    CHECK(gr_scene_load_string("{ \"version\" : 1,\n \"camera\": {\"fov_deg\": 60.0, \"width\": 640} }", "b", NULL, 0,
                               b, &err) == GR_OK);
    CHECK(!strcmp(a->hash, b->hash));
    for (int i = 0; i < 16; i++) CHECK(strchr("0123456789abcdef", a->hash[i]) != NULL);
    /* one value changed: different hash */
    const char *ov = "camera.fov_deg=60.000000000001";
    CHECK(gr_scene_load_string("{}", "b", &ov, 1, b, &err) == GR_OK);
    CHECK(strcmp(a->hash, b->hash) != 0);
    ov = "reference.seed=2";
    CHECK(gr_scene_load_string("{}", "b", &ov, 1, b, &err) == GR_OK);
    CHECK(strcmp(a->hash, b->hash) != 0);
    /* the label / source path is not part of the hash */
    CHECK(gr_scene_load_string("{}", "another-label", NULL, 0, b, &err) == GR_OK);
    CHECK(!strcmp(a->hash, b->hash));
    free(a);
    free(b);
}

int main(void)
{
    gr_technique_count(); /* the built-in techniques' sections ("shafts") before any scene */
    test_fnv_vectors();
    test_shipped_scenes();
    test_awkward_values();
    test_hash();
    CHECK_DONE();
}
