/* tree_util: in-memory oct_tree builder for tests and benchmarks. */
#include "bench/tree_util.h"

#include "bench/rng.h"

#include <stdlib.h>
#include <string.h>

typedef struct owned_tree {
    oct_tree t; /* first: the public view */
    oct_group *groups[OCT_MAX_LEVELS];
    uint32_t *voxels;
    uint8_t *surfaces;
    float *palette;
} owned_tree;

typedef struct keyed {
    uint64_t code;
    size_t index;
} keyed;

uint64_t tree_util_morton(uint32_t x, uint32_t y, uint32_t z)
{
    uint64_t m = 0;
    for (unsigned i = 0; i < 21; i++) {
        m |= (uint64_t)((x >> i) & 1u) << (3 * i);
        m |= (uint64_t)((y >> i) & 1u) << (3 * i + 1);
        m |= (uint64_t)((z >> i) & 1u) << (3 * i + 2);
    }
    return m;
}

static int cmp_keyed(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    if (a->code != b->code)
        return a->code < b->code ? -1 : 1;
    return a->index < b->index ? -1 : a->index > b->index; /* stable: first wins */
}

void tree_util_free(oct_tree *t)
{
    owned_tree *o = (owned_tree *)t;
    if (!o)
        return;
    for (unsigned d = 0; d < OCT_MAX_LEVELS; d++)
        free(o->groups[d]);
    free(o->voxels);
    free(o->surfaces);
    free(o->palette);
    free(o);
}

oct_tree *tree_util_build(unsigned levels, const double origin[3], double edge,
                          const uint32_t (*xyz)[3], size_t n, const uint32_t *attrs,
                          const uint8_t *surfaces, unsigned surface_count, const float *palette)
{
    if (levels < 1 || levels > OCT_MAX_LEVELS || surface_count < 1 ||
        surface_count > OCT_MAX_SURFACES || !(edge > 0))
        return NULL;
    owned_tree *o = calloc(1, sizeof *o);
    keyed *keys = calloc(n ? n : 1, sizeof *keys);
    if (!o || !keys)
        goto fail;
    o->t.levels = levels;
    memcpy(o->t.origin, origin, sizeof o->t.origin);
    o->t.edge = edge;
    o->t.surface_count = surface_count;
    o->palette = malloc(3 * sizeof(float) * surface_count);
    if (!o->palette)
        goto fail;
    for (unsigned i = 0; i < 3 * surface_count; i++)
        o->palette[i] = palette ? palette[i] : 0.8f;
    o->t.palette = o->palette;

    const uint32_t lim = UINT32_C(1) << levels;
    for (size_t i = 0; i < n; i++) {
        if (xyz[i][0] >= lim || xyz[i][1] >= lim || xyz[i][2] >= lim)
            goto fail;
        keys[i].code = tree_util_morton(xyz[i][0], xyz[i][1], xyz[i][2]);
        keys[i].index = i;
    }
    qsort(keys, n, sizeof *keys, cmp_keyed);
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (m == 0 || keys[i].code != keys[m - 1].code)
            keys[m++] = keys[i];
    o->t.voxel_count = m;
    o->voxels = calloc(m ? m : 1, sizeof *o->voxels);
    if (surface_count > 1)
        o->surfaces = calloc(m ? m : 1, 1);
    if (!o->voxels || (surface_count > 1 && !o->surfaces))
        goto fail;
    for (size_t i = 0; i < m; i++) {
        o->voxels[i] = attrs ? attrs[keys[i].index] : 0;
        if (o->surfaces)
            o->surfaces[i] = surfaces ? surfaces[keys[i].index] : 0;
    }
    o->t.voxels = o->voxels;
    o->t.surfaces = o->surfaces;

    /* Per depth d, a node is a unique prefix code >> 3(L-d) of the sorted
     * voxel codes, its child slot the next three bits. Nodes come out in
     * Morton order, children within a parent in increasing slot: the
     * breadth-first order of oct.h. Bases are running popcount sums. */
    for (unsigned dd = 0; dd < levels; dd++) {
        const unsigned shift = 3 * (levels - 1 - dd); /* child key = code >> shift */
        size_t count = 0;
        for (size_t i = 0; i < m; i++)
            if (i == 0 || (keys[i].code >> (shift + 3)) != (keys[i - 1].code >> (shift + 3)))
                count++;
        o->t.node_count[dd] = count;
        size_t ng = (count + 7) / 8;
        o->groups[dd] = calloc(ng ? ng : 1, sizeof(oct_group));
        if (!o->groups[dd])
            goto fail;
        size_t node = 0;
        for (size_t i = 0; i < m; i++) {
            if (i > 0 && (keys[i].code >> (shift + 3)) != (keys[i - 1].code >> (shift + 3)))
                node++;
            o->groups[dd][node >> 3].mask[node & 7] |= (uint8_t)(1u << ((keys[i].code >> shift) & 7u));
        }
        uint64_t total = 0;
        for (size_t g = 0; g < ng; g++) {
            o->groups[dd][g].base = total;
            for (unsigned k = 0; k < 8; k++)
                total += (unsigned)__builtin_popcount(o->groups[dd][g].mask[k]);
        }
        o->t.groups[dd] = o->groups[dd];
    }
    free(keys);
    return &o->t;
fail:
    free(keys);
    tree_util_free(o ? &o->t : NULL);
    return NULL;
}

oct_tree *tree_util_simple(unsigned levels, const uint32_t (*xyz)[3], size_t n)
{
    static const double origin[3] = {0, 0, 0};
    return tree_util_build(levels, origin, 1.0, xyz, n, NULL, NULL, 1, NULL);
}

size_t tree_util_distinct_voxels(size_t n, uint32_t lo, uint32_t width, uint64_t *rng_state,
                                 uint32_t (*xyz)[3])
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t v[3];
        for (int a = 0; a < 3; a++)
            v[a] = lo + (uint32_t)(rng_xorshift64star(rng_state) % width);
        int dup = 0;
        for (size_t j = 0; j < m && !dup; j++)
            dup = !memcmp(xyz[j], v, sizeof v);
        if (!dup)
            memcpy(xyz[m++], v, sizeof v);
    }
    return m;
}
