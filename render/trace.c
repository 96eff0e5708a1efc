/* trace: two-step discrete ray traversal of an oct_tree (see trace.h). */
#include "render/trace.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

#include "format/oct_normal.h"

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
    e->ok = 1;
    return 1;
}

int trace_setup_eye(const trace_eye *e, const double dir[3], trace_ray *r)
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
    unsigned active = 0;
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        const double inv = 1.0 / d[a];
        const int act = fabs(inv) <= DBL_MAX;
        active |= (unsigned)act << a;
        r->inv[a] = act ? inv : 1.0;
        r->sgn[a] = act && d[a] < 0.0 ? -1 : 1;
        r->d[a] = act ? d[a] : 0.0;
    }
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

void trace_anchor_find(const oct_tree *tree, const double lo[3], const double hi[3],
                       trace_anchor *a)
{
    const unsigned levels = tree->levels;
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
    /* whole voxels: the box lies in voxels [vl, vh] */
    uint32_t vl[3], vh[3];
    for (int i = 0; i < 3; i++) {
        vl[i] = (uint32_t)lo[i];
        vh[i] = (uint32_t)hi[i];
    }
    for (unsigned d = 1; d < levels; d++) {
        const unsigned sh = levels - d;
        if ((vl[0] >> sh) != (vh[0] >> sh) || (vl[1] >> sh) != (vh[1] >> sh) ||
            (vl[2] >> sh) != (vh[2] >> sh))
            return; /* the box straddles two cells of depth d */
        const unsigned c = (vl[0] >> sh & 1u) | (vl[1] >> sh & 1u) << 1 | (vl[2] >> sh & 1u) << 2;
        const uint32_t m = a->node[d - 1].mask;
        if (!(m >> c & 1u))
            return; /* an empty cell: its parent is the deepest occupied one */
        const uint64_t idx = a->node[d - 1].prefix + oct_popcount64(m & ((1u << c) - 1u));
        const oct_children ch = oct_node_children(tree->groups[d], idx);
        a->node[d].mask = ch.mask;
        a->node[d].prefix = ch.first;
        a->node[d].ci = c;
        a->depth = d;
        for (int i = 0; i < 3; i++)
            a->cell[i] = vl[i] >> sh << sh;
    }
}

/* --refine in one occupied voxel `idx` (corner v), which the ray occupies
 * for local t in [t_in, t_out]. The stored plane n . (p - centre) = offset
 * (voxel units) splits space into s > 0 and s < 0, s(t) = n . (p(t) -
 * centre) - offset; its normal is the field's gradient, so the side is
 * consistent from voxel to voxel. *side is the side the ray was on when it
 * entered the current run of consecutive occupied voxels (0: no run yet; the
 * caller resets it in every empty cell). The ray hits this voxel when it is
 * already across (s(t_in) on the other side, or 0: it crossed on the shared
 * face or between two neighbours' slightly different planes: t_in), or
 * crosses inside (s(t_out) across or 0: the plane time clamped to the
 * voxel). Otherwise it goes on with *side kept. Returns 1 and sets *t_hit on
 * a hit. */
static int refine_voxel(const oct_tree *tree, const trace_ray *r, uint64_t idx,
                        const uint32_t v[3], double t_in, double t_out, int *side, double *t_hit)
{
    const uint32_t rec = tree->voxels[idx];
    float nf[3];
    oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, nf);
    double num = oct_offset_decode((int8_t)(uint8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT)), den = 0.0;
    for (int a = 0; a < 3; a++) {
        num -= (double)nf[a] * (r->o[a] - ((double)v[a] + 0.5));
        den += (double)nf[a] * r->d[a];
    }
    /* s(t) = t * den - num */
    const double s_in = t_in * den - num, s_out = t_out * den - num;
    if (*side == 0)
        *side = s_in > 0.0 ? 1 : -1;
    if (!(s_in * *side > 0.0)) {
        *t_hit = t_in;
        return 1;
    }
    if (!(s_out * *side > 0.0)) {
        const double tp = num / den; /* den != 0: s changed sign */
        *t_hit = tp < t_in ? t_in : tp > t_out ? t_out : tp;
        return 1;
    }
    return 0;
}

#if defined(__SSE4_1__)
/* The same traversal with the three axes in SSE registers: (x, y) in one,
 * (z, w) in the other, w a dummy lane (o = inv = 0) whose exit time stays
 * +inf: its mid-plane time is 0, never > tc, so it never picks a near half,
 * and it never equals a step time te < t_end, so its mask bits are 0. The
 * arithmetic per lane is the scalar T() above, operation for operation. */
typedef struct trace_frame_v {
    uint64_t prefix;
    uint32_t mask, ci;
} trace_frame_v;
/* trace_anchor's nodes are copied onto the frames */
_Static_assert(sizeof(trace_frame_v) == 16 && offsetof(trace_frame_v, mask) == 8 &&
                   offsetof(trace_frame_v, ci) == 12 && sizeof(((trace_anchor *)0)->node[0]) == 16,
               "trace_anchor node layout");

/* The exit times of the cell with corner V (bits below `edge` ignored) and
 * edge `edge`, T(corner + far * edge) per axis: the same T of the same
 * planes as a descent blends from mid-plane times, bit for bit. FARM has
 * all bits set in the lanes of the far axes; the dummy lane w comes out 0
 * and is raised to +inf by WINF = (-inf, +inf). */
static inline void trace_cell_exits(__m128i V, uint32_t edge, __m128i FARM, __m128d ZOxy,
                                    __m128d ZOzw, __m128d ZIxy, __m128d ZIzw, __m128d WINF,
                                    __m128d *txy, __m128d *tzw)
{
    const __m128i C = _mm_andnot_si128(_mm_set1_epi32((int32_t)(edge - 1u)), V);
    const __m128i K = _mm_add_epi32(C, _mm_and_si128(_mm_set1_epi32((int32_t)edge), FARM));
    *txy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(K), ZOxy), ZIxy);
    *tzw = _mm_max_pd(_mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(K, K)), ZOzw), ZIzw),
                      WINF);
}

/* lane masks for a 3-bit axis set */
static const int32_t trace_lut[8][4] __attribute__((aligned(16))) = {
    {0, 0, 0, 0},   {-1, 0, 0, 0},   {0, -1, 0, 0},   {-1, -1, 0, 0},
    {0, 0, -1, 0},  {-1, 0, -1, 0},  {0, -1, -1, 0},  {-1, -1, -1, 0},
};

/* Step two below K: walks the empty cell (corner V, edge size > 1, entered
 * at tc with exit times Txy, Tzw) voxel by voxel. Its entry voxel is found
 * bit by bit as on entry into any cell; then a unit DDA whose exit times are
 * T of the voxel's far faces runs until the cell's own exit time, where the
 * caller leaves the cell as above K: the same voxels, times and step count as
 * walking the cell as a subtree with an all-empty mask. Returns the step
 * count (steps plus the voxel steps taken), max_steps + 1 when the bound is
 * passed. Out of line: the default K = L never calls it. */
static __attribute__((noinline)) uint32_t
trace_walk_empty(__m128i V, uint32_t size, __m128d TC, __m128d Wxy, __m128d Wzw, __m128d ZOxy,
                 __m128d ZOzw, __m128d ZIxy, __m128d ZIzw, double zoz, double ziz, unsigned far,
                 uint32_t steps, uint32_t max_steps)
{
    const __m128d c2 = _mm_min_pd(Wxy, Wzw);
    const double te_cell = _mm_cvtsd_f64(_mm_min_pd(c2, _mm_shuffle_pd(c2, c2, 1)));
    while (size > 1) {
        const uint32_t half = size >> 1;
        const __m128i H = _mm_set1_epi32((int32_t)half);
        const __m128i MID = _mm_add_epi32(V, H);
        const __m128d TMxy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(MID), ZOxy), ZIxy);
        const __m128d TMzw =
            _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(MID, MID)), ZOzw), ZIzw);
        const __m128d Nxy = _mm_cmplt_pd(TC, TMxy), Nzw = _mm_cmplt_pd(TC, TMzw);
        Wxy = _mm_blendv_pd(Wxy, TMxy, Nxy);
        Wzw = _mm_blendv_pd(Wzw, TMzw, Nzw);
        const unsigned b = ((unsigned)_mm_movemask_pd(Nxy) | (unsigned)_mm_movemask_pd(Nzw) << 2) ^ far;
        V = _mm_or_si128(V, _mm_and_si128(H, _mm_load_si128((const __m128i *)trace_lut[b])));
        size = half;
    }
    /* far-face offsets and unit moves per lane; the dummy lane w uses
     * o = -1/2, inv = +inf so that its exit time is +inf */
    const __m128i FARV = _mm_setr_epi32((int32_t)(far & 1u), (int32_t)(far >> 1 & 1u),
                                        (int32_t)(far >> 2 & 1u), 0);
    const __m128i DIRV = _mm_sub_epi32(_mm_add_epi32(FARV, FARV), _mm_set1_epi32(1));
    const __m128d WZOzw = _mm_setr_pd(zoz, -0.5), WZIzw = _mm_setr_pd(ziz, INFINITY);
    for (;;) {
        const __m128d w2 = _mm_min_pd(Wxy, Wzw);
        const __m128d WEv = _mm_min_pd(w2, _mm_shuffle_pd(w2, w2, 1));
        if (_mm_cvtsd_f64(WEv) >= te_cell)
            return steps;
        if (++steps > max_steps)
            return steps;
        const unsigned wm = (unsigned)_mm_movemask_pd(_mm_cmpeq_pd(Wxy, WEv)) |
                            (unsigned)_mm_movemask_pd(_mm_cmpeq_pd(Wzw, WEv)) << 2;
        V = _mm_add_epi32(V, _mm_and_si128(DIRV, _mm_load_si128((const __m128i *)trace_lut[wm])));
        const __m128i F = _mm_add_epi32(V, FARV);
        Wxy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(F), ZOxy), ZIxy);
        Wzw = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(F, F)), WZOzw), WZIzw);
    }
}

static int trace_ray_run(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                         const trace_anchor *anchor, trace_hit *hit)
{
    const unsigned levels = tree->levels;
    hit->hit = 0;
    hit->t = INFINITY;
    hit->steps = 0;
    if (tree->node_count[0] == 0)
        return 0;
    const unsigned split = opts->split > levels ? levels : opts->split;
    const int refine = opts->refine;
    const uint32_t max_steps = trace_max_steps(levels);
    const double t_end = r->t_end;
    const oct_group *const *groups = tree->groups;

    double zo[4], zi[4], root[4];
    unsigned far = 0;
    const double nroot = (double)(UINT32_C(1) << levels);
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        const int act = r->active >> a & 1;
        zo[a] = act ? r->ot[a] : (double)r->v[a] + 0.5;
        zi[a] = act ? r->inv[a] : INFINITY;
        far |= (r->sgn[a] > 0 ? 1u : 0u) << a; /* sgn is +1 on a zero axis */
        root[a] = ((far >> a & 1u ? nroot : 0.0) - zo[a]) * zi[a];
    }
    zo[3] = 0.0;
    zi[3] = 0.0;
    root[3] = INFINITY;
    const __m128d ZOxy = _mm_loadu_pd(zo), ZOzw = _mm_loadu_pd(zo + 2);
    const __m128d ZIxy = _mm_loadu_pd(zi), ZIzw = _mm_loadu_pd(zi + 2);

    const __m128i FARM = _mm_setr_epi32(-(int32_t)(far & 1u), -(int32_t)(far >> 1 & 1u),
                                        -(int32_t)(far >> 2 & 1u), 0);
    const __m128d WINF = _mm_setr_pd(-INFINITY, INFINITY);

    /* the nodes from the root down to the current cell's parent; exit times
     * are recomputed when the ray climbs back */
    trace_frame_v fr[OCT_MAX_LEVELS];
    __m128d TPxy = _mm_loadu_pd(root), TPzw = _mm_loadu_pd(root + 2);
    uint32_t M = groups[0][0].mask[0];
    uint64_t P = groups[0][0].base;
    fr[0].mask = M;
    fr[0].prefix = P;
    fr[0].ci = 0;
    unsigned d = 0, ci = 0;
    uint32_t size = UINT32_C(1) << levels;
    __m128i V = _mm_setzero_si128();
    double tc = r->t_start;
    __m128d Txy, Tzw, TC = _mm_set1_pd(tc);
    uint32_t steps = 0;
    int side = 0; /* --refine: see refine_voxel */

    if (anchor && anchor->depth) {
        /* the start lies in the anchor's cell: the descent from the root
         * would take its path */
        d = anchor->depth;
        memcpy(fr, anchor->node, (d + 1) * sizeof fr[0]);
        size = UINT32_C(1) << (levels - d);
        V = _mm_setr_epi32((int32_t)anchor->cell[0], (int32_t)anchor->cell[1],
                           (int32_t)anchor->cell[2], 0);
        trace_cell_exits(V, size, FARM, ZOxy, ZOzw, ZIxy, ZIzw, WINF, &TPxy, &TPzw);
        M = fr[d].mask;
        P = fr[d].prefix;
    }
    goto enter;
    for (;;) {
        uint32_t Mn;
        uint64_t Pn;
        if (M >> ci & 1u) {
            const uint64_t n = P + oct_popcount64(M & ((1u << ci) - 1u));
            if (d == levels) {
                /* a voxel */
                if (!refine) {
                    hit->hit = 1;
                    hit->voxel = n;
                    hit->t = r->t_base + tc;
                    break;
                }
                const __m128d m2 = _mm_min_pd(Txy, Tzw);
                const double te = _mm_cvtsd_f64(_mm_min_sd(m2, _mm_unpackhi_pd(m2, m2)));
                uint32_t v[4];
                _mm_storeu_si128((__m128i *)v, V);
                double tp;
                if (refine_voxel(tree, r, n, v, tc, te < t_end ? te : t_end, &side, &tp)) {
                    hit->hit = 1;
                    hit->voxel = n;
                    hit->t = r->t_base + tp;
                    break;
                }
                goto step;
            }
            const oct_children ch = oct_node_children(groups[d], n);
            Mn = ch.mask;
            Pn = ch.first;
        } else {
            if (d > split && d < levels) {
                /* step two, below K: walk the empty cell voxel by voxel */
                steps = trace_walk_empty(V, size, TC, Txy, Tzw, ZOxy, ZOzw, ZIxy, ZIzw, zo[2],
                                         zi[2], far, steps, max_steps);
                if (steps > max_steps)
                    goto out;
            }
            side = 0;
            goto step;
        }
        /* the cell becomes the parent: push it, then enter its child */
        fr[d].mask = Mn;
        fr[d].prefix = Pn;
        fr[d].ci = ci;
        M = Mn;
        P = Pn;
        TPxy = Txy;
        TPzw = Tzw;
    enter:;
        {
            const uint32_t half = size >> 1;
            const __m128i H = _mm_set1_epi32((int32_t)half);
            const __m128i MID = _mm_add_epi32(V, H);
            const __m128d TMxy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(MID), ZOxy), ZIxy);
            const __m128d TMzw =
                _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(MID, MID)), ZOzw), ZIzw);
            const __m128d Nxy = _mm_cmplt_pd(TC, TMxy), Nzw = _mm_cmplt_pd(TC, TMzw); /* near */
            Txy = _mm_blendv_pd(TPxy, TMxy, Nxy);
            Tzw = _mm_blendv_pd(TPzw, TMzw, Nzw);
            ci = ((unsigned)_mm_movemask_pd(Nxy) | (unsigned)_mm_movemask_pd(Nzw) << 2) ^ far;
            V = _mm_or_si128(V, _mm_and_si128(H, _mm_load_si128((const __m128i *)trace_lut[ci])));
            size = half;
            d++;
            continue;
        }
    step:;
        const __m128d m2 = _mm_min_pd(Txy, Tzw);
        const __m128d TEv = _mm_min_pd(m2, _mm_shuffle_pd(m2, m2, 1)); /* te in both lanes */
        const double te = _mm_cvtsd_f64(TEv);
        if (te >= t_end || ++steps > max_steps)
            break;
        __m128d Exy = _mm_cmpeq_pd(Txy, TEv), Ezw = _mm_cmpeq_pd(Tzw, TEv);
        unsigned smask = (unsigned)_mm_movemask_pd(Exy) | (unsigned)_mm_movemask_pd(Ezw) << 2;
        if (~(ci ^ far) & smask) {
            do {
                d--;
                if (d == 0)
                    goto out;
                size <<= 1;
                ci = fr[d].ci;
                /* One stepped axis a, on the far half: the parent's exit on a
                 * is the same plane (= te) and its other exits are later, so
                 * its stepped set is {a} again; only ties need comparing
                 * anew, with the parent's own exit times. */
                if (smask & (smask - 1u)) {
                    trace_cell_exits(V, size, FARM, ZOxy, ZOzw, ZIxy, ZIzw, WINF, &Txy, &Tzw);
                    Exy = _mm_cmpeq_pd(Txy, TEv);
                    Ezw = _mm_cmpeq_pd(Tzw, TEv);
                    smask = (unsigned)_mm_movemask_pd(Exy) | (unsigned)_mm_movemask_pd(Ezw) << 2;
                }
            } while (~(ci ^ far) & smask);
            V = _mm_andnot_si128(_mm_set1_epi32((int32_t)(size - 1u)), V);
            trace_cell_exits(V, size, FARM, ZOxy, ZOzw, ZIxy, ZIzw, WINF, &Txy, &Tzw);
            trace_cell_exits(V, 2u * size, FARM, ZOxy, ZOzw, ZIxy, ZIzw, WINF, &TPxy, &TPzw);
            M = fr[d - 1].mask;
            P = fr[d - 1].prefix;
        }
        ci ^= smask;
        Txy = _mm_blendv_pd(Txy, TPxy, Exy);
        Tzw = _mm_blendv_pd(Tzw, TPzw, Ezw);
        V = _mm_xor_si128(V, _mm_and_si128(_mm_set1_epi32((int32_t)size),
                                           _mm_load_si128((const __m128i *)trace_lut[smask])));
        TC = TEv;
        tc = te;
    }
out:;
    uint32_t v[4];
    _mm_storeu_si128((__m128i *)v, V);
    hit->xyz[0] = v[0];
    hit->xyz[1] = v[1];
    hit->xyz[2] = v[2];
    hit->steps = steps;
    return hit->hit;
}

int trace_ray_prepared(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       trace_hit *hit)
{
    return trace_ray_run(tree, opts, r, NULL, hit);
}

int trace_ray_anchored(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *a, trace_hit *hit)
{
    return trace_ray_run(tree, opts, r, a, hit);
}
#else
/* One node of the descent stack: the node's child mask and first-child index,
 * its cell's three exit-plane times, and its child index in its parent. */
typedef struct trace_frame {
    double tex[3];
    uint64_t prefix; /* index in the next depth of the node's first child */
    uint32_t mask;   /* child mask; 0 for an empty cell walked voxel by voxel */
    uint32_t ci;     /* child index (x + 2y + 4z) of this node in its parent */
} trace_frame;

/* Stack-based traversal. The state is the current cell (depth d, child ci of
 * its parent node, integer corner v, edge `size`), the time tc the ray entered
 * it and its three exit-plane times; the ancestors are on a stack. A step
 * leaves the cell through the axes whose exit time is the minimum te: when
 * every such axis is on the near half of the parent, the next cell is the
 * sibling across (one mask test); otherwise the parent is left too (pop) and
 * the test repeats one level up — the paper's common ancestor, found without
 * re-descending. Entering a non-empty cell chooses, per axis, the half the ray
 * is in at tc by comparing tc with the mid-plane time T(mid): that is the tie
 * rule of trace.h read bit by bit (T is monotone in k), so entry voxels are
 * never estimated from positions. Every time is T_a(k) = (k - o_a) * inv_a of
 * an integer plane, as before. Zero axes use o' = v + 1/2, inv' = +inf, so
 * that T(k) = -inf for k <= v and +inf above: the ray stays in voxel v. */
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
    const int refine = opts->refine;
    const uint32_t max_steps = trace_max_steps(levels);
    const double t_end = r->t_end;
    const oct_group *const *groups = tree->groups;

    /* plane-time parameters per axis; far: the child bit of the far half */
    double zo[3], zi[3];
    unsigned far = 0;
    for (int a = 0; a < 3; a++) {
        if (r->active >> a & 1) {
            zo[a] = r->ot[a];
            zi[a] = r->inv[a];
            far |= (r->sgn[a] > 0 ? 1u : 0u) << a;
        } else {
            zo[a] = (double)r->v[a] + 0.5;
            zi[a] = INFINITY;
            far |= 1u << a;
        }
    }
    const double zox = zo[0], zoy = zo[1], zoz = zo[2];
    const double zix = zi[0], ziy = zi[1], ziz = zi[2];
    const unsigned fx = far & 1u, fy = far >> 1 & 1u, fz = far >> 2 & 1u;
    const double nroot = (double)(UINT32_C(1) << levels);

    trace_frame fr[OCT_MAX_LEVELS];
    /* the current cell's parent node (fr[d - 1], kept in registers) */
    double tpx = ((fx ? nroot : 0.0) - zox) * zix;
    double tpy = ((fy ? nroot : 0.0) - zoy) * ziy;
    double tpz = ((fz ? nroot : 0.0) - zoz) * ziz;
    uint32_t M = groups[0][0].mask[0];
    uint64_t P = groups[0][0].base;
    fr[0].tex[0] = tpx;
    fr[0].tex[1] = tpy;
    fr[0].tex[2] = tpz;
    fr[0].mask = M;
    fr[0].prefix = P;
    fr[0].ci = 0;
    /* the current cell */
    unsigned d = 0, ci = 0;
    uint32_t vx = 0, vy = 0, vz = 0, size = UINT32_C(1) << levels;
    double tx, ty, tz, tc = r->t_start;
    uint32_t steps = 0;
    int side = 0; /* --refine: see refine_voxel */

    goto enter;
    for (;;) {
        const unsigned occ = M >> ci & 1u;
        if (d < levels && (occ || d > split)) {
            /* the cell becomes the parent: push it, then enter its child */
            uint32_t Mn = 0;
            uint64_t Pn = 0;
            if (occ) {
                const uint64_t n = P + oct_popcount64(M & ((1u << ci) - 1u));
                const oct_children ch = oct_node_children(groups[d], n);
            Mn = ch.mask;
            Pn = ch.first;
            }
            fr[d].tex[0] = tx;
            fr[d].tex[1] = ty;
            fr[d].tex[2] = tz;
            fr[d].mask = Mn;
            fr[d].prefix = Pn;
            fr[d].ci = ci;
            M = Mn;
            P = Pn;
            tpx = tx;
            tpy = ty;
            tpz = tz;
        enter:;
            /* the child the ray is in at tc: per axis, the far half when the
             * mid plane is crossed at or before tc */
            const uint32_t half = size >> 1;
            const double tmx = ((double)(vx + half) - zox) * zix;
            const double tmy = ((double)(vy + half) - zoy) * ziy;
            const double tmz = ((double)(vz + half) - zoz) * ziz;
            const unsigned nx = tmx > tc, ny = tmy > tc, nz = tmz > tc; /* near halves */
            tx = nx ? tmx : tpx;
            ty = ny ? tmy : tpy;
            tz = nz ? tmz : tpz;
            const unsigned bx = nx ^ fx, by = ny ^ fy, bz = nz ^ fz;
            vx |= (0u - bx) & half;
            vy |= (0u - by) & half;
            vz |= (0u - bz) & half;
            ci = bx | by << 1 | bz << 2;
            size = half;
            d++;
            continue;
        }
        if (occ) {
            /* a voxel */
            const uint64_t vidx = P + oct_popcount64(M & ((1u << ci) - 1u));
            if (!refine) {
                hit->hit = 1;
                hit->voxel = vidx;
                hit->t = r->t_base + tc;
                break;
            }
            double te = tx < ty ? tx : ty;
            te = tz < te ? tz : te;
            const uint32_t v[3] = {vx, vy, vz};
            double tp;
            if (refine_voxel(tree, r, vidx, v, tc, te < t_end ? te : t_end, &side, &tp)) {
                hit->hit = 1;
                hit->voxel = vidx;
                hit->t = r->t_base + tp;
                break;
            }
        } else {
            side = 0;
        }

        /* leave the cell through its nearest exit planes */
        double te = tx < ty ? tx : ty;
        te = tz < te ? tz : te;
        if (te >= t_end || ++steps > max_steps)
            break;
        unsigned smask = (unsigned)(tx == te) | (unsigned)(ty == te) << 1 |
                         (unsigned)(tz == te) << 2;
        /* an axis stepped on the far half leaves the parent: go up */
        while (~(ci ^ far) & smask) {
            d--;
            if (d == 0)
                goto out; /* the root is left (te >= t_end caught it first) */
            size <<= 1;
            vx &= ~(size - 1u);
            vy &= ~(size - 1u);
            vz &= ~(size - 1u);
            tx = tpx;
            ty = tpy;
            tz = tpz;
            ci = fr[d].ci;
            const trace_frame *pf = &fr[d - 1];
            M = pf->mask;
            P = pf->prefix;
            tpx = pf->tex[0];
            tpy = pf->tex[1];
            tpz = pf->tex[2];
            smask = (unsigned)(tx == te) | (unsigned)(ty == te) << 1 | (unsigned)(tz == te) << 2;
        }
        /* the sibling across the stepped axes: their exits are the parent's */
        ci ^= smask;
        tx = smask & 1u ? tpx : tx;
        ty = smask & 2u ? tpy : ty;
        tz = smask & 4u ? tpz : tz;
        vx ^= (0u - (smask & 1u)) & size;
        vy ^= (0u - (smask >> 1 & 1u)) & size;
        vz ^= (0u - (smask >> 2 & 1u)) & size;
        tc = te;
    }
out:
    hit->xyz[0] = vx;
    hit->xyz[1] = vy;
    hit->xyz[2] = vz;
    hit->steps = steps;
    return hit->hit;
}

/* The scalar build descends from the root for every ray. */
int trace_ray_anchored(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
                       const trace_anchor *a, trace_hit *hit)
{
    (void)a;
    return trace_ray_prepared(tree, opts, r, hit);
}
#endif

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
