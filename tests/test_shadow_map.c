/* Tests for render/shadow_map: the time after which a ray towards the light
 * meets no occupied voxel (checked against every voxel's closed box), and
 * shadow rays stopped there giving the answers of rays traced whole, on
 * every implementation, with and without --refine. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bench/rng.h"
#include "bench/tree_util.h"
#include "format/oct_normal.h"
#include "render/shadow.h"
#include "render/shadow_map.h"
#include "tests/grid_hits.h"
#include "tests/voxel_shapes.h"

/* The t range in which the ray g + t D meets the closed box [v, v + 1]^3,
 * t >= 0; 0 when it does not. */
static int box_span(const double g[3], const double D[3], const uint32_t v[3], double *t0,
                    double *t1)
{
    double lo = 0.0, hi = INFINITY;
    for (int a = 0; a < 3; a++) {
        const double b0 = v[a], b1 = v[a] + 1.0;
        if (D[a] == 0.0) {
            if (g[a] < b0 || g[a] > b1)
                return 0;
            continue;
        }
        double ta = (b0 - g[a]) / D[a], tb = (b1 - g[a]) / D[a];
        if (ta > tb) {
            const double x = ta;
            ta = tb;
            tb = x;
        }
        lo = fmax(lo, ta);
        hi = fmin(hi, tb);
    }
    *t0 = lo;
    *t1 = hi;
    return lo <= hi;
}

/* Every voxel a ray meets, even at one point, is met before the map's
 * time: random trees of 5, 6 and 20 levels (scattered and clustered
 * voxels), lights with and without zero components, starts inside and
 * outside, maps of voxels and of cells of 4 voxels (at 20 levels, of cells
 * of depth 10 and 9 above the voxels). */
static void test_clear_t_bounds_every_voxel(void **state)
{
    (void)state;
    static const double lights[][3] = {{0.3, 0.2, 0.93}, {-0.8, 0.1, 0.59}, {0, 0, 1},
                                       {1, -1, 0},        {-0.1, -0.7, -0.2}, {0, -1, 0}};
    uint64_t rng = 0x5eed5eedu;
    unsigned long met = 0, finite = 0, none = 0;
    static const unsigned depths[] = {5, 6, 20};
    for (unsigned li = 0; li < 3; li++)
        for (unsigned form = 0; form < 2; form++) {
            const unsigned levels = depths[li];
            const uint32_t n = UINT32_C(1) << levels;
            static uint32_t xyz[600][3];
            /* 20 levels: clustered at the far corner, where heights are
               large (a float's step is 8 times the margin there) and the
               map's last texels are reached */
            const size_t nv = form   ? tree_util_distinct_voxels(600, n / 4, n / 3, &rng, xyz)
                              : li == 2 ? tree_util_distinct_voxels(300, n - 40, 40, &rng, xyz)
                                      : tree_util_distinct_voxels(150, 0, n, &rng, xyz);
            oct_tree *t = tree_util_simple(levels, (const uint32_t(*)[3])xyz, nv);
            assert_non_null(t);
            const double scale = (double)n / t->edge;
            for (size_t q = 0; q < 2 * sizeof lights / sizeof lights[0]; q++) {
                shadow_map m; /* each light with cells of voxels and of 4 voxels */
                const size_t l = q / 2;
                const unsigned up = q % 2 ? SHADOW_MAP_COARSE : SHADOW_MAP_FINE;
                assert_int_equal(shadow_map_build(t, lights[l], up, 1, &m), 0);
                assert_int_equal(m.depth, li < 2 ? levels - up : up ? 9 : 10); /* capped */
                const double D[3] = {scale * lights[l][0], scale * lights[l][1],
                                     scale * lights[l][2]};
                for (int k = 0; k < 400; k++) {
                    double g[3];
                    for (int a = 0; a < 3; a++)
                        g[a] = -2.0 + (n + 4.0) * rng_unit(rng_xorshift64star(&rng));
                    if (k % 2) {
                        /* back along the light from near a voxel: a ray past it */
                        const uint32_t *v = xyz[rng_xorshift64star(&rng) % nv];
                        const double back = (double)n * rng_unit(rng_xorshift64star(&rng));
                        for (int a = 0; a < 3; a++)
                            g[a] = v[a] - 0.5 + 2.0 * rng_unit(rng_xorshift64star(&rng)) -
                                   back * lights[l][a];
                    }
                    if (k % 4 < 2) /* on voxel planes */
                        for (int a = 0; a < 3; a++)
                            g[a] = floor(g[a]);
                    const double tc = shadow_map_clear_t(&m, g, lights[l], scale);
                    assert_true(tc < INFINITY);
                    int any = 0;
                    for (size_t i = 0; i < nv; i++) {
                        double t0, t1;
                        if (box_span(g, D, xyz[i], &t0, &t1)) {
                            assert_true(t0 < tc);
                            any = 1;
                        }
                    }
                    met += (unsigned)any;
                    none += tc == -INFINITY;
                    finite += tc > -INFINITY;
                }
                assert_true(shadow_map_clear_t(&m, (const double[3]){1, 1, 1}, lights[(l + 1) % 6],
                                               scale) == INFINITY); /* not its light */
                shadow_map_free(&m);
            }
            tree_util_free(t);
        }
    print_message("map: %lu rays meeting voxels, %lu with a finite end, %lu clear from the start\n",
                  met, finite, none);
    assert_true(met > 4000 && none > 2000);
}

/* Heights far from the origin: at 20 levels a float's step is 8 times the
 * margin, so the map's heights must be rounded up. One voxel at the cube's
 * far corner, lights nearly along z (its top face a hair below its top
 * corner's height), rays along the light that enter it through the side
 * y = N - 1 a thousandth below the top face and leave through that face:
 * the map's time is after their entry (maps of cells of depth 10 and 9,
 * whose tops are that corner too). */
static void test_far_heights_rounded_up(void **state)
{
    (void)state;
    enum { LEVELS = 20 };
    const uint32_t n = UINT32_C(1) << LEVELS;
    const uint32_t xyz[1][3] = {{n - 1, n - 1, n - 1}};
    oct_tree *t = tree_util_simple(LEVELS, xyz, 1);
    assert_non_null(t);
    const double scale = (double)n / t->edge;
    unsigned checked = 0;
    for (unsigned q = 1; q <= 60; q++) {
        const double light[3] = {0.0001 * (q % 7), 0.001 + 0.0001 * q, 1.0};
        const double D[3] = {scale * light[0], scale * light[1], scale * light[2]};
        for (unsigned up = SHADOW_MAP_FINE; up <= SHADOW_MAP_COARSE; up += 2) {
            shadow_map m;
            assert_int_equal(shadow_map_build(t, light, up, 1, &m), 0);
            for (int b = 0; b < 4; b++) {
                const double p[3] = {(double)n - 0.2 - 0.2 * b, (double)n - 1.0,
                                     (double)n - 0.001};
                double g[3];
                for (int a = 0; a < 3; a++)
                    g[a] = p[a] - 2.0 * D[a];
                double t0, t1;
                assert_true(box_span(g, D, xyz[0], &t0, &t1));
                assert_true(t1 - t0 < 0.01); /* a short chord under the top */
                assert_true(t0 < shadow_map_clear_t(&m, g, light, scale));
                checked++;
            }
            shadow_map_free(&m);
        }
    }
    assert_int_equal(checked, 60 * 2 * 4);
    tree_util_free(t);
}

/* The map is the same whatever the number of threads that build it (each
 * takes whole subtrees into a map of its own, merged by the maximum): bit
 * for bit, on a random tree of 7 levels with more subtrees than threads, at
 * both resolutions. */
static void test_same_map_any_threads(void **state)
{
    (void)state;
    enum { LEVELS = 7 };
    const uint32_t n = UINT32_C(1) << LEVELS;
    uint64_t rng = 0x7ea45u;
    static uint32_t xyz[3000][3];
    const size_t nv = tree_util_distinct_voxels(3000, 0, n, &rng, xyz);
    oct_tree *t = tree_util_simple(LEVELS, (const uint32_t(*)[3])xyz, nv);
    assert_non_null(t);
    const double light[3] = {-0.3, 0.45, 0.84};
    for (unsigned up = SHADOW_MAP_FINE; up <= SHADOW_MAP_COARSE; up += 2) {
        shadow_map one;
        assert_int_equal(shadow_map_build(t, light, up, 1, &one), 0);
        size_t raised = 0;
        for (size_t k = 0; k < (size_t)one.nu * one.nv; k++)
            raised += one.top[k] > -INFINITY;
        assert_true(raised > (size_t)one.nu * one.nv / 4);
        for (unsigned threads = 2; threads <= 9; threads += 7) {
            shadow_map m;
            assert_int_equal(shadow_map_build(t, light, up, threads, &m), 0);
            assert_int_equal(m.nu, one.nu);
            assert_int_equal(m.nv, one.nv);
            assert_memory_equal(m.top, one.top, (size_t)one.nu * one.nv * sizeof *one.top);
            shadow_map_free(&m);
        }
        shadow_map_free(&one);
    }
    tree_util_free(t);
}

/* The map kept from frame to frame (shadow_map_cached): made again when
 * the light's bits or the tree change or finer cells are asked for, kept
 * otherwise, and then the map a build from scratch gives, bit for bit. */
static void check_same_map(const shadow_map *m, const oct_tree *t, const double light[3],
                           unsigned up)
{
    shadow_map fresh;
    assert_int_equal(shadow_map_build(t, light, up, 1, &fresh), 0);
    assert_int_equal(m->depth, fresh.depth);
    assert_memory_equal(m->light, light, sizeof m->light);
    assert_int_equal(m->nu, fresh.nu);
    assert_int_equal(m->nv, fresh.nv);
    assert_memory_equal(m->top, fresh.top, (size_t)fresh.nu * fresh.nv * sizeof *fresh.top);
    shadow_map_free(&fresh);
}

static void test_cache_follows_tree_and_light(void **state)
{
    (void)state;
    enum { LEVELS = 6 };
    const uint32_t n = UINT32_C(1) << LEVELS;
    uint64_t rng = 0xcac4e5u;
    static uint32_t xyz[2][800][3];
    oct_tree *t[2];
    for (int k = 0; k < 2; k++) {
        const size_t nv = tree_util_distinct_voxels(800, 0, n, &rng, xyz[k]);
        t[k] = tree_util_simple(LEVELS, (const uint32_t(*)[3])xyz[k], nv);
        assert_non_null(t[k]);
    }
    const double l1[3] = {-0.3, 0.45, 0.84}, l2[3] = {0.6, -0.2, 0.77};
    const double l1z[3] = {-0.3, 0.45, 0.84 + 0x1p-52}; /* one ulp off l1 */
    shadow_map_cache c;
    memset(&c, 0, sizeof c);
    int built = -1;
    const unsigned C = SHADOW_MAP_COARSE, F = SHADOW_MAP_FINE;
    const shadow_map *m = shadow_map_cached(&c, t[0], l1, C, 2, &built);
    assert_non_null(m);
    assert_int_equal(built, 1);
    check_same_map(m, t[0], l1, C);
    assert_ptr_equal(shadow_map_cached(&c, t[0], l1, C, 1, &built), m);
    assert_int_equal(built, 0); /* the same tree and light: kept */
    m = shadow_map_cached(&c, t[0], l1, F, 2, &built);
    assert_int_equal(built, 1); /* finer cells asked for: made again */
    check_same_map(m, t[0], l1, F);
    assert_ptr_equal(shadow_map_cached(&c, t[0], l1, C, 2, &built), m);
    assert_int_equal(built, 0); /* coarser asked for: the finer one kept */
    check_same_map(m, t[0], l1, F);
    m = shadow_map_cached(&c, t[0], l2, C, 2, &built);
    assert_int_equal(built, 1);
    check_same_map(m, t[0], l2, C);
    m = shadow_map_cached(&c, t[0], l1z, C, 2, &built);
    assert_int_equal(built, 1);
    check_same_map(m, t[0], l1z, C);
    m = shadow_map_cached(&c, t[1], l1z, C, 2, &built);
    assert_int_equal(built, 1); /* another tree */
    check_same_map(m, t[1], l1z, C);
    shadow_map_cache_free(&c);
    assert_null(c.tree);
    shadow_map_cache_free(&c); /* twice: nothing kept, nothing freed */
    for (int k = 0; k < 2; k++)
        tree_util_free(t[k]);
}

/* The scene of the shadow tests: a floor and a wall meeting at a corner,
 * a ball above the floor, SCENE_LEVELS levels over a cube of 64. */
enum { SCENE_LEVELS = 6 };
static oct_tree *floor_wall_ball(void)
{
    shape sh[3] = {shape_plane(0, 0, 1, 20.5), shape_plane(1, 0, 0, 20.5),
                   shape_sphere(40, 40, 30, 8)};
    sh[0].lo[0] = 20;
    sh[1].lo[2] = 20;
    oct_tree *t = shapes_build(SCENE_LEVELS, 64.0, sh, 3, 1);
    assert_non_null(t);
    return t;
}

/* Shadow rays from the hits of a view, stopped where the map says: the
 * answers of the rays traced whole, never more steps. */
static void test_stopped_rays_same_answers(void **state)
{
    (void)state;
    enum { LEVELS = SCENE_LEVELS };
    oct_tree *t = floor_wall_ball();
    const double eye[3] = {150, 110, 120};
    static const double lights[][3] = {{0.3, 0.2, 0.93}, {-0.8, 0.1, 0.59}, {0.5, 0.7, 0.5},
                                       {0, 0, 1}};
    enum { NL = sizeof lights / sizeof lights[0] };
    shadow_map maps[2 * NL]; /* light l's with cells of voxels, then of 4 voxels */
    for (unsigned l = 0; l < 2 * NL; l++)
        assert_int_equal(shadow_map_build(t, lights[l % NL], l < NL ? SHADOW_MAP_FINE
                                                                     : SHADOW_MAP_COARSE,
                                          2, &maps[l]),
                         0);
    unsigned long rays = 0, blocked = 0, fewer = 0;
    for (unsigned impl = 0; impl < trace_impl_count; impl++)
        for (int refine = 0; refine <= 1; refine++) {
            const trace_opts o = {.split = LEVELS, .refine = refine};
            const trace_traverse_fn fn = trace_impls[impl].traverse;
            shadow_start st;
            st.near = 0;
            for (int y = 0; y < GRID_HITS_SIDE; y++)
                for (int x = 0; x < GRID_HITS_SIDE; x++) {
                    trace_hit h;
                    float n[3];
                    if (!grid_hit(t, &o, eye, x, y, &h, n))
                        continue;
                    if (!shadow_start_hit(t, &h, n, &st))
                        continue;
                    for (unsigned l = 0; l < 2 * NL; l++) {
                        uint64_t s0 = 0, s1 = 0;
                        const double *light = lights[l % NL];
                        const int b0 = shadow_blocked_from(t, &o, fn, &st, NULL, light,
                                                           INFINITY, &s0);
                        const int b1 = shadow_blocked_from(t, &o, fn, &st, &maps[l], light,
                                                           INFINITY, &s1);
                        assert_int_equal(b0, b1);
                        assert_true(s1 <= s0);
                        rays++;
                        blocked += (unsigned)b0;
                        fewer += s1 < s0;
                    }
                }
        }
    for (unsigned l = 0; l < 2 * NL; l++)
        shadow_map_free(&maps[l]);
    print_message("stopped rays: %lu rays, %lu blocked, %lu in fewer steps\n", rays, blocked,
                  fewer);
    assert_true(rays > 4000 && blocked > 200 && fewer > rays / 4);
    tree_util_free(t);
}

/* A shadow ray the map answers where it would start (shadow_lit_stored,
 * shadow_lit_at: no start search, no set-up) has the answer of the start
 * and the walk it skips: lit, from a start outside every occupied voxel;
 * with a map of another light, or of cells above the voxels, it is never
 * answered so. From voxel hits and from world points (the --exact path). */
static void test_lit_at_start_same_answers(void **state)
{
    (void)state;
    enum { LEVELS = SCENE_LEVELS };
    oct_tree *t = floor_wall_ball();
    const double eye[3] = {150, 110, 120};
    static const double lights[][3] = {{0.3, 0.2, 0.93}, {-0.8, 0.1, 0.59}, {0.5, 0.7, 0.5}};
    enum { NL = sizeof lights / sizeof lights[0] };
    const trace_opts o = {.split = LEVELS};
    const double vox = t->edge / (double)(1u << LEVELS);
    unsigned long asked = 0, answered[2] = {0, 0};
    for (unsigned up = SHADOW_MAP_FINE; up <= SHADOW_MAP_COARSE; up += 2)
        for (unsigned l = 0; l < NL; l++) {
            shadow_map m;
            assert_int_equal(shadow_map_build(t, lights[l], up, 2, &m), 0);
            shadow_start st;
            st.near = 0;
            for (int y = 0; y < GRID_HITS_SIDE; y++)
                for (int x = 0; x < GRID_HITS_SIDE; x++) {
                    trace_hit h;
                    float n[3], ns[3];
                    if (!grid_hit(t, &o, eye, x, y, &h, n))
                        continue;
                    oct_normal_decode(t->voxels[h.voxel] & OCT_VOXEL_NORMAL_MASK, ns);
                    double p[3]; /* a world point of the hit voxel, for the exact path */
                    for (int a = 0; a < 3; a++)
                        p[a] = t->origin[a] + ((double)h.xyz[a] + 0.25 + 0.125 * a) * vox;
                    for (int at = 0; at < 2; at++) {
                        const int lit = at ? shadow_lit_at(t, p, n, &m, lights[l])
                                           : shadow_lit_stored(t, &h, ns, n, &m, lights[l]);
                        assert_int_equal(at ? shadow_lit_at(t, p, n, &m, lights[(l + 1) % NL])
                                            : shadow_lit_stored(t, &h, ns, n, &m,
                                                                lights[(l + 1) % NL]),
                                         0);
                        asked++;
                        if (!lit)
                            continue;
                        answered[up == SHADOW_MAP_COARSE]++;
                        assert_int_equal(at ? shadow_start_at(t, p, n, &st)
                                            : shadow_start_stored(t, &h, ns, n, &st),
                                         1);
                        uint64_t s0 = 0, s1 = 0;
                        assert_int_equal(shadow_blocked_from(t, &o, NULL, &st, &m, lights[l],
                                                             INFINITY, &s0),
                                         0);
                        assert_int_equal(s0, 0); /* the map answers, no walk */
                        assert_int_equal(shadow_blocked_from(t, &o, NULL, &st, NULL, lights[l],
                                                             INFINITY, &s1),
                                         0);
                    }
                }
            shadow_map_free(&m);
        }
    print_message("lit where they start: %lu of %lu asked (voxel cells), %lu (4-voxel cells)\n",
                  answered[0], asked / 2, answered[1]);
    assert_true(answered[0] > asked / 8);
    assert_int_equal(answered[1], 0); /* only a map of voxels is asked */
    tree_util_free(t);
}

/* The map worth making: the fine one from one pixel a voxel on. */
static void test_map_resolution_rule(void **state)
{
    (void)state;
    uint32_t xyz[3][3] = {{1, 1, 1}, {5, 2, 7}, {3, 3, 3}};
    oct_tree *t = tree_util_simple(4, (const uint32_t(*)[3])xyz, 3);
    assert_non_null(t);
    assert_int_equal(shadow_map_up_for(t, 2), SHADOW_MAP_COARSE);
    assert_int_equal(shadow_map_up_for(t, 3), SHADOW_MAP_FINE);
    assert_int_equal(shadow_map_depth(t, SHADOW_MAP_FINE), 4);
    assert_int_equal(shadow_map_depth(t, SHADOW_MAP_COARSE), 2);
    assert_int_equal(shadow_map_depth(t, 7), 1); /* at least the root's children */
    tree_util_free(t);
}

/* grid_hit: every ray from an eye above a plane to a grid target hits the
 * plane with a normal facing the eye, and so does every ray from below. */
static void test_grid_hit_faces_eye(void **state)
{
    (void)state;
    enum { LEVELS = 6 };
    const shape sh[1] = {shape_plane(0, 0, 1, 21.0)};
    oct_tree *t = shapes_build(LEVELS, 64.0, sh, 1, 1);
    assert_non_null(t);
    const trace_opts o = {.split = LEVELS};
    const double eye[3] = {150, 110, 120}, away[3] = {150, 110, -120};
    unsigned hits = 0;
    for (int y = 0; y < GRID_HITS_SIDE; y++)
        for (int x = 0; x < GRID_HITS_SIDE; x++) {
            trace_hit h;
            float n[3];
            if (!grid_hit(t, &o, eye, x, y, &h, n))
                continue;
            hits++;
            assert_true(n[2] > 0.5f); /* the plane's normal, toward the eye above it */
            trace_hit g;
            float m[3];
            assert_int_equal(grid_hit(t, &o, away, x, y, &g, m), 1);
            assert_true(m[2] < -0.5f); /* the same plane seen from below */
        }
    assert_int_equal(hits, GRID_HITS_SIDE * GRID_HITS_SIDE);
    tree_util_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clear_t_bounds_every_voxel),
        cmocka_unit_test(test_far_heights_rounded_up),
        cmocka_unit_test(test_same_map_any_threads),
        cmocka_unit_test(test_cache_follows_tree_and_light),
        cmocka_unit_test(test_stopped_rays_same_answers),
        cmocka_unit_test(test_lit_at_start_same_answers),
        cmocka_unit_test(test_map_resolution_rule),
        cmocka_unit_test(test_grid_hit_faces_eye),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
