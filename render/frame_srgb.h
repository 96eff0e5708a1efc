/* frame_srgb: image_srgb8 without pow, bit for bit, by tables of buckets
 * and thresholds (what the frames write; see frame_srgb.c). The tables are
 * made once (frame_srgb_setup, or frame_srgb8's first call); the inline
 * lookup is for the per-pixel paths that run after that. */
#ifndef FRAME_SRGB_H
#define FRAME_SRGB_H

#include <stdint.h>

#define FRAME_SRGB_BUCKETS 4096
extern float frame_srgb_threshold[257];                     /* [256] = NaN ends the count */
extern uint8_t frame_srgb_bucket[FRAME_SRGB_BUCKETS + 1];

/* Makes the tables, once for the process; thread-safe. */
void frame_srgb_setup(void);

/* frame_srgb8 once frame_srgb_setup has run. */
static inline uint8_t frame_srgb8_ready(float x)
{
    if (!(x > 0.0f)) /* misses on a black background, NaN */
        return 0;
    unsigned k = frame_srgb_bucket[x < 1.0f ? (unsigned)(x * FRAME_SRGB_BUCKETS)
                                              : FRAME_SRGB_BUCKETS];
    while (x >= frame_srgb_threshold[k + 1])
        k++;
    return (uint8_t)k;
}

#endif
