/* Counter-based random numbers: a generator is made from (seed, stream, index), e.g.
 * (render seed, pixel, sample), so what a sample draws never depends on which thread ran
 * it or in what order. The three words go through a SplitMix64 finalizer chain (a bijective
 * 64-bit mixer, Steele et al. 2014) and seed a PCG32 XSH-RR generator (O'Neill 2014).
 * Tests: tests/unit/test_rng.c. */
#ifndef GR_RNG_H
#define GR_RNG_H

#include <stdint.h>

typedef struct gr_rng {
    uint64_t state;   /* PCG32 LCG state */
    uint64_t inc;     /* PCG32 stream increment, always odd */
} gr_rng;

/* Generator for sample `index` of stream `stream` under `seed`. Equal inputs give equal
 * sequences; different inputs give (statistically) independent ones. */
gr_rng gr_rng_make(uint64_t seed, uint64_t stream, uint64_t index);
/* PCG32 seeded exactly as the reference pcg32_srandom_r(initstate, initseq), so the
 * generator core can be checked against the published demo output. */
gr_rng gr_rng_pcg32(uint64_t initstate, uint64_t initseq);
/* Next 32 uniformly distributed bits. */
uint32_t gr_rng_u32(gr_rng *r);
/* Uniform float in [0, 1): top 24 bits times 2^-24, so never 1.0. */
float gr_rng_float(gr_rng *r);
/* Uniform double in [0, 1) with 53 random bits, never 1.0. */
double gr_rng_double(gr_rng *r);
/* The 64-bit SplitMix64 finalizer (bijective mixer). */
uint64_t gr_mix64(uint64_t z);

/* The u32 -> float map used by gr_rng_float, exposed so its top end can be tested. */
static inline float gr_rng_u32_to_float(uint32_t u)
{
    return (float)(u >> 8) * 0x1.0p-24f;
}

#endif
