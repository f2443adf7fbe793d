/* Grid sweeps of a technique's settings and their error surface (sweep.h). */
#include "tune/sweep.h"
#include "common/outfile.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "image/oiio.h"
#include "report/plot.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void gr_sweep_result_free(gr_sweep_result *res)
{
    if (!res) return;
    free(res->xs);
    free(res->ys);
    free(res->err);
    free(res->case_err);
    free(res->scale);
    memset(res, 0, sizeof *res);
}

gr_status gr_sweep_run(gr_tune_problem *p, gr_sweep_result *res, gr_sweep_progress_fn cb, void *user,
                       gr_error *err)
{
    memset(res, 0, sizeof *res);
    if (p->n_params < 1 || p->n_params > 2)
        return gr_fail(err, GR_E_USAGE, "sweep: %d parameters (give one or two --param)", p->n_params);
    for (int k = 0; k < p->n_params; k++)
        if (p->params[k].count < 2)
            return gr_fail(err, GR_E_USAGE, "sweep: %s has %d values (need >= 2)", p->params[k].key, p->params[k].count);
    res->n_axes = p->n_params;
    res->nx = p->params[0].count;
    res->ny = p->n_params > 1 ? p->params[1].count : 1;
    res->n_cases = p->n_cases;
    size_t npts = (size_t)res->nx * (size_t)res->ny;
    res->xs = malloc((size_t)res->nx * sizeof(double));
    res->ys = malloc((size_t)res->ny * sizeof(double));
    res->err = malloc(npts * sizeof(double));
    res->scale = malloc(npts * sizeof(double));
    res->case_err = malloc(npts * (size_t)p->n_cases * sizeof(double));
    double *sc = malloc((size_t)p->n_cases * sizeof(double));
    if (!res->xs || !res->ys || !res->err || !res->scale || !res->case_err || !sc) {
        free(sc);
        gr_sweep_result_free(res);
        return gr_fail(err, GR_E_NOMEM, "sweep: out of memory for %zu grid points", npts);
    }
    for (int i = 0; i < res->nx; i++) res->xs[i] = gr_tune_param_value(&p->params[0], i);
    for (int j = 0; j < res->ny; j++) res->ys[j] = p->n_params > 1 ? gr_tune_param_value(&p->params[1], j) : 0.0;
    double t0 = now_s();
    gr_status st = GR_OK;
    res->best = 0;
    for (int j = 0; j < res->ny && st == GR_OK; j++) {
        for (int i = 0; i < res->nx; i++) {
            size_t idx = (size_t)i + (size_t)res->nx * (size_t)j;
            double x[2] = {res->xs[i], res->ys[j]};
            st = gr_tune_evaluate(p, x, &res->err[idx], &res->case_err[idx * (size_t)p->n_cases], sc, err);
            if (st != GR_OK) {
                if (p->n_params > 1)
                    gr_error_prefix(err, "sweep point %s = %g, %s = %g", p->params[0].key, x[0], p->params[1].key, x[1]);
                else
                    gr_error_prefix(err, "sweep point %s = %g", p->params[0].key, x[0]);
                break;
            }
            double ms = 0.0;
            for (int c = 0; c < p->n_cases; c++) ms += sc[c];
            res->scale[idx] = ms / (double)p->n_cases;
            if (res->err[idx] < res->err[res->best]) res->best = (int)idx;
            if (cb) cb(user, (int)idx + 1, (int)npts);
        }
    }
    res->wall_s = now_s() - t0;
    free(sc);
    if (st != GR_OK) gr_sweep_result_free(res);
    return st;
}

/* Atomic output (common/outfile); the caller finishes with close_rename. */
static FILE *open_tmp(const char *path, gr_outfile *of, gr_error *err)
{
    return gr_outfile_open(of, path, err) == GR_OK ? of->f : NULL;
}

static gr_status close_rename(gr_outfile *of, gr_error *err)
{
    return gr_outfile_commit(of, 0, err);
}

gr_status gr_sweep_write_csv(const char *path, const gr_tune_problem *p, const gr_sweep_result *res,
                             const char *const *case_labels, gr_error *err)
{
    gr_outfile of;
    FILE *f = open_tmp(path, &of, err);
    if (!f) return err->status;
    fprintf(f, "%s", p->params[0].key);
    if (res->n_axes > 1) fprintf(f, ",%s", p->params[1].key);
    fprintf(f, ",%s%s,scale", gr_tune_metric_name(p->metric), p->fit == GR_FIT_RGB ? "_fit_rgb" : p->fit ? "_fit" : "");
    for (int c = 0; c < res->n_cases; c++) {
        if (case_labels && case_labels[c]) fprintf(f, ",%s", case_labels[c]);
        else fprintf(f, ",case%d", c);
    }
    fputc('\n', f);
    for (int j = 0; j < res->ny; j++) {
        for (int i = 0; i < res->nx; i++) {
            size_t idx = (size_t)i + (size_t)res->nx * (size_t)j;
            fprintf(f, "%.9g", res->xs[i]);
            if (res->n_axes > 1) fprintf(f, ",%.9g", res->ys[j]);
            fprintf(f, ",%.9g,%.9g", res->err[idx], res->scale[idx]);
            for (int c = 0; c < res->n_cases; c++) fprintf(f, ",%.9g", res->case_err[idx * (size_t)res->n_cases + (size_t)c]);
            fputc('\n', f);
        }
    }
    return close_rename(&of, err);
}

/* ---- drawing ---------------------------------------------------------------------------- */

static void fill_rect(gr_image *img, int x0, int y0, int x1, int y1, const float rgb[3])
{
    for (int y = y0 < 0 ? 0 : y0; y < y1 && y < img->height; y++)
        for (int x = x0 < 0 ? 0 : x0; x < x1 && x < img->width; x++) {
            float *px = gr_image_pixel(img, x, y);
            px[0] = rgb[0];
            px[1] = rgb[1];
            px[2] = rgb[2];
        }
}

/* Optional text: no font is not an error (the image is drawn unlabelled). */
static void text(gr_image *img, int x, int y, const char *s, int size, const float rgb[3], int align)
{
    gr_error e;
    (void)gr_oiio_render_text(img, x, y, s, size, rgb, align, &e);
}

/* Pastes the color map of v (w x h values in [0, 1], row 0 at the top) at (ox, oy). */
static gr_status paste_mapped(gr_image *dst, const float *v, int w, int h, int ox, int oy, gr_error *err)
{
    gr_image *src = gr_image_create(w, h, 1, (const char *const[]){"Y"});
    if (!src) return gr_fail(err, GR_E_NOMEM, "heat map: out of memory");
    memcpy(src->pixels, v, (size_t)w * (size_t)h * sizeof(float));
    gr_image *rgb = NULL;
    gr_status st = gr_oiio_color_map(src, 0, "viridis", &rgb, err);
    gr_image_destroy(src);
    if (st != GR_OK) return st;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (ox + x < 0 || oy + y < 0 || ox + x >= dst->width || oy + y >= dst->height) continue;
            float *d = gr_image_pixel(dst, ox + x, oy + y);
            const float *s = gr_image_pixel(rgb, x, y);
            d[0] = s[0];
            d[1] = s[1];
            d[2] = s[2];
        }
    gr_image_destroy(rgb);
    return GR_OK;
}

gr_status gr_tune_heatmap(const double *z, int nx, int ny, double x0, double x1, double y0, double y1,
                          const char *xlabel, const char *ylabel, const char *title, int mark, gr_image **out,
                          gr_error *err)
{
    *out = NULL;
    if (nx < 1 || ny < 1) return gr_fail(err, GR_E_INPUT, "heat map: %d x %d cells", nx, ny);
    const int W = 760, H = 600, L = 90, R = 130, T = 56, B = 76;
    const int pw = W - L - R, ph = H - T - B;
    gr_image *img = gr_image_create(W, H, 3, NULL);
    float *v = malloc((size_t)pw * (size_t)ph * sizeof(float));
    if (!img || !v) {
        gr_image_destroy(img);
        free(v);
        return gr_fail(err, GR_E_NOMEM, "heat map: out of memory");
    }
    static const float white[3] = {1, 1, 1}, black[3] = {0, 0, 0}, gray[3] = {0.35f, 0.35f, 0.35f};
    fill_rect(img, 0, 0, W, H, white);
    double zmin = INFINITY, zmax = -INFINITY;
    for (int k = 0; k < nx * ny; k++) {
        if (!isfinite(z[k])) continue;
        zmin = fmin(zmin, z[k]);
        zmax = fmax(zmax, z[k]);
    }
    if (!(zmax > zmin)) zmax = zmin + 1.0;
    if (!isfinite(zmin)) zmin = 0.0, zmax = 1.0;
    for (int y = 0; y < ph; y++) {
        int iy = ny - 1 - (int)((double)y * ny / ph); /* y axis grows upward */
        for (int x = 0; x < pw; x++) {
            int ix = (int)((double)x * nx / pw);
            double val = z[ix + nx * iy];
            v[(size_t)y * (size_t)pw + (size_t)x] = isfinite(val) ? (float)((val - zmin) / (zmax - zmin)) : 1.0f;
        }
    }
    gr_status st = paste_mapped(img, v, pw, ph, L, T, err);
    /* colorbar: bottom = zmin, top = zmax */
    const int cbw = 22, cbx = L + pw + 24;
    float *cb = st == GR_OK ? malloc((size_t)cbw * (size_t)ph * sizeof(float)) : NULL;
    if (st == GR_OK && !cb) st = gr_fail(err, GR_E_NOMEM, "heat map: out of memory");
    if (st == GR_OK) {
        for (int y = 0; y < ph; y++)
            for (int x = 0; x < cbw; x++) cb[(size_t)y * cbw + (size_t)x] = 1.0f - (float)y / (float)(ph - 1);
        st = paste_mapped(img, cb, cbw, ph, cbx, T, err);
    }
    free(cb);
    free(v);
    if (st != GR_OK) {
        gr_image_destroy(img);
        return st;
    }
    /* frame */
    fill_rect(img, L - 1, T - 1, L + pw + 1, T, gray);
    fill_rect(img, L - 1, T + ph, L + pw + 1, T + ph + 1, gray);
    fill_rect(img, L - 1, T - 1, L, T + ph + 1, gray);
    fill_rect(img, L + pw, T - 1, L + pw + 1, T + ph + 1, gray);
    if (mark >= 0 && mark < nx * ny) {
        int ix = mark % nx, iy = mark / nx;
        int cx = L + (int)((ix + 0.5) * pw / nx), cy = T + (int)((ny - 1 - iy + 0.5) * ph / ny);
        int arm = 12;
        /* white cross with a black outline, visible on any color of the map */
        fill_rect(img, cx - arm - 1, cy - 2, cx + arm + 2, cy + 3, black);
        fill_rect(img, cx - 2, cy - arm - 1, cx + 3, cy + arm + 2, black);
        fill_rect(img, cx - arm, cy - 1, cx + arm + 1, cy + 2, white);
        fill_rect(img, cx - 1, cy - arm, cx + 2, cy + arm + 1, white);
    }
    char buf[128];
    text(img, L, T - 18, title ? title : "", 17, black, 0);
    snprintf(buf, sizeof buf, "%.4g", x0);
    text(img, L, T + ph + 22, buf, 15, black, 0);
    snprintf(buf, sizeof buf, "%.4g", x1);
    text(img, L + pw, T + ph + 22, buf, 15, black, 2);
    text(img, L + pw / 2, T + ph + 52, xlabel ? xlabel : "", 16, black, 1);
    snprintf(buf, sizeof buf, "%.4g", y1);
    text(img, L - 8, T + 14, buf, 15, black, 2);
    snprintf(buf, sizeof buf, "%.4g", y0);
    text(img, L - 8, T + ph, buf, 15, black, 2);
    text(img, 8, T + ph / 2, ylabel ? ylabel : "", 14, black, 0);
    snprintf(buf, sizeof buf, "%.4g", zmax);
    text(img, cbx, T - 6, buf, 14, black, 0);
    snprintf(buf, sizeof buf, "%.4g", zmin);
    text(img, cbx, T + ph + 20, buf, 14, black, 0);
    *out = img;
    return GR_OK;
}

gr_status gr_sweep_write_plot(const char *path, const gr_tune_problem *p, const gr_sweep_result *res, int *drawn,
                              gr_error *err)
{
    *drawn = 0;
    char title[512], ylabel[128];
    snprintf(ylabel, sizeof ylabel, "%s of Y%s", gr_tune_metric_name(p->metric), p->fit == GR_FIT_RGB ? " after per-channel fit" : p->fit ? " after scale fit" : "");
    if (res->n_axes == 2) {
        int bx = res->best % res->nx, by = res->best / res->nx;
        snprintf(title, sizeof title, "%s; min %.4g at %s=%.4g, %s=%.4g", ylabel, res->err[res->best],
                 p->params[0].key, res->xs[bx], p->params[1].key, res->ys[by]);
        gr_image *img = NULL;
        gr_status st = gr_tune_heatmap(res->err, res->nx, res->ny, res->xs[0], res->xs[res->nx - 1], res->ys[0],
                                       res->ys[res->ny - 1], p->params[0].key, p->params[1].key, title, res->best,
                                       &img, err);
        if (st != GR_OK) return st;
        st = gr_oiio_write(path, img, err);
        gr_image_destroy(img);
        if (st == GR_OK) *drawn = 1;
        return st;
    }
    if (!gr_plot_available()) return GR_OK;
    double bx = res->xs[res->best], by = res->err[res->best];
    gr_plot_series s[2] = {
        {.label = ylabel, .x = res->xs, .y = res->err, .n = res->nx, .rgb = {31, 119, 180}, .markers = 1},
        {.label = "minimum", .x = &bx, .y = &by, .n = 1, .rgb = {214, 39, 40}, .markers = 1},
    };
    snprintf(title, sizeof title, "sweep of %s: min %.4g at %.4g", p->params[0].key, by, bx);
    gr_plot_spec spec = {.title = title, .xlabel = p->params[0].key, .ylabel = ylabel, .series = s, .n_series = 2,
                         .legend_headroom = 0.25};
    gr_status st = gr_plot_write(path, &spec, err);
    if (st == GR_OK) *drawn = 1;
    return st;
}
