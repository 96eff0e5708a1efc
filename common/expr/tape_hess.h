/* tape_hess: an enclosure of f's Hessian over a box (second-order
 * forward-mode AD in interval arithmetic, outward rounding as interval.h;
 * tape_eval_interval_hess.c), for a bound on the second derivative of f
 * along any line through the box. */
#ifndef TAPE_HESS_H
#define TAPE_HESS_H

#include "common/expr/tape.h"

/* Entries of a symmetric 3 x 3 matrix: xx, xy, xz, yy, yz, zz. */
enum { TAPE_HXX, TAPE_HXY, TAPE_HXZ, TAPE_HYY, TAPE_HYZ, TAPE_HZZ, TAPE_HN };

/* Slot scratch of the Hessian evaluator: value, gradient, Hessian. */
typedef struct tape_ihess {
    interval v, g[3], h[TAPE_HN];
} tape_ihess;

/* Set in *flags (besides INTERVAL_MAYBE_NAN) when f may have a kink in the
 * box: abs of an operand whose enclosure holds 0 inside, or min/max whose
 * operands' enclosures overlap. There f is not twice differentiable and the
 * Hessian enclosure means nothing. */
enum { TAPE_HESS_KINK = 2u };

/* Enclosures of f, its gradient and its Hessian over the box: for every p
 * in the box, the Hessian of f at p lies in hess[] when *flags is 0 (f is
 * then defined and twice differentiable on the whole box). `slots`: t->n
 * elements. */
interval tape_eval_interval_hess(const tape *t, const interval box[3], interval grad[3],
                                 interval hess[TAPE_HN], tape_ihess *slots, unsigned *flags);

/* The magnitudes max |h| of the Hessian enclosure's entries over the box
 * (mag[TAPE_HN]), so that |d^T Hess f(p) d| <= sum over i, j of mag_ij
 * |d_i| |d_j| for every p in the box and every d. All +inf when the
 * evaluation is flagged (undefined, kink) or an entry is not finite.
 * Returns 1 when the magnitudes are finite, else 0. */
int tape_hess_mag(const tape *t, const interval box[3], tape_ihess *slots,
                  double mag[TAPE_HN]);

/* tape_hess_mag's magnitudes in mag[], and in branch[] those of the same
 * enclosure with the kinks allowed (+inf only when flagged otherwise, i.e.
 * f may be undefined in the box, or an entry is not finite): a min/max
 * whose operands overlap encloses both operands' derivatives, an abs of
 * an operand holding 0 has its first derivative in [-1, 1] and its second
 * 0. So branch[] bounds |d^T Hess f(p) d| on every sub-box of the box where
 * f has no kink (tape_hess_kinks is 0 for it, or for a tape_prune of it for
 * that sub-box): there every min/max keeps one operand and every abs one
 * sign, f is the composition of those branches, and each instruction's
 * enclosure over the box holds its branch's derivatives at the sub-box's
 * points. */
void tape_hess_mags(const tape *t, const interval box[3], tape_ihess *slots, double mag[TAPE_HN],
                    double branch[TAPE_HN]);

/* What may keep f from being twice differentiable in the box, by the rule
 * of TAPE_HESS_KINK: a mask of TAPE_KINK_ABS (an abs of an operand whose
 * enclosure holds 0 inside), TAPE_KINK_MINMAX (a min/max whose operands'
 * enclosures overlap) and TAPE_KINK_FLAG (f may be undefined there); 0:
 * none. `slots`: t->n elements (one interval evaluation over the box). */
enum { TAPE_KINK_ABS = 1u, TAPE_KINK_MINMAX = 2u, TAPE_KINK_FLAG = 4u };
unsigned tape_hess_kinks(const tape *t, const interval box[3], interval *slots);

/* tape_hess_kinks of `pruned` over the box without evaluating it again:
 * `pruned` is what tape_prune or tape_prune_const last wrote from t with
 * `slots` (t's tape_eval_interval over the box, with flags 0) and `scratch`
 * (the same array, left as they leave it); scratch NULL: pruned is t
 * itself. The pruned tape's evaluation over the box gives each instruction
 * the enclosure t's gave it (a constant holds its slot's enclosure, a
 * decided min/max's winner is its operand's), so the mask reads those; no
 * flag, as t's evaluation has none (tape_prune.c). */
unsigned tape_prune_kinks(const tape *t, const interval *slots, const uint32_t *scratch,
                          const tape *pruned);

#endif
