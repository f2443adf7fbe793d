/* report/report: the whole report on synthetic images, checked against values the test
 * computes itself:
 *  - the best scale a = <t, r> / <t, t> and the luminance RMSE over the pixels that pass the
 *    stderr rule (relative luminance stderr <= 0.5), the reference noise RMS and the profile's
 *    pixel count in metrics.json;
 *  - the preview's exposure (99th percentile of max(R, G, B) -> 0.8) and its sRGB encoding;
 *  - index.html: every <img> points at a file that exists, text is escaped, nothing external;
 *  - the contact sheet places each panel at its (integer-resized) size;
 *  - two techniques: the leaderboard ranks the exact one (2 x the reference) first;
 *  - bad inputs are rejected. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <cjson/cJSON.h>

#include "check.h"
#include "files.h"
#include "compare/metrics.h"
#include "image/oiio.h"
#include "report/plot.h"
#include "report/report.h"
#include "scene/scene.h"

#define W 48
#define H 32

static double srgb(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055;
}

static int exists(const char *dir, const char *name)
{
    char p[2048];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    struct stat sb;
    return stat(p, &sb) == 0 && sb.st_size > 0;
}

static int cmp_f(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static void contact_sheet_test(void)
{
    gr_error err = {GR_OK, ""};
    const int sz[3][2] = {{20, 10}, {900, 100}, {400, 50}};
    const float col[3][3] = {{0.9f, 0.1f, 0.2f}, {0.2f, 0.8f, 0.1f}, {0.1f, 0.3f, 0.95f}};
    gr_image *p[3];
    for (int i = 0; i < 3; i++) {
        p[i] = gr_image_create(sz[i][0], sz[i][1], 3, NULL);
        for (int k = 0; k < sz[i][0] * sz[i][1]; k++)
            for (int c = 0; c < 3; c++) p[i]->pixels[k * 3 + c] = col[i][c];
    }
    const gr_image *panels[3] = {p[0], p[1], p[2]};
    const char *titles[3] = {"one", "two", "three"};
    const char *lines[2] = {"first line", "second line"};
    gr_image *s = NULL;
    int labelled = -1;
    CHECK_OK(gr_report_contact_sheet(panels, titles, lines, 2, 360, 800, &s, &labelled, &err), err);
    /* 20 px enlarged x18 to 360 (>= 360), 900 shrunk /2 to 450 (<= 800), 400 kept */
    const long expect[3] = {360L * 180, 450L * 50, 400L * 50};
    for (int i = 0; s && i < 3; i++) {
        long n = 0;
        for (int k = 0; k < s->width * s->height; k++) {
            const float *q = s->pixels + (size_t)k * 3;
            if (fabsf(q[0] - col[i][0]) < 1e-6f && fabsf(q[1] - col[i][1]) < 1e-6f && fabsf(q[2] - col[i][2]) < 1e-6f)
                n++;
        }
        CHECK_MSG(n == expect[i], "panel %d: %ld pixels of its colour, expected %ld", i, n, expect[i]);
    }
    CHECK(s && s->width >= 360 + 450 + 400 && s->height >= 180);
    CHECK(labelled == 0 || labelled == 1);
    gr_image_destroy(s);
    CHECK(gr_report_contact_sheet(panels, titles, lines, -1, 360, 800, &s, NULL, &err) == GR_E_INPUT);
    for (int i = 0; i < 3; i++) gr_image_destroy(p[i]);
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    contact_sheet_test();

    /* display encoding and exposure */
    gr_image *g = gr_image_create(10, 10, 3, NULL);
    for (int i = 0; i < 100; i++) {
        g->pixels[i * 3 + 0] = (float)(i + 1);
        g->pixels[i * 3 + 1] = 0.0f;
        g->pixels[i * 3 + 2] = 0.0f;
    }
    /* 100 values 1..100: the 99th percentile sample (index floor(99 * 0.99) = 98) is 99 */
    CHECK_NEAR(gr_report_exposure(g, 1.0, 0.99, 0.8), 0.8 / 99.0, 1e-12);
    CHECK_NEAR(gr_report_exposure(g, 2.0, 0.99, 0.8), 0.4 / 99.0, 1e-12);
    g->pixels[0] = 0.5f;
    g->pixels[3] = 0.002f;
    gr_image *d = NULL;
    CHECK_OK(gr_report_display(g, 1.0, &d, &err), err);
    if (d) {
        CHECK_NEAR(d->pixels[0], 0.735356983, 1e-6); /* 1.055 * 0.5^(1/2.4) - 0.055 */
        CHECK_NEAR(d->pixels[3], 0.02584, 1e-6);     /* 12.92 * 0.002 */
        CHECK_NEAR(d->pixels[6], 1.0, 0.0);          /* 3 clamps to 1 */
    }
    gr_image_destroy(d);
    for (int i = 0; i < 100; i++) g->pixels[i * 3] = 0.0f;
    CHECK_NEAR(gr_report_exposure(g, 1.0, 0.99, 0.8), 1.0, 0.0); /* black: 1 */
    gr_image_destroy(g);

    /* the synthetic pair */
    gr_scene *scene = calloc(1, sizeof *scene);
    char json[512];
    snprintf(json, sizeof json,
             "{\"name\": \"a<b>&c\", \"camera\": {\"position_m\": [0, -5, 0], \"pitch_deg\": 40, \"width\": %d,"
             " \"height\": %d}}",
             W, H);
    CHECK_OK(gr_scene_load_string(json, "synthetic", NULL, 0, scene, &err), err);
    static const char *const rn[6] = {"R", "G", "B", "stderr.R", "stderr.G", "stderr.B"};
    gr_image *ref = gr_image_create(W, H, 6, rn), *test = gr_image_create(W, H, 3, NULL);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float *r = gr_image_pixel(ref, x, y), *t = gr_image_pixel(test, x, y);
            const double base = 0.05 + 0.9 * exp(-((x - 20.0) * (x - 20.0) + (y - 10.0) * (y - 10.0)) / 60.0);
            r[0] = (float)(0.3 * base);
            r[1] = (float)(0.6 * base);
            r[2] = (float)(0.9 * base);
            const float se = (x < 4 && y < 4) ? 0.5f : 0.004f; /* a noisy corner: not scored */
            r[3] = r[4] = r[5] = se;
            const double wob = 1.0 + 0.2 * sin(0.7 * x) * cos(0.5 * y);
            for (int c = 0; c < 3; c++) t[c] = (float)(3.0 * r[c] * wob);
        }
    /* independent: scored pixels, a, luminance RMSE, noise */
    double tr = 0, tt = 0, noise = 0;
    int scored[W * H], nsc = 0;
    for (int p = 0; p < W * H; p++) {
        const float *r = ref->pixels + p * 6, *t = test->pixels + p * 3;
        const double yr = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2];
        const double sy = 0.2126 * r[3] + 0.7152 * r[4] + 0.0722 * r[5];
        noise += sy * sy;
        scored[p] = sy / fabs(yr) <= 0.5;
        if (!scored[p]) continue;
        nsc++;
        for (int c = 0; c < 3; c++) {
            tr += (double)t[c] * r[c];
            tt += (double)t[c] * t[c];
        }
    }
    noise = sqrt(noise / (W * H));
    const double a = tr / tt;
    double se_raw = 0;
    for (int p = 0; p < W * H; p++) {
        if (!scored[p]) continue;
        const float *r = ref->pixels + p * 6, *t = test->pixels + p * 3;
        const double dy = 0.2126 * (t[0] - r[0]) + 0.7152 * (t[1] - r[1]) + 0.0722 * (t[2] - r[2]);
        se_raw += dy * dy;
    }
    const double rmse_raw = sqrt(se_raw / nsc);
    CHECK(nsc == W * H - 16);

    /* a second technique: exactly twice the reference, so a = 1/2 and it leads the board */
    gr_image *test2 = gr_image_create(W, H, 3, NULL);
    for (int p = 0; p < W * H; p++)
        for (int c = 0; c < 3; c++) test2->pixels[p * 3 + c] = 2.0f * ref->pixels[p * 6 + c];
    gr_metrics m, m2;
    gr_metrics_options opt = {0};
    opt.fit_scale = 1;
    CHECK_OK(gr_metrics_compute(ref, test, &opt, &m, &err), err);
    CHECK_OK(gr_metrics_compute(ref, test2, &opt, &m2, &err), err);
    gr_metadata rmeta, tmeta;
    gr_meta_init(&rmeta);
    gr_meta_init(&tmeta);
    gr_meta_set_double(&rmeta, "godrays:wall_s", 12.5);
    gr_meta_set_string(&rmeta, "godrays:note", "x < y & \"z\"");
    gr_meta_set_string(&tmeta, "godrays:passes", "first main");
    gr_meta_set_int(&tmeta, "godrays:gpu_ns.main", 2000000);
    gr_meta_set_int(&tmeta, "godrays:gpu_ns.first", -1);
    gr_meta_set_double(&tmeta, "godrays:gpu_ms", 2.0);

    const char *out = getenv("GODRAYS_TEST_OUT");
    char dir[1024], cmd[2200], path[1200];
    snprintf(dir, sizeof dir, "%s/report_write", out ? out : "/tmp");
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
    gr_report_technique ts[2] = {
        {.name = "wobble", .description = "test <one>", .test = test, .meta = &tmeta, .metrics = &m, .seconds = 0.5},
        {.name = "exact", .test = test2, .metrics = &m2, .seconds = 0.25},
    };
    gr_report_input in = {.scene = scene, .ref = ref, .ref_meta = &rmeta, .n_techniques = 2, .techniques = ts,
                          .command_line = "godrays run <x>", .ref_seconds = 1.0, .compare_seconds = 0.1};
    gr_report_result res;
    CHECK_OK(gr_report_write(dir, &in, &res, &err), err);
    CHECK_NEAR(res.fit_scale[0], a, 1e-9 * a);
    CHECK_NEAR(res.fit_scale[1], 0.5, 1e-6);
    CHECK(res.order[0] == 1 && res.order[1] == 0); /* exact first */
    static const char *const files[] = {"index.html", "summary.png", "metrics.json", "reference.png", "wobble.png",
                                        "wobble_raw.png", "wobble_diff.png", "wobble_diff_signed.png", "exact.png",
                                        "exact_raw.png", "exact_diff.png", "exact_diff_signed.png", "wobble_flip.png",
                                        "exact_flip.png"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) CHECK_MSG(exists(dir, files[i]), "%s missing", files[i]);
    CHECK(res.charts == (gr_plot_available() ? 5 : 0)); /* the shared profile + 2 per technique */

    /* metrics.json */
    snprintf(path, sizeof path, "%s/metrics.json", dir);
    char *text = slurp(path);
    cJSON *root = text ? cJSON_Parse(text) : NULL;
    CHECK(root != NULL);
    if (root) {
        cJSON *tarr = cJSON_GetObjectItemCaseSensitive(root, "techniques");
        CHECK(cJSON_IsArray(tarr) && cJSON_GetArraySize(tarr) == 2);
        cJSON *t0 = cJSON_GetArrayItem(tarr, 0), *t1 = cJSON_GetArrayItem(tarr, 1);
        cJSON *v = get(t0, "name");
        CHECK(cJSON_IsString(v) && !strcmp(v->valuestring, "wobble"));
        v = get(t0, "fit_scale");
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - a) <= 1e-9 * a);
        v = get(t0, "previews.scale");
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - a) <= 1e-9 * a);
        v = get(t0, "error_vs_blur.rmse_y_raw");
        CHECK(cJSON_IsArray(v) && cJSON_GetArraySize(v) == 4);
        if (cJSON_IsArray(v)) CHECK_REL(cJSON_GetArrayItem(v, 0)->valuedouble, rmse_raw, 1e-9);
        v = get(t0, "errors_y.rmse");
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - rmse_raw) <= 1e-9 * rmse_raw);
        v = get(t0, "compare.stderr_excluded_pixels");
        CHECK(cJSON_IsNumber(v) && v->valuedouble == 16);
        v = get(t0, "gpu_ms");
        CHECK(cJSON_IsNumber(v) && v->valuedouble == 2.0);
        v = get(t0, "rank");
        CHECK(cJSON_IsNumber(v) && v->valuedouble == 2);
        v = get(t1, "rank");
        CHECK(cJSON_IsNumber(v) && v->valuedouble == 1);
        v = get(t1, "errors_y.rel_rmse_fit"); /* 2 r scaled by 1/2 is r: no error */
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble) <= 1e-6);
        v = get(t1, "flip.mean"); /* the same image after the fit: FLIP 0 (within float rounding of a) */
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble) <= 1e-3);
        v = get(t0, "flip.mean");
        CHECK(cJSON_IsNumber(v) && v->valuedouble > 0.0);
        v = get(t0, "flip.map");
        CHECK(cJSON_IsString(v) && !strcmp(v->valuestring, "wobble_flip.png"));
        v = get(t1, "gpu_ms");
        CHECK(cJSON_IsNull(v)); /* no metadata: unknown */
        v = cJSON_GetObjectItemCaseSensitive(root, "leaderboard");
        CHECK(cJSON_IsArray(v) && cJSON_GetArraySize(v) == 2 &&
              !strcmp(cJSON_GetArrayItem(v, 0)->valuestring, "exact") &&
              !strcmp(cJSON_GetArrayItem(v, 1)->valuestring, "wobble"));
        v = get(root, "reference.noise_rms_stderr_y");
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - noise) <= 1e-6 * noise);
        v = get(root, "radial_profile.pixels");
        double total = 0;
        for (cJSON *e = v ? v->child : NULL; e; e = e->next) total += e->valuedouble;
        CHECK_NEAR(total, W * H, 0);
        v = get(root, "scene.name");
        CHECK(cJSON_IsString(v) && !strcmp(v->valuestring, "a<b>&c"));
        v = get(root, "reference.metadata.godrays:wall_s");
        CHECK(cJSON_IsNumber(v) && v->valuedouble == 12.5);
        /* the preview exposure: 99th percentile of max(R, G, B) of the reference -> 0.8 */
        float mx[W * H];
        for (int p = 0; p < W * H; p++) mx[p] = ref->pixels[p * 6 + 2]; /* B is the largest here */
        qsort(mx, W * H, sizeof(float), cmp_f);
        const double e = 0.8 / mx[(int)((W * H - 1) * 0.99)];
        v = get(root, "reference.preview_exposure");
        CHECK(cJSON_IsNumber(v) && fabs(v->valuedouble - e) <= 1e-9 * e);
        /* reference.png holds sRGB(e * R) in 8 bits */
        gr_image *png = NULL;
        snprintf(path, sizeof path, "%s/reference.png", dir);
        CHECK_OK(gr_oiio_read(path, 0, &png, &err), err);
        if (png) {
            const float *q = gr_image_pixel(png, 20, 10);
            const float *r = gr_image_pixel(ref, 20, 10);
            for (int c = 0; c < 3; c++) CHECK_NEAR(q[c], srgb(e * r[c]), 0.5 / 255 + 1e-6);
        }
        gr_image_destroy(png);
    }
    cJSON_Delete(root);
    free(text);

    /* index.html */
    snprintf(path, sizeof path, "%s/index.html", dir);
    char *html = slurp(path);
    CHECK(html != NULL);
    if (html) {
        CHECK(strstr(html, "a&lt;b&gt;&amp;c") != NULL);
        CHECK(strstr(html, "a<b>&c") == NULL);
        CHECK(strstr(html, "x &lt; y &amp; &quot;z&quot;") != NULL);
        CHECK(strstr(html, "godrays run &lt;x&gt;") != NULL);
        CHECK(strstr(html, "http://") == NULL && strstr(html, "https://") == NULL);
        /* one script: the interactive comparison (report/viewer.h), its images inside the page */
        const char *sc = strstr(html, "<script");
        CHECK(sc != NULL && strstr(sc + 1, "<script") == NULL);
        CHECK(strstr(html, "data:image/png;base64,") != NULL);
        int nimg = 0;
        for (const char *p = strstr(html, "<img src=\""); p; p = strstr(p + 1, "<img src=\"")) {
            char name[256];
            const char *b = p + 10, *e = strchr(b, '"');
            if (!e || e - b >= (long)sizeof name) break;
            memcpy(name, b, (size_t)(e - b));
            name[e - b] = '\0';
            CHECK_MSG(exists(dir, name) && !strchr(name, '/'), "<img src=\"%s\"> is not a file in the folder", name);
            nimg++;
        }
        /* 2 thumbnails, 6 figures per technique (the reference beside each), the charts */
        CHECK_MSG(nimg == 2 + 2 * 6 + res.charts, "%d images in index.html", nimg); /* 6 with the FLIP map */
        CHECK(strstr(html, "16 pixels NOT SCORED") != NULL);
        CHECK(strstr(html, "2 ms") != NULL); /* the main pass's GPU time from the metadata */
        CHECK(strstr(html, "test &lt;one&gt;") != NULL);
        const char *pe = strstr(html, "href=\"#t-exact\""), *pw = strstr(html, "href=\"#t-wobble\"");
        CHECK(pe && pw && pe < pw); /* the leaderboard lists the better technique first */
    }
    free(html);

    /* bad inputs */
    gr_image *small = gr_image_create(W - 1, H, 3, NULL);
    ts[1].test = small;
    CHECK(gr_report_write(dir, &in, NULL, &err) == GR_E_INPUT);
    ts[1].test = test2;
    ts[0].metrics = NULL;
    CHECK(gr_report_write(dir, &in, NULL, &err) == GR_E_INPUT);
    ts[0].metrics = &m;
    ts[1].name = "wobble"; /* twice the same name */
    CHECK(gr_report_write(dir, &in, NULL, &err) == GR_E_INPUT && strstr(err.msg, "twice"));
    ts[1].name = "exact";
    in.n_techniques = 0;
    CHECK(gr_report_write(dir, &in, NULL, &err) == GR_E_INPUT);
    in.n_techniques = 2;
    snprintf(path, sizeof path, "%s/index.html", dir);
    CHECK(gr_report_write(path, &in, NULL, &err) == GR_E_IO); /* a file where the folder should be */
    CHECK(strstr(err.msg, "index.html") != NULL);

    gr_image_destroy(small);
    gr_image_destroy(ref);
    gr_image_destroy(test);
    gr_image_destroy(test2);
    gr_meta_free(&rmeta);
    gr_meta_free(&tmeta);
    free(scene);
    CHECK_DONE();
}
