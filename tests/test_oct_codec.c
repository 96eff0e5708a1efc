/* The voxel record codecs: the 24-bit normal (format/oct_normal.c) and the
 * plane offset. */

/* The bound FORMAT.md states for the 24-bit normal ("Voxel record"). */
#define NORMAL_MAX_ERROR_DEG 0.06

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "format/oct.h"
#include "format/oct_normal.h"
#include "bench/oct_synth.h"
#include "bench/rng.h"

static void test_normal_codec_error(void **state)
{
    (void)state;
    uint64_t rs = 12345;
    double worst = 0.0;
    for (int i = 0; i < 2000000; i++) {
        double v[3], l;
        do { /* uniform on the sphere by rejection */
            for (int k = 0; k < 3; k++)
                v[k] = rng_unit(test_rand(&rs)) * 2.0 - 1.0;
            l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        } while (l > 1.0 || l < 1e-3);
        for (int k = 0; k < 3; k++)
            v[k] /= l;
        if (i < 64) { /* the axes, diagonals and fold edges, where errors peak */
            static const double e[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1},
                                          {1, 1, 0}, {1, -1, 0}, {0, 1, -1}, {1, 1, -1}, {-1, -1, -1}};
            const double *a = e[i % 11];
            double al = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
            for (int k = 0; k < 3; k++)
                v[k] = a[k] / al;
        }
        uint32_t code = oct_normal_encode(v);
        assert_true(code <= OCT_VOXEL_NORMAL_MASK);
        float n[3];
        oct_normal_decode(code, n);
        double dot = (double)n[0] * v[0] + (double)n[1] * v[1] + (double)n[2] * v[2];
        double cross[3] = {n[1] * v[2] - n[2] * v[1], n[2] * v[0] - n[0] * v[2], n[0] * v[1] - n[1] * v[0]};
        double ang = atan2(sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]), dot);
        if (ang > worst)
            worst = ang;
        double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        assert_true(fabs(nl - 1.0) < 1e-6);
    }
    double deg = worst * 180.0 / M_PI;
    print_message("normal codec: max angular error %.4f degrees over 2e6 unit vectors\n", deg);
    assert_true(deg < NORMAL_MAX_ERROR_DEG);
    /* Degenerate input encodes +z. */
    double z[3] = {0, 0, 0}, nanv[3] = {NAN, 0, 0};
    float n[3];
    oct_normal_decode(oct_normal_encode(z), n);
    assert_true(n[2] > 0.99999f);
    oct_normal_decode(oct_normal_encode(nanv), n);
    assert_true(n[2] > 0.99999f);
}

static void test_offset_codec(void **state)
{
    (void)state;
    for (int q = -127; q <= 127; q++)
        assert_int_equal(oct_offset_encode(oct_offset_decode((int8_t)q)), q);
    for (double d = -0.99; d < 0.99; d += 0.001) {
        double back = oct_offset_decode(oct_offset_encode(d));
        assert_true(fabs(back - d) <= 0.5 * OCT_OFFSET_UNIT + 1e-12);
    }
    assert_int_equal(oct_offset_encode(5.0), 127);
    assert_int_equal(oct_offset_encode(-5.0), -127); /* never -128: reserved */
    assert_int_equal(oct_offset_encode(NAN), -127);
    double nz[3] = {0, 0, 1};
    uint32_t rec = oct_voxel_pack(nz, -0.25);
    assert_int_equal((int8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT), -32);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normal_codec_error),
        cmocka_unit_test(test_offset_codec),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
