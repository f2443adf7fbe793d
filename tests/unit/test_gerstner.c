/* Gerstner surface, seed eqs. 5.5.7-5.5.8 (src/core/gerstner.c). Oracles:
 *  - hand values of one wave at phases 0, pi/2, pi (crest, node, trough) and a literal
 *    evaluation of eq. 5.5.7 at generic points;
 *  - analytic tangents and normal against central finite differences of the position
 *    (8 waves, several points and times, also at x, z ~ 1e5 m);
 *  - far from the origin, in double: a single wave shifted by a whole number of wavelengths
 *    (25000 x 4 m = 1e5 m) reproduces the near-origin point to 1e-9 m, i.e. the phase keeps
 *    its precision at 1.5e5 rad (float would lose ~1e-2 rad there);
 *  - the normal is unit, points up, and matches the upward normal (-f_x, 1, -f_z) of the
 *    height field f(x, z) obtained by finite differences of gr_gerstner_height_at;
 *  - steepness = sum a k by hand;
 *  - height_at: converges for steepness 0.5, 0.9, 0.97, the rest point maps back to (x, z)
 *    within 1e-9 m, agrees with a bisection on the 1-D map for a single wave, and returns
 *    -1 (with finite outputs) when capped, for non-finite input and for NULL water. */
#include <string.h>

#include "check.h"
#include "core/gerstner.h"
#include "core/optics.h"

#define DEG (GR_PI / 180.0)

static void add_wave(gr_water *w, double a, double lambda, double az_deg, double phi0)
{
    gr_wave *wv = &w->waves[w->n_waves++];
    memset(wv, 0, sizeof *wv);
    wv->amplitude_m = a;
    wv->wavelength_m = lambda;
    wv->direction_deg = az_deg;
    wv->phase_rad = phi0;
    wv->k = 2.0 * GR_PI / lambda;
    wv->dir[0] = sin(az_deg * DEG);
    wv->dir[1] = cos(az_deg * DEG);
    wv->omega_rad_s = sqrt(9.81 * wv->k);
}

/* Eight waves of decreasing length in assorted directions, amplitudes scaled so that the
 * steepness sum a k equals `steep`. */
static void make_sea(gr_water *w, double steep, double h0)
{
    static const double lambda[8] = {9.0, 6.5, 5.0, 3.7, 2.9, 2.1, 1.6, 1.2};
    static const double az[8] = {10.0, 37.0, -25.0, 80.0, 140.0, -70.0, 200.0, 95.0};
    static const double rel[8] = {1.0, 0.8, 0.7, 0.5, 0.45, 0.35, 0.3, 0.2};
    memset(w, 0, sizeof *w);
    w->rest_height_m = h0;
    double s = 0.0;
    for (int i = 0; i < 8; i++)
        s += rel[i] * 2.0 * GR_PI / lambda[i];
    for (int i = 0; i < 8; i++)
        add_wave(w, steep * rel[i] / s, lambda[i], az[i], 0.7 * i - 1.3);
}

static void test_single_wave_by_hand(void)
{
    gr_water w;
    memset(&w, 0, sizeof w);
    w.rest_height_m = -2.0;
    add_wave(&w, 0.25, 8.0, 0.0, 0.0); /* travels along +z, dir = (0, 1) */
    /* t = 0: phase = k z0. z0 = 0: crest, no horizontal shift */
    gr_dvec3 p = gr_gerstner_position(&w, 3.0, 0.0, 0.0);
    CHECK_NEAR(p.x, 3.0, 1e-15);
    CHECK_NEAR(p.y, -2.0 + 0.25, 1e-15);
    CHECK_NEAR(p.z, 0.0, 1e-15);
    /* z0 = lambda/4: phase pi/2, y at rest, pulled back by a */
    p = gr_gerstner_position(&w, 3.0, 2.0, 0.0);
    CHECK_NEAR(p.y, -2.0, 1e-15);
    CHECK_NEAR(p.z, 2.0 - 0.25, 1e-15);
    /* z0 = lambda/2: trough */
    p = gr_gerstner_position(&w, -1.0, 4.0, 0.0);
    CHECK_NEAR(p.y, -2.25, 1e-15);
    CHECK_NEAR(p.z, 4.0, 1e-15);
    CHECK_NEAR(p.x, -1.0, 1e-15);
    /* time: after t the phase is k z0 - w t, so the crest sits at z0 = w t / k (phase speed) */
    double t = 1.3, c = w.waves[0].omega_rad_s / w.waves[0].k;
    p = gr_gerstner_position(&w, 0.0, c * t, t);
    CHECK_NEAR(p.y, -1.75, 1e-14);
    CHECK_NEAR(p.z, c * t, 1e-14);

    /* a generic wave at generic points, eq. 5.5.7 written out here */
    memset(&w, 0, sizeof w);
    w.rest_height_m = 0.5;
    add_wave(&w, 0.3, 5.0, 30.0, 0.4);
    add_wave(&w, 0.1, 2.0, -100.0, 2.0);
    double pts[3][3] = {{0.0, 0.0, 0.0}, {1.7, -3.2, 2.5}, {-40.0, 12.0, 100.0}};
    for (int i = 0; i < 3; i++) {
        double x0 = pts[i][0], z0 = pts[i][1], tt = pts[i][2];
        double ex = x0, ey = 0.5, ez = z0;
        for (int j = 0; j < 2; j++) {
            const gr_wave *v = &w.waves[j];
            double kx = v->k * sin(v->direction_deg * DEG), kz = v->k * cos(v->direction_deg * DEG);
            double ph = kx * x0 + kz * z0 - v->omega_rad_s * tt + v->phase_rad;
            ex -= v->amplitude_m * kx / v->k * sin(ph);
            ez -= v->amplitude_m * kz / v->k * sin(ph);
            ey += v->amplitude_m * cos(ph);
        }
        p = gr_gerstner_position(&w, x0, z0, tt);
        CHECK_NEAR(p.x, ex, 1e-12);
        CHECK_NEAR(p.y, ey, 1e-12);
        CHECK_NEAR(p.z, ez, 1e-12);
    }
}

static void test_steepness(void)
{
    gr_water w;
    memset(&w, 0, sizeof w);
    CHECK(gr_gerstner_steepness(&w) == 0.0);
    add_wave(&w, 0.1, 2.0 * GR_PI, 0.0, 0.0);  /* k = 1 */
    add_wave(&w, 0.05, GR_PI, 45.0, 0.0);      /* k = 2 */
    add_wave(&w, 0.02, 0.5 * GR_PI, 90.0, 0.0); /* k = 4 */
    CHECK_NEAR(gr_gerstner_steepness(&w), 0.1 + 0.1 + 0.08, 1e-15);
    gr_water sea;
    make_sea(&sea, 0.9, 0.0);
    CHECK_NEAR(gr_gerstner_steepness(&sea), 0.9, 1e-15);
}

/* central differences of the position with step h */
static void fd_frame(const gr_water *w, double x0, double z0, double t, double h, gr_dvec3 *T,
                     gr_dvec3 *B)
{
    gr_dvec3 px = gr_gerstner_position(w, x0 + h, z0, t), mx = gr_gerstner_position(w, x0 - h, z0, t);
    gr_dvec3 pz = gr_gerstner_position(w, x0, z0 + h, t), mz = gr_gerstner_position(w, x0, z0 - h, t);
    *T = gr_d3_scale(gr_d3_sub(px, mx), 0.5 / h);
    *B = gr_d3_scale(gr_d3_sub(pz, mz), 0.5 / h);
}

static double dist(gr_dvec3 a, gr_dvec3 b) { return gr_d3_len(gr_d3_sub(a, b)); }

static void test_frame_vs_finite_differences(void)
{
    gr_water w;
    make_sea(&w, 0.8, 0.0);
    double pts[][2] = {{0.0, 0.0}, {1.3, -2.7}, {-7.5, 4.1}, {33.0, 12.5}, {-120.25, 64.5},
                       {1e5, 1e5}, {-1e5 + 0.37, 1e5 - 2.9}, {123456.7, -98765.4}};
    double times[] = {0.0, 0.83, 17.5, 3600.0};
    double worst[2] = {0.0, 0.0}; /* near, far */
    for (unsigned i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        for (unsigned j = 0; j < sizeof times / sizeof times[0]; j++) {
            double x0 = pts[i][0], z0 = pts[i][1], t = times[j];
            int far = fabs(x0) > 1e4;
            gr_dvec3 T, B, N, fT, fB;
            gr_gerstner_frame(&w, x0, z0, t, &T, &B, &N);
            fd_frame(&w, x0, z0, t, 1e-4, &fT, &fB);
            gr_dvec3 fN = gr_d3_norm(gr_d3_cross(fB, fT));
            double e = fmax(dist(T, fT), fmax(dist(B, fB), dist(N, fN)));
            if (e > worst[far])
                worst[far] = e;
            CHECK_MSG(e <= 1e-6, "frame vs FD at (%g, %g) t %g: %.3g", x0, z0, t, e);
            CHECK_NEAR(gr_d3_len(N), 1.0, 1e-12);
            CHECK(N.y > 0.0);
            /* normal orthogonal to both tangents */
            CHECK(fabs(gr_d3_dot(N, T)) <= 1e-12 && fabs(gr_d3_dot(N, B)) <= 1e-12);
        }
    }
    printf("max |analytic - FD| (tangents, normal): near origin %.2e, at 1e5 m %.2e\n", worst[0], worst[1]);
    /* NULL outputs are allowed; flat water gives the identity frame */
    gr_gerstner_frame(&w, 1.0, 2.0, 0.0, NULL, NULL, NULL);
    gr_water flat;
    memset(&flat, 0, sizeof flat);
    gr_dvec3 N;
    gr_gerstner_frame(&flat, 5.0, 6.0, 7.0, NULL, NULL, &N);
    CHECK(N.x == 0.0 && N.y == 1.0 && N.z == 0.0);
}

static void test_far_precision(void)
{
    /* one wave along +z, wavelength 4 m: 1e5 m is exactly 25000 wavelengths */
    gr_water w;
    memset(&w, 0, sizeof w);
    add_wave(&w, 0.3, 4.0, 0.0, 0.25);
    for (double z0 = -1.7; z0 < 2.0; z0 += 0.61) {
        for (double t = 0.0; t < 30.0; t += 7.3) {
            gr_dvec3 a = gr_gerstner_position(&w, 0.5, z0, t);
            gr_dvec3 b = gr_gerstner_position(&w, 1e5 + 0.5, z0 + 1e5, t);
            CHECK_NEAR(b.x - 1e5, a.x, 1e-9);
            CHECK_NEAR(b.y, a.y, 1e-9);
            CHECK_NEAR(b.z - 1e5, a.z, 1e-9);
        }
    }
}

static void test_normal_is_height_field_normal(void)
{
    /* The upward normal of y = f(x, z) is (-f_x, 1, -f_z) normalized; f from height_at in
     * world coordinates (a different route than the rest-space tangents). */
    gr_water w;
    make_sea(&w, 0.7, 1.0);
    double pts[][3] = {{0.3, 0.4, 0.0}, {-3.1, 8.2, 2.0}, {15.0, -6.0, 9.5}, {2e4 + 0.1, -3e4, 1.0}};
    for (int i = 0; i < 4; i++) {
        double x = pts[i][0], z = pts[i][1], t = pts[i][2], h = 1e-4;
        double fpx, fmx, fpz, fmz, f0, rx, rz;
        int bad = gr_gerstner_height_at(&w, x + h, z, t, &fpx, NULL, NULL) |
                  gr_gerstner_height_at(&w, x - h, z, t, &fmx, NULL, NULL) |
                  gr_gerstner_height_at(&w, x, z + h, t, &fpz, NULL, NULL) |
                  gr_gerstner_height_at(&w, x, z - h, t, &fmz, NULL, NULL) |
                  gr_gerstner_height_at(&w, x, z, t, &f0, &rx, &rz);
        CHECK(bad == 0);
        gr_dvec3 ref = gr_d3_norm(gr_d3(-(fpx - fmx) / (2 * h), 1.0, -(fpz - fmz) / (2 * h)));
        gr_dvec3 N;
        gr_gerstner_frame(&w, rx, rz, t, NULL, NULL, &N);
        CHECK_MSG(dist(N, ref) <= 1e-6, "normal vs height field at (%g, %g): %.3g", x, z, dist(N, ref));
    }
}

/* 1-D oracle: x0 - a sin(k x0 + c) = x is increasing when a k < 1; bisect it. */
static double bisect_rest(double a, double k, double c, double x)
{
    double lo = x - fabs(a) - 1.0, hi = x + fabs(a) + 1.0;
    for (int i = 0; i < 200; i++) {
        double mid = 0.5 * (lo + hi);
        if (mid - a * sin(k * mid + c) < x)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

static void test_height_at(void)
{
    double steeps[] = {0.5, 0.9, 0.97};
    for (int s = 0; s < 3; s++) {
        gr_water w;
        make_sea(&w, steeps[s], -0.5);
        int max_it = 0, n = 0;
        for (double x = -20.0; x <= 20.0; x += 1.37) {
            for (double z = -20.0; z <= 20.0; z += 1.91) {
                for (int k = 0; k < 3; k++) {
                    double t = 2.1 * k;
                    double px = x + (k == 2 ? 1e5 : 0.0), pz = z + (k == 2 ? -1e5 : 0.0);
                    double hgt, rx, rz;
                    int it = 0;
                    int rc = gr_gerstner_height_at_iter(&w, px, pz, t, 64, &hgt, &rx, &rz, &it);
                    CHECK_MSG(rc == 0, "steepness %g at (%g, %g): no convergence", steeps[s], px, pz);
                    gr_dvec3 p = gr_gerstner_position(&w, rx, rz, t);
                    CHECK_MSG(fabs(p.x - px) <= 1e-9 && fabs(p.z - pz) <= 1e-9,
                              "steepness %g: maps back to (%.12g, %.12g) not (%g, %g)", steeps[s], p.x,
                              p.z, px, pz);
                    CHECK(hgt == p.y);
                    if (it > max_it)
                        max_it = it;
                    n++;
                }
            }
        }
        printf("steepness %.2f: %d points, at most %d Newton iterations\n", steeps[s], n, max_it);
    }
    /* single wave along +x: compare with bisection on the 1-D map */
    double ak[] = {0.5, 0.9, 0.97};
    for (int s = 0; s < 3; s++) {
        gr_water w;
        memset(&w, 0, sizeof w);
        add_wave(&w, 0.0, 3.0, 90.0, 0.4);
        w.waves[0].dir[0] = 1.0; /* exactly (1, 0) so the oracle below is exactly 1-D */
        w.waves[0].dir[1] = 0.0;
        w.waves[0].amplitude_m = ak[s] / w.waves[0].k;
        double t = 0.6, a = w.waves[0].amplitude_m, k = w.waves[0].k;
        double c = -w.waves[0].omega_rad_s * t + 0.4;
        int max_it = 0;
        for (double x = -3.0; x <= 3.0; x += 0.0625) {
            double hgt, rx, rz;
            int it = 0;
            CHECK(gr_gerstner_height_at_iter(&w, x, 0.7, t, 64, &hgt, &rx, &rz, &it) == 0);
            if (it > max_it)
                max_it = it;
            double ref = bisect_rest(a, k, c, x);
            CHECK_NEAR(rx, ref, 1e-9);
            CHECK_NEAR(rz, 0.7, 1e-12);
            CHECK_NEAR(hgt, a * cos(k * ref + c), 1e-9);
        }
        printf("single wave a k = %.2f: at most %d Newton iterations\n", ak[s], max_it);
    }
}

static void test_height_at_near_fold(void)
{
    /* a k = 0.995, one wave, 20000 points over one wavelength: at the crest the Jacobian is
     * 0.005, where undamped Newton overshoots and cycles; the damped iteration must converge
     * everywhere (docs/optics.md, convergence of height_at). */
    gr_water w;
    memset(&w, 0, sizeof w);
    add_wave(&w, 0.0, 3.0, 90.0, 0.0);
    w.waves[0].dir[0] = 1.0;
    w.waves[0].dir[1] = 0.0;
    w.waves[0].amplitude_m = 0.995 / w.waves[0].k;
    int fails = 0, max_it = 0;
    for (int i = 0; i < 20000; i++) {
        double x = -1.5 + 3.0 * i / 20000.0, h, rx, rz;
        int it = 0;
        int rc = gr_gerstner_height_at_iter(&w, x, 0.0, 0.0, 64, &h, &rx, &rz, &it);
        gr_dvec3 p = gr_gerstner_position(&w, rx, rz, 0.0);
        fails += rc != 0 || fabs(p.x - x) > 1e-9;
        max_it = it > max_it ? it : max_it;
    }
    CHECK_MSG(fails == 0, "a k = 0.995: %d of 20000 points failed", fails);
    printf("single wave a k = 0.995: at most %d Newton iterations\n", max_it);
}

static void test_height_at_failure(void)
{
    gr_water w;
    make_sea(&w, 0.97, 0.0);
    double h = 123.0, rx = 1.0, rz = 1.0;
    int it = -1;
    /* a cap of one iteration cannot reach 1e-10 m on a steep sea: -1, finite outputs */
    int fails = 0;
    for (double x = 0.0; x < 5.0; x += 0.5) {
        int rc = gr_gerstner_height_at_iter(&w, x, 0.3, 0.0, 1, &h, &rx, &rz, &it);
        fails += rc == -1;
        CHECK(rc == 0 || rc == -1);
        CHECK(isfinite(h) && isfinite(rx) && isfinite(rz) && it <= 1);
    }
    CHECK(fails > 0);
    CHECK(gr_gerstner_height_at(&w, NAN, 0.0, 0.0, &h, &rx, &rz) == -1);
    CHECK(isfinite(h) && isfinite(rx) && isfinite(rz));
    CHECK(gr_gerstner_height_at(&w, 0.0, INFINITY, 0.0, &h, NULL, NULL) == -1);
    CHECK(gr_gerstner_height_at(&w, 0.0, 0.0, NAN, &h, NULL, NULL) == -1);
    CHECK(isfinite(h));
    CHECK(gr_gerstner_height_at(NULL, 0.0, 0.0, 0.0, &h, &rx, &rz) == -1);
    /* folded surface (steepness 1.6): the answer is ambiguous; it must terminate and either
     * report -1 or a point that really maps back */
    gr_water loop;
    make_sea(&loop, 1.6, 0.0);
    for (double x = -3.0; x < 3.0; x += 0.25) {
        int rc = gr_gerstner_height_at(&loop, x, 0.1, 0.0, &h, &rx, &rz);
        CHECK(isfinite(h) && isfinite(rx) && isfinite(rz));
        if (rc == 0) {
            gr_dvec3 p = gr_gerstner_position(&loop, rx, rz, 0.0);
            CHECK(fabs(p.x - x) <= 1e-9 && fabs(p.z - 0.1) <= 1e-9);
        }
    }
}

int main(void)
{
    test_single_wave_by_hand();
    test_steepness();
    test_frame_vs_finite_differences();
    test_far_precision();
    test_normal_is_height_field_normal();
    test_height_at();
    test_height_at_near_fold();
    test_height_at_failure();
    CHECK_DONE();
}
