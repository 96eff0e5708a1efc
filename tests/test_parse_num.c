/* Tests for common/parse_num: the strict number grammar shared by the CLI,
 * scene and views parsers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "common/parse_num.h"

static void test_double_accepts_c_float_syntax(void **state)
{
    (void)state;
    static const struct { const char *s; double v; } ok[] = {
        {"1", 1.0}, {"0.78", 0.78}, {"1e-3", 1e-3}, {".5", 0.5}, {"5.", 5.0},
        {"-2.5E+2", -250.0}, {"+7", 7.0}, {"1e-400", 0.0},
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        double v = NAN;
        assert_int_equal(parse_double(ok[i].s, &v), PARSE_OK);
        assert_true(v == ok[i].v);
    }
}

static void test_double_rejects_what_strtod_accepts(void **state)
{
    (void)state;
    static const char *syntax[] = {"0x1p3", "inf", "nan", "1e", "1e+", "1.2.3", "1 ", " 1", "--1", ".", "e5", "1,5"};
    for (size_t i = 0; i < sizeof syntax / sizeof syntax[0]; i++) {
        double v = 42.0;
        assert_int_equal(parse_double(syntax[i], &v), PARSE_SYNTAX);
        assert_true(v == 42.0); /* untouched on error */
    }
    double v;
    assert_int_equal(parse_double("1e999", &v), PARSE_RANGE);
    assert_int_equal(parse_double("-1e309", &v), PARSE_RANGE);
    assert_int_equal(parse_double("", &v), PARSE_EMPTY);
}

static void test_float_prefix_reports_dangling_exponent(void **state)
{
    (void)state;
    int bad = 0;
    assert_int_equal(parse_float_prefix("12.5*x", &bad), 4);
    assert_false(bad);
    assert_int_equal(parse_float_prefix("1e+x", &bad), 1);
    assert_true(bad);
    assert_int_equal(parse_float_prefix("x", &bad), 0);
}

static void test_long_range_and_syntax(void **state)
{
    (void)state;
    long v;
    assert_int_equal(parse_long("20", 1, 20, &v), PARSE_OK);
    assert_int_equal(v, 20);
    assert_int_equal(parse_long("21", 1, 20, &v), PARSE_RANGE);
    assert_int_equal(parse_long("0", 1, 20, &v), PARSE_RANGE);
    assert_int_equal(parse_long("3x", 1, 20, &v), PARSE_SYNTAX);
    assert_int_equal(parse_long("99999999999999999999999", 0, 10, &v), PARSE_RANGE);
}

static void test_vec3_and_size(void **state)
{
    (void)state;
    double e[3];
    assert_int_equal(parse_vec3("2.2,1.6,-1.9", e), PARSE_OK);
    assert_true(e[0] == 2.2 && e[1] == 1.6 && e[2] == -1.9);
    assert_int_equal(parse_vec3("1,2", e), PARSE_SYNTAX);
    assert_int_equal(parse_vec3("1,2,3,4", e), PARSE_SYNTAX);
    assert_int_equal(parse_vec3("1,,3", e), PARSE_SYNTAX);
    assert_int_equal(parse_vec3("1,nan,3", e), PARSE_SYNTAX);
    long w, h;
    assert_int_equal(parse_size("640x480", 32768, &w, &h), PARSE_OK);
    assert_true(w == 640 && h == 480);
    assert_int_equal(parse_size("0x480", 32768, &w, &h), PARSE_RANGE);
    assert_int_equal(parse_size("-4x4", 32768, &w, &h), PARSE_RANGE);
    assert_int_equal(parse_size("40000x4", 32768, &w, &h), PARSE_RANGE);
    assert_int_equal(parse_size("64", 32768, &w, &h), PARSE_SYNTAX);
    assert_int_equal(parse_size("64x", 32768, &w, &h), PARSE_SYNTAX);
}

static void test_index_of(void **state)
{
    (void)state;
    long i = -5, n = -5;
    assert_int_equal(parse_index_of("0/1", 64, &i, &n), PARSE_OK);
    assert_int_equal(i, 0);
    assert_int_equal(n, 1);
    assert_int_equal(parse_index_of("6/7", 64, &i, &n), PARSE_OK);
    assert_int_equal(i, 6);
    assert_int_equal(n, 7);
    i = n = -5;
    assert_int_equal(parse_index_of("3/3", 64, &i, &n), PARSE_RANGE);
    assert_int_equal(parse_index_of("-1/4", 64, &i, &n), PARSE_RANGE);
    assert_int_equal(parse_index_of("0/0", 64, &i, &n), PARSE_RANGE);
    assert_int_equal(parse_index_of("0/65", 64, &i, &n), PARSE_RANGE);
    assert_int_equal(parse_index_of("x/y", 64, &i, &n), PARSE_SYNTAX);
    assert_int_equal(parse_index_of("1", 64, &i, &n), PARSE_SYNTAX);
    assert_int_equal(parse_index_of("/4", 64, &i, &n), PARSE_SYNTAX);
    assert_int_equal(parse_index_of("1/", 64, &i, &n), PARSE_SYNTAX);
    assert_int_equal(parse_index_of("1/2/3", 64, &i, &n), PARSE_SYNTAX);
    assert_int_equal(parse_index_of("", 64, &i, &n), PARSE_EMPTY);
    assert_int_equal(i, -5); /* untouched on failure */
    assert_int_equal(n, -5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_double_accepts_c_float_syntax),
        cmocka_unit_test(test_double_rejects_what_strtod_accepts),
        cmocka_unit_test(test_float_prefix_reports_dangling_exponent),
        cmocka_unit_test(test_long_range_and_syntax),
        cmocka_unit_test(test_vec3_and_size),
        cmocka_unit_test(test_index_of),
    };
    return cmocka_run_group_tests_name("parse_num", tests, NULL, NULL);
}
