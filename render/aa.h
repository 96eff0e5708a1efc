/* aa: adaptive antialiasing (RENDER.md, "Antialiasing"). Every pixel gets
 * its centre ray first; a pixel whose centre ray differs from one of its
 * four neighbours' (hit or miss, surface, depth by more than
 * AA_DEPTH_REL of the nearer t, normal by more than AA_NORMAL_COS) is then
 * traced again with N x N stratified samples: the centres of the N x N
 * sub-squares of the pixel. The decision reads only centre rays, so the
 * image is the same whatever the thread count. */
#ifndef AA_H
#define AA_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#define AA_MAX 16
#define AA_DEPTH_REL 0.01f   /* |t - t'| > 1 % of min(t, t') */
#define AA_NORMAL_COS 0.866f /* normals more than 30 degrees apart */

/* What the edge test keeps of a pixel's centre ray. */
typedef struct aa_probe {
    float t;
    float t_lo;       /* the beam's start for the centre ray's sub-block (rounded down) */
    float n[3];
    uint16_t surface;
    uint8_t hit;
    uint8_t need;     /* the pixel needs its samples (aa_mark_inside, the beam's mark) */
} aa_probe;

/* 1 when the centre rays a and b differ by the rule above (symmetric). */
static inline int aa_differs(const aa_probe *a, const aa_probe *b)
{
    if (a->hit != b->hit)
        return 1;
    if (!a->hit)
        return 0;
    if (a->surface != b->surface)
        return 1;
    const float lo = a->t < b->t ? a->t : b->t;
    if (fabsf(a->t - b->t) > AA_DEPTH_REL * lo)
        return 1;
    const float c = a->n[0] * b->n[0] + a->n[1] * b->n[1] + a->n[2] * b->n[2];
    return c < AA_NORMAL_COS;
}

/* A pixel needs its samples when it differs from a 4-neighbour inside the
 * image, or when the beam pre-pass says its sub-block holds an edge: the
 * sub-block's pyramid, which lies within its pixels' squares, may meet an
 * occupied voxel (a finite start) but none of its centre rays hit one, so
 * something lies between them that only samples can find. (A sub-block
 * with hits holds its edges where the neighbour test finds them.)
 * aa_mark_inside sets `need` on each probe of the w x h rectangle p (rows
 * `stride` probes apart) that differs from a 4-neighbour inside the
 * rectangle, each pair compared once; the frame compares the pairs that
 * straddle two tiles apart. */
void aa_mark_inside(aa_probe *p, size_t stride, uint32_t w, uint32_t h);

/* Offset of sample k (k < n * n) inside the pixel, in pixel units, each in
 * (0, 1): the centre of sub-square (k % n, k / n). */
static inline void aa_sample_offset(unsigned n, unsigned k, double *fx, double *fy)
{
    *fx = ((double)(k % n) + 0.5) / (double)n;
    *fy = ((double)(k / n) + 0.5) / (double)n;
}

#endif
