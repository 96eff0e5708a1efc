/* Tests for bench/pfm and bench/compare: 1- and 3-channel PFM round trips
 * through the common writers, and error statistics on hand-made images. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "bench/compare.h"
#include "bench/pfm.h"
#include "common/view/image.h"

static void test_pfm_round_trip(void **state)
{
    (void)state;
    char path[] = "/tmp/test_compare_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    const float d[6] = {1.0f, INFINITY, 0.25f, -2.0f, 3.5f, 0.0f}; /* 3x2 */
    assert_int_equal(image_write_pfm(path, d, 3, 2, NULL), 0);
    pfm_image img;
    const char *why = NULL;
    assert_int_equal(pfm_read(path, &img, &why), 0);
    assert_int_equal(img.width, 3);
    assert_int_equal(img.height, 2);
    assert_int_equal(img.channels, 1);
    for (int i = 0; i < 6; i++)
        assert_true(img.data[i] == d[i]);
    pfm_free(&img);
    float n[12];
    for (int i = 0; i < 12; i++)
        n[i] = (float)i - 5.5f;
    assert_int_equal(image_write_pfm_rgb(path, n, 2, 2, NULL), 0);
    FILE *f = fopen(path, "rb");
    char magic[3] = {0};
    assert_int_equal(fread(magic, 1, 2, f), 2);
    fclose(f);
    assert_string_equal(magic, "PF");
    assert_int_equal(pfm_read(path, &img, &why), 0);
    assert_int_equal(img.channels, 3);
    for (int i = 0; i < 12; i++)
        assert_true(img.data[i] == n[i]);
    pfm_free(&img);
    f = fopen(path, "wb");
    fputs("Pf\n2 2\n-1.0\n\1\2\3", f);
    fclose(f);
    assert_int_equal(pfm_read(path, &img, &why), -1);
    assert_string_equal(why, "truncated");
    unlink(path);
}

static void test_depth_stats(void **state)
{
    (void)state;
    /* 4 pixels: errors 0.5 and 1.5 voxels, one disagreement, one shared miss */
    const float a[4] = {1.0f, 2.0f, 3.0f, INFINITY};
    const float b[4] = {1.005f, 2.015f, INFINITY, INFINITY};
    const float na[12] = {0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0};
    const float nb[12] = {0, 0, -1, 0.70710678f, 0.70710678f, 0, 0, 0, 0, 0, 0, 0};
    compare_stats st;
    assert_int_equal(compare_depth(a, b, 4, 0.01, na, nb, &st), 0);
    assert_int_equal(st.both_hit, 2);
    assert_int_equal(st.disagree, 1);
    assert_true(fabs(st.mean - 1.0) < 1e-4);
    assert_true(fabs(st.max - 1.5) < 1e-4);
    assert_true(fabs(st.p99 - 1.5) < 1e-4);
    assert_true(fabs(st.nmean - 22.5) < 1e-3); /* 0 (flipped) and 45 degrees */
    assert_true(fabs(st.np99 - 45.0) < 1e-3);
    assert_true(fabs(st.nmax - 45.0) < 1e-3);
    assert_int_equal(st.nan, 0);
    const uint8_t m[4] = {1, 0, 1, 1};
    compare_mask(m, b, 4, &st);
    assert_int_equal(st.disagree, 3); /* pixels 1, 2 and 3 */
}

/* A NaN depth is a miss and counted; a NaN normal is counted and left out of
 * the angles. */
static void test_nan_pixels(void **state)
{
    (void)state;
    const float a[3] = {NAN, 2.0f, 3.0f};
    const float b[3] = {1.0f, 2.0f, 3.0f};
    const float na[9] = {0, 0, 1, NAN, 0, 0, 0, 1, 0};
    const float nb[9] = {0, 0, 1, 1, 0, 0, 0, 0.70710678f, 0.70710678f};
    compare_stats st;
    assert_int_equal(compare_depth(a, b, 3, 1.0, na, nb, &st), 0);
    assert_int_equal(st.nan, 2);
    assert_int_equal(st.disagree, 1);
    assert_int_equal(st.both_hit, 2);
    assert_true(fabs(st.nmean - 45.0) < 1e-3);
    assert_true(fabs(st.nmax - 45.0) < 1e-3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pfm_round_trip),
        cmocka_unit_test(test_depth_stats),
        cmocka_unit_test(test_nan_pixels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
