/* shadow_map: the light's-eye heights of the occupied cells (shadow_map.h). */
#include "render/shadow_map.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "render/basis.h"

/* The map's cells are no deeper than this: under 900 texels a side
 * (a 2^9 grid's projection) whatever the levels. */
#define SHADOW_MAP_MAX_DEPTH 9
/* The depth of the subtrees the threads take one at a time (at most 512). */
#define SPLIT_DEPTH 3

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A node and its corner's projections (. u, . v, . w), grid units. */
typedef struct map_node {
    uint64_t index;
    double p[3];
} map_node;

/* What the walk over the cells reads. */
typedef struct build_ctx {
    const oct_tree *tree;
    const shadow_map *m;
    unsigned depth;           /* of the map's cells */
    struct {
        double lo[2], hi[2];  /* a cell's texel range: corner . u (v) / texel + these */
        double top;           /* its greatest height: corner . w + this */
    } box[256];               /* by the cell's mask of children: the boxes of its
                                 occupied children, grown by the margin */
    double child[SHADOW_MAP_MAX_DEPTH + 1][8][3]; /* child k's corner offset at depth d + 1,
                                                 projected: the corner's, summed on the way
                                                 down (one rounding a level, far under
                                                 the margin) */
    map_node *split;          /* the nodes of depth min(SPLIT_DEPTH, depth) */
    size_t nsplit;
    atomic_size_t next;       /* the next of them to take */
} build_ctx;

/* floor(x) clamped to [0, n - 1] (x >= 0 but for the margin); branch-free
 * (a NaN gives 0). */
static uint32_t texel(double x, uint32_t n)
{
    const double top = (double)(n - 1u);
    x = x > 0.0 ? x : 0.0;
    return (uint32_t)(x < top ? x : top);
}

/* x (finite or -inf) as a float no smaller than x. */
static float float_up(double x)
{
    float f = (float)x;
    if ((double)f < x) { /* rounded down: one step up, by its bits */
        uint32_t b;
        memcpy(&b, &f, sizeof b);
        if (f > 0.0f)
            b++;
        else if (f < 0.0f)
            b--;
        else
            b = 1u; /* the least subnormal */
        memcpy(&f, &b, sizeof f);
    }
    return f;
}

static void put_cell(const build_ctx *c, float *top, const double p[3], unsigned mask)
{
    const shadow_map *m = c->m;
    const float f = float_up(p[2] + c->box[mask].top);
    const double su = p[0] * m->inv_texel, sv = p[1] * m->inv_texel;
    const double *lo = c->box[mask].lo, *hi = c->box[mask].hi;
    const uint32_t i0 = texel(su + lo[0], m->nu), i1 = texel(su + hi[0], m->nu);
    const uint32_t j0 = texel(sv + lo[1], m->nv), j1 = texel(sv + hi[1], m->nv);
    for (uint32_t j = j0; j <= j1; j++) {
        float *row = &top[(size_t)j * m->nu];
        for (uint32_t i = i0; i <= i1; i++)
            row[i] = f > row[i] ? f : row[i]; /* maxss: no branch to mispredict */
    }
}

/* Where a walk puts what it reaches at its stop depth: the nodes into list
 * (the threads' subtrees), or, list NULL, the cells into top. */
typedef struct walk_out {
    float *top;
    map_node *list;
    size_t count;
} walk_out;

/* Node n of depth d and the nodes under it down to depth `stop`, in order. */
static void walk(const build_ctx *c, walk_out *out, unsigned d, unsigned stop,
                 const map_node *n)
{
    if (d == stop && out->list) {
        out->list[out->count++] = *n;
        return;
    }
    const oct_children ch = oct_node_children(c->tree->groups[d], n->index);
    if (d == stop) {
        put_cell(c, out->top, n->p, ch.mask);
        return;
    }
    map_node k;
    k.index = ch.first;
    for (unsigned i = 0; i < 8; i++) {
        if (!(ch.mask >> i & 1u))
            continue;
        for (int a = 0; a < 3; a++)
            k.p[a] = n->p[a] + c->child[d][i][a];
        walk(c, out, d + 1u, stop, &k);
        k.index++;
    }
}

typedef struct build_worker {
    build_ctx *c;
    float *top;
} build_worker;

static void *build_run(void *arg)
{
    const build_worker *w = arg;
    build_ctx *c = w->c;
    const unsigned d = c->depth < SPLIT_DEPTH ? c->depth : SPLIT_DEPTH;
    for (;;) {
        const size_t k = atomic_fetch_add(&c->next, 1);
        if (k >= c->nsplit)
            return NULL;
        walk_out out = {w->top, NULL, 0};
        walk(c, &out, d, c->depth, &c->split[k]);
    }
}

static float *empty_map(size_t texels)
{
    float *t = malloc(texels * sizeof *t);
    for (size_t k = 0; t && k < texels; k++)
        t[k] = -INFINITY;
    return t;
}

/* The cells put into m->top by up to `threads` threads. */
static int put_cells(build_ctx *c, unsigned threads)
{
    const shadow_map *m = c->m;
    const size_t texels = (size_t)m->nu * m->nv;
    const unsigned d = c->depth < SPLIT_DEPTH ? c->depth : SPLIT_DEPTH;
    c->split = malloc(((size_t)1 << (3 * d)) * sizeof *c->split);
    if (!c->split)
        return -1;
    const map_node root = {0, {0.0, 0.0, 0.0}};
    walk_out out = {NULL, c->split, 0};
    walk(c, &out, 0, d, &root);
    c->nsplit = out.count;
    atomic_init(&c->next, 0);
    if (threads > 8)
        threads = 8;
    if ((size_t)threads > c->nsplit)
        threads = c->nsplit ? (unsigned)c->nsplit : 1u;
    build_worker w[8];
    pthread_t tid[8];
    unsigned started = 1;
    w[0] = (build_worker){c, m->top};
    for (; started < threads; started++) {
        w[started] = (build_worker){c, empty_map(texels)};
        if (!w[started].top)
            break;
        if (pthread_create(&tid[started], NULL, build_run, &w[started]) != 0) {
            free(w[started].top);
            break; /* the started threads and this one do the rest */
        }
    }
    build_run(&w[0]);
    for (unsigned t = 1; t < started; t++) {
        pthread_join(tid[t], NULL);
        const float *src = w[t].top;
        for (size_t k = 0; k < texels; k++)
            if (m->top[k] < src[k])
                m->top[k] = src[k];
        free(w[t].top);
    }
    free(c->split);
    return 0;
}

int shadow_map_build(const oct_tree *tree, const double light[3], unsigned threads,
                     shadow_map *m)
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
    const double side = (double)(UINT32_C(1) << (levels - c.depth));
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
    m->inv_texel = 1.0 / side;
    m->nu = (uint32_t)((uhi + 1.0 - m->u0) * m->inv_texel) + 1u;
    m->nv = (uint32_t)((vhi + 1.0 - m->v0) * m->inv_texel) + 1u;
    m->top = empty_map((size_t)m->nu * m->nv);
    if (!m->top)
        return -1;
    const double *axes[3] = {m->u, m->v, m->w};
    for (unsigned d = 0; d <= c.depth; d++) {
        const double half = (double)(UINT32_C(1) << (levels - d - 1u));
        for (unsigned k = 0; k < 8; k++)
            for (int p = 0; p < 3; p++) {
                const double *ax = axes[p];
                c.child[d][k][p] = (double)(k & 1u) * half * ax[0] +
                                   (double)(k >> 1 & 1u) * half * ax[1] +
                                   (double)(k >> 2 & 1u) * half * ax[2];
            }
    }
    /* a child's extremes over its corners from its own corner, grown by the
       margin; a cell's, those of its occupied children, in texels from the
       plane's origin (the texel side is a power of two: scaling by it is exact) */
    const double half = side / 2.0;
    double clo[3], chi[3];
    for (int p = 0; p < 3; p++) {
        clo[p] = -SHADOW_MAP_MARGIN;
        chi[p] = SHADOW_MAP_MARGIN;
        for (int a = 0; a < 3; a++) {
            clo[p] += fmin(0.0, axes[p][a] * half);
            chi[p] += fmax(0.0, axes[p][a] * half);
        }
    }
    for (unsigned mask = 0; mask < 256; mask++) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (unsigned k = 0; k < 8; k++)
            for (int p = 0; mask >> k & 1u && p < 3; p++) {
                lo[p] = fmin(lo[p], c.child[c.depth][k][p] + clo[p]);
                hi[p] = fmax(hi[p], c.child[c.depth][k][p] + chi[p]);
            }
        for (int p = 0; p < 2; p++) {
            const double o = p ? m->v0 : m->u0;
            c.box[mask].lo[p] = (lo[p] - o) * m->inv_texel;
            c.box[mask].hi[p] = (hi[p] - o) * m->inv_texel;
        }
        c.box[mask].top = hi[2];
    }
    if (tree->node_count[0] && put_cells(&c, threads ? threads : 1u) != 0) {
        shadow_map_free(m);
        return -1;
    }
    return 0;
}

void shadow_map_free(shadow_map *m)
{
    free(m->top);
    m->top = NULL;
}

const shadow_map *shadow_map_cached(shadow_map_cache *c, const oct_tree *tree,
                                    const double light[3], unsigned threads, int *built)
{
    *built = 0;
    if (c->tree == tree && memcmp(c->map.light, light, sizeof c->map.light) == 0)
        return &c->map;
    shadow_map_cache_free(c);
    *built = 1;
    if (shadow_map_build(tree, light, threads, &c->map) != 0)
        return NULL;
    c->tree = tree;
    return &c->map;
}

void shadow_map_cache_free(shadow_map_cache *c)
{
    if (c->tree)
        shadow_map_free(&c->map);
    c->tree = NULL;
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
    const double top = (double)m->top[(size_t)(uint32_t)y * m->nu + (uint32_t)x];
    if (top == -INFINITY)
        return -INFINITY;
    return (top - dot3(g, m->w)) / (scale * dot3(light, m->w));
}
