/* trace_sse_walk: what the SSE traversal (trace_sse.c) and the SSE any-hit
 * walks (trace_anyhit_sse.c) share: a ray's axes in SSE registers, a cell's
 * exit times, the climb to the common ancestor. Internal: included only
 * where TRACE_HAVE_SSE (render/trace_impl.h). The two files are apart on
 * purpose: with the any-hit walks in its file, GCC allocated the
 * traversal's registers worse (13 % more instructions, docs/perf-log.md). */
#ifndef TRACE_SSE_WALK_H
#define TRACE_SSE_WALK_H

#include <math.h>

#include <smmintrin.h>

#include "render/trace_impl.h"

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

/* T() of the planes K (voxel coordinates, lanes x, y, z; w ignored) per
 * axis, the dummy lane w raised to +inf by WINF. */
SSE_INLINE void sse_plane_times(__m128i K, const sse_axes *ax, __m128d *txy, __m128d *tzw)
{
    *txy = _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(K), ax->ZOxy), ax->ZIxy);
    *tzw = _mm_max_pd(
        _mm_mul_pd(_mm_sub_pd(_mm_cvtepi32_pd(_mm_unpackhi_epi64(K, K)), ax->ZOzw), ax->ZIzw),
        ax->WINF);
}

/* The exit times of the cell with corner V (bits below `edge` ignored) and
 * edge `edge`, T(corner + far * edge) per axis: the same T of the same
 * planes as a descent blends from mid-plane times, bit for bit. The dummy lane
 * w comes out 0 and is raised to +inf by WINF. */
SSE_INLINE void trace_cell_exits(__m128i V, uint32_t edge, const sse_axes *ax, __m128d *txy,
                                 __m128d *tzw)
{
    const __m128i C = _mm_andnot_si128(_mm_set1_epi32((int32_t)(edge - 1u)), V);
    sse_plane_times(_mm_add_epi32(C, _mm_and_si128(_mm_set1_epi32((int32_t)edge), ax->FARM)), ax,
                    txy, tzw);
}

/* The least of the times (x, y) and (z, w), in both lanes. */
SSE_INLINE __m128d sse_min3(__m128d txy, __m128d tzw)
{
    const __m128d m2 = _mm_min_pd(txy, tzw);
    return _mm_min_pd(m2, _mm_shuffle_pd(m2, m2, 1));
}

/* The axes whose time is t: bits x, y, z (and w, bit 3). */
SSE_INLINE unsigned sse_ties(__m128d txy, __m128d tzw, __m128d t)
{
    return (unsigned)_mm_movemask_pd(_mm_cmpeq_pd(txy, t)) |
           (unsigned)_mm_movemask_pd(_mm_cmpeq_pd(tzw, t)) << 2;
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

/* climb (the paper's ascent to the common ancestor, Fig. 3): the step at
 * TEv through the axes *smask (E: their lanes) leaves the parent too, one of
 * them being on its far half. Pops (depth d, child index ci, edge size)
 * until the common ancestor, the node in which the step stays, and makes its
 * child on the way up the current cell: corner V, exit times T, its parent's
 * exit times TP and node (M, P). Returns 0 when the root is left. */
SSE_INLINE int climb(const trace_frame *fr, const sse_axes *ax, unsigned floor, __m128d TEv,
                     unsigned *d, unsigned *ci, uint32_t *size, __m128i *V, unsigned *smask,
                     __m128d *Exy, __m128d *Ezw, __m128d *Txy, __m128d *Tzw, __m128d *TPxy,
                     __m128d *TPzw, uint32_t *M, uint64_t *P)
{
    do {
        (*d)--;
        if (*d == floor)
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

#endif
