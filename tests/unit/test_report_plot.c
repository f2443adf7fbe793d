/* report/plot: PLplot charts drawn through the memory device.
 * Oracle: the viewport fractions GR_PLOT_VP_* and the axis ranges fix where a data point must
 * land (x_pixel = (VP_X0 + (x - xmin) / (xmax - xmin) (VP_X1 - VP_X0)) W, rows from the top
 * = (1 - VP_Y0 - (y - ymin) / (ymax - ymin) (VP_Y1 - VP_Y0)) H, log10 on log axes); the
 * test finds the pixels of each series' colour and checks their position, extent and the gap a
 * non-finite point leaves. Also: bad descriptions are rejected, files are written atomically. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "image/oiio.h"
#include "report/plot.h"

/* How much of colour c is blended over the white background at (x, y): t in p = (1 - t) white
 * + t c, by least squares, or 0 when the pixel is not such a blend (antialiased strokes are
 * partial blends, so a line can spread over two rows at reduced strength). */
static double coverage(const gr_image *img, int x, int y, const float c[3])
{
    const float *p = img->pixels + ((size_t)y * (size_t)img->width + (size_t)x) * 3;
    double num = 0, den = 0;
    for (int k = 0; k < 3; k++) {
        num += (1.0 - p[k]) * (1.0 - c[k]);
        den += (1.0 - c[k]) * (1.0 - c[k]);
    }
    const double t = den > 0 ? num / den : 0;
    double res = 0;
    for (int k = 0; k < 3; k++) {
        const double d = p[k] - ((1 - t) + t * c[k]);
        res += d * d;
    }
    return t > 0.25 && sqrt(res) < 0.15 ? t : 0.0;
}

static int is_col(const gr_image *img, int x, int y, const float c[3])
{
    return coverage(img, x, y, c) > 0.0;
}

/* Mean row, min/max column of the pixels of colour c (count in *n). */
static void find(const gr_image *img, const float c[3], double *row, double *col, int *xmin, int *xmax, int *ymin,
                 int *ymax, long *n)
{
    double sr = 0, sc = 0, wsum = 0;
    *n = 0;
    *xmin = *ymin = 1 << 30;
    *xmax = *ymax = -1;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++)
            if (is_col(img, x, y, c)) {
                const double w = coverage(img, x, y, c);
                sr += w * (y + 0.5);
                sc += w * (x + 0.5);
                wsum += w;
                (*n)++;
                if (x < *xmin) *xmin = x;
                if (x > *xmax) *xmax = x;
                if (y < *ymin) *ymin = y;
                if (y > *ymax) *ymax = y;
            }
    *row = *n ? sr / wsum : -1;
    *col = *n ? sc / wsum : -1;
}

static double px_x(double x, double x0, double x1, int W)
{
    return (GR_PLOT_VP_X0 + (x - x0) / (x1 - x0) * (GR_PLOT_VP_X1 - GR_PLOT_VP_X0)) * W;
}
static double px_y(double y, double y0, double y1, int H)
{
    return (1.0 - GR_PLOT_VP_Y0 - (y - y0) / (y1 - y0) * (GR_PLOT_VP_Y1 - GR_PLOT_VP_Y0)) * H;
}

int main(void)
{
    gr_error err = {GR_OK, ""};
    const double hx[2] = {2, 8}, hy[2] = {0.25, 0.25};
    const double vx[2] = {7.5, 7.5}, vy[2] = {0.1, 0.9};
    gr_plot_series ser[2] = {
        {NULL, hx, hy, 2, {255, 0, 0}, GR_PLOT_SOLID, 0},
        {NULL, vx, vy, 2, {0, 200, 0}, GR_PLOT_SOLID, 0},
    };
    gr_plot_spec spec = {.width = 400, .height = 300, .title = "t #1", .xlabel = "x", .ylabel = "y", .xmin = 0,
                         .xmax = 10, .ymin = 0, .ymax = 1, .series = ser, .n_series = 2};
    gr_image *img = NULL;
    if (!gr_plot_available()) {
        CHECK(gr_plot_render(&spec, &img, &err) == GR_E_RUNTIME && img == NULL);
        printf("built without PLplot: only the refusal is checked\n");
        CHECK_DONE();
    }
    CHECK_OK(gr_plot_render(&spec, &img, &err), err);
    const float red[3] = {1, 0, 0}, green[3] = {0, 200.0f / 255, 0}, blue[3] = {0, 0, 1};
    double row, col;
    int x0, x1, y0, y1;
    long n;
    if (img) {
        CHECK(img->width == 400 && img->height == 300 && img->nchannels == 3);
        find(img, red, &row, &col, &x0, &x1, &y0, &y1, &n);
        CHECK_MSG(n > 100, "red pixels: %ld", n);
        CHECK_MSG(fabs(row - px_y(0.25, 0, 1, 300)) < 1.5, "horizontal line at row %.2f, expected %.2f", row,
                  px_y(0.25, 0, 1, 300));
        CHECK_MSG(fabs(x0 - px_x(2, 0, 10, 400)) < 2.5 && fabs(x1 + 1 - px_x(8, 0, 10, 400)) < 2.5,
                  "horizontal line spans columns %d..%d, expected %.1f..%.1f", x0, x1, px_x(2, 0, 10, 400),
                  px_x(8, 0, 10, 400));
        find(img, green, &row, &col, &x0, &x1, &y0, &y1, &n);
        CHECK_MSG(n > 100, "green pixels: %ld", n);
        CHECK_MSG(fabs(col - px_x(7.5, 0, 10, 400)) < 1.5, "vertical line at column %.2f, expected %.2f", col,
                  px_x(7.5, 0, 10, 400));
        CHECK_MSG(fabs(y0 - px_y(0.9, 0, 1, 300)) < 2.5 && fabs(y1 + 1 - px_y(0.1, 0, 1, 300)) < 2.5,
                  "vertical line spans rows %d..%d, expected %.1f..%.1f", y0, y1, px_y(0.9, 0, 1, 300),
                  px_y(0.1, 0, 1, 300));
        /* the background is white and the axes black: both present */
        CHECK(gr_image_pixel(img, 5, 5)[0] > 0.99f);
    }
    gr_image_destroy(img);
    img = NULL;

    /* log y axis: y = 10 in [1, 100] sits half way up; a NaN point breaks the line */
    double lx[11], ly[11];
    for (int i = 0; i < 11; i++) {
        lx[i] = i;
        ly[i] = 10.0;
    }
    ly[5] = NAN;
    gr_plot_series ls = {"blue series", lx, ly, 11, {0, 0, 255}, GR_PLOT_SOLID, 0};
    spec = (gr_plot_spec){.width = 500, .height = 300, .log_y = 1, .xmin = 0, .xmax = 10, .ymin = 1, .ymax = 100,
                          .series = &ls, .n_series = 1};
    CHECK_OK(gr_plot_render(&spec, &img, &err), err);
    if (img) {
        find(img, blue, &row, &col, &x0, &x1, &y0, &y1, &n);
        /* the legend's sample line is blue too: keep to the plot rows below the legend */
        double sr = 0, wsum = 0;
        long cnt = 0;
        int gap_hits = 0;
        const double expect_row = px_y(1.0, 0, 2, 300);
        for (int y = 0; y < 300; y++)
            for (int x = 0; x < 500; x++)
                if (fabs(y + 0.5 - expect_row) < 6 && is_col(img, x, y, blue)) {
                    const double w = coverage(img, x, y, blue);
                    sr += w * (y + 0.5);
                    wsum += w;
                    cnt++;
                    if (fabs(x + 0.5 - px_x(5, 0, 10, 500)) < 0.6 * (px_x(1, 0, 10, 500) - px_x(0, 0, 10, 500)))
                        gap_hits++;
                }
        CHECK_MSG(cnt > 100 && fabs(sr / wsum - expect_row) < 1.5, "log axis: line at row %.2f, expected %.2f",
                  cnt ? sr / wsum : -1.0, expect_row);
        CHECK_MSG(gap_hits == 0, "%d line pixels inside the gap around the NaN point", gap_hits);
        /* the legend (label given) is drawn: blue pixels above the line's band */
        CHECK_MSG(y0 < expect_row - 20, "no legend sample line found (topmost blue row %d)", y0);
    }
    gr_image_destroy(img);
    img = NULL;

    /* the legend right of the plot area (legend_outside): the plot area narrows to
     * [VP_X0, VP_X1 - f] of the width, the legend's sample line lies right of it, and a line at
     * the legend's height stays whole across the plot area (the legend is pasted over the
     * margin only); a title too long for one line is wrapped, not cut */
    {
        const double f = 0.3, top = 80.0;
        double tx[2] = {0, 10}, ty[2] = {top, top};
        char longt[400];
        memset(longt, 0, sizeof longt);
        for (int i = 0; i < 30; i++) strcat(longt, "word word ");
        gr_plot_series os = {"a rather long legend label", tx, ty, 2, {0, 0, 255}, GR_PLOT_SOLID, 0};
        spec = (gr_plot_spec){.width = 600, .height = 300, .title = longt, .log_y = 1, .xmin = 0, .xmax = 10,
                              .ymin = 1, .ymax = 100, .series = &os, .n_series = 1, .legend_outside = f};
        CHECK_OK(gr_plot_render(&spec, &img, &err), err);
        if (img) {
            const double ax0 = GR_PLOT_VP_X0 * 600, ax1 = (GR_PLOT_VP_X1 - f) * 600;
            const double erow = (1.0 - (GR_PLOT_VP_Y0 + (GR_PLOT_VP_Y1 - GR_PLOT_VP_Y0) * log10(top) / 2.0)) * 300;
            long in_row = 0, right = 0, stray = 0;
            for (int y = 0; y < 300; y++)
                for (int x = 0; x < 600; x++) {
                    if (!is_col(img, x, y, blue)) continue;
                    if (x + 0.5 > ax1 + 3) right++;
                    else if (fabs(y + 0.5 - erow) < 3) in_row++;
                    else stray++;
                }
            CHECK_MSG(right > 10, "legend outside: no sample line right of the plot area (%ld pixels)", right);
            CHECK_MSG(in_row > 0.9 * (ax1 - ax0), "legend outside: the line at the legend's height has %ld pixels of "
                      "%.0f columns", in_row, ax1 - ax0);
            CHECK_MSG(stray == 0, "legend outside: %ld blue pixels elsewhere", stray);
        }
        gr_image_destroy(img);
        img = NULL;
        spec.legend_outside = 0.7;
        CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT && !img);
    }

    /* categorical x axis, dashed styles and markers, automatic ranges: draws */
    static const char *const cats[4] = {"none", "1", "4", "16"};
    const double cx[4] = {0, 1, 2, 3}, cy[4] = {0.5, 0.4, 0.2, 0.1}, cy2[4] = {5, 4, 3, NAN};
    gr_plot_series cs[2] = {{"a", cx, cy, 4, {10, 20, 30}, GR_PLOT_DASHED, 1},
                            {"b", cx, cy2, 4, {90, 20, 30}, GR_PLOT_LONG_DASHED, 1}};
    spec = (gr_plot_spec){.title = "categories", .log_y = 1, .series = cs, .n_series = 2, .x_categories = cats,
                          .n_categories = 4, .legend_headroom = 0.5};
    CHECK_OK(gr_plot_render(&spec, &img, &err), err);
    CHECK(img && img->width == 800 && img->height == 450); /* the default size */
    gr_image_destroy(img);
    img = NULL;

    /* bad descriptions */
    spec = (gr_plot_spec){.width = 10, .height = 300};
    CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT && !img);
    spec = (gr_plot_spec){.series = ser, .n_series = GR_PLOT_MAX_SERIES + 1};
    CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT);
    gr_plot_series bad = {"x", NULL, hy, 2, {0, 0, 0}, GR_PLOT_SOLID, 0};
    spec = (gr_plot_spec){.title = "bad", .series = &bad, .n_series = 1};
    CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT && strstr(err.msg, "bad") != NULL);
    spec = (gr_plot_spec){.log_y = 1, .ymin = -1, .ymax = 10};
    CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT && strstr(err.msg, "positive") != NULL);
    bad = (gr_plot_series){"x", hx, hy, 2, {0, 0, 0}, (gr_plot_style)7, 0};
    spec = (gr_plot_spec){.series = &bad, .n_series = 1};
    CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT);
    spec = (gr_plot_spec){.log_x = 1, .x_categories = cats, .n_categories = 4};
    CHECK(gr_plot_render(&spec, &img, &err) == GR_E_INPUT);

    /* written as PNG through a temporary name; reads back at its size */
    const char *out = getenv("GODRAYS_TEST_OUT");
    char dir[1024], path[1200], cmd[2400];
    snprintf(dir, sizeof dir, "%s/report_plot", out ? out : "/tmp");
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    CHECK(system(cmd) == 0);
    snprintf(path, sizeof path, "%s/chart.png", dir);
    spec = (gr_plot_spec){.width = 320, .height = 200, .title = "file", .series = ser, .n_series = 2};
    CHECK_OK(gr_plot_write(path, &spec, &err), err);
    gr_image *back = NULL;
    CHECK_OK(gr_oiio_read(path, 0, &back, &err), err);
    CHECK(back && back->width == 320 && back->height == 200);
    gr_image_destroy(back);
    snprintf(cmd, sizeof cmd, "ls '%s' | grep -v '^chart.png$' | grep -q .", dir);
    CHECK_MSG(system(cmd) != 0, "files other than chart.png left in %s", dir);
    CHECK_DONE();
}
