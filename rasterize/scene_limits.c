/* scene_limits: the format's limits applied to a scene, with the place in
 * the scene file that breaks them. */
#include "rasterize/scene_limits.h"

#include <math.h>
#include <stdio.h>

#include "format/oct.h"
#include "rasterize/build.h"

static int fail(scene_error *err, unsigned line, unsigned col, const char *msg)
{
    err->line = line;
    err->col = col;
    snprintf(err->message, sizeof err->message, "%s", msg);
    return -1;
}

int scene_limits_check(const scene *sc, unsigned levels, scene_error *err)
{
    char msg[sizeof err->message];
    if (sc->nsurfaces > OCT_MAX_SURFACES) {
        const scene_surface *s = &sc->surfaces[OCT_MAX_SURFACES];
        snprintf(msg, sizeof msg, "surface %d: at most %d surfaces are supported",
                 OCT_MAX_SURFACES + 1, OCT_MAX_SURFACES);
        return fail(err, s->line, s->col, msg);
    }
    double origin[3], edge;
    build_cube(sc, origin, &edge);
    int longest = 0; /* the axis whose side is the cube's edge */
    for (int a = 1; a < 3; a++)
        if (sc->hi[a] - sc->lo[a] > sc->hi[longest] - sc->lo[longest])
            longest = a;
    const unsigned line = sc->bounds_line, *col = sc->bounds_col;
    for (int a = 0; a < 3; a++) {
        switch (oct_cube_check(origin[a], edge, 0, levels)) {
        case OCT_CUBE_OK: break;
        case OCT_CUBE_EDGE_LARGE:
            snprintf(msg, sizeof msg, "bounds: the cube's edge (%g, the longest side) exceeds the largest, %g",
                     edge, OCT_MAX_COORD);
            return fail(err, line, col[4 + longest], msg);
        case OCT_CUBE_EDGE_SMALL:
            snprintf(msg, sizeof msg, "bounds: the cube's edge (%g, the longest side) is below the smallest, %g",
                     edge, OCT_MIN_EDGE);
            return fail(err, line, col[4 + longest], msg);
        case OCT_CUBE_ORIGIN_FAR:
            snprintf(msg, sizeof msg, "bounds: %c0 (%g) is farther from 0 than the largest coordinate, %g",
                     'X' + a, origin[a], OCT_MAX_COORD);
            return fail(err, line, col[1 + a], msg);
        case OCT_CUBE_VOXEL_FINE:
            snprintf(msg, sizeof msg,
                     "bounds: at --levels %u a voxel (%g) is finer than 2^-%d of |%c0| + edge (%g): "
                     "use fewer levels or bounds nearer the origin",
                     levels, ldexp(edge, -(int)levels), OCT_RES_BITS, 'X' + a, fabs(origin[a]) + edge);
            return fail(err, line, col[0], msg);
        }
    }
    return 0;
}
