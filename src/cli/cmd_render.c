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

#include "gl/gl.h"
#include "gl/glctx.h"
#include "image/exr.h"
#include "image/png.h"
#include "realtime/technique.h"
#include "realtime/timing.h"
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
            "  --preset FILE        apply a preset (docs/tuning.md \"Presets\"): its technique's settings as\n"
            "                       overrides; TECHNIQUE may then be left out\n"
            "  --time-limit S       give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --shader-dir DIR     GLSL files in DIR replace the technique's embedded ones of the same name\n"
            "  --time T             water time t (s) of eq. 5.5.7 (default: the scene's water.time_s)\n"
            "  --frames A:B:S       render frames A, A+S, ... up to B at time T + frame / fps; the\n"
            "                       frame number goes into the file names (OUT.0007.exr)\n"
            "  --fps F              frames per second for --frames (default 30)\n"
            "  --repeat R           render each frame R times in one context after a warm-up render;\n"
            "                       timings printed are the median of the R renders, with their\n"
            "                       spread and GL_RENDERER (default 1: one render, no warm-up)\n"
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

/* What the command line asks for. */
typedef struct render_opts {
    const char *out_path, *shader_dir, *target_path, *tech_name;
    int preview, quiet, have_time, have_frames, help;
    double time_s, fps, exposure;
    long f0, f1, fstep, repeat;
    gr_gl_platform platform;
} render_opts;

/* One option with a value (a = its name); returns the exit code, 0 when taken. */
static int take_value_option(gr_args *args, render_opts *o, const char *a)
{
    const char *cmd = "render", *val = NULL;
    int rc = gr_args_value(args, &val);
    if (rc) return rc;
    if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
        o->out_path = val;
    } else if (!strcmp(a, "--save-target")) {
        o->target_path = val;
    } else if (!strcmp(a, "--shader-dir")) {
        o->shader_dir = val;
    } else if (!strcmp(a, "--time")) {
        if (parse_double(val, &o->time_s)) return gr_cli_usage_error(cmd, "--time %s: not a number", val);
        o->have_time = 1;
    } else if (!strcmp(a, "--fps")) {
        if (parse_double(val, &o->fps) || !(o->fps > 0)) return gr_cli_usage_error(cmd, "--fps %s: expected a number > 0", val);
    } else if (!strcmp(a, "--exposure")) {
        if (parse_double(val, &o->exposure) || !(o->exposure > 0))
            return gr_cli_usage_error(cmd, "--exposure %s: expected a number > 0", val);
    } else if (!strcmp(a, "--repeat")) {
        if (parse_int(val, &o->repeat) || o->repeat < 1 || o->repeat > 100000)
            return gr_cli_usage_error(cmd, "--repeat %s: expected an integer in [1, 100000]", val);
    } else if (!strcmp(a, "--frames")) {
        char extra;
        if (sscanf(val, "%ld:%ld:%ld%c", &o->f0, &o->f1, &o->fstep, &extra) != 3 || o->fstep < 1 || o->f1 < o->f0 ||
            o->f0 < 0)
            return gr_cli_usage_error(cmd, "--frames %s: expected START:END:STEP with 0 <= START <= END, STEP >= 1", val);
        if ((o->f1 - o->f0) / o->fstep >= 100000) return gr_cli_usage_error(cmd, "--frames %s: too many frames", val);
        o->have_frames = 1;
    } else {
        return gr_cli_usage_error(cmd, "unknown option %s", a);
    }
    return 0;
}

/* The argument loop; returns the exit code (o->help: help printed). */
static int parse_args(gr_args *args, render_opts *o)
{
    int rc = 0;
    o->preview = 1;
    o->fps = 30.0;
    o->fstep = o->repeat = 1;
    o->platform = GR_GL_AUTO;
    for (; args->i < args->argc && !rc; args->i++) {
        const char *a = args->argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            o->help = 1;
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o->quiet = 1;
        } else if (!strcmp(a, "--no-preview")) {
            o->preview = 0;
        } else if (!strcmp(a, "--set")) {
            rc = gr_args_take_set(args);
        } else if (!strcmp(a, "--gl-platform")) {
            rc = gr_args_take_gl_platform(args, &o->platform);
        } else if (!strcmp(a, "--size")) {
            rc = gr_args_take_size(args);
        } else if (!strcmp(a, "--technique-dir")) {
            rc = gr_args_take_technique_dir(args);
        } else if (!strcmp(a, "--time-limit")) {
            rc = gr_args_take_time_limit(args);
        } else if (!strcmp(a, "--preset")) {
            rc = gr_args_take_preset(args);
        } else if (a[0] == '-' && a[1] != '\0') {
            rc = take_value_option(args, o, a); /* every other option takes a value */
        } else if (!o->tech_name) {
            o->tech_name = a; /* the first positional argument */
        } else {
            rc = gr_args_take_scene(args);
        }
    }
    if (rc) return rc;
    if (args->preset_path && o->tech_name && !args->scene_path && (strchr(o->tech_name, '/') || strchr(o->tech_name, '.'))) {
        /* `render --preset P SCENE`: the technique is the preset's */
        args->scene_path = o->tech_name;
        o->tech_name = NULL;
        if ((rc = gr_args_add_input(args, "the scene", args->scene_path)) != 0) return rc;
    }
    if (!o->tech_name && !args->preset_path) return gr_cli_usage_error("render", "no technique given (`godrays techniques` lists them)");
    if (!args->scene_path && (strchr(o->tech_name, '/') || strchr(o->tech_name, '.')))
        return gr_cli_usage_error("render", "%s: expected TECHNIQUE SCENE, the technique first (`godrays techniques` lists them)",
                                  o->tech_name);
    if (!o->have_frames) {
        o->f0 = o->f1 = 0;
        o->fstep = 1;
    }
    return gr_args_need_scene(args);
}

/* The line printed per frame: the pass timings, the wall time and the technique's summary. */
static void print_frame(const char *path, const gr_technique *r, const gr_technique_class *cls, const gr_scene *scene,
                        const gr_technique_stats *stats, const gr_timing *tm)
{
    gr_strbuf line;
    char extra[512];
    gr_sb_init(&line);
    gr_sb_printf(&line, "%s: %s, t = %.4f s, GPU ms:", path, cls->name, scene->water.time_s);
    for (int p = 0; p < stats->n_passes; p++) {
        if (stats->gpu_ns[p] >= 0)
            gr_sb_printf(&line, "%s %s %.3f", p ? "," : "", stats->pass_names[p], (double)stats->gpu_ns[p] * 1e-6);
        else
            gr_sb_printf(&line, "%s %s n/a", p ? "," : "", stats->pass_names[p]);
    }
    gr_sb_printf(&line, "; wall %.3f ms", stats->wall_ms);
    if (tm)
        gr_sb_printf(&line, " (median of %d after %d warm-up; %.3f-%.3f; %s)", tm->n, tm->warmup, tm->wall_min_ms,
                     tm->wall_max_ms, tm->renderer);
    if (stats->fragments >= 0) gr_sb_printf(&line, "; fragments %lld", stats->fragments);
    for (int p = 0; p < stats->n_passes; p++) { /* cost counters (docs/techniques.md; * = GL query) */
        gr_pass_cost_text(&stats->cost[p], extra, sizeof extra);
        if (extra[0]) gr_sb_printf(&line, "%s %s [%s]", p ? "," : "; cost:", stats->pass_names[p], extra);
    }
    gr_technique_summary(r, stats, extra, sizeof extra);
    if (extra[0]) gr_sb_printf(&line, "; %s", extra);
    printf("%s\n", gr_sb_str(&line));
    gr_sb_free(&line);
}

/* One frame's files: the EXR with its metadata, the preview, the intermediate target. */
static gr_status write_frame(const render_opts *o, gr_technique *r, const gr_scene *scene, long fr, const gr_image *img,
                             const gr_technique_stats *stats, const char *path, gr_error *err)
{
    gr_metadata meta;
    gr_meta_init(&meta);
    gr_status st = gr_technique_metadata(r, scene, NULL, stats, &meta, err);
    if (st == GR_OK && ((o->have_frames && gr_meta_set_int(&meta, "godrays:frame", fr) != GR_OK) ||
                        (o->repeat > 1 && gr_meta_set_int(&meta, "godrays:timing_repeats", o->repeat) != GR_OK)))
        st = gr_fail(err, GR_E_NOMEM, "out of memory");
    if (st == GR_OK) st = gr_exr_write(path, img, &meta, err);
    if (st == GR_OK && o->preview) {
        static const int rgb[3] = {0, 1, 2};
        char png[4200];
        gr_args_preview_path(path, png, sizeof png);
        st = gr_png_write_preview(png, img, rgb, o->exposure > 0 ? o->exposure : auto_exposure(img), err);
    }
    if (st == GR_OK && o->target_path) {
        char tpath[4096];
        gr_image *timg = NULL;
        if (o->have_frames) frame_path(o->target_path, fr, tpath, sizeof tpath);
        else snprintf(tpath, sizeof tpath, "%s", o->target_path);
        st = gr_technique_read_target(r, &timg, err);
        if (st == GR_OK) st = gr_exr_write(tpath, timg, &meta, err);
        gr_image_destroy(timg);
    }
    gr_meta_free(&meta);
    return st;
}

/* The GL context, the technique, and every frame (each rendered o->repeat times; the
 * timings printed and stored are the median's). */
static gr_status render_frames(const render_opts *o, const gr_technique_class *cls, gr_scene *scene, gr_error *err)
{
    gr_gl *gl = NULL;
    gr_technique *r = NULL;
    gr_image *img = NULL;
    const double t_base = o->have_time ? o->time_s : scene->water.time_s;
    gr_gl_options glo;
    memset(&glo, 0, sizeof glo);
    glo.platform = o->platform;
    gr_technique_options opts;
    memset(&opts, 0, sizeof opts);
    opts.shader_dir = o->shader_dir;
    gr_status st = gr_gl_create(&glo, &gl, err);
    /* the god-ray layer's float target must fit this GL (a 16384 x 16384 one failed late as
     * "framebuffer incomplete"): said up front, with the limit */
    if (st == GR_OK)
        st = gr_gl_check_target_size("camera.width/height", scene->camera.width, scene->camera.height, GL_RGBA32F, err);
    if (st == GR_OK) st = gr_technique_create(cls, gl, &opts, &r, err);
    if (st == GR_OK) {
        img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
        if (!img)
            st = gr_fail(err, GR_E_NOMEM, "out of memory for a %dx%d image", scene->camera.width, scene->camera.height);
    }
    for (long fr = o->f0; st == GR_OK && fr <= o->f1; fr += o->fstep) {
        char path[4096];
        scene->water.time_s = o->have_frames ? t_base + (double)fr / o->fps : t_base;
        /* with --repeat, one warm-up render first (realtime/timing.h) */
        gr_timing tm;
        if ((st = gr_timing_measure(r, scene, NULL, img, o->repeat > 1, (int)o->repeat, &tm, err)) != GR_OK) break;
        const gr_technique_stats stats = tm.median;
        if (o->have_frames) frame_path(o->out_path, fr, path, sizeof path);
        else snprintf(path, sizeof path, "%s", o->out_path);
        st = write_frame(o, r, scene, fr, img, &stats, path, err);
        if (st == GR_OK && !o->quiet) print_frame(path, r, cls, scene, &stats, o->repeat > 1 ? &tm : NULL);
    }
    gr_image_destroy(img);
    gr_technique_destroy(r);
    gr_gl_destroy(gl);
    return st;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int render_with(gr_args *args)
{
    const char *cmd = "render";
    render_opts o;
    memset(&o, 0, sizeof o);
    int rc = parse_args(args, &o);
    if (rc || o.help) return rc;
    /* user techniques before the scene, whose sections they add */
    const gr_technique_class *cls = NULL;
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    if (!o.tech_name) o.tech_name = args->preset_technique;
    if ((rc = gr_args_find_technique(args, "TECHNIQUE", o.tech_name, &cls)) != 0) return rc;
    if (args->preset_path && strcmp(cls->name, args->preset_technique))
        return gr_cli_usage_error("render", "--preset %s: a preset of technique %s, not %s", args->preset_path,
                                  args->preset_technique, cls->name);
    char default_out[GR_TECH_NAME_MAX + 8];
    snprintf(default_out, sizeof default_out, "%s.exr", cls->name);
    if (!o.out_path) o.out_path = default_out;

    gr_error err = {GR_OK, ""};
    gr_scene *scene = NULL;
    if ((rc = gr_args_load_scene(args, &scene)) != 0) return rc;
    /* Settings are checked before any GL work, so bad input exits 2 even without GL. */
    gr_status st = gr_technique_check(cls, gr_technique_scene_settings(cls, scene), &err);
    /* So are the outputs (frames and previews go beside OUT). */
    if (st == GR_OK) {
        if (!rc) rc = gr_args_check_output_file(args, "-o", o.out_path);
        if (!rc && !o.have_frames && o.preview) rc = gr_args_note_preview(args, "-o", o.out_path);
        if (!rc && o.target_path) rc = gr_args_check_output_file(args, "--save-target", o.target_path);
        if (!rc && o.target_path && !cls->read_target)
            st = gr_fail(&err, GR_E_USAGE, "--save-target: technique %s has no intermediate render target to save", cls->name);
        if (!rc && st == GR_OK) st = render_frames(&o, cls, scene, &err);
    }
    if (!rc && st != GR_OK) rc = gr_cli_report(cmd, &err);
    free(scene);
    return rc;
}

int cmd_render(int argc, char **argv)
{
    return gr_args_main("render", argc, argv, render_with);
}
