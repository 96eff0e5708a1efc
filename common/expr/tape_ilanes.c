/* tape_ilanes: tape_eval_interval over up to TAPE_LANES boxes per pass
 * (tape_ilanes_body.h), built twice: here for the baseline target, and in
 * tape_ilanes_avx2.c for AVX2; the AVX2 build runs where the processor has
 * it. Both give every lane the bits of tape_eval_interval, so the choice
 * never shows in a result. Test builds force the portable one with
 * DDA_SIMD=portable (common/test_hooks.h), so the tests run both. */
#include "common/expr/tape.h"

#include <stdatomic.h>

#include "common/expr/tape_ilanes_int.h"
#include "common/test_hooks.h"

#define NAME tape_ilanes_portable
#include "common/expr/tape_ilanes_inst.h"
#undef NAME

const char *tape_lanes_path_name(int path)
{
    return path == TAPE_PATH_AVX2 ? "avx2" : "portable";
}

int tape_lanes_path_available(int path)
{
    if (path == TAPE_PATH_PORTABLE)
        return 1;
#if TAPE_ILANES_AVX2
    if (path == TAPE_PATH_AVX2)
        return __builtin_cpu_supports("avx2") != 0;
#endif
    return 0;
}

int tape_lanes_path(void)
{
    static atomic_int chosen = -1; /* any thread may decide: they decide alike */
    int p = atomic_load_explicit(&chosen, memory_order_relaxed);
    if (p < 0) {
        p = !test_hooks_portable_simd() && tape_lanes_path_available(TAPE_PATH_AVX2)
                ? TAPE_PATH_AVX2
                : TAPE_PATH_PORTABLE;
        atomic_store_explicit(&chosen, p, memory_order_relaxed);
    }
    return p;
}

void tape_eval_interval_lanes_on(int path, const tape *t, unsigned n,
                                 const interval box[][3], interval out[],
                                 unsigned flags[], tape_ilanes *slots)
{
    tape_ilanes b[3];
    unsigned fl[TAPE_LANES] = {0};
    il_boxes_in_lanes(n, box, b);
#if TAPE_ILANES_AVX2
    if (path == TAPE_PATH_AVX2)
        tape_ilanes_avx2(t, n, b, fl, slots);
    else
#endif
        tape_ilanes_portable(t, n, b, fl, slots);
    (void)path;
    for (unsigned l = 0; l < n; l++) {
        out[l] = il_get(&slots[t->root], l);
        flags[l] = fl[l];
    }
}

void tape_eval_interval_lanes(const tape *t, unsigned n, const interval box[][3], interval out[],
                              unsigned flags[], tape_ilanes *slots)
{
    tape_eval_interval_lanes_on(tape_lanes_path(), t, n, box, out, flags, slots);
}
