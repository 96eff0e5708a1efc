/* Tests for render/views: the views-file rules, FILE:LINE errors, orbit
 * patterns and geometry. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <limits.h>
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
    /* A width no file name can hold is refused before any formatting. */
    assert_int_equal(views_check_pattern("f%0255d.png"), 0);
    assert_int_equal(views_check_pattern("f%256d.png"), -2);
    assert_int_equal(views_check_pattern("f%2147483647d.png"), -2);
    assert_int_equal(views_check_pattern("f%99999999999999999999999d.png"), -2);
}

/* The out-of-memory case asks for ~300 GB: under AddressSanitizer malloc
 * must then return NULL, as libc's does, instead of aborting. */
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "allocator_may_return_null=1"; }

/* Every orbit failure has its own reason, out of memory included. */
static void test_orbit_errors(void **state)
{
    (void)state;
    views_view base, *v = (views_view *)&base;
    views_defaults(&base);
    base.eye[0] = 3;
    assert_int_equal(views_orbit(&base, 4, "f%2147483647d.png", &v), VIEWS_ORBIT_WIDTH);
    assert_null(v);
    assert_int_equal(views_orbit(&base, 4, "f%s.png", &v), VIEWS_ORBIT_PATTERN);
    static char longp[PATH_MAX + 8];
    memset(longp, 'p', sizeof longp - 1);
    memcpy(longp + 10, "%d", 2);
    assert_int_equal(views_orbit(&base, 4, longp, &v), VIEWS_ORBIT_NAME);
    assert_int_equal(views_orbit(&base, 2000000000u, "%d", &v), VIEWS_ORBIT_NOMEM);
    assert_null(v);
    assert_string_equal(views_orbit_strerror(VIEWS_ORBIT_NOMEM), "out of memory");
}

/* The views file's limits: NUL bytes and long lines with FILE:LINE:COL. */
static void test_views_text_limits(void **state)
{
    (void)state;
    unsigned line = 0, col = 0;
    const char *msg = NULL;
    static const char nul[] = "-o a.png\n-o b\0.png\n";
    assert_int_equal(views_check_text(nul, sizeof nul - 1, &line, &col, &msg), -2);
    assert_int_equal(line, 2);
    assert_int_equal(col, 5);
    assert_non_null(strstr(msg, "NUL"));
    size_t n = VIEWS_MAX_LINE + 10;
    char *big = malloc(n + 1);
    assert_non_null(big);
    memset(big, ' ', n);
    big[0] = '\n';
    assert_int_equal(views_check_text(big, VIEWS_MAX_LINE + 1, &line, &col, &msg), 0);
    assert_int_equal(views_check_text(big, VIEWS_MAX_LINE + 2, &line, &col, &msg), -2);
    assert_int_equal(line, 2);
    assert_non_null(strstr(msg, "65536"));
    free(big);
}

static void test_orbit_geometry(void **state)
{
    (void)state;
    views_view base;
    views_defaults(&base);
    const double eye[3] = {3, 0, 2}, target[3] = {0, 0, 1};
    memcpy(base.eye, eye, sizeof eye);
    memcpy(base.target, target, sizeof target);
    views_view *v = NULL;
    assert_int_equal(views_orbit(&base, 4, "f_%03d.png", &v), VIEWS_ORBIT_OK);
    assert_non_null(v);
    assert_string_equal(v[0].out, "f_000.png");
    assert_string_equal(v[3].out, "f_003.png");
    assert_true(fabs(v[0].eye[0] - 3) < 1e-12 && fabs(v[0].eye[1]) < 1e-12);
    assert_true(fabs(v[1].eye[0]) < 1e-12 && fabs(fabs(v[1].eye[1]) - 3) < 1e-12);
    for (int k = 0; k < 4; k++)
        assert_true(fabs(v[k].eye[2] - 2) < 1e-12);
    free(v);
    base.eye[0] = 0; /* on the axis */
    assert_int_equal(views_orbit(&base, 4, "f_%03d.png", &v), VIEWS_ORBIT_AXIS);
    assert_null(v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_file),
        cmocka_unit_test(test_every_bad_line_reported),
        cmocka_unit_test(test_empty_file),
        cmocka_unit_test(test_orbit_patterns),
        cmocka_unit_test(test_orbit_errors),
        cmocka_unit_test(test_views_text_limits),
        cmocka_unit_test(test_orbit_geometry),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
