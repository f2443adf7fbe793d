/* Charts through PLplot's memory device (see plot.h for the method). */
#include "report/plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/oiio.h"

#ifdef GR_HAVE_PLPLOT
#include <plplot.h>
#endif

#define SS 2 /* supersampling factor */

int gr_plot_available(void)
{
#ifdef GR_HAVE_PLPLOT
    return 1;
#else
    return 0;
#endif
}

/* A usable point of series s (finite, positive on log axes), mapped to world coordinates. */
static int world_point(const gr_plot_spec *spec, const gr_plot_series *s, int i, double *wx, double *wy)
{
    double x = s->x[i], y = s->y[i];
    if (!isfinite(x) || !isfinite(y)) return 0;
    if (spec->log_x) {
        if (!(x > 0.0)) return 0;
        x = log10(x);
    }
    if (spec->log_y) {
        if (!(y > 0.0)) return 0;
        y = log10(y);
    }
    *wx = x;
    *wy = y;
    return 1;
}

/* World range of one axis: explicit (converted to log10 on log axes) or from the data. */
static void axis_range(const gr_plot_spec *spec, int axis, double *lo, double *hi)
{
    if (axis == 0 && spec->n_categories > 0) {
        *lo = -0.3;
        *hi = spec->n_categories - 1 + 0.3;
        return;
    }
    const int logax = axis ? spec->log_y : spec->log_x;
    const double a = axis ? spec->ymin : spec->xmin, b = axis ? spec->ymax : spec->xmax;
    if (a != b) {
        *lo = logax ? log10(a) : a;
        *hi = logax ? log10(b) : b;
        return;
    }
    double mn = INFINITY, mx = -INFINITY;
    for (int k = 0; k < spec->n_series; k++) {
        const gr_plot_series *s = &spec->series[k];
        for (int i = 0; i < s->n; i++) {
            double wx, wy;
            if (!world_point(spec, s, i, &wx, &wy)) continue;
            const double v = axis ? wy : wx;
            mn = fmin(mn, v);
            mx = fmax(mx, v);
        }
    }
    if (!(mn <= mx)) { /* no data: a unit range */
        mn = 0.0;
        mx = 1.0;
    }
    const double head = axis && spec->legend_headroom > 0.0 && isfinite(spec->legend_headroom)
                            ? spec->legend_headroom : 0.0;
    if (logax) {
        *lo = floor(mn);
        *hi = ceil(mx + head * (mx - mn > 1.0 ? mx - mn : 1.0));
        if (*hi <= *lo) *hi = *lo + 1.0;
    } else {
        double span = mx - mn;
        if (span <= 0.0) span = fabs(mx) > 0.0 ? fabs(mx) : 1.0;
        *lo = mn - 0.04 * span;
        *hi = mx + (0.04 + head) * span;
    }
}

static gr_status check_spec(const gr_plot_spec *spec, int *w, int *h, gr_error *err)
{
    if (!spec) return gr_fail(err, GR_E_INPUT, "plot: no chart description");
    *w = spec->width ? spec->width : 800;
    *h = spec->height ? spec->height : 450;
    if (*w < 64 || *h < 64 || *w > 4096 || *h > 4096)
        return gr_fail(err, GR_E_INPUT, "plot '%s': size %d x %d outside 64..4096", spec->title ? spec->title : "",
                       *w, *h);
    if (spec->n_series < 0 || spec->n_series > GR_PLOT_MAX_SERIES || (spec->n_series > 0 && !spec->series))
        return gr_fail(err, GR_E_INPUT, "plot '%s': %d series (at most %d)", spec->title ? spec->title : "",
                       spec->n_series, GR_PLOT_MAX_SERIES);
    for (int k = 0; k < spec->n_series; k++) {
        const gr_plot_series *s = &spec->series[k];
        if (s->n < 0 || (s->n > 0 && (!s->x || !s->y)))
            return gr_fail(err, GR_E_INPUT, "plot '%s': series %d ('%s') has %d points and %s",
                           spec->title ? spec->title : "", k, s->label ? s->label : "", s->n,
                           s->n < 0 ? "a negative count" : "no data array");
        if (s->style < GR_PLOT_SOLID || s->style > GR_PLOT_LONG_DASHED)
            return gr_fail(err, GR_E_INPUT, "plot '%s': series %d: unknown line style %d",
                           spec->title ? spec->title : "", k, (int)s->style);
    }
    if (!(spec->legend_outside >= 0.0 && spec->legend_outside <= 0.6))
        return gr_fail(err, GR_E_INPUT, "plot '%s': legend_outside %g outside [0, 0.6]", spec->title ? spec->title : "",
                       spec->legend_outside);
    if (spec->n_categories < 0 || spec->n_categories > 32 || (spec->n_categories > 0 && (!spec->x_categories || spec->log_x)))
        return gr_fail(err, GR_E_INPUT, "plot '%s': %d x categories (at most 32, with labels, linear axis)",
                       spec->title ? spec->title : "", spec->n_categories);
    const double r[2][2] = {{spec->xmin, spec->xmax}, {spec->ymin, spec->ymax}};
    const int lg[2] = {spec->log_x, spec->log_y};
    for (int a = 0; a < 2; a++) {
        if (r[a][0] == r[a][1]) continue;
        if (!isfinite(r[a][0]) || !isfinite(r[a][1]) || (lg[a] && !(r[a][0] > 0.0 && r[a][1] > 0.0)))
            return gr_fail(err, GR_E_INPUT, "plot '%s': %s range [%g, %g] is not %s",
                           spec->title ? spec->title : "", a ? "y" : "x", r[a][0], r[a][1],
                           lg[a] ? "positive (log axis)" : "finite");
    }
    return GR_OK;
}

#ifdef GR_HAVE_PLPLOT
/* PLplot treats '#' as its escape character: a literal one is written "##". */
static void plot_text(const char *s, char *buf, size_t n)
{
    size_t j = 0;
    for (const char *p = s ? s : ""; *p && j + 2 < n; p++) {
        if (*p == '#') buf[j++] = '#';
        buf[j++] = *p;
    }
    buf[j] = '\0';
}

static char g_abort_msg[256];
static void on_plabort(const char *msg)
{
    /* PLplot's non-fatal errors land here instead of on stderr; the caller reports them. */
    snprintf(g_abort_msg, sizeof g_abort_msg, "%s", msg ? msg : "");
}

enum { PART_CONTENT = 0, PART_LEGEND = 1 };

/* plslabelfunc callback: category labels at integer x, nothing elsewhere; y as PLplot would. */
static void category_label(PLINT axis, PLFLT value, char *label, PLINT length, PLPointer data)
{
    const gr_plot_spec *spec = data;
    label[0] = '\0';
    if (axis != PL_X_AXIS) {
        snprintf(label, (size_t)length, "%g", value);
        return;
    }
    const double r = floor(value + 0.5);
    if (fabs(value - r) > 1e-6 || r < 0 || r >= spec->n_categories) return;
    plot_text(spec->x_categories[(int)r], label, (size_t)length);
}

/* One PLplot session on the shared buffer, shifted by (dx, dy) device pixels. */
static void draw_session(const gr_plot_spec *spec, unsigned char *buf, int W, int H, int dx, int dy, int part)
{
    PLINT prev = 0, strm = 0;
    plgstrm(&prev);
    plmkstrm(&strm);
    plsdev("mem");
    plsmem(W, H, buf);
    plscmap0n(3 + GR_PLOT_MAX_SERIES); /* background, axes, grid, one per series */
    plscol0(0, 255, 255, 255); /* background */
    plscol0(1, 0, 0, 0);       /* axes and text */
    plscol0(2, 210, 210, 210); /* grid */
    for (int k = 0; k < spec->n_series && k < GR_PLOT_MAX_SERIES; k++)
        plscol0(3 + k, spec->series[k].rgb[0], spec->series[k].rgb[1], spec->series[k].rgb[2]);
    plinit();
    pladv(0);
    plschr(0.0, 1.0);
    const double ox = (double)dx / W, oy = -(double)dy / H;
    if (part == PART_LEGEND && spec->legend_outside > 0.0) /* the margin right of the plot area */
        plvpor(GR_PLOT_VP_X1 - spec->legend_outside + 0.035 + ox, 0.995 + ox, GR_PLOT_VP_Y0 + oy, GR_PLOT_VP_Y1 + oy);
    else
        plvpor(GR_PLOT_VP_X0 + ox, GR_PLOT_VP_X1 - spec->legend_outside + ox, GR_PLOT_VP_Y0 + oy, GR_PLOT_VP_Y1 + oy);
    double x0, x1, y0, y1;
    axis_range(spec, 0, &x0, &x1);
    axis_range(spec, 1, &y0, &y1);
    plwind(x0, x1, y0, y1);
    char xo[16], yo[16];
    if (part == PART_CONTENT) {
        plcol0(2);
        snprintf(xo, sizeof xo, "g%s", spec->log_x ? "l" : "");
        snprintf(yo, sizeof yo, "g%s", spec->log_y ? "l" : "");
        plbox(xo, spec->n_categories > 0 ? 1.0 : 0.0, 0, yo, 0.0, 0);
        for (int k = 0; k < spec->n_series; k++) {
            const gr_plot_series *s = &spec->series[k];
            plcol0(3 + k);
            pllsty(s->style == GR_PLOT_DASHED ? 2 : s->style == GR_PLOT_LONG_DASHED ? 3 : 1);
            double seg_x[2], seg_y[2];
            int have_prev = 0;
            for (int i = 0; i < s->n; i++) {
                double wx, wy;
                if (!world_point(spec, s, i, &wx, &wy)) {
                    have_prev = 0;
                    continue;
                }
                if (have_prev) {
                    seg_x[1] = wx;
                    seg_y[1] = wy;
                    plline(2, seg_x, seg_y);
                }
                if (s->markers) plpoin(1, &wx, &wy, 4);
                seg_x[0] = wx;
                seg_y[0] = wy;
                have_prev = 1;
            }
            pllsty(1);
        }
        plcol0(1);
        if (spec->n_categories > 0) {
            /* custom labels at every integer, major ticks there, no minor ticks */
            plslabelfunc(category_label, (PLPointer)spec);
            plbox("bcnto", 1.0, 1, "", 0.0, 0);
            plslabelfunc(NULL, NULL);
            snprintf(yo, sizeof yo, "bcnstv%s", spec->log_y ? "l" : "");
            plbox("", 0.0, 0, yo, 0.0, 0);
        }
        snprintf(xo, sizeof xo, "bcnst%s", spec->log_x ? "l" : "");
        snprintf(yo, sizeof yo, "bcnstv%s", spec->log_y ? "l" : "");
        if (spec->n_categories == 0) plbox(xo, 0.0, 0, yo, 0.0, 0);
        char t[3][512];
        plot_text(spec->xlabel, t[0], sizeof t[0]);
        plot_text(spec->ylabel, t[1], sizeof t[1]);
        plot_text(spec->title, t[2], sizeof t[2]);
        /* a title wider than the plot area goes on up to three lines across the whole chart,
         * broken at spaces, at 0.85 of the size (PLplot's characters here: at most 0.0125 of the
         * chart's width wide at size 1, measured at 600 and 1240 pixels) */
        const double vx0 = GR_PLOT_VP_X0, vx1 = GR_PLOT_VP_X1 - spec->legend_outside;
        const int cw = spec->width ? spec->width : 800;
        const double chw = 0.0125 * cw;
        if (strlen(t[2]) * chw <= (vx1 - vx0) * cw) {
            pllab(t[0], t[1], t[2]);
        } else {
            pllab(t[0], t[1], "");
            const size_t fit = (size_t)(0.97 * cw / (0.85 * chw));
            char lines[3][512];
            int nl = 0;
            const char *c = t[2];
            while (*c && nl < 3) {
                size_t len = strlen(c), take = len;
                int dots = 0;
                if (len > fit && nl < 2) {
                    take = fit;
                    while (take > 0 && c[take] != ' ') take--;
                    if (take == 0) take = fit;
                } else if (len > fit) { /* the third line: cut, with an ellipsis */
                    take = fit > 3 ? fit - 3 : fit;
                    dots = 1;
                }
                if (take >= sizeof lines[0] - 4) take = sizeof lines[0] - 4;
                memcpy(lines[nl], c, take);
                memcpy(lines[nl] + take, "...", dots ? 4 : 1);
                lines[nl++][take + (dots ? 3 : 0)] = '\0';
                c += take;
                while (*c == ' ') c++;
            }
            plschr(0.0, 0.85);
            const double mid = (0.5 - vx0) / (vx1 - vx0); /* the chart's centre in viewport units */
            for (int i = 0; i < nl; i++) plmtex("t", 1.0 + 1.6 * (nl - 1 - i), mid, 0.5, lines[i]);
            plschr(0.0, 1.0);
        }
    } else {
        PLINT opt[GR_PLOT_MAX_SERIES], tcol[GR_PLOT_MAX_SERIES], lcol[GR_PLOT_MAX_SERIES], lsty[GR_PLOT_MAX_SERIES];
        PLFLT lwid[GR_PLOT_MAX_SERIES];
        char texts[GR_PLOT_MAX_SERIES][256];
        const char *tp[GR_PLOT_MAX_SERIES];
        int n = 0;
        for (int k = 0; k < spec->n_series; k++) {
            const gr_plot_series *s = &spec->series[k];
            if (!s->label || !s->label[0]) continue;
            opt[n] = PL_LEGEND_LINE;
            tcol[n] = 1;
            lcol[n] = 3 + k;
            lsty[n] = s->style == GR_PLOT_DASHED ? 2 : s->style == GR_PLOT_LONG_DASHED ? 3 : 1;
            lwid[n] = 1.0;
            plot_text(s->label, texts[n], sizeof texts[n]);
            tp[n] = texts[n];
            n++;
        }
        if (n > 0) {
            PLFLT lw = 0, lh = 0;
            /* outside: the top left of its own viewport (the margin), a smaller text */
            const int out = spec->legend_outside > 0.0;
            pllegend(&lw, &lh, PL_LEGEND_BOUNDING_BOX,
                     PL_POSITION_TOP | PL_POSITION_INSIDE | (out ? PL_POSITION_LEFT : PL_POSITION_RIGHT), out ? 0.0 : 0.02,
                     out ? 0.0 : 0.03, 0.08, 0, 1, 1, 0, 0, n, opt, 0.8, out ? 0.72 : 0.8, 2.0, 0.0, tcol, tp, NULL, NULL,
                     NULL, NULL, lcol, lsty, lwid, NULL, NULL, NULL, NULL);
        }
    }
    plend1();
    plsstrm(prev);
}
#endif

gr_status gr_plot_render(const gr_plot_spec *spec, gr_image **out, gr_error *err)
{
    *out = NULL;
    int w = 0, h = 0;
    gr_status st = check_spec(spec, &w, &h, err);
    if (st != GR_OK) return st;
#ifndef GR_HAVE_PLPLOT
    return gr_fail(err, GR_E_RUNTIME, "plot '%s': this build has no PLplot (libplplot-dev not found)",
                   spec->title ? spec->title : "");
#else
    const int W = SS * w, H = SS * h;
    unsigned char *buf = malloc((size_t)W * (size_t)H * 3);
    gr_image *img = gr_image_create(w, h, 3, NULL);
    if (!buf || !img) { /* (the legend buffer below is optional: without it, no legend) */
        free(buf);
        gr_image_destroy(img);
        return gr_fail(err, GR_E_NOMEM, "plot '%s': out of memory for %d x %d", spec->title ? spec->title : "", W, H);
    }
    memset(buf, 255, (size_t)W * (size_t)H * 3); /* the mem device draws over what is there */
    g_abort_msg[0] = '\0';
    plsabort(on_plabort);
    /* Four passes shifted by one device pixel make every stroke two device pixels wide. */
    for (int k = 0; k < 4; k++) draw_session(spec, buf, W, H, k & 1, k >> 1, PART_CONTENT);
    /* The legend on a white buffer of its own; the bounding box of what it drew (its frame
     * included) is pasted over the chart, which makes it opaque without a PLplot fill. */
    unsigned char *leg = malloc((size_t)W * (size_t)H * 3);
    if (leg) {
        memset(leg, 255, (size_t)W * (size_t)H * 3);
        for (int k = 0; k < 4; k++) draw_session(spec, leg, W, H, k & 1, k >> 1, PART_LEGEND);
        int x0 = W, x1 = -1, y0 = H, y1 = -1;
        /* outside: only the margin right of the plot area (a legend wider than the margin is
         * cut at the chart's edge; what the memory device wraps past it is not pasted) */
        const int xs = spec->legend_outside > 0.0 ? (int)((GR_PLOT_VP_X1 - spec->legend_outside + 0.02) * W) : 0;
        for (int y = 0; y < H; y++)
            for (int x = xs; x < W; x++) {
                const unsigned char *q = leg + ((size_t)y * (size_t)W + (size_t)x) * 3;
                if (q[0] == 255 && q[1] == 255 && q[2] == 255) continue;
                if (x < x0) x0 = x;
                if (x > x1) x1 = x;
                if (y < y0) y0 = y;
                if (y > y1) y1 = y;
            }
        for (int y = y0; y <= y1; y++)
            memcpy(buf + ((size_t)y * (size_t)W + (size_t)x0) * 3, leg + ((size_t)y * (size_t)W + (size_t)x0) * 3,
                   (size_t)(x1 - x0 + 1) * 3);
        free(leg);
    }
    plsabort(NULL);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                unsigned s = 0;
                for (int j = 0; j < SS; j++)
                    for (int i = 0; i < SS; i++)
                        s += buf[(((size_t)(y * SS + j) * (size_t)W) + (size_t)(x * SS + i)) * 3 + (size_t)c];
                gr_image_pixel(img, x, y)[c] = (float)s / (255.0f * SS * SS);
            }
    free(buf);
    if (g_abort_msg[0]) {
        gr_image_destroy(img);
        return gr_fail(err, GR_E_RUNTIME, "plot '%s': PLplot: %s", spec->title ? spec->title : "", g_abort_msg);
    }
    *out = img;
    return GR_OK;
#endif
}

gr_status gr_plot_write(const char *path, const gr_plot_spec *spec, gr_error *err)
{
    gr_image *img = NULL;
    gr_status st = gr_plot_render(spec, &img, err);
    if (st == GR_OK) st = gr_oiio_write(path, img, err);
    gr_image_destroy(img);
    return st;
}
