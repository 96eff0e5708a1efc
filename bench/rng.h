/* rng: the deterministic pseudo-random generators the tests and tools share.
 * Each caller keeps its own state and seed, so a suite draws the same
 * sequence wherever it calls from. Header-only (static inline): it needs no
 * library and so serves tests, fuzz targets and bench tools alike. */
#ifndef BENCH_RNG_H
#define BENCH_RNG_H

#include <stdint.h>

/* Marsaglia's xorshift64 (shifts 13, 7, 17). *state must not be 0. */
static inline uint64_t rng_xorshift64(uint64_t *state)
{
    uint64_t x = *state;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *state = x;
}

/* Vigna's xorshift64* (shifts 12, 25, 27, then a multiply). *state must not
 * be 0. */
static inline uint64_t rng_xorshift64star(uint64_t *state)
{
    uint64_t x = *state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    *state = x;
    return x * UINT64_C(0x2545f4914f6cdd1d);
}

/* A double in [0, 1) from the top 53 bits of a draw. */
static inline double rng_unit(uint64_t draw) { return (double)(draw >> 11) * 0x1p-53; }

#endif
