/* godrays tune SCENE --params NAME.KEY,NAME.KEY[,...]: the technique's settings that
 * minimize the error against the ground truth over frames and views, found by bounded
 * Nelder-Mead with restarts (src/tune/optimize.h). */
#include "cli/cli.h"
#include "cli/args.h"
#include "common/outfile.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "image/oiio.h"
#include "image/png.h"
#include "reference/progress.h"
#include "report/report.h"
#include "tune/page.h"
#include "tune/budget.h"
#include "tune/cliopts.h"
#include "tune/optimize.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: godrays tune SCENE [--params TECHNIQUE.KEY[,TECHNIQUE.KEY...]] [options]\n"
            "\n"
            "Finds the settings of a real-time technique (--technique, else the one the parameters\n"
            "name) that minimize the error against the ground truth (rendered\n"
            "once per frame and view, cached), averaged over the frames (--frames/--times) and views\n"
            "(--view): a sample of the bounds, short Nelder-Mead runs from its best points, the\n"
            "best of them (and the scene's own settings) continued, then a polish. Prints the best\n"
            "settings as a\n"
            "snippet for the technique's scene section and the error before and after per frame and\n"
            "view; writes DIR/tune.json, DIR/trace.csv (every evaluation), DIR/compare.png\n"
            "(reference | before | after) and per-case reference/before/after PNGs.\n"
            "RGB settings are tuned as a SCALE on the scene's value.\n"
            "docs/tuning.md.\n"
            "\n"
            "options:\n"
            "  --params LIST        comma-separated TECHNIQUE.KEY settings to tune (at most %d; default:\n"
            "                       the technique's own list, docs/tuning.md)\n"
            "  (default objective: --objective " GR_TUNE_DEFAULT_OBJECTIVE "; --metric rmse for RMSE alone)\n"
            "  --bounds KEY=LO:HI   box of one parameter (repeatable; default: the setting's tuning box,\n"
            "                       `godrays techniques`)\n"
            "  --start KEY=V        first starting point of a parameter (repeatable; default: the\n"
            "                       scene's value, clamped into the box)\n"
            "  --starts N           starting points (default 4, at most %d)\n"
            "  --max-evals N        objective evaluations per start (default 60 + 40 x parameters)\n"
            "  --coarse M           first stage: M points of a shifted Halton sample over the box; the\n"
            "                       starts after the scene's settings are its best points, apart from\n"
            "                       each other (default 16 x parameters; 0: starts on a fixed lattice)\n"
            "  --screen C           candidates screened by short local searches before the starts\n"
            "                       continue (default 4 x --starts; 0 or <= --starts: none)\n"
            "  --method M           nelder-mead (default: local searches from the starts) or cmaes\n"
            "                       (CMA-ES runs with a doubling population, one per start)\n"
            "  --seed S             the sample's random shift (default 0; same seed, same search)\n"
            "%s"
            "  -h, --help           this help\n"
            "\n"
            "Exit codes: 0 ok, 1 runtime failure, 2 bad usage, bad parameter spec or bad scene.\n",
            GR_TUNE_MAX_PARAMS, GR_OPT_MAX_STARTS, gr_tune_cli_help());
}

/* The objective, recording every evaluation into trace.csv. */
typedef struct traced {
    gr_tune_problem *p;
    FILE *trace;        /* the temporary file of trace.csv (common/outfile), renamed at the end */
    int n;
    gr_progress *bar;   /* evaluations of the planned most: a bar on a terminal, a line per 10 % or
                           10 s otherwise (reference/progress.h; never prints with -q) */
    gr_tune_budget *budget; /* the estimate after the first evaluation; NULL: none (-q) */
} traced;

static gr_status traced_objective(void *user, const double *x, double *f, gr_error *err)
{
    traced *t = user;
    gr_status st = gr_tune_evaluate(t->p, x, f, NULL, NULL, err);
    if (st != GR_OK) return st;
    t->n++;
    if (t->trace) {
        fprintf(t->trace, "%d", t->n);
        for (int k = 0; k < t->p->n_params; k++) fprintf(t->trace, ",%.9g", x[k]);
        fprintf(t->trace, ",%.9g\n", *f);
    }
    char eta[512], note[64];
    if (t->budget && gr_tune_budget_eta(t->budget, t->n, eta, sizeof eta)) {
        gr_progress_finish(t->bar);
        fprintf(stderr, "%s\n", eta);
    }
    /* the plan is an upper bound (the search may stop early): the fraction of it */
    const long long planned = t->budget && t->budget->planned > 0 ? t->budget->planned : 0;
    snprintf(note, sizeof note, "%d evaluations", t->n);
    gr_progress_update(t->bar, planned ? (double)t->n / (double)planned : 0.0, note);
    return GR_OK;
}

static int parse_kv(const char *spec, char *key, size_t kn, double *v)
{
    const char *eq = strchr(spec, '=');
    if (!eq || (size_t)(eq - spec) >= kn) return -1;
    memcpy(key, spec, (size_t)(eq - spec));
    key[eq - spec] = '\0';
    char *end = NULL;
    *v = strtod(eq + 1, &end);
    if (end == eq + 1 || *end || !isfinite(*v)) return -1;
    return 0;
}

static int parse_count(const char *s, int lo, int hi, int *out)
{
    char *end = NULL;
    long v = strtol(s, &end, 10);
    if (end == s || *end || v < lo || v > hi) return -1;
    *out = (int)v;
    return 0;
}

/* Per-case before/after images and the contact sheet of case 0. */
static gr_status write_images(const char *dir, const gr_tune_session *s, gr_tune_problem *p, const double *xb,
                              const double *xa, gr_error *err)
{
    gr_section_store sb, sa;
    gr_status st = gr_tune_settings_at(p, xb, sb.bytes, err);
    if (st == GR_OK) st = gr_tune_settings_at(p, xa, sa.bytes, err);
    if (st != GR_OK) return st;
    int W = p->scratch->width, H = p->scratch->height;
    gr_image *ib = gr_image_create(W, H, 3, NULL), *ia = gr_image_create(W, H, 3, NULL);
    gr_image *disp[3] = {NULL, NULL, NULL}, *sheet = NULL;
    char path[4300];
    if (!ib || !ia) st = gr_fail(err, GR_E_NOMEM, "out of memory");
    for (int i = 0; st == GR_OK && i < s->n_cases; i++) {
        gr_metrics mb, ma;
        if ((st = gr_tune_render_case(p, i, sb.bytes, ib, &mb, err)) != GR_OK) break;
        if ((st = gr_tune_render_case(p, i, sa.bytes, ia, &ma, err)) != GR_OK) break;
        double e = gr_report_exposure(p->refs[i], 1.0, 0.99, 0.8);
        double ab = p->fit ? mb.fit.scale : 1.0, aa = p->fit ? ma.fit.scale : 1.0;
        int rr[3];
        static const int rgb[3] = {0, 1, 2};
        gr_metrics_pick_rgb(p->refs[i], rr);
        snprintf(path, sizeof path, "%s/reference_%02d.png", dir, i);
        if ((st = gr_png_write_preview(path, p->refs[i], rr, e, err)) != GR_OK) break;
        snprintf(path, sizeof path, "%s/before_%02d.png", dir, i);
        if ((st = gr_png_write_preview(path, ib, rgb, e * ab, err)) != GR_OK) break;
        snprintf(path, sizeof path, "%s/after_%02d.png", dir, i);
        if ((st = gr_png_write_preview(path, ia, rgb, e * aa, err)) != GR_OK) break;
        if (i == 0) {
            if ((st = gr_report_display(p->refs[0], e, &disp[0], err)) != GR_OK) break;
            if ((st = gr_report_display(ib, e * ab, &disp[1], err)) != GR_OK) break;
            if ((st = gr_report_display(ia, e * aa, &disp[2], err)) != GR_OK) break;
            char l0[256], l1[256], l2[160];
            const char *metric = gr_tune_metric_name(p->metric);
            snprintf(l0, sizeof l0, "%s (%s): %s of Y%s", s->labels[0], s->base->name, metric,
                     p->fit ? " after the best scale fit" : "");
            snprintf(l1, sizeof l1, "before: %.5g    after: %.5g    (%.1f %% lower)",
                     gr_tune_value(p, p->fit ? &mb.fit : &mb.raw),
                     gr_tune_value(p, p->fit ? &ma.fit : &ma.raw),
                     100.0 * (1.0 - gr_tune_value(p, p->fit ? &ma.fit : &ma.raw) /
                                        fmax(1e-300, gr_tune_value(p, p->fit ? &mb.fit : &mb.raw))));
            snprintf(l2, sizeof l2, "%s shown x its fitted scale (%.3g, %.3g), same exposure as the reference",
                     p->cls->name, ab, aa);
            const char *lines[3] = {l0, l1, l2};
            char t1[64], t2[80];
            snprintf(t1, sizeof t1, "%s before", p->cls->name);
            snprintf(t2, sizeof t2, "%s after tuning", p->cls->name);
            const char *titles[3] = {"ground truth", t1, t2};
            int labelled = 0;
            const gr_image *panels[3] = {disp[0], disp[1], disp[2]};
            if ((st = gr_report_contact_sheet(panels, titles, lines, 3, 320, 640, &sheet, &labelled, err)) != GR_OK)
                break;
            snprintf(path, sizeof path, "%s/compare.png", dir);
            if ((st = gr_oiio_write(path, sheet, err)) != GR_OK) break;
        }
    }
    for (int k = 0; k < 3; k++) gr_image_destroy(disp[k]);
    gr_image_destroy(sheet);
    gr_image_destroy(ib);
    gr_image_destroy(ia);
    return st;
}

/* What the command line asks for, besides the options sweep shares (gr_tune_cli). */
typedef struct tune_opts {
    gr_tune_cli c;
    const char *outopt, *params_spec;
    const char *bounds[32], *starts[32];
    int n_bounds, n_start_specs;
    int n_starts, max_evals, coarse, screen, help;
    unsigned long long seed;
    gr_opt_method method;
} tune_opts;

/* The search's box and its result. */
typedef struct tune_run {
    gr_tune_param params[GR_TUNE_MAX_PARAMS];
    int n_params;
    double x0[GR_TUNE_MAX_PARAMS];
    int have_x0[GR_TUNE_MAX_PARAMS];
    double lo[GR_TUNE_MAX_PARAMS], hi[GR_TUNE_MAX_PARAMS], xb[GR_TUNE_MAX_PARAMS]; /* xb: the scene's own */
    double before[GR_TUNE_MAX_CASES], after[GR_TUNE_MAX_CASES], sc_b[GR_TUNE_MAX_CASES], sc_a[GR_TUNE_MAX_CASES];
    double fb, fa;                          /* the mean error before and after */
    gr_opt_result res;
    double spread[GR_TUNE_MAX_PARAMS];      /* of the starts that agree (fraction of the box) */
    int agreeing;
    gr_opt_options oo;                      /* the search's options, known before the ground truths */
    gr_tune_budget budget;                  /* its count and estimate (tune/budget.h) */
    long long renders0;                     /* the problem's counters before the search */
    double render_s0, metrics_s0;
    char *snippet;
} tune_run;

/* One of tune's own options with a value (argv[args->i]); *rc the exit code. 0: not one. */
static int take_own_option(gr_args *args, tune_opts *t, int *rc)
{
    static const char *const own[] = {"--params", "--bounds", "--start", "--starts", "--max-evals",
                                      "--coarse", "--seed",   "--method", "--screen"};
    const char *cmd = "tune", *a = args->argv[args->i], *v = NULL;
    size_t k = 0;
    while (k < sizeof own / sizeof own[0] && strcmp(a, own[k])) k++;
    if (k == sizeof own / sizeof own[0]) return 0;
    if ((*rc = gr_args_value(args, &v)) != 0) return 1;
    if (!strcmp(a, "--params")) {
        if (t->params_spec) *rc = gr_cli_usage_error(cmd, "--params given twice");
        t->params_spec = v; /* parsed after the loop, once --technique-dir is known */
    } else if (!strcmp(a, "--bounds")) {
        if (t->n_bounds >= 32) *rc = gr_cli_usage_error(cmd, "--bounds: too many");
        else t->bounds[t->n_bounds++] = v;
    } else if (!strcmp(a, "--start")) {
        if (t->n_start_specs >= 32) *rc = gr_cli_usage_error(cmd, "--start: too many");
        else t->starts[t->n_start_specs++] = v;
    } else if (!strcmp(a, "--starts")) {
        if (parse_count(v, 1, GR_OPT_MAX_STARTS, &t->n_starts))
            *rc = gr_cli_usage_error(cmd, "--starts %s: expected an integer in [1, %d]", v, GR_OPT_MAX_STARTS);
    } else if (!strcmp(a, "--method")) {
        if (!strcmp(v, "nelder-mead")) t->method = GR_OPT_NELDER_MEAD;
        else if (!strcmp(v, "cmaes")) t->method = GR_OPT_CMAES;
        else *rc = gr_cli_usage_error(cmd, "--method %s: expected nelder-mead or cmaes", v);
    } else if (!strcmp(a, "--screen")) {
        if (parse_count(v, 0, GR_OPT_MAX_STARTS, &t->screen))
            *rc = gr_cli_usage_error(cmd, "--screen %s: expected an integer in [0, %d]", v, GR_OPT_MAX_STARTS);
    } else if (!strcmp(a, "--coarse")) {
        if (parse_count(v, 0, 100000, &t->coarse))
            *rc = gr_cli_usage_error(cmd, "--coarse %s: expected an integer in [0, 100000]", v);
    } else if (!strcmp(a, "--seed")) {
        char *end = NULL;
        if (!v[0] || v[0] == '-' || (t->seed = strtoull(v, &end, 10), *end))
            *rc = gr_cli_usage_error(cmd, "--seed %s: expected an integer >= 0", v);
    } else if (parse_count(v, 4, 1000000, &t->max_evals)) {
        *rc = gr_cli_usage_error(cmd, "--max-evals %s: expected an integer >= 4", v);
    }
    return 1;
}

/* The argument loop; returns the exit code (t->help: the help was printed). */
static int parse_args(gr_args *args, tune_opts *t)
{
    const char *cmd = "tune";
    gr_error err = {GR_OK, ""};
    gr_tune_cli_init(&t->c);
    t->n_starts = 4;
    t->coarse = t->screen = -1;
    t->method = GR_OPT_NELDER_MEAD;
    /* tune's default is the weighted objective (sweep keeps rmse: a map of one error) */
    t->c.metric = GR_TM_WEIGHTED;
    if (gr_tune_weights_parse("--objective", GR_TUNE_DEFAULT_OBJECTIVE, t->c.weights, &err) != GR_OK)
        return gr_cli_report(cmd, &err);
    for (; args->i < args->argc; args->i++) {
        const char *a = args->argv[args->i];
        int rc = 0, taken = 0;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            usage(stdout);
            t->help = 1;
            return 0;
        }
        if (take_own_option(args, t, &rc)) {
            if (rc) return rc;
            continue;
        }
        if ((rc = gr_args_take_common(args, &t->outopt, &t->c.so.gl_platform, &taken)) == 0 && !taken) {
            int r = gr_tune_cli_option(&t->c, args->argc, args->argv, &args->i, &err);
            if (r < 0) return gr_cli_report(cmd, &err);
            if (r == 0) rc = gr_args_take_scene(args);
        }
        if (rc) return rc;
    }
    return 0;
}

/* --params (default: the technique's own list), --bounds and --start; an exit code. */
static int parse_params(tune_opts *t, tune_run *r)
{
    const char *cmd = "tune";
    gr_error err = {GR_OK, ""};
    char default_params[1024];
    if (!t->params_spec) {
        /* the technique's own list (--technique, else the first registered) */
        const char *tn = t->c.technique_name;
        const gr_technique_class *cls = tn ? gr_technique_find(tn) : gr_technique_at(0);
        if (!cls) return gr_cli_usage_error(cmd, "--technique %s: unknown technique", tn);
        if (gr_tune_default_params(cls, default_params, sizeof default_params))
            return gr_cli_usage_error(cmd, "no --params given and technique %s has no settings to tune by default",
                                      cls->name);
        t->params_spec = default_params;
    }
    if (gr_tune_param_parse_list("--params", t->params_spec, r->params, GR_TUNE_MAX_PARAMS, &r->n_params, &err) != GR_OK)
        return gr_cli_report(cmd, &err);
    t->params_spec = NULL; /* default_params ends here */
    for (int b = 0; b < t->n_bounds; b++)
        if (gr_tune_param_parse_bounds("--bounds", t->bounds[b], r->params, r->n_params, &err) != GR_OK)
            return gr_cli_report(cmd, &err);
    for (int k = 0; k < r->n_params; k++)
        if (!(r->params[k].lo < r->params[k].hi))
            return gr_cli_usage_error(cmd, "--params %s: no default bounds; give --bounds %s=LO:HI", r->params[k].key,
                                      r->params[k].key);
    for (int b = 0; b < t->n_start_specs; b++) {
        char key[64];
        double v;
        if (parse_kv(t->starts[b], key, sizeof key, &v))
            return gr_cli_usage_error(cmd, "--start %s: expected TECHNIQUE.KEY=VALUE", t->starts[b]);
        int idx = -1;
        for (int k = 0; k < r->n_params; k++)
            if (!strcmp(r->params[k].key, key)) idx = k;
        if (idx < 0) return gr_cli_usage_error(cmd, "--start %s: %s is not among the --params", t->starts[b], key);
        r->x0[idx] = v;
        r->have_x0[idx] = 1;
    }
    return 0;
}

/* The box, the scene's own point xb and the first start x0 (clamped into the box); a bound
 * that the setting refuses is bad usage. */
static gr_status set_box(gr_tune_problem *p, tune_run *r, gr_error *err)
{
    for (int k = 0; k < r->n_params; k++) {
        r->lo[k] = r->params[k].lo;
        r->hi[k] = r->params[k].hi;
        r->xb[k] = gr_tune_param_current(&r->params[k], p->base.bytes, p->base.bytes); /* the scene's own value */
        if (!r->have_x0[k]) r->x0[k] = fmin(r->hi[k], fmax(r->lo[k], r->xb[k]));
        gr_section_store s = p->base;
        for (int e = 0; e < 2; e++)
            if (gr_tune_param_apply(&r->params[k], p->base.bytes, e ? r->hi[k] : r->lo[k], s.bytes, err) != GR_OK) {
                err->status = GR_E_USAGE;
                return gr_error_prefix(err, "bounds of %s", r->params[k].key);
            }
    }
    return GR_OK;
}

/* The search's options, and its count against the budget, before any ground truth. */
static gr_status plan_search(const tune_opts *t, tune_run *r, gr_error *err)
{
    gr_opt_options *oo = &r->oo;
    gr_tune_search_defaults(oo, r->n_params, r->x0);
    oo->method = t->method;
    oo->n_starts = t->n_starts;
    oo->screen = t->screen >= 0 ? t->screen : (4 * t->n_starts <= GR_OPT_MAX_STARTS ? 4 * t->n_starts : GR_OPT_MAX_STARTS);
    oo->seed = t->seed;
    if (t->max_evals > 0) {
        oo->max_evals = oo->polish = t->max_evals;
        if (oo->screen_evals > t->max_evals) oo->screen_evals = t->max_evals; /* a small budget stays small */
    }
    if (t->coarse >= 0) oo->coarse = t->coarse;
    if (t->coarse == 0) oo->polish = 0, oo->screen = 0; /* the fixed-lattice search of before */
    return gr_tune_budget_init(&r->budget, "godrays tune", "evaluations", gr_tune_budget_search(oo, r->n_params),
                               gr_tune_budget_cases(&t->c.so), t->c.yes, err);
}

/* The search itself (trace.csv, every evaluation), the errors before and after, the snippet
 * and the agreement of the starts. */
static gr_status search(const tune_opts *t, const gr_tune_session *s, gr_tune_problem *p, tune_run *r,
                        const char *outdir, gr_error *err)
{
    const int n = r->n_params;
    char path[4300];
    snprintf(path, sizeof path, "%s/trace.csv", outdir);
    gr_outfile trace = {.slot = -1}; /* a new trace replaces the old one only once complete */
    gr_status st = gr_outfile_open_stream(&trace, path, err);
    if (st != GR_OK) return st;
    fprintf(trace.f, "eval");
    for (int k = 0; k < n; k++) fprintf(trace.f, ",%s", r->params[k].key);
    fprintf(trace.f, ",%s%s\n", gr_tune_metric_name(p->metric), p->fit == GR_FIT_RGB ? "_fit_rgb" : p->fit ? "_fit" : "");
    st = gr_tune_evaluate(p, r->xb, &r->fb, r->before, r->sc_b, err);
    traced tr = {.p = p, .trace = trace.f, .bar = gr_progress_create("godrays tune", !t->c.quiet),
                 .budget = t->c.quiet ? NULL : &r->budget};
    char plan[512];
    gr_tune_budget_plan_line(&r->budget, plan, sizeof plan);
    if (!t->c.quiet) fprintf(stderr, "%s (at most)\n", plan);
    gr_tune_budget_start(&r->budget);
    r->renders0 = p->renders;
    r->render_s0 = p->render_s;
    r->metrics_s0 = p->metrics_s;
    if (st == GR_OK) st = gr_opt_minimize(n, r->lo, r->hi, traced_objective, &tr, &r->oo, &r->res, err);
    gr_progress_destroy(tr.bar);
    if (st == GR_OK && !t->c.quiet && isatty(2)) fprintf(stderr, "godrays tune: %d evaluations\n", tr.n);
    if (st == GR_OK) st = gr_outfile_commit(&trace, 0, err);
    gr_outfile_abort(&trace);
    if (st == GR_OK) st = gr_tune_evaluate(p, r->res.x, &r->fa, r->after, r->sc_a, err);
    if (st != GR_OK) return st;
    double fold[3] = {0.0, 0.0, 0.0}; /* the fitted factors folded into the gain: mean over the cases */
    for (int i = 0; i < s->n_cases; i++) fold[0] += r->sc_a[i] / s->n_cases;
    fold[1] = fold[2] = fold[0];
    if (p->rgb_per_channel) gr_tune_mean_scale_rgb(p, fold);
    if (!(r->snippet = gr_tune_snippet(p, r->res.x, p->fit ? fold : NULL)))
        return gr_fail(err, GR_E_NOMEM, "out of memory");
    /* Agreement of the starts: the spread (fraction of each box side) of the results of the
     * starts that reached the best value within 2 %. */
    for (int j = 0; j < r->res.n_starts; j++) {
        if (!(r->res.starts[j].f <= r->res.f * 1.02 + 1e-300)) continue;
        r->agreeing++;
        for (int k = 0; k < n; k++)
            r->spread[k] = fmax(r->spread[k], fabs(r->res.starts[j].x[k] - r->res.x[k]) / (r->hi[k] - r->lo[k]));
    }
    return GR_OK;
}

/* tune.json's "params", "starts" and "cases" arrays. */
static void json_arrays(cJSON *root, const gr_tune_session *s, const tune_run *r)
{
    const gr_opt_result *res = &r->res;
    cJSON *pa = cJSON_AddArrayToObject(root, "params");
    for (int k = 0; pa && k < r->n_params; k++) {
        cJSON *o = cJSON_CreateObject();
        if (!o) break;
        cJSON_AddStringToObject(o, "key", r->params[k].key);
        cJSON_AddStringToObject(o, "meaning", r->params[k].kind == GR_TK_RGB_SCALE ? "scale on the scene's RGB value"
                                                                                  : "setting value");
        cJSON_AddNumberToObject(o, "lo", r->lo[k]);
        cJSON_AddNumberToObject(o, "hi", r->hi[k]);
        cJSON_AddNumberToObject(o, "before", r->xb[k]);
        cJSON_AddNumberToObject(o, "after", res->x[k]);
        cJSON_AddNumberToObject(o, "start_spread_fraction", r->spread[k]);
        cJSON_AddItemToArray(pa, o);
    }
    cJSON *st = cJSON_AddArrayToObject(root, "starts");
    for (int j = 0; st && j < res->n_starts; j++) {
        cJSON *o = cJSON_CreateObject();
        if (!o) break;
        cJSON_AddItemToObject(o, "x0", cJSON_CreateDoubleArray(res->starts[j].x0, r->n_params));
        cJSON_AddItemToObject(o, "x", cJSON_CreateDoubleArray(res->starts[j].x, r->n_params));
        cJSON_AddNumberToObject(o, "f", res->starts[j].f);
        cJSON_AddNumberToObject(o, "evals", res->starts[j].evals);
        cJSON_AddBoolToObject(o, "converged", res->starts[j].converged);
        cJSON_AddNumberToObject(o, "f0", res->starts[j].f0);
        cJSON_AddNumberToObject(o, "sample_rank", res->starts[j].coarse_rank);
        cJSON_AddItemToArray(st, o);
    }
    cJSON *cs = cJSON_AddArrayToObject(root, "cases");
    for (int i = 0; cs && i < s->n_cases; i++) {
        cJSON *o = gr_tune_json_case(s, i);
        if (!o) break;
        cJSON_AddNumberToObject(o, "before", r->before[i]);
        cJSON_AddNumberToObject(o, "after", r->after[i]);
        cJSON_AddNumberToObject(o, "scale_before", r->sc_b[i]);
        cJSON_AddNumberToObject(o, "scale_after", r->sc_a[i]);
        cJSON_AddBoolToObject(o, "ground_truth_cached", s->truth[i].cached);
        cJSON_AddItemToArray(cs, o);
    }
}

/* tune.json as text (NULL: out of memory). */
static char *tune_json(const tune_opts *t, const gr_tune_session *s, const gr_tune_problem *p, const tune_run *r)
{
    const gr_opt_result *res = &r->res;
    cJSON *root = gr_tune_json_root(s, p);
    if (!root) return NULL;
    json_arrays(root, s, r);
    cJSON_AddNumberToObject(root, "before", r->fb);
    cJSON_AddNumberToObject(root, "after", r->fa);
    cJSON_AddNumberToObject(root, "evaluations", res->evals);
    cJSON_AddNumberToObject(root, "sample_evaluations", res->coarse_evals);
    cJSON_AddNumberToObject(root, "screened", res->n_screened);
    cJSON_AddNumberToObject(root, "screen_evaluations", res->screen_evals);
    cJSON_AddNumberToObject(root, "polish_evaluations", res->polish_evals);
    cJSON_AddNumberToObject(root, "seed", (double)t->seed);
    cJSON_AddNumberToObject(root, "starts_agreeing", r->agreeing);
    cJSON *sn = cJSON_Parse(r->snippet);
    if (sn) cJSON_AddItemToObject(root, "snippet", sn);
    cJSON *tm = cJSON_AddObjectToObject(root, "timing");
    if (tm) {
        cJSON_AddNumberToObject(tm, "renders", (double)(p->renders - r->renders0));
        cJSON_AddNumberToObject(tm, "render_readback_s", p->render_s - r->render_s0);
        cJSON_AddNumberToObject(tm, "metrics_s", p->metrics_s - r->metrics_s0);
        cJSON_AddNumberToObject(tm, "ground_truth_s", s->truth_seconds);
        cJSON_AddStringToObject(tm, "gl_renderer", gr_gl_renderer(gr_technique_gl(p->renderer)));
    }
    char *json = cJSON_Print(root);
    cJSON_Delete(root);
    return json;
}

/* The summary printed and shown on the page. */
static void tune_summary(const tune_opts *t, const gr_tune_session *s, const gr_tune_problem *p, const tune_run *r,
                         const char *outdir, gr_strbuf *sum)
{
    const gr_opt_result *res = &r->res;
    const int n = r->n_params;
    gr_sb_printf(sum, "technique %s, scene '%s' (%d x %d), %d case(s), metric %s of Y%s%s\n", p->cls->name,
                 s->base->name, s->base->camera.width, s->base->camera.height, s->n_cases,
                 gr_tune_metric_name(p->metric),
                 p->fit == GR_FIT_RGB ? " after the per-channel fit" : p->fit ? " after the best scale fit" : "",
                 p->normalize ? ", / mean reference Y per case" : "");
    gr_sb_printf(sum, "%-28s %12s %12s %14s\n", "parameter", "before", "after", "box");
    for (int k = 0; k < n; k++)
        gr_sb_printf(sum, "%-28s %12.5g %12.5g    [%g, %g]%s\n", r->params[k].key, r->xb[k], res->x[k], r->lo[k],
                     r->hi[k], r->params[k].kind == GR_TK_RGB_SCALE ? " (scale)" : "");
    if (res->coarse_evals > 0)
        gr_sb_printf(sum, "first stage: %d sample points (seed %llu), best error %.6g\n", res->coarse_evals, t->seed,
                     res->coarse_best);
    if (res->n_screened > 0)
        gr_sb_printf(sum, "screening: %d candidates, %d evaluations; the %d best continue\n", res->n_screened,
                     res->screen_evals, res->n_starts);
    gr_sb_printf(sum, "starts:\n");
    for (int j = 0; j < res->n_starts; j++) {
        const gr_opt_start *sj = &res->starts[j];
        if (sj->coarse_rank >= 0) gr_sb_printf(sum, "  %d: sample #%d, from (", j, sj->coarse_rank + 1);
        else gr_sb_printf(sum, "  %d: from (", j);
        for (int k = 0; k < n; k++) gr_sb_printf(sum, "%s%.4g", k ? ", " : "", sj->x0[k]);
        gr_sb_printf(sum, ") to (");
        for (int k = 0; k < n; k++) gr_sb_printf(sum, "%s%.5g", k ? ", " : "", sj->x[k]);
        gr_sb_printf(sum, ") error %.6g, %d evaluations%s\n", sj->f, sj->evals, sj->converged ? "" : " (budget reached)");
    }
    if (res->polish_evals > 0)
        gr_sb_printf(sum, "polish (compass search from the best): %d evaluations, error lowered by %.3g\n",
                     res->polish_evals, res->polish_gain);
    gr_sb_printf(sum, "%d of %d starts reached the best value within 2 %%; their spread:", r->agreeing, res->n_starts);
    for (int k = 0; k < n; k++) gr_sb_printf(sum, " %s %.2f %%", r->params[k].key, 100.0 * r->spread[k]);
    gr_sb_printf(sum, " of the box\n");
    gr_sb_printf(sum, "error per case (%s):        before        after\n", gr_tune_metric_name(p->metric));
    for (int i = 0; i < s->n_cases; i++)
        gr_sb_printf(sum, "  %-24s %12.6g %12.6g\n", s->labels[i], r->before[i], r->after[i]);
    gr_sb_printf(sum, "  %-24s %12.6g %12.6g (%.1f %% lower)\n", "mean", r->fb, r->fa,
                 r->fb > 0 ? 100.0 * (1.0 - r->fa / r->fb) : 0.0);
    gr_sb_printf(sum, "%d evaluations (%lld renders) in %.1f s (renders %.1f s, comparisons %.1f s); ground truth %.1f s\n",
                 res->evals, p->renders, p->render_s + p->metrics_s, p->render_s, p->metrics_s, s->truth_seconds);
    gr_sb_printf(sum, "best settings for the scene:\n%s\n", r->snippet);
    gr_sb_printf(sum, "written: %s/tune.json, trace.csv, compare.png, reference_NN.png, before_NN.png, after_NN.png\n",
                 outdir);
}

/* DIR/index.html: the contact sheet, the other cases' after images, the summary. */
static gr_status write_page(const gr_tune_session *s, const char *summary, const char *outdir, gr_error *err)
{
    gr_strbuf pg;
    gr_sb_init(&pg);
    gr_tune_page_begin(&pg, outdir, "godrays tune: %s", s->base->name);
    gr_tune_page_figure(&pg, "compare.png", "ground truth | the technique before | after tuning (case 0)");
    for (int i = 1; i < s->n_cases && i < 8; i++) {
        char f[64], cap[128];
        snprintf(f, sizeof f, "after_%02d.png", i);
        snprintf(cap, sizeof cap, "after tuning, %s (reference_%02d.png, before_%02d.png beside)", s->labels[i], i, i);
        gr_tune_page_figure(&pg, f, cap);
    }
    return gr_tune_page_write(&pg, summary, "tune.json,trace.csv", outdir, err);
}

/* The session (ground truths, renderer), the search and every output. */
static gr_status tune_outputs(tune_opts *t, tune_run *r, gr_tune_session *s, gr_tune_problem *p, const char *outdir,
                              gr_error *err)
{
    gr_status st = gr_tune_cli_open(&t->c, r->params, r->n_params, s, p, err);
    if (st == GR_OK) st = set_box(p, r, err);
    if (st == GR_OK) st = gr_report_make_dir(outdir, err);
    if (st == GR_OK) st = search(t, s, p, r, outdir, err);
    if (st == GR_OK) st = write_images(outdir, s, p, r->xb, r->res.x, err);
    if (st != GR_OK) return st;
    char *json = tune_json(t, s, p, r);
    if (!json) return gr_fail(err, GR_E_NOMEM, "out of memory building the JSON");
    char path[4300];
    snprintf(path, sizeof path, "%s/tune.json", outdir);
    st = gr_tune_write_text(path, json, err);
    free(json);
    if (st != GR_OK) return st;
    gr_strbuf sum;
    gr_sb_init(&sum);
    tune_summary(t, s, p, r, outdir, &sum);
    fputs(gr_sb_str(&sum), stdout);
    st = write_page(s, gr_sb_str(&sum), outdir, err);
    gr_sb_free(&sum);
    return st;
}

/* The command after gr_args_create; returns the exit code (gr_args_main frees args). */
static int tune_with(gr_args *args)
{
    const char *cmd = "tune";
    tune_opts *t = calloc(1, sizeof *t);
    tune_run *r = calloc(1, sizeof *r);
    gr_tune_problem *p = calloc(1, sizeof *p);
    gr_tune_session s;
    memset(&s, 0, sizeof s);
    gr_error err = {GR_OK, ""};
    int rc = 0;
    if (!t || !r || !p) {
        gr_fail(&err, GR_E_NOMEM, "out of memory");
        rc = gr_cli_report(cmd, &err);
    }
    if (!rc) rc = parse_args(args, t);
    if (!rc && !t->help && (rc = gr_args_need_scene(args)) == 0 && (rc = gr_args_add_technique_dirs(args)) == 0 &&
        (rc = parse_params(t, r)) == 0) {
        if (gr_tune_cli_finish(&t->c, &err) != GR_OK || plan_search(t, r, &err) != GR_OK) rc = gr_cli_report(cmd, &err);
    }
    char dirbuf[4096];
    const char *outdir = NULL;
    if (!rc && !t->help) {
        t->c.so.scene_path = args->scene_path;
        t->c.so.sets = gr_args_sets(args);
        t->c.so.n_sets = args->n_sets;
        t->c.so.progress_label = "godrays tune";
        /* The ground truths take minutes: a folder that cannot be made is refused before them. */
        rc = gr_args_output_dir(args, NULL, t->outopt, "tune", dirbuf, sizeof dirbuf, &outdir);
        if (!rc && tune_outputs(t, r, &s, p, outdir, &err) != GR_OK) rc = gr_cli_report(cmd, &err);
    }
    if (r) free(r->snippet);
    if (p) gr_tune_problem_free(p);
    free(p);
    free(r);
    free(t);
    gr_tune_session_close(&s);
    return rc;
}

int cmd_tune(int argc, char **argv)
{
    return gr_args_main("tune", argc, argv, tune_with);
}
