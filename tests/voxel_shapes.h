/* voxel_shapes: small analytic scenes voxelized for the tests of shadows,
 * ambient occlusion and antialiasing: every voxel a shape's surface meets,
 * with the shape's normal and plane offset, as the rasterizer stores them. */
#ifndef VOXEL_SHAPES_H
#define VOXEL_SHAPES_H

#include <stdint.h>

#include "format/oct.h"

/* A shape in grid units (the cube is [0, 2^levels]^3). */
typedef enum shape_kind { SHAPE_PLANE, SHAPE_SPHERE } shape_kind;
typedef struct shape {
    shape_kind kind;
    double n[3], d;   /* plane n . p = d (n unit) */
    double c[3], r;   /* sphere |p - c| = r */
    double lo[3], hi[3]; /* only voxels whose centre lies in this box */
    uint8_t surface;
} shape;

/* Voxelizes `count` shapes (a voxel met by several keeps the first) into a
 * tree of `levels` levels over the cube origin (0,0,0), edge `edge`, one
 * palette colour a surface (white). Returns NULL on allocation failure. */
oct_tree *shapes_build(unsigned levels, double edge, const shape *shapes, unsigned count,
                       unsigned surface_count);

/* A plane shape over the whole cube. */
shape shape_plane(double nx, double ny, double nz, double d);
/* A sphere shape. */
shape shape_sphere(double cx, double cy, double cz, double r);

#endif
