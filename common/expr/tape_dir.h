/* tape_dir: f and its derivative along one direction d (one tangent of
 * forward-mode AD: a third of the gradient evaluator's work), at a point in
 * double and over a box in interval arithmetic (tape_eval_dir.c). For a
 * line p(t) = o + t d, the derivative is g'(t) of g(t) = f(p(t)). */
#ifndef TAPE_DIR_H
#define TAPE_DIR_H

#include "common/expr/tape.h"

/* A value and its directional derivative. */
typedef struct tape_dir1 {
    double v, d[1];
} tape_dir1;
/* A value, its directional derivative (d[0]) and its gradient (d[1..3]). */
typedef struct tape_dir4 {
    double v, d[4];
} tape_dir4;
typedef struct tape_idir1 {
    interval v, d;
} tape_idir1;

/* f(p) and grad f(p) . d in double (*deriv). The value is, bit for bit,
 * tape_eval's at p; the derivative follows tape_eval_grad's rules (abs,
 * min, max: the branch taken). `slots`: t->n elements. */
double tape_eval_dir(const tape *t, const double p[3], const double d[3], double *deriv,
                     tape_dir1 *slots);

/* tape_eval_dir's value and *deriv, bit for bit, and in the same pass
 * grad[3], bit for bit tape_eval_grad's at p (the same rules on each
 * tangent). `slots`: t->n elements. */
double tape_eval_dir_grad(const tape *t, const double p[3], const double d[3], double *deriv,
                          double grad[3], tape_dir4 *slots);

/* Enclosures over the box: of f (as tape_eval_interval's, *deriv aside) and
 * of grad f . d at every point of the box where f is defined and
 * differentiable (unless *flags is set: see tape_eval_interval). d is exact
 * (point intervals). At a kink (abs, or min/max whose operands' enclosures
 * overlap) the derivative encloses both branches' derivatives. */
interval tape_eval_interval_dir(const tape *t, const interval box[3], const double d[3],
                                interval *deriv, tape_idir1 *slots, unsigned *flags);

#endif
