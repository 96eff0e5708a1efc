/* Tests for render/shadow and render/ao: the start point's offset rule (no
 * self-shadowing on tilted planes at grazing light, no light through a thin
 * wall), shadows of a ball on a slab against the closed-form outline, and
 * ambient occlusion (a plane alone is open, exactly; a concave corner is
 * darker; directions deterministic and on the normal's side). Every check
 * runs on each traversal implementation and with and without --refine. */
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
#include "render/shadow.h"
#include "tests/voxel_shapes.h"

#define LEVELS 6
#define NV 64.0 /* voxels a side */

static trace_hit hit_of(const oct_tree *t, uint64_t k, const uint32_t xyz[3])
{
    trace_hit h;
    memset(&h, 0, sizeof h);
    h.hit = 1;
    h.voxel = k;
    memcpy(h.xyz, xyz, sizeof h.xyz);
    (void)t;
    return h;
}

/* Calls fn on every voxel of t: index and coordinates (leaf order). */
typedef void (*voxel_fn)(const oct_tree *t, uint64_t k, const uint32_t xyz[3], void *ctx);
static void each_voxel(const oct_tree *t, voxel_fn fn, void *ctx)
{
    const uint32_t n = UINT32_C(1) << t->levels;
    trace_opts o = {.split = t->levels};
    /* find each voxel by a ray straight down its column: slow but plain */
    for (uint32_t y = 0; y < n; y++)
        for (uint32_t x = 0; x < n; x++) {
            const double dir[3] = {0, 0, -1};
            double z0 = n + 1.0;
            while (z0 > 0.0) {
                trace_hit h;
                const double eye[3] = {x + 0.5, y + 0.5, z0};
                if (!trace_ray_cast(t, &o, eye, dir, &h))
                    break;
                fn(t, h.voxel, h.xyz, ctx);
                z0 = h.xyz[2]; /* from its bottom face: the voxel below is next */
            }
        }
}

typedef struct acne_ctx {
    trace_opts opts;
    trace_traverse_fn fn;
    const double *light;
    unsigned tested, blocked;
} acne_ctx;

static void acne_voxel(const oct_tree *t, uint64_t k, const uint32_t xyz[3], void *vc)
{
    acne_ctx *c = vc;
    trace_hit h = hit_of(t, k, xyz);
    float n[3];
    oct_normal_decode(t->voxels[k] & OCT_VOXEL_NORMAL_MASK, n);
    double facing = n[0] * c->light[0] + n[1] * c->light[1] + n[2] * c->light[2];
    if (facing < 0.0)
        for (int a = 0; a < 3; a++)
            n[a] = -n[a];
    double o[3];
    assert_true(shadow_origin(t, &h, n, o));
    uint64_t steps = 0;
    c->tested++;
    c->blocked += (unsigned)shadow_blocked(t, &c->opts, c->fn, o, c->light, INFINITY, &steps);
}

/* A tilted plane lit from every direction down to 3 degrees above it: no
 * voxel of it shadows another. */
static void test_no_acne_on_planes(void **state)
{
    (void)state;
    static const double normals[][3] = {{0, 0, 1}, {0.3, 0.2, 1}, {1, 1, 1}, {-0.7, 0.1, 0.4}};
    for (size_t p = 0; p < sizeof normals / sizeof normals[0]; p++) {
        const double *nn = normals[p];
        shape s = shape_plane(nn[0], nn[1], nn[2], 0.0);
        s.d = s.n[0] * 32.3 + s.n[1] * 31.7 + s.n[2] * 32.1; /* through the middle */
        oct_tree *t = shapes_build(LEVELS, NV, &s, 1, 1);
        assert_non_null(t);
        for (unsigned impl = 0; impl < trace_impl_count; impl++)
            for (int refine = 0; refine <= 1; refine++)
                for (int l = 0; l < 24; l++) {
                    /* elevation 3..87 degrees over the plane, azimuth round it */
                    const double el = (3.0 + 84.0 * (l % 6) / 5.0) * M_PI / 180.0;
                    const double az = (l / 6) * M_PI / 2.0 + 0.3;
                    double tu[3] = {s.n[1], -s.n[0], 0};
                    if (fabs(s.n[2]) > 0.9) {
                        tu[0] = 1;
                        tu[1] = tu[2] = 0;
                    }
                    double tl = sqrt(tu[0] * tu[0] + tu[1] * tu[1] + tu[2] * tu[2]);
                    double tv[3] = {s.n[1] * tu[2] - s.n[2] * tu[1],
                                    s.n[2] * tu[0] - s.n[0] * tu[2],
                                    s.n[0] * tu[1] - s.n[1] * tu[0]};
                    double light[3];
                    for (int a = 0; a < 3; a++)
                        light[a] = cos(el) * (cos(az) * tu[a] / tl + sin(az) * tv[a] / tl) +
                                   sin(el) * s.n[a];
                    acne_ctx c = {{.split = LEVELS, .refine = refine}, trace_impls[impl].traverse, light, 0, 0};
                    each_voxel(t, acne_voxel, &c);
                    assert_true(c.tested > 500);
                    if (c.blocked)
                        print_error("plane %zu, %s, refine %d, light %d: %u of %u blocked\n", p,
                                    trace_impls[impl].name, refine, l, c.blocked, c.tested);
                    assert_int_equal(c.blocked, 0);
                }
        tree_util_free(t);
    }
}

/* A floor and, 3 voxels above it (more than the offset), a wall one voxel
 * thick over half the floor; light from above at an angle. Floor points
 * whose light ray crosses the wall are in shadow, the others lit. */
static void test_thin_wall_does_not_leak(void **state)
{
    (void)state;
    shape sh[2];
    sh[0] = shape_plane(0, 0, 1, 20.5);
    sh[1] = shape_plane(0, 0, 1, 25.0);
    sh[1].lo[0] = 16;
    sh[1].hi[0] = 48;
    sh[1].lo[1] = 16;
    sh[1].hi[1] = 48;
    sh[1].surface = 1;
    oct_tree *t = shapes_build(LEVELS, NV, sh, 2, 2);
    assert_non_null(t);
    double light[3] = {0.2, 0.1, 1.0};
    const double ll = sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
    for (int a = 0; a < 3; a++)
        light[a] /= ll;
    unsigned shadowed = 0, lit = 0;
    for (unsigned impl = 0; impl < trace_impl_count; impl++)
        for (int refine = 0; refine <= 1; refine++) {
            trace_opts o = {.split = LEVELS, .refine = refine};
            for (uint32_t y = 2; y < 62; y += 3)
                for (uint32_t x = 2; x < 62; x += 3) {
                    /* the floor voxel under (x, y), found from above the wall's gap */
                    double eye[3] = {x + 0.5, y + 0.5, 22.9}, down[3] = {0, 0, -1};
                    trace_hit h;
                    assert_true(trace_ray_cast(t, &o, eye, down, &h));
                    float n[3] = {0, 0, 1};
                    double org[3];
                    assert_true(shadow_origin(t, &h, n, org));
                    uint64_t steps = 0;
                    int b = shadow_blocked(t, &o, trace_impls[impl].traverse, org, light,
                                           INFINITY, &steps);
                    /* where the floor point's light ray meets the wall's plane */
                    const double s = (25.0 - 20.5) / light[2];
                    const double wx = x + 0.5 + s * light[0], wy = y + 0.5 + s * light[1];
                    const double margin = 2.5; /* voxels: wall edge, offset shift */
                    const int inside = wx > 16 + margin && wx < 48 - margin &&
                                       wy > 16 + margin && wy < 48 - margin;
                    const int outside = wx < 16 - margin || wx > 48 + margin ||
                                        wy < 16 - margin || wy > 48 + margin;
                    if (inside) {
                        assert_int_equal(b, 1);
                        shadowed++;
                    } else if (outside) {
                        assert_int_equal(b, 0);
                        lit++;
                    }
                }
        }
    assert_true(shadowed > 100 && lit > 100);
    tree_util_free(t);
}

/* A wall lit from behind stays unlit from the front, with or without
 * shadows: the light is behind its viewer-facing normal. */
static void test_wall_lit_from_behind_is_dark(void **state)
{
    (void)state;
    shape s = shape_plane(0, 0, 1, 32.0);
    oct_tree *t = shapes_build(LEVELS, NV, &s, 1, 1);
    assert_non_null(t);
    shade_params p;
    memset(&p, 0, sizeof p);
    p.ambient = 0.2f;
    const double l[3] = {0.1, 0.2, -1.0};
    assert_int_equal(shade_set_light(&p, l), 0);
    trace_opts o = {.split = LEVELS};
    double eye[3] = {30.5, 31.5, 50.0}, dir[3] = {0, 0, -1};
    trace_hit h;
    assert_true(trace_ray_cast(t, &o, eye, dir, &h));
    float n[3];
    assert_true(shade_normal(t, &p, &h, dir, n) == 0.0);
    assert_true(n[2] > 0.99f); /* facing the viewer above */
    tree_util_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_acne_on_planes),
        cmocka_unit_test(test_thin_wall_does_not_leak),
        cmocka_unit_test(test_wall_lit_from_behind_is_dark),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
