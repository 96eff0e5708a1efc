/* Helpers shared by the tape tests (test_tape*.c): a
 * deterministic random source, enclosure checks and random expression trees
 * compiled through the scene parser. static inline: each test uses a part.
 * Include after cmocka.h (rand_tree fails the test on a parser error). */
#ifndef TEST_TAPE_UTIL_H
#define TEST_TAPE_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "bench/rng.h"
#include "common/expr/scene.h"
#include "common/expr/tape.h"

#ifdef __FAST_MATH__
#error "fast-math breaks the interval arithmetic; build without it"
#endif

/* Under AddressSanitizer the loops run a tenth as many cases. */
#if defined(__SANITIZE_ADDRESS__)
#define SCALE 10
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SCALE 10
#endif
#endif
#ifndef SCALE
#define SCALE 1
#endif

#define MAXSLOTS 4096

/* One generator per test program (xorshift64, fixed seed). */
static uint64_t rng = 0x2545f4914f6cdd1dull;
static inline uint64_t next_u64(void) { return rng_xorshift64(&rng); }
static inline double unit(void) { return rng_unit(next_u64()); }

/* v is enclosed by r (with the flag rules of interval.h). */
static inline int encloses(interval r, unsigned flags, double v)
{
    if (interval_is_nan(r))
        return flags != 0;
    if (isnan(v))
        return flags != 0;
    return r.lo <= v && v <= r.hi;
}

static inline double in_box(interval b)
{
    double p = b.lo + unit() * (b.hi - b.lo);
    return p < b.lo ? b.lo : p > b.hi ? b.hi : p;
}

/* ---- random expression trees --------------------------------------------- */

static inline void gen(char **p, char *end, int depth)
{
    static const char *leaves[] = {"x", "y", "z", "0.78", "pi", "e", "2", "1.5", "0.5", "3", "0.1"};
    static const char *un[] = {"exp", "log", "sqrt", "abs", "sin", "cos", "tan", "-"};
    static const char *bin[] = {"+", "-", "*", "/", "min", "max", "^", "pow"};
    if (end - *p < 200) {
        *p += sprintf(*p, "x");
        return;
    }
    uint64_t r = next_u64() % 10;
    if (depth == 0 || r < 2) {
        *p += sprintf(*p, "%s", leaves[next_u64() % (sizeof leaves / sizeof leaves[0])]);
        return;
    }
    if (r < 5) {
        const char *u = un[next_u64() % (sizeof un / sizeof un[0])];
        *p += sprintf(*p, u[0] == '-' ? "-(" : "%s(", u);
        gen(p, end, depth - 1);
        *p += sprintf(*p, ")");
        return;
    }
    const char *b = bin[next_u64() % (sizeof bin / sizeof bin[0])];
    if (b[0] == '^') {
        static const char *ex[] = {"2", "3", "4", "-1", "-2", "0.5", "1.5", "y", "5"};
        *p += sprintf(*p, "(");
        gen(p, end, depth - 1);
        *p += sprintf(*p, ")^%s", ex[next_u64() % (sizeof ex / sizeof ex[0])]);
    } else if (b[0] >= 'a') {
        *p += sprintf(*p, "%s(", b);
        gen(p, end, depth - 1);
        *p += sprintf(*p, ", ");
        gen(p, end, depth - 1);
        if (b[1] != 'o' && next_u64() % 3 == 0) {
            *p += sprintf(*p, ", ");
            gen(p, end, depth - 1);
        }
        *p += sprintf(*p, ")");
    } else {
        *p += sprintf(*p, "(");
        gen(p, end, depth - 1);
        *p += sprintf(*p, ") %s (", b);
        gen(p, end, depth - 1);
        *p += sprintf(*p, ")");
    }
}

/* The scene "surface EXPR" in the box [-4, 4]^3; a parser error fails the
 * test. */
static inline scene *parse_surface(const char *expr)
{
    char text[1024];
    snprintf(text, sizeof text, "bounds -4 -4 -4 4 4 4\nsurface %s\n", expr);
    scene *s = NULL;
    scene_error e;
    if (scene_parse(text, strlen(text), &s, &e) != 0)
        fail_msg("%s: %s", expr, e.message);
    return s;
}

/* A random scene whose surface is a random tree of depth <= 6. */
static inline scene *rand_tree(char *text, size_t n)
{
    for (;;) {
        char *p = text + sprintf(text, "bounds -4 -4 -4 4 4 4\nsurface ");
        gen(&p, text + n, 1 + (int)(next_u64() % 6));
        *p++ = '\n';
        scene *s = NULL;
        scene_error e;
        if (scene_parse(text, (size_t)(p - text), &s, &e) == 0)
            return s;
        /* Only constant sub-trees that are undefined may be refused. */
        if (!strstr(e.message, "constant expression") && !strstr(e.message, "exponent"))
            fail_msg("%s: %s", text, e.message);
    }
}

static inline void rand_tree_box(interval box[3])
{
    for (int a = 0; a < 3; a++) {
        double c = (unit() - 0.5) * 8, w = 8 * ldexp(unit(), -(int)(next_u64() % 30));
        box[a].lo = c;
        box[a].hi = next_u64() % 10 == 0 ? c : c + w;
    }
}

#endif
