/* Tests for common/view/camera: docs/INTERFACE.md's formula by hand, exact centre rays
 * for odd sizes, rejections. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "common/view/camera.h"

static void test_formula_by_hand(void **state)
{
    (void)state;
    camera c;
    const double eye[3] = {0, 0, 0}, target[3] = {0, 1, 0}, up[3] = {0, 0, 1};
    assert_int_equal(camera_init(&c, eye, target, up, 90.0, 4, 2), CAMERA_OK);
    /* forward +y, right = forward x up = +x, up' = right x forward = +z, h = 1 */
    assert_true(fabs(c.h - 1.0) < 1e-15);
    assert_true(c.right[0] == 1.0 && c.up[2] == 1.0);
    double d[3];
    camera_ray(&c, 0, 0, d);
    /* u = (2*0.5/4 - 1) * 1 * 4/2 = -1.5, v = (1 - 2*0.5/2) = 0.5 */
    double n = sqrt(1.5 * 1.5 + 1 + 0.25);
    assert_true(fabs(d[0] - (-1.5 / n)) < 1e-15);
    assert_true(fabs(d[1] - (1.0 / n)) < 1e-15);
    assert_true(fabs(d[2] - (0.5 / n)) < 1e-15);
    camera_ray(&c, 3, 1, d);
    assert_true(fabs(d[0] - (1.5 / n)) < 1e-15 && fabs(d[2] + 0.5 / n) < 1e-15);
}

static void test_odd_size_centre_is_exact(void **state)
{
    (void)state;
    camera c;
    const double eye[3] = {-5, 0.5, 0.5}, target[3] = {0.5, 0.5, 0.5}, up[3] = {0, 0, 1};
    assert_int_equal(camera_init(&c, eye, target, up, 30.0, 101, 33), CAMERA_OK);
    double d[3];
    camera_ray(&c, 50, 16, d);
    assert_true(d[0] == 1.0 && d[1] == 0.0 && d[2] == 0.0);
    camera_ray(&c, 50, 0, d); /* centre column: no sideways component */
    assert_true(d[1] == 0.0 && d[2] > 0.0);
    camera_ray(&c, 0, 16, d); /* centre row: no vertical component */
    assert_true(d[2] == 0.0 && d[1] > 0.0); /* right = fwd x up = (1,0,0)x(0,0,1) = -y */
}

static void test_rejections(void **state)
{
    (void)state;
    camera c;
    const double eye[3] = {1, 2, 3}, target[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    const double vert_eye[3] = {0, 0, 5}, zero[3] = {0, 0, 0}, nan3[3] = {NAN, 0, 0};
    const double inf3[3] = {0, INFINITY, 0};
    assert_int_equal(camera_init(&c, eye, eye, up, 30, 8, 8), CAMERA_ESAME);
    assert_int_equal(camera_init(&c, vert_eye, target, up, 30, 8, 8), CAMERA_EPARALLEL);
    assert_int_equal(camera_init(&c, eye, target, zero, 30, 8, 8), CAMERA_EPARALLEL);
    assert_int_equal(camera_init(&c, eye, target, up, 0, 8, 8), CAMERA_EFOV);
    assert_int_equal(camera_init(&c, eye, target, up, 180, 8, 8), CAMERA_EFOV);
    assert_int_equal(camera_init(&c, eye, target, up, -5, 8, 8), CAMERA_EFOV);
    assert_int_equal(camera_init(&c, eye, target, up, NAN, 8, 8), CAMERA_ENONFINITE);
    assert_int_equal(camera_init(&c, nan3, target, up, 30, 8, 8), CAMERA_ENONFINITE);
    assert_int_equal(camera_init(&c, eye, inf3, up, 30, 8, 8), CAMERA_ENONFINITE);
    assert_int_equal(camera_init(&c, eye, target, up, 30, 0, 8), CAMERA_ESIZE);
    assert_int_equal(camera_init(&c, eye, target, up, 30, 8, 32769), CAMERA_ESIZE);
    assert_int_equal(camera_init(&c, eye, target, up, 30, 32768, 1), CAMERA_OK);
    for (int e = CAMERA_OK; e <= CAMERA_ESIZE; e++)
        assert_non_null(camera_strerror((camera_err)e));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_formula_by_hand),
        cmocka_unit_test(test_odd_size_centre_is_exact),
        cmocka_unit_test(test_rejections),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
