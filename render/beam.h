/* beam: ray coherence for a block of pixels. The rays through the squares
 * of a block of pixels (centre rays and antialiasing samples) all lie in one
 * pyramid with its apex at the eye, bounded by the block's outer pixel
 * edges, and those of each of its sub-blocks in a smaller one. One walk of the octree
 * finds, for every sub-block, the nearest distance at which its pyramid may
 * touch an occupied voxel: before that t_lo no ray of the sub-block can meet
 * one. The frame then traces each ray from its t_lo only (trace_clip); a
 * sub-block, or a block, whose pyramid touches nothing costs no ray at all.
 *
 * Exactness. The test is conservative: a cell is rejected only when one of
 * the bounding half-spaces (four sides through the eye, one "in front of the
 * eye"; for a sub-block, also the planes through the eye halfway between its
 * pixel centres and its neighbours') holds none of the cell, with the cell
 * grown on every side by a margin far above the rounding of the camera's
 * directions and of the traversal's plane times. The walk works in grid
 * units relative to the eye placed as the traversal places it, so that
 * rounding is ulp(max(|eye|, N)) voxels whatever the cube's origin; the
 * margin is 2^-12 voxel plus 2^-40 of that magnitude. The distances are
 * widened too. A unit ray at parameter t is at distance t from the eye, so
 * it can be in an occupied voxel only after its t_lo: traced from there,
 * a ray meets the same voxels at the same plane times as traced whole, and
 * the image is the same (tests/test_frame.c compares the two, byte for
 * byte). */
#ifndef BEAM_H
#define BEAM_H

#include "common/view/camera.h"
#include "format/oct.h"

#define BEAM_GRID 4 /* sub-blocks a block side, each with its own start */

typedef struct beam_grid {
    unsigned cols, rows;         /* sub-blocks across and down, 1..BEAM_GRID */
    uint32_t col[BEAM_GRID + 1]; /* sub-block column c: pixels [col[c], col[c + 1]) */
    uint32_t row[BEAM_GRID + 1];
    double t_lo[BEAM_GRID][BEAM_GRID]; /* [row][column]; +inf: none of its rays meets a voxel */
} beam_grid;

/* Splits the pixel block [i0, i1) x [j0, j1) (non-empty) into up to
 * BEAM_GRID x BEAM_GRID sub-blocks and returns 1 with, for each, the t
 * (caller's t along unit rays from cam->eye) before which none of its rays
 * can meet an occupied voxel; returns 0 when no ray of the block can meet
 * one. The starts come from the voxels themselves, found for all
 * sub-blocks in one walk (RENDER.md, "Beam"). Reads the tree only; no
 * allocation. */
int beam_starts(const oct_tree *tree, const camera *cam, uint32_t i0, uint32_t i1, uint32_t j0,
                uint32_t j1, beam_grid *grid);

/* A box (grid units) holding the point at distance t (the caller's t along
 * unit rays) of every ray through the pixel centres [i0, i1) x [j0, j1)
 * from the eye at grid position o, scale grid units a caller unit; grown by
 * a margin far above the rounding of those points as the traversal
 * computes them. For trace_anchor_find. */
void beam_start_box(const camera *cam, const double o[3], double scale, uint32_t i0, uint32_t i1,
                    uint32_t j0, uint32_t j1, double t, double lo[3], double hi[3]);

/* The same for the rays whose camera (u, v) lie in [u0, u1] x [v0, v1]
 * (u0 <= u1, v0 <= v1; beam_start_box's rectangle is its pixel centres'). */
void beam_start_box_uv(const camera *cam, const double o[3], double scale, double u0, double u1,
                       double v0, double v1, double t, double lo[3], double hi[3]);

#endif
