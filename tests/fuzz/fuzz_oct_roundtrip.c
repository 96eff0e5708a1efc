/* fuzz_oct_roundtrip: bytes -> a voxel set -> the streaming writer -> the
 * reader; what is read back must be exactly what was written, as a 1.0
 * file or as 1.1 (a function, shell-only, shard fields). */
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

/* A minimal FUNCTION section: `count` tapes of one instruction, X (8 bytes
 * of head, then 16 of tape head, 12 of instruction, 4 of padding each). */
static size_t tiny_function(unsigned char *p, uint32_t count)
{
    memset(p, 0, 8 + 32 * (size_t)count);
    memcpy(p, &count, 4);
    for (uint32_t s = 0; s < count; s++) {
        const uint32_t head[3] = {1, 0, 0}, x[3] = {OCT_OP_X, 0, 0};
        memcpy(p + 8 + 32 * s, head, sizeof head);
        memcpy(p + 8 + 32 * s + 16, x, sizeof x);
    }
    return 8 + 32 * (size_t)count;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    /* data[0]: levels 1..12; data[1]: surfaces 1..4 (bits 0-1) and the
     * format (bits 2-3: 1.0, 1.1 with a function, shell-only, a shard);
     * then 4 bytes a voxel: 3 of Morton code (wrapped into the grid), 1 of
     * record and surface. */
    const unsigned mode = (data[1] >> 2) & 3u;
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

    unsigned char fn[8 + 32 * 4];
    oct_writer_params v11 = {0};
    if (mode == 1 || mode == 2) {
        v11.function = fn;
        v11.function_size = tiny_function(fn, t.surface_count);
        v11.flags = mode == 2 ? OCT_FLAG_SHELL_ONLY : 0;
    } else if (mode == 3) { /* shard 1 of 2 of the depth-1 cells */
        v11.shard_count = 2;
        v11.shard_index = 1;
        v11.shard_depth = 1;
        v11.morton_lo = 4;
        v11.morton_hi = 8;
    }
    unsigned char *buf;
    size_t len;
    if (test_tree_write_1_1(&t, &v11, &buf, &len) != OCT_OK)
        abort();
    oct_file *f;
    if (oct_open_memory(buf, len, 0, &f, NULL) != OCT_OK)
        abort();
    const oct_tree *ft = oct_get_tree(f);
    const oct_info *in = oct_get_info(f);
    const oct_function_tape *ftapes = oct_get_function(f);
    if (in->version_minor != (mode ? 1 : 0) || (ftapes != NULL) != (mode == 1 || mode == 2) ||
        in->flags != v11.flags || in->shard_count != v11.shard_count ||
        in->morton_lo != v11.morton_lo || in->morton_hi != v11.morton_hi)
        abort();
    for (uint32_t s = 0; ftapes && s < t.surface_count; s++)
        if (ftapes[s].insn_count != 1 || ftapes[s].insn[0] != OCT_OP_X)
            abort();
    if (ft->levels != t.levels || ft->voxel_count != m)
        abort();
    for (uint32_t d = 0; d < t.levels; d++) {
        if (ft->node_count[d] != t.count[d])
            abort();
        for (size_t i = 0; i < t.count[d]; i++)
            if (oct_node_mask(ft->groups[d], i) != t.masks[d][i])
                abort();
    }
    if (mode == 2 ? ft->voxels != NULL : m && memcmp(ft->voxels, t.voxels, 4 * m) != 0)
        abort();
    if (t.surface_count > 1 && m && memcmp(ft->surfaces, t.surfaces, m) != 0)
        abort();
    oct_close(f);
    free(buf);
    test_tree_free(&t);
    return 0;
}
