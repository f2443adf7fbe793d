/* compare/registry: a metric added in ONE place (one descriptor registered at run time, with
 * its own compute function) is seen everywhere that lists metrics, with the value the test
 * computes itself from the definition (max |a Y(test) - Y(ref)| over the scored pixels, a the
 * least-squares scale over the scored RGB samples):
 *  - gr_metrics_compute: the raw and fitted values, the mask honoured, skip_extra leaves it out;
 *  - `compare`'s outputs: gr_metrics_to_json (each set's "registry" object, the descriptor
 *    under conventions.registry) and the text summary (gr_metrics_print_summary);
 *  - `run`'s report: metrics.json (errors_y.KEY, KEY_fit and the "compare" entry), index.html
 *    (the registry table and a leaderboard column);
 *  - tuning: --metric/--objective accept the key, the objective is its value (divided by the
 *    mean reference Y with --normalize: the metric is in image units), the help lists it.
 * Also the registry's refusals (bad or taken key, both or neither function, wrong cost, full). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "check.h"
#include "files.h"
#include "compare/metrics.h"
#include "compare/metrics_io.h"
#include "compare/registry.h"
#include "report/report.h"
#include "scene/scene.h"
#include "tune/cliopts.h"
#include "tune/objective.h"

#define W 24
#define H 16
#define KEY "peak_dy"

static const double lw[3] = {0.2126, 0.7152, 0.0722};

/* The new metric: max over scored pixels of |scale Y(test) - Y(ref)|. */
static gr_status peak_dy(const gr_metric_input *in, void *user, double *value, gr_error *err)
{
    (void)err;
    int *calls = user;
    (*calls)++;
    double mx = 0.0;
    const size_t n = (size_t)in->ref->width * (size_t)in->ref->height;
    for (size_t p = 0; p < n; p++) {
        if (!in->scored[p]) continue;
        const float *r = in->ref->pixels + p * (size_t)in->ref->nchannels;
        const float *t = in->test->pixels + p * (size_t)in->test->nchannels;
        double d = 0.0;
        for (int c = 0; c < 3; c++) d += lw[c] * (in->scale * t[in->test_rgb[c]] - r[in->ref_rgb[c]]);
        if (fabs(d) > mx) mx = fabs(d);
    }
    *value = mx;
    return GR_OK;
}

static int calls = 0;

static void refusals(void)
{
    gr_error err = {GR_OK, ""};
    gr_metric_desc d = {.key = "x", .label = "x", .doc = "x", .cost = GR_METRIC_COST_OWN, .compute = peak_dy};
    d.key = "Bad-key";
    CHECK(gr_metric_register(&d, &err) == GR_E_INPUT && strstr(err.msg, "Bad-key"));
    d.key = "rmse";
    CHECK(gr_metric_register(&d, &err) == GR_E_INPUT && strstr(err.msg, "already registered"));
    d.key = "two_fns";
    d.extract = NULL;
    d.compute = NULL;
    CHECK(gr_metric_register(&d, &err) == GR_E_INPUT && strstr(err.msg, "exactly one"));
    d.key = "wrong_cost";
    d.compute = peak_dy;
    d.cost = GR_METRIC_COST_PASS;
    CHECK(gr_metric_register(&d, &err) == GR_E_INPUT && strstr(err.msg, "cost"));
    d.cost = GR_METRIC_COST_OWN;
    d.doc = "";
    CHECK(gr_metric_register(&d, &err) == GR_E_INPUT && strstr(err.msg, "doc"));
    CHECK(gr_metric_count() == GR_METRIC_N_BUILTIN); /* nothing refused was added */
}

/* The expected value: a the least-squares scale over scored RGB samples (fit) or 1. */
static double expect_peak(const gr_image *ref, const gr_image *test, const unsigned char *scored, int fit)
{
    double tr = 0, tt = 0;
    for (int p = 0; p < W * H; p++)
        for (int c = 0; c < 3 && scored[p]; c++) {
            tr += (double)test->pixels[p * 3 + c] * ref->pixels[p * 3 + c];
            tt += (double)test->pixels[p * 3 + c] * test->pixels[p * 3 + c];
        }
    const double a = fit ? tr / tt : 1.0;
    double mx = 0;
    for (int p = 0; p < W * H; p++) {
        if (!scored[p]) continue;
        double d = 0;
        for (int c = 0; c < 3; c++) d += lw[c] * (a * test->pixels[p * 3 + c] - ref->pixels[p * 3 + c]);
        mx = fmax(mx, fabs(d));
    }
    return mx;
}

static void check_report(const gr_scene *scene, const gr_image *ref, const gr_image *test, const gr_metrics *m,
                         double raw, double fit)
{
    gr_error err = {GR_OK, ""};
    const char *out = getenv("GODRAYS_TEST_OUT");
    char dir[1024], cmd[1200], path[1200];
    snprintf(dir, sizeof dir, "%s/metric_registry", out ? out : "/tmp");
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
    gr_report_technique t = {.name = "spiky", .test = test, .metrics = m, .seconds = 0.1};
    gr_report_input in = {.scene = scene, .ref = ref, .n_techniques = 1, .techniques = &t};
    CHECK_OK(gr_report_write(dir, &in, NULL, &err), err);
    /* index.html: the registry table names it; the leaderboard has its two columns */
    snprintf(path, sizeof path, "%s/index.html", dir);
    char *html = slurp(path);
    const char *lb = html ? strstr(html, "id=\"leaderboard\"") : NULL, *end = lb ? strstr(lb, "</tr>") : NULL;
    const char *col = lb ? strstr(lb, "<th>peak dY</th><th>peak dY<br>after fit</th>") : NULL;
    CHECK(html && strstr(html, "<code>" KEY "</code>") != NULL);
    CHECK(col && end && col < end);
    free(html);
    /* metrics.json: errors_y and the compare block */
    snprintf(path, sizeof path, "%s/metrics.json", dir);
    char *text = slurp(path);
    cJSON *root = text ? cJSON_Parse(text) : NULL;
    cJSON *t0 = root ? cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "techniques"), 0) : NULL;
    cJSON *v = get(t0, "errors_y." KEY);
    CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - raw) <= 1e-12);
    v = get(t0, "errors_y." KEY "_fit");
    CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - fit) <= 1e-12);
    v = get(t0, "compare.fitted.registry." KEY);
    CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - fit) <= 1e-12);
    cJSON_Delete(root);
    free(text);
}

static void check_tune(const gr_metrics *m, int idx, double raw)
{
    gr_error err = {GR_OK, ""};
    gr_tune_metric tm = -2;
    CHECK_OK(gr_tune_metric_parse("--metric", KEY, &tm, &err), err);
    CHECK(tm == idx && !strcmp(gr_tune_metric_name(tm), KEY));
    gr_tune_problem *p = calloc(1, sizeof *p);
    CHECK_OK(gr_tune_weights_parse("--objective", KEY "=2,rmse=0", p->weights, &err), err);
    CHECK(p->weights[idx] == 2.0 && p->weights[GR_METRIC_RMSE] == 0.0);
    p->metric = tm;
    CHECK_NEAR(gr_tune_value(p, &m->raw), raw, 1e-15);
    p->normalize = 1; /* in image units: relative to the mean reference Y */
    CHECK_NEAR(gr_tune_value(p, &m->raw), raw / m->raw.ch[GR_MCH_Y].ref_mean, 1e-12);
    p->metric = GR_TM_WEIGHTED; /* its weight alone: the same relative value */
    CHECK_NEAR(gr_tune_value(p, &m->raw), raw / m->raw.ch[GR_MCH_Y].ref_mean, 1e-12);
    free(p);
    CHECK(strstr(gr_tune_cli_help(), KEY) != NULL);
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    refusals();

    /* the ONE place: the descriptor */
    static const gr_metric_desc desc = {
        .key = KEY, .label = "peak dY", .doc = "largest |a Y(test) - Y(ref)| over the scored pixels",
        .unit = GR_METRIC_RADIANCE, .better = GR_METRIC_LOWER, .cost = GR_METRIC_COST_OWN, .leaderboard = 1,
        .compute = peak_dy, .user = &calls};
    CHECK_OK(gr_metric_register(&desc, &err), err);
    const int idx = gr_metric_find(KEY);
    CHECK(idx == GR_METRIC_N_BUILTIN && gr_metric_count() == GR_METRIC_N_BUILTIN + 1);
    CHECK(gr_metric_register(&desc, &err) == GR_E_INPUT); /* once */

    /* ref: a gray ramp; test: 1.5 x ref with a spike at (5, 3) */
    gr_image *ref = gr_image_create(W, H, 3, NULL), *test = gr_image_create(W, H, 3, NULL);
    gr_image *mask = gr_image_create(W, H, 1, NULL);
    for (int p = 0; p < W * H; p++) {
        const float r = 0.2f + 0.01f * (float)(p % W);
        for (int c = 0; c < 3; c++) {
            ref->pixels[p * 3 + c] = r;
            test->pixels[p * 3 + c] = 1.5f * r + (p == 3 * W + 5 ? 0.3f : 0.0f);
        }
        mask->pixels[p] = p == 3 * W + 5 ? 0.0f : 1.0f;
    }
    unsigned char all[W * H], masked[W * H];
    for (int p = 0; p < W * H; p++) all[p] = 1, masked[p] = mask->pixels[p] != 0.0f;
    const double raw = expect_peak(ref, test, all, 0), fit = expect_peak(ref, test, all, 1);
    CHECK(raw > 0.4 && fit > 0.0 && fit < raw); /* the spike dominates raw */

    gr_metrics m;
    gr_metrics_options opt = {.fit_scale = 1};
    CHECK_OK(gr_metrics_compute(ref, test, &opt, &m, &err), err);
    CHECK(calls == 2); /* once per set */
    CHECK_NEAR(gr_metric_value(&m.raw, idx), raw, 1e-12);
    CHECK_NEAR(gr_metric_value(&m.fit, idx), fit, 1e-12);

    gr_metrics mm;
    gr_metrics_options mopt = {.fit_scale = 1, .mask = mask};
    CHECK_OK(gr_metrics_compute(ref, test, &mopt, &mm, &err), err);
    CHECK_NEAR(gr_metric_value(&mm.raw, idx), expect_peak(ref, test, masked, 0), 1e-12);
    CHECK_NEAR(gr_metric_value(&mm.fit, idx), expect_peak(ref, test, masked, 1), 1e-12);
    gr_metrics ms;
    gr_metrics_options sopt = {.skip_extra = 1};
    calls = 0;
    CHECK_OK(gr_metrics_compute(ref, test, &sopt, &ms, &err), err);
    CHECK(calls == 0 && isnan(gr_metric_value(&ms.raw, idx)));

    /* compare's JSON and text */
    cJSON *j = gr_metrics_to_json(&m);
    cJSON *v = get(j, "metrics.registry." KEY);
    CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - raw) <= 1e-12);
    v = get(j, "fitted.registry." KEY);
    CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - fit) <= 1e-12);
    v = get(j, "conventions.registry." KEY ".unit");
    CHECK(cJSON_IsString(v) && !strcmp(v->valuestring, "radiance"));
    v = get(j, "conventions.registry." KEY ".cost");
    CHECK(cJSON_IsString(v) && !strcmp(v->valuestring, "own"));
    cJSON_Delete(j);
    char buf[4096] = "";
    FILE *f = tmpfile();
    CHECK(f != NULL);
    if (f) {
        gr_metrics_print_summary(f, &m, ~0u);
        rewind(f);
        size_t n = fread(buf, 1, sizeof buf - 1, f);
        buf[n] = '\0';
        fclose(f);
    }
    char want[128];
    snprintf(want, sizeof want, "peak dY (" KEY ")");
    const char *line = strstr(buf, want);
    double vr = NAN, vf = NAN;
    CHECK(line && sscanf(line + strlen(want), "%lf %lf", &vr, &vf) == 2);
    CHECK_REL(vr, raw, 1e-5); /* printed with 6 digits */
    CHECK_REL(vf, fit, 1e-5);

    /* the report */
    gr_scene *scene = calloc(1, sizeof *scene);
    char sj[256];
    snprintf(sj, sizeof sj, "{\"camera\": {\"position_m\": [0, -5, 0], \"pitch_deg\": 40, \"width\": %d, \"height\": %d}}",
             W, H);
    CHECK_OK(gr_scene_load_string(sj, "synthetic", NULL, 0, scene, &err), err);
    check_report(scene, ref, test, &m, raw, fit);
    check_tune(&m, idx, raw);

    free(scene);
    gr_image_destroy(ref);
    gr_image_destroy(test);
    gr_image_destroy(mask);
    CHECK_DONE();
}
