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
    double shadow_ns, ao_ns;
    shadow_start start; /* the last hit's secondary start: its anchor is the
                           next one's search hint (start.near) */
} frame_acc;

typedef struct frame_sync frame_sync; /* frame.c's */

/* What a thread reads while it renders: one per thread (a copy), so that
 * with --exact its job carries that thread's own exact worker. */
typedef struct frame_shared {
    const frame_job *job;
    trace_traverse_fn traverse;
    aa_probe *probes; /* centre rays, for the antialiasing pass; NULL without */
    uint8_t *tile_any; /* with probes: per tile, 1 when a centre ray hit or a
                          sub-block was marked (supersample_tile) */
    const shadow_map *shadow_map; /* with --shadows: the light's map, or NULL */
    int phase;        /* 0: centre rays; 1: samples where needed */
    uint32_t tiles_x, tiles_y;
    frame_sync *sync;
} frame_shared;

/* CLOCK_MONOTONIC in nanoseconds. */
double frame_now_ns(void);

/* frame_srgb8 once a frame_render has set its tables up. */
uint8_t frame_srgb8_ready(float x);

/* Shades a traced sample of pixel (i, j) seen along `dir`: the shadow ray,
 * AO rays k0 .. k0 + ao_count - 1 of ao_total, the colour; n gets the
 * facing normal. */
void frame_shade_sample(const frame_shared *sh, frame_acc *acc, const trace_hit *h,
                        const double dir[3], uint32_t i, uint32_t j, unsigned ao_k0,
                        unsigned ao_count, unsigned ao_total, float rgb[3], float n[3]);

/* The probes of an image of n pixels, zeroed (NULL when they cannot be
 * had), and their release (accepts NULL). */
aa_probe *frame_probes_alloc(size_t n);
void frame_probes_free(aa_probe *p, size_t n);

/* The antialiasing pass over the pixels [i0, i1) x [j0, j1) of a tile:
 * samples where the edge test asks for them. any: the tile's centre rays
 * hit or the beam marked one of its sub-blocks (else only its border
 * pixels are tested). */
void frame_supersample_tile(const frame_shared *sh, frame_acc *acc, const trace_eye *eye, int any,
                            uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1);

#endif
