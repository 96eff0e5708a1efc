/* interval_lanes: the fast paths of interval_add, interval_mul and
 * interval_sqr in a form that vectorises: bit-pattern tests (no
 * floating-point exception, no branch) of when that path applies, and its
 * bit steps. Where il_normal holds for a sum's ends, interval_add's result
 * is [il_step_down(lo), il_step_up(hi)]; where the four ends of two factors
 * are finite and the least and greatest of the four products are normal,
 * interval_mul's is the same of those. Used by the lane interval evaluators
 * (tape_ilanes.c, tape_iglanes.c) and the rasterizer's mean-value forms. */
#ifndef INTERVAL_LANES_H
#define INTERVAL_LANES_H

#include <stdint.h>

#include "common/expr/double_bits.h"

/* 1 when x is neither infinite nor NaN, else 0 (a quiet test). */
static inline uint64_t il_finite(double x) { return ((double_bits(x) >> 52) & 0x7ff) != 0x7ff; }
/* 1 when x is finite and |x| >= DBL_MIN (not 0, not subnormal), else 0. */
static inline uint64_t il_normal(double x) { return ((double_bits(x) >> 52) & 0x7ff) - 1 < 0x7fe; }
/* interval__up_finite and interval__down_finite of such a normal x: the
 * bit step alone. */
static inline double il_step_up(double x)
{
    uint64_t u = double_bits(x);
    return bits_double(u + (1 - ((u >> 63) << 1)));
}
static inline double il_step_down(double x)
{
    uint64_t u = double_bits(x);
    return bits_double(u - (1 - ((u >> 63) << 1)));
}
/* m ? a : b for m 0 or 1, on the bit patterns (vector code without
 * branches). */
static inline double il_sel(uint64_t m, double a, double b)
{
    return bits_double((double_bits(a) & (0 - m)) | (double_bits(b) & (m - 1)));
}
static inline double il_min(double a, double b) { return a < b ? a : b; } /* as interval__min2 */
static inline double il_max(double a, double b) { return a > b ? a : b; }


#include "common/expr/exp_kernel.h"
#include "common/expr/interval.h"

/* interval_add(a, b) where its fast path applies; *ok becomes 0 where it
 * does not (the result is then not interval_add's). */
static inline interval il_add(interval a, interval b, uint64_t *ok)
{
    double lo = a.lo + b.lo, hi = a.hi + b.hi;
    *ok &= il_normal(lo) & il_normal(hi);
    interval r = {il_step_down(lo), il_step_up(hi)};
    return r;
}

/* interval_exp of [lo, hi] where its plain path applies: both ends' e^x
 * (exp_kernel) normal and two bit steps from the limits, the lower at least
 * 2^-1021 and the upper below 2^1023; the result is then their two bit steps
 * outward (dn2_pos, up2_pos), returned with 1, else 0 (*rl, *rh are then not
 * interval_exp's; a NaN end fails the test). */
static inline __attribute__((always_inline)) uint64_t il_exp_ends(double lo, double hi,
                                                                  double *rl, double *rh)
{
    const uint64_t el = double_bits(exp_kernel(lo)), eh = double_bits(exp_kernel(hi));
    const uint64_t min_lo = double_bits(0x1p-1021), min_hi = double_bits(0x1p-1022);
    *rl = bits_double(el - 2);
    *rh = bits_double(eh + 2);
    /* positive doubles order as their bits; NaN's bits lie above +inf's */
    return (el - min_lo < double_bits(INFINITY) - min_lo) &
           (eh - min_hi < double_bits(0x1p1023) - min_hi);
}

/* 1 when x is +0 or -0. */
static inline uint64_t il_zero(double x) { return (double_bits(x) << 1) == 0; }

/* interval_mul(a, b) likewise; with finite ends, a factor that is exactly
 * [0, 0] gives interval_mul's [+0, +0] (a zero end from a zero factor stays
 * 0: the partials of a term without that variable). */
/* interval_sqr([al, ah]) where its fast path applies (finite ends, normal
 * results but a lower 0 of a straddling a); *ok becomes 0 where not. */
INTERVAL_INLINE void il_sqr_ends(double al, double ah, double *rlo, double *rhi, uint64_t *ok)
{
    uint64_t f = il_finite(al) & il_finite(ah);
    double x = il_sel(f, al, 1.0), y = il_sel(f, ah, 1.0);
    double m1 = x * x, m2 = y * y;
    uint64_t strad = (uint64_t)(x < 0.0) & (uint64_t)(y > 0.0);
    double h = il_max(m1, m2), l0 = il_min(m1, m2);
    *ok &= f & il_normal(h) & (strad | il_normal(l0));
    *rlo = il_sel(strad, 0.0, il_step_down(l0));
    *rhi = il_step_up(h);
}

/* il_mul on the ends (the lane loops' form): [*rlo, *rhi] = [al, ah] x
 * [bl, bh] where *ok stays 1. */
INTERVAL_INLINE void il_mul_ends(double al, double ah, double bl, double bh, double *rlo,
                                 double *rhi, uint64_t *ok)
{
    uint64_t f = il_finite(al) & il_finite(ah) & il_finite(bl) & il_finite(bh);
    uint64_t z = (il_zero(al) & il_zero(ah)) | (il_zero(bl) & il_zero(bh));
    al = il_sel(f, al, 1.0);
    ah = il_sel(f, ah, 1.0);
    bl = il_sel(f, bl, 1.0);
    bh = il_sel(f, bh, 1.0);
    double p1 = al * bl, p2 = al * bh, p3 = ah * bl, p4 = ah * bh;
    double lo = il_min(il_min(p1, p2), il_min(p3, p4)), hi = il_max(il_max(p1, p2), il_max(p3, p4));
    *ok &= f & (z | (il_normal(lo) & il_normal(hi)));
    *rlo = il_sel(z, 0.0, il_step_down(lo));
    *rhi = il_sel(z, 0.0, il_step_up(hi));
}

INTERVAL_INLINE interval il_mul(interval a, interval b, uint64_t *ok)
{
    interval r;
    il_mul_ends(a.lo, a.hi, b.lo, b.hi, &r.lo, &r.hi, ok);
    return r;
}

#endif
