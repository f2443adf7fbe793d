/* Vector math (src/core/vec.h) against algebraic identities evaluated in double or long
 * double: basis cross products, anti-commutativity, orthogonality, Lagrange's identity,
 * the triple product expansion, and normalization (unit length, direction kept, zero stays
 * zero, tiny and huge vectors still normalize). */
#include <float.h>
#include <stdint.h>

#include "check.h"
#include "core/vec.h"

/* Test-local xorshift64* so the inputs do not depend on the module under test. */
static uint64_t rng_state = 0x2545F4914F6CDD1DULL;
static double urand(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 0x2545F4914F6CDD1DULL) >> 11) * 0x1.0p-53;
}
static gr_vec3 rand_v3(double scale)
{
    return gr_v3((float)((2.0 * urand() - 1.0) * scale), (float)((2.0 * urand() - 1.0) * scale),
                 (float)((2.0 * urand() - 1.0) * scale));
}
static long double ldot(gr_vec3 a, gr_vec3 b)
{
    return (long double)a.x * b.x + (long double)a.y * b.y + (long double)a.z * b.z;
}

static void test_basis(void)
{
    gr_vec3 ex = gr_v3(1, 0, 0), ey = gr_v3(0, 1, 0), ez = gr_v3(0, 0, 1);
    gr_vec3 c = gr_v3_cross(ex, ey); /* right-handed: x cross y = z */
    CHECK(c.x == 0.0f && c.y == 0.0f && c.z == 1.0f);
    c = gr_v3_cross(ey, ez);
    CHECK(c.x == 1.0f && c.y == 0.0f && c.z == 0.0f);
    c = gr_v3_cross(ez, ex);
    CHECK(c.x == 0.0f && c.y == 1.0f && c.z == 0.0f);
    gr_dvec3 d = gr_d3_cross(gr_d3(0, 0, 1), gr_d3(1, 0, 0)); /* z cross x = y: Gerstner's up */
    CHECK(d.x == 0.0 && d.y == 1.0 && d.z == 0.0);
    CHECK(gr_v3_dot(ex, ey) == 0.0f && gr_v3_dot(ez, ez) == 1.0f);
    gr_vec3 m = gr_v3_madd(gr_v3(1, 2, 3), gr_v3(4, 5, 6), 2.0f);
    CHECK(m.x == 9.0f && m.y == 12.0f && m.z == 15.0f);
    gr_vec3 s = gr_v3_sub(gr_v3_add(gr_v3(1, 2, 3), gr_v3(4, 5, 6)), gr_v3(4, 5, 6));
    CHECK(s.x == 1.0f && s.y == 2.0f && s.z == 3.0f);
}

static void test_identities(void)
{
    for (int i = 0; i < 2000; i++) {
        gr_vec3 a = rand_v3(10.0), b = rand_v3(10.0), c = rand_v3(10.0);
        long double na2 = ldot(a, a), nb2 = ldot(b, b), nc2 = ldot(c, c);
        long double scale = na2 * nb2; /* |a|^2 |b|^2 sets the size of the quantities below */
        gr_vec3 axb = gr_v3_cross(a, b), bxa = gr_v3_cross(b, a);
        /* anti-commutativity is exact in IEEE arithmetic */
        CHECK(axb.x == -bxa.x && axb.y == -bxa.y && axb.z == -bxa.z);
        /* a x b is orthogonal to a and b (relative to |a| |b| |a|) */
        CHECK(fabsl(ldot(axb, a)) <= 1e-5L * sqrtl(scale * na2));
        CHECK(fabsl(ldot(axb, b)) <= 1e-5L * sqrtl(scale * nb2));
        /* Lagrange: |a x b|^2 + (a.b)^2 = |a|^2 |b|^2 */
        long double lag = ldot(axb, axb) + ldot(a, b) * ldot(a, b);
        CHECK_MSG(fabsl(lag - scale) <= 1e-5L * scale, "lagrange %Lg vs %Lg", lag, scale);
        /* dot agrees with the long double dot */
        CHECK(fabsl((long double)gr_v3_dot(a, b) - ldot(a, b)) <= 1e-6L * sqrtl(scale));
        /* a x (b x c) = b (a.c) - c (a.b) */
        gr_vec3 lhs = gr_v3_cross(a, gr_v3_cross(b, c));
        long double ac = ldot(a, c), ab = ldot(a, b);
        long double tol = 1e-5L * sqrtl(na2 * nb2 * nc2);
        CHECK(fabsl(lhs.x - (b.x * ac - c.x * ab)) <= tol);
        CHECK(fabsl(lhs.y - (b.y * ac - c.y * ab)) <= tol);
        CHECK(fabsl(lhs.z - (b.z * ac - c.z * ab)) <= tol);
        /* the double versions on the same inputs */
        gr_dvec3 da = gr_v3_to_d(a), db = gr_v3_to_d(b);
        gr_dvec3 dc = gr_d3_cross(da, db);
        CHECK(fabs(gr_d3_dot(dc, da)) <= 1e-12 * (double)sqrtl(scale * na2));
        CHECK(fabs(gr_d3_dot(dc, dc) + gr_d3_dot(da, db) * gr_d3_dot(da, db) - (double)scale) <=
              1e-12 * (double)scale);
    }
}

static void check_unit_f(gr_vec3 a, const char *what)
{
    gr_vec3 n = gr_v3_norm(a);
    long double l = sqrtl(ldot(n, n));
    CHECK_MSG(fabsl(l - 1.0L) <= 1e-6L, "%s: |norm| = %.9Lg", what, l);
    /* same direction: parallel (cross ~ 0) and not reversed (dot > 0) */
    long double la = sqrtl(ldot(a, a));
    if (la > 0.0L && isfinite((double)la)) {
        gr_vec3 au = gr_v3((float)(a.x / la), (float)(a.y / la), (float)(a.z / la));
        gr_vec3 c = gr_v3_cross(n, au);
        CHECK_MSG(sqrtl(ldot(c, c)) <= 1e-6L, "%s: direction changed", what);
    }
    CHECK_MSG(gr_v3_dot(n, a) > 0.0f || ldot(n, a) > 0.0L, "%s: reversed", what);
}

static void test_norm(void)
{
    for (int i = 0; i < 1000; i++)
        check_unit_f(rand_v3(100.0), "random");
    gr_vec3 z = gr_v3_norm(gr_v3(0, 0, 0));
    CHECK(z.x == 0.0f && z.y == 0.0f && z.z == 0.0f); /* zero stays zero, no NaN */
    gr_vec3 nz = gr_v3_norm(gr_v3(-0.0f, 0.0f, -0.0f));
    CHECK(!isnan(nz.x) && !isnan(nz.y) && !isnan(nz.z) && nz.x == 0.0f);
    CHECK(gr_v3_len(gr_v3(0, 0, 0)) == 0.0f);
    CHECK(gr_v3_len(gr_v3(3, 4, 12)) == 13.0f);
    /* |v|^2 of these under/overflows float: they must still normalize */
    check_unit_f(gr_v3(1e-30f, -2e-30f, 2e-30f), "tiny");
    check_unit_f(gr_v3(1e-44f, 0.0f, 0.0f), "denormal");
    check_unit_f(gr_v3(1e30f, 2e30f, -2e30f), "huge");
    check_unit_f(gr_v3(FLT_MAX, FLT_MAX, 0.0f), "max");
    gr_vec3 h = gr_v3_norm(gr_v3(0.0f, 3e25f, 4e25f));
    CHECK_NEAR(h.y, 0.6, 1e-7);
    CHECK_NEAR(h.z, 0.8, 1e-7);

    /* double */
    gr_dvec3 dz = gr_d3_norm(gr_d3(0, 0, 0));
    CHECK(dz.x == 0.0 && dz.y == 0.0 && dz.z == 0.0);
    gr_dvec3 cases[] = {gr_d3(1e-200, 2e-200, -2e-200), gr_d3(1e200, -2e200, 2e200),
                        gr_d3(1.0, 2.0, -2.0), gr_d3(5e-324, 0.0, 0.0)};
    for (int i = 0; i < 4; i++) {
        gr_dvec3 n = gr_d3_norm(cases[i]);
        CHECK_NEAR(gr_d3_len(n), 1.0, 1e-15);
    }
    gr_dvec3 n = gr_d3_norm(cases[1]);
    CHECK_NEAR(n.x, 1.0 / 3.0, 1e-15);
    CHECK_NEAR(n.y, -2.0 / 3.0, 1e-15);
    CHECK_NEAR(n.z, 2.0 / 3.0, 1e-15);
    CHECK(gr_d3_len(gr_d3(2, 3, 6)) == 7.0);
}

int main(void)
{
    test_basis();
    test_identities();
    test_norm();
    CHECK_DONE();
}
