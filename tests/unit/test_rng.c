/* Counter-based RNG (src/core/rng.c). Oracles:
 *  - the PCG32 core reproduces the reference pcg32-demo output for (initstate 42, initseq 54)
 *    and the mixer reproduces SplitMix64's first output for seed 1234567 (published vectors);
 *  - determinism: equal (seed, stream, index) give equal sequences, in any call order;
 *  - different streams / indices / seeds give different sequences, and the first draw of
 *    consecutive streams has balanced bits (each bit set 50% +- 5 sigma);
 *  - chi-square of 1e6 floats in 64 bins below the p = 0.001 critical value (63 dof: 103.44),
 *    both along one sequence and across 1e6 consecutive streams;
 *  - mean 0.5 within 5 sigma (sigma = sqrt(1/12 / n)); every float < 1, and the worst-case
 *    u32 (all ones) maps below 1. */
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "core/rng.h"

#define NBINS 64
#define NSAMP 1000000
#define CHI2_CRIT_63_999 103.442 /* chi-square quantile, 63 dof, p = 0.999 */

static void test_reference_vectors(void)
{
    /* pcg32-demo (pcg-random.org), pcg32_srandom_r(&rng, 42u, 54u), first six outputs */
    static const uint32_t expect[6] = {0xa15c02b7u, 0x7b47f409u, 0xba1d3330u,
                                       0x83d2f293u, 0xbfa4784bu, 0xcbed606eu};
    gr_rng r = gr_rng_pcg32(42u, 54u);
    for (int i = 0; i < 6; i++)
        CHECK_MSG(gr_rng_u32(&r) == expect[i], "pcg32 output %d", i);
    /* SplitMix64: first output for seed 1234567 = mix(1234567 + golden increment) */
    CHECK(gr_mix64(1234567u + 0x9e3779b97f4a7c15ULL) == UINT64_C(6457827717110365317));
}

static void test_determinism(void)
{
    gr_rng a = gr_rng_make(7, 12345, 3), b = gr_rng_make(7, 12345, 3);
    for (int i = 0; i < 1000; i++)
        CHECK(gr_rng_u32(&a) == gr_rng_u32(&b));
    /* order independence: draws of (stream, index) do not depend on what was made before */
    uint32_t fwd[64], bwd[64];
    for (int s = 0; s < 64; s++) {
        gr_rng r = gr_rng_make(99, (uint64_t)s, 5);
        fwd[s] = gr_rng_u32(&r);
    }
    for (int s = 63; s >= 0; s--) {
        gr_rng r = gr_rng_make(99, (uint64_t)s, 5);
        bwd[s] = gr_rng_u32(&r);
    }
    CHECK(memcmp(fwd, bwd, sizeof fwd) == 0);
}

static int same_prefix(gr_rng a, gr_rng b)
{
    for (int i = 0; i < 4; i++)
        if (gr_rng_u32(&a) != gr_rng_u32(&b))
            return 0;
    return 1;
}

static void test_streams_differ(void)
{
    int collisions = 0;
    gr_rng base = gr_rng_make(1, 0, 0);
    for (uint64_t s = 1; s < 2000; s++) {
        collisions += same_prefix(base, gr_rng_make(1, s, 0));  /* other stream */
        collisions += same_prefix(base, gr_rng_make(1, 0, s));  /* other index */
        collisions += same_prefix(base, gr_rng_make(1 + s, 0, 0)); /* other seed */
    }
    /* swapping stream and index must not give the same generator */
    collisions += same_prefix(gr_rng_make(1, 5, 9), gr_rng_make(1, 9, 5));
    CHECK(collisions == 0);
    /* adjacent streams: equal outputs at the same position happen at the 2^-32 rate only */
    int equal = 0;
    for (uint64_t s = 0; s < 1000; s++) {
        gr_rng a = gr_rng_make(3, s, 0), b = gr_rng_make(3, s + 1, 0);
        for (int i = 0; i < 100; i++)
            equal += gr_rng_u32(&a) == gr_rng_u32(&b);
    }
    CHECK(equal <= 1);
    /* bit balance of the first draw over consecutive streams (tests the mixer) */
    int counts[32] = {0};
    const int n = 100000;
    for (int s = 0; s < n; s++) {
        gr_rng r = gr_rng_make(0, (uint64_t)s, 0);
        uint32_t u = gr_rng_u32(&r);
        for (int bit = 0; bit < 32; bit++)
            counts[bit] += (u >> bit) & 1u;
    }
    double sigma = sqrt(n * 0.25);
    for (int bit = 0; bit < 32; bit++)
        CHECK_MSG(fabs(counts[bit] - 0.5 * n) <= 5.0 * sigma, "bit %d set %d of %d", bit, counts[bit], n);
}

/* chi-square, mean and max of NSAMP floats drawn by `next` */
static void check_uniform(const char *what, float (*next)(void *), void *ctx)
{
    long bins[NBINS] = {0};
    double sum = 0.0;
    float mx = 0.0f;
    for (int i = 0; i < NSAMP; i++) {
        float f = next(ctx);
        CHECK_MSG(f >= 0.0f && f < 1.0f, "%s: sample %d = %.9g", what, i, (double)f);
        if (!(f >= 0.0f && f < 1.0f))
            return;
        bins[(int)(f * NBINS)]++;
        sum += f;
        if (f > mx)
            mx = f;
    }
    double expect = (double)NSAMP / NBINS, chi2 = 0.0;
    for (int b = 0; b < NBINS; b++)
        chi2 += (bins[b] - expect) * (bins[b] - expect) / expect;
    double mean = sum / NSAMP, sigma = sqrt(1.0 / 12.0 / NSAMP);
    printf("%s: chi2 %.2f (crit %.2f), mean %.6f (%.2f sigma), max %.9f\n", what, chi2,
           CHI2_CRIT_63_999, mean, (mean - 0.5) / sigma, (double)mx);
    CHECK_MSG(chi2 < CHI2_CRIT_63_999, "%s: chi2 %.2f", what, chi2);
    CHECK_MSG(fabs(mean - 0.5) <= 5.0 * sigma, "%s: mean %.6f", what, mean);
    CHECK(mx < 1.0f);
}

static float next_seq(void *ctx) { return gr_rng_float((gr_rng *)ctx); }
static float next_stream(void *ctx)
{
    uint64_t *s = (uint64_t *)ctx;
    gr_rng r = gr_rng_make(2024, (*s)++, 0);
    return gr_rng_float(&r);
}

static void test_uniformity(void)
{
    gr_rng r = gr_rng_make(42, 0, 0);
    check_uniform("one sequence", next_seq, &r);
    uint64_t s = 0;
    check_uniform("first draw of consecutive streams", next_stream, &s);
    /* the top of the map: all-ones bits still give a float below 1 */
    CHECK(gr_rng_u32_to_float(0xffffffffu) < 1.0f);
    CHECK(gr_rng_u32_to_float(0xffffffffu) == 1.0f - 0x1.0p-24f);
    CHECK(gr_rng_u32_to_float(0u) == 0.0f);
    /* doubles: [0, 1), mean 0.5 */
    double sum = 0.0, mx = 0.0;
    for (int i = 0; i < NSAMP; i++) {
        double d = gr_rng_double(&r);
        CHECK(d >= 0.0 && d < 1.0);
        sum += d;
        mx = d > mx ? d : mx;
    }
    CHECK(fabs(sum / NSAMP - 0.5) <= 5.0 * sqrt(1.0 / 12.0 / NSAMP));
    CHECK(mx < 1.0);
}

int main(void)
{
    test_reference_vectors();
    test_determinism();
    test_streams_differ();
    test_uniformity();
    CHECK_DONE();
}
