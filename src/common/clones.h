/* Function multi-versioning for the comparisons' vectorizable loops (the Gaussian blurs and
 * FLIP's convolutions): GR_CLONES_AVX2 before a function makes GCC or Clang compile it twice,
 * for AVX2 and for the baseline x86-64, and pick one when the program starts (an ifunc).
 * The numbers do not depend on the pick: the loops are the same operations in the same order
 * per element, AVX2 only does four elements at once where the baseline does two, and no FMA is
 * enabled (a fused multiply-add rounds once: other bits). tests/unit/test_metrics_blur.c checks
 * the bits against a plain scalar copy of the loops. Elsewhere (other CPUs, other compilers,
 * -DGR_NO_CLONES) it is empty. Measured: docs/benchmarks.md, seventeenth session. */
#ifndef GR_CLONES_H
#define GR_CLONES_H

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(GR_NO_CLONES)
#define GR_CLONES_AVX2 __attribute__((target_clones("avx2", "default")))
#else
#define GR_CLONES_AVX2
#endif

#endif
