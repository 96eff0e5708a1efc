/* Stress tests for render/trace against an exact oracle (TESTPLAN.md section
 * 3, issue 6).
 *
 * The oracle does not use trace_plane_time: it slab-tests every voxel of the
 * list in exact rational arithmetic on the ray's grid-space start point o and
 * direction d (both dyadic: o a multiple of 2^-16, d a double), applying
 * trace.h's tie rule (half-open occupancy per axis, zero axes in floor(o),
 * the root's upper face in voxel N-1). A plane crossing time is
 * (k - o_a) / d_a; two are compared by cross-multiplication in __int128.
 *
 * Which rays must match exactly. The traversal rounds T = (k - o) * (1/d);
 * it is exact when 1/d is exact, i.e. d a power of two. The exact-class rays
 * therefore use direction components 0, -0, +-2^j (j in -3..3; down to -30
 * for near-axis rays starting inside), or one tiny
 * magnitude c in {1e-12, 1e-30} shared by all tiny axes of the ray (its
 * crossings lie beyond the cube, or compare against each other through the
 * same rounded 1/c, which keeps their order). For these rays the traversal's
 * first hit, for every split K, must equal the oracle's, and its t must be
 * the exact entry time. General rays (random directions, corner-aimed rays
 * from random points) may differ from the exact answer only within the
 * documented rounding (2 ulp of T): a mismatch is accepted only when both
 * voxels are within 2^-40 relative of the exact ray at the same time, and
 * such near ties are counted and bounded.
 *
 * Watertightness and the step bound: tests/test_trace_watertight.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <fenv.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/trace.h"
#include "bench/tree_util.h"
#include "tests/exact_ray_oracle.h"
#include "tests/sanitized.h"
#include "tests/trace_oracle.h"

/* Rays in the exact-class run on random trees (levels 1-8) and deep trees. */
#define RANDOM_TREE_RAYS (SANITIZED ? 240000ul : 960000ul)
#define DEEP_RAYS (SANITIZED ? 25000ul : 100000ul)
#define GENERAL_RAYS (SANITIZED ? 50000ul : 200000ul)

static uint64_t rng_state = 0x243f6a8885a308d3u;
static uint64_t rng(void) { return rng_xorshift64star(&rng_state); }
static double urand(void) { return (double)(rng() >> 11) * 0x1p-53; }
static uint32_t irand(uint32_t n) { return (uint32_t)(rng() % n); }

/* ---- Long-double oracle with the documented tolerance (general rays) ---- */

/* [tin, tout] of voxel v for the ray (o, d) in long double; zero axes
 * exactly as in the tie rule. Returns 0 if the voxel is off a zero axis. */
static int ld_voxel(const double o[3], const double d[3], uint32_t lim, const uint32_t v[3],
                    long double *tin, long double *tout)
{
    long double lo = 0, hi = INFINITY;
    for (int a = 0; a < 3; a++) {
        double inv = 1.0 / d[a];
        if (d[a] == 0.0 || !isfinite(inv)) {
            if (o[a] < 0 || o[a] > (double)lim)
                return 0;
            double f = floor(o[a]);
            uint32_t k = f >= (double)lim ? lim - 1 : (uint32_t)f;
            if (v[a] != k)
                return 0;
            continue;
        }
        long double t0 = ((long double)v[a] - o[a]) / d[a];
        long double t1 = ((long double)v[a] + 1 - o[a]) / d[a];
        long double en = t0 < t1 ? t0 : t1, ex = t0 < t1 ? t1 : t0;
        if (en > lo)
            lo = en;
        if (ex < hi)
            hi = ex;
    }
    *tin = lo;
    *tout = hi;
    return 1;
}

/* ---- Trees and rays ------------------------------------------------------ */

typedef struct stats {
    unsigned long rays, hits, traces, trees, near_ties, skipped, aimed_traces, aimed_ties;
    uint32_t max_steps_seen;
} stats;

/* Random sparse tree; attrs[i] = i + 1 so a hit names its list entry. */
static oct_tree *random_tree(unsigned levels, size_t want, const double origin[3], double edge,
                             uint32_t (**vox_out)[3], size_t *n_out)
{
    const uint32_t lim = UINT32_C(1) << levels;
    const uint64_t cells = (uint64_t)lim * lim * lim;
    if (want > cells)
        want = (size_t)cells;
    uint32_t(*vox)[3] = calloc(want + 1, sizeof *vox);
    uint32_t *attrs = calloc(want + 1, sizeof *attrs);
    assert_non_null(vox);
    assert_non_null(attrs);
    size_t n = 0;
    for (size_t tries = 0; n < want && tries < 50 * want + 100; tries++) {
        uint32_t x = irand(lim), y = irand(lim), z = irand(lim);
        int dup = 0;
        for (size_t j = 0; j < n && !dup; j++)
            dup = vox[j][0] == x && vox[j][1] == y && vox[j][2] == z;
        if (dup)
            continue;
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
    free(attrs);
    *vox_out = vox;
    *n_out = n;
    return t;
}

/* A dyadic coordinate in [0, lim] of the kind the plan asks for. */
static double pick_target_coord(uint32_t lim, uint32_t near)
{
    switch (irand(7)) {
    case 0: return (double)irand(lim + 1);                             /* grid plane */
    case 1: return irand(2) ? 0.0 : (double)lim;                        /* root face */
    case 2: return (double)irand(lim) + 0.5;                            /* voxel middle */
    case 3: return (double)near + irand(2);                             /* plane of a voxel */
    case 4: return (double)near + (double)(1 + irand(255)) / 256.0;     /* inside a voxel */
    default: return ldexp(floor(ldexp(urand() * lim, FRAC_BITS)), -FRAC_BITS);
    }
}

/* Builds one exact-class ray aimed at point P (grid space); fills o and d.
 * Returns 1 if the ray is in the oracle's range. */
static int exact_class_ray(uint32_t lim, const double P[3], double o[3], double d[3])
{
    int kind[3], any_pow2 = 0;
    const double c = irand(2) ? 1e-12 : 1e-30;
    for (int a = 0; a < 3; a++) {
        uint32_t r = irand(20);
        kind[a] = r < 4 ? 0 : r < 7 ? 2 : 1; /* 0 zero, 1 power of two, 2 tiny */
        if (kind[a] == 0)
            d[a] = irand(2) ? 0.0 : -0.0;
        else if (kind[a] == 1)
            d[a] = (irand(2) ? 1 : -1) * ldexp(1.0, (int)irand(7) - 3);
        else
            d[a] = (irand(2) ? c : -c) * (double)lim; /* tiny in world units */
        any_pow2 |= kind[a] == 1;
    }
    if (!any_pow2 && irand(4)) {
        int a = (int)irand(3);
        kind[a] = 1;
        d[a] = irand(2) ? 1.0 : -1.0;
        any_pow2 = 1;
    }
    if (!any_pow2 && kind[0] == 0 && kind[1] == 0 && kind[2] == 0) {
        kind[2] = 1;
        d[2] = -1.0;
        any_pow2 = 1;
    }
    /* how far back along the ray the start is */
    double tb = 0.0, dmax = 0.0;
    for (int a = 0; a < 3; a++)
        if (kind[a] == 1)
            dmax = fmax(dmax, fabs(d[a]));
    if (any_pow2) {
        switch (irand(6)) {
        case 0: tb = 0.0; break;                                                /* start at P */
        case 1: tb = ldexp(floor(urand() * 512.0), -8) * (double)lim; break;    /* near */
        case 2: tb = 0x1p20 * (double)lim * (1.0 + (double)irand(256) / 256) / dmax; break; /* 10^6 cubes */
        case 3: {                                                               /* on a root face */
            int a;
            do
                a = (int)irand(3);
            while (kind[a] != 1);
            double face = irand(2) ? 0.0 : (double)lim;
            tb = (P[a] - face) / d[a];
            break;
        }
        case 4: tb = -ldexp(floor(urand() * 64.0), -4); break; /* past P */
        default: tb = ldexp(floor(urand() * 64.0), -6); break;
        }
    }
    /* near-axis rays: one component 2^-4 .. 2^-30, from inside only (a
     * re-based start is rounded, and 1/d would amplify that rounding) */
    if (tb == 0.0 && irand(3) == 0) {
        int a = (int)irand(3);
        if (kind[a] == 1)
            d[a] = (d[a] < 0 ? -1 : 1) * ldexp(1.0, -4 - (int)irand(27));
    }
    for (int a = 0; a < 3; a++) {
        if (kind[a] == 1)
            o[a] = P[a] - tb * d[a];
        else if (kind[a] == 0 && irand(16) == 0)
            o[a] = irand(2) ? -1.0 - irand(4) : (double)lim + 1.0 + irand(4); /* off the cube */
        else
            o[a] = P[a];
    }
    return 1;
}

/* Maps grid-space (o, d) to world (eye, dir) for tree t; 0 if not exact. */
static int to_world(const oct_tree *t, const double o[3], const double d[3], double eye[3],
                    double dir[3])
{
    const double lim = ldexp(1.0, (int)t->levels);
    const double h = t->edge / lim, scale = lim / t->edge;
    for (int a = 0; a < 3; a++) {
        eye[a] = t->origin[a] + o[a] * h;
        dir[a] = d[a] * h;
        if ((eye[a] - t->origin[a]) * scale != o[a] || dir[a] * scale != d[a])
            return 0;
        if (d[a] == 0.0 && signbit(d[a]) != signbit(dir[a]))
            return 0;
    }
    return 1;
}

/* Exact number of unit DDA steps before the hit (or the exit) for a ray
 * whose active axes are all powers of two: the distinct plane crossing times
 * in (0, t_stop], in (0, t_stop) on a miss. All T are exact doubles. */
static uint32_t exact_unit_steps(const double o[3], const double d[3], double t_stop, int hit)
{
    double next[3];
    int64_t k[3];
    for (int a = 0; a < 3; a++) {
        next[a] = INFINITY;
        if (d[a] == 0.0)
            continue;
        /* first plane strictly after o in the direction of travel */
        double f = d[a] > 0 ? floor(o[a]) + 1 : ceil(o[a]) - 1;
        k[a] = (int64_t)f;
        next[a] = (f - o[a]) / d[a];
    }
    uint32_t steps = 0;
    for (;;) {
        double t = fmin(next[0], fmin(next[1], next[2]));
        if (hit ? !(t <= t_stop) : !(t < t_stop))
            return steps;
        steps++;
        for (int a = 0; a < 3; a++)
            if (next[a] == t) {
                k[a] += d[a] > 0 ? 1 : -1;
                next[a] = ((double)k[a] - o[a]) / d[a];
            }
    }
}

/* Traces the exact-class ray for the splits [k_lo, k_hi] and compares. */
static void check_exact(const oct_tree *t, const uint32_t (*vox)[3], size_t n, const double o[3],
                        const double d[3], unsigned k_lo, unsigned k_hi, int count_steps, stats *st)
{
    double eye[3], dir[3];
    xray xr;
    if (!to_world(t, o, d, eye, dir) || !xray_init(&xr, o, d)) {
        st->skipped++;
        return;
    }
    const uint32_t lim = UINT32_C(1) << t->levels;
    long double want_t;
    long want = oracle_exact(&xr, t->levels, vox, n, &want_t);
    st->rays++;
    st->hits += want >= 0;
    for (unsigned k = k_lo; k <= k_hi; k++) {
        trace_opts opts = {k, 0};
        trace_hit h;
        trace_cast_all(t, &opts, eye, dir, &h);
        st->traces++;
        if (h.steps > st->max_steps_seen)
            st->max_steps_seen = h.steps;
        int ok = h.steps <= trace_max_steps(t->levels);
        if (want < 0)
            ok = ok && !h.hit && isinf(h.t);
        else
            ok = ok && h.hit && memcmp(h.xyz, vox[want], sizeof h.xyz) == 0 &&
                 t->voxels[h.voxel] == (uint32_t)want + 1 &&
                 fabsl((long double)h.t - want_t) <= 1e-12L * (fabsl(want_t) + lim);
        if (ok && count_steps && k == 0 && (d[0] == 0 || fabs(d[0]) >= 0.125) &&
            (d[1] == 0 || fabs(d[1]) >= 0.125) && (d[2] == 0 || fabs(d[2]) >= 0.125)) {
            /* K = 0: every step is one voxel; the count is exact */
            trace_ray r;
            if (trace_setup(t, eye, dir, &r) && r.t_base == 0.0) {
                double stop = want >= 0 ? (double)want_t : r.t_end;
                uint32_t es = exact_unit_steps(o, d, stop, want >= 0);
                if (es != h.steps) {
                    print_error("steps %u, exact %u\n", h.steps, es);
                    ok = 0;
                }
            }
        }
        if (!ok) {
            print_error("L=%u K=%u o=(%a %a %a) d=(%a %a %a)\n  trace: hit %d (%u %u %u) t=%.17g "
                        "steps %u\n",
                        t->levels, k, o[0], o[1], o[2], d[0], d[1], d[2], h.hit, h.xyz[0],
                        h.xyz[1], h.xyz[2], h.t, h.steps);
            if (want >= 0)
                print_error("  oracle: (%u %u %u) t=%.17Lg\n", vox[want][0], vox[want][1],
                            vox[want][2], want_t);
            else
                print_error("  oracle: miss\n");
            fail();
        }
    }
}

static void test_exact_random_trees(void **state)
{
    (void)state;
    feenableexcept(FE_INVALID);
    stats st = {0};
    static const size_t sizes[] = {1, 3, 12, 40};
    const unsigned trees_per_level = 24;
    const unsigned long rays_per_tree = RANDOM_TREE_RAYS / (8 * trees_per_level);
    for (unsigned levels = 1; levels <= 8; levels++) {
        const uint32_t lim = UINT32_C(1) << levels;
        for (unsigned ti = 0; ti < trees_per_level; ti++) {
            const double origin[3] = {ti % 2 ? -1.5 : 0.0, ti % 3 ? 2.0 : 0.0, 0.25};
            const double edge = ti % 4 ? 2.0 : 1.0 / 1024;
            size_t want = sizes[ti % 4] * (levels <= 2 ? 1 : 1 + ti % 3);
            if (levels <= 2 && ti % 5 == 0)
                want = lim * lim * lim; /* full */
            uint32_t(*vox)[3];
            size_t n;
            oct_tree *t = random_tree(levels, want, origin, edge, &vox, &n);
            st.trees++;
            for (unsigned long ri = 0; ri < rays_per_tree; ri++) {
                const uint32_t *near = vox[irand((uint32_t)n)];
                double P[3], o[3], d[3];
                for (int a = 0; a < 3; a++)
                    P[a] = ri % 2 ? pick_target_coord(lim, near[a]) /* anywhere */
                                  : (double)near[a] + (double)irand(5) / 4; /* on its cube */
                exact_class_ray(lim, P, o, d);
                check_exact(t, (const uint32_t(*)[3])vox, n, o, d, 0, levels, 1, &st);
            }
            tree_util_free(t);
            free(vox);
        }
    }
    fedisableexcept(FE_INVALID);
    print_message("exact, levels 1-8: %lu trees, %lu rays (%lu hits), %lu traversals, "
                  "%lu skipped, max steps %u\n",
                  st.trees, st.rays, st.hits, st.traces, st.skipped, st.max_steps_seen);
    assert_true(st.hits > st.rays / 5);
    assert_true(st.skipped < st.rays / 100);
}

/* Levels 16-20: a cluster of voxels around one random point plus scattered
 * ones; rays aimed at the cluster's corners, edges and faces. */
static void test_exact_deep_trees(void **state)
{
    (void)state;
    feenableexcept(FE_INVALID);
    stats st = {0};
    const unsigned trees_per_level = 8;
    const unsigned long rays_per_tree = DEEP_RAYS / (5 * trees_per_level);
    for (unsigned levels = 16; levels <= 20; levels++) {
        const uint32_t lim = UINT32_C(1) << levels;
        for (unsigned ti = 0; ti < trees_per_level; ti++) {
            uint32_t c[3] = {1 + irand(lim - 2), 1 + irand(lim - 2), 1 + irand(lim - 2)};
            if (ti == 0)
                c[0] = c[1] = c[2] = lim / 2; /* on the root's middle planes */
            uint32_t vox[40][3], attrs[40];
            size_t n = 0;
            for (int dz = -1; dz <= 1; dz++)
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++)
                        if ((dx == 0 && dy == 0 && dz == 0) || irand(3) == 0) {
                            vox[n][0] = (uint32_t)((int)c[0] + dx);
                            vox[n][1] = (uint32_t)((int)c[1] + dy);
                            vox[n][2] = (uint32_t)((int)c[2] + dz);
                            n++;
                        }
            for (int j = 0; j < 6; j++, n++)
                for (int a = 0; a < 3; a++)
                    vox[n][a] = j == 0 ? (a == 0 ? lim - 1 : 0) : irand(lim);
            for (size_t i = 0; i < n; i++)
                attrs[i] = (uint32_t)i + 1;
            /* drop duplicates (the scattered ones could meet the cluster) */
            size_t m = 0;
            for (size_t i = 0; i < n; i++) {
                int dup = 0;
                for (size_t j = 0; j < m && !dup; j++)
                    dup = !memcmp(vox[i], vox[j], sizeof vox[i]);
                if (!dup) {
                    memmove(vox[m], vox[i], sizeof vox[i]);
                    attrs[m] = (uint32_t)m + 1;
                    m++;
                }
            }
            n = m;
            const double origin[3] = {-0.5, 0.0, 1.0};
            oct_tree *t = tree_util_build(levels, origin, ti % 2 ? 1.0 : 4.0,
                                          (const uint32_t(*)[3])vox, n, attrs, NULL, 1, NULL);
            assert_non_null(t);
            st.trees++;
            for (unsigned long ri = 0; ri < rays_per_tree; ri++) {
                const uint32_t *near = vox[irand((uint32_t)n)];
                double P[3], o[3], d[3];
                for (int a = 0; a < 3; a++)
                    P[a] = ri % 4 == 0 ? pick_target_coord(lim, near[a])
                                       : (double)near[a] + (double)irand(5) / 4;
                exact_class_ray(lim, P, o, d);
                /* voxel-by-voxel walks at 2^20 cost up to 3 M steps: every
                 * split on one ray in 256, the upper splits on the rest */
                unsigned k_lo = ri % 256 == 0 ? 0 : levels - 6;
                if (ri % 256 == 128)
                    k_lo = 8;
                check_exact(t, (const uint32_t(*)[3])vox, n, o, d, k_lo, levels, 0, &st);
            }
            tree_util_free(t);
        }
    }
    fedisableexcept(FE_INVALID);
    print_message("exact, levels 16-20: %lu trees, %lu rays (%lu hits), %lu traversals, "
                  "%lu skipped\n",
                  st.trees, st.rays, st.hits, st.traces, st.skipped);
    assert_true(st.hits > st.rays / 4);
    assert_true(st.skipped < st.rays / 100);
}

/* General rays: random directions and corner-aimed rays from random points.
 * The first hit must equal the exact one unless a near tie (within 2^-40
 * relative of the exact ray) explains the difference. */
static void test_general_rays_tolerance(void **state)
{
    (void)state;
    feenableexcept(FE_INVALID);
    stats st = {0};
    const unsigned long per_level = GENERAL_RAYS / 10;
    for (unsigned li = 0; li < 10; li++) {
        const unsigned levels = li < 8 ? li + 1 : (li == 8 ? 12 : 18);
        const uint32_t lim = UINT32_C(1) << levels;
        uint32_t(*vox)[3];
        size_t n;
        const double origin[3] = {0.1, -0.3, 0.7};
        oct_tree *t = random_tree(levels, levels <= 8 ? 60 : 30, origin, 1.7, &vox, &n);
        const double scale = (double)lim / t->edge;
        for (unsigned long ri = 0; ri < per_level; ri++) {
            double eye[3], dir[3], o[3], d[3];
            const uint32_t *near = vox[irand((uint32_t)n)];
            for (int a = 0; a < 3; a++) {
                double g = ri % 4 == 0 ? -2.0 * lim + 5.0 * lim * urand() : lim * urand();
                eye[a] = origin[a] + g / scale;
                double tgt = (double)near[a] + (ri % 3 == 0 ? irand(2) : urand());
                dir[a] = ri % 7 == 0 ? 2 * urand() - 1 : (tgt - g) / scale;
            }
            if (ri % 11 == 0)
                dir[irand(3)] = irand(2) ? 0.0 : -0.0;
            for (int a = 0; a < 3; a++) {
                o[a] = (eye[a] - origin[a]) * scale; /* as trace_setup computes it */
                d[a] = dir[a] * scale;
            }
            /* exact answer in long double (the ray o + t d as represented),
             * computed after trace_setup so that eps can use t_base */
            trace_ray r;
            long double scale_t = lim / fmax(fmax(fabs(d[0]), fabs(d[1])), fabs(d[2]));
            if (trace_setup(t, eye, dir, &r))
                scale_t += fabsl((long double)r.t_base);
            const long double eps = 0x1p-40L * scale_t;
            /* best: first voxel with a non-empty interval; robust_in: first
             * entry into a voxel crossed for longer than eps */
            long best = -1;
            long double best_in = INFINITY, robust_in = INFINITY;
            for (size_t i = 0; i < n; i++) {
                long double tin, tout;
                if (!ld_voxel(o, d, lim, vox[i], &tin, &tout) || !(tin < tout))
                    continue;
                if (tin < best_in) {
                    best = (long)i;
                    best_in = tin;
                }
                if (tout - tin > eps && tin < robust_in)
                    robust_in = tin;
            }
            /* aimed exactly at a grid corner: exact ties, broken by rounding */
            const int aimed = ri % 3 == 0 && ri % 7 != 0;
            const unsigned k0 = levels > 8 ? levels - 9 : 0, kstep = levels > 8 ? 3 : 1;
            for (unsigned k = k0; k <= levels; k += kstep) {
                trace_opts opts = {k, 0};
                trace_hit h;
                trace_cast_all(t, &opts, eye, dir, &h);
                st.traces++;
                st.aimed_traces += aimed;
                assert_true(h.steps <= trace_max_steps(levels));
                long got = h.hit ? (long)t->voxels[h.voxel] - 1 : -1;
                if (got == best) {
                    if (best >= 0 && !(fabsl((long double)h.t - best_in) <= eps + 1e-12L * best_in))
                        fail_msg("t %.17g, exact %.17Lg", h.t, best_in);
                    continue;
                }
                /* A different answer must be explained by rounding: the voxel
                 * hit is within eps of the exact ray, and no voxel the exact
                 * ray crosses robustly comes before it; a miss only when every
                 * voxel is merely grazed. */
                long double gin = 0, gout = 0;
                int ok;
                if (got < 0)
                    ok = isinf(robust_in);
                else
                    ok = ld_voxel(o, d, lim, vox[got], &gin, &gout) && gin <= gout + eps &&
                         gin <= robust_in + eps && fabsl((long double)h.t - gin) <= eps + 1e-12L * gin;
                if (!ok)
                    fail_msg("L=%u K=%u o=(%a %a %a) d=(%a %a %a): trace %ld t %.17g (exact "
                             "[%.17Lg, %.17Lg]), exact %ld t %.17Lg",
                             levels, opts.split, o[0], o[1], o[2], d[0], d[1], d[2], got, h.t,
                             gin, gout, best, best_in);
                if (aimed)
                    st.aimed_ties++;
                else
                    st.near_ties++;
            }
            st.rays++;
            st.hits += best >= 0;
        }
        tree_util_free(t);
        free(vox);
    }
    fedisableexcept(FE_INVALID);
    print_message("general rays: %lu rays (%lu hits), %lu traversals; near ties: %lu of %lu "
                  "corner-aimed traversals, %lu of %lu others\n",
                  st.rays, st.hits, st.traces, st.aimed_ties, st.aimed_traces, st.near_ties,
                  st.traces - st.aimed_traces);
    assert_true(st.hits > st.rays / 10);
    /* off exact ties, a 2-ulp error decides almost nothing */
    assert_true(st.near_ties * 10000 < st.traces - st.aimed_traces);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_random_trees),
        cmocka_unit_test(test_exact_deep_trees),
        cmocka_unit_test(test_general_rays_tolerance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
