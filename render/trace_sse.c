/* trace_sse: the traversal (trace_impl.h) with the three axes in SSE
 * registers, built when the target has SSE4.1 (the default x86-64-v2). */
#include "render/exact_scene.h"
#include "render/trace_impl.h"

#if TRACE_HAVE_SSE
#include <math.h>
#include <string.h>

#include <smmintrin.h>

/* (x, y) in one register, (z, w) in the other, w a dummy lane (o = inv = 0)
 * whose exit time stays +inf: its mid-plane time is 0, never > tc, so it
 * never picks a near half, and it never equals a step time te < t_end, so its
 * mask bits are 0. The arithmetic per lane is trace_traverse_portable's,
 * operation for operation. The helpers are always inlined: the loop's state
 * stays in registers. */
#define SSE_INLINE static inline __attribute__((always_inline))

/* lane masks for a 3-bit axis set */
static const int32_t trace_lut[8][4] __attribute__((aligned(16))) = {
    {0, 0, 0, 0},   {-1, 0, 0, 0},   {0, -1, 0, 0},   {-1, -1, 0, 0},
    {0, 0, -1, 0},  {-1, 0, -1, 0},  {0, -1, -1, 0},  {-1, -1, -1, 0},
};

/* A ray's plane-time parameters per lane: T(k) = (k - ZO) * ZI. */
typedef struct sse_axes {
    __m128d ZOxy, ZOzw, ZIxy, ZIzw;
    __m128d WINF;  /* (-inf, +inf): raises the dummy lane's exit to +inf */
    __m128i FARM;  /* all bits set in the lanes of the far axes */
    double zoz, ziz;
    unsigned far;  /* child bit of the far half, per axis */
} sse_axes;

/* The axes of ray r in a tree of `levels` levels, and the root's exit
 * times (TRxy NULL: not wanted). A zero axis uses o = v + 1/2, inv = +inf. */
SSE_INLINE void sse_axes_init(const trace_ray *r, unsigned levels, sse_axes *ax, __m128d *TRxy,
                              __m128d *TRzw)
{
    if (!TRxy && r->active == 7u) {
        /* no zero axis (nearly every secondary ray): the loop's values,
           loaded as they are */
        const unsigned f = (r->sgn[0] > 0 ? 1u : 0u) | (r->sgn[1] > 0 ? 2u : 0u) |
                           (r->sgn[2] > 0 ? 4u : 0u);
        ax->ZOxy = _mm_loadu_pd(r->ot);
        ax->ZOzw = _mm_set_sd(r->ot[2]);
        ax->ZIxy = _mm_loadu_pd(r->inv);
        ax->ZIzw = _mm_set_sd(r->inv[2]);
        ax->FARM = _mm_setr_epi32(-(int32_t)(f & 1u), -(int32_t)(f >> 1 & 1u),
                                  -(int32_t)(f >> 2 & 1u), 0);
        ax->WINF = _mm_setr_pd(-INFINITY, INFINITY);
        ax->zoz = r->ot[2];
        ax->ziz = r->inv[2];
        ax->far = f;
        return;
    }
    double zo[4], zi[4], root[4];
    unsigned far = 0;
    const double nroot = (double)(UINT32_C(1) << levels);
#pragma GCC unroll 3
    for (int a = 0; a < 3; a++) {
        const int act = r->active >> a & 1;
        zo[a] = act ? r->ot[a] : (double)r->v[a] + 0.5;
        zi[a] = act ? r->inv[a] : INFINITY;
        far |= (r->sgn[a] > 0 ? 1u : 0u) << a; /* sgn is +1 on a zero axis */
        if (TRxy)
            root[a] = ((far >> a & 1u ? nroot : 0.0) - zo[a]) * zi[a];
    }
    zo[3] = 0.0;
    zi[3] = 0.0;
    root[3] = INFINITY;
    ax->ZOxy = _mm_loadu_pd(zo);
    ax->ZOzw = _mm_loadu_pd(zo + 2);
    ax->ZIxy = _mm_loadu_pd(zi);
    ax->ZIzw = _mm_loadu_pd(zi + 2);
    ax->FARM = _mm_setr_epi32(-(int32_t)(far & 1u), -(int32_t)(far >> 1 & 1u),
                              -(int32_t)(far >> 2 & 1u), 0);
    ax->WINF = _mm_setr_pd(-INFINITY, INFINITY);
    ax->zoz = zo[2];
    ax->ziz = zi[2];
    ax->far = far;
    if (TRxy) {
        *TRxy = _mm_loadu_pd(root);
        *TRzw = _mm_loadu_pd(root + 2);
    }
}

/* The exit times of the cell with corner V (bits below `edge` ignored) and
 * edge `edge`, T(corner + far * edge) per axis: the same T of the same
 * planes as a descent blends from mid-plane times, bit for bit. The dummy lane
 * w comes out 0 and is raised to +inf by WINF. */
SSE_INLINE void trace_cell_exits(__m128i V, uint32_t edge, const sse_axes *ax, __m128d *txy,
                                 __m128d *tzw)
{
    const __m128i C = _mm_andnot_si128(_mm_set1_epi32((int32_t)(edge - 1u)), V);
    const __m128i K = _mm_add_epi32(C, _mm_and_si128(_mm_set1_epi32((int32_t)edge), ax->FARM));
    *txy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(K), ax->ZOxy), ax->ZIxy);
    *tzw = _mm_max_pd(
        _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(K, K)), ax->ZOzw), ax->ZIzw),
        ax->WINF);
}


/* 64-bit lane masks (as blendv reads them) of a 3-bit axis set: (x, y), (z, w) */
static const double trace_near64[8][2][2] __attribute__((aligned(16))) = {
#define NM(b) ((b) ? -NAN : 0.0)
    {{NM(0), NM(0)}, {NM(0), 0.0}}, {{NM(1), NM(0)}, {NM(0), 0.0}},
    {{NM(0), NM(1)}, {NM(0), 0.0}}, {{NM(1), NM(1)}, {NM(0), 0.0}},
    {{NM(0), NM(0)}, {NM(1), 0.0}}, {{NM(1), NM(0)}, {NM(1), 0.0}},
    {{NM(0), NM(1)}, {NM(1), 0.0}}, {{NM(1), NM(1)}, {NM(1), 0.0}},
#undef NM
};

/* enter (the paper's vertical traverse, Fig. 2, one level): the child of
 * the cell (corner V, edge size, exit times TP) the ray is in at TC: per axis
 * the far half when the mid plane is crossed at or before TC. The child's
 * exit times T are the mid plane's (near) or the cell's (far). Returns the
 * child's index. */
SSE_INLINE unsigned enter(const sse_axes *ax, __m128d TC, __m128d TPxy, __m128d TPzw, __m128i *V,
                          uint32_t *size, __m128d *Txy, __m128d *Tzw)
{
    const uint32_t half = *size >> 1;
    const __m128i H = _mm_set1_epi32((int32_t)half);
    const __m128i MID = _mm_add_epi32(*V, H);
    const __m128d TMxy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(MID), ax->ZOxy), ax->ZIxy);
    const __m128d TMzw =
        _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(MID, MID)), ax->ZOzw), ax->ZIzw);
    const __m128d Nxy = _mm_cmplt_pd(TC, TMxy), Nzw = _mm_cmplt_pd(TC, TMzw); /* near */
    *Txy = _mm_blendv_pd(TPxy, TMxy, Nxy);
    *Tzw = _mm_blendv_pd(TPzw, TMzw, Nzw);
    const unsigned ci =
        ((unsigned)_mm_movemask_pd(Nxy) | (unsigned)_mm_movemask_pd(Nzw) << 2) ^ ax->far;
    *V = _mm_or_si128(*V, _mm_and_si128(H, _mm_load_si128((const __m128i *)trace_lut[ci])));
    *size = half;
    return ci;
}

/* The voxel walk (step two, below K): walks the empty cell (corner V, edge
 * size > 1, entered at tc with exit times Txy, Tzw) voxel by voxel. Its entry
 * voxel is found bit by bit as on entry into any cell; then a unit DDA whose
 * exit times are T of the voxel's far faces runs until the cell's own exit
 * time, where the caller leaves the cell as above K: the same voxels, times
 * and step count as walking the cell as a subtree with an all-empty mask.
 * Returns the step count (steps plus the voxel steps taken), max_steps + 1
 * when the bound is passed. Out of line: the default K = L never calls it. */
static __attribute__((noinline)) uint32_t
voxel_walk(const sse_axes *ax, __m128i V, uint32_t size, __m128d TC, __m128d Wxy, __m128d Wzw,
           uint32_t steps, uint32_t max_steps)
{
    const unsigned far = ax->far;
    const __m128d ZOxy = ax->ZOxy, ZIxy = ax->ZIxy;
    const __m128d c2 = _mm_min_pd(Wxy, Wzw);
    const double te_cell = _mm_cvtsd_f64(_mm_min_pd(c2, _mm_shuffle_pd(c2, c2, 1)));
    while (size > 1)
        enter(ax, TC, Wxy, Wzw, &V, &size, &Wxy, &Wzw);
    /* far-face offsets and unit moves per lane; the dummy lane w uses
     * o = -1/2, inv = +inf so that its exit time is +inf */
    const __m128i FARV = _mm_setr_epi32((int32_t)(far & 1u), (int32_t)(far >> 1 & 1u),
                                        (int32_t)(far >> 2 & 1u), 0);
    const __m128i DIRV = _mm_sub_epi32(_mm_add_epi32(FARV, FARV), _mm_set1_epi32(1));
    const __m128d WZOzw = _mm_setr_pd(ax->zoz, -0.5), WZIzw = _mm_setr_pd(ax->ziz, INFINITY);
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

/* A voxel (node index n) entered at tc, with exit times Txy, Tzw: the hit,
 * with --refine the plane test of the current run (*side), with --exact the
 * root test. Returns 1 and fills hit on a hit. */
SSE_INLINE int voxel_hit(const oct_tree *tree, const trace_ray *r, const trace_opts *opts,
                         uint64_t n, double tc, __m128d Txy, __m128d Tzw, __m128i V, int *side,
                         trace_hit *hit)
{
    double t = tc;
    if (opts->refine || opts->exact) {
        const __m128d m2 = _mm_min_pd(Txy, Tzw);
        const double te = _mm_cvtsd_f64(_mm_min_sd(m2, _mm_unpackhi_pd(m2, m2)));
        const double t_out = te < r->t_end ? te : r->t_end;
        uint32_t v[4];
        _mm_storeu_si128((__m128i *)v, V);
        if (opts->exact ? !exact_voxel(opts->exact, r, v, tc, t_out, &t, hit)
                        : !trace_refine_voxel(tree, r, n, v, tc, t_out, side, &t))
            return 0;
    }
    hit->hit = 1;
    hit->voxel = n;
    hit->t = r->t_base + t;
    return 1;
}

/* climb (the paper's ascent to the common ancestor, Fig. 3): the step at
 * TEv through the axes *smask (E: their lanes) leaves the parent too, one of
 * them being on its far half. Pops (depth d, child index ci, edge size)
 * until the common ancestor, the node in which the step stays, and makes its
 * child on the way up the current cell: corner V, exit times T, its parent's
 * exit times TP and node (M, P). Returns 0 when the root is left. */
SSE_INLINE int climb(const trace_frame *fr, const sse_axes *ax, __m128d TEv, unsigned *d,
                     unsigned *ci, uint32_t *size, __m128i *V, unsigned *smask, __m128d *Exy,
                     __m128d *Ezw, __m128d *Txy, __m128d *Tzw, __m128d *TPxy, __m128d *TPzw,
                     uint32_t *M, uint64_t *P)
{
    do {
        (*d)--;
        if (*d == 0)
            return 0;
        *size <<= 1;
        *ci = fr[*d].ci;
        /* One stepped axis a, on the far half: the parent's exit on a
         * is the same plane (= te) and its other exits are later, so
         * its stepped set is {a} again; only ties need comparing
         * anew, with the parent's own exit times. */
        if (*smask & (*smask - 1u)) {
            trace_cell_exits(*V, *size, ax, Txy, Tzw);
            *Exy = _mm_cmpeq_pd(*Txy, TEv);
            *Ezw = _mm_cmpeq_pd(*Tzw, TEv);
            *smask = (unsigned)_mm_movemask_pd(*Exy) | (unsigned)_mm_movemask_pd(*Ezw) << 2;
        }
    } while (~(*ci ^ ax->far) & *smask);
    *V = _mm_andnot_si128(_mm_set1_epi32((int32_t)(*size - 1u)), *V);
    trace_cell_exits(*V, *size, ax, Txy, Tzw);
    trace_cell_exits(*V, 2u * *size, ax, TPxy, TPzw);
    *M = fr[*d - 1].mask;
    *P = fr[*d - 1].prefix;
    return 1;
}

int trace_traverse_sse(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
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
    const oct_group *const *groups = tree->groups;

    sse_axes ax;
    __m128d TPxy, TPzw;
    sse_axes_init(r, levels, &ax, &TPxy, &TPzw);
    const unsigned far = ax.far;

    /* the nodes from the root down to the current cell's parent; exit times
     * are recomputed when the ray climbs back */
    trace_frame fr[OCT_MAX_LEVELS];
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
    int side = 0; /* --refine: see trace_refine_voxel */

    if (anchor && anchor->depth) {
        /* the start lies in the anchor's cell: the descent from the root
         * would take its path */
        d = anchor->depth;
        /* a frame a register move (the layouts are one: trace_impl.h);
           shorter than a call to memcpy for the few frames of an anchor */
        for (unsigned k = 0; k <= d; k++)
            _mm_storeu_si128((__m128i *)(void *)&fr[k],
                             _mm_loadu_si128((const __m128i *)(const void *)&anchor->node[k]));
        size = UINT32_C(1) << (levels - d);
        V = _mm_setr_epi32((int32_t)anchor->cell[0], (int32_t)anchor->cell[1],
                           (int32_t)anchor->cell[2], 0);
        trace_cell_exits(V, size, &ax, &TPxy, &TPzw);
        M = fr[d].mask;
        P = fr[d].prefix;
    }
    goto enter; /* the descent starts in the root's (or the anchor's) cell */
    for (;;) {
        uint32_t Mn;
        uint64_t Pn;
        if (M >> ci & 1u) {
            const uint64_t n = P + oct_popcount64(M & ((1u << ci) - 1u));
            if (d == levels) {
                if (voxel_hit(tree, r, opts, n, tc, Txy, Tzw, V, &side, hit))
                    break;
                goto step;
            }
            const oct_children ch = oct_node_children(groups[d], n);
            Mn = ch.mask;
            Pn = ch.first;
        } else {
            if (d > split && d < levels) {
                /* step two, below K: walk the empty cell voxel by voxel */
                steps = voxel_walk(&ax, V, size, TC, Txy, Tzw, steps, max_steps);
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
        ci = enter(&ax, TC, TPxy, TPzw, &V, &size, &Txy, &Tzw);
        d++;
        continue;
    step:;
        /* leave the cell through its nearest exit planes (all axes whose exit
         * time is te) */
        const __m128d m2 = _mm_min_pd(Txy, Tzw);
        const __m128d TEv = _mm_min_pd(m2, _mm_shuffle_pd(m2, m2, 1)); /* te in both lanes */
        const double te = _mm_cvtsd_f64(TEv);
        if (te >= t_end || ++steps > max_steps)
            break;
        __m128d Exy = _mm_cmpeq_pd(Txy, TEv), Ezw = _mm_cmpeq_pd(Tzw, TEv);
        unsigned smask = (unsigned)_mm_movemask_pd(Exy) | (unsigned)_mm_movemask_pd(Ezw) << 2;
        if (~(ci ^ far) & smask) {
            /* a stepped axis on the far half leaves the parent too */
            if (!climb(fr, &ax, TEv, &d, &ci, &size, &V, &smask, &Exy, &Ezw, &Txy, &Tzw, &TPxy,
                       &TPzw, &M, &P))
                goto out;
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
/* The any-hit walk (trace_impl.h): trace_traverse_sse's steps, enter and
 * climb, with each occupied cell tested before it is entered: the children
 * the ray visits in it (trace_path_children, from enter's mid-plane times)
 * against its child mask. None occupied: the cell is left as if empty; a
 * cell of voxels with one: the ray meets it. Plain rule only, every empty
 * cell skipped whole (the split does not change the answer). */
int trace_occluded_sse(const oct_tree *tree, const trace_ray *r, const trace_anchor *anchor,
                       uint32_t *steps_out)
{
    const unsigned levels = tree->levels;
    int hit = 0;
    *steps_out = 0;
    if (tree->node_count[0] == 0)
        return 0;
    const uint32_t max_steps = trace_max_steps(levels);
    uint32_t left = max_steps; /* steps left: counted down */
    const double t_end = r->t_end;
    const __m128d TEND = _mm_set1_pd(t_end);
    const oct_group *const *groups = tree->groups;

    sse_axes ax;
    __m128d TPxy, TPzw;
    sse_axes_init(r, levels, &ax, NULL, NULL);
    const unsigned far = ax.far;

    trace_frame fr[OCT_MAX_LEVELS];
    uint32_t M = groups[0][0].mask[0], Mn;
    uint64_t P = groups[0][0].base, Pn;
    fr[0].mask = M;
    fr[0].prefix = P;
    fr[0].ci = 0;
    unsigned d = 0, ci = 0;
    uint32_t size = UINT32_C(1) << levels;
    __m128i V = _mm_setzero_si128();
    __m128d Txy, Tzw, TC = _mm_set1_pd(r->t_start);

    if (anchor && anchor->depth) {
        /* the anchor's cell is the current one: tested like any other */
        d = anchor->depth;
        memcpy(fr, anchor->node, (d + 1u) * sizeof fr[0]); /* frames 0..d, one layout */
        size = UINT32_C(1) << (levels - d);
        V = _mm_setr_epi32((int32_t)anchor->cell[0], (int32_t)anchor->cell[1],
                           (int32_t)anchor->cell[2], 0);
        trace_cell_exits(V, size, &ax, &Txy, &Tzw);
        trace_cell_exits(V, 2u * size, &ax, &TPxy, &TPzw);
        ci = fr[d].ci;
        M = fr[d - 1].mask;
        P = fr[d - 1].prefix;
        Mn = fr[d].mask;
        Pn = fr[d].prefix;
        goto look;
    }
    /* from the root, tested like any other cell (its exits: sse_axes_init's) */
    trace_cell_exits(V, size, &ax, &Txy, &Tzw);
    Mn = M;
    Pn = P;
    goto look;
    for (;;) {
        if (M >> ci & 1u) {
            if (d == levels) {
                hit = 1; /* entered after a tie above */
                break;
            }
            const uint64_t n = P + oct_popcount64(M & ((1u << ci) - 1u));
            const oct_children ch = oct_node_children(groups[d], n);
            Mn = ch.mask;
            Pn = ch.first;
        look:;
            /* enter's mid-plane times, and the children they make the ray visit */
            const uint32_t half = size >> 1;
            const __m128i H = _mm_set1_epi32((int32_t)half);
            const __m128i MID = _mm_add_epi32(V, H);
            const __m128d TMxy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(MID), ax.ZOxy), ax.ZIxy);
            const __m128d TMzw = _mm_mul_pd(
                _mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(MID, MID)), ax.ZOzw), ax.ZIzw);
            const __m128d m2 = _mm_min_pd(Txy, Tzw);
            const __m128d LIM = _mm_min_pd(_mm_min_pd(m2, _mm_shuffle_pd(m2, m2, 1)), TEND);
            /* one 32-bit lane per axis (w: 0) for each comparison, read by one movemask */
            const unsigned near = (unsigned)_mm_movemask_ps(
                _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(TC, TMxy)),
                               _mm_castpd_ps(_mm_cmplt_pd(TC, TMzw)), _MM_SHUFFLE(2, 0, 2, 0)));
            const unsigned before = (unsigned)_mm_movemask_ps(
                _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(TMxy, LIM)),
                               _mm_castpd_ps(_mm_cmplt_pd(TMzw, LIM)), _MM_SHUFFLE(2, 0, 2, 0)));
            const unsigned order = (unsigned)_mm_movemask_ps(_mm_shuffle_ps(
                                       _mm_castpd_ps(_mm_cmplt_pd(TMxy, _mm_shuffle_pd(TMxy, TMzw, 1))),
                                       _mm_castpd_ps(_mm_cmplt_pd(TMxy, TMzw)), _MM_SHUFFLE(0, 0, 2, 0))) &
                                   7u;
            const unsigned c0 = near ^ far;
            const unsigned crossed = near & before;
            if (!(trace_path_children[c0 | crossed << 3 | order << 6] & Mn)) {
                if (!d)
                    break; /* the root */
                goto step; /* nothing on the way: as an empty cell */
            }
            if (d + 1 == levels) {
                /* the set is exact unless two crossed mid planes tie */
                const unsigned eq =
                    (unsigned)_mm_movemask_pd(_mm_cmpeq_pd(TMxy, _mm_shuffle_pd(TMxy, TMzw, 1))) |
                    ((unsigned)_mm_movemask_pd(_mm_cmpeq_sd(TMxy, TMzw)) & 1u) << 2;
                if (!(eq & TRACE_PAIRS(crossed))) {
                    hit = 1; /* a voxel on the way */
                    break;
                }
            }
            /* push the cell and enter its child c0 (enter's blend) */
            fr[d].mask = Mn;
            fr[d].prefix = Pn;
            fr[d].ci = ci;
            M = Mn;
            P = Pn;
            TPxy = Txy;
            TPzw = Tzw;
            Txy = _mm_blendv_pd(TPxy, TMxy, _mm_load_pd(trace_near64[near][0]));
            Tzw = _mm_blendv_pd(TPzw, TMzw, _mm_load_pd(trace_near64[near][1]));
            ci = c0;
            V = _mm_or_si128(V, _mm_and_si128(H, _mm_load_si128((const __m128i *)trace_lut[ci])));
            size = half;
            d++;
            continue;
        }
    step:;
        const __m128d s2 = _mm_min_pd(Txy, Tzw);
        const __m128d TEv = _mm_min_pd(s2, _mm_shuffle_pd(s2, s2, 1));
        if (_mm_cvtsd_f64(TEv) >= t_end || left-- == 0)
            break;
        __m128d Exy = _mm_cmpeq_pd(Txy, TEv), Ezw = _mm_cmpeq_pd(Tzw, TEv);
        unsigned smask = (unsigned)_mm_movemask_pd(Exy) | (unsigned)_mm_movemask_pd(Ezw) << 2;
        if ((~(ci ^ far) & smask) && !climb(fr, &ax, TEv, &d, &ci, &size, &V, &smask, &Exy, &Ezw,
                                             &Txy, &Tzw, &TPxy, &TPzw, &M, &P))
            break;
        ci ^= smask;
        Txy = _mm_blendv_pd(Txy, TPxy, Exy);
        Tzw = _mm_blendv_pd(Tzw, TPzw, Ezw);
        V = _mm_xor_si128(V, _mm_and_si128(_mm_set1_epi32((int32_t)size),
                                           _mm_load_si128((const __m128i *)trace_lut[smask])));
        TC = TEv;
    }
    *steps_out = max_steps - left; /* max_steps + 1 when the bound was passed */
    return hit;
}
#endif
