/* Tests for common/expr/exp_kernel.h: its error against MPFR (correctly
 * rounded at 200 bits) over the whole range, the limits and the special
 * values, no invalid-operation flag, and the lane loop's bits against the
 * scalar call. interval_exp's widening (two bit steps, a relative 2^-52 at
 * least) relies on the relative error bound checked here; the analysis is in
 * docs/NUMERICS.md ("exp"). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fenv.h>
#include <float.h>
#include <math.h>
#include <mpfr.h>
#include <string.h>

#include "bench/rng.h"
#include "common/expr/exp_kernel.h"
#include "common/expr/interval.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define NPOINTS 20000
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NPOINTS 20000
#endif
#endif
#ifndef NPOINTS
#define NPOINTS 200000
#endif

/* The bound of docs/NUMERICS.md: |e_kernel(x) / e^x - 1| <= 0.8 * 2^-52 where
 * the result is normal (the measured worst is about 0.67 * 2^-52). */
#define REL_BOUND (0.8 * 0x1p-52)

static uint64_t rng = 0x2545f4914f6cdd1dull;

static mpfr_t mx, me, md;

static int mpfr_setup(void **state)
{
    (void)state;
    mpfr_inits2(200, mx, me, md, (mpfr_ptr)0);
    return 0;
}

static int mpfr_teardown(void **state)
{
    (void)state;
    mpfr_clears(mx, me, md, (mpfr_ptr)0);
    mpfr_free_cache();
    return 0;
}

/* |y / e^x - 1| in units of 2^-52 (e^x normal), or |y - e^x| in units of the
 * least subnormal (e^x below DBL_MIN). */
static double error_of(double x, double y, int *subnormal)
{
    mpfr_set_d(mx, x, MPFR_RNDN);
    mpfr_exp(me, mx, MPFR_RNDN);
    mpfr_sub_d(md, me, y, MPFR_RNDN);
    *subnormal = mpfr_cmp_d(me, DBL_MIN) < 0;
    if (*subnormal)
        mpfr_mul_2si(md, md, 1074, MPFR_RNDN);
    else {
        mpfr_div(md, md, me, MPFR_RNDN);
        mpfr_mul_2si(md, md, 52, MPFR_RNDN);
    }
    return fabs(mpfr_get_d(md, MPFR_RNDN));
}

static void check_range(double lo, double hi, const char *what)
{
    double worst = 0.0, worst_sub = 0.0, at = lo;
    for (int i = 0; i < NPOINTS; i++) {
        const double x = lo + (hi - lo) * rng_unit(rng_xorshift64(&rng));
        int sub;
        const double e = error_of(x, exp_kernel(x), &sub);
        if (sub) {
            if (e > worst_sub)
                worst_sub = e;
        } else if (e > worst) {
            worst = e;
            at = x;
        }
    }
    if (worst * 0x1p-52 > REL_BOUND || worst_sub > 1.0)
        fail_msg("%s: relative error %.4f * 2^-52 at %a, subnormal %.3f", what, worst, at,
                 worst_sub);
}

static void test_error_bound(void **state)
{
    (void)state;
    check_range(-0.3466, 0.3466, "the reduced range");
    check_range(-1.0, 1.0, "[-1, 1]");
    check_range(-60.0, 10.0, "blob exponents");
    check_range(-708.0, 709.78, "the normal results");
    check_range(-745.2, -708.0, "the subnormal results");
}

/* Arguments where the reduction's k changes: x near (j + 1/2) ln 2, either
 * side, over the whole range of j. */
static void test_error_at_reduction_ties(void **state)
{
    (void)state;
    double worst = 0.0, at = 0.0;
    for (int j = -1074; j <= 1023; j++) {
        const double mid = ((double)j + 0.5) * 0.69314718055994530942;
        double x = nextafter(mid, -INFINITY);
        for (int s = 0; s < 8; s++, x = nextafter(x, INFINITY)) {
            int sub;
            const double e = error_of(x, exp_kernel(x), &sub);
            if (!sub && e > worst) {
                worst = e;
                at = x;
            }
            assert_true(!sub || e <= 1.0);
        }
    }
    if (worst * 0x1p-52 > REL_BOUND)
        fail_msg("relative error %.4f * 2^-52 at %a", worst, at);
}

static void test_limits_and_specials(void **state)
{
    (void)state;
    feclearexcept(FE_ALL_EXCEPT);
    assert_true(isnan(exp_kernel(NAN)));
    assert_true(isnan(exp_kernel(-NAN)));
    assert_true(exp_kernel(INFINITY) == INFINITY);
    const double z = exp_kernel(-INFINITY);
    assert_true(z == 0.0 && !signbit(z));
    assert_true(exp_kernel(0.0) == 1.0 && exp_kernel(-0.0) == 1.0);
    assert_true(exp_kernel(0x1p-1074) == 1.0 && exp_kernel(-0x1p-1074) == 1.0);
    assert_true(exp_kernel(1e300) == INFINITY && exp_kernel(DBL_MAX) == INFINITY);
    assert_true(exp_kernel(-1e300) == 0.0 && exp_kernel(-DBL_MAX) == 0.0);
    assert_false(fetestexcept(FE_INVALID));
    /* the overflow threshold: ln(DBL_MAX) = 709.782712893383996843 */
    assert_true(isfinite(exp_kernel(709.782712893383973096)));
    assert_true(exp_kernel(nextafter(709.782712893383973096, INFINITY)) == INFINITY);
    assert_true(exp_kernel(709.9) == INFINITY && exp_kernel(710.0) == INFINITY);
    assert_true(exp_kernel(745.0) == INFINITY && exp_kernel(746.5) == INFINITY);
    /* the underflow threshold: below ln(2^-1075) = -745.1332191019411 the
     * result rounds to 0, above it to the least subnormal */
    assert_true(exp_kernel(-745.13) == 0x1p-1074);
    assert_true(exp_kernel(-745.14) == 0.0);
    assert_true(exp_kernel(-746.0) == 0.0 && exp_kernel(-746.5) == 0.0);
    /* monotone across the limits of the clamp and of the two-factor scaling */
    const double edges[] = {-746.0, -745.14, -708.4, -708.39, 709.78, 710.0};
    for (unsigned i = 0; i < sizeof edges / sizeof edges[0]; i++) {
        double x = edges[i] - 1e-9;
        for (int s = 0; s < 16; s++) {
            const double x2 = nextafter(x, INFINITY);
            assert_true(exp_kernel(x) <= exp_kernel(x2));
            x = x2;
        }
    }
}

/* The loop the lane evaluators run (a constant trip count: vector code in
 * the builds that vectorise it) gives the scalar call's bits. */
static void test_lanes_same_bits(void **state)
{
    (void)state;
    enum { W = 8 };
    for (int i = 0; i < NPOINTS / W; i++) {
        double x[W], y[W];
        for (int l = 0; l < W; l++) {
            const uint64_t u = rng_xorshift64(&rng);
            x[l] = (u & 3) == 0 ? -800.0 + 1600.0 * rng_unit(u)
                                : -50.0 + 60.0 * rng_unit(rng_xorshift64(&rng));
        }
        for (int l = 0; l < W; l++)
            y[l] = exp_kernel(x[l]);
        for (int l = 0; l < W; l++) {
            volatile double xv = x[l]; /* kept out of the vector loop */
            const double s = exp_kernel(xv);
            assert_memory_equal(&s, &y[l], sizeof s);
        }
    }
}

/* interval_exp encloses e^x at the ends of random intervals (MPFR). */
static void test_interval_exp_encloses(void **state)
{
    (void)state;
    for (int i = 0; i < NPOINTS; i++) {
        double a = -740.0 + 1449.0 * rng_unit(rng_xorshift64(&rng));
        double b = a + ldexp(rng_unit(rng_xorshift64(&rng)), -(int)(rng_xorshift64(&rng) % 40));
        unsigned flags = 0;
        const interval v = interval_exp((interval){a, b}, &flags);
        assert_int_equal(flags, 0);
        mpfr_set_d(mx, a, MPFR_RNDN);
        mpfr_exp(me, mx, MPFR_RNDN);
        assert_true(mpfr_cmp_d(me, v.lo) >= 0);
        mpfr_set_d(mx, b, MPFR_RNDN);
        mpfr_exp(me, mx, MPFR_RNDN);
        assert_true(mpfr_cmp_d(me, v.hi) <= 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_bound),
        cmocka_unit_test(test_error_at_reduction_ties),
        cmocka_unit_test(test_limits_and_specials),
        cmocka_unit_test(test_lanes_same_bits),
        cmocka_unit_test(test_interval_exp_encloses),
    };
    return cmocka_run_group_tests(tests, mpfr_setup, mpfr_teardown);
}
