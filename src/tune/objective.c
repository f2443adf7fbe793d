/* A technique's error against the ground truth as a function of its settings (objective.h). */
#include "tune/objective.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "report/profile.h"

gr_status gr_tune_metric_parse(const char *flag, const char *s, gr_tune_metric *m, gr_error *err)
{
    const int i = gr_metric_find(s);
    if (i >= 0 && gr_metric_is_objective(gr_metric_at(i))) {
        *m = i;
        return GR_OK;
    }
    char keys[512];
    gr_metric_keys(keys, sizeof keys, ", ", 1);
    return gr_fail(err, GR_E_USAGE, "%s %s: unknown metric (expected one of %s)", flag, s, keys);
}

gr_status gr_tune_weights_parse(const char *flag, const char *s, double w[GR_METRIC_MAX], gr_error *err)
{
    for (int k = 0; k < GR_METRIC_MAX; k++) w[k] = 0.0;
    char buf[512];
    if (!s || strlen(s) >= sizeof buf) return gr_fail(err, GR_E_USAGE, "%s: missing or too long", flag);
    strcpy(buf, s);
    double total = 0.0;
    for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(t, '=');
        if (!eq) return gr_fail(err, GR_E_USAGE, "%s %s: '%s' is not NAME=WEIGHT", flag, s, t);
        *eq = '\0';
        gr_tune_metric m = 0;
        if (gr_tune_metric_parse(flag, t, &m, err) != GR_OK) return err->status;
        char *end = NULL;
        const double v = strtod(eq + 1, &end);
        if (end == eq + 1 || *end || !isfinite(v) || v < 0.0)
            return gr_fail(err, GR_E_USAGE, "%s %s: weight '%s' of %s is not a number >= 0", flag, s, eq + 1, t);
        w[m] = v;
        total += v;
    }
    if (!(total > 0.0)) return gr_fail(err, GR_E_USAGE, "%s %s: no weight > 0", flag, s);
    return GR_OK;
}

const char *gr_tune_metric_name(gr_tune_metric m)
{
    if (m == GR_TM_WEIGHTED) return "objective";
    const gr_metric_desc *d = gr_metric_at(m);
    return d ? d->key : "?";
}

double gr_tune_metric_value(const gr_metrics_set *set, gr_tune_metric m)
{
    const double v = gr_metric_loss(gr_metric_at(m), gr_metric_value(set, m));
    return isfinite(v) ? v : 1e300;
}

/* Whether registry metric k enters the problem's value. */
static int uses(const gr_tune_problem *p, int k)
{
    return p->metric == k || (p->metric == GR_TM_WEIGHTED && p->weights[k] > 0.0);
}

/* Whether any metric the problem uses needs the scene (the beams' vanishing point). */
static int uses_scene(const gr_tune_problem *p)
{
    for (int k = 0; k < gr_metric_count(); k++)
        if (uses(p, k) && gr_metric_at(k)->needs_scene) return 1;
    return 0;
}

double gr_tune_value(const gr_tune_problem *p, const gr_metrics_set *set)
{
    const double mean_y = set->ch[GR_MCH_Y].ref_mean;
    if (p->metric != GR_TM_WEIGHTED) {
        double v = gr_tune_metric_value(set, p->metric);
        /* relative error: a bright view (toward the sun) would otherwise outweigh the rest */
        const gr_metric_desc *d = gr_metric_at(p->metric);
        if (p->normalize && d && d->unit == GR_METRIC_RADIANCE && mean_y > 0) v /= mean_y;
        return v;
    }
    return gr_metric_weighted(set, p->weights); /* compare/registry.h: the verdict's combination */
}

/* The metrics options of case i for the problem's metric(s): only the parts (cost classes)
 * they need; fo and so are the caller's. */
static void case_options(const gr_tune_problem *p, int i, gr_metrics_options *opt, gr_flip_options *fo,
                         gr_structure_options *so)
{
    for (int k = 0; k < gr_metric_count(); k++) {
        if (!uses(p, k)) continue;
        switch (gr_metric_at(k)->cost) {
        case GR_METRIC_COST_FLIP:
            memset(fo, 0, sizeof *fo);
            fo->mode = GR_FLIP_HDR;
            opt->flip = fo;
            break;
        case GR_METRIC_COST_STRUCTURE:
            if (!p->no_vp[i]) {
                const gr_camera *c = &p->scenes[i]->camera;
                memset(so, 0, sizeof *so);
                so->vp_x = p->vp[i][0], so->vp_y = p->vp[i][1];
                so->radial = p->angles[i], so->radial_bin = c->fov_deg / c->height;
                opt->structure = so;
            }
            break;
        case GR_METRIC_COST_SSIM: opt->skip_ssim = 0; break;
        case GR_METRIC_COST_BLUR: opt->skip_blur = 0; break;
        case GR_METRIC_COST_OWN: opt->skip_extra = 0; break;
        case GR_METRIC_COST_PASS:
        case GR_METRIC_COST_COUNT: break;
        }
    }
}

gr_status gr_tune_make_case(const gr_scene *base, double time_s, const gr_tune_view *view, gr_scene *out,
                            gr_error *err)
{
    if (out != base) memcpy(out, base, sizeof *out);
    out->water.time_s = time_s;
    if (view) {
        out->camera.has_look_at = 0;
        out->camera.yaw_deg = view->yaw_deg;
        out->camera.pitch_deg = view->pitch_deg;
    }
    gr_status st = gr_scene_refresh(out, err);
    if (st != GR_OK && view)
        gr_error_prefix(err, "--view %g,%g", view->yaw_deg, view->pitch_deg);
    return st;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

gr_status gr_tune_problem_init(gr_tune_problem *p, gr_error *err)
{
    p->scratch = p->scratch2 = NULL;
    for (int i = 0; i < GR_TUNE_MAX_CASES; i++) p->angles[i] = NULL, p->sref[i] = NULL, p->fref[i] = NULL;
    if (p->n_cases < 1 || p->n_cases > GR_TUNE_MAX_CASES)
        return gr_fail(err, GR_E_INPUT, "tuning: %d cases (1..%d)", p->n_cases, GR_TUNE_MAX_CASES);
    if (p->n_params < 0 || p->n_params > GR_TUNE_MAX_PARAMS)
        return gr_fail(err, GR_E_INPUT, "tuning: %d parameters (0..%d)", p->n_params, GR_TUNE_MAX_PARAMS);
    const gr_camera *c0 = &p->scenes[0]->camera;
    for (int i = 0; i < p->n_cases; i++) {
        const gr_camera *c = &p->scenes[i]->camera;
        if (c->width != c0->width || c->height != c0->height)
            return gr_fail(err, GR_E_INPUT, "tuning: case %d is %dx%d, case 0 is %dx%d", i, c->width, c->height,
                           c0->width, c0->height);
        if (!p->refs[i] || p->refs[i]->width != c->width || p->refs[i]->height != c->height)
            return gr_fail(err, GR_E_INPUT, "tuning: the ground truth of case %d is not %dx%d", i, c->width, c->height);
    }
    if (!p->cls || !p->renderer || gr_technique_class_of(p->renderer) != p->cls)
        return gr_fail(err, GR_E_INPUT, "tuning: no technique instance of the problem's class");
    for (int k = 0; k < p->n_params; k++)
        if (p->params[k].cls != p->cls)
            return gr_fail(err, GR_E_USAGE, "%s: not a setting of technique %s (choose it with --technique)",
                           p->params[k].key, p->cls->name);
    gr_section_store r;
    gr_technique_resolve(p->cls, p->scenes[0], p->base.bytes, r.bytes);
    p->base = r;
    p->scratch = gr_image_create(c0->width, c0->height, 3, NULL);
    p->scratch2 = gr_image_create(c0->width, c0->height, 3, NULL);
    if (!p->scratch || !p->scratch2) return gr_fail(err, GR_E_NOMEM, "tuning: out of memory for a %dx%d frame", c0->width, c0->height);
    if (uses_scene(p)) {
        /* the structure metrics' geometry per case: the vanishing point of the refracted sun's
         * rays and the angle to the sun (their de-glow), once */
        for (int i = 0; i < p->n_cases; i++) {
            const gr_camera *c = &p->scenes[i]->camera;
            gr_status st = gr_structure_scene_vp(p->scenes[i], c->width, c->height, &p->vp[i][0], &p->vp[i][1], err);
            p->no_vp[i] = 0;
            double others = 0.0;
            for (int k = 0; k < gr_metric_count(); k++)
                if (!gr_metric_at(k)->needs_scene) others += p->weights[k];
            if (st == GR_E_INPUT && p->metric == GR_TM_WEIGHTED && others > 0.0) {
                p->no_vp[i] = 1; /* the other terms carry this case */
                continue;
            }
            if (st != GR_OK) {
                gr_error_prefix(err, "tuning: case %d: structure metrics", i);
                gr_tune_problem_free(p);
                return st;
            }
            p->angles[i] = malloc((size_t)c->width * (size_t)c->height * sizeof(float));
            if (!p->angles[i]) {
                gr_tune_problem_free(p);
                return gr_fail(err, GR_E_NOMEM, "tuning: out of memory");
            }
            double dir[3];
            gr_profile_sun_view_dir(p->scenes[i], dir);
            gr_profile_angles(c, dir, p->angles[i]);
        }
    }
    p->renders = 0;
    p->work = 0.0;
    p->render_s = p->metrics_s = p->wall_ms_sum = p->gpu_ms_sum = 0.0;
    p->gpu_timed = 0;
    return GR_OK;
}

void gr_tune_problem_free(gr_tune_problem *p)
{
    if (!p) return;
    gr_image_destroy(p->scratch);
    gr_image_destroy(p->scratch2);
    p->scratch = p->scratch2 = NULL;
    for (int i = 0; i < GR_TUNE_MAX_CASES; i++) {
        free(p->angles[i]);
        p->angles[i] = NULL;
        gr_structure_ref_destroy(p->sref[i]);
        p->sref[i] = NULL;
        gr_flip_reference_destroy(p->fref[i]);
        p->fref[i] = NULL;
    }
}

gr_status gr_tune_settings_at(const gr_tune_problem *p, const double *x, void *out, gr_error *err)
{
    memcpy(out, p->base.bytes, p->cls->settings_size);
    for (int k = 0; k < p->n_params; k++) {
        gr_status st = gr_tune_param_apply(&p->params[k], p->base.bytes, x[k], out, err);
        if (st != GR_OK) return st;
    }
    return GR_OK;
}

/* One render of case i into out (GL: the calling thread), counted in p's accounting. */
static gr_status render_case(gr_tune_problem *p, int i, const void *s, gr_image *out, gr_error *err)
{
    gr_technique_stats stats;
    double t0 = now_s();
    /* a search's renders: what depends only on the frame may be reused (technique.h); off
     * again after, for whoever times this instance next */
    gr_technique_set_reuse(p->renderer, 1);
    gr_status st = gr_technique_render(p->renderer, p->scenes[i], s, out, &stats, err);
    gr_technique_set_reuse(p->renderer, 0);
    p->render_s += now_s() - t0;
    if (st != GR_OK) return st;
    p->renders++;
    p->work += (double)gr_technique_stats_work(&stats);
    p->wall_ms_sum += stats.wall_ms;
    for (int k = 0; k < stats.n_passes; k++) {
        if (stats.gpu_ns[k] >= 0) {
            p->gpu_ms_sum += (double)stats.gpu_ns[k] * 1e-6;
            p->gpu_timed = 1;
        }
    }
    return GR_OK;
}

/* One render + metrics; opt chooses which metrics are computed. */
static gr_status render_score(gr_tune_problem *p, int i, const void *s, gr_image *out,
                              const gr_metrics_options *opt, gr_metrics *m, gr_error *err)
{
    gr_status st = render_case(p, i, s, out, err);
    if (st != GR_OK) return st;
    const double t1 = now_s();
    st = gr_metrics_compute(p->refs[i], out, opt, m, err);
    p->metrics_s += now_s() - t1;
    return st;
}

/* The comparison of one rendered case, run beside the next case's render (gr_tune_evaluate):
 * it reads only its own frame, its case's truth and its case's kept structure half. */
typedef struct score_job {
    const gr_image *ref, *img;
    gr_metrics_options opt;
    gr_flip_options fo;
    gr_structure_options so;
    gr_metrics m;
    gr_status st;
    gr_error err;
    double seconds;
} score_job;

static void *score_run(void *arg)
{
    score_job *j = arg;
    const double t0 = now_s();
    j->st = gr_metrics_compute(j->ref, j->img, &j->opt, &j->m, &j->err);
    j->seconds = now_s() - t0;
    return NULL;
}

/* The case's value from its finished comparison (taken in case order, so that the sum is the
 * same as one case after the other). */
static gr_status take_score(gr_tune_problem *p, int i, score_job *j, double *sum, double *per_case, double *scale,
                            gr_error *err)
{
    p->metrics_s += j->seconds;
    if (j->st != GR_OK) {
        if (err) *err = j->err;
        return j->st;
    }
    const gr_metrics_set *set = p->fit ? &j->m.fit : &j->m.raw;
    const double v = gr_tune_value(p, set);
    *sum += v;
    if (per_case) per_case[i] = v;
    if (scale) scale[i] = p->fit ? j->m.fit.scale : 1.0;
    for (int c = 0; c < 3; c++) p->scale_rgb[i][c] = p->fit ? j->m.fit.scale_rgb[c] : 1.0;
    return GR_OK;
}

gr_status gr_tune_evaluate(gr_tune_problem *p, const double *x, double *mean, double *per_case, double *scale,
                           gr_error *err)
{
    gr_section_store s;
    gr_status st = gr_tune_settings_at(p, x, s.bytes, err);
    if (st != GR_OK) return st;
    /* Case i's comparison runs on a second thread while case i + 1 renders (GL stays on this
     * thread; the two frames alternate), so that a 2-core machine compares on the core the
     * rasterizer leaves idle; the values and their order are those of one case after the
     * other. Only what the metric needs: the pointwise pass is cheap, SSIM and blurs are not. */
    score_job *jobs = malloc(2 * sizeof *jobs);
    if (!jobs) return gr_fail(err, GR_E_NOMEM, "tuning: out of memory");
    gr_image *frames[2] = {p->scratch, p->scratch2};
    pthread_t th;
    int pending = -1, threaded = 0; /* the case whose comparison runs (threaded: on th) */
    double sum = 0.0;
    for (int i = 0; i < p->n_cases && st == GR_OK; i++) {
        score_job *j = &jobs[i & 1];
        st = render_case(p, i, s.bytes, frames[i & 1], err);
        if (pending >= 0) { /* the previous case's comparison, taken before this one's starts */
            if (threaded) pthread_join(th, NULL);
            const gr_status sp = take_score(p, pending, &jobs[pending & 1], &sum, per_case, scale,
                                            st == GR_OK ? err : NULL);
            if (st == GR_OK) st = sp;
            pending = -1;
        }
        if (st != GR_OK) break;
        memset(j, 0, sizeof *j);
        j->ref = p->refs[i];
        j->img = frames[i & 1];
        j->opt.stderr_bound = p->stderr_bound;
        j->opt.fit_scale = p->fit;
        j->opt.skip_ssim = j->opt.skip_blur = j->opt.skip_extra = 1;
        j->opt.flip_fit_only = 1; /* take_score reads the fitted set alone when fitting */
        j->opt.structure_ref = &p->sref[i]; /* the truth's half, made once per case */
        size_t kept = 0; /* FLIP's truth half too, while the cases' halves fit GR_TUNE_FLIP_KEEP_MAX */
        for (int k = 0; k < p->n_cases; k++) kept += gr_flip_reference_bytes(p->fref[k]);
        if (p->fref[i] || kept < GR_TUNE_FLIP_KEEP_MAX) j->opt.flip_ref = &p->fref[i];
        case_options(p, i, &j->opt, &j->fo, &j->so);
        pending = i;
        threaded = i + 1 < p->n_cases && pthread_create(&th, NULL, score_run, j) == 0;
        if (!threaded) score_run(j); /* the last case (or no thread to be had): here */
    }
    if (pending >= 0) {
        if (threaded) pthread_join(th, NULL);
        const gr_status sp = take_score(p, pending, &jobs[pending & 1], &sum, per_case, scale, st == GR_OK ? err : NULL);
        if (st == GR_OK) st = sp;
    }
    free(jobs);
    if (st == GR_OK) *mean = sum / (double)p->n_cases;
    return st;
}

gr_status gr_tune_render_case(gr_tune_problem *p, int i, const void *s, gr_image *out, gr_metrics *m,
                              gr_error *err)
{
    if (i < 0 || i >= p->n_cases) return gr_fail(err, GR_E_INPUT, "tuning: no case %d", i);
    gr_metrics_options opt = {0};
    gr_flip_options fo;
    gr_structure_options so;
    opt.stderr_bound = p->stderr_bound;
    opt.fit_scale = 1;
    case_options(p, i, &opt, &fo, &so);
    gr_metrics local;
    return render_score(p, i, s, out, &opt, m ? m : &local, err);
}

gr_status gr_tune_objective(void *user, const double *x, double *f, gr_error *err)
{
    return gr_tune_evaluate((gr_tune_problem *)user, x, f, NULL, NULL, err);
}

static double round_sig(double v, int digits)
{
    if (v == 0.0 || !isfinite(v)) return v;
    char buf[64];
    snprintf(buf, sizeof buf, "%.*g", digits, v);
    return strtod(buf, NULL);
}

static int add_rgb(cJSON *o, const char *name, const double *rgb)
{
    double r[3] = {round_sig(rgb[0], 5), round_sig(rgb[1], 5), round_sig(rgb[2], 5)};
    cJSON *a = cJSON_CreateDoubleArray(r, 3);
    return a && cJSON_AddItemToObject(o, name, a);
}

void gr_tune_mean_scale_rgb(const gr_tune_problem *p, double out[3])
{
    for (int c = 0; c < 3; c++) {
        out[c] = 0.0;
        for (int i = 0; i < p->n_cases; i++) out[c] += p->scale_rgb[i][c] / p->n_cases;
    }
}

char *gr_tune_snippet(const gr_tune_problem *p, const double *x, const double *scale)
{
    gr_section_store s;
    gr_error e;
    if (gr_tune_settings_at(p, x, s.bytes, &e) != GR_OK) return NULL;
    cJSON *root = cJSON_CreateObject();
    cJSON *sh = root ? cJSON_AddObjectToObject(root, p->cls->name) : NULL;
    const gr_param *gain = p->cls->gain_key ? gr_param_find(p->cls->params, p->cls->gain_key) : NULL;
    int ok = sh != NULL, has_gain = 0;
    const int per_channel = p->rgb_per_channel && scale && gain && gain->type == GR_PT_RGB;
    for (int k = 0; ok && k < p->n_params; k++) {
        const gr_tune_param *tp = &p->params[k];
        if (tp->p == gain) has_gain = 1;
        if (tp->p == gain && per_channel) continue; /* written below, with the fit folded in */
        if (tp->kind == GR_TK_RGB_SCALE) {
            const double *rgb = (const double *)(const void *)(s.bytes + tp->p->offset);
            ok = add_rgb(sh, tp->p->name, rgb);
        } else {
            double v = gr_param_get_number(tp->p, s.bytes, 0);
            ok = cJSON_AddNumberToObject(sh, tp->p->name, tp->kind == GR_TK_INT ? v : round_sig(v, 5)) != NULL;
        }
    }
    const double a = scale ? scale[0] : 0.0;
    if (ok && (per_channel || (gain && !has_gain && a > 0 && a != 1.0))) {
        if (gain->type == GR_PT_RGB) {
            double in[3];
            for (int c = 0; c < 3; c++) in[c] = gr_param_get_number(gain, s.bytes, c) * (per_channel ? scale[c] : a);
            ok = add_rgb(sh, gain->name, in);
        } else {
            ok = cJSON_AddNumberToObject(sh, gain->name, round_sig(gr_param_get_number(gain, s.bytes, 0) * a, 5)) != NULL;
        }
    }
    char *text = ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    return text;
}
