/* Numbers at the edges (issue 13): interval operations on overflowed
 * (infinite) ends raise no invalid-operation exception, so the trap mode of
 * the test builds (DDA_FPE_TRAPS=1) is quiet on scenes that merely overflow;
 * a divisor that is exactly zero leaves no finite value (no surface); a - a
 * encloses to [0, 0] over a box. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fenv.h>
#include <float.h>
#include <math.h>
#include <string.h>

#include "common/expr/interval.h"
#include "common/expr/scene.h"

/* Ends read through volatile, so that nothing is folded at compile time and
 * every operation runs (and could raise) at run time. */
static interval iv(double lo, double hi)
{
    volatile double l = lo, h = hi;
    interval r = {l, h};
    return r;
}

static int same(interval r, double lo, double hi)
{
    return memcmp(&r.lo, &lo, sizeof lo) == 0 && memcmp(&r.hi, &hi, sizeof hi) == 0;
}

#define QUIET(expr)                                                                                \
    do {                                                                                           \
        feclearexcept(FE_ALL_EXCEPT);                                                              \
        r = (expr);                                                                                \
        if (fetestexcept(FE_INVALID))                                                              \
            fail_msg("%s raised an invalid operation", #expr);                                     \
    } while (0)

static void test_infinite_ends_are_quiet(void **state)
{
    (void)state;
    interval r;
    unsigned f = 0;
    /* exp(x*1e6) - 2 over a cell where exp overflows: [e, inf] + [-2, -2] */
    QUIET(interval_add(iv(1.0, INFINITY), iv(-2.0, -2.0), &f));
    assert_true(same(r, nextafter(-1.0, -2.0), INFINITY) && f == 0);
    QUIET(interval_sub(iv(-INFINITY, 0.0), iv(1.0, 2.0), &f));
    assert_true(same(r, -INFINITY, nextafter(-1.0, 0.0)) && f == 0);
    QUIET(interval_add(iv(INFINITY, INFINITY), iv(1.0, 1.0), &f));
    assert_true(same(r, DBL_MAX, INFINITY) && f == 0); /* the lower end steps down */
    /* -inf + inf inside the box: flagged, not computed */
    QUIET(interval_add(iv(0.0, INFINITY), iv(-INFINITY, 0.0), &f));
    assert_true(same(r, -INFINITY, INFINITY) && f == INTERVAL_MAYBE_NAN);
    f = 0;
    /* x * exp(x*1e6) on [0, 1]: 0 * inf is flagged and counts as 0 */
    QUIET(interval_mul(iv(0.0, 1.0), iv(1.0, INFINITY), &f));
    assert_true(same(r, 0.0, INFINITY) && f == INTERVAL_MAYBE_NAN);
    f = 0;
    QUIET(interval_mul(iv(2.0, 3.0), iv(-INFINITY, -1.0), &f));
    assert_true(same(r, -INFINITY, nextafter(-2.0, 0.0)) && f == 0);
    /* inf / inf: flagged, the whole line */
    QUIET(interval_div(iv(1.0, INFINITY), iv(1.0, INFINITY), &f));
    assert_true(same(r, -INFINITY, INFINITY) && f == INTERVAL_MAYBE_NAN);
    f = 0;
    QUIET(interval_div(iv(1.0, 2.0), iv(4.0, INFINITY), &f));
    assert_true(r.lo <= 0.0 && r.lo >= -DBL_MIN && r.hi >= 0.5 && f == 0);
}

static void test_zero_divisor_has_no_value(void **state)
{
    (void)state;
    unsigned f = 0;
    interval r = interval_div(iv(1.0, 2.0), iv(0.0, 0.0), &f);
    assert_true(interval_is_nan(r) && f == INTERVAL_MAYBE_NAN);
    f = 0;
    r = interval_div(iv(1.0, 2.0), iv(0.0, 1.0), &f); /* a pole at the edge: kept */
    assert_true(same(r, -INFINITY, INFINITY) && f == 0);
}

/* f's enclosure over the box [-1, 1]^3. */
static interval over_box(const char *text, unsigned *flags)
{
    scene *sc = NULL;
    scene_error err;
    if (scene_parse(text, strlen(text), &sc, &err) != 0)
        fail_msg("%s: %u:%u: %s", text, err.line, err.col, err.message);
    static interval slots[256];
    interval box[3] = {{-1.0, 1.0}, {-1.0, 1.0}, {-1.0, 1.0}};
    assert_true(sc->surfaces[0].tape.n <= 256);
    *flags = 0;
    interval v = tape_eval_interval(&sc->surfaces[0].tape, box, slots, flags);
    scene_free(sc);
    return v;
}

static void test_poles_without_a_finite_value(void **state)
{
    (void)state;
    unsigned f;
    interval v = over_box("bounds -1 -1 -1 1 1 1\nsurface x - x\n", &f);
    assert_true(same(v, 0.0, 0.0) && f == 0);
    v = over_box("bounds -1 -1 -1 1 1 1\nsurface 1/(x-x)\n", &f);
    assert_true(interval_is_nan(v)); /* defined nowhere: not a surface */
    v = over_box("bounds -1 -1 -1 1 1 1\nsurface 1/(x*0) + y\n", &f);
    assert_true(interval_is_nan(v));
    v = over_box("bounds -1 -1 -1 1 1 1\nsurface 1/x - 2\n", &f); /* a real pole: kept */
    assert_true(v.lo == -INFINITY && v.hi == INFINITY);
}

/* The libm operations widen by two steps: with both ends normal numbers,
 * exactly two nextafter steps outward (the fast path that makes them one
 * step of 2), across the binades, both signs and up to DBL_MAX (tan of
 * point intervals: its ends are tan(x) itself; powc near overflow). */
static void test_two_steps_are_nextafter(void **state)
{
    (void)state;
    static const double xs[] = {0.1, -0.1, 0.7853981633974483, -1.2, 1.5707963,
                                -1.5707963, 1e-300, -1e-300, 3e-308, -3e-308};
    for (size_t i = 0; i < sizeof xs / sizeof *xs; i++) {
        unsigned f = 0;
        double t = tan(xs[i]);
        interval r = interval_tan(iv(xs[i], xs[i]), &f);
        if (fabs(t) >= 0x1p-1020) /* the ends of two steps below stay normal */
            assert_true(same(r, nextafter(nextafter(t, -INFINITY), -INFINITY),
                             nextafter(nextafter(t, INFINITY), INFINITY)));
        assert_true(r.lo < t && t < r.hi && f == 0);
    }
    for (double x = 1.0; x < 1e300; x *= 7.3) { /* pow(x, 1.5) up to overflow */
        unsigned f = 0;
        double p = pow(x, 1.5);
        interval r = interval_powc(iv(x, x), 1.5, &f);
        double lo = nextafter(nextafter(p, -INFINITY), -INFINITY);
        double hi = p == INFINITY ? INFINITY : nextafter(nextafter(p, INFINITY), INFINITY);
        if (!same(r, lo, hi))
            fail_msg("powc(%a, 1.5) = [%a, %a], nextafter twice [%a, %a]", x, r.lo, r.hi, lo, hi);
    }
    unsigned f = 0;
    interval r = interval_powc(iv(0x1.fffffffffffffp+681, 0x1.fffffffffffffp+681), 1.5, &f);
    assert_true(r.hi == INFINITY || r.hi == DBL_MAX || r.hi > 0x1p1022); /* near DBL_MAX */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_infinite_ends_are_quiet),
        cmocka_unit_test(test_zero_divisor_has_no_value),
        cmocka_unit_test(test_poles_without_a_finite_value),
        cmocka_unit_test(test_two_steps_are_nextafter),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
