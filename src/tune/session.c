/* Cases, ground truths and renderer shared by sweep and tune (session.h). */
#include "tune/session.h"
#include "common/outfile.h"
#include "compare/fit.h"

#include <cjson/cJSON.h>

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int parse_num(const char *s, double *v)
{
    char *end = NULL;
    errno = 0;
    double x = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(x)) return -1;
    *v = x;
    return 0;
}

gr_status gr_tune_parse_frames(const char *flag, const char *spec, double fps, double *times, int max, int *n,
                               gr_error *err)
{
    long a, b, step;
    char extra;
    if (sscanf(spec, "%ld:%ld:%ld%c", &a, &b, &step, &extra) != 3 || a < 0 || b < a || step < 1)
        return gr_fail(err, GR_E_USAGE, "%s %s: expected START:END:STEP with 0 <= START <= END, STEP >= 1", flag, spec);
    for (long f = a; f <= b; f += step) {
        if (*n >= max) return gr_fail(err, GR_E_USAGE, "%s %s: more than %d frames", flag, spec, max);
        times[(*n)++] = (double)f / fps;
    }
    return GR_OK;
}

gr_status gr_tune_parse_times(const char *flag, const char *spec, double *times, int max, int *n, gr_error *err)
{
    char buf[1024];
    if (snprintf(buf, sizeof buf, "%s", spec) >= (int)sizeof buf)
        return gr_fail(err, GR_E_USAGE, "%s: list too long", flag);
    char *save = NULL;
    int any = 0;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        double t;
        if (parse_num(tok, &t)) return gr_fail(err, GR_E_USAGE, "%s %s: '%s' is not a number", flag, spec, tok);
        if (*n >= max) return gr_fail(err, GR_E_USAGE, "%s %s: more than %d times", flag, spec, max);
        times[(*n)++] = t;
        any = 1;
    }
    if (!any) return gr_fail(err, GR_E_USAGE, "%s: empty list of times", flag);
    return GR_OK;
}

gr_status gr_tune_parse_view(const char *flag, const char *spec, gr_tune_view *v, gr_error *err)
{
    char buf[256];
    if (snprintf(buf, sizeof buf, "%s", spec) >= (int)sizeof buf) return gr_fail(err, GR_E_USAGE, "%s: too long", flag);
    char *comma = strchr(buf, ',');
    if (!comma) return gr_fail(err, GR_E_USAGE, "%s %s: expected YAW,PITCH in degrees", flag, spec);
    *comma = '\0';
    if (parse_num(buf, &v->yaw_deg) || parse_num(comma + 1, &v->pitch_deg))
        return gr_fail(err, GR_E_USAGE, "%s %s: expected YAW,PITCH in degrees", flag, spec);
    if (!(v->pitch_deg >= -90 && v->pitch_deg <= 90))
        return gr_fail(err, GR_E_USAGE, "%s %s: pitch must be in [-90, 90]", flag, spec);
    return GR_OK;
}

void gr_tune_default_dir(const char *name, const char *sub, char *buf, size_t n)
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
    size_t len = strlen(buf);
    if (sub && len + 1 < n) snprintf(buf + len, n - len, "/%s", sub);
}

gr_status gr_tune_write_text(const char *path, const char *text, gr_error *err)
{
    return gr_outfile_write(path, text, -1, err);
}

void gr_tune_session_close(gr_tune_session *s)
{
    if (!s) return;
    for (int i = 0; i < GR_TUNE_MAX_CASES; i++) {
        gr_image_destroy(s->refs[i]);
        s->refs[i] = NULL;
    }
    gr_technique_destroy(s->renderer);
    gr_gl_destroy(s->gl);
    free(s->cases);
    free(s->base);
    memset(s, 0, sizeof *s);
}

gr_status gr_tune_session_open(const gr_tune_session_options *o, gr_tune_session *s, gr_error *err)
{
    memset(s, 0, sizeof *s);
    const char *label = o->progress_label ? o->progress_label : "godrays";
    int n_times = o->n_times > 0 ? o->n_times : 1;
    int n_views = 1 + o->n_views;
    if (n_times * n_views > GR_TUNE_MAX_CASES)
        return gr_fail(err, GR_E_USAGE, "%d frames x %d views: more than %d cases", n_times, n_views, GR_TUNE_MAX_CASES);
    s->base = malloc(sizeof *s->base);
    s->cases = malloc((size_t)(n_times * n_views) * sizeof *s->cases);
    if (!s->base || !s->cases) return gr_fail(err, GR_E_NOMEM, "out of memory for the scene");
    s->cls = o->technique ? o->technique : gr_technique_at(0);
    if (!s->cls) return gr_fail(err, GR_E_USAGE, "no real-time technique is registered");
    gr_status st = gr_scene_load_file(o->scene_path, o->sets, o->n_sets, s->base, err);
    if (st != GR_OK) return st;
    /* bad settings are bad input (exit 2) before any GL or slow work */
    if ((st = gr_technique_check(s->cls, gr_technique_scene_settings(s->cls, s->base), err)) != GR_OK) return st;
    for (int t = 0; t < n_times; t++) {
        double time_s = o->n_times > 0 ? o->times[t] + (o->times_relative ? s->base->water.time_s : 0.0)
                                        : s->base->water.time_s;
        for (int v = 0; v < n_views; v++) {
            int i = t * n_views + v;
            st = gr_tune_make_case(s->base, time_s, v == 0 ? NULL : &o->views[v - 1], &s->cases[i], err);
            if (st != GR_OK) return st;
            snprintf(s->labels[i], sizeof s->labels[i], "t=%gs,view%d", time_s, v);
            s->n_cases = i + 1;
        }
    }
    gr_gl_options glo;
    memset(&glo, 0, sizeof glo);
    glo.platform = o->gl_platform;
    if ((st = gr_gl_create(&glo, &s->gl, err)) != GR_OK) return st;
    if ((st = gr_technique_create(s->cls, s->gl, NULL, &s->renderer, err)) != GR_OK) return st;
    for (int i = 0; i < s->n_cases; i++) {
        if (o->progress)
            fprintf(stderr, "%s: ground truth %d/%d (%s, %dx%d)...\n", label, i + 1, s->n_cases, s->labels[i],
                    s->cases[i].camera.width, s->cases[i].camera.height);
        gr_truth_options to;
        gr_truth_options_default(&to);
        to.use_cache = o->use_cache;
        to.ref.progress = o->progress;
        st = gr_truth_image(&s->cases[i], &to, &s->refs[i], &s->truth[i], err);
        if (st != GR_OK) return st;
        s->truth_seconds += s->truth[i].seconds;
        if (o->progress && s->truth[i].cached) fprintf(stderr, "%s:   from the cache %s\n", label, s->truth[i].path);
        if (o->progress && s->truth[i].note[0]) fprintf(stderr, "%s:   note: %s\n", label, s->truth[i].note);
        /* a coarse truth (docs/reference.md 4, "Views with a wide lit region"), as run's page says; not
         * under -q, as reference and run */
        char coarse[320];
        if (o->progress && gr_truth_coarse(&s->truth[i], &s->cases[i], coarse, sizeof coarse))
            fprintf(stderr, "%s: warning: ground truth %d/%d (%s): %s\n", label, i + 1, s->n_cases, s->labels[i], coarse);
    }
    return GR_OK;
}

void gr_tune_session_problem(const gr_tune_session *s, gr_tune_problem *p)
{
    p->renderer = s->renderer;
    p->n_cases = s->n_cases;
    for (int i = 0; i < s->n_cases; i++) {
        p->scenes[i] = &s->cases[i];
        p->refs[i] = s->refs[i];
    }
    p->cls = s->cls;
    memcpy(p->base.bytes, gr_technique_scene_settings(s->cls, s->base), s->cls->settings_size);
}

cJSON *gr_tune_json_root(const gr_tune_session *s, const gr_tune_problem *p)
{
    cJSON *root = cJSON_CreateObject();
    if (!root) return NULL;
    cJSON_AddStringToObject(root, "scene", s->base->name);
    cJSON_AddStringToObject(root, "technique", p->cls->name);
    cJSON_AddStringToObject(root, "scene_file", s->base->source_path);
    cJSON_AddStringToObject(root, "metric", gr_tune_metric_name(p->metric));
    cJSON_AddStringToObject(root, "channel", "Y");
    cJSON_AddBoolToObject(root, "fit_scale", p->fit);
    cJSON_AddStringToObject(root, "fit", gr_fit_mode_name((gr_fit_mode)p->fit));
    cJSON_AddBoolToObject(root, "rgb_per_channel", p->rgb_per_channel);
    cJSON_AddBoolToObject(root, "normalized", p->normalize);
    cJSON_AddNumberToObject(root, "width", s->base->camera.width);
    cJSON_AddNumberToObject(root, "height", s->base->camera.height);
    return root;
}

cJSON *gr_tune_json_case(const gr_tune_session *s, int i)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddStringToObject(o, "label", s->labels[i]);
    cJSON_AddNumberToObject(o, "time_s", s->cases[i].water.time_s);
    cJSON_AddNumberToObject(o, "yaw_deg", s->cases[i].camera.yaw_deg);
    cJSON_AddNumberToObject(o, "pitch_deg", s->cases[i].camera.pitch_deg);
    return o;
}
