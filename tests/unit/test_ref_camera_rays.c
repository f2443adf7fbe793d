/* Rays per camera sample (reference.camera_rays; docs/reference.md 2.5, "Rays per camera
 * sample"), checked with real renders of the default scene's water at 96 x 54:
 * (a) unbiased: 4 rays per sample and 1 ray per sample with the same seed share the passes'
 *     grid offsets, so batch b's difference of a block's mean keeps the camera's and the
 *     steps' noise and any bias of the rays, not the passes' tessellation noise; batches are
 *     independent, so the mean difference over its standard error is Student t with 7
 *     degrees of freedom: every 8 x 8 block and the image mean within 99.9 % (as
 *     unit.ref_adaptive (a));
 * (b) the pixels' own error bars are honest for both: the per-pixel differences over their
 *     combined standard errors have a spread near that of t with 7 degrees of freedom
 *     (sqrt(7/5) = 1.18 for one side; between 0.8 and 1.5 here);
 * (c) it does what it is for: at the same march steps, the pixels' variance (stderr^2 summed
 *     over the image) falls by at least a quarter, the camera's footprint on the caustics'
 *     sub-pixel lines being sampled by 4 rays instead of 1 (at 640 x 360 the 95th-percentile
 *     pixel's relative standard error fell from 0.72 to 0.51 %: docs/benchmarks.md);
 * (d) determinism: 1 ray and 4 rays per sample each give the same bytes with 1 and 3 threads.
 * (camera_rays 1 gives the bytes of the renderer before the setting: checked once with idiff
 * against that binary, docs/benchmarks.md; not repeatable here.) */
#include <math.h>
#include "check.h"
#include "test_ref_util.h"

/* Student's t, 7 degrees of freedom, two-sided 99.9 % (standard table): 73 comparisons of an
 * unbiased pair exceed it somewhere with probability about 7 % (the seed is fixed: the test
 * gives the same figures every run; seeds 21-28 and 11 gave image-mean t of 0.33, -0.55,
 * -2.30, -0.12, -1.08, -0.92, 1.84, -0.88 and -2.57; on a scene with 6 of the 8 waves seeds
 * 1-6 gave -0.47, -0.53, 0.42, 1.45, 0.26, 0.26: over the 15, mean -0.32 against a standard
 * error of 0.30) */
#define T7_9995 5.408

/* the plain grid alone (4.2 cells per wave here: by default a set near the camera, docs/reference.md
 * 2.2, which is not what this test is about and doubles its time) */
static gr_scene *scene(int rays, int seed, int threads)
{
    return ref_scene("{\"name\":\"rays\"," REF_DEFAULT_WAVES "," REF_DEFAULT_MEDIUM ","
                     "\"sun\":{\"elevation_deg\":55,\"azimuth_deg\":20},"
                     "\"camera\":{\"position_m\":[0,-3,0],\"yaw_deg\":20,\"pitch_deg\":35,\"fov_deg\":60,"
                     "\"width\":96,\"height\":54},"
                     "\"reference\":{\"camera_rays\":%d,\"seed\":%d,\"threads\":%d,\"bias_probe\":false,"
                     "\"near_cells_per_wavelength\":0}}",
                     rays, seed, threads);
}

static gr_ref_result render(int rays, int seed, int threads)
{
    gr_scene *s = scene(rays, seed, threads);
    gr_ref_result r;
    ref_render(s, NULL, &r);
    free(s);
    return r;
}

/* channel c of pixel (x, y) */
static double px(const gr_image *im, int x, int y, int c)
{
    return im->pixels[((size_t)y * im->width + x) * im->nchannels + c];
}

/* Per 8 x 8 block k (k < nb; k = nb: the image) and batch b, the RGB mean of the batch's
 * pixel estimates: m[k * B + b] (m may be NULL). Returns nb. */
static int block_means(const gr_ref_sums *s, double *m)
{
    int bw = s->W / 8, nb = bw * (s->H / 8);
    for (int k = 0; m && k <= nb; k++)
        for (int b = 0; b < s->B; b++)
            m[k * s->B + b] = k < nb ? ref_batch_region_mean(s, b, (k % bw) * 8, (k % bw) * 8 + 8, (k / bw) * 8,
                                                            (k / bw) * 8 + 8)
                                     : ref_batch_region_mean(s, b, 0, s->W, 0, s->H);
    return nb;
}

int main(void)
{
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.keep_sums = 1;
    gr_scene *s4 = scene(4, 11, 0), *s1 = scene(1, 11, 0);
    gr_ref_result a, b;
    ref_render(s4, &o, &a);
    ref_render(s1, &o, &b);
    free(s4);
    free(s1);
    const gr_image *ia = a.image, *ib = b.image;
    const int W = 96, H = 54;
    CHECK(ia->width == W && ia->height == H && ia->nchannels >= 6);
    /* (a) */
    int B = a.sums->B, nb = block_means(a.sums, NULL);
    double *ma = malloc((size_t)(nb + 1) * B * sizeof *ma), *mb = malloc((size_t)(nb + 1) * B * sizeof *mb);
    if (!ma || !mb) return 1;
    block_means(a.sums, ma);
    block_means(b.sums, mb);
    double worst = 0.0;
    for (int k = 0; k <= nb; k++) {
        double m, se, f, t = ref_paired_t(ma + k * B, mb + k * B, B, &m, &se, &f);
        if (k == nb)
            printf("(a) image mean: 1 ray %.6f, 4 rays - 1 ray %+.2e +- %.1e (t = %.2f)\n", f, m, se, t);
        else if (fabs(t) > fabs(worst))
            worst = t;
        CHECK_MSG(fabs(t) <= T7_9995, "%s %d: 4 rays - 1 ray = %.3g +- %.2g (t = %.2f, mean %.6f)", k == nb ? "image" : "block",
                  k, m, se, t, f);
    }
    printf("(a) %d blocks: largest |t| %.2f (limit %.3f, Student t, 7 dof, two-sided 99.9 %%)\n", nb, fabs(worst), T7_9995);
    free(ma);
    free(mb);
    /* (b) and (c) */
    double z2 = 0.0, vsa = 0.0, vsb = 0.0;
    int n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double sa = px(ia, x, y, 4), sb = px(ib, x, y, 4);
            vsa += sa * sa;
            vsb += sb * sb;
            if (sa + sb <= 0.0) continue;
            double z = (px(ia, x, y, 1) - px(ib, x, y, 1)) / sqrt(sa * sa + sb * sb);
            z2 += z * z;
            n++;
        }
    double spread = sqrt(z2 / n);
    printf("pixels: spread of the differences over their standard errors %.3f (%d pixels); variance summed over "
           "the image: 4 rays %.4e, 1 ray %.4e (ratio %.3f)\n", spread, n, vsa, vsb, vsa / vsb);
    CHECK(spread > 0.8 && spread < 1.5);
    CHECK(vsa < 0.75 * vsb);
    printf("steps per ray: 4 rays %.3f, 1 ray %.3f\n", a.steps_mean, b.steps_mean);
    gr_ref_result_free(&a);
    gr_ref_result_free(&b);
    /* (d) one ray, the same seed: the same bytes with 1 and 3 threads; 4 rays likewise */
    for (int rays = 1; rays <= 4; rays += 3) {
        gr_ref_result c = render(rays, 5, 1), d = render(rays, 5, 3);
        size_t nbytes = (size_t)W * H * c.image->nchannels * sizeof(float);
        CHECK(c.image->nchannels == d.image->nchannels && memcmp(c.image->pixels, d.image->pixels, nbytes) == 0);
        gr_ref_result_free(&c);
        gr_ref_result_free(&d);
    }
    CHECK_DONE();
}
