/* Parameter specs of sweep and tune (src/tune/paramspec.h): good specs give the documented
 * grid (endpoints exact, even spacing), RGB settings act as scales on the scene's value (the
 * oracle is the medium's sigma_a + sigma_s computed here by hand), and every bad spec is a
 * usage error (exit 2) whose one-line message names the flag. */
#include <string.h>

#include "check.h"
#include "realtime/shafts.h"
#include "scene/scene.h"
#include "tune/paramspec.h"

static void bad_sweep(const char *spec, const char *must_contain)
{
    gr_tune_param tp;
    gr_error err = {GR_OK, ""};
    gr_status st = gr_tune_param_parse_sweep("--param", spec, &tp, &err);
    CHECK_MSG(st == GR_E_USAGE, "%s: status %d", spec, (int)st);
    CHECK_MSG(strstr(err.msg, "--param") != NULL, "%s: message lacks the flag: %s", spec, err.msg);
    CHECK_MSG(strstr(err.msg, must_contain) != NULL, "%s: message lacks '%s': %s", spec, must_contain, err.msg);
    CHECK_MSG(strchr(err.msg, '\n') == NULL, "%s: message is not one line", spec);
}

static void bad_list(const char *spec, const char *must_contain)
{
    gr_tune_param tp[GR_TUNE_MAX_PARAMS];
    int n = 0;
    gr_error err = {GR_OK, ""};
    gr_status st = gr_tune_param_parse_list("--params", spec, tp, GR_TUNE_MAX_PARAMS, &n, &err);
    CHECK_MSG(st == GR_E_USAGE, "%s: status %d", spec, (int)st);
    CHECK_MSG(strstr(err.msg, "--params") != NULL && strstr(err.msg, must_contain) != NULL, "%s: %s", spec, err.msg);
}

int main(void)
{
    gr_technique_count(); /* the built-in techniques' sections ("shafts") before any scene */
    gr_error err;
    gr_tune_param tp;

    /* a good spec: 16 values from 0.4 to 1.2 inclusive, step 0.8 / 15 */
    CHECK_OK(gr_tune_param_parse_sweep("--param", "shafts.K=0.4:1.2:16", &tp, &err), err);
    CHECK(tp.kind == GR_TK_SCALAR && tp.count == 16 && !strcmp(tp.key, "shafts.K"));
    CHECK(gr_tune_param_value(&tp, 0) == 0.4);
    CHECK(gr_tune_param_value(&tp, 15) == 1.2);
    CHECK_NEAR(gr_tune_param_value(&tp, 5), 0.4 + 5 * 0.8 / 15, 1e-15);
    /* integers: N = 5..11 in 4 values -> 5, 7, 9, 11 */
    CHECK_OK(gr_tune_param_parse_sweep("--param", "shafts.N=5:11:4", &tp, &err), err);
    CHECK(tp.kind == GR_TK_INT && gr_tune_param_value(&tp, 1) == 7 && gr_tune_param_value(&tp, 3) == 11);

    /* RGB scale: extinction x 0.5 on a scene with sigma_a = (0.3, 0.06, 0.03), sigma_s = 0.03 */
    gr_scene *s = malloc(sizeof *s);
    CHECK(s != NULL);
    const char *json = "{\"name\": \"t\", \"sun\": {\"elevation_deg\": 60}, \"medium\": {\"absorption_per_m\": "
                       "[0.3, 0.06, 0.03], \"scattering_per_m\": 0.03, \"g\": 0.8}, \"camera\": {\"position_m\": "
                       "[0, -8, 0], \"yaw_deg\": 0, \"pitch_deg\": 30, \"fov_deg\": 60, \"width\": 16, \"height\": 9}}";
    CHECK_OK(gr_scene_load_string(json, "t", NULL, 0, s, &err), err);
    gr_shafts_settings base = *gr_shafts_scene_settings(s), out;
    for (int c = 0; c < 3; c++) base.extinction[c] = s->medium.extinction[c]; /* resolved */
    base.g = s->medium.g;
    CHECK_OK(gr_tune_param_parse_sweep("--param", "shafts.extinction=0.25:2:8", &tp, &err), err);
    CHECK(tp.kind == GR_TK_RGB_SCALE);
    out = base;
    CHECK_OK(gr_tune_param_apply(&tp, &base, 0.5, &out, &err), err);
    const double sig_t[3] = {0.3 + 0.03, 0.06 + 0.03, 0.03 + 0.03};
    for (int c = 0; c < 3; c++) CHECK_NEAR(out.extinction[c], 0.5 * sig_t[c], 1e-15);
    CHECK_NEAR(gr_tune_param_current(&tp, &base, &out), 0.5, 1e-15);
    CHECK_NEAR(gr_tune_param_current(&tp, &base, &base), 1.0, 0.0);
    /* a scalar applies as is, and out-of-range values are refused by the descriptor table */
    CHECK_OK(gr_tune_param_lookup("--params", "shafts.K", &tp, &err), err);
    out = base;
    CHECK_OK(gr_tune_param_apply(&tp, &base, 0.7, &out, &err), err);
    CHECK(out.K == 0.7);
    CHECK(gr_tune_param_apply(&tp, &base, -1.0, &out, &err) == GR_E_INPUT && strstr(err.msg, "shafts.K"));
    free(s);

    /* bad sweep specs: unknown key, other section, empty range, counts, non-numeric, types */
    bad_sweep("shafts.nope=0:1:4", "unknown shafts setting");
    bad_sweep("medium.g=0:1:4", "unknown parameter");
    bad_sweep("shafts.K", "expected TECHNIQUE.KEY=LO:HI:COUNT");
    bad_sweep("shafts.K=0.4:1.2", "expected TECHNIQUE.KEY=LO:HI:COUNT");
    bad_sweep("shafts.K=1.2:0.4:16", "empty range");
    bad_sweep("shafts.K=0.5:0.5:16", "empty range");
    bad_sweep("shafts.K=0.4:1.2:0", "COUNT must be in");
    bad_sweep("shafts.K=0.4:1.2:1", "COUNT must be in");
    bad_sweep("shafts.K=0.4:1.2:2.5", "COUNT must be an integer");
    bad_sweep("shafts.K=a:1.2:16", "finite numbers");
    bad_sweep("shafts.K=0.4:nan:16", "finite numbers");
    bad_sweep("shafts.K=-1:1:4", "shafts.K");
    bad_sweep("shafts.target_format=0:1:2", "not a numeric setting");
    bad_sweep("shafts.caps=0:1:2", "not a numeric setting");
    bad_sweep("shafts.N=2.5:8:3", "integer");
    bad_sweep("shafts.N=2:4:5", "only 3 integers");
    bad_sweep("shafts.extinction=-1:2:4", "scale");

    /* tune lists and bounds */
    gr_tune_param list[GR_TUNE_MAX_PARAMS];
    int n = 0;
    CHECK_OK(gr_tune_param_parse_list("--params", "shafts.extinction,shafts.K", list, GR_TUNE_MAX_PARAMS, &n, &err),
             err);
    CHECK(n == 2 && list[0].lo == 0.1 && list[0].hi == 4.0 && list[1].lo == 0.2 && list[1].hi == 2.0);
    CHECK_OK(gr_tune_param_parse_bounds("--bounds", "shafts.K=0.5:1.5", list, n, &err), err);
    CHECK(list[1].lo == 0.5 && list[1].hi == 1.5);
    CHECK(gr_tune_param_parse_bounds("--bounds", "shafts.K=1.5:0.5", list, n, &err) == GR_E_USAGE &&
          strstr(err.msg, "--bounds") && strstr(err.msg, "empty range"));
    CHECK(gr_tune_param_parse_bounds("--bounds", "shafts.g=0:0.5", list, n, &err) == GR_E_USAGE &&
          strstr(err.msg, "not among"));
    bad_list("", "empty");
    bad_list("shafts.K,,shafts.g", "empty parameter name");
    bad_list("shafts.K,shafts.K", "twice");
    bad_list("shafts.N", "integer setting");
    bad_list("shafts.K,shafts.bogus", "unknown shafts setting");
    bad_list("shafts.target_format", "not a numeric setting");
    CHECK_DONE();
}
