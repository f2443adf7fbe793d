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
 * (d) determinism: the same bytes with 1 and 3 threads;
 * (e) the camera samples and the steps are paired too: in (a)'s renders the pixels' own
 *     relative variance summed is at most PIX_RATIO of the plain render's (the second pass
 *     of a pair takes the first's rays mirrored in their sub-cells and every step moved by
 *     half a stratum; the tessellation's pairing alone leaves more);
 * (f) the pilot counts a pair as one sample of twice the strata (step noise a quarter,
 *     alpha = 2): 4 batches of 2 antithetic passes take exactly the steps of 8 plain passes
 *     with 2 camera samples each (spp 4: 2 in each of a batch's two passes; N^2 / (P + U) =
 *     16 samples' worth; the pilot is the same rays), with min_steps 8 and step_error 0.004
 *     so that most pixels are above the floor. */
#include <math.h>
#include "check.h"
#include "test_ref_util.h"

/* Student's t, 3 degrees of freedom, two-sided 99.9 % (standard table); Welch's t of two
 * 3-dof estimates has at least 3 degrees of freedom, so this bound is conservative */
#define T3_9995 12.92

/* (e): measured on (a)'s renders: 0.271 with the rays mirrored and the steps paired; 0.449
 * with only the tessellation's offsets paired (each pass's own random numbers, the code
 * before). At fixed 16 steps: 0.365 against 0.513, and 0.647 with the first's rays copied
 * unmirrored (docs/benchmarks.md) */
#define PIX_RATIO 0.36

/* The plain grid alone: this view's grid has 4.2 cells across the shortest wave, so by
 * default a set near the camera would be refined 3 x 3 (docs/reference.md 2.2, "Near the
 * camera"), whose disc's edge and fans do not move with the pair's half-cell shift: there the
 * pixels' variance ratio is 0.38 (measured), the blocks' 0.024 */
static gr_scene *scene_x(int anti, int batches, int seed, int threads, const char *extra)
{
    return ref_scene("{\"name\":\"anti\"," REF_DEFAULT_WAVES "," REF_DEFAULT_MEDIUM ","
                     "\"sun\":{\"elevation_deg\":55,\"azimuth_deg\":20},"
                     "\"camera\":{\"position_m\":[0,-3,0],\"yaw_deg\":20,\"pitch_deg\":35,\"fov_deg\":60,"
                     "\"width\":96,\"height\":54},"
                     "\"reference\":{\"antithetic\":%s,\"batches\":%d,\"seed\":%d,\"threads\":%d,\"bias_probe\":false,"
                     "\"near_cells_per_wavelength\":0%s}}",
                     anti ? "true" : "false", batches, seed, threads, extra);
}


static gr_ref_result render_x(int anti, int batches, int seed, int threads, const gr_ref_options *o, const char *extra)
{
    gr_scene *s = scene_x(anti, batches, seed, threads, extra);
    gr_ref_result r;
    ref_render(s, o, &r);
    free(s);
    return r;
}

static gr_ref_result render(int anti, int batches, int seed, int threads, const gr_ref_options *o)
{
    return render_x(anti, batches, seed, threads, o, "");
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

/* the pixels' own variances (their batch means' spread / B, channels summed) relative to
 * max(pixel, image mean)^2 (the renderer's "within 1 %" norm), summed */
static double pixel_var_sum(const gr_ref_sums *s, int W, int H)
{
    double img, vimg, v = 0.0;
    region_stats(s, 0, W, 0, H, &img, &vimg);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double m, vv;
            region_stats(s, x, x + 1, y, y + 1, &m, &vv);
            double nm = m > img ? m : img;
            v += vv / (nm * nm);
        }
    return v;
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
    double pa = pixel_var_sum(a.sums, W, H), pp = pixel_var_sum(p.sums, W, H);
    printf("(e) the pixels' relative variance summed: pairs %.4e, plain %.4e (ratio %.3f, at most %.2f)\n", pa, pp, pa / pp,
           PIX_RATIO);
    CHECK(pa < PIX_RATIO * pp);
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
    /* (f) */
    const char *fine = ",\"step_error\":0.004,\"min_steps\":8";
    gr_ref_result sa = render_x(1, 4, 3, 0, NULL, fine),
                  sp = render_x(0, 4, 3, 0, NULL, ",\"step_error\":0.004,\"min_steps\":8,\"spp\":4");
    printf("(f) steps per ray: 4 x 2 antithetic passes %.6f, 8 plain passes of 2 camera samples %.6f\n", sa.steps_mean,
           sp.steps_mean);
    CHECK(sa.steps_mean > 0.0 && sa.steps_mean == sp.steps_mean);
    gr_ref_result_free(&sa);
    gr_ref_result_free(&sp);
    CHECK_DONE();
}
