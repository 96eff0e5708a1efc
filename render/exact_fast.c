/* exact_fast: Taylor-certified decisions and Newton steps for the exact
 * hit test (see exact_fast.h; the argument is in RENDER.md). */
#include "render/exact_fast.h"

#include <math.h>

#include "common/expr/tape_err.h"
#include "common/expr/tape_hess.h"

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

/* The bounds below are sums of products of non-negative doubles with fewer
 * than 20 roundings each: times CM they are at least their exact values. */
#define U 0x1p-53
#define CM (1.0 + 0x1p-46)

/* x clamped into [a, b]; NaN gives a. */
static double clamp(double x, double a, double b) { return x > a ? (x < b ? x : b) : a; }

/* The sign of g at m + s* (s* = t - m exactly, s its rounding: |s - s*| <=
 * u |s|) when the model certifies it: g(m + s*) = v* + d* s* + R with |R| <=
 * K s*^2 / 2 (Taylor), |v* - v| <= ev, |d* - d| <= ed, and c = v + d s
 * rounded twice; rs >= |s| bounds the |s*| of the tail (rs = |s|: at the
 * point; rs = r: anywhere on a span whose linear part keeps c's sign). */
static int sign_at(const exact_model *md, double s, double rs, double K)
{
    const double ds = md->d * s, c = md->v + ds;
    const double bnd =
        (md->ev + (md->ed + 0.5 * K * rs) * rs + U * (fabs(c) + 2.0 * fabs(ds))) * CM;
    return c > bnd ? 1 : c < -bnd ? -1 : 0;
}

static void line_point(const exact_line *l, double x, double p[3], double ep[3])
{
    for (int k = 0; k < 3; k++)
        ep[k] = tape_err_point(l->o[k], x, l->d[k], &p[k]);
}

/* g and g' at the computed point p of the line (within ep of the exact one,
 * which lies in the region's box) with bounds on their errors: with the
 * model's a-priori bound where p lies in its box too (then the segment
 * between them does, and f's gradient and g''s over the box carry the
 * input error: |f(p) - f(P)| <= sum grad_k ep_k, |g'(p) - g'(P)| <= sum
 * ep_k hd_k), else tape_eval_dir_err. With grad (may be NULL): f's gradient
 * at p from the same pass where the a-priori bound is used, else grad[0] =
 * NaN. 1, or 0: no bound. */
static int eval_bounded(const tape *t, exact_scratch *w, const exact_line *l,
                        const exact_model *md, const double p[3], const double ep[3], tape_edir *e,
                        double grad[3])
{
    const exact_bound *cb = md->cb;
    if (grad)
        grad[0] = NAN;
    if (cb && p[0] >= cb->box[0].lo && p[0] <= cb->box[0].hi && p[1] >= cb->box[1].lo &&
        p[1] <= cb->box[1].hi && p[2] >= cb->box[2].lo && p[2] <= cb->box[2].hi) {
        e->v = grad ? tape_eval_dir_grad(t, p, l->d, &e->d, grad, w->dirg)
                    : tape_eval_dir(t, p, l->d, &e->d, w->dir);
        if (!(fabs(e->v) <= 0x1p100 && fabs(e->d) <= 0x1p100))
            return 0;
        e->ev = (cb->e.ev + cb->e.grad[0] * ep[0] + cb->e.grad[1] * ep[1] +
                 cb->e.grad[2] * ep[2]) * CM;
        e->ed = (md->fd + md->hd[0] * ep[0] + md->hd[1] * ep[1] + md->hd[2] * ep[2]) * CM;
        w->nbound++;
        return 1;
    }
    return tape_eval_dir_err(t, p, ep, l->d, e, w->edir);
}

/* The root t* of g in [a, b], where g is certified monotone with g' of sign
 * sg and |g'| >= dmin there: Newton steps from the model's estimate, plain
 * (tape_eval_dir) while the next step's quadratic error (K err^2 / 2 dmin,
 * err the predicted error) would exceed the model's noise, then with error
 * bounds (tape_eval_dir_err) at x: |x - t*| <= rho = (|v| + ev) / dmin, g'
 * lies within dr = ed + K rho of d between x and t*, and t* - x = -g(x) /
 * g'(xi) by the mean value theorem: t* lies in x - [v +- ev] / [d +- dr]
 * (outward-rounded intervals), intersected with [a, b]. Accepted once that
 * enclosure is no wider than EXACT_FAST_BAND; *root is the Newton point
 * clamped into it, grad f at x from that evaluation (eval_bounded). 1, or 0:
 * undecided. */
static int place(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                 int sg, double K, double dmin, const exact_model *md, double *root,
                 double grad[3])
{
    double x = clamp(md->m - md->v / md->d, a, b); /* (NaN: a) */
    double err = K * (x - md->m) * (x - md->m) / (2.0 * dmin);
    const double noise = 2.0 * md->ev / dmin;
    double lo = a, hi = b;
    for (int it = 0; it < 6; it++) {
        double p[3], ep[3];
        line_point(l, x, p, ep);
        if (it < 3 && K * err * err > noise * dmin) {
            double dv;
            const double v = tape_eval_dir(t, p, l->d, &dv, w->dir);
            if (!(sg > 0 ? dv > 0.0 : dv < 0.0) || v != v)
                return 0; /* the double derivative disagrees with the certificate */
            x = clamp(x - v / dv, lo, hi);
            err = K * err * err / (2.0 * dmin);
            continue;
        }
        tape_edir e;
        if (!eval_bounded(t, w, l, md, p, ep, &e, grad))
            return 0;
        const double rho = (fabs(e.v) + e.ev) / dmin * CM;
        const double dr = (e.ed + K * rho) * CM;
        if (!(sg > 0 ? e.d > dr : e.d < -dr))
            return 0;
        unsigned f = 0;
        const interval G = {interval_next_down(e.v - e.ev), interval_next_up(e.v + e.ev)};
        const interval D = {interval_next_down(e.d - dr), interval_next_up(e.d + dr)};
        const interval T = interval_sub((interval){x, x}, interval_div(G, D, &f), &f);
        lo = T.lo > lo ? T.lo : lo;
        hi = T.hi < hi ? T.hi : hi;
        if (f || !(lo <= hi))
            return 0; /* (cannot happen: both hold t*) */
        x = clamp(x - e.v / e.d, lo, hi);
        const double ax = fabs(x);
        if (hi - lo <= EXACT_FAST_BAND(e.ev / fabs(e.d), interval_next_up(ax) - ax)) {
            *root = x;
            return 1;
        }
        err = hi - lo;
    }
    return 0;
}

int exact_fast_model(const tape *t, exact_scratch *w, const exact_line *l, double m,
                     const exact_bound *cb, exact_model *model)
{
    double p[3], ep[3];
    line_point(l, m, p, ep);
    model->m = m;
    model->cb = cb;
    if (cb) {
        /* per line: the derivative's rounding bound and |d g'/dx_k| <=
         * sum_j M_kj |d_j| (rounded up by CM: fewer than 20 roundings) */
        const double *M = cb->hmag;
        const double ax = fabs(l->d[0]), ay = fabs(l->d[1]), az = fabs(l->d[2]);
        model->fd = (cb->e.ed[0] * ax + cb->e.ed[1] * ay + cb->e.ed[2] * az) * CM;
        model->hd[0] = (M[TAPE_HXX] * ax + M[TAPE_HXY] * ay + M[TAPE_HXZ] * az) * CM;
        model->hd[1] = (M[TAPE_HXY] * ax + M[TAPE_HYY] * ay + M[TAPE_HYZ] * az) * CM;
        model->hd[2] = (M[TAPE_HXZ] * ax + M[TAPE_HYZ] * ay + M[TAPE_HZZ] * az) * CM;
    }
    tape_edir e;
    if (!eval_bounded(t, w, l, model, p, ep, &e, NULL))
        return 0;
    model->v = e.v;
    model->d = e.d;
    model->ev = e.ev;
    model->ed = e.ed;
    return 1;
}

#define ONE_ROOT 3 /* (classify: one root, to be placed) */

/* The Taylor decisions of exact_fast_decide without the placing: NONE,
 * UNDECIDED, or ONE_ROOT with g''s sign *sg and |g'| >= *dmin on [a, b]. */
static inline int classify(const exact_model *model, double a, double b, double K, int *sg,
                           double *dmin)
{
    /* g'(m + s) within ed + K |s| of d (Taylor with |g''| <= K), |s| <= r
     * (1 + u) on the span (m may lie outside it) */
    const double m = model->m;
    const double sa = a - m, sb = b - m;
    const double r = fabs(sa) > fabs(sb) ? fabs(sa) : fabs(sb); /* (finite; not libm's fmax) */
    const double bd = (model->ed + K * r) * CM;
    *sg = model->d > bd ? 1 : model->d < -bd ? -1 : 0;
    if (!*sg) {
        /* g's linear part keeps one sign over the span, beyond the tail at r */
        const int ga = sign_at(model, sa, r, K);
        return ga && ga == sign_at(model, sb, r, K) ? EXACT_FAST_NONE : EXACT_FAST_UNDECIDED;
    }
    const int ga = sign_at(model, sa, fabs(sa), K), gb = sign_at(model, sb, fabs(sb), K);
    if (!ga || !gb)
        return EXACT_FAST_UNDECIDED;
    if (ga == gb)
        return EXACT_FAST_NONE; /* monotone, the same sign at both ends */
    /* one root in (a, b); |g'| >= |d| - bd there (rounded down) */
    *dmin = (fabs(model->d) - bd) * (1.0 - 0x1p-50);
    return ONE_ROOT;
}

int exact_fast_decide(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                      double curv, const exact_model *model, double *root, double grad[3])
{
    int sg;
    double dmin;
    const int st = classify(model, a, b, curv, &sg, &dmin);
    if (st != ONE_ROOT)
        return st;
    return place(t, w, l, a, b, sg, curv, dmin, model, root, grad) ? EXACT_FAST_ROOT
                                                             : EXACT_FAST_UNDECIDED;
}

/* Could a per-point model at the same m decide where this one did not?
 * Not if the same model without any rounding error cannot (the decisions
 * only get easier as ev and ed shrink); if the classification passed, the
 * placing failed: retry. */
static int worth_retry(const exact_model *model, double a, double b, double K)
{
    int sg;
    double dmin;
    if (classify(model, a, b, K, &sg, &dmin) == ONE_ROOT)
        return 1;
    exact_model exact = *model;
    exact.ev = exact.ed = 0.0;
    return classify(&exact, a, b, K, &sg, &dmin) != EXACT_FAST_UNDECIDED;
}

/* A new model at m: from cb's bound first, and where that gives none or
 * does not decide (and a per-point bound might: worth_retry), from the
 * per-point one; `retry`: this is such a second try already. */
static inline __attribute__((always_inline)) int
fresh(const tape *t, exact_scratch *w, const exact_line *l, double a, double b, double curv,
      const exact_bound *cb, double m, int retry, exact_model *model, int *have, double *root,
      double grad[3])
{
    if (cb) {
        *have = exact_fast_model(t, w, l, m, cb, model);
        if (*have) {
            const int st = exact_fast_decide(t, w, l, a, b, curv, model, root, grad);
            if (st != EXACT_FAST_UNDECIDED || !worth_retry(model, a, b, curv))
                return st;
        }
        w->nretry++;
        retry = 1;
    }
    *have = exact_fast_model(t, w, l, m, NULL, model);
    const int st = *have ? exact_fast_decide(t, w, l, a, b, curv, model, root, grad)
                         : EXACT_FAST_UNDECIDED;
    if (retry && st != EXACT_FAST_UNDECIDED)
        w->nrescue++;
    return st;
}

int exact_fast_first(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                     double curv, const exact_bound *cb, double m, exact_model *model, int *have,
                     double *root, double grad[3])
{
    if (!(curv < INFINITY))
        return EXACT_FAST_UNDECIDED;
    return fresh(t, w, l, a, b, curv, cb, m, 0, model, have, root, grad);
}

int exact_fast_root(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                    double curv, const exact_bound *cb, double m_new, exact_model *model,
                    int *have, double *root, double grad[3])
{
    if (!(curv < INFINITY))
        return EXACT_FAST_UNDECIDED;
    const double mid = 0.5 * (a + b);
    if (!*have && m_new == m_new && m_new != mid) {
        /* the caller's point first; undecided there: the span's midpoint */
        const int st = fresh(t, w, l, a, b, curv, cb, m_new, 0, model, have, root, grad);
        if (st != EXACT_FAST_UNDECIDED)
            return st;
        *have = 0;
    }
    if (*have) {
        const int st = exact_fast_decide(t, w, l, a, b, curv, model, root, grad);
        if (st != EXACT_FAST_UNDECIDED)
            return st;
        if (fabs(model->m - mid) <= 0.25 * (b - a)) {
            /* a model of this span (at its midpoint) would be about the
             * same, but for its bound */
            if (!model->cb || !worth_retry(model, a, b, curv))
                return EXACT_FAST_UNDECIDED;
            w->nretry++;
            return fresh(t, w, l, a, b, curv, NULL, model->m, 1, model, have, root, grad);
        }
    }
    return fresh(t, w, l, a, b, curv, cb, mid, 0, model, have, root, grad);
}
