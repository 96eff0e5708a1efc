/* trace_refine: the --refine hit test in one voxel (RENDER.md, "--refine"). */
#include <stdint.h>

#include "format/oct_normal.h"
#include "render/trace_impl.h"

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
int trace_refine_voxel(const oct_tree *tree, const trace_ray *r, uint64_t idx,
                       const uint32_t v[3], double t_in, double t_out, int *side, double *t_hit)
{
    double num, den;
    trace_voxel_plane(tree, r, idx, v, &num, &den);
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
