/* trace_impl: what the traversal's files share; not part of trace.h's
 * interface (the tests include it to run every implementation).
 *
 * One algorithm, the paper's (RENDER.md, "Traversal"), in two
 * implementations: trace_traverse_portable (plain C, built everywhere) and
 * trace_traverse_sse (the three axes in SSE registers, built when the target
 * has SSE4.1). They take the same steps on the same plane times and return
 * the same hits, voxels, t and step counts, bit for bit; trace.c picks the
 * SSE one when it is built. */
#ifndef TRACE_IMPL_H
#define TRACE_IMPL_H

#include <stdint.h>

#include "format/oct_normal.h"
#include "render/trace.h"

#if defined(__SSE4_1__)
#define TRACE_HAVE_SSE 1
#else
#define TRACE_HAVE_SSE 0
#endif

/* One frame of the descent stack: a node (the paper's "cell", the eight
 * children of one cube of space) on the path from the root. The layout is
 * trace_anchor's node[], so an anchor's nodes are copied onto the frames. */
typedef struct trace_frame {
    uint64_t prefix; /* index in the next depth of the node's first child */
    uint32_t mask;   /* child mask */
    uint32_t ci;     /* child index (x + 2y + 4z) of the node in its parent */
} trace_frame;

/* The traversal from r->t_start, from the root or (anchor not NULL, depth
 * > 0) from the anchor's cell. */
typedef int (*trace_traverse_fn)(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                                 const trace_anchor *anchor, trace_hit *hit);

int trace_traverse_portable(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                            const trace_anchor *anchor, trace_hit *hit);
#if TRACE_HAVE_SSE
int trace_traverse_sse(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *anchor, trace_hit *hit);
#endif

/* The any-hit walk of secondary rays (shadow and AO rays, the paper's rule:
 * neither --refine nor --exact): 1 when the ray meets an occupied voxel
 * between r->t_start and r->t_end, which is when the traversal above hits
 * one, 0 otherwise. It starts in the anchor's cell (anchor not NULL, depth
 * > 0; else at the root) and skips every occupied cell the ray crosses
 * without meeting an occupied child (trace_path_children); a cell whose
 * children are voxels so answers at once (unless two of its mid planes
 * are crossed at one time: then its voxels are walked). *steps gets its
 * own step count (it takes fewer steps than the traversal). */
typedef int (*trace_occluded_fn)(const oct_tree *tree, const trace_ray *r,
                                 const trace_anchor *anchor, uint32_t *steps);

int trace_occluded_portable(const oct_tree *tree, const trace_ray *r, const trace_anchor *anchor,
                            uint32_t *steps);
#if TRACE_HAVE_SSE
int trace_occluded_sse(const oct_tree *tree, const trace_ray *r, const trace_anchor *anchor,
                       uint32_t *steps);
/* The any-hit walk of an AO ray through the clearance grid g of tree
 * (render/ao_grid.h): the same answer as trace_occluded_sse (another step
 * count). A ray with a zero axis takes trace_occluded_sse. */
struct ao_grid;
int trace_occluded_grid_sse(const oct_tree *tree, const struct ao_grid *g, const trace_ray *r,
                            const trace_anchor *anchor, uint32_t *steps);
#endif

/* The children a ray visits in a cell, from the order of its mid-plane
 * times (render/trace_path.c): entry c0 | crossed << 3 | order << 6, where
 * c0 is the child it enters (x + 2y + 4z), crossed the axes whose mid plane
 * it crosses before it leaves the cell or passes t_end, and order the bits
 * T_x(mid) < T_y(mid), T_y(mid) < T_z(mid), T_x(mid) < T_z(mid). Child k is
 * visited when bit k is set; for tied mid-plane times (the ray passes an
 * edge or a corner between children) the set holds a child it only touches
 * too: a superset, never a child short. */
extern const uint8_t trace_path_children[512];

/* The pairs of a crossed set, as the bits x-y, y-z, x-z: where a tie among
 * their mid-plane times makes trace_path_children a superset. */
#define TRACE_PAIRS(crossed) (0x72401000u >> (4u * (crossed)) & 7u)

/* Every implementation built into this binary, the one in use first. */
typedef struct trace_impl {
    const char *name;
    trace_traverse_fn traverse;
    trace_occluded_fn occluded; /* its any-hit walk */
} trace_impl;
extern const trace_impl trace_impls[];
extern const unsigned trace_impl_count;

/* The any-hit walk of the implementation whose traversal is fn, the
 * preferred one for NULL or a traversal not in trace_impls. */
trace_occluded_fn trace_occluded_for(trace_traverse_fn fn);

/* trace_setup_eye without its shortcut for an eye inside the root cube:
 * the tests compare the two. */
int trace_setup_eye_general(const trace_eye *e, const double dir[3], trace_ray *r);

/* Voxel idx's stored plane along the ray (corner v): s(t) = t * den - num
 * is the signed distance, in voxel edges, of p(t) from the plane. */
static inline void trace_voxel_plane(const oct_tree *tree, const trace_ray *r, uint64_t idx,
                                     const uint32_t v[3], double *num, double *den)
{
    const uint32_t rec = tree->voxels[idx];
    float nf[3];
    oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
    double nu = oct_offset_decode((int8_t)(uint8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT)), de = 0.0;
    for (int a = 0; a < 3; a++) {
        nu -= (double)nf[a] * (r->o[a] - ((double)v[a] + 0.5));
        de += (double)nf[a] * r->d[a];
    }
    *num = nu;
    *den = de;
}

/* --refine in one occupied voxel (render/trace_refine.c). */
int trace_refine_voxel(const oct_tree *tree, const trace_ray *r, uint64_t idx, const uint32_t v[3],
                       double t_in, double t_out, int *side, double *t_hit);

#endif
