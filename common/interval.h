/* interval: sound interval arithmetic in double, with outward rounding by
 * nextafter, for the operations of the scene language. */
#ifndef INTERVAL_H
#define INTERVAL_H

/* A closed interval [lo, hi] of extended reals (ends may be +-inf).
 * The NaN interval (lo and hi NaN) means "undefined everywhere": it
 * encloses nothing useful and callers must treat it as "anything".
 *
 * Rounding. Every operation whose double result may be inexact widens it
 * outward with nextafter: one ulp for + - * / sqrt (IEEE 754 rounds these
 * correctly, so the true value is within half an ulp), two ulps for the libm
 * functions exp log sin cos tan pow (glibc documents at most 1-2 ulp for
 * these; see also the MPFR cross-checks in tests/test_interval.c). We do not
 * use fesetround: it needs -frounding-math to stop the compiler from folding
 * and moving floating-point code across the mode switch, it is slow to toggle,
 * it is per-thread state, and it says nothing about libm's accuracy anyway.
 *
 * Flags. Each operation ORs INTERVAL_MAYBE_NAN into *flags when some point
 * of its input box may give NaN (sqrt/log/pow of a negative number, 0/0,
 * 0*inf, inf-inf, inf/inf, sin/cos/tan of an infinite argument). The
 * returned interval then encloses the operation's value at every point
 * where it is defined (not NaN); if it is defined nowhere the result is the
 * NaN interval. A NaN input interval gives a NaN result. Rasterizer rule: a
 * flagged or NaN result means "may contain surface: subdivide". */
typedef struct interval {
    double lo, hi;
} interval;

enum { INTERVAL_MAYBE_NAN = 1u };

/* One step outward from x (towards +inf / -inf): nextafter's result for
 * normal numbers, inlined; values below the smallest normal step to
 * +-DBL_MIN or 0 instead of into the subnormals, whose operations cost a
 * microcode assist each on x86. Still outward, so still sound. inf and NaN
 * stay. */
static inline double interval_up(double x)
{
    if (!(x < __builtin_inf())) /* +inf or NaN */
        return x;
    if (__builtin_fabs(x) < 0x1p-1022)
        return x < 0.0 ? 0.0 : 0x1p-1022;
    unsigned long long b;
    __builtin_memcpy(&b, &x, sizeof b);
    b = x > 0.0 ? b + 1 : b - 1;
    __builtin_memcpy(&x, &b, sizeof x);
    return x;
}
static inline double interval_down(double x) { return -interval_up(-x); }

/* True when i is the NaN interval. */
int interval_is_nan(interval i);
/* The NaN interval. */
interval interval_nan(void);
/* [lo, hi] widened by one ulp each way unless lo == hi is exact: used for
 * constants such as 0.78 or pi that a double cannot hold. */
interval interval_around(double v);

interval interval_neg(interval a);
interval interval_add(interval a, interval b, unsigned *flags);
interval interval_sub(interval a, interval b, unsigned *flags);
interval interval_mul(interval a, interval b, unsigned *flags);
/* Division by an interval that touches 0 gives [-inf, inf]. */
interval interval_div(interval a, interval b, unsigned *flags);
/* a*a, tight: [-2,3]^2 = [0,9]. */
interval interval_sqr(interval a, unsigned *flags);
interval interval_sqrt(interval a, unsigned *flags);
/* Overflow gives +inf, never NaN. */
interval interval_exp(interval a, unsigned *flags);
/* log(0) = -inf (a value, not NaN), log of a negative = NaN. */
interval interval_log(interval a, unsigned *flags);
interval interval_abs(interval a);
interval interval_sin(interval a, unsigned *flags);
interval interval_cos(interval a, unsigned *flags);
/* Across a pole (or wider than pi) gives [-inf, inf]. */
interval interval_tan(interval a, unsigned *flags);
interval interval_min(interval a, interval b);
interval interval_max(interval a, interval b);
/* a^p for a constant non-integer p (finite): defined for a >= 0 only,
 * pow(0, p<0) = +inf. Integer powers are multiplications (see tape.h). */
interval interval_powc(interval a, double p, unsigned *flags);
/* Smallest interval holding both. NaN interval if either is NaN. */
interval interval_hull(interval a, interval b);

#endif
