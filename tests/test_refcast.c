/* Tests for bench/refcast: the exact reference against closed forms (sphere,
 * plane, box face, misses, several surfaces, a tangential touch) and the
 * image driver's agreement with single rays. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench/refcast.h"
#include "common/view/camera.h"
#include "common/expr/scene.h"

static scene *parse(const char *text)
{
    scene *s = NULL;
    scene_error err;
    int rc = scene_parse(text, strlen(text), &s, &err);
    if (rc != 0)
        fail_msg("scene: %u:%u: %s", err.line, err.col, err.message);
    return s;
}

static void unit(double d[3])
{
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int a = 0; a < 3; a++)
        d[a] /= n;
}

static double rnd(unsigned *state) /* [0, 1), a small LCG: reproducible */
{
    *state = *state * 1103515245u + 12345u;
    return (double)((*state >> 8) & 0xffffffu) / 16777216.0;
}

static refcast_hit cast(const scene *s, const double eye[3], const double dir[3])
{
    refcast_scratch *w = refcast_scratch_new(s);
    assert_non_null(w);
    refcast_hit h;
    refcast_stats st = {0, 0, 0, 0};
    refcast_ray(s, w, eye, dir, &h, &st);
    refcast_scratch_free(w);
    return h;
}

static void test_sphere_closed_form(void **state)
{
    (void)state;
    scene *s = parse("bounds -1.25 -1.25 -1.25 1.25 1.25 1.25\nsurface x^2 + y^2 + z^2 - 1\n");
    unsigned seed = 7;
    int hits = 0;
    for (int k = 0; k < 2000; k++) {
        double eye[3] = {2.0 * (rnd(&seed) - 0.5), 2.0 * (rnd(&seed) - 0.5), 4.0};
        double dir[3] = {0.4 * (rnd(&seed) - 0.5), 0.4 * (rnd(&seed) - 0.5), -1.0};
        unit(dir);
        double b = eye[0] * dir[0] + eye[1] * dir[1] + eye[2] * dir[2];
        double c = eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2] - 1.0;
        double disc = b * b - c;
        refcast_hit h = cast(s, eye, dir);
        if (disc < 1e-6) { /* clear misses only: near-grazing rays are ill-posed */
            if (disc < -1e-6)
                assert_true(isinf(h.t));
            continue;
        }
        double t = -b - sqrt(disc);
        hits++;
        assert_true(fabs(h.t - t) <= 1e-9 * t);
        assert_int_equal(h.touch, 0);
        /* normal: the unit position vector, facing the eye */
        double p[3], dot = 0.0;
        for (int a = 0; a < 3; a++)
            p[a] = eye[a] + t * dir[a];
        for (int a = 0; a < 3; a++)
            dot += p[a] * h.normal[a];
        assert_true(fabs(fabs(dot) - 1.0) < 1e-9);
        assert_true(h.normal[0] * dir[0] + h.normal[1] * dir[1] + h.normal[2] * dir[2] <= 0.0);
    }
    assert_true(hits > 500);
    scene_free(s);
}

static void test_plane(void **state)
{
    (void)state;
    scene *s = parse("bounds -1 -1 -1 1 1 1\nsurface z - 0.3\n");
    unsigned seed = 3;
    for (int k = 0; k < 500; k++) {
        double eye[3] = {rnd(&seed) - 0.5, rnd(&seed) - 0.5, 2.0};
        double dir[3] = {0.4 * (rnd(&seed) - 0.5), 0.4 * (rnd(&seed) - 0.5), -1.0};
        unit(dir);
        double t = (0.3 - eye[2]) / dir[2];
        refcast_hit h = cast(s, eye, dir);
        assert_true(fabs(h.t - t) <= 1e-11 * t);
        assert_true(fabs(h.normal[2] - 1.0) < 1e-12);
    }
    scene_free(s);
}

/* The cube max(|x|,|y|,|z|) = c against the slab-test entry distance. */
static void test_box_face(void **state)
{
    (void)state;
    const double c = 0.5;
    scene *s = parse("bounds -1 -1 -1 1 1 1\nsurface max(abs(x), abs(y), abs(z)) - 0.5\n");
    unsigned seed = 11;
    int hits = 0;
    for (int k = 0; k < 1000; k++) {
        double eye[3] = {2.0 + rnd(&seed), 1.5 * (rnd(&seed) - 0.5), 1.5 * (rnd(&seed) - 0.5)};
        double dir[3] = {-1.0, 0.6 * (rnd(&seed) - 0.5), 0.6 * (rnd(&seed) - 0.5)};
        unit(dir);
        double ta = 0.0, tb = INFINITY;
        for (int a = 0; a < 3; a++) {
            double t0 = (-c - eye[a]) / dir[a], t1 = (c - eye[a]) / dir[a];
            if (t0 > t1) {
                double x = t0;
                t0 = t1;
                t1 = x;
            }
            ta = t0 > ta ? t0 : ta;
            tb = t1 < tb ? t1 : tb;
        }
        refcast_hit h = cast(s, eye, dir);
        if (!(ta < tb - 1e-6)) {
            if (ta > tb + 1e-6)
                assert_true(isinf(h.t));
            continue;
        }
        hits++;
        assert_true(fabs(h.t - ta) <= 1e-9 * ta);
    }
    assert_true(hits > 200);
    /* straight on: the face x = 0.5 from x = 3 */
    const double eye[3] = {3.0, 0.1, -0.2}, dir[3] = {-1.0, 0.0, 0.0};
    refcast_hit h = cast(s, eye, dir);
    assert_true(fabs(h.t - 2.5) <= 1e-12 * 2.5);
    assert_true(h.normal[0] == 1.0);
    scene_free(s);
}

static void test_misses(void **state)
{
    (void)state;
    scene *s = parse("bounds -1.25 -1.25 -1.25 1.25 1.25 1.25\nsurface x^2 + y^2 + z^2 - 1\n");
    const double eye[3] = {0.0, 0.0, 4.0};
    const double away[3] = {0.0, 0.0, 1.0};           /* away from the bounds */
    const double past[3] = {0.6, 0.0, -0.8};          /* through the box corner region, past the ball */
    const double outside_box[3] = {0.8, 0.0, -0.6};   /* misses the bounds box entirely */
    assert_true(isinf(cast(s, eye, away).t));
    assert_true(isinf(cast(s, eye, outside_box).t));
    double b = eye[2] * past[2], disc = b * b - (16.0 - 1.0);
    assert_true(disc < 0.0);
    assert_true(isinf(cast(s, eye, past).t));
    /* an eye inside the ball finds the far wall */
    const double centre[3] = {0.0, 0.0, 0.0}, up[3] = {0.0, 0.0, 1.0};
    assert_true(fabs(cast(s, centre, up).t - 1.0) < 1e-12);
    scene_free(s);
}

static void test_nearest_surface_wins(void **state)
{
    (void)state;
    scene *s = parse("bounds -2 -2 -2 2 2 2\n"
                     "surface (x - 1)^2 + y^2 + z^2 - 0.25\ncolor 1 0 0\n"
                     "surface (x + 1)^2 + y^2 + z^2 - 0.25\ncolor 0 1 0\n");
    const double eye[3] = {5.0, 0.0, 0.0}, left[3] = {-1.0, 0.0, 0.0};
    refcast_hit h = cast(s, eye, left);
    assert_int_equal(h.surface, 0);
    assert_true(fabs(h.t - 3.5) < 1e-11);
    const double eye2[3] = {-5.0, 0.0, 0.0}, right[3] = {1.0, 0.0, 0.0};
    h = cast(s, eye2, right);
    assert_int_equal(h.surface, 1);
    assert_true(fabs(h.t - 3.5) < 1e-11);
    scene_free(s);
}

/* f = (z - 0.3)^2 touches 0 without changing sign: reported as a touch. */
static void test_tangential_touch(void **state)
{
    (void)state;
    scene *s = parse("bounds -1 -1 -1 1 1 1\nsurface (z - 0.3)^2\n");
    const double eye[3] = {0.1, 0.2, 2.0}, down[3] = {0.0, 0.0, -1.0};
    refcast_hit h = cast(s, eye, down);
    assert_int_equal(h.touch, 1);
    assert_true(fabs(h.t - 1.7) < 1e-6);
    scene_free(s);
}

/* Thin features: a slab 0.002 thick is found, at its near face. */
static void test_thin_slab(void **state)
{
    (void)state;
    scene *s = parse("bounds -1 -1 -1 1 1 1\nsurface abs(z - 0.1) - 0.001\n");
    double eye[3] = {0.3, -0.2, 2.0}, dir[3] = {0.05, 0.02, -1.0};
    unit(dir);
    refcast_hit h = cast(s, eye, dir);
    double t = (0.101 - eye[2]) / dir[2];
    assert_true(fabs(h.t - t) <= 1e-9 * t);
    scene_free(s);
}

/* The threaded image driver gives exactly the single-ray results. */
static void test_image_matches_rays(void **state)
{
    (void)state;
    scene *s = parse("bounds -1.25 -1.25 -1.25 1.25 1.25 1.25\nsurface x^2 + y^2 + z^2 - 1\n");
    camera cam;
    const double eye[3] = {3.0, 2.0, 1.5}, target[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    assert_int_equal(camera_init(&cam, eye, target, up, 40.0, 23, 17), CAMERA_OK);
    float depth[23 * 17], nrm[23 * 17 * 3];
    uint8_t surf[23 * 17];
    refcast_stats st;
    assert_int_equal(refcast_image(s, &cam, 2, depth, nrm, surf, &st), 0);
    int hits = 0;
    for (uint32_t j = 0; j < 17; j++)
        for (uint32_t i = 0; i < 23; i++) {
            double dir[3];
            camera_ray(&cam, i, j, dir);
            refcast_hit h = cast(s, eye, dir);
            size_t px = (size_t)j * 23 + i;
            assert_true(depth[px] == (float)h.t);
            assert_int_equal(surf[px], isinf(h.t) ? 255 : 0);
            hits += !isinf(h.t);
        }
    assert_true(hits > 50 && hits < 23 * 17);
    scene_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_closed_form),
        cmocka_unit_test(test_plane),
        cmocka_unit_test(test_box_face),
        cmocka_unit_test(test_misses),
        cmocka_unit_test(test_nearest_surface_wins),
        cmocka_unit_test(test_tangential_touch),
        cmocka_unit_test(test_thin_slab),
        cmocka_unit_test(test_image_matches_rays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
