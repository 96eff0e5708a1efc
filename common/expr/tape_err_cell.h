/* tape_err_cell: an a-priori bound on the rounding error of tape_eval_dir
 * over a whole box (tape_err_cell.c): made once per box from the interval
 * enclosures of every slot's value and gradient there, it bounds the error
 * of the plain double evaluation at every point of the box, so that a caller
 * evaluating many points of one box pays tape_eval_dir plus a constant
 * instead of tape_eval_dir_err's running bound at each point. */
#ifndef TAPE_ERR_CELL_H
#define TAPE_ERR_CELL_H

#include "common/expr/tape.h"

/* The bounds for one tape over one box. */
typedef struct tape_cell_err {
    double ev;      /* |v - f(p)| <= ev */
    double ed[3];   /* |d - grad f(p) . dir| <= sum_k |dir_k| ed[k] */
    double grad[3]; /* |df/dx_k| <= grad[k] everywhere in the box */
} tape_cell_err;

/* Per-slot scratch of tape_err_cell. */
typedef struct tape_cerr {
    double e, f[3];
} tape_cerr;

/* On 1: for every double point p in the box, every exact direction dir and
 * every function the tape stands for (a pruned constant anywhere in its
 * [lo, hi]), tape_eval_dir's v and d at p (computed from p, dir exactly as
 * given) satisfy the bounds of *out, f is defined and differentiable on a
 * neighbourhood of the box's points with no kink (abs, min, max) or domain
 * edge within reach of the computed operands, and out->grad bounds f's
 * gradient over the box. Returns 0 (nothing is claimed) where the box's
 * enclosure is flagged (f may be undefined), an abs or min/max operand's
 * range (widened by its error) reaches the kink, a sqrt, log or divisor's
 * range reaches 0, for exp of an operand known to less than 1/16 or above
 * 69, sin and cos beyond |1e8|, tan and powc (no bound made: the caller
 * uses tape_eval_dir_err), or a magnitude or bound beyond 2^100. The
 * rounding assumptions are tape_err.h's. `gslots` and `slots`: t->n
 * elements each. */
int tape_err_cell(const tape *t, const interval box[3], tape_cell_err *out, tape_idual *gslots,
                  tape_cerr *slots);

#endif
