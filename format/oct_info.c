/* oct_info: the human summary of an opened file that `render --info` prints. */
#include "format/oct.h"

#include <stdio.h>

/* The function line: how many tapes, instructions and constants. */
static void print_function(FILE *out, const oct_file *f)
{
    const oct_function_tape *fn = oct_get_function(f);
    if (!fn) {
        fprintf(out, "function:    none\n");
        return;
    }
    const uint32_t ns = oct_get_tree(f)->surface_count;
    uint64_t insns = 0, consts = 0;
    for (uint32_t s = 0; s < ns; s++) {
        insns += fn[s].insn_count;
        consts += fn[s].const_count;
    }
    fprintf(out, "function:    %u tape%s, %llu instructions, %llu constants (%llu bytes)\n", ns,
            ns == 1 ? "" : "s", (unsigned long long)insns, (unsigned long long)consts,
            (unsigned long long)oct_get_info(f)->function_size);
}

int oct_print_info(void *out_file, const oct_file *f)
{
    FILE *out = out_file;
    const oct_tree *t = oct_get_tree(f);
    const oct_info *in = oct_get_info(f);
    fprintf(out, "format:      .oct %u.%u\n", in->version_major, in->version_minor);
    if (in->flags & OCT_FLAG_SHELL_ONLY)
        fprintf(out, "flags:       shell-only (no normals or planes: render --exact)\n");
    else
        fprintf(out, "flags:       none\n");
    fprintf(out, "levels:      %u (%llu voxels a side)\n", t->levels,
            (unsigned long long)(UINT64_C(1) << t->levels));
    fprintf(out, "cube:        origin (%.17g, %.17g, %.17g), edge %.17g\n", t->origin[0], t->origin[1],
            t->origin[2], t->edge);
    if (in->root_depth > 0)
        fprintf(out, "subtree:     depth %u, cell (%llu, %llu, %llu) of the grid at (%.17g, %.17g, %.17g), edge %.17g\n",
                in->root_depth, (unsigned long long)in->root_cell[0],
                (unsigned long long)in->root_cell[1], (unsigned long long)in->root_cell[2],
                in->grid_origin[0], in->grid_origin[1], in->grid_origin[2], in->grid_edge);
    if (in->shard_count > 0)
        fprintf(out, "shard:       %u of %u (0-based), cells of depth %u, Morton codes [%llu, %llu), "
                     "partition crc 0x%08x\n",
                in->shard_index, in->shard_count, in->shard_depth, (unsigned long long)in->morton_lo,
                (unsigned long long)in->morton_hi, in->partition_crc);
    fprintf(out, "nodes:       %llu\n", (unsigned long long)in->total_nodes);
    for (uint32_t d = 0; d < t->levels; d++)
        fprintf(out, "  depth %2u:  %llu\n", d, (unsigned long long)t->node_count[d]);
    fprintf(out, "voxels:      %llu\n", (unsigned long long)t->voxel_count);
    fprintf(out, "surfaces:    %u\n", t->surface_count);
    print_function(out, f);
    fprintf(out, "file bytes:  %llu\n", (unsigned long long)in->file_size);
    if (t->voxel_count)
        fprintf(out, "bytes/voxel: %.3f\n", (double)in->file_size / (double)t->voxel_count);
    else
        fprintf(out, "bytes/voxel: - (no voxels)\n");
    return ferror(out) ? -1 : 0;
}
