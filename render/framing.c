/* framing: the default camera from the occupied voxels' box. */
#include "render/framing.h"

#include <math.h>
#include <string.h>

typedef struct box_walk {
    const oct_tree *tree;
    unsigned depth;       /* the cells boxed: this depth's */
    uint32_t lo[3], hi[3]; /* in cells of that depth, hi exclusive */
} box_walk;

/* Node `node` of depth d, corner c (cells of depth d): its occupied
 * children, down to w->depth. */
static void walk(box_walk *w, unsigned d, uint64_t node, const uint32_t c[3])
{
    const oct_children ch = oct_node_children(w->tree->groups[d], node);
    unsigned rank = 0;
    for (unsigned k = 0; k < 8; k++) {
        if (!(ch.mask & (1u << k)))
            continue;
        const uint32_t cc[3] = {2 * c[0] + (k & 1), 2 * c[1] + (k >> 1 & 1), 2 * c[2] + (k >> 2)};
        if (d + 1 == w->depth) {
            for (int a = 0; a < 3; a++) {
                w->lo[a] = cc[a] < w->lo[a] ? cc[a] : w->lo[a];
                w->hi[a] = cc[a] + 1 > w->hi[a] ? cc[a] + 1 : w->hi[a];
            }
        } else {
            walk(w, d + 1, ch.first + rank, cc);
        }
        rank++;
    }
}

int framing_occupied_box(const oct_tree *tree, double lo[3], double hi[3])
{
    if (tree->node_count[0] == 0 || tree->voxel_count == 0 || tree->levels < 1)
        return 0;
    box_walk w;
    w.tree = tree;
    w.depth = tree->levels < FRAMING_DEPTH ? tree->levels : FRAMING_DEPTH;
    for (int a = 0; a < 3; a++) {
        w.lo[a] = UINT32_MAX;
        w.hi[a] = 0;
    }
    const uint32_t c0[3] = {0, 0, 0};
    walk(&w, 0, 0, c0);
    if (w.hi[0] == 0)
        return 0;
    const double cell = tree->edge / (double)(1u << w.depth);
    for (int a = 0; a < 3; a++) {
        lo[a] = tree->origin[a] + (double)w.lo[a] * cell;
        hi[a] = tree->origin[a] + (double)w.hi[a] * cell;
    }
    return 1;
}

void framing_default_view(const oct_tree *tree, views_view *v)
{
    double lo[3], hi[3];
    if (!framing_occupied_box(tree, lo, hi))
        for (int a = 0; a < 3; a++) {
            lo[a] = tree->origin[a];
            hi[a] = tree->origin[a] + tree->edge;
        }
    double c[3], r2 = 0.0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (lo[a] + hi[a]);
        r2 += 0.25 * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    if (!v->has_target)
        memcpy(v->target, c, sizeof c);
    if (!v->has_eye) {
        static const double dir[3] = {1.7, 1.1, 1.4};
        double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        double h = tan(v->fov * M_PI / 360.0);
        if (v->width < v->height)
            h = h * (double)v->width / (double)v->height;
        /* the box's bounding sphere (about the target, which may be given) */
        double r = 0.0;
        for (int a = 0; a < 3; a++) {
            const double e = fmax(fabs(lo[a] - v->target[a]), fabs(hi[a] - v->target[a]));
            r += e * e;
        }
        r = sqrt(v->has_target ? r : r2);
        double dist = 1.05 * r / sin(atan(h));
        for (int a = 0; a < 3; a++)
            v->eye[a] = v->target[a] + dist * dir[a] / n;
    }
}
