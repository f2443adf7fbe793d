/* Comparison metrics (see metrics.h; formulas and conventions in docs/metrics.md). */
#include "compare/metrics.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "compare/blur.h"
#include "compare/registry.h"
#include "core/student.h"

const double gr_metrics_blur_sigmas[GR_METRICS_NSCALES] = {1.0, 4.0, 16.0};

static const double lum_w[3] = {GR_LUM_R, GR_LUM_G, GR_LUM_B};

/* Everything a metrics set needs, shared between the raw and the fitted pass. */
typedef struct ctx {
    const gr_image *ref, *test;
    size_t n;                     /* pixels */
    const unsigned char *scored;  /* per pixel */
    long long n_scored;
    int have_stderr;
    int serr[3];                  /* stderr channel indices in ref */
    int have_bias;                /* ref carries bias.R/G/B (a bias estimate per pixel) */
    int sbias[3];
    double z;                     /* significance quantile: Student t (stderr_dof) or GR_METRICS_STDERR_Z */
    double eps[GR_MCH_COUNT];     /* rel MSE epsilons (independent of the test scale) */
    double peak_ref[GR_MCH_COUNT];
    double ssim_c1, ssim_c2;
    const gr_metrics_options *opt;
    int fitted;                   /* computing the fitted set (fit_set) */
} ctx;

static inline double refv(const ctx *cx, size_t p, int c, const int rgb[3])
{
    return (double)cx->ref->pixels[p * (size_t)cx->ref->nchannels + (size_t)rgb[c]];
}

/* Per-row accumulator. */
typedef struct acc {
    double sr, st, sd, sad, sd2, srel, max_r, max_t, max_f;
    long long n, nsig;
    int mx, my, mc;
    double m_ref, m_test;
} acc;

/* s: the difference that noise and bias together explain (z stderr + |bias|) */
static void acc_add(acc *a, double r, double t, double s, int have_s, double eps, int x, int y, int c)
{
    const double d = t - r, f = fabs(d);
    a->sr += r;
    a->st += t;
    a->sd += d;
    a->sad += f;
    a->sd2 += d * d;
    a->srel += d * d / (r * r + eps);
    if (a->n == 0 || r > a->max_r) a->max_r = r;
    if (a->n == 0 || t > a->max_t) a->max_t = t;
    /* Strictly greater: the first maximum in scan order wins, as in OpenImageIO's compare(). */
    if (a->n == 0 || f > a->max_f) {
        a->max_f = f, a->mx = x, a->my = y, a->mc = c;
        a->m_ref = r, a->m_test = t;
    }
    if (have_s && f <= s) a->nsig++;
    a->n++;
}

static void acc_finish(const acc *a, double eps, double peak_ref, gr_channel_metrics *m)
{
    memset(m, 0, sizeof *m);
    m->rel_mse_eps = eps;
    m->peak_ref = peak_ref;
    m->n_samples = a->n;
    m->n_not_significant = a->nsig;
    m->max_x = m->max_y = m->max_c = -1;
    if (a->n > 0) {
        const double n = (double)a->n;
        m->ref_mean = a->sr / n;
        m->test_mean = a->st / n;
        m->bias = a->sd / n;
        m->mae = a->sad / n;
        m->mse = a->sd2 / n;
        m->rel_mse = a->srel / n;
        m->max_abs_err = a->max_f;
        m->max_x = a->mx, m->max_y = a->my, m->max_c = a->mc;
        m->max_ref = a->m_ref, m->max_test = a->m_test;
    }
    m->rmse = sqrt(m->mse);
    /* idiff's peak: 1, raised by any larger value of either image (OpenImageIO compare()). */
    double pk = 1.0;
    if (a->n > 0) {
        if (a->max_r > pk) pk = a->max_r;
        if (a->max_t > pk) pk = a->max_t;
    }
    m->peak_idiff = pk;
    m->psnr_ref_db = m->rmse > 0.0 ? 20.0 * log10(peak_ref / m->rmse) : INFINITY;
    m->psnr_idiff_db = m->rmse > 0.0 ? 20.0 * log10(pk / m->rmse) : INFINITY;
}

/* Reference luminance standard error: the channels' errors are correlated (the same paths
 * carry R, G and B), so use the bound valid for any correlation, SUM w_c s_c (docs/metrics.md). */
static double stderr_y(const ctx *cx, size_t p)
{
    const float *px = cx->ref->pixels + p * (size_t)cx->ref->nchannels;
    return GR_LUM_R * fabs((double)px[cx->serr[0]]) + GR_LUM_G * fabs((double)px[cx->serr[1]]) +
           GR_LUM_B * fabs((double)px[cx->serr[2]]);
}

static gr_status ssim_luminance(const ctx *cx, const int rr[3], const int tr[3], double scale, double *out,
                                gr_error *err)
{
    const gr_image *ref = cx->ref, *test = cx->test;
    const size_t n = cx->n;
    const int W = ref->width, H = ref->height;
    if (cx->n_scored == 0) {
        *out = 1.0;
        return GR_OK;
    }
    /* Weight, the five moment fields, and the five blurred moments. */
    double *buf = calloc(n * 11, sizeof(double));
    if (!buf) return gr_fail(err, GR_E_NOMEM, "SSIM: cannot allocate %zu pixels", n);
    double *wt = buf, *f[5], *b[5];
    for (int k = 0; k < 5; k++) {
        f[k] = buf + (size_t)(1 + k) * n;
        b[k] = buf + (size_t)(6 + k) * n;
    }
    /* Luminance of both images, centred on their scored means before the second moments are
     * formed (variances are shift invariant; centring keeps E[x^2] - mu^2 from cancelling). */
    double sr = 0.0, st = 0.0;
    for (size_t p = 0; p < n; p++) {
        const float *a = ref->pixels + p * (size_t)ref->nchannels;
        const float *t = test->pixels + p * (size_t)test->nchannels;
        f[0][p] = GR_LUM_R * a[rr[0]] + GR_LUM_G * a[rr[1]] + GR_LUM_B * a[rr[2]];
        f[1][p] = scale * (GR_LUM_R * t[tr[0]] + GR_LUM_G * t[tr[1]] + GR_LUM_B * t[tr[2]]);
        wt[p] = cx->scored[p] ? 1.0 : 0.0;
        if (cx->scored[p]) sr += f[0][p], st += f[1][p];
    }
    const double cr = sr / (double)cx->n_scored, ct = st / (double)cx->n_scored;
    /* The local moments of Wang et al. 2004 (eq. 14-16) as weighted Gaussian means. */
    for (size_t p = 0; p < n; p++) {
        const double u = f[0][p] - cr, v = f[1][p] - ct;
        f[0][p] = u;
        f[1][p] = v;
        f[2][p] = u * u;
        f[3][p] = v * v;
        f[4][p] = u * v;
    }
    gr_status st2 = gr_blur_fields((const double *const *)f, 5, wt, W, H, GR_SSIM_SIGMA, GR_SSIM_RADIUS, b, NULL, err);
    if (st2 != GR_OK) {
        free(buf);
        return st2;
    }
    double sum = 0.0;
    for (size_t p = 0; p < n; p++) {
        if (!cx->scored[p]) continue;
        const double mu_u = b[0][p], mu_v = b[1][p];
        double var_x = b[2][p] - mu_u * mu_u, var_y = b[3][p] - mu_v * mu_v;
        const double cov = b[4][p] - mu_u * mu_v;
        if (var_x < 0.0) var_x = 0.0; /* rounding only */
        if (var_y < 0.0) var_y = 0.0;
        const double mx = mu_u + cr, my = mu_v + ct;
        /* SSIM index, Wang et al. 2004 eq. 13. */
        const double num = (2.0 * mx * my + cx->ssim_c1) * (2.0 * cov + cx->ssim_c2);
        const double den = (mx * mx + my * my + cx->ssim_c1) * (var_x + var_y + cx->ssim_c2);
        sum += num / den;
    }
    *out = sum / (double)cx->n_scored;
    free(buf);
    return GR_OK;
}

/* Multi-scale RMSE: blurring is linear, so RMSE(G*t - G*r) = RMSE(G*(t - r)); the difference
 * is blurred once per sigma, as a normalized convolution over the scored pixels. */
static gr_status blurred_rmse(const ctx *cx, const int rr[3], const int tr[3], double scale, gr_metrics_set *set,
                              gr_error *err)
{
    const gr_image *ref = cx->ref, *test = cx->test;
    const size_t n = cx->n;
    if (cx->n_scored == 0) return GR_OK;
    double *buf = calloc(n * 7, sizeof(double));
    if (!buf) return gr_fail(err, GR_E_NOMEM, "multi-scale RMSE: cannot allocate %zu pixels", n);
    double *d[3] = {buf, buf + n, buf + 2 * n}, *o[3] = {buf + 3 * n, buf + 4 * n, buf + 5 * n};
    double *wt = buf + 6 * n;
    for (size_t p = 0; p < n; p++) {
        const float *a = ref->pixels + p * (size_t)ref->nchannels;
        const float *t = test->pixels + p * (size_t)test->nchannels;
        wt[p] = cx->scored[p] ? 1.0 : 0.0;
        for (int c = 0; c < 3; c++) d[c][p] = cx->scored[p] ? scale * (double)t[tr[c]] - (double)a[rr[c]] : 0.0;
    }
    for (int s = 0; s < GR_METRICS_NSCALES; s++) {
        const double sigma = gr_metrics_blur_sigmas[s];
        gr_status st = gr_blur_fields((const double *const *)d, 3, wt, ref->width, ref->height, sigma,
                                      gr_blur_radius(sigma), o, NULL, err);
        if (st != GR_OK) {
            free(buf);
            return st;
        }
        double s2[GR_MCH_COUNT] = {0};
        for (size_t p = 0; p < n; p++) {
            if (!cx->scored[p]) continue;
            double dy = 0.0;
            for (int c = 0; c < 3; c++) {
                s2[c] += o[c][p] * o[c][p];
                dy += lum_w[c] * o[c][p];
            }
            s2[GR_MCH_Y] += dy * dy;
        }
        s2[GR_MCH_RGB] = s2[0] + s2[1] + s2[2];
        const double ns = (double)cx->n_scored;
        for (int c = 0; c < GR_MCH_COUNT; c++)
            set->ch[c].rmse_blur[s] = sqrt(s2[c] / (c == GR_MCH_RGB ? 3.0 * ns : ns));
    }
    free(buf);
    set->have_blur = 1;
    return GR_OK;
}

/* The registry's metrics that come with their own compute function (registry.h), on this
 * set's scaling; the others are read from the set's fields by their extract functions. */
static gr_status own_metrics(const ctx *cx, const int rr[3], const int tr[3], double scale, gr_metrics_set *set,
                             gr_error *err)
{
    set->n_extra = gr_metric_count();
    for (int i = 0; i < GR_METRIC_MAX; i++) set->extra[i] = NAN;
    if (cx->opt->skip_extra) return GR_OK;
    gr_metric_input in = {.ref = cx->ref, .test = cx->test, .scale = scale, .scored = cx->scored,
                          .n_scored = cx->n_scored};
    memcpy(in.ref_rgb, rr, sizeof in.ref_rgb);
    memcpy(in.test_rgb, tr, sizeof in.test_rgb);
    for (int i = 0; i < set->n_extra; i++) {
        const gr_metric_desc *d = gr_metric_at(i);
        if (!d->compute) continue;
        gr_status st = d->compute(&in, d->user, &set->extra[i], err);
        if (st != GR_OK) {
            gr_error_prefix(err, "metric %s", d->key);
            return st;
        }
    }
    return GR_OK;
}

static gr_status compute_set(const ctx *cx, const int rr[3], const int tr[3], double scale, gr_metrics_set *set,
                             gr_error *err)
{
    memset(set, 0, sizeof *set);
    set->scale = scale;
    set->scale_rgb[0] = set->scale_rgb[1] = set->scale_rgb[2] = scale;
    acc a[GR_MCH_COUNT];
    memset(a, 0, sizeof a);
    const gr_image *ref = cx->ref, *test = cx->test;
    const int W = ref->width;
    for (size_t p = 0; p < cx->n; p++) {
        if (!cx->scored[p]) continue;
        const int x = (int)(p % (size_t)W), y = (int)(p / (size_t)W);
        const float *rp = ref->pixels + p * (size_t)ref->nchannels;
        const float *tp = test->pixels + p * (size_t)test->nchannels;
        double yr = 0.0, yt = 0.0;
        for (int c = 0; c < 3; c++) {
            const double r = (double)rp[rr[c]], t = scale * (double)tp[tr[c]];
            const double s = cx->have_stderr ? cx->z * fabs((double)rp[cx->serr[c]]) +
                                                   (cx->have_bias ? fabs((double)rp[cx->sbias[c]]) : 0.0)
                                             : 0.0;
            acc_add(&a[c], r, t, s, cx->have_stderr, cx->eps[c], x, y, -1);
            acc_add(&a[GR_MCH_RGB], r, t, s, cx->have_stderr, cx->eps[GR_MCH_RGB], x, y, c);
            yr += lum_w[c] * r;
            yt += lum_w[c] * t;
        }
        double sy = 0.0;
        if (cx->have_stderr) {
            sy = cx->z * stderr_y(cx, p);
            for (int c = 0; cx->have_bias && c < 3; c++) sy += lum_w[c] * fabs((double)rp[cx->sbias[c]]);
        }
        acc_add(&a[GR_MCH_Y], yr, yt, sy, cx->have_stderr, cx->eps[GR_MCH_Y], x, y, -1);
    }
    for (int c = 0; c < GR_MCH_COUNT; c++) acc_finish(&a[c], cx->eps[c], cx->peak_ref[c], &set->ch[c]);
    set->ssim_y = 1.0;
    if (!cx->opt->skip_ssim) {
        gr_status st = ssim_luminance(cx, rr, tr, scale, &set->ssim_y, err);
        if (st != GR_OK) return st;
        set->have_ssim = 1;
    }
    if (!cx->opt->skip_blur) {
        gr_status st = blurred_rmse(cx, rr, tr, scale, set, err);
        if (st != GR_OK) return st;
        set->have_blur = 1;
    }
    if (cx->opt->flip && (cx->fitted || !cx->opt->flip_fit_only || !cx->opt->fit_scale)) {
        gr_flip_options fo = *cx->opt->flip;
        fo.scored = cx->scored, fo.test_scale = scale;
        /* a black reference (all zero, or a zero median) gives HDR-FLIP no exposure range: FLIP
         * is left out (have_flip 0: NaN), as compare does, instead of failing every metric */
        int undefined = 0;
        gr_status st = gr_flip_compute_defined(ref, test, &fo, NULL, &set->flip, &undefined, NULL, 0, err);
        if (st != GR_OK) return st;
        set->have_flip = !undefined;
    }
    return own_metrics(cx, rr, tr, scale, set, err);
}

double gr_structure_score(const gr_structure_compare *c)
{
    if (!c) return 1.0;
    const double v = (0.5 * (1.0 - c->bandpass_corr) + fmin(c->contrast_log_err, 3.0) / 3.0 +
                      fmin(c->spectrum_log_dist, 3.0) / 3.0) / 3.0;
    return isfinite(v) ? v : 1.0;
}

/* The structure comparison of test against the reference into sets[0..n) (invariant to one
 * scale: computed once for the raw and the single-scale fitted set; the per-channel fit changes
 * the luminance's mix, so its set gets its own). */
static gr_status structure_fill(const ctx *cx, const gr_image *test, gr_metrics_set *const *sets, int n,
                                gr_error *err)
{
    gr_structure_options so = *cx->opt->structure;
    so.scored = cx->scored;
    gr_structure_compare *c = malloc(sizeof *c);
    if (!c) return gr_fail(err, GR_E_NOMEM, "metrics: out of memory");
    gr_status st = GR_OK;
    gr_structure_ref **keep = cx->opt->structure_ref;
    if (!keep) {
        st = gr_structure_compare_images(cx->ref, test, &so, c, err);
    } else {
        if (!gr_structure_ref_matches(*keep, cx->ref, &so)) {
            gr_structure_ref_destroy(*keep);
            *keep = NULL;
            st = gr_structure_ref_create(cx->ref, &so, keep, err);
        }
        if (st == GR_OK) st = gr_structure_compare_ref(*keep, test, c, err);
    }
    if (st == GR_OK) {
        for (int k = 0; k < n; k++) {
            sets[k]->have_structure = 1;
            sets[k]->structure_corr = c->bandpass_corr;
            sets[k]->structure_contrast_err = c->contrast_log_err;
            sets[k]->structure_contrast_ratio = c->contrast_ratio;
            sets[k]->structure_lsd = c->spectrum_log_dist;
            sets[k]->structure_score = gr_structure_score(c);
        }
    }
    free(c);
    return st;
}

/* The fitted set (options.fit_scale): one factor on the test, or one per channel. The per-
 * channel fit is computed on a copy of the test scaled per channel (R, G, B), with scale 1, so
 * that every part (SSIM, blurs, FLIP, the registry's own functions) sees the test as fitted;
 * *scaled is that copy (the caller destroys it), NULL for one factor. */
static gr_status fit_set(const ctx *cx, const int rr[3], const int tr[3], gr_metrics *out, gr_image **scaled,
                         gr_error *err)
{
    const gr_fit_mode mode = cx->opt->fit_scale == GR_FIT_RGB ? GR_FIT_RGB : GR_FIT_SCALE;
    double a[3];
    out->have_fit = 1;
    out->fit_mode = (int)mode;
    out->fit_defined = gr_fit_scales(cx->ref, cx->test, cx->scored, rr, tr, mode, a) > 0;
    ctx c2 = *cx;
    c2.fitted = 1;
    if (mode == GR_FIT_SCALE) return compute_set(&c2, rr, tr, a[0], &out->fit, err);
    static const char *const rgb_names[3] = {"R", "G", "B"};
    static const int rgb_idx[3] = {0, 1, 2};
    const gr_image *test = cx->test;
    gr_image *t = *scaled = gr_image_create(test->width, test->height, 3, rgb_names);
    if (!t) return gr_fail(err, GR_E_NOMEM, "metrics: cannot allocate the per-channel fitted test");
    for (size_t p = 0; p < cx->n; p++)
        for (int c = 0; c < 3; c++)
            t->pixels[3 * p + (size_t)c] = (float)(a[c] * (double)test->pixels[p * (size_t)test->nchannels + (size_t)tr[c]]);
    c2.test = t;
    gr_status st = compute_set(&c2, rr, rgb_idx, 1.0, &out->fit, err);
    const double mean_t[3] = {out->raw.ch[0].test_mean, out->raw.ch[1].test_mean, out->raw.ch[2].test_mean};
    out->fit.scale = gr_fit_luminance_scale(a, mean_t);
    memcpy(out->fit.scale_rgb, a, sizeof a);
    return st;
}

/* Reference stderr channels, or -1s. */
static int find_stderr(const gr_image *ref, int serr[3])
{
    serr[0] = gr_image_channel(ref, "stderr.R");
    serr[1] = gr_image_channel(ref, "stderr.G");
    serr[2] = gr_image_channel(ref, "stderr.B");
    return serr[0] >= 0 && serr[1] >= 0 && serr[2] >= 0;
}

static gr_status check_bound(double *bound, gr_error *err)
{
    if (isnan(*bound) || *bound < 0.0)
        return gr_fail(err, GR_E_INPUT, "metrics: stderr bound %g is not a value >= 0", *bound);
    if (*bound == 0.0) *bound = GR_METRICS_STDERR_BOUND;
    return GR_OK;
}

gr_status gr_metrics_scored_pixels(const gr_image *ref, const gr_image *mask, double stderr_bound,
                                   unsigned char *scored, long long *n_masked_out, long long *n_stderr_excluded,
                                   gr_error *err)
{
    if (!ref || !ref->pixels || !scored) return gr_fail(err, GR_E_INPUT, "metrics: no reference image");
    if (mask && (!mask->pixels || mask->width != ref->width || mask->height != ref->height))
        return gr_fail(err, GR_E_INPUT, "metrics: mask is %d x %d, images are %d x %d", mask->width, mask->height,
                       ref->width, ref->height);
    gr_status st = check_bound(&stderr_bound, err);
    if (st != GR_OK) return st;
    ctx cx;
    memset(&cx, 0, sizeof cx);
    cx.ref = ref;
    cx.have_stderr = find_stderr(ref, cx.serr);
    int rr[3];
    gr_metrics_pick_rgb(ref, rr);
    long long nm = 0, ne = 0;
    const size_t n = (size_t)ref->width * (size_t)ref->height;
    for (size_t p = 0; p < n; p++) {
        unsigned char ok = 1;
        if (mask && mask->pixels[p * (size_t)mask->nchannels] == 0.0f) {
            ok = 0;
            nm++;
        } else if (cx.have_stderr) {
            /* Relative stderr of the reference luminance; 0/0 counts as 0 (an exact zero). */
            double yr = 0.0;
            for (int c = 0; c < 3; c++) yr += lum_w[c] * refv(&cx, p, c, rr);
            const double s = stderr_y(&cx, p);
            const double rel = s == 0.0 ? 0.0 : (yr != 0.0 ? s / fabs(yr) : INFINITY);
            if (rel > stderr_bound) {
                ok = 0;
                ne++;
            }
        }
        scored[p] = ok;
    }
    if (n_masked_out) *n_masked_out = nm;
    if (n_stderr_excluded) *n_stderr_excluded = ne;
    return GR_OK;
}

gr_status gr_metrics_compute(const gr_image *ref, const gr_image *test, const gr_metrics_options *opt,
                             gr_metrics *out, gr_error *err)
{
    static const gr_metrics_options defaults = {0};
    if (!out) return gr_fail(err, GR_E_INPUT, "metrics: no output");
    memset(out, 0, sizeof *out);
    if (!opt) opt = &defaults;
    if (!ref || !ref->pixels) return gr_fail(err, GR_E_INPUT, "metrics: no reference image");
    if (!test || !test->pixels) return gr_fail(err, GR_E_INPUT, "metrics: no test image");
    if (ref->width != test->width || ref->height != test->height)
        return gr_fail(err, GR_E_INPUT, "metrics: reference is %d x %d, test is %d x %d", ref->width, ref->height,
                       test->width, test->height);
    const gr_image *mask = opt->mask; /* its size is checked by gr_metrics_scored_pixels */
    double bound = opt->stderr_bound;
    gr_status st = check_bound(&bound, err);
    if (st != GR_OK) return st;
    st = gr_image_check_finite(ref, "reference", err);
    if (st == GR_OK) st = gr_image_check_finite(test, "test", err);
    if (st == GR_OK && mask) st = gr_image_check_finite(mask, "mask", err);
    if (st != GR_OK) {
        if (err) err->status = GR_E_INPUT;
        return GR_E_INPUT;
    }

    ctx cx;
    memset(&cx, 0, sizeof cx);
    cx.ref = ref, cx.test = test, cx.opt = opt;
    cx.n = (size_t)ref->width * (size_t)ref->height;
    int rr[3], tr[3];
    gr_metrics_pick_rgb(ref, rr);
    gr_metrics_pick_rgb(test, tr);
    cx.have_stderr = find_stderr(ref, cx.serr);
    cx.sbias[0] = gr_image_channel(ref, "bias.R");
    cx.sbias[1] = gr_image_channel(ref, "bias.G");
    cx.sbias[2] = gr_image_channel(ref, "bias.B");
    cx.have_bias = cx.sbias[0] >= 0 && cx.sbias[1] >= 0 && cx.sbias[2] >= 0;
    /* a standard error from B batches has B - 1 degrees of freedom: Student's t */
    cx.z = opt->stderr_dof > 0 ? gr_student_t975(opt->stderr_dof) : GR_METRICS_STDERR_Z;

    unsigned char *scored = malloc(cx.n);
    if (!scored) return gr_fail(err, GR_E_NOMEM, "metrics: cannot allocate %zu pixels", cx.n);
    cx.scored = scored;

    out->width = ref->width, out->height = ref->height;
    memcpy(out->ref_rgb, rr, sizeof rr);
    memcpy(out->test_rgb, tr, sizeof tr);
    out->n_pixels = (long long)cx.n;
    out->have_stderr = cx.have_stderr;
    out->stderr_bound = bound;
    out->stderr_z = cx.z;
    out->stderr_dof = opt->stderr_dof;
    out->have_bias = cx.have_bias;

    /* Which pixels are scored, and the scale-independent statistics of the reference. */
    double sabs[GR_MCH_COUNT] = {0}, pk[GR_MCH_COUNT];
    int pk_set[GR_MCH_COUNT] = {0};
    st = gr_metrics_scored_pixels(ref, mask, bound, scored, &out->n_masked_out, &out->n_stderr_excluded, err);
    if (st != GR_OK) {
        free(scored);
        return st;
    }
    for (size_t p = 0; p < cx.n; p++) {
        if (!scored[p]) continue;
        double r[3], yr = 0.0;
        for (int c = 0; c < 3; c++) {
            r[c] = refv(&cx, p, c, rr);
            yr += lum_w[c] * r[c];
        }
        cx.n_scored++;
        const double v[GR_MCH_COUNT] = {r[0], r[1], r[2], 0.0, yr};
        for (int c = 0; c < GR_MCH_COUNT; c++) {
            if (c == GR_MCH_RGB) continue;
            sabs[c] += fabs(v[c]);
            if (!pk_set[c] || v[c] > pk[c]) pk[c] = v[c], pk_set[c] = 1;
        }
    }
    out->n_scored = cx.n_scored;
    sabs[GR_MCH_RGB] = sabs[0] + sabs[1] + sabs[2];
    pk_set[GR_MCH_RGB] = pk_set[0];
    pk[GR_MCH_RGB] = 0.0;
    if (pk_set[0]) {
        pk[GR_MCH_RGB] = pk[0];
        if (pk[1] > pk[GR_MCH_RGB]) pk[GR_MCH_RGB] = pk[1];
        if (pk[2] > pk[GR_MCH_RGB]) pk[GR_MCH_RGB] = pk[2];
    }
    for (int c = 0; c < GR_MCH_COUNT; c++) {
        const double ns = (double)cx.n_scored * (c == GR_MCH_RGB ? 3.0 : 1.0);
        const double mabs = ns > 0.0 ? sabs[c] / ns : 0.0;
        double eps = GR_METRICS_RELMSE_K * mabs * mabs;
        cx.eps[c] = eps > GR_METRICS_RELMSE_FLOOR ? eps : GR_METRICS_RELMSE_FLOOR;
        /* PSNR's HDR peak: the reference's maximum; 1 when it has no positive value. */
        cx.peak_ref[c] = pk_set[c] && pk[c] > 0.0 ? pk[c] : 1.0;
    }
    /* SSIM's dynamic range L: the reference luminance peak (docs/metrics.md). */
    out->ssim_L = cx.peak_ref[GR_MCH_Y];
    cx.ssim_c1 = (GR_SSIM_K1 * out->ssim_L) * (GR_SSIM_K1 * out->ssim_L);
    cx.ssim_c2 = (GR_SSIM_K2 * out->ssim_L) * (GR_SSIM_K2 * out->ssim_L);
    out->ssim_c1 = cx.ssim_c1, out->ssim_c2 = cx.ssim_c2;

    /* FLIP of the raw and of the fitted test against the same reference: its half once
     * (compare/flip.h; the same numbers), unless the caller prepared it */
    gr_flip_reference *own_flip = NULL, *use_flip = NULL;
    gr_flip_options fo_local;
    gr_metrics_options o_local;
    if (opt->flip && !opt->flip->reference && (opt->flip_ref || (opt->fit_scale && !opt->flip_fit_only))) {
        gr_flip_reference **keep = opt->flip_ref ? opt->flip_ref : &own_flip;
        if (!gr_flip_reference_matches(*keep, ref, opt->flip)) {
            gr_flip_reference_destroy(*keep);
            *keep = NULL;
            st = gr_flip_reference_create(ref, opt->flip, GR_METRICS_FLIP_PREPARE_MAX, 1, keep, err);
            if (st != GR_OK) {
                free(scored);
                return st;
            }
        }
        use_flip = *keep;
    }
    if (use_flip) {
        fo_local = *opt->flip, fo_local.reference = use_flip;
        o_local = *opt, o_local.flip = &fo_local;
        cx.opt = &o_local;
    }
    st = compute_set(&cx, rr, tr, 1.0, &out->raw, err);
    gr_image *scaled = NULL; /* the per-channel fitted test */
    if (st == GR_OK && opt->fit_scale) st = fit_set(&cx, rr, tr, out, &scaled, err);
    if (st == GR_OK && opt->structure) {
        gr_metrics_set *sets[2] = {&out->raw, &out->fit};
        st = structure_fill(&cx, test, sets, out->have_fit && !scaled ? 2 : 1, err);
        if (st == GR_OK && scaled) st = structure_fill(&cx, scaled, sets + 1, 1, err);
    }
    gr_image_destroy(scaled);
    gr_flip_reference_destroy(own_flip);
    free(scored);
    return st;
}
