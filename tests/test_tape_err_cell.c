/* Tests for the a-priori rounding-error bound over a box, tape_err_cell
 * (common/expr/tape_err_cell.h): in random boxes of the example scenes'
 * functions (blobs, sphere, torus, csg, gyroid) and of every op it bounds,
 * at random points with random directions (zero components among them),
 * tape_eval_dir's value and derivative lie within the bound of a
 * long-double reference (for a pruned constant, at either end of its
 * interval), and the gradient bound holds; near the surface (cancellation)
 * the bound is no wider than a small multiple of the per-point one
 * (tape_eval_dir_err) at the same point; it gives up where a kink, a
 * domain edge or a pole is within the box. The rasterizer's use, one bound
 * over the whole cube of a scene whose function has no kink, is checked on
 * every example scene. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <string.h>

#include "common/expr/tape_dir.h"
#include "common/expr/tape_err.h"
#include "common/expr/tape_err_cell.h"
#include "rasterize/build.h"
#include "tests/scene_util.h"
#include "tests/test_tape_util.h"
#include "tests/tape_ref.h"

static tape_idual gs[MAXSLOTS];
static tape_cerr cs[MAXSLOTS];
static tape_dir1 ds[MAXSLOTS];
static tape_edir es[MAXSLOTS];
static ldual ls[MAXSLOTS];

typedef struct tally {
    unsigned boxes, bounded, points;
    double worst; /* the largest ratio of the cell's value bound to the per-point one */
} tally;

/* A box of edge `size` around c (each side a random part of it). */
static void make_box(const double c[3], double size, interval box[3])
{
    for (int k = 0; k < 3; k++) {
        const double lo = c[k] - size * unit();
        box[k] = (interval){lo, lo + size};
    }
}

static void rand_dir(double d[3])
{
    for (int k = 0; k < 3; k++)
        d[k] = next_u64() % 4 == 0 ? 0.0 : ldexp(2.0 * unit() - 1.0, -(int)(next_u64() % 12));
}

/* Checks `n` random points of the box against the bound (if it is made). */
static void check_box(const char *what, const tape *t, const interval box[3], unsigned n,
                      tally *ty)
{
    assert_true(t->n <= MAXSLOTS);
    tape_cell_err ce;
    ty->boxes++;
    if (!tape_err_cell(t, box, &ce, gs, cs))
        return;
    ty->bounded++;
    assert_true(ce.ev >= 0.0 && isfinite(ce.ev));
    for (int k = 0; k < 3; k++)
        assert_true(ce.ed[k] >= 0.0 && isfinite(ce.ed[k]) && ce.grad[k] >= 0.0);
    for (unsigned i = 0; i < n; i++) {
        double p[3], d[3], dv;
        for (int k = 0; k < 3; k++)
            p[k] = in_box(box[k]);
        rand_dir(d);
        const double v = tape_eval_dir(t, p, d, &dv, ds);
        const double ed = ce.ed[0] * fabs(d[0]) + ce.ed[1] * fabs(d[1]) + ce.ed[2] * fabs(d[2]);
        const long double P[3] = {p[0], p[1], p[2]};
        ty->points++;
        for (int end = 0; end < 3; end++) {
            const ldual r = ref_eval(t, P, d, end, ls);
            /* (the reference's own error: 2^-11 of the double evaluation's) */
            const long double sv = (long double)ce.ev * 0x1p-7L + fabsl(r.v) * 0x1p-60L;
            const long double sd = (long double)ed * 0x1p-7L + fabsl(r.d) * 0x1p-60L;
            if (!(fabsl(r.v - v) <= ce.ev + sv && fabsl(r.d - dv) <= ed * 1.0000001 + sd))
                fail_msg("%s at (%.17g, %.17g, %.17g) end %d: value %.17g +- %.3g, reference "
                         "%.20Lg; derivative %.17g +- %.3g, reference %.20Lg",
                         what, p[0], p[1], p[2], end, v, ce.ev, r.v, dv, ed, r.d);
        }
        for (int k = 0; k < 3; k++) {
            const double e[3] = {k == 0, k == 1, k == 2};
            const ldual r = ref_eval(t, P, e, 0, ls);
            if (!(fabsl(r.d) <= ce.grad[k] * (1.0L + 0x1p-40L) + 1e-300L))
                fail_msg("%s: |df/dx_%d| %.17Lg over the bound %.17g", what, k, r.d, ce.grad[k]);
        }
        tape_edir pe;
        const double ep[3] = {0.0, 0.0, 0.0};
        if (tape_eval_dir_err(t, p, ep, d, &pe, es) && pe.ev > 0.0 && ce.ev / pe.ev > ty->worst)
            ty->worst = ce.ev / pe.ev;
    }
}

/* `nb` random boxes of edge `size` in [lo, hi]^3; at least `min_ok` of them
 * bounded. */
static tally run(const char *expr, double lo, double hi, double size, unsigned nb, double min_ok)
{
    scene *s = parse_surface(expr);
    const tape *t = &s->surfaces[0].tape;
    tally ty = {0, 0, 0, 0.0};
    for (unsigned i = 0; i < nb / SCALE; i++) {
        double c[3];
        for (int k = 0; k < 3; k++)
            c[k] = lo + (hi - lo) * unit();
        interval box[3];
        make_box(c, size * ldexp(1.0, -(int)(next_u64() % 4)), box);
        check_box(expr, t, box, 20, &ty);
    }
    if (!((double)ty.bounded >= min_ok * (double)ty.boxes))
        fail_msg("%s: %u of %u boxes bounded", expr, ty.bounded, ty.boxes);
    scene_free(s);
    return ty;
}

static const char *const BLOBS_A =
    "exp(-3.25*((x-0.78)^2+(y-0.78)^2+(z-0.78)^2)) + exp(-3.25*((x-0.23)^2+(y-0.23)^2+"
    "(z-0.23)^2)) - 0.9";

static void test_scenes(void **state)
{
    (void)state;
    run(BLOBS_A, 0, 1, 1.0 / 32, 400, 0.99);
    run("exp(-196*((x-0.23)^4+(y-0.23)^4+(z-0.68)^4)) + exp(-7*((x-0.68)^2+(y-0.68)^2+"
        "(z-0.68)^2)) - 0.9", 0, 1, 1.0 / 32, 400, 0.99);
    run("x^2 + y^2 + z^2 - 0.8", -1, 1, 1.0 / 16, 400, 0.99);
    run("(sqrt(x^2 + y^2) - 0.6)^2 + z^2 - 0.04", -1, 1, 1.0 / 32, 400, 0.9);
    /* csg and gyroid: bounded only where every kink is decided in the box */
    run("max(max(abs(x), abs(y), abs(z)) - 0.8, x^2 + y^2 + z^2 - 1.0, 0.16 - min(x^2 + y^2, "
        "y^2 + z^2, z^2 + x^2))", -1, 1, 1.0 / 32, 400, 0.05);
    run("max(abs(sin(20*x)*cos(20*y) + sin(20*y)*cos(20*z) + sin(20*z)*cos(20*x)) - 0.2, "
        "x^2 + y^2 + z^2 - 0.81)", -1, 1, 1.0 / 64, 400, 0.05);
    /* every op it bounds */
    run("x*y - z*x + 0.78 - (x - y)^2 / (z*z + 0.5)", -4, 4, 0.25, 300, 0.99);
    run("sqrt(x*x + y*y + 0.01) - log(z*z + 0.5) + sin(3*x + y) * cos(x*y)", -4, 4, 0.25, 300,
        0.99);
    run("exp(x*y - z) + 1/(x + 5) - abs(y + 9)", -4, 4, 0.25, 300, 0.99);
    run("(x + 1e6) - 1e6 - x + y*y - y*y + 1e20*x*z - 1e20*z*x", -4, 4, 0.25, 300, 0.99);
}

/* Near the surface of blobs_a (cancellation: f is 0 there), at the size
 * of a coarse cell, the bound is within a small factor of the per-point
 * one. */
static void test_tight(void **state)
{
    (void)state;
    scene *s = parse_surface(BLOBS_A);
    const tape *t = &s->surfaces[0].tape;
    tally ty = {0, 0, 0, 0.0};
    static double slots[MAXSLOTS];
    for (unsigned i = 0; i < 40000 && ty.bounded < 100 / SCALE; i++) {
        double c[3];
        for (int k = 0; k < 3; k++)
            c[k] = unit();
        if (fabs(tape_eval(t, c[0], c[1], c[2], slots)) > 0.02)
            continue;
        interval box[3];
        make_box(c, 1.0 / 32, box);
        check_box("blobs_a near its surface", t, box, 20, &ty);
    }
    assert_true(ty.bounded >= 100 / SCALE);
    print_message("blobs_a near its surface: the cell bound at most %.3g times the point one\n", ty.worst);
    if (!(ty.worst <= 4.0))
        fail_msg("the cell's bound is %.3g times the per-point one", ty.worst);
    scene_free(s);
}

/* A kink, domain edge or pole in the box, tan and powc: no bound. */
static void test_gives_up(void **state)
{
    (void)state;
    const char *none[] = {"sqrt(x) + y", "log(x) + y", "1 / x + y", "abs(x) + y",
                          "min(x, y) + z", "max(x, 0.5 + y) + z", "tan(y) + x",
                          "(y*y + 1)^0.375 + x", "exp(x + 69) + y", "sin(x + 1e8) + y"};
    const interval box[3] = {{-0.25, 0.25}, {-0.25, 0.25}, {-0.25, 0.25}};
    for (size_t i = 0; i < sizeof none / sizeof none[0]; i++) {
        scene *s = parse_surface(none[i]);
        tape_cell_err ce;
        if (tape_err_cell(&s->surfaces[0].tape, box, &ce, gs, cs))
            fail_msg("%s: bounded over a box holding its edge", none[i]);
        scene_free(s);
    }
    /* the same away from the edge: bounded, and checked */
    const char *away[] = {"sqrt(x) + y", "log(x) + y", "1 / x + y", "abs(x) + y",
                          "min(x, y - 2) + z", "max(x, 0.5 + y) + z"};
    const interval off[3] = {{1.0, 1.25}, {-0.25, 0.25}, {-0.25, 0.25}};
    tally ty = {0, 0, 0, 0.0};
    for (size_t i = 0; i < sizeof away / sizeof away[0]; i++) {
        scene *s = parse_surface(away[i]);
        check_box(away[i], &s->surfaces[0].tape, off, 50, &ty);
        scene_free(s);
    }
    assert_int_equal(ty.bounded, ty.boxes);
}

/* The rasterizer's centred re-test takes one bound per surface over the
 * whole cube around the scene's bounds (build_cube) where the function has
 * no abs, min or max (rasterize/build.c): on the example scenes such
 * surfaces are bounded there (at least five; not the torus, whose sqrt
 * reaches 0), and the bound holds at random points of the cube. */
static void test_whole_cube(void **state)
{
    (void)state;
    DIR *d = opendir("scenes");
    assert_non_null(d);
    unsigned checked = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        const size_t len = strlen(e->d_name);
        if (len < 7 || strcmp(e->d_name + len - 6, ".scene") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "scenes/%s", e->d_name);
        scene *sc = test_scene_load(path);
        double origin[3], edge;
        build_cube(sc, origin, &edge);
        interval cube[3];
        for (int k = 0; k < 3; k++)
            cube[k] = (interval){origin[k], origin[k] + edge};
        for (size_t i = 0; i < sc->nsurfaces; i++) {
            const tape *t = &sc->surfaces[i].tape;
            int kink = 0;
            for (uint32_t j = 0; j < t->n; j++)
                kink |= t->insn[j].op == TAPE_ABS || t->insn[j].op == TAPE_MIN ||
                        t->insn[j].op == TAPE_MAX;
            if (kink)
                continue;
            tally ty = {0, 0, 0, 0.0};
            check_box(path, t, cube, 2000 / SCALE, &ty);
            checked += ty.bounded;
            print_message("%s surface %zu: %s over the whole cube\n", path, i,
                          ty.bounded ? "bounded" : "no bound");
        }
        scene_free(sc);
    }
    closedir(d);
    assert_true(checked >= 5); /* (the blobs, sphere, torus, manyblobs at least) */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scenes),
        cmocka_unit_test(test_tight),
        cmocka_unit_test(test_gives_up),
        cmocka_unit_test(test_whole_cube),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
