/* Scene loader: defaults of "{}", derived fields against hand-computed values, the camera
 * frame, deep-water dispersion, the under-the-surface check against a closed-form crest
 * height, gr_scene_refresh, and I/O errors. Round trip and hashing: test_scene_roundtrip.c;
 * overrides: test_scene_overrides.c. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/shafts.h"
#include "scene/scene.h"

/* The scene's shafts section, writable. */
#define SHAFTS(s) ((gr_shafts_settings *)gr_technique_scene_settings_rw(&gr_shafts_class, (s)))

static const double PI = 3.14159265358979323846;

static gr_scene *load(const char *json)
{
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err = {GR_OK, ""};
    gr_status st = gr_scene_load_string(json, "test", NULL, 0, s, &err);
    CHECK_OK(st, err);
    return s;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void test_defaults(void)
{
    gr_scene *s = load("{}");
    CHECK(!strcmp(s->name, "default"));
    CHECK(s->water.n_waves == 0);
    CHECK(s->water.rest_height_m == 0.0 && s->water.time_s == 0.0);
    CHECK(s->sun.elevation_deg == 60.0 && s->sun.azimuth_deg == 0.0);
    CHECK(s->sun.irradiance[0] == 1.0 && s->sun.irradiance[1] == 1.0 && s->sun.irradiance[2] == 1.0);
    CHECK(s->sun.angular_diameter_deg == 0.53);
    CHECK(s->medium.g == 0.9 && s->medium.ior == 1.333);
    CHECK(s->medium.preset[0] == '\0');
    CHECK(s->camera.position_m[0] == 0.0 && s->camera.position_m[1] == -8.0 && s->camera.position_m[2] == 0.0);
    CHECK(!s->camera.has_look_at);
    CHECK(s->camera.yaw_deg == 0.0 && s->camera.pitch_deg == 45.0 && s->camera.fov_deg == 60.0);
    CHECK(s->camera.width == 640 && s->camera.height == 360);
    CHECK(s->n_occluders == 0 && !s->has_seabed);
    /* renderer defaults: the quality ones are tuned by the renderers (test_params checks the
     * tables, test_scene_doc checks the documented rows); these are fixed by the format */
    CHECK(s->reference.seed == 1ull);
    CHECK(s->reference.threads == 0 && s->reference.target_error == 0.0);
    CHECK(s->reference.transmittance_cutoff == 1e-4);
    CHECK(SHAFTS(s)->caps == 1 && SHAFTS(s)->target_format == GR_TARGET_RGBA8);
    /* FROM_SCENE defaults resolved to the medium */
    for (int k = 0; k < 3; k++) {
        CHECK(SHAFTS(s)->extinction[k] == s->medium.absorption[k] + s->medium.scattering[k]);
        CHECK(s->medium.extinction[k] == s->medium.absorption[k] + s->medium.scattering[k]);
    }
    CHECK(SHAFTS(s)->g == 0.5); /* the seed's g (issue 12), not derived from the medium */
    CHECK(strlen(s->hash) == 16);
    CHECK(s->source_path[0] == '\0');
    free(s);
}

static void test_sun(void)
{
    /* elevation 30, azimuth 90: toward the sun = (cos 30, sin 30, 0) = (sqrt(3)/2, 1/2, 0) */
    gr_scene *s = load("{\"sun\": {\"elevation_deg\": 30, \"azimuth_deg\": 90}}");
    CHECK_NEAR(s->sun.to_sun[0], sqrt(3.0) / 2.0, 1e-15);
    CHECK_NEAR(s->sun.to_sun[1], 0.5, 1e-15);
    CHECK_NEAR(s->sun.to_sun[2], 0.0, 1e-15);
    for (int k = 0; k < 3; k++) CHECK(s->sun.dir[k] == -s->sun.to_sun[k]);
    free(s);
    /* elevation 60, azimuth 0: (0, sqrt(3)/2, 1/2); azimuth 180 flips z */
    s = load("{\"sun\": {\"elevation_deg\": 60, \"azimuth_deg\": 180}}");
    CHECK_NEAR(s->sun.to_sun[0], 0.0, 1e-15);
    CHECK_NEAR(s->sun.to_sun[1], sqrt(3.0) / 2.0, 1e-15);
    CHECK_NEAR(s->sun.to_sun[2], -0.5, 1e-15);
    CHECK(s->sun.dir[1] < 0.0); /* light travels downward */
    free(s);
    s = load("{\"sun\": {\"elevation_deg\": 90, \"azimuth_deg\": 37}}");
    CHECK_NEAR(s->sun.dir[1], -1.0, 1e-15);
    free(s);
}

static void check_frame(const gr_camera *c, const char *what)
{
    CHECK_MSG(fabs(dot3(c->forward, c->forward) - 1.0) < 1e-12, "%s: |forward| != 1", what);
    CHECK_MSG(fabs(dot3(c->right, c->right) - 1.0) < 1e-12, "%s: |right| != 1", what);
    CHECK_MSG(fabs(dot3(c->up, c->up) - 1.0) < 1e-12, "%s: |up| != 1", what);
    CHECK_MSG(fabs(dot3(c->forward, c->right)) < 1e-12, "%s: forward.right", what);
    CHECK_MSG(fabs(dot3(c->forward, c->up)) < 1e-12, "%s: forward.up", what);
    CHECK_MSG(fabs(dot3(c->right, c->up)) < 1e-12, "%s: right.up", what);
    CHECK_MSG(fabs(c->right[1]) < 1e-15, "%s: right not horizontal", what);
    CHECK_MSG(c->up[1] >= -1e-15, "%s: up points down", what);
    /* right-handed: right x up = -forward */
    double x[3] = {c->right[1] * c->up[2] - c->right[2] * c->up[1], c->right[2] * c->up[0] - c->right[0] * c->up[2],
                   c->right[0] * c->up[1] - c->right[1] * c->up[0]};
    for (int k = 0; k < 3; k++) CHECK_MSG(fabs(x[k] + c->forward[k]) < 1e-12, "%s: right x up != -forward", what);
}

static void test_camera(void)
{
    /* yaw 90, pitch 0: forward +x; right = cross(+x, +y) = +z */
    gr_scene *s = load("{\"camera\": {\"yaw_deg\": 90, \"pitch_deg\": 0}}");
    CHECK_NEAR(s->camera.forward[0], 1.0, 1e-15);
    CHECK_NEAR(s->camera.forward[1], 0.0, 1e-15);
    CHECK_NEAR(s->camera.forward[2], 0.0, 1e-15);
    CHECK_NEAR(s->camera.right[2], 1.0, 1e-15);
    CHECK_NEAR(s->camera.up[1], 1.0, 1e-15);
    check_frame(&s->camera, "yaw 90");
    /* look_at derived as position + forward */
    CHECK_NEAR(s->camera.look_at_m[0], 1.0, 1e-15);
    CHECK_NEAR(s->camera.look_at_m[1], -8.0, 1e-15);
    free(s);

    /* yaw 0, pitch 45: forward (0, 1, 1)/sqrt 2; right = cross(f, y) normalized = (-1, 0, 0) */
    s = load("{}");
    CHECK_NEAR(s->camera.forward[1], sqrt(0.5), 1e-15);
    CHECK_NEAR(s->camera.forward[2], sqrt(0.5), 1e-15);
    CHECK_NEAR(s->camera.right[0], -1.0, 1e-15);
    check_frame(&s->camera, "default");
    free(s);

    /* a sweep of yaw/pitch including straight up and down */
    const double pitches[] = {-90, -60, -1e-9, 0, 30, 89.999, 90};
    const double yaws[] = {-400, -90, 0, 17, 180, 359};
    char json[256], what[64];
    for (size_t i = 0; i < sizeof pitches / sizeof *pitches; i++)
        for (size_t j = 0; j < sizeof yaws / sizeof *yaws; j++) {
            snprintf(json, sizeof json, "{\"camera\": {\"yaw_deg\": %.17g, \"pitch_deg\": %.17g}}", yaws[j], pitches[i]);
            snprintf(what, sizeof what, "yaw %g pitch %g", yaws[j], pitches[i]);
            s = load(json);
            check_frame(&s->camera, what);
            CHECK_NEAR(s->camera.forward[1], sin(pitches[i] * PI / 180.0), 1e-15);
            /* the right vector is continuous through the zenith: (-cos yaw, 0, sin yaw) */
            CHECK_NEAR(s->camera.right[0], -cos(yaws[j] * PI / 180.0), 1e-9);
            CHECK_NEAR(s->camera.right[2], sin(yaws[j] * PI / 180.0), 1e-9);
            free(s);
        }

    /* look_at: forward = normalize(look_at - position); yaw/pitch derived */
    s = load("{\"camera\": {\"position_m\": [1, -10, 2], \"look_at_m\": [4, -6, 2]}}");
    CHECK(s->camera.has_look_at);
    CHECK_NEAR(s->camera.forward[0], 0.6, 1e-15);
    CHECK_NEAR(s->camera.forward[1], 0.8, 1e-15);
    CHECK_NEAR(s->camera.forward[2], 0.0, 1e-15);
    CHECK_NEAR(s->camera.yaw_deg, 90.0, 1e-12);
    CHECK_NEAR(s->camera.pitch_deg, atan2(0.8, 0.6) * 180.0 / PI, 1e-12);
    check_frame(&s->camera, "look_at");
    free(s);
    s = load("{\"camera\": {\"position_m\": [0, -5, 0], \"look_at_m\": [0, -1, 0]}}");
    check_frame(&s->camera, "look_at straight up");
    CHECK_NEAR(s->camera.forward[1], 1.0, 1e-15);
    free(s);
}

static void test_waves(void)
{
    gr_scene *s = load("{\"water\": {\"waves\": [{\"wavelength_m\": 8, \"direction_deg\": 90},"
                       " {\"wavelength_m\": 2, \"amplitude_m\": 0.05, \"angular_frequency_rad_s\": 1.25}]}}");
    CHECK(s->water.n_waves == 2);
    const gr_wave *w = &s->water.waves[0];
    CHECK(w->amplitude_m == 0.1 && w->phase_rad == 0.0); /* per-wave defaults */
    CHECK_NEAR(w->k, 2.0 * PI / 8.0, 1e-15);
    /* deep-water dispersion w^2 = g k with g = 9.81 m/s^2: w = sqrt(9.81 * pi / 4) */
    CHECK_NEAR(w->omega_rad_s, sqrt(9.81 * PI / 4.0), 1e-15);
    CHECK_NEAR(w->dir[0], 1.0, 1e-15);
    CHECK_NEAR(w->dir[1], 0.0, 1e-15);
    CHECK(s->water.waves[1].omega_rad_s == 1.25); /* given: kept */
    free(s);
}

static void test_under_surface(void)
{
    /* One wave, phase 0 at the origin: the crest there is at rest + a = 0.3 (eq. 5.5.7 with
     * sin 0 = 0, cos 0 = 1). A camera at y = 0.29 is under that crest although above rest
     * height; at y = 0.31 it is above the water. Half a wavelength away (trough, -0.3) a
     * camera at y = -0.29 is above the water although below rest height. */
    char json[256];
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err;
    const double cases[4][3] = {{0.29, 0.0, GR_OK}, {0.31, 0.0, GR_E_INPUT}, {-0.29, 5.0, GR_E_INPUT},
                                {-0.31, 5.0, GR_OK}};
    for (int i = 0; i < 4; i++) {
        snprintf(json, sizeof json,
                 "{\"water\": {\"waves\": [{\"amplitude_m\": 0.3, \"wavelength_m\": 10}]},"
                 " \"camera\": {\"position_m\": [0, %.17g, %.17g]}}", cases[i][0], cases[i][1]);
        gr_status st = gr_scene_load_string(json, "t", NULL, 0, s, &err);
        CHECK_MSG(st == (gr_status)cases[i][2], "camera y %g z %g: status %d", cases[i][0], cases[i][1], (int)st);
        if (st != GR_OK)
            CHECK(strstr(err.msg, "t: camera.position_m: camera is not under water") != NULL);
    }
    /* flat water: compared with the rest height */
    CHECK(gr_scene_load_string("{\"water\": {\"rest_height_m\": 2}, \"camera\": {\"position_m\": [0, 1.999, 0]}}",
                               "t", NULL, 0, s, &err) == GR_OK);
    CHECK(gr_scene_load_string("{\"water\": {\"rest_height_m\": 2}, \"camera\": {\"position_m\": [0, 2, 0]}}",
                               "t", NULL, 0, s, &err) == GR_E_INPUT);
    free(s);
}

static void test_medium(void)
{
    gr_scene *s = load("{\"medium\": {\"preset\": \"pure_seawater\"}}");
    /* Pope & Fry 1997 absorption and Morel 1974 scattering at 650/550/450 nm, g = 0 */
    CHECK(s->medium.absorption[0] == 0.340 && s->medium.absorption[1] == 0.0565 && s->medium.absorption[2] == 0.00922);
    CHECK(s->medium.scattering[0] == 0.0009 && s->medium.scattering[1] == 0.0019 && s->medium.scattering[2] == 0.0045);
    CHECK(s->medium.g == 0.0 && SHAFTS(s)->g == 0.5);
    CHECK(!strcmp(s->medium.preset, "pure_seawater"));
    free(s);
    /* explicit keys override the preset per key */
    s = load("{\"medium\": {\"preset\": \"pure_seawater\", \"scattering_per_m\": 0.05, \"g\": 0.8}}");
    CHECK(s->medium.absorption[1] == 0.0565);
    CHECK(s->medium.scattering[0] == 0.05 && s->medium.scattering[2] == 0.05);
    CHECK(s->medium.g == 0.8);
    CHECK_NEAR(s->medium.extinction[1], 0.0565 + 0.05, 1e-17);
    free(s);
    /* explicit shafts values win over FROM_SCENE */
    s = load("{\"shafts\": {\"extinction\": [0.1, 0.2, 0.3], \"g\": 0.5}}");
    CHECK(SHAFTS(s)->extinction[0] == 0.1 && SHAFTS(s)->extinction[2] == 0.3 && SHAFTS(s)->g == 0.5);
    free(s);
}

static void test_refresh(void)
{
    gr_scene *s = load("{}");
    gr_error err;
    char old_hash[17];
    memcpy(old_hash, s->hash, sizeof old_hash);
    s->sun.elevation_deg = 30.0;
    s->sun.azimuth_deg = 90.0;
    CHECK(gr_scene_refresh(s, &err) == GR_OK);
    CHECK_NEAR(s->sun.to_sun[0], sqrt(3.0) / 2.0, 1e-15);
    CHECK(strcmp(s->hash, old_hash) != 0);
    /* NaN asks for re-derivation from the medium */
    s->medium.scattering[0] = 0.5;
    SHAFTS(s)->extinction[0] = NAN;
    CHECK(gr_scene_refresh(s, &err) == GR_OK);
    CHECK(SHAFTS(s)->extinction[0] == s->medium.absorption[0] + 0.5);
    /* refresh re-validates */
    s->camera.fov_deg = 200.0;
    CHECK(gr_scene_refresh(s, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "camera.fov_deg: must be in (0, 180), got 200") != NULL);
    s->camera.fov_deg = 60.0;
    s->camera.position_m[1] = 1.0;
    CHECK(gr_scene_refresh(s, &err) == GR_E_INPUT);
    s->camera.position_m[1] = -8.0;
    SHAFTS(s)->K = -1.0;
    CHECK(gr_scene_refresh(s, &err) == GR_E_INPUT);
    CHECK(strstr(err.msg, "shafts.K:") != NULL);
    CHECK(gr_scene_refresh(NULL, &err) != GR_OK);
    free(s);
}

static void test_io_errors(void)
{
    gr_scene *s = calloc(1, sizeof *s);
    gr_error err;
    const char *missing = "/nonexistent-dir/no-scene.json";
    CHECK(gr_scene_load_file(missing, NULL, 0, s, &err) == GR_E_IO);
    CHECK(strstr(err.msg, missing) != NULL);
    CHECK(strstr(err.msg, strerror(ENOENT)) != NULL);
    CHECK(strchr(err.msg, '\n') == NULL);
    /* a directory is not a readable scene */
    CHECK(gr_scene_load_file("/", NULL, 0, s, &err) != GR_OK);
    /* malformed JSON names line and column */
    CHECK(gr_scene_load_string("{\n  \"name\": \"x\",\n  oops\n}", "f.json", NULL, 0, s, &err) == GR_E_INPUT);
    CHECK_MSG(strstr(err.msg, "f.json:3:") != NULL && strstr(err.msg, "malformed JSON") != NULL, "%s", err.msg);
    CHECK(gr_scene_load_string(NULL, "x", NULL, 0, s, &err) != GR_OK);
    /* the source path is recorded on success */
    const char *src = getenv("GODRAYS_SOURCE_DIR");
    if (src) {
        char path[1024];
        snprintf(path, sizeof path, "%s/data/scenes/default.json", src);
        CHECK(gr_scene_load_file(path, NULL, 0, s, &err) == GR_OK);
        CHECK(!strcmp(s->source_path, path));
        CHECK(!strcmp(s->name, "default"));
    }
    free(s);
}

int main(void)
{
    gr_technique_count(); /* the built-in techniques' sections ("shafts") before any scene */
    test_defaults();
    test_sun();
    test_camera();
    test_waves();
    test_under_surface();
    test_medium();
    test_refresh();
    test_io_errors();
    CHECK_DONE();
}
