/* godrays validate [--set K=V]... SCENE: load and check a scene, print it normalized. */
#include "cli/cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "realtime/technique.h"
#include "scene/scene.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays validate [--set json.path=value]... [--technique-dir DIR]... SCENE.json\n"
            "\n"
            "Loads SCENE.json (scene format v1, docs/scene-format.md), applies the overrides,\n"
            "checks every value and prints the normalized scene (all defaults filled in) to stdout.\n"
            "\n"
            "options:\n"
            "  --set PATH=VALUE  override one value before validation; VALUE is JSON (a number,\n"
            "                    array, true/false, \"string\") or a bare word taken as a string.\n"
            "                    Examples: --set camera.fov_deg=50  --set sun.irradiance=[1,0.9,0.8]\n"
            "                    --set water.waves[0].amplitude_m=0.2  --set TECHNIQUE.KEY=V\n"
            "  --technique-dir DIR  add the user technique in DIR first (its section is then known)\n"
            "  -h, --help        this help\n"
            "\n"
            "Exit codes: 0 valid; 2 bad usage or invalid scene; 1 file cannot be read.\n");
}

int cmd_validate(int argc, char **argv)
{
    const char *cmd = "validate";
    const char **sets = NULL;
    int n_sets = 0;
    const char *scene = NULL;
    int only_args = 0;
    if (argc > 1) {
        sets = malloc(sizeof *sets * (size_t)argc);
        if (!sets) {
            gr_error e;
            gr_fail(&e, GR_E_NOMEM, "out of memory");
            return gr_cli_report(cmd, &e);
        }
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!only_args && (!strcmp(a, "-h") || !strcmp(a, "--help"))) {
            usage(stdout);
            free(sets);
            return 0;
        }
        if (!only_args && !strcmp(a, "--")) {
            only_args = 1;
        } else if (!only_args && !strcmp(a, "--set")) {
            if (i + 1 >= argc) {
                free(sets);
                return gr_cli_usage_error(cmd, "--set needs a value json.path=value");
            }
            sets[n_sets++] = argv[++i];
        } else if (!only_args && !strncmp(a, "--set=", 6)) {
            sets[n_sets++] = a + 6;
        } else if (!only_args && !strcmp(a, "--technique-dir")) {
            /* a user technique's section is known once its folder is loaded: before the scene */
            gr_error e = {GR_OK, ""};
            if (i + 1 >= argc || !argv[i + 1][0]) {
                free(sets);
                return gr_cli_usage_error(cmd, "--technique-dir needs a folder");
            }
            if (gr_technique_add_dir(argv[++i], &e) != GR_OK) {
                free(sets);
                return gr_cli_report(cmd, &e);
            }
        } else if (!only_args && a[0] == '-' && a[1] != '\0') {
            free(sets);
            return gr_cli_usage_error(cmd, "unknown option '%s'", a);
        } else if (scene) {
            free(sets);
            return gr_cli_usage_error(cmd, "more than one scene given ('%s' and '%s')", scene, a);
        } else {
            scene = a;
        }
    }
    if (!scene) {
        free(sets);
        return gr_cli_usage_error(cmd, "no scene file given");
    }
    gr_scene *s = malloc(sizeof *s);
    gr_error err = {GR_OK, ""};
    if (!s) {
        free(sets);
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        return gr_cli_report(cmd, &err);
    }
    gr_status st = gr_scene_load_file(scene, (const char *const *)sets, n_sets, s, &err);
    free(sets);
    if (st != GR_OK) {
        free(s);
        return gr_cli_report(cmd, &err);
    }
    char *json = gr_scene_to_json(s);
    free(s);
    if (!json) {
        gr_fail(&err, GR_E_NOMEM, "out of memory printing the scene");
        return gr_cli_report(cmd, &err);
    }
    int rc = fputs(json, stdout) < 0 || fflush(stdout) != 0;
    free(json);
    if (rc) {
        gr_fail(&err, GR_E_IO, "cannot write to stdout");
        return gr_cli_report(cmd, &err);
    }
    return 0;
}
