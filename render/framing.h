/* framing: the default camera. Without --eye and --target a view aims at
 * the centre of the box of the occupied voxels (as far as the octree's top
 * levels tell it: the occupied cells of depth FRAMING_DEPTH, at most 1/64 of
 * the cube larger on a side) from the direction of the benchmark view, far
 * enough that the box's bounding sphere fits the field of view. An empty
 * tree frames the whole cube. */
#ifndef FRAMING_H
#define FRAMING_H

#include "format/oct.h"
#include "render/views.h"

#define FRAMING_DEPTH 6

/* The occupied cells' box (world units) in lo, hi; 0 for an empty tree. */
int framing_occupied_box(const oct_tree *tree, double lo[3], double hi[3]);

/* Sets v's target and eye where v does not have them. */
void framing_default_view(const oct_tree *tree, views_view *v);

#endif
