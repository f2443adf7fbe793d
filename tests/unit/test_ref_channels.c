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
 *     in proportion has no noise (its error is float rounding, ~1e-7) and is left out. */
#include <math.h>
#include "check.h"
#include "core/optics.h"
#include "core/student.h"
#include "test_ref_util.h"

static const double SA[3] = {1.5, 0.06, 0.02}, SS[3] = {0.02, 0.03, 0.05};
#define MEDIUM "\"medium\":{\"absorption_per_m\":[1.5,0.06,0.02],\"scattering_per_m\":[0.02,0.03,0.05],\"g\":0.8}"

/* Oracle 1 along the unit direction w from the camera at depth z0 (ray ending on the surface,
 * w_y > 0): sigma_s p E_w exp(-sigma_t z0 / mu) (1 - exp(-sigma_t k D)) / (sigma_t k),
 * k = 1 - w_y / mu, D = z0 / w_y. */
static double closed_form(const gr_scene *s, gr_dvec3 w, double z0, int c)
{
    gr_dvec3 I = gr_d3(s->sun.dir[0], s->sun.dir[1], s->sun.dir[2]);
    gr_dvec3 T = gr_refract_d(I, gr_d3(0, 1, 0), 1.0 / 1.333);
    double mu = -T.y, ft = 1.0 - gr_fresnel_exact(-I.y, 1.0, 1.333), e_w = ft * -I.y / mu;
    double st = SA[c] + SS[c], k = 1.0 - w.y / mu, D = z0 / w.y;
    return SS[c] * gr_hg_phase(-gr_d3_dot(T, w), 0.8) * e_w * exp(-st * z0 / mu) * -expm1(-st * k * D) / (st * k);
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

int main(void)
{
    test_red();
    test_coverage();
    CHECK_DONE();
}
