/* godrays render TECHNIQUE SCENE: render a scene with any registered real-time technique
 * (src/realtime/technique.h) into an EXR god-ray layer (linear float, frame resolution) plus
 * a PNG preview. (main.c's aliases name a technique; nothing here does.) */
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/exr.h"
#include "image/oiio.h"
#include "realtime/technique.h"
#include "scene/scene.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays render TECHNIQUE SCENE [-o OUT.exr] [options]\n"
            "\n"
            "Renders SCENE's god-ray layer with the real-time TECHNIQUE (OpenGL through headless EGL;\n"
            "`godrays techniques` lists them and their settings) and writes it as a linear float EXR\n"
            "with timings and settings in its metadata, plus an sRGB PNG preview beside it (OUT.png).\n"
            "\n"
            "options:\n"
            "  -o, --output FILE    EXR to write (default: TECHNIQUE.exr)\n"
            "  --set KEY=VALUE      override a scene value before validation, e.g. TECHNIQUE.KEY=V,\n"
            "                       medium.g=0.9 (repeatable)\n"
            "  --size WxH           image size (same as --set camera.width=W --set camera.height=H)\n"
            "  --technique-dir DIR  add the user technique in DIR (its manifest.json; repeatable)\n"
            "  --time-limit S       give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --shader-dir DIR     GLSL files in DIR replace the technique's embedded ones of the same name\n"
            "  --time T             water time t (s) of eq. 5.5.7 (default: the scene's water.time_s)\n"
            "  --frames A:B:S       render frames A, A+S, ... up to B at time T + frame / fps; the\n"
            "                       frame number goes into the file names (OUT.0007.exr)\n"
            "  --fps F              frames per second for --frames (default 30)\n"
            "  --repeat R           render each frame R times in one context; timings printed are\n"
            "                       the median of the renders (default 1)\n"
            "  --exposure E         preview exposure (default: auto, the 99.5th percentile maps to 1)\n"
            "  --no-preview         do not write the PNG preview\n"
            "  --save-target FILE   also write the technique's intermediate render target (RGBA float\n"
            "                       EXR), for the techniques that have one\n"
            "  --gl-platform P      auto, surfaceless or device (default auto)\n"
            "  -q, --quiet          print nothing on success\n"
            "  -h, --help           this help\n"
            "\n"
            "Settings (scene section named after the technique): `godrays techniques`,\n"
            "docs/scene-format.md. Exit codes: 0 ok, 1 runtime/GL failure, 2 bad usage or input.\n");
}

static int parse_double(const char *s, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

static int parse_int(const char *s, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end) return -1;
    *out = v;
    return 0;
}

/* "out.exr" + frame 7 -> "out.0007.exr"; no extension -> "out.0007". */
static void frame_path(const char *base, long frame, char *buf, size_t n)
{
    const char *slash = strrchr(base, '/');
    const char *dot = strrchr(base, '.');
    if (dot && (!slash || dot > slash) && dot != base && (!slash || dot != slash + 1))
        snprintf(buf, n, "%.*s.%04ld%s", (int)(dot - base), base, frame, dot);
    else
        snprintf(buf, n, "%s.%04ld", base, frame);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Exposure that maps the 99.5th percentile of max(R, G, B) to 1 (1 if the image is black). */
static double auto_exposure(const gr_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    float *v = malloc(n * sizeof *v);
    if (!v) return 1.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = img->pixels + i * (size_t)img->nchannels;
        v[i] = fmaxf(p[0], fmaxf(p[1], p[2]));
    }
    qsort(v, n, sizeof *v, cmp_float);
    double q = v[(size_t)((double)(n - 1) * 0.995)];
    free(v);
    return q > 0 ? 1.0 / q : 1.0;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int render_with(gr_args *args)
{
    const char *cmd = "render";
    const char *out_path = NULL, *shader_dir = NULL, *target_path = NULL, *tech_name = NULL;

    const int argc = args->argc;
    char **argv = args->argv;
    int preview = 1, quiet = 0, have_time = 0, have_frames = 0, rc = 0;
    double time_s = 0.0, fps = 30.0, exposure = 0.0;
    long f0 = 0, f1 = 0, fstep = 1, repeat = 1;
    gr_gl_platform platform = GR_GL_AUTO;

    for (; args->i < argc; args->i++) {
        const char *a = argv[args->i], *val = NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--no-preview")) {
            preview = 0;
        } else if (!strcmp(a, "--set")) {
            if ((rc = gr_args_take_set(args)) != 0) return rc;
        } else if (!strcmp(a, "--gl-platform")) {
            if ((rc = gr_args_take_gl_platform(args, &platform)) != 0) return rc;
        } else if (!strcmp(a, "--size")) {
            if ((rc = gr_args_take_size(args)) != 0) return rc;
        } else if (!strcmp(a, "--technique-dir")) {
            if ((rc = gr_args_take_technique_dir(args)) != 0) return rc;
        } else if (!strcmp(a, "--time-limit")) {
            if ((rc = gr_args_take_time_limit(args)) != 0) return rc;
        } else if (a[0] == '-' && a[1] != '\0') {
            /* every other option takes a value */
            if ((rc = gr_args_value(args, &val)) != 0) return rc;
            if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
                out_path = val;
            } else if (!strcmp(a, "--save-target")) {
                target_path = val;
            } else if (!strcmp(a, "--shader-dir")) {
                shader_dir = val;
            } else if (!strcmp(a, "--time")) {
                if (parse_double(val, &time_s)) return gr_cli_usage_error(cmd, "--time %s: not a number", val);
                have_time = 1;
            } else if (!strcmp(a, "--fps")) {
                if (parse_double(val, &fps) || !(fps > 0))
                    return gr_cli_usage_error(cmd, "--fps %s: expected a number > 0", val);
            } else if (!strcmp(a, "--exposure")) {
                if (parse_double(val, &exposure) || !(exposure > 0))
                    return gr_cli_usage_error(cmd, "--exposure %s: expected a number > 0", val);
            } else if (!strcmp(a, "--repeat")) {
                if (parse_int(val, &repeat) || repeat < 1 || repeat > 100000)
                    return gr_cli_usage_error(cmd, "--repeat %s: expected an integer in [1, 100000]", val);
            } else if (!strcmp(a, "--frames")) {
                char extra;
                if (sscanf(val, "%ld:%ld:%ld%c", &f0, &f1, &fstep, &extra) != 3 || fstep < 1 || f1 < f0 || f0 < 0)
                    return gr_cli_usage_error(cmd, "--frames %s: expected START:END:STEP with 0 <= START <= END, STEP >= 1", val);
                if ((f1 - f0) / fstep >= 100000) return gr_cli_usage_error(cmd, "--frames %s: too many frames", val);
                have_frames = 1;
            } else {
                return gr_cli_usage_error(cmd, "unknown option %s", a);
            }
        } else if (!tech_name) {
            tech_name = a; /* the first positional argument */
        } else if ((rc = gr_args_take_scene(args)) != 0) {
            return rc;
        }
    }
    if (!tech_name) return gr_cli_usage_error(cmd, "no technique given (`godrays techniques` lists them)");
    if (!args->scene_path && (strchr(tech_name, '/') || strchr(tech_name, '.')))
        return gr_cli_usage_error(cmd, "%s: expected TECHNIQUE SCENE, the technique first (`godrays techniques` lists them)",
                                  tech_name);
    if ((rc = gr_args_need_scene(args)) != 0) return rc;
    /* user techniques before the scene, whose sections they add */
    const gr_technique_class *cls = NULL;
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    if ((rc = gr_args_find_technique(args, "TECHNIQUE", tech_name, &cls)) != 0) return rc;
    char default_out[GR_TECH_NAME_MAX + 8];
    snprintf(default_out, sizeof default_out, "%s.exr", cls->name);
    if (!out_path) out_path = default_out;

    gr_error err = {GR_OK, ""};
    gr_scene *scene = NULL;
    gr_gl *gl = NULL;
    gr_technique *r = NULL;
    gr_image *img = NULL;
    gr_technique_stats *runs = NULL;
    gr_metadata meta;
    gr_meta_init(&meta);
    if ((rc = gr_args_load_scene(args, &scene)) != 0) goto done;
    /* Settings are checked before any GL work, so bad input exits 2 even without GL. */
    if (gr_technique_check(cls, gr_technique_scene_settings(cls, scene), &err) != GR_OK) goto fail;
    /* So are the outputs (frames and previews go beside OUT). */
    if ((rc = gr_args_check_output_file(args, "-o", out_path)) != 0) goto done;
    if (target_path && (rc = gr_args_check_output_file(args, "--save-target", target_path)) != 0) goto done;
    double t_base = have_time ? time_s : scene->water.time_s;

    if (target_path && !cls->read_target) {
        gr_fail(&err, GR_E_USAGE, "--save-target: technique %s has no intermediate render target to save", cls->name);
        goto fail;
    }
    gr_gl_options glo;
    memset(&glo, 0, sizeof glo);
    glo.platform = platform;
    gr_technique_options opts;
    memset(&opts, 0, sizeof opts);
    opts.shader_dir = shader_dir;
    if (gr_gl_create(&glo, &gl, &err) != GR_OK) goto fail;
    if (gr_technique_create(cls, gl, &opts, &r, &err) != GR_OK) goto fail;
    img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    runs = calloc((size_t)repeat, sizeof *runs);
    if (!img || !runs) {
        gr_fail(&err, GR_E_NOMEM, "out of memory for a %dx%d image", scene->camera.width, scene->camera.height);
        goto fail;
    }
    if (!have_frames) {
        f0 = f1 = 0;
        fstep = 1;
    }
    for (long fr = f0; fr <= f1; fr += fstep) {
        char path[4096], png[4200];
        scene->water.time_s = have_frames ? t_base + (double)fr / fps : t_base;
        for (long k = 0; k < repeat; k++)
            if (gr_technique_render(r, scene, NULL, img, &runs[k], &err) != GR_OK) goto fail;
        gr_technique_stats stats;
        gr_technique_stats_median(runs, (int)repeat, &stats);
        if (have_frames) frame_path(out_path, fr, path, sizeof path);
        else snprintf(path, sizeof path, "%s", out_path);
        gr_meta_free(&meta);
        gr_meta_init(&meta);
        if (gr_technique_metadata(r, scene, NULL, &stats, &meta, &err) != GR_OK) goto fail;
        if (have_frames && gr_meta_set_int(&meta, "godrays:frame", fr) != GR_OK) {
            gr_fail(&err, GR_E_NOMEM, "out of memory");
            goto fail;
        }
        if (repeat > 1 && gr_meta_set_int(&meta, "godrays:timing_repeats", repeat) != GR_OK) {
            gr_fail(&err, GR_E_NOMEM, "out of memory");
            goto fail;
        }
        if (gr_exr_write(path, img, &meta, &err) != GR_OK) goto fail;
        if (preview) {
            static const int rgb[3] = {0, 1, 2};
            gr_args_preview_path(path, png, sizeof png);
            double e = exposure > 0 ? exposure : auto_exposure(img);
            if (gr_oiio_write_preview(png, img, rgb, e, &err) != GR_OK) goto fail;
        }
        if (target_path) {
            char tpath[4096];
            gr_image *timg = NULL;
            if (have_frames) frame_path(target_path, fr, tpath, sizeof tpath);
            else snprintf(tpath, sizeof tpath, "%s", target_path);
            if (gr_technique_read_target(r, &timg, &err) != GR_OK) goto fail;
            gr_status tst = gr_exr_write(tpath, timg, &meta, &err);
            gr_image_destroy(timg);
            if (tst != GR_OK) goto fail;
        }
        if (!quiet) {
            gr_strbuf line;
            char extra[512];
            gr_sb_init(&line);
            gr_sb_printf(&line, "%s: %s, t = %.4f s, GPU ms:", path, cls->name, scene->water.time_s);
            for (int p = 0; p < stats.n_passes; p++) {
                if (stats.gpu_ns[p] >= 0)
                    gr_sb_printf(&line, "%s %s %.3f", p ? "," : "", stats.pass_names[p], (double)stats.gpu_ns[p] * 1e-6);
                else
                    gr_sb_printf(&line, "%s %s n/a", p ? "," : "", stats.pass_names[p]);
            }
            gr_sb_printf(&line, "; wall %.3f ms", stats.wall_ms);
            if (stats.fragments >= 0) gr_sb_printf(&line, "; fragments %lld", stats.fragments);
            gr_technique_summary(r, &stats, extra, sizeof extra);
            if (extra[0]) gr_sb_printf(&line, "; %s", extra);
            printf("%s\n", gr_sb_str(&line));
            gr_sb_free(&line);
        }
    }
    goto done;
fail:
    rc = gr_cli_report(cmd, &err);
done:
    gr_meta_free(&meta);
    free(runs);
    gr_image_destroy(img);
    gr_technique_destroy(r);
    gr_gl_destroy(gl);
    free(scene);
    return rc;
}

int cmd_render(int argc, char **argv)
{
    return gr_args_main("render", argc, argv, render_with);
}
