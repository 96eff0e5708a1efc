/* interval: sound interval arithmetic in double (see interval.h for the
 * rounding and flag rules). */
#include "common/expr/interval.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "common/expr/exp_kernel.h"
#include "common/expr/sincos_kernel.h"

/* Short local names for the helpers of interval.h. */
static inline double up(double x) { return interval_next_up(x); }
static inline double dn(double x) { return interval_next_down(x); }
static inline double min2(double a, double b) { return interval__min2(a, b); }
static inline double max2(double a, double b) { return interval__max2(a, b); }
static inline int isnan_iv(interval a) { return interval__isnan(a); }
static inline int has_inf(interval a) { return interval__has_inf(a); }
static inline interval mk(double lo, double hi) { return interval__mk(lo, hi); }
static inline interval nan_iv(unsigned *flags) { return interval__nan_flag(flags); }

/* x with its bit pattern stepped by k. */
static double step_bits(double x, int64_t k)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u += (uint64_t)k;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* 1 when 2^-1021 <= |x| < 2^1023 (tested on the bits: no floating-point
 * exception on NaN): two steps either way stay among the normal numbers,
 * so each is the plain bit step and the two are one step of 2. */
static int two_steps_normal(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    return ((u >> 52) & 0x7ff) - 2 < 2044;
}

/* dn(dn(x)) and up(up(x)), with the two steps made at once where they are
 * plain bit steps (the same result). */
static double dn2(double x)
{
    if (two_steps_normal(x))
        return step_bits(x, x > 0.0 ? -2 : 2);
    return dn(dn(x));
}
static double up2(double x)
{
    if (two_steps_normal(x))
        return step_bits(x, x > 0.0 ? 2 : -2);
    return up(up(x));
}

/* dn2 and up2 of a positive x, where the steps cannot leave the normal
 * numbers (or reach +inf for up2): two steps of the bit pattern, which is
 * what they give there, without their tests. */
static double dn2_pos(double x) { return x >= 0x1p-1021 ? step_bits(x, -2) : dn2(x); }
static double up2_pos(double x)
{
    return x >= 0x1p-1022 && x < 0x1p1023 ? step_bits(x, 2) : up2(x);
}

interval interval_around(double v) { return mk(dn(v), up(v)); }

interval interval_div(interval a, interval b, unsigned *flags)
{
    if (isnan_iv(a) || isnan_iv(b))
        return nan_iv(flags);
    if (has_inf(a) && has_inf(b))
        *flags |= INTERVAL_MAYBE_NAN; /* inf/inf */
    /* A divisor that is exactly 0 over the whole box: the quotient has no
     * finite value anywhere (+-inf, or NaN for 0/0), so no point of the box
     * can be on a surface through it: undefined everywhere (1/(x*0)). */
    if (b.lo == 0.0 && b.hi == 0.0)
        return nan_iv(flags);
    if (b.lo <= 0.0 && b.hi >= 0.0) {
        /* Either sign of infinity is reachable (a signed zero is not
         * visible to comparisons), so give up on half-infinite bounds. */
        if (a.lo <= 0.0 && a.hi >= 0.0)
            *flags |= INTERVAL_MAYBE_NAN; /* 0/0 */
        return mk(-INFINITY, INFINITY);
    }
    /* inf/inf, tested before dividing (it would raise an invalid operation) */
    if ((isinf(a.lo) || isinf(a.hi)) && (isinf(b.lo) || isinf(b.hi))) {
        *flags |= INTERVAL_MAYBE_NAN;
        return mk(-INFINITY, INFINITY);
    }
    double q1 = a.lo / b.lo, q2 = a.lo / b.hi, q3 = a.hi / b.lo, q4 = a.hi / b.hi;
    return mk(dn(min2(min2(q1, q2), min2(q3, q4))), up(max2(max2(q1, q2), max2(q3, q4))));
}

interval interval_sqrt(interval a, unsigned *flags)
{
    if (isnan_iv(a) || a.hi < 0.0)
        return nan_iv(flags);
    double lo = a.lo;
    if (lo < 0.0) {
        *flags |= INTERVAL_MAYBE_NAN;
        lo = 0.0;
    }
    double l = dn(sqrt(lo));
    return mk(l < 0.0 ? 0.0 : l, up(sqrt(a.hi)));
}

interval interval_exp(interval a, unsigned *flags)
{
    if (isnan_iv(a))
        return nan_iv(flags);
    double l = dn2_pos(exp_kernel(a.lo)), h = up2_pos(exp_kernel(a.hi));
    /* Widen subnormal ends to 0 and DBL_MIN: exp of a large negative
     * number would otherwise feed subnormals, which are ~100 times slower
     * on x86, into everything downstream (blobs_b's exp(-196*...)). */
    if (l < DBL_MIN)
        l = 0.0;
    if (h < DBL_MIN)
        h = DBL_MIN;
    return mk(l, h);
}

interval interval_log(interval a, unsigned *flags)
{
    if (isnan_iv(a) || a.hi < 0.0)
        return nan_iv(flags);
    double lo = a.lo;
    if (lo < 0.0) {
        *flags |= INTERVAL_MAYBE_NAN;
        lo = 0.0;
    }
    return mk(dn2(log(lo)), up2(log(a.hi)));
}

/* May [lo, hi] contain phase + k*period for an integer k? Errs towards yes.
 * k = (x - phase) / period in double carries an absolute error below
 * ~2.2e-16 * (|x| + 2) / period (the subtraction) plus ~4.4e-16 * |k|
 * (phase, period and the division), i.e. below 1e-15 * (|x| + 4) for
 * period >= pi; eps takes that over both ends. */
static int may_hit(double lo, double hi, double phase, double period)
{
    double kl = (lo - phase) / period, kh = (hi - phase) / period;
    double eps = 1e-15 * (fabs(lo) + fabs(hi) + 4.0);
    return floor(kh + eps) >= ceil(kl - eps);
}

/* sin and cos share this: phase_max is where the function is 1. */
static interval sin_or_cos(interval a, unsigned *flags, int is_cos)
{
    if (isnan_iv(a))
        return nan_iv(flags);
    if (isinf(a.lo) || isinf(a.hi))
        *flags |= INTERVAL_MAYBE_NAN; /* sin(inf) is NaN */
    if (!(fabs(a.lo) <= INTERVAL_TRIG_MAX && fabs(a.hi) <= INTERVAL_TRIG_MAX) || a.hi - a.lo >= 6.0)
        return mk(-1.0, 1.0);
    double f0 = is_cos ? cos(a.lo) : sin(a.lo), f1 = is_cos ? cos(a.hi) : sin(a.hi);
    double lo = dn2(min2(f0, f1)), hi = up2(max2(f0, f1));
    double pmax = is_cos ? 0.0 : M_PI / 2, pmin = is_cos ? M_PI : -M_PI / 2;
    if (may_hit(a.lo, a.hi, pmax, 2 * M_PI))
        hi = 1.0;
    if (may_hit(a.lo, a.hi, pmin, 2 * M_PI))
        lo = -1.0;
    return interval__clamp11(lo, hi);
}

interval interval_sin(interval a, unsigned *flags) { return sin_or_cos(a, flags, 0); }
interval interval_cos(interval a, unsigned *flags) { return sin_or_cos(a, flags, 1); }

/* For x and m in a, Taylor's theorem with the Lagrange remainder gives
 * sin x = sin m + cos m (x - m) - sin(xi) (x - m)^2 / 2 for some xi between
 * m and x, and |sin xi - sin m| <= |xi - m| <= h; likewise cos x = cos m -
 * sin m (x - m) - cos(xi) (x - m)^2 / 2. sin m and cos m come from one
 * sincos_point (sincos_kernel.h; libm beyond its range), within 2 ulps
 * (2^-52) of the reals,
 * the assumption interval_sin makes too. h is max |x - m| raised by 2^-50
 * of itself (above its rounding). Every term of the sums is at most 1.125
 * in magnitude and there are five roundings, each within 2^-53: with the
 * libm errors (2^-52 in v, 2^-52 h through w, 2^-50 in sigma's bounds
 * times q <= 2^-5) the sums are within 2^-50 of the real bounds, well
 * inside INTERVAL_SINCOS_MARGIN; so both enclosures are sound. */
void interval_sincos(interval a, interval *so, interval *co, unsigned *flags)
{
    if (!interval__sincos_narrow(a)) {
        if (so)
            *so = interval_sin(a, flags);
        if (co)
            *co = interval_cos(a, flags);
        return;
    }
    double m = interval__sincos_mid(a), sm, cm;
    sincos_point(m, &sm, &cm);
    double h = interval__sincos_half(a, m), q = 0.5 * h * h;
    if (so)
        *so = interval__sincos_form(sm, cm, h, q);
    if (co)
        *co = interval__sincos_form(cm, sm, h, q);
}

interval interval_tan(interval a, unsigned *flags)
{
    if (isnan_iv(a))
        return nan_iv(flags);
    if (isinf(a.lo) || isinf(a.hi))
        *flags |= INTERVAL_MAYBE_NAN;
    if (!(fabs(a.lo) <= INTERVAL_TRIG_MAX && fabs(a.hi) <= INTERVAL_TRIG_MAX) ||
        a.hi - a.lo >= 3.0 || may_hit(a.lo, a.hi, M_PI / 2, M_PI))
        return mk(-INFINITY, INFINITY);
    return mk(dn2(tan(a.lo)), up2(tan(a.hi)));
}

interval interval_powc(interval a, double p, unsigned *flags)
{
    if (isnan_iv(a) || a.hi < 0.0 || p != p)
        return nan_iv(flags);
    double lo = a.lo;
    if (lo < 0.0) {
        *flags |= INTERVAL_MAYBE_NAN;
        lo = 0.0;
    }
    double r0 = pow(lo, p), r1 = pow(a.hi, p);
    double l = dn2(p > 0 ? r0 : r1), h = up2(p > 0 ? r1 : r0);
    if (a.lo == -INFINITY) { /* pow(-inf, p) is +0 for p < 0, +inf for p > 0 */
        if (p > 0)
            h = INFINITY;
        else
            l = 0.0;
    }
    if (p == 0.0) { l = 1.0; h = 1.0; }
    return mk(l < 0.0 ? 0.0 : l, h);
}
