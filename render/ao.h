/* ao: ambient occlusion. From the start point of render/shadow.h, rays over
 * the hemisphere of the viewer-facing normal, cosine-weighted, each up to a
 * distance given as a fraction of the cube's edge (--ao-distance, 1/8 by
 * default); the ambient term is scaled by the fraction that meet nothing
 * (RENDER.md, "Ambient occlusion").
 *
 * Directions: ray k of M is u_k = (k + 1/2) / M (stratified in cos^2 of the
 * angle to the normal: cosine weighting), azimuth 2 pi frac(k phi) + 2 pi s
 * with phi the golden ratio's fraction and s = seed / 2^32 from a hash of
 * the pixel: a fixed pattern (its azimuths' cos and sin made once), turned
 * from pixel to pixel (one cos and sin a hit), the same whatever thread
 * traces it. cos = sqrt(1 - u_k) >= sqrt(1 / (2M)) > 0: every ray leaves
 * the surface's side, so a plane alone occludes none (factor 1 exactly). */
#ifndef AO_H
#define AO_H

#include <stdint.h>

#include "format/oct.h"
#include "render/trace.h"
#include "render/trace_impl.h"

#define AO_MAX_RAYS 4096  /* --ao 0..AO_MAX_RAYS */

/* The per-pixel rotation seed of pixel (i, j) (a 32-bit hash). */
uint32_t ao_seed(uint32_t i, uint32_t j);

/* Direction of ray k of M (k < M) over the hemisphere of unit n, rotated by
 * `seed`, in d[3] (unit). */
void ao_direction(const float n[3], unsigned k, unsigned m, uint32_t seed, double d[3]);

/* ao_direction in two parts: the hemisphere's frame for n and the pixel's
 * turn by `seed` once (ao_basis), then each ray in it (ao_direction_in):
 * the same operations on the same values, so the same bits. */
typedef struct ao_frame {
    double t[3], b[3], n[3];
    double cs, ss; /* cos and sin of the pixel's turn */
} ao_frame;
void ao_basis(const float n[3], uint32_t seed, ao_frame *f);
void ao_direction_in(const ao_frame *f, unsigned k, unsigned m, double d[3]);

/* The unoccluded fraction of rays k0 .. k0 + count - 1 of M from the world
 * point o (shadow_origin's) over unit n, each `reach` cube edges long:
 * (rays meeting nothing) / count, count >= 1. Adds the rays' DDA steps to
 * *steps. */
float ao_factor(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                const double o[3], const float n[3], unsigned k0, unsigned count, unsigned m,
                uint32_t seed, double reach, uint64_t *steps);

/* 1 when AO rays under opts and traverse walk through the clearance grid
 * (render/ao_grid.h) if one is given: the paper's rule and the SSE any-hit
 * walk. */
int ao_grid_wanted(const trace_opts *opts, trace_traverse_fn traverse);

struct shadow_start; /* render/shadow.h */
struct ao_grid;      /* render/ao_grid.h */

/* ao_factor from a hit's shared start (shadow_start_hit's), its rays
 * started at its anchor, or (grid not NULL, the SSE any-hit walk in use)
 * walked through the tree's clearance grid: the same factor (the steps
 * differ with a grid). */
float ao_factor_from(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                     const struct shadow_start *s, const float n[3], unsigned k0, unsigned count,
                     unsigned m, uint32_t seed, double reach, const struct ao_grid *grid,
                     uint64_t *steps);

#endif
