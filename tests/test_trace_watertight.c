/* Watertightness and the step bound of render/trace (TESTPLAN.md section 3):
 * rays shot at closed one-voxel shells (sphere and box) at levels 4-10 never
 * get through, and the step count of the worst rays reaches, never exceeds,
 * trace_max_steps, with an exact count for K = 0. Every cast runs every
 * traversal implementation (tests/trace_oracle.h). */
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
#include "tests/sanitized.h"
#include "tests/trace_oracle.h"

static uint64_t rng_state = 0x243f6a8885a308d3u;
static uint64_t rng(void) { return rng_xorshift64star(&rng_state); }
static uint32_t irand(uint32_t n) { return (uint32_t)(rng() % n); }

/* ---- Watertightness ------------------------------------------------------ */

/* Voxels whose closed cube meets the sphere |p - c| = R (grid units): a
 * one-voxel shell that separates inside from outside for 26-paths. */
static size_t sphere_shell(unsigned levels, const double c[3], double R, uint32_t (**out)[3])
{
    const uint32_t lim = UINT32_C(1) << levels;
    size_t cap = 1024, n = 0;
    uint32_t(*v)[3] = malloc(cap * sizeof *v);
    assert_non_null(v);
    int lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = (int)floor(c[a] - R) - 1;
        hi[a] = (int)ceil(c[a] + R) + 1;
        if (lo[a] < 0)
            lo[a] = 0;
        if (hi[a] > (int)lim - 1)
            hi[a] = (int)lim - 1;
    }
    for (int z = lo[2]; z <= hi[2]; z++)
        for (int y = lo[1]; y <= hi[1]; y++)
            for (int x = lo[0]; x <= hi[0]; x++) {
                const int p[3] = {x, y, z};
                double dmin = 0, dmax = 0;
                for (int a = 0; a < 3; a++) {
                    double l = p[a] - c[a], h = p[a] + 1 - c[a];
                    double m = l > 0 ? l : h < 0 ? -h : 0;
                    double M = fmax(fabs(l), fabs(h));
                    dmin += m * m;
                    dmax += M * M;
                }
                if (dmin <= R * R && R * R <= dmax) {
                    if (n == cap) {
                        cap *= 2;
                        v = realloc(v, cap * sizeof *v);
                        assert_non_null(v);
                    }
                    v[n][0] = (uint32_t)x;
                    v[n][1] = (uint32_t)y;
                    v[n][2] = (uint32_t)z;
                    n++;
                }
            }
    *out = v;
    return n;
}

/* The faces of the voxel box [lo, hi]^3: a closed one-voxel wall. */
static size_t box_shell(uint32_t lo, uint32_t hi, uint32_t (**out)[3])
{
    size_t cap = (size_t)(hi - lo + 1) * (hi - lo + 1) * 6 + 8, n = 0;
    uint32_t(*v)[3] = malloc(cap * sizeof *v);
    assert_non_null(v);
    for (uint32_t z = lo; z <= hi; z++)
        for (uint32_t y = lo; y <= hi; y++)
            for (uint32_t x = lo; x <= hi; x++)
                if (x == lo || x == hi || y == lo || y == hi || z == lo || z == hi) {
                    assert_true(n < cap);
                    v[n][0] = x;
                    v[n][1] = y;
                    v[n][2] = z;
                    n++;
                    if (!(y == lo || y == hi || z == lo || z == hi) && x == lo)
                        x = hi - 1; /* skip the hollow */
                }
    *out = v;
    return n;
}

/* Rays from inside aimed exactly at corners, edge points and face points of
 * shell voxels, and the same rays reversed from outside: every one hits, and
 * no later than the aimed point. */
static void shoot_at_shell(const oct_tree *t, const uint32_t (*v)[3], size_t n, const double c[3],
                           double R, unsigned nrays, unsigned long *count)
{
    const double lim = ldexp(1.0, (int)t->levels), h = t->edge / lim;
    for (unsigned ri = 0; ri < nrays; ri++) {
        const uint32_t *s = v[irand((uint32_t)n)];
        double P[3];
        unsigned kind = irand(3); /* corner, edge, face */
        for (int a = 0; a < 3; a++) {
            P[a] = (double)s[a] + irand(2);
            if ((kind == 1 && a == 0) || (kind == 2 && a < 2))
                P[a] = (double)s[a] + (double)(1 + irand(15)) / 16.0;
        }
        double eye[3], dir[3], far[3], back[3];
        for (int a = 0; a < 3; a++) {
            eye[a] = t->origin[a] + c[a] * h;
            dir[a] = (P[a] - c[a]) * h;
            far[a] = t->origin[a] + (P[a] + (P[a] - c[a]) * (ri % 2 ? 1.0 : 0x1p20)) * h;
            back[a] = -dir[a];
        }
        for (unsigned k = 0; k <= t->levels; k++) {
            trace_opts o = {k, 0};
            trace_hit hin, hout;
            trace_cast_all(t, &o, eye, dir, &hin);
            trace_cast_all(t, &o, far, back, &hout);
            if (!hin.hit || !hout.hit)
                fail_msg("hole: L=%u K=%u aim (%.17g %.17g %.17g) from %s", t->levels, k, P[0],
                         P[1], P[2], hin.hit ? "outside" : "inside");
            /* from the centre, the hit is no later than the sphere (radius R
             * in grid units; the aimed point is at t = 1) */
            if (R > 0) {
                double len = sqrt((P[0] - c[0]) * (P[0] - c[0]) + (P[1] - c[1]) * (P[1] - c[1]) +
                                  (P[2] - c[2]) * (P[2] - c[2]));
                if (!(hin.t <= R / len * (1 + 1e-12)))
                    fail_msg("hit at t %.17g after the sphere at %.17g", hin.t, R / len);
            }
            assert_true(hin.steps <= trace_max_steps(t->levels));
            assert_true(hout.steps <= trace_max_steps(t->levels));
            (*count)++;
        }
    }
}

static void test_watertight_shells(void **state)
{
    (void)state;
    feenableexcept(FE_INVALID);
    unsigned long traced = 0;
    for (unsigned levels = 4; levels <= 10; levels++) {
        const uint32_t lim = UINT32_C(1) << levels;
        const double origin[3] = {-1, -1, -1};
        /* sphere: centre on a voxel corner, then off-grid */
        for (int variant = 0; variant < 2; variant++) {
            double c[3] = {lim / 2.0, lim / 2.0, lim / 2.0};
            if (variant)
                for (int a = 0; a < 3; a++)
                    c[a] += (double)(1 + irand(255)) / 256.0 - 0.5;
            double R = fmin(0.35 * lim, 40.0);
            if (variant == 0)
                R = floor(R); /* passes exactly through corners and edges */
            uint32_t(*v)[3];
            size_t n = sphere_shell(levels, c, R, &v);
            oct_tree *t = tree_util_build(levels, origin, 2.0, (const uint32_t(*)[3])v, n, NULL,
                                          NULL, 1, NULL);
            assert_non_null(t);
            shoot_at_shell(t, (const uint32_t(*)[3])v, n, c, R, SANITIZED ? 150 : 400, &traced);
            tree_util_free(t);
            free(v);
        }
        /* box wall */
        uint32_t lo = lim / 4, hi = lim - lim / 4 - 1;
        if (hi > lo + 60)
            hi = lo + 60;
        uint32_t(*v)[3];
        size_t n = box_shell(lo, hi, &v);
        oct_tree *t =
            tree_util_build(levels, origin, 2.0, (const uint32_t(*)[3])v, n, NULL, NULL, 1, NULL);
        assert_non_null(t);
        const double c[3] = {(lo + hi + 1) / 2.0, (lo + hi + 1) / 2.0 + 0.25, (lo + hi + 1) / 2.0};
        shoot_at_shell(t, (const uint32_t(*)[3])v, n, c, 0.0, SANITIZED ? 150 : 400, &traced);
        tree_util_free(t);
        free(v);
    }
    fedisableexcept(FE_INVALID);
    print_message("watertight: %lu traversals at shell corners, edges and faces\n", traced);
}

/* The step bound is reached by the worst rays and never exceeded: a ray
 * along the main diagonal, slightly off, through an empty tree with one
 * voxel in the far corner, walks about 3 * 2^L voxels at K = 0. */
static void test_step_bound(void **state)
{
    (void)state;
    for (unsigned levels = 1; levels <= 12; levels++) {
        const uint32_t lim = UINT32_C(1) << levels;
        const uint32_t far[1][3] = {{lim - 1, lim - 1, lim - 1}};
        oct_tree *t = tree_util_simple(levels, far, 1);
        assert_non_null(t);
        /* d = (1, 1 - e, 1 - 2e): crosses each axis' planes at distinct times */
        const double eye[3] = {0, 0, 0}, dir[3] = {1, 1 - 0x1p-30, 1 - 0x1p-29};
        trace_opts o = {0, 0};
        trace_hit h;
        assert_int_equal(trace_cast_all(t, &o, eye, dir, &h), 1);
        assert_true(h.steps <= trace_max_steps(levels));
        assert_int_equal(h.steps, 3 * (lim - 1)); /* every plane crossed separately */
        /* exactly diagonal: one step per voxel */
        const double diag[3] = {1, 1, 1};
        assert_int_equal(trace_cast_all(t, &o, eye, diag, &h), 1);
        assert_int_equal(h.steps, lim - 1);
        tree_util_free(t);
        /* empty tree: returns at once */
        t = tree_util_simple(levels, NULL, 0);
        assert_int_equal(trace_cast_all(t, &o, eye, dir, &h), 0);
        assert_int_equal(h.steps, 0);
        tree_util_free(t);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_step_bound),
        cmocka_unit_test(test_watertight_shells),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
