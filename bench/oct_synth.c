/* oct_synth: random sparse voxel trees and writer round trips for tests and benchmarks. */
#include "bench/oct_synth.h"

#include "format/oct_layout.h"
#include "format/oct_normal.h"
#include "bench/rng.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <zlib.h>

uint64_t test_rand(uint64_t *s)
{
    if (!*s)
        *s = 0x9e3779b97f4a7c15u;
    return rng_xorshift64star(s);
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        abort();
    return p;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

void test_tree_build_masks(test_tree *t)
{
    const uint32_t L = t->levels;
    for (uint32_t d = 0; d < L; d++) {
        free(t->masks[d]);
        t->masks[d] = xmalloc(t->voxel_count + 1);
        t->count[d] = 0;
        unsigned shift = 3 * (L - d); /* node id at depth d = code >> shift */
        for (size_t i = 0; i < t->voxel_count; i++) {
            uint64_t node = shift >= 64 ? 0 : t->codes[i] >> shift;
            unsigned child = (unsigned)(t->codes[i] >> (shift - 3)) & 7;
            if (i == 0 || (shift >= 64 ? 0 : t->codes[i - 1] >> shift) != node)
                t->masks[d][t->count[d]++] = 0;
            t->masks[d][t->count[d] - 1] |= (uint8_t)(1u << child);
        }
    }
}

void test_tree_random(test_tree *t, uint32_t levels, size_t target, uint32_t surface_count,
                      uint64_t seed, int clustered)
{
    memset(t, 0, sizeof *t);
    uint64_t rs = seed * 2654435761u + 1;
    t->levels = levels;
    t->surface_count = surface_count;
    t->edge = 2.0;
    t->origin[0] = -1.0;
    t->origin[1] = -0.5;
    t->origin[2] = 3.25;
    uint64_t cells = UINT64_C(1) << (3 * levels);
    if (target > cells)
        target = (size_t)cells;
    uint64_t *codes = xmalloc(target * sizeof *codes);
    uint64_t cur = test_rand(&rs) & (cells - 1);
    for (size_t i = 0; i < target; i++) {
        if (clustered && (test_rand(&rs) % 16) != 0)
            cur = (cur + 1 + test_rand(&rs) % 3) & (cells - 1); /* nearby in Morton order */
        else
            cur = test_rand(&rs) & (cells - 1);
        codes[i] = cur;
    }
    qsort(codes, target, sizeof *codes, cmp_u64);
    size_t n = 0;
    for (size_t i = 0; i < target; i++)
        if (n == 0 || codes[n - 1] != codes[i])
            codes[n++] = codes[i];
    t->codes = codes;
    t->voxel_count = n;
    t->voxels = xmalloc(n * sizeof *t->voxels);
    t->surfaces = xmalloc(n);
    for (size_t i = 0; i < n; i++) {
        double v[3];
        for (int k = 0; k < 3; k++)
            v[k] = (double)(test_rand(&rs) % 2001) / 1000.0 - 1.0;
        double off = (double)(int)(test_rand(&rs) % 201 - 100) / 100.0;
        t->voxels[i] = oct_voxel_pack(v, off);
        t->surfaces[i] = (uint8_t)(test_rand(&rs) % surface_count);
    }
    for (uint32_t i = 0; i < 3 * surface_count; i++)
        t->palette[i] = (float)(test_rand(&rs) % 1001) / 1000.0f;
    test_tree_build_masks(t);
}

void test_tree_free(test_tree *t)
{
    free(t->codes);
    free(t->voxels);
    free(t->surfaces);
    for (int d = 0; d < OCT_MAX_LEVELS; d++)
        free(t->masks[d]);
    memset(t, 0, sizeof *t);
}

oct_err test_tree_write(const test_tree *t, unsigned char **buf, size_t *len)
{
    oct_writer_params none = {0};
    return test_tree_write_1_1(t, &none, buf, len);
}

oct_err test_tree_write_1_1(const test_tree *t, const oct_writer_params *v11, unsigned char **buf,
                            size_t *len)
{
    oct_writer_params p = *v11; /* flags, shard fields, function */
    p.levels = t->levels;
    memcpy(p.origin, t->origin, sizeof p.origin);
    p.edge = t->edge;
    p.root_depth = t->root_depth;
    memcpy(p.root_cell, t->root_cell, sizeof p.root_cell);
    p.surface_count = t->surface_count;
    p.palette = t->palette;
    oct_writer *w = NULL;
    *buf = NULL;
    *len = 0;
    oct_err rc = oct_writer_create(&p, &w);
    if (rc != OCT_OK)
        return rc;
    uint64_t rs = t->voxel_count * 31 + t->levels;
    for (int d = (int)t->levels - 1; d >= 0 && rc == OCT_OK; d--) { /* any depth order works */
        size_t i = 0;
        while (i < t->count[d] && rc == OCT_OK) {
            size_t n = 1 + (size_t)(test_rand(&rs) % 97);
            if (n > t->count[d] - i)
                n = t->count[d] - i;
            rc = oct_writer_add_masks(w, (unsigned)d, t->masks[d] + i, n);
            i += n;
        }
    }
    for (size_t i = 0; i < t->voxel_count && rc == OCT_OK;) {
        size_t n = 1 + (size_t)(test_rand(&rs) % 1000);
        if (n > t->voxel_count - i)
            n = t->voxel_count - i;
        rc = oct_writer_add_voxels(w, t->voxels + i, t->surfaces + i, n);
        i += n;
    }
    char *mem = NULL;
    size_t memlen = 0;
    FILE *f = open_memstream(&mem, &memlen);
    if (!f)
        abort();
    uint64_t written = 0;
    if (rc == OCT_OK)
        rc = oct_writer_finish(w, f, &written);
    oct_writer_free(w);
    fclose(f);
    if (rc == OCT_OK && written != memlen)
        abort();
    *buf = (unsigned char *)mem;
    *len = memlen;
    return rc;
}

void test_oct_refresh_crcs(unsigned char *buf, size_t len)
{
    if (len < OCT_HEADER_SIZE)
        return;
    /* a 1.0 file has five section entries, later minors six */
    const int nsec = rd_u16le(buf + OCT_OFF_MINOR) == 0 ? OCT_SEC_COUNT_1_0 : OCT_SEC_COUNT;
    for (int k = 0; k < nsec; k++) {
        unsigned char *e = buf + OCT_SEC_OFF(k);
        uint64_t off = rd_u64le(e), size = rd_u64le(e + 8);
        if (off > len || size > len - off)
            continue;
        wr_u32le(e + 16, (uint32_t)crc32_z(0, size ? buf + off : NULL, (size_t)size));
    }
    uint32_t hsize = rd_u32le(buf + OCT_OFF_HEADER_SIZE);
    if (hsize < 4 || hsize > len)
        hsize = OCT_HEADER_SIZE;
    wr_u32le(buf + hsize - 4, (uint32_t)crc32_z(0, buf, hsize - 4));
}
