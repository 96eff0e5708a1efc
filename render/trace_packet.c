/* trace_packet: one depth-first walk of the octree for a packet of rays
 * (see trace_packet.h). The lanes' steps through a node in plain C
 * (node_steps) and, where the target has SSE2, two lanes at a time
 * (node_steps_sse2): the same values, bit for bit. */
#include "render/trace_packet.h"

#include <math.h>

#if TRACE_PACKET_HAVE_SSE2
#include <emmintrin.h>
#endif

#define LANES TRACE_PACKET_MAX

/* What the walk keeps for the whole packet. Lane s is ray s; lanes past
 * the packet's rays hold harmless values (the SSE2 steps read lanes in
 * pairs). */
typedef struct packet {
    _Alignas(16) double zo[3][LANES];
    _Alignas(16) double zi[3][LANES]; /* T_a(k) = (k - zo_a) * zi_a */
    double tb[LANES];                  /* t_base */
    const oct_tree *tree;
    trace_hit *hits;
    unsigned levels;
    unsigned flip;  /* bit a: the rays go down axis a (child k ^ flip is k-th in order) */
    uint32_t alive; /* lanes whose voxel is not found yet */
    int sse2;       /* 1: node_steps_sse2 */
} packet;

/* The lanes in each child of a node and their intervals there. */
typedef struct child_lanes {
    _Alignas(16) double lo[8][LANES];
    _Alignas(16) double hi[8][LANES];
    uint32_t lanes[8]; /* node_steps: the lanes in child k */
    uint64_t w[LANES / 8]; /* node_steps_sse2: bit 16 (q % 4) + 2k + l of w[q / 4]
                              for lane 2q + l in child k (pair q), 0 elsewhere */
} child_lanes;

int trace_packet_fits(const trace_ray *r, unsigned n)
{
    if (n > LANES)
        return 0;
    for (int a = 0; a < 3; a++) {
        unsigned pos = 0, neg = 0;
        for (unsigned k = 0; k < n; k++)
            if (r[k].active >> a & 1u) {
                pos |= r[k].sgn[a] > 0;
                neg |= r[k].sgn[a] < 0;
            }
        if (pos && neg)
            return 0;
    }
    return 1;
}

/* The children of a node each lane of `live` passes through, in its order,
 * and its interval in each: the traversal's own steps inside the node.
 * The lane enters at lo the child whose far halves are those of the axes
 * whose mid plane it crossed at or before lo (enter's rule); it leaves a
 * child at the least mid-plane time of its near axes, or at hi, the node's
 * end, and enters the child across every axis whose mid plane it crosses
 * then (a tie: straight to the diagonal child). So the child c's interval
 * is [max(lo, tm of its far axes), min(hi, tm of its near axes)), the tie
 * rule read on the child, the same values bit for bit; the children of
 * the other lanes' steps are exactly those whose interval is not empty.
 * ch->lanes[k]: the lanes in child k (front-to-back order: bit a set for
 * the far half along the rays); returns the union of the k touched. */
static unsigned node_steps(const packet *p, const uint32_t c[3], uint32_t half,
                           const double *nlo, const double *nhi, uint32_t live,
                           child_lanes *ch)
{
    const double km[3] = {(double)(c[0] + half), (double)(c[1] + half), (double)(c[2] + half)};
    unsigned touched = 0;
    for (uint32_t b = live; b; b &= b - 1u) {
        const unsigned s = (unsigned)__builtin_ctz(b);
        const double lo = nlo[s], hi = nhi[s];
        double t[3];
        unsigned k = 0;
#pragma GCC unroll 3
        for (unsigned a = 0; a < 3; a++) {
            t[a] = (km[a] - p->zo[a][s]) * p->zi[a][s];
            k |= (unsigned)(t[a] <= lo) << a;
        }
        double l = lo;
        for (;;) {
            double e = hi;
#pragma GCC unroll 3
            for (unsigned a = 0; a < 3; a++)
                if (!(k >> a & 1u) && t[a] < e)
                    e = t[a];
            ch->lanes[k] |= UINT32_C(1) << s;
            ch->lo[k][s] = l;
            ch->hi[k][s] = e;
            touched |= 1u << k;
            if (!(e < hi))
                break;
#pragma GCC unroll 3
            for (unsigned a = 0; a < 3; a++)
                k |= (unsigned)(t[a] == e) << a;
            l = e;
        }
    }
    return touched;
}

#if TRACE_PACKET_HAVE_SSE2
/* node_steps for two lanes at a time, without following each lane's steps:
 * child k's interval is [L(k), H(k)), L(k) = max(lo, tm of its far axes),
 * H(k) = min(hi, tm of its near axes), for all eight children from 7 max
 * and 7 min (each over its axes in increasing order, as node_steps
 * compares them: _mm_max_pd(t, acc) keeps acc on a tie, _mm_min_pd(t, acc)
 * too), and a lane is in child k when L(k) < H(k). These are node_steps'
 * values bit for bit: its entry child's start is lo, each later child's
 * the exit time of the one before, which is the largest tm of the axes
 * crossed then (the first of them on a tie, as here); its ends are H(k),
 * computed in the same order. A lane of a pair outside `live` computes
 * values no mask lets out (from slots written before: the set-up fills
 * every lane, and each pair's child slots are written whole). */
static unsigned node_steps_sse2(const packet *p, const uint32_t c[3], uint32_t half,
                                const double *nlo, const double *nhi, uint32_t live,
                                child_lanes *ch)
{
    const __m128d km0 = _mm_set1_pd((double)(c[0] + half));
    const __m128d km1 = _mm_set1_pd((double)(c[1] + half));
    const __m128d km2 = _mm_set1_pd((double)(c[2] + half));
    const uint32_t pairs = (live | live >> 1) & UINT32_C(0x55555555);
    unsigned any = 0;
    ch->w[0] = ch->w[1] = 0;
    for (uint32_t b = pairs; b; b &= b - 1u) {
        const unsigned s = (unsigned)__builtin_ctz(b);
        const __m128d lo = _mm_load_pd(nlo + s), hi = _mm_load_pd(nhi + s);
        const __m128d t0 = _mm_mul_pd(_mm_sub_pd(km0, _mm_load_pd(&p->zo[0][s])),
                                      _mm_load_pd(&p->zi[0][s]));
        const __m128d t1 = _mm_mul_pd(_mm_sub_pd(km1, _mm_load_pd(&p->zo[1][s])),
                                      _mm_load_pd(&p->zi[1][s]));
        const __m128d t2 = _mm_mul_pd(_mm_sub_pd(km2, _mm_load_pd(&p->zo[2][s])),
                                      _mm_load_pd(&p->zi[2][s]));
        __m128d L[8], H[8];
        L[0] = lo;
        L[1] = _mm_max_pd(t0, lo);
        L[2] = _mm_max_pd(t1, lo);
        L[3] = _mm_max_pd(t1, L[1]);
        L[4] = _mm_max_pd(t2, lo);
        L[5] = _mm_max_pd(t2, L[1]);
        L[6] = _mm_max_pd(t2, L[2]);
        L[7] = _mm_max_pd(t2, L[3]);
        H[7] = hi;
        H[6] = _mm_min_pd(t0, hi);
        H[5] = _mm_min_pd(t1, hi);
        H[4] = _mm_min_pd(t1, H[6]);
        H[3] = _mm_min_pd(t2, hi);
        H[2] = _mm_min_pd(t2, H[6]);
        H[1] = _mm_min_pd(t2, H[5]);
        H[0] = _mm_min_pd(t2, H[4]);
#pragma GCC unroll 8
        for (unsigned k = 0; k < 8; k++) {
            _mm_store_pd(&ch->lo[k][s], L[k]);
            _mm_store_pd(&ch->hi[k][s], H[k]);
        }
        /* the eight compare masks to 16 bits, 2k + l, by packing */
        __m128 cm[8];
#pragma GCC unroll 8
        for (unsigned k = 0; k < 8; k++)
            cm[k] = _mm_castpd_ps(_mm_cmplt_pd(L[k], H[k]));
        const __m128i p0 = _mm_packs_epi32(
            _mm_castps_si128(_mm_shuffle_ps(cm[0], cm[1], _MM_SHUFFLE(2, 0, 2, 0))),
            _mm_castps_si128(_mm_shuffle_ps(cm[2], cm[3], _MM_SHUFFLE(2, 0, 2, 0))));
        const __m128i p1 = _mm_packs_epi32(
            _mm_castps_si128(_mm_shuffle_ps(cm[4], cm[5], _MM_SHUFFLE(2, 0, 2, 0))),
            _mm_castps_si128(_mm_shuffle_ps(cm[6], cm[7], _MM_SHUFFLE(2, 0, 2, 0))));
        static const uint16_t of_lanes[4] = {0, 0x5555u, 0xaaaau, 0xffffu};
        const unsigned w = (unsigned)_mm_movemask_epi8(_mm_packs_epi16(p0, p1)) &
                           of_lanes[live >> s & 3u];
        ch->w[s >> 3] |= (uint64_t)w << (16u * (s >> 1 & 3u));
        any |= w;
    }
    /* child k is touched when bit 2k or 2k + 1 of `any` is set */
    unsigned touched = (any | any >> 1) & 0x5555u;
    touched = (touched | touched >> 1) & 0x3333u;
    touched = (touched | touched >> 2) & 0x0f0fu;
    touched = (touched | touched >> 4) & 0x00ffu;
    return touched;
}

/* The lanes node_steps_sse2 put in child k: the 2-bit group 2k of each
 * pair's 16 bits, four pairs a word, gathered by one multiplication. After
 * the mask, pair q's group is at bit 16q; the product's term for pair q and
 * factor 2^(48 - 14j) lands at bit 48 + 16q - 14j, and only j = q puts a
 * term in bits 48..55 (at 48 + 2q); the terms' 2-bit fields never overlap,
 * so nothing carries. */
_Static_assert(LANES == 16, "pair_lanes gathers two words of four pairs");

static inline uint32_t pair_lanes(const child_lanes *ch, unsigned k)
{
    const uint64_t groups = UINT64_C(0x0003000300030003);
    const uint64_t gather = UINT64_C(1) << 48 | UINT64_C(1) << 34 | UINT64_C(1) << 20 | UINT64_C(1) << 6;
    const uint64_t lo = ((ch->w[0] >> (2u * k) & groups) * gather) >> 48 & 0xffu;
    const uint64_t hi = ((ch->w[1] >> (2u * k) & groups) * gather) >> 48 & 0xffu;
    return (uint32_t)(lo | hi << 8);
}
#endif

/* The children of mask `m` (bit ci) in the order of `flip` (bit ci ^ flip). */
static inline unsigned mask_in_order(unsigned m, unsigned flip)
{
    if (flip & 1u)
        m = (m & 0x55u) << 1 | (m >> 1 & 0x55u);
    if (flip & 2u)
        m = (m & 0x33u) << 2 | (m >> 2 & 0x33u);
    if (flip & 4u)
        m = (m & 0x0fu) << 4 | (m >> 4 & 0x0fu);
    return m;
}

/* Node `node` of depth d (corner c, edge size), met by the lanes `live` over
 * [lo, hi) each: its occupied children front to back, each opened for the
 * lanes that pass through it and are still looking; a voxel ends the
 * search of the lanes in it. */
static void visit(packet *p, unsigned d, uint64_t node, const uint32_t c[3], uint32_t size,
                  const double *lo, const double *hi, uint32_t live)
{
    const oct_children och = oct_node_children(p->tree->groups[d], node);
    const uint32_t half = size >> 1;
    child_lanes ch;
    unsigned todo;
#if TRACE_PACKET_HAVE_SSE2
    if (p->sse2) {
        todo = node_steps_sse2(p, c, half, lo, hi, live, &ch);
    } else
#endif
    {
        for (unsigned k = 0; k < 8; k++)
            ch.lanes[k] = 0;
        todo = node_steps(p, c, half, lo, hi, live, &ch);
    }
    const int leaf = d + 1 == p->levels;
    for (todo &= mask_in_order(och.mask, p->flip); todo; todo &= todo - 1u) {
        const unsigned k = (unsigned)__builtin_ctz(todo), ci = k ^ p->flip;
#if TRACE_PACKET_HAVE_SSE2
        const uint32_t m = (p->sse2 ? pair_lanes(&ch, k) : ch.lanes[k]) & p->alive;
#else
        const uint32_t m = ch.lanes[k] & p->alive;
#endif
        if (!m)
            continue;
        const uint64_t idx = och.first + oct_popcount64(och.mask & ((1u << ci) - 1u));
        uint32_t cc[3];
#pragma GCC unroll 3
        for (unsigned a = 0; a < 3; a++)
            cc[a] = c[a] + ((ci >> a & 1u) ? half : 0u);
        if (leaf) {
            for (uint32_t b = m; b; b &= b - 1u) {
                const unsigned s = (unsigned)__builtin_ctz(b);
                trace_hit *h = &p->hits[s];
                h->hit = 1;
                h->voxel = idx;
                h->t = p->tb[s] + ch.lo[k][s];
                for (unsigned a = 0; a < 3; a++)
                    h->xyz[a] = cc[a];
            }
            p->alive &= ~m;
        } else {
            visit(p, d + 1, idx, cc, half, ch.lo[k], ch.hi[k], m);
        }
        if (!(live & p->alive))
            return;
    }
}

/* The walk, node_steps in SSE2 lanes or not. */
static void packet_first(const oct_tree *tree, const trace_ray *r, unsigned n, trace_hit *hits,
                         int sse2)
{
    for (unsigned k = 0; k < n; k++) {
        hits[k].hit = 0;
        hits[k].voxel = 0;
        hits[k].xyz[0] = hits[k].xyz[1] = hits[k].xyz[2] = 0;
        hits[k].t = INFINITY;
        hits[k].steps = 0;
        hits[k].exact = 0;
    }
    if (n == 0 || n > LANES || tree->node_count[0] == 0)
        return;
    packet p;
    p.tree = tree;
    p.hits = hits;
    p.levels = tree->levels;
    p.sse2 = sse2;
    p.flip = 0;
    for (unsigned k = 0; k < n; k++)
        for (unsigned a = 0; a < 3; a++)
            if (r[k].active >> a & 1u && r[k].sgn[a] < 0)
                p.flip |= 1u << a;
    _Alignas(16) double lo[LANES], hi[LANES];
    uint32_t live = 0;
    /* the SSE2 steps read lanes in pairs: the lane past an odd n too */
    for (unsigned s = 0; s < n + (n & 1u); s++) {
        if (s >= n) { /* no ray: finite values, an empty interval */
            for (unsigned a = 0; a < 3; a++) {
                p.zo[a][s] = 0.5;
                p.zi[a][s] = 1.0;
            }
            p.tb[s] = 0.0;
            lo[s] = hi[s] = 0.0;
            continue;
        }
        const trace_ray *ray = &r[s];
        for (unsigned a = 0; a < 3; a++) {
            const int act = ray->active >> a & 1u;
            /* a zero axis as trace_sse.c has it, turned to the packet's
               order: T = -inf up to the ray's voxel v, +inf past it, along
               the order */
            p.zo[a][s] = act ? ray->ot[a] : (double)ray->v[a] + 0.5;
            p.zi[a][s] = act ? ray->inv[a] : (p.flip >> a & 1u) ? -INFINITY : INFINITY;
        }
        p.tb[s] = ray->t_base;
        lo[s] = ray->t_start;
        hi[s] = ray->t_end;
        live |= (uint32_t)(lo[s] < hi[s]) << s;
    }
    p.alive = live;
    const uint32_t corner[3] = {0, 0, 0};
    if (live)
        visit(&p, 0, 0, corner, UINT32_C(1) << p.levels, lo, hi, live);
}

void trace_packet_first(const oct_tree *tree, const trace_ray *r, unsigned n, trace_hit *hits)
{
    packet_first(tree, r, n, hits, TRACE_PACKET_HAVE_SSE2);
}

void trace_packet_first_portable(const oct_tree *tree, const trace_ray *r, unsigned n,
                                 trace_hit *hits)
{
    packet_first(tree, r, n, hits, 0);
}
