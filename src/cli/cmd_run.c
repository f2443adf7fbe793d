/* godrays run SCENE [-o DIR] [--techniques a,b]: the main job. Renders every chosen real-time
 * technique (default: every registered one) and the ground truth (or reuses a cached one),
 * compares each against it (reference-stderr aware, raw and after the best scale fit), writes
 * the report folder with its leaderboard (src/report/report.h) and prints a short table. */
#include "cli/cli.h"
#include "cli/args.h"
#include "cli/render.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "compare/metrics.h"
#include "compare/structure.h"
#include "image/exr.h"
#include "realtime/technique.h"
#include "reference/integrator.h"
#include "report/cache.h"
#include "report/profile.h"
#include "report/report.h"
#include "report/sequence.h"
#include "scene/scene.h"
#include "tune/objective.h"
#include "tune/session.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays run SCENE [-o DIR] [--techniques A,B] [--frames A:B:S | --times T,..] [options]\n"
            "\n"
            "The main job: renders SCENE with every real-time technique (OpenGL; `godrays techniques`\n"
            "lists them) and as ground truth (Embree single scattering, with error bars), compares\n"
            "each technique against the one ground truth and writes a report with a leaderboard:\n"
            "  DIR/index.html    the leaderboard (image, errors with and without the scale fit, GPU\n"
            "                    and wall time per technique), then each technique's images beside the\n"
            "                    reference, metrics, charts, timings; the scene and settings\n"
            "  DIR/summary.png   labelled contact sheet, one row per technique\n"
            "  DIR/metrics.json  every number, one entry per technique\n"
            "  DIR/reference.exr, DIR/TECHNIQUE.exr  the linear images (for godrays compare)\n"
            "index.html links DIR/sweep, DIR/tune and DIR/pareto (godrays sweep, tune, pareto) when\n"
            "they exist, and gives the command that makes each one that does not.\n"
            "The ground truth is cached (key: the scene's content and the reference settings) and\n"
            "reused by later runs. How to read the report: docs/report.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR     report folder (default: out/SCENE_NAME)\n"
            "  --techniques A,B     the techniques to compare (default: every registered one)\n"
            "  --technique-dir DIR  add the user technique in DIR (its manifest.json; repeatable)\n"
            "  --time-limit S       give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --set KEY=VALUE      override a scene value before validation, e.g. TECHNIQUE.KEY=V,\n"
            "                       reference.spp=4, medium.g=0.9 (repeatable)\n"
            "  --size WxH           image size (same as --set camera.width=W --set camera.height=H)\n"
            "  --frames A:B:S       a sequence: frames A, A+S, ... B of the animated water (at --fps,\n"
            "                       from the scene's water.time_s): every technique and the ground truth\n"
            "                       per frame, and DIR/sequence/ (index.html: a chart per metric over\n"
            "                       time, temporal metrics: flicker, frame-difference error, beam drift;\n"
            "                       an animated GIF per technique); index.html compares the first frame\n"
            "  --times T1,T2,...    a sequence at these water times (s)\n"
            "  --fps F              frames per second of --frames (default 30)\n"
            "  --no-cache           render the ground truth even if a cached one exists, and do not\n"
            "                       store it\n"
            "  -q, --quiet          no progress bar or step messages (the summary table is printed)\n"
            "  -h, --help           this help\n"
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

/* The command line, each argument shell-quoted where it needs it, for the report. */
static void command_line(int argc, char **argv, gr_strbuf *b)
{
    gr_sb_puts(b, "godrays");
    for (int i = 0; i < argc; i++) {
        gr_sb_puts(b, " ");
        gr_sb_shell_word(b, argv[i]);
    }
}

/* One render of technique cls in context gl, as `godrays render` does. */
static gr_status render_technique(const gr_technique_class *cls, gr_gl *gl, const gr_scene *scene, gr_image **img,
                                  gr_metadata *meta, gr_error *err)
{
    gr_technique *r = NULL;
    gr_status st = gr_technique_create(cls, gl, NULL, &r, err);
    if (st != GR_OK) return st;
    *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    if (!*img) {
        gr_technique_destroy(r);
        return gr_fail(err, GR_E_NOMEM, "out of memory for a %d x %d image", scene->camera.width, scene->camera.height);
    }
    gr_technique_stats stats;
    st = gr_technique_render(r, scene, NULL, *img, &stats, err);
    if (st == GR_OK) st = gr_technique_metadata(r, scene, NULL, &stats, meta, err);
    gr_technique_destroy(r);
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
            fprintf(stderr, "godrays run: warning: %s\n", ro->note); /* warnings even with -q */
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
                fprintf(stderr, "godrays run: warning: cache entry %s\n", why); /* even with -q */
            }
        }
    }
    if (!quiet)
        fprintf(stderr, "godrays run: rendering the ground truth (%d x %d; %s)...\n", scene->camera.width,
                scene->camera.height, ro->cache_on ? "cached for later runs" : "not cached");
    gr_ref_options opt;
    gr_ref_options_default(&opt);
    opt.progress = !quiet;
    gr_ref_result res;
    st = gr_cli_render_reference(scene, &opt, &res, NULL, err);
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
            fprintf(stderr, "godrays run: warning: %s\n", ro->note); /* warnings even with -q */
            ro->cache_on = 0;
        }
    }
    return GR_OK;
}

static double rel(const gr_channel_metrics *y) { return y->ref_mean != 0 ? y->rmse / fabs(y->ref_mean) : NAN; }

static void print_summary(const char *dir, const gr_scene *scene, const gr_report_technique *ts, int nt,
                          const int *order, const ref_out *ro, double t_ref)
{
    printf("scene '%s' (%d x %d): ground truth %.1f s (%s), %d real-time technique%s\n", scene->name,
           scene->camera.width, scene->camera.height, t_ref, ro->cached ? "from the cache" : "rendered", nt,
           nt == 1 ? "" : "s");
    for (int r = 0; r < nt; r++) {
        const gr_report_technique *t = &ts[order[r]];
        const gr_metrics *m = t->metrics;
        const gr_metrics_set *raw = &m->raw, *fit = m->have_fit ? &m->fit : &m->raw;
        const gr_channel_metrics *yr = &raw->ch[GR_MCH_Y], *yf = &fit->ch[GR_MCH_Y];
        const gr_meta_item *g = gr_meta_get(t->meta, "godrays:gpu_ms"), *w = gr_meta_get(t->meta, "godrays:wall_ms");
        printf("\n#%d %s: %.2f s in this run (GPU ", r + 1, t->name, t->seconds);
        if (g && g->type != GR_META_STRING && g->num >= 0) printf("%.2f ms", g->num);
        else printf("n/a");
        printf(", wall %.2f ms per render)\n", w && w->type != GR_META_STRING ? w->num : NAN);
        printf("luminance Y                  as rendered   x a (a = %.4g)\n", fit->scale);
#define ROW(label, a, b) printf("  %-24s %12.4g %12.4g\n", label, (double)(a), (double)(b))
        ROW("bias (mean a t - r)", yr->bias, yf->bias);
        ROW("RMSE", yr->rmse, yf->rmse);
        ROW("RMSE / mean reference", rel(yr), rel(yf));
        ROW("relative MSE", yr->rel_mse, yf->rel_mse);
        ROW("PSNR dB (ref peak)", yr->psnr_ref_db, yf->psnr_ref_db);
        ROW("SSIM", raw->ssim_y, fit->ssim_y);
        ROW("RMSE, blur sigma 16 px", yr->rmse_blur[GR_METRICS_NSCALES - 1], yf->rmse_blur[GR_METRICS_NSCALES - 1]);
#undef ROW
        printf("scored %lld of %lld pixels (%lld not scored: reference rel. std. error > %g)", m->n_scored,
               m->n_pixels, m->n_stderr_excluded, m->stderr_bound);
        if (m->have_stderr && yf->n_samples > 0)
            printf("; after the fit %.1f %% of Y differences are within 2 std. errors",
                   100.0 * (double)yf->n_not_significant / (double)yf->n_samples);
        printf("\n");
    }
    printf("\nleaderboard (rel. RMSE of Y after the scale fit):\n");
    printf("  %-4s %-24s %12s %12s %10s %10s %10s\n", "rank", "technique", "rel. RMSE", "after fit", "SSIM fit",
           "GPU ms", "wall ms");
    for (int r = 0; r < nt; r++) {
        const gr_report_technique *t = &ts[order[r]];
        const gr_metrics *m = t->metrics;
        const gr_metrics_set *fit = m->have_fit ? &m->fit : &m->raw;
        const gr_meta_item *g = gr_meta_get(t->meta, "godrays:gpu_ms"), *w = gr_meta_get(t->meta, "godrays:wall_ms");
        printf("  %-4d %-24s %12.4g %12.4g %10.4f %10.3f %10.3f\n", r + 1, t->name, rel(&m->raw.ch[GR_MCH_Y]),
               rel(&fit->ch[GR_MCH_Y]), fit->ssim_y, g && g->type != GR_META_STRING && g->num >= 0 ? g->num : NAN,
               w && w->type != GR_META_STRING ? w->num : NAN);
    }
    printf("report: %s/index.html (also summary.png, metrics.json)\n", dir);
    if (nt > 0 && ts[0].metrics->raw.ch[GR_MCH_Y].ref_mean == 0.0) /* the ground truth is >= 0: zero mean = zero everywhere scored */
        fprintf(stderr, "godrays run: warning: the ground truth is zero everywhere scored: the metrics say nothing "
                "(camera inside an occluder, no scattering, or no light reaching the view?)\n");
}

/* Issue 31: a technique that fails (a user shader over its time limit, a GL error, a memory
 * refusal) is left out of the comparison instead of ending the run: a warning now, a row in
 * the printed summary, exit 1 at the end. Its image and metadata are freed, cls[k] is removed
 * (the entries after k are not rendered yet), and a context abandoned after a time limit is
 * replaced by a new one. Ctrl-C still ends the run. */
typedef struct run_failures {
    int n;
    const char *name[GR_REPORT_MAX_TECHNIQUES];
    char msg[GR_REPORT_MAX_TECHNIQUES][GR_ERROR_MSG_MAX];
} run_failures;

static gr_status drop_failed(const gr_technique_class **cls, int *nt, int k, gr_image **img, gr_metadata *meta,
                             gr_gl **gl, run_failures *f, gr_error *err)
{
    if (err->status == GR_E_INTERRUPTED) return err->status;
    fprintf(stderr, "godrays run: warning: %s failed, left out of the comparison: %s\n", cls[k]->name, err->msg);
    f->name[f->n] = cls[k]->name;
    snprintf(f->msg[f->n++], GR_ERROR_MSG_MAX, "%s", err->msg);
    gr_image_destroy(*img);
    *img = NULL;
    gr_meta_free(meta);
    gr_meta_init(meta);
    memmove(&cls[k], &cls[k + 1], (size_t)(*nt - k - 1) * sizeof *cls);
    (*nt)--;
    if (!gr_gl_abandoned(*gl)) return GR_OK;
    gr_gl_destroy(*gl);
    *gl = NULL;
    return gr_gl_create(NULL, gl, err);
}

static int print_failures(const run_failures *f)
{
    if (f->n == 0) return 0;
    printf("\nfailed, left out of the comparison:\n");
    for (int i = 0; i < f->n; i++) printf("  %-4s %-24s %s\n", "-", f->name[i], f->msg[i]);
    return 1;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int run_with(gr_args *args)
{
    const int argc = args->argc;
    char **argv = args->argv;
    const char *cmd = "run";
    const char *outdir = NULL, *tech_list = NULL;
    const char *frames_spec = NULL, *times_spec = NULL, *fps_spec = NULL;
    int quiet = 0, use_cache = 1, rc = 0, taken = 0;
    for (; args->i < argc && !rc; args->i++) {
        const char *a = argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--no-cache")) {
            use_cache = 0;
        } else if (!strcmp(a, "--techniques")) {
            rc = gr_args_value(args, &tech_list);
        } else if (!strcmp(a, "--frames")) {
            rc = gr_args_value(args, &frames_spec);
        } else if (!strcmp(a, "--times")) {
            rc = gr_args_value(args, &times_spec);
        } else if (!strcmp(a, "--fps")) {
            rc = gr_args_value(args, &fps_spec);
        } else if ((rc = gr_args_take_common(args, &outdir, NULL, &taken)) == 0 && !taken) {
            rc = gr_args_take_scene(args);
        }
    }
    if (rc || (rc = gr_args_need_scene(args)) != 0) return rc;
    /* user techniques before the scene, whose sections they add */
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    const gr_technique_class *cls[GR_REPORT_MAX_TECHNIQUES];
    int nt = 0;
    gr_error err = {GR_OK, ""};
    if (gr_technique_parse_list("--techniques", tech_list, cls, GR_REPORT_MAX_TECHNIQUES, &nt, &err) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", err.msg);
    if (nt == 0) return gr_cli_usage_error(cmd, "no real-time technique to compare");
    /* a sequence: --frames or --times (report/sequence.h) */
    double fps = 30.0, times[GR_SEQUENCE_MAX_FRAMES];
    long frame_no[GR_SEQUENCE_MAX_FRAMES];
    int n_times = 0;
    if (frames_spec && times_spec) return gr_cli_usage_error(cmd, "--frames and --times: give one of them");
    if (fps_spec) {
        char *end = NULL;
        fps = strtod(fps_spec, &end);
        if (end == fps_spec || *end || !isfinite(fps) || !(fps > 0))
            return gr_cli_usage_error(cmd, "--fps %s: expected a number > 0", fps_spec);
    }
    if (frames_spec &&
        gr_tune_parse_frames("--frames", frames_spec, fps, times, GR_SEQUENCE_MAX_FRAMES, &n_times, &err) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", err.msg);
    if (times_spec && gr_tune_parse_times("--times", times_spec, times, GR_SEQUENCE_MAX_FRAMES, &n_times, &err) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", err.msg);
    if ((frames_spec || times_spec) && n_times < 2)
        return gr_cli_usage_error(cmd, "%s %s: one frame; a sequence needs two or more", frames_spec ? "--frames" : "--times",
                                  frames_spec ? frames_spec : times_spec);
    for (int i = 0; i < n_times; i++) frame_no[i] = lround(times[i] * fps);
    const int nf = n_times > 0 ? n_times : 1;

    gr_scene *scene = NULL, *cases = NULL;
    float *angles = NULL;
    gr_image **seq_test = NULL; /* seq_test[k * nf + i], i >= 1 (frame 0: test[k]) */
    ref_out *seq_ref = NULL;    /* frames >= 1 (frame 0: ro) */
    char *seq_json = NULL;
    gr_sequence_result sres;
    memset(&sres, 0, sizeof sres);
    gr_gl *gl = NULL;
    run_failures fails = {0};
    gr_image *test[GR_REPORT_MAX_TECHNIQUES] = {NULL};
    gr_metadata smeta[GR_REPORT_MAX_TECHNIQUES];
    gr_metrics *mets = calloc((size_t)nt, sizeof *mets);
    gr_report_technique ts[GR_REPORT_MAX_TECHNIQUES];
    char exr_names[GR_REPORT_MAX_TECHNIQUES][48];
    memset(ts, 0, sizeof ts);
    for (int k = 0; k < GR_REPORT_MAX_TECHNIQUES; k++) gr_meta_init(&smeta[k]);
    ref_out ro;
    memset(&ro, 0, sizeof ro);
    gr_meta_init(&ro.meta);
    gr_strbuf cmdline, words;
    gr_sb_init(&cmdline);
    gr_sb_init(&words);
    char dirbuf[4096], path[4300];
    if (!mets) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = gr_args_load_scene(args, &scene)) != 0) goto done;
    if (n_times > 0) { /* each frame's scene: the water at its time (--frames: from the scene's time) */
        cases = calloc((size_t)nf, sizeof *cases);
        seq_test = calloc((size_t)(nf * nt), sizeof *seq_test);
        seq_ref = calloc((size_t)nf, sizeof *seq_ref);
        if (!cases || !seq_test || !seq_ref) {
            gr_fail(&err, GR_E_NOMEM, "out of memory");
            goto fail;
        }
        for (int i = 0; i < nf; i++) {
            gr_meta_init(&seq_ref[i].meta);
            const double tw = times[i] + (frames_spec ? scene->water.time_s : 0.0);
            if (gr_tune_make_case(scene, tw, NULL, &cases[i], &err) != GR_OK) {
                gr_error_prefix(&err, "%s: frame %d", frames_spec ? "--frames" : "--times", i);
                goto fail;
            }
            times[i] = tw;
        }
    }
    const gr_scene *scene0 = cases ? &cases[0] : scene; /* the frame index.html compares */
    /* Bad settings are bad input (exit 2) before any slow or GL work. */
    for (int k = 0; k < nt; k++)
        if (gr_technique_check(cls[k], gr_technique_scene_settings(cls[k], scene), &err) != GR_OK) goto fail;
    /* The ground truth takes minutes: a folder that cannot be made is refused before it. */
    if ((rc = gr_args_output_dir(args, scene, outdir, NULL, dirbuf, sizeof dirbuf, &outdir)) != 0) goto done;
    command_line(argc, argv, &cmdline);
    gr_args_scene_words(args, &words);
    if (gr_sb_status(&cmdline, "the command line", &err) != GR_OK || gr_sb_status(&words, "the command line", &err) != GR_OK)
        goto fail;

    /* The real-time side first: it takes seconds, and a GL failure should not cost the user
     * a two-minute ground truth first. One context, one instance per technique. */
    if (gr_gl_create(NULL, &gl, &err) != GR_OK) goto fail;
    for (int k = 0; k < nt; k++) {
        if (!quiet) fprintf(stderr, "godrays run: rendering %s...\n", cls[k]->name);
        double t = now_s();
        int failed = render_technique(cls[k], gl, scene0, &test[k], &smeta[k], &err) != GR_OK;
        for (int i = 1; i < nf && !failed; i++) {
            gr_metadata scratch;
            gr_meta_init(&scratch);
            gr_status rst = render_technique(cls[k], gl, &cases[i], &seq_test[k * nf + i], &scratch, &err);
            gr_meta_free(&scratch);
            if (rst != GR_OK) {
                gr_error_prefix(&err, "frame %d (t = %g s)", i, times[i]);
                failed = 1;
            }
        }
        if (failed) {
            for (int i = 1; i < nf; i++) {
                gr_image_destroy(seq_test[k * nf + i]);
                seq_test[k * nf + i] = NULL;
            }
            if (drop_failed(cls, &nt, k, &test[k], &smeta[k], &gl, &fails, &err) != GR_OK) goto fail;
            k--;
            continue;
        }
        ts[k].seconds = now_s() - t;
        ts[k].name = cls[k]->name;
        ts[k].description = cls[k]->description;
        ts[k].test = test[k];
        ts[k].meta = &smeta[k];
        snprintf(exr_names[k], sizeof exr_names[k], "%s.exr", cls[k]->name);
        ts[k].exr = exr_names[k];
        if (nf > 1) seq_test[k * nf] = test[k];
    }
    if (nt == 0) goto fail; /* every technique failed: the last one's message */
    gr_gl_destroy(gl);
    gl = NULL;

    double t = now_s();
    if (nf > 1 && !quiet) fprintf(stderr, "godrays run: frame 1 of %d (t = %g s)\n", nf, times[0]);
    if (get_reference(scene0, use_cache, quiet, &ro, &err) != GR_OK) goto fail;
    const double t_ref = now_s() - t;
    for (int i = 1; i < nf; i++) {
        if (!quiet) fprintf(stderr, "godrays run: frame %d of %d (t = %g s)\n", i + 1, nf, times[i]);
        if (get_reference(&cases[i], use_cache, quiet, &seq_ref[i], &err) != GR_OK) {
            gr_error_prefix(&err, "frame %d (t = %g s)", i, times[i]);
            goto fail;
        }
    }
    const double t_refs = now_s() - t;

    if (!quiet) fprintf(stderr, "godrays run: comparing...\n");
    t = now_s();
    const gr_meta_item *dof = gr_meta_get(&ro.meta, "godrays:stderr_dof"); /* Student t for significance */
    /* beam structure around the refracted sun's vanishing point, de-glowed by the angle to
     * the sun (docs/metrics.md), in every technique's metric sets; skipped when the beams have
     * no finite vanishing point (parallel to the image plane) */
    gr_structure_options so = {.radial_bin = scene->camera.fov_deg / scene->camera.height};
    int with_structure = 0;
    {
        gr_error e2 = {GR_OK, ""};
        angles = malloc((size_t)scene->camera.width * (size_t)scene->camera.height * sizeof(float));
        if (!angles) {
            gr_fail(&err, GR_E_NOMEM, "out of memory for the structure metrics");
            goto fail;
        }
        if (gr_structure_scene_vp(scene, scene->camera.width, scene->camera.height, &so.vp_x, &so.vp_y, &e2) == GR_OK) {
            double dir[3];
            gr_profile_sun_view_dir(scene, dir);
            gr_profile_angles(&scene->camera, dir, angles);
            so.radial = angles;
            with_structure = 1;
        }
    }
    for (int k = 0; k < nt; k++) {
        gr_metrics_options mopt = {0};
        mopt.fit_scale = 1; /* a technique's intensity is an arbitrary factor (seed 000) */
        if (with_structure) mopt.structure = &so;
        if (dof && dof->type != GR_META_STRING && dof->num >= 1.0) mopt.stderr_dof = (int)dof->num;
        if (gr_metrics_compute(ro.img, test[k], &mopt, &mets[k], &err) != GR_OK) goto fail;
        ts[k].metrics = &mets[k];
    }
    const double t_cmp = now_s() - t;

    /* The report links the EXRs; they are written first so that a finished index.html never
     * points at a missing file. */
    if (!quiet) fprintf(stderr, "godrays run: writing the report...\n");
    if (nf > 1) {
        if (!quiet) fprintf(stderr, "godrays run: the sequence (%d frames)...\n", nf);
        const gr_scene *fs[GR_SEQUENCE_MAX_FRAMES];
        const gr_image *frefs[GR_SEQUENCE_MAX_FRAMES];
        const char *names[GR_REPORT_MAX_TECHNIQUES];
        for (int i = 0; i < nf; i++) {
            fs[i] = &cases[i];
            frefs[i] = i ? seq_ref[i].img : ro.img;
        }
        for (int k = 0; k < nt; k++) names[k] = cls[k]->name;
        gr_sequence_input sin = {.n_frames = nf, .times = times, .frame_numbers = frames_spec ? frame_no : NULL,
                                 .scenes = fs, .refs = frefs, .n_techniques = nt, .names = names,
                                 .tests = (const gr_image *const *)seq_test, .up_href = "../index.html",
                                 .command_line = gr_sb_str(&cmdline)};
        if (snprintf(path, sizeof path, "%s/sequence", outdir) >= (int)sizeof path - 48) {
            gr_fail(&err, GR_E_USAGE, "%s: output directory name too long", outdir);
            goto fail;
        }
        if (gr_sequence_write(path, &sin, &seq_json, &sres, &err) != GR_OK) goto fail;
    }
    gr_report_input in = {.scene = scene0, .ref = ro.img, .ref_meta = &ro.meta, .n_techniques = nt, .techniques = ts,
                          .command_line = gr_sb_str(&cmdline), .scene_words = gr_sb_str(&words),
                          .ref_cached = ro.cached, .ref_cache_path = ro.cache_on ? ro.cache_path : NULL,
                          .ref_cache_note = ro.note[0] ? ro.note : NULL, .ref_seconds = t_ref,
                          .compare_seconds = t_cmp, .ref_exr = "reference.exr", .sequence_json = seq_json,
                          .sequence_href = seq_json ? "sequence/index.html" : NULL};
    gr_report_result rres;
    if (gr_report_make_dir(outdir, &err) != GR_OK) goto fail;
    if (snprintf(path, sizeof path, "%s/reference.exr", outdir) >= (int)sizeof path - 48) {
        gr_fail(&err, GR_E_USAGE, "%s: output directory name too long", outdir);
        goto fail;
    }
    if (gr_exr_write(path, ro.img, &ro.meta, &err) != GR_OK) goto fail;
    for (int k = 0; k < nt; k++) {
        snprintf(path, sizeof path, "%s/%s", outdir, exr_names[k]);
        if (gr_exr_write(path, test[k], &smeta[k], &err) != GR_OK) goto fail;
    }
    if (gr_report_write(outdir, &in, &rres, &err) != GR_OK) goto fail;
    if (!quiet && !rres.labelled)
        fprintf(stderr, "godrays run: note: no font for OpenImageIO's text: summary.png is unlabelled\n");
    if (!quiet && rres.charts == 0) fprintf(stderr, "godrays run: note: charts not drawn (see index.html)\n");
    print_summary(outdir, scene0, ts, nt, rres.order, &ro, t_ref);
    rc = print_failures(&fails);
    if (nf > 1) {
        printf("\nsequence: %d frames, t = %g .. %g s; ground truths %.1f s in all\n", nf, times[0], times[nf - 1],
               t_refs);
        printf("  %-24s %10s %14s %12s %14s\n", "technique", "a", "diff. error", "flicker", "drift err deg");
        for (int k = 0; k < nt; k++)
            printf("  %-24s %10.4g %14.4g %12.4g %14.3g\n", cls[k]->name, sres.scale[k], sres.rel_diff_rmse[k],
                   sres.flicker_ratio[k], sres.drift_err_deg[k]);
        printf("sequence report: %s/sequence/index.html (%d charts, %d animations)\n", outdir, sres.charts,
               sres.animations);
    }
    goto done;
fail:
    rc = gr_cli_report(cmd, &err);
done:
    free(angles);
    gr_gl_destroy(gl);
    gr_image_destroy(ro.img);
    gr_meta_free(&ro.meta);
    for (int i = 1; seq_ref && i < nf; i++) {
        gr_image_destroy(seq_ref[i].img);
        gr_meta_free(&seq_ref[i].meta);
    }
    for (int k = 0; seq_test && k < nt; k++)
        for (int i = 1; i < nf; i++) gr_image_destroy(seq_test[k * nf + i]);
    free(seq_test);
    free(seq_ref);
    free(cases);
    free(seq_json);
    for (int k = 0; k < GR_REPORT_MAX_TECHNIQUES; k++) {
        gr_image_destroy(test[k]);
        gr_meta_free(&smeta[k]);
    }
    free(mets);
    free(scene);
    gr_sb_free(&cmdline);
    gr_sb_free(&words);
    return rc;
}

int cmd_run(int argc, char **argv)
{
    return gr_args_main("run", argc, argv, run_with);
}
