/* Tests for the second-order and directional evaluators of the exact fast
 * path: tape_eval_interval_hess (common/expr/tape_hess.h) encloses sampled
 * finite-difference Hessians on random boxes for every op and for random
 * expression trees, and flags kinks, poles and undefined parts;
 * tape_eval_dir and tape_eval_interval_dir (tape_dir.h) agree with the
 * point and gradient evaluators and enclose the directional derivative. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>

#include "common/expr/tape_dir.h"
#include "common/expr/tape_hess.h"
#include "tests/test_tape_util.h"

static const int hr[TAPE_HN] = {0, 0, 0, 1, 1, 2}, hc[TAPE_HN] = {0, 1, 2, 1, 2, 2};

static double f_at(const tape *t, const double p[3], double *slots)
{
    return tape_eval(t, p[0], p[1], p[2], slots);
}

/* Central-difference Hessian entry e at p with step h. */
static double fd_entry(const tape *t, const double p[3], int e, double h, double *slots)
{
    const int i = hr[e], j = hc[e];
    double q[4][3];
    for (int k = 0; k < 4; k++) {
        memcpy(q[k], p, sizeof q[k]);
        q[k][i] += k & 1 ? -h : h;
        q[k][j] += k & 2 ? -h : h;
    }
    return (f_at(t, q[0], slots) - f_at(t, q[1], slots) - f_at(t, q[2], slots) +
            f_at(t, q[3], slots)) /
           (4.0 * h * h);
}

/* The Hessian enclosure over box holds the finite-difference Hessian at
 * `samples` points of it, where two step sizes agree (else the difference
 * quotient is no witness and the point is skipped). Returns the number of
 * entries checked. */
static unsigned check_hess(const tape *t, const interval box[3], unsigned samples)
{
    static tape_ihess hs[MAXSLOTS];
    static tape_dual gs[MAXSLOTS];
    static double slots[MAXSLOTS];
    interval g[3], h[TAPE_HN];
    unsigned flags = 0;
    const interval v = tape_eval_interval_hess(t, box, g, h, hs, &flags);
    if (flags)
        return 0;
    unsigned checked = 0;
    for (unsigned s = 0; s < samples; s++) {
        double p[3];
        for (int a = 0; a < 3; a++)
            p[a] = in_box(box[a]);
        const double fv = f_at(t, p, slots);
        if (!isfinite(fv))
            continue;
        assert_true(encloses(v, 0, fv));
        double grad[3];
        tape_eval_grad(t, p, grad, gs);
        for (int a = 0; a < 3; a++)
            if (isfinite(grad[a]) && !(g[a].lo <= grad[a] && grad[a] <= g[a].hi))
                fail_msg("gradient %d: %.17g not in [%.17g, %.17g]", a, grad[a], g[a].lo, g[a].hi);
        const double step = 1e-4 * (1.0 + fabs(p[0]) + fabs(p[1]) + fabs(p[2]));
        for (int e = 0; e < TAPE_HN; e++) {
            const double d1 = fd_entry(t, p, e, step, slots);
            const double d2 = fd_entry(t, p, e, 0.5 * step, slots);
            const double tol = 1e-3 * (1.0 + fabs(d1));
            if (!isfinite(d1) || !isfinite(d2) || fabs(d1 - d2) > 0.1 * tol)
                continue;
            if (!(h[e].lo - tol <= d2 && d2 <= h[e].hi + tol))
                fail_msg("entry %d at (%.9g %.9g %.9g): %.9g not in [%.9g, %.9g]", e, p[0], p[1],
                         p[2], d2, h[e].lo, h[e].hi);
            checked++;
        }
    }
    return checked;
}

/* A random box inside [-4, 4]^3 of edges up to `w`. */
static void rand_box(interval box[3], double w)
{
    for (int a = 0; a < 3; a++) {
        const double e = w * unit();
        box[a].lo = -4.0 + (8.0 - e) * unit();
        box[a].hi = box[a].lo + e;
    }
}

/* Every op, each where it is twice differentiable on [-4, 4]^3 (a decided
 * min/max, abs away from 0, tan within (-pi/2, pi/2)). */
static const char *const per_op[] = {
    "-(x*y) + z",           "(x - 0.3)^2 * y - z^3", "sqrt(x + 4.5) * y",  "exp(0.3*x*y - z)",
    "log(x + 4.5) * z",     "abs(x - 5) * y",        "abs(y + 4.5)^2 * x", "sin(x*y)",
    "cos(x + z*y)",         "tan(0.3*x) + y",        "x*y - z*x",          "x / (y + 5) + z / (x - 6)",
    "min(x, y + 10) * z",   "max(x + 10, y) * z",    "(x + 5)^2.5 * y",    "pow(x + 4.5, 0.7) - z",
    "1 / (x*x + y*y + 1)",  "exp(-3.25*((x-0.78)^2+(y-0.78)^2+(z-0.78)^2)) - 0.9",
};

static void test_hess_every_op(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof per_op / sizeof per_op[0]; k++) {
        scene *s = parse_surface(per_op[k]);
        unsigned checked = 0;
        for (unsigned b = 0; b < 200 / SCALE + 5; b++) {
            interval box[3];
            rand_box(box, b % 3 == 0 ? 2.0 : 0.2);
            checked += check_hess(&s->surfaces[0].tape, box, 8);
        }
        if (checked < 100)
            fail_msg("%s: only %u entries checked", per_op[k], checked);
        scene_free(s);
    }
}

static void test_hess_random_trees(void **state)
{
    (void)state;
    char text[4096];
    unsigned checked = 0;
    for (unsigned n = 0; n < 3000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        interval box[3];
        rand_tree_box(box);
        checked += check_hess(&s->surfaces[0].tape, box, 3);
        scene_free(s);
    }
    assert_true(checked > 1000 / SCALE);
}

/* Kinks, poles and undefined parts switch the bound off. */
static void test_hess_off(void **state)
{
    (void)state;
    static tape_ihess hs[MAXSLOTS];
    static const struct {
        const char *expr;
        double lo, hi; /* x's range; y, z in [0.5, 1] */
        int finite;
    } cases[] = {
        {"abs(x) + y", -0.5, 0.5, 0}, {"abs(x) + y", 0.1, 0.5, 1},
        {"min(x, y)", 0.0, 1.0, 0},   {"min(x, y)", 2.0, 3.0, 1},
        {"max(x, z)", 0.6, 0.7, 0},   {"max(x, z)", -1.0, 0.2, 1},
        {"sqrt(x) * y", 0.0, 1.0, 0}, {"sqrt(x) * y", -1.0, 1.0, 0},
        {"sqrt(x) * y", 0.5, 1.0, 1}, {"log(x)", -0.5, 1.0, 0},
        {"y / x", -0.5, 0.5, 0},      {"y / x", 0.5, 1.5, 1},
        {"tan(x)", 1.0, 2.0, 0},      {"x^0.5 + y", 0.0, 1.0, 0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        scene *s = parse_surface(cases[k].expr);
        const interval box[3] = {{cases[k].lo, cases[k].hi}, {0.5, 1.0}, {0.5, 1.0}};
        double mag[TAPE_HN];
        const int ok = tape_hess_mag(&s->surfaces[0].tape, box, hs, mag);
        if (ok != cases[k].finite)
            fail_msg("%s on x in [%g, %g]: %s", cases[k].expr, cases[k].lo, cases[k].hi,
                     ok ? "finite" : "off");
        for (int e = 0; e < TAPE_HN; e++)
            assert_true(ok ? isfinite(mag[e]) && mag[e] >= 0.0 : mag[e] == INFINITY);
        scene_free(s);
    }
}

/* Bit for bit, or both NaN (whose sign bits -x and x * -1 may set apart). */
static int same_double(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (a != a && b != b);
}

/* The directional evaluators on t over box along d: the point one's value
 * is bit for bit tape_eval's, tape_eval_dir_grad's value and derivative are
 * tape_eval_dir's and its gradient tape_eval_grad's (bit for bit, or both
 * NaN), and where `compare` the derivative is grad . d of tape_eval_grad to
 * rounding; the interval one's value enclosure is
 * tape_eval_interval's (its flags at least those) and, unflagged, its
 * derivative encloses the point one's.
 * Returns the number of points whose derivative was enclosed. */
static unsigned check_dir(const tape *t, const interval box[3], const double d[3], int compare,
                          const char *what)
{
    static tape_dir1 ds[MAXSLOTS];
    static tape_idir1 ids[MAXSLOTS];
    static tape_dual gs[MAXSLOTS];
    static tape_dir4 d4[MAXSLOTS];
    static interval is[MAXSLOTS];
    static double slots[MAXSLOTS];
    interval D;
    unsigned flags = 0, f0 = 0, enclosed = 0;
    const interval V = tape_eval_interval_dir(t, box, d, &D, ids, &flags);
    const interval V0 = tape_eval_interval(t, box, is, &f0);
    assert_memory_equal(&V, &V0, sizeof V);
    assert_true((flags & f0) == f0); /* (the derivative may raise one more) */
    for (unsigned k = 0; k < 4; k++) {
        double p[3], grad[3], dv;
        for (int a = 0; a < 3; a++)
            p[a] = in_box(box[a]);
        const double v = tape_eval_dir(t, p, d, &dv, ds);
        const double v0 = tape_eval(t, p[0], p[1], p[2], slots);
        assert_memory_equal(&v, &v0, sizeof v);
        double dv4, grad4[3];
        const double v4 = tape_eval_dir_grad(t, p, d, &dv4, grad4, d4);
        tape_eval_grad(t, p, grad, gs);
        assert_true(same_double(v4, v) && same_double(dv4, dv));
        for (int a = 0; a < 3; a++)
            if (!same_double(grad4[a], grad[a]))
                fail_msg("%s: tape_eval_dir_grad's partial %d %.17g, tape_eval_grad's %.17g", what,
                         a, grad4[a], grad[a]);
        if (compare) {
            const double ref = grad[0] * d[0] + grad[1] * d[1] + grad[2] * d[2];
            const double scale =
                fabs(grad[0] * d[0]) + fabs(grad[1] * d[1]) + fabs(grad[2] * d[2]);
            if (!(fabs(dv - ref) <= 1e-9 * scale + 1e-300))
                fail_msg("%s: derivative %.17g, gradient . d %.17g", what, dv, ref);
        }
        if (!flags && isfinite(dv) && isfinite(v)) {
            if (!(D.lo <= dv && dv <= D.hi))
                fail_msg("%s: derivative %.17g not in [%.17g, %.17g]", what, dv, D.lo, D.hi);
            enclosed++;
        }
    }
    return enclosed;
}

static void rand_dir(double d[3], unsigned n)
{
    for (int a = 0; a < 3; a++)
        d[a] = n % 7 == 0 && a == 1 ? 0.0 : 2.0 * unit() - 1.0; /* some with a zero component */
}

static void test_dir_every_op(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof per_op / sizeof per_op[0]; k++) {
        scene *s = parse_surface(per_op[k]);
        unsigned enclosed = 0;
        for (unsigned n = 0; n < 100; n++) {
            interval box[3];
            rand_box(box, n % 2 ? 1e-9 : 0.5);
            double d[3];
            rand_dir(d, n);
            enclosed += check_dir(&s->surfaces[0].tape, box, d, 1, per_op[k]);
        }
        assert_true(enclosed == 400);
        scene_free(s);
    }
}

static void test_dir_random_trees(void **state)
{
    (void)state;
    char text[4096];
    unsigned enclosed = 0;
    for (unsigned n = 0; n < 3000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        interval box[3];
        rand_tree_box(box);
        double d[3];
        rand_dir(d, n);
        enclosed += check_dir(&s->surfaces[0].tape, box, d, 0, text);
        scene_free(s);
    }
    assert_true(enclosed > 1000 / SCALE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hess_every_op),
        cmocka_unit_test(test_hess_random_trees),
        cmocka_unit_test(test_hess_off),
        cmocka_unit_test(test_dir_every_op),
        cmocka_unit_test(test_dir_random_trees),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
