/* Tests for common/expr/sincos_kernel.h: sin and cos against MPFR (200
 * bits) over the kernel's range and at the arguments nearest the multiples
 * of pi/2, the choice of libm beyond it, special values without an
 * invalid-operation flag, the lane loop's bits against the scalar call, and
 * interval_sincos's narrow forms around MPFR's values. The bound is the one
 * docs/NUMERICS.md ("sin and cos") states and interval_sincos and the
 * error-bounded evaluator (two ulps) rely on. */
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
#include "common/expr/interval.h"
#include "common/expr/sincos_kernel.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define NPOINTS 10000
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NPOINTS 10000
#endif
#endif
#ifndef NPOINTS
#define NPOINTS 100000
#endif

/* |y / f(x) - 1| <= REL_BOUND (measured: at most 0.59 * 2^-52) */
#define REL_BOUND (0.75 * 0x1p-52)

static uint64_t rng = 0x5851f42d4c957f2dull;
static mpfr_t mx, mv, md;

static int mpfr_setup(void **state)
{
    (void)state;
    mpfr_inits2(200, mx, mv, md, (mpfr_ptr)0);
    return 0;
}

static int mpfr_teardown(void **state)
{
    (void)state;
    mpfr_clears(mx, mv, md, (mpfr_ptr)0);
    mpfr_free_cache();
    return 0;
}

/* |y / f(x) - 1| in units of 2^-52, f sin or cos (MPFR); 0 where f(x) is
 * exactly 0 and y too. */
static double rel_error(double x, double y, int cosine)
{
    mpfr_set_d(mx, x, MPFR_RNDN);
    if (cosine)
        mpfr_cos(mv, mx, MPFR_RNDN);
    else
        mpfr_sin(mv, mx, MPFR_RNDN);
    if (mpfr_zero_p(mv))
        return y == 0.0 ? 0.0 : INFINITY;
    mpfr_sub_d(md, mv, y, MPFR_RNDN);
    mpfr_div(md, md, mv, MPFR_RNDN);
    mpfr_mul_2si(md, md, 52, MPFR_RNDN);
    return fabs(mpfr_get_d(md, MPFR_RNDN));
}

static void check_at(double x, double *worst, double *at)
{
    double s, c;
    sincos_point(x, &s, &c);
    const double es = rel_error(x, s, 0), ec = rel_error(x, c, 1);
    const double e = es > ec ? es : ec;
    if (e > *worst) {
        *worst = e;
        *at = x;
    }
}

static void test_error_bound(void **state)
{
    (void)state;
    static const double ranges[] = {0.7854, 10.0, 1000.0, SINCOS_KERNEL_MAX};
    for (unsigned g = 0; g < sizeof ranges / sizeof ranges[0]; g++) {
        double worst = 0.0, at = 0.0;
        for (int i = 0; i < NPOINTS; i++)
            check_at(ranges[g] * (2.0 * rng_unit(rng_xorshift64(&rng)) - 1.0), &worst, &at);
        if (worst * 0x1p-52 > REL_BOUND)
            fail_msg("|x| <= %g: relative error %.4f * 2^-52 at %a", ranges[g], worst, at);
    }
}

/* The doubles nearest k pi/2 (where sin or cos is smallest and the
 * reduction cancels most), two either side, for k over the kernel's range
 * in steps that visit every quadrant. */
static void test_near_multiples_of_pi_over_2(void **state)
{
    (void)state;
    double worst = 0.0, at = 0.0;
    const long kmax = (long)(SINCOS_KERNEL_MAX / 1.5707963267948966);
    for (long k = -kmax; k <= kmax; k += (k > -8 && k < 8) ? 1 : 37) {
        mpfr_const_pi(mv, MPFR_RNDN);
        mpfr_mul_si(mv, mv, k, MPFR_RNDN);
        mpfr_div_2ui(mv, mv, 1, MPFR_RNDN);
        double x = nextafter(nextafter(mpfr_get_d(mv, MPFR_RNDN), -INFINITY), -INFINITY);
        for (int s = 0; s < 5; s++, x = nextafter(x, INFINITY))
            if (fabs(x) <= SINCOS_KERNEL_MAX)
                check_at(x, &worst, &at);
    }
    if (worst * 0x1p-52 > REL_BOUND)
        fail_msg("relative error %.4f * 2^-52 at %a", worst, at);
}

static void test_range_and_specials(void **state)
{
    (void)state;
    double s, c;
    feclearexcept(FE_ALL_EXCEPT);
    sincos_point(0.0, &s, &c);
    assert_true(s == 0.0 && !signbit(s) && c == 1.0);
    sincos_point(-0.0, &s, &c);
    assert_true(s == 0.0 && signbit(s) && c == 1.0); /* sin(-0) = -0 */
    sincos_point(0x1p-1074, &s, &c);
    assert_true(s == 0x1p-1074 && c == 1.0);
    sincos_point(NAN, &s, &c);
    assert_true(isnan(s) && isnan(c));
    /* the kernel itself on what it does not serve: no exception */
    const double far[] = {INFINITY, -INFINITY, NAN, 1e300, -1e20, nextafter(SINCOS_KERNEL_MAX, 1e9)};
    for (unsigned i = 0; i < sizeof far / sizeof far[0]; i++) {
        assert_false(sincos_kernel_serves(far[i]));
        sincos_kernel(far[i], &s, &c);
    }
    assert_false(fetestexcept(FE_INVALID));
    /* beyond the range: libm's sin and cos, bit for bit */
    const double big[] = {nextafter(SINCOS_KERNEL_MAX, 1e9), -3e5, 1e15, 1e300};
    for (unsigned i = 0; i < sizeof big / sizeof big[0]; i++) {
        sincos_point(big[i], &s, &c);
        const double ls = sin(big[i]), lc = cos(big[i]);
        assert_memory_equal(&s, &ls, sizeof s);
        assert_memory_equal(&c, &lc, sizeof c);
    }
    assert_true(sincos_kernel_serves(SINCOS_KERNEL_MAX) && sincos_kernel_serves(-SINCOS_KERNEL_MAX));
    /* the quadrants' signs */
    const double q[][3] = {{1.0, 0.8414709848078965, 0.5403023058681398},
                           {2.0, 0.9092974268256817, -0.4161468365471424},
                           {4.0, -0.7568024953079282, -0.6536436208636119},
                           {-1.0, -0.8414709848078965, 0.5403023058681398},
                           {5.0, -0.9589242746631385, 0.28366218546322625}};
    for (unsigned i = 0; i < sizeof q / sizeof q[0]; i++) {
        sincos_point(q[i][0], &s, &c);
        assert_true(fabs(s - q[i][1]) <= 0x1p-52 && fabs(c - q[i][2]) <= 0x1p-52);
    }
}

/* The lane loop (vector code where it is built so) gives the scalar call's
 * bits, libm's lanes among the kernel's, and lanes from n on lane 0's. */
static void test_lanes_same_bits(void **state)
{
    (void)state;
    enum { W = 8 };
    for (int i = 0; i < NPOINTS / W; i++) {
        double x[W], s[W], c[W];
        const unsigned n = 1 + (unsigned)(rng_xorshift64(&rng) % W);
        for (int l = 0; l < W; l++) {
            const uint64_t u = rng_xorshift64(&rng);
            x[l] = (u & 7) == 0 ? 1e6 * (2.0 * rng_unit(rng_xorshift64(&rng)) - 1.0)
                                : 30.0 * (2.0 * rng_unit(rng_xorshift64(&rng)) - 1.0);
        }
        sincos_point_lanes(W, n, x, s, c);
        for (unsigned l = 0; l < W; l++) {
            volatile double xv = x[l < n ? l : 0]; /* kept out of the vector loop */
            double ss, cs;
            sincos_point(xv, &ss, &cs);
            assert_memory_equal(&ss, &s[l], sizeof ss);
            assert_memory_equal(&cs, &c[l], sizeof cs);
        }
    }
}

/* interval_sincos's narrow forms (midpoint from sincos_point) enclose MPFR's
 * sin and cos at points of the interval. */
static void test_interval_sincos_encloses(void **state)
{
    (void)state;
    for (int i = 0; i < NPOINTS / 4; i++) {
        const double a = 2e3 * (2.0 * rng_unit(rng_xorshift64(&rng)) - 1.0);
        const double b = a + ldexp(rng_unit(rng_xorshift64(&rng)), -(int)(rng_xorshift64(&rng) % 30) - 8);
        interval so, co;
        unsigned flags = 0;
        interval_sincos((interval){a, b}, &so, &co, &flags);
        assert_int_equal(flags, 0);
        for (int j = 0; j < 3; j++) {
            const double x = j == 0 ? a : j == 1 ? b : a + 0.5 * (b - a);
            mpfr_set_d(mx, x, MPFR_RNDN);
            mpfr_sin(mv, mx, MPFR_RNDN);
            assert_true(mpfr_cmp_d(mv, so.lo) >= 0 && mpfr_cmp_d(mv, so.hi) <= 0);
            mpfr_cos(mv, mx, MPFR_RNDN);
            assert_true(mpfr_cmp_d(mv, co.lo) >= 0 && mpfr_cmp_d(mv, co.hi) <= 0);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_error_bound),
        cmocka_unit_test(test_near_multiples_of_pi_over_2),
        cmocka_unit_test(test_range_and_specials),
        cmocka_unit_test(test_lanes_same_bits),
        cmocka_unit_test(test_interval_sincos_encloses),
    };
    return cmocka_run_group_tests(tests, mpfr_setup, mpfr_teardown);
}
