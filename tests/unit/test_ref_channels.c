/* The ground truth's error targets per channel and the honesty of its error bars (issue 30),
 * against Oracle 1 (flat water, the closed form written here: Snell, exact Fresnel, HG,
 * Beer-Lambert; docs/reference.md 2.1):
 * (a) an absorption-dominated medium (red extinction 20x the blue): the march density follows
 *     the least attenuated channel, so red's integrand is not in proportion and carries step
 *     noise; with the pilot's target on the RGB mean (1eea25b) red was left at min_steps (8)
 *     with a relative stderr of 6-13 % and errors up to 12 % on this very scene. Now the step allocation meets step_error in each channel: red's relative
 *     standard error is within 1.5 x step_error and its value within Student-t bounds of the
 *     closed form;
 * (b) coverage: over 16 x 16 pixels of a 0.5 deg view (independent pixels: flat water has no
 *     beam sets shared between pixels), the closed form lies within the render's own 95 %
 *     interval (value +- t975(batches - 1) stderr) for about 95 % of the noisy values (91 to
 *     99 % required: the binomial spread of 500-768 values is about 1 %). The channel sampled
 *     in proportion has no noise (its error is float rounding, ~1e-7) and is left out;
 * (c) views and media the test's author did not pick: 6 flat-water scenes drawn from a fixed
 *     seed (absorption 3e-3..3 /m per channel, one channel 20x that, scattering 1e-3..0.1 /m,
 *     g -0.5..0.99, camera 0.5-20.5 m deep looking 5-85 deg up, 0.2-40 deg wide, sun 15-90 deg),
 *     96 x 96 pixels, every 8th pixel in x and y against the closed form averaged over the
 *     pixel (16 x 16 points: wide pixels are not their centres): in every channel the worst
 *     pixel's standard error within 1.5 x step_error of max(pixel, image mean) (the target's
 *     normalization, docs/reference.md 2.5) and its error within 1.5 t of that; the 95 %
 *     intervals, widened by the cutoff's bound (1e-4 of the value, docs/reference.md 1), cover
 *     91-99 % of the noisy values. Values below 1e-30 (an extinction of tens per metre over
 *     metres: 0 in float) are left out. A scene where the cap held pixels back (the render
 *     warns) misses its targets by design and its error bars run low (too few strata for
 *     light packed into the ray's first metre: skewed batch means, docs/reference.md 2.5,
 *     "The floor"): it is printed, not checked. */
#include <math.h>
#include "check.h"
#include "core/optics.h"
#include "core/rng.h"
#include "core/student.h"
#include "test_ref_util.h"

static double SA[3] = {1.5, 0.06, 0.02}, SS[3] = {0.02, 0.03, 0.05}, G = 0.8;
#define MEDIUM "\"medium\":{\"absorption_per_m\":[1.5,0.06,0.02],\"scattering_per_m\":[0.02,0.03,0.05],\"g\":0.8}"

/* Oracle 1 along the unit direction w from the camera at depth z0 (ray ending on the surface,
 * w_y > 0): sigma_s p E_w exp(-sigma_t z0 / mu) (1 - exp(-sigma_t k D)) / (sigma_t k),
 * k = 1 - w_y / mu, D = z0 / w_y (infinite for a ray level or looking down: no seabed). SA, SS, G:
 * the medium of the scene being checked. */
static double closed_form(const gr_scene *s, gr_dvec3 w, double z0, int c)
{
    gr_dvec3 I = gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]);
    gr_dvec3 T = gr_refract_d(I, gr_d3(0, 1, 0), 1.0 / 1.333);
    double mu = -T.y, ft = 1.0 - gr_fresnel_exact(-I.y, 1.0, 1.333), e_w = ft * -I.y / mu;
    double st = SA[c] + SS[c], k = 1.0 - w.y / mu, D = w.y > 0.0 ? z0 / w.y : INFINITY; /* no seabed: down to infinity */
    return SS[c] * gr_hg_phase(-gr_d3_dot(T, w), G) * e_w * exp(-st * z0 / mu) * -expm1(-st * k * D) / (st * k);
}

static gr_dvec3 pixel_dir(const gr_camera *c, double fx, double fy)
{
    double tf = tan(0.5 * c->fov_deg * GR_PI / 180.0), aspect = (double)c->width / c->height;
    double nx = (2.0 * fx / c->width - 1.0) * tf * aspect, ny = (1.0 - 2.0 * fy / c->height) * tf;
    gr_dvec3 f = gr_d3(c->forward[0], c->forward[1], c->forward[2]), r = gr_d3(c->right[0], c->right[1], c->right[2]);
    gr_dvec3 u = gr_d3(c->up[0], c->up[1], c->up[2]);
    return gr_d3_norm(gr_d3_madd(gr_d3_madd(f, r, nx), u, ny));
}

static gr_scene *flat_scene(int w, int h, double fov, double pitch, int seed)
{
    return ref_scene("{\"sun\":{\"elevation_deg\":60,\"azimuth_deg\":30,\"angular_diameter_deg\":0}," MEDIUM ","
                     "\"camera\":{\"position_m\":[0,-6,0],\"yaw_deg\":30,\"pitch_deg\":%g,\"fov_deg\":%g,"
                     "\"width\":%d,\"height\":%d},"
                     "\"reference\":{\"steps\":192,\"seed\":%d}}",
                     pitch, fov, w, h, seed);
}

static void test_red(void)
{
    gr_scene *s = flat_scene(3, 3, 0.01, 20.0, 1);
    gr_ref_result r;
    ref_render(s, NULL, &r);
    double tau = s->reference.step_error, t = gr_student_t975(s->reference.batches - 1);
    for (int c = 0; c < 3; c++) {
        double worst_se = 0.0, worst_err = 0.0, L = 0.0;
        for (int y = 0; y < 3; y++)
            for (int x = 0; x < 3; x++) {
                const float *px = gr_image_pixel(r.image, x, y);
                L = closed_form(s, pixel_dir(&s->camera, x + 0.5, y + 0.5), 6.0, c);
                double err = fabs(px[c] - L) / L, se = px[3 + c] / L;
                if (se > worst_se) worst_se = se;
                if (err > worst_err) worst_err = err;
                /* within its own 99.8 % interval (t 4.785 at 7 dof) plus float rounding */
                CHECK_MSG(fabs(px[c] - L) <= 4.785 * px[3 + c] + 1e-5 * L, "channel %d pixel (%d, %d): %.6g +- %.2g, closed form %.6g",
                          c, x, y, px[c], px[3 + c], L);
            }
        printf("(a) channel %d: closed form %.6g (the last pixel); worst relative stderr %.3f %%, worst |error| %.3f %% (target %.2f %%, 95 %% "
               "interval %.2f %%); steps %g\n",
               c, L, 100.0 * worst_se, 100.0 * worst_err, 100.0 * tau, 100.0 * t * tau,
               r.steps_mean);
        /* the target, per channel: the relative standard error within step_error (the pilot's
         * estimate, with some slack for its own noise) and the error within the t interval of
         * that */
        CHECK_MSG(worst_se <= 1.5 * tau, "channel %d: relative stderr %.4f over 1.5 x step_error %.4f", c, worst_se, tau);
        CHECK_MSG(worst_err <= 1.5 * t * tau, "channel %d: relative error %.4f over the target's interval %.4f", c, worst_err,
                  1.5 * t * tau);
    }
    gr_ref_result_free(&r);
    free(s);
}

static void test_coverage(void)
{
    int n = 0, in = 0;
    for (int seed = 1; seed <= 2; seed++) {
        gr_scene *s = flat_scene(16, 16, 0.5, 25.0, seed);
        gr_ref_result r;
        ref_render(s, NULL, &r);
        double t = gr_student_t975(s->reference.batches - 1);
        for (int y = 0; y < 16; y++)
            for (int x = 0; x < 16; x++) {
                const float *px = gr_image_pixel(r.image, x, y);
                gr_dvec3 w = pixel_dir(&s->camera, x + 0.5, y + 0.5);
                for (int c = 0; c < 3; c++) {
                    double L = closed_form(s, w, 6.0, c);
                    if (!(px[3 + c] > 1e-5 * L)) continue; /* no noise: the channel sampled in proportion */
                    n++;
                    in += fabs(px[c] - L) <= t * px[3 + c];
                }
            }
        gr_ref_result_free(&r);
        free(s);
    }
    double f = n ? (double)in / n : 0.0;
    printf("(b) coverage: %d of %d noisy values within their 95 %% interval (%.1f %%)\n", in, n, 100.0 * f);
    CHECK_MSG(n >= 500, "only %d noisy values", n);
    CHECK_MSG(f >= 0.91 && f <= 0.99, "95 %% intervals cover %.1f %% of %d values", 100.0 * f, n);
}

static void test_random(void)
{
    const double CUT = 1e-4; /* the cutoff's bound: a ray drops at most this much of a channel (docs/reference.md 1) */
    const int W = 96, SUB = 8, NP = W / SUB;
    gr_rng st = gr_rng_make(12345u, 0, 0); /* the project's PCG: the same scenes on every machine */
    long n = 0, in = 0;
    int checked = 0;
    for (int it = 0; it < 6; it++) {
        for (int c = 0; c < 3; c++) {
            SA[c] = pow(10.0, -2.5 + 3.0 * gr_rng_double(&st));
            SS[c] = pow(10.0, -3.0 + 2.0 * gr_rng_double(&st));
        }
        SA[(int)(3.0 * gr_rng_double(&st))] *= 20.0;
        G = -0.5 + 1.49 * gr_rng_double(&st);
        double z0 = 0.5 + 20.0 * gr_rng_double(&st), elev = 15.0 + 75.0 * gr_rng_double(&st), pitch = 5.0 + 80.0 * gr_rng_double(&st);
        double fov = 0.2 + 40.0 * gr_rng_double(&st);
        gr_scene *s = ref_scene("{\"sun\":{\"elevation_deg\":%.17g,\"azimuth_deg\":30,\"angular_diameter_deg\":0},"
                                "\"medium\":{\"absorption_per_m\":[%.17g,%.17g,%.17g],\"scattering_per_m\":[%.17g,%.17g,%.17g],"
                                "\"g\":%.17g},\"camera\":{\"position_m\":[0,%.17g,0],\"yaw_deg\":30,\"pitch_deg\":%.17g,"
                                "\"fov_deg\":%.17g,\"width\":%d,\"height\":%d},\"reference\":{\"steps\":192,\"seed\":%d}}",
                                elev, SA[0], SA[1], SA[2], SS[0], SS[1], SS[2], G, -z0, pitch, fov, W, W, it + 1);
        gr_ref_result r;
        ref_render(s, NULL, &r);
        double tau = s->reference.step_error, t = gr_student_t975(s->reference.batches - 1);
        printf("(c) scene %d: absorption %.3g %.3g %.3g, scattering %.3g %.3g %.3g /m, g %.2f, %.1f m deep, pitch %.0f, "
               "fov %.1f, sun %.0f deg; %.1f steps, %.1f %% of the pixels held to the cap\n", it, SA[0], SA[1], SA[2], SS[0], SS[1],
               SS[2], G, z0, pitch, fov, elev, r.steps_mean, 100.0 * r.steps_capped_frac);
        /* pixels whose pilot asked for more than the cap miss the target by design (the render
         * warns: docs/reference.md 2.5, "When the cap holds the steps back"): the targets are
         * checked where no pixel was held back, the coverage everywhere */
        const int capped = r.steps_capped_frac > 0.0;
        int sn = 0, sin = 0;
        for (int c = 0; c < 3; c++) {
            double mean = 0.0, worst_se = 0.0, worst_err = 0.0;
            for (int y = 0; y < NP; y++)
                for (int x = 0; x < NP; x++) mean += gr_image_pixel(r.image, x * SUB, y * SUB)[c] / (NP * NP);
            int used = 0;
            for (int y = 0; y < NP; y++)
                for (int x = 0; x < NP; x++) {
                    const float *px = gr_image_pixel(r.image, x * SUB, y * SUB);
                    double L = 0.0;
                    for (int j = 0; j < 16; j++)
                        for (int i = 0; i < 16; i++)
                            L += closed_form(s, pixel_dir(&s->camera, x * SUB + (i + 0.5) / 16.0, y * SUB + (j + 0.5) / 16.0), z0, c) /
                                 256.0;
                    if (!(L > 1e-30)) continue;
                    used++;
                    double norm = L > mean ? L : mean, se = px[3 + c] / norm, err = fabs(px[c] - L) / norm;
                    if (se > worst_se) worst_se = se;
                    if (err > worst_err) worst_err = err;
                    if (!(px[3 + c] > 1e-5 * L)) continue; /* no noise: sampled in proportion */
                    sn++;
                    sin += fabs(px[c] - L) <= t * px[3 + c] + CUT * L;
                }
            if (!used) continue;
            printf("    channel %d: worst stderr %.3f %%, worst |error| %.3f %% of max(pixel, image mean)\n", c, 100.0 * worst_se,
                   100.0 * worst_err);
            if (capped) continue;
            checked++;
            CHECK_MSG(worst_se <= 1.5 * tau, "(c) scene %d channel %d: stderr %.4f of max(pixel, mean) over 1.5 x step_error", it, c,
                      worst_se);
            CHECK_MSG(worst_err <= 1.5 * t * tau, "(c) scene %d channel %d: error %.4f of max(pixel, mean) over %.4f", it, c,
                      worst_err, 1.5 * t * tau);
        }
        printf("    %d of %d noisy values covered%s\n", sin, sn, capped ? " (held to the cap: not counted)" : "");
        if (!capped) {
            n += sn;
            in += sin;
        }
        gr_ref_result_free(&r);
        free(s);
    }
    double f = n ? (double)in / n : 0.0;
    printf("(c) coverage: %ld of %ld noisy values within their 95 %% interval (%.1f %%)\n", in, n, 100.0 * f);
    CHECK_MSG(n >= 500, "(c) only %ld noisy values", n);
    CHECK_MSG(checked >= 10, "(c) the targets checked in only %d channels", checked);
    CHECK_MSG(f >= 0.91 && f <= 0.99, "(c) 95 %% intervals cover %.1f %% of %ld values", 100.0 * f, n);
}

int main(void)
{
    test_red();
    test_coverage();
    test_random();
    CHECK_DONE();
}
