/* Tests for render/trace: the two-step traversal against a brute-force oracle
 * that slab-tests every voxel, for every split K, on random sparse trees and
 * deep single-path trees; degenerate rays; the step bound. Every cast runs
 * each traversal implementation built (tests/trace_oracle.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fenv.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "format/oct_normal.h"
#include "render/trace.h"
#include "render/trace_impl.h"
#include "bench/tree_util.h"
#include "tests/trace_oracle.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15u;
static uint64_t rng(void) { return rng_xorshift64star(&rng_state); }
static double urand(void) { return (double)(rng() >> 11) * 0x1p-53; }
static uint32_t irand(uint32_t n) { return (uint32_t)(rng() % n); }

/* --refine oracle, written from the rule of trace_refine_voxel without
 * the traversal: the voxels the ray occupies for a non-empty time [lo, hi)
 * in the order of lo; a run is a sequence of them each starting where the
 * previous one ends (no empty cell between). The ray hits the first voxel
 * where it is across the plane at entry from the side it had when its run
 * began (t = lo), or gets across before leaving (the plane time clamped to
 * [lo, hi]). Same arithmetic as the tracer. */
typedef struct span {
    double lo, hi;
    size_t i;
} span;

static int span_cmp(const void *a, const void *b)
{
    const span *x = a, *y = b;
    return x->lo < y->lo ? -1 : x->lo > y->lo;
}

static long oracle_refine(const trace_ray *r, const oct_tree *tree, const uint32_t (*vox)[3],
                          size_t n, double *t_out)
{
    const uint32_t lim = UINT32_C(1) << tree->levels;
    span *sp = malloc((n ? n : 1) * sizeof *sp);
    assert_non_null(sp);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        double lo = 0.0, hi = INFINITY;
        int ok = 1;
        for (int a = 0; a < 3 && ok; a++) {
            double k = (double)vox[i][a];
            if (!(r->active >> a & 1)) {
                double f = floor(r->o[a]);
                ok = vox[i][a] == (f >= (double)lim ? lim - 1 : (uint32_t)f);
                continue;
            }
            double en = trace_plane_time(r, a, r->sgn[a] > 0 ? k : k + 1);
            double ex = trace_plane_time(r, a, r->sgn[a] > 0 ? k + 1 : k);
            lo = en > lo ? en : lo;
            hi = ex < hi ? ex : hi;
        }
        if (hi > r->t_end)
            hi = r->t_end;
        if (ok && lo < hi)
            sp[m++] = (span){lo, hi, i};
    }
    qsort(sp, m, sizeof *sp, span_cmp);
    long best = -1;
    double best_t = INFINITY;
    int side = 0;
    for (size_t j = 0; j < m && best < 0; j++) {
        if (j == 0 || sp[j].lo != sp[j - 1].hi)
            side = 0; /* an empty stretch before this voxel */
        const size_t i = sp[j].i;
        /* the record of voxel i: attrs hold i + 1 */
        uint32_t rec = (uint32_t)i + 1;
        float nf[3];
        oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
        double num = oct_offset_decode((int8_t)(uint8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT)), den = 0.0;
        for (int a = 0; a < 3; a++) {
            num -= (double)nf[a] * (r->o[a] - ((double)vox[i][a] + 0.5));
            den += (double)nf[a] * r->d[a];
        }
        const double s_in = sp[j].lo * den - num, s_out = sp[j].hi * den - num;
        if (side == 0)
            side = s_in > 0.0 ? 1 : -1;
        if (s_in * side <= 0.0) {
            best = (long)i;
            best_t = sp[j].lo;
        } else if (s_out * side <= 0.0) {
            double tp = num / den;
            best = (long)i;
            best_t = tp < sp[j].lo ? sp[j].lo : tp > sp[j].hi ? sp[j].hi : tp;
        }
    }
    free(sp);
    *t_out = best_t;
    return best;
}

/* A grid-space coordinate of one of the kinds the plan asks for. */
static double pick_coord(uint32_t lim)
{
    switch (irand(6)) {
    case 0: return (double)irand(lim + 1);                       /* on a grid plane */
    case 1: return irand(2) ? 0.0 : (double)lim;                   /* on the root face */
    case 2: return -2.0 * lim + 5.0 * lim * urand();               /* anywhere, often out */
    case 3: return (double)irand(lim) + (double)irand(8) / 8.0;    /* dyadic inside */
    default: return (double)lim * urand();                         /* inside */
    }
}

static double pick_dir(void)
{
    switch (irand(10)) {
    case 0: return 0.0;
    case 1: return -0.0;
    case 2: return irand(2) ? 1e-30 : -1e-30;
    case 3: return irand(2) ? 1.0 : -1.0;
    case 4: return irand(2) ? 0.5 : -2.0;
    default: return 2.0 * urand() - 1.0;
    }
}

typedef struct check_stats {
    unsigned long rays, hits, traces;
} check_stats;

/* Casts eye+t*dir for every split and compares with the oracle. */
static void check_ray(const oct_tree *tree, const uint32_t (*vox)[3], size_t n, const double eye[3],
                      const double dir[3], unsigned k_min, check_stats *st)
{
    trace_ray r;
    int in = trace_setup(tree, eye, dir, &r);
    double ot = INFINITY;
    long want = in ? trace_oracle_first(&r, tree->levels, vox, n, &ot) : -1;
    st->rays++;
    if (want >= 0)
        st->hits++;
    double rt = INFINITY;
    long want_refined = in ? oracle_refine(&r, tree, vox, n, &rt) : -1;
    for (unsigned k = k_min; k <= tree->levels; k++) {
        for (int refine = 0; refine <= 1; refine++) {
            if (refine) {
                trace_opts ro = {k, 1, NULL};
                trace_hit rh;
                trace_cast_all(tree, &ro, eye, dir, &rh);
                st->traces++;
                assert_true(rh.steps <= trace_max_steps(tree->levels));
                assert_int_equal(rh.hit, want_refined >= 0);
                if (want_refined >= 0) {
                    assert_memory_equal(rh.xyz, vox[want_refined], sizeof rh.xyz);
                    assert_true(rh.t == r.t_base + rt);
                }
                continue;
            }
            trace_opts opts = {k, refine, NULL};
            trace_hit h;
            trace_cast_all(tree, &opts, eye, dir, &h);
            st->traces++;
            assert_true(h.steps <= trace_max_steps(tree->levels));
            if (want < 0) {
                if (h.hit)
                    print_error("L=%u K=%u eye %.17g %.17g %.17g dir %a %a %a: hit %u %u %u, oracle miss\n",
                                tree->levels, k, eye[0], eye[1], eye[2], dir[0], dir[1], dir[2],
                                h.xyz[0], h.xyz[1], h.xyz[2]);
                assert_false(h.hit);
                assert_true(isinf(h.t));
                continue;
            }
            if (!h.hit || memcmp(h.xyz, vox[want], sizeof h.xyz) != 0)
                print_error("L=%u K=%u eye %.17g %.17g %.17g dir %a %a %a: got %d %u %u %u want %u %u %u\n",
                            tree->levels, k, eye[0], eye[1], eye[2], dir[0], dir[1], dir[2], h.hit,
                            h.xyz[0], h.xyz[1], h.xyz[2], vox[want][0], vox[want][1], vox[want][2]);
            assert_true(h.hit);
            assert_memory_equal(h.xyz, vox[want], sizeof h.xyz);
            /* attrs carry the list index + 1: the voxel index is right too */
            assert_int_equal(tree->voxels[h.voxel], (uint32_t)want + 1);
            double t = r.t_base + ot;
            assert_true(h.t == t); /* exactly the entry time under the tie rule */
        }
    }
}

/* Random sparse tree with unique voxels; attrs = index + 1. */
static oct_tree *random_tree(unsigned levels, double density, const double origin[3], double edge,
                             uint32_t (**vox_out)[3], size_t *n_out)
{
    const uint32_t lim = UINT32_C(1) << levels;
    size_t cells = (size_t)lim * lim * lim;
    size_t want = (size_t)(density * (double)cells);
    if (want > 3000)
        want = 3000;
    uint8_t *seen = calloc(cells, 1);
    uint32_t (*vox)[3] = calloc(want + 1, sizeof *vox);
    uint32_t *attrs = calloc(want + 1, sizeof *attrs);
    assert_non_null(seen);
    assert_non_null(vox);
    assert_non_null(attrs);
    size_t n = 0;
    for (size_t tries = 0; n < want && tries < 20 * want; tries++) {
        uint32_t x = irand(lim), y = irand(lim), z = irand(lim);
        size_t c = ((size_t)z * lim + y) * lim + x;
        if (seen[c])
            continue;
        seen[c] = 1;
        vox[n][0] = x;
        vox[n][1] = y;
        vox[n][2] = z;
        attrs[n] = (uint32_t)n + 1;
        n++;
    }
    oct_tree *t = tree_util_build(levels, origin, edge, (const uint32_t(*)[3])vox, n, attrs, NULL,
                                  1, NULL);
    assert_non_null(t);
    assert_int_equal(t->voxel_count, n);
    free(seen);
    free(attrs);
    *vox_out = vox;
    *n_out = n;
    return t;
}

static void test_random_trees_vs_oracle(void **state)
{
    (void)state;
    feenableexcept(FE_INVALID);
    static const double densities[] = {0.0, 0.002, 0.02, 0.1, 0.4, 1.0};
    check_stats st = {0, 0, 0};
    for (unsigned levels = 1; levels <= 6; levels++) {
        for (unsigned ti = 0; ti < 18; ti++) {
            const double origin[3] = {ti % 2 ? -1.5 : 0.0, ti % 3 ? 2.0 : 0.0, 0.25};
            const double edge = ti % 4 ? 2.0 : 1.0;
            uint32_t(*vox)[3];
            size_t n;
            oct_tree *t = random_tree(levels, densities[ti % 6], origin, edge, &vox, &n);
            const uint32_t lim = UINT32_C(1) << levels;
            for (unsigned ri = 0; ri < 1000; ri++) {
                double g[3], dir[3], eye[3];
                do {
                    for (int a = 0; a < 3; a++)
                        dir[a] = pick_dir();
                } while (dir[0] == 0 && dir[1] == 0 && dir[2] == 0);
                for (int a = 0; a < 3; a++) {
                    g[a] = pick_coord(lim);
                    eye[a] = origin[a] + g[a] * edge / (double)lim;
                }
                /* a third of the rays aim exactly at a voxel corner/edge/centre */
                if (ri % 3 == 0) {
                    double tgt[3];
                    for (int a = 0; a < 3; a++) {
                        tgt[a] = (double)irand(lim + 1) + (irand(2) ? 0.5 : 0.0);
                        dir[a] = tgt[a] - g[a];
                    }
                    if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0)
                        dir[2] = 1.0;
                }
                check_ray(t, (const uint32_t(*)[3])vox, n, eye, dir, 0, &st);
            }
            tree_util_free(t);
            free(vox);
        }
    }
    fedisableexcept(FE_INVALID);
    print_message("trace: %lu rays, %lu hits, %lu traversals compared\n", st.rays, st.hits,
                  st.traces);
    assert_true(st.hits > st.rays / 10);
}

/* Levels 16-20: a few voxels around one random point, rays from far away
 * aimed at its centre, faces, edges and corners. */
static void test_deep_single_path(void **state)
{
    (void)state;
    feenableexcept(FE_INVALID);
    check_stats st = {0, 0, 0};
    for (unsigned levels = 16; levels <= 20; levels++) {
        const uint32_t lim = UINT32_C(1) << levels;
        for (unsigned ti = 0; ti < 6; ti++) {
            uint32_t c[3] = {1 + irand(lim - 2), 1 + irand(lim - 2), 1 + irand(lim - 2)};
            uint32_t vox[27][3], attrs[27];
            size_t n = 0;
            for (int dz = -1; dz <= 1; dz++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++)
                        if ((dx == 0 && dy == 0 && dz == 0) || irand(3) == 0) {
                            vox[n][0] = (uint32_t)((int)c[0] + dx);
                            vox[n][1] = (uint32_t)((int)c[1] + dy);
                            vox[n][2] = (uint32_t)((int)c[2] + dz);
                            attrs[n] = (uint32_t)n + 1;
                            n++;
                        }
            const double origin[3] = {0, 0, 0};
            oct_tree *t = tree_util_build(levels, origin, 1.0, (const uint32_t(*)[3])vox, n,
                                          attrs, NULL, 1, NULL);
            assert_non_null(t);
            for (unsigned ri = 0; ri < 400; ri++) {
                double tg[3], eye[3], dir[3];
                for (int a = 0; a < 3; a++) {
                    tg[a] = (double)c[a] + (double)irand(5) * 0.5 - 0.5; /* centre/face/edge/corner */
                    double e;
                    switch (irand(3)) {
                    case 0: e = tg[a]; break;                               /* axis-aligned */
                    case 1: e = -1e6 * lim + 3e6 * lim * urand(); break;   /* far */
                    default: e = (double)lim * urand(); break;
                    }
                    eye[a] = e / (double)lim;
                    dir[a] = (tg[a] - e) / (double)lim;
                }
                if (dir[0] == 0 && dir[1] == 0 && dir[2] == 0)
                    dir[0] = 1.0;
                /* voxel-by-voxel walks at 2^20 cost 3 M steps a ray: all
                 * splits on a few rays, the coarse-heavy ones on the rest */
                check_ray(t, (const uint32_t(*)[3])vox, n, eye, dir, ri % 100 ? levels - 5 : 0, &st);
            }
            tree_util_free(t);
        }
    }
    fedisableexcept(FE_INVALID);
    print_message("trace deep: %lu rays, %lu hits\n", st.rays, st.hits);
    assert_true(st.hits > st.rays / 2);
}

static void test_empty_tree_and_degenerate_rays(void **state)
{
    (void)state;
    oct_tree *t = tree_util_simple(4, NULL, 0);
    assert_non_null(t);
    trace_opts o = {2, 0, NULL};
    trace_hit h;
    const double eye[3] = {0.5, 0.5, -1}, dir[3] = {0, 0, 1};
    assert_int_equal(trace_cast_all(t, &o, eye, dir, &h), 0);
    assert_int_equal(h.steps, 0);
    tree_util_free(t);

    static const uint32_t one[1][3] = {{0, 0, 0}};
    t = tree_util_simple(1, one, 1);
    const double zero[3] = {0, 0, 0}, nan3[3] = {NAN, 0, 1}, inf3[3] = {INFINITY, 0, 0};
    assert_int_equal(trace_cast_all(t, &o, eye, zero, &h), 0);
    assert_int_equal(trace_cast_all(t, &o, eye, nan3, &h), 0);
    assert_int_equal(trace_cast_all(t, &o, inf3, dir, &h), 0);
    /* eye inside the occupied voxel: t = 0 */
    const double in[3] = {0.25, 0.25, 0.25};
    assert_int_equal(trace_cast_all(t, &o, in, dir, &h), 1);
    assert_true(h.t == 0.0);
    /* along the face x = 0.5 between voxel 0 and voxel 1 (x+): voxel x = 1, empty */
    const double face[3] = {0.5, 0.25, -1};
    assert_int_equal(trace_cast_all(t, &o, face, dir, &h), 0);
    /* along the root's lower face x = 0: voxel x = 0, hit at t = 1 */
    const double lowface[3] = {0.0, 0.25, -1};
    assert_int_equal(trace_cast_all(t, &o, lowface, dir, &h), 1);
    assert_true(h.t == 1.0);
    /* eye at 1e30: no NaN, finite t or miss */
    const double far[3] = {1e30, 1e30, 1e30}, back[3] = {-1, -1, -1};
    feenableexcept(FE_INVALID);
    trace_cast_all(t, &o, far, back, &h);
    fedisableexcept(FE_INVALID);
    assert_true(!h.hit || isfinite(h.t));
    tree_util_free(t);
}

static void test_tree_util_layout(void **state)
{
    (void)state;
    /* two voxels in opposite corners of a level-2 grid, given out of order
     * and duplicated */
    static const uint32_t v[3][3] = {{3, 3, 3}, {0, 0, 0}, {3, 3, 3}};
    oct_tree *t = tree_util_simple(2, v, 3);
    assert_non_null(t);
    assert_int_equal(t->voxel_count, 2);
    assert_int_equal(t->node_count[0], 1);
    assert_int_equal(t->node_count[1], 2);
    assert_int_equal(oct_node_mask(t->groups[0], 0), 0x81);
    assert_int_equal(oct_node_mask(t->groups[1], 0), 0x01);
    assert_int_equal(oct_node_mask(t->groups[1], 1), 0x80);
    assert_int_equal(oct_child_index(t->groups[0], 0, 7), 1);
    assert_int_equal(oct_child_index(t->groups[1], 1, 7), 1);
    tree_util_free(t);
}

/* trace_clip: a ray started at any plane time before its hit (or at the
 * hit's own entry time) meets the same voxel at the same t, bits and all, as
 * the whole ray: rays full of exact ties (dyadic eyes, direction components
 * in {0, +-1, +-2}), every split, plain and --refine. */
static void test_clip_same_hit(void **state)
{
    (void)state;
    unsigned long checked = 0, steps_whole = 0, steps_clipped = 0;
    for (int tr = 0; tr < 16; tr++) {
        const unsigned L = 2 + irand(5);
        const uint32_t N = 1u << L;
        const size_t n = 1 + irand(N * N / 2 + 1);
        uint32_t(*xyz)[3] = malloc(n * sizeof *xyz);
        uint32_t *attr = malloc(n * sizeof *attr);
        assert_non_null(xyz);
        assert_non_null(attr);
        const size_t m = tree_util_distinct_voxels(n, 0, N, &rng_state, xyz);
        for (size_t i = 0; i < m; i++) {
            const double nr[3] = {(double)irand(5) - 2.0, (double)irand(5) - 2.0, 1.0};
            attr[i] = oct_voxel_pack(nr, ((double)irand(200) - 100.0) / 128.0);
        }
        const double origin[3] = {0, 0, 0};
        oct_tree *t = tree_util_build(L, origin, (double)N, (const uint32_t(*)[3])xyz, m, attr, NULL,
                                      1, NULL);
        assert_non_null(t);
        for (int ray = 0; ray < 160; ray++) {
            double eye[3], dir[3];
            for (int a = 0; a < 3; a++) {
                eye[a] = (double)irand(4 * (N + 4)) / 4.0 - 2.0;
                dir[a] = (double)irand(5) - 2.0;
            }
            trace_ray r0;
            if (!trace_setup(t, eye, dir, &r0))
                continue;
            trace_opts plain = {L, 0, NULL};
            trace_hit hp;
            if (!trace_prepared_all(t, &plain, &r0, &hp))
                continue;
            double starts[3 * 65 + 1];
            int ns = 0;
            for (int a = 0; a < 3; a++)
                for (uint32_t k = 0; k <= N && (r0.active >> a & 1); k++) {
                    const double tl = trace_plane_time(&r0, a, (double)k);
                    if (tl >= 0.0 && r0.t_base + tl <= hp.t)
                        starts[ns++] = r0.t_base + tl;
                }
            starts[ns++] = hp.t;
            for (unsigned K = 0; K <= L; K++)
                for (int refine = 0; refine <= 1; refine++) {
                    const trace_opts op = {K, refine, NULL};
                    trace_hit h0;
                    trace_prepared_all(t, &op, &r0, &h0);
                    for (int c = 0; c < ns; c++) {
                        trace_ray r = r0;
                        assert_true(trace_clip(&r, starts[c], INFINITY));
                        trace_hit h1;
                        trace_prepared_all(t, &op, &r, &h1);
                        assert_int_equal(h1.hit, h0.hit);
                        assert_true(h1.voxel == h0.voxel);
                        assert_true(h1.t == h0.t);
                        assert_true(h1.steps <= h0.steps);
                        steps_whole += h0.steps;
                        steps_clipped += h1.steps;
                        checked++;
                    }
                }
        }
        tree_util_free(t);
        free(xyz);
        free(attr);
    }
    print_message("clip: %lu clipped traversals, all the same hit; %lu steps against %lu whole\n",
                  checked, steps_clipped, steps_whole);
    assert_true(checked > 5000);
    assert_true(steps_clipped < steps_whole * 3 / 4); /* they do start later */
}

/* trace_ray_anchored: rays whose start points lie in a box begin at the
 * deepest occupied cell holding the box and meet the same voxel at the same
 * t, with the same step count and end cell, as from the root. Groups of
 * rays share one box (the hull of their start points, grown by 2^-10
 * voxel, as the renderer grows its boxes); starts at plane times put start
 * points on cell faces, where the box must straddle. */
static void test_anchored_same_hit(void **state)
{
    (void)state;
    unsigned long checked = 0, anchored = 0, depth_sum = 0;
    unsigned deepest = 0;
    for (int tr = 0; tr < 24; tr++) {
        const unsigned L = 3 + irand(6);
        const uint32_t N = 1u << L;
        const size_t n = 1 + irand(N * N + 1);
        uint32_t(*xyz)[3] = malloc(n * sizeof *xyz);
        uint32_t *attr = malloc(n * sizeof *attr);
        assert_non_null(xyz);
        assert_non_null(attr);
        /* clustered off the root's mid-planes, so that occupied cells nest
         * deeply */
        const uint32_t base = N / 8 + irand(N / 2 + 1);
        const size_t m = tree_util_distinct_voxels(n, base, N / 4 + 1, &rng_state, xyz);
        for (size_t i = 0; i < m; i++)
            attr[i] = (uint32_t)i + 1;
        const double origin[3] = {0, 0, 0};
        oct_tree *t = tree_util_build(L, origin, (double)N, (const uint32_t(*)[3])xyz, m, attr, NULL,
                                      1, NULL);
        assert_non_null(t);
        for (int group = 0; group < 120; group++) {
            const int group_size = 1 + (int)irand(6);
            const double spread = irand(2) ? 0.02 : 0.001;
            /* a few rays from one eye with nearby directions, started at one
             * distance (a plane time of the first ray, or anywhere) */
            double eye[3], dir0[3];
            for (int a = 0; a < 3; a++) {
                eye[a] = irand(2) ? (double)irand(4 * (N + 4)) / 4.0 - 2.0
                                  : -2.0 * N + 5.0 * N * urand();
                dir0[a] = irand(3) ? 2.0 * urand() - 1.0 : (double)irand(5) - 2.0;
            }
            trace_ray r0;
            if (!trace_setup(t, eye, dir0, &r0))
                continue;
            /* start at a plane time, anywhere, at the whole ray's hit or
             * shortly before it (deep in occupied cells) */
            double t_start;
            const int a0 = (int)irand(3);
            const trace_opts whole = {L, 0, NULL};
            trace_hit hw;
            const int how = (int)irand(4);
            if (how == 0 && (r0.active >> a0 & 1)) {
                const double tl = trace_plane_time(&r0, a0, (double)irand(N + 1));
                if (!(tl >= 0.0 && tl < r0.t_end))
                    continue;
                t_start = r0.t_base + tl;
            } else if (how >= 2 && trace_prepared_all(t, &whole, &r0, &hw)) {
                t_start = how == 2 ? hw.t : hw.t - urand() * 2.0 * (hw.t - r0.t_base);
                if (!(t_start >= r0.t_base))
                    t_start = r0.t_base;
            } else {
                t_start = r0.t_base + urand() * (r0.t_end);
            }
            trace_ray rays[6];
            int nr = 0;
            double lo[3] = {INFINITY, INFINITY, INFINITY};
            double hi[3] = {-INFINITY, -INFINITY, -INFINITY};
            for (int k = 0; k < group_size; k++) {
                double dir[3];
                for (int a = 0; a < 3; a++)
                    dir[a] = dir0[a] + (k ? (urand() - 0.5) * spread : 0.0);
                trace_ray r;
                if (!trace_setup(t, eye, dir, &r) || !trace_clip(&r, t_start, INFINITY))
                    continue;
                for (int a = 0; a < 3; a++) {
                    const double p = r.o[a] + r.t_start * r.d[a];
                    lo[a] = p < lo[a] ? p : lo[a];
                    hi[a] = p > hi[a] ? p : hi[a];
                }
                rays[nr++] = r;
            }
            if (!nr)
                continue;
            for (int a = 0; a < 3; a++) {
                lo[a] -= 0x1p-10;
                hi[a] += 0x1p-10;
            }
            trace_anchor an;
            trace_anchor_find(t, lo, hi, &an);
            anchored += an.depth > 0;
            depth_sum += an.depth;
            deepest = an.depth > deepest ? an.depth : deepest;
            for (int k = 0; k < nr; k++)
                for (int refine = 0; refine <= 1; refine++) {
                    const trace_opts op = {irand(2) ? L : irand(L + 1), refine, NULL};
                    trace_hit h0, h1;
                    trace_prepared_all(t, &op, &rays[k], &h0);
                    trace_anchored_all(t, &op, &rays[k], &an, &h1);
                    assert_int_equal(h1.hit, h0.hit);
                    assert_true(h1.voxel == h0.voxel || !h0.hit);
                    assert_true(h1.t == h0.t || (isinf(h1.t) && isinf(h0.t)));
                    assert_int_equal(h1.steps, h0.steps);
                    assert_memory_equal(h1.xyz, h0.xyz, sizeof h0.xyz);
                    checked++;
                }
        }
        tree_util_free(t);
        free(xyz);
        free(attr);
    }
    print_message("anchored: %lu traversals the same, %lu groups anchored below the root "
                  "(mean depth %.2f, deepest %u)\n",
                  checked, anchored, anchored ? (double)depth_sum / (double)anchored : 0.0,
                  deepest);
    assert_true(checked > 2000);
    assert_true(anchored > 100 && deepest >= 4); /* the anchors do go below the root */
}

int main(void)
{
    /* TEST_SEED=N replays another deterministic stream of rays and trees */
    const char *seed = getenv("TEST_SEED");
    if (seed && *seed)
        rng_state ^= strtoull(seed, NULL, 10) * 0x9e3779b97f4a7c15ULL + 1;
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tree_util_layout),
        cmocka_unit_test(test_empty_tree_and_degenerate_rays),
        cmocka_unit_test(test_random_trees_vs_oracle),
        cmocka_unit_test(test_deep_single_path),
        cmocka_unit_test(test_clip_same_hit),
        cmocka_unit_test(test_anchored_same_hit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
