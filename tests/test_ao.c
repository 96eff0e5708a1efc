/* Tests for render/ao: directions on the normal's side, unit, the same for
 * the same pixel; a plane alone is open (factor 1, exactly); the inside of
 * a concave corner is darker than its open floor, and lighter with shorter
 * rays; the frame's AO image is the same on every traversal implementation
 * and thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench/tree_util.h"
#include "format/oct_normal.h"
#include "render/ao.h"
#include "render/frame.h"
#include "render/views.h"
#include "render/shadow.h"
#include "tests/grid_hits.h"
#include "tests/voxel_shapes.h"

#define LEVELS 6
#define NV 64.0
#define REACH VIEWS_AO_DISTANCE /* the default --ao-distance: 8 voxels here */

static void test_directions(void **state)
{
    (void)state;
    static const float ns[][3] = {{0, 0, 1}, {0, 0, -1}, {0.6f, 0.0f, 0.8f}, {-0.48f, 0.6f, -0.64f}};
    for (size_t k = 0; k < sizeof ns / sizeof ns[0]; k++)
        for (unsigned m = 1; m <= 64; m *= 4)
            for (unsigned r = 0; r < m; r++) {
                double d[3], e[3];
                ao_direction(ns[k], r, m, ao_seed(3, 7), d);
                ao_direction(ns[k], r, m, ao_seed(3, 7), e);
                assert_memory_equal(d, e, sizeof d);
                ao_frame f; /* the frame once, the rays in it: the same bits */
                ao_basis(ns[k], ao_seed(3, 7), &f);
                ao_direction_in(&f, r, m, e);
                assert_memory_equal(d, e, sizeof d);
                const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                assert_true(fabs(len - 1.0) < 1e-12);
                const double c = d[0] * ns[k][0] + d[1] * ns[k][1] + d[2] * ns[k][2];
                assert_true(c >= sqrt(0.5 / m) - 1e-6); /* cos of the last stratum */
            }
    assert_true(ao_seed(3, 7) != ao_seed(7, 3));
    assert_true(ao_seed(0, 0) != ao_seed(1, 0));
}

/* The AO factor of rays k0 .. k0 + count - 1 of `rays`, each `reach` cube
 * edges long, from the surface point under (x, y), looked at from above; -1
 * when there is none. */
static float factor_of(const oct_tree *t, const trace_opts *o, trace_traverse_fn fn, double x,
                       double y, unsigned k0, unsigned count, unsigned rays, double reach)
{
    const double eye[3] = {x, y, NV - 0.5}, down[3] = {0, 0, -1};
    trace_hit h;
    if (!trace_ray_cast(t, o, eye, down, &h))
        return -1.0f;
    float n[3];
    oct_normal_decode(t->voxels[h.voxel] & OCT_VOXEL_NORMAL_MASK, n);
    if (n[2] < 0.0f)
        for (int a = 0; a < 3; a++)
            n[a] = -n[a];
    double org[3];
    assert_true(shadow_origin(t, &h, n, org));
    uint64_t steps = 0;
    return ao_factor(t, o, fn, org, n, k0, count, rays, ao_seed((uint32_t)x, (uint32_t)y), reach,
                     &steps);
}

/* factor_of for all the rays, at the default length. */
static float factor_at(const oct_tree *t, const trace_opts *o, trace_traverse_fn fn, double x,
                       double y, unsigned rays)
{
    return factor_of(t, o, fn, x, y, 0, rays, rays, REACH);
}

static void test_plane_alone_is_open(void **state)
{
    (void)state;
    static const double normals[][3] = {{0, 0, 1}, {0.3, -0.2, 1}, {0.7, 0.6, 1}};
    for (size_t p = 0; p < sizeof normals / sizeof normals[0]; p++) {
        shape s = shape_plane(normals[p][0], normals[p][1], normals[p][2], 0.0);
        s.d = s.n[0] * 32 + s.n[1] * 32 + s.n[2] * 20;
        oct_tree *t = shapes_build(LEVELS, NV, &s, 1, 1);
        assert_non_null(t);
        for (unsigned impl = 0; impl < trace_impl_count; impl++)
            for (int refine = 0; refine <= 1; refine++) {
                trace_opts o = {.split = LEVELS, .refine = refine};
                unsigned tested = 0;
                for (double y = 4.3; y < 60; y += 5.1)
                    for (double x = 4.7; x < 60; x += 5.3) {
                        float f = factor_at(t, &o, trace_impls[impl].traverse, x, y, 64);
                        if (f < 0.0f)
                            continue; /* the plane leaves the cube there */
                        assert_true(f == 1.0f);
                        tested++;
                    }
                assert_true(tested > 40);
            }
        tree_util_free(t);
    }
}

static void test_concave_corner_is_darker(void **state)
{
    (void)state;
    shape sh[2] = {shape_plane(0, 0, 1, 20.5), shape_plane(1, 0, 0, 20.5)};
    sh[0].lo[0] = 20; /* floor from the wall on */
    sh[1].lo[2] = 20; /* wall from the floor up */
    oct_tree *t = shapes_build(LEVELS, NV, sh, 2, 1);
    assert_non_null(t);
    for (unsigned impl = 0; impl < trace_impl_count; impl++)
        for (int refine = 0; refine <= 1; refine++) {
            trace_opts o = {.split = LEVELS, .refine = refine};
            trace_traverse_fn fn = trace_impls[impl].traverse;
            /* the rays go 8 voxels here: open beyond them, dark near the wall */
            const float open = factor_at(t, &o, fn, 40.5, 30.5, 256);
            const float mid = factor_at(t, &o, fn, 25.5, 30.5, 256);
            const float corner = factor_at(t, &o, fn, 22.5, 30.5, 256);
            assert_true(open == 1.0f);
            assert_true(mid < open);
            assert_true(corner < mid);
            assert_true(corner < 0.85f);
        }
    tree_util_free(t);
}

/* --ao-distance: each ray's answer over a shorter length is its answer over
 * the first part of a longer one (open there when open all along), so no
 * ray of the corner's floor is occluded at a short length and open at a
 * longer one; rays too short to reach the wall leave the floor open
 * (factor 1 exactly), and the corner is still darker up close. */
static void test_shorter_reach_is_lighter(void **state)
{
    (void)state;
    shape sh[2] = {shape_plane(0, 0, 1, 20.5), shape_plane(1, 0, 0, 20.5)};
    sh[0].lo[0] = 20;
    sh[1].lo[2] = 20;
    oct_tree *t = shapes_build(LEVELS, NV, sh, 2, 1);
    assert_non_null(t);
    static const double reach[] = {1.0 / 64, 3.0 / 64, REACH, 0.5, 2.0}; /* 1, 3, 8 voxels, ... */
    enum { RAYS = 32, NR = sizeof reach / sizeof reach[0] };
    unsigned long turned = 0; /* rays open at one length and occluded at the next */
    for (unsigned impl = 0; impl < trace_impl_count; impl++)
        for (int refine = 0; refine <= 1; refine++) {
            trace_opts o = {.split = LEVELS, .refine = refine};
            trace_traverse_fn fn = trace_impls[impl].traverse;
            for (double x = 21.3; x < 34; x += 0.9)
                for (unsigned k = 0; k < RAYS; k++) {
                    float prev = 1.0f;
                    for (unsigned r = 0; r < NR; r++) {
                        const float f = factor_of(t, &o, fn, x, 30.5, k, 1, RAYS, reach[r]);
                        assert_true(f == 0.0f || f == 1.0f);
                        assert_true(f <= prev); /* occluded stays occluded */
                        turned += f < prev;
                        prev = f;
                    }
                }
            /* 5 voxels from the wall: 3-voxel rays reach nothing, 8-voxel ones do */
            assert_true(factor_of(t, &o, fn, 25.5, 30.5, 0, 256, 256, 3.0 / 64) == 1.0f);
            assert_true(factor_of(t, &o, fn, 25.5, 30.5, 0, 256, 256, REACH) < 1.0f);
            assert_true(factor_of(t, &o, fn, 22.5, 30.5, 0, 256, 256, 3.0 / 64) < 1.0f);
        }
    assert_true(turned > 100);
    tree_util_free(t);
}

static void render_ao(const oct_tree *t, const camera *cam, trace_traverse_fn fn,
                      unsigned threads, unsigned aa, uint8_t *rgb)
{
    frame_job job;
    memset(&job, 0, sizeof job);
    job.tree = t;
    job.cam = cam;
    job.opts.split = LEVELS;
    job.shade.ambient = 0.3f;
    job.shade.ao_rays = 16;
    job.shade.ao_distance = REACH;
    job.shade.shadows = 1;
    shade_default_light(cam, job.shade.light);
    job.rgb = rgb;
    job.threads = threads;
    job.beam_size = FRAME_BEAM_DEFAULT;
    job.traverse = fn;
    job.aa = aa;
    frame_stats st;
    assert_int_equal(frame_render(&job, &st), 0);
    assert_true(st.ao_rays >= 16 * st.hits);
}

static void test_frame_ao_deterministic(void **state)
{
    (void)state;
    shape sh[3] = {shape_plane(0, 0, 1, 20.5), shape_plane(1, 0, 0, 20.5),
                   shape_sphere(40, 40, 30, 8)};
    sh[0].lo[0] = 20;
    sh[1].lo[2] = 20;
    oct_tree *t = shapes_build(LEVELS, NV, sh, 3, 1);
    assert_non_null(t);
    const double eye[3] = {150, 110, 120}, target[3] = {32, 32, 24}, up[3] = {0, 0, 1};
    camera cam;
    assert_int_equal(camera_init(&cam, eye, target, up, 30, 96, 80), CAMERA_OK);
    uint8_t *ref = malloc(96 * 80 * 3), *rgb = malloc(96 * 80 * 3);
    assert_non_null(ref);
    assert_non_null(rgb);
    for (unsigned aa = 1; aa <= 3; aa += 2) {
        render_ao(t, &cam, NULL, 1, aa, ref);
        for (unsigned impl = 0; impl < trace_impl_count; impl++)
            for (unsigned th = 1; th <= 4; th += 3) {
                render_ao(t, &cam, trace_impls[impl].traverse, th, aa, rgb);
                assert_memory_equal(rgb, ref, 96 * 80 * 3);
            }
    }
    free(ref);
    free(rgb);
    tree_util_free(t);
}

/* The secondary rays of a hit share its start (shadow_start_hit): its
 * grid position and its anchor. Each answer and step count is that of the
 * ray traced alone from the world start point (shadow_blocked, ao_factor),
 * on every implementation, with and without --refine, for hits of all
 * kinds: floor, wall, the corner between them, a ball. */
static void test_shared_start_same_answers(void **state)
{
    (void)state;
    shape sh[3] = {shape_plane(0, 0, 1, 20.5), shape_plane(1, 0, 0, 20.5),
                   shape_sphere(40, 40, 30, 8)};
    sh[0].lo[0] = 20;
    sh[1].lo[2] = 20;
    oct_tree *t = shapes_build(LEVELS, NV, sh, 3, 1);
    assert_non_null(t);
    const double eye[3] = {150, 110, 120};
    static const double lights[][3] = {{0.3, 0.2, 0.93}, {-0.8, 0.1, 0.59}, {0.5, 0.7, 0.5}};
    unsigned long checked = 0, deep = 0, blocked = 0, shaded = 0;
    shadow_start st; /* kept from hit to hit: each start's search starts near the last */
    st.near = 0;
    for (unsigned impl = 0; impl < trace_impl_count; impl++)
        for (int refine = 0; refine <= 1; refine++) {
            const trace_opts o = {.split = LEVELS, .refine = refine};
            trace_traverse_fn fn = trace_impls[impl].traverse;
            for (int y = 0; y < GRID_HITS_SIDE; y++)
                for (int x = 0; x < GRID_HITS_SIDE; x++) {
                    trace_hit h;
                    float n[3];
                    if (!grid_hit(t, &o, eye, x, y, &h, n))
                        continue;
                    double org[3];
                    const int ok = shadow_origin(t, &h, n, org);
                    assert_int_equal(shadow_start_hit(t, &h, n, &st), ok);
                    if (!ok)
                        continue;
                    assert_memory_equal(st.o, org, sizeof org);
                    deep += st.anchor.depth + 2 >= LEVELS;
                    const uint32_t seed = ao_seed((uint32_t)x, (uint32_t)y);
                    uint64_t s0 = 0, s1 = 0;
                    const float f0 = ao_factor(t, &o, fn, org, n, 0, 16, 16, seed, REACH, &s0);
                    const float f1 =
                        ao_factor_from(t, &o, fn, &st, n, 0, 16, 16, seed, REACH, NULL, &s1);
                    assert_true(f0 == f1);
                    assert_true(s0 == s1);
                    shaded += f0 < 1.0f;
                    for (size_t l = 0; l < sizeof lights / sizeof lights[0]; l++) {
                        s0 = s1 = 0;
                        const int b0 = shadow_blocked(t, &o, fn, org, lights[l], INFINITY, &s0);
                        const int b1 =
                            shadow_blocked_from(t, &o, fn, &st, NULL, lights[l], INFINITY, &s1);
                        assert_int_equal(b0, b1);
                        assert_true(s0 == s1);
                        blocked += (unsigned)b0;
                    }
                    checked++;
                }
        }
    print_message("shared starts: %lu hits, %lu anchored within 2 levels of the voxels, "
                  "%lu shadow rays blocked, %lu partly occluded\n",
                  checked, deep, blocked, shaded);
    assert_true(checked > 1000);
    assert_true(deep > checked / 2 && blocked > 50 && shaded > 100);
    tree_util_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_directions),
        cmocka_unit_test(test_plane_alone_is_open),
        cmocka_unit_test(test_concave_corner_is_darker),
        cmocka_unit_test(test_shorter_reach_is_lighter),
        cmocka_unit_test(test_frame_ao_deterministic),
        cmocka_unit_test(test_shared_start_same_answers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
