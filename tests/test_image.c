/* Tests for common/view/image: PFM bytes exactly as docs/INTERFACE.md, PNG read back
 * with libpng, failures leave no file. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/view/image.h"

static char dir[64];

static int setup(void **state)
{
    (void)state;
    strcpy(dir, "/tmp/test_image_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *buf = malloc(1 << 16);
    *n = fread(buf, 1, 1 << 16, f);
    fclose(f);
    return buf;
}

static void test_pfm_bytes(void **state)
{
    (void)state;
    char path[128];
    snprintf(path, sizeof path, "%s/d.pfm", dir);
    /* 2x2, rows top to bottom: {1, inf} / {0.5, -2} */
    const float v[4] = {1.0f, INFINITY, 0.5f, -2.0f};
    assert_int_equal(image_write_pfm(path, v, 2, 2, NULL), 0);
    size_t n;
    unsigned char *b = slurp(path, &n);
    assert_non_null(b);
    static const unsigned char want[] = {
        'P', 'f', '\n', '2', ' ', '2', '\n', '-', '1', '.', '0', '\n',
        0x00, 0x00, 0x00, 0x3f, 0x00, 0x00, 0x00, 0xc0, /* bottom row first: 0.5, -2 */
        0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0x80, 0x7f, /* then 1, +inf */
    };
    assert_int_equal(n, sizeof want);
    assert_memory_equal(b, want, sizeof want);
    free(b);
}

static void test_png_round_trip(void **state)
{
    (void)state;
    char path[128];
    snprintf(path, sizeof path, "%s/c.png", dir);
    uint8_t rgb[3 * 3 * 2];
    for (size_t i = 0; i < sizeof rgb; i++)
        rgb[i] = (uint8_t)(i * 13);
    assert_int_equal(image_write_png(path, rgb, 3, 2, NULL), 0);
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    assert_true(png_image_begin_read_from_file(&img, path));
    assert_int_equal(img.width, 3);
    assert_int_equal(img.height, 2);
    img.format = PNG_FORMAT_RGB;
    uint8_t back[sizeof rgb];
    assert_true(png_image_finish_read(&img, NULL, back, 0, NULL));
    assert_memory_equal(back, rgb, sizeof rgb);
}

static void test_srgb(void **state)
{
    (void)state;
    assert_int_equal(image_srgb8(0.0f), 0);
    assert_int_equal(image_srgb8(1.0f), 255);
    assert_int_equal(image_srgb8(2.0f), 255);
    assert_int_equal(image_srgb8(-1.0f), 0);
    assert_int_equal(image_srgb8(NAN), 0);
    assert_int_equal(image_srgb8(0.5f), 188); /* 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 */
}

static void test_failures_leave_nothing(void **state)
{
    (void)state;
    char path[128];
    snprintf(path, sizeof path, "%s/nodir/x.png", dir);
    const uint8_t rgb[3] = {1, 2, 3};
    const char *op = NULL;
    assert_int_equal(image_write_png(path, rgb, 1, 1, &op), -1);
    assert_non_null(op);
    assert_int_equal(access(path, F_OK), -1);
    size_t n;
    assert_int_equal(image_rgb_size(UINT32_MAX, UINT32_MAX, &n), -1); /* 5.5e19 bytes > SIZE_MAX */
    assert_int_equal(image_rgb_size(32768, 32768, &n), 0);
    assert_int_equal(n, (size_t)32768 * 32768 * 3);
    assert_int_equal(image_rgb_size(0, 5, &n), -1);
    /* a write fault through the atomic_file hook: no file left behind */
    snprintf(path, sizeof path, "%s/fault.png", dir);
    setenv("ATOMIC_FAULT", "write:1:ENOSPC", 1);
    int rc = image_write_png(path, rgb, 1, 1, &op);
    int e = errno;
    unsetenv("ATOMIC_FAULT");
    assert_int_equal(rc, -1);
    assert_int_equal(e, ENOSPC);
    assert_int_equal(access(path, F_OK), -1);
    snprintf(path, sizeof path, "%s/fault.pfm", dir);
    const float v = 1.0f;
    setenv("ATOMIC_FAULT", "fsync:1", 1);
    rc = image_write_pfm(path, &v, 1, 1, &op);
    unsetenv("ATOMIC_FAULT");
    assert_int_equal(rc, -1);
    assert_int_equal(access(path, F_OK), -1);
    /* nothing else in the directory: temporaries removed */
    char cmd[160];
    snprintf(cmd, sizeof cmd, "test -z \"$(ls -A '%s' | grep -v -e '^d.pfm$' -e '^c.png$')\"", dir);
    assert_int_equal(system(cmd), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pfm_bytes),
        cmocka_unit_test(test_png_round_trip),
        cmocka_unit_test(test_srgb),
        cmocka_unit_test(test_failures_leave_nothing),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
