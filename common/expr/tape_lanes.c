/* tape_lanes: the point-gradient evaluator of tape_eval.c run over up to
 * TAPE_LANES points per pass. Each lane performs exactly the operations of
 * tape_eval_grad, in the same order (no contraction: -ffp-contract=off), so
 * the results are the same bits; what changes is that the dispatch on the
 * instruction is paid once per pass and the lane loops are vector code. */
#include "common/expr/tape.h"

#include <math.h>
#include <string.h>

#include "common/expr/tape_int.h"

#define L TAPE_LANES

/* Lanes from n on take lane 0's value (their points repeat lane 0's). */
static void fill(double *v, unsigned n)
{
    for (unsigned l = n; l < L; l++)
        v[l] = v[0];
}

#define W 2
#define FN eval2
#define SCALE scale2
#include "common/expr/tape_lanes_body.h"
#undef W
#undef FN
#undef SCALE
#define W 4
#define FN eval4
#define SCALE scale4
#include "common/expr/tape_lanes_body.h"
#undef W
#undef FN
#undef SCALE
#define W 6
#define FN eval6
#define SCALE scale6
#include "common/expr/tape_lanes_body.h"
#undef W
#undef FN
#undef SCALE
#define W 8
#define FN eval8
#define SCALE scale8
#include "common/expr/tape_lanes_body.h"

/* The fewest lanes that hold n: the arithmetic runs on every lane. */
void tape_eval_grad_lanes(const tape *t, unsigned n, const double x[L], const double y[L],
                          const double z[L], double f[L], double g[3][L], tape_dual_lanes *s)
{
    if (n <= 2)
        eval2(t, n, x, y, z, f, g, s);
    else if (n <= 4)
        eval4(t, n, x, y, z, f, g, s);
    else if (n <= 6)
        eval6(t, n, x, y, z, f, g, s);
    else
        eval8(t, n, x, y, z, f, g, s);
}
