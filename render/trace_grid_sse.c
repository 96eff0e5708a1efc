/* trace_grid_sse: the any-hit walk of AO rays through the clearance grid
 * (render/ao_grid.h), built where the SSE traversal is. */
#include "render/ao_grid.h"
#include "render/trace_impl.h"

#if TRACE_HAVE_SSE
#include <math.h>

#include "render/trace_sse_walk.h"

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

/* T() of the planes K (voxel coordinates, lanes x, y, z; w ignored) per
 * axis, the dummy lane w raised to +inf: trace_cell_exits's arithmetic. */
SSE_INLINE void grid_plane_times(__m128i K, const sse_axes *ax, __m128d *txy, __m128d *tzw)
{
    *txy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(K), ax->ZOxy), ax->ZIxy);
    *tzw = _mm_max_pd(
        _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(K, K)), ax->ZOzw), ax->ZIzw),
        ax->WINF);
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
            grid_plane_times(_mm_sll_epi32(_mm_sub_epi32(C, ax.FARM), SH), &ax, &Txy, &Tzw);
            const __m128d m2 = _mm_min_pd(Txy, Tzw);
            TEv = _mm_min_pd(m2, _mm_shuffle_pd(m2, m2, 1));
            if (_mm_cvtsd_f64(TEv) >= t_end || left-- == 0)
                break;
            exits = grid_mask(_mm_cmpeq_pd(Txy, TEv), _mm_cmpeq_pd(Tzw, TEv));
            goto next_cell;
        }
        /* the empty cube of k cells from C on the ray's side */
        const __m128i K1 = _mm_set1_epi32((int32_t)k - 1);
        const __m128i LO = _mm_max_epi32(_mm_sub_epi32(C, _mm_andnot_si128(ax.FARM, K1)), ZERO);
        const __m128i HI =
            _mm_min_epi32(_mm_add_epi32(_mm_add_epi32(C, ONE), _mm_and_si128(ax.FARM, K1)), NMAX);
        /* the box's exit: its planes on the far sides */
        __m128d Txy, Tzw;
        grid_plane_times(_mm_sll_epi32(_mm_blendv_epi8(LO, HI, ax.FARM), SH), &ax, &Txy, &Tzw);
        const __m128d m2 = _mm_min_pd(Txy, Tzw);
        TEv = _mm_min_pd(m2, _mm_shuffle_pd(m2, m2, 1));
        if (_mm_cvtsd_f64(TEv) >= t_end || left-- == 0)
            break;
        exits = grid_mask(_mm_cmpeq_pd(Txy, TEv), _mm_cmpeq_pd(Tzw, TEv));
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
