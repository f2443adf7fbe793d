/* Adaptive march steps (docs/reference.md 2.5, "Adaptive steps"), checked with real renders:
 * (a) unbiased: an adaptive render and a fixed-steps render of a wavy scene agree in the
 *     image mean and in every block's mean: their batch-by-batch differences have mean zero
 *     within their error bar (Student t with the batches' 7 degrees of freedom, not a normal z);
 * (b) the allocation does what it says: in a narrow view where step noise dominates, more
 *     pixels are within 1 % than with fixed steps at the same march points per pixel (the
 *     pilot's included), counted from the metadata;
 * (c) flat water (Oracle 1: the march samples the integrand of the least attenuated channel
 *     in proportion; the other channels' step noise sets the steps, issue 30) equals the
 *     closed form written here (that channel exactly, the others within their error bars);
 * (d) the steps stay within [min_steps, steps], vary across the image, and the same seed
 *     gives the same bytes with 1 and 2 threads (the farm merge: tests/integration/test_merge.c);
 * (e) steps along the ray (the default, checked unbiased by (a)): where step noise dominates,
 *     allotting each pixel's steps along its ray by the pilot's per-segment noise takes fewer
 *     steps than spreading them evenly for at least as many pixels within 1 %. */
#include <math.h>
#include "check.h"
#include "core/optics.h"
#include "test_ref_util.h"


/* Student's t, 7 degrees of freedom, two-sided 99.8 % (P(|T| <= t) = 0.998; standard table):
 * the family of 17 comparisons in (a) then fails by chance with probability below 4 %. */
#define T7_9990 4.785

static double meta(const gr_ref_result *r, const char *key)
{
    const gr_meta_item *m = gr_meta_get(&r->meta, key);
    return m ? m->num : NAN;
}

static gr_scene *wavy_along(int w, int h, double fov, int steps, int adaptive, int seed, int surface_res,
                            double step_error, int along)
{
    return ref_scene("{" REF_DEFAULT_WAVES ",\"sun\":{\"elevation_deg\":60,\"azimuth_deg\":30}," REF_DEFAULT_MEDIUM ","
                     "\"camera\":{\"position_m\":[0,-8,0],\"yaw_deg\":30,\"pitch_deg\":60,\"fov_deg\":%g,"
                     "\"width\":%d,\"height\":%d},\"seabed\":{\"depth_m\":25},"
                     "\"reference\":{\"steps\":%d,\"adaptive_steps\":%s,\"seed\":%d,\"surface_res\":%d,"
                     "\"bias_probe\":false,\"sun_samples\":8,\"batches\":8,\"step_error\":%g,\"steps_along_ray\":%s}}",
                     fov, w, h, steps, adaptive ? "true" : "false", seed, surface_res, step_error, along ? "true" : "false");
}

static gr_scene *wavy(int w, int h, double fov, int steps, int adaptive, int seed, int surface_res, double step_error)
{
    return wavy_along(w, h, fov, steps, adaptive, seed, surface_res, step_error, 1);
}

/* Per-batch means (RGB mean) of the image (k = NB) and of NBX x NBY blocks (k < NB) from the
 * raw per-batch sums: m[k * B + b]. */
enum { NBX = 4, NBY = 4, NB = NBX * NBY };
static void batch_means(const gr_ref_sums *s, double *m)
{
    for (int k = 0; k <= NB; k++)
        for (int b = 0; b < s->B; b++)
            m[k * s->B + b] = k < NB ? ref_batch_region_mean(s, b, (k % NBX) * s->W / NBX, (k % NBX + 1) * s->W / NBX,
                                                            (k / NBX) * s->H / NBY, (k / NBX + 1) * s->H / NBY)
                                     : ref_batch_region_mean(s, b, 0, s->W, 0, s->H);
}

/* (a) The same seed for both renders: their batches share the passes' grid offsets and the
 * camera jitter, so batch b's difference d_b = adaptive_b - fixed_b keeps the step noise and
 * any bias of the adaptive steps, not the far larger noise of the passes. Batches are
 * independent and identically distributed (each its own passes), so mean(d) / (sd(d) /
 * sqrt(B)) follows Student's t with B - 1 = 7 degrees of freedom if the adaptive render is
 * unbiased. (The pilot's random numbers are its own stream: the same seed does not tie them
 * to the estimate's.) */
static void test_unbiased(int reduced)
{
    int w = reduced ? 48 : 80, h = reduced ? 27 : 45;
    int seed = 21;
    gr_ref_options o;
    gr_ref_options_default(&o);
    o.keep_sums = 1;
    gr_scene *sa = wavy(w, h, 60.0, 96, 1, seed, 96, 0.008), *sf = wavy(w, h, 60.0, 96, 0, seed, 96, 0.008);
    gr_ref_result ra, rf;
    ref_render(sa, &o, &ra);
    ref_render(sf, &o, &rf);
    int B = ra.sums->B;
    double *ma = malloc((NB + 1) * B * sizeof *ma), *mf = malloc((NB + 1) * B * sizeof *mf);
    batch_means(ra.sums, ma);
    batch_means(rf.sums, mf);
    double worst = 0.0;
    for (int k = 0; k <= NB; k++) {
        double a, se, f, t = ref_paired_t(ma + k * B, mf + k * B, B, &a, &se, &f);
        if (k == NB)
            printf("(a) image mean: fixed 96 steps %.6f, adaptive (%.1f steps) - fixed %+.2e +- %.1e (t = %.2f)\n", f,
                   ra.steps_mean, a, se, t);
        else if (fabs(t) > fabs(worst))
            worst = t;
        CHECK_MSG(fabs(t) <= T7_9990, "%s %d: adaptive - fixed = %.3g +- %.2g (t = %.2f, mean %.6f)",
                  k == NB ? "image" : "block", k, a, se, t, f);
    }
    printf("(a) %d blocks: largest |t| %.2f (limit %.3f, Student t, 7 dof, two-sided 99.8 %%)\n", NB, fabs(worst), T7_9990);
    free(ma);
    free(mf);
    CHECK_MSG(ra.steps_mean < 0.8 * 96, "the adaptive render must take fewer steps (%.1f)", ra.steps_mean);
    /* (d) the steps: within [min_steps, steps], not all equal */
    CHECK(meta(&ra, "godrays:steps_min") >= sa->reference.min_steps);
    CHECK(meta(&ra, "godrays:steps_max") <= 96);
    CHECK(meta(&ra, "godrays:steps_min") < meta(&ra, "godrays:steps_max"));
    CHECK(meta(&ra, "godrays:pilot_steps") == sa->reference.pilot_steps);
    CHECK(meta(&rf, "godrays:steps_mean") == 96 && meta(&rf, "godrays:pilot_steps") == 0);
    gr_ref_result_free(&ra);
    gr_ref_result_free(&rf);
    free(sa);
    free(sf);
}

/* (b) A narrow view (0.1 deg pixels, as at 640x360 with the default 60 deg) into the sun's
 * caustics, where step noise dominates the error bars. */
static void test_allocation(int reduced)
{
    (void)reduced; /* smaller views leave too few pixels above the 1 % line to tell */
    int w = 64, h = 36, seed = 5;
    double fov = 0.1 * w;
    /* the default target (below the 1 % line: a target above it aims the noisy pixels just
     * above the line, where fixed steps leave many below) */
    double tau = 0.008;
    gr_scene *sa = wavy(w, h, fov, 192, 1, seed, 96, tau);
    gr_ref_result ra, rf;
    ref_render(sa, NULL, &ra);
    /* march points per camera ray, the pilot's (one ray per 2 x 2 pixels, per round of
     * passes x spp camera rays) included */
    double spp = (double)ra.passes * meta(&ra, "godrays:spp_per_pass");
    double points = ra.steps_mean + meta(&ra, "godrays:pilot_steps") / 4.0 / spp;
    int nf = (int)ceil(points);
    gr_scene *sf = wavy(w, h, fov, nf, 0, seed, 96, tau);
    ref_render(sf, NULL, &rf);
    printf("(b) pixels within 1 %%: adaptive %.1f %% (%.1f steps per ray, %.2f with the pilot), fixed %d steps %.1f %%\n",
           100.0 * ra.frac_se_1pct, ra.steps_mean, points, nf, 100.0 * rf.frac_se_1pct);
    CHECK_MSG(ra.frac_se_1pct > rf.frac_se_1pct + 0.02, "adaptive %.3f, fixed %.3f at equal points", ra.frac_se_1pct,
              rf.frac_se_1pct);
    gr_ref_result_free(&ra);
    gr_ref_result_free(&rf);
    free(sa);
    free(sf);
}

/* (e) The same narrow view as (b): the same target with steps along the ray and evenly. */
static void test_along_ray(void)
{
    int w = 64, h = 36, seed = 5;
    double fov = 0.1 * w, tau = 0.010;
    gr_scene *sa = wavy_along(w, h, fov, 192, 1, seed, 96, tau, 1), *se = wavy_along(w, h, fov, 192, 1, seed, 96, tau, 0);
    gr_ref_result ra, re;
    ref_render(sa, NULL, &ra);
    ref_render(se, NULL, &re);
    printf("(e) along the ray: %.1f steps, %.1f %% within 1 %%; evenly: %.1f steps, %.1f %%\n", ra.steps_mean,
           100.0 * ra.frac_se_1pct, re.steps_mean, 100.0 * re.frac_se_1pct);
    CHECK_MSG(ra.steps_mean < 0.85 * re.steps_mean, "along the ray %.1f steps, evenly %.1f", ra.steps_mean, re.steps_mean);
    CHECK_MSG(ra.frac_se_1pct >= re.frac_se_1pct - 0.01, "along the ray %.3f within 1 %%, evenly %.3f", ra.frac_se_1pct,
              re.frac_se_1pct);
    gr_ref_result_free(&ra);
    gr_ref_result_free(&re);
    free(sa);
    free(se);
}

/* (c) Flat water, no occluders: the least attenuated channel has no step noise, the others
 * ask for steps (the target holds per channel), and the image is Oracle 1's closed form (as in unit.ref_flat, written here for one ray). */
static void test_flat(void)
{
    gr_scene *s = ref_scene("{\"sun\":{\"elevation_deg\":60,\"azimuth_deg\":30,\"angular_diameter_deg\":0}," REF_DEFAULT_MEDIUM ","
                            "\"camera\":{\"position_m\":[0,-8,0],\"yaw_deg\":30,\"pitch_deg\":-60,\"fov_deg\":0.01,"
                            "\"width\":3,\"height\":3},"
                            "\"reference\":{\"steps\":96,\"bias_probe\":false,\"sun_samples\":8,\"batches\":8}}");
    gr_ref_result r;
    ref_render(s, NULL, &r);
    /* the least attenuated channel has no step noise; R and G do (their integrands are not in
     * proportion to the march density), and since the target holds per channel (issue 30)
     * they ask for more than min_steps, the same on every pixel of this one-direction view */
    CHECK_MSG(meta(&r, "godrays:steps_min") == meta(&r, "godrays:steps_max") &&
                  meta(&r, "godrays:steps_max") > s->reference.min_steps,
              "flat water: steps %g to %g, expected one count above %d", meta(&r, "godrays:steps_min"),
              meta(&r, "godrays:steps_max"), s->reference.min_steps);
    /* Oracle 1 along the centre ray (the scene's sun and view directions): the refracted
     * direction T, exact Fresnel, HG phase, the two extinctions, integrated by Simpson's rule
     * along the physical ray (no seabed: to max_distance_m; the renderer's cutoff drops at most
     * its fraction, 1e-4, and here, looking down, about 1e-8) */
    gr_dvec3 I = gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]);
    gr_dvec3 T = gr_refract_d(I, gr_d3(0, 1, 0), 1.0 / 1.333);
    double ft = 1.0 - gr_fresnel_exact(-I.y, 1.0, 1.333), e_perp = ft * -I.y / -T.y;
    gr_dvec3 w = gr_d3(s->camera.forward[0], s->camera.forward[1], s->camera.forward[2]);
    double sa[3] = {0.342, 0.0585, 0.0212}, ss[3] = {0.041, 0.049, 0.062};
    double ph = gr_hg_phase(-gr_d3_dot(T, w), 0.9);
    const float *px = gr_image_pixel(r.image, 1, 1);
    for (int c = 0; c < 3; c++) {
        double st = sa[c] + ss[c], D = s->reference.max_distance_m, L = 0.0;
        int n = 200000;
        for (int i = 0; i <= n; i++) {
            double t = D * i / n, y = -8.0 + t * w.y;
            double f = ss[c] * ph * e_perp * exp(-st * (-y / -T.y)) * exp(-st * t);
            L += f * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
        }
        L *= D / n / 3.0;
        /* the least attenuated channel (B) is sampled in proportion: exact per march point; the
         * others keep the step noise the pilot allows (its target holds per channel) and must
         * lie within their own error bars (Student t, 7 dof, 99.8 %) */
        double tol = c == 2 ? 1e-4 * L : T7_9990 * px[3 + c] + 1e-4 * L;
        printf("(c) flat water, channel %d: %.7g +- %.2g, closed form %.7g\n", c, px[c], px[3 + c], L);
        CHECK_NEAR(px[c], L, tol);
    }
    gr_ref_result_free(&r);
    free(s);
}

/* (f) the cap: flat water whose R and G ask for more steps than min_steps (test (c)), under a
 * cap of min_steps + 1: every pixel is held back and says so (godrays:steps_capped_frac 1, the
 * steps it asked for above the cap); under the cap of 96 none is, with the steps it asked for
 * taken */
static void test_cap(void)
{
#define CAP_SCENE                                                                                                             \
    "{\"sun\":{\"elevation_deg\":60,\"azimuth_deg\":30,\"angular_diameter_deg\":0}," REF_DEFAULT_MEDIUM ","                     \
    "\"camera\":{\"position_m\":[0,-8,0],\"yaw_deg\":30,\"pitch_deg\":-60,\"fov_deg\":0.01,\"width\":3,\"height\":3},"        \
    "\"reference\":{\"steps\":%d,\"pilot_steps\":16,\"bias_probe\":false,\"sun_samples\":8,\"batches\":8}}"
    gr_scene *sc = ref_scene(CAP_SCENE, 17), *sf = ref_scene(CAP_SCENE, 96);
#undef CAP_SCENE
    gr_ref_result c, f;
    ref_render(sc, NULL, &c);
    ref_render(sf, NULL, &f);
    printf("(f) the cap: 17 steps: %g of the pixels held back, asking for %g; 96 steps: %g held back, %g to %g taken\n",
           c.steps_capped_frac, c.steps_wanted_capped, f.steps_capped_frac, meta(&f, "godrays:steps_min"),
           meta(&f, "godrays:steps_max"));
    CHECK(c.steps_capped_frac == 1.0 && meta(&c, "godrays:steps_capped_frac") == 1.0);
    CHECK(meta(&c, "godrays:steps_max") <= 17.0);
    CHECK_MSG(c.steps_wanted_capped > 17.0, "asked for %g steps, above the cap of 17", c.steps_wanted_capped);
    /* the same pilot (16 steps in both) and target: the capped render asked for what the free one took */
    CHECK_MSG(c.steps_wanted_capped == meta(&f, "godrays:steps_max"), "asked for %g under the cap, took %g without",
              c.steps_wanted_capped, meta(&f, "godrays:steps_max"));
    CHECK(f.steps_capped_frac == 0.0 && f.steps_wanted_capped == 0.0);
    gr_ref_result_free(&c);
    gr_ref_result_free(&f);
    free(sc);
    free(sf);
}

/* (d) the same bytes with 1 and 2 threads (the pilot's rays are keyed per pixel) */
static void test_threads(void)
{
    gr_ref_result a, b;
    gr_scene *s1 = wavy(24, 16, 60.0, 48, 1, 3, 64, 0.008), *s2 = wavy(24, 16, 60.0, 48, 1, 3, 64, 0.008);
    s1->reference.threads = 1;
    s2->reference.threads = 2;
    ref_render(s1, NULL, &a);
    ref_render(s2, NULL, &b);
    size_t n = (size_t)a.image->width * a.image->height * a.image->nchannels * sizeof(float);
    CHECK_MSG(memcmp(a.image->pixels, b.image->pixels, n) == 0, "1 and 2 threads must give the same bytes");
    CHECK(meta(&a, "godrays:steps_mean") == meta(&b, "godrays:steps_mean"));
    CHECK(meta(&a, "godrays:steps_min") < meta(&a, "godrays:steps_max"));
    gr_ref_result_free(&a);
    gr_ref_result_free(&b);
    free(s1);
    free(s2);
}

int main(void)
{
    int reduced = ref_reduced();
    test_flat();
    test_cap();
    test_threads();
    test_unbiased(reduced);
    test_allocation(reduced);
    test_along_ray();
    CHECK_DONE();
}
