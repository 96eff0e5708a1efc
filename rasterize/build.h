/* build: subdivide space once around the scene's surfaces (Stolte & Caubet
 * section 2; Duff 1992 interval subdivision, or Kalra & Barr 1989 Lipschitz
 * bounds) and stream the non-empty voxels into an oct_writer. */
#ifndef BUILD_H
#define BUILD_H

#include <stdint.h>

#include "common/expr/scene.h"
#include "format/oct.h"

typedef enum build_method {
    BUILD_INTERVAL,  /* drop a cell when f's interval over it excludes 0 */
    BUILD_LIPSCHITZ  /* drop a cell when |f(centre)| exceeds the gradient bound times its half-size */
} build_method;

/* The piece of the grid one shard builds (rasterize --shard, shard.h): the
 * voxels whose depth-`depth` ancestor has a Morton code in [lo, hi). The
 * decisions for a cell do not depend on the range, so N shards together
 * hold exactly the whole tree. */
typedef struct build_shard {
    uint32_t count, index, depth, crc; /* crc: of the partition's count + 1 boundaries */
    uint64_t lo, hi;
} build_shard;

typedef struct build_params {
    unsigned levels;     /* 1..OCT_MAX_LEVELS */
    build_method method;
    unsigned threads;    /* worker threads, >= 1; the output does not depend on it */
    /* Called from the calling thread with the fraction of work done (0..1);
     * may be NULL. */
    void (*progress)(void *ctx, double fraction);
    void *progress_ctx;
    int shell_only;      /* --shell-only: voxels without records (no normals, no Newton steps) */
    const build_shard *shard; /* NULL: the whole grid */
} build_params;

/* What the build did, for the summary and the benchmark. */
typedef struct build_stats {
    uint64_t voxels;
    uint64_t nodes;
    uint64_t interval_evals;     /* interval evaluations of f over a cell */
    uint64_t gradient_evals;     /* interval-gradient evaluations (Taylor or Lipschitz tests) */
    uint64_t point_evals;        /* point/gradient evaluations for normals */
    uint64_t insns_evaluated;    /* tape instructions run by the interval evaluations */
    uint64_t insns_full;         /* what they would have been without pruning */
    uint64_t taylor_drops;       /* candidate voxels the mean-value (Taylor) form dropped */
    uint64_t nan_cells;          /* cells where f may be undefined (kept, subdivided) */
    uint64_t normal_fallbacks;   /* voxels whose gradient was zero or not finite */
} build_stats;

/* How many of the finest levels the mean-value form tests (subdivide.c;
 * at least 2): 5 for one surface with no kink (abs, min, max) under the
 * interval method, whose tape the coarse levels' pruning barely shortens and
 * the form tests more tightly than the plain test, else 3, below the levels
 * where pruning decides kinks. A shard's partition lies above them. */
unsigned build_mean_value_levels(const scene *sc, build_method method);

/* The cube the grid covers: min corner of `bounds`, edge = its longest side. */
void build_cube(const scene *sc, double origin[3], double *edge);

/* Writer parameters for the scene's grid at `levels`: its cube, its surface
 * count and their colours, copied into `palette`, which wp points to. */
void build_writer_params(const scene *sc, unsigned levels, float palette[3 * OCT_MAX_SURFACES],
                         oct_writer_params *wp);

/* Runs the subdivision (of the whole grid, or of p->shard's piece) and appends every node and voxel to `w`
 * (created by the caller with the same levels and cube). Returns OCT_OK,
 * OCT_ENOMEM, or the writer's error. *stats is filled in either way. */
oct_err build_octree(const scene *sc, const build_params *p, oct_writer *w, build_stats *stats);

#endif
