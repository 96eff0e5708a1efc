/* Tests for render/views: the views-file rules, FILE:LINE errors, orbit
 * patterns and geometry. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/views.h"

typedef struct reports {
    unsigned lines[8];
    char msgs[8][128];
    unsigned n;
} reports;

static void collect(void *ctx, unsigned line, const char *msg)
{
    reports *r = ctx;
    if (r->n < 8) {
        r->lines[r->n] = line;
        snprintf(r->msgs[r->n], sizeof r->msgs[0], "%s", msg);
    }
    r->n++;
}

static void test_good_file(void **state)
{
    (void)state;
    char text[] = "# two views\n"
                  "\n"
                  "-o a.png --eye 1,2,3 --size 64x32   # trailing comment\n"
                  "  -o b.png\t--fov 45 --depth b.pfm --normals n.png --target 0,0,1 --up 0,1,0\n";
    views_view base, *v = NULL;
    views_defaults(&base);
    base.fov = 20;
    size_t n = 0;
    reports r = {{0}, {{0}}, 0};
    assert_int_equal(views_parse(text, &base, &v, &n, collect, &r), 0);
    assert_int_equal(r.n, 0);
    assert_int_equal(n, 2);
    assert_string_equal(v[0].out, "a.png");
    assert_true(v[0].has_eye && v[0].eye[2] == 3.0 && !v[0].has_target);
    assert_int_equal(v[0].width, 64);
    assert_int_equal(v[0].height, 32);
    assert_true(v[0].fov == 20.0); /* inherited */
    assert_null(v[0].depth);
    assert_int_equal(v[0].line, 3);
    assert_string_equal(v[1].depth, "b.pfm");
    assert_string_equal(v[1].normals, "n.png");
    assert_true(v[1].fov == 45.0 && v[1].up[1] == 1.0 && v[1].has_target);
    assert_int_equal(v[1].width, 512);
    free(v);
}

static void test_every_bad_line_reported(void **state)
{
    (void)state;
    char text[] = "-o ok.png\n"
                  "-o x.png --eye 1,2\n"           /* 2: bad vector */
                  "--eye 1,2,3\n"                  /* 3: no -o */
                  "-o y.png --bogus 1\n"           /* 4: unknown option */
                  "-o z.png --fov\n"               /* 5: missing value */
                  "-o w.png --size 0x10\n"         /* 6: bad size */
                  "-o v.png --fov 180\n"           /* 7: fov range */
                  "-o u.png --eye nan,0,0";        /* 8: not a number, no final newline */
    views_view base, *v = (views_view *)1;
    views_defaults(&base);
    size_t n = 99;
    reports r = {{0}, {{0}}, 0};
    assert_int_equal(views_parse(text, &base, &v, &n, collect, &r), -1);
    assert_null(v);
    assert_int_equal(n, 0);
    assert_int_equal(r.n, 7);
    for (unsigned k = 0; k < 7; k++)
        assert_int_equal(r.lines[k], k + 2);
    assert_non_null(strstr(r.msgs[1], "-o"));
    assert_non_null(strstr(r.msgs[2], "--bogus"));
    assert_non_null(strstr(r.msgs[3], "--fov"));
}

static void test_empty_file(void **state)
{
    (void)state;
    char text[] = "# nothing\n\n   \n";
    views_view base, *v = NULL;
    views_defaults(&base);
    size_t n = 5;
    assert_int_equal(views_parse(text, &base, &v, &n, NULL, NULL), 0);
    assert_int_equal(n, 0);
    free(v);
}

static void test_orbit_patterns(void **state)
{
    (void)state;
    assert_int_equal(views_check_pattern("frame_%04d.png"), 0);
    assert_int_equal(views_check_pattern("%d"), 0);
    assert_int_equal(views_check_pattern("100%%_%u.png"), 0);
    assert_int_equal(views_check_pattern("frame.png"), -1);
    assert_int_equal(views_check_pattern("%d_%d.png"), -1);
    assert_int_equal(views_check_pattern("%s.png"), -1);
    assert_int_equal(views_check_pattern("%ld.png"), -1);
    assert_int_equal(views_check_pattern("%*d.png"), -1);
    assert_int_equal(views_check_pattern("x%"), -1);
}

static void test_orbit_geometry(void **state)
{
    (void)state;
    views_view base;
    views_defaults(&base);
    const double eye[3] = {3, 0, 2}, target[3] = {0, 0, 1};
    memcpy(base.eye, eye, sizeof eye);
    memcpy(base.target, target, sizeof target);
    views_view *v = views_orbit(&base, 4, "f_%03d.png");
    assert_non_null(v);
    assert_string_equal(v[0].out, "f_000.png");
    assert_string_equal(v[3].out, "f_003.png");
    assert_true(fabs(v[0].eye[0] - 3) < 1e-12 && fabs(v[0].eye[1]) < 1e-12);
    assert_true(fabs(v[1].eye[0]) < 1e-12 && fabs(fabs(v[1].eye[1]) - 3) < 1e-12);
    for (int k = 0; k < 4; k++)
        assert_true(fabs(v[k].eye[2] - 2) < 1e-12);
    free(v);
    base.eye[0] = 0; /* on the axis */
    assert_null(views_orbit(&base, 4, "f_%03d.png"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_file),
        cmocka_unit_test(test_every_bad_line_reported),
        cmocka_unit_test(test_empty_file),
        cmocka_unit_test(test_orbit_patterns),
        cmocka_unit_test(test_orbit_geometry),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
