/* Antithetic pairs of passes (reference.antithetic; docs/reference.md 2.5, "Antithetic
 * pairs"), checked with real renders of the default scene's water at 96 x 54, 4 batches of 2
 * passes (sun_samples 8), with and without the pairs, independent seeds:
 * (a) unbiased: every pass's grid offset is still uniform over a cell, so the two renders
 *     estimate the same image: each 8 x 8 block's and the image's difference over its
 *     combined standard error (each render's batch means: 3 degrees of freedom) stays within
 *     Student t with 3 degrees of freedom at 99.9 % two-sided, and the differences' spread over
 *     the blocks is near 1 (0.6 to 1.6: Welch's t on about 6 degrees of freedom has a spread of
 *     1.2);
 * (b) it does what it is for: the blocks' own variance (their batch means' spread), summed
 *     over the blocks, falls by at least a third with the pairs: the tessellation's noise of
 *     the two passes of a pair largely cancels (at 640 x 360 the 99th-percentile block's
 *     relative standard error fell from 0.34 to 0.14 %: docs/benchmarks.md);
 * (c) with one pass per batch (the default 8 batches) there is no pair: the same bytes;
 * (d) determinism: the same bytes with 1 and 3 threads. */
#include <math.h>
#include "check.h"
#include "test_ref_util.h"

/* Student's t, 3 degrees of freedom, two-sided 99.9 % (standard table); Welch's t of two
 * 3-dof estimates has at least 3 degrees of freedom, so this bound is conservative */
#define T3_9995 12.92

static gr_scene *scene(int anti, int batches, int seed, int threads)
{
    return ref_scene("{\"name\":\"anti\"," REF_DEFAULT_WAVES "," REF_DEFAULT_MEDIUM ","
                     "\"sun\":{\"elevation_deg\":55,\"azimuth_deg\":20},"
                     "\"camera\":{\"position_m\":[0,-3,0],\"yaw_deg\":20,\"pitch_deg\":35,\"fov_deg\":60,"
                     "\"width\":96,\"height\":54},"
                     "\"reference\":{\"antithetic\":%s,\"batches\":%d,\"seed\":%d,\"threads\":%d,\"bias_probe\":false}}",
                     anti ? "true" : "false", batches, seed, threads);
}

static gr_ref_result render(int anti, int batches, int seed, int threads, const gr_ref_options *o)
{
    gr_scene *s = scene(anti, batches, seed, threads);
    gr_ref_result r;
    ref_render(s, o, &r);
    free(s);
    return r;
}

/* Region [x0, x1) x [y0, y1): the mean of its batch means and that mean's variance (batch
 * spread / B) */
static void region_stats(const gr_ref_sums *s, int x0, int x1, int y0, int y1, double *mean, double *var)
{
    double m = 0.0, m2 = 0.0;
    for (int b = 0; b < s->B; b++) {
        double v = ref_batch_region_mean(s, b, x0, x1, y0, y1);
        m += v;
        m2 += v * v;
    }
    m /= s->B;
    *mean = m;
    *var = fmax(0.0, (m2 - s->B * m * m) / (s->B - 1)) / s->B;
}

int main(void)
{
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.keep_sums = 1;
    gr_ref_result a = render(1, 4, 11, 0, &o), p = render(0, 4, 12, 0, &o);
    const int W = 96, H = 54, bw = W / 8, nb = bw * (H / 8);
    CHECK(a.sums && p.sums && a.sums->B == 4 && p.sums->B == 4);
    double worst = 0.0, z2 = 0.0, va = 0.0, vp = 0.0;
    for (int k = 0; k <= nb; k++) {
        int x0 = k < nb ? (k % bw) * 8 : 0, x1 = k < nb ? x0 + 8 : W;
        int y0 = k < nb ? (k / bw) * 8 : 0, y1 = k < nb ? y0 + 8 : H;
        double ma, sa, mp, sp;
        region_stats(a.sums, x0, x1, y0, y1, &ma, &sa);
        region_stats(p.sums, x0, x1, y0, y1, &mp, &sp);
        double t = sa + sp > 0.0 ? (ma - mp) / sqrt(sa + sp) : 0.0;
        if (k == nb) {
            printf("(a) image mean: pairs %.6f +- %.1e, plain %.6f +- %.1e (t = %.2f)\n", ma, sqrt(sa), mp, sqrt(sp), t);
        } else {
            z2 += t * t;
            va += sa;
            vp += sp;
            if (fabs(t) > fabs(worst)) worst = t;
        }
        CHECK_MSG(fabs(t) <= T3_9995, "%s %d: pairs %.6g, plain %.6g (t = %.2f)", k == nb ? "image" : "block", k, ma, mp, t);
    }
    double spread = sqrt(z2 / nb);
    printf("(a) %d blocks: largest |t| %.2f (limit %.2f), spread %.3f\n", nb, fabs(worst), T3_9995, spread);
    CHECK(spread > 0.6 && spread < 1.6);
    printf("(b) the blocks' variance summed: pairs %.4e, plain %.4e (ratio %.3f)\n", va, vp, va / vp);
    CHECK(va < 0.67 * vp);
    gr_ref_result_free(&a);
    gr_ref_result_free(&p);
    /* (c) one pass per batch: nothing to pair */
    gr_ref_result c = render(1, 8, 5, 0, NULL), d = render(0, 8, 5, 0, NULL);
    size_t nbytes = (size_t)W * H * c.image->nchannels * sizeof(float);
    CHECK(c.image->nchannels == d.image->nchannels && memcmp(c.image->pixels, d.image->pixels, nbytes) == 0);
    gr_ref_result_free(&c);
    gr_ref_result_free(&d);
    /* (d) */
    gr_ref_result e = render(1, 4, 5, 1, NULL), f = render(1, 4, 5, 3, NULL);
    CHECK(e.image->nchannels == f.image->nchannels && memcmp(e.image->pixels, f.image->pixels, nbytes) == 0);
    gr_ref_result_free(&e);
    gr_ref_result_free(&f);
    CHECK_DONE();
}
