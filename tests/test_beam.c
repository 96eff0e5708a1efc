/* Tests for render/beam's start boxes: every ray of a pixel block, set up
 * and clipped at t as the frame does it, starts inside the box
 * beam_start_box gives for that t, with normal cameras and with the skewed
 * ones camera_init accepts (up within a sine of 1e-9 of the view, which
 * leaves right off orthogonal to forward by up to about 1e-7). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bench/rng.h"
#include "common/view/camera.h"
#include "render/beam.h"
#include "render/trace.h"

static uint64_t rng_state = 0x2545f4914f6cdd1dULL;

static double urand(void) /* [0, 1) */
{
    return rng_unit(rng_xorshift64(&rng_state));
}

static double srand1(void) { return 2.0 * urand() - 1.0; } /* [-1, 1) */

/* The least distance from a start point to its box's faces over many
 * random blocks (the eye inside the cube, so every ray starts at t);
 * negative when one lies outside. */
static double least_slack(unsigned levels, int skewed, unsigned long *rays)
{
    oct_tree t;
    memset(&t, 0, sizeof t); /* trace_eye_init reads levels, edge, origin */
    t.levels = levels;
    t.edge = 1.0;
    double least = INFINITY;
    for (int it = 0; it < 40000; it++) {
        const double eye[3] = {0.5 + 0.45 * srand1(), 0.5 + 0.45 * srand1(), 0.5 + 0.45 * srand1()};
        const double target[3] = {0.5 + srand1(), 0.5 + srand1(), 0.5 + srand1()};
        double up[3];
        const double sk = 3.0 * srand1();
        for (int a = 0; a < 3; a++) {
            const double f = target[a] - eye[a];
            /* skewed: up along the view, off by ~1e-10..1e-8 (camera_init
             * refuses sines below 1e-9; the error peaks just above that) */
            up[a] = skewed ? f * sk + pow(10.0, -9.0 + 0.8 * srand1()) * srand1() : srand1();
        }
        const double fov = 10.0 + 160.0 * urand();
        const uint32_t w = 16 + (uint32_t)(1000 * urand()), h = 16 + (uint32_t)(1000 * urand());
        camera cam;
        trace_eye e;
        if (camera_init(&cam, eye, target, up, fov, w, h) != CAMERA_OK ||
            !trace_eye_init(&t, cam.eye, &e))
            continue;
        const uint32_t i0 = (uint32_t)(urand() * (w - 8)), j0 = (uint32_t)(urand() * (h - 8));
        const uint32_t i1 = i0 + 1 + (uint32_t)(urand() * 8), j1 = j0 + 1 + (uint32_t)(urand() * 8);
        const double tl = 0.9 * urand();
        double lo[3], hi[3];
        beam_start_box(&cam, e.o, e.scale, i0, i1, j0, j1, tl, lo, hi);
        for (uint32_t j = j0; j < j1; j++)
            for (uint32_t i = i0; i < i1; i++) {
                double d[3];
                camera_ray(&cam, i, j, d);
                trace_ray r;
                if (!trace_setup_eye(&e, d, &r) || !trace_clip(&r, tl, INFINITY))
                    continue;
                (*rays)++;
                for (int a = 0; a < 3; a++) {
                    const double p = r.o[a] + r.t_start * r.d[a];
                    least = fmin(least, fmin(p - lo[a], hi[a] - p));
                }
            }
    }
    return least;
}

static void test_start_box_holds_start_points(void **state)
{
    (void)state;
    static const unsigned levels[] = {10, 18, 20};
    for (int skewed = 0; skewed <= 1; skewed++)
        for (size_t k = 0; k < sizeof levels / sizeof levels[0]; k++) {
            unsigned long rays = 0;
            const double least = least_slack(levels[k], skewed, &rays);
            print_message("start box: levels %u, %s cameras: %lu rays, least slack %.3g voxel\n",
                          levels[k], skewed ? "skewed" : "normal", rays, least);
            assert_true(rays > 10000);
            assert_true(least > 0.0);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_start_box_holds_start_points),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
