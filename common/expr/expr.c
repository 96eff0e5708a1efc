/* expr: recursive-descent parser for EXPR (INTERFACE.md) with a depth
 * limit, emitting into a tape builder. The grammar, loosest first (a
 * function's argument count is checked after its call is read):
 *   sum     := term (('+' | '-') term)*
 *   term    := unary (('*' | '/') unary)*
 *   unary   := '-' unary | power
 *   power   := primary ('^' unary)?
 *   primary := number | x | y | z | pi | e | '(' sum ')' | name '(' [sum (',' sum)*] ')'
 */
#include "common/expr/expr.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/parse_num.h"

void expr_fail_at(expr_parser *p, size_t pos, const char *fmt, ...)
{
    if (p->failed)
        return; /* keep the first error */
    p->failed = 1;
    p->err->line = p->line;
    p->err->col = (unsigned)pos + 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->err->message, sizeof p->err->message, fmt, ap);
    va_end(ap);
}

void expr_skip_ws(expr_parser *p)
{
    while (p->s[p->pos] == ' ' || p->s[p->pos] == '\t' || p->s[p->pos] == '\r')
        p->pos++;
}

void expr_describe(const expr_parser *p, size_t pos, char *buf, size_t n)
{
    unsigned char c = (unsigned char)p->s[pos];
    if (c == '\0')
        snprintf(buf, n, "end of line");
    else if (c > ' ' && c < 0x7f)
        snprintf(buf, n, "'%c'", c);
    else
        snprintf(buf, n, "byte 0x%02x", c);
}

/* Is the decimal literal s[0..n) exactly a double? Decides from the digits
 * (value = D * 10^E): integers up to 2^53, and D / 10^k when 5^k divides D.
 * Errs towards "inexact", which only widens an interval. */
static int literal_is_exact(const char *s, size_t n)
{
    uint64_t d = 0;
    int e = 0, ndig = 0, frac = 0;
    size_t i = 0;
    for (; i < n && (expr_is_digit(s[i]) || s[i] == '.'); i++) {
        if (s[i] == '.') {
            frac = 1;
            continue;
        }
        if (d == 0 && s[i] == '0') {
            if (frac)
                e--;
            continue;
        }
        if (ndig >= 19) {
            if (s[i] != '0')
                return 0;
            if (!frac)
                e++;
            continue;
        }
        d = d * 10 + (uint64_t)(s[i] - '0');
        ndig++;
        if (frac)
            e--;
    }
    if (i < n) { /* exponent */
        long x = strtol(s + i + 1, NULL, 10);
        if (x > 400 || x < -400)
            return d == 0;
        e += (int)x;
    }
    if (d == 0)
        return 1;
    while (d % 10 == 0) {
        d /= 10;
        e++;
    }
    const uint64_t two53 = (uint64_t)1 << 53;
    if (e >= 0) {
        for (; e > 0; e--) {
            if (d > two53 / 10)
                return 0;
            d *= 10;
        }
        return d <= two53;
    }
    if (e < -22)
        return 0;
    uint64_t p5 = 1;
    for (int k = 0; k < -e; k++)
        p5 *= 5;
    return d % p5 == 0 && d / p5 <= two53;
}

int expr_read_number(expr_parser *p, double *v, int *exact, int *none)
{
    size_t start = p->pos;
    int bad_exp = 0;
    size_t n = parse_float_prefix(p->s + start, &bad_exp);
    *none = n == 0;
    if (n == 0)
        return 0;
    if (bad_exp) {
        expr_fail_at(p, start, "malformed number: exponent without digits");
        return 0;
    }
    char next = p->s[start + n];
    if (expr_is_alnum(next) || next == '.') {
        expr_fail_at(p, start, "malformed number");
        return 0;
    }
    errno = 0;
    char *end;
    double d = strtod(p->s + start, &end);
    if ((size_t)(end - (p->s + start)) != n) {
        expr_fail_at(p, start, "malformed number");
        return 0;
    }
    if (!isfinite(d)) {
        expr_fail_at(p, start, "number out of range");
        return 0;
    }
    *v = d;
    *exact = literal_is_exact(p->s + start, n);
    p->pos = start + n;
    return 1;
}

/* Reports a negative builder result at pos; passes others through. */
static int32_t chk(expr_parser *p, int32_t r, size_t pos)
{
    if (r < 0) {
        if (r == TAPE_EDOMAIN)
            expr_fail_at(p, pos, "constant expression is undefined or not finite here");
        else
            expr_fail_at(p, pos, "%s", tape_strerror(r));
        return -1;
    }
    return r;
}

static int32_t parse_sum(expr_parser *p);

static int enter(expr_parser *p)
{
    if (++p->depth > SCENE_MAX_DEPTH) {
        expr_fail_at(p, p->pos, "expression nested too deeply (limit %d)", SCENE_MAX_DEPTH);
        return 0;
    }
    return 1;
}

struct func {
    const char *name;
    int nargs; /* -1: two or more */
    tape_op op;
};

static const struct func funcs[] = {
    {"exp", 1, TAPE_EXP}, {"log", 1, TAPE_LOG}, {"sqrt", 1, TAPE_SQRT}, {"abs", 1, TAPE_ABS},
    {"sin", 1, TAPE_SIN}, {"cos", 1, TAPE_COS}, {"tan", 1, TAPE_TAN},
    {"min", -1, TAPE_MIN}, {"max", -1, TAPE_MAX}, {"pow", 2, TAPE_POWC},
};

/* Arguments are consumed as they come: min/max fold into a binary chain
 * at once, so no argument array lives on the (recursive) stack. */
static int32_t parse_call(expr_parser *p, const struct func *fn, size_t name_pos)
{
    int32_t first = -1, second = -1, acc = -1;
    int n = 0;
    size_t open = p->pos;
    p->pos++; /* '(' */
    expr_skip_ws(p);
    if (p->s[p->pos] != ')') {
        for (;;) {
            size_t apos = p->pos;
            int32_t a = parse_sum(p);
            if (a < 0)
                return -1;
            if (n == 0)
                first = acc = a;
            else if (n == 1)
                second = a;
            if (fn->nargs == -1 && n > 0) {
                acc = chk(p, tape_emit_binary(p->b, fn->op, acc, a), apos);
                if (acc < 0)
                    return -1;
            }
            n++;
            expr_skip_ws(p);
            if (p->s[p->pos] == ',') {
                p->pos++;
                continue;
            }
            break;
        }
    }
    if (p->s[p->pos] != ')') {
        char what[32];
        expr_describe(p, p->pos, what, sizeof what);
        expr_fail_at(p, p->pos, "expected ',' or ')' to close '(' at column %zu, found %s", open + 1, what);
        return -1;
    }
    p->pos++;
    if (fn->nargs == -1 ? n < 2 : n != fn->nargs) {
        if (fn->nargs == -1)
            expr_fail_at(p, name_pos, "%s takes 2 or more arguments, got %d", fn->name, n);
        else
            expr_fail_at(p, name_pos, "%s takes %d argument%s, got %d", fn->name, fn->nargs,
                    fn->nargs == 1 ? "" : "s", n);
        return -1;
    }
    if (fn->nargs == 1)
        return chk(p, tape_emit_unary(p->b, fn->op, first), name_pos);
    if (fn->op == TAPE_POWC)
        return chk(p, tape_emit_pow(p->b, first, second), name_pos);
    return acc;
}

static int32_t parse_primary(expr_parser *p)
{
    expr_skip_ws(p);
    size_t start = p->pos;
    char c = p->s[start];
    if (c == '(') {
        p->pos++;
        int32_t r = parse_sum(p);
        if (r < 0)
            return -1;
        expr_skip_ws(p);
        if (p->s[p->pos] != ')') {
            char what[32];
            expr_describe(p, p->pos, what, sizeof what);
            expr_fail_at(p, p->pos, "expected ')' to close '(' at column %zu, found %s", start + 1, what);
            return -1;
        }
        p->pos++;
        return r;
    }
    if (expr_is_digit(c) || c == '.') {
        double v;
        int exact, none;
        if (!expr_read_number(p, &v, &exact, &none)) {
            if (none)
                expr_fail_at(p, start, "malformed number");
            return -1;
        }
        interval k = exact ? (interval){v, v} : interval_around(v);
        return chk(p, tape_emit_const(p->b, v, k.lo, k.hi), start);
    }
    if (expr_is_alpha(c)) {
        size_t n = 0;
        while (expr_is_alnum(p->s[start + n]))
            n++;
        p->pos = start + n;
        const char *w = p->s + start;
        size_t after = p->pos;
        expr_skip_ws(p);
        int call = p->s[p->pos] == '(';
        for (size_t i = 0; i < sizeof funcs / sizeof funcs[0]; i++)
            if (strlen(funcs[i].name) == n && memcmp(funcs[i].name, w, n) == 0) {
                if (!call) {
                    expr_fail_at(p, after, "expected '(' after '%s'", funcs[i].name);
                    return -1;
                }
                return parse_call(p, &funcs[i], start);
            }
        p->pos = after;
        if (call) {
            expr_fail_at(p, start, "unknown function '%.*s'", (int)(n > 64 ? 64 : n), w);
            return -1;
        }
        if (n == 1 && (w[0] == 'x' || w[0] == 'y' || w[0] == 'z'))
            return chk(p, tape_emit_var(p->b, w[0] - 'x'), start);
        if (n == 2 && memcmp(w, "pi", 2) == 0) {
            interval k = interval_around(M_PI);
            return chk(p, tape_emit_const(p->b, M_PI, k.lo, k.hi), start);
        }
        if (n == 1 && w[0] == 'e') {
            interval k = interval_around(M_E);
            return chk(p, tape_emit_const(p->b, M_E, k.lo, k.hi), start);
        }
        expr_fail_at(p, start, "unknown variable '%.*s'", (int)(n > 64 ? 64 : n), w);
        return -1;
    }
    char what[32];
    expr_describe(p, start, what, sizeof what);
    if (c == '\0')
        expr_fail_at(p, start, "expected an expression, found end of line");
    else
        expr_fail_at(p, start, "expected an expression, found %s", what);
    return -1;
}

static int32_t parse_unary(expr_parser *p);

/* power := primary ('^' unary)? — right-associative, and tighter than a
 * unary minus on its left: -x^2 = -(x^2), 2^-1 = 0.5. */
static int32_t parse_power(expr_parser *p)
{
    int32_t base = parse_primary(p);
    if (base < 0)
        return -1;
    expr_skip_ws(p);
    if (p->s[p->pos] != '^')
        return base;
    size_t op = p->pos++;
    int32_t e = parse_unary(p);
    if (e < 0)
        return -1;
    return chk(p, tape_emit_pow(p->b, base, e), op);
}

static int32_t parse_unary(expr_parser *p)
{
    if (!enter(p))
        return -1;
    expr_skip_ws(p);
    int32_t r;
    if (p->s[p->pos] == '-') {
        size_t op = p->pos++;
        r = parse_unary(p);
        if (r >= 0)
            r = chk(p, tape_emit_unary(p->b, TAPE_NEG, r), op);
    } else {
        r = parse_power(p);
    }
    p->depth--;
    return r;
}

static int32_t parse_term(expr_parser *p)
{
    int32_t r = parse_unary(p);
    for (;;) {
        if (r < 0)
            return -1;
        expr_skip_ws(p);
        char c = p->s[p->pos];
        if (c != '*' && c != '/')
            return r;
        size_t op = p->pos++;
        int32_t q = parse_unary(p);
        if (q < 0)
            return -1;
        r = chk(p, tape_emit_binary(p->b, c == '*' ? TAPE_MUL : TAPE_DIV, r, q), op);
    }
}

static int32_t parse_sum(expr_parser *p)
{
    if (!enter(p))
        return -1;
    int32_t r = parse_term(p);
    for (;;) {
        if (r < 0)
            break;
        expr_skip_ws(p);
        char c = p->s[p->pos];
        if (c != '+' && c != '-')
            break;
        size_t op = p->pos++;
        int32_t q = parse_term(p);
        if (q < 0) {
            r = -1;
            break;
        }
        r = chk(p, tape_emit_binary(p->b, c == '+' ? TAPE_ADD : TAPE_SUB, r, q), op);
    }
    p->depth--;
    return r;
}

int32_t expr_parse(expr_parser *p)
{
    return parse_sum(p);
}
