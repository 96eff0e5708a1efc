/* scene: line-oriented reader for .scene files and a recursive-descent
 * parser for EXPR with a depth limit, building tapes. */
#include "common/expr/scene.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/diag.h"
#include "common/parse_num.h"

typedef struct parser {
    const char *s;  /* current line, NUL-terminated, comment cut off */
    size_t pos;     /* byte offset in s */
    unsigned line;
    int depth;
    int failed;
    tape_builder *b;
    scene_error *err;
} parser;

static void fail_at(parser *p, size_t pos, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void fail_at(parser *p, size_t pos, const char *fmt, ...)
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

static void set_err(scene_error *err, unsigned line, unsigned col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void set_err(scene_error *err, unsigned line, unsigned col, const char *fmt, ...)
{
    err->line = line;
    err->col = col;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

static int is_alpha(int c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
static int is_digit(int c) { return c >= '0' && c <= '9'; }
static int is_alnum(int c) { return is_alpha(c) || is_digit(c); }

static void skip_ws(parser *p)
{
    while (p->s[p->pos] == ' ' || p->s[p->pos] == '\t' || p->s[p->pos] == '\r')
        p->pos++;
}

/* Describes the byte at pos for "unexpected ..." messages. */
static void describe(const parser *p, size_t pos, char *buf, size_t n)
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
    for (; i < n && (is_digit(s[i]) || s[i] == '.'); i++) {
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

/* Reads an unsigned decimal literal at p->pos: 1 and the value, or 0 with
 * an error (or without one if there is no digit at all: *none is set). */
static int read_number(parser *p, double *v, int *exact, int *none)
{
    size_t start = p->pos;
    int bad_exp = 0;
    size_t n = parse_float_prefix(p->s + start, &bad_exp);
    *none = n == 0;
    if (n == 0)
        return 0;
    if (bad_exp) {
        fail_at(p, start, "malformed number: exponent without digits");
        return 0;
    }
    char next = p->s[start + n];
    if (is_alnum(next) || next == '.') {
        fail_at(p, start, "malformed number");
        return 0;
    }
    errno = 0;
    char *end;
    double d = strtod(p->s + start, &end);
    if ((size_t)(end - (p->s + start)) != n) {
        fail_at(p, start, "malformed number");
        return 0;
    }
    if (!isfinite(d)) {
        fail_at(p, start, "number out of range");
        return 0;
    }
    *v = d;
    *exact = literal_is_exact(p->s + start, n);
    p->pos = start + n;
    return 1;
}

/* Reports a negative builder result at pos; passes others through. */
static int32_t chk(parser *p, int32_t r, size_t pos)
{
    if (r < 0) {
        if (r == TAPE_EDOMAIN)
            fail_at(p, pos, "constant expression is undefined or not finite here");
        else
            fail_at(p, pos, "%s", tape_strerror(r));
        return -1;
    }
    return r;
}

static int32_t parse_sum(parser *p);

static int enter(parser *p)
{
    if (++p->depth > SCENE_MAX_DEPTH) {
        fail_at(p, p->pos, "expression nested too deeply (limit %d)", SCENE_MAX_DEPTH);
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
static int32_t parse_call(parser *p, const struct func *fn, size_t name_pos)
{
    int32_t first = -1, second = -1, acc = -1;
    int n = 0;
    size_t open = p->pos;
    p->pos++; /* '(' */
    skip_ws(p);
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
            skip_ws(p);
            if (p->s[p->pos] == ',') {
                p->pos++;
                continue;
            }
            break;
        }
    }
    if (p->s[p->pos] != ')') {
        char what[32];
        describe(p, p->pos, what, sizeof what);
        fail_at(p, p->pos, "expected ',' or ')' to close '(' at column %zu, found %s", open + 1, what);
        return -1;
    }
    p->pos++;
    if (fn->nargs == -1 ? n < 2 : n != fn->nargs) {
        if (fn->nargs == -1)
            fail_at(p, name_pos, "%s takes 2 or more arguments, got %d", fn->name, n);
        else
            fail_at(p, name_pos, "%s takes %d argument%s, got %d", fn->name, fn->nargs,
                    fn->nargs == 1 ? "" : "s", n);
        return -1;
    }
    if (fn->nargs == 1)
        return chk(p, tape_emit_unary(p->b, fn->op, first), name_pos);
    if (fn->op == TAPE_POWC)
        return chk(p, tape_emit_pow(p->b, first, second), name_pos);
    return acc;
}

static int32_t parse_primary(parser *p)
{
    skip_ws(p);
    size_t start = p->pos;
    char c = p->s[start];
    if (c == '(') {
        p->pos++;
        int32_t r = parse_sum(p);
        if (r < 0)
            return -1;
        skip_ws(p);
        if (p->s[p->pos] != ')') {
            char what[32];
            describe(p, p->pos, what, sizeof what);
            fail_at(p, p->pos, "expected ')' to close '(' at column %zu, found %s", start + 1, what);
            return -1;
        }
        p->pos++;
        return r;
    }
    if (is_digit(c) || c == '.') {
        double v;
        int exact, none;
        if (!read_number(p, &v, &exact, &none)) {
            if (none)
                fail_at(p, start, "malformed number");
            return -1;
        }
        interval k = exact ? (interval){v, v} : interval_around(v);
        return chk(p, tape_emit_const(p->b, v, k.lo, k.hi), start);
    }
    if (is_alpha(c)) {
        size_t n = 0;
        while (is_alnum(p->s[start + n]))
            n++;
        p->pos = start + n;
        const char *w = p->s + start;
        size_t after = p->pos;
        skip_ws(p);
        int call = p->s[p->pos] == '(';
        for (size_t i = 0; i < sizeof funcs / sizeof funcs[0]; i++)
            if (strlen(funcs[i].name) == n && memcmp(funcs[i].name, w, n) == 0) {
                if (!call) {
                    fail_at(p, after, "expected '(' after '%s'", funcs[i].name);
                    return -1;
                }
                return parse_call(p, &funcs[i], start);
            }
        p->pos = after;
        if (call) {
            fail_at(p, start, "unknown function '%.*s'", (int)(n > 64 ? 64 : n), w);
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
        fail_at(p, start, "unknown variable '%.*s'", (int)(n > 64 ? 64 : n), w);
        return -1;
    }
    char what[32];
    describe(p, start, what, sizeof what);
    if (c == '\0')
        fail_at(p, start, "expected an expression, found end of line");
    else
        fail_at(p, start, "expected an expression, found %s", what);
    return -1;
}

static int32_t parse_unary(parser *p);

/* power := primary ('^' unary)? — right-associative, and tighter than a
 * unary minus on its left: -x^2 = -(x^2), 2^-1 = 0.5. */
static int32_t parse_power(parser *p)
{
    int32_t base = parse_primary(p);
    if (base < 0)
        return -1;
    skip_ws(p);
    if (p->s[p->pos] != '^')
        return base;
    size_t op = p->pos++;
    int32_t e = parse_unary(p);
    if (e < 0)
        return -1;
    return chk(p, tape_emit_pow(p->b, base, e), op);
}

static int32_t parse_unary(parser *p)
{
    if (!enter(p))
        return -1;
    skip_ws(p);
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

static int32_t parse_term(parser *p)
{
    int32_t r = parse_unary(p);
    for (;;) {
        if (r < 0)
            return -1;
        skip_ws(p);
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

static int32_t parse_sum(parser *p)
{
    if (!enter(p))
        return -1;
    int32_t r = parse_term(p);
    for (;;) {
        if (r < 0)
            break;
        skip_ws(p);
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

/* Reads n signed numbers for bounds/color; positions into cols. */
static int read_numbers(parser *p, const char *stmt, int n, double *v, size_t *cols)
{
    for (int i = 0; i < n; i++) {
        skip_ws(p);
        size_t start = p->pos;
        int neg = 0;
        if (p->s[p->pos] == '-' || p->s[p->pos] == '+')
            neg = p->s[p->pos++] == '-';
        int exact, none;
        if (!read_number(p, &v[i], &exact, &none)) {
            if (none) {
                char what[32];
                describe(p, start, what, sizeof what);
                fail_at(p, start, "%s needs %d numbers, found %s", stmt, n, what);
            }
            return 0;
        }
        if (neg)
            v[i] = -v[i];
        cols[i] = start;
    }
    skip_ws(p);
    if (p->s[p->pos] != '\0') {
        char what[32];
        describe(p, p->pos, what, sizeof what);
        fail_at(p, p->pos, "unexpected %s after the %d numbers of %s", what, n, stmt);
        return 0;
    }
    return 1;
}

void scene_free(scene *s)
{
    if (!s)
        return;
    for (size_t i = 0; i < s->nsurfaces; i++)
        tape_free(&s->surfaces[i].tape);
    free(s->surfaces);
    free(s);
}

/* Parses one statement line (comment already removed) into sc. */
static void parse_line(parser *p, scene *sc, int *have_bounds, unsigned *bounds_line,
                       int *has_color, size_t *cap)
{
    skip_ws(p);
    size_t start = p->pos;
    if (p->s[start] == '\0')
        return;
    size_t n = 0;
    while (is_alnum(p->s[start + n]))
        n++;
    const char *w = p->s + start;
    p->pos = start + n;
    if (n == 6 && memcmp(w, "bounds", 6) == 0) {
        if (*have_bounds) {
            fail_at(p, start, "bounds already given on line %u", *bounds_line);
            return;
        }
        double v[6];
        size_t cols[6];
        if (!read_numbers(p, "bounds", 6, v, cols))
            return;
        for (int a = 0; a < 3; a++)
            if (!(v[a + 3] > v[a])) {
                fail_at(p, cols[a + 3], "empty bounds: %c1 (%g) must be greater than %c0 (%g)",
                        'X' + a, v[a + 3], 'X' + a, v[a]);
                return;
            }
        for (int a = 0; a < 3; a++) {
            sc->lo[a] = v[a];
            sc->hi[a] = v[a + 3];
        }
        *have_bounds = 1;
        *bounds_line = p->line;
    } else if (n == 7 && memcmp(w, "surface", 7) == 0) {
        if (sc->nsurfaces == *cap) {
            size_t nc = *cap ? *cap * 2 : 4;
            scene_surface *ns = realloc(sc->surfaces, nc * sizeof *ns);
            if (!ns) {
                fail_at(p, start, "out of memory");
                return;
            }
            sc->surfaces = ns;
            *cap = nc;
        }
        p->b = tape_builder_new();
        if (!p->b) {
            fail_at(p, start, "out of memory");
            return;
        }
        if (p->s[p->pos] != ' ' && p->s[p->pos] != '\t' && p->s[p->pos] != '\0') {
            char what[32];
            describe(p, p->pos, what, sizeof what);
            fail_at(p, p->pos, "unexpected %s after 'surface'", what);
            goto done;
        }
        int32_t root = parse_sum(p);
        if (root < 0)
            goto done;
        skip_ws(p);
        if (p->s[p->pos] != '\0') {
            char what[32];
            describe(p, p->pos, what, sizeof what);
            if (p->s[p->pos] == ')')
                fail_at(p, p->pos, "unmatched ')'");
            else
                fail_at(p, p->pos, "unexpected %s after the expression", what);
            goto done;
        }
        scene_surface *sf = &sc->surfaces[sc->nsurfaces];
        if (tape_builder_finish(p->b, root, &sf->tape) != TAPE_OK) {
            fail_at(p, start, "out of memory");
            goto done;
        }
        sf->color[0] = sf->color[1] = sf->color[2] = SCENE_DEFAULT_COLOR;
        sf->line = p->line;
        sc->nsurfaces++;
        *has_color = 0;
    done:
        tape_builder_free(p->b);
        p->b = NULL;
    } else if (n == 5 && memcmp(w, "color", 5) == 0) {
        if (sc->nsurfaces == 0) {
            fail_at(p, start, "color before any surface");
            return;
        }
        if (*has_color) {
            fail_at(p, start, "the surface on line %u already has a color",
                    sc->surfaces[sc->nsurfaces - 1].line);
            return;
        }
        double v[3];
        size_t cols[3];
        if (!read_numbers(p, "color", 3, v, cols))
            return;
        for (int i = 0; i < 3; i++)
            if (!(v[i] >= 0.0 && v[i] <= 1.0)) {
                fail_at(p, cols[i], "color component %g outside 0..1", v[i]);
                return;
            }
        memcpy(sc->surfaces[sc->nsurfaces - 1].color, v, sizeof v);
        *has_color = 1;
    } else if (n > 0) {
        fail_at(p, start, "unknown statement '%.*s' (expected bounds, surface or color)",
                (int)(n > 64 ? 64 : n), w);
    } else {
        char what[32];
        describe(p, start, what, sizeof what);
        fail_at(p, start, "expected bounds, surface or color, found %s", what);
    }
}

int scene_parse(const char *text, size_t len, scene **out, scene_error *err)
{
    *out = NULL;
    memset(err, 0, sizeof *err);
    char *buf = NULL;
    scene *sc = calloc(1, sizeof *sc);
    parser p = {0};
    p.err = err;
    if (!sc) {
        set_err(err, 1, 1, "out of memory");
        goto fail;
    }
    if (len == 0) {
        set_err(err, 1, 1, "empty file");
        goto fail;
    }
    int have_bounds = 0, has_color = 0;
    unsigned bounds_line = 0;
    size_t cap = 0;
    size_t off = 0;
    for (unsigned line = 1; off < len; line++) {
        const char *nl = memchr(text + off, '\n', len - off);
        size_t n = nl ? (size_t)(nl - (text + off)) : len - off;
        if (n > SCENE_MAX_LINE) {
            set_err(err, line, SCENE_MAX_LINE + 1, "line longer than %u bytes", SCENE_MAX_LINE);
            goto fail;
        }
        const unsigned char *l = (const unsigned char *)text + off;
        size_t stmt = n; /* bytes before a comment */
        for (size_t i = 0; i < n; i++) {
            unsigned char c = l[i];
            int ok = c >= 0x20 ? c != 0x7f : (c == '\t' || (c == '\r' && i + 1 == n));
            if (!ok) {
                set_err(err, line, (unsigned)i + 1, "not a text file: byte 0x%02x", c);
                goto fail;
            }
            if (c == '#' && stmt == n)
                stmt = i;
        }
        free(buf);
        buf = malloc(stmt + 1);
        if (!buf) {
            set_err(err, line, 1, "out of memory");
            goto fail;
        }
        memcpy(buf, l, stmt);
        buf[stmt] = '\0';
        p.s = buf;
        p.pos = 0;
        p.line = line;
        p.depth = 0;
        parse_line(&p, sc, &have_bounds, &bounds_line, &has_color, &cap);
        if (p.failed)
            goto fail;
        off += n + (nl ? 1 : 0);
    }
    if (!have_bounds) {
        set_err(err, 1, 1, "missing 'bounds' statement");
        goto fail;
    }
    if (sc->nsurfaces == 0) {
        set_err(err, 1, 1, "missing 'surface' statement");
        goto fail;
    }
    free(buf);
    *out = sc;
    return 0;
fail:
    free(buf);
    scene_free(sc);
    return -1;
}

int scene_load(const char *path, scene **out, scene_error *err)
{
    *out = NULL;
    memset(err, 0, sizeof *err);
    char *text = NULL;
    int rc = -1;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        set_err(err, 1, 1, "cannot open: %s", strerror(errno));
        goto done;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        set_err(err, 1, 1, "cannot stat: %s", strerror(errno));
        goto done;
    }
    if (S_ISDIR(st.st_mode)) {
        set_err(err, 1, 1, "is a directory, not a scene file");
        goto done;
    }
    size_t cap = 4096, len = 0;
    text = malloc(cap);
    if (!text) {
        set_err(err, 1, 1, "out of memory");
        goto done;
    }
    for (;;) {
        if (len == cap) {
            if (cap > SCENE_MAX_FILE) {
                set_err(err, 1, 1, "file larger than %u bytes", SCENE_MAX_FILE);
                goto done;
            }
            char *t = realloc(text, cap * 2);
            if (!t) {
                set_err(err, 1, 1, "out of memory");
                goto done;
            }
            text = t;
            cap *= 2;
        }
        ssize_t r = read(fd, text + len, cap - len);
        if (r < 0) {
            if (errno == EINTR)
                continue;
            set_err(err, 1, 1, "cannot read: %s", strerror(errno));
            goto done;
        }
        if (r == 0)
            break;
        len += (size_t)r;
    }
    rc = scene_parse(text, len, out, err);
done:
    if (fd >= 0)
        close(fd);
    free(text);
    return rc;
}

void scene_print_error(const char *path, const scene_error *err)
{
    diag_at(path, err->line, err->col, "%s", err->message);
}
