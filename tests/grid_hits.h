/* grid_hits: the primary hits the shadow and AO tests start their rays
 * from: rays from an eye to a 40x40 grid of targets, each hit with its
 * voxel's normal turned toward the eye. */
#ifndef GRID_HITS_H
#define GRID_HITS_H

#include "format/oct.h"
#include "render/trace.h"

enum { GRID_HITS_SIDE = 40 };

/* Traces the ray from `eye` to grid target (x, y). Returns 1 with `h` and
 * `n` (the hit voxel's normal facing the eye) set, 0 when the ray misses. */
int grid_hit(const oct_tree *t, const trace_opts *o, const double eye[3], int x, int y,
             trace_hit *h, float n[3]);

#endif
