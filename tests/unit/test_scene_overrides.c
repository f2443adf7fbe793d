/* "json.path=value" overrides: value types, array indices, created paths, validation of
 * overridden values, and errors that name the override rather than the file. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "realtime/shafts.h"
#include "scene/scene.h"

/* The scene's shafts section, writable. */
#define SHAFTS(s) ((gr_shafts_settings *)gr_technique_scene_settings_rw(&gr_shafts_class, (s)))

static gr_scene *scene;
static gr_error err;

static gr_status with(const char *json, const char *o1, const char *o2)
{
    const char *ov[2] = {o1, o2};
    int n = o2 ? 2 : o1 ? 1 : 0;
    memset(&err, 0, sizeof err);
    return gr_scene_load_string(json, "scene.json", ov, n, scene, &err);
}

#define EXPECT_ERR(st, text) do { gr_status st_ = (st); \
    CHECK_MSG(st_ == GR_E_INPUT, "status %d, message: %s", (int)st_, err.msg); \
    CHECK_MSG(strstr(err.msg, (text)) != NULL, "message '%s' lacks '%s'", err.msg, (text)); \
    CHECK_MSG(strchr(err.msg, '\n') == NULL, "multi-line message: %s", err.msg); } while (0)

static const char *waves2 =
    "{\"water\": {\"waves\": [{\"amplitude_m\": 0.1, \"wavelength_m\": 8}, {\"amplitude_m\": 0.2, \"wavelength_m\": 20}]}}";

static void test_values(void)
{
    CHECK_OK(with("{}", "camera.fov_deg=45", NULL), err);
    CHECK(scene->camera.fov_deg == 45.0);
    CHECK_OK(with("{}", "sun.irradiance=[1,2,3]", "shafts.caps=false"), err);
    CHECK(scene->sun.irradiance[0] == 1.0 && scene->sun.irradiance[2] == 3.0);
    CHECK(SHAFTS(scene)->caps == 0);
    CHECK_OK(with("{}", "sun.irradiance=2.5", NULL), err);
    CHECK(scene->sun.irradiance[1] == 2.5);
    /* a bare word is a string; quoted JSON strings work too */
    CHECK_OK(with("{}", "name=hello world", "shafts.target_format=rgba16f"), err);
    CHECK(!strcmp(scene->name, "hello world"));
    CHECK(SHAFTS(scene)->target_format == GR_TARGET_RGBA16F);
    CHECK_OK(with("{}", "name=\"42\"", NULL), err);
    CHECK(!strcmp(scene->name, "42"));
    /* a value containing '=' keeps it (split at the first '=') */
    CHECK_OK(with("{}", "name=a=b", NULL), err);
    CHECK(!strcmp(scene->name, "a=b"));
    /* whole objects, null */
    CHECK_OK(with("{\"seabed\": {\"depth_m\": 30}}", "seabed=null", NULL), err);
    CHECK(!scene->has_seabed);
    CHECK_OK(with("{}", "medium={\"preset\": \"pure_seawater\"}", NULL), err);
    CHECK(scene->medium.g == 0.0);
    /* the last override of a key wins */
    CHECK_OK(with("{}", "camera.fov_deg=45", "camera.fov_deg=50"), err);
    CHECK(scene->camera.fov_deg == 50.0);
    /* an override can repair a file */
    CHECK_OK(with("{\"camera\": {\"fov_deg\": 190}}", "camera.fov_deg=70", NULL), err);
    CHECK(scene->camera.fov_deg == 70.0);
}

static void test_paths(void)
{
    /* array index into an existing element */
    CHECK_OK(with(waves2, "water.waves[1].amplitude_m=0.05", NULL), err);
    CHECK(scene->water.n_waves == 2);
    CHECK(scene->water.waves[1].amplitude_m == 0.05 && scene->water.waves[0].amplitude_m == 0.1);
    CHECK(scene->water.waves[1].wavelength_m == 20.0);
    /* index == length appends; missing intermediate objects and arrays are created */
    CHECK_OK(with(waves2, "water.waves[2].wavelength_m=4", NULL), err);
    CHECK(scene->water.n_waves == 3 && scene->water.waves[2].wavelength_m == 4.0);
    CHECK(scene->water.waves[2].amplitude_m == 0.1); /* the element got its defaults */
    CHECK_OK(with("{}", "water.waves[0].amplitude_m=0.02", NULL), err);
    CHECK(scene->water.n_waves == 1 && scene->water.waves[0].amplitude_m == 0.02);
    CHECK_OK(with("{}", "seabed.depth_m=30", NULL), err);
    CHECK(scene->has_seabed && scene->seabed_depth_m == 30.0);
    /* whole-array element replacement and an element of an RGB array */
    CHECK_OK(with("{}", "sun.irradiance=[1,1,1]", "sun.irradiance[1]=0.5"), err);
    CHECK(scene->sun.irradiance[1] == 0.5 && scene->sun.irradiance[0] == 1.0);
    CHECK_OK(with("{}", "occluders[0]={\"type\": \"sphere\", \"center_m\": [0, -4, 3]}", NULL), err);
    CHECK(scene->n_occluders == 1 && scene->occluders[0].type == GR_OCC_SPHERE);
}

static void test_errors(void)
{
    /* the override's own text leads the message, then the path and reason */
    EXPECT_ERR(with("{}", "shafts.Kx=1", NULL), "--set shafts.Kx=1: shafts.Kx: unknown key");
    EXPECT_ERR(with("{}", "camera.fov_deg=190", NULL), "--set camera.fov_deg=190: camera.fov_deg: must be in (0, 180), got 190");
    EXPECT_ERR(with("{}", "camera.fov_deg=wide", NULL), "--set camera.fov_deg=wide: camera.fov_deg: must be a number");
    EXPECT_ERR(with(waves2, "water.waves[1].amplitude_m=-1", NULL), "--set water.waves[1].amplitude_m=-1: water.waves[1].amplitude_m");
    EXPECT_ERR(with(waves2, "water.waves[5].amplitude_m=0.1", NULL), "--set water.waves[5].amplitude_m=0.1: water.waves[5]: index out of range");
    EXPECT_ERR(with("{\"camera\": {\"fov_deg\": 60}}", "camera.fov_deg.x=1", NULL), "camera.fov_deg: not an object");
    EXPECT_ERR(with("{\"camera\": {}}", "camera[0]=1", NULL), "camera: not an array");
    EXPECT_ERR(with("{}", "camera.fov_deg", NULL), "--set camera.fov_deg: expected json.path=value");
    EXPECT_ERR(with("{}", "=1", NULL), "expected json.path=value");
    EXPECT_ERR(with("{}", "a..b=1", NULL), "--set a..b=1: bad path");
    EXPECT_ERR(with("{}", "a[x]=1", NULL), "bad path");
    EXPECT_ERR(with("{}", "sun.irradiance=[1,2", NULL), "--set sun.irradiance=[1,2: value is not valid JSON");
    /* a cross-field error caused by an override whose path differs from the failing one */
    EXPECT_ERR(with("{}", "camera.fov_deg=50", "water.rest_height_m=-10"),
               "--set water.rest_height_m=-10: camera.position_m: camera is not under water");
    EXPECT_ERR(with(waves2, "water.waves[1].amplitude_m=3", NULL), "--set water.waves[1].amplitude_m=3: water.waves: steepness");
    /* a bad file with an unrelated override is still the file's fault */
    EXPECT_ERR(with("{\"camera\": {\"fov_deg\": 190}}", "medium.g=0.5", NULL), "scene.json: camera.fov_deg: must be in (0, 180)");
    /* malformed JSON is reported before overrides */
    EXPECT_ERR(with("{\"camera\": }", "medium.g=0.5", NULL), "scene.json:1:");
}

int main(void)
{
    gr_technique_count(); /* the built-in techniques' sections ("shafts") before any scene */
    scene = calloc(1, sizeof *scene);
    test_values();
    test_paths();
    test_errors();
    free(scene);
    CHECK_DONE();
}
