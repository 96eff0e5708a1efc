/* Tests for render/ao_grid and the walk through it
 * (trace_occluded_grid_sse): every cell's word against a brute-force count
 * of its empty cubes; the walk's answer against the plain any-hit walk and
 * the traversal for rays of every kind (random, from grid planes and voxel
 * corners, along cell faces, with tied axes, clipped, anchored or not), on
 * random and shaped trees; too shallow a tree has no grid. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "bench/rng.h"
#include "bench/tree_util.h"
#include "render/ao_grid.h"
#include "render/trace.h"
#include "render/trace_impl.h"
#include "tests/sanitized.h"
#include "tests/voxel_shapes.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15u;
static uint64_t rng(void) { return rng_xorshift64star(&rng_state); }
static uint32_t irand(uint32_t n) { return (uint32_t)(rng() % n); }

/* Voxels in a few clusters (AO's case: surfaces with empty space between)
 * or spread at random. */
static oct_tree *random_tree(unsigned levels, size_t want, int clustered)
{
    const uint32_t lim = UINT32_C(1) << levels;
    uint32_t(*xyz)[3] = calloc(want, sizeof *xyz);
    assert_non_null(xyz);
    uint32_t c[3] = {0, 0, 0};
    for (size_t i = 0; i < want; i++) {
        if (!clustered || i % 64 == 0)
            for (int a = 0; a < 3; a++)
                c[a] = irand(lim);
        for (int a = 0; a < 3; a++) {
            const uint32_t v = clustered ? c[a] + irand(9) - 4 : c[a];
            xyz[i][a] = v >= lim ? c[a] : v; /* out of the cube: the centre */
        }
    }
    oct_tree *t = tree_util_simple(levels, (const uint32_t(*)[3])xyz, want);
    assert_non_null(t);
    free(xyz);
    return t;
}

/* Marks in occ the cells at depth `depth` under node `node` at depth d
 * (corner x, y, z in cells of depth d), by a walk over all children. */
static void mark_cells(const oct_tree *t, unsigned depth, uint32_t n, uint8_t *occ, unsigned d,
                       uint64_t node, uint32_t x, uint32_t y, uint32_t z)
{
    if (d == depth) {
        occ[x + (size_t)n * (y + (size_t)n * z)] = 1;
        return;
    }
    const oct_children ch = oct_node_children(t->groups[d], node);
    uint64_t k = ch.first;
    for (unsigned c = 0; c < 8; c++)
        if (ch.mask >> c & 1u)
            mark_cells(t, depth, n, occ, d + 1, k++, 2 * x + (c & 1u), 2 * y + (c >> 1 & 1u),
                       2 * z + (c >> 2 & 1u));
}

/* The occupied cells at the grid's depth: those holding a voxel. */
static uint8_t *occupied_cells(const oct_tree *t, const ao_grid *g)
{
    const size_t n = g->n;
    uint8_t *occ = calloc(n * n * n, 1);
    assert_non_null(occ);
    if (t->node_count[0])
        mark_cells(t, g->depth, g->n, occ, 0, 0, 0, 0, 0);
    return occ;
}

/* The largest k <= the cap whose cube of k cells from c on octant o's side
 * (clipped to the grid: outside is empty) holds no occupied cell. */
static unsigned brute_clearance(const uint8_t *occ, uint32_t n, const uint32_t c[3], unsigned o)
{
    unsigned k = 0;
    while (k < AO_GRID_MAX_CLEARANCE) {
        /* the cube of edge k + 1 */
        for (uint32_t i = 0; i <= k; i++)
            for (uint32_t j = 0; j <= k; j++)
                for (uint32_t l = 0; l <= k; l++) {
                    const int64_t x = (int64_t)c[0] + (o & 1u ? i : -(int64_t)i),
                                  y = (int64_t)c[1] + (o & 2u ? j : -(int64_t)j),
                                  z = (int64_t)c[2] + (o & 4u ? l : -(int64_t)l);
                    if (x < 0 || y < 0 || z < 0 || x >= n || y >= n || z >= n)
                        continue;
                    if (occ[x + (int64_t)n * (y + (int64_t)n * z)])
                        return k;
                }
        k++;
    }
    return k;
}

static void check_words(const oct_tree *t)
{
    ao_grid g;
    assert_int_equal(ao_grid_build(t, &g), 0);
    assert_int_equal(g.depth, ao_grid_depth(t));
    assert_int_equal(g.n, UINT32_C(1) << g.depth);
    uint8_t *occ = occupied_cells(t, &g);
    const uint32_t n = g.n;
    for (uint32_t z = 0; z < n; z++)
        for (uint32_t y = 0; y < n; y++)
            for (uint32_t x = 0; x < n; x++) {
                const uint32_t c[3] = {x, y, z};
                const uint32_t w = g.cell[x + n * (y + n * z)];
                assert_int_equal(AO_GRID_OCCUPIED(w), occ[x + n * (y + n * z)]);
                if (AO_GRID_OCCUPIED(w))
                    continue;
                for (unsigned o = 0; o < 8; o++)
                    assert_int_equal(AO_GRID_CLEARANCE(w, o), brute_clearance(occ, n, c, o));
            }
    free(occ);
    ao_grid_free(&g);
    assert_null(g.cell);
}

static void test_clearances_brute_force(void **state)
{
    (void)state;
    for (unsigned levels = 4; levels <= 7; levels++)
        for (int clustered = 0; clustered <= 1; clustered++) {
            const size_t want = (size_t)1 << (levels + 2 + (unsigned)clustered * 2);
            oct_tree *t = random_tree(levels, want, clustered);
            check_words(t);
            tree_util_free(t);
        }
    /* an empty tree: every cell clear up to the cap */
    const uint32_t none[1][3] = {{0, 0, 0}};
    oct_tree *t = tree_util_simple(5, none, 0);
    assert_non_null(t);
    check_words(t);
    tree_util_free(t);
}

/* The node of an occupied cell is the tree's node at the grid's depth that
 * covers it: its children, walked, are voxels of that cell. */
static void test_occupied_nodes(void **state)
{
    (void)state;
    oct_tree *t = random_tree(7, 3000, 1);
    ao_grid g;
    assert_int_equal(ao_grid_build(t, &g), 0);
    const uint32_t n = g.n;
    unsigned long checked = 0;
    for (uint32_t z = 0; z < n; z++)
        for (uint32_t y = 0; y < n; y++)
            for (uint32_t x = 0; x < n; x++) {
                const uint32_t w = g.cell[x + n * (y + n * z)];
                if (!AO_GRID_OCCUPIED(w))
                    continue;
                /* the descent to (x, y, z) from the root names the same node */
                uint64_t node = 0;
                for (unsigned d = 0; d < g.depth; d++) {
                    const unsigned s = g.depth - 1 - d;
                    const unsigned ci = (x >> s & 1u) | (y >> s & 1u) << 1 | (z >> s & 1u) << 2;
                    const oct_children ch = oct_node_children(t->groups[d], node);
                    assert_true(ch.mask >> ci & 1u);
                    node = ch.first + (uint64_t)__builtin_popcount(ch.mask & ((1u << ci) - 1u));
                }
                assert_int_equal(AO_GRID_NODE(w), node);
                checked++;
            }
    assert_true(checked > 100);
    ao_grid_free(&g);
    tree_util_free(t);
}

static void test_too_shallow(void **state)
{
    (void)state;
    const uint32_t one[1][3] = {{0, 1, 0}};
    for (unsigned levels = 1; levels <= 3; levels++) {
        oct_tree *t = tree_util_simple(levels, one, 1);
        assert_non_null(t);
        ao_grid g;
        assert_int_equal(ao_grid_depth(t), 0);
        assert_int_equal(ao_grid_build(t, &g), -1);
        assert_int_equal(g.n, 0);
        assert_null(g.cell);
        tree_util_free(t);
    }
}

#if TRACE_HAVE_SSE
static double urand(void) { return (double)(rng() >> 11) * 0x1p-53; }

/* A start coordinate: on a grid plane, a cell's plane, a voxel's middle,
 * or anywhere. */
static double pick_coord(uint32_t lim, unsigned shift)
{
    switch (irand(5)) {
    case 0: return (double)irand(lim + 1);
    case 1: return (double)(irand((lim >> shift) + 1) << shift);
    case 2: return (double)irand(lim) + 0.5;
    default: return urand() * lim;
    }
}

/* A direction component: tied with others, zero now and then, or any. */
static double pick_dir(void)
{
    static const double tied[] = {1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 0.25};
    switch (irand(6)) {
    case 0: return tied[irand(7)];
    case 1: return irand(50) ? tied[irand(7)] : 0.0;
    default: return 2.0 * urand() - 1.0;
    }
}

typedef struct walk_stats {
    unsigned long rays, occluded, anchored;
} walk_stats;

/* Rays from inside the cube through tree t: the grid's walk answers as the
 * plain walk (and the traversal: an occupied voxel met or not). */
/* An occupied cell of the grid drawn at random (its coordinates in cc):
 * 1, or 0 when 64 draws found none. */
static int random_occupied_cell(const ao_grid *g, uint32_t cc[3])
{
    const uint32_t n = g->n;
    for (int tries = 0; tries < 64; tries++) {
        const uint32_t c = irand(n * n * n);
        if (AO_GRID_OCCUPIED(g->cell[c])) {
            cc[0] = c % n;
            cc[1] = c / n % n;
            cc[2] = c / n / n;
            return 1;
        }
    }
    return 0;
}

static void check_rays(const oct_tree *t, unsigned long count, walk_stats *st)
{
    ao_grid g;
    assert_int_equal(ao_grid_build(t, &g), 0);
    const uint32_t lim = UINT32_C(1) << t->levels;
    const trace_opts opts = {.split = t->levels};
    for (unsigned long i = 0; i < count; i++) {
        double o[3], d[3];
        for (int a = 0; a < 3; a++) {
            o[a] = pick_coord(lim, g.shift);
            d[a] = pick_dir();
        }
        const unsigned kind = irand(3);
        if (kind == 2) {
            /* aimed through a corner of an occupied cell's voxel along a
               dyadic direction: positions on cell planes at the grid's
               steps, where the cell is taken from the plane times */
            static const double comp[] = {1.0, -1.0, 2.0, -2.0, 0.5, -0.5};
            uint32_t cc[3];
            if (random_occupied_cell(&g, cc)) {
                const double back = (double)(1 + irand(48));
                for (int a = 0; a < 3; a++) {
                    d[a] = comp[irand(6)];
                    const double target = (double)((cc[a] << g.shift) + irand((1u << g.shift) + 1));
                    const double v = target - back * d[a];
                    o[a] = v < 0.0 ? 0.0 : v > lim ? (double)lim : v;
                }
            }
        } else if (kind == 1) {
            /* rays that start next to an occupied cell, as AO rays do */
            uint32_t cc[3];
            if (random_occupied_cell(&g, cc))
                for (int a = 0; a < 3; a++) {
                    const double v =
                        ((double)cc[a] + 3.0 * urand() - 1.0) * (double)(1u << g.shift);
                    o[a] = v < 0.0 ? 0.0 : v > lim ? (double)lim : v;
                }
        }
        if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
            d[2] = 1.0;
        /* the tree's unit cube: grid point g is world g / lim */
        const double eye[3] = {o[0] / lim, o[1] / lim, o[2] / lim};
        trace_ray r;
        if (!trace_setup(t, eye, d, &r))
            continue;
        if (irand(3) == 0 && !trace_clip(&r, 0.0, urand() * 0.5))
            continue;
        trace_anchor an, *anp = NULL;
        if (irand(2)) {
            const double m = 0x1p-10;
            double lo[3], hi[3];
            for (int a = 0; a < 3; a++) {
                lo[a] = r.o[a] - m;
                hi[a] = r.o[a] + m;
            }
            trace_anchor_find(t, lo, hi, &an);
            anp = &an;
            st->anchored += an.depth > g.depth;
        }
        uint32_t s0, s1;
        const int plain = trace_occluded_sse(t, &r, anp, &s0);
        const int grid = trace_occluded_grid_sse(t, &g, &r, anp, &s1);
        if (plain != grid)
            fail_msg("grid walk %d, plain walk %d: o (%a %a %a) d (%a %a %a) t %a..%a anchor %u",
                     grid, plain, o[0], o[1], o[2], d[0], d[1], d[2], r.t_start, r.t_end,
                     anp ? anp->depth : 0u);
        trace_hit h;
        trace_impls[0].traverse(t, &opts, &r, NULL, &h);
        assert_int_equal(grid, h.hit);
        st->rays++;
        st->occluded += (unsigned long)grid;
    }
    ao_grid_free(&g);
}

static void test_walk_matches_plain_walk(void **state)
{
    (void)state;
    walk_stats st = {0};
    const unsigned long per_tree = SANITIZED ? 4000 : 20000;
    for (unsigned levels = 4; levels <= 9; levels++)
        for (int clustered = 0; clustered <= 1; clustered++) {
            const size_t want = (size_t)1 << (levels + 1 + (unsigned)clustered * 2);
            oct_tree *t = random_tree(levels, want > 60000 ? 60000 : want, clustered);
            check_rays(t, per_tree, &st);
            tree_util_free(t);
        }
    /* surfaces: a floor, a wall and a ball, as the AO tests see them */
    shape sh[3] = {shape_plane(0, 0, 1, 80.5), shape_plane(1, 0, 0, 80.5),
                   shape_sphere(160, 160, 120, 32)};
    sh[0].lo[0] = 80;
    sh[1].lo[2] = 80;
    oct_tree *t = shapes_build(8, 1.0, sh, 3, 1);
    assert_non_null(t);
    check_rays(t, 4 * per_tree, &st);
    tree_util_free(t);
    print_message("grid walk: %lu rays, %lu occluded, %lu from an anchor below the grid\n",
                  st.rays, st.occluded, st.anchored);
    assert_true(st.occluded > st.rays / 10 && st.occluded < st.rays - st.rays / 10);
    assert_true(st.anchored > st.rays / 50);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clearances_brute_force),
        cmocka_unit_test(test_occupied_nodes),
        cmocka_unit_test(test_too_shallow),
#if TRACE_HAVE_SSE
        cmocka_unit_test(test_walk_matches_plain_walk),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
