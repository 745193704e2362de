/* Seedable random numbers that give the same stream on every platform: xoshiro256** (Blackman &
 * Vigna 2018) seeded through splitmix64. Independent streams (one per thread, per particle block,
 * per scene) come from the generator's jump function: stream k starts 2^128·k draws ahead of
 * stream 0, so streams never overlap in practice. The integer stream is bit-identical everywhere;
 * rng_normal uses log() and sqrt(), so its last bits follow the C library. */
#ifndef GRAINLAB_CORE_RNG_H
#define GRAINLAB_CORE_RNG_H

#include <stdint.h>

typedef struct rng {
    uint64_t s[4];
} rng;

/* Stream `stream` of the generator seeded by `seed`. */
void rng_seed(rng *r, uint64_t seed, uint64_t stream);

/* Advances r by 2^128 draws (xoshiro256** jump polynomial). */
void rng_jump(rng *r);

uint64_t rng_next(rng *r);

/* Uniform double in [0, 1) with 53 random bits. */
double rng_uniform(rng *r);

/* Uniform integer in [0, n), n >= 1, without modulo bias (Lemire's method). */
uint64_t rng_below(rng *r, uint64_t n);

/* Standard normal deviate (Marsaglia polar method; the spare value is discarded so the stream
 * position does not depend on how many normals were drawn before). */
double rng_normal(rng *r);

#endif
