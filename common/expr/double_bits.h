/* double_bits: a double's bit pattern and back, for tests and selections
 * made on the bits (quiet: no floating-point exception, and they vectorize).
 * memcpy keeps to the aliasing rules; the compiler makes it a move. */
#ifndef DOUBLE_BITS_H
#define DOUBLE_BITS_H

#include <stdint.h>
#include <string.h>

static inline uint64_t double_bits(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

static inline double bits_double(uint64_t u)
{
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

#endif
