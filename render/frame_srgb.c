/* frame_srgb: image_srgb8 without pow. The code value is the number of
 * thresholds at or below the input, where threshold k is the least float
 * whose image_srgb8 is >= k (found by bisection over the float bit
 * patterns, image_srgb8 being monotone). The count starts at the code of
 * the input's bucket [i, i + 1) / 4096 (i / 4096 is exact, so that code is
 * a lower bound) and steps past the one or two thresholds inside the
 * bucket. Bit for bit image_srgb8, NaN and out-of-range inputs included;
 * tests/test_frame.c compares the two over every float in [0, 1]. */
#include "render/frame_srgb.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

#include "common/view/image.h"
#include "render/frame.h"

float frame_srgb_threshold[257];
uint8_t frame_srgb_bucket[FRAME_SRGB_BUCKETS + 1];
static pthread_once_t srgb_once = PTHREAD_ONCE_INIT;

static float float_of_bits(uint32_t b)
{
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

static void srgb_init(void)
{
    frame_srgb_threshold[0] = -INFINITY;
    for (unsigned k = 1; k < 256; k++) {
        uint32_t lo = 0, hi = 0x3f800000u; /* image_srgb8(1.0f) == 255 >= k */
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (image_srgb8(float_of_bits(mid)) >= k)
                hi = mid;
            else
                lo = mid + 1;
        }
        frame_srgb_threshold[k] = float_of_bits(lo);
    }
    frame_srgb_threshold[256] = NAN; /* no x is >= it, +inf included */
    for (unsigned i = 0; i <= FRAME_SRGB_BUCKETS; i++)
        frame_srgb_bucket[i] = image_srgb8((float)i / FRAME_SRGB_BUCKETS);
}

void frame_srgb_setup(void) { pthread_once(&srgb_once, srgb_init); }

uint8_t frame_srgb8(float x)
{
    frame_srgb_setup();
    return frame_srgb8_ready(x);
}
