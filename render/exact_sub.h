/* exact_sub: Hessian bounds and pruned tapes per sub-cell of a coarse cell,
 * made on first use by each worker, for the candidates whose bound over the
 * whole coarse cell is +inf because min/max operands overlap somewhere in
 * it or f may be undefined there (not where an abs of an operand that
 * changes sign there is left: exact_sub_wanted). A sub-cell where the
 * kink's operands separate gets the tape with that min/max pruned to its
 * winner and a finite bound: the fast path runs there, and the fallback
 * and the normal evaluate the shorter tape. Sub-cells refine adaptively
 * (EXACT_SUB_STEP depths a level) down to the voxel's parent while the
 * bound stays +inf. What a sub-cell holds depends on that sub-cell and the
 * candidate alone, so the cache (bounded, emptied when full) changes the
 * work done, never a result (RENDER.md, "--exact", "Sub-cells"). */
#ifndef EXACT_SUB_H
#define EXACT_SUB_H

#include <stdint.h>

#include "common/expr/tape.h"
#include "common/expr/tape_hess.h"

struct exact_scene;

/* The kinks (tape_hess_kinks) sub-cells are made for: a min/max's
 * operands separate a little away from its crease, and a flag may go. An
 * abs of an operand that vanishes inside the (sub-)cell, left there by the
 * pruning (the gyroid's |G|, whose zero set runs a few voxels from the
 * surface), seldom separates in the first levels, each a pruning more: a
 * region whose tape still has one gets no sub-cells, whatever else is
 * kinked there (docs/perf-log.md). The rule reads the region's own kink
 * mask, so it depends on the region alone. */
#define EXACT_SUB_KINKS (TAPE_KINK_MINMAX | TAPE_KINK_FLAG)
static inline int exact_sub_wanted(unsigned kinks)
{
    return (kinks & EXACT_SUB_KINKS) && !(kinks & TAPE_KINK_ABS);
}

#define EXACT_SUB_STEP 2    /* depths from a level to the next: 8^2 sub-cells */
#define EXACT_SUB_MAX_REL 8 /* deepest sub-cell: coarse depth + this */
/* Soft limits of one worker's cache, past which it is emptied before the
 * next voxel: sub-cells (some 80 bytes each) and pruned instructions. */
#define EXACT_SUB_NODES (1u << 17)
#define EXACT_SUB_INSNS (1u << 21)

/* What a voxel's test uses for one candidate: the coarse cell's tapes and
 * bound, or those of the sub-cell holding the voxel. The tapes' arrays stay
 * valid until the next exact_sub_reserve. */
typedef struct exact_region {
    tape t, cull;
    double hmag[TAPE_HN]; /* the Hessian's magnitudes over it: +inf, the fast path is off */
    uint64_t key;       /* 0: the coarse cell; else the sub-cell (depth, corner) */
    unsigned depth;     /* the region's depth in the tree and its corner in cells */
    uint32_t corner[3]; /* of that depth (exact_scene_box gives its box) */
    unsigned shift;     /* levels - depth: a voxel v lies in it iff v >> shift is corner */
    int empty;          /* certified: the surface has no point in the region */
} exact_region;

typedef struct exact_sub_node exact_sub_node;

#define EXACT_SUB_LAST 8 /* regions remembered, by candidate index mod this */

/* One worker's sub-cells (not shared: no locks). */
typedef struct exact_sub_cache {
    exact_sub_node *node;
    uint32_t nnode, cap_node;
    uint32_t *block;   /* blocks of 8^EXACT_SUB_STEP node indices (UINT32_MAX: not made) */
    uint32_t nblock, cap_block;
    uint32_t *top;     /* per candidate of the scene: its block of first-level sub-cells */
    uint32_t ncand;
    tape_insn **chunk; /* the pruned tapes' instructions, in chunks that never move */
    uint32_t nchunk, cap_chunk, cur, chunk_used; /* cur: the chunk in use */
    uint32_t chunk_size;
    interval *islots;  /* scratch for the longest tape */
    tape_ihess *hslots;
    tape_insn *tmp_insn;
    uint32_t *tmp_mark;
    uint32_t max_nodes;    /* the soft limit (EXACT_SUB_NODES; tests set less) */
    /* the last region found for candidate last_k[i] (i = k mod EXACT_SUB_LAST;
     * UINT32_MAX: none, as after a reset) */
    exact_region last[EXACT_SUB_LAST];
    uint32_t last_k[EXACT_SUB_LAST];
    uint64_t made, resets; /* statistics: sub-cells made, times emptied */
} exact_sub_cache;

/* Scratch and tables for the scene's candidates and tapes of up to max_n
 * instructions: 0, or -1 when out of memory (then nothing is held). */
int exact_sub_init(exact_sub_cache *c, uint32_t ncand, uint32_t max_n);
void exact_sub_free(exact_sub_cache *c); /* accepts a zeroed or freed one */

/* Empties the cache when it is full: call before a voxel's lookups (the
 * regions found before are invalid afterwards). */
void exact_sub_reserve(exact_sub_cache *c);

/* The region of candidate k (index into es->cand) that voxel v (integer
 * corner) lies in: the coarse cell when its bound is finite or sub-cells
 * are off; else the deepest sub-cell needed, made (with its ancestors) if
 * missing; the coarse cell too when memory runs out (sound: its bound is
 * +inf). The region stays valid until the next call for a candidate of the
 * same index mod EXACT_SUB_LAST, or exact_sub_reserve. */
const exact_region *exact_sub_find(exact_sub_cache *c, const struct exact_scene *es, uint32_t k,
                                   const uint32_t v[3]);

#endif
