/* exp_kernel: e^x in plain double arithmetic, without a branch or a table,
 * so that a loop over lanes of it becomes vector code (the lane
 * evaluators) and every build (portable, AVX2, any compiler that keeps
 * IEEE operations as written: -ffp-contract=off, no -ffast-math) gives the
 * same bits. Every evaluator takes it in place of libm's exp (a lane
 * evaluator, one call a lane); docs/NUMERICS.md ("exp") gives its error,
 * below 0.8 * 2^-52 of the result, and tests/test_exp.c measures it against
 * MPFR.
 *
 * Method: x = k ln2 + r with k = round(x / ln2), |r| <= ln2 / 2 + tiny,
 * the reduction in two steps (Cody and Waite: ln2's high part has its low
 * 21 bits zero, so k * LN2_HI is exact for |k| < 2^21); e^r by its Taylor
 * series to degree 13 (remainder below 2^-57 relative), evaluated as
 * 1 + (r + (c + r^2 q(r))), q by Estrin's scheme, c what the rounding of r
 * lost, so that the last rounding is of the sum with 1; then times 2^k in
 * two factors 2^k1 2^k2 (k1 = floor(k / 2)), each a normal
 * double, so results in the subnormal range are rounded once, by the
 * second product. Beyond -746 and 710 the result is chosen at the end
 * (+0, +inf); from 709.79 on the products overflow to +inf themselves, from
 * -745.14 down they underflow to +0. NaN gives NaN.
 *
 * Every choice is made on the bits, with masks: under the default
 * -ftrapping-math GCC keeps a ?: of doubles as a branch, and a branch in
 * the loop keeps it from vectorizing. */
#ifndef EXP_KERNEL_H
#define EXP_KERNEL_H

#include <math.h>
#include <stdint.h>

#include "common/expr/double_bits.h"

static inline __attribute__((always_inline)) double exp_kernel(double x)
{
    const double magic = 0x1.8p52; /* adding it rounds to an integer, kept in the low bits */
    const double inv_ln2 = 0x1.71547652b82fep0;
    const double ln2_hi = 0x1.62e42fee00000p-1, ln2_lo = 0x1.a39ef35793c76p-33;
    /* all bits set where the quiet comparison holds (no invalid-operation
     * flag on NaN: the tests trap on it) */
#define EXP_KERNEL_MASK(c) ((uint64_t)0 - (uint64_t)(c))
    const uint64_t far = EXP_KERNEL_MASK(__builtin_isgreater(fabs(x), 746.0));
    const uint64_t under = EXP_KERNEL_MASK(__builtin_isless(x, -746.0));
    const uint64_t over = EXP_KERNEL_MASK(__builtin_isgreater(x, 710.0));
#undef EXP_KERNEL_MASK
    /* 0 in place of an argument out of range: inf - inf below would raise
     * the invalid-operation flag */
    x = bits_double(double_bits(x) & ~far);
    const double t = x * inv_ln2 + magic;
    const double k = t - magic; /* round(x / ln2), ties to even */
    const double hi = x - k * ln2_hi, lo = k * ln2_lo; /* hi exact */
    const double r = hi - lo;
    const double c = (hi - r) - lo; /* what r's rounding lost (|lo| <= |hi| or r = 0) */
    /* q(r) = 1/2! + r/3! + ... + r^11/13! by Estrin's scheme: pairs, then
     * pairs of pairs with r^2, r^4, r^8 (a chain of 6 roundings where
     * Horner's has 24: an exact hit's evaluations wait on it, the lanes do
     * not mind) */
    const double r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
    const double q01 = 0.5 + r * 0x1.5555555555555p-3;                  /* 1/2!, 1/3! */
    const double q23 = 0x1.5555555555555p-5 + r * 0x1.1111111111111p-7; /* 1/4!, 1/5! */
    const double q45 = 0x1.6c16c16c16c17p-10 + r * 0x1.a01a01a01a01ap-13; /* 1/6!, 1/7! */
    const double q67 = 0x1.a01a01a01a01ap-16 + r * 0x1.71de3a556c734p-19; /* 1/8!, 1/9! */
    const double q89 = 0x1.27e4fb7789f5cp-22 + r * 0x1.ae64567f544e4p-26; /* 1/10!, 1/11! */
    const double qab = 0x1.1eed8eff8d898p-29 + r * 0x1.6124613a86d09p-33; /* 1/12!, 1/13! */
    const double q03 = q01 + r2 * q23, q47 = q45 + r2 * q67, q8b = q89 + r2 * qab;
    const double q = (q03 + r4 * q47) + r8 * q8b;
    const double p = 1.0 + (r + (c + r2 * q));
    /* k's two's complement from t's low bits; k1 = k >> 1 (arithmetic),
     * k2 = k - k1; for -746 <= x <= 710, |k| <= 1077 and both 2^k1 and 2^k2
     * are normal */
    const uint64_t ki = double_bits(t) - double_bits(magic);
    const uint64_t k1 = ki >> 1 | (ki & UINT64_C(0x8000000000000000));
    const uint64_t k2 = ki - k1;
    const double s1 = bits_double((k1 + 1023u) << 52);
    const double s2 = bits_double((k2 + 1023u) << 52);
    const double y = p * s1 * s2;
    /* out of range: the limits; NaN stays NaN (y is NaN then) */
    return bits_double((double_bits(y) & ~(under | over)) | (double_bits(INFINITY) & over));
}

#endif
