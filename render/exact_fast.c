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

int exact_fast_in_bound(const exact_bound *cb, const double p[3])
{
    return cb && p[0] >= cb->box[0].lo && p[0] <= cb->box[0].hi && p[1] >= cb->box[1].lo &&
           p[1] <= cb->box[1].hi && p[2] >= cb->box[2].lo && p[2] <= cb->box[2].hi;
}

int exact_fast_bounded(exact_scratch *w, const exact_model *md, const double ep[3], double v,
                       double d, tape_edir *e)
{
    const exact_bound *cb = md->cb;
    if (!(fabs(v) <= 0x1p100 && fabs(d) <= 0x1p100))
        return 0;
    e->v = v;
    e->d = d;
    e->ev = (cb->e.ev + cb->e.grad[0] * ep[0] + cb->e.grad[1] * ep[1] + cb->e.grad[2] * ep[2]) * CM;
    e->ed = (md->fd + md->hd[0] * ep[0] + md->hd[1] * ep[1] + md->hd[2] * ep[2]) * CM;
    w->nbound++;
    return 1;
}

/* g and g' at the computed point p of the line (within ep of the exact one,
 * which lies in the region's box) with bounds on their errors: with the
 * model's a-priori bound where p lies in its box too (exact_fast_in_bound,
 * exact_fast_bounded), else tape_eval_dir_err. With grad (may be NULL): f's
 * gradient at p from the same pass where the a-priori bound is used, else
 * grad[0] = NaN. 1, or 0: no bound. */
static int eval_bounded(const tape *t, exact_scratch *w, const exact_line *l,
                        const exact_model *md, const double p[3], const double ep[3], tape_edir *e,
                        double grad[3])
{
    if (grad)
        grad[0] = NAN;
    if (exact_fast_in_bound(md->cb, p)) {
        double v, d;
        v = grad ? tape_eval_dir_grad(t, p, l->d, &d, grad, w->dirg) : tape_eval_dir(t, p, l->d, &d, w->dir);
        return exact_fast_bounded(w, md, ep, v, d, e);
    }
    return tape_eval_dir_err(t, p, ep, l->d, e, w->edir);
}

void exact_place_begin(exact_place *pl, double a, double b, int sg, double K, double dmin,
                       const exact_model *md)
{
    pl->md = md;
    pl->K = K;
    pl->dmin = dmin;
    pl->sg = sg;
    pl->it = 0;
    pl->x = clamp(md->m - md->v / md->d, a, b); /* (NaN: a) */
    pl->err = K * (pl->x - md->m) * (pl->x - md->m) / (2.0 * dmin);
    pl->noise = 2.0 * md->ev / dmin;
    pl->lo = a;
    pl->hi = b;
}

int exact_place_ask(exact_place *pl, const exact_line *l)
{
    if (pl->it == 6)
        return EXACT_PLACE_FAIL;
    line_point(l, pl->x, pl->p, pl->ep);
    const double K = pl->K;
    return pl->it++ < 3 && K * pl->err * pl->err > pl->noise * pl->dmin ? EXACT_PLACE_PLAIN
                                                                        : EXACT_PLACE_BOUNDED;
}

int exact_place_plain(exact_place *pl, double v, double dv)
{
    if (!(pl->sg > 0 ? dv > 0.0 : dv < 0.0) || v != v)
        return EXACT_PLACE_FAIL; /* the double derivative disagrees with the certificate */
    pl->x = clamp(pl->x - v / dv, pl->lo, pl->hi);
    pl->err = pl->K * pl->err * pl->err / (2.0 * pl->dmin);
    return EXACT_PLACE_MORE;
}

int exact_place_bounded(exact_place *pl, const tape_edir *e)
{
    const double K = pl->K, dmin = pl->dmin, x = pl->x;
    const double rho = (fabs(e->v) + e->ev) / dmin * CM;
    const double dr = (e->ed + K * rho) * CM;
    if (!(pl->sg > 0 ? e->d > dr : e->d < -dr))
        return EXACT_PLACE_FAIL;
    unsigned f = 0;
    const interval G = {interval_next_down(e->v - e->ev), interval_next_up(e->v + e->ev)};
    const interval D = {interval_next_down(e->d - dr), interval_next_up(e->d + dr)};
    const interval T = interval_sub((interval){x, x}, interval_div(G, D, &f), &f);
    const double lo = T.lo > pl->lo ? T.lo : pl->lo;
    const double hi = T.hi < pl->hi ? T.hi : pl->hi;
    pl->lo = lo;
    pl->hi = hi;
    if (f || !(lo <= hi))
        return EXACT_PLACE_FAIL; /* (cannot happen: both hold t*) */
    pl->x = clamp(x - e->v / e->d, lo, hi);
    const double ax = fabs(pl->x);
    if (hi - lo <= EXACT_FAST_BAND(e->ev / fabs(e->d), interval_next_up(ax) - ax))
        return EXACT_PLACE_DONE;
    pl->err = hi - lo;
    return EXACT_PLACE_MORE;
}

/* The root t* of g in [a, b], where g is certified monotone with g' of sign
 * sg and |g'| >= dmin there (exact_place_begin: Newton steps from the
 * model's estimate, plain while the next step's quadratic error would exceed
 * the model's noise, then with error bounds until the root's enclosure is
 * within EXACT_FAST_BAND), each evaluation made here; *root the Newton point
 * clamped into the enclosure, grad f at the last evaluation's point
 * (eval_bounded). 1, or 0: undecided. */
static int place(const tape *t, exact_scratch *w, const exact_line *l, double a, double b,
                 int sg, double K, double dmin, const exact_model *md, double *root,
                 double grad[3])
{
    exact_place pl;
    exact_place_begin(&pl, a, b, sg, K, dmin, md);
    for (;;) {
        int st = exact_place_ask(&pl, l);
        if (st == EXACT_PLACE_PLAIN) {
            double dv;
            const double v = tape_eval_dir(t, pl.p, l->d, &dv, w->dir);
            st = exact_place_plain(&pl, v, dv);
        } else if (st == EXACT_PLACE_BOUNDED) {
            tape_edir e;
            st = eval_bounded(t, w, l, md, pl.p, pl.ep, &e, grad) ? exact_place_bounded(&pl, &e)
                                                                   : EXACT_PLACE_FAIL;
        }
        if (st == EXACT_PLACE_FAIL)
            return 0;
        if (st == EXACT_PLACE_DONE) {
            *root = pl.x;
            return 1;
        }
    }
}

void exact_fast_model_begin(const exact_line *l, double m, const exact_bound *cb,
                            exact_model *model, double p[3], double ep[3])
{
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
}

void exact_fast_model_end(exact_model *model, const tape_edir *e)
{
    model->v = e->v;
    model->d = e->d;
    model->ev = e->ev;
    model->ed = e->ed;
}

int exact_fast_model(const tape *t, exact_scratch *w, const exact_line *l, double m,
                     const exact_bound *cb, exact_model *model)
{
    double p[3], ep[3];
    exact_fast_model_begin(l, m, cb, model, p, ep);
    tape_edir e;
    if (!eval_bounded(t, w, l, model, p, ep, &e, NULL))
        return 0;
    exact_fast_model_end(model, &e);
    return 1;
}

#define ONE_ROOT EXACT_FAST_ONE_ROOT

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

int exact_fast_classify(const exact_model *model, double a, double b, double curv, int *sg,
                        double *dmin)
{
    return classify(model, a, b, curv, sg, dmin);
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
