/* Tests for common/expr/scene: every statement and grammar rule, precedence,
 * and each error with its exact line and column. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/exp_kernel.h"
#include "common/expr/scene.h"

#ifdef __FAST_MATH__
#error "fast-math breaks the interval arithmetic; build without it"
#endif

#define B "bounds 0 0 0 1 1 1\n"

static scene *parse_ok(const char *text)
{
    scene *s = NULL;
    scene_error e;
    int rc = scene_parse(text, strlen(text), &s, &e);
    if (rc != 0)
        fail_msg("unexpected error %u:%u: %s for <%s>", e.line, e.col, e.message, text);
    assert_non_null(s);
    return s;
}

static void expect_err_len(const char *text, size_t len, unsigned line, unsigned col, const char *msg)
{
    scene *s = (scene *)1;
    scene_error e;
    int rc = scene_parse(text, len, &s, &e);
    if (rc == 0)
        fail_msg("accepted <%.60s>", text);
    assert_null(s);
    if (e.line != line || e.col != col || !strstr(e.message, msg))
        fail_msg("<%.60s>: got %u:%u: %s; want %u:%u: ...%s...", text, e.line, e.col, e.message,
                 line, col, msg);
}

static void expect_err(const char *text, unsigned line, unsigned col, const char *msg)
{
    expect_err_len(text, strlen(text), line, col, msg);
}

/* f(x,y,z) of the first surface of a one-surface scene. */
static double eval1(const char *expr, double x, double y, double z)
{
    char buf[512];
    snprintf(buf, sizeof buf, B "surface %s\n", expr);
    scene *s = parse_ok(buf);
    double slots[256];
    assert_true(s->surfaces[0].tape.n <= 256);
    double v = tape_eval(&s->surfaces[0].tape, x, y, z, slots);
    scene_free(s);
    return v;
}

static uint32_t tape_len(const char *expr)
{
    char buf[512];
    snprintf(buf, sizeof buf, B "surface %s\n", expr);
    scene *s = parse_ok(buf);
    uint32_t n = s->surfaces[0].tape.n;
    scene_free(s);
    return n;
}

static void test_statements(void **state)
{
    (void)state;
    scene *s = parse_ok("# a comment\n\n  bounds -1 -2 -3.5 1 2e0 3.5   # box\r\n"
                        "surface x + y # first\ncolor 0.1 0.2 1\n\tsurface z\n");
    assert_true(s->lo[0] == -1 && s->lo[1] == -2 && s->lo[2] == -3.5);
    assert_true(s->hi[0] == 1 && s->hi[1] == 2 && s->hi[2] == 3.5);
    assert_int_equal(s->nsurfaces, 2);
    assert_true(s->surfaces[0].color[0] == 0.1 && s->surfaces[0].color[2] == 1.0);
    assert_true(s->surfaces[1].color[1] == SCENE_DEFAULT_COLOR);
    assert_int_equal(s->surfaces[0].line, 4);
    assert_int_equal(s->surfaces[1].line, 6);
    scene_free(s);
    /* Bounds may come after the surfaces; no final newline needed. */
    s = parse_ok("surface x\nbounds 0 0 0 1 1 1");
    scene_free(s);
    scene_free(NULL);
}

static void test_precedence(void **state)
{
    (void)state;
    assert_true(eval1("-x^2", 3, 0, 0) == -9);
    assert_true(eval1("2^3^2", 0, 0, 0) == 512);
    assert_true(eval1("-2^2", 0, 0, 0) == -4);
    assert_true(eval1("(-2)^2", 0, 0, 0) == 4);
    assert_true(eval1("2^-1", 0, 0, 0) == 0.5);
    assert_true(eval1("x-y-z", 1, 2, 3) == -4);
    assert_true(eval1("x/y/z", 8, 2, 2) == 2);
    assert_true(eval1("x+y*z", 1, 2, 3) == 7);
    assert_true(eval1("(x+y)*z", 1, 2, 3) == 9);
    assert_true(eval1("--x", 5, 0, 0) == 5);
    assert_true(eval1("x*-y", 2, 3, 0) == -6);
    assert_true(eval1("x^y", 2, 3, 0) == exp(3 * log(2.0)));
    assert_true(eval1("x^3", -2, 0, 0) == -8);
    assert_true(eval1("x^-2", 2, 0, 0) == 0.25);
    assert_true(eval1("x^0", 0, 0, 0) == 1);
    assert_true(eval1("x^0.5", 4, 0, 0) == 2);
    assert_true(eval1("pow(x, 3)", 2, 0, 0) == 8);
    assert_true(eval1("e^x", 1, 0, 0) == exp_kernel(1.0)); /* the evaluators' exp */
}

static void test_functions_and_constants(void **state)
{
    (void)state;
    assert_true(eval1("pi", 0, 0, 0) == M_PI);
    assert_true(eval1("e", 0, 0, 0) == M_E);
    assert_true(eval1("exp(x)", 1, 0, 0) == exp_kernel(1.0));
    assert_true(fabs(eval1("exp(x)", 1, 0, 0) - M_E) <= 0x1p-51); /* one ulp */
    assert_true(eval1("log(x)", 2, 0, 0) == log(2.0));
    assert_true(eval1("sqrt(x)", 2, 0, 0) == sqrt(2.0));
    assert_true(eval1("abs(x)", -2, 0, 0) == 2);
    assert_true(eval1("sin(x)+cos(y)+tan(z)", 1, 2, 0.5) == sin(1.0) + cos(2.0) + tan(0.5));
    assert_true(eval1("min(x, y, z)", 3, 1, 2) == 1);
    assert_true(eval1("max(x,y,z,-1)", 3, 1, 2) == 3);
    assert_true(eval1("min( x , y )", 3, 1, 2) == 1);
    assert_true(eval1("1e-3 + .5 + 5. + 0.78", 0, 0, 0) == 1e-3 + .5 + 5. + 0.78);
    assert_true(eval1("1e-400", 0, 0, 0) == 0);
    assert_true(isnan(eval1("sqrt(x)", -1, 0, 0)));
    assert_true(isinf(eval1("1/(x-x)", 1, 0, 0)));
}

static void test_tape_sharing(void **state)
{
    (void)state;
    /* x, 0.78, x-0.78, square, add: the repeated square is computed once. */
    assert_int_equal(tape_len("(x-0.78)^2 + (x-0.78)^2"), 5);
    assert_int_equal(tape_len("x^4"), 3);     /* x, square, square */
    assert_int_equal(tape_len("x^5"), 4);     /* ... and one multiply */
    assert_int_equal(tape_len("x^-2"), 4);    /* 1, x, square, divide */
    assert_int_equal(tape_len("2*3*pi + x"), 3);  /* folded */
    assert_int_equal(tape_len("x*y + y*x"), 4);   /* commutative */
    assert_int_equal(tape_len("min(x, y, z)"), 5);
}

static void test_constant_intervals(void **state)
{
    (void)state;
    scene *s = parse_ok(B "surface 0.78 + x\n");
    const tape *t = &s->surfaces[0].tape;
    int found = 0;
    for (uint32_t i = 0; i < t->nconst; i++)
        if (t->konst[i].v == 0.78) {
            found = 1;
            assert_true(t->konst[i].lo < 0.78 && t->konst[i].hi > 0.78);
        }
    assert_true(found);
    scene_free(s);
    s = parse_ok(B "surface 0.25 + 3 + x + 1.5e2 + 12.5e-1\n");
    t = &s->surfaces[0].tape;
    for (uint32_t i = 0; i < t->nconst; i++)
        if (t->konst[i].v == 154.5)
            assert_true(t->konst[i].lo == t->konst[i].hi); /* exact literals stay exact */
    scene_free(s);
    /* Folded constants: exact when the double operation is, else an
     * enclosure of the real value. */
    static const struct { const char *e; double v; int exact; } fold[] = {
        {"0.25*4", 1.0, 1}, {"1/4", 0.25, 1}, {"1.5^2", 2.25, 1}, {"3-0.5", 2.5, 1},
        {"1/3", 1.0 / 3.0, 0}, {"0.1*3", 0.1 * 3, 0}, {"2*pi", 2 * M_PI, 0}, {"sqrt(2)", M_SQRT2, 0},
        {"1e-200*1e-200", 1e-200 * 1e-200, 0}, {"-0.5", -0.5, 1},
    };
    for (size_t i = 0; i < sizeof fold / sizeof fold[0]; i++) {
        char buf[128];
        snprintf(buf, sizeof buf, B "surface x + (%s)\n", fold[i].e);
        s = parse_ok(buf);
        t = &s->surfaces[0].tape;
        if (t->n != 3) /* x, the constant, add */
            fail_msg("%s: %u instructions", fold[i].e, t->n);
        const tape_const *k = &t->konst[t->insn[0].op == TAPE_CONST ? t->insn[0].a : t->insn[1].a];
        assert_true(k->v == fold[i].v);
        if (fold[i].exact)
            assert_true(k->lo == k->v && k->hi == k->v);
        else
            assert_true(k->lo < k->v && k->v < k->hi);
        scene_free(s);
    }
}

static void test_expression_errors(void **state)
{
    (void)state;
    expect_err(B "surface foo(x)\n", 2, 9, "unknown function 'foo'");
    expect_err(B "surface x + w\n", 2, 13, "unknown variable 'w'");
    expect_err(B "surface inf\n", 2, 9, "unknown variable 'inf'");
    expect_err(B "surface x*nan\n", 2, 11, "unknown variable 'nan'");
    expect_err(B "surface sin(x, y)\n", 2, 9, "sin takes 1 argument, got 2");
    expect_err(B "surface sin()\n", 2, 9, "sin takes 1 argument, got 0");
    expect_err(B "surface min(x)\n", 2, 9, "min takes 2 or more arguments, got 1");
    expect_err(B "surface 1 + pow(x)\n", 2, 13, "pow takes 2 arguments, got 1");
    expect_err(B "surface sin x\n", 2, 12, "expected '(' after 'sin'");
    expect_err(B "surface x - 1e999\n", 2, 13, "number out of range");
    expect_err(B "surface x - 1e\n", 2, 13, "malformed number");
    expect_err(B "surface x - 1e+\n", 2, 13, "malformed number");
    expect_err(B "surface 0x1p3\n", 2, 9, "malformed number");
    expect_err(B "surface 1.2.3\n", 2, 9, "malformed number");
    expect_err(B "surface 2y\n", 2, 9, "malformed number");
    expect_err(B "surface x y\n", 2, 11, "unexpected 'y' after the expression");
    expect_err(B "surface x)\n", 2, 10, "unmatched ')'");
    expect_err(B "surface (x\n", 2, 11, "expected ')' to close '(' at column 9");
    expect_err(B "surface min(x, (y\n", 2, 18, "expected ')' to close '(' at column 16");
    expect_err(B "surface min(x, y\n", 2, 17, "to close '(' at column 12");
    expect_err(B "surface\n", 2, 8, "expected an expression, found end of line");
    expect_err(B "surface x +\n", 2, 12, "expected an expression");
    expect_err(B "surface x + # comment\n", 2, 13, "expected an expression");
    expect_err(B "surface x * $\n", 2, 13, "expected an expression, found '$'");
    expect_err(B "surface x + \xc3\xa9\n", 2, 13, "byte 0xc3");
    expect_err(B "surfacex\n", 2, 1, "unknown statement 'surfacex'");
    /* Constant sub-expressions that are undefined or overflow. */
    expect_err(B "surface x + exp(1000)\n", 2, 13, "constant expression");
    expect_err(B "surface x + 1/0\n", 2, 14, "constant expression");
    expect_err(B "surface x + 0/0\n", 2, 14, "constant expression");
    expect_err(B "surface x + sqrt(-1)\n", 2, 13, "constant expression");
    expect_err(B "surface x + log(0)\n", 2, 13, "constant expression");
    expect_err(B "surface x + 10^400\n", 2, 15, "constant expression");
    expect_err(B "surface x^100000\n", 2, 10, "integer exponent too large");
}

static void test_statement_errors(void **state)
{
    (void)state;
    expect_err("surface x\n", 1, 1, "missing 'bounds'");
    expect_err(B, 1, 1, "missing 'surface'");
    expect_err("# only a comment\n", 1, 1, "missing 'bounds'");
    expect_err(B "surface x\n" B, 3, 1, "bounds already given on line 1");
    expect_err("bounds 0 0 0 1 -1 1\n", 1, 16, "empty bounds: Y1");
    expect_err("bounds 0 0 0 1 1 0\n", 1, 18, "empty bounds: Z1");
    expect_err("bounds 2 0 0 1 1 1\n", 1, 14, "empty bounds: X1");
    expect_err("bounds 0 0 0 1 1\n", 1, 17, "bounds needs 6 numbers, found end of line");
    expect_err("bounds 0 0 0 nan 1 1\n", 1, 14, "bounds needs 6 numbers, found 'n'");
    expect_err("bounds 0 0 0 1 1 1e999\n", 1, 18, "number out of range");
    expect_err("bounds 0 0 0 1 1 1 1\n", 1, 20, "unexpected '1' after the 6 numbers of bounds");
    expect_err("bounds 0 0 0 1 1 0x1\n", 1, 18, "malformed number");
    expect_err(B "color 1 0 0\nsurface x\n", 2, 1, "color before any surface");
    expect_err(B "surface x\ncolor 1 2 0\n", 3, 9, "color component 2 outside 0..1");
    expect_err(B "surface x\ncolor 1 -0.5 0\n", 3, 9, "outside 0..1");
    expect_err(B "surface x\ncolor 1 0\n", 3, 10, "color needs 3 numbers");
    expect_err(B "surface x\ncolor 1 0 0\ncolor 0 0 0\n", 4, 1, "line 2 already has a color");
    expect_err(B "sphere x\n", 2, 1, "unknown statement 'sphere'");
    expect_err(B "  = x\n", 2, 3, "expected bounds, surface or color, found '='");
    expect_err("", 1, 1, "empty file");
}

static void test_bytes_and_limits(void **state)
{
    (void)state;
    static const char nul[] = "bounds 0 0 0 1 1 1\nsurf\0ace x\n";
    expect_err_len(nul, sizeof nul - 1, 2, 5, "not a text file: byte 0x00");
    expect_err(B "surface x\x01\n", 2, 10, "byte 0x01");
    expect_err(B "surface x\r+y\n", 2, 10, "byte 0x0d"); /* CR only at a line's end */
    expect_err(B "# \x7f\n", 2, 3, "byte 0x7f");

    /* A line one byte over the limit. */
    size_t n = SCENE_MAX_LINE + 1;
    char *big = malloc(sizeof B + n + 2);
    assert_non_null(big);
    strcpy(big, B);
    memset(big + strlen(B), ' ', n);
    big[strlen(B) + n] = '\0';
    expect_err(big, 2, SCENE_MAX_LINE + 1, "line longer than");
    free(big);

    /* 10^5 nested parentheses and 10^5 minus signs: an error, not a crash. */
    size_t deep = 100000;
    char *t = malloc(sizeof B + 8 + 2 * deep + 4);
    assert_non_null(t);
    char *p = t + sprintf(t, B "surface ");
    memset(p, '(', deep);
    p[deep] = 'x';
    memset(p + deep + 1, ')', deep);
    p[2 * deep + 1] = '\0';
    expect_err(t, 2, 9 + SCENE_MAX_DEPTH / 2, "nested too deeply");
    memset(p, '-', deep);
    p[deep] = 'x';
    p[deep + 1] = '\0';
    expect_err(t, 2, 8 + SCENE_MAX_DEPTH, "nested too deeply");
    /* x^x^x^...: right-associative power recursion is limited too. */
    p = t + sprintf(t, B "surface x");
    for (size_t i = 0; i < deep / 2; i++) {
        *p++ = '^';
        *p++ = 'x';
    }
    *p = '\0';
    expect_err(t, 2, 7 + 2 * SCENE_MAX_DEPTH, "nested too deeply");
    free(t);
    /* Just under the limit is fine. */
    char ok[1024];
    p = ok + sprintf(ok, B "surface ");
    for (int i = 0; i < SCENE_MAX_DEPTH / 2 - 2; i++)
        *p++ = '(';
    *p++ = 'x';
    for (int i = 0; i < SCENE_MAX_DEPTH / 2 - 2; i++)
        *p++ = ')';
    *p = '\0';
    scene_free(parse_ok(ok));
}

static void test_load(void **state)
{
    (void)state;
    scene *s = (scene *)1;
    scene_error e;
    assert_int_equal(scene_load("scenes", &s, &e), -1);
    assert_null(s);
    assert_true(e.line == 1 && e.col == 1 && strstr(e.message, "directory"));
    assert_int_equal(scene_load("scenes/no-such-file.scene", &s, &e), -1);
    assert_true(e.line == 1 && e.col == 1 && strstr(e.message, "cannot open"));
    assert_int_equal(scene_load("/dev/null", &s, &e), -1);
    assert_true(strstr(e.message, "empty file") != NULL);
    assert_int_equal(scene_load("scenes/sphere.scene", &s, &e), 0);
    assert_int_equal(s->nsurfaces, 1);
    scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_statements),
        cmocka_unit_test(test_precedence),
        cmocka_unit_test(test_functions_and_constants),
        cmocka_unit_test(test_tape_sharing),
        cmocka_unit_test(test_constant_intervals),
        cmocka_unit_test(test_expression_errors),
        cmocka_unit_test(test_statement_errors),
        cmocka_unit_test(test_bytes_and_limits),
        cmocka_unit_test(test_load),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
