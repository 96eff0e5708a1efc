/* ao_grid: the clearance grid (ao_grid.h): the occupied cells at the grid's
 * depth from the tree, then each octant's clearances by a sweep against its
 * direction, packed into the cells' words one octant at a time. */
#include "render/ao_grid.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

unsigned ao_grid_depth(const oct_tree *tree)
{
    if (tree->levels < AO_GRID_MIN_SHIFT + 1u)
        return 0;
    const unsigned d = tree->levels - AO_GRID_MIN_SHIFT;
    return d > AO_GRID_MAX_DEPTH ? AO_GRID_MAX_DEPTH : d;
}

/* Writes the words of the occupied cells under node `node` at depth d,
 * whose cell's corner is (x, y, z) in cells of that depth, and marks them
 * in occ. (Depth 7 has at most 2^21 nodes: the index fits 28 bits.) */
static void mark(const oct_tree *tree, ao_grid *g, uint8_t *occ, unsigned d, uint64_t node,
                 uint32_t x, uint32_t y, uint32_t z)
{
    if (d == g->depth) {
        const size_t i = (size_t)x + (size_t)g->n * ((size_t)y + (size_t)g->n * z);
        g->cell[i] = (uint32_t)node << 4;
        occ[i] = 1;
        return;
    }
    const oct_children ch = oct_node_children(tree->groups[d], node);
    uint64_t k = ch.first;
    for (unsigned c = 0; c < 8; c++)
        if (ch.mask >> c & 1u)
            mark(tree, g, occ, d + 1, k++, 2 * x + (c & 1u), 2 * y + (c >> 1 & 1u),
                 2 * z + (c >> 2 & 1u));
}

/* Byte rows: out = min(a, b, c); the SSE2 body does 16 at a time. */
static void row_min3(uint8_t *out, const uint8_t *a, const uint8_t *b, const uint8_t *c, size_t n)
{
    size_t x = 0;
#ifdef __SSE2__
    for (; x + 16 <= n; x += 16) {
        const __m128i v = _mm_min_epu8(_mm_loadu_si128((const __m128i *)(a + x)),
                                       _mm_loadu_si128((const __m128i *)(b + x)));
        _mm_storeu_si128((__m128i *)(out + x),
                         _mm_min_epu8(v, _mm_loadu_si128((const __m128i *)(c + x))));
    }
#endif
    for (; x < n; x++) {
        const uint8_t v = a[x] < b[x] ? a[x] : b[x];
        out[x] = v < c[x] ? v : c[x];
    }
}

/* out[x] = min(out[x], in[x + s] + add) for x in [0, n), where in has
 * AO_GRID_MAX_CLEARANCE past both ends (ROW_PAD bytes of padding). */
static void row_min_shifted(uint8_t *out, const uint8_t *in, ptrdiff_t s, unsigned add, size_t n)
{
    size_t x = 0;
#ifdef __SSE2__
    const __m128i S = _mm_set1_epi8((char)add);
    for (; x + 16 <= n; x += 16) {
        const __m128i v = _mm_adds_epu8(_mm_loadu_si128((const __m128i *)(in + x + s)), S);
        _mm_storeu_si128((__m128i *)(out + x),
                         _mm_min_epu8(_mm_loadu_si128((const __m128i *)(out + x)), v));
    }
#endif
    for (; x < n; x++) {
        const unsigned v = in[(ptrdiff_t)x + s] + add;
        out[x] = v < out[x] ? (uint8_t)v : out[x];
    }
}

/* v[x] = 0 for an occupied cell, else min(v[x] + 1, the cap). */
static void row_step(uint8_t *v, const uint8_t *occ, size_t n)
{
    size_t x = 0;
#ifdef __SSE2__
    const __m128i ONE = _mm_set1_epi8(1), CAP = _mm_set1_epi8((char)AO_GRID_MAX_CLEARANCE);
    for (; x + 16 <= n; x += 16) {
        const __m128i m1 = _mm_adds_epu8(_mm_loadu_si128((const __m128i *)(v + x)), ONE);
        const __m128i m = _mm_min_epu8(m1, CAP);
        const __m128i empty = _mm_cmpeq_epi8(_mm_loadu_si128((const __m128i *)(occ + x)),
                                             _mm_setzero_si128());
        _mm_storeu_si128((__m128i *)(v + x), _mm_and_si128(m, empty));
    }
#endif
    for (; x < n; x++) {
        const unsigned m = v[x] + 1u;
        v[x] = occ[x] ? 0 : m < AO_GRID_MAX_CLEARANCE ? (uint8_t)m : AO_GRID_MAX_CLEARANCE;
    }
}

/* Octant o's clearances (cl) into the cells' words: an occupied cell's
 * clearance is 0, so its word (its node) is kept as it is. */
static void pack_octant(uint32_t *cell, const uint8_t *cl, unsigned o, size_t cells)
{
    size_t i = 0;
#ifdef __SSE2__
    const __m128i Z = _mm_setzero_si128();
    const __m128i SH = _mm_cvtsi32_si128((int)(4u * o));
    for (; i + 16 <= cells; i += 16) {
        const __m128i b = _mm_loadu_si128((const __m128i *)(cl + i));
        const __m128i lo = _mm_unpacklo_epi8(b, Z), hi = _mm_unpackhi_epi8(b, Z);
        const __m128i w[4] = {_mm_unpacklo_epi16(lo, Z), _mm_unpackhi_epi16(lo, Z),
                              _mm_unpacklo_epi16(hi, Z), _mm_unpackhi_epi16(hi, Z)};
        for (size_t q = 0; q < 4; q++) {
            __m128i *p = (__m128i *)(void *)(cell + i + 4 * q);
            _mm_storeu_si128(p, _mm_or_si128(_mm_loadu_si128(p), _mm_sll_epi32(w[q], SH)));
        }
    }
#endif
    for (; i < cells; i++)
        cell[i] |= (uint32_t)cl[i] << (4u * o);
}

/* Padding of the scratch rows on each side: the largest shift. */
#define ROW_PAD 16

/* Octant o's clearances into cl (a byte a cell) from occ (1: occupied).
 * The clearance of an empty cell c is 1 + the least of its 7 neighbours'
 * on o's side (outside the grid: the cap): the cube of edge k at c is
 * empty exactly when c is and the cubes of edge k - 1 at those 7 are.
 * Unrolled along the row x: r[x] = min over j >= 0 of v[x + j sx] + j,
 * where v is 0 for an occupied cell and 1 + the least of its 6 neighbours
 * off the row (rows done) for an empty one; an occupied cell at x + j sx
 * so bounds r[x] by j, as it should. The rows are visited against o's
 * direction; each row's min over j in four passes of shifts 1, 2, 4, 8
 * (j < 16 covers the cap). `scratch` holds 2 (n + 2 ROW_PAD) bytes, `cap`
 * n bytes of the cap. */
static void octant_clearances(uint8_t *cl, const uint8_t *occ, uint32_t n, unsigned o,
                              uint8_t *scratch, const uint8_t *cap)
{
    const ptrdiff_t N = (ptrdiff_t)n;
    const ptrdiff_t sx = o & 1u ? 1 : -1, sy = o & 2u ? 1 : -1, sz = o & 4u ? 1 : -1;
    uint8_t *a = scratch + ROW_PAD, *v = scratch + 2 * ROW_PAD + n + ROW_PAD;
    memset(scratch, AO_GRID_MAX_CLEARANCE, 2 * ((size_t)n + 2 * ROW_PAD));
    for (ptrdiff_t iz = 0; iz < N; iz++) {
        const ptrdiff_t z = sz > 0 ? N - 1 - iz : iz, zn = z + sz;
        const int zin = zn >= 0 && zn < N;
        for (ptrdiff_t iy = 0; iy < N; iy++) {
            const ptrdiff_t y = sy > 0 ? N - 1 - iy : iy, yn = y + sy;
            const int yin = yn >= 0 && yn < N;
            row_min3(a, yin ? cl + (yn + N * z) * N : cap, zin ? cl + (y + N * zn) * N : cap,
                     yin && zin ? cl + (yn + N * zn) * N : cap, n);
            memcpy(v, a, n);
            row_min_shifted(v, a, sx, 0, n); /* and the three at x + sx */
            row_step(v, occ + (y + N * z) * N, n);
            uint8_t *r = cl + (y + N * z) * N;
            memcpy(r, v, n);
            for (ptrdiff_t s = 1; s < 16; s *= 2) {
                row_min_shifted(r, v, s * sx, (unsigned)s, n);
                memcpy(v, r, n);
            }
        }
    }
}

int ao_grid_build(const oct_tree *tree, ao_grid *g)
{
    memset(g, 0, sizeof *g);
    const unsigned depth = ao_grid_depth(tree);
    if (!depth)
        return -1;
    const uint32_t n = UINT32_C(1) << depth;
    const size_t cells = (size_t)n * n * n;
    g->depth = depth;
    g->shift = tree->levels - depth;
    g->near_plane = ldexp(1.0, (int)tree->levels - 40);
    g->cell = calloc(cells, sizeof g->cell[0]);
    uint8_t *occ = calloc(cells, 1), *cl = malloc(cells),
            *scratch = malloc(3 * (size_t)n + 4 * ROW_PAD);
    if (!g->cell || !occ || !cl || !scratch) {
        free(occ);
        free(cl);
        free(scratch);
        ao_grid_free(g);
        return -1;
    }
    g->n = n;
    if (tree->node_count[0] != 0)
        mark(tree, g, occ, 0, 0, 0, 0, 0);
    uint8_t *cap = scratch + 2 * ((size_t)n + 2 * ROW_PAD);
    memset(cap, AO_GRID_MAX_CLEARANCE, n);
    for (unsigned o = 0; o < 8; o++) {
        octant_clearances(cl, occ, n, o, scratch, cap);
        pack_octant(g->cell, cl, o, cells);
    }
    free(occ);
    free(cl);
    free(scratch);
    return 0;
}

void ao_grid_free(ao_grid *g)
{
    free(g->cell);
    memset(g, 0, sizeof *g);
}
