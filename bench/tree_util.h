/* tree_util: builds owned in-memory oct_tree views from voxel lists, for
 * tests and benchmarks (no file, no reader). */
#ifndef TREE_UTIL_H
#define TREE_UTIL_H

#include <stddef.h>
#include <stdint.h>

#include "format/oct.h"

/* Builds a tree of `levels` (1..OCT_MAX_LEVELS) levels over origin/edge from
 * n voxel coordinates xyz[i] (each < 2^levels; any order; duplicates keep
 * the first). attrs[i] is voxel i's 32-bit record (NULL: all 0, i.e. the
 * +z-ish normal code 0, offset 0); surfaces[i] its surface index (NULL: all
 * 0). palette holds surface_count RGB triples (NULL: grey for all).
 * Returns NULL on bad arguments or allocation failure. Free with
 * tree_util_free. */
oct_tree *tree_util_build(unsigned levels, const double origin[3], double edge,
                          const uint32_t (*xyz)[3], size_t n, const uint32_t *attrs,
                          const uint8_t *surfaces, unsigned surface_count, const float *palette);

/* Same, unit cube at the origin, one surface, attrs all 0. */
oct_tree *tree_util_simple(unsigned levels, const uint32_t (*xyz)[3], size_t n);

void tree_util_free(oct_tree *t); /* accepts NULL */

/* Up to n distinct voxels drawn from [lo, lo + width)^3 into xyz, each
 * coordinate rng_xorshift64star(rng_state) % width (bench/rng.h); a repeat
 * is dropped. Returns how many were kept. */
size_t tree_util_distinct_voxels(size_t n, uint32_t lo, uint32_t width, uint64_t *rng_state,
                                 uint32_t (*xyz)[3]);

/* Morton code of (x, y, z): bit i of x goes to bit 3i (x + 2y + 4z order). */
uint64_t tree_util_morton(uint32_t x, uint32_t y, uint32_t z);

#endif
