/* trace: two-step discrete ray traversal of an oct_tree (see trace.h). */
#include "render/trace.h"

#include <math.h>

#include "format/oct_normal.h"

uint32_t trace_max_steps(unsigned levels)
{
    return 3u * (UINT32_C(1) << levels) + levels;
}

/* The voxel k in [lo, hi] along `axis` that the ray occupies at local time t
 * (trace.h's tie rule), starting from the estimate k. T is monotone in k, so
 * at most a few moves; the bounds keep it inside the cell being left. */
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

static uint32_t settle(const trace_ray *r, int axis, uint32_t k, uint32_t lo, uint32_t hi, double t);

/* The same from the position p = o + t*d on that axis. Fast path: when p is
 * more than SETTLE_MARGIN voxel inside a voxel of [lo, hi], that voxel is
 * the answer: p and T() differ by far less (about 2^-31 voxel at level 20,
 * see RENDER.md), so no T() evaluation can disagree. Otherwise settle. */
#define SETTLE_MARGIN 1e-6
static inline uint32_t settle_at(const trace_ray *r, int axis, double p, uint32_t lo, uint32_t hi,
                                 double t)
{
    double f = floor(p), frac = p - f;
    if (f >= (double)lo && f <= (double)hi && frac > SETTLE_MARGIN && frac < 1.0 - SETTLE_MARGIN)
        return (uint32_t)f;
    return settle(r, axis, floor_clamp(p, lo, hi), lo, hi, t);
}

static uint32_t settle(const trace_ray *r, int axis, uint32_t k, uint32_t lo, uint32_t hi, double t)
{
    if (r->sgn[axis] > 0) {
        while (k < hi && trace_plane_time(r, axis, (double)k + 1.0) <= t)
            k++;
        while (k > lo && trace_plane_time(r, axis, (double)k) > t)
            k--;
    } else {
        while (k > lo && trace_plane_time(r, axis, (double)k) <= t)
            k--;
        while (k < hi && trace_plane_time(r, axis, (double)k + 1.0) > t)
            k++;
    }
    return k;
}


int trace_setup(const oct_tree *tree, const double eye[3], const double dir[3], trace_ray *r)
{
    if (tree->levels < 1 || tree->levels > OCT_MAX_LEVELS)
        return 0;
    const uint32_t nvox = UINT32_C(1) << tree->levels;
    const double n = (double)nvox;
    const double scale = n / tree->edge;
    double o[3], d[3];
    unsigned active = 0;
    for (int a = 0; a < 3; a++) {
        if (!isfinite(eye[a]) || !isfinite(dir[a]))
            return 0;
        o[a] = (eye[a] - tree->origin[a]) * scale;
        d[a] = dir[a] * scale;
        if (!isfinite(o[a]) || !isfinite(d[a]))
            return 0;
        double inv = 1.0 / d[a];
        if (d[a] != 0.0 && isfinite(inv)) {
            active |= 1u << a;
            r->inv[a] = inv;
            r->sgn[a] = d[a] > 0 ? 1 : -1;
            r->d[a] = d[a];
        } else {
            r->inv[a] = 1.0;
            r->sgn[a] = 1;
            r->d[a] = 0.0;
        }
    }
    if (!active)
        return 0;
    r->active = active;

    /* One slab test against [0, n]^3. No 0 * inf: zero axes are tested by
     * position only. */
    double t0 = -INFINITY, t1 = INFINITY;
    int entry = -1;
    for (int a = 0; a < 3; a++) {
        if (!(active >> a & 1)) {
            if (o[a] < 0.0 || o[a] > n)
                return 0;
            continue;
        }
        double ta = (0.0 - o[a]) * r->inv[a], tb = (n - o[a]) * r->inv[a];
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
        for (int a = 0; a < 3; a++)
            r->o[a] = o[a];
    }
    double t_end = INFINITY;
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
    r->t_end = t_end;
    for (int a = 0; a < 3; a++) {
        r->v[a] = (active >> a & 1) ? settle_at(r, a, r->o[a], 0, nvox - 1, 0.0)
                                    : floor_clamp(r->o[a], 0, nvox - 1);
    }
    return 1;
}

/* --refine: local t where the ray meets voxel `idx`'s stored plane, if that
 * lies in [t_in, t_out]; -1 otherwise. The plane: n . (p - centre) = offset,
 * in voxel units (grid space). */
static double plane_time(const oct_tree *tree, const trace_ray *r, uint64_t idx,
                         const uint32_t v[3], double t_in, double t_out)
{
    uint32_t rec = tree->voxels[idx];
    float nf[3];
    oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
    double off = oct_offset_decode((int8_t)(uint8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
    double num = off, den = 0.0;
    for (int a = 0; a < 3; a++) {
        num -= (double)nf[a] * (r->o[a] - ((double)v[a] + 0.5));
        den += (double)nf[a] * r->d[a];
    }
    if (den == 0.0)
        return -1.0;
    double t = num / den;
    if (!(t >= t_in && t <= t_out))
        return -1.0;
    return t;
}

int trace_ray_prepared(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       trace_hit *hit)
{
    const unsigned levels = tree->levels;
    hit->hit = 0;
    hit->t = INFINITY;
    hit->steps = 0;
    if (tree->node_count[0] == 0)
        return 0;
    const unsigned split = opts->split > levels ? levels : opts->split;
    const uint32_t max_steps = trace_max_steps(levels);
    /* per axis: all ones when stepping up (the exit plane is the cell's top) */
    const uint32_t up[3] = {r->sgn[0] > 0 ? ~0u : 0u, r->sgn[1] > 0 ? ~0u : 0u,
                            r->sgn[2] > 0 ? ~0u : 0u};
    uint64_t node[OCT_MAX_LEVELS]; /* node[d]: the depth-d ancestor of v */
    unsigned valid = 0;            /* node[0..valid] hold for the current v */
    node[0] = 0;
    uint32_t v[3] = {r->v[0], r->v[1], r->v[2]};
    double tc = 0.0; /* local time the ray entered v */
    const double otx = r->ot[0], oty = r->ot[1], otz = r->ot[2];
    const double ivx = r->inv[0], ivy = r->inv[1], ivz = r->inv[2];
    const double t_end = r->t_end;
    uint32_t steps = 0;

    for (;;) {
        /* Vertical traverse (Figure 2) from the deepest still-valid ancestor
         * down to the first empty child, or to the voxel. */
        unsigned depth = valid;
        uint32_t size;   /* edge, in voxels, of the cell to leave next */
        int occupied = 0;
        uint64_t vidx = 0;
        for (;;) {
            const unsigned bit = levels - 1 - depth;
            const unsigned ci = ((v[0] >> bit) & 1u) | (((v[1] >> bit) & 1u) << 1) |
                                (((v[2] >> bit) & 1u) << 2);
            const oct_group *g = tree->groups[depth];
            if (!((oct_node_mask(g, node[depth]) >> ci) & 1u)) {
                /* Step one skips the whole empty cell while it is at depth
                 * <= K; below K, step two walks single voxels. */
                size = depth + 1 <= split ? UINT32_C(1) << bit : 1u;
                break;
            }
            uint64_t child = oct_child_index(g, node[depth], ci);
            if (depth == levels - 1) {
                occupied = 1;
                vidx = child;
                size = 1;
                break;
            }
            node[++depth] = child;
        }
        valid = depth;
        if (occupied && !opts->refine) {
            hit->hit = 1;
            hit->voxel = vidx;
            hit->t = r->t_base + tc;
            break;
        }

        /* Leave the cell: the nearest of its three exit planes, all from T(). */
        const uint32_t cmask = ~(size - 1u);
        const uint32_t lx = v[0] & cmask, ly = v[1] & cmask, lz = v[2] & cmask;
        const uint32_t bx = lx + (size & up[0]), by = ly + (size & up[1]), bz = lz + (size & up[2]);
        const double tx = (bx - otx) * ivx, ty = (by - oty) * ivy, tz = (bz - otz) * ivz;
        double te = tx < ty ? tx : ty;
        te = tz < te ? tz : te;
        if (occupied) {
            double tp = plane_time(tree, r, vidx, v, tc, te < t_end ? te : t_end);
            if (tp >= 0.0) {
                hit->hit = 1;
                hit->voxel = vidx;
                hit->t = r->t_base + tp;
                break;
            }
        }
        if (te >= t_end || ++steps > max_steps)
            break;
        uint32_t nx, ny, nz;
        if (size == 1u) {
            /* step two: unit steps, only the axes whose plane comes first */
            nx = tx == te ? (up[0] ? bx : bx - 1u) : v[0];
            ny = ty == te ? (up[1] ? by : by - 1u) : v[1];
            nz = tz == te ? (up[2] ? bz : bz - 1u) : v[2];
        } else {
            const uint32_t hi = size - 1u;
            nx = tx == te ? (up[0] ? bx : bx - 1u)
                 : (r->active & 1u) ? settle_at(r, 0, r->o[0] + te * r->d[0], lx, lx + hi, te)
                                    : v[0];
            ny = ty == te ? (up[1] ? by : by - 1u)
                 : (r->active & 2u) ? settle_at(r, 1, r->o[1] + te * r->d[1], ly, ly + hi, te)
                                    : v[1];
            nz = tz == te ? (up[2] ? bz : bz - 1u)
                 : (r->active & 4u) ? settle_at(r, 2, r->o[2] + te * r->d[2], lz, lz + hi, te)
                                    : v[2];
        }
        /* Figure 3's XOR: the highest changed bit names the common ancestor. */
        const uint32_t diff = (v[0] ^ nx) | (v[1] ^ ny) | (v[2] ^ nz);
        const unsigned keep = levels - 1u - (31u - (unsigned)__builtin_clz(diff | 1u));
        if (keep < valid)
            valid = keep;
        v[0] = nx;
        v[1] = ny;
        v[2] = nz;
        tc = te;
    }
    hit->xyz[0] = v[0];
    hit->xyz[1] = v[1];
    hit->xyz[2] = v[2];
    hit->steps = steps;
    return hit->hit;
}

int trace_ray_cast(const oct_tree *tree, const trace_opts *opts, const double eye[3],
                   const double dir[3], trace_hit *hit)
{
    trace_ray r;
    if (!trace_setup(tree, eye, dir, &r)) {
        hit->hit = 0;
        hit->t = INFINITY;
        hit->steps = 0;
        return 0;
    }
    return trace_ray_prepared(tree, opts, &r, hit);
}
