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
#include "compare/registry.h"
#include "realtime/technique.h"
#include "realtime/timing.h"
#include "report/chart.h"
#include "report/profile.h"
#include "report/report.h"
#include "tune/page.h"
#include "tune/budget.h"
#include "reference/progress.h"
#include "reference/truth.h"
#include "tune/pareto.h"
#include "tune/suitetune.h"
#include "cli/pareto_suite.h"
#include "tune/session.h"

#define MAX_POINTS 256

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays pareto SCENE [-o DIR] [options]\n"
            "       godrays pareto --suite SUITE [--tune] [--budgets MS,MS,..] [--timing-size WxH] [options]\n"
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
            "Error = the verdict against the high-quality ground truth, the score `godrays run` ranks\n"
            "by ((RMSE of Y / its mean Y + structure score) / 2; docs/metrics.md). The techniques\n"
            "are ranked by the wall time of a render with readback on llvmpipe, by the GPU time of\n"
            "their GL passes on a hardware GPU (both are listed). Writes DIR/pareto.csv and\n"
            "DIR/pareto.png (every family and its Pareto front, one colour each). docs/tuning.md.\n"
            "\n"
            "options:\n"
            "  -o, --output DIR   folder (default: out/SCENE_NAME/pareto)\n"
            "  --size WxH         image size (default 320x180: the high-quality ground truth costs\n"
            "                     about 4x a default-quality one)\n"
            "  --set KEY=VALUE    override a scene value (repeatable)\n"
            "  --preset FILE      apply a preset's settings as overrides (docs/tuning.md \"Presets\")\n"
            "  --techniques A,B   the techniques to place (default: every registered one)\n"
            "  --technique NAME   one technique only (same as --techniques NAME)\n"
            "  --technique-dir DIR  add the user technique in DIR (repeatable)\n"
            "  --time-limit S     give up a render after S seconds (default 60, or $GODRAYS_TIME_LIMIT)\n"
            "  --quick            fewer points (q0, q1, the quick levels of each ladder), for tests\n"
            "  --repeat R         renders per setting; time = median (default 5; with --suite 3 on a CPU\n"
            "                     rasterizer, 5 on a GPU)\n"
            "  --no-cache         render the high-quality ground truth even if cached\n"
            "  --suite SUITE      over a view suite instead of one scene (docs/tuning.md \"Tuned fronts and\n"
            "                     budgets\"): each technique's ladder points scored against the cases'\n"
            "                     ground truths (cached) on the train and the test cases; writes\n"
            "                     DIR/fronts.csv, fronts.png (time against TEST error), index.html\n"
            "  --tune             with --suite: each ladder point's look settings (its tune_keys) also\n"
            "                     tuned on the train cases (verdict, global search), scored on the test ones\n"
            "  --budgets LIST     with --suite: frame budgets in ms (e.g. 0.5,1,2,4): the budget table\n"
            "                     (DIR/budgets.csv) and one preset per budget (DIR/presets/)\n"
            "  --timing-size WxH  with --suite: the size each point is timed at (default 1920x1080;\n"
            "                     errors are at the suite's size or --size)\n"
            "  --seed S           with --tune: the search's seed (default 0; same seed, same result)\n"
            "  --max-evals N      with --tune: evaluations per local search of the global search\n"
            "                     (default 60 + 40 per setting)\n"
            "  --local-evals N    with --tune: the continuation's local search at the ladder points other\n"
            "                     than the anchor (the ladder's middle; default 20 + 12 per setting, and as\n"
            "                     many for its polish)\n"
            "  --tune-full        --tune with the global search at every ladder point, no search budget\n"
            "                     (slow)\n"
            "  --no-search-budget with --tune: every point gets its whole search; by default a point\n"
            "                     whose render work (cost counters) is r times the ladder's cheapest\n"
            "                     one's gets 1/r of its evaluations (docs/tuning.md \"Search budgets\")\n"
            "  --timing-cap S     with --suite: time fewer renders once the timed ones took S seconds\n"
            "                     (default 2; 0: all --repeat; the count is in fronts.csv)\n"
            "  --yes              start more than 20000 technique renders (docs/tuning.md \"Budgets\")\n"
            "  --max-memory SIZE  refuse (exit 2) a ground truth estimated to need more (e.g. 8G;\n"
            "                     default $GODRAYS_MAX_MEMORY, else 80 %% of the memory)\n"
            "  --gl-platform P    auto, surfaceless or device\n"
            "  -q, --quiet        no progress messages\n"
            "  -h, --help         this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage or bad scene.\n");
}

/* The error axis: the verdict (compare/registry.h), the score `godrays run` ranks by. */
static double verdict(const gr_metrics_set *set) { return gr_metric_value(set, GR_METRIC_VERDICT); }

/* The metrics the verdict needs against the scene's truth: the pointwise pass and the beam
 * structure (so, when the beams have a vanishing point); no stderr exclusion (the HQ image is
 * the reference, its own noise is tiny). */
static gr_metrics_options verdict_options(const gr_structure_options *so, int fit)
{
    gr_metrics_options mo = {0};
    mo.skip_ssim = 1;
    mo.skip_blur = 1;
    mo.fit_scale = fit;
    mo.stderr_bound = INFINITY;
    mo.structure = so && so->radial ? so : NULL;
    return mo;
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

/* What the command line asks for. */
typedef struct pareto_opts {
    const char *outopt, *tech_list, *tech_flag;
    int quiet, quick, use_cache, help, yes;
    gr_tune_budget budget; /* the count before the ground truths, the estimate after a render (tune/budget.h) */
    long repeat;
    int have_repeat;
    gr_ps_opts ps;                 /* --suite and its options (cli/pareto_suite.h) */
    const char *outdir;            /* the output folder (each point's thumbnail, report/chart.h) */
    gr_gl_platform platform;
    const gr_technique_class *techs[GR_TECH_MAX];
    int n_techs;
} pareto_opts;

/* --suite, --tune, --budgets, --timing-size, --seed, --max-evals: 1 when argv[i] is one of
 * them (*rc: the exit code of its value). */
static int take_suite_option(gr_args *args, pareto_opts *o, int *rc)
{
    const char *a = args->argv[args->i], *v = NULL;
    gr_error e = {GR_OK, ""};
    if (!strcmp(a, "--tune") || !strcmp(a, "--tune-full")) {
        o->ps.tune = 1;
        o->ps.tune_full |= !strcmp(a, "--tune-full");
        return 1;
    }
    if (!strcmp(a, "--no-search-budget")) {
        o->ps.no_search_budget = 1;
        return 1;
    }
    if (strcmp(a, "--suite") && strcmp(a, "--budgets") && strcmp(a, "--timing-size") && strcmp(a, "--seed") &&
        strcmp(a, "--max-evals") && strcmp(a, "--local-evals") && strcmp(a, "--timing-cap"))
        return 0;
    if ((*rc = gr_args_value(args, &v)) != 0) return 1;
    char *end = NULL, x = 0;
    errno = 0;
    if (!strcmp(a, "--suite")) {
        o->ps.suite_path = v;
    } else if (!strcmp(a, "--budgets")) {
        if (gr_st_parse_budgets(a, v, o->ps.budgets_ms, GR_PS_MAX_BUDGETS, &o->ps.n_budgets, &e) != GR_OK)
            *rc = gr_cli_usage_error("pareto", "%s", e.msg);
    } else if (!strcmp(a, "--timing-size")) {
        if (sscanf(v, "%dx%d%c", &o->ps.timing_w, &o->ps.timing_h, &x) != 2 || o->ps.timing_w < 1 || o->ps.timing_h < 1 ||
            o->ps.timing_w > 16384 || o->ps.timing_h > 16384)
            *rc = gr_cli_usage_error("pareto", "--timing-size %s: expected WxH, e.g. 1920x1080", v);
    } else if (!strcmp(a, "--seed")) {
        o->ps.seed = strtoull(v, &end, 10);
        if (errno || end == v || *end || v[0] == '-') *rc = gr_cli_usage_error("pareto", "--seed %s: expected an integer >= 0", v);
    } else if (!strcmp(a, "--timing-cap")) {
        o->ps.timing_cap_s = strtod(v, &end);
        if (errno || end == v || *end || !(o->ps.timing_cap_s >= 0) || o->ps.timing_cap_s > 1e6)
            *rc = gr_cli_usage_error("pareto", "--timing-cap %s: expected seconds >= 0 (0: no cap)", v);
    } else {
        const long m = strtol(v, &end, 10);
        if (errno || end == v || *end || m < 4 || m > 100000)
            *rc = gr_cli_usage_error("pareto", "%s %s: expected an integer in [4, 100000]", a, v);
        *(!strcmp(a, "--max-evals") ? &o->ps.max_evals : &o->ps.local_evals) = (int)m;
    }
    return 1;
}

/* The argument loop and the technique list; returns the exit code (o->help: help printed). */
static int parse_args(gr_args *args, pareto_opts *o)
{
    const char *cmd = "pareto";
    int rc = 0, taken = 0;
    o->use_cache = 1;
    o->repeat = 5;
    o->ps.timing_cap_s = 2; /* --timing-cap */
    o->tech_flag = "--techniques";
    o->platform = GR_GL_AUTO;
    args->size_example = "320x180";
    for (; args->i < args->argc && !rc; args->i++) {
        const char *a = args->argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            o->help = 1;
            return 0;
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            o->quiet = 1;
        } else if (!strcmp(a, "--quick")) {
            o->quick = 1;
        } else if (!strcmp(a, "--techniques") || !strcmp(a, "--technique")) {
            o->tech_flag = a;
            if ((rc = gr_args_value(args, &o->tech_list)) != 0) break;
            if (!strcmp(a, "--technique") && strchr(o->tech_list, ','))
                rc = gr_cli_usage_error(cmd, "--technique %s: one technique (use --techniques for a list)", o->tech_list);
        } else if (!strcmp(a, "--no-cache")) {
            o->use_cache = 0;
        } else if (!strcmp(a, "--yes")) {
            o->yes = 1;
        } else if (!strcmp(a, "--repeat")) {
            const char *v;
            char *end = NULL;
            if ((rc = gr_args_value(args, &v)) != 0) break;
            errno = 0;
            o->repeat = strtol(v, &end, 10);
            if (errno || end == v || *end || o->repeat < 1 || o->repeat > 1000)
                rc = gr_cli_usage_error(cmd, "--repeat %s: expected an integer in [1, 1000]", v);
            o->have_repeat = 1;
        } else if (take_suite_option(args, o, &rc)) {
            if (rc) break;
        } else if ((rc = gr_args_take_common(args, &o->outopt, &o->platform, &taken)) == 0 && !taken) {
            rc = gr_args_take_scene(args);
        }
    }
    if (rc || (!o->ps.suite_path && (rc = gr_args_need_scene(args)) != 0)) return rc;
    if (o->ps.suite_path && args->scene_path)
        return gr_cli_usage_error(cmd, "--suite %s and the scene %s: give one of them", o->ps.suite_path, args->scene_path);
    if (!o->ps.suite_path && (o->ps.tune || o->ps.n_budgets))
        return gr_cli_usage_error(cmd, "--tune and --budgets need --suite SUITE");
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    gr_error lerr = {GR_OK, ""};
    if (gr_technique_parse_list(o->tech_flag, o->tech_list, o->techs, GR_TECH_MAX, &o->n_techs, &lerr) != GR_OK)
        return gr_cli_usage_error(cmd, "%s", lerr.msg);
    if (gr_tune_budget_init(&o->budget, "godrays pareto", "renders",
                            gr_tune_budget_ladders(o->techs, o->n_techs, o->quick, o->repeat), 1, o->yes, &lerr) != GR_OK)
        return gr_cli_report(cmd, &lerr);
    if (o->ps.suite_path) return 0; /* the suite's size unless --size */
    /* the default size after every override, so that it wins over --set camera.width/height */
    if (!args->have_size && (rc = gr_args_add_set(args, "camera.width=320")) != 0) return rc;
    if (!args->have_size && (rc = gr_args_add_set(args, "camera.height=180")) != 0) return rc;
    return 0;
}

/* The high-quality ground truth (*truth, cached), then the ground truth's own ladder: each
 * level timed (never cached) and scored against it; points appended to pts[*n]. */
static gr_status reference_points(const pareto_opts *o, const gr_scene *scene, gr_scene *work, gr_image **truth,
                                  gr_truth_info *ti, const gr_structure_options *so, gr_pareto_point *pts, int *n,
                                  gr_error *err)
{
    /* the high-quality ground truth, with its own seed so that no ladder level shares its
     * random numbers (a shared seed would make the lower levels look better than they are) */
    memcpy(work, scene, sizeof *work);
    const ref_level hq = make_level(&scene->reference, N_LEVELS);
    set_level(work, &hq);
    work->reference.seed = scene->reference.seed + 7919;
    gr_status st = gr_scene_refresh(work, err);
    if (st != GR_OK) return st;
    if (!o->quiet)
        fprintf(stderr, "godrays pareto: high-quality ground truth (%d x %d)...\n", work->camera.width, work->camera.height);
    gr_truth_options to;
    gr_truth_options_default(&to);
    to.use_cache = o->use_cache;
    to.ref.progress = !o->quiet;
    if ((st = gr_truth_image(work, &to, truth, ti, err)) != GR_OK) return st;
    if (!o->quiet && ti->cached) fprintf(stderr, "godrays pareto:   from the cache %s\n", ti->path);
    char coarse[320]; /* docs/reference.md 4, "Views with a wide lit region" */
    if (!o->quiet && gr_truth_coarse(ti, scene, coarse, sizeof coarse)) /* the remedy in the scene's setting */
        fprintf(stderr, "godrays pareto: warning: the high-quality ground truth: %s\n", coarse);
    to.use_cache = 0; /* each level is timed: rendered, never cached */
    const int n_levels = o->quick ? 2 : N_LEVELS;
    for (int l = 0; l < n_levels; l++) {
        memcpy(work, scene, sizeof *work);
        const ref_level lv = make_level(&scene->reference, l);
        set_level(work, &lv);
        if ((st = gr_scene_refresh(work, err)) != GR_OK) return st;
        if (!o->quiet) fprintf(stderr, "godrays pareto: ground truth %s...\n", lv.name);
        gr_image *ri = NULL;
        gr_truth_info li;
        if ((st = gr_truth_image(work, &to, &ri, &li, err)) != GR_OK) return st;
        const gr_metrics_options ro = verdict_options(so, 0);
        gr_metrics m;
        st = gr_metrics_compute(*truth, ri, &ro, &m, err);
        char thumb[64];
        gr_chart_thumb_name(*n, thumb, sizeof thumb);
        if (st == GR_OK) st = gr_chart_write_thumb(o->outdir, thumb, *truth, ri, err);
        gr_image_destroy(ri);
        if (st != GR_OK) return st;
        gr_pareto_point *p = &pts[(*n)++];
        p->family = GR_PARETO_REFERENCE;
        snprintf(p->family_name, sizeof p->family_name, "reference");
        snprintf(p->label, sizeof p->label, "%s", lv.name);
        snprintf(p->settings, sizeof p->settings, "sun_samples=%d;batches=%d;steps=%d;surface_res=%d;spp=%d",
                 lv.sun_samples, lv.batches, lv.steps, lv.surface_res, lv.spp);
        p->time_s = li.seconds;
        p->gpu_s = -1;
        p->cost_s = li.seconds;
        p->error = verdict(&m.raw);
    }
    return GR_OK;
}

/* One setting of a technique's ladder: warm timing (realtime/timing.h: a warm-up render,
 * then the median of o->repeat renders in one context) and the error after the best scale
 * fit against truth. */
static gr_status ladder_point(pareto_opts *o, const gr_technique_class *cls, gr_technique *r,
                              const gr_scene *scene, const char *lvs, const gr_image *truth,
                              const gr_structure_options *so, gr_image *img, gr_pareto_point *p, gr_error *err)
{
    gr_section_store s;
    memcpy(s.bytes, gr_technique_scene_settings(cls, scene), cls->settings_size);
    gr_timing tm;
    gr_status st = gr_technique_apply_text(cls, s.bytes, lvs, err);
    if (st == GR_OK) st = gr_timing_measure(r, scene, s.bytes, img, 1, (int)o->repeat, &tm, err);
    /* once, after the first level's warm-up and timed renders */
    char line[512];
    if (st == GR_OK && !o->quiet && gr_tune_budget_eta(&o->budget, 1 + o->repeat, line, sizeof line))
        fprintf(stderr, "%s\n", line);
    gr_metrics m;
    if (st == GR_OK) {
        const gr_metrics_options fo = verdict_options(so, 1);
        st = gr_metrics_compute(truth, img, &fo, &m, err);
    }
    if (st != GR_OK) return st;
    snprintf(p->family_name, sizeof p->family_name, "%s", cls->name);
    snprintf(p->label, sizeof p->label, "%s %s", cls->name, lvs[0] ? lvs : "(scene's settings)");
    for (char *c = p->label; *c; c++)
        if (*c == ',') *c = ' ';
    snprintf(p->settings, sizeof p->settings, "%s", lvs);
    for (char *c = p->settings; *c; c++)
        if (*c == ',') *c = ';';
    p->time_s = tm.wall_ms * 1e-3;
    p->gpu_s = tm.gpu_ms >= 0 ? tm.gpu_ms * 1e-3 : -1;
    p->error = verdict(&m.fit);
    return GR_OK;
}

/* The ladder points technique_points renders (--quick: the quick levels). */
static int count_points(const pareto_opts *o)
{
    int total = 0;
    for (int k = 0; k < o->n_techs; k++) {
        const gr_technique_class *cls = o->techs[k];
        for (int l = 0; l < (cls->n_ladder > 0 ? cls->n_ladder : 1); l++)
            total += !(o->quick && cls->n_ladder > 0 && !cls->ladder[l].quick);
    }
    return total;
}

/* Each technique over the settings of its ladder, which trade speed for quality; points
 * appended to pts[*n]; *gpu_any = 1 when some GL pass timer worked. */
static gr_status technique_points(pareto_opts *o, const gr_scene *scene, gr_gl *gl, const gr_image *truth,
                                  const gr_structure_options *so,
                                  gr_pareto_point *pts, int *n, int *gpu_any, gr_error *err)
{
    gr_image *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    gr_technique *r = NULL;
    gr_status st = img ? GR_OK : gr_fail(err, GR_E_NOMEM, "out of memory");
    char line[512];
    gr_tune_budget_plan_line(&o->budget, line, sizeof line);
    if (!o->quiet) fprintf(stderr, "%s\n", line);
    gr_tune_budget_start(&o->budget);
    /* a line per 10 % or 10 s with elapsed and remaining time when stderr is no terminal */
    gr_progress *bar = gr_progress_create("godrays pareto", !o->quiet);
    const int total = count_points(o);
    int done = 0;
    for (int k = 0; k < o->n_techs && st == GR_OK; k++) {
        const gr_technique_class *cls = o->techs[k];
        gr_technique_destroy(r);
        r = NULL;
        if ((st = gr_technique_create(cls, gl, NULL, &r, err)) != GR_OK) break;
        const int n_lv = cls->n_ladder > 0 ? cls->n_ladder : 1;
        for (int l = 0; l < n_lv && st == GR_OK; l++) {
            const char *lvs = cls->n_ladder > 0 ? cls->ladder[l].settings : "";
            if (o->quick && cls->n_ladder > 0 && !cls->ladder[l].quick) continue;
            if (*n >= MAX_POINTS) break;
            gr_pareto_point *p = &pts[*n];
            char thumb[64];
            gr_chart_thumb_name(*n, thumb, sizeof thumb);
            if ((st = ladder_point(o, cls, r, scene, lvs, truth, so, img, p, err)) != GR_OK) break;
            if ((st = gr_chart_write_thumb(o->outdir, thumb, truth, img, err)) != GR_OK) break;
            (*n)++;
            p->family = 1 + k;
            if (p->gpu_s >= 0) *gpu_any = 1;
            gr_progress_finish(bar);
            if (!o->quiet) fprintf(stderr, "godrays pareto: %s: %.2f ms, error %.4g\n", p->label, 1e3 * p->time_s, p->error);
            snprintf(line, sizeof line, "%d of %d ladder points", ++done, total);
            gr_progress_update(bar, total ? (double)done / total : 1.0, line);
        }
    }
    gr_progress_destroy(bar);
    gr_technique_destroy(r);
    gr_image_destroy(img);
    return st;
}

/* The page's interactive chart (report/chart.h): one series per family, each point's
 * tooltip (setting, times, verdict) and thumbnail. */
static void page_chart(gr_strbuf *pg, const char *title, const char *tlabel, const char *glr,
                       const gr_pareto_point *pts, int n, int drawn)
{
    gr_chart c;
    memset(&c, 0, sizeof c);
    gr_chart_point *cp = calloc((size_t)(n > 0 ? n : 1), sizeof *cp);
    if (!cp) {
        gr_sb_puts(pg, "<p>(no chart: out of memory)</p>\n");
        return;
    }
    int family[GR_CHART_MAX_SERIES];
    for (int i = 0; i < n; i++) {
        int s = 0;
        while (s < c.n_series && family[s] != pts[i].family) s++;
        if (s == c.n_series && c.n_series < GR_CHART_MAX_SERIES) {
            family[s] = pts[i].family;
            snprintf(c.series[s].name, sizeof c.series[s].name, "%s", pts[i].family_name);
            c.series[s].color = pts[i].family;
            c.series[s].hollow = pts[i].family == GR_PARETO_REFERENCE;
            c.n_series++;
        }
        char g[32];
        if (pts[i].gpu_s >= 0) snprintf(g, sizeof g, "%.4g ms", 1e3 * pts[i].gpu_s);
        else snprintf(g, sizeof g, "n/a");
        cp[i] = (gr_chart_point){.series = s < c.n_series ? s : -1, .x = 1e3 * pts[i].cost_s, .y = pts[i].error,
                                 .on_front = pts[i].on_front};
        snprintf(cp[i].title, sizeof cp[i].title, "%s", pts[i].label);
        snprintf(cp[i].lines, sizeof cp[i].lines, "settings: %s\ntime: %.4g ms (wall %.4g ms, GL timers %s)\n"
                 "error (verdict): %.4g%s", pts[i].settings, 1e3 * pts[i].cost_s, 1e3 * pts[i].time_s, g, pts[i].error,
                 pts[i].on_front ? "\non its family's front" : "");
        gr_chart_thumb_name(i, cp[i].thumb, sizeof cp[i].thumb);
    }
    char xlab[200], sub[300];
    snprintf(xlab, sizeof xlab, "time per frame (ms, log): %s; reference: whole render", tlabel);
    c.id = "pareto";
    snprintf(sub, sizeof sub, "GL_RENDERER: %.200s%s", glr ? glr : "?",
             gr_timing_is_cpu_renderer(glr) ? ": CPU-rasterizer times, which do NOT stand for a GPU's" : "");
    c.title = title;
    c.subtitle = sub;
    c.x_label = xlab;
    c.y_label = "error (verdict against the high-quality ground truth)";
    c.png = drawn ? "pareto.png" : NULL;
    c.log_y = 1;
    c.n_points = n;
    c.points = cp;
    char why[512];
    gr_chart_html(pg, &c, why, sizeof why);
    free(cp);
}

/* pareto.csv, pareto.png, the summary (printed) and index.html. */
static gr_status write_outputs(const gr_scene *scene, const gr_truth_info *ti, const char *glr, int is_llvmpipe,
                               int by_gpu, int gpu_any, const gr_pareto_point *pts, int n, const char *outdir,
                               gr_error *err)
{
    char tlabel[128], title[256], path[4300];
    snprintf(tlabel, sizeof tlabel, "%s", is_llvmpipe ? "llvmpipe wall time" : by_gpu ? "GPU time of the GL passes" : "GPU frame wall time");
    snprintf(title, sizeof title, "speed vs error, scene '%s' %dx%d (real time on %s)", scene->name, scene->camera.width,
             scene->camera.height, is_llvmpipe ? "llvmpipe, no GPU" : glr);
    gr_status st = gr_report_make_dir(outdir, err);
    if (st != GR_OK) return st;
    snprintf(path, sizeof path, "%s/pareto.csv", outdir);
    if ((st = gr_pareto_write_csv(path, pts, n, err)) != GR_OK) return st;
    int drawn = 0;
    snprintf(path, sizeof path, "%s/pareto.png", outdir);
    if ((st = gr_pareto_write_plot(path, pts, n, title, tlabel, &drawn, err)) != GR_OK) return st;

    gr_strbuf sum;
    gr_sb_init(&sum);
    gr_sb_printf(&sum, "scene '%s' (%d x %d); high-quality ground truth %.1f s (%s); real time on %s\n", scene->name,
           scene->camera.width, scene->camera.height, ti->seconds, ti->cached ? "from the cache" : "rendered", glr);
    gr_sb_printf(&sum, "%-16s %-50s %12s %12s %12s %6s\n", "family", "setting", "time ms", "GL timers ms", "verdict", "front");
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
    gr_strbuf pg;
    gr_sb_init(&pg);
    gr_tune_page_begin(&pg, outdir, "godrays pareto: %s", scene->name);
    page_chart(&pg, title, tlabel, glr, pts, n, drawn);
    st = gr_tune_page_write(&pg, gr_sb_str(&sum), drawn ? "pareto.csv,pareto.png" : "pareto.csv", outdir, err);
    gr_sb_free(&sum);
    return st;
}

/* Everything after the command line. */
static gr_status pareto_scene(pareto_opts *o, const gr_scene *scene, const char *outdir, gr_error *err)
{
    gr_scene *work = malloc(sizeof *work);
    gr_pareto_point *pts = calloc(MAX_POINTS, sizeof *pts);
    gr_image *truth = NULL;
    gr_gl *gl = NULL;
    gr_truth_info ti;
    int n = 0, gpu_any = 0;
    gr_gl_options glo;
    memset(&glo, 0, sizeof glo);
    glo.platform = o->platform;
    float *angles = malloc((size_t)scene->camera.width * (size_t)scene->camera.height * sizeof *angles);
    gr_structure_options so; /* the verdict's structure term (report/profile.h) */
    gr_status st = work && pts && angles ? GR_OK : gr_fail(err, GR_E_NOMEM, "out of memory");
    o->outdir = outdir;
    if (st == GR_OK && !gr_profile_structure_options(scene, angles, &so) && !o->quiet)
        fprintf(stderr, "godrays pareto: the beams have no vanishing point in this view: error = the error term alone\n");
    if (st == GR_OK) st = gr_gl_create(&glo, &gl, err); /* before the slow ground truths */
    if (st == GR_OK) st = reference_points(o, scene, work, &truth, &ti, &so, pts, &n, err);
    if (st == GR_OK) st = technique_points(o, scene, gl, truth, &so, pts, &n, &gpu_any, err);
    if (st == GR_OK) {
        const char *glr = gr_gl_renderer(gl);
        int is_llvmpipe = glr && strstr(glr, "llvmpipe") != NULL;
        /* What the techniques cost: on a hardware GPU the GL pass timers (a render's wall time
         * there is mostly this harness's synchronous float readback: docs/benchmarks.md); on
         * llvmpipe the wall time (its timers see a deferred rasterizer). */
        int by_gpu = !is_llvmpipe && gpu_any;
        for (int i = 0; i < n; i++)
            if (pts[i].family != GR_PARETO_REFERENCE)
                pts[i].cost_s = by_gpu && pts[i].gpu_s >= 0 ? pts[i].gpu_s : pts[i].time_s;
        gr_pareto_mark_fronts(pts, n);
        st = write_outputs(scene, &ti, glr, is_llvmpipe, by_gpu, gpu_any, pts, n, outdir, err);
    }
    gr_image_destroy(truth);
    gr_gl_destroy(gl);
    free(pts);
    free(work);
    free(angles);
    return st;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int pareto_with(gr_args *args)
{
    const char *cmd = "pareto";
    pareto_opts o;
    memset(&o, 0, sizeof o);
    int rc = parse_args(args, &o);
    if (rc || o.help) return rc;
    gr_error err = {GR_OK, ""};
    gr_scene *scene = NULL;
    char dirbuf[4096];
    const char *outdir = NULL;
    if (o.ps.suite_path) {
        o.ps.outopt = o.outopt;
        o.ps.quick = o.quick, o.ps.quiet = o.quiet, o.ps.use_cache = o.use_cache, o.ps.platform = o.platform;
        o.ps.repeat = o.have_repeat ? (int)o.repeat : 0; /* 0: 3 on a CPU rasterizer, 5 on a GPU */
        if (o.ps.timing_w <= 0) o.ps.timing_w = 1920, o.ps.timing_h = 1080;
        o.ps.techs = o.techs;
        o.ps.n_techs = o.n_techs;
        return gr_pareto_suite(args, &o.ps);
    }
    if ((rc = gr_args_load_scene(args, &scene)) != 0) return rc;
    for (int k = 0; k < o.n_techs && !rc; k++)
        if (gr_technique_check(o.techs[k], gr_technique_scene_settings(o.techs[k], scene), &err) != GR_OK)
            rc = gr_cli_report(cmd, &err);
    /* The ground truths take minutes: a folder that cannot be made is refused before them. */
    if (!rc) rc = gr_args_output_dir(args, scene, o.outopt, "pareto", dirbuf, sizeof dirbuf, &outdir);
    if (!rc && pareto_scene(&o, scene, outdir, &err) != GR_OK) rc = gr_cli_report(cmd, &err);
    free(scene);
    return rc;
}

int cmd_pareto(int argc, char **argv)
{
    return gr_args_main("pareto", argc, argv, pareto_with);
}
