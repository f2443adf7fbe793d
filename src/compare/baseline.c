/* Baselines and the equivalent blur (baseline.h). */
#include "compare/baseline.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/parallel.h"
#include "compare/blur.h"
#include "compare/registry.h"

const char *gr_baseline_key(int i)
{
    static const char *const k[GR_BASELINE_COUNT] = {"black", "constant", "blur"};
    return i >= 0 && i < GR_BASELINE_COUNT ? k[i] : NULL;
}

const char *gr_baseline_label(int i)
{
    static const char *const l[GR_BASELINE_COUNT] = {"black frame", "constant: the truth's mean",
                                                     "truth blurred, sigma 4 px"};
    return i >= 0 && i < GR_BASELINE_COUNT ? l[i] : NULL;
}

/* The truth's R, G, B as a 3-channel image (stderr channels dropped). */
static gr_image *rgb_copy(const gr_image *ref)
{
    int rgb[3];
    gr_metrics_pick_rgb(ref, rgb);
    gr_image *o = gr_image_create(ref->width, ref->height, 3, NULL);
    if (!o) return NULL;
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    for (size_t p = 0; p < n; p++)
        for (int c = 0; c < 3; c++) o->pixels[3 * p + (size_t)c] = ref->pixels[p * (size_t)ref->nchannels + (size_t)rgb[c]];
    return o;
}

/* The blurred truth's verdict after the fit, with only what the verdict needs. */
static gr_status rung(const gr_image *ref, const gr_image *rgb, double sigma, const gr_metrics_options *opt,
                      gr_metrics *m, double *v, gr_error *err)
{
    gr_image *b = NULL;
    gr_status st = gr_blur_image(rgb, sigma, &b, err);
    if (st == GR_OK) st = gr_metrics_compute(ref, b, opt, m, err);
    gr_image_destroy(b);
    *v = st == GR_OK ? gr_metric_value(&m->fit, GR_METRIC_VERDICT) : NAN;
    return st;
}

/* The baselines' jobs (gr_parallel_try): 0 black, 1 constant, 2 the blur baseline, then the
 * ladder's rungs; each writes only its own slot. */
typedef struct bl_ctx {
    const gr_image *ref, *rgb;
    const gr_metrics_options *o, *lo;
    gr_baselines *out;
} bl_ctx;

static gr_status bl_job(void *arg, int i, gr_error *err)
{
    bl_ctx *c = arg;
    const gr_image *ref = c->ref;
    if (i == GR_BASELINE_BLUR) {
        double v;
        return rung(ref, c->rgb, GR_BASELINE_BLUR_SIGMA, c->o, &c->out->m[GR_BASELINE_BLUR], &v, err);
    }
    if (i >= GR_BASELINE_COUNT) { /* rung k: the verdict alone */
        const int k = i - GR_BASELINE_COUNT;
        gr_metrics *m = malloc(sizeof *m);
        gr_status st = m ? rung(ref, c->rgb, c->out->sigma_px[k], c->lo, m, &c->out->verdict[k], err)
                         : gr_fail(err, GR_E_NOMEM, "baselines: out of memory");
        free(m);
        return st;
    }
    /* black: the image as created (zeros); constant: the truth's mean per channel (sums in double) */
    gr_image *flat = gr_image_create(ref->width, ref->height, 3, NULL);
    if (!flat) return gr_fail(err, GR_E_NOMEM, "baselines: out of memory");
    if (i == GR_BASELINE_CONSTANT) {
        const size_t n = (size_t)ref->width * (size_t)ref->height;
        const float *px = c->rgb->pixels;
        double mean[3] = {0, 0, 0};
        for (size_t p = 0; p < n; p++)
            for (int ch = 0; ch < 3; ch++) mean[ch] += px[3 * p + (size_t)ch];
        for (size_t p = 0; p < n; p++)
            for (int ch = 0; ch < 3; ch++) flat->pixels[3 * p + (size_t)ch] = (float)(mean[ch] / (double)n);
    }
    gr_status st = gr_metrics_compute(ref, flat, c->o, &c->out->m[i], err);
    gr_image_destroy(flat);
    return st;
}

gr_status gr_baselines_compute(const gr_image *ref, const gr_metrics_options *opt, gr_baselines *out,
                               gr_error *err)
{
    if (!ref || !ref->pixels || !out) return gr_fail(err, GR_E_INPUT, "baselines: no ground truth");
    memset(out, 0, sizeof *out);
    gr_metrics_options o = opt ? *opt : (gr_metrics_options){0};
    o.fit_scale = 1;
    /* the ladder: the verdict alone (no FLIP, SSIM, blurs or own-function metrics) */
    gr_metrics_options lo = o;
    lo.flip = NULL, lo.skip_ssim = 1, lo.skip_blur = 1, lo.skip_extra = 1;
    /* the three baselines' FLIPs (raw and fitted) share the truth's half (compare/flip.h) */
    gr_flip_reference *fref = NULL;
    gr_flip_options fo;
    if (o.flip && !o.flip->reference) {
        gr_status fst = gr_flip_reference_create(ref, o.flip, GR_FLIP_SHARED_PREPARE_MAX, 0, &fref, err);
        if (fst != GR_OK) return fst;
        if (fref) fo = *o.flip, fo.reference = fref, o.flip = &fo;
    }
    gr_image *rgb = rgb_copy(ref);
    if (!rgb) {
        gr_flip_reference_destroy(fref);
        return gr_fail(err, GR_E_NOMEM, "baselines: out of memory");
    }
    for (int k = 0; k < GR_BASELINE_LADDER_N; k++) out->sigma_px[k] = 0.5 * pow(2.0, 0.5 * k);
    bl_ctx c = {.ref = ref, .rgb = rgb, .o = &o, .lo = &lo, .out = out};
    /* independent jobs on a few threads (common/parallel.h): the same numbers for any count */
    gr_status st = gr_parallel_try(GR_BASELINE_COUNT + GR_BASELINE_LADDER_N, 0, bl_job, &c, err);
    for (int k = 0; k < GR_BASELINE_LADDER_N && st == GR_OK; k++) {
        /* the blurred truth gets worse with blur; where a measure wobbles, the running maximum
         * keeps the curve monotone so that each verdict has one equivalent blur */
        out->envelope[k] = k == 0 || out->verdict[k] > out->envelope[k - 1] ? out->verdict[k] : out->envelope[k - 1];
        out->n_ladder = k + 1;
    }
    gr_image_destroy(rgb);
    gr_flip_reference_destroy(fref);
    return st;
}

double gr_equivalent_blur(const gr_baselines *b, double v, int *where)
{
    if (where) *where = 0;
    if (!b || b->n_ladder < 1 || isnan(v)) return NAN;
    const int n = b->n_ladder;
    if (v < b->envelope[0]) {
        if (where) *where = -1;
        return b->sigma_px[0];
    }
    if (v > b->envelope[n - 1]) {
        if (where) *where = 1;
        return b->sigma_px[n - 1];
    }
    int k = 0;
    while (k < n - 1 && b->envelope[k] < v) k++; /* the first rung at or above v */
    if (k == 0 || !(b->envelope[k] > b->envelope[k - 1])) return b->sigma_px[k];
    const double t = (v - b->envelope[k - 1]) / (b->envelope[k] - b->envelope[k - 1]);
    return exp(log(b->sigma_px[k - 1]) + t * (log(b->sigma_px[k]) - log(b->sigma_px[k - 1])));
}

const char *gr_equivalent_blur_text(const gr_baselines *b, double v, char *buf, size_t n)
{
    int where = 0;
    const double px = gr_equivalent_blur(b, v, &where);
    if (isnan(px)) snprintf(buf, n, "n/a");
    else if (where < 0) snprintf(buf, n, "< %.2g px", px);
    else if (where > 0) snprintf(buf, n, "> %.3g px", px);
    else snprintf(buf, n, "%.3g px", px);
    return buf;
}
