/* frame: renders one view of a tree into caller-owned buffers on N threads;
 * tiles are handed out through an atomic counter, every pixel is computed
 * the same way whatever thread takes it, so output is byte-identical for
 * any thread count. */
#ifndef FRAME_H
#define FRAME_H

#include <stdint.h>

#include "common/view/camera.h"
#include "format/oct.h"
#include "render/exact_scene.h"
#include "render/shade.h"
#include "render/trace.h"

#define FRAME_TILE 32 /* pixels a tile side */
#define FRAME_BEAM_DEFAULT 32 /* beam block side: fewest instructions measured (docs/perf-log.md) */

typedef struct frame_job {
    const oct_tree *tree;
    const camera *cam;
    trace_opts opts;    /* opts.exact is set per thread from `exact` */
    const exact_scene *exact; /* not NULL: --exact */
    shade_params shade;
    uint8_t *rgb;       /* width*height*3 sRGB bytes, rows top to bottom; required */
    float *depth;       /* width*height t values (+inf on miss), or NULL */
    uint8_t *normals;   /* width*height*3 bytes, (n + 1) / 2 per channel, or NULL */
    float *normals_f;   /* width*height*3 floats, the unit normal (0 on miss), or NULL */
    unsigned threads;   /* >= 1 */
    unsigned beam_size; /* pixel block side of the beam test (beam.h), 1..FRAME_TILE;
                           0: every ray traced whole */
    /* Called by the calling thread after each tile it finishes, with tiles
     * done so far and the total; may be NULL. */
    void (*progress)(void *ctx, uint64_t done, uint64_t total);
    void *progress_ctx;
} frame_job;

typedef struct frame_stats {
    uint64_t rays, hits, steps; /* steps: DDA steps, all rays */
} frame_stats;

/* Returns 0, or an errno value when a thread could not be started (the
 * frame is then rendered by the threads that did start); -1 before
 * rendering anything when --exact's per-thread scratch cannot be had. */
int frame_render(const frame_job *job, frame_stats *stats);

/* image_srgb8(x), bit for bit, by tables of buckets and thresholds (no
 * pow): what frame_render writes. Thread-safe. */
uint8_t frame_srgb8(float x);

#endif
