/* tape_lanes: the point-gradient evaluator of tape_eval.c run over up to
 * TAPE_LANES points per pass. Each lane performs exactly the operations of
 * tape_eval_grad, in the same order (no contraction: -ffp-contract=off), so
 * the results are the same bits; what changes is that the dispatch on the
 * instruction is paid once per pass and the lane loops are vector code. */
#include "common/expr/tape.h"

#include "common/expr/tape_ilanes_int.h"

#define NAME tape_grad_lanes_portable
#include "common/expr/tape_lanes_inst.h"
#undef NAME

/* The build for AVX2 (tape_lanes_avx2.c) where the processor has it
 * (tape_lanes_path): the same operations, so the same bits. */
void tape_eval_grad_lanes(const tape *t, unsigned n, const double x[TAPE_LANES],
                          const double y[TAPE_LANES], const double z[TAPE_LANES],
                          double f[TAPE_LANES], double g[3][TAPE_LANES], tape_dual_lanes *s)
{
#if TAPE_ILANES_AVX2
    if (tape_lanes_path() == TAPE_PATH_AVX2) {
        tape_grad_lanes_avx2(t, n, x, y, z, f, g, s);
        return;
    }
#endif
    tape_grad_lanes_portable(t, n, x, y, z, f, g, s);
}

void tape_eval_lanes(const tape *t, unsigned n, const double x[TAPE_LANES],
                     const double y[TAPE_LANES], const double z[TAPE_LANES], double f[TAPE_LANES],
                     tape_dual_lanes *s)
{
#if TAPE_ILANES_AVX2
    if (tape_lanes_path() == TAPE_PATH_AVX2) {
        tape_grad_lanes_avx2_value(t, n, x, y, z, f, s);
        return;
    }
#endif
    tape_grad_lanes_portable_value(t, n, x, y, z, f, s);
}
