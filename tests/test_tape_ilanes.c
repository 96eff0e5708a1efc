/* Tests for the lane interval evaluators (common/expr/tape_ilanes.c,
 * tape_iglanes.c): on every build the processor can run (portable, AVX2),
 * each lane gives the bits and flags of tape_eval_interval (and
 * tape_eval_interval_grad, gradient included) on its box, for random trees of every
 * operation over boxes that reach the edge cases (points, signed zeros,
 * subnormal and huge ends, infinite ends, overflow), and for the example
 * scenes over the cells of their subdivision. Runs from the repository
 * root (reads scenes/). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/expr/scene.h"
#include "common/expr/tape.h"
#include "tests/test_tape_util.h"

static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b));
}

static tape_ilanes lslots[MAXSLOTS];
static interval islots[MAXSLOTS];
static tape_idual_lanes glslots[MAXSLOTS];
static tape_idual gslots[MAXSLOTS];

static int same_interval(interval a, interval b)
{
    return same_bits(a.lo, b.lo) && same_bits(a.hi, b.hi);
}

/* The gradient lanes against tape_eval_interval_grad, on the given path. */
static void check_grad(int path, const tape *t, const interval box[][3], unsigned n,
                       const char *what)
{
    interval out[TAPE_LANES], g[TAPE_LANES][3];
    unsigned fl[TAPE_LANES];
    tape_eval_interval_grad_lanes_on(path, t, n, box, out, g, fl, glslots);
    for (unsigned l = 0; l < n; l++) {
        unsigned f1 = 0;
        interval rg[3], r = tape_eval_interval_grad(t, box[l], rg, gslots, &f1);
        int j = 0;
        while (j < 3 && same_interval(g[l][j], rg[j]))
            j++;
        if (!same_interval(out[l], r) || j < 3 || fl[l] != f1)
            fail_msg("%s: gradient path %s lane %u of %u, box [%a,%a]x[%a,%a]x[%a,%a]: "
                     "[%a,%a] flags %u, scalar [%a,%a] flags %u, first partial differing %d",
                     what, tape_lanes_path_name(path), l, n, box[l][0].lo, box[l][0].hi,
                     box[l][1].lo, box[l][1].hi, box[l][2].lo, box[l][2].hi, out[l].lo,
                     out[l].hi, fl[l], r.lo, r.hi, f1, j);
    }
}

/* Lane by lane against tape_eval_interval, on the given path. */
static void check(int path, const tape *t, const interval box[][3], unsigned n, const char *what)
{
    interval out[TAPE_LANES];
    unsigned fl[TAPE_LANES];
    tape_eval_interval_lanes_on(path, t, n, box, out, fl, lslots);
    for (unsigned l = 0; l < n; l++) {
        unsigned f1;
        interval r = tape_eval_interval(t, box[l], islots, &f1);
        if (!same_bits(out[l].lo, r.lo) || !same_bits(out[l].hi, r.hi) || fl[l] != f1)
            fail_msg("%s path %s lane %u of %u, box [%a,%a]x[%a,%a]x[%a,%a]: [%a,%a] flags %u, "
                     "scalar [%a,%a] flags %u",
                     what, tape_lanes_path_name(path), l, n, box[l][0].lo, box[l][0].hi,
                     box[l][1].lo, box[l][1].hi, box[l][2].lo, box[l][2].hi, out[l].lo,
                     out[l].hi, fl[l], r.lo, r.hi, f1);
        /* every slot too: the rasterizer prunes a cell's tape from them
         * (children_may_cross) */
        for (uint32_t i = 0; i < t->n; i++)
            if (!same_bits(lslots[i].lo[l], islots[i].lo) ||
                !same_bits(lslots[i].hi[l], islots[i].hi))
                fail_msg("%s path %s lane %u of %u: slot %u [%a,%a], scalar [%a,%a]", what,
                         tape_lanes_path_name(path), l, n, (unsigned)i, lslots[i].lo[l],
                         lslots[i].hi[l], islots[i].lo, islots[i].hi);
    }
    check_grad(path, t, box, n, what);
}

/* An end from the edge cases, or an ordinary number. */
static double edge_value(void)
{
    static const double v[] = {0.0, -0.0, DBL_MIN, -DBL_MIN, 0x1p-1070, -0x1p-1070, 1e300,
                               -1e300, 1e-300, INFINITY, -INFINITY, 1.0, -1.0, 0.78, 3.0};
    return v[next_u64() % (sizeof v / sizeof v[0])];
}

static void rand_box(interval box[3])
{
    rand_tree_box(box);
    for (int a = 0; a < 3; a++) {
        uint64_t r = next_u64() % 16;
        if (r == 0) { /* an edge value as a point */
            box[a].lo = box[a].hi = edge_value();
        } else if (r == 1) { /* an edge value at either end */
            double e = edge_value(), c = box[a].lo;
            box[a].lo = e < c ? e : c;
            box[a].hi = e < c ? c : e;
        }
    }
}

static void test_random_trees(void **state)
{
    (void)state;
    static char text[16384];
    interval box[TAPE_LANES][3];
    for (int n = 0; n < 4000 / SCALE; n++) {
        scene *s = rand_tree(text, sizeof text);
        const tape *t = &s->surfaces[0].tape;
        assert_true(t->n <= MAXSLOTS);
        unsigned lanes = 1 + (unsigned)n % TAPE_LANES;
        for (unsigned l = 0; l < lanes; l++)
            rand_box(box[l]);
        for (int path = 0; path < TAPE_PATHS; path++)
            if (tape_lanes_path_available(path))
                check(path, t, (const interval(*)[3])box, lanes, text);
        scene_free(s);
    }
}

/* The example scenes over random cells of their subdivision (levels 1 to
 * 12) and the points at those cells' centres, as the rasterizer asks. */
static void test_scenes(void **state)
{
    (void)state;
    FILE *ls = popen("ls scenes/*.scene", "r");
    assert_non_null(ls);
    char path[512];
    int nscenes = 0;
    while (fgets(path, sizeof path, ls)) {
        path[strcspn(path, "\n")] = 0;
        scene *s = NULL;
        scene_error e;
        if (scene_load(path, &s, &e) != 0)
            fail_msg("%s:%u:%u: %s", path, e.line, e.col, e.message);
        nscenes++;
        for (size_t j = 0; j < s->nsurfaces; j++) {
            const tape *t = &s->surfaces[j].tape;
            assert_true(t->n <= MAXSLOTS);
            for (int i = 0; i < 400 / SCALE; i++) {
                interval box[TAPE_LANES][3];
                unsigned lanes = 1 + (unsigned)i % TAPE_LANES, level = 1 + (unsigned)i % 12;
                for (unsigned l = 0; l < lanes; l++)
                    for (int a = 0; a < 3; a++) {
                        double h = ldexp(s->hi[a] - s->lo[a], -(int)level);
                        double lo = s->lo[a] + floor(unit() * ldexp(1.0, (int)level)) * h;
                        box[l][a].lo = lo;
                        box[l][a].hi = i & 1 ? lo + h : lo + 0.5 * h; /* odd: cells, even: points */
                        if (!(i & 1))
                            box[l][a].lo = box[l][a].hi;
                    }
                for (int p = 0; p < TAPE_PATHS; p++)
                    if (tape_lanes_path_available(p))
                        check(p, t, (const interval(*)[3])box, lanes, path);
            }
        }
        scene_free(s);
    }
    pclose(ls);
    assert_true(nscenes >= 10);
}

/* Boxes that share coordinates, as a cell's eight children share each
 * axis's two halves: the lane evaluators take the sine and cosine
 * enclosures once per distinct argument and copy them, with their flags,
 * to the other lanes. Each lane must still give the scalar bits and flags:
 * narrow and wide trig arguments, signed-zero points ([-0,-0] beside
 * [+0,+0]), infinite ends. */
static void test_shared_boxes(void **state)
{
    (void)state;
    static const char *texts[] = {
        "bounds -1 -1 -1 1 1 1\nsurface sin(x)*cos(y) + sin(y)*cos(z) + sin(z)*cos(x)\n",
        "bounds -1 -1 -1 1 1 1\nsurface cos(3*x) - sin(3*x) + sin(x*y) + cos(z) + tan(z)\n",
    };
    static char text[16384];
    interval box[TAPE_LANES][3];
    for (size_t k = 0; k < sizeof texts / sizeof *texts + 1; k++) {
        scene *s = NULL;
        scene_error e;
        for (int i = 0; i < 3000 / SCALE; i++) {
            if (k == sizeof texts / sizeof *texts) { /* random trees */
                s = rand_tree(text, sizeof text);
            } else if (!s) {
                assert_int_equal(scene_parse(texts[k], strlen(texts[k]), &s, &e), 0);
            }
            interval half[3][2];
            for (int a = 0; a < 3; a++) {
                rand_box(box[0]);
                const double lo = box[0][a].lo, hi = box[0][a].hi;
                const double mid = isfinite(lo) && isfinite(hi) ? lo + 0.5 * (hi - lo) : 0.0;
                half[a][0] = (interval){lo, mid < lo ? lo : mid};
                half[a][1] = (interval){mid > hi ? hi : mid, hi};
                if (i % 5 == 0) { /* signed-zero points side by side */
                    half[a][0] = (interval){0.0, 0.0};
                    half[a][1] = (interval){-0.0, -0.0};
                }
            }
            const unsigned lanes = 1 + (unsigned)i % TAPE_LANES;
            for (unsigned l = 0; l < lanes; l++)
                for (int a = 0; a < 3; a++)
                    box[l][a] = half[a][(l >> a) & 1u];
            const tape *t = &s->surfaces[0].tape;
            for (int p = 0; p < TAPE_PATHS; p++)
                if (tape_lanes_path_available(p))
                    check(p, t, (const interval(*)[3])box, lanes,
                          k < sizeof texts / sizeof *texts ? texts[k] : text);
            if (k == sizeof texts / sizeof *texts) {
                scene_free(s);
                s = NULL;
            }
        }
        scene_free(s);
    }
}

/* The path in use is one that is available; DDA_SIMD=portable (test
 * builds) selects the portable one. */
static void test_path_choice(void **state)
{
    (void)state;
    int p = tape_lanes_path();
    assert_true(tape_lanes_path_available(p));
    assert_true(tape_lanes_path_available(TAPE_PATH_PORTABLE));
    const char *v = getenv("DDA_SIMD");
    if (v && strcmp(v, "portable") == 0)
        assert_int_equal(p, TAPE_PATH_PORTABLE);
    else
        assert_int_equal(p, tape_lanes_path_available(TAPE_PATH_AVX2) ? TAPE_PATH_AVX2
                                                                       : TAPE_PATH_PORTABLE);
    printf("lane evaluator path: %s\n", tape_lanes_path_name(p));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_random_trees),
        cmocka_unit_test(test_scenes),
        cmocka_unit_test(test_shared_boxes),
        cmocka_unit_test(test_path_choice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
