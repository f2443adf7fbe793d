/* Refraction, seed eq. 5.5.1 (gr_refract / gr_refract_d). Main oracle: Snell's law with
 * angles measured from the result (n1 sin(theta_i) = n2 sin(theta_t)); also unit length,
 * coplanarity with I and N, the transmitted side, the critical angle from water to air
 * (zero vector beyond it, as GLSL refract specifies) and finite results at grazing. */
#include <stdint.h>

#include "check.h"
#include "core/optics.h"

#define N_WATER 1.333
#define DEG (GR_PI / 180.0)

static uint64_t rng_state = 0x9E3779B97F4A7C15ULL;
static double urand(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 0x2545F4914F6CDD1DULL) >> 11) * 0x1.0p-53;
}

/* A random unit normal N and a unit P perpendicular to it, built in double. */
static void random_frame(gr_dvec3 *N, gr_dvec3 *P)
{
    double u = 2.0 * urand() - 1.0, phi = 2.0 * GR_PI * urand();
    double s = sqrt(1.0 - u * u);
    *N = gr_d3(s * cos(phi), u, s * sin(phi));
    gr_dvec3 a = fabs(N->x) < 0.9 ? gr_d3(1, 0, 0) : gr_d3(0, 1, 0);
    *P = gr_d3_norm(gr_d3_cross(*N, a));
}

static long double llen(gr_dvec3 v)
{
    return sqrtl((long double)v.x * v.x + (long double)v.y * v.y + (long double)v.z * v.z);
}

/* Checks one refraction of the incidence angle theta_i (radians) from n1 into n2. */
static void check_case(double theta_i, double n1, double n2, int expect_tir)
{
    gr_dvec3 N, P;
    random_frame(&N, &P);
    /* I travels toward the surface: against N, tilted by theta_i toward P. */
    gr_dvec3 I = gr_d3_add(gr_d3_scale(N, -cos(theta_i)), gr_d3_scale(P, sin(theta_i)));
    gr_dvec3 plane_n = gr_d3_norm(gr_d3_cross(I, N)); /* normal of the plane of incidence */
    double sin_i = sin(theta_i);

    for (int prec = 0; prec < 2; prec++) {
        gr_dvec3 T;
        double tol;
        if (prec == 0) {
            gr_vec3 t = gr_refract(gr_d3_to_f(I), gr_d3_to_f(N), (float)(n1 / n2));
            T = gr_v3_to_d(t);
            tol = 1e-6;
        } else {
            T = gr_refract_d(I, N, n1 / n2);
            tol = 1e-13;
        }
        CHECK(isfinite(T.x) && isfinite(T.y) && isfinite(T.z));
        if (expect_tir) {
            CHECK_MSG(T.x == 0.0 && T.y == 0.0 && T.z == 0.0,
                      "theta_i %.4f deg n1 %g n2 %g prec %d: no TIR", theta_i / DEG, n1, n2, prec);
            continue;
        }
        long double len = llen(T);
        CHECK_MSG(fabsl(len - 1.0L) <= tol, "theta_i %.4f prec %d |T| = %.12Lg", theta_i / DEG,
                  prec, len);
        /* Snell: sin(theta_t) = |T x N| (N is unit) */
        double sin_t = (double)llen(gr_d3_cross(T, N));
        CHECK_MSG(fabs(n1 * sin_i - n2 * sin_t) <= tol * n2,
                  "Snell theta_i %.4f prec %d: n1 sin_i %.12g n2 sin_t %.12g", theta_i / DEG, prec,
                  n1 * sin_i, n2 * sin_t);
        /* coplanar with I and N */
        CHECK_MSG(fabs(gr_d3_dot(T, plane_n)) <= tol, "coplanar theta_i %.4f prec %d: %.3g",
                  theta_i / DEG, prec, gr_d3_dot(T, plane_n));
        /* transmitted side (beyond the surface) and same tangential sense as I */
        CHECK(gr_d3_dot(T, N) < 0.0);
        CHECK(gr_d3_dot(T, P) >= -tol);
    }
}

static void test_air_to_water(void)
{
    for (int d = 0; d < 90; d += 1)
        check_case(d * DEG, 1.0, N_WATER, 0);
    double extra[] = {89.5, 89.9, 89.999};
    for (int i = 0; i < 3; i++)
        check_case(extra[i] * DEG, 1.0, N_WATER, 0);
    /* normal incidence passes straight through */
    gr_vec3 t = gr_refract(gr_v3(0, -1, 0), gr_v3(0, 1, 0), (float)(1.0 / N_WATER));
    CHECK(t.x == 0.0f && t.z == 0.0f && t.y == -1.0f);
    /* the seed's air index 1.05 is a slip (physics-oracles.md); with eta = 1/1.333 the
     * refracted angle of a 60 degree incidence is asin(sin 60 / 1.333) = 40.50 degrees */
    gr_dvec3 T = gr_refract_d(gr_d3(sin(60 * DEG), -cos(60 * DEG), 0), gr_d3(0, 1, 0), 1.0 / N_WATER);
    CHECK_NEAR(acos(-T.y) / DEG, asin(sin(60 * DEG) / N_WATER) / DEG, 1e-10);
}

static void test_water_to_air(void)
{
    double crit = asin(1.0 / N_WATER); /* 48.61 deg */
    for (int d = 0; d < 48; d++)
        check_case(d * DEG, N_WATER, 1.0, 0);
    check_case(crit - 1e-4, N_WATER, 1.0, 0);
    double beyond[] = {crit + 1e-4, 49.0 * DEG, 60.0 * DEG, 75.0 * DEG, 89.0 * DEG, 90.0 * DEG};
    for (int i = 0; i < 6; i++)
        check_case(beyond[i], N_WATER, 1.0, 1);
}

static void test_grazing(void)
{
    /* cos_i -> 0 from air: the transmitted ray is at the critical angle, finite and unit */
    double cs[] = {1e-3, 1e-6, 1e-9, 0.0};
    for (int i = 0; i < 4; i++) {
        double c = cs[i], s = sqrt(1.0 - c * c);
        gr_vec3 t = gr_refract(gr_v3((float)s, (float)-c, 0.0f), gr_v3(0, 1, 0), (float)(1.0 / N_WATER));
        CHECK(isfinite(t.x) && isfinite(t.y) && isfinite(t.z));
        CHECK_NEAR(gr_v3_len(t), 1.0, 1e-6);
        CHECK_NEAR(t.x, s / N_WATER, 1e-6); /* sin(theta_t) = sin(theta_i) / n */
        gr_dvec3 td = gr_refract_d(gr_d3(s, -c, 0.0), gr_d3(0, 1, 0), 1.0 / N_WATER);
        CHECK_NEAR(gr_d3_len(td), 1.0, 1e-14);
        CHECK_NEAR(td.x, s / N_WATER, 1e-14);
    }
}

static void test_float_matches_double(void)
{
    for (int i = 0; i < 1000; i++) {
        gr_dvec3 N, P;
        random_frame(&N, &P);
        double th = urand() * 89.9 * DEG;
        gr_dvec3 I = gr_d3_add(gr_d3_scale(N, -cos(th)), gr_d3_scale(P, sin(th)));
        gr_vec3 tf = gr_refract(gr_d3_to_f(I), gr_d3_to_f(N), (float)(1.0 / N_WATER));
        gr_dvec3 td = gr_refract_d(I, N, 1.0 / N_WATER);
        CHECK(fabs(tf.x - td.x) <= 1e-6 && fabs(tf.y - td.y) <= 1e-6 && fabs(tf.z - td.z) <= 1e-6);
    }
}

int main(void)
{
    test_air_to_water();
    test_water_to_air();
    test_grazing();
    test_float_matches_double();
    CHECK_DONE();
}
