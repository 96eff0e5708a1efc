/* shadow_map: where a shadow ray towards a directional light is past every
 * occupied cell (RENDER.md, "Shadows"). A ray parallel to the light projects
 * to one point of the plane across it; the map holds, per square of that
 * plane (a texel, as wide as a cell), the greatest height along the light of
 * any occupied cell of its depth whose projection meets the texel (the box
 * of the projected corners of the cell, or above the voxels of its occupied
 * children, and their top, grown by SHADOW_MAP_MARGIN).
 * A ray whose height has passed its texel's value meets no occupied voxel
 * after that: its shadow test can stop there with the same answer. */
#ifndef SHADOW_MAP_H
#define SHADOW_MAP_H

#include <stdint.h>

#include "format/oct.h"

#define SHADOW_MAP_MAX_DEPTH 10  /* cells no deeper (a coarse map's: 9): under
                                    1 800 texels a side */
#define SHADOW_MAP_FINE 0        /* `up`: cells of depth levels - up, the voxels */
#define SHADOW_MAP_COARSE 2      /* cells of 4 voxels a side */
#define SHADOW_MAP_MARGIN 0x1p-6 /* grid units: far above the roundings of the
                                    projections, the heights and the traversal's
                                    plane times (each under 2^-26 of a voxel) */

typedef struct shadow_map {
    double light[3];        /* the direction it was made for, as given */
    double u[3], v[3], w[3]; /* the plane's axes and the unit light, orthonormal */
    double u0, v0;          /* the plane's origin: the cube's projections start there */
    double inv_texel;       /* 1 / texel side, grid units */
    unsigned depth;         /* of its cells */
    uint32_t nu, nv;
    float *top;             /* nu * nv greatest heights rounded up, -inf: none */
} shadow_map;

/* The depth of the cells of a map `up` levels above the voxels (at least 1,
 * at most SHADOW_MAP_MAX_DEPTH, or one less for a coarse map). */
unsigned shadow_map_depth(const oct_tree *tree, unsigned up);

/* The map worth making for `pixels` pixels to come under one light (the
 * frames that will share it): SHADOW_MAP_FINE from one pixel a voxel on
 * when the map can hold the voxels (levels <= SHADOW_MAP_MAX_DEPTH), else
 * SHADOW_MAP_COARSE. The fine map costs some 10 ns a voxel more to make
 * (one core) and answers most lit shadow rays where they start, some 300
 * instructions fewer a ray: on blobs_a levels 10 at 1024², three frames
 * about break even (docs/perf-log.md). */
unsigned shadow_map_up_for(const oct_tree *tree, uint64_t pixels);

/* Makes m for tree and the unit-or-not light direction `light` (finite,
 * non-zero), cells `up` levels above the voxels (shadow_map_depth), on up
 * to `threads` threads (the same map whatever their number: each takes
 * whole subtrees into a map of its own, the maps are merged by their
 * maximum). Returns 0, or -1 when the memory cannot be had (m->top NULL:
 * then shadow_map_clear_t gives +inf). Free with shadow_map_free. */
int shadow_map_build(const oct_tree *tree, const double light[3], unsigned up, unsigned threads,
                     shadow_map *m);
void shadow_map_free(shadow_map *m); /* accepts a failed build */

/* The map of the last frame, kept for the next ones: a map depends on the
 * tree and the light alone, so the views of one file under one --light (a
 * views file, an orbit) make it once. */
typedef struct shadow_map_cache {
    const oct_tree *tree; /* NULL: none kept */
    shadow_map map;
} shadow_map_cache;

/* The map of tree and light: c's when it was made for both (the light's
 * bits) with cells at least as deep as `up` asks, else made anew into c on
 * up to `threads` threads (*built = 1).
 * NULL when the memory cannot be had (then rays go without a map). c must
 * start zeroed; free with shadow_map_cache_free. */
const shadow_map *shadow_map_cached(shadow_map_cache *c, const oct_tree *tree,
                                    const double light[3], unsigned up, unsigned threads,
                                    int *built);
void shadow_map_cache_free(shadow_map_cache *c);

/* For the ray g + t (scale * light), g a grid point and scale the tree's
 * N / edge: a t after which the ray meets no occupied voxel (-inf when it
 * meets none at all, +inf when the map cannot tell: light not m's, no map). */
double shadow_map_clear_t(const shadow_map *m, const double g[3], const double light[3],
                          double scale);

#endif
