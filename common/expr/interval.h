/* interval: sound interval arithmetic in double, with outward rounding by
 * bit steps (interval_next_up / interval_next_down), for the operations of
 * the scene language. */
#ifndef INTERVAL_H
#define INTERVAL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* A closed interval [lo, hi] of extended reals (ends may be +-inf).
 * The NaN interval (lo and hi NaN) means "undefined everywhere": it
 * encloses nothing useful and callers must treat it as "anything".
 *
 * Rounding. Every operation whose double result may be inexact widens it
 * outward, the lower end down and the upper end up, by steps of at least
 * one ulp (interval_next_down / interval_next_up): one step for + - * /
 * sqrt (IEEE 754 rounds these correctly, so the true value is within half
 * an ulp), two steps for exp (our own, exp_kernel.h: below one ulp, measured
 * against MPFR in tests/test_exp.c) and the libm functions log sin cos tan
 * pow (glibc documents at most 1-2 ulp for these; see also the MPFR
 * cross-checks in tests/test_interval.c). Each operation below states its rounding. We do not
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

/* ---- Out-of-line part (interval.c): the rarer and libm operations. ---- */

/* [next_down(v), next_up(v)]: one step each way, always. For a constant
 * such as 0.78 or pi that the double v only approximates; the parser makes
 * an exact literal [v, v] itself instead. */
interval interval_around(double v);

/* a / b, the quotient ends rounded one step outward. A divisor that touches
 * 0 gives [-inf, inf] (flagged when a touches 0 too: 0/0); one that is
 * exactly [0, 0] gives the NaN interval (no finite quotient anywhere). */
interval interval_div(interval a, interval b, unsigned *flags);
/* sqrt(a), ends rounded one step outward, the lower end clamped at 0. The
 * negative part of a is flagged and dropped; all of a negative is NaN. */
interval interval_sqrt(interval a, unsigned *flags);
/* exp(a), ends rounded two steps outward (exp_kernel.h's e^x, below one ulp
 * from the true value: docs/NUMERICS.md). Overflow gives +inf, never NaN;
 * subnormal ends widen to 0 (lower) and DBL_MIN (upper). */
interval interval_exp(interval a, unsigned *flags);
/* log(a), ends rounded two steps outward. log(0) = -inf (a value, not NaN);
 * the negative part of a is flagged and dropped; all of a negative is NaN. */
interval interval_log(interval a, unsigned *flags);
/* sin(a) and cos(a): ends rounded two steps outward, then clamped to
 * [-1, 1]; an extremum inside a sets that end to 1 or -1. With an end
 * beyond |1e8|, or 6 wide or more, the result is [-1, 1]. */
interval interval_sin(interval a, unsigned *flags);
interval interval_cos(interval a, unsigned *flags);
/* Enclosures of sin and cos over a (either pointer may be NULL). Up to a
 * quarter wide, from one sincos at a's midpoint and the second-order
 * remainder (sound, a little wider than interval_sin's, at a fraction of
 * its cost); otherwise interval_sin's and interval_cos's. The rasterizer's
 * and the exact renderer's interval evaluators use this. */
void interval_sincos(interval a, interval *so, interval *co, unsigned *flags);
/* tan(a), ends rounded two steps outward. Across a pole, 3 wide or more,
 * or with an end beyond |1e8|, the result is [-inf, inf]. */
interval interval_tan(interval a, unsigned *flags);
/* a^p for a constant non-integer p (finite): defined for a >= 0 only,
 * pow(0, p<0) = +inf. Ends rounded two steps outward, the lower clamped at
 * 0. Integer powers are multiplications (see tape.h). */
interval interval_powc(interval a, double p, unsigned *flags);

/* ---- Inline part: the cheap operations the evaluators call most. ----
 * Names with a double underscore are internal helpers, not for use outside
 * interval.[ch]. */

/* Inlined even where the compiler would rather call: a call costs as much
 * as the operation in the evaluators' loops. */
#if defined(__GNUC__)
#define INTERVAL_INLINE static inline __attribute__((always_inline))
#else
#define INTERVAL_INLINE static inline
#endif

/* At least nextafter(x, +inf) for a finite x, without the libm call (it was
 * the hot spot of every interval operation): step the bit pattern. Zero and
 * subnormals step to 0 or DBL_MIN (2^-1022) instead: a wider but still
 * outward step that keeps subnormals, ~100 times slower on x86, from
 * spreading through the evaluation. */
static inline double interval__up_finite(double x)
{
    if (fabs(x) < 0x1p-1022)
        return x < 0.0 ? 0.0 : 0x1p-1022;
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u += 1 - ((u >> 63) << 1); /* away from 0 when positive, towards it when negative */
    memcpy(&x, &u, sizeof x);
    return x;
}
/* At least nextafter(x, -inf) for a finite x: -interval__up_finite(-x), bit
 * for bit, without the two negations. */
static inline double interval__down_finite(double x)
{
    if (fabs(x) < 0x1p-1022)
        return x > 0.0 ? -0.0 : -0x1p-1022;
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u -= 1 - ((u >> 63) << 1); /* towards 0 when positive, away from it when negative */
    memcpy(&x, &u, sizeof x);
    return x;
}

/* One outward step for any x: interval__up_finite (interval__down_finite)
 * for a finite x; NaN and +inf (-inf) stay. */
static inline double interval_next_up(double x)
{
    return x < INFINITY ? interval__up_finite(x) : x;
}
static inline double interval_next_down(double x)
{
    return x > -INFINITY ? interval__down_finite(x) : x;
}

static inline double interval__min2(double a, double b) { return a < b ? a : b; } /* no NaN */
static inline double interval__max2(double a, double b) { return a > b ? a : b; }
static inline int interval__has_zero(interval a) { return a.lo <= 0.0 && a.hi >= 0.0; }
static inline int interval__has_inf(interval a) { return isinf(a.lo) || isinf(a.hi); }
static inline int interval__isnan(interval a) { return a.lo != a.lo || a.hi != a.hi; }
static inline interval interval__mk(double lo, double hi) { interval r = {lo, hi}; return r; }
static inline interval interval__nan_flag(unsigned *flags)
{
    *flags |= INTERVAL_MAYBE_NAN;
    return interval__mk(NAN, NAN);
}

/* interval_sincos's narrow form, shared with the lane evaluators (the same
 * operations, so the same bits). Up to this width it applies: there its
 * excess width, about h^2 / 2 for a half-width h, is a few percent of the
 * range at most, and one sincos replaces the libm calls at both ends and
 * the extremum tests. NaN and infinite ends fail the width test. */
#define INTERVAL_TRIG_TAYLOR_WIDTH 0.25
#define INTERVAL_TRIG_MAX 1e8
/* Covers every rounding of the narrow form (see interval_sincos). */
#define INTERVAL_SINCOS_MARGIN 0x1p-48
/* [lo, hi] with its ends limited to [-1, 1], the range of sin and cos. */
static inline interval interval__clamp11(double lo, double hi)
{
    return interval__mk(lo < -1.0 ? -1.0 : lo, hi > 1.0 ? 1.0 : hi);
}
static inline int interval__sincos_narrow(interval a)
{
    return a.hi - a.lo <= INTERVAL_TRIG_TAYLOR_WIDTH && fabs(a.lo) <= INTERVAL_TRIG_MAX &&
           fabs(a.hi) <= INTERVAL_TRIG_MAX;
}
static inline double interval__sincos_mid(interval a)
{
    return interval__min2(interval__max2(0.5 * a.lo + 0.5 * a.hi, a.lo), a.hi);
}
/* max |x - m| over a, raised by 2^-50 of itself (above its rounding). */
static inline double interval__sincos_half(interval a, double m)
{
    return interval__max2(m - a.lo, a.hi - m) * (1.0 + 0x1p-50);
}
/* The second-order form about m of sin (v = sin m, w = cos m) or of cos
 * (v = cos m, w = -sin m; only |w| matters), for |x - m| <= h and
 * (x - m)^2 / 2 <= q: v + w (x - m) - sigma (x - m)^2 / 2 with sigma
 * (sin xi, or cos xi) within h of v; clamped to [-1, 1]. */
static inline interval interval__sincos_form(double v, double w, double h, double q)
{
    double t1 = fabs(w) * h;
    double sl = interval__max2(v - h - 0x1p-50, -1.0), sh = interval__min2(v + h + 0x1p-50, 1.0);
    double rl = interval__min2(0.0, -sh * q), rh = interval__max2(0.0, -sl * q);
    return interval__clamp11(v - t1 + rl - INTERVAL_SINCOS_MARGIN,
                             v + t1 + rh + INTERVAL_SINCOS_MARGIN);
}

/* True when i is the NaN interval. */
static inline int interval_is_nan(interval i) { return interval__isnan(i); }

/* The NaN interval. */
static inline interval interval_nan(void) { return interval__mk(NAN, NAN); }

/* Smallest interval holding both, exact (no rounding). NaN interval if
 * either is NaN. */
static inline interval interval_hull(interval a, interval b)
{
    if (interval__isnan(a) || interval__isnan(b))
        return interval__mk(NAN, NAN);
    return interval__mk(a.lo < b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi);
}

/* -a, exact (no rounding). */
static inline interval interval_neg(interval a) { return interval__mk(-a.hi, -a.lo); }

/* The ends of a finite sum s = x + y, rounded outward as interval_add
 * rounds them: an end of at least DBL_MIN in magnitude is not 0, so only
 * the bit step is tested for there. */
static inline double interval__sum_down(double s, double x, double y)
{
    if (fabs(s) >= 0x1p-1022)
        return interval__down_finite(s);
    return s == 0.0 && x == -y ? s : interval__down_finite(s);
}
static inline double interval__sum_up(double s, double x, double y)
{
    if (fabs(s) >= 0x1p-1022)
        return interval__up_finite(s);
    return s == 0.0 && x == -y ? s : interval__up_finite(s);
}

/* a + b, ends rounded one step outward, except that an exact zero end
 * (x + -x) stays 0. -inf + inf inside the box is flagged, and that end
 * becomes infinite. */
INTERVAL_INLINE interval interval_add(interval a, interval b, unsigned *flags)
{
    double flo = a.lo + b.lo, fhi = a.hi + b.hi;
    /* Fast path, same result: finite sums come from finite operands only
     * (inf + x is inf or NaN), and then no flag can be raised. isfinite is a
     * quiet test: no invalid-operation exception on inf or NaN (trap mode,
     * README), where a relational test or inf - inf would raise one. */
    if (isfinite(flo) && isfinite(fhi))
        return interval__mk(interval__sum_down(flo, a.lo, b.lo), interval__sum_up(fhi, a.hi, b.hi));
    if (interval__isnan(a) || interval__isnan(b))
        return interval__nan_flag(flags);
    /* Infinite ends are points of the box (an overflowed value), so
     * -inf + inf may happen inside even when no corner shows it. */
    if ((a.lo == -INFINITY && b.hi == INFINITY) || (a.hi == INFINITY && b.lo == -INFINITY))
        *flags |= INTERVAL_MAYBE_NAN;
    double lo = flo, hi = fhi;
    if (lo != lo) { /* -inf + inf: an operand is infinite at some point */
        lo = -INFINITY;
        *flags |= INTERVAL_MAYBE_NAN;
    }
    if (hi != hi) {
        hi = INFINITY;
        *flags |= INTERVAL_MAYBE_NAN;
    }
    /* x + y == 0 exactly when x == -y: such a zero is exact and stays zero
     * instead of widening to +-DBL_MIN (see interval_mul). The test is on the
     * operands, not the sum, so it stays sound where subnormal results are
     * flushed to zero (the rasterizer's workers run so). */
    return interval__mk(lo == 0.0 && a.lo == -b.lo ? lo : interval_next_down(lo),
                        hi == 0.0 && a.hi == -b.hi ? hi : interval_next_up(hi));
}

/* a - b, as interval_add(a, -b): the same rounding. */
INTERVAL_INLINE interval interval_sub(interval a, interval b, unsigned *flags)
{
    return interval_add(a, interval_neg(b), flags);
}

/* x*y where 0*inf (NaN) counts as 0 for the bounds and raises the flag:
 * the product is bilinear, so the limits near that corner lie between 0
 * and the other corners. */
static inline double interval__mul0(double x, double y, int *bad)
{
    /* tested before multiplying: 0 * inf would raise an invalid operation */
    if ((x == 0.0 && isinf(y)) || (isinf(x) && y == 0.0)) {
        *bad = 1;
        return 0.0;
    }
    return x * y;
}

/* a * b, ends rounded one step outward, except that a zero end coming from
 * a zero factor stays 0. 0 * inf inside the box is flagged and counts as 0
 * for the ends. */
INTERVAL_INLINE interval interval_mul(interval a, interval b, unsigned *flags)
{
    /* Fast path, same result: when neither factor holds 0 (nor is NaN), the
     * signs say which ends give the least and greatest products, and as
     * rounding is monotone those are the least and greatest of the four
     * rounded products. No flag can be raised (no 0 * inf). A zero product
     * (an underflow) takes the general path. */
    if ((a.lo > 0.0 || a.hi < 0.0) && (b.lo > 0.0 || b.hi < 0.0)) {
        double lo, hi;
        if (a.lo > 0.0) {
            if (b.lo > 0.0) {
                lo = a.lo * b.lo;
                hi = a.hi * b.hi;
            } else {
                lo = a.hi * b.lo;
                hi = a.lo * b.hi;
            }
        } else if (b.lo > 0.0) {
            lo = a.lo * b.hi;
            hi = a.hi * b.lo;
        } else {
            lo = a.hi * b.hi;
            hi = a.lo * b.lo;
        }
        if (lo != 0.0 && hi != 0.0)
            return interval__mk(interval_next_down(lo), interval_next_up(hi));
    }
    if (isfinite(a.lo) && isfinite(a.hi) && isfinite(b.lo) && isfinite(b.hi)) { /* quiet tests */
        /* All ends finite, so no product is NaN and no flag is raised. The
         * same result as below, the underflow test made only when it counts. */
        double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo, p4 = a.hi * b.hi;
        double lo = interval__min2(interval__min2(p1, p2), interval__min2(p3, p4));
        double hi = interval__max2(interval__max2(p1, p2), interval__max2(p3, p4));
        if (lo != 0.0 && hi != 0.0)
            return interval__mk(interval_next_down(lo), interval_next_up(hi));
        int underflow = (p1 == 0.0 && a.lo != 0.0 && b.lo != 0.0) || (p2 == 0.0 && a.lo != 0.0 && b.hi != 0.0) ||
                        (p3 == 0.0 && a.hi != 0.0 && b.lo != 0.0) || (p4 == 0.0 && a.hi != 0.0 && b.hi != 0.0);
        return interval__mk(lo == 0.0 && !underflow ? 0.0 : interval_next_down(lo),
                            hi == 0.0 && !underflow ? 0.0 : interval_next_up(hi));
    }
    if (interval__isnan(a) || interval__isnan(b))
        return interval__nan_flag(flags);
    int bad = (interval__has_zero(a) && interval__has_inf(b)) || (interval__has_zero(b) && interval__has_inf(a)); /* 0*inf inside */
    double p1 = interval__mul0(a.lo, b.lo, &bad), p2 = interval__mul0(a.lo, b.hi, &bad);
    double p3 = interval__mul0(a.hi, b.lo, &bad), p4 = interval__mul0(a.hi, b.hi, &bad);
    double lo = interval__min2(interval__min2(p1, p2), interval__min2(p3, p4));
    double hi = interval__max2(interval__max2(p1, p2), interval__max2(p3, p4));
    if (bad)
        *flags |= INTERVAL_MAYBE_NAN;
    /* A zero bound that comes from a zero factor is exact and stays zero.
     * Widened to +-DBL_MIN it would make every later product with it a
     * subnormal, a microcode assist each on x86: the zero derivatives of
     * constants in the gradient evaluators made half of all products so. A
     * product of two non-zero factors that underflowed to 0 is widened. */
    int underflow = (p1 == 0.0 && a.lo != 0.0 && b.lo != 0.0) || (p2 == 0.0 && a.lo != 0.0 && b.hi != 0.0) ||
                    (p3 == 0.0 && a.hi != 0.0 && b.lo != 0.0) || (p4 == 0.0 && a.hi != 0.0 && b.hi != 0.0);
    return interval__mk(lo == 0.0 && !underflow ? 0.0 : interval_next_down(lo),
                        hi == 0.0 && !underflow ? 0.0 : interval_next_up(hi));
}

/* a*a, tight: [-2,3]^2 = [0,9]. Ends rounded one step outward, the lower
 * end clamped at 0. */
INTERVAL_INLINE interval interval_sqr(interval a, unsigned *flags)
{
    if (interval__isnan(a))
        return interval__nan_flag(flags);
    double l, h;
    if (a.lo >= 0.0) {
        l = a.lo * a.lo;
        h = a.hi * a.hi;
    } else if (a.hi <= 0.0) {
        l = a.hi * a.hi;
        h = a.lo * a.lo;
    } else {
        double m = -a.lo > a.hi ? -a.lo : a.hi;
        l = 0.0;
        h = m * m;
    }
    l = interval_next_down(l);
    return interval__mk(l < 0.0 ? 0.0 : l, interval_next_up(h));
}

/* |a|, exact (no rounding). */
static inline interval interval_abs(interval a)
{
    if (a.lo >= 0.0)
        return a;
    if (a.hi <= 0.0)
        return interval__mk(-a.hi, -a.lo);
    return interval__mk(0.0, -a.lo > a.hi ? -a.lo : a.hi);
}

/* Elementwise min and max of the ends, exact (no rounding); NaN interval
 * if either is NaN. */
static inline interval interval_min(interval a, interval b)
{
    if (interval__isnan(a) || interval__isnan(b))
        return interval__mk(NAN, NAN);
    return interval__mk(a.lo < b.lo ? a.lo : b.lo, a.hi < b.hi ? a.hi : b.hi);
}

static inline interval interval_max(interval a, interval b)
{
    if (interval__isnan(a) || interval__isnan(b))
        return interval__mk(NAN, NAN);
    return interval__mk(a.lo > b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi);
}

#endif
