/* trace: the two-step discrete ray traversal of an oct_tree (Stolte & Caubet,
 * sections 3-4): clip to the root cube, skip empty cells down to the split
 * depth K (step one: `enter`, the paper's vertical traverse, and `climb` to
 * the common ancestor, the nodes kept on a stack), then walk voxel by voxel
 * (step two, `voxel_walk`). See RENDER.md, "Traversal"; the implementations
 * are in trace_sse.c and trace_portable.c (trace_impl.h).
 *
 * Coordinates. The ray is mapped to grid coordinates, where the root cube is
 * [0, N]^3 with N = 2^L voxels a side: g = (p - origin) * N / edge. The
 * direction is scaled by the same factor, so the ray parameter t is the same
 * in both spaces: world units along the caller's direction (unit direction ->
 * world distance).
 *
 * Integer positions, exact times. The traversal state is the integer voxel
 * (x, y, z) (a 0-fraction-bit fixed-point position, 32 bits a coordinate,
 * exact at every level up to OCT_MAX_LEVELS = 20). Continuous time is never
 * accumulated: the time at which the ray crosses the grid plane "axis a = k"
 * is always evaluated from scratch as
 *       T_a(k) = (k - o_a) * inv_a        (double, one rounding each op)
 * where o is the ray's grid-space start point and inv_a = 1 / d_a. The
 * coarse step and the fine step use this one function, so the hand-over
 * from coarse cells to voxels can neither skip a voxel nor enter one twice:
 * both steps agree on every plane-crossing order by construction. The error
 * of T relative to the exact real crossing is <= 2 ulp of T (one subtraction,
 * exact when k and o share an exponent range, and one multiplication; the
 * reciprocal adds 0.5 ulp), independent of the number of steps. It is exact
 * (T equals the real crossing) whenever o has at most 52 - L fraction bits
 * and 1/d_a is representable, e.g. axis-aligned and (±1,±1,±1)-type rays
 * from dyadic points; ties between axes in such cases are therefore exact.
 *
 * Tie rule (which voxel a ray is in at time t). Along each axis with d_a > 0
 * the ray occupies voxel k for T_a(k) <= t < T_a(k+1); with d_a < 0 for
 * T_a(k+1) <= t < T_a(k). A voxel is occupied for the intersection of its
 * three half-open intervals, so at every t the ray is in exactly one voxel.
 * Consequences: a ray crossing a face enters the voxel beyond it; a ray
 * through an edge or corner goes straight to the diagonal voxel and does not
 * enter the voxels it only touches (zero-length interval). A direction
 * component of exactly +0 or -0 (or so small that 1/d overflows) is treated
 * as 0: the ray stays in voxel floor(o_a), and a ray lying in the root's
 * upper face o_a = N belongs to voxel N - 1 (the root cube is closed).
 *
 * Start. A ray starting outside the cube is re-based to its entry point
 * (entry-axis coordinate set exactly on the face, the others clamped into
 * [0, N]); t of a hit is then t_base + local t. A ray starting inside a
 * voxel that is occupied hits it at t = 0.
 */
#ifndef TRACE_H
#define TRACE_H

#include <stdint.h>

#include "format/oct.h"

/* A ray prepared for one tree (grid space, re-based). Plain data: the tests'
 * brute-force oracle reads it. */
typedef struct trace_ray {
    double o[3];      /* local start point in grid units, inside [0, N]^3 */
    double ot[3];     /* o for T(); -inf on a zero axis so that T = +inf */
    double inv[3];    /* 1/d per axis; 1 on a zero axis */
    double d[3];      /* direction in grid units per t; 0 on a zero axis */
    double t_base;    /* t of the local start point on the caller's ray */
    double t_start;   /* local t at which the traversal starts: 0, or trace_clip's */
    double t_end;     /* local t at which the ray leaves the root cube (or trace_clip's) */
    int32_t sgn[3];   /* +1 or -1; +1 on a zero axis */
    uint32_t v[3];    /* zero axis: the voxel the ray stays in (floor(o) clamped to
                         N - 1); 0 on other axes, whose start voxel the
                         traversal finds from T() */
    unsigned active;  /* bit a set when axis a has a non-zero direction */
} trace_ray;

/* Time (local, in t units) at which the ray crosses grid plane axis = k;
 * +inf on a zero axis. The one crossing function the traversal uses. */
static inline double trace_plane_time(const trace_ray *r, int axis, double k)
{
    return (k - r->ot[axis]) * r->inv[axis];
}

/* Maps eye + t * dir into `tree`'s grid and clips it to the root cube (one
 * slab test). Returns 1 when some t >= 0 lies inside the cube (r filled),
 * 0 when the ray misses it, has a zero or non-finite direction, or a
 * non-finite eye. `dir` need not be unit length; t is in its units. */
int trace_setup(const oct_tree *tree, const double eye[3], const double dir[3], trace_ray *r);

/* trace_setup in two parts for many rays from one eye: the eye's grid
 * position and its slab differences once (trace_eye_init, 0 when no ray from
 * this eye can be set up), then per ray the rest (trace_setup_eye). The same
 * operations on the same values as trace_setup, which is the pair. */
typedef struct trace_eye {
    double o[3];      /* eye in grid units */
    double lo[3];     /* 0 - o */
    double hi[3];     /* n - o */
    double n, scale;  /* N = 2^L, N / edge */
    uint32_t nvox;
    int inside[3];    /* 0 <= o_a <= N */
    int all_inside;   /* all three */
    int ok;
} trace_eye;

int trace_eye_init(const oct_tree *tree, const double eye[3], trace_eye *e);
int trace_setup_eye(const trace_eye *e, const double dir[3], trace_ray *r);

/* The direction's part of trace_setup_eye, made once for many rays of one
 * direction (shadow rays towards one light): trace_setup_dir(e, td, r) sets
 * up trace_setup_eye(e, td->dir, r)'s ray, bit for bit, for every eye e of
 * the tree (the grid scale) td was made for; from an eye inside the root
 * cube without a division. */
typedef struct trace_dir {
    double dir[3];     /* as given */
    double scale;      /* the tree's N / edge (trace_eye's) */
    double d[3], inv[3]; /* trace_ray's: 0 and 1 on a zero axis */
    int32_t sgn[3];
    unsigned active;
    int ok;            /* 0: no ray of this direction can be set up */
} trace_dir;

void trace_dir_init(const trace_eye *e, const double dir[3], trace_dir *td);
int trace_setup_dir(const trace_eye *e, const trace_dir *td, trace_ray *r);

/* Restricts a prepared ray to the caller's t in [t_lo, t_hi]: the traversal
 * starts in the cell the ray is in at t_lo (chosen by the tie rule, as if it
 * had walked there) and stops at t_hi. When no occupied voxel meets the ray
 * outside [t_lo, t_hi] (what beam_starts guarantees for [t_lo, +inf)), the
 * hit, its voxel and its t are those of the whole ray, bit for bit; only the
 * step count falls.
 * Returns 0 when nothing of the ray is left (then it must not be traced). */
int trace_clip(trace_ray *r, double t_lo, double t_hi);

struct exact_worker; /* render/exact_scene.h */

typedef struct trace_opts {
    unsigned split;   /* K: empty cells of depth <= K are skipped whole; 0..L */
    int refine;       /* hit where the ray crosses the stored planes of a run of
                         occupied voxels (RENDER.md, "--refine"); 0: voxel entry */
    struct exact_worker *exact; /* not NULL: --exact, the first root of the scene's
                                   functions in the occupied voxels (RENDER.md,
                                   "--exact"); this thread's own; refine is ignored */
} trace_opts;

typedef struct trace_hit {
    int hit;          /* 1 hit, 0 miss */
    uint64_t voxel;   /* index into tree->voxels / surfaces */
    uint32_t xyz[3];  /* integer voxel coordinates */
    double t;         /* caller's t of the hit: voxel entry, plane with refine, root
                         with exact */
    uint32_t steps;   /* DDA steps taken (<= trace_max_steps) */
    int exact;        /* 1: an --exact hit, with the two fields below */
    uint32_t surface; /* the palette index of the surface whose root it is */
    double normal[3]; /* its unit gradient there, facing the viewer */
} trace_hit;

/* Upper bound on steps for a tree of `levels` levels: 3 * 2^L + L. */
uint32_t trace_max_steps(unsigned levels);

/* Traces one ray. Thread-safe (reads the tree only), no allocation.
 * Returns hit->hit. On a miss hit->t is +inf. */
int trace_ray_cast(const oct_tree *tree, const trace_opts *opts, const double eye[3],
                   const double dir[3], trace_hit *hit);

/* The same on a prepared ray (r from trace_setup returning 1). */
int trace_ray_prepared(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       trace_hit *hit);

/* A start shared by a set of rays: the deepest occupied cell holding every
 * one of their start points, with the nodes from the root down to it. */
typedef struct trace_anchor {
    unsigned depth;   /* 0: the root, no help */
    uint32_t cell[3]; /* the cell's corner, in voxels */
    struct {          /* laid out as the traversal's own frames */
        uint64_t prefix; /* index in the next depth of the node's first child */
        uint32_t mask;   /* child mask */
        uint32_t ci;     /* child index in its parent */
    } node[OCT_MAX_LEVELS]; /* depths 0..depth */
} trace_anchor;

/* The anchor for start points known to lie in the box [lo, hi] (grid
 * units: the root cube is [0, N]^3), the box already grown by a margin
 * above the rounding of the rays' start points and plane times. A box not
 * inside the root cube gets the root. */
void trace_anchor_find(const oct_tree *tree, const double lo[3], const double hi[3],
                       trace_anchor *a);

/* The same anchor, found faster for a box near the one `near` was found
 * for (an anchor of this tree, or NULL): the nodes the two share are
 * copied from it. a may be near. */
void trace_anchor_find_near(const oct_tree *tree, const double lo[3], const double hi[3],
                            const trace_anchor *near, trace_anchor *a);

/* trace_ray_prepared for a ray whose start point (at r->t_start) lies in
 * the box a was found for: the descent begins at the anchor. Hit, voxel, t
 * and step count are those of trace_ray_prepared, bit for bit. */
int trace_ray_anchored(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *a, trace_hit *hit);

#endif
