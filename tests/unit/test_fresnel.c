/* Fresnel reflectance (gr_fresnel_exact / gr_fresnel_sp / gr_fresnel_schlick / r0).
 * Oracles, each computed here independently of the code under test:
 *  - the angle form of Fresnel's equations, R_s = sin^2(ti - tt) / sin^2(ti + tt),
 *    R_p = tan^2(ti - tt) / tan^2(ti + tt), with tt = asin(n1 sin ti / n2);
 *  - energy: R + T = 1 with T from the transmission amplitudes times the beam-area ratio;
 *  - normal incidence ((n1 - n2)/(n1 + n2))^2, grazing -> 1, Brewster R_p = 0;
 *  - reciprocity R(air->water, ti) = R(water->air, tt); TIR beyond the critical angle;
 *  - Schlick (seed eq. 5.5.2a) with the seed's R0 = 0.0204. */
#include "check.h"
#include "core/optics.h"

#define N_AIR 1.0
#define N_WATER 1.333
#define DEG (GR_PI / 180.0)

static void test_normal_incidence(void)
{
    double r0 = (N_AIR - N_WATER) / (N_AIR + N_WATER);
    r0 *= r0;
    CHECK_NEAR(gr_fresnel_exact(1.0, N_AIR, N_WATER), r0, 1e-15);
    CHECK_NEAR(gr_fresnel_exact(1.0, N_WATER, N_AIR), r0, 1e-15);
    CHECK_NEAR(gr_fresnel_r0(N_AIR, N_WATER), r0, 1e-16);
    /* the seed's value to 4 digits: R0 = 0.0204 */
    CHECK_NEAR(gr_fresnel_r0(N_AIR, N_WATER), 0.0204, 5e-5);
    /* glass, a second textbook value: n = 1.5 gives 0.04 */
    CHECK_NEAR(gr_fresnel_exact(1.0, 1.0, 1.5), 0.04, 1e-15);
    /* no interface, no reflection */
    CHECK(gr_fresnel_exact(0.3, 1.333, 1.333) == 0.0);
}

static void test_grazing(void)
{
    CHECK(gr_fresnel_exact(0.0, N_AIR, N_WATER) == 1.0);
    double prev = 0.0;
    /* R rises monotonically toward 1 as cos_i -> 0 */
    for (double c = 1.0; c > 1e-9; c *= 0.5) {
        double r = gr_fresnel_exact(c, N_AIR, N_WATER);
        CHECK(r >= prev);
        prev = r;
    }
    CHECK(prev > 1.0 - 1e-7);
    /* asymptote: with a = n1 c, b = n2 cos_t, r_s = (a - b)/(a + b) ~ -(1 - 2a/b), likewise
     * for r_p, so 1 - R ~ 2 c (n1/n2 + n2/n1) / cos_t(grazing), cos_t^2 = 1 - (n1/n2)^2 */
    double ctg = sqrt(1.0 - (N_AIR / N_WATER) * (N_AIR / N_WATER));
    double slope = 2.0 * (N_AIR / N_WATER + N_WATER / N_AIR) / ctg;
    CHECK_REL((1.0 - gr_fresnel_exact(1e-7, N_AIR, N_WATER)) / 1e-7, slope, 1e-5);
}

static void test_angle_form_and_energy(void)
{
    for (int pass = 0; pass < 2; pass++) {
        double n1 = pass == 0 ? N_AIR : N_WATER, n2 = pass == 0 ? N_WATER : N_AIR;
        double tmax = pass == 0 ? 89.99 : asin(n2 / n1) / DEG - 1e-3;
        for (double deg = 0.5; deg <= tmax; deg += 0.5) {
            double ti = deg * DEG, tt = asin(n1 * sin(ti) / n2);
            double rs_ref = sin(ti - tt) / sin(ti + tt), rp_ref = tan(ti - tt) / tan(ti + tt);
            rs_ref *= rs_ref;
            rp_ref *= rp_ref;
            double rs, rp;
            gr_fresnel_sp(cos(ti), n1, n2, &rs, &rp);
            CHECK_MSG(fabs(rs - rs_ref) <= 1e-12, "R_s %g deg n1 %g: %.15g vs %.15g", deg, n1, rs, rs_ref);
            CHECK_MSG(fabs(rp - rp_ref) <= 1e-12, "R_p %g deg n1 %g: %.15g vs %.15g", deg, n1, rp, rp_ref);
            CHECK_NEAR(gr_fresnel_exact(cos(ti), n1, n2), 0.5 * (rs_ref + rp_ref), 1e-12);
            /* transmittance from the transmission amplitudes t_s, t_p (Born & Wolf) and the
             * ratio of beam cross-sections and speeds n2 cos tt / (n1 cos ti) */
            double ci = cos(ti), ct = cos(tt);
            double ts = 2.0 * n1 * ci / (n1 * ci + n2 * ct), tp = 2.0 * n1 * ci / (n2 * ci + n1 * ct);
            double w = n2 * ct / (n1 * ci);
            CHECK_NEAR(rs + w * ts * ts, 1.0, 1e-12);
            CHECK_NEAR(rp + w * tp * tp, 1.0, 1e-12);
            CHECK_NEAR(gr_fresnel_exact(ci, n1, n2) + 0.5 * w * (ts * ts + tp * tp), 1.0, 1e-12);
        }
    }
}

static void test_brewster(void)
{
    double rs, rp;
    double tb = atan(N_WATER / N_AIR); /* 53.12 deg from air */
    gr_fresnel_sp(cos(tb), N_AIR, N_WATER, &rs, &rp);
    CHECK_NEAR(rp, 0.0, 1e-15);
    CHECK(rs > 0.01);
    CHECK_NEAR(gr_fresnel_exact(cos(tb), N_AIR, N_WATER), 0.5 * rs, 1e-15);
    /* R_p has its minimum there: larger on both sides */
    double rpl, rph;
    gr_fresnel_sp(cos(tb - 0.01), N_AIR, N_WATER, NULL, &rpl);
    gr_fresnel_sp(cos(tb + 0.01), N_AIR, N_WATER, NULL, &rph);
    CHECK(rpl > rp && rph > rp);
    tb = atan(N_AIR / N_WATER); /* 36.88 deg from water */
    gr_fresnel_sp(cos(tb), N_WATER, N_AIR, &rs, &rp);
    CHECK_NEAR(rp, 0.0, 1e-15);
    CHECK(rs > 0.01);
}

static void test_reciprocity_and_tir(void)
{
    for (double deg = 0.0; deg < 89.95; deg += 0.25) {
        double ti = deg * DEG, tt = asin(sin(ti) / N_WATER);
        double ra = gr_fresnel_exact(cos(ti), N_AIR, N_WATER);
        double rw = gr_fresnel_exact(cos(tt), N_WATER, N_AIR);
        CHECK_MSG(fabs(ra - rw) <= 1e-12, "reciprocity at %g deg: %.15g vs %.15g", deg, ra, rw);
    }
    double crit = asin(N_AIR / N_WATER);
    for (double deg = 48.7; deg <= 90.0; deg += 0.1)
        CHECK(gr_fresnel_exact(cos(deg * DEG), N_WATER, N_AIR) == 1.0);
    /* continuous at the critical angle: R -> 1 from below */
    CHECK(gr_fresnel_exact(cos(crit - 1e-7), N_WATER, N_AIR) > 0.99);
    /* inputs outside the contract stay finite and in [0, 1] */
    double bad[] = {-0.5, 1.5, NAN, INFINITY};
    for (int i = 0; i < 4; i++) {
        double r = gr_fresnel_exact(bad[i], N_AIR, N_WATER);
        CHECK(r >= 0.0 && r <= 1.0);
        r = gr_fresnel_schlick(bad[i], 0.0204);
        CHECK(r >= 0.0 && r <= 1.0);
    }
}

static void test_schlick(void)
{
    double r0 = 0.0204;
    CHECK(gr_fresnel_schlick(1.0, r0) == r0);
    CHECK(gr_fresnel_schlick(0.0, r0) == 1.0);
    /* (1 - 0.5)^5 = 1/32 */
    CHECK_NEAR(gr_fresnel_schlick(0.5, r0), r0 + (1.0 - r0) / 32.0, 1e-16);
    /* Schlick is a first-order fit at normal incidence: close there, and a few percent off
     * toward grazing (docs/optics.md has the table). It is a real approximation, not the
     * exact curve under another name: the gap exceeds 0.01 somewhere. */
    double r0w = gr_fresnel_r0(N_AIR, N_WATER), maxgap = 0.0;
    for (double d = 0.0; d <= 90.0; d += 0.1) {
        double c = cos(d * DEG);
        double gap = fabs(gr_fresnel_schlick(c, r0w) - gr_fresnel_exact(c, N_AIR, N_WATER));
        if (d <= 30.0)
            CHECK_MSG(gap <= 2e-3, "Schlick gap %.5f at %g deg", gap, d);
        if (gap > maxgap)
            maxgap = gap;
    }
    CHECK_MSG(maxgap > 0.01 && maxgap < 0.07, "max Schlick gap %.5f", maxgap);
}

int main(void)
{
    test_normal_incidence();
    test_grazing();
    test_angle_form_and_energy();
    test_brewster();
    test_reciprocity_and_tir();
    test_schlick();
    CHECK_DONE();
}
