/* The report of `godrays run` (see report.h; how to read it: docs/report.md). */
#include "report/report.h"
#include "common/outfile.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "common/parallel.h"
#include "compare/diffmap.h"
#include "compare/flip.h"
#include "compare/metrics_io.h"
#include "compare/registry.h"
#include "image/oiio.h"
#include "report/html.h"
#include "report/leaderboard.h"
#include "report/plot.h"
#include "report/profile.h"
#include "report/viewer.h"
#include "scene/params.h"
#include "scene/sections.h"
#include "scene/settings.h"

#ifndef GR_VERSION
#define GR_VERSION "unknown"
#endif

#define PROFILE_TARGET_BINS 60

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- small helpers -------------------------------------------------------------------- */

gr_status gr_report_make_dir(const char *dir, gr_error *err)
{
    char buf[4096];
    if (!dir || !dir[0]) return gr_fail(err, GR_E_USAGE, "report: no output directory");
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return gr_fail(err, GR_E_USAGE, "%s: output directory name too long", dir);
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char saved = *p;
            *p = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST)
                return gr_fail(err, GR_E_IO, "%s: cannot create directory: %s", buf, strerror(errno));
            *p = saved;
            if (saved == '\0') break;
        }
    }
    struct stat sb;
    if (stat(dir, &sb) != 0 || !S_ISDIR(sb.st_mode)) return gr_fail(err, GR_E_IO, "%s: not a directory", dir);
    return GR_OK;
}

static gr_status join(char *buf, size_t n, const char *dir, const char *name, gr_error *err)
{
    if (snprintf(buf, n, "%s/%s", dir, name) >= (int)n)
        return gr_fail(err, GR_E_USAGE, "%s: output directory name too long", dir);
    return GR_OK;
}

/* Writes text to path atomically (common/outfile). */
static gr_status write_text(const char *path, const char *text, gr_error *err)
{
    return gr_outfile_write(path, text, -1, err);
}

static const gr_meta_item *meta_get(const gr_metadata *m, const char *key)
{
    return m ? gr_meta_get(m, key) : NULL;
}

/* The number stored under key, or NaN. */
static double meta_num(const gr_metadata *m, const char *key)
{
    const gr_meta_item *it = meta_get(m, key);
    if (!it || it->type == GR_META_STRING) return NAN;
    return it->num;
}

static const char *meta_str(const gr_metadata *m, const char *key)
{
    const gr_meta_item *it = meta_get(m, key);
    return it && it->type == GR_META_STRING ? it->str : NULL;
}

/* "%.4g", with "inf" / "n/a" for non-finite values. */
static const char *fmt(double v, char *buf, size_t n)
{
    if (isnan(v)) snprintf(buf, n, "n/a");
    else if (isinf(v)) snprintf(buf, n, "%sinf", v < 0 ? "-" : "");
    else snprintf(buf, n, "%.4g", v);
    return buf;
}

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

double gr_report_exposure(const gr_image *img, double scale, double q, double target)
{
    if (!img || !img->pixels || !(scale > 0.0) || !isfinite(scale)) return 1.0;
    int rgb[3];
    gr_metrics_pick_rgb(img, rgb);
    const size_t n = (size_t)img->width * (size_t)img->height;
    float *v = malloc(n * sizeof *v);
    if (!v) return 1.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = img->pixels + i * (size_t)img->nchannels;
        v[i] = fmaxf(p[rgb[0]], fmaxf(p[rgb[1]], p[rgb[2]]));
    }
    qsort(v, n, sizeof *v, cmp_float);
    const double qq = q < 0.0 ? 0.0 : q > 1.0 ? 1.0 : q;
    const double val = scale * (double)v[(size_t)((double)(n - 1) * qq)];
    free(v);
    return val > 0.0 && isfinite(target / val) ? target / val : 1.0;
}

/* sRGB transfer function (IEC 61966-2-1) of a linear value clamped to [0, 1]. */
static float srgb_encode(double x)
{
    if (!(x > 0.0)) return 0.0f;
    if (x >= 1.0) return 1.0f;
    return (float)(x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055);
}

gr_status gr_report_display(const gr_image *img, double exposure, gr_image **out, gr_error *err)
{
    *out = NULL;
    if (!img || !img->pixels) return gr_fail(err, GR_E_INPUT, "display image: no image");
    gr_image *d = gr_image_create(img->width, img->height, 3, NULL);
    if (!d) return gr_fail(err, GR_E_NOMEM, "display image: out of memory for %d x %d", img->width, img->height);
    int rgb[3];
    gr_metrics_pick_rgb(img, rgb);
    const size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            d->pixels[i * 3 + (size_t)c] = srgb_encode(exposure * (double)img->pixels[i * (size_t)img->nchannels + (size_t)rgb[c]]);
    *out = d;
    return GR_OK;
}

/* Integer resize of a 3-channel display image: k > 0 shrinks by k (box filter), k < 0
 * enlarges by -k (pixel replication: small renders stay honest, no invented detail). */
static gr_image *resize(const gr_image *src, int k)
{
    const int up = k < 0 ? -k : 1, down = k > 0 ? k : 1;
    const int w = up * ((src->width + down - 1) / down), h = up * ((src->height + down - 1) / down);
    gr_image *d = gr_image_create(w, h, 3, NULL);
    if (!d) return NULL;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s[3] = {0, 0, 0};
            int cnt = 0;
            for (int j = 0; j < down; j++)
                for (int i = 0; i < down; i++) {
                    const int sx = (x / up) * down + i, sy = (y / up) * down + j;
                    if (sx >= src->width || sy >= src->height) continue;
                    const float *p = src->pixels + ((size_t)sy * (size_t)src->width + (size_t)sx) * (size_t)src->nchannels;
                    for (int c = 0; c < 3; c++) s[c] += p[c < src->nchannels ? c : 0];
                    cnt++;
                }
            for (int c = 0; c < 3; c++) gr_image_pixel(d, x, y)[c] = (float)(s[c] / cnt);
        }
    return d;
}

gr_status gr_report_contact_sheet(const gr_image *const panels[3], const char *const titles[3],
                                  const char *const *lines, int n_lines, int min_panel_w, int max_panel_w,
                                  gr_image **out, int *labelled, gr_error *err)
{
    *out = NULL;
    if (labelled) *labelled = 0;
    if (n_lines < 0 || (n_lines > 0 && !lines) || min_panel_w < 1 || max_panel_w < 16 || min_panel_w > max_panel_w)
        return gr_fail(err, GR_E_INPUT, "contact sheet: bad text lines or panel widths %d..%d", min_panel_w, max_panel_w);
    for (int i = 0; i < 3; i++)
        if (!panels[i] || !panels[i]->pixels || panels[i]->nchannels < 1)
            return gr_fail(err, GR_E_INPUT, "contact sheet: panel %d missing", i);
    enum { M = 16, TITLE_H = 32, TITLE_PX = 18, LINE_H = 24, LINE_PX = 16 };
    gr_image *p[3] = {NULL, NULL, NULL};
    int W = M, maxh = 0;
    for (int i = 0; i < 3; i++) {
        const int w = panels[i]->width;
        int k = 1;
        if (w > max_panel_w) k = (w + max_panel_w - 1) / max_panel_w;
        else if (w < min_panel_w) k = -((min_panel_w + w - 1) / w);
        if (k < 0 && -k * w > max_panel_w) k = w * 2 <= max_panel_w ? -(max_panel_w / w) : 1;
        p[i] = resize(panels[i], k);
        if (!p[i]) {
            for (int j = 0; j < i; j++) gr_image_destroy(p[j]);
            return gr_fail(err, GR_E_NOMEM, "contact sheet: out of memory");
        }
        W += p[i]->width + M;
        if (p[i]->height > maxh) maxh = p[i]->height;
    }
    /* Wide enough for the longest text line (DejaVu Sans advances about 0.58 em per
     * character on average; 0.6 em keeps a margin). */
    size_t longest = 0;
    for (int i = 0; i < n_lines; i++)
        if (lines[i] && strlen(lines[i]) > longest) longest = strlen(lines[i]);
    const int text_w = 2 * M + (int)(0.6 * LINE_PX * (double)longest);
    const int extra = text_w > W ? text_w - W : 0;
    W += extra;
    const int H = M + TITLE_H + maxh + M + n_lines * LINE_H + M;
    gr_image *s = gr_image_create(W, H, 3, NULL);
    if (!s) {
        for (int j = 0; j < 3; j++) gr_image_destroy(p[j]);
        return gr_fail(err, GR_E_NOMEM, "contact sheet: out of memory for %d x %d", W, H);
    }
    static const float bg[3] = {0.11f, 0.12f, 0.14f};
    for (size_t i = 0; i < (size_t)W * (size_t)H; i++)
        for (int c = 0; c < 3; c++) s->pixels[i * 3 + (size_t)c] = bg[c];
    int x0 = M + extra / 2;
    int x_centre[3];
    for (int i = 0; i < 3; i++) {
        for (int y = 0; y < p[i]->height; y++)
            memcpy(gr_image_pixel(s, x0, M + TITLE_H + y), gr_image_pixel(p[i], 0, y),
                   (size_t)p[i]->width * 3 * sizeof(float));
        x_centre[i] = x0 + p[i]->width / 2;
        x0 += p[i]->width + M;
    }
    for (int j = 0; j < 3; j++) gr_image_destroy(p[j]);
    /* Labels are optional: the first text that cannot be drawn (no font) stops them all. */
    static const float fg[3] = {0.93f, 0.93f, 0.93f};
    gr_error terr = {GR_OK, ""};
    int ok = 1;
    for (int i = 0; ok && i < 3; i++)
        if (titles && titles[i])
            ok = gr_oiio_render_text(s, x_centre[i], M + TITLE_H - 10, titles[i], TITLE_PX, fg, 1, &terr) == GR_OK;
    for (int i = 0; ok && i < n_lines; i++)
        if (lines[i])
            ok = gr_oiio_render_text(s, M, M + TITLE_H + maxh + M + (i + 1) * LINE_H - 7, lines[i], LINE_PX, fg, 0,
                                     &terr) == GR_OK;
    if (labelled) *labelled = ok;
    *out = s;
    return GR_OK;
}

/* ---- charts ----------------------------------------------------------------------------- */

typedef struct profiles {
    double dir[3];
    double max_deg;
    gr_radial_profile ref;
    gr_radial_profile fit[GR_REPORT_MAX_TECHNIQUES], raw[GR_REPORT_MAX_TECHNIQUES];
    int n; /* techniques computed */
} profiles;

/* as[k]: technique k's fitted scale. */
static gr_status compute_profiles(const gr_report_input *in, const double *as, profiles *pr, gr_error *err)
{
    memset(pr, 0, sizeof *pr);
    const gr_camera *cam = &in->scene->camera;
    if (cam->width != in->ref->width || cam->height != in->ref->height)
        return gr_fail(err, GR_E_INPUT, "report: the scene's camera is %d x %d but the images are %d x %d",
                       cam->width, cam->height, in->ref->width, in->ref->height);
    const size_t n = (size_t)cam->width * (size_t)cam->height;
    float *ang = malloc(n * sizeof *ang);
    if (!ang) return gr_fail(err, GR_E_NOMEM, "report: out of memory for the radial profile");
    gr_profile_sun_view_dir(in->scene, pr->dir);
    gr_profile_angles(cam, pr->dir, ang);
    double mx = 0.0;
    for (size_t i = 0; i < n; i++) mx = fmax(mx, ang[i]);
    pr->max_deg = mx;
    const double bin = gr_profile_bin_width(mx, PROFILE_TARGET_BINS);
    const int nbins = (int)floor(mx / bin) + 1; /* the last bin holds the maximum itself */
    gr_status st = gr_radial_profile_compute(in->ref, ang, NULL, nbins, bin, 1.0, &pr->ref, err);
    for (int k = 0; st == GR_OK && k < in->n_techniques; k++) {
        const gr_image *test = in->techniques[k].test;
        st = gr_radial_profile_compute(test, ang, NULL, nbins, bin, as[k], &pr->fit[k], err);
        if (st == GR_OK) st = gr_radial_profile_compute(test, ang, NULL, nbins, bin, 1.0, &pr->raw[k], err);
        if (st == GR_OK) pr->n = k + 1;
    }
    free(ang);
    return st;
}

static void free_profiles(profiles *pr)
{
    gr_radial_profile_free(&pr->ref);
    for (int k = 0; k < GR_REPORT_MAX_TECHNIQUES; k++) {
        gr_radial_profile_free(&pr->fit[k]);
        gr_radial_profile_free(&pr->raw[k]);
    }
}

/* RMS over the image of the reference's luminance standard error (linear sum over channels,
 * docs/metrics.md): the noise level the error-vs-blur chart is drawn against. NaN without
 * stderr channels. */
static double ref_noise_rms_y(const gr_image *ref)
{
    const int s[3] = {gr_image_channel(ref, "stderr.R"), gr_image_channel(ref, "stderr.G"),
                      gr_image_channel(ref, "stderr.B")};
    if (s[0] < 0 || s[1] < 0 || s[2] < 0) return NAN;
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        const float *p = ref->pixels + i * (size_t)ref->nchannels;
        const double sy = GR_LUM_R * p[s[0]] + GR_LUM_G * p[s[1]] + GR_LUM_B * p[s[2]];
        sum += sy * sy;
    }
    return sqrt(sum / (double)n);
}

/* Colours of the techniques in the shared charts (Tableau 10 without its red, which the
 * reference's differences use). */
static const unsigned char tech_rgb[9][3] = {{31, 119, 180}, {44, 160, 44},   {255, 127, 14},
                                              {148, 103, 189}, {140, 86, 75},  {227, 119, 194},
                                              {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};

/* The report's own file stems: a technique with one of these names gets "rt_" in front. */
void gr_report_tech_stem(const char *name, char *buf, size_t n)
{
    static const char *const own[] = {"reference", "summary", "metrics", "index", "radial_profile"};
    for (size_t i = 0; i < sizeof own / sizeof own[0]; i++)
        if (!strcmp(name, own[i])) {
            snprintf(buf, n, "rt_%s", name);
            return;
        }
    snprintf(buf, n, "%s", name);
}

/* The shared luminance profile (reference + every technique x its a). */
static gr_status draw_profile_all(const char *dir, const gr_report_input *in, const double *as, const profiles *pr,
                                  gr_error *err)
{
    char path[4200], title[256];
    char (*lab)[128] = calloc((size_t)in->n_techniques, sizeof *lab);
    gr_plot_series *sr = calloc((size_t)in->n_techniques + 1, sizeof *sr);
    if (!lab || !sr) {
        free(lab);
        free(sr);
        return gr_fail(err, GR_E_NOMEM, "report: out of memory for the charts");
    }
    sr[0] = (gr_plot_series){"ground truth (reference)", pr->ref.center_deg, pr->ref.mean[GR_PROFILE_Y], pr->ref.nbins,
                             {0, 0, 0}, GR_PLOT_SOLID, 0};
    for (int k = 0; k < in->n_techniques; k++) {
        const unsigned char *c = tech_rgb[k % 9];
        snprintf(lab[k], sizeof lab[k], "%s x a (a = %.4g)", in->techniques[k].name, as[k]);
        sr[k + 1] = (gr_plot_series){lab[k], pr->fit[k].center_deg, pr->fit[k].mean[GR_PROFILE_Y], pr->fit[k].nbins,
                                     {c[0], c[1], c[2]}, GR_PLOT_DASHED, 1};
    }
    snprintf(title, sizeof title, "Radial profile of '%s': luminance vs angle from the refracted sun", in->scene->name);
    gr_plot_spec spec = {.width = 800, .height = 450, .title = title,
                         .xlabel = "angle between view ray and refracted sun direction (deg)",
                         .ylabel = "mean luminance Y", .log_y = 1, .series = sr, .n_series = in->n_techniques + 1,
                         .legend_headroom = 0.25 + 0.1 * (double)(in->n_techniques - 1)};
    gr_status st = join(path, sizeof path, dir, "radial_profile.png", err);
    if (st == GR_OK) st = gr_plot_write(path, &spec, err);
    free(lab);
    free(sr);
    return st;
}

/* Technique k's own charts: per-channel profile, error against blur. */
static gr_status draw_tech_charts(const char *dir, const gr_report_input *in, int k, double a, const profiles *pr,
                                  double noise_y, int *n_charts, gr_error *err)
{
    char path[4200], title[256], lab[2][128], stem[48], file[96];
    gr_status st;
    const gr_report_technique *t = &in->techniques[k];
    const gr_metrics *m = t->metrics;
    gr_report_tech_stem(t->name, stem, sizeof stem);
    /* 1. Radial profile per channel. */
    static const unsigned char col[3][3] = {{215, 40, 40}, {30, 150, 50}, {40, 80, 220}};
    static const char *const cn[3] = {"R", "G", "B"};
    char labs[6][64];
    gr_plot_series prof_c[6];
    for (int c = 0; c < 3; c++) {
        snprintf(labs[2 * c], sizeof labs[0], "%s reference", cn[c]);
        snprintf(labs[2 * c + 1], sizeof labs[0], "%s %.40s x a", cn[c], t->name);
        prof_c[2 * c] = (gr_plot_series){labs[2 * c], pr->ref.center_deg, pr->ref.mean[c], pr->ref.nbins,
                                         {col[c][0], col[c][1], col[c][2]}, GR_PLOT_SOLID, 0};
        prof_c[2 * c + 1] = (gr_plot_series){labs[2 * c + 1], pr->fit[k].center_deg, pr->fit[k].mean[c],
                                             pr->fit[k].nbins, {col[c][0], col[c][1], col[c][2]}, GR_PLOT_DASHED, 0};
    }
    snprintf(title, sizeof title, "Radial profile per channel (%s x a, a = %.4g)", t->name, a);
    gr_plot_spec spec = {.width = 800, .height = 450, .title = title,
                         .xlabel = "angle between view ray and refracted sun direction (deg)",
                         .ylabel = "mean radiance per channel", .log_y = 1, .series = prof_c, .n_series = 6,
                         .legend_headroom = 0.6};
    snprintf(file, sizeof file, "%s_radial_profile_rgb.png", stem);
    if ((st = join(path, sizeof path, dir, file, err)) != GR_OK) return st;
    if ((st = gr_plot_write(path, &spec, err)) != GR_OK) return st;
    (*n_charts)++;

    /* 2. Error against blur scale: unblurred, then sigma 1, 4, 16 px. */
    static const char *const cats[1 + GR_METRICS_NSCALES] = {"none", "1", "4", "16"};
    double xs[1 + GR_METRICS_NSCALES], fy[1 + GR_METRICS_NSCALES], frgb[1 + GR_METRICS_NSCALES],
        ry[1 + GR_METRICS_NSCALES], nz[1 + GR_METRICS_NSCALES];
    const gr_metrics_set *fs = m->have_fit ? &m->fit : &m->raw;
    xs[0] = 0;
    fy[0] = fs->ch[GR_MCH_Y].rmse;
    frgb[0] = fs->ch[GR_MCH_RGB].rmse;
    ry[0] = m->raw.ch[GR_MCH_Y].rmse;
    for (int s = 0; s < GR_METRICS_NSCALES; s++) {
        xs[s + 1] = s + 1;
        fy[s + 1] = fs->have_blur ? fs->ch[GR_MCH_Y].rmse_blur[s] : NAN;
        frgb[s + 1] = fs->have_blur ? fs->ch[GR_MCH_RGB].rmse_blur[s] : NAN;
        ry[s + 1] = m->raw.have_blur ? m->raw.ch[GR_MCH_Y].rmse_blur[s] : NAN;
    }
    for (int s = 0; s <= GR_METRICS_NSCALES; s++) nz[s] = noise_y;
    char lab2[128];
    snprintf(lab[0], sizeof lab[0], "Y, %.40s x a (a = %.4g)", t->name, fs->scale);
    snprintf(lab[1], sizeof lab[1], "RGB pooled, %.40s x a", t->name);
    snprintf(lab2, sizeof lab2, "Y, %.40s as rendered (a = 1)", t->name);
    gr_plot_series blur[4] = {
        {lab[0], xs, fy, 1 + GR_METRICS_NSCALES, {30, 100, 220}, GR_PLOT_SOLID, 1},
        {lab[1], xs, frgb, 1 + GR_METRICS_NSCALES, {120, 60, 170}, GR_PLOT_DASHED, 1},
        {lab2, xs, ry, 1 + GR_METRICS_NSCALES, {215, 40, 40}, GR_PLOT_LONG_DASHED, 1},
        {"reference noise (RMS std. error of Y)", xs, nz, 1 + GR_METRICS_NSCALES, {120, 120, 120}, GR_PLOT_DASHED, 0},
    };
    snprintf(title, sizeof title, "%s: RMSE after Gaussian blur of the difference", t->name);
    spec = (gr_plot_spec){.width = 800, .height = 450, .title = title,
                          .xlabel = "blur sigma (px)", .ylabel = "RMSE", .log_y = 1, .series = blur,
                          .n_series = isfinite(noise_y) && noise_y > 0 ? 4 : 3, .legend_headroom = 0.8, .x_categories = cats,
                          .n_categories = 1 + GR_METRICS_NSCALES};
    snprintf(file, sizeof file, "%s_error_vs_blur.png", stem);
    if ((st = join(path, sizeof path, dir, file, err)) != GR_OK) return st;
    if ((st = gr_plot_write(path, &spec, err)) != GR_OK) return st;
    (*n_charts)++;
    return GR_OK;
}

static gr_status draw_charts(const char *dir, const gr_report_input *in, const double *as, const profiles *pr,
                             double noise_y, int *n_charts, char *note, size_t note_n, gr_error *err)
{
    *n_charts = 0;
    if (!gr_plot_available()) {
        snprintf(note, note_n, "charts not drawn: this build has no PLplot (install libplplot-dev and rebuild)");
        return GR_OK;
    }
    gr_status st = draw_profile_all(dir, in, as, pr, err);
    if (st != GR_OK) return st;
    (*n_charts)++;
    for (int k = 0; k < in->n_techniques; k++)
        if ((st = draw_tech_charts(dir, in, k, as[k], pr, noise_y, n_charts, err)) != GR_OK) return st;
    return GR_OK;
}

/* ---- metrics.json ------------------------------------------------------------------------- */

static void jnum(cJSON *o, const char *k, double v, int *ok)
{
    if (!*ok) return;
    *ok = (isfinite(v) ? cJSON_AddNumberToObject(o, k, v) : cJSON_AddNullToObject(o, k)) != NULL;
}

static void jstr(cJSON *o, const char *k, const char *v, int *ok)
{
    if (!*ok) return;
    *ok = (v ? cJSON_AddStringToObject(o, k, v) : cJSON_AddNullToObject(o, k)) != NULL;
}

static cJSON *jarr(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++) {
        cJSON *x = isfinite(v[i]) ? cJSON_CreateNumber(v[i]) : cJSON_CreateNull();
        if (!x || !cJSON_AddItemToArray(a, x)) {
            cJSON_Delete(x);
            cJSON_Delete(a);
            return NULL;
        }
    }
    return a;
}

static void jadd(cJSON *o, const char *k, cJSON *item, int *ok)
{
    if (!*ok || !item || !cJSON_AddItemToObject(o, k, item)) {
        cJSON_Delete(item); /* not attached: ours to free (NULL is fine) */
        *ok = 0;
    }
}

static cJSON *meta_json(const gr_metadata *m)
{
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL;
    for (int i = 0; ok && m && i < m->count; i++) {
        const gr_meta_item *it = &m->items[i];
        if (it->type == GR_META_STRING) jstr(o, it->key, it->str, &ok);
        else jnum(o, it->key, it->num, &ok);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static cJSON *profile_json(const gr_radial_profile *p, int with_se)
{
    static const char *const names[GR_PROFILE_NCH] = {"R", "G", "B", "Y"};
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL;
    for (int c = 0; ok && c < GR_PROFILE_NCH; c++) jadd(o, names[c], jarr(p->mean[c], p->nbins), &ok);
    if (ok && with_se && p->stderr_bound[0]) {
        cJSON *s = cJSON_CreateObject();
        for (int c = 0; s && c < GR_PROFILE_NCH; c++) {
            int ok2 = 1;
            jadd(s, names[c], jarr(p->stderr_bound[c], p->nbins), &ok2);
            if (!ok2) {
                cJSON_Delete(s);
                s = NULL;
            }
        }
        jadd(o, "stderr_bound_of_mean", s, &ok);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

/* ---- index.html ----------------------------------------------------------------------------- */

static const char *const CSS =
    "body{font-family:DejaVu Sans,Helvetica,Arial,sans-serif;margin:0 auto;max-width:1500px;padding:0 18px 40px;"
    "color:#1d1f23;background:#fafafa;line-height:1.4}"
    "h1{font-size:1.6em;margin:18px 0 4px}h2{font-size:1.25em;margin-top:28px;border-bottom:1px solid #ccc}"
    ".sub{color:#555;font-size:.92em}.box{background:#fff;border:1px solid #ddd;border-radius:6px;padding:10px 14px}"
    ".warn{background:#fff4e0;border-color:#e5b567}"
    ".grid{display:flex;flex-wrap:wrap;gap:14px}.grid figure{margin:0;background:#fff;border:1px solid #ddd;"
    "border-radius:6px;padding:8px;flex:1 1 250px;max-width:520px}.grid figure.chart{flex:1 1 560px;"
    "max-width:820px}figure img{width:100%;height:auto;display:block;image-rendering:pixelated}"
    "figure.chart img{image-rendering:auto}figcaption{font-size:.85em;color:#444;margin-top:6px}"
    "table{border-collapse:collapse;background:#fff;font-size:.88em;margin:6px 0}"
    "td,th{border:1px solid #ddd;padding:3px 8px;text-align:right;vertical-align:top}"
    "th{background:#f0f2f5}td.l,th.l{text-align:left}pre{background:#fff;border:1px solid #ddd;padding:10px;"
    "overflow:auto;font-size:.85em;max-height:520px}details{margin:8px 0}summary{cursor:pointer;font-weight:bold}"
    "code{background:#eef0f3;padding:0 3px}"
    "table.lb td{vertical-align:middle}img.thumb{width:200px;height:auto;image-rendering:pixelated;display:block}"
    "tr.baseline td{background:#f3f3ee;color:#444}tr.failed td{background:#fdeaea}.flag{color:#b00000;font-weight:bold}";

static void html_metrics_table(gr_strbuf *b, const gr_metrics *m, const gr_metrics_set *s, const char *caption)
{
    char t[GR_MCH_COUNT][64];
    gr_sb_puts(b, "<table><caption class=\"sub\">");
    gr_sb_html(b, caption);
    gr_sb_puts(b, "</caption><tr><th class=\"l\">metric</th>");
    for (int c = 0; c < GR_MCH_COUNT; c++) gr_sb_printf(b, "<th>%s</th>", gr_metric_channel_name((gr_metric_channel)c));
    gr_sb_puts(b, "</tr>\n");
#define ROW(label, expr)                                                                   \
    do {                                                                                   \
        gr_sb_puts(b, "<tr><td class=\"l\">");                                             \
        gr_sb_html(b, label);                                                              \
        gr_sb_puts(b, "</td>");                                                            \
        for (int c = 0; c < GR_MCH_COUNT; c++) {                                           \
            const gr_channel_metrics *cm = &s->ch[c];                                      \
            gr_sb_printf(b, "<td>%s</td>", fmt((expr), t[c], sizeof t[c]));               \
        }                                                                                  \
        gr_sb_puts(b, "</tr>\n");                                                          \
    } while (0)
    ROW("mean reference", cm->ref_mean);
    ROW("mean test (x scale)", cm->test_mean);
    ROW("bias: mean(a t - r)", cm->bias);
    ROW("MAE", cm->mae);
    ROW("RMSE", cm->rmse);
    ROW("RMSE / mean reference", cm->ref_mean != 0.0 ? cm->rmse / fabs(cm->ref_mean) : NAN);
    ROW("relative MSE", cm->rel_mse);
    ROW("  its epsilon", cm->rel_mse_eps);
    ROW("PSNR (dB), peak = reference max", cm->psnr_ref_db);
    ROW("  reference max", cm->peak_ref);
    ROW("PSNR (dB), idiff peak", cm->psnr_idiff_db);
    ROW("max |a t - r|", cm->max_abs_err);
    for (int k = 0; k < GR_METRICS_NSCALES && s->have_blur; k++) {
        char label[64];
        snprintf(label, sizeof label, "RMSE after blur, sigma %g px", gr_metrics_blur_sigmas[k]);
        ROW(label, cm->rmse_blur[k]);
    }
    if (m->have_stderr) {
        char sl[96]; /* z: Student t with the reference's batches - 1 degrees of freedom, or 2 */
        snprintf(sl, sizeof sl, "not significant (|d| <= %.3g stderr%s), %%", m->stderr_z,
                 m->have_bias ? " + |bias|" : "");
        ROW(sl, cm->n_samples > 0 ? 100.0 * (double)cm->n_not_significant / (double)cm->n_samples : NAN);
    }
#undef ROW
    gr_sb_puts(b, "<tr><td class=\"l\">max error at (x, y)</td>");
    for (int c = 0; c < GR_MCH_COUNT; c++) {
        const gr_channel_metrics *cm = &s->ch[c];
        if (cm->max_x < 0) gr_sb_puts(b, "<td>n/a</td>");
        else if (cm->max_c >= 0) gr_sb_printf(b, "<td>%d, %d, %c</td>", cm->max_x, cm->max_y, "RGB"[cm->max_c]);
        else gr_sb_printf(b, "<td>%d, %d</td>", cm->max_x, cm->max_y);
    }
    gr_sb_puts(b, "</tr>\n<tr><td class=\"l\">SSIM (luminance)</td>");
    gr_sb_printf(b, "<td colspan=\"%d\">%s</td></tr>\n</table>\n", GR_MCH_COUNT,
                 s->have_ssim ? fmt(s->ssim_y, t[0], sizeof t[0]) : "not computed");
}

/* Every metric of the registry (compare/registry.h): as rendered and after the scale fit. */
static void html_registry_table(gr_strbuf *b, const gr_metrics *m)
{
    char t[2][64];
    const gr_metrics_set *fs = m->have_fit ? &m->fit : &m->raw;
    gr_sb_puts(b, "<table><caption class=\"sub\">The metrics of the registry (n/a: not computed in this run)"
                  "</caption><tr><th class=\"l\">metric</th><th class=\"l\">key</th><th>a = 1</th><th>x a</th>"
                  "<th class=\"l\">better</th><th class=\"l\">unit</th><th class=\"l\">what</th></tr>\n");
    for (int i = 0; i < gr_metric_count(); i++) {
        const gr_metric_desc *d = gr_metric_at(i);
        gr_sb_puts(b, "<tr><td class=\"l\">");
        gr_sb_html(b, d->label);
        gr_sb_puts(b, "</td><td class=\"l\"><code>");
        gr_sb_html(b, d->key);
        gr_sb_printf(b, "</code></td><td>%s</td><td>%s</td><td class=\"l\">%s</td><td class=\"l\">%s</td>"
                        "<td class=\"l\">", fmt(gr_metric_value(&m->raw, i), t[0], sizeof t[0]),
                     fmt(gr_metric_value(fs, i), t[1], sizeof t[1]), gr_metric_better_name(d->better),
                     gr_metric_unit_name(d->unit));
        gr_sb_html(b, d->doc);
        gr_sb_puts(b, "</td></tr>\n");
    }
    gr_sb_puts(b, "</table>\n");
}

static void html_settings_table(gr_strbuf *b, const gr_param_table *t, const void *settings)
{
    gr_sb_puts(b, "<table><tr><th class=\"l\">setting</th><th>value</th><th class=\"l\">unit</th>"
                  "<th class=\"l\">range</th><th class=\"l\">meaning</th></tr>\n");
    for (size_t i = 0; i < t->count; i++) {
        const gr_param *p = &t->params[i];
        char v[128], tmp[3][40], range[64];
        if (p->type == GR_PT_ENUM) {
            const char *nm = gr_param_enum_name(p, (int)gr_param_get_number(p, settings, 0));
            snprintf(v, sizeof v, "%s", nm ? nm : "?");
        } else if (p->type == GR_PT_BOOL) {
            snprintf(v, sizeof v, "%s", gr_param_get_number(p, settings, 0) != 0.0 ? "true" : "false");
        } else if (p->type == GR_PT_U64) {
            snprintf(v, sizeof v, "%llu", *(const unsigned long long *)((const char *)settings + p->offset));
        } else if (p->type == GR_PT_RGB) {
            /* 6 digits for people; the exact values are in the scene JSON below */
            for (int c = 0; c < 3; c++) snprintf(tmp[c], sizeof tmp[c], "%.6g", gr_param_get_number(p, settings, c));
            snprintf(v, sizeof v, "%s, %s, %s", tmp[0], tmp[1], tmp[2]);
        } else {
            snprintf(v, sizeof v, "%.6g", gr_param_get_number(p, settings, 0));
        }
        gr_sb_puts(b, "<tr><td class=\"l\"><code>");
        gr_sb_htmlf(b, "%s.%s", t->section, p->name);
        gr_sb_puts(b, "</code></td><td>");
        if (isnan(gr_param_get_number(p, settings, 0)) && (p->flags & GR_PF_FROM_SCENE))
            gr_sb_htmlf(b, "from %s", p->scene_source ? p->scene_source : "the scene");
        else
            gr_sb_html(b, v);
        gr_sb_puts(b, "</td><td class=\"l\">");
        gr_sb_html(b, p->unit);
        gr_sb_puts(b, "</td><td class=\"l\">");
        gr_sb_html(b, gr_param_range_text(p, range, sizeof range));
        gr_sb_puts(b, "</td><td class=\"l\">");
        gr_sb_html(b, p->doc);
        gr_sb_puts(b, "</td></tr>\n");
    }
    gr_sb_puts(b, "</table>\n");
}

static void html_meta_table(gr_strbuf *b, const gr_metadata *m)
{
    if (!m || m->count == 0) {
        gr_sb_puts(b, "<p class=\"sub\">(no metadata)</p>\n");
        return;
    }
    gr_sb_puts(b, "<table><tr><th class=\"l\">attribute</th><th class=\"l\">value</th></tr>\n");
    for (int i = 0; i < m->count; i++) {
        const gr_meta_item *it = &m->items[i];
        char v[64];
        gr_sb_puts(b, "<tr><td class=\"l\"><code>");
        gr_sb_html(b, it->key);
        gr_sb_puts(b, "</code></td><td class=\"l\">");
        if (it->type == GR_META_STRING) gr_sb_html(b, it->str);
        else gr_sb_html(b, gr_format_double(it->num, v, sizeof v));
        gr_sb_puts(b, "</td></tr>\n");
    }
    gr_sb_puts(b, "</table>\n");
}

/* One "name | value" row; value from metadata (number) or "n/a". */
static void kv_row(gr_strbuf *b, const char *name, const char *value)
{
    gr_sb_puts(b, "<tr><td class=\"l\">");
    gr_sb_html(b, name);
    gr_sb_puts(b, "</td><td>");
    gr_sb_html(b, value);
    gr_sb_puts(b, "</td></tr>\n");
}

static void kv_num(gr_strbuf *b, const char *name, double v, double factor, const char *unit)
{
    char t[64], u[96];
    if (isnan(v)) snprintf(u, sizeof u, "n/a");
    else snprintf(u, sizeof u, "%s%s%s", fmt(v * factor, t, sizeof t), unit && unit[0] ? " " : "", unit ? unit : "");
    kv_row(b, name, u);
}

static void html_figure(gr_strbuf *b, const char *file, const gr_image *img, const char *alt, const char *caption)
{
    /* Renders are shown pixel for pixel when enlarged (no invented detail); charts smoothly. */
    gr_sb_puts(b, img ? "<figure><img src=\"" : "<figure class=\"chart\"><img src=\"");
    gr_sb_html(b, file);
    gr_sb_puts(b, "\" alt=\"");
    gr_sb_html(b, alt);
    gr_sb_puts(b, "\"");
    if (img) gr_sb_printf(b, " width=\"%d\" height=\"%d\"", img->width, img->height);
    gr_sb_puts(b, "><figcaption>");
    gr_sb_html(b, caption);
    gr_sb_puts(b, "</figcaption></figure>\n");
}

/* ---- the writer ----------------------------------------------------------------------------- */

/* What the report computes for one technique. */
typedef struct tctx {
    const gr_report_technique *t;
    char stem[48];                 /* file-name stem (tech_stem) */
    double a, exposure_raw;
    double gpu_ms, wall_ms;        /* from its metadata (NaN: unknown) */
    gr_image *disp_fit, *disp_raw, *diff_signed, *diff_abs;
    gr_diffmap_info info_signed, info_abs;
    gr_image *flip_map;            /* per-pixel HDR-FLIP of a * test, magma (docs/metrics.md) */
    gr_image *disp_targets;        /* t->targets for display (NULL: none) */
    double exposure_targets;
    gr_flip_result flip;
    int flip_undefined;            /* 1: a black ground truth gives HDR-FLIP no exposure range */
    char flip_why[160];
    char lines[3][512];            /* its summary lines */
    float *flip_px;                /* the FLIP job's per-pixel map (freed once drawn) */
    gr_status flip_st;             /* the FLIP job's status and message */
    gr_error flip_err;
} tctx;

typedef struct ctx {
    const char *dir;
    const gr_report_input *in;
    double exposure, noise_y;
    gr_image *disp_ref;
    const gr_flip_reference *flip_ref; /* the truth's half of HDR-FLIP, shared by the jobs; may be NULL */
    tctx t[GR_REPORT_MAX_TECHNIQUES];
    int order[GR_REPORT_MAX_TECHNIQUES];
    gr_leaderboard lb;             /* every row: techniques, baselines, failures */
    profiles pr;
    int have_profiles;
    int charts;
    char chart_note[512];
    int labelled;
    char lines[2][512];            /* scene, reference */
} ctx;

/* The leaderboard's ranking metric (compare/registry.h: the verdict). */
static double verdict_of(const gr_metrics_set *s) { return gr_metric_value(s, GR_METRIC_VERDICT); }
static double rel_rmse_y(const gr_metrics_set *s) { return gr_metric_value(s, GR_METRIC_REL_RMSE); }

static const gr_metrics_set *fit_set(const gr_metrics *m) { return m->have_fit ? &m->fit : &m->raw; }

void gr_report_rank(const gr_report_technique *techniques, int n, int *order)
{
    for (int i = 0; i < n; i++) order[i] = i;
    /* insertion sort: stable, n is small */
    for (int i = 1; i < n; i++) {
        int v = order[i], j = i;
        double ev = verdict_of(fit_set(techniques[v].metrics));
        while (j > 0) {
            double eu = verdict_of(fit_set(techniques[order[j - 1]].metrics));
            int before = isfinite(ev) && (!isfinite(eu) || ev < eu);
            if (!before) break;
            order[j] = order[j - 1];
            j--;
        }
        order[j] = v;
    }
}

static void summary_lines(ctx *c)
{
    const gr_report_input *in = c->in;
    char t[8][48];
    char failed[48] = "";
    if (in->n_failed > 0) snprintf(failed, sizeof failed, " (%d FAILED)", in->n_failed);
    snprintf(c->lines[0], sizeof c->lines[0], "scene '%s' (hash %s), %d x %d; godrays %s; %d real-time technique%s%s",
             in->scene->name, in->scene->hash, in->ref->width, in->ref->height, GR_VERSION,
             in->n_techniques + in->n_failed, in->n_techniques + in->n_failed == 1 ? "" : "s", failed);
    const double wall = meta_num(in->ref_meta, "godrays:wall_s");
    /* the truth's own error: its noise and its surface tessellation's bias (docs/reference.md 4) */
    char bias[160] = "";
    const double be = meta_num(in->ref_meta, "godrays:bias_surface_rel_est"),
                 bm = meta_num(in->ref_meta, "godrays:bias_surface_rel_measured_order");
    if (be >= 0.0 && bm >= 0.0)
        snprintf(bias, sizeof bias, ", surface bias ~%s %% (%s %% with the measured order)", fmt(100.0 * be, t[3], sizeof t[3]),
                 fmt(100.0 * bm, t[4], sizeof t[4]));
    else if (be >= 0.0)
        snprintf(bias, sizeof bias, ", surface bias ~%s %%", fmt(100.0 * be, t[3], sizeof t[3]));
    snprintf(c->lines[1], sizeof c->lines[1],
             "reference: %s s render%s, %s spp, rel. std. error of the image mean %s %%%s",
             fmt(wall, t[0], sizeof t[0]), in->ref_cached ? " (read from the cache)" : "",
             fmt(meta_num(in->ref_meta, "godrays:spp"), t[1], sizeof t[1]),
             fmt(100.0 * meta_num(in->ref_meta, "godrays:rel_stderr_mean"), t[2], sizeof t[2]), bias);
    for (int k = 0; k < in->n_techniques; k++) {
        tctx *tc = &c->t[k];
        const gr_metrics *m = tc->t->metrics;
        const gr_metrics_set *fs = fit_set(m);
        const gr_channel_metrics *y = &fs->ch[GR_MCH_Y];
        snprintf(tc->lines[0], sizeof tc->lines[0], "%s: GPU %s ms (timed passes), wall %s ms per render, %s fragments",
                 tc->t->name, fmt(tc->gpu_ms, t[0], sizeof t[0]), fmt(tc->wall_ms, t[1], sizeof t[1]),
                 fmt(meta_num(tc->t->meta, "godrays:fragments"), t[2], sizeof t[2]));
        const gr_lb_row *row = gr_lb_technique_row(&c->lb, k);
        snprintf(tc->lines[1], sizeof tc->lines[1],
                 "verdict %s (equivalent blur %s)%s%s; best scale a = %s; luminance after fit: RMSE %s (%s of the mean), "
                 "bias %s, SSIM %s, structure score %s",
                 fmt(verdict_of(fs), t[6], sizeof t[6]), gr_lb_eq_blur_text(in, row, t[7], sizeof t[7]),
                 row && row->no_better ? ", " : "", row && row->no_better ? gr_lb_flag(row) : "", fmt(fs->scale, t[0], sizeof t[0]),
                 fmt(y->rmse, t[1], sizeof t[1]), fmt(rel_rmse_y(fs), t[2], sizeof t[2]), fmt(y->bias, t[3], sizeof t[3]),
                 fs->have_ssim ? fmt(fs->ssim_y, t[4], sizeof t[4]) : "n/a",
                 fmt(gr_metric_value(fs, GR_METRIC_STRUCTURE), t[5], sizeof t[5]));
        snprintf(tc->lines[2], sizeof tc->lines[2],
                 "scored pixels %lld of %lld; not scored: %lld (reference rel. std. error > %s)", m->n_scored,
                 m->n_pixels, m->n_stderr_excluded, fmt(m->stderr_bound, t[0], sizeof t[0]));
    }
}

/* A leaderboard row's numbers (report/leaderboard.h) as a JSON object. */
static cJSON *row_json(const ctx *c, const gr_lb_row *r)
{
    static const char *const kinds[3] = {"technique", "baseline", "failed"};
    char t[48];
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL;
    jstr(o, "kind", kinds[r->kind], &ok);
    jstr(o, "name", r->name, &ok);
    jstr(o, r->kind == GR_LB_FAILED ? "reason" : r->kind == GR_LB_BASELINE ? "label" : "description", r->text, &ok);
    if (r->kind == GR_LB_TECHNIQUE) jnum(o, "rank", r->rank, &ok);
    if (r->kind != GR_LB_FAILED) {
        jnum(o, "verdict", r->verdict, &ok);
        jnum(o, "rel_rmse_fit", r->error_fit, &ok);
        jnum(o, "structure", r->structure, &ok);
        jnum(o, "flip", r->flip, &ok);
        jnum(o, "bandpass_corr", r->corr, &ok);
        jnum(o, "streak_contrast_ratio", r->contrast_ratio, &ok);
        jnum(o, "scale", r->scale, &ok);
        jnum(o, "equivalent_blur_px", r->eq_blur_px, &ok);
        jstr(o, "equivalent_blur", gr_lb_eq_blur_text(c->in, r, t, sizeof t), &ok);
    }
    if (r->kind == GR_LB_TECHNIQUE) jstr(o, "flag", gr_lb_flag(r), &ok);
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

/* The leaderboard's rows, the baselines (their ladder included) and the failures. */
static void leaderboard_json(const ctx *c, cJSON *root, int *ok)
{
    const gr_report_input *in = c->in;
    jstr(root, "leaderboard_rule",
         "the verdict after the best scale fit, lower first: (relative RMSE of luminance Y + structure score) / 2 "
         "(" GR_VERDICT_OBJECTIVE ", tune's default objective; docs/metrics.md)", ok);
    cJSON *rows = *ok ? cJSON_CreateArray() : NULL;
    for (int i = 0; rows && i < c->lb.n; i++) {
        cJSON *x = row_json(c, &c->lb.rows[i]);
        if (!x || !cJSON_AddItemToArray(rows, x)) {
            cJSON_Delete(x);
            cJSON_Delete(rows);
            rows = NULL;
        }
    }
    jadd(root, "leaderboard_rows", rows, ok);
    jnum(root, "techniques_no_better_than_constant", c->lb.n_flagged, ok);
    cJSON *fl = *ok ? cJSON_CreateArray() : NULL;
    for (int f = 0; fl && f < in->n_failed; f++) {
        cJSON *x = cJSON_CreateObject();
        int xo = x != NULL;
        jstr(x, "name", in->failed[f].name, &xo);
        jstr(x, "description", in->failed[f].description, &xo);
        jstr(x, "reason", in->failed[f].reason, &xo);
        if (!xo || !cJSON_AddItemToArray(fl, x)) {
            cJSON_Delete(x);
            cJSON_Delete(fl);
            fl = NULL;
        }
    }
    jadd(root, "failed", fl, ok);
    const gr_baselines *b = in->baselines;
    if (!b) return;
    cJSON *bj = cJSON_CreateObject();
    jadd(root, "baselines", bj, ok);
    for (int i = 0; *ok && i < GR_BASELINE_COUNT; i++) {
        cJSON *one = cJSON_CreateObject();
        jadd(bj, gr_baseline_key(i), one, ok);
        jstr(one, "label", gr_baseline_label(i), ok);
        jadd(one, "compare", gr_metrics_to_json(&b->m[i]), ok);
    }
    cJSON *ld = cJSON_CreateObject();
    jadd(bj, "blur_ladder", ld, ok);
    jstr(ld, "what", "the truth blurred by a Gaussian of each sigma, scored like a technique: its verdict, and the "
                     "running maximum that turns a verdict into an equivalent blur (log-linear between rungs)", ok);
    jadd(ld, "sigma_px", jarr(b->sigma_px, b->n_ladder), ok);
    jadd(ld, "verdict", jarr(b->verdict, b->n_ladder), ok);
    jadd(ld, "envelope", jarr(b->envelope, b->n_ladder), ok);
}

/* ---- cost counters (written by realtime/technique.c as EXR metadata) ------------------------ */

/* Calls fn(pass, user) for each pass named in "godrays:passes", then fn(NULL, user) (the sum). */
static void cost_each_pass(const gr_metadata *m, void (*fn)(const gr_metadata *, const char *, void *), void *user)
{
    const char *p = meta_str(m, "godrays:passes");
    char pname[64];
    while (p && *p) {
        size_t n = strcspn(p, " ");
        snprintf(pname, sizeof pname, "%.*s", (int)(n < sizeof pname - 1 ? n : sizeof pname - 1), p);
        fn(m, pname, user);
        p += n;
        while (*p == ' ') p++;
    }
    fn(m, NULL, user);
}

/* The counter's name when item is one of pass's ("godrays:cost.PASS.NAME"; pass NULL: the sums,
 * "godrays:cost.NAME"), else NULL. */
static const char *cost_key(const gr_meta_item *it, const char *pass)
{
    static const char pre[] = "godrays:cost.";
    if (it->type == GR_META_STRING || strncmp(it->key, pre, sizeof pre - 1) != 0) return NULL;
    const char *rest = it->key + sizeof pre - 1;
    if (!pass) return strchr(rest, '.') ? NULL : rest;
    size_t n = strlen(pass);
    return strncmp(rest, pass, n) == 0 && rest[n] == '.' ? rest + n + 1 : NULL;
}

static void cost_json_pass(const gr_metadata *m, const char *pass, void *user)
{
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL, any = 0;
    for (int i = 0; m && i < m->count; i++) {
        const char *name = cost_key(&m->items[i], pass);
        if (!name) continue;
        jnum(o, name, m->items[i].num, &ok);
        any = 1;
    }
    if (!any) {
        cJSON_Delete(o);
        return;
    }
    jadd(user, pass ? pass : "total", o, &ok);
}

/* {"PASS": {"fragments": ..., ...}, ..., "total": {...}, "queried": "PASS.COUNTER ..."}; NULL
 * when nothing was counted. */
static cJSON *cost_json(const gr_metadata *m)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cost_each_pass(m, cost_json_pass, o);
    if (!cJSON_GetArraySize(o)) {
        cJSON_Delete(o);
        return NULL;
    }
    int ok = 1;
    jstr(o, "queried", meta_str(m, "godrays:cost_queried"), &ok);
    return o;
}

static void cost_text_pass(const gr_metadata *m, const char *pass, void *user)
{
    gr_strbuf *b = user;
    int first = 1;
    for (int i = 0; m && i < m->count; i++) {
        const char *name = cost_key(&m->items[i], pass);
        if (!name) continue;
        if (first) gr_sb_printf(b, "%s: ", pass ? pass : "all passes");
        gr_sb_printf(b, "%s%s %.0f", first ? "" : ", ", name, m->items[i].num);
        first = 0;
    }
    if (!first) gr_sb_puts(b, "\n");
}

/* One line per pass ("PASS: fragments N, taps N, ...") and the sum: the leaderboard's tooltip. */
static void cost_text(const gr_metadata *m, gr_strbuf *b) { cost_each_pass(m, cost_text_pass, b); }

/* One technique's entry of metrics.json. */
static cJSON *technique_json(const ctx *c, int k, int rank)
{
    const tctx *tc = &c->t[k];
    const gr_report_technique *t = tc->t;
    const gr_metrics *m = t->metrics;
    char file[96];
    cJSON *o = cJSON_CreateObject();
    int ok = o != NULL;
    jstr(o, "name", t->name, &ok);
    jstr(o, "description", t->description, &ok);
    jnum(o, "rank", rank, &ok);
    jstr(o, "file", t->exr, &ok);
    jnum(o, "seconds_this_run", t->seconds >= 0 ? t->seconds : NAN, &ok);
    jnum(o, "gpu_ms", tc->gpu_ms, &ok);
    jnum(o, "wall_ms", tc->wall_ms, &ok);
    cJSON *cost = cost_json(t->meta);
    if (cost) jadd(o, "cost", cost, &ok); /* per-pass cost counters (docs/techniques.md) */
    jnum(o, "fit_scale", tc->a, &ok);
    const gr_lb_row *row = gr_lb_technique_row(&c->lb, k);
    if (row) { /* the verdict, its components, the equivalent blur and the flag */
        jadd(o, "verdict", row_json(c, row), &ok);
        jstr(o, "flag", gr_lb_flag(row), &ok);
    }
    /* the headline errors (luminance), raw and after the fit */
    cJSON *e = cJSON_CreateObject();
    jadd(o, "errors_y", e, &ok);
    for (int i = 0; ok && i < gr_metric_count(); i++) { /* every registered metric: KEY and KEY_fit */
        char key[GR_METRIC_KEY_MAX + 8];
        snprintf(key, sizeof key, "%s_fit", gr_metric_at(i)->key);
        jnum(e, gr_metric_at(i)->key, gr_metric_value(&m->raw, i), &ok);
        jnum(e, key, gr_metric_value(fit_set(m), i), &ok);
    }
    /* every metric, as `godrays compare --json` writes it */
    jadd(o, "compare", gr_metrics_to_json(m), &ok);
    cJSON *pv = cJSON_CreateObject();
    jadd(o, "previews", pv, &ok);
    snprintf(file, sizeof file, "%s.png", tc->stem);
    jstr(pv, "fitted", file, &ok);
    snprintf(file, sizeof file, "%s_raw.png", tc->stem);
    jstr(pv, "raw", file, &ok);
    jnum(pv, "scale", tc->a, &ok);
    jnum(pv, "raw_exposure", tc->exposure_raw, &ok);
    {
        cJSON *fj = gr_flip_to_json(&tc->flip, tc->a);
        snprintf(file, sizeof file, "%s_flip.png", tc->stem);
        jstr(fj, "map", file, &ok);
        jadd(o, "flip", fj, &ok);
    }
    cJSON *dj = cJSON_CreateObject();
    jadd(o, "difference_images", dj, &ok);
    for (int s = 0; ok && s < 2; s++) {
        const gr_diffmap_info *info = s ? &tc->info_signed : &tc->info_abs;
        cJSON *one = cJSON_CreateObject();
        snprintf(file, sizeof file, "%s_%s.png", tc->stem, s ? "diff_signed" : "diff");
        jadd(dj, file, one, &ok);
        jstr(one, "quantity", s ? "scale * Y(test) - Y(ref)" : "|scale * Y(test) - Y(ref)|", &ok);
        jnum(one, "scale", tc->a, &ok);
        jstr(one, "color_map", info->map, &ok);
        jnum(one, "min", info->vmin, &ok);
        jnum(one, "max", info->vmax, &ok);
        jnum(one, "unscored_pixels_gray", (double)info->n_unscored, &ok);
    }
    if (c->have_profiles) {
        cJSON *rp = cJSON_CreateObject();
        jadd(o, "radial_profile", rp, &ok);
        jadd(rp, "fitted", profile_json(&c->pr.fit[k], 0), &ok);
        jadd(rp, "raw", profile_json(&c->pr.raw[k], 0), &ok);
    }
    {
        const gr_metrics_set *fs = fit_set(m);
        double sig[1 + GR_METRICS_NSCALES], fy[1 + GR_METRICS_NSCALES], ry[1 + GR_METRICS_NSCALES];
        sig[0] = 0;
        fy[0] = fs->ch[GR_MCH_Y].rmse;
        ry[0] = m->raw.ch[GR_MCH_Y].rmse;
        for (int s = 0; s < GR_METRICS_NSCALES; s++) {
            sig[s + 1] = gr_metrics_blur_sigmas[s];
            fy[s + 1] = fs->have_blur ? fs->ch[GR_MCH_Y].rmse_blur[s] : NAN;
            ry[s + 1] = m->raw.have_blur ? m->raw.ch[GR_MCH_Y].rmse_blur[s] : NAN;
        }
        cJSON *eb = cJSON_CreateObject();
        jadd(o, "error_vs_blur", eb, &ok);
        jadd(eb, "sigma_px", jarr(sig, 1 + GR_METRICS_NSCALES), &ok);
        jadd(eb, "rmse_y_fitted", jarr(fy, 1 + GR_METRICS_NSCALES), &ok);
        jadd(eb, "rmse_y_raw", jarr(ry, 1 + GR_METRICS_NSCALES), &ok);
    }
    jadd(o, "metadata", meta_json(t->meta), &ok);
    if (ok) {
        cJSON *sl = cJSON_CreateArray();
        for (int i = 0; sl && i < 3; i++) {
            cJSON *x = cJSON_CreateString(tc->lines[i]);
            if (!x || !cJSON_AddItemToArray(sl, x)) {
                cJSON_Delete(x);
                cJSON_Delete(sl);
                sl = NULL;
            }
        }
        jadd(o, "summary", sl, &ok);
    }
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static gr_status build_json(ctx *c, char **text, gr_error *err)
{
    const gr_report_input *in = c->in;
    cJSON *root = cJSON_CreateObject();
    int ok = root != NULL;
    jnum(root, "schema", 2, &ok);
    jstr(root, "godrays_version", GR_VERSION, &ok);
    jstr(root, "command_line", in->command_line, &ok);
    /* the scene as the renderers saw it: normalized, every default filled in */
    char *sj = gr_scene_to_json(in->scene);
    cJSON *scene = sj ? cJSON_Parse(sj) : NULL;
    free(sj);
    jadd(root, "scene", scene, &ok);
    jstr(root, "scene_hash", in->scene->hash, &ok);
    jstr(root, "scene_path", in->scene->source_path, &ok);

    cJSON *ref = cJSON_CreateObject();
    jadd(root, "reference", ref, &ok);
    if (ok) {
        jstr(ref, "file", in->ref_exr, &ok);
        jnum(ref, "seconds_this_run", in->ref_seconds >= 0 ? in->ref_seconds : NAN, &ok);
        if (ok) ok = cJSON_AddBoolToObject(ref, "from_cache", in->ref_cached) != NULL;
        jstr(ref, "cache_file", in->ref_cache_path, &ok);
        jstr(ref, "cache_note", in->ref_cache_note, &ok);
        jnum(ref, "noise_rms_stderr_y", c->noise_y, &ok);
        jnum(ref, "preview_exposure", c->exposure, &ok);
        jstr(ref, "preview_exposure_rule", "reference 99th percentile of max(R, G, B) -> 0.8, then sRGB", &ok);
        jadd(ref, "metadata", meta_json(in->ref_meta), &ok);
    }
    /* the leaderboard: technique names, best first */
    cJSON *lb = ok ? cJSON_CreateArray() : NULL;
    for (int r = 0; lb && r < in->n_techniques; r++) {
        cJSON *x = cJSON_CreateString(in->techniques[c->order[r]].name);
        if (!x || !cJSON_AddItemToArray(lb, x)) {
            cJSON_Delete(x);
            cJSON_Delete(lb);
            lb = NULL;
        }
    }
    jadd(root, "leaderboard", lb, &ok);
    leaderboard_json(c, root, &ok);
    cJSON *ts = ok ? cJSON_CreateArray() : NULL;
    for (int k = 0; ts && k < in->n_techniques; k++) {
        int rank = 0;
        for (int r = 0; r < in->n_techniques; r++)
            if (c->order[r] == k) rank = r + 1;
        cJSON *x = technique_json(c, k, rank);
        if (!x || !cJSON_AddItemToArray(ts, x)) {
            cJSON_Delete(x);
            cJSON_Delete(ts);
            ts = NULL;
        }
    }
    jadd(root, "techniques", ts, &ok);

    if (c->have_profiles) {
        cJSON *rp = cJSON_CreateObject();
        jadd(root, "radial_profile", rp, &ok);
        jadd(rp, "refracted_sun_view_dir", jarr(c->pr.dir, 3), &ok);
        jstr(rp, "angle", "between each pixel's central ray and -T0 (sun refracted by the flat surface)", &ok);
        jnum(rp, "bin_deg", c->pr.ref.bin_deg, &ok);
        jnum(rp, "max_angle_deg", c->pr.max_deg, &ok);
        jadd(rp, "angle_deg", jarr(c->pr.ref.center_deg, c->pr.ref.nbins), &ok);
        if (ok) {
            cJSON *cnt = cJSON_CreateArray();
            for (int i = 0; cnt && i < c->pr.ref.nbins; i++) {
                cJSON *x = cJSON_CreateNumber((double)c->pr.ref.count[i]);
                if (!x || !cJSON_AddItemToArray(cnt, x)) {
                    cJSON_Delete(x);
                    cJSON_Delete(cnt);
                    cnt = NULL;
                }
            }
            jadd(rp, "pixels", cnt, &ok);
        }
        jadd(rp, "reference", profile_json(&c->pr.ref, 1), &ok);
    }
    if (in->sequence_json) { /* godrays run --frames: report/sequence.h */
        cJSON *sq = cJSON_Parse(in->sequence_json);
        if (!sq && ok) {
            cJSON_Delete(root);
            return gr_fail(err, GR_E_INPUT, "%s/metrics.json: the sequence's JSON does not parse", c->dir);
        }
        jadd(root, "sequence", sq, &ok);
    }
    cJSON *ch = cJSON_CreateObject();
    jadd(root, "charts", ch, &ok);
    jnum(ch, "drawn", c->charts, &ok);
    jstr(ch, "note", c->chart_note[0] ? c->chart_note : NULL, &ok);
    cJSON *tm = cJSON_CreateObject();
    jadd(root, "timings_s", tm, &ok);
    jnum(tm, "reference", in->ref_seconds >= 0 ? in->ref_seconds : NAN, &ok);
    for (int k = 0; k < in->n_techniques; k++)
        jnum(tm, in->techniques[k].name, in->techniques[k].seconds >= 0 ? in->techniques[k].seconds : NAN, &ok);
    jnum(tm, "compare", in->compare_seconds >= 0 ? in->compare_seconds : NAN, &ok);
    if (ok) {
        cJSON *sl = cJSON_CreateArray();
        for (int i = 0; sl && i < 2; i++) {
            cJSON *x = cJSON_CreateString(c->lines[i]);
            if (!x || !cJSON_AddItemToArray(sl, x)) {
                cJSON_Delete(x);
                cJSON_Delete(sl);
                sl = NULL;
            }
        }
        jadd(root, "summary", sl, &ok);
    }
    *text = ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!*text) return gr_fail(err, GR_E_NOMEM, "%s/metrics.json: out of memory building the JSON", c->dir);
    return GR_OK;
}

/* The pages of `godrays sweep`, `tune` and `pareto` in their folders inside the report's
 * (docs/tuning.md): a link to each one that exists now, else the command that makes it. The
 * example parameters are the leader's first two tunable settings. */
static void html_tuning_pages(gr_strbuf *b, const ctx *c)
{
    static const struct { const char *sub, *what; } pages[3] = {
        {"sweep", "the error over a grid of one or two settings of a technique"},
        {"tune", "a technique's settings with the least error over frames and views"},
        {"pareto", "speed against error of the ground truth and of every technique"},
    };
    /* example: the first technique's first two settings with a tuning box */
    const char *tname = c->in->techniques[0].name;
    const gr_param *ex[2] = {NULL, NULL};
    int sec = gr_sections_find(tname);
    const gr_param_table *tab = gr_sections_table(sec);
    for (size_t i = 0; tab && i < tab->count && !ex[1]; i++) {
        const gr_param *p = &tab->params[i];
        if (p->tune_hi > p->tune_lo && (p->type == GR_PT_DOUBLE || p->type == GR_PT_RGB)) {
            if (!ex[0]) ex[0] = p;
            else ex[1] = p;
        }
    }
    gr_sb_puts(b, "<h2>Sweep, tuning, speed against error</h2>\n<ul>\n");
    for (int k = 0; k < 3; k++) {
        char path[4300];
        struct stat sb;
        snprintf(path, sizeof path, "%s/%s/index.html", c->dir, pages[k].sub);
        gr_sb_puts(b, "<li>");
        if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode)) {
            gr_sb_printf(b, "<a href=\"%s/index.html\">%s/index.html</a>: ", pages[k].sub, pages[k].sub);
            gr_sb_html(b, pages[k].what);
        } else {
            gr_strbuf cmd;
            gr_sb_init(&cmd);
            gr_sb_printf(&cmd, "godrays %s ", pages[k].sub);
            if (c->in->scene_words) gr_sb_puts(&cmd, c->in->scene_words);
            else gr_sb_shell_word(&cmd, c->in->scene->source_path);
            for (int e = 0; k == 0 && e < 2; e++)
                if (ex[e]) {
                    char lo[32], hi[32];
                    gr_sb_printf(&cmd, " --param %s.%s=%s:%s:16", tname, ex[e]->name,
                                 gr_format_double(ex[e]->tune_lo, lo, sizeof lo),
                                 gr_format_double(ex[e]->tune_hi, hi, sizeof hi));
                }
            if (k == 1 && ex[0]) {
                gr_sb_printf(&cmd, " --params %s.%s", tname, ex[0]->name);
                if (ex[1]) gr_sb_printf(&cmd, ",%s.%s", tname, ex[1]->name);
            }
            gr_sb_puts(&cmd, " -o ");
            snprintf(path, sizeof path, "%s/%s", c->dir, pages[k].sub);
            gr_sb_shell_word(&cmd, path);
            gr_sb_printf(b, "%s/: ", pages[k].sub);
            gr_sb_html(b, pages[k].what);
            gr_sb_puts(b, "; not made yet: <code>");
            gr_sb_html(b, gr_sb_str(&cmd));
            gr_sb_puts(b, "</code>");
            if (cmd.failed) b->failed = 1;
            gr_sb_free(&cmd);
        }
        gr_sb_puts(b, "</li>\n");
    }
    gr_sb_puts(b, "</ul>\n<p class=\"sub\">Links to the pages that were in this folder when the report was written "
                  "(a page made later links back here; the next <code>godrays run</code> into this folder links it). "
                  "The commands run from the folder <code>godrays run</code> was started in; docs/tuning.md.</p>\n");
}

/* The leaderboard's header: the verdict and its components, the equivalent blur, the other
 * registry leaderboard metrics (raw and after the fit), the timings. */
static int html_leaderboard_head(gr_strbuf *b)
{
    static const char *const cols[] = {"verdict", "error after fit<br>(rel. RMSE Y)", "structure<br>score",
                                       "FLIP", "band-pass<br>corr.", "streak<br>contrast ratio", "scale a",
                                       "equivalent<br>blur"};
    int n = 3;
    gr_sb_puts(b, "<h2 id=\"leaderboard\">Leaderboard</h2>\n<table class=\"lb\"><tr><th>rank</th><th class=\"l\">"
                  "technique</th><th class=\"l\">image (x a)</th>");
    for (size_t i = 0; i < sizeof cols / sizeof cols[0]; i++, n++) gr_sb_printf(b, "<th>%s</th>", cols[i]);
    for (int i = 0; i < gr_metric_count(); i++) {
        if (!gr_metric_at(i)->leaderboard || gr_lb_verdict_column(i)) continue;
        for (int f = 0; f < 2; f++, n++) {
            gr_sb_puts(b, "<th>");
            gr_sb_html(b, gr_metric_at(i)->label);
            gr_sb_puts(b, f ? "<br>after fit</th>" : "</th>");
        }
    }
    gr_sb_puts(b, "<th>GPU ms<br>(passes)</th><th>wall ms<br>(render)</th><th>s in<br>this run</th></tr>\n");
    return n + 3;
}

/* One row of the leaderboard (report/leaderboard.h). */
static void html_leaderboard_row(gr_strbuf *b, const ctx *c, const gr_lb_row *r, int n_cols)
{
    char t[48];
    static const char *const cls[3] = {"", " class=\"baseline\"", " class=\"failed\""};
    gr_sb_printf(b, "<tr%s><td>", cls[r->kind]);
    if (r->kind == GR_LB_TECHNIQUE) gr_sb_printf(b, "%d", r->rank);
    else gr_sb_puts(b, r->kind == GR_LB_BASELINE ? "baseline" : "<b>failed</b>");
    gr_sb_puts(b, "</td><td class=\"l\">");
    if (r->kind == GR_LB_BASELINE) {
        gr_sb_puts(b, "<i>baseline</i>: ");
        gr_sb_html(b, r->text);
        gr_sb_puts(b, "</td><td class=\"l\"></td>");
    } else {
        const tctx *tc = r->kind == GR_LB_TECHNIQUE ? &c->t[r->index] : NULL;
        const char *desc = tc ? tc->t->description : c->in->failed[r->index].description;
        if (tc) {
            gr_sb_puts(b, "<a href=\"#t-");
            gr_sb_html(b, r->name);
            gr_sb_puts(b, "\">");
        }
        gr_sb_puts(b, "<b>");
        gr_sb_html(b, r->name);
        gr_sb_puts(b, tc ? "</b></a>" : "</b>");
        if (tc && r->no_better) {
            gr_sb_puts(b, "<br><span class=\"flag\">");
            gr_sb_html(b, gr_lb_flag(r));
            gr_sb_puts(b, "</span>");
        }
        gr_sb_puts(b, "<br><span class=\"sub\">");
        gr_sb_html(b, desc ? desc : "");
        gr_sb_puts(b, "</span></td><td class=\"l\">");
        if (tc) {
            gr_sb_puts(b, "<img src=\"");
            gr_sb_htmlf(b, "%s.png", tc->stem);
            gr_sb_puts(b, "\" class=\"thumb\" alt=\"");
            gr_sb_html(b, r->name);
            gr_sb_printf(b, "\" width=\"%d\" height=\"%d\">", tc->disp_fit->width, tc->disp_fit->height);
        }
        gr_sb_puts(b, "</td>");
    }
    if (r->kind == GR_LB_FAILED) {
        gr_sb_printf(b, "<td class=\"l\" colspan=\"%d\">FAILED: ", n_cols - 3);
        gr_sb_html(b, r->text);
        gr_sb_puts(b, "</td></tr>\n");
        return;
    }
    const double v[7] = {r->verdict, r->error_fit, r->structure, r->flip, r->corr, r->contrast_ratio, r->scale};
    for (int i = 0; i < 7; i++) gr_sb_printf(b, i ? "<td>%s</td>" : "<td><b>%s</b></td>", fmt(v[i], t, sizeof t));
    gr_sb_printf(b, "<td>%s</td>", gr_lb_eq_blur_text(c->in, r, t, sizeof t));
    for (int i = 0; i < gr_metric_count(); i++) {
        if (!gr_metric_at(i)->leaderboard || gr_lb_verdict_column(i)) continue;
        gr_sb_printf(b, "<td>%s</td>", fmt(gr_metric_value(&r->m->raw, i), t, sizeof t));
        gr_sb_printf(b, "<td>%s</td>", fmt(gr_metric_value(fit_set(r->m), i), t, sizeof t));
    }
    if (r->kind == GR_LB_TECHNIQUE) {
        const tctx *tc = &c->t[r->index];
        const double w[3] = {tc->gpu_ms, tc->wall_ms, tc->t->seconds >= 0 ? tc->t->seconds : NAN};
        gr_strbuf tip; /* the cost counters per pass as the GPU time's tooltip */
        gr_sb_init(&tip);
        cost_text(tc->t->meta, &tip);
        gr_sb_puts(b, "<td title=\"");
        gr_sb_html(b, gr_sb_str(&tip));
        gr_sb_printf(b, "\">%s</td>", fmt(w[0], t, sizeof t));
        gr_sb_free(&tip);
        for (int i = 1; i < 3; i++) gr_sb_printf(b, "<td>%s</td>", fmt(w[i], t, sizeof t));
    } else {
        gr_sb_puts(b, "<td></td><td></td><td></td>");
    }
    gr_sb_puts(b, "</tr>\n");
}

/* The leaderboard table: techniques and baselines by verdict, then the failed techniques. */
static void html_leaderboard(gr_strbuf *b, const ctx *c)
{
    const int n_cols = html_leaderboard_head(b);
    for (int i = 0; i < c->lb.n; i++) html_leaderboard_row(b, c, &c->lb.rows[i], n_cols);
    gr_sb_puts(b, "</table>\n<p class=\"sub\">Ranked by the <b>verdict</b> (lower is better; 0 = the truth): the mean "
                  "of the error after the best scale fit (RMSE of luminance over the truth's mean Y; each technique's "
                  "intensity is an arbitrary factor, so shapes are compared at the best-fitting level a = &lt;t, r&gt; "
                  "/ &lt;t, t&gt;) and the structure score (0 = the truth's beams, about 0.7 = none), the objective "
                  "<code>godrays tune</code> minimizes by default. FLIP, the band-pass correlation (1 = beams in the "
                  "truth's places) and the streak contrast ratio (1 = as streaky as the truth) explain it. "
                  "<i>Baselines</i> are scored the same way: a black frame, the constant image at the truth's mean and "
                  "the truth blurred by a 4 px Gaussian. The <b>equivalent blur</b> is the Gaussian sigma at which the "
                  "blurred truth gets the same verdict: a technique at \"6 px\" looks as good as the truth blurred by "
                  "6 px. A technique whose verdict is not below the constant image's is flagged <span class=\"flag\">"
                  GR_LB_NO_BETTER "</span>, and one whose error after the fit alone is not below the constant's "
                  "<span class=\"flag\">" GR_LB_NO_BETTER_ERROR "</span> (its structure score ranks it, its light "
                  "is no closer). GPU ms: the sum of the technique's GL pass timers (GL_TIME_ELAPSED; on "
                  "llvmpipe they measure the CPU rasterizer); wall ms: its render call, readback included. "
                  "docs/metrics.md \"The verdict\"; details per technique below.</p>\n");
}

static void html_technique(ctx *c, gr_strbuf *b, int k)
{
    const gr_report_input *in = c->in;
    tctx *tc = &c->t[k];
    const gr_report_technique *t = tc->t;
    const gr_metrics *m = t->metrics;
    const gr_metadata *tmeta = t->meta;
    char cap[1024], f[5][96], tt[4][64];
    gr_sb_puts(b, "<h2 id=\"t-");
    gr_sb_html(b, t->name);
    gr_sb_puts(b, "\">Technique <code>");
    gr_sb_html(b, t->name);
    gr_sb_puts(b, "</code></h2>\n<p class=\"sub\">");
    gr_sb_html(b, t->description ? t->description : "");
    gr_sb_puts(b, "</p>\n<div class=\"box\">\n");
    for (int i = 0; i < 3; i++) {
        gr_sb_html(b, tc->lines[i]);
        gr_sb_puts(b, "<br>\n");
    }
    gr_sb_puts(b, "</div>\n");
    if (m->n_stderr_excluded > 0)
        gr_sb_htmlf(b, "<p class=\"box warn\">%lld pixels NOT SCORED: the reference's relative standard error of "
                       "luminance exceeds %g there (drawn mid gray in the difference images).</p>\n",
                    m->n_stderr_excluded, m->stderr_bound);
    snprintf(f[0], sizeof f[0], "%s.png", tc->stem);
    snprintf(f[1], sizeof f[1], "%s_diff_signed.png", tc->stem);
    snprintf(f[2], sizeof f[2], "%s_diff.png", tc->stem);
    snprintf(f[3], sizeof f[3], "%s_raw.png", tc->stem);
    snprintf(f[4], sizeof f[4], "%s_flip.png", tc->stem);
    gr_sb_puts(b, "<div class=\"grid\">\n");
    snprintf(cap, sizeof cap, "Ground truth, exposure %s (its 99th percentile -> 0.8), sRGB.%s",
             fmt(c->exposure, tt[0], sizeof tt[0]), in->ref_cached ? " Read from the cache." : "");
    html_figure(b, "reference.png", c->disp_ref, "reference (ground truth)", cap);
    snprintf(cap, sizeof cap,
             "%s times the best scale a = %s, same exposure as the reference: the technique's intensity is an "
             "arbitrary factor, so shapes are compared at the best-fitting level.",
             t->name, fmt(tc->a, tt[0], sizeof tt[0]));
    html_figure(b, f[0], tc->disp_fit, "technique times a", cap);
    snprintf(cap, sizeof cap,
             "Signed luminance difference a Y(test) - Y(ref), OpenImageIO map '%s' on [%s, %s]: blue = real-time "
             "too dark, red = too bright; gray = not scored.",
             tc->info_signed.map, fmt(tc->info_signed.vmin, tt[0], sizeof tt[0]),
             fmt(tc->info_signed.vmax, tt[1], sizeof tt[1]));
    html_figure(b, f[1], tc->diff_signed, "signed difference with colorbar", cap);
    snprintf(cap, sizeof cap, "Absolute luminance difference |a Y(test) - Y(ref)|, map '%s' on [%s, %s] (99th percentile).",
             tc->info_abs.map, fmt(tc->info_abs.vmin, tt[0], sizeof tt[0]), fmt(tc->info_abs.vmax, tt[1], sizeof tt[1]));
    html_figure(b, f[2], tc->diff_abs, "absolute difference with colorbar", cap);
    snprintf(cap, sizeof cap, "%s as rendered (a = 1), own exposure %s.", t->name,
             fmt(tc->exposure_raw, tt[0], sizeof tt[0]));
    html_figure(b, f[3], tc->disp_raw, "technique as rendered", cap);
    if (tc->flip_undefined)
        snprintf(cap, sizeof cap, "HDR-FLIP of a x %s against the ground truth: not computed (%s); the map is left black.",
                 t->name, tc->flip_why);
    else
        snprintf(cap, sizeof cap,
                 "HDR-FLIP per pixel of a x %s against the ground truth (Andersson et al. 2020, 2021; docs/metrics.md): "
                 "magma from 0 (black, no visible difference) to 1 (pale yellow); mean %.4f, median %.4f.",
                 t->name, tc->flip.mean, tc->flip.median);
    html_figure(b, f[4], tc->flip_map, "FLIP map", cap);
    gr_sb_puts(b, "</div>\n");
    if (tc->disp_targets) { /* run --save-targets */
        snprintf(f[0], sizeof f[0], "%s_targets.png", tc->stem);
        snprintf(cap, sizeof cap,
                 "Every render target of %s side by side, each at its own size (RGB; own exposure %s): the "
                 "intermediate images its passes wrote.", t->name, fmt(tc->exposure_targets, tt[0], sizeof tt[0]));
        html_figure(b, f[0], tc->disp_targets, "render targets", cap);
    }
    if (t->exr && in->ref_exr) {
        gr_sb_puts(b, "<p class=\"sub\">The linear images: <a href=\"");
        gr_sb_html(b, in->ref_exr);
        gr_sb_puts(b, "\">");
        gr_sb_html(b, in->ref_exr);
        gr_sb_puts(b, "</a>, <a href=\"");
        gr_sb_html(b, t->exr);
        gr_sb_puts(b, "\">");
        gr_sb_html(b, t->exr);
        gr_sb_puts(b, "</a>.</p>\n");
    }
    /* metrics */
    gr_sb_puts(b, "<h3>Metrics</h3>\n<p class=\"sub\">");
    gr_sb_htmlf(b, "%lld of %lld pixels scored (%lld masked out, %lld not scored because the reference's relative "
                   "standard error of luminance exceeds %s). Y = 0.2126 R + 0.7152 G + 0.0722 B; RGB pools the "
                   "three channels as OpenImageIO idiff does. Formulas and conventions: docs/metrics.md.",
                m->n_scored, m->n_pixels, m->n_masked_out, m->n_stderr_excluded, fmt(m->stderr_bound, tt[0], sizeof tt[0]));
    gr_sb_puts(b, "</p>\n");
    html_registry_table(b, m);
    gr_sb_puts(b, "<div class=\"grid\">\n<div>\n");
    if (m->have_fit) {
        char capt[160];
        snprintf(capt, sizeof capt, "After the best scale fit: test x a, a = <t, r> / <t, t> = %.6g%s", m->fit.scale,
                 m->fit_defined ? "" : " (undefined: test is black; a = 1)");
        html_metrics_table(b, m, &m->fit, capt);
        gr_sb_puts(b, "</div>\n<div>\n");
    }
    html_metrics_table(b, m, &m->raw, "As rendered (a = 1): the real-time technique's own, arbitrary, intensity scale");
    gr_sb_puts(b, "</div>\n</div>\n");
    gr_sb_htmlf(b, "SSIM: Wang et al. 2004 on luminance, L = %.4g (reference luminance peak), C1 = %.3g, C2 = %.3g.",
                m->ssim_L, m->ssim_c1, m->ssim_c2);
    if (c->charts > 0) {
        char alt[160];
        gr_sb_puts(b, "\n<div class=\"grid\">\n");
        snprintf(f[0], sizeof f[0], "%s_radial_profile_rgb.png", tc->stem);
        snprintf(alt, sizeof alt, "%s: radial profile per channel", t->name);
        html_figure(b, f[0], NULL, alt, "Mean radiance per RGB channel against the angle from the refracted sun: "
                                        "solid = reference, dashed = the technique x a.");
        snprintf(f[1], sizeof f[1], "%s_error_vs_blur.png", tc->stem);
        snprintf(alt, sizeof alt, "%s: error against blur scale", t->name);
        html_figure(b, f[1], NULL, alt,
                    "RMSE of the difference after a Gaussian blur of sigma 1, 4, 16 px: where it falls with blur, "
                    "the large-scale light distribution is right even if details do not line up. The gray line is "
                    "the reference's own noise (RMS standard error), below which differences mean nothing.");
        gr_sb_puts(b, "</div>\n");
    }
    /* timings and counters */
    gr_sb_puts(b, "<h3>Timings and counters</h3>\n<table>\n");
    kv_num(b, "time in this run (instance, render, readback)", t->seconds >= 0 ? t->seconds : NAN, 1.0, "s");
    const char *passes = meta_str(tmeta, "godrays:passes");
    if (passes && passes[0]) {
        char pname[64], key[96], label[128];
        const char *p = passes;
        while (*p) {
            size_t n = strcspn(p, " ");
            snprintf(pname, sizeof pname, "%.*s", (int)(n < sizeof pname - 1 ? n : sizeof pname - 1), p);
            snprintf(key, sizeof key, "godrays:gpu_ns.%s", pname);
            snprintf(label, sizeof label, "GPU time, pass '%s'", pname);
            const double v = meta_num(tmeta, key);
            kv_num(b, label, v >= 0 ? v : NAN, 1e-6, "ms");
            p += n;
            while (*p == ' ') p++;
        }
    }
    kv_num(b, "GPU time, all passes", tc->gpu_ms, 1.0, "ms");
    kv_num(b, "wall time of the render call", tc->wall_ms, 1.0, "ms");
    const double fr = meta_num(tmeta, "godrays:fragments");
    kv_num(b, "fragments (main passes)", fr >= 0 ? fr : NAN, 1.0, "");
    const char *gl = meta_str(tmeta, "godrays:gl_renderer");
    kv_row(b, "GL renderer", gl ? gl : "n/a");
    gr_sb_puts(b, "</table>\n<details><summary>Its EXR metadata (every figure the technique reports)</summary>\n");
    html_meta_table(b, tmeta);
    gr_sb_puts(b, "</details>\n");
}

static gr_status build_html(ctx *c, gr_strbuf *b, gr_error *err)
{
    const gr_report_input *in = c->in;
    const gr_scene *s = in->scene;
    gr_sb_puts(b, "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>");
    gr_sb_htmlf(b, "godrays report: %s", s->name);
    gr_sb_printf(b, "</title>\n<style>%s</style>\n</head>\n<body>\n<h1>", CSS);
    gr_sb_htmlf(b, "God rays: ground truth vs %d real-time technique%s, scene '%s'", in->n_techniques,
                in->n_techniques == 1 ? "" : "s", s->name);
    gr_sb_puts(b, "</h1>\n<p class=\"sub\">");
    {
        char when[64] = "";
        time_t now = time(NULL);
        struct tm tmv;
        if (gmtime_r(&now, &tmv)) strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &tmv);
        gr_sb_htmlf(b, "scene file %s, hash %s, %d x %d pixels; written by godrays %s on %s",
                    s->source_path[0] ? s->source_path : "(string)", s->hash, in->ref->width, in->ref->height,
                    GR_VERSION, when);
    }
    if (in->command_line) {
        gr_sb_puts(b, "<br>command: <code>");
        gr_sb_html(b, in->command_line);
        gr_sb_puts(b, "</code>");
    }
    gr_sb_puts(b, "</p>\n<div class=\"box\">\n");
    for (int i = 0; i < 2; i++) {
        gr_sb_html(b, c->lines[i]);
        gr_sb_puts(b, "<br>\n");
    }
    gr_sb_puts(b, "</div>\n");
    /* Warnings a reader must not miss. */
    const int no_stderr = gr_image_channel(in->ref, "stderr.R") < 0;
    const int black = gr_report_truth_zero(in); /* the terminal says it too (cmd_run) */
    char coarse_msg[512];
    const int coarse = gr_report_truth_coarse(in, coarse_msg, sizeof coarse_msg); /* cmd_run says it too */
    if (no_stderr || in->ref_cache_note || meta_num(in->ref_meta, "godrays:partial") > 0 || in->n_failed > 0 || black ||
        coarse) {
        gr_sb_puts(b, "<div class=\"box warn\">\n");
        if (black)
            gr_sb_html(b, " The ground truth is zero everywhere: the metrics below say nothing (camera inside an occluder, "
                          "no scattering, or no light left in float range: the medium's extinction times the depth).");
        if (in->n_failed > 0)
            gr_sb_htmlf(b, " %d technique%s FAILED (no image to score): see the leaderboard's failed rows.",
                        in->n_failed, in->n_failed == 1 ? "" : "s");
        if (no_stderr) gr_sb_html(b, " The reference carries no standard-error channels: no significance test.");
        if (coarse) {
            coarse_msg[0] = (char)toupper((unsigned char)coarse_msg[0]); /* lower-case for the terminal's "warning: " */
            gr_sb_html(b, " ");
            gr_sb_html(b, coarse_msg);
        }
        if (meta_num(in->ref_meta, "godrays:partial") > 0)
            gr_sb_html(b, " The reference is a PARTIAL (interrupted) render.");
        if (in->ref_cache_note) {
            gr_sb_puts(b, " Cache: ");
            gr_sb_html(b, in->ref_cache_note);
        }
        gr_sb_puts(b, "\n</div>\n");
    }
    html_leaderboard(b, c);
    if (in->sequence_href) {
        gr_sb_puts(b, "<p class=\"box\">This run rendered a sequence of frames: its report over time (a chart per "
                      "metric, an animation per technique) is <a href=\"");
        gr_sb_html(b, in->sequence_href);
        gr_sb_puts(b, "\">");
        gr_sb_html(b, in->sequence_href);
        gr_sb_puts(b, "</a>. This page compares the first frame.</p>\n");
    }
    if (in->n_techniques > 0) {
        gr_viewer_item vi[GR_REPORT_MAX_TECHNIQUES];
        for (int r = 0; r < in->n_techniques; r++) { /* leaderboard order: 1 = the best */
            const tctx *tc = &c->t[c->order[r]];
            vi[r] = (gr_viewer_item){.name = tc->t->name, .test = tc->t->test, .scale = tc->a,
                                     .flip_map = tc->flip_map, .flip_mean = tc->flip.mean};
        }
        gr_status vst = gr_viewer_write(c->dir, in->ref, vi, in->n_techniques, c->exposure, b, err);
        if (vst != GR_OK) return vst;
    }
    if (in->n_techniques > 0)
        gr_sb_puts(b, "<p class=\"sub\">Every technique beside the reference with the key numbers: "
                      "<a href=\"summary.png\">summary.png</a>; every number: <a href=\"metrics.json\">metrics.json</a>.</p>\n");
    else
        gr_sb_puts(b, "<p class=\"sub\">Every number: <a href=\"metrics.json\">metrics.json</a>.</p>\n");
    if (c->charts > 0) {
        gr_sb_puts(b, "<div class=\"grid\">\n");
        html_figure(b, "radial_profile.png", NULL, "radial profile, luminance, every technique",
                    "Mean luminance against the angle between each pixel's ray and the direction in which the "
                    "refracted sun is seen (log scale): the reference and every technique times its a.");
        gr_sb_puts(b, "</div>\n");
    }
    if (c->chart_note[0]) {
        gr_sb_puts(b, "<p class=\"box warn\">");
        gr_sb_html(b, c->chart_note);
        gr_sb_puts(b, "</p>\n");
    }
    for (int r = 0; r < in->n_techniques; r++) html_technique(c, b, c->order[r]);

    /* The ground truth */
    gr_sb_puts(b, "<h2>Ground truth</h2>\n<table><caption class=\"sub\">ground truth (reference/)</caption>\n");
    const gr_metadata *rm = in->ref_meta;
    kv_row(b, "source", in->ref_cached ? "cache" : "rendered in this run");
    kv_num(b, "time in this run", in->ref_seconds >= 0 ? in->ref_seconds : NAN, 1.0, "s");
    kv_num(b, "render wall time", meta_num(rm, "godrays:wall_s"), 1.0, "s");
    kv_num(b, "threads", meta_num(rm, "godrays:threads"), 1.0, "");
    kv_num(b, "camera samples per pixel", meta_num(rm, "godrays:spp"), 1.0, "");
    kv_num(b, "passes (sun directions)", meta_num(rm, "godrays:passes"), 1.0, "");
    kv_num(b, "rel. std. error of the image mean", meta_num(rm, "godrays:rel_stderr_mean"), 100.0, "%");
    kv_num(b, "rel. std. error of the p95 pixel", meta_num(rm, "godrays:rel_stderr_p95"), 100.0, "%");
    kv_num(b, "pixels with std. error <= 1%", meta_num(rm, "godrays:frac_pixels_stderr_le_1pct"), 100.0, "%");
    kv_num(b, "surface bias, estimate (order 2)", meta_num(rm, "godrays:bias_surface_rel_est"), 100.0, "%");
    kv_num(b, "surface bias, with the measured order", meta_num(rm, "godrays:bias_surface_rel_measured_order"), 100.0, "%");
    kv_num(b, "surface bias, 95th-percentile 10x10 block", meta_num(rm, "godrays:bias_block_p95_rel"), 100.0, "%");
    kv_num(b, "RMS std. error of Y (noise)", c->noise_y, 1.0, "");
    kv_num(b, "beam lookups per second", meta_num(rm, "godrays:queries_per_s"), 1.0, "");
    kv_num(b, "beam build time", meta_num(rm, "godrays:beam_build_s"), 1.0, "s");
    kv_num(b, "beam primitives", meta_num(rm, "godrays:beam_prims"), 1.0, "");
    if (in->ref_cache_path) kv_row(b, "cache file", in->ref_cache_path);
    kv_num(b, "comparison (metrics) time, all techniques", in->compare_seconds >= 0 ? in->compare_seconds : NAN, 1.0, "s");
    gr_sb_puts(b, "</table>\n");

    if (in->n_techniques > 0) html_tuning_pages(b, c);

    /* Scene and settings */
    gr_sb_puts(b, "<h2>Scene and settings</h2>\n");
    gr_sb_puts(b, "<h3>Ground-truth settings</h3>\n");
    html_settings_table(b, &gr_reference_param_table, &s->reference);
    for (int k = 0; k < in->n_techniques; k++) {
        const int i = gr_sections_find(in->techniques[k].name);
        const gr_param_table *tab = gr_sections_table(i);
        const void *set = gr_scene_section_const(s, i);
        if (!tab || !set) continue;
        gr_sb_puts(b, "<h3>Settings of <code>");
        gr_sb_html(b, tab->section);
        gr_sb_puts(b, "</code></h3>\n");
        html_settings_table(b, tab, set);
    }
    gr_sb_puts(b, "<details><summary>The scene, normalized (every default filled in)</summary>\n<pre>");
    char *sj = gr_scene_to_json(s);
    if (!sj) return gr_fail(err, GR_E_NOMEM, "%s/index.html: out of memory printing the scene", c->dir);
    gr_sb_html(b, sj);
    free(sj);
    gr_sb_puts(b, "</pre></details>\n");
    gr_sb_puts(b, "<details><summary>Reference EXR metadata</summary>\n");
    html_meta_table(b, rm);
    gr_sb_puts(b, "</details>\n<p class=\"sub\">How to read this report: docs/report.md in the godrays sources.</p>\n"
                  "</body>\n</html>\n");
    return gr_sb_status(b, "index.html", err);
}

/* HDR-FLIP of a * test over every pixel for technique k (gr_parallel_for: each job writes its
 * own tctx; the same numbers on any number of threads). */
static void flip_job(void *arg, int k)
{
    ctx *c = arg;
    tctx *tc = &c->t[k];
    const gr_image *ref = c->in->ref;
    tc->flip_px = malloc((size_t)ref->width * (size_t)ref->height * sizeof(float));
    gr_flip_options fo = {.mode = GR_FLIP_HDR, .test_scale = tc->a, .reference = c->flip_ref};
    tc->flip_st = tc->flip_px ? gr_flip_compute_defined(ref, tc->t->test, &fo, tc->flip_px, &tc->flip, &tc->flip_undefined,
                                                        tc->flip_why, sizeof tc->flip_why, &tc->flip_err)
                              : gr_fail(&tc->flip_err, GR_E_NOMEM, "report: out of memory for the FLIP map");
}

static gr_status check_input(const gr_report_input *in, gr_error *err)
{
    if (!in || !in->scene || !in->ref || !in->ref->pixels)
        return gr_fail(err, GR_E_INPUT, "report: missing scene or reference image");
    if (in->n_techniques < 0 || in->n_techniques > GR_REPORT_MAX_TECHNIQUES || (in->n_techniques > 0 && !in->techniques) ||
        in->n_failed < 0 || in->n_failed > GR_REPORT_MAX_TECHNIQUES || (in->n_failed > 0 && !in->failed) ||
        in->n_techniques + in->n_failed < 1)
        return gr_fail(err, GR_E_INPUT, "report: %d techniques and %d failed (1..%d)", in->n_techniques, in->n_failed,
                       GR_REPORT_MAX_TECHNIQUES);
    for (int f = 0; f < in->n_failed; f++)
        if (!in->failed[f].name || !in->failed[f].name[0] || !in->failed[f].reason)
            return gr_fail(err, GR_E_INPUT, "report: failed technique %d: missing name or reason", f);
    for (int k = 0; k < in->n_techniques; k++) {
        const gr_report_technique *t = &in->techniques[k];
        if (!t->name || !t->name[0] || !t->test || !t->test->pixels || !t->metrics)
            return gr_fail(err, GR_E_INPUT, "report: technique %d: missing name, image or metrics", k);
        for (const char *p = t->name; *p; p++)
            if (!((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_'))
                return gr_fail(err, GR_E_INPUT, "report: technique name '%s': only [a-z0-9_]", t->name);
        if (strlen(t->name) > 40) return gr_fail(err, GR_E_INPUT, "report: technique name '%s': too long", t->name);
        for (int j = 0; j < k; j++)
            if (!strcmp(in->techniques[j].name, t->name))
                return gr_fail(err, GR_E_INPUT, "report: technique '%s' given twice", t->name);
        if (in->ref->width != t->test->width || in->ref->height != t->test->height)
            return gr_fail(err, GR_E_INPUT, "report: reference is %d x %d, %s is %d x %d", in->ref->width,
                           in->ref->height, t->name, t->test->width, t->test->height);
        if (t->metrics->width != in->ref->width || t->metrics->height != in->ref->height)
            return gr_fail(err, GR_E_INPUT, "report: the metrics of %s are for %d x %d images, not %d x %d", t->name,
                           t->metrics->width, t->metrics->height, in->ref->width, in->ref->height);
    }
    return GR_OK;
}

/* Stacks the rows of the contact sheet (same background as gr_report_contact_sheet). */
static gr_image *stack_rows(gr_image *const *rows, int n)
{
    int W = 0, H = 0;
    for (int i = 0; i < n; i++) {
        if (rows[i]->width > W) W = rows[i]->width;
        H += rows[i]->height;
    }
    gr_image *s = gr_image_create(W, H, 3, NULL);
    if (!s) return NULL;
    static const float bg[3] = {0.11f, 0.12f, 0.14f};
    for (size_t i = 0; i < (size_t)W * (size_t)H; i++)
        for (int c = 0; c < 3; c++) s->pixels[i * 3 + (size_t)c] = bg[c];
    int y0 = 0;
    for (int i = 0; i < n; i++) {
        for (int y = 0; y < rows[i]->height; y++)
            memcpy(gr_image_pixel(s, 0, y0 + y), gr_image_pixel(rows[i], 0, y), (size_t)rows[i]->width * 3 * sizeof(float));
        y0 += rows[i]->height;
    }
    return s;
}

int gr_report_truth_coarse(const gr_report_input *in, char *msg, size_t n)
{
    const double est = meta_num(in->ref_meta, "godrays:bias_surface_rel_est");
    /* the line of GR_TRUTH_COARSE_BIAS (reference/truth.h; src/report does not include reference/) */
    if (!(est > 0.01) || !isfinite(est)) return 0;
    if (msg && n > 0) {
        const double bm = meta_num(in->ref_meta, "godrays:bias_surface_rel_measured_order"),
                     bp = meta_num(in->ref_meta, "godrays:bias_block_p95_rel"),
                     res = meta_num(in->ref_meta, "godrays:reference.surface_res");
        char more[160] = "", fix[96] = "";
        if (bm > est && bp > 0.0)
            snprintf(more, sizeof more, " (%.2g %% with the measured order; 95th-percentile block %.2g %%)", 100.0 * bm,
                     100.0 * bp);
        else if (bm > est) snprintf(more, sizeof more, " (%.2g %% with the measured order)", 100.0 * bm);
        if (res > 0.0) snprintf(fix, sizeof fix, " A finer truth: reference.surface_res %.0f.", 2.0 * res);
        snprintf(msg, n,
                 "the ground truth's surface tessellation is coarse for this view: its bias is about %.2g %% of the image "
                 "mean in the worst channel%s, so differences of that size are not the techniques' (docs/reference.md "
                 "4, \"Views with a wide lit region\").%s",
                 100.0 * est, more, fix);
    }
    return 1;
}

int gr_report_truth_zero(const gr_report_input *in)
{
    const gr_metrics *m0 = in->baselines ? &in->baselines->m[0] : in->n_techniques > 0 ? in->techniques[0].metrics : NULL;
    return m0 && m0->raw.ch[GR_MCH_Y].ref_mean == 0.0;
}

gr_status gr_report_write(const char *dir, const gr_report_input *in, gr_report_result *res, gr_error *err)
{
    const double t0 = now_s();
    gr_status st = check_input(in, err);
    if (st != GR_OK) return st;
    ctx *cp = calloc(1, sizeof *cp);
    if (!cp) return gr_fail(err, GR_E_NOMEM, "report: out of memory");
    ctx *c = cp;
    c->dir = dir;
    c->in = in;
    const int nt = in->n_techniques;
    double as[GR_REPORT_MAX_TECHNIQUES];
    c->exposure = gr_report_exposure(in->ref, 1.0, 0.99, 0.8);
    c->noise_y = ref_noise_rms_y(in->ref);
    gr_report_rank(in->techniques, nt, c->order);
    for (int k = 0; k < nt; k++) {
        tctx *tc = &c->t[k];
        tc->t = &in->techniques[k];
        gr_report_tech_stem(tc->t->name, tc->stem, sizeof tc->stem);
        const gr_metrics *m = tc->t->metrics;
        tc->a = as[k] = m->have_fit && m->fit_defined ? m->fit.scale : 1.0;
        tc->exposure_raw = gr_report_exposure(tc->t->test, 1.0, 0.99, 0.8);
        const double g = meta_num(tc->t->meta, "godrays:gpu_ms"), w = meta_num(tc->t->meta, "godrays:wall_ms");
        tc->gpu_ms = g >= 0 ? g : NAN;
        tc->wall_ms = w >= 0 ? w : NAN;
    }
    gr_image *sheet = NULL, *rows[GR_REPORT_MAX_TECHNIQUES] = {NULL};
    gr_flip_reference *flip_ref = NULL;
    char *json = NULL;
    gr_strbuf html;
    gr_sb_init(&html);
    char path[4200], file[128];

    /* Everything that can fail for lack of memory or bad input is computed first. */
    if ((st = gr_report_make_dir(dir, err)) != GR_OK) goto done;
    if ((st = gr_report_display(in->ref, c->exposure, &c->disp_ref, err)) != GR_OK) goto done;
    /* the techniques' HDR-FLIP maps, the report's dearest part, on a few threads, the truth's
     * half computed once (compare/flip.h: the same numbers) */
    const gr_flip_options flip_fo = {.mode = GR_FLIP_HDR};
    if (gr_flip_reference_matches(in->flip_ref, in->ref, &flip_fo)) {
        c->flip_ref = in->flip_ref;
    } else if (nt > 1) {
        if ((st = gr_flip_reference_create(in->ref, &flip_fo, GR_FLIP_SHARED_PREPARE_MAX, 0, &flip_ref, err)) != GR_OK)
            goto done;
        c->flip_ref = flip_ref;
    }
    gr_parallel_for(nt, 0, flip_job, c);
    for (int k = 0; k < nt; k++) {
        tctx *tc = &c->t[k];
        if ((st = gr_report_display(tc->t->test, c->exposure * tc->a, &tc->disp_fit, err)) != GR_OK) goto done;
        if ((st = gr_report_display(tc->t->test, tc->exposure_raw, &tc->disp_raw, err)) != GR_OK) goto done;
        if (tc->t->targets) {
            tc->exposure_targets = gr_report_exposure(tc->t->targets, 1.0, 0.99, 0.8);
            if ((st = gr_report_display(tc->t->targets, tc->exposure_targets, &tc->disp_targets, err)) != GR_OK) goto done;
        }
        for (int s = 0; s < 2; s++) {
            gr_diffmap_options dopt = {.kind = s ? GR_DIFFMAP_SIGNED : GR_DIFFMAP_ABS, .scale = tc->a, .mask = NULL,
                                       .stderr_bound = tc->t->metrics->stderr_bound};
            st = gr_diffmap_create(in->ref, tc->t->test, &dopt, s ? &tc->diff_signed : &tc->diff_abs,
                                   s ? &tc->info_signed : &tc->info_abs, err);
            if (st != GR_OK) goto done;
        }
        {
            /* HDR-FLIP of a * test over every pixel (flip_job), and its magma picture (none,
             * said in the caption, when a black ground truth gives it no exposure range) */
            st = tc->flip_st;
            if (st != GR_OK && err) *err = tc->flip_err;
            if (st == GR_OK) st = gr_flip_heatmap(tc->flip_px, in->ref->width, in->ref->height, &tc->flip_map, err);
            free(tc->flip_px);
            tc->flip_px = NULL;
            if (st != GR_OK) goto done;
        }
    }
    if ((st = compute_profiles(in, as, &c->pr, err)) != GR_OK) goto done;
    c->have_profiles = 1;
    {
        double flips[GR_REPORT_MAX_TECHNIQUES];
        for (int k = 0; k < nt; k++) flips[k] = c->t[k].flip.mean;
        gr_leaderboard_build(in, flips, &c->lb);
    }
    summary_lines(c);

    /* Files: images first, the pages that link them last. */
    if ((st = join(path, sizeof path, dir, "reference.png", err)) != GR_OK) goto done;
    if ((st = gr_oiio_write(path, c->disp_ref, err)) != GR_OK) goto done;
    for (int k = 0; k < nt; k++) {
        tctx *tc = &c->t[k];
        static const char *const suffix[5] = {"", "_raw", "_diff_signed", "_diff", "_flip"};
        const gr_image *imgs[5] = {tc->disp_fit, tc->disp_raw, tc->diff_signed, tc->diff_abs, tc->flip_map};
        for (int i = 0; i < 5; i++) {
            snprintf(file, sizeof file, "%s%s.png", tc->stem, suffix[i]);
            if ((st = join(path, sizeof path, dir, file, err)) != GR_OK) goto done;
            if ((st = gr_oiio_write(path, imgs[i], err)) != GR_OK) goto done;
        }
        if (tc->disp_targets) {
            snprintf(file, sizeof file, "%s_targets.png", tc->stem);
            if ((st = join(path, sizeof path, dir, file, err)) != GR_OK) goto done;
            if ((st = gr_oiio_write(path, tc->disp_targets, err)) != GR_OK) goto done;
        }
    }
    /* summary.png: one row per technique in leaderboard order, the first with the global lines */
    c->labelled = 1;
    for (int r = 0; r < nt; r++) {
        tctx *tc = &c->t[c->order[r]];
        char t0s[32], title[3][128];
        snprintf(title[0], sizeof title[0], "ground truth (reference)");
        snprintf(title[1], sizeof title[1], "#%d %s x %s", r + 1, tc->t->name, fmt(tc->a, t0s, sizeof t0s));
        snprintf(title[2], sizeof title[2], "a Y(test) - Y(ref)  (blue: too dark)");
        const gr_image *panels[3] = {c->disp_ref, tc->disp_fit, tc->diff_signed};
        const char *const titles[3] = {title[0], title[1], title[2]};
        const char *lines[5];
        int nl = 0;
        if (r == 0) {
            lines[nl++] = c->lines[0];
            lines[nl++] = c->lines[1];
        }
        for (int i = 0; i < 3; i++) lines[nl++] = tc->lines[i];
        int lab = 0;
        if ((st = gr_report_contact_sheet(panels, titles, lines, nl, 360, 800, &rows[r], &lab, err)) != GR_OK) goto done;
        c->labelled = c->labelled && lab;
    }
    sheet = nt > 0 ? stack_rows(rows, nt) : NULL;
    if (nt > 0 && !sheet) {
        st = gr_fail(err, GR_E_NOMEM, "report: out of memory for summary.png");
        goto done;
    }
    if ((st = join(path, sizeof path, dir, "summary.png", err)) != GR_OK) goto done;
    if (sheet && (st = gr_oiio_write(path, sheet, err)) != GR_OK) goto done;
    /* A chart PLplot could not draw is reported in the page, not fatal: the rest of the report
     * stands on its own. Running out of memory or disk is. */
    st = nt > 0 ? draw_charts(dir, in, as, &c->pr, c->noise_y, &c->charts, c->chart_note, sizeof c->chart_note, err)
                : GR_OK; /* every technique failed: the leaderboard alone */
    if (st == GR_E_RUNTIME) {
        snprintf(c->chart_note, sizeof c->chart_note, "charts incomplete (%d drawn): %.400s", c->charts, err->msg);
        st = GR_OK;
    }
    if (st != GR_OK) goto done;
    if ((st = build_json(c, &json, err)) != GR_OK) goto done;
    if ((st = join(path, sizeof path, dir, "metrics.json", err)) != GR_OK) goto done;
    if ((st = write_text(path, json, err)) != GR_OK) goto done;
    if ((st = build_html(c, &html, err)) != GR_OK) goto done;
    if ((st = join(path, sizeof path, dir, "index.html", err)) != GR_OK) goto done;
    if ((st = write_text(path, gr_sb_str(&html), err)) != GR_OK) goto done;
    if (res) {
        res->exposure = c->exposure;
        for (int k = 0; k < nt; k++) {
            res->fit_scale[k] = c->t[k].a;
            res->order[k] = c->order[k];
            res->flip[k] = c->t[k].flip.mean;
        }
        res->charts = c->charts;
        res->labelled = c->labelled;
        res->seconds = now_s() - t0;
    }
done:
    gr_sb_free(&html);
    cJSON_free(json);
    gr_image_destroy(sheet);
    for (int k = 0; k < GR_REPORT_MAX_TECHNIQUES; k++) gr_image_destroy(rows[k]);
    gr_image_destroy(c->disp_ref);
    gr_flip_reference_destroy(flip_ref);
    for (int k = 0; k < nt; k++) {
        tctx *tc = &c->t[k];
        gr_image_destroy(tc->disp_fit);
        gr_image_destroy(tc->disp_raw);
        gr_image_destroy(tc->diff_signed);
        gr_image_destroy(tc->diff_abs);
        gr_image_destroy(tc->flip_map);
        gr_image_destroy(tc->disp_targets);
        free(tc->flip_px); /* a FLIP map not drawn (an earlier step failed) */
    }
    free_profiles(&c->pr);
    free(cp);
    return st;
}
