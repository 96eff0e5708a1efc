/* Tests for render/view_light: the pixels a shadow map made for a view will
 * serve (the views after it under the same light, up to a shadow view under
 * another light), in one backward pass, with --light and with the default
 * light that follows each camera; and the views of one part of a run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "render/view_light.h"

enum { N = 7 };

/* A run of N views, view k with shadows[k] and the camera whose default
 * light is one of two (which[k]: 0 or 1). */
static void set_run(views_view *v, camera *cams, const int *shadows, const int *which)
{
    memset(v, 0, N * sizeof *v);
    memset(cams, 0, N * sizeof *cams);
    for (int k = 0; k < N; k++) {
        v[k].width = 10 + k;
        v[k].height = 2;
        v[k].shadows = shadows[k];
        cams[k].forward[0] = which[k] ? 1.0 : -1.0;
        cams[k].up[2] = 1.0;
        cams[k].right[1] = 1.0;
    }
}

static void test_one_light(void **state)
{
    (void)state;
    static const int shadows[N] = {1, 0, 1, 1, 0, 0, 1};
    static const int which[N] = {0, 1, 0, 1, 0, 1, 0}; /* ignored: --light given */
    views_view v[N];
    camera cams[N];
    set_run(v, cams, shadows, which);
    const double light[3] = {0.0, 0.0, 3.0};
    uint64_t ahead[N];
    memset(ahead, 0xff, sizeof ahead);
    view_shadow_pixels(1, light, v, cams, N, 0, 1, ahead);
    /* pixels: 20 22 24 26 28 30 32; shadow views 0, 2, 3, 6 */
    const uint64_t want[N] = {20 + 24 + 26 + 32, 0, 24 + 26 + 32, 26 + 32, 0, 0, 32};
    assert_memory_equal(ahead, want, sizeof want);
    double l[3];
    view_light(1, light, &cams[0], l);
    assert_true(l[0] == 0.0 && l[1] == 0.0 && l[2] == 1.0);
}

static void test_lights_of_cameras(void **state)
{
    (void)state;
    static const int shadows[N] = {1, 1, 0, 1, 1, 1, 1};
    static const int which[N] = {0, 0, 0, 1, 0, 0, 1};
    views_view v[N];
    camera cams[N];
    set_run(v, cams, shadows, which);
    uint64_t ahead[N];
    view_shadow_pixels(0, NULL, v, cams, N, 0, 1, ahead);
    /* view 3's other light makes the map again: views 0-1 do not count 4-5,
       a view without shadows (2) does not: its camera's light is not asked */
    const uint64_t want[N] = {20 + 22, 22, 0, 26, 28 + 30, 30, 32};
    assert_memory_equal(ahead, want, sizeof want);
    double l0[3], l3[3];
    view_light(0, NULL, &cams[0], l0);
    view_light(0, NULL, &cams[3], l3);
    assert_true(memcmp(l0, l3, sizeof l0) != 0);
}

/* --part: views first, first + step, ...; the others untouched. */
static void test_part_of_run(void **state)
{
    (void)state;
    static const int shadows[N] = {1, 1, 1, 1, 1, 1, 1}, which[N] = {0};
    views_view v[N];
    camera cams[N];
    set_run(v, cams, shadows, which);
    uint64_t ahead[N];
    memset(ahead, 0, sizeof ahead);
    view_shadow_pixels(0, NULL, v, cams, N, 1, 3, ahead); /* views 1, 4 */
    const uint64_t want[N] = {0, 22 + 28, 0, 0, 28, 0, 0};
    assert_memory_equal(ahead, want, sizeof want);
    view_shadow_pixels(0, NULL, v, cams, N, 7, 3, ahead); /* none: untouched */
    assert_memory_equal(ahead, want, sizeof want);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_light),
        cmocka_unit_test(test_lights_of_cameras),
        cmocka_unit_test(test_part_of_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
