/* exact_fast: the certified fast path of the exact hit test in one voxel
 * (RENDER.md, "--exact", "The fast path"): one interval evaluation of g and
 * g' at a point of the line and a bound on |g''| over the coarse cell decide
 * the common cases by Taylor's theorem, for every voxel of the cell along
 * the line; Newton steps and an enclosure of the root from an evaluation
 * with rounding-error bounds place the root. What it cannot decide is left to
 * exact_first_root. */
#ifndef EXACT_FAST_H
#define EXACT_FAST_H

#include "common/expr/tape.h"
#include "common/expr/tape_err_cell.h"
#include "render/exact_hit.h"

enum {
    EXACT_FAST_UNDECIDED = 0, /* use exact_first_root */
    EXACT_FAST_NONE = 1,      /* certified: no root of f on the span */
    EXACT_FAST_ROOT = 2,      /* the root, within a certified enclosure no wider
                                 than twice the noise band (EXACT_FAST_BAND) */
};

/* The bound on |g''(t)| = |d^T Hess f d| along the line's direction d from
 * the magnitudes of a Hessian enclosure (tape_hess_mag) over a box holding
 * every point tested, rounded up; +inf when those are. */
double exact_fast_curv(const double mag[6], const double d[3]);

/* A region's a-priori rounding-error bound (tape_err_cell over its box,
 * which holds every point tested there) and the magnitudes of its Hessian
 * enclosure over the same box (tape_hess_mag): with them an evaluation at a
 * point of the box is tape_eval_dir plus a constant (RENDER.md, "The
 * a-priori bound"). */
typedef struct exact_bound {
    tape_cell_err e;
    interval box[3];
    const double *hmag;
} exact_bound;

/* A first-order model of g at m: g(m) and g'(m) in double with rigorous
 * bounds on their errors (at the computed point o + m d, whose own rounding
 * is bounded too): from the region's a-priori bound (cb) or, where there is
 * none or it does not decide, tape_eval_dir_err's running one (cb NULL). */
typedef struct exact_model {
    double m;
    double v, d, ev, ed; /* |g(m) - v| <= ev, |g'(m) - d| <= ed */
    const exact_bound *cb;
    double fd, hd[3]; /* with cb: sum |d_k| ed_k, and sum_j M_kj |d_j| (|d g' / dx_k|) */
} exact_model;

/* Fills *model at m with cb's bound (cb may be NULL): 1, or 0 when the
 * evaluation gives no bound (no model). */
int exact_fast_model(const tape *t, exact_scratch *w, const exact_line *l, double m,
                     const exact_bound *cb, exact_model *model);

/* The first root of g(t) = f(o + t d) on [a, b] (a <= b, finite) decided
 * by Taylor's theorem from the model (at any m whose point lies in a box,
 * convex, holding the segment's points, over which `curv` bounds |g''|):
 * EXACT_FAST_NONE when g certainly has no root there; EXACT_FAST_ROOT with
 * *root when g is certified monotone on [a, b] with certified opposite
 * signs at the ends (so exactly one root t*), and *root lies in a certified
 * enclosure of t* no wider than the noise band of g's double evaluation
 * there (EXACT_FAST_BAND: four times its error bound over |g'|, and 4 ulps),
 * and in grad f's gradient from the evaluation that placed it (at the point
 * that the last Newton step, within the enclosure, moved to *root; grad[0]
 * NaN when that evaluation gave none); otherwise EXACT_FAST_UNDECIDED. */
/* The width of a root's enclosure that counts as converged: four times the
 * value's error bound over |g'| (twice the noise band's width), plus 4 ulps
 * of t. */
#define EXACT_FAST_BAND(ev_over_dg, ulp) (4.0 * (ev_over_dg) + 4.0 * (ulp))

int exact_fast_decide(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                      double curv, const exact_model *model, double *root, double grad[3]);

/* exact_fast_root's first try alone: a new model at m (*model, *have),
 * from cb's bound and, where that does not decide, from the per-point one,
 * asked about [a, b]; no other point is tried. EXACT_FAST_UNDECIDED when
 * curv is +inf. */
int exact_fast_first(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                     double curv, const exact_bound *cb, double m, exact_model *model, int *have,
                     double *root, double grad[3]);

/* exact_fast_decide with the caller's model (*have: it holds one, for this
 * line and a box as above) if that decides; else, unless the model's m is
 * within a quarter span of the span's midpoint already, with a new model
 * (*model and *have updated) at m_new when the caller had none and m_new
 * is not NaN (a point of the line in the box), and where that does not
 * decide, at the midpoint; each from cb's bound (may be NULL) and, if that
 * does not decide, from the per-point one. EXACT_FAST_UNDECIDED when curv
 * is +inf. (No
 * interval of f over the segment first: one model decides the voxels of
 * the whole cell along the line that it can, for the cost of about one such
 * interval.) */
int exact_fast_root(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                    double curv, const exact_bound *cb, double m_new, exact_model *model,
                    int *have, double *root, double grad[3]);

#endif
