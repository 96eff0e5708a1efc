/* trace_packet: one depth-first walk of the octree for a packet of rays
 * (see trace_packet.h). Plain C, the same on every target. */
#include "render/trace_packet.h"

#include <math.h>

#define LANES TRACE_PACKET_MAX

/* What the walk keeps for the whole packet. Lane s is ray s. */
typedef struct packet {
    double zo[3][LANES], zi[3][LANES]; /* T_a(k) = (k - zo_a) * zi_a */
    double tb[LANES];                  /* t_base */
    const oct_tree *tree;
    trace_hit *hits;
    unsigned levels;
    unsigned flip;  /* bit a: the rays go down axis a (child k ^ flip is k-th in order) */
    uint32_t alive; /* lanes whose voxel is not found yet */
} packet;

/* The lanes in each child of a node and their intervals there. */
typedef struct child_lanes {
    uint32_t lanes[8];
    double lo[8][LANES], hi[8][LANES];
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
    for (unsigned k = 0; k < 8; k++)
        ch.lanes[k] = 0;
    unsigned todo = node_steps(p, c, half, lo, hi, live, &ch);
    const int leaf = d + 1 == p->levels;
    for (; todo; todo &= todo - 1u) {
        const unsigned k = (unsigned)__builtin_ctz(todo), ci = k ^ p->flip;
        if (!(och.mask >> ci & 1u))
            continue;
        const uint32_t m = ch.lanes[k] & p->alive;
        if (!m)
            continue;
        const uint64_t idx = och.first + oct_popcount64(och.mask & ((1u << ci) - 1u));
        uint32_t cc[3];
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

void trace_packet_first(const oct_tree *tree, const trace_ray *r, unsigned n, trace_hit *hits)
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
    p.flip = 0;
    for (unsigned k = 0; k < n; k++)
        for (unsigned a = 0; a < 3; a++)
            if (r[k].active >> a & 1u && r[k].sgn[a] < 0)
                p.flip |= 1u << a;
    double lo[LANES], hi[LANES];
    uint32_t live = 0;
    for (unsigned s = 0; s < n; s++) {
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
