/* godrays run SCENE [-o DIR]: the main job. Renders the real-time shafts and the ground truth
 * (or reuses a cached one), compares them (reference-stderr aware, raw and after the best
 * scale fit) and writes the report folder (src/report/report.h), then prints a short table. */
#include "cli/cli.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "compare/metrics.h"
#include "image/exr.h"
#include "realtime/shafts.h"
#include "reference/integrator.h"
#include "report/cache.h"
#include "report/report.h"
#include "scene/scene.h"

#define MAX_SETS 256

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
            "usage: godrays run SCENE [-o DIR] [options]\n"
            "\n"
            "The main job: renders SCENE with seed 000's real-time shafts (OpenGL) and as ground truth\n"
            "(Embree single scattering, with error bars), compares them and writes a report:\n"
            "  DIR/index.html    images side by side, metrics, charts, timings, scene and settings\n"
            "  DIR/summary.png   labelled contact sheet;  DIR/metrics.json  every number\n"
            "  DIR/reference.exr, DIR/shafts.exr  the two linear images (for godrays compare)\n"
            "The ground truth is cached (key: the scene's content and the reference settings) and\n"
            "reused by later runs. How to read the report: docs/report.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR   report folder (default: out/SCENE_NAME)\n"
            "  --set KEY=VALUE    override a scene value before validation, e.g. shafts.K=0.7,\n"
            "                     reference.spp=4, medium.g=0.9 (repeatable)\n"
            "  --size WxH         image size (same as --set camera.width=W --set camera.height=H)\n"
            "  --no-cache         render the ground truth even if a cached one exists, and do not\n"
            "                     store it\n"
            "  -q, --quiet        no progress bar or step messages (the summary table is printed)\n"
            "  -h, --help         this help\n"
            "\n"
            "Cache directory: $GODRAYS_CACHE, else $XDG_CACHE_HOME/godrays or ~/.cache/godrays, else\n"
            "./.godrays-cache. Ctrl-C stops the ground truth; nothing is cached or reported (exit 1).\n"
            "Exit codes: 0 ok, 1 runtime failure (GL, I/O, interrupted), 2 bad usage or bad scene.\n");
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* "out/" + the scene name with every character outside [A-Za-z0-9._-] replaced by '_'. */
static void default_dir(const char *name, char *buf, size_t n)
{
    size_t j = (size_t)snprintf(buf, n, "out/");
    for (const char *p = name; *p && j + 1 < n; p++) {
        const char ch = *p;
        const int ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
                       ch == '_' || ch == '-';
        buf[j++] = ok ? ch : '_';
    }
    buf[j] = '\0';
    if (!strcmp(buf, "out/") || !strcmp(buf, "out/.") || !strcmp(buf, "out/..")) snprintf(buf, n, "out/scene");
}

/* The command line, arguments with spaces or quotes single-quoted, for the report. */
static void command_line(int argc, char **argv, char *buf, size_t n)
{
    size_t j = (size_t)snprintf(buf, n, "godrays");
    for (int i = 0; i < argc && j < n; i++) {
        const char *a = argv[i];
        const int quote = a[0] == '\0' || strpbrk(a, " \t\"'$\\") != NULL;
        j += (size_t)snprintf(buf + j, n - j, quote ? " '%s'" : " %s", a);
    }
}

/* One render in a fresh context, as `godrays shafts` does. */
static gr_status render_shafts(const gr_scene *scene, gr_image **img, gr_metadata *meta, gr_error *err)
{
    gr_shafts *r = NULL;
    gr_status st = gr_shafts_create(NULL, &r, err);
    if (st != GR_OK) return st;
    *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    if (!*img) {
        gr_shafts_destroy(r);
        return gr_fail(err, GR_E_NOMEM, "out of memory for a %d x %d image", scene->camera.width, scene->camera.height);
    }
    gr_shafts_stats stats;
    st = gr_shafts_render(r, scene, NULL, *img, &stats, err);
    if (st == GR_OK) st = gr_shafts_metadata(r, scene, NULL, &stats, meta, err);
    gr_shafts_destroy(r);
    return st;
}

typedef struct ref_out {
    gr_image *img;
    gr_metadata meta;
    int cached;            /* read from the cache */
    int cache_on;          /* a cache directory is in use */
    char cache_path[4200];
    char note[1400];       /* why an entry was ignored, or why caching is off */
} ref_out;

/* The ground truth: from the cache when a valid entry exists, else rendered (and stored). */
static gr_status get_reference(const gr_scene *scene, int use_cache, int quiet, ref_out *ro, gr_error *err)
{
    char dir[4096], key[GR_CACHE_KEY_LEN + 1];
    gr_status st;
    if (use_cache) {
        gr_error cerr = {GR_OK, ""};
        if (gr_cache_dir(dir, sizeof dir, &cerr) != GR_OK) {
            snprintf(ro->note, sizeof ro->note, "cache off: %.1000s", cerr.msg);
            if (!quiet) fprintf(stderr, "godrays run: warning: %s\n", ro->note);
        } else {
            if ((st = gr_cache_key(scene, key, err)) != GR_OK) return st;
            if ((st = gr_cache_path(dir, key, ro->cache_path, sizeof ro->cache_path, err)) != GR_OK) return st;
            ro->cache_on = 1;
            char why[1400];
            st = gr_cache_load(dir, key, scene->camera.width, scene->camera.height, &ro->img, &ro->meta, &ro->cached,
                               why, sizeof why, err);
            if (st != GR_OK) return st;
            if (ro->cached) {
                if (!quiet) fprintf(stderr, "godrays run: ground truth from the cache: %s\n", ro->cache_path);
                return GR_OK;
            }
            if (strstr(why, "ignored")) {
                snprintf(ro->note, sizeof ro->note, "%s", why);
                if (!quiet) fprintf(stderr, "godrays run: warning: cache entry %s\n", why);
            }
        }
    }
    if (!quiet)
        fprintf(stderr, "godrays run: rendering the ground truth (%d x %d; %s)...\n", scene->camera.width,
                scene->camera.height, ro->cache_on ? "cached for later runs" : "not cached");
    gr_ref_options opt;
    gr_ref_options_default(&opt);
    opt.progress = !quiet;
    opt.interrupt = &g_interrupt;
    gr_ref_renderer *r = NULL;
    if ((st = gr_ref_create(scene, &opt, &r, err)) != GR_OK) return st;
    struct sigaction sa, old;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old);
    gr_ref_result res;
    st = gr_ref_render(r, &res, err);
    sigaction(SIGINT, &old, NULL);
    gr_ref_destroy(r);
    if (st != GR_OK) return st;
    if (res.partial) {
        gr_ref_result_free(&res);
        return gr_fail(err, GR_E_INTERRUPTED, "interrupted while rendering the ground truth: no report written, "
                       "nothing cached");
    }
    ro->img = res.image;
    res.image = NULL;
    gr_meta_free(&ro->meta);
    ro->meta = res.meta; /* hand the items over */
    gr_meta_init(&res.meta);
    gr_ref_result_free(&res);
    if (ro->cache_on) {
        gr_error serr = {GR_OK, ""};
        if (gr_cache_store(dir, key, ro->img, &ro->meta, &serr) != GR_OK) {
            /* A cache that cannot be written costs time later, not correctness now. */
            snprintf(ro->note, sizeof ro->note, "not cached: %.1200s", serr.msg);
            if (!quiet) fprintf(stderr, "godrays run: warning: %s\n", ro->note);
            ro->cache_on = 0;
        }
    }
    return GR_OK;
}

static void print_summary(const char *dir, const gr_scene *scene, const gr_metrics *m, const ref_out *ro,
                          double t_ref, double t_shafts, const gr_metadata *smeta)
{
    const gr_metrics_set *raw = &m->raw, *fit = m->have_fit ? &m->fit : &m->raw;
    const gr_channel_metrics *yr = &raw->ch[GR_MCH_Y], *yf = &fit->ch[GR_MCH_Y];
    double gpu = 0.0;
    int any = 0;
    static const char *const keys[3] = {"godrays:gpu_ns.shadow", "godrays:gpu_ns.shafts", "godrays:gpu_ns.final"};
    for (int p = 0; p < 3; p++) {
        const gr_meta_item *it = gr_meta_get(smeta, keys[p]);
        if (it && it->type != GR_META_STRING && it->num >= 0) {
            gpu += it->num * 1e-6;
            any = 1;
        }
    }
    const gr_meta_item *cpu = gr_meta_get(smeta, "godrays:cpu_ms");
    printf("scene '%s' (%d x %d): ground truth %.1f s (%s), real-time shafts %.2f s (GPU ",
           scene->name, scene->camera.width, scene->camera.height, t_ref, ro->cached ? "from the cache" : "rendered",
           t_shafts);
    if (any) printf("%.2f ms", gpu);
    else printf("n/a");
    printf(", CPU %.2f ms)\n", cpu && cpu->type != GR_META_STRING ? cpu->num : NAN);
    printf("luminance Y                  as rendered   x a (a = %.4g)\n", fit->scale);
#define ROW(label, a, b) printf("  %-24s %12.4g %12.4g\n", label, (double)(a), (double)(b))
    ROW("bias (mean a t - r)", yr->bias, yf->bias);
    ROW("RMSE", yr->rmse, yf->rmse);
    ROW("RMSE / mean reference", yr->ref_mean != 0 ? yr->rmse / fabs(yr->ref_mean) : NAN,
        yf->ref_mean != 0 ? yf->rmse / fabs(yf->ref_mean) : NAN);
    ROW("relative MSE", yr->rel_mse, yf->rel_mse);
    ROW("PSNR dB (ref peak)", yr->psnr_ref_db, yf->psnr_ref_db);
    ROW("SSIM", raw->ssim_y, fit->ssim_y);
    ROW("RMSE, blur sigma 16 px", yr->rmse_blur[GR_METRICS_NSCALES - 1], yf->rmse_blur[GR_METRICS_NSCALES - 1]);
#undef ROW
    printf("scored %lld of %lld pixels (%lld not scored: reference rel. std. error > %g)", m->n_scored, m->n_pixels,
           m->n_stderr_excluded, m->stderr_bound);
    if (m->have_stderr && yf->n_samples > 0)
        printf("; after the fit %.1f %% of Y differences are within 2 std. errors",
               100.0 * (double)yf->n_not_significant / (double)yf->n_samples);
    printf("\nreport: %s/index.html (also summary.png, metrics.json)\n", dir);
}

int cmd_run(int argc, char **argv)
{
    const char *cmd = "run";
    const char *scene_path = NULL, *outdir = NULL;
    const char *sets[MAX_SETS + 2];
    char size_set[2][48];
    int n_sets = 0, quiet = 0, use_cache = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--no-cache")) {
            use_cache = 0;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output") || !strcmp(a, "--set") || !strcmp(a, "--size")) {
            if (i + 1 >= argc) return gr_cli_usage_error(cmd, "%s needs a value", a);
            const char *v = argv[++i];
            if (!strcmp(a, "--set")) {
                if (n_sets >= MAX_SETS) return gr_cli_usage_error(cmd, "--set: more than %d overrides", MAX_SETS);
                if (!strchr(v, '=')) return gr_cli_usage_error(cmd, "--set %s: expected KEY=VALUE", v);
                sets[n_sets++] = v;
            } else if (!strcmp(a, "--size")) {
                int w = 0, h = 0;
                char extra;
                if (sscanf(v, "%dx%d%c", &w, &h, &extra) != 2 || w < 1 || h < 1)
                    return gr_cli_usage_error(cmd, "--size %s: expected WxH, e.g. 640x360", v);
                snprintf(size_set[0], sizeof size_set[0], "camera.width=%d", w);
                snprintf(size_set[1], sizeof size_set[1], "camera.height=%d", h);
                sets[n_sets++] = size_set[0];
                sets[n_sets++] = size_set[1];
            } else {
                if (!v[0]) return gr_cli_usage_error(cmd, "%s: empty directory name", a);
                outdir = v;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            return gr_cli_usage_error(cmd, "unknown option %s", a);
        } else {
            if (scene_path) return gr_cli_usage_error(cmd, "more than one scene given (%s, %s)", scene_path, a);
            scene_path = a;
        }
    }
    if (!scene_path) return gr_cli_usage_error(cmd, "no scene file given");

    gr_error err = {GR_OK, ""};
    gr_scene *scene = malloc(sizeof *scene);
    gr_image *test = NULL;
    gr_metadata smeta;
    gr_meta_init(&smeta);
    ref_out ro;
    memset(&ro, 0, sizeof ro);
    gr_meta_init(&ro.meta);
    int rc = 0;
    char dirbuf[4096], cmdline[8192], path[4300];
    if (!scene) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        goto fail;
    }
    if (gr_scene_load_file(scene_path, sets, n_sets, scene, &err) != GR_OK) goto fail;
    /* Bad settings are bad input (exit 2) before any slow or GL work. */
    if (gr_shafts_check_settings(&scene->shafts, &err) != GR_OK) goto fail;
    if (!outdir) {
        default_dir(scene->name, dirbuf, sizeof dirbuf);
        outdir = dirbuf;
    }
    command_line(argc, argv, cmdline, sizeof cmdline);

    /* The real-time side first: it takes a second, and a GL failure should not cost the user
     * a two-minute ground truth first. */
    if (!quiet) fprintf(stderr, "godrays run: rendering the real-time shafts...\n");
    double t = now_s();
    if (render_shafts(scene, &test, &smeta, &err) != GR_OK) goto fail;
    const double t_shafts = now_s() - t;

    t = now_s();
    if (get_reference(scene, use_cache, quiet, &ro, &err) != GR_OK) goto fail;
    const double t_ref = now_s() - t;

    if (!quiet) fprintf(stderr, "godrays run: comparing...\n");
    t = now_s();
    gr_metrics_options mopt = {0};
    mopt.fit_scale = 1; /* the technique's intensity is an arbitrary factor (seed 000) */
    gr_metrics m;
    if (gr_metrics_compute(ro.img, test, &mopt, &m, &err) != GR_OK) goto fail;
    const double t_cmp = now_s() - t;

    /* The report links the EXRs; they are written first so that a finished index.html never
     * points at a missing file. */
    if (!quiet) fprintf(stderr, "godrays run: writing the report...\n");
    gr_report_input in = {.scene = scene, .ref = ro.img, .ref_meta = &ro.meta, .test = test, .test_meta = &smeta,
                          .metrics = &m, .command_line = cmdline, .ref_cached = ro.cached,
                          .ref_cache_path = ro.cache_on ? ro.cache_path : NULL,
                          .ref_cache_note = ro.note[0] ? ro.note : NULL, .ref_seconds = t_ref,
                          .shafts_seconds = t_shafts, .compare_seconds = t_cmp, .ref_exr = "reference.exr",
                          .test_exr = "shafts.exr"};
    gr_report_result rres;
    if (gr_report_make_dir(outdir, &err) != GR_OK) goto fail;
    if (snprintf(path, sizeof path, "%s/reference.exr", outdir) >= (int)sizeof path) {
        gr_fail(&err, GR_E_USAGE, "%s: output directory name too long", outdir);
        goto fail;
    }
    if (gr_exr_write(path, ro.img, &ro.meta, &err) != GR_OK) goto fail;
    snprintf(path, sizeof path, "%s/shafts.exr", outdir); /* no longer than reference.exr */
    if (gr_exr_write(path, test, &smeta, &err) != GR_OK) goto fail;
    if (gr_report_write(outdir, &in, &rres, &err) != GR_OK) goto fail;
    if (!quiet && !rres.labelled)
        fprintf(stderr, "godrays run: note: no font for OpenImageIO's text: summary.png is unlabelled\n");
    if (!quiet && rres.charts == 0) fprintf(stderr, "godrays run: note: charts not drawn (see index.html)\n");
    print_summary(outdir, scene, &m, &ro, t_ref, t_shafts, &smeta);
    goto done;
fail:
    rc = gr_cli_report(cmd, &err);
done:
    gr_image_destroy(ro.img);
    gr_meta_free(&ro.meta);
    gr_image_destroy(test);
    gr_meta_free(&smeta);
    free(scene);
    return rc;
}
