/* trace_portable: the traversal (trace_impl.h) in plain C, built on every
 * target. The same algorithm as trace_sse.c, step for step: enter (the
 * paper's vertical traverse, Fig. 2), climb (the common ancestor, Fig. 3)
 * and the voxel walk (step two below K), with the same plane times
 * T_a(k) = (k - zo_a) * zi_a. */
#include <math.h>
#include <string.h>

#include "render/exact_scene.h"
#include "render/trace_impl.h"

/* The traversal's state: the plane-time parameters, the current cell (depth
 * d, child ci of its parent node, corner v, edge size) with its exit times t
 * and its parent's tp, the parent node (mask, prefix) and the stack of the
 * nodes from the root down to it. */
typedef struct walk {
    double zo[3], zi[3]; /* T_a(k) = (k - zo_a) * zi_a; a zero axis: v + 1/2, +inf */
    unsigned far;        /* child bit of the far half, per axis */
    unsigned d, ci;
    uint32_t size, v[3];
    double t[3], tp[3];
    uint32_t mask;
    uint64_t prefix;
    trace_frame fr[OCT_MAX_LEVELS];
} walk;

static double plane_time(const walk *w, int a, uint32_t k)
{
    return ((double)k - w->zo[a]) * w->zi[a];
}

/* The exit times of the cell holding voxel v with edge `edge`: T of its far
 * faces, the planes a descent takes from mid-plane times, bit for bit. */
static void cell_exits(const walk *w, const uint32_t v[3], uint32_t edge, double out[3])
{
    for (int a = 0; a < 3; a++)
        out[a] = plane_time(w, a, (v[a] & ~(edge - 1u)) + (w->far >> a & 1u ? edge : 0u));
}

static double min3(const double t[3])
{
    const double m = t[0] < t[2] ? t[0] : t[2];
    return m < t[1] ? m : t[1];
}

/* enter (Fig. 2, one level): the child of the cell (corner v, edge size) the
 * ray is in at tc; per axis the far half when the mid plane is crossed at or
 * before tc, and the child's exit time is the mid plane's (near) or the
 * cell's own (far: tp). Sets ci to the child's index when ci is not NULL. */
static void enter(const walk *w, uint32_t v[3], uint32_t *size, double tc, double t[3],
                        const double tp[3], unsigned *ci)
{
    const uint32_t half = *size >> 1;
    unsigned c = 0;
    for (int a = 0; a < 3; a++) {
        const double tm = plane_time(w, a, v[a] + half);
        const unsigned near = tc < tm;
        t[a] = near ? tm : tp[a];
        const unsigned b = near ^ (w->far >> a & 1u);
        v[a] |= (0u - b) & half;
        c |= b << a;
    }
    *size = half;
    if (ci)
        *ci = c;
}

/* The voxel walk (step two, below K): the empty cell (corner v, edge size >
 * 1, entered at tc with exit times t) walked voxel by voxel: its entry voxel
 * found as by enter, then a unit DDA on T of the voxel's far faces until the
 * cell's own exit time, where the caller leaves the cell. Returns the step
 * count, max_steps + 1 when the bound is passed. */
static uint32_t voxel_walk(const walk *w, double tc, uint32_t steps, uint32_t max_steps)
{
    uint32_t v[3] = {w->v[0], w->v[1], w->v[2]}, size = w->size;
    double t[3] = {w->t[0], w->t[1], w->t[2]};
    const double te_cell = min3(t);
    while (size > 1)
        enter(w, v, &size, tc, t, t, NULL);
    for (;;) {
        const double te = min3(t);
        if (te >= te_cell || ++steps > max_steps)
            return steps;
        for (int a = 0; a < 3; a++) {
            const uint32_t f = w->far >> a & 1u;
            if (t[a] == te)
                v[a] += f ? 1u : UINT32_MAX; /* +1 or -1 */
            t[a] = plane_time(w, a, v[a] + f);
        }
    }
}

/* climb (Fig. 3): the step at te through the axes smask leaves the parent
 * too (one of them is on its far half): pop until the common ancestor, the
 * node in which the step stays, and make its child beside the way up the
 * current cell (exit times t, its parent's tp). *smask becomes the stepped
 * set there. Returns 0 when the root is left. */
static int climb(walk *w, double te, unsigned *smask_io)
{
    unsigned smask = *smask_io;
    do {
        w->d--;
        if (w->d == 0)
            return 0; /* the root is left (te >= t_end catches it first) */
        w->size <<= 1;
        w->ci = w->fr[w->d].ci;
        /* One stepped axis a, on the far half: the parent's exit on a is the
         * same plane (= te) and its other exits are later, so its stepped
         * set is {a} again; only ties need comparing anew, with the parent's
         * own exit times. */
        if (smask & (smask - 1u)) {
            cell_exits(w, w->v, w->size, w->t);
            smask = 0;
            for (int a = 0; a < 3; a++)
                smask |= (unsigned)(w->t[a] == te) << a;
        }
    } while (~(w->ci ^ w->far) & smask);
    for (int a = 0; a < 3; a++)
        w->v[a] &= ~(w->size - 1u);
    cell_exits(w, w->v, w->size, w->t);
    cell_exits(w, w->v, 2u * w->size, w->tp);
    w->mask = w->fr[w->d - 1].mask;
    w->prefix = w->fr[w->d - 1].prefix;
    *smask_io = smask;
    return 1;
}

int trace_traverse_portable(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                            const trace_anchor *anchor, trace_hit *hit)
{
    const unsigned levels = tree->levels;
    hit->hit = 0;
    hit->t = INFINITY;
    hit->steps = 0;
    hit->exact = 0;
    if (tree->node_count[0] == 0)
        return 0;
    const unsigned split = opts->split > levels ? levels : opts->split;
    const uint32_t max_steps = trace_max_steps(levels);
    const double t_end = r->t_end;
    walk w;
    w.far = 0;
    for (int a = 0; a < 3; a++) {
        const int act = r->active >> a & 1;
        w.zo[a] = act ? r->ot[a] : (double)r->v[a] + 0.5;
        w.zi[a] = act ? r->inv[a] : INFINITY;
        w.far |= (r->sgn[a] > 0 ? 1u : 0u) << a; /* sgn is +1 on a zero axis */
        w.v[a] = 0;
    }
    w.mask = tree->groups[0][0].mask[0];
    w.prefix = tree->groups[0][0].base;
    w.fr[0].mask = w.mask;
    w.fr[0].prefix = w.prefix;
    w.fr[0].ci = 0;
    w.d = 0;
    w.ci = 0;
    w.size = UINT32_C(1) << levels;
    if (anchor && anchor->depth) {
        /* the start lies in the anchor's cell: the descent from the root
         * would take its path */
        w.d = anchor->depth;
        memcpy(w.fr, anchor->node, (w.d + 1) * sizeof w.fr[0]);
        w.size = UINT32_C(1) << (levels - w.d);
        memcpy(w.v, anchor->cell, sizeof w.v);
        w.mask = w.fr[w.d].mask;
        w.prefix = w.fr[w.d].prefix;
    }
    cell_exits(&w, w.v, w.size, w.tp);
    double tc = r->t_start;
    uint32_t steps = 0;
    int side = 0; /* --refine: see trace_refine_voxel */

    enter(&w, w.v, &w.size, tc, w.t, w.tp, &w.ci);
    w.d++;
    for (;;) {
        if (w.mask >> w.ci & 1u) {
            const uint64_t n = w.prefix + oct_popcount64(w.mask & ((1u << w.ci) - 1u));
            if (w.d == levels) {
                /* a voxel */
                double t_hit = tc;
                if (opts->exact) {
                    const double te = min3(w.t);
                    hit->voxel = n; /* (exact_voxel reads it) */
                    hit->hit = exact_voxel(opts->exact, r, w.v, tc, te < t_end ? te : t_end,
                                           &t_hit, hit);
                } else if (!opts->refine) {
                    hit->hit = 1;
                } else {
                    const double te = min3(w.t);
                    hit->hit = trace_refine_voxel(tree, r, n, w.v, tc, te < t_end ? te : t_end,
                                                  &side, &t_hit);
                }
                if (hit->hit) {
                    hit->voxel = n;
                    hit->t = r->t_base + t_hit;
                    break;
                }
            } else {
                /* the cell becomes the parent: push it, then enter its child */
                const oct_children ch = oct_node_children(tree->groups[w.d], n);
                w.fr[w.d].mask = ch.mask;
                w.fr[w.d].prefix = ch.first;
                w.fr[w.d].ci = w.ci;
                w.mask = ch.mask;
                w.prefix = ch.first;
                memcpy(w.tp, w.t, sizeof w.tp);
                enter(&w, w.v, &w.size, tc, w.t, w.tp, &w.ci);
                w.d++;
                continue;
            }
        } else {
            if (w.d > split && w.d < levels) {
                steps = voxel_walk(&w, tc, steps, max_steps);
                if (steps > max_steps)
                    break;
            }
            side = 0;
        }

        /* leave the cell through its nearest exit planes (all axes whose
         * exit time is te) */
        const double te = min3(w.t);
        if (te >= t_end || ++steps > max_steps)
            break;
        unsigned smask = 0;
        for (int a = 0; a < 3; a++)
            smask |= (unsigned)(w.t[a] == te) << a;
        if ((~(w.ci ^ w.far) & smask) && !climb(&w, te, &smask))
            break;
        /* the sibling across the stepped axes: their exits are the parent's */
        w.ci ^= smask;
        for (int a = 0; a < 3; a++) {
            if (smask >> a & 1u) {
                w.t[a] = w.tp[a];
                w.v[a] ^= w.size;
            }
        }
        tc = te;
    }
    memcpy(hit->xyz, w.v, sizeof hit->xyz);
    hit->steps = steps;
    return hit->hit;
}

/* The any-hit walk (trace_impl.h), trace_occluded_sse's steps in plain C:
 * each occupied cell's children on the ray's way (trace_path_children)
 * tested against its mask before it is entered. */
int trace_occluded_portable(const oct_tree *tree, const trace_ray *r, const trace_anchor *anchor,
                            uint32_t *steps_out)
{
    const unsigned levels = tree->levels;
    uint32_t steps = 0, mn;
    uint64_t pn;
    int hit = 0;
    *steps_out = 0;
    if (tree->node_count[0] == 0)
        return 0;
    const uint32_t max_steps = trace_max_steps(levels);
    const double t_end = r->t_end;
    walk w;
    w.far = 0;
    for (int a = 0; a < 3; a++) {
        const int act = r->active >> a & 1;
        w.zo[a] = act ? r->ot[a] : (double)r->v[a] + 0.5;
        w.zi[a] = act ? r->inv[a] : INFINITY;
        w.far |= (r->sgn[a] > 0 ? 1u : 0u) << a;
        w.v[a] = 0;
    }
    w.mask = tree->groups[0][0].mask[0];
    w.prefix = tree->groups[0][0].base;
    w.fr[0].mask = w.mask;
    w.fr[0].prefix = w.prefix;
    w.fr[0].ci = 0;
    w.size = UINT32_C(1) << levels;
    double tc = r->t_start;
    if (anchor && anchor->depth) {
        /* the anchor's cell is the current one: tested like any other */
        w.d = anchor->depth;
        memcpy(w.fr, anchor->node, (w.d + 1) * sizeof w.fr[0]);
        w.size = UINT32_C(1) << (levels - w.d);
        memcpy(w.v, anchor->cell, sizeof w.v);
        cell_exits(&w, w.v, w.size, w.t);
        cell_exits(&w, w.v, 2u * w.size, w.tp);
        w.ci = w.fr[w.d].ci;
        w.mask = w.fr[w.d - 1].mask;
        w.prefix = w.fr[w.d - 1].prefix;
        mn = w.fr[w.d].mask;
        pn = w.fr[w.d].prefix;
        goto look;
    }
    /* from the root, tested like any other cell */
    w.d = 0;
    w.ci = 0;
    cell_exits(&w, w.v, w.size, w.t);
    mn = w.mask;
    pn = w.prefix;
    goto look;
    for (;;) {
        if (w.mask >> w.ci & 1u) {
            if (w.d == levels) {
                hit = 1; /* entered after a tie above */
                break;
            }
            const uint64_t n = w.prefix + oct_popcount64(w.mask & ((1u << w.ci) - 1u));
            const oct_children ch = oct_node_children(tree->groups[w.d], n);
            mn = ch.mask;
            pn = ch.first;
        look:;
            /* enter's mid-plane times, and the children they make the ray visit */
            const uint32_t half = w.size >> 1;
            double lim = min3(w.t);
            if (t_end < lim)
                lim = t_end;
            double tm[3];
            unsigned c0 = 0, crossed = 0;
            for (int a = 0; a < 3; a++) {
                tm[a] = plane_time(&w, a, w.v[a] + half);
                const unsigned near = tc < tm[a];
                c0 |= (near ^ (w.far >> a & 1u)) << a;
                crossed |= (unsigned)(near && tm[a] < lim) << a;
            }
            const unsigned order = (unsigned)(tm[0] < tm[1]) | (unsigned)(tm[1] < tm[2]) << 1 |
                                   (unsigned)(tm[0] < tm[2]) << 2;
            if (!(trace_path_children[c0 | crossed << 3 | order << 6] & mn)) {
                if (!w.d)
                    break; /* the root */
                goto step; /* nothing on the way: as an empty cell */
            }
            if (w.d + 1 == levels) {
                /* the set is exact unless two crossed mid planes tie */
                const unsigned eq = (unsigned)(tm[0] == tm[1]) | (unsigned)(tm[1] == tm[2]) << 1 |
                                    (unsigned)(tm[0] == tm[2]) << 2;
                if (!(eq & TRACE_PAIRS(crossed))) {
                    hit = 1; /* a voxel on the way */
                    break;
                }
            }
            /* push the cell and enter its child c0 (enter's rule) */
            w.fr[w.d].mask = mn;
            w.fr[w.d].prefix = pn;
            w.fr[w.d].ci = w.ci;
            w.mask = mn;
            w.prefix = pn;
            for (int a = 0; a < 3; a++) {
                w.tp[a] = w.t[a];
                if ((c0 ^ w.far) >> a & 1u) /* near half: the mid plane is its exit */
                    w.t[a] = tm[a];
                w.v[a] |= (0u - (c0 >> a & 1u)) & half;
            }
            w.ci = c0;
            w.size = half;
            w.d++;
            continue;
        }
    step:;
        const double te = min3(w.t);
        if (te >= t_end || ++steps > max_steps)
            break;
        unsigned smask = 0;
        for (int a = 0; a < 3; a++)
            smask |= (unsigned)(w.t[a] == te) << a;
        if ((~(w.ci ^ w.far) & smask) && !climb(&w, te, &smask))
            break;
        w.ci ^= smask;
        for (int a = 0; a < 3; a++) {
            if (smask >> a & 1u) {
                w.t[a] = w.tp[a];
                w.v[a] ^= w.size;
            }
        }
        tc = te;
    }
    *steps_out = steps;
    return hit;
}
