/* shadow: start point and any-hit cast of secondary rays. */
#include "render/shadow.h"

#include <math.h>

#include "format/oct_normal.h"

double shadow_offset(const float n[3])
{
    return (double)fabsf(n[0]) + (double)fabsf(n[1]) + (double)fabsf(n[2]) + 0.25;
}

/* The margin of the box around a start point: far above the rounding of
 * its grid position when computed back from the world point. */
#define START_MARGIN 0x1p-10

/* 1 when the voxel holding grid point g is known occupied; s->anchor gets
 * the deepest occupied cell holding the box g +- START_MARGIN. */
static int voxel_occupied(const oct_tree *tree, const double g[3], shadow_start *s)
{
    const double m = START_MARGIN;
    const double lo[3] = {g[0] - m, g[1] - m, g[2] - m}, hi[3] = {g[0] + m, g[1] + m, g[2] + m};
    trace_anchor *an = &s->anchor;
    trace_anchor_find_near(tree, lo, hi, s->near ? an : NULL, an);
    s->near = 1;
    if (an->depth + 1 != tree->levels)
        return 0; /* an empty cell above the voxels, outside the cube, or a box on a face */
    const unsigned c = ((uint32_t)lo[0] & 1u) | ((uint32_t)lo[1] & 1u) << 1 |
                       ((uint32_t)lo[2] & 1u) << 2;
    return (int)(an->node[an->depth].mask >> c & 1u);
}

/* A voxel's edge in world units. */
static double voxel_edge(const oct_tree *tree)
{
    return tree->edge / (double)(UINT64_C(1) << tree->levels);
}

/* The world point of grid point g, as the start keeps it (s->o). */
static void world_of(const oct_tree *tree, const double g[3], double o[3])
{
    const double vox = voxel_edge(tree);
    for (int a = 0; a < 3; a++)
        o[a] = tree->origin[a] + g[a] * vox;
}

/* Try k of the start point from base (grid units, on the surface) along n. */
static void start_grid(const double base[3], const float n[3], unsigned k, double g[3])
{
    const double h = shadow_offset(n) + (double)k;
    for (int a = 0; a < 3; a++)
        g[a] = base[a] + h * (double)n[a];
}

/* The start point from base along n, moved on out of occupied voxels
 * (shadow_origin). The anchor of the box around the start also holds
 * s->eye.o, which is within rounding of g: it is the rays' anchor. */
static int start_from(const oct_tree *tree, const double base[3], const float n[3],
                      shadow_start *s)
{
    if (!s->near)
        s->dir_ok = 0; /* a new tree, or a new shadow_start: no direction kept */
    double g[3];
    for (unsigned k = 0; k < SHADOW_TRIES; k++) {
        start_grid(base, n, k, g);
        if (!voxel_occupied(tree, g, s)) {
            world_of(tree, g, s->o);
            trace_eye_init(tree, s->o, &s->eye);
            return 1;
        }
    }
    return 0;
}

/* The hit voxel's plane point nearest its centre, grid units. */
static void stored_base(const oct_tree *tree, const trace_hit *hit, const float ns[3],
                        double base[3])
{
    const uint32_t rec = tree->voxels[hit->voxel];
    const double off = oct_offset_decode((int8_t)(uint8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
    for (int a = 0; a < 3; a++)
        base[a] = (double)hit->xyz[a] + 0.5 + off * (double)ns[a];
}

/* A world point p in grid units. */
static void grid_of(const oct_tree *tree, const double p[3], double base[3])
{
    const double vox = voxel_edge(tree);
    for (int a = 0; a < 3; a++)
        base[a] = (p[a] - tree->origin[a]) / vox;
}

int shadow_start_hit(const oct_tree *tree, const trace_hit *hit, const float n[3], shadow_start *s)
{
    float ns[3]; /* the stored normal: the plane's, n or -n */
    oct_normal_decode(tree->voxels[hit->voxel] & OCT_VOXEL_NORMAL_MASK, ns);
    return shadow_start_stored(tree, hit, ns, n, s);
}

int shadow_start_stored(const oct_tree *tree, const trace_hit *hit, const float ns[3],
                        const float n[3], shadow_start *s)
{
    double base[3];
    stored_base(tree, hit, ns, base);
    return start_from(tree, base, n, s);
}

int shadow_start_at(const oct_tree *tree, const double p[3], const float n[3], shadow_start *s)
{
    double base[3];
    grid_of(tree, p, base);
    return start_from(tree, base, n, s);
}

/* shadow_lit_stored and shadow_lit_at from base. The first start point,
 * taken to the world and back as start_from and trace_eye_init do (the
 * same bits as the eye's grid position there: trace_eye_init's scale and
 * (o - origin) * scale), asked of the map: past
 * every occupied cell there, it is in no occupied voxel either (the map
 * raises its texel above every point of one), so start_from would take it
 * and shadow_blocked_from would answer lit from the same query. */
static int lit_from(const oct_tree *tree, const double base[3], const float n[3],
                    const shadow_map *map, const double light[3])
{
    const double scale = (double)(UINT32_C(1) << tree->levels) / tree->edge;
    double g[3], o[3];
    start_grid(base, n, 0, g);
    world_of(tree, g, o);
    for (int a = 0; a < 3; a++)
        g[a] = (o[a] - tree->origin[a]) * scale;
    return shadow_map_clear_t(map, g, light, scale) <= 0.0;
}

/* 1 when a map can answer where the rays start: one of voxel cells (the
 * texels of coarser cells nearly always reach above a point 2 voxels off
 * the surface, docs/perf-log.md). */
static int map_of_voxels(const oct_tree *tree, const shadow_map *map)
{
    return map && map->depth == tree->levels;
}

int shadow_lit_stored(const oct_tree *tree, const trace_hit *hit, const float ns[3],
                      const float n[3], const shadow_map *map, const double light[3])
{
    if (!map_of_voxels(tree, map))
        return 0;
    double base[3];
    stored_base(tree, hit, ns, base);
    return lit_from(tree, base, n, map, light);
}

int shadow_lit_at(const oct_tree *tree, const double p[3], const float n[3],
                  const shadow_map *map, const double light[3])
{
    if (!map_of_voxels(tree, map))
        return 0;
    double base[3];
    grid_of(tree, p, base);
    return lit_from(tree, base, n, map, light);
}

int shadow_origin(const oct_tree *tree, const trace_hit *hit, const float n[3], double o[3])
{
    shadow_start s;
    s.near = 0;
    const int ok = shadow_start_hit(tree, hit, n, &s);
    for (int a = 0; ok && a < 3; a++)
        o[a] = s.o[a];
    return ok;
}

int shadow_origin_at(const oct_tree *tree, const double p[3], const float n[3], double o[3])
{
    shadow_start s;
    s.near = 0;
    const int ok = shadow_start_at(tree, p, n, &s);
    for (int a = 0; ok && a < 3; a++)
        o[a] = s.o[a];
    return ok;
}

trace_occluded_fn shadow_any_hit(const trace_opts *opts, trace_traverse_fn traverse)
{
    return !opts->refine && !opts->exact ? trace_occluded_for(traverse) : NULL;
}

int shadow_cast(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                const trace_ray *r, const trace_anchor *an, uint64_t *steps)
{
    const trace_occluded_fn occluded = shadow_any_hit(opts, traverse);
    if (occluded) {
        uint32_t n;
        const int hit = occluded(tree, r, an, &n);
        *steps += n;
        return hit;
    }
    trace_hit h;
    if (!traverse)
        traverse = trace_impls[0].traverse;
    traverse(tree, opts, r, an, &h);
    *steps += h.steps;
    return h.hit;
}

int shadow_blocked(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                   const double o[3], const double d[3], double t_max, uint64_t *steps)
{
    trace_ray r;
    if (!trace_setup(tree, o, d, &r))
        return 0; /* the ray misses the cube */
    if (t_max < INFINITY && !trace_clip(&r, 0.0, t_max))
        return 0;
    return shadow_cast(tree, opts, traverse, &r, NULL, steps);
}

int shadow_blocked_from(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                        shadow_start *s, const shadow_map *map, const double d[3], double t_max,
                        uint64_t *steps)
{
    if (!s->eye.ok)
        return 0; /* as trace_setup: no ray */
    if (map) {
        const double t_clear = shadow_map_clear_t(map, s->eye.o, d, s->eye.scale);
        if (t_clear <= 0.0)
            return 0; /* past every occupied cell from its start */
        if (t_clear < t_max)
            t_max = t_clear;
    }
    /* +0 and -0 make the same set-up, NaN never matches: == is enough */
    trace_dir *td = &s->dir;
    if (!s->dir_ok || td->dir[0] != d[0] || td->dir[1] != d[1] || td->dir[2] != d[2] ||
        td->scale != s->eye.scale) {
        trace_dir_init(&s->eye, d, td);
        s->dir_ok = 1;
    }
    trace_ray r;
    if (!trace_setup_dir(&s->eye, td, &r))
        return 0; /* as trace_setup: the ray misses the cube */
    if (t_max < INFINITY && !trace_clip(&r, 0.0, t_max))
        return 0;
    return shadow_cast(tree, opts, traverse, &r, &s->anchor, steps);
}
