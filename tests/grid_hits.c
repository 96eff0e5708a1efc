/* grid_hits: primary hits for the secondary-ray tests (see grid_hits.h). */
#include "tests/grid_hits.h"

#include "format/oct_normal.h"

int grid_hit(const oct_tree *t, const trace_opts *o, const double eye[3], int x, int y,
             trace_hit *h, float n[3])
{
    const double target[3] = {18.0 + 1.13 * x, 18.0 + 1.07 * y, 21.3};
    double dir[3];
    for (int a = 0; a < 3; a++)
        dir[a] = target[a] - eye[a];
    if (!trace_ray_cast(t, o, eye, dir, h))
        return 0;
    oct_normal_decode(t->voxels[h->voxel] & OCT_VOXEL_NORMAL_MASK, n);
    if (n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] > 0.0)
        for (int a = 0; a < 3; a++)
            n[a] = -n[a];
    return 1;
}
