/* aa: the edge test of adaptive antialiasing. */
#include "render/aa.h"

#include <math.h>
#include <stddef.h>

int aa_differs(const aa_probe *a, const aa_probe *b)
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

int aa_needs(const aa_probe *probes, uint32_t w, uint32_t h, uint32_t i, uint32_t j)
{
    const aa_probe *p = &probes[(size_t)j * w + i];
    if (p->beam_edge)
        return 1;
    /* the common case, misses all round, without the calls */
    if (!p->hit && (i == 0 || !p[-1].hit) && (i + 1 >= w || !p[1].hit) &&
        (j == 0 || !p[-(ptrdiff_t)w].hit) && (j + 1 >= h || !p[w].hit))
        return 0;
    return (i > 0 && aa_differs(p, p - 1)) || (i + 1 < w && aa_differs(p, p + 1)) ||
           (j > 0 && aa_differs(p, p - w)) || (j + 1 < h && aa_differs(p, p + w));
}
