/* sincos_kernel: sin x and cos x together in plain double arithmetic,
 * without a branch or a table, for |x| <= SINCOS_KERNEL_MAX, so that a loop
 * over lanes of it becomes vector code and every build gives the same bits
 * (as exp_kernel.h). sincos_point chooses: the kernel where it applies,
 * libm's sin and cos elsewhere (large, infinite or NaN arguments). Every
 * point evaluator and the narrow intervals' forms take sincos_point;
 * docs/NUMERICS.md ("sin and cos") gives the error, tests/test_sincos.c
 * measures it against MPFR.
 *
 * Method: x = k pi/2 + r, k = round(x 2/pi), |r| <= pi/4 + tiny; the
 * reduction in three parts (Cody and Waite; PIO2_1 and PIO2_2 have 33
 * significant bits, so k PIO2_1 and k PIO2_2 are exact for |k| < 2^20, and
 * x - k PIO2_1 is exact as the two are within a factor 2), the roundings of
 * the two other subtractions kept in a tail c (the second's by TwoSum,
 * exactly; the third's where it is the larger), so that r + c is x - k pi/2
 * to about 2^-100 relative even where x is close to a multiple of pi/2.
 * Then the minimax polynomials of sin and cos on [-pi/4, pi/4] (the
 * coefficients of the classic fdlibm kernels), with the tail's first-order
 * terms; the quadrant k mod 4 swaps them and sets their signs, on the bits. */
#ifndef SINCOS_KERNEL_H
#define SINCOS_KERNEL_H

#include <math.h>
#include <stdint.h>

#include "common/expr/double_bits.h"

/* The kernel's range: |k| < 2^17 (well inside the exact products' 2^20). */
#define SINCOS_KERNEL_MAX 0x1p17

/* 1 when the kernel serves x (a quiet comparison: NaN gives 0). */
static inline int sincos_kernel_serves(double x)
{
    return __builtin_islessequal(fabs(x), SINCOS_KERNEL_MAX);
}

/* sin x and cos x for |x| <= SINCOS_KERNEL_MAX; any other x (infinite, NaN)
 * gives those of 0, without a floating-point exception. */
static inline __attribute__((always_inline)) void sincos_kernel(double x, double *sp, double *cp)
{
    x = bits_double(double_bits(x) & ((uint64_t)0 - (uint64_t)sincos_kernel_serves(x)));
    const double magic = 0x1.8p52; /* adding it rounds to an integer, kept in the low bits */
    const double two_over_pi = 0x1.45f306dc9c883p-1;
    const double pio2_1 = 0x1.921fb54400000p0, pio2_2 = 0x1.0b4611a600000p-34,
                 pio2_3 = 0x1.3198a2e037073p-69;
    const double t = x * two_over_pi + magic;
    const double k = t - magic;
    const double t1 = x - k * pio2_1;   /* exact */
    const double w2 = k * pio2_2;       /* exact */
    const double t2 = t1 - w2;
    const double b2 = t2 - t1;          /* TwoSum: e2 is t2's rounding error, exactly */
    const double e2 = (t1 - (t2 - b2)) - (w2 + b2);
    const double w3 = k * pio2_3;
    const double r = t2 - w3;
    const double c = ((t2 - r) - w3) + e2;
    const double z = r * r, v = z * r;
    /* sin(r + c) = r + v (S1 + z P(z)) + c (1 - z / 2) */
    const double ps = 0x1.111111110f8a6p-7 +
                      z * (-0x1.a01a019c161d5p-13 +
                           z * (0x1.71de357b1fe7dp-19 +
                                z * (-0x1.ae5e68a2b9cebp-26 + z * 0x1.5d93a5acfd57cp-33)));
    const double s = r - ((z * (0.5 * c - v * ps) - c) - v * -0x1.5555555555549p-3);
    /* cos(r + c) = 1 - z / 2 + z^2 Q(z) - r c, the 1 - z / 2 in two parts */
    const double qc = z * (0x1.555555555554cp-5 +
                           z * (-0x1.6c16c16c15177p-10 +
                                z * (0x1.a01a019cb159p-16 +
                                     z * (-0x1.27e4f809c52adp-22 +
                                          z * (0x1.1ee9ebdb4b1c4p-29 + z * -0x1.8fae9be8838d4p-37)))));
    const double hz = 0.5 * z, w = 1.0 - hz;
    const double co = w + (((1.0 - w) - hz) + (z * qc - r * c));
    /* quadrant n = k mod 4: (s, c), (c, -s), (-s, -c), (-c, s) */
    const uint64_t n = double_bits(t) - double_bits(magic);
    const uint64_t swap = (uint64_t)0 - (n & 1);
    const uint64_t bs = double_bits(s), bc = double_bits(co);
    const uint64_t sin_bits = (bs & ~swap) | (bc & swap);
    const uint64_t cos_bits = (bc & ~swap) | (bs & swap);
    *sp = bits_double(sin_bits ^ ((n & 2) << 62));
    *cp = bits_double(cos_bits ^ (((n + 1) & 2) << 62));
}

/* sin x and cos x: the kernel, else libm. */
static inline void sincos_point(double x, double *s, double *c)
{
    if (sincos_kernel_serves(x)) {
        sincos_kernel(x, s, c);
        return;
    }
    *s = sin(x);
    *c = cos(x);
}

/* sincos_point of x[l < n ? l : 0] for the w <= 16 lanes l < w (w a constant
 * where it is inlined: the kernel's loop is vector code), the arguments
 * the kernel does not serve by libm. */
static inline __attribute__((always_inline)) void
sincos_point_lanes(unsigned w, unsigned n, const double *x, double *restrict s, double *restrict c)
{
    double xs[16];
    unsigned far = 0;
    for (unsigned l = 0; l < w; l++)
        xs[l] = x[l < n ? l : 0];
    for (unsigned l = 0; l < w; l++)
        sincos_kernel(xs[l], &s[l], &c[l]);
    for (unsigned l = 0; l < w; l++)
        far |= (unsigned)!sincos_kernel_serves(xs[l]) << l;
    for (; far; far &= far - 1) {
        const unsigned l = (unsigned)__builtin_ctz(far);
        sincos_point(xs[l], &s[l], &c[l]);
    }
}

#endif
