/* GRAINLAB_CLONES: a hot kernel compiled twice, for the portable baseline (x86-64: SSE2) and for
 * AVX2, the loader picking the clone this CPU runs (GCC's target_clones: an ifunc, resolved once
 * when the program starts). A portable build then runs four double lanes per vector instruction
 * on the machines that have them, with the same bits as the baseline: the build has no fused
 * multiply-adds (-ffp-contract=off, and GCC's avx2 target does not imply FMA), each lane does the
 * scalar IEEE operation, and the only vector reductions (omp simd) are exact in any order: sums
 * of 0s and 1s (or of zeros), minima, maxima. A floating-point sum as an omp simd reduction would
 * break that (its order follows the vector width): tests/cli/isa_same_bits.sh compares the two
 * clones' runs of every engine. Where the hot kernels are: the MPM step's stages (STAGE in
 * src/mpm/transfer.c, contact.c and stress.c) and DEM's pair kernel, force gather, walls and
 * integration passes. DSMC has none: its clones run no faster (a step of scattered memory
 * accesses).
 *
 * Empty (one compilation) elsewhere: another compiler or architecture, a build whose -march
 * already has AVX2 (GRAINLAB_MARCH), or GRAINLAB_NO_CLONES (CMake GRAINLAB_CLONES=OFF, which the
 * sanitizer build uses so that the suite runs the baseline code there). A function with the
 * attribute is never inlined; the omp parallel regions written in its body are cloned with it,
 * but not those of an always_inline function it calls (they are outlined before the cloning:
 * put the attribute on that function, or check `nm grainlab | grep avx2`). */
#ifndef GRAINLAB_CORE_CLONES_H
#define GRAINLAB_CORE_CLONES_H

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX2__) &&       \
    !defined(GRAINLAB_NO_CLONES)
#define GRAINLAB_CLONES __attribute__((target_clones("avx2", "default")))
#define GRAINLAB_CLONED 1
#else
#define GRAINLAB_CLONES
#define GRAINLAB_CLONED 0
#endif

/* The code the hot kernels run in this process, for `grainlab --version`: the clone the loader
 * picks (the same test as the ifunc's), or the one compilation of a build without clones. */
static inline const char *clones_kernels(void)
{
#if GRAINLAB_CLONED
    return __builtin_cpu_supports("avx2") ? "AVX2, picked at run time" : "SSE2, picked at run time";
#elif defined(__AVX2__)
    return "AVX2, built for it";
#else
    return "one compilation, no clones";
#endif
}

#endif
