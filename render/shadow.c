/* shadow: start point and any-hit cast of secondary rays. */
#include "render/shadow.h"

#include <math.h>

#include "format/oct_normal.h"

double shadow_offset(const float n[3])
{
    return (double)fabsf(n[0]) + (double)fabsf(n[1]) + (double)fabsf(n[2]) + 0.25;
}

void shadow_origin(const oct_tree *tree, const trace_hit *hit, const float n[3], double o[3])
{
    const uint32_t rec = tree->voxels[hit->voxel];
    float ns[3]; /* the stored normal: the plane's, n or -n */
    oct_normal_decode(rec & OCT_VOXEL_NORMAL_MASK, ns);
    const double off = oct_offset_decode((int8_t)(uint8_t)(rec >> OCT_VOXEL_OFFSET_SHIFT));
    const double h = shadow_offset(n);
    const double vox = tree->edge / (double)(UINT64_C(1) << tree->levels);
    for (int a = 0; a < 3; a++)
        o[a] = tree->origin[a] +
               ((double)hit->xyz[a] + 0.5 + off * (double)ns[a] + h * (double)n[a]) * vox;
}

int shadow_blocked(const oct_tree *tree, const trace_opts *opts, trace_traverse_fn traverse,
                   const double o[3], const double d[3], double t_max, uint64_t *steps)
{
    trace_ray r;
    if (!trace_setup(tree, o, d, &r))
        return 0; /* the ray misses the cube */
    if (t_max < INFINITY && !trace_clip(&r, 0.0, t_max))
        return 0;
    trace_hit h;
    if (!traverse)
        traverse = trace_impls[0].traverse;
    traverse(tree, opts, &r, NULL, &h);
    *steps += h.steps;
    return h.hit;
}
