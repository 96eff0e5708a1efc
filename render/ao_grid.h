/* ao_grid: a dense map of the tree's cells at one depth, for the any-hit
 * walk of AO rays (RENDER.md, "Ambient occlusion: the clearance grid").
 *
 * An AO ray starts on the surface and nearly always meets nothing: the
 * octree walk spends its time climbing out of the cells around its start
 * and down again into the next cells that hold some surface. The grid keeps,
 * for every cell at depth `depth` (2^shift voxels a side), either its node
 * (an occupied cell) or, for each of the eight octants of directions, its
 * clearance k >= 1: the cube of k x k x k cells with the cell as its corner,
 * reaching out on the octant's side, holds no occupied cell (k capped at
 * AO_GRID_MAX_CLEARANCE). A ray of that octant crosses such a cube in one
 * step; an occupied cell is walked through the octree from its node down to
 * its voxels (trace_occluded_grid_sse). The answers are the plain any-hit
 * walk's: both find the ray's cell from the same plane times with the same
 * tie rule (render/trace.h), and a cube the grid skips holds no voxel. */
#ifndef AO_GRID_H
#define AO_GRID_H

#include <stdint.h>

#include "format/oct.h"

/* A clearance is 4 bits: 1 .. 15 cells. */
#define AO_GRID_MAX_CLEARANCE 15u
/* The grid's depth: at most 7 (128^3 cells, 8 MiB), at least 3 levels above
 * the voxels; none for trees of under 4 levels. */
#define AO_GRID_MAX_DEPTH 7u
#define AO_GRID_MIN_SHIFT 3u

/* A cell's word: low 4 bits 0 for an occupied cell, its node index (at the
 * grid's depth) above them; else bits 4o .. 4o + 3 hold octant o's
 * clearance (o: bit a set when the rays' d_a > 0), all of them >= 1. */
#define AO_GRID_OCCUPIED(w) (((w) & 15u) == 0)
#define AO_GRID_NODE(w) ((w) >> 4)
#define AO_GRID_CLEARANCE(w, o) ((w) >> (4u * (o)) & 15u)

typedef struct ao_grid {
    unsigned depth;     /* the cells are the tree's cells at this depth */
    unsigned shift;     /* levels - depth: a cell is 2^shift voxels a side */
    uint32_t n;         /* 2^depth cells a side; 0: no grid */
    uint32_t *cell;     /* cell (x, y, z) at x + n (y + n z) */
    double near_plane;  /* 2^(levels - 40) voxels: a position this near a
                           cell's plane may fall in either cell by the
                           plane times, far above the error of both (trace.h:
                           T within 2 ulp; positions within 2^levels) */
} ao_grid;

/* The depth of tree's grid; 0 when the tree is too shallow for one (the
 * plain walk is then used). */
unsigned ao_grid_depth(const oct_tree *tree);

/* Makes tree's grid in g. Returns 0, or -1 (g zeroed) when the tree is too
 * shallow or the memory cannot be had. */
int ao_grid_build(const oct_tree *tree, ao_grid *g);

void ao_grid_free(ao_grid *g);

#endif
