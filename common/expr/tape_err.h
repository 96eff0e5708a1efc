/* tape_err: f and its derivative along d at a point, in double, each with
 * a rigorous bound on its distance from the exact value (a running
 * rounding-error bound, Wilkinson style; tape_eval_err.c). Two to three
 * times the work of tape_eval_dir, where an interval evaluation at a point
 * box costs about ten. */
#ifndef TAPE_ERR_H
#define TAPE_ERR_H

#include "common/expr/tape.h"

/* A value and its directional derivative, each with a bound on its error. */
typedef struct tape_edir {
    double v, d;   /* computed: bit for bit tape_eval_dir's */
    double ev, ed; /* |v - exact value| <= ev, |d - exact derivative| <= ed */
} tape_edir;

/* The exact point P is any point with |P_k - p[k]| <= ep[k] (ep >= 0), d is
 * exact. On 1, out->v and out->d are tape_eval_dir's at p, bit for bit, and
 * for every such P and every function the tape stands for (a pruned
 * constant anywhere in its [lo, hi]): |f(P) - v| <= ev and
 * |grad f(P) . d - d| <= ed, where f is defined and differentiable on a
 * neighbourhood of P (the bound says so: no kink, pole or domain edge lies
 * within the operands' error bounds). Returns 0 (nothing is claimed) where
 * it cannot say that: an operand of abs, min/max within its error of the
 * kink, of sqrt, log, powc or a divisor within its error of 0 (or of a pole
 * of tan), exp of an operand known to less than 1/16, sin, cos, tan beyond
 * |1e8|, or any value, derivative or bound beyond 2^100 in magnitude (also
 * NaN and overflow). The rounding assumptions are the interval code's
 * (interval.h): + - * / sqrt correctly rounded, exp log sin cos tan pow
 * within two ulps of their result; round to nearest with gradual underflow
 * (no flush to zero). `slots`: t->n elements. */
int tape_eval_dir_err(const tape *t, const double p[3], const double ep[3], const double d[3],
                      tape_edir *out, tape_edir *slots);

/* The bound on |fl(o + fl(m d)) - (o + m d)| for one coordinate of a
 * line's point: two roundings, each at most 2^-53 of its result. */
double tape_err_point(double o, double m, double d, double *p);

#endif
