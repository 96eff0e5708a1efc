/* Tests for render/framing: the occupied box holds every voxel and is at
 * most a depth-FRAMING_DEPTH cell larger on a side; the default view aims
 * at its centre and sees all of it; an empty tree frames the cube. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "bench/tree_util.h"
#include "common/view/camera.h"
#include "render/framing.h"

static void test_box_holds_voxels(void **state)
{
    (void)state;
    static const uint32_t xyz[][3] = {{100, 40, 70}, {130, 41, 90}, {101, 60, 71}, {120, 55, 88}};
    const unsigned levels = 8, n = 4;
    const double origin[3] = {-3, 2, 5}, edge = 4.0;
    oct_tree *t = tree_util_build(levels, origin, edge, xyz, n, NULL, NULL, 1, NULL);
    assert_non_null(t);
    double lo[3], hi[3];
    assert_int_equal(framing_occupied_box(t, lo, hi), 1);
    const double vox = edge / 256.0, cell = edge / 64.0;
    for (int a = 0; a < 3; a++) {
        uint32_t mn = UINT32_MAX, mx = 0;
        for (unsigned k = 0; k < n; k++) {
            mn = xyz[k][a] < mn ? xyz[k][a] : mn;
            mx = xyz[k][a] > mx ? xyz[k][a] : mx;
        }
        const double vlo = origin[a] + mn * vox, vhi = origin[a] + (mx + 1) * vox;
        assert_true(lo[a] <= vlo && vlo - lo[a] < cell);
        assert_true(hi[a] >= vhi && hi[a] - vhi < cell);
    }
    /* the default view: target at the centre, every corner of the box in view */
    views_view v;
    views_defaults(&v);
    v.width = 300;
    v.height = 200;
    framing_default_view(t, &v);
    camera cam;
    assert_int_equal(camera_init(&cam, v.eye, v.target, v.up, v.fov, v.width, v.height),
                     CAMERA_OK);
    for (int a = 0; a < 3; a++)
        assert_true(fabs(v.target[a] - 0.5 * (lo[a] + hi[a])) < 1e-12);
    for (unsigned k = 0; k < 8; k++) {
        const double p[3] = {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
        double q[3], f = 0, r = 0, u = 0;
        for (int a = 0; a < 3; a++)
            q[a] = p[a] - cam.eye[a];
        for (int a = 0; a < 3; a++) {
            f += q[a] * cam.forward[a];
            r += q[a] * cam.right[a];
            u += q[a] * cam.up[a];
        }
        assert_true(f > 0);
        assert_true(fabs(u / f) < cam.h);
        assert_true(fabs(r / f) < cam.h * v.width / v.height);
    }
    /* the box is small here: the eye is nearer than the cube's framing */
    double d = 0;
    for (int a = 0; a < 3; a++)
        d += (v.eye[a] - v.target[a]) * (v.eye[a] - v.target[a]);
    assert_true(sqrt(d) < 0.5 * sqrt(3.0) * edge / sin(atan(tan(M_PI / 12))));
    tree_util_free(t);
}

static void test_empty_tree_frames_cube(void **state)
{
    (void)state;
    const double origin[3] = {1, 1, 1};
    oct_tree *t = tree_util_build(4, origin, 2.0, NULL, 0, NULL, NULL, 1, NULL);
    assert_non_null(t);
    double lo[3], hi[3];
    assert_int_equal(framing_occupied_box(t, lo, hi), 0);
    views_view v;
    views_defaults(&v);
    framing_default_view(t, &v);
    for (int a = 0; a < 3; a++)
        assert_true(v.target[a] == 2.0);
    tree_util_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box_holds_voxels),
        cmocka_unit_test(test_empty_tree_frames_cube),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
