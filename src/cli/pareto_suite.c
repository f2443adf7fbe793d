/* pareto --suite (pareto_suite.h). */
#include "cli/pareto_suite.h"
#include "cli/cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "common/outfile.h"
#include "compare/baseline.h"
#include "reference/truth.h"
#include "report/chart.h"
#include "report/html.h"
#include "report/report.h"
#include "suite/suite.h"
#include "tune/page.h"
#include "tune/pareto.h"
#include "tune/preset.h"
#include "tune/suitetune.h"

#define PS_MAX_POINTS 512

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* What the run holds; ps_free frees it. */
typedef struct ps_run {
    gr_suite *suite;
    gr_image **truths;
    gr_st_case *cases;
    gr_scene *timing_scene;   /* the first train case at the timing size */
    gr_gl *gl;
    gr_st_point *pts;
    int n;
    double truth_s, tune_s, time_s;
    gr_baselines *bl;         /* the blur ladder over the test cases (equivalent blur) */
    const char *dir;          /* the output folder (thumbnails are written as points come) */
    int repeat;               /* renders timed per point: --repeat, else 3 on a CPU rasterizer, 5 on a GPU */
    int thumb_case;           /* the case the thumbnails show: the first test case */
} ps_run;

static void ps_free(ps_run *r)
{
    for (int i = 0; r->suite && r->truths && i < r->suite->n_cases; i++) gr_image_destroy(r->truths[i]);
    free(r->truths);
    free(r->cases);
    free(r->timing_scene);
    free(r->pts);
    free(r->bl);
    gr_gl_destroy(r->gl);
    gr_suite_destroy(r->suite);
}

/* Every case's ground truth through the provider (cached); the timing scene. */
static gr_status truths(const gr_ps_opts *o, ps_run *r, gr_error *err)
{
    const int n = r->suite->n_cases;
    r->truths = calloc((size_t)n, sizeof *r->truths);
    r->cases = calloc((size_t)n, sizeof *r->cases);
    r->timing_scene = malloc(sizeof *r->timing_scene);
    if (!r->truths || !r->cases || !r->timing_scene) return gr_fail(err, GR_E_NOMEM, "out of memory");
    gr_truth_options to;
    gr_truth_options_default(&to);
    to.use_cache = o->use_cache;
    to.ref.progress = !o->quiet;
    const double t0 = now_s();
    int first_train = -1;
    for (int i = 0; i < n; i++) {
        gr_suite_case *c = &r->suite->cases[i];
        gr_truth_info ti;
        if (!o->quiet) fprintf(stderr, "godrays pareto: ground truth of case %s (%s)...\n", c->name, gr_split_name(c->split));
        gr_status st = gr_truth_image(&c->scene, &to, &r->truths[i], &ti, err);
        if (st != GR_OK) return gr_error_prefix(err, "%s: case %s", r->suite->path, c->name);
        char coarse[320]; /* docs/reference.md 4, "Views with a wide lit region" */
        if (!o->quiet && gr_truth_coarse(&ti, &c->scene, coarse, sizeof coarse))
            fprintf(stderr, "godrays pareto: warning: the ground truth of case %s: %s\n", c->name, coarse);
        r->cases[i] = (gr_st_case){&c->scene, r->truths[i], c->split};
        if (first_train < 0 && c->split == GR_SPLIT_TRAIN) first_train = i;
        if (c->split == GR_SPLIT_TEST && r->suite->cases[r->thumb_case].split != GR_SPLIT_TEST) r->thumb_case = i;
    }
    r->truth_s = now_s() - t0;
    if (first_train < 0 || gr_suite_count(r->suite, GR_SPLIT_TEST) == 0)
        return gr_fail(err, GR_E_INPUT, "%s: --tune needs train and test cases (%d train, %d test)", r->suite->path,
                       gr_suite_count(r->suite, GR_SPLIT_TRAIN), gr_suite_count(r->suite, GR_SPLIT_TEST));
    memcpy(r->timing_scene, &r->suite->cases[first_train].scene, sizeof *r->timing_scene);
    r->timing_scene->camera.width = o->timing_w;
    r->timing_scene->camera.height = o->timing_h;
    return gr_scene_refresh(r->timing_scene, err);
}

/* Point k's thumbnail (report/chart.h): its settings rendered on the thumbnail case. */
static gr_status thumbnail(ps_run *r, gr_technique *t, int k, gr_error *err)
{
    const gr_scene *sc = &r->suite->cases[r->thumb_case].scene;
    gr_image *img = gr_image_create(sc->camera.width, sc->camera.height, 3, NULL);
    gr_status st = img ? GR_OK : gr_fail(err, GR_E_NOMEM, "out of memory");
    if (st == GR_OK) st = gr_technique_render(t, sc, r->pts[k].settings.bytes, img, NULL, err);
    char name[64];
    gr_chart_thumb_name(k, name, sizeof name);
    if (st == GR_OK) st = gr_chart_write_thumb(r->dir, name, r->truths[r->thumb_case], img, err);
    gr_image_destroy(img);
    return st;
}

/* Ladder position k's point of one technique: untuned (and tuned, *tu non-NULL) at level lv
 * (-1: the scene's settings), tuned from so (the continuation's from[] set by the caller). */
static gr_status tune_one(const gr_ps_opts *o, ps_run *r, gr_technique *t, int lv, const gr_st_options *so,
                          gr_st_point *u, gr_st_point *tu, gr_error *err)
{
    const double t0 = now_s();
    gr_status st = gr_st_tune_level(t, r->cases, r->suite->n_cases, lv, so, u, tu, err);
    r->tune_s += now_s() - t0;
    if (st == GR_OK && !o->quiet && tu) {
        char budget[64] = "";
        if (tu->budget > 0) snprintf(budget, sizeof budget, " of a budget of %d", tu->budget);
        fprintf(stderr, "godrays pareto: %s %s: tuned by the %s search (%d evaluations%s, %.1f s): train %.4g, test "
                "%.4g (untuned %.4g, %.4g)\n", u->cls->name, u->ladder[0] ? u->ladder : "(scene's)",
                gr_st_search_name(tu->local), tu->evals, budget, now_s() - t0, tu->train_error, tu->test_error,
                u->train_error, u->test_error);
    }
    return st;
}

/* One technique: each ladder point untuned (and tuned with --tune: the global search at the
 * anchor, the middle of the ladder, the continuation's local search at the others, or the
 * global one everywhere with --tune-full; tune/suitetune.h), each timed, in ladder order. */
static gr_status technique(const gr_ps_opts *o, ps_run *r, const gr_technique_class *cls, gr_error *err)
{
    gr_technique *t = NULL;
    gr_status st = gr_technique_create(cls, r->gl, NULL, &t, err);
    int lv[PS_MAX_POINTS], n = 0, order[PS_MAX_POINTS], prev[PS_MAX_POINTS];
    for (int l = 0; l < (cls->n_ladder > 0 ? cls->n_ladder : 1) && n < PS_MAX_POINTS; l++)
        if (!(o->quick && cls->n_ladder > 0 && !cls->ladder[l].quick)) lv[n++] = cls->n_ladder > 0 ? l : -1;
    if (r->n + 2 * n > PS_MAX_POINTS) n = (PS_MAX_POINTS - r->n) / 2;
    gr_st_point *u = &r->pts[r->n], *tu = &r->pts[r->n + n]; /* tuned points after the untuned, then interleaved */
    const int a = gr_st_continuation_order(n, order, prev);
    /* the search budget's reference: the work of the cheapest (first) point's train evaluation */
    double work_ref = 0.0;
    if (st == GR_OK && o->tune && !o->tune_full && !o->no_search_budget && n > 1) {
        gr_st_point u0;
        const gr_st_options so = {.seed = o->seed};
        st = gr_st_tune_level(t, r->cases, r->suite->n_cases, lv[0], &so, &u0, NULL, err);
        work_ref = u0.work;
    }
    for (int k = 0; k < n && st == GR_OK; k++) {
        const int i = order[k];
        gr_st_options so = {.max_evals = o->max_evals, .seed = o->seed, .local_evals = o->local_evals,
                            .work_ref = work_ref};
        if (o->tune && !o->tune_full && prev[k] >= 0) gr_st_continue_from(&so, &tu[a], &tu[order[prev[k]]]);
        st = tune_one(o, r, t, lv[i], &so, &u[i], o->tune ? &tu[i] : NULL, err);
    }
    if (st == GR_OK && o->tune) { /* interleave: each untuned point followed by its tuned one */
        gr_st_point *tmp = malloc((size_t)(2 * (n > 0 ? n : 1)) * sizeof *tmp);
        if (!tmp) st = gr_fail(err, GR_E_NOMEM, "out of memory");
        for (int i = 0; i < n && tmp; i++) tmp[2 * i] = u[i], tmp[2 * i + 1] = tu[i];
        if (tmp) memcpy(u, tmp, (size_t)(2 * n) * sizeof *tmp);
        free(tmp);
    }
    const int m = o->tune ? 2 * n : n;
    for (int k = 0; k < m && st == GR_OK; k++) {
        gr_st_point *p = &r->pts[r->n];
        const double t0 = now_s();
        st = gr_st_time_point(t, r->timing_scene, r->repeat, o->timing_cap_s, p, err);
        r->time_s += now_s() - t0;
        if (st == GR_OK) st = thumbnail(r, t, r->n, err);
        if (st != GR_OK) break;
        r->n++;
        if (!o->quiet)
            fprintf(stderr, "godrays pareto: %s %s %s: %.2f ms (%d timed%s), train %.4g, test %.4g\n", cls->name,
                    p->ladder[0] ? p->ladder : "(scene's)", p->tuned ? "tuned" : "untuned", p->timing.cost_ms,
                    p->timing.n, p->timing.warmup ? "" : ", no warm-up", p->train_error, p->test_error);
    }
    gr_technique_destroy(t);
    return st;
}

/* The header every table and chart of times carries: the renderer and what its times mean. */
static const char *run_renderer(const ps_run *r)
{
    return r->n > 0 ? r->pts[0].timing.renderer : gr_gl_renderer(r->gl);
}

static void time_header(const ps_run *r, const gr_ps_opts *o, char *buf, size_t n)
{
    const char *glr = run_renderer(r);
    char cap[96] = "";
    if (o->timing_cap_s > 0)
        snprintf(cap, sizeof cap, "; fewer once the timed renders took %g s", o->timing_cap_s);
    if (gr_timing_is_cpu_renderer(glr))
        snprintf(buf, n, "times on %s at %dx%d: CPU-rasterizer wall times (median of up to %d after a warm-up%s), which "
                 "do NOT stand for a GPU's", glr, o->timing_w, o->timing_h, r->repeat, cap);
    else
        snprintf(buf, n, "times on %s at %dx%d: GPU time of the GL passes (timer queries; median of up to %d after a "
                 "warm-up%s)", glr, o->timing_w, o->timing_h, r->repeat, cap);
}

/* fronts.csv: every point. */
static gr_status write_fronts_csv(const char *dir, const ps_run *r, gr_error *err)
{
    char path[4300], label[512];
    gr_strbuf b;
    gr_sb_init(&b);
    gr_sb_puts(&b, "technique,tuned,ladder,label,cost_ms,wall_ms,gpu_ms,wall_min_ms,wall_max_ms,train_error,test_error,"
                   "on_front,timed_renders,warmups,search,evals,budget,work,renderer\n");
    for (int i = 0; i < r->n; i++) {
        const gr_st_point *p = &r->pts[i];
        gr_st_point_label(p, label, sizeof label);
        for (char *c = label; *c; c++)
            if (*c == ',') *c = ';';
        char lad[200];
        snprintf(lad, sizeof lad, "%s", p->ladder);
        for (char *c = lad; *c; c++)
            if (*c == ',') *c = ';';
        gr_sb_printf(&b, "%s,%d,%s,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%s,%d,%d,%.6g,%s\n", p->cls->name, p->tuned, lad,
                     label, p->timing.cost_ms, p->timing.wall_ms, p->timing.gpu_ms, p->timing.wall_min_ms,
                     p->timing.wall_max_ms, p->train_error, p->test_error, p->on_front, p->timing.n,
                     p->timing.warmup, !p->tuned ? "none" : gr_st_search_name(p->local), p->evals, p->budget, p->work,
                     p->timing.renderer);
    }
    snprintf(path, sizeof path, "%s/fronts.csv", dir);
    gr_status st = gr_outfile_write(path, gr_sb_str(&b), -1, err);
    gr_sb_free(&b);
    return st;
}

/* The chart: time against TEST error, tuned and untuned families of every technique. */
static gr_status write_plot(const char *dir, const ps_run *r, const char *header, int *drawn, gr_error *err)
{
    gr_pareto_point *pp = calloc((size_t)(r->n > 0 ? r->n : 1), sizeof *pp);
    if (!pp) return gr_fail(err, GR_E_NOMEM, "out of memory");
    for (int i = 0; i < r->n; i++) {
        const gr_st_point *p = &r->pts[i];
        pp[i].family = 1 + 2 * gr_technique_index(p->cls) + p->tuned;
        snprintf(pp[i].family_name, sizeof pp[i].family_name, "%s %s", p->cls->name, p->tuned ? "tuned" : "untuned");
        pp[i].cost_s = pp[i].time_s = 1e-3 * p->timing.cost_ms;
        pp[i].error = p->test_error;
        pp[i].on_front = p->on_front;
        pp[i].colour = 1 + gr_technique_index(p->cls); /* one colour per technique, untuned lighter */
        pp[i].light = !p->tuned;
    }
    char path[4300], title[700];
    snprintf(path, sizeof path, "%s/fronts.png", dir);
    snprintf(title, sizeof title, "test error vs time per frame (%s)", header);
    gr_status st = gr_pareto_write_plot(path, pp, r->n, title, "", drawn, err);
    free(pp);
    return st;
}

/* The budget table (printed, budgets.csv) and one preset per row (presets/budget_Bms.json). */
static gr_status budget_table(const gr_ps_opts *o, const ps_run *r, const int *pick, const char *dir,
                              const char *header, gr_strbuf *sum, gr_error *err)
{
    char path[4400];
    snprintf(path, sizeof path, "%s/presets", dir);
    gr_status st = gr_report_make_dir(path, err);
    gr_strbuf csv;
    gr_sb_init(&csv);
    gr_sb_puts(&csv, "budget_ms,technique,settings,time_ms,train_error,test_error,generalization_gap,eq_blur_px,preset\n");
    gr_sb_printf(sum, "\nbudget table (%s);\nchosen by TRAIN error among the points within the budget, scored on the %d "
                 "test cases:\n", header, gr_suite_count(r->suite, GR_SPLIT_TEST));
    gr_sb_printf(sum, "%9s  %-12s %9s %9s %9s %8s %10s  %s\n", "budget ms", "technique", "time ms", "train", "test", "gap",
                 "eq. blur", "settings");
    for (int b = 0; b < o->n_budgets && st == GR_OK; b++) {
        if (pick[b] < 0) {
            gr_sb_printf(sum, "%9g  (no point within the budget)\n", o->budgets_ms[b]);
            gr_sb_printf(&csv, "%g,,,,,,,,\n", o->budgets_ms[b]);
            continue;
        }
        const gr_st_point *p = &r->pts[pick[b]];
        char label[512], eq[32], file[64];
        gr_st_point_label(p, label, sizeof label);
        gr_equivalent_blur_text(r->bl, p->test_error, eq, sizeof eq);
        snprintf(file, sizeof file, "budget_%gms.json", o->budgets_ms[b]);
        gr_preset_info info;
        gr_preset_info_clear(&info);
        snprintf(info.renderer, sizeof info.renderer, "%s", p->timing.renderer);
        info.timing_width = o->timing_w, info.timing_height = o->timing_h;
        info.time_ms = p->timing.cost_ms;
        info.cpu_rasterizer = !p->timing.hardware;
        info.budget_ms = o->budgets_ms[b];
        info.test_error = p->test_error, info.train_error = p->train_error;
        info.eq_blur_px = gr_equivalent_blur(r->bl, p->test_error, NULL);
        snprintf(info.suite, sizeof info.suite, "%s", r->suite->path);
        info.error_width = r->suite->cases[0].scene.camera.width;
        info.error_height = r->suite->cases[0].scene.camera.height;
        snprintf(path, sizeof path, "%s/presets/%s", dir, file);
        st = gr_preset_write(path, p->cls, p->settings.bytes, &info, err);
        gr_sb_printf(sum, "%9g  %-12s %9.3f %9.4g %9.4g %8.3g %10s  %s%s  -> presets/%s\n", o->budgets_ms[b], p->cls->name,
                     p->timing.cost_ms, p->train_error, p->test_error, p->test_error - p->train_error, eq,
                     p->tuned ? "tuned: " : "untuned: ", label, file);
        for (char *c = label; *c; c++)
            if (*c == ',') *c = ';';
        gr_sb_printf(&csv, "%g,%s,%s,%.6g,%.6g,%.6g,%.6g,%.4g,presets/%s\n", o->budgets_ms[b], p->cls->name, label,
                     p->timing.cost_ms, p->train_error, p->test_error, p->test_error - p->train_error,
                     info.eq_blur_px, file);
    }
    snprintf(path, sizeof path, "%s/budgets.csv", dir);
    if (st == GR_OK) st = gr_outfile_write(path, gr_sb_str(&csv), -1, err);
    gr_sb_free(&csv);
    return st;
}

/* The page's interactive chart (report/chart.h) of the fronts: one series per technique and
 * kind (tuned filled, untuned hollow), each point's tooltip and thumbnail. */
static void page_chart(gr_strbuf *pg, const ps_run *r, const char *header, int drawn)
{
    gr_chart c;
    memset(&c, 0, sizeof c);
    gr_chart_point *cp = calloc((size_t)(r->n > 0 ? r->n : 1), sizeof *cp);
    if (!cp) {
        gr_sb_puts(pg, "<p>(no chart: out of memory)</p>\n");
        return;
    }
    char title[600], label[512], ylab[160];
    snprintf(title, sizeof title, "Test error against time per frame, tuned and untuned fronts (GL_RENDERER: %s)",
             run_renderer(r));
    snprintf(ylab, sizeof ylab, "test error (mean verdict over the %d test cases)", gr_suite_count(r->suite, GR_SPLIT_TEST));
    int family[GR_CHART_MAX_SERIES];
    for (int i = 0; i < r->n; i++) {
        const gr_st_point *p = &r->pts[i];
        const int fam = 2 * gr_technique_index(p->cls) + p->tuned;
        int s = 0;
        while (s < c.n_series && family[s] != fam) s++;
        if (s == c.n_series && c.n_series < GR_CHART_MAX_SERIES) {
            family[s] = fam;
            snprintf(c.series[s].name, sizeof c.series[s].name, "%s %s", p->cls->name, p->tuned ? "tuned" : "untuned");
            c.series[s].color = gr_technique_index(p->cls);
            c.series[s].hollow = !p->tuned;
            c.n_series++;
        }
        gr_st_point_label(p, label, sizeof label);
        cp[i] = (gr_chart_point){.series = s < c.n_series ? s : -1, .x = p->timing.cost_ms, .y = p->test_error,
                                 .on_front = p->on_front};
        snprintf(cp[i].title, sizeof cp[i].title, "%s, %s", p->cls->name, p->tuned ? "tuned" : "untuned");
        snprintf(cp[i].lines, sizeof cp[i].lines, "ladder: %.200s\nsettings: %.400s\ntime: %.4g ms%s\ntrain error: %.4g\n"
                 "test error: %.4g (gap %+.3g)\nthumbnail: test case %.64s", p->ladder[0] ? p->ladder : "(scene's)", label,
                 p->timing.cost_ms, p->timing.hardware ? " (GPU)" : " (CPU-rasterizer wall)", p->train_error,
                 p->test_error, p->test_error - p->train_error, r->suite->cases[r->thumb_case].name);
        gr_chart_thumb_name(i, cp[i].thumb, sizeof cp[i].thumb);
    }
    c.id = "fronts";
    c.title = title;
    c.subtitle = header;
    c.x_label = "time per frame (ms, log)";
    c.y_label = ylab;
    c.png = drawn ? "fronts.png" : NULL;
    c.log_y = 1;
    c.n_points = r->n;
    c.points = cp;
    char why[512];
    gr_sb_puts(pg, "<h2>Fronts</h2>\n");
    gr_chart_html(pg, &c, why, sizeof why);
    gr_sb_puts(pg, "<p>Thumbnails: test case ");
    gr_sb_html(pg, r->suite->cases[r->thumb_case].name);
    gr_sb_puts(pg, "; its ground truth: <a href=\"thumbs/truth.png\">thumbs/truth.png</a>. Every point's row is in "
                   "fronts.csv.</p>\n");
    free(cp);
}

/* The budget table in the page: a row per budget, hovering it highlights its point. */
static void page_budgets(gr_strbuf *pg, const gr_ps_opts *o, const ps_run *r, const int *pick, const char *header)
{
    gr_sb_puts(pg, "<h2>Budget table</h2>\n<p><b>");
    gr_sb_html(pg, header);
    gr_sb_printf(pg, "</b>. Chosen by TRAIN error among the points within the budget, scored on the %d test cases. Hover a "
                "row: its point on the chart.</p>\n<table class=\"budgets\"><tr><th>budget ms</th><th>technique</th>"
                "<th>time ms</th><th>train</th><th>test</th><th>gap</th><th>eq. blur</th><th>settings</th><th>preset</th>"
                "<th>thumbnail</th></tr>\n", gr_suite_count(r->suite, GR_SPLIT_TEST));
    for (int b = 0; b < o->n_budgets; b++) {
        if (pick[b] < 0) {
            gr_sb_printf(pg, "<tr><td>%g</td><td colspan=\"9\">no point within the budget</td></tr>\n", o->budgets_ms[b]);
            continue;
        }
        const gr_st_point *p = &r->pts[pick[b]];
        char label[512], eq[32], thumb[64];
        gr_st_point_label(p, label, sizeof label);
        gr_equivalent_blur_text(r->bl, p->test_error, eq, sizeof eq);
        gr_chart_thumb_name(pick[b], thumb, sizeof thumb);
        gr_sb_puts(pg, "<tr");
        gr_chart_row_attrs(pg, "fronts", pick[b]);
        gr_sb_printf(pg, "><td>%g</td><td>", o->budgets_ms[b]);
        gr_sb_html(pg, p->cls->name);
        gr_sb_printf(pg, "</td><td>%.3f</td><td>%.4g</td><td>%.4g</td><td>%.3g</td><td>", p->timing.cost_ms,
                     p->train_error, p->test_error, p->test_error - p->train_error);
        gr_sb_html(pg, eq);
        gr_sb_puts(pg, "</td><td>");
        gr_sb_htmlf(pg, "%s%s", p->tuned ? "tuned: " : "untuned: ", label);
        gr_sb_printf(pg, "</td><td><a href=\"presets/budget_%gms.json\">budget_%gms.json</a></td>", o->budgets_ms[b],
                     o->budgets_ms[b]);
        gr_sb_printf(pg, "<td><img src=\"%s\" alt=\"thumbnail\" class=\"thumb\"></td></tr>\n", thumb);
    }
    gr_sb_puts(pg, "</table>\n<style>table.budgets{border-collapse:collapse;margin:1em 0}table.budgets td,table.budgets th"
                   "{border:1px solid #ccc;padding:.2em .5em;text-align:left}img.thumb{width:128px;border:0}</style>\n");
}

static gr_status outputs(const gr_ps_opts *o, ps_run *r, const char *dir, double wall_s, gr_error *err)
{
    char header[512], label[512];
    time_header(r, o, header, sizeof header);
    gr_st_mark_fronts(r->pts, r->n);
    gr_status st = gr_report_make_dir(dir, err);
    int drawn = 0;
    if (st == GR_OK) st = write_fronts_csv(dir, r, err);
    /* the chart's header, short (its page and the tables carry the whole one) */
    char chart_head[600];
    const char *glr = run_renderer(r);
    snprintf(chart_head, sizeof chart_head, "at %dx%d on %s: %s", o->timing_w, o->timing_h, glr,
             gr_timing_is_cpu_renderer(glr) ? "CPU-rasterizer wall times, NOT a GPU's" : "GPU time of the GL passes");
    if (st == GR_OK) st = write_plot(dir, r, chart_head, &drawn, err);
    gr_strbuf sum;
    gr_sb_init(&sum);
    gr_sb_printf(&sum, "suite %s: %d cases (%d train, %d test) at %dx%d; %s\n", r->suite->path, r->suite->n_cases,
                 gr_suite_count(r->suite, GR_SPLIT_TRAIN), gr_suite_count(r->suite, GR_SPLIT_TEST),
                 r->suite->cases[0].scene.camera.width, r->suite->cases[0].scene.camera.height, header);
    gr_sb_printf(&sum, "%-12s %-7s %10s %9s %9s %5s  %s\n", "technique", "", "time ms", "train", "test", "front", "settings");
    for (int i = 0; i < r->n; i++) {
        const gr_st_point *p = &r->pts[i];
        gr_st_point_label(p, label, sizeof label);
        gr_sb_printf(&sum, "%-12s %-7s %10.3f %9.4g %9.4g %5s  %s\n", p->cls->name, p->tuned ? "tuned" : "untuned",
                     p->timing.cost_ms, p->train_error, p->test_error, p->on_front ? "*" : "", label);
    }
    int pick[GR_PS_MAX_BUDGETS];
    gr_st_pick(r->pts, r->n, o->budgets_ms, o->n_budgets, pick);
    if (st == GR_OK && o->n_budgets > 0) st = budget_table(o, r, pick, dir, header, &sum, err);
    if (st == GR_OK) st = gr_chart_write_thumb(dir, "thumbs/truth.png", NULL, r->truths[r->thumb_case], err);
    gr_sb_printf(&sum, "\nseconds: ground truths %.1f, tuning and scoring %.1f, timing %.1f, all %.1f (seed %llu)\n",
                 r->truth_s, r->tune_s, r->time_s, wall_s, o->seed);
    gr_sb_printf(&sum, "written: %s/fronts.csv%s%s\n", dir, drawn ? ", fronts.png" : " (no chart: PLplot missing)",
                 o->n_budgets > 0 ? ", budgets.csv, presets/" : "");
    fputs(gr_sb_str(&sum), stdout);
    gr_strbuf pg;
    gr_sb_init(&pg);
    gr_tune_page_begin(&pg, dir, "godrays pareto --suite: %s", r->suite->name);
    page_chart(&pg, r, header, drawn);
    if (o->n_budgets > 0) page_budgets(&pg, o, r, pick, header);
    gr_sb_puts(&pg, "<h2>Summary</h2>\n");
    if (st == GR_OK) st = gr_tune_page_write(&pg, gr_sb_str(&sum), drawn ? "fronts.csv,fronts.png" : "fronts.csv", dir, err);
    else gr_sb_free(&pg);
    gr_sb_free(&sum);
    return st;
}

int gr_pareto_suite(gr_args *args, const gr_ps_opts *o)
{
    const char *cmd = "pareto";
    ps_run r;
    memset(&r, 0, sizeof r);
    gr_error err = {GR_OK, ""};
    int rc = gr_args_load_suite(args, o->suite_path, &r.suite);
    char dirbuf[4096];
    const char *dir = NULL;
    if (!rc) {
        char sub[GR_SUITE_NAME_MAX + 16];
        snprintf(sub, sizeof sub, "pareto-%s", r.suite->name);
        rc = gr_args_output_dir(args, &r.suite->cases[0].scene, o->outopt, sub, dirbuf, sizeof dirbuf, &dir);
    }
    if (rc) {
        ps_free(&r);
        return rc;
    }
    const double t0 = now_s();
    r.dir = dir;
    gr_gl_options glo;
    memset(&glo, 0, sizeof glo);
    glo.platform = o->platform;
    r.pts = calloc(PS_MAX_POINTS, sizeof *r.pts);
    r.bl = malloc(sizeof *r.bl);
    gr_status st = r.pts && r.bl ? GR_OK : gr_fail(&err, GR_E_NOMEM, "out of memory");
    if (st == GR_OK) st = gr_gl_create(&glo, &r.gl, &err); /* before the slow ground truths */
    if (st == GR_OK) r.repeat = o->repeat > 0 ? o->repeat : gr_timing_is_cpu_renderer(gr_gl_renderer(r.gl)) ? 3 : 5;
    if (st == GR_OK) st = truths(o, &r, &err);
    if (st == GR_OK) st = gr_st_baselines(r.cases, r.suite->n_cases, GR_SPLIT_TEST, r.bl, &err);
    for (int k = 0; k < o->n_techs && st == GR_OK; k++) st = technique(o, &r, o->techs[k], &err);
    if (st == GR_OK) st = outputs(o, &r, dir, now_s() - t0, &err);
    if (st != GR_OK) rc = gr_cli_report(cmd, &err);
    ps_free(&r);
    return rc;
}
