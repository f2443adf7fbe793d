/* Shaft placement, seed eqs. 5.5.5-5.5.6 (gr_shafts_center, gr_shafts_spacing). Oracles:
 *  - P lies on y = h0 and P = E + s T with s < 0 for a viewer under water (P above E);
 *  - T equals the direction built from Snell's angles: theta_t = asin(cos(elev) / n),
 *    horizontally along the sun's travel direction;
 *  - S = K 2 d tan(fov/2) / N by hand;
 *  - a camera 1 mm below the surface and a sun 1 degree (or 0) above the horizon stay finite. */
#include "check.h"
#include "core/optics.h"
#include "core/shaftgeom.h"

#define DEG (GR_PI / 180.0)
#define N_WATER 1.333

/* I for a sun at elevation `elev` whose light travels toward azimuth `az` (from +z to +x) */
static gr_dvec3 sun_travel(double elev_deg, double az_deg)
{
    double e = elev_deg * DEG, a = az_deg * DEG;
    return gr_d3(cos(e) * sin(a), -sin(e), cos(e) * cos(a));
}

static void check_center(gr_dvec3 E, double elev, double az, double h0)
{
    gr_dvec3 I = sun_travel(elev, az), T;
    gr_dvec3 P = gr_shafts_center(E, I, h0, N_WATER, &T);
    CHECK(isfinite(P.x) && isfinite(P.y) && isfinite(P.z));
    double scale = 1.0 + fabs(h0) + gr_d3_len(E);
    CHECK_MSG(fabs(P.y - h0) <= 1e-12 * scale, "P.y %.15g h0 %g", P.y, h0);
    /* P - E parallel to T, and behind E along T (s < 0) when E is below the plane */
    gr_dvec3 d = gr_d3_sub(P, E);
    double dl = gr_d3_len(d);
    CHECK(gr_d3_len(gr_d3_cross(d, T)) <= 1e-12 * scale);
    if (E.y < h0) {
        CHECK(gr_d3_dot(d, T) < 0.0);
        CHECK(P.y > E.y);
        CHECK_NEAR(dl, (h0 - E.y) / fabs(T.y), 1e-12 * scale);
    }
    /* T from Snell: sin(theta_t) = sin(theta_i) / n with theta_i = 90 deg - elevation */
    double tt = asin(cos(elev * DEG) / N_WATER);
    gr_dvec3 Tref = gr_d3(sin(tt) * sin(az * DEG), -cos(tt), sin(tt) * cos(az * DEG));
    CHECK_MSG(gr_d3_len(gr_d3_sub(T, Tref)) <= 1e-12, "T vs Snell at elev %g az %g", elev, az);
}

static void test_center(void)
{
    double elevs[] = {90.0, 75.0, 45.0, 20.0, 5.0, 1.0};
    double azs[] = {0.0, 33.0, 180.0, -120.0};
    gr_dvec3 eyes[] = {gr_d3(0, -5, 0), gr_d3(12.5, -30, -7.25), gr_d3(1e5, -2, -1e5)};
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 3; k++) {
                check_center(eyes[k], elevs[i], azs[j], 0.0);
                check_center(eyes[k], elevs[i], azs[j], 3.5);
            }
    /* by hand: sun at the zenith, P straight above E */
    gr_dvec3 T;
    gr_dvec3 P = gr_shafts_center(gr_d3(2, -7, 3), gr_d3(0, -1, 0), 0.0, N_WATER, &T);
    CHECK(P.x == 2.0 && P.y == 0.0 && P.z == 3.0);
    CHECK(T.x == 0.0 && T.y == -1.0 && T.z == 0.0);
    /* by hand: sun light travelling at 30 deg elevation along +x; theta_t = asin(cos 30 / n);
     * E 10 m deep: P.x = -10 tan(theta_t) */
    P = gr_shafts_center(gr_d3(0, -10, 0), sun_travel(30.0, 90.0), 0.0, N_WATER, NULL);
    CHECK_NEAR(P.x, -10.0 * tan(asin(cos(30.0 * DEG) / N_WATER)), 1e-12);
    CHECK_NEAR(P.z, 0.0, 1e-12);
    /* a non-unit sun direction gives the same result */
    gr_dvec3 P2 = gr_shafts_center(gr_d3(0, -10, 0), gr_d3_scale(sun_travel(30.0, 90.0), 7.0), 0.0,
                                   N_WATER, NULL);
    CHECK_NEAR(P2.x, P.x, 1e-12);
}

static void test_extremes(void)
{
    /* camera 1 mm below the surface, sun 1 deg above the horizon (and on it) */
    double elevs[] = {1.0, 0.0};
    for (int i = 0; i < 2; i++) {
        gr_dvec3 T;
        gr_dvec3 P = gr_shafts_center(gr_d3(4, -0.001, 5), sun_travel(elevs[i], 45.0), 0.0, N_WATER, &T);
        CHECK(isfinite(P.x) && isfinite(P.y) && isfinite(P.z));
        CHECK_NEAR(P.y, 0.0, 1e-15);
        /* horizontal offset is depth tan(theta_t), below the critical-angle limit */
        double off = hypot(P.x - 4.0, P.z - 5.0);
        CHECK(off <= 0.001 * tan(asin(1.0 / N_WATER)) + 1e-15);
        CHECK(T.y < 0.0);
    }
    /* invalid input (sun below the horizon, zero vector): finite, straight down */
    gr_dvec3 T;
    gr_dvec3 P = gr_shafts_center(gr_d3(1, -3, 2), gr_d3(0.5, 0.5, 0.0), 0.0, N_WATER, &T);
    CHECK(P.x == 1.0 && P.y == 0.0 && P.z == 2.0 && T.y == -1.0);
    P = gr_shafts_center(gr_d3(1, -3, 2), gr_d3(0, 0, 0), 0.0, N_WATER, &T);
    CHECK(isfinite(P.x) && isfinite(P.y) && isfinite(P.z) && P.y == 0.0);
}

static void test_spacing(void)
{
    /* K 0.8, depth 10 m, fov 60 deg (tan 30 = 1/sqrt 3), N 10: 0.8 * 2 * 10 / sqrt(3) / 10 */
    CHECK_NEAR(gr_shafts_spacing(0.8, 10.0, 60.0 * DEG, 10), 1.6 / sqrt(3.0), 1e-15);
    /* fov 90 deg: tan 45 = 1, so S = 2 K d / N */
    CHECK_NEAR(gr_shafts_spacing(0.8, 25.0, 90.0 * DEG, 100), 0.4, 1e-15);
    /* linear in depth (the seed's argument for eq. 5.5.6) */
    CHECK_NEAR(gr_shafts_spacing(0.8, 20.0, 1.0, 10), 2.0 * gr_shafts_spacing(0.8, 10.0, 1.0, 10), 1e-15);
    /* 1 mm deep: tiny but finite and positive */
    double s = gr_shafts_spacing(0.8, 0.001, 60.0 * DEG, 10);
    CHECK(s > 0.0 && s < 1e-3);
    /* degenerate inputs give 0, never negative, Inf or NaN */
    CHECK(gr_shafts_spacing(0.8, 10.0, 1.0, 0) == 0.0);
    CHECK(gr_shafts_spacing(0.8, -1.0, 1.0, 10) == 0.0);
    CHECK(gr_shafts_spacing(0.8, 10.0, GR_PI, 10) == 0.0);
    CHECK(gr_shafts_spacing(0.8, NAN, 1.0, 10) == 0.0);
}

int main(void)
{
    test_center();
    test_extremes();
    test_spacing();
    CHECK_DONE();
}
