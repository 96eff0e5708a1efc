/* Tests for render/exact_hit: the first root along a segment against
 * analytic roots (sphere, plane, torus), tangency, functions undefined on
 * part of the segment (sqrt of a negative, log 0, a pole), the normal, and
 * the workers' cache-line allocations. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "render/exact_hit.h"

typedef struct fixture {
    scene *sc;
    exact_scratch w;
} fixture;

static void load(fixture *f, const char *surface)
{
    char text[1024];
    snprintf(text, sizeof text, "bounds -4 -4 -4 4 4 4\nsurface %s\n", surface);
    scene_error err;
    assert_int_equal(scene_parse(text, strlen(text), &f->sc, &err), 0);
    assert_int_equal(exact_scratch_init(&f->w, f->sc->surfaces[0].tape.n), 0);
}

static void unload(fixture *f)
{
    exact_scratch_free(&f->w);
    scene_free(f->sc);
}

static double root(fixture *f, const double o[3], const double d[3], double a, double b, int *kind)
{
    exact_line l;
    memcpy(l.o, o, sizeof l.o);
    memcpy(l.d, d, sizeof l.d);
    *kind = 0;
    return exact_first_root(&f->sc->surfaces[0].tape, NULL, &f->w, &l, a, b, kind);
}

/* |got - want| within k ulps of want */
static void assert_ulps(double got, double want, double k)
{
    const double ulp = nextafter(fabs(want), INFINITY) - fabs(want);
    if (!(fabs(got - want) <= k * ulp))
        fail_msg("got %.17g, want %.17g (%.3g ulp)", got, want, fabs(got - want) / ulp);
}

static void test_sphere(void **state)
{
    (void)state;
    fixture f;
    load(&f, "x^2 + y^2 + z^2 - 1");
    int kind;
    const double o[3] = {0, 0, -3}, d[3] = {0, 0, 1};
    assert_ulps(root(&f, o, d, 0.0, 10.0, &kind), 2.0, 1);
    assert_int_equal(kind, EXACT_ROOT);
    /* starting inside: the exit point is the first root */
    assert_ulps(root(&f, o, d, 2.5, 10.0, &kind), 4.0, 1);
    /* a segment before the sphere holds none */
    assert_true(isinf(root(&f, o, d, 0.0, 1.9, &kind)));
    assert_int_equal(kind, 0);
    /* an oblique unit ray through (0.6, 0, 0): t = 3 - 0.8 */
    const double o2[3] = {0.6, -3, 0}, d2[3] = {0, 1, 0};
    assert_ulps(root(&f, o2, d2, 0.0, 3.0, &kind), 2.2, 2);
    unload(&f);
}

static void test_plane_and_torus(void **state)
{
    (void)state;
    fixture f;
    load(&f, "x - 0.3");
    int kind;
    const double o[3] = {-1, 0.2, 0.1}, d[3] = {0.5, 0, 0};
    assert_ulps(root(&f, o, d, 0.0, 8.0, &kind), 2.6, 1);
    unload(&f);
    /* a root exactly on the segment's end is found from either side */
    load(&f, "x - 0.25");
    assert_true(root(&f, o, d, 2.5, 3.0, &kind) == 2.5);
    assert_true(root(&f, o, d, 1.0, 2.5, &kind) == 2.5);
    assert_true(isinf(root(&f, o, d, nextafter(2.5, 3.0), 3.0, &kind)));
    unload(&f);

    load(&f, "(sqrt(x^2 + y^2) - 1)^2 + z^2 - 0.0625");
    const double o2[3] = {-3, 0, 0}, d2[3] = {1, 0, 0};
    /* roots at x = -1.25, -0.75, 0.75, 1.25 */
    assert_ulps(root(&f, o2, d2, 0.0, 6.0, &kind), 1.75, 2);
    assert_ulps(root(&f, o2, d2, 1.8, 6.0, &kind), 2.25, 2);
    assert_ulps(root(&f, o2, d2, 2.3, 6.0, &kind), 3.75, 2);
    /* through the hole at z = 0.2: inside the tube's radius 0.25 */
    const double o3[3] = {0, 0, 0.2}, d3[3] = {1, 0, 0};
    assert_ulps(root(&f, o3, d3, 0.0, 3.0, &kind), 1.0 - sqrt(0.0625 - 0.04), 4);
    unload(&f);
}

static void test_tangency(void **state)
{
    (void)state;
    fixture f;
    load(&f, "x^2 + y^2 + z^2 - 1");
    int kind;
    const double d[3] = {1, 0, 0};
    /* grazing the sphere at (0, 1, 0): f = x^2, a touch at t = 3 */
    const double o[3] = {-3, 1, 0};
    const double t = root(&f, o, d, 0.0, 6.0, &kind);
    assert_true(kind == EXACT_TOUCH || kind == EXACT_ROOT);
    assert_true(fabs(t - 3.0) <= 1e-6);
    /* just outside: a miss, just inside: the two roots apart */
    const double out[3] = {-3, 1 + 1e-6, 0}, in[3] = {-3, 1 - 1e-6, 0};
    assert_true(isinf(root(&f, out, d, 0.0, 6.0, &kind)));
    const double tin = root(&f, in, d, 0.0, 6.0, &kind);
    assert_int_equal(kind, EXACT_ROOT);
    const double y = 1 - 1e-6, want = 3.0 - sqrt(1.0 - y * y);
    assert_true(fabs(tin - want) <= 1e-12);
    unload(&f);
}

static void test_undefined(void **state)
{
    (void)state;
    fixture f;
    int kind;
    const double o[3] = {-1, 0, 0}, d[3] = {1, 0, 0};
    /* sqrt of a negative left of x = 0: the first root is x = 0.25 */
    load(&f, "sqrt(x) - 0.5");
    assert_ulps(root(&f, o, d, 0.0, 4.0, &kind), 1.25, 2);
    /* f = sqrt(x) reaches 0 at the domain's edge only: no surface */
    unload(&f);
    load(&f, "sqrt(x) + 0.25");
    assert_true(isinf(root(&f, o, d, 0.0, 4.0, &kind)));
    unload(&f);
    /* log 0 = -inf at x = 0, undefined left of it; root at x = 1 */
    load(&f, "log(x)");
    assert_ulps(root(&f, o, d, 0.0, 4.0, &kind), 2.0, 2);
    unload(&f);
    /* a pole at x = 0: the sign change through it is not a root; x = 0.5 is */
    load(&f, "1/x - 2");
    const double t = root(&f, o, d, 0.0, 4.0, &kind);
    assert_ulps(t, 1.5, 2);
    unload(&f);
    /* undefined on the whole segment */
    load(&f, "sqrt(-1 - x^2) - 1");
    assert_true(isinf(root(&f, o, d, 0.0, 4.0, &kind)));
    unload(&f);
}

static void test_normal(void **state)
{
    (void)state;
    fixture f;
    load(&f, "x^2 + y^2 + z^2 - 1");
    double n[3];
    const double p[3] = {0.6, 0.8, 0}, d[3] = {0, -1, 0};
    exact_normal(&f.sc->surfaces[0].tape, &f.w, p, d, n);
    assert_true(fabs(n[0] - 0.6) < 1e-15 && fabs(n[1] - 0.8) < 1e-15 && n[2] == 0.0);
    /* seen from inside: turned to face the viewer */
    const double d2[3] = {0, 1, 0};
    exact_normal(&f.sc->surfaces[0].tape, &f.w, p, d2, n);
    assert_true(fabs(n[0] + 0.6) < 1e-15 && fabs(n[1] + 0.8) < 1e-15);
    /* a zero gradient (the centre): faces the viewer */
    const double c[3] = {0, 0, 0};
    exact_normal(&f.sc->surfaces[0].tape, &f.w, c, d, n);
    assert_true(n[0] == 0.0 && n[1] == 1.0 && n[2] == 0.0);
    unload(&f);
}

/* exact_line_alloc: 64-byte aligned, whole lines usable (the sanitizer
 * build would catch a write past the block), and NULL, not a wrapped size,
 * on overflow. Two blocks never share a line. */
static void test_line_alloc(void **state)
{
    (void)state;
    static const size_t sizes[][2] = {{0, 8}, {1, 1}, {3, 16}, {5, 24}, {64, 1}, {100, 40}};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        unsigned char *a = exact_line_alloc(sizes[k][0], sizes[k][1]);
        unsigned char *b = exact_line_alloc(sizes[k][0], sizes[k][1]);
        assert_non_null(a);
        assert_non_null(b);
        assert_int_equal((uintptr_t)a % 64, 0);
        assert_int_equal((uintptr_t)b % 64, 0);
        const size_t bytes = sizes[k][0] * sizes[k][1];
        const size_t lines = bytes ? (bytes + 63) / 64 * 64 : 64;
        memset(a, 0xa5, lines);
        memset(b, 0x5a, lines);
        /* (disjoint whole lines: b's writes left a's alone) */
        for (size_t i = 0; i < lines; i++)
            assert_int_equal(a[i], 0xa5);
        free(a);
        free(b);
    }
    assert_null(exact_line_alloc(SIZE_MAX / 8, 16));
    assert_null(exact_line_alloc(SIZE_MAX, 1));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),       cmocka_unit_test(test_plane_and_torus),
        cmocka_unit_test(test_tangency),     cmocka_unit_test(test_undefined),
        cmocka_unit_test(test_normal),       cmocka_unit_test(test_line_alloc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
