/* godrays sweep SCENE --param NAME.KEY=0.4:1.2:16 [--param ...]: a technique's error surface over
 * a grid of one or two settings against the cached ground truth (src/tune/sweep.h). */
#include "cli/cli.h"
#include "cli/args.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "image/png.h"
#include "reference/progress.h"
#include "report/report.h"
#include "tune/page.h"
#include "tune/budget.h"
#include "tune/cliopts.h"
#include "tune/sweep.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays sweep SCENE --param TECHNIQUE.KEY=LO:HI:COUNT [--param ...] [options]\n"
            "\n"
            "Renders a real-time technique (--technique, else the one the parameters name) over a\n"
            "grid of one or two of its settings (COUNT values from LO to\n"
            "HI inclusive per axis; the grid is COUNT1 x COUNT2 renders per frame and view), scores\n"
            "each render against the ground truth (rendered once and cached), and writes into DIR:\n"
            "sweep.csv (every point), sweep.json (grid, minimum, timings, snippet), sweep.png (heat\n"
            "map with the minimum marked; a line chart for one axis), reference.png and best.png.\n"
            "RGB settings are swept as a SCALE on the scene's value (1 = the scene's own). Integer\n"
            "settings take integer values; booleans and choices are set with --set. `godrays\n"
            "techniques` lists every setting. docs/tuning.md.\n"
            "\n"
            "options:\n"
            "  --param SPEC         a sweep axis TECHNIQUE.KEY=LO:HI:COUNT (one or two)\n"
            "%s"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage, bad parameter spec or bad scene.\n",
            gr_tune_cli_help());
}

typedef struct progress_ctx {
    int quiet;
    gr_tune_budget budget; /* the estimate after the first grid point (tune/budget.h) */
    gr_progress *bar;      /* a bar on a terminal, a line per 10 % or 10 s otherwise (NULL: -q) */
} progress_ctx;

static void progress(void *user, int done, int total)
{
    progress_ctx *p = user;
    char eta[512], note[64];
    if (!p->quiet && gr_tune_budget_eta(&p->budget, done, eta, sizeof eta)) {
        gr_progress_finish(p->bar);
        fprintf(stderr, "%s\n", eta);
    }
    snprintf(note, sizeof note, "%d/%d grid points", done, total);
    gr_progress_update(p->bar, total > 0 ? (double)done / total : 1.0, note);
}

static cJSON *num_array(const double *v, int n)
{
    return cJSON_CreateDoubleArray(v, n);
}

/* sweep.json: everything a script needs to redraw or re-check the sweep. */
static char *sweep_json(const gr_tune_session *s, const gr_tune_problem *p, const gr_sweep_result *r,
                        const char *snippet)
{
    cJSON *root = gr_tune_json_root(s, p);
    if (!root) return NULL;
    cJSON *axes = cJSON_AddArrayToObject(root, "axes");
    for (int k = 0; axes && k < p->n_params; k++) {
        cJSON *a = cJSON_CreateObject();
        if (!a) break;
        cJSON_AddStringToObject(a, "key", p->params[k].key);
        cJSON_AddStringToObject(a, "meaning", p->params[k].kind == GR_TK_RGB_SCALE ? "scale on the scene's RGB value"
                                                                                  : "setting value");
        cJSON_AddNumberToObject(a, "lo", p->params[k].lo);
        cJSON_AddNumberToObject(a, "hi", p->params[k].hi);
        cJSON_AddNumberToObject(a, "count", p->params[k].count);
        cJSON_AddItemToObject(a, "values", num_array(k == 0 ? r->xs : r->ys, k == 0 ? r->nx : r->ny));
        cJSON_AddItemToArray(axes, a);
    }
    cJSON *cases = cJSON_AddArrayToObject(root, "cases");
    for (int i = 0; cases && i < s->n_cases; i++) {
        cJSON *c = gr_tune_json_case(s, i);
        if (!c) break;
        cJSON_AddBoolToObject(c, "ground_truth_cached", s->truth[i].cached);
        cJSON_AddNumberToObject(c, "ground_truth_seconds", s->truth[i].seconds);
        cJSON_AddItemToArray(cases, c);
    }
    /* error[iy][ix] */
    cJSON *grid = cJSON_AddArrayToObject(root, "error");
    for (int j = 0; grid && j < r->ny; j++) cJSON_AddItemToArray(grid, num_array(r->err + (size_t)j * r->nx, r->nx));
    cJSON *best = cJSON_AddObjectToObject(root, "minimum");
    if (best) {
        int bx = r->best % r->nx, by = r->best / r->nx;
        cJSON_AddNumberToObject(best, p->params[0].key, r->xs[bx]);
        if (p->n_params > 1) cJSON_AddNumberToObject(best, p->params[1].key, r->ys[by]);
        cJSON_AddNumberToObject(best, "error", r->err[r->best]);
        cJSON_AddNumberToObject(best, "scale", r->scale[r->best]);
        cJSON_AddItemToObject(best, "per_case", num_array(r->case_err + (size_t)r->best * r->n_cases, r->n_cases));
        cJSON *snip = snippet ? cJSON_Parse(snippet) : NULL;
        if (snip) cJSON_AddItemToObject(best, "snippet", snip);
    }
    cJSON *t = cJSON_AddObjectToObject(root, "timing");
    if (t) {
        cJSON_AddNumberToObject(t, "renders", (double)p->renders);
        cJSON_AddNumberToObject(t, "sweep_wall_s", r->wall_s);
        cJSON_AddNumberToObject(t, "render_readback_s", p->render_s);
        cJSON_AddNumberToObject(t, "metrics_s", p->metrics_s);
        cJSON_AddNumberToObject(t, "other_s", r->wall_s - p->render_s - p->metrics_s);
        cJSON_AddNumberToObject(t, "ms_per_render", p->renders ? 1e3 * r->wall_s / (double)p->renders : 0.0);
        cJSON_AddNumberToObject(t, "gl_pass_timers_ms", p->gpu_timed ? p->gpu_ms_sum : -1.0);
        cJSON_AddStringToObject(t, "gl_renderer", gr_gl_renderer(gr_technique_gl(p->renderer)));
        cJSON_AddNumberToObject(t, "ground_truth_s", s->truth_seconds);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}

/* reference.png and best.png of case 0 at the same exposure (best x its fitted scale). */
static gr_status write_images(const char *dir, gr_tune_problem *p, const double *x, gr_error *err)
{
    char path[4300];
    gr_section_store s;
    gr_status st = gr_tune_settings_at(p, x, s.bytes, err);
    if (st != GR_OK) return st;
    gr_metrics m;
    gr_image *img = gr_image_create(p->scratch->width, p->scratch->height, 3, NULL);
    if (!img) return gr_fail(err, GR_E_NOMEM, "out of memory");
    st = gr_tune_render_case(p, 0, s.bytes, img, &m, err);
    if (st == GR_OK) {
        double e = gr_report_exposure(p->refs[0], 1.0, 0.99, 0.8);
        static const int rgb[3] = {0, 1, 2};
        int rr[3];
        gr_metrics_pick_rgb(p->refs[0], rr);
        snprintf(path, sizeof path, "%s/reference.png", dir);
        st = gr_png_write_preview(path, p->refs[0], rr, e, err);
        if (st == GR_OK) {
            snprintf(path, sizeof path, "%s/best.png", dir);
            st = gr_png_write_preview(path, img, rgb, e * (p->fit ? m.fit.scale : 1.0), err);
        }
    }
    gr_image_destroy(img);
    return st;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int sweep_with(gr_args *args)
{
    const int argc = args->argc;
    char **argv = args->argv;
    const char *cmd = "sweep", *outopt = NULL;
    gr_tune_cli c;
    gr_tune_cli_init(&c);
    gr_tune_param params[2];
    const char *param_specs[2];
    int n_params = 0, rc = 0, taken = 0;
    gr_error err = {GR_OK, ""};
    for (; args->i < argc && !rc; args->i++) {
        const char *a = argv[args->i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(a, "--param")) {
            const char *v = NULL;
            if ((rc = gr_args_value(args, &v)) != 0) return rc;
            if (n_params >= 2) return gr_cli_usage_error(cmd, "--param %s: at most two axes", v);
            param_specs[n_params++] = v; /* parsed after the loop, once --technique-dir is known */
        } else if ((rc = gr_args_take_common(args, &outopt, &c.so.gl_platform, &taken)) == 0 && !taken) {
            int r = gr_tune_cli_option(&c, argc, argv, &args->i, &err);
            if (r < 0) rc = gr_cli_report(cmd, &err);
            else if (r == 0) rc = gr_args_take_scene(args);
        }
    }
    if (rc || (rc = gr_args_need_scene(args)) != 0) return rc;
    if (n_params == 0) return gr_cli_usage_error(cmd, "no --param given (e.g. --param TECHNIQUE.KEY=0.4:1.2:16)");
    if ((rc = gr_args_add_technique_dirs(args)) != 0) return rc;
    for (int j = 0; j < n_params; j++) {
        if (gr_tune_param_parse_sweep("--param", param_specs[j], &params[j], &err) != GR_OK)
            return gr_cli_report(cmd, &err);
        for (int k = 0; k < j; k++)
            if (!strcmp(params[k].key, params[j].key))
                return gr_cli_usage_error(cmd, "--param %s: %s swept twice", param_specs[j], params[k].key);
    }
    if (gr_tune_cli_finish(&c, &err) != GR_OK) return gr_cli_report(cmd, &err);
    progress_ctx pc = {c.quiet, {0}, NULL}; /* the count before the ground truths */
    const long long points = (long long)params[0].count * (n_params > 1 ? params[1].count : 1);
    if (gr_tune_budget_init(&pc.budget, "godrays sweep", "grid points", points, gr_tune_budget_cases(&c.so), c.yes,
                            &err) != GR_OK)
        return gr_cli_report(cmd, &err);
    c.so.scene_path = args->scene_path;
    c.so.sets = gr_args_sets(args);
    c.so.n_sets = args->n_sets;
    c.so.progress_label = "godrays sweep";

    gr_tune_session s;
    gr_tune_problem *p = calloc(1, sizeof *p);
    gr_sweep_result r;
    memset(&r, 0, sizeof r);
    char dirbuf[4096], path[4300];
    char *json = NULL, *snippet = NULL;
    const char *outdir = NULL;
    memset(&s, 0, sizeof s);
    if (!p) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        goto fail;
    }
    /* The ground truths take minutes: a folder that cannot be made is refused before them. */
    if ((rc = gr_args_output_dir(args, NULL, outopt, "sweep", dirbuf, sizeof dirbuf, &outdir)) != 0) goto done;
    if (gr_tune_cli_open(&c, params, n_params, &s, p, &err) != GR_OK) goto fail;
    /* every grid value must be a valid setting before the first render */
    for (int k = 0; k < n_params; k++) {
        gr_section_store t = p->base;
        for (int e = 0; e < 2; e++)
            if (gr_tune_param_apply(&params[k], p->base.bytes, e ? params[k].hi : params[k].lo, t.bytes, &err) != GR_OK) {
                err.status = GR_E_USAGE;
                gr_error_prefix(&err, "--param %s", params[k].key);
                goto fail;
            }
    }
    if (gr_report_make_dir(outdir, &err) != GR_OK) goto fail;

    char plan[512];
    gr_tune_budget_plan_line(&pc.budget, plan, sizeof plan);
    if (!c.quiet) fprintf(stderr, "%s\n", plan);
    gr_tune_budget_start(&pc.budget);
    pc.bar = gr_progress_create("godrays sweep", !c.quiet);
    gr_status swst = gr_sweep_run(p, &r, progress, &pc, &err);
    gr_progress_destroy(pc.bar);
    if (swst != GR_OK) goto fail;
    /* the sweep's own accounting, before the extra render of best.png */
    const long long sw_renders = p->renders;
    const double sw_render_s = p->render_s, sw_metrics_s = p->metrics_s;
    int bx = r.best % r.nx, by = r.best / r.nx;
    double xbest[2] = {r.xs[bx], r.ys[by]};
    double fold[3] = {r.scale[r.best], r.scale[r.best], r.scale[r.best]}, fbest;
    /* --rgb-per-channel: the best point's per-channel factors (one more evaluation) */
    if (p->rgb_per_channel && gr_tune_evaluate(p, xbest, &fbest, NULL, NULL, &err) != GR_OK) goto fail;
    if (p->rgb_per_channel) gr_tune_mean_scale_rgb(p, fold);
    snippet = gr_tune_snippet(p, xbest, p->fit ? fold : NULL);
    json = sweep_json(&s, p, &r, snippet);
    if (!snippet || !json) {
        gr_fail(&err, GR_E_NOMEM, "out of memory building the JSON");
        goto fail;
    }
    const char *labels[GR_TUNE_MAX_CASES];
    for (int i = 0; i < s.n_cases; i++) labels[i] = s.labels[i];
    snprintf(path, sizeof path, "%s/sweep.csv", outdir);
    if (gr_sweep_write_csv(path, p, &r, labels, &err) != GR_OK) goto fail;
    snprintf(path, sizeof path, "%s/sweep.json", outdir);
    if (gr_tune_write_text(path, json, &err) != GR_OK) goto fail;
    int drawn = 0;
    snprintf(path, sizeof path, "%s/sweep.png", outdir);
    if (gr_sweep_write_plot(path, p, &r, &drawn, &err) != GR_OK) goto fail;
    if (write_images(outdir, p, xbest, &err) != GR_OK) goto fail;

    gr_strbuf sum;
    gr_sb_init(&sum);
    gr_sb_printf(&sum, "technique %s, scene '%s' (%d x %d), %d case(s), metric %s of Y%s%s\n", p->cls->name,
           s.base->name, s.base->camera.width, s.base->camera.height, s.n_cases, gr_tune_metric_name(p->metric),
           p->fit == GR_FIT_RGB ? " after the per-channel fit" : p->fit ? " after the best scale fit" : "",
           p->normalize ? ", / mean reference Y per case" : "");
    gr_sb_printf(&sum, "minimum %.6g at %s = %.6g", r.err[r.best], p->params[0].key, xbest[0]);
    if (n_params > 1) gr_sb_printf(&sum, ", %s = %.6g", p->params[1].key, xbest[1]);
    gr_sb_printf(&sum, " (fitted scale %.4g)\n", r.scale[r.best]);
    gr_sb_printf(&sum, "%lld renders in %.2f s (%.1f ms each: render + readback %.2f s, metrics %.2f s, other %.2f s; %s)\n",
           sw_renders, r.wall_s, sw_renders ? 1e3 * r.wall_s / (double)sw_renders : 0.0, sw_render_s, sw_metrics_s,
           r.wall_s - sw_render_s - sw_metrics_s, gr_gl_renderer(gr_technique_gl(p->renderer)));
    gr_sb_printf(&sum, "ground truth: %.1f s (%s)\n", s.truth_seconds, s.truth[0].cached ? "from the cache" : "rendered");
    gr_sb_printf(&sum, "best settings for the scene:\n%s\n", snippet);
    gr_sb_printf(&sum, "written: %s/sweep.csv, sweep.json, %s, reference.png, best.png\n", outdir,
           drawn ? "sweep.png" : "(no sweep.png: charts need PLplot)");
    fputs(gr_sb_str(&sum), stdout);
    {
        gr_strbuf pg;
        gr_sb_init(&pg);
        gr_tune_page_begin(&pg, outdir, "godrays sweep: %s", s.base->name);
        if (drawn) gr_tune_page_figure(&pg, "sweep.png", "error surface; the cross marks the minimum");
        gr_tune_page_figure(&pg, "reference.png", "ground truth (case 0)");
        gr_tune_page_figure(&pg, "best.png", "the technique at the minimum, x the fitted scale, same exposure");
        gr_status pst = gr_tune_page_write(&pg, gr_sb_str(&sum), "sweep.csv,sweep.json", outdir, &err);
        gr_sb_free(&sum);
        if (pst != GR_OK) goto fail;
    }
    goto done;
fail:
    rc = gr_cli_report(cmd, &err);
done:
    free(json);
    free(snippet);
    gr_sweep_result_free(&r);
    if (p) gr_tune_problem_free(p);
    free(p);
    gr_tune_session_close(&s);
    return rc;
}

int cmd_sweep(int argc, char **argv)
{
    return gr_args_main("sweep", argc, argv, sweep_with);
}
