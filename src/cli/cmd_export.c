/* godrays export: the scene for other engines (docs/engines.md): glTF 2.0 (--gltf), the
 * shader constants as JSON (--constants) or GLSL (--glsl). */
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "export/constants.h"
#include "export/gltf.h"
#include "scene/scene.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays export SCENE.json [--gltf OUT.gltf|OUT.glb] [--constants OUT.json] [--glsl OUT.glsl]\n"
            "                      [--frames A:B:S] [--grid N] [--half-size M] [--time T] [--set K=V]... [--size WxH]\n"
            "\n"
            "Writes the scene for the engine you build in (docs/engines.md), at least one of:\n"
            "  --gltf OUT        glTF 2.0: .gltf (+ OUT.bin beside it) or .glb. The displaced water surface at\n"
            "                    the scene's time (mesh with normals), the camera, the sun as a\n"
            "                    KHR_lights_punctual directional light, occluders and seabed as meshes; wave\n"
            "                    constants, medium, g, ior, sun diameter, units and axes under scenes[0].extras\n"
            "  --constants OUT   the per-frame values of seed 000's shader as JSON (packed waves, P, S, refracted\n"
            "                    sun, GL view/projection matrices, medium)\n"
            "  --glsl OUT        the same as GLSL constants to paste into a shader\n"
            "options:\n"
            "  --frames A:B:S    with --gltf: the water at times A, A+S, ... <= B (s) as morph targets of the\n"
            "                    water mesh and a STEP animation of their weights (at most %d frames)\n"
            "  --grid N          water mesh cells per side (default 512)\n"
            "  --half-size M     half side of the square water patch in m (default 32), centred on the\n"
            "                    point P of seed eq. 5.5.5 (above the eye along the refracted sun)\n"
            "  --time T          water time in s (same as --set water.time_s=T)\n"
            "  --set PATH=VALUE  override a scene value (as in godrays validate)\n"
            "  --preset FILE     apply a preset's settings as overrides (docs/tuning.md \"Presets\")\n"
            "  --size WxH        frame size (camera.width, camera.height)\n"
            "  -h, --help        this help\n"
            "\n"
            "Exit codes: 0 ok; 2 bad usage, bad scene or an output that cannot be written; 1 run-time failure.\n",
            GR_GLTF_MAX_FRAMES);
}

static int parse_long(const char *s, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end) return -1;
    *out = v;
    return 0;
}

static int export_with(gr_args *args)
{
    const char *cmd = "export";
    const char *gltf = NULL, *constants = NULL, *glsl = NULL, *frames = NULL;
    gr_gltf_options go = {0};
    int rc = 0;
    for (; args->i < args->argc; args->i++) {
        const char *a = args->argv[args->i], *val = NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "--set")) {
            if ((rc = gr_args_take_set(args)) != 0) return rc;
        } else if (!strcmp(a, "--size")) {
            if ((rc = gr_args_take_size(args)) != 0) return rc;
        } else if (!strcmp(a, "--preset")) {
            if ((rc = gr_args_take_preset(args)) != 0) return rc;
        } else if (!strcmp(a, "--time")) {
            if ((rc = gr_args_take_setting(args, "water.time_s")) != 0) return rc;
        } else if (!strcmp(a, "--gltf") || !strcmp(a, "--constants") || !strcmp(a, "--glsl") ||
                   !strcmp(a, "--frames") || !strcmp(a, "--grid") || !strcmp(a, "--half-size")) {
            if ((rc = gr_args_value(args, &val)) != 0) return rc;
            if (!strcmp(a, "--gltf")) {
                if (!gr_gltf_kind(val))
                    return gr_cli_usage_error(cmd, "--gltf %s: unknown extension, expected .gltf or .glb", val);
                gltf = val;
            } else if (!strcmp(a, "--constants")) {
                constants = val;
            } else if (!strcmp(a, "--glsl")) {
                glsl = val;
            } else if (!strcmp(a, "--frames")) {
                gr_error e;
                if (gr_gltf_parse_frames(val, "--frames", &go, &e) != GR_OK) return gr_cli_usage_error(cmd, "%s", e.msg);
                frames = val;
            } else if (!strcmp(a, "--grid")) {
                long n;
                if (parse_long(val, &n) || n < 1 || n > 4096)
                    return gr_cli_usage_error(cmd, "--grid %s: expected an integer in [1, 4096]", val);
                go.grid_cells = (int)n;
            } else {
                char *end = NULL;
                errno = 0;
                double m = strtod(val, &end);
                if (errno || end == val || *end || !(m > 0.0 && m <= 1e5))
                    return gr_cli_usage_error(cmd, "--half-size %s: expected metres in (0, 1e5]", val);
                go.half_size_m = m;
            }
        } else {
            if ((rc = gr_args_take_scene(args)) != 0) return rc;
        }
    }
    if ((rc = gr_args_need_scene(args)) != 0) return rc;
    if (!gltf && !constants && !glsl) return gr_cli_usage_error(cmd, "nothing to export: give --gltf, --constants or --glsl");
    if (frames && !gltf) return gr_cli_usage_error(cmd, "--frames %s: only with --gltf", frames);
    /* every output checked before any work (none may be an input or another output); a
     * .gltf also writes its .bin */
    if (gltf && (rc = gr_args_check_output_file(args, "--gltf", gltf)) != 0) return rc;
    char bin[4096], bin_role[4200];
    if (gltf && gr_gltf_bin_path(gltf, bin, sizeof bin)) { /* the buffer beside it is an output too */
        snprintf(bin_role, sizeof bin_role, "--gltf %s's buffer", gltf);
        if ((rc = gr_args_note_output(args, bin_role, bin)) != 0) return rc;
    }
    if (constants && (rc = gr_args_check_output_file(args, "--constants", constants)) != 0) return rc;
    if (glsl && (rc = gr_args_check_output_file(args, "--glsl", glsl)) != 0) return rc;

    gr_scene *scene = NULL;
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc; /* the built-ins, then --preset */
    if ((rc = gr_args_load_scene(args, &scene)) != 0) return rc;
    gr_error err = {GR_OK, ""};
    gr_shader_constants *c = NULL;
    if (constants || glsl) {
        c = malloc(sizeof *c);
        if (!c) gr_fail(&err, GR_E_NOMEM, "out of memory");
        else if (gr_constants_compute(scene, c, &err) == GR_OK && constants)
            gr_constants_write_json(scene, c, constants, &err);
        if (err.status == GR_OK && glsl) gr_constants_write_glsl(scene, c, glsl, &err);
    }
    if (err.status == GR_OK && gltf) gr_gltf_write(scene, &go, gltf, &err);
    free(c);
    free(scene);
    if (err.status != GR_OK) return gr_cli_report(cmd, &err);
    return 0;
}

int cmd_export(int argc, char **argv) { return gr_args_main("export", argc, argv, export_with); }
