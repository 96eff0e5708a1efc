/* frame_impl: what render/frame.c and render/frame_samples.c share; not
 * part of frame.h's interface. */
#ifndef FRAME_IMPL_H
#define FRAME_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "render/frame.h"
#include "render/shadow.h"

/* What a thread adds up. */
typedef struct frame_acc {
    uint64_t rays, hits, steps, aa_pixels, aa_full, shadow_rays, ao_rays, secondary_steps;
    uint64_t marked; /* sub-blocks marked by the beam's edge trigger */
    /* with timing, in frame_ticks' ticks: the secondary rays' time, and the
       antialiasing samples' less their secondary rays' */
    double shadow_tk, ao_tk, sample_tk;
    shadow_start start; /* the last hit's secondary start: its anchor is the
                           next one's search hint (start.near) */
} frame_acc;

/* A thread's probes of the tile it renders (the edge test's input). */
typedef struct frame_tile {
    uint32_t i0, j0; /* the tile's first pixel */
    aa_probe p[FRAME_TILE * FRAME_TILE]; /* pixel (i, j) at (j - j0) * FRAME_TILE + i - i0 */
} frame_tile;

/* The probes a tile keeps for the pairs that straddle two tiles, each tile
 * FRAME_BORDER of them: its top row, bottom row, left and right columns,
 * FRAME_TILE slots each (a corner is in two). */
#define FRAME_BORDER (4 * FRAME_TILE)

typedef struct frame_sync frame_sync; /* frame.c's */

/* What a thread reads while it renders: one per thread (a copy), so that
 * with --exact its job carries that thread's own exact worker. */
typedef struct frame_shared {
    const frame_job *job;
    trace_traverse_fn traverse;
    frame_tile *tile; /* with --aa: this thread's tile probes; NULL without */
    aa_probe *border; /* with tile: FRAME_BORDER probes a tile, tiles in row order */
    uint8_t *border_hit; /* with border: per tile, bit s when a probe of side s hit */
    const shadow_map *shadow_map; /* with --shadows: the light's map, or NULL */
    const struct ao_grid *ao_grid; /* with --ao: the tree's clearance grid, or NULL */
    int phase;        /* 0: centre rays, then the samples a tile's own pixels
                         ask for; 1: those the pairs across tiles ask for */
    uint32_t tiles_x, tiles_y;
    frame_sync *sync;
} frame_shared;

/* CLOCK_MONOTONIC in nanoseconds. */
double frame_now_ns(void);

/* A clock for the short intervals timed per hit and per sample: the CPU's
 * time-stamp counter where there is one (a third of clock_gettime's cost
 * here, which would otherwise be a tenth of a shadow ray's time), else
 * frame_now_ns. Its ticks become nanoseconds by the rate measured over a
 * thread's pass (frame.c's work). */
double frame_ticks(void);

/* Shades a traced sample of pixel (i, j) seen along `dir`: the shadow ray,
 * AO rays k0 .. k0 + ao_count - 1 of ao_total, the colour; n gets the
 * facing normal. */
void frame_shade_sample(const frame_shared *sh, frame_acc *acc, const trace_hit *h,
                        const double dir[3], uint32_t i, uint32_t j, unsigned ao_k0,
                        unsigned ao_count, unsigned ao_total, float rgb[3], float n[3]);

/* The probes of n tile borders (FRAME_BORDER each), NULL when they cannot
 * be had, and their release (accepts NULL). */
aa_probe *frame_border_alloc(size_t n);
void frame_border_free(aa_probe *p, size_t n);

/* The end of tile (tx, ty)'s first pass, [i0, i1) x [j0, j1), its probes
 * in sh->tile: the edge test of the pairs inside it (when `any`: a centre
 * ray hit or the beam marked a sub-block; else none differs), samples for
 * the pixels that need them, the border probes kept. */
void frame_aa_tile(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, int any,
                   uint32_t tx, uint32_t ty, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1);

/* The second pass over tile (tx, ty): samples for its border pixels that
 * only a pixel of a neighbouring tile tells apart. */
void frame_aa_border(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, uint32_t tx,
                     uint32_t ty, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1);

#endif
