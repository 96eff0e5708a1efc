/* exact_scene: a tree's surface functions prepared for `render --exact`:
 * per occupied coarse cell (the tree's nodes of one depth), the surfaces
 * that can be present there, each with its tape pruned for that cell
 * (tape_prune_const), so a voxel is never tested with a whole long tape
 * (exact_scene.c); and the exact hit test in one voxel (exact_voxel.c;
 * RENDER.md, "--exact"). */
#ifndef EXACT_SCENE_H
#define EXACT_SCENE_H

#include <stdint.h>

#include "common/expr/tape.h"
#include "format/oct.h"
#include "render/exact_fast.h"
#include "render/exact_hit.h"
#include "render/exact_sub.h"
#include "render/trace.h"

/* Coarse depth (docs/perf-log.md, "render --exact"). */
#define EXACT_CELL_DEPTH 5
#define EXACT_CELL_MAX_DEPTH 7 /* 8^7 map entries: 8 MiB */

/* One surface in one coarse cell. */
typedef struct exact_cand {
    uint32_t surface; /* palette index */
    tape t;           /* pruned for the cell, as exact as the whole tape (points,
                         derivative); arrays in the scene's pools */
    tape cull;        /* pruned coarsely, for the interval that drops segments */
    double hmag[6];   /* magnitudes of t's Hessian enclosure over the cell
                         (tape_hess_mag): +inf where the fast path is off */
    double hbranch[6]; /* the same with kinks allowed (tape_hess_mags): what
                          bounds the sub-cells where t has none (exact_sub.h) */
    unsigned kinks;    /* tape_hess_kinks of t over the cell */
} exact_cand;

typedef struct exact_scene {
    const oct_tree *tree;
    unsigned depth;      /* coarse depth D, <= tree->levels */
    uint32_t *cell_slot; /* 8^D entries, x + 2^D y + 4^D z: index into first[], or UINT32_MAX */
    uint32_t *first;     /* ncells + 1 offsets into cand[] */
    exact_cand *cand;
    uint32_t ncells, ncand;
    uint32_t max_n;      /* most instructions of any tape (scratch size) */
    uint64_t whole_insns, pruned_insns, cull_insns; /* statistics: sum over candidates */
    double h;            /* world units per voxel: edge / 2^L */
    unsigned sub_max;    /* deepest sub-cells (exact_sub.h), relative to depth; 0: none */
    tape_insn *insn_pool;
    tape_const *konst_pool;
} exact_scene;

/* Prepares `tapes` (tree->surface_count of them, palette order; borrowed
 * only while this runs) for the tree at coarse depth `depth` (clamped to
 * the tree's levels and EXACT_CELL_MAX_DEPTH). Returns 0, or -1 when out of
 * memory (then *es holds nothing). */
int exact_scene_init(exact_scene *es, const oct_tree *tree, const tape *tapes, unsigned depth);
void exact_scene_free(exact_scene *es); /* accepts a zeroed or freed one */

/* The world box of the tree's cell of depth d (<= the tree's levels) with
 * corner c (in cells of that depth), grown by 2^-8 voxel each side (more
 * than the 2^-16 voxel a test span is widened by) and rounded outward, so
 * every span tested in it lies inside. */
void exact_scene_box(const exact_scene *es, unsigned d, const uint32_t c[3], interval box[3]);

#define EXACT_MODELS 8 /* candidates of a cell that keep a model */

/* Tapes shorter than this keep the per-point bound: its making costs more
 * than it saves there (csg's pruned tapes; docs/perf-log.md, "render
 * --exact: the a-priori bound per cell"). */
#define EXACT_BOUND_MIN_N 16

/* A thread's state for the exact test: the scene and scratch for its tapes. */
typedef struct exact_worker {
    _Alignas(64) const exact_scene *scene; /* (a cache line of its own: threads write theirs) */
    exact_scratch scratch;
    exact_sub_cache sub; /* its own sub-cells */
    uint64_t fast, slow; /* statistics: candidate tests the fast path decided, and not */
    uint64_t beyond;     /* statistics: hits placed past their voxel (root_beyond) */
    uint64_t skipped;    /* statistics: voxels inside a span root_beyond had
                            certified root-free, not tested */
    /* The fast path's models (exact_fast.h) for the line of the last test
     * (key: o, d; key_t: its t_in), valid while its voxels stay in one
     * coarse cell: candidate k of the cell has one when bit k of `have` is
     * set, for the region (the cell or a sub-cell: exact_region.key)
     * model_key[k]. */
    double key[6], key_t;
    uint32_t key_slot, have;
    exact_model model[EXACT_MODELS];
    uint64_t model_key[EXACT_MODELS];
    /* candidate k's curvature bound (exact_fast_curv) on that line when bit
     * k of `have_curv` is set, for the region curv_key[k] */
    uint32_t have_curv;
    double curv[EXACT_MODELS];
    uint64_t curv_key[EXACT_MODELS];
    /* The line of the last test in world units and its widening, made from
     * the ray's o and d (ray_od) once for all of its voxels; line_new: it
     * differs from `key` (the models start afresh at the next voxel). */
    double ray_od[6];
    exact_line line;
    double exit_t;     /* where the line leaves region exit_key (NaN: not made) */
    uint64_t exit_key;
    double clear_to;   /* the cell's one surface has no root on the line from
                          the last voxel tested up to here (root_beyond) */
    double widen;
    int line_new;
    /* per candidate of the scene, made on first use: its cell's a-priori
     * bound (exact_fast.h), when bound_state is 1 (0: not made, 2: none) */
    exact_bound *bound;
    uint8_t *bound_state;
    uint32_t bound_min_n; /* tapes shorter than this keep the per-point bound
                             (EXACT_BOUND_MIN_N; a test may set it) */
} exact_worker;

int exact_worker_init(exact_worker *w, const exact_scene *es); /* 0, or -1: out of memory */
void exact_worker_free(exact_worker *w);
/* Forgets the last line and its models (a worker kept from frame to frame
 * keeps its sub-cells and bounds; a ray's hit never depends on them). */
void exact_worker_new_frame(exact_worker *w);

/* The exact test in occupied voxel v (integer corner), which the ray r
 * occupies for local t in [t_in, t_out]: the nearest root of any surface
 * present in v's coarse cell on that span, widened by 2^-16 of a voxel each
 * way (so that a root the rasterizer's and this test's roundings put on
 * different sides of a voxel face is not lost; any root found is a root of
 * f, and nearer ones would lie in voxels already tested); where v's cell has
 * one surface, the first root past the span, up to where the ray leaves the
 * cell, when the span's model certifies it (RENDER.md, "The root past the
 * voxel"). hit->voxel holds v's index in the tree on entry (its stored
 * plane places the first model). Returns 1 on a hit, with its local t in
 * *t_hit and hit's exact (1), surface and unit normal (facing the viewer)
 * filled; the caller sets the rest. */
int exact_voxel(exact_worker *w, const trace_ray *r, const uint32_t v[3], double t_in,
                double t_out, double *t_hit, trace_hit *hit);

#endif
