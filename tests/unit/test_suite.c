/* src/suite: a suite file's cases load with their overrides in the documented order (the
 * suite's size, the case's "set", its structured objects, the caller's), relative scene paths
 * resolve against the suite's folder, and every malformed suite is refused with ONE line that
 * names the suite file and the JSON path (docs/scene-format.md "Suites"). The expected values
 * are the literals written into the suite files here, not the loader's earlier output. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check.h"
#include "suite/suite.h"

static char g_dir[1024];

static const char *write_file(const char *name, const char *text)
{
    static char path[2048];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    fputs(text, f);
    fclose(f);
    return path;
}

/* A scene beside the suites, referred to by a relative path. */
static const char *scene_json =
    "{\"version\": 1, \"name\": \"tiny\",\n"
    " \"water\": {\"rest_height_m\": 0, \"time_s\": 0,\n"
    "   \"waves\": [{\"amplitude_m\": 0.1, \"wavelength_m\": 8, \"direction_deg\": 20, \"phase_rad\": 0}]},\n"
    " \"sun\": {\"elevation_deg\": 60, \"azimuth_deg\": 30},\n"
    " \"medium\": {\"preset\": \"pure_seawater\"},\n"
    " \"camera\": {\"position_m\": [0, -8, 0], \"yaw_deg\": 30, \"pitch_deg\": 60, \"fov_deg\": 60,\n"
    "   \"width\": 64, \"height\": 36}}\n";

static gr_status load(const char *name, const char *text, gr_suite **s, gr_error *err)
{
    return gr_suite_load(write_file(name, text), s, err);
}

/* The suite's cases as written. */
static void check_valid(void)
{
    const char *text =
        "{\"version\": 1, \"name\": \"mini\", \"description\": \"two views\", \"size\": \"48x27\",\n"
        " \"cases\": [\n"
        "  {\"name\": \"up\", \"split\": \"train\", \"scene\": \"sub/tiny.json\"},\n"
        "  {\"name\": \"flat-view\", \"split\": \"test\", \"scene\": \"sub/tiny.json\",\n"
        "   \"set\": [\"camera.fov_deg=45\", \"sun.elevation_deg=20\"],\n"
        "   \"camera\": {\"pitch_deg\": 0, \"position_m\": [1, -3, 2]}, \"water\": {\"time_s\": 1.5},\n"
        "   \"sun\": {\"azimuth_deg\": 100}},\n"
        "  {\"name\": \"late\", \"split\": \"train\", \"scene\": \"sub/tiny.json\", \"description\": \"d\",\n"
        "   \"set\": [\"sun.elevation_deg=20\"], \"sun\": {\"elevation_deg\": 35}}]}\n";
    gr_suite *s = NULL;
    gr_error err = {GR_OK, ""};
    gr_status st = load("ok.json", text, &s, &err);
    CHECK_OK(st, err);
    if (st != GR_OK) return;
    CHECK(!strcmp(s->name, "mini"));
    CHECK(!strcmp(s->description, "two views"));
    CHECK(s->width == 48 && s->height == 27);
    CHECK(s->n_cases == 3);
    CHECK(gr_suite_count(s, GR_SPLIT_TRAIN) == 2 && gr_suite_count(s, GR_SPLIT_TEST) == 1);
    CHECK(gr_suite_find(s, "flat-view") == 1 && gr_suite_find(s, "late") == 2 && gr_suite_find(s, "nope") == -1);
    CHECK(!strcmp(gr_split_name(s->cases[1].split), "test"));
    char want[2100];
    snprintf(want, sizeof want, "%s/sub/tiny.json", g_dir);
    CHECK_MSG(!strcmp(s->cases[0].scene_path, want), "%s", s->cases[0].scene_path);
    const gr_scene *a = &s->cases[0].scene, *b = &s->cases[1].scene, *c = &s->cases[2].scene;
    CHECK(a->camera.width == 48 && a->camera.height == 27); /* the suite's size */
    CHECK_NEAR(a->camera.pitch_deg, 60, 0);                 /* the scene's own */
    CHECK_NEAR(b->camera.pitch_deg, 0, 0);
    CHECK_NEAR(b->camera.fov_deg, 45, 0);
    CHECK_NEAR(b->camera.position_m[0], 1, 0);
    CHECK_NEAR(b->camera.position_m[1], -3, 0);
    CHECK_NEAR(b->water.time_s, 1.5, 0);
    CHECK_NEAR(b->sun.elevation_deg, 20, 0);
    CHECK_NEAR(b->sun.azimuth_deg, 100, 0);
    CHECK_NEAR(c->sun.elevation_deg, 35, 0); /* the structured object after the "set" list */
    CHECK(strcmp(a->hash, b->hash) != 0);
    gr_suite_destroy(s);

    /* the caller's overrides come last: --size beats the suite's size */
    const char *extra[] = {"camera.width=32", "camera.height=18", "camera.fov_deg=50"};
    st = gr_suite_load_with(write_file("ok.json", text), extra, 3, &s, &err);
    CHECK_OK(st, err);
    if (st != GR_OK) return;
    for (int i = 0; i < s->n_cases; i++) {
        CHECK(s->cases[i].scene.camera.width == 32 && s->cases[i].scene.camera.height == 18);
        CHECK_NEAR(s->cases[i].scene.camera.fov_deg, 50, 0);
    }
    gr_suite_destroy(s);
    /* a bad caller override keeps its --set wording */
    const char *bad[] = {"camera.fov_deg=500"};
    st = gr_suite_load_with(write_file("ok.json", text), bad, 1, &s, &err);
    CHECK(st == GR_E_INPUT && s == NULL);
    CHECK_MSG(strstr(err.msg, "ok.json: cases[0] (up): --set camera.fov_deg=500") != NULL, "%s", err.msg);
}

typedef struct bad_case {
    const char *what, *text;
    const char *expect; /* in the one-line message, after "DIR/bad.json: " */
} bad_case;

#define CASE_UP "{\"name\": \"up\", \"split\": \"train\", \"scene\": \"sub/tiny.json\"}"
#define CASE_T "{\"name\": \"t\", \"split\": \"test\", \"scene\": \"sub/tiny.json\"}"

static void check_bad(void)
{
    static const bad_case bad[] = {
        {"unknown top-level key", "{\"name\": \"x\", \"casez\": [], \"cases\": [" CASE_UP "," CASE_T "]}",
         "casez: unknown key"},
        {"unknown case key", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"t\", \"split\": \"test\", "
         "\"scene\": \"sub/tiny.json\", \"cam\": {}}]}", "cases[1].cam: unknown key"},
        {"missing scene file", "{\"name\": \"x\", \"cases\": [{\"name\": \"up\", \"split\": \"train\", "
         "\"scene\": \"nowhere.json\"}," CASE_T "]}", "cases[0].scene: "},
        {"scene key missing", "{\"name\": \"x\", \"cases\": [{\"name\": \"up\", \"split\": \"train\"}," CASE_T "]}",
         "cases[0].scene: missing"},
        {"duplicate names", "{\"name\": \"x\", \"cases\": [" CASE_UP "," CASE_T ", {\"name\": \"up\", "
         "\"split\": \"test\", \"scene\": \"sub/tiny.json\"}]}", "cases[2].name: 'up' is also the name of cases[0]"},
        {"no test case", "{\"name\": \"x\", \"cases\": [" CASE_UP "]}", "cases: no test case"},
        {"no train case", "{\"name\": \"x\", \"cases\": [" CASE_T "]}", "cases: no train case"},
        {"bad split", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"t\", \"split\": \"val\", "
         "\"scene\": \"sub/tiny.json\"}]}", "cases[1].split: must be \"train\" or \"test\""},
        {"bad structured override", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"t\", \"split\": \"test\", "
         "\"scene\": \"sub/tiny.json\", \"camera\": {\"pitch_deg\": \"up\"}}]}", "cases[1].camera.pitch_deg: "},
        {"override out of range", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"t\", \"split\": \"test\", "
         "\"scene\": \"sub/tiny.json\", \"set\": [\"camera.fov_deg=45\", \"sun.elevation_deg=120\"]}]}",
         "cases[1].set[1]: "},
        {"override not key=value", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"t\", \"split\": \"test\", "
         "\"scene\": \"sub/tiny.json\", \"set\": [\"camera.fov_deg\"]}]}", "cases[1].set[0]: must be a string"},
        {"unknown scene key in an override", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"t\", "
         "\"split\": \"test\", \"scene\": \"sub/tiny.json\", \"sun\": {\"elevation\": 10}}]}", "cases[1].sun.elevation: "},
        {"bad case name", "{\"name\": \"x\", \"cases\": [" CASE_UP ", {\"name\": \"T 1\", \"split\": \"test\", "
         "\"scene\": \"sub/tiny.json\"}]}", "cases[1].name: 'T 1': only a-z"},
        {"bad size", "{\"name\": \"x\", \"size\": \"big\", \"cases\": [" CASE_UP "," CASE_T "]}", "size: 'big'"},
        {"no name", "{\"cases\": [" CASE_UP "," CASE_T "]}", "name: missing"},
        {"cases not an array", "{\"name\": \"x\", \"cases\": {}}", "cases: must be an array"},
        {"malformed JSON", "{\"name\": \"x\", \"cases\": [", "malformed JSON"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        gr_suite *s = (gr_suite *)1;
        gr_error err = {GR_OK, ""};
        const char *path = write_file("bad.json", bad[i].text);
        gr_status st = gr_suite_load(path, &s, &err);
        CHECK_MSG(st == GR_E_INPUT, "%s: status %d (%s)", bad[i].what, (int)st, err.msg);
        CHECK_MSG(s == NULL, "%s: suite not NULL", bad[i].what);
        CHECK_MSG(!strncmp(err.msg, path, strlen(path)), "%s: message does not start with the file: %s", bad[i].what,
                  err.msg);
        CHECK_MSG(strstr(err.msg, bad[i].expect) != NULL, "%s: '%s' not in: %s", bad[i].what, bad[i].expect, err.msg);
        CHECK_MSG(strchr(err.msg, '\n') == NULL, "%s: more than one line: %s", bad[i].what, err.msg);
    }
    /* an unreadable suite is an I/O error */
    gr_suite *s = NULL;
    gr_error err;
    char path[2048];
    snprintf(path, sizeof path, "%s/missing.json", g_dir);
    CHECK(gr_suite_load(path, &s, &err) == GR_E_IO && s == NULL);
}

int main(void)
{
    const char *out = getenv("GODRAYS_TEST_OUT");
    snprintf(g_dir, sizeof g_dir, "%s/suite_unit", out ? out : "/tmp");
    mkdir(g_dir, 0777);
    char sub[1100];
    snprintf(sub, sizeof sub, "%s/sub", g_dir);
    mkdir(sub, 0777);
    write_file("sub/tiny.json", scene_json);
    check_valid();
    check_bad();
    gr_suite_destroy(NULL);
    CHECK(gr_suite_count(NULL, GR_SPLIT_TEST) == 0);
    CHECK_DONE();
}
