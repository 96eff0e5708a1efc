/* shadow_map: the light's-eye heights of the occupied cells (shadow_map.h). */
#include "render/shadow_map.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "common/big_alloc.h"
#include "render/basis.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
    double child[SHADOW_MAP_MAX_DEPTH][8][3]; /* child k's corner offset at depth d + 1,
                                                 projected: the corner's, summed on the way
                                                 down (one rounding a level, far under
                                                 the margin) */
    double centre[3][8];      /* a cell's centre from its parent's corner, projected
                                 (by axis, then child), u and v in texels from the
                                 plane's origin */
    struct {
        double lo[2], hi[2];  /* a cell's box across the light from its centre, in
                                 texels (within 0.87 of it) */
        double top;           /* its greatest height from its centre's */
    } box[256];               /* by the cell's mask of children (a cell of voxels:
                                 255): its occupied children's corners, grown by
                                 the margin */
    map_node *split;          /* the nodes of depth min(SPLIT_DEPTH, depth - 1) */
    size_t nsplit;
    atomic_size_t next;       /* the next of them to take */
} build_ctx;

/* The cells of a parent of cells (corner projections p, its children
 * `ch`) into top: each raises the texels its box (c->box) meets to its
 * greatest height (rounded to nearest; merge_run adds the rest). A box is at
 * most 2 x 0.87 texels wide (one to three texels each way) and lies inside
 * the cube's projection grown by the margin; the map starts a grid unit
 * before that projection (its indices are never negative) and ends two
 * texels after it: the 3x3 block from the box's first texel needs no
 * clamp. */
static void put_cells_of(const build_ctx *c, float *top, const double p[3], oct_children ch)
{
    const size_t nu = c->m->nu;
    const double su = p[0] * c->m->inv_texel, sv = p[1] * c->m->inv_texel;
    const int voxels = c->depth == c->tree->levels;
    uint64_t index = ch.first;
    for (unsigned mask = ch.mask; mask; mask &= mask - 1u, index++) {
        const unsigned k = (unsigned)__builtin_ctz(mask);
        const unsigned cm = voxels ? 255u : oct_node_children(c->tree->groups[c->depth], index).mask;
        const double cu = su + c->centre[0][k], cv = sv + c->centre[1][k];
        const size_t i0 = (size_t)(int64_t)(cu + c->box[cm].lo[0]);
        const size_t i1 = (size_t)(int64_t)(cu + c->box[cm].hi[0]);
        const size_t j0 = (size_t)(int64_t)(cv + c->box[cm].lo[1]);
        const size_t j1 = (size_t)(int64_t)(cv + c->box[cm].hi[1]);
        const float f = (float)(p[2] + c->centre[2][k] + c->box[cm].top);
        /* one to three texels each way: a 3x3 block raised without a branch,
           by -inf where the box ends short */
        const float col[3] = {f, i1 > i0 ? f : -INFINITY, i1 > i0 + 1u ? f : -INFINITY};
        const float row[3] = {f, j1 > j0 ? f : -INFINITY, j1 > j0 + 1u ? f : -INFINITY};
        float *t = &top[j0 * nu + i0];
#pragma GCC unroll 3
        for (int r = 0; r < 3; r++, t += nu)
#pragma GCC unroll 3
            for (int q = 0; q < 3; q++) {
                const float x = col[q] < row[r] ? col[q] : row[r];
                t[q] = x > t[q] ? x : t[q]; /* maxss */
            }
    }
}

#if defined(__SSE2__)
#define SHADOW_MAP_SSE2 1
/* put_cells_of for a map of voxels (every cell's box is box[255]), in SSE2
 * lanes: the eight children's texels and heights two at a time (the same
 * sums in the same order as put_cells_of, so the same map), then each
 * occupied voxel's 3x3 block as three rows of four texels (the fourth
 * raised by -inf, unchanged: the map has a spare texel after its last). */
static void put_voxels_of(const build_ctx *c, float *top, const double p[3], unsigned mask)
{
    const size_t nu = c->m->nu;
    const __m128d SU = _mm_set1_pd(p[0] * c->m->inv_texel), SV = _mm_set1_pd(p[1] * c->m->inv_texel);
    const __m128d W = _mm_set1_pd(p[2]), TOP = _mm_set1_pd(c->box[255].top);
    const __m128d LU = _mm_set1_pd(c->box[255].lo[0]), HU = _mm_set1_pd(c->box[255].hi[0]);
    const __m128d LV = _mm_set1_pd(c->box[255].lo[1]), HV = _mm_set1_pd(c->box[255].hi[1]);
    int32_t i0[8], di[8], j0[8], dj[8];
    float f[8];
    for (int k = 0; k < 8; k += 2) {
        const __m128d cu = _mm_add_pd(SU, _mm_loadu_pd(&c->centre[0][k]));
        const __m128d cv = _mm_add_pd(SV, _mm_loadu_pd(&c->centre[1][k]));
        const __m128i a = _mm_cvttpd_epi32(_mm_add_pd(cu, LU)); /* (int32_t), as put_cells_of */
        const __m128i b = _mm_cvttpd_epi32(_mm_add_pd(cv, LV));
        _mm_storel_epi64((__m128i *)&i0[k], a);
        _mm_storel_epi64((__m128i *)&di[k], _mm_sub_epi32(_mm_cvttpd_epi32(_mm_add_pd(cu, HU)), a));
        _mm_storel_epi64((__m128i *)&j0[k], b);
        _mm_storel_epi64((__m128i *)&dj[k], _mm_sub_epi32(_mm_cvttpd_epi32(_mm_add_pd(cv, HV)), b));
        const __m128d h = _mm_add_pd(_mm_add_pd(W, _mm_loadu_pd(&c->centre[2][k])), TOP);
        _mm_storel_pi((__m64 *)&f[k], _mm_cvtpd_ps(h));
    }
    /* the texels of a row the box reaches, by how many follow its first (0..2) */
    static const union {
        uint32_t u[4];
        float x[4];
    } reach[3] = {{{~0u, 0, 0, 0}}, {{~0u, ~0u, 0, 0}}, {{~0u, ~0u, ~0u, 0}}};
    const __m128 NONE = _mm_set1_ps(-INFINITY);
    for (; mask; mask &= mask - 1u) {
        const unsigned k = (unsigned)__builtin_ctz(mask);
        const __m128 H = _mm_set1_ps(f[k]);
        const __m128 R = _mm_loadu_ps(reach[di[k]].x);
        const __m128 row = _mm_or_ps(_mm_and_ps(R, H), _mm_andnot_ps(R, NONE));
        const __m128 row2 = dj[k] > 0 ? row : NONE, row3 = dj[k] > 1 ? row : NONE;
        float *t = &top[(size_t)j0[k] * nu + (size_t)i0[k]];
        _mm_storeu_ps(t, _mm_max_ps(row, _mm_loadu_ps(t)));
        _mm_storeu_ps(t + nu, _mm_max_ps(row2, _mm_loadu_ps(t + nu)));
        _mm_storeu_ps(t + 2 * nu, _mm_max_ps(row3, _mm_loadu_ps(t + 2 * nu)));
    }
}
#else
#define SHADOW_MAP_SSE2 0
#endif

/* Where a walk puts what it reaches at its stop depth: the nodes into list
 * (the threads' subtrees), or, list NULL, their cells into top. */
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
#if SHADOW_MAP_SSE2
        if (c->depth == c->tree->levels) {
            put_voxels_of(c, out->top, n->p, ch.mask);
            return;
        }
#endif
        put_cells_of(c, out->top, n->p, ch);
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

#define BUILD_THREADS 8 /* at most: the build's threads and maps */

/* A thread of the build: first its share of the subtrees into a map of its
 * own, then its range of texels of the merge. */
typedef struct build_worker {
    build_ctx *c;
    float *top;      /* its map: made by the thread itself, NULL when it could not be */
    size_t lo, hi;   /* the merge: texels [lo, hi) */
    float *const *maps;
    unsigned nmaps;
} build_worker;

static unsigned split_depth(const build_ctx *c)
{
    return c->depth - 1u < SPLIT_DEPTH ? c->depth - 1u : SPLIT_DEPTH;
}

/* A map's texels and the spare one after them (put_voxels_of's fourth
 * column may reach it), all -inf (a megabyte or more: big_alloc's). */
static size_t map_bytes(size_t texels)
{
    return texels < SIZE_MAX / sizeof(float) ? (texels + 1u) * sizeof(float) : 0;
}

static float *empty_map(size_t texels)
{
    const size_t bytes = map_bytes(texels);
    float *t = bytes ? big_alloc(bytes) : NULL;
    for (size_t k = 0; t && k <= texels; k++)
        t[k] = -INFINITY;
    return t;
}

static size_t map_texels(const shadow_map *m) { return (size_t)m->nu * m->nv; }

/* Makes the thread's map (so that the threads clear theirs together), then
 * takes subtrees until none is left; without a map it takes none. */
static void *walk_run(void *arg)
{
    build_worker *w = arg;
    build_ctx *c = w->c;
    if (!w->top)
        w->top = empty_map(map_texels(c->m));
    while (w->top) {
        const size_t k = atomic_fetch_add(&c->next, 1);
        if (k >= c->nsplit)
            break;
        walk_out out = {w->top, NULL, 0};
        walk(c, &out, split_depth(c), c->depth - 1u, &c->split[k]);
    }
    return NULL;
}

/* Texels [lo, hi) of the threads' maps merged by their maximum into the
 * first, each height then one float step up (rounded to nearest, it is no
 * lower than the height it was rounded from). */
static void *merge_run(void *arg)
{
    const build_worker *w = arg;
    float *out = w->maps[0];
    for (size_t k = w->lo; k < w->hi; k++) {
        float v = out[k];
        for (unsigned t = 1; t < w->nmaps; t++)
            v = w->maps[t][k] > v ? w->maps[t][k] : v;
        out[k] = v == -INFINITY ? v : nextafterf(v, INFINITY);
    }
    return NULL;
}

/* Runs fn on w[0 .. n - 1]: w[0] on this thread, the others on threads of
 * their own where they can be started, else here after w[0]. */
static void run_all(void *(*fn)(void *), build_worker *w, unsigned n)
{
    pthread_t tid[BUILD_THREADS];
    int started[BUILD_THREADS] = {0};
    for (unsigned t = 1; t < n; t++)
        started[t] = pthread_create(&tid[t], NULL, fn, &w[t]) == 0;
    fn(&w[0]);
    for (unsigned t = 1; t < n; t++) {
        if (started[t])
            pthread_join(tid[t], NULL);
        else
            fn(&w[t]);
    }
}

/* m->top made, the cells put into it and the heights stepped up, on up to
 * `threads` threads: each puts whole subtrees into a map of its own, then
 * each merges a range of texels. */
static int put_cells(build_ctx *c, shadow_map *m, unsigned threads)
{
    const size_t texels = map_texels(m);
    const unsigned d = split_depth(c);
    c->split = malloc(((size_t)1 << (3 * d)) * sizeof *c->split);
    if (!c->split)
        return -1;
    const map_node root = {0, {0.0, 0.0, 0.0}};
    walk_out out = {NULL, c->split, 0};
    walk(c, &out, 0, d, &root);
    c->nsplit = out.count;
    atomic_init(&c->next, 0);
    if (threads > BUILD_THREADS)
        threads = BUILD_THREADS;
    if ((size_t)threads > c->nsplit)
        threads = c->nsplit ? (unsigned)c->nsplit : 1u;
    build_worker w[BUILD_THREADS];
    for (unsigned t = 0; t < threads; t++)
        w[t] = (build_worker){.c = c};
    run_all(walk_run, w, threads);
    free(c->split);
    /* the maps that were made (a thread that could not make one took no
       subtree: the others took them all) */
    float *maps[BUILD_THREADS];
    unsigned n = 0;
    for (unsigned t = 0; t < threads; t++)
        if (w[t].top)
            maps[n++] = w[t].top;
    int rc = 0;
    if (n == 0) {
        rc = -1;
    } else {
        for (unsigned t = 0; t < threads; t++)
            w[t] = (build_worker){.c = c,
                                  .lo = texels / threads * t,
                                  .hi = t + 1 == threads ? texels : texels / threads * (t + 1),
                                  .maps = maps,
                                  .nmaps = n};
        run_all(merge_run, w, threads);
        m->top = maps[0];
    }
    for (unsigned t = rc == 0; t < n; t++)
        big_free(maps[t], map_bytes(texels));
    return rc;
}

unsigned shadow_map_depth(const oct_tree *tree, unsigned up)
{
    const unsigned d = tree->levels > up ? tree->levels - up : 1u;
    const unsigned cap = up == SHADOW_MAP_FINE ? SHADOW_MAP_MAX_DEPTH : SHADOW_MAP_MAX_DEPTH - 1u;
    return d < cap ? d : cap;
}

unsigned shadow_map_up_for(const oct_tree *tree, uint64_t pixels)
{
    return tree->levels <= SHADOW_MAP_MAX_DEPTH && pixels >= tree->voxel_count
               ? SHADOW_MAP_FINE
               : SHADOW_MAP_COARSE;
}

/* The projection on axis ax of the offset (k_x + shift, k_y + shift,
 * k_z + shift) * step, k's bits the child's place in its parent: a child's
 * corner or centre from a corner or centre, by the shift. */
static double corner_along(const double ax[3], unsigned k, double shift, double step)
{
    return ((double)(k & 1u) + shift) * step * ax[0] +
           ((double)(k >> 1 & 1u) + shift) * step * ax[1] +
           ((double)(k >> 2 & 1u) + shift) * step * ax[2];
}

int shadow_map_build(const oct_tree *tree, const double light[3], unsigned up, unsigned threads,
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
    c.depth = shadow_map_depth(tree, up);
    m->depth = c.depth;
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
    m->nu = (uint32_t)((uhi + 1.0 - m->u0) * m->inv_texel) + 3u;
    m->nv = (uint32_t)((vhi + 1.0 - m->v0) * m->inv_texel) + 3u;
    m->top = NULL;
    const double *axes[3] = {m->u, m->v, m->w};
    for (unsigned d = 0; d + 1u < c.depth; d++) /* child k's corner from its parent's */
        for (unsigned k = 0; k < 8; k++)
            for (int p = 0; p < 3; p++)
                c.child[d][k][p] =
                    corner_along(axes[p], k, 0.0, (double)(UINT32_C(1) << (levels - d - 1u)));
    /* a cell's centre from its parent's corner; u and v from the plane's
       origin in texels (the texel side is a power of two: scaling by it is
       exact) */
    for (unsigned k = 0; k < 8; k++)
        for (int p = 0; p < 3; p++) {
            const double x = corner_along(axes[p], k, 0.5, side);
            c.centre[p][k] = p == 2 ? x : (x - (p ? m->v0 : m->u0)) * m->inv_texel;
        }
    /* a child's corners from the cell's centre, at most, grown by the
       margin; a cell's box, those of its occupied children */
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
    for (unsigned mask = 1; mask < 256; mask++) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (unsigned k = 0; k < 8; k++)
            for (int p = 0; mask >> k & 1u && p < 3; p++) {
                const double o = corner_along(axes[p], k, -1.0, half); /* from the centre */
                lo[p] = fmin(lo[p], o + clo[p]);
                hi[p] = fmax(hi[p], o + chi[p]);
            }
        for (int p = 0; p < 2; p++) {
            c.box[mask].lo[p] = lo[p] * m->inv_texel;
            c.box[mask].hi[p] = hi[p] * m->inv_texel;
        }
        c.box[mask].top = hi[2];
    }
    if (!tree->node_count[0]) { /* no cell: every texel -inf */
        m->top = empty_map(map_texels(m));
        return m->top ? 0 : -1;
    }
    return put_cells(&c, m, threads ? threads : 1u);
}

void shadow_map_free(shadow_map *m)
{
    big_free(m->top, map_bytes(map_texels(m)));
    m->top = NULL;
}

const shadow_map *shadow_map_cached(shadow_map_cache *c, const oct_tree *tree,
                                    const double light[3], unsigned up, unsigned threads,
                                    int *built)
{
    *built = 0;
    if (c->tree == tree && memcmp(c->map.light, light, sizeof c->map.light) == 0 &&
        c->map.depth >= shadow_map_depth(tree, up))
        return &c->map;
    shadow_map_cache_free(c);
    *built = 1;
    if (shadow_map_build(tree, light, up, threads, &c->map) != 0)
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
