/* Numerics at the extremes (TESTPLAN.md sections 4 and 5, issue 6):
 * interval operations on extreme inputs checked against MPFR witnesses and
 * the documented NaN flag; scenes with poles, undefined regions and
 * overflow through the rasterizer, against the documented rules; the same
 * sphere at the origin and at 10^6 (cancellation). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <mpfr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/interval.h"
#include "common/expr/scene.h"
#include "format/oct.h"
#include "rasterize/build.h"

#ifdef __FAST_MATH__
#error "interval soundness needs IEEE semantics: no -ffast-math"
#endif

static interval iv(double lo, double hi)
{
    interval r = {lo, hi};
    return r;
}

typedef enum { OP_EXP, OP_LOG, OP_SQRT, OP_SIN, OP_COS, OP_DIV, OP_POWC } op_kind;

/* The exact value of the operation at (x, y) in MPFR (128 bits, then the
 * comparison is exact); returns 0 when it is NaN (undefined). */
static int exact(op_kind op, double x, double y, mpfr_t r)
{
    mpfr_t a, b;
    mpfr_inits2(128, a, b, (mpfr_ptr)0);
    mpfr_set_d(a, x, MPFR_RNDN);
    mpfr_set_d(b, y, MPFR_RNDN);
    switch (op) {
    case OP_EXP: mpfr_exp(r, a, MPFR_RNDN); break;
    case OP_LOG: mpfr_log(r, a, MPFR_RNDN); break;
    case OP_SQRT: mpfr_sqrt(r, a, MPFR_RNDN); break;
    case OP_SIN: mpfr_sin(r, a, MPFR_RNDN); break;
    case OP_COS: mpfr_cos(r, a, MPFR_RNDN); break;
    case OP_DIV: mpfr_div(r, a, b, MPFR_RNDN); break;
    case OP_POWC:
        /* the scene language's a^p for non-integer p: defined for a >= 0 */
        if (x < 0)
            mpfr_set_nan(r);
        else
            mpfr_pow(r, a, b, MPFR_RNDN);
        break;
    }
    mpfr_clears(a, b, (mpfr_ptr)0);
    return !mpfr_nan_p(r);
}

static interval apply(op_kind op, interval a, interval b, double p, unsigned *f)
{
    switch (op) {
    case OP_EXP: return interval_exp(a, f);
    case OP_LOG: return interval_log(a, f);
    case OP_SQRT: return interval_sqrt(a, f);
    case OP_SIN: return interval_sin(a, f);
    case OP_COS: return interval_cos(a, f);
    case OP_DIV: return interval_div(a, b, f);
    case OP_POWC: return interval_powc(a, p, f);
    }
    return interval_nan();
}

/* Witness points of [lo, hi]: the ends, zero, a few inside (finite only). */
static int witnesses(interval a, double *w)
{
    int n = 0;
    const double cand[] = {a.lo, a.hi, 0.0, -0.0, a.lo / 2 + a.hi / 2,
                           nextafter(a.lo, INFINITY), nextafter(a.hi, -INFINITY),
                           a.lo + (a.hi - a.lo) * 0.318, a.lo + (a.hi - a.lo) * 0.77};
    for (size_t i = 0; i < sizeof cand / sizeof cand[0]; i++)
        if (isfinite(cand[i]) && cand[i] >= a.lo && cand[i] <= a.hi)
            w[n++] = cand[i];
    return n;
}

/* Every witness's exact value lies in the result; a NaN witness needs the
 * flag. Returns the result for extra assertions. */
static interval check(op_kind op, interval a, interval b, double p, unsigned *flags_out)
{
    unsigned f = 0;
    interval r = apply(op, a, b, p, &f);
    double wa[12], wb[12];
    int na = witnesses(a, wa), nb = op == OP_DIV ? witnesses(b, wb) : 1;
    if (op != OP_DIV)
        wb[0] = p;
    mpfr_t v;
    mpfr_init2(v, 128);
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb; j++) {
            if (!exact(op, wa[i], wb[j], v)) {
                if (!(f & INTERVAL_MAYBE_NAN))
                    fail_msg("op %d [%a, %a] [%a, %a]: undefined at %a, %a but no NaN flag", (int)op,
                             a.lo, a.hi, b.lo, b.hi, wa[i], wb[j]);
                continue;
            }
            if (interval_is_nan(r) || mpfr_cmp_d(v, r.lo) < 0 || mpfr_cmp_d(v, r.hi) > 0)
                fail_msg("op %d [%a, %a] [%a, %a] p=%g: value at %a, %a = %.17g outside [%a, %a]",
                         (int)op, a.lo, a.hi, b.lo, b.hi, p, wa[i], wb[j], mpfr_get_d(v, MPFR_RNDN),
                         r.lo, r.hi);
        }
    mpfr_clear(v);
    *flags_out = f;
    return r;
}

static void test_interval_extremes(void **state)
{
    (void)state;
    unsigned f;
    interval r;
    const interval none = iv(0, 0);
    /* exp(+-1000): overflow to +inf, underflow to a positive bound, no NaN */
    r = check(OP_EXP, iv(1000, 1000), none, 0, &f);
    assert_true(r.hi == INFINITY && f == 0);
    r = check(OP_EXP, iv(-1000, -1000), none, 0, &f);
    assert_true(r.lo >= 0 && r.hi > 0 && f == 0); /* e^-1000 > 0 must stay inside */
    r = check(OP_EXP, iv(-1000, 1000), none, 0, &f);
    assert_true(r.lo >= 0 && r.hi == INFINITY && f == 0);
    check(OP_EXP, iv(709, 710), none, 0, &f);   /* the overflow threshold */
    check(OP_EXP, iv(-746, -744), none, 0, &f); /* the subnormal range */
    r = check(OP_EXP, iv(-INFINITY, INFINITY), none, 0, &f);
    assert_true(r.lo == 0 && r.hi == INFINITY && f == 0);

    /* division by [0, 0] and by [-1, 1] */
    r = check(OP_DIV, iv(1, 2), iv(0, 0), 0, &f);
    assert_false(interval_is_nan(r)); /* 1/0 is an infinity, not undefined */
    assert_int_equal(f, 0);
    r = check(OP_DIV, iv(0, 0), iv(0, 0), 0, &f); /* 0/0 */
    assert_true(f & INTERVAL_MAYBE_NAN);
    r = check(OP_DIV, iv(-1, 1), iv(0, 0), 0, &f);
    assert_true(f & INTERVAL_MAYBE_NAN);
    r = check(OP_DIV, iv(1, 2), iv(-1, 1), 0, &f);
    assert_true(r.lo == -INFINITY && r.hi == INFINITY && f == 0);
    r = check(OP_DIV, iv(-1, 1), iv(-1, 1), 0, &f);
    assert_true(r.lo == -INFINITY && r.hi == INFINITY && (f & INTERVAL_MAYBE_NAN));
    r = check(OP_DIV, iv(1e308, 1e308), iv(1e-308, 1e-308), 0, &f); /* overflow */
    assert_true(r.hi == INFINITY && f == 0);
    r = check(OP_DIV, iv(1e-308, 1e-308), iv(1e308, 1e308), 0, &f); /* underflow */
    assert_true(r.lo <= 0 && r.hi > 0 && f == 0); /* widened to +-DBL_MIN: still encloses */

    /* pow with a non-integer exponent of negative bases */
    r = check(OP_POWC, iv(-8, -1), none, 0.5, &f);
    assert_true(interval_is_nan(r) && (f & INTERVAL_MAYBE_NAN)); /* defined nowhere */
    r = check(OP_POWC, iv(-1, 4), none, 1.0 / 3.0, &f);
    assert_true(r.lo <= 0 && r.hi >= cbrt(4.0) && (f & INTERVAL_MAYBE_NAN));
    r = check(OP_POWC, iv(-2, 0), none, -0.5, &f); /* only 0 is defined: +inf */
    assert_true(f & INTERVAL_MAYBE_NAN);
    assert_true(interval_is_nan(r) || r.hi == INFINITY);
    r = check(OP_POWC, iv(0, 1e300), none, 2.5, &f);
    assert_true(r.lo == 0 && r.hi == INFINITY && f == 0);

    /* sin/cos over wide and huge arguments */
    r = check(OP_SIN, iv(0, 1e6), none, 0, &f);
    assert_true(r.lo == -1 && r.hi == 1 && f == 0);
    r = check(OP_SIN, iv(1e6, 1e6 + 1e-3), none, 0, &f);
    assert_true(r.hi - r.lo < 2e-3 && f == 0); /* narrow stays narrow */
    check(OP_SIN, iv(1e22, 1e22), none, 0, &f);
    check(OP_COS, iv(1e300, 1e300), none, 0, &f);
    check(OP_COS, iv(-1e6, 1e6), none, 0, &f);
    r = check(OP_SIN, iv(-INFINITY, 0), none, 0, &f);
    assert_true(r.lo >= -1 && r.hi <= 1);

    /* log of [0, a]: -inf lower bound, no NaN flag; negative parts flag */
    r = check(OP_LOG, iv(0, 5), none, 0, &f);
    assert_true(r.lo == -INFINITY && r.hi >= log(5.0) && f == 0);
    r = check(OP_LOG, iv(0, 0), none, 0, &f);
    assert_true(r.lo == -INFINITY && f == 0);
    r = check(OP_LOG, iv(-1, 0), none, 0, &f);
    assert_true(f & INTERVAL_MAYBE_NAN);
    r = check(OP_LOG, iv(4.9e-324, 1e308), none, 0, &f);
    assert_true(r.lo <= -744 && r.hi >= 709 && f == 0);

    /* sqrt of [-1, 4] is [0, 2] with the flag; of [-4, -1] defined nowhere */
    r = check(OP_SQRT, iv(-1, 4), none, 0, &f);
    assert_true(r.lo == 0 && r.hi >= 2 && r.hi <= nextafter(2, 3) && (f & INTERVAL_MAYBE_NAN));
    r = check(OP_SQRT, iv(-4, -1), none, 0, &f);
    assert_true(interval_is_nan(r) && (f & INTERVAL_MAYBE_NAN));

    /* (x*1e200)^2 - 1 over [-1, 1]: saturates at +inf, never inf - inf */
    f = 0;
    r = interval_sub(interval_sqr(interval_mul(iv(-1, 1), iv(1e200, 1e200), &f), &f), iv(1, 1),
                     &f);
    assert_true(r.lo <= -1 && r.hi == INFINITY && f == 0);
    /* and on a box away from 0 it excludes 0 (the cell is dropped) */
    f = 0;
    r = interval_sub(interval_sqr(interval_mul(iv(0.25, 0.5), iv(1e200, 1e200), &f), &f),
                     iv(1, 1), &f);
    assert_true(r.lo > 0 && r.hi == INFINITY && f == 0);
}

/* ---- Scenes through the rasterizer --------------------------------------- */

typedef struct vox_list {
    size_t n;
    uint32_t xmin, xmax;
} vox_list;

static scene *parse(const char *text)
{
    scene *s = NULL;
    scene_error err;
    if (scene_parse(text, strlen(text), &s, &err) != 0)
        fail_msg("%u:%u: %s", err.line, err.col, err.message);
    return s;
}

/* Builds `text` at `levels` into memory; returns the stats and the range of
 * voxel x indices (walking the tree through the reader). */
static build_stats rasterize_text(const char *text, unsigned levels, vox_list *vl)
{
    scene *sc = parse(text);
    oct_writer_params wp;
    memset(&wp, 0, sizeof wp);
    wp.levels = levels;
    build_cube(sc, wp.origin, &wp.edge);
    wp.surface_count = (uint32_t)sc->nsurfaces;
    float palette[3] = {1, 1, 1};
    wp.palette = palette;
    oct_writer *w = NULL;
    assert_int_equal(oct_writer_create(&wp, &w), OCT_OK);
    build_params bp = {.levels = levels, .method = BUILD_INTERVAL, .threads = 2};
    build_stats st;
    assert_int_equal(build_octree(sc, &bp, w, &st), OCT_OK);
    char *bytes = NULL;
    size_t size = 0;
    FILE *mem = open_memstream(&bytes, &size);
    assert_non_null(mem);
    uint64_t n = 0;
    assert_int_equal(oct_writer_finish(w, mem, &n), OCT_OK);
    assert_int_equal(fclose(mem), 0);
    oct_writer_free(w);
    oct_file *file = NULL;
    uint64_t off = 0;
    assert_int_equal(oct_open_memory(bytes, size, 0, &file, &off), OCT_OK);
    const oct_tree *t = oct_get_tree(file);
    /* depth-first walk keeping the x coordinate */
    vl->n = 0;
    vl->xmin = UINT32_MAX;
    vl->xmax = 0;
    if (t->node_count[0]) {
        struct {
            uint64_t node;
            uint32_t x;
            unsigned depth;
        } stack[8 * OCT_MAX_LEVELS + 8];
        int sp = 0;
        stack[sp].node = 0;
        stack[sp].x = 0;
        stack[sp].depth = 0;
        sp++;
        while (sp > 0) {
            sp--;
            uint64_t node = stack[sp].node;
            uint32_t x = stack[sp].x;
            unsigned d = stack[sp].depth;
            uint8_t m = oct_node_mask(t->groups[d], node);
            for (unsigned c = 0; c < 8; c++) {
                if (!(m >> c & 1))
                    continue;
                uint32_t cx = x << 1 | (c & 1);
                uint64_t child = oct_child_index(t->groups[d], node, c);
                if (d + 1 == t->levels) {
                    vl->n++;
                    vl->xmin = cx < vl->xmin ? cx : vl->xmin;
                    vl->xmax = cx > vl->xmax ? cx : vl->xmax;
                } else {
                    stack[sp].node = child;
                    stack[sp].x = cx;
                    stack[sp].depth = d + 1;
                    sp++;
                }
            }
        }
    }
    assert_int_equal(vl->n, t->voxel_count);
    oct_close(file);
    free(bytes);
    scene_free(sc);
    return st;
}

#define BOX "bounds -1 -1 -1 1 1 1\n"

static void test_scene_rules(void **state)
{
    (void)state;
    vox_list v;
    build_stats st;
    const unsigned L = 5; /* 32^3; x = 0 is the plane between x-indices 15 and 16 */
    const size_t layer = 32 * 32;

    /* sqrt(x): undefined for x < 0 (NaN cells counted, then dropped where
     * defined nowhere); the zero set x = 0 lies on a voxel plane: both
     * layers that touch it, nothing else */
    st = rasterize_text(BOX "surface sqrt(x)\n", L, &v);
    assert_true(st.nan_cells > 0);
    assert_int_equal(v.n, 2 * layer);
    assert_true(v.xmin == 15 && v.xmax == 16);
    /* sqrt(x - 2): defined nowhere in the box: no voxel */
    st = rasterize_text(BOX "surface sqrt(x-2)\n", L, &v);
    assert_true(st.nan_cells > 0);
    assert_int_equal(v.n, 0);
    /* log(x) = 0 on x = 1, the root's upper face: the last layer only */
    st = rasterize_text(BOX "surface log(x)\n", L, &v);
    assert_int_equal(v.n, layer);
    assert_true(v.xmin == 31 && v.xmax == 31);
    /* 1/x: the pole at x = 0 is a sign change the interval test keeps (the
     * documented rule: division by an interval touching 0 is [-inf, inf]) */
    st = rasterize_text(BOX "surface 1/x\n", L, &v);
    assert_int_equal(v.n, 2 * layer);
    assert_true(v.xmin == 15 && v.xmax == 16);
    /* 1/(x-x): x - x is [-w, w] for interval arithmetic (the dependency
     * problem), so every cell is kept; each voxel's normal falls back */
    st = rasterize_text(BOX "surface 1/(x-x)\n", L, &v);
    assert_int_equal(v.n, 32 * layer);
    assert_int_equal(st.normal_fallbacks, v.n);
    /* (x*1e200)^2 - 1 = 0 at |x| = 1e-200: saturates without NaN, kept only
     * next to x = 0 */
    st = rasterize_text(BOX "surface (x*1e200)^2-1\n", L, &v);
    assert_int_equal(st.nan_cells, 0);
    assert_true(v.n >= 2 * layer);
    assert_true(v.xmin >= 14 && v.xmax <= 17);
    assert_true(v.xmin <= 15 && v.xmax >= 16);
}

/* The unit sphere at the origin and at 10^6: same voxel count within 1 %
 * (in double the shift costs 20 bits of 53; the grid needs 7). */
static void test_cancellation(void **state)
{
    (void)state;
    vox_list a, b, c;
    rasterize_text("bounds -1.25 -1.25 -1.25 1.25 1.25 1.25\nsurface x^2+y^2+z^2-1\n", 7, &a);
    rasterize_text("bounds 999998.75 999998.75 999998.75 1000001.25 1000001.25 1000001.25\n"
                   "surface (x-1e6)^2+(y-1e6)^2+(z-1e6)^2-1\n",
                   7, &b);
    /* expanded form: catastrophic cancellation (x^2 ~ 1e12), still sound */
    rasterize_text("bounds 999998.75 -1.25 -1.25 1000001.25 1.25 1.25\n"
                   "surface x^2-2e6*x+1e12+y^2+z^2-1\n",
                   7, &c);
    print_message("sphere voxels: origin %zu, at 1e6 %zu, expanded at 1e6 %zu\n", a.n, b.n, c.n);
    assert_true(a.n > 10000);
    assert_true(fabs((double)b.n - (double)a.n) <= 0.01 * (double)a.n);
    /* the expanded form may only keep more (no false negatives) */
    assert_true(c.n >= b.n * 99 / 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_interval_extremes),
        cmocka_unit_test(test_scene_rules),
        cmocka_unit_test(test_cancellation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
