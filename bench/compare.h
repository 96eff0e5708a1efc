/* compare: error statistics of a depth (and normal) image against a reference. */
#ifndef COMPARE_H
#define COMPARE_H

#include <stddef.h>
#include <stdint.h>

typedef struct compare_stats {
    size_t pixels, both_hit, disagree; /* disagree: one hits, the other misses */
    double mean, p99, max;             /* |depth error| over both_hit, in voxels */
    double nmean, np99, nmax;          /* normal angle error in degrees (NAN without normals) */
    size_t nan;                        /* test pixels with a NaN depth or normal component */
} compare_stats;

/* Compares depth images a (test) and b (reference), n pixels each (+inf =
 * miss), errors divided by `voxel`. na and nb are n*3 normals or NULL; the
 * angle ignores orientation (two-sided shading). A NaN depth counts as a
 * miss and in `nan`, as does a pixel with a NaN normal component (its angle is
 * left out). Returns 0, or -1 when out of memory. */
int compare_depth(const float *a, const float *b, size_t n, double voxel, const float *na,
                  const float *nb, compare_stats *out);

/* Hit/miss disagreement only: mask a (nonzero = hit) against depth b. */
void compare_mask(const uint8_t *a, const float *b, size_t n, compare_stats *out);

#endif
