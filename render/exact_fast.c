/* exact_fast: Taylor-certified decisions and Newton steps for the exact
 * hit test (see exact_fast.h; the argument is in RENDER.md). */
#include "render/exact_fast.h"

#include <math.h>

#include "common/expr/tape_hess.h"

static interval ipt(double x) { interval r = {x, x}; return r; }

double exact_fast_curv(const double mag[6], const double d[3])
{
    const double ax = fabs(d[0]), ay = fabs(d[1]), az = fabs(d[2]);
    /* nine products and eight sums of non-negative terms: each rounding
     * loses at most 2^-53 of the running sum, so 2^-48 covers them all */
    const double s = mag[TAPE_HXX] * ax * ax + mag[TAPE_HYY] * ay * ay + mag[TAPE_HZZ] * az * az +
                     2.0 * (mag[TAPE_HXY] * ax * ay + mag[TAPE_HXZ] * ax * az +
                            mag[TAPE_HYZ] * ay * az);
    return s != s ? INFINITY : interval_next_up(s * (1.0 + 0x1p-48));
}

static double g_at(const tape *t, exact_scratch *w, const exact_line *l, double s)
{
    return tape_eval(t, l->o[0] + s * l->d[0], l->o[1] + s * l->d[1], l->o[2] + s * l->d[2],
                     w->slots);
}

/* Strictly positive (1), strictly negative (-1), or holding 0 or NaN (0). */
static int sign_of(interval x)
{
    return x.lo > 0.0 ? 1 : x.hi < 0.0 ? -1 : 0;
}

/* The root of g in [a, b], where g is certified monotone (g' of sign sg)
 * with one root: one Newton step from x1 (the midpoint's step), whose
 * error is about curv dx^2 / (2 |g'|) plus the rounding noise of g's double
 * evaluation (at most about the width w0 of the midpoint's enclosure over
 * |g'|); the bracket of twice that around it, confirmed by the signs of g
 * at its ends (else widened to an end of [a, b]), is refined to adjacent
 * doubles (exact_refine). 1 with *root, or 0: undecided. */
static int newton(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                  int sg, double x1, double curv, double w0, double *root)
{
    const double p[3] = {l->o[0] + x1 * l->d[0], l->o[1] + x1 * l->d[1], l->o[2] + x1 * l->d[2]};
    double dv;
    const double v = tape_eval_dir(t, p, l->d, &dv, w->dir);
    if (v == 0.0) {
        *root = x1;
        return 1;
    }
    if (!(sg > 0 ? dv > 0.0 : dv < 0.0) || v != v || !isfinite(dv))
        return 0; /* the double derivative disagrees with the certificate */
    double x2 = x1 - v / dv;
    x2 = x2 > a ? (x2 < b ? x2 : b) : a;
    const double dx = x2 - x1, adv = fabs(dv);
    const double e = 2.0 * (curv * dx * dx / (2.0 * adv) + w0 / adv) +
                     4.0 * (interval_next_up(fabs(x2)) - fabs(x2));
    double lo = x2 - e > a ? x2 - e : a, hi = x2 + e < b ? x2 + e : b;
    double glo = g_at(t, w, l, lo), ghi = g_at(t, w, l, hi);
    if (glo != glo || ghi != ghi)
        return 0;
    if (!(glo == 0.0 || ghi == 0.0 || (glo < 0.0) != (ghi < 0.0))) {
        /* both on one side of the root: it lies beyond, up to an end */
        const int below = (glo < 0.0) == (sg > 0); /* g below the root's sign */
        if (below ? hi == b : lo == a)
            return 0;
        if (below) {
            lo = hi;
            glo = ghi;
            hi = b;
            ghi = g_at(t, w, l, b);
        } else {
            hi = lo;
            ghi = glo;
            lo = a;
            glo = g_at(t, w, l, a);
        }
        if (!(glo == 0.0 || ghi == 0.0 || (glo < 0.0) != (ghi < 0.0)))
            return 0;
    }
    const double r = exact_refine(t, w, l, lo, hi, glo, ghi);
    if (!(r < INFINITY))
        return 0;
    *root = r;
    return 1;
}

int exact_fast_model(const tape *t, exact_scratch *w, const exact_line *l, double m,
                     exact_model *model)
{
    interval box[3];
    exact_segment_box(l, m, m, box);
    unsigned flags = 0;
    model->m = m;
    model->g = tape_eval_interval_dir(t, box, l->d, &model->dg, w->idir, &flags);
    return !flags && !interval_is_nan(model->g) && !interval_is_nan(model->dg);
}

int exact_fast_decide(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                      double curv, const exact_model *model, double *root)
{
    const double m = model->m;
    const interval G0 = model->g, G1 = model->dg;
    unsigned flags = 0;
    /* g(m + s) in G0 + G1 s + [-1, 1] curv s^2 / 2 for s in [a - m, b - m]
     * (Taylor with the remainder's bound), and g'(m + s) in G1 + [-1, 1]
     * curv |s|: all evaluated with outward rounding */
    const interval Sa = interval_sub(ipt(a), ipt(m), &flags);
    const interval Sb = interval_sub(ipt(b), ipt(m), &flags);
    const double r = fmax(-Sa.lo, Sb.hi); /* max |s| (m may lie outside [a, b]) */
    const double kr = interval_next_up(curv * r);
    const double q = interval_next_up(interval_next_up(kr * r) * 0.5);
    const interval Q = {-q, q};
    const int sg = G1.lo > kr ? 1 : G1.hi < -kr ? -1 : 0;
    if (!sg) {
        const interval S = {Sa.lo, Sb.hi};
        const interval G = interval_add(interval_add(G0, interval_mul(G1, S, &flags), &flags), Q,
                                        &flags);
        return sign_of(G) && !flags ? EXACT_FAST_NONE : EXACT_FAST_UNDECIDED;
    }
    const int ga = sign_of(interval_add(interval_add(G0, interval_mul(G1, Sa, &flags), &flags), Q,
                                        &flags));
    const int gb = sign_of(interval_add(interval_add(G0, interval_mul(G1, Sb, &flags), &flags), Q,
                                        &flags));
    if (flags || !ga || !gb)
        return EXACT_FAST_UNDECIDED;
    if (ga == gb)
        return EXACT_FAST_NONE; /* monotone, the same sign at both ends */
    /* one root in (a, b): the first Newton step from the enclosures' midpoints */
    double x = m - 0.5 * (G0.lo + G0.hi) / (0.5 * (G1.lo + G1.hi));
    x = x > a ? (x < b ? x : b) : a; /* (NaN: a) */
    return newton(t, w, l, a, b, sg, x, curv, G0.hi - G0.lo, root) ? EXACT_FAST_ROOT
                                                                  : EXACT_FAST_UNDECIDED;
}

int exact_fast_root(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                    double curv, exact_model *model, int *have, double *root)
{
    if (!(curv < INFINITY))
        return EXACT_FAST_UNDECIDED;
    if (*have) {
        const int st = exact_fast_decide(t, w, l, a, b, curv, model, root);
        if (st != EXACT_FAST_UNDECIDED)
            return st;
        if (model->m >= a && model->m <= b)
            return EXACT_FAST_UNDECIDED; /* a model of this span would be the same */
    }
    *have = exact_fast_model(t, w, l, 0.5 * (a + b), model);
    return *have ? exact_fast_decide(t, w, l, a, b, curv, model, root) : EXACT_FAST_UNDECIDED;
}
