/* tape_iglanes: tape_eval_interval_grad over up to TAPE_LANES boxes per
 * pass (tape_iglanes_body.h), built twice: here for the baseline target,
 * and in tape_iglanes_avx2.c for AVX2, chosen as the lane interval
 * evaluator's build is (tape_lanes_path). Both give every lane the bits of
 * tape_eval_interval_grad. */
#include "common/expr/tape.h"

#include "common/expr/tape_idual_op.h"
#include "common/expr/tape_ilanes_int.h"

#define NAME tape_iglanes_portable
#include "common/expr/tape_iglanes_inst.h"
#undef NAME

void tape_eval_interval_grad_lanes_on(int path, const tape *t, unsigned n,
                                      const interval box[][3], interval out[],
                                      interval grad[][3], unsigned flags[],
                                      tape_idual_lanes *slots)
{
    tape_ilanes b[3];
    unsigned fl[TAPE_LANES] = {0};
    il_boxes_in_lanes(n, box, b);
#if TAPE_ILANES_AVX2
    if (path == TAPE_PATH_AVX2)
        tape_iglanes_avx2(t, n, b, fl, slots);
    else
#endif
        tape_iglanes_portable(t, n, b, fl, slots);
    (void)path;
    const tape_idual_lanes *r = &slots[t->root];
    for (unsigned l = 0; l < n; l++) {
        out[l] = il_get(&r->v, l);
        for (int j = 0; j < 3; j++)
            grad[l][j] = il_get(&r->d[j], l);
        flags[l] = fl[l];
    }
}

void tape_eval_interval_grad_lanes(const tape *t, unsigned n, const interval box[][3],
                                   interval out[], interval grad[][3], unsigned flags[],
                                   tape_idual_lanes *slots)
{
    tape_eval_interval_grad_lanes_on(tape_lanes_path(), t, n, box, out, grad, flags, slots);
}
