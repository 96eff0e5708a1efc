/* trace_anyhit_sse: the any-hit walks of secondary rays with the three
 * axes in SSE registers (trace_impl.h): the plain walk, and the walk of AO
 * rays through the clearance grid (render/ao_grid.h). Built where the SSE
 * traversal is. */
#include "render/ao_grid.h"
#include "render/trace_impl.h"

#if TRACE_HAVE_SSE
#include <string.h>

#include "render/trace_sse_walk.h"

/* The any-hit walk's loop (trace_occluded_sse's), entered with a look at
 * the current cell: depth d, child index ci, corner V, edge size, exit
 * times T, its parent's TP and node (M, P), its own node (Mn, Pn), entered
 * at TC; fr holds the frames above it from depth `floor` + 1 on. Returns
 * WALK_HIT at an occupied voxel on the way; WALK_LEFT when it leaves the
 * cell at depth `floor` > 0, at *exit_t (in both lanes) through the axes
 * *exit_mask (that step counted); WALK_END when the ray passes t_end, uses
 * up *left steps (then *left wraps to UINT32_MAX) or leaves the root. */
enum { WALK_END, WALK_HIT, WALK_LEFT };
SSE_INLINE int occluded_walk(const oct_group *const *groups, const sse_axes *ax, unsigned levels,
                             unsigned floor, trace_frame *fr, unsigned d, unsigned ci,
                             uint32_t size, __m128i V, __m128d Txy, __m128d Tzw, __m128d TPxy,
                             __m128d TPzw, __m128d TC, uint32_t M, uint64_t P, uint32_t Mn,
                             uint64_t Pn, double t_end, uint32_t *left_io, __m128d *exit_t,
                             unsigned *exit_mask)
{
    const __m128d TEND = _mm_set1_pd(t_end);
    const unsigned far = ax->far;
    uint32_t left = *left_io;
    int res = WALK_END;
    goto look;
    for (;;) {
        if (M >> ci & 1u) {
            if (d == levels) {
                res = WALK_HIT; /* entered after a tie above */
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
            const __m128d TMxy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(MID), ax->ZOxy), ax->ZIxy);
            const __m128d TMzw = _mm_mul_pd(
                _mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(MID, MID)), ax->ZOzw), ax->ZIzw);
            const __m128d LIM = _mm_min_pd(sse_min3(Txy, Tzw), TEND);
            /* one 32-bit lane per axis (w: 0) for each comparison, read by one movemask */
            const unsigned near = (unsigned)_mm_movemask_ps(
                _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(TC, TMxy)),
                               _mm_castpd_ps(_mm_cmplt_pd(TC, TMzw)), _MM_SHUFFLE(2, 0, 2, 0)));
            const unsigned before = (unsigned)_mm_movemask_ps(
                _mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(TMxy, LIM)),
                               _mm_castpd_ps(_mm_cmplt_pd(TMzw, LIM)), _MM_SHUFFLE(2, 0, 2, 0)));
            const __m128d YZ = _mm_shuffle_pd(TMxy, TMzw, 1); /* (y, z) */
            const unsigned order =
                (unsigned)_mm_movemask_ps(_mm_shuffle_ps(_mm_castpd_ps(_mm_cmplt_pd(TMxy, YZ)),
                                                         _mm_castpd_ps(_mm_cmplt_pd(TMxy, TMzw)),
                                                         _MM_SHUFFLE(0, 0, 2, 0))) &
                7u;
            const unsigned c0 = near ^ far;
            const unsigned crossed = near & before;
            if (!(trace_path_children[c0 | crossed << 3 | order << 6] & Mn)) {
                if (d != floor)
                    goto step; /* nothing on the way: as an empty cell */
                if (!floor)
                    break; /* the root */
                goto leave; /* the walk's own cell */
            }
            if (d + 1 == levels) {
                /* the set is exact unless two crossed mid planes tie */
                const unsigned eq =
                    (unsigned)_mm_movemask_pd(_mm_cmpeq_pd(TMxy, YZ)) |
                    ((unsigned)_mm_movemask_pd(_mm_cmpeq_sd(TMxy, TMzw)) & 1u) << 2;
                if (!(eq & TRACE_PAIRS(crossed))) {
                    res = WALK_HIT; /* a voxel on the way */
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
        const __m128d TEv = sse_min3(Txy, Tzw);
        if (_mm_cvtsd_f64(TEv) >= t_end || left-- == 0)
            break;
        __m128d Exy = _mm_cmpeq_pd(Txy, TEv), Ezw = _mm_cmpeq_pd(Tzw, TEv);
        unsigned smask = (unsigned)_mm_movemask_pd(Exy) | (unsigned)_mm_movemask_pd(Ezw) << 2;
        if ((~(ci ^ far) & smask) && !climb(fr, ax, floor, TEv, &d, &ci, &size, &V, &smask, &Exy,
                                             &Ezw, &Txy, &Tzw, &TPxy, &TPzw, &M, &P)) {
            /* the floor's cell left: through the stepped axes on which its
               child (ci) is on the far half; on the others the step only
               crosses the floor cell's mid plane (and no other axis of the
               floor cell's exits at TEv: the child's later exits are not
               nearer on the parent) */
            if (floor) {
                *exit_t = TEv;
                *exit_mask = smask & ~(ci ^ far) & 7u;
                res = WALK_LEFT;
            }
            break;
        }
        ci ^= smask;
        Txy = _mm_blendv_pd(Txy, TPxy, Exy);
        Tzw = _mm_blendv_pd(Tzw, TPzw, Ezw);
        V = _mm_xor_si128(V, _mm_and_si128(_mm_set1_epi32((int32_t)size),
                                           _mm_load_si128((const __m128i *)trace_lut[smask])));
        TC = TEv;
        continue;
    leave:;
        /* nothing on the way in the floor's cell: left through its exits */
        const __m128d TFv = sse_min3(Txy, Tzw);
        if (_mm_cvtsd_f64(TFv) >= t_end || left-- == 0)
            break;
        *exit_t = TFv;
        *exit_mask = sse_ties(Txy, Tzw, TFv);
        res = WALK_LEFT;
        break;
    }
    *left_io = left;
    return res;
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
    *steps_out = 0;
    if (tree->node_count[0] == 0)
        return 0;
    const uint32_t max_steps = trace_max_steps(levels);
    uint32_t left = max_steps; /* steps left: counted down */
    const oct_group *const *groups = tree->groups;

    sse_axes ax;
    __m128d TPxy, TPzw, Txy, Tzw;
    sse_axes_init(r, levels, &ax, NULL, NULL);

    trace_frame fr[OCT_MAX_LEVELS];
    uint32_t M = groups[0][0].mask[0], Mn;
    uint64_t P = groups[0][0].base, Pn;
    fr[0].mask = M;
    fr[0].prefix = P;
    fr[0].ci = 0;
    unsigned d = 0, ci = 0;
    uint32_t size = UINT32_C(1) << levels;
    __m128i V = _mm_setzero_si128();

    if (anchor && anchor->depth) {
        /* the anchor's cell is the current one: tested like any other */
        d = anchor->depth;
        memcpy(fr, anchor->node, (d + 1u) * sizeof fr[0]); /* frames 0..d, one layout */
        size = UINT32_C(1) << (levels - d);
        V = _mm_setr_epi32((int32_t)anchor->cell[0], (int32_t)anchor->cell[1],
                           (int32_t)anchor->cell[2], 0);
        trace_cell_exits(V, 2u * size, &ax, &TPxy, &TPzw);
        ci = fr[d].ci;
        M = fr[d - 1].mask;
        P = fr[d - 1].prefix;
        Mn = fr[d].mask;
        Pn = fr[d].prefix;
    } else {
        /* from the root, tested like any other cell (its exits: sse_axes_init's) */
        TPxy = TPzw = _mm_setzero_pd(); /* the root has no parent: never read */
        Mn = M;
        Pn = P;
    }
    trace_cell_exits(V, size, &ax, &Txy, &Tzw);
    __m128d exit_t; /* not set: the floor is the root */
    unsigned exit_mask;
    const int hit = occluded_walk(groups, &ax, levels, 0, fr, d, ci, size, V, Txy, Tzw, TPxy, TPzw,
                                  _mm_set1_pd(r->t_start), M, P, Mn, Pn, r->t_end, &left, &exit_t,
                                  &exit_mask) == WALK_HIT;
    *steps_out = max_steps - left; /* max_steps + 1 when the bound was passed */
    return hit;
}

/* The ray's cell of `shift`-voxel cells along active axis a at t, by the
 * tie rule of trace.h on the cells' planes (voxel planes, whose T() the walk
 * computes too), within [lo, hi - 1] where the caller knows it lies. */
static uint32_t grid_cell_at(const trace_ray *r, int a, double t, unsigned shift, uint32_t lo,
                             uint32_t hi)
{
    const double cs = (double)(UINT32_C(1) << shift);
    const double p = (r->o[a] + t * r->d[a]) / cs;
    uint32_t m = !(p > (double)lo) ? lo : p >= (double)hi ? hi - 1u : (uint32_t)p;
    if (r->sgn[a] > 0) {
        while (m > lo && trace_plane_time(r, a, (double)m * cs) > t)
            m--;
        while (m + 1u < hi && trace_plane_time(r, a, (double)(m + 1u) * cs) <= t)
            m++;
    } else {
        while (m > lo && trace_plane_time(r, a, (double)m * cs) <= t)
            m--;
        while (m + 1u < hi && trace_plane_time(r, a, (double)(m + 1u) * cs) > t)
            m++;
    }
    return m;
}

/* A 3-bit mask (one bit a lane x, y, z) of the lanes set in two 64-bit
 * comparisons. */
SSE_INLINE unsigned grid_mask(__m128d xy, __m128d zw)
{
    return ((unsigned)_mm_movemask_pd(xy) | (unsigned)_mm_movemask_pd(zw) << 2) & 7u;
}

int trace_occluded_grid_sse(const oct_tree *tree, const ao_grid *g, const trace_ray *r,
                            const trace_anchor *anchor, uint32_t *steps_out)
{
    if (r->active != 7u || tree->node_count[0] == 0)
        return trace_occluded_sse(tree, r, anchor, steps_out);
    const unsigned levels = tree->levels;
    const uint32_t max_steps = trace_max_steps(levels);
    uint32_t left = max_steps;
    const oct_group *const *groups = tree->groups;
    sse_axes ax;
    sse_axes_init(r, levels, &ax, NULL, NULL);
    const unsigned shift = g->shift, depth = g->depth;
    const uint32_t n = g->n, cs = UINT32_C(1) << shift;
    const double t_end = r->t_end;
    const __m128i SH = _mm_cvtsi32_si128((int)shift);
    const __m128i ONE = _mm_set1_epi32(1), ZERO = _mm_setzero_si128();
    const __m128i NMAX = _mm_set1_epi32((int32_t)n);
    const double near_plane = g->near_plane;
    const unsigned octant_shift = 4u * ax.far; /* the rays' octant's clearance in a word */
    /* +1 on the far axes, -1 on the others: a step to the next cell */
    const __m128i DIR = _mm_sub_epi32(_mm_and_si128(ax.FARM, _mm_set1_epi32(2)), ONE);
    __m128d TC = _mm_set1_pd(r->t_start);
    trace_frame fr[OCT_MAX_LEVELS];
    __m128i C;
    __m128d TEv;    /* a step out of the current cell: its time, */
    unsigned exits; /* and the axes it crosses */
    int hit = 0;
    if (anchor && anchor->depth > depth) {
        /* the start lies in the anchor's cell, in an occupied cell of the
           grid: walked from the anchor as the plain walk does, up to the
           grid cell's faces */
        const unsigned d = anchor->depth;
        /* frames depth .. d, one layout: the walk reads none above its floor */
        for (unsigned k = depth; k <= d; k++)
            _mm_storeu_si128((__m128i *)(void *)&fr[k],
                             _mm_loadu_si128((const __m128i *)(const void *)&anchor->node[k]));
        const uint32_t size = UINT32_C(1) << (levels - d);
        const __m128i V = _mm_setr_epi32((int32_t)anchor->cell[0], (int32_t)anchor->cell[1],
                                         (int32_t)anchor->cell[2], 0);
        __m128d Txy, Tzw, TPxy, TPzw;
        trace_cell_exits(V, size, &ax, &Txy, &Tzw);
        trace_cell_exits(V, 2u * size, &ax, &TPxy, &TPzw);
        const int res = occluded_walk(groups, &ax, levels, depth, fr, d, fr[d].ci, size, V, Txy,
                                      Tzw, TPxy, TPzw, TC, fr[d - 1].mask, fr[d - 1].prefix,
                                      fr[d].mask, fr[d].prefix, t_end, &left, &TEv, &exits);
        if (res != WALK_LEFT) {
            *steps_out = max_steps - left;
            return res == WALK_HIT;
        }
        C = _mm_srl_epi32(V, SH);
        goto next_cell;
    } else {
        uint32_t c[4];
        for (int a = 0; a < 3; a++)
            c[a] = grid_cell_at(r, a, r->t_start, shift, 0, n);
        c[3] = 0;
        C = _mm_loadu_si128((const __m128i *)c);
    }
    for (;;) {
        const uint32_t cx = (uint32_t)_mm_cvtsi128_si32(C),
                       cy = (uint32_t)_mm_extract_epi32(C, 1),
                       cz = (uint32_t)_mm_extract_epi32(C, 2);
        const uint32_t w = g->cell[cx + (size_t)n * (cy + (size_t)n * cz)];
        const uint32_t k = AO_GRID_OCCUPIED(w) ? 0u : w >> octant_shift & 15u;
        if (k == 0) {
            const __m128i V = _mm_sll_epi32(C, SH);
            __m128d Txy, Tzw;
            trace_cell_exits(V, cs, &ax, &Txy, &Tzw);
            const oct_children ch = oct_node_children(groups[depth], AO_GRID_NODE(w));
            const int res = occluded_walk(groups, &ax, levels, depth, fr, depth, 0, cs, V, Txy, Tzw,
                                          Txy, Tzw, TC, 0, 0, ch.mask, ch.first, t_end, &left,
                                          &TEv, &exits);
            if (res != WALK_LEFT) {
                hit = res == WALK_HIT;
                break;
            }
            goto next_cell;
        }
        if (k == 1) {
            /* the cell alone: left through its exit planes */
            __m128d Txy, Tzw;
            sse_plane_times(_mm_sll_epi32(_mm_sub_epi32(C, ax.FARM), SH), &ax, &Txy, &Tzw);
            TEv = sse_min3(Txy, Tzw);
            if (_mm_cvtsd_f64(TEv) >= t_end || left-- == 0)
                break;
            exits = sse_ties(Txy, Tzw, TEv) & 7u;
            goto next_cell;
        }
        /* the empty cube of k cells from C on the ray's side */
        const __m128i K1 = _mm_set1_epi32((int32_t)k - 1);
        const __m128i LO = _mm_max_epi32(_mm_sub_epi32(C, _mm_andnot_si128(ax.FARM, K1)), ZERO);
        const __m128i HI =
            _mm_min_epi32(_mm_add_epi32(_mm_add_epi32(C, ONE), _mm_and_si128(ax.FARM, K1)), NMAX);
        /* the box's exit: its planes on the far sides */
        __m128d Txy, Tzw;
        sse_plane_times(_mm_sll_epi32(_mm_blendv_epi8(LO, HI, ax.FARM), SH), &ax, &Txy, &Tzw);
        TEv = sse_min3(Txy, Tzw);
        if (_mm_cvtsd_f64(TEv) >= t_end || left-- == 0)
            break;
        exits = sse_ties(Txy, Tzw, TEv) & 7u;
        /* past the box on the exit axes; the root is left past 0 or n */
        const __m128i NEXT = _mm_blendv_epi8(_mm_sub_epi32(LO, ONE), HI, ax.FARM);
        const __m128i EM = _mm_load_si128((const __m128i *)trace_lut[exits]);
        const __m128i OUTS = _mm_and_si128(
            EM, _mm_or_si128(_mm_cmpgt_epi32(ZERO, NEXT), _mm_cmpeq_epi32(NEXT, NMAX)));
        if (!_mm_testz_si128(OUTS, OUTS))
            break;
        /* the other axes: the cell the position falls in, unless it is
           near a plane: then the cell by the plane times */
        const __m128d Pxy = _mm_add_pd(_mm_loadu_pd(r->o), _mm_mul_pd(TEv, _mm_loadu_pd(r->d)));
        const __m128d Pzw = _mm_add_pd(_mm_set_sd(r->o[2]), _mm_mul_pd(TEv, _mm_set_sd(r->d[2])));
        const __m128i VOX = _mm_unpacklo_epi64(_mm_cvttpd_epi32(Pxy), _mm_cvttpd_epi32(Pzw));
        const __m128i CAND = _mm_srl_epi32(VOX, SH);
        const __m128i CORNER = _mm_sll_epi32(CAND, SH);
        /* the position from the cell's corner, in [0, cs) away from planes */
        const __m128d Fxy = _mm_sub_pd(Pxy, _mm_cvtepi32_pd(CORNER));
        const __m128d Fzw = _mm_sub_pd(Pzw, _mm_cvtepi32_pd(_mm_unpackhi_epi64(CORNER, CORNER)));
        const __m128d NEAR_PLANE = _mm_set1_pd(near_plane);
        const __m128d FAR_PLANE = _mm_set1_pd((double)cs - near_plane);
        const unsigned near = grid_mask(
            _mm_or_pd(_mm_cmplt_pd(Fxy, NEAR_PLANE), _mm_cmpgt_pd(Fxy, FAR_PLANE)),
            _mm_or_pd(_mm_cmplt_pd(Fzw, NEAR_PLANE), _mm_cmpgt_pd(Fzw, FAR_PLANE)));
        C = _mm_blendv_epi8(CAND, NEXT, EM);
        if (near & ~exits) {
            const double te = _mm_cvtsd_f64(TEv);
            uint32_t cc[4], lo[4], hi[4];
            _mm_storeu_si128((__m128i *)cc, C);
            _mm_storeu_si128((__m128i *)lo, LO);
            _mm_storeu_si128((__m128i *)hi, HI);
            for (int a = 0; a < 3; a++)
                if ((near & ~exits) >> a & 1u)
                    cc[a] = grid_cell_at(r, a, te, shift, lo[a], hi[a]);
            C = _mm_loadu_si128((const __m128i *)cc);
        }
        TC = TEv;
        continue;
    next_cell:;
        /* one cell on along the exit axes, the same cell on the others
           (the step left only the current cell, or its box was one cell) */
        C = _mm_add_epi32(C, _mm_and_si128(_mm_load_si128((const __m128i *)trace_lut[exits]), DIR));
        const __m128i OUT = _mm_or_si128(_mm_cmpgt_epi32(ZERO, C), _mm_cmpeq_epi32(C, NMAX));
        if (!_mm_testz_si128(OUT, OUT))
            break; /* the root left */
        TC = TEv;
    }
    *steps_out = max_steps - left;
    return hit;
}
#endif
