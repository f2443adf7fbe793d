/* Beam-structure metrics (src/compare/structure.c) on synthetic images with known answers:
 * a radial streak pattern I = 1 + A cos(m0 theta + phi) around a vanishing point has all its
 * angular power at m0, A^2 / 2 times the square of the Gaussian blurs' attenuation of a
 * sinusoid of wavenumber m0 / r (closed form: exp(-sigma^2 m0^2 / (2 r^2))); rotating it moves
 * no power and flips the band-pass contrast's sign at half a period (correlation about -1)
 * and decorrelates it at a quarter; blurring it scales the power by the blur's attenuation;
 * noise leaves the peak and lowers the band-pass correlation to sqrt(S / (S + N)) with N the
 * noise's variance through the difference-of-Gaussians kernel (its energy, computed here from
 * the kernels). Also the vanishing point of a camera (closed form) and bad input. */
#include "check.h"

#include <stdlib.h>
#include <string.h>

#include "compare/blur.h"
#include "compare/structure.h"
#include "core/rng.h"

#define W 256
#define H 256
#define PI 3.14159265358979323846

static const double A = 0.5;
static const int M0 = 24;

static gr_image *pattern(double vx, double vy, double phi)
{
    gr_image *img = gr_image_create(W, H, 3, NULL);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const double th = atan2(y + 0.5 - vy, x + 0.5 - vx);
            float *p = gr_image_pixel(img, x, y);
            p[0] = p[1] = p[2] = (float)(1.0 + A * cos(M0 * th + phi));
        }
    return img;
}

/* Expected P(m0) on annulus [r0, r1] after a total blur variance s2: (A mean_r att)^2 / 2 */
static double expected_peak(double r0, double r1, double s2)
{
    const int nr = (int)floor(r1 - r0);
    double att = 0.0;
    for (int k = 0; k < nr; k++) {
        const double r = r0 + (k + 0.5) * (r1 - r0) / nr;
        att += exp(-s2 * M0 * M0 / (2.0 * r * r));
    }
    att /= nr;
    return 0.5 * A * A * att * att;
}

int main(void)
{
    gr_error err = {0};
    gr_structure_options o = {.vp_x = 128, .vp_y = 128, .sigma_fine_px = 1, .sigma_coarse_px = 4, .n_annuli = 2,
                              .r_min_px = 60, .r_max_px = 120, .n_theta = 1024, .m_max = 64};
    gr_image *base = pattern(128, 128, 0.0);
    gr_structure_image si;
    CHECK_OK(gr_structure_image_compute(base, &o, &si, NULL, &err), err);
    /* 1. the pattern: peak at m0 with the closed-form power, full circles, nothing elsewhere */
    CHECK(si.n_usable == 2 && si.arc_deg[0] == 360.0 && si.arc_deg[1] == 360.0);
    CHECK(si.peak_m == M0);
    for (int a = 0; a < 2; a++) {
        const double e = expected_peak(si.r0[a], si.r1[a], 1.0);
        printf("annulus %d [%g, %g]: P(m0) %.5f, closed form %.5f (ratio %.4f)\n", a, si.r0[a], si.r1[a],
               si.spectrum[a][M0], e, si.spectrum[a][M0] / e);
        CHECK_REL(si.spectrum[a][M0], e, 0.04);
        double off = 0.0;
        for (int m = 2; m <= 64; m++)
            if (m != M0 && m != 2 * M0) off = fmax(off, si.spectrum[a][m]);
        CHECK_MSG(off < 1e-3 * si.spectrum[a][M0], "largest off-peak P %.3g", off);
    }
    /* streak contrast: closed form per pixel (local sinusoid of wavenumber m0 / r through the
     * two blurs), RMS over the image */
    {
        double s2 = 0.0, mean_l = 0.0;
        for (int pass = 0; pass < 2; pass++)
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    const double dx = x + 0.5 - 128, dy = y + 0.5 - 128, r = hypot(dx, dy), th = atan2(dy, dx);
                    const double k2 = r > 0 ? (double)M0 * M0 / (r * r) : 1e9;
                    const double af = exp(-1.0 * k2 / 2.0), ac = exp(-16.0 * k2 / 2.0), c = A * cos(M0 * th);
                    if (pass == 0) mean_l += (1.0 + c * ac) / (W * H);
                    else {
                        const double v = c * (af - ac) / (1.0 + c * ac + 0.01 * mean_l);
                        s2 += v * v / (W * H);
                    }
                }
        printf("streak contrast %.5f, closed form %.5f\n", si.streak_contrast, sqrt(s2));
        CHECK_REL(si.streak_contrast, sqrt(s2), 0.05);
    }
    /* 2. rotated by half a period, a quarter period, and an arbitrary angle */
    const double shifts[3] = {PI, PI / 2, 1.234};
    for (int k = 0; k < 3; k++) {
        gr_image *rot = pattern(128, 128, shifts[k]);
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(base, rot, &o, &c, &err), err);
        printf("rotated by %.3f rad of phase: corr %.4f, P ratio %.5f, contrast ratio %.5f, log-spectral distance %.4f\n",
               shifts[k], c.bandpass_corr, c.test.spectrum[0][M0] / c.ref.spectrum[0][M0], c.contrast_ratio,
               c.spectrum_log_dist);
        CHECK_REL(c.test.spectrum[0][M0], c.ref.spectrum[0][M0], 0.01);
        CHECK_REL(c.test.spectrum[1][M0], c.ref.spectrum[1][M0], 0.01);
        CHECK_NEAR(c.contrast_ratio, 1.0, 0.01);
        CHECK(c.spectrum_log_dist < 0.02);
        /* C(phi) ~ cos(m0 theta + phi) x amplitude: correlation cos(phi) (the local mean's own
         * modulation, 1 +- 0.14 here, bends it slightly) */
        CHECK_NEAR(c.bandpass_corr, cos(shifts[k]), 0.035);
        gr_image_destroy(rot);
    }
    /* identical: correlation 1, distance 0 */
    {
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(base, base, &o, &c, &err), err);
        CHECK_NEAR(c.bandpass_corr, 1.0, 1e-12);
        CHECK_NEAR(c.spectrum_log_dist, 0.0, 1e-12);
        CHECK_NEAR(c.contrast_log_err, 0.0, 1e-12);
    }
    /* scale invariance: 7.5 x the image changes nothing */
    {
        gr_image *sc = pattern(128, 128, 0.0);
        for (size_t i = 0; i < (size_t)W * H * 3; i++) sc->pixels[i] *= 7.5f;
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(base, sc, &o, &c, &err), err);
        CHECK_NEAR(c.bandpass_corr, 1.0, 1e-6);
        CHECK_NEAR(c.contrast_ratio, 1.0, 1e-6);
        CHECK_NEAR(c.power_ratio, 1.0, 1e-6);
        gr_image_destroy(sc);
    }
    /* 3. blurred with sigma 2: the power at m0 scales by the blur's attenuation squared */
    {
        gr_image *bl = NULL;
        CHECK_OK(gr_blur_image(base, 2.0, &bl, &err), err);
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(base, bl, &o, &c, &err), err);
        for (int a = 0; a < 2; a++) {
            const double e = expected_peak(c.ref.r0[a], c.ref.r1[a], 1.0 + 4.0) /
                             expected_peak(c.ref.r0[a], c.ref.r1[a], 1.0);
            const double got = c.test.spectrum[a][M0] / c.ref.spectrum[a][M0];
            printf("blurred sigma 2, annulus %d: P ratio %.5f, closed form %.5f\n", a, got, e);
            CHECK_REL(got, e, 0.03);
        }
        CHECK(c.test.peak_m == M0);
        CHECK(c.contrast_ratio < 0.8);
        gr_image_destroy(bl);
    }
    /* 4. noise of std 0.25: peak kept, correlation sqrt(S / (S + N)) */
    {
        gr_image *nz = pattern(128, 128, 0.0);
        for (size_t p = 0; p < (size_t)W * H; p++) {
            gr_rng rng = gr_rng_make(11, 0, p);
            /* Box-Muller */
            const double u1 = 1.0 - gr_rng_double(&rng), u2 = gr_rng_double(&rng);
            const float v = (float)(0.25 * sqrt(-2.0 * log(u1)) * cos(2.0 * PI * u2));
            for (int ch = 0; ch < 3; ch++) nz->pixels[3 * p + (size_t)ch] += v;
        }
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(base, nz, &o, &c, &err), err);
        /* DoG kernel energy: with separable normalized kernels kf, kc, sum (Kf - Kc)^2 =
         * (sum kf^2)^2 + (sum kc^2)^2 - 2 (sum kf kc)^2 */
        const int rf = gr_blur_radius(1.0), rc = gr_blur_radius(4.0);
        double kf[64] = {0}, kc[64] = {0};
        CHECK_OK(gr_gaussian_kernel(1.0, rf, kf + (rc - rf), &err), err);
        CHECK_OK(gr_gaussian_kernel(4.0, rc, kc, &err), err);
        double ff = 0, cc = 0, fc = 0;
        for (int i = 0; i <= 2 * rc; i++) ff += kf[i] * kf[i], cc += kc[i] * kc[i], fc += kf[i] * kc[i];
        const double energy = ff * ff + cc * cc - 2.0 * fc * fc;
        /* S: the clean contrast field's variance (its mean is ~0); N: noise variance through
         * the DoG over the local mean (about 1.01) */
        const double S = c.ref.streak_contrast * c.ref.streak_contrast, N = 0.25 * 0.25 * energy / (1.01 * 1.01);
        const double e = sqrt(S / (S + N));
        printf("noise 0.25: corr %.4f, expected %.4f; peak m %d, P(m0) ratio %.4f\n", c.bandpass_corr, e,
               c.test.peak_m, c.test.spectrum[0][M0] / c.ref.spectrum[0][M0]);
        CHECK_NEAR(c.bandpass_corr, e, 0.02);
        CHECK(c.test.peak_m == M0);
        CHECK_REL(c.test.spectrum[0][M0], c.ref.spectrum[0][M0], 0.05);
        gr_image_destroy(nz);
    }
    /* 5. vanishing point outside the image (partial arcs, Hann window): the peak and its power */
    {
        gr_image *out = pattern(-40, 100, 0.0);
        gr_structure_options o2 = o;
        o2.vp_x = -40, o2.vp_y = 100, o2.r_min_px = 80, o2.r_max_px = 240;
        gr_structure_image s2;
        CHECK_OK(gr_structure_image_compute(out, &o2, &s2, NULL, &err), err);
        CHECK(s2.peak_m == M0);
        for (int a = 0; a < 2; a++) {
            const double e = expected_peak(s2.r0[a], s2.r1[a], 1.0);
            printf("vp outside, annulus %d: arc %.1f deg, P(m0) %.5f, closed form %.5f\n", a, s2.arc_deg[a],
                   s2.spectrum[a][M0], e);
            CHECK(s2.arc_deg[a] > 30.0 && s2.arc_deg[a] < 180.0);
            CHECK_REL(s2.spectrum[a][M0], e, 0.10); /* a short arc leaks: 65 degrees hold 4.3 periods */
        }
        gr_image_destroy(out);
    }
    /* 6. a featureless image: no angular power, zero contrast */
    {
        gr_image *flat = gr_image_create(W, H, 3, NULL);
        for (size_t i = 0; i < (size_t)W * H * 3; i++) flat->pixels[i] = 0.3f;
        gr_structure_compare c;
        CHECK_OK(gr_structure_compare_images(base, flat, &o, &c, &err), err);
        CHECK(c.test.angular_power < 1e-12 && c.test.streak_contrast < 1e-9);
        /* P_t = 0: distance = RMS over annuli and m of log10(f / (P_r + f)), f = 0.01 mean P_r */
        double mp = 0.0, d2 = 0.0;
        int k = 0;
        for (int a = 0; a < 2; a++)
            for (int m = 2; m <= 64; m++) mp += c.ref.spectrum[a][m], k++;
        for (int a = 0; a < 2; a++)
            for (int m = 2; m <= 64; m++) d2 += pow(log10(0.01 * mp / k / (c.ref.spectrum[a][m] + 0.01 * mp / k)), 2);
        CHECK_NEAR(c.spectrum_log_dist, sqrt(d2 / k), 1e-9);
        CHECK(c.spectrum_log_dist > 0.4);
        CHECK(c.bandpass_corr == 0.0);
        gr_image_destroy(flat);
    }
    /* vanishing point of a camera: forward projects to the centre, forward + tan(fov/2) up
     * to the top edge's middle, and so does the opposite sense (a line has both) */
    {
        gr_camera cam = {.fov_deg = 60, .width = 320, .height = 180, .forward = {0, 0, 1}, .right = {1, 0, 0},
                         .up = {0, 1, 0}};
        double x, y;
        CHECK_OK(gr_structure_vanishing_point(&cam, (const double[]){0, 0, 1}, &x, &y, &err), err);
        CHECK_NEAR(x, 160.0, 1e-9);
        CHECK_NEAR(y, 90.0, 1e-9);
        const double t = tan(PI / 6);
        CHECK_OK(gr_structure_vanishing_point(&cam, (const double[]){0, -t, -1}, &x, &y, &err), err);
        CHECK_NEAR(x, 160.0, 1e-9);
        CHECK_NEAR(y, 0.0, 1e-9); /* the sense in front of the camera, (0, t, 1): the top edge */
        CHECK_OK(gr_structure_vanishing_point(&cam, (const double[]){t * 16.0 / 9.0, 0, 1}, &x, &y, &err), err);
        CHECK_NEAR(x, 320.0, 1e-9);
        CHECK(gr_structure_vanishing_point(&cam, (const double[]){1, 0, 0}, &x, &y, &err) == GR_E_INPUT &&
              strstr(err.msg, "parallel"));
    }
    /* bad input */
    {
        gr_structure_options bad = o;
        bad.sigma_coarse_px = 0.5;
        CHECK(gr_structure_image_compute(base, &bad, &si, NULL, &err) == GR_E_INPUT && strstr(err.msg, "sigma"));
        bad = o, bad.m_max = 600;
        CHECK(gr_structure_image_compute(base, &bad, &si, NULL, &err) == GR_E_INPUT && strstr(err.msg, "m_max"));
        gr_image *small = gr_image_create(8, 8, 3, NULL);
        gr_structure_compare c;
        CHECK(gr_structure_compare_images(base, small, &o, &c, &err) == GR_E_INPUT && strstr(err.msg, "size"));
        gr_image_destroy(small);
    }
    /* the reference's half kept (a search): the same numbers to the bit as a whole comparison;
     * it is recognized for the same reference and options only (a changed pixel, option or
     * scored mask makes gr_structure_ref_matches false) */
    {
        gr_image *rot = pattern(128, 128, 1.0);
        gr_structure_compare whole, kept;
        gr_structure_ref *r = NULL;
        CHECK_OK(gr_structure_compare_images(base, rot, &o, &whole, &err), err);
        CHECK_OK(gr_structure_ref_create(base, &o, &r, &err), err);
        CHECK_OK(gr_structure_compare_ref(r, rot, &kept, &err), err);
        CHECK(!memcmp(&whole, &kept, sizeof whole));
        CHECK(gr_structure_ref_matches(r, base, &o));
        gr_structure_options o2 = o;
        o2.sigma_fine_px = 1.5;
        CHECK(!gr_structure_ref_matches(r, base, &o2));
        unsigned char *mask = malloc((size_t)W * H);
        memset(mask, 1, (size_t)W * H);
        o2 = o, o2.scored = mask;
        CHECK(!gr_structure_ref_matches(r, base, &o2));
        gr_image *moved = pattern(128, 128, 0.0);
        gr_image_pixel(moved, 3, 5)[1] += 0.25f;
        CHECK(!gr_structure_ref_matches(r, moved, &o));
        gr_structure_ref_destroy(r);
        /* with a scored mask: kept = whole as well */
        mask[10] = mask[2000] = 0;
        o2 = o, o2.scored = mask;
        CHECK_OK(gr_structure_compare_images(base, rot, &o2, &whole, &err), err);
        CHECK_OK(gr_structure_ref_create(base, &o2, &r, &err), err);
        mask[11] = 0; /* the kept half holds its own copy of the mask */
        CHECK(!gr_structure_ref_matches(r, base, &o2));
        mask[11] = 1;
        CHECK(gr_structure_ref_matches(r, base, &o2));
        CHECK_OK(gr_structure_compare_ref(r, rot, &kept, &err), err);
        CHECK(!memcmp(&whole, &kept, sizeof whole));
        gr_structure_ref_destroy(r);
        free(mask);
        gr_image_destroy(moved);
        gr_image_destroy(rot);
    }
    gr_image_destroy(base);
    CHECK_DONE();
}
