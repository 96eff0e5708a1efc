/* oct_cube: the cube rule of FORMAT.md §6, shared by the reader, the writer
 * and the rasterizer's check of a scene's bounds. */
#include "format/oct.h"

#include <math.h>

oct_cube_err oct_cube_check(double grid_origin, double grid_edge, uint32_t root_depth,
                            uint32_t levels)
{
    if (!(grid_edge <= OCT_MAX_COORD))
        return OCT_CUBE_EDGE_LARGE;
    if (!(grid_edge >= OCT_MIN_EDGE))
        return OCT_CUBE_EDGE_SMALL;
    if (!(fabs(grid_origin) <= OCT_MAX_COORD))
        return OCT_CUBE_ORIGIN_FAR;
    /* exact: scalings by powers of two of a normal number that stay normal */
    double voxel = ldexp(grid_edge, -(int)(root_depth + levels));
    if (!(fabs(grid_origin) + grid_edge <= ldexp(voxel, OCT_RES_BITS)))
        return OCT_CUBE_VOXEL_FINE;
    return OCT_CUBE_OK;
}
