/* Beer-Lambert attenuation, seed eq. 5.5.3 (gr_beer = exp(-c L)). Oracles: the long double
 * exponential, the semigroup property T(L1 + L2) = T(L1) T(L2), the limits c = 0 -> 1 and
 * huge c L -> exactly 0, and the absence of NaN and of denormal results for any input. */
#include <float.h>

#include "check.h"
#include "core/optics.h"

static void test_values(void)
{
    for (double tau = 0.0; tau <= 700.0; tau += 0.37) {
        double c = 0.05 + tau * 1e-3, L = tau / c;
        long double ref = expl(-(long double)c * (long double)L);
        double t = gr_beer(c, L);
        /* the product c L is rounded once (relative eps), which moves exp by tau eps */
        CHECK_MSG(fabsl(t - ref) <= (2.0L + tau) * DBL_EPSILON * ref, "tau %g: %.17g vs %.17Lg", tau, t, ref);
    }
    /* one e-folding length */
    CHECK_NEAR(gr_beer(0.5, 2.0), exp(-1.0), 1e-16);
    /* semigroup: transmittance of two legs multiplies */
    for (double L1 = 0.0; L1 < 50.0; L1 += 3.7)
        for (double L2 = 0.0; L2 < 50.0; L2 += 4.1)
            CHECK_REL(gr_beer(0.3, L1 + L2), gr_beer(0.3, L1) * gr_beer(0.3, L2), 1e-13);
}

static void test_limits(void)
{
    double Ls[] = {0.0, 1.0, 1e10, 1e300, INFINITY};
    for (int i = 0; i < 5; i++) {
        CHECK(gr_beer(0.0, Ls[i]) == 1.0); /* clear water: no attenuation at any distance */
        CHECK(gr_beer(Ls[i], 0.0) == 1.0); /* zero distance: none either */
    }
    CHECK(gr_beer(1.0, 1e6) == 0.0);
    CHECK(gr_beer(1e300, 1e300) == 0.0); /* c L overflows to inf */
    CHECK(gr_beer(INFINITY, 1.0) == 0.0);
    CHECK(gr_beer(1.0, 710.0) == 0.0);
    /* no NaN from undefined products or NaN inputs */
    double odd[][2] = {{NAN, 1.0}, {1.0, NAN}, {INFINITY, 0.0}, {-1.0, 5.0}, {2.0, -3.0}};
    for (int i = 0; i < 5; i++) {
        double t = gr_beer(odd[i][0], odd[i][1]);
        CHECK(!isnan(t) && t >= 0.0 && t <= 1.0);
    }
    /* sweep across the underflow region: every result is 0 or a normal number, never a
     * denormal, and the curve never increases */
    double prev = 1.0;
    for (double tau = 600.0; tau < 800.0; tau += 0.01) {
        double t = gr_beer(1.0, tau);
        int cls = fpclassify(t);
        CHECK_MSG(cls == FP_ZERO || cls == FP_NORMAL, "tau %g gives class %d", tau, cls);
        CHECK(t <= prev);
        prev = t;
    }
    CHECK(prev == 0.0);
    CHECK(gr_beer(1.0, 700.0) > DBL_MIN); /* still resolved well inside the normal range */
}

int main(void)
{
    test_values();
    test_limits();
    CHECK_DONE();
}
