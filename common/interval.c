/* interval: sound interval arithmetic in double (see interval.h for the
 * rounding and flag rules). */
#include "common/interval.h"

#include <math.h>
#include <stdint.h>
#include <string.h>


/* nextafter(x, +inf) without the libm call (it is the hot spot of every
 * interval operation): step the bit pattern. NaN and +inf stay. */
static inline double up(double x)
{
    if (x != x || x == INFINITY)
        return x;
    if (x == 0.0)
        return 0x1p-1074;
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u = x > 0.0 ? u + 1 : u - 1;
    memcpy(&x, &u, sizeof x);
    return x;
}
static inline double dn(double x) { return -up(-x); }
static inline double min2(double a, double b) { return a < b ? a : b; } /* no NaN here */
static inline double max2(double a, double b) { return a > b ? a : b; }
static double dn2(double x) { return dn(dn(x)); }
static double up2(double x) { return up(up(x)); }
static int has_zero(interval a) { return a.lo <= 0.0 && a.hi >= 0.0; }
static int has_inf(interval a) { return isinf(a.lo) || isinf(a.hi); }
static int isnan_iv(interval a) { return a.lo != a.lo || a.hi != a.hi; }
static interval mk(double lo, double hi) { interval r = {lo, hi}; return r; }
static interval nan_iv(unsigned *flags)
{
    *flags |= INTERVAL_MAYBE_NAN;
    return mk(NAN, NAN);
}

int interval_is_nan(interval i) { return isnan_iv(i); }
interval interval_nan(void) { return mk(NAN, NAN); }

interval interval_around(double v) { return mk(dn(v), up(v)); }

interval interval_hull(interval a, interval b)
{
    if (isnan_iv(a) || isnan_iv(b))
        return mk(NAN, NAN);
    return mk(a.lo < b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi);
}

interval interval_neg(interval a) { return mk(-a.hi, -a.lo); }

interval interval_add(interval a, interval b, unsigned *flags)
{
    if (isnan_iv(a) || isnan_iv(b))
        return nan_iv(flags);
    /* Infinite ends are points of the box (an overflowed value), so
     * -inf + inf may happen inside even when no corner shows it. */
    if ((a.lo == -INFINITY && b.hi == INFINITY) || (a.hi == INFINITY && b.lo == -INFINITY))
        *flags |= INTERVAL_MAYBE_NAN;
    double lo = a.lo + b.lo, hi = a.hi + b.hi;
    if (lo != lo) { /* -inf + inf: an operand is infinite at some point */
        lo = -INFINITY;
        *flags |= INTERVAL_MAYBE_NAN;
    }
    if (hi != hi) {
        hi = INFINITY;
        *flags |= INTERVAL_MAYBE_NAN;
    }
    return mk(dn(lo), up(hi));
}

interval interval_sub(interval a, interval b, unsigned *flags)
{
    return interval_add(a, interval_neg(b), flags);
}

/* x*y where 0*inf (NaN) counts as 0 for the bounds and raises the flag:
 * the product is bilinear, so the limits near that corner lie between 0
 * and the other corners. */
static double mul0(double x, double y, int *bad)
{
    double p = x * y;
    if (p != p) {
        *bad = 1;
        return 0.0;
    }
    return p;
}

interval interval_mul(interval a, interval b, unsigned *flags)
{
    if (isnan_iv(a) || isnan_iv(b))
        return nan_iv(flags);
    int bad = (has_zero(a) && has_inf(b)) || (has_zero(b) && has_inf(a)); /* 0*inf inside */
    double p1 = mul0(a.lo, b.lo, &bad), p2 = mul0(a.lo, b.hi, &bad);
    double p3 = mul0(a.hi, b.lo, &bad), p4 = mul0(a.hi, b.hi, &bad);
    double lo = min2(min2(p1, p2), min2(p3, p4));
    double hi = max2(max2(p1, p2), max2(p3, p4));
    if (bad)
        *flags |= INTERVAL_MAYBE_NAN;
    return mk(dn(lo), up(hi));
}

interval interval_div(interval a, interval b, unsigned *flags)
{
    if (isnan_iv(a) || isnan_iv(b))
        return nan_iv(flags);
    if (has_inf(a) && has_inf(b))
        *flags |= INTERVAL_MAYBE_NAN; /* inf/inf */
    if (b.lo <= 0.0 && b.hi >= 0.0) {
        /* Either sign of infinity is reachable (a signed zero is not
         * visible to comparisons), so give up on half-infinite bounds. */
        if (a.lo <= 0.0 && a.hi >= 0.0)
            *flags |= INTERVAL_MAYBE_NAN; /* 0/0 */
        return mk(-INFINITY, INFINITY);
    }
    double q1 = a.lo / b.lo, q2 = a.lo / b.hi, q3 = a.hi / b.lo, q4 = a.hi / b.hi;
    if (q1 != q1 || q2 != q2 || q3 != q3 || q4 != q4) { /* inf/inf */
        *flags |= INTERVAL_MAYBE_NAN;
        return mk(-INFINITY, INFINITY);
    }
    return mk(dn(min2(min2(q1, q2), min2(q3, q4))), up(max2(max2(q1, q2), max2(q3, q4))));
}

interval interval_sqr(interval a, unsigned *flags)
{
    if (isnan_iv(a))
        return nan_iv(flags);
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
    l = dn(l);
    return mk(l < 0.0 ? 0.0 : l, up(h));
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
    double l = dn2(exp(a.lo));
    return mk(l < 0.0 ? 0.0 : l, up2(exp(a.hi)));
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

interval interval_abs(interval a)
{
    if (a.lo >= 0.0)
        return a;
    if (a.hi <= 0.0)
        return mk(-a.hi, -a.lo);
    return mk(0.0, -a.lo > a.hi ? -a.lo : a.hi);
}

interval interval_min(interval a, interval b)
{
    if (isnan_iv(a) || isnan_iv(b))
        return mk(NAN, NAN);
    return mk(a.lo < b.lo ? a.lo : b.lo, a.hi < b.hi ? a.hi : b.hi);
}

interval interval_max(interval a, interval b)
{
    if (isnan_iv(a) || isnan_iv(b))
        return mk(NAN, NAN);
    return mk(a.lo > b.lo ? a.lo : b.lo, a.hi > b.hi ? a.hi : b.hi);
}

/* Beyond this magnitude trigonometric functions get their full range. */
#define TRIG_MAX 1e8

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

static interval clamp11(double lo, double hi)
{
    return mk(lo < -1.0 ? -1.0 : lo, hi > 1.0 ? 1.0 : hi);
}

/* sin and cos share this: phase_max is where the function is 1. */
static interval sin_or_cos(interval a, unsigned *flags, int is_cos)
{
    if (isnan_iv(a))
        return nan_iv(flags);
    if (isinf(a.lo) || isinf(a.hi))
        *flags |= INTERVAL_MAYBE_NAN; /* sin(inf) is NaN */
    if (!(fabs(a.lo) <= TRIG_MAX && fabs(a.hi) <= TRIG_MAX) || a.hi - a.lo >= 6.0)
        return mk(-1.0, 1.0);
    double f0 = is_cos ? cos(a.lo) : sin(a.lo), f1 = is_cos ? cos(a.hi) : sin(a.hi);
    double lo = dn2(min2(f0, f1)), hi = up2(max2(f0, f1));
    double pmax = is_cos ? 0.0 : M_PI / 2, pmin = is_cos ? M_PI : -M_PI / 2;
    if (may_hit(a.lo, a.hi, pmax, 2 * M_PI))
        hi = 1.0;
    if (may_hit(a.lo, a.hi, pmin, 2 * M_PI))
        lo = -1.0;
    return clamp11(lo, hi);
}

interval interval_sin(interval a, unsigned *flags) { return sin_or_cos(a, flags, 0); }
interval interval_cos(interval a, unsigned *flags) { return sin_or_cos(a, flags, 1); }

interval interval_tan(interval a, unsigned *flags)
{
    if (isnan_iv(a))
        return nan_iv(flags);
    if (isinf(a.lo) || isinf(a.hi))
        *flags |= INTERVAL_MAYBE_NAN;
    if (!(fabs(a.lo) <= TRIG_MAX && fabs(a.hi) <= TRIG_MAX) || a.hi - a.lo >= 3.0 ||
        may_hit(a.lo, a.hi, M_PI / 2, M_PI))
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
