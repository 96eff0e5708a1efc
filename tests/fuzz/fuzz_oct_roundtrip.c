/* fuzz_oct_roundtrip: bytes -> a voxel set -> the streaming writer -> the
 * reader; what is read back must be exactly what was written. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "format/oct.h"
#include "bench/oct_synth.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    /* data[0]: levels 1..12; data[1]: surfaces 1..4; then 4 bytes a voxel:
     * 3 of Morton code (wrapped into the grid), 1 of record and surface. */
    test_tree t;
    memset(&t, 0, sizeof t);
    t.levels = 1u + data[0] % 12u;
    t.surface_count = 1u + data[1] % 4u;
    t.edge = 1.0;
    size_t n = (size - 2) / 4;
    if (n > 4096)
        n = 4096;
    t.codes = malloc((n ? n : 1) * sizeof *t.codes);
    t.voxels = malloc((n ? n : 1) * sizeof *t.voxels);
    t.surfaces = malloc(n ? n : 1);
    if (!t.codes || !t.voxels || !t.surfaces)
        abort();
    uint64_t cells_mask = t.levels >= 8 ? UINT64_C(0xffffff) : (UINT64_C(1) << (3 * t.levels)) - 1;
    for (size_t i = 0; i < n; i++) {
        const uint8_t *r = data + 2 + 4 * i;
        uint64_t c = (uint64_t)r[0] | (uint64_t)r[1] << 8 | (uint64_t)r[2] << 16;
        if (t.levels > 8)
            c <<= 3 * (t.levels - 8); /* spread over the bigger grid */
        t.codes[i] = c & (cells_mask << (t.levels > 8 ? 3 * (t.levels - 8) : 0));
    }
    qsort(t.codes, n, sizeof *t.codes, cmp_u64);
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (m == 0 || t.codes[m - 1] != t.codes[i])
            t.codes[m++] = t.codes[i];
    t.voxel_count = m;
    for (size_t i = 0; i < m; i++) {
        uint8_t b = data[2 + 4 * i + 3];
        uint32_t off = b == 0x80 ? 0x7f : b; /* -128 is reserved */
        t.voxels[i] = (uint32_t)(t.codes[i] * 2654435761u & 0xffffffu) | off << 24;
        t.surfaces[i] = (uint8_t)(b % t.surface_count);
    }
    for (uint32_t i = 0; i < 3 * t.surface_count; i++)
        t.palette[i] = (float)i / (float)(3 * t.surface_count);
    test_tree_build_masks(&t);

    unsigned char *buf;
    size_t len;
    if (test_tree_write(&t, &buf, &len) != OCT_OK)
        abort();
    oct_file *f;
    if (oct_open_memory(buf, len, 0, &f, NULL) != OCT_OK)
        abort();
    const oct_tree *ft = oct_get_tree(f);
    if (ft->levels != t.levels || ft->voxel_count != m)
        abort();
    for (uint32_t d = 0; d < t.levels; d++) {
        if (ft->node_count[d] != t.count[d])
            abort();
        for (size_t i = 0; i < t.count[d]; i++)
            if (oct_node_mask(ft->groups[d], i) != t.masks[d][i])
                abort();
    }
    if (m && memcmp(ft->voxels, t.voxels, 4 * m) != 0)
        abort();
    if (t.surface_count > 1 && m && memcmp(ft->surfaces, t.surfaces, m) != 0)
        abort();
    oct_close(f);
    free(buf);
    test_tree_free(&t);
    return 0;
}
