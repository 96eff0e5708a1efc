/* Tests for the error-bounded directional evaluator tape_eval_dir_err
 * (common/expr/tape_err.h): on random points of every op, composed so that
 * the operands carry errors, with random input errors, its value and
 * derivative are tape_eval_dir's bit for bit, its bounds hold a long-double
 * reference at a random exact point within the input errors (for a pruned
 * constant, at either end of its interval), they meet the interval
 * enclosure over the point's error box and are no looser than a few times
 * it; near cancellation, large exponents and at the domain edges (sqrt and
 * log near 0, a divisor near 0, a pole of tan, a kink of abs, min, max) it
 * either holds or gives up, and it gives up where the edge is within the
 * errors. Random expression trees as well. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "common/expr/tape_dir.h"
#include "common/expr/tape_err.h"
#include "common/expr/tape_int.h"
#include "tests/test_tape_util.h"
#include "tests/tape_ref.h"

typedef struct tally {
    unsigned tried, ok;
} tally;

/* One point: p with input errors ep, an exact point P within them. Checks
 * everything the header promises when the evaluator answers. */
static void check_point(const char *what, const tape *t, const double p[3], const double ep[3],
                        const double d[3], double loose, tally *ty)
{
    static tape_edir es[MAXSLOTS];
    static tape_dir1 ds[MAXSLOTS];
    static tape_idir1 is[MAXSLOTS];
    static ldual ls[MAXSLOTS];
    static double slots[MAXSLOTS];
    assert_true(t->n <= MAXSLOTS);
    tape_edir e;
    ty->tried++;
    if (!tape_eval_dir_err(t, p, ep, d, &e, es))
        return;
    ty->ok++;
    double dd;
    const double v = tape_eval_dir(t, p, d, &dd, ds);
    if (!(e.v == v && e.d == dd && v == tape_eval(t, p[0], p[1], p[2], slots)))
        fail_msg("%s: value %.17g / %.17g, derivative %.17g / %.17g", what, e.v, v, e.d, dd);
    assert_true(e.ev >= 0.0 && e.ed >= 0.0 && isfinite(e.ev) && isfinite(e.ed));
    /* the interval enclosure over the error box holds the exact values too */
    interval box[3];
    for (int k = 0; k < 3; k++) {
        box[k].lo = interval_next_down(p[k] - ep[k]);
        box[k].hi = interval_next_up(p[k] + ep[k]);
    }
    unsigned flags = 0;
    interval D;
    const interval G = tape_eval_interval_dir(t, box, d, &D, is, &flags);
    if (!flags) {
        if (!(e.v - e.ev <= G.hi && e.v + e.ev >= G.lo && e.d - e.ed <= D.hi &&
              e.d + e.ed >= D.lo))
            fail_msg("%s: %.17g +- %.3g, interval [%.17g, %.17g]; derivative %.17g +- %.3g, "
                     "[%.17g, %.17g]", what, e.v, e.ev, G.lo, G.hi, e.d, e.ed, D.lo, D.hi);
        /* no looser than the interval evaluation, give or take (a factor
         * of 8 for one op, more where ops nest) */
        if (!(e.ev <= loose * (G.hi - G.lo) + 1e-100 && e.ed <= loose * (D.hi - D.lo) + 1e-100))
            fail_msg("%s: bounds %.3g %.3g, interval widths %.3g %.3g", what, e.ev, e.ed,
                     G.hi - G.lo, D.hi - D.lo);
    }
    /* the reference at exact points within the input errors */
    for (int end = 0; end < 3; end++) {
        long double P[3];
        for (int k = 0; k < 3; k++) {
            P[k] = (long double)p[k] + (long double)ep[k] * (2.0L * (long double)unit() - 1.0L);
            if (!(fabsl(P[k] - (long double)p[k]) <= (long double)ep[k]))
                P[k] = p[k]; /* (rounded beyond the error: the point itself) */
        }
        const ldual r = ref_eval(t, P, d, end, ls);
        /* (the reference's own error: 2^-11 of the double evaluation's) */
        const long double sv = (long double)e.ev * 0x1p-7L + fabsl(r.v) * 0x1p-60L;
        const long double sd = (long double)e.ed * 0x1p-7L + fabsl(r.d) * 0x1p-60L;
        if (!(fabsl(r.v - e.v) <= e.ev + sv && fabsl(r.d - e.d) <= e.ed + sd))
            fail_msg("%s at (%.17g, %.17g, %.17g) end %d: value %.17g +- %.3g, reference "
                     "%.20Lg; derivative %.17g +- %.3g, reference %.20Lg",
                     what, p[0], p[1], p[2], end, e.v, e.ev, r.v, e.d, e.ed, r.d);
    }
}

static void rand_dir(double d[3])
{
    for (int k = 0; k < 3; k++)
        d[k] = next_u64() % 5 == 0 ? 0.0 : 2.0 * unit() - 1.0;
}

/* Input errors: none, a few ulps, or up to 2^-20 of the coordinate. */
static void rand_err(const double p[3], double ep[3])
{
    const uint64_t kind = next_u64() % 3;
    for (int k = 0; k < 3; k++)
        ep[k] = kind == 0 ? 0.0
                : kind == 1 ? ldexp(fabs(p[k]) + 1e-300, -52) * unit()
                            : ldexp(fabs(p[k]) + 1e-3, -20 - (int)(next_u64() % 30));
}

/* `n` random points in [lo, hi]^3; at least `min_ok` of them answered. */
static void run_loose(const char *expr, double lo, double hi, unsigned n, double min_ok,
                      double loose)
{
    scene *s = parse_surface(expr);
    const tape *t = &s->surfaces[0].tape;
    static double slots[MAXSLOTS];
    tally ty = {0, 0};
    for (unsigned i = 0; i < n / SCALE; i++) {
        double p[3], ep[3], d[3];
        for (int k = 0; k < 3; k++)
            p[k] = lo + (hi - lo) * unit();
        if (isnan(tape_eval(t, p[0], p[1], p[2], slots)))
            continue; /* undefined there */
        rand_err(p, ep);
        rand_dir(d);
        check_point(expr, t, p, ep, d, loose, &ty);
    }
    if (!((double)ty.ok >= min_ok * (double)ty.tried))
        fail_msg("%s: %u of %u answered", expr, ty.ok, ty.tried);
    scene_free(s);
}

static void run(const char *expr, double lo, double hi, unsigned n, double min_ok)
{
    run_loose(expr, lo, hi, n, min_ok, 8.0);
}

static void test_every_op(void **state)
{
    (void)state;
    run("x*y + z", -4, 4, 3000, 0.99);
    run("x*y - z*x + 0.78", -4, 4, 3000, 0.99);
    run("-(x*y) + (x - y)^2 - z", -4, 4, 3000, 0.99);
    run("sqrt(x*x + y*y + 0.01) - z", -4, 4, 3000, 0.99);
    run("exp(x*y - z) + exp(-3.25*((x-0.78)^2 + (y-0.78)^2 + (z-0.78)^2))", -2, 2, 3000, 0.99);
    run("log(x*x + y*y + 0.5) * z", -4, 4, 3000, 0.99);
    run("abs(x - y) + z", -4, 4, 3000, 0.99);
    run("sin(3*x + y) + cos(x*y) * z", -4, 4, 3000, 0.99);
    run("tan(0.3*x + 0.1*y) + z", -4, 4, 3000, 0.99);
    run("x / (y*y + 0.5) - z / (x + 5)", -4, 4, 3000, 0.99);
    run("min(x, y*y) + max(z, x*y)", -4, 4, 3000, 0.95);
    run("(x*x + 1)^0.375 + (y*y + 2)^-1.5 + pow(z*z + 0.5, 2.5)", -4, 4, 3000, 0.99);
    run("x^4 - 5*x^2*y + z^3 - 1/(x*x + 1)", -4, 4, 3000, 0.99);
}

/* Cancellation, large values and exponents, the domain edges: an answer is
 * checked like any other; a point within the errors of an edge must give
 * none. */
static void test_edges(void **state)
{
    (void)state;
    run("(x + 1e6) - 1e6 - x + y*y - y*y", -4, 4, 2000, 0.99);
    run("x*x - y*y", -4, 4, 2000, 0.99);
    run("exp(60 + x) - exp(60 + y)", -4, 4, 2000, 0.3);
    run("1e20*x*y - 1e20*z", -4, 4, 2000, 0.99);
    run("1e40*x*y*1e40", -4, 4, 500, 0.0);
    run_loose("sqrt(x - 0.5) + y", 0.5, 0.5000001, 2000, 0.5, 64.0);
    run_loose("log(x - 0.5) + y", 0.5, 0.5000001, 2000, 0.5, 64.0);
    run_loose("1 / (x - 0.5) + y", 0.4999999, 0.5000001, 2000, 0.5, 64.0);
    run_loose("tan(x) + y", 1.5707963, 1.5707964, 2000, 0.0, 64.0);
    run("abs(x - 0.5) + y", 0.4999999, 0.5000001, 2000, 0.5);
    run("min(x, y) + max(x, z)", -1e-12, 1e-12, 2000, 0.0);
    scene *s = parse_surface("sqrt(x - 0.5) + log(y - 0.5) + 1/(z - 0.5)");
    const tape *t = &s->surfaces[0].tape;
    static tape_edir es[MAXSLOTS];
    tape_edir e;
    const double d[3] = {1, 1, 1}, ep[3] = {0x1p-60, 0x1p-60, 0x1p-60};
    const double at[3][3] = {{0.5, 0.7, 0.7}, {0.7, 0.5, 0.7}, {0.7, 0.7, 0.5}};
    for (int i = 0; i < 3; i++)
        assert_int_equal(tape_eval_dir_err(t, at[i], ep, d, &e, es), 0);
    /* just off the edges, but within the input errors of them */
    const double wide[3] = {0x1p-50, 0x1p-50, 0x1p-50};
    const double near[3][3] = {{0.5 + 0x1p-52, 0.7, 0.7}, {0.7, 0.5 + 0x1p-52, 0.7},
                               {0.7, 0.7, 0.5 + 0x1p-52}};
    for (int i = 0; i < 3; i++) {
        assert_int_equal(tape_eval_dir_err(t, near[i], wide, d, &e, es), 0);
        assert_int_equal(tape_eval_dir_err(t, near[i], ep, d, &e, es), 1);
    }
    assert_int_equal(tape_eval_dir_err(t, (double[3]){0.7, 0.7, 0.7}, ep, d, &e, es), 1);
    scene_free(s);
    const char *kinks[] = {"abs(x - 0.5)", "min(x, 0.5)", "max(0.5, x)", "tan(x - 0.5 + pi/2)",
                           "exp(x + 69.5)"};
    for (size_t i = 0; i < sizeof kinks / sizeof kinks[0]; i++) {
        s = parse_surface(kinks[i]);
        assert_int_equal(tape_eval_dir_err(&s->surfaces[0].tape, (double[3]){0.5, 0, 0}, ep, d,
                                           &e, es),
                         0);
        scene_free(s);
    }
}

/* Random expression trees (every op, nested) at random points. */
static void test_random_trees(void **state)
{
    (void)state;
    static double slots[MAXSLOTS];
    char text[2048];
    unsigned answered = 0, tried = 0;
    for (unsigned k = 0; k < 600 / SCALE; k++) {
        scene *s = rand_tree(text, sizeof text);
        const tape *t = &s->surfaces[0].tape;
        for (unsigned i = 0; i < 20; i++) {
            double p[3], ep[3], d[3];
            for (int a = 0; a < 3; a++)
                p[a] = 8.0 * unit() - 4.0;
            if (!isfinite(tape_eval(t, p[0], p[1], p[2], slots)))
                continue;
            rand_err(p, ep);
            rand_dir(d);
            tally ty = {0, 0};
            check_point(text, t, p, ep, d, 4096.0, &ty);
            tried++;
            answered += ty.ok;
        }
        scene_free(s);
    }
    assert_true(answered * 2 > tried);
}

/* The point of a line and its rounding bound. */
static void test_point(void **state)
{
    (void)state;
    for (unsigned i = 0; i < 10000; i++) {
        const double o = ldexp(2.0 * unit() - 1.0, (int)(next_u64() % 20) - 10);
        const double m = ldexp(unit(), (int)(next_u64() % 20) - 10);
        const double d = ldexp(2.0 * unit() - 1.0, (int)(next_u64() % 20) - 10);
        double p;
        const double e = tape_err_point(o, m, d, &p);
        assert_true(p == o + m * d);
        /* the exact o + m d - p: the product's error (fma, exact) plus the
         * sum's (two-sum, exact) */
        const double q = m * d, r1 = fma(m, d, -q), bb = p - o;
        const double r2 = (o - (p - bb)) + (q - bb);
        assert_true(fabs(r1) + fabs(r2) <= e);
        assert_true(e <= 0x1p-51 * (fabs(p) + fabs(m * d)) + 0x1p-400);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_op),
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_random_trees),
        cmocka_unit_test(test_point),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
