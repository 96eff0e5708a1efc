/* fuzz_oct: the .oct reader on arbitrary bytes; whatever it accepts must be
 * walkable through oct_child_index without leaving the mapped data, and its
 * stored function (format 1.1) must decode into tapes that evaluate. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "common/expr/tape_io.h"
#include "format/oct.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

volatile uint64_t fuzz_oct_sink; /* keeps the walk's voxel reads */

static uint64_t walk(const oct_tree *t)
{
    uint64_t sum = 0;
    for (uint32_t d = 0; d < t->levels; d++) {
        for (uint64_t i = 0; i < t->node_count[d]; i++) {
            uint8_t m = oct_node_mask(t->groups[d], i);
            if (m == 0)
                abort();
            for (unsigned c = 0; c < 8; c++) {
                if (!(m & (1u << c)))
                    continue;
                uint64_t idx = oct_child_index(t->groups[d], i, c);
                uint64_t limit = d + 1 < t->levels ? t->node_count[d + 1] : t->voxel_count;
                if (idx >= limit)
                    abort();
                if (d + 1 == t->levels) {
                    if (t->voxels) /* none in a shell-only file */
                        sum += t->voxels[idx];
                    if (t->surfaces && t->surfaces[idx] >= t->surface_count)
                        abort();
                }
            }
        }
    }
    for (uint32_t i = 0; i < 3 * t->surface_count; i++)
        if (!(t->palette[i] >= 0.0f && t->palette[i] <= 1.0f))
            abort();
    return sum;
}

/* Each stored tape decodes (the reader's checks are the decoder's) and
 * evaluates at a point without reading outside its slots. */
static uint64_t eval_function(const oct_file *f)
{
    const oct_function_tape *fn = oct_get_function(f);
    uint64_t sum = 0;
    for (uint32_t s = 0; fn && s < oct_get_tree(f)->surface_count; s++) {
        tape t;
        if (tape_io_decode(fn[s].insn, fn[s].insn_count, fn[s].konst, fn[s].const_count, fn[s].root,
                           &t) != TAPE_OK)
            abort();
        double *slots = malloc(t.n * sizeof *slots);
        if (!slots)
            abort();
        double v = tape_eval(&t, 0.25, 0.5, 0.75, slots);
        sum += v == v; /* NaN is allowed (log of a negative): the result is not the point */
        free(slots);
        tape_free(&t);
    }
    return sum;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    oct_file *f = NULL;
    uint64_t at = 0;
    /* Structure checks alone (CRCs would stop nearly every mutation)... */
    oct_err trusted = oct_open_memory(data, size, OCT_OPEN_TRUST, &f, &at);
    if (trusted == OCT_OK) {
        fuzz_oct_sink = walk(oct_get_tree(f)) + eval_function(f);
        oct_close(f);
    } else if (f || (unsigned)trusted >= OCT_ERR_COUNT) {
        abort();
    }
    /* ...then everything: never more permissive than the structure checks. */
    oct_err full = oct_open_memory(data, size, 0, &f, &at);
    if (full == OCT_OK) {
        if (trusted != OCT_OK)
            abort();
        oct_close(f);
    }
    return 0;
}
