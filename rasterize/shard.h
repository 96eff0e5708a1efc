/* shard: splitting one rasterization into N independent pieces
 * (rasterize --shard I/N). The pieces are contiguous Morton ranges of the
 * cells of one depth k, cut where a cheap coarse pass says each piece holds
 * about 1/N of the work. Every shard computes the same partition: it
 * depends only on the scene, the levels and N. */
#ifndef SHARD_H
#define SHARD_H

#include <stdint.h>

#include "common/expr/scene.h"
#include "rasterize/build.h"

#define SHARD_MAX_COUNT 4096 /* N; 8^k then stays at most 2^21 cells */

/* Parses "I/N" (decimal, 0 <= I < N <= SHARD_MAX_COUNT, nothing else).
 * 0 on success, -1 otherwise. */
int shard_parse(const char *s, uint32_t *index, uint32_t *count);

/* The depth k of the partition of an N-way split at `levels`: the least k
 * with 8^k >= 64 N, at least 4, and at most levels - mv_levels (the
 * scene's build_mean_value_levels: above them the subdivision still tests
 * cells one by one) and at least 0. */
unsigned shard_depth(unsigned levels, unsigned mv_levels, uint32_t count);

/* The work estimate of each cell of depth k (8^k values, Morton order):
 * 0 for a cell no surface may cross, else 1 + the number of its
 * descendants ESTIMATE_DEPTH levels deeper (at most levels - 1) that the
 * interval test keeps. Single-threaded and deterministic. Returns 0, or -1
 * when memory runs out. */
int shard_estimate(const scene *sc, const build_params *p, unsigned depth, uint64_t *weight);

/* Cuts the weights of the ncells cells into `count` contiguous ranges:
 * bounds[i] is the first cell of range i, bounds[0] = 0, bounds[count] =
 * ncells, and bounds[i] the first cell whose running weight sum reaches
 * ceil(i W / count) (W the total). */
void shard_cut(const uint64_t *weight, uint64_t ncells, uint32_t count, uint64_t *bounds);

/* CRC-32 of the count + 1 boundaries as u64 little-endian (the header's
 * partition_crc). */
uint32_t shard_partition_crc(const uint64_t *bounds, uint32_t count);

/* The whole step: the partition of an N-way split of the scene at
 * p->levels, and shard `index`'s piece of it in *out. When share is not
 * NULL it receives the estimated fraction of the work in this piece.
 * Returns 0, or -1 when memory runs out. */
int shard_plan(const scene *sc, const build_params *p, uint32_t index, uint32_t count,
               build_shard *out, double *share);

#endif
