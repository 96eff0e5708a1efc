/* Tests for render/trace_setup's shortcuts: trace_setup_eye from an eye
 * inside the root cube against its general path, and trace_anchor_find
 * (from the root or near an earlier anchor) against the plain per-level
 * search, bit for bit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench/rng.h"
#include "bench/tree_util.h"
#include "render/trace.h"
#include "render/trace_impl.h"

static uint64_t rng_state = 0x2545f4914f6cdd1du;
static uint64_t rng(void) { return rng_xorshift64star(&rng_state); }
static double urand(void) { return (double)(rng() >> 11) * 0x1p-53; }
static uint32_t irand(uint32_t n) { return (uint32_t)(rng() % n); }

/* trace_setup_eye's shortcut for eyes inside the root cube gives the ray
 * of the general path, bit for bit, and so does trace_setup_dir: eyes
 * anywhere inside, on faces, edges and corners, directions with zero, tiny
 * and huge components. */
static void test_setup_inside_same_ray(void **state)
{
    (void)state;
    uint32_t vox[1][3] = {{1, 2, 3}};
    unsigned long same = 0, set = 0;
    for (unsigned L = 1; L <= 12; L += 1) {
        oct_tree *t = tree_util_simple(L, (const uint32_t(*)[3])vox, L >= 2 ? 1 : 0);
        assert_non_null(t);
        const double N = (double)(1u << L);
        for (int k = 0; k < 4000; k++) {
            double eye[3], dir[3];
            for (int a = 0; a < 3; a++) {
                const int how = (int)irand(4);
                eye[a] = how == 0 ? 0.0 : how == 1 ? 1.0 : how == 2 ? urand() : (double)irand(9) / 8.0;
                const int dh = (int)irand(6);
                dir[a] = dh == 0 ? 0.0 : dh == 1 ? -0.0 : dh == 2 ? (urand() - 0.5) * 1e-310
                       : dh == 3 ? (urand() - 0.5) * 1e300 : 2.0 * urand() - 1.0;
            }
            trace_eye e;
            if (!trace_eye_init(t, eye, &e))
                continue;
            assert_true(e.all_inside); /* the unit cube: every eye above is in it */
            trace_ray r0, r1;
            memset(&r0, 0, sizeof r0);
            memset(&r1, 0, sizeof r1);
            const int ok0 = trace_setup_eye_general(&e, dir, &r0);
            const int ok1 = trace_setup_eye(&e, dir, &r1);
            assert_int_equal(ok1, ok0);
            /* the direction's part made once (trace_dir): the same ray */
            trace_dir td;
            trace_dir_init(&e, dir, &td);
            trace_ray r2;
            memset(&r2, 0, sizeof r2);
            assert_int_equal(trace_setup_dir(&e, &td, &r2), ok0);
            if (ok0)
                assert_memory_equal(&r2, &r1, sizeof r1);
            if (ok0) {
                assert_memory_equal(r1.o, r0.o, sizeof r0.o);
                assert_memory_equal(r1.ot, r0.ot, sizeof r0.ot);
                assert_memory_equal(r1.inv, r0.inv, sizeof r0.inv);
                assert_memory_equal(r1.d, r0.d, sizeof r0.d);
                assert_memory_equal(&r1.t_base, &r0.t_base, sizeof r0.t_base);
                assert_memory_equal(&r1.t_start, &r0.t_start, sizeof r0.t_start);
                assert_memory_equal(&r1.t_end, &r0.t_end, sizeof r0.t_end);
                assert_memory_equal(r1.sgn, r0.sgn, sizeof r0.sgn);
                assert_memory_equal(r1.v, r0.v, sizeof r0.v);
                assert_int_equal(r1.active, r0.active);
                set++;
            }
            same++;
        }
        (void)N;
        tree_util_free(t);
    }
    print_message("setup: %lu rays from inside the cube the same (%lu set up)\n", same, set);
    assert_true(set > 10000 && same > set);
}

/* trace_anchor_find against the plain per-level search it replaces, and
 * trace_anchor_find_near from the previous box's anchor: the same depth,
 * corner and nodes for boxes anywhere, small and large, near the last one
 * or not. */
static void ref_anchor(const oct_tree *tree, const double lo[3], const double hi[3],
                       trace_anchor *a)
{
    const unsigned levels = tree->levels;
    a->depth = 0;
    a->cell[0] = a->cell[1] = a->cell[2] = 0;
    a->node[0].prefix = tree->groups[0][0].base;
    a->node[0].mask = tree->groups[0][0].mask[0];
    a->node[0].ci = 0;
    const double n = (double)(UINT32_C(1) << levels);
    for (int i = 0; i < 3; i++)
        if (!(lo[i] > 0.0 && hi[i] < n && lo[i] <= hi[i]))
            return;
    uint32_t vl[3], vh[3];
    for (int i = 0; i < 3; i++) {
        vl[i] = (uint32_t)lo[i];
        vh[i] = (uint32_t)hi[i];
    }
    for (unsigned d = 1; d < levels; d++) {
        const unsigned sh = levels - d;
        if ((vl[0] >> sh) != (vh[0] >> sh) || (vl[1] >> sh) != (vh[1] >> sh) ||
            (vl[2] >> sh) != (vh[2] >> sh))
            return;
        const unsigned c = (vl[0] >> sh & 1u) | (vl[1] >> sh & 1u) << 1 | (vl[2] >> sh & 1u) << 2;
        const uint32_t m = a->node[d - 1].mask;
        if (!(m >> c & 1u))
            return;
        const uint64_t idx = a->node[d - 1].prefix + oct_popcount64(m & ((1u << c) - 1u));
        const oct_children ch = oct_node_children(tree->groups[d], idx);
        a->node[d].mask = ch.mask;
        a->node[d].prefix = ch.first;
        a->node[d].ci = c;
        a->depth = d;
        for (int i = 0; i < 3; i++)
            a->cell[i] = vl[i] >> sh << sh;
    }
}

static void test_anchor_find_reference(void **state)
{
    (void)state;
    unsigned long boxes = 0, deep = 0, shared = 0;
    for (int tr = 0; tr < 16; tr++) {
        const unsigned L = 1 + irand(8);
        const uint32_t N = 1u << L;
        const size_t n = 1 + irand(N < 64 ? N * N + 1 : 4000);
        uint32_t(*xyz)[3] = malloc(n * sizeof *xyz);
        assert_non_null(xyz);
        const uint32_t width = N - N / 8 > 0 ? N - N / 8 : 1;
        const size_t m = tree_util_distinct_voxels(n, N / 8, width, &rng_state, xyz);
        oct_tree *t = tree_util_simple(L, (const uint32_t(*)[3])xyz, m);
        assert_non_null(t);
        trace_anchor last;
        last.depth = 0;
        double nlo[3], nhi[3];
        int near_next = 0;
        for (int k = 0; k < 3000; k++) {
            double lo[3], hi[3];
            const double w = irand(2) ? 0x1p-9 : urand() * (double)N / (double)(1u << irand(L + 1));
            for (int a = 0; a < 3; a++) {
                lo[a] = near_next ? nlo[a] : urand() * (N + 2.0) - 1.0;
                hi[a] = near_next ? nhi[a] : lo[a] + (irand(8) ? w : -w);
            }
            near_next = 0;
            trace_anchor a0, a1, a2;
            ref_anchor(t, lo, hi, &a0);
            trace_anchor_find(t, lo, hi, &a1);
            assert_int_equal(a1.depth, a0.depth);
            assert_memory_equal(a1.cell, a0.cell, sizeof a0.cell);
            assert_memory_equal(a1.node, a0.node, (a0.depth + 1) * sizeof a0.node[0]);
            /* from the last box's anchor (near or far from this one), into
               another struct and in place */
            trace_anchor_find_near(t, lo, hi, &last, &a2);
            assert_int_equal(a2.depth, a0.depth);
            assert_memory_equal(a2.cell, a0.cell, sizeof a0.cell);
            assert_memory_equal(a2.node, a0.node, (a0.depth + 1) * sizeof a0.node[0]);
            shared += last.depth > 0 && a0.depth > 0 && a0.node[1].ci == last.node[1].ci;
            trace_anchor_find_near(t, lo, hi, &last, &last);
            assert_int_equal(last.depth, a0.depth);
            assert_memory_equal(last.cell, a0.cell, sizeof a0.cell);
            assert_memory_equal(last.node, a0.node, (a0.depth + 1) * sizeof a0.node[0]);
            if (irand(3) == 0) { /* the next box next to this one */
                for (int a = 0; a < 3; a++) {
                    nlo[a] = lo[a] + (urand() - 0.5) * 4.0;
                    nhi[a] = nlo[a] + 0x1p-9;
                }
                near_next = 1;
            }
            boxes++;
            deep += a0.depth + 1 >= L && L > 1;
        }
        tree_util_free(t);
        free(xyz);
    }
    print_message("anchors: %lu boxes the same, from the root and from the last box's anchor "
                  "(%lu sharing nodes with it), %lu down to the voxels' parents\n",
                  boxes, shared, deep);
    assert_true(deep > 100 && shared > 1000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_setup_inside_same_ray),
        cmocka_unit_test(test_anchor_find_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
