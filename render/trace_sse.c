/* trace_sse: the traversal (trace_impl.h) with the three axes in SSE
 * registers, built when the target has SSE4.1 (the default x86-64-v2). */
#include "render/exact_scene.h"
#include "render/trace_impl.h"

#if TRACE_HAVE_SSE
#include <math.h>
#include <string.h>

#include "render/trace_sse_walk.h"

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
    const double te_cell = _mm_cvtsd_f64(sse_min3(Wxy, Wzw));
    while (size > 1)
        enter(ax, TC, Wxy, Wzw, &V, &size, &Wxy, &Wzw);
    /* far-face offsets and unit moves per lane; the dummy lane w uses
     * o = -1/2, inv = +inf so that its exit time is +inf */
    const __m128i FARV = _mm_setr_epi32((int32_t)(far & 1u), (int32_t)(far >> 1 & 1u),
                                        (int32_t)(far >> 2 & 1u), 0);
    const __m128i DIRV = _mm_sub_epi32(_mm_add_epi32(FARV, FARV), _mm_set1_epi32(1));
    const __m128d WZOzw = _mm_setr_pd(ax->zoz, -0.5), WZIzw = _mm_setr_pd(ax->ziz, INFINITY);
    for (;;) {
        const __m128d WEv = sse_min3(Wxy, Wzw);
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
        hit->voxel = n; /* (exact_voxel reads it) */
        if (opts->exact ? !exact_voxel(opts->exact, r, v, tc, t_out, &t, hit)
                        : !trace_refine_voxel(tree, r, n, v, tc, t_out, side, &t))
            return 0;
    }
    hit->hit = 1;
    hit->voxel = n;
    hit->t = r->t_base + t;
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
            if (d + 1 == levels && tree->voxels)
                __builtin_prefetch(&tree->voxels[Pn]); /* the records a hit reads: mostly a miss */
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
        const __m128d TEv = sse_min3(Txy, Tzw); /* te in both lanes */
        const double te = _mm_cvtsd_f64(TEv);
        if (te >= t_end || ++steps > max_steps)
            break;
        __m128d Exy = _mm_cmpeq_pd(Txy, TEv), Ezw = _mm_cmpeq_pd(Tzw, TEv);
        unsigned smask = (unsigned)_mm_movemask_pd(Exy) | (unsigned)_mm_movemask_pd(Ezw) << 2;
        if (~(ci ^ far) & smask) {
            /* a stepped axis on the far half leaves the parent too */
            if (!climb(fr, &ax, 0, TEv, &d, &ci, &size, &V, &smask, &Exy, &Ezw, &Txy, &Tzw, &TPxy,
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
#endif
