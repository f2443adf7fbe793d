/* False-color luminance difference images with a colorbar (see diffmap.h). */
#include "compare/diffmap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/oiio.h"

#define BAR_GAP 6     /* px between the image and the colorbar */
#define BAR_H 12      /* colorbar height */
#define LABEL_H 22    /* room for one line of 14 px text */
#define MIN_WIDTH 256 /* narrow images get a wider canvas so the labels fit */

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

gr_status gr_diffmap_create(const gr_image *ref, const gr_image *test, const gr_diffmap_options *opt,
                            gr_image **out, gr_diffmap_info *info, gr_error *err)
{
    static const gr_diffmap_options defaults = {0};
    if (out) *out = NULL;
    if (!out) return gr_fail(err, GR_E_INPUT, "difference image: no output");
    if (!opt) opt = &defaults;
    if (!ref || !ref->pixels || !test || !test->pixels)
        return gr_fail(err, GR_E_INPUT, "difference image: no reference or test image");
    if (ref->width != test->width || ref->height != test->height)
        return gr_fail(err, GR_E_INPUT, "difference image: reference is %d x %d, test is %d x %d", ref->width,
                       ref->height, test->width, test->height);
    if (!isfinite(opt->scale) || !isfinite(opt->vmax) || opt->vmax < 0.0)
        return gr_fail(err, GR_E_INPUT, "difference image: scale %g or range %g is not finite or negative", opt->scale,
                       opt->vmax);
    const int W = ref->width, H = ref->height;
    const size_t n = (size_t)W * (size_t)H;
    const double a = opt->scale != 0.0 ? opt->scale : 1.0;
    const int is_signed = opt->kind == GR_DIFFMAP_SIGNED;
    const char *map = is_signed ? "blue-red" : "inferno";
    int rr[3], tr[3];
    gr_metrics_pick_rgb(ref, rr);
    gr_metrics_pick_rgb(test, tr);

    const char *one[] = {"v"};
    unsigned char *scored = malloc(n);
    float *dy = malloc(sizeof(float) * n), *sorted = malloc(sizeof(float) * n);
    gr_image *val = gr_image_create(W, H, 1, one), *mapped = NULL, *bar = NULL, *bar_rgb = NULL, *canvas = NULL;
    gr_status st = GR_OK;
    if (!scored || !dy || !sorted || !val) {
        st = gr_fail(err, GR_E_NOMEM, "difference image: cannot allocate %d x %d", W, H);
        goto done;
    }
    long long nm = 0, ne = 0;
    st = gr_metrics_scored_pixels(ref, opt->mask, opt->stderr_bound, scored, &nm, &ne, err);
    if (st != GR_OK) goto done;

    size_t ns = 0;
    for (size_t p = 0; p < n; p++) {
        const float *rp = ref->pixels + p * (size_t)ref->nchannels;
        const float *tp = test->pixels + p * (size_t)test->nchannels;
        double d = 0.0;
        for (int c = 0; c < 3; c++) {
            const double w = c == 0 ? GR_LUM_R : (c == 1 ? GR_LUM_G : GR_LUM_B);
            d += w * (a * (double)tp[tr[c]] - (double)rp[rr[c]]);
        }
        dy[p] = isfinite(d) ? (float)d : 0.0f;
        if (scored[p]) sorted[ns++] = fabsf(dy[p]);
    }
    /* The range: given, else the 99th percentile of |dY| (one firefly must not turn the whole
     * picture black), else the maximum, else 1 (identical images). */
    double vmax = opt->vmax;
    if (vmax == 0.0 && ns > 0) {
        qsort(sorted, ns, sizeof(float), cmp_float);
        vmax = sorted[(size_t)floor(0.99 * (double)(ns - 1))];
        if (!(vmax > 0.0)) vmax = sorted[ns - 1];
    }
    if (!(vmax > 0.0)) vmax = 1.0;
    for (size_t p = 0; p < n; p++) {
        double v = is_signed ? 0.5 + 0.5 * dy[p] / vmax : fabs(dy[p]) / vmax;
        val->pixels[p] = (float)(v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v));
    }
    st = gr_oiio_color_map(val, 0, map, &mapped, err);
    if (st != GR_OK) goto done;

    /* Canvas: the difference on top, the colorbar under it, the numbers under the bar. */
    const int CW = W > MIN_WIDTH ? W : MIN_WIDTH, CH = H + BAR_GAP + BAR_H + LABEL_H;
    const int x0 = 8, x1 = CW - 9; /* the bar spans [x0, x1] */
    bar = gr_image_create(x1 - x0 + 1, 1, 1, one);
    canvas = gr_image_create(CW, CH, 3, NULL);
    if (!bar || !canvas) {
        st = gr_fail(err, GR_E_NOMEM, "difference image: cannot allocate %d x %d", CW, CH);
        goto done;
    }
    for (int x = x0; x <= x1; x++) bar->pixels[x - x0] = (float)(x - x0) / (float)(x1 - x0);
    st = gr_oiio_color_map(bar, 0, map, &bar_rgb, err);
    if (st != GR_OK) goto done;
    const float bg = 0.12f, gray = 0.5f;
    for (size_t i = 0; i < (size_t)CW * (size_t)CH * 3; i++) canvas->pixels[i] = bg;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const size_t p = (size_t)y * (size_t)W + (size_t)x;
            float *dst = gr_image_pixel(canvas, x, y);
            for (int c = 0; c < 3; c++) dst[c] = scored[p] ? mapped->pixels[3 * p + (size_t)c] : gray;
        }
    for (int y = H + BAR_GAP; y < H + BAR_GAP + BAR_H; y++)
        for (int x = x0; x <= x1; x++) memcpy(gr_image_pixel(canvas, x, y), bar_rgb->pixels + 3 * (x - x0), 3 * sizeof(float));
    char lo[64], hi[64], mid[96];
    snprintf(lo, sizeof lo, "%.3g", is_signed ? -vmax : 0.0);
    snprintf(hi, sizeof hi, "%.3g", vmax);
    snprintf(mid, sizeof mid, "%s", is_signed ? "a Y(test) - Y(ref)" : "|a Y(test) - Y(ref)|");
    const float white[3] = {1.0f, 1.0f, 1.0f};
    const int base = H + BAR_GAP + BAR_H + 16;
    gr_error terr = {0};
    /* Labels are optional: without a font the range is still in metrics.json and on stdout. */
    int labelled = gr_oiio_render_text(canvas, x0, base, lo, 14, white, 0, &terr) == GR_OK &&
                   gr_oiio_render_text(canvas, x1, base, hi, 14, white, 2, &terr) == GR_OK &&
                   gr_oiio_render_text(canvas, CW / 2, base, mid, 14, white, 1, &terr) == GR_OK;
    if (info) {
        info->vmin = is_signed ? -vmax : 0.0;
        info->vmax = vmax;
        info->map = map;
        info->labelled = labelled;
        info->n_unscored = nm + ne;
    }
    *out = canvas;
    canvas = NULL;
done:
    free(scored);
    free(dy);
    free(sorted);
    gr_image_destroy(val);
    gr_image_destroy(mapped);
    gr_image_destroy(bar);
    gr_image_destroy(bar_rgb);
    gr_image_destroy(canvas);
    return st;
}
