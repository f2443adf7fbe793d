/* godrays reference SCENE -o OUT.exr: the ground-truth god-ray layer (reference/), with a
 * PNG preview beside it. Quality flags become "reference.*" overrides of the scene, so they
 * are range-checked by the same tables as the file. */
#include "cli/cli.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/exr.h"
#include "image/oiio.h"
#include "reference/bench.h"
#include "reference/integrator.h"
#include "scene/scene.h"

#define MAX_OVERRIDES 64

static volatile sig_atomic_t g_interrupt = 0;

static void on_sigint(int sig)
{
    (void)sig;
    g_interrupt = 1;
    signal(SIGINT, SIG_DFL); /* a second Ctrl-C ends the process at once */
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays reference SCENE.json -o OUT.exr [options]\n"
            "\n"
            "Renders the ground-truth god-ray layer (sunlight refracted by the waves and scattered\n"
            "once toward the camera) with per-pixel standard errors, and a PNG preview beside it.\n"
            "\n"
            "options (defaults: the scene's \"reference\" section):\n"
            "  -o, --output FILE      EXR to write (required); the preview is FILE with .png\n"
            "  --spp N                camera samples per pixel in each batch\n"
            "  --steps N              stratified march steps per camera ray\n"
            "  --surface-res N        surface tessellation (N x N cells over the lit patch)\n"
            "  --sun-samples N        directions sampled inside the sun's disc\n"
            "  --batches N            independent batches for the error bars\n"
            "  --seed N               RNG seed (same seed, same bytes, any thread count)\n"
            "  --threads N            worker threads (0 = all cores)\n"
            "  --target-error E       refine until the relative standard error of the image mean\n"
            "                         and of its 95th-percentile pixel are below E\n"
            "  --cutoff T             stop camera rays where their transmittance falls below T\n"
            "  --size WxH             override the image size\n"
            "  --set PATH=VALUE       any scene override, e.g. --set medium.g=0.9 (repeatable)\n"
            "  --aov                  add transmittance and ray_length channels\n"
            "  --no-preview           do not write the PNG preview\n"
            "  --quiet                no progress bar\n"
            "  --bench                benchmark instead of writing files: hot-loop lookups per second\n"
            "                         with 1 and 2 threads, Embree's raw occlusion-ray throughput\n"
            "\n"
            "Ctrl-C stops the render and writes what is done, marked godrays:partial = 1 (exit 1).\n");
}

/* Appends the override a + b + c (e.g. "reference." "spp=" "16"). */
static int add_override(char **ov, int *n, const char *a, const char *b, const char *c)
{
    if (*n >= MAX_OVERRIDES) return -1;
    size_t len = strlen(a) + strlen(b) + strlen(c) + 1;
    char *s = malloc(len);
    if (!s) return -1;
    snprintf(s, len, "%s%s%s", a, b, c);
    ov[(*n)++] = s;
    return 0;
}

/* Appends value to the last override. */
static int add_override_value(char **ov, int n, const char *value)
{
    size_t len = strlen(ov[n - 1]) + strlen(value) + 1;
    char *s = realloc(ov[n - 1], len);
    if (!s) return -1;
    strcat(s, value);
    ov[n - 1] = s;
    return 0;
}

static void preview_path(const char *out, char *buf, size_t n)
{
    snprintf(buf, n, "%s", out);
    char *dot = strrchr(buf, '.'), *slash = strrchr(buf, '/');
    if (dot && (!slash || dot > slash)) *dot = '\0';
    size_t l = strlen(buf);
    snprintf(buf + l, n - l, ".png");
}

int cmd_reference(int argc, char **argv)
{
    static const struct { const char *flag, *key; } qflags[] = {
        {"--spp", "spp"}, {"--steps", "steps"}, {"--surface-res", "surface_res"},
        {"--sun-samples", "sun_samples"}, {"--batches", "batches"}, {"--seed", "seed"},
        {"--threads", "threads"}, {"--target-error", "target_error"}, {"--cutoff", "transmittance_cutoff"}};
    const char *cmd = "reference", *scene_path = NULL, *out_path = NULL;
    char *ov[MAX_OVERRIDES];
    int nov = 0, quiet = 0, aov = 0, preview = 1, bench = 0, rc = 2;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            rc = 0;
            goto done;
        }
        if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) { quiet = 1; continue; }
        if (!strcmp(a, "--aov")) { aov = 1; continue; }
        if (!strcmp(a, "--bench")) { bench = 1; continue; }
        if (!strcmp(a, "--no-preview")) { preview = 0; continue; }
        int matched = 0;
        for (size_t k = 0; k < sizeof qflags / sizeof qflags[0]; k++) {
            if (strcmp(a, qflags[k].flag)) continue;
            matched = 1;
            if (i + 1 >= argc) { rc = gr_cli_usage_error(cmd, "%s needs a value", a); goto done; }
            if (add_override(ov, &nov, "reference.", qflags[k].key, "=") ||
                add_override_value(ov, nov, argv[++i])) {
                rc = gr_cli_usage_error(cmd, "too many overrides");
                goto done;
            }
        }
        if (matched) continue;
        if (!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--set") || !strcmp(a, "--size")) {
            if (i + 1 >= argc) { rc = gr_cli_usage_error(cmd, "%s needs a value", a); goto done; }
            const char *v = argv[++i];
            if (a[1] == 'o' || !strcmp(a, "--output")) { out_path = v; continue; }
            if (!strcmp(a, "--set")) {
                if (!strchr(v, '=')) { rc = gr_cli_usage_error(cmd, "--set %s: expected PATH=VALUE", v); goto done; }
                if (add_override(ov, &nov, v, "", "")) { rc = gr_cli_usage_error(cmd, "too many overrides"); goto done; }
                continue;
            }
            int w = 0, h = 0;
            char extra;
            if (sscanf(v, "%dx%d%c", &w, &h, &extra) != 2 || w < 1 || h < 1) {
                rc = gr_cli_usage_error(cmd, "--size %s: expected WxH, e.g. 640x360", v);
                goto done;
            }
            char ws[32], hs[32];
            snprintf(ws, sizeof ws, "%d", w);
            snprintf(hs, sizeof hs, "%d", h);
            if (add_override(ov, &nov, "camera.width=", ws, "") || add_override(ov, &nov, "camera.height=", hs, "")) {
                rc = gr_cli_usage_error(cmd, "too many overrides");
                goto done;
            }
            continue;
        }
        if (a[0] == '-' && a[1]) { rc = gr_cli_usage_error(cmd, "unknown option %s", a); goto done; }
        if (scene_path) { rc = gr_cli_usage_error(cmd, "more than one scene given (%s, %s)", scene_path, a); goto done; }
        scene_path = a;
    }
    if (!scene_path) { rc = gr_cli_usage_error(cmd, "no scene file given"); goto done; }
    if (!out_path && !bench) { rc = gr_cli_usage_error(cmd, "no output given (-o OUT.exr)"); goto done; }

    gr_error err = {GR_OK, ""};
    gr_scene *scene = malloc(sizeof *scene);
    if (!scene) { err.status = GR_E_NOMEM; snprintf(err.msg, sizeof err.msg, "out of memory"); rc = gr_cli_report(cmd, &err); goto done; }
    gr_status st = gr_scene_load_file(scene_path, (const char *const *)ov, nov, scene, &err);
    if (st != GR_OK) { rc = gr_cli_report(cmd, &err); free(scene); goto done; }

    if (bench) {
        gr_ref_bench_result b;
        st = gr_ref_bench(scene, &b, &err);
        free(scene);
        if (st != GR_OK) { rc = gr_cli_report(cmd, &err); goto done; }
        printf("Embree raw rtcOccluded1 (1 thread, random rays): %.3g rays/s vs occluders, %.3g rays/s vs the "
               "surface mesh (%lld triangles)\n", b.occluded_occluders_per_s, b.occluded_surface_per_s, b.surface_triangles);
        printf("beam lookups alone (rtcPointQuery + containment, 1 thread, %lld primitives): %.3g /s\n", b.beam_prims,
               b.point_queries_per_s);
        printf("hot loop (lookups incl. shadow rays and shading): 1 thread %.3g /s (%.2f s), 2 threads %.3g /s (%.2f s)\n",
               b.qps[0], b.wall_s[0], b.qps[1], b.wall_s[1]);
        printf("speed-up 1 -> 2 threads: %.2fx; identical bytes: %s; pixels within 1%%: %.1f%%\n", b.speedup,
               b.identical ? "yes" : "NO", 100.0 * b.frac_se_1pct);
        rc = 0;
        goto done;
    }
    gr_ref_options opt;
    gr_ref_options_default(&opt);
    opt.progress = !quiet;
    opt.aovs = aov;
    opt.interrupt = &g_interrupt;
    gr_ref_renderer *r = NULL;
    st = gr_ref_create(scene, &opt, &r, &err);
    if (st != GR_OK) { rc = gr_cli_report(cmd, &err); free(scene); goto done; }
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old);
    gr_ref_result res;
    st = gr_ref_render(r, &res, &err);
    sigaction(SIGINT, &old, NULL);
    gr_ref_destroy(r);
    free(scene);
    if (st != GR_OK) { rc = gr_cli_report(cmd, &err); goto done; }
    st = gr_exr_write(out_path, res.image, &res.meta, &err);
    if (st == GR_OK && preview) {
        char pp[4096];
        preview_path(out_path, pp, sizeof pp);
        const int rgb[3] = {0, 1, 2};
        st = gr_oiio_write_preview(pp, res.image, rgb, res.preview_exposure, &err);
    }
    if (st != GR_OK) {
        rc = gr_cli_report(cmd, &err);
        gr_ref_result_free(&res);
        goto done;
    }
    if (!quiet)
        fprintf(stderr,
                "godrays reference: wrote %s (%dx%d, %d spp, %.1f s%s): rel. std. error of the mean %.3g%%, "
                "of the p95 pixel %.3g%%, %.1f%% of pixels within 1%%\n",
                out_path, res.image->width, res.image->height, res.spp, res.wall_s, res.partial ? ", PARTIAL" : "",
                100.0 * res.rel_se_mean, 100.0 * res.rel_se_p95, 100.0 * res.frac_se_1pct);
    if (res.partial) {
        fprintf(stderr, "godrays reference: interrupted; %s holds the partial result (godrays:partial = 1)\n", out_path);
        rc = 1;
    } else {
        rc = 0;
    }
    gr_ref_result_free(&res);
done:
    for (int i = 0; i < nov; i++) free(ov[i]);
    return rc;
}
