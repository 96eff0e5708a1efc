/* frame: renders one view of a tree into caller-owned buffers on N threads;
 * tiles are handed out through an atomic counter, every pixel is computed
 * the same way whatever thread takes it, so output is byte-identical for
 * any thread count. */
#ifndef FRAME_H
#define FRAME_H

#include <stdint.h>

#include "common/view/camera.h"
#include "format/oct.h"
#include "render/aa.h"
#include "render/ao_grid.h"
#include "render/exact_scene.h"
#include "render/shade.h"
#include "render/shadow_map.h"
#include "render/trace.h"
#include "render/trace_impl.h"

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
    unsigned aa;        /* 2..AA_MAX: N x N samples for the pixels that need them
                           (aa.h); 0 or 1: one ray a pixel */
    uint8_t *alpha;     /* width*height coverage bytes (255 * hit samples / samples,
                           rounded), or NULL; with it, rgb is the covered part's
                           colour (straight alpha) and misses are black */
    int no_beam_edge;   /* 1: without the beam's edge trigger (aa.h), only the
                           neighbour test chooses the pixels to sample (tests) */
    int no_packets;     /* 1: every antialiasing sample traced alone, not in
                           packets (trace_packet.h; tests compare the two) */
    trace_traverse_fn traverse; /* NULL: the build's preferred implementation */
    struct frame_keep *keep; /* what is kept from frame to frame; NULL: all made and
                                freed in the frame */
    uint64_t shadow_pixels; /* with shadows: the pixels of this frame and of the frames
                               to come under the same light, whose rays the shadow map
                               will serve (shadow_map_up_for); 0: this frame's */
    int timing;         /* 1: time the secondary rays apart (frame_stats) */
    /* Called by the calling thread after each tile it finishes, with tiles
     * done so far and the total; may be NULL. */
    void (*progress)(void *ctx, uint64_t done, uint64_t total);
    void *progress_ctx;
} frame_job;

/* What a run of frames keeps from one to the next (render's views loop):
 * the light's shadow map, made again only for another light or when a
 * finer one is wanted (shadow_map_cached), the antialiasing pass's tile
 * border probes, grown as the images do (a mapping made anew each frame
 * costs a page fault a page), and --exact's workers with the sub-cells and
 * a-priori bounds they made (what they hold changes the work, never a
 * result: exact_sub.h, exact_scene.h). Zeroed to start; frame_keep_free at
 * the end, before the tree and scene it was used with go (they are known
 * by their address). */
typedef struct frame_keep {
    shadow_map_cache maps;
    ao_grid grid;          /* with --ao: grid_tree's clearance grid (n = 0: none) */
    const oct_tree *grid_tree; /* the tree the grid was made for, or NULL */
    aa_probe *border;      /* border_tiles tiles' probes, or NULL */
    uint8_t *border_hit;   /* a byte a tile */
    size_t border_tiles;
    exact_worker *exact;   /* exact_n workers for the scene exact_scene, or NULL */
    unsigned exact_n;
    const exact_scene *exact_scene;
} frame_keep;

void frame_keep_free(frame_keep *k);

typedef struct frame_stats {
    uint64_t rays, hits, steps; /* primary rays (centre rays and samples), centre rays
                                   that hit, their DDA steps */
    uint64_t aa_pixels;         /* pixels traced again with samples (the edge test) */
    uint64_t aa_full;           /* of those, with all N x N (their corners disagreed) */
    uint64_t shadow_rays, ao_rays, secondary_steps;
    uint64_t samples;           /* of the primary rays, the antialiasing samples */
    double primary_ns, secondary_ns; /* with job->timing: thread time summed over
                                        threads, spent on each kind of ray */
    double centre_ns, sample_ns;     /* primary_ns in two: centre rays, samples (each
                                        pass's time but its secondary rays') */
    double shadow_ns, ao_ns;         /* secondary_ns in two (a hit's shared start
                                        counts as its shadow ray's when it has one) */
    /* --exact: the occupied voxels the rays reached, tested for a root (of
     * them by interval bisection, the certified path undecided) or passed
     * inside a span certified root-free; the hits placed past the voxel
     * tested (exact_scene.h) */
    uint64_t exact_tests, exact_bisected, exact_passed, exact_beyond;
    int file_changed; /* the mapped file changed under a thread (map_guard.h): image incomplete */
} frame_stats;

/* Returns 0, or an errno value when a thread could not be started (the
 * frame is then rendered by the threads that did start); -1 before
 * rendering anything when --exact's per-thread scratch cannot be had. */
int frame_render(const frame_job *job, frame_stats *stats);

/* image_srgb8(x), bit for bit, by tables of buckets and thresholds (no
 * pow): what frame_render writes. Thread-safe. */
uint8_t frame_srgb8(float x);

#endif
