/* The sequence report: see sequence.h; docs/report.md "Sequence report". */
#include "report/sequence.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cjson/cJSON.h>

#include "common/outfile.h"
#include "compare/diffmap.h"
#include "compare/flip.h"
#include "compare/metrics.h"
#include "compare/structure.h"
#include "compare/temporal.h"
#include "image/oiio.h"
#include "report/html.h"
#include "report/plot.h"
#include "report/profile.h"
#include "report/report.h"

enum { M_REL = 0, M_SSIM, M_FLIP, M_STRUCT, M_FRAME_COUNT };

typedef struct seq_tech {
    gr_metrics *m;                   /* per frame */
    double a;                        /* the scale for the whole sequence */
    gr_temporal_frame *tf;
    gr_temporal_pair *tp;
    gr_temporal_summary sum;
    int have_temporal;
    char note[256];                  /* why drift is missing */
    double series[M_FRAME_COUNT][GR_SEQUENCE_MAX_FRAMES];
} seq_tech;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    if (n <= 0) return 1.0;
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static gr_status check_input(const gr_sequence_input *in, gr_error *err)
{
    if (!in || !in->times || !in->scenes || !in->refs || !in->names || !in->tests)
        return gr_fail(err, GR_E_INPUT, "sequence: missing input");
    if (in->n_frames < 2 || in->n_frames > GR_SEQUENCE_MAX_FRAMES)
        return gr_fail(err, GR_E_INPUT, "sequence: %d frames (2..%d)", in->n_frames, GR_SEQUENCE_MAX_FRAMES);
    if (in->n_techniques < 1 || in->n_techniques > GR_SEQUENCE_MAX_TECHNIQUES)
        return gr_fail(err, GR_E_INPUT, "sequence: %d techniques (1..%d)", in->n_techniques,
                       GR_SEQUENCE_MAX_TECHNIQUES);
    const gr_image *r0 = in->refs[0];
    for (int i = 0; i < in->n_frames; i++) {
        if (!in->refs[i] || !in->scenes[i] || in->refs[i]->width != r0->width || in->refs[i]->height != r0->height)
            return gr_fail(err, GR_E_INPUT, "sequence: frame %d: ground truth missing or of another size", i);
        for (int k = 0; k < in->n_techniques; k++) {
            const gr_image *t = in->tests[k * in->n_frames + i];
            if (!in->names[k] || !t || t->width != r0->width || t->height != r0->height)
                return gr_fail(err, GR_E_INPUT, "sequence: technique %d, frame %d: image missing or of another size",
                               k, i);
        }
    }
    return GR_OK;
}

/* One frame of the animation: truth | a T | signed difference, labelled. */
static gr_status anim_frame(const gr_sequence_input *in, int k, int i, double a, double exposure, double *vmax,
                            gr_image **out, gr_error *err)
{
    gr_image *p[3] = {NULL, NULL, NULL};
    const gr_image *ref = in->refs[i], *test = in->tests[k * in->n_frames + i];
    gr_status st = gr_report_display(ref, exposure, &p[0], err);
    if (st == GR_OK) st = gr_report_display(test, exposure * a, &p[1], err);
    if (st == GR_OK) {
        gr_diffmap_options dopt = {.kind = GR_DIFFMAP_SIGNED, .scale = a, .vmax = *vmax};
        gr_diffmap_info info;
        st = gr_diffmap_create(ref, test, &dopt, &p[2], &info, err);
        if (st == GR_OK && *vmax == 0) *vmax = info.vmax; /* frame 0 sets the scale of every frame */
    }
    if (st == GR_OK) {
        char title[3][96], line[160];
        snprintf(title[0], sizeof title[0], "ground truth");
        snprintf(title[1], sizeof title[1], "%.40s x %.4g", in->names[k], a);
        snprintf(title[2], sizeof title[2], "a Y(test) - Y(ref)");
        if (in->frame_numbers)
            snprintf(line, sizeof line, "frame %4ld   t = %8.3f s", in->frame_numbers[i], in->times[i]);
        else
            snprintf(line, sizeof line, "frame %4d   t = %8.3f s", i, in->times[i]);
        const gr_image *const panels[3] = {p[0], p[1], p[2]};
        const char *const titles[3] = {title[0], title[1], title[2]};
        const char *lines[1] = {line};
        int lab = 0;
        st = gr_report_contact_sheet(panels, titles, lines, 1, 240, 640, out, &lab, err);
    }
    for (int j = 0; j < 3; j++) gr_image_destroy(p[j]);
    return st;
}

/* The animation of technique k: frames padded to the largest (sheets widen with their text). */
static gr_status write_gif(const char *dir, const gr_sequence_input *in, int k, double a, double exposure,
                           gr_error *err)
{
    const int n = in->n_frames;
    gr_image *f[GR_SEQUENCE_MAX_FRAMES] = {NULL};
    double vmax = 0;
    gr_status st = GR_OK;
    int w = 0, h = 0;
    for (int i = 0; i < n && st == GR_OK; i++) {
        st = anim_frame(in, k, i, a, exposure, &vmax, &f[i], err);
        if (st == GR_OK) {
            if (f[i]->width > w) w = f[i]->width;
            if (f[i]->height > h) h = f[i]->height;
        }
    }
    for (int i = 0; i < n && st == GR_OK; i++) {
        if (f[i]->width == w && f[i]->height == h) continue;
        gr_image *g = gr_image_create(w, h, 3, NULL);
        if (!g) {
            st = gr_fail(err, GR_E_NOMEM, "sequence: out of memory for an animation frame");
            break;
        }
        for (int y = 0; y < f[i]->height; y++)
            memcpy(gr_image_pixel(g, 0, y), gr_image_pixel(f[i], 0, y), (size_t)f[i]->width * 3 * sizeof(float));
        gr_image_destroy(f[i]);
        f[i] = g;
    }
    if (st == GR_OK) {
        char path[4300];
        snprintf(path, sizeof path, "%s/%s.gif", dir, in->names[k]);
        st = gr_oiio_write_animation(path, (const gr_image *const *)f, n, in->playback_fps > 0 ? in->playback_fps : 4.0,
                                     err);
    }
    for (int i = 0; i < n; i++) gr_image_destroy(f[i]);
    return st;
}

static const unsigned char COLORS[8][3] = {{31, 119, 180}, {44, 160, 44},  {255, 127, 14}, {214, 39, 40},
                                           {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {23, 190, 207}};

typedef struct chart_def {
    const char *file, *title, *ylabel, *caption;
    int pairs;     /* 1: one value per pair of frames (x = the pair's middle time) */
} chart_def;

static const chart_def CHARTS[7] = {
    {"seq_rel_rmse.png", "Relative RMSE of luminance after the fit, per frame", "RMSE(a T - R) / mean R", 
     "Per frame: RMSE of luminance after the frame's own best scale over the truth's mean (lower is better).", 0},
    {"seq_ssim.png", "SSIM of luminance after the fit, per frame", "SSIM", "Per frame: SSIM (1 = identical).", 0},
    {"seq_flip.png", "HDR-FLIP mean, per frame", "mean FLIP",
     "Per frame: the mean of HDR-FLIP (exposures from the truth) of a T against R (0 = identical).", 0},
    {"seq_structure.png", "Beam structure score, per frame", "structure score",
     "Per frame: the structure score (band-pass correlation, streak contrast, angular spectrum; 0 = the "
     "truth's structure, docs/metrics.md).", 0},
    {"seq_diff_error.png", "Frame-difference error (truth noise taken out)", "RMS(a dT - dR) / RMS(dR)",
     "Between consecutive frames: how wrong the change is, relative to the truth's change.", 1},
    {"seq_flicker.png", "Flicker ratio", "RMS(a dT) / RMS(dR)",
     "Between consecutive frames: 1 moves as much as the truth, above 1 flickers, below 1 is too static.", 1},
    {"seq_drift.png", "Beam drift between frames", "drift (degrees around the vanishing point)",
     "Between consecutive frames: how far the beams turn around the vanishing point; black dashed: the "
     "truth's, coloured: each technique's.", 1},
};

static double pair_value(const seq_tech *t, int c, int p)
{
    const gr_temporal_pair *q = &t->tp[p];
    if (c == 4) return q->truth_diff_rms > 0 ? q->diff_rmse / q->truth_diff_rms : NAN;
    if (c == 5) return q->truth_diff_rms > 0 ? q->test_diff_rms / q->truth_diff_rms : NAN;
    return t->sum.have_drift ? q->drift_test_deg : NAN;
}

static gr_status draw_charts(const char *dir, const gr_sequence_input *in, seq_tech *ts, int *drawn, char *note,
                             size_t nn, gr_error *err)
{
    const int n = in->n_frames, nt = in->n_techniques;
    double xf[GR_SEQUENCE_MAX_FRAMES], xp[GR_SEQUENCE_MAX_FRAMES], truth_drift[GR_SEQUENCE_MAX_FRAMES];
    double yv[GR_SEQUENCE_MAX_TECHNIQUES][GR_SEQUENCE_MAX_FRAMES];
    for (int i = 0; i < n; i++) xf[i] = in->times[i];
    for (int i = 0; i + 1 < n; i++) xp[i] = 0.5 * (in->times[i] + in->times[i + 1]);
    *drawn = 0;
    for (int c = 0; c < 7; c++) {
        gr_plot_series s[GR_PLOT_MAX_SERIES];
        int ns = 0;
        const int np = CHARTS[c].pairs ? n - 1 : n;
        for (int k = 0; k < nt && ns < GR_PLOT_MAX_SERIES - 1; k++) {
            if (CHARTS[c].pairs && !ts[k].have_temporal) continue;
            for (int i = 0; i < np; i++) yv[k][i] = CHARTS[c].pairs ? pair_value(&ts[k], c, i) : ts[k].series[c][i];
            s[ns++] = (gr_plot_series){.label = in->names[k], .x = CHARTS[c].pairs ? xp : xf, .y = yv[k], .n = np,
                                       .rgb = {COLORS[k % 8][0], COLORS[k % 8][1], COLORS[k % 8][2]},
                                       .style = GR_PLOT_SOLID, .markers = 1};
        }
        if (c == 6) {
            int any = 0;
            for (int k = 0; k < nt && !any; k++)
                if (ts[k].have_temporal && ts[k].sum.have_drift) {
                    for (int i = 0; i + 1 < n; i++) truth_drift[i] = ts[k].tp[i].drift_ref_deg;
                    any = 1;
                }
            if (!any) continue; /* no drift measured: no chart (the page says why) */
            s[ns++] = (gr_plot_series){.label = "ground truth", .x = xp, .y = truth_drift, .n = n - 1,
                                       .rgb = {0, 0, 0}, .style = GR_PLOT_DASHED, .markers = 1};
        }
        if (ns == 0) continue;
        gr_plot_spec spec = {.width = 800, .height = 420, .title = CHARTS[c].title, .xlabel = "water time (s)",
                             .ylabel = CHARTS[c].ylabel, .legend_headroom = 0.25, .series = s, .n_series = ns};
        char path[4300];
        snprintf(path, sizeof path, "%s/%s", dir, CHARTS[c].file);
        gr_status st = gr_plot_write(path, &spec, err);
        if (st == GR_E_RUNTIME) {
            snprintf(note, nn, "charts incomplete (%d drawn): %.300s", *drawn, err->msg);
            return GR_OK;
        }
        if (st != GR_OK) return st;
        (*drawn)++;
    }
    return GR_OK;
}

static void jnum(cJSON *o, const char *k, double v)
{
    if (isfinite(v)) cJSON_AddNumberToObject(o, k, v);
    else cJSON_AddNullToObject(o, k);
}

static cJSON *jarr(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++) cJSON_AddItemToArray(a, isfinite(v[i]) ? cJSON_CreateNumber(v[i]) : cJSON_CreateNull());
    return a;
}

static char *build_json(const gr_sequence_input *in, const seq_tech *ts)
{
    const int n = in->n_frames;
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddNumberToObject(o, "n_frames", n);
    cJSON_AddItemToObject(o, "times_s", jarr(in->times, n));
    if (in->frame_numbers) {
        double f[GR_SEQUENCE_MAX_FRAMES];
        for (int i = 0; i < n; i++) f[i] = (double)in->frame_numbers[i];
        cJSON_AddItemToObject(o, "frames", jarr(f, n));
    }
    cJSON_AddStringToObject(o, "page", "sequence/index.html");
    cJSON *arr = cJSON_AddArrayToObject(o, "techniques");
    for (int k = 0; arr && k < in->n_techniques; k++) {
        const seq_tech *t = &ts[k];
        cJSON *e = cJSON_CreateObject();
        if (!e) break;
        cJSON_AddItemToArray(arr, e);
        cJSON_AddStringToObject(e, "name", in->names[k]);
        jnum(e, "scale", t->a);
        char anim[128];
        snprintf(anim, sizeof anim, "sequence/%s.gif", in->names[k]);
        cJSON_AddStringToObject(e, "animation", anim);
        cJSON *pf = cJSON_AddObjectToObject(e, "per_frame");
        if (pf) {
            cJSON_AddItemToObject(pf, "rel_rmse_y_fit", jarr(t->series[M_REL], n));
            cJSON_AddItemToObject(pf, "ssim_y_fit", jarr(t->series[M_SSIM], n));
            cJSON_AddItemToObject(pf, "flip_hdr_mean", jarr(t->series[M_FLIP], n));
            cJSON_AddItemToObject(pf, "structure_score", jarr(t->series[M_STRUCT], n));
            double fs[GR_SEQUENCE_MAX_FRAMES];
            for (int i = 0; i < n; i++) fs[i] = t->m[i].have_fit ? t->m[i].fit.scale : NAN;
            cJSON_AddItemToObject(pf, "fit_scale", jarr(fs, n));
            if (t->have_temporal) {
                double r[GR_SEQUENCE_MAX_FRAMES];
                for (int i = 0; i < n; i++) r[i] = t->tf[i].rmse_y;
                cJSON_AddItemToObject(pf, "rmse_y_at_scale", jarr(r, n));
            }
        }
        if (t->have_temporal) {
            cJSON *tp = cJSON_AddObjectToObject(e, "pairs");
            double v[7][GR_SEQUENCE_MAX_FRAMES];
            for (int i = 0; i + 1 < n; i++) {
                const gr_temporal_pair *q = &t->tp[i];
                v[0][i] = q->diff_rmse_raw, v[1][i] = q->truth_noise_rms, v[2][i] = q->diff_rmse;
                v[3][i] = q->truth_diff_rms, v[4][i] = q->test_diff_rms;
                v[5][i] = t->sum.have_drift ? q->drift_ref_deg : NAN;
                v[6][i] = t->sum.have_drift ? q->drift_test_deg : NAN;
            }
            static const char *const keys[7] = {"diff_rmse_raw", "truth_noise_rms", "diff_rmse", "truth_diff_rms",
                                                "test_diff_rms", "drift_ref_deg", "drift_test_deg"};
            for (int j = 0; tp && j < 7; j++) cJSON_AddItemToObject(tp, keys[j], jarr(v[j], n - 1));
            cJSON *s = cJSON_AddObjectToObject(e, "temporal");
            if (s) {
                cJSON_AddBoolToObject(s, "have_stderr", t->sum.have_stderr);
                cJSON_AddBoolToObject(s, "have_drift", t->sum.have_drift);
                jnum(s, "frame_rmse_mean", t->sum.frame_rmse_mean);
                jnum(s, "diff_rmse", t->sum.diff_rmse);
                jnum(s, "rel_diff_rmse", t->sum.rel_diff_rmse);
                jnum(s, "flicker_ratio", t->sum.flicker_ratio);
                jnum(s, "drift_err_mean_deg", t->sum.have_drift ? t->sum.drift_err_mean_deg : NAN);
            }
        }
        if (t->note[0]) cJSON_AddStringToObject(e, "note", t->note);
    }
    char *text = cJSON_Print(o);
    cJSON_Delete(o);
    if (!text) return NULL;
    char *copy = malloc(strlen(text) + 1);
    if (copy) strcpy(copy, text);
    cJSON_free(text);
    return copy;
}

static void cell(gr_strbuf *b, double v, int digits)
{
    if (isfinite(v)) gr_sb_printf(b, "<td>%.*g</td>", digits, v);
    else gr_sb_puts(b, "<td>n/a</td>");
}

static void build_html(gr_strbuf *b, const gr_sequence_input *in, const seq_tech *ts, int charts, const char *note)
{
    const int n = in->n_frames, nt = in->n_techniques;
    gr_sb_puts(b, "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>godrays sequence "
                  "report</title>\n<style>body{font-family:DejaVu Sans,Helvetica,Arial,sans-serif;margin:0 auto;"
                  "max-width:1500px;padding:0 18px 40px;color:#1d1f23;background:#fafafa;line-height:1.4}"
                  "h2{border-bottom:1px solid #ccc}.sub{color:#555;font-size:.92em}table{border-collapse:collapse;"
                  "background:#fff;font-size:.88em}td,th{border:1px solid #ddd;padding:3px 8px;text-align:right}"
                  "th{background:#f0f2f5}td.l,th.l{text-align:left}.grid{display:flex;flex-wrap:wrap;gap:14px}"
                  "figure{margin:0;background:#fff;border:1px solid #ddd;border-radius:6px;padding:8px}"
                  "figure img{max-width:100%;height:auto;display:block}figcaption{font-size:.85em;color:#444}"
                  ".warn{background:#fff4e0;border:1px solid #e5b567;padding:8px}</style>\n</head>\n<body>\n");
    gr_sb_puts(b, "<h1>");
    gr_sb_htmlf(b, "God rays over time: %d frames, %d technique%s", n, nt, nt == 1 ? "" : "s");
    gr_sb_puts(b, "</h1>\n");
    gr_sb_puts(b, "<p class=\"sub\">");
    if (in->up_href) {
        gr_sb_puts(b, "<a href=\"");
        gr_sb_html(b, in->up_href);
        gr_sb_puts(b, "\">The run's report (first frame)</a>. ");
    }
    gr_sb_htmlf(b, "Water time %.4g s to %.4g s.", in->times[0], in->times[n - 1]);
    if (in->command_line) {
        gr_sb_puts(b, " Command: <code>");
        gr_sb_html(b, in->command_line);
        gr_sb_puts(b, "</code>");
    }
    gr_sb_puts(b, " Every number: <a href=\"../metrics.json\">metrics.json</a> (\"sequence\"); how to read this "
                  "page: docs/report.md, \"Sequence report\".</p>\n");
    gr_sb_puts(b, "<h2>Over the sequence</h2>\n<table><tr><th class=\"l\">technique</th><th>a (median of the "
                  "frames' fits)</th><th>mean RMSE of Y at a</th><th>frame-difference error / truth's change</th>"
                  "<th>flicker ratio</th><th>mean beam drift error (deg)</th><th>mean HDR-FLIP</th>"
                  "<th>mean structure score</th></tr>\n");
    for (int k = 0; k < nt; k++) {
        const seq_tech *t = &ts[k];
        double fm = 0, sm = 0;
        for (int i = 0; i < n; i++) fm += t->series[M_FLIP][i], sm += t->series[M_STRUCT][i];
        gr_sb_puts(b, "<tr><td class=\"l\"><a href=\"#t-");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, "\">");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, "</a></td>");
        cell(b, t->a, 4);
        cell(b, t->have_temporal ? t->sum.frame_rmse_mean : NAN, 4);
        cell(b, t->have_temporal ? t->sum.rel_diff_rmse : NAN, 4);
        cell(b, t->have_temporal ? t->sum.flicker_ratio : NAN, 4);
        cell(b, t->have_temporal && t->sum.have_drift ? t->sum.drift_err_mean_deg : NAN, 3);
        cell(b, fm / n, 4);
        cell(b, sm / n, 4);
        gr_sb_puts(b, "</tr>\n");
    }
    gr_sb_puts(b, "</table>\n<p class=\"sub\">Between consecutive frames (compare/temporal.h): the error of the "
                  "change a (T<sub>i+1</sub> - T<sub>i</sub>) - (R<sub>i+1</sub> - R<sub>i</sub>) with the truth's "
                  "Monte Carlo noise taken out through its standard errors, over the RMS of the truth's change; "
                  "the flicker ratio (1: moves as much as the truth); how far the beams turn around the vanishing "
                  "point compared with the truth's.</p>\n");
    for (int k = 0; k < nt; k++)
        if (ts[k].note[0]) {
            gr_sb_puts(b, "<p class=\"warn\">");
            gr_sb_html(b, in->names[k]);
            gr_sb_puts(b, ": ");
            gr_sb_html(b, ts[k].note);
            gr_sb_puts(b, "</p>\n");
        }
    if (note && note[0]) {
        gr_sb_puts(b, "<p class=\"warn\">");
        gr_sb_html(b, note);
        gr_sb_puts(b, "</p>\n");
    }
    gr_sb_puts(b, "<h2>Animations</h2>\n<p class=\"sub\">Ground truth | technique x a | signed difference of "
                  "luminance, the same exposure (the first truth's 99th percentile -> 0.8) and difference scale "
                  "in every frame. Animated GIF (256 colours per frame).</p>\n<div class=\"grid\">\n");
    for (int k = 0; k < nt; k++) {
        gr_sb_puts(b, "<figure id=\"t-");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, "\"><img src=\"");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, ".gif\" alt=\"animation of ");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, "\"><figcaption>");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, "</figcaption></figure>\n");
    }
    gr_sb_puts(b, "</div>\n<h2>Metrics over time</h2>\n<div class=\"grid\">\n");
    int shown = 0;
    for (int c = 0; c < 7 && shown < charts; c++) {
        if (c == 6) {
            int any = 0;
            for (int k = 0; k < nt; k++) any |= ts[k].have_temporal && ts[k].sum.have_drift;
            if (!any) continue;
        }
        gr_sb_puts(b, "<figure><img src=\"");
        gr_sb_puts(b, CHARTS[c].file);
        gr_sb_puts(b, "\" alt=\"");
        gr_sb_html(b, CHARTS[c].title);
        gr_sb_puts(b, "\"><figcaption>");
        gr_sb_html(b, CHARTS[c].caption);
        gr_sb_puts(b, "</figcaption></figure>\n");
        shown++;
    }
    gr_sb_puts(b, "</div>\n<h2>Per frame</h2>\n<table><tr><th>frame</th><th>t (s)</th>");
    for (int k = 0; k < nt; k++) {
        gr_sb_puts(b, "<th>");
        gr_sb_html(b, in->names[k]);
        gr_sb_puts(b, ": rel. RMSE fit / HDR-FLIP / structure</th>");
    }
    gr_sb_puts(b, "</tr>\n");
    for (int i = 0; i < n; i++) {
        if (in->frame_numbers) gr_sb_printf(b, "<tr><td>%ld</td>", in->frame_numbers[i]);
        else gr_sb_printf(b, "<tr><td>%d</td>", i);
        gr_sb_printf(b, "<td>%.4g</td>", in->times[i]);
        for (int k = 0; k < nt; k++)
            gr_sb_printf(b, "<td>%.4g / %.4g / %.4g</td>", ts[k].series[M_REL][i], ts[k].series[M_FLIP][i],
                         ts[k].series[M_STRUCT][i]);
        gr_sb_puts(b, "</tr>\n");
    }
    gr_sb_puts(b, "</table>\n</body>\n</html>\n");
}

gr_status gr_sequence_write(const char *dir, const gr_sequence_input *in, char **json, gr_sequence_result *res,
                            gr_error *err)
{
    const double t0 = now_s();
    if (json) *json = NULL;
    gr_status st = check_input(in, err);
    if (st != GR_OK) return st;
    const int n = in->n_frames, nt = in->n_techniques;
    const int w = in->refs[0]->width, h = in->refs[0]->height;
    seq_tech *ts = calloc((size_t)nt, sizeof *ts);
    float *angles = malloc((size_t)w * (size_t)h * sizeof *angles);
    gr_strbuf html;
    gr_sb_init(&html);
    char note[512] = "", path[4300];
    int charts = 0, anims = 0;
    /* each frame's truth half of FLIP, kept for the techniques after the first while the frames'
     * halves hold at most GR_SEQUENCE_FLIP_KEEP_MAX together (compare/flip.h: the same numbers) */
    gr_flip_reference *fref[GR_SEQUENCE_MAX_FRAMES] = {NULL};
    size_t fref_bytes = 0;
    if (!ts || !angles) {
        st = gr_fail(err, GR_E_NOMEM, "sequence: out of memory");
        goto done;
    }
    if ((st = gr_report_make_dir(dir, err)) != GR_OK) goto done;
    /* The beams' geometry (the camera and the sun do not move with the water): the vanishing
     * point of the refracted sun's rays and the angle to the sun, which the structure metrics'
     * de-glow divides out (as godrays compare --scene does). */
    gr_structure_options so = {0};
    int have_vp = gr_structure_scene_vp(in->scenes[0], w, h, &so.vp_x, &so.vp_y, err) == GR_OK;
    if (have_vp) {
        double dir3[3];
        gr_profile_sun_view_dir(in->scenes[0], dir3);
        gr_profile_angles(&in->scenes[0]->camera, dir3, angles);
        so.radial = angles;
        so.radial_bin = in->scenes[0]->camera.fov_deg / h;
    } else {
        snprintf(note, sizeof note, "no structure metrics or beam drift: %.400s", err->msg);
        *err = (gr_error){GR_OK, ""};
    }
    gr_flip_options fo = {.mode = GR_FLIP_HDR};
    for (int k = 0; k < nt; k++) {
        seq_tech *t = &ts[k];
        t->m = calloc((size_t)n, sizeof *t->m);
        t->tf = calloc((size_t)n, sizeof *t->tf);
        t->tp = calloc((size_t)n, sizeof *t->tp);
        if (!t->m || !t->tf || !t->tp) {
            st = gr_fail(err, GR_E_NOMEM, "sequence: out of memory");
            goto done;
        }
        double fits[GR_SEQUENCE_MAX_FRAMES];
        int nf = 0;
        for (int i = 0; i < n; i++) {
            gr_metrics_options mo = {.fit_scale = 1, .skip_blur = 1, .flip = &fo, .structure = have_vp ? &so : NULL};
            if (nt > 1 && (fref[i] || fref_bytes < GR_SEQUENCE_FLIP_KEEP_MAX)) mo.flip_ref = &fref[i];
            const int made = mo.flip_ref && !fref[i];
            if ((st = gr_metrics_compute(in->refs[i], in->tests[k * n + i], &mo, &t->m[i], err)) != GR_OK) {
                gr_error_prefix(err, "sequence: %s, frame %d", in->names[k], i);
                goto done;
            }
            if (made) fref_bytes += gr_flip_reference_bytes(fref[i]);
            const gr_metrics_set *f = t->m[i].have_fit ? &t->m[i].fit : &t->m[i].raw;
            const gr_channel_metrics *y = &f->ch[GR_MCH_Y];
            t->series[M_REL][i] = y->ref_mean != 0 ? y->rmse / fabs(y->ref_mean) : NAN;
            t->series[M_SSIM][i] = f->ssim_y;
            t->series[M_FLIP][i] = f->have_flip ? f->flip.mean : NAN;
            t->series[M_STRUCT][i] = f->have_structure ? f->structure_score : NAN;
            if (t->m[i].have_fit && t->m[i].fit_defined) fits[nf++] = t->m[i].fit.scale;
        }
        /* One a for the whole sequence: a per-frame a would hide flicker in the intensity. */
        t->a = median(fits, nf);
        const gr_image *tests[GR_SEQUENCE_MAX_FRAMES];
        for (int i = 0; i < n; i++) tests[i] = in->tests[k * n + i];
        gr_temporal_options to = {.scale = t->a, .structure = so, .skip_drift = !have_vp};
        gr_error terr = {GR_OK, ""};
        gr_status ts_st = gr_temporal_compute(in->refs, tests, n, &to, t->tf, t->tp, &t->sum, &terr);
        if (ts_st == GR_E_INPUT && have_vp) { /* e.g. the ring around the vanishing point misses the image */
            snprintf(t->note, sizeof t->note, "no beam drift: %.200s", terr.msg);
            to.skip_drift = 1;
            terr = (gr_error){GR_OK, ""};
            ts_st = gr_temporal_compute(in->refs, tests, n, &to, t->tf, t->tp, &t->sum, &terr);
        }
        if (ts_st == GR_E_NOMEM) {
            st = gr_fail(err, GR_E_NOMEM, "sequence: %s: %s", in->names[k], terr.msg);
            goto done;
        }
        if (ts_st != GR_OK) snprintf(t->note, sizeof t->note, "no temporal metrics: %.200s", terr.msg);
        t->have_temporal = ts_st == GR_OK;
        if (res) {
            res->scale[k] = t->a;
            res->flicker_ratio[k] = t->have_temporal ? t->sum.flicker_ratio : NAN;
            res->rel_diff_rmse[k] = t->have_temporal ? t->sum.rel_diff_rmse : NAN;
            res->drift_err_deg[k] = t->have_temporal && t->sum.have_drift ? t->sum.drift_err_mean_deg : NAN;
        }
    }
    /* Files: animations and charts, then the page that shows them. */
    const double exposure = gr_report_exposure(in->refs[0], 1.0, 0.99, 0.8);
    for (int k = 0; k < nt; k++) {
        if ((st = write_gif(dir, in, k, ts[k].a, exposure, err)) != GR_OK) goto done;
        anims++;
    }
    if ((st = draw_charts(dir, in, ts, &charts, note[0] ? note + strlen(note) : note,
                          sizeof note - strlen(note), err)) != GR_OK)
        goto done;
    build_html(&html, in, ts, charts, note);
    if ((st = gr_sb_status(&html, "the sequence page", err)) != GR_OK) goto done;
    snprintf(path, sizeof path, "%s/index.html", dir);
    if ((st = gr_outfile_write(path, gr_sb_str(&html), -1, err)) != GR_OK) goto done;
    if (json) {
        *json = build_json(in, ts);
        if (!*json) {
            st = gr_fail(err, GR_E_NOMEM, "sequence: out of memory for its JSON");
            goto done;
        }
    }
    if (res) {
        res->charts = charts;
        res->animations = anims;
        res->seconds = now_s() - t0;
    }
done:
    for (int k = 0; ts && k < nt; k++) {
        free(ts[k].m);
        free(ts[k].tf);
        free(ts[k].tp);
    }
    free(ts);
    free(angles);
    for (int i = 0; i < GR_SEQUENCE_MAX_FRAMES; i++) gr_flip_reference_destroy(fref[i]);
    gr_sb_free(&html);
    return st;
}
