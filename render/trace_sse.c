/* trace_sse: the traversal (trace_impl.h) with the three axes in SSE
 * registers, built when the target has SSE4.1 (the default x86-64-v2). */
#include "render/trace_impl.h"

#if TRACE_HAVE_SSE
#include <math.h>
#include <string.h>

#include <smmintrin.h>

/* (x, y) in one register, (z, w) in the other, w a dummy lane (o = inv = 0)
 * whose exit time stays +inf: its mid-plane time is 0, never > tc, so it
 * never picks a near half, and it never equals a step time te < t_end, so its
 * mask bits are 0. The arithmetic per lane is trace_traverse_portable's,
 * operation for operation. */

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

/* The voxel walk (step two, below K): walks the empty cell (corner V, edge
 * size > 1, entered at tc with exit times Txy, Tzw) voxel by voxel. Its entry
 * voxel is found bit by bit as on entry into any cell; then a unit DDA whose
 * exit times are T of the voxel's far faces runs until the cell's own exit
 * time, where the caller leaves the cell as above K: the same voxels, times
 * and step count as walking the cell as a subtree with an all-empty mask.
 * Returns the step count (steps plus the voxel steps taken), max_steps + 1
 * when the bound is passed. Out of line: the default K = L never calls it. */
static __attribute__((noinline)) uint32_t
voxel_walk(__m128i V, uint32_t size, __m128d TC, __m128d Wxy, __m128d Wzw, __m128d ZOxy,
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

int trace_traverse_sse(const oct_tree *tree, const trace_opts *opts, const trace_ray *r,
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
    trace_frame fr[OCT_MAX_LEVELS];
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
    int side = 0; /* --refine: see trace_refine_voxel */

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
                if (trace_refine_voxel(tree, r, n, v, tc, te < t_end ? te : t_end, &side, &tp)) {
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
                steps = voxel_walk(V, size, TC, Txy, Tzw, ZOxy, ZOzw, ZIxy, ZIzw, zo[2], zi[2], far,
                                   steps, max_steps);
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
        /* enter (the paper's vertical traverse, Fig. 2): the child the ray
         * is in at tc, per axis the far half when the mid plane is crossed at
         * or before tc */
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
            /* climb (Fig. 3): a stepped axis on the far half leaves the
             * parent too; pop until the common ancestor, whose child across
             * the stepped axes is the next cell */
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
#endif
