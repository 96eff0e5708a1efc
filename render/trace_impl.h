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

/* Every implementation built into this binary, the one in use first. */
typedef struct trace_impl {
    const char *name;
    trace_traverse_fn traverse;
} trace_impl;
extern const trace_impl trace_impls[];
extern const unsigned trace_impl_count;

/* trace_setup_eye without its shortcut for an eye inside the root cube:
 * the tests compare the two. */
int trace_setup_eye_general(const trace_eye *e, const double dir[3], trace_ray *r);

/* --refine in one occupied voxel (render/trace_refine.c). */
int trace_refine_voxel(const oct_tree *tree, const trace_ray *r, uint64_t idx, const uint32_t v[3],
                       double t_in, double t_out, int *side, double *t_hit);

#endif
