/* Tests for common/expr/interval: per-operation soundness against MPFR at witness
 * points of many random boxes, point-box widths, and the known pitfalls. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <mpfr.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "common/expr/exp_kernel.h"
#include "common/expr/interval.h"
#include "bench/rng.h"

#ifdef __FAST_MATH__
#error "fast-math breaks the interval arithmetic; build without it"
#endif

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define NBOX 20000
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NBOX 20000
#endif
#endif
#ifndef NBOX
#define NBOX 100000
#endif
/* TEST_INTERVAL_BOXES=1000000 runs TESTPLAN 19's full count. */
static int nbox(void)
{
    const char *e = getenv("TEST_INTERVAL_BOXES");
    int n = e ? atoi(e) : 0;
    return n > 0 ? n : NBOX;
}

/* ---- random numbers (xorshift; deterministic) ---- */
static uint64_t rng = 0x9e3779b97f4a7c15ull;
static uint64_t next_u64(void) { return rng_xorshift64(&rng); }
static double unit(void) { return rng_unit(next_u64()); }

static double special(void)
{
    static const double sp[] = {0.0, -0.0, 1.0, -1.0, 3.141592653589793, 3.1415926535897936,
                                1.5707963267948966, -1.5707963267948966, 2.0, 0.5, 709.8, -745.2,
                                DBL_MAX, -DBL_MAX, DBL_MIN, 4.9e-324, 1e300, -1e300};
    return sp[next_u64() % (sizeof sp / sizeof sp[0])];
}

/* A value whose magnitude spreads over many binades. */
static double rand_value(void)
{
    uint64_t r = next_u64() % 100;
    if (r < 5)
        return special();
    double sign = (next_u64() & 1) ? -1.0 : 1.0;
    int e = r < 70 ? (int)(next_u64() % 16) - 8 : (int)(next_u64() % 1200) - 600;
    return sign * ldexp(1.0 + unit(), e);
}

/* Boxes: tiny, huge, degenerate, straddling 0, infinite ends. */
static interval rand_interval(void)
{
    interval r;
    uint64_t kind = next_u64() % 100;
    double a = rand_value(), b = rand_value();
    if (kind < 15) { /* degenerate */
        r.lo = r.hi = a;
    } else if (kind < 35) { /* tiny */
        double w = fabs(a) * ldexp(unit(), -(int)(next_u64() % 50)) + 4.9e-324;
        r.lo = a;
        r.hi = a + w;
    } else if (kind < 55) { /* straddling 0 */
        r.lo = -fabs(a);
        r.hi = fabs(b);
    } else if (kind < 60) { /* infinite end(s) */
        r.lo = (next_u64() & 1) ? -INFINITY : -fabs(a);
        r.hi = (next_u64() & 1) ? INFINITY : fabs(b);
        if (next_u64() % 4 == 0) {
            r.lo = a;
            r.hi = INFINITY;
        }
    } else { /* arbitrary, possibly huge */
        r.lo = fmin(a, b);
        r.hi = fmax(a, b);
    }
    if (!(r.lo <= r.hi) || isinf(r.hi - r.lo) == 0 ? 0 : 0) {}
    if (r.hi < r.lo) { double t = r.lo; r.lo = r.hi; r.hi = t; }
    return r;
}

/* A point of the box: an end or a random interior point. */
static double witness(interval a, int k)
{
    if (k == 0) return a.lo;
    if (k == 1) return a.hi;
    double lo = isinf(a.lo) ? (isinf(a.hi) ? -1e308 : fmin(a.hi, 0.0) - 1e300) : a.lo;
    double hi = isinf(a.hi) ? (isinf(a.lo) ? 1e308 : fmax(lo, 0.0) + 1e300) : a.hi;
    double t = unit();
    double p = lo + t * (hi - lo);
    if (isinf(p)) p = lo / 2 + t * (hi / 2 - lo / 2) * 2;
    if (next_u64() % 8 == 0) p = lo * (1 - t) + hi * t;
    if (p < a.lo || isnan(p)) p = a.lo;
    if (p > a.hi) p = a.hi;
    return p;
}

typedef enum { NEG, ADD, SUB, MUL, DIV, SQR, SQRT, EXP, LOG, ABS, SIN, COS, TAN, MIN, MAX, POWC } opk;
static const char *opname[] = {"neg", "add", "sub", "mul", "div", "sqr", "sqrt", "exp", "log",
                               "abs", "sin", "cos", "tan", "min", "max", "powc"};

static interval apply(opk op, interval a, interval b, double p, unsigned *f)
{
    switch (op) {
    case NEG: return interval_neg(a);
    case ADD: return interval_add(a, b, f);
    case SUB: return interval_sub(a, b, f);
    case MUL: return interval_mul(a, b, f);
    case DIV: return interval_div(a, b, f);
    case SQR: return interval_sqr(a, f);
    case SQRT: return interval_sqrt(a, f);
    case EXP: return interval_exp(a, f);
    case LOG: return interval_log(a, f);
    case ABS: return interval_abs(a);
    case SIN: return interval_sin(a, f);
    case COS: return interval_cos(a, f);
    case TAN: return interval_tan(a, f);
    case MIN: return interval_min(a, b);
    case MAX: return interval_max(a, b);
    case POWC: return interval_powc(a, p, f);
    }
    return interval_nan();
}

/* The exact value at (x, y) by MPFR, as a NaN flag and the doubles just
 * below and above it: MPFR rounds correctly, so the 53-bit result rounded
 * down plus its ternary value pins the real value between two doubles. */
static mpfr_t ma, mb, mr; /* set up once per run (see setup/teardown) */

static int mpfr_setup(void **state)
{
    (void)state;
    mpfr_inits2(53, ma, mb, mr, (mpfr_ptr)0);
    return 0;
}

static int mpfr_teardown(void **state)
{
    (void)state;
    mpfr_clears(ma, mb, mr, (mpfr_ptr)0);
    mpfr_free_cache();
    return 0;
}

static int exact_at(opk op, double x, double y, double p, double *rd, double *ru)
{
    const mpfr_rnd_t D = MPFR_RNDD;
    int t = 0;
    mpfr_set_d(ma, x, MPFR_RNDN); /* exact: both have 53 bits */
    mpfr_set_d(mb, op == POWC ? p : y, MPFR_RNDN);
    switch (op) {
    case NEG: t = mpfr_neg(mr, ma, D); break;
    case ADD: t = mpfr_add(mr, ma, mb, D); break;
    case SUB: t = mpfr_sub(mr, ma, mb, D); break;
    case MUL: t = mpfr_mul(mr, ma, mb, D); break;
    case DIV: t = mpfr_div(mr, ma, mb, D); break;
    case SQR: t = mpfr_sqr(mr, ma, D); break;
    case SQRT: t = mpfr_sqrt(mr, ma, D); break;
    case EXP: t = mpfr_exp(mr, ma, D); break;
    case LOG: t = mpfr_log(mr, ma, D); break;
    case ABS: t = mpfr_abs(mr, ma, D); break;
    case SIN: t = mpfr_sin(mr, ma, D); break;
    case COS: t = mpfr_cos(mr, ma, D); break;
    case TAN: t = mpfr_tan(mr, ma, D); break;
    case MIN: t = mpfr_min(mr, ma, mb, D); break;
    case MAX: t = mpfr_max(mr, ma, mb, D); break;
    case POWC: t = mpfr_pow(mr, ma, mb, D); break;
    }
    if (mpfr_nan_p(mr))
        return 1;
    *rd = mpfr_get_d(mr, MPFR_RNDD);
    *ru = mpfr_get_d(mr, MPFR_RNDU);
    if (t < 0 && mpfr_cmp_d(mr, *ru) == 0) /* the real value is above mr */
        *ru = nextafter(*ru, INFINITY);
    return 0;
}

static int is_binary(opk op) { return op == ADD || op == SUB || op == MUL || op == DIV || op == MIN || op == MAX; }

static void check_op(opk op)
{
    long checked = 0;
    const int count = nbox();
    for (int n = 0; n < count; n++) {
        interval a = rand_interval(), b = rand_interval();
        double p = 0.0;
        if (op == POWC) {
            p = (next_u64() & 1 ? 1 : -1) * (unit() * 4 + 0.01);
            if (p == floor(p)) p += 0.5;
            if (next_u64() % 4 == 0) p = (next_u64() & 1) ? 0.5 : -1.5;
        }
        unsigned f = 0;
        interval r = apply(op, a, b, p, &f);
        for (int k = 0; k < 3; k++) { /* two random corners and an interior point */
            int c = (int)(next_u64() % 4);
            double x = witness(a, k == 2 ? 2 : c % 2), y = witness(b, k == 2 ? 2 : c / 2);
            double rd, ru;
            if ((op == SIN || op == COS) && fabs(x) > 1e8 && r.lo <= -1 && r.hi >= 1)
                continue; /* trivially contained; spares MPFR a long reduction */
            if (op == TAN && fabs(x) > 1e8 && r.lo == -INFINITY && r.hi == INFINITY)
                continue;
            int nan = exact_at(op, x, y, p, &rd, &ru);
            if (interval_is_nan(r)) {
                if (!f)
                    fail_msg("%s: NaN interval without flag", opname[op]);
                continue;
            }
            if (nan) {
                if (!f)
                    fail_msg("%s([%a,%a], [%a,%a]) at (%a, %a): NaN but no flag", opname[op], a.lo,
                             a.hi, b.lo, b.hi, x, y);
                continue;
            }
            if (!(r.lo <= rd && ru <= r.hi))
                fail_msg("%s([%a,%a], [%a,%a]; p=%a) = [%a,%a] misses value in [%a,%a] at (%a,%a)",
                         opname[op], a.lo, a.hi, b.lo, b.hi, p, r.lo, r.hi, rd, ru, x, y);
            checked++;
        }
        (void)is_binary;
    }
    assert_true(checked > count);
    if (getenv("TIME_OPS")) fprintf(stderr, "%s %.2f\n", opname[op], (double)clock() / CLOCKS_PER_SEC);
}

#define OPTEST(name, op) \
    static void test_sound_##name(void **state) { (void)state; check_op(op); }
OPTEST(neg, NEG) OPTEST(add, ADD) OPTEST(sub, SUB) OPTEST(mul, MUL) OPTEST(div, DIV)
OPTEST(sqr, SQR) OPTEST(sqrt, SQRT) OPTEST(exp, EXP) OPTEST(log, LOG) OPTEST(abs, ABS)
OPTEST(sin, SIN) OPTEST(cos, COS) OPTEST(tan, TAN) OPTEST(min, MIN) OPTEST(max, MAX)
OPTEST(powc, POWC)

/* A point box gives an interval a few ulps wide around the double result. */
static void test_point_box_width(void **state)
{
    (void)state;
    for (int op = NEG; op <= POWC; op++) {
        for (int n = 0; n < 2000; n++) {
            double x = (unit() - 0.5) * 40, y = (unit() - 0.5) * 40, p = 0.5 + unit();
            if (op == SQRT || op == LOG || op == POWC) x = fabs(x);
            interval a = {x, x}, b = {y, y};
            unsigned f = 0;
            interval r = apply((opk)op, a, b, p, &f);
            if (!isfinite(r.lo) || !isfinite(r.hi))
                continue; /* near a pole of tan, say */
            double lo = r.lo, hi = r.hi;
            for (int k = 0; k < 6; k++) { /* at most 6 ulps on both sides together */
                if (hi > lo) hi = nextafter(hi, -INFINITY);
                if (hi > lo) lo = nextafter(lo, INFINITY);
            }
            if (hi > lo)
                fail_msg("%s at %a: [%a, %a] too wide", opname[op], x, r.lo, r.hi);
            assert_int_equal(f, 0);
        }
    }
}

static int eq(interval r, double lo, double hi) { return r.lo == lo && r.hi == hi; }
static interval iv(double lo, double hi) { interval r = {lo, hi}; return r; }

/* One assertion per pitfall of TESTPLAN 4 and 5. */
static void test_pitfalls(void **state)
{
    (void)state;
    unsigned f = 0;
    interval r = interval_sqr(iv(-2, 3), &f);
    assert_true(r.lo == 0 && r.hi >= 9 && r.hi <= nextafter(9, 10) && f == 0);
    r = interval_sqr(iv(-2, 1), &f);
    assert_true(r.lo == 0 && r.hi >= 4);
    r = interval_sqr(iv(-INFINITY, INFINITY), &f);
    assert_true(eq(r, 0, INFINITY) && f == 0); /* not [NaN, inf] */
    r = interval_div(iv(1, 2), iv(-1, 1), &f);
    assert_true(eq(r, -INFINITY, INFINITY) && f == 0);
    r = interval_div(iv(-1, 2), iv(0, 1), &f);
    assert_true(eq(r, -INFINITY, INFINITY) && f == INTERVAL_MAYBE_NAN); /* 0/0 */
    f = 0;
    r = interval_exp(iv(0, 1000), &f);
    assert_true(r.hi == INFINITY && r.lo <= 1 && f == 0); /* overflow: +inf, no NaN */
    r = interval_exp(iv(-INFINITY, -1000), &f);
    assert_true(r.lo == 0 && r.hi >= 0 && f == 0);
    r = interval_log(iv(0, 1), &f);
    assert_true(r.lo == -INFINITY && r.hi >= 0 && f == 0);
    r = interval_sqrt(iv(-1, 4), &f);
    assert_true(r.lo == 0 && r.hi >= 2 && f == INTERVAL_MAYBE_NAN);
    f = 0;
    r = interval_log(iv(-2, -1), &f);
    assert_true(interval_is_nan(r) && f == INTERVAL_MAYBE_NAN);
    f = 0;
    r = interval_sin(iv(0, 7), &f);
    assert_true(eq(r, -1, 1));
    r = interval_cos(iv(1e300, 1e300), &f);
    assert_true(r.lo >= -1 && r.hi <= 1 && f == 0);
    r = interval_sin(iv(1.0, 2.0), &f); /* holds pi/2 */
    assert_true(r.hi == 1 && r.lo <= sin(1.0));
    r = interval_tan(iv(1.5, 1.6), &f); /* across the pole */
    assert_true(eq(r, -INFINITY, INFINITY));
    r = interval_tan(iv(-1.0, 1.0), &f);
    assert_true(r.lo <= tan(-1.0) && r.hi >= tan(1.0) && isfinite(r.hi));
    assert_int_equal(f, 0);
    /* pi and e as intervals contain the reals. */
    r = interval_around(M_PI);
    assert_true(r.lo < M_PI && r.hi > M_PI && r.lo < 3.14159265358979323846 && r.hi > 3.14159265358979323);
    /* inf - inf never silently gives NaN. */
    r = interval_sub(iv(INFINITY, INFINITY), iv(INFINITY, INFINITY), &f);
    assert_true(!interval_is_nan(r) && r.lo == -INFINITY && r.hi == INFINITY && f == INTERVAL_MAYBE_NAN);
    f = 0;
    /* (x*1e200)^2 - 1 saturates to +inf, and no inf - inf appears. */
    r = interval_sub(interval_sqr(interval_mul(iv(1, 2), iv(1e200, 1e200), &f), &f), iv(1, 1), &f);
    assert_true(r.hi == INFINITY && f == 0);
    /* 0 * inf */
    r = interval_mul(iv(0, 1), iv(1, INFINITY), &f);
    assert_true(r.lo <= 0 && r.hi == INFINITY && f == INTERVAL_MAYBE_NAN);
    f = 0;
    /* pow with a non-integer exponent: no truncation to an integer (libfive #574). */
    r = interval_powc(iv(8, 8), 1.0 / 3.0, &f);
    assert_true(r.lo <= 2 && r.hi >= 2 && r.hi < 2.001);
    r = interval_powc(iv(0, 64), 0.5, &f);
    assert_true(r.lo == 0 && r.hi >= 8 && f == 0);
    r = interval_powc(iv(0, 4), -0.5, &f);
    assert_true(r.hi == INFINITY && r.lo <= 0.5);
    r = interval_abs(iv(-3, 2));
    assert_true(eq(r, 0, 3));
    r = interval_min(iv(-3, 2), iv(0, 1));
    assert_true(eq(r, -3, 1));
    r = interval_max(iv(-3, 2), iv(0, 1));
    assert_true(eq(r, 0, 2));
    /* NaN in, NaN out. */
    f = 0;
    r = interval_add(interval_nan(), iv(0, 1), &f);
    assert_true(interval_is_nan(r) && f);
}

/* interval_exp rounds each end by two steps of interval_next_down and
 * interval_next_up (widened to 0 and DBL_MIN below DBL_MIN), bit for bit,
 * its shortcut for ends far from the limits of the range included: random
 * boxes and the binades around those limits. */
static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* The rounding steps: interval_next_up is nextafter towards +inf on the
 * normal numbers and -inf, keeps NaN and +inf, and takes zero and the
 * subnormals to 0 or DBL_MIN; interval_next_down is -interval_next_up(-x),
 * bit for bit, and the _finite forms agree with both on finite x. */
static double up_reference(double x)
{
    if (isnan(x) || x == INFINITY)
        return x;
    if (fabs(x) < DBL_MIN)
        return x < 0.0 ? 0.0 : DBL_MIN;
    return nextafter(x, INFINITY);
}

static void check_steps(double x)
{
    double up = interval_next_up(x), down = interval_next_down(x);
    if (!same_bits(up, up_reference(x)) || !same_bits(down, -up_reference(-x)))
        fail_msg("steps of %a: up %a down %a", x, up, down);
    if (isfinite(x) && (!same_bits(interval__up_finite(x), up) ||
                        !same_bits(interval__down_finite(x), down)))
        fail_msg("finite steps of %a", x);
}

static void test_rounding_steps(void **state)
{
    (void)state;
    static const double sp[] = {0.0, -0.0, DBL_MIN, -DBL_MIN, 0x1p-1074, -0x1p-1074,
                                0x1.fffffffffffffp-1023, -0x1.fffffffffffffp-1023, DBL_MAX,
                                -DBL_MAX, INFINITY, -INFINITY, NAN, -NAN, 1.0, -1.0};
    for (size_t i = 0; i < sizeof sp / sizeof sp[0]; i++)
        check_steps(sp[i]);
    for (int i = 0; i < 200000; i++) {
        uint64_t u = next_u64();
        double x;
        memcpy(&x, &u, sizeof x);
        check_steps(x);
        check_steps(rand_value());
    }
}


/* interval_add on finite sums: each end stepped outward by
 * interval__down_finite / interval__up_finite unless it is an exact zero
 * (x == -y), bit for bit, on random boxes, tiny ends and cancellations. */
static void test_add_rounding(void **state)
{
    (void)state;
    for (int i = 0; i < 200000; i++) {
        interval a = rand_interval(), b = rand_interval();
        if (i % 4 == 0) /* exact cancellation */
            b = interval_neg(a);
        if (i % 8 == 1) { /* ends near DBL_MIN */
            a.lo = ldexp(1.0 + unit(), -1022 - (int)(next_u64() % 3));
            a.hi = a.lo;
            b.lo = b.hi = -ldexp(1.0 + unit(), -1022 - (int)(next_u64() % 3));
        }
        double lo = a.lo + b.lo, hi = a.hi + b.hi;
        if (!(lo - lo == 0.0 && hi - hi == 0.0))
            continue;
        unsigned f = 0;
        interval r = interval_add(a, b, &f);
        double el = lo == 0.0 && a.lo == -b.lo ? lo : interval__down_finite(lo);
        double eh = hi == 0.0 && a.hi == -b.hi ? hi : interval__up_finite(hi);
        if (!same_bits(r.lo, el) || !same_bits(r.hi, eh) || f)
            fail_msg("[%a, %a] + [%a, %a]: [%a, %a], expected [%a, %a]", a.lo, a.hi, b.lo, b.hi,
                     r.lo, r.hi, el, eh);
    }
}

static void check_exp_rounding(interval a)
{
    unsigned f = 0;
    interval r = interval_exp(a, &f);
    double l = interval_next_down(interval_next_down(exp_kernel(a.lo)));
    double h = interval_next_up(interval_next_up(exp_kernel(a.hi)));
    if (l < DBL_MIN)
        l = 0.0;
    if (h < DBL_MIN)
        h = DBL_MIN;
    if (!same_bits(r.lo, l) || !same_bits(r.hi, h) || f)
        fail_msg("exp [%a, %a]: [%a, %a], expected [%a, %a]", a.lo, a.hi, r.lo, r.hi, l, h);
}

static void test_exp_rounding(void **state)
{
    (void)state;
    for (int i = 0; i < 100000; i++) {
        interval a = rand_interval();
        if (!interval_is_nan(a))
            check_exp_rounding(a);
    }
    static const double edges[] = {-745.2, -745.1, -708.4, -708.39, -707.7, -707.6, 0.0,
                                   709.0, 709.7, 709.78, 709.79, 710.0};
    for (size_t e = 0; e < sizeof edges / sizeof edges[0]; e++)
        for (int i = 0; i < 2000; i++) {
            double x = edges[e] + (unit() - 0.5) * 0.02;
            interval a = {x, x};
            check_exp_rounding(a);
        }
    check_exp_rounding((interval){-INFINITY, INFINITY});
}

/* Whether [r.lo, r.hi] holds sin (or cos) at x, by MPFR. */
static int trig_holds(interval r, double x, int is_cos)
{
    double rd, ru;
    exact_at(is_cos ? COS : SIN, x, 0.0, 0.0, &rd, &ru);
    return r.lo <= rd && ru <= r.hi;
}

/* interval_sincos: the midpoint form on narrow intervals holds sin and cos
 * at the ends, the midpoint, random interior points and the extrema inside;
 * it is no wider than the range's slope bound plus the remainder; each
 * enclosure is the same with the other pointer NULL; wide or far intervals
 * get interval_sin's and interval_cos's. */
static void test_sincos(void **state)
{
    (void)state;
    static const double scale[] = {1.0, 10.0, 1e3, 1e7};
    static const double width[] = {0.0, 1e-12, 1e-6, 0.01, 0.1, 0.25};
    for (int n = 0; n < 20000; n++) {
        double c = (unit() - 0.5) * 2 * scale[n % 4];
        if (n % 5 == 0) /* near an extremum of sin or cos */
            c = (double)(long)(c / (M_PI / 2)) * (M_PI / 2) + (unit() - 0.5) * 1e-3;
        double w = n % 7 == 6 ? unit() * 0.25 : width[n % 6];
        interval a = {c - w / 2, c + w / 2};
        if (a.hi - a.lo > 0.25)
            a.hi = a.lo + 0.25;
        unsigned f = 0;
        interval s, co, s1, c1;
        interval_sincos(a, &s, &co, &f);
        interval_sincos(a, &s1, NULL, &f);
        interval_sincos(a, NULL, &c1, &f);
        assert_int_equal(f, 0);
        assert_true(s.lo == s1.lo && s.hi == s1.hi && co.lo == c1.lo && co.hi == c1.hi);
        double h = (a.hi - a.lo) / 2, bound = 2 * h + h * h + 1e-9;
        if (!(s.hi - s.lo <= bound && co.hi - co.lo <= bound))
            fail_msg("sincos([%a,%a]) too wide: [%a,%a] [%a,%a]", a.lo, a.hi, s.lo, s.hi, co.lo, co.hi);
        double pts[8] = {a.lo, a.hi, 0.5 * a.lo + 0.5 * a.hi};
        int np = 3;
        for (; np < 6; np++)
            pts[np] = witness(a, 2);
        double k = ceil(a.lo / (M_PI / 2)); /* an extremum inside, as a double */
        if (k * (M_PI / 2) <= a.hi)
            pts[np++] = k * (M_PI / 2);
        for (int j = 0; j < np; j++)
            if (!trig_holds(s, pts[j], 0) || !trig_holds(co, pts[j], 1))
                fail_msg("sincos([%a,%a]) = [%a,%a] [%a,%a] misses the value at %a", a.lo, a.hi,
                         s.lo, s.hi, co.lo, co.hi, pts[j]);
    }
    static const interval wide[] = {{0.0, 0.5}, {-3.0, 3.0}, {1e9, 1e9}, {-INFINITY, 1.0}};
    for (size_t j = 0; j < sizeof wide / sizeof wide[0]; j++) {
        unsigned f = 0, g = 0;
        interval s, co, s0 = interval_sin(wide[j], &g), c0 = interval_cos(wide[j], &g);
        interval_sincos(wide[j], &s, &co, &f);
        assert_true(s.lo == s0.lo && s.hi == s0.hi && co.lo == c0.lo && co.hi == c0.hi && f == g);
    }
    unsigned f = 0;
    interval s, co;
    interval_sincos(interval_nan(), &s, &co, &f);
    assert_true(interval_is_nan(s) && interval_is_nan(co) && f == INTERVAL_MAYBE_NAN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sound_neg), cmocka_unit_test(test_sound_add),
        cmocka_unit_test(test_sound_sub), cmocka_unit_test(test_sound_mul),
        cmocka_unit_test(test_sound_div), cmocka_unit_test(test_sound_sqr),
        cmocka_unit_test(test_sound_sqrt), cmocka_unit_test(test_sound_exp),
        cmocka_unit_test(test_sound_log), cmocka_unit_test(test_sound_abs),
        cmocka_unit_test(test_sound_sin), cmocka_unit_test(test_sound_cos),
        cmocka_unit_test(test_sound_tan), cmocka_unit_test(test_sound_min),
        cmocka_unit_test(test_sound_max), cmocka_unit_test(test_sound_powc),
        cmocka_unit_test(test_point_box_width), cmocka_unit_test(test_pitfalls),
        cmocka_unit_test(test_exp_rounding), cmocka_unit_test(test_rounding_steps),
        cmocka_unit_test(test_add_rounding), cmocka_unit_test(test_sincos),
    };
    return cmocka_run_group_tests(tests, mpfr_setup, mpfr_teardown);
}
