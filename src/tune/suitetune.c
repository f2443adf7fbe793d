/* Tuning over a view suite (suitetune.h). */
#include "tune/suitetune.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "report/profile.h"
#include "tune/cliopts.h"
#include "tune/optimize.h"
#include "tune/paramspec.h"
#include "tune/pareto.h"

/* The settings a level starts from: case 0's section with the ladder applied, and every
 * scene-derived setting that is not in keep[] (the tuned ones) set back to NaN, so that each
 * case's render resolves it from its own scene (gr_technique_render). */
static gr_status level_base(const gr_technique_class *cls, const gr_scene *scene0, int level,
                            const gr_tune_param *keep, int n_keep, gr_section_store *out, gr_error *err)
{
    memcpy(out->bytes, gr_technique_scene_settings(cls, scene0), cls->settings_size);
    if (level >= 0) {
        gr_status st = gr_technique_apply_text(cls, out->bytes, cls->ladder[level].settings, err);
        if (st != GR_OK) return st;
    }
    for (size_t i = 0; i < cls->params->count; i++) {
        const gr_param *p = &cls->params->params[i];
        int kept = 0;
        for (int k = 0; k < n_keep; k++) kept |= keep[k].p == p;
        if (!p->scene_source || kept) continue;
        double *v = (double *)(void *)(out->bytes + p->offset);
        if (p->type == GR_PT_DOUBLE) v[0] = NAN;
        else if (p->type == GR_PT_RGB) v[0] = v[1] = v[2] = NAN;
    }
    return GR_OK;
}

/* A problem over the cases of one split, scored by the default objective (the verdict) after
 * the scale fit, from base (kept unresolved: see level_base). */
static gr_status make_problem(gr_technique *r, const gr_st_case *cases, int n_cases, gr_split split,
                              const gr_section_store *base, const gr_tune_param *params, int n_params,
                              gr_tune_problem *p, gr_error *err)
{
    memset(p, 0, sizeof *p);
    p->renderer = r;
    p->cls = gr_technique_class_of(r);
    for (int i = 0; i < n_cases; i++) {
        if (cases[i].split != split) continue;
        if (p->n_cases >= GR_TUNE_MAX_CASES)
            return gr_fail(err, GR_E_INPUT, "suite tuning: more than %d %s cases", GR_TUNE_MAX_CASES,
                           split == GR_SPLIT_TRAIN ? "train" : "test");
        p->scenes[p->n_cases] = cases[i].scene;
        p->refs[p->n_cases++] = cases[i].truth;
    }
    if (p->n_cases == 0)
        return gr_fail(err, GR_E_INPUT, "suite tuning: no %s case", split == GR_SPLIT_TRAIN ? "train" : "test");
    p->base = *base;
    p->n_params = n_params;
    if (n_params > 0) memcpy(p->params, params, (size_t)n_params * sizeof *params);
    p->metric = GR_TM_WEIGHTED;
    gr_status st = gr_tune_weights_parse("objective", GR_TUNE_DEFAULT_OBJECTIVE, p->weights, err);
    p->fit = GR_FIT_SCALE;
    if (st == GR_OK) st = gr_tune_problem_init(p, err);
    if (st == GR_OK) p->base = *base; /* init resolved it from case 0: each case resolves its own */
    return st;
}

gr_status gr_st_score(gr_technique *r, const gr_st_case *cases, int n_cases, gr_split split, const void *s,
                      double *mean, gr_error *err)
{
    gr_tune_problem p;
    gr_section_store base;
    memcpy(base.bytes, s, gr_technique_class_of(r)->settings_size);
    gr_status st = make_problem(r, cases, n_cases, split, &base, NULL, 0, &p, err);
    if (st == GR_OK) st = gr_tune_evaluate(&p, NULL, mean, NULL, NULL, err);
    gr_tune_problem_free(&p);
    return st;
}

/* The parameters: o->params or the class's tune_keys. */
static gr_status level_params(const gr_technique_class *cls, const gr_st_options *o, gr_tune_param *params, int *n,
                              gr_error *err)
{
    char buf[1024];
    const char *spec = o && o->params ? o->params : NULL;
    if (!spec) {
        if (gr_tune_default_params(cls, buf, sizeof buf))
            return gr_fail(err, GR_E_INPUT, "technique %s has no settings to tune", cls->name);
        spec = buf;
    }
    return gr_tune_param_parse_list("--params", spec, params, GR_TUNE_MAX_PARAMS, n, err);
}

static void point_init(gr_st_point *pt, const gr_technique_class *cls, int level, int tuned, const gr_tune_problem *p)
{
    memset(pt, 0, sizeof *pt);
    pt->cls = cls;
    pt->level = level;
    pt->tuned = tuned;
    snprintf(pt->ladder, sizeof pt->ladder, "%s", level >= 0 ? cls->ladder[level].settings : "");
    pt->n_params = tuned ? p->n_params : 0;
    for (int k = 0; k < pt->n_params; k++) snprintf(pt->keys[k], sizeof pt->keys[k], "%s", p->params[k].p->name);
    pt->train_error = pt->test_error = NAN;
}

const char *gr_st_search_name(int local)
{
    return local == GR_ST_CARRIED ? "carried" : local == GR_ST_LOCAL ? "local" : "global";
}

/* The global search's options for np settings (o's overrides applied). */
static void global_options(gr_opt_options *oo, int np, const double *x0, const gr_st_options *o)
{
    gr_tune_search_defaults(oo, np, x0);
    oo->seed = o ? o->seed : 0;
    oo->n_starts = o && o->n_starts > 0 ? o->n_starts : 2;
    oo->screen = 2 * oo->n_starts;
    oo->coarse = o && o->coarse > 0 ? o->coarse : 8 * np;
    if (o && o->max_evals > 0) {
        oo->max_evals = oo->polish = o->max_evals;
        if (oo->screen_evals > o->max_evals) oo->screen_evals = o->max_evals;
    }
}

/* The most evaluations a global search with these options makes: the first stage, each
 * screened candidate's short run, the continuing starts' remainder, the polish. */
static int global_evals(const gr_opt_options *oo)
{
    const int screened = oo->screen > oo->n_starts ? oo->screen : 0;
    const int rest = oo->max_evals - (screened ? oo->screen_evals : 0);
    return oo->coarse + screened * oo->screen_evals + oo->n_starts * (rest > 0 ? rest : 0) + oo->polish;
}

static int local_budget(int np, const gr_st_options *o)
{
    return o && o->local_evals > 0 ? o->local_evals : gr_st_local_evals(np);
}

/* The evaluations the search of this point makes without a budget (gr_st_options.work_ref). */
static int full_evals(int np, const double *x0, const gr_st_options *o)
{
    if (o && o->n_from > 0) return (o->n_from < 2 ? o->n_from : 2) + 2 * local_budget(np, o);
    gr_opt_options oo;
    global_options(&oo, np, x0, o);
    return global_evals(&oo);
}

/* The search of one ladder point on the train problem p from the untuned x0 (its value f0):
 * the global search of optimize.c, or with o->n_from the continuation's local search
 * (suitetune.h) from the best of x0 and o->from[] (candidates evaluated in order, ties: the
 * earlier; their evaluations counted in res->evals). budget > 0: at most about that many
 * evaluations (suitetune.h "Search budgets"): a global search that does not fit becomes the
 * local one from x0, a local one is shortened, and below the least local search only the
 * candidates are evaluated (*local = GR_ST_CARRIED). */
static gr_status search(gr_tune_problem *p, int np, const double *x0, double f0, const double *lo, const double *hi,
                        const gr_st_options *o, int budget, gr_opt_result *res, int *local, gr_error *err)
{
    gr_opt_options oo;
    global_options(&oo, np, x0, o);
    const int n_from = o && o->n_from > 0 ? (o->n_from < 2 ? o->n_from : 2) : 0;
    *local = n_from > 0 || (budget > 0 && budget < global_evals(&oo)) ? GR_ST_LOCAL : GR_ST_GLOBAL;
    if (*local == GR_ST_GLOBAL) return gr_opt_minimize(np, lo, hi, gr_tune_objective, p, &oo, res, err);
    double best[GR_TUNE_MAX_PARAMS], fb = f0;
    int extra = 0;
    memcpy(best, x0, (size_t)np * sizeof *best);
    for (int c = 0; c < n_from; c++) {
        double xc[GR_TUNE_MAX_PARAMS], f;
        for (int k = 0; k < np; k++) xc[k] = o->from[c][k] < lo[k] ? lo[k] : o->from[c][k] > hi[k] ? hi[k] : o->from[c][k];
        gr_status st = gr_tune_objective(p, xc, &f, err);
        if (st != GR_OK) return st;
        extra++;
        if (f < fb) fb = f, memcpy(best, xc, (size_t)np * sizeof *best);
    }
    /* the continuation's local search, shortened to the budget; an anchor's global search that
     * does not fit: the local search from x0 with the whole budget */
    int evals = n_from > 0 ? local_budget(np, o) : budget / 2;
    if (budget > 0 && n_from + 2 * evals > budget) evals = (budget - n_from) / 2;
    if (evals < np + 2) { /* not even a simplex and a step along each axis: the best candidate */
        memset(res, 0, sizeof *res);
        res->n = np;
        res->f = fb;
        memcpy(res->x, best, (size_t)np * sizeof *best);
        res->evals = extra;
        *local = GR_ST_CARRIED;
        return GR_OK;
    }
    /* one start, no first stage, no screening: a simplex of 5 % of each box side (the
     * neighbouring point's optimum is that close: docs/tuning.md) and its restart at a fifth
     * of that, then the compass polish along the axes (on an 8-bit target's stepped error
     * surface the simplex stalls on a step; the polish moves one setting at a time) */
    oo.x0 = best;
    oo.n_starts = 1;
    oo.coarse = oo.screen = 0;
    oo.init_step = 0.05;
    oo.max_evals = oo.polish = evals;
    gr_status st = gr_opt_minimize(np, lo, hi, gr_tune_objective, p, &oo, res, err);
    if (st == GR_OK && !(res->f <= fb)) { /* never worse than its start (a failed run's f is +inf) */
        res->f = fb;
        memcpy(res->x, best, (size_t)np * sizeof *best);
    }
    res->evals += extra;
    return st;
}

gr_status gr_st_tune_level(gr_technique *r, const gr_st_case *cases, int n_cases, int level, const gr_st_options *o,
                           gr_st_point *untuned, gr_st_point *tuned, gr_error *err)
{
    const gr_technique_class *cls = gr_technique_class_of(r);
    gr_tune_param params[GR_TUNE_MAX_PARAMS];
    int np = 0;
    gr_section_store base;
    gr_tune_problem train, test;
    memset(&train, 0, sizeof train);
    memset(&test, 0, sizeof test);
    if (n_cases < 1) return gr_fail(err, GR_E_INPUT, "suite tuning: no cases");
    if (level >= cls->n_ladder) return gr_fail(err, GR_E_INPUT, "technique %s: no ladder level %d", cls->name, level);
    gr_status st = level_params(cls, o, params, &np, err);
    if (st == GR_OK) st = level_base(cls, cases[0].scene, level, params, np, &base, err);
    if (st == GR_OK) st = make_problem(r, cases, n_cases, GR_SPLIT_TRAIN, &base, params, np, &train, err);
    if (st == GR_OK) st = make_problem(r, cases, n_cases, GR_SPLIT_TEST, &base, params, np, &test, err);
    /* the untuned point: x0 = the base's own values (RGB: scale 1), the search's first start */
    double x0[GR_TUNE_MAX_PARAMS], lo[GR_TUNE_MAX_PARAMS], hi[GR_TUNE_MAX_PARAMS];
    for (int k = 0; k < np; k++) {
        const gr_tune_param *tp = &params[k];
        x0[k] = tp->kind == GR_TK_RGB_SCALE ? 1.0 : gr_param_get_number(tp->p, train.base.bytes, 0);
        lo[k] = tp->lo;
        hi[k] = tp->hi;
        x0[k] = x0[k] < lo[k] ? lo[k] : x0[k] > hi[k] ? hi[k] : x0[k];
    }
    gr_st_point u;
    point_init(&u, cls, level, 0, &train);
    if (st == GR_OK) st = gr_tune_settings_at(&train, x0, u.settings.bytes, err);
    train.work = 0.0;
    if (st == GR_OK) st = gr_tune_evaluate(&train, x0, &u.train_error, NULL, NULL, err);
    u.work = train.work;
    if (st == GR_OK) st = gr_tune_evaluate(&test, x0, &u.test_error, NULL, NULL, err);
    if (st == GR_OK && untuned) *untuned = u;
    if (st == GR_OK && tuned) {
        gr_opt_result res;
        gr_st_point *t = tuned;
        point_init(t, cls, level, 1, &train);
        /* the search budget: 1 / r of the evaluations for r times the reference work */
        if (o && o->work_ref > 0 && u.work > o->work_ref)
            t->budget = (int)ceil(o->work_ref / u.work * (double)full_evals(np, x0, o));
        st = search(&train, np, x0, u.train_error, lo, hi, o, t->budget, &res, &t->local, err);
        if (st == GR_OK) {
            memcpy(t->x, res.x, (size_t)np * sizeof *t->x);
            t->evals = res.evals;
            t->work = u.work;
            st = gr_tune_settings_at(&train, res.x, t->settings.bytes, err);
        }
        /* the errors at the best point: the untuned point's where it is the untuned settings
         * (renders are deterministic: the same settings give the same images), else the
         * search's own train value (the same function on the same problem) and the test cases */
        if (st == GR_OK && memcmp(res.x, x0, (size_t)np * sizeof *x0) == 0) {
            t->train_error = u.train_error;
            t->test_error = u.test_error;
        } else if (st == GR_OK) {
            if (isfinite(res.f)) t->train_error = res.f;
            else st = gr_tune_evaluate(&train, res.x, &t->train_error, NULL, NULL, err);
            if (st == GR_OK) st = gr_tune_evaluate(&test, res.x, &t->test_error, NULL, NULL, err);
        }
    }
    gr_tune_problem_free(&train);
    gr_tune_problem_free(&test);
    if (st != GR_OK) gr_error_prefix(err, "%s %s", cls->name, level >= 0 ? cls->ladder[level].settings : "(scene's settings)");
    return st;
}

gr_status gr_st_level_settings(const gr_technique_class *cls, const gr_scene *scene0, int level, const gr_st_options *o,
                               const double *x, void *out, gr_error *err)
{
    gr_tune_param params[GR_TUNE_MAX_PARAMS];
    int np = 0;
    gr_section_store base, resolved;
    gr_status st = level_params(cls, o, params, &np, err);
    if (st == GR_OK) st = level_base(cls, scene0, level, params, np, &base, err);
    if (st != GR_OK) return st;
    memcpy(out, base.bytes, cls->settings_size);
    gr_technique_resolve(cls, scene0, base.bytes, resolved.bytes); /* as make_problem's init: case 0's */
    for (int k = 0; k < np && st == GR_OK; k++) st = gr_tune_param_apply(&params[k], resolved.bytes, x[k], out, err);
    return st;
}

gr_status gr_st_time_point(gr_technique *r, const gr_scene *scene, int repeat, double cap_s, gr_st_point *pt,
                           gr_error *err)
{
    gr_image *img = gr_image_create(scene->camera.width, scene->camera.height, 3, NULL);
    if (!img) return gr_fail(err, GR_E_NOMEM, "out of memory for a %dx%d frame", scene->camera.width, scene->camera.height);
    gr_status st = gr_timing_measure_capped(r, scene, pt->settings.bytes, img, 1, repeat, cap_s, &pt->timing, err);
    pt->timed = st == GR_OK;
    gr_image_destroy(img);
    return st;
}

int gr_st_local_evals(int n)
{
    return 20 + 12 * n;
}

int gr_st_continuation_order(int n, int *order, int *prev)
{
    const int a = n / 2;
    int k = 0;
    for (int l = a; l < n; l++, k++) order[k] = l, prev[k] = l == a ? -1 : k - 1;
    for (int l = a - 1; l >= 0; l--, k++) order[k] = l, prev[k] = l == a - 1 ? 0 : k - 1;
    return a;
}

void gr_st_continue_from(gr_st_options *o, const gr_st_point *anchor, const gr_st_point *neighbour)
{
    o->n_from = 0;
    const gr_st_point *c[2] = {neighbour, anchor};
    for (int i = 0; i < 2; i++) {
        if (!c[i] || !c[i]->tuned || (i == 1 && c[1] == c[0])) continue;
        memcpy(o->from[o->n_from++], c[i]->x, sizeof o->from[0]);
    }
}

void gr_st_mark_fronts(gr_st_point *pts, int n)
{
    gr_pareto_point *pp = calloc((size_t)(n > 0 ? n : 1), sizeof *pp);
    if (!pp) return;
    for (int i = 0; i < n; i++) {
        pp[i].family = 2 * gr_technique_index(pts[i].cls) + pts[i].tuned;
        pp[i].cost_s = pts[i].timed ? pts[i].timing.cost_ms : NAN;
        pp[i].error = pts[i].test_error;
    }
    gr_pareto_mark_fronts(pp, n);
    for (int i = 0; i < n; i++) pts[i].on_front = pp[i].on_front;
    free(pp);
}

void gr_st_pick(const gr_st_point *pts, int n, const double *budgets_ms, int n_budgets, int *pick)
{
    for (int b = 0; b < n_budgets; b++) {
        pick[b] = -1;
        for (int i = 0; i < n; i++) {
            if (!pts[i].timed || !(pts[i].timing.cost_ms <= budgets_ms[b]) || !isfinite(pts[i].train_error)) continue;
            const int j = pick[b];
            if (j < 0 || pts[i].train_error < pts[j].train_error ||
                (pts[i].train_error == pts[j].train_error && pts[i].timing.cost_ms < pts[j].timing.cost_ms))
                pick[b] = i;
        }
    }
}

gr_status gr_st_baselines(const gr_st_case *cases, int n_cases, gr_split split, gr_baselines *out, gr_error *err)
{
    memset(out, 0, sizeof *out);
    gr_baselines *one = malloc(sizeof *one);
    int m = 0;
    gr_status st = one ? GR_OK : gr_fail(err, GR_E_NOMEM, "out of memory");
    for (int i = 0; i < n_cases && st == GR_OK; i++) {
        if (cases[i].split != split) continue;
        const gr_camera *c = &cases[i].scene->camera;
        float *angles = malloc((size_t)c->width * (size_t)c->height * sizeof *angles);
        if (!angles) {
            st = gr_fail(err, GR_E_NOMEM, "out of memory");
            break;
        }
        gr_structure_options so;
        gr_metrics_options mo = {0};
        mo.skip_ssim = mo.skip_blur = mo.skip_extra = 1;
        mo.fit_scale = 1;
        mo.structure = gr_profile_structure_options(cases[i].scene, angles, &so) ? &so : NULL;
        st = gr_baselines_compute(cases[i].truth, &mo, one, err);
        free(angles);
        if (st != GR_OK) break;
        if (m == 0) *out = *one;
        else
            for (int k = 0; k < one->n_ladder; k++) out->verdict[k] += one->verdict[k];
        m++;
    }
    if (st == GR_OK && m == 0) st = gr_fail(err, GR_E_INPUT, "suite: no case in the split");
    if (st == GR_OK) {
        for (int k = 0; k < out->n_ladder; k++) {
            out->verdict[k] /= m;
            out->envelope[k] = k == 0 || out->verdict[k] > out->envelope[k - 1] ? out->verdict[k] : out->envelope[k - 1];
        }
    }
    free(one);
    return st;
}

void gr_st_point_label(const gr_st_point *pt, char *buf, size_t n)
{
    size_t len = 0;
    buf[0] = '\0';
    len += (size_t)snprintf(buf, n, "%s", pt->ladder[0] ? pt->ladder : "scene's settings");
    for (int k = 0; k < pt->n_params && len < n; k++) {
        const gr_param *p = gr_param_find(pt->cls->params, pt->keys[k]);
        len += (size_t)snprintf(buf + len, n - len, "%s%s=%s%.4g", k ? " " : "; ", pt->keys[k],
                                p && p->type == GR_PT_RGB ? "x" : "", pt->x[k]);
    }
}

gr_status gr_st_parse_budgets(const char *flag, const char *s, double *budgets, int max, int *n, gr_error *err)
{
    *n = 0;
    const char *c = s;
    while (*c) {
        char *end = NULL;
        errno = 0;
        const double v = strtod(c, &end);
        if (errno || end == c || !(v > 0) || !isfinite(v) || (*end && *end != ','))
            return gr_fail(err, GR_E_USAGE, "%s %s: expected milliseconds > 0 separated by commas, e.g. 0.5,1,2,4", flag, s);
        if (*n >= max) return gr_fail(err, GR_E_USAGE, "%s %s: at most %d budgets", flag, s, max);
        budgets[(*n)++] = v;
        c = *end ? end + 1 : end;
    }
    if (*n == 0) return gr_fail(err, GR_E_USAGE, "%s: no budget given", flag);
    return GR_OK;
}
