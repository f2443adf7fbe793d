/* Separable Gaussian normalized convolution (see blur.h and docs/metrics.md). */
#include "compare/blur.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/clones.h"

int gr_blur_radius(double sigma)
{
    if (!(sigma > 0.0) || !isfinite(sigma)) return 1;
    double r = ceil(3.0 * sigma);
    if (r < 1.0) r = 1.0;
    if (r > 100000.0) r = 100000.0; /* far beyond any image we compare */
    return (int)r;
}

gr_status gr_gaussian_kernel(double sigma, int radius, double *w, gr_error *err)
{
    if (!(sigma > 0.0) || !isfinite(sigma))
        return gr_fail(err, GR_E_INPUT, "Gaussian kernel: sigma %g is not a finite value > 0", sigma);
    if (radius < 0) return gr_fail(err, GR_E_INPUT, "Gaussian kernel: radius %d is negative", radius);
    if (!w) return gr_fail(err, GR_E_INPUT, "Gaussian kernel: no output array");
    double sum = 0.0;
    for (int i = -radius; i <= radius; i++) {
        double v = exp(-(double)i * (double)i / (2.0 * sigma * sigma));
        w[i + radius] = v;
        sum += v;
    }
    /* sum >= 1 (the centre tap is exp(0)), so the division is safe. */
    for (int i = 0; i <= 2 * radius; i++) w[i] /= sum;
    return GR_OK;
}

GR_CLONES_AVX2 gr_status gr_blur_fields(const double *const *src, int nch, const double *weight, int width, int height,
                         double sigma, int radius, double *const *dst, double *dst_weight, gr_error *err)
{
    if (width <= 0 || height <= 0 || nch < 0 || (nch > 0 && (!src || !dst)))
        return gr_fail(err, GR_E_INPUT, "blur: bad image size %d x %d or channel count %d", width, height, nch);
    if (radius < 0) return gr_fail(err, GR_E_INPUT, "blur: radius %d is negative", radius);
    const size_t W = (size_t)width, H = (size_t)height, N = W * H;
    const int nf = nch + 1; /* the fields, then the weight */
    double *kern = malloc(sizeof(double) * (size_t)(2 * radius + 1));
    double *hor = malloc(sizeof(double) * N * (size_t)nf); /* after the horizontal pass */
    double *acc = malloc(sizeof(double) * W * (size_t)nf); /* one output row */
    double *prow = malloc(sizeof(double) * W);             /* one premultiplied input row */
    gr_status st = GR_OK;
    if (!kern || !hor || !acc || !prow) {
        st = gr_fail(err, GR_E_NOMEM, "blur: cannot allocate %zu x %zu x %d doubles", W, H, nf);
        goto done;
    }
    st = gr_gaussian_kernel(sigma, radius, kern, err);
    if (st != GR_OK) goto done;
    const double *g = kern + radius; /* g[i] for i in [-radius, radius] */

    /* Horizontal pass: taps that would fall outside the row are simply absent; the weight
     * field carries the missing mass, so the final division renormalizes (blur.h). Written
     * tap by tap over a whole row (contiguous, vectorizable loops). */
    for (size_t y = 0; y < H; y++) {
        const double *wrow = weight ? weight + y * W : NULL;
        for (int f = 0; f < nf; f++) {
            /* The premultiplied row w x (w itself for the weight field); a zero weight drops
             * the sample whatever it holds. */
            if (f == nch) {
                for (size_t x = 0; x < W; x++) prow[x] = wrow ? wrow[x] : 1.0;
            } else {
                const double *row = src[f] + y * W;
                for (size_t x = 0; x < W; x++) prow[x] = !wrow ? row[x] : (wrow[x] == 0.0 ? 0.0 : wrow[x] * row[x]);
            }
            double *o = hor + (size_t)f * N + y * W;
            memset(o, 0, sizeof(double) * W);
            for (long i = -(long)radius; i <= (long)radius; i++) {
                /* output x reads input x + i: valid for 0 <= x + i < W */
                const long xlo = i < 0 ? -i : 0, xhi = i > 0 ? (long)W - i : (long)W;
                const double gi = g[i];
                for (long x = xlo; x < xhi; x++) o[x] += gi * prow[x + i];
            }
        }
    }
    /* Vertical pass, row by row (contiguous inner loops), then the normalization. */
    for (size_t y = 0; y < H; y++) {
        long lo = -(long)radius, hi = (long)radius;
        if ((long)y + lo < 0) lo = -(long)y;
        if ((long)y + hi > (long)H - 1) hi = (long)H - 1 - (long)y;
        memset(acc, 0, sizeof(double) * W * (size_t)nf);
        for (long j = lo; j <= hi; j++) {
            const size_t yy = (size_t)((long)y + j);
            for (int f = 0; f < nf; f++) {
                const double *row = hor + (size_t)f * N + yy * W;
                double *a = acc + (size_t)f * W;
                for (size_t x = 0; x < W; x++) a[x] += g[j] * row[x];
            }
        }
        const double *aw = acc + (size_t)nch * W;
        for (size_t x = 0; x < W; x++) {
            const double den = aw[x];
            for (int c = 0; c < nch; c++) dst[c][y * W + x] = den > 0.0 ? acc[(size_t)c * W + x] / den : 0.0;
            if (dst_weight) dst_weight[y * W + x] = den;
        }
    }
done:
    free(kern);
    free(hor);
    free(acc);
    free(prow);
    return st;
}

gr_status gr_blur_image(const gr_image *img, double sigma, gr_image **out, gr_error *err)
{
    if (out) *out = NULL;
    if (!img || !img->pixels || !out) return gr_fail(err, GR_E_INPUT, "blur: no image");
    const size_t N = (size_t)img->width * (size_t)img->height;
    const int nc = img->nchannels;
    const char *names[GR_IMAGE_MAX_CHANNELS] = {0};
    for (int c = 0; c < nc; c++) names[c] = img->names[c];
    gr_image *res = gr_image_create(img->width, img->height, nc, names);
    double *buf = malloc(sizeof(double) * N * (size_t)nc * 2);
    double *srcp[GR_IMAGE_MAX_CHANNELS], *dstp[GR_IMAGE_MAX_CHANNELS];
    gr_status st = GR_OK;
    if (!res || !buf) {
        st = gr_fail(err, GR_E_NOMEM, "blur: cannot allocate a %d x %d x %d image", img->width, img->height, nc);
        goto fail;
    }
    for (int c = 0; c < nc; c++) {
        srcp[c] = buf + (size_t)c * N;
        dstp[c] = buf + (size_t)(nc + c) * N;
        for (size_t p = 0; p < N; p++) srcp[c][p] = img->pixels[p * (size_t)nc + (size_t)c];
    }
    st = gr_blur_fields((const double *const *)srcp, nc, NULL, img->width, img->height, sigma,
                        gr_blur_radius(sigma), dstp, NULL, err);
    if (st != GR_OK) goto fail;
    for (int c = 0; c < nc; c++)
        for (size_t p = 0; p < N; p++) res->pixels[p * (size_t)nc + (size_t)c] = (float)dstp[c][p];
    free(buf);
    *out = res;
    return GR_OK;
fail:
    free(buf);
    gr_image_destroy(res);
    return st;
}
