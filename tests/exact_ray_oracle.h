/* exact_ray_oracle: the first voxel a ray occupies, in exact rational
 * arithmetic (test_trace_stress.c explains the model). The ray's grid-space
 * start o is dyadic (a multiple of 2^-FRAC_BITS), its direction d any
 * double; a plane crossing time (k - o_a) / d_a is held exactly and two are
 * compared by cross-multiplication in __int128. trace.h's tie rule applies:
 * half-open occupancy per axis, zero axes in floor(o), the root's upper face
 * in voxel N-1. */
#ifndef EXACT_RAY_ORACLE_H
#define EXACT_RAY_ORACLE_H

#include <stddef.h>
#include <stdint.h>

#define FRAC_BITS 16 /* o is a multiple of 2^-FRAC_BITS */

typedef __int128 i128;

/* A time (k - o) / d: num * 2^-FRAC_BITS / (dm * 2^de), dm > 0 (the sign of d
 * is folded into num). */
typedef struct xtime {
    i128 num;
    int64_t dm;
    int de;
} xtime;

/* An exact ray in grid space. */
typedef struct xray {
    int64_t O[3];   /* o * 2^FRAC_BITS, exact */
    int64_t dm[3];  /* |d| = dm * 2^de */
    int de[3];
    int sgn[3];     /* sign of d; 0 on a zero axis */
    double o[3], d[3];
} xray;

/* Fills r from grid-space o and d; returns 0 when o is not a multiple of
 * 2^-FRAC_BITS below 2^46 in magnitude (the oracle's range). */
int xray_init(xray *r, const double o[3], const double d[3]);

/* First voxel of the list the exact ray occupies (smallest tin). Returns the
 * index or -1; *t_out its exact entry time (long double). */
long oracle_exact(const xray *r, unsigned levels, const uint32_t (*vox)[3], size_t n,
                  long double *t_out);

#endif
