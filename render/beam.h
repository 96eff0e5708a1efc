/* beam: ray coherence for a block of pixels. The rays through the centres of
 * a block of pixels all lie in one pyramid with its apex at the eye; a walk
 * of the octree's upper levels finds the occupied cells that pyramid may
 * touch and returns a window [t_lo, t_hi] of ray parameter outside which no
 * ray of the block can meet an occupied voxel. The frame then traces each
 * ray inside its window only (trace_clip), and a block whose pyramid touches
 * nothing costs no ray at all.
 *
 * Exactness. The test is conservative: a cell is rejected only when one of
 * the pyramid's five bounding half-spaces (four sides through the eye, one
 * "in front of the eye") holds none of the cell, with the cell grown on every
 * side by a margin far above the rounding of the camera's directions and of
 * the traversal's plane times. The walk works in grid units relative to the
 * eye placed as the traversal places it, so that rounding is
 * ulp(max(|eye|, N)) voxels whatever the cube's origin; the margin is 2^-12
 * voxel plus 2^-40 of that magnitude. The window is the nearest and farthest
 * distance from the eye to the kept cells, also widened. A unit ray at
 * parameter t is at distance t from the eye, so it can be in an occupied
 * voxel only inside the window: traced inside it, a ray meets the same
 * voxels at the same plane times as traced whole, and the
 * image is the same (tests/test_frame.c compares the two, byte for byte). */
#ifndef BEAM_H
#define BEAM_H

#include "common/camera.h"
#include "format/oct.h"

typedef struct beam_block {
    double u0, u1, v0, v1; /* camera_u / camera_v of the block's extreme pixel centres */
} beam_block;

/* The pixel block [i0, i1) x [j0, j1) of cam (non-empty). */
beam_block beam_block_of(const camera *cam, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1);

/* Sets *t_lo <= *t_hi (caller's t along unit rays from cam->eye) and returns
 * 1, or returns 0 when no ray of the block can meet an occupied voxel.
 * t_lo comes from the voxels themselves (the tightest start pays most), t_hi
 * from their ancestors of depth L - 3 (RENDER.md, "Beam"). Reads the tree
 * only; no allocation. */
int beam_window(const oct_tree *tree, const camera *cam, const beam_block *b, double *t_lo,
                double *t_hi);

#endif
