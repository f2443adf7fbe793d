/* godrays run SCENE [-o DIR] [--techniques a,b]: the main job. Renders every chosen real-time
 * technique (default: every registered one) and the ground truth (or reuses a cached one),
 * compares each against it (reference-stderr aware, raw and after the best scale fit), writes
 * the report folder with its leaderboard (src/report/report.h) and prints a short table. */
#include "cli/cli.h"
#include "cli/args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "common/parallel.h"
#include "compare/baseline.h"
#include "compare/metrics.h"
#include "compare/registry.h"
#include "compare/structure.h"
#include "image/exr.h"
#include "realtime/technique.h"
#include "realtime/timing.h"
#include "reference/truth.h"
#include "report/leaderboard.h"
#include "report/profile.h"
#include "report/report.h"
#include "report/sequence.h"
#include "report/suite_board.h"
#include "common/outfile.h"
#include "scene/scene.h"
#include "suite/suite.h"
#include "tune/objective.h"
#include "tune/session.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays run SCENE [-o DIR] [--techniques A,B] [--frames A:B:S | --times T,..] [options]\n"
            "       godrays run --suite SUITE [-o DIR] [--techniques A,B] [--size WxH] [options]\n"
            "\n"
            "The main job: renders SCENE with every real-time technique (OpenGL; `godrays techniques`\n"
            "lists them) and as ground truth (Embree single scattering, with error bars), compares\n"
            "each technique against the one ground truth and writes a report with a leaderboard:\n"
            "  DIR/index.html    the leaderboard: techniques ranked by the verdict (the error after the\n"
            "                    scale fit + the beam-structure score, tune's default objective; its\n"
            "                    components beside it), among baselines (black, the constant image at\n"
            "                    the truth's mean, the truth blurred by 4 px), each technique's\n"
            "                    equivalent blur (the truth blurred by how much scores the same), a\n"
            "                    failed row per technique that failed; then each technique's images\n"
            "                    beside the reference, metrics, charts, timings; the scene and settings\n"
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
            "  --suite SUITE        every case of a view suite (docs/scene-format.md \"Suites\") instead of\n"
            "                       one scene: each case's report in DIR/cases/CASE/, and in DIR the suite\n"
            "                       leaderboard: per case the verdict of each technique, their mean over\n"
            "                       the cases and the worst case (index.html with thumbnails, metrics.json,\n"
            "                       the terminal); default DIR out/SUITE_NAME; --set/--size apply to every\n"
            "                       case, after its own overrides (docs/report.md \"Suites\")\n"
            "  --technique-dir DIR  add the user technique in DIR (its manifest.json; repeatable)\n"
            "  --time-limit S       give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --preset FILE        apply a preset's settings as overrides (docs/tuning.md \"Presets\")\n"
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
            "  --repeat N           time each technique as the median of N renders after a warm-up\n"
            "                       render, the spread (min-max) in metrics.json (default 1)\n"
            "  --fit MODE           the fit before the errors after the fit: scale (default: one\n"
            "                       least-squares factor), rgb (one per channel: a tint is fitted too)\n"
            "                       or none (docs/metrics.md, \"Scale fits\")\n"
            "  --save-targets       the report shows each technique's intermediate render targets as a\n"
            "                       strip (those that have them; off by default: pages stay small)\n"
            "  --no-cache           render the ground truth even if a cached one exists, and do not\n"
            "                       store it\n"
            "  --max-memory SIZE    refuse (exit 2) a ground truth estimated to need more (e.g. 8G;\n"
            "                       default $GODRAYS_MAX_MEMORY, else 80 %% of the memory)\n"
            "  -q, --quiet          no progress bar or step messages (the summary table is printed)\n"
            "  -h, --help           this help\n"
            "\n"
            "Cache directory: $GODRAYS_CACHE, else $XDG_CACHE_HOME/godrays or ~/.cache/godrays, else\n"
            "./.godrays-cache. Ctrl-C stops the ground truth; nothing is cached or reported (exit 1).\n"
            "A technique that fails (shader does not compile, render error or time limit, black or NaN\n"
            "image) is a failed row with its reason; the other techniques and the report go on.\n"
            "Exit codes: 0 ok, 3 the report is complete but some technique failed (its row says why),\n"
            "1 runtime failure (no GL context, I/O, interrupted: no report), 2 bad usage or bad scene.\n");
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

/* Technique cls in context gl, as `godrays render --repeat` does: with repeat > 1 a warm-up
 * render, then the median of repeat renders (realtime/timing.h), its spread in the metadata. */
static gr_status render_technique(const gr_technique_class *cls, gr_gl *gl, const gr_scene *scene, int repeat,
                                  gr_image **img, gr_image **targets, gr_metadata *meta, gr_error *err)
{
    gr_technique *r = NULL;
    gr_status st = gr_technique_create(cls, gl, NULL, &r, err);
    if (st != GR_OK) return st;
    *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    if (!*img) {
        gr_technique_destroy(r);
        return gr_fail(err, GR_E_NOMEM, "out of memory for a %d x %d image", scene->camera.width, scene->camera.height);
    }
    gr_timing tm;
    st = gr_timing_measure(r, scene, NULL, *img, repeat > 1, repeat, &tm, err);
    if (st == GR_OK) st = gr_technique_metadata(r, scene, NULL, &tm.median, meta, err);
    /* --save-targets: every intermediate target side by side, for the report's strip */
    if (st == GR_OK && targets && cls->read_target) st = gr_technique_read_target(r, targets, err);
    if (st == GR_OK && repeat > 1 &&
        (gr_meta_set_int(meta, "godrays:timing_repeats", repeat) != GR_OK ||
         gr_meta_set_double(meta, "godrays:wall_min_ms", tm.wall_min_ms) != GR_OK ||
         gr_meta_set_double(meta, "godrays:wall_max_ms", tm.wall_max_ms) != GR_OK))
        st = gr_fail(err, GR_E_NOMEM, "out of memory");
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

/* Before a ground truth is rendered (gr_truth_options.before_render): why the cache was not
 * used, then what comes. */
static void say_render(void *user, const gr_scene *scene, const gr_truth_info *info)
{
    const int quiet = *(const int *)user;
    if (info->note[0]) fprintf(stderr, "godrays run: warning: %s\n", info->note); /* warnings even with -q */
    if (!quiet)
        fprintf(stderr, "godrays run: rendering the ground truth (%d x %d; %s)...\n", scene->camera.width,
                scene->camera.height, info->cache_on ? "cached for later runs" : "not cached");
}

/* The ground truth through the provider (reference/truth.h): from the cache when a valid
 * entry exists, else rendered (Ctrl-C, --max-memory) and stored. */
static gr_status get_reference(const gr_scene *scene, int use_cache, int quiet, ref_out *ro, gr_error *err)
{
    gr_truth_options to;
    gr_truth_options_default(&to);
    to.use_cache = use_cache;
    to.ref.progress = !quiet;
    to.before_render = say_render;
    to.user = &quiet;
    gr_ref_result res;
    gr_truth_info ti;
    gr_status st = gr_truth_get(scene, &to, &res, &ti, err);
    if (st == GR_E_INTERRUPTED) gr_error_prefix(err, "no report written");
    if (st != GR_OK) return st;
    ro->img = res.image;
    res.image = NULL;
    gr_meta_free(&ro->meta);
    ro->meta = res.meta; /* hand the items over */
    gr_meta_init(&res.meta);
    gr_ref_result_free(&res);
    ro->cached = ti.cached;
    ro->cache_on = ti.cache_on;
    snprintf(ro->cache_path, sizeof ro->cache_path, "%s", ti.path);
    snprintf(ro->note, sizeof ro->note, "%s", ti.note);
    if (ti.cached && !quiet) fprintf(stderr, "godrays run: ground truth from the cache: %s\n", ti.path);
    if (!strncmp(ti.note, "not cached", 10)) fprintf(stderr, "godrays run: warning: %s\n", ti.note); /* even with -q */
    return GR_OK;
}

/* Each technique's registry metrics, as rendered and after the fit. */
static void print_details(const gr_report_input *in, const gr_leaderboard *lb)
{
    for (int i = 0; i < lb->n; i++) {
        const gr_lb_row *row = &lb->rows[i];
        if (row->kind != GR_LB_TECHNIQUE) continue;
        const gr_report_technique *t = &in->techniques[row->index];
        const gr_metrics *m = t->metrics;
        const gr_metrics_set *raw = &m->raw, *fit = m->have_fit ? &m->fit : &m->raw;
        const gr_channel_metrics *yf = &fit->ch[GR_MCH_Y];
        const gr_meta_item *g = gr_meta_get(t->meta, "godrays:gpu_ms"), *w = gr_meta_get(t->meta, "godrays:wall_ms");
        printf("\n#%d %s: %.2f s in this run (GPU ", row->rank, t->name, t->seconds);
        if (g && g->type != GR_META_STRING && g->num >= 0) printf("%.2f ms", g->num);
        else printf("n/a");
        printf(", wall %.2f ms per render)\n", w && w->type != GR_META_STRING ? w->num : NAN);
        printf("metric (registry)            as rendered   x a (a = %.4g)\n", fit->scale);
        for (int k = 0; k < gr_metric_count(); k++) { /* those computed in this run */
            const double vr = gr_metric_value(raw, k), vf = gr_metric_value(fit, k);
            if (!isnan(vr) || !isnan(vf)) printf("  %-24s %12.4g %12.4g\n", gr_metric_at(k)->label, vr, vf);
        }
        printf("scored %lld of %lld pixels (%lld not scored: reference rel. std. error > %g)", m->n_scored,
               m->n_pixels, m->n_stderr_excluded, m->stderr_bound);
        if (m->have_stderr && yf->n_samples > 0)
            printf("; after the fit %.1f %% of Y differences are within 2 std. errors",
                   100.0 * (double)yf->n_not_significant / (double)yf->n_samples);
        printf("\n");
    }
}

/* The leaderboard (report/leaderboard.h): the rows index.html shows, in the same order. */
static void print_leaderboard(const gr_report_input *in, const gr_leaderboard *lb)
{
    printf("\nleaderboard (by the verdict = (error after the fit + structure score) / 2, lower is better; "
           "baselines among the techniques):\n");
    printf("  %-4s %-34s %9s %9s %9s %8s %8s %9s %9s %10s", "rank", "technique", "verdict", "err. fit", "structure",
           "FLIP", "bp corr", "contrast", "scale a", "eq. blur");
    for (int i = 0; i < gr_metric_count(); i++)
        if (gr_metric_at(i)->leaderboard && !gr_lb_verdict_column(i)) printf(" %12.12s", gr_metric_at(i)->label);
    printf(" %10s %10s\n", "GPU ms", "wall ms");
    for (int r = 0; r < lb->n; r++) {
        const gr_lb_row *row = &lb->rows[r];
        char rank[16], name[64], eq[32];
        if (row->kind == GR_LB_TECHNIQUE) snprintf(rank, sizeof rank, "%d", row->rank);
        else snprintf(rank, sizeof rank, "%s", row->kind == GR_LB_BASELINE ? "base" : "FAIL");
        snprintf(name, sizeof name, row->kind == GR_LB_BASELINE ? "(%s)" : "%s", row->kind == GR_LB_BASELINE ? row->text : row->name);
        printf("  %-4s %-34s", rank, name);
        if (row->kind == GR_LB_FAILED) {
            printf(" failed: %s\n", row->text);
            continue;
        }
        printf(" %9.4g %9.4g %9.4g %8.4g %8.3g %9.3g %9.4g %10s", row->verdict, row->error_fit, row->structure, row->flip,
               row->corr, row->contrast_ratio, row->scale, gr_lb_eq_blur_text(in, row, eq, sizeof eq));
        for (int i = 0; i < gr_metric_count(); i++)
            if (gr_metric_at(i)->leaderboard && !gr_lb_verdict_column(i))
                printf(" %12.4g", gr_metric_value(row->m->have_fit ? &row->m->fit : &row->m->raw, i));
        const gr_metadata *meta = row->kind == GR_LB_TECHNIQUE ? in->techniques[row->index].meta : NULL;
        const gr_meta_item *g = gr_meta_get(meta, "godrays:gpu_ms"), *w = gr_meta_get(meta, "godrays:wall_ms");
        printf(" %10.3f %10.3f", g && g->type != GR_META_STRING && g->num >= 0 ? g->num : NAN,
               w && w->type != GR_META_STRING ? w->num : NAN);
        printf("%s%s\n", row->no_better ? "  <- " : "", row->no_better ? gr_lb_flag(row) : "");
    }
}

static void print_summary(const char *dir, const gr_report_input *in, const gr_leaderboard *lb, const ref_out *ro,
                          double t_ref, int quiet)
{
    const gr_scene *scene = in->scene;
    const int nt = in->n_techniques + in->n_failed;
    printf("scene '%s' (%d x %d): ground truth %.1f s (%s), %d real-time technique%s", scene->name,
           scene->camera.width, scene->camera.height, t_ref, ro->cached ? "from the cache" : "rendered", nt,
           nt == 1 ? "" : "s");
    if (in->n_failed > 0) printf(", %d FAILED", in->n_failed);
    printf("\n");
    print_details(in, lb);
    print_leaderboard(in, lb);
    if (lb->n_flagged > 0)
        printf("%d technique%s no better than a constant image at the truth's mean (verdict, or error after the fit, "
               "not below its)\n",
               lb->n_flagged, lb->n_flagged == 1 ? " is" : "s are");
    if (in->n_failed > 0)
        printf("%d technique%s FAILED (rows above; exit code 3)\n", in->n_failed, in->n_failed == 1 ? "" : "s");
    printf("report: %s/index.html (also %smetrics.json)\n", dir, in->n_techniques > 0 ? "summary.png, " : "");
    if (gr_report_truth_zero(in))
        fprintf(stderr, "godrays run: warning: the ground truth is zero everywhere scored: the metrics say nothing "
                "(camera inside an occluder, no scattering, or no light reaching the view?)\n");
    /* as `reference` warns: not under -q (the page says it in every case) */
    char coarse[512];
    if (!quiet && gr_report_truth_coarse(in, coarse, sizeof coarse)) fprintf(stderr, "godrays run: warning: %s\n", coarse);
}

/* What the command line asks for. */
typedef struct run_opts {
    const char *outdir, *tech_list, *frames_spec, *times_spec, *fps_spec;
    const char *suite;              /* --suite SUITE: every case of a view suite (run_suite) */
    int quiet, use_cache, help;
    int repeat;                     /* --repeat: renders timed per technique (median; 1: one render) */
    int save_targets;               /* --save-targets: each technique's targets strip in the report */
    gr_fit_mode fit;                /* --fit: the leaderboard's scaling (default: one scale) */
    const gr_technique_class *cls[GR_REPORT_MAX_TECHNIQUES];
    int nt;                         /* techniques */
    double fps, times[GR_SEQUENCE_MAX_FRAMES];
    long frame_no[GR_SEQUENCE_MAX_FRAMES];
    int n_times;                    /* 0: one frame, no sequence */
    int nf;                         /* frames (1 without a sequence) */
} run_opts;

/* What a run makes; run_free frees it. */
typedef struct run_state {
    gr_scene *scene;
    gr_scene *cases;                /* a sequence: one scene per frame (NULL otherwise) */
    const gr_scene *scene0;         /* the frame index.html compares */
    gr_image *test[GR_REPORT_MAX_TECHNIQUES];
    gr_image *targets[GR_REPORT_MAX_TECHNIQUES]; /* --save-targets (NULL: none, or no target) */
    gr_metadata smeta[GR_REPORT_MAX_TECHNIQUES];
    gr_image **seq_test;            /* seq_test[k * nf + i], i >= 1 (frame 0: test[k]) */
    ref_out ro;                     /* frame 0's ground truth */
    ref_out *seq_ref;               /* frames >= 1 */
    gr_metrics *mets;
    float *angles;
    gr_report_technique ts[GR_REPORT_MAX_TECHNIQUES];
    char exr_names[GR_REPORT_MAX_TECHNIQUES][48];
    int failed[GR_REPORT_MAX_TECHNIQUES];     /* 1: technique k has a failed row (reason[k]) */
    char reason[GR_REPORT_MAX_TECHNIQUES][GR_ERROR_MSG_MAX];
    int n_failed;
    gr_baselines *baselines;        /* black, constant, blurred truth, the blur ladder */
    gr_flip_reference *flip_ref;    /* the truth's half of HDR-FLIP: the baselines', then the report's */
    gr_report_input in;             /* what the report was made of (write_report) */
    gr_report_technique in_ts[GR_REPORT_MAX_TECHNIQUES]; /* the techniques that rendered, for in */
    gr_report_failure in_failed[GR_REPORT_MAX_TECHNIQUES];
    gr_leaderboard lb;              /* the rows printed (report/leaderboard.h) */
    char *seq_json;
    gr_sequence_result sres;
    gr_strbuf cmdline, words;
    double t_ref, t_refs, t_cmp;    /* frame 0's ground truth, every frame's, the comparison (s) */
} run_state;

/* The argument loop; returns the exit code (o->help: the help was printed). */
static int parse_args(gr_args *args, run_opts *o)
{
    int rc = 0, taken = 0;
    gr_error ferr;
    for (; args->i < args->argc && !rc; args->i++) {
        const char *a = args->argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            o->help = 1;
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o->quiet = 1;
        } else if (!strcmp(a, "--no-cache")) {
            o->use_cache = 0;
        } else if (!strcmp(a, "--save-targets")) {
            o->save_targets = 1;
        } else if (!strcmp(a, "--techniques")) {
            rc = gr_args_value(args, &o->tech_list);
        } else if (!strcmp(a, "--frames")) {
            rc = gr_args_value(args, &o->frames_spec);
        } else if (!strcmp(a, "--times")) {
            rc = gr_args_value(args, &o->times_spec);
        } else if (!strcmp(a, "--fps")) {
            rc = gr_args_value(args, &o->fps_spec);
        } else if (!strcmp(a, "--repeat")) {
            const char *v = NULL;
            char *end = NULL;
            if ((rc = gr_args_value(args, &v)) != 0) break;
            errno = 0;
            const long r = strtol(v, &end, 10);
            if (errno || end == v || *end || r < 1 || r > 1000)
                rc = gr_cli_usage_error("run", "--repeat %s: expected an integer in [1, 1000]", v);
            o->repeat = (int)r;
        } else if (!strcmp(a, "--suite")) {
            rc = gr_args_value(args, &o->suite);
        } else if ((taken = gr_fit_mode_option(args->argc, args->argv, &args->i, &o->fit, &ferr)) != 0) {
            rc = taken < 0 ? gr_cli_usage_error("run", "%s", ferr.msg) : 0;
        } else if ((rc = gr_args_take_common(args, &o->outdir, NULL, &taken)) == 0 && !taken) {
            rc = gr_args_take_scene(args);
        }
    }
    return rc;
}

/* --techniques and a sequence's --frames/--times/--fps (report/sequence.h); an exit code. */
static int parse_choices(run_opts *o)
{
    const char *cmd = "run";
    gr_error err = {GR_OK, ""};
    if (gr_technique_parse_list("--techniques", o->tech_list, o->cls, GR_REPORT_MAX_TECHNIQUES, &o->nt, &err) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", err.msg);
    if (o->nt == 0) return gr_cli_usage_error(cmd, "no real-time technique to compare");
    if (o->frames_spec && o->times_spec) return gr_cli_usage_error(cmd, "--frames and --times: give one of them");
    o->fps = 30.0;
    if (o->fps_spec) {
        char *end = NULL;
        o->fps = strtod(o->fps_spec, &end);
        if (end == o->fps_spec || *end || !isfinite(o->fps) || !(o->fps > 0))
            return gr_cli_usage_error(cmd, "--fps %s: expected a number > 0", o->fps_spec);
    }
    if (o->frames_spec && gr_tune_parse_frames("--frames", o->frames_spec, o->fps, o->times, GR_SEQUENCE_MAX_FRAMES,
                                               &o->n_times, &err) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", err.msg);
    if (o->times_spec &&
        gr_tune_parse_times("--times", o->times_spec, o->times, GR_SEQUENCE_MAX_FRAMES, &o->n_times, &err) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", err.msg);
    if ((o->frames_spec || o->times_spec) && o->n_times < 2)
        return gr_cli_usage_error(cmd, "%s %s: one frame; a sequence needs two or more",
                                  o->frames_spec ? "--frames" : "--times", o->frames_spec ? o->frames_spec : o->times_spec);
    for (int i = 0; i < o->n_times; i++) o->frame_no[i] = lround(o->times[i] * o->fps);
    o->nf = o->n_times > 0 ? o->n_times : 1;
    return 0;
}

/* A sequence: each frame's scene, the water at its time (--frames: from the scene's time). */
static gr_status make_cases(run_opts *o, run_state *rs, gr_error *err)
{
    const int nf = o->nf;
    rs->cases = calloc((size_t)nf, sizeof *rs->cases);
    rs->seq_test = calloc((size_t)(nf * o->nt), sizeof *rs->seq_test);
    rs->seq_ref = calloc((size_t)nf, sizeof *rs->seq_ref);
    if (!rs->cases || !rs->seq_test || !rs->seq_ref) return gr_fail(err, GR_E_NOMEM, "out of memory");
    for (int i = 0; i < nf; i++) {
        gr_meta_init(&rs->seq_ref[i].meta);
        const double tw = o->times[i] + (o->frames_spec ? rs->scene->water.time_s : 0.0);
        if (gr_tune_make_case(rs->scene, tw, NULL, &rs->cases[i], err) != GR_OK)
            return gr_error_prefix(err, "%s: frame %d", o->frames_spec ? "--frames" : "--times", i);
        o->times[i] = tw;
    }
    return GR_OK;
}

/* Technique k cannot be scored (it failed to build or render, a time limit included, or its
 * image is black): a failed row with the one-line reason, and the run goes on without it.
 * The one place a technique's failure is decided; only Ctrl-C stops the whole run. Returns
 * the status the run continues with. */
static gr_status technique_failed(const run_opts *o, run_state *rs, int k, const gr_error *e)
{
    if (e->status == GR_E_INTERRUPTED) return e->status;
    rs->failed[k] = 1;
    rs->n_failed++;
    snprintf(rs->reason[k], sizeof rs->reason[k], "%s", e->msg);
    fprintf(stderr, "godrays run: warning: %s FAILED: %s\n", o->cls[k]->name, e->msg); /* even with -q */
    return GR_OK;
}

/* GR_E_RUNTIME when img is black (every value 0): nothing to score, the technique's fault. */
static gr_status check_not_black(const gr_image *img, gr_error *err)
{
    const size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->nchannels;
    for (size_t i = 0; i < n; i++)
        if (img->pixels[i] != 0.0f) return GR_OK;
    return gr_fail(err, GR_E_RUNTIME, "rendered a black image (every pixel 0): nothing to score");
}

/* Technique k on every frame: frame 0 into rs->test[k], the others into rs->seq_test. */
static gr_status render_one(const run_opts *o, run_state *rs, gr_gl *gl, int k, gr_error *err)
{
    const gr_technique_class *cls = o->cls[k];
    const int nf = o->nf;
    gr_status st = render_technique(cls, gl, rs->scene0, o->repeat, &rs->test[k], o->save_targets ? &rs->targets[k] : NULL,
                                    &rs->smeta[k], err);
    /* a suite scores a black frame (a screen-space effect with its light off screen draws
     * nothing: that is what the player sees, the black baseline's score); one view refuses it */
    if (st == GR_OK && !o->suite) st = check_not_black(rs->test[k], err);
    if (st != GR_OK) return st; /* its row names it */
    for (int i = 1; i < nf && st == GR_OK; i++) {
        gr_metadata scratch;
        gr_meta_init(&scratch);
        st = render_technique(cls, gl, &rs->cases[i], 1, &rs->seq_test[k * nf + i], NULL, &scratch, err);
        gr_meta_free(&scratch);
        if (st != GR_OK) gr_error_prefix(err, "%s: frame %d (t = %g s)", cls->name, i, o->times[i]);
    }
    if (nf > 1) rs->seq_test[k * nf] = rs->test[k];
    return st;
}

/* The real-time side: it takes seconds, and a GL failure should not cost the user a
 * two-minute ground truth first. One context, one instance per technique; a technique that
 * fails is a failed row (technique_failed). */
/* A line while a technique's render is long (realtime/technique.h's wait report): every 10 s,
 * or $GODRAYS_PROGRESS_SECONDS (tests: shorter). */
static void say_waiting(void *user, const char *technique, const char *what, double elapsed_s, double limit_s)
{
    (void)user;
    fprintf(stderr, "godrays run: %s: still rendering (%s), elapsed %.0f s of its time limit of %g s\n", technique,
            what, elapsed_s, limit_s);
    fflush(stderr);
}

static double progress_seconds(void)
{
    const char *env = getenv("GODRAYS_PROGRESS_SECONDS");
    char *end = NULL;
    double v = env && env[0] ? strtod(env, &end) : 0.0;
    return v > 0 && end && !*end ? v : 10.0;
}

static gr_status render_techniques(const run_opts *o, run_state *rs, gr_error *err)
{
    gr_gl *gl = NULL;
    gr_status st = gr_gl_create(NULL, &gl, err);
    if (!o->quiet) gr_technique_set_wait_report(say_waiting, NULL, progress_seconds());
    const double t0 = now_s();
    for (int k = 0; k < o->nt && st == GR_OK; k++) {
        const gr_technique_class *cls = o->cls[k];
        /* progress in a pipe too (issue 29): which one, elapsed, remaining at the mean so far */
        double el = now_s() - t0;
        if (!o->quiet && k == 0) fprintf(stderr, "godrays run: rendering %s (1 of %d)...\n", cls->name, o->nt);
        else if (!o->quiet)
            fprintf(stderr, "godrays run: rendering %s (%d of %d; elapsed %.0f s, remaining ~%.0f s)...\n", cls->name,
                    k + 1, o->nt, el, el / k * (o->nt - k));
        double t = now_s();
        gr_report_technique *ts = &rs->ts[k];
        ts->name = cls->name;
        ts->description = cls->description;
        gr_error e = {GR_OK, ""};
        if (render_one(o, rs, gl, k, &e) != GR_OK) {
            if ((st = technique_failed(o, rs, k, &e)) != GR_OK) *err = e;
            /* a render over its time limit abandons its context (realtime/technique.h): the
             * techniques after it get a new one */
            if (st == GR_OK && gr_gl_abandoned(gl)) {
                gr_gl_destroy(gl);
                gl = NULL;
                st = gr_gl_create(NULL, &gl, err);
            }
            continue;
        }
        ts->seconds = now_s() - t;
        ts->test = rs->test[k];
        ts->targets = rs->targets[k];
        ts->meta = &rs->smeta[k];
        snprintf(rs->exr_names[k], sizeof rs->exr_names[k], "%s.exr", cls->name);
        ts->exr = rs->exr_names[k];
    }
    gr_technique_set_wait_report(NULL, NULL, 0);
    gr_gl_destroy(gl);
    return st;
}

/* Every frame's ground truth (reference/truth.h). */
static gr_status get_references(const run_opts *o, run_state *rs, gr_error *err)
{
    const int nf = o->nf;
    double t = now_s();
    if (nf > 1 && !o->quiet) fprintf(stderr, "godrays run: frame 1 of %d (t = %g s)\n", nf, o->times[0]);
    gr_status st = get_reference(rs->scene0, o->use_cache, o->quiet, &rs->ro, err);
    if (st != GR_OK) return st;
    rs->t_ref = now_s() - t;
    for (int i = 1; i < nf; i++) {
        if (!o->quiet) fprintf(stderr, "godrays run: frame %d of %d (t = %g s)\n", i + 1, nf, o->times[i]);
        if ((st = get_reference(&rs->cases[i], o->use_cache, o->quiet, &rs->seq_ref[i], err)) != GR_OK) {
            gr_error_prefix(err, "frame %d (t = %g s)", i, o->times[i]);
            const size_t l = strlen(err->msg); /* the frames before it were cached ("nothing cached" was wrong) */
            if (st == GR_E_INTERRUPTED && rs->ro.cache_on)
                snprintf(err->msg + l, sizeof err->msg - l, "; the %d frame%s before it cached", i, i > 1 ? "s" : "");
            return st;
        }
    }
    rs->t_refs = now_s() - t;
    return GR_OK;
}

/* compute_metrics's jobs: technique k's metrics against the truth (gr_parallel_try). */
typedef struct metrics_jobs {
    run_state *rs;
    const gr_metrics_options *mopt;
} metrics_jobs;

static gr_status metrics_job(void *arg, int k, gr_error *err)
{
    metrics_jobs *j = arg;
    if (j->rs->failed[k]) return GR_OK;
    return gr_metrics_compute(j->rs->ro.img, j->rs->test[k], j->mopt, &j->rs->mets[k], err);
}

/* Each technique's metrics against frame 0's ground truth (compare/metrics.h): raw and after
 * the best scale fit, reference-stderr aware. */
static gr_status compute_metrics(const run_opts *o, run_state *rs, gr_error *err)
{
    const gr_scene *scene = rs->scene;
    const gr_meta_item *dof = gr_meta_get(&rs->ro.meta, "godrays:stderr_dof"); /* Student t for significance */
    /* beam structure around the refracted sun's vanishing point, de-glowed by the angle to
     * the sun (docs/metrics.md), in every technique's metric sets; skipped when the beams have
     * no finite vanishing point (parallel to the image plane) */
    gr_structure_options so;
    rs->angles = malloc((size_t)scene->camera.width * (size_t)scene->camera.height * sizeof(float));
    if (!rs->angles) return gr_fail(err, GR_E_NOMEM, "out of memory for the structure metrics");
    const int with_structure = gr_profile_structure_options(scene, rs->angles, &so);
    gr_metrics_options mopt = {0};
    mopt.fit_scale = (int)o->fit; /* a technique's intensity is an arbitrary factor (seed 000) */
    if (with_structure) mopt.structure = &so;
    if (dof && dof->type != GR_META_STRING && dof->num >= 1.0) mopt.stderr_dof = (int)dof->num;
    /* every technique's metrics on a few threads (common/parallel.h: the same numbers for any
     * count), the first failure in the techniques' order reported */
    metrics_jobs mj = {rs, &mopt};
    gr_status mst = gr_parallel_try(o->nt, 0, metrics_job, &mj, err);
    if (mst != GR_OK) return mst;
    for (int k = 0; k < o->nt; k++)
        if (!rs->failed[k]) rs->ts[k].metrics = &rs->mets[k];
    /* the baselines, scored exactly as the techniques (and with HDR-FLIP, which the report
     * computes for each technique from its own map); the truth's half of FLIP made once for
     * both (compare/flip.h) */
    gr_flip_options fo = {.mode = GR_FLIP_HDR};
    gr_status fst = gr_flip_reference_create(rs->ro.img, &fo, GR_FLIP_SHARED_PREPARE_MAX, 0, &rs->flip_ref, err);
    if (fst != GR_OK) return fst;
    fo.reference = rs->flip_ref;
    mopt.flip = &fo;
    if (!(rs->baselines = malloc(sizeof *rs->baselines))) return gr_fail(err, GR_E_NOMEM, "out of memory");
    return gr_baselines_compute(rs->ro.img, &mopt, rs->baselines, err);
}

/* OUTDIR/sequence (report/sequence.h). */
static gr_status write_sequence(const run_opts *o, run_state *rs, const char *outdir, gr_error *err)
{
    const int nf = o->nf;
    if (!o->quiet) fprintf(stderr, "godrays run: the sequence (%d frames)...\n", nf);
    const gr_scene *fs[GR_SEQUENCE_MAX_FRAMES];
    const gr_image *frefs[GR_SEQUENCE_MAX_FRAMES];
    const char *names[GR_REPORT_MAX_TECHNIQUES];
    const gr_image **tests = calloc((size_t)(nf * o->nt), sizeof *tests);
    if (!tests) return gr_fail(err, GR_E_NOMEM, "out of memory");
    for (int i = 0; i < nf; i++) {
        fs[i] = &rs->cases[i];
        frefs[i] = i ? rs->seq_ref[i].img : rs->ro.img;
    }
    int n = 0; /* the techniques that rendered every frame */
    for (int k = 0; k < o->nt; k++) {
        if (rs->failed[k]) continue;
        names[n] = o->cls[k]->name;
        for (int i = 0; i < nf; i++) tests[n * nf + i] = rs->seq_test[k * nf + i];
        n++;
    }
    gr_sequence_input sin = {.n_frames = nf, .times = o->times, .frame_numbers = o->frames_spec ? o->frame_no : NULL,
                             .scenes = fs, .refs = frefs, .n_techniques = n, .names = names,
                             .tests = tests, .up_href = "../index.html",
                             .command_line = gr_sb_str(&rs->cmdline)};
    char path[4300];
    gr_status st = snprintf(path, sizeof path, "%s/sequence", outdir) >= (int)sizeof path - 48
                       ? gr_fail(err, GR_E_USAGE, "%s: output directory name too long", outdir)
                       : gr_sequence_write(path, &sin, &rs->seq_json, &rs->sres, err);
    free(tests);
    return st;
}

/* The report folder. The report links the EXRs; they are written first so that a finished
 * index.html never points at a missing file. */
static gr_status write_report(const run_opts *o, run_state *rs, const char *outdir, gr_report_result *rres,
                              gr_error *err)
{
    if (!o->quiet) fprintf(stderr, "godrays run: writing the report...\n");
    gr_status st = o->nf > 1 && rs->n_failed < o->nt ? write_sequence(o, rs, outdir, err) : GR_OK;
    if (st != GR_OK) return st;
    const ref_out *ro = &rs->ro;
    int n_ok = 0, n_failed = 0; /* the techniques that rendered, then the failed rows */
    for (int k = 0; k < o->nt; k++) {
        if (!rs->failed[k]) rs->in_ts[n_ok++] = rs->ts[k];
        else rs->in_failed[n_failed++] = (gr_report_failure){.name = o->cls[k]->name,
                                                             .description = o->cls[k]->description,
                                                             .reason = rs->reason[k]};
    }
    gr_report_input in = {.scene = rs->scene0, .ref = ro->img, .ref_meta = &ro->meta, .n_techniques = n_ok,
                          .techniques = rs->in_ts, .n_failed = n_failed, .failed = rs->in_failed,
                          .baselines = rs->baselines, .flip_ref = rs->flip_ref, .command_line = gr_sb_str(&rs->cmdline),
                          .scene_words = gr_sb_str(&rs->words), .ref_cached = ro->cached,
                          .ref_cache_path = ro->cache_on ? ro->cache_path : NULL,
                          .ref_cache_note = ro->note[0] ? ro->note : NULL, .ref_seconds = rs->t_ref,
                          .compare_seconds = rs->t_cmp, .ref_exr = "reference.exr", .sequence_json = rs->seq_json,
                          .sequence_href = rs->seq_json ? "sequence/index.html" : NULL};
    if ((st = gr_report_make_dir(outdir, err)) != GR_OK) return st;
    char path[4300];
    if (snprintf(path, sizeof path, "%s/reference.exr", outdir) >= (int)sizeof path - 48)
        return gr_fail(err, GR_E_USAGE, "%s: output directory name too long", outdir);
    if ((st = gr_exr_write(path, ro->img, &ro->meta, err)) != GR_OK) return st;
    for (int k = 0; k < o->nt; k++) {
        if (rs->failed[k]) continue;
        snprintf(path, sizeof path, "%s/%s", outdir, rs->exr_names[k]);
        if ((st = gr_exr_write(path, rs->test[k], &rs->smeta[k], err)) != GR_OK) return st;
    }
    if ((st = gr_report_write(outdir, &in, rres, err)) != GR_OK) return st;
    rs->in = in;
    gr_leaderboard_build(&rs->in, rres->flip, &rs->lb); /* the report's rows, for the terminal */
    if (!o->quiet && !rres->labelled)
        fprintf(stderr, "godrays run: note: no font for OpenImageIO's text: summary.png is unlabelled\n");
    if (!o->quiet && rres->charts == 0) fprintf(stderr, "godrays run: note: charts not drawn (see index.html)\n");
    return GR_OK;
}

/* The sequence's table (after print_summary). */
static void print_sequence(const run_opts *o, const run_state *rs, const char *outdir)
{
    const int nf = o->nf;
    printf("\nsequence: %d frames, t = %g .. %g s; ground truths %.1f s in all\n", nf, o->times[0], o->times[nf - 1],
           rs->t_refs);
    printf("  %-24s %10s %14s %12s %14s\n", "technique", "a", "diff. error", "flicker", "drift err deg");
    for (int k = 0, j = 0; k < o->nt; k++) { /* j: the sequence's index of the techniques that rendered */
        if (rs->failed[k]) continue;
        printf("  %-24s %10.4g %14.4g %12.4g %14.3g\n", o->cls[k]->name, rs->sres.scale[j], rs->sres.rel_diff_rmse[j],
               rs->sres.flicker_ratio[j], rs->sres.drift_err_deg[j]);
        j++;
    }
    printf("sequence report: %s/sequence/index.html (%d charts, %d animations)\n", outdir, rs->sres.charts,
           rs->sres.animations);
}

static void run_free(const run_opts *o, run_state *rs)
{
    const int nf = o->nf;
    free(rs->angles);
    gr_image_destroy(rs->ro.img);
    gr_meta_free(&rs->ro.meta);
    for (int i = 1; rs->seq_ref && i < nf; i++) {
        gr_image_destroy(rs->seq_ref[i].img);
        gr_meta_free(&rs->seq_ref[i].meta);
    }
    for (int k = 0; rs->seq_test && k < o->nt; k++)
        for (int i = 1; i < nf; i++) gr_image_destroy(rs->seq_test[k * nf + i]);
    free(rs->seq_test);
    free(rs->seq_ref);
    free(rs->cases);
    free(rs->seq_json);
    for (int k = 0; k < GR_REPORT_MAX_TECHNIQUES; k++) {
        gr_image_destroy(rs->test[k]);
        gr_image_destroy(rs->targets[k]);
        gr_meta_free(&rs->smeta[k]);
    }
    free(rs->mets);
    free(rs->baselines);
    gr_flip_reference_destroy(rs->flip_ref);
    free(rs->scene);
    gr_sb_free(&rs->cmdline);
    gr_sb_free(&rs->words);
    free(rs);
}

/* One case's work (a scene's run, or one case of a suite): techniques, ground truth, metrics
 * and the report into outdir, whose leaderboard rs->lb then holds; rs->scene0 is the scene.
 * Returns an exit code (0: done, failed techniques included). */
static int run_case(run_opts *o, run_state *rs, const char *outdir)
{
    const char *cmd = "run";
    gr_error err = {GR_OK, ""};
    if (!(rs->mets = calloc((size_t)o->nt, sizeof *rs->mets))) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        return gr_cli_report(cmd, &err);
    }
    if (render_techniques(o, rs, &err) != GR_OK || get_references(o, rs, &err) != GR_OK)
        return gr_cli_report(cmd, &err);
    if (!o->quiet) fprintf(stderr, "godrays run: comparing...\n");
    double t = now_s();
    if (compute_metrics(o, rs, &err) != GR_OK) return gr_cli_report(cmd, &err);
    rs->t_cmp = now_s() - t;
    gr_report_result rres;
    if (write_report(o, rs, outdir, &rres, &err) != GR_OK) return gr_cli_report(cmd, &err);
    return 0;
}

/* Bad settings are bad input (exit 2) before any slow or GL work. */
static int check_settings(const run_opts *o, const gr_scene *scene)
{
    gr_error err = {GR_OK, ""};
    for (int k = 0; k < o->nt; k++)
        if (gr_technique_check(o->cls[k], gr_technique_scene_settings(o->cls[k], scene), &err) != GR_OK)
            return gr_cli_report("run", &err);
    return 0;
}

/* Everything after the command line: scene, techniques, ground truths, metrics, report. */
static int run_scene(gr_args *args, run_opts *o, run_state *rs)
{
    const char *cmd = "run";
    gr_error err = {GR_OK, ""};
    int rc = 0;
    char dirbuf[4096];
    if ((rc = gr_args_load_scene(args, &rs->scene)) != 0) return rc;
    if (o->n_times > 0 && make_cases(o, rs, &err) != GR_OK) return gr_cli_report(cmd, &err);
    rs->scene0 = rs->cases ? &rs->cases[0] : rs->scene;
    if ((rc = check_settings(o, rs->scene)) != 0) return rc;
    /* The ground truth takes minutes: a folder that cannot be made is refused before it. */
    const char *outdir = NULL;
    if ((rc = gr_args_output_dir(args, rs->scene, o->outdir, NULL, dirbuf, sizeof dirbuf, &outdir)) != 0) return rc;
    command_line(args->argc, args->argv, &rs->cmdline);
    gr_args_scene_words(args, &rs->words);
    if (gr_sb_status(&rs->cmdline, "the command line", &err) != GR_OK ||
        gr_sb_status(&rs->words, "the command line", &err) != GR_OK)
        return gr_cli_report(cmd, &err);
    if ((rc = run_case(o, rs, outdir)) != 0) return rc;
    print_summary(outdir, &rs->in, &rs->lb, &rs->ro, rs->t_ref, o->quiet);
    if (o->nf > 1 && rs->n_failed < o->nt) print_sequence(o, rs, outdir);
    return rs->n_failed > 0 ? 3 : 0; /* the report is complete; some technique failed (docs/report.md) */
}

/* A new, empty run state (NULL: out of memory); run_free frees it. */
static run_state *run_state_new(void)
{
    run_state *rs = calloc(1, sizeof *rs);
    if (!rs) return NULL;
    for (int k = 0; k < GR_REPORT_MAX_TECHNIQUES; k++) gr_meta_init(&rs->smeta[k]);
    gr_meta_init(&rs->ro.meta);
    gr_sb_init(&rs->cmdline);
    gr_sb_init(&rs->words);
    return rs;
}

/* ---- run --suite: every case of a view suite (suite/suite.h), then the suite leaderboard ---- */

/* The suite's cells, [case * nt + technique] (report/suite_board.h). */
typedef struct suite_cells {
    double *verdict, *error_fit, *structure, *gpu_ms, *constant;
    char **reasons;
} suite_cells;

static void cells_free(suite_cells *c, int n)
{
    for (int i = 0; c->reasons && i < n; i++) free(c->reasons[i]);
    free(c->reasons);
    free(c->verdict);
    free(c->error_fit);
    free(c->structure);
    free(c->gpu_ms);
    free(c->constant);
}

static gr_status cells_alloc(suite_cells *c, int nc, int nt, gr_error *err)
{
    const size_t n = (size_t)nc * (size_t)nt;
    c->verdict = malloc(n * sizeof *c->verdict);
    c->error_fit = malloc(n * sizeof *c->error_fit);
    c->structure = malloc(n * sizeof *c->structure);
    c->gpu_ms = malloc(n * sizeof *c->gpu_ms);
    c->constant = malloc((size_t)nc * sizeof *c->constant);
    c->reasons = calloc(n, sizeof *c->reasons);
    if (!c->verdict || !c->error_fit || !c->structure || !c->gpu_ms || !c->constant || !c->reasons)
        return gr_fail(err, GR_E_NOMEM, "out of memory");
    for (size_t i = 0; i < n; i++) c->verdict[i] = c->error_fit[i] = c->structure[i] = c->gpu_ms[i] = NAN;
    for (int i = 0; i < nc; i++) c->constant[i] = NAN;
    return GR_OK;
}

/* Case c's leaderboard (rs->lb, the rows its report shows) into the cells. */
static void collect_case(const run_opts *o, const run_state *rs, int c, suite_cells *cells)
{
    for (int r = 0; r < rs->lb.n; r++) {
        const gr_lb_row *row = &rs->lb.rows[r];
        if (row->kind == GR_LB_BASELINE) {
            if (row->index == GR_BASELINE_CONSTANT) cells->constant[c] = row->verdict;
            continue;
        }
        int k = 0;
        while (k < o->nt && strcmp(o->cls[k]->name, row->name) != 0) k++;
        if (k == o->nt) continue;
        const int i = c * o->nt + k;
        if (row->kind == GR_LB_FAILED) {
            cells->reasons[i] = strdup(row->text ? row->text : "failed");
            continue;
        }
        cells->verdict[i] = row->verdict;
        cells->error_fit[i] = row->error_fit;
        cells->structure[i] = row->structure;
        const gr_meta_item *g = gr_meta_get(rs->in.techniques[row->index].meta, "godrays:gpu_ms");
        cells->gpu_ms[i] = g && g->type != GR_META_STRING && g->num >= 0 ? g->num : NAN;
    }
}

/* Case c into DIR/cases/NAME/: its scene as normalized JSON (scene.json, which the report's
 * suggested commands name), then run_case. Returns an exit code. */
static int suite_case(gr_args *args, run_opts *o, const gr_suite *s, int c, const char *outdir, suite_cells *cells)
{
    const gr_suite_case *sc = &s->cases[c];
    char dir[4400], file[4500];
    gr_error err = {GR_OK, ""};
    snprintf(dir, sizeof dir, "%s/cases/%s", outdir, sc->name);
    snprintf(file, sizeof file, "%s/scene.json", dir);
    run_state *rs = run_state_new();
    char *json = gr_scene_to_json(&sc->scene);
    gr_status st = rs && json && (rs->scene = malloc(sizeof *rs->scene)) ? GR_OK : gr_fail(&err, GR_E_NOMEM, "out of memory");
    if (st == GR_OK) {
        *rs->scene = sc->scene;
        rs->scene0 = rs->scene;
        command_line(args->argc, args->argv, &rs->cmdline);
        gr_sb_shell_word(&rs->words, file);
        st = gr_report_make_dir(dir, &err);
    }
    if (st == GR_OK) st = gr_outfile_write(file, json, -1, &err);
    free(json);
    int rc = st != GR_OK ? gr_cli_report("run", &err) : 0;
    if (!rc && !o->quiet)
        fprintf(stderr, "godrays run: case %d of %d: %s (%s, %d x %d)\n", c + 1, s->n_cases, sc->name,
                gr_split_name(sc->split), sc->scene.camera.width, sc->scene.camera.height);
    if (!rc) rc = run_case(o, rs, dir);
    if (!rc) collect_case(o, rs, c, cells);
    if (rs) run_free(o, rs);
    return rc;
}

/* The terminal's suite table: per case the verdict of every technique, then the aggregate. */
static void print_suite(const run_opts *o, const gr_suite *s, const gr_suite_board_input *in, const char *outdir)
{
    const int nt = o->nt;
    gr_suite_aggregate agg[GR_SUITE_BOARD_MAX_TECHNIQUES];
    int order[GR_SUITE_BOARD_MAX_TECHNIQUES], w[GR_SUITE_BOARD_MAX_TECHNIQUES];
    gr_suite_board_aggregate(in, agg, order);
    printf("suite '%s': %d cases (%d train, %d test); verdict per case (lower is better):\n", s->name, s->n_cases,
           gr_suite_count(s, GR_SPLIT_TRAIN), gr_suite_count(s, GR_SPLIT_TEST));
    printf("  %-24s %-5s %10s", "case", "split", "(constant)");
    for (int k = 0; k < nt; k++) {
        w[k] = (int)strlen(o->cls[k]->name) > 11 ? (int)strlen(o->cls[k]->name) : 11;
        printf(" %*s", w[k], o->cls[k]->name);
    }
    printf("\n");
    for (int c = 0; c < s->n_cases; c++) {
        printf("  %-24s %-5s %10.6g", s->cases[c].name, gr_split_name(s->cases[c].split), in->constant[c]);
        for (int k = 0; k < nt; k++)
            if (isfinite(in->verdict[c * nt + k])) printf(" %*.6g", w[k], in->verdict[c * nt + k]);
            else printf(" %*s", w[k], "FAILED");
        printf("\n");
    }
    static const char *const rows[] = {"mean", "worst", "mean train", "mean test"};
    for (int r = 0; r < 4; r++) {
        printf("  %-24s %-5s %10s", rows[r], "", "");
        for (int k = 0; k < nt; k++)
            printf(" %*.6g", w[k], r == 0 ? agg[k].mean : r == 1 ? agg[k].worst : r == 2 ? agg[k].mean_train : agg[k].mean_test);
        printf("\n");
    }
    printf("ranking (mean verdict over the cases; worst case):\n");
    for (int r = 0; r < nt; r++) {
        const gr_suite_aggregate *a = &agg[order[r]];
        printf("  %2d %-24s mean %.6g, worst %.6g (%s)", r + 1, o->cls[order[r]]->name, a->mean, a->worst,
               a->worst_case >= 0 ? s->cases[a->worst_case].name : "-");
        if (a->n_failed) printf(", FAILED in %d case%s", a->n_failed, a->n_failed == 1 ? "" : "s");
        printf("\n");
    }
    printf("report: %s/index.html (also metrics.json; each case's report in %s/cases/CASE/)\n", outdir, outdir);
}

/* run --suite SUITE: each case as a run of its own into DIR/cases/CASE/, then the suite's
 * leaderboard (report/suite_board.h) in DIR and on the terminal. Returns the exit code. */
static int run_suite(gr_args *args, run_opts *o)
{
    gr_suite *s = NULL;
    int rc = gr_args_load_suite(args, o->suite, &s);
    if (rc) return rc;
    for (int c = 0; c < s->n_cases && !rc; c++) rc = check_settings(o, &s->cases[c].scene);
    char dirbuf[4096];
    const char *outdir = o->outdir;
    if (!rc && !outdir) {
        gr_tune_default_dir(s->name, NULL, dirbuf, sizeof dirbuf);
        outdir = dirbuf;
    }
    if (!rc) rc = gr_args_check_output_dir(args, o->outdir ? "-o" : "default output folder", outdir);
    suite_cells cells = {0};
    gr_error err = {GR_OK, ""};
    if (!rc && cells_alloc(&cells, s->n_cases, o->nt, &err) != GR_OK) rc = gr_cli_report("run", &err);
    const double t0 = now_s();
    for (int c = 0; c < s->n_cases && !rc; c++) rc = suite_case(args, o, s, c, outdir, &cells);
    gr_strbuf cl;
    gr_sb_init(&cl);
    command_line(args->argc, args->argv, &cl);
    const char *names[GR_REPORT_MAX_TECHNIQUES];
    for (int k = 0; k < o->nt; k++) names[k] = o->cls[k]->name;
    gr_suite_board_input in = {.suite = s, .n_techniques = o->nt, .techniques = names, .verdict = cells.verdict,
                               .error_fit = cells.error_fit, .structure = cells.structure, .gpu_ms = cells.gpu_ms,
                               .reasons = (const char *const *)cells.reasons, .constant = cells.constant,
                               .command_line = gr_sb_str(&cl), .seconds = now_s() - t0};
    if (!rc && gr_suite_board_write(outdir, &in, &err) != GR_OK) rc = gr_cli_report("run", &err);
    int failed = 0;
    for (int i = 0; !rc && i < s->n_cases * o->nt; i++) failed += cells.reasons[i] != NULL;
    if (!rc) print_suite(o, s, &in, outdir);
    if (!rc && failed) printf("%d case x technique cell%s FAILED (exit code 3)\n", failed, failed == 1 ? "" : "s");
    gr_sb_free(&cl);
    cells_free(&cells, s->n_cases * o->nt);
    gr_suite_destroy(s);
    return rc ? rc : failed ? 3 : 0;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int run_with(gr_args *args)
{
    run_opts o;
    memset(&o, 0, sizeof o);
    o.use_cache = 1;
    o.repeat = 1;
    o.fit = GR_FIT_SCALE;
    int rc = parse_args(args, &o);
    if (rc || o.help) return rc;
    if (o.suite && args->scene_path)
        return gr_cli_usage_error("run", "--suite %s and the scene %s: give one of them", o.suite, args->scene_path);
    if (!o.suite && (rc = gr_args_need_scene(args)) != 0) return rc;
    /* user techniques before the scene, whose sections they add */
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    if ((rc = parse_choices(&o)) != 0) return rc;
    if (o.suite && o.n_times > 0) return gr_cli_usage_error("run", "--suite with --frames/--times: not supported");
    if (o.suite) return run_suite(args, &o);
    run_state *rs = run_state_new();
    if (!rs) {
        gr_error err = {GR_E_NOMEM, "out of memory"};
        return gr_cli_report("run", &err);
    }
    rc = run_scene(args, &o, rs);
    run_free(&o, rs);
    return rc;
}

int cmd_run(int argc, char **argv)
{
    return gr_args_main("run", argc, argv, run_with);
}
