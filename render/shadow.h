/* shadow: secondary rays from a hit (shadow rays, ambient occlusion rays)
 * through the same octree and the same traversal as the primary rays. They
 * only ask "is anything in the way": the traversal stops at the first
 * occupied voxel it meets (with --refine, the first whose planes the ray
 * crosses), which is what the primary traversal does too, so no third
 * traversal is needed.
 *
 * Start point (RENDER.md, "Shadows"): from the hit voxel's stored plane
 * n . (p - centre) = offset (the plane --refine uses), the point of that
 * plane nearest the voxel's centre moved SHADOW_OFFSET(n) voxel edges along
 * the viewer-facing normal, where
 *     SHADOW_OFFSET(n) = |n|_1 + 0.25   (1.25 .. 1.99 voxels).
 * For a plane with unit normal n, a voxel meets it only when its centre is
 * within |n|_1 / 2 of it, so every point of every voxel of the plane is
 * within |n|_1; the start point is |n|_1 + 0.25 away on the facing side
 * (the 0.25 covers the stored normal's and offset's rounding), and a ray
 * leaving it with d . n > 0 only gets farther: a surface never shadows
 * itself (no acne). A point whose light lies behind its facing normal gets
 * no light at all (no shadow ray), so a wall can only be lit from the side
 * it is seen from: light cannot leak through it, however thin. What the
 * offset skips is an occluder nearer than SHADOW_OFFSET along the normal
 * (under 2 voxels); a shadow's outline moves by up to SHADOW_OFFSET times
 * the sine of the light's angle to the normal. A start point inside an
 * occupied voxel is moved on (shadow_origin). */
#ifndef SHADOW_H
#define SHADOW_H

#include <stdint.h>

#include "format/oct.h"
#include "render/shadow_map.h"
#include "render/trace.h"
#include "render/trace_impl.h"

/* The offset rule above, in voxel edges, for a unit normal n. */
double shadow_offset(const float n[3]);

#define SHADOW_TRIES 3

/* World position of the start point of secondary rays from the hit voxel
 * `hit` (hit->hit set) with viewer-facing unit normal n, in o; returns 1.
 * Where that point falls in an occupied voxel (at a crease, or where
 * surfaces crowd: the voxel's normal does not point to open space), it
 * moves one voxel further along n, up to SHADOW_TRIES - 1 times; returns 0
 * when it is still inside one (the caller then treats the point as lit and
 * open: a start inside the surface would shadow it by itself). */
int shadow_origin(const oct_tree *tree, const trace_hit *hit, const float n[3], double o[3]);

/* The same from a surface point p in world coordinates (an --exact hit,
 * whose place is known without the voxel's stored plane). */
int shadow_origin_at(const oct_tree *tree, const double p[3], const float n[3], double o[3]);

/* What the secondary rays of one hit share: their start point o
 * (shadow_origin's), its grid position, and its anchor, the deepest
 * occupied cell around it (found by the test that the start is not inside a
 * voxel, so it costs no walk of its own), where every one of those rays'
 * descents from the root arrives. */
typedef struct shadow_start {
    double o[3];
    trace_eye eye;       /* eye.ok = 0: no ray from o can be set up */
    trace_anchor anchor;
    int near;            /* in and out: 1 when anchor holds an earlier start's
                            anchor (same tree), which speeds the next search
                            up (trace_anchor_find_near); 0 the first time */
    trace_dir dir;       /* the direction part of the last shadow ray's set-up
                            (the light's, the same from hit to hit) */
    int dir_ok;          /* dir is set (cleared when near is 0) */
} shadow_start;

/* shadow_origin and shadow_origin_at, with the shared part in *s (set
 * s->near first). */
int shadow_start_hit(const oct_tree *tree, const trace_hit *hit, const float n[3], shadow_start *s);
/* shadow_start_hit with the hit voxel's stored normal ns already decoded. */
int shadow_start_stored(const oct_tree *tree, const trace_hit *hit, const float ns[3],
                        const float n[3], shadow_start *s);
int shadow_start_at(const oct_tree *tree, const double p[3], const float n[3], shadow_start *s);

/* 1 when the map of `light` (made for it, of voxel cells: SHADOW_MAP_FINE
 * and at most SHADOW_MAP_MAX_DEPTH levels; else, or NULL: 0) says that a
 * hit's shadow ray is lit from where it would start: what
 * shadow_start_stored (or shadow_start_at) and shadow_blocked_from with
 * that map would answer, without the start's search and set-up; 0: not
 * known so. For a shadow ray alone (AO rays need the start). */
int shadow_lit_stored(const oct_tree *tree, const trace_hit *hit, const float ns[3],
                      const float n[3], const shadow_map *map, const double light[3]);
int shadow_lit_at(const oct_tree *tree, const double p[3], const float n[3],
                  const shadow_map *map, const double light[3]);

/* The any-hit walk shadow_cast uses for opts and traverse (under the paper's
 * rule: traverse's implementation's), or NULL: the full traversal. */
trace_occluded_fn shadow_any_hit(const trace_opts *opts, trace_traverse_fn traverse);

/* 1 when the prepared ray r, started at anchor an (or NULL), meets an
 * occupied voxel by opts' rule: under the paper's rule the any-hit walk of
 * traverse's implementation (trace_impl.h), else traverse itself (NULL:
 * the build's preferred implementation). Adds its steps to *steps. */
int shadow_cast(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                const trace_ray *r, const trace_anchor *an, uint64_t *steps);

/* 1 when the ray o + t d (d unit), 0 <= t <= t_max (+inf allowed), meets an
 * occupied voxel (by opts' rule), traced by `traverse` (NULL: the build's
 * preferred implementation); 0 otherwise. Adds its DDA steps to *steps. */
int shadow_blocked(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                   const double o[3], const double d[3], double t_max, uint64_t *steps);

/* shadow_blocked from s->o, started at s's anchor: the same answer and
 * steps. The set-up's direction part is kept in s for the next call with
 * the same d. With map (made for d; NULL: none) the ray stops where the map
 * says it is past every occupied cell: the same answer in fewer steps. */
int shadow_blocked_from(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                        shadow_start *s, const shadow_map *map, const double d[3], double t_max,
                        uint64_t *steps);

#endif
