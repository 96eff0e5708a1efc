/* shadow_map: the light's-eye heights of the occupied cells (shadow_map.h). */
#include "render/shadow_map.h"

#include <math.h>
#include <stdlib.h>

#include "render/basis.h"

/* The map's cells are no deeper than this: under 900 texels a side
 * (a 2^9 grid's projection) whatever the levels. */
#define SHADOW_MAP_MAX_DEPTH 9

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* What the walk over the cells reads. */
typedef struct build_ctx {
    const oct_tree *tree;
    shadow_map *m;
    unsigned depth;     /* of the map's cells */
    double side;        /* their side, grid units */
    double lo[2], hi[2]; /* a cell's projected corners: corner . u (v) + these */
    double top;         /* its greatest height: corner . w + this */
} build_ctx;

/* floor(x) clamped to [0, n - 1] (x >= 0 but for the margin). */
static uint32_t texel(double x, uint32_t n)
{
    if (!(x >= 0.0))
        return 0;
    if (x >= (double)(n - 1u))
        return n - 1u;
    return (uint32_t)x;
}

static void put_cell(const build_ctx *c, const double corner[3])
{
    shadow_map *m = c->m;
    const double pu = dot3(corner, m->u), pv = dot3(corner, m->v);
    const double f = dot3(corner, m->w) + c->top;
    const uint32_t i0 = texel((pu + c->lo[0] - m->u0) * m->inv_texel, m->nu);
    const uint32_t i1 = texel((pu + c->hi[0] - m->u0) * m->inv_texel, m->nu);
    const uint32_t j0 = texel((pv + c->lo[1] - m->v0) * m->inv_texel, m->nv);
    const uint32_t j1 = texel((pv + c->hi[1] - m->v0) * m->inv_texel, m->nv);
    for (uint32_t j = j0; j <= j1; j++)
        for (uint32_t i = i0; i <= i1; i++) {
            double *p = &m->top[(size_t)j * m->nu + i];
            if (*p < f)
                *p = f;
        }
}

/* Node `node` of depth d with corner (x, y, z) in voxels: its cells of the
 * map's depth put into the map. */
static void put_node(const build_ctx *c, unsigned d, uint64_t node, const uint32_t corner[3])
{
    if (d == c->depth) {
        const double g[3] = {corner[0], corner[1], corner[2]};
        put_cell(c, g);
        return;
    }
    const oct_children ch = oct_node_children(c->tree->groups[d], node);
    const uint32_t half = UINT32_C(1) << (c->tree->levels - d - 1u);
    uint64_t k = ch.first;
    for (unsigned i = 0; i < 8; i++) {
        if (!(ch.mask >> i & 1u))
            continue;
        const uint32_t cc[3] = {corner[0] + (i & 1u) * half, corner[1] + (i >> 1 & 1u) * half,
                                corner[2] + (i >> 2 & 1u) * half};
        put_node(c, d + 1u, k++, cc);
    }
}

int shadow_map_build(const oct_tree *tree, const double light[3], shadow_map *m)
{
    for (int a = 0; a < 3; a++)
        m->light[a] = light[a];
    const double len = sqrt(dot3(light, light));
    double *w = m->w;
    for (int a = 0; a < 3; a++)
        w[a] = light[a] / len;
    basis_across(w, m->u, m->v);

    const unsigned levels = tree->levels;
    build_ctx c;
    c.tree = tree;
    c.m = m;
    c.depth = levels > SHADOW_MAP_UP ? levels - SHADOW_MAP_UP : 0;
    if (c.depth > SHADOW_MAP_MAX_DEPTH)
        c.depth = SHADOW_MAP_MAX_DEPTH;
    c.side = (double)(UINT32_C(1) << (levels - c.depth));
    const double n = (double)(UINT32_C(1) << levels);
    /* the cube's projection, one grid unit wider on each side than its
       corners' (every grown cell lies inside) */
    double ulo = INFINITY, uhi = -INFINITY, vlo = INFINITY, vhi = -INFINITY;
    for (unsigned k = 0; k < 8; k++) {
        const double g[3] = {k & 1u ? n : 0.0, k & 2u ? n : 0.0, k & 4u ? n : 0.0};
        const double pu = dot3(g, m->u), pv = dot3(g, m->v);
        ulo = fmin(ulo, pu);
        uhi = fmax(uhi, pu);
        vlo = fmin(vlo, pv);
        vhi = fmax(vhi, pv);
    }
    m->u0 = ulo - 1.0;
    m->v0 = vlo - 1.0;
    m->inv_texel = 1.0 / c.side;
    m->nu = (uint32_t)((uhi + 1.0 - m->u0) * m->inv_texel) + 1u;
    m->nv = (uint32_t)((vhi + 1.0 - m->v0) * m->inv_texel) + 1u;
    m->top = malloc((size_t)m->nu * m->nv * sizeof *m->top);
    if (!m->top)
        return -1;
    for (size_t k = 0; k < (size_t)m->nu * m->nv; k++)
        m->top[k] = -INFINITY;
    /* a cell's extremes over its corners, grown by the margin */
    for (int p = 0; p < 2; p++) {
        const double *ax = p ? m->v : m->u;
        c.lo[p] = -SHADOW_MAP_MARGIN;
        c.hi[p] = SHADOW_MAP_MARGIN;
        for (int a = 0; a < 3; a++) {
            c.lo[p] += fmin(0.0, ax[a] * c.side);
            c.hi[p] += fmax(0.0, ax[a] * c.side);
        }
    }
    c.top = SHADOW_MAP_MARGIN;
    for (int a = 0; a < 3; a++)
        c.top += fmax(0.0, w[a] * c.side);
    if (tree->node_count[0]) {
        const uint32_t origin[3] = {0, 0, 0};
        put_node(&c, 0, 0, origin);
    }
    return 0;
}

void shadow_map_free(shadow_map *m)
{
    free(m->top);
    m->top = NULL;
}

double shadow_map_clear_t(const shadow_map *m, const double g[3], const double light[3],
                          double scale)
{
    if (!m || !m->top || light[0] != m->light[0] || light[1] != m->light[1] ||
        light[2] != m->light[2])
        return INFINITY;
    const double x = (dot3(g, m->u) - m->u0) * m->inv_texel;
    const double y = (dot3(g, m->v) - m->v0) * m->inv_texel;
    if (!(x >= 0.0 && y >= 0.0 && x < (double)m->nu && y < (double)m->nv))
        return x == x && y == y ? -INFINITY : INFINITY; /* beside every cell; NaN: unknown */
    const double top = m->top[(size_t)(uint32_t)y * m->nu + (uint32_t)x];
    if (top == -INFINITY)
        return -INFINITY;
    return ((double)top - dot3(g, m->w)) / (scale * dot3(light, m->w));
}
