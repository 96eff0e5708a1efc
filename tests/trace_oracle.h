/* trace_oracle: what the trace tests share. The brute-force tie-rule oracle
 * (trace.h's rule, every voxel slab-tested with trace_plane_time) and casts
 * that run every traversal implementation built into the binary
 * (render/trace_impl.h) and insist they agree bit for bit, so that each
 * oracle comparison checks all of them. No cmocka: the fuzz
 * targets link it too. */
#ifndef TRACE_ORACLE_H
#define TRACE_ORACLE_H

#include <stddef.h>
#include <stdint.h>

#include "bench/rng.h" /* the tests' random numbers: rng_xorshift64star */
#include "render/trace.h"

/* The first voxel of the list whose occupancy interval under the tie rule
 * is non-empty and starts at or after local 0. Returns the list index or -1;
 * *t_out is the local entry time (+inf on a miss). */
long trace_oracle_first(const trace_ray *r, unsigned levels, const uint32_t (*vox)[3], size_t n,
                        double *t_out);

/* trace_ray_cast, trace_ray_prepared and trace_ray_anchored run on every
 * implementation; aborts with a message when two differ in hit, voxel, xyz,
 * t or steps. Under the paper's rule each implementation's any-hit walk
 * (trace_impl.h) runs too, from the anchor and from the root, and must give
 * the traversal's answer with one step count for all. The result is the
 * implementation in use's. */
int trace_cast_all(const oct_tree *tree, const trace_opts *opts, const double eye[3],
                   const double dir[3], trace_hit *hit);
int trace_prepared_all(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       trace_hit *hit);
int trace_anchored_all(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *a, trace_hit *hit);

#endif
