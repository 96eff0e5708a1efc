/* trace_setup: a ray mapped into a tree's grid and clipped to its root cube
 * (trace_setup, trace_eye_init / trace_setup_eye, trace_dir_init /
 * trace_setup_dir, trace_clip), and the
 * anchors a bundle of rays starts from (trace_anchor_find). See trace.h. */
#include "render/trace.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

#include "render/trace_impl.h"

/* trace_anchor's nodes are copied onto the traversal's frames */
_Static_assert(sizeof(trace_frame) == 16 && offsetof(trace_frame, mask) == 8 &&
                   offsetof(trace_frame, ci) == 12 && sizeof(((trace_anchor *)0)->node[0]) == 16,
               "trace_anchor node layout");

uint32_t trace_max_steps(unsigned levels)
{
    return 3u * (UINT32_C(1) << levels) + levels;
}

/* floor(x) clamped to [lo, hi] and converted without overflow. */
static uint32_t floor_clamp(double x, uint32_t lo, uint32_t hi)
{
    double f = floor(x);
    if (!(f >= (double)lo))
        return lo;
    if (f >= (double)hi)
        return hi;
    return (uint32_t)f;
}

int trace_eye_init(const oct_tree *tree, const double eye[3], trace_eye *e)
{
    e->ok = 0;
    if (tree->levels < 1 || tree->levels > OCT_MAX_LEVELS)
        return 0;
    e->nvox = UINT32_C(1) << tree->levels;
    e->n = (double)e->nvox;
    e->scale = e->n / tree->edge;
    if (!(e->scale > 0.0 && e->scale <= DBL_MAX)) /* trace_setup_eye relies on it */
        return 0;
    for (int a = 0; a < 3; a++) {
        if (!isfinite(eye[a]))
            return 0;
        e->o[a] = (eye[a] - tree->origin[a]) * e->scale;
        if (!isfinite(e->o[a]))
            return 0;
        e->lo[a] = 0.0 - e->o[a];
        e->hi[a] = e->n - e->o[a];
        e->inside[a] = !(e->o[a] < 0.0 || e->o[a] > e->n);
    }
    e->all_inside = e->inside[0] && e->inside[1] && e->inside[2];
    e->ok = 1;
    return 1;
}

/* The per-axis part of a direction d (in grid units): 1/d, sign and d, with 1,
 * +1 and 0 on an axis whose reciprocal is not finite; returns the mask of the
 * other (active) axes. One place for trace_setup_eye's, trace_dir_init's and
 * setup_inside's rule. */
static inline unsigned dir_axes(const double d[3], double inv_out[3], int32_t sgn[3],
                                double d_out[3])
{
    unsigned active = 0;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        const double inv = 1.0 / d[a];
        const int act = fabs(inv) <= DBL_MAX;
        active |= (unsigned)act << a;
        inv_out[a] = act ? inv : 1.0;
        sgn[a] = act && d[a] < 0.0 ? -1 : 1;
        d_out[a] = act ? d[a] : 0.0;
    }
    return active;
}

/* setup_inside for a direction with no zero axis (every 1/d finite: an
 * AO ray, nearly always): dir_axes' values and the loop's comparisons in
 * the same order, written out without the zero-axis cases. */
static inline int setup_inside_all(const trace_eye *e, const double d[3], double inv0,
                                   double inv1, double inv2, trace_ray *r)
{
    const double inv[3] = {inv0, inv1, inv2};
    double t_end = INFINITY;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        const int neg = d[a] < 0.0;
        r->inv[a] = inv[a];
        r->sgn[a] = neg ? -1 : 1;
        r->d[a] = d[a];
        r->o[a] = e->o[a];
        r->ot[a] = e->o[a];
        r->v[a] = 0u;
        const double te = (neg ? e->lo[a] : e->hi[a]) * inv[a];
        if (te < t_end)
            t_end = te;
    }
    if (!(t_end > 0.0))
        return 0;
    r->active = 7u;
    r->t_base = 0.0;
    r->t_start = 0.0;
    r->t_end = t_end;
    return 1;
}

/* The axis part of an inside set-up once r's inv, sgn and d are made: the
 * origin, its voxel on inactive axes, and the root exit time. 0: no ray. */
static inline int inside_axes(const trace_eye *e, unsigned active, trace_ray *r)
{
    double t_end = INFINITY;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        const int act = active >> a & 1u;
        r->o[a] = e->o[a];
        r->ot[a] = act ? e->o[a] : -INFINITY;
        r->v[a] = act ? 0u : floor_clamp(e->o[a], 0, e->nvox - 1);
        if (act) {
            const double te = (r->d[a] < 0.0 ? e->lo[a] : e->hi[a]) * r->inv[a];
            if (te < t_end)
                t_end = te;
        }
    }
    if (!active || !(t_end > 0.0))
        return 0;
    r->active = active;
    r->t_base = 0.0;
    r->t_start = 0.0;
    r->t_end = t_end;
    return 1;
}

/* trace_setup_eye from an eye inside the root cube (the start of secondary
 * rays): there every axis' slab entry time is <= 0, so the ray is never
 * re-based, and its slab exit time is the root exit time T(n or 0) the
 * general path computes afterwards, the same product of the same values.
 * So: the same ray, bit for bit, in one pass over the axes. */
static int setup_inside(const trace_eye *e, const double dir[3], trace_ray *r)
{
    const double scale = e->scale;
    double d[3];
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++)
        d[a] = dir[a] * scale;
    if (!(fabs(d[0]) <= DBL_MAX && fabs(d[1]) <= DBL_MAX && fabs(d[2]) <= DBL_MAX))
        return 0;
    const double inv0 = 1.0 / d[0], inv1 = 1.0 / d[1], inv2 = 1.0 / d[2];
    if (fabs(inv0) <= DBL_MAX && fabs(inv1) <= DBL_MAX && fabs(inv2) <= DBL_MAX)
        return setup_inside_all(e, d, inv0, inv1, inv2, r); /* dir_axes' test, every axis */
    return inside_axes(e, dir_axes(d, r->inv, r->sgn, r->d), r);
}

int trace_setup_eye(const trace_eye *e, const double dir[3], trace_ray *r)
{
    if (!e->ok)
        return 0;
    if (e->all_inside)
        return setup_inside(e, dir, r);
    return trace_setup_eye_general(e, dir, r);
}

void trace_dir_init(const trace_eye *e, const double dir[3], trace_dir *td)
{
    const double scale = e->scale;
    double d[3];
    for (int a = 0; a < 3; a++) {
        td->dir[a] = dir[a];
        d[a] = dir[a] * scale;
    }
    td->scale = scale;
    td->ok = 0;
    if (!(fabs(d[0]) <= DBL_MAX && fabs(d[1]) <= DBL_MAX && fabs(d[2]) <= DBL_MAX))
        return;
    const unsigned active = dir_axes(d, td->inv, td->sgn, td->d);
    td->active = active;
    td->ok = active != 0;
}

int trace_setup_dir(const trace_eye *e, const trace_dir *td, trace_ray *r)
{
    if (!e->ok)
        return 0;
    if (!e->all_inside)
        return trace_setup_eye_general(e, td->dir, r);
    if (!td->ok)
        return 0;
    /* setup_inside with the direction's part made: the same values */
    for (int a = 0; a < 3; a++) {
        r->inv[a] = td->inv[a];
        r->sgn[a] = td->sgn[a];
        r->d[a] = td->d[a];
    }
    return inside_axes(e, td->active, r);
}

int trace_setup_eye_general(const trace_eye *e, const double dir[3], trace_ray *r)
{
    if (!e->ok)
        return 0;
    const double n = e->n, scale = e->scale;
    const double *o = e->o;
    /* scale is finite and > 0, so d is finite exactly when dir is and the
     * product does not overflow; 1/d is finite exactly when d is neither 0
     * nor so small that the reciprocal overflows */
    double d[3];
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++)
        d[a] = dir[a] * scale;
    if (!(fabs(d[0]) <= DBL_MAX && fabs(d[1]) <= DBL_MAX && fabs(d[2]) <= DBL_MAX))
        return 0;
    const unsigned active = dir_axes(d, r->inv, r->sgn, r->d);
    if (!active)
        return 0;
    r->active = active;

    /* One slab test against [0, n]^3. No 0 * inf: zero axes are tested by
     * position only. */
    double t0 = -INFINITY, t1 = INFINITY;
    int entry = -1;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        if (!(active >> a & 1)) {
            if (!e->inside[a])
                return 0;
            continue;
        }
        double ta = e->lo[a] * r->inv[a], tb = e->hi[a] * r->inv[a];
        double lo = ta < tb ? ta : tb, hi = ta < tb ? tb : ta;
        if (lo > t0) {
            t0 = lo;
            entry = a;
        }
        if (hi < t1)
            t1 = hi;
    }
    if (!(t0 <= t1) || !(t1 > 0.0))
        return 0;

    /* Re-base a ray from outside to its entry point, so that T() works on
     * coordinates of the grid's magnitude whatever the eye's distance. */
    if (t0 > 0.0) {
        r->t_base = t0;
#pragma GCC unroll 3
        for (int a = 0; a < 3; a++) {
            double p = o[a];
            if (a == entry)
                p = r->sgn[a] > 0 ? 0.0 : n;
            else if (active >> a & 1)
                p = o[a] + t0 * r->d[a];
            r->o[a] = p < 0.0 ? 0.0 : p > n ? n : p;
        }
    } else {
        r->t_base = 0.0;
#pragma GCC unroll 3
        for (int a = 0; a < 3; a++)
            r->o[a] = o[a];
    }
    double t_end = INFINITY;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        r->ot[a] = (active >> a & 1) ? r->o[a] : -INFINITY;
        if (active >> a & 1) {
            double te = trace_plane_time(r, a, r->sgn[a] > 0 ? n : 0.0);
            if (te < t_end)
                t_end = te;
        }
    }
    if (!(t_end > 0.0))
        return 0;
    r->t_start = 0.0;
    r->t_end = t_end;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        r->v[a] = (active >> a & 1) ? 0u : floor_clamp(r->o[a], 0, e->nvox - 1);
    }
    return 1;
}

int trace_setup(const oct_tree *tree, const double eye[3], const double dir[3], trace_ray *r)
{
    trace_eye e;
    if (!trace_eye_init(tree, eye, &e))
        return 0;
    return trace_setup_eye(&e, dir, r);
}

int trace_clip(trace_ray *r, double t_lo, double t_hi)
{
    const double lo = t_lo - r->t_base, hi = t_hi - r->t_base;
    if (lo > r->t_start)
        r->t_start = lo;
    if (hi < r->t_end)
        r->t_end = hi;
    return r->t_start < r->t_end;
}

/* trace_anchor_find, the nodes down to the deepest cell the box shares
 * with `near`'s (a result of this search on the same tree, or NULL) taken
 * from near instead of the tree: the same nodes, as the search from the
 * root passes them. a may be near. */
static void anchor_search(const oct_tree *tree, const double lo[3], const double hi[3],
                          const trace_anchor *near, trace_anchor *a)
{
    const unsigned levels = tree->levels;
    const unsigned pd = near ? near->depth : 0;
    uint32_t pc[3] = {0, 0, 0};
    for (int i = 0; pd && i < 3; i++)
        pc[i] = near->cell[i];
    a->depth = 0;
    a->cell[0] = a->cell[1] = a->cell[2] = 0;
    if (tree->node_count[0] == 0 || levels < 1 || levels > OCT_MAX_LEVELS)
        return; /* an empty tree: nothing to anchor */
    a->node[0].prefix = tree->groups[0][0].base;
    a->node[0].mask = tree->groups[0][0].mask[0];
    a->node[0].ci = 0;
    const double n = (double)(UINT32_C(1) << levels);
    for (int i = 0; i < 3; i++)
        if (!(lo[i] > 0.0 && hi[i] < n && lo[i] <= hi[i])) /* NaN too */
            return;
    /* whole voxels: the box lies in voxels [vl, vh]; it straddles two
     * cells of depth d exactly when vl ^ vh has a bit at levels - d or
     * above, so the deepest depth it can reach is known at once */
    uint32_t vl[3], diff = 0, off = 0;
    for (int i = 0; i < 3; i++) {
        vl[i] = (uint32_t)lo[i];
        diff |= vl[i] ^ (uint32_t)hi[i];
        off |= vl[i] ^ pc[i];
    }
    unsigned dmax = levels - 1;
    if (diff) {
        const unsigned bits = 32u - (unsigned)__builtin_clz(diff);
        if (bits > levels - 1u)
            return; /* it straddles two children of the root */
        dmax = levels - bits < dmax ? levels - bits : dmax;
    }
    /* near's cell of depth d <= pd holds the box's when vl and its corner
     * agree above bit levels - d */
    unsigned d0 = pd < dmax ? pd : dmax;
    if (off) {
        const unsigned bits = 32u - (unsigned)__builtin_clz(off);
        const unsigned common = bits >= levels ? 0 : levels - bits;
        d0 = common < d0 ? common : d0;
    }
    if (a != near)
        for (unsigned d = 1; d <= d0; d++)
            a->node[d] = near->node[d];
    unsigned d = d0 + 1;
    for (; d <= dmax; d++) {
        const unsigned sh = levels - d;
        const unsigned c = (vl[0] >> sh & 1u) | (vl[1] >> sh & 1u) << 1 | (vl[2] >> sh & 1u) << 2;
        const uint32_t m = a->node[d - 1].mask;
        if (!(m >> c & 1u))
            break; /* an empty cell: its parent is the deepest occupied one */
        const uint64_t idx = a->node[d - 1].prefix + oct_popcount64(m & ((1u << c) - 1u));
        const oct_children ch = oct_node_children(tree->groups[d], idx);
        a->node[d].mask = ch.mask;
        a->node[d].prefix = ch.first;
        a->node[d].ci = c;
    }
    a->depth = d - 1;
    const unsigned sh = levels - a->depth;
    for (int i = 0; a->depth && i < 3; i++)
        a->cell[i] = vl[i] >> sh << sh;
}

void trace_anchor_find(const oct_tree *tree, const double lo[3], const double hi[3],
                       trace_anchor *a)
{
    anchor_search(tree, lo, hi, NULL, a);
}

void trace_anchor_find_near(const oct_tree *tree, const double lo[3], const double hi[3],
                            const trace_anchor *near, trace_anchor *a)
{
    anchor_search(tree, lo, hi, near, a);
}
