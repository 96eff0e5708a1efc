/* beam: the window of ray parameter a pixel block needs (see beam.h). */
#include "render/beam.h"

#include <math.h>

beam_block beam_block_of(const camera *cam, uint32_t i0, uint32_t i1, uint32_t j0, uint32_t j1)
{
    /* u grows with i, v falls with j */
    beam_block b = {camera_u(cam, i0), camera_u(cam, i1 - 1), camera_v(cam, j1 - 1),
                    camera_v(cam, j0)};
    return b;
}

/* The pyramid as five half-spaces a_k . (p - eye) >= 0. A ray direction is
 * F + uR + vU (normalised) with u in [u0, u1], v in [v0, v1]; its points q
 * relative to the eye have q.F >= 0 and u0 q.F <= q.R <= u1 q.F, and the
 * same in v. */
typedef struct pyramid {
    double a[5][3], m[5][3]; /* normals and their absolute values */
} pyramid;

static void pyramid_init(pyramid *p, const camera *cam, const beam_block *b)
{
    const double *F = cam->forward, *R = cam->right, *U = cam->up;
    for (int i = 0; i < 3; i++) {
        p->a[0][i] = R[i] - b->u0 * F[i];
        p->a[1][i] = b->u1 * F[i] - R[i];
        p->a[2][i] = U[i] - b->v0 * F[i];
        p->a[3][i] = b->v1 * F[i] - U[i];
        p->a[4][i] = F[i];
    }
    for (int k = 0; k < 5; k++)
        for (int i = 0; i < 3; i++)
            p->m[k][i] = fabs(p->a[k][i]);
}

/* 0 when the box (centre c relative to the eye, half edge h) lies wholly
 * outside one of the half-spaces. */
static int pyramid_may_touch(const pyramid *p, const double c[3], double h)
{
    for (int k = 0; k < 5; k++) {
        const double *a = p->a[k], *m = p->m[k];
        if (a[0] * c[0] + a[1] * c[1] + a[2] * c[2] + h * (m[0] + m[1] + m[2]) < 0.0)
            return 0;
    }
    return 1;
}

typedef struct beam_item {
    uint64_t node;  /* index in its depth */
    uint32_t cell[3];
    unsigned depth;
    double dist;    /* its distance bound when it was pushed */
} beam_item;

typedef struct beam_walk {
    const oct_tree *tree;
    pyramid p;
    double o[3];   /* the eye in grid units (voxels), as the traversal has it */
    double margin; /* voxels added to every half edge */
    unsigned flip;
} beam_walk;

/* The nearest (far = 0) or farthest (far = 1) distance from the eye to an
 * occupied cell of depth lim (1..levels) the pyramid may touch; +inf (far: -inf) when
 * there is none. Children are visited nearest first for the nearest and
 * farthest first for the farthest, and a cell that cannot beat the best so
 * far is not opened: a best-first search along the front (or back) of the
 * surface, not a sweep of the pyramid. */
static double beam_extreme(const beam_walk *bw, int far, unsigned lim)
{
    const oct_tree *tree = bw->tree;
    const double *o = bw->o;
    double best = far ? -INFINITY : INFINITY;
    beam_item stack[8 * OCT_MAX_LEVELS + 1];
    unsigned sp = 0;
    stack[sp++] = (beam_item){0, {0, 0, 0}, 0, 0.0};
    const unsigned order = bw->flip ^ (far ? 7u : 0u);
    while (sp) {
        const beam_item it = stack[--sp];
        if (far ? it.dist <= best : it.dist >= best)
            continue; /* the best improved since it was pushed */
        const oct_group *g = &tree->groups[it.depth][it.node >> 3];
        const unsigned mask = g->mask[it.node & 7u];
        const double s = (double)(UINT32_C(1) << (tree->levels - it.depth - 1)); /* child edge */
        const double h = 0.5 * s + bw->margin;
        /* pushed in reverse order: the child to look at first is popped first */
        for (int k = 7; k >= 0; k--) {
            const unsigned c = (unsigned)k ^ order;
            if (!(mask >> c & 1u))
                continue;
            uint32_t cell[3];
            double ctr[3], d2 = 0.0;
            for (int i = 0; i < 3; i++) {
                cell[i] = 2u * it.cell[i] + (c >> i & 1u);
                ctr[i] = ((double)cell[i] + 0.5) * s - o[i]; /* one rounding */
                const double e = far ? fabs(ctr[i]) + h : fabs(ctr[i]) - h;
                if (e > 0.0)
                    d2 += e * e;
            }
            const double dist = sqrt(d2);
            if (far ? dist <= best : dist >= best)
                continue; /* nothing inside can beat the best */
            if (!pyramid_may_touch(&bw->p, ctr, h))
                continue;
            if (it.depth + 1 == lim) {
                best = dist;
                continue;
            }
            stack[sp++] = (beam_item){oct_child_index(tree->groups[it.depth], it.node, c),
                                      {cell[0], cell[1], cell[2]}, it.depth + 1, dist};
        }
    }
    return best;
}

/* Grid distance -> the caller's t (unit directions), widened outward by a
 * relative 2^-40 for the division and a direction's length of 1 +- ulps. */
static double t_down(double dist, double scale) { return dist / scale * (1.0 - 0x1p-40); }
static double t_up(double dist, double scale) { return dist / scale * (1.0 + 0x1p-40); }

int beam_window(const oct_tree *tree, const camera *cam, const beam_block *b, double *t_lo,
                double *t_hi)
{
    const unsigned levels = tree->levels;
    if (tree->node_count[0] == 0 || levels < 1 || levels > OCT_MAX_LEVELS)
        return 0;
    beam_walk bw;
    bw.tree = tree;
    pyramid_init(&bw.p, cam, b);
    /* Grid units, the eye placed as the traversal places it: cell centres
     * are exact and, relative to the eye, carry one rounding of
     * ulp(max(|o|, N)), as the traversal's plane times do. The margin covers
     * both with room to spare: 2^-12 voxel plus 2^-40 of that magnitude. */
    const double n = (double)(UINT32_C(1) << levels), scale = n / tree->edge;
    double big = n;
    bw.flip = 0; /* the child nearest the eye along the view direction */
    for (int i = 0; i < 3; i++) {
        bw.o[i] = (cam->eye[i] - tree->origin[i]) * scale;
        if (!isfinite(bw.o[i]))
            return 0; /* trace_eye_init refuses such an eye: every ray misses */
        big = fmax(big, fabs(bw.o[i]));
        bw.flip |= (cam->forward[i] < 0.0 ? 1u : 0u) << i;
    }
    bw.margin = 0x1p-12 + big * 0x1p-40;
    const double lo = beam_extreme(&bw, 0, levels);
    if (!(lo < INFINITY))
        return 0;
    *t_lo = t_down(lo, scale);
    /* The far end only stops rays that miss: the voxels' parents of depth
     * L - 3 bound it a few voxels later for far fewer opened cells
     * (RENDER.md, "Beam"). */
    *t_hi = t_up(beam_extreme(&bw, 1, levels > 3 ? levels - 3 : 1), scale);
    return 1;
}
