/* voxel_shapes: analytic shapes to trees (see voxel_shapes.h). */
#include "tests/voxel_shapes.h"

#include <math.h>
#include <stdlib.h>

#include "bench/tree_util.h"
#include "format/oct_normal.h"

shape shape_plane(double nx, double ny, double nz, double d)
{
    shape s = {0};
    const double len = sqrt(nx * nx + ny * ny + nz * nz);
    s.kind = SHAPE_PLANE;
    s.n[0] = nx / len;
    s.n[1] = ny / len;
    s.n[2] = nz / len;
    s.d = d / len;
    for (int a = 0; a < 3; a++) {
        s.lo[a] = -INFINITY;
        s.hi[a] = INFINITY;
    }
    return s;
}

shape shape_sphere(double cx, double cy, double cz, double r)
{
    shape s = shape_plane(0, 0, 1, 0);
    s.kind = SHAPE_SPHERE;
    s.c[0] = cx;
    s.c[1] = cy;
    s.c[2] = cz;
    s.r = r;
    return s;
}

/* 1 when the unit voxel at corner v meets shape s, with its normal and the
 * offset of its tangent plane from the voxel's centre. */
static int meets(const shape *s, const double p[3], double n[3], double *off)
{
    for (int a = 0; a < 3; a++)
        if (!(p[a] >= s->lo[a] && p[a] <= s->hi[a]))
            return 0;
    if (s->kind == SHAPE_PLANE) {
        const double dist = s->n[0] * p[0] + s->n[1] * p[1] + s->n[2] * p[2] - s->d;
        const double half = 0.5 * (fabs(s->n[0]) + fabs(s->n[1]) + fabs(s->n[2]));
        for (int a = 0; a < 3; a++)
            n[a] = s->n[a];
        *off = -dist;
        return fabs(dist) <= half;
    }
    double q[3], dn = 0.0, lo2 = 0.0, hi2 = 0.0;
    for (int a = 0; a < 3; a++) {
        q[a] = p[a] - s->c[a];
        dn += q[a] * q[a];
        /* nearest and farthest points of the voxel box from the centre */
        const double e = fabs(q[a]), near = e > 0.5 ? e - 0.5 : 0.0, far = e + 0.5;
        lo2 += near * near;
        hi2 += far * far;
    }
    dn = sqrt(dn);
    if (!(dn > 0.0))
        return 0;
    for (int a = 0; a < 3; a++)
        n[a] = q[a] / dn;
    *off = s->r - dn;
    return lo2 <= s->r * s->r && s->r * s->r <= hi2; /* the box straddles the sphere */
}

/* Doubles the three arrays; 0 when out of memory (what did grow is kept). */
static int grow(uint32_t (**xyz)[3], uint32_t **attr, uint8_t **surf, size_t *cap)
{
    const size_t nc = 2 * *cap;
    void *a = realloc(*xyz, nc * sizeof **xyz);
    if (!a)
        return 0;
    *xyz = a;
    void *b = realloc(*attr, nc * sizeof **attr);
    if (!b)
        return 0;
    *attr = b;
    void *c = realloc(*surf, nc);
    if (!c)
        return 0;
    *surf = c;
    *cap = nc;
    return 1;
}

oct_tree *shapes_build(unsigned levels, double edge, const shape *shapes, unsigned count,
                       unsigned surface_count)
{
    const uint32_t n = UINT32_C(1) << levels;
    size_t cap = 1 << 16, cnt = 0;
    uint32_t(*xyz)[3] = malloc(cap * sizeof *xyz);
    uint32_t *attr = malloc(cap * sizeof *attr);
    uint8_t *surf = malloc(cap);
    float *pal = malloc(3 * surface_count * sizeof *pal);
    oct_tree *t = NULL;
    if (!xyz || !attr || !surf || !pal)
        goto done;
    for (unsigned k = 0; k < 3 * surface_count; k++)
        pal[k] = 1.0f;
    /* shape by shape (the first to claim a voxel keeps it: tree_util_build
       keeps the first duplicate); a sphere only near its shell */
    for (unsigned k = 0; k < count; k++)
        for (uint32_t y = 0; y < n; y++)
            for (uint32_t x = 0; x < n; x++) {
                uint32_t zr[2][2] = {{0, n}, {n, n}}; /* z ranges [lo, hi) to look at */
                const shape *sk = &shapes[k];
                if (sk->kind == SHAPE_SPHERE) {
                    const double dx = x + 0.5 - sk->c[0], dy = y + 0.5 - sk->c[1];
                    const double out = (sk->r + 1.0) * (sk->r + 1.0) - dx * dx - dy * dy;
                    if (out < 0.0)
                        continue;
                    const double in = sk->r > 1.0 ? (sk->r - 1.0) * (sk->r - 1.0) - dx * dx - dy * dy
                                                  : -1.0;
                    const double zo = sqrt(out), zi = in > 0.0 ? sqrt(in) : 0.0;
                    for (int h = 0; h < 2; h++) {
                        const double a0 = h ? sk->c[2] + zi - 1.0 : sk->c[2] - zo - 1.0;
                        const double a1 = h ? sk->c[2] + zo + 1.0 : sk->c[2] - zi + 1.0;
                        zr[h][0] = a0 < 0.0 ? 0 : a0 >= n ? n : (uint32_t)a0;
                        zr[h][1] = a1 < 0.0 ? 0 : a1 >= n ? n : (uint32_t)a1 + 1;
                        if (zr[h][1] > n)
                            zr[h][1] = n;
                    }
                }
                for (int h = 0; h < 2; h++)
                    for (uint32_t z = zr[h][0]; z < zr[h][1]; z++) {
                        const double p[3] = {x + 0.5, y + 0.5, z + 0.5};
                        double nn[3], off;
                        if (!meets(sk, p, nn, &off))
                            continue;
                        if (cnt == cap && !grow(&xyz, &attr, &surf, &cap))
                            goto done;
                        xyz[cnt][0] = x;
                        xyz[cnt][1] = y;
                        xyz[cnt][2] = z;
                        attr[cnt] = oct_voxel_pack(nn, off);
                        surf[cnt++] = sk->surface;
                    }
            }
    const double origin[3] = {0, 0, 0};
    t = tree_util_build(levels, origin, edge, (const uint32_t(*)[3])xyz, cnt, attr,
                        surface_count > 1 ? surf : NULL, surface_count, pal);
done:
    free(xyz);
    free(attr);
    free(surf);
    free(pal);
    return t;
}
