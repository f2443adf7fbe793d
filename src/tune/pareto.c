/* Pareto fronts and the speed/error outputs (pareto.h). */
#include "tune/pareto.h"
#include "common/outfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "report/plot.h"

void gr_pareto_front(int n, const double *cost, const double *err, int *on_front)
{
    for (int i = 0; i < n; i++) {
        on_front[i] = isfinite(cost[i]) && isfinite(err[i]);
        for (int j = 0; j < n && on_front[i]; j++) {
            if (j == i || !isfinite(cost[j]) || !isfinite(err[j])) continue;
            if (cost[j] <= cost[i] && err[j] <= err[i] && (cost[j] < cost[i] || err[j] < err[i])) on_front[i] = 0;
        }
    }
}

void gr_pareto_mark_fronts(gr_pareto_point *pts, int n)
{
    double *c = malloc((size_t)(n > 0 ? n : 1) * sizeof *c), *e = malloc((size_t)(n > 0 ? n : 1) * sizeof *e);
    int *f = malloc((size_t)(n > 0 ? n : 1) * sizeof *f), *idx = malloc((size_t)(n > 0 ? n : 1) * sizeof *idx);
    if (!c || !e || !f || !idx) {
        for (int i = 0; i < n; i++) pts[i].on_front = 0;
    } else {
        /* every family present (the ground truth = 0, technique k = 1 + k) */
        int max_fam = -1;
        for (int i = 0; i < n; i++)
            if (pts[i].family > max_fam) max_fam = pts[i].family;
        for (int i = 0; i < n; i++) pts[i].on_front = 0;
        for (int fam = 0; fam <= max_fam; fam++) {
            int m = 0;
            for (int i = 0; i < n; i++)
                if (pts[i].family == fam) {
                    c[m] = pts[i].cost_s;
                    e[m] = pts[i].error;
                    idx[m++] = i;
                }
            gr_pareto_front(m, c, e, f);
            for (int k = 0; k < m; k++) pts[idx[k]].on_front = f[k];
        }
    }
    free(c);
    free(e);
    free(f);
    free(idx);
}

gr_status gr_pareto_write_csv(const char *path, const gr_pareto_point *pts, int n, gr_error *err)
{
    gr_outfile of;
    gr_status st = gr_outfile_open(&of, path, err);
    if (st != GR_OK) return st;
    FILE *f = of.f;
    fprintf(f, "family,label,settings,time_s,gpu_s,cost_s,error,on_front\n");
    for (int i = 0; i < n; i++)
        fprintf(f, "%s,%s,%s,%.6g,%.6g,%.6g,%.6g,%d\n",
                pts[i].family_name[0] ? pts[i].family_name : pts[i].family == GR_PARETO_REFERENCE ? "reference" : "?",
                pts[i].label, pts[i].settings, pts[i].time_s, pts[i].gpu_s, pts[i].cost_s, pts[i].error,
                pts[i].on_front);
    return gr_outfile_commit(&of, 0, err);
}

/* The points of one family as isolated markers (a NaN between points breaks the line, per
 * gr_plot_series), and its front sorted by time as a line. */
static int family_series(const gr_pareto_point *pts, int n, int fam, double *px, double *py, double *fx, double *fy,
                         int *nf)
{
    int m = 0;
    *nf = 0;
    for (int i = 0; i < n; i++) {
        if (pts[i].family != fam) continue;
        px[m] = pts[i].cost_s;
        py[m++] = pts[i].error;
        px[m] = NAN;
        py[m++] = NAN;
        if (pts[i].on_front) {
            int k = (*nf)++;
            while (k > 0 && fx[k - 1] > pts[i].cost_s) {
                fx[k] = fx[k - 1];
                fy[k] = fy[k - 1];
                k--;
            }
            fx[k] = pts[i].cost_s;
            fy[k] = pts[i].error;
        }
    }
    return m;
}

/* Colours per family: red for the ground truth, then the techniques (Tableau 10). */
static const unsigned char palette[10][3] = {{214, 39, 40},  {31, 119, 180}, {44, 160, 44},   {255, 127, 14},
                                             {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127},
                                             {188, 189, 34},  {23, 190, 207}};

gr_status gr_pareto_write_plot(const char *path, const gr_pareto_point *pts, int n, const char *title,
                               const char *time_label, int *drawn, gr_error *err)
{
    *drawn = 0;
    if (!gr_plot_available()) return GR_OK;
    int fams[GR_PARETO_MAX_FAMILIES], nfam = 0;
    for (int i = 0; i < n; i++) {
        int k = 0;
        while (k < nfam && fams[k] != pts[i].family) k++;
        if (k == nfam && nfam < GR_PARETO_MAX_FAMILIES) fams[nfam++] = pts[i].family;
    }
    size_t cap = (size_t)(2 * n + 2);
    double *buf = malloc(cap * 4 * (size_t)(nfam ? nfam : 1) * sizeof *buf);
    gr_plot_series *s = calloc((size_t)(2 * nfam + 1), sizeof *s);
    char (*labels)[160] = calloc((size_t)(nfam ? nfam : 1), sizeof *labels);
    if (!buf || !s || !labels) {
        free(buf);
        free(s);
        free(labels);
        return gr_fail(err, GR_E_NOMEM, "pareto plot: out of memory");
    }
    int ns = 0;
    for (int k = 0; k < nfam; k++) {
        double *x = buf + cap * 4 * (size_t)k, *y = x + cap, *fx = y + cap, *fy = fx + cap;
        int nf = 0, m = family_series(pts, n, fams[k], x, y, fx, fy, &nf);
        const char *name = "";
        int slot = fams[k] == GR_PARETO_REFERENCE ? 0 : 1 + (fams[k] - 1) % 9, light = 0;
        for (int i = 0; i < n; i++)
            if (pts[i].family == fams[k]) {
                name = pts[i].family_name;
                if (pts[i].colour > 0) slot = 1 + (pts[i].colour - 1) % 9;
                light = pts[i].light;
            }
        if (fams[k] == GR_PARETO_REFERENCE)
            snprintf(labels[k], sizeof labels[k], "ground truth at lower quality");
        else if (time_label && !time_label[0])
            snprintf(labels[k], sizeof labels[k], "%s", name);
        else
            snprintf(labels[k], sizeof labels[k], "%s (%s)", name, time_label ? time_label : "wall time");
        unsigned char rgb[3];
        for (int c = 0; c < 3; c++) /* the lighter shade: halfway to white */
            rgb[c] = (unsigned char)(light ? (palette[slot][c] + 255 + 1) / 2 : palette[slot][c]);
        gr_plot_series a = {.label = labels[k], .x = x, .y = y, .n = m, .rgb = {rgb[0], rgb[1], rgb[2]}, .markers = 1};
        gr_plot_series b = {.label = k == nfam - 1 ? "Pareto fronts (dashed)" : "", .x = fx, .y = fy, .n = nf,
                            .rgb = {rgb[0], rgb[1], rgb[2]}, .style = GR_PLOT_DASHED};
        s[ns++] = a;
        s[ns++] = b;
    }
    gr_plot_spec spec = {.width = 1240, .height = 600, .title = title, .xlabel = "time per frame (s)",
                         .ylabel = "verdict vs HQ ground truth", .log_x = 1, .log_y = 1,
                         .series = s, .n_series = ns, .legend_outside = 0.29};
    gr_status st = gr_plot_write(path, &spec, err);
    free(buf);
    free(s);
    free(labels);
    if (st == GR_OK) *drawn = 1;
    return st;
}
