/* godrays pareto SCENE: speed against error (src/tune/pareto.h): the ground truth at increasing
 * quality against a high-quality one, and every chosen real-time technique over the settings
 * of its class's ladder (gr_technique_class.ladder), one family and one front each. */
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "compare/metrics.h"
#include "realtime/technique.h"
#include "report/report.h"
#include "tune/page.h"
#include "tune/pareto.h"
#include "tune/session.h"
#include "tune/truth.h"

#define MAX_POINTS 256

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays pareto SCENE [-o DIR] [options]\n"
            "\n"
            "Speed against error. Renders a high-quality ground truth (2x the scene's passes\n"
            "(sun_samples), 2x its march steps, 1.5x its surface resolution, another seed; cached),\n"
            "then\n"
            "  - the ground truth at increasing quality (q0..q3, q3 = the scene's reference settings,\n"
            "    the others fractions of its passes, steps and surface resolution; each timed,\n"
            "    never cached), error against the high-quality one;\n"
            "  - each real-time technique over its own speed/quality ladder (settings such as a grid\n"
            "    or target size; docs/tuning.md), median time of --repeat renders in one context,\n"
            "    error after the best scale fit.\n"
            "Error = RMSE of luminance Y / mean Y of the high-quality ground truth. The techniques\n"
            "are ranked by the wall time of a render with readback on llvmpipe, by the GPU time of\n"
            "their GL passes on a hardware GPU (both are listed). Writes DIR/pareto.csv and\n"
            "DIR/pareto.png (every family and its Pareto front, one colour each). docs/tuning.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR   folder (default: out/SCENE_NAME/pareto)\n"
            "  --size WxH         image size (default 320x180: the high-quality ground truth costs\n"
            "                     about 4x a default-quality one)\n"
            "  --set KEY=VALUE    override a scene value (repeatable)\n"
            "  --techniques A,B   the techniques to place (default: every registered one)\n"
            "  --technique NAME   one technique only (same as --techniques NAME)\n"
            "  --technique-dir DIR  add the user technique in DIR (repeatable)\n"
            "  --time-limit S     give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --quick            fewer points (q0, q1, the quick levels of each ladder), for tests\n"
            "  --repeat R         renders per setting; time = median (default 5)\n"
            "  --no-cache         render the high-quality ground truth even if cached\n"
            "  --gl-platform P    auto, surfaceless or device\n"
            "  -q, --quiet        no progress messages\n"
            "  -h, --help         this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage or bad scene.\n");
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Relative RMSE of Y: RMSE / mean reference Y (0 mean: the RMSE itself). */
static double rel_rmse(const gr_metrics_set *set)
{
    const gr_channel_metrics *y = &set->ch[GR_MCH_Y];
    return y->ref_mean > 0 ? y->rmse / y->ref_mean : y->rmse;
}

/* Reference quality ladder (docs/tuning.md), relative to the scene's own reference settings
 * (q3): each level about twice the work of the one before; hq = 2x the passes, 2x the march
 * steps and 1.5x the surface resolution of q3. */
typedef struct ref_level {
    char name[32];
    int sun_samples, batches, steps, surface_res, spp;
} ref_level;
enum { N_LEVELS = 4 };

static int at_least(int v, int lo) { return v > lo ? v : lo; }

/* Level k in 0..N_LEVELS-1 from the scene's settings; k = N_LEVELS gives hq. */
static ref_level make_level(const gr_reference_settings *b, int k)
{
    /* fractions of q3's passes, steps and surface resolution for q0, q1, q2, q3 */
    static const double pass_f[] = {0.25, 0.25, 0.5, 1.0}, step_f[] = {0.25, 0.5, 0.75, 1.0}, res_f[] = {0.25, 0.5, 0.75, 1.0};
    ref_level l;
    l.spp = b->spp;
    if (k >= N_LEVELS) {
        snprintf(l.name, sizeof l.name, "hq");
        l.sun_samples = 2 * b->sun_samples;
        l.batches = b->batches;
        l.steps = 2 * b->steps;
        l.surface_res = b->surface_res + b->surface_res / 2;
        return l;
    }
    snprintf(l.name, sizeof l.name, k == N_LEVELS - 1 ? "q%d (scene's settings)" : "q%d", k);
    l.sun_samples = at_least((int)(pass_f[k] * b->sun_samples + 0.5), 2);
    l.batches = at_least(b->batches < l.sun_samples ? b->batches : l.sun_samples, 2);
    l.steps = at_least((int)(step_f[k] * b->steps + 0.5), 1);
    l.surface_res = at_least((int)(res_f[k] * b->surface_res + 0.5), 2);
    return l;
}

static void set_level(gr_scene *s, const ref_level *l)
{
    s->reference.sun_samples = l->sun_samples;
    s->reference.batches = l->batches;
    s->reference.steps = l->steps;
    s->reference.surface_res = l->surface_res;
    s->reference.spp = l->spp;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int pareto_with(gr_args *args)
{
    const char *cmd = "pareto", *outopt = NULL;
    const int argc = args->argc;
    char **argv = args->argv;
    int quiet = 0, quick = 0, use_cache = 1, rc = 0, taken = 0;
    const char *tech_list = NULL, *tech_flag = "--techniques";
    long repeat = 5;
    gr_gl_platform platform = GR_GL_AUTO;
    args->size_example = "320x180";
    for (; args->i < argc && !rc; args->i++) {
        const char *a = argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--quick")) {
            quick = 1;
        } else if (!strcmp(a, "--techniques") || !strcmp(a, "--technique")) {
            tech_flag = a;
            if ((rc = gr_args_value(args, &tech_list)) != 0) break;
            if (!strcmp(a, "--technique") && strchr(tech_list, ','))
                rc = gr_cli_usage_error(cmd, "--technique %s: one technique (use --techniques for a list)", tech_list);
        } else if (!strcmp(a, "--no-cache")) {
            use_cache = 0;
        } else if (!strcmp(a, "--repeat")) {
            const char *v;
            char *end = NULL;
            if ((rc = gr_args_value(args, &v)) != 0) break;
            errno = 0;
            repeat = strtol(v, &end, 10);
            if (errno || end == v || *end || repeat < 1 || repeat > 1000)
                rc = gr_cli_usage_error(cmd, "--repeat %s: expected an integer in [1, 1000]", v);
        } else if ((rc = gr_args_take_common(args, &outopt, &platform, &taken)) == 0 && !taken) {
            rc = gr_args_take_scene(args);
        }
    }
    if (rc || (rc = gr_args_need_scene(args)) != 0) return rc;
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    const gr_technique_class *techs[GR_TECH_MAX];
    int n_techs = 0;
    {
        gr_error lerr = {GR_OK, ""};
        if (gr_technique_parse_list(tech_flag, tech_list, techs, GR_TECH_MAX, &n_techs, &lerr) != GR_OK)
            return gr_cli_usage_error(cmd, "%s", lerr.msg);
    }
    /* the default size after every override, so that it wins over --set camera.width/height */
    if (!args->have_size && (rc = gr_args_add_set(args, "camera.width=320")) != 0) return rc;
    if (!args->have_size && (rc = gr_args_add_set(args, "camera.height=180")) != 0) return rc;

    gr_error err = {GR_OK, ""};
    gr_scene *scene = NULL, *work = malloc(sizeof *work);
    gr_image *truth = NULL, *img = NULL;
    gr_gl *gl = NULL;
    gr_technique *r = NULL;
    gr_pareto_point *pts = calloc(MAX_POINTS, sizeof *pts);
    int n = 0;
    char dirbuf[4096], path[4300];
    const char *outdir = NULL;
    if (!work || !pts) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        goto fail;
    }
    if ((rc = gr_args_load_scene(args, &scene)) != 0) goto done;
    for (int k = 0; k < n_techs; k++)
        if (gr_technique_check(techs[k], gr_technique_scene_settings(techs[k], scene), &err) != GR_OK) goto fail;
    /* The ground truths take minutes: a folder that cannot be made is refused before them. */
    if ((rc = gr_args_output_dir(args, scene, outopt, "pareto", dirbuf, sizeof dirbuf, &outdir)) != 0) goto done;
    gr_gl_options glo;
    memset(&glo, 0, sizeof glo);
    glo.platform = platform;
    if (gr_gl_create(&glo, &gl, &err) != GR_OK) goto fail;

    /* the high-quality ground truth, with its own seed so that no ladder level shares its
     * random numbers (a shared seed would make the lower levels look better than they are) */
    memcpy(work, scene, sizeof *work);
    const ref_level hq = make_level(&scene->reference, N_LEVELS);
    set_level(work, &hq);
    work->reference.seed = scene->reference.seed + 7919;
    if (gr_scene_refresh(work, &err) != GR_OK) goto fail;
    if (!quiet) fprintf(stderr, "godrays pareto: high-quality ground truth (%d x %d)...\n", work->camera.width,
                        work->camera.height);
    gr_truth_info ti;
    if (gr_truth_get(work, use_cache, !quiet, &truth, &ti, &err) != GR_OK) goto fail;
    if (!quiet && ti.cached) fprintf(stderr, "godrays pareto:   from the cache %s\n", ti.path);

    gr_metrics_options mo = {0};
    mo.skip_ssim = 1;
    mo.skip_blur = 1;
    gr_metrics m;
    /* ground truth ladder */
    int n_levels = quick ? 2 : N_LEVELS;
    for (int l = 0; l < n_levels; l++) {
        memcpy(work, scene, sizeof *work);
        const ref_level lv = make_level(&scene->reference, l);
        set_level(work, &lv);
        if (gr_scene_refresh(work, &err) != GR_OK) goto fail;
        if (!quiet) fprintf(stderr, "godrays pareto: ground truth %s...\n", lv.name);
        gr_image *ri = NULL;
        double secs = 0;
        if (gr_truth_render(work, !quiet, &ri, &secs, &err) != GR_OK) goto fail;
        /* no stderr exclusion: the HQ image is the reference, its own noise is tiny */
        gr_metrics_options ro = mo;
        ro.stderr_bound = INFINITY;
        gr_status st = gr_metrics_compute(truth, ri, &ro, &m, &err);
        gr_image_destroy(ri);
        if (st != GR_OK) goto fail;
        gr_pareto_point *p = &pts[n++];
        p->family = GR_PARETO_REFERENCE;
        snprintf(p->family_name, sizeof p->family_name, "reference");
        snprintf(p->label, sizeof p->label, "%s", lv.name);
        snprintf(p->settings, sizeof p->settings, "sun_samples=%d;batches=%d;steps=%d;surface_res=%d;spp=%d",
                 lv.sun_samples, lv.batches, lv.steps, lv.surface_res, lv.spp);
        p->time_s = secs;
        p->gpu_s = -1;
        p->cost_s = secs;
        p->error = rel_rmse(&m.raw);
    }

    /* each technique over the settings of its ladder, which trade speed for quality */
    img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    double *times = malloc((size_t)repeat * sizeof *times), *gpus = malloc((size_t)repeat * sizeof *gpus);
    if (!img || !times || !gpus) {
        free(times);
        free(gpus);
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        goto fail;
    }
    int gpu_any = 0;
    for (int k = 0; k < n_techs; k++) {
        const gr_technique_class *cls = techs[k];
        gr_technique_destroy(r);
        r = NULL;
        if (gr_technique_create(cls, gl, NULL, &r, &err) != GR_OK) {
            free(times);
            free(gpus);
            goto fail;
        }
        const int n_lv = cls->n_ladder > 0 ? cls->n_ladder : 1;
        for (int l = 0; l < n_lv; l++) {
            const char *lvs = cls->n_ladder > 0 ? cls->ladder[l].settings : "";
            if (quick && cls->n_ladder > 0 && !cls->ladder[l].quick) continue;
            if (n >= MAX_POINTS) break;
            gr_section_store s;
            memcpy(s.bytes, gr_technique_scene_settings(cls, scene), cls->settings_size);
            gr_technique_stats stats;
            /* warm-up render: buffers rebuilt for new sizes, shader JIT */
            gr_status st = gr_technique_apply_text(cls, s.bytes, lvs, &err);
            if (st == GR_OK) st = gr_technique_render(r, scene, s.bytes, img, &stats, &err);
            for (long q = 0; st == GR_OK && q < repeat; q++) {
                st = gr_technique_render(r, scene, s.bytes, img, &stats, &err);
                times[q] = stats.wall_ms * 1e-3;
                double g = 0;
                int ok = stats.n_passes > 0;
                for (int pp = 0; pp < stats.n_passes; pp++) {
                    if (stats.gpu_ns[pp] < 0) ok = 0;
                    else g += (double)stats.gpu_ns[pp] * 1e-9;
                }
                gpus[q] = ok ? g : -1;
            }
            if (st == GR_OK) {
                gr_metrics_options fo = mo;
                fo.fit_scale = 1;
                fo.stderr_bound = INFINITY;
                st = gr_metrics_compute(truth, img, &fo, &m, &err);
            }
            if (st != GR_OK) {
                free(times);
                free(gpus);
                goto fail;
            }
            qsort(times, (size_t)repeat, sizeof *times, cmp_double);
            qsort(gpus, (size_t)repeat, sizeof *gpus, cmp_double);
            gr_pareto_point *p = &pts[n++];
            p->family = 1 + k;
            snprintf(p->family_name, sizeof p->family_name, "%s", cls->name);
            snprintf(p->label, sizeof p->label, "%s %s", cls->name, lvs[0] ? lvs : "(scene's settings)");
            for (char *c = p->label; *c; c++)
                if (*c == ',') *c = ' ';
            snprintf(p->settings, sizeof p->settings, "%s", lvs);
            for (char *c = p->settings; *c; c++)
                if (*c == ',') *c = ';';
            p->time_s = times[repeat / 2];
            p->gpu_s = gpus[repeat / 2];
            if (p->gpu_s >= 0) gpu_any = 1;
            p->error = rel_rmse(&m.fit);
            if (!quiet) fprintf(stderr, "godrays pareto: %s: %.2f ms, error %.4g\n", p->label, 1e3 * p->time_s, p->error);
        }
    }
    free(times);
    free(gpus);
    const char *glr = gr_gl_renderer(gl);
    int is_llvmpipe = glr && strstr(glr, "llvmpipe") != NULL;
    /* What the techniques cost: on a hardware GPU the GL pass timers (a render's wall time there
     * is mostly this harness's synchronous float readback: docs/benchmarks.md); on llvmpipe
     * the wall time (its timers see a deferred rasterizer). */
    int by_gpu = !is_llvmpipe && gpu_any;
    for (int i = 0; i < n; i++)
        if (pts[i].family != GR_PARETO_REFERENCE) pts[i].cost_s = by_gpu && pts[i].gpu_s >= 0 ? pts[i].gpu_s : pts[i].time_s;
    gr_pareto_mark_fronts(pts, n);

    char tlabel[128], title[256];
    snprintf(tlabel, sizeof tlabel, "%s", is_llvmpipe ? "llvmpipe wall time" : by_gpu ? "GPU time of the GL passes" : "GPU frame wall time");
    snprintf(title, sizeof title, "speed vs error, scene '%s' %dx%d (real time on %s)", scene->name, scene->camera.width,
             scene->camera.height, is_llvmpipe ? "llvmpipe, no GPU" : glr);
    if (gr_report_make_dir(outdir, &err) != GR_OK) goto fail;
    snprintf(path, sizeof path, "%s/pareto.csv", outdir);
    if (gr_pareto_write_csv(path, pts, n, &err) != GR_OK) goto fail;
    int drawn = 0;
    snprintf(path, sizeof path, "%s/pareto.png", outdir);
    if (gr_pareto_write_plot(path, pts, n, title, tlabel, &drawn, &err) != GR_OK) goto fail;

    gr_strbuf sum;
    gr_sb_init(&sum);
    gr_sb_printf(&sum, "scene '%s' (%d x %d); high-quality ground truth %.1f s (%s); real time on %s\n", scene->name,
           scene->camera.width, scene->camera.height, ti.seconds, ti.cached ? "from the cache" : "rendered", glr);
    gr_sb_printf(&sum, "%-16s %-50s %12s %12s %12s %6s\n", "family", "setting", "time ms", "GL timers ms", "rel. RMSE Y", "front");
    for (int i = 0; i < n; i++) {
        char g[32];
        if (pts[i].gpu_s >= 0) snprintf(g, sizeof g, "%.3f", 1e3 * pts[i].gpu_s);
        else snprintf(g, sizeof g, "n/a");
        gr_sb_printf(&sum, "%-16s %-50s %12.2f %12s %12.4g %6s\n", pts[i].family_name, pts[i].label,
               1e3 * pts[i].time_s, g, pts[i].error, pts[i].on_front ? "*" : "");
    }
    gr_sb_printf(&sum, "GL pass timers %s; the real-time techniques are ranked by %s\n", gpu_any ? "available" : "unavailable",
           is_llvmpipe ? "llvmpipe (CPU) wall times" : by_gpu ? "the GPU time of their GL passes" : "wall times on the GPU");
    gr_sb_printf(&sum, "written: %s/pareto.csv%s\n", outdir, drawn ? ", pareto.png" : " (no plot: charts need PLplot)");
    fputs(gr_sb_str(&sum), stdout);
    {
        gr_strbuf pg;
        gr_sb_init(&pg);
        gr_tune_page_begin(&pg, outdir, "godrays pareto: %s", scene->name);
        if (drawn) gr_tune_page_figure(&pg, "pareto.png", title);
        gr_status pst = gr_tune_page_write(&pg, gr_sb_str(&sum), "pareto.csv", outdir, &err);
        gr_sb_free(&sum);
        if (pst != GR_OK) goto fail;
    }
    goto done;
fail:
    rc = gr_cli_report(cmd, &err);
done:
    gr_image_destroy(img);
    gr_image_destroy(truth);
    gr_technique_destroy(r);
    gr_gl_destroy(gl);
    free(pts);
    free(work);
    free(scene);
    return rc;
}

int cmd_pareto(int argc, char **argv)
{
    return gr_args_main("pareto", argc, argv, pareto_with);
}
