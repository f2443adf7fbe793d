/* Counter-based RNG: SplitMix64 mixing of (seed, stream, index) into a PCG32 state.
 * See rng.h for the contract. */
#include "core/rng.h"

#define GR_GOLDEN64 0x9e3779b97f4a7c15ULL /* 2^64 / golden ratio, SplitMix64's increment */
#define GR_PCG_MULT 6364136223846793005ULL /* Knuth's MMIX LCG multiplier, used by PCG32 */

uint64_t gr_mix64(uint64_t z)
{
    /* SplitMix64 finalizer (Steele, Lea, Flood 2014): xor-shift-multiply rounds with
     * full avalanche; every step is invertible, so distinct inputs stay distinct. */
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static void pcg32_step(gr_rng *r)
{
    r->state = r->state * GR_PCG_MULT + r->inc;
}

gr_rng gr_rng_pcg32(uint64_t initstate, uint64_t initseq)
{
    /* Reference PCG32 seeding: choose the stream, advance once, add the state, advance. */
    gr_rng r;
    r.state = 0u;
    r.inc = (initseq << 1) | 1u;
    pcg32_step(&r);
    r.state += initstate;
    pcg32_step(&r);
    return r;
}

gr_rng gr_rng_make(uint64_t seed, uint64_t stream, uint64_t index)
{
    /* Chain the mixer so that each word changes every bit of the result; the offsets by
     * multiples of the golden increment keep (0, 0, 0) away from the mixer's fixed point 0. */
    uint64_t h = gr_mix64(seed + GR_GOLDEN64);
    h = gr_mix64(h ^ (stream + 2u * GR_GOLDEN64));
    h = gr_mix64(h ^ (index + 3u * GR_GOLDEN64));
    /* The stream selector comes from a second, differently offset mix of the same hash,
     * so two inputs that collide on one 64-bit word still differ in the other. */
    uint64_t seq = gr_mix64(h + 4u * GR_GOLDEN64);
    return gr_rng_pcg32(h, seq);
}

uint32_t gr_rng_u32(gr_rng *r)
{
    /* PCG32 XSH-RR output: xorshift the high bits down, then a data-dependent rotation. */
    uint64_t old = r->state;
    pcg32_step(r);
    uint32_t xorshifted = (uint32_t)(((old >> 18) ^ old) >> 27);
    uint32_t rot = (uint32_t)(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

float gr_rng_float(gr_rng *r)
{
    return gr_rng_u32_to_float(gr_rng_u32(r));
}

double gr_rng_double(gr_rng *r)
{
    /* 27 + 26 = 53 bits: every double in [0, 1) on a 2^-53 grid, 1.0 excluded. */
    uint64_t hi = gr_rng_u32(r) >> 5;
    uint64_t lo = gr_rng_u32(r) >> 6;
    return (double)((hi << 26) | lo) * 0x1.0p-53;
}
