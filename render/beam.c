/* beam: where a pixel block's rays can start (see beam.h). */
#include "render/beam.h"

#include <math.h>

typedef struct beam_block {
    double u0, u1, v0, v1; /* the block's outer pixel edges in camera (u, v) */
} beam_block;

/* The block's pyramid is bounded by its pixels' outer edges (camera_u's
 * formula at i0 and i1, not at the pixel centres i0 + 1/2 and i1 - 1/2), so
 * that every sub-block's pyramid holds its pixels' whole squares, where the
 * antialiasing samples lie. */
static beam_block beam_block_of(const camera *cam, uint32_t i0, uint32_t i1, uint32_t j0,
                                uint32_t j1)
{
    const double w = (double)cam->width, h = (double)cam->height;
    /* u grows with i, v falls with j */
    beam_block b = {(2.0 * (double)i0 / w - 1.0) * cam->h * w / h,
                    (2.0 * (double)i1 / w - 1.0) * cam->h * w / h,
                    (1.0 - 2.0 * (double)j1 / h) * cam->h, (1.0 - 2.0 * (double)j0 / h) * cam->h};
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

/* Sub-blocks [c0, c1] x [r0, r1] (columns, rows). */
typedef struct beam_rect {
    uint8_t c0, c1, r0, r1;
} beam_rect;

typedef struct beam_item {
    uint64_t node;  /* index in its depth */
    uint32_t cell[3];
    unsigned depth;
    double dist;    /* its squared distance when it was pushed */
    beam_rect reach; /* the sub-blocks it may touch */
} beam_item;

typedef struct beam_walk {
    const oct_tree *tree;
    pyramid p;
    double o[3];   /* the eye in grid units (voxels), as the traversal has it */
    double margin; /* voxels added to every half edge */
    unsigned flip;
    /* the sub-blocks' inner boundaries, planes through the eye: column k
     * (1..cols-1) u = ub_k as R - ub_k F, row k v = vb_k as U - vb_k F,
     * with the sums of their absolute components */
    unsigned cols, rows;
    double col_a[BEAM_GRID][3], col_m[BEAM_GRID], row_a[BEAM_GRID][3], row_m[BEAM_GRID];
} beam_walk;

/* Side of the box (centre c relative to the eye, half edge h) against the
 * plane a through the eye: bit 0 when some of it may lie on the negative
 * side, bit 1 on the positive side. */
static unsigned box_side(const double a[3], double m, const double c[3], double h)
{
    const double sd = a[0] * c[0] + a[1] * c[1] + a[2] * c[2], e = h * m;
    return (unsigned)(sd - e <= 0.0) | (unsigned)(sd + e >= 0.0) << 1;
}

/* Narrows *r, the sub-blocks the box's parent may touch, to those whose
 * pyramids the box may touch, assuming it may touch the block's (a box
 * between two sub-blocks' pixel centres keeps one of them). Only the
 * boundaries inside *r are tested. u grows with the column
 * (a column boundary's positive side is to its right); v falls with the row
 * (a row boundary's positive side is above it, towards row 0). */
static void rect_touch(const beam_walk *bw, const double c[3], double h, beam_rect *r)
{
    unsigned c0 = r->c0, c1 = r->c1, r0 = r->r0, r1 = r->r1;
    while (c0 < c1 && !(box_side(bw->col_a[c0 + 1], bw->col_m[c0 + 1], c, h) & 1u))
        c0++; /* wholly right of boundary c0 + 1 */
    while (c1 > c0 && !(box_side(bw->col_a[c1], bw->col_m[c1], c, h) & 2u))
        c1--; /* wholly left of boundary c1 */
    while (r0 < r1 && !(box_side(bw->row_a[r0 + 1], bw->row_m[r0 + 1], c, h) & 2u))
        r0++; /* wholly below boundary r0 + 1 */
    while (r1 > r0 && !(box_side(bw->row_a[r1], bw->row_m[r1], c, h) & 1u))
        r1--; /* wholly above boundary r1 */
    *r = (beam_rect){(uint8_t)c0, (uint8_t)c1, (uint8_t)r0, (uint8_t)r1};
}

/* The bound a cell must beat to be worth opening for the sub-blocks in r:
 * the largest of their nearest distances so far (a nearer cell improves at
 * least one of them). */
static inline double rect_bound(const double (*best)[BEAM_GRID], beam_rect r)
{
    if (r.c0 == r.c1 && r.r0 == r.r1) /* deep cells reach one sub-block */
        return best[r.r0][r.c0];
    double b = -INFINITY;
    for (unsigned y = r.r0; y <= r.r1; y++)
        for (unsigned x = r.c0; x <= r.c1; x++)
            b = best[y][x] > b ? best[y][x] : b;
    return b;
}

/* For every sub-block in `all`, the squared distance from the eye to the
 * nearest voxel its pyramid may touch, into best (+inf beforehand, and
 * where there is none). One walk serves them all: children nearest the eye
 * first, and a cell opened only while it may touch some sub-block whose
 * distance it could still beat: a best-first search along the front of the
 * surface, not a sweep of the pyramid, with the way down to the surface
 * shared and only the last levels parting. Squared distances order as the
 * distances do, without a square root a cell. */
static void beam_nearest(const beam_walk *bw, beam_rect all, double (*best)[BEAM_GRID])
{
    const oct_tree *tree = bw->tree;
    const unsigned levels = tree->levels;
    const double *o = bw->o;
    beam_item stack[8 * OCT_MAX_LEVELS + 1];
    unsigned sp = 0;
    stack[sp++] = (beam_item){0, {0, 0, 0}, 0, 0.0, all};
    while (sp) {
        const beam_item it = stack[--sp];
        const double it_bound = rect_bound(best, it.reach);
        if (it.dist >= it_bound)
            continue; /* the distances improved since it was pushed */
        const oct_group *g = &tree->groups[it.depth][it.node >> 3];
        const unsigned mask = g->mask[it.node & 7u];
        const double s = (double)(UINT32_C(1) << (levels - it.depth - 1)); /* child edge */
        const double h = 0.5 * s + bw->margin;
        /* pushed in reverse order: the child to look at first is popped first */
        for (int k = 7; k >= 0; k--) {
            const unsigned c = (unsigned)k ^ bw->flip;
            if (!(mask >> c & 1u))
                continue;
            uint32_t cell[3];
            double ctr[3], d2 = 0.0;
            for (int i = 0; i < 3; i++) {
                cell[i] = 2u * it.cell[i] + (c >> i & 1u);
                ctr[i] = ((double)cell[i] + 0.5) * s - o[i]; /* one rounding */
                const double e = fabs(ctr[i]) - h;
                if (e > 0.0)
                    d2 += e * e;
            }
            if (d2 >= it_bound || !pyramid_may_touch(&bw->p, ctr, h))
                continue;
            beam_rect reach = it.reach;
            if (reach.c0 != reach.c1 || reach.r0 != reach.r1) {
                rect_touch(bw, ctr, h, &reach);
                if (d2 >= rect_bound(best, reach))
                    continue;
            }
            if (it.depth + 1 == levels) {
                for (unsigned y = reach.r0; y <= reach.r1; y++)
                    for (unsigned x = reach.c0; x <= reach.c1; x++)
                        best[y][x] = d2 < best[y][x] ? d2 : best[y][x];
                continue;
            }
            stack[sp++] = (beam_item){oct_child_index(tree->groups[it.depth], it.node, c),
                                      {cell[0], cell[1], cell[2]}, it.depth + 1, d2, reach};
        }
    }
}

/* How far the camera's basis is from orthonormal, for the block's (u, v):
 * the pyramid's planes and beam_start_box take F, R, U orthonormal, but
 * camera_init's right, normalise(F x up), leaves F by up to about 1e-7 when
 * up lies within a sine of 1e-9 of F (which it accepts). With e the largest
 * of |F.R|, |F.U|, |R.U| and ||X|^2 - 1|, w = F + uR + vU meets each plane,
 * and |w|^2 meets 1 + u^2 + v^2, within 4 e (1 + |u| + |v|)^2 of the
 * orthonormal values (relative to |w|). */
static double basis_slack(const camera *cam, double umax, double vmax)
{
    const double *F = cam->forward, *R = cam->right, *U = cam->up;
    const double d[6] = {F[0] * R[0] + F[1] * R[1] + F[2] * R[2],
                         F[0] * U[0] + F[1] * U[1] + F[2] * U[2],
                         R[0] * U[0] + R[1] * U[1] + R[2] * U[2],
                         F[0] * F[0] + F[1] * F[1] + F[2] * F[2] - 1.0,
                         R[0] * R[0] + R[1] * R[1] + R[2] * R[2] - 1.0,
                         U[0] * U[0] + U[1] * U[1] + U[2] * U[2] - 1.0};
    double e = 0x1p-50; /* the rounding of these sums themselves */
    for (int k = 0; k < 6; k++)
        e = fmax(e, fabs(d[k]));
    const double g = 1.0 + umax + vmax;
    return 4.0 * e * g * g;
}

/* Grid distance -> the caller's t (unit directions), widened downward by a
 * relative 2^-40 for the division and a direction's length of 1 +- ulps. */
static double t_down(double dist, double scale) { return dist / scale * (1.0 - 0x1p-40); }

/* The plane through the eye where q.X / q.F = at (X = R for u, U for v):
 * normal X - at F, and the sum of its absolute components. */
static void boundary_plane(const double X[3], const double F[3], double at, double a[3], double *m)
{
    *m = 0.0;
    for (int i = 0; i < 3; i++) {
        a[i] = X[i] - at * F[i];
        *m += fabs(a[i]);
    }
}

/* Sub-block boundaries: `n` near-equal parts of [a, b). */
static unsigned grid_split(uint32_t a, uint32_t b, uint32_t *at)
{
    const uint32_t w = b - a;
    const unsigned n = w < BEAM_GRID ? (unsigned)w : BEAM_GRID;
    for (unsigned k = 0; k <= n; k++)
        at[k] = a + (uint32_t)((uint64_t)w * k / n);
    return n;
}

int beam_starts(const oct_tree *tree, const camera *cam, uint32_t i0, uint32_t i1, uint32_t j0,
                uint32_t j1, beam_grid *grid)
{
    const unsigned levels = tree->levels;
    grid->cols = grid_split(i0, i1, grid->col);
    grid->rows = grid_split(j0, j1, grid->row);
    if (tree->node_count[0] == 0 || levels < 1 || levels > OCT_MAX_LEVELS)
        return 0;
    beam_walk bw;
    bw.tree = tree;
    const beam_block b = beam_block_of(cam, i0, i1, j0, j1);
    pyramid_init(&bw.p, cam, &b);
    /* Boundaries halfway between the pixel centres either side: no ray lies
     * on one. */
    const double *F = cam->forward, *R = cam->right, *U = cam->up;
    bw.cols = grid->cols;
    bw.rows = grid->rows;
    for (unsigned k = 1; k < bw.cols; k++)
        boundary_plane(R, F, 0.5 * (camera_u(cam, grid->col[k] - 1) + camera_u(cam, grid->col[k])),
                       bw.col_a[k], &bw.col_m[k]);
    for (unsigned k = 1; k < bw.rows; k++)
        boundary_plane(U, F, 0.5 * (camera_v(cam, grid->row[k] - 1) + camera_v(cam, grid->row[k])),
                       bw.row_a[k], &bw.row_m[k]);
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
    /* ... plus what a basis off orthonormal can move a ray off a plane at
     * any distance in the walk (below |o| + sqrt(3) N) */
    const double slack =
        basis_slack(cam, fmax(fabs(b.u0), fabs(b.u1)), fmax(fabs(b.v0), fabs(b.v1)));
    bw.margin = 0x1p-12 + big * 0x1p-40 + slack * 2.0 * (2.0 * big + 2.0 * n);
    double best[BEAM_GRID][BEAM_GRID];
    for (unsigned r = 0; r < BEAM_GRID; r++)
        for (unsigned c = 0; c < BEAM_GRID; c++)
            best[r][c] = INFINITY;
    beam_nearest(&bw, (beam_rect){0, (uint8_t)(bw.cols - 1), 0, (uint8_t)(bw.rows - 1)}, best);
    int any = 0;
    for (unsigned r = 0; r < bw.rows; r++)
        for (unsigned c = 0; c < bw.cols; c++) {
            const double lo = best[r][c];
            grid->t_lo[r][c] = lo < INFINITY ? t_down(sqrt(lo), scale) : INFINITY;
            any |= lo < INFINITY;
        }
    return any;
}

void beam_start_box(const camera *cam, const double o[3], double scale, uint32_t i0, uint32_t i1,
                    uint32_t j0, uint32_t j1, double t, double lo[3], double hi[3])
{
    beam_start_box_uv(cam, o, scale, camera_u(cam, i0), camera_u(cam, i1 - 1), camera_v(cam, j1 - 1),
                      camera_v(cam, j0), t, lo, hi);
}

void beam_start_box_uv(const camera *cam, const double o[3], double scale, double u0, double u1,
                       double v0, double v1, double t, double lo[3], double hi[3])
{
    /* A ray's unit direction is w / |w|, w = F + uR + vU, with |w|^2 =
     * 1 + u^2 + v^2 within basis_slack; w lies in the hull of the four
     * corner pixels' w and |w| between its least and greatest over the
     * block, so the point lies in the hull of the corners' w scaled by t
     * over both extremes of |w|. */
    const double u[2] = {u0, u1};
    const double v[2] = {v0, v1};
    const double u_in = u[0] <= 0.0 && u[1] >= 0.0 ? 0.0 : fmin(u[0] * u[0], u[1] * u[1]);
    const double v_in = v[0] <= 0.0 && v[1] >= 0.0 ? 0.0 : fmin(v[0] * v[0], v[1] * v[1]);
    const double u_out = fmax(u[0] * u[0], u[1] * u[1]), v_out = fmax(v[0] * v[0], v[1] * v[1]);
    const double slack = basis_slack(cam, sqrt(u_out), sqrt(v_out));
    const double w_in = sqrt(fmax(1.0 + u_in + v_in - slack, 0x1p-60)) * (1.0 - 0x1p-40);
    const double w_out = sqrt(1.0 + u_out + v_out + slack) * (1.0 + 0x1p-40);
    const double s[2] = {t * scale / w_out, t * scale / w_in};
    double big = 0.0;
    for (int i = 0; i < 3; i++) {
        lo[i] = INFINITY;
        hi[i] = -INFINITY;
        big = fmax(big, fabs(o[i]));
    }
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++)
            for (int i = 0; i < 3; i++) {
                const double w = cam->forward[i] + u[a] * cam->right[i] + v[b] * cam->up[i];
                for (int k = 0; k < 2; k++) {
                    const double p = o[i] + s[k] * w;
                    lo[i] = fmin(lo[i], p);
                    hi[i] = fmax(hi[i], p);
                }
            }
    /* 2^-10 voxel plus 2^-36 of the magnitudes involved */
    const double margin = 0x1p-10 + (big + s[1] * 2.0) * 0x1p-36;
    for (int i = 0; i < 3; i++) {
        lo[i] -= margin;
        hi[i] += margin;
    }
}
